/* bench_pt.c: `rl bench pt`: the measurements of Schröder 2017, Ch. 10-12,
 * for the path tracer "pt" and the Line Space, as tables on stdout and one
 * JSON record:
 *   generation    Table 1: grid and Line Space build times (and memory,
 *                 fill) for the thesis' scene / voxel resolution / N rows
 *   scenes        Diagram 1: frame time and Mrays/s at 1280x720, 1 spp,
 *                 all secondary and shadow rays through the grid vs the
 *                 PNMT Line Space (and our BVH), for the 7 scenes of Sec. 9.3
 *   diffuse       Diagram 2: Cornell box with the bunny-sized model, diffuse
 *                 rays through each structure, shadows by shadow maps; each
 *                 Line Space variant at voxels 8^3..64^3 and its best
 *                 (the thesis tuned the resolution per structure), and a
 *                 frame without diffuse rays as the floor of the rays' share
 *   shadow        Diagram 3: the same scene, shadow rays through each
 *                 structure (and shadow maps), diffuse rays by the BVH;
 *                 then shadow and first-bounce diffuse rays alone, also
 *                 through the scene and object Line Spaces (Sec. 13.1-13.2,
 *                 with their build time and memory); both sections also
 *                 render with ls-object and ls-scene
 *   error         RMSE and SSIM of every variant against a converged BVH
 *                 reference at equal sample counts, and the time each needs
 *                 to reach the RMSE the BVH reaches at 4, 16, 64 spp
 *   specular      Sec. 11.2, 12.3: mirror and refraction rays through the
 *                 exact grid (specular=exact, the thesis) or the diffuse
 *                 payload (specular=diffuse), on ls-cornell's mirror cuboid
 *   accumulation  RMSE against total samples, and what each filter of
 *                 Sec. 8.2 does to RMSE and SSIM at 1, 4 and 16 spp
 *   convergence   issue 37: RMSE against time on Bitterli's Cornell box
 *                 settings, pt's defaults vs the thesis' settings and each
 *                 improvement switched off (bench_pt_conv.c)
 *   bdpt          issue 37: pt against bdpt at equal CPU time on the Cornell
 *                 box lit directly and through a shade (bench_pt_bdpt.c)
 *   hybrid        Sec. 8.4: gl-pt without and with the CPU's light paths at
 *                 equal CPU time on the same scenes (bench_pt_bdpt.c)
 *
 * Every section but convergence measures the thesis' configuration, so
 * make_pt sets the thesis' sampling options explicitly (rng=hybrid,
 * mis=off, light_samples=1, rr_depth=2): pt's defaults changed in issue 37
 * and the records of bench/README stay comparable.
 *
 * Timing: per configuration one warm-up render (it builds and caches the
 * grid, Line Space and shadow maps, which the thesis also builds once per
 * scene, Fig. 8), then the fastest of 5 renders (--quick: 1), with
 * accumulate=false so that each render is one frame of spp samples.
 * Mrays/s counts every ray of the frame (primary, shadow, diffuse,
 * reflection, refraction; a shadow-map lookup counts as a shadow ray, as
 * the thesis counts it in Diagram 3). */
#define _POSIX_C_SOURCE 200809L
#include "bench_pt.h"

#include "bench_args.h"
#include "bench_pt_bdpt.h"
#include "bench_pt_conv.h"
#include "bench_rays.h"
#include "bench_util.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "rl/rl_gl.h"
#include "rl/rl_linespace.h"
#include "rl/rl_metrics.h"

#define note(...) bench_note("pt", __VA_ARGS__)

static const char bench_pt_help[] =
    "usage: rl bench pt [options]\n"
    "\n"
    "Measures the path tracer (renderer pt) and the Line Space as in Schroeder 2017,\n"
    "Ch. 10-12, and writes a table and JSON. Sections:\n"
    "  generation    grid and Line Space build time, memory and fill for the rows\n"
    "                of the thesis' Table 1 (Cornell box with boxes/teapot/bunny/dragon)\n"
    "  scenes        frame time and Mrays/s, all rays through the grid vs the PNMT\n"
    "                Line Space vs our BVH, for the 7 scenes of Sec. 9.3 (Diagram 1)\n"
    "  diffuse       Cornell box + bunny: diffuse rays through grid, BVH, and each\n"
    "                Line Space variant (exact and fixed-k candidates, PNMT,\n"
    "                pre-illuminated) at voxels\n"
    "                8^3..64^3, best per variant; shadows by shadow maps (Diagram 2)\n"
    "  shadow        the same for shadow rays, plus shadow maps; diffuse rays by\n"
    "                the BVH (Diagram 3); then the frame's shadow rays alone through\n"
    "                the BVH, the grid and each Line Space (Mrays/s, occluded counts),\n"
    "                and first-bounce diffuse rays through the exact ones; both\n"
    "                sections also time ls-object and ls-scene (Sec. 13.1, 13.2)\n"
    "  error         RMSE/SSIM of each variant (PNMT and pre-illuminated at every\n"
    "                voxel resolution) against a converged BVH reference at equal\n"
    "                spp, and time to reach the BVH's RMSE at 4/16/64 spp\n"
    "  specular      mirror/refraction rays through the exact grid (the thesis) or\n"
    "                the diffuse Line Space payload: RMSE, SSIM, ms/spp on ls-cornell\n"
    "  accumulation  RMSE against total samples; each filter's RMSE/SSIM\n"
    "  convergence   RMSE against time on cornell:variant=bitterli: pt's defaults, the\n"
    "                thesis' settings, each improvement off, light_samples 1/2/4,\n"
    "                adaptive sampling and the a-trous denoiser;\n"
    "                time to RMSE 0.0069 and 0.0014, RMSE at 64 spp (issue 37)\n"
    "  bdpt          pt against bdpt at equal CPU time (5 s per thread; quick 0.5)\n"
    "                on cornell:variant=bitterli and variant=shade, 96x96 (quick\n"
    "                32x32): RMSE against a 512-spp bdpt reference, channel means\n"
    "  hybrid        gl-pt without and with light_paths=1024 (Sec. 8.4; overlapped\n"
    "                and not) at equal CPU time (5 s per thread; quick 1) on the\n"
    "                same scenes, 48x48 (quick 32x32), reference bdpt 1024 spp\n"
    "                (quick 64): fps, RMSE, channel means;\n"
    "                skipped without a GL 4.5 context\n"
    "\n"
    "options:\n"
    "  --size WxH        frame sections; default 1280x720 (the thesis)\n"
    "  --error-size WxH  error and accumulation sections; default 320x180\n"
    "  --ref-spp N       samples of the BVH reference; default 1024\n"
    "  --spp-max N       samples accumulated per variant in the error section; default 64\n"
    "  --conv-size N     convergence: image side; default 512 (quick: 64)\n"
    "  --conv-ref-spp N  convergence: reference samples, rendered once and cached\n"
    "                    beside --out; default 4096 (quick: 64); 16384 on a big machine;\n"
    "                    progress is saved beside it (.part) and a rerun continues it\n"
    "  --conv-ref-budget S  convergence: stop rendering the reference after S seconds\n"
    "                    (wall clock, at a chunk's end), save it and exit 1; rerun the\n"
    "                    same command to go on; default 0 = no limit\n"
    "  --conv-spp-max N  convergence: the longest curves' samples; default 1024 (quick: 16)\n"
    "  --conv-configs L  convergence: only these configurations (defaults, thesis,\n"
    "                    mis=off, rng=hybrid, rr=false, light_samples=2, light_samples=4,\n"
    "                    adaptive=on, quad_sampling=solid_angle, atrous,\n"
    "                    adaptive+atrous; none: only --conv-set's)\n"
    "  --conv-set KV     convergence: one more configuration, \"custom\", to\n"
    "                    --conv-spp-max with pt's options KEY=VALUE,KEY=VALUE,... (an\n"
    "                    A/B of a setting against the same cached reference)\n"
    "  --max-memory GB   skip Line Spaces estimated to need more; default 60% of RAM\n"
    "  --builds N        generation: the fastest of N builds per row; default 3 (quick: 1)\n"
    "  --fixed-k K       generation: also build fixed lists of K (even; default 8), for\n"
    "                    the cost of the dynamic lists (time, memory, truncated shafts)\n"
    "  --small-pages     generation: build without transparent huge pages\n"
    "                    (rl_linespace_desc.small_pages), for an A/B of the page size\n"
    "  --threads N       threads; default all cores\n"
    "  --only LIST       comma-separated subset of the sections above\n"
    "  --out FILE.json   default bench/results/pt-YYYYMMDD-HHMMSS.json\n"
    "  --quick           tiny run: Cornell box only, 128x72 frames, 64x36 error\n"
    "                    images, 64 reference spp, 8 spp per variant, one timed render\n"
    "\n"
    "example:\n"
    "  rl bench pt --only generation,shadow\n";

enum { SEC_GENERATION, SEC_SCENES, SEC_DIFFUSE, SEC_SHADOW, SEC_ERROR, SEC_SPECULAR, SEC_ACCUMULATION,
       SEC_CONVERGENCE, SEC_BDPT, SEC_HYBRID, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "generation", "scenes",       "diffuse",
                                                      "shadow",     "error",        "specular",
                                                      "accumulation", "convergence", "bdpt", "hybrid" };

/* Schröder 2017, Table 1: generation times in ms on a GeForce GTX 1080. */
static const struct gen_row {
    const char *scene;        /* built-in with parameters */
    int thesis_scene;         /* numbering of Sec. 9.3 */
    int res, n;
    double thesis_grid_ms, thesis_ls_ms;
    bool quick;
} gen_rows[] = {
    { "ls-cornell:model=boxes", 4, 8, 4, 43, 154, true },
    { "ls-cornell:model=boxes", 4, 8, 5, 43, 269, true },
    { "ls-cornell:model=teapot", 5, 8, 5, 58, 644, false },
    { "ls-cornell:model=teapot", 5, 32, 5, 47, 1795, false },
    { "ls-cornell:model=bunny", 6, 8, 5, 51, 3915, false },
    { "ls-cornell:model=bunny", 6, 64, 5, 71, 10081, false },
    { "ls-cornell:model=dragon", 7, 8, 5, 95, 94393, false },
    { "ls-cornell:model=dragon", 7, 72, 5, 88, 53675, false },
};

/* Sec. 9.3: the seven scenes, with the Line Space voxel resolution we use
 * for each (the thesis tuned it per scene and names these in Table 1). */
static const struct scene_row {
    const char *scene;
    int thesis_scene;
    int max_depth;            /* the thesis' maximum path length */
    int ls_res;
    bool quick;
} scene_rows[] = {
    { "ls-open:model=teapot", 1, 2, 32, false },
    { "ls-open:model=bunny", 2, 2, 64, false },
    { "ls-open:model=dragon", 3, 2, 72, false },
    { "ls-cornell:model=boxes", 4, 3, 8, true },
    { "ls-cornell:model=teapot", 5, 3, 32, false },
    { "ls-cornell:model=bunny", 6, 3, 64, false },
    { "ls-cornell:model=dragon", 7, 3, 72, false },
};

#define MAX_SCENES 8
#define RUNS 5               /* best of 5: frame times on a shared 2-core machine vary by up to 30 % */
#define PT_SEED "1"
#define REF_SEED "90210"

typedef struct bpt_args {
    int width, height, err_width, err_height;
    long long ref_spp, spp_max, threads;
    long long max_memory_gb;       /* 0: 60% of physical memory */
    long long builds;              /* generation: fastest of this many builds */
    long long fixed_k;             /* generation: fixed lists of k for the cost of dynamic ones */
    long long conv_size, conv_ref_spp, conv_spp_max;
    double conv_ref_budget;        /* seconds of reference rendering per run; 0 = no limit */
    const char *conv_configs;
    const char *conv_set;
    bool has_conv_size, has_conv_ref_spp, has_conv_spp_max;
    bool has_size, has_err_size, has_ref_spp, has_spp_max, has_builds, has_fixed_k, quick, small_pages;
    unsigned sections;
    const char *out;
} bpt_args;

typedef struct bpt {
    const bpt_args *a;
    int threads, runs;
    double max_memory_bytes;
    struct { char name[64]; rl_scene *scene; } scenes[MAX_SCENES];
    int num_scenes;
    rl_image *reference;           /* error/accumulation reference, when made */
    const char *out_path;          /* the JSON record (convergence caches its reference beside it) */
    double reference_ms;
    char reason[256];
} bpt;

/* One configuration of the path tracer. */
typedef struct pt_config {
    const char *label;
    const char *shadow, *diffuse;
    const char *filter;            /* NULL: none */
    int grid_res;                  /* 0: the grid heuristic */
    int max_depth;                 /* 0: the renderer's default */
    bool direct_only;              /* max_depth 0: no secondary rays */
    const char *ls_origin;         /* NULL: the renderer's default (offset) */
    const char *specular;          /* NULL: the renderer's default (exact) */
    bool ls_fixed;                 /* the thesis' fixed lists of k = 8 (ls_dynamic=false) */
    const char *ls_scene_inner;    /* NULL: the renderer's default (object) */
    int spp;
    bool accumulate;
    const char *seed;
} pt_config;

static rl_status fail(bpt *b, rl_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static rl_status fail(bpt *b, rl_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(b->reason, sizeof b->reason, fmt, ap);
    va_end(ap);
    return st;
}

/* A built-in scene with parameters, loaded once. */
static rl_status scene_get(bpt *b, const char *name, rl_scene **out)
{
    for (int i = 0; i < b->num_scenes; i++)
        if (strcmp(b->scenes[i].name, name) == 0) {
            *out = b->scenes[i].scene;
            return RL_OK;
        }
    if (b->num_scenes == MAX_SCENES) {
        /* Keep memory bounded: the dragon scenes are large. */
        rl_scene_release(b->scenes[0].scene);
        memmove(&b->scenes[0], &b->scenes[1], sizeof b->scenes[0] * (MAX_SCENES - 1));
        b->num_scenes--;
    }
    char *source = NULL, *params = NULL;
    if (!cli_split_source(name, &source, &params))
        return fail(b, RL_ERR_OUT_OF_MEMORY, "out of memory");
    note("loading %s", name);
    rl_scene *s = NULL;
    rl_status st = rl_scene_create_builtin(source, params, &s);
    free(source);
    free(params);
    if (st != RL_OK)
        return st;
    snprintf(b->scenes[b->num_scenes].name, sizeof b->scenes[0].name, "%s", name);
    b->scenes[b->num_scenes++].scene = s;
    *out = s;
    return RL_OK;
}

static rl_status set_num(rl_renderer *r, const char *key, long long value)
{
    char text[32];
    snprintf(text, sizeof text, "%lld", value);
    return rl_renderer_set(r, key, text);
}

static rl_status make_pt(const bpt *b, const pt_config *c, rl_renderer **out)
{
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create("pt", &r);
    if (st == RL_OK) st = set_num(r, "threads", b->threads);
    /* The thesis' sampling (pt's defaults before issue 37). */
    if (st == RL_OK) st = rl_renderer_set(r, "rng", "hybrid");
    if (st == RL_OK) st = rl_renderer_set(r, "mis", "off");
    if (st == RL_OK) st = rl_renderer_set(r, "light_samples", "1");
    if (st == RL_OK) st = rl_renderer_set(r, "rr_depth", "2");
    if (st == RL_OK) st = rl_renderer_set(r, "seed", c->seed ? c->seed : PT_SEED);
    if (st == RL_OK) st = rl_renderer_set(r, "shadow", c->shadow);
    if (st == RL_OK) st = rl_renderer_set(r, "diffuse", c->diffuse);
    if (st == RL_OK) st = rl_renderer_set(r, "filter", c->filter ? c->filter : "none");
    if (st == RL_OK && c->filter) st = rl_renderer_set(r, "filter_fade", "0");
    if (st == RL_OK) st = set_num(r, "grid_res", c->grid_res);
    if (st == RL_OK && c->max_depth) st = set_num(r, "max_depth", c->max_depth);
    if (st == RL_OK && c->direct_only) st = set_num(r, "max_depth", 0);
    if (st == RL_OK && c->ls_origin) st = rl_renderer_set(r, "ls_origin", c->ls_origin);
    if (st == RL_OK && c->ls_scene_inner) st = rl_renderer_set(r, "ls_scene_inner", c->ls_scene_inner);
    if (st == RL_OK && c->specular) st = rl_renderer_set(r, "specular", c->specular);
    if (st == RL_OK && c->ls_fixed) st = rl_renderer_set(r, "ls_dynamic", "false");
    if (st == RL_OK) st = set_num(r, "spp", c->spp ? c->spp : 1);
    if (st == RL_OK) st = rl_renderer_set(r, "accumulate", c->accumulate ? "true" : "false");
    if (st != RL_OK) {
        rl_renderer_release(r);
        r = NULL;
    }
    *out = r;
    return st;
}

static rl_camera scene_camera(const rl_scene *scene, int width, int height)
{
    rl_camera cam;
    if (rl_scene_get_camera(scene, NULL, &cam) != RL_OK)
        cam = rl_camera_frame_bounds(rl_scene_get_data(scene)->bounds, width, height);
    cam.width = width;
    cam.height = height;
    return cam;
}

/* One warm-up frame (builds what the configuration needs), then the
 * fastest of b->runs frames. */
static rl_status frame_timed(const bpt *b, const pt_config *c, const rl_scene *scene, int width,
                             int height, rl_render_stats *best, double *warmup_ms)
{
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam = scene_camera(scene, width, height);
    rl_status st = make_pt(b, c, &r);
    if (st == RL_OK)
        st = rl_image_create(width, height, RL_LAYER_COLOR, &img);
    rl_render_stats s;
    if (st == RL_OK)
        st = rl_renderer_render(r, scene, &cam, img, &s);
    *warmup_ms = st == RL_OK ? s.time_ms : NAN;
    memset(best, 0, sizeof *best);
    best->time_ms = INFINITY;
    for (int i = 0; st == RL_OK && i < b->runs; i++)
        if ((st = rl_renderer_render(r, scene, &cam, img, &s)) == RL_OK && s.time_ms < best->time_ms)
            *best = s;
    rl_image_release(img);
    rl_renderer_release(r);
    return st;
}

static double mrays(const rl_render_stats *s)
{
    return s->time_ms > 0.0 ? (double)bench_rays_total(s) / (s->time_ms * 1e3) : NAN;
}

/* ------------------------------------------------------- memory guard -- */

/* An upper bound of a Line Space's size before building it: the cells a
 * triangle's box overlaps are at least the cells that hold it, and each
 * such cell gets at most 15·N^4 occupied shafts of a list offset and a
 * PNMT record (16 half floats). The grid tiles the scene's box (plus a tiny
 * pad). */
static double ls_bytes_upper(const rl_scene *scene, int res, int n)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    size_t cells = (size_t)res * res * res;
    uint8_t *filled = calloc(cells, 1);
    if (!filled)
        return INFINITY;
    rl_vec3 lo = d->bounds.min, hi = d->bounds.max;
    float ext[3] = { hi.x - lo.x, hi.y - lo.y, hi.z - lo.z };
    float mn[3] = { lo.x, lo.y, lo.z };
    for (uint32_t t = 0; t < d->num_triangles; t++) {
        int c0[3], c1[3];
        for (int a = 0; a < 3; a++) {
            float tmin = INFINITY, tmax = -INFINITY;
            for (int v = 0; v < 3; v++) {
                rl_vec3 p = d->positions[d->indices[3 * t + v]];
                float x = a == 0 ? p.x : a == 1 ? p.y : p.z;
                tmin = fminf(tmin, x);
                tmax = fmaxf(tmax, x);
            }
            float s = ext[a] > 0.0f ? (float)res / ext[a] : 0.0f;
            c0[a] = (int)floorf((tmin - mn[a]) * s);
            c1[a] = (int)floorf((tmax - mn[a]) * s);
            c0[a] = c0[a] < 0 ? 0 : c0[a] >= res ? res - 1 : c0[a];
            c1[a] = c1[a] < 0 ? 0 : c1[a] >= res ? res - 1 : c1[a];
        }
        for (int z = c0[2]; z <= c1[2]; z++)
            for (int y = c0[1]; y <= c1[1]; y++)
                for (int x = c0[0]; x <= c1[0]; x++)
                    filled[(size_t)x + (size_t)res * ((size_t)y + (size_t)res * (size_t)z)] = 1;
    }
    size_t count = 0;
    for (size_t i = 0; i < cells; i++)
        count += filled[i];
    free(filled);
    return (double)count * rl_ls_shafts_per_voxel(n) * (4.0 + 32.0);
}

/* The largest resolution <= res (halving) whose Line Space fits the limit. */
static int ls_res_that_fits(const bpt *b, const rl_scene *scene, int res, int n)
{
    while (res > 1 && ls_bytes_upper(scene, res, n) > b->max_memory_bytes)
        res /= 2;
    return res;
}

/* -------------------------------------------------------- generation -- */

/* The fastest of --builds fresh builds of desc (a build's first touch of
 * gigabytes varies with the VM's memory state by up to 1.5x); every build
 * time goes to runs. */
static rl_status fastest_build(const bpt *b, const rl_accel *grid, const rl_linespace_desc *desc,
                               cJSON *runs, rl_linespace **out)
{
    *out = NULL;
    double best_ms = INFINITY;
    for (long long r = 0; r < b->a->builds; r++) {
        rl_linespace *next = NULL;
        rl_status st = rl_linespace_create(grid, desc, &next);
        if (st == RL_OK) st = rl_linespace_commit(next);
        if (st != RL_OK) {
            rl_linespace_release(next);
            rl_linespace_release(*out);
            *out = NULL;
            return st;
        }
        rl_linespace_stats ns;
        rl_linespace_get_stats(next, &ns);
        cJSON_AddItemToArray(runs, cJSON_CreateNumber(ns.build_ms));
        if (ns.build_ms < best_ms) {
            best_ms = ns.build_ms;
            rl_linespace_release(*out);
            *out = next;
        } else {
            rl_linespace_release(next);
        }
    }
    return RL_OK;
}

/* The cost of dynamic allocation (Sec. 7.1.1 proposes it, we build it):
 * the same row with the thesis' fixed lists of k candidates, built as
 * often, against the dynamic build's stats `dyn`: time, memory and the
 * shafts the fixed lists truncate. Its size is known from dyn's occupied
 * shafts; the dynamic Line Space must be released before (both of the
 * dragon-sized model at 72³ do not fit in 24 GB). */
static rl_status fixed_row(const bpt *b, const struct gen_row *g, const rl_accel *grid,
                           const rl_linespace_stats *dyn, cJSON *row)
{
    const rl_linespace_stats ds = *dyn;
    int k = (int)b->a->fixed_k;
    cJSON *o = cJSON_AddObjectToObject(row, "fixed");
    if (!o)
        return RL_ERR_OUT_OF_MEMORY;
    cJSON_AddNumberToObject(o, "k", k);
    double occupied = (double)(ds.shafts - ds.empty_shafts);
    double need = (double)ds.memory_bytes - 4.0 * (double)ds.candidates - 4.0 * (occupied + 1.0) +
                  4.0 * k * occupied;
    if (need > b->max_memory_bytes) {
        char why[160];
        snprintf(why, sizeof why, "skipped: fixed lists of %d need %.1f GiB, the limit is %.1f GiB "
                 "(--max-memory)", k, need / 1073741824.0, b->max_memory_bytes / 1073741824.0);
        cJSON_AddStringToObject(o, "status", why);
        printf("%-26s %4d %2d  fixed k=%d %s\n", g->scene, g->res, g->n, k, why);
        return RL_OK;
    }
    rl_linespace_desc fd = { .n = g->n, .k = k, .dynamic = false, .small_pages = b->a->small_pages,
                             .payloads = RL_LS_CANDIDATES | RL_LS_PNMT, .threads = b->threads };
    rl_linespace *ls = NULL;
    rl_status st = fastest_build(b, grid, &fd, cJSON_AddArrayToObject(o, "ms_runs"), &ls);
    if (st != RL_OK)
        return st;
    rl_linespace_stats fs;
    rl_linespace_get_stats(ls, &fs);
    rl_linespace_release(ls);
    double trunc = occupied > 0.0 ? 100.0 * (double)fs.truncated_shafts / occupied : 0.0;
    cJSON_AddStringToObject(o, "status", "ok");
    bench_add_num(o, "ms", fs.build_ms);
    cJSON_AddNumberToObject(o, "bytes", (double)fs.memory_bytes);
    cJSON_AddNumberToObject(o, "candidates", (double)fs.candidates);
    cJSON_AddNumberToObject(o, "truncated_shafts", (double)fs.truncated_shafts);
    bench_add_num(o, "truncated_pct_of_occupied", trunc);
    bench_add_num(o, "dynamic_over_fixed_ms", bench_ratio(ds.build_ms, fs.build_ms));
    bench_add_num(o, "dynamic_over_fixed_bytes", bench_ratio((double)ds.memory_bytes,
                                                                   (double)fs.memory_bytes));
    printf("%-26s %4d %2d  fixed k=%d: %.1f ms (dynamic / fixed %.2f), %.1f MiB (dynamic / fixed "
           "%.2f), %.1f %% of occupied shafts truncated\n", g->scene, g->res, g->n, k, fs.build_ms,
           bench_ratio(ds.build_ms, fs.build_ms), (double)fs.memory_bytes / 1048576.0,
           bench_ratio((double)ds.memory_bytes, (double)fs.memory_bytes), trunc);
    return RL_OK;
}

static rl_status sec_generation(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    if (!rows)
        return RL_ERR_OUT_OF_MEMORY;
    printf("\ngeneration (Table 1; thesis: GTX 1080, candidates + PNMT on the GPU; ours: dynamic "
           "candidate lists + PNMT, %d threads)\n", b->threads);
    printf("%-26s %4s %2s %10s %10s %10s %10s %7s %9s %8s %10s\n", "scene", "res", "N",
           "grid ms", "thesis", "LS ms", "thesis", "x GPU", "LS MiB", "empty %", "cand/shaft");
    bool any_failed = false;
    for (size_t i = 0; i < sizeof gen_rows / sizeof gen_rows[0]; i++) {
        const struct gen_row *g = &gen_rows[i];
        if (b->a->quick && !g->quick)
            continue;
        cJSON *row = cJSON_CreateObject();
        if (!row)
            return RL_ERR_OUT_OF_MEMORY;
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "scene", g->scene);
        cJSON_AddNumberToObject(row, "thesis_scene", g->thesis_scene);
        cJSON_AddNumberToObject(row, "voxel_res", g->res);
        cJSON_AddNumberToObject(row, "n", g->n);
        cJSON_AddNumberToObject(row, "thesis_grid_ms", g->thesis_grid_ms);
        cJSON_AddNumberToObject(row, "thesis_ls_ms", g->thesis_ls_ms);
        rl_scene *scene = NULL;
        rl_clear_error();
        rl_status st = scene_get(b, g->scene, &scene);
        double need = st == RL_OK ? ls_bytes_upper(scene, g->res, g->n) : NAN;
        if (st == RL_OK && need > b->max_memory_bytes) {
            char why[160];
            snprintf(why, sizeof why, "skipped: the Line Space may need up to %.1f GiB, the limit "
                     "is %.1f GiB (--max-memory)", need / 1073741824.0,
                     b->max_memory_bytes / 1073741824.0);
            cJSON_AddStringToObject(row, "status", why);
            printf("%-26s %4d %2d  %s\n", g->scene, g->res, g->n, why);
            continue;
        }
        rl_accel *grid = NULL;
        rl_linespace *ls = NULL;
        rl_accel_desc ad = { .kind = RL_ACCEL_GRID, .threads = b->threads,
                             .grid_res = { g->res, g->res, g->res } };
        if (st == RL_OK) st = rl_accel_create(scene, &ad, &grid);
        if (st == RL_OK) st = rl_accel_commit(grid);
        rl_linespace_desc ld = { .n = g->n, .dynamic = true, .small_pages = b->a->small_pages,
                                 .payloads = RL_LS_CANDIDATES | RL_LS_PNMT, .threads = b->threads };
        if (st == RL_OK)
            st = fastest_build(b, grid, &ld, cJSON_AddArrayToObject(row, "ls_ms_runs"), &ls);
        if (st != RL_OK) {
            const char *why = rl_last_error() && *rl_last_error() ? rl_last_error()
                                                                   : rl_status_string(st);
            cJSON_AddStringToObject(row, "status", why);
            printf("%-26s %4d %2d  failed: %s\n", g->scene, g->res, g->n, why);
            any_failed = true;
        } else {
            rl_accel_stats gs;
            rl_linespace_stats ls_s;
            rl_accel_get_stats(grid, &gs);
            rl_linespace_get_stats(ls, &ls_s);
            double empty = ls_s.shafts ? 100.0 * (double)ls_s.empty_shafts / (double)ls_s.shafts
                                       : NAN;
            cJSON_AddStringToObject(row, "status", "ok");
            cJSON_AddNumberToObject(row, "triangles", gs.num_triangles);
            bench_add_num(row, "grid_ms", gs.build_ms);
            bench_add_num(row, "ls_ms", ls_s.build_ms);
            bench_add_num(row, "ls_candidates_ms", ls_s.candidates_ms);
            bench_add_num(row, "ls_pnmt_ms", ls_s.pnmt_ms);
            bench_add_num(row, "thesis_over_ours_ls", bench_ratio(g->thesis_ls_ms, ls_s.build_ms));
            cJSON_AddNumberToObject(row, "grid_bytes", (double)gs.memory_bytes);
            cJSON_AddNumberToObject(row, "ls_bytes", (double)ls_s.memory_bytes);
            cJSON_AddNumberToObject(row, "filled_voxels", ls_s.filled_voxels);
            cJSON_AddNumberToObject(row, "shafts", (double)ls_s.shafts);
            cJSON_AddNumberToObject(row, "empty_shafts", (double)ls_s.empty_shafts);
            cJSON_AddNumberToObject(row, "candidates", (double)ls_s.candidates);
            cJSON_AddNumberToObject(row, "max_candidates", ls_s.max_candidates);
            bench_add_num(row, "mean_candidates", ls_s.mean_candidates);
            printf("%-26s %4d %2d %10.1f %10.0f %10.1f %10.0f %7.2f %9.1f %8.1f %10.2f\n",
                   g->scene, g->res, g->n, gs.build_ms, g->thesis_grid_ms, ls_s.build_ms,
                   g->thesis_ls_ms, bench_ratio(g->thesis_ls_ms, ls_s.build_ms),
                   (double)ls_s.memory_bytes / 1048576.0, empty, ls_s.mean_candidates);
            note("generation %s %d^3 N=%d: grid %.1f ms, LS %.1f ms", g->scene, g->res, g->n,
                 gs.build_ms, ls_s.build_ms);
            fflush(stdout);
            rl_linespace_release(ls);
            ls = NULL;
            if ((st = fixed_row(b, g, grid, &ls_s, row)) != RL_OK) {
                const char *why = rl_last_error() && *rl_last_error() ? rl_last_error() : rl_status_string(st);
                printf("%-26s %4d %2d  fixed lists failed: %s\n", g->scene, g->res, g->n, why);
                any_failed = true;
            }
        }
        fflush(stdout);
        rl_linespace_release(ls);
        rl_accel_release(grid);
    }
    if (any_failed)
        return fail(b, RL_ERR_INTERNAL, "a Line Space build failed (see the rows)");
    return RL_OK;
}

/* ------------------------------------------------------------ frames -- */

static cJSON *frame_json(const pt_config *c, const rl_render_stats *s, double warmup_ms)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "label", c->label);
    cJSON_AddStringToObject(o, "shadow", c->shadow);
    cJSON_AddStringToObject(o, "diffuse", c->diffuse);
    cJSON_AddNumberToObject(o, "grid_res", c->grid_res);
    cJSON_AddBoolToObject(o, "ls_fixed_lists", c->ls_fixed);
    bench_add_num(o, "frame_ms", s->time_ms);
    bench_add_num(o, "fps", s->time_ms > 0.0 ? 1e3 / s->time_ms : NAN);
    bench_add_num(o, "mrays_per_s", mrays(s));
    bench_add_num(o, "warmup_ms", warmup_ms);
    cJSON_AddItemToObject(o, "rays", bench_rays_json(s));
    return o;
}

#define MAX_CONFIGS 24

/* Renders each configuration on one scene and prints a row per config
 * with its speed relative to configuration `base`. With floor >= 0 (a
 * configuration without the rays under test), also the speed-up of the
 * rest of the frame, (base - floor) / (config - floor): the rays' own
 * share, which the frame's fixed cost (primary rays, shading) hides. */
static rl_status frame_table(bpt *b, const char *scene_name, const pt_config *configs, int count,
                             int base, int floor, cJSON *out, rl_render_stats *stats)
{
    rl_scene *scene = NULL;
    rl_status st = scene_get(b, scene_name, &scene);
    if (st != RL_OK)
        return st;
    if (count > MAX_CONFIGS)
        return fail(b, RL_ERR_LIMIT, "bench pt: %d configurations > %d", count, MAX_CONFIGS);
    double warm[MAX_CONFIGS];
    for (int i = 0; i < count; i++) {
        rl_clear_error();
        if ((st = frame_timed(b, &configs[i], scene, b->a->width, b->a->height, &stats[i],
                              &warm[i])) != RL_OK)
            return st;
        note("%s %s (shadow %s, diffuse %s): %.1f ms, %.1f Mrays/s", scene_name, configs[i].label,
             configs[i].shadow, configs[i].diffuse, stats[i].time_ms, mrays(&stats[i]));
    }
    printf("%-18s %-14s %-14s %5s %10s %8s %9s %10s %9s%s\n", "config", "shadow", "diffuse", "res",
           "frame ms", "fps", "Mrays/s", "warmup ms", "x base", floor >= 0 ? " x base (rays)" : "");
    for (int i = 0; i < count; i++) {
        double x = bench_ratio(stats[base].time_ms, stats[i].time_ms);
        double xr = floor >= 0 && i != floor
                        ? bench_ratio(stats[base].time_ms - stats[floor].time_ms,
                                         stats[i].time_ms - stats[floor].time_ms)
                        : NAN;
        printf("%-18s %-14s %-14s %5d %10.1f %8.2f %9.2f %10.1f %9.2f", configs[i].label,
               configs[i].shadow, configs[i].diffuse, configs[i].grid_res, stats[i].time_ms,
               1e3 / stats[i].time_ms, mrays(&stats[i]), warm[i], x);
        if (floor >= 0 && isfinite(xr))
            printf(" %14.2f", xr);
        printf("\n");
        cJSON *row = frame_json(&configs[i], &stats[i], warm[i]);
        if (!row)
            return RL_ERR_OUT_OF_MEMORY;
        bench_add_num(row, "speedup_vs_base", x);
        if (floor >= 0)
            bench_add_num(row, "rays_speedup_vs_base", xr);
        cJSON_AddItemToArray(out, row);
    }
    fflush(stdout);
    return RL_OK;
}

static rl_status sec_scenes(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    cJSON *rows = cJSON_AddArrayToObject(sec, "scenes");
    if (!rows)
        return RL_ERR_OUT_OF_MEMORY;
    printf("\nscenes (Diagram 1: %dx%d, 1 spp, all secondary and shadow rays through one "
           "structure; x base = speed-up over the grid)\n", b->a->width, b->a->height);
    for (size_t i = 0; i < sizeof scene_rows / sizeof scene_rows[0]; i++) {
        const struct scene_row *sr = &scene_rows[i];
        if (b->a->quick && !sr->quick)
            continue;
        rl_scene *scene = NULL;
        rl_status st = scene_get(b, sr->scene, &scene);
        if (st != RL_OK)
            return st;
        int res = ls_res_that_fits(b, scene, sr->ls_res, RL_LS_DEFAULT_N);
        pt_config configs[] = {
            { .label = "grid", .shadow = "grid", .diffuse = "grid", .max_depth = sr->max_depth },
            { .label = "ls-pnmt", .shadow = "ls-pnmt", .diffuse = "ls-pnmt", .grid_res = res,
              .max_depth = sr->max_depth },
            { .label = "ls-candidates", .shadow = "ls-candidates", .diffuse = "ls-candidates",
              .grid_res = res, .max_depth = sr->max_depth },
            { .label = "bvh", .shadow = "bvh", .diffuse = "bvh", .max_depth = sr->max_depth },
        };
        printf("\n%s (thesis scene %d, max path length %d, LS voxels %d^3%s)\n", sr->scene,
               sr->thesis_scene, sr->max_depth, res,
               res < sr->ls_res ? ", reduced to fit --max-memory" : "");
        cJSON *entry = cJSON_CreateObject();
        if (!entry)
            return RL_ERR_OUT_OF_MEMORY;
        cJSON_AddItemToArray(rows, entry);
        cJSON_AddStringToObject(entry, "scene", sr->scene);
        cJSON_AddNumberToObject(entry, "thesis_scene", sr->thesis_scene);
        cJSON_AddNumberToObject(entry, "max_depth", sr->max_depth);
        cJSON_AddNumberToObject(entry, "ls_voxel_res", res);
        cJSON_AddNumberToObject(entry, "ls_voxel_res_wanted", sr->ls_res);
        cJSON *frames = cJSON_AddArrayToObject(entry, "frames");
        if (!frames)
            return RL_ERR_OUT_OF_MEMORY;
        rl_render_stats stats[4];
        if ((st = frame_table(b, sr->scene, configs, 4, 0, -1, frames, stats)) != RL_OK)
            return st;
    }
    return RL_OK;
}

/* The scene of Diagrams 2 and 3 (the Cornell box with the bunny). */
static const char *diagram_scene(const bpt *b)
{
    return b->a->quick ? "ls-cornell:model=boxes" : "ls-cornell:model=bunny";
}

/* The Line Space voxel resolutions the diagram and error sections sweep
 * (the thesis picked the best resolution per structure, Sec. 11.1); those
 * estimated above --max-memory are left out. Returns how many. */
static int sweep_res(bpt *b, const char *name, int res[4])
{
    static const int full[] = { 8, 16, 32, 64 }, quick[] = { 4, 8 };
    const int *list = b->a->quick ? quick : full;
    int count = b->a->quick ? 2 : 4, n = 0;
    rl_scene *scene = NULL;
    if (scene_get(b, name, &scene) != RL_OK)
        return 0;
    for (int i = 0; i < count; i++) {
        if (ls_bytes_upper(scene, list[i], RL_LS_DEFAULT_N) <= b->max_memory_bytes)
            res[n++] = list[i];
        else
            note("LS voxels %d^3 skipped: estimated above --max-memory", list[i]);
    }
    return n;
}

/* The Line Space variants under test: the label, the backend and whether
 * its candidate lists are the thesis' fixed ones (k = 8, the renderer's
 * default) instead of our exact dynamic lists. */
static const struct ls_variant {
    const char *label, *backend;
    bool fixed;
} ls_variants[] = {
    { "ls-candidates", "ls-candidates", false },
    { "ls-fixed-k8", "ls-candidates", true },
    { "ls-pnmt", "ls-pnmt", false },
    { "ls-preillum", "ls-preillum", false },
};
#define NUM_LS_VARIANTS ((int)(sizeof ls_variants / sizeof ls_variants[0]))
#define LS_FIRST_APPROX 2      /* ls_variants[2..]: the approximate ones */

/* Which rays a sweep configuration routes through the variant under test:
 * diffuse rays (shadows by shadow maps), shadow rays (diffuse rays by the
 * BVH), or both. */
typedef enum sweep_rays { SWEEP_DIFFUSE, SWEEP_SHADOW, SWEEP_BOTH } sweep_rays;

/* Appends one configuration per Line Space variant from `first` on and per
 * resolution, up to cap configurations; labels "variant@res" live in
 * labels[]. */
static int add_sweep(pt_config *configs, int count, int cap, char labels[][32], int first,
                     const int *res, int nres, sweep_rays rays)
{
    for (int v = first; v < NUM_LS_VARIANTS; v++)
        for (int i = 0; i < nres && count < cap; i++, count++) {
            snprintf(labels[count], 32, "%s@%d", ls_variants[v].label, res[i]);
            pt_config c = { .label = labels[count], .grid_res = res[i], .ls_fixed = ls_variants[v].fixed,
                            .shadow = rays == SWEEP_DIFFUSE ? "shadowmap" : ls_variants[v].backend,
                            .diffuse = rays == SWEEP_SHADOW ? "bvh" : ls_variants[v].backend };
            configs[count] = c;
        }
    return count;
}

/* The scene and object Line Spaces (Sec. 13.1, 13.2) at the renderer's
 * defaults after the sweep: exact, on no voxel resolution of the sweep
 * (the object grids have ls_object_res voxels per axis and object), the
 * scene Line Space over the object Line Spaces and over the BVH. */
static int add_levels(pt_config *configs, int count, int cap, sweep_rays rays)
{
    static const char *const labels[3] = { "ls-object", "ls-scene/object", "ls-scene/bvh" };
    static const char *const backends[3] = { "ls-object", "ls-scene", "ls-scene" };
    static const char *const inner[3] = { NULL, "object", "bvh" };
    for (int i = 0; i < 3 && count < cap; i++, count++) {
        pt_config c = { .label = labels[i], .ls_scene_inner = inner[i],
                        .shadow = rays == SWEEP_DIFFUSE ? "shadowmap" : backends[i],
                        .diffuse = rays == SWEEP_SHADOW ? "bvh" : backends[i] };
        configs[count] = c;
    }
    return count;
}

/* Per Line Space variant, the fastest resolution of the sweep, against
 * the grid (config 0) and the BVH (config 1); with floor >= 0 also the
 * rays' own share (see frame_table). */
static void sweep_best(const pt_config *configs, const rl_render_stats *stats, int first, int count,
                       int floor, sweep_rays rays, cJSON *sec)
{
    cJSON *best = cJSON_AddObjectToObject(sec, "best");
    printf("best resolution per variant:\n");
    for (int v = 0; v < NUM_LS_VARIANTS; v++) {
        int bi = -1;
        for (int i = first; i < count; i++)
            if (strcmp(rays == SWEEP_SHADOW ? configs[i].shadow : configs[i].diffuse, ls_variants[v].backend) == 0 &&
                configs[i].ls_fixed == ls_variants[v].fixed && (bi < 0 || stats[i].time_ms < stats[bi].time_ms))
                bi = i;
        if (bi < 0)
            continue;
        double xg = bench_ratio(stats[0].time_ms, stats[bi].time_ms);
        double xb = bench_ratio(stats[1].time_ms, stats[bi].time_ms);
        double xr = floor >= 0 ? bench_ratio(stats[0].time_ms - stats[floor].time_ms,
                                                stats[bi].time_ms - stats[floor].time_ms)
                               : NAN;
        printf("  %-14s %3d^3  %8.1f ms  %5.2fx the grid  %5.2fx the BVH", ls_variants[v].label,
               configs[bi].grid_res, stats[bi].time_ms, xg, xb);
        if (isfinite(xr))
            printf("  rays alone %5.2fx the grid", xr);
        printf("\n");
        cJSON *o = best ? cJSON_AddObjectToObject(best, ls_variants[v].label) : NULL;
        if (!o)
            continue;
        cJSON_AddNumberToObject(o, "grid_res", configs[bi].grid_res);
        bench_add_num(o, "frame_ms", stats[bi].time_ms);
        bench_add_num(o, "speedup_vs_grid", xg);
        bench_add_num(o, "speedup_vs_bvh", xb);
        if (floor >= 0)
            bench_add_num(o, "rays_speedup_vs_grid", xr);
    }
    fflush(stdout);
}

static rl_status sec_diffuse(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    const char *name = diagram_scene(b);
    int res[4], nres = sweep_res(b, name, res);
    pt_config configs[MAX_CONFIGS] = {
        { .label = "grid", .shadow = "shadowmap", .diffuse = "grid" },
        { .label = "bvh", .shadow = "shadowmap", .diffuse = "bvh" },
        { .label = "no diffuse rays", .shadow = "shadowmap", .diffuse = "bvh", .direct_only = true },
    };
    char labels[MAX_CONFIGS][32];
    int count = add_sweep(configs, 3, MAX_CONFIGS, labels, 0, res, nres, SWEEP_DIFFUSE);
    count = add_levels(configs, count, MAX_CONFIGS, SWEEP_DIFFUSE);
    printf("\ndiffuse (Diagram 2: %s, %dx%d, 1 spp, shadows by shadow maps, each Line Space variant "
           "at voxels %d^3..%d^3; x base = speed-up over the grid, (rays): of the frame without "
           "the direct-light-only floor; thesis: PNMT > 20x the grid)\n", name, b->a->width,
           b->a->height, nres ? res[0] : 0, nres ? res[nres - 1] : 0);
    cJSON_AddStringToObject(sec, "scene", name);
    cJSON *frames = cJSON_AddArrayToObject(sec, "frames");
    if (!frames)
        return RL_ERR_OUT_OF_MEMORY;
    rl_render_stats stats[MAX_CONFIGS];
    rl_status st = frame_table(b, name, configs, count, 0, 2, frames, stats);
    if (st == RL_OK)
        sweep_best(configs, stats, 3, count, 2, SWEEP_DIFFUSE, sec);
    return st;
}

/* Diagram 3's shadow rays alone, without the rest of the frame: one ray
 * per pixel from the primary hit (by the BVH) to a random point of the
 * first light, the same rays through every structure, the fastest of
 * b->runs passes each. PNMT answers rays under the renderer's rule (a
 * voxel diagonal cut off at both ends, pathtrace_path.c), so the BVH is
 * timed on those rays too, for a like-for-like ratio; the candidate Line
 * Space is exact and answers the full rays. Pre-illuminated shadow tests
 * walk like PNMT and need a shading function, so they are not repeated. */
typedef enum ray_structure { RS_BVH, RS_GRID, RS_LS_CAND, RS_LS_PNMT, RS_LS_OBJECT, RS_LS_SCENE } ray_structure;

/* The structure a pass queries: acc for RS_BVH/RS_GRID, ls for the
 * per-voxel Line Space, lso/lss for the object and scene Line Spaces. */
typedef struct ray_target {
    const rl_accel *acc;
    const rl_linespace *ls;
    const rl_ls_objects *lso;
    const rl_ls_scene *lss;
} ray_target;

static bool target_occluded(ray_structure k, const ray_target *t, const rl_ray *ray)
{
    switch (k) {
    case RS_LS_CAND: return rl_linespace_occluded(t->ls, ray);
    case RS_LS_PNMT: return rl_linespace_pnmt_occluded(t->ls, ray);
    case RS_LS_OBJECT: return rl_ls_objects_occluded(t->lso, ray);
    case RS_LS_SCENE: return rl_ls_scene_occluded(t->lss, ray);
    default: return rl_accel_occluded(t->acc, ray);
    }
}

static bool target_closest(ray_structure k, const ray_target *t, rl_ray *ray, rl_hit *h)
{
    switch (k) {
    case RS_LS_CAND: return rl_linespace_intersect(t->ls, ray, h);
    case RS_LS_OBJECT: return rl_ls_objects_intersect(t->lso, ray, h);
    case RS_LS_SCENE: return rl_ls_scene_intersect(t->lss, ray, h);
    default: return rl_accel_intersect(t->acc, ray, h);
    }
}

static double occluded_pass_on(const bpt *b, ray_structure k, const ray_target *t, const rl_ray *rays, size_t n,
                               uint64_t *occluded)
{
    double best = INFINITY;
    for (int r = 0; r < b->runs; r++) {
        uint64_t occ = 0;
        double t0 = omp_get_wtime();
        #pragma omp parallel for num_threads(b->threads) schedule(dynamic, 1024) reduction(+ : occ)
        for (long i = 0; i < (long)n; i++)
            occ += target_occluded(k, t, &rays[i]);
        double ms = (omp_get_wtime() - t0) * 1e3;
        best = ms < best ? ms : best;
        *occluded = occ;
    }
    return best;
}

/* The fastest of b->runs closest-hit passes over rays; *hits: rays that hit. */
static double closest_pass(const bpt *b, ray_structure k, const ray_target *t, const rl_ray *rays, size_t n,
                           uint64_t *hits)
{
    double best = INFINITY;
    for (int r = 0; r < b->runs; r++) {
        uint64_t hit = 0;
        double t0 = omp_get_wtime();
        #pragma omp parallel for num_threads(b->threads) schedule(dynamic, 1024) reduction(+ : hit)
        for (long i = 0; i < (long)n; i++) {
            rl_ray ray = rays[i];
            rl_hit h;
            hit += target_closest(k, t, &ray, &h);
        }
        double ms = (omp_get_wtime() - t0) * 1e3;
        best = ms < best ? ms : best;
        *hits = hit;
    }
    return best;
}

static double occluded_pass(const bpt *b, ray_structure k, const rl_accel *acc, const rl_linespace *ls,
                            const rl_ray *rays, size_t n, uint64_t *occluded)
{
    ray_target t = { .acc = acc, .ls = ls };
    return occluded_pass_on(b, k, &t, rays, n, occluded);
}

static cJSON *pass_json(cJSON *parent, const char *name, double ms, size_t rays, uint64_t occluded)
{
    cJSON *o = cJSON_AddObjectToObject(parent, name);
    if (!o)
        return NULL;
    bench_add_num(o, "ms", ms);
    bench_add_num(o, "mrays_per_s", ms > 0.0 ? (double)rays / (ms * 1e3) : NAN);
    cJSON_AddNumberToObject(o, "rays", (double)rays);
    cJSON_AddNumberToObject(o, "occluded", (double)occluded);
    return o;
}

static rl_status shadow_rays(const bpt *b, const rl_scene *scene, const rl_accel *bvh, rl_ray **out,
                             size_t *count)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    *out = NULL;
    *count = 0;
    if (d->num_lights == 0)
        return RL_OK;
    rl_status st = RL_OK;
    rl_camera cam = scene_camera(scene, b->a->width, b->a->height);
    rl_camera_frame f = rl_camera_frame_make(&cam);
    size_t cap = (size_t)cam.width * (size_t)cam.height;
    rl_ray *rays = st == RL_OK ? malloc(cap * sizeof *rays) : NULL;
    if (st == RL_OK && !rays)
        st = RL_ERR_OUT_OF_MEMORY;
    const rl_light *L = &d->lights[0];
    rl_vec3 ext = rl_sub(d->bounds.max, d->bounds.min);
    float eps = 1e-4f * rl_maxf(1.0f, rl_maxf(ext.x, rl_maxf(ext.y, ext.z)));
    size_t n = 0;
    for (int y = 0; st == RL_OK && y < cam.height; y++)
        for (int x = 0; x < cam.width; x++) {
            rl_ray pr = rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f);
            rl_hit h;
            if (!rl_accel_intersect(bvh, &pr, &h))
                continue;
            rl_vec3 p = rl_ray_at(&pr, h.t), q = L->position;
            if (L->type == RL_LIGHT_QUAD) {
                rl_rng rng;
                rl_rng_seed(&rng, 1, (uint64_t)y * (uint64_t)cam.width + (uint64_t)x);
                float u = rl_rng_float(&rng), v = rl_rng_float(&rng);
                q = rl_add(L->position, rl_add(rl_scale(L->edge_u, u), rl_scale(L->edge_v, v)));
            }
            rl_vec3 dir = L->type == RL_LIGHT_DIRECTIONAL ? rl_scale(L->direction, -1.0f) : rl_sub(q, p);
            float dist = L->type == RL_LIGHT_DIRECTIONAL ? INFINITY : rl_length(dir);
            if (!(dist > 2.0f * eps))
                continue;
            dir = rl_normalize(dir);
            /* As the renderer: no ray where the light is behind the surface
             * (seen from the camera) or the surface behind a quad light. */
            const uint32_t *tri = d->indices + 3 * (size_t)h.triangle;
            rl_vec3 ng = rl_cross(rl_sub(d->positions[tri[1]], d->positions[tri[0]]),
                                  rl_sub(d->positions[tri[2]], d->positions[tri[0]]));
            if (rl_dot(ng, pr.d) > 0.0f)
                ng = rl_scale(ng, -1.0f);
            if (!(rl_dot(ng, dir) > 0.0f))
                continue;
            if (L->type == RL_LIGHT_QUAD && !(rl_dot(rl_cross(L->edge_u, L->edge_v), dir) < 0.0f))
                continue;
            rays[n++] = (rl_ray){ rl_madd(p, rl_normalize(ng), eps), 0.0f, dir,
                                  isinf(dist) ? INFINITY : dist * (1.0f - 1e-4f) };
        }
    if (st != RL_OK) {
        free(rays);
        return st;
    }
    *out = rays;
    *count = n;
    return RL_OK;
}

/* One diffuse ray per pixel: from the primary hit (by the BVH), offset
 * along the geometric normal, in a cosine-distributed direction of its
 * hemisphere (the path tracer's first bounce on a Lambertian surface). */
static rl_status diffuse_rays(const bpt *b, const rl_scene *scene, const rl_accel *bvh, rl_ray **out, size_t *count)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    rl_camera cam = scene_camera(scene, b->a->width, b->a->height);
    rl_camera_frame f = rl_camera_frame_make(&cam);
    rl_ray *rays = malloc((size_t)cam.width * (size_t)cam.height * sizeof *rays);
    *out = NULL;
    *count = 0;
    if (!rays)
        return RL_ERR_OUT_OF_MEMORY;
    rl_vec3 ext = rl_sub(d->bounds.max, d->bounds.min);
    float eps = 1e-4f * rl_maxf(1.0f, rl_maxf(ext.x, rl_maxf(ext.y, ext.z)));
    size_t n = 0;
    for (int y = 0; y < cam.height; y++)
        for (int x = 0; x < cam.width; x++) {
            rl_ray pr = rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f);
            rl_hit h;
            if (!rl_accel_intersect(bvh, &pr, &h))
                continue;
            const uint32_t *tri = d->indices + 3 * (size_t)h.triangle;
            rl_vec3 ng = rl_normalize(rl_cross(rl_sub(d->positions[tri[1]], d->positions[tri[0]]),
                                               rl_sub(d->positions[tri[2]], d->positions[tri[0]])));
            if (rl_dot(ng, pr.d) > 0.0f)
                ng = rl_scale(ng, -1.0f);
            rl_rng rng;
            rl_rng_seed(&rng, 2, (uint64_t)y * (uint64_t)cam.width + (uint64_t)x);
            float u = rl_rng_float(&rng), v = rl_rng_float(&rng), r = sqrtf(u), phi = 2.0f * RL_PI * v;
            rl_onb basis = rl_onb_from_normal(ng);
            rl_vec3 dir = rl_onb_to_world(&basis, rl_v3(r * cosf(phi), r * sinf(phi), sqrtf(rl_maxf(0.0f, 1.0f - u))));
            rays[n++] = (rl_ray){ rl_madd(rl_ray_at(&pr, h.t), ng, eps), 0.0f, dir, INFINITY };
        }
    *out = rays;
    *count = n;
    return RL_OK;
}

/* The scene and object Line Spaces (Sec. 13.1, 13.2) at pt's defaults:
 * build time and memory, then the shadow rays and the diffuse rays
 * through them, against the BVH and the grid on the same rays. */
static rl_status levels_alone(const bpt *b, const rl_scene *scene, rl_accel *const acc[2], const rl_ray *rays,
                              size_t n, const double acc_ms[2], const rl_ray *drays, size_t dn,
                              const double dacc_ms[2], cJSON *o)
{
    rl_ls_objects *lso = NULL;
    rl_ls_scene *lss[2] = { NULL, NULL };
    rl_status st = rl_ls_objects_create(scene, &(rl_ls_objects_desc){ .threads = b->threads }, &lso);
    if (st == RL_OK)
        st = rl_ls_objects_commit(lso);
    for (int k = 0; k < 2 && st == RL_OK; k++) {
        rl_ls_scene_desc sd = { .threads = b->threads };
        if (k == 0)
            sd.inner.objects = lso;
        else
            sd.inner.accel = acc[0];
        st = rl_ls_scene_create(scene, &sd, &lss[k]);
        if (st == RL_OK)
            st = rl_ls_scene_commit(lss[k]);
    }
    cJSON *lv = st == RL_OK ? cJSON_AddObjectToObject(o, "scene_and_object_line_spaces") : NULL;
    if (st == RL_OK && !lv)
        st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK) {
        rl_ls_objects_stats os;
        rl_ls_scene_stats ss;
        rl_ls_objects_get_stats(lso, &os);
        rl_ls_scene_get_stats(lss[0], &ss);
        rl_accel_stats bs, gs;
        rl_accel_get_stats(acc[0], &bs);
        rl_accel_get_stats(acc[1], &gs);
        printf("scene and object Line Spaces (Sec. 13.1, 13.2; pt's defaults): builds ls-object %.1f ms "
               "(%u Line Spaces for %u objects, N = %d, %d^3 voxels each, %.1f MiB), ls-scene signatures %.1f ms "
               "(N = %d, %d bits, %d^3 cells, %.1f %% set, %.2f MiB); bvh %.1f ms (%.1f MiB), grid %.1f ms "
               "(%.1f MiB)\n", os.build_ms, os.linespaces, os.objects, os.n, os.res, os.memory_bytes / 1048576.0,
               ss.build_ms, ss.n, ss.segments, ss.cells,
               100.0 * (double)ss.filled_bits / ((double)ss.shafts * ss.segments), ss.memory_bytes / 1048576.0,
               bs.build_ms, bs.memory_bytes / 1048576.0, gs.build_ms, gs.memory_bytes / 1048576.0);
        cJSON *bj = cJSON_AddObjectToObject(lv, "build");
        bench_add_num(bj, "ls_object_ms", os.build_ms);
        bench_add_num(bj, "ls_object_bytes", (double)os.memory_bytes);
        cJSON_AddNumberToObject(bj, "ls_object_linespaces", os.linespaces);
        cJSON_AddNumberToObject(bj, "ls_object_objects", os.objects);
        bench_add_num(bj, "ls_scene_ms", ss.build_ms);
        bench_add_num(bj, "ls_scene_bytes", (double)ss.memory_bytes);
        bench_add_num(bj, "ls_scene_fill", (double)ss.filled_bits / ((double)ss.shafts * ss.segments));
        bench_add_num(bj, "bvh_ms", bs.build_ms);
        bench_add_num(bj, "bvh_bytes", (double)bs.memory_bytes);
        bench_add_num(bj, "grid_ms", gs.build_ms);
        bench_add_num(bj, "grid_bytes", (double)gs.memory_bytes);
        static const char *const names[3] = { "ls-object", "ls-scene/object", "ls-scene/bvh" };
        const ray_structure kinds[3] = { RS_LS_OBJECT, RS_LS_SCENE, RS_LS_SCENE };
        const ray_target targets[3] = { { .lso = lso }, { .lss = lss[0] }, { .lss = lss[1] } };
        cJSON *sj = cJSON_AddObjectToObject(lv, "shadow"), *dj = cJSON_AddObjectToObject(lv, "diffuse");
        for (int k = 0; k < 3; k++) {
            uint64_t occ = 0, hits = 0;
            double ms = occluded_pass_on(b, kinds[k], &targets[k], rays, n, &occ);
            double dms = closest_pass(b, kinds[k], &targets[k], drays, dn, &hits);
            cJSON *e = pass_json(sj, names[k], ms, n, occ);
            bench_add_num(e, "speedup_vs_bvh", bench_ratio(acc_ms[0], ms));
            bench_add_num(e, "speedup_vs_grid", bench_ratio(acc_ms[1], ms));
            e = pass_json(dj, names[k], dms, dn, hits);
            bench_add_num(e, "speedup_vs_bvh", bench_ratio(dacc_ms[0], dms));
            bench_add_num(e, "speedup_vs_grid", bench_ratio(dacc_ms[1], dms));
            printf("  %-22s shadow %8.1f ms %8.2f Mrays/s %9llu  %5.2fx the BVH, %5.2fx the grid\n", names[k], ms,
                   (double)n / (ms * 1e3), (unsigned long long)occ, bench_ratio(acc_ms[0], ms),
                   bench_ratio(acc_ms[1], ms));
            printf("  %-22s diffuse %7.1f ms %8.2f Mrays/s %9llu  %5.2fx the BVH, %5.2fx the grid\n", names[k], dms,
                   (double)dn / (dms * 1e3), (unsigned long long)hits, bench_ratio(dacc_ms[0], dms),
                   bench_ratio(dacc_ms[1], dms));
            fflush(stdout);
        }
    }
    rl_ls_scene_release(lss[1]);
    rl_ls_scene_release(lss[0]);
    rl_ls_objects_release(lso);
    return st;
}

static rl_status shadow_rays_alone(bpt *b, const char *name, const int *res, int nres, cJSON *sec)
{
    rl_scene *scene = NULL;
    rl_status st = scene_get(b, name, &scene);
    rl_ray *rays = NULL, *cut = NULL;
    size_t n = 0;
    rl_accel *acc[2] = { NULL, NULL };
    static const char *const acc_names[2] = { "bvh", "grid" };
    for (int k = 0; k < 2 && st == RL_OK; k++) {
        st = rl_accel_create(scene, &(rl_accel_desc){ .kind = k ? RL_ACCEL_GRID : RL_ACCEL_BVH,
                                                      .threads = b->threads }, &acc[k]);
        if (st == RL_OK)
            st = rl_accel_commit(acc[k]);
    }
    if (st == RL_OK)
        st = shadow_rays(b, scene, acc[0], &rays, &n);
    cJSON *o = st == RL_OK && n ? cJSON_AddObjectToObject(sec, "rays_alone") : NULL;
    cJSON *lsj = o ? cJSON_AddArrayToObject(o, "line_spaces") : NULL;
    if (st != RL_OK || n == 0 || !lsj) {
        rl_accel_release(acc[0]);
        rl_accel_release(acc[1]);
        free(rays);
        return st != RL_OK || n == 0 ? st : RL_ERR_OUT_OF_MEMORY;
    }
    cJSON_AddStringToObject(o, "rays_are", "one per pixel: primary hit (BVH) to a random point of the "
                                           "first light; PNMT and bvh_same_rays: a voxel diagonal cut "
                                           "off at both ends (the renderer's rule)");
    printf("shadow rays alone (%zu rays, the frame's first bounce; fastest of %d passes; Mrays/s, "
           "occluded):\n", n, b->runs);
    double acc_ms[2] = { NAN, NAN };
    for (int k = 0; k < 2; k++) {
        uint64_t occ = 0;
        acc_ms[k] = occluded_pass(b, k ? RS_GRID : RS_BVH, acc[k], NULL, rays, n, &occ);
        pass_json(o, acc_names[k], acc_ms[k], n, occ);
        printf("  %-22s %8.1f ms %8.2f Mrays/s %9llu\n", acc_names[k], acc_ms[k],
               (double)n / (acc_ms[k] * 1e3), (unsigned long long)occ);
    }
    /* Diffuse rays too, for the structures that answer closest hits
     * exactly: the BVH, the grid, the candidate Line Space, and the scene
     * and object Line Spaces. */
    rl_ray *drays = NULL;
    size_t dn = 0;
    double dacc_ms[2] = { NAN, NAN };
    if (st == RL_OK)
        st = diffuse_rays(b, scene, acc[0], &drays, &dn);
    cJSON *dj = st == RL_OK ? cJSON_AddObjectToObject(o, "diffuse_rays") : NULL;
    for (int k = 0; k < 2 && dj; k++) {
        uint64_t hits = 0;
        ray_target t = { .acc = acc[k] };
        dacc_ms[k] = closest_pass(b, k ? RS_GRID : RS_BVH, &t, drays, dn, &hits);
        pass_json(dj, acc_names[k], dacc_ms[k], dn, hits);
        printf("  %-22s diffuse %7.1f ms %8.2f Mrays/s %9llu (closest hits, %zu rays)\n", acc_names[k], dacc_ms[k],
               (double)dn / (dacc_ms[k] * 1e3), (unsigned long long)hits, dn);
    }
    if (st == RL_OK)
        st = levels_alone(b, scene, acc, rays, n, acc_ms, drays, dn, dacc_ms, o);
    cut = st == RL_OK ? malloc(n * sizeof *cut) : NULL;
    if (st == RL_OK && !cut)
        st = RL_ERR_OUT_OF_MEMORY;
    const rl_scene_data *d = rl_scene_get_data(scene);
    for (int i = 0; st == RL_OK && i < nres; i++) {
        rl_accel *grid = NULL;
        rl_linespace *ls = NULL;
        st = rl_accel_create(scene, &(rl_accel_desc){ .kind = RL_ACCEL_GRID, .threads = b->threads,
                                                      .grid_res = { res[i], res[i], res[i] } }, &grid);
        if (st == RL_OK)
            st = rl_accel_commit(grid);
        rl_linespace_desc ld = { .dynamic = true, .payloads = RL_LS_CANDIDATES | RL_LS_PNMT,
                                 .threads = b->threads };
        if (st == RL_OK)
            st = rl_linespace_create(grid, &ld, &ls);
        if (st == RL_OK)
            st = rl_linespace_commit(ls);
        if (st == RL_OK)
            st = rl_linespace_set_origin(ls, RL_LS_ORIGIN_RECORDS);
        if (st == RL_OK) {
            /* The renderer's PNMT rule (pathtrace_backend.c: ls_offset). */
            float diag = rl_length(rl_scale(rl_sub(d->bounds.max, d->bounds.min), 1.0f / (float)res[i]));
            size_t m = 0;
            for (size_t r = 0; r < n; r++) {
                rl_ray c = rays[r];
                c.t_min = rl_maxf(c.t_min, diag);
                c.t_max -= diag;
                if (c.t_min < c.t_max)
                    cut[m++] = c;
            }
            uint64_t occ_c = 0, occ_p = 0, occ_b = 0, hits_c = 0;
            double ms_c = occluded_pass(b, RS_LS_CAND, NULL, ls, rays, n, &occ_c);
            ray_target lt = { .ls = ls };
            double dms_c = closest_pass(b, RS_LS_CAND, &lt, drays, dn, &hits_c);
            double ms_p = occluded_pass(b, RS_LS_PNMT, NULL, ls, cut, m, &occ_p);
            double ms_b = occluded_pass(b, RS_BVH, acc[0], NULL, cut, m, &occ_b);
            cJSON *e = cJSON_CreateObject();
            cJSON_AddItemToArray(lsj, e);
            cJSON_AddNumberToObject(e, "voxel_res", res[i]);
            pass_json(e, "candidates", ms_c, n, occ_c);
            bench_add_num(pass_json(e, "candidates_diffuse", dms_c, dn, hits_c), "speedup_vs_bvh",
                          bench_ratio(dacc_ms[0], dms_c));
            pass_json(e, "pnmt", ms_p, m, occ_p);
            pass_json(e, "bvh_same_rays", ms_b, m, occ_b);
            bench_add_num(e, "candidates_speedup_vs_bvh", bench_ratio(acc_ms[0], ms_c));
            bench_add_num(e, "candidates_speedup_vs_grid", bench_ratio(acc_ms[1], ms_c));
            bench_add_num(e, "pnmt_speedup_vs_bvh", bench_ratio(ms_b, ms_p));
            char label[32];
            snprintf(label, sizeof label, "ls-candidates@%d", res[i]);
            printf("  %-22s %8.1f ms %8.2f Mrays/s %9llu  %5.2fx the BVH, %5.2fx the grid\n",
                   label, ms_c, (double)n / (ms_c * 1e3), (unsigned long long)occ_c,
                   bench_ratio(acc_ms[0], ms_c), bench_ratio(acc_ms[1], ms_c));
            printf("  %-22s diffuse %7.1f ms %8.2f Mrays/s %9llu  %5.2fx the BVH, %5.2fx the grid\n", label, dms_c,
                   (double)dn / (dms_c * 1e3), (unsigned long long)hits_c, bench_ratio(dacc_ms[0], dms_c),
                   bench_ratio(dacc_ms[1], dms_c));
            printf("  ls-pnmt@%-14d %8.1f ms %8.2f Mrays/s %9llu  %5.2fx the BVH on the same %zu rays "
                   "(%.1f ms, %llu occluded)\n", res[i], ms_p, (double)m / (ms_p * 1e3),
                   (unsigned long long)occ_p, bench_ratio(ms_b, ms_p), m, ms_b,
                   (unsigned long long)occ_b);
            fflush(stdout);
        }
        rl_linespace_release(ls);
        rl_accel_release(grid);
    }
    rl_accel_release(acc[0]);
    rl_accel_release(acc[1]);
    free(rays);
    free(drays);
    free(cut);
    return st;
}

static rl_status sec_shadow(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    const char *name = diagram_scene(b);
    int res[4], nres = sweep_res(b, name, res);
    pt_config configs[MAX_CONFIGS] = {
        { .label = "grid", .shadow = "grid", .diffuse = "bvh" },
        { .label = "bvh", .shadow = "bvh", .diffuse = "bvh" },
        { .label = "shadowmap", .shadow = "shadowmap", .diffuse = "bvh" },
    };
    char labels[MAX_CONFIGS][32];
    int count = add_sweep(configs, 3, MAX_CONFIGS, labels, 0, res, nres, SWEEP_SHADOW);
    count = add_levels(configs, count, MAX_CONFIGS, SWEEP_SHADOW);
    printf("\nshadow (Diagram 3: %s, %dx%d, 1 spp, diffuse rays by the BVH, each Line Space variant "
           "at voxels %d^3..%d^3; x base = speed-up over the grid; thesis: PNMT ~10x the grid, "
           "shadow maps faster still)\n", name, b->a->width, b->a->height, nres ? res[0] : 0,
           nres ? res[nres - 1] : 0);
    cJSON_AddStringToObject(sec, "scene", name);
    cJSON *frames = cJSON_AddArrayToObject(sec, "frames");
    if (!frames)
        return RL_ERR_OUT_OF_MEMORY;
    rl_render_stats stats[MAX_CONFIGS];
    rl_status st = frame_table(b, name, configs, count, 0, -1, frames, stats);
    if (st == RL_OK)
        sweep_best(configs, stats, 3, count, -1, SWEEP_SHADOW, sec);
    if (st == RL_OK)
        st = shadow_rays_alone(b, name, res, nres, sec);
    return st;
}

/* ------------------------------------------------ error and accumulation -- */

/* A converged BVH image of scene (ref_spp samples) into *out. */
static rl_status make_reference(bpt *b, const rl_scene *scene, const rl_camera *cam, rl_image **out, double *ms)
{
    int per_frame = 16;
    pt_config c = { .label = "reference", .shadow = "bvh", .diffuse = "bvh", .spp = per_frame,
                    .accumulate = true, .seed = REF_SEED };
    rl_renderer *r = NULL;
    rl_status st = make_pt(b, &c, &r);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, out);
    *ms = 0.0;
    long long frames = (b->a->ref_spp + per_frame - 1) / per_frame;
    for (long long f = 0; st == RL_OK && f < frames; f++) {
        rl_render_stats s;
        st = rl_renderer_render(r, scene, cam, *out, &s);
        *ms += s.time_ms;
    }
    rl_renderer_release(r);
    if (st != RL_OK) {
        rl_image_release(*out);
        *out = NULL;
        return st;
    }
    note("reference: %lld spp in %.0f ms", frames * per_frame, *ms);
    return RL_OK;
}

/* The converged BVH image of the diagram scene at the error size. */
static rl_status reference(bpt *b, const rl_scene *scene, const rl_camera *cam)
{
    return b->reference ? RL_OK : make_reference(b, scene, cam, &b->reference, &b->reference_ms);
}

typedef struct curve_point {
    long long spp;
    double time_ms;            /* accumulated frame time */
    rl_image_metrics m;
} curve_point;

#define MAX_POINTS 24

/* Accumulates 1 spp per frame up to spp_max, measuring at powers of two
 * (and at the checkpoints given, when not NULL). */
static rl_status accumulate_curve_against(bpt *b, const pt_config *c, const rl_scene *scene,
                                          const rl_camera *cam, const rl_image *ref, long long spp_max,
                                          curve_point *pts, int *num)
{
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    pt_config cc = *c;
    cc.spp = 1;
    cc.accumulate = true;
    rl_status st = make_pt(b, &cc, &r);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    /* A warm-up frame builds the structures; changing the seed afterwards
     * restarts the accumulation (any option change does), so the curve
     * holds frame time only. */
    rl_render_stats s0;
    if (st == RL_OK) st = rl_renderer_set(r, "seed", "7");
    if (st == RL_OK) st = rl_renderer_render(r, scene, cam, img, &s0);
    if (st == RL_OK) st = rl_renderer_set(r, "seed", cc.seed ? cc.seed : PT_SEED);
    double t = 0.0;
    *num = 0;
    for (long long spp = 1; st == RL_OK && spp <= spp_max; spp++) {
        rl_render_stats s;
        if ((st = rl_renderer_render(r, scene, cam, img, &s)) != RL_OK)
            break;
        t += s.time_ms;
        if ((spp & (spp - 1)) == 0 && *num < MAX_POINTS) {
            curve_point *p = &pts[(*num)++];
            p->spp = spp;
            p->time_ms = t;
            st = rl_image_compare(img, ref, &(rl_metric_options){ 0 }, &p->m);
        }
    }
    rl_image_release(img);
    rl_renderer_release(r);
    return st;
}

/* Against the diagram scene's reference (error and accumulation sections). */
static rl_status accumulate_curve(bpt *b, const pt_config *c, const rl_scene *scene,
                                  const rl_camera *cam, long long spp_max, curve_point *pts,
                                  int *num)
{
    return accumulate_curve_against(b, c, scene, cam, b->reference, spp_max, pts, num);
}

static cJSON *curve_json(const curve_point *pts, int num)
{
    cJSON *a = cJSON_CreateArray();
    for (int i = 0; a && i < num; i++) {
        cJSON *p = cJSON_CreateObject();
        if (!p)
            break;
        cJSON_AddNumberToObject(p, "spp", (double)pts[i].spp);
        bench_add_num(p, "time_ms", pts[i].time_ms);
        bench_add_num(p, "rmse", pts[i].m.rmse);
        bench_add_num(p, "ssim", pts[i].m.ssim);
        cJSON_AddItemToArray(a, p);
    }
    return a;
}

/* Accumulated time at the first checkpoint whose RMSE is at most target. */
static double time_to_rmse(const curve_point *pts, int num, double target)
{
    for (int i = 0; i < num; i++)
        if (pts[i].m.rmse <= target)
            return pts[i].time_ms;
    return NAN;
}

static rl_status error_setup(bpt *b, const rl_scene **scene, rl_camera *cam)
{
    rl_scene *s = NULL;
    rl_status st = scene_get(b, diagram_scene(b), &s);
    if (st != RL_OK)
        return st;
    *scene = s;
    *cam = scene_camera(s, b->a->err_width, b->a->err_height);
    return reference(b, s, cam);
}

static rl_status sec_error(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    const rl_scene *scene = NULL;
    rl_camera cam;
    rl_status st = error_setup(b, &scene, &cam);
    if (st != RL_OK)
        return st;
    int res[4], nres = sweep_res(b, diagram_scene(b), res);
    int mid = nres ? res[(nres - 1) / 2] : 4;     /* for the variants measured once */
    /* The exact variants once (candidates: the BVH's image), the
     * approximate ones at every resolution of the sweep. */
    pt_config configs[MAX_CONFIGS] = {
        { .label = "bvh", .shadow = "bvh", .diffuse = "bvh" },
        { .label = "grid", .shadow = "grid", .diffuse = "grid" },
        { .label = "shadowmap", .shadow = "shadowmap", .diffuse = "bvh" },
    };
    char labels[MAX_CONFIGS][32];
    int count = 3;
    for (int v = 0; v < LS_FIRST_APPROX; v++, count++) {
        snprintf(labels[count], 32, "%s@%d", ls_variants[v].label, mid);
        configs[count] = (pt_config){ .label = labels[count], .shadow = ls_variants[v].backend,
                                      .diffuse = ls_variants[v].backend, .grid_res = mid,
                                      .ls_fixed = ls_variants[v].fixed };
    }
    count = add_sweep(configs, count, MAX_CONFIGS - 1, labels, LS_FIRST_APPROX, res, nres, SWEEP_BOTH);
    snprintf(labels[count], 32, "ls-pnmt@%d exact", mid);
    configs[count] = (pt_config){ .label = labels[count], .shadow = "ls-pnmt", .diffuse = "ls-pnmt",
                                  .grid_res = mid, .ls_origin = "exact" };
    count++;
    const int NUM = count;
    curve_point pts[MAX_CONFIGS][MAX_POINTS];
    int num[MAX_CONFIGS];
    for (int i = 0; i < NUM; i++) {
        rl_clear_error();
        if ((st = accumulate_curve(b, &configs[i], scene, &cam, b->a->spp_max, pts[i], &num[i])) != RL_OK)
            return st;
        note("error %s: %lld spp, RMSE %.4f", configs[i].label, pts[i][num[i] - 1].spp,
             pts[i][num[i] - 1].m.rmse);
    }
    /* Targets: the BVH's RMSE at 4, 16 and 64 spp (as far as measured). */
    double targets[3];
    long long target_spp[3] = { 4, 16, 64 };
    for (int k = 0; k < 3; k++) {
        targets[k] = NAN;
        for (int p = 0; p < num[0]; p++)
            if (pts[0][p].spp == target_spp[k])
                targets[k] = pts[0][p].m.rmse;
    }
    printf("\nerror (%s, %dx%d, against %lld spp of the BVH; equal spp = %lld; time to the "
           "BVH's RMSE at 4/16/64 spp, '-' = never within %lld spp)\n", diagram_scene(b),
           cam.width, cam.height, b->a->ref_spp, b->a->spp_max, b->a->spp_max);
    printf("%-18s %9s %8s %11s %11s %11s %11s\n", "variant", "RMSE", "SSIM", "ms/spp", "t(4) ms",
           "t(16) ms", "t(64) ms");
    cJSON_AddStringToObject(sec, "scene", diagram_scene(b));
    cJSON_AddNumberToObject(sec, "reference_spp", (double)b->a->ref_spp);
    bench_add_num(sec, "reference_ms", b->reference_ms);
    cJSON *vars = cJSON_AddArrayToObject(sec, "variants");
    if (!vars)
        return RL_ERR_OUT_OF_MEMORY;
    for (int i = 0; i < NUM; i++) {
        const curve_point *last = &pts[i][num[i] - 1];
        double tt[3];
        for (int k = 0; k < 3; k++)
            tt[k] = isfinite(targets[k]) ? time_to_rmse(pts[i], num[i], targets[k]) : NAN;
        printf("%-18s %9.4f %8.4f %11.2f", configs[i].label, last->m.rmse, last->m.ssim,
               last->time_ms / (double)last->spp);
        for (int k = 0; k < 3; k++) {
            if (isfinite(tt[k]))
                printf(" %11.1f", tt[k]);
            else
                printf(" %11s", "-");
        }
        printf("\n");
        cJSON *v = cJSON_CreateObject();
        if (!v)
            return RL_ERR_OUT_OF_MEMORY;
        cJSON_AddItemToArray(vars, v);
        cJSON_AddStringToObject(v, "label", configs[i].label);
        cJSON_AddStringToObject(v, "shadow", configs[i].shadow);
        cJSON_AddStringToObject(v, "diffuse", configs[i].diffuse);
        cJSON_AddNumberToObject(v, "grid_res", configs[i].grid_res);
        cJSON_AddStringToObject(v, "ls_origin", configs[i].ls_origin ? configs[i].ls_origin : "offset");
        cJSON_AddBoolToObject(v, "ls_fixed_lists", configs[i].ls_fixed);
        cJSON_AddItemToObject(v, "curve", curve_json(pts[i], num[i]));
        cJSON *ttj = cJSON_AddObjectToObject(v, "time_to_bvh_rmse_ms");
        for (int k = 0; ttj && k < 3; k++) {
            char key[16];
            snprintf(key, sizeof key, "spp%lld", target_spp[k]);
            bench_add_num(ttj, key, tt[k]);
        }
    }
    fflush(stdout);
    return RL_OK;
}

/* Sec. 11.2, 12.3: mirror and refraction rays through the exact grid (the
 * thesis, specular=exact) or through the diffuse backend's Line Space
 * payload (specular=diffuse), on the Line Space Cornell box with its
 * mirror cuboid (the diagram scenes have no mirror). Equal spp, against a
 * converged BVH image of the same scene. */
#define SPECULAR_SCENE "ls-cornell:model=boxes"
static rl_status sec_specular(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    rl_scene *scene = NULL;
    rl_status st = scene_get(b, SPECULAR_SCENE, &scene);
    if (st != RL_OK)
        return st;
    rl_camera cam = scene_camera(scene, b->a->err_width, b->a->err_height);
    /* The error section's reference where it is this scene (--quick). */
    bool shared = strcmp(diagram_scene(b), SPECULAR_SCENE) == 0;
    rl_image *own = NULL;
    double ref_ms = 0.0;
    if ((st = shared ? reference(b, scene, &cam) : make_reference(b, scene, &cam, &own, &ref_ms)) != RL_OK)
        return st;
    const rl_image *ref = shared ? b->reference : own;
    const pt_config configs[] = {
        { .label = "bvh", .shadow = "bvh", .diffuse = "bvh" },
        { .label = "ls-pnmt, specular=exact", .shadow = "bvh", .diffuse = "ls-pnmt", .specular = "exact" },
        { .label = "ls-pnmt, specular=diffuse", .shadow = "bvh", .diffuse = "ls-pnmt", .specular = "diffuse" },
        { .label = "ls-preillum, specular=exact", .shadow = "bvh", .diffuse = "ls-preillum", .specular = "exact" },
        { .label = "ls-preillum, specular=diffuse", .shadow = "bvh", .diffuse = "ls-preillum",
          .specular = "diffuse" },
    };
    /* --quick: the PNMT pair only (pre-illumination builds are the slow
     * part under the sanitizers). */
    const int N = b->a->quick ? 3 : (int)(sizeof configs / sizeof configs[0]);
    printf("\nspecular rays (%s, %dx%d, %lld spp against %lld spp of the BVH; shadows: bvh)\n", SPECULAR_SCENE,
           cam.width, cam.height, b->a->spp_max, b->a->ref_spp);
    printf("%-32s %9s %8s %11s\n", "variant", "RMSE", "SSIM", "ms/spp");
    cJSON_AddStringToObject(sec, "scene", SPECULAR_SCENE);
    cJSON_AddNumberToObject(sec, "reference_spp", (double)b->a->ref_spp);
    cJSON *vars = cJSON_AddArrayToObject(sec, "variants");
    for (int i = 0; st == RL_OK && vars && i < N; i++) {
        curve_point pts[MAX_POINTS];
        int num = 0;
        rl_clear_error();
        if ((st = accumulate_curve_against(b, &configs[i], scene, &cam, ref, b->a->spp_max, pts, &num)) != RL_OK)
            break;
        const curve_point *last = &pts[num - 1];
        printf("%-32s %9.4f %8.4f %11.2f\n", configs[i].label, last->m.rmse, last->m.ssim,
               last->time_ms / (double)last->spp);
        cJSON *v = cJSON_CreateObject();
        if (!v) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        cJSON_AddItemToArray(vars, v);
        cJSON_AddStringToObject(v, "label", configs[i].label);
        cJSON_AddStringToObject(v, "diffuse", configs[i].diffuse);
        cJSON_AddStringToObject(v, "specular", configs[i].specular ? configs[i].specular : "exact");
        bench_add_num(v, "rmse", last->m.rmse);
        bench_add_num(v, "ssim", last->m.ssim);
        bench_add_num(v, "ms_per_spp", last->time_ms / (double)last->spp);
        cJSON_AddItemToObject(v, "curve", curve_json(pts, num));
    }
    rl_image_release(own);
    fflush(stdout);
    return st;
}

static rl_status sec_accumulation(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    const rl_scene *scene = NULL;
    rl_camera cam;
    rl_status st = error_setup(b, &scene, &cam);
    if (st != RL_OK)
        return st;
    /* Convergence of the exact path tracer. */
    curve_point pts[MAX_POINTS];
    int num = 0;
    pt_config base = { .label = "bvh", .shadow = "bvh", .diffuse = "bvh" };
    if ((st = accumulate_curve(b, &base, scene, &cam, b->a->spp_max, pts, &num)) != RL_OK)
        return st;
    printf("\naccumulation (%s, %dx%d, BVH, eq. 8): RMSE against total samples\n",
           diagram_scene(b), cam.width, cam.height);
    printf("%8s %10s %9s %8s\n", "spp", "time ms", "RMSE", "SSIM");
    for (int i = 0; i < num; i++)
        printf("%8lld %10.1f %9.4f %8.4f\n", pts[i].spp, pts[i].time_ms, pts[i].m.rmse,
               pts[i].m.ssim);
    cJSON_AddStringToObject(sec, "scene", diagram_scene(b));
    cJSON_AddItemToObject(sec, "convergence", curve_json(pts, num));
    /* Filters of Sec. 8.2 at full strength (filter_fade 0). */
    static const char *const filters[] = { "none", "gauss", "bilateral", "aniso", "kuwahara" };
    long long max_spp = b->a->spp_max < 16 ? b->a->spp_max : 16;
    printf("\nfilters (Sec. 8.2, full strength): RMSE / SSIM at 1, 4, 16 spp\n");
    printf("%-10s", "filter");
    for (long long s = 1; s <= max_spp; s *= 4)
        printf(" %8lld spp RMSE %7s", s, "SSIM");
    printf("\n");
    cJSON *fl = cJSON_AddArrayToObject(sec, "filters");
    if (!fl)
        return RL_ERR_OUT_OF_MEMORY;
    for (size_t f = 0; f < sizeof filters / sizeof filters[0]; f++) {
        pt_config c = base;
        c.label = filters[f];
        c.filter = strcmp(filters[f], "none") ? filters[f] : NULL;
        curve_point fp[MAX_POINTS];
        int fn = 0;
        rl_clear_error();
        if ((st = accumulate_curve(b, &c, scene, &cam, max_spp, fp, &fn)) != RL_OK)
            return st;
        printf("%-10s", filters[f]);
        cJSON *o = cJSON_CreateObject();
        if (!o)
            return RL_ERR_OUT_OF_MEMORY;
        cJSON_AddItemToArray(fl, o);
        cJSON_AddStringToObject(o, "filter", filters[f]);
        cJSON *pj = cJSON_AddArrayToObject(o, "points");
        for (int i = 0; i < fn; i++) {
            if (fp[i].spp != 1 && fp[i].spp != 4 && fp[i].spp != 16)
                continue;
            printf(" %17.4f %7.4f", fp[i].m.rmse, fp[i].m.ssim);
            cJSON *p = cJSON_CreateObject();
            if (!p || !pj)
                return RL_ERR_OUT_OF_MEMORY;
            cJSON_AddNumberToObject(p, "spp", (double)fp[i].spp);
            bench_add_num(p, "rmse", fp[i].m.rmse);
            bench_add_num(p, "ssim", fp[i].m.ssim);
            bench_add_num(p, "time_ms", fp[i].time_ms);
            cJSON_AddItemToArray(pj, p);
        }
        printf("\n");
    }
    fflush(stdout);
    return RL_OK;
}

static rl_status sec_convergence(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    bench_pt_conv_args ca = { .size = (int)b->a->conv_size, .ref_spp = b->a->conv_ref_spp,
                              .spp_max = b->a->conv_spp_max, .threads = b->threads, .out_path = b->out_path,
                              .configs = b->a->conv_configs, .custom = b->a->conv_set,
                              .ref_budget_s = b->a->conv_ref_budget,
                              .reason = b->reason, .reason_size = sizeof b->reason };
    return bench_pt_convergence(&ca, sec);
}

static rl_status sec_bdpt(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    bench_pt_bdpt_args ba = { .threads = b->threads, .quick = b->a->quick };
    return bench_pt_bdpt(&ba, sec);
}

static rl_status sec_hybrid(void *ctx, cJSON *sec)
{
    bpt *b = ctx;
    char why[256];
    if (!rl_gl_available(NULL, why, sizeof why)) {
        printf("hybrid: skipped, no OpenGL 4.5 context (%s)\n", why);
        cJSON_AddStringToObject(sec, "skipped", why);
        return RL_OK;
    }
    bench_pt_bdpt_args ba = { .threads = b->threads, .quick = b->a->quick };
    return bench_pt_hybrid(&ba, sec);
}

/* ------------------------------------------------------- the command -- */

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bpt_args *a)
{
    a->sections = (1u << SEC_COUNT) - 1;
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_FLAG("--small-pages", &a->small_pages),
        RL_BENCH_COUNT("--builds", 100, &a->builds, &a->has_builds),
        RL_BENCH_COUNT("--fixed-k", RL_LS_MAX_K, &a->fixed_k, &a->has_fixed_k),
        RL_BENCH_SIZE("--size", &a->width, &a->height, &a->has_size),
        RL_BENCH_SIZE("--error-size", &a->err_width, &a->err_height, &a->has_err_size),
        RL_BENCH_COUNT("--ref-spp", 1 << 20, &a->ref_spp, &a->has_ref_spp),
        RL_BENCH_COUNT("--spp-max", 1 << 16, &a->spp_max, &a->has_spp_max),
        RL_BENCH_COUNT("--max-memory", 1 << 16, &a->max_memory_gb, NULL),
        RL_BENCH_COUNT("--conv-size", 8192, &a->conv_size, &a->has_conv_size),
        RL_BENCH_COUNT("--conv-ref-spp", 1 << 20, &a->conv_ref_spp, &a->has_conv_ref_spp),
        RL_BENCH_COUNT("--conv-spp-max", 1 << 20, &a->conv_spp_max, &a->has_conv_spp_max),
        RL_BENCH_STRING("--conv-configs", &a->conv_configs),
        RL_BENCH_STRING("--conv-set", &a->conv_set),
        RL_BENCH_REAL("--conv-ref-budget", 0.0, 1e9, &a->conv_ref_budget, NULL),
        RL_BENCH_COUNT("--threads", 1024, &a->threads, NULL),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench pt", bench_pt_help, rows,
                                 (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    if (!a->has_size) {
        a->width = a->quick ? 128 : 1280;      /* Sec. 9.2: 1280x720 */
        a->height = a->quick ? 72 : 720;
    }
    if (!a->has_err_size) {
        a->err_width = a->quick ? 64 : 320;
        a->err_height = a->quick ? 36 : 180;
    }
    if (!a->has_ref_spp)
        a->ref_spp = a->quick ? 64 : 1024;
    if (!a->has_spp_max)
        a->spp_max = a->quick ? 8 : 64;
    if (!a->has_builds)
        a->builds = a->quick ? 1 : 3;
    if (!a->has_conv_size)
        a->conv_size = a->quick ? 64 : 512;
    if (!a->has_conv_ref_spp)
        a->conv_ref_spp = a->quick ? 64 : 4096;
    if (!a->has_conv_spp_max)
        a->conv_spp_max = a->quick ? 16 : 1024;
    if (a->conv_ref_spp < 2 || a->conv_spp_max < 4)
        return cli_fail(RL_CLI_USAGE, "--conv-ref-spp needs at least 2 (two halves), --conv-spp-max at least 4");
    if (!a->has_fixed_k)
        a->fixed_k = 8;
    if (a->fixed_k % 2 != 0)
        return cli_fail(RL_CLI_USAGE, "--fixed-k: %lld is odd (front and back halves of k/2, Alg. 3)",
                           a->fixed_k);
    return RL_CLI_OK;
}

static cJSON *params_json(const bpt *b)
{
    const bpt_args *a = b->a;
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    char text[64];
    snprintf(text, sizeof text, "%dx%d", a->width, a->height);
    cJSON_AddStringToObject(o, "size", text);
    snprintf(text, sizeof text, "%dx%d", a->err_width, a->err_height);
    cJSON_AddStringToObject(o, "error_size", text);
    cJSON_AddNumberToObject(o, "reference_spp", (double)a->ref_spp);
    cJSON_AddNumberToObject(o, "spp_max", (double)a->spp_max);
    cJSON_AddNumberToObject(o, "threads", b->threads);
    cJSON_AddNumberToObject(o, "max_memory_bytes", b->max_memory_bytes);
    cJSON_AddNumberToObject(o, "ls_n", RL_LS_DEFAULT_N);
    cJSON_AddBoolToObject(o, "quick", a->quick);
    cJSON_AddBoolToObject(o, "ls_huge_pages", !a->small_pages);
    cJSON_AddNumberToObject(o, "ls_builds", (double)a->builds);
    cJSON_AddNumberToObject(o, "ls_fixed_k", (double)a->fixed_k);
    cJSON_AddNumberToObject(o, "conv_size", (double)a->conv_size);
    cJSON_AddNumberToObject(o, "conv_ref_spp", (double)a->conv_ref_spp);
    cJSON_AddNumberToObject(o, "conv_spp_max", (double)a->conv_spp_max);
    cJSON_AddNumberToObject(o, "conv_ref_budget_s", a->conv_ref_budget);
    cJSON_AddStringToObject(o, "sampling",
                            "all sections but convergence: rng=hybrid, mis=off, light_samples=1, rr_depth=2 "
                            "(the thesis; pt's defaults before issue 37)");
    cJSON_AddNumberToObject(o, "warmup_renders", 1);
    cJSON_AddNumberToObject(o, "timed_renders", b->runs);
    cJSON_AddStringToObject(o, "seed", PT_SEED);
    cJSON_AddStringToObject(o, "timing",
                            "wall time of rl_renderer_render; per configuration one warm-up "
                            "render (builds grid/Line Space/shadow maps), then the fastest of "
                            "timed_renders with accumulate=false");
    cJSON_AddStringToObject(o, "metrics", "rl_image_compare: sRGB, SSIM on luma");
    return o;
}

static cJSON *thesis_json(void)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "machine", "Intel Core i7-6800K, NVIDIA GeForce GTX 1080 (GPU "
                                          "compute shaders)");
    cJSON_AddStringToObject(o, "resolution", "1280x720");
    cJSON_AddNumberToObject(o, "ls_n", 5);
    cJSON_AddStringToObject(o, "diffuse_pnmt_vs_grid", "more than 20x (Diagram 2)");
    cJSON_AddStringToObject(o, "shadow_pnmt_vs_grid", "about 10x (Diagram 3)");
    cJSON_AddStringToObject(o, "source", "Schroeder 2017, Table 1, Diagrams 1-3, Sec. 9-12");
    return o;
}

static double physical_memory(void)
{
    long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && page > 0 ? (double)pages * (double)page : 8.0 * 1073741824.0;
}

int bench_pt(int argc, char **argv)
{
    bpt_args a;
    memset(&a, 0, sizeof a);
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    bpt b;
    memset(&b, 0, sizeof b);
    b.a = &a;
    b.threads = a.threads ? (int)a.threads : omp_get_max_threads();
    b.runs = a.quick ? 1 : RUNS;
    b.max_memory_bytes = a.max_memory_gb > 0 ? (double)a.max_memory_gb * 1073741824.0
                                               : 0.6 * physical_memory();
    char out[4096];
    if (!bench_out_path(a.out, "pt", out, sizeof out))
        return RL_CLI_FAIL;
    rl_renderer *probe = NULL;
    rl_clear_error();
    rl_status st = rl_renderer_create("pt", &probe);
    /* Issue 34: refuse a --size that cannot fit, with the estimate. */
    int fits = st == RL_OK ? cli_check_frame_memory(probe, a.width, a.height, RL_LAYER_COLOR, 0.0,
                                                    a.max_memory_gb > 0 ? b.max_memory_bytes : 0.0)
                           : RL_CLI_OK;
    rl_renderer_release(probe);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, "bench pt");
    if (fits != RL_CLI_OK)
        return fits;
    cJSON *root = bench_record_json("pt", b.threads);
    if (!root)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    cJSON_AddItemToObject(root, "parameters", params_json(&b));
    cJSON_AddItemToObject(root, "thesis", thesis_json());
    static const bench_section_fn fns[SEC_COUNT] = { sec_generation, sec_scenes,       sec_diffuse,
                                                        sec_shadow,     sec_error,        sec_specular,
                                                        sec_accumulation, sec_convergence, sec_bdpt,
                                                        sec_hybrid };
    b.out_path = out;
    printf("rl bench pt: Line Space path tracing (Schroeder 2017), %d threads\n", b.threads);
    rc = bench_run_sections("pt", root, section_names, fns, SEC_COUNT, a.sections, &b,
                               b.reason, b.threads, out);
    cJSON_Delete(root);
    for (int i = 0; i < b.num_scenes; i++)
        rl_scene_release(b.scenes[i].scene);
    rl_image_release(b.reference);
    return rc;
}
