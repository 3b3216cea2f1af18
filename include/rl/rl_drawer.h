/* rl_drawer.h: drawing a committed scene, for the renderers that rasterize
 * it object by object. One interface with one implementation per backend:
 * the software rasterizer's scene drawer (src/raster, rl_drawer_create) and
 * the OpenGL one (src/gl, rl_gl_drawer_create in rl_gl.h). The culling and
 * level-of-detail renderers (chcpp, svs, visset, surfels, select through
 * them) and the visibility
 * property of Jähn 2015 draw, query and read back only through this header,
 * so that a second backend changes none of them.
 *
 * A frame:
 *     rl_drawer_begin(dr, image, &view, &proj, eye);   target and camera
 *     rl_drawer_draw(dr, objects, n, &counters);       any number of lists
 *     rl_drawer_query(dr, &boxes, &pixels, &counters); occlusion queries
 *     rl_drawer_query_issue / _poll / _result(...);    the same, asynchronous
 *     rl_drawer_draw_points(dr, &points, &counters);   surfels
 *     rl_drawer_end(dr);                               image holds the frame
 * A frame starts from the target as it is (the caller clears it; a GPU
 * backend uploads it). The target must have a depth layer; IDs are
 * written unless the desc's
 * flags say RL_RASTER_NO_ID. Lighting is the local Phong model of the
 * software drawer (src/raster/scene_drawer.c), evaluated only when the
 * draw writes colour. A drawer is made for one scene and desc and kept
 * across frames: its per-vertex buffers span the whole scene, and making
 * them every frame costs more than drawing a culled set.
 *
 * Failure: RL_ERR_INVALID_ARG (NULL arguments, a target without depth),
 * RL_ERR_NOT_COMMITTED, RL_ERR_OUT_OF_MEMORY, RL_ERR_CANCELLED (progress). */
#ifndef RL_DRAWER_H
#define RL_DRAWER_H

#include "rl/rl_camera.h"
#include "rl/rl_common.h"
#include "rl/rl_image.h"
#include "rl/rl_math.h"
#include "rl/rl_raster.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rl_raster_shading {
    RL_SHADING_FLAT = 0,      /* per triangle, geometric normal at the centroid */
    RL_SHADING_GOURAUD,       /* per vertex, interpolated */
    RL_SHADING_TEXTURED,      /* gouraud times the diffuse texture */
} rl_raster_shading;

typedef struct rl_drawer_desc {   /* zero = default */
    rl_raster_shading shading;
    float ambient;            /* times k_d */
    int threads;              /* 0 = all */
    unsigned flags;           /* rl_raster_flags added to every draw; with
                               * RL_RASTER_NO_COLOR nothing is lit */
    const uint8_t *object_mask;   /* per object, nonzero = draw; NULL = all;
                                   * borrowed for the drawer's life and read
                                   * at every draw. Lit drawers make their
                                   * lighting buffers for the objects it
                                   * selects at create: only with
                                   * RL_RASTER_NO_COLOR may its contents
                                   * change between frames */
    bool deferred_counts;         /* the pixels_written of draws may reach
                                   * their counters only at rl_drawer_end,
                                   * so those must outlive the frame: a GPU
                                   * backend then never waits for a draw */
    uint32_t query_delay;         /* simulated query latency: the first
                                   * query_delay polls of each query say
                                   * its answer is not there; 0 = as the
                                   * backend has it. For tests and
                                   * measurements of latency hiding on a
                                   * backend that answers at once (result
                                   * still answers) */
} rl_drawer_desc;

typedef struct rl_drawer rl_drawer;

/* A drawer of scene (committed) with the software rasterizer. */
RL_API rl_status rl_drawer_create(const rl_scene *scene, const rl_drawer_desc *desc, rl_drawer **out);
RL_API void rl_drawer_release(rl_drawer *dr);        /* NULL is a no-op */
/* Whether dr was made for this scene (rl_scene_uid) and desc: a renderer
 * keeps its drawer while it fits and makes a new one otherwise. */
RL_API bool rl_drawer_fits(const rl_drawer *dr, const rl_scene *scene, const rl_drawer_desc *desc);
/* The backend's name ("software", "gl"). */
RL_API const char *rl_drawer_backend(const rl_drawer *dr);

/* Starts a frame into target (which must have a depth layer; it is not
 * cleared) seen with view and proj from eye (for specular lighting and
 * two-sided normals): every object is lit anew when first drawn. */
RL_API rl_status rl_drawer_begin(rl_drawer *dr, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj,
                                 rl_vec3 eye);
/* The same with cam's matrices, its clip range from scene_bounds when the
 * camera has none (as rl_raster_set_camera). */
RL_API rl_status rl_drawer_begin_camera(rl_drawer *dr, rl_image *target, const rl_camera *cam,
                                        rl_aabb scene_bounds);
/* Lights the listed objects now, in one parallel pass, for a renderer that
 * knows what it will draw before it draws (optional: a draw lights what it
 * needs; the image is the same). */
RL_API void rl_drawer_light(rl_drawer *dr, const uint32_t *objects, uint32_t count);
/* Draws the listed objects (unselected ones skipped) in list order. Object
 * IDs are object indices, triangle IDs the scene's triangle indices.
 * Counters accumulate into c (may be NULL). */
RL_API rl_status rl_drawer_draw(rl_drawer *dr, const uint32_t *objects, uint32_t count, rl_raster_counters *c);
/* Draws every selected object in index order; progress (may be NULL) about
 * a hundred times, false cancels. */
RL_API rl_status rl_drawer_draw_all(rl_drawer *dr, rl_raster_counters *c, rl_progress_fn progress, void *user);
/* An occlusion query: the pixels of boxes (triangles, e.g. the front faces
 * of bounding boxes) that would pass the depth test, writing nothing;
 * answered when it returns (on a GPU after a wait, which the asynchronous
 * calls below avoid). */
RL_API rl_status rl_drawer_query(rl_drawer *dr, const rl_raster_batch *boxes, uint64_t *pixels,
                                 rl_raster_counters *c);
/* Asynchronous occlusion queries, for renderers that hide a GPU's query
 * latency as Mattausch et al. 2008 do: issue starts the query of boxes (as
 * rl_drawer_query, against the depth buffer as it is at the issue) and
 * returns a handle at once; poll says, without waiting, whether its answer
 * is there; result waits for the answer where it is not, gives the pixels
 * and frees the handle. Handles belong to the frame: rl_drawer_end drops
 * those never read unless kept (rl_drawer_query_keep), and at most
 * RL_DRAWER_MAX_QUERIES may be open at once (RL_ERR_LIMIT beyond). The
 * software backend answers at the issue (poll is always true, unless the
 * desc's query_delay says otherwise); the GL one runs GL query objects from
 * a pool kept across frames. rl_drawer_query is issue followed by result. */
#define RL_DRAWER_MAX_QUERIES (1u << 20)
RL_API rl_status rl_drawer_query_issue(rl_drawer *dr, const rl_raster_batch *boxes, uint32_t *handle,
                                       rl_raster_counters *c);
RL_API rl_status rl_drawer_query_poll(rl_drawer *dr, uint32_t handle, bool *ready);
RL_API rl_status rl_drawer_query_result(rl_drawer *dr, uint32_t handle, uint64_t *pixels);
/* Keeps an open query past the frame's end (CHC++ reads the answers of
 * previously visible nodes a frame later): rl_drawer_end leaves it open,
 * and in the next frame (begun on the same drawer) poll and result read it
 * as any other; there it is dropped at the end unless kept again. A frame
 * begun while the last one never ended drops every open query. */
RL_API rl_status rl_drawer_query_keep(rl_drawer *dr, uint32_t handle);
/* Draws a triangle batch made by the caller (rl_raster.h), e.g. Vertex
 * Tracing's refined mesh with its deferred textures as layers (Ullmann
 * 2003, Sec. 3.5), into the frame beside the scene's objects, with the
 * batch's flags (the desc's are not added). Textures are the scene's:
 * layers' textures must be rl_scene_data.textures (or NULL). Every
 * backend draws positions with indices, IDs (per triangle or one) and
 * the colour from layers, per-vertex colors or the one color; the GL
 * backend refuses face_colors, a batch texture or uvs outside layers,
 * and lazy colours (RL_ERR_UNSUPPORTED), which the software one draws. */
RL_API rl_status rl_drawer_draw_batch(rl_drawer *dr, const rl_raster_batch *batch, rl_raster_counters *c);
/* Draws points (surfels: square splats of a size in pixels). */
RL_API rl_status rl_drawer_draw_points(rl_drawer *dr, const rl_raster_points *points, rl_raster_counters *c);
/* Ends the frame: the target holds colour, depth and IDs. */
RL_API rl_status rl_drawer_end(rl_drawer *dr);

/* The drawers' lighting of a diffuse point (the ambient and diffuse terms
 * of their Phong model, two-sided, quad lights as points): for primitives
 * without a mesh material, such as surfels, lit like the meshes they
 * replace. */
RL_API rl_vec3 rl_raster_light_diffuse(const rl_scene_data *d, rl_vec3 p, rl_vec3 n, rl_vec3 kd, float ambient,
                                       rl_vec3 eye);

#ifdef __cplusplus
}
#endif
#endif
