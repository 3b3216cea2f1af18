/* options.c: validation, storage and typed reads of key/value options
 * (options.h), the same for renderers, properties and built-in scenes. */
#include "core/options.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/params.h"

void rl_option_append(char *buf, size_t size, const char *text)
{
    size_t used = strlen(buf);
    if (used + 1 < size)
        snprintf(buf + used, size - used, "%s", text);
}

const char *rl_option_did_you_mean(const rl_suggestion *s, char *buf, size_t size)
{
    if (!s->name || size == 0)
        return "";
    snprintf(buf, size, "did you mean \"%s\"? ", s->name);
    return buf;
}

static long rl_option_find(const rl_option_info *opts, size_t n, const char *prefix, const char *key)
{
    if (!key)
        return -1;
    if (prefix) {
        size_t len = strlen(prefix);
        if (strncmp(key, prefix, len) == 0 && key[len] == '.')
            key += len + 1;
    }
    for (size_t i = 0; i < n; ++i)
        if (strcmp(opts[i].key, key) == 0)
            return (long)i;
    return -1;
}

static rl_status rl_option_unknown(const rl_option_info *opts, size_t n, const char *context,
                                   const char *prefix, const char *key)
{
    if (n == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: unknown option \"%s\" (it takes none)", context, key);
    /* "raster.shadng" is a typo of "shading": suggest without the prefix. */
    const char *bare = key;
    size_t len = prefix ? strlen(prefix) : 0;
    if (prefix && strncmp(key, prefix, len) == 0 && key[len] == '.')
        bare = key + len + 1;
    char keys[RL_OPTION_LIST_SIZE] = "", hint[96];
    rl_suggestion sg = { 0 };
    for (size_t k = 0; k < n; ++k) {
        if (k)
            rl_option_append(keys, sizeof keys, ", ");
        rl_option_append(keys, sizeof keys, opts[k].key);
        rl_suggest(&sg, bare, opts[k].key);
    }
    return rl_error(RL_ERR_INVALID_ARG, "%s: unknown option \"%s\" (%soptions: %s)", context, key,
                    rl_option_did_you_mean(&sg, hint, sizeof hint), keys);
}

static bool rl_option_parse_bool(const char *s, bool *out)
{
    static const char *const yes[] = { "true", "1", "yes", "on" };
    static const char *const no[] = { "false", "0", "no", "off" };
    for (int i = 0; s && i < 4; ++i) {
        if (strcmp(s, yes[i]) == 0) { *out = true; return true; }
        if (strcmp(s, no[i]) == 0) { *out = false; return true; }
    }
    return false;
}

static int rl_option_enum_index(const rl_option_info *o, const char *s)
{
    for (int i = 0; s && o->choices && o->choices[i]; ++i)
        if (strcmp(o->choices[i], s) == 0)
            return i;
    return -1;
}

bool rl_option_parse_color(const char *text, rl_vec3 *out)
{
    /* "r,g,b" or one grey value; strtod per component, nothing else allowed. */
    float c[3];
    int n = 0;
    const char *p = text;
    if (!text)
        return false;
    for (;;) {
        char *end;
        double v = strtod(p, &end);
        if (end == p || !(v >= 0.0) || v > 3.4e38 || n == 3)
            return false;
        c[n++] = (float)v;
        while (*end == ' ')
            ++end;
        if (*end == '\0')
            break;
        if (*end != ',')
            return false;
        p = end + 1;
    }
    if (n == 2)
        return false;
    *out = n == 1 ? rl_v3s(c[0]) : rl_v3(c[0], c[1], c[2]);
    return true;
}

static rl_status rl_option_validate(const rl_option_info *o, const char *value, const char *context)
{
    const char *name = context ? context : "";
    switch (o->type) {
    case RL_OPT_INT: {
        long long v;
        if (!rl_parse_int(value, &v))
            return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=\"%s\" is not an integer",
                            name, o->key, value);
        if ((double)v < o->min || (double)v > o->max)
            return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=%s is outside [%.0f, %.0f]",
                            name, o->key, value, o->min, o->max);
        return RL_OK;
    }
    case RL_OPT_FLOAT: {
        double v;
        if (!rl_parse_float(value, &v))
            return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=\"%s\" is not a finite number",
                            name, o->key, value);
        if (v < o->min || v > o->max)
            return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=%s is outside [%g, %g]",
                            name, o->key, value, o->min, o->max);
        return RL_OK;
    }
    case RL_OPT_BOOL: {
        bool b;
        if (!rl_option_parse_bool(value, &b))
            return rl_error(RL_ERR_INVALID_ARG,
                            "%s: option %s=\"%s\" is not a boolean (true/false, 1/0, yes/no, on/off)",
                            name, o->key, value);
        return RL_OK;
    }
    case RL_OPT_ENUM: {
        if (rl_option_enum_index(o, value) >= 0)
            return RL_OK;
        char list[RL_OPTION_LIST_SIZE] = "";
        for (int i = 0; o->choices && o->choices[i]; ++i) {
            if (i)
                rl_option_append(list, sizeof list, ", ");
            rl_option_append(list, sizeof list, o->choices[i]);
        }
        return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=\"%s\" is not one of %s",
                        name, o->key, value, list);
    }
    case RL_OPT_STRING:
        return RL_OK;
    case RL_OPT_COLOR: {
        rl_vec3 c;
        if (rl_option_parse_color(value, &c))
            return RL_OK;
        return rl_error(RL_ERR_INVALID_ARG,
                        "%s: option %s=\"%s\" is not a colour (\"r,g,b\" or one value, >= 0)",
                        name, o->key, value);
    }
    }
    return rl_error(RL_ERR_INTERNAL, "%s: option %s has an unknown type", name, o->key);
}

static long long rl_option_read_int(const char *s)
{
    long long v = 0;
    return s && rl_parse_int(s, &v) ? v : 0;
}

static double rl_option_read_float(const char *s)
{
    double v = 0.0;
    return s && rl_parse_float(s, &v) ? v : 0.0;
}

static bool rl_option_read_bool(const char *s)
{
    bool v = false;
    return s && rl_option_parse_bool(s, &v) ? v : false;
}

static int rl_option_read_enum(const rl_option_info *o, const char *s)
{
    int idx = o ? rl_option_enum_index(o, s) : -1;
    return idx < 0 ? 0 : idx;
}

static void free_values(char **values, size_t n)
{
    for (size_t i = 0; values && i < n; ++i)
        free(values[i]);
    free(values);
}

rl_status rl_option_store_init(rl_option_store *s, const rl_option_info *options, size_t count,
                               const char *prefix)
{
    memset(s, 0, sizeof *s);
    char **values = rl_calloc(count ? count : 1, sizeof *values);
    bool *given = rl_calloc(count ? count : 1, sizeof *given);
    if (!values || !given) {
        free(values);
        free(given);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < count; ++i) {
        const char *def = options[i].default_value;
        if (!(values[i] = rl_strdup(def ? def : ""))) {
            free_values(values, count);
            free(given);
            return RL_ERR_OUT_OF_MEMORY;
        }
    }
    *s = (rl_option_store){ .options = options, .count = count, .prefix = prefix, .values = values,
                            .given = given };
    return RL_OK;
}

void rl_option_store_free(rl_option_store *s)
{
    if (!s)
        return;
    free_values(s->values, s->count);
    free(s->given);
    memset(s, 0, sizeof *s);
}

long rl_option_store_find(const rl_option_store *s, const char *key)
{
    return s && s->values ? rl_option_find(s->options, s->count, s->prefix, key) : -1;
}

rl_status rl_option_store_set(rl_option_store *s, const char *key, const char *value, const char *context,
                              rl_status (*check)(const char *key, const char *value))
{
    long i = rl_option_store_find(s, key);
    if (i < 0)
        return rl_option_unknown(s->options, s->count, context, s->prefix, key);
    const rl_option_info *o = &s->options[i];
    rl_status st = rl_option_validate(o, value, context);
    if (st == RL_OK && check)
        st = check(o->key, value);
    if (st != RL_OK)
        return st;
    char *copy = rl_strdup(value);
    if (!copy)
        return RL_ERR_OUT_OF_MEMORY;
    free(s->values[i]);
    s->values[i] = copy;
    s->given[i] = true;
    return RL_OK;
}

bool rl_option_store_given(const rl_option_store *s, const char *key)
{
    long i = rl_option_store_find(s, key);
    return i >= 0 && s->given[i];
}

const char *rl_option_store_get(const rl_option_store *s, const char *key)
{
    long i = rl_option_store_find(s, key);
    return i < 0 ? NULL : s->values[i];
}

long long rl_option_store_int(const rl_option_store *s, const char *key)
{
    return rl_option_read_int(rl_option_store_get(s, key));
}

double rl_option_store_float(const rl_option_store *s, const char *key)
{
    return rl_option_read_float(rl_option_store_get(s, key));
}

bool rl_option_store_bool(const rl_option_store *s, const char *key)
{
    return rl_option_read_bool(rl_option_store_get(s, key));
}

int rl_option_store_enum(const rl_option_store *s, const char *key)
{
    long i = rl_option_store_find(s, key);
    return i < 0 ? 0 : rl_option_read_enum(&s->options[i], s->values[i]);
}

const char *rl_option_store_string(const rl_option_store *s, const char *key)
{
    const char *v = rl_option_store_get(s, key);
    return v ? v : "";
}

rl_vec3 rl_option_store_color(const rl_option_store *s, const char *key)
{
    rl_vec3 c = rl_v3s(0.0f);
    rl_option_parse_color(rl_option_store_get(s, key), &c);
    return c;
}
