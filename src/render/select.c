/* select.c: renderer "select", the runtime selection of a culling method
 * per position (Jähn 2015, Sec. 7.5): two renderers (default chcpp and
 * svs) and a sampled position-dependent property that predicts, at the
 * viewer's position, which of them to use for the frame.
 *
 * Rules:
 *   time       (default) the renderer whose sampled time property is lower
 *              there: the thesis' "hardware-dependent" variant, which needs
 *              the time of both measured on the target machine. The two
 *              approximations come from `rl eval --property time` (options
 *              first_time, second_time = their approx.json), or are sampled
 *              before the first frame over the scene (a 2-D slice at
 *              `height` above the floor, or the 3-D bounds) with `samples`
 *              samples of `resolution`² pixels per direction, conditioned
 *              by 2 frames and measured once (coarse: a first look).
 *   threshold  the thesis' rule: `first` where the sampled property in
 *              `property` (an approx.json, e.g. the polygons in visible
 *              objects, `rl eval --property visibility --set
 *              measure=polygons`) is below `threshold`, else `second`.
 * Where the viewer is outside a sampled region, `first` draws (the
 * conservative choice with the defaults).
 *
 * The renderer reads the approximations through its inputs, named after
 * those options (rl_position_lookup, rl_render.h), and never samples or
 * loads them itself: rl_renderer_prepare_inputs() (rl_sampling.h, which the
 * CLI calls) loads the files or samples the times. Its two renderers get no
 * inputs, so neither may be one that reads them (visset, select).
 *
 * The chosen renderer draws the whole frame with the shared raster options
 * forwarded (drawer and device too, where it has them: drawer=gl draws on
 * the GPU; the times sampled without files are the software drawer's); both are kept between frames, so CHC++ keeps its temporal
 * coherence across frames that SVS drew. The first frame for a scene also
 * lets the renderer not chosen draw once (into the same image, overwritten
 * after), so that both build for the scene (SVS' sets, CHC++'s octree) in
 * that frame's preprocessing and a later switch costs a frame, not a
 * build. rl_culling_get_stats returns the drawing renderer's statistics
 * with `selected` set. */
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/culling.h"
#include "render/renderer.h"
#include "rl/rl_timer.h"

#define NAME_MAX_LEN 64

static const char *const rule_choices[] = { "time", "threshold", NULL };
enum { RULE_TIME, RULE_THRESHOLD };

/* The options forwarded to both renderers (RL_CULL_RASTER_OPTIONS). */
static const char *const forwarded[] = { "shading", "cull", "ambient", "background", "threads", "drawer", "device" };
/* The last two only reach renderers that have them (every culling one):
 * another renderer draws with its own backend, so they must keep their
 * defaults for it. */
#define NUM_FORWARDED_ALWAYS 5

static const rl_option_info select_options[] = {
    RL_CULL_RASTER_OPTIONS,
    { "first", RL_OPT_STRING, "chcpp", "renderer drawn where the rule picks it, and outside the sampled region",
      0, 0, NULL },
    { "second", RL_OPT_STRING, "svs", "the other renderer", 0, 0, NULL },
    { "rule", RL_OPT_ENUM, "time",
      "time: the one with the lower sampled time property; threshold: first where `property` < threshold",
      0, 0, rule_choices },
    { "first_time", RL_OPT_STRING, "", "rule=time: approx.json of first's time property (rl eval); empty: sampled before the first frame",
      0, 0, NULL },
    { "second_time", RL_OPT_STRING, "", "rule=time: approx.json of second's time property; empty: sampled before the first frame",
      0, 0, NULL },
    { "property", RL_OPT_STRING, "", "rule=threshold: approx.json of a scalar property (required)", 0, 0, NULL },
    { "threshold", RL_OPT_FLOAT, "0", "rule=threshold: first where the property is below this", -1e300, 1e300, NULL },
    { "samples", RL_OPT_INT, "8", "samples per time property when sampled before the first frame (a coarse default: give files from rl eval for a real selection)", 1, 1 << 20, NULL },
    { "dims", RL_OPT_INT, "2", "sampled: 2 = a horizontal slice at `height`, 3 = the scene's bounds", 2, 3,
      NULL },
    { "height", RL_OPT_FLOAT, "1.7", "slice height above the scene's lowest point (dims 2)", -1e6, 1e6, NULL },
    { "resolution", RL_OPT_INT, "32", "sampled: pixels per side of each of the 6 directions", 8, 4096, NULL },
    { "seed", RL_OPT_INT, "1", "sampling seed", 0, 4294967295.0, NULL },
};

typedef struct select_state {
    rl_culling_head head;         /* first: rl_culling_get_stats */
    rl_renderer *child[2];
    char child_name[2][NAME_MAX_LEN];
    uint64_t built_uid[2];        /* scene the child has drawn once for (0: none) */
    uint64_t generation[2];       /* of the inputs last used: their making is reported once */
} select_state;

/* rule=time reads both times, rule=threshold the property. */
static const char *const select_inputs[] = { "first_time", "second_time", "property" };

static void select_release(void *state)
{
    select_state *s = state;
    for (int i = 0; i < 2; ++i)
        rl_renderer_release(s->child[i]);
}

static void select_reset(void *state)
{
    select_state *s = state;
    for (int i = 0; i < 2; ++i)
        if (s->child[i])
            rl_renderer_reset(s->child[i]);
}

static rl_status copy_text(char *dst, size_t size, const char *src, const char *what)
{
    if (strlen(src) >= size)
        return rl_error(RL_ERR_INVALID_ARG, "select: %s longer than %zu characters", what, size - 1);
    strcpy(dst, src);
    return RL_OK;
}

/* The two renderers, created when their names change; the shared raster
 * options forwarded whenever they differ. */
static rl_status prepare_children(select_state *s, rl_renderer *r)
{
    const char *keys[2] = { "first", "second" };
    for (int i = 0; i < 2; ++i) {
        const char *name = rl_renderer_opt_string(r, keys[i]);
        if (strcmp(name, "select") == 0)
            return rl_error(RL_ERR_INVALID_ARG, "select: %s=select would select itself", keys[i]);
        if (!s->child[i] || strcmp(s->child_name[i], name) != 0) {
            rl_renderer_release(s->child[i]);
            s->child[i] = NULL;
            s->child_name[i][0] = '\0';
            s->built_uid[i] = 0;
            rl_status st = copy_text(s->child_name[i], sizeof s->child_name[i], name, keys[i]);
            if (st == RL_OK)
                st = rl_renderer_create(name, &s->child[i]);   /* names an unknown renderer */
            size_t inputs = 0;
            rl_renderer_input_slots(s->child[i], &inputs);
            if (st == RL_OK && inputs)
                st = rl_error(RL_ERR_INVALID_ARG, "select: %s=%s reads measured inputs, which select does not "
                                                  "hand on", keys[i], name);
            if (st != RL_OK) {
                s->child_name[i][0] = '\0';
                return st;
            }
        }
        /* Culling renderers have them all; another renderer must too.
         * Set only when changed: no copies on every frame. */
        for (size_t k = 0; k < sizeof forwarded / sizeof forwarded[0]; ++k) {
            const char *want = rl_renderer_get(r, forwarded[k]), *have = rl_renderer_get(s->child[i], forwarded[k]);
            if (have && strcmp(have, want) == 0)
                continue;
            if (!have && k >= NUM_FORWARDED_ALWAYS) {
                const rl_option_info *info = NULL;
                size_t n = 0;
                const rl_option_info *opts = rl_renderer_options(r, &n);
                for (size_t j = 0; j < n; ++j)
                    if (strcmp(opts[j].key, forwarded[k]) == 0)
                        info = &opts[j];
                if (info && strcmp(info->default_value, want) == 0)
                    continue;
                return rl_error(RL_ERR_INVALID_ARG, "select: %s=%s has no option %s (%s=%s)", keys[i],
                                s->child_name[i], forwarded[k], forwarded[k], want);
            }
            rl_status st = rl_renderer_set(s->child[i], forwarded[k], want);
            if (st != RL_OK)
                return st;
        }
    }
    return RL_OK;
}

/* The lookups the rule reads: both times (rule=time) or the property
 * (rule=threshold), checked; their making is reported as preprocessing on
 * the first frame that uses them. */
static rl_status prepare(select_state *s, rl_renderer *r, int rule, const rl_position_lookup *l[2])
{
    const char *slots[2] = { "first_time", "second_time" };
    if (rule == RULE_THRESHOLD)
        slots[0] = "property", slots[1] = NULL;
    for (int i = 0; i < 2; ++i) {
        l[i] = NULL;
        if (!slots[i])
            continue;
        uint64_t generation;
        l[i] = rl_renderer_input(r, slots[i], &generation);
        if (!l[i])
            return rule == RULE_THRESHOLD
                       ? rl_error(RL_ERR_INVALID_ARG, "select: rule=threshold needs property=FILE (approx.json "
                                                      "of rl eval, e.g. --property visibility --set "
                                                      "measure=polygons)")
                       : rl_error(RL_ERR_INVALID_ARG,
                                  "select: no %s: load or sample it with rl_renderer_prepare_inputs() "
                                  "(rl_sampling.h; the rl tool does), or hand a lookup to input \"%s\"",
                                  slots[i], slots[i]);
        /* A time read from a file must be a time (of any renderer: the
         * file does not say which). */
        rl_status st = rule == RULE_TIME ? rl_renderer_check_input_property(r, slots[i], l[i], "time") : RL_OK;
        if (st != RL_OK)
            return st;
        if (generation != s->generation[i]) {
            s->head.stats.preprocess_ms += l[i]->prepare_ms;
            s->generation[i] = generation;
        }
    }
    return RL_OK;
}

/* The lookup's value at the eye; false outside its region. */
static bool value_at(const rl_position_lookup *l, rl_vec3 eye, double *value)
{
    uint32_t region;
    return l->query(l->user, eye, value, &region);
}

static rl_status select_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                               rl_image *image, rl_render_stats *stats)
{
    select_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    s->head.have_frame = false;
    memset(&s->head.stats, 0, sizeof s->head.stats);   /* prepare() times what it loads or samples */
    const int rule = rl_renderer_opt_enum(r, "rule");
    const rl_position_lookup *l[2];
    rl_status st = prepare_children(s, r);
    if (st == RL_OK)
        st = prepare(s, r, rule, l);
    if (st != RL_OK)
        return st;

    int pick = 0;
    double v0, v1;
    if (rule == RULE_THRESHOLD) {
        if (value_at(l[0], cam->eye, &v0))
            pick = v0 < rl_renderer_opt_float(r, "threshold") ? 0 : 1;
    } else if (value_at(l[0], cam->eye, &v0) && value_at(l[1], cam->eye, &v1)) {
        pick = v1 < v0 ? 1 : 0;
    }
    double pre_ms = s->head.stats.preprocess_ms, other_ms = 0.0;
    uint64_t uid = rl_scene_uid(scene);
    if (s->built_uid[1 - pick] != uid) {
        /* The other one builds for the scene now, as preprocessing. */
        rl_timer t;
        rl_timer_start(&t);
        st = rl_renderer_render(s->child[1 - pick], scene, cam, image, NULL);
        if (st != RL_OK)
            return st;
        s->built_uid[1 - pick] = uid;
        other_ms = rl_timer_ms(&t);
        pre_ms += other_ms;
    }
    st = rl_renderer_render(s->child[pick], scene, cam, image, stats);
    if (st != RL_OK)
        return st;
    /* The chosen one's own preparation and the other's whole first frame;
     * the inputs were made before this frame. */
    stats->prep_ms += other_ms;
    s->built_uid[pick] = uid;
    /* Another renderer than a culling one has its rl_render_stats only. */
    const rl_culling_stats *cs = rl_cull_stats_of(s->child[pick]);
    if (cs)
        s->head.stats = *cs;
    s->head.stats.preprocess_ms += pre_ms;
    s->head.stats.selected = (uint32_t)pick + 1;
    s->head.have_frame = true;
    return RL_OK;
}

const rl_renderer_class rl_select_renderer_class = {
    .info = { .name = "select",
              .description = "Runtime selection per position of one of two culling renderers (default chcpp or "
                             "svs) from sampled properties",
              .reference = "Jähn 2015, Sec. 7.5",
              .frame_bytes_per_pixel = 2 * RL_CULL_FRAME_BYTES_PER_PIXEL },   /* both renderers it picks from */
    .options = select_options,
    .num_options = sizeof select_options / sizeof select_options[0],
    .state_size = sizeof(select_state),
    .render = select_render,
    .release = select_release,
    .check = NULL,
    .reset = select_reset,
    .available = rl_cull_available,
    .inputs = select_inputs,
    .num_inputs = sizeof select_inputs / sizeof select_inputs[0],
};
