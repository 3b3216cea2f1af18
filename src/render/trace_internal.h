/* trace_internal.h: what the two halves of the Whitted tracer share.
 *
 * trace.c owns the tracer, the recursion (reflection/refraction) and the ray
 * tree; trace_shade.c owns the local Phong term with its shadow feelers
 * (Ullmann 2003, eq. 3.2). Both record rays through one per-sample context. */
#ifndef RL_RENDER_TRACE_INTERNAL_H
#define RL_RENDER_TRACE_INTERNAL_H

#include "rl/rl_rng.h"
#include "rl/rl_trace.h"

struct rl_tracer {
    const rl_accel *accel;
    const rl_scene_data *data;
    int max_depth;            /* resolved: 0 = no secondary rays */
    int area_samples;         /* n of the n x n quad-light grid */
    float ambient;            /* resolved: 0 = none */
    rl_vec3 background;
    bool shadows;
    uint64_t seed;
    float eps;                /* secondary-ray origin offset, see trace.c */
};

/* State of one traced sample: counters, tree and the area-light jitter. */
typedef struct rl_trace_ctx {
    const rl_tracer *tracer;
    rl_rng rng;
    uint64_t *rays;           /* rl_trace_result.rays */
    rl_ray_tree *tree;        /* or NULL */
} rl_trace_ctx;

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
    rl_vec3 kd;               /* k_d times the diffuse texture */
    const rl_material *m;
} rl_trace_surface;

/* Local term: emission + ambient k_d + sum over visible lights of
 * E (k_d max(0, n.l) + k_s max(0, r.v)^n), tracing one shadow feeler per
 * light sample (trace_shade.c). */
rl_vec3 rl_trace_local(rl_trace_ctx *ctx, const rl_trace_surface *s, int depth);

/* Origin of a secondary ray leaving s in direction dir: offset along the
 * geometric normal to the side dir leaves on, so the ray cannot hit the
 * surface it starts from. */
rl_vec3 rl_trace_offset(const rl_tracer *tracer, const rl_trace_surface *s, rl_vec3 dir);

#endif
