/* texture.c: image textures for shading. Decoding is stb_image's (PNG, JPEG,
 * BMP, TGA, ...); 8- and 16-bit colour is converted from sRGB to linear with
 * the exact curve (stbi_loadf would apply a plain 2.2 gamma), alpha is kept
 * linear. Texels are stored top row first like the picture; sampling flips v
 * so that uv (0,0) is the bottom-left (OpenGL convention), with bilinear
 * filtering between texel centres and repeat wrapping. */
#include "rl/rl_image.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <stb/stb_image.h>

#include "core/error.h"
#include "core/image_internal.h"
#include "core/texture_sample.h"
#include "rl/rl_path.h"

static unsigned long long max_pixels = RL_TEXTURE_MAX_PIXELS;

void rl_texture_set_max_pixels(unsigned long long pixels)
{
    max_pixels = pixels ? pixels : RL_TEXTURE_MAX_PIXELS;
}

unsigned long long rl_texture_max_pixels(void) { return max_pixels; }

rl_status rl_texture_check_size(const char *what, long long w, long long h)
{
    if (w < 1 || h < 1 || w > RL_IMAGE_MAX_SIZE || h > RL_IMAGE_MAX_SIZE)
        return rl_error(RL_ERR_LIMIT, "%s: texture size %lldx%lld outside 1..%d per side", what,
                        w, h, RL_IMAGE_MAX_SIZE);
    if ((unsigned long long)w * (unsigned long long)h > max_pixels)
        return rl_error(RL_ERR_LIMIT, "%s: texture of %lldx%lld pixels exceeds the limit of %llu "
                        "(%.0f MiB as float texels; rl_texture_set_max_pixels)", what, w, h, max_pixels,
                        (double)w * (double)h * 16.0 / (1024.0 * 1024.0));
    return RL_OK;
}

/* Allocates the texture and its texel array; path may be NULL. */
static rl_status texture_alloc(int w, int h, const char *path, rl_texture **out)
{
    rl_texture *tex = rl_calloc(1, sizeof *tex);
    if (!tex)
        return RL_ERR_OUT_OF_MEMORY;
    tex->width = w;
    tex->height = h;
    tex->texels = rl_calloc((size_t)w * (size_t)h, sizeof *tex->texels);
    if (tex->texels && path)
        tex->path = rl_strdup(path);
    if (!tex->texels || (path && !tex->path)) {
        rl_texture_release(tex);
        return RL_ERR_OUT_OF_MEMORY;
    }
    *out = tex;
    return RL_OK;
}

/* stb_image grows its buffer to a PNG chunk's declared length before it
 * reads the chunk: 200 bytes claiming a 2 GB chunk cost 2 GB (issue 34,
 * found by tests/fuzz/fuzz_texture.c). Every chunk must fit in the bytes
 * that follow its header; len bytes of data (the whole file or an embedded
 * picture) start with the PNG signature, others pass. next(user, at, 8)
 * reads the 8 bytes of a chunk header at offset at. */
static rl_status check_png_chunks(uint64_t len, bool (*next)(void *user, uint64_t at, unsigned char *b), void *user,
                                  const char *what)
{
    static const unsigned char sig[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
    unsigned char b[8];
    if (len < 8 || !next(user, 0, b) || memcmp(b, sig, 8) != 0)
        return RL_OK;
    for (uint64_t at = 8; at + 8 <= len; ) {
        if (!next(user, at, b))
            return rl_error(RL_ERR_IO, "%s: cannot read", what);
        uint64_t n = (uint64_t)b[0] << 24 | (uint64_t)b[1] << 16 | (uint64_t)b[2] << 8 | b[3];
        if (n > len - at - 8)
            return rl_error(RL_ERR_PARSE, "%s: PNG chunk \"%.4s\" of %llu bytes, longer than the file", what,
                            (const char *)b + 4, (unsigned long long)n);
        if (memcmp(b + 4, "IEND", 4) == 0)
            break;
        at += 12 + n;
    }
    return RL_OK;
}

static bool file_chunk_header(void *user, uint64_t at, unsigned char *b)
{
    FILE *f = user;
    return fseek(f, (long)at, SEEK_SET) == 0 && fread(b, 1, 8, f) == 8;
}

typedef struct bytes_view { const unsigned char *p; size_t n; } bytes_view;

static bool memory_chunk_header(void *user, uint64_t at, unsigned char *b)
{
    const bytes_view *v = user;
    if (at + 8 > v->n)
        return false;
    memcpy(b, v->p + at, 8);
    return true;
}

rl_status rl_texture_check_png_memory(const unsigned char *data, size_t len, const char *what)
{
    bytes_view v = { data, len };
    return check_png_chunks(len, memory_chunk_header, &v, what);
}

rl_status rl_texture_load(const char *path, rl_texture **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_texture_load: path or out is NULL");
    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    long len = fseek(f, 0, SEEK_END) == 0 ? ftell(f) : -1;
    rl_status checked = len < 0 ? rl_error(RL_ERR_IO, "%s: cannot seek", path)
                                : check_png_chunks((uint64_t)len, file_chunk_header, f, path);
    if (checked != RL_OK || fseek(f, 0, SEEK_SET) != 0) {
        fclose(f);
        return checked != RL_OK ? checked : rl_error(RL_ERR_IO, "%s: cannot seek", path);
    }
    /* Read the header only, so absurd sizes are refused before decoding. */
    int w = 0, h = 0, comp = 0;
    if (!stbi_info_from_file(f, &w, &h, &comp)) {
        fclose(f);
        return rl_error(RL_ERR_PARSE, "%s: cannot decode image: %s", path, stbi_failure_reason());
    }
    rl_status st = rl_texture_check_size(path, w, h);
    if (st != RL_OK) {
        fclose(f);
        return st;
    }
    bool wide = stbi_is_16_bit_from_file(f);
    void *data = wide ? (void *)stbi_load_from_file_16(f, &w, &h, &comp, 4)
                      : (void *)stbi_load_from_file(f, &w, &h, &comp, 4);
    fclose(f);
    if (!data)
        return rl_error(RL_ERR_PARSE, "%s: cannot decode image: %s", path, stbi_failure_reason());
    rl_texture *tex = NULL;
    if ((st = texture_alloc(w, h, path, &tex)) != RL_OK) {
        stbi_image_free(data);
        return st;
    }
    const float scale = wide ? 1.0f / 65535.0f : 1.0f / 255.0f;
    for (size_t i = 0; i < (size_t)w * h; ++i) {
        float v[4];
        for (int c = 0; c < 4; ++c)
            v[c] = scale * (wide ? (float)((const stbi_us *)data)[4 * i + c]
                                 : (float)((const stbi_uc *)data)[4 * i + c]);
        tex->texels[i] = rl_v4(rl_srgb_to_linear(v[0]), rl_srgb_to_linear(v[1]),
                               rl_srgb_to_linear(v[2]), v[3]);
    }
    stbi_image_free(data);
    *out = tex;
    return RL_OK;
}

rl_status rl_texture_create(int width, int height, const rl_vec4 *texels, rl_texture **out)
{
    if (!texels || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_texture_create: texels or out is NULL");
    rl_status st = rl_texture_check_size("rl_texture_create", width, height);
    if (st != RL_OK)
        return st;
    rl_texture *tex = NULL;
    if ((st = texture_alloc(width, height, NULL, &tex)) != RL_OK)
        return st;
    memcpy(tex->texels, texels, (size_t)width * (size_t)height * sizeof *texels);
    *out = tex;
    return RL_OK;
}

void rl_texture_release(rl_texture *tex)
{
    if (!tex)
        return;
    free(tex->texels);
    free(tex->path);
    free(tex);
}

rl_vec4 rl_texture_sample(const rl_texture *tex, rl_vec2 uv)
{
    return rl_texture_sample_inline(tex, uv);
}

/* Radiance RGBE (.hdr): stb_image's float path returns its linear values
 * unchanged (the 2.2 gamma it applies is for LDR files only). */
static rl_status load_hdr(const char *path, rl_texture **out)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    int w = 0, h = 0, comp = 0;
    if (!stbi_is_hdr_from_file(f) || !stbi_info_from_file(f, &w, &h, &comp)) {
        fclose(f);
        return rl_error(RL_ERR_PARSE, "%s: not a Radiance HDR (RGBE) file", path);
    }
    rl_status st = rl_texture_check_size(path, w, h);
    if (st != RL_OK) {
        fclose(f);
        return st;
    }
    float *data = stbi_loadf_from_file(f, &w, &h, &comp, 4);
    fclose(f);
    if (!data)
        return rl_error(RL_ERR_PARSE, "%s: cannot decode image: %s", path, stbi_failure_reason());
    rl_texture *tex = NULL;
    if ((st = texture_alloc(w, h, path, &tex)) != RL_OK) {
        stbi_image_free(data);
        return st;
    }
    for (size_t i = 0; i < (size_t)w * h; ++i)
        tex->texels[i] = rl_v4(data[4 * i], data[4 * i + 1], data[4 * i + 2], 1.0f);
    stbi_image_free(data);
    *out = tex;
    return RL_OK;
}

rl_status rl_texture_load_linear(const char *path, rl_texture **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_texture_load_linear: path or out is NULL");
    if (rl_path_has_ext(path, ".hdr"))
        return load_hdr(path, out);
    if (!rl_path_has_ext(path, ".exr"))
        return rl_texture_load(path, out);
    long long w = 0, h = 0;
    rl_status st = rl_image_exr_size(path, &w, &h);
    if (st == RL_OK)
        st = rl_texture_check_size(path, w, h);   /* before the pixels are decoded */
    rl_image *img = NULL;
    if (st != RL_OK || (st = rl_image_read_exr(path, &img)) != RL_OK)
        return st;
    rl_texture *tex = NULL;
    if ((st = texture_alloc(img->width, img->height, path, &tex)) == RL_OK) {
        memcpy(tex->texels, img->color, (size_t)img->width * (size_t)img->height * sizeof *tex->texels);
        *out = tex;
    }
    rl_image_release(img);
    return st;
}
