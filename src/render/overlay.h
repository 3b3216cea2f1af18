/* overlay.h: diagnostic drawing over a finished image (overlay.c): the
 * lines of vt's refined mesh, its samples, and the octree nodes of chcpp
 * (option overlay of both). Only the colour layer changes; depth and IDs
 * stay those of the frame. */
#ifndef RL_RENDER_OVERLAY_H
#define RL_RENDER_OVERLAY_H

#include "rl/rl_image.h"
#include "rl/rl_math.h"

void rl_overlay_plot(rl_image *img, int x, int y, rl_vec4 c);
/* A line between two pixel positions (pixel (x, y) covers [x, x+1) x
 * [y, y+1)); clipped to the image. */
void rl_overlay_line(rl_image *img, float x0, float y0, float x1, float y1, rl_vec4 c);
/* The 12 edges of box b as seen through view_proj (rl_math.h: row-major,
 * column vectors; OpenGL clip space), each clipped where the clip w falls
 * below w_min (the near distance), so that boxes around the eye draw only
 * their parts in front. */
void rl_overlay_box(rl_image *img, const rl_mat4 *view_proj, float w_min, rl_aabb b, rl_vec4 c);

#endif
