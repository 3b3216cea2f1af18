/* drawer_backend.h: how a backend plugs into rl_drawer (rl_drawer.h). A
 * backend provides one rl_drawer_ops table and makes its drawers with
 * rl_drawer_make; rl_drawer.c dispatches every call through the table. The
 * software backend is drawer.c's own (the rasterizer and the scene drawer
 * of scene_drawer.c); the OpenGL one is src/gl/gl_drawer.c. */
#ifndef RL_RASTER_DRAWER_BACKEND_H
#define RL_RASTER_DRAWER_BACKEND_H

#include "rl/rl_drawer.h"

typedef struct rl_drawer_ops {
    const char *name;
    void (*release)(void *impl);
    rl_status (*begin)(void *impl, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj, rl_vec3 eye);
    void (*light)(void *impl, const uint32_t *objects, uint32_t count);
    rl_status (*draw)(void *impl, const uint32_t *objects, uint32_t count, rl_raster_counters *c);
    rl_status (*draw_all)(void *impl, rl_raster_counters *c, rl_progress_fn progress, void *user);
    /* Asynchronous queries in slots that rl_drawer.c hands out (0, 1, ...,
     * reused once read or at the frame's end): issue starts the query in
     * slot, poll tells whether its answer is there, result waits for it. */
    rl_status (*query_issue)(void *impl, const rl_raster_batch *boxes, uint32_t slot);
    rl_status (*query_poll)(void *impl, uint32_t slot, bool *ready);
    rl_status (*query_result)(void *impl, uint32_t slot, uint64_t *pixels);
    rl_status (*draw_batch)(void *impl, const rl_raster_batch *batch, rl_raster_counters *c);
    rl_status (*draw_points)(void *impl, const rl_raster_points *points, rl_raster_counters *c);
    rl_status (*end)(void *impl);
} rl_drawer_ops;

/* A drawer over impl (released with ops->release when the drawer is) for
 * scene and desc; on failure impl is released too. */
rl_status rl_drawer_make(const rl_drawer_ops *ops, void *impl, const rl_scene *scene, const rl_drawer_desc *desc,
                         rl_drawer **out);

/* The impl of d when d was made with ops, else NULL: for calls that only one
 * backend offers (the GL drawer's frame texture, src/gl/gl_frame.h). */
void *rl_drawer_impl(const rl_drawer *d, const rl_drawer_ops *ops);

#endif
