/* test_surfels.c: the Progressive Blue Surfels renderer (Jähn 2015, Sec.
 * 6.2) on the box city: never approximating gives raster's image; far away
 * the city becomes points only, at a measured quality; in between both are
 * drawn; the same options give the same image; the prefix and point-size
 * rule matches hand-computed values; bad sizes are refused; the levels
 * overlay recolours the points only. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/surfels_internal.h"
#include "render_fixtures.h"
#include "rl/rl.h"

/* Small surfel sets so that the preprocessing stays fast under ASan. */
#define SMALL "count", "3000", "resolution", "128", "min_triangles", "2000"

static rl_camera far_camera(float dist)
{
    rl_camera c = { .eye = rl_v3(60.0f - dist, 0.8f * dist, 60.0f - dist), .target = rl_v3(60, 5, 60),
                    .fov_deg = 40.0f, .width = 160, .height = 120 };
    return c;
}

static void test_surfels_without_approximation_equal_raster(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_camera cam = far_camera(150.0f);
    rl_render_stats a, b;
    rl_image *ref = fx_render("raster", s, &cam, FX_ALL_LAYERS, NULL, &a);
    rl_image *img = fx_render("surfels", s, &cam, FX_ALL_LAYERS,
                              (const char *const[]){ SMALL, "min_size", "0", "max_size", "0", NULL }, &b);
    fx_assert_images_identical(ref, img);
    rl_image_release(ref);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_surfels_replace_distant_geometry(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_camera cam = far_camera(260.0f);
    rl_render_stats full, st;
    rl_image *ref = fx_render("raster", s, &cam, RL_LAYER_COLOR, NULL, &full);

    /* Everything below 400 px a side: the whole city as points. */
    rl_renderer *r = fx_make("surfels", (const char *const[]){ SMALL, "min_size", "400", "max_size", "800", NULL });
    rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, &st);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(r, &cs), RL_OK);
    assert_int_equal(st.triangles_rasterized, 0);
    assert_true(cs.points_drawn > 500);
    assert_true(st.points_drawn > 0 && st.points_drawn <= cs.points_drawn);   /* rl_render_stats too */
    assert_true(cs.surfel_nodes >= 1);
    assert_true(cs.preprocess_ms > 0.0);
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(img, ref, NULL, &m), RL_OK);
    print_message("points only: %llu points, SSIM %.3f\n", (unsigned long long)cs.points_drawn, m.ssim);
    assert_true(m.ssim > 0.85);   /* 0.909 measured; deterministic with the seed */
    /* The next frame reuses the surfels. */
    rl_image *again = fx_render_with(r, s, &cam, RL_LAYER_COLOR, &st);
    assert_int_equal(rl_culling_get_stats(r, &cs), RL_OK);
    assert_true(cs.preprocess_ms == 0.0);
    fx_assert_images_identical(img, again);
    rl_image_release(again);
    rl_image_release(img);
    rl_renderer_release(r);

    /* Closer: the blend zone. A fresh renderer with the same seed draws
     * the same points, with any thread count. */
    rl_image_release(ref);
    cam = far_camera(110.0f);
    ref = fx_render("raster", s, &cam, RL_LAYER_COLOR, NULL, &full);
    rl_image *one = fx_render("surfels", s, &cam, RL_LAYER_COLOR,
                              (const char *const[]){ SMALL, "min_size", "60", "max_size", "120", "threads", "1", NULL },
                              &st);
    rl_render_stats st2;
    rl_image *two = fx_render("surfels", s, &cam, RL_LAYER_COLOR,
                              (const char *const[]){ SMALL, "min_size", "60", "max_size", "120", "threads", "2", NULL },
                              &st2);
    fx_assert_images_identical(one, two);
    /* The blend zone: meshes and points together, fewer triangles. */
    assert_true(st.triangles_rasterized > 0 && st.triangles_rasterized < full.triangles_rasterized);
    assert_int_equal(rl_image_compare(one, ref, NULL, &m), RL_OK);
    print_message("blended: %llu of %llu triangles, SSIM %.3f\n", (unsigned long long)st.triangles_rasterized,
                  (unsigned long long)full.triangles_rasterized, m.ssim);
    assert_true(m.ssim > 0.8);
    rl_image_release(one);
    rl_image_release(two);
    rl_image_release(ref);
    rl_scene_release(s);
}

/* Points drawn (front-facing points of the prefix) by a surfels-only
 * frame of the whole city from `dist`, on a small image so that no prefix
 * reaches the set's 3000 surfels. */
static uint64_t points_at(const rl_scene *s, float dist, const char *overdraw)
{
    rl_camera cam = far_camera(dist);
    cam.width = 64;
    cam.height = 48;
    rl_renderer *r = fx_make("surfels", (const char *const[]){ SMALL, "min_size", "400", "max_size", "800",
                                                               "overdraw", overdraw, NULL });
    rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(r, &cs), RL_OK);
    rl_image_release(img);
    rl_renderer_release(r);
    return cs.points_drawn;
}

/* Sec. 6.2: the prefix length is projected size x coverage x overdraw,
 * so the points drawn grow linearly with the overdraw factor and fall
 * with the square of the distance (the city's projected box, nearly
 * 1/d^2 this far away). Counted are the front-facing points of the
 * prefix, a nearly constant share of a blue-noise prefix. */
static void test_surfel_prefix_follows_projected_size_and_overdraw(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    double p1 = (double)points_at(s, 150.0f, "1"), p2 = (double)points_at(s, 150.0f, "2");
    double far = (double)points_at(s, 300.0f, "2");
    print_message("surfel prefixes: overdraw 1: %.0f points, 2: %.0f (x%.3f); twice as far: %.0f (x%.3f)\n", p1,
                  p2, p2 / p1, far, far / p2);
    assert_true(p1 > 200.0);
    assert_float_equal(p2 / p1, 2.0, 0.2);
    assert_float_equal(far / p2, 0.25, 0.05);
    rl_scene_release(s);
}

/* Sec. 6.2's rule with the thesis' defaults (min 100 px, max 200 px,
 * overdraw 4, point size 7) on a node of 40,000 surfels covering half its
 * box, against values computed by hand. */
static void test_surfel_lod_rule_by_hand(void **state)
{
    (void)state;
    const uint32_t count = 40000;
    /* 50^2 px: surfels only, 2500 * 0.5 * 4 = 5000 of them at size 7. */
    rl_surfel_lod l = rl_surfels_node_lod(2500.0, 0.5, count, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 5000);
    assert_float_equal(l.point_size, 7.0f, 1e-6f);
    assert_false(l.descend);
    /* 100^2 px exactly: still surfels only, 20,000 of them. */
    l = rl_surfels_node_lod(10000.0, 0.5, count, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 20000);
    assert_false(l.descend);
    /* Coverage 1 at 150^2 px: 90,000 wanted of 40,000, so all of them at
     * 7 * sqrt(90000 / 40000) = 10.5 px at the minimum size; here t =
     * (40000 - 22500) / (40000 - 10000) = 7/12: ceil(40000 * 7/12) =
     * 23,334 surfels at 10.5 * 7/12 = 6.125 px, and the meshes too. */
    l = rl_surfels_node_lod(22500.0, 1.0, count, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 23334);
    assert_float_equal(l.point_size, 6.125f, 1e-4f);
    assert_true(l.descend);
    /* All of a small node at 80^2 px: 25,600 wanted of 10,000, size 7 * 1.6. */
    l = rl_surfels_node_lod(6400.0, 1.0, 10000, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 10000);
    assert_float_equal(l.point_size, 11.2f, 1e-4f);
    /* At the maximum size the blend reaches zero; above it, meshes only. */
    l = rl_surfels_node_lod(40000.0, 0.5, count, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 0);
    assert_float_equal(l.point_size, 0.0f, 1e-6f);
    assert_true(l.descend);
    l = rl_surfels_node_lod(40001.0, 0.5, count, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 0);
    assert_true(l.descend);
    /* Reaching behind the near plane (projected size +inf): meshes. */
    l = rl_surfels_node_lod(INFINITY, 0.5, count, 100.0f, 200.0f, 4.0f, 7.0f);
    assert_int_equal(l.prefix, 0);
    assert_true(l.descend);
    /* Sec. 6.2.1: a point's side is 7 x relative size x cosine, at least
     * one pixel; points facing away are hidden. */
    assert_float_equal(rl_surfel_point_side(7.0f, 1.0f, 1.0f), 7.0f, 1e-6f);
    assert_float_equal(rl_surfel_point_side(7.0f, 0.5f, 0.5f), 1.75f, 1e-6f);
    assert_float_equal(rl_surfel_point_side(7.0f, 0.1f, 0.5f), 1.0f, 1e-6f);
    assert_float_equal(rl_surfel_point_side(7.0f, 1.0f, 0.0f), 0.0f, 1e-6f);
    assert_float_equal(rl_surfel_point_side(7.0f, 1.0f, -0.3f), 0.0f, 1e-6f);
    assert_float_equal(rl_surfel_point_side(7.0f, 1.0f, NAN), 0.0f, 1e-6f);
}

/* overlay=levels: the points take their node depth's colour, unlit; the
 * meshes and the depth layer stay those of the lit frame. */
static void test_surfels_overlay_colours_points_by_level(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_camera cam = far_camera(110.0f);
    const char *const lit_opts[] = { SMALL, "min_size", "60", "max_size", "120", NULL };
    const char *const lvl_opts[] = { SMALL, "min_size", "60", "max_size", "120", "overlay", "levels", NULL };
    rl_image *lit = fx_render("surfels", s, &cam, FX_ALL_LAYERS, lit_opts, NULL);
    rl_image *lvl = fx_render("surfels", s, &cam, FX_ALL_LAYERS, lvl_opts, NULL);
    size_t n = (size_t)cam.width * (size_t)cam.height, changed = 0;
    for (size_t i = 0; i < n; ++i) {
        assert_int_equal(lit->object_id[i], lvl->object_id[i]);
        rl_vec4 p = lit->color[i], q = lvl->color[i];
        if (p.x == q.x && p.y == q.y && p.z == q.z)
            continue;
        /* Only point pixels change, to a palette colour: one channel near
         * full, as no lit surface of the city is. */
        changed++;
        assert_int_equal(lvl->object_id[i], RL_ID_NONE);
        assert_true(fmaxf(q.x, fmaxf(q.y, q.z)) >= 0.9f);
    }
    assert_true(changed > 100);
    rl_image_release(lit);
    rl_image_release(lvl);
    rl_scene_release(s);
}

static void test_surfels_refuse_bad_options(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_renderer *r = fx_make("surfels", (const char *const[]){ "min_size", "300", "max_size", "200", NULL });
    rl_camera cam = far_camera(100.0f);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, RL_LAYER_COLOR, &img), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "overdraw", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "count", "0"), RL_ERR_INVALID_ARG);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_surfels_without_approximation_equal_raster),
        cmocka_unit_test(test_surfels_replace_distant_geometry),
        cmocka_unit_test(test_surfel_prefix_follows_projected_size_and_overdraw),
        cmocka_unit_test(test_surfel_lod_rule_by_hand),
        cmocka_unit_test(test_surfels_refuse_bad_options),
        cmocka_unit_test(test_surfels_overlay_colours_points_by_level),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
