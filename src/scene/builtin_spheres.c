/* builtin_spheres.c: the "spheres" scene, a Whitted-style test of the
 * ray-tracing coefficients (Ullmann 2003, Sec. 3.1): mirror (k_r = 0.9),
 * glass (k_t = 0.9, ior 1.5), diffuse and glossy Phong spheres on a
 * procedural checkerboard floor, lit by a point light and a directional
 * light. Units are metres, y up; spheres have radius 0.5 and rest on the
 * floor. rows x cols spheres cycle through the four materials; all share one
 * mesh (instancing). */
#include "scene/builtin.h"

#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "scene/generators.h"

#define RADIUS 0.5f
#define SPACING 1.4f                   /* centre distance between spheres */
#define CHECK_TEXELS 8                 /* texels per checker cell */

/* Two-colour checkerboard with 2x2 cells; the floor repeats it. */
static rl_status add_checker_texture(rl_scene *scene, uint32_t *id)
{
    return rl_builtin_checker(scene, CHECK_TEXELS, rl_v4(0.85f, 0.85f, 0.80f, 1.0f),
                              rl_v4(0.10f, 0.10f, 0.12f, 1.0f), id);
}

static rl_status add_materials(rl_scene *scene, uint32_t ids[4], uint32_t floor_texture,
                               uint32_t *floor)
{
    rl_material m[5];
    for (int i = 0; i < 5; ++i)
        m[i] = rl_material_default();
    snprintf(m[0].name, sizeof m[0].name, "mirror");
    m[0].diffuse = rl_v3s(0.05f);
    m[0].specular = rl_v3s(0.8f);
    m[0].shininess = 200.0f;
    m[0].reflectivity = 0.9f;
    snprintf(m[1].name, sizeof m[1].name, "glass");
    m[1].diffuse = rl_v3s(0.02f);
    m[1].specular = rl_v3s(0.8f);
    m[1].shininess = 200.0f;
    m[1].reflectivity = 0.05f;
    m[1].transmissivity = 0.9f;
    m[1].ior = 1.5f;
    snprintf(m[2].name, sizeof m[2].name, "diffuse");
    m[2].diffuse = rl_v3(0.75f, 0.25f, 0.20f);
    snprintf(m[3].name, sizeof m[3].name, "glossy");
    m[3].diffuse = rl_v3(0.20f, 0.30f, 0.70f);
    m[3].specular = rl_v3s(0.6f);
    m[3].shininess = 80.0f;
    m[3].reflectivity = 0.15f;
    snprintf(m[4].name, sizeof m[4].name, "floor");
    m[4].diffuse = rl_v3s(1.0f);           /* modulated by the checker texture */
    m[4].diffuse_texture = floor_texture;
    rl_status s = RL_OK;
    for (int i = 0; i < 4 && !s; ++i)
        s = rl_scene_add_material(scene, &m[i], &ids[i]);
    if (!s)
        s = rl_scene_add_material(scene, &m[4], floor);
    return s;
}

static rl_status build_spheres(rl_scene *scene, const rl_option_store *params)
{
    long long rows = rl_option_store_int(params, "rows"), cols = rl_option_store_int(params, "cols"),
              segments = rl_option_store_int(params, "segments"), checks = rl_option_store_int(params, "checks");
    uint32_t texture = RL_NONE, materials[4], floor_material;
    rl_status s = add_checker_texture(scene, &texture);
    if (!s) s = add_materials(scene, materials, texture, &floor_material);
    if (s)
        return s;

    /* Floor: a square a few sphere rows larger than the grid. */
    float width = (float)cols * SPACING, depth = (float)rows * SPACING;
    float floor_size = 4.0f + 2.0f * rl_maxf(width, depth);
    uint32_t sphere_mesh, floor_mesh;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = floor_material;
    /* One texture repeat holds 2x2 checker cells. */
    rl_gen_quad(&b, floor_size, floor_size, 0.5f * (float)checks);
    s = rl_meshbuf_add_to_scene(scene, &b, "floor", &floor_mesh);
    rl_meshbuf_free(&b);
    if (!s)
        s = rl_builtin_instance(scene, RL_NODE_ROOT, "floor", floor_mesh, "floor", NULL, NULL);
    rl_meshbuf_init(&b);
    b.material = materials[2];
    rl_gen_sphere(&b, RADIUS, (uint32_t)segments, (uint32_t)segments / 2);
    if (!s)
        s = rl_meshbuf_add_to_scene(scene, &b, "sphere", &sphere_mesh);
    rl_meshbuf_free(&b);

    for (long long r = 0; r < rows && !s; ++r)
        for (long long c = 0; c < cols && !s; ++c) {
            float x = ((float)c - 0.5f * (float)(cols - 1)) * SPACING;
            float z = -((float)r - 0.5f * (float)(rows - 1)) * SPACING;
            rl_mat4 t = rl_mat4_translate(rl_v3(x, RADIUS, z));
            char name[64];
            snprintf(name, sizeof name, "sphere_%d_%d", (int)r, (int)c);
            uint32_t node;
            s = rl_builtin_instance(scene, RL_NODE_ROOT, name, sphere_mesh, "sphere", &t, &node);
            /* Mirror, glass, diffuse, glossy, shifted per row for variety. */
            if (!s)
                s = rl_scene_node_set_material(scene, node, materials[(r + c) % 4]);
        }
    if (s)
        return s;

    rl_light point = {
        .type = RL_LIGHT_POINT,
        .color = rl_v3(1.0f, 0.95f, 0.85f),
        .intensity = 30.0f,
        .position = rl_v3(-2.0f, 4.0f, 3.0f),
    };
    rl_light sun = {
        .type = RL_LIGHT_DIRECTIONAL,
        .color = rl_v3(0.8f, 0.85f, 1.0f),
        .intensity = 0.6f,
        .direction = rl_v3(0.4f, -1.0f, -0.3f),
    };
    if ((s = rl_scene_add_light(scene, &point)) || (s = rl_scene_add_light(scene, &sun)))
        return s;
    float reach = rl_maxf(width, depth);
    rl_camera cam = {
        .eye = rl_v3(0.0f, 1.2f + 0.3f * reach, 2.5f + 0.9f * reach),
        .target = rl_v3(0.0f, RADIUS, 0.0f),
        .up = rl_v3(0.0f, 1.0f, 0.0f),
        .fov_deg = 45.0f,
        .width = 640,
        .height = 480,
    };
    return rl_scene_add_camera(scene, "default", &cam);
}

static const rl_option_info spheres_options[] = {
    { "rows", RL_OPT_INT, "1", "rows of spheres (materials cycle)", 1, 32, NULL },
    { "cols", RL_OPT_INT, "4", "spheres per row", 1, 32, NULL },
    { "segments", RL_OPT_INT, "48", "sphere tessellation", 8, 1024, NULL },
    { "checks", RL_OPT_INT, "16", "floor checkers per side", 1, 1024, NULL },
};

const rl_builtin_class rl_builtin_spheres_class = {
    { "spheres",
      "mirror, glass, diffuse and glossy spheres on a checkerboard floor; point and directional light",
      RL_BUILTIN_OPTIONS(spheres_options) },
    build_spheres,
};
