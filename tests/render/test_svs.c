/* test_svs.c: Spherical Visibility Sampling (renderer "svs") draws only
 * what its sampled sets hold: from far away a fraction of the triangles at
 * high image quality, never an object sealed inside another, the same
 * image for 1 and 2 threads; with distance = 1000 (sets never used) it
 * equals raster. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl.h"

static rl_camera far_camera(void)
{
    rl_camera c = { .eye = rl_v3(-120.0f, 90.0f, -110.0f), .target = rl_v3(60, 0, 60), .fov_deg = 40.0f,
                    .width = 160, .height = 120 };
    return c;
}

static void test_svs_draws_less_at_high_quality_from_far(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_camera cam = far_camera();
    rl_render_stats full, st;
    rl_image *ref = fx_render("raster", s, &cam, RL_LAYER_COLOR, NULL, &full);
    rl_renderer *svs = fx_make("svs", (const char *const[]){ "max_depth", "3", NULL });
    rl_image *img = fx_render_with(svs, s, &cam, RL_LAYER_COLOR, &st);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(svs, &cs), RL_OK);
    assert_true(cs.preprocess_ms > 0.0);
    assert_true(st.triangles_rasterized < full.triangles_rasterized);
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(img, ref, NULL, &m), RL_OK);
    assert_true(m.ssim > 0.9);
    /* The second frame reuses the preprocessing. */
    rl_image *again = fx_render_with(svs, s, &cam, RL_LAYER_COLOR, &st);
    assert_int_equal(rl_culling_get_stats(svs, &cs), RL_OK);
    assert_true(cs.preprocess_ms == 0.0);
    fx_assert_images_identical(img, again);
    rl_image_release(again);
    rl_image_release(img);
    rl_renderer_release(svs);

    /* Thread count does not change the sets. */
    rl_image *one = fx_render("svs", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "threads", "1", NULL }, NULL);
    rl_image *two = fx_render("svs", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "threads", "2", NULL }, NULL);
    fx_assert_images_identical(one, two);
    rl_image_release(one);
    rl_image_release(two);

    /* Sets never used: the traversal draws every object in the frustum,
     * deepest first; with no coplanar faces that is raster's image. */
    rl_image *exact = fx_render("svs", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "distance", "1000", NULL },
                                NULL);
    rl_image *ref_all = fx_render("raster", s, &cam, FX_ALL_LAYERS, NULL, NULL);
    fx_assert_images_identical(exact, ref_all);
    rl_image_release(exact);
    rl_image_release(ref_all);
    rl_image_release(ref);
    rl_scene_release(s);
}

static void test_svs_never_draws_a_sealed_object(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t mat;
    rl_material m = rl_material_default();
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    fx_add_box(s, mat, rl_v3(0, 0, 0), rl_v3(10, 10, 10), 2);     /* the shell */
    fx_add_box(s, mat, rl_v3(4, 4, 4), rl_v3(6, 6, 6), 2);        /* inside it */
    fx_add_box(s, mat, rl_v3(20, 0, 0), rl_v3(22, 2, 2), 2);      /* outside, visible */
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_renderer *svs = fx_make("svs", (const char *const[]){ "max_depth", "0", NULL });
    for (int v = 0; v < 6; ++v) {
        float a = 1.1f * (float)v;
        rl_camera cam = { .eye = rl_v3(11 + 60 * cosf(a), 30.0f * sinf(2.0f * a), 60 * sinf(a)),
                          .target = rl_v3(11, 5, 5), .width = 96, .height = 96 };
        rl_render_stats st;
        rl_image *img = fx_render_with(svs, s, &cam, FX_ALL_LAYERS, &st);
        rl_culling_stats cs;
        assert_int_equal(rl_culling_get_stats(svs, &cs), RL_OK);
        assert_int_equal(cs.objects_drawn, 2);
        assert_int_equal(cs.triangles_drawn, 2 * 6 * 2 * 2 * 2);
        assert_true(st.triangles_rasterized <= cs.triangles_drawn);
        rl_image_release(img);
    }
    rl_renderer_release(svs);
    rl_scene_release(s);
}

/* The rasterizer and drawer kept between frames (culling.c, shared by
 * chcpp, svs, visset and surfels) follow the viewer, the drawing options,
 * the image's layers and the scene: every frame equals a fresh renderer's.
 * Fails when the drawer keeps the lighting of the previous viewer (the
 * materials have a specular term) or outlives its scene or options. */
static void test_kept_drawer_follows_view_options_layers_and_scene(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city(), *other = fx_box_city();
    rl_camera a = far_camera(), b = far_camera();
    b.eye = rl_v3(180.0f, 70.0f, -90.0f);
    /* Coarse sets (12 directions, 32² renders): this is about the drawer. */
    const char *const opts[] = { "max_depth", "3", "levels", "0", "resolution", "32", NULL };
    const char *const flat[] = { "max_depth", "3", "levels", "0", "resolution", "32", "shading", "flat", NULL };
    rl_renderer *r = fx_make("svs", opts);
    rl_image *first = fx_render_with(r, s, &a, FX_ALL_LAYERS, NULL);
    rl_image_release(first);
    struct {
        const rl_scene *scene;
        const char *shading;
        unsigned layers;
    } steps[] = { { s, "textured", FX_ALL_LAYERS }, { s, "flat", FX_ALL_LAYERS },
                  { s, "flat", RL_LAYER_COLOR }, { other, "flat", RL_LAYER_COLOR } };
    for (size_t i = 0; i < sizeof steps / sizeof steps[0]; ++i) {
        assert_int_equal(rl_renderer_set(r, "shading", steps[i].shading), RL_OK);
        const rl_camera *cam = i % 2 ? &a : &b;
        rl_image *kept = fx_render_with(r, steps[i].scene, cam, steps[i].layers, NULL);
        rl_image *fresh = fx_render("svs", steps[i].scene, cam, steps[i].layers,
                                    strcmp(steps[i].shading, "flat") == 0 ? flat : opts, NULL);
        fx_assert_images_identical(kept, fresh);
        rl_image_release(kept);
        rl_image_release(fresh);
    }
    rl_renderer_release(r);
    rl_scene_release(other);
    rl_scene_release(s);
}

static void test_svs_refuses_bad_options(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("svs", NULL);
    assert_int_equal(rl_renderer_set(r, "levels", "4"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "resolution", "4"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "neighbours", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "distance", "0.5"), RL_ERR_INVALID_ARG);
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_svs_draws_less_at_high_quality_from_far),
        cmocka_unit_test(test_svs_never_draws_a_sealed_object),
        cmocka_unit_test(test_kept_drawer_follows_view_options_layers_and_scene),
        cmocka_unit_test(test_svs_refuses_bad_options),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
