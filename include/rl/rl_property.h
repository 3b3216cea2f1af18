/* rl_property.h: position-dependent scene properties (Jähn 2015, Ch. 4).
 *
 * A property maps a viewer position in a committed scene to a value
 * (Def. 1): the number of visible objects, the rendering time of an
 * algorithm, the image quality of an approximate algorithm against a
 * reference, an operation count, or a combination of two properties. The
 * viewer is omnidirectional: every built-in property looks in the six
 * directions of a cube around the position (+x, -x, +y, -y, +z, -z) and
 * reduces the six per-direction values to one (Sec. 4.2.2-4.2.5).
 *
 * Besides its scalar value a property may produce a set: a bit vector over
 * the scene's objects (bit i of word i / 64 = object i), e.g. the set of
 * visible objects (Def. 5). rl_property_set_size() says how many bits; 0
 * means the property has no set.
 *
 * Usage:
 *     rl_property *p;
 *     rl_property_create("visibility", &p);
 *     rl_property_set(p, "resolution", "256");
 *     rl_property_commit(p, scene, 0);               // binds the scene
 *     rl_property_sample s = {0};
 *     rl_property_evaluate(p, 0, (rl_vec3){0, 1.7f, 0}, &s);
 *     rl_property_release(p);
 *
 * Built-in properties (options are typed and validated like a renderer's,
 * with rl_option_info; keys may carry the property's name as a prefix):
 *   visibility  Pixel visibility (Sec. 4.2.2, Def. 4/5): the scene is
 *               rasterized into 6 cube faces (90° frusta, resolution²
 *               pixels each, default 1024 as in the thesis, 1..4096) with
 *               object IDs; an object is visible when it owns at least one
 *               pixel. The value is `measure` = objects (count, default),
 *               polygons (triangles of the visible objects) or pixels
 *               (visible pixels of all objects); direction[i] is the same
 *               measure for face i alone; the set is the visible objects.
 *               The far plane encloses the scene. Options: resolution,
 *               near (near-plane distance, m, default 0.1), measure,
 *               threads (per worker's rasterizer; 0 = all threads for a
 *               single worker, 1 each when several workers are committed),
 *               backend (software, default, or gl: the six faces drawn by
 *               OpenGL 4.5 and counted on the GPU, one GL context shared
 *               by the workers; commit fails with RL_ERR_UNSUPPORTED and
 *               the reason where no context can be made; see docs/gl.md),
 *               device (backend gl's EGL device, as rl_gl.h).
 *   time        Rendering time of a renderer (Sec. 4.2.3, Def. 6), ms:
 *               per direction the median of `repeats` (default 5) renders
 *               with a `fov_deg` (default 120) frustum into width x height
 *               (default 256 x 256) pixels, then the maximum over the
 *               directions. Unconditioned (default): the renderer is
 *               reset (rl_renderer_reset) before every measured frame, so
 *               no state of earlier frames is reused, while what it built
 *               for the scene (BVH, Line Space) is kept; each worker's
 *               renderer draws one unmeasured frame before its first
 *               measured one, so that building for the scene is never
 *               timed. Conditioned: the worker's renderer is kept and
 *               up to `condition_frames` (default 10) unmeasured frames
 *               come first, stopping after the first frame that is not 2 %
 *               faster than the one before. Options: renderer (default
 *               raster), renderer_options ("key=value,..." passed to
 *               rl_renderer_set; commas separate items, so a colour
 *               option takes one grey value), width, height, fov_deg, repeats,
 *               conditioned, condition_frames, threads (the renderer's
 *               threads; 0 = all). Flagged RL_PROPERTY_EXCLUSIVE.
 *   ops         An operation count of a renderer (Sec. 4.2.4): `counter` =
 *               triangles (rasterized), rays (all types), primary_rays,
 *               shadow_rays, secondary_rays (reflection + refraction +
 *               diffuse), pixels, samples, occlusion_queries, points or
 *               primitives (triangles + points), reduced over
 *               the directions by `reduce` = max (default) or sum;
 *               direction[i] holds the count of direction i. Options as
 *               for time, minus repeats/conditioning; the worker's
 *               renderer is kept between frames. threads = 0 means one
 *               thread per renderer when several workers are committed.
 *   quality     Image quality of a renderer against a reference renderer
 *               (Sec. 4.2.5, Def. 7): per direction both render; `metric` =
 *               hssim (default: hierarchical SSIM over a Gaussian pyramid,
 *               as the thesis, see rl_metrics.h), ssim, psnr (dB, capped
 *               at RL_PROPERTY_PSNR_MAX for equal images, so that
 *               statistics stay finite) or rmse; the minimum over the
 *               directions for ssim/hssim/psnr, the maximum for rmse.
 *               Flagged RL_PROPERTY_HIGHER_IS_BETTER except for rmse.
 *               Options: renderer, renderer_options, reference (default
 *               raster), reference_options, width, height, fov_deg,
 *               threads (as for ops), metric, hssim_levels (2..5, default
 *               5).
 *
 * Combined properties (Sec. 4.2.6): rl_property_create_combined() makes
 * a - b, a / b, min(a, b) or max(a, b) of two properties at the same
 * position; the set, if any, is taken from a; direction[i] combines a's
 * and b's direction[i]. Its unit is a's ("" for a ratio); it has no
 * options of its own (set a and b before combining them).
 *
 * Custom properties: rl_property_create_custom() wraps callbacks, so tests
 * and applications can sample any function of the position.
 *
 * Workers: rl_property_commit() takes the number of workers that will call
 * rl_property_evaluate() concurrently, each with its own worker index in
 * [0, workers); a property keeps per-worker state (rasterizer, renderer,
 * images) so that workers never share mutable data. A property flagged
 * RL_PROPERTY_EXCLUSIVE (timings) must be evaluated by one worker at a time;
 * it then uses all threads itself. Evaluation is deterministic except for
 * timings.
 *
 * Failure: outputs stay untouched; rl_last_error() says why. */
#ifndef RL_PROPERTY_H
#define RL_PROPERTY_H

#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_property rl_property;

/* The quality property's PSNR of equal images (otherwise +inf), dB: above
 * any real difference of 8-bit images (one level in every pixel: 48 dB). */
#define RL_PROPERTY_PSNR_MAX 100.0

typedef enum rl_property_flags {
    /* Timing: evaluate on one worker at a time, never concurrently. */
    RL_PROPERTY_EXCLUSIVE        = 1 << 0,
    /* Larger values are better (quality); for reports and colour maps. */
    RL_PROPERTY_HIGHER_IS_BETTER = 1 << 1,
} rl_property_flags;

typedef struct rl_property_info {
    const char *name;
    const char *description;
    const char *reference;          /* paper section, or "" */
} rl_property_info;

/* One evaluation at one position. set: caller-provided storage of
 * rl_property_set_words() words, written (all words) when the property has
 * a set; may be NULL to skip the set. direction[] holds the six
 * per-direction values before the reduction (NAN where a property has
 * none), for reports that want the direction that limited a value. */
typedef struct rl_property_sample {
    double value;
    uint64_t *set;
    double direction[6];
} rl_property_sample;

RL_API const rl_property_info *rl_property_list(size_t *count);
/* RL_ERR_NOT_FOUND for an unknown name (the message lists the known ones). */
RL_API rl_status rl_property_create(const char *name, rl_property **out);
RL_API void rl_property_release(rl_property *p);              /* NULL is a no-op */
RL_API const char *rl_property_name(const rl_property *p);
/* Unit of the value ("objects", "triangles", "ms", "SSIM", "dB", ...). */
RL_API const char *rl_property_unit(const rl_property *p);
RL_API unsigned rl_property_get_flags(const rl_property *p);  /* rl_property_flags */
RL_API const rl_option_info *rl_property_options(const rl_property *p, size_t *count);
/* Validates and stores one option; RL_ERR_INVALID_ARG for an unknown key or
 * a bad value (the message lists what is accepted), and after commit (the
 * options are frozen then). A renderer name is checked against the
 * registry; renderer_options are checked on commit. */
RL_API rl_status rl_property_set(rl_property *p, const char *key, const char *value);
RL_API const char *rl_property_get(const rl_property *p, const char *key);
/* Binds a committed scene and prepares `workers` workers (0 ->
 * omp_get_max_threads(), at most 4096). Options are frozen from here on; a
 * second commit rebinds (a failed one keeps the previous binding).
 * RL_ERR_INVALID_ARG (NULL scene for a built-in property, workers out of
 * range, bad renderer options), RL_ERR_NOT_COMMITTED (scene not committed;
 * a scene without triangles cannot be committed, see rl_scene_commit),
 * RL_ERR_EMPTY_SCENE (a committed scene without objects),
 * RL_ERR_OUT_OF_MEMORY. */
RL_API rl_status rl_property_commit(rl_property *p, const rl_scene *scene, int workers);
RL_API int rl_property_workers(const rl_property *p);       /* 0 before commit */
/* Bits in the set (the scene's object count) or 0; valid after commit. */
RL_API uint32_t rl_property_set_size(const rl_property *p);
RL_API size_t rl_property_set_words(const rl_property *p);  /* (set_size + 63) / 64 */
/* RL_ERR_NOT_COMMITTED, RL_ERR_INVALID_ARG (worker out of range, position
 * not finite), or what the underlying renderer returned. */
RL_API rl_status rl_property_evaluate(rl_property *p, int worker, rl_vec3 pos,
                                      rl_property_sample *out);

/* The six cube directions in order +x, -x, +y, -y, +z, -z, with the up
 * vector each uses (+y for the horizontal ones, -z looking up along +y, +z
 * looking down); for callers that build their own per-direction views.
 * Both are unit vectors and orthogonal; i outside 0..5 gives zero vectors. */
RL_API void rl_property_direction(int i, rl_vec3 *dir, rl_vec3 *up);

/* Visibility only: visible pixels per object at pos (num_objects values),
 * the per-object measure the set and counts derive from. RL_ERR_INVALID_ARG
 * for another property. */
RL_API rl_status rl_property_object_pixels(rl_property *p, int worker, rl_vec3 pos,
                                           uint32_t *pixels_per_object);

typedef enum rl_property_op {
    RL_PROPERTY_DIFFERENCE = 0,     /* a - b */
    RL_PROPERTY_RATIO,              /* a / b (NAN where b is 0) */
    RL_PROPERTY_MIN,
    RL_PROPERTY_MAX,
} rl_property_op;

/* Takes ownership of a and b (they are released with the combined property,
 * and also when this call fails). Commit commits both with the same scene
 * and workers. The flags are the union of a's and b's. RL_ERR_INVALID_ARG
 * for NULL arguments, a == b or an unknown op. The name is "op(a, b)". */
RL_API rl_status rl_property_create_combined(rl_property_op op, rl_property *a, rl_property *b,
                                             rl_property **out);

typedef struct rl_property_callbacks {
    const char *name;               /* required */
    const char *unit;               /* NULL -> "" */
    unsigned flags;                 /* rl_property_flags */
    /* Called on commit with the scene (may be NULL for scene-free test
     * properties: commit then accepts a NULL scene) and worker count;
     * returns the set size (0: no set) in *set_size. May be NULL. */
    rl_status (*commit)(void *user, const rl_scene *scene, int workers, uint32_t *set_size);
    /* Required. Fill value (and set, when non-NULL and set_size > 0). */
    rl_status (*evaluate)(void *user, int worker, rl_vec3 pos, double *value, uint64_t *set);
    void (*release)(void *user);    /* may be NULL */
} rl_property_callbacks;

/* name and unit are copied. RL_ERR_INVALID_ARG without a name or an
 * evaluate callback; on failure release is not called (user stays the
 * caller's). An error status from a callback is returned as is (with the
 * callback's message, if it recorded one). */
RL_API rl_status rl_property_create_custom(const rl_property_callbacks *cb, void *user,
                                           rl_property **out);

#ifdef __cplusplus
}
#endif
#endif
