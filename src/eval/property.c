/* property.c: the generic rl_property layer (rl_property.h), position-
 * dependent scene properties after Jähn 2015, Ch. 4 (Def. 1: a function of
 * the viewer position in a scene).
 *
 * Creates built-in properties by name from one list (visibility, time, ops,
 * quality), keeps their options as validated text (the same typed tables
 * and messages as renderers, src/core/options.h), binds a committed scene
 * and a worker count on commit, and wraps every evaluation with the checks
 * the classes then need not repeat: committed, worker in range, finite
 * position. A class writes its set into per-worker scratch, copied to the
 * caller only on success, so that outputs stay untouched on failure.
 *
 * Also here: combined properties (Sec. 4.2.6: a - b, a / b, min, max at the
 * same position) and custom properties (callbacks), which plug in as two
 * more classes with per-instance data. */
#include "eval/property_internal.h"

#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/options.h"

/* More workers than this is a mistake, not a machine. */
#define MAX_WORKERS 4096

struct rl_property {
    const rl_property_class *cls;
    char *name;
    rl_option_store options;    /* the class's table and this property's values */
    void *impl;                 /* custom / combined data, or NULL */
    void *state;                /* committed state, or NULL */
    bool committed;
    int workers;
    uint32_t set_size;
    size_t set_words;
    uint64_t *scratch;          /* workers * set_words, or NULL */
};

static const rl_property_class *const builtin_classes[] = {
    &rl_property_visibility_class,
    &rl_property_time_class,
    &rl_property_ops_class,
    &rl_property_quality_class,
};
enum { NUM_BUILTINS = sizeof builtin_classes / sizeof builtin_classes[0] };

const rl_property_info *rl_property_list(size_t *count)
{
    /* The infos live in the classes; the public list wants them contiguous. */
    static rl_property_info infos[NUM_BUILTINS];
    static bool built;
#pragma omp critical(rl_property_list)
    {
        if (!built) {
            for (size_t i = 0; i < NUM_BUILTINS; ++i)
                infos[i] = builtin_classes[i]->info;
            built = true;
        }
    }
    if (count)
        *count = NUM_BUILTINS;
    return infos;
}

/* A property of class cls with default option values; impl is attached by
 * the caller. */
static rl_status make(const rl_property_class *cls, const char *name, rl_property **out)
{
    rl_property *p = rl_calloc(1, sizeof *p);
    if (!p)
        return RL_ERR_OUT_OF_MEMORY;
    p->cls = cls;
    p->name = rl_strdup(name);
    rl_status st = p->name ? rl_option_store_init(&p->options, cls->options, cls->num_options, cls->info.name)
                           : RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        free(p->name);
        free(p);
        return st;
    }
    *out = p;
    return RL_OK;
}

rl_status rl_property_create(const char *name, rl_property **out)
{
    if (!name || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_property_create: name and out must not be NULL");
    for (size_t i = 0; i < NUM_BUILTINS; ++i)
        if (strcmp(builtin_classes[i]->info.name, name) == 0)
            return make(builtin_classes[i], name, out);
    char names[RL_OPTION_LIST_SIZE] = "", hint[96];
    rl_suggestion sg = { 0 };
    for (size_t i = 0; i < NUM_BUILTINS; ++i) {
        if (i)
            rl_option_append(names, sizeof names, ", ");
        rl_option_append(names, sizeof names, builtin_classes[i]->info.name);
        rl_suggest(&sg, name, builtin_classes[i]->info.name);
    }
    return rl_error(RL_ERR_NOT_FOUND, "unknown property \"%s\" (%savailable: %s)", name,
                    rl_option_did_you_mean(&sg, hint, sizeof hint), names);
}

static void unbind(rl_property *p)
{
    if (p->cls->release)
        p->cls->release(p->state);
    free(p->scratch);
    p->state = NULL;
    p->scratch = NULL;
    p->committed = false;
    p->workers = 0;
    p->set_size = 0;
    p->set_words = 0;
}

void rl_property_release(rl_property *p)
{
    if (!p)
        return;
    unbind(p);
    if (p->cls->release_impl)
        p->cls->release_impl(p->impl);
    rl_option_store_free(&p->options);
    free(p->name);
    free(p);
}

const char *rl_property_name(const rl_property *p) { return p ? p->name : NULL; }

const char *rl_property_unit(const rl_property *p)
{
    if (!p)
        return NULL;
    return p->cls->unit ? p->cls->unit(p) : "";
}

unsigned rl_property_get_flags(const rl_property *p)
{
    return p && p->cls->flags ? p->cls->flags(p) : 0u;
}

const rl_option_info *rl_property_options(const rl_property *p, size_t *count)
{
    if (count)
        *count = p ? p->cls->num_options : 0;
    return p && p->cls->num_options ? p->cls->options : NULL;
}

rl_status rl_property_set(rl_property *p, const char *key, const char *value)
{
    if (!p || !key || !value)
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_property_set: property, key and value must not be NULL");
    if (p->committed && rl_option_store_find(&p->options, key) >= 0)
        return rl_error(RL_ERR_INVALID_ARG,
                        "%s: option %s cannot change after commit (create a new property)",
                        p->name, key);
    return rl_option_store_set(&p->options, key, value, p->name, p->cls->check);
}

const char *rl_property_get(const rl_property *p, const char *key)
{
    return p && key ? rl_option_store_get(&p->options, key) : NULL;
}

const char *rl_property_opt(const rl_property *p, const char *key)
{
    const char *s = rl_property_get(p, key);
    return s ? s : "";
}

long long rl_property_opt_int(const rl_property *p, const char *key)
{
    return p ? rl_option_store_int(&p->options, key) : 0;
}

double rl_property_opt_float(const rl_property *p, const char *key)
{
    return p ? rl_option_store_float(&p->options, key) : 0.0;
}

bool rl_property_opt_bool(const rl_property *p, const char *key)
{
    return p && rl_option_store_bool(&p->options, key);
}

int rl_property_opt_enum(const rl_property *p, const char *key)
{
    return p ? rl_option_store_enum(&p->options, key) : 0;
}

void *rl_property_impl(const rl_property *p) { return p ? p->impl : NULL; }

rl_status rl_property_commit(rl_property *p, const rl_scene *scene, int workers)
{
    if (!p)
        return rl_error(RL_ERR_INVALID_ARG, "rl_property_commit: property is NULL");
    if (workers < 0 || workers > MAX_WORKERS)
        return rl_error(RL_ERR_INVALID_ARG, "%s: workers %d outside [0, %d]", p->name, workers,
                        MAX_WORKERS);
    if (!scene && !p->cls->accepts_null_scene)
        return rl_error(RL_ERR_INVALID_ARG, "%s: the scene is NULL", p->name);
    if (scene && !rl_scene_is_committed(scene))
        return rl_error(RL_ERR_NOT_COMMITTED,
                        "%s: the scene must be committed before the property", p->name);
    if (workers == 0)
        workers = omp_get_max_threads() > 0 ? omp_get_max_threads() : 1;

    void *state = NULL;
    uint32_t set_size = 0;
    rl_status st = p->cls->commit(p, scene, workers, &state, &set_size);
    if (st != RL_OK)
        return st;
    size_t words = ((size_t)set_size + 63) / 64;
    uint64_t *scratch = NULL;
    if (words) {
        scratch = rl_calloc((size_t)workers * words, sizeof *scratch);
        if (!scratch) {
            if (p->cls->release)
                p->cls->release(state);
            return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: set scratch for %d workers", p->name,
                            workers);
        }
    }
    unbind(p);
    p->state = state;
    p->scratch = scratch;
    p->workers = workers;
    p->set_size = set_size;
    p->set_words = words;
    p->committed = true;
    return RL_OK;
}

int rl_property_workers(const rl_property *p) { return p && p->committed ? p->workers : 0; }

uint32_t rl_property_set_size(const rl_property *p) { return p && p->committed ? p->set_size : 0; }

size_t rl_property_set_words(const rl_property *p) { return p && p->committed ? p->set_words : 0; }

/* The checks evaluate and object_pixels share. */
static rl_status check_call(const char *fn, const rl_property *p, int worker, rl_vec3 pos,
                            const void *out)
{
    if (!p || !out)
        return rl_error(RL_ERR_INVALID_ARG, "%s: property and output must not be NULL", fn);
    if (!p->committed)
        return rl_error(RL_ERR_NOT_COMMITTED, "%s: commit the property before evaluating it",
                        p->name);
    if (worker < 0 || worker >= p->workers)
        return rl_error(RL_ERR_INVALID_ARG, "%s: worker %d outside [0, %d)", p->name, worker,
                        p->workers);
    if (!rl_vfinite(pos))
        return rl_error(RL_ERR_INVALID_ARG, "%s: position (%g, %g, %g) is not finite", p->name,
                        (double)pos.x, (double)pos.y, (double)pos.z);
    return RL_OK;
}

rl_status rl_property_evaluate(rl_property *p, int worker, rl_vec3 pos, rl_property_sample *out)
{
    rl_status st = check_call("rl_property_evaluate", p, worker, pos, out);
    if (st != RL_OK)
        return st;
    rl_property_result r;
    r.value = NAN;
    r.set = out->set && p->set_words ? p->scratch + (size_t)worker * p->set_words : NULL;
    for (int i = 0; i < 6; ++i)
        r.direction[i] = NAN;
    st = p->cls->evaluate(p, p->state, worker, pos, &r);
    if (st != RL_OK)
        return st;
    out->value = r.value;
    memcpy(out->direction, r.direction, sizeof out->direction);
    if (r.set)
        memcpy(out->set, r.set, p->set_words * sizeof *out->set);
    return RL_OK;
}

void rl_property_direction(int i, rl_vec3 *dir, rl_vec3 *up)
{
    /* Jähn 2015, Sec. 4.2.2: the six faces of a cube around the viewer.
     * Horizontal views keep y up; the vertical ones take a horizontal up
     * (-z looking up, +z looking down) so that every frame is orthonormal. */
    static const float dirs[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 },
                                      { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
    static const float ups[6][3] = { { 0, 1, 0 }, { 0, 1, 0 }, { 0, 0, -1 },
                                     { 0, 0, 1 }, { 0, 1, 0 }, { 0, 1, 0 } };
    bool ok = i >= 0 && i < 6;
    if (dir)
        *dir = ok ? rl_v3(dirs[i][0], dirs[i][1], dirs[i][2]) : rl_v3s(0.0f);
    if (up)
        *up = ok ? rl_v3(ups[i][0], ups[i][1], ups[i][2]) : rl_v3s(0.0f);
}

rl_status rl_property_object_pixels(rl_property *p, int worker, rl_vec3 pos,
                                    uint32_t *pixels_per_object)
{
    if (p && p->cls != &rl_property_visibility_class)
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_property_object_pixels: %s is not a visibility property", p->name);
    rl_status st = check_call("rl_property_object_pixels", p, worker, pos, pixels_per_object);
    if (st != RL_OK)
        return st;
    return rl_property_visibility_pixels(p, p->state, worker, pos, pixels_per_object);
}

/* ---- combined properties (Jähn 2015, Sec. 4.2.6) ----------------------- */

typedef struct combined {
    rl_property_op op;
    rl_property *a, *b;
} combined;

static const char *const op_names[] = { "difference", "ratio", "min", "max" };

static const char *combined_unit(const rl_property *p)
{
    const combined *c = p->impl;
    /* a / b has no unit; the others keep a's */
    return c->op == RL_PROPERTY_RATIO ? "" : rl_property_unit(c->a);
}

static unsigned combined_flags(const rl_property *p)
{
    const combined *c = p->impl;
    return rl_property_get_flags(c->a) | rl_property_get_flags(c->b);
}

static rl_status combined_commit(rl_property *p, const rl_scene *scene, int workers,
                                 void **state, uint32_t *set_size)
{
    combined *c = p->impl;
    rl_status st = rl_property_commit(c->a, scene, workers);
    if (st == RL_OK)
        st = rl_property_commit(c->b, scene, workers);
    if (st != RL_OK)
        return st;
    *state = NULL;
    *set_size = rl_property_set_size(c->a);
    return RL_OK;
}

static double combine(rl_property_op op, double a, double b)
{
    if (isnan(a) || isnan(b))
        return NAN;
    switch (op) {
    case RL_PROPERTY_DIFFERENCE: return a - b;
    case RL_PROPERTY_RATIO: return b == 0.0 ? NAN : a / b;
    case RL_PROPERTY_MIN: return a < b ? a : b;
    case RL_PROPERTY_MAX: return a > b ? a : b;
    }
    return NAN;
}

static rl_status combined_evaluate(rl_property *p, void *state, int worker, rl_vec3 pos,
                                   rl_property_result *out)
{
    (void)state;
    combined *c = p->impl;
    rl_property_sample sa, sb;
    memset(&sa, 0, sizeof sa);
    memset(&sb, 0, sizeof sb);
    sa.set = out->set;          /* the set is a's (rl_property.h) */
    rl_status st = rl_property_evaluate(c->a, worker, pos, &sa);
    if (st == RL_OK)
        st = rl_property_evaluate(c->b, worker, pos, &sb);
    if (st != RL_OK)
        return st;
    /* Sec. 4.2.6: both values come from the same position; per direction
     * they are combined direction by direction, but the reduced values may
     * stem from different directions. */
    out->value = combine(c->op, sa.value, sb.value);
    for (int i = 0; i < 6; ++i)
        out->direction[i] = combine(c->op, sa.direction[i], sb.direction[i]);
    return RL_OK;
}

static void combined_release_impl(void *impl)
{
    combined *c = impl;
    if (!c)
        return;
    rl_property_release(c->a);
    rl_property_release(c->b);
    free(c);
}

static const rl_property_class combined_class = {
    .info = { "combined", "a - b, a / b, min(a, b) or max(a, b) of two properties",
              "Jähn 2015, Sec. 4.2.6" },
    .unit = combined_unit,
    .flags = combined_flags,
    .commit = combined_commit,
    .evaluate = combined_evaluate,
    .release_impl = combined_release_impl,
    .accepts_null_scene = true,         /* a and b check the scene themselves */
};

rl_status rl_property_create_combined(rl_property_op op, rl_property *a, rl_property *b,
                                      rl_property **out)
{
    rl_status st = RL_OK;
    if (!a || !b || !out)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_property_create_combined: a, b and out must not be NULL");
    else if (a == b)
        st = rl_error(RL_ERR_INVALID_ARG,
                      "rl_property_create_combined: a and b must be two properties (one is "
                      "evaluated by both workers' calls otherwise)");
    else if ((unsigned)op > RL_PROPERTY_MAX)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_property_create_combined: unknown operation %d",
                      (int)op);
    combined *c = NULL;
    char *name = NULL;
    if (st == RL_OK) {
        const char *an = rl_property_name(a), *bn = rl_property_name(b);
        size_t len = strlen(op_names[op]) + strlen(an) + strlen(bn) + 5;
        c = rl_calloc(1, sizeof *c);
        name = rl_alloc(len);
        if (!c || !name)
            st = RL_ERR_OUT_OF_MEMORY;
        else
            snprintf(name, len, "%s(%s, %s)", op_names[op], an, bn);
    }
    rl_property *p = NULL;
    if (st == RL_OK)
        st = make(&combined_class, name, &p);
    free(name);
    if (st != RL_OK) {
        /* rl_property.h: ownership passes even when this call fails */
        free(c);
        rl_property_release(a);
        if (b != a)
            rl_property_release(b);
        return st;
    }
    c->op = op;
    c->a = a;
    c->b = b;
    p->impl = c;
    *out = p;
    return RL_OK;
}

/* ---- custom properties ------------------------------------------------- */

typedef struct custom {
    rl_property_callbacks cb;
    void *user;
    char *unit;
} custom;

static const char *custom_unit(const rl_property *p) { return ((const custom *)p->impl)->unit; }

static unsigned custom_flags(const rl_property *p)
{
    return ((const custom *)p->impl)->cb.flags &
           (unsigned)(RL_PROPERTY_EXCLUSIVE | RL_PROPERTY_HIGHER_IS_BETTER);
}

static rl_status custom_commit(rl_property *p, const rl_scene *scene, int workers, void **state,
                               uint32_t *set_size)
{
    custom *c = p->impl;
    uint32_t size = 0;
    if (c->cb.commit) {
        rl_status st = c->cb.commit(c->user, scene, workers, &size);
        if (st != RL_OK)    /* keeps the callback's own message if it recorded one */
            return rl_error(st, "%s: the commit callback failed", p->name);
    }
    *state = NULL;
    *set_size = size;
    return RL_OK;
}

static rl_status custom_evaluate(rl_property *p, void *state, int worker, rl_vec3 pos,
                                 rl_property_result *out)
{
    (void)state;
    custom *c = p->impl;
    double value = NAN;
    rl_status st = c->cb.evaluate(c->user, worker, pos, &value, out->set);
    if (st != RL_OK)        /* keeps the callback's own message if it recorded one */
        return rl_error(st, "%s: the evaluate callback failed", p->name);
    out->value = value;
    return RL_OK;
}

static void custom_release_impl(void *impl)
{
    custom *c = impl;
    if (!c)
        return;
    if (c->cb.release)
        c->cb.release(c->user);
    free(c->unit);
    free(c);
}

static const rl_property_class custom_class = {
    .info = { "custom", "a property given by callbacks", "" },
    .unit = custom_unit,
    .flags = custom_flags,
    .commit = custom_commit,
    .evaluate = custom_evaluate,
    .release_impl = custom_release_impl,
    .accepts_null_scene = true,         /* the commit callback decides */
};

rl_status rl_property_create_custom(const rl_property_callbacks *cb, void *user,
                                    rl_property **out)
{
    if (!cb || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_property_create_custom: callbacks and out must not be NULL");
    if (!cb->name || !cb->name[0] || !cb->evaluate)
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_property_create_custom: a name and an evaluate callback are required");
    custom *c = rl_calloc(1, sizeof *c);
    char *unit = rl_strdup(cb->unit ? cb->unit : "");
    rl_property *p = NULL;
    rl_status st = c && unit ? make(&custom_class, cb->name, &p) : RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        free(c);
        free(unit);
        return st;
    }
    c->cb = *cb;
    c->cb.name = p->name;       /* the caller's strings need not outlive the call */
    c->cb.unit = unit;
    c->user = user;
    c->unit = unit;
    p->impl = c;
    *out = p;
    return RL_OK;
}
