/* cmd_demo.c: `rl demo`: every built-in scene with every renderer, one PNG
 * each, plus DIR/report.json (machine, date, scene and render statistics per
 * image) and DIR/index.html (the same, as a page). `make demo` runs it.
 * --scenes also takes the user's own model files and JSON scenes, named by
 * their file stem.
 *
 * Every image is marked exact or approximate and carries its error (RMSE,
 * SSIM) against the scene's reference: Whitted ray tracing at its defaults,
 * the default reference of `rl compare`.
 *
 * Then pt and bdpt at equal time on two Cornell boxes (issue 37), when
 * both renderers and the Cornell box are in the run.
 *
 * Then a small `rl compare` (Jähn 2015's evaluation: every renderer at the
 * same adaptively sampled positions) of the first demo scene, or `table`
 * by default, into DIR/compare/, linked from the page.
 *
 * A failing scene or renderer does not stop the demo: it is reported as one
 * error line, listed in the report, and the exit code becomes 1. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include "bench_util.h"

#include <cjson/cJSON.h>
#include <ctype.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

static const char demo_help[] =
    "usage: rl demo [--out DIR] [--size WxH] [--scenes a,b] [--algos a,b]\n"
    "\n"
    "Renders every built-in scene (rl scenes) with every renderer (rl algos)\n"
    "and writes DIR/<scene>-<algo>.png, DIR/report.json (command, build,\n"
    "machine, date and, per image, scene and render statistics) and\n"
    "DIR/index.html (the images and their statistics on one page). Each image\n"
    "is marked exact or approximate, with its RMSE and SSIM against the\n"
    "scene's reference (whitted at its defaults). A model file without\n"
    "cameras is framed from its default view. Prints one\n"
    "line per image; its times separate the one-time preparation (prep:\n"
    "sampled inputs, structures built for the scene) from the frame. Defaults that\n"
    "changed on purpose are drawn once more with the old value, and where that\n"
    "changes an image both are shown side by side (DIR/changes/). Then compares\n"
    "the renderers over a small sampled region of one scene (rl compare) into\n"
    "DIR/compare/report.html.\n"
    "\n"
    "When pt, bdpt and cornell are all in the run, also draws pt and bdpt at\n"
    "equal time on the Cornell box lit directly and lit through bounces only\n"
    "(DIR/equal-time/): each accumulates samples until its CPU time per thread\n"
    "reaches --equal-time. These images depend on the machine's speed.\n"
    "\n"
    "The images, report.json and index.html replace the previous ones together\n"
    "at the end of the run: a run that is stopped, or fails to write an image,\n"
    "leaves the previous demo in DIR as it was.\n"
    "\n"
    "options:\n"
    "  --out DIR       output folder, created if missing; default out/demo\n"
    "  --size WxH      resolution of every image; default 640x480\n"
    "  --scenes a,b    only these scenes: built-in names (default parameters),\n"
    "                  model files (model.obj:lights=add,cameras=off; a k=v item\n"
    "                  after a comma continues the file's parameters) and JSON\n"
    "                  scenes, named by their file stem\n"
    "  --algos a,b     only these renderers\n"
    "  --no-compare    skip the comparison\n"
    "  --equal-time T  CPU time per thread of each equal-time image (500ms,\n"
    "                  2s, ...); default 2s; 0 skips them\n"
    "\n"
    "example:\n"
    "  rl demo --out out/demo\n"
    "  rl demo --out /tmp/quick --size 160x120 --scenes cornell,spheres\n"
    "  rl demo --out /tmp/duck --scenes duck.dae,spider.obj:lights=add\n";

/* One scene of the demo, as --scenes named it. */
typedef struct demo_scene {
    char *arg;            /* "cornell", "model.obj:lights=add,cameras=off" */
    char name[128];       /* the built-in's name or the file's stem: file names, page */
    bool builtin;
} demo_scene;

typedef struct demo_args {
    const char *out, *scenes, *algos;
    int width, height;
    bool no_compare;
    double equal_time;    /* seconds of CPU per thread for pt and bdpt; 0: none */
    demo_scene *list;     /* the scenes to render, in order */
    size_t count;
    /* Every image, report.json and index.html of the run go through one
     * batch (rl_output.h) committed at the end, so that the page never
     * mixes two runs: a run killed or stopped by a full disk midway
     * leaves the previous demo as it was. */
    rl_output_batch *batch;
    /* The first output that failed to write: the run stops there and does
     * not commit; the message is the run's one error line. */
    char *unwritten;      /* "" while every write succeeded */
} demo_args;

/* An image of the run could not be written (disk full, a size limit):
 * its path (up to 4 KB) and the library's reason. */
#define RL_DEMO_UNWRITTEN 8192
static void note_unwritten(const demo_args *a, rl_status st, const char *path)
{
    if (!*a->unwritten)
        snprintf(a->unwritten, RL_DEMO_UNWRITTEN, "%s: %s", path, rl_last_error()[0] ? rl_last_error() : rl_status_string(st));
}

static void free_args(demo_args *a)
{
    for (size_t i = 0; i < a->count; i++)
        free(a->list[i].arg);
    free(a->list);
    a->list = NULL;
    a->count = 0;
}

/* Whether renderer name can render here; a GL renderer without a GL
 * context is left out of the demo with one warning, not a failure. */
static bool available(const char *name, bool warn)
{
    rl_renderer *r = NULL;
    if (rl_renderer_create(name, &r) != RL_OK)
        return true;   /* render_one reports it */
    char why[256];
    bool ok = rl_renderer_available(r, why, sizeof why);
    rl_renderer_release(r);
    if (!ok && warn)
        fprintf(stderr, "rl: warning: demo: %s left out: unavailable: %s\n", name, why);
    return ok;
}

/* True when name is an item of the comma-separated list (NULL = all). */
static bool in_list(const char *list, const char *name)
{
    if (!list)
        return true;
    size_t n = strlen(name);
    for (const char *p = list; *p;) {
        const char *end = strchr(p, ',');
        size_t m = end ? (size_t)(end - p) : strlen(p);
        if (m == n && strncmp(p, name, n) == 0)
            return true;
        p = end ? end + 1 : p + m;
    }
    return false;
}

/* Every item of list must be a known name: a typo should not silently
 * produce an empty demo. */
static bool check_list(const char *option, const char *list, const char *const *names,
                       size_t count)
{
    for (const char *p = list; *p;) {
        const char *end = strchr(p, ',');
        size_t m = end ? (size_t)(end - p) : strlen(p);
        bool known = false;
        for (size_t i = 0; i < count && !known; i++)
            known = strlen(names[i]) == m && strncmp(names[i], p, m) == 0;
        if (!known) {
            char typed[256];
            snprintf(typed, sizeof typed, "%.*s", (int)m, p);
            rl_suggestion sg = { 0 };
            for (size_t i = 0; i < count; i++)
                rl_suggest(&sg, typed, names[i]);
            if (sg.name)
                cli_fail(RL_CLI_USAGE, "%s: unknown name '%s' (did you mean '%s'?)", option, typed, sg.name);
            else
                cli_fail(RL_CLI_USAGE, "%s: unknown name '%s'", option, typed);
            return false;
        }
        p = end ? end + 1 : p + m;
    }
    return true;
}

/* The page and the file names take a file's stem; characters that a file
 * name or a shell could trip over become '_'. */
static void stem_of(const char *path, char *out, size_t size)
{
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    const char *dot = strrchr(base, '.');
    size_t n = dot && dot != base ? (size_t)(dot - base) : strlen(base);
    if (n >= size)
        n = size - 1;
    for (size_t i = 0; i < n; i++) {
        unsigned char c = (unsigned char)base[i];
        out[i] = isalnum(c) || c == '-' || c == '_' || c == '+' || c == '.' ? (char)c : '_';
    }
    out[n] = '\0';
}

static bool name_taken(const demo_args *a, const char *name)
{
    for (size_t i = 0; i < a->count; i++)
        if (strcmp(a->list[i].name, name) == 0)
            return true;
    return false;
}

/* Adds one scene of --scenes: a built-in name, or an existing file (model or
 * JSON scene, with its parameters after a colon). Repeats are dropped;
 * two files with one stem (Wuson.obj, Wuson.ply) get "-2", "-3". */
static int add_scene(demo_args *a, const char *arg)
{
    for (size_t i = 0; i < a->count; i++)
        if (strcmp(a->list[i].arg, arg) == 0)
            return RL_CLI_OK;
    char *source = NULL, *params = NULL;
    if (!cli_split_source(arg, &source, &params))
        return cli_fail(RL_CLI_FAIL, "out of memory");
    struct stat st;
    demo_scene sc = { .builtin = cli_is_builtin(source) };
    int rc = RL_CLI_OK;
    if (sc.builtin && params)
        rc = cli_fail(RL_CLI_USAGE, "--scenes: '%s': built-in scenes take their default parameters here", arg);
    else if (!sc.builtin && stat(source, &st) != 0) {
        /* Neither a file nor a built-in: most likely a typo of a built-in. */
        size_t ns = 0;
        const rl_builtin_info *builtins = rl_builtin_scenes(&ns);
        rl_suggestion sg = { 0 };
        for (size_t i = 0; i < ns; i++)
            rl_suggest(&sg, source, builtins[i].name);
        if (sg.name)
            rc = cli_fail(RL_CLI_USAGE, "--scenes: unknown name '%s' (did you mean '%s'?)", source, sg.name);
        else
            rc = cli_fail(RL_CLI_USAGE, "--scenes: unknown name '%s' (neither a built-in scene nor a file)", source);
    }
    if (rc == RL_CLI_OK) {
        if (sc.builtin)
            snprintf(sc.name, sizeof sc.name, "%s", source);
        else {
            char stem[100];
            stem_of(source, stem, sizeof stem);
            snprintf(sc.name, sizeof sc.name, "%s", stem);
            for (int k = 2; name_taken(a, sc.name) && k < 1000; k++)
                snprintf(sc.name, sizeof sc.name, "%s-%d", stem, k);
        }
        demo_scene *grown = realloc(a->list, (a->count + 1) * sizeof *grown);
        sc.arg = strdup(arg);
        if (!grown || !sc.arg) {
            free(sc.arg);
            if (grown)
                a->list = grown;
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
        } else {
            a->list = grown;
            a->list[a->count++] = sc;
        }
    }
    free(source);
    free(params);
    return rc;
}

/* --scenes, item by item. A model file's parameters are separated by
 * commas too: an item with '=' but no ':' continues the item before it
 * ("spider.obj:lights=add,cameras=off"), as rl compare's --algos does. */
static int collect_scenes(demo_args *a)
{
    size_t ns = 0;
    const rl_builtin_info *builtins = rl_builtin_scenes(&ns);
    if (!a->scenes) {
        for (size_t i = 0; i < ns; i++) {
            int rc = add_scene(a, builtins[i].name);
            if (rc != RL_CLI_OK)
                return rc;
        }
        return RL_CLI_OK;
    }
    size_t len = strlen(a->scenes);
    char *item = malloc(len + 1);
    if (!item)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    int rc = RL_CLI_OK;
    size_t n = 0;                  /* characters of the item being joined */
    for (const char *p = a->scenes; rc == RL_CLI_OK && *p;) {
        const char *end = strchr(p, ',');
        size_t m = end ? (size_t)(end - p) : strlen(p);
        bool continues = n > 0 && memchr(p, '=', m) && !memchr(p, ':', m);
        if (n > 0 && !continues) {
            item[n] = '\0';
            rc = add_scene(a, item);
            n = 0;
        }
        if (continues)
            item[n++] = ',';
        memcpy(item + n, p, m);
        n += m;
        p = end ? end + 1 : p + m;
    }
    if (rc == RL_CLI_OK && n > 0) {
        item[n] = '\0';
        rc = add_scene(a, item);
    }
    free(item);
    if (rc == RL_CLI_OK && a->count == 0)
        rc = cli_fail(RL_CLI_USAGE, "--scenes: no scene given");
    return rc;
}

static int parse_args(int argc, char **argv, demo_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        int m;
        if (cli_is_help(argv[i])) {
            fputs(demo_help, stdout);
            return -1;
        }
        if (strcmp(argv[i], "--no-compare") == 0) {
            a->no_compare = true;
            continue;
        }
        if ((m = cli_take_value(argc, argv, &i, "--out", &v)) > 0)
            a->out = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--scenes", &v)) > 0)
            a->scenes = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--algos", &v)) > 0)
            a->algos = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--size", &v)) > 0) {
            if (!cli_parse_size(v, &a->width, &a->height))
                return RL_CLI_USAGE;
        } else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--equal-time", &v)) > 0) {
            if (!cli_parse_duration(v, &a->equal_time) || a->equal_time > 3600.0)
                return cli_fail(RL_CLI_USAGE, "--equal-time: expected a duration from 0 to 1h (2s, 500ms), got "
                                              "'%s'", v);
        } else if (m == 0)
            return cli_unknown_arg("demo", argv[i]);
        if (m < 0)
            return RL_CLI_USAGE;
    }
    size_t nr = 0;
    const rl_renderer_info *algos = rl_renderer_list(&nr);
    const char **names = calloc(nr + 1, sizeof *names);
    if (!names)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    for (size_t i = 0; i < nr; i++)
        names[i] = algos[i].name;
    bool ok = !a->algos || check_list("--algos", a->algos, names, nr);
    free(names);
    return ok ? collect_scenes(a) : RL_CLI_USAGE;
}

static void add_failure(cJSON *failures, const char *scene, const char *algo)
{
    cJSON *f = cJSON_CreateObject();
    if (!f)
        return;
    cJSON_AddStringToObject(f, "scene", scene);
    cJSON_AddStringToObject(f, "algorithm", algo ? algo : "");
    cJSON_AddStringToObject(f, "error", *rl_last_error() ? rl_last_error() : "failed");
    cJSON_AddItemToArray(failures, f);
}

/* Renders scene with one renderer into DIR/<scene>-<algo>.png and appends
 * the entry to images; returns false (error printed) on failure. keep (may
 * be NULL) receives the image, entry (may be NULL) the entry. */
static bool render_one(const demo_args *a, const char *scene_name, const rl_scene *scene,
                       const rl_camera *cam, const char *algo, cJSON *images, rl_image **keep,
                       cJSON **entry)
{
    char file[512], path[4096];
    snprintf(file, sizeof file, "%s-%s.png", scene_name, algo);
    if ((size_t)snprintf(path, sizeof path, "%s/%s", a->out, file) >= sizeof path) {
        cli_fail(RL_CLI_FAIL, "%s: output path too long", a->out);
        return false;
    }
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_progress *progress = NULL;
    rl_render_stats stats = { 0 };
    rl_timer phase;
    double inputs_ms = 0.0;
    rl_clear_error();
    rl_status st = rl_renderer_create(algo, &r);
    /* A frame that cannot fit is refused with its estimate (printed). */
    if (st == RL_OK &&
        cli_check_frame_memory(r, cam->width, cam->height, RL_LAYER_COLOR, 8.0, 0.0) != RL_CLI_OK)
        st = RL_ERR_LIMIT;
    rl_timer_start(&phase);
    if (st == RL_OK)
        st = rl_renderer_prepare_inputs(r, scene);   /* visset, select: sampled here */
    inputs_ms = rl_timer_ms(&phase);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    if (st == RL_OK) {
        char label[600];
        snprintf(label, sizeof label, "%s %s", algo, scene_name);
        if (rl_log_get_level() >= RL_LOG_INFO && rl_progress_create(label, stderr, &progress) == RL_OK)
            rl_renderer_set_progress(r, rl_progress_update, progress);
        st = rl_renderer_render(r, scene, cam, img, &stats);
        rl_renderer_set_progress(r, NULL, NULL);
        rl_progress_finish(progress);
    }
    const char *write_to = NULL;
    if (st == RL_OK)
        st = rl_output_batch_add(a->batch, path, &write_to);
    bool unwritten = false;
    if (st == RL_OK && (st = rl_image_write(img, write_to)) != RL_OK) {
        note_unwritten(a, st, path);
        unwritten = true;
    }
    bool ok = st == RL_OK;
    if (ok) {
        cli_debug("timing: %s %s: build %.1f ms (inputs %.1f ms, for the scene %.1f ms), frame %.1f ms", algo,
                  scene_name, inputs_ms + stats.prep_ms, inputs_ms, stats.prep_ms, stats.time_ms - stats.prep_ms);
        cli_print_summary(stdout, algo, scene_name, cam->width, cam->height, &stats, inputs_ms);
        fflush(stdout);
        cJSON *e = cJSON_CreateObject();
        if (e) {
            cJSON_AddStringToObject(e, "scene", scene_name);
            cJSON_AddStringToObject(e, "algorithm", algo);
            cJSON_AddStringToObject(e, "file", file);
            cJSON_AddNumberToObject(e, "width", cam->width);
            cJSON_AddNumberToObject(e, "height", cam->height);
            cJSON *ss = cli_scene_stats_json(scene);
            cJSON *rs = cli_render_stats_json(&stats, inputs_ms);
            if (ss)
                cJSON_AddItemToObject(e, "scene_stats", ss);
            if (rs)
                cJSON_AddItemToObject(e, "render_stats", rs);
            cJSON_AddItemToArray(images, e);
            if (entry)
                *entry = e;
        }
    } else if (!unwritten) {
        char what[600];
        snprintf(what, sizeof what, "%s with %s", scene_name, algo);
        cli_fail_status(RL_CLI_FAIL, st, what);
    }
    if (ok && keep)
        *keep = img;
    else
        rl_image_release(img);
    rl_renderer_release(r);
    return ok;
}

/* Changes of the defaults made on purpose, shown side by side on the page:
 * the renderer is drawn again with the option at its old value, and where
 * the images differ both go on the page with their difference. */
typedef struct demo_change {
    const char *algo, *key, *old_value, *what;
} demo_change;

static const demo_change changes[] = {
    { "whitted", "transmitted_highlight", "false",
      "Ullmann 2003, eq. 3.17: lights behind a transmissive surface add k_t cos^n of the angle between their "
      "refracted direction and the viewer's (new); false: classic Phong, as before" },
    { "vt", "transmitted_highlight", "false",
      "Ullmann 2003, eq. 3.17, in the vertex samples (as whitted)" },
};

/* The scene with algo's old default of change c into DIR/changes/, compared
 * with now (the image of the new default); a change that leaves the image
 * as it was is not listed. */
static bool render_change(const demo_args *a, const char *scene_name, const rl_scene *scene, const rl_camera *cam,
                          const demo_change *c, const rl_image *now, cJSON *list)
{
    char file[512], path[4096];
    snprintf(file, sizeof file, "changes/%s-%s-%s-%s.png", scene_name, c->algo, c->key, c->old_value);
    if ((size_t)snprintf(path, sizeof path, "%s/%s", a->out, file) >= sizeof path)
        return cli_fail(RL_CLI_FAIL, "%s: output path too long", a->out), false;
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_render_stats stats = { 0 };
    rl_image_metrics m = { 0 };
    rl_clear_error();
    rl_status st = rl_renderer_create(c->algo, &r);
    if (st == RL_OK)
        st = rl_renderer_set(r, c->key, c->old_value);
    if (st == RL_OK)
        st = rl_renderer_prepare_inputs(r, scene);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    if (st == RL_OK)
        st = rl_renderer_render(r, scene, cam, img, &stats);
    if (st == RL_OK)
        st = rl_image_compare(img, now, NULL, &m);
    bool differs = st == RL_OK && m.max_abs > 0.0;
    if (differs) {
        char dir[4096];
        snprintf(dir, sizeof dir, "%s/changes", a->out);
        const char *write_to = NULL;
        st = cli_make_dirs(dir) ? rl_output_batch_add(a->batch, path, &write_to) : RL_ERR_IO;
        if (st == RL_OK && (st = rl_image_write(img, write_to)) != RL_OK)
            note_unwritten(a, st, path);
    }
    if (st == RL_OK && differs) {
        printf("changed: %s %s, %s=%s before: RMSE %.4f, SSIM %.4f\n", scene_name, c->algo, c->key, c->old_value,
               m.rmse, m.ssim);
        fflush(stdout);
        cJSON *e = cJSON_CreateObject();
        if (e) {
            char now_file[512];
            snprintf(now_file, sizeof now_file, "%s-%s.png", scene_name, c->algo);
            cJSON_AddStringToObject(e, "scene", scene_name);
            cJSON_AddStringToObject(e, "algorithm", c->algo);
            cJSON_AddStringToObject(e, "option", c->key);
            cJSON_AddStringToObject(e, "before", c->old_value);
            cJSON_AddStringToObject(e, "what", c->what);
            cJSON_AddStringToObject(e, "file_now", now_file);
            cJSON_AddStringToObject(e, "file_before", file);
            cJSON_AddNumberToObject(e, "rmse", m.rmse);
            cJSON_AddNumberToObject(e, "ssim", m.ssim);
            cJSON_AddNumberToObject(e, "time_ms_before", stats.time_ms);
            cJSON_AddItemToArray(list, e);
        }
    } else if (st != RL_OK && !*a->unwritten) {
        char what[600];
        snprintf(what, sizeof what, "%s with %s, %s=%s", scene_name, c->algo, c->key, c->old_value);
        cli_fail_status(RL_CLI_FAIL, st, what);
    }
    rl_image_release(img);
    rl_renderer_release(r);
    return st == RL_OK;
}

/* The scene's reference: Whitted ray tracing at its defaults, the default
 * reference of rl compare (every image of the demo uses its renderer's
 * defaults). The renderers compute different things (pt global
 * illumination, raster local lighting only), so an image's error says
 * how far it is from the reference, and its note why. */
static const char demo_reference[] = "whitted";

/* Where each renderer's image differs from the reference's, for the page. */
static const struct {
    const char *algo, *note;
} demo_notes[] = {
    { "raster", "local Phong lighting: no shadows, reflection or refraction" },
    { "whitted", "the reference" },
    { "vt", "the VT objects (mirrors, glass) traced at adaptively refined vertices and interpolated, "
            "the rest as raster" },
    { "pt", "path tracing, 1 path per pixel: noise, and indirect light the reference lacks" },
    { "gl-pt", "pt in GL compute shaders (1 path per pixel): pt's estimator, its own noise" },
    { "bdpt", "bidirectional path tracing, 1 sample per pixel: noise (less where light arrives by bounces), "
              "and indirect light the reference lacks" },
    { "chcpp", "raster's image: occlusion culling is exact" },
    { "svs", "raster's image without the objects its sampled visibility misses" },
    { "visset", "raster's image without the objects its sampled visible sets miss" },
    { "surfels", "raster's image with distant parts drawn as surfels" },
    { "select", "chcpp's or svs's image, chosen per position" },
};

static const char *demo_note(const char *algo)
{
    for (size_t i = 0; i < sizeof demo_notes / sizeof demo_notes[0]; i++)
        if (strcmp(demo_notes[i].algo, algo) == 0)
            return demo_notes[i].note;
    return "";
}

/* The reference image when the reference renderer is not among --algos;
 * NULL (a warning, no error values on the page) when it fails. */
static rl_image *render_reference(const rl_scene *scene, const rl_camera *cam, const char *scene_name)
{
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_render_stats stats = { 0 };
    rl_clear_error();
    rl_status st = rl_renderer_create(demo_reference, &r);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    if (st == RL_OK)
        st = rl_renderer_render(r, scene, cam, img, &stats);
    rl_renderer_release(r);
    if (st != RL_OK) {
        fprintf(stderr, "rl: warning: %s: the reference (%s) failed, images go without their error: %s\n",
                scene_name, demo_reference, *rl_last_error() ? rl_last_error() : rl_status_string(st));
        rl_image_release(img);
        return NULL;
    }
    return img;
}

/* Marks entry exact or approximate, with its error against ref (may be
 * NULL: no error values). Exact: the reference itself, or an image equal
 * to it; everything else approximates it. */
static void add_accuracy(cJSON *entry, const char *algo, const rl_image *img, const rl_image *ref)
{
    rl_image_metrics m = { 0 };
    bool measured = ref && rl_image_compare(img, ref, NULL, &m) == RL_OK;
    bool exact = strcmp(algo, demo_reference) == 0 || (measured && m.max_abs == 0.0);
    cJSON_AddStringToObject(entry, "accuracy", exact ? "exact" : "approximate");
    cJSON_AddStringToObject(entry, "note", demo_note(algo));
    cJSON *err = cJSON_AddObjectToObject(entry, "error");
    if (!err)
        return;
    cJSON_AddStringToObject(err, "reference", demo_reference);
    if (measured) {
        cJSON_AddNumberToObject(err, "rmse", m.rmse);
        cJSON_AddNumberToObject(err, "ssim", m.ssim);
        cJSON_AddNumberToObject(err, "max_abs", m.max_abs);
    }
}

/* The camera of a demo image. A built-in scene's own; a file's first
 * camera, or, without one, the tight framing of the model from its default
 * view at the demo's size (a fit for another aspect would crop or pad). */
static rl_status demo_camera(const demo_args *a, const demo_scene *sc, const rl_scene *scene, rl_camera *cam)
{
    const rl_scene_data *sd = rl_scene_get_data(scene);
    if (!sc->builtin && sd && sd->num_cameras == 0)
        return rl_scene_fit_camera(scene, a->width, a->height, cam);
    rl_status st = rl_scene_get_camera(scene, NULL, cam);
    /* Same size for every image so the grid compares like with like. */
    cam->width = a->width;
    cam->height = a->height;
    return st;
}

static int run_demo(const demo_args *a, cJSON *report)
{
    cJSON *images = cJSON_AddArrayToObject(report, "images");
    cJSON *failures = cJSON_AddArrayToObject(report, "failures");
    cJSON *changed = cJSON_AddArrayToObject(report, "changes");
    if (!images || !failures || !changed)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    size_t nr = 0;
    const rl_renderer_info *algos = rl_renderer_list(&nr);
    /* A scene's images stay until its reference is there (whitted comes
     * after raster): at most one image per renderer at the demo's size. */
    rl_image **row = calloc(nr ? nr : 1, sizeof *row);
    cJSON **entries = calloc(nr ? nr : 1, sizeof *entries);
    if (!row || !entries) {
        free(row);
        free(entries);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    bool *usable = calloc(nr ? nr : 1, sizeof *usable);
    if (!usable) {
        free(row);
        free(entries);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    for (size_t k = 0; k < nr; k++)
        usable[k] = in_list(a->algos, algos[k].name) && available(algos[k].name, true);
    int rc = RL_CLI_OK;
    cJSON *listed = cJSON_AddArrayToObject(report, "scenes");
    for (size_t s = 0; s < a->count && !*a->unwritten; s++) {   /* a failed write ends the run */
        const demo_scene *sc = &a->list[s];
        const char *name = sc->name;
        cJSON *item = cJSON_CreateObject();
        if (item) {
            cJSON_AddStringToObject(item, "name", name);
            cJSON_AddStringToObject(item, "source", sc->arg);
            cJSON_AddBoolToObject(item, "builtin", sc->builtin);
            cJSON_AddItemToArray(listed, item);
        }
        rl_scene *scene = NULL;
        rl_camera cam;
        rl_timer phase;
        rl_clear_error();
        rl_timer_start(&phase);
        rl_status st = RL_OK;
        if (sc->builtin)
            st = rl_scene_create_builtin(name, NULL, &scene);
        else if (cli_load_scene(sc->arg, &scene) != RL_CLI_OK)
            st = RL_ERR_IO;   /* printed by cli_load_scene */
        if (st == RL_OK)
            cli_debug("timing: %s: load %.1f ms", name, rl_timer_ms(&phase));
        if (st == RL_OK)
            st = demo_camera(a, sc, scene, &cam);
        if (st != RL_OK) {
            if (sc->builtin || scene)
                cli_fail_status(RL_CLI_FAIL, st, name);
            add_failure(failures, name, NULL);
            rl_scene_release(scene);
            rc = RL_CLI_FAIL;
            continue;
        }
        rl_image *ref = NULL;
        for (size_t k = 0; k < nr && !*a->unwritten; k++) {
            if (!usable[k])
                continue;
            rl_image *now = NULL;
            if (!render_one(a, name, scene, &cam, algos[k].name, images, &now, &entries[k])) {
                add_failure(failures, name, algos[k].name);
                rc = RL_CLI_FAIL;
            }
            for (size_t c = 0; now && c < sizeof changes / sizeof changes[0]; c++)
                if (strcmp(changes[c].algo, algos[k].name) == 0 &&
                    !render_change(a, name, scene, &cam, &changes[c], now, changed)) {
                    add_failure(failures, name, algos[k].name);
                    rc = RL_CLI_FAIL;
                }
            row[k] = now;
            if (now && strcmp(algos[k].name, demo_reference) == 0)
                ref = now;
        }
        bool own_ref = !ref && !in_list(a->algos, demo_reference);
        if (own_ref)
            ref = render_reference(scene, &cam, name);
        for (size_t k = 0; k < nr; k++)
            if (row[k] && entries[k])
                add_accuracy(entries[k], algos[k].name, row[k], ref);
        for (size_t k = 0; k < nr; k++) {   /* ref may be one of them */
            rl_image_release(row[k]);
            row[k] = NULL;
            entries[k] = NULL;
        }
        if (own_ref)
            rl_image_release(ref);
        rl_scene_release(scene);
    }
    free(row);
    free(entries);
    free(usable);
    return rc;
}

/* pt against bdpt at equal time (issue 37, "the demo page shows pt and
 * bdpt at equal time"): the Cornell box lit directly (variant=bitterli)
 * and lit only by bounces off a plate under the lamp (variant=shade).
 * Each renderer first draws one frame under another seed (its BVH and
 * light tables: preparation, not counted), then accumulates frames of one
 * sample until its CPU time per thread reaches --equal-time, as `rl bench
 * pt --only bdpt` does (bench_render_for_cpu). CPU time, not wall time:
 * on a busy machine the two would otherwise get different shares. The
 * images are square, at most 256 pixels a side, to keep the samples a
 * few seconds buy visible. */
static const char *const equal_time_variants[] = { "bitterli", "shade" };
static const char *const equal_time_algos[] = { "pt", "bdpt" };

static bool equal_time_wanted(const demo_args *a)
{
    if (a->equal_time <= 0.0)
        return false;
    for (size_t k = 0; k < 2; k++)
        if (!in_list(a->algos, equal_time_algos[k]) || !available(equal_time_algos[k], false))
            return false;
    for (size_t s = 0; s < a->count; s++)
        if (a->list[s].builtin && strcmp(a->list[s].name, "cornell") == 0)
            return true;
    return false;
}

static rl_status equal_time_one(const demo_args *a, const rl_scene *scene, const rl_camera *cam,
                                const char *variant, const char *algo, cJSON *list)
{
    char file[256], path[4096 + 256], dir[4096 + 16];   /* a->out is shorter than 4096 (cli_demo) */
    snprintf(file, sizeof file, "equal-time/cornell-%s-%s.png", variant, algo);
    snprintf(path, sizeof path, "%s/%s", a->out, file);
    snprintf(dir, sizeof dir, "%s/equal-time", a->out);
    int threads = cli_threads();
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_render_stats stats = { 0 };
    bench_budget_run run = { 0 };
    rl_status st = rl_renderer_create(algo, &r);
    if (st == RL_OK) st = rl_renderer_set(r, "spp", "1");
    if (st == RL_OK) st = rl_renderer_set(r, "seed", "9");
    if (st == RL_OK) st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    if (st == RL_OK) st = rl_renderer_render(r, scene, cam, img, &stats);
    /* A new seed restarts the accumulation: the warm-up frame is not in it. */
    if (st == RL_OK) st = rl_renderer_set(r, "seed", "1");
    if (st == RL_OK) st = bench_render_for_cpu(r, scene, cam, img, threads, a->equal_time, &run);
    const char *write_to = NULL;
    if (st == RL_OK)
        st = cli_make_dirs(dir) ? rl_output_batch_add(a->batch, path, &write_to) : RL_ERR_IO;
    if (st == RL_OK && (st = rl_image_write(img, write_to)) != RL_OK)
        note_unwritten(a, st, path);
    if (st == RL_OK) {
        double m[3] = { 0.0, 0.0, 0.0 }, n = (double)cam->width * cam->height;
        for (size_t i = 0; i < (size_t)cam->width * cam->height; i++) {
            m[0] += img->color[i].x / n;
            m[1] += img->color[i].y / n;
            m[2] += img->color[i].z / n;
        }
        double cpu_s = run.cpu_ms / 1e3 / threads;
        printf("equal time: cornell:variant=%s %s, %lld spp in %.2f s CPU per thread (%.2f s wall)\n", variant,
               algo, run.frames, cpu_s, run.wall_ms / 1e3);
        fflush(stdout);
        cJSON *e = cJSON_CreateObject();
        if (e) {
            cJSON_AddStringToObject(e, "scene", "cornell");
            cJSON_AddStringToObject(e, "variant", variant);
            cJSON_AddStringToObject(e, "algorithm", algo);
            cJSON_AddStringToObject(e, "file", file);
            cJSON_AddNumberToObject(e, "spp", (double)run.frames);
            cJSON_AddNumberToObject(e, "cpu_s_per_thread", cpu_s);
            cJSON_AddNumberToObject(e, "wall_ms", run.wall_ms);
            cJSON_AddNumberToObject(e, "threads", threads);
            cJSON *mean = cJSON_AddArrayToObject(e, "means");
            for (int k = 0; k < 3 && mean; k++)
                cJSON_AddItemToArray(mean, cJSON_CreateNumber(m[k]));
            cJSON_AddItemToArray(list, e);
        }
    }
    rl_image_release(img);
    rl_renderer_release(r);
    return st;
}

static int run_equal_time(const demo_args *a, cJSON *report)
{
    if (!equal_time_wanted(a))
        return RL_CLI_OK;
    cJSON *list = cJSON_AddArrayToObject(report, "equal_time");
    cJSON *failures = cJSON_GetObjectItemCaseSensitive(report, "failures");
    if (!list)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    cJSON_AddNumberToObject(report, "equal_time_s", a->equal_time);
    int side = a->width < a->height ? a->width : a->height;
    if (side > 256)
        side = 256;
    int rc = RL_CLI_OK;
    for (size_t v = 0; v < 2 && !*a->unwritten; v++) {
        char params[64], name[96];
        snprintf(params, sizeof params, "variant=%s", equal_time_variants[v]);
        snprintf(name, sizeof name, "cornell:%s", params);
        rl_scene *scene = NULL;
        rl_camera cam;
        rl_clear_error();
        rl_status st = rl_scene_create_builtin("cornell", params, &scene);
        if (st == RL_OK)
            st = rl_scene_get_camera(scene, NULL, &cam);
        cam.width = cam.height = side;
        for (size_t k = 0; k < 2 && st == RL_OK && !*a->unwritten; k++) {
            rl_clear_error();
            if ((st = equal_time_one(a, scene, &cam, equal_time_variants[v], equal_time_algos[k], list)) != RL_OK) {
                char what[160];
                snprintf(what, sizeof what, "%s with %s at equal time", name, equal_time_algos[k]);
                if (!*a->unwritten)
                    cli_fail_status(RL_CLI_FAIL, st, what);
                add_failure(failures, name, equal_time_algos[k]);
                rc = RL_CLI_FAIL;
            }
        }
        if (st != RL_OK && rc == RL_CLI_OK) {   /* the scene itself */
            cli_fail_status(RL_CLI_FAIL, st, name);
            add_failure(failures, name, NULL);
            rc = RL_CLI_FAIL;
        }
        rl_scene_release(scene);
    }
    return rc;
}

/* The small comparison: every demo renderer at the same 24 positions of
 * one scene, tiny images, one timed render per direction. */
static int run_compare(const demo_args *a)
{
    char scene[4096] = "table", algos[1024] = "", out[4096];
    if (a->scenes && a->count > 0)
        snprintf(scene, sizeof scene, "%s", a->list[0].arg);
    size_t nr = 0;
    const rl_renderer_info *info = rl_renderer_list(&nr);
    for (size_t k = 0; k < nr; k++)
        if (in_list(a->algos, info[k].name) && available(info[k].name, false)) {
            size_t len = strlen(algos);
            snprintf(algos + len, sizeof algos - len, "%s%s", len ? "," : "", info[k].name);
        }
    if (!*algos)
        return RL_CLI_OK;
    snprintf(out, sizeof out, "%s/compare", a->out);
    char *argv[] = { "compare", scene, "--algos", algos, "--size", "48x48", "--samples", "24",
                     "--repeats", "1", "--resolution", "32", "--out", out, NULL };
    return cli_compare((int)(sizeof argv / sizeof argv[0]) - 1, argv);
}

int cli_demo(int argc, char **argv)
{
    char unwritten[RL_DEMO_UNWRITTEN] = "";
    demo_args a = { .out = "out/demo", .width = 640, .height = 480, .equal_time = 2.0, .unwritten = unwritten };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK) {
        free_args(&a);
        return rc < 0 ? RL_CLI_OK : rc;
    }
    char probe[4096];
    cJSON *report = NULL;
    if ((size_t)snprintf(probe, sizeof probe, "%s/report.json", a.out) >= sizeof probe)
        rc = cli_fail(RL_CLI_USAGE, "--out: path too long");
    else if (!cli_make_dirs(a.out) || !cli_check_writable(probe))
        rc = RL_CLI_FAIL;
    else if (!(report = cJSON_CreateObject()))
        rc = cli_fail(RL_CLI_FAIL, "out of memory");
    else if (rl_output_batch_create(&a.batch) != RL_OK)
        rc = cli_fail_status(RL_CLI_FAIL, RL_ERR_OUT_OF_MEMORY, "demo");
    if (rc != RL_CLI_OK) {
        cJSON_Delete(report);
        free_args(&a);
        return rc;
    }
    char date[64];
    time_t now = time(NULL);
    struct tm tm;
    strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", gmtime_r(&now, &tm));
    cJSON_AddStringToObject(report, "renderlab", RL_CLI_VERSION);
    cJSON_AddStringToObject(report, "date", date);
    char build[512];
    cli_build_text(build, sizeof build);
    cJSON_AddStringToObject(report, "command", cli_command_line());
    cJSON_AddStringToObject(report, "build", build);
    cJSON *machine = cli_machine_json(cli_threads());
    if (machine)
        cJSON_AddItemToObject(report, "machine", machine);
    cJSON_AddNumberToObject(report, "width", a.width);
    cJSON_AddNumberToObject(report, "height", a.height);
    cJSON_AddStringToObject(report, "reference", demo_reference);

    rc = run_demo(&a, report);
    if (!*unwritten && run_equal_time(&a, report) != RL_CLI_OK)
        rc = RL_CLI_FAIL;
    if (!a.no_compare && !*unwritten) {
        int crc = run_compare(&a);
        if (crc == RL_CLI_OK)
            cJSON_AddStringToObject(report, "compare", "compare/report.html");
        else
            rc = RL_CLI_FAIL;
    }
    char html[4096];
    snprintf(html, sizeof html, "%s/index.html", a.out);
    /* A renderer that failed is recorded in the report and the run still
     * commits (the page says what failed); an output that could not be
     * written stops the commit, and the previous demo stays whole. */
    const char *json_tmp = NULL, *html_tmp = NULL;
    rl_status st = rl_output_batch_add(a.batch, probe, &json_tmp);
    if (st == RL_OK)
        st = rl_output_batch_add(a.batch, html, &html_tmp);
    if (st != RL_OK)
        rc = cli_fail_status(RL_CLI_FAIL, st, "demo");
    else if (*unwritten)
        rc = cli_fail(RL_CLI_FAIL, "demo: %s; %s keeps the previous demo", unwritten, a.out);
    else if (!cli_write_json(report, json_tmp) || !cli_write_demo_html(report, html_tmp))
        rc = RL_CLI_FAIL;
    else if ((st = rl_output_batch_commit(a.batch)) != RL_OK)
        rc = cli_fail_status(RL_CLI_FAIL, st, "demo");
    else
        printf("report: %s, %s\n", probe, html);
    rl_output_batch_release(a.batch);
    cJSON_Delete(report);
    free_args(&a);
    return rc;
}
