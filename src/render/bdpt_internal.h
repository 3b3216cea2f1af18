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

#endif
