/* load_message.c: an importer's error message made fit for one error line.
 *
 * Assimp quotes the text it failed on ("Cannot parse string \"...\" as a
 * real number"), and that text may come from a file the model references
 * rather than the one the user named: `mtllib ../../../../etc/passwd` in
 * an OBJ made the error line print part of /etc/passwd. So a quoted
 * excerpt is kept only when it occurs in the named file (within its first
 * SEARCH_BYTES), and then cut to EXCERPT_CHARS with non-printable bytes
 * escaped; the named path itself is kept (escaped); anything else quoted
 * is replaced by a note. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/load_internal.h"

#define EXCERPT_CHARS 40
/* How much of the named file is searched for an excerpt: an error path
 * should not read gigabytes; an excerpt found nowhere is dropped. */
#define SEARCH_BYTES ((size_t)64 << 20)
#define CHUNK ((size_t)1 << 16)

/* Whether the n bytes of text occur in the first SEARCH_BYTES of path. */
static bool file_contains(const char *path, const char *text, size_t n)
{
    if (n == 0 || n > CHUNK)
        return false;
    FILE *f = fopen(path, "rb");
    char *buf = malloc(2 * CHUNK);
    bool found = false;
    size_t kept = 0, total = 0;
    while (f && buf && !found && total < SEARCH_BYTES) {
        size_t got = fread(buf + kept, 1, CHUNK, f);
        if (got == 0)
            break;
        total += got;
        found = memmem(buf, kept + got, text, n) != NULL;
        /* The last n - 1 bytes may start a match that the next chunk ends. */
        size_t tail = kept + got < n - 1 ? kept + got : n - 1;
        memmove(buf, buf + kept + got - tail, tail);
        kept = tail;
    }
    if (f)
        fclose(f);
    free(buf);
    return found;
}

typedef struct sink { char *out; size_t size, len; } sink;

static void put(sink *s, const char *text, size_t n)
{
    for (size_t i = 0; i < n && s->len + 1 < s->size; ++i)
        s->out[s->len++] = text[i];
    s->out[s->len] = '\0';
}

/* One byte as itself when printable ASCII, else as \xNN: a terminal must
 * not receive control sequences from a file. */
static void put_byte(sink *s, unsigned char c)
{
    char esc[8];
    if (c >= 0x20 && c < 0x7f)
        put(s, (const char *)&c, 1);
    else
        put(s, esc, (size_t)snprintf(esc, sizeof esc, "\\x%02x", c));
}

void rl_load_safe_message(const char *path, const char *msg, char *out, size_t size)
{
    if (!size)
        return;
    sink s = { out, size, 0 };
    out[0] = '\0';
    for (const char *p = msg ? msg : ""; *p;) {
        const char *close = *p == '"' ? strchr(p + 1, '"') : NULL;
        if (!close) {
            put_byte(&s, (unsigned char)*p++);
            continue;
        }
        size_t n = (size_t)(close - p - 1);
        if (n == strlen(path) && memcmp(p + 1, path, n) == 0) {
            /* The path the user named (Assimp quotes it when no reader
             * takes the file): theirs, not the file's text. */
            put(&s, "\"", 1);
            for (size_t i = 0; i < n; ++i)
                put_byte(&s, (unsigned char)path[i]);
            put(&s, "\"", 1);
        } else if (file_contains(path, p + 1, n)) {
            put(&s, "\"", 1);
            for (size_t i = 0; i < n && i < EXCERPT_CHARS; ++i)
                put_byte(&s, (unsigned char)p[1 + i]);
            put(&s, n > EXCERPT_CHARS ? "...\"" : "\"", n > EXCERPT_CHARS ? 4 : 1);
        } else {
            static const char note[] = "(text not from this file, not shown)";
            put(&s, note, sizeof note - 1);
        }
        p = close + 1;
    }
}
