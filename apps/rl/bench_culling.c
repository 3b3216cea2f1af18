/* bench_culling.c: `rl bench culling`, the applications of Jähn 2015,
 * Ch. 7 for the culling and level-of-detail renderers, each measured with
 * the evaluator
 * (position-dependent properties over a sampled region) and printed beside
 * the thesis' figures:
 *   surfels Sec. 7.2: the time, the primitives drawn (triangles + points,
 *           max of 6 directions) and the image quality (hierarchical SSIM
 *           against raster) of the surfels renderer for the projected-size
 *           ranges [50,100], [100,200] (default), [200,300], [300,400],
 *           at the same positions of a 3-D region from the ground to twice
 *           the scene's height (the thesis samples a vertical 2-D slice,
 *           which our sampler does not offer; 1024 samples there);
 *   depth   Sec. 7.3: the conditioned rendering time of chcpp for octree
 *           depths 0..--max-depth, each approximated by adaptive sampling
 *           of a 3-D region (the scene's bounds, 20 % higher); the depth
 *           with the lowest area-weighted mean (the thesis: 5, 9.9 ms);
 *   svs     Sec. 7.4: over a 2-D slice, at the positions of the sampled
 *           "polygons in visible objects" (the visibility property,
 *           measure polygons; the lower bound of any object-based
 *           conservative method), the conditioned time and the rasterized
 *           triangles of chcpp and svs, and svs' image quality (SSIM, worst
 *           of 6 directions) against raster (the conservative image). The
 *           thesis: mean 18 ms (svs) vs 55 ms (chcpp), 7.1 M vs 15 M
 *           polygons;
 *   select  Sec. 7.5: at --select-positions random positions of the slice,
 *           each with a random view direction, one frame of chcpp and of
 *           svs (median of 3 after 3 unmeasured frames); runtime selection
 *           takes chcpp where the sampled polygons in visible objects fall
 *           below their --select-quantile, else svs. Mean time of each and
 *           of the selection, over all positions and over the
 *           high-occlusion ones (the thesis: 7 ms -> 3 ms there); with the
 *           svs section run too, also the selection by its sampled times
 *           (the faster of the two approximations at the position, the
 *           thesis' hardware-bound alternative), judged both on those
 *           single frames and on the time property itself (6 views, max)
 *           measured anew at the same positions;
 *   visset  Sec. 7.6: the sampled visible sets of the svs section as a
 *           renderer (visset, from the saved approx.json): memory of the
 *           sets (the thesis: 31 MB), its time (max; the thesis 14 ms) and
 *           its image quality (hierarchical SSIM, min) at
 *           --visset-positions random positions of the slice (not the
 *           samples, where the sets are exact), and the budgeted variant
 *           (--budget triangles).
 *   walk    (only with --only walk) Sec. 7.4 frame by frame: chcpp and
 *           svs down a walk of --walk-frames frames along the scene's
 *           "street" camera (else its default one), with the software
 *           drawer and the GL one (--drawer): frame times, triangles,
 *           occlusion queries and how many of their answers chcpp found
 *           ready, had to wait for or carried into the next frame; chcpp
 *           twice: as CHC++ hides latency (its V-queue, answers a frame
 *           later: latency=frame, the default) and in CHC's order waiting
 *           for every answer (vqueue=false latency=wait, as before). The
 *           rows' renderers take each frame in turn, so that a shared
 *           machine's load falls on all of them alike. On a GPU this is
 *           the thesis' question with real query latency; on llvmpipe
 *           (Mesa's CPU GL) there is little to hide.
 * The reports of the same measurements as heat maps and violins come from
 * `rl compare` (docs/culling.md gives the commands). */
#define _POSIX_C_SOURCE 200809L
#include "bench_culling.h"

#include "bench_args.h"
#include "bench_rays.h"
#include "bench_resume.h"
#include "bench_util.h"
#include "cli.h"
#include "eval_common.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define note(...) (fflush(stdout), bench_note("culling", __VA_ARGS__))

static const char bench_culling_help[] =
    "usage: rl bench culling [options]\n"
    "\n"
    "The Jaehn 2015 Ch. 7 applications of the culling renderers, measured as\n"
    "position-dependent properties (see docs/culling.md). Sections:\n"
    "  surfels  Sec. 7.2: surfels time and quality per projected-size range\n"
    "  depth    Sec. 7.3: chcpp time per octree depth over a 3-D region\n"
    "  svs      Sec. 7.4: chcpp vs svs over a 2-D slice: time, triangles,\n"
    "           polygons in visible objects, svs quality\n"
    "  select   Sec. 7.5: runtime selection of chcpp or svs per position\n"
    "  visset   Sec. 7.6: the sampled visible sets as a renderer, with budget\n"
    "  walk     Sec. 7.4 per frame down a street: chcpp (latency=frame, and\n"
    "           CHC's order with latency=wait) and svs on the software and the\n"
    "           GL drawer (only when named in --only)\n"
    "\n"
    "options:\n"
    "  --scene S            default city (the thesis: 4 Power Plants for 7.4-7.6;\n"
    "                       city:blocks=12 is 4x city)\n"
    "  --only LIST          sections, comma-separated; default all\n"
    "  --samples N          samples per approximation; default 96\n"
    "  --max-depth N        depth section: depths 0..N; default 8\n"
    "  --size N             image side per direction; default 128\n"
    "  --height H           slice height above the scene's floor; default 10\n"
    "  --extent F           the slice of svs/select/visset spans F times the\n"
    "                       scene's width and depth around its centre (2: the\n"
    "                       city seen from outside too); default 1\n"
    "  --resolution N       cube-face side of the visibility property; default 128\n"
    "  --select-positions N default 100\n"
    "  --select-quantile Q  high occlusion below this quantile; default 0.25\n"
    "  --surfels N          surfels per node (surfels section); default 40000\n"
    "  --visset-positions N random positions of the slice (not the samples)\n"
    "                       where visset is measured; default: --samples\n"
    "  --budget N           triangles of the budgeted visset; default: a quarter\n"
    "                       of chcpp's mean\n"
    "  --threads N          default all\n"
    "  --seed N             default 1\n"
    "  --out FILE.json      default bench/results/culling-YYYYMMDD-HHMMSS.json\n"
    "  --resume DIR         keep the sampled slice of svs/select/visset and\n"
    "                       every value measured at its positions in DIR (saved\n"
    "                       every 32 positions), and each depth's sampling of\n"
    "                       the depth section: the same command continues a\n"
    "                       run that stopped; DIR must be new or made by a run\n"
    "                       with the same options\n"
    "  --walk-frames N      walk section: frames; default 40\n"
    "  --drawer D           walk section: software, gl or both; default both\n"
    "                       (gl where a GL 4.5 context can be made)\n"
    "  --quick              tiny run: cornell-sized box city, few samples\n"
    "\n"
    "example:\n"
    "  rl bench culling --only depth,svs --samples 256\n"
    "  rl bench culling --scene city:blocks=12 --only svs --samples 4096 --resume out/svs4096\n"
    "  rl bench culling --only walk --size 640 --drawer both\n";

enum { SEC_SURFELS, SEC_DEPTH, SEC_SVS, SEC_SELECT, SEC_VISSET, SEC_WALK, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "surfels", "depth", "svs", "select", "visset", "walk" };
static const char *const drawer_names[] = { "software", "gl", "both" };
enum { DRAWER_SOFTWARE, DRAWER_GL, DRAWER_BOTH };

/* Positions measured between two saves of a --resume run. */
#define RESUME_BLOCK 32

typedef struct bc_args {
    const char *scene, *out, *resume;
    long long samples, max_depth, size, resolution, select_positions, visset_positions, budget, threads, seed, surfels;
    long long walk_frames;
    int drawer;                   /* DRAWER_* */
    double height, select_quantile, extent;
    unsigned sections;
    bool quick;
} bc_args;

typedef struct bc_ctx {
    bc_args *a;
    rl_scene *scene;
    const rl_scene_data *d;
    char dir[1024];               /* for the saved approximation */
    /* svs section's positions and values, reused by select and visset */
    rl_approx *driver;
    rl_vec3 *pos;
    uint32_t npos;
    double chcpp_triangles_mean;
    rl_approx *time_chcpp, *time_svs;   /* the svs section's sampled times, for select */
    bench_resume *resume;      /* --resume: NULL without */
    const char *frames;           /* measured and conditioning frames of the time property */
    char reason[512];
} bc_ctx;

/* eval_measure, over the job's ranks under --dist (the property service:
 * the workers make the property themselves from its options). */
static rl_status bc_measure(rl_property *p, const rl_vec3 *pos, size_t n, double **values, const char *label)
{
    if (cli_dist_ranks() == 1)
        return eval_measure(p, pos, n, values, label);
    double *v = malloc((n ? n : 1) * sizeof *v);
    if (!v)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st = cli_measure_call(p, pos, n, v);
    if (st != RL_OK) {
        free(v);
        return st;
    }
    *values = v;
    return RL_OK;
}

/* A property with options {key, value, ..., NULL}, committed. */
static rl_status make_property(bc_ctx *c, const char *name, const char *const *kv, rl_property **out)
{
    rl_property *p = NULL;
    rl_status st = rl_property_create(name, &p);
    for (size_t i = 0; st == RL_OK && kv && kv[i]; i += 2)
        st = rl_property_set(p, kv[i], kv[i + 1]);
    if (st == RL_OK)
        st = rl_property_commit(p, c->scene, (int)c->a->threads);
    if (st != RL_OK) {
        rl_property_release(p);
        return st;
    }
    *out = p;
    return RL_OK;
}

/* Area- (volume-) weighted statistics of values given at the driver's
 * samples, through the driver's regions. */
static rl_status region_stats(const rl_approx *driver, const double *values, rl_stats *out)
{
    rl_approx *a = NULL;
    rl_status st = rl_approx_with_values(driver, values, "v", "", &a);
    double *v = NULL, *w = NULL;
    size_t n = 0;
    if (st == RL_OK && !eval_leaf_series(a, &v, &w, &n))
        st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        st = rl_stats_compute(v, w, n, out);
    free(v);
    free(w);
    rl_approx_release(a);
    return st;
}

static cJSON *stats_json(const rl_stats *s)
{
    return eval_stats_json(s);
}

/* The time property's options for one renderer: conditioned (Jähn 2015, Sec.
 * 4.2.3), the median of c->frames measured frames after as many unmeasured
 * ones (3; 1 with --quick). */
#define TIME_KV(renderer, options)                                                                     \
    (const char *const[]) { "renderer", renderer, "renderer_options", options, "width", size, "height", size, \
                            "repeats", c->frames, "conditioned", "true", "condition_frames", c->frames, NULL }

/* --- Sec. 7.2 --- */
static rl_status sec_surfels(void *ctx, cJSON *sec)
{
    bc_ctx *c = ctx;
    static const int ranges[4][2] = { { 50, 100 }, { 100, 200 }, { 200, 300 }, { 300, 400 } };
    char size[32];
    snprintf(size, sizeof size, "%lld", c->a->size);
    /* The positions: adaptive sampling of the default range's time. */
    rl_aabb region = c->d->bounds;
    region.max.y = region.min.y + 2.0f * (region.max.y - region.min.y);
    char common[160];
    /* --quick: few, small surfel nodes, so that it stays a smoke test. */
    snprintf(common, sizeof common, "count=%lld,resolution=%d,min_triangles=%lld", c->a->surfels,
             c->a->quick ? 64 : 1024, c->a->quick ? 16 * c->a->surfels : c->a->surfels);
    char opts[4][256];
    for (int k = 0; k < 4; ++k)
        snprintf(opts[k], sizeof opts[k], "%s,min_size=%d,max_size=%d", common, ranges[k][0], ranges[k][1]);
    rl_property *p = NULL;
    rl_status st = make_property(c, "time", TIME_KV("surfels", opts[1]), &p);
    rl_sampling_desc sd = { .region = region, .dims = 3, .max_samples = (uint32_t)c->a->samples,
                            .seed = (uint64_t)c->a->seed };
    rl_approx *driver = NULL;
    if (st == RL_OK) {
        note("surfels: sampling the time of [100,200] (%lld samples; the first builds the surfels)",
             c->a->samples);
        st = cli_sample_call(p, &sd, &driver);
    }
    rl_property_release(p);
    if (st != RL_OK)
        return st;
    uint32_t n = rl_approx_sample_count(driver);
    rl_vec3 *pos = malloc((n ? n : 1) * sizeof *pos);
    double *tv = malloc((n ? n : 1) * sizeof *tv);
    if (!pos || !tv) {
        free(pos);
        free(tv);
        rl_approx_release(driver);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < n; ++i)
        rl_approx_sample(driver, i, &pos[i], &tv[i]);
    printf("\nSec. 7.2: surfels (%lld per node) time and quality per projected-size range, %u positions, 3-D\n",
           c->a->surfels, n);
    printf("%-12s %10s %10s %10s %10s %12s\n", "range (px)", "time mean", "time max", "hSSIM mean", "hSSIM min",
           "primitives");
    cJSON *rows = cJSON_AddArrayToObject(sec, "ranges");
    for (int k = 0; k < 4 && st == RL_OK; ++k) {
        rl_stats t, q, prim;
        double *values = NULL;
        if (k == 1) {
            st = region_stats(driver, tv, &t);
        } else {
            rl_property *pt = NULL;
            st = make_property(c, "time", TIME_KV("surfels", opts[k]), &pt);
            if (st == RL_OK)
                st = bc_measure(pt, pos, n, &values, "surfels time");
            if (st == RL_OK)
                st = region_stats(driver, values, &t);
            free(values);
            values = NULL;
            rl_property_release(pt);
        }
        const char *const q_kv[] = { "renderer", "surfels", "renderer_options", opts[k], "reference", "raster",
                                     "metric", "hssim", "width", size, "height", size, NULL };
        rl_property *pq = NULL;
        if (st == RL_OK)
            st = make_property(c, "quality", q_kv, &pq);
        if (st == RL_OK)
            st = bc_measure(pq, pos, n, &values, "surfels quality");
        if (st == RL_OK)
            st = region_stats(driver, values, &q);
        free(values);
        values = NULL;
        rl_property_release(pq);
        const char *const prim_kv[] = { "renderer", "surfels", "renderer_options", opts[k], "counter", "primitives",
                                        "width", size, "height", size, NULL };
        rl_property *pp = NULL;
        if (st == RL_OK)
            st = make_property(c, "ops", prim_kv, &pp);
        if (st == RL_OK)
            st = bc_measure(pp, pos, n, &values, "surfels primitives");
        if (st == RL_OK)
            st = region_stats(driver, values, &prim);
        free(values);
        rl_property_release(pp);
        if (st != RL_OK)
            break;
        char label[32];
        snprintf(label, sizeof label, "[%d,%d]", ranges[k][0], ranges[k][1]);
        printf("%-12s %10.3f %10.3f %10.4f %10.4f %12.4g\n", label, t.mean, t.max, q.mean, q.min, prim.mean);
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "min_size", ranges[k][0]);
        cJSON_AddNumberToObject(o, "max_size", ranges[k][1]);
        cJSON_AddItemToObject(o, "time_ms", stats_json(&t));
        cJSON_AddItemToObject(o, "hssim", stats_json(&q));
        cJSON_AddItemToObject(o, "primitives", stats_json(&prim));
        cJSON_AddItemToArray(rows, o);
    }
    printf("thesis (162 M polygons, 80k surfels per subtree > 2 M polygons): max time < 45 ms from [100,200] on;\n"
           "time and quality fall as the range grows (Fig. 7.3-7.4)\n");
    free(pos);
    free(tv);
    rl_approx_release(driver);
    return st;
}

/* --- Sec. 7.3 --- */
/* The time of chcpp with options opts sampled over region; with --resume,
 * the approximation of one depth is kept in DIR/depth-N.json, so a stopped
 * run continues with the next depth (one depth is the unit: the adaptive
 * sampling itself cannot be resumed). */
static rl_status depth_sampled(bc_ctx *c, int depth, const rl_aabb *region, const char *opts, const char *size,
                               rl_approx **out)
{
    char name[32];
    snprintf(name, sizeof name, "depth-%d.json", depth);
    *out = NULL;
    rl_status st = c->resume ? bench_resume_load_approx(c->resume, name, out) : RL_OK;
    if (st != RL_OK || *out) {
        if (*out)
            note("depth %d: sampled before (%s)", depth, bench_resume_path(c->resume, name));
        return st;
    }
    rl_property *p = NULL;
    st = make_property(c, "time", TIME_KV("chcpp", opts), &p);
    rl_sampling_desc sd = { .region = *region, .dims = 3, .max_samples = (uint32_t)c->a->samples,
                            .seed = (uint64_t)c->a->seed };
    if (st == RL_OK) {
        note("depth %d: sampling chcpp's time (%lld samples)", depth, c->a->samples);
        st = cli_sample_call(p, &sd, out);
    }
    rl_property_release(p);
    if (st == RL_OK && c->resume && !bench_resume_save_approx(c->resume, name, *out)) {
        rl_approx_release(*out);
        *out = NULL;
        st = RL_ERR_IO;
    }
    return st;
}

static rl_status sec_depth(void *ctx, cJSON *sec)
{
    bc_ctx *c = ctx;
    char size[32];
    snprintf(size, sizeof size, "%lld", c->a->size);
    rl_aabb region = c->d->bounds;
    region.max.y += 0.2f * (region.max.y - region.min.y);
    printf("\nSec. 7.3: conditioned chcpp time (ms) per maximum octree depth, %lld samples each, 3-D region\n",
           c->a->samples);
    printf("%5s %7s %9s %9s %9s %9s %9s\n", "depth", "nodes", "mean", "q25", "median", "q75", "max");
    cJSON *rows = cJSON_AddArrayToObject(sec, "depths");
    int best = -1;
    double best_mean = INFINITY;
    for (int depth = 0; depth <= (int)c->a->max_depth; ++depth) {
        char opts[64];
        snprintf(opts, sizeof opts, "max_depth=%d", depth);
        rl_approx *a = NULL;
        rl_status st = depth_sampled(c, depth, &region, opts, size, &a);
        double *v = NULL, *w = NULL;
        size_t n = 0;
        rl_stats s;
        if (st == RL_OK && !eval_leaf_series(a, &v, &w, &n))
            st = RL_ERR_OUT_OF_MEMORY;
        if (st == RL_OK)
            st = rl_stats_compute(v, w, n, &s);
        free(v);
        free(w);
        rl_approx_release(a);
        if (st != RL_OK)
            return st;
        rl_octree *t = NULL;
        uint32_t nodes = 0;
        if (rl_octree_build(c->scene, &(rl_octree_desc){ .max_depth = depth ? depth : RL_OCTREE_DEPTH_ZERO },
                            &t) == RL_OK)
            rl_octree_nodes(t, &nodes);
        rl_octree_release(t);
        printf("%5d %7u %9.2f %9.2f %9.2f %9.2f %9.2f\n", depth, nodes, s.mean, s.q[1], s.q[2], s.q[3], s.max);
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "max_depth", depth);
        cJSON_AddNumberToObject(o, "octree_nodes", nodes);
        cJSON_AddItemToObject(o, "time_ms", stats_json(&s));
        cJSON_AddItemToArray(rows, o);
        if (s.mean < best_mean) {
            best_mean = s.mean;
            best = depth;
        }
    }
    printf("best depth %d, mean %.2f ms (thesis, Power Plant: depth 5, 9.9 ms)\n", best, best_mean);
    cJSON_AddNumberToObject(sec, "best_depth", best);
    bench_add_num(sec, "best_mean_ms", best_mean);
    cJSON_AddNumberToObject(sec, "thesis_best_depth", 5);
    cJSON_AddNumberToObject(sec, "thesis_best_mean_ms", 9.9);
    return RL_OK;
}

/* --- the shared slice of Sec. 7.4-7.6 --- */
/* c->pos and c->npos from the driver's samples. */
static rl_status driver_positions(bc_ctx *c)
{
    c->npos = rl_approx_sample_count(c->driver);
    c->pos = malloc((c->npos ? c->npos : 1) * sizeof *c->pos);
    if (!c->pos)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t k = 0; k < c->npos; ++k)
        rl_approx_sample(c->driver, k, &c->pos[k], NULL);
    return RL_OK;
}

static rl_status ensure_driver(bc_ctx *c)
{
    if (c->driver)
        return RL_OK;
    /* --resume: the slice of an earlier run with the same options. */
    rl_status st = c->resume ? bench_resume_load_approx(c->resume, "slice.json", &c->driver) : RL_OK;
    if (st != RL_OK)
        return st;
    if (c->driver) {
        note("polygons in visible objects: the slice sampled before (%s)",
             bench_resume_path(c->resume, "slice.json"));
        return driver_positions(c);
    }
    char res[32];
    snprintf(res, sizeof res, "%lld", c->a->resolution);
    rl_property *vis = NULL;
    st = make_property(c, "visibility", (const char *const[]){ "resolution", res, "measure", "polygons",
                                                                         NULL },
                                 &vis);
    /* --extent: the scene's x/z extent scaled about its centre. */
    rl_aabb slice = c->d->bounds;
    float cx = 0.5f * (slice.min.x + slice.max.x), cz = 0.5f * (slice.min.z + slice.max.z);
    float hx = 0.5f * (float)c->a->extent * (slice.max.x - slice.min.x);
    float hz = 0.5f * (float)c->a->extent * (slice.max.z - slice.min.z);
    slice.min.x = cx - hx;
    slice.max.x = cx + hx;
    slice.min.z = cz - hz;
    slice.max.z = cz + hz;
    rl_sampling_desc sd = { .region = slice, .dims = 2,
                            .height = c->d->bounds.min.y + (float)c->a->height,
                            .max_samples = (uint32_t)c->a->samples, .seed = (uint64_t)c->a->seed };
    if (st == RL_OK) {
        note("sampling polygons in visible objects (%lld samples)", c->a->samples);
        st = cli_sample_call(vis, &sd, &c->driver);
    }
    rl_property_release(vis);
    if (st == RL_OK && c->resume && !bench_resume_save_approx(c->resume, "slice.json", c->driver))
        st = RL_ERR_IO;
    if (st != RL_OK)
        return st;
    return driver_positions(c);
}

/* --resume: p at the npos positions pos, continuing the series saved under
 * label and saving it every RESUME_BLOCK positions. */
static rl_status measure_resumable(bc_ctx *c, rl_property *p, const char *label, const rl_vec3 *pos,
                                   uint32_t npos, double **values)
{
    char name[128];
    size_t k = 0;
    for (const char *q = label; *q && k + 6 < sizeof name; ++q)
        name[k++] = (*q >= 'a' && *q <= 'z') || (*q >= '0' && *q <= '9') ? *q : '-';
    snprintf(name + k, sizeof name - k, ".json");
    double *v = NULL;
    size_t done = 0;
    if (!bench_resume_load(c->resume, name, &v, &done))
        return RL_ERR_IO;
    if (done > npos) {
        free(v);
        note("%s holds %zu values for %u positions", bench_resume_path(c->resume, name), done, npos);
        return RL_ERR_IO;
    }
    double *all = realloc(v, (npos ? npos : 1) * sizeof *all);
    if (!all) {
        free(v);
        return RL_ERR_OUT_OF_MEMORY;
    }
    if (done > 0)
        note("%s: %zu of %u positions measured before", label, done, npos);
    rl_status st = RL_OK;
    while (st == RL_OK && done < npos) {
        size_t n = npos - done < RESUME_BLOCK ? npos - done : RESUME_BLOCK;
        double *block = NULL;
        char what[160];
        snprintf(what, sizeof what, "%s (%zu-%zu of %u)", label, done + 1, done + n, npos);
        st = bc_measure(p, pos + done, n, &block, what);
        if (st == RL_OK) {
            memcpy(all + done, block, n * sizeof *block);
            done += n;
            if (!bench_resume_save(c->resume, name, all, done))
                st = RL_ERR_IO;
        }
        free(block);
    }
    if (st != RL_OK) {
        free(all);
        return st;
    }
    *values = all;
    return RL_OK;
}

/* Property name/kv at the npos positions pos into *values (a series kept
 * under label with --resume). */
static rl_status measure_at(bc_ctx *c, const char *label, const char *name, const char *const *kv,
                            const rl_vec3 *pos, uint32_t npos, double **values)
{
    rl_property *p = NULL;
    rl_status st = make_property(c, name, kv, &p);
    if (st == RL_OK)
        st = c->resume ? measure_resumable(c, p, label, pos, npos, values)
                       : bc_measure(p, pos, npos, values, label);
    rl_property_release(p);
    return st;
}

/* Measures property name/kv at the driver's positions into stats; with
 * keep, also the approximation over the driver's regions (for queries). */
static rl_status measure_at_driver_keep(bc_ctx *c, const char *label, const char *name, const char *const *kv,
                                        rl_stats *s, rl_approx **keep)
{
    double *values = NULL;
    rl_status st = measure_at(c, label, name, kv, c->pos, c->npos, &values);
    if (st == RL_OK)
        st = region_stats(c->driver, values, s);
    if (st == RL_OK && keep)
        st = rl_approx_with_values(c->driver, values, "time", "ms", keep);
    free(values);
    return st;
}

/* Measures property name/kv at the driver's positions into stats. */
static rl_status measure_at_driver(bc_ctx *c, const char *label, const char *name, const char *const *kv,
                                   rl_stats *s)
{
    return measure_at_driver_keep(c, label, name, kv, s, NULL);
}

static void table_row(const char *what, const rl_stats *s, const char *thesis)
{
    printf("%-36s %11.4g %11.4g %11.4g %11.4g  %s\n", what, s->mean, s->min, s->q[2], s->max, thesis);
}

/* svs' options: its defaults, or 12 directions at 32² for --quick, which
 * only keeps the benchmark from rotting. */
static const char *svs_options(const bc_ctx *c)
{
    return c->a->quick ? "levels=0,resolution=32" : "";
}

/* --- Sec. 7.4 --- */
static rl_status sec_svs(void *ctx, cJSON *sec)
{
    bc_ctx *c = ctx;
    rl_status st = ensure_driver(c);
    if (st != RL_OK)
        return st;
    char size[32];
    snprintf(size, sizeof size, "%lld", c->a->size);
    rl_stats vis, t_chc, t_svs, tri_chc, tri_svs, q_svs;
    double *dv = NULL, *dw = NULL;
    size_t dn = 0;
    if (!eval_leaf_series(c->driver, &dv, &dw, &dn))
        return RL_ERR_OUT_OF_MEMORY;
    st = rl_stats_compute(dv, dw, dn, &vis);
    free(dv);
    free(dw);
    const char *const tri_kv_chc[] = { "renderer", "chcpp", "width", size, "height", size, "counter", "triangles",
                                       NULL };
    const char *const tri_kv_svs[] = { "renderer", "svs", "renderer_options", svs_options(c), "width", size,
                                       "height", size, "counter", "triangles", NULL };
    /* Single-scale SSIM, as every record of this section so far (the
     * quality property's default is hierarchical SSIM since 2026-12-04). */
    const char *const q_kv[] = { "renderer", "svs", "renderer_options", svs_options(c), "reference", "raster",
                                 "metric", "ssim", "width", size, "height", size, NULL };
    if (st == RL_OK)
        st = measure_at_driver_keep(c, "chcpp time", "time", TIME_KV("chcpp", ""), &t_chc, &c->time_chcpp);
    if (st == RL_OK)
        st = measure_at_driver_keep(c, "svs time", "time", TIME_KV("svs", svs_options(c)), &t_svs, &c->time_svs);
    if (st == RL_OK)
        st = measure_at_driver(c, "chcpp triangles", "ops", tri_kv_chc, &tri_chc);
    if (st == RL_OK)
        st = measure_at_driver(c, "svs triangles", "ops", tri_kv_svs, &tri_svs);
    if (st == RL_OK)
        st = measure_at_driver(c, "svs quality", "quality", q_kv, &q_svs);
    if (st != RL_OK)
        return st;
    c->chcpp_triangles_mean = tri_chc.mean;
    printf("\nSec. 7.4: chcpp vs svs over the slice y = floor + %g (%g x the scene's width), %u positions "
           "(area-weighted)\n", c->a->height, c->a->extent, c->npos);
    printf("%-36s %11s %11s %11s %11s  %s\n", "property", "mean", "min", "median", "max", "thesis (mean)");
    table_row("polygons in visible objects", &vis, "-");
    table_row("chcpp time (ms, conditioned)", &t_chc, "55 ms");
    table_row("svs time (ms, conditioned)", &t_svs, "18 ms");
    table_row("chcpp triangles (max of 6 dirs)", &tri_chc, "15 M");
    table_row("svs triangles (max of 6 dirs)", &tri_svs, "7.1 M");
    table_row("svs SSIM vs raster (min of 6 dirs)", &q_svs, "not measured");
    printf("svs / chcpp: time %.2f (thesis 0.33), triangles %.2f (thesis 0.47)\n",
           bench_ratio(t_svs.mean, t_chc.mean), bench_ratio(tri_svs.mean, tri_chc.mean));
    cJSON_AddNumberToObject(sec, "positions", c->npos);
    cJSON_AddItemToObject(sec, "visible_polygons", stats_json(&vis));
    cJSON_AddItemToObject(sec, "chcpp_time_ms", stats_json(&t_chc));
    cJSON_AddItemToObject(sec, "svs_time_ms", stats_json(&t_svs));
    cJSON_AddItemToObject(sec, "chcpp_triangles", stats_json(&tri_chc));
    cJSON_AddItemToObject(sec, "svs_triangles", stats_json(&tri_svs));
    cJSON_AddItemToObject(sec, "svs_ssim", stats_json(&q_svs));
    bench_add_num(sec, "time_ratio_svs_chcpp", bench_ratio(t_svs.mean, t_chc.mean));
    bench_add_num(sec, "triangle_ratio_svs_chcpp", bench_ratio(tri_svs.mean, tri_chc.mean));
    return RL_OK;
}

/* --- Sec. 7.5 --- */

/* Median of 3 measured frames after 3 unmeasured ones (conditioned). */
static rl_status frame_ms(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *img, double *ms)
{
    double t[3];
    rl_render_stats st;
    for (int i = 0; i < 6; ++i) {
        rl_status s = rl_renderer_render(r, scene, cam, img, &st);
        if (s != RL_OK)
            return s;
        if (i >= 3)
            t[i - 3] = st.time_ms;
    }
    double lo = fmin(t[0], fmin(t[1], t[2])), hi = fmax(t[0], fmax(t[1], t[2]));
    *ms = t[0] + t[1] + t[2] - lo - hi;
    return RL_OK;
}

static rl_status sec_select(void *ctx, cJSON *sec)
{
    bc_ctx *c = ctx;
    rl_status st = ensure_driver(c);
    if (st != RL_OK)
        return st;
    /* The threshold: a quantile of the sampled polygons in visible objects. */
    double *dv = NULL, *dw = NULL, threshold = 0.0;
    size_t dn = 0;
    if (!eval_leaf_series(c->driver, &dv, &dw, &dn))
        return RL_ERR_OUT_OF_MEMORY;
    st = rl_stats_quantiles(dv, dw, dn, &c->a->select_quantile, 1, &threshold);
    free(dv);
    free(dw);
    if (st != RL_OK)
        return st;
    const size_t n = (size_t)c->a->select_positions;
    rl_vec3 *pos = eval_random_positions(c->driver, n, (uint64_t)c->a->seed + 75);
    rl_renderer *chc = NULL, *svs = NULL;
    rl_image *img = NULL;
    /* Per position: the sampled times pick chcpp (the same pick judges
     * the single frames and the time property below). */
    bool *pick_chcpp = calloc(n ? n : 1, sizeof *pick_chcpp);
    if (!pos || !pick_chcpp) {
        free(pos);
        free(pick_chcpp);
        return RL_ERR_OUT_OF_MEMORY;
    }
    char th[32];
    snprintf(th, sizeof th, "%lld", c->a->threads);
    st = rl_renderer_create("chcpp", &chc);
    if (st == RL_OK)
        st = rl_renderer_create("svs", &svs);
    if (st == RL_OK)
        st = rl_renderer_set(chc, "threads", th);
    if (st == RL_OK)
        st = rl_renderer_set(svs, "threads", th);
    if (st == RL_OK && c->a->quick)
        st = rl_renderer_set(svs, "levels", "0");
    if (st == RL_OK && c->a->quick)
        st = rl_renderer_set(svs, "resolution", "32");
    if (st == RL_OK)
        st = rl_image_create((int)c->a->size, (int)c->a->size, RL_LAYER_COLOR, &img);
    rl_rng rng;
    rl_rng_seed(&rng, (uint64_t)c->a->seed, 0x75);
    double sum_c = 0, sum_s = 0, sum_sel = 0, hc = 0, hs = 0, hsel = 0, sum_tsel = 0;
    size_t timed = 0, picked_chcpp = 0;
    size_t high = 0;
    note("select: %zu random positions and directions", n);
    for (size_t i = 0; i < n && st == RL_OK; ++i) {
        /* Sec. 7.5: a random direction, so that the view is not averaged away. */
        float yaw = 2.0f * RL_PI * rl_rng_float(&rng), pitch = rl_radians(40.0f * (rl_rng_float(&rng) - 0.5f));
        rl_vec3 dir = rl_v3(cosf(pitch) * cosf(yaw), sinf(pitch), cosf(pitch) * sinf(yaw));
        rl_camera cam = { .eye = pos[i], .target = rl_add(pos[i], dir), .fov_deg = 60.0f,
                          .width = (int)c->a->size, .height = (int)c->a->size };
        double vp = 0.0, tc = 0.0, ts = 0.0;
        st = rl_approx_query(c->driver, pos[i], &vp, NULL);
        if (st == RL_OK)
            st = frame_ms(chc, c->scene, &cam, img, &tc);
        if (st == RL_OK)
            st = frame_ms(svs, c->scene, &cam, img, &ts);
        bool occluded = vp < threshold;
        double sel = occluded ? tc : ts;
        /* The other rule of Sec. 7.5: the faster by the sampled times of
         * the svs section (hardware-bound, the thesis warns), where known. */
        double pc = 0.0, ps = 0.0;
        if (st == RL_OK && c->time_chcpp && c->time_svs &&
            rl_approx_query(c->time_chcpp, pos[i], &pc, NULL) == RL_OK &&
            rl_approx_query(c->time_svs, pos[i], &ps, NULL) == RL_OK) {
            ++timed;
            pick_chcpp[i] = pc <= ps;
            picked_chcpp += pick_chcpp[i];
            sum_tsel += pick_chcpp[i] ? tc : ts;
        }
        sum_c += tc;
        sum_s += ts;
        sum_sel += sel;
        if (occluded) {
            ++high;
            hc += tc;
            hs += ts;
            hsel += sel;
        }
    }
    rl_image_release(img);
    rl_renderer_release(chc);
    rl_renderer_release(svs);
    /* The selection judged on the quantity it predicts: the time property
     * itself (6 directions of 120°, the max) of both renderers at the same
     * positions, not at the sampled ones. */
    double *pc6 = NULL, *ps6 = NULL, sum_c6 = 0, sum_s6 = 0, sum_sel6 = 0;
    const bool six = st == RL_OK && timed == n;
    if (six) {
        char size[32];
        snprintf(size, sizeof size, "%lld", c->a->size);
        rl_property *tp = NULL;
        st = make_property(c, "time", TIME_KV("chcpp", ""), &tp);
        if (st == RL_OK)
            st = bc_measure(tp, pos, n, &pc6, "select chcpp time");
        rl_property_release(tp);
        tp = NULL;
        if (st == RL_OK)
            st = make_property(c, "time", TIME_KV("svs", svs_options(c)), &tp);
        if (st == RL_OK)
            st = bc_measure(tp, pos, n, &ps6, "select svs time");
        rl_property_release(tp);
        for (size_t i = 0; i < n && st == RL_OK; ++i) {
            sum_c6 += pc6[i];
            sum_s6 += ps6[i];
            sum_sel6 += pick_chcpp[i] ? pc6[i] : ps6[i];
        }
    }
    free(pc6);
    free(ps6);
    free(pos);
    free(pick_chcpp);
    if (st != RL_OK)
        return st;
    printf("\nSec. 7.5: runtime selection (chcpp where polygons in visible objects < %.4g, the %.2f quantile; "
           "else svs)\n", threshold, c->a->select_quantile);
    printf("%-32s %10s %10s %10s\n", "mean frame time (ms)", "chcpp", "svs", "selected");
    printf("%-32s %10.3f %10.3f %10.3f\n", "all positions", sum_c / (double)n, sum_s / (double)n,
           sum_sel / (double)n);
    if (high)
        printf("%-32s %10.3f %10.3f %10.3f  (%zu positions; thesis: svs 7 ms -> 3 ms)\n", "high occlusion",
               hc / (double)high, hs / (double)high, hsel / (double)high, high);
    /* "Beats" is strict: a selection that always picks one renderer only
     * equals it. */
    bool beats = sum_sel < sum_c && sum_sel < sum_s;
    printf("selection beats both on mean time: %s\n", beats ? "yes" : "NO");
    bool tbeats = timed == n && sum_tsel < sum_c && sum_tsel < sum_s;
    if (timed == n) {
        printf("%-32s %10.3f %10.3f %10.3f  (selected by the sampled times: chcpp at %zu of %zu)\n",
               "all positions, by time", sum_c / (double)n, sum_s / (double)n, sum_tsel / (double)n,
               picked_chcpp, n);
        printf("selection by sampled time beats both on mean time: %s\n", tbeats ? "yes" : "NO");
    }
    bool beats6 = six && sum_sel6 < sum_c6 && sum_sel6 < sum_s6;
    if (six) {
        printf("%-32s %10.3f %10.3f %10.3f  (the time property, 6 views of 120 deg, max; by the sampled "
               "times: chcpp at %zu of %zu)\n", "all positions, 6 views, by time", sum_c6 / (double)n,
               sum_s6 / (double)n, sum_sel6 / (double)n, picked_chcpp, n);
        printf("selection by sampled time beats both on the time property: %s\n", beats6 ? "yes" : "NO");
    }
    cJSON_AddNumberToObject(sec, "positions", (double)n);
    bench_add_num(sec, "threshold_visible_polygons", threshold);
    cJSON_AddNumberToObject(sec, "quantile", c->a->select_quantile);
    bench_add_num(sec, "chcpp_mean_ms", sum_c / (double)n);
    bench_add_num(sec, "svs_mean_ms", sum_s / (double)n);
    bench_add_num(sec, "selected_mean_ms", sum_sel / (double)n);
    cJSON_AddNumberToObject(sec, "high_occlusion_positions", (double)high);
    bench_add_num(sec, "high_chcpp_mean_ms", high ? hc / (double)high : NAN);
    bench_add_num(sec, "high_svs_mean_ms", high ? hs / (double)high : NAN);
    bench_add_num(sec, "high_selected_mean_ms", high ? hsel / (double)high : NAN);
    cJSON_AddBoolToObject(sec, "selection_beats_both", beats);
    if (timed == n) {
        bench_add_num(sec, "time_selected_mean_ms", sum_tsel / (double)n);
        cJSON_AddNumberToObject(sec, "time_selected_chcpp", (double)picked_chcpp);
        cJSON_AddBoolToObject(sec, "time_selection_beats_both", tbeats);
    }
    if (six) {
        bench_add_num(sec, "property_chcpp_mean_ms", sum_c6 / (double)n);
        bench_add_num(sec, "property_svs_mean_ms", sum_s6 / (double)n);
        bench_add_num(sec, "property_time_selected_mean_ms", sum_sel6 / (double)n);
        cJSON_AddNumberToObject(sec, "property_time_selected_chcpp", (double)picked_chcpp);
        cJSON_AddBoolToObject(sec, "property_time_selection_beats_both", beats6);
    }
    return RL_OK;
}

/* --- Sec. 7.6 --- */

/* The sets' time and image quality, at positions that are not
 * the samples the sets were taken at. */
static rl_status sec_visset(void *ctx, cJSON *sec)
{
    bc_ctx *c = ctx;
    rl_status st = ensure_driver(c);
    if (st != RL_OK)
        return st;
    /* The sets: with --resume the kept slice itself (on the 4x city with
     * 4096 samples that file holds 7.6 MB), else a copy beside --out. */
    char path[1200], opts[1400], size[32];
    if (c->resume)
        snprintf(path, sizeof path, "%s", bench_resume_path(c->resume, "slice.json"));
    else
        snprintf(path, sizeof path, "%s/culling-visset-approx.json", c->dir);
    if (strchr(path, ',')) {
        snprintf(c->reason, sizeof c->reason, "the path of the sets contains a comma (renderer options cannot hold "
                 "it): %.400s", path);
        return RL_ERR_INVALID_ARG;
    }
    if (!c->resume && (st = rl_approx_save_json(c->driver, path)) != RL_OK)
        return st;
    snprintf(size, sizeof size, "%lld", c->a->size);
    /* The sets' memory: one bit per object for every leaf and every sample. */
    double words = (double)((rl_approx_set_size(c->driver) + 63) / 64);
    double bytes = 8.0 * words * (rl_approx_region_count(c->driver) + rl_approx_sample_count(c->driver));
    long long budget = c->a->budget;
    if (budget <= 0)
        budget = c->chcpp_triangles_mean >= 4 ? (long long)(c->chcpp_triangles_mean / 4) : 10000;
    char budget_opts[1500];
    snprintf(opts, sizeof opts, "approx=%s", path);
    snprintf(budget_opts, sizeof budget_opts, "approx=%s,budget=%lld", path, budget);
    /* Jähn 2015, Sec. 7.6 evaluates the renderer's time and image quality
     * as properties of their own, i.e. away from the samples the sets were
     * taken at: at a sample the set holds all that is visible from there,
     * so the image would be exact by construction. Here: uniform random
     * positions of the slice (their plain mean estimates the area mean),
     * and hierarchical SSIM, the thesis' metric for Fig. 7.11. */
    const uint32_t n = (uint32_t)c->a->visset_positions;
    rl_vec3 *pos = eval_random_positions(c->driver, n, (uint64_t)c->a->seed + 76);
    if (!pos)
        return RL_ERR_OUT_OF_MEMORY;
    const char *const q_kv[] = { "renderer", "visset", "renderer_options", opts, "reference", "raster",
                                 "metric", "hssim", "width", size, "height", size, NULL };
    const char *const qb_kv[] = { "renderer", "visset", "renderer_options", budget_opts, "reference", "raster",
                                  "metric", "hssim", "width", size, "height", size, NULL };
    /* The labels name the positions and the budget, so that a --resume
     * series is continued only by the same measurement (the budget's
     * default depends on whether the svs section ran). */
    char l_t[96], l_q[96], l_bt[128], l_bq[128];
    snprintf(l_t, sizeof l_t, "visset time at %u random positions", n);
    snprintf(l_q, sizeof l_q, "visset quality at %u random positions", n);
    snprintf(l_bt, sizeof l_bt, "visset budget %lld time at %u random positions", budget, n);
    snprintf(l_bq, sizeof l_bq, "visset budget %lld quality at %u random positions", budget, n);
    double *v[4] = { NULL, NULL, NULL, NULL };
    st = measure_at(c, l_t, "time", TIME_KV("visset", opts), pos, n, &v[0]);
    if (st == RL_OK)
        st = measure_at(c, l_q, "quality", q_kv, pos, n, &v[1]);
    if (st == RL_OK)
        st = measure_at(c, l_bt, "time", TIME_KV("visset", budget_opts), pos, n, &v[2]);
    if (st == RL_OK)
        st = measure_at(c, l_bq, "quality", qb_kv, pos, n, &v[3]);
    rl_stats s[4];
    for (int k = 0; k < 4 && st == RL_OK; ++k)
        st = rl_stats_compute(v[k], NULL, n, &s[k]);
    /* "Massive errors at a few positions" (the thesis): how few, and where
     * the worst one is (render it with `rl render --eye`). */
    uint32_t worst = 0, poor = 0;
    double svs_sum = 0.0;
    bool svs_ok = c->time_svs != NULL;
    for (uint32_t i = 0; i < n && st == RL_OK; ++i) {
        if (v[1][i] < v[1][worst])
            worst = i;
        poor += v[1][i] < 0.9;
        double t = 0.0;
        if (svs_ok && rl_approx_query(c->time_svs, pos[i], &t, NULL) == RL_OK)
            svs_sum += t;
        else
            svs_ok = false;
    }
    if (st == RL_OK) {
        printf("\nSec. 7.6: the sampled visible sets as a renderer (%u leaves, %u samples; sets %.2f MB, thesis 31 MB "
               "for 4096 samples), at %u random positions of the slice\n", rl_approx_region_count(c->driver),
               rl_approx_sample_count(c->driver), bytes / 1e6, n);
        printf("%-36s %11s %11s %11s %11s  %s\n", "property", "mean", "min", "median", "max", "thesis");
        table_row("visset time (ms)", &s[0], "max 14 ms");
        table_row("visset hSSIM vs raster", &s[1], "min: massive errors");
        char what[64];
        snprintf(what, sizeof what, "budget %lld: time (ms)", budget);
        table_row(what, &s[2], "-");
        snprintf(what, sizeof what, "budget %lld: hSSIM vs raster", budget);
        table_row(what, &s[3], "-");
        printf("positions with hSSIM < 0.9: %u of %u; the worst (%.4g) at (%.6g, %.6g, %.6g)\n", poor, n,
               v[1][worst], (double)pos[worst].x, (double)pos[worst].y, (double)pos[worst].z);
        if (svs_ok)
            printf("svs' sampled time at the same positions (Sec. 7.4): mean %.4g ms\n", svs_sum / n);
        cJSON_AddNumberToObject(sec, "positions", n);
        bench_add_num(sec, "set_bytes", bytes);
        cJSON_AddNumberToObject(sec, "thesis_set_bytes", 31e6);
        cJSON_AddItemToObject(sec, "time_ms", stats_json(&s[0]));
        cJSON_AddItemToObject(sec, "hssim", stats_json(&s[1]));
        cJSON_AddNumberToObject(sec, "hssim_below_0_9", poor);
        const double w[3] = { pos[worst].x, pos[worst].y, pos[worst].z };
        cJSON_AddItemToObject(sec, "worst_position", cJSON_CreateDoubleArray(w, 3));
        if (svs_ok)
            bench_add_num(sec, "svs_sampled_time_mean_ms", svs_sum / n);
        cJSON_AddNumberToObject(sec, "budget_triangles", (double)budget);
        cJSON_AddItemToObject(sec, "budget_time_ms", stats_json(&s[2]));
        cJSON_AddItemToObject(sec, "budget_hssim", stats_json(&s[3]));
    }
    for (int k = 0; k < 4; ++k)
        free(v[k]);
    free(pos);
    return st;
}

/* --- Sec. 7.4, frame by frame, software and GL --- */

/* Frame k of n down the walk: from the street camera's eye along its view
 * (kept level) for 80 % of the scene's extent that way, the view swinging
 * 20 degrees left and right, at --size pixels. */
static rl_camera walk_camera(const bc_ctx *c, const rl_camera *start, int k, int n)
{
    rl_vec3 dir = rl_sub(start->target, start->eye);
    dir.y = 0.0f;
    dir = rl_length(dir) > 0.0f ? rl_normalize(dir) : rl_v3(0, 0, -1);
    rl_vec3 ext = rl_sub(c->d->bounds.max, c->d->bounds.min);
    float len = 0.8f * (fabsf(dir.x) * ext.x + fabsf(dir.z) * ext.z);
    float t = n > 1 ? (float)k / (float)(n - 1) : 0.0f;
    float yaw = 0.35f * sinf(6.2831853f * 1.5f * t);
    rl_vec3 look = rl_v3(dir.x * cosf(yaw) - dir.z * sinf(yaw), -0.05f, dir.x * sinf(yaw) + dir.z * cosf(yaw));
    rl_camera cam = *start;
    cam.eye = rl_add(start->eye, rl_scale(dir, len * t));
    cam.target = rl_add(cam.eye, look);
    cam.width = cam.height = (int)c->a->size;
    cam.z_near = cam.z_far = 0.0f;
    return cam;
}

/* What one renderer on one drawer did over the walk. */
typedef struct walk_run {
    double *ms;                   /* per frame after the first */
    double first_ms, prep_ms;
    uint64_t triangles, queries, ready, waited, carried, carried_in, filled;
    char device[512];
} walk_run;

/* The rows of the walk: chcpp as CHC++ hides latency (the defaults:
 * V-queue, answers a frame later) and in CHC's order waiting for every
 * answer, then svs. */
typedef struct walk_variant {
    const char *label, *name;
    const char *const *opts;      /* option pairs, NULL-terminated */
} walk_variant;
static const char *const chc_wait_opts[] = { "vqueue", "false", "latency", "wait", NULL };
static const walk_variant walk_variants[] = {
    { "chcpp", "chcpp", NULL },
    { "chcpp-wait", "chcpp", chc_wait_opts },
    { "svs", "svs", NULL },
};
#define NUM_WALK_VARIANTS (sizeof walk_variants / sizeof walk_variants[0])

static rl_status make_walk_renderer(bc_ctx *c, const walk_variant *v, bool gl, rl_renderer **out)
{
    char th[32];
    snprintf(th, sizeof th, "%lld", c->a->threads);
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create(v->name, &r);
    if (st == RL_OK)
        st = rl_renderer_set(r, "threads", th);
    if (st == RL_OK && gl)
        st = rl_renderer_set(r, "drawer", "gl");
    for (const char *const *o = v->opts; st == RL_OK && o && o[0]; o += 2)
        st = rl_renderer_set(r, o[0], o[1]);
    if (st == RL_OK && strcmp(v->name, "svs") == 0 && c->a->quick)
        st = rl_renderer_set(r, "levels", "0");
    if (st == RL_OK && strcmp(v->name, "svs") == 0 && c->a->quick)
        st = rl_renderer_set(r, "resolution", "32");
    if (st != RL_OK)
        rl_renderer_release(r);
    *out = st == RL_OK ? r : NULL;
    return st;
}

/* Every row's renderer on one drawer down the walk, frame by frame in
 * turn, so that the load of a shared machine falls on all of them alike. */
static rl_status walk_drawer(bc_ctx *c, bool gl, const rl_camera *start, walk_run *runs)
{
    const int n = (int)c->a->walk_frames;
    rl_renderer *r[NUM_WALK_VARIANTS] = { NULL };
    rl_image *img = NULL;
    rl_status st = rl_image_create((int)c->a->size, (int)c->a->size, RL_LAYER_COLOR, &img);
    for (size_t i = 0; i < NUM_WALK_VARIANTS && st == RL_OK; ++i)
        st = make_walk_renderer(c, &walk_variants[i], gl, &r[i]);
    for (int k = 0; k < n && st == RL_OK; ++k) {
        rl_camera cam = walk_camera(c, start, k, n);
        for (size_t i = 0; i < NUM_WALK_VARIANTS && st == RL_OK; ++i) {
            walk_run *w = &runs[i];
            rl_render_stats rs;
            st = rl_renderer_render(r[i], c->scene, &cam, img, &rs);
            rl_culling_stats cs;
            if (st == RL_OK)
                st = rl_culling_get_stats(r[i], &cs);
            if (st != RL_OK)
                break;
            if (k == 0) {
                /* The octree, svs' sets, a GL context and the scene's buffers. */
                w->first_ms = rs.time_ms;
                w->prep_ms = rs.prep_ms;
                snprintf(w->device, sizeof w->device, "%s", rs.device ? rs.device : "");
                continue;
            }
            w->ms[k - 1] = rs.time_ms;
            /* The renderer's own count: the drawers count rasterized
             * triangles differently (docs/gl.md). */
            w->triangles += cs.triangles_drawn;
            w->queries += cs.queries;
            w->ready += cs.queries_ready;
            w->waited += cs.queries_waited;
            w->carried += cs.queries_carried;
            w->carried_in += cs.queries_carried_in;
            w->filled += cs.queries_filled;
        }
    }
    rl_image_release(img);
    for (size_t i = 0; i < NUM_WALK_VARIANTS; ++i)
        rl_renderer_release(r[i]);
    return st;
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static rl_status sec_walk(void *ctx, cJSON *sec)
{
    bc_ctx *c = ctx;
    const int n = (int)c->a->walk_frames, m = n - 1;
    rl_camera start;
    if (rl_scene_get_camera(c->scene, "street", &start) != RL_OK &&
        rl_scene_get_camera(c->scene, NULL, &start) != RL_OK)
        return RL_ERR_NOT_FOUND;
    bool drawers[2] = { c->a->drawer != DRAWER_GL, c->a->drawer != DRAWER_SOFTWARE };
    char why[256] = "";
    if (drawers[1] && !rl_gl_available(NULL, why, sizeof why)) {
        if (c->a->drawer == DRAWER_GL) {
            snprintf(c->reason, sizeof c->reason, "--drawer gl: no GL 4.5 context: %s", why);
            return RL_ERR_UNSUPPORTED;
        }
        note("no GL 4.5 context (%s): the walk runs on the software drawer only", why);
        cJSON_AddStringToObject(sec, "gl_unavailable", why);
        drawers[1] = false;
    }
    printf("\nSec. 7.4 per frame: chcpp and svs down a walk of %d frames at %lldx%lld (the first frame, with "
           "its preparation, apart)\n", n, c->a->size, c->a->size);
    printf("%-10s %-8s %9s %9s %9s %9s %11s %9s %8s %8s %8s %8s\n", "renderer", "drawer", "mean ms", "min", "median",
           "first", "triangles", "queries", "ready", "waited", "carried", "filled");
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    cJSON_AddNumberToObject(sec, "frames", n);
    cJSON_AddNumberToObject(sec, "size", (double)c->a->size);
    double mean[2][NUM_WALK_VARIANTS] = { { 0 } };
    rl_status st = RL_OK;
    for (int g = 0; g < 2 && st == RL_OK; ++g) {
        if (!drawers[g])
            continue;
        walk_run runs[NUM_WALK_VARIANTS] = { { 0 } };
        for (size_t i = 0; i < NUM_WALK_VARIANTS && st == RL_OK; ++i)
            if (!(runs[i].ms = calloc((size_t)m, sizeof *runs[i].ms)))
                st = RL_ERR_OUT_OF_MEMORY;
        if (st == RL_OK)
            st = walk_drawer(c, g == 1, &start, runs);
        for (size_t i = 0; i < NUM_WALK_VARIANTS; ++i) {
            const walk_variant *v = &walk_variants[i];
            walk_run w = runs[i];
            if (st == RL_OK) {
                double sum = 0.0;
                for (int k = 0; k < m; ++k)
                    sum += w.ms[k];
                qsort(w.ms, (size_t)m, sizeof *w.ms, cmp_double);
                mean[g][i] = sum / m;
                const double per = 1.0 / m;
                printf("%-10s %-8s %9.2f %9.2f %9.2f %9.1f %11.0f %9.1f %8.1f %8.1f %8.1f %8.1f\n", v->label,
                       g ? "gl" : "software", mean[g][i], w.ms[0], w.ms[m / 2], w.first_ms, (double)w.triangles * per,
                       (double)w.queries * per, (double)w.ready * per, (double)w.waited * per,
                       (double)w.carried * per, (double)w.filled * per);
                cJSON *o = cJSON_CreateObject();
                cJSON_AddStringToObject(o, "renderer", v->name);
                cJSON_AddStringToObject(o, "drawer", g ? "gl" : "software");
                if (strcmp(v->name, "chcpp") == 0) {
                    cJSON_AddStringToObject(o, "latency", v->opts ? "wait" : "frame");
                    cJSON_AddBoolToObject(o, "vqueue", v->opts == NULL);
                }
                if (w.device[0])
                    cJSON_AddStringToObject(o, "gl_device", w.device);
                bench_add_num(o, "mean_ms", mean[g][i]);
                bench_add_num(o, "min_ms", w.ms[0]);
                bench_add_num(o, "median_ms", w.ms[m / 2]);
                bench_add_num(o, "max_ms", w.ms[m - 1]);
                bench_add_num(o, "first_frame_ms", w.first_ms);
                bench_add_num(o, "first_frame_prep_ms", w.prep_ms);
                bench_add_num(o, "triangles_mean", (double)w.triangles * per);
                bench_add_num(o, "queries_mean", (double)w.queries * per);
                bench_add_num(o, "queries_ready_mean", (double)w.ready * per);
                bench_add_num(o, "queries_waited_mean", (double)w.waited * per);
                bench_add_num(o, "queries_carried_mean", (double)w.carried * per);
                bench_add_num(o, "queries_carried_in_mean", (double)w.carried_in * per);
                bench_add_num(o, "queries_filled_mean", (double)w.filled * per);
                cJSON_AddItemToArray(rows, o);
                if (w.device[0] && !cJSON_GetObjectItem(sec, "gl_device"))
                    cJSON_AddStringToObject(sec, "gl_device", w.device);
            }
            free(w.ms);
        }
        if (st == RL_OK && mean[g][0] > 0.0) {
            printf("svs / chcpp (%s): %.2fx (thesis, Power Plant on a GPU: 18 / 55 ms = 0.33x); chcpp, latency=wait "
                   "in CHC's order / latency=frame: %.2fx\n", g ? "gl" : "software", mean[g][2] / mean[g][0],
                   mean[g][1] / mean[g][0]);
            bench_add_num(sec, g ? "svs_over_chcpp_gl" : "svs_over_chcpp_software", mean[g][2] / mean[g][0]);
            bench_add_num(sec, g ? "chcpp_wait_over_frame_gl" : "chcpp_wait_over_frame_software",
                          mean[g][1] / mean[g][0]);
        }
    }
    cJSON_AddNumberToObject(sec, "thesis_svs_over_chcpp", 18.0 / 55.0);
    return st;
}

static bool take_drawer(void *a, const char *v)
{
    for (int i = 0; i < 3; ++i)
        if (strcmp(v, drawer_names[i]) == 0) {
            ((bc_args *)a)->drawer = i;
            return true;
        }
    cli_fail(RL_CLI_USAGE, "--drawer: expected software, gl or both, got '%s'", v);
    return false;
}

/* --max-depth: 0 is a valid depth, so not a count. */
static bool take_max_depth(void *a, const char *v)
{
    char *end = NULL;
    long long d = strtoll(v, &end, 10);
    if (!*v || *end || d < 0 || d > RL_OCTREE_MAX_DEPTH) {
        cli_fail(RL_CLI_USAGE, "--max-depth: expected 0..%d, got '%s'", RL_OCTREE_MAX_DEPTH, v);
        return false;
    }
    ((bc_args *)a)->max_depth = d;
    return true;
}

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bc_args *a)
{
    /* The walk only when asked for: it wants a GL context and a GPU. */
    a->sections = ((1u << SEC_COUNT) - 1) & ~(1u << SEC_WALK);
    a->drawer = DRAWER_BOTH;
    a->seed = 1;
    a->select_quantile = 0.25;
    a->height = 10.0;
    a->extent = 1.0;
    bool has_samples = false, has_depth = false, has_size = false, has_res = false, has_sel = false;
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_COUNT("--samples", 1 << 20, &a->samples, &has_samples),
        RL_BENCH_COUNT("--size", 4096, &a->size, &has_size),
        RL_BENCH_COUNT("--resolution", 4096, &a->resolution, &has_res),
        RL_BENCH_COUNT("--select-positions", 1 << 20, &a->select_positions, &has_sel),
        RL_BENCH_COUNT("--visset-positions", 1 << 20, &a->visset_positions, NULL),
        RL_BENCH_COUNT("--budget", 1LL << 40, &a->budget, NULL),
        RL_BENCH_COUNT("--surfels", 1 << 24, &a->surfels, NULL),
        RL_BENCH_COUNT("--threads", 1024, &a->threads, NULL),
        RL_BENCH_COUNT("--seed", 1LL << 62, &a->seed, NULL),
        RL_BENCH_CUSTOM("--max-depth", take_max_depth, a, &has_depth),
        RL_BENCH_COUNT("--walk-frames", 1 << 20, &a->walk_frames, NULL),
        RL_BENCH_CUSTOM("--drawer", take_drawer, a, NULL),
        RL_BENCH_REAL("--height", -1e6, 1e6, &a->height, NULL),
        RL_BENCH_REAL("--extent", 0.01, 100.0, &a->extent, NULL),
        RL_BENCH_REAL("--select-quantile", 1e-6, 1.0 - 1e-6, &a->select_quantile, NULL),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_STRING("--scene", &a->scene),
        RL_BENCH_STRING("--resume", &a->resume),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench culling", bench_culling_help, rows,
                                 (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    if (!a->scene)
        a->scene = a->quick ? "city:blocks=1" : "city";
    if (!has_samples)
        a->samples = a->quick ? 6 : 96;
    if (!has_depth)
        a->max_depth = a->quick ? 2 : 8;
    if (!has_size)
        a->size = a->quick ? 32 : 128;
    if (!has_res)
        a->resolution = a->quick ? 32 : 128;
    if (!has_sel)
        a->select_positions = a->quick ? 4 : 100;
    if (!a->surfels)
        a->surfels = a->quick ? 1000 : 40000;
    if (!a->visset_positions)
        a->visset_positions = a->quick ? 4 : a->samples;
    if (!a->walk_frames)
        a->walk_frames = a->quick ? 4 : 40;
    if (a->walk_frames < 2)
        return cli_fail(RL_CLI_USAGE, "--walk-frames: at least 2 (the first is timed apart)");
    return RL_CLI_OK;
}

int bench_culling(int argc, char **argv)
{
    bc_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    char out[1024];               /* its folder goes to c.dir, of this size */
    if (!bench_out_path(a.out, "culling", out, sizeof out))
        return RL_CLI_FAIL;
    bc_ctx c = { .a = &a, .frames = a.quick ? "1" : "3" };
    snprintf(c.dir, sizeof c.dir, "%s", out);
    char *slash = strrchr(c.dir, '/');
    if (slash)
        *slash = '\0';
    else
        snprintf(c.dir, sizeof c.dir, ".");
    if ((rc = cli_load_scene(a.scene, &c.scene)) != RL_CLI_OK)
        return rc;
    c.d = rl_scene_get_data(c.scene);
    int threads = a.threads > 0 ? (int)a.threads : omp_get_max_threads();
    if (!cli_dist_master()) {
        /* --dist: a sampling node, measuring whatever property the master
         * samples next; the master runs the sections, prints and writes. */
        rc = cli_dist_serve(c.scene, threads);
        rl_scene_release(c.scene);
        return rc;
    }
    if (a.resume) {
        /* Everything that changes the slice or a value measured on it. */
        char key[1024];
        snprintf(key, sizeof key,
                 "rl bench culling: scene=%s samples=%lld size=%lld resolution=%lld height=%.17g extent=%.17g "
                 "seed=%lld budget=%lld threads=%d quick=%d\n",
                 a.scene, a.samples, a.size, a.resolution, a.height, a.extent, a.seed, a.budget, threads,
                 (int)a.quick);
        if (!bench_resume_open(a.resume, key, &c.resume)) {
            rl_scene_release(c.scene);
            return RL_CLI_FAIL;
        }
    }
    cJSON *root = bench_record_json("culling", threads);
    if (!root) {
        rl_scene_release(c.scene);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    cJSON *params = cJSON_AddObjectToObject(root, "parameters");
    cJSON_AddStringToObject(params, "scene", a.scene);
    cJSON_AddItemToObject(params, "scene_stats", cli_scene_stats_json(c.scene));
    cJSON_AddNumberToObject(params, "samples", (double)a.samples);
    cJSON_AddNumberToObject(params, "max_depth", (double)a.max_depth);
    cJSON_AddNumberToObject(params, "size", (double)a.size);
    cJSON_AddNumberToObject(params, "height", a.height);
    cJSON_AddNumberToObject(params, "extent", a.extent);
    cJSON_AddNumberToObject(params, "resolution", (double)a.resolution);
    cJSON_AddNumberToObject(params, "select_positions", (double)a.select_positions);
    cJSON_AddNumberToObject(params, "select_quantile", a.select_quantile);
    cJSON_AddNumberToObject(params, "visset_positions", (double)a.visset_positions);
    cJSON_AddNumberToObject(params, "seed", (double)a.seed);
    cJSON_AddBoolToObject(params, "quick", a.quick);
    cJSON_AddNumberToObject(params, "surfels", (double)a.surfels);
    cJSON_AddNumberToObject(params, "walk_frames", (double)a.walk_frames);
    cJSON_AddStringToObject(params, "drawer", drawer_names[a.drawer]);
    static const bench_section_fn fns[SEC_COUNT] = { sec_surfels, sec_depth, sec_svs, sec_select, sec_visset,
                                                     sec_walk };
    if (cli_dist_ranks() > 1) {
        /* Under --dist: the sampled and measured values come from every
         * rank (times from each rank's own machine); the rest is the
         * master's. */
        cJSON *dist = cJSON_AddObjectToObject(root, "dist");
        if (dist)
            cJSON_AddNumberToObject(dist, "ranks", cli_dist_ranks());
    }
    cli_dist_service_begin();
    rc = bench_run_sections("culling", root, section_names, fns, SEC_COUNT, a.sections, &c, c.reason, threads,
                               out);
    rc = cli_dist_service_end(rc);
    cJSON_Delete(root);
    rl_approx_release(c.driver);
    rl_approx_release(c.time_chcpp);
    rl_approx_release(c.time_svs);
    free(c.pos);
    bench_resume_close(c.resume);
    rl_scene_release(c.scene);
    return rc;
}
