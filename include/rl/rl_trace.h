/* rl_trace.h: the exact recursive ray tracer (Whitted 1980) as a library.
 *
 * The renderer "whitted" is built on this, and so will be Vertex Tracing:
 * Ullmann 2003 shoots its vertex rays through exactly this tracer and
 * compares their ray trees (Sec. 3.3.1). Shading follows Ullmann 2003,
 * Sec. 3.1, eq. 3.1-3.4: local Phong with hard shadow feelers to every light
 * (area lights with a fixed sample count), plus k_r times the reflected and
 * k_t times the refracted radiance, recursively up to max_depth.
 *
 * A ray tree is the ordered sequence of (ray type, hit object) of every ray
 * spawned while shading one sample, depth-first in the order the tracer
 * traces them: the primary ray, then its shadow rays, then the reflection
 * subtree, then the refraction subtree. Two samples see the same
 * combination of surfaces exactly when their trees are equal. */
#ifndef RL_TRACE_H
#define RL_TRACE_H

#include "rl/rl_accel.h"
#include "rl/rl_common.h"
#include "rl/rl_image.h"
#include "rl/rl_math.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_RAY_TREE_MAX 64

typedef struct rl_ray_tree_node {
    uint8_t type;             /* rl_ray_type */
    uint8_t depth;            /* recursion depth, 0 = primary; a shadow
                               * feeler is one deeper than the ray it lights */
    uint32_t object;          /* hit object, RL_ID_NONE for a miss; for a
                               * shadow ray the occluder, RL_ID_NONE if the
                               * light is visible */
    uint32_t light;           /* shadow rays: the light index, else RL_ID_NONE */
} rl_ray_tree_node;

typedef struct rl_ray_tree {
    uint32_t count;
    bool truncated;           /* more than RL_RAY_TREE_MAX nodes were spawned */
    rl_ray_tree_node nodes[RL_RAY_TREE_MAX];
} rl_ray_tree;

RL_API bool rl_ray_tree_equal(const rl_ray_tree *a, const rl_ray_tree *b);

typedef struct rl_tracer_desc {           /* zero = default */
    int max_depth;            /* reflection/refraction recursion; 0 -> 5,
                               * < 0 -> none (local term only); at most 64 */
    int area_samples;         /* shadow samples per quad light, n x n grid
                               * jittered; 0 -> 4 (16 samples); at most 32 */
    float ambient;            /* ambient term × k_d; 0 -> 0.05, < 0 -> none */
    rl_vec3 background;       /* radiance of rays that leave the scene */
    bool no_shadows;          /* skip shadow feelers (all lights visible) */
    uint64_t seed;            /* area-light jitter */
} rl_tracer_desc;

typedef struct rl_tracer rl_tracer;

/* Borrows scene and accel (both committed, accel built over scene). */
RL_API rl_status rl_tracer_create(const rl_accel *accel, const rl_tracer_desc *desc, rl_tracer **out);
RL_API void rl_tracer_release(rl_tracer *tracer);

typedef struct rl_trace_result {
    rl_vec3 color;            /* radiance along the ray */
    uint64_t rays[RL_RAY_TYPE_COUNT];  /* rays traced for this sample */
    rl_hit hit;               /* the first hit (triangle RL_ID_NONE: miss) */
} rl_trace_result;

/* Traces one arbitrary ray of the given type (normally RL_RAY_PRIMARY) and
 * shades it recursively. tree may be NULL. Thread-safe. sample_id seeds the
 * area-light jitter so results are deterministic per sample. */
RL_API void rl_tracer_trace(const rl_tracer *tracer, const rl_ray *ray, rl_ray_type type,
                            uint64_t sample_id, rl_trace_result *out, rl_ray_tree *tree);
/* Shades a known hit (for Vertex Tracing: the ray aimed at a vertex, whose hit
 * is the vertex itself, Ullmann 2003 eq. 3.1) without tracing the ray. The
 * result counts the ray as one of `type` nonetheless. */
RL_API void rl_tracer_shade(const rl_tracer *tracer, const rl_ray *ray, const rl_hit *hit,
                            rl_ray_type type, uint64_t sample_id, rl_trace_result *out,
                            rl_ray_tree *tree);

#ifdef __cplusplus
}
#endif
#endif
