/* lathe.h: surfaces of revolution, swept tubes and extruded outlines for the
 * built-in scenes (builtin_table.c, builtin_cluster.c), appended to an
 * rl_meshbuf like the generators in generators.h.
 *
 * All three build closed, outward-wound solids when given closed input, so
 * refractive parts made with them can be entered and left by the tracer,
 * which decides by the geometric normal facing the ray. Vertices along
 * seams and creases are duplicated (for uv and sharp normals); the solids
 * are watertight after welding by position. */
#ifndef RL_SCENE_LATHE_H
#define RL_SCENE_LATHE_H

#include "scene/generators.h"

/* Below this angle between neighbouring profile segments the lathe shares
 * smooth normals; above it the corner becomes a crease. */
#define RL_LATHE_CREASE_DEG 35.0f

/* Revolves a profile around the y axis: profile[i] = (r, y) with r >= 0.
 * Winding rule: walking along the profile, the solid's material lies on the
 * right of the walking direction in the (r, y) plane (r to the right, y up),
 * e.g. down the outside of a cup. A profile that starts and ends on the axis
 * (r = 0) gives a closed solid; points on the axis become fan apexes, so no
 * degenerate triangles appear. u runs around (0..1), v along the profile by
 * arc length. segments >= 3. */
void rl_lathe(rl_meshbuf *b, const rl_vec2 *profile, uint32_t count, uint32_t segments);

/* Appends n+1 points of a circular arc (centre c, radius, angles a0..a1 in
 * radians measured from +r towards +y) to profile at *count (capacity
 * checked by the caller). Used for rounded rims. */
void rl_lathe_arc(rl_vec2 *profile, uint32_t *count, rl_vec2 c, float radius, float a0,
                  float a1, uint32_t n);

/* Part of a torus around the z axis, in the xy plane: centre line of radius
 * major_r from angle a0 to a1 (radians, from +x towards +y), tube radius
 * minor_r. caps closes both ends with flat discs (a closed solid). */
void rl_torus_arc(rl_meshbuf *b, float major_r, float minor_r, float a0, float a1,
                  uint32_t arc_segments, uint32_t tube_segments, bool caps);

/* Prism from a convex outline in the xz plane (outline[i] = (x, z), either
 * orientation, 3..RL_EXTRUDE_MAX_POINTS points; others are ignored) between
 * heights y0 < y1: top, bottom and flat sides. */
#define RL_EXTRUDE_MAX_POINTS 64
void rl_extrude_convex(rl_meshbuf *b, const rl_vec2 *outline, uint32_t count, float y0,
                       float y1);

#endif
