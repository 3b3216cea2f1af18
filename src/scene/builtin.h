/* builtin.h: the built-in scenes, one builder per file (builtin_*.c), listed
 * once in builtin.c.
 *
 * A scene is a class: its rl_builtin_info (name, description and the table
 * of its key=value parameters, the same rl_option_info rows that renderers
 * use, so rl scenes prints them as rl algos prints options) and a builder.
 * builtin.c parses and validates the parameters against the table (unknown
 * keys and out-of-range values fail there, before any work), hands the
 * builder the values, names and commits the scene and releases it on
 * failure. A builder checks only what a table cannot say (e.g. a range that
 * depends on another parameter), then fills an empty scene through the
 * public API. */
#ifndef RL_SCENE_BUILTIN_H
#define RL_SCENE_BUILTIN_H

#include "core/options.h"
#include "rl/rl_scene.h"

typedef struct rl_builtin_class {
    rl_builtin_info info;
    rl_status (*build)(rl_scene *scene, const rl_option_store *params);
} rl_builtin_class;

#define RL_BUILTIN_OPTIONS(table) (table), sizeof(table) / sizeof((table)[0])

extern const rl_builtin_class rl_builtin_cornell_class;
extern const rl_builtin_class rl_builtin_cornell_teapot_class;
extern const rl_builtin_class rl_builtin_spheres_class;
extern const rl_builtin_class rl_builtin_city_class;
extern const rl_builtin_class rl_builtin_table_class;
extern const rl_builtin_class rl_builtin_cluster_class;
/* The test scenes of Schröder 2017, Sec. 9.3 (builtin_linespace.c). */
extern const rl_builtin_class rl_builtin_ls_open_class;
extern const rl_builtin_class rl_builtin_ls_cornell_class;
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
