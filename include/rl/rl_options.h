/* rl_options.h: typed key/value option tables and strict number parsing.
 *
 * Everything in renderlab that is configured with "key=value" text (the
 * renderers of rl_render.h, the properties of rl_property.h) describes its
 * options with one table of rl_option_info rows: key, type, default, help
 * and, for numbers, the accepted range. Values are checked against the row
 * when set, and the same rows print the help of `rl algos`. This header is
 * part of the core layer: it knows nothing of scenes or renderers. */
#ifndef RL_OPTIONS_H
#define RL_OPTIONS_H

#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rl_option_type {
    RL_OPT_INT, RL_OPT_FLOAT, RL_OPT_BOOL, RL_OPT_ENUM, RL_OPT_STRING,
    RL_OPT_COLOR                          /* "r,g,b" or one grey value, finite, >= 0 */
} rl_option_type;

typedef struct rl_option_info {
    const char *key;
    rl_option_type type;
    const char *default_value;
    const char *help;
    double min, max;                      /* RL_OPT_INT / RL_OPT_FLOAT range */
    const char *const *choices;           /* RL_OPT_ENUM: NULL-terminated */
} rl_option_info;

/* Strict text -> number conversions: the whole string must be one finite
 * number (an int for rl_parse_int); false otherwise, *out untouched. */
RL_API bool rl_parse_int(const char *s, long long *out);
RL_API bool rl_parse_float(const char *s, double *out);

#ifdef __cplusplus
}
#endif
#endif
