/* registry.c: the one list of renderer classes (pbrt-style create-by-name).
 *
 * A new built-in algorithm adds its class to `builtins` here and nowhere
 * else. Classes written outside the library join after the built-ins
 * through rl_renderer_register(); rl_renderer_list() and
 * rl_renderer_create() see both, in that order.
 *
 * Registration may happen while other threads list or create renderers, so
 * every access to the table goes through one critical section. Entries are
 * only ever appended and never move, so a class pointer or a row of
 * rl_renderer_list() handed out earlier stays valid. */
#include "render/renderer.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/options.h"

/* Each class is defined in the file named after its algorithm. */
extern const rl_renderer_class rl_raster_renderer_class;     /* raster.c */
extern const rl_renderer_class rl_gl_raster_renderer_class;  /* gl_raster.c */
extern const rl_renderer_class rl_gl_pt_renderer_class;      /* gl_pathtrace.c */
extern const rl_renderer_class rl_whitted_renderer_class;    /* whitted.c */
extern const rl_renderer_class rl_vt_renderer_class;         /* vt.c */
extern const rl_renderer_class rl_pt_renderer_class;         /* pathtrace.c */
extern const rl_renderer_class rl_bdpt_renderer_class;       /* bdpt.c */
extern const rl_renderer_class rl_chcpp_renderer_class;      /* chcpp.c */
extern const rl_renderer_class rl_svs_renderer_class;        /* svs.c */
extern const rl_renderer_class rl_visset_renderer_class;     /* visset.c */
extern const rl_renderer_class rl_surfels_renderer_class;    /* surfels.c */
extern const rl_renderer_class rl_select_renderer_class;     /* select.c */

static const rl_renderer_class *const builtins[] = {
    &rl_raster_renderer_class,
    &rl_gl_raster_renderer_class,
    &rl_gl_pt_renderer_class,
    &rl_whitted_renderer_class,
    &rl_vt_renderer_class,
    &rl_pt_renderer_class,
    &rl_bdpt_renderer_class,
    &rl_chcpp_renderer_class,
    &rl_svs_renderer_class,
    &rl_visset_renderer_class,
    &rl_surfels_renderer_class,
    &rl_select_renderer_class,
};
enum {
    NUM_BUILTINS = sizeof builtins / sizeof builtins[0],
    MAX_CLASSES = NUM_BUILTINS + RL_RENDERER_MAX_REGISTERED,
    MAX_NAME = 31,
};

/* The registered classes own copies of their strings (the desc's may be a
 * caller's buffers); the option tables are borrowed, as documented. */
static struct registered {
    rl_renderer_class cls;
    char name[MAX_NAME + 1];
    char *description, *reference;
} registered[RL_RENDERER_MAX_REGISTERED];

/* All classes in order, and their infos side by side for rl_renderer_list(),
 * which hands out a contiguous array. Filled with the built-ins on first use. */
static const rl_renderer_class *classes[MAX_CLASSES];
static rl_renderer_info infos[MAX_CLASSES];
static size_t num_classes;

/* Call inside the critical section. */
static void init_builtins(void)
{
    if (num_classes)
        return;
    for (size_t i = 0; i < NUM_BUILTINS; ++i) {
        classes[i] = builtins[i];
        infos[i] = builtins[i]->info;
    }
    num_classes = NUM_BUILTINS;
}

static const rl_renderer_class *find_locked(const char *name)
{
    for (size_t i = 0; i < num_classes; ++i)
        if (strcmp(classes[i]->info.name, name) == 0)
            return classes[i];
    return NULL;
}

const rl_renderer_info *rl_renderer_list(size_t *count)
{
    size_t n;
#pragma omp critical(rl_renderer_registry)
    {
        init_builtins();
        n = num_classes;
    }
    if (count)
        *count = n;
    return infos;
}

const rl_renderer_class *rl_renderer_find_class(const char *name)
{
    const rl_renderer_class *cls;
#pragma omp critical(rl_renderer_registry)
    {
        init_builtins();
        cls = find_locked(name);
    }
    return cls;
}

void rl_renderer_class_names(char *buf, size_t size)
{
    if (!size)
        return;
    buf[0] = '\0';
#pragma omp critical(rl_renderer_registry)
    {
        init_builtins();
        for (size_t i = 0; i < num_classes; ++i) {
            if (i)
                rl_option_append(buf, size, ", ");
            rl_option_append(buf, size, classes[i]->info.name);
        }
    }
}

/* The name is written "name:key=value" (rl compare --algos) and "name.key"
 * (prefixed option keys), so it may not contain those separators. */
static bool valid_name(const char *name)
{
    size_t n = strlen(name);
    if (n == 0 || n > MAX_NAME)
        return false;
    for (size_t i = 0; i < n; ++i) {
        char c = name[i];
        bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                  c == '-';
        if (!ok)
            return false;
    }
    return true;
}

/* Every row's default must pass its own type, range and extra check, so
 * that a renderer's options are valid before anyone sets one (the typed
 * reads trust them). Run through the same store that renderers use. */
static rl_status check_options(const rl_renderer_class_desc *desc)
{
    if (desc->num_options && !desc->options)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_register: %s: num_options is %zu but options is NULL",
                        desc->info.name, desc->num_options);
    for (size_t i = 0; i < desc->num_options; ++i)
        if (!desc->options[i].key || !desc->options[i].key[0])
            return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_register: %s: option row %zu has no key",
                            desc->info.name, i);
    rl_option_store store;
    rl_status st = rl_option_store_init(&store, desc->options, desc->num_options, desc->info.name);
    for (size_t i = 0; st == RL_OK && i < desc->num_options; ++i) {
        const rl_option_info *o = &desc->options[i];
        st = rl_option_store_set(&store, o->key, o->default_value ? o->default_value : "", desc->info.name,
                                 desc->check);
        if (st != RL_OK)
            rl_error(st, "rl_renderer_register: %s: the default of option \"%s\" is not valid", desc->info.name,
                     o->key);
    }
    rl_option_store_free(&store);
    return st;
}

rl_status rl_renderer_register(const rl_renderer_class_desc *desc)
{
    if (!desc || !desc->render)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_register: desc and its render function must not be NULL");
    const char *name = desc->info.name;
    if (!name || !valid_name(name))
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_renderer_register: name \"%s\" must be 1 to %d characters of A-Z, a-z, 0-9, _ and -",
                        name ? name : "(null)", MAX_NAME);
    /* A budget is a wait the caller imposes on its user: a day bounds a typo. */
    if (desc->info.progressive && !(desc->info.default_time_s >= 0.0 && desc->info.default_time_s <= 86400.0))
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_register: %s: default_time_s must be in [0, 86400] s",
                        name);
    rl_status st = check_options(desc);
    if (st != RL_OK)
        return st;
    char *description = rl_strdup(desc->info.description ? desc->info.description : "");
    char *reference = rl_strdup(desc->info.reference ? desc->info.reference : "");
    if (!description || !reference) {
        free(description);
        free(reference);
        return RL_ERR_OUT_OF_MEMORY;
    }

    /* The checks that depend on what is registered already and the append
     * are one step, so that two threads cannot take the same name. */
    enum { ADDED, TAKEN, FULL } outcome;
#pragma omp critical(rl_renderer_registry)
    {
        init_builtins();
        size_t k = num_classes - NUM_BUILTINS;
        if (find_locked(name)) {
            outcome = TAKEN;
        } else if (k >= RL_RENDERER_MAX_REGISTERED) {
            outcome = FULL;
        } else {
            struct registered *reg = &registered[k];
            memcpy(reg->name, name, strlen(name) + 1);
            reg->description = description;
            reg->reference = reference;
            reg->cls = (rl_renderer_class){
                .info = { .name = reg->name, .description = description, .reference = reference,
                          .progressive = desc->info.progressive,
                          .default_time_s = desc->info.progressive ? desc->info.default_time_s : 0.0,
                          .frame_bytes_per_pixel = desc->info.frame_bytes_per_pixel },
                .options = desc->num_options ? desc->options : NULL,
                .num_options = desc->num_options,
                .state_size = desc->state_size,
                .render = desc->render,
                .release = desc->release,
                .check = desc->check,
                .reset = desc->reset,
            };
            classes[num_classes] = &reg->cls;
            infos[num_classes] = reg->cls.info;
            num_classes++;
            outcome = ADDED;
        }
    }
    if (outcome == ADDED)
        return RL_OK;
    free(description);
    free(reference);
    if (outcome == TAKEN)
        return rl_error(RL_ERR_INVALID_ARG, "rl_renderer_register: a renderer named \"%s\" exists already", name);
    return rl_error(RL_ERR_LIMIT, "rl_renderer_register: %s: at most %d renderers can be registered", name,
                    RL_RENDERER_MAX_REGISTERED);
}
