/* scene_drawer.h: the software rasterizer's way of drawing a committed
 * scene (scene_drawer.c), shared by every renderer that rasterizes, so that
 * "rasterized" means the same thing in all of them. The "raster" renderer,
 * the culling and level-of-detail renderers and the visibility property
 * use it through rl_drawer (rl_drawer.h, drawer.c: its software backend);
 * Vertex Tracing (Ullmann 2003, Sec. 3.5: its ID/Z pre-pass and its non-VT
 * objects) and pt's rasterized G-buffer call it directly.
 *
 * Lighting is the local Phong model described in scene_drawer.c; it is
 * evaluated only when the draw writes colour. */
#ifndef RL_RASTER_SCENE_DRAWER_H
#define RL_RASTER_SCENE_DRAWER_H

#include "rl/rl_drawer.h"
#include "rl/rl_raster.h"
#include "rl/rl_scene.h"


/* Draws the objects of d selected by the mask into the rasterizer's current
 * target (set with rl_raster_set_target/set_camera; it must have a depth
 * layer), one batch per object: object IDs are object indices, triangle IDs
 * the scene's global triangle indices. eye is the viewer position for
 * specular lighting and two-sided normals. Counters accumulate into c
 * (may be NULL). progress (may be NULL) is called with the fraction of
 * objects done about a hundred times; returning false cancels with
 * RL_ERR_CANCELLED. */
rl_status rl_raster_draw_scene(rl_raster *ras, const rl_scene_data *d, rl_vec3 eye,
                               const rl_drawer_desc *desc, rl_raster_counters *c,
                               bool (*progress)(void *user, double done), void *user);

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
rl_status rl_scene_drawer_create(const rl_scene_data *d, rl_vec3 eye, const rl_drawer_desc *desc,
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
/* Ends a lit gouraud or textured frame drawn into target with view and
 * proj: the pixels that show a normal-mapped surface (rl_material
 * .normal_texture) are shaded again per pixel with the bent normal of
 * rl_shading_normal, because a map's detail is finer than the vertices
 * that Gouraud shading lights (a deferred pass over the ID layer, Saito &
 * Takahashi 1990). Needs the target's colour and ID layers; a no-op
 * without normal maps, in flat shading, for unlit drawers and for
 * multi-pass blending. Not for frames with points (their IDs are point
 * IDs): the caller skips it there. */
void rl_scene_drawer_finish(rl_scene_drawer *dr, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj);
/* Draws every selected object in index order (lists of many objects, see
 * rl_scene_drawer_draw_list): rl_raster_draw_scene with a drawer of one's
 * own. */
rl_status rl_scene_drawer_draw_all(rl_scene_drawer *dr, rl_raster *ras, rl_raster_counters *c,
                                   bool (*progress)(void *user, double done), void *user);

#endif
