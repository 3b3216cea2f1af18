/* builtin.h: the built-in scenes, one builder per file (builtin_*.c), listed
 * once in builtin.c.
 *
 * A builder reads its parameters, calls rl_params_check_unused() before doing
 * any heavy work, then fills an empty scene through the public API. builtin.c
 * names and commits the scene and releases it on failure. */
#ifndef RL_SCENE_BUILTIN_H
#define RL_SCENE_BUILTIN_H

#include "core/params.h"
#include "rl/rl_scene.h"

typedef rl_status (*rl_builtin_build_fn)(rl_scene *scene, rl_params *params);

rl_status rl_builtin_cornell(rl_scene *scene, rl_params *params);
rl_status rl_builtin_cornell_teapot(rl_scene *scene, rl_params *params);
rl_status rl_builtin_spheres(rl_scene *scene, rl_params *params);
rl_status rl_builtin_city(rl_scene *scene, rl_params *params);
rl_status rl_builtin_table(rl_scene *scene, rl_params *params);
rl_status rl_builtin_cluster(rl_scene *scene, rl_params *params);

/* Adds a material with the given name, diffuse colour and otherwise the
 * defaults of rl_material_default(); *id receives its index. */
rl_status rl_builtin_material(rl_scene *scene, const char *name, rl_vec3 diffuse,
                              uint32_t *id);
/* Adds a node under parent with a mesh, an optional "kind" attribute and a
 * transform (NULL: identity); *node (may be NULL) receives its id. */
rl_status rl_builtin_instance(rl_scene *scene, uint32_t parent, const char *name,
                              uint32_t mesh, const char *kind, const rl_mat4 *transform,
                              uint32_t *node);

#endif
