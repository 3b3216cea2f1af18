/* load_json_base.c: "base": a JSON scene may start from a built-in scene.
 * Built-ins come committed (immutable), so their contents are replayed into
 * a fresh, editable scene through the public building calls. */
#include <stdlib.h>

#include "core/error.h"
#include "scene/load_json_internal.h"

/* Ids stay the same because the copy starts empty (only the root node) and
 * adds everything in order. */
rl_status rl_jscene_copy_base(const rl_scene *src, rl_scene *dst)
{
    rl_status st = RL_OK;
    for (uint32_t i = 0; st == RL_OK && i < src->num_textures; ++i) {
        const rl_texture *t = src->textures[i];
        rl_texture *copy = NULL;
        st = rl_texture_create(t->width, t->height, t->texels, &copy);
        if (st == RL_OK && (st = rl_scene_add_texture(dst, copy, NULL)) != RL_OK)
            rl_texture_release(copy);
    }
    for (uint32_t i = 0; st == RL_OK && i < src->num_materials; ++i)
        st = rl_scene_add_material(dst, &src->materials[i], NULL);
    for (uint32_t i = 0; st == RL_OK && i < src->num_meshes; ++i) {
        const rl_mesh *m = &src->meshes[i];
        rl_mesh_desc d = { .name = m->name, .num_vertices = m->num_vertices,
                           .positions = m->positions, .normals = m->normals, .uvs = m->uvs,
                           .num_triangles = m->num_triangles, .indices = m->indices,
                           .triangle_materials = m->materials };
        st = rl_scene_add_mesh(dst, &d, NULL);
    }
    for (uint32_t i = 0; st == RL_OK && i < src->num_nodes; ++i) {
        const rl_node *n = &src->nodes[i];
        uint32_t id = RL_NODE_ROOT;
        if (i == RL_NODE_ROOT)
            dst->nodes[RL_NODE_ROOT].local = n->local;
        else
            st = rl_scene_add_node(dst, n->parent, n->name, &n->local, &id);
        if (st == RL_OK && n->mesh != RL_NONE)
            st = rl_scene_node_set_mesh(dst, id, n->mesh);
        if (st == RL_OK && n->material != RL_NONE)
            st = rl_scene_node_set_material(dst, id, n->material);
        for (uint32_t a = 0; st == RL_OK && a < n->num_attrs; ++a)
            st = rl_scene_node_set_attr(dst, id, n->attrs[a].key, n->attrs[a].value);
    }
    for (uint32_t i = 0; st == RL_OK && i < src->num_lights; ++i)
        st = rl_scene_add_light(dst, &src->lights[i]);
    for (uint32_t i = 0; st == RL_OK && i < src->num_cameras; ++i)
        st = rl_scene_add_camera(dst, src->camera_names[i], &src->cameras[i]);
    if (st == RL_OK && src->camera_path) {
        uint32_t n = rl_camera_path_key_count(src->camera_path);
        rl_camera_key *keys = rl_calloc(n ? n : 1, sizeof *keys);
        rl_camera_path *path = NULL;
        st = keys ? RL_OK : RL_ERR_OUT_OF_MEMORY;
        for (uint32_t k = 0; st == RL_OK && k < n; ++k)
            keys[k] = *rl_camera_path_key(src->camera_path, k);
        if (st == RL_OK)
            st = rl_camera_path_create(keys, n, &path);
        free(keys);
        if (st == RL_OK && (st = rl_scene_set_camera_path(dst, path)) != RL_OK)
            rl_camera_path_release(path);
    }
    return st;
}
