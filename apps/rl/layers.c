/* layers.c: writes the depth and object-ID layers of a frame as pictures
 * (rl render --depth-out / --id-out), or fills a colour array with them
 * (rl view's L key). Files go through a temporary colour-only rl_image so
 * that rl_image_write() does the file formats. */
#include "cli.h"

#include <math.h>

/* rl_image_write_png() encodes linear colour as sRGB; handing it the
 * inverse makes the stored 8-bit value equal to v, so grey levels and false
 * colours come out exactly as chosen here. */
static float srgb_to_linear(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

/* The picture of a depth layer: raw (EXR) keeps the measurement; else the
 * nearest surface is white and the farthest still 10 % grey, so that it
 * differs from the black background. */
static void depth_picture(const rl_image *img, bool raw, rl_vec4 *out)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    float near = INFINITY, far = -INFINITY;
    for (size_t i = 0; i < n; i++)
        if (isfinite(img->depth[i])) {
            near = fminf(near, img->depth[i]);
            far = fmaxf(far, img->depth[i]);
        }
    float range = far > near ? far - near : 1.0f;
    for (size_t i = 0; i < n; i++) {
        float d = img->depth[i];
        bool hit = isfinite(d);
        float g;
        if (raw)
            g = d; /* EXR: the measurement itself (+inf where nothing was hit) */
        else
            g = hit ? srgb_to_linear(1.0f - 0.9f * (d - near) / range) : 0.0f;
        out[i] = (rl_vec4){ g, g, g, hit || !raw ? 1.0f : 0.0f };
    }
}

/* An integer hash (the "lowbias32" mixer by C. Wellons) spreads neighbouring
 * IDs to unrelated colours. */
static uint32_t hash_id(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352dU;
    x ^= x >> 15;
    x *= 0x846ca68bU;
    x ^= x >> 16;
    return x;
}

static void id_picture(const rl_image *img, rl_vec4 *out)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    for (size_t i = 0; i < n; i++) {
        uint32_t id = img->object_id[i];
        rl_vec4 c = { 0.0f, 0.0f, 0.0f, 1.0f };
        if (id != RL_ID_NONE) {
            uint32_t h = hash_id(id);
            /* Keep every channel >= 48 so no object is mistaken for "none". */
            c.x = srgb_to_linear((48 + (h & 0xff) * 207 / 255) / 255.0f);
            c.y = srgb_to_linear((48 + ((h >> 8) & 0xff) * 207 / 255) / 255.0f);
            c.z = srgb_to_linear((48 + ((h >> 16) & 0xff) * 207 / 255) / 255.0f);
        }
        out[i] = c;
    }
}

bool cli_layer_picture(const rl_image *img, cli_layer layer, rl_vec4 *out)
{
    if (layer == CLI_LAYER_DEPTH && img->depth)
        depth_picture(img, false, out);
    else if (layer == CLI_LAYER_IDS && img->object_id)
        id_picture(img, out);
    else
        return false;
    return true;
}

static rl_status write_picture(const rl_image *img, cli_layer layer, bool raw, const char *path)
{
    rl_image *out = NULL;
    rl_status st = rl_image_create(img->width, img->height, RL_LAYER_COLOR, &out);
    if (st != RL_OK)
        return st;
    if (layer == CLI_LAYER_DEPTH)
        depth_picture(img, raw, out->color);
    else
        id_picture(img, out->color);
    st = rl_image_write(out, path);
    rl_image_release(out);
    return st;
}

rl_status cli_write_depth(const rl_image *img, const char *path)
{
    if (!img->depth)
        return RL_ERR_INVALID_ARG;
    static const char *const exr[] = { ".exr", NULL };
    return write_picture(img, CLI_LAYER_DEPTH, cli_has_extension(path, exr), path);
}

rl_status cli_write_ids(const rl_image *img, const char *path)
{
    if (!img->object_id)
        return RL_ERR_INVALID_ARG;
    return write_picture(img, CLI_LAYER_IDS, false, path);
}
