/* texture_sample.h: the bilinear, repeat-wrapped texture lookup behind
 * rl_texture_sample, inline so that the rasterizer's pixel loop can use it
 * without a call per fragment (the call and its AVX state change cost as
 * much as the lookup itself there).
 *
 * uv (0,0) is the bottom-left of the picture; texel centres sit at
 * half-integers. After reducing u and v to [0,1] the two texel indices of
 * each axis lie in [-1, n], so wrapping is one compare each, not a modulo. */
#ifndef RL_CORE_TEXTURE_SAMPLE_H
#define RL_CORE_TEXTURE_SAMPLE_H

#include <math.h>

#include "rl/rl_image.h"

/* The bilinear blend of texels (x0, y0), (x1, y0), (x0, y1), (x1, y1) with
 * weights w00, w10, w01, w11 (indices already wrapped). */
static inline __attribute__((always_inline)) rl_vec4
rl_texture_blend(const rl_texture *tex, int x0, int x1, int y0, int y1, float w00, float w10,
                 float w01, float w11)
{
    const rl_vec4 *row0 = tex->texels + (size_t)y0 * (size_t)tex->width;
    const rl_vec4 *row1 = tex->texels + (size_t)y1 * (size_t)tex->width;
    rl_vec4 a = row0[x0], b = row0[x1], c = row1[x0], d = row1[x1];
    return rl_v4(w00 * a.x + w10 * b.x + w01 * c.x + w11 * d.x,
                 w00 * a.y + w10 * b.y + w01 * c.y + w11 * d.y,
                 w00 * a.z + w10 * b.z + w01 * c.z + w11 * d.z,
                 w00 * a.w + w10 * b.w + w01 * c.w + w11 * d.w);
}

static inline __attribute__((always_inline)) rl_vec4
rl_texture_sample_inline(const rl_texture *tex, rl_vec2 uv)
{
    float u = uv.x, v = uv.y;
    /* Reduce first: keeps huge or NaN coordinates in integer range. u - floor(u)
     * lies in [0,1]: it rounds to 1 for tiny negative u. */
    u = isfinite(u) ? u - floorf(u) : 0.0f;
    v = isfinite(v) ? v - floorf(v) : 0.0f;
    const int w = tex->width, h = tex->height;
    float fx = u * (float)w - 0.5f;
    float fy = (1.0f - v) * (float)h - 0.5f;
    float x0f = floorf(fx), y0f = floorf(fy);
    float tx = fx - x0f, ty = fy - y0f;
    int x0 = (int)x0f, y0 = (int)y0f;   /* in [-1, n - 1] */
    int x1 = x0 + 1, y1 = y0 + 1;       /* in [0, n] */
    x0 += x0 < 0 ? w : 0;
    y0 += y0 < 0 ? h : 0;
    x1 -= x1 >= w ? w : 0;
    y1 -= y1 >= h ? h : 0;
    return rl_texture_blend(tex, x0, x1, y0, y1, (1 - tx) * (1 - ty), tx * (1 - ty),
                            (1 - tx) * ty, tx * ty);
}

#endif
