/* image_exr.c: OpenEXR output and input (half-float linear RGBA) through
 * OpenEXR's C RGBA interface (ImfCRgbaFile.h). That interface catches the
 * library's C++ exceptions and reports them through ImfErrorMessage(), which
 * we forward into rl_error(). Values are stored unclamped, as EXR is meant
 * for HDR; half precision keeps about 3 significant decimal digits. */
#include "rl/rl_image.h"
#include "rl/rl_output.h"

#include <ImfCRgbaFile.h>
#include <errno.h>
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

rl_status rl_image_read_exr(const char *path, rl_image **out)
{
    /* ImfOpenInputFile's message for a missing file is terse; check first. */
    FILE *probe = fopen(path, "rb");
    if (!probe)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    fclose(probe);
    ImfInputFile *file = ImfOpenInputFile(path);
    if (!file)
        return rl_error(RL_ERR_PARSE, "%s: invalid EXR: %s", path, ImfErrorMessage());
    int x0, y0, x1, y1;
    ImfHeaderDataWindow(ImfInputHeader(file), &x0, &y0, &x1, &y1);
    long long w = (long long)x1 - x0 + 1, h = (long long)y1 - y0 + 1;
    rl_status st = rl_image_check_size(path, w, h);
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
