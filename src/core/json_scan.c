/* json_scan.c: a strict recursive-descent JSON scanner (RFC 8259) that runs
 * beside cJSON. cJSON keeps no source positions and reports a syntax error
 * only as a pointer, so this scanner (1) diagnoses syntax errors in words
 * ("expected ',' or '}' after object member") at the exact offset, and
 * (2) after cJSON succeeded, walks the text in the same order as cJSON's tree
 * (cJSON keeps member order) and records where every item starts. It is also
 * stricter than cJSON, which accepts e.g. leading zeros ("01"). */
#include "core/json_scan.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* Below cJSON's CJSON_NESTING_LIMIT, so we are the ones who report it. */
#define MAX_DEPTH 512

typedef struct scan {
    const char *s;
    size_t len, i;
    int depth;
    rl_status status;
    rl_json_scan_result *res;
    const cJSON *target;        /* the item whose position is wanted, or NULL */
    bool done;                  /* target found: the rest is not scanned */
} scan;

void rl_json_line_col(const char *text, size_t len, size_t offset, int *line, int *col)
{
    int l = 1;
    /* Columns on line 1 count from after a byte order mark, as editors do. */
    size_t start = len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0 && offset >= 3 ? 3 : 0;
    for (size_t k = 0; k < offset && k < len; ++k)
        if (text[k] == '\n') {
            ++l;
            start = k + 1;
        }
    *line = l;
    *col = (int)(offset - start) + 1;
}

static bool fail(scan *sc, size_t at, const char *fmt, ...) RL_PRINTF(3, 4);
static bool fail(scan *sc, size_t at, const char *fmt, ...)
{
    if (sc->status == RL_OK) {
        sc->status = RL_ERR_PARSE;
        sc->res->err_offset = at;
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(sc->res->message, sizeof sc->res->message, fmt, ap);
        va_end(ap);
    }
    return false;
}

static bool disagree(scan *sc)
{
    if (sc->status == RL_OK)
        sc->status = RL_ERR_INTERNAL;
    return false;
}

/* Names the byte at i for a message: 'x', "end of file" or "byte 0x07". */
static const char *describe(const scan *sc, size_t i, char buf[16])
{
    if (i >= sc->len)
        return "end of file";
    unsigned char c = (unsigned char)sc->s[i];
    if (c >= 0x20 && c < 0x7f)
        snprintf(buf, 16, "'%c'", c);
    else
        snprintf(buf, 16, "byte 0x%02x", c);
    return buf;
}

static bool at_end(const scan *sc) { return sc->i >= sc->len; }
static char peek(const scan *sc) { return at_end(sc) ? '\0' : sc->s[sc->i]; }

static void skip_ws(scan *sc)
{
    while (!at_end(sc)) {
        char c = sc->s[sc->i];
        if (c != ' ' && c != '\t' && c != '\n' && c != '\r')
            break;
        ++sc->i;
    }
}

static bool looks_like_comment(const scan *sc)
{
    return peek(sc) == '/' && sc->i + 1 < sc->len &&
           (sc->s[sc->i + 1] == '/' || sc->s[sc->i + 1] == '*');
}

/* Notes that item starts at `at`; once it is the target, stops the scan
 * (returning false unwinds the recursion; the status stays RL_OK). */
static bool record(scan *sc, const cJSON *item, size_t at)
{
    if (!item || item != sc->target)
        return true;
    rl_json_line_col(sc->s, sc->len, at, &sc->res->line, &sc->res->col);
    sc->res->found = sc->done = true;
    return false;
}

static bool scan_value(scan *sc, const cJSON *node, bool record_here);
static bool is_digit(char c) { return c >= '0' && c <= '9'; }
static bool is_alpha(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

static bool is_hex(char c)
{
    return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/* Reads "XXXX" after "\u" at sc->i; -1 if not four hex digits. */
static long hex4(scan *sc)
{
    if (sc->i + 4 > sc->len)
        return -1;
    for (int k = 0; k < 4; ++k)
        if (!is_hex(sc->s[sc->i + k]))
            return -1;
    char digits[5];
    memcpy(digits, sc->s + sc->i, 4);
    digits[4] = '\0';
    sc->i += 4;
    return strtol(digits, NULL, 16);
}

static bool scan_string(scan *sc)
{
    size_t start = sc->i++;
    int line, col;
    for (;;) {
        if (at_end(sc)) {
            rl_json_line_col(sc->s, sc->len, start, &line, &col);
            return fail(sc, sc->i, "unexpected end of file in string (started at %d:%d)", line, col);
        }
        unsigned char c = (unsigned char)sc->s[sc->i];
        if (c == '"') {
            ++sc->i;
            return true;
        }
        if (c == '\n')
            return fail(sc, sc->i, "unterminated string (strings cannot span lines; write \\n)");
        if (c < 0x20)
            return fail(sc, sc->i, "control character (byte 0x%02x) in string; escape it", c);
        if (c != '\\') {
            ++sc->i;
            continue;
        }
        size_t esc = sc->i++;
        char e = peek(sc);
        if (at_end(sc))
            continue; /* reported as end of file in string */
        if (strchr("\"\\/bfnrt", e) && e != '\0') {
            ++sc->i;
            continue;
        }
        if (e != 'u') {
            char buf[16];
            return fail(sc, esc, "invalid escape in string: '\\' followed by %s (valid: \\\" \\\\ \\/ \\b \\f \\n \\r \\t \\uXXXX)",
                        describe(sc, sc->i, buf));
        }
        ++sc->i;
        long code = hex4(sc);
        if (code < 0)
            return fail(sc, esc, "invalid \\u escape (expected 4 hex digits)");
        /* UTF-16 surrogates must come as a high/low pair (cJSON rejects
         * unpaired ones too). */
        if (code >= 0xDC00 && code <= 0xDFFF)
            return fail(sc, esc, "unpaired UTF-16 low surrogate \\u%04lX in string", code);
        if (code >= 0xD800 && code <= 0xDBFF) {
            long low = -1;
            if (sc->i + 1 < sc->len && sc->s[sc->i] == '\\' && sc->s[sc->i + 1] == 'u') {
                sc->i += 2;
                low = hex4(sc);
            }
            if (low < 0xDC00 || low > 0xDFFF)
                return fail(sc, esc, "unpaired UTF-16 high surrogate \\u%04lX in string", code);
        }
    }
}


static bool scan_number(scan *sc)
{
    size_t start = sc->i;
    if (peek(sc) == '-')
        ++sc->i;
    if (!is_digit(peek(sc)))
        return fail(sc, start, "invalid number: expected a digit after '-'");
    if (peek(sc) == '0') {
        ++sc->i;
        if (is_digit(peek(sc)))
            return fail(sc, start, "invalid number: leading zeros are not allowed");
    } else {
        while (is_digit(peek(sc)))
            ++sc->i;
    }
    if (peek(sc) == '.') {
        ++sc->i;
        if (!is_digit(peek(sc)))
            return fail(sc, start, "invalid number: expected a digit after '.'");
        while (is_digit(peek(sc)))
            ++sc->i;
    }
    if (peek(sc) == 'e' || peek(sc) == 'E') {
        ++sc->i;
        if (peek(sc) == '+' || peek(sc) == '-')
            ++sc->i;
        if (!is_digit(peek(sc)))
            return fail(sc, start, "invalid number: expected a digit in the exponent");
        while (is_digit(peek(sc)))
            ++sc->i;
    }
    return true;
}

static bool scan_literal(scan *sc)
{
    static const char *const words[] = { "true", "false", "null" };
    for (int k = 0; k < 3; ++k) {
        size_t n = strlen(words[k]);
        if (sc->len - sc->i >= n && memcmp(sc->s + sc->i, words[k], n) == 0) {
            sc->i += n;
            return true;
        }
    }
    return fail(sc, sc->i, "invalid literal (expected true, false or null; strings need double quotes)");
}

/* Error for a missing value at sc->i. */
static bool expected_value(scan *sc)
{
    char buf[16];
    char c = peek(sc);
    if (at_end(sc))
        return fail(sc, sc->i, "unexpected end of file (expected a value)");
    if (looks_like_comment(sc))
        return fail(sc, sc->i, "comments are not allowed in JSON");
    if (c == '\'')
        return fail(sc, sc->i, "strings must use double quotes, found '''");
    if (is_alpha(c))
        return fail(sc, sc->i, "expected a value, found %s (strings need double quotes)",
                    describe(sc, sc->i, buf));
    return fail(sc, sc->i, "expected a value, found %s", describe(sc, sc->i, buf));
}

/* Error for a container that the text leaves open or continues wrongly. */
static bool bad_continuation(scan *sc, size_t open_at, const char *what, char close,
                             const char *after)
{
    char buf[16];
    int line, col;
    if (at_end(sc)) {
        rl_json_line_col(sc->s, sc->len, open_at, &line, &col);
        return fail(sc, sc->i, "unexpected end of file (%s opened at %d:%d is not closed)", what,
                    line, col);
    }
    if (looks_like_comment(sc))
        return fail(sc, sc->i, "comments are not allowed in JSON");
    char other = close == '}' ? ']' : '}';
    if (peek(sc) == other) {
        rl_json_line_col(sc->s, sc->len, open_at, &line, &col);
        return fail(sc, sc->i, "expected ',' or '%c' after %s, found '%c' (%s opened at %d:%d)",
                    close, after, other, what, line, col);
    }
    return fail(sc, sc->i, "expected ',' or '%c' after %s, found %s", close, after,
                describe(sc, sc->i, buf));
}

static bool enter(scan *sc)
{
    if (++sc->depth > MAX_DEPTH)
        return fail(sc, sc->i, "nesting deeper than %d levels", MAX_DEPTH);
    return true;
}

static bool scan_object(scan *sc, const cJSON *node)
{
    size_t open_at = sc->i++;
    if (!enter(sc))
        return false;
    const cJSON *child = node ? node->child : NULL;
    skip_ws(sc);
    if (peek(sc) == '}') {
        ++sc->i;
        --sc->depth;
        return node && child ? disagree(sc) : true;
    }
    for (bool first = true;; first = false) {
        skip_ws(sc);
        if (peek(sc) != '"' || at_end(sc)) {
            char buf[16];
            if (at_end(sc))
                return bad_continuation(sc, open_at, "object", '}', "");
            if (!first && peek(sc) == '}')
                return fail(sc, sc->i, "trailing comma before '}'");
            if (looks_like_comment(sc))
                return fail(sc, sc->i, "comments are not allowed in JSON");
            return fail(sc, sc->i, "expected a string key%s, found %s%s", first ? " or '}'" : "",
                        describe(sc, sc->i, buf),
                        peek(sc) == '\'' || is_alpha(peek(sc)) ? " (keys need double quotes)" : "");
        }
        if (node && !child)
            return disagree(sc);
        if (!record(sc, child, sc->i) || !scan_string(sc))
            return false;
        skip_ws(sc);
        if (peek(sc) != ':' || at_end(sc)) {
            char buf[16];
            return fail(sc, sc->i, "expected ':' after object key, found %s", describe(sc, sc->i, buf));
        }
        ++sc->i;
        if (!scan_value(sc, child, false))
            return false;
        child = child ? child->next : NULL;
        skip_ws(sc);
        if (peek(sc) == ',' && !at_end(sc)) {
            ++sc->i;
            continue;
        }
        if (peek(sc) == '}' && !at_end(sc)) {
            ++sc->i;
            break;
        }
        return bad_continuation(sc, open_at, "object", '}', "object member");
    }
    --sc->depth;
    return child ? disagree(sc) : true;
}

static bool scan_array(scan *sc, const cJSON *node)
{
    size_t open_at = sc->i++;
    if (!enter(sc))
        return false;
    const cJSON *child = node ? node->child : NULL;
    skip_ws(sc);
    if (peek(sc) == ']' && !at_end(sc)) {
        ++sc->i;
        --sc->depth;
        return node && child ? disagree(sc) : true;
    }
    for (;;) {
        skip_ws(sc);
        if (peek(sc) == ']' && !at_end(sc))
            return fail(sc, sc->i, "trailing comma before ']'");
        if (at_end(sc))
            return bad_continuation(sc, open_at, "array", ']', "");
        if (node && !child)
            return disagree(sc);
        if (!scan_value(sc, child, true))
            return false;
        child = child ? child->next : NULL;
        skip_ws(sc);
        if (peek(sc) == ',' && !at_end(sc)) {
            ++sc->i;
            continue;
        }
        if (peek(sc) == ']' && !at_end(sc)) {
            ++sc->i;
            break;
        }
        return bad_continuation(sc, open_at, "array", ']', "array element");
    }
    --sc->depth;
    return child ? disagree(sc) : true;
}

static bool type_matches(const cJSON *node, char c)
{
    if (!node)
        return true;
    switch (c) {
    case '{': return cJSON_IsObject(node);
    case '[': return cJSON_IsArray(node);
    case '"': return cJSON_IsString(node);
    case 't': case 'f': return cJSON_IsBool(node);
    case 'n': return cJSON_IsNull(node);
    default: return cJSON_IsNumber(node);
    }
}

static bool scan_value(scan *sc, const cJSON *node, bool record_here)
{
    skip_ws(sc);
    char c = peek(sc);
    bool known = !at_end(sc) && (c == '{' || c == '[' || c == '"' || c == '-' || is_digit(c) ||
                                 c == 't' || c == 'f' || c == 'n');
    if (!known)
        return expected_value(sc);
    if (!type_matches(node, c))
        return disagree(sc);
    ++sc->res->values;
    if (record_here && !record(sc, node, sc->i))
        return false;
    switch (c) {
    case '{': return scan_object(sc, node);
    case '[': return scan_array(sc, node);
    case '"': return scan_string(sc);
    case 't': case 'f': case 'n': return scan_literal(sc);
    default: return scan_number(sc);
    }
}

rl_status rl_json_scan(const char *text, size_t len, const cJSON *root, const cJSON *target,
                       rl_json_scan_result *res)
{
    memset(res, 0, sizeof *res);
    scan sc = { .s = text, .len = len, .status = RL_OK, .res = res, .target = root ? target : NULL };
    /* A UTF-8 byte order mark is tolerated (editors on Windows add one). */
    if (len >= 3 && memcmp(text, "\xEF\xBB\xBF", 3) == 0)
        sc.i = 3;
    skip_ws(&sc);
    if (at_end(&sc)) {
        fail(&sc, sc.i, "unexpected end of file: the document is empty (expected a value)");
    } else if (scan_value(&sc, root, true) && !sc.done) {
        skip_ws(&sc);
        if (!at_end(&sc)) {
            char buf[16];
            fail(&sc, sc.i, "unexpected %s after the top-level value (a document holds one value)",
                 describe(&sc, sc.i, buf));
        }
    }
    return sc.status;
}
