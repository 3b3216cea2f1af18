/* test_shadowmap.c: cube shadow maps (Schröder 2017, Sec. 8.6) against
 * exact shadow rays: on the Cornell box the map must agree with a BVH
 * shadow ray at random surface points nearly everywhere, and on a small
 * scene built here a point under an occluder is dark and one in the open
 * lit, for point, spot and quad lights. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_accel.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"
#include "rl/rl_shadowmap.h"

#define SAMPLES 40000

static rl_vec3 light_centre(const rl_light *l)
{
    if (l->type == RL_LIGHT_QUAD)
        return rl_add(l->position, rl_scale(rl_add(l->edge_u, l->edge_v), 0.5f));
    return l->position;
}

/* The oracle: a shadow ray from p + n·eps to the light's sample point. */
static bool ray_visible(const rl_accel *a, rl_vec3 p, rl_vec3 n, rl_vec3 light, float eps)
{
    rl_vec3 o = rl_madd(p, n, eps);
    rl_vec3 to = rl_sub(light, o);
    float len = rl_length(to);
    rl_ray r = { .o = o, .d = rl_scale(to, 1.0f / len), .t_min = 0.0f,
                 .t_max = len * (1.0f - 1e-4f) };
    return !rl_accel_occluded(a, &r);
}

static void test_shadowmap_agrees_with_shadow_rays_in_the_cornell_box(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    rl_shadowmap *sm = NULL;
    rl_accel *a = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    rl_status st = rl_shadowmap_create(s, NULL, &sm);
    if (st)
        fail_msg("%s", rl_last_error());
    print_message("shadow map build, 1 light x 6 faces at 1024^2: %.1f ms, %.1f MiB\n",
                  rl_shadowmap_build_ms(sm), (double)rl_shadowmap_memory(sm) / (1 << 20));
    assert_true(rl_shadowmap_memory(sm) >= 6u * 1024 * 1024 * sizeof(float));
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &a), RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_lights, 1);
    rl_vec3 light = light_centre(&d->lights[0]);
    const float eps = 1e-4f * rl_length(rl_aabb_extent(d->bounds));

    /* Random triangles, random barycentrics. Points on the light's own
     * emitter are counted apart: a path tracer does not shade them with
     * shadow rays, and they lie in the plane of the light's centre. */
    rl_rng rng;
    rl_rng_seed(&rng, 8, 6);
    int agree = 0, total = 0, shadowed = 0, emitter_agree = 0, emitter_total = 0;
    int map_dark_ray_lit = 0, map_lit_ray_dark = 0;
    for (int i = 0; i < SAMPLES; ++i) {
        uint32_t t = rl_rng_bounded(&rng, d->num_triangles);
        float r1 = rl_rng_float(&rng), r2 = rl_rng_float(&rng);
        float su = sqrtf(r1), b0 = 1.0f - su, b1 = su * (1.0f - r2), b2 = su * r2;
        const uint32_t *tri = &d->indices[3 * t];
        rl_vec3 v0 = d->positions[tri[0]], v1 = d->positions[tri[1]], v2 = d->positions[tri[2]];
        rl_vec3 p = rl_add(rl_add(rl_scale(v0, b0), rl_scale(v1, b1)), rl_scale(v2, b2));
        rl_vec3 n = rl_normalize(rl_cross(rl_sub(v1, v0), rl_sub(v2, v0)));
        bool exact = ray_visible(a, p, n, light, eps);
        bool map = rl_shadowmap_visible(sm, 0, p, n, rl_rng_float(&rng), rl_rng_float(&rng));
        rl_vec3 e = d->materials[d->triangle_material[t]].emission;
        if (e.x > 0.0f || e.y > 0.0f || e.z > 0.0f) {
            ++emitter_total;
            emitter_agree += exact == map;
            continue;
        }
        ++total;
        agree += exact == map;
        shadowed += !exact;
        map_dark_ray_lit += !map && exact;
        map_lit_ray_dark += map && !exact;
    }
    double rate = (double)agree / total;
    print_message("shadow map vs exact shadow ray at %d points: %.2f %% agree (%.1f %% in "
                  "shadow; map dark/ray lit %d, map lit/ray dark %d); on the emitter %d/%d\n",
                  total, 100.0 * rate, 100.0 * shadowed / total, map_dark_ray_lit,
                  map_lit_ray_dark, emitter_agree, emitter_total);
    assert_true(total >= 20000);
    assert_true(shadowed > total / 20);          /* the test sees real shadows */
    assert_true(rate >= 0.99);            /* measured 99.57 % */
    rl_accel_release(a);
    rl_shadowmap_release(sm);
    rl_scene_release(s);
}

/* Floor 4 x 4 at y = 0, a 1 x 1 occluder at y = 1 above the origin, and
 * one light of the given type above it. */
static rl_scene *occluder_scene(rl_light_type type)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, floor_mesh, occluder_mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "quad", "sx=4,sz=4", mat, &floor_mesh), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "quad", "sx=1,sz=1", mat, &occluder_mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "floor", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, floor_mesh), RL_OK);
    rl_mat4 up = rl_mat4_translate(rl_v3(0.0f, 1.0f, 0.0f));
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "occluder", &up, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, occluder_mesh), RL_OK);
    rl_light l = { .type = type, .color = rl_v3s(1.0f), .intensity = 10.0f,
                   .position = rl_v3(0.0f, 3.0f, 0.0f), .direction = rl_v3(0.0f, -1.0f, 0.0f),
                   .spot_inner_deg = 40.0f, .spot_outer_deg = 60.0f };
    if (type == RL_LIGHT_QUAD) {
        l.position = rl_v3(-0.1f, 3.0f, -0.1f);       /* centre (0, 3, 0), facing down */
        l.edge_u = rl_v3(0.0f, 0.0f, 0.2f);
        l.edge_v = rl_v3(0.2f, 0.0f, 0.0f);
    }
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static void test_point_under_an_occluder_is_shadowed_and_one_in_the_open_lit(void **state)
{
    (void)state;
    const rl_light_type types[] = { RL_LIGHT_POINT, RL_LIGHT_SPOT, RL_LIGHT_QUAD };
    const rl_vec3 up = rl_v3(0.0f, 1.0f, 0.0f);
    for (size_t i = 0; i < sizeof types / sizeof types[0]; ++i) {
        rl_scene *s = occluder_scene(types[i]);
        rl_shadowmap *sm = NULL;
        assert_int_equal(rl_shadowmap_create(s, &(rl_shadowmap_desc){ .size = 256 }, &sm), RL_OK);
        /* Every jitter gives the same answer well inside and well outside. */
        for (int j = 0; j < 16; ++j) {
            float ju = (float)(j % 4) / 4.0f, jv = (float)(j / 4) / 4.0f;
            assert_false(rl_shadowmap_visible(sm, 0, rl_v3(0.0f, 0.0f, 0.0f), up, ju, jv));
            assert_false(rl_shadowmap_visible(sm, 0, rl_v3(0.2f, 0.0f, -0.3f), up, ju, jv));
            assert_true(rl_shadowmap_visible(sm, 0, rl_v3(1.5f, 0.0f, 1.5f), up, ju, jv));
            assert_true(rl_shadowmap_visible(sm, 0, rl_v3(-1.8f, 0.0f, 0.1f), up, ju, jv));
            /* The occluder's top is lit, a floor point facing away is not. */
            assert_true(rl_shadowmap_visible(sm, 0, rl_v3(0.1f, 1.0f, 0.1f), up, ju, jv));
            assert_false(rl_shadowmap_visible(sm, 0, rl_v3(1.5f, 0.0f, 1.5f), rl_neg(up), ju, jv));
        }
        /* Out-of-range light: not visible, no crash. */
        assert_false(rl_shadowmap_visible(sm, 1, rl_v3(1.5f, 0.0f, 1.5f), up, 0.5f, 0.5f));
        assert_int_equal(rl_shadowmap_memory(sm) >= 6u * 256 * 256 * sizeof(float), true);
        rl_shadowmap_release(sm);
        rl_scene_release(s);
    }
}

static void test_shadowmap_rejects_directional_lights_and_bad_arguments(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    rl_shadowmap *sm = NULL;
    assert_int_equal(rl_scene_create_builtin("spheres", NULL, &s), RL_OK);  /* has a sun */
    rl_clear_error();
    assert_int_equal(rl_shadowmap_create(s, NULL, &sm), RL_ERR_UNSUPPORTED);
    assert_null(sm);
    assert_true(strstr(rl_last_error(), "directional") != NULL);
    rl_clear_error();
    rl_scene_release(s);

    s = occluder_scene(RL_LIGHT_POINT);
    assert_int_equal(rl_shadowmap_create(NULL, NULL, &sm), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_shadowmap_create(s, NULL, NULL), RL_ERR_INVALID_ARG);
    const rl_shadowmap_desc bad[] = {
        { .size = -1 }, { .size = 100000 }, { .bias = -0.1f }, { .slope_bias = NAN },
        { .pcf_radius = -1.0f }, { .pcf_radius = 1000.0f },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        assert_int_equal(rl_shadowmap_create(s, &bad[i], &sm), RL_ERR_INVALID_ARG);
        assert_null(sm);
    }
    rl_clear_error();
    rl_scene_release(s);

    rl_scene *open = NULL;
    assert_int_equal(rl_scene_create(&open), RL_OK);
    assert_int_equal(rl_shadowmap_create(open, NULL, &sm), RL_ERR_NOT_COMMITTED);
    rl_clear_error();
    rl_scene_release(open);
    rl_shadowmap_release(NULL);
    assert_true(rl_shadowmap_build_ms(NULL) == 0.0);
}

/* Build times at the thesis' 1024^2 (Sec. 9.2) on its test scenes; the
 * dragon only without AddressSanitizer. */
static void test_shadowmap_build_time_on_the_line_space_scenes(void **state)
{
    (void)state;
    const char *scenes[][2] = { { "ls-cornell", NULL }, { "ls-open", NULL },
                                { "ls-open", "model=dragon" } };
#if defined(__SANITIZE_ADDRESS__)
    const size_t count = 2;
#else
    const size_t count = 3;
#endif
    for (size_t i = 0; i < count; ++i) {
        rl_scene *s = NULL;
        rl_shadowmap *sm = NULL;
        assert_int_equal(rl_scene_create_builtin(scenes[i][0], scenes[i][1], &s), RL_OK);
        const rl_scene_data *d = rl_scene_get_data(s);
        assert_int_equal(rl_shadowmap_create(s, NULL, &sm), RL_OK);
        print_message("shadow maps %s %s: %u triangles, %u lights: %.0f ms, %.0f MiB\n",
                      scenes[i][0], scenes[i][1] ? scenes[i][1] : "", d->num_triangles,
                      d->num_lights, rl_shadowmap_build_ms(sm),
                      (double)rl_shadowmap_memory(sm) / (1 << 20));
        assert_true(rl_shadowmap_memory(sm) >= d->num_lights * 6u * 1024 * 1024 * sizeof(float));
        /* ls-open: the floor right under the object is dark for every light. */
        for (uint32_t li = 0; li < d->num_lights && i > 0; ++li)
            assert_false(rl_shadowmap_visible(sm, li, rl_v3(0.0f, 0.0f, 0.0f),
                                              rl_v3(0.0f, 1.0f, 0.0f), 0.5f, 0.5f));
        rl_shadowmap_release(sm);
        rl_scene_release(s);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_shadowmap_agrees_with_shadow_rays_in_the_cornell_box),
        cmocka_unit_test(test_point_under_an_occluder_is_shadowed_and_one_in_the_open_lit),
        cmocka_unit_test(test_shadowmap_rejects_directional_lights_and_bad_arguments),
        cmocka_unit_test(test_shadowmap_build_time_on_the_line_space_scenes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
