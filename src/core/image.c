/* image.c: rl_image allocation, clearing and format dispatch by extension.
 * Sizes are checked against RL_IMAGE_MAX_SIZE before anything is allocated,
 * so a corrupt header or a typo on the command line cannot ask for 64 GiB. */
#define _POSIX_C_SOURCE 200809L
#include "rl/rl_image.h"

#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/error.h"
#include "rl/rl_path.h"
#include "core/image_internal.h"

rl_status rl_image_check_size(const char *what, long long width, long long height)
{
    if (width < 1 || height < 1 || width > RL_IMAGE_MAX_SIZE || height > RL_IMAGE_MAX_SIZE)
        return rl_error(RL_ERR_LIMIT, "%s: size %lldx%lld outside 1..%d per side", what,
                        width, height, RL_IMAGE_MAX_SIZE);
    return RL_OK;
}

rl_status rl_image_check_file_size(const char *path, long long width, long long height, double min_bytes_per_pixel)
{
    struct stat s;
    if (stat(path, &s) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    /* Deflate, the strongest compression either format uses, shrinks at
     * most 1032:1; 2048 leaves room for any header. */
    double least = (double)width * (double)height * min_bytes_per_pixel / 2048.0;
    if ((double)s.st_size < least)
        return rl_error(RL_ERR_PARSE, "%s: %lld bytes cannot hold a %lldx%lld picture (truncated or corrupt)", path,
                        (long long)s.st_size, width, height);
    return RL_OK;
}

double rl_image_bytes(int width, int height, unsigned layers)
{
    if (layers & ~(unsigned)(RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID))
        return 0.0;
    double per_pixel = ((layers & RL_LAYER_COLOR) ? sizeof(rl_vec4) : 0) + ((layers & RL_LAYER_DEPTH) ? sizeof(float) : 0) +
                       ((layers & RL_LAYER_ID) ? 2 * sizeof(uint32_t) : 0);
    return (double)width * (double)height * per_pixel;
}

rl_status rl_image_create(int width, int height, unsigned layers, rl_image **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_create: out is NULL");
    rl_status st = rl_image_check_size("rl_image_create", width, height);
    if (st != RL_OK)
        return st;
    if (layers & ~(unsigned)(RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID))
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_create: unknown layer bits 0x%x", layers);
    size_t n = (size_t)width * (size_t)height;
    rl_image *img = rl_calloc(1, sizeof *img);
    if (!img)
        return RL_ERR_OUT_OF_MEMORY;
    img->width = width;
    img->height = height;
    img->layers = layers;
    bool ok = true;
    if (layers & RL_LAYER_COLOR)
        ok = ok && (img->color = rl_calloc(n, sizeof *img->color)) != NULL;
    if (layers & RL_LAYER_DEPTH)
        ok = ok && (img->depth = rl_calloc(n, sizeof *img->depth)) != NULL;
    if (layers & RL_LAYER_ID) {
        ok = ok && (img->object_id = rl_calloc(n, sizeof *img->object_id)) != NULL;
        ok = ok && (img->triangle_id = rl_calloc(n, sizeof *img->triangle_id)) != NULL;
    }
    if (!ok) {
        rl_image_release(img);
        return RL_ERR_OUT_OF_MEMORY;
    }
    rl_image_clear(img);
    *out = img;
    return RL_OK;
}

void rl_image_release(rl_image *img)
{
    if (!img)
        return;
    free(img->color);
    free(img->depth);
    free(img->object_id);
    free(img->triangle_id);
    free(img);
}

/* Frames are cleared and filled once per render, at up to 16 MB of colour
 * each: in parallel above this many pixels (a nested call, inside another
 * parallel region, runs on its own thread). */
#define PARALLEL_PIXELS (1 << 16)

void rl_image_clear_to(rl_image *img, rl_vec4 background)
{
    if (!img)
        return;
    const int64_t n = (int64_t)img->width * (int64_t)img->height;
    rl_vec4 *color = img->color;
    float *depth = img->depth;
    uint32_t *object_id = img->object_id, *triangle_id = img->triangle_id;
    #pragma omp parallel for schedule(static) if (n >= PARALLEL_PIXELS)
    for (int64_t i = 0; i < n; ++i) {
        if (color)
            color[i] = background;
        if (depth)
            depth[i] = INFINITY;
        if (object_id)
            object_id[i] = RL_ID_NONE;
        if (triangle_id)
            triangle_id[i] = RL_ID_NONE;
    }
}

void rl_image_clear(rl_image *img)
{
    rl_image_clear_to(img, rl_v4(0.0f, 0.0f, 0.0f, 0.0f));
}

void rl_image_fill(rl_image *img, rl_vec4 color)
{
    if (!img || !img->color)
        return;
    const int64_t n = (int64_t)img->width * (int64_t)img->height;
    rl_vec4 *c = img->color;
    #pragma omp parallel for schedule(static) if (n >= PARALLEL_PIXELS)
    for (int64_t i = 0; i < n; ++i)
        c[i] = color;
}

static const char *extension_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    const char *dot = strrchr(path, '.');
    return dot && (!slash || dot > slash) ? dot : "";
}

rl_status rl_image_check_writable(const rl_image *img, const char *who, const char *path)
{
    if (!img || !path)
        return rl_error(RL_ERR_INVALID_ARG, "%s: image or path is NULL", who);
    if (!img->color)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %s: image has no colour layer", who, path);
    return rl_image_check_size(path, img->width, img->height);
}

rl_status rl_image_write(const rl_image *img, const char *path)
{
    if (!img || !path)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_write: image or path is NULL");
    if (rl_path_has_ext(path, ".png"))
        return rl_image_write_png(img, path);
    if (rl_path_has_ext(path, ".exr"))
        return rl_image_write_exr(img, path);
    const char *ext = extension_of(path);
    return rl_error(RL_ERR_UNSUPPORTED,
                    "%s: unsupported image extension \"%s\" (accepted: .png, .exr)", path,
                    *ext ? ext : "(none)");
}

rl_status rl_image_read(const char *path, rl_image **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_read: path or out is NULL");
    if (rl_path_has_ext(path, ".exr"))
        return rl_image_read_exr(path, out);
    /* Anything else is sniffed by libpng, which names what it found. */
    return rl_image_read_png(path, out);
}
