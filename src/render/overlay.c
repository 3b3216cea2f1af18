/* overlay.c: see overlay.h. */
#include "render/overlay.h"

#include <math.h>

void rl_overlay_plot(rl_image *img, int x, int y, rl_vec4 c)
{
    if (x >= 0 && y >= 0 && x < img->width && y < img->height)
        img->color[(size_t)y * (size_t)img->width + (size_t)x] = c;
}

/* A DDA is enough for a diagnostic wireframe. The part outside the image
 * is skipped by steps, not clipped: a line is never longer than 1e5 px
 * here (longer ones are dropped as degenerate). */
void rl_overlay_line(rl_image *img, float x0, float y0, float x1, float y1, rl_vec4 c)
{
    float dx = x1 - x0, dy = y1 - y0;
    float steps = fmaxf(fabsf(dx), fabsf(dy));
    if (!(steps < 1e5f))
        return;
    int n = (int)ceilf(steps);
    for (int i = 0; i <= n; ++i) {
        float t = n ? (float)i / (float)n : 0.0f;
        rl_overlay_plot(img, (int)floorf(x0 + t * dx), (int)floorf(y0 + t * dy), c);
    }
}

static rl_vec4 to_clip(const rl_mat4 *m, rl_vec3 p)
{
    return rl_v4(m->m[0][0] * p.x + m->m[0][1] * p.y + m->m[0][2] * p.z + m->m[0][3],
                 m->m[1][0] * p.x + m->m[1][1] * p.y + m->m[1][2] * p.z + m->m[1][3],
                 m->m[2][0] * p.x + m->m[2][1] * p.y + m->m[2][2] * p.z + m->m[2][3],
                 m->m[3][0] * p.x + m->m[3][1] * p.y + m->m[3][2] * p.z + m->m[3][3]);
}

static rl_vec4 lerp4(rl_vec4 a, rl_vec4 b, float t)
{
    return rl_v4(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t, a.w + (b.w - a.w) * t);
}

void rl_overlay_box(rl_image *img, const rl_mat4 *view_proj, float w_min, rl_aabb b, rl_vec4 c)
{
    rl_vec4 q[8];
    for (int k = 0; k < 8; ++k)
        q[k] = to_clip(view_proj, rl_v3(k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y,
                                        k & 4 ? b.max.z : b.min.z));
    /* The 12 edges join corners that differ in one bit. */
    for (int k = 0; k < 8; ++k)
        for (int bit = 1; bit < 8; bit <<= 1) {
            if (k & bit)
                continue;
            rl_vec4 p = q[k], r = q[k | bit];
            if (p.w < w_min && r.w < w_min)
                continue;
            if (p.w < w_min)
                p = lerp4(p, r, (w_min - p.w) / (r.w - p.w));
            else if (r.w < w_min)
                r = lerp4(r, p, (w_min - r.w) / (p.w - r.w));
            float x0 = (p.x / p.w + 1.0f) * 0.5f * (float)img->width;
            float y0 = (1.0f - p.y / p.w) * 0.5f * (float)img->height;
            float x1 = (r.x / r.w + 1.0f) * 0.5f * (float)img->width;
            float y1 = (1.0f - r.y / r.w) * 0.5f * (float)img->height;
            rl_overlay_line(img, x0, y0, x1, y1, c);
        }
}
