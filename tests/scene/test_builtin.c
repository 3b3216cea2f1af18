/* test_builtin.c: the built-in scenes (cornell, cornell-teapot, spheres,
 * city) and their parameter handling. The default city is heavy and is
 * built exactly once. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_scene.h"

static rl_scene *build(const char *name, const char *params)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_create_builtin(name, params, &s);
    if (st != RL_OK)
        fail_msg("%s (%s): %s", name, params ? params : "", rl_last_error());
    assert_true(rl_scene_is_committed(s));
    return s;
}

static void assert_within(double value, double target, double rel)
{
    if (!(value >= target * (1.0 - rel) && value <= target * (1.0 + rel)))
        fail_msg("%g is not within %g %% of %g", value, 100.0 * rel, target);
}

static void test_builtin_list_names_every_scene(void **state)
{
    (void)state;
    size_t n = 0;
    const rl_builtin_info *info = rl_builtin_scenes(&n);
    const char *expected[] = { "cornell", "cornell-teapot", "spheres", "city", "table", "cluster",
                               "ls-open", "ls-cornell" };
    assert_int_equal(n, sizeof expected / sizeof expected[0]);
    for (size_t i = 0; i < n; ++i) {
        assert_string_equal(info[i].name, expected[i]);
        assert_true(strlen(info[i].description) > 0);
        /* Every parameter is a table row with a default the table accepts:
         * the scene builds from the defaults spelled out. */
        for (size_t k = 0; k < info[i].num_options; ++k) {
            const rl_option_info *o = &info[i].options[k];
            assert_true(o->key && o->default_value && o->help && strlen(o->help) > 0);
        }
    }
    assert_true(info[0].num_options == 1 && info[3].num_options == 8);   /* cornell variant, city 8 */
}

static void test_cornell_has_36_triangles_and_a_downward_quad_light(void **state)
{
    (void)state;
    rl_scene *s = build("cornell", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 36);
    assert_string_equal(rl_scene_name(s), "cornell");
    int quads = 0;
    for (uint32_t i = 0; i < d->num_lights; ++i)
        if (d->lights[i].type == RL_LIGHT_QUAD) {
            ++quads;
            /* Emits on the side of cross(edge_u, edge_v): down into the box,
             * from just below the ceiling. */
            assert_true(rl_cross(d->lights[i].edge_u, d->lights[i].edge_v).y < 0.0f);
            assert_true(d->lights[i].position.y < 0.5488f && d->lights[i].position.y > 0.54f);
        }
    assert_int_equal(quads, 1);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.emissive_triangles, 2);
    assert_int_equal(st.dropped_degenerate, 0);
    /* Colours and camera of the Cornell data. */
    uint32_t red = rl_scene_find_material(s, "red");
    assert_int_not_equal(red, RL_NONE);
    assert_true(d->materials[red].diffuse.x == 0.65f && d->materials[red].diffuse.y == 0.05f);
    assert_int_not_equal(rl_scene_find_material(s, "green"), RL_NONE);
    assert_int_not_equal(rl_scene_find_material(s, "white"), RL_NONE);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    assert_true(fabsf(cam.fov_deg - 39.3f) < 1e-4f);
    assert_int_equal(cam.width, cam.height);
    assert_true(cam.eye.z < d->bounds.min.z);   /* at the opening, looking in */
    /* Metres: the box is about 0.55 m on each side. */
    assert_within(rl_aabb_extent(d->bounds).y, 0.5488, 0.001);
    rl_scene_release(s);
}

static void test_cornell_bitterli_variant_has_bitterlis_albedos_and_a_black_lamp(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", "variant=bitterli", &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_non_null(d);
    assert_int_equal(d->num_triangles, 36);
    const rl_material *white = &d->materials[rl_scene_find_material(s, "white")];
    const rl_material *green = &d->materials[rl_scene_find_material(s, "green")];
    const rl_material *lamp = &d->materials[rl_scene_find_material(s, "light")];
    assert_float_equal(white->diffuse.y, 0.71f, 1e-6f);
    assert_float_equal(green->diffuse.z, 0.091f, 1e-6f);
    assert_true(rl_vmax_comp(lamp->diffuse) == 0.0f && lamp->emission.x == 17.0f);
    assert_string_equal(rl_scene_node_attr(s, RL_NODE_ROOT, "max_path_length"), "7");
    rl_scene_release(s);
    /* The classic box keeps its materials and no path length. */
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    assert_float_equal(rl_scene_get_data(s)->materials[rl_scene_find_material(s, "white")].diffuse.y, 0.73f, 1e-6f);
    assert_null(rl_scene_node_attr(s, RL_NODE_ROOT, "max_path_length"));
    rl_scene_release(s);
}

static void test_cornell_teapot_defaults_to_about_15700_triangles(void **state)
{
    (void)state;
    rl_scene *s = build("cornell-teapot", NULL);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_within((double)st.triangles, 15700.0, 0.02);
    assert_int_equal(st.dropped_degenerate, 0);
    uint32_t teapot = rl_scene_find_material(s, "teapot");
    assert_int_not_equal(teapot, RL_NONE);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_true(d->materials[teapot].specular.x > 0.0f);
    /* Blocks removed, the teapot stands inside the box. */
    assert_int_equal(rl_scene_find_node(s, "tall_block"), RL_NONE);
    for (uint32_t i = 0; i < d->num_objects; ++i)
        if (strcmp(d->objects[i].name, "teapot") == 0) {
            assert_true(d->objects[i].bounds.min.y >= -1e-6f);
            assert_true(d->objects[i].bounds.min.x > 0.0f && d->objects[i].bounds.max.x < 0.55f);
        }
    rl_scene_release(s);
}

static void test_cornell_teapot_honours_the_triangle_budget(void **state)
{
    (void)state;
    rl_scene *s = build("cornell-teapot", "triangles=70000");
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_within((double)st.triangles, 70000.0, 0.02);
    rl_scene_release(s);
}

static void test_spheres_has_mirror_glass_and_a_textured_floor(void **state)
{
    (void)state;
    rl_scene *s = build("spheres", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    bool mirror = false, glass = false, textured = false;
    for (uint32_t i = 0; i < d->num_materials; ++i) {
        const rl_material *m = &d->materials[i];
        mirror |= m->reflectivity >= 0.85f;
        glass |= m->transmissivity >= 0.85f && m->ior == 1.5f;
        textured |= m->diffuse_texture != RL_NONE && m->diffuse_texture < d->num_textures;
    }
    assert_true(mirror && glass && textured);
    assert_true(d->num_textures >= 1);
    assert_true(d->num_lights >= 2);
    assert_true(d->num_cameras >= 1);
    /* Materials used by triangles include both the mirror and the glass. */
    bool used_mirror = false, used_glass = false;
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        const rl_material *m = &d->materials[d->triangle_material[t]];
        used_mirror |= m->reflectivity >= 0.85f;
        used_glass |= m->transmissivity >= 0.85f;
    }
    assert_true(used_mirror && used_glass);
    rl_scene_release(s);

    s = build("spheres", "rows=3,cols=5");
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.objects, 3 * 5 + 1);
    rl_scene_release(s);
}

static void test_city_default_is_large_enough_for_visibility_work(void **state)
{
    (void)state;
    rl_scene *s = build("city", NULL);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    if (st.objects < 1000 || st.triangles < 1000000)
        fail_msg("city: %u objects, %llu triangles", st.objects, (unsigned long long)st.triangles);
    rl_vec3 e = rl_aabb_extent(st.bounds);
    assert_true(e.x >= 300.0f && e.z >= 300.0f);
    assert_true(e.y > 20.0f);                 /* buildings, y up */
    assert_true(st.meshes < st.objects / 10);  /* instancing */
    assert_int_equal(st.dropped_degenerate, 0);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, "street", &cam), RL_OK);
    assert_true(cam.eye.y < 2.0f);
    assert_int_equal(rl_scene_get_camera(s, "overview", &cam), RL_OK);
    uint32_t buildings = 0;
    for (uint32_t n = 0; n < rl_scene_node_count(s); ++n) {
        const char *kind = rl_scene_node_attr(s, n, "kind");
        buildings += kind && strcmp(kind, "building") == 0;
    }
    assert_true(buildings >= 100);
    rl_scene_release(s);
}

static void city_signature(const char *params, rl_scene_stats *st)
{
    rl_scene *s = build("city", params);
    rl_scene_get_stats(s, st);
    rl_scene_release(s);
}

static void test_city_is_deterministic_for_a_seed(void **state)
{
    (void)state;
    rl_scene_stats a, b, c;
    city_signature("blocks=2,seed=7", &a);
    city_signature("blocks=2,seed=7", &b);
    city_signature("blocks=2,seed=8", &c);
    assert_int_equal(a.triangles, b.triangles);
    assert_int_equal(a.objects, b.objects);
    assert_memory_equal(&a.bounds, &b.bounds, sizeof a.bounds);
    assert_true(a.triangles != c.triangles || a.objects != c.objects ||
                a.bounds.max.y != c.bounds.max.y);
    /* Less detail, fewer triangles, same layout. */
    rl_scene_stats low;
    city_signature("blocks=2,seed=7,detail=0", &low);
    assert_true(low.triangles < a.triangles / 2);
    assert_int_equal(low.objects, a.objects);
}

static void test_unknown_builtin_is_not_found(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("sponza", NULL, &s), RL_ERR_NOT_FOUND);
    assert_null(s);
    assert_non_null(strstr(rl_last_error(), "cornell"));   /* lists the built-ins */
    rl_clear_error();
}

static void test_unknown_parameter_is_invalid(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", "triangles=10", &s), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "variant"));     /* lists the accepted keys */
    rl_clear_error();
    assert_int_equal(rl_scene_create_builtin("cornell", "variant=mitsuba", &s), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "bitterli"));
    rl_clear_error();
    assert_int_equal(rl_scene_create_builtin("city", "blocks=65", &s), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "outside [1, 64]"));
    rl_clear_error();
    assert_int_equal(rl_scene_create_builtin("city", "bounce=2", &s), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "floors_max"));  /* lists the accepted keys */
    rl_clear_error();
    assert_int_equal(rl_scene_create_builtin("spheres", "rows", &s), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_null(s);
}

static void test_absurd_parameters_fail_cleanly(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    static const char *const cases[][2] = {
        { "cornell-teapot", "triangles=-5" },
        { "cornell-teapot", "triangles=99999999999" },
        { "cornell-teapot", "size=nan" },
        { "city", "blocks=100000" },
        { "city", "blocks=0" },
        { "city", "floors_min=9,floors_max=3" },
        { "city", "seed=-1" },
        { "spheres", "rows=1000000" },
        /* Within every range but too big as a whole: refused before commit. */
        { "city", "blocks=64,floors_min=200,floors_max=200" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        rl_status st = rl_scene_create_builtin(cases[i][0], cases[i][1], &s);
        if (st != RL_ERR_INVALID_ARG && st != RL_ERR_LIMIT)
            fail_msg("%s %s: status %s", cases[i][0], cases[i][1], rl_status_name(st));
        assert_null(s);
        rl_clear_error();
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_builtin_list_names_every_scene),
        cmocka_unit_test(test_cornell_has_36_triangles_and_a_downward_quad_light),
        cmocka_unit_test(test_cornell_bitterli_variant_has_bitterlis_albedos_and_a_black_lamp),
        cmocka_unit_test(test_cornell_teapot_defaults_to_about_15700_triangles),
        cmocka_unit_test(test_cornell_teapot_honours_the_triangle_budget),
        cmocka_unit_test(test_spheres_has_mirror_glass_and_a_textured_floor),
        cmocka_unit_test(test_city_default_is_large_enough_for_visibility_work),
        cmocka_unit_test(test_city_is_deterministic_for_a_seed),
        cmocka_unit_test(test_unknown_builtin_is_not_found),
        cmocka_unit_test(test_unknown_parameter_is_invalid),
        cmocka_unit_test(test_absurd_parameters_fail_cleanly),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
