/* options.h: the one option store of renderlab. Everything configured with
 * key=value text describes its options with a table of rl_option_info rows
 * (rl_options.h) and keeps their values in an rl_option_store: renderers
 * (src/render/renderer.c), position-dependent properties
 * (src/eval/property.c) and the built-in scenes (src/scene/builtin.c). One
 * definition, so that "threads=x" fails with the same message whoever owns
 * the option, and so that every table prints alike (rl algos, rl scenes).
 *
 * Values are kept as validated text (get() returns exactly what was set, so
 * that options can be listed and reproduced in reports); the typed reads
 * convert text that already passed rl_option_validate() and return zero for
 * a key that is not in the table (which means a wrong key in the caller). */
#ifndef RL_CORE_OPTIONS_H
#define RL_CORE_OPTIONS_H

#include "rl/rl_math.h"
#include "rl/rl_options.h"

/* Message lists ("raster, whitted, ..."): enough room for a few dozen
 * names; longer lists are cut, which only shortens a message. */
#define RL_OPTION_LIST_SIZE 512

/* Appends text to the NUL-terminated buf of size bytes, cutting it short
 * when full. */
void rl_option_append(char *buf, size_t size, const char *text);
/* "did you mean \"NAME\"? " for a suggestion with a name (rl_suggest), else
 * "": the start of an unknown name's message, written into buf. */
const char *rl_option_did_you_mean(const rl_suggestion *s, char *buf, size_t size);
/* "r,g,b" or one grey value, each finite and >= 0 (no error recorded). */
bool rl_option_parse_color(const char *text, rl_vec3 *out);

/* A table's values. Zero-initialised it is empty; init fills the
 * defaults. prefix (may be NULL) is the owner's name: "<prefix>.key" names
 * the same option as "key". The table and prefix are borrowed. */
typedef struct rl_option_store {
    const rl_option_info *options;
    size_t count;
    const char *prefix;
    char **values;                /* one per option, never NULL after init */
    bool *given;                  /* per option: set since init (not only the default) */
} rl_option_store;

rl_status rl_option_store_init(rl_option_store *s, const rl_option_info *options, size_t count,
                               const char *prefix);
void rl_option_store_free(rl_option_store *s);   /* zeroes *s; NULL is a no-op */
/* Index of key (with or without the prefix), or -1. */
long rl_option_store_find(const rl_option_store *s, const char *key);
/* Validates value against key's row, then with check (may be NULL: an
 * owner's extra rule), and stores a copy. Messages start with context.
 * RL_ERR_INVALID_ARG for an unknown key (listing the keys) or a bad value;
 * the old value stays on failure. */
rl_status rl_option_store_set(rl_option_store *s, const char *key, const char *value, const char *context,
                              rl_status (*check)(const char *key, const char *value));
/* Whether key was set since init: for an owner whose default depends on
 * other options (a box's sx defaults to its size). */
bool rl_option_store_given(const rl_option_store *s, const char *key);
/* The value as text; NULL for an unknown key. */
const char *rl_option_store_get(const rl_option_store *s, const char *key);
/* Typed reads (zero, false, "" or black for an unknown key). */
long long rl_option_store_int(const rl_option_store *s, const char *key);
double rl_option_store_float(const rl_option_store *s, const char *key);
bool rl_option_store_bool(const rl_option_store *s, const char *key);
int rl_option_store_enum(const rl_option_store *s, const char *key);     /* choice index */
const char *rl_option_store_string(const rl_option_store *s, const char *key);
rl_vec3 rl_option_store_color(const rl_option_store *s, const char *key);

#endif
