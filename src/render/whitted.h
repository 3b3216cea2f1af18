/* whitted.h: internal access to what the "whitted" renderer kept of its last
 * frame, for tests and for Vertex Tracing (Ullmann 2003, Sec. 3.3.1 compares
 * ray trees). Not part of the public API. */
#ifndef RL_RENDER_WHITTED_H
#define RL_RENDER_WHITTED_H

#include "rl/rl_render.h"
#include "rl/rl_trace.h"

/* Copies the ray tree of pixel (x, y)'s centre sample from the last frame
 * rendered with ray_trees=true into *out. RL_ERR_INVALID_ARG for a NULL
 * argument, a renderer that is not "whitted" or (x, y) outside that frame;
 * RL_ERR_NOT_FOUND when the last frame kept no trees. */
rl_status rl_whitted_pixel_tree(const rl_renderer *r, int x, int y, rl_ray_tree *out);

#endif
