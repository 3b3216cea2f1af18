/* visset.c: renderer "visset", visibility as a position-dependent property
 * (Jähn 2015, Sec. 7.6): the set of visible objects, approximated over a
 * region by adaptive sampling (Ch. 5, the visibility property of Sec.
 * 4.2.2), is queried at the viewer's position and only that set is drawn.
 *
 * The renderer reads the approximation through its input "approx" (a
 * rl_position_lookup, rl_render.h) and never samples or loads it itself:
 * rl_renderer_prepare_inputs() (rl_sampling.h, which the CLI calls) loads
 * the file written by `rl eval --property visibility` (option approx = its
 * approx.json), or samples it over the scene's bounds (a 2-D slice at
 * `height` above the scene's floor, or the 3-D bounds) with `samples`
 * samples of `resolution`² pixels per cube face. Where the viewer is
 * outside the sampled region the renderer draws everything in the frustum
 * (and counts it), so it never shows an empty image for want of data.
 *
 * Budgeted variant (Sec. 7.6 after Eikel, Jähn & Fischer 2010): with
 * budget > 0 the objects of the set are drawn in decreasing estimated
 * impact, their visible pixels at the centre of the region they come from,
 * as long as the triangles drawn stay within the budget; an object that
 * would exceed it is skipped and smaller ones still get their turn, so the
 * budget is never exceeded. The impact estimate at the region centre is
 * ours (the lookup's object_pixels): the thesis' property stores pixels per
 * object and sample.
 *
 * drawer = gl (device: the EGL device) draws the set with the GL drawer of
 * src/gl; the sampled approximation is the software property's either way.
 *
 * Frustum culling applies to each object of the set. Approximate: an
 * object that no sample of the region saw is missing (Fig. 7.11). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/culling.h"
#include "rl/rl_drawer.h"
#include "render/renderer.h"
#include "rl/rl_timer.h"

static const rl_option_info visset_options[] = {
    RL_CULL_RASTER_OPTIONS,
    { "approx", RL_OPT_STRING, "", "approx.json of the visibility property (rl eval); empty: sampled before the "
      "first frame", 0, 0, NULL },
    { "samples", RL_OPT_INT, "256", "samples when sampled before the first frame", 1, 1 << 20, NULL },
    { "dims", RL_OPT_INT, "2", "2: a horizontal slice at `height`; 3: the scene's bounds", 2, 3, NULL },
    { "height", RL_OPT_FLOAT, "1.7", "slice height above the scene's lowest point (dims 2)", -1e6, 1e6, NULL },
    { "resolution", RL_OPT_INT, "128", "pixels per cube face of each visibility sample", 8, 4096, NULL },
    { "seed", RL_OPT_INT, "1", "sampling seed", 0, 4294967295.0, NULL },
    { "budget", RL_OPT_INT, "0", "triangles per frame, highest impact first (0: no budget)", 0, 4294967295.0,
      NULL },
};

typedef struct visset_state {
    rl_culling_head head;         /* first: rl_culling_get_stats */
    /* What the per-object arrays and the ranking were made for: the
     * input's generation (rl_renderer_input) and the scene. */
    uint64_t generation, scene_uid;
    bool ready, ranked;
    /* budget mode: per leaf region its set ordered by impact */
    uint64_t *rank_offset;
    uint32_t *rank_objects;
    uint32_t *stamp;
    uint32_t frame;
    uint32_t frames_outside;      /* viewer outside the sampled region */
    /* This frame's objects in drawing order, drawn as one list
     * (rl_drawer_draw), on all threads. */
    uint32_t *draw;
    uint32_t num_draw;
} visset_state;

static const char *const visset_inputs[] = { "approx" };

static void drop(visset_state *s)
{
    free(s->rank_offset);
    free(s->rank_objects);
    free(s->stamp);
    free(s->draw);
    s->rank_offset = NULL;
    s->rank_objects = NULL;
    s->stamp = NULL;
    s->draw = NULL;
    s->ready = s->ranked = false;
}

static void visset_release(void *state)
{
    visset_state *s = state;
    drop(s);
    rl_drawer_release(s->head.drawer);
}

typedef struct ranked {
    uint32_t object, pixels;
} ranked;

static int by_impact(const void *a, const void *b)
{
    const ranked *x = a, *y = b;
    if (x->pixels != y->pixels)
        return x->pixels > y->pixels ? -1 : 1;
    return x->object < y->object ? -1 : x->object > y->object;
}

/* Budget mode: each leaf's set ordered by visible pixels at its centre. */
static rl_status build_ranking(visset_state *s, const rl_position_lookup *l, const rl_scene_data *d)
{
    if (!l->object_pixels || !l->region_center)
        return rl_error(RL_ERR_INVALID_ARG, "visset: budget > 0 needs the visible pixels per object, which the "
                                            "lookup in input \"approx\" does not offer");
    rl_status st = RL_OK;
    uint32_t nr = l->num_regions;
    uint32_t *pixels = rl_calloc(d->num_objects, sizeof *pixels);
    ranked *tmp = rl_calloc(d->num_objects, sizeof *tmp);
    s->rank_offset = rl_calloc((size_t)nr + 1, sizeof *s->rank_offset);
    size_t total = 0;
    for (uint32_t i = 0; i < nr; ++i) {
        const uint64_t *set = l->region_set(l->user, i);
        for (uint32_t o = 0; set && o < d->num_objects; ++o)
            total += (set[o / 64] >> (o % 64)) & 1u;
    }
    s->rank_objects = rl_calloc(total + 1, sizeof *s->rank_objects);
    if (!pixels || !tmp || !s->rank_offset || !s->rank_objects)
        st = RL_ERR_OUT_OF_MEMORY;
    size_t at = 0;
    for (uint32_t i = 0; i < nr && st == RL_OK; ++i) {
        st = l->object_pixels(l->user, l->region_center(l->user, i), pixels);
        const uint64_t *set = l->region_set(l->user, i);
        uint32_t n = 0;
        for (uint32_t o = 0; st == RL_OK && set && o < d->num_objects; ++o)
            if ((set[o / 64] >> (o % 64)) & 1u)
                tmp[n++] = (ranked){ o, pixels[o] };
        qsort(tmp, n, sizeof *tmp, by_impact);
        s->rank_offset[i] = at;
        for (uint32_t k = 0; k < n; ++k)
            s->rank_objects[at++] = tmp[k].object;
    }
    if (st == RL_OK)
        s->rank_offset[nr] = at;
    free(pixels);
    free(tmp);
    return st;
}

/* The sets of input "approx", checked against the scene, and the
 * per-object arrays; the ranking too in budget mode. Redone when the input
 * or the scene changes. */
static rl_status prepare(visset_state *s, rl_renderer *r, const rl_scene *scene, const rl_scene_data *d,
                         bool budget, const rl_position_lookup **out, double *built_ms)
{
    uint64_t generation;
    const rl_position_lookup *l = rl_renderer_input(r, "approx", &generation);
    if (!l)
        return rl_error(RL_ERR_INVALID_ARG,
                        "visset: no visible sets: load or sample them with rl_renderer_prepare_inputs() "
                        "(rl_sampling.h; the rl tool does), or hand a lookup to input \"approx\"");
    rl_status st = rl_renderer_check_input_property(r, "approx", l, "visibility");
    if (st != RL_OK)
        return st;
    *out = l;
    uint64_t uid = rl_scene_uid(scene);
    bool same_sets = s->ready && s->generation == generation && s->scene_uid == uid;
    if (same_sets && (!budget || s->ranked))
        return RL_OK;

    rl_timer t0;
    rl_timer_start(&t0);
    double input_ms = 0.0;
    if (!same_sets) {
        drop(s);
        if (l->set_size != d->num_objects || !l->region_set)
            return rl_error(RL_ERR_INVALID_ARG,
                            "visset: the approximation holds sets of %u objects, the scene has %u (is it the "
                            "visibility property of this scene?)",
                            l->set_size, d->num_objects);
        s->stamp = rl_calloc(d->num_objects, sizeof *s->stamp);
        s->draw = rl_calloc(d->num_objects ? d->num_objects : 1, sizeof *s->draw);
        if (!s->stamp || !s->draw) {
            drop(s);
            return RL_ERR_OUT_OF_MEMORY;
        }
        s->frame = 0;
        s->ready = true;
        s->generation = generation;
        s->scene_uid = uid;
        input_ms = l->prepare_ms;   /* the first frame with these sets reports their making */
    }
    if (budget) {
        st = build_ranking(s, l, d);
        if (st != RL_OK) {
            drop(s);
            return st;
        }
        s->ranked = true;
    }
    *built_ms = rl_timer_ms(&t0);   /* the frame's preparation; the input was made before */
    s->head.stats.preprocess_ms = input_ms + *built_ms;
    return RL_OK;
}

typedef struct visset_frame {
    visset_state *s;
    const rl_scene_data *d;
    rl_cull_frame cf;
    uint64_t budget;
} visset_frame;

/* Draws object o unless culled, drawn already or beyond the budget. */
static rl_status draw_object(visset_frame *f, uint32_t o)
{
    visset_state *s = f->s;
    const rl_object *obj = &f->d->objects[o];
    if (s->stamp[o] == s->frame || !rl_cull_box_in_frustum(&f->cf.view, obj->bounds))
        return RL_OK;
    if (f->budget && s->head.stats.triangles_drawn + obj->num_triangles > f->budget)
        return RL_OK;
    s->stamp[o] = s->frame;
    s->head.stats.objects_drawn++;
    s->head.stats.triangles_drawn += obj->num_triangles;
    s->draw[s->num_draw++] = o;       /* once per frame (the stamp) */
    return RL_OK;
}

static rl_status visset_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                               rl_image *image, rl_render_stats *stats)
{
    visset_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    memset(&s->head.stats, 0, sizeof s->head.stats);
    s->head.have_frame = false;
    const uint64_t budget = (uint64_t)rl_renderer_opt_int(r, "budget");
    const rl_position_lookup *l = NULL;
    rl_status st = prepare(s, r, scene, d, budget > 0, &l, &stats->prep_ms);
    if (st != RL_OK)
        return st;

    visset_frame f;
    memset(&f, 0, sizeof f);
    f.s = s;
    f.d = d;
    f.budget = budget;
    st = rl_cull_frame_begin(r, scene, &s->head, cam, image, true, &f.cf);
    if (st != RL_OK)
        return st;
    if (++s->frame == 0) {
        memset(s->stamp, 0, d->num_objects * sizeof *s->stamp);
        s->frame = 1;
    }
    s->num_draw = 0;
    /* Inside the sampled region (2-D: its x-z extent)? Checked here so that
     * a viewer outside raises no error. */
    rl_vec3 e = f.cf.view.eye;
    double ignored;
    uint32_t region = 0;
    bool inside = l->query(l->user, e, &ignored, &region) && region < l->num_regions;
    if (st == RL_OK && !inside) {
        s->frames_outside++;
        for (uint32_t o = 0; o < d->num_objects && st == RL_OK; ++o)
            st = draw_object(&f, o);
    } else if (st == RL_OK && budget) {
        for (uint64_t a = s->rank_offset[region]; a < s->rank_offset[region + 1] && st == RL_OK; ++a)
            st = draw_object(&f, s->rank_objects[a]);
    } else if (st == RL_OK) {
        const uint64_t *set = l->region_set(l->user, region);
        for (uint32_t o = 0; set && o < d->num_objects && st == RL_OK; ++o)
            if ((set[o / 64] >> (o % 64)) & 1u)
                st = draw_object(&f, o);
    }
    if (st == RL_OK)
        st = rl_drawer_draw(f.cf.drawer, s->draw, s->num_draw, &f.cf.counters);
    st = rl_cull_frame_end(&f.cf, st, image, stats);
    if (st != RL_OK)
        return st;
    s->head.have_frame = true;
    return RL_OK;
}

const rl_renderer_class rl_visset_renderer_class = {
    .info = { .name = "visset",
              .description = "Draws the set of visible objects stored in a sampled visibility property "
                             "(approximate; optional triangle budget)",
              .reference = "Jähn 2015, Sec. 7.6; Eikel, Jähn & Fischer 2010",
              .frame_bytes_per_pixel = RL_CULL_FRAME_BYTES_PER_PIXEL },
    .options = visset_options,
    .num_options = sizeof visset_options / sizeof visset_options[0],
    .state_size = sizeof(visset_state),
    .render = visset_render,
    .release = visset_release,
    .check = NULL,
    .reset = NULL,
    .available = rl_cull_available,
    .inputs = visset_inputs,
    .num_inputs = sizeof visset_inputs / sizeof visset_inputs[0],
};
