/* trace_internal.h: what the parts of the Whitted tracer share.
 *
 * trace.c owns the tracer, the recursion (reflection/refraction) and the ray
 * tree; trace_shade.c owns the local Phong term with its shadow feelers
 * (Ullmann 2003, eq. 3.2) and the feeler cache (Sec. 3.4.5); trace_point.c
 * shades explicit surface points for Vertex Tracing with deferred textures
 * (Sec. 3.5.3). All record rays through one per-sample context. */
#ifndef RL_RENDER_TRACE_INTERNAL_H
#define RL_RENDER_TRACE_INTERNAL_H

#include "rl/rl_rng.h"
#include "rl/rl_trace.h"

/* rl_trace_feelers.occluder: blocked, found by an any-hit query that does
 * not name the occluder (documented in rl_trace.h). */
#define RL_TRACE_OCCLUDER_UNKNOWN (RL_ID_NONE - 1u)

/* The offset of a secondary ray's origin along the geometric normal in a
 * scene with these bounds: 1e-5 times the scene's size (trace.c, header;
 * pt's backends use the same, pathtrace_backend.c). */
float rl_trace_origin_eps(rl_aabb bounds);

struct rl_tracer {
    const rl_accel *accel;
    const rl_scene_data *data;
    int max_depth;            /* resolved: 0 = no secondary rays */
    int area_samples;         /* n of the n x n quad-light grid */
    float ambient;            /* resolved: 0 = none */
    rl_vec3 background;
    bool shadows;
    bool reflections, transmission;   /* the +-R, +-T modes (rl_tracer_desc) */
    bool transmitted_highlight;   /* eq. 3.17's k_t cos^p φ_t term */
    bool tree_shadow_any_hit; /* see rl_tracer_desc */
    bool defer_through;       /* see rl_tracer_desc */
    bool hints;               /* intersection hints are exact on this accel */
    uint64_t seed;
    float eps;                /* secondary-ray origin offset, see trace.c */
};

/* State of one traced sample: counters, tree, the area-light jitter and the
 * depth-0 feeler cache (both cache pointers NULL outside trace_point.c). */
typedef struct rl_trace_ctx {
    const rl_tracer *tracer;
    rl_rng rng;
    uint64_t *rays;           /* rl_trace_result.rays */
    rl_ray_tree *tree;        /* or NULL */
    const rl_trace_feelers *cache_in;  /* replayed depth-0 feelers, or NULL */
    rl_trace_feelers *cache_out;       /* recorded depth-0 feelers, or NULL */
    uint32_t feelers;         /* depth-0 feelers met so far */
    uint32_t reused;          /* of those, answered from cache_in */
    /* intersection hints (rl_trace_hints); both NULL outside trace_point.c */
    const rl_trace_hints *hint_in[2];  /* entries may be NULL */
    rl_trace_hints *hint_out;
    uint32_t slot;            /* rays met so far: the next ray's hint slot */
    uint32_t hint_tests, hint_hits;
} rl_trace_ctx;

/* Intersection hints (trace.c). rl_trace_slot takes the next ray's slot;
 * the queries answer like rl_accel_intersect / the feeler's query, trying
 * the slot's hinted triangles first, and record the triangle found in
 * hint_out. */
uint32_t rl_trace_slot(rl_trace_ctx *ctx);
void rl_trace_record(rl_trace_ctx *ctx, uint32_t slot, uint32_t triangle);
bool rl_trace_intersect(rl_trace_ctx *ctx, uint32_t slot, rl_ray *ray, rl_hit *hit);
bool rl_trace_occluded(rl_trace_ctx *ctx, uint32_t slot, const rl_ray *ray);

/* Zeroes rays (RL_RAY_TYPE_COUNT counters), empties the tree and seeds the
 * jitter from (tracer seed, sample_id) so that a sample repeats exactly. */
void rl_trace_begin(const rl_tracer *tracer, uint64_t sample_id, uint64_t *rays, rl_ray_tree *tree,
                    rl_trace_ctx *ctx);

/* Appends a node (or sets the truncation flag); returns its index or
 * RL_ID_NONE when no node was written. */
uint32_t rl_trace_tree_push(rl_trace_ctx *ctx, rl_ray_type type, int depth, uint32_t object,
                            uint32_t light);

/* Surface point being shaded; normals are unit and face the incoming ray. */
typedef struct rl_trace_surface {
    rl_vec3 p;
    rl_vec3 ng;               /* geometric normal, towards the ray's origin side */
    rl_vec3 ns;               /* interpolated shading normal, flipped likewise */
    rl_vec3 v;                /* unit direction back along the ray */
    bool front;               /* the unflipped geometric normal faced the ray */
    bool ns_front;            /* the unflipped shading normal faced the ray */
    rl_vec3 kd;               /* k_d times the diffuse texture */
    uint32_t texture;         /* the material's valid diffuse texture or RL_NONE */
    rl_vec2 uv;               /* texture coordinates at p */
    const rl_material *m;
} rl_trace_surface;

/* Completes s on scene triangle tri at s->p with raw shading normal ns (any
 * length; degenerate -> geometric normal), texture coordinates uv, seen
 * along unit v: flips the normals towards v and applies the texture to k_d.
 * tri must be in range. */
void rl_trace_surface_finish(const rl_tracer *tr, uint32_t tri, rl_vec3 ns, rl_vec2 uv, rl_vec3 v,
                             rl_trace_surface *s);

/* Local term split for deferred texturing (Sec. 3.5.3): local = kd * irr +
 * rest, where irr = ambient + sum over visible lights of E max(0, n.l)
 * (the light k_d modulates) and rest = emission + sum E k_s max(0, r.v)^n.
 * Traces one shadow feeler per light sample (trace_shade.c). */
typedef struct rl_trace_local {
    rl_vec3 irr;
    rl_vec3 rest;
} rl_trace_local;
rl_trace_local rl_trace_local_term(rl_trace_ctx *ctx, const rl_trace_surface *s, int depth);

/* The reflection and refraction rays leaving s (eq. 3.3, 3.4) for a ray
 * along unit d, in tracing order, with their coefficients after total
 * internal reflection and the path-weight cut-off. Returns how many (0-2). */
typedef struct rl_trace_secondary {
    rl_ray ray;
    rl_ray_type type;
    float k;                  /* k_r or k_t */
} rl_trace_secondary;
int rl_trace_secondary_rays(const rl_tracer *tr, const rl_trace_surface *s, rl_vec3 d, float weight,
                            rl_trace_secondary out[2]);

/* Traces ray (counted and recorded as type at depth) and returns the
 * radiance it brings back, recursively. layer (may be NULL) receives the
 * same radiance split at the first hit: diffuse = untextured k_d * irr, rest
 * = everything else, texture/uv of the hit; a miss has rest = background. */
rl_vec3 rl_trace_ray(rl_trace_ctx *ctx, rl_ray ray, rl_ray_type type, int depth, float weight,
                     rl_trace_layer *layer);

/* A deferred layer's radiance with its texel looked up (diffuse * texel +
 * rest; no texel when untextured). */
rl_vec3 rl_trace_layer_color(const rl_scene_data *data, const rl_trace_layer *layer);

/* Origin of a secondary ray leaving s in direction dir: offset along the
 * geometric normal to the side dir leaves on, so the ray cannot hit the
 * surface it starts from. */
rl_vec3 rl_trace_offset(const rl_tracer *tracer, const rl_trace_surface *s, rl_vec3 dir);

#endif
