/* rl_common.h: status codes, per-thread error messages and logging.
 *
 * Every fallible renderlab call returns an rl_status. On failure the library
 * keeps a readable message per thread (the first error since the last
 * rl_clear_error(), with context such as "scene.json:12:5: unknown key
 * \"bounce\""), available from rl_last_error(). The library never prints and
 * never exits: log lines go to a callback the application installs. */
#ifndef RL_COMMON_H
#define RL_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The shared library is built with hidden visibility, so that it exports
 * exactly the functions declared RL_API here and none of the internal rl_*
 * helpers of src/ (tests/install/exports.sh checks this). RL_BUILD_LIBRARY
 * is defined only while compiling renderlab itself; an application sees a
 * plain declaration, so that its own visibility settings stay its own. */
#if defined(RL_BUILD_LIBRARY) && (defined(__GNUC__) || defined(__clang__))
#define RL_API __attribute__((visibility("default")))
#else
#define RL_API
#endif

/* One list of (code, value, message); tests compare codes, people read text. */
#define RL_STATUS_LIST(X)                                                     \
    X(RL_OK,                  0, "success")                                   \
    X(RL_ERR_INVALID_ARG,     1, "invalid argument")                          \
    X(RL_ERR_OUT_OF_MEMORY,   2, "out of memory")                             \
    X(RL_ERR_IO,              3, "file could not be read or written")         \
    X(RL_ERR_PARSE,           4, "malformed input")                           \
    X(RL_ERR_UNSUPPORTED,     5, "unsupported format or feature")             \
    X(RL_ERR_NOT_FOUND,       6, "no such item")                              \
    X(RL_ERR_EMPTY_SCENE,     7, "scene has no renderable geometry")          \
    X(RL_ERR_NOT_COMMITTED,   8, "object must be committed first")            \
    X(RL_ERR_CANCELLED,       9, "cancelled")                                 \
    X(RL_ERR_LIMIT,          10, "size or count exceeds a limit")             \
    X(RL_ERR_INTERNAL,       11, "internal error")                          \
    X(RL_ERR_CRASHED,        12, "third-party code crashed in a child process")

typedef enum rl_status {
#define RL_STATUS_ENUM(code, value, msg) code = value,
    RL_STATUS_LIST(RL_STATUS_ENUM)
#undef RL_STATUS_ENUM
    RL_STATUS_COUNT
} rl_status;

/* Static description of a status code ("invalid argument"); never NULL. */
RL_API const char *rl_status_string(rl_status status);
/* Symbolic name of a status code ("RL_ERR_PARSE"); never NULL. */
RL_API const char *rl_status_name(rl_status status);

/* Message of the first error on this thread since rl_clear_error(), or "" if
 * none. The pointer stays valid until the next error or clear on this thread. */
RL_API const char *rl_last_error(void);
RL_API rl_status rl_last_status(void);
RL_API void rl_clear_error(void);

/* Logging. Default: no callback, nothing printed. */
typedef enum rl_log_level {
    RL_LOG_ERROR = 0, RL_LOG_WARN, RL_LOG_INFO, RL_LOG_DEBUG
} rl_log_level;
typedef void (*rl_log_fn)(void *user, rl_log_level level, const char *message);
RL_API void rl_log_set_callback(rl_log_fn fn, void *user);
/* Messages above this level are dropped before formatting (default INFO). */
RL_API void rl_log_set_level(rl_log_level level);
RL_API rl_log_level rl_log_get_level(void);
RL_API const char *rl_log_level_name(rl_log_level level);

/* JSON files the library reads (scenes, approximation files): at most
 * rl_json_max_bytes() bytes (a regular file is refused before it is read)
 * and one value per 16 of those bytes, counted before the tree is built:
 * cJSON takes about 80 bytes per value, so a 64 MB array of zeros would
 * take 3 GB. Default RL_JSON_MAX_BYTES (256 MiB: 16 M values, a tree of
 * about 1.3 GB); above: RL_ERR_LIMIT naming the file. Process-wide; 0
 * restores the default; set it before loading (not thread-safe against
 * loads in flight). */
#define RL_JSON_MAX_BYTES (256ull << 20)
RL_API void rl_json_set_max_bytes(unsigned long long bytes);
RL_API unsigned long long rl_json_max_bytes(void);

/* Progress reporting for anything long: done in [0,1]. Return false to
 * cancel; the operation then fails with RL_ERR_CANCELLED. */
typedef bool (*rl_progress_fn)(void *user, double done);

#ifdef __cplusplus
}
#endif
#endif
