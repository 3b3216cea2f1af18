/* bench_pt_bdpt.c: `rl bench pt --only bdpt` (issue 37): the path tracer
 * "pt" at its defaults against the bidirectional path tracer "bdpt" at
 * equal time, on cornell:variant=bitterli (lit directly) and on
 * cornell:variant=shade (the lamp behind a plate: lit by bounces).
 *
 * Per scene: a bdpt reference of REF_SPP samples in two independent halves;
 * its own mean squared error, MSE(half A, half B) / 4, is subtracted from
 * every measured MSE (as bench_pt_conv.c). Each renderer then accumulates
 * frames of 1 spp after a warm-up frame (builds excluded) until its process
 * CPU time divided by the threads reaches the budget: on a shared machine
 * that is what a quiet machine's wall clock would show. Recorded: samples
 * reached, wall and CPU time, RMSE of linear RGB clamped to [0, 1] (the
 * lamp's radiance would otherwise decide it) against the reference, and the
 * channel means (unclamped) of the image and of the reference. */
#define _POSIX_C_SOURCE 200809L
#include "bench_pt_bdpt.h"

#include "bench_util.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "rl/rl_timer.h"

#define note(...) bench_note("pt", __VA_ARGS__)

static const char *const scenes[] = { "variant=bitterli", "variant=shade" };
#define NUM_SCENES (sizeof scenes / sizeof scenes[0])
/* A run: a renderer and its options ({key, value, ..., NULL}). */
typedef struct bd_config {
    const char *label, *algo;
    const char *const *opts;
} bd_config;

static const bd_config bdpt_configs[] = { { "pt", "pt", NULL }, { "bdpt", "bdpt", NULL } };

/* --only hybrid (Schröder 2017 Sec. 8.4): gl-pt with and without the CPU's
 * light paths; light_overlap=false traces them before each frame instead
 * of beside it, so its extra time over the overlapped run is the CPU work
 * the overlap hides. */
static const char *const hy_paths[] = { "light_paths", "1024", NULL };
static const char *const hy_sync[] = { "light_paths", "1024", "light_overlap", "false", NULL };
static const bd_config hybrid_configs[] = {
    { "gl-pt", "gl-pt", NULL },
    { "gl-pt light_paths=1024", "gl-pt", hy_paths },
    { "gl-pt light_paths=1024 light_overlap=false", "gl-pt", hy_sync },
};

/* A section: its sizes (quick, full), what its note says, its configs and
 * the JSON key of configs[0]'s RMSE over configs[1]'s. */
typedef struct bd_section {
    int size[2];
    long long ref_spp[2];
    double budget_s[2];
    const char *what;         /* the note's opening: "<section>: <renderers>" */
    const char *cpu_extra;    /* appended inside the note's "(s per thread...)" */
    const char *time_note;    /* the section's "time" entry */
    const bd_config *configs;
    int num_configs;
    const char *ratio_key;
} bd_section;

static float disp(float v)
{
    return v < 0.0f ? 0.0f : (v < 1.0f ? v : 1.0f);
}

static rl_status make(const char *algo, int threads, const char *seed, long long spp, rl_renderer **out)
{
    char buf[32];
    rl_status st = rl_renderer_create(algo, out);
    snprintf(buf, sizeof buf, "%d", threads);
    if (st == RL_OK) st = rl_renderer_set(*out, "threads", buf);
    snprintf(buf, sizeof buf, "%lld", spp);
    if (st == RL_OK) st = rl_renderer_set(*out, "spp", buf);
    if (st == RL_OK) st = rl_renderer_set(*out, "seed", seed);
    return st;
}

/* Squared error of img against ref (clamped), summed over n pixels x 3. */
static double mse(const rl_image *img, const float *ref, size_t n)
{
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        const float c[3] = { img->color[i].x, img->color[i].y, img->color[i].z };
        for (int k = 0; k < 3; ++k) {
            double d = disp(c[k]) - disp(ref[3 * i + k]);
            sum += d * d;
        }
    }
    return sum / (3.0 * (double)n);
}

static void add_means(cJSON *o, const char *key, const double m[3])
{
    cJSON *a = cJSON_AddArrayToObject(o, key);
    for (int k = 0; k < 3; ++k)
        cJSON_AddItemToArray(a, cJSON_CreateNumber(m[k]));
}

static rl_status run_scene(const bench_pt_bdpt_args *a, const char *params, int size, long long ref_spp,
                           double budget_s, const bd_section *sect, cJSON *out)
{
    const bd_config *configs = sect->configs;
    const int num_configs = sect->num_configs;
    rl_scene *scene = NULL;
    rl_status st = rl_scene_create_builtin("cornell", params, &scene);
    rl_camera cam;
    if (st == RL_OK) st = rl_scene_get_camera(scene, NULL, &cam);
    if (st != RL_OK) {
        rl_scene_release(scene);
        return st;
    }
    cam.width = cam.height = size;
    size_t n = (size_t)size * size;
    float *ref = calloc(3 * n, sizeof *ref), *half = calloc(3 * n, sizeof *half);
    rl_image *img = NULL;
    if (!ref || !half || rl_image_create(size, size, RL_LAYER_COLOR, &img) != RL_OK) {
        free(ref);
        free(half);
        rl_scene_release(scene);
        return RL_ERR_OUT_OF_MEMORY;
    }
    /* The reference in two halves: their mean, and its own error. */
    rl_timer timer;
    rl_timer_start(&timer);
    double ref_mse = 0.0, ref_means[3] = { 0.0, 0.0, 0.0 };
    static const char *const ref_seeds[2] = { "4242", "4343" };
    for (int h = 0; h < 2 && st == RL_OK; ++h) {
        rl_renderer *r = NULL;
        rl_render_stats s;
        st = make("bdpt", a->threads, ref_seeds[h], ref_spp / 2, &r);
        if (st == RL_OK) st = rl_renderer_render(r, scene, &cam, img, &s);
        rl_renderer_release(r);
        for (size_t i = 0; st == RL_OK && i < n; ++i) {
            const float c[3] = { img->color[i].x, img->color[i].y, img->color[i].z };
            for (int k = 0; k < 3; ++k) {
                if (h == 0) {
                    half[3 * i + k] = c[k];
                } else {
                    double d = disp(c[k]) - disp(half[3 * i + k]);
                    ref_mse += d * d;
                    ref[3 * i + k] = 0.5f * (c[k] + half[3 * i + k]);
                    ref_means[k] += ref[3 * i + k] / (double)n;
                }
            }
        }
    }
    ref_mse /= 4.0 * 3.0 * (double)n;
    double ref_ms = rl_timer_ms(&timer);
    if (st == RL_OK) {
        cJSON_AddStringToObject(out, "scene", params);
        bench_add_num(out, "reference_spp", (double)ref_spp);
        bench_add_num(out, "reference_ms", ref_ms);
        bench_add_num(out, "reference_rmse", sqrt(ref_mse));
        add_means(out, "reference_means", ref_means);
    }
    cJSON *runs = st == RL_OK ? cJSON_AddArrayToObject(out, "runs") : NULL;
    double rmse_of[8] = { 0.0 };
    for (int k = 0; k < num_configs && k < 8 && st == RL_OK; ++k) {
        const bd_config *c = &configs[k];
        rl_renderer *r = NULL;
        rl_render_stats s;
        /* Warm-up under another seed (builds the BVH and the light table;
         * gl-pt: the context and its shaders), then the seed change
         * restarts the accumulation. */
        st = make(c->algo, a->threads, "9", 1, &r);
        for (int i = 0; st == RL_OK && c->opts && c->opts[i]; i += 2)
            st = rl_renderer_set(r, c->opts[i], c->opts[i + 1]);
        if (st == RL_OK) st = rl_renderer_render(r, scene, &cam, img, &s);
        if (st == RL_OK) st = rl_renderer_set(r, "seed", "1");
        bench_budget_run run = { 0 };
        if (st == RL_OK)
            st = bench_render_for_cpu(r, scene, &cam, img, a->threads, budget_s, &run);
        double wall = run.wall_ms, cpu = run.cpu_ms;
        long long spp = run.frames;
        rl_renderer_release(r);
        if (st != RL_OK)
            break;
        double e = mse(img, ref, n) - ref_mse;
        double rmse = sqrt(e > 0.0 ? e : 0.0), m[3] = { 0.0, 0.0, 0.0 };
        for (size_t i = 0; i < n; ++i) {
            m[0] += img->color[i].x / (double)n;
            m[1] += img->color[i].y / (double)n;
            m[2] += img->color[i].z / (double)n;
        }
        rmse_of[k] = rmse;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "algo", c->label);
        bench_add_num(o, "spp", (double)spp);
        bench_add_num(o, "wall_ms", wall);
        bench_add_num(o, "cpu_ms", cpu);
        bench_add_num(o, "fps", spp > 0 && wall > 0.0 ? 1e3 * (double)spp / wall : 0.0);
        bench_add_num(o, "rmse", rmse);
        add_means(o, "means", m);
        cJSON_AddItemToArray(runs, o);
        printf("%-18s %-5s %6lld spp %8.1f s cpu/thr %8.1f s wall  RMSE %.5f  means %.4f %.4f %.4f "
               "(ref %.4f %.4f %.4f)\n", params, c->label, spp, cpu / 1e3 / a->threads, wall / 1e3, rmse, m[0],
               m[1], m[2], ref_means[0], ref_means[1], ref_means[2]);
        fflush(stdout);
    }
    if (st == RL_OK)
        bench_add_num(out, sect->ratio_key, bench_ratio(rmse_of[0], rmse_of[1]));
    rl_image_release(img);
    free(ref);
    free(half);
    rl_scene_release(scene);
    return st;
}

/* One section: the note, its settings, then every scene with its configs. */
static rl_status run_section(const bench_pt_bdpt_args *a, const bd_section *sect, cJSON *sec)
{
    int size = sect->size[!a->quick];
    long long ref_spp = sect->ref_spp[!a->quick];
    double budget_s = sect->budget_s[!a->quick];
    note("%s at equal CPU time (%.1f s per thread%s) on cornell, %dx%d, reference bdpt %lld spp", sect->what,
         budget_s, sect->cpu_extra, size, size, ref_spp);
    cJSON_AddStringToObject(sec, "error", "RMSE of linear RGB clamped to [0,1], all pixels and channels, against "
                                          "a bdpt reference in two halves, its own MSE subtracted");
    cJSON_AddStringToObject(sec, "time", sect->time_note);
    bench_add_num(sec, "size", size);
    bench_add_num(sec, "budget_s", budget_s);
    bench_add_num(sec, "threads", a->threads);
    cJSON *list = cJSON_AddArrayToObject(sec, "scenes");
    rl_status st = RL_OK;
    for (size_t i = 0; i < NUM_SCENES && st == RL_OK; ++i) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(list, o);
        st = run_scene(a, scenes[i], size, ref_spp, budget_s, sect, o);
    }
    return st;
}

#define TIME_NOTE "frames of 1 spp after a warm-up frame until process CPU time / threads reaches budget_s"

rl_status bench_pt_bdpt(const bench_pt_bdpt_args *a, cJSON *sec)
{
    static const bd_section bdpt = {
        .size = { 32, 96 }, .ref_spp = { 64, 512 }, .budget_s = { 0.5, 5.0 },
        .what = "bdpt: pt and bdpt", .cpu_extra = "", .time_note = TIME_NOTE,
        .configs = bdpt_configs, .num_configs = 2, .ratio_key = "rmse_ratio_pt_over_bdpt",
    };
    return run_section(a, &bdpt, sec);
}

rl_status bench_pt_hybrid(const bench_pt_bdpt_args *a, cJSON *sec)
{
    static const bd_section hybrid = {
        .size = { 32, 48 }, .ref_spp = { 64, 1024 }, .budget_s = { 1.0, 5.0 },
        .what = "hybrid: gl-pt without and with light paths (Sec. 8.4)",
        .cpu_extra = ", the GL driver's threads included", .time_note = TIME_NOTE "; fps = frames / wall",
        .configs = hybrid_configs, .num_configs = 3, .ratio_key = "rmse_ratio_off_over_light_paths",
    };
    return run_section(a, &hybrid, sec);
}
