/* property_internal.h: how a property plugs into rl_property (rl_property.h).
 *
 * A property kind provides one rl_property_class: its name, its option table
 * and a few functions, like a renderer's rl_renderer_class (renderer.h). The
 * generic layer (property.c) validates and stores option values as text,
 * checks every argument of rl_property_evaluate() and keeps outputs
 * untouched on failure; a class only computes. Built-in classes are listed
 * once, in property.c. */
#ifndef RL_EVAL_PROPERTY_INTERNAL_H
#define RL_EVAL_PROPERTY_INTERNAL_H

#include "rl/rl_property.h"

/* What a class's evaluate() fills. set points to per-worker scratch of
 * rl_property_set_words() words (all of them to be written) or is NULL when
 * the caller does not want the set; direction[] starts as NAN. */
typedef struct rl_property_result {
    double value;
    uint64_t *set;
    double direction[6];
} rl_property_result;

typedef struct rl_property_class {
    rl_property_info info;
    const rl_option_info *options;
    size_t num_options;
    /* Unit and flags may depend on the options (measure, metric). */
    const char *(*unit)(const rl_property *p);
    unsigned (*flags)(const rl_property *p);
    /* Optional extra check of a value that passed the type check (e.g. a
     * renderer name); records and returns the error. NULL: none. */
    rl_status (*check)(const char *key, const char *value);
    /* Builds the committed state for scene (already checked: committed,
     * non-empty, unless the class accepts NULL) and workers >= 1; sets
     * *set_size (0: no set). On failure *state is left alone. */
    rl_status (*commit)(rl_property *p, const rl_scene *scene, int workers, void **state,
                        uint32_t *set_size);
    /* Computes one sample on `worker` (in range, pos finite). */
    rl_status (*evaluate)(rl_property *p, void *state, int worker, rl_vec3 pos,
                          rl_property_result *out);
    void (*release)(void *state);           /* committed state; NULL-safe */
    void (*release_impl)(void *impl);       /* per-instance data; may be NULL */
    /* Scene may be NULL at commit (custom properties whose commit says so). */
    bool accepts_null_scene;
} rl_property_class;

/* Built-in classes (property_visibility.c, property_render.c). */
extern const rl_property_class rl_property_visibility_class;
extern const rl_property_class rl_property_time_class;
extern const rl_property_class rl_property_ops_class;
extern const rl_property_class rl_property_quality_class;

/* Option values for implementations (validated on set, frozen by commit). */
const char *rl_property_opt(const rl_property *p, const char *key);
long long rl_property_opt_int(const rl_property *p, const char *key);
double rl_property_opt_float(const rl_property *p, const char *key);
bool rl_property_opt_bool(const rl_property *p, const char *key);
int rl_property_opt_enum(const rl_property *p, const char *key);
/* Per-instance data of a custom or combined property (NULL for built-ins). */
void *rl_property_impl(const rl_property *p);

/* property_visibility.c: the per-object pixel counts behind
 * rl_property_object_pixels (state is the visibility class's). */
rl_status rl_property_visibility_pixels(rl_property *p, void *state, int worker, rl_vec3 pos,
                                        uint32_t *pixels_per_object);

/* property_render.c: the time property's rule (Jähn 2015, Sec. 4.2.3, Def.
 * 6) on frames from callbacks, so that tests can script frame times. */
typedef struct rl_time_frames {
    /* Renders direction (0..5) once; *ms its time. */
    rl_status (*render)(void *ctx, int direction, double *ms);
    void (*reset)(void *ctx);               /* rl_renderer_reset */
    void *ctx;
} rl_time_frames;

typedef struct rl_time_rule {
    int repeats;                /* measured frames per direction, >= 1 */
    bool conditioned;
    int condition_frames;       /* conditioned: at most this many unmeasured frames */
} rl_time_rule;

/* One sample: unless *built, an unmeasured frame of direction 0, a reset,
 * and *built = true (the build for the scene is not a frame's time); then
 * per direction, conditioned: unmeasured frames until one is not 2 % faster
 * than the one before (at most condition_frames), unconditioned: a reset
 * before every measured frame; the median of `repeats` measured frames.
 * direction[i] gets the medians, *value their maximum. scratch holds
 * `repeats` doubles. */
rl_status rl_time_measure(const rl_time_frames *f, const rl_time_rule *rule, bool *built,
                          double *scratch, double direction[6], double *value);

#endif
