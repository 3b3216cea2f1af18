/* light_eval.h: how much a light sends towards a surface point, shared by
 * the renderers so that raster and whitted light a scene identically. */
#ifndef RL_SCENE_LIGHT_EVAL_H
#define RL_SCENE_LIGHT_EVAL_H

#include "rl/rl_scene.h"

/* Point, spot and directional lights (rl_light.h): the irradiance-like scale
 * *E at p (colour·intensity/d², the spot cone fading with a smoothstep
 * between its outer and inner half angles; directional: colour·intensity),
 * the unit direction *l towards the light and the distance *dist to it
 * (INFINITY for directional). False where the light cannot reach p.
 * Quad lights are area lights: each renderer samples them its own way. */
bool rl_light_eval_delta(const rl_light *L, rl_vec3 p, rl_vec3 *E, rl_vec3 *l, float *dist);

#endif
