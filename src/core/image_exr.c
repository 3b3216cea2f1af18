/* image_exr.c: OpenEXR output and input (half-float linear RGBA) through
 * OpenEXR's C RGBA interface (ImfCRgbaFile.h). That interface catches the
 * library's C++ exceptions and reports them through ImfErrorMessage(), which
 * we forward into rl_error(). Values are stored unclamped, as EXR is meant
 * for HDR; half precision keeps about 3 significant decimal digits. */
#define _POSIX_C_SOURCE 200809L   /* fseeko, ftello */
#include "rl/rl_image.h"
#include "rl/rl_output.h"

#include <ImfCRgbaFile.h>
#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/image_internal.h"

rl_status rl_image_write_exr(const rl_image *img, const char *path)
{
    rl_status st = rl_image_check_writable(img, "rl_image_write_exr", path);
    if (st != RL_OK)
        return st;
    int w = img->width, h = img->height;
    ImfRgba *px = rl_calloc((size_t)w * (size_t)h, sizeof *px);
    if (!px)
        return RL_ERR_OUT_OF_MEMORY;
    for (size_t i = 0; i < (size_t)w * h; ++i) {
        ImfFloatToHalf(img->color[i].x, &px[i].r);
        ImfFloatToHalf(img->color[i].y, &px[i].g);
        ImfFloatToHalf(img->color[i].z, &px[i].b);
        ImfFloatToHalf(img->color[i].w, &px[i].a);
    }
    /* OpenEXR opens the file by name: it writes the output's temporary,
     * and the output's own stream only serves the commit's sync. Opening
     * it first also words an unwritable path as users expect (OpenEXR's
     * message lacks errno's reason). */
    rl_output *o = NULL;
    st = rl_output_open(path, &o);
    if (st != RL_OK) {
        free(px);
        return st;
    }
    ImfHeader *hdr = ImfNewHeader();
    if (!hdr) {
        free(px);
        rl_output_abort(o);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: cannot create EXR header", path);
    }
    ImfHeaderSetDataWindow(hdr, 0, 0, w - 1, h - 1);
    ImfHeaderSetDisplayWindow(hdr, 0, 0, w - 1, h - 1);
    ImfOutputFile *file = ImfOpenOutputFile(rl_output_temp_path(o), hdr, IMF_WRITE_RGBA);
    ImfDeleteHeader(hdr);
    if (!file) {
        st = rl_error(RL_ERR_IO, "%s: cannot open for writing: %s", path, ImfErrorMessage());
        free(px);
        rl_output_abort(o);
        return st;
    }
    /* Strides are in ImfRgba units: one pixel across, one row down. */
    bool ok = ImfOutputSetFrameBuffer(file, px, 1, (size_t)w) && ImfOutputWritePixels(file, h);
    if (!ok)
        st = rl_error(RL_ERR_IO, "%s: cannot write EXR: %s", path, ImfErrorMessage());
    if (!ImfCloseOutputFile(file) && ok)
        st = rl_error(RL_ERR_IO, "%s: cannot write EXR: %s", path, ImfErrorMessage());
    free(px);
    if (st != RL_OK) {
        rl_output_abort(o);
        return st;
    }
    return rl_output_commit(o);
}

static int32_t le32(const unsigned char *b)
{
    return (int32_t)((uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24);
}

/* The chunks of a single-part scan-line file, behind the header at the
 * stream's position: each one's declared size fits in the file (OpenEXR
 * allocates that size before reading it). */
static rl_status check_exr_chunks(FILE *f, const char *path, off_t length, long long height, int compression)
{
    /* Scan lines per chunk by compression (OpenEXR's order: none, RLE,
     * ZIPS, ZIP, PIZ, PXR24, B44, B44A, DWAA, DWAB). */
    static const int lines[] = { 1, 1, 1, 16, 32, 16, 32, 32, 32, 256 };
    if (compression < 0 || compression >= (int)(sizeof lines / sizeof lines[0]))
        return rl_error(RL_ERR_PARSE, "%s: invalid EXR: unknown compression %d", path, compression);
    long long chunks = (height + lines[compression] - 1) / lines[compression];
    off_t table = ftello(f);
    if (table < 0 || chunks * 8 > (long long)(length - table))
        return rl_error(RL_ERR_PARSE, "%s: invalid EXR: the chunk table is longer than the file", path);
    for (long long i = 0; i < chunks; ++i) {
        unsigned char b[8];
        if (fseeko(f, table + 8 * (off_t)i, SEEK_SET) != 0 || fread(b, 1, 8, f) != 8)
            return rl_error(RL_ERR_PARSE, "%s: invalid EXR: the chunk table ends early", path);
        uint64_t offset = (uint64_t)(uint32_t)le32(b) | (uint64_t)(uint32_t)le32(b + 4) << 32;
        if (offset < (uint64_t)table + 8 * (uint64_t)chunks || offset > (uint64_t)length - 8)
            return rl_error(RL_ERR_PARSE, "%s: invalid EXR: chunk %lld lies outside the file", path, i);
        if (fseeko(f, (off_t)offset + 4, SEEK_SET) != 0 || fread(b, 1, 4, f) != 4)
            return rl_error(RL_ERR_PARSE, "%s: invalid EXR: chunk %lld ends early", path, i);
        int32_t size = le32(b);
        if (size < 0 || (uint64_t)size > (uint64_t)length - offset - 8)
            return rl_error(RL_ERR_PARSE, "%s: invalid EXR: chunk %lld of %d bytes, longer than the file", path, i,
                            (int)size);
    }
    return RL_OK;
}

/* OpenEXR allocates each header attribute and each chunk at the size the
 * file declares before reading it, and sizes its chunk table by the data
 * window: a few bytes could claim gigabytes (issue 34, found by
 * tests/fuzz/fuzz_texture.c). Walks the attributes of every header
 * (several in a multi-part file) and refuses one longer than the rest of
 * the file, a missing data window or one beyond the picture limits or
 * than the file can hold, and, in a single-part scan-line file, a chunk
 * longer than the file, before OpenEXR sees any of it. */
static rl_status check_exr(FILE *f, const char *path)
{
    if (fseeko(f, 0, SEEK_END) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot seek", path);
    off_t length = ftello(f);
    unsigned char head[8];
    if (fseeko(f, 0, SEEK_SET) != 0 || fread(head, 1, 8, f) != 8)
        return rl_error(RL_ERR_PARSE, "%s: invalid EXR: too short", path);
    bool tiled = head[5] & 0x02, deep = head[5] & 0x08, multipart = head[5] & 0x10;
    long long height = -1;
    int compression = -1;
    for (int attributes = 0;; ++attributes) {
        char text[2][257];
        for (int t = 0; t < 2; ++t) {
            int n = 0, c;
            while ((c = fgetc(f)) > 0 && n < 256)
                text[t][n++] = (char)c;
            text[t][n] = '\0';
            if (c != 0)
                return rl_error(RL_ERR_PARSE, "%s: invalid EXR: header ends early or names too long", path);
            if (t == 0 && n == 0)
                break;                      /* the end of a header */
        }
        if (!text[0][0]) {
            if (height < 0)
                return rl_error(RL_ERR_PARSE, "%s: invalid EXR: no dataWindow", path);
            if (!multipart && !tiled && !deep)
                return check_exr_chunks(f, path, length, height, compression);
            /* A multi-part file's headers end with an empty one. */
            if (!multipart || attributes == 0)
                return RL_OK;
            attributes = -1;
            height = -1;
            continue;
        }
        unsigned char b[4];
        if (fread(b, 1, 4, f) != 4)
            return rl_error(RL_ERR_PARSE, "%s: invalid EXR: header ends early", path);
        int32_t size = le32(b);
        off_t at = ftello(f);
        if (size < 0 || at < 0 || (off_t)size > length - at)
            return rl_error(RL_ERR_PARSE, "%s: invalid EXR: attribute \"%s\" of %d bytes, longer than the file",
                            path, text[0], (int)size);
        if (strcmp(text[0], "dataWindow") == 0 && size == 16) {
            unsigned char v[16];
            if (fread(v, 1, 16, f) != 16)
                return rl_error(RL_ERR_PARSE, "%s: invalid EXR: header ends early", path);
            long long w = (long long)le32(v + 8) - le32(v) + 1;
            height = (long long)le32(v + 12) - le32(v + 4) + 1;
            rl_status st = rl_image_check_size(path, w, height);
            if (st == RL_OK)
                st = rl_image_check_file_size(path, w, height, 2.0);   /* one half-float channel at least */
            if (st != RL_OK)
                return st;
            continue;
        }
        if (strcmp(text[0], "compression") == 0 && size == 1) {
            compression = fgetc(f);
            continue;
        }
        if (fseeko(f, size, SEEK_CUR) != 0)
            return rl_error(RL_ERR_IO, "%s: cannot seek", path);
    }
}

/* path opened by OpenEXR after our own walk of its header and chunk
 * table (check_exr); ImfOpenInputFile's message for a missing file is
 * terse, so that is checked first too. */
static rl_status open_exr(const char *path, ImfInputFile **out)
{
    FILE *probe = fopen(path, "rb");
    if (!probe)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    rl_status checked = check_exr(probe, path);
    fclose(probe);
    if (checked != RL_OK)
        return checked;
    if (!(*out = ImfOpenInputFile(path)))
        return rl_error(RL_ERR_PARSE, "%s: invalid EXR: %s", path, ImfErrorMessage());
    return RL_OK;
}

rl_status rl_image_exr_size(const char *path, long long *width, long long *height)
{
    ImfInputFile *file = NULL;
    rl_status opened = open_exr(path, &file);
    if (opened != RL_OK)
        return opened;
    int x0, y0, x1, y1;
    ImfHeaderDataWindow(ImfInputHeader(file), &x0, &y0, &x1, &y1);
    ImfCloseInputFile(file);
    *width = (long long)x1 - x0 + 1;
    *height = (long long)y1 - y0 + 1;
    return RL_OK;
}

rl_status rl_image_read_exr(const char *path, rl_image **out)
{
    ImfInputFile *file = NULL;
    rl_status opened = open_exr(path, &file);
    if (opened != RL_OK)
        return opened;
    int x0, y0, x1, y1;
    ImfHeaderDataWindow(ImfInputHeader(file), &x0, &y0, &x1, &y1);
    long long w = (long long)x1 - x0 + 1, h = (long long)y1 - y0 + 1;
    rl_status st = rl_image_check_size(path, w, h);     /* checked before OpenEXR too */
    if (st != RL_OK) {
        ImfCloseInputFile(file);
        return st;
    }
    rl_image *img = NULL;
    ImfRgba *px = rl_calloc((size_t)(w * h), sizeof *px);
    if (!px || (st = rl_image_create((int)w, (int)h, RL_LAYER_COLOR, &img)) != RL_OK) {
        free(px);
        ImfCloseInputFile(file);
        return RL_ERR_OUT_OF_MEMORY;
    }
    /* The frame buffer base is the address of pixel (0,0) in data-window
     * coordinates, so it is offset by the window origin (usually zero). */
    ImfRgba *base = px - ((ptrdiff_t)x0 + (ptrdiff_t)y0 * (ptrdiff_t)w);
    if (!ImfInputSetFrameBuffer(file, base, 1, (size_t)w) || !ImfInputReadPixels(file, y0, y1)) {
        st = rl_error(RL_ERR_PARSE, "%s: invalid EXR: %s", path, ImfErrorMessage());
        free(px);
        rl_image_release(img);
        ImfCloseInputFile(file);
        return st;
    }
    ImfCloseInputFile(file);
    for (size_t i = 0; i < (size_t)(w * h); ++i)
        img->color[i] = rl_v4(ImfHalfToFloat(px[i].r), ImfHalfToFloat(px[i].g),
                              ImfHalfToFloat(px[i].b), ImfHalfToFloat(px[i].a));
    free(px);
    *out = img;
    return RL_OK;
}
