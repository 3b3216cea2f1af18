/* options.c: validation and typed reads of key/value options (options.h).
 * Moved here from renderer.c unchanged in behaviour and wording, so that
 * properties (src/eval/property.c) validate exactly like renderers. */
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

long rl_option_find(const rl_option_info *opts, size_t n, const char *prefix, const char *key)
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

rl_status rl_option_unknown(const rl_option_info *opts, size_t n, const char *context,
                            const char *key)
{
    char keys[RL_OPTION_LIST_SIZE] = "";
    for (size_t k = 0; k < n; ++k) {
        if (k)
            rl_option_append(keys, sizeof keys, ", ");
        rl_option_append(keys, sizeof keys, opts[k].key);
    }
    return rl_error(RL_ERR_INVALID_ARG, "%s: unknown option \"%s\" (options: %s)", context, key,
                    keys);
}

bool rl_option_parse_bool(const char *s, bool *out)
{
    static const char *const yes[] = { "true", "1", "yes", "on" };
    static const char *const no[] = { "false", "0", "no", "off" };
    for (int i = 0; s && i < 4; ++i) {
        if (strcmp(s, yes[i]) == 0) { *out = true; return true; }
        if (strcmp(s, no[i]) == 0) { *out = false; return true; }
    }
    return false;
}

int rl_option_enum_index(const rl_option_info *o, const char *s)
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

rl_status rl_option_validate(const rl_option_info *o, const char *value, const char *context)
{
    const char *name = context ? context : "";
    switch (o->type) {
    case RL_OPT_INT: {
        long long v;
        if (!rl_parse_int(value, &v))
            return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=\"%s\" is not an integer",
                            name, o->key, value);
        if ((double)v < o->min || (double)v > o->max)
            return rl_error(RL_ERR_INVALID_ARG, "%s: option %s=%s is outside [%.17g, %.17g]",
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

long long rl_option_read_int(const char *s)
{
    long long v = 0;
    return s && rl_parse_int(s, &v) ? v : 0;
}

double rl_option_read_float(const char *s)
{
    double v = 0.0;
    return s && rl_parse_float(s, &v) ? v : 0.0;
}

bool rl_option_read_bool(const char *s)
{
    bool v = false;
    return s && rl_option_parse_bool(s, &v) ? v : false;
}

int rl_option_read_enum(const rl_option_info *o, const char *s)
{
    int idx = o ? rl_option_enum_index(o, s) : -1;
    return idx < 0 ? 0 : idx;
}
