/* bench_sampling.c: `rl bench sampling`: the sampling experiments of Jähn
 * 2015, Sec. 5.7, on the visibility property (visible objects, 6 cube
 * faces), as tables on stdout and one JSON record:
 *   variants     Fig. 5.5: 2-D and 3-D, a tight region (the scene's bounds)
 *                and one of doubled side length, 256/1024/4096 samples, the
 *                grid (Alg. 5.2) and adaptive sampling (Alg. 5.3) with
 *                random, blue-noise and blue-noise-with-corners positions;
 *                absolute error at 2000 uniform random validation points,
 *                measured once per region and shared by all variants. The
 *                target: adaptive (blue noise, our default) no worse than
 *                the grid in mean error in every case, the grid answering
 *                queries as the thesis does (its cell's sample) or our way
 *                (inverse distance weighting), whichever is better. Beside
 *                the thesis' grid (cell centres) a shifted grid (one random
 *                offset for all cells): on a regular scene like `city` the
 *                centred lattice's alignment with the streets moves its
 *                error by up to 40 % between neighbouring sample counts.
 *                --repeats R runs the shifted grid and the two blue-noise
 *                variants with seeds 1..R and compares means over the seeds.
 *   convergence  Table 5.1: quantiles and mean of the area/volume-weighted
 *                approximation against the sample count (100 ... 3200),
 *                3-D tight region, blue noise with corners.
 *   throughput   samples/s of the visibility property at the bench's and
 *                the thesis' resolution (1024), for 1 .. all workers.
 *
 * Regions: tight = the scene's bounds (2-D: their x/z extent, the slice at
 * --height); doubled = twice the side lengths around the same centre in x
 * and z, and in y from the ground up (below the ground there is nothing to
 * look at). */
#define _POSIX_C_SOURCE 200809L
#include "bench_sampling.h"

#include "bench_args.h"
#include "bench_rays.h"
#include "bench_util.h"
#include "cli.h"
#include "eval_common.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

/* The tables go to stdout, notes to stderr: flush so they do not interleave. */
#define note(...) (fflush(stdout), bench_note("sampling", __VA_ARGS__))

static const char bench_sampling_help[] =
    "usage: rl bench sampling [options]\n"
    "\n"
    "Measures the global approximation of the visibility property (visible\n"
    "objects over 6 cube faces) as in Jaehn 2015, Sec. 5.7. Sections:\n"
    "  variants      2-D/3-D x tight/doubled region x 256/1024/4096 samples x\n"
    "                grid (cell centres, queries by the cell's sample: the thesis),\n"
    "                grid-idw (the same samples, our idw queries), grid~ (one\n"
    "                random offset for all cells), adaptive random, blue noise\n"
    "                (the target), blue noise with corners (our defaults: idw\n"
    "                queries, density-over-range splits), and blue noise with\n"
    "                corners as in the thesis (region-value queries, diameter in\n"
    "                q: bnc-region): absolute error at 2000 random validation\n"
    "                points (Fig. 5.5)\n"
    "  convergence   quantiles and mean against the sample count, 100..3200\n"
    "                (Table 5.1), 3-D tight region\n"
    "  throughput    visibility samples/s and scaling with workers\n"
    "\n"
    "options:\n"
    "  --scene S         default city:blocks=3 (see rl scenes)\n"
    "  --resolution N    cube-face resolution of the property; default 256\n"
    "                    (the thesis: 1024, see the throughput section)\n"
    "  --visibility-backend B  software (default) or gl: the property drawn by\n"
    "                    OpenGL and counted on the GPU (docs/gl.md)\n"
    "  --height H        2-D slice height above the scene's floor; default 1.7 m\n"
    "  --samples A,B,..  sample counts of the variants section; default 256,1024,4096\n"
    "  --validation N    random validation points per region; default 2000\n"
    "  --repeats R       grid~, bn and bn-corners with seeds 1..R, errors averaged\n"
    "                    over the seeds (the other variants: seed 1); default 1\n"
    "  --quality-size Q  measure (default) or diameter (the thesis): the size in\n"
    "                    q = n / (size * range) of the adaptive variants other\n"
    "                    than bnc-region (always the thesis')\n"
    "  --samples-base B, --samples-per-meter M\n"
    "                    samples of a new region, B + M * diameter, of the adaptive\n"
    "                    variants other than bnc-region; default 5 and 0.05/m\n"
    "                    (the thesis, Sec. 5.4.2)\n"
    "  --threads N       workers; default all\n"
    "  --only A,B        sections: variants, convergence, throughput (under\n"
    "                    rl --dist: variants and convergence; docs/distributed.md)\n"
    "  --out FILE.json   default bench/results/sampling-YYYYMMDD-HHMMSS.json\n"
    "  --quick           tiny run (cornell, resolution 32, 16/48 samples,\n"
    "                    64 validation points): a smoke test\n"
    "\n"
    "example:\n"
    "  rl bench sampling --only variants --samples 256,1024 --resolution 128\n";

enum { SEC_VARIANTS, SEC_CONVERGENCE, SEC_THROUGHPUT, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "variants", "convergence", "throughput" };

#define MAX_COUNTS 8
#define NUM_VARIANTS 7
#define V_GRID 0          /* the thesis' grid: cell centres, nearest-sample (cell) queries */
#define V_GRID_IDW 1      /* the same approximation with our default queries */
#define V_SHIFTED 2
#define V_BN 4
#define V_BNC 5
#define V_TARGET V_BN     /* our default adaptive sampler */

typedef struct bs_args {
    const char *scene, *out;
    long long resolution, validation, threads, repeats;
    const char *backend;          /* --visibility-backend: the property's backend option */
    double height;
    rl_quality_size quality_size;     /* of the adaptive variants but bnc-region */
    double samples_base, samples_per_meter;   /* the same; 0: the defaults (Sec. 5.4.2) */
    long long counts[MAX_COUNTS];
    int num_counts;
    unsigned sections;
    bool quick;
} bs_args;

typedef struct bs_ctx {
    bs_args *a;
    rl_scene *scene;
    rl_property *vis;
    rl_aabb bounds;
    char reason[512];
} bs_ctx;

/* Variant k: 0 the grid (cell centres, Alg. 5.2) answering queries with
 * the cell's sample as the thesis does, 1 the same approximation answering
 * with our default queries (inverse distance weighting of the 4 nearest
 * samples), 2 the grid shifted by one random offset, then adaptive with
 * random, blue noise (the target: our default), blue noise with corners
 * (2-6 with our defaults: idw queries, regions chosen by density over
 * range), and last blue noise with corners as the thesis has it: the
 * region's value answers queries, q uses the diameter (rl_sampling.h: the
 * deviations). */
static const char *const variant_names[NUM_VARIANTS] = { "grid", "grid-idw", "grid~", "random", "bn",
                                                         "bn-corners", "bnc-region" };

static void variant_desc(const bs_args *a, int k, rl_sampling_desc *d)
{
    bool thesis = k == NUM_VARIANTS - 1;
    d->method = k <= V_SHIFTED ? RL_SAMPLING_GRID : RL_SAMPLING_ADAPTIVE;
    d->grid_shift = k == V_SHIFTED;
    d->positions = k == 3 ? RL_POSITIONS_RANDOM
                 : k == V_BN ? RL_POSITIONS_BLUE_NOISE : RL_POSITIONS_BLUE_NOISE_CORNERS;
    d->interpolation = thesis ? RL_INTERP_REGION : k == V_GRID ? RL_INTERP_NEAREST : RL_INTERP_IDW;
    d->quality_size = thesis ? RL_QUALITY_DIAMETER : a->quality_size;
    d->samples_base = thesis ? 0.0f : (float)a->samples_base;
    d->samples_per_meter = thesis ? 0.0f : (float)a->samples_per_meter;
}

/* Seeds of variant k: 1..repeats for the shifted grid and the two
 * blue-noise variants, else seed 1 (the centred grid has no randomness). */
static int variant_seeds(const bs_args *a, int k)
{
    return k == V_SHIFTED || k == V_BN || k == V_BNC ? (int)a->repeats : 1;
}

static rl_aabb region_of(const bs_ctx *c, bool doubled)
{
    rl_aabb b = c->bounds;
    if (!doubled)
        return b;
    float cx = 0.5f * (b.min.x + b.max.x), cz = 0.5f * (b.min.z + b.max.z);
    float ex = b.max.x - b.min.x, ey = b.max.y - b.min.y, ez = b.max.z - b.min.z;
    return (rl_aabb){ { cx - ex, b.min.y, cz - ez }, { cx + ex, b.min.y + 2.0f * ey, cz + ez } };
}

static rl_sampling_desc base_desc(const bs_ctx *c, int dims, bool doubled)
{
    rl_sampling_desc d = { 0 };
    d.region = region_of(c, doubled);
    d.dims = dims;
    d.height = c->bounds.min.y + (float)c->a->height;
    float ex = d.region.max.x - d.region.min.x, ez = d.region.max.z - d.region.min.z;
    float ey = dims == 3 ? d.region.max.y - d.region.min.y : 0.0f;
    d.min_side = fminf(1.0f, fmaxf(ex, fmaxf(ey, ez)) / 64.0f);
    d.seed = 1;
    d.workers = (int)c->a->threads;
    d.quality_size = c->a->quality_size;
    d.samples_base = (float)c->a->samples_base;
    d.samples_per_meter = (float)c->a->samples_per_meter;
    return d;
}

/* Mean/median/q75/max of |approx - measured| at the validation points. */
static rl_status errors(const rl_approx *ap, const rl_vec3 *pos, const double *measured, size_t n,
                        rl_stats *out)
{
    double *e = malloc(n * sizeof *e);
    if (!e)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st = eval_errors(ap, pos, measured, n, NULL, e);
    if (st == RL_OK)
        st = rl_stats_compute(e, NULL, n, out);
    free(e);
    return st;
}

/* The validation values: under --dist measured on every rank (the
 * sampling nodes of Jähn 2015, Alg. 5.4, for positions chosen beforehand). */
static rl_status measure_validation(rl_property *vis, const rl_vec3 *pos, size_t n, double **values)
{
    if (cli_dist_ranks() == 1)
        return eval_measure(vis, pos, n, values, NULL);
    double *v = malloc((n ? n : 1) * sizeof *v);
    rl_status st = cli_measure_call(v ? vis : NULL, pos, n, v);
    if (st != RL_OK || !v) {
        free(v);
        return v ? st : RL_ERR_OUT_OF_MEMORY;
    }
    *values = v;
    return RL_OK;
}

/* A sampling node under --dist: the collective calls of sec_variants and
 * sec_convergence in their order, every position measured for the control
 * node, which keeps the approximations, computes and writes. A failure on
 * the control node reaches every node through the call it was in (or the
 * job ends with the control node's error). */
static rl_status serve_sections(const bs_ctx *c)
{
    const bs_args *a = c->a;
    rl_status st = RL_OK;
    if (a->sections & (1u << SEC_VARIANTS))
        for (int r = 0; r < 4 && st == RL_OK; r++) {
            rl_sampling_desc d = base_desc(c, 2 + r / 2, r % 2);
            if ((st = cli_measure_call(c->vis, NULL, 0, NULL)) != RL_OK)
                break;
            for (int ci = 0; ci < a->num_counts && st == RL_OK; ci++)
                for (int k = 0; k < NUM_VARIANTS && st == RL_OK; k++)
                    for (int seed = 1; k != V_GRID_IDW && seed <= variant_seeds(a, k) && st == RL_OK; seed++) {
                        rl_approx *none = NULL;
                        st = cli_sample_call(c->vis, &d, &none);
                    }
        }
    if (a->sections & (1u << SEC_CONVERGENCE))
        for (int i = 0; i < (a->quick ? 3 : 6) && st == RL_OK; i++) {
            rl_sampling_desc d = base_desc(c, 3, false);
            rl_approx *none = NULL;
            st = cli_sample_call(c->vis, &d, &none);
        }
    return st;
}

static rl_status sec_variants(void *ctx, cJSON *sec)
{
    bs_ctx *c = ctx;
    cJSON *cases = cJSON_AddArrayToObject(sec, "cases");
    int met = 0, met_thesis_grid = 0, met_shifted = 0, total = 0;
    printf("\nvariants (Jaehn 2015, Fig. 5.5): mean |error| in visible objects at %lld random "
           "points", c->a->validation);
    if (c->a->repeats > 1)
        printf("; grid~, bn and bn-corners: mean over seeds 1..%lld", c->a->repeats);
    printf("\n%-4s %-8s %7s", "dims", "region", "samples");
    for (int k = 0; k < NUM_VARIANTS; k++)
        printf(" %11s", variant_names[k]);
    printf("  bn<=grid (best query)  over grid  over grid~\n");
    for (int dims = 2; dims <= 3; dims++) {
        for (int doubled = 0; doubled <= 1; doubled++) {
            rl_sampling_desc d = base_desc(c, dims, doubled);
            /* The validation values are the property itself at random
             * positions: measured once, shared by every variant. */
            rl_approx *shape = NULL;
            rl_sampling_desc probe = d;
            probe.max_samples = 1;
            probe.method = RL_SAMPLING_GRID;
            rl_status st = rl_sample_property(c->vis, &probe, &shape);
            if (st != RL_OK)
                return st;
            size_t nv = (size_t)c->a->validation;
            rl_vec3 *pos = eval_random_positions(shape, nv, 0xba5eULL + (uint64_t)(dims * 2 + doubled));
            rl_approx_release(shape);
            double *measured = NULL;
            if (!pos)
                return RL_ERR_OUT_OF_MEMORY;
            note("%dD %s region: measuring %zu validation points", dims,
                 doubled ? "doubled" : "tight", nv);
            st = measure_validation(c->vis, pos, nv, &measured);
            if (st != RL_OK) {
                free(pos);
                return st;
            }
            for (int ci = 0; ci < c->a->num_counts && st == RL_OK; ci++) {
                cJSON *o = cJSON_CreateObject();
                cJSON_AddItemToArray(cases, o);
                cJSON_AddNumberToObject(o, "dims", dims);
                cJSON_AddStringToObject(o, "region", doubled ? "doubled" : "tight");
                cJSON_AddNumberToObject(o, "samples", (double)c->a->counts[ci]);
                printf("%-4d %-8s %7lld", dims, doubled ? "doubled" : "tight", c->a->counts[ci]);
                double mean_err[NUM_VARIANTS], grid_secs = 0.0;
                rl_approx *grid_ap = NULL;
                for (int k = 0; k < NUM_VARIANTS && st == RL_OK; k++) {
                    cJSON *v = cJSON_AddObjectToObject(o, variant_names[k]);
                    cJSON *per_seed = cJSON_AddArrayToObject(v, "mean_abs_error_per_seed");
                    int seeds = variant_seeds(c->a, k);
                    mean_err[k] = 0.0;
                    for (int seed = 1; seed <= seeds && st == RL_OK; seed++) {
                        rl_sampling_desc dk = d;
                        variant_desc(c->a, k, &dk);
                        dk.max_samples = (uint32_t)c->a->counts[ci];
                        dk.seed = (uint64_t)seed;
                        rl_approx *ap = NULL;
                        double t0 = rl_time_s();
                        if (k == V_GRID_IDW) {
                            /* The grid's own samples, queried our way. */
                            ap = grid_ap;
                            grid_ap = NULL;
                            st = rl_approx_set_interpolation(ap, RL_INTERP_IDW, 0);
                        } else {
                            st = cli_sample_call(c->vis, &dk, &ap);
                        }
                        double secs = k == V_GRID_IDW ? grid_secs : rl_time_s() - t0;
                        rl_stats es;
                        if (st == RL_OK)
                            st = errors(ap, pos, measured, nv, &es);
                        if (st == RL_OK) {
                            /* Seed 1's details, as in records without repeats. */
                            if (seed == 1) {
                                cJSON_AddNumberToObject(v, "samples_taken", rl_approx_sample_count(ap));
                                cJSON_AddNumberToObject(v, "regions", rl_approx_region_count(ap));
                                bench_add_num(v, "seconds", secs);
                                cJSON_AddItemToObject(v, "abs_error", eval_stats_json(&es));
                            }
                            cJSON_AddItemToArray(per_seed, cJSON_CreateNumber(es.mean));
                            mean_err[k] += es.mean / seeds;
                        }
                        if (k == V_GRID && st == RL_OK) {
                            grid_ap = ap;          /* for V_GRID_IDW */
                            grid_secs = secs;
                        } else {
                            rl_approx_release(ap);
                        }
                    }
                    if (st == RL_OK) {
                        bench_add_num(v, "mean_abs_error", mean_err[k]);
                        printf(" %11.3f", mean_err[k]);
                        fflush(stdout);
                    }
                }
                rl_approx_release(grid_ap);
                if (st != RL_OK)
                    break;
                /* The target: no worse than the grid with either query. */
                double grid_best = fmin(mean_err[V_GRID], mean_err[V_GRID_IDW]);
                bool ok = mean_err[V_TARGET] <= grid_best;
                met += ok;
                met_thesis_grid += mean_err[V_TARGET] <= mean_err[V_GRID];
                met_shifted += mean_err[V_TARGET] <= mean_err[V_SHIFTED];
                total++;
                cJSON_AddBoolToObject(o, "adaptive_no_worse_than_grid", ok);
                bench_add_num(o, "adaptive_over_grid", bench_ratio(mean_err[V_TARGET], grid_best));
                cJSON_AddBoolToObject(o, "adaptive_no_worse_than_thesis_grid",
                                      mean_err[V_TARGET] <= mean_err[V_GRID]);
                bench_add_num(o, "adaptive_over_thesis_grid",
                                 bench_ratio(mean_err[V_TARGET], mean_err[V_GRID]));
                cJSON_AddBoolToObject(o, "adaptive_no_worse_than_shifted_grid",
                                      mean_err[V_TARGET] <= mean_err[V_SHIFTED]);
                bench_add_num(o, "adaptive_over_shifted_grid",
                                 bench_ratio(mean_err[V_TARGET], mean_err[V_SHIFTED]));
                printf("  %s (%.2fx) %9.2fx %10.2fx\n", ok ? "yes" : "NO", bench_ratio(mean_err[V_TARGET], grid_best),
                       bench_ratio(mean_err[V_TARGET], mean_err[V_GRID]),
                       bench_ratio(mean_err[V_TARGET], mean_err[V_SHIFTED]));
            }
            free(pos);
            free(measured);
            if (st != RL_OK)
                return st;
        }
    }
    cJSON_AddNumberToObject(sec, "cases_met", met);
    cJSON_AddNumberToObject(sec, "cases_met_thesis_grid", met_thesis_grid);
    cJSON_AddNumberToObject(sec, "cases_met_shifted_grid", met_shifted);
    cJSON_AddNumberToObject(sec, "cases_total", total);
    printf("target adaptive (bn, our default) mean error <= the grid's with either query: met in %d of %d "
           "cases (<= the thesis' grid: %d, <= the shifted grid: %d)\n", met, total, met_thesis_grid,
           met_shifted);
    return RL_OK;
}

static rl_status sec_convergence(void *ctx, cJSON *sec)
{
    bs_ctx *c = ctx;
    static const long long full[] = { 100, 200, 400, 800, 1600, 3200 };
    static const long long quick[] = { 16, 32, 64 };
    const long long *counts = c->a->quick ? quick : full;
    int n = c->a->quick ? 3 : 6;
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    printf("\nconvergence (Jaehn 2015, Table 5.1): visible objects, 3-D tight region, bn-corners\n"
           "%7s %9s %9s %9s %9s %9s %9s\n", "samples", "min", "q25", "median", "q75", "max", "mean");
    for (int i = 0; i < n; i++) {
        rl_sampling_desc d = base_desc(c, 3, false);
        /* Region values, the thesis' statistics: with its corners. */
        d.positions = RL_POSITIONS_BLUE_NOISE_CORNERS;
        d.max_samples = (uint32_t)counts[i];
        rl_approx *ap = NULL;
        rl_status st = cli_sample_call(c->vis, &d, &ap);
        double *v = NULL, *w = NULL;
        size_t m = 0;
        rl_stats s;
        if (st == RL_OK && !eval_leaf_series(ap, &v, &w, &m))
            st = RL_ERR_OUT_OF_MEMORY;
        if (st == RL_OK)
            st = rl_stats_compute(v, w, m, &s);
        free(v);
        free(w);
        if (st == RL_OK) {
            cJSON *o = eval_stats_json(&s);
            cJSON_AddNumberToObject(o, "samples", (double)counts[i]);
            cJSON_AddNumberToObject(o, "regions", rl_approx_region_count(ap));
            cJSON_AddItemToArray(rows, o);
            printf("%7lld %9.2f %9.2f %9.2f %9.2f %9.2f %9.2f\n", counts[i], s.min, s.q[1], s.q[2],
                   s.q[3], s.max, s.mean);
        }
        rl_approx_release(ap);
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

static rl_status sec_throughput(void *ctx, cJSON *sec)
{
    bs_ctx *c = ctx;
    long long resolutions[2] = { c->a->resolution, c->a->quick ? 64 : 1024 };
    int nres = resolutions[0] == resolutions[1] ? 1 : 2;
    int max_workers = c->a->threads > 0 ? (int)c->a->threads : omp_get_max_threads();
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    printf("\nthroughput: visibility samples/s (6 faces)\n%10s %8s %10s %8s\n", "resolution",
           "workers", "samples/s", "speedup");
    for (int r = 0; r < nres; r++) {
        double base = 0.0;
        for (int w = 1; w <= max_workers; w = w < max_workers && 2 * w > max_workers ? max_workers : 2 * w) {
            rl_property *p = NULL;
            char num[32];
            snprintf(num, sizeof num, "%lld", resolutions[r]);
            rl_status st = rl_property_create("visibility", &p);
            if (st == RL_OK)
                st = rl_property_set(p, "resolution", num);
            if (st == RL_OK)
                st = rl_property_set(p, "backend", c->a->backend);
            if (st == RL_OK)
                st = rl_property_commit(p, c->scene, w);
            /* Enough positions for about a second of work at the first
             * measured rate; at least 4 per worker. */
            size_t n = (size_t)(c->a->quick ? 8 : (resolutions[r] >= 1024 ? 16 : 64)) * (size_t)w;
            rl_sampling_desc d = base_desc(c, 2, false);
            d.max_samples = 1;
            d.method = RL_SAMPLING_GRID;
            rl_approx *shape = NULL;
            if (st == RL_OK)
                st = rl_sample_property(p, &d, &shape);
            rl_vec3 *pos = st == RL_OK ? eval_random_positions(shape, n, 77) : NULL;
            double *vals = NULL;
            double t0 = rl_time_s();
            if (st == RL_OK)
                st = pos ? eval_measure(p, pos, n, &vals, NULL) : RL_ERR_OUT_OF_MEMORY;
            double secs = rl_time_s() - t0;
            free(vals);
            free(pos);
            rl_approx_release(shape);
            rl_property_release(p);
            if (st != RL_OK)
                return st;
            double rate = (double)n / secs;
            if (w == 1)
                base = rate;
            cJSON *o = cJSON_CreateObject();
            cJSON_AddNumberToObject(o, "resolution", (double)resolutions[r]);
            cJSON_AddNumberToObject(o, "workers", w);
            bench_add_num(o, "samples_per_second", rate);
            bench_add_num(o, "speedup", bench_ratio(rate, base));
            cJSON_AddItemToArray(rows, o);
            printf("%10lld %8d %10.2f %8.2f\n", resolutions[r], w, rate, bench_ratio(rate, base));
            if (w == max_workers)
                break;
        }
    }
    return RL_OK;
}

static bool parse_counts(const char *text, bs_args *a)
{
    a->num_counts = 0;
    const char *p = text;
    while (*p) {
        char *end = NULL;
        long long n = strtoll(p, &end, 10);
        if (end == p || n < 1 || n > (1 << 20) || (*end && *end != ',') ||
            a->num_counts == MAX_COUNTS) {
            cli_fail(RL_CLI_USAGE, "--samples: expected up to %d counts in 1..%d, got '%s'",
                        MAX_COUNTS, 1 << 20, text);
            return false;
        }
        a->counts[a->num_counts++] = n;
        p = *end ? end + 1 : end;
    }
    return a->num_counts > 0;
}

static bool take_counts(void *a, const char *text)
{
    return parse_counts(text, a);
}

static bool take_backend(void *ctx, const char *text)
{
    return eval_parse_visibility_backend("--visibility-backend", text, &((bs_args *)ctx)->backend);
}

static bool take_quality_size(void *ctx, const char *text)
{
    return eval_parse_quality_size("--quality-size", text, &((bs_args *)ctx)->quality_size);
}

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bs_args *a)
{
    a->sections = (1u << SEC_COUNT) - 1;
    a->height = 1.7;
    bool has_res = false, has_val = false, has_counts = false;
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_STRING("--scene", &a->scene),
        RL_BENCH_COUNT("--resolution", 4096, &a->resolution, &has_res),
        RL_BENCH_COUNT("--validation", 1 << 20, &a->validation, &has_val),
        RL_BENCH_COUNT("--repeats", 64, &a->repeats, NULL),
        { .name = "--height", .kind = RL_BENCH_OPT_REAL, .real = &a->height, .lo = 0.0,
          .hi = INFINITY, .expect = "metres >= 0" },
        RL_BENCH_CUSTOM("--samples", take_counts, a, &has_counts),
        RL_BENCH_CUSTOM("--quality-size", take_quality_size, a, NULL),
        RL_BENCH_CUSTOM("--visibility-backend", take_backend, a, NULL),
        RL_BENCH_REAL("--samples-base", 1.0, 1e6, &a->samples_base, NULL),
        RL_BENCH_REAL("--samples-per-meter", 1e-9, 1e6, &a->samples_per_meter, NULL),
        RL_BENCH_COUNT("--threads", 1024, &a->threads, NULL),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench sampling", bench_sampling_help, rows,
                                 (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    if (!a->scene)
        a->scene = a->quick ? "cornell" : "city:blocks=3";
    if (!a->backend)
        a->backend = "software";
    if (!has_res)
        a->resolution = a->quick ? 32 : 256;
    if (!has_val)
        a->validation = a->quick ? 64 : 2000;
    if (a->repeats < 1)
        a->repeats = 1;
    if (!has_counts) {
        static const long long full[] = { 256, 1024, 4096 }, quick[] = { 16, 48 };
        a->num_counts = a->quick ? 2 : 3;
        memcpy(a->counts, a->quick ? quick : full, (size_t)a->num_counts * sizeof *a->counts);
    }
    return RL_CLI_OK;
}

int bench_sampling(int argc, char **argv)
{
    bs_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    if (cli_dist_active() && (a.sections & (1u << SEC_THROUGHPUT)))
        return cli_fail(RL_CLI_USAGE, "--dist: the throughput section measures this machine's samples/s and "
                                      "does not run distributed; choose --only variants,convergence");
    char out[4096];
    if (cli_dist_master() && !bench_out_path(a.out, "sampling", out, sizeof out))
        return RL_CLI_FAIL;
    bs_ctx c = { .a = &a };
    if ((rc = cli_load_scene(a.scene, &c.scene)) != RL_CLI_OK)
        return rc;
    c.bounds = rl_scene_get_data(c.scene)->bounds;
    if (a.height > c.bounds.max.y - c.bounds.min.y)
        a.height = 0.5 * (c.bounds.max.y - c.bounds.min.y);
    char num[32];
    snprintf(num, sizeof num, "%lld", a.resolution);
    rl_status st = rl_property_create("visibility", &c.vis);
    if (st == RL_OK)
        st = rl_property_set(c.vis, "resolution", num);
    if (st == RL_OK)
        st = rl_property_set(c.vis, "backend", a.backend);
    if (st == RL_OK)
        st = rl_property_commit(c.vis, c.scene, (int)a.threads);
    if (st != RL_OK) {
        rl_property_release(c.vis);
        rl_scene_release(c.scene);
        return cli_fail_status(RL_CLI_FAIL, st, "visibility property");
    }
    if (!cli_dist_master()) {
        /* --dist: a sampling node; the control node prints and writes. */
        st = serve_sections(&c);
        rl_property_release(c.vis);
        rl_scene_release(c.scene);
        return st == RL_OK ? RL_CLI_OK : cli_fail_status(RL_CLI_FAIL, st, "sampling node");
    }
    int threads = rl_property_workers(c.vis);
    cJSON *root = bench_record_json("sampling", threads);
    cJSON *params = cJSON_AddObjectToObject(root, "parameters");
    cJSON_AddStringToObject(params, "scene", a.scene);
    cJSON_AddItemToObject(params, "scene_stats", cli_scene_stats_json(c.scene));
    cJSON_AddStringToObject(params, "property", "visibility (objects)");
    cJSON_AddNumberToObject(params, "resolution", (double)a.resolution);
    cJSON_AddStringToObject(params, "visibility_backend", a.backend);
    cJSON_AddNumberToObject(params, "validation_points", (double)a.validation);
    cJSON_AddNumberToObject(params, "repeats", (double)a.repeats);
    cJSON_AddStringToObject(params, "quality_size", eval_quality_size_name(a.quality_size));
    cJSON_AddNumberToObject(params, "samples_base", a.samples_base > 0.0 ? a.samples_base : 5.0);
    cJSON_AddNumberToObject(params, "samples_per_meter", a.samples_per_meter > 0.0 ? a.samples_per_meter : 0.05);
    cJSON_AddNumberToObject(params, "height_above_floor", a.height);
    if (cli_dist_ranks() > 1) {
        /* Under --dist: the "seconds" are this job's, every other value one process's. */
        cJSON *dist = cJSON_AddObjectToObject(root, "dist");
        if (dist)
            cJSON_AddNumberToObject(dist, "ranks", cli_dist_ranks());
    }
    cJSON *thesis = cJSON_AddObjectToObject(root, "thesis");
    cJSON_AddStringToObject(thesis, "scene", "Power Plant, 1171 objects, 22 ms per sample at 1024^2");
    cJSON_AddStringToObject(thesis, "finding", "grid better only for 3-D, 1024 samples, small "
                                               "region: mean error 12.65 (grid) vs 19.22 (adaptive)");
    printf("rl bench sampling: Jaehn 2015, Sec. 5.7, on %s (%u objects), visibility at %lld^2, "
           "%d workers\n", a.scene, rl_scene_get_data(c.scene)->num_objects, a.resolution, threads);
    static const bench_section_fn fns[SEC_COUNT] = { sec_variants, sec_convergence,
                                                        sec_throughput };
    rc = bench_run_sections("sampling", root, section_names, fns, SEC_COUNT, a.sections, &c,
                               c.reason, threads, out);
    cJSON_Delete(root);
    rl_property_release(c.vis);
    rl_scene_release(c.scene);
    return rc;
}
