/* params.h: "key=value" parameter lists with typed, validated lookups.
 *
 * Used for built-in scene and generator parameters, renderer options and the
 * CLI's --set. Unknown keys are errors: after reading every key it knows, a
 * consumer calls rl_params_check_unused(), which fails naming the first key
 * nobody asked for and the accepted ones. */
#ifndef RL_CORE_PARAMS_H
#define RL_CORE_PARAMS_H

#include "rl/rl_options.h"   /* rl_parse_int, rl_parse_float */

typedef struct rl_param { char *key, *value; bool used; } rl_param;
typedef struct rl_params { rl_param *items; uint32_t count; } rl_params;

/* Parses "a=1,b=x" (commas or whitespace separate; NULL or "" is empty).
 * RL_ERR_INVALID_ARG for an item without '=' or an empty key; a repeated key
 * keeps the last value. */
rl_status rl_params_parse(const char *text, rl_params *out);
/* Adds or replaces one key. */
rl_status rl_params_set(rl_params *p, const char *key, const char *value);
void rl_params_free(rl_params *p);
/* Value or NULL; marks the key used. */
const char *rl_params_get(rl_params *p, const char *key);

/* Typed lookups: if the key is absent, *out keeps its value (the default) and
 * RL_OK is returned; a malformed or out-of-range value is RL_ERR_INVALID_ARG
 * with a message naming context, key, value and the accepted range. */
rl_status rl_params_int(rl_params *p, const char *context, const char *key,
                        long long min, long long max, long long *out);
rl_status rl_params_float(rl_params *p, const char *context, const char *key,
                          double min, double max, double *out);
rl_status rl_params_bool(rl_params *p, const char *context, const char *key, bool *out);
/* choices: NULL-terminated; *out = index of the matching choice. */
rl_status rl_params_enum(rl_params *p, const char *context, const char *key,
                         const char *const *choices, int *out);

/* RL_ERR_INVALID_ARG naming the first unused key and listing `accepted`
 * (a human-readable list such as "triangles, seed"). */
rl_status rl_params_check_unused(const rl_params *p, const char *context, const char *accepted);

#endif
