/* scene_drawer.h: the software rasterizer's way of drawing a committed
 * scene (scene_drawer.c), shared by every renderer that rasterizes: the
 * "raster" renderer, Vertex Tracing (Ullmann 2003, Sec. 3.5: its ID/Z
 * pre-pass and its non-VT objects), the culling and level-of-detail
 * renderers and the visibility property, so that "rasterized" means the
 * same thing in every renderer.
 *
 * Lighting is the local Phong model described in scene_drawer.c; it is
 * evaluated only when the draw writes colour. */
#ifndef RL_RASTER_SCENE_DRAWER_H
#define RL_RASTER_SCENE_DRAWER_H

#include "rl/rl_raster.h"
#include "rl/rl_scene.h"

typedef enum rl_raster_shading {
    RL_SHADING_FLAT = 0,      /* per triangle, geometric normal at the centroid */
    RL_SHADING_GOURAUD,       /* per vertex, interpolated */
    RL_SHADING_TEXTURED,      /* gouraud times the diffuse texture */
} rl_raster_shading;

typedef struct rl_raster_scene_desc {
    rl_raster_shading shading;
    float ambient;            /* times k_d */
    int threads;              /* for lighting; 0 = all */
    unsigned flags;           /* rl_raster_flags added to every batch; with
                               * RL_RASTER_NO_COLOR no lighting is computed */
    const uint8_t *object_mask;   /* per object, nonzero = draw; NULL = all */
} rl_raster_scene_desc;

/* Draws the objects of d selected by the mask into the rasterizer's current
 * target (set with rl_raster_set_target/set_camera; it must have a depth
 * layer), one batch per object: object IDs are object indices, triangle IDs
 * the scene's global triangle indices. eye is the viewer position for
 * specular lighting and two-sided normals. Counters accumulate into c
 * (may be NULL). progress (may be NULL) is called with the fraction of
 * objects done about a hundred times; returning false cancels with
 * RL_ERR_CANCELLED. */
rl_status rl_raster_draw_scene(rl_raster *ras, const rl_scene_data *d, rl_vec3 eye,
                               const rl_raster_scene_desc *desc, rl_raster_counters *c,
                               bool (*progress)(void *user, double done), void *user);

/* raster's lighting of a diffuse point (the ambient and diffuse terms of
 * its Phong model, two-sided, quad lights as points): for primitives
 * without a mesh material, such as surfels, lit like the meshes they
 * replace. */
rl_vec3 rl_raster_light_diffuse(const rl_scene_data *d, rl_vec3 p, rl_vec3 n, rl_vec3 kd, float ambient,
                                rl_vec3 eye);

/* The same drawing one object at a time, for renderers that decide per
 * object what to draw and in which order (occlusion culling, level of
 * detail): buffers are prepared once per drawer (rl_scene_drawer_new_frame
 * reuses them for the next frame), and an object is lit when it is first
 * drawn in a frame, so culled objects cost no lighting; in gouraud and
 * textured shading only the vertices of its triangles that the rasterizer
 * keeps are lit (rl_raster_lazy_colors), and an object whose box is
 * outside the view is skipped whole (rl_raster_box_outside). Drawing every
 * selected object in index order gives exactly rl_raster_draw_scene's
 * image. The drawer borrows d and desc->object_mask. */
typedef struct rl_scene_drawer rl_scene_drawer;
rl_status rl_scene_drawer_create(const rl_scene_data *d, rl_vec3 eye, const rl_raster_scene_desc *desc,
                                 rl_scene_drawer **out);
/* Starts another frame with a drawer made for the same scene and desc: the
 * viewer moves to eye, and every object is lit again when it is first drawn.
 * The buffers (per vertex and corner of the whole scene) are made once, so
 * a renderer that keeps its drawer does not allocate and fault in the
 * whole scene's buffers every frame for the few objects it draws. */
void rl_scene_drawer_new_frame(rl_scene_drawer *dr, rl_vec3 eye);
/* Lights the listed objects that are selected and not yet lit this frame,
 * in one parallel pass over the objects, for a renderer that knows what it
 * will draw before it draws: most objects are too small to light in
 * parallel one by one, so that would leave all threads but one idle. The
 * images do not change (lighting is per object). Objects lit lazily (all
 * of them in gouraud and textured shading) are left to the draw. */
void rl_scene_drawer_light(rl_scene_drawer *dr, const uint32_t *objects, uint32_t count);
/* Draws object (an index < d->num_objects; unselected objects are skipped)
 * into the rasterizer's current target. */
rl_status rl_scene_drawer_draw(rl_scene_drawer *dr, rl_raster *ras, uint32_t object, rl_raster_counters *c);
/* Draws the listed objects in list order, exactly as one rl_scene_drawer_draw
 * each would, but as one rl_raster_draw_many: a renderer that knows its set
 * before drawing it (SVS, a stored visible set) gets its many small objects
 * drawn on all threads, where one draw each would run on one. */
rl_status rl_scene_drawer_draw_list(rl_scene_drawer *dr, rl_raster *ras, const uint32_t *objects, uint32_t count,
                                    rl_raster_counters *c);
void rl_scene_drawer_release(rl_scene_drawer *dr);    /* NULL is a no-op */
/* Draws every selected object in index order (lists of many objects, see
 * rl_scene_drawer_draw_list): rl_raster_draw_scene with a drawer of one's
 * own. */
rl_status rl_scene_drawer_draw_all(rl_scene_drawer *dr, rl_raster *ras, rl_raster_counters *c,
                                   bool (*progress)(void *user, double done), void *user);

/* What a renderer keeps between frames: a rasterizer and a drawer, whose
 * per-vertex and per-corner buffers span the whole scene. Made afresh
 * every frame they cost more than drawing a culled set, and on a VM as
 * much as lighting the whole scene (allocating and faulting in about
 * 200 MB on `city`). Zero-initialise; released with rl_drawer_keep_release. */
typedef struct rl_drawer_keep {
    rl_raster *ras;
    rl_scene_drawer *drawer;
    uint64_t scene_uid;
    rl_raster_scene_desc desc;
} rl_drawer_keep;
/* Makes k's rasterizer and drawer ready for a frame of scene drawn with
 * desc from eye: the kept ones (a new frame of the drawer) when the scene
 * (rl_scene_uid) and desc are those they were made for, else new ones.
 * On failure k is released (empty). */
rl_status rl_drawer_keep_acquire(rl_drawer_keep *k, const rl_scene *scene, const rl_raster_scene_desc *desc,
                                 rl_vec3 eye);
void rl_drawer_keep_release(rl_drawer_keep *k);

#endif
