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
/* The test scenes of Schröder 2017, Sec. 9.3 (builtin_linespace.c). */
rl_status rl_builtin_ls_open(rl_scene *scene, rl_params *params);
rl_status rl_builtin_ls_cornell(rl_scene *scene, rl_params *params);
/* Triangle counts of the bunny and dragon stand-ins (closed blobs): the
 * thesis' 69,451 is odd, impossible for a closed mesh, hence 69,450. */
#define RL_LS_BUNNY_TRIANGLES 69450u
#define RL_LS_DRAGON_TRIANGLES 871306u

/* Adds a material with the given name, diffuse colour and otherwise the
 * defaults of rl_material_default(); *id receives its index. */
rl_status rl_builtin_material(rl_scene *scene, const char *name, rl_vec3 diffuse,
                              uint32_t *id);
/* Phong material: diffuse kd, grey specular ks, shininess; the rest as
 * rl_material_default(). */
rl_material rl_builtin_phong(const char *name, rl_vec3 kd, float ks, float shininess);
/* Adds a width x height texture made from texels (copied); *id receives
 * its index. */
rl_status rl_builtin_texture(rl_scene *scene, int width, int height, const rl_vec4 *texels,
                             uint32_t *id);
/* A two-colour checkerboard of 2 x 2 cells, each cell_texels wide (whole
 * texel blocks, so bilinear lookup only blurs the cell borders); a surface
 * repeats it. odd colours the cells with odd x + y. */
rl_status rl_builtin_checker(rl_scene *scene, int cell_texels, rl_vec4 even, rl_vec4 odd,
                             uint32_t *id);

/* Adds a node under parent with a mesh, an optional "kind" attribute and a
 * transform (NULL: identity); *node (may be NULL) receives its id. */
rl_status rl_builtin_instance(rl_scene *scene, uint32_t parent, const char *name,
                              uint32_t mesh, const char *kind, const rl_mat4 *transform,
                              uint32_t *node);

#endif
