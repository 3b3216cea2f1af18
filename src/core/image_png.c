/* image_png.c: PNG output (8-bit sRGB RGBA) and input (8/16-bit, any colour
 * type) through libpng. libpng reports errors by longjmp; its default
 * handlers print to stderr, so we install our own that keep the message for
 * rl_error() and stay silent on warnings. Colour is encoded with the exact
 * sRGB curve and rounded to nearest so that 8-bit values survive a
 * read/write round trip; alpha is stored linearly as PNG requires. */
#include "rl/rl_image.h"
#include "rl/rl_output.h"

#include <errno.h>
#include <math.h>
#include <png.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/image_internal.h"

typedef struct png_ctx {
    char message[256];
    FILE *file;
    rl_output *output;          /* writing: file is its stream */
    png_structp png;
    png_infop info;
    unsigned char *pixels;
    png_bytep *rows;
    rl_image *img;
} png_ctx;

static void on_png_error(png_structp png, png_const_charp msg)
{
    png_ctx *ctx = png_get_error_ptr(png);
    snprintf(ctx->message, sizeof ctx->message, "%s", msg);
    png_longjmp(png, 1);
}

/* libpng's own writer reports a failed write as "Write Error"; ours keeps
 * the reason (disk full, file too large). */
static void on_png_write(png_structp png, png_bytep data, png_size_t n)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (fwrite(data, 1, n, ctx->file) != n)
        png_error(png, strerror(errno));
}

static void on_png_flush(png_structp png)
{
    png_ctx *ctx = png_get_io_ptr(png);
    if (fflush(ctx->file) != 0)
        png_error(png, strerror(errno));
}

static void on_png_warning(png_structp png, png_const_charp msg)
{
    (void)png;
    rl_debug("libpng: %s", msg);
}

/* Linear float -> 8-bit sRGB; NaN -> 0 because it marks a renderer bug and a
 * black pixel is easier to spot than a saturated one. */
static unsigned char encode_srgb(float c)
{
    if (!(c > 0.0f))
        return 0;
    if (c >= 1.0f)
        return 255;
    return (unsigned char)lrintf(rl_linear_to_srgb(c) * 255.0f);
}

static unsigned char encode_linear(float c)
{
    if (!(c > 0.0f))
        return 0;
    if (c >= 1.0f)
        return 255;
    return (unsigned char)lrintf(c * 255.0f);
}

static void png_ctx_free(png_ctx *ctx, bool reading)
{
    if (reading)
        png_destroy_read_struct(&ctx->png, ctx->info ? &ctx->info : NULL, NULL);
    else
        png_destroy_write_struct(&ctx->png, ctx->info ? &ctx->info : NULL);
    if (ctx->output)
        rl_output_abort(ctx->output);
    else if (ctx->file)
        fclose(ctx->file);
    free(ctx->pixels);
    free(ctx->rows);
    rl_image_release(ctx->img);
}

rl_status rl_image_write_png(const rl_image *img, const char *path)
{
    rl_status st = rl_image_check_writable(img, "rl_image_write_png", path);
    if (st != RL_OK)
        return st;
    int w = img->width, h = img->height;
    /* Encode first so that a failed allocation never leaves a truncated file. */
    png_ctx *ctx = rl_calloc(1, sizeof *ctx);
    if (!ctx)
        return RL_ERR_OUT_OF_MEMORY;
    ctx->pixels = rl_calloc((size_t)w * (size_t)h, 4);
    ctx->rows = rl_calloc((size_t)h, sizeof *ctx->rows);
    if (!ctx->pixels || !ctx->rows) {
        png_ctx_free(ctx, false);
        free(ctx);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (int y = 0; y < h; ++y) {
        unsigned char *row = ctx->pixels + (size_t)y * (size_t)w * 4;
        ctx->rows[y] = row;
        for (int x = 0; x < w; ++x) {
            rl_vec4 c = img->color[(size_t)y * w + x];
            row[4 * x + 0] = encode_srgb(c.x);
            row[4 * x + 1] = encode_srgb(c.y);
            row[4 * x + 2] = encode_srgb(c.z);
            row[4 * x + 3] = encode_linear(c.w);
        }
    }
    st = rl_output_open(path, &ctx->output);
    if (st != RL_OK) {
        png_ctx_free(ctx, false);
        free(ctx);
        return st;
    }
    ctx->file = rl_output_file(ctx->output);
    ctx->png = png_create_write_struct(PNG_LIBPNG_VER_STRING, ctx, on_png_error, on_png_warning);
    if (ctx->png)
        ctx->info = png_create_info_struct(ctx->png);
    if (!ctx->png || !ctx->info) {
        png_ctx_free(ctx, false);
        free(ctx);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: cannot create libpng writer", path);
    }
    if (setjmp(png_jmpbuf(ctx->png))) {
        st = rl_error(RL_ERR_IO, "%s: cannot write PNG: %s", path, ctx->message);
        png_ctx_free(ctx, false);
        free(ctx);
        return st;
    }
    png_set_write_fn(ctx->png, ctx, on_png_write, on_png_flush);
    png_set_IHDR(ctx->png, ctx->info, (png_uint_32)w, (png_uint_32)h, 8, PNG_COLOR_TYPE_RGBA,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(ctx->png, ctx->info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(ctx->png, ctx->info);
    png_write_image(ctx->png, ctx->rows);
    png_write_end(ctx->png, NULL);
    rl_output *o = ctx->output;
    ctx->output = NULL;
    ctx->file = NULL;
    png_ctx_free(ctx, false);
    free(ctx);
    return rl_output_commit(o);
}

rl_status rl_image_read_png(const char *path, rl_image **out)
{
    png_ctx *ctx = rl_calloc(1, sizeof *ctx);
    if (!ctx)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st;
    ctx->file = fopen(path, "rb");
    if (!ctx->file) {
        st = rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
        free(ctx);
        return st;
    }
    unsigned char sig[8];
    if (fread(sig, 1, sizeof sig, ctx->file) != sizeof sig || png_sig_cmp(sig, 0, sizeof sig)) {
        png_ctx_free(ctx, true);
        free(ctx);
        return rl_error(RL_ERR_PARSE, "%s: not a PNG file", path);
    }
    ctx->png = png_create_read_struct(PNG_LIBPNG_VER_STRING, ctx, on_png_error, on_png_warning);
    if (ctx->png)
        ctx->info = png_create_info_struct(ctx->png);
    if (!ctx->png || !ctx->info) {
        png_ctx_free(ctx, true);
        free(ctx);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: cannot create libpng reader", path);
    }
    if (setjmp(png_jmpbuf(ctx->png))) {
        st = rl_error(RL_ERR_PARSE, "%s: invalid PNG: %s", path, ctx->message);
        png_ctx_free(ctx, true);
        free(ctx);
        return st;
    }
    png_init_io(ctx->png, ctx->file);
    png_set_sig_bytes(ctx->png, sizeof sig);
    png_read_info(ctx->png, ctx->info);
    png_uint_32 w = png_get_image_width(ctx->png, ctx->info);
    png_uint_32 h = png_get_image_height(ctx->png, ctx->info);
    /* One bit (grey, depth 1) is the least a pixel stores. */
    if ((st = rl_image_check_size(path, w, h)) != RL_OK || (st = rl_image_check_file_size(path, w, h, 0.125)) != RL_OK) {
        png_ctx_free(ctx, true);
        free(ctx);
        return st;
    }
    int depth = png_get_bit_depth(ctx->png, ctx->info);
    int type = png_get_color_type(ctx->png, ctx->info);
    /* Normalise every colour type to RGBA at 8 or 16 bits. */
    png_set_expand(ctx->png);
    if (type == PNG_COLOR_TYPE_GRAY || type == PNG_COLOR_TYPE_GRAY_ALPHA)
        png_set_gray_to_rgb(ctx->png);
    if (!(type & PNG_COLOR_MASK_ALPHA) && !png_get_valid(ctx->png, ctx->info, PNG_INFO_tRNS))
        png_set_add_alpha(ctx->png, depth == 16 ? 0xFFFF : 0xFF, PNG_FILLER_AFTER);
    png_set_interlace_handling(ctx->png);
    png_read_update_info(ctx->png, ctx->info);
    int out_depth = png_get_bit_depth(ctx->png, ctx->info);
    size_t rowbytes = png_get_rowbytes(ctx->png, ctx->info);
    size_t bytes_per_px = out_depth == 16 ? 8 : 4;
    if (png_get_channels(ctx->png, ctx->info) != 4 || rowbytes != bytes_per_px * w) {
        png_ctx_free(ctx, true);
        free(ctx);
        return rl_error(RL_ERR_UNSUPPORTED, "%s: PNG layout not convertible to RGBA", path);
    }
    ctx->pixels = rl_calloc(h, rowbytes);
    ctx->rows = rl_calloc(h, sizeof *ctx->rows);
    if (!ctx->pixels || !ctx->rows || rl_image_create((int)w, (int)h, RL_LAYER_COLOR, &ctx->img) != RL_OK) {
        png_ctx_free(ctx, true);
        free(ctx);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (png_uint_32 y = 0; y < h; ++y)
        ctx->rows[y] = ctx->pixels + (size_t)y * rowbytes;
    png_read_image(ctx->png, ctx->rows);
    png_read_end(ctx->png, NULL);
    for (size_t i = 0; i < (size_t)w * h; ++i) {
        float v[4];
        for (int c = 0; c < 4; ++c) {
            if (out_depth == 16) {
                const unsigned char *p = ctx->pixels + 8 * i + 2 * c;  /* big-endian */
                v[c] = (float)((p[0] << 8) | p[1]) / 65535.0f;
            } else {
                v[c] = (float)ctx->pixels[4 * i + c] / 255.0f;
            }
        }
        ctx->img->color[i] = rl_v4(rl_srgb_to_linear(v[0]), rl_srgb_to_linear(v[1]),
                                   rl_srgb_to_linear(v[2]), v[3]);
    }
    *out = ctx->img;
    ctx->img = NULL;
    png_ctx_free(ctx, true);
    free(ctx);
    return RL_OK;
}
