/* load_json_read.c: typed reads for the JSON scene loader that report
 * mistakes at file:line:col with what was expected, in the spirit of
 * pbrt-v4's parameter checking, plus the conversion of JSON parameter
 * objects to the "k=v" lists that generators and built-ins read. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "scene/load_json_internal.h"

/* A core call (validator, importer, generator) failed and recorded its own
 * message without a position. Re-record it prefixed with file:line:col of
 * the item that caused it, unless the thread already held an older error
 * (which rl_error keeps). Invalid arguments are the document's fault, so
 * they become RL_ERR_PARSE; I/O and memory problems keep their code. */
rl_status rl_jscene_located(const rl_jscene_ctx *c, const cJSON *item, rl_status st)
{
    if (st == RL_OK || c->had_error)
        return st;
    char msg[1024];
    snprintf(msg, sizeof msg, "%s", rl_last_error());
    rl_clear_error();
    int line = 0, col = 0;
    rl_json_pos(c->doc, item, &line, &col);
    rl_status code = st == RL_ERR_INVALID_ARG || st == RL_ERR_NOT_FOUND ? RL_ERR_PARSE : st;
    return rl_error(code, "%s:%d:%d: %s", c->path, line, col, msg);
}

/* ---- typed reads -------------------------------------------------------- */

rl_status rl_jscene_expect_object(const rl_jscene_ctx *c, const cJSON *item, const char *what)
{
    if (!cJSON_IsObject(item))
        return rl_json_error(c->doc, item, "expected an object for %s", what);
    return RL_OK;
}

/* Object check and unknown keys (repeated keys are refused by the parser). */
rl_status rl_jscene_check_object(const rl_jscene_ctx *c, const cJSON *obj, const char *what,
                                 const char *const *allowed)
{
    rl_status st = rl_jscene_expect_object(c, obj, what);
    if (st == RL_OK)
        st = rl_json_check_keys(c->doc, obj, what, allowed);
    return st;
}

const cJSON *rl_jscene_member(const cJSON *obj, const char *key)
{
    return cJSON_GetObjectItemCaseSensitive(obj, key);
}

rl_status rl_jscene_require(const rl_jscene_ctx *c, const cJSON *obj, const char *key,
                            const char *what, const cJSON **out)
{
    *out = rl_jscene_member(obj, key);
    if (!*out)
        return rl_json_error(c->doc, obj, "missing required key \"%s\" in %s", key, what);
    return RL_OK;
}

/* Optional number in [lo, hi]; *out keeps its default when key is absent. */
rl_status rl_jscene_number(const rl_jscene_ctx *c, const cJSON *obj, const char *key, double lo,
                           double hi, double *out)
{
    const cJSON *item = rl_jscene_member(obj, key);
    if (!item)
        return RL_OK;
    if (!cJSON_IsNumber(item))
        return rl_json_error(c->doc, item, "\"%s\" must be a number", key);
    double v;
    rl_status st = rl_json_number(c->doc, item, &v);
    if (st != RL_OK)
        return st;
    if (!isfinite(v) || v < lo || v > hi) {
        if (isinf(hi))
            return rl_json_error(c->doc, item, "\"%s\" must be a number >= %g", key, lo);
        return rl_json_error(c->doc, item, "\"%s\" must be a number in [%g, %g]", key, lo, hi);
    }
    *out = v;
    return RL_OK;
}

rl_status rl_jscene_float(const rl_jscene_ctx *c, const cJSON *obj, const char *key, double lo,
                          double hi, float *out)
{
    double v = *out;
    rl_status st = rl_jscene_number(c, obj, key, lo, hi, &v);
    if (st == RL_OK)
        *out = (float)v;
    return st;
}

rl_status rl_jscene_read_vec3(const rl_jscene_ctx *c, const cJSON *item, rl_vec3 *out)
{
    float v[3];
    rl_status st = rl_json_vec3(c->doc, item, v);
    if (st != RL_OK)
        return st;
    rl_vec3 r = rl_v3(v[0], v[1], v[2]);
    if (!rl_vfinite(r))
        return rl_json_error(c->doc, item, "expected an array of 3 finite numbers");
    *out = r;
    return RL_OK;
}

/* Optional [x, y, z]; nonzero demands a vector of non-zero length. */
rl_status rl_jscene_vec3(const rl_jscene_ctx *c, const cJSON *obj, const char *key, bool nonzero,
                         rl_vec3 *out)
{
    const cJSON *item = rl_jscene_member(obj, key);
    if (!item)
        return RL_OK;
    rl_vec3 v;
    rl_status st = rl_jscene_read_vec3(c, item, &v);
    if (st != RL_OK)
        return st;
    if (nonzero && !(rl_length2(v) > 0.0f))
        return rl_json_error(c->doc, item, "\"%s\" must not be the zero vector", key);
    *out = v;
    return RL_OK;
}

/* Optional colour: [r, g, b] or one number for grey, never negative. */
rl_status rl_jscene_color(const rl_jscene_ctx *c, const cJSON *obj, const char *key, rl_vec3 *out)
{
    const cJSON *item = rl_jscene_member(obj, key);
    if (!item)
        return RL_OK;
    rl_vec3 v;
    if (cJSON_IsNumber(item)) {
        v = rl_v3s((float)item->valuedouble);
    } else {
        rl_status st = rl_jscene_read_vec3(c, item, &v);
        if (st != RL_OK)
            return st;
    }
    if (!rl_vfinite(v) || v.x < 0.0f || v.y < 0.0f || v.z < 0.0f)
        return rl_json_error(c->doc, item,
                             "\"%s\" must be a colour [r, g, b] or a number, not negative", key);
    *out = v;
    return RL_OK;
}

rl_status rl_jscene_string(const rl_jscene_ctx *c, const cJSON *obj, const char *key,
                           const char **out)
{
    const cJSON *item = rl_jscene_member(obj, key);
    if (!item)
        return RL_OK;
    if (!cJSON_IsString(item) || !item->valuestring)
        return rl_json_error(c->doc, item, "\"%s\" must be a string", key);
    if (item->valuestring[0] == '\0')
        return rl_json_error(c->doc, item, "\"%s\" must not be empty", key);
    *out = item->valuestring;
    return RL_OK;
}

rl_status rl_jscene_expect_array(const rl_jscene_ctx *c, const cJSON *item, const char *what)
{
    if (!cJSON_IsArray(item))
        return rl_json_error(c->doc, item, "expected an array of %s", what);
    return RL_OK;
}

/* ---- key/value parameter objects ---------------------------------------- */

static bool is_plain_token(const char *s)
{
    for (; *s; ++s)
        if (*s == ',' || *s == '=' || *s == ' ' || (*s >= '\t' && *s <= '\r'))
            return false;
    return true;
}

/* Formats a scalar JSON value as the text the params parser reads back. */
rl_status rl_jscene_scalar_text(const rl_jscene_ctx *c, const cJSON *item, char *out,
                                size_t size)
{
    if (cJSON_IsBool(item)) {
        snprintf(out, size, "%s", cJSON_IsTrue(item) ? "true" : "false");
    } else if (cJSON_IsNumber(item)) {
        double v = item->valuedouble;
        if (!isfinite(v))
            return rl_json_error(c->doc, item, "expected a finite number");
        if (v == floor(v) && fabs(v) < 1e15)
            snprintf(out, size, "%.0f", v);
        else
            snprintf(out, size, "%.9g", v);
    } else if (cJSON_IsString(item) && item->valuestring) {
        if (snprintf(out, size, "%s", item->valuestring) >= (int)size)
            return rl_json_error(c->doc, item, "string value too long");
    } else {
        return rl_json_error(c->doc, item, "expected a number, string or bool");
    }
    return RL_OK;
}

/* {"segments": 32, "smooth": true} -> "segments=32,smooth=true" (params.h). */
rl_status rl_jscene_params_text(const rl_jscene_ctx *c, const cJSON *obj, char *out,
                                size_t size)
{
    out[0] = '\0';
    if (cJSON_IsString(obj) && obj->valuestring) {   /* already "k=v,..." */
        if (snprintf(out, size, "%s", obj->valuestring) >= (int)size)
            return rl_json_error(c->doc, obj, "\"params\" too long");
        return RL_OK;
    }
    /* Any key is accepted here: the generator or built-in reports unknown ones. */
    rl_status st = rl_jscene_expect_object(c, obj, "\"params\" (key -> number, string or bool)");
    if (st != RL_OK)
        return st;
    size_t len = 0;
    for (const cJSON *m = obj->child; m; m = m->next) {
        char value[512];
        if ((st = rl_jscene_scalar_text(c, m, value, sizeof value)) != RL_OK)
            return st;
        if (!is_plain_token(m->string) || !is_plain_token(value) || !m->string[0])
            return rl_json_error(c->doc, m,
                                 "parameter keys and values must not contain ',', '=' or spaces");
        int n = snprintf(out + len, size - len, "%s%s=%s", len ? "," : "", m->string, value);
        if (n < 0 || (size_t)n >= size - len)
            return rl_json_error(c->doc, m, "\"params\" too long");
        len += (size_t)n;
    }
    return RL_OK;
}
