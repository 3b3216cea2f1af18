/* rl_image.h: the frame every renderer writes, and textures.
 *
 * An rl_image is a float RGBA colour buffer (linear, premultiplied alpha not
 * assumed) with optional per-pixel layers: depth (eye-space distance along
 * the view axis, +INFINITY where nothing was hit) and IDs (object ID and
 * triangle ID, RL_ID_NONE where nothing was hit). Pixel (0,0) is top-left;
 * rows are stored top to bottom.
 *
 * Output: PNG (8-bit sRGB, via libpng) and OpenEXR (half RGBA, via OpenEXR).
 * Input: PNG, JPEG and the other formats stb_image reads, for textures.
 * Limits: width and height in 1..RL_IMAGE_MAX_SIZE; anything larger is refused
 * with RL_ERR_LIMIT before allocating. */
#ifndef RL_IMAGE_H
#define RL_IMAGE_H

#include <stdint.h>
#include "rl/rl_common.h"
#include "rl/rl_math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_IMAGE_MAX_SIZE 16384
#define RL_ID_NONE 0xFFFFFFFFu

typedef enum rl_image_layers {
    RL_LAYER_COLOR = 1 << 0,
    RL_LAYER_DEPTH = 1 << 1,
    RL_LAYER_ID    = 1 << 2,   /* object_id and triangle_id */
} rl_image_layers;

typedef struct rl_image {
    int width, height;
    unsigned layers;          /* rl_image_layers present */
    rl_vec4 *color;           /* width*height, or NULL */
    float *depth;             /* width*height, or NULL */
    uint32_t *object_id;      /* width*height, or NULL */
    uint32_t *triangle_id;    /* width*height, or NULL */
} rl_image;

/* Bytes rl_image_create allocates for these layers (0 for unknown bits):
 * for an estimate before allocating a large frame. */
RL_API double rl_image_bytes(int width, int height, unsigned layers);
/* Allocates an image with the given layers, cleared (see rl_image_clear). */
RL_API rl_status rl_image_create(int width, int height, unsigned layers, rl_image **out);
RL_API void rl_image_release(rl_image *img);      /* NULL is a no-op */
/* Colour to (0,0,0,0), depth to +INFINITY, IDs to RL_ID_NONE. */
RL_API void rl_image_clear(rl_image *img);
/* rl_image_clear with the colour set to color (a background), in one pass. */
RL_API void rl_image_clear_to(rl_image *img, rl_vec4 color);
RL_API void rl_image_fill(rl_image *img, rl_vec4 color);
static inline rl_vec4 *rl_image_pixel(rl_image *img, int x, int y) { return &img->color[(size_t)y * img->width + x]; }

/* Writes colour by extension: ".png" (8-bit sRGB, alpha kept) or ".exr"
 * (half float linear RGBA). RL_ERR_UNSUPPORTED for other extensions,
 * RL_ERR_IO when the file cannot be written. */
RL_API rl_status rl_image_write(const rl_image *img, const char *path);
RL_API rl_status rl_image_write_png(const rl_image *img, const char *path);
RL_API rl_status rl_image_write_exr(const rl_image *img, const char *path);
/* Tone mapping: display colour in [0, 1] from linear radiance, for 8-bit
 * output. The exposure (in stops: colour times 2^exposure_ev) comes first,
 * then the operator. The PNG writer clamps to [0, 1] and encodes sRGB; it
 * does not tone map by itself, so a caller that wants an operator applies
 * it to a copy of the frame first (EXR output stays linear: it is for
 * further processing). Alpha is left alone; NaN stays NaN (the writer makes
 * it black, the sign of a renderer bug).
 *   none      clamp only: what the PNG writer did before tone mapping existed
 *   reinhard  Reinhard et al. 2002, eq. 3, L_d = L / (1 + L), on the
 *             luminance L (Rec. 709 weights); the colour is scaled by L_d / L,
 *             which keeps its hue and saturation (a saturated bright colour
 *             can still leave [0, 1] in one channel and is clamped). The
 *             paper's key scaling (eq. 1-2, log-average luminance) is left
 *             out: the exposure takes its place and keeps the mapping the
 *             same for every image.
 *   aces      the ACES filmic curve as fitted by Narkowicz 2015 ("ACES Filmic
 *             Tone Mapping Curve"), per channel:
 *             f(x) = x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped
 *             to [0, 1]; without the fit's 0.6 pre-exposure (use
 *             exposure_ev = log2(0.6) for it). */
typedef enum rl_tonemap_op {
    RL_TONEMAP_NONE = 0,
    RL_TONEMAP_REINHARD,
    RL_TONEMAP_ACES,
    RL_TONEMAP_COUNT
} rl_tonemap_op;

typedef struct rl_tonemap_desc {   /* zero = default: no exposure change, clamp */
    rl_tonemap_op op;
    double exposure_ev;            /* stops; finite */
} rl_tonemap_desc;

/* "none", "reinhard", "aces"; NULL for a value out of range. */
RL_API const char *rl_tonemap_name(rl_tonemap_op op);
/* The operator of a name; RL_ERR_INVALID_ARG (the message lists the names)
 * for an unknown one. */
RL_API rl_status rl_tonemap_parse(const char *name, rl_tonemap_op *out);
/* One linear RGB colour mapped to [0, 1]^3 (NaN channels stay NaN). desc
 * NULL = default. */
RL_API rl_vec3 rl_tonemap_rgb(rl_vec3 c, const rl_tonemap_desc *desc);
/* Maps img's colour layer in place. RL_ERR_INVALID_ARG for a NULL image,
 * one without a colour layer, an unknown operator or a non-finite exposure;
 * the image is untouched then. desc NULL = default. */
RL_API rl_status rl_image_tonemap(rl_image *img, const rl_tonemap_desc *desc);

/* Reads a PNG (8/16-bit) or EXR into a colour-only image, linear values
 * (PNG is decoded from sRGB). For round trips and tests. */
RL_API rl_status rl_image_read(const char *path, rl_image **out);

/* Textures: linear RGBA float texels, bilinear lookup with repeat wrapping. */
typedef struct rl_texture {
    int width, height;
    rl_vec4 *texels;          /* row 0 = top of the picture */
    char *path;               /* where it came from, or NULL */
} rl_texture;

/* Loads PNG/JPEG/BMP/TGA via stb_image; sRGB colour converted to linear. */
RL_API rl_status rl_texture_load(const char *path, rl_texture **out);
/* The largest texture (width x height) that loading decodes, read from the
 * file's header before any decoding: a small PNG can claim 16384 x 16384,
 * which is 4 GiB of float texels. Default RL_TEXTURE_MAX_PIXELS (8192 x
 * 8192, 1 GiB); larger files fail with RL_ERR_LIMIT. Process-wide; set it
 * before loading (not thread-safe against loads in flight). */
#define RL_TEXTURE_MAX_PIXELS (8192ull * 8192ull)
RL_API void rl_texture_set_max_pixels(unsigned long long pixels);
RL_API unsigned long long rl_texture_max_pixels(void);
/* RL_ERR_LIMIT (message naming what) unless 1 <= w, h <= RL_IMAGE_MAX_SIZE
 * and w x h <= rl_texture_max_pixels(). */
RL_API rl_status rl_texture_check_size(const char *what, long long w, long long h);
/* Loads high-dynamic-range pictures with their linear values: OpenEXR
 * (.exr) and Radiance RGBE (.hdr); anything else as rl_texture_load. The
 * size is checked against rl_texture_max_pixels() from the header, before
 * the pixels are decoded (RL_ERR_LIMIT). For environment maps. */
RL_API rl_status rl_texture_load_linear(const char *path, rl_texture **out);
/* Creates a texture from texels (copied). */
RL_API rl_status rl_texture_create(int width, int height, const rl_vec4 *texels, rl_texture **out);
RL_API void rl_texture_release(rl_texture *tex);
/* uv (0,0) is the bottom-left of the picture (OpenGL convention), repeat wrap. */
RL_API rl_vec4 rl_texture_sample(const rl_texture *tex, rl_vec2 uv);

#ifdef __cplusplus
}
#endif
#endif
