/* test_chcpp.c: CHC++ (renderer "chcpp") is conservative: on walks through
 * a box city built here, where no two surfaces are coplanar, every frame
 * equals "raster" in colour, depth and IDs, pixel for pixel; and it culls:
 * at street level it draws a fraction of the triangles. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl.h"

static void add_box(rl_scene *s, uint32_t mat, rl_vec3 lo, rl_vec3 hi, uint32_t subdiv)
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

/* A 12 x 12 grid of buildings of random heights on a ground slab, every
 * coordinate jittered so that no two faces share a plane. */
static rl_scene *box_city(void)
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
    add_box(s, mats[0], rl_v3(-5.013f, -1.0f, -5.021f), rl_v3(125.017f, -0.0031f, 125.011f), 8);
    for (int i = 0; i < 12; ++i)
        for (int j = 0; j < 12; ++j) {
            float x = 10.0f * (float)i + 1.0f + 0.37f * rl_rng_float(&rng);
            float z = 10.0f * (float)j + 1.0f + 0.41f * rl_rng_float(&rng);
            float h = 4.0f + 30.0f * rl_rng_float(&rng);
            float w = 6.0f + 1.5f * rl_rng_float(&rng);
            add_box(s, mats[(i + j) % 4], rl_v3(x, 0.0013f * (float)(i * 12 + j + 1), z),
                    rl_v3(x + w, h, z + w + 0.1f * rl_rng_float(&rng)), 4);
        }
    rl_light l = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3s(1.0f), .intensity = 1.0f,
                   .direction = rl_normalize(rl_v3(-0.3f, -1.0f, -0.5f)) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static rl_camera street_camera(float t)
{
    /* Down a street between building rows, turning slowly. */
    rl_camera c = { .eye = rl_v3(9.5f + 0.8f * t, 1.7f, -2.0f + 6.0f * t),
                    .target = rl_v3(9.5f + 3.0f * sinf(0.2f * t), 1.5f, 60.0f),
                    .fov_deg = 60.0f, .width = 160, .height = 120 };
    return c;
}

static void check_walk(const rl_scene *s, const char *const *opts, const char *const *raster_opts, int frames,
                       uint64_t seed, bool street)
{
    rl_renderer *chc = fx_make("chcpp", opts);
    rl_rng rng;
    rl_rng_seed(&rng, seed, 3);
    rl_vec3 eye = rl_v3(60, 20, -30), dir = rl_v3(0, -0.3f, 1);
    for (int f = 0; f < frames; ++f) {
        rl_camera cam;
        if (street) {
            cam = street_camera((float)f);
        } else {
            /* A random walk with random turns, inside and above the city. */
            eye = rl_add(eye, rl_v3(6.0f * (rl_rng_float(&rng) - 0.5f), 4.0f * (rl_rng_float(&rng) - 0.5f),
                                    6.0f * (rl_rng_float(&rng) - 0.3f)));
            eye.y = rl_maxf(eye.y, 0.5f);
            dir = rl_normalize(rl_add(dir, rl_v3(0.6f * (rl_rng_float(&rng) - 0.5f),
                                                 0.3f * (rl_rng_float(&rng) - 0.5f),
                                                 0.6f * (rl_rng_float(&rng) - 0.5f))));
            cam = (rl_camera){ .eye = eye, .target = rl_add(eye, dir), .fov_deg = 70.0f, .width = 128,
                               .height = 96 };
        }
        rl_render_stats a, b;
        rl_image *ref = fx_render("raster", s, &cam, FX_ALL_LAYERS, raster_opts, &a);
        rl_image *img = fx_render_with(chc, s, &cam, FX_ALL_LAYERS, &b);
        fx_assert_images_identical(ref, img);
        assert_true(b.triangles_rasterized <= a.triangles_rasterized);
        rl_image_release(ref);
        rl_image_release(img);
    }
    rl_renderer_release(chc);
}

static void test_chcpp_equals_raster_on_random_walks(void **state)
{
    (void)state;
    rl_scene *s = box_city();
    check_walk(s, NULL, NULL, 16, 11, false);
    check_walk(s, NULL, NULL, 10, 0, true);
    rl_scene_release(s);
}

/* Every variant must stay conservative: no multi-queries, loose boxes, a
 * flat tree, a deep one, queries every frame, batch 1. */
static void test_chcpp_variants_stay_conservative(void **state)
{
    (void)state;
    rl_scene *s = box_city();
    static const char *const variants[][7] = {
        { "multiquery", "false", NULL },
        { "tight", "false", NULL },
        { "max_depth", "0", NULL },
        { "max_depth", "9", "looseness", "1.5", NULL },
        { "assumed_visible", "1", "batch", "1", NULL },
        { "shading", "flat", "cull", "true", "background", "0.2,0.3,0.4", NULL },
    };
    static const char *const shaded[] = { "shading", "flat", "cull", "true", "background", "0.2,0.3,0.4", NULL };
    const size_t n = sizeof variants / sizeof variants[0];
    for (size_t v = 0; v < n; ++v)
        check_walk(s, variants[v], v + 1 == n ? shaded : NULL, 5, 100 + v, v % 2 == 0);
    rl_scene_release(s);
}

static void test_chcpp_culls_at_street_level(void **state)
{
    (void)state;
    rl_scene *s = box_city();
    rl_renderer *chc = fx_make("chcpp", NULL);
    rl_render_stats full, st;
    rl_camera cam = street_camera(2.0f);
    rl_image *ref = fx_render("raster", s, &cam, RL_LAYER_COLOR, NULL, &full);
    for (int f = 0; f < 3; ++f) {   /* the third frame is temporally coherent */
        rl_image *img = fx_render_with(chc, s, &cam, RL_LAYER_COLOR, &st);
        rl_image_release(img);
    }
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(chc, &cs), RL_OK);
    assert_true(st.triangles_rasterized * 3 < full.triangles_rasterized);
    assert_true(cs.objects_drawn < 60);
    assert_true(cs.nodes_occluded + cs.nodes_frustum_culled > 0);
    assert_int_equal(st.occlusion_queries, cs.queries);
    /* A coherent frame needs fewer queries than the first one after a reset. */
    uint64_t coherent = cs.queries;
    rl_renderer_reset(chc);
    rl_image *img = fx_render_with(chc, s, &cam, RL_LAYER_COLOR, &st);
    assert_int_equal(rl_culling_get_stats(chc, &cs), RL_OK);
    assert_true(cs.queries > coherent);
    assert_true(cs.octree_nodes > 1 && cs.octree_depth <= 5);
    rl_image_release(img);
    rl_image_release(ref);
    rl_renderer_release(chc);
    rl_scene_release(s);
}

static void test_chcpp_refuses_bad_options(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("chcpp", NULL);
    assert_int_equal(rl_renderer_set(r, "max_depth", "21"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "looseness", "0.5"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "batch", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "assumed_visible", "-1"), RL_ERR_INVALID_ARG);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(r, &cs), RL_ERR_INVALID_ARG);   /* nothing rendered */
    rl_renderer *raster = fx_make("raster", NULL);
    assert_int_equal(rl_culling_get_stats(raster, &cs), RL_ERR_INVALID_ARG);
    rl_renderer_release(raster);
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chcpp_equals_raster_on_random_walks),
        cmocka_unit_test(test_chcpp_variants_stay_conservative),
        cmocka_unit_test(test_chcpp_culls_at_street_level),
        cmocka_unit_test(test_chcpp_refuses_bad_options),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
