/* renderer.c: the generic rl_renderer layer shared by every algorithm.
 *
 * Creates renderers by name from the registry (registry.c, which also
 * lists them and registers classes from outside the library), keeps option
 * values as validated text (so that get() returns exactly what was set and a
 * renderer's options can be listed and reproduced in reports), and wraps the
 * class's render() with the checks every algorithm needs: committed scene,
 * valid camera, an image that matches the camera, zeroed and timed stats. */
#include "render/renderer.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/options.h"
#include "core/threads.h"
#include "gl/gl_context.h"
#include "rl/rl_timer.h"

struct rl_renderer {
    const rl_renderer_class *cls;
    void *state;
    rl_option_store options;    /* the class's table and this renderer's values */
    rl_progress_fn progress;
    void *progress_user;
    /* Lookup inputs per slot of the class (rl_renderer_set_input). */
    struct renderer_input {
        rl_position_lookup lookup;
        bool set;
        char *key;
        uint64_t generation;
    } inputs[RL_RENDERER_MAX_INPUTS];
    rl_rect region;             /* rl_renderer_set_region */
    bool has_region;
    bool defer_whole;           /* rl_renderer_defer_whole_passes */
};

static void clear_input(struct renderer_input *in)
{
    if (in->set && in->lookup.release)
        in->lookup.release(in->lookup.user);
    free(in->key);
    in->key = NULL;
    in->set = false;
    memset(&in->lookup, 0, sizeof in->lookup);
}

void *rl_renderer_state(const rl_renderer *r) { return r ? r->state : NULL; }

char *rl_renderer_option_signature(const rl_renderer *r, bool (*keep)(const rl_renderer *r, size_t i))
{
    const rl_option_info *opts = r->cls->options;
    size_t len = 1;
    for (size_t i = 0; i < r->cls->num_options; ++i)
        if (!keep || keep(r, i))
            len += strlen(opts[i].key) + strlen(rl_renderer_get(r, opts[i].key)) + 2;
    char *sig = rl_alloc(len);
    if (!sig)
        return NULL;
    sig[0] = '\0';
    size_t used = 0;
    for (size_t i = 0; i < r->cls->num_options; ++i)
        if (!keep || keep(r, i))
            used += (size_t)snprintf(sig + used, len - used, "%s=%s;", opts[i].key, rl_renderer_get(r, opts[i].key));
    return sig;
}

rl_status rl_renderer_set_region(rl_renderer *r, const rl_rect *region)
{
    if (!r)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_set_region: renderer is NULL");
    if (region && !r->cls->info.regions)
        return rl_error(RL_ERR_UNSUPPORTED, "%s: renders whole images only (no regions)", r->cls->info.name);
    if (region && (region->x0 < 0 || region->y0 < 0 || region->x1 <= region->x0 || region->y1 <= region->y0))
        return rl_error(RL_ERR_INVALID_ARG, "%s: region [%d,%d)x[%d,%d) is empty or negative", r->cls->info.name,
                        region->x0, region->x1, region->y0, region->y1);
    r->has_region = region != NULL;
    if (region)
        r->region = *region;
    return RL_OK;
}

void rl_renderer_defer_whole_passes(rl_renderer *r, bool defer)
{
    if (r)
        r->defer_whole = defer && r->cls->finish_regions;
}

bool rl_renderer_whole_passes_deferred(const rl_renderer *r) { return r && r->defer_whole; }

rl_status rl_renderer_finish_regions(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                                     uint64_t samples)
{
    if (!r || !r->cls->finish_regions)
        return RL_OK;
    return r->cls->finish_regions(r, r->state, scene, cam, image, samples);
}

rl_rect rl_renderer_region(const rl_renderer *r, int width, int height)
{
    if (!r || !r->has_region)
        return (rl_rect){ 0, 0, width, height };
    return r->region;
}

const char *rl_ray_type_name(rl_ray_type type)
{
    static const char *const names[RL_RAY_TYPE_COUNT] = {
        "primary", "shadow", "reflection", "refraction", "diffuse"
    };
    return (unsigned)type < RL_RAY_TYPE_COUNT ? names[type] : "unknown";
}

rl_status rl_renderer_create(const char *name, rl_renderer **out)
{
    if (!name || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_create: name and out must not be NULL");
    const rl_renderer_class *cls = rl_renderer_find_class(name);
    if (!cls) {
        char names[RL_OPTION_LIST_SIZE], hint[96];
        rl_renderer_class_names(names, sizeof names);
        rl_suggestion sg = { 0 };
        size_t count = 0;
        const rl_renderer_info *infos = rl_renderer_list(&count);
        for (size_t i = 0; i < count; ++i)
            rl_suggest(&sg, name, infos[i].name);
        return rl_error(RL_ERR_NOT_FOUND, "unknown algorithm \"%s\" (%savailable: %s)", name,
                        rl_option_did_you_mean(&sg, hint, sizeof hint), names);
    }

    rl_renderer *r = rl_calloc(1, sizeof *r);
    if (!r)
        return RL_ERR_OUT_OF_MEMORY;
    r->cls = cls;
    rl_status st = rl_option_store_init(&r->options, cls->options, cls->num_options, cls->info.name);
    if (st != RL_OK) {
        free(r);
        return st;
    }
    if (cls->state_size && !(r->state = rl_calloc(1, cls->state_size))) {
        rl_option_store_free(&r->options);
        free(r);
        return RL_ERR_OUT_OF_MEMORY;
    }
    *out = r;
    return RL_OK;
}

void rl_renderer_release(rl_renderer *r)
{
    if (!r)
        return;
    if (r->cls->release && r->state)
        r->cls->release(r->state);
    free(r->state);
    for (size_t i = 0; i < RL_RENDERER_MAX_INPUTS; ++i)
        clear_input(&r->inputs[i]);
    rl_option_store_free(&r->options);
    free(r);
}

const char *const *rl_renderer_input_slots(const rl_renderer *r, size_t *count)
{
    if (count)
        *count = r ? r->cls->num_inputs : 0;
    return r ? r->cls->inputs : NULL;
}

static long find_input(const rl_renderer *r, const char *slot)
{
    for (size_t i = 0; slot && i < r->cls->num_inputs && i < RL_RENDERER_MAX_INPUTS; ++i)
        if (strcmp(r->cls->inputs[i], slot) == 0)
            return (long)i;
    return -1;
}

rl_status rl_renderer_set_input(rl_renderer *r, const char *slot, const rl_position_lookup *lookup,
                                const char *key)
{
    if (!r || !slot)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_set_input: renderer and slot must not be NULL");
    long i = find_input(r, slot);
    if (i < 0) {
        if (!r->cls->num_inputs)
            return rl_error(RL_ERR_INVALID_ARG, "%s: reads no measured inputs (slot \"%s\")", r->cls->info.name,
                            slot);
        char names[RL_OPTION_LIST_SIZE] = "";
        for (size_t k = 0; k < r->cls->num_inputs; ++k) {
            if (k)
                rl_option_append(names, sizeof names, ", ");
            rl_option_append(names, sizeof names, r->cls->inputs[k]);
        }
        return rl_error(RL_ERR_INVALID_ARG, "%s: unknown input \"%s\" (inputs: %s)", r->cls->info.name, slot,
                        names);
    }
    if (lookup && !lookup->query)
        return rl_error(RL_ERR_INVALID_ARG, "%s: input %s: the lookup has no query function", r->cls->info.name,
                        slot);
    char *copy = NULL;
    if (lookup && key && !(copy = rl_strdup(key)))
        return RL_ERR_OUT_OF_MEMORY;
    struct renderer_input *in = &r->inputs[i];
    clear_input(in);
    if (lookup) {
        in->lookup = *lookup;
        in->set = true;
        in->key = copy;
    }
    in->generation++;
    return RL_OK;
}

const char *rl_renderer_input_key(const rl_renderer *r, const char *slot)
{
    long i = r ? find_input(r, slot) : -1;
    if (i < 0 || !r->inputs[i].set)
        return NULL;
    return r->inputs[i].key ? r->inputs[i].key : "";
}

const rl_position_lookup *rl_renderer_input(const rl_renderer *r, const char *slot, uint64_t *generation)
{
    long i = find_input(r, slot);
    if (generation)
        *generation = i < 0 ? 0 : r->inputs[i].generation;
    return i >= 0 && r->inputs[i].set ? &r->inputs[i].lookup : NULL;
}

rl_status rl_renderer_check_input_property(const rl_renderer *r, const char *slot, const rl_position_lookup *l,
                                           const char *want)
{
    const char *have = l->property ? l->property : "";
    if (strcmp(have, want) == 0)
        return RL_OK;
    const char *file = rl_renderer_get(r, slot);
    return rl_error(RL_ERR_INVALID_ARG, "%s: %s holds the property '%s', not %s", rl_renderer_name(r),
                    file && file[0] ? file : slot, have, want);
}

const char *rl_renderer_name(const rl_renderer *r) { return r ? r->cls->info.name : NULL; }

double rl_renderer_frame_bytes(const rl_renderer *r, int width, int height)
{
    return r ? (double)width * (double)height * r->cls->info.frame_bytes_per_pixel : 0.0;
}

const rl_option_info *rl_renderer_options(const rl_renderer *r, size_t *count)
{
    if (count)
        *count = r ? r->cls->num_options : 0;
    return r ? r->cls->options : NULL;
}

rl_status rl_renderer_set(rl_renderer *r, const char *key, const char *value)
{
    if (!r || !key || !value)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_set: renderer, key and value must not be NULL");
    rl_status st = rl_option_store_set(&r->options, key, value, r->cls->info.name, r->cls->check);
    /* OpenMP exits the process when it cannot start a thread, so the
     * count is clamped here, where every renderer reads it from. */
    const char *dot = strrchr(key, '.');
    if (st != RL_OK || strcmp(dot ? dot + 1 : key, "threads") != 0)
        return st;
    long long asked = rl_option_store_int(&r->options, "threads");
    char clamped[32];
    int most = rl_threads_clamp(asked > INT_MAX ? INT_MAX : (int)asked, r->cls->info.name);
    if (most == asked)
        return RL_OK;
    snprintf(clamped, sizeof clamped, "%d", most);
    return rl_option_store_set(&r->options, "threads", clamped, r->cls->info.name, r->cls->check);
}

rl_status rl_renderer_set_gl_output(rl_renderer *r, bool texture)
{
    if (!r)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_set_gl_output: NULL renderer");
    if (!r->cls->gl_output)
        return rl_error(RL_ERR_UNSUPPORTED, "%s: no GL frame texture (only the GL renderers have one)",
                        r->cls->info.name);
    if (texture && !rl_gl_share_active())
        return rl_error(RL_ERR_UNSUPPORTED, "%s: a GL frame texture needs a context shared with the caller's "
                        "(rl_gl_share_with)", r->cls->info.name);
    r->cls->gl_output(r->state, texture);
    return RL_OK;
}

rl_status rl_renderer_take_gl_frame(rl_renderer *r, rl_gl_frame *out)
{
    if (!r || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_take_gl_frame: NULL argument");
    if (!r->cls->take_gl_frame)
        return rl_error(RL_ERR_UNSUPPORTED, "%s: no GL frame texture (only the GL renderers have one)",
                        r->cls->info.name);
    if (!r->cls->take_gl_frame(r->state, out))
        return rl_error(RL_ERR_NOT_FOUND, "%s: no GL frame waiting (texture output off, taken already, or the "
                        "last frame went to the image)", r->cls->info.name);
    return RL_OK;
}

void rl_renderer_reset(rl_renderer *r)
{
    if (r && r->cls->reset)
        r->cls->reset(r->state);
}

const char *rl_renderer_get(const rl_renderer *r, const char *key)
{
    return r && key ? rl_option_store_get(&r->options, key) : NULL;
}

void rl_renderer_set_progress(rl_renderer *r, rl_progress_fn fn, void *user)
{
    if (!r)
        return;
    r->progress = fn;
    r->progress_user = user;
}

void rl_renderer_get_progress(const rl_renderer *r, rl_progress_fn *fn, void **user)
{
    *fn = r ? r->progress : NULL;
    *user = r ? r->progress_user : NULL;
}

bool rl_renderer_progress(const rl_renderer *r, double done)
{
    return !r || !r->progress || r->progress(r->progress_user, done);
}

/* Typed reads (options.h). Values were validated on set and defaults are
 * trusted, so a failed parse means a wrong key in an implementation. */
long long rl_renderer_opt_int(const rl_renderer *r, const char *key)
{
    return rl_option_store_int(&r->options, key);
}

double rl_renderer_opt_float(const rl_renderer *r, const char *key)
{
    return rl_option_store_float(&r->options, key);
}

bool rl_renderer_opt_bool(const rl_renderer *r, const char *key)
{
    return rl_option_store_bool(&r->options, key);
}

int rl_renderer_opt_enum(const rl_renderer *r, const char *key)
{
    return rl_option_store_enum(&r->options, key);
}

const char *rl_renderer_opt_string(const rl_renderer *r, const char *key)
{
    return rl_option_store_string(&r->options, key);
}

bool rl_renderer_parse_color(const char *text, rl_vec3 *out)
{
    return rl_option_parse_color(text, out);
}

rl_vec3 rl_renderer_opt_color(const rl_renderer *r, const char *key)
{
    return rl_option_store_color(&r->options, key);
}

bool rl_renderer_available(const rl_renderer *r, char *why, size_t n)
{
    if (why && n)
        why[0] = '\0';
    if (!r)
        return false;
    return !r->cls->available || r->cls->available(r, why, n);
}

rl_status rl_renderer_render(rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                             rl_image *image, rl_render_stats *stats)
{
    if (!r || !scene || !cam || !image)
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_renderer_render: renderer, scene, camera and image must not be NULL");
    const char *name = r->cls->info.name;
    if (!rl_scene_is_committed(scene))
        return rl_error(RL_ERR_NOT_COMMITTED, "%s: the scene must be committed before rendering", name);
    rl_camera resolved = rl_camera_resolve(cam);
    rl_status st = rl_camera_validate(&resolved);
    if (st != RL_OK)
        return st;
    if (!(image->layers & RL_LAYER_COLOR) || !image->color)
        return rl_error(RL_ERR_INVALID_ARG, "%s: the image has no colour layer", name);
    if (image->width != resolved.width || image->height != resolved.height)
        return rl_error(RL_ERR_INVALID_ARG, "%s: image is %dx%d but the camera renders %dx%d",
                        name, image->width, image->height, resolved.width, resolved.height);

    if (r->has_region && (r->region.x1 > image->width || r->region.y1 > image->height))
        return rl_error(RL_ERR_INVALID_ARG, "%s: region [%d,%d)x[%d,%d) lies outside the %dx%d image", name,
                        r->region.x0, r->region.x1, r->region.y0, r->region.y1, image->width, image->height);

    char why[256];
    if (!rl_renderer_available(r, why, sizeof why))
        return rl_error(RL_ERR_UNSUPPORTED, "%s: unavailable: %s", name, why);

    rl_render_stats local;
    memset(&local, 0, sizeof local);
    rl_timer timer;
    rl_timer_start(&timer);
    st = r->cls->render(r, r->state, scene, &resolved, image, &local);
    local.time_ms = rl_timer_ms(&timer);
    if (st != RL_OK)
        return st;
    if (stats)
        *stats = local;
    return RL_OK;
}
