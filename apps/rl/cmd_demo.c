/* cmd_demo.c: `rl demo`: every built-in scene with every renderer, one PNG
 * each, plus DIR/report.json (machine, date, scene and render statistics per
 * image) and DIR/index.html (the same, as a page). `make demo` runs it.
 *
 * Then a small `rl compare` (Jähn 2015's evaluation: every renderer at the
 * same adaptively sampled positions) of the first demo scene, or `table`
 * by default, into DIR/compare/, linked from the page.
 *
 * A failing scene or renderer does not stop the demo: it is reported as one
 * error line, listed in the report, and the exit code becomes 1. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const char demo_help[] =
    "usage: rl demo [--out DIR] [--size WxH] [--scenes a,b] [--algos a,b]\n"
    "\n"
    "Renders every built-in scene (rl scenes) with every renderer (rl algos)\n"
    "and writes DIR/<scene>-<algo>.png, DIR/report.json (command, build,\n"
    "machine, date and, per image, scene and render statistics) and\n"
    "DIR/index.html (the images and their statistics on one page). Prints one\n"
    "line per image; its times separate the one-time preparation (prep:\n"
    "sampled inputs, structures built for the scene) from the frame. Defaults that\n"
    "changed on purpose are drawn once more with the old value, and where that\n"
    "changes an image both are shown side by side (DIR/changes/). Then compares\n"
    "the renderers over a small sampled region of one scene (rl compare) into\n"
    "DIR/compare/report.html.\n"
    "\n"
    "options:\n"
    "  --out DIR       output folder, created if missing; default out/demo\n"
    "  --size WxH      resolution of every image; default 640x480\n"
    "  --scenes a,b    only these built-in scenes (default parameters)\n"
    "  --algos a,b     only these renderers\n"
    "  --no-compare    skip the comparison\n"
    "\n"
    "example:\n"
    "  rl demo --out out/demo\n"
    "  rl demo --out /tmp/quick --size 160x120 --scenes cornell,spheres\n";

typedef struct demo_args {
    const char *out, *scenes, *algos;
    int width, height;
    bool no_compare;
} demo_args;

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
        } else if (m == 0)
            return cli_unknown_arg("demo", argv[i]);
        if (m < 0)
            return RL_CLI_USAGE;
    }
    size_t ns = 0, nr = 0;
    const rl_builtin_info *scenes = rl_builtin_scenes(&ns);
    const rl_renderer_info *algos = rl_renderer_list(&nr);
    const char **names = calloc(ns + nr + 1, sizeof *names);
    if (!names)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    for (size_t i = 0; i < ns; i++)
        names[i] = scenes[i].name;
    for (size_t i = 0; i < nr; i++)
        names[ns + i] = algos[i].name;
    bool ok = (!a->scenes || check_list("--scenes", a->scenes, names, ns)) &&
              (!a->algos || check_list("--algos", a->algos, names + ns, nr));
    free(names);
    return ok ? RL_CLI_OK : RL_CLI_USAGE;
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
 * be NULL) receives the image. */
static bool render_one(const demo_args *a, const char *scene_name, const rl_scene *scene,
                       const rl_camera *cam, const char *algo, cJSON *images, rl_image **keep)
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
    if (st == RL_OK)
        st = rl_image_write(img, path);
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
        }
    } else {
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
        st = cli_make_dirs(dir) ? rl_image_write(img, path) : RL_ERR_IO;
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
    } else if (st != RL_OK) {
        char what[600];
        snprintf(what, sizeof what, "%s with %s, %s=%s", scene_name, c->algo, c->key, c->old_value);
        cli_fail_status(RL_CLI_FAIL, st, what);
    }
    rl_image_release(img);
    rl_renderer_release(r);
    return st == RL_OK;
}

static int run_demo(const demo_args *a, cJSON *report)
{
    cJSON *images = cJSON_AddArrayToObject(report, "images");
    cJSON *failures = cJSON_AddArrayToObject(report, "failures");
    cJSON *changed = cJSON_AddArrayToObject(report, "changes");
    if (!images || !failures || !changed)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    size_t ns = 0, nr = 0;
    const rl_builtin_info *scenes = rl_builtin_scenes(&ns);
    const rl_renderer_info *algos = rl_renderer_list(&nr);
    int rc = RL_CLI_OK;
    for (size_t s = 0; s < ns; s++) {
        const char *name = scenes[s].name;
        if (!in_list(a->scenes, name))
            continue;
        rl_scene *scene = NULL;
        rl_camera cam;
        rl_timer phase;
        rl_clear_error();
        rl_timer_start(&phase);
        rl_status st = rl_scene_create_builtin(name, NULL, &scene);
        if (st == RL_OK)
            cli_debug("timing: %s: load %.1f ms", name, rl_timer_ms(&phase));
        if (st == RL_OK)
            st = rl_scene_get_camera(scene, NULL, &cam);
        if (st != RL_OK) {
            cli_fail_status(RL_CLI_FAIL, st, name);
            add_failure(failures, name, NULL);
            rl_scene_release(scene);
            rc = RL_CLI_FAIL;
            continue;
        }
        /* Same size for every image so the grid compares like with like. */
        cam.width = a->width;
        cam.height = a->height;
        for (size_t k = 0; k < nr; k++) {
            if (!in_list(a->algos, algos[k].name))
                continue;
            rl_image *now = NULL;
            if (!render_one(a, name, scene, &cam, algos[k].name, images, &now)) {
                add_failure(failures, name, algos[k].name);
                rc = RL_CLI_FAIL;
            }
            for (size_t c = 0; now && c < sizeof changes / sizeof changes[0]; c++)
                if (strcmp(changes[c].algo, algos[k].name) == 0 &&
                    !render_change(a, name, scene, &cam, &changes[c], now, changed)) {
                    add_failure(failures, name, algos[k].name);
                    rc = RL_CLI_FAIL;
                }
            rl_image_release(now);
        }
        rl_scene_release(scene);
    }
    return rc;
}

/* The small comparison: every demo renderer at the same 24 positions of
 * one scene, tiny images, one timed render per direction. */
static int run_compare(const demo_args *a)
{
    char scene[256] = "table", algos[1024] = "", out[4096];
    if (a->scenes) {
        const char *end = strchr(a->scenes, ',');
        snprintf(scene, sizeof scene, "%.*s", end ? (int)(end - a->scenes) : (int)strlen(a->scenes),
                 a->scenes);
    }
    size_t nr = 0;
    const rl_renderer_info *info = rl_renderer_list(&nr);
    for (size_t k = 0; k < nr; k++)
        if (in_list(a->algos, info[k].name)) {
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
    demo_args a = { .out = "out/demo", .width = 640, .height = 480 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc < 0 ? RL_CLI_OK : rc;
    char probe[4096];
    if ((size_t)snprintf(probe, sizeof probe, "%s/report.json", a.out) >= sizeof probe)
        return cli_fail(RL_CLI_USAGE, "--out: path too long");
    if (!cli_make_dirs(a.out) || !cli_check_writable(probe))
        return RL_CLI_FAIL;

    cJSON *report = cJSON_CreateObject();
    if (!report)
        return cli_fail(RL_CLI_FAIL, "out of memory");
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

    rc = run_demo(&a, report);
    if (!a.no_compare) {
        int crc = run_compare(&a);
        if (crc == RL_CLI_OK)
            cJSON_AddStringToObject(report, "compare", "compare/report.html");
        else
            rc = RL_CLI_FAIL;
    }
    char html[4096];
    snprintf(html, sizeof html, "%s/index.html", a.out);
    if (!cli_write_json(report, probe) || !cli_write_demo_html(report, html))
        rc = RL_CLI_FAIL;
    else
        printf("report: %s, %s\n", probe, html);
    cJSON_Delete(report);
    return rc;
}
