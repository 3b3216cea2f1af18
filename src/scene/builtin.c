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

/* One entry per scene; builders[i] builds infos[i]. */
static const rl_builtin_info infos[] = {
    { "cornell",
      "Cornell box from the Cornell measured data (metres): 5 walls, short and tall "
      "block, ceiling quad light; 36 triangles",
      "none" },
    { "cornell-teapot",
      "Cornell box without the blocks, a slightly glossy Utah teapot on the floor",
      "triangles=15704 (teapot, 1..4000000; the closest patch grid is used), "
      "size=0.2 (teapot height, m, 0.01..0.5), shininess=64, rotate=-30 (degrees about y)" },
    { "spheres",
      "mirror, glass, diffuse and glossy spheres on a checkerboard floor; point and "
      "directional light",
      "rows=1, cols=4 (spheres, 1..32 each, materials cycle), segments=48 (sphere "
      "tessellation, 8..1024), checks=16 (floor checkers per side, 1..1024)" },
    { "city",
      "procedural city: blocks of buildings with window openings, floor slabs and "
      "interior rooms, street lamps and trees; for visibility and LOD work",
      "blocks=6 (per side, 1..64), seed=1, floors_min=2, floors_max=16 (1..200), "
      "detail=2 (0 boxes with slabs, 1 + windows, 2 + interior walls), "
      "block_size=64 (m, 24..512), street_width=16 (m, 4..200), furniture=true" },
    { "table",
      "the table scene of Ullmann 2003, Sec. 5.1: checkered table top, blue mirroring "
      "cup and red glass (the VT objects, node attribute vt=true), fork, teapot, plate, "
      "book, table lamp with a point light in its shade; cameras default and overview",
      "detail=1 (tessellation multiplier, 0.25..8; about 20000 triangles at 1), "
      "checks=8 (tablecloth checkers across the table, 1..256), fill=0.15 (dim fill "
      "light from behind the camera, 0..1; 0 = the thesis' single lamp light)" },
    { "cluster",
      "vehicle instrument cluster of Ullmann 2003, Sec. 5.4: speedometer and tachometer "
      "dials with printed textures, needles, warning lights behind a curved reflecting "
      "and refracting cover glass (the only VT object), steering wheel; cameras driver, "
      "lateral, zoom and a 4 s head-movement camera path",
      "speed=80 (km/h, 0..240), rpm=3 (x1000/min, 0..8), tex=1024 (dial texture size, "
      "64..4096), glass_segments=48 (cover glass columns, 4..1024), detail=1 "
      "(tessellation multiplier, 0.25..8)" },
    { "ls-open",
      "Schröder 2017, Sec. 9.3, scenes 1-3: one object (90 % diffuse, 10 % specular, "
      "shininess 50) on a floor under three quad lights; object + 8 triangles; "
      "max path length 2 (root attribute max_path_length); camera 1280x720",
      "model=teapot (teapot: 15704 triangles; bunny: closed blob of 69450, the thesis' "
      "69451 being odd; dragon: closed blob of 871306), triangles=N (teapot: closest patch "
      "grid, 1..4000000; bunny/dragon: exactly N, even, 4..16000000)" },
    { "ls-cornell",
      "Schröder 2017, Sec. 9.3, scenes 4-7: Cornell box (5 walls, ceiling quad light: 12 "
      "triangles) with a diffuse and a mirror cuboid (36 triangles) or one model (+12); "
      "max path length 3 (root attribute max_path_length); camera 1280x720",
      "model=boxes (or teapot, bunny, dragon as in ls-open), triangles=N (models only, "
      "as in ls-open)" },
};
static const rl_builtin_build_fn builders[] = {
    rl_builtin_cornell, rl_builtin_cornell_teapot, rl_builtin_spheres, rl_builtin_city,
    rl_builtin_table, rl_builtin_cluster, rl_builtin_ls_open, rl_builtin_ls_cornell,
};
#define NUM_BUILTINS (sizeof infos / sizeof infos[0])
_Static_assert(sizeof builders / sizeof builders[0] == NUM_BUILTINS, "one builder per scene");

const rl_builtin_info *rl_builtin_scenes(size_t *count)
{
    if (count)
        *count = NUM_BUILTINS;
    return infos;
}

rl_status rl_scene_create_builtin(const char *name, const char *params, rl_scene **out)
{
    if (!name || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_create_builtin: NULL argument");
    rl_builtin_build_fn build = NULL;
    for (size_t i = 0; i < NUM_BUILTINS; ++i)
        if (strcmp(infos[i].name, name) == 0)
            build = builders[i];
    if (!build)
        return rl_error(RL_ERR_NOT_FOUND,
                        "unknown built-in scene \"%s\" (built-ins: cornell, cornell-teapot, "
                        "spheres, city, table, cluster, ls-open, ls-cornell)", name);
    rl_params p;
    rl_status s = rl_params_parse(params, &p);
    if (s)
        return s;
    rl_scene *scene = NULL;
    s = rl_scene_create(&scene);
    if (!s) s = rl_scene_set_name(scene, name);
    if (!s) s = build(scene, &p);
    if (!s) s = rl_scene_commit(scene);
    rl_params_free(&p);
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
