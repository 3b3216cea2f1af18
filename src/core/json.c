/* json.c: cJSON documents with source positions (json.h).
 *
 * json_scan.c first checks the text strictly, explains syntax errors in
 * words and counts the values, so that a file of too many values is
 * refused before cJSON allocates about 80 bytes for each; then cJSON
 * builds the tree. The document keeps its text, and rl_json_pos() scans
 * it again to find an item: positions are wanted only for messages, and
 * a table of them cost 16 bytes per value, 8 times the text of "0,".
 * Duplicate keys are rejected: cJSON would keep both and lookups would see
 * only the first, which silently ignores the user's later value. */
#define _POSIX_C_SOURCE 200809L
#include "core/json.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "core/json_scan.h"
#include "rl/rl_output.h"

/* Bytes of the limit per value allowed: 16 M values under the default
 * 256 MiB, whose tree takes about 1.3 GB. */
#define BYTES_PER_VALUE 16u

static unsigned long long max_bytes = RL_JSON_MAX_BYTES;

void rl_json_set_max_bytes(unsigned long long bytes) { max_bytes = bytes ? bytes : RL_JSON_MAX_BYTES; }
unsigned long long rl_json_max_bytes(void) { return max_bytes; }

struct rl_json_doc {
    char *name;
    cJSON *root;
    char *text;                 /* NUL-terminated; for rl_json_pos */
    size_t len;
};

void rl_json_free(rl_json_doc *doc)
{
    if (!doc)
        return;
    cJSON_Delete(doc->root);
    free(doc->text);
    free(doc->name);
    free(doc);
}

cJSON *rl_json_root(const rl_json_doc *doc) { return doc ? doc->root : NULL; }
const char *rl_json_name(const rl_json_doc *doc) { return doc ? doc->name : ""; }

void rl_json_pos(const rl_json_doc *doc, const cJSON *item, int *line, int *col)
{
    int l = 0, c = 0;
    rl_json_scan_result res;
    if (doc && item && doc->text && rl_json_scan(doc->text, doc->len, doc->root, item, &res) == RL_OK &&
        res.found) {
        l = res.line;
        c = res.col;
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

static rl_status too_large(const char *name, size_t len)
{
    return rl_error(RL_ERR_LIMIT, "%s: %zu bytes of JSON, more than the limit of %llu (rl_json_set_max_bytes)",
                    name, len, max_bytes);
}

/* Parses buf (len bytes and a NUL after them), which the document takes
 * over, also on failure. */
static rl_status parse_owned(const char *name, char *buf, size_t len, rl_json_doc **out)
{
    if (len > max_bytes) {
        free(buf);
        return too_large(name, len);
    }
    rl_json_doc *doc = rl_calloc(1, sizeof *doc);
    if (doc)
        doc->name = rl_strdup(name);
    if (!doc || !doc->name) {
        free(buf);
        rl_json_free(doc);
        return RL_ERR_OUT_OF_MEMORY;
    }
    doc->text = buf;
    doc->len = len;
    rl_json_scan_result res;
    rl_status st = rl_json_scan(buf, len, NULL, NULL, &res);
    int line, col;
    if (st == RL_ERR_PARSE) {
        rl_json_line_col(buf, len, res.err_offset, &line, &col);
        st = rl_error(RL_ERR_PARSE, "%s:%d:%d: %s", name, line, col, res.message);
    } else if (res.values > max_bytes / BYTES_PER_VALUE) {
        st = rl_error(RL_ERR_LIMIT, "%s: %zu JSON values, more than the limit of %llu (one per %u bytes of "
                      "rl_json_set_max_bytes)", name, res.values, max_bytes / BYTES_PER_VALUE, BYTES_PER_VALUE);
    }
    if (st == RL_OK) {
        size_t bom = len >= 3 && memcmp(buf, "\xEF\xBB\xBF", 3) == 0 ? 3 : 0;
        const char *end = NULL;
        doc->root = cJSON_ParseWithLengthOpts(buf + bom, len - bom, &end, 0);
        if (!doc->root) {
            /* Valid JSON that cJSON still refused: out of memory or one of
             * its own limits (e.g. numbers longer than 63 characters). */
            size_t at = end && end >= buf && end <= buf + len ? (size_t)(end - buf) : 0;
            rl_json_line_col(buf, len, at, &line, &col);
            st = rl_error(RL_ERR_PARSE, "%s:%d:%d: cannot parse this value (too long or out of memory)",
                          name, line, col);
        } else if (rl_json_scan(buf, len, doc->root, NULL, &res) != RL_OK) {
            st = rl_error(RL_ERR_INTERNAL, "%s: JSON scanner and cJSON disagree", name);
        }
    }
    if (st == RL_OK)
        st = check_duplicates(doc, doc->root);
    if (st != RL_OK) {
        rl_json_free(doc);
        return st;
    }
    *out = doc;
    return RL_OK;
}

rl_status rl_json_parse(const char *name, const char *text, size_t len, rl_json_doc **out)
{
    if (!out || (!text && len))
        return rl_error(RL_ERR_INVALID_ARG, "rl_json_parse: text or out is NULL");
    name = name ? name : "<json>";
    if (len > max_bytes)
        return too_large(name, len);
    /* cJSON wants a terminated buffer even with an explicit length. */
    char *buf = rl_alloc(len + 1);
    if (!buf)
        return RL_ERR_OUT_OF_MEMORY;
    if (len)
        memcpy(buf, text, len);
    buf[len] = '\0';
    return parse_owned(name, buf, len, out);
}

rl_status rl_json_parse_file(const char *path, rl_json_doc **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_json_parse_file: path or out is NULL");
    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* A regular file is read into a buffer of its size (and the NUL) and
     * refused unread when too large; pipes and /dev/stdin grow one. */
    struct stat sb;
    size_t cap = 1 << 16, n = 0;
    if (fstat(fileno(f), &sb) == 0 && S_ISREG(sb.st_mode)) {
        if ((unsigned long long)sb.st_size > max_bytes) {
            fclose(f);
            return too_large(path, (size_t)sb.st_size);
        }
        cap = (size_t)sb.st_size + 1;
    }
    char *data = rl_alloc(cap);
    rl_status st = data ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    while (st == RL_OK) {
        if (n == cap) {
            if (n > max_bytes) {
                st = too_large(path, n);
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
    if (st != RL_OK) {
        free(data);
        return st;
    }
    data[n] = '\0';          /* n < cap: the loop ends only on a read of nothing */
    return parse_owned(path, data, n, out);
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
