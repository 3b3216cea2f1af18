/* test_renderer.c: the generic rl_renderer layer: registry, option
 * validation (types, ranges, prefixes) and the checks render() makes before
 * any algorithm runs. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/threads.h"
#include "rl/rl_culling.h"
#include "rl/rl_render.h"
#include "rl/rl_sampling.h"
#include "rl/rl_scene.h"

#include "render_fixtures.h"

/* A one-triangle committed (or not) scene. */
static rl_scene *make_scene(bool commit) { return fx_triangle_scene(commit); }

static rl_camera small_camera(int w, int h)
{
    return (rl_camera){ .eye = { 0, 0, 4 }, .target = { 0, 0, 0 }, .width = w, .height = h };
}

static void test_renderer_list_contains_raster(void **state)
{
    (void)state;
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    bool found = false;
    for (size_t i = 0; i < n; ++i)
        found |= strcmp(list[i].name, "raster") == 0 && list[i].description[0] != '\0';
    assert_true(found);
}

static void test_unknown_algorithm_is_not_found_and_lists_known_ones(void **state)
{
    (void)state;
    rl_renderer *r = NULL;
    rl_clear_error();
    assert_int_equal(rl_renderer_create("nosuch", &r), RL_ERR_NOT_FOUND);
    assert_null(r);
    assert_non_null(strstr(rl_last_error(), "\"nosuch\""));
    assert_non_null(strstr(rl_last_error(), "raster"));
    assert_int_equal(rl_renderer_create(NULL, &r), RL_ERR_INVALID_ARG);
}

/* Sets key=value, expects `want`, and (for failures) that the message names needle. */
static void expect_set(rl_renderer *r, const char *key, const char *value, rl_status want,
                       const char *needle)
{
    rl_clear_error();
    const char *before = rl_renderer_get(r, key);
    char saved[64] = "";
    if (before)
        strncpy(saved, before, sizeof saved - 1);
    assert_int_equal(rl_renderer_set(r, key, value), want);
    if (want != RL_OK) {
        assert_non_null(strstr(rl_last_error(), needle));
        /* Outputs untouched on failure. */
        if (before)
            assert_string_equal(rl_renderer_get(r, key), saved);
    }
}

static void test_bad_options_are_invalid_and_name_the_option(void **state)
{
    (void)state;
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    expect_set(r, "bounces", "3", RL_ERR_INVALID_ARG, "bounces");
    expect_set(r, "shading", "phong", RL_ERR_INVALID_ARG, "shading");
    assert_non_null(strstr(rl_last_error(), "flat, gouraud, textured"));
    expect_set(r, "threads", "2000", RL_ERR_INVALID_ARG, "threads");
    expect_set(r, "threads", "-1", RL_ERR_INVALID_ARG, "threads");
    expect_set(r, "threads", "2.5", RL_ERR_INVALID_ARG, "threads");
    expect_set(r, "ambient", "1.5", RL_ERR_INVALID_ARG, "ambient");
    expect_set(r, "ambient", "nan", RL_ERR_INVALID_ARG, "ambient");
    expect_set(r, "cull", "maybe", RL_ERR_INVALID_ARG, "cull");
    expect_set(r, "background", "1,2", RL_ERR_INVALID_ARG, "background");
    expect_set(r, "background", "-1,0,0", RL_ERR_INVALID_ARG, "background");
    expect_set(r, "whitted.shading", "flat", RL_ERR_INVALID_ARG, "whitted.shading");
    assert_int_equal(rl_renderer_set(r, NULL, "1"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "cull", NULL), RL_ERR_INVALID_ARG);
    rl_renderer_release(r);
}

static void test_good_options_are_accepted_with_or_without_prefix(void **state)
{
    (void)state;
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    assert_string_equal(rl_renderer_name(r), "raster");
    expect_set(r, "raster.shading", "flat", RL_OK, NULL);
    assert_string_equal(rl_renderer_get(r, "shading"), "flat");
    const char *bools[] = { "true", "false", "1", "0", "yes", "no", "on", "off" };
    for (size_t i = 0; i < sizeof bools / sizeof bools[0]; ++i)
        expect_set(r, "cull", bools[i], RL_OK, NULL);
    expect_set(r, "threads", "1024", RL_OK, NULL);
    expect_set(r, "threads", "0", RL_OK, NULL);
    expect_set(r, "ambient", "0", RL_OK, NULL);
    expect_set(r, "ambient", "1", RL_OK, NULL);
    expect_set(r, "background", "0.2,0.3,0.4", RL_OK, NULL);
    expect_set(r, "background", "0.5", RL_OK, NULL);
    rl_renderer_release(r);
}

static void test_get_returns_default_then_set_value(void **state)
{
    (void)state;
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    size_t n = 0;
    const rl_option_info *opts = rl_renderer_options(r, &n);
    assert_true(n >= 5);
    for (size_t i = 0; i < n; ++i)
        assert_string_equal(rl_renderer_get(r, opts[i].key), opts[i].default_value);
    assert_string_equal(rl_renderer_get(r, "shading"), "textured");
    assert_string_equal(rl_renderer_get(r, "raster.ambient"), "0.05");
    assert_null(rl_renderer_get(r, "nosuch"));
    assert_int_equal(rl_renderer_set(r, "shading", "gouraud"), RL_OK);
    assert_string_equal(rl_renderer_get(r, "raster.shading"), "gouraud");
    rl_renderer_release(r);
}

/* Issue 34: a thread count above what the process can start is clamped
 * (OpenMP would exit the process), with or without the renderer's prefix;
 * smaller counts are kept. */
static void test_thread_counts_are_clamped_to_what_can_be_started(void **state)
{
    (void)state;
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("pt", &r), RL_OK);
    int most = rl_threads_creatable();
    assert_true(most >= 1);
    assert_int_equal(rl_renderer_set(r, "pt.threads", "1024"), RL_OK);
    assert_int_equal(atoi(rl_renderer_get(r, "threads")), most < 1024 ? most : 1024);
    assert_int_equal(rl_renderer_set(r, "threads", "1"), RL_OK);
    assert_string_equal(rl_renderer_get(r, "threads"), "1");
    assert_int_equal(rl_renderer_set(r, "threads", "0"), RL_OK);
    assert_string_equal(rl_renderer_get(r, "threads"), "0");
    assert_int_equal(rl_threads_clamp(most + 1, "test"), most);
    assert_int_equal(rl_threads_clamp(0, "test"), 0);
    rl_renderer_release(r);
}

static void test_ray_type_names_are_distinct(void **state)
{
    (void)state;
    assert_string_equal(rl_ray_type_name(RL_RAY_PRIMARY), "primary");
    assert_string_equal(rl_ray_type_name(RL_RAY_SHADOW), "shadow");
    for (int a = 0; a < RL_RAY_TYPE_COUNT; ++a)
        for (int b = a + 1; b < RL_RAY_TYPE_COUNT; ++b)
            assert_string_not_equal(rl_ray_type_name((rl_ray_type)a), rl_ray_type_name((rl_ray_type)b));
    assert_string_equal(rl_ray_type_name(RL_RAY_TYPE_COUNT), "unknown");
}

static void test_render_refuses_uncommitted_scene(void **state)
{
    (void)state;
    rl_scene *s = make_scene(false);
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    assert_int_equal(rl_image_create(8, 8, RL_LAYER_COLOR, &img), RL_OK);
    rl_camera cam = small_camera(8, 8);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_NOT_COMMITTED);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

static void test_render_refuses_mismatched_image_and_bad_camera(void **state)
{
    (void)state;
    rl_scene *s = make_scene(true);
    rl_renderer *r = NULL;
    rl_image *img = NULL, *no_color = NULL;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    assert_int_equal(rl_image_create(8, 6, RL_LAYER_COLOR, &img), RL_OK);
    rl_camera cam = small_camera(8, 8);
    rl_render_stats stats = { .samples = 42 };
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, img, &stats), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "8x6"));
    assert_non_null(strstr(rl_last_error(), "8x8"));
    assert_int_equal(stats.samples, 42);             /* untouched on failure */

    rl_camera bad = small_camera(8, 6);
    bad.target = bad.eye;
    assert_int_equal(rl_renderer_render(r, s, &bad, img, NULL), RL_ERR_INVALID_ARG);

    assert_int_equal(rl_image_create(8, 8, RL_LAYER_DEPTH, &no_color), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, no_color, NULL), RL_ERR_INVALID_ARG);

    cam.height = 6;
    assert_int_equal(rl_renderer_render(r, s, &cam, img, &stats), RL_OK);
    assert_int_equal(stats.samples, 48);
    rl_image_release(no_color);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

static void test_render_refuses_null_arguments(void **state)
{
    (void)state;
    rl_scene *s = make_scene(true);
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    assert_int_equal(rl_image_create(8, 8, RL_LAYER_COLOR, &img), RL_OK);
    rl_camera cam = small_camera(8, 8);
    assert_int_equal(rl_renderer_render(NULL, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_render(r, NULL, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_render(r, s, NULL, img, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_render(r, s, &cam, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
    rl_renderer_release(NULL);
}

static bool cancel_at_once(void *user, double done)
{
    (void)done;
    ++*(int *)user;
    return false;
}

static void test_progress_callback_can_cancel_a_render(void **state)
{
    (void)state;
    rl_scene *s = make_scene(true);
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    int calls = 0;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    assert_int_equal(rl_image_create(8, 8, RL_LAYER_COLOR, &img), RL_OK);
    rl_camera cam = small_camera(8, 8);
    rl_renderer_set_progress(r, cancel_at_once, &calls);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_CANCELLED);
    assert_true(calls >= 1);
    rl_renderer_set_progress(r, NULL, NULL);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* prep_ms: what a renderer builds for the scene is timed on the first
 * frame only, and is part of that frame's time_ms; a rasterizer builds
 * nothing. For the culling renderers it is their preprocess_ms. */
static void test_first_frame_reports_its_preparation_and_later_frames_none(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    const char *const names[] = { "raster", "whitted", "vt", "pt", "chcpp" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
        rl_renderer *r = fx_make(names[i], NULL);
        rl_render_stats first = { 0 }, second = { 0 };
        rl_image *a = fx_render_with(r, s, &cam, RL_LAYER_COLOR, &first);
        rl_image *b = fx_render_with(r, s, &cam, RL_LAYER_COLOR, &second);
        bool builds = strcmp(names[i], "raster") != 0;
        if (builds)
            assert_true(first.prep_ms > 0.0);
        else
            assert_true(first.prep_ms == 0.0);
        assert_true(first.prep_ms <= first.time_ms);
        assert_true(second.prep_ms == 0.0);
        rl_culling_stats cs;
        if (strcmp(names[i], "chcpp") == 0) {
            assert_int_equal(rl_culling_get_stats(r, &cs), RL_OK);
            assert_true(cs.preprocess_ms == second.prep_ms);
        }
        rl_image_release(a);
        rl_image_release(b);
        rl_renderer_release(r);
    }
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_renderer_list_contains_raster),
        cmocka_unit_test(test_unknown_algorithm_is_not_found_and_lists_known_ones),
        cmocka_unit_test(test_bad_options_are_invalid_and_name_the_option),
        cmocka_unit_test(test_good_options_are_accepted_with_or_without_prefix),
        cmocka_unit_test(test_get_returns_default_then_set_value),
        cmocka_unit_test(test_thread_counts_are_clamped_to_what_can_be_started),
        cmocka_unit_test(test_ray_type_names_are_distinct),
        cmocka_unit_test(test_render_refuses_uncommitted_scene),
        cmocka_unit_test(test_render_refuses_mismatched_image_and_bad_camera),
        cmocka_unit_test(test_render_refuses_null_arguments),
        cmocka_unit_test(test_progress_callback_can_cancel_a_render),
        cmocka_unit_test(test_first_frame_reports_its_preparation_and_later_frames_none),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
