/* params.h: "key=value" lists as text, e.g. a built-in scene's "blocks=8,
 * seed=2" or a renderer recipe's options. Only the list: what the keys mean,
 * their types, ranges and defaults are an option table's, and the values
 * are checked and kept in an rl_option_store (options.h). */
#ifndef RL_CORE_PARAMS_H
#define RL_CORE_PARAMS_H

#include "rl/rl_options.h"   /* rl_parse_int, rl_parse_float */

typedef struct rl_param { char *key, *value; } rl_param;
typedef struct rl_params { rl_param *items; uint32_t count; } rl_params;

/* Parses "a=1,b=x" (commas or whitespace separate; NULL or "" is empty).
 * RL_ERR_INVALID_ARG for an item without '=' or an empty key; a repeated key
 * keeps the last value. */
rl_status rl_params_parse(const char *text, rl_params *out);
/* Adds or replaces one key. */
rl_status rl_params_set(rl_params *p, const char *key, const char *value);
void rl_params_free(rl_params *p);
/* Value or NULL. */
const char *rl_params_get(rl_params *p, const char *key);

#endif
