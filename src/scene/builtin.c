/* builtin.c: the registry of built-in scenes (rl_builtin_scenes,
 * rl_scene_create_builtin) and helpers shared by their builders.
 *
 * Like pbrt-v4's create(name, params): one list, unknown names and unknown
 * parameters are errors that list what is accepted. */
#include "scene/builtin.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/params.h"

/* One entry per scene, in the order rl scenes lists them. */
static const rl_builtin_class *const classes[] = {
    &rl_builtin_cornell_class, &rl_builtin_cornell_teapot_class, &rl_builtin_spheres_class,
    &rl_builtin_city_class,    &rl_builtin_table_class,          &rl_builtin_cluster_class,
    &rl_builtin_ls_open_class, &rl_builtin_ls_cornell_class,
};
#define NUM_BUILTINS (sizeof classes / sizeof classes[0])

const rl_builtin_info *rl_builtin_scenes(size_t *count)
{
    /* The infos live in the classes; the public list wants them contiguous. */
    static rl_builtin_info infos[NUM_BUILTINS];
    static bool built;
#pragma omp critical(rl_builtin_scenes)
    {
        if (!built) {
            for (size_t i = 0; i < NUM_BUILTINS; ++i)
                infos[i] = classes[i]->info;
            built = true;
        }
    }
    if (count)
        *count = NUM_BUILTINS;
    return infos;
}

rl_status rl_scene_create_builtin(const char *name, const char *params, rl_scene **out)
{
    if (!name || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_create_builtin: NULL argument");
    const rl_builtin_class *cls = NULL;
    char names[RL_OPTION_LIST_SIZE] = "", hint[96];
    rl_suggestion sg = { 0 };
    for (size_t i = 0; i < NUM_BUILTINS; ++i) {
        if (strcmp(classes[i]->info.name, name) == 0)
            cls = classes[i];
        if (i)
            rl_option_append(names, sizeof names, ", ");
        rl_option_append(names, sizeof names, classes[i]->info.name);
        rl_suggest(&sg, name, classes[i]->info.name);
    }
    if (!cls)
        return rl_error(RL_ERR_NOT_FOUND, "unknown built-in scene \"%s\" (%sbuilt-ins: %s)", name,
                        rl_option_did_you_mean(&sg, hint, sizeof hint), names);
    /* Every key=value checked against the table before anything is built;
     * a repeated key keeps the last value. */
    rl_params list;
    rl_status s = rl_params_parse(params, &list);
    if (s)
        return s;
    rl_option_store values;
    s = rl_option_store_init(&values, cls->info.options, cls->info.num_options, NULL);
    for (uint32_t i = 0; s == RL_OK && i < list.count; ++i)
        s = rl_option_store_set(&values, list.items[i].key, list.items[i].value, name, NULL);
    rl_params_free(&list);
    rl_scene *scene = NULL;
    if (!s) s = rl_scene_create(&scene);
    if (!s) s = rl_scene_set_name(scene, name);
    if (!s) s = cls->build(scene, &values);
    if (!s) s = rl_scene_commit(scene);
    rl_option_store_free(&values);
    if (s) {
        rl_scene_release(scene);
        return s;
    }
    *out = scene;
    return RL_OK;
}

rl_status rl_builtin_material(rl_scene *scene, const char *name, rl_vec3 diffuse,
                              uint32_t *id)
{
    rl_material m = rl_material_default();
    snprintf(m.name, sizeof m.name, "%s", name);
    m.diffuse = diffuse;
    return rl_scene_add_material(scene, &m, id);
}

rl_status rl_builtin_instance(rl_scene *scene, uint32_t parent, const char *name,
                              uint32_t mesh, const char *kind, const rl_mat4 *transform,
                              uint32_t *node)
{
    uint32_t n;
    rl_status s = rl_scene_add_node(scene, parent, name, transform, &n);
    if (!s && mesh != RL_NONE) s = rl_scene_node_set_mesh(scene, n, mesh);
    if (!s && kind) s = rl_scene_node_set_attr(scene, n, "kind", kind);
    if (!s && node)
        *node = n;
    return s;
}

rl_material rl_builtin_phong(const char *name, rl_vec3 kd, float ks, float shininess)
{
    rl_material m = rl_material_default();
    snprintf(m.name, sizeof m.name, "%s", name);
    m.diffuse = kd;
    m.specular = rl_v3s(ks);
    m.shininess = shininess;
    return m;
}

rl_status rl_builtin_texture(rl_scene *scene, int width, int height, const rl_vec4 *texels,
                             uint32_t *id)
{
    rl_texture *tex = NULL;
    rl_status s = rl_texture_create(width, height, texels, &tex);
    if (!s && (s = rl_scene_add_texture(scene, tex, id)))
        rl_texture_release(tex);   /* ownership passes only on success */
    return s;
}

rl_status rl_builtin_checker(rl_scene *scene, int cell_texels, rl_vec4 even, rl_vec4 odd,
                             uint32_t *id)
{
    const int n = 2 * cell_texels;
    rl_vec4 *texels = rl_alloc((size_t)n * (size_t)n * sizeof *texels);
    if (!texels)
        return RL_ERR_OUT_OF_MEMORY;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x)
            texels[y * n + x] = ((x / cell_texels) + (y / cell_texels)) & 1 ? odd : even;
    rl_status s = rl_builtin_texture(scene, n, n, texels, id);
    free(texels);
    return s;
}
