/* test_whitted.c: renderer "whitted" against other accelerators, other
 * thread counts, the raster renderer (visibility, unshadowed diffuse
 * light) and its own counters; option validation, ray-tree access and
 * cancellation. Small images so the ASan build stays fast. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/whitted.h"
#include "rl/rl_accel.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render/render_fixtures.h"

#define ALL_LAYERS FX_ALL_LAYERS
#define SIZE 48

static void test_whitted_is_registered_and_refuses_bad_options(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("whitted", NULL);
    assert_string_equal(rl_renderer_get(r, "accel"), "bvh");
    assert_int_equal(rl_renderer_set(r, "accel", "octree"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "ss", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "ss", "17"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "max_depth", "65"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "area_samples", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "background", "red"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "ambient", "2"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "bounces", "2"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "whitted.background", "0.1,0.2,0.3"), RL_OK);
    assert_int_equal(rl_renderer_set(r, "accel", "embree"),
                     rl_accel_kind_available(RL_ACCEL_EMBREE) ? RL_OK : RL_ERR_INVALID_ARG);
    rl_renderer_release(r);
}

static void test_cornell_is_identical_with_bvh_and_brute_force(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    rl_render_stats st_bvh, st_brute;
    rl_image *bvh = fx_render("whitted", s, &cam, ALL_LAYERS,
                              (const char *const[]){ "accel", "bvh", NULL }, &st_bvh);
    rl_image *brute = fx_render("whitted", s, &cam, ALL_LAYERS,
                                (const char *const[]){ "accel", "brute", NULL }, &st_brute);
    fx_assert_images_identical(bvh, brute);
    assert_memory_equal(st_bvh.rays, st_brute.rays, sizeof st_bvh.rays);
    assert_int_equal(st_bvh.rays[RL_RAY_PRIMARY], SIZE * SIZE);
    assert_true(st_bvh.rays[RL_RAY_SHADOW] > 0);
    assert_int_equal(st_bvh.samples, SIZE * SIZE);
    rl_image_release(bvh);
    rl_image_release(brute);
    rl_scene_release(s);
}

static void test_image_does_not_depend_on_the_thread_count(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    rl_image *one = fx_render("whitted", s, &cam, ALL_LAYERS,
                              (const char *const[]){ "threads", "1", NULL }, NULL);
    rl_image *two = fx_render("whitted", s, &cam, ALL_LAYERS,
                              (const char *const[]){ "threads", "2", NULL }, NULL);
    fx_assert_images_identical(one, two);
    rl_image_release(one);
    rl_image_release(two);
    rl_scene_release(s);
}

static void test_supersampling_traces_ss_squared_primary_rays_per_pixel(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    cam.width = cam.height = 24;
    rl_render_stats st1, st2;
    rl_image *a = fx_render("whitted", s, &cam, ALL_LAYERS,
                            (const char *const[]){ "ss", "1", NULL }, &st1);
    rl_image *b = fx_render("whitted", s, &cam, ALL_LAYERS,
                            (const char *const[]){ "ss", "2", NULL }, &st2);
    assert_int_equal(st1.rays[RL_RAY_PRIMARY], 24 * 24);
    assert_int_equal(st2.rays[RL_RAY_PRIMARY], 4 * 24 * 24);
    assert_int_equal(st2.samples, 4 * 24 * 24);
    assert_int_equal(st2.pixels_written, 24 * 24);
    assert_true(st2.rays[RL_RAY_SHADOW] > 3 * st1.rays[RL_RAY_SHADOW]);
    /* Antialiased, not a copy: some silhouette pixel changes colour. */
    assert_memory_not_equal(a->color, b->color, (size_t)24 * 24 * sizeof *a->color);
    rl_image_release(a);
    rl_image_release(b);
    rl_scene_release(s);
}

static void test_depth_and_ids_agree_with_the_raster_renderer(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    rl_image *ras = fx_render("raster", s, &cam, ALL_LAYERS, NULL, NULL);
    rl_image *wt = fx_render("whitted", s, &cam, ALL_LAYERS, NULL, NULL);
    int n = SIZE * SIZE, same = 0, hits = 0;
    for (int p = 0; p < n; ++p) {
        if (wt->object_id[p] != ras->object_id[p])
            continue;
        ++same;
        if (wt->object_id[p] == RL_ID_NONE) {
            assert_true(isinf(wt->depth[p]));
            continue;
        }
        ++hits;
        assert_float_equal(wt->depth[p], ras->depth[p], 1e-3 * ras->depth[p]);
        assert_float_equal(wt->color[p].w, 1.0f, 0.0f);
    }
    assert_true(hits > n / 2);
    assert_true(same * 100 >= 99 * n);
    rl_image_release(ras);
    rl_image_release(wt);
    rl_scene_release(s);
}

/* A finely tessellated matte floor under a point light: per-vertex raster
 * lighting (gouraud) and per-pixel tracing agree up to interpolation. */
static rl_scene *lit_floor(rl_camera *cam)
{
    enum { N = 32 };
    rl_vec3 pos[(N + 1) * (N + 1)];
    uint32_t idx[N * N * 6], *t = idx;
    for (int j = 0; j <= N; ++j)
        for (int i = 0; i <= N; ++i)
            pos[j * (N + 1) + i] = rl_v3(-2.0f + 4.0f * i / N, 0.0f, -2.0f + 4.0f * j / N);
    for (int j = 0; j < N; ++j)
        for (int i = 0; i < N; ++i) {
            uint32_t a = (uint32_t)(j * (N + 1) + i), b = a + 1, c = a + N + 2, d = a + N + 1;
            *t++ = a; *t++ = c; *t++ = b;
            *t++ = a; *t++ = d; *t++ = c;
        }
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse = rl_v3(0.7f, 0.5f, 0.3f);
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    rl_mesh_desc md = { .name = "floor", .num_vertices = (N + 1) * (N + 1), .positions = pos,
                        .num_triangles = N * N * 2, .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "floor", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    rl_light l = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = 3.0f,
                   .position = rl_v3(0.3f, 1.5f, 0.2f) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    *cam = (rl_camera){ .eye = rl_v3(0.0f, 3.0f, 3.0f), .target = rl_v3(0.0f, 0.0f, 0.0f),
                        .fov_deg = 50.0f, .width = SIZE, .height = SIZE };
    return s;
}

static void test_unshadowed_diffuse_floor_matches_gouraud_raster(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = lit_floor(&cam);
    rl_image *ras = fx_render("raster", s, &cam, ALL_LAYERS,
                              (const char *const[]){ "shading", "gouraud", NULL },
                              NULL);
    rl_image *wt = fx_render("whitted", s, &cam, ALL_LAYERS,
                             (const char *const[]){ "shadows", "false", "max_depth", "0", NULL }, NULL);
    double sum_abs = 0.0, sum = 0.0;
    int compared = 0;
    for (int p = 0; p < SIZE * SIZE; ++p) {
        if (wt->object_id[p] == RL_ID_NONE || ras->object_id[p] != wt->object_id[p])
            continue;
        sum_abs += fabs((double)wt->color[p].x - ras->color[p].x);
        sum += ras->color[p].x;
        ++compared;
    }
    assert_true(compared > SIZE * SIZE / 2);
    assert_true(sum_abs < 0.01 * sum);      /* mean relative difference under 1 % */
    rl_image_release(ras);
    rl_image_release(wt);
    rl_scene_release(s);
}

static void test_max_depth_zero_traces_no_secondary_rays(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("spheres", NULL, &s), RL_OK);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = cam.height = 16;
    rl_render_stats flat, deep;
    rl_image *a = fx_render("whitted", s, &cam, ALL_LAYERS,
                            (const char *const[]){ "max_depth", "0", NULL }, &flat);
    rl_image *b = fx_render("whitted", s, &cam, ALL_LAYERS, NULL, &deep);
    assert_int_equal(flat.rays[RL_RAY_REFLECTION] + flat.rays[RL_RAY_REFRACTION], 0);
    assert_true(deep.rays[RL_RAY_REFLECTION] > 0);
    assert_true(deep.rays[RL_RAY_REFRACTION] > 0);
    rl_image_release(a);
    rl_image_release(b);
    rl_scene_release(s);
}

/* The shading modes +-S +-R +-T of Ullmann 2003, Figs. 5.9/5.10, in both
 * ray tracers: each switch removes exactly its ray type and changes the
 * image; the other types are still traced. */
static void test_shading_modes_switch_their_ray_types_off(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("table", NULL, &s), RL_OK);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = 40;
    cam.height = 30;
    const char *const algos[] = { "whitted", "vt" };
    const char *const keys[] = { "shadows", "reflections", "transmission" };
    const rl_ray_type types[] = { RL_RAY_SHADOW, RL_RAY_REFLECTION, RL_RAY_REFRACTION };
    for (int a = 0; a < 2; ++a) {
        rl_render_stats all;
        rl_image *full = fx_render(algos[a], s, &cam, ALL_LAYERS, NULL, &all);
        for (int k = 0; k < 3; ++k)
            assert_true(all.rays[types[k]] > 0);
        for (int k = 0; k < 3; ++k) {
            rl_render_stats st;
            rl_image *img = fx_render(algos[a], s, &cam, ALL_LAYERS, (const char *const[]){ keys[k], "false", NULL },
                                      &st);
            for (int j = 0; j < 3; ++j)
                if (j == k)
                    assert_int_equal(st.rays[types[j]], 0);
                else
                    assert_true(st.rays[types[j]] > 0);
            size_t differ = 0;
            for (int i = 0; i < cam.width * cam.height; ++i)
                differ += fabsf(img->color[i].x - full->color[i].x) > 1e-3f;
            assert_true(differ > 0);
            rl_image_release(img);
        }
        rl_image_release(full);
    }
    rl_scene_release(s);
}

static void test_pixel_trees_are_kept_on_request_and_match_the_ids(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    cam.width = cam.height = 16;
    rl_ray_tree tree;
    rl_renderer *r = fx_make("whitted", NULL);
    assert_int_equal(rl_whitted_pixel_tree(r, 0, 0, &tree), RL_ERR_NOT_FOUND);
    rl_image *plain = fx_render_with(r, s, &cam, ALL_LAYERS, NULL);
    assert_int_equal(rl_whitted_pixel_tree(r, 0, 0, &tree), RL_ERR_NOT_FOUND);
    assert_int_equal(rl_renderer_set(r, "ray_trees", "true"), RL_OK);
    rl_image *img = fx_render_with(r, s, &cam, ALL_LAYERS, NULL);
    fx_assert_images_identical(plain, img);        /* keeping trees changes nothing */
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            assert_int_equal(rl_whitted_pixel_tree(r, x, y, &tree), RL_OK);
            assert_true(tree.count >= 1);
            assert_int_equal(tree.nodes[0].type, RL_RAY_PRIMARY);
            assert_int_equal(tree.nodes[0].object, img->object_id[y * 16 + x]);
        }
    assert_int_equal(rl_whitted_pixel_tree(r, 16, 0, &tree), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_whitted_pixel_tree(NULL, 0, 0, &tree), RL_ERR_INVALID_ARG);
    rl_renderer *ras = fx_make("raster", NULL);
    assert_int_equal(rl_whitted_pixel_tree(ras, 0, 0, &tree), RL_ERR_INVALID_ARG);
    rl_renderer_release(ras);
    rl_image_release(plain);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* The cached accel must follow a new scene (and a new accel kind). */
static void test_cached_accel_follows_scene_and_kind_changes(void **state)
{
    (void)state;
    rl_camera cam_c, cam_f;
    rl_scene *box = fx_cornell(&cam_c, SIZE);
    rl_scene *floor = lit_floor(&cam_f);
    rl_renderer *r = fx_make("whitted", NULL);
    rl_image *a = fx_render_with(r, box, &cam_c, ALL_LAYERS, NULL);
    rl_image *b = fx_render_with(r, floor, &cam_f, ALL_LAYERS, NULL);
    assert_int_equal(rl_renderer_set(r, "accel", "grid"), RL_OK);
    rl_image *c = fx_render_with(r, box, &cam_c, ALL_LAYERS, NULL);
    rl_image *fresh_b = fx_render("whitted", floor, &cam_f, ALL_LAYERS, NULL, NULL);
    fx_assert_images_identical(a, c);
    fx_assert_images_identical(b, fresh_b);
    rl_image_release(a);
    rl_image_release(b);
    rl_image_release(c);
    rl_image_release(fresh_b);
    rl_renderer_release(r);
    rl_scene_release(box);
    rl_scene_release(floor);
}

static bool cancel_midway(void *user, double done)
{
    int *calls = user;
    ++*calls;
    return done < 0.5;
}

static void test_a_view_of_nothing_renders_the_background(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    /* Turn round: the box is behind the eye, nothing is in view. */
    cam.target = rl_add(cam.eye, rl_sub(cam.eye, cam.target));
    rl_render_stats st;
    rl_image *img = fx_render("whitted", s, &cam, ALL_LAYERS,
                              (const char *const[]){ "background", "0.25,0.5,0.75", NULL }, &st);
    for (int i = 0; i < SIZE * SIZE; ++i) {
        assert_true(img->color[i].x == 0.25f && img->color[i].y == 0.5f && img->color[i].z == 0.75f);
        assert_int_equal(img->object_id[i], RL_ID_NONE);
        assert_true(isinf(img->depth[i]));
    }
    assert_int_equal(st.rays[RL_RAY_PRIMARY], SIZE * SIZE);
    assert_int_equal(st.rays[RL_RAY_SHADOW] + st.rays[RL_RAY_REFLECTION] + st.rays[RL_RAY_REFRACTION], 0);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_progress_callback_can_cancel_the_frame(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    rl_renderer *r = fx_make("whitted", NULL);
    int calls = 0;
    rl_renderer_set_progress(r, cancel_midway, &calls);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(SIZE, SIZE, RL_LAYER_COLOR, &img), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_CANCELLED);
    assert_true(calls > 1);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_whitted_is_registered_and_refuses_bad_options),
        cmocka_unit_test(test_cornell_is_identical_with_bvh_and_brute_force),
        cmocka_unit_test(test_image_does_not_depend_on_the_thread_count),
        cmocka_unit_test(test_supersampling_traces_ss_squared_primary_rays_per_pixel),
        cmocka_unit_test(test_depth_and_ids_agree_with_the_raster_renderer),
        cmocka_unit_test(test_unshadowed_diffuse_floor_matches_gouraud_raster),
        cmocka_unit_test(test_max_depth_zero_traces_no_secondary_rays),
        cmocka_unit_test(test_shading_modes_switch_their_ray_types_off),
        cmocka_unit_test(test_pixel_trees_are_kept_on_request_and_match_the_ids),
        cmocka_unit_test(test_cached_accel_follows_scene_and_kind_changes),
        cmocka_unit_test(test_a_view_of_nothing_renders_the_background),
        cmocka_unit_test(test_progress_callback_can_cancel_the_frame),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
