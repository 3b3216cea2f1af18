/* bdpt_internal.h: what the parts of the bidirectional path tracer "bdpt"
 * share (Schröder 2017, Sec. 8.3 outlook; Veach 1997, Ch. 10).
 *
 * bdpt.c        the renderer: options, frame loop, accumulation, the
 *               deterministic gathering of the light-tracing splats
 * bdpt_path.c   one sample: a camera subpath and a light subpath, every
 *               connection strategy (s, t), their MIS weights
 *
 * It stands on the parts of "pt" (pathtrace_internal.h): the BVH and the
 * light table chosen by power (pt_backends), the environment's importance
 * distribution, the surfaces and the BRDFs. */
#ifndef RL_RENDER_BDPT_INTERNAL_H
#define RL_RENDER_BDPT_INTERNAL_H

#include "render/pathtrace_internal.h"

typedef enum bd_mis { BD_MIS_POWER = 0, BD_MIS_UNIFORM } bd_mis;

/* What a sample needs; read-only during a pass. */
typedef struct bd_ctx {
    const rl_scene_data *data;
    const pt_backends *b;
    int max_depth;                 /* surface interactions after the camera hit, as pt */
    int rr_depth;
    bool rr;
    bd_mis mis;
    int only_s, only_t;            /* strategy=s,t: that one alone, unweighted; -1 all */
    rl_vec3 background;            /* without an environment */
    bool ggx_ms;                   /* GGX energy compensation (pathtrace_ggx.c) */
    /* The scene's environment as an emitter at infinity (bdpt_path.c):
     * light subpaths start on it with probability env_pick (the light
     * table gets the rest, light_share), from a disk of the bounding
     * sphere's radius across the sampled direction (density env_disk_pdf). */
    const rl_environment *environment;   /* NULL: background */
    const pt_env *env;             /* its importance distribution */
    float env_pick, light_share;
    rl_vec3 env_centre;
    float env_radius, env_disk_pdf;
    /* the pinhole camera (importance W_e, Veach 1997 Sec. 10.3) */
    rl_camera_frame cam;
    rl_vec3 forward;
    float film_area;               /* image plane at distance 1 */
} bd_ctx;

typedef enum bd_light_kind {
    BD_LIGHT_NONE = 0, BD_LIGHT_QUAD, BD_LIGHT_TRI, BD_LIGHT_POINT, BD_LIGHT_DIRECTIONAL, BD_LIGHT_ENV
} bd_light_kind;

/* An emitter at a point: what emits, how strongly, and how a light subpath
 * would have sampled it. */
typedef struct bd_light {
    bd_light_kind kind;
    const rl_light *L;             /* point, spot, directional */
    rl_vec3 n;                     /* quad: emitting side; triangle: its normal */
    rl_vec3 le;                    /* area radiance; environment: its radiance along dir */
    rl_vec3 dir;                   /* environment: unit direction from the scene towards it */
    float pdf_pos;                 /* pmf / area, or the pmf of a delta position; environment:
                                    * env_pick p_env(dir), in solid angle */
    bool hittable;                 /* a camera ray can find it (s = 0 possible) */
} bd_light;

typedef enum bd_vkind { BD_V_CAMERA = 0, BD_V_LIGHT, BD_V_SURFACE } bd_vkind;

typedef struct bd_vertex {
    bd_vkind kind;
    rl_vec3 p, ng;                 /* ng: geometric normal (surface: facing s.v); light: n */
    pt_surface s;
    bd_light light;                /* light vertex, or the emitter a surface is */
    rl_vec3 beta;                  /* path throughput up to this vertex */
    float pdf_fwd, pdf_rev;        /* area densities from its own side and from the other */
    bool delta;                    /* scattered by a mirror / refraction event */
} bd_vertex;

/* One light-tracing contribution to a pixel's sum. */
typedef struct bd_splat {
    uint32_t pixel;
    float r, g, b;
} bd_splat;

/* Growable list of splats, one per tile, added in tile order. */
typedef struct bd_splats {
    bd_splat *v;
    size_t n, cap;
    bool failed;                   /* out of memory */
} bd_splats;

/* Per-thread scratch for one sample's subpaths. */
typedef struct bd_scratch {
    struct bd_vertex *camera, *light;
    float *pl, *pe;
    bool *delta;
} bd_scratch;

rl_status bd_scratch_init(bd_scratch *sc, int max_depth);
void bd_scratch_release(bd_scratch *sc);

/* Radiance of sample `index` of pixel (x, y): the camera-side strategies
 * (t >= 2) are returned, the light-tracing ones (t = 1) go to *splats with
 * the pixel they land in. rng: the sample's own generator. */
rl_vec3 bd_sample(const bd_ctx *ctx, bd_scratch *sc, rl_rng *rng, int x, int y, bd_splats *splats,
                  uint64_t *rays);

/* The light subpath y_0 .. y_{n-1} (n returned, at most max_vertices): y_0
 * a point on a light chosen by power (the light table, or the environment
 * with ctx->env_pick), then a random walk carrying importance; each vertex
 * with its throughput and its area densities pdf_fwd (from the light
 * side) and pdf_rev (from the next vertex, set once that is sampled; 1
 * where a delta vertex makes it). bdpt joins these to its camera subpath;
 * gl-pt's light_paths (gl_pathtrace.c, Schröder 2017 Sec. 8.4) hands them
 * to the GPU. */
int bd_light_subpath(const bd_ctx *ctx, rl_rng *rng, bd_vertex *y, int max_vertices, uint64_t *rays);

#endif
