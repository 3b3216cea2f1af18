/* test_tonemap.c: exposure and the tone-mapping operators (none = clamp,
 * Reinhard 2002 eq. 3 on luminance, Narkowicz 2015's ACES fit): 0 maps to
 * 0, the curves rise monotonically towards 1, exact values at chosen
 * inputs, one stop doubles the input, and the in-place image pass. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "rl/rl_image.h"

static rl_vec3 grey(float v) { return (rl_vec3){ v, v, v }; }

static float map_grey(rl_tonemap_op op, double ev, float v)
{
    return rl_tonemap_rgb(grey(v), &(rl_tonemap_desc){ .op = op, .exposure_ev = ev }).x;
}

/* The Narkowicz 2015 curve written out, for the exact values. */
static double aces_fit(double x)
{
    return x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
}

static void test_black_stays_black_under_every_operator(void **state)
{
    (void)state;
    for (int op = 0; op < RL_TONEMAP_COUNT; ++op) {
        rl_vec3 m = rl_tonemap_rgb(grey(0.0f), &(rl_tonemap_desc){ .op = (rl_tonemap_op)op, .exposure_ev = 3.0 });
        assert_true(m.x == 0.0f && m.y == 0.0f && m.z == 0.0f);
    }
}

static void test_operators_rise_monotonically_and_stay_in_unit_range(void **state)
{
    (void)state;
    for (int op = 0; op < RL_TONEMAP_COUNT; ++op) {
        float prev = 0.0f;
        for (float v = 0.0f; v < 100.0f; v = v * 1.05f + 0.001f) {
            float m = map_grey((rl_tonemap_op)op, 0.0, v);
            assert_true(m >= prev);
            assert_true(m >= 0.0f && m <= 1.0f);
            prev = m;
        }
    }
}

static void test_none_clamps_as_the_png_writer_did(void **state)
{
    (void)state;
    rl_vec3 m = rl_tonemap_rgb((rl_vec3){ -1.0f, 0.25f, 7.0f }, NULL);
    assert_true(m.x == 0.0f && m.y == 0.25f && m.z == 1.0f);
    assert_true(isnan(rl_tonemap_rgb((rl_vec3){ NAN, 0.5f, 0.5f }, NULL).x));
}

static void test_reinhard_is_l_over_one_plus_l_on_luminance(void **state)
{
    (void)state;
    /* Grey: L = v, so every channel is v / (1 + v). */
    assert_float_equal(map_grey(RL_TONEMAP_REINHARD, 0.0, 1.0f), 0.5f, 1e-6f);
    assert_float_equal(map_grey(RL_TONEMAP_REINHARD, 0.0, 3.0f), 0.75f, 1e-6f);
    /* The limit is white and infinity reaches it. */
    assert_float_equal(map_grey(RL_TONEMAP_REINHARD, 0.0, 1e6f), 1.0f, 1e-5f);
    assert_float_equal(map_grey(RL_TONEMAP_REINHARD, 0.0, INFINITY), 1.0f, 0.0f);
    /* A colour keeps its channel ratios: all scaled by 1 / (1 + L). */
    rl_vec3 c = { 0.8f, 0.4f, 0.2f };
    double lum = 0.2126 * 0.8 + 0.7152 * 0.4 + 0.0722 * 0.2;
    rl_vec3 m = rl_tonemap_rgb(c, &(rl_tonemap_desc){ .op = RL_TONEMAP_REINHARD });
    assert_float_equal(m.x, 0.8 / (1.0 + lum), 1e-6f);
    assert_float_equal(m.y, 0.4 / (1.0 + lum), 1e-6f);
    assert_float_equal(m.x / m.z, 4.0f, 1e-5f);
}

static void test_aces_matches_the_narkowicz_fit(void **state)
{
    (void)state;
    const float xs[] = { 0.01f, 0.18f, 0.5f, 1.0f, 2.0f, 4.0f };
    for (size_t k = 0; k < sizeof xs / sizeof xs[0]; ++k)
        assert_float_equal(map_grey(RL_TONEMAP_ACES, 0.0, xs[k]), aces_fit(xs[k]), 1e-6f);
    assert_float_equal(map_grey(RL_TONEMAP_ACES, 0.0, 1.0f), 2.54 / 3.16, 1e-6f);
    /* The fit passes 1 near 7.24 and is clamped there. */
    assert_float_equal(map_grey(RL_TONEMAP_ACES, 0.0, 7.0f), aces_fit(7.0), 1e-6f);
    assert_true(map_grey(RL_TONEMAP_ACES, 0.0, 7.0f) < 1.0f);
    assert_true(map_grey(RL_TONEMAP_ACES, 0.0, 7.5f) == 1.0f);
    assert_true(map_grey(RL_TONEMAP_ACES, 0.0, INFINITY) == 1.0f);
    assert_true(map_grey(RL_TONEMAP_ACES, 0.0, -2.0f) == 0.0f);
}

static void test_one_stop_of_exposure_doubles_the_input(void **state)
{
    (void)state;
    for (int op = 0; op < RL_TONEMAP_COUNT; ++op) {
        float v = 0.3f;
        assert_float_equal(map_grey((rl_tonemap_op)op, 1.0, v), map_grey((rl_tonemap_op)op, 0.0, 2.0f * v), 1e-6f);
        assert_float_equal(map_grey((rl_tonemap_op)op, -2.0, v), map_grey((rl_tonemap_op)op, 0.0, v / 4.0f), 1e-6f);
    }
    assert_float_equal(map_grey(RL_TONEMAP_NONE, 1.0, 0.25f), 0.5f, 0.0f);
}

static void test_image_pass_maps_colour_and_keeps_alpha(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 1, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = (rl_vec4){ 3.0f, 3.0f, 3.0f, 0.5f };
    img->color[1] = (rl_vec4){ 1.0f, 1.0f, 1.0f, 1.0f };
    assert_int_equal(rl_image_tonemap(img, &(rl_tonemap_desc){ .op = RL_TONEMAP_REINHARD }), RL_OK);
    assert_float_equal(img->color[0].x, 0.75f, 1e-6f);
    assert_true(img->color[0].w == 0.5f);
    assert_float_equal(img->color[1].z, 0.5f, 1e-6f);
    rl_image_release(img);
}

static void test_bad_arguments_leave_the_image_alone(void **state)
{
    (void)state;
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(1, 1, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = (rl_vec4){ 5.0f, 5.0f, 5.0f, 1.0f };
    assert_int_equal(rl_image_tonemap(NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_tonemap(img, &(rl_tonemap_desc){ .op = RL_TONEMAP_COUNT }), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_tonemap(img, &(rl_tonemap_desc){ .exposure_ev = INFINITY }), RL_ERR_INVALID_ARG);
    assert_true(img->color[0].x == 5.0f);
    rl_image_release(img);
    rl_clear_error();
}

static void test_names_parse_back(void **state)
{
    (void)state;
    for (int op = 0; op < RL_TONEMAP_COUNT; ++op) {
        rl_tonemap_op back = RL_TONEMAP_COUNT;
        assert_int_equal(rl_tonemap_parse(rl_tonemap_name((rl_tonemap_op)op), &back), RL_OK);
        assert_int_equal(back, op);
    }
    assert_null(rl_tonemap_name(RL_TONEMAP_COUNT));
    assert_int_equal(rl_tonemap_parse("filmic", NULL), RL_ERR_INVALID_ARG);
    rl_clear_error();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_black_stays_black_under_every_operator),
        cmocka_unit_test(test_operators_rise_monotonically_and_stay_in_unit_range),
        cmocka_unit_test(test_none_clamps_as_the_png_writer_did),
        cmocka_unit_test(test_reinhard_is_l_over_one_plus_l_on_luminance),
        cmocka_unit_test(test_aces_matches_the_narkowicz_fit),
        cmocka_unit_test(test_one_stop_of_exposure_doubles_the_input),
        cmocka_unit_test(test_image_pass_maps_colour_and_keeps_alpha),
        cmocka_unit_test(test_bad_arguments_leave_the_image_alone),
        cmocka_unit_test(test_names_parse_back),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
