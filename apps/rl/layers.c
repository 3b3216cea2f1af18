/* layers.c: writes the depth and object-ID layers of a frame as pictures
 * (rl render --depth-out / --id-out). Both go through a temporary colour-only
 * rl_image so that rl_image_write() does the file formats. */
#include "cli.h"

#include <math.h>

/* rl_image_write_png() encodes linear colour as sRGB; handing it the
 * inverse makes the stored 8-bit value equal to v, so grey levels and false
 * colours come out exactly as chosen here. */
static float srgb_to_linear(float v)
{
    return v <= 0.04045f ? v / 12.92f : powf((v + 0.055f) / 1.055f, 2.4f);
}

rl_status cli_write_depth(const rl_image *img, const char *path)
{
    if (!img->depth)
        return RL_ERR_INVALID_ARG;
    static const char *const exr[] = { ".exr", NULL };
    bool raw = cli_has_extension(path, exr);
    size_t n = (size_t)img->width * (size_t)img->height;
    float near = INFINITY, far = -INFINITY;
    for (size_t i = 0; i < n; i++)
        if (isfinite(img->depth[i])) {
            near = fminf(near, img->depth[i]);
            far = fmaxf(far, img->depth[i]);
        }
    rl_image *out = NULL;
    rl_status st = rl_image_create(img->width, img->height, RL_LAYER_COLOR, &out);
    if (st != RL_OK)
        return st;
    float range = far > near ? far - near : 1.0f;
    for (size_t i = 0; i < n; i++) {
        float d = img->depth[i];
        bool hit = isfinite(d);
        float g;
        if (raw)
            g = d; /* EXR: the measurement itself (+inf where nothing was hit) */
        else
            /* Nearest white, farthest still 10% grey so it differs from the
             * black background. */
            g = hit ? srgb_to_linear(1.0f - 0.9f * (d - near) / range) : 0.0f;
        out->color[i] = (rl_vec4){ g, g, g, hit || !raw ? 1.0f : 0.0f };
    }
    st = rl_image_write(out, path);
    rl_image_release(out);
    return st;
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

rl_status cli_write_ids(const rl_image *img, const char *path)
{
    if (!img->object_id)
        return RL_ERR_INVALID_ARG;
    rl_image *out = NULL;
    rl_status st = rl_image_create(img->width, img->height, RL_LAYER_COLOR, &out);
    if (st != RL_OK)
        return st;
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
        out->color[i] = c;
    }
    st = rl_image_write(out, path);
    rl_image_release(out);
    return st;
}
