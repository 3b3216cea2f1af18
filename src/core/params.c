/* params.c: "key=value" lists (params.h) and the strict number parsing of
 * rl_options.h. Unknown keys become errors where the list meets its option
 * table (rl_option_store_set), not here. */
#define _POSIX_C_SOURCE 200809L
#include "core/params.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "core/error.h"

static rl_param *find(const rl_params *p, const char *key)
{
    for (uint32_t i = 0; i < p->count; ++i)
        if (strcmp(p->items[i].key, key) == 0)
            return &p->items[i];
    return NULL;
}

/* Adds or replaces; takes ownership of key and value on success. */
static rl_status set_owned(rl_params *p, char *key, char *value)
{
    rl_param *it = find(p, key);
    if (it) {
        free(it->value);
        free(key);
        it->value = value;
        return RL_OK;
    }
    rl_param *items = rl_realloc_array(p->items, (size_t)p->count + 1, sizeof *items);
    if (!items)
        return RL_ERR_OUT_OF_MEMORY;
    p->items = items;
    p->items[p->count++] = (rl_param){ key, value };
    return RL_OK;
}

rl_status rl_params_set(rl_params *p, const char *key, const char *value)
{
    if (!p || !key || !value)
        return rl_error(RL_ERR_INVALID_ARG, "rl_params_set: NULL argument");
    if (!*key)
        return rl_error(RL_ERR_INVALID_ARG, "rl_params_set: empty key");
    char *k = rl_strdup(key), *v = rl_strdup(value);
    rl_status st = k && v ? set_owned(p, k, v) : RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        free(k);
        free(v);
    }
    return st;
}

static char *dup_range(const char *s, size_t n)
{
    char *d = rl_alloc(n + 1);
    if (d) {
        memcpy(d, s, n);
        d[n] = '\0';
    }
    return d;
}

static bool is_separator(char c) { return c == ',' || isspace((unsigned char)c); }

rl_status rl_params_parse(const char *text, rl_params *out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_params_parse: out is NULL");
    /* Build into a local list so that *out is untouched on failure. */
    rl_params p = { NULL, 0 };
    const char *s = text ? text : "";
    while (*s) {
        while (*s && is_separator(*s))
            ++s;
        if (!*s)
            break;
        const char *start = s;
        while (*s && !is_separator(*s))
            ++s;
        size_t len = (size_t)(s - start);
        const char *eq = memchr(start, '=', len);
        if (!eq || eq == start) {
            rl_params_free(&p);
            return rl_error(RL_ERR_INVALID_ARG, "parameter \"%.*s\": %s", (int)len, start,
                            eq ? "empty key" : "expected key=value");
        }
        char *k = dup_range(start, (size_t)(eq - start));
        char *v = dup_range(eq + 1, (size_t)(s - eq - 1));
        rl_status st = k && v ? set_owned(&p, k, v) : RL_ERR_OUT_OF_MEMORY;
        if (st != RL_OK) {
            free(k);
            free(v);
            rl_params_free(&p);
            return st;
        }
    }
    *out = p;
    return RL_OK;
}

void rl_params_free(rl_params *p)
{
    if (!p)
        return;
    for (uint32_t i = 0; i < p->count; ++i) {
        free(p->items[i].key);
        free(p->items[i].value);
    }
    free(p->items);
    p->items = NULL;
    p->count = 0;
}

const char *rl_params_get(rl_params *p, const char *key)
{
    rl_param *it = p && key ? find(p, key) : NULL;
    return it ? it->value : NULL;
}

bool rl_parse_int(const char *s, long long *out)
{
    if (!s || !*s || isspace((unsigned char)*s))
        return false;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (errno == ERANGE || *end != '\0')
        return false;
    *out = v;
    return true;
}

bool rl_parse_float(const char *s, double *out)
{
    if (!s || !*s || isspace((unsigned char)*s))
        return false;
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    /* ERANGE on underflow still yields a usable (tiny) value; overflow,
     * inf and nan are refused by the finiteness test. */
    if (*end != '\0' || !isfinite(v))
        return false;
    *out = v;
    return true;
}
