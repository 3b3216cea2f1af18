/* watertight.h: the body of the watertight ray/triangle test (watertight.c
 * documents it: Woop, Benthin, Wald 2013) as a static inline function, so
 * that the hot loops of brute.c and bvh_wide_traverse.c inline it. Every caller
 * runs exactly these IEEE operations (C11 mode: no FMA contraction, no
 * fast-math), so inlined and called versions agree bit for bit. */
#ifndef RL_ACCEL_WATERTIGHT_H
#define RL_ACCEL_WATERTIGHT_H

#include <math.h>

#include "accel/accel_internal.h"

#if defined(__GNUC__)
#define RL_WT_INLINE static inline __attribute__((always_inline))
#else
#define RL_WT_INLINE static inline
#endif

/* The axis permutation of rl_ray_watertight_setup: kz = the largest |d|
 * component, kx, ky the next ones cyclically, swapped when looking down
 * -z so that the projected triangle keeps its winding. */
static inline void rl_watertight_axes(rl_vec3 d, int *kx, int *ky, int *kz)
{
    float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
    int z = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
    int x = z == 2 ? 0 : z + 1;
    int y = x == 2 ? 0 : x + 1;
    if (rl_vget(d, z) < 0.0f) {
        int s = x;
        x = y;
        y = s;
    }
    *kx = x;
    *ky = y;
    *kz = z;
}

/* Component k of v; with a constant k the choice folds away. */
#define RL_WT_COMP(v, k) ((k) == 0 ? (v).x : ((k) == 1 ? (v).y : (v).z))

/* The test with the axis permutation passed separately: hot loops call it
 * with constants (one specialised loop per permutation, see
 * bvh_wide_traverse.c) so that no vertex is indexed at run time. kx, ky, kz
 * must equal w's. */
RL_WT_INLINE bool rl_watertight_hit_k(const rl_ray_watertight *w, int kx, int ky, int kz, rl_vec3 p0,
                                      rl_vec3 p1, rl_vec3 p2, float t_min, float t_max, float *t, float *u,
                                      float *v)
{
    float oz = RL_WT_COMP(w->o, kz);
    float Az = RL_WT_COMP(p0, kz) - oz, Bz = RL_WT_COMP(p1, kz) - oz, Cz = RL_WT_COMP(p2, kz) - oz;
    /* Shear and scale the vertices into ray space (the paper: ray along +z). */
    float ox = RL_WT_COMP(w->o, kx), oy = RL_WT_COMP(w->o, ky);
    float Ax = (RL_WT_COMP(p0, kx) - ox) - w->sx * Az, Ay = (RL_WT_COMP(p0, ky) - oy) - w->sy * Az;
    float Bx = (RL_WT_COMP(p1, kx) - ox) - w->sx * Bz, By = (RL_WT_COMP(p1, ky) - oy) - w->sy * Bz;
    float Cx = (RL_WT_COMP(p2, kx) - ox) - w->sx * Cz, Cy = (RL_WT_COMP(p2, ky) - oy) - w->sy * Cz;
    /* 2D edge functions; U belongs to edge p1p2 (the weight of p0). */
    float U = Cx * By - Cy * Bx;
    float V = Ax * Cy - Ay * Cx;
    float W = Bx * Ay - By * Ax;
    if (U == 0.0f || V == 0.0f || W == 0.0f) {
        /* The paper's fallback: the ray passes (nearly) through an edge;
         * the products are exact in double, so the sign is the true one. */
        U = (float)((double)Cx * (double)By - (double)Cy * (double)Bx);
        V = (float)((double)Ax * (double)Cy - (double)Ay * (double)Cx);
        W = (float)((double)Bx * (double)Ay - (double)By * (double)Ax);
    }
    if ((U < 0.0f || V < 0.0f || W < 0.0f) && (U > 0.0f || V > 0.0f || W > 0.0f))
        return false;
    float det = U + V + W;
    if (det == 0.0f)
        return false;
    Az *= w->sz;
    Bz *= w->sz;
    Cz *= w->sz;
    float T = U * Az + V * Bz + W * Cz;
    /* det-scaled early reject (sign-normalised so that det > 0). Behind the
     * ray is exact by sign; the far side keeps a 2^-16 margin so that it
     * never rejects what the divided test below would accept. */
    float det_abs = fabsf(det), T_abs = det < 0.0f ? -T : T;
    if (t_min >= 0.0f && T_abs <= 0.0f)
        return false;
    float bound = t_max * det_abs * (1.0f + 0x1p-16f);
    if (bound > 0x1p-100f && T_abs > bound)   /* no reject once bound underflows */
        return false;
    /* Divisions, not a reciprocal: a denormal det would overflow 1/det. */
    float th = T / det;
    if (!(th > t_min && th < t_max))
        return false;
    *t = th;
    *u = V / det;
    *v = W / det;
    return true;
}

static inline bool rl_watertight_hit(const rl_ray_watertight *w, rl_vec3 p0, rl_vec3 p1, rl_vec3 p2,
                                     float t_min, float t_max, float *t, float *u, float *v)
{
    return rl_watertight_hit_k(w, w->kx, w->ky, w->kz, p0, p1, p2, t_min, t_max, t, u, v);
}

#endif
