/* bench_surfels.c: `rl bench surfels`: Jähn 2015, Table 6.1 (Sec. 6.4.3),
 * the time of each step of building one surfel representation with 40000
 * surfels, on the whole built-in `city` as one node (the thesis: the Power
 * Plant), as a table beside the thesis' figures and one JSON record:
 *   defaults  one build with the defaults (progressive, start sample 160):
 *             atlas (8 views), candidate set and its size, sampling, relative
 *             sizes, total; the surfel set's memory (Sec. 6.1.3: 20 bytes
 *             per surfel). Target of the issue: sampling <= 520 ms, the
 *             thesis' figure for this variant.
 *   variants  the sampling variants of Table 6.1 (random; progressive with
 *             start 160 and 1000; constant 160 and 1000), each one build with
 *             the same seed, with its sampling time and, so that speed comes
 *             with quality, the nearest-neighbour distances within every
 *             power-of-two prefix relative to the bounds' diagonal (the
 *             "minimaler relativer Punktabstand" of Sec. 6.4): minimum and
 *             mean. A variant whose estimated sampling time exceeds
 *             --max-seconds is skipped: the estimate is its number of
 *             nearest-chosen queries (samples x sample size, from the round
 *             schedule) times the time per query of the default variant.
 *   atlas     the 8 views rendered by the software rasterizer and by OpenGL
 *             (issue 35, part 6: rl_surfel_desc.atlas_drawer = a GL drawer,
 *             docs/gl.md) in the same run: the least atlas time of
 *             --atlas-runs builds each (count 1, so that the sampling after
 *             the atlas costs nothing), wall and process CPU time, the GL
 *             drawer's making apart, the candidates of each; the record
 *             names the GL renderer. Where no GL context can be made the
 *             section records why and the software figures only.
 * Texture transfer (111 ms in the thesis) has no counterpart: our atlas is
 * rendered in main memory, or on GL where only depth and IDs are read
 * back (src/render/surfels_build.c). */
#define _POSIX_C_SOURCE 200809L
#include "bench_surfels.h"

#include "bench_args.h"
#include "bench_rays.h"
#include "bench_util.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rl/rl_gl.h"
#include "rl/rl_surfels.h"
#include "rl/rl_timer.h"

#define note(...) (fflush(stdout), bench_note("surfels", __VA_ARGS__))

static const char bench_surfels_help[] =
    "usage: rl bench surfels [options]\n"
    "\n"
    "Times the Progressive Blue Surfels preprocessing step by step as in\n"
    "Jaehn 2015, Table 6.1, on one scene as one node, beside the thesis'\n"
    "figures, and measures each sampling variant's quality (nearest-neighbour\n"
    "distances within power-of-two prefixes). Sections:\n"
    "  defaults   atlas (8 views), candidate set, sampling, relative sizes,\n"
    "             total, memory; target: sampling <= 520 ms\n"
    "  variants   random, prog-160, prog-1000, const-160, const-1000\n"
    "  atlas      the 8 views on the software rasterizer and on OpenGL\n"
    "             (GL drawer), least of --atlas-runs builds each\n"
    "\n"
    "options:\n"
    "  --scene S          default city (see rl scenes)\n"
    "  --resolution N     pixels per side of each view; default 1024\n"
    "  --count N          surfels; default 40000\n"
    "  --variants LIST    comma-separated subset of the variants; default all\n"
    "  --max-seconds S    skip variants estimated to sample longer; default 120\n"
    "  --seed N           default 1\n"
    "  --threads N        default all\n"
    "  --only LIST        sections: defaults, variants, atlas; default all\n"
    "  --atlas-runs N     builds per atlas backend; default 3\n"
    "  --device D         EGL device of the GL atlas (auto, surfaceless, N);\n"
    "                     default $RL_EGL_DEVICE, else auto\n"
    "  --out FILE.json    default bench/results/surfels-YYYYMMDD-HHMMSS.json\n"
    "  --quick            tiny run: cornell, 128^2, 2000 surfels\n"
    "\n"
    "example:\n"
    "  rl bench surfels --variants random,prog-160,prog-1000\n"
    "  rl bench surfels --only atlas\n";

enum { SEC_DEFAULTS, SEC_VARIANTS, SEC_ATLAS, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "defaults", "variants", "atlas" };

enum { V_RANDOM, V_PROG_160, V_PROG_1000, V_CONST_160, V_CONST_1000, V_COUNT };
static const char *const variant_names[V_COUNT] = { "random", "prog-160", "prog-1000",
                                                    "const-160", "const-1000" };
static const char *const variant_labels[V_COUNT] = {
    "sampling: random (uniform)", "sampling: progressive, start 160 (default)",
    "sampling: progressive, start 1000", "sampling: constant sample 160",
    "sampling: constant sample 1000"
};
/* Jähn 2015, Table 6.1, ms. */
static const double thesis_variant_ms[V_COUNT] = { 25, 520, 1740, 13000, 81000 };
#define THESIS_ATLAS_MS 270.0
#define THESIS_TRANSFER_MS 111.0
#define THESIS_CANDIDATES_MS 18.0
#define THESIS_SIZES_MS 456.0
#define THESIS_TOTAL_MS 1375.0
#define TARGET_SAMPLING_MS 520.0

typedef struct bsf_args {
    const char *scene, *out, *device;
    long long resolution, count, seed, threads, atlas_runs;
    unsigned sections;
    double max_seconds;
    unsigned variants;
    bool quick;
} bsf_args;

typedef struct bsf_ctx {
    bsf_args *a;
    rl_scene *scene;
    double diagonal;
    double ms_per_query;       /* from the default build; 0 until measured */
    double variant_ms[V_COUNT];
    bool variant_done[V_COUNT];
    rl_surfel_set defaults;    /* kept for the variants section */
    char reason[512];
} bsf_ctx;

static void variant_desc(const bsf_ctx *c, int v, rl_surfel_desc *d)
{
    memset(d, 0, sizeof *d);
    d->resolution = (uint32_t)c->a->resolution;
    d->count = (uint32_t)c->a->count;
    d->seed = (uint64_t)c->a->seed;
    d->threads = (int)c->a->threads;
    d->sampling = v == V_RANDOM ? RL_SURFEL_RANDOM
                : v == V_CONST_160 || v == V_CONST_1000 ? RL_SURFEL_CONSTANT : RL_SURFEL_PROGRESSIVE;
    d->start_sample = v == V_PROG_1000 || v == V_CONST_1000 ? 1000 : 160;
}

/* Nearest-chosen queries of a variant: its samples times their size, from
 * the round schedule of rl_surfels.h (r = 1 + rounds / 500, at most half
 * the sample; constant: 1). */
static double queries(int v, uint32_t count, uint32_t candidates)
{
    if (v == V_RANDOM)
        return 0.0;
    uint32_t s = v == V_PROG_1000 || v == V_CONST_1000 ? 1000 : 160;
    uint32_t want = count < candidates ? count : candidates;
    double q = 0.0;
    for (uint32_t n = 1; n < want;) {
        uint32_t uses = v == V_CONST_160 || v == V_CONST_1000 ? 1 : 1 + (n - 1) / 500;
        if (uses > s / 2)
            uses = s / 2;
        q += s;
        n += uses;
    }
    return q;
}

static cJSON *timing_json(const rl_surfel_timing *t)
{
    cJSON *o = cJSON_CreateObject();
    bench_add_num(o, "atlas_ms", t->atlas_ms);
    bench_add_num(o, "candidates_ms", t->candidates_ms);
    bench_add_num(o, "sampling_ms", t->sampling_ms);
    bench_add_num(o, "sizes_ms", t->sizes_ms);
    bench_add_num(o, "total_ms", t->total_ms);
    return o;
}

static rl_status build(bsf_ctx *c, int v, rl_surfel_set *set)
{
    rl_surfel_desc d;
    variant_desc(c, v, &d);
    note("building %s: %lld surfels at %lld^2 per view", variant_names[v], c->a->count,
         c->a->resolution);
    rl_status st = rl_surfels_build(c->scene, NULL, 0, &d, set);
    if (st != RL_OK)
        snprintf(c->reason, sizeof c->reason, "%s: %s", variant_names[v], rl_last_error());
    return st;
}

static void row(const char *label, double ours, double thesis)
{
    printf("%-46s %10.1f %10.0f %8.2f\n", label, ours, thesis, bench_ratio(ours, thesis));
}

static rl_status sec_defaults(void *ctx, cJSON *sec)
{
    bsf_ctx *c = ctx;
    rl_surfel_set *s = &c->defaults;
    rl_status st = build(c, V_PROG_160, s);
    if (st != RL_OK)
        return st;
    const rl_surfel_timing *t = &s->timing;
    c->variant_ms[V_PROG_160] = t->sampling_ms;
    c->variant_done[V_PROG_160] = true;
    double q = queries(V_PROG_160, s->count, s->candidates);
    c->ms_per_query = q > 0.0 ? t->sampling_ms / q : 0.0;
    printf("\ndefaults (Jaehn 2015, Table 6.1)%15s %10s %10s %8s\n", "", "ours ms", "thesis ms",
           "ratio");
    row("atlas: rendering the 8 views", t->atlas_ms, THESIS_ATLAS_MS);
    printf("%-46s %10s %10.0f\n", "transfer of the textures to main memory", "-", THESIS_TRANSFER_MS);
    char label[96];
    snprintf(label, sizeof label, "candidate set (%.2f M; thesis 1.3 M)", s->candidates / 1e6);
    row(label, t->candidates_ms, THESIS_CANDIDATES_MS);
    row(variant_labels[V_PROG_160], t->sampling_ms, thesis_variant_ms[V_PROG_160]);
    row("relative point sizes", t->sizes_ms, THESIS_SIZES_MS);
    row("total with the defaults", t->total_ms, THESIS_TOTAL_MS);
    size_t bytes = (size_t)s->count * sizeof *s->surfels;
    printf("surfels %u of %u candidates, relative coverage %.3f; memory %zu bytes per surfel, "
           "%zu bytes (thesis: 20, ~800 kB for 40000)\n", s->count, s->candidates,
           (double)s->coverage, sizeof *s->surfels, bytes);
    bool met = t->sampling_ms <= TARGET_SAMPLING_MS;
    printf("target: default sampling <= %.0f ms: %s (%.1f ms)\n", TARGET_SAMPLING_MS,
           met ? "met" : "NOT met", t->sampling_ms);
    cJSON_AddItemToObject(sec, "timing", timing_json(t));
    cJSON_AddNumberToObject(sec, "surfels", s->count);
    cJSON_AddNumberToObject(sec, "candidates", s->candidates);
    bench_add_num(sec, "coverage", s->coverage);
    cJSON_AddNumberToObject(sec, "bytes_per_surfel", (double)sizeof *s->surfels);
    cJSON_AddNumberToObject(sec, "surfel_bytes", (double)bytes);
    bench_add_num(sec, "ms_per_query", c->ms_per_query);
    cJSON_AddNumberToObject(sec, "target_sampling_ms", TARGET_SAMPLING_MS);
    cJSON_AddBoolToObject(sec, "target_met", met);
    return RL_OK;
}

/* Prefix spacing 16, 32, ... and the whole sequence, relative to the
 * diagonal; the table shows every other one. */
static rl_status quality(bsf_ctx *c, const rl_surfel_set *s, cJSON *out)
{
    cJSON *rows = cJSON_AddArrayToObject(out, "prefixes");
    int col = 0;
    for (uint32_t k = 16;; k *= 2) {
        uint32_t m = k < s->count ? k : s->count;
        double lo, mean;
        rl_status st = rl_surfels_prefix_spacing(s->surfels, m, (int)c->a->threads, &lo, &mean);
        if (st != RL_OK)
            return st;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddNumberToObject(o, "prefix", m);
        bench_add_num(o, "min_rel", lo / c->diagonal);
        bench_add_num(o, "mean_rel", mean / c->diagonal);
        cJSON_AddItemToArray(rows, o);
        if (col++ % 2 == 0 || m == s->count)
            printf(" %6u:%.2f/%.2f", m, 1e3 * lo / c->diagonal, 1e3 * mean / c->diagonal);
        if (m == s->count)
            break;
    }
    printf("\n");
    return RL_OK;
}

static rl_status sec_variants(void *ctx, cJSON *sec)
{
    bsf_ctx *c = ctx;
    cJSON *list = cJSON_AddArrayToObject(sec, "variants");
    printf("\nvariants: sampling time and nearest-neighbour distance in prefixes\n"
           "(prefix: min/mean, in 1e-3 of the bounds' diagonal %.1f)\n", c->diagonal);
    for (int v = 0; v < V_COUNT; ++v) {
        if (!((c->a->variants >> v) & 1u))
            continue;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(list, o);
        cJSON_AddStringToObject(o, "variant", variant_names[v]);
        cJSON_AddNumberToObject(o, "thesis_ms", thesis_variant_ms[v]);
        double est = c->ms_per_query * queries(v, (uint32_t)c->a->count,
                                               c->defaults.candidates ? c->defaults.candidates
                                                                      : UINT32_MAX);
        bench_add_num(o, "estimated_ms", c->ms_per_query > 0.0 ? est : NAN);
        if (v != V_PROG_160 && c->ms_per_query > 0.0 && est > 1e3 * c->a->max_seconds) {
            printf("%-12s skipped: estimated %.0f ms > --max-seconds %g\n", variant_names[v], est,
                   c->a->max_seconds);
            cJSON_AddBoolToObject(o, "skipped", true);
            continue;
        }
        rl_surfel_set own = { 0 };
        const rl_surfel_set *s = &c->defaults;
        if (v != V_PROG_160 || !c->defaults.surfels) {
            rl_status st = build(c, v, &own);
            if (st != RL_OK)
                return st;
            s = &own;
        }
        cJSON_AddBoolToObject(o, "skipped", false);
        bench_add_num(o, "sampling_ms", s->timing.sampling_ms);
        cJSON_AddItemToObject(o, "timing", timing_json(&s->timing));
        cJSON_AddNumberToObject(o, "surfels", s->count);
        c->variant_ms[v] = s->timing.sampling_ms;
        c->variant_done[v] = true;
        printf("%-12s %9.1f ms (thesis %6.0f)", variant_names[v], s->timing.sampling_ms,
               thesis_variant_ms[v]);
        rl_status st = quality(c, s, o);
        rl_surfel_set_free(&own);
        if (st != RL_OK)
            return st;
    }
    printf("\nTable 6.1 (ms)%33s %10s %10s\n", "", "ours", "thesis");
    for (int v = 0; v < V_COUNT; ++v)
        if (c->variant_done[v])
            printf("%-46s %10.1f %10.0f\n", variant_labels[v], c->variant_ms[v], thesis_variant_ms[v]);
        else
            printf("%-46s %10s %10.0f\n", variant_labels[v], "-", thesis_variant_ms[v]);
    return RL_OK;
}

/* CPU time of the whole process (every thread, llvmpipe's included), s. */
static double cpu_s(void)
{
    struct timespec t;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) == 0 ? (double)t.tv_sec + 1e-9 * (double)t.tv_nsec : NAN;
}

typedef struct atlas_time {
    double min_ms, min_cpu_ms;    /* the least of the runs */
    uint32_t candidates;
    float coverage;
} atlas_time;

/* The least atlas time of the runs with drawer dr (NULL: software). The
 * process CPU time spans the whole build, whose other steps cost next to
 * nothing at count 1 besides the candidates. */
static rl_status time_atlas(bsf_ctx *c, rl_drawer *dr, atlas_time *t)
{
    t->min_ms = t->min_cpu_ms = INFINITY;
    for (long long k = 0; k < c->a->atlas_runs; ++k) {
        rl_surfel_desc d = { .resolution = (uint32_t)c->a->resolution, .count = 1,
                             .seed = (uint64_t)c->a->seed, .threads = (int)c->a->threads, .atlas_drawer = dr };
        rl_surfel_set set;
        double c0 = cpu_s();
        rl_status st = rl_surfels_build(c->scene, NULL, 0, &d, &set);
        double cpu_ms = 1e3 * (cpu_s() - c0);
        if (st != RL_OK) {
            snprintf(c->reason, sizeof c->reason, "atlas, %s: %s", dr ? "gl" : "software", rl_last_error());
            return st;
        }
        t->min_ms = fmin(t->min_ms, set.timing.atlas_ms);
        t->min_cpu_ms = fmin(t->min_cpu_ms, cpu_ms);
        t->candidates = set.candidates;
        t->coverage = set.coverage;
        rl_surfel_set_free(&set);
    }
    return RL_OK;
}

static cJSON *atlas_json(const atlas_time *t)
{
    cJSON *o = cJSON_CreateObject();
    bench_add_num(o, "min_atlas_ms", t->min_ms);
    bench_add_num(o, "min_build_cpu_ms", t->min_cpu_ms);
    cJSON_AddNumberToObject(o, "candidates", t->candidates);
    bench_add_num(o, "coverage", t->coverage);
    return o;
}

static rl_status sec_atlas(void *ctx, cJSON *sec)
{
    bsf_ctx *c = ctx;
    note("atlas: software, %lld builds", c->a->atlas_runs);
    atlas_time sw, gl;
    rl_status st = time_atlas(c, NULL, &sw);
    if (st != RL_OK)
        return st;
    cJSON_AddNumberToObject(sec, "runs", (double)c->a->atlas_runs);
    cJSON_AddNumberToObject(sec, "thesis_atlas_ms", THESIS_ATLAS_MS);
    cJSON_AddItemToObject(sec, "software", atlas_json(&sw));
    printf("\natlas: the 8 views at %lld^2, least of %lld builds   %10s %10s %10s\n", c->a->resolution,
           c->a->atlas_runs, "wall ms", "cpu ms", "thesis ms");
    printf("%-52s %10.1f %10.1f %10.0f\n", "software rasterizer", sw.min_ms, sw.min_cpu_ms, THESIS_ATLAS_MS);
    char why[512];
    const char *device = c->a->device ? c->a->device : "";
    rl_gl_info info;
    bool ok = rl_gl_available(device, why, sizeof why);
    if (ok && rl_gl_info_get(device, &info) != RL_OK) {
        ok = false;
        snprintf(why, sizeof why, "%s", rl_last_error());
    }
    if (!ok) {
        printf("%-52s unavailable: %s\n", "OpenGL", why);
        cJSON_AddStringToObject(sec, "gl_unavailable", why);
        return RL_OK;
    }
    cJSON *g = cJSON_AddObjectToObject(sec, "gl_device");
    cJSON_AddStringToObject(g, "vendor", info.vendor);
    cJSON_AddStringToObject(g, "renderer", info.renderer);
    cJSON_AddStringToObject(g, "version", info.version);
    cJSON_AddStringToObject(g, "device", info.device);
    note("atlas: OpenGL (%s), %lld builds", info.renderer, c->a->atlas_runs);
    const rl_drawer_desc dd = RL_SURFEL_ATLAS_DRAWER_DESC;
    rl_drawer *dr = NULL;
    double t0 = rl_time_s();
    st = rl_gl_drawer_create(c->scene, &dd, device, &dr);
    double make_ms = 1e3 * (rl_time_s() - t0);
    if (st != RL_OK) {
        snprintf(c->reason, sizeof c->reason, "atlas: the GL drawer: %s", rl_last_error());
        return st;
    }
    st = time_atlas(c, dr, &gl);
    rl_drawer_release(dr);
    if (st != RL_OK)
        return st;
    cJSON *o = atlas_json(&gl);
    bench_add_num(o, "drawer_create_ms", make_ms);
    cJSON_AddItemToObject(sec, "gl", o);
    bench_add_num(sec, "software_over_gl", bench_ratio(sw.min_ms, gl.min_ms));
    bench_add_num(sec, "software_over_gl_cpu", bench_ratio(sw.min_cpu_ms, gl.min_cpu_ms));
    bench_add_num(sec, "gl_over_thesis", bench_ratio(gl.min_ms, THESIS_ATLAS_MS));
    char label[96];
    snprintf(label, sizeof label, "OpenGL (%.40s)", info.renderer);
    printf("%-52s %10.1f %10.1f %10.0f\n", label, gl.min_ms, gl.min_cpu_ms, THESIS_ATLAS_MS);
    printf("GL drawer made in %.1f ms (context, shaders, buffers; not in the atlas time); candidates "
           "software %u, GL %u; software / GL %.2f (wall), %.2f (cpu); GL / thesis %.2f\n", make_ms,
           sw.candidates, gl.candidates, bench_ratio(sw.min_ms, gl.min_ms),
           bench_ratio(sw.min_cpu_ms, gl.min_cpu_ms), bench_ratio(gl.min_ms, THESIS_ATLAS_MS));
    return RL_OK;
}

static bool parse_variants(const char *text, unsigned *bits)
{
    *bits = 0;
    const char *p = text;
    for (;;) {
        size_t n = strcspn(p, ",");
        int found = -1;
        for (int v = 0; v < V_COUNT && found < 0; ++v)
            if (strlen(variant_names[v]) == n && strncmp(p, variant_names[v], n) == 0)
                found = v;
        if (found < 0) {
            cli_fail(RL_CLI_USAGE, "--variants: expected a list of random, prog-160, "
                        "prog-1000, const-160, const-1000, got '%s'", text);
            return false;
        }
        *bits |= 1u << found;
        if (p[n] == '\0')
            return true;
        p += n + 1;
    }
}

static bool take_variants(void *a, const char *text)
{
    return parse_variants(text, &((bsf_args *)a)->variants);
}

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bsf_args *a)
{
    a->variants = (1u << V_COUNT) - 1;
    a->sections = (1u << SEC_COUNT) - 1;
    a->atlas_runs = 3;
    a->seed = 1;
    a->max_seconds = 120.0;
    bool has_res = false, has_count = false, has_max = false;
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_STRING("--scene", &a->scene),
        RL_BENCH_COUNT("--resolution", 16384, &a->resolution, &has_res),
        RL_BENCH_COUNT("--count", 1 << 26, &a->count, &has_count),
        RL_BENCH_CUSTOM("--variants", take_variants, a, NULL),
        { .name = "--max-seconds", .kind = RL_BENCH_OPT_REAL, .real = &a->max_seconds,
          .lo = 0.0, .lo_open = true, .hi = INFINITY, .expect = "seconds > 0", .set = &has_max },
        RL_BENCH_COUNT("--seed", 1LL << 62, &a->seed, NULL),
        RL_BENCH_COUNT("--threads", 1024, &a->threads, NULL),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_COUNT("--atlas-runs", 100, &a->atlas_runs, NULL),
        RL_BENCH_STRING("--device", &a->device),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench surfels", bench_surfels_help, rows,
                                 (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    if (!a->scene)
        a->scene = a->quick ? "cornell" : "city";
    if (!has_res)
        a->resolution = a->quick ? 128 : 1024;
    if (!has_count)
        a->count = a->quick ? 2000 : 40000;
    if (!has_max && a->quick)
        a->max_seconds = 10.0;
    return RL_CLI_OK;
}

int bench_surfels(int argc, char **argv)
{
    bsf_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    char out[4096];
    if (!bench_out_path(a.out, "surfels", out, sizeof out))
        return RL_CLI_FAIL;
    bsf_ctx c = { .a = &a };
    if ((rc = cli_load_scene(a.scene, &c.scene)) != RL_CLI_OK)
        return rc;
    const rl_scene_data *d = rl_scene_get_data(c.scene);
    c.diagonal = rl_length(rl_aabb_extent(d->bounds));
    int threads = a.threads > 0 ? (int)a.threads : omp_get_max_threads();
    cJSON *root = bench_record_json("surfels", threads);
    if (!root) {
        rl_scene_release(c.scene);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    cJSON *params = cJSON_AddObjectToObject(root, "parameters");
    cJSON_AddStringToObject(params, "scene", a.scene);
    cJSON_AddItemToObject(params, "scene_stats", cli_scene_stats_json(c.scene));
    cJSON_AddStringToObject(params, "objects", "all, as one node");
    cJSON_AddNumberToObject(params, "resolution", (double)a.resolution);
    cJSON_AddNumberToObject(params, "count", (double)a.count);
    cJSON_AddNumberToObject(params, "seed", (double)a.seed);
    cJSON_AddNumberToObject(params, "max_seconds", a.max_seconds);
    cJSON_AddBoolToObject(params, "quick", a.quick);
    cJSON_AddNumberToObject(params, "atlas_runs", (double)a.atlas_runs);
    cJSON *vl = cJSON_AddArrayToObject(params, "variants");
    for (int v = 0; v < V_COUNT; ++v)
        if ((a.variants >> v) & 1u)
            cJSON_AddItemToArray(vl, cJSON_CreateString(variant_names[v]));
    cJSON *thesis = cJSON_AddObjectToObject(root, "thesis");
    cJSON_AddStringToObject(thesis, "source", "Jaehn 2015, Table 6.1: Power Plant, 40k surfels, "
                                              "1024^2 per view, GPU atlas");
    cJSON_AddNumberToObject(thesis, "atlas_ms", THESIS_ATLAS_MS);
    cJSON_AddNumberToObject(thesis, "transfer_ms", THESIS_TRANSFER_MS);
    cJSON_AddNumberToObject(thesis, "candidates_ms", THESIS_CANDIDATES_MS);
    cJSON_AddNumberToObject(thesis, "candidates", 1.3e6);
    for (int v = 0; v < V_COUNT; ++v) {
        char key[48];
        snprintf(key, sizeof key, "sampling_%s_ms", variant_names[v]);
        cJSON_AddNumberToObject(thesis, key, thesis_variant_ms[v]);
    }
    cJSON_AddNumberToObject(thesis, "sizes_ms", THESIS_SIZES_MS);
    cJSON_AddNumberToObject(thesis, "total_ms", THESIS_TOTAL_MS);
    cJSON_AddNumberToObject(thesis, "bytes_per_surfel", 20);
    printf("rl bench surfels: Jaehn 2015, Table 6.1, on %s (%u objects, %u triangles) as one node: "
           "%lld surfels, %lld^2 per view, %d threads\n", a.scene, d->num_objects, d->num_triangles,
           a.count, a.resolution, threads);
    static const bench_section_fn fns[SEC_COUNT] = { sec_defaults, sec_variants, sec_atlas };
    rc = bench_run_sections("surfels", root, section_names, fns, SEC_COUNT, a.sections, &c, c.reason,
                            threads, out);
    cJSON_Delete(root);
    rl_surfel_set_free(&c.defaults);
    rl_scene_release(c.scene);
    return rc;
}
