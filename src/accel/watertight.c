/* watertight.c: the watertight ray/triangle test of Woop, Benthin and Wald,
 * "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013, and the
 * reference code it lists.
 *
 * The ray is made the +z axis of a sheared space (axis permutation so that
 * kz is the largest |d| component, then a shear), which turns the test into
 * 2D edge functions U, V, W of the triangle's projected vertices around the
 * origin. Neighbouring triangles evaluate the same edge function for a shared
 * edge with exactly the same operands, so a ray can never slip between them.
 *
 * Choices (the paper leaves them open or we deviate):
 *   - no backface culling: a hit is all of U, V, W >= 0 or all <= 0;
 *   - an edge function that is exactly 0 in float is recomputed in double
 *     (the paper's fallback), so that rays through edges and vertices still
 *     get a consistent sign;
 *   - barycentrics follow rl_hit: U weights p0, V weights p1, W weights p2,
 *     so u = V/det and v = W/det give p = (1-u-v)·p0 + u·p1 + v·p2;
 *   - in contrast to the paper we accept a hit on the *divided* t
 *     (t_min < t < t_max). The paper's det-scaled comparison only serves as
 *     a conservative early reject. Acceptance thus depends on t alone, never
 *     on rounding in T·det, which makes every kind's closest hit
 *     independent of traversal order (ties: lowest triangle ID, see
 *     accel.c).
 * The test's body is in watertight.h (static inline) so that the hot loops
 * of brute.c and bvh_wide_traverse.c can inline it; this file exports it. */
#include "accel/watertight.h"

void rl_ray_watertight_setup(const rl_ray *ray, rl_ray_watertight *w)
{
    int kx, ky, kz;
    rl_watertight_axes(ray->d, &kx, &ky, &kz);
    float dz = rl_vget(ray->d, kz);
    w->kx = kx;
    w->ky = ky;
    w->kz = kz;
    w->sx = rl_vget(ray->d, kx) / dz;
    w->sy = rl_vget(ray->d, ky) / dz;
    w->sz = 1.0f / dz;
    w->o = ray->o;
}

bool rl_triangle_intersect_watertight(const rl_ray_watertight *w, rl_vec3 p0, rl_vec3 p1, rl_vec3 p2,
                                      float t_min, float t_max, float *t, float *u, float *v)
{
    return rl_watertight_hit(w, p0, p1, p2, t_min, t_max, t, u, v);
}
