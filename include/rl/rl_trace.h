/* rl_trace.h: the exact recursive ray tracer (Whitted 1980) as a library.
 *
 * The renderers "whitted" and "vt" are built on this: Vertex Tracing
 * (Ullmann 2003) shoots its vertex rays through exactly this tracer and
 * compares their ray trees (Sec. 3.3.1). Shading follows Ullmann 2003,
 * Sec. 3.1, eq. 3.1-3.4 and Sec. 3.5.2, eq. 3.17-3.19: local Phong with hard
 * shadow feelers to every light (area lights with a fixed sample count) and
 * the transmitted highlight of lights behind a transmissive surface, plus
 * k_r times the reflected and k_t times the refracted radiance, recursively
 * up to max_depth.
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
/* 64-bit hash of the nodes (type, depth, object, light) and the truncation
 * flag: equal trees hash equally; Vertex Tracing stores only this per vertex
 * and compares hashes (a false "equal" has probability ~2^-64). */
RL_API uint64_t rl_ray_tree_hash(const rl_ray_tree *tree);

typedef struct rl_tracer_desc {           /* zero = default */
    int max_depth;            /* reflection/refraction recursion; 0 -> 5,
                               * < 0 -> none (local term only); at most 64 */
    int area_samples;         /* shadow samples per quad light, n x n grid
                               * jittered; 0 -> 4 (16 samples); at most 32 */
    float ambient;            /* ambient term × k_d; 0 -> 0.05, < 0 -> none */
    rl_vec3 background;       /* radiance of rays that leave the scene */
    bool no_shadows;          /* skip shadow feelers (all lights visible) */
    /* The shading modes of Ullmann 2003, Figs. 5.9/5.10 (+-S +-R +-T):
     * without reflection (transmission) rays the k_r (k_t) term is left
     * out, as the thesis switches the ray type off; no_shadows is -S. */
    bool no_reflections;
    bool no_transmission;
    /* Leave out eq. 3.17's transmitted highlight k_t cos^p φ_t (Ullmann
     * 2003, Sec. 3.5.2), which lights behind a transmissive surface add;
     * with it off the local term is classic Phong, as before 2026-12-05. */
    bool no_transmitted_highlight;
    uint64_t seed;            /* area-light jitter */
    /* Ray trees record only whether a shadow feeler was blocked (occluder
     * RL_ID_NONE - 1 for any occluder), not by which object, so feelers keep
     * the cheaper any-hit query even when a tree is kept. Enough for the
     * ray-tree criterion of Vertex Tracing, whose shadow nodes say whether
     * the light is visible (Ullmann 2003, Sec. 3.3.1, Fig. 3.7). */
    bool tree_shadow_any_hit;
    /* Deferred textures (the layers of rl_tracer_shade_point) pass through
     * untextured reflecting or refracting surfaces to the first textured
     * surface along the strongest of their secondary rays, so that a
     * texture behind a glass shell (two surfaces) is still looked up per
     * fragment. Our extension of Ullmann 2003, Sec. 3.5.3, which stops at
     * the first surface. The recombined colour is unchanged. */
    bool defer_through;
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

/* ---- Vertex Tracing samples (Ullmann 2003, Sec. 3.1, 3.4.5, 3.5.3) ---- */

/* A surface point given explicitly instead of by a ray hit: a vertex of a
 * refined VT mesh. Position and shading normal come from the refinement
 * (eq. 3.7, 3.8), not from the triangle, which supplies only the geometric
 * normal, the material and the object. */
typedef struct rl_trace_point {
    rl_vec3 p;                /* world position */
    rl_vec3 n;                /* shading normal (need not be unit) */
    rl_vec2 uv;               /* texture coordinates */
    uint32_t triangle;        /* scene triangle the point lies on */
} rl_trace_point;

/* One deferred-texture term (Sec. 3.5.3): what the rasterizer multiplies by
 * a texel. The term's radiance is diffuse * texel(uv) + rest, or
 * diffuse + rest when texture is RL_NONE. Weights (k_r, k_t) are folded in. */
typedef struct rl_trace_layer {
    rl_vec3 diffuse;          /* k_d (untextured) times the light it receives */
    rl_vec3 rest;             /* everything not modulated by the texture:
                               * emission, specular, and for the reflection
                               * and refraction terms the deeper recursion
                               * (C_comb, eq. 3.21) and misses (background) */
    uint32_t texture;         /* scene texture index, or RL_NONE */
    rl_vec2 uv;
} rl_trace_layer;

enum { RL_TRACE_LAYER_PRIMARY = 0, RL_TRACE_LAYER_REFLECTION, RL_TRACE_LAYER_REFRACTION,
       RL_TRACE_LAYER_COUNT };

/* Depth-0 shadow-feeler results of one point, for temporal coherence
 * (Sec. 3.4.5): the occluding object of each feeler the point traced, in the
 * order traced (RL_ID_NONE: light visible; RL_ID_NONE - 1: blocked by an
 * object not named, because the feeler was traced without a ray tree and
 * used the any-hit query). Valid while lights and geometry stay and the
 * point is seen from the same side (front). A cache holding RL_ID_NONE - 1
 * is not replayed into a ray tree (the tree would not be exact): the
 * feelers are traced again. cache_in and cache_out may be the same struct. */
#define RL_TRACE_FEELER_CACHE_MAX 64
typedef struct rl_trace_feelers {
    uint32_t count;           /* 0..RL_TRACE_FEELER_CACHE_MAX */
    bool front;               /* the viewer was on the side the point's shading
                               * normal points to: that side (the normal
                               * flipped towards the viewer) decides which
                               * feelers are shot. With a degenerate shading
                               * normal, the geometric normal's side. */
    bool complete;            /* all feelers fitted (count <= MAX) */
    uint32_t occluder[RL_TRACE_FEELER_CACHE_MAX];
} rl_trace_feelers;

/* Intersection hints (Ullmann 2003, Sec. 3.3.1 and 6.2.2): the triangle each
 * ray of a sample hit, in the order the rays were met (the ray tree's order
 * without the primary ray; a feeler replayed from the cache takes its slot
 * too): the closest hit of a reflection or refraction ray, the occluder of
 * a blocked shadow feeler (with the any-hit query, any occluder in range),
 * RL_ID_NONE for a miss, a visible light or a replayed feeler. A sample
 * traced with the hints of its neighbours first tests each ray against the
 * triangles they name in its slot: a shadow feeler that hits one is
 * blocked at once, a closest-hit ray searches the accelerator only up to
 * that hit. Exact: the results are the same as without hints (trace.c). */
#define RL_TRACE_HINT_MAX 64
typedef struct rl_trace_hints {
    uint32_t count;           /* slots filled, 0..RL_TRACE_HINT_MAX */
    uint32_t triangle[RL_TRACE_HINT_MAX];
} rl_trace_hints;

typedef struct rl_trace_sample {
    rl_vec3 color;            /* radiance towards the eye, textures applied:
                               * equals rl_tracer_shade() of the same point */
    rl_vec3 flat;             /* the same with every deferred texture taken
                               * as white: what refinement criteria compare */
    rl_trace_layer layers[RL_TRACE_LAYER_COUNT];
    uint64_t rays[RL_RAY_TYPE_COUNT];  /* rays traced (cached feelers excluded;
                                        * the eye ray counts as one primary) */
    uint32_t feelers_reused;  /* depth-0 feelers answered from the cache */
    uint32_t hint_tests;      /* rays tested against a hinted triangle first */
    uint32_t hint_hits;       /* of those, a hinted triangle was hit: a
                               * feeler ended there, or the search was
                               * bounded by it */
} rl_trace_sample;

/* Shades the point as seen from eye (the primary ray eye -> p, eq. 3.1, is
 * not traced: its hit is the point). The reflection and refraction terms of
 * the first recursion level are returned as deferred-texture layers; deeper
 * levels are sampled with their textures, as the thesis does. sample_id
 * seeds the area-light jitter. cache_in (may be NULL) answers depth-0
 * feelers when it matches (same front side, complete); cache_out (may be
 * NULL) receives this point's depth-0 feelers. tree may be NULL. A point
 * whose triangle is out of range or whose eye ray has no direction shades
 * as a miss (background). Thread-safe. */
RL_API void rl_tracer_shade_point(const rl_tracer *tracer, rl_vec3 eye, const rl_trace_point *pt,
                                  uint64_t sample_id, const rl_trace_feelers *cache_in,
                                  rl_trace_feelers *cache_out, rl_trace_sample *out,
                                  rl_ray_tree *tree);

/* rl_tracer_shade_point with intersection hints: hint_in (may be NULL, or
 * either entry NULL) lists the triangles to test first, slot by slot; two
 * lists, so that a vertex can take those of both its parents (Ullmann 2003,
 * Sec. 3.3.1: the ray trees of the samples at an edge's ends). hint_out
 * (may be NULL) receives this sample's own. Hints never change the result,
 * only the work: the tracer falls back to the full search wherever a hint
 * does not hold, and ignores them on an Embree accelerator, whose triangle
 * test is not ours. */
RL_API void rl_tracer_shade_point_hinted(const rl_tracer *tracer, rl_vec3 eye, const rl_trace_point *pt,
                                         uint64_t sample_id, const rl_trace_feelers *cache_in,
                                         rl_trace_feelers *cache_out, const rl_trace_hints *const hint_in[2],
                                         rl_trace_hints *hint_out, rl_trace_sample *out, rl_ray_tree *tree);

#ifdef __cplusplus
}
#endif
#endif
