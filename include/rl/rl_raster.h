/* rl_raster.h: the software rasterizer, renderlab's reference "hardware" path.
 *
 * Triangles are transformed by a view-projection, clipped against the near
 * plane (and a guard band, so that fixed-point setup never overflows),
 * rasterized with edge functions in 8-bit sub-pixel fixed point and the
 * top-left fill rule (a pixel is covered when its centre is inside, shared
 * edges are drawn exactly once), depth-tested on the eye-space depth
 * recovered from the screen-linear 1/w (perspective-correct), and written to
 * the layers of an rl_image that the batch asks for: colour, depth, IDs.
 * Colours and uvs are interpolated perspective-correctly.
 *
 * Multithreaded (OpenMP): the screen is split into horizontal bands, each
 * band owned by one thread, so results are deterministic and need no locks.
 * Points are drawn as screen-aligned squares of a given pixel size.
 * rl_raster_query() counts the pixels of a batch that would pass the depth
 * test without writing anything: an occlusion query.
 *
 * Lighting is not done here: callers pass per-vertex (Gouraud) or per-face
 * (flat) colours, optionally modulated by a texture; see src/render/raster.c. */
#ifndef RL_RASTER_H
#define RL_RASTER_H

#include "rl/rl_camera.h"
#include "rl/rl_common.h"
#include "rl/rl_image.h"
#include "rl/rl_math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_raster rl_raster;

typedef struct rl_raster_desc {         /* zero = default */
    int threads;                        /* 0 -> omp_get_max_threads() */
} rl_raster_desc;

typedef enum rl_raster_flags {
    RL_RASTER_CULL_BACK     = 1 << 0,   /* drop triangles facing away (CCW = front) */
    RL_RASTER_NO_DEPTH_TEST = 1 << 1,   /* draw regardless of depth (still writes depth) */
    RL_RASTER_NO_COLOR      = 1 << 2,   /* do not write colour */
    RL_RASTER_NO_DEPTH      = 1 << 3,   /* do not write depth */
    RL_RASTER_NO_ID         = 1 << 4,   /* do not write IDs */
    /* Multi-pass rendering (Ullmann 2003, Sec. 3.5.4): a later pass over the
     * same geometry adds its colour to the target where its depth equals
     * the stored depth (bit-identical setup gives bit-identical depth). */
    RL_RASTER_DEPTH_EQUAL   = 1 << 5,   /* pass when depth == stored (instead of <) */
    RL_RASTER_BLEND_ADD     = 1 << 6,   /* colour += fragment (alpha kept) instead of = */
} rl_raster_flags;

/* One term of a multi-textured draw (Ullmann 2003, Sec. 3.5.5): per-vertex
 * colour times a texture looked up at per-vertex uvs, both interpolated
 * perspective-correctly. A triangle whose texture is RL_ID_NONE (or a layer
 * without textures/uvs) uses the colour alone. */
#define RL_RASTER_MAX_LAYERS 4
typedef struct rl_raster_layer {
    const rl_vec4 *colors;                /* per vertex, required */
    const rl_vec2 *uvs;                   /* per vertex, or NULL: untextured */
    const uint32_t *triangle_texture;     /* per triangle index into textures, or NULL */
    rl_texture *const *textures;
} rl_raster_layer;

/* Counters accumulated by draws (add, never reset by the rasterizer). */
typedef struct rl_raster_counters {
    uint64_t triangles_in;        /* submitted */
    uint64_t triangles_drawn;     /* after culling and clipping, setup done */
    uint64_t pixels_written;      /* fragments that passed the depth test */
    uint64_t points_drawn;
} rl_raster_counters;

/* A triangle batch. positions are world space (transformed by the current
 * view-projection). Colour source, first non-NULL wins: layers (num_layers >
 * 0: the fragment is the sum over layers of colour x texel, alpha = layer 0's
 * alpha), colors (per vertex,
 * Gouraud), face_colors (per triangle, flat), otherwise color. With uvs and a
 * texture (the per-triangle texture_index into textures, or texture), the
 * colour is multiplied by the texel. IDs: triangle_ids[i] or
 * first_triangle_id + i; object_ids[i] or object_id. With lazy set, colors
 * need not be filled before the draw (see rl_raster_lazy_colors). */
typedef struct rl_raster_lazy_colors rl_raster_lazy_colors;
typedef struct rl_raster_batch {
    uint32_t num_vertices;
    const rl_vec3 *positions;
    const rl_vec4 *colors;
    const rl_vec4 *face_colors;
    rl_vec4 color;
    const rl_vec2 *uvs;
    const rl_texture *texture;
    const uint32_t *triangle_texture;     /* per triangle index or RL_ID_NONE */
    rl_texture *const *textures;
    uint32_t num_triangles;
    const uint32_t *indices;              /* 3 per triangle */
    const uint32_t *triangle_ids;
    uint32_t first_triangle_id;
    const uint32_t *object_ids;
    uint32_t object_id;
    unsigned flags;                       /* rl_raster_flags */
    uint32_t num_layers;                  /* 0..RL_RASTER_MAX_LAYERS */
    const rl_raster_layer *layers;
    const rl_raster_lazy_colors *lazy;    /* NULL: colors are filled already */
    /* Alpha masks (glTF 2.0 alphaMode MASK, rl_material.alpha_cutoff): a
     * fragment of triangle i is dropped before the depth test where the
     * alpha of textures[mask_texture[i]] at the interpolated uvs is below
     * mask_cutoff[i], exactly where rl_alpha_masked() says a ray passes.
     * It holds in every pass, RL_RASTER_NO_COLOR included, so that ID and
     * depth passes see the holes the ray tracers see. NULL: no masks;
     * otherwise uvs, textures and mask_cutoff are required, and
     * mask_texture[i] = RL_ID_NONE leaves triangle i whole. */
    const uint32_t *mask_texture;
    const float *mask_cutoff;
} rl_raster_batch;

/* Vertex colours computed on demand. A GPU runs its vertex shader on every
 * vertex submitted; in a large scene most of them belong to triangles that
 * the trivial reject, back-face culling or the pixel-centre test drop
 * (Jaehn 2015, Sec. 7.4: SVS submits ~20x the triangles it draws). With
 * lazy colours, setup asks for colors[v] only for the vertices of triangles
 * that survive, by calling shade(user, v), which must write colors[v] as a
 * pure function of v (so the image equals that of filling colors first).
 * stamps (one per vertex, owned by the caller, zeroed once) remember across
 * draws which vertices are shaded for the current value of frame: each is
 * shaded at most once per frame, by one thread, even when parallel setup
 * chunks share it. A new lighting (another eye, say) takes a new frame
 * value, 1 <= frame < 2^31. Batches without per-vertex colors or with layers
 * ignore lazy. */
struct rl_raster_lazy_colors {
    void (*shade)(void *user, uint32_t vertex);
    void *user;
    uint32_t *stamps;                     /* accessed atomically */
    uint32_t frame;
};

typedef struct rl_raster_points {
    uint32_t count;
    const rl_vec3 *positions;             /* world space */
    const rl_vec4 *colors;                /* per point, or NULL: color */
    rl_vec4 color;
    const float *sizes_px;                /* per point side length, or NULL: size_px */
    float size_px;
    const uint32_t *object_ids;
    uint32_t object_id;
    unsigned flags;
} rl_raster_points;

RL_API rl_status rl_raster_create(const rl_raster_desc *desc, rl_raster **out);
RL_API void rl_raster_release(rl_raster *r);
/* Sets the render target and view-projection. The target's width/height
 * define the viewport. RL_ERR_INVALID_ARG for a NULL target. */
RL_API rl_status rl_raster_set_target(rl_raster *r, rl_image *target,
                                      const rl_mat4 *view, const rl_mat4 *projection);
/* Convenience: view and projection from a camera (near/far from the camera,
 * or rl_camera_clip_range() over bounds when its z_near is 0). */
RL_API rl_status rl_raster_set_camera(rl_raster *r, rl_image *target, const rl_camera *cam,
                                      rl_aabb scene_bounds);
/* Those matrices alone (RL_ERR_INVALID_ARG for a bad camera or clip range). */
RL_API rl_status rl_raster_camera_matrices(const rl_camera *cam, rl_aabb scene_bounds, rl_mat4 *view,
                                           rl_mat4 *proj);
RL_API rl_status rl_raster_draw(rl_raster *r, const rl_raster_batch *batch, rl_raster_counters *c);
/* Draws count batches in order: image, IDs and counters are exactly those of
 * count rl_raster_draw calls, but runs of small batches (a scene of many
 * small objects) are set up and filled on all threads together, where one
 * draw each would run on one. Every batch is checked first: an invalid one
 * (its index in the message) fails the call before anything is drawn. */
RL_API rl_status rl_raster_draw_many(rl_raster *r, const rl_raster_batch *batches, uint32_t count,
                                     rl_raster_counters *c);
RL_API rl_status rl_raster_draw_points(rl_raster *r, const rl_raster_points *pts, rl_raster_counters *c);
/* True when nothing inside box (world space) can be drawn in the current
 * view: the box lies entirely beyond the near plane or a side of the
 * viewport. Conservative (a margin covers rounding), so skipping the
 * triangles of such a box never changes an image; false without a target
 * and for empty or non-finite boxes. */
RL_API bool rl_raster_box_outside(const rl_raster *r, rl_aabb box);
/* Occlusion query: number of pixels of the batch's triangles that would pass
 * the depth test (strictly nearer than the stored depth, or equal to it with
 * RL_RASTER_DEPTH_EQUAL). Writes nothing. */
RL_API rl_status rl_raster_query(rl_raster *r, const rl_raster_batch *batch, uint64_t *visible_pixels);

#ifdef __cplusplus
}
#endif
#endif
