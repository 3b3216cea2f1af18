/* rl_render.h: the pluggable renderer interface.
 *
 * Every algorithm in renderlab (raster, whitted, vt, pt, chcpp, svs, visset,
 * surfels, select; rl_renderer_list) is an rl_renderer created by name from
 * one registry, configured with validated key/value options, and run as
 *     render(scene, camera, image, stats)
 * so that the evaluator can time and compare any of them. Options are typed
 * (int, float, bool, enum, string, colour) and checked on rl_renderer_set(); unknown
 * keys and malformed values fail with RL_ERR_INVALID_ARG and a message that
 * lists what is accepted.
 *
 * Renderers of your own: rl_renderer_register() adds a class described by
 * an rl_renderer_class_desc to the same registry, after the built-ins. It
 * is then listed, created by name and measured like any built-in (by the
 * properties of rl_property.h, by rl_sample_property, by a program's own
 * comparison): see examples/custom_renderer.c. */
#ifndef RL_RENDER_H
#define RL_RENDER_H

#include "rl/rl_camera.h"
#include "rl/rl_common.h"
#include "rl/rl_gl.h"
#include "rl/rl_image.h"
#include "rl/rl_options.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rl_ray_type {
    RL_RAY_PRIMARY = 0,
    RL_RAY_SHADOW,
    RL_RAY_REFLECTION,
    RL_RAY_REFRACTION,
    RL_RAY_DIFFUSE,
    RL_RAY_TYPE_COUNT
} rl_ray_type;
RL_API const char *rl_ray_type_name(rl_ray_type type);

typedef struct rl_render_stats {
    double time_ms;                       /* wall time of render(), prep_ms included */
    /* Of time_ms, the one-time preparation: building what the renderer
     * keeps for the scene (BVH or grid, Line Space, shadow map, octree,
     * surfels, SVS's sets, select's second renderer); 0 on frames that
     * reuse it. The frame's own time is time_ms - prep_ms. Inputs made by
     * rl_renderer_prepare_inputs() (rl_sampling.h) are made before
     * render() and are not in either. */
    double prep_ms;
    uint64_t rays[RL_RAY_TYPE_COUNT];     /* traced rays by type */
    uint64_t triangles_rasterized;        /* triangles set up by a rasterizer */
    uint64_t pixels_written;              /* fragments/pixels written */
    uint64_t samples;                     /* shading samples (e.g. spp * pixels) */
    uint64_t occlusion_queries;           /* rasterizer occlusion queries issued */
    uint64_t points_drawn;                /* point primitives rasterized (surfels) */
    /* The GPU that drew the frame (GL renderers: "vendor | renderer |
     * version" of their context), NULL for the CPU renderers; owned by
     * the renderer, valid until it renders again or is released. */
    const char *device;
} rl_render_stats;


typedef struct rl_renderer rl_renderer;

typedef struct rl_renderer_info {
    const char *name;
    const char *description;
    const char *reference;                /* paper, or "" */
    /* Progressive: every render() from the same camera adds to what the
     * earlier ones accumulated (pt: more samples per pixel) until
     * rl_renderer_reset() or a change restarts it, so a caller improves the
     * image by rendering again. A caller that loops over frames (rl render
     * --time) refuses to loop a renderer that is not progressive. */
    bool progressive;
    /* Progressive renderers: the time budget in seconds that a caller with
     * no budget of its own should spend, one that gives a clean-enough
     * image of a small scene at about 512 x 512 on a few cores; 0: one
     * frame, as for the others. */
    double default_time_s;
    /* Bytes per pixel of the frame buffers the renderer allocates beyond
     * the caller's image (accumulation, G-buffer, scratch depth), so that a
     * caller can estimate a frame's memory before allocating it
     * (rl_renderer_frame_bytes); 0: none. */
    double frame_bytes_per_pixel;
    /* Regions: the renderer can render a part of the image
     * (rl_renderer_set_region) with exactly the pixels a whole frame gives
     * there, because every pixel depends only on its own position, the
     * camera, the scene and the options; a distributed run (rl_dist.h)
     * hands such a renderer's image out in parts. */
    bool regions;
} rl_renderer_info;

RL_API const rl_renderer_info *rl_renderer_list(size_t *count);
/* Estimated bytes of the renderer's own buffers for a width x height frame
 * (info.frame_bytes_per_pixel per pixel; the image is the caller's:
 * rl_image_bytes). 0 for NULL. */
RL_API double rl_renderer_frame_bytes(const rl_renderer *r, int width, int height);
/* RL_ERR_NOT_FOUND for an unknown name (the message lists the known ones). */
RL_API rl_status rl_renderer_create(const char *name, rl_renderer **out);
RL_API void rl_renderer_release(rl_renderer *r);
RL_API const char *rl_renderer_name(const rl_renderer *r);
/* Whether r can render on this machine and build: false (with the reason
 * in why, cut to n bytes; why may be NULL) for a GL renderer where no GL
 * 4.5 context can be made on its device. rl_renderer_render() of an
 * unavailable renderer fails with RL_ERR_UNSUPPORTED and that reason. */
RL_API bool rl_renderer_available(const rl_renderer *r, char *why, size_t n);
RL_API const rl_option_info *rl_renderer_options(const rl_renderer *r, size_t *count);
/* Validates and stores one option. key may carry the renderer's name as a
 * prefix ("raster.shading"). */
RL_API rl_status rl_renderer_set(rl_renderer *r, const char *key, const char *value);
/* Current value as text (the default if never set); NULL for unknown keys. */
RL_API const char *rl_renderer_get(const rl_renderer *r, const char *key);
/* Forgets what the renderer carried over from earlier frames (temporal
 * coherence, accumulated samples, culling state) but keeps what it built
 * for the scene (acceleration structures, Line Spaces, shadow maps): the
 * next frame is rendered as if it were the first from its camera. This is
 * the "unconditioned" state of Jähn 2015, Sec. 4.2.3. NULL is a no-op. */
RL_API void rl_renderer_reset(rl_renderer *r);
/* A part of the image: the pixels x0 <= x < x1, y0 <= y < y1. */
typedef struct rl_rect {
    int x0, y0, x1, y1;
} rl_rect;
/* Restricts the following renders to region (NULL: the whole image, the
 * default): the pixels inside it are rendered as a whole frame renders
 * them, the image's other pixels are left as they are, and the stats count
 * the region's work. A region must be non-empty and lie within the image
 * at render time (RL_ERR_INVALID_ARG there). RL_ERR_UNSUPPORTED for a
 * renderer without info.regions. */
RL_API rl_status rl_renderer_set_region(rl_renderer *r, const rl_rect *region);
/* Inputs measured elsewhere. A renderer that draws from a measured
 * position-dependent property (visset: the sets of visible objects of
 * Jähn 2015, Sec. 7.6; select: a time or another scalar per position,
 * Sec. 7.5) reads it through this lookup and never samples or loads it
 * itself: renderers sit below the evaluation layer. The caller builds the
 * lookup, usually from a sampled approximation: rl_renderer_prepare_inputs()
 * (rl_sampling.h) loads or samples what the renderer's options ask for and
 * hands it in, and the CLI calls it for every renderer it creates. A test
 * or an application may hand in a lookup of its own. */
typedef struct rl_position_lookup {
    void *user;
    const char *property;         /* what was measured ("visibility", "time", ...) */
    uint32_t set_size;            /* bits of each region's set (one per object); 0: no sets */
    uint32_t num_regions;
    double prepare_ms;            /* loading or sampling it: reported as the renderer's preprocessing */
    /* False where p lies outside what the lookup covers (a 2-D slice covers
     * its x-z extent at any height); else the value at p and its region. */
    bool (*query)(void *user, rl_vec3 p, double *value, uint32_t *region);
    /* Region i's set (set_size bits, 64 per word, object o in bit o % 64 of
     * word o / 64); NULL where there is none. */
    const uint64_t *(*region_set)(void *user, uint32_t region);
    rl_vec3 (*region_center)(void *user, uint32_t region);
    /* Optional (NULL: not offered): the visible pixels of each of the
     * set_size objects seen from p, into pixels. */
    rl_status (*object_pixels)(void *user, rl_vec3 p, uint32_t *pixels);
    void (*release)(void *user);  /* frees user; may be NULL */
} rl_position_lookup;

/* The lookup inputs ("slots") of r, named after the option that names
 * their file (visset: "approx"; select: "first_time", "second_time",
 * "property"); count 0 for renderers that read none. */
RL_API const char *const *rl_renderer_input_slots(const rl_renderer *r, size_t *count);
/* Hands lookup to r's slot (NULL clears it); on success r owns lookup->user
 * and calls lookup->release when the slot is replaced or r released; on
 * failure the caller still owns it. key (may be NULL) is kept for
 * rl_renderer_input_key: whoever prepares inputs says what they were made
 * from, so that it can skip work that is already done. RL_ERR_INVALID_ARG
 * for an unknown slot or a lookup without query. */
RL_API rl_status rl_renderer_set_input(rl_renderer *r, const char *slot, const rl_position_lookup *lookup,
                                       const char *key);
/* The key given with the slot's lookup; NULL when the slot is empty. */
RL_API const char *rl_renderer_input_key(const rl_renderer *r, const char *slot);
/* Optional progress callback for long renders. */
RL_API void rl_renderer_set_progress(rl_renderer *r, rl_progress_fn fn, void *user);
/* Renders the committed scene from cam into image, which must match the
 * camera's resolved resolution and have at least RL_LAYER_COLOR. stats may
 * be NULL; otherwise it is overwritten. */
RL_API rl_status rl_renderer_render(rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                                    rl_image *image, rl_render_stats *stats);

/* GL renderers' frames as textures (docs/gl.md, "Sharing with a window").
 *
 * rl_renderer_set_gl_output(r, true), after rl_gl_share_with (rl_gl.h),
 * keeps r's frames on the GPU: a successful render copies the frame's
 * colour into a new texture of the caller's share group with a fence and
 * does not write the image's colour layer (the other layers are written
 * as before; the colour layer may be cleared to the background on the way).
 * rl_renderer_take_gl_frame then hands that texture over (rl_gl_frame: the
 * caller owns it, waits on the fence before sampling and deletes both).
 * A frame the renderer finishes on the CPU writes the image as without
 * texture output and offers no texture: gl-pt with a filter, or on the
 * first frame of a checkerboard accumulation (half its pixels are filled
 * in from their neighbours). A texture not taken is deleted by the next
 * frame or the release. false turns it off (the default): frames are read
 * back into the image, as always.
 *
 * RL_ERR_UNSUPPORTED for a renderer without GL frames (every CPU renderer)
 * and, for true, where the GL backend does not share with the caller;
 * RL_ERR_NOT_FOUND from take where no texture waits (output off, taken,
 * the frame went to the image, or the render failed). */
RL_API rl_status rl_renderer_set_gl_output(rl_renderer *r, bool texture);
RL_API rl_status rl_renderer_take_gl_frame(rl_renderer *r, rl_gl_frame *out);

/* A renderer class written outside the library (rl_renderer_register).
 * The built-ins are described the same way inside src/render/. */
typedef struct rl_renderer_class_desc {
    /* name: required, 1..31 characters of [A-Za-z0-9_-] (it is written
     * "name:key=value" and "name.key" on command lines), unique among all
     * renderers. description and reference may be NULL (""). */
    rl_renderer_info info;
    /* The option table, typed and checked as for the built-ins (may be NULL
     * with num_options 0); read the values in render() with
     * rl_renderer_opt_*. Borrowed, not copied: it must stay valid for as
     * long as the library is used (a static table, as the built-ins'). */
    const rl_option_info *options;
    size_t num_options;
    /* Bytes of per-renderer state, allocated zeroed by rl_renderer_create()
     * and freed after release (0: no state, state is NULL). */
    size_t state_size;
    /* Required. Called by rl_renderer_render() after its checks: the scene
     * is committed, cam is resolved and valid, image matches cam's
     * resolution and has a colour layer; stats is zeroed and its time_ms
     * filled by the caller. Fill the counters that apply. Record failures
     * with a status (and, where useful, a message the caller can read: any
     * failing rl_* call has already recorded one). */
    rl_status (*render)(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                        rl_image *image, rl_render_stats *stats);
    /* Optional: frees what state holds (not state itself). */
    void (*release)(void *state);
    /* Optional: forgets frame-to-frame state (rl_renderer_reset). */
    void (*reset)(void *state);
    /* Optional: an extra check of a value that already passed its row's
     * type and range check; return RL_ERR_INVALID_ARG to refuse it. */
    rl_status (*check)(const char *key, const char *value);
} rl_renderer_class_desc;

/* At most this many classes can be registered besides the built-ins. */
#define RL_RENDERER_MAX_REGISTERED 32

/* Adds a renderer class to the registry: from now on rl_renderer_list()
 * lists it (after the built-ins, in registration order) and
 * rl_renderer_create() makes it by name, for every caller in the process.
 * desc and its strings are copied; the option table is borrowed (above).
 * Classes cannot be removed. Safe to call from any thread; a renderer
 * created concurrently by the new name may or may not find it.
 * RL_ERR_INVALID_ARG: NULL desc or render, a missing or malformed name, a
 * name already taken (built-in or registered), a progressive class's
 * default_time_s outside [0, 86400], an option row without a key
 * or whose default does not pass its own check. RL_ERR_LIMIT after
 * RL_RENDERER_MAX_REGISTERED classes. Nothing is registered on failure. */
RL_API rl_status rl_renderer_register(const rl_renderer_class_desc *desc);

/* For render() implementations: the current value of an option of r's
 * table, typed (values were validated when set; defaults when never set).
 * A key that is not in the table reads as 0, 0.0, false, choice 0, "" or
 * black: a mistake in the implementation, not in the user's input. */
RL_API long long rl_renderer_opt_int(const rl_renderer *r, const char *key);
RL_API double rl_renderer_opt_float(const rl_renderer *r, const char *key);
RL_API bool rl_renderer_opt_bool(const rl_renderer *r, const char *key);
RL_API int rl_renderer_opt_enum(const rl_renderer *r, const char *key);   /* choice index */
RL_API const char *rl_renderer_opt_string(const rl_renderer *r, const char *key);
RL_API rl_vec3 rl_renderer_opt_color(const rl_renderer *r, const char *key);
/* For long render() implementations: reports done in [0, 1] to the
 * callback of rl_renderer_set_progress(); false means the caller cancels
 * (return RL_ERR_CANCELLED then). True when no callback is set. */
RL_API bool rl_renderer_progress(const rl_renderer *r, double done);

#ifdef __cplusplus
}
#endif
#endif
