/* inputs.c: the measured inputs of renderers (rl_renderer_set_input,
 * rl_render.h) made from sampled approximations.
 *
 * visset and select draw from position-dependent properties (Jähn 2015,
 * Sec. 7.5, 7.6) but sit below the evaluation layer, so they only read a
 * rl_position_lookup. Sampling or loading what their options describe is
 * done here, before the first frame, by whoever drives the renderer (the
 * CLI calls rl_renderer_prepare_inputs for every renderer it creates, and
 * so do the time, ops and quality properties for the renderers they
 * measure). What each option means is documented in visset.c and select.c. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/sampling_internal.h"
#include "render/renderer.h"
#include "rl/rl_property.h"
#include "rl/rl_sampling.h"
#include "rl/rl_timer.h"

/* The lookup's state: the approximation and, for visset's budget, the
 * visibility property that counts pixels per object (made on first use). */
typedef struct approx_input {
    rl_approx *approx;
    const rl_scene *scene;        /* NULL: no object pixels offered */
    uint32_t resolution;
    int threads;
    rl_property *visibility;
} approx_input;

/* Whether the approximation covers the viewer at p: inside its bounds, for
 * a 2-D slice inside its x-z extent at any height. */
static bool covers(const rl_approx *a, rl_vec3 p)
{
    rl_aabb b = rl_approx_bounds(a);
    return p.x >= b.min.x && p.x <= b.max.x && p.z >= b.min.z && p.z <= b.max.z &&
           (rl_approx_dims(a) == 2 || (p.y >= b.min.y && p.y <= b.max.y));
}

static bool input_query(void *user, rl_vec3 p, double *value, uint32_t *region)
{
    const approx_input *in = user;
    return covers(in->approx, p) && rl_approx_query(in->approx, p, value, region) == RL_OK;
}

static const uint64_t *input_region_set(void *user, uint32_t region)
{
    return rl_approx_region_set(((const approx_input *)user)->approx, region);
}

static rl_vec3 input_region_center(void *user, uint32_t region)
{
    rl_approx_region reg;
    if (rl_approx_get_region(((const approx_input *)user)->approx, region, &reg) != RL_OK)
        return rl_v3s(0.0f);
    return rl_aabb_center(reg.box);
}

static rl_status make_visibility(const rl_scene *scene, uint32_t resolution, int threads, rl_property **out)
{
    rl_property *p = NULL;
    char res[32];
    snprintf(res, sizeof res, "%u", resolution);
    rl_status st = rl_property_create("visibility", &p);
    if (st == RL_OK)
        st = rl_property_set(p, "resolution", res);
    if (st == RL_OK)
        st = rl_property_commit(p, scene, threads > 0 ? threads : 0);
    if (st != RL_OK) {
        rl_property_release(p);
        return st;
    }
    *out = p;
    return RL_OK;
}

static rl_status input_object_pixels(void *user, rl_vec3 p, uint32_t *pixels)
{
    approx_input *in = user;
    if (!in->visibility) {
        rl_status st = make_visibility(in->scene, in->resolution, in->threads, &in->visibility);
        if (st != RL_OK)
            return st;
    }
    return rl_property_object_pixels(in->visibility, 0, p, pixels);
}

static void input_release(void *user)
{
    approx_input *in = user;
    if (!in)
        return;
    rl_approx_release(in->approx);
    rl_property_release(in->visibility);
    free(in);
}

/* A lookup over a; with scene set it also offers the visible pixels per
 * object (a visibility property of resolution² pixels per cube face). */
static rl_status make_lookup(rl_approx *a, const rl_scene *scene, uint32_t resolution, int threads,
                             rl_position_lookup *out)
{
    approx_input *in = rl_calloc(1, sizeof *in);
    if (!in)
        return RL_ERR_OUT_OF_MEMORY;
    *in = (approx_input){ .approx = a, .scene = scene, .resolution = resolution, .threads = threads };
    *out = (rl_position_lookup){
        .user = in,
        .property = rl_approx_property(a),
        .set_size = rl_approx_set_size(a),
        .num_regions = rl_approx_region_count(a),
        .query = input_query,
        .region_set = input_region_set,
        .region_center = input_region_center,
        .object_pixels = scene ? input_object_pixels : NULL,
        .release = input_release,
    };
    return RL_OK;
}

rl_status rl_approx_lookup(rl_approx *a, rl_position_lookup *out)
{
    if (!a || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_lookup: approximation and out must not be NULL");
    return make_lookup(a, NULL, 0, 0, out);
}

/* The options that say how an input is sampled (visset and select name
 * them alike). */
typedef struct sample_opts {
    uint32_t samples, resolution;
    int dims, threads;
    float height;
    uint64_t seed;
} sample_opts;

static sample_opts read_sample_opts(const rl_renderer *r)
{
    return (sample_opts){
        .samples = (uint32_t)rl_renderer_opt_int(r, "samples"),
        .resolution = (uint32_t)rl_renderer_opt_int(r, "resolution"),
        .dims = (int)rl_renderer_opt_int(r, "dims"),
        .threads = (int)rl_renderer_opt_int(r, "threads"),
        .height = (float)rl_renderer_opt_float(r, "height"),
        .seed = (uint64_t)rl_renderer_opt_int(r, "seed"),
    };
}

/* Samples property p over the scene's bounds as o says: a 2-D slice at
 * height above the scene's lowest point, or the 3-D bounds. */
static rl_status sample_over_scene(rl_property *p, const rl_scene *scene, const sample_opts *o, rl_approx **out)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    rl_sampling_desc sd = { .region = d->bounds, .dims = o->dims, .max_samples = o->samples, .seed = o->seed };
    sd.height = d->bounds.min.y + o->height;
    return rl_sample_property(p, &sd, out);
}

/* Sec. 4.2.3: the conditioned time property of renderer `name` (with its
 * default options; the forwarded raster options change little of its
 * time), coarse and quick: a default for a first look, rl eval's files are
 * the real measurement. 2 unmeasured frames, then 1 measured. */
static rl_status sample_time(const rl_scene *scene, const sample_opts *o, const char *name, rl_approx **out)
{
    rl_property *p = NULL;
    char res[32];
    snprintf(res, sizeof res, "%u", o->resolution);
    rl_status st = rl_property_create("time", &p);
    if (st == RL_OK) st = rl_property_set(p, "renderer", name);
    if (st == RL_OK) st = rl_property_set(p, "width", res);
    if (st == RL_OK) st = rl_property_set(p, "height", res);
    if (st == RL_OK) st = rl_property_set(p, "repeats", "1");
    if (st == RL_OK) st = rl_property_set(p, "conditioned", "true");
    if (st == RL_OK) st = rl_property_set(p, "condition_frames", "2");
    if (st == RL_OK) st = rl_property_commit(p, scene, 0);
    if (st == RL_OK)
        st = sample_over_scene(p, scene, o, out);
    rl_property_release(p);
    return st;
}

/* What an input is made from, as text: the same key means the same
 * lookup, so a second call skips the work. */
static void input_key(char *key, size_t size, const rl_scene *scene, const char *what, const char *path,
                      const sample_opts *o)
{
    if (path[0])
        snprintf(key, size, "scene %llu; %s; file %s", (unsigned long long)rl_scene_uid(scene), what, path);
    else
        snprintf(key, size, "scene %llu; %s; sampled %u x %u px, dims %d, height %.9g, seed %llu",
                 (unsigned long long)rl_scene_uid(scene), what, o->samples, o->resolution, o->dims,
                 (double)o->height, (unsigned long long)o->seed);
}

/* How an input is sampled when no file names it. */
typedef rl_status (*sample_fn)(const rl_scene *scene, const sample_opts *o, const char *name, rl_approx **out);

/* Loads path, or samples with sample(), and hands the lookup to slot; skips
 * both when the slot already holds a lookup of the same key. With
 * object_pixels (visset) the file's sets must be the scene's objects: a
 * file of another scene is refused before its sets are allocated. */
static rl_status set_input(rl_renderer *r, const char *slot, const rl_scene *scene, const char *what,
                           const char *path, const sample_opts *o, sample_fn sample, bool object_pixels)
{
    char key[1024];
    input_key(key, sizeof key, scene, what, path, o);
    const char *have = rl_renderer_input_key(r, slot);
    if (have && strcmp(have, key) == 0)
        return RL_OK;
    rl_timer t;
    rl_timer_start(&t);
    rl_approx *a = NULL;
    uint32_t sets = object_pixels ? rl_scene_get_data(scene)->num_objects : RL_APPROX_ANY_SET_SIZE;
    rl_status st = path[0] ? rl_approx_load_json_sets(path, sets, &a) : sample(scene, o, what, &a);
    rl_position_lookup l;
    if (st == RL_OK)
        st = make_lookup(a, object_pixels ? scene : NULL, o->resolution, o->threads, &l);
    if (st != RL_OK) {
        rl_approx_release(a);
        return st;
    }
    l.prepare_ms = rl_timer_ms(&t);
    st = rl_renderer_set_input(r, slot, &l, key);
    if (st != RL_OK)
        input_release(l.user);
    return st;
}

static rl_status sample_visibility(const rl_scene *scene, const sample_opts *o, const char *what, rl_approx **out)
{
    (void)what;
    rl_property *p = NULL;
    rl_status st = make_visibility(scene, o->resolution, o->threads, &p);
    if (st == RL_OK)
        st = sample_over_scene(p, scene, o, out);
    rl_property_release(p);
    return st;
}

/* visset (Sec. 7.6): the visible sets, from `approx` or sampled. */
static rl_status prepare_visset(rl_renderer *r, const rl_scene *scene)
{
    sample_opts o = read_sample_opts(r);
    return set_input(r, "approx", scene, "visibility", rl_renderer_opt_string(r, "approx"), &o, sample_visibility,
                     true);
}

/* select (Sec. 7.5): both renderers' times (rule=time), from first_time /
 * second_time or sampled, or the property of rule=threshold. */
static rl_status prepare_select(rl_renderer *r, const rl_scene *scene)
{
    sample_opts o = read_sample_opts(r);
    if (strcmp(rl_renderer_get(r, "rule"), "threshold") == 0) {
        const char *path = rl_renderer_opt_string(r, "property");
        if (!path[0])   /* the renderer says what is missing */
            return RL_OK;
        return set_input(r, "property", scene, "threshold property", path, &o, sample_time, false);
    }
    const char *names[2] = { "first", "second" }, *slots[2] = { "first_time", "second_time" };
    for (int i = 0; i < 2; ++i) {
        const char *name = rl_renderer_opt_string(r, names[i]);
        /* Refused before any sampling, as select refuses them: itself, and
         * renderers that read inputs select does not hand on. */
        if (strcmp(name, "select") == 0)
            return rl_error(RL_ERR_INVALID_ARG, "select: %s=select would select itself", names[i]);
        rl_renderer *probe = NULL;
        rl_status st = rl_renderer_create(name, &probe);
        size_t inputs = 0;
        rl_renderer_input_slots(probe, &inputs);
        rl_renderer_release(probe);
        if (st == RL_OK && inputs)
            st = rl_error(RL_ERR_INVALID_ARG, "select: %s=%s reads measured inputs, which select does not hand on",
                          names[i], name);
        if (st != RL_OK)
            return st;
        st = set_input(r, slots[i], scene, name, rl_renderer_opt_string(r, slots[i]), &o, sample_time, false);
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

rl_status rl_renderer_prepare_inputs(rl_renderer *r, const rl_scene *scene)
{
    if (!r || !scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_prepare_inputs: renderer and scene must not be NULL");
    size_t slots = 0;
    rl_renderer_input_slots(r, &slots);
    if (!slots)
        return RL_OK;
    if (!rl_scene_is_committed(scene))
        return rl_error(RL_ERR_NOT_COMMITTED, "%s: the scene must be committed before its inputs are sampled",
                        rl_renderer_name(r));
    const char *name = rl_renderer_name(r);
    if (strcmp(name, "visset") == 0)
        return prepare_visset(r, scene);
    if (strcmp(name, "select") == 0)
        return prepare_select(r, scene);
    return rl_error(RL_ERR_UNSUPPORTED, "%s: no way known to prepare its inputs", name);
}
