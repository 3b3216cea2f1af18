/* json_scan.h: strict JSON scanner behind rl_json_parse() (json.c). */
#ifndef RL_CORE_JSON_SCAN_H
#define RL_CORE_JSON_SCAN_H

#include <cjson/cJSON.h>
#include "rl/rl_common.h"

typedef struct rl_json_scan_result {
    size_t err_offset;          /* RL_ERR_PARSE: byte offset of the problem */
    char message[256];          /* RL_ERR_PARSE: what was expected, in words */
    size_t values;              /* RL_OK: how many values (cJSON items) the text holds */
    bool found;                 /* with a target: whether it was met */
    int line, col;              /* where the target starts (for object members: the key) */
} rl_json_scan_result;

/* Checks text against RFC 8259 and counts its values. With root, the cJSON
 * tree parsed from the same text, and target, an item of it, also finds
 * where target starts: positions are looked up only when a message needs
 * one, so a document costs no memory per value beyond cJSON's own.
 * Returns RL_OK, RL_ERR_PARSE (err_offset/message filled, no rl_error
 * recorded) or RL_ERR_INTERNAL when root does not mirror the text. */
rl_status rl_json_scan(const char *text, size_t len, const cJSON *root, const cJSON *target,
                       rl_json_scan_result *res);
/* 1-based line and byte column of offset in text. */
void rl_json_line_col(const char *text, size_t len, size_t offset, int *line, int *col);

#endif
