/* renderer.h: how an algorithm plugs into the rl_renderer interface.
 *
 * A renderer provides one rl_renderer_class: its name, its option table, the
 * size of its state and its functions, so that a new renderer is only its
 * algorithm. The generic layer (renderer.c) validates and stores option
 * values as text; an implementation reads them typed with rl_renderer_opt_*.
 * All built-in classes are listed once, in registry.c; classes from outside
 * the library join them there through rl_renderer_register(). */
#ifndef RL_RENDER_RENDERER_H
#define RL_RENDER_RENDERER_H

#include "rl/rl_render.h"

typedef struct rl_renderer_class {
    rl_renderer_info info;
    const rl_option_info *options;
    size_t num_options;
    /* Bytes of the implementation's state: the generic layer allocates it
     * zeroed on create and frees it after release (0: no state). */
    size_t state_size;
    /* Renders; stats is zeroed by the caller, time_ms is filled by the caller. */
    rl_status (*render)(rl_renderer *r, void *state, const rl_scene *scene,
                        const rl_camera *cam, rl_image *image, rl_render_stats *stats);
    /* Optional: frees what the state holds, not the state itself. */
    void (*release)(void *state);
    /* Optional extra check of a value that already passed the type check
     * (e.g. a colour in a string option); NULL: none. Records and returns
     * RL_ERR_INVALID_ARG for a bad value. */
    rl_status (*check)(const char *key, const char *value);
    /* Optional: forget frame-to-frame state, keep per-scene preprocessing
     * (rl_renderer_reset); NULL: the renderer keeps none. */
    void (*reset)(void *state);
    /* Optional: whether r can render here (rl_renderer_available), the
     * reason into why (n bytes) if not; NULL: always. */
    bool (*available)(const rl_renderer *r, char *why, size_t n);
    /* Optional lookup inputs (rl_renderer_set_input), by slot name. */
    const char *const *inputs;
    size_t num_inputs;
    /* Optional, for classes with regions: the whole-image passes that a
     * region render leaves out while they are deferred
     * (rl_renderer_defer_whole_passes), run once on the assembled image;
     * samples are the frame's samples over all its regions. */
    rl_status (*finish_regions)(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                                rl_image *image, uint64_t samples);
    /* Optional, GL renderers (rl_renderer_set_gl_output): texture output
     * on or off, and the last frame's texture handed over (false: the
     * last render wrote the image instead, or it was taken). NULL: the
     * renderer's frames exist only as rl_images. */
    void (*gl_output)(void *state, bool on);
    bool (*take_gl_frame)(void *state, rl_gl_frame *out);
} rl_renderer_class;

/* At most this many input slots per class. */
#define RL_RENDERER_MAX_INPUTS 4

/* registry.c: the classes, built-ins first, then those registered with
 * rl_renderer_register() (rl_render.h). The class of name, or NULL. */
const rl_renderer_class *rl_renderer_find_class(const char *name);
/* The names of all classes, ", "-separated, into buf (cut when full): for
 * the message of an unknown name. */
void rl_renderer_class_names(char *buf, size_t size);

/* The typed option reads rl_renderer_opt_* are public (rl_render.h), for
 * renderers written outside the library too. RL_OPT_COLOR values: "r,g,b"
 * or a single grey value, finite and >= 0. rl_renderer_parse_color() only
 * parses (no error recorded); the option read returns black for a value
 * that does not parse. */
bool rl_renderer_parse_color(const char *text, rl_vec3 *out);
/* The implementation's state made by its class's create(), for accessors
 * of a renderer's own (e.g. rl_whitted_pixel_tree). */
void *rl_renderer_state(const rl_renderer *r);
/* All of r's option values as one string "key=value;..." (rl_alloc'd; NULL
 * when out of memory), leaving out option i where keep(r, i) is false (keep
 * NULL: none left out). The accumulating renderers restart when it
 * changes. */
char *rl_renderer_option_signature(const rl_renderer *r, bool (*keep)(const rl_renderer *r, size_t i));
/* The part of a width x height image to render (rl_renderer_set_region;
 * checked against the image by rl_renderer_render): the whole image when
 * none was set. Only classes with info.regions read it. */
rl_rect rl_renderer_region(const rl_renderer *r, int width, int height);
/* A distributed frame (src/dist) renders its image as regions on several
 * ranks. Passes over the whole image (pt's filter, Schröder Sec. 8.2)
 * cannot run on a region: while deferred, a class with finish_regions
 * leaves them out of its region renders instead of refusing them, and
 * rl_renderer_finish_regions runs them on the assembled image (RL_OK and
 * nothing done for a class without). */
void rl_renderer_defer_whole_passes(rl_renderer *r, bool defer);
bool rl_renderer_whole_passes_deferred(const rl_renderer *r);
rl_status rl_renderer_finish_regions(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                                     uint64_t samples);
/* The callback of rl_renderer_set_progress (NULLs when none), for a caller
 * that renders a frame in parts and reports the whole (src/dist). */
void rl_renderer_get_progress(const rl_renderer *r, rl_progress_fn *fn, void **user);
/* The lookup in slot (NULL when none was handed in) and how often the slot
 * was set, so that a renderer can tell a new lookup from the one it built
 * its per-region data for. */
const rl_position_lookup *rl_renderer_input(const rl_renderer *r, const char *slot, uint64_t *generation);
/* A lookup must hold the property its renderer reads (select's times,
 * visset's visible sets): the sets or values of any other would be read as
 * if they were. RL_ERR_INVALID_ARG "<renderer>: <file or slot> holds the
 * property 'p', not <want>". */
rl_status rl_renderer_check_input_property(const rl_renderer *r, const char *slot, const rl_position_lookup *l,
                                           const char *want);

#endif
