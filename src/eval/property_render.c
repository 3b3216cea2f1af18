/* property_render.c: the properties that run a renderer at the position:
 * "time" (rendering time, Jähn 2015, Sec. 4.2.3, Def. 6), "ops" (operation
 * counts, Sec. 4.2.4) and "quality" (image quality against a reference,
 * Sec. 4.2.5, Def. 7).
 *
 * All three render the six main directions (rl_property_direction) with
 * overlapping frusta of `fov_deg` (default 120°: "ab 120 Grad Öffnungswinkel
 * [zeigen sich] kaum mehr merkliche Auswirkungen", Sec. 4.2.3) into
 * width x height images (default 256 x 256; the thesis leaves the size to
 * the renderer parameters, and 256² keeps one sample at a few renders of a
 * small image). Near and far planes are the renderer's choice from the
 * scene bounds, as for any camera with z_near = 0.
 *
 * Renderers come from the registry by name (`renderer`, and `reference` for
 * quality) with "key=value,..." options (`renderer_options`,
 * `reference_options`, validated at commit by configuring a renderer with
 * them; commas separate items, so a colour option takes one grey value
 * here). Every worker owns its renderers and images. `threads` goes to a
 * renderer's own "threads" option (unless its options set one): 0 means
 * all threads for a single worker and for time (RL_PROPERTY_EXCLUSIVE,
 * evaluated alone), one thread per renderer when several workers evaluate
 * concurrently.
 *
 * time: per direction the median of `repeats` (default 5) measured frames
 * (Sec. 4.1.4: the median evens out external disturbances), then the
 * maximum over the directions (Sec. 4.2.3: the maximum bounds the frame
 * rate). Unconditioned (default): the renderer is reset before every
 * measured frame (rl_renderer_reset), so nothing of an earlier frame is
 * reused, not even by the other repeats, while what it built for the scene
 * (BVH, Line Space) stays: that is preprocessing, not "Informationen aus
 * vorangegangenen Frames". The worker's first frame ever builds it, so a
 * direction's first repeat may be slow; the median keeps it out for
 * repeats >= 3. Conditioned: the worker's renderer is kept, and before
 * measuring a direction up to `condition_frames` (default 10) unmeasured
 * frames are rendered, stopping after the first frame that is not at least
 * 2 % faster than the one before ("bis keine weitere Verbesserung mehr ...
 * zu erwarten ist"). Times are wall-clock milliseconds of
 * rl_renderer_render() measured with rl_timer.
 *
 * ops: one frame per direction with the worker's renderer; `counter` from
 * rl_render_stats, reduced by `reduce` = max (default, like time) or sum.
 * The renderer is reset before each direction (rl_renderer_reset keeps
 * what it built for the scene), so that a renderer with temporal coherence
 * (chcpp, vt) counts what it does at this position, not what the previous
 * position left it: until 2026-12-04 chcpp's count depended on the order
 * in which the workers took the positions. Conditioning, as for time, is
 * not offered: CHC++ re-queries a visible node only every assumed_visible
 * frames, so a count does not settle when it first repeats.
 *
 * quality: per direction one frame of the renderer and one of the
 * reference, compared by rl_image_compare() on sRGB luma: ssim (Wang et
 * al. 2004), hssim (multi-scale SSIM over a Burt pyramid of `hssim_levels`
 * levels, rl_metrics.h; the thesis' "hierarchisch gefiltert ... nach
 * [Bur81]"), psnr (dB; +inf for identical images) or rmse. Def. 7: the
 * minimum over the directions for quality values, the maximum for the
 * error value rmse. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/options.h"
#include "core/params.h"
#include "eval/property_internal.h"
#include "rl/rl_metrics.h"
#include "rl/rl_sampling.h"
#include "rl/rl_timer.h"

/* ---- options ----------------------------------------------------------- */

#define RENDER_OPTION_ROWS                                                                      \
    { "renderer", RL_OPT_STRING, "raster", "renderer name from the registry (rl algos)", 0, 0,  \
      NULL },                                                                                   \
    { "renderer_options", RL_OPT_STRING, "",                                                    \
      "\"key=value,...\" options of the renderer, checked on commit", 0, 0, NULL },             \
    { "width", RL_OPT_INT, "256", "image width per direction, pixels", 1, 4096, NULL },        \
    { "height", RL_OPT_INT, "256", "image height per direction, pixels", 1, 4096, NULL },      \
    { "fov_deg", RL_OPT_FLOAT, "120",                                                           \
      "vertical field of view per direction (overlapping frusta, Jähn 2015 Sec. 4.2.3)", 1,    \
      179, NULL },                                                                              \
    { "threads", RL_OPT_INT, "0",                                                               \
      "renderer threads (0: all for one worker or time, else 1 per worker)", 0, 1024, NULL }

static const rl_option_info time_options[] = {
    RENDER_OPTION_ROWS,
    { "repeats", RL_OPT_INT, "5", "measured frames per direction; the median counts", 1, 1000,
      NULL },
    { "conditioned", RL_OPT_BOOL, "false",
      "keep the renderer and render unmeasured frames first (conditioned time)", 0, 0, NULL },
    { "condition_frames", RL_OPT_INT, "10",
      "at most this many unmeasured frames per direction when conditioned", 0, 1000, NULL },
};

static const char *const counter_choices[] = {
    "triangles", "rays", "primary_rays", "shadow_rays", "secondary_rays",
    "pixels", "samples", "occlusion_queries", "points", "primitives", NULL
};
enum { CNT_TRIANGLES = 0, CNT_RAYS, CNT_PRIMARY, CNT_SHADOW, CNT_SECONDARY, CNT_PIXELS,
       CNT_SAMPLES, CNT_QUERIES, CNT_POINTS, CNT_PRIMITIVES, CNT_COUNT };
_Static_assert(sizeof counter_choices / sizeof counter_choices[0] == CNT_COUNT + 1,
               "one name per counter");
static const char *const reduce_choices[] = { "max", "sum", NULL };
enum { REDUCE_MAX = 0, REDUCE_SUM };

static const rl_option_info ops_options[] = {
    RENDER_OPTION_ROWS,
    { "counter", RL_OPT_ENUM, "triangles",
      "triangles (rasterized), rays (all), primary_rays, shadow_rays, secondary_rays "
      "(reflection + refraction + diffuse), pixels (written), samples, occlusion_queries, points "
      "(drawn), primitives (triangles + points)",
      0, 0, counter_choices },
    { "reduce", RL_OPT_ENUM, "max", "over the six directions: max or sum", 0, 0, reduce_choices },
};

static const char *const metric_choices[] = { "ssim", "hssim", "psnr", "rmse", NULL };
enum { METRIC_SSIM = 0, METRIC_HSSIM, METRIC_PSNR, METRIC_RMSE };

static const rl_option_info quality_options[] = {
    RENDER_OPTION_ROWS,
    { "reference", RL_OPT_STRING, "raster", "conservative reference renderer (Def. 7)", 0, 0,
      NULL },
    { "reference_options", RL_OPT_STRING, "", "\"key=value,...\" options of the reference", 0,
      0, NULL },
    { "metric", RL_OPT_ENUM, "hssim",
      "ssim, hssim (multi-scale SSIM, Burt pyramid), psnr (dB, at most 100: equal images) or rmse",
      0, 0, metric_choices },
    { "hssim_levels", RL_OPT_INT, "5", "pyramid levels of hssim (Wang et al. 2003 use 5)", 2, 5,
      NULL },
};

/* Renderer names are checked against the registry when set. */
static rl_status check_renderer_name(const char *key, const char *value)
{
    if (strcmp(key, "renderer") != 0 && strcmp(key, "reference") != 0)
        return RL_OK;
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    char names[RL_OPTION_LIST_SIZE] = "", hint[96];
    rl_suggestion sg = { 0 };
    for (size_t i = 0; i < n; ++i) {
        if (strcmp(list[i].name, value) == 0)
            return RL_OK;
        if (i)
            rl_option_append(names, sizeof names, ", ");
        rl_option_append(names, sizeof names, list[i].name);
        rl_suggest(&sg, value, list[i].name);
    }
    return rl_error(RL_ERR_INVALID_ARG, "option %s=\"%s\" is not a renderer (%savailable: %s)", key,
                    value, rl_option_did_you_mean(&sg, hint, sizeof hint), names);
}

/* ---- shared state ------------------------------------------------------ */

typedef enum rp_kind { KIND_TIME = 0, KIND_OPS, KIND_QUALITY } rp_kind;

/* How to make one renderer: registry name plus its options. */
typedef struct renderer_recipe {
    const char *name;           /* points into the property's option text */
    rl_params params;
    int threads;                /* for the renderer's "threads" option, -1: leave */
} renderer_recipe;

typedef struct rp_worker {
    rl_renderer *r, *ref;
    rl_image *img, *ref_img;
    bool built;                 /* time: the renderer has built for the scene */
} rp_worker;

typedef struct rp_state {
    rp_kind kind;
    const char *who;            /* property name for messages */
    const rl_scene *scene;
    renderer_recipe main, reference;
    int width, height;
    float fov_deg;
    int repeats, condition_frames;
    bool conditioned;
    int counter, reduce, metric, hssim_levels;
    double *times;              /* repeats, per worker */
    int workers;
    rp_worker *w;
} rp_state;

static void render_release(void *state)
{
    rp_state *s = state;
    if (!s)
        return;
    for (int i = 0; s->w && i < s->workers; ++i) {
        rl_renderer_release(s->w[i].r);
        rl_renderer_release(s->w[i].ref);
        rl_image_release(s->w[i].img);
        rl_image_release(s->w[i].ref_img);
    }
    free(s->w);
    free(s->times);
    rl_params_free(&s->main.params);
    rl_params_free(&s->reference.params);
    free(s);
}

/* A configured renderer: the threads default first, so that an explicit
 * "threads" in the recipe's options wins. Bad options are reported with the
 * property and option key in front of the renderer's own message. */
static rl_status make_renderer(const rp_state *s, const renderer_recipe *rc, const char *key,
                               rl_renderer **out)
{
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create(rc->name, &r);
    if (st != RL_OK)
        return st;
    if (rc->threads >= 0 && rl_renderer_get(r, "threads")) {
        char text[16];
        snprintf(text, sizeof text, "%d", rc->threads);
        st = rl_renderer_set(r, "threads", text);
    }
    for (uint32_t i = 0; st == RL_OK && i < rc->params.count; ++i) {
        st = rl_renderer_set(r, rc->params.items[i].key, rc->params.items[i].value);
        if (st != RL_OK)
            rl_error(st, "%s: option %s: \"%s=%s\" rejected by %s", s->who, key,
                     rc->params.items[i].key, rc->params.items[i].value, rc->name);
    }
    /* What visset and select draw from (their sampled properties). */
    if (st == RL_OK)
        st = rl_renderer_prepare_inputs(r, s->scene);
    if (st != RL_OK) {
        rl_renderer_release(r);
        return st;
    }
    *out = r;
    return RL_OK;
}

static rl_status read_recipe(rl_property *p, rp_state *s, const char *name_key,
                             const char *options_key, renderer_recipe *rc)
{
    rc->name = rl_property_opt(p, name_key);
    rl_status st = rl_params_parse(rl_property_opt(p, options_key), &rc->params);
    if (st != RL_OK)
        return rl_error(st, "%s: option %s=\"%s\" is not \"key=value,...\"", s->who, options_key,
                        rl_property_opt(p, options_key));
    int threads = (int)rl_property_opt_int(p, "threads");
    if (threads == 0)
        threads = s->kind == KIND_TIME || s->workers == 1 ? 0 : 1;
    rc->threads = threads;
    return RL_OK;
}

static rl_status render_commit(rl_property *p, rp_kind kind, const rl_scene *scene, int workers,
                               void **state, uint32_t *set_size)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    const char *who = rl_property_name(p);
    if (d->num_triangles == 0)
        return rl_error(RL_ERR_EMPTY_SCENE, "%s: the scene has no triangles", who);
    rp_state *s = rl_calloc(1, sizeof *s);
    if (!s)
        return RL_ERR_OUT_OF_MEMORY;
    s->kind = kind;
    s->who = who;
    s->scene = scene;
    s->workers = workers;
    s->width = (int)rl_property_opt_int(p, "width");
    s->height = (int)rl_property_opt_int(p, "height");
    s->fov_deg = (float)rl_property_opt_float(p, "fov_deg");
    if (kind == KIND_TIME) {
        s->repeats = (int)rl_property_opt_int(p, "repeats");
        s->conditioned = rl_property_opt_bool(p, "conditioned");
        s->condition_frames = (int)rl_property_opt_int(p, "condition_frames");
    } else if (kind == KIND_OPS) {
        s->counter = rl_property_opt_enum(p, "counter");
        s->reduce = rl_property_opt_enum(p, "reduce");
    } else {
        s->metric = rl_property_opt_enum(p, "metric");
        s->hssim_levels = (int)rl_property_opt_int(p, "hssim_levels");
    }

    rl_status st = read_recipe(p, s, "renderer", "renderer_options", &s->main);
    if (st == RL_OK && kind == KIND_QUALITY)
        st = read_recipe(p, s, "reference", "reference_options", &s->reference);
    if (st == RL_OK) {
        s->w = rl_calloc((size_t)workers, sizeof *s->w);
        s->times = rl_calloc((size_t)workers * (size_t)(s->repeats > 0 ? s->repeats : 1),
                             sizeof *s->times);
        if (!s->w || !s->times)
            st = RL_ERR_OUT_OF_MEMORY;
    }
    for (int i = 0; st == RL_OK && i < workers; ++i) {
        rp_worker *w = &s->w[i];
        st = make_renderer(s, &s->main, "renderer_options", &w->r);
        if (st == RL_OK)
            st = rl_image_create(s->width, s->height, RL_LAYER_COLOR, &w->img);
        if (st == RL_OK && kind == KIND_QUALITY)
            st = make_renderer(s, &s->reference, "reference_options", &w->ref);
        if (st == RL_OK && kind == KIND_QUALITY)
            st = rl_image_create(s->width, s->height, RL_LAYER_COLOR, &w->ref_img);
    }
    if (st != RL_OK) {
        render_release(s);
        return st;
    }
    *state = s;
    *set_size = 0;
    return RL_OK;
}

static rl_camera direction_camera(const rp_state *s, rl_vec3 pos, int i)
{
    rl_vec3 dir, up;
    rl_property_direction(i, &dir, &up);
    rl_camera cam = { .eye = pos, .target = rl_add(pos, dir), .up = up, .fov_deg = s->fov_deg,
                      .width = s->width, .height = s->height };
    return cam;
}

/* ---- time (Sec. 4.2.3, Def. 6) ----------------------------------------- */

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *v, int n)
{
    qsort(v, (size_t)n, sizeof *v, compare_double);
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

rl_status rl_time_measure(const rl_time_frames *f, const rl_time_rule *rule, bool *built,
                          double *scratch, double direction[6], double *value)
{
    double ms = 0.0;
    if (!*built) {
        /* What a renderer builds for the scene on its first frame (a BVH, a
         * Line Space, surfels, sampled properties) is preprocessing, not the
         * time of a frame at this position: one unmeasured frame first, then
         * reset, which keeps the build (rl_renderer_reset). */
        rl_status st = f->render(f->ctx, 0, &ms);
        if (st != RL_OK)
            return st;
        f->reset(f->ctx);
        *built = true;
    }
    double v = 0.0;
    for (int i = 0; i < 6; ++i) {
        rl_status st = RL_OK;
        if (rule->conditioned) {
            /* condition until a frame is not 2 % faster than its predecessor */
            double prev = INFINITY;
            for (int k = 0; st == RL_OK && k < rule->condition_frames; ++k) {
                st = f->render(f->ctx, i, &ms);
                if (!(ms < 0.98 * prev))
                    break;
                prev = ms;
            }
        }
        for (int k = 0; st == RL_OK && k < rule->repeats; ++k) {
            if (!rule->conditioned)
                f->reset(f->ctx);   /* unconditioned: no earlier frame survives */
            st = f->render(f->ctx, i, &scratch[k]);
        }
        if (st != RL_OK)
            return st;
        direction[i] = median(scratch, rule->repeats);
        v = direction[i] > v ? direction[i] : v;
    }
    *value = v;
    return RL_OK;
}

typedef struct time_ctx {
    rp_state *s;
    rp_worker *w;
    rl_vec3 pos;
} time_ctx;

static rl_status time_render(void *ctx, int direction, double *ms)
{
    time_ctx *c = ctx;
    rl_camera cam = direction_camera(c->s, c->pos, direction);
    rl_timer t;
    rl_timer_start(&t);
    rl_status st = rl_renderer_render(c->w->r, c->s->scene, &cam, c->w->img, NULL);
    *ms = rl_timer_ms(&t);
    return st;
}

static void time_reset(void *ctx) { rl_renderer_reset(((time_ctx *)ctx)->w->r); }

static rl_status time_evaluate(rl_property *p, void *state, int worker, rl_vec3 pos,
                               rl_property_result *out)
{
    (void)p;
    rp_state *s = state;
    time_ctx c = { s, &s->w[worker], pos };
    rl_time_frames f = { time_render, time_reset, &c };
    rl_time_rule rule = { s->repeats, s->conditioned, s->condition_frames };
    return rl_time_measure(&f, &rule, &c.w->built, s->times + (size_t)worker * (size_t)s->repeats,
                           out->direction, &out->value);
}

/* ---- ops (Sec. 4.2.4) -------------------------------------------------- */

static double read_counter(int counter, const rl_render_stats *st)
{
    switch (counter) {
    case CNT_TRIANGLES: return (double)st->triangles_rasterized;
    case CNT_RAYS: {
        uint64_t sum = 0;
        for (int t = 0; t < RL_RAY_TYPE_COUNT; ++t)
            sum += st->rays[t];
        return (double)sum;
    }
    case CNT_PRIMARY: return (double)st->rays[RL_RAY_PRIMARY];
    case CNT_SHADOW: return (double)st->rays[RL_RAY_SHADOW];
    case CNT_SECONDARY:
        return (double)(st->rays[RL_RAY_REFLECTION] + st->rays[RL_RAY_REFRACTION] +
                        st->rays[RL_RAY_DIFFUSE]);
    case CNT_PIXELS: return (double)st->pixels_written;
    case CNT_SAMPLES: return (double)st->samples;
    case CNT_QUERIES: return (double)st->occlusion_queries;
    case CNT_POINTS: return (double)st->points_drawn;
    case CNT_PRIMITIVES: return (double)(st->triangles_rasterized + st->points_drawn);
    }
    return NAN;
}

static rl_status ops_evaluate(rl_property *p, void *state, int worker, rl_vec3 pos,
                              rl_property_result *out)
{
    (void)p;
    rp_state *s = state;
    rp_worker *w = &s->w[worker];
    double value = 0.0;
    for (int i = 0; i < 6; ++i) {
        rl_camera cam = direction_camera(s, pos, i);
        rl_render_stats stats;
        rl_renderer_reset(w->r);        /* nothing of an earlier frame survives */
        rl_status st = rl_renderer_render(w->r, s->scene, &cam, w->img, &stats);
        if (st != RL_OK)
            return st;
        double v = read_counter(s->counter, &stats);
        out->direction[i] = v;
        value = s->reduce == REDUCE_SUM ? value + v : (v > value ? v : value);
    }
    out->value = value;
    return RL_OK;
}

/* ---- quality (Sec. 4.2.5, Def. 7) -------------------------------------- */

static rl_status quality_evaluate(rl_property *p, void *state, int worker, rl_vec3 pos,
                                  rl_property_result *out)
{
    (void)p;
    rp_state *s = state;
    rp_worker *w = &s->w[worker];
    const bool error_metric = s->metric == METRIC_RMSE;
    double value = error_metric ? -INFINITY : INFINITY;
    rl_metric_options mo = { .ssim_levels = s->metric == METRIC_HSSIM ? s->hssim_levels : 0 };
    for (int i = 0; i < 6; ++i) {
        rl_camera cam = direction_camera(s, pos, i);
        rl_status st = rl_renderer_render(w->r, s->scene, &cam, w->img, NULL);
        if (st == RL_OK)
            st = rl_renderer_render(w->ref, s->scene, &cam, w->ref_img, NULL);
        rl_image_metrics m;
        if (st == RL_OK)
            st = rl_image_compare(w->img, w->ref_img, &mo, &m);
        if (st != RL_OK)
            return st;
        double v = s->metric == METRIC_PSNR ? fmin(m.psnr, RL_PROPERTY_PSNR_MAX)
                 : s->metric == METRIC_RMSE ? m.rmse : m.ssim;
        out->direction[i] = v;
        /* Def. 7: the worst direction, i.e. min of a quality, max of an error */
        value = error_metric ? (v > value ? v : value) : (v < value ? v : value);
    }
    out->value = value;
    return RL_OK;
}

/* ---- classes ----------------------------------------------------------- */

static rl_status time_commit(rl_property *p, const rl_scene *scene, int workers, void **state,
                             uint32_t *set_size)
{
    return render_commit(p, KIND_TIME, scene, workers, state, set_size);
}

static rl_status ops_commit(rl_property *p, const rl_scene *scene, int workers, void **state,
                            uint32_t *set_size)
{
    return render_commit(p, KIND_OPS, scene, workers, state, set_size);
}

static rl_status quality_commit(rl_property *p, const rl_scene *scene, int workers, void **state,
                                uint32_t *set_size)
{
    return render_commit(p, KIND_QUALITY, scene, workers, state, set_size);
}

static const char *time_unit(const rl_property *p)
{
    (void)p;
    return "ms";
}

static unsigned time_flags(const rl_property *p)
{
    (void)p;
    return RL_PROPERTY_EXCLUSIVE;
}

static const char *ops_unit(const rl_property *p)
{
    static const char *const units[CNT_COUNT] = {
        [CNT_TRIANGLES] = "triangles", [CNT_RAYS] = "rays", [CNT_PRIMARY] = "rays",
        [CNT_SHADOW] = "rays", [CNT_SECONDARY] = "rays", [CNT_PIXELS] = "pixels",
        [CNT_SAMPLES] = "samples", [CNT_QUERIES] = "queries", [CNT_POINTS] = "points",
        [CNT_PRIMITIVES] = "primitives" };
    _Static_assert(sizeof units / sizeof units[0] == CNT_COUNT, "one unit per counter");
    return units[rl_property_opt_enum(p, "counter")];
}

static const char *quality_unit(const rl_property *p)
{
    static const char *const units[] = { "SSIM", "SSIM", "dB", "RMSE" };
    return units[rl_property_opt_enum(p, "metric")];
}

static unsigned quality_flags(const rl_property *p)
{
    return rl_property_opt_enum(p, "metric") == METRIC_RMSE ? 0u
                                                            : (unsigned)RL_PROPERTY_HIGHER_IS_BETTER;
}

const rl_property_class rl_property_time_class = {
    .info = { "time", "Rendering time of a renderer, max over six directions of the median, ms",
              "Jähn 2015, Sec. 4.2.3, Def. 6" },
    .options = time_options,
    .num_options = sizeof time_options / sizeof time_options[0],
    .unit = time_unit,
    .flags = time_flags,
    .check = check_renderer_name,
    .commit = time_commit,
    .evaluate = time_evaluate,
    .release = render_release,
};

const rl_property_class rl_property_ops_class = {
    .info = { "ops", "An operation count of a renderer (triangles, rays, ...) over six directions",
              "Jähn 2015, Sec. 4.2.4" },
    .options = ops_options,
    .num_options = sizeof ops_options / sizeof ops_options[0],
    .unit = ops_unit,
    .check = check_renderer_name,
    .commit = ops_commit,
    .evaluate = ops_evaluate,
    .release = render_release,
};

const rl_property_class rl_property_quality_class = {
    .info = { "quality",
              "Image quality of a renderer against a reference, worst of six directions",
              "Jähn 2015, Sec. 4.2.5, Def. 7" },
    .options = quality_options,
    .num_options = sizeof quality_options / sizeof quality_options[0],
    .unit = quality_unit,
    .flags = quality_flags,
    .check = check_renderer_name,
    .commit = quality_commit,
    .evaluate = quality_evaluate,
    .release = render_release,
};
