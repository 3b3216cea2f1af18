/* rl_math.h: small-vector math for geometry (float) shared by every module.
 *
 * Header-only and branch-free where possible so that hot loops inline it.
 * Conventions: right-handed world, column vectors, rl_mat4 stored row-major
 * (m[row][col]) and applied as M * v. Angles are in radians unless the name
 * says _deg. Accumulation and statistics use double elsewhere. */
#ifndef RL_MATH_H
#define RL_MATH_H

#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_PI 3.14159265358979323846f
#define RL_INV_PI 0.31830988618379067154f

typedef struct rl_vec2 { float x, y; } rl_vec2;
typedef struct rl_vec3 { float x, y, z; } rl_vec3;
typedef struct rl_vec4 { float x, y, z, w; } rl_vec4;
typedef struct rl_mat4 { float m[4][4]; } rl_mat4;
typedef struct rl_aabb { rl_vec3 min, max; } rl_aabb;

/* A ray segment o + t*d for t in (t_min, t_max). d need not be normalised. */
typedef struct rl_ray {
    rl_vec3 o; float t_min;
    rl_vec3 d; float t_max;
} rl_ray;

/* Orthonormal basis (tangent, bitangent, normal). */
typedef struct rl_onb { rl_vec3 t, b, n; } rl_onb;

static inline float rl_radians(float deg) { return deg * (RL_PI / 180.0f); }
static inline float rl_degrees(float rad) { return rad * (180.0f / RL_PI); }
static inline float rl_clampf(float x, float lo, float hi) { return x < lo ? lo : (x > hi ? hi : x); }
static inline float rl_lerpf(float a, float b, float t) { return a + (b - a) * t; }
static inline float rl_minf(float a, float b) { return a < b ? a : b; }
static inline float rl_maxf(float a, float b) { return a > b ? a : b; }

static inline rl_vec2 rl_v2(float x, float y) { rl_vec2 r = { x, y }; return r; }
static inline rl_vec3 rl_v3(float x, float y, float z) { rl_vec3 r = { x, y, z }; return r; }
static inline rl_vec3 rl_v3s(float s) { rl_vec3 r = { s, s, s }; return r; }
static inline rl_vec4 rl_v4(float x, float y, float z, float w) { rl_vec4 r = { x, y, z, w }; return r; }
static inline rl_vec4 rl_v4_from3(rl_vec3 v, float w) { return rl_v4(v.x, v.y, v.z, w); }

static inline rl_vec3 rl_add(rl_vec3 a, rl_vec3 b) { return rl_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline rl_vec3 rl_sub(rl_vec3 a, rl_vec3 b) { return rl_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline rl_vec3 rl_mul(rl_vec3 a, rl_vec3 b) { return rl_v3(a.x * b.x, a.y * b.y, a.z * b.z); }
static inline rl_vec3 rl_scale(rl_vec3 a, float s) { return rl_v3(a.x * s, a.y * s, a.z * s); }
static inline rl_vec3 rl_neg(rl_vec3 a) { return rl_v3(-a.x, -a.y, -a.z); }
static inline rl_vec3 rl_madd(rl_vec3 a, rl_vec3 b, float s) { return rl_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline float rl_dot(rl_vec3 a, rl_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline rl_vec3 rl_cross(rl_vec3 a, rl_vec3 b)
{
    return rl_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float rl_length2(rl_vec3 a) { return rl_dot(a, a); }
static inline float rl_length(rl_vec3 a) { return sqrtf(rl_dot(a, a)); }
/* Returns a unit vector, or the zero vector for a zero-length input. */
static inline rl_vec3 rl_normalize(rl_vec3 a)
{
    float l = rl_length(a);
    return l > 0.0f ? rl_scale(a, 1.0f / l) : rl_v3s(0.0f);
}
static inline rl_vec3 rl_vmin(rl_vec3 a, rl_vec3 b) { return rl_v3(rl_minf(a.x, b.x), rl_minf(a.y, b.y), rl_minf(a.z, b.z)); }
static inline rl_vec3 rl_vmax(rl_vec3 a, rl_vec3 b) { return rl_v3(rl_maxf(a.x, b.x), rl_maxf(a.y, b.y), rl_maxf(a.z, b.z)); }
static inline rl_vec3 rl_vlerp(rl_vec3 a, rl_vec3 b, float t) { return rl_madd(a, rl_sub(b, a), t); }
static inline float rl_vmax_comp(rl_vec3 a) { return rl_maxf(a.x, rl_maxf(a.y, a.z)); }
static inline float rl_vget(rl_vec3 a, int axis) { return axis == 0 ? a.x : (axis == 1 ? a.y : a.z); }
static inline bool rl_vfinite(rl_vec3 a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* Mirror direction of incident d about unit normal n (d points towards the surface). */
static inline rl_vec3 rl_reflect(rl_vec3 d, rl_vec3 n) { return rl_sub(d, rl_scale(n, 2.0f * rl_dot(d, n))); }
/* Snell refraction of unit d through unit n (facing against d), eta = n_i/n_t.
 * Returns false on total internal reflection. */
static inline bool rl_refract(rl_vec3 d, rl_vec3 n, float eta, rl_vec3 *out)
{
    float cos_i = -rl_dot(d, n);
    float k = 1.0f - eta * eta * (1.0f - cos_i * cos_i);
    if (k < 0.0f)
        return false;
    *out = rl_add(rl_scale(d, eta), rl_scale(n, eta * cos_i - sqrtf(k)));
    return true;
}

/* Axis-aligned boxes. rl_aabb_empty() is inverted so that growing works. */
static inline rl_aabb rl_aabb_empty(void)
{
    rl_aabb b = { { INFINITY, INFINITY, INFINITY }, { -INFINITY, -INFINITY, -INFINITY } };
    return b;
}
static inline rl_aabb rl_aabb_grow(rl_aabb b, rl_vec3 p) { b.min = rl_vmin(b.min, p); b.max = rl_vmax(b.max, p); return b; }
static inline rl_aabb rl_aabb_union(rl_aabb a, rl_aabb b) { a.min = rl_vmin(a.min, b.min); a.max = rl_vmax(a.max, b.max); return a; }
static inline bool rl_aabb_is_empty(rl_aabb b) { return b.min.x > b.max.x || b.min.y > b.max.y || b.min.z > b.max.z; }
static inline rl_vec3 rl_aabb_extent(rl_aabb b) { return rl_aabb_is_empty(b) ? rl_v3s(0.0f) : rl_sub(b.max, b.min); }
static inline rl_vec3 rl_aabb_center(rl_aabb b) { return rl_scale(rl_add(b.min, b.max), 0.5f); }
static inline float rl_aabb_area(rl_aabb b)
{
    rl_vec3 e = rl_aabb_extent(b);
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
}
static inline bool rl_aabb_contains(rl_aabb b, rl_vec3 p)
{
    return p.x >= b.min.x && p.x <= b.max.x && p.y >= b.min.y && p.y <= b.max.y && p.z >= b.min.z && p.z <= b.max.z;
}
/* Slab test; on a hit narrows [*t0, *t1] to the overlap and returns true. */
static inline bool rl_aabb_intersect_ray(rl_aabb b, const rl_ray *r, float *t0, float *t1)
{
    float lo = r->t_min, hi = r->t_max;
    for (int a = 0; a < 3; ++a) {
        float inv = 1.0f / rl_vget(r->d, a);
        float tn = (rl_vget(b.min, a) - rl_vget(r->o, a)) * inv;
        float tf = (rl_vget(b.max, a) - rl_vget(r->o, a)) * inv;
        if (tn > tf) { float s = tn; tn = tf; tf = s; }
        lo = tn > lo ? tn : lo;   /* NaN-safe: NaN comparisons keep lo/hi */
        hi = tf < hi ? tf : hi;
        if (lo > hi)
            return false;
    }
    *t0 = lo;
    *t1 = hi;
    return true;
}

static inline rl_vec3 rl_ray_at(const rl_ray *r, float t) { return rl_madd(r->o, r->d, t); }

/* Orthonormal basis around unit n (Duff et al. 2017, "Building an orthonormal
 * basis, revisited"): continuous except at one point, no normalisation. */
static inline rl_onb rl_onb_from_normal(rl_vec3 n)
{
    float s = copysignf(1.0f, n.z);
    float a = -1.0f / (s + n.z);
    float b = n.x * n.y * a;
    rl_onb o;
    o.t = rl_v3(1.0f + s * n.x * n.x * a, s * b, -s * n.x);
    o.b = rl_v3(b, s + n.y * n.y * a, -n.y);
    o.n = n;
    return o;
}
static inline rl_vec3 rl_onb_to_world(const rl_onb *o, rl_vec3 v)
{
    return rl_add(rl_add(rl_scale(o->t, v.x), rl_scale(o->b, v.y)), rl_scale(o->n, v.z));
}
static inline rl_vec3 rl_onb_to_local(const rl_onb *o, rl_vec3 v)
{
    return rl_v3(rl_dot(v, o->t), rl_dot(v, o->b), rl_dot(v, o->n));
}

/* 4x4 matrices. */
RL_API rl_mat4 rl_mat4_identity(void);
RL_API rl_mat4 rl_mat4_mul(const rl_mat4 *a, const rl_mat4 *b);      /* a * b */
RL_API rl_mat4 rl_mat4_translate(rl_vec3 t);
RL_API rl_mat4 rl_mat4_scale(rl_vec3 s);
RL_API rl_mat4 rl_mat4_rotate(rl_vec3 axis, float angle_rad);        /* right-handed */
RL_API rl_mat4 rl_mat4_transpose(const rl_mat4 *a);
/* General inverse; returns false (and identity) for a singular matrix. */
RL_API bool rl_mat4_invert(const rl_mat4 *a, rl_mat4 *out);
/* View matrix looking from eye at target (camera looks down -z). */
RL_API rl_mat4 rl_mat4_look_at(rl_vec3 eye, rl_vec3 target, rl_vec3 up);
/* OpenGL-style perspective projection: clip w = -z_eye, NDC z in [-1,1]. */
RL_API rl_mat4 rl_mat4_perspective(float fov_y_rad, float aspect, float z_near, float z_far);
/* Centred orthographic projection (glOrtho with symmetric bounds): eye x in
 * [-half_width, half_width], y likewise, z_eye = -z_near .. -z_far to NDC
 * -1 .. +1, clip w = 1. */
RL_API rl_mat4 rl_mat4_orthographic(float half_width, float half_height, float z_near, float z_far);
RL_API rl_vec4 rl_mat4_mul_vec4(const rl_mat4 *a, rl_vec4 v);
RL_API rl_vec3 rl_mat4_mul_point(const rl_mat4 *a, rl_vec3 p);       /* w = 1, no divide */
RL_API rl_vec3 rl_mat4_mul_dir(const rl_mat4 *a, rl_vec3 d);         /* w = 0 */
/* Transforms normals: inverse transpose of the upper 3x3, result normalised. */
RL_API rl_vec3 rl_mat4_mul_normal(const rl_mat4 *inv_transpose, rl_vec3 n);
RL_API rl_aabb rl_mat4_mul_aabb(const rl_mat4 *a, rl_aabb b);

/* Colour helpers (linear RGB). */
RL_API float rl_luminance(rl_vec3 rgb);
RL_API rl_vec3 rl_rgb_to_hsv(rl_vec3 rgb);  /* h in [0,360), s,v in [0,1] */
RL_API rl_vec3 rl_hsv_to_rgb(rl_vec3 hsv);
RL_API float rl_linear_to_srgb(float c);
RL_API float rl_srgb_to_linear(float c);

#ifdef __cplusplus
}
#endif
#endif
