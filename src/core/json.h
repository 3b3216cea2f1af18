/* json.h: cJSON with source positions, for scene files and result files.
 *
 * cJSON itself keeps no positions. The document keeps its text, and
 * rl_json_pos() walks it in the same order as cJSON's tree to find the
 * line and column where a value (or an object member's key) starts, so
 * that semantic errors ("unknown key", "expected a number") can point at
 * file:line:col like syntax errors do. Files and texts above
 * rl_json_max_bytes(), or with more values than it allows, are
 * RL_ERR_LIMIT (rl_common.h). */
#ifndef RL_CORE_JSON_H
#define RL_CORE_JSON_H

#include <cjson/cJSON.h>
#include "rl/rl_common.h"

typedef struct rl_json_doc rl_json_doc;

/* Parses text (len bytes, need not be NUL-terminated). name is used in
 * messages (usually the path). Syntax errors are RL_ERR_PARSE with
 * "name:line:col: <what was expected>". */
rl_status rl_json_parse(const char *name, const char *text, size_t len, rl_json_doc **out);
/* Reads and parses a file; RL_ERR_IO "path: cannot open: <reason>". */
rl_status rl_json_parse_file(const char *path, rl_json_doc **out);
void rl_json_free(rl_json_doc *doc);
cJSON *rl_json_root(const rl_json_doc *doc);
const char *rl_json_name(const rl_json_doc *doc);
/* 1-based line/column where item starts (for object members: the key);
 * 0/0 if item is not part of doc. Scans the text up to item: for messages,
 * not for loops. */
void rl_json_pos(const rl_json_doc *doc, const cJSON *item, int *line, int *col);
/* Records RL_ERR_PARSE with "name:line:col: " + message at item; returns it. */
rl_status rl_json_error(const rl_json_doc *doc, const cJSON *item, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;

/* Typed reads that report with position on mismatch (RL_ERR_PARSE). */
rl_status rl_json_number(const rl_json_doc *doc, const cJSON *item, double *out);
rl_status rl_json_vec3(const rl_json_doc *doc, const cJSON *item, float out[3]);
/* Checks that every member of object is in the NULL-terminated list allowed;
 * otherwise "name:line:col: unknown key \"k\" in <what> (expected one of: ...)". */
rl_status rl_json_check_keys(const rl_json_doc *doc, const cJSON *object, const char *what,
                             const char *const *allowed);

/* Writing result files: serialises item (pretty) to path; RL_ERR_IO on failure. */
rl_status rl_json_write_file(const cJSON *item, const char *path);

#endif
