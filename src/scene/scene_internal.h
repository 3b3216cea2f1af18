/* scene_internal.h: the rl_scene struct, shared by the files of src/scene. */
#ifndef RL_SCENE_INTERNAL_H
#define RL_SCENE_INTERNAL_H

#include "rl/rl_path.h"
#include "rl/rl_scene.h"

typedef struct rl_attr { char *key, *value; } rl_attr;

typedef struct rl_node {
    char *name;
    uint32_t parent;           /* RL_NONE for root */
    rl_mat4 local;             /* local -> parent */
    uint32_t mesh;             /* RL_NONE if none */
    uint32_t material;         /* override or RL_NONE */
    uint32_t first_child, next_sibling, last_child; /* RL_NONE-terminated lists */
    rl_attr *attrs;
    uint32_t num_attrs;
} rl_node;

typedef struct rl_mesh {
    char *name;
    uint32_t num_vertices, num_triangles;
    rl_vec3 *positions, *normals;
    rl_vec2 *uvs;
    uint32_t *indices;
    uint32_t *materials;       /* per triangle */
} rl_mesh;

struct rl_scene {
    uint64_t uid;            /* see rl_scene_uid() */
    char *name;
    char *base_dir;
    bool committed;

    rl_node *nodes;       uint32_t num_nodes, cap_nodes;
    rl_mesh *meshes;      uint32_t num_meshes, cap_meshes;
    rl_material *materials; uint32_t num_materials, cap_materials;
    rl_texture **textures; uint32_t num_textures, cap_textures;
    char **texture_paths;  /* resolved file path per texture or NULL (sharing) */
    rl_light *lights;     uint32_t num_lights, cap_lights;
    rl_camera *cameras;   char **camera_names; uint32_t num_cameras, cap_cameras;
    rl_camera_path *camera_path;
    bool has_environment;
    rl_environment environment;   /* its map owned (environment.c) */

    uint64_t dropped_degenerate, dropped_nonfinite;
    /* Set by an import, which reports drops once per file instead of once
     * per mesh (load_assimp.c). */
    bool quiet_mesh_warnings;
    /* The orbit of the camera made for a scene without one
     * (rl_scene_set_default_view). */
    float view_azimuth_deg, view_elevation_deg;

    /* Flattened by commit. */
    rl_scene_data data;
    rl_vec3 *flat_positions, *flat_normals;
    rl_vec2 *flat_uvs;
    uint32_t *flat_indices, *flat_tri_object, *flat_tri_material;
    rl_object *flat_objects;
    uint64_t emissive_triangles;  /* counted by commit */
};

/* Frees the arrays made by commit and clears scene->data (commit.c). */
void rl_scene_free_flat(rl_scene *scene);

/* Returns RL_ERR_INVALID_ARG with a message if the scene is committed. */
rl_status rl_scene_check_mutable(const rl_scene *scene, const char *what);

/* Makes room for `need` elements in *array (capacity *cap, elements of
 * elem_size bytes), growing geometrically. RL_ERR_OUT_OF_MEMORY or
 * RL_ERR_LIMIT past 2^31 elements; *array is untouched on failure. */
rl_status rl_scene_reserve(void **array, uint32_t *cap, uint32_t need, size_t elem_size);

/* RL_ERR_INVALID_ARG "node \"name\": ..." for a non-finite or singular
 * node transform, which rl_scene_add_node refuses (scene_graph.c). */
rl_status rl_node_check_transform(const rl_mat4 *t, const char *name);

/* Appends tex (taken over on success) with its resolved file path, by
 * which rl_scene_load_texture shares it, or NULL (scene.c). */
rl_status rl_scene_push_texture(rl_scene *scene, rl_texture *tex, const char *resolved,
                                uint32_t *id);

/* Area-weighted smooth vertex normals; vertices without area get +z. */
void rl_mesh_compute_normals(uint32_t num_vertices, const rl_vec3 *positions,
                             uint32_t num_triangles, const uint32_t *indices, rl_vec3 *normals);


#endif
