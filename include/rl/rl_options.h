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

/* "Did you mean": the known name closest to what was typed. Zero-initialise
 * an rl_suggestion, offer it every known name with rl_suggest(), then read
 * .name: NULL when none is a likely typo. Likely means at most 1 edit for a
 * name of up to 4 characters and 2 for a longer one (Levenshtein: insert,
 * delete or replace a character; ASCII case ignored); the first of equally
 * close names wins. Names are borrowed, not copied. */
typedef struct rl_suggestion {
    const char *name;                     /* best so far, or NULL */
    int distance;
} rl_suggestion;
RL_API void rl_suggest(rl_suggestion *s, const char *typed, const char *known);
/* Edit distance of a and b as above, counted up to limit (a larger
 * distance returns limit + 1). */
RL_API int rl_edit_distance(const char *a, const char *b, int limit);

#ifdef __cplusplus
}
#endif
#endif
