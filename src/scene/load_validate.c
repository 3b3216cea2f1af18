/* load_validate.c: our own sanity checks on mesh files, run before Assimp.
 *
 * Assimp's readers are forgiving: the OBJ reader skips lines it does not
 * understand (including binary garbage) and the PLY reader fills in a body
 * that ends before the header's element counts are reached. Both hide
 * truncated or corrupted files, so we check what is cheap to check:
 *   - OBJ is a text format: control bytes mean corruption, and a face
 *     needs at least 3 corners (a cut-off last line has fewer).
 *   - PLY (Turk 1994 format description): the header lists every element
 *     with its count and properties; the body must provide all of them, as
 *     whitespace-separated tokens (ascii) or fixed-size binary values with
 *     counted lists (binary_little_endian / binary_big_endian). Faces need
 *     at least 3 corners (Assimp's triangulation asserts otherwise) and
 *     indices below the vertex count. */
#define _POSIX_C_SOURCE 200809L   /* fstat, fileno */
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/stat.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_path.h"
#include "scene/load_internal.h"

#define PLY_MAX_ELEMENTS 16
#define PLY_MAX_PROPERTIES 64
/* A PLY header keyword, name, type or count: longer ones are refused. */
#define PLY_WORD 64

/* A mesh file is a regular file of at most this size: a path to a device
 * (a symlink to /dev/zero) or an endless pipe would be read until memory
 * runs out. 4 GiB holds far more than RL_SCENE_MAX_TRIANGLES in any format. */
#define MESH_FILE_MAX_BYTES (4ull << 30)

/* RL_ERR_IO unless the open file f is a regular file, RL_ERR_LIMIT above
 * MESH_FILE_MAX_BYTES; *bytes gets its size. */
static rl_status check_regular_file(const char *path, FILE *f, unsigned long long *bytes)
{
    struct stat st;
    if (fstat(fileno(f), &st) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot stat: %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return rl_error(RL_ERR_IO, "%s: not a regular file", path);
    if ((unsigned long long)st.st_size > MESH_FILE_MAX_BYTES)
        return rl_error(RL_ERR_LIMIT, "%s: %llu bytes exceed the limit of %llu for a mesh file", path,
                        (unsigned long long)st.st_size, MESH_FILE_MAX_BYTES);
    *bytes = (unsigned long long)st.st_size;
    return RL_OK;
}

/* Reads the open file f (a regular file, checked by the caller) from the
 * start; it stays open. */
static rl_status read_all(const char *path, FILE *f, char **data, size_t *size)
{
    if (fseek(f, 0, SEEK_SET) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot seek: %s", path, strerror(errno));
    char *buf = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len == cap) {
            cap = cap ? cap * 2 : 65536;
            char *nb = rl_realloc_array(buf, cap + 1, 1);
            if (!nb) {
                free(buf);
                return RL_ERR_OUT_OF_MEMORY;
            }
            buf = nb;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0)
            break;
        if (len > MESH_FILE_MAX_BYTES) {   /* the file grew while we read it */
            free(buf);
            return rl_error(RL_ERR_LIMIT, "%s: more than %llu bytes", path, MESH_FILE_MAX_BYTES);
        }
    }
    if (ferror(f)) {
        free(buf);
        return rl_error(RL_ERR_IO, "%s: read error", path);
    }
    buf[len] = '\0';
    *data = buf;
    *size = len;
    return RL_OK;
}

static bool obj_space(char c) { return c == ' ' || c == '\t' || c == '\r'; }

/* Corners of the face statement starting at line (just after "f"). */
static int obj_face_corners(const char *p, const char *end)
{
    int corners = 0;
    while (p < end && *p != '\n') {
        while (p < end && obj_space(*p))
            ++p;
        if (p >= end || *p == '\n' || *p == '#')
            break;
        ++corners;
        while (p < end && !obj_space(*p) && *p != '\n')
            ++p;
    }
    return corners;
}

static rl_status check_obj(const char *path, const char *data, size_t size)
{
    /* A UTF-16 file is text, but not text the OBJ reader can parse: say so
     * rather than "binary". */
    if (size >= 2 && (((unsigned char)data[0] == 0xFE && (unsigned char)data[1] == 0xFF) ||
                      ((unsigned char)data[0] == 0xFF && (unsigned char)data[1] == 0xFE)))
        return rl_error(RL_ERR_PARSE, "%s: UTF-16 text; save the OBJ file as UTF-8 or ASCII", path);
    for (size_t i = 0; i < size; ++i) {
        unsigned char c = (unsigned char)data[i];
        /* Tabs, line breaks, vertical tab and form feed are whitespace. */
        if ((c < 0x20 && !(c >= 0x09 && c <= 0x0D)) || c == 0x7F)
            return rl_error(RL_ERR_PARSE, "%s: byte %zu: binary data in a text OBJ file", path,
                            i);
    }
    /* A file cut inside a face statement leaves a face with one or two
     * corners, which Assimp turns into a point or line and then rejects with
     * an internal validation message; name the line instead. */
    const char *end = data + size;
    size_t line = 1;
    for (const char *p = data; p < end; ++line) {
        const char *q = p;
        while (q < end && obj_space(*q))
            ++q;
        if (q + 1 < end && q[0] == 'f' && obj_space(q[1])) {
            int corners = obj_face_corners(q + 1, end);
            if (corners < 3)
                return rl_error(RL_ERR_PARSE,
                                "%s:%zu: face with %d corner%s, at least 3 expected "
                                "(truncated file?)",
                                path, line, corners, corners == 1 ? "" : "s");
        }
        const char *nl = memchr(p, '\n', (size_t)(end - p));
        p = nl ? nl + 1 : end;
    }
    return RL_OK;
}

typedef struct ply_property {
    int size;        /* bytes of a scalar value, or of each list item */
    int count_size;  /* bytes of the list count, 0 for scalars */
    bool is_signed, is_float;   /* of the (item) type */
    bool face_indices;          /* "vertex_indices" of "face": checked */
} ply_property;

typedef struct ply_element {
    char name[PLY_WORD];
    unsigned long long count;
    ply_property props[PLY_MAX_PROPERTIES];
    int num_props;
} ply_element;

static bool type_signed(const char *t)
{
    return strcmp(t, "char") == 0 || strcmp(t, "int8") == 0 || strcmp(t, "short") == 0 ||
           strcmp(t, "int16") == 0 || strcmp(t, "int") == 0 || strcmp(t, "int32") == 0;
}

static bool type_float(const char *t) { return t[0] == 'f' || t[0] == 'd'; }

static int type_size(const char *t)
{
    static const struct { const char *name; int size; } types[] = {
        { "char", 1 },   { "int8", 1 },   { "uchar", 1 },  { "uint8", 1 },
        { "short", 2 },  { "int16", 2 },  { "ushort", 2 }, { "uint16", 2 },
        { "int", 4 },    { "int32", 4 },  { "uint", 4 },   { "uint32", 4 },
        { "float", 4 },  { "float32", 4 }, { "double", 8 }, { "float64", 8 },
    };
    for (size_t i = 0; i < sizeof types / sizeof types[0]; ++i)
        if (strcmp(t, types[i].name) == 0)
            return types[i].size;
    return 0;
}

/* Reads the next header line into line (NUL-terminated, without '\r').
 * *ctrl: it holds a control byte other than '\t' and '\r', a NUL too
 * (which would end the string early and hide the rest of the line from
 * every check); *cut: it was longer than cap - 1 bytes and is cut short. */
static bool next_line(const char *data, size_t size, size_t *pos, char *line, size_t cap, bool *ctrl,
                      bool *cut)
{
    *ctrl = *cut = false;
    if (*pos >= size)
        return false;
    size_t n = 0;
    while (*pos < size && data[*pos] != '\n') {
        unsigned char c = (unsigned char)data[*pos];
        if (c < 0x20 && c != '\t' && c != '\r')
            *ctrl = true;
        if (c != '\r') {
            if (n + 1 < cap)
                line[n++] = (char)c;
            else
                *cut = true;
        }
        ++*pos;
    }
    if (*pos < size)
        ++*pos;   /* the '\n' */
    line[n] = '\0';
    return true;
}

/* Splits line into at most max words separated by spaces or tabs, as
 * Assimp's header reader does; the rest of the line is ignored. *long_word:
 * a word has PLY_WORD bytes or more (sscanf's "%31s" cut such a word in two
 * and read its tail as the next word, so the header checked was not the
 * one Assimp reads: a fuzzed element name of 97 digits became a count of 0
 * here and 3 there). */
static int split_words(const char *line, char words[][PLY_WORD], int max, bool *long_word)
{
    int n = 0;
    *long_word = false;
    for (const char *p = line; *p && n < max;) {
        while (*p == ' ' || *p == '\t')
            ++p;
        if (!*p)
            break;
        const char *w = p;
        while (*p && *p != ' ' && *p != '\t')
            ++p;
        size_t len = (size_t)(p - w);
        if (len >= PLY_WORD) {
            *long_word = true;
            len = PLY_WORD - 1;
        }
        memcpy(words[n], w, len);
        words[n][len] = '\0';
        ++n;
    }
    return n;
}

static unsigned long long read_uint(const unsigned char *p, int size, bool big_endian)
{
    unsigned long long v = 0;
    for (int i = 0; i < size; ++i)
        v |= (unsigned long long)p[big_endian ? size - 1 - i : i] << (8 * i);
    return v;
}

static bool is_space(char c) { return c == ' ' || (c >= '\t' && c <= '\r'); }

/* Skips one whitespace-separated token (at least one byte, so that every
 * call makes progress); false at the end of the data. */
static bool skip_token(const char *data, size_t size, size_t *pos, const char **tok)
{
    while (*pos < size && is_space(data[*pos]))
        ++*pos;
    if (*pos >= size)
        return false;
    *tok = data + *pos;
    while (*pos < size && !is_space(data[*pos]))
        ++*pos;
    return true;
}

/* The whole token [tok, end) is one number (strtod stops at NUL bytes, so
 * binary junk inside a token fails too). */
static bool is_number(const char *tok, const char *end)
{
    char *stop;
    (void)strtod(tok, &stop);
    return stop == end;
}

static rl_status not_a_number(const char *path, const ply_element *e, unsigned long long i)
{
    return rl_error(RL_ERR_PARSE, "%s: PLY \"%s\" element %llu holds something that is not a "
                    "number", path, e->name, i);
}

static rl_status ply_body_short(const char *path, const ply_element *e, unsigned long long i)
{
    return rl_error(RL_ERR_PARSE, "%s: PLY body ends after %llu of %llu \"%s\" elements", path,
                    i, e->count, e->name);
}

/* Assimp's triangulation asserts on faces with fewer than 3 corners. */
static rl_status check_face_size(const char *path, const ply_property *p, unsigned long long face,
                                 unsigned long long n)
{
    if (p->face_indices && n < 3)
        return rl_error(RL_ERR_PARSE, "%s: PLY face %llu has %llu corners (at least 3 needed)",
                        path, face, n);
    return RL_OK;
}

static rl_status bad_index(const char *path, unsigned long long face, const char *index)
{
    return rl_error(RL_ERR_PARSE, "%s: PLY face %llu uses vertex %.20s, out of range", path,
                    face, index);
}

static rl_status check_ply(const char *path, const char *data, size_t size)
{
    char line[512];
    size_t pos = 0;
    bool ctrl, cut;
    if (!next_line(data, size, &pos, line, sizeof line, &ctrl, &cut) || strcmp(line, "ply") != 0 || ctrl)
        return rl_error(RL_ERR_PARSE, "%s: not a PLY file (first line is not \"ply\")", path);

    ply_element elems[PLY_MAX_ELEMENTS];
    int num_elems = 0, format = -1;   /* 0 ascii, 1 little, 2 big endian */
    for (;;) {
        if (!next_line(data, size, &pos, line, sizeof line, &ctrl, &cut))
            return rl_error(RL_ERR_PARSE, "%s: PLY header has no end_header", path);
        /* Assimp's PLY reader can loop forever on odd header bytes. */
        if (ctrl)
            return rl_error(RL_ERR_PARSE, "%s: control byte in the PLY header", path);
        char w[5][PLY_WORD] = { "" };
        bool long_word;
        int words = split_words(line, w, 5, &long_word);
        if (words < 1)
            continue;
        const char *word = w[0], *a = w[1], *b = w[2], *c = w[3], *d = w[4];
        /* Free text may be long; what is parsed must be read whole. */
        bool text = strcmp(word, "comment") == 0 || strcmp(word, "obj_info") == 0;
        if (!text && (long_word || cut))
            return long_word ? rl_error(RL_ERR_PARSE, "%s: PLY header line \"%.40s...\" has a word of %d bytes "
                                        "or more", path, line, PLY_WORD)
                             : rl_error(RL_ERR_PARSE, "%s: PLY header line \"%.40s...\" is longer than %zu bytes",
                                        path, line, sizeof line - 1);
        if (strcmp(word, "end_header") == 0) {
            if (words != 1)
                return rl_error(RL_ERR_PARSE, "%s: junk after PLY end_header", path);
            break;
        }
        if (strcmp(word, "format") == 0) {
            format = strcmp(a, "ascii") == 0                  ? 0
                     : strcmp(a, "binary_little_endian") == 0 ? 1
                     : strcmp(a, "binary_big_endian") == 0    ? 2 : -1;
            if (format < 0)
                return rl_error(RL_ERR_PARSE, "%s: unknown PLY format \"%s\"", path, a);
        } else if (strcmp(word, "element") == 0) {
            if (num_elems == PLY_MAX_ELEMENTS)
                return rl_error(RL_ERR_PARSE, "%s: more than %d PLY elements", path,
                                PLY_MAX_ELEMENTS);
            ply_element *e = &elems[num_elems++];
            memset(e, 0, sizeof *e);
            snprintf(e->name, sizeof e->name, "%s", a);
            char *end = NULL;
            e->count = strtoull(b, &end, 10);
            if (b[0] == '\0' || b[0] == '-' || *end != '\0')
                return rl_error(RL_ERR_PARSE, "%s: PLY element \"%s\" has a bad count \"%s\"",
                                path, a, b);
        } else if (strcmp(word, "property") == 0) {
            if (num_elems == 0)
                return rl_error(RL_ERR_PARSE, "%s: PLY property before any element", path);
            ply_element *e = &elems[num_elems - 1];
            if (e->num_props == PLY_MAX_PROPERTIES)
                return rl_error(RL_ERR_PARSE, "%s: too many PLY properties", path);
            ply_property *p = &e->props[e->num_props++];
            bool list = strcmp(a, "list") == 0;
            p->count_size = list ? type_size(b) : 0;
            const char *item_type = list ? c : a, *prop_name = list ? d : b;
            p->size = type_size(item_type);
            p->is_signed = type_signed(item_type);
            p->is_float = type_float(item_type);
            p->face_indices = list && strcmp(e->name, "face") == 0 &&
                              (strcmp(prop_name, "vertex_indices") == 0 ||
                               strcmp(prop_name, "vertex_index") == 0);
            if (p->size == 0 || (list && p->count_size == 0))
                return rl_error(RL_ERR_PARSE, "%s: unknown PLY property type in \"%s\"", path,
                                line);
        } else if (!text) {
            /* Real exporters write free text without "comment" (Blender 2.4x:
             * "Created by Blender3D ..."); Assimp skips such lines, so do we. */
            rl_warn("%s: ignoring unknown PLY header line \"%s\"", path, line);
        }
    }
    if (format < 0)
        return rl_error(RL_ERR_PARSE, "%s: PLY header has no format line", path);

    unsigned long long vertices = 0;
    for (int k = 0; k < num_elems; ++k)
        if (strcmp(elems[k].name, "vertex") == 0)
            vertices = elems[k].count;
    /* The walk below checks every count against the body, and stops where
     * the body ends. An element without properties has no body to run out
     * of, yet Assimp loops over its count ("element vertex 4000000000" and
     * nothing else ran forever): allow it at most one item per byte after
     * the header. */
    for (int k = 0; k < num_elems; ++k)
        if (elems[k].num_props == 0 && elems[k].count > size - pos)
            return rl_error(RL_ERR_PARSE,
                            "%s: PLY element \"%s\" declares %llu items without properties, more "
                            "than the %llu bytes after the header",
                            path, elems[k].name, elems[k].count, (unsigned long long)(size - pos));
    const unsigned char *bytes = (const unsigned char *)data;
    rl_status st;
    for (int k = 0; k < num_elems; ++k) {
        const ply_element *e = &elems[k];
        if (e->num_props == 0)
            continue;
        for (unsigned long long i = 0; i < e->count; ++i) {
            for (int j = 0; j < e->num_props; ++j) {
                const ply_property *p = &e->props[j];
                if (format == 0) {
                    const char *tok;
                    if (!skip_token(data, size, &pos, &tok))
                        return ply_body_short(path, e, i);
                    if (!is_number(tok, data + pos))
                        return not_a_number(path, e, i);
                    if (p->count_size == 0)
                        continue;
                    char *end;
                    unsigned long long n = strtoull(tok, &end, 10);
                    if (tok[0] == '-' || end == tok)
                        return rl_error(RL_ERR_PARSE, "%s: bad PLY list length in \"%s\"",
                                        path, e->name);
                    if ((st = check_face_size(path, p, i, n)) != RL_OK)
                        return st;
                    for (unsigned long long m = 0; m < n; ++m) {
                        if (!skip_token(data, size, &pos, &tok))
                            return ply_body_short(path, e, i);
                        if (!is_number(tok, data + pos))
                            return not_a_number(path, e, i);
                        if (p->face_indices && !p->is_float) {
                            long long idx = strtoll(tok, &end, 10);
                            if (end == tok || idx < 0 || (unsigned long long)idx >= vertices)
                                return bad_index(path, i, tok);
                        }
                    }
                } else if (p->count_size == 0) {
                    if (size - pos < (size_t)p->size)
                        return ply_body_short(path, e, i);
                    pos += (size_t)p->size;
                } else {
                    if (size - pos < (size_t)p->count_size)
                        return ply_body_short(path, e, i);
                    unsigned long long n = read_uint(bytes + pos, p->count_size, format == 2);
                    pos += (size_t)p->count_size;
                    if (n > (size - pos) / (size_t)p->size)
                        return ply_body_short(path, e, i);
                    if ((st = check_face_size(path, p, i, n)) != RL_OK)
                        return st;
                    for (unsigned long long m = 0; p->face_indices && !p->is_float && m < n; ++m) {
                        unsigned long long idx = read_uint(bytes + pos + m * (size_t)p->size,
                                                           p->size, format == 2);
                        /* A negative signed index has its top bit set. */
                        bool negative = p->is_signed && (idx >> (8 * p->size - 1)) & 1u;
                        if (negative || idx >= vertices) {
                            char text[32];
                            snprintf(text, sizeof text, "%s%llu", negative ? "negative " : "",
                                     negative ? 0ull : idx);
                            return bad_index(path, i, text);
                        }
                    }
                    pos += (size_t)(n * (unsigned long long)p->size);
                }
            }
        }
    }
    return RL_OK;
}

/* OFF (Geomview's Object File Format): a header word ending in "OFF"
 * (OFF, COFF, NOFF, ...), the counts "vertices faces edges", one vertex
 * per line, then one face per line: its corner count and the indices.
 * Assimp's reader clamps an index past the vertices onto the last vertex,
 * which hides a broken file; we refuse it, as for PLY. Only the text's
 * structure is read: numbers stay Assimp's to parse. */
static bool off_blank(const char *line)
{
    while (*line == ' ' || *line == '\t')
        ++line;
    return *line == '\0' || *line == '#';
}

static rl_status check_off(const char *path, const char *data, size_t size)
{
    char line[4096];
    size_t pos = 0;
    bool ctrl, cut;   /* not checked: Assimp's OFF reader reads numbers only */
    long long nums[4] = { -1, -1, -1, -1 };
    int have = 0, need = 2;
    bool header = false;
    /* The header word, then the counts (on its line or the next): vertices
     * and faces, the ones Assimp reads, and the edges where they stand on
     * the same line. A missing edge count does not stop the check (fuzzed:
     * "OFF\n4 333...3 ???" named 10^62 faces, and Assimp, reading only two
     * counts, asked for 22 GB). */
    while (have < need && next_line(data, size, &pos, line, sizeof line, &ctrl, &cut)) {
        char *p = line;
        if (off_blank(p))
            continue;
        if (!header) {
            /* The header word as Assimp's OFF reader reads it: optional
             * "ST", "C", "N", "4" and "n" (texture coordinates, colours,
             * normals, homogeneous points, a dimension count first), then
             * "OFF", and the counts may follow it without a space (fuzzed:
             * "OFF444...4" made Assimp ask for 5.7 GB of vertices). */
            while (*p == ' ' || *p == '\t')
                ++p;
            if (p[0] == 'S' && p[1] == 'T')
                p += 2;
            if (*p == 'C')
                ++p;
            if (*p == 'N')
                ++p;
            if (*p == '4')
                ++p;
            if (*p == 'n') {
                ++p;
                need = 3;   /* the dimension, then the counts */
            }
            if (strncmp(p, "OFF", 3) == 0)
                p += 3;
            else if (!(*p >= '0' && *p <= '9') && *p != '+')
                return RL_OK;   /* not the text form we know: Assimp decides */
            /* else no header word: Assimp then reads the counts straight
             * away (fuzzed: a line of 98 digits asked for 28 GB). */
            header = true;
        }
        for (char *end; have < need + 1; p = end) {
            long long v = strtoll(p, &end, 10);
            if (end == p)
                break;
            nums[have++] = v;
        }
    }
    long long counts[2] = { nums[need - 2], nums[need - 1] };
    if (have < need || counts[0] < 0 || counts[1] < 0)
        return RL_OK;
    /* Assimp sizes its arrays by the declared counts before it reads a
     * line, so a few bytes declaring 10^12 faces ask for gigabytes (found
     * by fuzz_load_mesh). Every vertex and face takes a line of at least
     * two bytes (a number and its end; the last may lack the end), so
     * counts beyond about half of what follows the header cannot be true;
     * strtoll saturates, so a count too long for any integer lands here
     * too. */
    const long long room = (long long)((size - pos + 1) / 2);
    if (counts[0] > room || counts[1] > room || counts[0] + counts[1] > room)
        return rl_error(RL_ERR_PARSE, "%s: OFF declares %lld vertices and %lld faces, more than its %zu bytes after "
                        "the header can hold", path, counts[0], counts[1], size - pos);
    for (long long v = 0; v < counts[0];) {
        if (!next_line(data, size, &pos, line, sizeof line, &ctrl, &cut))
            return RL_OK;   /* short: Assimp reports it */
        if (!off_blank(line))
            ++v;
    }
    for (long long f = 0; f < counts[1];) {
        if (!next_line(data, size, &pos, line, sizeof line, &ctrl, &cut))
            return RL_OK;
        if (off_blank(line))
            continue;
        char *p = line, *end;
        long long corners = strtoll(p, &end, 10);
        for (long long k = 0; end != p && k < corners; ++k) {
            p = end;
            long long idx = strtoll(p, &end, 10);
            if (end == p)
                break;
            if (idx < 0 || idx >= counts[0])
                return rl_error(RL_ERR_PARSE, "%s: OFF face %lld uses vertex %lld of %lld", path, f, idx,
                                counts[0]);
        }
        ++f;
    }
    return RL_OK;
}

/* Assimp picks its reader by content when the extension's reader declines
 * (its glTF reader declines what does not parse as glTF), and its PLY
 * reader then takes any file that starts with "ply" in any case, whatever
 * follows; so a PLY body in a ".gltf" file still reaches the PLY reader:
 * sniff those three bytes as well as the extension. (fuzz_load_mesh: "ply"
 * followed by 0xff or NUL bytes instead of the line's end, named .gltf,
 * made the PLY reader run forever.) */
static bool starts_like_ply(const char *path)
{
    char head[3] = "";
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    size_t n = fread(head, 1, 3, f);
    fclose(f);
    return n == 3 && (head[0] | 0x20) == 'p' && (head[1] | 0x20) == 'l' && (head[2] | 0x20) == 'y';
}

static uint32_t le32(const unsigned char *p)
{
    return (uint32_t)p[0] | (uint32_t)p[1] << 8 | (uint32_t)p[2] << 16 | (uint32_t)p[3] << 24;
}

/* Binary glTF (glTF 2.0 spec, "GLB File Format Specification"): a 12-byte
 * header (magic "glTF", version, total length) and chunks (length, type,
 * data padded to 4 bytes). Assimp allocates what a chunk header claims, so a
 * 300-byte file claiming 2 GB got 2 GB: every length is checked against
 * the file's size first, reading only the headers. */
static rl_status check_glb(const char *path, FILE *f, unsigned long long file_size)
{
    rl_status st = RL_OK;
    unsigned char head[12];
    if (fseek(f, 0, SEEK_SET) != 0 || fread(head, 1, 12, f) != 12 || memcmp(head, "glTF", 4) != 0)
        st = RL_OK;   /* not binary glTF after all: Assimp decides */
    else {
        unsigned long long total = le32(head + 8), at = 12;
        if (total > file_size)
            st = rl_error(RL_ERR_PARSE, "%s: GLB header claims %llu bytes, the file has %llu", path,
                          total, file_size);
        for (int chunk = 0; st == RL_OK && at + 8 <= total; ++chunk) {
            unsigned char ch[8];
            if (fseek(f, (long)at, SEEK_SET) != 0 || fread(ch, 1, 8, f) != 8) {
                st = rl_error(RL_ERR_PARSE, "%s: GLB chunk %d header cut off", path, chunk);
                break;
            }
            unsigned long long len = le32(ch);
            if (len > total - at - 8)
                st = rl_error(RL_ERR_PARSE, "%s: GLB chunk %d claims %llu bytes, %llu remain", path,
                              chunk, len, total - at - 8);
            at += 8 + ((len + 3) & ~3ull);
        }
    }
    return st;
}

/* The JSON chunk of a GLB file whose chunk lengths check_glb accepted
 * (the first chunk, glTF 2.0 spec): only it is read, not the binary
 * buffers. NULL data when there is none. */
static rl_status read_glb_json(const char *path, FILE *f, char **data, size_t *size)
{
    unsigned char ch[8];
    *data = NULL;
    *size = 0;
    if (fseek(f, 12, SEEK_SET) != 0 || fread(ch, 1, 8, f) != 8 || memcmp(ch + 4, "JSON", 4) != 0)
        return RL_OK;
    size_t len = le32(ch);
    char *json = rl_alloc(len + 1);
    if (!json)
        return RL_ERR_OUT_OF_MEMORY;
    if (fread(json, 1, len, f) != len) {
        free(json);
        return rl_error(RL_ERR_IO, "%s: cannot read the GLB JSON chunk", path);
    }
    json[len] = '\0';
    *data = json;
    *size = len;
    return RL_OK;
}

rl_status rl_check_mesh_file(const char *path)
{
    /* Whatever the format: Assimp would read a device until memory runs
     * out. One open serves every check below. */
    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned long long file_size = 0;
    rl_status st = check_regular_file(path, f, &file_size);
    if (st == RL_OK && rl_path_has_ext(path, ".glb"))
        st = check_glb(path, f, file_size);
    bool ply = rl_path_has_ext(path, ".ply") || starts_like_ply(path);
    bool obj = !ply && rl_path_has_ext(path, ".obj");
    bool off = !ply && !obj && rl_path_has_ext(path, ".off");
    bool gltf = !ply && rl_path_has_ext(path, ".gltf"), glb = !ply && rl_path_has_ext(path, ".glb");
    bool dae = !ply && rl_path_has_ext(path, ".dae");
    char *data = NULL;
    size_t size = 0;
    if (st == RL_OK && glb && (st = read_glb_json(path, f, &data, &size)) == RL_OK && data)
        st = rl_check_gltf_nodes(path, data, size);
    else if (st == RL_OK && (obj || ply || off || gltf || dae) &&
             (st = read_all(path, f, &data, &size)) == RL_OK)
        st = obj    ? check_obj(path, data, size)
             : ply  ? check_ply(path, data, size)
             : off  ? check_off(path, data, size)
             : gltf ? rl_check_gltf_nodes(path, data, size)
                    : rl_check_dae_nodes(path, data, size);
    free(data);
    fclose(f);
    return st;
}
