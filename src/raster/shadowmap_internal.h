/* shadowmap_internal.h: what a shadow-map build other than shadowmap.c's
 * must share with it to give the same maps: gl-pt renders the depth maps
 * with GL (src/gl/gl_pt.c) and looks them up in GLSL, with this file's
 * frames, depth range, emitter rule and defaults, so that its shadow test
 * is rl_shadowmap_visible's. */
#ifndef RL_SHADOWMAP_INTERNAL_H
#define RL_SHADOWMAP_INTERNAL_H

#include "rl/rl_shadowmap.h"
#include "rl/rl_scene.h"

/* desc with its zeros replaced by the defaults, checked: RL_ERR_INVALID_ARG
 * for values out of range (recorded, prefixed by who). */
rl_status rl_shadowmap_resolve_desc(const rl_shadowmap_desc *desc, const char *who, rl_shadowmap_desc *out);
/* RL_ERR_UNSUPPORTED for a scene with a directional light (recorded). */
rl_status rl_shadowmap_check_lights(const rl_scene_data *d, const char *who);
/* Cube face f (0..5: +x, -x, +y, -y, +z, -z): right s, up u, view axis. */
void rl_shadowmap_face_frame(int f, rl_vec3 *s, rl_vec3 *u, rl_vec3 *axis);
/* Where a light's maps are rendered from. */
rl_vec3 rl_shadowmap_light_point(const rl_light *l);
/* The near and far planes of the faces at eye. */
void rl_shadowmap_depth_range(const rl_scene_data *d, rl_vec3 eye, float *z_near, float *z_far);
/* Whether triangle t is drawn into light l's maps (all but a quad light's
 * own emitter). */
bool rl_shadowmap_casts(const rl_scene_data *d, const rl_light *l, uint32_t t);

#endif
