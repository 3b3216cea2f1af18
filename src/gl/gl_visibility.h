/* gl_visibility.h: the ID renders of the visibility property (Jähn 2015,
 * Sec. 4.2.2) on OpenGL with the counting on the GPU (gl_visibility.c).
 *
 * Six square views of one position are rasterized with object IDs and a
 * depth test into the six layers of one integer texture; a compute pass
 * then counts, over all six layers at once, the pixels each object owns
 * and per layer the objects seen, their triangles and the covered pixels.
 * Only those counts come back (one buffer of 18 + num_objects words), not
 * the ID images. src/eval/property_visibility.c chooses the views and the
 * objects drawn into each, exactly as for its software drawer.
 *
 * A counter owns its own GL context (gl_context.h), current on the calling
 * thread for the length of one call: calls must not overlap (the caller
 * serialises them), but consecutive ones may come from different threads. */
#ifndef RL_GL_VISIBILITY_H
#define RL_GL_VISIBILITY_H

#include "rl/rl_gl.h"
#include "rl/rl_math.h"
#include "rl/rl_scene.h"

typedef struct rl_gl_visibility rl_gl_visibility;

/* One view's counts, as the software property counts them per face. */
typedef struct rl_gl_view_counts {
    uint32_t objects;             /* objects owning at least one pixel */
    uint32_t polygons;            /* their triangles */
    uint32_t pixels;              /* pixels owned by some object */
} rl_gl_view_counts;

#define RL_GL_VISIBILITY_VIEWS 6

/* A counter of scene (committed) for views of resolution² pixels (1..4096)
 * on device (rl_gl.h). RL_ERR_UNSUPPORTED where no GL 4.5 context can be
 * made (with the reason), RL_ERR_LIMIT where the scene's arrays or the
 * images exceed the GL's limits, RL_ERR_INTERNAL for a GL error. */
rl_status rl_gl_visibility_create(const rl_scene *scene, int resolution, const char *device,
                                  rl_gl_visibility **out);
void rl_gl_visibility_release(rl_gl_visibility *v);    /* NULL is a no-op */
const rl_gl_info *rl_gl_visibility_info(const rl_gl_visibility *v);

/* Renders view i with the perspective view_proj[i] (proj * view, the
 * near plane at clip z = -w) and counts. masks[i] (or masks NULL) selects
 * the objects drawn into view i (nonzero = drawn; NULL = all): objects
 * that cannot reach a pixel centre may be left out to save vertex work.
 * pixels (num_objects words) gets the pixels each object owns over all six
 * views, views[i] view i's counts. */
rl_status rl_gl_visibility_count(rl_gl_visibility *v, const rl_mat4 view_proj[RL_GL_VISIBILITY_VIEWS],
                                 const uint8_t *const *masks, uint32_t *pixels,
                                 rl_gl_view_counts views[RL_GL_VISIBILITY_VIEWS]);

/* The object IDs of view `view` of the last count (resolution² words, row 0
 * the top row, RL_ID_NONE for background): what the GPU counted, for tests
 * that count it again on the CPU. RL_ERR_INVALID_ARG before any count. */
rl_status rl_gl_visibility_read_ids(rl_gl_visibility *v, int view, uint32_t *ids);

#endif
