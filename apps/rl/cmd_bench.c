/* cmd_bench.c: `rl bench rays`: ray throughput of every accelerator on the
 * same standard workloads (bench_rays.h), as a table and a JSON record.
 * `rl bench vt` (Vertex Tracing vs Whitted) lives in bench_vt.c.
 *
 * The benchmark doubles as a smoke test: every accelerator traces exactly the
 * same rays, so their hit counts per workload must agree; a mismatch is
 * printed as a warning and recorded. As in `rl render`, everything cheap is
 * checked before anything long runs: arguments (exit 2), the output path
 * (1), then every scene is loaded (1, or 2 for bad built-in parameters). A
 * mesh file that does not exist is skipped with the reason, not a failure,
 * so the default list works without the Assimp test models. */
#define _POSIX_C_SOURCE 200809L
#include "bench_args.h"
#include "bench_pt.h"
#include "bench_rays.h"
#include "bench_sampling.h"
#include "bench_culling.h"
#include "bench_dist.h"
#include "bench_gl.h"
#include "bench_surfels.h"
#include "bench_util.h"
#include "bench_vt.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rl/rl_options.h"

/* rl bench --help: every kind on one line. Durations are the defaults' on
 * 2 cores (bench/README.md); --quick is the toy run ctest uses. */
static const char bench_overview[] =
    "usage: rl bench rays|vt|pt|sampling|surfels|culling|gl|dist [options]\n"
    "       rl bench KIND --help    the options of one kind\n"
    "\n"
    "Timed runs, each writing one JSON record (machine, build, command line,\n"
    "parameters, results) to --out FILE.json, by default\n"
    "bench/results/KIND-YYYYMMDD-HHMMSS.json (UTC). --quick: a toy run of\n"
    "seconds that only checks that nothing rots.\n"
    "\n"
    "kinds (what it measures; duration of the defaults on 2 cores, bench/README.md):\n"
    "  rl bench rays      ray throughput of BVH, grid, Embree: Mrays/s, build,\n"
    "                     memory (~35 s)\n"
    "  rl bench vt        Vertex Tracing vs Whitted, Ullmann 2003 Ch. 5: time,\n"
    "                     rays, SSIM (~8 min)\n"
    "  rl bench pt        Line Space path tracing, Schroeder 2017 Table 1, Diagrams\n"
    "                     1-3 (long: Line Spaces of up to 8 GB; choose with --only)\n"
    "  rl bench sampling  approximation error of sampled visibility, Jaehn 2015\n"
    "                     Sec. 5.7 (an hour or more; --samples, --repeats shorten it)\n"
    "  rl bench surfels   Progressive Blue Surfels preprocessing step by step,\n"
    "                     Jaehn 2015 Table 6.1 (minutes; variants capped by --max-seconds)\n"
    "  rl bench culling   CHC++, SVS, visible sets, runtime selection, Jaehn 2015\n"
    "                     Ch. 7 (about an hour on city; choose with --only)\n"
    "  rl bench gl        the OpenGL backend vs the software paths: gl-raster vs\n"
    "                     raster frames, the visibility property (~1 min)\n"
    "  rl bench dist      rl --dist under mpirun against the rank count: tiles\n"
    "                     (whitted, pt) and Alg. 5.4 sampling (~3 min)\n"
    "\n"
    "example:\n"
    "  rl bench rays --quick --out /tmp/rays.json\n"
    "  rl bench vt --help\n";

static const char *const bench_kinds[] = { "rays", "vt", "pt", "sampling", "surfels", "culling", "gl", "dist" };

static const char bench_help[] =
    "usage: rl bench rays [options]      (rl bench --help: every kind)\n"
    "\n"
    "Times ray queries of each accelerator on three workloads generated once\n"
    "per scene and shared by all accelerators:\n"
    "  primary  one ray per pixel of the scene camera, 8x8 tiles in scanline order\n"
    "  shadow   from each primary hit towards the first light (any hit)\n"
    "  diffuse  cosine-weighted directions from each primary hit, in pixel order\n"
    "Prints build time, memory and Mrays/s per workload with the ratio to Embree,\n"
    "warns when accelerators disagree on the number of hits, and writes JSON.\n"
    "Packet section (bvh and embree, when among --accels): primary rays in 4x2\n"
    "tiles and their shadow rays, each accelerator with single queries and with\n"
    "the batch queries in packets of 8 (our packet traversal; rtcIntersect8),\n"
    "interleaved, with CPU-time ratios to single rays and to Embree's packets.\n"
    "\n"
    "options:\n"
    "  --scenes A,B,...   scenes (built-in[:k=v,...], .json or mesh file); a\n"
    "                     k=v item after a comma continues the previous scene's\n"
    "                     parameters. default: cornell, cornell-teapot:triangles=70000,\n"
    "                     city, /usr/share/assimp/models/PLY/Wuson.ply\n"
    "  --accels A,B,...   accelerators: bvh, grid, embree, brute; default bvh,grid,embree\n"
    "  --size WxH         primary rays per scene; default 1024x768\n"
    "  --rays N           about N primary rays instead (aspect ratio of --size)\n"
    "  --threads N        threads tracing (and building); default all\n"
    "  --out FILE.json    default bench/results/rays-YYYYMMDD-HHMMSS.json\n"
    "  --quick            tiny run: cornell only, 64x48, every available\n"
    "                     accelerator, one timed pass\n"
    "\n"
    "Timing: one warm-up pass, then the best of 3 passes (more until 0.5 s).\n"
    "\n"
    "example:\n"
    "  rl bench rays --scenes cornell,city:blocks=4 --accels bvh,embree --size 640x480\n";

#define MAX_SCENES 32
#define MAX_RAYS (1LL << 24)       /* 16M rays: 512 MiB per workload */
#define TINY_SCENE 1024            /* triangles: brute force finds primary hits */
#define DEFAULT_MESH "/usr/share/assimp/models/PLY/Wuson.ply"

typedef struct bench_args {
    char *scenes[MAX_SCENES];      /* malloc'd */
    int num_scenes;
    rl_accel_kind accels[RL_ACCEL_KIND_COUNT];
    int num_accels;
    bool has_size;
    int width, height;
    long long rays, threads;
    const char *out;
    bool quick;
} bench_args;

static void free_args(bench_args *a)
{
    for (int i = 0; i < a->num_scenes; i++)
        free(a->scenes[i]);
    a->num_scenes = 0;
}

static bool add_scene(bench_args *a, const char *text, size_t n)
{
    if (a->num_scenes >= MAX_SCENES) {
        cli_fail(RL_CLI_USAGE, "--scenes: at most %d scenes", MAX_SCENES);
        return false;
    }
    char *s = malloc(n + 1);
    if (!s) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    memcpy(s, text, n);
    s[n] = '\0';
    a->scenes[a->num_scenes++] = s;
    return true;
}

/* Appends ",k=v" to the last scene: "city:blocks=4,seed=2" is one scene. */
static bool continue_scene(bench_args *a, const char *text, size_t n)
{
    char *last = a->scenes[a->num_scenes - 1];
    size_t len = strlen(last);
    char *s = realloc(last, len + n + 2);
    if (!s) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    s[len] = ',';
    memcpy(s + len + 1, text, n);
    s[len + 1 + n] = '\0';
    a->scenes[a->num_scenes - 1] = s;
    return true;
}

static bool parse_scenes(const char *text, bench_args *a)
{
    free_args(a);
    const char *p = text;
    for (;;) {
        size_t n = strcspn(p, ",");
        bool param = memchr(p, '=', n) && !memchr(p, ':', n);
        if (n == 0 || (param && a->num_scenes == 0)) {
            cli_fail(RL_CLI_USAGE, "--scenes: expected NAME[:k=v,...],... such as "
                                      "cornell,city:blocks=4, got '%s'", text);
            return false;
        }
        if (!(param ? continue_scene(a, p, n) : add_scene(a, p, n)))
            return false;
        if (p[n] == '\0')
            return true;
        p += n + 1;
    }
}

static bool parse_accels(const char *text, bench_args *a)
{
    a->num_accels = 0;
    const char *p = text;
    for (;;) {
        size_t n = strcspn(p, ",");
        char name[32];
        rl_accel_kind kind;
        if (n == 0 || n >= sizeof name) {
            cli_fail(RL_CLI_USAGE, "--accels: expected names such as bvh,grid,embree, got '%s'",
                        text);
            return false;
        }
        memcpy(name, p, n);
        name[n] = '\0';
        rl_clear_error();
        rl_status st = rl_accel_kind_parse(name, &kind);
        if (st != RL_OK) {
            cli_fail_status(RL_CLI_USAGE, st, "--accels");
            return false;
        }
        bool seen = false;      /* a repeated name is measured once */
        for (int i = 0; i < a->num_accels; i++)
            seen = seen || a->accels[i] == kind;
        if (!seen)
            a->accels[a->num_accels++] = kind;
        if (p[n] == '\0')
            return true;
        p += n + 1;
    }
}

static bool take_scenes(void *a, const char *text)
{
    return parse_scenes(text, a);
}

static bool take_accels(void *a, const char *text)
{
    return parse_accels(text, a);
}

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bench_args *a)
{
    if (argc < 2)
        return cli_fail(RL_CLI_USAGE,
                           "bench: missing benchmark (rays, vt, pt, sampling, surfels, culling, gl, dist; see rl bench "
                           "--help)");
    if (cli_is_help(argv[1])) {
        fputs(bench_overview, stdout);
        return RL_BENCH_HELP_SHOWN;
    }
    if (strcmp(argv[1], "rays") != 0) {
        char hint[96];
        return cli_fail(RL_CLI_USAGE, "bench: unknown benchmark '%s' (%sknown: rays, vt, pt, "
                           "sampling, surfels, culling, gl, dist)",
                           argv[1], cli_did_you_mean(argv[1], bench_kinds, sizeof bench_kinds / sizeof *bench_kinds,
                                                     hint, sizeof hint));
    }
    bool has_scenes = false, has_accels = false;
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_CUSTOM("--scenes", take_scenes, a, &has_scenes),
        RL_BENCH_CUSTOM("--accels", take_accels, a, &has_accels),
        RL_BENCH_SIZE("--size", &a->width, &a->height, &a->has_size),
        RL_BENCH_COUNT("--rays", MAX_RAYS, &a->rays, NULL),
        RL_BENCH_COUNT("--threads", 4096, &a->threads, NULL),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench rays", bench_help, rows,
                                 (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;

    /* Defaults; --quick only changes what was not given explicitly. */
    if (!has_scenes) {
        static const char *const full[] = { "cornell", "cornell-teapot:triangles=70000", "city",
                                            DEFAULT_MESH };
        for (size_t i = 0; i < (a->quick ? 1 : sizeof full / sizeof full[0]); i++)
            if (!add_scene(a, full[i], strlen(full[i])))
                return RL_CLI_FAIL;
    }
    if (!has_accels) {
        if (a->quick) {
            for (int k = 0; k < RL_ACCEL_KIND_COUNT; k++)
                if (rl_accel_kind_available((rl_accel_kind)k))
                    a->accels[a->num_accels++] = (rl_accel_kind)k;
        } else {
            a->accels[a->num_accels++] = RL_ACCEL_BVH;
            a->accels[a->num_accels++] = RL_ACCEL_GRID;
            a->accels[a->num_accels++] = RL_ACCEL_EMBREE;
        }
    }
    if (!a->has_size) {
        a->width = a->quick ? 64 : 1024;
        a->height = a->quick ? 48 : 768;
    }
    if (a->rays > 0) {
        /* N pixels with the aspect ratio of --size. */
        double aspect = (double)a->width / a->height;
        long long w = llround(sqrt((double)a->rays * aspect));
        w = w < 1 ? 1 : (w > RL_IMAGE_MAX_SIZE ? RL_IMAGE_MAX_SIZE : w);
        long long h = llround((double)a->rays / (double)w);
        h = h < 1 ? 1 : (h > RL_IMAGE_MAX_SIZE ? RL_IMAGE_MAX_SIZE : h);
        a->width = (int)w;
        a->height = (int)h;
    }
    if ((long long)a->width * a->height > MAX_RAYS)
        return cli_fail(RL_CLI_USAGE, "--size: %dx%d is more than %lld primary rays", a->width,
                           a->height, MAX_RAYS);
    if (a->threads == 0)
        a->threads = omp_get_max_threads();
    return RL_CLI_OK;
}

/* The file part of a scene argument, for the table. */
static void scene_label(const char *arg, char *out, size_t size)
{
    const char *slash = strrchr(arg, '/');
    snprintf(out, size, "%s", slash && slash[1] ? slash + 1 : arg);
}

/* Loads every scene up front, so that a typo in the last one does not cost
 * the minutes spent on the first. A missing file becomes a skipped scene. */
static int load_scenes(const bench_args *a, rl_scene **scenes, bench_scene_result *results)
{
    for (int i = 0; i < a->num_scenes; i++) {
        bench_scene_result *r = &results[i];
        r->arg = a->scenes[i];
        r->status = "ok";
        scene_label(r->arg, r->label, sizeof r->label);
        char *source = NULL, *params = NULL;
        if (!cli_split_source(r->arg, &source, &params))
            return cli_fail(RL_CLI_FAIL, "out of memory");
        struct stat st;
        bool looks_like_file = strchr(source, '/') || strchr(source, '.');
        bool missing = !cli_is_builtin(source) && looks_like_file && stat(source, &st) != 0;
        free(source);
        free(params);
        if (missing) {
            r->status = "skipped";
            snprintf(r->reason, sizeof r->reason, "%s: no such file", r->arg);
            if (rl_log_get_level() >= RL_LOG_WARN)
                fprintf(stderr, "rl: warning: bench: skipping %s: no such file\n", r->arg);
            continue;
        }
        int rc = cli_load_scene(r->arg, &scenes[i]);
        if (rc != RL_CLI_OK)
            return rc;
        rl_scene_stats stats;
        rl_scene_get_stats(scenes[i], &stats);
        r->triangles = stats.triangles;
    }
    return RL_CLI_OK;
}

/* "bench: city: building grid" on stderr, unless -q. */
static void progress(const char *scene, const char *what, const char *name)
{
    if (rl_log_get_level() >= RL_LOG_INFO)
        fprintf(stderr, "bench: %s: %s %s\n", scene, what, name);
}

static rl_status build_accel(const rl_scene *scene, rl_accel_kind kind, int threads,
                             rl_accel **out)
{
    rl_accel *accel = NULL;
    rl_clear_error();
    rl_status st = rl_accel_create(scene, &(rl_accel_desc){ .kind = kind, .threads = threads },
                                   &accel);
    if (st == RL_OK && (st = rl_accel_commit(accel)) != RL_OK) {
        rl_accel_release(accel);
        accel = NULL;
    }
    *out = accel;
    return st;
}

static void set_reason(char *reason, size_t size, rl_status st)
{
    const char *msg = rl_last_error();
    snprintf(reason, size, "%s", msg && *msg ? msg : rl_status_string(st));
}

/* Times every built accelerator on every workload, interleaved
 * (bench_time_rays), and fills Mrays/s. */
static void measure(rl_accel **built, const bench_rays *rays, const bench_params *p,
                    bench_scene_result *sc)
{
    const rl_accel *list[RL_ACCEL_KIND_COUNT];
    bench_accel_result *which[RL_ACCEL_KIND_COUNT];
    bench_timing timing[RL_ACCEL_KIND_COUNT];
    int n = 0;
    for (int i = 0; i < sc->num_accels; i++)
        if (built[i]) {
            list[n] = built[i];
            which[n++] = &sc->accels[i];
        }
    for (int w = 0; w < RL_BENCH_WORKLOADS; w++) {
        if (rays->count[w] == 0 || n == 0)
            continue;
        progress(sc->label, "tracing", bench_workload_name(w));
        bench_time_rays(list, NULL, n, rays->rays[w], rays->count[w], w == RL_BENCH_SHADOW,
                        p->threads, p->min_runs, p->max_runs, p->min_total_s, timing);
        for (int k = 0; k < n; k++) {
            which[k]->timing[w] = timing[k];
            if (timing[k].best_s > 0.0)
                which[k]->mrays_per_s[w] = (double)rays->count[w] / timing[k].best_s * 1e-6;
            if (timing[k].best_cpu_s > 0.0)
                which[k]->mrays_per_cpu_s[w] =
                    (double)rays->count[w] / timing[k].best_cpu_s * 1e-6;
        }
    }
}

/* The packet section: bvh and embree, each with single queries and with
 * the batch queries (packets of 8), interleaved on the primary rays of 4x2
 * tiles and their shadow rays; CPU-time ratios to Embree's packets and to
 * single rays. Returns the number of workloads whose hit counts differ. */
static int measure_packets(const rl_scene *scene, const rl_camera *cam, const rl_accel *ref,
                           rl_accel **built, const bench_params *p, bench_scene_result *sc)
{
    const rl_accel *list[RL_BENCH_PACKET_RUNS];
    bool batched[RL_BENCH_PACKET_RUNS];
    int n = 0;
    for (int i = 0; i < sc->num_accels; i++) {
        rl_accel_kind k = sc->accels[i].kind;
        if (!built[i] || (k != RL_ACCEL_BVH && k != RL_ACCEL_EMBREE) || n + 2 > RL_BENCH_PACKET_RUNS)
            continue;
        for (int mode = 0; mode < 2; mode++) {
            list[n] = built[i];
            batched[n] = mode == 1;
            bench_packet_result *r = &sc->packet_runs[n++];
            *r = (bench_packet_result){ .kind = k, .packets = mode == 1 };
            for (int w = 0; w < RL_BENCH_PACKET_WORKLOADS; w++) {
                r->timing[w] = (bench_timing){ .deterministic = true };
                r->mrays_per_s[w] = r->mrays_per_cpu_s[w] = NAN;
                r->cpu_ratio_to_embree_packets[w] = r->cpu_ratio_to_single[w] = NAN;
            }
        }
    }
    if (n == 0)
        return 0;
    bench_rays rays = { { NULL }, { 0 } };
    if (!bench_make_packet_rays(scene, cam, ref, p->threads, &rays)) {
        if (rl_log_get_level() >= RL_LOG_WARN)
            fprintf(stderr, "rl: warning: bench: %s: out of memory for the packet workloads\n",
                    sc->label);
        return 0;
    }
    sc->num_packet_runs = n;
    static const int workload[RL_BENCH_PACKET_WORKLOADS] = { RL_BENCH_PRIMARY, RL_BENCH_SHADOW };
    int mismatches = 0;
    for (int w = 0; w < RL_BENCH_PACKET_WORKLOADS; w++) {
        size_t count = rays.count[workload[w]];
        sc->packet_rays[w] = count;
        sc->packet_hits_agree[w] = true;
        if (count == 0)
            continue;
        progress(sc->label, "tracing packets of", bench_workload_name(workload[w]));
        bench_timing timing[RL_BENCH_PACKET_RUNS];
        bench_time_rays(list, batched, n, rays.rays[workload[w]], count,
                        workload[w] == RL_BENCH_SHADOW, p->threads, p->min_runs, p->max_runs,
                        p->min_total_s, timing);
        const bench_packet_result *embree_packets = NULL;
        for (int k = 0; k < n; k++) {
            bench_packet_result *r = &sc->packet_runs[k];
            r->timing[w] = timing[k];
            if (timing[k].best_s > 0.0)
                r->mrays_per_s[w] = (double)count / timing[k].best_s * 1e-6;
            if (timing[k].best_cpu_s > 0.0)
                r->mrays_per_cpu_s[w] = (double)count / timing[k].best_cpu_s * 1e-6;
            if (r->kind == RL_ACCEL_EMBREE && r->packets)
                embree_packets = r;
            if (timing[k].hits != timing[0].hits)
                sc->packet_hits_agree[w] = false;
        }
        for (int k = 0; k < n; k++) {
            bench_packet_result *r = &sc->packet_runs[k];
            if (embree_packets)
                r->cpu_ratio_to_embree_packets[w] = r->mrays_per_cpu_s[w] /
                                                    embree_packets->mrays_per_cpu_s[w];
            /* Runs come in pairs: single, then packets of the same accel. */
            const bench_packet_result *single = &sc->packet_runs[k & ~1];
            r->cpu_ratio_to_single[w] = r->mrays_per_cpu_s[w] / single->mrays_per_cpu_s[w];
        }
        if (!sc->packet_hits_agree[w]) {
            mismatches++;
            if (rl_log_get_level() >= RL_LOG_WARN) {
                fprintf(stderr, "rl: warning: bench: %s packets %s: hit counts differ:", sc->label,
                        bench_workload_name(workload[w]));
                for (int k = 0; k < n; k++)
                    fprintf(stderr, " %s/%s %llu", rl_accel_kind_name(sc->packet_runs[k].kind),
                            sc->packet_runs[k].packets ? "packets" : "single",
                            (unsigned long long)sc->packet_runs[k].timing[w].hits);
                fprintf(stderr, " (of %zu rays)\n", count);
            }
        }
    }
    bench_rays_free(&rays);
    return mismatches;
}

/* Ratios to Embree of the same run, and the hit-count check; returns the
 * number of workloads where the accelerators disagree. */
static int compare(bench_scene_result *sc)
{
    const bench_accel_result *embree = NULL, *first = NULL;
    for (int i = 0; i < sc->num_accels; i++) {
        const bench_accel_result *a = &sc->accels[i];
        if (strcmp(a->status, "ok") != 0)
            continue;
        first = first ? first : a;
        if (a->kind == RL_ACCEL_EMBREE)
            embree = a;
    }
    int mismatches = 0;
    for (int w = 0; w < RL_BENCH_WORKLOADS; w++)
        sc->hits_agree[w] = true;
    if (!first)
        return 0;
    for (int w = 0; w < RL_BENCH_WORKLOADS; w++) {
        for (int i = 0; i < sc->num_accels; i++) {
            bench_accel_result *a = &sc->accels[i];
            if (strcmp(a->status, "ok") != 0)
                continue;
            if (embree) {
                a->ratio_to_embree[w] = a->mrays_per_s[w] / embree->mrays_per_s[w];
                a->cpu_ratio_to_embree[w] = a->mrays_per_cpu_s[w] / embree->mrays_per_cpu_s[w];
            }
            if (a->timing[w].hits != first->timing[w].hits)
                sc->hits_agree[w] = false;
            if (!a->timing[w].deterministic && rl_log_get_level() >= RL_LOG_WARN)
                fprintf(stderr, "rl: warning: bench: %s %s: %s found different hit counts "
                                "in different passes\n",
                        sc->label, bench_workload_name(w), rl_accel_kind_name(a->kind));
        }
        if (sc->hits_agree[w])
            continue;
        mismatches++;
        if (rl_log_get_level() >= RL_LOG_WARN) {
            fprintf(stderr, "rl: warning: bench: %s %s: hit counts differ:", sc->label,
                    bench_workload_name(w));
            for (int i = 0; i < sc->num_accels; i++)
                if (strcmp(sc->accels[i].status, "ok") == 0)
                    fprintf(stderr, " %s %llu", rl_accel_kind_name(sc->accels[i].kind),
                            (unsigned long long)sc->accels[i].timing[w].hits);
            fprintf(stderr, " (of %zu rays)\n", sc->rays[w]);
        }
    }
    return mismatches;
}

/* Runs every accelerator on one scene; false when something failed. */
static bool run_scene(const rl_scene *scene, const bench_args *a, const bench_params *p,
                      bench_scene_result *sc)
{
    rl_camera cam;
    rl_clear_error();
    rl_status st = rl_scene_get_camera(scene, NULL, &cam);
    if (st == RL_OK) {
        cam.width = p->width;
        cam.height = p->height;
        st = rl_camera_validate(&cam);
    }
    if (st != RL_OK) {
        sc->status = "failed";
        set_reason(sc->reason, sizeof sc->reason, st);
        return false;
    }
    sc->width = p->width;
    sc->height = p->height;

    /* Primary hits for the secondary workloads come from a structure that is
     * fast to build and trusted: brute force for tiny scenes, else the BVH. */
    rl_accel_kind ref_kind = sc->triangles <= TINY_SCENE ? RL_ACCEL_BRUTE : RL_ACCEL_BVH;
    rl_accel *ref = NULL;
    bench_rays rays = { { NULL }, { 0 } };
    progress(sc->label, "workloads from primary hits of", rl_accel_kind_name(ref_kind));
    st = build_accel(scene, ref_kind, p->threads, &ref);
    if (st == RL_OK && !bench_make_rays(scene, &cam, ref, p->seed, p->threads, &rays))
        st = RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        sc->status = "failed";
        set_reason(sc->reason, sizeof sc->reason, st);
        rl_accel_release(ref);
        return false;
    }
    for (int w = 0; w < RL_BENCH_WORKLOADS; w++)
        sc->rays[w] = rays.count[w];

    /* Build everything first, so that the passes can be interleaved. */
    rl_accel *built[RL_ACCEL_KIND_COUNT] = { NULL };
    bool ok = true;
    for (int i = 0; i < sc->num_accels; i++) {
        bench_accel_result *r = &sc->accels[i];
        r->kind = a->accels[i];
        r->status = "ok";
        for (int w = 0; w < RL_BENCH_WORKLOADS; w++) {
            r->timing[w] = (bench_timing){ .deterministic = true };
            r->mrays_per_s[w] = r->ratio_to_embree[w] = NAN;
            r->mrays_per_cpu_s[w] = r->cpu_ratio_to_embree[w] = NAN;
        }
        if (!rl_accel_kind_available(r->kind)) {
            r->status = "unavailable";
            snprintf(r->reason, sizeof r->reason, "%s is not in this build",
                     rl_accel_kind_name(r->kind));
            continue;
        }
        if (r->kind == ref_kind) {
            /* The reference was built with the same settings: reuse it. */
            built[i] = ref;
            st = RL_OK;
        } else {
            progress(sc->label, "building", rl_accel_kind_name(r->kind));
            st = build_accel(scene, r->kind, p->threads, &built[i]);
        }
        if (st != RL_OK) {
            r->status = "failed";
            set_reason(r->reason, sizeof r->reason, st);
            ok = false;
            continue;
        }
        rl_accel_get_stats(built[i], &r->stats);
    }
    measure(built, &rays, p, sc);
    bench_rays_free(&rays);   /* the packet workloads may be large too */
    sc->packet_mismatches = measure_packets(scene, &cam, ref, built, p, sc);
    for (int i = 0; i < sc->num_accels; i++)
        if (built[i] != ref)
            rl_accel_release(built[i]);
    rl_accel_release(ref);
    return ok;
}

static void print_header(void)
{
    /* Group titles over the workload columns (see the widths below). */
    printf("%76s%s  %s  %s\n", "", "---------- Mrays/s ----------", "--- ratio to embree ---",
           "--- ratio, CPU time ---");
    printf("%-30s %9s %-7s %9s %8s %6s  %9s %9s %9s  %7s %7s %7s  %7s %7s %7s\n", "scene",
           "triangles", "accel", "build ms", "MiB", "B/tri", "primary", "shadow", "diffuse",
           "primary", "shadow", "diffuse", "primary", "shadow", "diffuse");
}

static void print_scene(const bench_scene_result *sc)
{
    if (strcmp(sc->status, "ok") != 0) {
        printf("%-30s %s: %s\n", sc->label, sc->status, sc->reason);
        return;
    }
    for (int i = 0; i < sc->num_accels; i++) {
        const bench_accel_result *r = &sc->accels[i];
        printf("%-30s %9llu %-7s", sc->label, (unsigned long long)sc->triangles,
               rl_accel_kind_name(r->kind));
        if (strcmp(r->status, "ok") != 0) {
            printf(" %s: %s\n", r->status, r->reason);
            continue;
        }
        printf(" %9.1f %8.2f %6.1f ", r->stats.build_ms,
               (double)r->stats.memory_bytes / (1024.0 * 1024.0), r->stats.bytes_per_triangle);
        for (int w = 0; w < RL_BENCH_WORKLOADS; w++) {
            if (isfinite(r->mrays_per_s[w]))
                printf(" %9.2f", r->mrays_per_s[w]);
            else
                printf(" %9s", "-");
        }
        for (int cpu = 0; cpu < 2; cpu++) {
            const double *ratio = cpu ? r->cpu_ratio_to_embree : r->ratio_to_embree;
            putchar(' ');
            for (int w = 0; w < RL_BENCH_WORKLOADS; w++) {
                if (isfinite(ratio[w]))
                    printf(" %6.2fx", ratio[w]);
                else
                    printf(" %7s", "-");
            }
        }
        putchar('\n');
    }
    fflush(stdout);
}

/* The packet section of a scene: Mrays per CPU second and CPU-time ratios. */
static void print_packets(const bench_scene_result *sc)
{
    if (sc->num_packet_runs == 0)
        return;
    printf("  packets of 8 (%dx%d tiles)  %-8s  Mrays/CPU-s: %9s %9s   x single: %7s %7s   "
           "x embree packets: %7s %7s\n", RL_BENCH_PACKET_TILE_W, RL_BENCH_PACKET_TILE_H, "",
           "primary", "shadow", "primary", "shadow", "primary", "shadow");
    for (int k = 0; k < sc->num_packet_runs; k++) {
        const bench_packet_result *r = &sc->packet_runs[k];
        printf("  %-6s %-20s %-8s %13s", rl_accel_kind_name(r->kind),
               r->packets ? (r->kind == RL_ACCEL_EMBREE ? "rtcIntersect8" : "packets") : "single rays",
               "", "");
        for (int w = 0; w < RL_BENCH_PACKET_WORKLOADS; w++)
            isfinite(r->mrays_per_cpu_s[w]) ? printf(" %9.2f", r->mrays_per_cpu_s[w]) : printf(" %9s", "-");
        printf("   %9s", "");
        for (int w = 0; w < RL_BENCH_PACKET_WORKLOADS; w++)
            isfinite(r->cpu_ratio_to_single[w]) ? printf(" %6.2fx", r->cpu_ratio_to_single[w])
                                                : printf(" %7s", "-");
        printf("   %17s", "");
        for (int w = 0; w < RL_BENCH_PACKET_WORKLOADS; w++)
            isfinite(r->cpu_ratio_to_embree_packets[w]) ? printf(" %6.2fx", r->cpu_ratio_to_embree_packets[w])
                                                        : printf(" %7s", "-");
        putchar('\n');
    }
    fflush(stdout);
}

static int run(bench_args *a)
{
    char out[4096];
    if (!bench_out_path(a->out, "rays", out, sizeof out))
        return RL_CLI_FAIL;

    bench_params p = {
        .width = a->width, .height = a->height, .rays = a->rays, .threads = (int)a->threads,
        .quick = a->quick, .min_runs = a->quick ? 1 : 3, .max_runs = a->quick ? 1 : 100,
        .min_total_s = a->quick ? 0.0 : 0.5, .seed = 1,
    };
    rl_scene *scenes[MAX_SCENES] = { NULL };
    bench_scene_result results[MAX_SCENES];
    memset(results, 0, sizeof results);
    int rc = load_scenes(a, scenes, results);
    bool ok = true;
    int mismatches = 0;
    if (rc == RL_CLI_OK)
        print_header();
    for (int i = 0; rc == RL_CLI_OK && i < a->num_scenes; i++) {
        bench_scene_result *sc = &results[i];
        if (!scenes[i]) {
            print_scene(sc);    /* skipped */
            continue;
        }
        sc->accels = calloc((size_t)a->num_accels, sizeof *sc->accels);
        if (!sc->accels) {
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
            break;
        }
        sc->num_accels = a->num_accels;
        if (!run_scene(scenes[i], a, &p, sc))
            ok = false;
        if (strcmp(sc->status, "ok") == 0)
            mismatches += compare(sc) + sc->packet_mismatches;
        print_scene(sc);
        print_packets(sc);
        /* Free the scene now: the next one may be large. */
        rl_scene_release(scenes[i]);
        scenes[i] = NULL;
    }
    if (rc == RL_CLI_OK) {
        cJSON *report = bench_report_json(&p, results, a->num_scenes, mismatches);
        if (!report)
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
        else if (!cli_write_json(report, out))
            rc = RL_CLI_FAIL;
        else if (rl_log_get_level() >= RL_LOG_INFO)
            fprintf(stderr, "bench: wrote %s%s\n", out,
                    mismatches ? " (with hit-count mismatches, see warnings)" : "");
        cJSON_Delete(report);
    }
    if (rc == RL_CLI_OK && !ok)
        rc = cli_fail(RL_CLI_FAIL, "bench: some scenes or accelerators failed (see table)");
    for (int i = 0; i < a->num_scenes; i++) {
        rl_scene_release(scenes[i]);
        free(results[i].accels);
    }
    return rc;
}

int cli_bench(int argc, char **argv)
{
    if (argc >= 2 && strcmp(argv[1], "vt") == 0)
        return bench_vt(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "pt") == 0)
        return bench_pt(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "sampling") == 0)
        return bench_sampling(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "surfels") == 0)
        return bench_surfels(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "culling") == 0)
        return bench_culling(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "gl") == 0)
        return bench_gl(argc, argv);
    if (argc >= 2 && strcmp(argv[1], "dist") == 0)
        return bench_dist(argc, argv);
    bench_args a;
    memset(&a, 0, sizeof a);
    int rc = parse_args(argc, argv, &a);
    if (rc == RL_CLI_OK)
        rc = run(&a);
    free_args(&a);
    return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
}
