/* rl_pt.h: what the path tracer "pt" (Schröder 2017) reports beyond the
 * common rl_renderer interface: per-frame statistics (rays by kind and by
 * backend, the time split of Sec. 9, the build times of the structures),
 * the reset of the progressive accumulation (Sec. 6.5) and the G-buffer of
 * the current frame (Sec. 8.1), which the noise filters use as guidance.
 *
 * The path tracer in one paragraph: per pixel and frame, spp camera paths;
 * at each diffuse or glossy vertex the lights are sampled with shadow rays
 * (next-event estimation, eq. 7 for quad lights; by default one light chosen
 * by power and weighted against the BSDF sample by MIS), then Russian roulette
 * picks mirror, refraction or the Phong BRDF, whose direction is importance
 * sampled; frames are blended into the running mean (eq. 8). Shadow and
 * secondary rays go through selectable backends: BVH, grid, Embree, Line
 * Space (candidates, PNMT, pre-illumination) or shadow maps. See
 * src/render/pathtrace.c and docs/path-tracing.md. */
#ifndef RL_PT_H
#define RL_PT_H

#include "rl/rl_common.h"
#include "rl/rl_gbuffer.h"
#include "rl/rl_render.h"
#include "rl/rl_rng.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Where a ray query goes (options shadow= and diffuse=). */
typedef enum rl_pt_backend {
    RL_PT_BACKEND_BVH = 0,
    RL_PT_BACKEND_GRID,
    RL_PT_BACKEND_EMBREE,
    RL_PT_BACKEND_LS_CANDIDATES,   /* Line Space shaft candidates (Sec. 7.1) */
    RL_PT_BACKEND_LS_PREILLUM,     /* stored direct light of the first surface (Sec. 7.4) */
    RL_PT_BACKEND_LS_PNMT,         /* stored surface, no triangle test (Sec. 7.2-7.3) */
    RL_PT_BACKEND_SHADOWMAP,       /* shadow maps, shadow tests only (Sec. 8.6) */
    RL_PT_BACKEND_LS_SCENE,        /* scene Line Space signatures over an inner structure (Sec. 13.1) */
    RL_PT_BACKEND_LS_OBJECT,       /* object Line Spaces under a BVH of instance boxes (Sec. 13.2) */
    RL_PT_BACKEND_COUNT
} rl_pt_backend;

/* The option spelling: "bvh", "grid", "embree", "ls-candidates", ... */
RL_API const char *rl_pt_backend_name(rl_pt_backend backend);

typedef struct rl_pt_stats {
    uint64_t frames;              /* accumulated since the last reset, this one included */
    bool reset;                   /* this frame started a new accumulation */
    double spp;                   /* mean samples per pixel accumulated so far */
    uint32_t spp_frame;           /* samples per traced pixel in this frame */
    uint64_t pixels_traced;       /* this frame (about half with checkerboard) */
    uint64_t samples;             /* paths started this frame */
    uint64_t rays[RL_RAY_TYPE_COUNT];   /* this frame, as rl_render_stats */
    uint64_t gbuffer_rays;        /* pixel-centre rays of a traced G-buffer
                                   * (made on reset only; not in rays[]) */
    uint64_t shadow_queries[RL_PT_BACKEND_COUNT];  /* shadow tests by backend */
    uint64_t trace_queries[RL_PT_BACKEND_COUNT];   /* closest-surface queries (primary
                                                    * and secondary) by backend */
    uint64_t preillum_ends;       /* paths ended by a pre-illuminated surface */
    double mrays_per_s;           /* rays[] / (time_primary + time_paths) */
    double time_primary_ms;       /* primary rays, or the rasterized G-buffer */
    double time_paths_ms;         /* path tracing after the primary hit */
    double time_filter_ms;        /* noise filter (0 when filter=none) */
    double time_build_ms;         /* structures built during this frame */
    double time_total_ms;         /* the whole render() call */
    /* Build times of the structures in use, whenever they were built
     * (they are kept between frames); 0 for one not in use. With ls_file
     * the Line Space's is its load time when the file was loaded. */
    double build_bvh_ms, build_grid_ms, build_embree_ms, build_linespace_ms, build_shadowmap_ms;
    double build_ls_scene_ms, build_ls_object_ms;   /* ls-scene's signatures; the object Line Spaces */
    rl_rng_gpu_kind rng;          /* the GPU generator, when not sobol */
    bool sobol;                   /* rng=sobol: Owen-scrambled Sobol points */
    float filter_weight;          /* weight of the filtered image in the output */
    uint64_t adaptive_converged;  /* adaptive=on: traced pixels whose relative error was
                                   * below adaptive_threshold at the frame's last round */
} rl_pt_stats;

/* Statistics of the last frame of r. RL_ERR_INVALID_ARG when r is not a
 * "pt" renderer or has rendered nothing yet. */
RL_API rl_status rl_pt_get_stats(const rl_renderer *r, rl_pt_stats *out);
/* Starts a new accumulation with the next render() (the per-pixel random
 * states are seeded again, so the same frames repeat exactly). */
RL_API rl_status rl_pt_reset(rl_renderer *r);
/* The G-buffer of the current accumulation (pixel-centre primary hits),
 * valid until the next render or release; NULL when r is not "pt" or has
 * not rendered. After a render with a region (rl_renderer_set_region),
 * only the region's pixels are this accumulation's. */
RL_API const rl_gbuffer *rl_pt_gbuffer(const rl_renderer *r);
/* The samples that frame number frame (0: the first after a reset) of a
 * width x height image traces with r's options: spp per pixel, in half the
 * pixels with checkerboard (with adaptive=on, at most that many). Lets a caller fix the frames of a sample target
 * before rendering (rl --dist: rl_dist_render_frames). 0 when r is not
 * "pt" or the size is not positive. */
RL_API uint64_t rl_pt_frame_samples(const rl_renderer *r, int width, int height, uint64_t frame);
/* Samples per pixel of the current accumulation (width x height, row-major),
 * valid until the next render or release; NULL when r is not "pt" or has
 * not rendered. With adaptive=on they differ from pixel to pixel. */
RL_API const uint32_t *rl_pt_sample_counts(const rl_renderer *r);

#ifdef __cplusplus
}
#endif
#endif
