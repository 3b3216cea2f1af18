/* test_property_visibility.c: the "visibility" property (Jähn 2015,
 * Sec. 4.2.2) against hand-counted pixels. The viewer sits at the centre of
 * a closed box of six separate quads, so with 90° faces every quad fills
 * exactly one face; further quads are placed where their projection has
 * edges on pixel boundaries, so the top-left fill rule gives an exact
 * count (a pixel is covered when its centre is inside). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl.h"
#include "rl/rl_property.h"

#define RES 32
#define FACE (RES * RES)

/* ---- scenes ------------------------------------------------------------ */

static uint32_t add_material(rl_scene *s)
{
    rl_material m = rl_material_default();
    uint32_t id;
    assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
    return id;
}

/* One object: the quad a, b, c, d (two triangles). */
static void add_quad(rl_scene *s, uint32_t material, rl_vec3 a, rl_vec3 b, rl_vec3 c, rl_vec3 d)
{
    const rl_vec3 pos[4] = { a, b, c, d };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc md = { .name = "quad", .num_vertices = 4, .positions = pos,
                        .num_triangles = 2, .indices = idx, .material = material };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "quad", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

/* A quad in the plane x = x0 spanning y0..y1, z0..z1. */
static void add_x_quad(rl_scene *s, uint32_t m, float x0, float y0, float y1, float z0, float z1)
{
    add_quad(s, m, rl_v3(x0, y0, z0), rl_v3(x0, y1, z0), rl_v3(x0, y1, z1), rl_v3(x0, y0, z1));
}

/* Objects 0..5: the six walls of the box [-1, 1]^3, in the order +x, -x,
 * +y, -y, +z, -z. */
static void add_box(rl_scene *s, uint32_t m)
{
    add_x_quad(s, m, 1, -1, 1, -1, 1);
    add_x_quad(s, m, -1, -1, 1, -1, 1);
    add_quad(s, m, rl_v3(-1, 1, -1), rl_v3(1, 1, -1), rl_v3(1, 1, 1), rl_v3(-1, 1, 1));
    add_quad(s, m, rl_v3(-1, -1, -1), rl_v3(1, -1, -1), rl_v3(1, -1, 1), rl_v3(-1, -1, 1));
    add_quad(s, m, rl_v3(-1, -1, 1), rl_v3(1, -1, 1), rl_v3(1, 1, 1), rl_v3(-1, 1, 1));
    add_quad(s, m, rl_v3(-1, -1, -1), rl_v3(1, -1, -1), rl_v3(1, 1, -1), rl_v3(-1, 1, -1));
}

static rl_scene *commit(rl_scene *s)
{
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static rl_scene *box_scene(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    add_box(s, add_material(s));
    return commit(s);
}

static rl_property *make_visibility(const rl_scene *s, const char *measure, int workers)
{
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "resolution", "32"), RL_OK);
    assert_int_equal(rl_property_set(p, "near", "0.1"), RL_OK);
    if (measure)
        assert_int_equal(rl_property_set(p, "measure", measure), RL_OK);
    assert_int_equal(rl_property_commit(p, s, workers), RL_OK);
    return p;
}

static double evaluate(rl_property *p, rl_vec3 pos, uint64_t *set, double *direction)
{
    rl_property_sample smp;
    memset(&smp, 0, sizeof smp);
    smp.set = set;
    assert_int_equal(rl_property_evaluate(p, 0, pos, &smp), RL_OK);
    if (direction)
        memcpy(direction, smp.direction, sizeof smp.direction);
    return smp.value;
}

/* ---- tests ------------------------------------------------------------- */

static void test_directions_are_the_six_axes_with_orthonormal_up(void **state)
{
    (void)state;
    const float want[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 },
                               { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
    for (int i = 0; i < 6; ++i) {
        rl_vec3 d, up;
        rl_property_direction(i, &d, &up);
        assert_true(d.x == want[i][0] && d.y == want[i][1] && d.z == want[i][2]);
        assert_true(rl_length(up) == 1.0f);
        assert_true(rl_dot(d, up) == 0.0f);
    }
    rl_vec3 d = rl_v3s(7), up = rl_v3s(7);
    rl_property_direction(6, &d, &up);
    assert_true(rl_length(d) == 0.0f && rl_length(up) == 0.0f);
}

static void test_viewer_in_a_box_sees_each_wall_fill_one_face(void **state)
{
    (void)state;
    rl_scene *s = box_scene();
    rl_property *objects = make_visibility(s, NULL, 1);
    rl_property *polygons = make_visibility(s, "polygons", 1);
    rl_property *pixels = make_visibility(s, "pixels", 1);
    assert_string_equal(rl_property_unit(objects), "objects");
    assert_int_equal(rl_property_set_size(objects), 6);
    assert_int_equal(rl_property_set_words(objects), 1);

    const rl_vec3 centre = rl_v3(0, 0, 0);
    uint64_t set = 0;
    double dir[6];
    assert_true(evaluate(objects, centre, &set, dir) == 6.0);
    assert_true(set == 0x3Fu);
    for (int i = 0; i < 6; ++i)
        assert_true(dir[i] == 1.0);
    assert_true(evaluate(polygons, centre, NULL, dir) == 12.0);
    for (int i = 0; i < 6; ++i)
        assert_true(dir[i] == 2.0);
    assert_true(evaluate(pixels, centre, NULL, dir) == 6.0 * FACE);
    for (int i = 0; i < 6; ++i)
        assert_true(dir[i] == FACE);

    uint32_t per_object[6];
    assert_int_equal(rl_property_object_pixels(objects, 0, centre, per_object), RL_OK);
    for (int o = 0; o < 6; ++o)
        assert_int_equal(per_object[o], FACE);
    /* the pixel counts are a visibility-only accessor */
    assert_int_equal(rl_property_object_pixels(NULL, 0, centre, per_object), RL_ERR_INVALID_ARG);

    rl_property_release(objects);
    rl_property_release(polygons);
    rl_property_release(pixels);
    rl_scene_release(s);
}

static void test_hidden_and_too_near_objects_are_not_visible(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t m = add_material(s);
    add_box(s, m);
    /* object 6: behind the +x wall, hidden */
    add_x_quad(s, m, 1.5f, -0.5f, 0.5f, -0.5f, 0.5f);
    /* object 7: in front of the viewer but entirely closer than near = 0.1
     * (Jähn 2015, Fig. 4.2: "liegt vollständig vor den Nahebenen") */
    add_x_quad(s, m, 0.05f, -0.01f, 0.01f, -0.01f, 0.01f);
    commit(s);
    rl_property *p = make_visibility(s, NULL, 1);
    assert_int_equal(rl_property_set_size(p), 8);
    uint64_t set = ~UINT64_C(0);
    assert_true(evaluate(p, rl_v3(0, 0, 0), &set, NULL) == 6.0);
    assert_true(set == 0x3Fu);
    uint32_t per_object[8];
    assert_int_equal(rl_property_object_pixels(p, 0, rl_v3(0, 0, 0), per_object), RL_OK);
    assert_int_equal(per_object[6], 0);
    assert_int_equal(per_object[7], 0);

    /* with a nearer near plane the small quad is seen again */
    rl_property *q = NULL;
    assert_int_equal(rl_property_create("visibility", &q), RL_OK);
    assert_int_equal(rl_property_set(q, "visibility.resolution", "32"), RL_OK);
    assert_int_equal(rl_property_set(q, "near", "0.01"), RL_OK);
    assert_int_equal(rl_property_commit(q, s, 1), RL_OK);
    assert_true(evaluate(q, rl_v3(0, 0, 0), &set, NULL) == 7.0);
    assert_true(set == 0xBFu);
    rl_property_release(q);
    rl_property_release(p);
    rl_scene_release(s);
}

static void test_partial_quad_covers_the_hand_counted_pixels(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t m = add_material(s);
    add_box(s, m);
    /* Object 6 at x = 0.5 in the +x face (right = +z, up = +y): its edges
     * project to z/x = -0.25 .. 0.5 and y/x = 0 .. 0.5, i.e. columns
     * (1 + z/x) / 2 * 32 = 12 .. 24 and rows (1 - y/x) / 2 * 32 = 8 .. 16:
     * 12 x 8 = 96 pixels, all edges on pixel boundaries. */
    add_x_quad(s, m, 0.5f, 0.0f, 0.25f, -0.125f, 0.25f);
    commit(s);
    rl_property *p = make_visibility(s, NULL, 1);
    uint32_t per_object[7];
    assert_int_equal(rl_property_object_pixels(p, 0, rl_v3(0, 0, 0), per_object), RL_OK);
    assert_int_equal(per_object[6], 96);
    assert_int_equal(per_object[0], FACE - 96);
    for (int o = 1; o < 6; ++o)
        assert_int_equal(per_object[o], FACE);
    double dir[6];
    assert_true(evaluate(p, rl_v3(0, 0, 0), NULL, dir) == 7.0);
    assert_true(dir[0] == 2.0 && dir[1] == 1.0);

    /* Off-centre: from (-0.5, 0, 0) object 6 is 1 away along x, so it
     * projects to z/x = -0.125 .. 0.25 and y/x = 0 .. 0.25: columns 14 .. 20,
     * rows 12 .. 16, 24 pixels; no other face sees it. */
    assert_int_equal(rl_property_object_pixels(p, 0, rl_v3(-0.5f, 0, 0), per_object), RL_OK);
    assert_int_equal(per_object[6], 24);
    rl_property_release(p);
    rl_scene_release(s);
}

static void test_two_workers_give_the_values_of_one(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t m = add_material(s);
    add_box(s, m);
    /* a few occluders inside the box so that values vary with position */
    for (int i = 0; i < 6; ++i) {
        float c = -0.6f + 0.25f * (float)i;
        add_x_quad(s, m, c, -0.3f + 0.1f * (float)i, 0.2f + 0.1f * (float)i, -0.7f, 0.1f * (float)i);
        add_quad(s, m, rl_v3(-0.4f, c, -0.2f), rl_v3(0.3f, c, -0.2f), rl_v3(0.3f, c, 0.4f),
                 rl_v3(-0.4f, c, 0.4f));
    }
    commit(s);
    enum { N = 48 };
    rl_vec3 pos[N];
    uint32_t seed = 12345u;
    for (int i = 0; i < N; ++i) {
        float c[3];
        for (int k = 0; k < 3; ++k) {
            seed = seed * 1664525u + 1013904223u;
            c[k] = 1.8f * ((float)(seed >> 8) / (float)(1u << 24)) - 0.9f;
        }
        pos[i] = rl_v3(c[0], c[1], c[2]);
    }

    rl_property *one = make_visibility(s, "pixels", 1);
    rl_property *two = make_visibility(s, "pixels", 2);
    assert_int_equal(rl_property_workers(two), 2);
    const size_t words = rl_property_set_words(one);
    double want[N], got[N];
    uint64_t *want_set = calloc(N * words, sizeof *want_set);
    uint64_t *got_set = calloc(N * words, sizeof *got_set);
    assert_non_null(want_set);
    assert_non_null(got_set);
    for (int i = 0; i < N; ++i)
        want[i] = evaluate(one, pos[i], want_set + (size_t)i * words, NULL);

    int failures = 0;
#pragma omp parallel for num_threads(2) schedule(dynamic, 1) reduction(+ : failures)
    for (int i = 0; i < N; ++i) {
        rl_property_sample smp = { .set = got_set + (size_t)i * words };
        failures += rl_property_evaluate(two, omp_get_thread_num(), pos[i], &smp) != RL_OK;
        got[i] = smp.value;
    }
    assert_int_equal(failures, 0);
    for (int i = 0; i < N; ++i)
        assert_true(got[i] == want[i]);
    assert_memory_equal(got_set, want_set, N * words * sizeof *got_set);
    free(want_set);
    free(got_set);
    rl_property_release(one);
    rl_property_release(two);
    rl_scene_release(s);
}

static void test_visibility_rejects_bad_options(void **state)
{
    (void)state;
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    const char *const bad[][2] = {
        { "resolution", "0" }, { "resolution", "5000" }, { "resolution", "1.5" },
        { "near", "0" },       { "near", "-1" },         { "near", "nan" },
        { "measure", "faces" }, { "far", "10" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rl_clear_error();
        assert_int_equal(rl_property_set(p, bad[i][0], bad[i][1]), RL_ERR_INVALID_ARG);
        assert_true(strlen(rl_last_error()) > 0);
    }
    assert_string_equal(rl_property_get(p, "resolution"), "1024");   /* untouched */
    assert_string_equal(rl_property_get(p, "near"), "0.1");
    assert_null(rl_property_get(p, "far"));
    rl_property_release(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_directions_are_the_six_axes_with_orthonormal_up),
        cmocka_unit_test(test_viewer_in_a_box_sees_each_wall_fill_one_face),
        cmocka_unit_test(test_hidden_and_too_near_objects_are_not_visible),
        cmocka_unit_test(test_partial_quad_covers_the_hand_counted_pixels),
        cmocka_unit_test(test_two_workers_give_the_values_of_one),
        cmocka_unit_test(test_visibility_rejects_bad_options),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
