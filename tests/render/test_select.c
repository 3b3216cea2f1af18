/* test_select.c: renderer "select", the runtime selection of Jähn 2015,
 * Sec. 7.5: per frame the renderer the sampled properties predict draws,
 * with its own image (bit-identical to that renderer alone), `first`
 * outside the sampled region; both rules; clear errors for missing or
 * wrong inputs; sampling the times itself when given no files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl.h"

#define MID_X 60.0f                       /* the box city spans x = -5 .. 125 */

/* Stand-ins for sampled properties: a step in x (first faster on the
 * left), a constant, and x itself. */
static rl_status step_time(void *user, int worker, rl_vec3 pos, double *value, uint64_t *set)
{
    (void)user, (void)worker, (void)set;
    *value = pos.x < MID_X ? 1.0 : 3.0;
    return RL_OK;
}
static rl_status flat_time(void *user, int worker, rl_vec3 pos, double *value, uint64_t *set)
{
    (void)user, (void)worker, (void)pos, (void)set;
    *value = 2.0;
    return RL_OK;
}
static rl_status x_value(void *user, int worker, rl_vec3 pos, double *value, uint64_t *set)
{
    (void)user, (void)worker, (void)set;
    *value = pos.x;
    return RL_OK;
}

/* Samples fn over the city's slice at 1.7 m on an 8 x 8 grid and saves the
 * approximation as DIR/file; returns the path. */
static const char *save_approx(const rl_scene *s, const char *name,
                               rl_status (*fn)(void *, int, rl_vec3, double *, uint64_t *), const char *file,
                               char *path, size_t size)
{
    rl_property_callbacks cb = { .name = name, .unit = "ms", .evaluate = fn };
    rl_property *p = NULL;
    assert_int_equal(rl_property_create_custom(&cb, NULL, &p), RL_OK);
    assert_int_equal(rl_property_commit(p, s, 1), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_sampling_desc sd = { .region = d->bounds, .dims = 2, .height = 1.7f, .method = RL_SAMPLING_GRID,
                            .max_samples = 64, .seed = 1 };
    rl_approx *a = NULL;
    assert_int_equal(rl_sample_property(p, &sd, &a), RL_OK);
    const char *dir = getenv("RL_TEST_TMP");
    snprintf(path, size, "%s/%s", dir ? dir : "/tmp", file);
    assert_int_equal(rl_approx_save_json(a, path), RL_OK);
    rl_approx_release(a);
    rl_property_release(p);
    return path;
}

static rl_camera at_x(float x)
{
    rl_camera c = { .eye = rl_v3(x, 1.7f, 3.0f), .target = rl_v3(x + 4.0f, 1.5f, 70.0f), .fov_deg = 60.0f,
                    .width = 96, .height = 72 };
    return c;
}

static uint32_t selected(const rl_renderer *r)
{
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(r, &cs), RL_OK);
    return cs.selected;
}

/* The frame of `sel` at x equals the one of renderer `name` alone. */
static void expect_frame_of(rl_renderer *sel, const rl_scene *s, float x, const char *name, uint32_t which)
{
    rl_camera cam = at_x(x);
    rl_image *img = fx_render_with(sel, s, &cam, FX_ALL_LAYERS, NULL);
    assert_int_equal(selected(sel), which);
    rl_image *ref = fx_render(name, s, &cam, FX_ALL_LAYERS, NULL, NULL);
    fx_assert_images_identical(img, ref);
    rl_image_release(ref);
    rl_image_release(img);
}

static void test_select_draws_with_the_renderer_the_sampled_times_pick(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    char a[1024], b[1024];
    save_approx(s, "time", step_time, "select_first_time.json", a, sizeof a);
    save_approx(s, "time", flat_time, "select_second_time.json", b, sizeof b);
    rl_renderer *sel = fx_make("select", (const char *const[]){ "first_time", a, "second_time", b, NULL });
    expect_frame_of(sel, s, 20.0f, "chcpp", 1);       /* first (chcpp) sampled faster */
    expect_frame_of(sel, s, 100.0f, "svs", 2);        /* second (svs) sampled faster */
    expect_frame_of(sel, s, 30.0f, "chcpp", 1);
    expect_frame_of(sel, s, -30.0f, "chcpp", 1);      /* outside the slice: first */
    /* Swapped roles follow the files, not the names. */
    rl_renderer *swap = fx_make("select", (const char *const[]){ "first", "svs", "second", "chcpp", "first_time", a,
                                                                  "second_time", b, NULL });
    expect_frame_of(swap, s, 20.0f, "svs", 1);
    expect_frame_of(swap, s, 100.0f, "chcpp", 2);
    rl_renderer_release(swap);
    rl_renderer_release(sel);
    rl_scene_release(s);
}

/* The first frame for a scene lets both renderers build for it (the one
 * not chosen draws once, as preprocessing): a later switch builds nothing
 * more. Two CHC++ instances (their build: the octree), which is quicker
 * than SVS' sets and tells the same. */
static void test_select_builds_both_renderers_on_the_first_frame(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    char a[1024], b[1024];
    save_approx(s, "time", step_time, "select_build_first.json", a, sizeof a);
    save_approx(s, "time", flat_time, "select_build_second.json", b, sizeof b);
    rl_renderer *sel = fx_make("select", (const char *const[]){ "second", "chcpp", "first_time", a, "second_time", b,
                                                                NULL });
    rl_culling_stats cs;
    rl_camera left = at_x(20.0f), right = at_x(100.0f);
    rl_image *img = fx_render_with(sel, s, &left, RL_LAYER_COLOR, NULL);
    assert_int_equal(rl_culling_get_stats(sel, &cs), RL_OK);
    assert_int_equal(cs.selected, 1);
    assert_true(cs.preprocess_ms > 0.0);
    rl_image_release(img);
    img = fx_render_with(sel, s, &right, RL_LAYER_COLOR, NULL);
    assert_int_equal(rl_culling_get_stats(sel, &cs), RL_OK);
    assert_int_equal(cs.selected, 2);
    assert_true(cs.preprocess_ms == 0.0);          /* built on the first frame */
    rl_image_release(img);
    rl_renderer_release(sel);
    rl_scene_release(s);
}

/* The shared raster options reach the drawing renderer, also when they
 * change between frames. */
static void test_select_forwards_the_raster_options(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    char a[1024], b[1024];
    save_approx(s, "time", step_time, "select_fwd_first.json", a, sizeof a);
    save_approx(s, "time", flat_time, "select_fwd_second.json", b, sizeof b);
    rl_renderer *sel = fx_make("select", (const char *const[]){ "first_time", a, "second_time", b, "shading", "flat",
                                                                 "background", "0.2,0.3,0.4", NULL });
    rl_camera cam = at_x(20.0f);
    const char *const flat[] = { "shading", "flat", "background", "0.2,0.3,0.4", NULL };
    const char *const gouraud[] = { "shading", "gouraud", "background", "0.2,0.3,0.4", NULL };
    for (int f = 0; f < 2; ++f) {
        if (f == 1)
            assert_int_equal(rl_renderer_set(sel, "shading", "gouraud"), RL_OK);
        rl_image *img = fx_render_with(sel, s, &cam, FX_ALL_LAYERS, NULL);
        rl_image *ref = fx_render("chcpp", s, &cam, FX_ALL_LAYERS, f == 0 ? flat : gouraud, NULL);
        fx_assert_images_identical(img, ref);
        rl_image_release(ref);
        rl_image_release(img);
    }
    rl_renderer_release(sel);
    rl_scene_release(s);
}

/* The thesis' rule: first where the property is below the threshold. */
static void test_select_threshold_rule(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    char p[1024];
    save_approx(s, "polygons", x_value, "select_polygons.json", p, sizeof p);
    rl_renderer *sel = fx_make("select", (const char *const[]){ "rule", "threshold", "property", p, "threshold",
                                                                 "50", NULL });
    expect_frame_of(sel, s, 20.0f, "chcpp", 1);
    expect_frame_of(sel, s, 90.0f, "svs", 2);
    rl_renderer_release(sel);
    rl_scene_release(s);
}

static rl_status render_status(rl_renderer *r, const rl_scene *s)
{
    rl_camera cam = at_x(20.0f);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, RL_LAYER_COLOR, &img), RL_OK);
    rl_clear_error();
    rl_status st = rl_renderer_prepare_inputs(r, s);
    if (st == RL_OK)
        st = rl_renderer_render(r, s, &cam, img, NULL);
    rl_image_release(img);
    return st;
}

static void expect_refused(const rl_scene *s, const char *const *opts, const char *text)
{
    rl_renderer *r = fx_make("select", opts);
    assert_int_not_equal(render_status(r, s), RL_OK);
    if (!strstr(rl_last_error(), text))
        print_error("expected '%s' in: %s\n", text, rl_last_error());
    assert_non_null(strstr(rl_last_error(), text));
    rl_renderer_release(r);
}

static void test_select_refuses_bad_inputs_with_a_message(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    char p[1024];
    save_approx(s, "polygons", x_value, "select_not_time.json", p, sizeof p);
    expect_refused(s, (const char *const[]){ "rule", "threshold", NULL }, "property=FILE");
    expect_refused(s, (const char *const[]){ "first", "nosuch", NULL }, "nosuch");
    expect_refused(s, (const char *const[]){ "second", "select", NULL }, "itself");
    expect_refused(s, (const char *const[]){ "first", "visset", NULL }, "measured inputs");
    /* The renderer refuses it too, when a caller skips the preparation. */
    rl_renderer *r = fx_make("select", (const char *const[]){ "first", "visset", NULL });
    rl_camera cam = at_x(20.0f);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, RL_LAYER_COLOR, &img), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "measured inputs"));
    rl_image_release(img);
    rl_renderer_release(r);
    expect_refused(s, (const char *const[]){ "first_time", "/no/such/approx.json", "second_time", p, NULL },
                   "/no/such/approx.json");
    expect_refused(s, (const char *const[]){ "first_time", p, "second_time", p, NULL }, "not time");
    rl_scene_release(s);
}

/* Without files the two times are sampled before the first frame
 * (rl_renderer_prepare_inputs) and kept: preparing again for the same
 * options and scene does nothing, and the first frame reports the
 * sampling as preprocessing. */
static void test_select_samples_the_times_itself(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_renderer *sel = fx_make("select", (const char *const[]){ "samples", "4", "resolution", "16", NULL });
    rl_camera cam = at_x(20.0f);
    rl_image *img = fx_render_with(sel, s, &cam, RL_LAYER_COLOR, NULL);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(sel, &cs), RL_OK);
    assert_true(cs.selected == 1 || cs.selected == 2);
    assert_true(cs.preprocess_ms > 0.0);
    const char *key = rl_renderer_input_key(sel, "first_time");
    assert_non_null(key);
    char before[1024];
    snprintf(before, sizeof before, "%s", key);
    assert_int_equal(rl_renderer_prepare_inputs(sel, s), RL_OK);
    assert_string_equal(rl_renderer_input_key(sel, "first_time"), before);
    assert_int_equal(rl_renderer_render(sel, s, &cam, img, NULL), RL_OK);
    assert_int_equal(rl_culling_get_stats(sel, &cs), RL_OK);
    assert_true(cs.preprocess_ms == 0.0);   /* sampled once, and the same renderer drew */
    rl_image_release(img);
    rl_renderer_release(sel);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_select_draws_with_the_renderer_the_sampled_times_pick),
        cmocka_unit_test(test_select_builds_both_renderers_on_the_first_frame),
        cmocka_unit_test(test_select_forwards_the_raster_options),
        cmocka_unit_test(test_select_threshold_rule),
        cmocka_unit_test(test_select_refuses_bad_inputs_with_a_message),
        cmocka_unit_test(test_select_samples_the_times_itself),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
