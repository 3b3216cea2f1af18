/* json_scan.h: strict JSON scanner behind rl_json_parse() (json.c). */
#ifndef RL_CORE_JSON_SCAN_H
#define RL_CORE_JSON_SCAN_H

#include <cjson/cJSON.h>
#include "rl/rl_common.h"

/* Where one cJSON item starts in the text (1-based). */
typedef struct rl_json_pos_entry { const cJSON *item; int line, col; } rl_json_pos_entry;

typedef struct rl_json_scan_result {
    size_t err_offset;          /* RL_ERR_PARSE: byte offset of the problem */
    char message[256];          /* RL_ERR_PARSE: what was expected, in words */
    rl_json_pos_entry *pos;     /* RL_OK with a root: one entry per item, text order */
    size_t npos;
} rl_json_scan_result;

/* Checks text against RFC 8259 and, when root is the cJSON tree parsed from
 * the same text, records where each of its items starts. Returns RL_OK,
 * RL_ERR_PARSE (err_offset/message filled, no rl_error recorded),
 * RL_ERR_INTERNAL when root does not mirror the text, or
 * RL_ERR_OUT_OF_MEMORY. res->pos is malloc'd and owned by the caller. */
rl_status rl_json_scan(const char *text, size_t len, const cJSON *root, rl_json_scan_result *res);
/* 1-based line and byte column of offset in text. */
void rl_json_line_col(const char *text, size_t len, size_t offset, int *line, int *col);

#endif
