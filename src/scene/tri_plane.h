/* tri_plane.h: where a ray meets the plane of a scene triangle, for the
 * passes that know from a rasterized ID buffer which triangle a pixel shows
 * and need the point on it (pt's G-buffer, Schröder 2017, Sec. 8.1; the
 * per-pixel shading of normal-mapped surfaces in scene_drawer.c). */
#ifndef RL_SCENE_TRI_PLANE_H
#define RL_SCENE_TRI_PLANE_H

#include <math.h>

#include "rl/rl_math.h"
#include "rl/rl_scene.h"

/* The ray's intersection with the plane of triangle tri (Möller & Trumbore
 * 1997 without the inside test), barycentrics clamped onto the triangle:
 * the rasterizer's pixel centre may lie just outside the triangle it
 * covers. False only for a ray parallel to the plane or a hit behind it. */
static inline bool rl_tri_plane_hit(const rl_scene_data *d, uint32_t tri, const rl_ray *ray, float *t, float *u,
                                    float *v)
{
    const uint32_t *idx = &d->indices[3 * (size_t)tri];
    rl_vec3 p0 = d->positions[idx[0]];
    rl_vec3 e1 = rl_sub(d->positions[idx[1]], p0), e2 = rl_sub(d->positions[idx[2]], p0);
    rl_vec3 pv = rl_cross(ray->d, e2);
    float det = rl_dot(e1, pv);
    if (!(fabsf(det) > 0.0f))
        return false;
    float inv = 1.0f / det;
    rl_vec3 tv = rl_sub(ray->o, p0);
    float uu = rl_dot(tv, pv) * inv;
    rl_vec3 qv = rl_cross(tv, e1);
    float vv = rl_dot(ray->d, qv) * inv;
    *t = rl_dot(e2, qv) * inv;
    uu = rl_maxf(uu, 0.0f);
    vv = rl_maxf(vv, 0.0f);
    if (uu + vv > 1.0f) {
        float s = 1.0f / (uu + vv);
        uu *= s;
        vv *= s;
    }
    *u = uu;
    *v = vv;
    return isfinite(*t) && *t > 0.0f;
}

#endif
