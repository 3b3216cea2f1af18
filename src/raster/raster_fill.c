/* raster_fill.c: the pixel loop: edge functions, depth test, attributes.
 *
 * Edge functions (Pineda 1988, "A parallel algorithm for polygon
 * rasterization") are evaluated exactly in int64 on 24.8 fixed-point
 * vertices and stepped incrementally; they decide coverage. Barycentrics
 * come from the unsnapped vertices (see rl_raster_prim). 1/w and
 * attribute/w are linear in screen space, so depth = 1 / (1/w) and
 * colour = (colour/w) / (1/w) are perspective-correct (Heckbert & Moreton
 * 1991, "Interpolation for polygon texture mapping and shading"). Draws and
 * occlusion queries run this same code, a query just has no layer to write,
 * so their counts agree by construction.
 *
 * Multi-pass and multi-texturing for Vertex Tracing's reconstruction
 * (Ullmann 2003, Sec. 3.5.4, 3.5.5), done in one pass or several:
 *  - layers: the fragment is the sum over layers of colour x texel, where
 *    the thesis sums texture units in hardware (Sec. 3.5.5);
 *  - RL_RASTER_DEPTH_EQUAL + RL_RASTER_BLEND_ADD: a later pass over the same
 *    triangles adds its colour exactly where the first pass won (Sec. 3.5.4,
 *    glDepthFunc(GL_EQUAL) with additive blending). Exact equality is safe
 *    here, unlike on hardware with varying invariance: the same triangle with
 *    the same view and target goes through the same deterministic transform,
 *    clipping, setup and interpolation (no thread-dependent order, no FMA
 *    contraction in ISO C mode), so its fragments get bit-identical depth;
 *    a different, nearer triangle wrote a different depth there, and equal
 *    depth from another triangle is as rare as an exact tie. */
#include "raster/raster_internal.h"

static inline rl_vec4 mul4(rl_vec4 a, rl_vec4 b)
{
    return rl_v4(a.x * b.x, a.y * b.y, a.z * b.z, a.w * b.w);
}

static inline __attribute__((always_inline)) rl_vec4
shade(const rl_raster_prim *p, double l0, double l1, double l2, double inv_iw)
{
    rl_vec4 c = p->color;
    if (p->gouraud) {
        const rl_vec4 *a = p->cw;
        c = rl_v4((float)((l0 * a[0].x + l1 * a[1].x + l2 * a[2].x) * inv_iw),
                  (float)((l0 * a[0].y + l1 * a[1].y + l2 * a[2].y) * inv_iw),
                  (float)((l0 * a[0].z + l1 * a[1].z + l2 * a[2].z) * inv_iw),
                  (float)((l0 * a[0].w + l1 * a[1].w + l2 * a[2].w) * inv_iw));
    }
    if (p->tex) {
        const rl_vec2 *t = p->uvw;
        rl_vec2 uv = rl_v2((float)((l0 * t[0].x + l1 * t[1].x + l2 * t[2].x) * inv_iw),
                           (float)((l0 * t[0].y + l1 * t[1].y + l2 * t[2].y) * inv_iw));
        c = mul4(c, rl_texture_sample(p->tex, uv));
    }
    return c;
}

/* Ullmann 2003, Sec. 3.5.5: sum over layers of colour x texel, both read
 * from the batch at the source triangle's perspective-correct barycentrics;
 * alpha is layer 0's (interpolated, not modulated). */
static rl_vec4 shade_layers(const rl_raster_batch *b, const rl_raster_prim_src *src, double l0,
                            double l1, double l2, double inv_iw)
{
    const rl_vec3 *bw = src->bw;
    const double b0 = (l0 * bw[0].x + l1 * bw[1].x + l2 * bw[2].x) * inv_iw;
    const double b1 = (l0 * bw[0].y + l1 * bw[1].y + l2 * bw[2].y) * inv_iw;
    const double b2 = (l0 * bw[0].z + l1 * bw[1].z + l2 * bw[2].z) * inv_iw;
    const uint32_t *tri = &b->indices[3 * (size_t)src->triangle];
    const uint32_t i0 = tri[0], i1 = tri[1], i2 = tri[2];
    double sum_r = 0.0, sum_g = 0.0, sum_b = 0.0;
    float alpha = 0.0f;
    for (uint32_t i = 0; i < b->num_layers; ++i) {
        const rl_raster_layer *layer = &b->layers[i];
        const rl_vec4 *c = layer->colors;
        rl_vec4 col = rl_v4((float)(b0 * c[i0].x + b1 * c[i1].x + b2 * c[i2].x),
                            (float)(b0 * c[i0].y + b1 * c[i1].y + b2 * c[i2].y),
                            (float)(b0 * c[i0].z + b1 * c[i1].z + b2 * c[i2].z),
                            (float)(b0 * c[i0].w + b1 * c[i1].w + b2 * c[i2].w));
        if (i == 0)
            alpha = col.w;
        if (layer->uvs && layer->textures && layer->triangle_texture) {
            uint32_t ti = layer->triangle_texture[src->triangle];
            if (ti != RL_ID_NONE) {
                const rl_vec2 *uv = layer->uvs;
                rl_vec2 at = rl_v2((float)(b0 * uv[i0].x + b1 * uv[i1].x + b2 * uv[i2].x),
                                   (float)(b0 * uv[i0].y + b1 * uv[i1].y + b2 * uv[i2].y));
                col = mul4(col, rl_texture_sample(layer->textures[ti], at));
            }
        }
        sum_r += col.x;
        sum_g += col.y;
        sum_b += col.z;
    }
    return rl_v4((float)sum_r, (float)sum_g, (float)sum_b, alpha);
}

/* The pixel loop, compiled twice: plain (the common single pass, kept as
 * lean as before multi-pass existed) and multi (DEPTH_EQUAL, BLEND_ADD,
 * layers). Both run the same depth arithmetic, so a multi pass sees the
 * depth a plain pass wrote. */
static inline __attribute__((always_inline)) uint64_t
fill_prim(const rl_raster_target *t, const rl_raster_prim *p, const rl_raster_prim_src *src,
          int row0, int row1, const bool multi)
{
    const int y0 = p->y0 > row0 ? p->y0 : row0, y1 = p->y1 < row1 ? p->y1 : row1;
    const int64_t s = RL_RASTER_SUBPIXEL, half = RL_RASTER_SUBPIXEL / 2;
    /* Edge k runs from vertex k+1 to k+2 and is positive on the inside. */
    int64_t dx[3], dy[3], row_e[3];
    const int64_t px0 = p->x0 * s + half, py0 = y0 * s + half;
    for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        dx[k] = (int64_t)p->vx[b] - p->vx[a];
        dy[k] = (int64_t)p->vy[b] - p->vy[a];
        row_e[k] = dx[k] * (py0 - p->vy[a]) - dy[k] * (px0 - p->vx[a]) + p->bias[k];
    }
    const bool write_color = t->color != NULL;
    const bool depth_equal = multi && t->depth_equal;
    uint64_t passed = 0;
    for (int y = y0; y < y1; ++y) {
        int64_t e0 = row_e[0], e1 = row_e[1], e2 = row_e[2];
        const double cy = y + 0.5;
        const double r0 = p->ly[0] * cy + p->l0[0], r1 = p->ly[1] * cy + p->l0[1],
                     r2 = p->ly[2] * cy + p->l0[2];
        size_t pix = (size_t)y * (size_t)t->width + (size_t)p->x0;
        for (int x = p->x0; x < p->x1; ++x, ++pix) {
            if ((e0 | e1 | e2) >= 0) {
                const double cx = x + 0.5;
                double l0 = p->lx[0] * cx + r0, l1 = p->lx[1] * cx + r1, l2 = p->lx[2] * cx + r2;
                double iw = l0 * p->iw[0] + l1 * p->iw[1] + l2 * p->iw[2];
                double inv_iw = 1.0 / iw;
                double z = t->perspective ? inv_iw
                                          : (l0 * p->dw[0] + l1 * p->dw[1] + l2 * p->dw[2]) * inv_iw;
                float zf = (float)z;
                if (!t->depth_test ||
                    (depth_equal ? zf == t->depth_test[pix] : zf < t->depth_test[pix])) {
                    ++passed;
                    if (t->depth)
                        t->depth[pix] = zf;
                    if (write_color) {
                        rl_vec4 c = multi && t->layered
                                        ? shade_layers(t->layered, src, l0, l1, l2, inv_iw)
                                        : shade(p, l0, l1, l2, inv_iw);
                        if (multi && t->blend_add) {
                            rl_vec4 dst = t->color[pix];
                            c = rl_v4(dst.x + c.x, dst.y + c.y, dst.z + c.z, dst.w);
                        }
                        t->color[pix] = c;
                    }
                    if (t->object_id)
                        t->object_id[pix] = p->object_id;
                    if (t->triangle_id)
                        t->triangle_id[pix] = p->triangle_id;
                }
            }
            e0 -= dy[0] * s;
            e1 -= dy[1] * s;
            e2 -= dy[2] * s;
        }
        row_e[0] += dx[0] * s;
        row_e[1] += dx[1] * s;
        row_e[2] += dx[2] * s;
    }
    return passed;
}

uint64_t rl_raster_fill_prim(const rl_raster_target *t, const rl_raster_prim *p,
                             const rl_raster_prim_src *src, int row0, int row1)
{
    if (t->depth_equal || t->blend_add || t->layered)
        return fill_prim(t, p, src, row0, row1, true);
    return fill_prim(t, p, src, row0, row1, false);
}

uint64_t rl_raster_fill_point(const rl_raster_target *t, const rl_raster_point *p,
                              int row0, int row1)
{
    const int y0 = p->y0 > row0 ? p->y0 : row0, y1 = p->y1 < row1 ? p->y1 : row1;
    uint64_t passed = 0;
    for (int y = y0; y < y1; ++y) {
        size_t pix = (size_t)y * (size_t)t->width + (size_t)p->x0;
        for (int x = p->x0; x < p->x1; ++x, ++pix) {
            if (t->depth_test && !(t->depth_equal ? p->depth == t->depth_test[pix]
                                                  : p->depth < t->depth_test[pix]))
                continue;
            ++passed;
            if (t->depth)
                t->depth[pix] = p->depth;
            if (t->color) {
                rl_vec4 c = p->color, dst = t->color[pix];
                t->color[pix] = t->blend_add ? rl_v4(dst.x + c.x, dst.y + c.y, dst.z + c.z, dst.w)
                                             : c;
            }
            if (t->object_id)
                t->object_id[pix] = p->object_id;
            if (t->triangle_id)
                t->triangle_id[pix] = p->point_id;
        }
    }
    return passed;
}
