/* options.h: typed option tables (rl_option_info, rl_options.h) checked and
 * read as text, shared by everything configured with key/value options:
 * renderers (src/render/renderer.c) and position-dependent properties
 * (src/eval/property.c). One definition, so that "threads=x" fails with the
 * same message whoever owns the option.
 *
 * Values are kept as validated text by the owner; the readers here convert
 * text that already passed rl_option_validate() and return zero for text
 * that does not parse (which then means a wrong key in the caller). */
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
/* Index of key in opts[0..n), or -1; key may carry "<prefix>." in front
 * (prefix may be NULL). */
long rl_option_find(const rl_option_info *opts, size_t n, const char *prefix, const char *key);
/* Records and returns RL_ERR_INVALID_ARG "<context>: unknown option
 * \"key\" (options: a, b, ...)". */
rl_status rl_option_unknown(const rl_option_info *opts, size_t n, const char *context,
                            const char *key);
/* Checks value against o's type and range; records a message naming
 * context, key and value and returns RL_ERR_INVALID_ARG on failure. */
rl_status rl_option_validate(const rl_option_info *o, const char *value, const char *context);

/* Parsers (no error recorded). */
bool rl_option_parse_bool(const char *s, bool *out);   /* true/false, 1/0, yes/no, on/off */
int rl_option_enum_index(const rl_option_info *o, const char *s);  /* -1 if not a choice */
/* "r,g,b" or one grey value, each finite and >= 0. */
bool rl_option_parse_color(const char *text, rl_vec3 *out);

/* Readers of validated text (zero / false / black when it does not parse). */
long long rl_option_read_int(const char *s);
double rl_option_read_float(const char *s);
bool rl_option_read_bool(const char *s);
int rl_option_read_enum(const rl_option_info *o, const char *s);   /* 0 if not a choice */

#endif
