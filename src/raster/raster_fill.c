/* raster_fill.c: the pixel loop: edge functions, depth test, attributes.
 *
 * Edge functions (Pineda 1988, "A parallel algorithm for polygon
 * rasterization") are evaluated exactly in int64 on 24.8 fixed-point
 * vertices and stepped incrementally; they decide coverage. Barycentrics
 * come from the unsnapped vertices (see rl_raster_prim). 1/w and
 * attribute/w are linear in screen space, so depth = 1 / (1/w) and
 * colour = (colour/w) / (1/w) are perspective-correct (Heckbert & Moreton
 * 1991, "Interpolation for polygon texture mapping and shading"). Draws and occlusion queries run this same code,
 * a query just has no layer to write, so their counts agree by construction. */
#include "raster/raster_internal.h"

static inline rl_vec4 mul4(rl_vec4 a, rl_vec4 b)
{
    return rl_v4(a.x * b.x, a.y * b.y, a.z * b.z, a.w * b.w);
}

static rl_vec4 shade(const rl_raster_prim *p, double l0, double l1, double l2, double inv_iw)
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

uint64_t rl_raster_fill_prim(const rl_raster_target *t, const rl_raster_prim *p,
                             int row0, int row1)
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
                if (!t->depth_test || zf < t->depth_test[pix]) {
                    ++passed;
                    if (t->depth)
                        t->depth[pix] = zf;
                    if (write_color)
                        t->color[pix] = shade(p, l0, l1, l2, inv_iw);
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

uint64_t rl_raster_fill_point(const rl_raster_target *t, const rl_raster_point *p,
                              int row0, int row1)
{
    const int y0 = p->y0 > row0 ? p->y0 : row0, y1 = p->y1 < row1 ? p->y1 : row1;
    uint64_t passed = 0;
    for (int y = y0; y < y1; ++y) {
        size_t pix = (size_t)y * (size_t)t->width + (size_t)p->x0;
        for (int x = p->x0; x < p->x1; ++x, ++pix) {
            if (t->depth_test && !(p->depth < t->depth_test[pix]))
                continue;
            ++passed;
            if (t->depth)
                t->depth[pix] = p->depth;
            if (t->color)
                t->color[pix] = p->color;
            if (t->object_id)
                t->object_id[pix] = p->object_id;
            if (t->triangle_id)
                t->triangle_id[pix] = p->point_id;
        }
    }
    return passed;
}
