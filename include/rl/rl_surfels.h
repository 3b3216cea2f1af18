/* rl_surfels.h: Progressive Blue Surfels (Jähn 2015, Ch. 6), the
 * preprocessing of one surfel representation for a set of objects.
 *
 * rl_surfels_build() renders the objects from the 8 corners of a cube
 * around their bounds towards its centre, orthographically, with our
 * rasterizer (Sec. 6.1.1: the 8 cube-corner directions; fewer leave holes)
 * or, given an atlas_drawer, with that drawer (OpenGL: rl_gl_drawer_create),
 * turns every covered pixel into a candidate surfel (position, normal,
 * unlit colour), records the relative coverage (covered pixels / all
 * pixels of the 8 views), draws a progressive best-candidate sequence from
 * the candidates so that every prefix is a blue-noise sample of the
 * outside-visible surface, and estimates each surfel's relative point size
 * from its nearest neighbours' normals. The renderer (renderer "surfels")
 * draws prefixes of these sequences; see src/render/surfels.c.
 *
 * Defaults are the thesis' (Sec. 6.3): 1024^2 pixels per view, 40000
 * surfels, start sample 160 candidates, +1 round per sample every 500
 * rounds up to half the sample, 20 neighbours. */
#ifndef RL_SURFELS_H
#define RL_SURFELS_H

#include "rl/rl_common.h"
#include "rl/rl_drawer.h"
#include "rl/rl_math.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One surfel in 20 bytes (Jähn 2015, Sec. 6.1.3): position as 3 floats,
 * normal in 4 bytes, colour and relative size in 4 more. */
typedef struct rl_surfel {
    float position[3];        /* world space */
    int8_t normal[4];         /* unit normal as snorm8 x, y, z; [3] = 0 */
    uint8_t color[3];         /* unlit surface colour (k_d x texture), linear, 0..255 */
    uint8_t size;             /* relative point size, 0..255 = 0..1 */
} rl_surfel;

/* How the sequence is drawn from the candidates (Table 6.1's variants). */
typedef enum rl_surfel_sampling {
    RL_SURFEL_PROGRESSIVE = 0,    /* the thesis' default: start sample, reused more and more */
    RL_SURFEL_CONSTANT,           /* a fresh sample of start_sample for every surfel */
    RL_SURFEL_RANDOM,             /* uniform random order (the reference) */
} rl_surfel_sampling;

typedef struct rl_surfel_desc {   /* zero = default */
    uint32_t resolution;          /* pixels per side of each of the 8 views; 0 -> 1024 */
    uint32_t count;               /* surfels wanted; 0 -> 40000 (fewer if fewer candidates) */
    uint32_t start_sample;        /* candidates per sample; 0 -> 160 */
    uint32_t rounds_step;         /* rounds per sample grow by 1 every this many; 0 -> 500 */
    uint32_t neighbours;          /* for the relative size; 0 -> 20 */
    rl_surfel_sampling sampling;
    uint64_t seed;                /* the same seed gives the same sequence */
    int threads;                  /* 0 -> all */
    rl_progress_fn progress;      /* may be NULL; false cancels (RL_ERR_CANCELLED) */
    void *user;
    rl_drawer *atlas_drawer;      /* NULL: the 8 views by the software rasterizer;
                                   * else by this drawer (borrowed, e.g. the GPU's:
                                   * rl_gl_drawer_create), made for the same scene with
                                   * RL_SURFEL_ATLAS_DRAWER_DESC (RL_ERR_INVALID_ARG
                                   * otherwise). Only the atlas moves; the steps after
                                   * it are the same. One drawer may serve many builds */
} rl_surfel_desc;

/* The desc an atlas_drawer is made with: depth and IDs only, nothing lit,
 * no culling, every object selectable. */
#define RL_SURFEL_ATLAS_DRAWER_DESC ((rl_drawer_desc){ .flags = RL_RASTER_NO_COLOR })

/* Time per step, the rows of Jähn 2015, Table 6.1. */
typedef struct rl_surfel_timing {
    double atlas_ms;              /* rendering the 8 views (a drawer's: upload, draw,
                                   * readback; its making is the caller's) */
    double candidates_ms;         /* building the initial candidate set */
    double sampling_ms;           /* drawing the sequence */
    double sizes_ms;              /* relative point sizes */
    double total_ms;
} rl_surfel_timing;

typedef struct rl_surfel_set {
    rl_surfel *surfels;           /* the sequence; every prefix is a blue-noise sample */
    uint32_t count;
    uint32_t candidates;          /* size of the initial candidate set */
    float coverage;               /* relative coverage: covered / all pixels of the views */
    rl_aabb bounds;               /* of the objects the set represents */
    rl_surfel_timing timing;
} rl_surfel_set;

/* Builds the surfel representation of the given objects of a committed
 * scene (objects == NULL: all of them). RL_ERR_INVALID_ARG (NULL scene or
 * out, object index out of range, absurd parameters), RL_ERR_NOT_COMMITTED,
 * RL_ERR_OUT_OF_MEMORY, RL_ERR_CANCELLED. On failure *out is zeroed. A set
 * of objects that covers no pixel gives count 0, not an error. */
RL_API rl_status rl_surfels_build(const rl_scene *scene, const uint32_t *objects, uint32_t num_objects,
                                  const rl_surfel_desc *desc, rl_surfel_set *out);
RL_API void rl_surfel_set_free(rl_surfel_set *set);    /* NULL is a no-op; zeroes *set */

/* Nearest-neighbour distances within the prefix [0, m) of a sequence (the
 * measure of Jähn 2015, Sec. 6.4): their minimum and mean (m >= 2, else
 * both 0, as for s == NULL). Deterministic for any thread count. threads
 * 0 = all. RL_ERR_INVALID_ARG for NULL outputs; RL_ERR_OUT_OF_MEMORY. */
RL_API rl_status rl_surfels_prefix_spacing(const rl_surfel *s, uint32_t m, int threads, double *min_dist,
                                           double *mean_dist);

/* Decoders for the packed fields. */
RL_API rl_vec3 rl_surfel_normal(const rl_surfel *s);
RL_API rl_vec3 rl_surfel_color(const rl_surfel *s);
RL_API float rl_surfel_size(const rl_surfel *s);

#ifdef __cplusplus
}
#endif
#endif
