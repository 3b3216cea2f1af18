/* json.c: cJSON documents with source positions (json.h).
 *
 * cJSON builds the tree; json_scan.c checks the text strictly, explains
 * syntax errors in words and records where every item starts. The position
 * table is sorted by item address so rl_json_pos() is a binary search.
 * Duplicate keys are rejected: cJSON would keep both and lookups would see
 * only the first, which silently ignores the user's later value. */
#include "core/json.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/json_scan.h"
#include "rl/rl_output.h"

/* Scene and result files are small; this only stops runaway inputs. */
#define JSON_MAX_FILE_BYTES ((size_t)1 << 30)

struct rl_json_doc {
    char *name;
    cJSON *root;
    rl_json_pos_entry *pos;   /* sorted by item address */
    size_t npos;
};

static int cmp_pos(const void *a, const void *b)
{
    uintptr_t x = (uintptr_t)((const rl_json_pos_entry *)a)->item;
    uintptr_t y = (uintptr_t)((const rl_json_pos_entry *)b)->item;
    return x < y ? -1 : (x > y);
}

void rl_json_free(rl_json_doc *doc)
{
    if (!doc)
        return;
    cJSON_Delete(doc->root);
    free(doc->pos);
    free(doc->name);
    free(doc);
}

cJSON *rl_json_root(const rl_json_doc *doc) { return doc ? doc->root : NULL; }
const char *rl_json_name(const rl_json_doc *doc) { return doc ? doc->name : ""; }

void rl_json_pos(const rl_json_doc *doc, const cJSON *item, int *line, int *col)
{
    int l = 0, c = 0;
    if (doc && item && doc->npos) {
        rl_json_pos_entry key = { item, 0, 0 };
        const rl_json_pos_entry *e = bsearch(&key, doc->pos, doc->npos, sizeof key, cmp_pos);
        if (e) {
            l = e->line;
            c = e->col;
        }
    }
    if (line)
        *line = l;
    if (col)
        *col = c;
}

rl_status rl_json_error(const rl_json_doc *doc, const cJSON *item, const char *fmt, ...)
{
    char msg[768];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int line, col;
    rl_json_pos(doc, item, &line, &col);
    if (line > 0)
        return rl_error(RL_ERR_PARSE, "%s:%d:%d: %s", rl_json_name(doc), line, col, msg);
    return rl_error(RL_ERR_PARSE, "%s: %s", rl_json_name(doc), msg);
}

typedef struct member { const char *key; int index; const cJSON *item; } member;

static int cmp_member(const void *a, const void *b)
{
    const member *x = a, *y = b;
    int c = strcmp(x->key, y->key);
    return c ? c : (x->index > y->index) - (x->index < y->index);
}

/* Finds a repeated key anywhere below item; reports the later occurrence. */
static rl_status check_duplicates(const rl_json_doc *doc, const cJSON *item)
{
    int n = 0;
    for (const cJSON *c = item->child; c; c = c->next)
        ++n;
    if (cJSON_IsObject(item) && n > 1) {
        member *m = rl_calloc((size_t)n, sizeof *m);
        if (!m)
            return RL_ERR_OUT_OF_MEMORY;
        int k = 0;
        for (const cJSON *c = item->child; c; c = c->next, ++k)
            m[k] = (member){ c->string ? c->string : "", k, c };
        qsort(m, (size_t)n, sizeof *m, cmp_member);
        for (k = 1; k < n; ++k)
            if (strcmp(m[k - 1].key, m[k].key) == 0) {
                int line, col;
                rl_json_pos(doc, m[k - 1].item, &line, &col);
                rl_status st = rl_json_error(doc, m[k].item,
                                             "duplicate key \"%s\" (first defined at %d:%d)",
                                             m[k].key, line, col);
                free(m);
                return st;
            }
        free(m);
    }
    for (const cJSON *c = item->child; c; c = c->next) {
        rl_status st = check_duplicates(doc, c);
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

rl_status rl_json_parse(const char *name, const char *text, size_t len, rl_json_doc **out)
{
    if (!out || (!text && len))
        return rl_error(RL_ERR_INVALID_ARG, "rl_json_parse: text or out is NULL");
    name = name ? name : "<json>";
    /* cJSON wants a terminated buffer even with an explicit length. */
    char *buf = rl_alloc(len + 1);
    rl_json_doc *doc = rl_calloc(1, sizeof *doc);
    if (doc)
        doc->name = rl_strdup(name);
    if (!buf || !doc || !doc->name) {
        free(buf);
        rl_json_free(doc);
        return RL_ERR_OUT_OF_MEMORY;
    }
    if (len)
        memcpy(buf, text, len);
    buf[len] = '\0';
    size_t bom = len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
    const char *end = NULL;
    doc->root = cJSON_ParseWithLengthOpts(buf + bom, len - bom, &end, 0);
    rl_json_scan_result res;
    rl_status st = rl_json_scan(buf, len, doc->root, &res);
    int line, col;
    if (st == RL_ERR_PARSE) {
        rl_json_line_col(buf, len, res.err_offset, &line, &col);
        st = rl_error(RL_ERR_PARSE, "%s:%d:%d: %s", name, line, col, res.message);
    } else if (st == RL_OK && !doc->root) {
        /* Valid JSON that cJSON still refused: out of memory or one of its
         * own limits (e.g. numbers longer than 63 characters). */
        size_t at = end && end >= buf && end <= buf + len ? (size_t)(end - buf) : 0;
        rl_json_line_col(buf, len, at, &line, &col);
        st = rl_error(RL_ERR_PARSE, "%s:%d:%d: cannot parse this value (too long or out of memory)",
                      name, line, col);
    } else if (st == RL_ERR_INTERNAL) {
        st = rl_error(RL_ERR_INTERNAL, "%s: JSON scanner and cJSON disagree", name);
    }
    free(buf);
    if (st != RL_OK) {
        free(res.pos);
        rl_json_free(doc);
        return st;
    }
    doc->pos = res.pos;
    doc->npos = res.npos;
    qsort(doc->pos, doc->npos, sizeof *doc->pos, cmp_pos);
    if ((st = check_duplicates(doc, doc->root)) != RL_OK) {
        rl_json_free(doc);
        return st;
    }
    *out = doc;
    return RL_OK;
}

rl_status rl_json_parse_file(const char *path, rl_json_doc **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_json_parse_file: path or out is NULL");
    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* Read in growing chunks so that pipes and /dev/stdin work too. */
    size_t cap = 1 << 16, n = 0;
    char *data = rl_alloc(cap);
    rl_status st = data ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    while (st == RL_OK) {
        if (n == cap) {
            if (cap >= JSON_MAX_FILE_BYTES) {
                st = rl_error(RL_ERR_LIMIT, "%s: JSON file larger than %zu bytes", path,
                              JSON_MAX_FILE_BYTES);
                break;
            }
            char *bigger = rl_realloc_array(data, cap * 2, 1);
            if (!bigger) {
                st = RL_ERR_OUT_OF_MEMORY;
                break;
            }
            data = bigger;
            cap *= 2;
        }
        size_t got = fread(data + n, 1, cap - n, f);
        n += got;
        if (got == 0) {
            if (ferror(f))
                st = rl_error(RL_ERR_IO, "%s: read error: %s", path, strerror(errno));
            break;
        }
    }
    fclose(f);
    if (st == RL_OK)
        st = rl_json_parse(path, data, n, out);
    free(data);
    return st;
}

rl_status rl_json_number(const rl_json_doc *doc, const cJSON *item, double *out)
{
    if (!cJSON_IsNumber(item) || !isfinite(item->valuedouble))
        return rl_json_error(doc, item, "expected a finite number");
    *out = item->valuedouble;
    return RL_OK;
}

rl_status rl_json_vec3(const rl_json_doc *doc, const cJSON *item, float out[3])
{
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 3)
        return rl_json_error(doc, item, "expected an array of 3 numbers");
    float v[3];
    int k = 0;
    for (const cJSON *c = item->child; c; c = c->next, ++k) {
        if (!cJSON_IsNumber(c) || !isfinite(c->valuedouble) || !isfinite((float)c->valuedouble))
            return rl_json_error(doc, c, "expected a finite number in this 3-vector");
        v[k] = (float)c->valuedouble;
    }
    memcpy(out, v, sizeof v);
    return RL_OK;
}

rl_status rl_json_check_keys(const rl_json_doc *doc, const cJSON *object, const char *what,
                             const char *const *allowed)
{
    what = what ? what : "object";
    if (!cJSON_IsObject(object))
        return rl_json_error(doc, object, "expected an object for %s", what);
    for (const cJSON *c = object->child; c; c = c->next) {
        bool ok = false;
        for (int k = 0; allowed && allowed[k] && !ok; ++k)
            ok = strcmp(c->string, allowed[k]) == 0;
        if (ok)
            continue;
        char list[512] = "";
        size_t n = 0;
        for (int k = 0; allowed && allowed[k] && n < sizeof list; ++k)
            n += (size_t)snprintf(list + n, sizeof list - n, "%s%s", k ? ", " : "", allowed[k]);
        return rl_json_error(doc, c, "unknown key \"%s\" in %s (expected one of: %s)", c->string,
                             what, n ? list : "no keys");
    }
    return RL_OK;
}

rl_status rl_json_write_file(const cJSON *item, const char *path)
{
    if (!item || !path)
        return rl_error(RL_ERR_INVALID_ARG, "rl_json_write_file: item or path is NULL");
    char *text = cJSON_Print(item);
    if (!text)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: cannot serialise JSON", path);
    rl_output *o = NULL;
    rl_status st = rl_output_open(path, &o);
    if (st == RL_OK) {
        FILE *f = rl_output_file(o);
        fputs(text, f);
        fputc('\n', f);
        st = rl_output_commit(o);
    }
    cJSON_free(text);
    return st;
}
