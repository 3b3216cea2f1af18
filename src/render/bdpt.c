/* bdpt.c: renderer "bdpt", bidirectional path tracing with multiple
 * importance sampling over all strategies (Veach 1997, Ch. 10), the light
 * transport of Schröder 2017's outlook (Sec. 8.3). The sample itself is in
 * bdpt_path.c; this file runs the frames.
 *
 * Options (defaults):
 *   spp = 1            samples (a camera and a light subpath) per pixel and frame
 *   max_depth = -1     surface interactions after the camera hit, as pt:
 *                      paths of up to max_depth + 2 edges; -1 = the scene's
 *                      root attribute max_path_length, else 3
 *   rr = true, rr_depth = 4    Russian roulette from that bounce on
 *   mis = power        power (power heuristic, beta = 2) | uniform (each
 *                      strategy one over the number that can make the path)
 *   strategy = all     all | "s,t": that strategy alone, unweighted (a
 *                      debugging view; each alone estimates the paths of
 *                      s + t vertices without bias)
 *   seed = 0, background = 0,0,0, ggx_ms = true, accumulate = true,
 *   threads = 0 (all)
 *
 * A frame: spp passes over 16 x 16 tiles handed out dynamically to OpenMP
 * threads. Every pixel sample draws from its own PCG32 stream, keyed by
 * (seed, sample number) and the pixel, so a pixel's camera-side sum does
 * not depend on the thread count. Light tracing (t = 1) lands anywhere in
 * the image: each tile keeps its splats in a list, and after the pass the
 * lists are added to the sums in tile order, so the image is the same for
 * any thread count. The pixel's value is its sum over its samples (the
 * splats carry the film-area factor, bdpt_path.c).
 *
 * Accumulation as pt: the per-pixel sums in double over frames; any change
 * of camera, scene, size or option restarts them. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "core/params.h"
#include "render/bdpt_internal.h"
#include "render/renderer.h"
#include "rl/rl_timer.h"

#define TILE 16
#define BUILD_SHARE 0.1
#define BDPT_DEFAULT_TIME_S 10.0

static const char *const mis_choices[] = { "power", "uniform", NULL };

static const rl_option_info bdpt_options[] = {
    { "spp", RL_OPT_INT, "1", "samples (a camera and a light subpath) per pixel and frame", 1, 65536, NULL },
    { "max_depth", RL_OPT_INT, "-1",
      "surface interactions after the camera hit, as pt (paths of up to max_depth + 2 edges; -1: the "
      "scene's root attribute max_path_length, else 3)", -1, 1024, NULL },
    { "rr", RL_OPT_BOOL, "true", "Russian roulette on the subpath lengths", 0, 0, NULL },
    { "rr_depth", RL_OPT_INT, "4", "bounce from which Russian roulette may end a subpath", 0, 1024, NULL },
    { "mis", RL_OPT_ENUM, "power",
      "weights of the strategies: power (power heuristic, Veach 1997) or uniform (one over the number of "
      "strategies that can make the path)", 0, 0, mis_choices },
    { "strategy", RL_OPT_STRING, "all",
      "all, or \"s,t\": only the strategy with s light and t camera vertices, unweighted (debugging)",
      0, 0, NULL },
    { "seed", RL_OPT_INT, "0", "seed of the per-sample generators", 0, 9007199254740991.0, NULL },
    { "background", RL_OPT_COLOR, "0,0,0",
      "radiance arriving from every direction where a camera ray leaves the scene (no light samples it); a "
      "scene \"environment\" replaces it", 0, 0, NULL },
    { "ggx_ms", RL_OPT_BOOL, "true", "GGX energy compensation (Kulla & Conty 2017), as pt", 0, 0, NULL },
    { "accumulate", RL_OPT_BOOL, "true", "progressive accumulation across frames", 0, 0, NULL },
    { "threads", RL_OPT_INT, "0", "OpenMP threads (0 = all)", 0, 1024, NULL },
};
#define NUM_OPTIONS (sizeof bdpt_options / sizeof bdpt_options[0])

typedef struct bdpt_state {
    pt_backends b;
    bool valid, force_reset;
    uint64_t scene_uid;
    rl_camera cam;
    int width, height;
    char *signature;
    double *accum;                 /* 3 per pixel */
    uint64_t samples;              /* per pixel, all pixels alike */
} bdpt_state;

static void bdpt_reset_state(void *state)
{
    bdpt_state *s = state;
    if (s)
        s->force_reset = true;
}

static void bdpt_release(void *state)
{
    bdpt_state *s = state;
    rl_pt_backends_release(&s->b);
    free(s->accum);
    free(s->signature);
}

/* "s,t" with s >= 0, t >= 1; false if not of that form. */
static bool parse_strategy(const char *v, int *s, int *t)
{
    if (strcmp(v, "all") == 0) {
        *s = *t = -1;
        return true;
    }
    char *end;
    long a = strtol(v, &end, 10);
    if (end == v || *end != ',' || a < 0 || a > 2048)
        return false;
    const char *q = end + 1;
    long b = strtol(q, &end, 10);
    if (end == q || *end != '\0' || b < 1 || b > 2048)
        return false;
    *s = (int)a;
    *t = (int)b;
    return true;
}

static rl_status bdpt_check(const char *key, const char *value)
{
    int s, t;
    if (strcmp(key, "strategy") == 0 && !parse_strategy(value, &s, &t))
        return rl_error(RL_ERR_INVALID_ARG, "bdpt: strategy=%s: expected all or s,t (s >= 0 light vertices, "
                        "t >= 1 camera vertices)", value);
    return RL_OK;
}

typedef struct bd_frame {
    bdpt_state *s;
    bd_ctx ctx;
    uint64_t seed;
    int tiles_x;
    bd_splats *splats;             /* per tile */
    uint64_t *rays;                /* per tile */
    bool *failed;                  /* per tile: scratch out of memory */
} bd_frame;

static void sample_tile(const bd_frame *f, int64_t t, uint64_t sample)
{
    int w = f->ctx.cam.width, h = f->ctx.cam.height;
    int x0 = (int)(t % f->tiles_x) * TILE, y0 = (int)(t / f->tiles_x) * TILE;
    int x1 = x0 + TILE < w ? x0 + TILE : w, y1 = y0 + TILE < h ? y0 + TILE : h;
    bd_scratch sc;
    if (bd_scratch_init(&sc, f->ctx.max_depth) != RL_OK) {
        f->failed[t] = true;
        return;
    }
    uint64_t key = rl_hash64(f->seed * 0x9e3779b97f4a7c15ull + sample);
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            size_t i = (size_t)y * w + x;
            rl_rng rng;
            rl_rng_seed(&rng, key, i);
            rl_vec3 L = bd_sample(&f->ctx, &sc, &rng, x, y, &f->splats[t], &f->rays[t]);
            if (!rl_vfinite(L))
                continue;          /* a NaN would poison the pixel for good */
            f->s->accum[3 * i + 0] += L.x;
            f->s->accum[3 * i + 1] += L.y;
            f->s->accum[3 * i + 2] += L.z;
        }
    }
    bd_scratch_release(&sc);
}

static rl_status cancelled(bdpt_state *s)
{
    s->force_reset = true;
    return rl_error(RL_ERR_CANCELLED, "bdpt: cancelled by the progress callback");
}

/* The spp passes; after each the tiles' splats join the sums in tile order. */
static rl_status run_passes(rl_renderer *r, bd_frame *f, int spp, int threads, uint64_t *rays)
{
    int h = f->ctx.cam.height;
    int64_t num_tiles = (int64_t)f->tiles_x * ((h + TILE - 1) / TILE);
    f->splats = rl_calloc((size_t)num_tiles, sizeof *f->splats);
    f->rays = rl_calloc((size_t)num_tiles, sizeof *f->rays);
    f->failed = rl_calloc((size_t)num_tiles, sizeof *f->failed);
    rl_status st = f->splats && f->rays && f->failed ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (int k = 0; st == RL_OK && k < spp; ++k) {
        uint64_t sample = f->s->samples + (uint64_t)k;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
        for (int64_t t = 0; t < num_tiles; ++t)
            sample_tile(f, t, sample);
        for (int64_t t = 0; t < num_tiles; ++t) {
            bd_splats *sp = &f->splats[t];
            if (sp->failed || f->failed[t]) {
                st = RL_ERR_OUT_OF_MEMORY;
                break;
            }
            for (size_t j = 0; j < sp->n; ++j) {
                double *a = &f->s->accum[3 * (size_t)sp->v[j].pixel];
                a[0] += sp->v[j].r;
                a[1] += sp->v[j].g;
                a[2] += sp->v[j].b;
            }
            sp->n = 0;
        }
        if (st == RL_OK && !rl_renderer_progress(r, BUILD_SHARE + (1.0 - BUILD_SHARE) * (k + 1) / spp))
            st = cancelled(f->s);
    }
    *rays = 0;
    for (int64_t t = 0; f->rays && t < num_tiles; ++t)
        *rays += f->rays[t];
    for (int64_t t = 0; f->splats && t < num_tiles; ++t)
        free(f->splats[t].v);
    free(f->splats);
    free(f->rays);
    free(f->failed);
    if (st == RL_ERR_OUT_OF_MEMORY)
        f->s->force_reset = true;   /* half a pass is in the sums */
    return st;
}

static rl_status bdpt_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                             rl_image *image, rl_render_stats *stats)
{
    bdpt_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    rl_timer total;
    rl_timer_start(&total);
    int threads = (int)rl_renderer_opt_int(r, "threads");
#ifdef _OPENMP
    threads = threads > 0 ? threads : omp_get_max_threads();
#else
    threads = 1;
#endif
    /* pt's backends with the BVH for every ray: the light table and the
     * covers of quad lights come with them. */
    pt_settings set;
    memset(&set, 0, sizeof set);
    set.shadow = set.diffuse = set.specular = RL_PT_BACKEND_BVH;
    set.primary = PT_PRIMARY_TRACE;
    set.ls_n = 5;
    set.ls_k = 8;
    double built_ms = 0.0;
    rl_status st = rl_pt_backends_prepare(&s->b, scene, &set, threads, &built_ms);
    if (st != RL_OK)
        return st;
    if (!rl_renderer_progress(r, BUILD_SHARE))
        return cancelled(s);

    char *sig = rl_renderer_option_signature(r, NULL);
    if (!sig)
        return RL_ERR_OUT_OF_MEMORY;
    size_t n = (size_t)cam->width * cam->height;
    bool reset = s->force_reset || !s->valid || !rl_renderer_opt_bool(r, "accumulate") ||
                 s->scene_uid != rl_scene_uid(scene) || s->width != cam->width || s->height != cam->height ||
                 !rl_camera_equal(&s->cam, cam) || strcmp(s->signature, sig) != 0;
    if (reset) {
        if (!s->accum || s->width != cam->width || s->height != cam->height) {
            free(s->accum);
            s->accum = rl_calloc(3 * n, sizeof *s->accum);
            if (!s->accum) {
                free(sig);
                s->valid = false;
                return RL_ERR_OUT_OF_MEMORY;
            }
        }
        memset(s->accum, 0, 3 * n * sizeof *s->accum);
        free(s->signature);
        s->signature = sig;
        s->scene_uid = rl_scene_uid(scene);
        s->cam = *cam;
        s->width = cam->width;
        s->height = cam->height;
        s->samples = 0;
        s->valid = true;
        s->force_reset = false;
    } else {
        free(sig);
    }

    int spp = (int)rl_renderer_opt_int(r, "spp");
    int max_depth = (int)rl_renderer_opt_int(r, "max_depth");
    bd_frame f = { .s = s, .seed = (uint64_t)rl_renderer_opt_int(r, "seed"),
                   .tiles_x = (cam->width + TILE - 1) / TILE };
    bd_ctx *c = &f.ctx;
    c->data = d;
    c->b = &s->b;
    c->max_depth = max_depth >= 0 ? max_depth : rl_pt_scene_max_depth(scene);
    c->rr = rl_renderer_opt_bool(r, "rr");
    c->rr_depth = (int)rl_renderer_opt_int(r, "rr_depth");
    c->mis = (bd_mis)rl_renderer_opt_enum(r, "mis");
    parse_strategy(rl_renderer_opt_string(r, "strategy"), &c->only_s, &c->only_t);
    c->background = rl_renderer_opt_color(r, "background");
    c->ggx_ms = rl_renderer_opt_bool(r, "ggx_ms");
    /* The environment shares the light subpaths with the light table half
     * and half (all of them when the table is empty): a choice by power
     * would need the sky's power against the lights', and either is
     * unbiased. A black environment is reached by escaping rays alone. */
    c->environment = d->environment;
    c->env = &s->b.env;
    c->env_pick = d->environment && s->b.env.sampled ? (s->b.lights.count > 0 ? 0.5f : 1.0f) : 0.0f;
    c->light_share = 1.0f - c->env_pick;
    c->env_centre = s->b.lights.centre;
    c->env_radius = 1.001f * s->b.lights.radius;
    c->env_disk_pdf = 1.0f / (RL_PI * c->env_radius * c->env_radius);
    c->cam = rl_camera_frame_make(cam);
    c->forward = rl_neg(c->cam.w);
    c->film_area = 4.0f * c->cam.tan_half_fov_y * c->cam.tan_half_fov_y * c->cam.aspect;

    uint64_t rays = 0;
    if ((st = run_passes(r, &f, spp, threads, &rays)) != RL_OK)
        return st;
    s->samples += (uint64_t)spp;

    double inv = 1.0 / (double)s->samples;
    for (size_t i = 0; i < n; ++i)
        image->color[i] = rl_v4((float)(s->accum[3 * i] * inv), (float)(s->accum[3 * i + 1] * inv),
                                (float)(s->accum[3 * i + 2] * inv), 1.0f);
    /* Depth and IDs are not this renderer's: the layers stay cleared. */
    stats->rays[RL_RAY_DIFFUSE] = rays;
    stats->pixels_written = n;
    stats->samples = n * (uint64_t)spp;
    stats->prep_ms = built_ms;
    (void)total;
    return RL_OK;
}

const rl_renderer_class rl_bdpt_renderer_class = {
    .info = { .name = "bdpt",
              .description = "Bidirectional path tracing, MIS (power heuristic) over all strategies",
              .reference = "Veach 1997 Ch. 10; Schröder 2017 Sec. 8.3 (outlook)", .progressive = true,
              .default_time_s = BDPT_DEFAULT_TIME_S,
              .frame_bytes_per_pixel = 3 * sizeof(double) },
    .options = bdpt_options,
    .num_options = NUM_OPTIONS,
    .state_size = sizeof(bdpt_state),
    .render = bdpt_render,
    .release = bdpt_release,
    .check = bdpt_check,
    .reset = bdpt_reset_state,
};
