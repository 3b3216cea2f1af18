/* pathtrace.c: renderer "pt", the GPU path tracer of Schröder 2017 (Ch. 6,
 * 8) on the CPU: progressive path tracing with next-event estimation,
 * Russian roulette and Phong importance sampling, with selectable ray
 * backends (BVH, grid, Embree, Line Space candidates / PNMT /
 * pre-illumination, shadow maps) for the shadow and the secondary rays.
 *
 * Options (defaults; the thesis' values in brackets):
 *   spp = 1            paths per pixel and frame
 *   max_depth = -1     surface interactions after the camera hit [2 open
 *                      scenes, 3 Cornell box]; 0 = direct light only;
 *                      -1 = the scene's root attribute max_path_length
 *                      (ls-open, ls-cornell carry the thesis' value), else 3
 *   rr = true, rr_depth = 4    Russian roulette from that bounce on [2]
 *   rng = sobol        sobol (Owen-scrambled Sobol points, issue 37) | lcg |
 *                      tausworthe | hybrid (Sec. 5.3) [hybrid]
 *   mis = on           on: lights chosen by power, MIS with the BSDF sample
 *                      (Veach 1997, issue 37) | off [every light per vertex]
 *   seed = 0
 *   shadow = bvh       bvh | grid | embree | ls-candidates | ls-preillum |
 *                      ls-pnmt | shadowmap | ls-scene | ls-object
 *   diffuse = bvh      bvh | grid | embree | ls-candidates | ls-preillum | ls-pnmt
 *                      | ls-scene | ls-object (exact, Sec. 13.1, 13.2)
 *   specular = exact   mirror and refraction rays: exact (the thesis, Sec.
 *                      11.2, 12.3: the PNMT Line Space is not accurate enough
 *                      for them, so they go to the voxel grid it lives in;
 *                      with an exact diffuse backend, that one) | diffuse
 *                      (through the diffuse backend, Line Space payloads
 *                      included: ours before 2026-12-05)
 *   primary = trace    trace (jittered camera rays through the BVH) |
 *                      raster (G-buffer from the rasterizer, Sec. 8.1: no
 *                      jitter, so edges alias as the thesis notes)
 *   checkerboard = false       Sec. 8.5
 *   accumulate = true          Sec. 6.5, eq. 8
 *   filter = none, filter_fade = 16    Sec. 8.2 (atrous: issue 37, Dammertz
 *                      et al. 2010, with atrous_iterations = 5, atrous_sigma_rt
 *                      = 0 (from the spp), atrous_sigma_n = 0.1,
 *                      atrous_sigma_x = 0 (from the pixel footprint))
 *   adaptive = off     on: per-pixel adaptive sampling (issue 37, below),
 *                      adaptive_threshold = 0.01, adaptive_min_spp = 8
 *   grid_res = 0 (grid heuristic), ls_n = 5 [5], ls_k = 8, ls_dynamic = true,
 *   ls_origin = offset [offset], ls_file = "" (Line Space cache, Sec. 13.3)
 *   ls_scene_n = 4, ls_scene_segments = 64, ls_scene_cells = 16,
 *   ls_scene_inner = object, ls_object_res = 8 (outlook, not in the thesis)
 *   shadowmap_size = 1024 [1024], light_samples = 1, threads = 0 (all)
 *   quad_sampling = area [area]: solid_angle (pathtrace_quad.c) is ours
 *
 * A frame (Sec. 5.1, Fig. 8): build what the backends need (once per
 * scene, pathtrace_backend.c); on a reset fill the G-buffer; then for each
 * of the spp samples a primary pass (jittered camera rays, or the
 * rasterized G-buffer once per frame) and a path pass (pathtrace_path.c),
 * over 16 x 16 tiles handed out dynamically to OpenMP threads: a tile
 * makes all the frame's passes over its pixels (run_tiles).
 *
 * Accumulation (Sec. 6.5, eq. 8): C_{s+1} = s/(s+1) C_s + 1/(s+1) C_trace.
 * We keep the per-pixel sum in double and its sample count and divide,
 * which is eq. 8 without its rounding drift; the count is per pixel because
 * checkerboard rendering (Sec. 8.5) renders the pixels with (x + y + frame)
 * even in one frame and the others in the next; in the first frame after a
 * reset the missing pixels are the mean of their rendered 4-neighbours.
 * The accumulation restarts when the camera, the scene (rl_scene_uid), the
 * image size or any option changes, on rl_pt_reset(), and every frame with
 * accumulate = false.
 *
 * Random numbers (Sec. 5.3): one GPU-style generator state per pixel (the
 * thesis' state texture), seeded on reset from PCG32 (seed, pixel) and
 * advanced across frames; or (rng=sobol) the Sobol point numbered by the
 * pixel's accumulated samples (pathtrace_sampler.c). Every pixel's result
 * depends only on its own state, so images do not depend on the thread
 * count.
 *
 * Filter (Sec. 8.2): the filtered accumulated image is blended in with the
 * weight 1 / (1 + spp / filter_fade), spp the mean samples per pixel so far:
 * "the filter's influence decreases as the samples grow"; filter_fade = 0
 * keeps the full filter. The G-buffer guides the filter.
 *
 * Adaptive sampling (adaptive=on, issue 37): a frame still spends spp
 * paths per traced pixel on average, but hands them out by each pixel's
 * estimated error. Per pixel we keep, beside the sum of the radiance, the
 * sum of the squared luminance of its samples; the relative error of the
 * mean is e = sqrt(s^2 / n) / (mean + ADAPTIVE_EPS), s^2 the sample
 * variance of the luminance, averaged over the 3 x 3 neighbourhood because
 * one pixel's few samples estimate it badly (a pixel whose samples all
 * missed a light would otherwise claim to be exact). Pixels with fewer
 * than adaptive_min_spp samples first get up to that many, uniformly; then
 * the frame's remaining paths go out in rounds, each pixel's share in
 * proportion to its e, none to a pixel with e < adaptive_threshold (it has
 * converged), and at most ADAPTIVE_CAP times the round's mean to any one
 * (water-filling; what the cap or convergence leaves over is not spent). A
 * round at most doubles the mean count, so the estimate is refreshed as
 * the samples grow within one large frame. The shares are computed in one
 * sequential pass in pixel order and each pixel's samples keep their
 * numbers (sample index = the pixel's count so far), so the image does not
 * depend on the thread count and the Sobol sequence of a pixel continues
 * where it stopped. In the uniform phase the image is bit-identical to
 * adaptive=off's. The variance of Sobol samples overstates the error of
 * their mean (they are stratified); as a relative measure between pixels
 * it serves.
 *
 * Depth and ID layers come from the G-buffer (pixel centres).
 *
 * Regions (rl_renderer_set_region, what rl --dist hands out): every pixel's
 * samples depend only on its own generator state or Sobol index, so a
 * region renders exactly the pixels of the whole frame there. A region is
 * an accumulation of its own: it restarts when the region changes, so N
 * frames of a region are the region of N whole frames. With checkerboard,
 * the first frame's holes need their neighbours, so a region traces a ring
 * of one pixel around itself too. The filters work on the whole image and
 * primary=raster rasterizes it, and adaptive sampling shares a frame's
 * paths over the whole image: a region refuses all three. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "core/params.h"
#include "render/pathtrace_internal.h"
#include "render/renderer.h"
#include "rl/rl_pt.h"
#include "rl/rl_timer.h"

#define TILE 16
#define BUILD_SHARE 0.1
/* The budget a caller without one spends (rl_renderer_info): about 30-60
 * spp of cornell at 512 x 512 on 2 cores, where the noise has fallen to a
 * quarter of 1 spp's (docs/path-tracing.md, "Time budget"). */
#define PT_DEFAULT_TIME_S 10.0
/* Adaptive sampling (see the top): the offset that keeps dark pixels'
 * relative error finite and stops them from drawing every path (a
 * luminance of 0.05 is dark grey on the display), and the most one pixel
 * takes of a round, in multiples of the round's mean. */
#define ADAPTIVE_EPS 0.05
#define ADAPTIVE_CAP 8.0

/* Order: sobol, then rl_rng_gpu_kind. */
const char *const rl_pt_rng_choices[] = { "sobol", "lcg", "tausworthe", "hybrid", NULL };
const char *const rl_pt_mis_choices[] = { "off", "on", NULL };
/* Order = pt_env_sampling. */
const char *const rl_pt_env_sampling_choices[] = { "importance", "uniform", "bsdf", NULL };
static const char *const quad_sampling_choices[] = { "area", "solid_angle", NULL };
/* Order = rl_pt_backend. */
const char *const rl_pt_shadow_choices[] = { "bvh", "grid", "embree", "ls-candidates", "ls-preillum", "ls-pnmt",
                                              "shadowmap", "ls-scene", "ls-object", NULL };
const char *const rl_pt_specular_choices[] = { "exact", "diffuse", NULL };
/* Order = rl_pt_backend up to ls-pnmt; then ls-scene and ls-object, which
 * come after shadowmap there (diffuse_backend maps them). */
const char *const rl_pt_diffuse_choices[] = { "bvh", "grid", "embree", "ls-candidates", "ls-preillum", "ls-pnmt",
                                               "ls-scene", "ls-object", NULL };
/* Order = pt_ls_scene_inner. */
static const char *const ls_scene_inner_choices[] = { "object", "bvh", "candidates", NULL };
const char *const rl_pt_ls_origin_choices[] = { "offset", "exact", NULL };
const char *const rl_pt_primary_choices[] = { "trace", "raster", NULL };
/* Order = rl_filter_kind. */
const char *const rl_pt_filter_choices[] = { "none", "gauss", "bilateral", "aniso", "kuwahara", "atrous", NULL };
const char *const rl_pt_adaptive_choices[] = { "off", "on", NULL };

static const rl_option_info pt_options[] = {
    { "spp", RL_OPT_INT, "1", "paths per pixel and frame", 1, 65536, NULL },
    { "max_depth", RL_OPT_INT, "-1",
      "surface interactions after the camera hit (0: direct light only; thesis: 2 open scenes, 3 Cornell box; "
      "-1: the scene's root attribute max_path_length, else 3)",
      -1, 1024, NULL },
    { "rr", RL_OPT_BOOL, "true", "Russian roulette on the path length (Sec. 3.2.4)", 0, 0, NULL },
    { "rr_depth", RL_OPT_INT, "4",
      "bounce from which Russian roulette may end a path (thesis: 2; 4 by measurement, issue 37)", 0, 1024, NULL },
    { "rng", RL_OPT_ENUM, "sobol",
      "sample numbers: sobol (Owen-scrambled Sobol points) or the thesis' per-pixel generators (Sec. 5.3): lcg, "
      "tausworthe or their hybrid", 0, 0, rl_pt_rng_choices },
    { "mis", RL_OPT_ENUM, "on",
      "on: lights chosen by power, light and BSDF samples weighted by the power heuristic (Veach 1997); off: "
      "the thesis' next-event estimation of every light", 0, 0, rl_pt_mis_choices },
    { "seed", RL_OPT_INT, "0", "seed of the per-pixel generator states", 0, 9007199254740991.0, NULL },
    { "sample_offset", RL_OPT_INT, "0",
      "rng=sobol: number of the first Sobol point of an accumulation, so that renders of consecutive sample "
      "ranges together are one longer render (a resumable reference; other rng: must be 0)", 0, 2147483647.0,
      NULL },
    { "shadow", RL_OPT_ENUM, "bvh", "shadow test: exact accelerator, Line Space payload or shadow maps",
      0, 0, rl_pt_shadow_choices },
    { "diffuse", RL_OPT_ENUM, "bvh", "secondary rays: exact accelerator or Line Space payload",
      0, 0, rl_pt_diffuse_choices },
    { "specular", RL_OPT_ENUM, "exact",
      "mirror and refraction rays: exact (the thesis, Sec. 11.2, 12.3: the grid under a Line Space payload, "
      "else the diffuse backend) or diffuse (the diffuse backend, payloads included)", 0, 0, rl_pt_specular_choices },
    { "primary", RL_OPT_ENUM, "trace",
      "primary visibility: trace (jittered rays, BVH) or raster (G-buffer, Sec. 8.1)", 0, 0, rl_pt_primary_choices },
    { "checkerboard", RL_OPT_BOOL, "false", "render alternate halves of the pixels per frame (Sec. 8.5)",
      0, 0, NULL },
    { "accumulate", RL_OPT_BOOL, "true", "progressive accumulation across frames (Sec. 6.5, eq. 8)", 0, 0, NULL },
    { "filter", RL_OPT_ENUM, "none", "noise filter on the accumulated image (Sec. 8.2)", 0, 0, rl_pt_filter_choices },
    RL_PT_FILTER_PARAM_OPTIONS,
    RL_PT_ADAPTIVE_OPTIONS(""),
    RL_PT_LINE_SPACE_OPTIONS,
    { "ls_file", RL_OPT_STRING, "",
      "Line Space cache (Sec. 13.3): loaded if the file exists (it must match the scene, grid and "
      "ls_* options), else built and saved there; empty = build in memory only", 0, 0, NULL },
    { "ls_scene_n", RL_OPT_INT, "4", "ls-scene: patches per face side of the scene box (Sec. 13.1)", 1,
      RL_LS_SCENE_MAX_N, NULL },
    { "ls_scene_segments", RL_OPT_INT, "64", "ls-scene: signature bits per shaft (filled/empty stretches)", 1,
      RL_LS_SCENE_MAX_SEGMENTS, NULL },
    { "ls_scene_cells", RL_OPT_INT, "16", "ls-scene: occupancy cells per axis behind the signatures", 1,
      RL_LS_SCENE_MAX_CELLS, NULL },
    { "ls_scene_inner", RL_OPT_ENUM, "object",
      "ls-scene: what answers the filled stretches: object (the object Line Spaces, Sec. 13.2), bvh, or "
      "candidates (the per-voxel Line Space on the grid of grid_res)", 0, 0, ls_scene_inner_choices },
    { "ls_object_res", RL_OPT_INT, "8", "ls-object: voxels per axis of each object's Line Space (N = ls_n; Sec. 13.2)",
      1, RL_LS_OBJECT_MAX_RES, NULL },
    { "shadowmap_size", RL_OPT_INT, "1024", "texels per shadow-map face side (Sec. 8.6)", 16, 16384, NULL },
    { "light_samples", RL_OPT_INT, "1", "shadow rays per quad light and vertex", 1, 1024, NULL },
    { "quad_sampling", RL_OPT_ENUM, "area",
      "next-event points on a rectangular quad light with mis=on: area (uniform on the quad, Sec. 6.3) or "
      "solid_angle (uniform in the solid angle it subtends; Urena et al. 2013)", 0, 0, quad_sampling_choices },
    { "background", RL_OPT_COLOR, "0,0,0",
      "radiance arriving from every direction where a ray leaves the scene (a uniform environment); a scene "
      "\"environment\" replaces it", 0, 0, NULL },
    { "env_sampling", RL_OPT_ENUM, "importance",
      "light samples of a scene environment (issue 37): importance (by its radiance x sin(theta)), uniform "
      "(over the sphere) or bsdf (none: escaping BSDF rays only); MIS with the BSDF either way", 0, 0,
      rl_pt_env_sampling_choices },
    { "ggx_ms", RL_OPT_BOOL, "true",
      "GGX energy compensation (Kulla & Conty 2017): the light single scattering loses returns as a "
      "diffuse-like lobe; false: single scattering alone", 0, 0, NULL },
    { "threads", RL_OPT_INT, "0", "OpenMP threads (0 = all)", 0, 1024, NULL },
};
#define NUM_OPTIONS (sizeof pt_options / sizeof pt_options[0])

typedef struct pt_state {
    pt_backends b;
    /* the accumulation and what it depends on */
    bool valid, force_reset;
    uint64_t scene_uid;
    rl_camera cam;
    int width, height;
    rl_rect area;                 /* the traced pixels: the region (and its ring), else the image */
    char *signature;
    double *accum;                /* 3 per pixel: summed radiance */
    uint32_t *count;              /* samples per pixel */
    double *sum2;                 /* adaptive: per pixel, the sum of squared sample luminances */
    float *err;                   /* adaptive scratch: per pixel, the relative error */
    uint32_t *share;              /* adaptive scratch: per pixel, the samples of a round */
    rl_rng_gpu *rng;              /* per pixel */
    rl_gbuffer *gbuf;
    uint64_t frames, total_samples;
    /* per-frame scratch */
    rl_hit *hits;
    rl_vec3 *dirs;
    /* the last frame */
    bool have_frame;
    rl_pt_stats stats;
} pt_state;

static void free_frame(pt_state *s)
{
    free(s->accum);
    free(s->count);
    free(s->sum2);
    free(s->err);
    free(s->share);
    free(s->rng);
    free(s->hits);
    free(s->dirs);
    rl_gbuffer_release(s->gbuf);
    s->accum = NULL;
    s->count = NULL;
    s->sum2 = NULL;
    s->err = NULL;
    s->share = NULL;
    s->rng = NULL;
    s->hits = NULL;
    s->dirs = NULL;
    s->gbuf = NULL;
    s->valid = false;
}

/* The accumulation restarts; the grid, Line Space and shadow maps stay. */
static void pt_reset_state(void *state)
{
    pt_state *s = state;
    if (s)
        s->force_reset = true;
}

static void pt_release(void *state)
{
    pt_state *s = state;
    rl_pt_backends_release(&s->b);
    free_frame(s);
    free(s->signature);
}

int rl_pt_scene_max_depth(const rl_scene *scene)
{
    const char *v = rl_scene_node_attr(scene, 0, "max_path_length");
    long long n;
    return v && rl_parse_int(v, &n) && n >= 0 && n <= 1024 ? (int)n : 3;
}

static rl_status pt_check(const char *key, const char *value)
{
    if (strcmp(key, "shadow") == 0 || strcmp(key, "diffuse") == 0) {
        bool shadow = key[0] == 's';
        for (int k = 0; k < RL_PT_BACKEND_COUNT; ++k) {
            if (strcmp(value, rl_pt_backend_name((rl_pt_backend)k)) != 0)
                continue;
            if (!rl_pt_backend_available((rl_pt_backend)k, shadow))
                return rl_error(RL_ERR_INVALID_ARG, "pt: %s=%s is not available in this build%s", key, value,
                                k == RL_PT_BACKEND_EMBREE ? " (configure with -DRL_EMBREE=ON)" : "");
        }
        return RL_OK;
    }
    if (strcmp(key, "ls_k") == 0 && atoi(value) % 2 != 0)
        return rl_error(RL_ERR_INVALID_ARG, "pt: ls_k=%s must be even (front and back halves, Alg. 3)", value);
    return RL_OK;
}

static void read_settings(const rl_renderer *r, pt_settings *set)
{
    memset(set, 0, sizeof *set);
    set->spp = (int)rl_renderer_opt_int(r, "spp");
    set->max_depth = (int)rl_renderer_opt_int(r, "max_depth");
    set->rr = rl_renderer_opt_bool(r, "rr");
    set->rr_depth = (int)rl_renderer_opt_int(r, "rr_depth");
    int rng = rl_renderer_opt_enum(r, "rng");
    set->sobol = rng == 0;
    set->rng = set->sobol ? RL_RNG_GPU_HYBRID : (rl_rng_gpu_kind)(rng - 1);
    set->mis = rl_renderer_opt_enum(r, "mis") == 1;
    set->seed = (uint64_t)rl_renderer_opt_int(r, "seed");
    set->sample_offset = (uint32_t)rl_renderer_opt_int(r, "sample_offset");
    set->shadow = (rl_pt_backend)rl_renderer_opt_enum(r, "shadow");
    int diffuse = rl_renderer_opt_enum(r, "diffuse");
    set->diffuse = diffuse <= RL_PT_BACKEND_LS_PNMT ? (rl_pt_backend)diffuse
                                                    : (rl_pt_backend)(RL_PT_BACKEND_LS_SCENE + diffuse - RL_PT_BACKEND_SHADOWMAP);
    /* Sec. 11.2, 12.3: specular rays leave the approximate payloads for the
     * exact grid the Line Space lives in (always built with a payload). */
    bool payload = set->diffuse == RL_PT_BACKEND_LS_PNMT || set->diffuse == RL_PT_BACKEND_LS_PREILLUM;
    set->specular = rl_renderer_opt_enum(r, "specular") == 0 && payload ? RL_PT_BACKEND_GRID : set->diffuse;
    set->primary = (pt_primary)rl_renderer_opt_enum(r, "primary");
    set->checkerboard = rl_renderer_opt_bool(r, "checkerboard");
    set->accumulate = rl_renderer_opt_bool(r, "accumulate");
    rl_pt_read_filter_settings(r, set);
    set->adaptive = rl_renderer_opt_enum(r, "adaptive") == 1;
    set->adaptive_threshold = rl_renderer_opt_float(r, "adaptive_threshold");
    set->adaptive_min_spp = (int)rl_renderer_opt_int(r, "adaptive_min_spp");
    set->grid_res = (int)rl_renderer_opt_int(r, "grid_res");
    set->ls_n = (int)rl_renderer_opt_int(r, "ls_n");
    set->ls_k = (int)rl_renderer_opt_int(r, "ls_k");
    set->ls_dynamic = rl_renderer_opt_bool(r, "ls_dynamic");
    set->ls_origin_exact = rl_renderer_opt_enum(r, "ls_origin") == 1;
    set->ls_file = rl_renderer_opt_string(r, "ls_file");
    set->ls_scene_n = (int)rl_renderer_opt_int(r, "ls_scene_n");
    set->ls_scene_segments = (int)rl_renderer_opt_int(r, "ls_scene_segments");
    set->ls_scene_cells = (int)rl_renderer_opt_int(r, "ls_scene_cells");
    set->ls_scene_inner = rl_renderer_opt_enum(r, "ls_scene_inner");
    set->ls_object_res = (int)rl_renderer_opt_int(r, "ls_object_res");
    set->shadowmap_size = (int)rl_renderer_opt_int(r, "shadowmap_size");
    set->light_samples = (int)rl_renderer_opt_int(r, "light_samples");
    set->quad_solid_angle = rl_renderer_opt_enum(r, "quad_sampling") == 1;
    set->background = rl_renderer_opt_color(r, "background");
    set->env_sampling = (int)rl_renderer_opt_enum(r, "env_sampling");
    set->ggx_ms = rl_renderer_opt_bool(r, "ggx_ms");
    int threads = (int)rl_renderer_opt_int(r, "threads");
#ifdef _OPENMP
    set->threads = threads > 0 ? threads : omp_get_max_threads();
#else
    (void)threads;
    set->threads = 1;
#endif
}

/* Whether option i can change the image: ls_k sizes the fixed candidate
 * lists only, so with dynamic lists it has no effect. */
static bool option_matters(const rl_renderer *r, size_t i)
{
    return strcmp(pt_options[i].key, "ls_k") != 0 || !rl_renderer_opt_bool(r, "ls_dynamic");
}

static bool same_rect(const rl_rect *a, const rl_rect *b)
{
    return a->x0 == b->x0 && a->y0 == b->y0 && a->x1 == b->x1 && a->y1 == b->y1;
}

/* Starts a new accumulation in area: buffers, generator states, G-buffer. */
static rl_status reset(pt_state *s, const rl_scene *scene, const rl_camera *cam, const pt_settings *set,
                       const rl_rect *area, char *signature)
{
    int w = cam->width, h = cam->height;
    size_t n = (size_t)w * (size_t)h;
    if (!s->accum || s->width != w || s->height != h) {
        free_frame(s);
        s->accum = rl_calloc(3 * n, sizeof *s->accum);
        s->count = rl_calloc(n, sizeof *s->count);
        s->rng = rl_calloc(n, sizeof *s->rng);
        s->hits = rl_calloc(n, sizeof *s->hits);
        s->dirs = rl_calloc(n, sizeof *s->dirs);
        rl_status st = s->accum && s->count && s->rng && s->hits && s->dirs ? RL_OK : RL_ERR_OUT_OF_MEMORY;
        if (st == RL_OK)
            st = rl_gbuffer_create(w, h, &s->gbuf);
        if (st != RL_OK) {
            free_frame(s);
            free(signature);
            return st;
        }
    }
    if (set->adaptive && !s->sum2) {
        s->sum2 = rl_calloc(n, sizeof *s->sum2);
        s->err = rl_calloc(2 * n, sizeof *s->err);
        s->share = rl_calloc(n, sizeof *s->share);
        if (!s->sum2 || !s->err || !s->share) {
            free_frame(s);
            free(signature);
            return RL_ERR_OUT_OF_MEMORY;
        }
    }
    /* Only area's pixels: a rank of rl --dist renders one band after
     * another into the same buffers, each band its own accumulation. */
    size_t len = (size_t)(area->x1 - area->x0);
    for (int y = area->y0; y < area->y1; ++y) {
        size_t row = (size_t)y * (size_t)w + (size_t)area->x0;
        memset(s->accum + 3 * row, 0, 3 * len * sizeof *s->accum);
        memset(s->count + row, 0, len * sizeof *s->count);
        if (s->sum2)
            memset(s->sum2 + row, 0, len * sizeof *s->sum2);
        /* Sec. 5.3.3: the state texture is filled once from the CPU generator. */
        for (size_t i = row; i < row + len; ++i)
            rl_rng_gpu_seed(&s->rng[i], set->rng, set->seed, i);
    }
    free(s->signature);
    s->signature = signature;
    s->scene_uid = rl_scene_uid(scene);
    s->cam = *cam;
    s->width = w;
    s->height = h;
    s->area = *area;
    s->frames = 0;
    s->total_samples = 0;
    s->valid = true;
    s->force_reset = false;
    return RL_OK;
}

/* Everything a tile needs; read-only but for its pixels and counters. */
typedef struct frame {
    pt_state *s;
    const pt_settings *set;
    pt_ctx ctx;
    rl_camera_frame cam;
    rl_vec3 eye;
    int width, height;
    rl_rect area;                 /* the traced pixels; tiles are numbered from its corner */
    int tiles_x;
    uint64_t parity;
} frame;

static bool active(const frame *f, int x, int y)
{
    return !f->set->checkerboard || (((uint64_t)(x + y) + f->parity) & 1u) == 0;
}

static void tile_bounds(const frame *f, int64_t t, int *x0, int *y0, int *x1, int *y1)
{
    *x0 = f->area.x0 + (int)(t % f->tiles_x) * TILE;
    *y0 = f->area.y0 + (int)(t / f->tiles_x) * TILE;
    *x1 = *x0 + TILE < f->area.x1 ? *x0 + TILE : f->area.x1;
    *y1 = *y0 + TILE < f->area.y1 ? *y0 + TILE : f->area.y1;
}

/* Primary pass of one sample (trace mode): jittered camera rays, Sec. 8.1's
 * "jittering of the primary rays". */
/* Sample `pass` of this frame in pixel i: the pixel's generator state, or
 * the Sobol point numbered by the samples the pixel has accumulated. */
static void pixel_sampler(const frame *f, size_t i, uint32_t pass, pt_sampler *sp)
{
    if (f->set->sobol)
        rl_pt_sampler_init(sp, NULL, rl_pt_pixel_seed(f->set->seed, i), f->set->sample_offset + f->s->count[i] + pass);
    else
        rl_pt_sampler_init(sp, &f->s->rng[i], 0, 0);
}

static void primary_tile(const frame *f, int64_t t, uint32_t pass, pt_counters *c)
{
    int x0, y0, x1, y1;
    tile_bounds(f, t, &x0, &y0, &x1, &y1);
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            if (!active(f, x, y))
                continue;
            size_t i = (size_t)y * f->width + x;
            pt_sampler sp;
            pixel_sampler(f, i, pass, &sp);
            rl_pt_sampler_seek(&sp, PT_SLOT_PIXEL);
            rl_vec2 j = rl_pt_sample_2d(&sp);   /* box filter: uniform in the pixel */
            rl_ray ray = rl_camera_frame_ray(&f->cam, (float)x + j.x, (float)y + j.y);
            rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
            c->rays[RL_RAY_PRIMARY]++;
            c->trace_q[RL_PT_BACKEND_BVH]++;
            rl_accel_intersect(f->s->b.exact[RL_ACCEL_BVH], &ray, &hit);
            f->s->hits[i] = hit;
            f->s->dirs[i] = ray.d;
        }
    }
}

/* The first vertex of pixel i: the traced hit or the G-buffer's surface. */
static bool first_vertex(const frame *f, size_t i, pt_surface *s)
{
    const rl_scene_data *d = f->ctx.data;
    if (f->set->primary == PT_PRIMARY_TRACE)
        return rl_pt_surface_at_hit(d, &f->s->hits[i], f->eye, f->s->dirs[i], s);
    const rl_gbuffer *g = f->s->gbuf;
    uint32_t tri = g->triangle[i];
    if (tri >= d->num_triangles)
        return false;
    rl_vec3 v = rl_normalize(rl_sub(f->eye, g->position[i]));
    rl_pt_surface_finish(d, tri, g->position[i], g->normal[i], g->uv[i], v, s);
    return true;
}

static void path_tile(const frame *f, int64_t t, uint32_t pass, pt_counters *c)
{
    int x0, y0, x1, y1;
    tile_bounds(f, t, &x0, &y0, &x1, &y1);
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            if (!active(f, x, y))
                continue;
            size_t i = (size_t)y * f->width + x;
            pt_surface first;
            rl_vec3 L;
            if (!first_vertex(f, i, &first)) {
                /* a camera ray that leaves the scene */
                L = f->ctx.env ? rl_pt_escape_radiance(&f->ctx, rl_camera_frame_ray(&f->cam, (float)x + 0.5f,
                                                                                   (float)y + 0.5f).d)
                               : f->ctx.background;
            } else {
                pt_sampler sp;
                pixel_sampler(f, i, pass, &sp);
                L = rl_pt_trace_path(&f->ctx, &first, &sp, c);
            }
            /* A NaN or infinity would poison the pixel's mean for good. */
            if (!rl_vfinite(L))
                continue;
            f->s->accum[3 * i + 0] += L.x;
            f->s->accum[3 * i + 1] += L.y;
            f->s->accum[3 * i + 2] += L.z;
        }
    }
}

static void add_counters(pt_counters *to, const pt_counters *from)
{
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        to->rays[k] += from->rays[k];
    for (int k = 0; k < RL_PT_BACKEND_COUNT; ++k) {
        to->shadow_q[k] += from->shadow_q[k];
        to->trace_q[k] += from->trace_q[k];
    }
    to->preillum_ends += from->preillum_ends;
}

/* The frame's spp samples of every tile, in one parallel loop: a tile
 * traces sample k's primary rays and paths, then sample k + 1's. Each
 * pixel gets its samples in the same order as in one pass over all tiles
 * per sample, so the image is the same; but the threads meet at one
 * barrier per frame instead of two per sample, and they spin there (6-13 %
 * of the CPU time on a loaded 2-core machine). part_ms (two entries per
 * tile: primary rays, paths) gets each part's time. The calling thread
 * (thread 0) reports the progress, in steps of 1/64; once the callback
 * cancels, the tiles not started are skipped and *stop tells so. */
static void run_tiles(rl_renderer *r, const frame *f, int64_t num_tiles, pt_counters *tile_c, double *part_ms,
                      bool *stop)
{
    const pt_settings *set = f->set;
    bool primary = set->primary == PT_PRIMARY_TRACE;
    int64_t done = 0;
    int reported = 0;
    bool cancel = false;
#pragma omp parallel for num_threads(set->threads) schedule(dynamic, 1)
    for (int64_t t = 0; t < num_tiles; ++t) {
        bool skip;
#pragma omp atomic read
        skip = cancel;
        if (skip)
            continue;
        for (int k = 0; k < set->spp; ++k) {
            rl_timer timer;
            rl_timer_start(&timer);
            double primary_ms = 0.0;
            if (primary) {
                primary_tile(f, t, (uint32_t)k, &tile_c[t]);
                primary_ms = rl_timer_ms(&timer);
            }
            path_tile(f, t, (uint32_t)k, &tile_c[t]);
            part_ms[2 * t] += primary_ms;
            part_ms[2 * t + 1] += rl_timer_ms(&timer) - primary_ms;
        }
        int64_t now;
#pragma omp atomic capture
        now = ++done;
        if (omp_get_thread_num() == 0 && (int)(64 * now / num_tiles) > reported) {
            reported = (int)(64 * now / num_tiles);
            if (!rl_renderer_progress(r, BUILD_SHARE + (1.0 - BUILD_SHARE) * (double)now / (double)num_tiles)) {
#pragma omp atomic write
                cancel = true;
            }
        }
    }
    *stop = cancel;
}

/* The accumulated mean into the image's region; checkerboard holes (first
 * frame after a reset) from the rendered 4-neighbours (Sec. 8.5, Fig. 17). */
static void resolve(const pt_state *s, const rl_rect *region, rl_image *image)
{
    int w = s->width, h = s->height;
#pragma omp parallel for schedule(static)
    for (int y = region->y0; y < region->y1; ++y) {
        for (int x = region->x0; x < region->x1; ++x) {
            size_t i = (size_t)y * w + x;
            double c[3] = { 0.0, 0.0, 0.0 };
            if (s->count[i] > 0) {
                for (int k = 0; k < 3; ++k)
                    c[k] = s->accum[3 * i + k] / s->count[i];
            } else {
                static const int dx[4] = { -1, 1, 0, 0 }, dy[4] = { 0, 0, -1, 1 };
                int n = 0;
                for (int j = 0; j < 4; ++j) {
                    int nx = x + dx[j], ny = y + dy[j];
                    if (nx < 0 || ny < 0 || nx >= w || ny >= h)
                        continue;
                    size_t q = (size_t)ny * w + nx;
                    if (s->count[q] == 0)
                        continue;
                    for (int k = 0; k < 3; ++k)
                        c[k] += s->accum[3 * q + k] / s->count[q];
                    ++n;
                }
                for (int k = 0; k < 3 && n > 0; ++k)
                    c[k] /= n;
            }
            image->color[i] = rl_v4((float)c[0], (float)c[1], (float)c[2], 1.0f);
        }
    }
}

/* sigma_r (bilateral) and kappa (anisotropic diffusion) at 1 spp. */
#define PT_FILTER_RANGE_1SPP 0.8f
void rl_pt_read_filter_settings(const rl_renderer *r, pt_settings *set)
{
    set->filter = (rl_filter_kind)rl_renderer_opt_enum(r, "filter");
    set->filter_fade = rl_renderer_opt_float(r, "filter_fade");
    set->atrous_iterations = (int)rl_renderer_opt_int(r, "atrous_iterations");
    set->atrous_sigma_rt = rl_renderer_opt_float(r, "atrous_sigma_rt");
    set->atrous_sigma_n = rl_renderer_opt_float(r, "atrous_sigma_n");
    set->atrous_sigma_x = rl_renderer_opt_float(r, "atrous_sigma_x");
}

/* The a-trous colour sigma at 1 spp (atrous_sigma_rt = 0). */
#define PT_ATROUS_RT_1SPP 1.0f

/* Sec. 8.2: filter, faded out as the samples grow (pathtrace_internal.h). */
rl_status rl_pt_filter_image(const pt_settings *set, const rl_gbuffer *gbuf, double spp, rl_image *image,
                             float *weight)
{
    const int width = image->width, height = image->height;
    float w = set->filter_fade > 0.0 ? (float)(1.0 / (1.0 + spp / set->filter_fade)) : 1.0f;
    *weight = w;
    rl_image *in = NULL, *out = NULL;
    rl_status st = rl_image_create(width, height, RL_LAYER_COLOR, &in);
    if (st == RL_OK)
        st = rl_image_create(width, height, RL_LAYER_COLOR, &out);
    if (st == RL_OK) {
        size_t n = (size_t)width * height;
        memcpy(in->color, image->color, n * sizeof *in->color);
        /* The colour scales of the edge-stopping filters follow the noise,
         * which falls as the samples grow; the library's fixed 0.1 takes
         * 1-spp noise for edges and barely filters. Swept against
         * converged references on cornell and ls-open at 1, 4 and 16 spp
         * (160x120, G-buffer guided): sigma_r = 0.8 spp^-3/4 stays within
         * 3 % of the best bilateral RMSE and kappa = 0.8 / spp within 14 %
         * of the best diffusion, where 0.1 was up to 2.3x the best. */
        double n_spp = spp > 1.0 ? spp : 1.0;
        rl_filter_desc fd = { .kind = set->filter,
                              .sigma_r = PT_FILTER_RANGE_1SPP * (float)pow(n_spp, -0.75),
                              .kappa = PT_FILTER_RANGE_1SPP / (float)n_spp };
        if (set->filter == RL_FILTER_ATROUS) {
            /* The paper's colour sigma is a user setting; ours follows the
             * noise of the mean, which falls as spp^-1/2. */
            fd.sigma_r = set->atrous_sigma_rt > 0.0 ? (float)set->atrous_sigma_rt
                                                     : PT_ATROUS_RT_1SPP / (float)sqrt(n_spp);
            fd.sigma_n = (float)set->atrous_sigma_n;
            fd.sigma_x = (float)set->atrous_sigma_x;
            fd.iterations = set->atrous_iterations;
        }
        st = rl_filter_apply(&fd, in, gbuf, out);
        for (size_t i = 0; st == RL_OK && i < n; ++i) {
            rl_vec4 a = in->color[i], b = out->color[i];
            image->color[i] = rl_v4(a.x + w * (b.x - a.x), a.y + w * (b.y - a.y), a.z + w * (b.z - a.z), 1.0f);
        }
    }
    rl_image_release(in);
    rl_image_release(out);
    return st;
}

static rl_status apply_filter(const pt_state *s, const pt_settings *set, uint64_t total_samples, rl_image *image,
                              float *weight)
{
    return rl_pt_filter_image(set, s->gbuf, (double)total_samples / ((double)s->width * s->height), image, weight);
}

static void write_layers(const pt_state *s, const rl_rect *region, rl_image *image)
{
    const rl_gbuffer *g = s->gbuf;
    size_t n = (size_t)(region->x1 - region->x0);
    for (int y = region->y0; y < region->y1; ++y) {
        size_t i = (size_t)y * (size_t)s->width + (size_t)region->x0;
        if ((image->layers & RL_LAYER_DEPTH) && image->depth)
            memcpy(image->depth + i, g->depth + i, n * sizeof *image->depth);
        if ((image->layers & RL_LAYER_ID) && image->object_id && image->triangle_id) {
            memcpy(image->object_id + i, g->object + i, n * sizeof *image->object_id);
            memcpy(image->triangle_id + i, g->triangle + i, n * sizeof *image->triangle_id);
        }
    }
}

static rl_status cancelled(pt_state *s)
{
    s->force_reset = true;        /* a half-accumulated frame is no frame */
    return rl_error(RL_ERR_CANCELLED, "pt: cancelled by the progress callback");
}

/* What the frame needs before tracing: the backends' structures (built
 * once per scene), a new accumulation when anything changed, and the
 * primary visibility that does not change while accumulating (the traced
 * G-buffer once per reset; the rasterized one every frame, as the thesis'
 * extra render pass, Sec. 8.1). */
static rl_status prepare_frame(rl_renderer *r, pt_state *s, const rl_scene *scene, const rl_camera *cam,
                               const pt_settings *set, const rl_rect *area, rl_pt_stats *ps)
{
    double built_ms = 0.0;
    rl_status st = rl_pt_backends_prepare(&s->b, scene, set, set->threads, &built_ms);
    if (st != RL_OK)
        return st;
    const rl_scene_data *d = s->b.data;
    bool uniform = set->env_sampling == PT_ENV_UNIFORM;
    if (d->environment && s->b.env.uniform != uniform && (st = rl_pt_env_build(&s->b.env, d->environment, uniform)))
        return st;
    ps->time_build_ms = built_ms;
    if (!rl_renderer_progress(r, BUILD_SHARE))
        return cancelled(s);

    char *sig = rl_renderer_option_signature(r, option_matters);
    if (!sig)
        return RL_ERR_OUT_OF_MEMORY;
    bool need_reset = s->force_reset || !s->valid || !set->accumulate || s->scene_uid != rl_scene_uid(scene) ||
                      s->width != cam->width || s->height != cam->height || !rl_camera_equal(&s->cam, cam) ||
                      !same_rect(&s->area, area) || strcmp(s->signature, sig) != 0;
    if (need_reset) {
        if ((st = reset(s, scene, cam, set, area, sig)) != RL_OK)
            return st;
    } else {
        free(sig);
    }
    ps->reset = need_reset;

    rl_timer timer;
    rl_timer_start(&timer);
    if (set->primary == PT_PRIMARY_RASTER) {
        st = rl_gbuffer_raster(s->gbuf, scene, cam);
    } else if (need_reset) {
        st = rl_gbuffer_trace_part(s->gbuf, s->b.exact[RL_ACCEL_BVH], cam, area->x0, area->y0, area->x1, area->y1);
        ps->gbuffer_rays = (uint64_t)(area->x1 - area->x0) * (uint64_t)(area->y1 - area->y0);
    }
    if (st != RL_OK) {
        s->force_reset = true;
        return st;
    }
    ps->time_primary_ms = rl_timer_ms(&timer);
    return RL_OK;
}

/* The frame's spp samples over the tiles (primary rays, then the paths),
 * their counters summed into *sum. */
static rl_status trace_passes(rl_renderer *r, const frame *f, pt_counters *sum, rl_pt_stats *ps)
{
    int64_t num_tiles = (int64_t)f->tiles_x * ((f->area.y1 - f->area.y0 + TILE - 1) / TILE);
    pt_counters *tile_c = rl_calloc((size_t)num_tiles, sizeof *tile_c);
    double *part_ms = rl_calloc((size_t)num_tiles * 2, sizeof *part_ms);
    if (!tile_c || !part_ms) {
        free(tile_c);
        free(part_ms);
        return RL_ERR_OUT_OF_MEMORY;
    }
    rl_timer timer;
    rl_timer_start(&timer);
    bool stop = false;
    run_tiles(r, f, num_tiles, tile_c, part_ms, &stop);
    double pass_ms = rl_timer_ms(&timer);
    if (stop || !rl_renderer_progress(r, 1.0)) {
        free(tile_c);
        free(part_ms);
        return cancelled(f->s);
    }
    /* The frame's wall time, split between primary rays and paths as the
     * threads' time in each. */
    double part_sum[2] = { 0.0, 0.0 };
    for (int64_t t = 0; t < num_tiles; ++t) {
        part_sum[0] += part_ms[2 * t];
        part_sum[1] += part_ms[2 * t + 1];
    }
    double primary_share = part_sum[0] + part_sum[1] > 0.0 ? part_sum[0] / (part_sum[0] + part_sum[1]) : 0.0;
    ps->time_primary_ms += pass_ms * primary_share;
    ps->time_paths_ms += pass_ms * (1.0 - primary_share);
    free(part_ms);
    memset(sum, 0, sizeof *sum);
    for (int64_t t = 0; t < num_tiles; ++t)
        add_counters(sum, &tile_c[t]);
    free(tile_c);
    return RL_OK;
}

/* ---- adaptive sampling (see the top) ------------------------------------ */

static double luminance(rl_vec3 c)
{
    return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
}

/* Sample number `index` of pixel (x, y), primary ray and path in one go,
 * drawing in the order of the uniform passes (primary_tile, then
 * path_tile with a fresh sampler), so the samples are the same ones. */
static rl_vec3 pixel_sample(const frame *f, int x, int y, uint32_t index, pt_counters *c)
{
    size_t i = (size_t)y * f->width + x;
    uint32_t seed = f->set->sobol ? rl_pt_pixel_seed(f->set->seed, i) : 0;
    rl_rng_gpu *rng = f->set->sobol ? NULL : &f->s->rng[i];
    pt_sampler sp;
    pt_surface first;
    bool seen;
    rl_vec3 dir = rl_v3s(0.0f);   /* of the camera ray, for the environment */
    if (f->set->primary == PT_PRIMARY_TRACE) {
        rl_pt_sampler_init(&sp, rng, seed, index);
        rl_pt_sampler_seek(&sp, PT_SLOT_PIXEL);
        rl_vec2 j = rl_pt_sample_2d(&sp);
        rl_ray ray = rl_camera_frame_ray(&f->cam, (float)x + j.x, (float)y + j.y);
        dir = ray.d;
        rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
        c->rays[RL_RAY_PRIMARY]++;
        c->trace_q[RL_PT_BACKEND_BVH]++;
        rl_accel_intersect(f->s->b.exact[RL_ACCEL_BVH], &ray, &hit);
        seen = rl_pt_surface_at_hit(f->ctx.data, &hit, f->eye, ray.d, &first);
    } else {
        seen = first_vertex(f, i, &first);
        if (!seen && f->ctx.env)
            dir = rl_camera_frame_ray(&f->cam, (float)x + 0.5f, (float)y + 0.5f).d;
    }
    if (!seen)
        return rl_pt_escape_radiance(&f->ctx, dir);
    rl_pt_sampler_init(&sp, rng, seed, index);
    return rl_pt_trace_path(&f->ctx, &first, &sp, c);
}

/* A round: every pixel of tile t traces its share of samples. */
static void adaptive_tile(const frame *f, int64_t t, pt_counters *c)
{
    pt_state *s = f->s;
    int x0, y0, x1, y1;
    tile_bounds(f, t, &x0, &y0, &x1, &y1);
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            size_t i = (size_t)y * f->width + x;
            for (uint32_t k = 0; k < s->share[i]; ++k) {
                rl_vec3 L = pixel_sample(f, x, y, f->set->sample_offset + s->count[i] + k, c);
                if (!rl_vfinite(L))       /* as path_tile: counted, not added */
                    continue;
                s->accum[3 * i + 0] += L.x;
                s->accum[3 * i + 1] += L.y;
                s->accum[3 * i + 2] += L.z;
                double l = luminance(L);
                s->sum2[i] += l * l;
            }
            s->count[i] += s->share[i];
        }
    }
}

static void adaptive_round(const frame *f, int threads, int64_t num_tiles, pt_counters *tile_c)
{
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int64_t t = 0; t < num_tiles; ++t)
        adaptive_tile(f, t, &tile_c[t]);
}

/* s->err[n + i]: pixel i's relative error of the mean, averaged over its
 * 3 x 3 neighbours with at least two samples (s->err[i], the raw value,
 * is negative for the others); *converged: active pixels below the
 * threshold. */
static void pixel_errors(const frame *f, uint64_t *converged)
{
    pt_state *s = f->s;
    const int w = f->width, h = f->height;
    const size_t n = (size_t)w * h;
    float *raw = s->err, *smooth = s->err + n;
#pragma omp parallel for num_threads(f->set->threads) schedule(static)
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            double cnt = s->count[i];
            if (cnt < 2.0) {
                raw[i] = -1.0f;
                continue;
            }
            double mean = luminance(rl_v3((float)s->accum[3 * i], (float)s->accum[3 * i + 1],
                                          (float)s->accum[3 * i + 2])) / cnt;
            double var = (s->sum2[i] - cnt * mean * mean) / (cnt - 1.0);
            raw[i] = (float)(sqrt((var > 0.0 ? var : 0.0) / cnt) / (fabs(mean) + ADAPTIVE_EPS));
        }
    }
    uint64_t conv = 0;
#pragma omp parallel for num_threads(f->set->threads) schedule(static) reduction(+ : conv)
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            double sum = 0.0;
            int k = 0;
            for (int yy = y > 0 ? y - 1 : 0; yy <= y + 1 && yy < h; ++yy)
                for (int xx = x > 0 ? x - 1 : 0; xx <= x + 1 && xx < w; ++xx) {
                    float e = raw[(size_t)yy * w + xx];
                    if (e >= 0.0f) {
                        sum += e;
                        ++k;
                    }
                }
            size_t i = (size_t)y * w + x;
            smooth[i] = k > 0 ? (float)(sum / k) : INFINITY;
            if (active(f, x, y) && smooth[i] < f->set->adaptive_threshold)
                ++conv;
        }
    }
    *converged = conv;
}

/* Whether pixel i takes part in a round: active, not converged, and with
 * an error above zero (a zero weight would meet an infinite factor when
 * the cap binds everywhere else). */
static bool wants_samples(const frame *f, const float *e, size_t i, double thr)
{
    int x = (int)(i % (size_t)f->width), y = (int)(i / (size_t)f->width);
    return active(f, x, y) && isfinite(e[i]) && e[i] >= thr && e[i] > 0.0f;
}

/* The share of `budget` samples by error (s->err[n..]) among the active
 * pixels: t_i = min(cap, lambda e_i) with sum t_i = budget (water-filling;
 * lambda by bisection when the cap binds), zero for converged pixels,
 * rounded by the running sum so that the integers add up. One sequential
 * pass in pixel order keeps it independent of the threads. Returns the
 * samples handed out (less than budget when the cap or convergence leaves
 * some over). */
static uint64_t adaptive_shares(const frame *f, uint64_t budget, uint64_t num_active)
{
    pt_state *s = f->s;
    const size_t n = (size_t)f->width * f->height;
    const float *e = s->err + n;
    /* The raw errors are used up: their half holds the weights of the
     * pixels that want samples, packed, for the bisection. */
    float *packed = s->err;
    const double thr = f->set->adaptive_threshold;
    const double cap = ADAPTIVE_CAP * (double)budget / (double)num_active;
    double total = 0.0, e_max = 0.0, e_min = INFINITY;
    uint64_t positive = 0;
    for (size_t i = 0; i < n; ++i) {
        s->share[i] = 0;
        if (!wants_samples(f, e, i, thr))
            continue;
        packed[positive] = e[i];
        total += e[i];
        e_max = e[i] > e_max ? e[i] : e_max;
        e_min = e[i] < e_min ? e[i] : e_min;
        ++positive;
    }
    if (positive == 0 || !(total > 0.0))
        return 0;
    double lambda = (double)budget / total;
    if ((double)positive * cap <= (double)budget) {
        lambda = INFINITY;              /* every unconverged pixel takes the cap */
    } else if (lambda * e_max > cap) {
        double lo = lambda, hi = cap / e_min;
        for (int it = 0; it < 50; ++it) {
            double mid = 0.5 * (lo + hi), got = 0.0;
            for (uint64_t k = 0; k < positive; ++k)
                got += fmin(cap, mid * packed[k]);
            if (got < (double)budget)
                lo = mid;
            else
                hi = mid;
        }
        lambda = hi;
    }
    double run = 0.0;
    uint64_t given = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!wants_samples(f, e, i, thr))
            continue;
        run += fmin(cap, lambda * e[i]);
        uint64_t upto = (uint64_t)floor(run + 0.5);
        s->share[i] = (uint32_t)(upto - given);
        given = upto;
    }
    return given;
}

/* The frame with adaptive sampling: the uniform start up to
 * adaptive_min_spp, then rounds by error until the frame's spp x active
 * pixels are spent or every pixel has converged. *traced: pixels that got
 * samples; *samples: the paths traced. */
static rl_status adaptive_passes(rl_renderer *r, const frame *f, const pt_settings *set, pt_counters *sum,
                                 rl_pt_stats *ps, uint64_t *traced, uint64_t *samples)
{
    pt_state *s = f->s;
    const size_t n = (size_t)f->width * f->height;
    int64_t num_tiles = (int64_t)f->tiles_x * ((f->height + TILE - 1) / TILE);
    pt_counters *tile_c = rl_calloc((size_t)num_tiles, sizeof *tile_c);
    uint32_t *before = rl_alloc(n * sizeof *before);
    if (!tile_c || !before) {
        free(tile_c);
        free(before);
        return RL_ERR_OUT_OF_MEMORY;
    }
    memcpy(before, s->count, n * sizeof *before);
    uint64_t num_active = 0, spent = 0, counted = 0;
    uint32_t min_spp = (uint32_t)set->adaptive_min_spp, spp = (uint32_t)set->spp;
    for (size_t i = 0; i < n; ++i) {
        s->share[i] = 0;
        if (!active(f, (int)(i % (size_t)f->width), (int)(i / (size_t)f->width)))
            continue;
        ++num_active;
        counted += s->count[i];
        if (s->count[i] < min_spp) {
            uint32_t need = min_spp - s->count[i];
            s->share[i] = need < spp ? need : spp;
            spent += s->share[i];
        }
    }
    uint64_t budget = (uint64_t)spp * num_active;
    rl_timer timer;
    rl_timer_start(&timer);
    if (spent > 0)
        adaptive_round(f, set->threads, num_tiles, tile_c);
    counted += spent;
    uint64_t remaining = budget - spent;
    rl_status st = RL_OK;
    ps->adaptive_converged = 0;
    while (remaining > 0 && num_active > 0) {
        if (!rl_renderer_progress(r, BUILD_SHARE + (1.0 - BUILD_SHARE) * (double)(budget - remaining) / budget)) {
            st = cancelled(s);
            break;
        }
        /* A round at most doubles the mean count: the errors are then
         * re-estimated before the next. */
        uint64_t mean = counted / num_active, round = num_active * (mean > 1 ? mean : 1);
        round = round < remaining ? round : remaining;
        pixel_errors(f, &ps->adaptive_converged);
        uint64_t given = adaptive_shares(f, round, num_active);
        if (given == 0)
            break;
        adaptive_round(f, set->threads, num_tiles, tile_c);
        spent += given;
        counted += given;
        remaining -= round;
    }
    ps->time_paths_ms += rl_timer_ms(&timer);
    *traced = 0;
    for (size_t i = 0; i < n; ++i)
        *traced += s->count[i] != before[i];
    *samples = spent;
    memset(sum, 0, sizeof *sum);
    for (int64_t t = 0; t < num_tiles; ++t)
        add_counters(sum, &tile_c[t]);
    free(tile_c);
    free(before);
    return st == RL_OK && !rl_renderer_progress(r, 1.0) ? cancelled(s) : st;
}

/* The frame's statistics (rl_pt_stats and the generic ones). */
static void finish_stats(pt_state *s, const pt_settings *set, const pt_counters *sum, uint64_t traced,
                         uint64_t samples, uint64_t pixels, const rl_timer *total, rl_render_stats *stats,
                         rl_pt_stats *ps)
{
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        stats->rays[k] = ps->rays[k] = sum->rays[k];
    memcpy(ps->shadow_queries, sum->shadow_q, sizeof ps->shadow_queries);
    memcpy(ps->trace_queries, sum->trace_q, sizeof ps->trace_queries);
    ps->preillum_ends = sum->preillum_ends;
    stats->pixels_written = pixels;
    stats->samples = ps->samples = samples;
    ps->frames = s->frames;
    ps->spp = (double)s->total_samples / (double)pixels;
    ps->spp_frame = (uint32_t)set->spp;
    ps->pixels_traced = traced;
    uint64_t rays = 0;
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        rays += ps->rays[k];
    double ray_ms = ps->time_primary_ms + ps->time_paths_ms;
    ps->mrays_per_s = ray_ms > 0.0 ? (double)rays / (ray_ms * 1e3) : 0.0;
    ps->build_bvh_ms = s->b.exact[RL_ACCEL_BVH] ? s->b.exact_ms[RL_ACCEL_BVH] : 0.0;
    ps->build_grid_ms = s->b.exact[RL_ACCEL_GRID] ? s->b.exact_ms[RL_ACCEL_GRID] : 0.0;
    ps->build_embree_ms = s->b.exact[RL_ACCEL_EMBREE] ? s->b.exact_ms[RL_ACCEL_EMBREE] : 0.0;
    ps->build_linespace_ms = s->b.ls ? s->b.ls_ms : 0.0;
    ps->build_shadowmap_ms = s->b.sm ? s->b.sm_ms : 0.0;
    ps->build_ls_scene_ms = s->b.lss ? s->b.lss_ms : 0.0;
    ps->build_ls_object_ms = s->b.lso ? s->b.lso_ms : 0.0;
    ps->rng = set->rng;
    ps->sobol = set->sobol;
    ps->time_total_ms = rl_timer_ms(total);
}

/* Whether secondary rays through backend k find the triangles themselves
 * (not a Line Space payload), so emitters they hit can be MIS-weighted. */
static bool exact_backend(rl_pt_backend k)
{
    return k == RL_PT_BACKEND_BVH || k == RL_PT_BACKEND_GRID || k == RL_PT_BACKEND_EMBREE ||
           k == RL_PT_BACKEND_LS_CANDIDATES || k == RL_PT_BACKEND_LS_SCENE || k == RL_PT_BACKEND_LS_OBJECT;
}

static rl_status pt_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                           rl_image *image, rl_render_stats *stats)
{
    pt_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    rl_timer total;
    rl_timer_start(&total);
    pt_settings set;
    read_settings(r, &set);
    s->have_frame = false;
    rl_rect region = rl_renderer_region(r, cam->width, cam->height), area = region;
    bool part = region.x0 > 0 || region.y0 > 0 || region.x1 < cam->width || region.y1 < cam->height;
    /* A distributed frame filters its assembled image (pt_finish_regions). */
    bool filter_here = set.filter != RL_FILTER_NONE && !(part && rl_renderer_whole_passes_deferred(r));
    /* The per-pixel generators (Sec. 5.3) draw a varying number of values
     * per sample, so they cannot skip ahead to sample n as Sobol points do. */
    if (set.sample_offset != 0 && !set.sobol)
        return rl_error(RL_ERR_INVALID_ARG, "pt: sample_offset=%u needs rng=sobol (the per-pixel generators "
                        "cannot skip ahead)", set.sample_offset);
    if (part) {
        if (filter_here)
            return rl_error(RL_ERR_UNSUPPORTED, "pt: filter=%s filters the whole image; a region (rl --dist) "
                            "needs filter=none", rl_pt_filter_choices[set.filter]);
        if (set.primary == PT_PRIMARY_RASTER)
            return rl_error(RL_ERR_UNSUPPORTED, "pt: primary=raster rasterizes the whole image; a region "
                            "(rl --dist) needs primary=trace");
        if (set.adaptive)
            return rl_error(RL_ERR_UNSUPPORTED, "pt: adaptive=on shares a frame's paths over the whole image; a "
                            "region (rl --dist) needs adaptive=off");
        if (set.checkerboard) {
            /* The first frame's holes are the mean of their neighbours,
             * which may lie outside: trace those too. */
            area.x0 = region.x0 > 0 ? region.x0 - 1 : 0;
            area.y0 = region.y0 > 0 ? region.y0 - 1 : 0;
            area.x1 = region.x1 < cam->width ? region.x1 + 1 : cam->width;
            area.y1 = region.y1 < cam->height ? region.y1 + 1 : cam->height;
        }
    }
    rl_pt_stats ps;
    memset(&ps, 0, sizeof ps);
    rl_status st = prepare_frame(r, s, scene, cam, &set, &area, &ps);
    if (st != RL_OK)
        return st;

    frame f = {
        .s = s,
        .set = &set,
        .ctx = { .data = d, .b = &s->b, .shadow = set.shadow, .diffuse = set.diffuse, .specular = set.specular,
                 .max_depth = set.max_depth >= 0 ? set.max_depth : rl_pt_scene_max_depth(scene),
                 .rr_depth = set.rr_depth, .light_samples = set.light_samples, .rr = set.rr,
                 .mis = set.mis, .mis_hits = set.mis && exact_backend(set.diffuse),
                 .quad_solid_angle = set.mis && set.quad_solid_angle,
                 .tri_lights = set.mis && exact_backend(set.diffuse) && set.shadow != RL_PT_BACKEND_SHADOWMAP,
                 .vertex_slots = PT_SLOTS_VERTEX + PT_SLOTS_LIGHT * (uint32_t)set.light_samples *
                                                   (set.mis ? 1u : (d->num_lights ? d->num_lights : 1u)),
                 .background = set.background, .env = d->environment, .ggx_ms = set.ggx_ms },
        .cam = rl_camera_frame_make(cam),
        .eye = cam->eye,
        .width = cam->width,
        .height = cam->height,
        .area = area,
        .tiles_x = (area.x1 - area.x0 + TILE - 1) / TILE,
        .parity = s->frames & 1u,
    };
    if (d->environment) {
        /* The environment's sample takes one slot after the lights' (pathtrace_path.c). */
        f.ctx.env_nee = s->b.env.sampled && set.env_sampling != PT_ENV_BSDF && set.shadow != RL_PT_BACKEND_SHADOWMAP;
        f.ctx.env_slot = f.ctx.vertex_slots;
        f.ctx.vertex_slots += 1u;
    }
    pt_counters sum;
    uint64_t traced = 0, samples = 0;
    if (set.adaptive) {
        /* Whole frames only (a region refuses adaptive=on). */
        if ((st = adaptive_passes(r, &f, &set, &sum, &ps, &traced, &samples)) != RL_OK)
            return st;
    } else {
        if ((st = trace_passes(r, &f, &sum, &ps)) != RL_OK)
            return st;
        /* Sec. 6.5, eq. 8: the traced pixels' sample counts (all of them, or
         * the frame's checkerboard half); the samples are the region's, not
         * its ring's. */
        for (int y = area.y0; y < area.y1; ++y)
            for (int x = area.x0; x < area.x1; ++x)
                if (active(&f, x, y)) {
                    s->count[(size_t)y * cam->width + x] += (uint32_t)set.spp;
                    if (x >= region.x0 && x < region.x1 && y >= region.y0 && y < region.y1)
                        ++traced;
                }
        samples = traced * (uint64_t)set.spp;
    }
    s->frames++;
    s->total_samples += samples;

    resolve(s, &region, image);
    if (filter_here) {
        rl_timer timer;
        rl_timer_start(&timer);
        st = apply_filter(s, &set, s->total_samples, image, &ps.filter_weight);
        ps.time_filter_ms = rl_timer_ms(&timer);
        if (st != RL_OK)
            return st;
    }
    write_layers(s, &region, image);
    uint64_t pixels = (uint64_t)(region.x1 - region.x0) * (uint64_t)(region.y1 - region.y0);
    finish_stats(s, &set, &sum, traced, samples, pixels, &total, stats, &ps);
    stats->prep_ms = ps.time_build_ms;     /* the backends built for the scene */
    s->stats = ps;
    s->have_frame = true;
    return RL_OK;
}

/* After a distributed frame (rl_renderer_finish_regions): the filter of
 * Sec. 8.2 over the assembled image, guided by a G-buffer of the whole
 * image traced here (one ray per pixel), with the frame's samples over
 * all regions; the one-process image bit for bit, since the filter reads
 * only the accumulated colours, the G-buffer and the sample count. The
 * state is left to restart: it holds no accumulation of the whole image. */
static rl_status pt_finish_regions(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                                   rl_image *image, uint64_t samples)
{
    pt_state *s = state;
    pt_settings set;
    read_settings(r, &set);
    if (set.filter == RL_FILTER_NONE)
        return RL_OK;
    if (!rl_scene_get_data(scene))
        return RL_ERR_NOT_COMMITTED;
    rl_rect whole = { 0, 0, cam->width, cam->height };
    rl_pt_stats ps;
    memset(&ps, 0, sizeof ps);
    s->force_reset = true;
    rl_status st = prepare_frame(r, s, scene, cam, &set, &whole, &ps);
    s->force_reset = true;
    if (st != RL_OK)
        return st;
    float weight = 0.0f;
    return apply_filter(s, &set, samples, image, &weight);
}

/* The state of r if it is a "pt" renderer, else NULL. */
static pt_state *pt_of(const rl_renderer *r)
{
    if (!r || strcmp(rl_renderer_name(r), "pt") != 0)
        return NULL;
    return rl_renderer_state(r);
}

rl_status rl_pt_get_stats(const rl_renderer *r, rl_pt_stats *out)
{
    pt_state *s = pt_of(r);
    if (!s || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_pt_get_stats: needs a \"pt\" renderer and out");
    if (!s->have_frame)
        return rl_error(RL_ERR_INVALID_ARG, "rl_pt_get_stats: no frame rendered yet");
    *out = s->stats;
    return RL_OK;
}

rl_status rl_pt_reset(rl_renderer *r)
{
    pt_state *s = pt_of(r);
    if (!s)
        return rl_error(RL_ERR_INVALID_ARG, "rl_pt_reset: needs a \"pt\" renderer");
    s->force_reset = true;
    return RL_OK;
}

const rl_gbuffer *rl_pt_gbuffer(const rl_renderer *r)
{
    pt_state *s = pt_of(r);
    return s && s->have_frame ? s->gbuf : NULL;
}

uint64_t rl_pt_frame_samples(const rl_renderer *r, int width, int height, uint64_t frame)
{
    if (!pt_of(r) || width < 1 || height < 1)
        return 0;
    uint64_t n = (uint64_t)width * (uint64_t)height, spp = (uint64_t)rl_renderer_opt_int(r, "spp");
    if (!rl_renderer_opt_bool(r, "checkerboard"))
        return n * spp;
    /* active(): x + y + parity even; x + y even holds for the larger half
     * when both sides are odd. */
    uint64_t even = (width & height & 1) ? (n + 1) / 2 : n / 2;
    return spp * ((frame & 1u) == 0 ? even : n - even);
}

const uint32_t *rl_pt_sample_counts(const rl_renderer *r)
{
    pt_state *s = pt_of(r);
    return s && s->have_frame ? s->count : NULL;
}

const rl_renderer_class rl_pt_renderer_class = {
    .info = { .name = "pt",
              .description = "Progressive path tracing with NEE, Russian roulette and Phong sampling; "
                             "Line Space backends",
              .reference = "Schröder 2017", .progressive = true, .default_time_s = PT_DEFAULT_TIME_S,
              .regions = true,
              /* reset(): accumulation, sample counts, generators, first hits and
               * directions, the G-buffer of the first hits, and adaptive
               * sampling's buffers */
              .frame_bytes_per_pixel = 3 * sizeof(double) + sizeof(uint32_t) + sizeof(rl_rng_gpu) + sizeof(rl_hit) +
                                       sizeof(rl_vec3) + RL_GBUFFER_BYTES_PER_PIXEL +
                                       /* adaptive=on: squared sums, errors, shares, counts */
                                       sizeof(double) + 2 * sizeof(float) + 2 * sizeof(uint32_t) },
    .options = pt_options,
    .num_options = NUM_OPTIONS,
    .state_size = sizeof(pt_state),
    .render = pt_render,
    .release = pt_release,
    .check = pt_check,
    .reset = pt_reset_state,
    .finish_regions = pt_finish_regions,
};
