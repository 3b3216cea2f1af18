/* cmd_view.c: `rl view SCENE ...`: an interactive window on any renderer.
 *
 * Two threads. The main thread owns the window, the events, the camera and
 * the clock; a worker owns the renderer and renders whatever the main
 * thread last asked for. The main thread never waits on a frame: it shows
 * the last image the worker published (an intermediate one of vt's
 * progressive display included), and a camera change cancels the running
 * frame through the renderer's progress callback. Progressive renderers
 * (pt) are asked for one more frame whenever the worker is idle, so they
 * accumulate while the camera stands still.
 *
 * With --script the clock is virtual: it advances by one step (1/25 s)
 * per finished frame, and every event waits for the frame of the events
 * before it. A scripted run is therefore the same on any machine, and a
 * screenshot of an unmoved camera equals `rl render` of that camera. */
#define _POSIX_C_SOURCE 200809L
#include "view.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

static const char view_help[] =
    "usage: rl view SCENE [options]\n"
    "\n"
    "Opens a window on SCENE rendered by any renderer, and flies through it.\n"
    "The window stays responsive while a frame renders: it shows the last image\n"
    "(vt with --set vt.progressive=overdraw|redraw: every intermediate one; pt\n"
    "accumulates samples while the camera stands still), and moving the camera\n"
    "cancels the frame. docs/viewer.md describes scripting and recording.\n"
    "\n"
    "SCENE  a built-in name (see rl scenes), optionally with parameters, a .json\n"
    "       scene or a mesh file\n"
    "\n"
    "options:\n"
    "  --algo NAME         renderer (see rl algos); default raster\n"
    "  --set KEY=VALUE     renderer option, repeatable (see rl algos); a key with\n"
    "                      a renderer's prefix (vt.min_edge=14) applies when Tab\n"
    "                      or the menu switches to that renderer\n"
    "  --camera NAME       a camera of the scene; default its first one\n"
    "  --size WxH|window   WxH: a fixed image size, which the window scales;\n"
    "                      window (the default): the image follows the window's\n"
    "                      pixel size, at most 1920x1200's worth of pixels; the\n"
    "                      window starts at the camera's size, else 1280x720\n"
    "  --script FILE       timed events (keys, mouse, camera moves, screenshots);\n"
    "                      exits at its end, on a virtual clock of 25 steps a\n"
    "                      second that advances by finished frames\n"
    "  --screenshot-at T:FILE  write the frame shown at T seconds (repeatable)\n"
    "  --record DIR        write every displayed frame as DIR/frame_NNNNNN.png\n"
    "  --shot-dir DIR      where F12 writes rl-view-NNNN.png (+ .json); default .\n"
    "  --path-out FILE     where R saves the recorded camera path; default\n"
    "                      rl-view-path.json\n"
    "  --stats-out FILE    the viewer's statistics at exit (JSON): frames, fps\n"
    "                      while the camera moved, time to the first image\n"
    "  --max-spp N         progressive renderers stop accumulating at N samples\n"
    "                      per pixel; default 4096\n"
    "  --ref-spp N         samples per pixel of the pt reference that X compares\n"
    "                      the path tracers with; default 256\n"
    "  --display MODE      how the image reaches the window: shared (the window's\n"
    "                      EGL context shared with the GL renderers: their frames\n"
    "                      stay on the GPU), software (SDL's software renderer),\n"
    "                      gl (SDL's OpenGL renderer) or auto (default: shared for\n"
    "                      a GL renderer, else software; falls back to software)\n"
    "\n"
    "model files (the same as SCENE:cameras=off,lights=add,...; see rl scenes):\n"
    CLI_MODEL_FLAGS_HELP
    "\n"
    "%s"
    "\n"
    "example:\n"
    "  rl view cornell --algo vt --set vt.progressive=overdraw --size 640x480\n"
    "  xvfb-run -a rl view cornell --script tour.txt --size 96x72\n";

int cli_view(int argc, char **argv)
{
    for (int i = 1; i < argc; i++)
        if (cli_is_help(argv[i])) {
            printf(view_help, view_keys_help);
            return RL_CLI_OK;
        }
    return view_run(argc, argv);
}

#ifndef RL_HAVE_SDL2

int view_run(int argc, char **argv)
{
    (void)argc;
    (void)argv;
    return cli_fail(RL_CLI_FAIL, "view: this rl was built without SDL2 (install libsdl2-dev and rebuild)");
}

#else

#include <SDL.h>

/* The virtual clock of a script: steps per second. */
#define SCRIPT_FPS 25.0
#define MAX_SHOTS 64
#define MAX_CMDS 64
#define DEFAULT_MAX_SPP 4096
#define DEFAULT_REF_SPP 256
/* An accumulating renderer's image is stable once a new frame changes it
 * by less than this mean absolute difference of 8-bit sRGB values: half a
 * code value, below what a viewer sees. */
#define STABLE_CHANGE 0.5
/* Every image of the viewer: the depth and ID layers are shown by L. */
#define VIEW_LAYERS (RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID)
/* With the image following the window (--size window, the default), a
 * window larger than this many pixels gets an image scaled down to it
 * (same aspect; the window scales it up): a full-screen window on a 4K
 * display would otherwise make every frame four times the work of 1080p
 * and hold about a gigabyte of frame buffers. */
#define VIEW_MAX_WINDOW_PIXELS (1920 * 1200)

typedef struct shot_at {
    double time_s;
    const char *file;
    bool done;
} shot_at;

typedef struct view_args {
    const char *scene, *algo, *camera, *script, *record_dir, *shot_dir, *path_out, *stats_out;
    const char *display;       /* --display: auto, shared, software or gl */
    bool has_size;             /* --size WxH; without it (or with --size window) the image follows the window */
    int width, height;
    const char **sets;
    int num_sets;
    shot_at shots[MAX_SHOTS];
    int num_shots;
    long long max_spp, ref_spp;
    cli_model_flags model;
} view_args;

/* A change of the renderer that the worker applies before its next frame:
 * renderers are only ever touched on the worker thread. */
typedef enum cmd_kind {
    CMD_ALGO,         /* text: the renderer */
    CMD_SET,          /* text: KEY=VALUE */
    CMD_STEP,         /* the renderer's selected live option up or down */
    CMD_SELECT,       /* select the next / previous live option for CMD_STEP */
    CMD_CLICK,        /* text: an option clicked in the menu; dir +1 left, -1 right */
    CMD_CYCLE,        /* text: an enum option, set to its next choice */
    CMD_REFERENCE     /* compare the next finished frame with a reference */
} cmd_kind;
typedef struct view_cmd {
    cmd_kind kind;
    char text[256];
    int dir;          /* CMD_STEP, CMD_SELECT, CMD_CYCLE, CMD_CLICK: +1 or -1 */
    int line;         /* script line, 0 for a key */
} view_cmd;

/* What the two threads share; everything under lock except gen. */
typedef struct shared {
    SDL_mutex *lock;
    SDL_cond *wake, *done;
    /* Bumped by the main thread for every change that makes the running
     * frame useless: the progress callback compares it without the lock. */
    SDL_atomic_t gen;
    /* the request */
    uint64_t req_seq;
    rl_camera req_cam;
    bool req_moved;                /* the request restarted: a camera or renderer change */
    double req_time_s;             /* when it was made */
    bool quit;
    view_cmd cmds[MAX_CMDS];
    int num_cmds;
    /* the worker */
    uint64_t done_seq;
    bool worker_progressive;       /* the current renderer accumulates */
    double worker_spp;             /* accumulated since the last restart */
    char algo[64];
    char status[256];              /* the last change's outcome, for the overlay */
    char options[2048];            /* the current renderer's options, for the menu: "key=value\n"... */
    /* the last comparison with a reference (X) */
    bool ref_valid;
    char ref_algo[64], ref_of[64];
    double ref_ssim, ref_hssim, ref_rmse, ref_spp;
    int ref_levels;
    int fatal;                     /* exit code of a failure that ends a scripted run */
    char fatal_msg[512];
    /* the published image; with the shared path (front_gpu) its colour is
     * front_tex, a texture of the window's share group, not front->color */
    bool front_gpu;
    rl_gl_frame front_tex;
    /* textures published but never taken (a newer frame came first), for
     * the main thread to delete: only it has a context of the share group */
    rl_gl_frame trash[16];
    int num_trash;
    rl_image *front;
    uint64_t front_seq;
    bool front_final;
    rl_render_stats front_stats;
    char front_algo[64];
    double front_spp;
    double front_time_s;           /* when it was published */
    bool front_moved;              /* its request's */
    double front_request_s;
} shared;

/* The worker's own state. */
typedef struct worker {
    shared *sh;
    const view_args *args;
    const rl_scene *scene;
    rl_renderer *r;
    rl_image *back;
    int running_gen;
    bool running_moved;
    double running_request_s;
    rl_camera last_cam;
    bool have_last;
    int step_sel;                  /* the live option of + and -: an index among the renderer's */
    rl_renderer *ref;              /* the reference renderer of X, kept for the next X */
    rl_image *ref_img;
    bool want_ref;
    bool glshare;                  /* the shared path: GL renderers hand over textures */
    /* The shared path's GL renderers that Tab left, kept for the next
     * switch to them: a released one's GL objects would stay in the
     * window's share group until the window closes (docs/viewer.md). */
    rl_renderer *parked[4];
} worker;

/* *img at w x h with layers: kept when it has that size, else replaced
 * (its pixels are not kept: every user overwrites them). */
static rl_status fit_image(rl_image **img, int w, int h, unsigned layers)
{
    if (*img && (*img)->width == w && (*img)->height == h)
        return RL_OK;
    rl_image *next = NULL;
    rl_status st = rl_image_create(w, h, layers, &next);
    if (st != RL_OK)
        return st;
    rl_image_release(*img);
    *img = next;
    return RL_OK;
}

static bool on_progress(void *user, double done)
{
    (void)done;
    worker *w = user;
    return SDL_AtomicGet(&w->sh->gen) == w->running_gen;
}

/* A texture that will never be shown, to the main thread for deletion
 * (with the lock held); one that finds the bin full is left to the share
 * group's end. */
static void discard_tex(shared *sh, rl_gl_frame *t)
{
    if (t->texture && sh->num_trash < (int)(sizeof sh->trash / sizeof sh->trash[0]))
        sh->trash[sh->num_trash++] = *t;
    *t = (rl_gl_frame){ 0 };
}

/* img's layers and, with tex (the shared path), its colour as a texture
 * instead of img->color. */
static void publish(worker *w, const rl_image *img, const rl_render_stats *stats, bool final, rl_gl_frame *tex)
{
    shared *sh = w->sh;
    SDL_LockMutex(sh->lock);
    discard_tex(sh, &sh->front_tex);
    sh->front_gpu = tex != NULL;
    if (tex) {
        sh->front_tex = *tex;
        *tex = (rl_gl_frame){ 0 };
    }
    /* The window's size may have changed the image's (--size window). */
    if (fit_image(&sh->front, img->width, img->height, VIEW_LAYERS) != RL_OK) {
        snprintf(sh->status, sizeof sh->status, "out of memory for a %dx%d image", img->width, img->height);
        SDL_UnlockMutex(sh->lock);
        rl_clear_error();
        return;
    }
    size_t n = (size_t)img->width * (size_t)img->height;
    if (!sh->front_gpu)
        memcpy(sh->front->color, img->color, n * sizeof *img->color);
    /* An intermediate image without these layers must not show the last
     * frame's depth and IDs under its colour. */
    for (size_t i = 0; i < n; i++) {
        sh->front->depth[i] = img->depth ? img->depth[i] : INFINITY;
        sh->front->object_id[i] = img->object_id ? img->object_id[i] : RL_ID_NONE;
    }
    sh->front_seq++;
    sh->front_final = final;
    if (stats)
        sh->front_stats = *stats;
    snprintf(sh->front_algo, sizeof sh->front_algo, "%s", rl_renderer_name(w->r));
    sh->front_spp = sh->worker_spp;
    sh->front_time_s = rl_time_s();
    sh->front_moved = w->running_moved;
    sh->front_request_s = w->running_request_s;
    SDL_UnlockMutex(sh->lock);
}

/* vt's progressive display: every intermediate image is shown. */
static bool on_vt_update(void *user, const rl_image *image, uint32_t stage, bool final)
{
    (void)stage;
    worker *w = user;
    if (!final)
        publish(w, image, NULL, false, NULL);
    return SDL_AtomicGet(&w->sh->gen) == w->running_gen;
}

static bool is_progressive(const char *name)
{
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    for (size_t i = 0; i < n; i++)
        if (strcmp(list[i].name, name) == 0)
            return list[i].progressive;
    return false;
}

/* The renderer whose name prefixes key ("visset" of "visset.samples"),
 * other than self, or NULL. */
static const char *other_prefix(const char *key, const char *self)
{
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    for (size_t i = 0; i < n; i++) {
        size_t len = strlen(list[i].name);
        if (strcmp(list[i].name, self) != 0 && strncmp(key, list[i].name, len) == 0 && key[len] == '.')
            return list[i].name;
    }
    return NULL;
}

/* The --set options for renderer r: for the first renderer all but those
 * with another renderer's prefix, which are checked on that renderer
 * instead (a failure is a usage error either way); for one that Tab or
 * the menu switched to only those with r's prefix (so "vt.min_edge=14"
 * follows the user around). */
static int apply_sets(rl_renderer *r, const view_args *a, bool first)
{
    const char *name = rl_renderer_name(r);
    size_t len = strlen(name);
    for (int k = 0; k < a->num_sets; k++) {
        char key[128];
        const char *value = NULL;
        if (!cli_split_option("--set", a->sets[k], key, sizeof key, &value))
            return RL_CLI_USAGE;
        if (!first && !(strncmp(key, name, len) == 0 && key[len] == '.'))
            continue;
        const char *other = first ? other_prefix(key, name) : NULL;
        if (other) {
            rl_renderer *o = NULL;
            rl_clear_error();
            rl_status st = rl_renderer_create(other, &o);
            if (st == RL_OK)
                st = rl_renderer_set(o, key, value);
            rl_renderer_release(o);
            if (st != RL_OK)
                return cli_fail_status(RL_CLI_USAGE, st, "--set");
            rl_clear_error();
            continue;
        }
        rl_clear_error();
        rl_status st = rl_renderer_set(r, key, value);
        if (st != RL_OK && first)
            return cli_fail_status(RL_CLI_USAGE, st, "--set");
        rl_clear_error();
    }
    return RL_CLI_OK;
}

/* A renderer by name with its --set options and inputs, or NULL with the
 * reason in why. */
static rl_renderer *make_renderer(const worker *w, const char *name, char *why, size_t n)
{
    rl_renderer *r = NULL;
    rl_clear_error();
    if (rl_renderer_create(name, &r) != RL_OK) {
        snprintf(why, n, "%s", rl_last_error());
        return NULL;
    }
    apply_sets(r, w->args, false);
    rl_clear_error();
    if (!rl_renderer_available(r, why, n) || rl_renderer_prepare_inputs(r, w->scene) != RL_OK) {
        if (rl_last_error()[0])
            snprintf(why, n, "%s", rl_last_error());
        rl_renderer_release(r);
        return NULL;
    }
    /* The shared path: a GL renderer's frames stay textures (the CPU
     * renderers have none and say so, which is no error here). */
    if (w->glshare)
        rl_renderer_set_gl_output(r, true);
    rl_clear_error();
    return r;
}

static void set_fatal(shared *sh, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static void set_fatal(shared *sh, int code, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    SDL_LockMutex(sh->lock);
    if (!sh->fatal) {
        sh->fatal = code;
        vsnprintf(sh->fatal_msg, sizeof sh->fatal_msg, fmt, ap);
    }
    SDL_UnlockMutex(sh->lock);
    va_end(ap);
}

static void set_status(shared *sh, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void set_status(shared *sh, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    SDL_LockMutex(sh->lock);
    vsnprintf(sh->status, sizeof sh->status, fmt, ap);
    SDL_UnlockMutex(sh->lock);
    va_end(ap);
}

/* The live options of + and -, per renderer: those that trade quality for
 * time (or show the trade). The first of a renderer is the one + and -
 * change after a switch; [ and ] select another. A number is multiplied or
 * divided by factor (an integer moves by at least 1) and kept in [lo, hi];
 * factor 0 is a boolean that + and - switch. A number whose 0 means "no
 * limit" (visset's budget) has start > 0: - from 0 sets start, + beyond hi
 * returns to 0. Renderers rebuild what an option changes (svs its sets,
 * surfels nothing but the selection) before the next frame. */
typedef struct step_option {
    const char *algo, *key;
    double factor, lo, hi, start;
} step_option;
static const step_option step_options[] = {
    { "vt", "min_edge", 1.25, 0.25, 1024.0, 0.0 },
    { "pt", "spp", 2.0, 1.0, 1024.0, 0.0 },
    { "surfels", "overdraw", 1.5, 0.01, 1000.0, 0.0 },
    { "surfels", "point_size", 1.25, 0.5, 64.0, 0.0 },
    { "surfels", "min_size", 1.25, 1.0, 1e5, 0.0 },
    { "surfels", "max_size", 1.25, 1.0, 1e5, 0.0 },
    { "chcpp", "assumed_visible", 2.0, 1.0, 1000.0, 0.0 },
    { "chcpp", "batch", 2.0, 1.0, 10000.0, 0.0 },
    { "chcpp", "multiquery", 0.0, 0.0, 0.0, 0.0 },
    { "chcpp", "tight", 0.0, 0.0, 0.0, 0.0 },
    { "svs", "neighbours", 1.5, 1.0, 12.0, 0.0 },
    { "svs", "distance", 1.25, 1.0, 1000.0, 0.0 },
    { "svs", "levels", 1.5, 0.0, 3.0, 0.0 },
    { "svs", "resolution", 2.0, 8.0, 1024.0, 0.0 },
    { "visset", "budget", 2.0, 64.0, 67108864.0, 65536.0 },
    { "visset", "resolution", 2.0, 8.0, 1024.0, 0.0 },
    { "select", "samples", 2.0, 1.0, 256.0, 0.0 },
    { "select", "resolution", 2.0, 8.0, 256.0, 0.0 },
};
#define NUM_STEP_OPTIONS (sizeof step_options / sizeof step_options[0])

/* The i-th live option of renderer name (i wraps), or NULL if it has none. */
static const step_option *live_option(const char *name, int i)
{
    int count = 0;
    for (size_t k = 0; k < NUM_STEP_OPTIONS; k++)
        count += strcmp(step_options[k].algo, name) == 0;
    if (count == 0)
        return NULL;
    i = (i % count + count) % count;
    for (size_t k = 0; k < NUM_STEP_OPTIONS; k++)
        if (strcmp(step_options[k].algo, name) == 0 && i-- == 0)
            return &step_options[k];
    return NULL;
}

static const rl_option_info *option_info(const rl_renderer *r, const char *key)
{
    size_t n = 0;
    const rl_option_info *opts = rl_renderer_options(r, &n);
    for (size_t i = 0; i < n; i++)
        if (strcmp(opts[i].key, key) == 0)
            return &opts[i];
    return NULL;
}

/* Moves the live option o of the current renderer one step in dir. */
static void step_option_apply(worker *w, const step_option *o, int dir)
{
    shared *sh = w->sh;
    const char *name = rl_renderer_name(w->r);
    const rl_option_info *info = option_info(w->r, o->key);
    const char *cur = rl_renderer_get(w->r, o->key);
    char text[64];
    if (info && info->type == RL_OPT_BOOL) {
        snprintf(text, sizeof text, "%s", cur && strcmp(cur, "true") == 0 ? "false" : "true");
    } else {
        double v = 0.0;
        if (!info || !cur || !rl_parse_float(cur, &v)) {
            set_status(sh, "%s has no option %s", name, o->key);
            return;
        }
        bool integer = info->type == RL_OPT_INT;
        double next;
        if (o->start > 0.0 && v == 0.0)
            next = dir < 0 ? o->start : 0.0;
        else {
            next = dir > 0 ? v * o->factor : v / o->factor;
            if (integer) {
                next = (double)llround(next);
                if (next == v)
                    next = v + dir;
            }
            if (o->start > 0.0 && dir > 0 && next > o->hi)
                next = 0.0;
            else
                next = fmin(fmax(next, o->lo), o->hi);
        }
        if (integer)
            snprintf(text, sizeof text, "%lld", (long long)llround(next));
        else
            snprintf(text, sizeof text, "%.4g", next);
    }
    rl_clear_error();
    if (rl_renderer_set(w->r, o->key, text) == RL_OK)
        set_status(sh, "%s %s=%s%s", name, o->key, text, o->start > 0.0 && strcmp(text, "0") == 0 ? " (none)" : "");
    else
        set_status(sh, "%s %s=%s: %s", name, o->key, text, rl_last_error());
    rl_clear_error();
    w->have_last = false;
}

/* Sets the enum option key of the current renderer to its next (dir +1) or
 * previous choice. A choice the renderer refuses here (embree in a build
 * without it) is skipped. */
static void cycle_option(worker *w, const char *key, int dir)
{
    shared *sh = w->sh;
    const char *name = rl_renderer_name(w->r);
    size_t n = 0;
    const rl_option_info *opts = rl_renderer_options(w->r, &n);
    const rl_option_info *o = NULL;
    for (size_t i = 0; i < n; i++)
        if (strcmp(opts[i].key, key) == 0 && opts[i].type == RL_OPT_ENUM && opts[i].choices)
            o = &opts[i];
    if (!o) {
        set_status(sh, "%s has no option %s", name, key);
        return;
    }
    int count = 0, cur = 0;
    const char *value = rl_renderer_get(w->r, key);
    for (; o->choices[count]; count++)
        if (value && strcmp(o->choices[count], value) == 0)
            cur = count;
    for (int step = 1; step < count; step++) {
        const char *next = o->choices[((cur + dir * step) % count + count) % count];
        rl_clear_error();
        if (rl_renderer_set(w->r, key, next) == RL_OK) {
            set_status(sh, "%s %s=%s", name, key, next);
            w->have_last = false;
            rl_clear_error();
            return;
        }
    }
    set_status(sh, "%s %s: no other choice works here (%s)", name, key, rl_last_error());
    rl_clear_error();
}

/* The current renderer's options for the menu, one a line: "key=value",
 * the live option of + and - marked ">". */
static void publish_options(worker *w)
{
    shared *sh = w->sh;
    char text[sizeof sh->options];
    size_t n = 0, len = 0;
    const rl_option_info *opts = rl_renderer_options(w->r, &n);
    const step_option *sel = live_option(rl_renderer_name(w->r), w->step_sel);
    text[0] = '\0';
    for (size_t i = 0; i < n; i++) {
        const char *value = rl_renderer_get(w->r, opts[i].key);
        char item[160];
        int k = snprintf(item, sizeof item, "%s%s=%s", sel && strcmp(sel->key, opts[i].key) == 0 ? ">" : "",
                         opts[i].key, value ? value : "?");
        if (k < 0 || k >= (int)sizeof item)
            continue;
        if (len + (size_t)k + 2 >= sizeof text)
            break;
        len += (size_t)snprintf(text + len, sizeof text - len, "%s\n", item);
    }
    SDL_LockMutex(sh->lock);
    snprintf(sh->options, sizeof sh->options, "%s", text);
    SDL_UnlockMutex(sh->lock);
}

static void apply_cmd(worker *w, const view_cmd *c)
{
    shared *sh = w->sh;
    char why[512] = "";
    if (c->kind == CMD_ALGO) {
        rl_renderer *r = NULL;
        for (size_t i = 0; i < sizeof w->parked / sizeof w->parked[0] && !r; i++)
            if (w->parked[i] && strcmp(rl_renderer_name(w->parked[i]), c->text) == 0) {
                /* as new: its defaults, then --set, and no frame-to-frame state */
                r = w->parked[i];
                w->parked[i] = NULL;
                size_t n = 0;
                const rl_option_info *opts = rl_renderer_options(r, &n);
                for (size_t k = 0; k < n; k++)
                    rl_renderer_set(r, opts[k].key, opts[k].default_value);
                apply_sets(r, w->args, false);
                rl_renderer_reset(r);
                rl_clear_error();
            }
        if (!r)
            r = make_renderer(w, c->text, why, sizeof why);
        if (!r) {
            if (c->line)
                set_fatal(sh, RL_CLI_FAIL, "%s:%d: algo %s: %s", w->args->script, c->line, c->text, why);
            set_status(sh, "%s: %s", c->text, why);
            return;
        }
        /* A GL renderer of the shared path (one that takes texture output) is
         * parked, not released; a full park releases its oldest. */
        rl_renderer *old = w->r;
        if (w->glshare && rl_renderer_set_gl_output(old, true) == RL_OK) {
            rl_renderer_release(w->parked[0]);
            memmove(w->parked, w->parked + 1, sizeof w->parked - sizeof w->parked[0]);
            w->parked[sizeof w->parked / sizeof w->parked[0] - 1] = old;
            old = NULL;
        }
        rl_clear_error();
        rl_renderer_release(old);
        w->r = r;
        w->have_last = false;
        w->step_sel = 0;
        SDL_LockMutex(sh->lock);
        snprintf(sh->algo, sizeof sh->algo, "%.63s", c->text);
        sh->worker_progressive = is_progressive(c->text);
        sh->worker_spp = 0.0;
        snprintf(sh->status, sizeof sh->status, "renderer %.200s", c->text);
        SDL_UnlockMutex(sh->lock);
        return;
    }
    if (c->kind == CMD_SET) {
        char key[128];
        const char *value = strchr(c->text, '=');
        size_t n = (size_t)(value - c->text);
        snprintf(key, sizeof key, "%.*s", (int)(n < sizeof key ? n : sizeof key - 1), c->text);
        rl_clear_error();
        rl_status st = rl_renderer_set(w->r, key, value + 1);
        if (st != RL_OK) {
            if (c->line)
                set_fatal(sh, RL_CLI_USAGE, "%s:%d: set %s: %s", w->args->script, c->line, c->text, rl_last_error());
            set_status(sh, "set %s: %s", c->text, rl_last_error());
        } else
            set_status(sh, "%s %s", rl_renderer_name(w->r), c->text);
        rl_clear_error();
        w->have_last = false;
        return;
    }
    if (c->kind == CMD_CYCLE) {
        cycle_option(w, c->text, c->dir);
        return;
    }
    if (c->kind == CMD_REFERENCE) {
        w->want_ref = true;
        set_status(sh, "comparing with a reference after this frame ...");
        return;
    }
    const char *name = rl_renderer_name(w->r);
    if (c->kind == CMD_CLICK) {
        /* A menu entry: an enum or a boolean goes to its next choice, a
         * live number one step (and becomes the one of + and -). */
        const rl_option_info *info = option_info(w->r, c->text);
        for (int i = 0, n = 0; info && (size_t)i < NUM_STEP_OPTIONS; i++) {
            if (strcmp(step_options[i].algo, name) != 0)
                continue;
            if (strcmp(step_options[i].key, c->text) == 0) {
                w->step_sel = n;
                step_option_apply(w, &step_options[i], c->dir);
                return;
            }
            n++;
        }
        if (info && info->type == RL_OPT_ENUM && info->choices)
            cycle_option(w, c->text, c->dir);
        else if (info && info->type == RL_OPT_BOOL)
            step_option_apply(w, &(step_option){ .algo = name, .key = info->key }, c->dir);
        else
            set_status(sh, "%s %s: not a live option (--set it, or a script's set)", name, c->text);
        return;
    }
    const step_option *o = live_option(name, w->step_sel);
    if (!o) {
        set_status(sh, "%s: no live option for + and -", name);
        return;
    }
    if (c->kind == CMD_SELECT) {
        w->step_sel += c->dir;
        o = live_option(name, w->step_sel);
        set_status(sh, "+ and - change %s %s=%s", name, o->key, rl_renderer_get(w->r, o->key));
        return;
    }
    step_option_apply(w, o, c->dir);
}

static bool is_path_tracer(const char *name)
{
    return strcmp(name, "pt") == 0 || strcmp(name, "gl-pt") == 0 || strcmp(name, "bdpt") == 0;
}

/* X: the frame just finished against an exact reference of the same camera
 * (Whitted ray tracing; pt at --ref-spp with another seed for the path
 * tracers, whose images whitted's local model cannot match), by SSIM and
 * the hierarchical SSIM of Jahn 2015 Sec. 4.2.5. A change cancels it. */
static void compare_reference(worker *w, const rl_camera *cam)
{
    shared *sh = w->sh;
    const char *of = rl_renderer_name(w->r);
    const char *ref_name = is_path_tracer(of) ? "pt" : "whitted";
    char why[512] = "";
    if (w->ref && strcmp(rl_renderer_name(w->ref), ref_name) != 0) {
        rl_renderer_release(w->ref);
        w->ref = NULL;
    }
    if (!w->ref) {
        w->ref = make_renderer(w, ref_name, why, sizeof why);
        if (!w->ref) {
            set_status(sh, "reference %s: %s", ref_name, why);
            return;
        }
    }
    char spp[32];
    snprintf(spp, sizeof spp, "%lld", w->args->ref_spp);
    rl_clear_error();
    if (strcmp(ref_name, "pt") == 0 &&
        (rl_renderer_set(w->ref, "spp", spp) != RL_OK || rl_renderer_set(w->ref, "accumulate", "false") != RL_OK ||
         rl_renderer_set(w->ref, "seed", "7919") != RL_OK)) {
        set_status(sh, "reference pt: %s", rl_last_error());
        rl_clear_error();
        return;
    }
    rl_status st = fit_image(&w->ref_img, cam->width, cam->height, RL_LAYER_COLOR);
    rl_render_stats stats = { 0 };
    rl_renderer_set_progress(w->ref, on_progress, w);
    if (st == RL_OK)
        st = rl_renderer_render(w->ref, w->scene, cam, w->ref_img, &stats);
    if (st == RL_ERR_CANCELLED) {
        set_status(sh, "reference cancelled by a change; press X again");
        rl_clear_error();
        return;
    }
    rl_image_metrics m = { 0 }, hm = { 0 };
    int levels = 1;
    while (levels < 5 && (cam->width < cam->height ? cam->width : cam->height) >> levels >= 11)
        levels++;
    if (st == RL_OK)
        st = rl_image_compare(w->back, w->ref_img, NULL, &m);
    if (st == RL_OK && levels >= 2)
        st = rl_image_compare(w->back, w->ref_img, &(rl_metric_options){ .ssim_levels = levels }, &hm);
    if (st != RL_OK) {
        set_status(sh, "reference %s: %s", ref_name, rl_last_error()[0] ? rl_last_error() : rl_status_string(st));
        rl_clear_error();
        return;
    }
    SDL_LockMutex(sh->lock);
    sh->ref_valid = true;
    snprintf(sh->ref_algo, sizeof sh->ref_algo, "%s", ref_name);
    snprintf(sh->ref_of, sizeof sh->ref_of, "%s", of);
    sh->ref_ssim = m.ssim;
    sh->ref_rmse = m.rmse;
    sh->ref_levels = levels >= 2 ? levels : 0;
    sh->ref_hssim = levels >= 2 ? hm.ssim : NAN;
    sh->ref_spp = strcmp(ref_name, "pt") == 0 ? (double)w->args->ref_spp : 0.0;
    if (levels >= 2)
        snprintf(sh->status, sizeof sh->status, "%s vs %s: SSIM %.4f hSSIM(%d) %.4f RMSE %.4f", of, ref_name,
                 m.ssim, levels, hm.ssim, m.rmse);
    else
        snprintf(sh->status, sizeof sh->status, "%s vs %s: SSIM %.4f RMSE %.4f", of, ref_name, m.ssim, m.rmse);
    SDL_UnlockMutex(sh->lock);
}

static int worker_main(void *user)
{
    worker *w = user;
    shared *sh = w->sh;
    view_cmd cmds[MAX_CMDS];
    for (;;) {
        SDL_LockMutex(sh->lock);
        while (!sh->quit && sh->done_seq == sh->req_seq)
            SDL_CondWait(sh->wake, sh->lock);
        if (sh->quit) {
            SDL_UnlockMutex(sh->lock);
            break;
        }
        uint64_t seq = sh->req_seq;
        rl_camera cam = sh->req_cam;
        int ncmds = sh->num_cmds;
        memcpy(cmds, sh->cmds, (size_t)ncmds * sizeof *cmds);
        sh->num_cmds = 0;
        w->running_gen = SDL_AtomicGet(&sh->gen);
        w->running_moved = sh->req_moved;
        w->running_request_s = sh->req_time_s;
        SDL_UnlockMutex(sh->lock);

        for (int i = 0; i < ncmds; i++)
            apply_cmd(w, &cmds[i]);
        if (ncmds > 0 || !w->have_last)
            publish_options(w);
        if (!w->have_last || !rl_camera_equal(&cam, &w->last_cam)) {
            SDL_LockMutex(sh->lock);
            sh->worker_spp = 0.0;
            SDL_UnlockMutex(sh->lock);
        }
        w->last_cam = cam;
        w->have_last = true;
        rl_renderer_set_progress(w->r, on_progress, w);
        if (strcmp(rl_renderer_name(w->r), "vt") == 0)
            rl_vt_set_update_callback(w->r, on_vt_update, w);
        rl_render_stats stats = { 0 };
        rl_clear_error();
        rl_status st = fit_image(&w->back, cam.width, cam.height, VIEW_LAYERS);
        /* X compares w->back's colour: that frame is read back. */
        bool texture = w->glshare && !w->want_ref && rl_renderer_set_gl_output(w->r, true) == RL_OK;
        if (w->glshare && !texture)
            rl_renderer_set_gl_output(w->r, false);
        rl_clear_error();
        if (st == RL_OK)
            st = rl_renderer_render(w->r, w->scene, &cam, w->back, &stats);
        if (st == RL_OK) {
            double pixels = (double)cam.width * (double)cam.height;
            SDL_LockMutex(sh->lock);
            sh->worker_spp += (double)stats.samples / pixels;
            SDL_UnlockMutex(sh->lock);
            rl_gl_frame tex = { 0 };
            /* A frame the renderer finished on the CPU (gl-pt's filter) has
             * no texture and is in w->back. */
            texture = texture && rl_renderer_take_gl_frame(w->r, &tex) == RL_OK;
            rl_clear_error();
            publish(w, w->back, &stats, true, texture ? &tex : NULL);
            if (w->want_ref) {
                w->want_ref = false;
                compare_reference(w, &cam);
            }
        } else if (st != RL_ERR_CANCELLED) {
            const char *msg = rl_last_error()[0] ? rl_last_error() : rl_status_string(st);
            set_fatal(sh, RL_CLI_FAIL, "render: %s: %s", rl_renderer_name(w->r), msg);
            set_status(sh, "%s: %s", rl_renderer_name(w->r), msg);
        }
        rl_clear_error();
        SDL_LockMutex(sh->lock);
        sh->done_seq = seq;
        SDL_CondBroadcast(sh->done);
        SDL_UnlockMutex(sh->lock);
    }
    return 0;
}

/* ---- the camera ---- */

typedef struct nav {
    rl_camera cam;
    float speed;          /* world units per second of flight */
    float min_dist;       /* the closest a dolly gets to the target */
    bool changed;
} nav;

static rl_vec3 world_up(const rl_camera *c)
{
    return rl_length2(c->up) > 0.0f ? rl_normalize(c->up) : rl_v3(0.0f, 1.0f, 0.0f);
}

/* Moves eye and target together along the view frame. */
static void nav_fly(nav *n, float forward, float right, float up)
{
    rl_vec3 f = rl_normalize(rl_sub(n->cam.target, n->cam.eye));
    rl_vec3 u = world_up(&n->cam);
    rl_vec3 r = rl_cross(f, u);
    if (!(rl_length2(r) > 1e-12f))
        return;
    r = rl_normalize(r);
    rl_vec3 d = rl_add(rl_add(rl_scale(f, forward), rl_scale(r, right)), rl_scale(u, up));
    n->cam.eye = rl_add(n->cam.eye, d);
    n->cam.target = rl_add(n->cam.target, d);
    n->changed = true;
}

/* v turned by yaw about up and by pitch about the axis right of v, with
 * the pitch stopped short of the poles (where look-at loses its frame). */
static rl_vec3 turn(rl_vec3 v, rl_vec3 up, float yaw, float pitch)
{
    float len = rl_length(v);
    rl_vec3 d = rl_scale(v, 1.0f / len);
    float cur = asinf(fminf(fmaxf(rl_dot(d, up), -1.0f), 1.0f));
    float lim = 1.5f;
    float next = fminf(fmaxf(cur + pitch, -lim), lim);
    rl_vec3 h = rl_sub(d, rl_scale(up, rl_dot(d, up)));
    if (!(rl_length2(h) > 1e-12f))
        return v;
    h = rl_normalize(h);
    rl_vec3 side = rl_cross(up, h);
    rl_vec3 hy = rl_add(rl_scale(h, cosf(yaw)), rl_scale(side, sinf(yaw)));
    rl_vec3 out = rl_add(rl_scale(hy, cosf(next)), rl_scale(up, sinf(next)));
    return rl_scale(out, len);
}

/* Right drag: the eye stays, the view turns. */
static void nav_look(nav *n, float dx, float dy)
{
    rl_vec3 v = rl_sub(n->cam.target, n->cam.eye);
    n->cam.target = rl_add(n->cam.eye, turn(v, world_up(&n->cam), -dx * 0.004f, -dy * 0.004f));
    n->changed = true;
}

/* Left drag: the target stays, the eye circles it. */
static void nav_orbit(nav *n, float dx, float dy)
{
    rl_vec3 v = rl_sub(n->cam.eye, n->cam.target);
    n->cam.eye = rl_add(n->cam.target, turn(v, world_up(&n->cam), -dx * 0.008f, dy * 0.008f));
    n->changed = true;
}

static void nav_dolly(nav *n, float steps)
{
    rl_vec3 v = rl_sub(n->cam.eye, n->cam.target);
    float d = rl_length(v);
    float next = fmaxf(d * powf(0.85f, steps), n->min_dist);
    n->cam.eye = rl_add(n->cam.target, rl_scale(v, next / d));
    n->changed = true;
}

/* ---- the viewer ---- */

typedef struct algo_stat {
    char name[64];
    long long frames, moving_frames;
    double moving_s;            /* request to finished frame, summed over moving frames */
    double first_image_ms, first_final_ms, prep_ms;
    double display_s;           /* taking and drawing its new images, summed */
    long long displayed;
    long long shared_frames;    /* of displayed: shown from a GL texture (the shared path) */
    /* From a restart (camera, renderer or option change) to its first
     * image on screen, an intermediate one included, summed. */
    double latency_s;
    long long latency_n;
    double last_restart_s;      /* the request time of the restart shown last */
    /* After the last restart: images shown until the image is stable, a
     * final one that nothing more will change (a renderer that does not
     * accumulate) or that changed less than STABLE_CHANGE from the one
     * before (one that does). */
    long long settle_frames;
    double settle_ms, last_change;
    bool settled;
    double requested_s;         /* when the renderer was asked for */
    bool have_first, have_final;
} algo_stat;

/* An entry of the menu (M) where it is drawn, for the mouse. */
enum { MENU_MAX_ITEMS = 256 };
typedef struct menu_item {
    int x, y, w, h;
    int algo;             /* the renderer's index in algos; -1 an option, -2 a heading */
    char label[96];       /* as drawn: an option's "key=value", ">" before the live one */
} menu_item;

typedef struct viewer {
    view_args *a;
    const rl_scene *scene;
    const rl_scene_data *data;
    shared sh;
    worker wk;
    SDL_Thread *thread;
    SDL_Window *win;
    SDL_Renderer *ren;
    char display[32];           /* SDL's renderer: software or opengl; or gl-shared */
    /* The shared path (--display shared or auto with a GL renderer): the
     * window's EGL context shared with the library (view_gl.c); NULL on the
     * readback path, with the reason it was not taken in path_why. */
    view_gl *gl;
    char path_why[256];
    bool shown_gpu;             /* the shown frame's colour is the texture of v->gl */
    bool shown_cpu;             /* v->shown->color holds the shown frame's colour */
    int px_rows, tex_rows;      /* rows of v->pixels / of the overlay texture that may not be transparent */
    SDL_Texture *tex;
    uint32_t *pixels;
    rl_image *shown;            /* the displayed frame, without the overlay */
    rl_render_stats shown_stats;
    char shown_algo[64];
    double shown_spp;
    bool shown_final;
    uint64_t shown_seq, recorded_seq;
    nav nav;
    int width, height;          /* of the frames asked for now; the shown one's may still differ */
    bool follow_window;         /* the image has the window's size (not --size WxH) */
    bool held[VIEW_KEY_COUNT];
    bool help, stats, menu;
    menu_item menu_items[MENU_MAX_ITEMS];   /* where the menu's entries are drawn */
    int num_menu_items;
    bool mouse_taken;           /* the pressed button clicked the menu: its drag is no orbit */
    cli_layer layer;            /* what L shows: colour, depth or IDs */
    rl_vec4 *layer_px;          /* the depth or ID picture */
    bool need_frame;            /* a frame without a restart is wanted (X) */
    /* algorithms Tab cycles through */
    const char **algos;
    size_t num_algos;
    size_t algo_index;
    /* the camera path */
    bool playing;
    double play_t;
    bool recording;
    rl_camera_key *rec;
    size_t num_rec, cap_rec;
    double rec_t0;
    char rec_file[4096];
    /* time */
    bool scripted;
    double now;                 /* seconds: virtual with a script, else wall */
    double start_wall;
    long long shot_counter, record_counter;
    /* frame rate */
    double final_times[32];
    int num_final;
    algo_stat stats_by_algo[32];
    int num_stats;
    bool shown_moved;           /* the shown frame was asked for by a change */
    double shown_request_s;
    int rc;
} viewer;

/* The scene's camera (name NULL: its first; index >= 0: the index-th)
 * at the viewer's size. */
static int scene_camera(const viewer *v, const char *name, rl_camera *cam)
{
    rl_clear_error();
    rl_status st = rl_scene_get_camera(v->scene, name, cam);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, "--camera");
    bool has_cameras = v->data->num_cameras > 0;
    if (v->a->has_size) {
        cam->width = v->a->width;
        cam->height = v->a->height;
    } else if (!has_cameras || cam->width <= 0 || cam->height <= 0) {
        cam->width = RL_CLI_DEFAULT_WIDTH;
        cam->height = RL_CLI_DEFAULT_HEIGHT;
    }
    if (!has_cameras) {
        rl_camera fit;
        if (rl_scene_fit_camera(v->scene, cam->width, cam->height, &fit) == RL_OK)
            *cam = fit;
    }
    *cam = rl_camera_resolve(cam);
    rl_clear_error();
    st = rl_camera_validate(cam);
    if (st != RL_OK)
        return cli_fail(RL_CLI_FAIL, "%s: no usable camera for this scene (%s)", v->a->scene, rl_last_error());
    return RL_CLI_OK;
}

static algo_stat *stat_of(viewer *v, const char *name)
{
    for (int i = 0; i < v->num_stats; i++)
        if (strcmp(v->stats_by_algo[i].name, name) == 0)
            return &v->stats_by_algo[i];
    if (v->num_stats == (int)(sizeof v->stats_by_algo / sizeof v->stats_by_algo[0]))
        return NULL;
    algo_stat *s = &v->stats_by_algo[v->num_stats++];
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%s", name);
    return s;
}

/* Asks the worker for a frame of the current camera. restart: the running
 * frame is obsolete (the camera or the renderer changed) and is cancelled. */
static void request(viewer *v, bool restart)
{
    shared *sh = &v->sh;
    SDL_LockMutex(sh->lock);
    if (restart)
        SDL_AtomicAdd(&sh->gen, 1);
    sh->req_cam = v->nav.cam;
    sh->req_seq++;
    sh->req_moved = restart;
    sh->req_time_s = rl_time_s();
    SDL_CondSignal(sh->wake);
    SDL_UnlockMutex(sh->lock);
}

static void push_cmd(viewer *v, cmd_kind kind, const char *text, int dir, int line)
{
    shared *sh = &v->sh;
    SDL_LockMutex(sh->lock);
    if (sh->num_cmds < MAX_CMDS) {
        view_cmd *c = &sh->cmds[sh->num_cmds++];
        c->kind = kind;
        snprintf(c->text, sizeof c->text, "%s", text ? text : "");
        c->dir = dir;
        c->line = line;
    }
    SDL_UnlockMutex(sh->lock);
    if (kind == CMD_ALGO) {
        algo_stat *s = stat_of(v, text);
        if (s && !s->have_first)
            s->requested_s = rl_time_s();
    }
}

static bool worker_idle(viewer *v)
{
    SDL_LockMutex(v->sh.lock);
    bool idle = v->sh.done_seq == v->sh.req_seq;
    SDL_UnlockMutex(v->sh.lock);
    return idle;
}

/* ---- output ---- */

static void draw(viewer *v);
static bool draw_ex(viewer *v, uint32_t *capture);
static bool ensure_shown_color(viewer *v);
static bool menu_click(viewer *v, int x, int y, int button);

static rl_status write_shot_json(const viewer *v, const char *png, const char *path)
{
    cJSON *obj = cli_render_stats_json(&v->shown_stats, 0.0);
    if (!obj)
        return RL_ERR_OUT_OF_MEMORY;
    cJSON_AddStringToObject(obj, "algorithm", v->shown_algo);
    cJSON_AddStringToObject(obj, "scene", v->a->scene);
    cJSON_AddNumberToObject(obj, "width", v->shown->width);
    cJSON_AddNumberToObject(obj, "height", v->shown->height);
    cJSON_AddStringToObject(obj, "file", png);
    cJSON_AddNumberToObject(obj, "spp", v->shown_spp);
    cJSON_AddBoolToObject(obj, "final", v->shown_final);
    cJSON_AddNumberToObject(obj, "time_s", v->now);
    const rl_vec3 vec[3] = { v->nav.cam.eye, v->nav.cam.target, v->nav.cam.up };
    const char *keys[3] = { "eye", "target", "up" };
    for (int k = 0; k < 3; k++) {
        cJSON *arr = cJSON_AddArrayToObject(obj, keys[k]);
        const double c[3] = { vec[k].x, vec[k].y, vec[k].z };
        for (int j = 0; arr && j < 3; j++)
            cJSON_AddItemToArray(arr, cJSON_CreateNumber(c[j]));
    }
    cJSON_AddNumberToObject(obj, "fov_deg", v->nav.cam.fov_deg);
    /* The last comparison of X, whichever frame it was made on. */
    shared *sh = (shared *)&v->sh;
    SDL_LockMutex(sh->lock);
    /* The renderer's options, so that a screenshot says how to make it
     * again with rl render --set (the live ones change during a run). */
    cJSON *opts = cJSON_AddObjectToObject(obj, "options");
    char options[sizeof sh->options];
    snprintf(options, sizeof options, "%s", sh->options);
    char *save = NULL;
    for (char *line = strtok_r(options, "\n", &save); opts && line; line = strtok_r(NULL, "\n", &save)) {
        char *eq = strchr(line, '=');
        if (!eq)
            continue;
        *eq = '\0';
        cJSON_AddStringToObject(opts, line[0] == '>' ? line + 1 : line, eq + 1);
    }
    cJSON *ref = sh->ref_valid ? cJSON_AddObjectToObject(obj, "reference") : NULL;
    if (ref) {
        cJSON_AddStringToObject(ref, "algorithm", sh->ref_algo);
        cJSON_AddStringToObject(ref, "compared", sh->ref_of);
        if (sh->ref_spp > 0.0)
            cJSON_AddNumberToObject(ref, "spp", sh->ref_spp);
        cJSON_AddNumberToObject(ref, "ssim", sh->ref_ssim);
        if (sh->ref_levels >= 2) {
            cJSON_AddNumberToObject(ref, "hssim", sh->ref_hssim);
            cJSON_AddNumberToObject(ref, "hssim_levels", sh->ref_levels);
        }
        cJSON_AddNumberToObject(ref, "rmse", sh->ref_rmse);
    }
    SDL_UnlockMutex(sh->lock);
    rl_status st = cli_write_json_status(obj, path);
    cJSON_Delete(obj);
    return st;
}

/* FILE.png and FILE.json beside it, renamed into place together. */
static bool write_screenshot(viewer *v, const char *png)
{
    char json[4096];
    size_t n = strlen(png);
    if (n < 4 || n - 4 + 6 > sizeof json) {
        cli_fail(RL_CLI_FAIL, "%s: name too long", png);
        return false;
    }
    snprintf(json, sizeof json, "%.*s.json", (int)(n - 4), png);
    rl_output_batch *batch = NULL;
    const char *tmp = NULL, *what = png;
    rl_clear_error();
    rl_status st = rl_output_batch_create(&batch);
    if (st == RL_OK && !ensure_shown_color(v)) {
        rl_output_batch_release(batch);
        cli_fail(RL_CLI_FAIL, "%s: the frame cannot be read back from the window's context", png);
        return false;
    }
    if (st == RL_OK && (st = rl_output_batch_add(batch, png, &tmp)) == RL_OK)
        st = rl_image_write(v->shown, tmp);
    if (st == RL_OK && (st = rl_output_batch_add(batch, what = json, &tmp)) == RL_OK)
        st = write_shot_json(v, png, tmp);
    if (st == RL_OK)
        st = rl_output_batch_commit(batch);
    rl_output_batch_release(batch);
    if (st != RL_OK) {
        cli_fail_status(RL_CLI_FAIL, st, what);
        return false;
    }
    return true;
}

/* What the window shows, overlay included (for documentation and for
 * testing the overlay): the displayed bytes decoded back to linear, which
 * the PNG writer encodes to the same bytes. */
static bool write_capture(viewer *v, const char *png)
{
    rl_image *img = NULL;
    rl_clear_error();
    uint32_t *px = malloc((size_t)v->shown->width * (size_t)v->shown->height * sizeof *px);
    /* a key of the script (help, stats) may have changed the overlay */
    if (!px || !draw_ex(v, px)) {
        free(px);
        cli_fail(RL_CLI_FAIL, "%s: cannot read the window's pixels", png);
        return false;
    }
    rl_status st = rl_image_create(v->shown->width, v->shown->height, RL_LAYER_COLOR, &img);
    if (st == RL_OK) {
        float lin[256];
        for (int i = 0; i < 256; i++)
            lin[i] = rl_srgb_to_linear((float)i / 255.0f);
        for (size_t i = 0; i < (size_t)img->width * (size_t)img->height; i++) {
            uint32_t p = px[i];
            img->color[i] = (rl_vec4){ lin[p >> 16 & 255], lin[p >> 8 & 255], lin[p & 255], 1.0f };
        }
        st = rl_image_write(img, png);
    }
    free(px);
    rl_image_release(img);
    if (st != RL_OK) {
        cli_fail_status(RL_CLI_FAIL, st, png);
        return false;
    }
    return true;
}

static void add_vec(cJSON *obj, const char *key, rl_vec3 v)
{
    cJSON *arr = cJSON_AddArrayToObject(obj, key);
    const double c[3] = { v.x, v.y, v.z };
    for (int j = 0; arr && j < 3; j++)
        cJSON_AddItemToArray(arr, cJSON_CreateNumber(c[j]));
}

/* The recorded keys as a scene file that `rl render --camera-path` reads:
 * a built-in scene as its "base" (with its parameters), a JSON scene as a
 * copy of itself with the path replaced. A model file has no such form
 * yet. */
static bool save_path(viewer *v, const char *path, char *why, size_t n)
{
    char *source = NULL, *params = NULL;
    if (!cli_split_source(v->a->scene, &source, &params)) {
        snprintf(why, n, "out of memory");
        return false;
    }
    cJSON *doc = NULL;
    bool ok = false;
    if (cli_is_builtin(source)) {
        doc = cJSON_CreateObject();
        if (doc) {
            cJSON_AddStringToObject(doc, "base", source);
            if (params)
                cJSON_AddStringToObject(doc, "params", params);
        }
    } else if (cli_has_extension(source, (const char *const[]){ ".json", NULL })) {
        FILE *f = fopen(source, "rb");
        char *text = NULL;
        if (f && fseek(f, 0, SEEK_END) == 0) {
            long size = ftell(f);
            if (size >= 0 && size < (1L << 30) && fseek(f, 0, SEEK_SET) == 0 && (text = malloc((size_t)size + 1))) {
                size_t got = fread(text, 1, (size_t)size, f);
                text[got] = '\0';
                doc = cJSON_Parse(text);
            }
        }
        if (f)
            fclose(f);
        free(text);
        if (doc && !cJSON_IsObject(doc)) {
            cJSON_Delete(doc);
            doc = NULL;
        }
        cJSON_DeleteItemFromObject(doc, "camera_path");
    } else {
        snprintf(why, n, "a camera path of a model file cannot be saved yet (use a JSON scene with \"file\")");
        goto done;
    }
    if (!doc) {
        snprintf(why, n, "%s: cannot read the scene to save the path with", source);
        goto done;
    }
    cJSON *cp = cJSON_AddObjectToObject(doc, "camera_path");
    cJSON *keys = cp ? cJSON_AddArrayToObject(cp, "keys") : NULL;
    for (size_t i = 0; keys && i < v->num_rec; i++) {
        cJSON *k = cJSON_CreateObject();
        if (!k)
            break;
        cJSON_AddNumberToObject(k, "time_s", v->rec[i].time_s);
        add_vec(k, "eye", v->rec[i].camera.eye);
        add_vec(k, "target", v->rec[i].camera.target);
        add_vec(k, "up", v->rec[i].camera.up);
        cJSON_AddNumberToObject(k, "fov_deg", v->rec[i].camera.fov_deg);
        cJSON_AddItemToArray(keys, k);
    }
    rl_status st = cli_write_json_status(doc, path);
    ok = st == RL_OK;
    if (!ok)
        snprintf(why, n, "%s", rl_last_error()[0] ? rl_last_error() : rl_status_string(st));
done:
    cJSON_Delete(doc);
    free(source);
    free(params);
    return ok;
}

/* ---- actions ---- */

static void set_camera(viewer *v, const rl_camera *cam)
{
    v->nav.cam = *cam;
    v->nav.cam.width = v->width;
    v->nav.cam.height = v->height;
    v->nav.cam = rl_camera_resolve(&v->nav.cam);
    v->nav.changed = true;
}

static void say(viewer *v, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
static void say(viewer *v, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    SDL_LockMutex(v->sh.lock);
    vsnprintf(v->sh.status, sizeof v->sh.status, fmt, ap);
    SDL_UnlockMutex(v->sh.lock);
    va_end(ap);
}

/* The image size for a window of w x h pixels: the same, or scaled down
 * with its aspect kept to at most VIEW_MAX_WINDOW_PIXELS. */
static void window_image_size(int w, int h, int *iw, int *ih)
{
    w = w < 1 ? 1 : w;
    h = h < 1 ? 1 : h;
    double area = (double)w * (double)h;
    if (area > VIEW_MAX_WINDOW_PIXELS) {
        double f = sqrt(VIEW_MAX_WINDOW_PIXELS / area);
        w = (int)fmax(1.0, floor(w * f));
        h = (int)fmax(1.0, floor(h * f));
    }
    *iw = w;
    *ih = h;
}

/* The window is w x h pixels now: an image that follows it is rendered
 * anew at that size (the renderer restarts, as for a camera change). */
static void window_resized(viewer *v, int w, int h)
{
    if (!v->follow_window)
        return;
    int iw, ih;
    window_image_size(w, h, &iw, &ih);
    if (iw == v->width && ih == v->height)
        return;
    v->width = iw;
    v->height = ih;
    v->nav.cam.width = iw;
    v->nav.cam.height = ih;
    v->nav.changed = true;
}

static void start_recording(viewer *v, const char *file)
{
    snprintf(v->rec_file, sizeof v->rec_file, "%s", file);
    v->recording = true;
    v->num_rec = 0;
    v->rec_t0 = v->now;
    say(v, "recording a camera path");
}

/* Adds a key when the camera moved since the last one (and the first). */
static void record_tick(viewer *v)
{
    if (!v->recording)
        return;
    if (v->num_rec > 0 && rl_camera_equal(&v->rec[v->num_rec - 1].camera, &v->nav.cam))
        return;
    double t = v->now - v->rec_t0;
    /* At most a key per script step (1/25 s): the times must increase, and
     * an interactive loop turning every few milliseconds would add
     * hundreds of keys a second that the spline does not need. */
    if (v->num_rec > 0 && t - v->rec[v->num_rec - 1].time_s < 1.0 / SCRIPT_FPS - 1e-6)
        return;
    if (v->num_rec == v->cap_rec) {
        size_t cap = v->cap_rec ? 2 * v->cap_rec : 64;
        rl_camera_key *k = cap <= 1000000 ? realloc(v->rec, cap * sizeof *k) : NULL;
        if (!k) {
            say(v, "recording: too many keys, stopped");
            v->recording = false;
            return;
        }
        v->rec = k;
        v->cap_rec = cap;
    }
    v->rec[v->num_rec].time_s = t;
    v->rec[v->num_rec].camera = v->nav.cam;
    v->num_rec++;
}

static bool stop_recording(viewer *v)
{
    v->recording = false;
    if (v->num_rec == 0) {
        say(v, "recording: no keys");
        return true;
    }
    char why[512];
    if (!save_path(v, v->rec_file, why, sizeof why)) {
        say(v, "recording: %s", why);
        if (v->scripted) {
            cli_fail(RL_CLI_FAIL, "record %s: %s", v->rec_file, why);
            return false;
        }
        return true;
    }
    say(v, "saved %zu keys to %s", v->num_rec, v->rec_file);
    return true;
}

static void switch_algo(viewer *v, int dir)
{
    if (v->num_algos == 0)
        return;
    v->algo_index = (v->algo_index + v->num_algos + (size_t)(dir > 0 ? 1 : v->num_algos - 1)) % v->num_algos;
    push_cmd(v, CMD_ALGO, v->algos[v->algo_index], 0, 0);
    v->nav.changed = true;
}

/* The F12 file: the first free rl-view-NNNN.png of --shot-dir. */
static void screenshot_key(viewer *v)
{
    char path[4096];
    for (int tries = 0; tries < 10000; tries++) {
        snprintf(path, sizeof path, "%s/rl-view-%04lld.png", v->a->shot_dir, v->shot_counter++);
        struct stat st;
        if (stat(path, &st) != 0)
            break;
    }
    if (write_screenshot(v, path))
        say(v, "wrote %s", path);
    else
        say(v, "screenshot failed: %s", path);
}

/* A key pressed once (held keys only set v->held). false: quit. */
static bool press(viewer *v, view_key k)
{
    if (k >= VIEW_KEY_CAMERA_1 && k < VIEW_KEY_CAMERA_1 + 9) {
        uint32_t i = (uint32_t)(k - VIEW_KEY_CAMERA_1);
        if (i >= v->data->num_cameras && !(i == 0)) {
            say(v, "the scene has %u camera%s", v->data->num_cameras, v->data->num_cameras == 1 ? "" : "s");
            return true;
        }
        rl_camera cam;
        if (scene_camera(v, v->data->num_cameras ? v->data->camera_names[i] : NULL, &cam) == RL_CLI_OK)
            set_camera(v, &cam);
        return true;
    }
    const rl_camera_path *path = v->data->camera_path;
    switch (k) {
    case VIEW_KEY_CAMERA_RESET: {
        rl_camera cam;
        if (scene_camera(v, NULL, &cam) == RL_CLI_OK)
            set_camera(v, &cam);
        break;
    }
    case VIEW_KEY_NEXT_ALGO: switch_algo(v, 1); break;
    case VIEW_KEY_PREV_ALGO: switch_algo(v, -1); break;
    case VIEW_KEY_HELP: v->help = !v->help; break;
    case VIEW_KEY_STATS: v->stats = !v->stats; break;
    case VIEW_KEY_PLAY:
    case VIEW_KEY_SCRUB_BACK:
    case VIEW_KEY_SCRUB_FORWARD:
        if (!path) {
            say(v, "the scene has no camera_path");
            break;
        }
        if (k == VIEW_KEY_PLAY) {
            v->playing = !v->playing;
            if (v->playing && v->play_t >= rl_camera_path_duration(path))
                v->play_t = 0.0;
        } else {
            v->play_t = fmin(fmax(v->play_t + (k == VIEW_KEY_SCRUB_BACK ? -1.0 : 1.0), 0.0),
                             rl_camera_path_duration(path));
            rl_camera cam = rl_camera_path_eval(path, rl_camera_path_key(path, 0)->time_s + v->play_t);
            set_camera(v, &cam);
        }
        break;
    case VIEW_KEY_RECORD:
        if (v->recording)
            return stop_recording(v);
        start_recording(v, v->a->path_out);
        break;
    case VIEW_KEY_OPTION_UP:
    case VIEW_KEY_OPTION_DOWN:
        push_cmd(v, CMD_STEP, NULL, k == VIEW_KEY_OPTION_UP ? 1 : -1, 0);
        v->nav.changed = true;
        break;
    case VIEW_KEY_OPTION_NEXT:
    case VIEW_KEY_OPTION_PREV:
        /* Changes no image: a frame without a restart carries it to the
         * worker, and pt keeps accumulating. */
        push_cmd(v, CMD_SELECT, NULL, k == VIEW_KEY_OPTION_NEXT ? 1 : -1, 0);
        v->need_frame = true;
        break;
    case VIEW_KEY_CYCLE_OVERLAY:
    case VIEW_KEY_CYCLE_SHADOW:
    case VIEW_KEY_CYCLE_DIFFUSE:
    case VIEW_KEY_CYCLE_FILTER:
    case VIEW_KEY_CYCLE_CRITERIA: {
        static const char *const keys[] = { "overlay", "shadow", "diffuse", "filter", "criteria" };
        push_cmd(v, CMD_CYCLE, keys[k - VIEW_KEY_CYCLE_OVERLAY], 1, 0);
        v->nav.changed = true;
        break;
    }
    case VIEW_KEY_LAYER: {
        static const char *const names[] = { "colour", "depth", "object IDs" };
        v->layer = (cli_layer)((v->layer + 1) % 3);
        say(v, "showing %s", names[v->layer]);
        break;
    }
    case VIEW_KEY_MENU: v->menu = !v->menu; break;
    case VIEW_KEY_REFERENCE:
        push_cmd(v, CMD_REFERENCE, NULL, 0, 0);
        v->need_frame = true;
        break;
    case VIEW_KEY_SCREENSHOT: screenshot_key(v); break;
    case VIEW_KEY_QUIT: return false;
    default: break;
    }
    return true;
}

/* Held keys and the camera path over dt seconds. */
static void advance(viewer *v, double dt)
{
    float f = (float)dt * v->nav.speed * (v->held[VIEW_KEY_FAST] ? 4.0f : 1.0f);
    float fwd = (float)(v->held[VIEW_KEY_FORWARD] - v->held[VIEW_KEY_BACK]);
    float right = (float)(v->held[VIEW_KEY_RIGHT] - v->held[VIEW_KEY_LEFT]);
    float up = (float)(v->held[VIEW_KEY_UP] - v->held[VIEW_KEY_DOWN]);
    if (fwd != 0.0f || right != 0.0f || up != 0.0f) {
        nav_fly(&v->nav, fwd * f, right * f, up * f);
        v->playing = false;
    }
    const rl_camera_path *path = v->data->camera_path;
    if (v->playing && path) {
        double dur = rl_camera_path_duration(path);
        v->play_t = fmin(v->play_t + dt, dur);
        rl_camera cam = rl_camera_path_eval(path, rl_camera_path_key(path, 0)->time_s + v->play_t);
        set_camera(v, &cam);
        if (v->play_t >= dur)
            v->playing = false;
    }
}

static view_key key_of(const SDL_Keysym *ks)
{
    switch (ks->sym) {
    case SDLK_w: return VIEW_KEY_FORWARD;
    case SDLK_s: return VIEW_KEY_BACK;
    case SDLK_a: return VIEW_KEY_LEFT;
    case SDLK_d: return VIEW_KEY_RIGHT;
    case SDLK_q: return VIEW_KEY_DOWN;
    case SDLK_e: return VIEW_KEY_UP;
    case SDLK_LSHIFT: case SDLK_RSHIFT: return VIEW_KEY_FAST;
    case SDLK_TAB: return ks->mod & KMOD_SHIFT ? VIEW_KEY_PREV_ALGO : VIEW_KEY_NEXT_ALGO;
    case SDLK_F1: case SDLK_h: return VIEW_KEY_HELP;
    case SDLK_i: return VIEW_KEY_STATS;
    case SDLK_c: return VIEW_KEY_CAMERA_RESET;
    case SDLK_p: return VIEW_KEY_PLAY;
    case SDLK_COMMA: return VIEW_KEY_SCRUB_BACK;
    case SDLK_PERIOD: return VIEW_KEY_SCRUB_FORWARD;
    case SDLK_r: return VIEW_KEY_RECORD;
    case SDLK_PLUS: case SDLK_EQUALS: case SDLK_KP_PLUS: return VIEW_KEY_OPTION_UP;
    case SDLK_MINUS: case SDLK_KP_MINUS: return VIEW_KEY_OPTION_DOWN;
    case SDLK_RIGHTBRACKET: return VIEW_KEY_OPTION_NEXT;
    case SDLK_LEFTBRACKET: return VIEW_KEY_OPTION_PREV;
    case SDLK_o: return VIEW_KEY_CYCLE_OVERLAY;
    case SDLK_b: return VIEW_KEY_CYCLE_SHADOW;
    case SDLK_n: return VIEW_KEY_CYCLE_DIFFUSE;
    case SDLK_f: return VIEW_KEY_CYCLE_FILTER;
    case SDLK_k: return VIEW_KEY_CYCLE_CRITERIA;
    case SDLK_l: return VIEW_KEY_LAYER;
    case SDLK_m: return VIEW_KEY_MENU;
    case SDLK_x: return VIEW_KEY_REFERENCE;
    case SDLK_F12: case SDLK_PRINTSCREEN: return VIEW_KEY_SCREENSHOT;
    case SDLK_ESCAPE: return VIEW_KEY_QUIT;
    default:
        if (ks->sym >= SDLK_1 && ks->sym <= SDLK_9)
            return (view_key)(VIEW_KEY_CAMERA_1 + (ks->sym - SDLK_1));
        return VIEW_KEY_NONE;
    }
}

/* Window events. false: the user closed the window or pressed Esc. */
static bool handle_events(viewer *v)
{
    SDL_Event e;
    while (SDL_PollEvent(&e)) {
        switch (e.type) {
        case SDL_QUIT: return false;
        case SDL_KEYDOWN:
        case SDL_KEYUP: {
            if (v->scripted)
                break;       /* a scripted run is the script's alone */
            view_key k = key_of(&e.key.keysym);
            if (k == VIEW_KEY_NONE)
                break;
            if (view_key_is_held(k))
                v->held[k] = e.type == SDL_KEYDOWN;
            else if (e.type == SDL_KEYDOWN && !e.key.repeat && !press(v, k))
                return false;
            break;
        }
        case SDL_MOUSEBUTTONDOWN:
            if (!v->scripted && (e.button.button == SDL_BUTTON_LEFT || e.button.button == SDL_BUTTON_RIGHT))
            {
                int x = e.button.x, y = e.button.y;
                if (v->gl) {
                    /* SDL maps the mouse to the image only for its renderers */
                    int vx, vy, vw, vh;
                    view_gl_viewport(v->gl, &vx, &vy, &vw, &vh);
                    x = vw > 0 ? (x - vx) * v->shown->width / vw : -1;
                    y = vh > 0 ? (y - vy) * v->shown->height / vh : -1;
                }
                v->mouse_taken = menu_click(v, x, y, e.button.button == SDL_BUTTON_RIGHT);
            }
            break;
        case SDL_MOUSEBUTTONUP:
            v->mouse_taken = false;
            break;
        case SDL_MOUSEMOTION:
            if (v->scripted || v->mouse_taken)
                break;
            if (e.motion.state & SDL_BUTTON_LMASK)
                nav_orbit(&v->nav, (float)e.motion.xrel, (float)e.motion.yrel);
            else if (e.motion.state & SDL_BUTTON_RMASK)
                nav_look(&v->nav, (float)e.motion.xrel, (float)e.motion.yrel);
            break;
        case SDL_MOUSEWHEEL:
            if (!v->scripted)
                nav_dolly(&v->nav, (float)e.wheel.y);
            break;
        case SDL_WINDOWEVENT:
            /* A script sets the size itself (its resize event), so that a
             * run does not depend on when the X server answers. */
            if (!v->scripted && e.window.event == SDL_WINDOWEVENT_SIZE_CHANGED) {
                int w = 0, h = 0;
                if (v->gl) {
                    view_gl_drawable_size(v->gl, &w, &h);
                    window_resized(v, w, h);
                } else if (SDL_GetRendererOutputSize(v->ren, &w, &h) == 0)
                    window_resized(v, w, h);
            }
            break;
        default: break;
        }
    }
    return true;
}

/* ---- display ---- */

static uint8_t srgb_lut[4097];

static void init_lut(void)
{
    for (int i = 0; i <= 4096; i++)
        srgb_lut[i] = (uint8_t)lrintf(rl_linear_to_srgb((float)i / 4096.0f) * 255.0f);
}

static uint8_t to_byte(float c)
{
    if (!(c > 0.0f))
        return 0;
    if (c >= 1.0f)
        return 255;
    return srgb_lut[(int)(c * 4096.0f + 0.5f)];
}

/* The displayed frame's buffers and texture at w x h: a frame of a new
 * size (the window was resized) replaces them. */
static bool fit_shown(viewer *v, int w, int h)
{
    if (v->shown && v->shown->width == w && v->shown->height == h && (v->tex || v->gl))
        return true;
    rl_clear_error();
    size_t n = (size_t)w * (size_t)h;
    uint32_t *px = malloc(n * sizeof *px);
    rl_vec4 *layer = malloc(n * sizeof *layer);
    rl_image *img = NULL;
    SDL_Texture *tex = NULL;
    bool ok = px && layer && rl_image_create(w, h, VIEW_LAYERS, &img) == RL_OK;
    if (ok && v->gl)
        ok = view_gl_resize(v->gl, w, h);
    else if (ok)
        ok = (tex = SDL_CreateTexture(v->ren, SDL_PIXELFORMAT_ARGB8888, SDL_TEXTUREACCESS_STREAMING, w, h)) != NULL;
    if (!ok) {
        free(px);
        free(layer);
        rl_image_release(img);
        rl_clear_error();
        return false;
    }
    memset(px, 0, n * sizeof *px);
    free(v->pixels);
    free(v->layer_px);
    rl_image_release(v->shown);
    if (v->tex)
        SDL_DestroyTexture(v->tex);
    v->pixels = px;
    v->layer_px = layer;
    v->shown = img;
    v->tex = tex;
    v->px_rows = v->tex_rows = h;
    v->shown_gpu = v->shown_cpu = false;
    if (v->gl) {
        view_gl_drop_frame(v->gl);
        return true;
    }
    /* Letterboxed scaling keeps the image's aspect ratio in any window; an
     * image that follows the window is drawn 1:1 (unless capped). */
    SDL_RenderSetLogicalSize(v->ren, w, h);
    return true;
}

/* Takes the newest published image, if there is one. */
static bool take_frame(viewer *v)
{
    shared *sh = &v->sh;
    rl_gl_frame trash[sizeof sh->trash / sizeof sh->trash[0]];
    rl_gl_frame tex = { 0 };
    bool gpu = false, want_change = false;
    SDL_LockMutex(sh->lock);
    int num_trash = sh->num_trash;
    memcpy(trash, sh->trash, (size_t)num_trash * sizeof *trash);
    sh->num_trash = 0;
    bool fresh = sh->front_seq != v->shown_seq;
    if (fresh && !fit_shown(v, sh->front->width, sh->front->height)) {
        fresh = false;
        v->shown_seq = sh->front_seq;
        snprintf(sh->status, sizeof sh->status, "out of memory for a %dx%d image", sh->front->width,
                 sh->front->height);
    }
    double change = -1.0;
    if (fresh) {
        size_t n = (size_t)sh->front->width * (size_t)sh->front->height;
        want_change = sh->front_final && !sh->front_moved && is_progressive(sh->front_algo) &&
                      strcmp(sh->front_algo, v->shown_algo) == 0;
        gpu = sh->front_gpu && sh->front_tex.texture;
        if (gpu) {
            /* The colour is a texture, now the main thread's (below). */
            tex = sh->front_tex;
            sh->front_tex = (rl_gl_frame){ 0 };
        } else if (want_change && (!v->gl || v->shown_cpu)) {
            double sum = 0.0;
            for (size_t i = 0; i < n; i++) {
                rl_vec4 a = sh->front->color[i], b = v->shown->color[i];
                sum += abs(to_byte(a.x) - to_byte(b.x)) + abs(to_byte(a.y) - to_byte(b.y)) +
                       abs(to_byte(a.z) - to_byte(b.z));
            }
            change = sum / (3.0 * (double)n);
        }
        if (!gpu)
            memcpy(v->shown->color, sh->front->color, n * sizeof *v->shown->color);
        memcpy(v->shown->depth, sh->front->depth, n * sizeof *v->shown->depth);
        memcpy(v->shown->object_id, sh->front->object_id, n * sizeof *v->shown->object_id);
        v->shown_seq = sh->front_seq;
        v->shown_final = sh->front_final;
        if (sh->front_final)
            v->shown_stats = sh->front_stats;
        snprintf(v->shown_algo, sizeof v->shown_algo, "%s", sh->front_algo);
        v->shown_spp = sh->front_spp;
        v->shown_moved = sh->front_moved;
        v->shown_request_s = sh->front_request_s;
    }
    SDL_UnlockMutex(sh->lock);
    for (int i = 0; i < num_trash && v->gl; i++)
        view_gl_delete(v->gl, &trash[i]);
    if (!fresh)
        return false;
    algo_stat *s = stat_of(v, v->shown_algo);
    if (v->gl && gpu) {
        bool had_cpu = v->shown_cpu;
        view_gl_adopt(v->gl, &tex);
        v->shown_gpu = true;
        v->shown_cpu = false;
        /* Read back only where the CPU needs the colour: --record, and an
         * accumulating renderer until its image is stable (the settle
         * measurement compares consecutive frames). */
        bool settled = s && s->settled && !v->shown_moved && want_change;
        if (v->a->record_dir || (is_progressive(v->shown_algo) && !settled)) {
            size_t n = (size_t)v->shown->width * (size_t)v->shown->height;
            if (view_gl_read(v->gl, v->layer_px)) {
                if (want_change && had_cpu) {
                    double sum = 0.0;
                    for (size_t i = 0; i < n; i++) {
                        rl_vec4 a = v->layer_px[i], b = v->shown->color[i];
                        sum += abs(to_byte(a.x) - to_byte(b.x)) + abs(to_byte(a.y) - to_byte(b.y)) +
                               abs(to_byte(a.z) - to_byte(b.z));
                    }
                    change = sum / (3.0 * (double)n);
                }
                memcpy(v->shown->color, v->layer_px, n * sizeof *v->shown->color);
                v->shown_cpu = true;
            }
        }
    } else {
        v->shown_gpu = false;
        v->shown_cpu = true;
        if (v->gl)
            view_gl_drop_frame(v->gl);
    }
    if (s && v->shown_gpu)
        s->shared_frames++;
    double now = rl_time_s();
    if (s && !s->have_first) {
        s->have_first = true;
        s->first_image_ms = (now - s->requested_s) * 1e3;
    }
    if (s && v->shown_moved && v->shown_request_s != s->last_restart_s) {
        /* The renderer's first restart is its first image (prep included),
         * reported as first_image_ms: the latency is that of input. */
        if (s->have_final) {
            s->latency_s += now - v->shown_request_s;
            s->latency_n++;
        }
        s->last_restart_s = v->shown_request_s;
        s->settle_frames = 0;
        s->settled = false;
    }
    if (s && !s->settled) {
        s->settle_frames++;
        s->settle_ms = (now - s->last_restart_s) * 1e3;
        if (change >= 0.0)
            s->last_change = change;
        s->settled = v->shown_final && (!is_progressive(v->shown_algo) || (change >= 0.0 && change < STABLE_CHANGE));
    }
    if (v->shown_final) {
        bool first = s && !s->have_final;
        if (s && !s->have_final) {
            s->have_final = true;
            s->first_final_ms = (now - s->requested_s) * 1e3;
            s->prep_ms = v->shown_stats.prep_ms;
        }
        if (s) {
            s->frames++;
            if (v->shown_moved && !first) {
                s->moving_frames++;
                s->moving_s += now - v->shown_request_s;
            }
        }
        if (v->num_final == 32)
            memmove(v->final_times, v->final_times + 1, 31 * sizeof *v->final_times);
        else
            v->num_final++;
        v->final_times[v->num_final - 1] = now;
    }
    return true;
}

/* Takes the newest image and draws it, timing both for --stats-out: the
 * display's share of a frame (the copy, the sRGB conversion, the upload
 * and the present). */
static bool show_frame(viewer *v)
{
    double t0 = rl_time_s();
    if (!take_frame(v))
        return false;
    draw(v);
    algo_stat *s = stat_of(v, v->shown_algo);
    if (s) {
        s->display_s += rl_time_s() - t0;
        s->displayed++;
    }
    return true;
}

static double current_fps(const viewer *v)
{
    if (v->num_final < 2)
        return 0.0;
    double span = v->final_times[v->num_final - 1] - v->final_times[0];
    return span > 0.0 ? (double)(v->num_final - 1) / span : 0.0;
}

/* The size of the overlay's text: legible on large images, fitting small ones. */
static int text_scale(const viewer *v)
{
    return v->shown->width >= 1200 ? 2 : 1;
}

static bool menu_add(viewer *v, int x, int y, int algo, const char *label)
{
    if (v->num_menu_items == MENU_MAX_ITEMS)
        return false;
    int scale = text_scale(v);
    menu_item *m = &v->menu_items[v->num_menu_items++];
    snprintf(m->label, sizeof m->label, "%s", label);
    m->x = x;
    m->y = y;
    m->w = view_text_width(m->label, scale);
    m->h = VIEW_FONT_LINE * scale;
    m->algo = algo;
    return true;
}

/* The menu from half the image's height down: the renderers Tab reaches,
 * wrapped to the width (the current one marked ">"); a blank line; the
 * current renderer's name and its options one a line, in columns where
 * the height runs out. Fixed cells, so that a script's click can name an
 * entry by its pixel (docs/viewer.md). */
static void menu_layout(viewer *v)
{
    int scale = text_scale(v);
    int adv = VIEW_FONT_ADVANCE * scale, lh = VIEW_FONT_LINE * scale;
    int x0 = 3 * scale, y0 = v->shown->height / 2;
    int cols = v->shown->width / adv - 1;
    cols = cols > 8 ? cols : 8;
    v->num_menu_items = 0;
    int col = 0, row = 0;
    for (size_t i = 0; i < v->num_algos; i++) {
        char label[96];
        int k = snprintf(label, sizeof label, "%s%s", i == v->algo_index ? ">" : "", v->algos[i]);
        if (col > 0 && col + 2 + k > cols) {
            row++;
            col = 0;
        } else if (col > 0)
            col += 2;
        menu_add(v, x0 + col * adv, y0 + row * lh, (int)i, label);
        col += k;
    }
    row += 2;
    char options[sizeof v->sh.options], heading[96];
    SDL_LockMutex(v->sh.lock);
    snprintf(options, sizeof options, "%s", v->sh.options);
    snprintf(heading, sizeof heading, "%s options:", v->sh.algo);
    SDL_UnlockMutex(v->sh.lock);
    menu_add(v, x0, y0 + row * lh, -2, heading);
    row++;
    int rows = (v->shown->height - y0) / lh - row;
    rows = rows > 1 ? rows : 1;
    int x = x0, widest = 0, r = 0;
    char *save = NULL;
    for (char *line = strtok_r(options, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        if (r == rows) {
            x += (widest + 2) * adv;
            widest = 0;
            r = 0;
        }
        if (!menu_add(v, x, y0 + (row + r) * lh, -1, line))
            break;
        int k = (int)strlen(v->menu_items[v->num_menu_items - 1].label);
        widest = k > widest ? k : widest;
        r++;
    }
}

/* A click at image pixel (x, y) with the menu open: an entry switches to
 * that renderer or changes that option (button 1, the right one: the
 * other way). false where no entry is. */
static bool menu_click(viewer *v, int x, int y, int button)
{
    if (!v->menu)
        return false;
    menu_layout(v);
    for (int i = 0; i < v->num_menu_items; i++) {
        const menu_item *m = &v->menu_items[i];
        if (x < m->x || x >= m->x + m->w || y < m->y || y >= m->y + m->h || m->algo == -2)
            continue;
        if (m->algo >= 0) {
            if ((size_t)m->algo != v->algo_index) {
                v->algo_index = (size_t)m->algo;
                push_cmd(v, CMD_ALGO, v->algos[m->algo], 0, 0);
                v->nav.changed = true;
            }
            return true;
        }
        char key[96];
        const char *from = m->label[0] == '>' ? m->label + 1 : m->label;
        snprintf(key, sizeof key, "%.*s", (int)strcspn(from, "="), from);
        push_cmd(v, CMD_CLICK, key, button ? -1 : 1, 0);
        v->nav.changed = true;
        return true;
    }
    return false;
}

/* The shown frame's colour in v->shown->color: read back from the window's
 * texture on the shared path, where it is not there yet. */
static bool ensure_shown_color(viewer *v)
{
    if (v->gl && v->shown_gpu && !v->shown_cpu)
        v->shown_cpu = view_gl_read(v->gl, v->shown->color);
    return !v->gl || v->shown_cpu;
}

/* The stats overlay's lines. */
static void stats_text(viewer *v, char *text, size_t size)
{
    int w = v->shown->width, h = v->shown->height;
    const rl_render_stats *s = &v->shown_stats;
    char status[256];
    SDL_LockMutex(v->sh.lock);
    snprintf(status, sizeof status, "%s", v->sh.status);
    SDL_UnlockMutex(v->sh.lock);
    int n = snprintf(text, size, "%s %dx%d %.1f fps, frame %.1f ms%s\n", v->shown_algo, w, h, current_fps(v),
                     s->time_ms - s->prep_ms, v->shown_final ? "" : " (refining)");
    uint64_t rays = 0;
    for (int t = 0; t < RL_RAY_TYPE_COUNT; t++)
        rays += s->rays[t];
    if (rays && n < (int)size)
        n += snprintf(text + n, size - (size_t)n, "rays %llu: prim %llu shadow %llu refl %llu refr %llu "
                      "diff %llu\n", (unsigned long long)rays, (unsigned long long)s->rays[RL_RAY_PRIMARY],
                      (unsigned long long)s->rays[RL_RAY_SHADOW], (unsigned long long)s->rays[RL_RAY_REFLECTION],
                      (unsigned long long)s->rays[RL_RAY_REFRACTION], (unsigned long long)s->rays[RL_RAY_DIFFUSE]);
    if (n < (int)size)
        n += snprintf(text + n, size - (size_t)n, "tris %llu points %llu queries %llu spp %.0f\n",
                      (unsigned long long)s->triangles_rasterized, (unsigned long long)s->points_drawn,
                      (unsigned long long)s->occlusion_queries, v->shown_spp);
    if (n < (int)size && (v->recording || v->playing))
        n += snprintf(text + n, size - (size_t)n, "%s%s\n", v->recording ? "[rec] " : "",
                      v->playing ? "[play]" : "");
    if (n < (int)size && status[0])
        snprintf(text + n, size - (size_t)n, "%s\n", status);
}

/* The window's pixels: the frame in sRGB bytes with the overlay. On the
 * shared path a GPU frame's colour is the texture's, encoded by the
 * window's shader (view_gl.c), and v->pixels holds only the overlay over a
 * transparent ground, of which only the rows the text covers are refilled
 * and uploaded. capture (may be NULL) gets the picture at the image's
 * size, ARGB8888: on the shared path as the window's shader draws it. */
static bool draw_ex(viewer *v, uint32_t *capture)
{
    int w = v->shown->width, h = v->shown->height;
    int scale = text_scale(v);
    char text[1024] = "";
    if (v->stats)
        stats_text(v, text, sizeof text);
    bool over_gpu = v->gl && v->shown_gpu && v->layer == CLI_LAYER_COLOR;
    int rows = h;
    if (over_gpu) {
        int lines = 0;
        for (const char *p = text; *p; p++)
            lines += *p == '\n';
        /* view_draw_text's box: from a scale above the text, 9 a line */
        rows = v->menu || v->help ? h : lines ? (3 + lines * VIEW_FONT_LINE) * scale : 0;
        rows = rows < h ? rows : h;
        int fill = rows > v->tex_rows ? rows : v->tex_rows;
        fill = fill > v->px_rows ? fill : v->px_rows;
        for (size_t i = 0; i < (size_t)fill * (size_t)w; i++)
            v->pixels[i] = 0x00fcfcfcu;     /* transparent: view_gl.c */
    } else {
        ensure_shown_color(v);
        const rl_vec4 *src = v->shown->color;
        if (v->layer != CLI_LAYER_COLOR && cli_layer_picture(v->shown, v->layer, v->layer_px))
            src = v->layer_px;
        for (size_t i = 0; i < (size_t)w * (size_t)h; i++) {
            rl_vec4 c = src[i];
            v->pixels[i] = 0xff000000u | (uint32_t)to_byte(c.x) << 16 | (uint32_t)to_byte(c.y) << 8 | to_byte(c.z);
        }
    }
    if (v->stats)
        view_draw_text(v->pixels, w, h, 3 * scale, 3 * scale, scale, text, 0xffffff40u);
    if (v->menu) {
        menu_layout(v);
        for (int i = 0; i < v->num_menu_items; i++)
            view_draw_text(v->pixels, w, h, v->menu_items[i].x, v->menu_items[i].y, scale, v->menu_items[i].label,
                           v->menu_items[i].algo == -2 ? 0xffffff40u : 0xffffffffu);
    }
    if (v->help)
        view_draw_text(v->pixels, w, h, 3 * scale, h / 3, scale, view_keys_help, 0xffffffffu);
    if (v->gl) {
        view_gl_present(v->gl, v->pixels, over_gpu && v->tex_rows > rows ? v->tex_rows : rows, over_gpu);
        v->tex_rows = v->px_rows = rows;
        return !capture || view_gl_capture(v->gl, v->pixels, 0, over_gpu, capture);
    }
    SDL_UpdateTexture(v->tex, NULL, v->pixels, w * (int)sizeof *v->pixels);
    SDL_RenderClear(v->ren);
    SDL_RenderCopy(v->ren, v->tex, NULL, NULL);
    SDL_RenderPresent(v->ren);
    if (capture)
        memcpy(capture, v->pixels, (size_t)w * (size_t)h * sizeof *capture);
    return true;
}

static void draw(viewer *v)
{
    draw_ex(v, NULL);
}

/* After a frame is on screen: --record and --screenshot-at. */
static bool after_frame(viewer *v)
{
    if (v->a->record_dir && v->shown_seq && v->shown_seq != v->recorded_seq) {
        v->recorded_seq = v->shown_seq;
        char path[4096];
        snprintf(path, sizeof path, "%s/frame_%06lld.png", v->a->record_dir, v->record_counter++);
        rl_clear_error();
        rl_status st = ensure_shown_color(v) ? rl_image_write(v->shown, path) : RL_ERR_INTERNAL;
        if (st != RL_OK) {
            cli_fail_status(RL_CLI_FAIL, st, path);
            return false;
        }
    }
    for (int i = 0; i < v->a->num_shots; i++) {
        shot_at *s = &v->a->shots[i];
        if (!s->done && v->now + 1e-9 >= s->time_s && v->shown_seq) {
            s->done = true;
            if (!write_screenshot(v, s->file))
                return false;
        }
    }
    return true;
}

/* ---- the run ---- */

static int parse_args(int argc, char **argv, view_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        int m;
#define VALUE(name) ((m = cli_take_value(argc, argv, &i, name, &v)) != 0)
        if (VALUE("--algo")) a->algo = v;
        else if (VALUE("--camera")) a->camera = v;
        else if (VALUE("--set")) a->sets[a->num_sets++] = v;
        else if (VALUE("--script")) a->script = v;
        else if (VALUE("--record")) a->record_dir = v;
        else if (VALUE("--shot-dir")) a->shot_dir = v;
        else if (VALUE("--path-out")) a->path_out = v;
        else if (VALUE("--stats-out")) a->stats_out = v;
        else if (VALUE("--display")) {
            if (m > 0 && strcmp(v, "auto") != 0 && strcmp(v, "software") != 0 && strcmp(v, "gl") != 0 &&
                strcmp(v, "shared") != 0)
                return cli_fail(RL_CLI_USAGE, "--display: expected auto, shared, software or gl, got '%s'", v);
            a->display = v;
        }
        else if (VALUE("--size")) {
            if (m > 0 && strcmp(v, "window") == 0)
                a->has_size = false;
            else if (m > 0 && !cli_parse_size(v, &a->width, &a->height))
                return RL_CLI_USAGE;
            else
                a->has_size = true;
        } else if (VALUE("--max-spp")) {
            if (m > 0 && (!rl_parse_int(v, &a->max_spp) || a->max_spp < 1 || a->max_spp > 1000000000))
                return cli_fail(RL_CLI_USAGE, "--max-spp: expected samples per pixel in [1, 1000000000], got '%s'",
                                v);
        } else if (VALUE("--ref-spp")) {
            if (m > 0 && (!rl_parse_int(v, &a->ref_spp) || a->ref_spp < 1 || a->ref_spp > 65536))
                return cli_fail(RL_CLI_USAGE, "--ref-spp: expected samples per pixel in [1, 65536], got '%s'", v);
        } else if (VALUE("--screenshot-at")) {
            if (m > 0) {
                const char *colon = strchr(v, ':');
                double t = 0.0;
                char num[64];
                size_t len = colon ? (size_t)(colon - v) : 0;
                if (!colon || len == 0 || len >= sizeof num)
                    return cli_fail(RL_CLI_USAGE, "--screenshot-at: expected T:FILE.png, got '%s'", v);
                memcpy(num, v, len);
                num[len] = '\0';
                if (!rl_parse_float(num, &t) || t < 0.0 || t > 1e6)
                    return cli_fail(RL_CLI_USAGE, "--screenshot-at: expected a time in seconds in [0, 1e6], got '%s'",
                                    num);
                if (!cli_has_extension(colon + 1, (const char *const[]){ ".png", NULL }))
                    return cli_fail(RL_CLI_USAGE, "--screenshot-at: expected a .png file, got '%s'", colon + 1);
                if (a->num_shots == MAX_SHOTS)
                    return cli_fail(RL_CLI_USAGE, "--screenshot-at: at most %d", MAX_SHOTS);
                a->shots[a->num_shots++] = (shot_at){ .time_s = t, .file = colon + 1 };
            }
        } else if ((m = cli_take_model_flag(argc, argv, &i, &a->model)) != 0) {
        } else if (argv[i][0] == '-' || a->scene)
            return cli_unknown_arg("view", argv[i]);
        else
            a->scene = argv[i];
#undef VALUE
        if (m < 0)
            return RL_CLI_USAGE;
    }
    if (!a->scene)
        return cli_fail(RL_CLI_USAGE, "view: missing SCENE (see rl view --help)");
    for (int k = 0; k < a->num_sets; k++) {
        const char *eq = strchr(a->sets[k], '=');
        if (!eq || eq == a->sets[k])
            return cli_fail(RL_CLI_USAGE, "--set: expected KEY=VALUE, got '%s'", a->sets[k]);
    }
    if (a->path_out && !cli_has_extension(a->path_out, (const char *const[]){ ".json", NULL }))
        return cli_fail(RL_CLI_USAGE, "--path-out: expected a .json file, got '%s'", a->path_out);
    return RL_CLI_OK;
}

/* Output folders, before the window opens. */
static int check_outputs(const view_args *a, const view_script *script)
{
    for (int i = 0; i < a->num_shots; i++)
        if (!cli_check_writable(a->shots[i].file))
            return RL_CLI_FAIL;
    for (size_t i = 0; i < script->count; i++) {
        const view_event *e = &script->events[i];
        if ((e->kind == VIEW_EV_SCREENSHOT || e->kind == VIEW_EV_CAPTURE || e->kind == VIEW_EV_RECORD) && e->text && !cli_check_writable(e->text))
            return RL_CLI_FAIL;
    }
    if (a->record_dir && !cli_make_dirs(a->record_dir))
        return RL_CLI_FAIL;
    if (a->stats_out && !cli_check_writable(a->stats_out))
        return RL_CLI_FAIL;
    return RL_CLI_OK;
}

/* Script events that can be checked against the scene and the registry. */
static int check_script(const view_script *s, const rl_scene_data *d)
{
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    for (size_t i = 0; i < s->count; i++) {
        const view_event *e = &s->events[i];
        if (e->kind == VIEW_EV_ALGO) {
            size_t k = 0;
            while (k < n && strcmp(list[k].name, e->text) != 0)
                k++;
            if (k == n)
                return cli_fail(RL_CLI_USAGE, "%s:%d: unknown renderer '%s' (see rl algos)", s->path, e->line,
                                e->text);
        }
        if (e->kind == VIEW_EV_CAMERA) {
            uint32_t k = 0;
            while (k < d->num_cameras && strcmp(d->camera_names[k], e->text) != 0)
                k++;
            if (k == d->num_cameras)
                return cli_fail(RL_CLI_USAGE, "%s:%d: the scene has no camera '%s'", s->path, e->line, e->text);
        }
    }
    return RL_CLI_OK;
}

/* The renderers Tab cycles through: every one of rl algos that is
 * available here (a GL renderer without a GL context is left out). */
static void list_algos(viewer *v)
{
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    v->algos = calloc(n ? n : 1, sizeof *v->algos);
    if (!v->algos)
        return;
    for (size_t i = 0; i < n; i++) {
        rl_renderer *r = NULL;
        if (rl_renderer_create(list[i].name, &r) == RL_OK && rl_renderer_available(r, NULL, 0)) {
            if (strcmp(list[i].name, v->a->algo) == 0)
                v->algo_index = v->num_algos;
            v->algos[v->num_algos++] = list[i].name;
        }
        rl_renderer_release(r);
        rl_clear_error();
    }
}

/* Whether s is set and not empty. */
static bool env_set(const char *name)
{
    const char *s = getenv(name);
    return s && *s;
}

static int open_window(viewer *v)
{
    /* Without a display SDL falls back to its offscreen driver: a window
     * nobody sees, and an interactive run that never ends. That driver is
     * used only when SDL_VIDEODRIVER asks for it (a headless script). */
    bool chosen = env_set("SDL_VIDEODRIVER");
    if (!chosen && !env_set("DISPLAY") && !env_set("WAYLAND_DISPLAY"))
        return cli_fail(RL_CLI_FAIL, "view: cannot open a window: no display (DISPLAY and WAYLAND_DISPLAY are "
                                     "unset; a script runs under xvfb-run or SDL_VIDEODRIVER=offscreen)");
    /* The readback path: the image is made on the CPU (or read back from a
     * GL renderer's context) and the window only scales it. SDL's
     * software path does that without loading an OpenGL driver (under Xvfb
     * that is Mesa, which SDL_Quit unloads with blocks still held, a leak
     * the sanitizer build cannot attribute). Where the shared path (below)
     * is not taken, a GL renderer's read-back images may have their upload
     * and scaling done by SDL's OpenGL renderer (--display gl), which SDL
     * replaces by its software one where it cannot make a context. auto
     * does so only where the GL
     * backend has a hardware device: on llvmpipe the GL upload is the CPU's
     * too and measured twice the software path's time (docs/viewer.md).
     * The environment's SDL_RENDER_DRIVER and SDL_FRAMEBUFFER_ACCELERATION
     * still override. */
    bool gl = strcmp(v->a->display, "gl") == 0;
    /* The shared path (docs/viewer.md): the window's context is EGL and
     * the library's contexts share with it, so that a GL renderer's frame
     * is drawn from its texture without the trip through the CPU. Tried
     * for --display shared, and by auto for a GL renderer; where it fails
     * the readback path below is taken and the status line says why. */
    bool gl_algo = strncmp(v->a->algo, "gl-", 3) == 0;
    bool want_share = strcmp(v->a->display, "shared") == 0 || (strcmp(v->a->display, "auto") == 0 && gl_algo);
    rl_gl_info gi;
    if (strcmp(v->a->display, "auto") == 0 && gl_algo && rl_gl_info_get(NULL, &gi) == RL_OK)
        gl = !strstr(gi.renderer, "llvmpipe") && !strstr(gi.renderer, "softpipe") && !strstr(gi.renderer, "swrast");
    rl_clear_error();
#ifdef SDL_HINT_VIDEO_X11_FORCE_EGL
    if (want_share)
        SDL_SetHint(SDL_HINT_VIDEO_X11_FORCE_EGL, "1");
#else
    if (want_share) {
        snprintf(v->path_why, sizeof v->path_why, "SDL %d.%d.%d has no SDL_HINT_VIDEO_X11_FORCE_EGL", SDL_MAJOR_VERSION,
                 SDL_MINOR_VERSION, SDL_PATCHLEVEL);
        want_share = false;
    }
#endif
    SDL_SetHint(SDL_HINT_RENDER_DRIVER, gl ? "opengl" : "software");
    if (!gl)
        SDL_SetHint(SDL_HINT_FRAMEBUFFER_ACCELERATION, "0");
    if (SDL_Init(SDL_INIT_VIDEO) != 0)
        return cli_fail(RL_CLI_FAIL, "view: cannot open a window: %s", SDL_GetError());
    const char *driver = SDL_GetCurrentVideoDriver();
    cli_debug("view: SDL video driver %s", driver ? driver : "none");
    if (!chosen && driver && (strcmp(driver, "offscreen") == 0 || strcmp(driver, "dummy") == 0))
        return cli_fail(RL_CLI_FAIL, "view: cannot open a window: SDL found no display, only its %s driver", driver);
    char title[256];
    snprintf(title, sizeof title, "rl view %s", v->a->scene);
    /* The window starts at the image size, halved until it fits a common
     * screen; it may then be resized freely (a --size image is scaled, an
     * image that follows the window is rendered at its new size). */
    int ww = v->width, wh = v->height;
    while (ww > 1600 || wh > 1000) {
        ww /= 2;
        wh /= 2;
    }
    if (want_share) {
        v->win = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, ww < 16 ? 16 : ww,
                                  wh < 16 ? 16 : wh, SDL_WINDOW_RESIZABLE | SDL_WINDOW_OPENGL);
        if (!v->win)
            snprintf(v->path_why, sizeof v->path_why, "no OpenGL window: %s", SDL_GetError());
        else if (!(v->gl = view_gl_open(v->win, v->path_why, sizeof v->path_why))) {
            SDL_DestroyWindow(v->win);
            v->win = NULL;
        }
        if (!v->gl)
            cli_debug("view: the shared path failed (%s); the readback path", v->path_why);
    }
    if (!v->gl) {
        v->win = SDL_CreateWindow(title, SDL_WINDOWPOS_UNDEFINED, SDL_WINDOWPOS_UNDEFINED, ww < 16 ? 16 : ww,
                                  wh < 16 ? 16 : wh, SDL_WINDOW_RESIZABLE);
        if (!v->win)
            return cli_fail(RL_CLI_FAIL, "view: cannot open a window: %s", SDL_GetError());
        v->ren = SDL_CreateRenderer(v->win, -1, 0);
        if (!v->ren)
            return cli_fail(RL_CLI_FAIL, "view: cannot draw into the window: %s", SDL_GetError());
        SDL_RendererInfo info;
        snprintf(v->display, sizeof v->display, "%s", SDL_GetRendererInfo(v->ren, &info) == 0 ? info.name : "?");
    } else {
        snprintf(v->display, sizeof v->display, "gl-shared");
        v->wk.glshare = true;
    }
    cli_debug("view: display %s", v->display);
    if (gl && !v->gl && strcmp(v->display, "opengl") != 0)
        snprintf(v->sh.status, sizeof v->sh.status, "--display gl: SDL made no OpenGL renderer; %s", v->display);
    if (want_share || v->path_why[0])
        snprintf(v->sh.status, sizeof v->sh.status, v->gl ? "display: shared GL context, frames stay on the GPU"
                 : "display: readback, no shared GL context: %.180s", v->path_why);
    int ow = ww, oh = wh;
    bool have_size = v->gl ? (view_gl_drawable_size(v->gl, &ow, &oh), true)
                           : SDL_GetRendererOutputSize(v->ren, &ow, &oh) == 0;
    if (v->follow_window && have_size) {
        window_image_size(ow, oh, &v->width, &v->height);
        v->nav.cam.width = v->width;
        v->nav.cam.height = v->height;
    }
    if (!fit_shown(v, v->width, v->height))
        return cli_fail(RL_CLI_FAIL, "view: cannot make a %dx%d image and its texture: %s", v->width, v->height,
                        SDL_GetError());
    return RL_CLI_OK;
}

/* Waits for the worker's frame while keeping the window alive; false when
 * the window was closed. */
static bool wait_frame(viewer *v)
{
    for (;;) {
        SDL_LockMutex(v->sh.lock);
        bool idle = v->sh.done_seq == v->sh.req_seq;
        if (!idle)
            SDL_CondWaitTimeout(v->sh.done, v->sh.lock, 20);
        idle = v->sh.done_seq == v->sh.req_seq;
        SDL_UnlockMutex(v->sh.lock);
        if (!handle_events(v))
            return false;
        show_frame(v);
        if (idle)
            return true;
    }
}

static int worker_fatal(viewer *v)
{
    SDL_LockMutex(v->sh.lock);
    int code = v->sh.fatal;
    char msg[512];
    snprintf(msg, sizeof msg, "%s", v->sh.fatal_msg);
    SDL_UnlockMutex(v->sh.lock);
    return code ? cli_fail(code, "%s", msg) : RL_CLI_OK;
}

/* Whether the worker should add a frame to a progressive accumulation. */
static bool wants_more(viewer *v)
{
    SDL_LockMutex(v->sh.lock);
    bool more = v->sh.worker_progressive && v->sh.worker_spp < (double)v->a->max_spp && !v->sh.fatal;
    SDL_UnlockMutex(v->sh.lock);
    return more;
}

/* One event of the script, after the frame of the ones before it. */
static int apply_event(viewer *v, const view_script *s, const view_event *e, bool *quit)
{
    switch (e->kind) {
    case VIEW_EV_KEY:
        if (view_key_is_held(e->key)) {
            /* A tap of a motion key moves one step. */
            v->held[e->key] = true;
            advance(v, 1.0 / SCRIPT_FPS);
            v->held[e->key] = false;
        } else if (!press(v, e->key)) {
            if (e->key == VIEW_KEY_QUIT)
                *quit = true;
            else
                return RL_CLI_FAIL;
        }
        break;
    case VIEW_EV_KEYDOWN: v->held[e->key] = true; break;
    case VIEW_EV_KEYUP: v->held[e->key] = false; break;
    case VIEW_EV_DRAG:
        if (e->button)
            nav_look(&v->nav, (float)e->dx, (float)e->dy);
        else
            nav_orbit(&v->nav, (float)e->dx, (float)e->dy);
        break;
    case VIEW_EV_WHEEL: nav_dolly(&v->nav, (float)e->dx); break;
    case VIEW_EV_MOVE: {
        rl_camera cam = v->nav.cam;
        cam.eye = e->eye;
        cam.target = e->target;
        rl_clear_error();
        if (rl_camera_validate(&cam) != RL_OK)
            return cli_fail(RL_CLI_USAGE, "%s:%d: move: %s", s->path, e->line, rl_last_error());
        set_camera(v, &cam);
        break;
    }
    case VIEW_EV_CAMERA: {
        rl_camera cam;
        if (scene_camera(v, e->text, &cam) != RL_CLI_OK)
            return RL_CLI_FAIL;
        set_camera(v, &cam);
        break;
    }
    case VIEW_EV_ALGO:
        for (size_t i = 0; i < v->num_algos; i++)
            if (strcmp(v->algos[i], e->text) == 0)
                v->algo_index = i;
        push_cmd(v, CMD_ALGO, e->text, 0, e->line);
        v->nav.changed = true;
        break;
    case VIEW_EV_SET:
        push_cmd(v, CMD_SET, e->text, 0, e->line);
        v->nav.changed = true;
        break;
    case VIEW_EV_SCREENSHOT:
        if (!write_screenshot(v, e->text))
            return RL_CLI_FAIL;
        break;
    case VIEW_EV_CAPTURE:
        if (!write_capture(v, e->text))
            return RL_CLI_FAIL;
        break;
    case VIEW_EV_RESIZE:
        SDL_SetWindowSize(v->win, (int)e->dx, (int)e->dy);
        window_resized(v, (int)e->dx, (int)e->dy);
        break;
    case VIEW_EV_CLICK:
        if (!menu_click(v, (int)e->dx, (int)e->dy, e->button))
            say(v, "click %g,%g: %s", e->dx, e->dy, v->menu ? "no menu entry there" : "the menu (M) is closed");
        break;
    case VIEW_EV_RECORD:
        if (e->text)
            start_recording(v, e->text);
        else if (!v->recording)
            return cli_fail(RL_CLI_USAGE, "%s:%d: record stop: nothing is being recorded", s->path, e->line);
        else if (!stop_recording(v))
            return RL_CLI_FAIL;
        break;
    case VIEW_EV_QUIT: *quit = true; break;
    }
    return RL_CLI_OK;
}

/* A script: a virtual clock, one step per finished frame. */
static int run_script(viewer *v, const view_script *s)
{
    size_t next = 0;
    long long step = 0;
    bool quit = false, ending = false;
    request(v, true);
    for (;;) {
        if (!wait_frame(v))
            return RL_CLI_OK;
        int rc = worker_fatal(v);
        if (rc != RL_CLI_OK)
            return rc;
        record_tick(v);
        if (!after_frame(v))
            return RL_CLI_FAIL;
        if (quit || ending)
            break;
        /* Events are applied one at a time, each after the frame of the
         * ones before it: a screenshot sees everything above it. */
        v->nav.changed = false;
        bool applied = false;
        if (next < s->count && s->events[next].time_s <= v->now + 1e-9) {
            rc = apply_event(v, s, &s->events[next], &quit);
            if (rc != RL_CLI_OK)
                return rc;
            next++;
            applied = true;
        }
        if (!applied) {
            step++;
            v->now = (double)step / SCRIPT_FPS;
            advance(v, 1.0 / SCRIPT_FPS);
        }
        if (quit)
            break;
        if (next == s->count) {
            bool pending = false;
            for (int i = 0; i < v->a->num_shots; i++)
                pending |= !v->a->shots[i].done;
            if (!pending)
                ending = true;
        }
        if (v->nav.changed)
            request(v, true);
        else if (v->need_frame || (!applied && wants_more(v)))
            request(v, false);
        else if (ending)
            break;
        v->need_frame = false;
    }
    return RL_CLI_OK;
}

/* Interactive: real time, never waiting on the worker. */
static int run_interactive(viewer *v)
{
    request(v, true);
    double last = rl_time_s();
    for (;;) {
        if (!handle_events(v))
            break;
        double t = rl_time_s();
        double dt = fmin(t - last, 0.25);
        last = t;
        v->now = t - v->start_wall;
        advance(v, dt);
        record_tick(v);
        bool idle = worker_idle(v);
        if (v->nav.changed) {
            v->nav.changed = false;
            v->need_frame = false;
            request(v, true);
        } else if (idle && (v->need_frame || wants_more(v))) {
            v->need_frame = false;
            request(v, false);
        }
        bool fresh = show_frame(v);
        if (fresh && !after_frame(v))
            return RL_CLI_FAIL;
        /* The overlay (help, status) changes without frames too. */
        if (!fresh)
            draw(v);
        SDL_Delay(fresh ? 1 : 8);
    }
    if (v->recording && !stop_recording(v))
        return RL_CLI_FAIL;
    return RL_CLI_OK;
}

static int write_stats_out(const viewer *v, double wall_s)
{
    cJSON *obj = cJSON_CreateObject();
    cJSON *arr = obj ? cJSON_AddArrayToObject(obj, "renderers") : NULL;
    if (!arr) {
        cJSON_Delete(obj);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    cJSON_AddStringToObject(obj, "scene", v->a->scene);
    cJSON_AddNumberToObject(obj, "width", v->width);
    cJSON_AddNumberToObject(obj, "height", v->height);
    cJSON_AddBoolToObject(obj, "scripted", v->scripted);
    cJSON_AddStringToObject(obj, "display", v->display);
    /* how a GL renderer's frame reaches the window: "shared" (its texture,
     * in the window's share group) or "readback" (through the CPU), and
     * why the shared path was not taken where it was tried */
    cJSON_AddStringToObject(obj, "display_path", v->gl ? "shared" : "readback");
    if (v->path_why[0])
        cJSON_AddStringToObject(obj, "display_fallback", v->path_why);
    cJSON_AddNumberToObject(obj, "wall_s", wall_s);
    for (int i = 0; i < v->num_stats; i++) {
        const algo_stat *s = &v->stats_by_algo[i];
        cJSON *e = cJSON_CreateObject();
        if (!e)
            break;
        cJSON_AddStringToObject(e, "algorithm", s->name);
        cJSON_AddNumberToObject(e, "frames", (double)s->frames);
        cJSON_AddNumberToObject(e, "moving_frames", (double)s->moving_frames);
        cJSON_AddNumberToObject(e, "moving_fps", s->moving_s > 0.0 ? (double)s->moving_frames / s->moving_s : 0.0);
        cJSON_AddNumberToObject(e, "moving_frame_ms", s->moving_frames ? s->moving_s * 1e3 / (double)s->moving_frames
                                                                       : 0.0);
        cJSON_AddNumberToObject(e, "first_image_ms", s->first_image_ms);
        cJSON_AddNumberToObject(e, "first_final_ms", s->first_final_ms);
        cJSON_AddNumberToObject(e, "first_prep_ms", s->prep_ms);
        cJSON_AddNumberToObject(e, "display_ms", s->displayed ? s->display_s * 1e3 / (double)s->displayed : 0.0);
        cJSON_AddNumberToObject(e, "shared_frames", (double)s->shared_frames);
        cJSON_AddNumberToObject(e, "latency_ms", s->latency_n ? s->latency_s * 1e3 / (double)s->latency_n : 0.0);
        /* After the last restart: null where the run ended before the
         * image was stable (last_change says how far it was). */
        if (s->settled) {
            cJSON_AddNumberToObject(e, "settle_frames", (double)s->settle_frames);
            cJSON_AddNumberToObject(e, "settle_ms", s->settle_ms);
        } else {
            cJSON_AddNullToObject(e, "settle_frames");
            cJSON_AddNullToObject(e, "settle_ms");
        }
        if (s->last_change > 0.0)
            cJSON_AddNumberToObject(e, "last_change", s->last_change);
        cJSON_AddItemToArray(arr, e);
    }
    cJSON *exp = cli_experiment_json(cli_threads());
    if (exp)
        cJSON_AddItemToObject(obj, "experiment", exp);
    bool ok = cli_write_json(obj, v->a->stats_out);
    cJSON_Delete(obj);
    return ok ? RL_CLI_OK : RL_CLI_FAIL;
}

static void close_viewer(viewer *v)
{
    if (v->thread) {
        SDL_LockMutex(v->sh.lock);
        v->sh.quit = true;
        SDL_AtomicAdd(&v->sh.gen, 1);      /* cancels the frame in flight */
        SDL_CondSignal(v->sh.wake);
        SDL_UnlockMutex(v->sh.lock);
        SDL_WaitThread(v->thread, NULL);
    }
    rl_renderer_release(v->wk.r);
    rl_renderer_release(v->wk.ref);
    v->wk.r = v->wk.ref = NULL;
    for (size_t i = 0; i < sizeof v->wk.parked / sizeof v->wk.parked[0]; i++) {
        rl_renderer_release(v->wk.parked[i]);
        v->wk.parked[i] = NULL;
    }
    if (v->gl) {
        /* the textures still on their way, in the share group */
        view_gl_delete(v->gl, &v->sh.front_tex);
        for (int i = 0; i < v->sh.num_trash; i++)
            view_gl_delete(v->gl, &v->sh.trash[i]);
        view_gl_close(v->gl);
        v->gl = NULL;
    }
    rl_image_release(v->wk.ref_img);
    rl_image_release(v->wk.back);
    rl_image_release(v->sh.front);
    rl_image_release(v->shown);
    free(v->pixels);
    free(v->layer_px);
    free(v->algos);
    free(v->rec);
    if (v->sh.wake)
        SDL_DestroyCond(v->sh.wake);
    if (v->sh.done)
        SDL_DestroyCond(v->sh.done);
    if (v->sh.lock)
        SDL_DestroyMutex(v->sh.lock);
    if (v->tex)
        SDL_DestroyTexture(v->tex);
    if (v->ren)
        SDL_DestroyRenderer(v->ren);
    if (v->win)
        SDL_DestroyWindow(v->win);
    SDL_Quit();
}

int view_run(int argc, char **argv)
{
    view_args a = { .algo = "raster", .display = "auto", .shot_dir = ".", .path_out = "rl-view-path.json",
                    .max_spp = DEFAULT_MAX_SPP, .ref_spp = DEFAULT_REF_SPP };
    a.sets = calloc((size_t)argc, sizeof *a.sets);
    if (!a.sets)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    view_script script = { 0 };
    viewer v = { .a = &a, .stats = true };
    rl_scene *scene = NULL;
    int rc = parse_args(argc, argv, &a);
    if (rc == RL_CLI_OK && a.script)
        rc = view_script_load(a.script, &script);
    if (rc == RL_CLI_OK)
        rc = check_outputs(&a, &script);
    /* The first renderer, its options checked before the scene loads. */
    if (rc == RL_CLI_OK) {
        rl_clear_error();
        rl_status st = rl_renderer_create(a.algo, &v.wk.r);
        rc = st == RL_OK ? apply_sets(v.wk.r, &a, true) : cli_fail_status(RL_CLI_USAGE, st, NULL);
    }
    if (rc == RL_CLI_OK)
        rc = cli_load_scene_with(a.scene, &a.model, &scene);
    if (rc == RL_CLI_OK) {
        v.scene = scene;
        v.data = rl_scene_get_data(scene);
        rc = check_script(&script, v.data);
    }
    rl_camera cam;
    if (rc == RL_CLI_OK)
        rc = scene_camera(&v, a.camera, &cam);
    if (rc == RL_CLI_OK) {
        v.width = cam.width;
        v.height = cam.height;
        v.nav.cam = cam;
        rl_vec3 ext = rl_sub(v.data->bounds.max, v.data->bounds.min);
        float diag = rl_length(ext);
        if (!(diag > 0.0f) || !isfinite(diag))
            diag = 1.0f;
        v.nav.speed = 0.25f * diag;
        v.nav.min_dist = 1e-3f * diag;
        /* back, front, shown with their layers, the reference, the layer
         * picture and the window's pixels; an image that follows the window
         * may grow to the cap */
        v.follow_window = !a.has_size;
        int mw = v.width, mh = v.height;
        if (v.follow_window)
            window_image_size(16384, 16384 * 10 / 16, &mw, &mh);
        rc = cli_check_frame_memory(v.wk.r, mw, mh, VIEW_LAYERS,
                                    3.0 * (sizeof(rl_vec4) + 8.0) + 2.0 * sizeof(rl_vec4) + 4.0, 0.0);
    }
    if (rc == RL_CLI_OK) {
        rl_clear_error();
        rl_status st = rl_renderer_available(v.wk.r, NULL, 0) ? rl_renderer_prepare_inputs(v.wk.r, scene)
                                                             : RL_ERR_UNSUPPORTED;
        if (st == RL_ERR_UNSUPPORTED) {
            char why[256] = "";
            rl_renderer_available(v.wk.r, why, sizeof why);
            rc = cli_fail(RL_CLI_FAIL, "%s: %s", a.algo, why);
        } else if (st != RL_OK)
            rc = cli_fail_status(RL_CLI_FAIL, st, a.algo);
    }
    if (rc == RL_CLI_OK)
        rc = open_window(&v);
    if (rc == RL_CLI_OK) {
        rl_clear_error();
        rl_status st = rl_image_create(v.width, v.height, VIEW_LAYERS, &v.wk.back);
        if (st == RL_OK)
            st = rl_image_create(v.width, v.height, VIEW_LAYERS, &v.sh.front);
        if (st != RL_OK)
            rc = cli_fail(RL_CLI_FAIL, "out of memory for a %dx%d view", v.width, v.height);
    }
    if (rc == RL_CLI_OK) {
        init_lut();
        list_algos(&v);
        v.scripted = a.script != NULL;
        v.start_wall = rl_time_s();
        v.sh.lock = SDL_CreateMutex();
        v.sh.wake = SDL_CreateCond();
        v.sh.done = SDL_CreateCond();
        snprintf(v.sh.algo, sizeof v.sh.algo, "%s", rl_renderer_name(v.wk.r));
        v.sh.worker_progressive = is_progressive(rl_renderer_name(v.wk.r));
        algo_stat *s = stat_of(&v, rl_renderer_name(v.wk.r));
        if (s)
            s->requested_s = rl_time_s();
        v.wk.sh = &v.sh;
        v.wk.args = &a;
        v.wk.scene = scene;
        if (!v.sh.lock || !v.sh.wake || !v.sh.done ||
            !(v.thread = SDL_CreateThread(worker_main, "rl-view-render", &v.wk)))
            rc = cli_fail(RL_CLI_FAIL, "view: cannot start the render thread: %s", SDL_GetError());
    }
    if (rc == RL_CLI_OK) {
        double t0 = rl_time_s();
        rc = v.scripted ? run_script(&v, &script) : run_interactive(&v);
        if (rc == RL_CLI_OK && a.stats_out)
            rc = write_stats_out(&v, rl_time_s() - t0);
    }
    close_viewer(&v);
    rl_scene_release(scene);
    view_script_free(&script);
    free(a.sets);
    return rc;
}

#endif
