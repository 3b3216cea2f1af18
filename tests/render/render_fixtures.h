/* render_fixtures.h: what the renderer tests share. Everything is static
 * inline so that each test uses any subset without unused-function
 * warnings. Failures are cmocka assertions (include <cmocka.h> first). */
#ifndef RL_TESTS_RENDER_FIXTURES_H
#define RL_TESTS_RENDER_FIXTURES_H

#include "rl/rl_render.h"
#include "rl/rl_rng.h"
#include "rl/rl_sampling.h"
#include "rl/rl_scene.h"

#include <stdlib.h>

#define FX_ALL_LAYERS (RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID)

/* A renderer with options {key, value, ..., NULL} set (each must succeed). */
static inline rl_renderer *fx_make(const char *name, const char *const *opts)
{
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create(name, &r), RL_OK);
    for (size_t i = 0; opts && opts[i]; i += 2)
        assert_int_equal(rl_renderer_set(r, opts[i], opts[i + 1]), RL_OK);
    return r;
}

/* One frame into a new image with the given layers (the camera's size),
 * after the renderer's measured inputs are prepared as the CLI does. */
static inline rl_image *fx_render_with(rl_renderer *r, const rl_scene *s, const rl_camera *cam,
                                       unsigned layers, rl_render_stats *stats)
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam->width, cam->height, layers, &img), RL_OK);
    rl_status st = rl_renderer_prepare_inputs(r, s);
    if (st == RL_OK)
        st = rl_renderer_render(r, s, cam, img, stats);
    if (st != RL_OK)
        print_error("%s: %s\n", rl_renderer_name(r), rl_last_error());
    assert_int_equal(st, RL_OK);
    return img;
}

static inline rl_image *fx_render(const char *name, const rl_scene *s, const rl_camera *cam,
                                  unsigned layers, const char *const *opts, rl_render_stats *stats)
{
    rl_renderer *r = fx_make(name, opts);
    rl_image *img = fx_render_with(r, s, cam, layers, stats);
    rl_renderer_release(r);
    return img;
}

/* Bitwise equality of every layer the images have (they must have the same). */
static inline void fx_assert_images_identical(const rl_image *a, const rl_image *b)
{
    size_t n = (size_t)a->width * a->height;
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    assert_int_equal(a->layers, b->layers);
    assert_memory_equal(a->color, b->color, n * sizeof *a->color);
    if (a->depth)
        assert_memory_equal(a->depth, b->depth, n * sizeof *a->depth);
    if (a->object_id) {
        assert_memory_equal(a->object_id, b->object_id, n * sizeof *a->object_id);
        assert_memory_equal(a->triangle_id, b->triangle_id, n * sizeof *a->triangle_id);
    }
}

/* The built-in Cornell box and its camera at size x size pixels. */
static inline rl_scene *fx_cornell(rl_camera *cam, int size)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, NULL, cam), RL_OK);
    cam->width = cam->height = size;
    return s;
}

/* Two triangles spanning corner p and edges u, v (normal along u x v). */
static inline void fx_room_quad(rl_scene *s, uint32_t mat, rl_vec3 p, rl_vec3 u, rl_vec3 v)
{
    rl_vec3 pos[4] = { p, rl_add(p, u), rl_add(rl_add(p, u), v), rl_add(p, v) };
    uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc md = { .name = "quad", .num_vertices = 4, .positions = pos, .num_triangles = 2, .indices = idx,
                        .material = mat };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "quad", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

static inline uint32_t fx_room_material(rl_scene *s, rl_vec3 kd, rl_vec3 emission)
{
    rl_material m = rl_material_default();
    m.diffuse = kd;
    m.emission = emission;
    uint32_t id;
    assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
    return id;
}

/* The closed room [-1,1] x [0,2] x [-1,1] with coloured side walls. */
static inline void fx_add_room(rl_scene *s)
{
    uint32_t white = fx_room_material(s, rl_v3s(0.75f), rl_v3s(0.0f));
    uint32_t red = fx_room_material(s, rl_v3(0.7f, 0.1f, 0.1f), rl_v3s(0.0f));
    uint32_t green = fx_room_material(s, rl_v3(0.1f, 0.6f, 0.1f), rl_v3s(0.0f));
    fx_room_quad(s, white, rl_v3(-1, 0, -1), rl_v3(0, 0, 2), rl_v3(2, 0, 0));   /* floor */
    fx_room_quad(s, white, rl_v3(-1, 2, -1), rl_v3(2, 0, 0), rl_v3(0, 0, 2));   /* ceiling */
    fx_room_quad(s, white, rl_v3(-1, 0, -1), rl_v3(2, 0, 0), rl_v3(0, 2, 0));   /* back */
    fx_room_quad(s, white, rl_v3(-1, 0, 1), rl_v3(0, 2, 0), rl_v3(2, 0, 0));    /* front */
    fx_room_quad(s, red, rl_v3(-1, 0, -1), rl_v3(0, 2, 0), rl_v3(0, 0, 2));     /* left */
    fx_room_quad(s, green, rl_v3(1, 0, -1), rl_v3(0, 0, 2), rl_v3(0, 2, 0));    /* right */
}

/* The room lit only through a shade (bdpt's test): a small quad lamp facing the ceiling
 * inside an open-topped box, so every path from the camera reaches the
 * lamp by a bounce off the ceiling; next-event estimation at the surfaces
 * the camera sees is always shadowed. */
static inline rl_scene *fx_shade_room(rl_camera *cam, int size)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    fx_add_room(s);
    uint32_t shade = fx_room_material(s, rl_v3s(0.5f), rl_v3s(0.0f));
    float L = 40.0f, a = 0.1f, y = 0.5f, h = 0.25f;
    uint32_t lamp = fx_room_material(s, rl_v3s(0.0f), rl_v3s(L));
    fx_room_quad(s, lamp, rl_v3(-a, y, -a), rl_v3(0, 0, 2 * a), rl_v3(2 * a, 0, 0));
    float b = a + 0.02f;
    /* four sides from below the lamp to above it, and a bottom */
    fx_room_quad(s, shade, rl_v3(-b, y - 0.05f, -b), rl_v3(2 * b, 0, 0), rl_v3(0, h, 0));
    fx_room_quad(s, shade, rl_v3(-b, y - 0.05f, b), rl_v3(0, h, 0), rl_v3(2 * b, 0, 0));
    fx_room_quad(s, shade, rl_v3(-b, y - 0.05f, -b), rl_v3(0, h, 0), rl_v3(0, 0, 2 * b));
    fx_room_quad(s, shade, rl_v3(b, y - 0.05f, -b), rl_v3(0, 0, 2 * b), rl_v3(0, h, 0));
    fx_room_quad(s, shade, rl_v3(-b, y - 0.05f, -b), rl_v3(0, 0, 2 * b), rl_v3(2 * b, 0, 0));
    rl_light q = { .type = RL_LIGHT_QUAD, .color = rl_v3s(1.0f), .intensity = L, .position = rl_v3(-a, y, -a),
                   .edge_u = rl_v3(0, 0, 2 * a), .edge_v = rl_v3(2 * a, 0, 0) };   /* u x v = +y */
    assert_int_equal(rl_scene_add_light(s, &q), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    *cam = (rl_camera){ .eye = rl_v3(0.0f, 0.6f, 0.95f), .target = rl_v3(0.0f, 0.9f, -1.0f), .fov_deg = 70.0f,
                        .width = size, .height = size };
    return s;
}

static inline void fx_add_box(rl_scene *s, uint32_t mat, rl_vec3 lo, rl_vec3 hi, uint32_t subdiv)
{
    /* A box whose faces are split into subdiv x subdiv quads, so that it
     * has enough triangles for culling to matter. */
    uint32_t n = subdiv + 1, nv = 6 * n * n, nt = 6 * subdiv * subdiv * 2;
    rl_vec3 *p = malloc(nv * sizeof *p);
    uint32_t *idx = malloc(nt * 3 * sizeof *idx);
    uint32_t v = 0, t = 0;
    for (int face = 0; face < 6; ++face) {
        int axis = face / 2, u = (axis + 1) % 3, w = (axis + 2) % 3;
        bool hi_side = face & 1;
        uint32_t base = v;
        for (uint32_t i = 0; i < n; ++i)
            for (uint32_t j = 0; j < n; ++j) {
                float c[3];
                float lo3[3] = { lo.x, lo.y, lo.z }, hi3[3] = { hi.x, hi.y, hi.z };
                c[axis] = hi_side ? hi3[axis] : lo3[axis];
                c[u] = lo3[u] + (hi3[u] - lo3[u]) * (float)i / (float)subdiv;
                c[w] = lo3[w] + (hi3[w] - lo3[w]) * (float)j / (float)subdiv;
                p[v++] = rl_v3(c[0], c[1], c[2]);
            }
        for (uint32_t i = 0; i < subdiv; ++i)
            for (uint32_t j = 0; j < subdiv; ++j) {
                uint32_t a = base + i * n + j, b = a + n, c = a + 1, d = b + 1;
                uint32_t q[6] = { a, b, c, c, b, d };
                if (!hi_side) {
                    q[1] = c, q[2] = b, q[4] = d, q[5] = b;
                }
                for (int k = 0; k < 6; ++k)
                    idx[t++] = q[k];
            }
    }
    uint32_t mesh, node;
    rl_mesh_desc md = { .name = "box", .num_vertices = nv, .positions = p, .num_triangles = nt,
                        .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "box", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    free(p);
    free(idx);
}

/* One triangle (-1,-1,0) (1,-1,0) (0,1,0) with the default material,
 * committed or not. */
static inline rl_scene *fx_triangle_scene(bool commit)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    const rl_vec3 pos[3] = { { -1, -1, 0 }, { 1, -1, 0 }, { 0, 1, 0 } };
    const uint32_t idx[3] = { 0, 1, 2 };
    rl_mesh_desc md = { .name = "tri", .num_vertices = 3, .positions = pos,
                        .num_triangles = 1, .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "tri", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    if (commit)
        assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* An empty scene with one default material (its index in *mat), for
 * tests that place their own boxes. */
static inline rl_scene *fx_scene_with_material(uint32_t *mat)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    assert_int_equal(rl_scene_add_material(s, &m, mat), RL_OK);
    return s;
}

/* The culling tests' city: a 12 x 12 grid of buildings of random heights on a ground slab, every
 * coordinate jittered so that no two faces share a plane. */
static inline rl_scene *fx_box_city(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_rng rng;
    rl_rng_seed(&rng, 7, 1);
    uint32_t mats[4];
    for (int i = 0; i < 4; ++i) {
        rl_material m = rl_material_default();
        m.diffuse = rl_v3(0.3f + 0.15f * (float)i, 0.5f, 0.8f - 0.15f * (float)i);
        m.specular = rl_v3s(0.2f);
        assert_int_equal(rl_scene_add_material(s, &m, &mats[i]), RL_OK);
    }
    fx_add_box(s, mats[0], rl_v3(-5.013f, -1.0f, -5.021f), rl_v3(125.017f, -0.0031f, 125.011f), 8);
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) {
            float x = 10.0f * (float)i + 1.0f + 0.37f * rl_rng_float(&rng);
            float z = 10.0f * (float)j + 1.0f + 0.41f * rl_rng_float(&rng);
            float h = 4.0f + 30.0f * rl_rng_float(&rng);
            float w = 6.0f + 1.5f * rl_rng_float(&rng);
            fx_add_box(s, mats[(i + j) % 4], rl_v3(x, 0.0013f * (float)(i * 12 + j + 1), z),
                    rl_v3(x + w, h, z + w + 0.1f * rl_rng_float(&rng)), 4);
        }
    rl_light l = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3s(1.0f), .intensity = 1.0f,
                   .direction = rl_normalize(rl_v3(-0.3f, -1.0f, -0.5f)) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

#endif
