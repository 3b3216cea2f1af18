/* error.h: internal error and log helpers (not part of the public API). */
#ifndef RL_CORE_ERROR_H
#define RL_CORE_ERROR_H

#include "rl/rl_common.h"

#if defined(__GNUC__)
#define RL_PRINTF(f, a) __attribute__((format(printf, f, a)))
#else
#define RL_PRINTF(f, a)
#endif

/* Records status + message for this thread (keeps the first one until cleared)
 * and returns status, so that callers can write
 *     return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno)); */
rl_status rl_error(rl_status status, const char *fmt, ...) RL_PRINTF(2, 3);
/* Formats and passes one line to the log callback if level is enabled. */
void rl_log(rl_log_level level, const char *fmt, ...) RL_PRINTF(2, 3);
#define rl_warn(...)  rl_log(RL_LOG_WARN, __VA_ARGS__)
#define rl_info(...)  rl_log(RL_LOG_INFO, __VA_ARGS__)
#define rl_debug(...) rl_log(RL_LOG_DEBUG, __VA_ARGS__)

/* Allocation helpers that set RL_ERR_OUT_OF_MEMORY on failure. */
void *rl_alloc(size_t size);                       /* malloc */
void *rl_calloc(size_t count, size_t size);        /* calloc, overflow-checked */
void *rl_realloc_array(void *p, size_t count, size_t size); /* overflow-checked */
/* Grow-by-doubling: makes *array (of item_size elements, capacity *cap) hold
 * at least count of them, starting at `first` when empty. Leaves both
 * untouched and returns false when out of memory (the error is set). The
 * _u32 form is for capacities kept in 32 bits; false also above UINT32_MAX. */
bool rl_reserve(void **array, size_t *cap, size_t count, size_t item_size, size_t first);
/* The capacity rl_reserve grows cap to for count items: cap itself when it
 * is enough, else doubled from cap (or `first` when cap is 0). For several
 * arrays kept under one capacity. */
size_t rl_grow_capacity(size_t cap, size_t count, size_t first);
bool rl_reserve_u32(void **array, uint32_t *cap, uint64_t count, size_t item_size, uint32_t first);
char *rl_strdup(const char *s);

#endif
