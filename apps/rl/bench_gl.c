/* bench_gl.c: `rl bench gl`: a quick overview of the OpenGL 4.5 backend
 * (docs/gl.md) against the software paths it mirrors, on every built-in
 * scene, as a table and one JSON record that names the GL vendor,
 * renderer and version besides the machine:
 *   frames      gl-raster vs raster at 640x480 with their defaults: the
 *               first frame (and of it the preparation: context, shaders,
 *               buffers on GL; nothing to build for raster) apart from the
 *               minimum of N warm frames; the GL/software ratio of the
 *               minima; and the share of pixels whose object IDs agree
 *   visibility  the visibility property (Jähn 2015, Sec. 4.2.2) with
 *               backend=gl vs software at a few positions on the scene's
 *               diagonal: commit time and time per position (mean and
 *               minimum), one worker each (the software rasterizer then
 *               uses every thread, as llvmpipe does); and whether the two
 *               agree: values equal, per-object pixels that differ
 *   pt          gl-pt vs pt (Schröder 2017's path tracer on GL compute
 *               shaders and on the CPU) at the same spp per frame on
 *               cornell (or --scenes) at 256x256: first frame (and its
 *               preparation) and the minimum of N warm frames, their
 *               ratio, and gl-pt's frames per second
 *   linespace   Line Space generation (Schröder 2017, Table 1's scenes and
 *               voxel resolutions, dynamic candidate lists) on the GPU
 *               (compute shaders, gl_linespace.c) vs the CPU build (every
 *               thread): GL_TIME_ELAPSED, GL_TIMESTAMP and wall ms on GL,
 *               build ms on the CPU, the thesis' ms beside them, and
 *               whether both give the same numbers of occupied shafts and
 *               candidates (the test compares the arrays themselves)
 * Speed ratios come from the same run on the same machine. Besides wall
 * time every figure has the process's CPU time (all threads, llvmpipe's
 * included), which a machine shared with other work inflates less. On llvmpipe
 * (Mesa's CPU rasterizer) the GL figures are no GPU figures: they say what
 * the GL path costs where there is no GPU, and that it runs. */
#define _POSIX_C_SOURCE 200809L
#include "bench_gl.h"

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
#include "rl/rl_property.h"

#define note(...) (fflush(stdout), bench_note("gl", __VA_ARGS__))

static const char bench_gl_help[] =
    "usage: rl bench gl [options]\n"
    "\n"
    "A quick overview of the OpenGL backend against the software paths, on\n"
    "every built-in scene (about a minute on llvmpipe, 2 cores). Sections:\n"
    "  frames      gl-raster vs raster: first frame (and its preparation) and\n"
    "              the minimum of N warm frames, ratio, object IDs that agree\n"
    "  visibility  the visibility property, backend=gl vs software: commit and\n"
    "              time per position, ratio, and whether the counts agree\n"
    "  pt          gl-pt vs pt at the same spp: first frame, minimum of N warm\n"
    "              frames (ms), ratio, gl-pt frames per second; cornell unless\n"
    "              --scenes names others\n"
    "  linespace   Line Space generation on GL vs CPU for the first rows of\n"
    "              Schröder 2017's Table 1 (ls-cornell scenes), the thesis' ms beside\n"
    "              ours\n"
    "The record names the GL vendor, renderer and version.\n"
    "\n"
    "options:\n"
    "  --scenes A,B,...  default every built-in scene, city as city:blocks=4\n"
    "  --size WxH        frames: image size; default 640x480\n"
    "  --frames N        frames: warm frames per renderer (minimum); default 5\n"
    "  --resolution N    visibility: cube-face side; default 256\n"
    "  --positions N     visibility: positions per scene; default 4\n"
    "  --ls-rows N       linespace: Table 1 rows 1..N (1..8); default 1 (llvmpipe\n"
    "                    needs about a minute for row 1, a GPU runs all 8)\n"
    "  --device D        EGL device (rl_gl.h); default $RL_EGL_DEVICE, else auto\n"
    "  --pt-size WxH     pt: image size; default 256x256\n"
    "  --pt-spp N        pt: samples per pixel and frame of both; default 1\n"
    "  --pt-gl-only      pt: time gl-pt alone (no pt frames to wait for)\n"
    "  --pt-backend A,B  pt: rows per backend of both (shadow and diffuse rays):\n"
    "                    bvh, grid, ls-candidates, ls-pnmt, ls-preillum; default bvh;\n"
    "                    shadowmap: shadow maps for shadows, the BVH for diffuse rays\n"
    "  --pt-grid-res N   pt: voxels per axis of the grid and the Line Space (0: the\n"
    "                    grid heuristic); default 0\n"
    "  --only A,B        sections: frames, visibility, pt, linespace\n"
    "  --out FILE.json   default bench/results/gl-YYYYMMDD-HHMMSS.json\n"
    "  --quick           tiny run: cornell and spheres, 160x120, 2 frames,\n"
    "                    resolution 32, 2 positions, pt at 64x64;\n"
    "                    linespace: row 1's scene at 4^3 voxels, N = 2 (no thesis row)\n"
    "\n"
    "example:\n"
    "  RL_EGL_DEVICE=surfaceless rl bench gl --only frames --scenes cornell,table\n";

enum { SEC_FRAMES, SEC_VISIBILITY, SEC_PT, SEC_LINESPACE, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "frames", "visibility", "pt", "linespace" };

#define MAX_SCENES 16
#define PT_MAX_BACKENDS 6
static const char *const pt_backend_names[PT_MAX_BACKENDS] = { "bvh", "grid", "ls-candidates", "ls-pnmt",
                                                               "ls-preillum", "shadowmap" };

typedef struct bgl_args {
    const char *scenes_text, *out, *device;
    int width, height;
    int pt_width, pt_height;
    long long frames, resolution, positions, pt_spp, ls_rows, pt_grid_res;
    unsigned sections;
    bool quick;
    bool pt_gl_only;              /* pt: gl-pt alone (a GPU's fps at sizes where pt takes seconds) */
    const char *pt_backend_text;  /* pt: the --pt-backend list */
    const char *pt_backends[PT_MAX_BACKENDS];
    int num_pt_backends;
} bgl_args;

typedef struct bgl_ctx {
    bgl_args *a;
    char *names[MAX_SCENES];      /* malloc'd */
    rl_scene *scenes[MAX_SCENES];
    int num_scenes;
    char reason[512];
} bgl_ctx;

/* The default list: every built-in scene, city smaller than its default
 * (1.4 M triangles take seconds per frame on llvmpipe). */
static bool default_scenes(bgl_ctx *c)
{
    size_t count = 0;
    const rl_builtin_info *b = rl_builtin_scenes(&count);
    for (size_t i = 0; i < count && c->num_scenes < MAX_SCENES; ++i) {
        const char *name = strcmp(b[i].name, "city") == 0 ? "city:blocks=4" : b[i].name;
        if (!(c->names[c->num_scenes++] = strdup(name)))
            return false;
    }
    return true;
}

/* --scenes: names separated by commas; "k=v" items continue the previous
 * scene's parameters, as in rl bench rays. */
static int parse_scenes(bgl_ctx *c, const char *text)
{
    const char *p = text;
    while (*p) {
        const char *end = strchr(p, ',');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        bool param = memchr(p, '=', n) != NULL && c->num_scenes > 0;
        if (n == 0)
            return cli_fail(RL_CLI_USAGE, "--scenes: empty name in '%s'", text);
        if (param) {
            char *last = c->names[c->num_scenes - 1];
            size_t len = strlen(last);
            char *s = realloc(last, len + n + 2);
            if (!s)
                return cli_fail(RL_CLI_FAIL, "out of memory");
            s[len] = strchr(s, ':') ? ',' : ':';
            memcpy(s + len + 1, p, n);
            s[len + n + 1] = '\0';
            c->names[c->num_scenes - 1] = s;
        } else {
            if (c->num_scenes >= MAX_SCENES)
                return cli_fail(RL_CLI_USAGE, "--scenes: at most %d scenes", MAX_SCENES);
            char *s = malloc(n + 1);
            if (!s)
                return cli_fail(RL_CLI_FAIL, "out of memory");
            memcpy(s, p, n);
            s[n] = '\0';
            c->names[c->num_scenes++] = s;
        }
        p = end ? end + 1 : p + n;
    }
    return RL_CLI_OK;
}

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bgl_args *a)
{
    a->sections = (1u << SEC_COUNT) - 1;
    bool has_size = false, has_frames = false, has_res = false, has_pos = false, has_pt_size = false,
         has_pt_spp = false, has_rows = false;
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_STRING("--scenes", &a->scenes_text),
        RL_BENCH_SIZE("--size", &a->width, &a->height, &has_size),
        RL_BENCH_COUNT("--frames", 1000, &a->frames, &has_frames),
        RL_BENCH_COUNT("--resolution", 4096, &a->resolution, &has_res),
        RL_BENCH_COUNT("--positions", 1000, &a->positions, &has_pos),
        RL_BENCH_COUNT("--ls-rows", 8, &a->ls_rows, &has_rows),
        RL_BENCH_STRING("--device", &a->device),
        RL_BENCH_SIZE("--pt-size", &a->pt_width, &a->pt_height, &has_pt_size),
        RL_BENCH_COUNT("--pt-spp", 65536, &a->pt_spp, &has_pt_spp),
        RL_BENCH_FLAG("--pt-gl-only", &a->pt_gl_only),
        RL_BENCH_STRING("--pt-backend", &a->pt_backend_text),
        RL_BENCH_COUNT("--pt-grid-res", 1024, &a->pt_grid_res, NULL),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench gl", bench_gl_help, rows, (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    if (!has_size) {
        a->width = a->quick ? 160 : 640;
        a->height = a->quick ? 120 : 480;
    }
    if (!has_frames)
        a->frames = a->quick ? 2 : 5;
    if (!has_res)
        a->resolution = a->quick ? 32 : 256;
    if (!has_pos)
        a->positions = a->quick ? 2 : 4;
    if (!has_pt_size)
        a->pt_width = a->pt_height = a->quick ? 64 : 256;
    if (!has_pt_spp)
        a->pt_spp = 1;
    if (!has_rows)
        a->ls_rows = 1;
    /* the names point into pt_backend_names, so they outlive the text */
    const char *text = a->pt_backend_text ? a->pt_backend_text : "bvh";
    for (const char *p = text; *p;) {
        size_t len = strcspn(p, ",");
        int found = -1;
        for (int k = 0; k < PT_MAX_BACKENDS; ++k)
            if (strlen(pt_backend_names[k]) == len && strncmp(p, pt_backend_names[k], len) == 0)
                found = k;
        if (found < 0 || a->num_pt_backends == PT_MAX_BACKENDS) {
            fprintf(stderr, "rl: error: bench gl: --pt-backend %s: one to %d of bvh, grid, ls-candidates, "
                    "ls-pnmt, ls-preillum, shadowmap\n", text, PT_MAX_BACKENDS);
            return RL_CLI_USAGE;
        }
        a->pt_backends[a->num_pt_backends++] = pt_backend_names[found];
        p += len + (p[len] == ',');
    }
    if (a->num_pt_backends == 0) {
        fprintf(stderr, "rl: error: bench gl: --pt-backend is empty\n");
        return RL_CLI_USAGE;
    }
    if (!a->device)
        a->device = "";
    return RL_CLI_OK;
}

/* ---------------------------------------------------------------- frames */

/* CPU time of the whole process (every thread), s. */
static double cpu_s(void)
{
    struct timespec t;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) == 0 ? (double)t.tv_sec + 1e-9 * (double)t.tv_nsec : NAN;
}

/* One renderer's frames of one scene. */
typedef struct frame_times {
    double first_ms, first_prep_ms, min_ms;
    double min_cpu_ms;            /* the least CPU time of a warm frame */
    double *warm_ms;              /* frames entries */
    rl_image *img;                /* the last frame */
} frame_times;

/* opts: NULL or key, value, ..., NULL. */
static rl_status time_frames(const bgl_ctx *c, const char *algo, const char *const *opts, const rl_scene *scene,
                             const rl_camera *cam, frame_times *t)
{
    const bgl_args *a = c->a;
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create(algo, &r);
    if (st == RL_OK && strncmp(algo, "gl-", 3) == 0 && a->device[0])
        st = rl_renderer_set(r, "device", a->device);
    for (int k = 0; st == RL_OK && opts && opts[k]; k += 2)
        st = rl_renderer_set(r, opts[k], opts[k + 1]);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &t->img);
    t->warm_ms = st == RL_OK ? calloc((size_t)a->frames, sizeof *t->warm_ms) : NULL;
    if (st == RL_OK && !t->warm_ms)
        st = RL_ERR_OUT_OF_MEMORY;
    t->min_ms = t->min_cpu_ms = INFINITY;
    for (long long k = -1; st == RL_OK && k < a->frames; ++k) {
        rl_render_stats s;
        const double c0 = cpu_s();
        st = rl_renderer_render(r, scene, cam, t->img, &s);
        const double cpu_ms = 1e3 * (cpu_s() - c0);
        if (st != RL_OK)
            break;
        if (k < 0) {
            t->first_ms = s.time_ms;
            t->first_prep_ms = s.prep_ms;
        } else {
            t->warm_ms[k] = s.time_ms;
            t->min_ms = fmin(t->min_ms, s.time_ms);
            t->min_cpu_ms = fmin(t->min_cpu_ms, cpu_ms);
        }
    }
    rl_renderer_release(r);
    return st;
}

static cJSON *frames_json(const frame_times *t, long long frames)
{
    cJSON *o = cJSON_CreateObject();
    bench_add_num(o, "first_ms", t->first_ms);
    bench_add_num(o, "first_prep_ms", t->first_prep_ms);
    bench_add_num(o, "min_ms", t->min_ms);
    bench_add_num(o, "min_cpu_ms", t->min_cpu_ms);
    cJSON *w = cJSON_AddArrayToObject(o, "warm_ms");
    for (long long k = 0; k < frames; ++k)
        cJSON_AddItemToArray(w, cJSON_CreateNumber(round(t->warm_ms[k] * 1000.0) / 1000.0));
    return o;
}

static rl_status sec_frames(void *ctx, cJSON *sec)
{
    bgl_ctx *c = ctx;
    const bgl_args *a = c->a;
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    printf("\nframes %dx%d, default options: first frame (prep) and min of %lld warm frames, ms\n"
           "%-16s %10s %14s %16s %10s %10s %8s %8s %8s\n", a->width, a->height, a->frames, "scene", "triangles",
           "raster first", "gl first (prep)", "raster", "gl-raster", "gl/sw", "cpu", "IDs %");
    rl_status st = RL_OK;
    for (int i = 0; i < c->num_scenes && st == RL_OK; ++i) {
        const rl_scene *scene = c->scenes[i];
        rl_camera cam;
        st = rl_scene_get_camera(scene, NULL, &cam);
        if (st != RL_OK)
            break;
        cam.width = a->width;
        cam.height = a->height;
        frame_times sw = { 0 }, gl = { 0 };
        note("%s: raster", c->names[i]);
        st = time_frames(c, "raster", NULL, scene, &cam, &sw);
        if (st == RL_OK) {
            note("%s: gl-raster", c->names[i]);
            st = time_frames(c, "gl-raster", NULL, scene, &cam, &gl);
        }
        if (st == RL_OK) {
            const size_t n = (size_t)a->width * (size_t)a->height;
            size_t same = 0;
            for (size_t k = 0; k < n; ++k)
                same += gl.img->object_id[k] == sw.img->object_id[k];
            const double ids = 100.0 * (double)same / (double)n;
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "scene", c->names[i]);
            cJSON_AddNumberToObject(o, "triangles", rl_scene_get_data(scene)->num_triangles);
            cJSON_AddItemToObject(o, "raster", frames_json(&sw, a->frames));
            cJSON_AddItemToObject(o, "gl_raster", frames_json(&gl, a->frames));
            bench_add_num(o, "gl_over_raster_min", bench_ratio(gl.min_ms, sw.min_ms));
            bench_add_num(o, "gl_over_raster_min_cpu", bench_ratio(gl.min_cpu_ms, sw.min_cpu_ms));
            bench_add_num(o, "ids_equal_percent", ids);
            cJSON_AddItemToArray(rows, o);
            char first[40];
            snprintf(first, sizeof first, "%.1f (%.1f)", gl.first_ms, gl.first_prep_ms);
            printf("%-16s %10u %14.1f %16s %10.1f %10.1f %8.2f %8.2f %8.3f\n", c->names[i],
                   rl_scene_get_data(scene)->num_triangles, sw.first_ms, first, sw.min_ms, gl.min_ms,
                   bench_ratio(gl.min_ms, sw.min_ms), bench_ratio(gl.min_cpu_ms, sw.min_cpu_ms), ids);
        } else {
            snprintf(c->reason, sizeof c->reason, "%s: %s", c->names[i], rl_last_error());
        }
        free(sw.warm_ms);
        free(gl.warm_ms);
        rl_image_release(sw.img);
        rl_image_release(gl.img);
    }
    fflush(stdout);
    return st;
}

/* -------------------------------------------------------------------- pt */

/* gl-pt vs pt: the same options (their defaults: mis=on, rng=sobol, BVH),
 * the same spp per frame, frames accumulating as in a progressive run. */
static rl_status sec_pt(void *ctx, cJSON *sec)
{
    bgl_ctx *c = ctx;
    const bgl_args *a = c->a;
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    char spp[32];
    snprintf(spp, sizeof spp, "%lld", a->pt_spp);
    printf("\npt %dx%d, %s spp per frame: first frame (prep) and min of %lld warm frames, ms\n"
           "%-24s %-14s %10s %14s %16s %10s %10s %8s %8s %10s\n", a->pt_width, a->pt_height, spp, a->frames,
           "scene", "backend", "triangles", "pt first", "gl first (prep)", "pt", "gl-pt", "gl/cpu", "cpu",
           "gl-pt fps");
    rl_status st = RL_OK;
    for (int row = 0; row < c->num_scenes * a->num_pt_backends && st == RL_OK; ++row) {
        const int i = row / a->num_pt_backends;
        const char *backend = a->pt_backends[row % a->num_pt_backends];
        /* the backend for shadow and diffuse rays, as Diagram 1 sets both */
        char grid_res[32];
        snprintf(grid_res, sizeof grid_res, "%lld", a->pt_grid_res);
        /* shadow maps answer shadow tests only (Diagram 3) */
        const char *diffuse = strcmp(backend, "shadowmap") == 0 ? "bvh" : backend;
        const char *const opts[] = { "spp", spp, "shadow", backend, "diffuse", diffuse, "grid_res", grid_res, NULL };
        /* Path tracing every built-in scene would take minutes: cornell,
         * unless the scenes were named. */
        if (!a->scenes_text && strcmp(c->names[i], "cornell") != 0)
            continue;
        const rl_scene *scene = c->scenes[i];
        rl_camera cam;
        st = rl_scene_get_camera(scene, NULL, &cam);
        if (st != RL_OK)
            break;
        cam.width = a->pt_width;
        cam.height = a->pt_height;
        frame_times cpu = { 0 }, gl = { 0 };
        if (!a->pt_gl_only) {
            note("%s: pt, %s", c->names[i], backend);
            st = time_frames(c, "pt", opts, scene, &cam, &cpu);
        }
        if (st == RL_OK) {
            note("%s: gl-pt, %s", c->names[i], backend);
            st = time_frames(c, "gl-pt", opts, scene, &cam, &gl);
        }
        if (st == RL_OK) {
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "scene", c->names[i]);
            cJSON_AddStringToObject(o, "backend", backend);
            cJSON_AddNumberToObject(o, "triangles", rl_scene_get_data(scene)->num_triangles);
            if (!a->pt_gl_only) {
                cJSON_AddItemToObject(o, "pt", frames_json(&cpu, a->frames));
                bench_add_num(o, "gl_over_pt_min", bench_ratio(gl.min_ms, cpu.min_ms));
                bench_add_num(o, "gl_over_pt_min_cpu", bench_ratio(gl.min_cpu_ms, cpu.min_cpu_ms));
            }
            cJSON_AddItemToObject(o, "gl_pt", frames_json(&gl, a->frames));
            bench_add_num(o, "gl_pt_fps", gl.min_ms > 0.0 ? 1e3 / gl.min_ms : 0.0);
            cJSON_AddItemToArray(rows, o);
            char first[40];
            snprintf(first, sizeof first, "%.1f (%.1f)", gl.first_ms, gl.first_prep_ms);
            if (a->pt_gl_only)
                printf("%-24s %-14s %10u %14s %16s %10s %10.1f %8s %8s %10.2f\n", c->names[i], backend,
                       rl_scene_get_data(scene)->num_triangles, "-", first, "-", gl.min_ms, "-", "-",
                       gl.min_ms > 0.0 ? 1e3 / gl.min_ms : 0.0);
            else
                printf("%-24s %-14s %10u %14.1f %16s %10.1f %10.1f %8.2f %8.2f %10.2f\n", c->names[i], backend,
                       rl_scene_get_data(scene)->num_triangles, cpu.first_ms, first, cpu.min_ms, gl.min_ms,
                       bench_ratio(gl.min_ms, cpu.min_ms), bench_ratio(gl.min_cpu_ms, cpu.min_cpu_ms),
                       gl.min_ms > 0.0 ? 1e3 / gl.min_ms : 0.0);
        } else {
            snprintf(c->reason, sizeof c->reason, "%s, %s: %s", c->names[i], backend, rl_last_error());
        }
        free(cpu.warm_ms);
        free(gl.warm_ms);
        rl_image_release(cpu.img);
        rl_image_release(gl.img);
    }
    fflush(stdout);
    return st;
}

/* ------------------------------------------------------------ visibility */

/* Positions on the scene's diagonal, evenly inside the bounds. */
static void diagonal_positions(const rl_scene *scene, long long count, rl_vec3 *pos)
{
    const rl_aabb b = rl_scene_get_data(scene)->bounds;
    for (long long k = 0; k < count; ++k)
        pos[k] = rl_add(b.min, rl_scale(rl_sub(b.max, b.min), (float)(k + 1) / (float)(count + 1)));
}

/* One backend's visibility on one scene. */
typedef struct vis_times {
    double commit_ms, mean_ms, min_ms, mean_cpu_ms;
    double *values;
    uint32_t *pixels;             /* positions x objects */
} vis_times;

static rl_status time_visibility(const bgl_ctx *c, const char *backend, const rl_scene *scene,
                                 const rl_vec3 *pos, vis_times *t)
{
    const bgl_args *a = c->a;
    const uint32_t n = rl_scene_get_data(scene)->num_objects;
    rl_property *p = NULL;
    char res[32];
    snprintf(res, sizeof res, "%lld", a->resolution);
    rl_status st = rl_property_create("visibility", &p);
    if (st == RL_OK)
        st = rl_property_set(p, "resolution", res);
    if (st == RL_OK)
        st = rl_property_set(p, "backend", backend);
    if (st == RL_OK && strcmp(backend, "gl") == 0 && a->device[0])
        st = rl_property_set(p, "device", a->device);
    double t0 = rl_time_s();
    if (st == RL_OK)
        st = rl_property_commit(p, scene, 1);
    t->commit_ms = 1e3 * (rl_time_s() - t0);
    t->values = calloc((size_t)a->positions, sizeof *t->values);
    t->pixels = calloc((size_t)a->positions * n, sizeof *t->pixels);
    if (st == RL_OK && (!t->values || !t->pixels))
        st = RL_ERR_OUT_OF_MEMORY;
    double sum = 0.0, cpu = 0.0;
    t->min_ms = INFINITY;
    for (long long k = 0; k < a->positions && st == RL_OK; ++k) {
        rl_property_sample s = { 0 };
        const double c0 = cpu_s();
        t0 = rl_time_s();
        st = rl_property_evaluate(p, 0, pos[k], &s);
        const double ms = 1e3 * (rl_time_s() - t0);
        cpu += 1e3 * (cpu_s() - c0);
        sum += ms;
        t->min_ms = fmin(t->min_ms, ms);
        t->values[k] = s.value;
        /* Untimed: the per-object pixels the two backends are compared on. */
        if (st == RL_OK)
            st = rl_property_object_pixels(p, 0, pos[k], t->pixels + (size_t)k * n);
    }
    t->mean_ms = sum / (double)a->positions;
    t->mean_cpu_ms = cpu / (double)a->positions;
    rl_property_release(p);
    return st;
}

static cJSON *vis_json(const vis_times *t)
{
    cJSON *o = cJSON_CreateObject();
    bench_add_num(o, "commit_ms", t->commit_ms);
    bench_add_num(o, "mean_ms_per_position", t->mean_ms);
    bench_add_num(o, "min_ms_per_position", t->min_ms);
    bench_add_num(o, "mean_cpu_ms_per_position", t->mean_cpu_ms);
    return o;
}

static rl_status sec_visibility(void *ctx, cJSON *sec)
{
    bgl_ctx *c = ctx;
    const bgl_args *a = c->a;
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    printf("\nvisibility property (objects), %lld^2 per face, %lld positions, 1 worker: ms per position\n"
           "%-16s %10s %10s %10s %10s %8s %8s %8s %18s\n", a->resolution, a->positions, "scene", "sw commit",
           "gl commit", "sw mean", "gl mean", "sw/gl", "cpu", "equal", "pixels differ");
    rl_vec3 *pos = calloc((size_t)a->positions, sizeof *pos);
    rl_status st = pos ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (int i = 0; i < c->num_scenes && st == RL_OK; ++i) {
        const rl_scene *scene = c->scenes[i];
        const uint32_t n = rl_scene_get_data(scene)->num_objects;
        diagonal_positions(scene, a->positions, pos);
        vis_times sw = { 0 }, gl = { 0 };
        note("%s: visibility, software", c->names[i]);
        st = time_visibility(c, "software", scene, pos, &sw);
        if (st == RL_OK) {
            note("%s: visibility, gl", c->names[i]);
            st = time_visibility(c, "gl", scene, pos, &gl);
        }
        if (st == RL_OK) {
            long long equal = 0;
            uint64_t differ = 0, total = 0;
            for (long long k = 0; k < a->positions; ++k) {
                equal += gl.values[k] == sw.values[k];
                for (uint32_t o = 0; o < n; ++o) {
                    const uint32_t x = gl.pixels[(size_t)k * n + o], y = sw.pixels[(size_t)k * n + o];
                    differ += x > y ? x - y : y - x;
                    total += y;
                }
            }
            cJSON *o = cJSON_CreateObject();
            cJSON_AddStringToObject(o, "scene", c->names[i]);
            cJSON_AddNumberToObject(o, "objects", n);
            cJSON_AddItemToObject(o, "software", vis_json(&sw));
            cJSON_AddItemToObject(o, "gl", vis_json(&gl));
            bench_add_num(o, "software_over_gl_mean", bench_ratio(sw.mean_ms, gl.mean_ms));
            bench_add_num(o, "software_over_gl_mean_cpu", bench_ratio(sw.mean_cpu_ms, gl.mean_cpu_ms));
            cJSON_AddNumberToObject(o, "values_equal", (double)equal);
            /* Sum over objects of |GL - software| pixels: a pixel that
             * changes hands counts twice, once per object. */
            cJSON_AddNumberToObject(o, "object_pixels_differing", (double)differ);
            cJSON_AddNumberToObject(o, "object_pixels_total", (double)total);
            cJSON *vals = cJSON_AddArrayToObject(o, "values");
            for (long long k = 0; k < a->positions; ++k)
                cJSON_AddItemToArray(vals, cJSON_CreateNumber(gl.values[k]));
            cJSON_AddItemToArray(rows, o);
            char diff[48];
            snprintf(diff, sizeof diff, "%llu / %llu", (unsigned long long)differ, (unsigned long long)total);
            printf("%-16s %10.1f %10.1f %10.1f %10.1f %8.2f %8.2f %5lld/%-2lld %18s\n", c->names[i], sw.commit_ms,
                   gl.commit_ms, sw.mean_ms, gl.mean_ms, bench_ratio(sw.mean_ms, gl.mean_ms),
                   bench_ratio(sw.mean_cpu_ms, gl.mean_cpu_ms), equal, a->positions, diff);
        } else {
            snprintf(c->reason, sizeof c->reason, "%s: %s", c->names[i], rl_last_error());
        }
        free(sw.values);
        free(sw.pixels);
        free(gl.values);
        free(gl.pixels);
    }
    free(pos);
    fflush(stdout);
    return st;
}

/* ------------------------------------------------------------- linespace */

/* Schröder 2017, Table 1: Line Space generation on a GeForce GTX 1080, ms
 * (the scenes of Sec. 9.3 as our ls-cornell built-in models them). */
static const struct ls_row {
    const char *scene;
    int res, n;
    double thesis_ms;
} ls_rows[] = {
    { "ls-cornell:model=boxes", 8, 4, 154 },    { "ls-cornell:model=boxes", 8, 5, 269 },
    { "ls-cornell:model=teapot", 8, 5, 644 },   { "ls-cornell:model=teapot", 32, 5, 1795 },
    { "ls-cornell:model=bunny", 8, 5, 3915 },   { "ls-cornell:model=bunny", 64, 5, 10081 },
    { "ls-cornell:model=dragon", 8, 5, 94393 }, { "ls-cornell:model=dragon", 72, 5, 53675 },
};

/* One row: the grid, the CPU build and the GL build of the same Line Space. */
static rl_status ls_row_run(const bgl_ctx *c, const char *name, int res, int n, double thesis_ms, cJSON *rows)
{
    rl_scene *scene = NULL;
    if (cli_load_scene(name, &scene) != RL_CLI_OK)
        return RL_ERR_INVALID_ARG;
    rl_accel *grid = NULL;
    rl_accel_desc gd = { .kind = RL_ACCEL_GRID, .grid_res = { res, res, res } };
    rl_status st = rl_accel_create(scene, &gd, &grid);
    if (st == RL_OK)
        st = rl_accel_commit(grid);
    const rl_linespace_desc desc = { .n = n, .dynamic = true };
    rl_linespace *ls = NULL;
    rl_linespace_stats cs = { 0 };
    if (st == RL_OK) {
        note("%s %d^3 N=%d: cpu", name, res, n);
        st = rl_linespace_create(grid, &desc, &ls);
        if (st == RL_OK)
            st = rl_linespace_commit(ls);
        rl_linespace_get_stats(ls, &cs);
        rl_linespace_release(ls);
    }
    rl_gl_linespace_timing gt = { 0 };
    rl_status gst = RL_ERR_INTERNAL;
    char gerr[256] = "";
    if (st == RL_OK) {
        note("%s %d^3 N=%d: gl", name, res, n);
        gst = rl_gl_linespace_time_build(grid, &desc, c->a->device, &gt);
        if (gst != RL_OK) {
            /* A row over the GL's limits is reported, not fatal. */
            snprintf(gerr, sizeof gerr, "%s", rl_last_error());
            rl_clear_error();
        }
    }
    if (st == RL_OK) {
        const bool same = gst == RL_OK && gt.occupied == cs.shafts - cs.empty_shafts && gt.candidates == cs.candidates;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "scene", name);
        cJSON_AddNumberToObject(o, "triangles", rl_scene_get_data(scene)->num_triangles);
        cJSON_AddNumberToObject(o, "res", res);
        cJSON_AddNumberToObject(o, "n", n);
        cJSON_AddNumberToObject(o, "filled_voxels", cs.filled_voxels);
        cJSON_AddNumberToObject(o, "candidates", (double)cs.candidates);
        bench_add_num(o, "cpu_ms", cs.build_ms);
        if (gst == RL_OK) {
            bench_add_num(o, "gl_time_elapsed_ms", gt.gpu_ms);
            bench_add_num(o, "gl_timestamp_ms", gt.stamp_ms);
            bench_add_num(o, "gl_wall_ms", gt.wall_ms);
            cJSON_AddNumberToObject(o, "gl_bytes", (double)gt.gpu_bytes);
        } else {
            cJSON_AddStringToObject(o, "gl_error", gerr);
        }
        cJSON_AddBoolToObject(o, "counts_equal", same);
        if (thesis_ms > 0.0) {
            bench_add_num(o, "thesis_ms", thesis_ms);
            /* The target: the thesis' time over ours, >= 3 on a GPU. */
            bench_add_num(o, "thesis_over_gl_wall", gst == RL_OK ? bench_ratio(thesis_ms, gt.wall_ms) : NAN);
        }
        cJSON_AddItemToArray(rows, o);
        char thesis[16] = "-";
        if (thesis_ms > 0.0)
            snprintf(thesis, sizeof thesis, "%.0f", thesis_ms);
        if (gst == RL_OK)
            printf("%-26s %4d %2d %9u %10.1f %10.1f %10.1f %10.1f %8s %7s\n", name, res, n, cs.filled_voxels,
                   cs.build_ms, gt.gpu_ms, gt.stamp_ms, gt.wall_ms, thesis, same ? "yes" : "NO");
        else
            printf("%-26s %4d %2d %9u %10.1f gl: %s\n", name, res, n, cs.filled_voxels, cs.build_ms, gerr);
    }
    rl_accel_release(grid);
    rl_scene_release(scene);
    return st;
}

static rl_status sec_linespace(void *ctx, cJSON *sec)
{
    bgl_ctx *c = ctx;
    const bgl_args *a = c->a;
    cJSON *rows = cJSON_AddArrayToObject(sec, "rows");
    printf("\nLine Space generation, dynamic lists: cpu build vs GL compute (time elapsed, timestamps, wall), ms\n"
           "%-26s %4s %2s %9s %10s %10s %10s %10s %8s %7s\n", "scene", "res", "N", "voxels", "cpu", "gl elapsed",
           "gl stamps", "gl wall", "thesis", "equal");
    rl_status st = RL_OK;
    if (a->quick)
        st = ls_row_run(c, ls_rows[0].scene, 4, 2, 0.0, rows);
    for (long long i = 0; !a->quick && st == RL_OK && i < a->ls_rows; ++i)
        st = ls_row_run(c, ls_rows[i].scene, ls_rows[i].res, ls_rows[i].n, ls_rows[i].thesis_ms, rows);
    if (st != RL_OK)
        snprintf(c->reason, sizeof c->reason, "linespace: %s", rl_last_error());
    fflush(stdout);
    return st;
}

/* ------------------------------------------------------------------ main */

static void release_ctx(bgl_ctx *c)
{
    for (int i = 0; i < c->num_scenes; ++i) {
        free(c->names[i]);
        rl_scene_release(c->scenes[i]);
    }
}

int bench_gl(int argc, char **argv)
{
    bgl_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    bgl_ctx c = { .a = &a };
    if (a.scenes_text)
        rc = parse_scenes(&c, a.scenes_text);
    else if (a.quick)
        rc = parse_scenes(&c, "cornell,spheres");
    else
        rc = default_scenes(&c) ? RL_CLI_OK : cli_fail(RL_CLI_FAIL, "out of memory");
    char out[4096];
    if (rc == RL_CLI_OK && !bench_out_path(a.out, "gl", out, sizeof out))
        rc = RL_CLI_FAIL;
    /* Without GL there is nothing to compare: say why before loading. */
    rl_gl_info info;
    if (rc == RL_CLI_OK && rl_gl_info_get(a.device, &info) != RL_OK)
        rc = cli_fail(RL_CLI_FAIL, "bench gl: %s", rl_last_error());
    /* The linespace section loads its own scenes (Table 1's). */
    const bool only_ls = a.sections == 1u << SEC_LINESPACE;
    for (int i = 0; !only_ls && rc == RL_CLI_OK && i < c.num_scenes; ++i)
        rc = cli_load_scene(c.names[i], &c.scenes[i]);
    if (rc != RL_CLI_OK) {
        release_ctx(&c);
        return rc;
    }
    const int threads = omp_get_max_threads();
    cJSON *root = bench_record_json("gl", threads);
    if (!root) {
        release_ctx(&c);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    cJSON *gl = cJSON_AddObjectToObject(root, "gl");
    cJSON_AddStringToObject(gl, "vendor", info.vendor);
    cJSON_AddStringToObject(gl, "renderer", info.renderer);
    cJSON_AddStringToObject(gl, "version", info.version);
    cJSON_AddStringToObject(gl, "device", info.device);
    cJSON *params = cJSON_AddObjectToObject(root, "parameters");
    cJSON *sl = cJSON_AddArrayToObject(params, "scenes");
    for (int i = 0; !only_ls && i < c.num_scenes; ++i) {
        cJSON *s = cJSON_CreateObject();
        cJSON_AddStringToObject(s, "name", c.names[i]);
        cJSON_AddItemToObject(s, "stats", cli_scene_stats_json(c.scenes[i]));
        cJSON_AddItemToArray(sl, s);
    }
    char size[32];
    snprintf(size, sizeof size, "%dx%d", a.width, a.height);
    cJSON_AddStringToObject(params, "size", size);
    cJSON_AddNumberToObject(params, "warm_frames", (double)a.frames);
    cJSON_AddNumberToObject(params, "resolution", (double)a.resolution);
    cJSON_AddNumberToObject(params, "positions", (double)a.positions);
    cJSON_AddStringToObject(params, "positions_at", "(k + 1) / (positions + 1) along the bounds' diagonal");
    snprintf(size, sizeof size, "%dx%d", a.pt_width, a.pt_height);
    cJSON_AddStringToObject(params, "pt_size", size);
    cJSON_AddNumberToObject(params, "pt_spp", (double)a.pt_spp);
    cJSON_AddBoolToObject(params, "pt_gl_only", a.pt_gl_only);
    cJSON_AddNumberToObject(params, "pt_grid_res", (double)a.pt_grid_res);
    cJSON *pt_backends = cJSON_AddArrayToObject(params, "pt_backends");
    for (int k = 0; k < a.num_pt_backends; ++k)
        cJSON_AddItemToArray(pt_backends, cJSON_CreateString(a.pt_backends[k]));
    cJSON_AddBoolToObject(params, "quick", a.quick);
    cJSON_AddNumberToObject(params, "ls_rows", (double)a.ls_rows);
    cJSON_AddStringToObject(params, "ls_note",
                            "llvmpipe's GL_TIME_ELAPSED times draws only and reads 0 for compute passes; "
                            "gl_timestamp_ms (GL_TIMESTAMP around the same passes) is the GPU-side time there");
    printf("rl bench gl: %s | %s | %s (%s), %d threads\n", info.vendor, info.renderer, info.version, info.device,
           threads);
    static const bench_section_fn fns[SEC_COUNT] = { sec_frames, sec_visibility, sec_pt, sec_linespace };
    rc = bench_run_sections("gl", root, section_names, fns, SEC_COUNT, a.sections, &c, c.reason, threads, out);
    cJSON_Delete(root);
    release_ctx(&c);
    return rc;
}
