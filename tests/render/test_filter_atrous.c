/* test_filter_atrous.c: the edge-avoiding a-trous wavelet filter
 * (Dammertz, Sewtz, Hanika, Lensch 2010; rl_filter.h, RL_FILTER_ATROUS)
 * against properties it must have: a constant image stays constant, noise
 * on a flat region falls by a stated factor, a step in the G-buffer
 * normals or positions stops the smoothing (while the same step without
 * the guide bleeds, so the bound can fail), and on a low-spp path-traced
 * Cornell box it lowers the error against a converged image, where the
 * G-buffer alone (no colour term) would raise it. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_filter.h"
#include "rl/rl_pt.h"
#include "rl/rl_rng.h"
#include "render/render_fixtures.h"

static rl_image *image(int w, int h)
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(w, h, RL_LAYER_COLOR, &img), RL_OK);
    return img;
}

static void apply(const rl_filter_desc *d, const rl_image *in, const rl_gbuffer *g, rl_image *out)
{
    rl_status s = rl_filter_apply(d, in, g, out);
    if (s != RL_OK)
        fail_msg("atrous: %s", rl_last_error());
}

/* A hand-made G-buffer: a plane z = 5 facing the camera, one world unit
 * per 100 pixels; only the arrays the filter reads. */
typedef struct test_gbuffer {
    rl_gbuffer g;
} test_gbuffer;

static test_gbuffer *flat_gbuffer(int w, int h)
{
    test_gbuffer *t = calloc(1, sizeof *t);
    size_t n = (size_t)w * (size_t)h;
    t->g.width = w;
    t->g.height = h;
    t->g.normal = calloc(n, sizeof *t->g.normal);
    t->g.position = calloc(n, sizeof *t->g.position);
    t->g.depth = calloc(n, sizeof *t->g.depth);
    assert_non_null(t->g.normal);
    assert_non_null(t->g.position);
    assert_non_null(t->g.depth);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            t->g.normal[i] = rl_v3(0.0f, 0.0f, 1.0f);
            t->g.position[i] = rl_v3(0.01f * (float)x, 0.01f * (float)y, 5.0f);
            t->g.depth[i] = 5.0f;
        }
    return t;
}

static void gbuffer_free(test_gbuffer *t)
{
    free(t->g.normal);
    free(t->g.position);
    free(t->g.depth);
    free(t);
}

static float gauss_noise(rl_rng *rng)
{
    /* Box-Muller. */
    double u1 = 1.0 - rl_rng_double(rng), u2 = rl_rng_double(rng);
    return (float)(sqrt(-2.0 * log(u1)) * cos(2.0 * 3.14159265358979323846 * u2));
}

static void test_atrous_is_a_named_kind_and_checks_its_parameters(void **state)
{
    (void)state;
    rl_filter_kind k = RL_FILTER_NONE;
    assert_int_equal(rl_filter_kind_parse("atrous", &k), RL_OK);
    assert_int_equal(k, RL_FILTER_ATROUS);
    assert_string_equal(rl_filter_kind_name(RL_FILTER_ATROUS), "atrous");
    rl_image *in = image(8, 8), *out = image(8, 8);
    rl_filter_desc d = { .kind = RL_FILTER_ATROUS, .iterations = 13 };
    assert_int_equal(rl_filter_apply(&d, in, NULL, out), RL_ERR_INVALID_ARG);
    d.iterations = -1;
    assert_int_equal(rl_filter_apply(&d, in, NULL, out), RL_ERR_INVALID_ARG);
    d = (rl_filter_desc){ .kind = RL_FILTER_ATROUS, .sigma_x = -1.0f };
    assert_int_equal(rl_filter_apply(&d, in, NULL, out), RL_ERR_INVALID_ARG);
    d.sigma_x = NAN;
    assert_int_equal(rl_filter_apply(&d, in, NULL, out), RL_ERR_INVALID_ARG);
    rl_image_release(in);
    rl_image_release(out);
}

/* Normalised weights: a constant stays constant with and without the
 * guide, at every level and up to the borders (taps outside drop out). */
static void test_constant_image_stays_constant(void **state)
{
    (void)state;
    const int w = 37, h = 29;
    rl_image *in = image(w, h), *out = image(w, h);
    for (size_t i = 0; i < (size_t)w * h; ++i)
        in->color[i] = rl_v4(0.3f, 0.6f, 0.9f, 1.0f);
    test_gbuffer *g = flat_gbuffer(w, h);
    for (int guided = 0; guided < 2; ++guided) {
        rl_filter_desc d = { .kind = RL_FILTER_ATROUS, .iterations = 6 };
        apply(&d, in, guided ? &g->g : NULL, out);
        for (size_t i = 0; i < (size_t)w * h; ++i) {
            assert_float_equal(out->color[i].x, 0.3f, 1e-5f);
            assert_float_equal(out->color[i].y, 0.6f, 1e-5f);
            assert_float_equal(out->color[i].z, 0.9f, 1e-5f);
            assert_float_equal(out->color[i].w, 1.0f, 0.0f);
        }
    }
    gbuffer_free(g);
    rl_image_release(in);
    rl_image_release(out);
}

/* Independent noise of sigma 0.1 on a flat grey plane: five levels (holes
 * up to 16 pixels) with a colour sigma that tolerates that noise average
 * over thousands of pixels (the plain B3 cascade has a variance of 341
 * pixels^2 per axis, about 1/4300 of the noise variance left); the
 * variance must fall at least 50-fold, whatever the edge-stopping weights
 * cost. */
static void test_noise_on_a_flat_region_falls_fifty_fold(void **state)
{
    (void)state;
    const int w = 96, h = 96;
    rl_image *in = image(w, h), *out = image(w, h);
    rl_rng rng;
    rl_rng_seed(&rng, 5, 1);
    for (size_t i = 0; i < (size_t)w * h; ++i) {
        float v = 0.5f + 0.1f * gauss_noise(&rng);
        in->color[i] = rl_v4(v, v, v, 1.0f);
    }
    test_gbuffer *g = flat_gbuffer(w, h);
    rl_filter_desc d = { .kind = RL_FILTER_ATROUS, .sigma_r = 1.0f };
    apply(&d, in, &g->g, out);
    double vin = 0.0, vout = 0.0, mout = 0.0;
    int m = 0;
    /* The interior: near the borders fewer taps average. */
    for (int y = 16; y < h - 16; ++y)
        for (int x = 16; x < w - 16; ++x, ++m) {
            size_t i = (size_t)y * w + x;
            vin += (in->color[i].x - 0.5) * (in->color[i].x - 0.5);
            vout += (out->color[i].x - 0.5) * (out->color[i].x - 0.5);
            mout += out->color[i].x;
        }
    print_message("flat noise: variance %.3g -> %.3g (ratio %.1f)\n", vin / m, vout / m, vin / vout);
    assert_true(vout * 50.0 < vin);
    assert_float_equal(mout / m, 0.5, 0.01);
    gbuffer_free(g);
    rl_image_release(in);
    rl_image_release(out);
}

/* A step of 0.2 | 0.8 whose halves the colour term cannot tell apart
 * (sigma_r huge): with a normal step in the G-buffer at the same column
 * nothing crosses it (every pixel within 1e-3 of its side), and with a
 * position step (the right half 1 unit deeper) neither; without the guide
 * the same step smears by more than 0.1 next to the edge. */
static void test_normal_and_position_steps_stop_the_smoothing(void **state)
{
    (void)state;
    const int w = 64, h = 32;
    rl_image *in = image(w, h), *out = image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float v = x < w / 2 ? 0.2f : 0.8f;
            *rl_image_pixel(in, x, y) = rl_v4(v, v, v, 1.0f);
        }
    test_gbuffer *normal_step = flat_gbuffer(w, h), *depth_step = flat_gbuffer(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = w / 2; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            normal_step->g.normal[i] = rl_v3(1.0f, 0.0f, 0.0f);
            depth_step->g.position[i].z += 1.0f;
            depth_step->g.depth[i] += 1.0f;
        }
    rl_filter_desc d = { .kind = RL_FILTER_ATROUS, .sigma_r = 1e3f };
    const rl_gbuffer *guides[2] = { &normal_step->g, &depth_step->g };
    for (int k = 0; k < 2; ++k) {
        apply(&d, in, guides[k], out);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                assert_float_equal(out->color[(size_t)y * w + x].x, x < w / 2 ? 0.2f : 0.8f, 1e-3f);
    }
    apply(&d, in, NULL, out);
    float left = out->color[(size_t)(h / 2) * w + w / 2 - 1].x, right = out->color[(size_t)(h / 2) * w + w / 2].x;
    print_message("unguided step: %.3f | %.3f\n", left, right);
    assert_true(left > 0.3f && right < 0.7f);
    gbuffer_free(normal_step);
    gbuffer_free(depth_step);
    rl_image_release(in);
    rl_image_release(out);
}

static double rmse_disp(const rl_image *a, const rl_image *b)
{
    double e = 0.0;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; ++i) {
        float pa[3] = { a->color[i].x, a->color[i].y, a->color[i].z };
        float pb[3] = { b->color[i].x, b->color[i].y, b->color[i].z };
        for (int k = 0; k < 3; ++k) {
            double d = fminf(pa[k], 1.0f) - fminf(pb[k], 1.0f);
            e += d * d;
        }
    }
    return sqrt(e / (3.0 * (double)n));
}

/* pt with filter=atrous (the full filter, filter_fade=0) on the Cornell box
 * at 4 spp, 32 x 32, two levels (five would blur the lighting of an image
 * this small across a third of its width): the RMSE against a 2048-spp
 * image falls to below 0.95 of the unfiltered one's (measured 0.91: at
 * this size and spp the error is mostly coverage noise at edges and spikes
 * of indirect light that the colour term rightly leaves alone; the
 * bilateral filter gets the same). The lamp shares the
 * ceiling's plane and normal, so only the colour term keeps its radiance
 * of 17 out of the ceiling: with the colour term switched off (a huge
 * sigma_rt) the error rises above the unfiltered one's. */
static void test_atrous_lowers_the_error_of_a_low_spp_cornell_render(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 32);
    rl_image *ref = fx_render("pt", s, &cam, RL_LAYER_COLOR,
                              (const char *const[]){ "spp", "2048", "seed", "3", NULL }, NULL);
    rl_image *noisy = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "4", NULL }, NULL);
    rl_pt_stats ps;
    rl_renderer *r = fx_make("pt", (const char *const[]){ "spp", "4", "filter", "atrous", "filter_fade", "0",
                                                          "atrous_iterations", "2", NULL });
    rl_image *filtered = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
    assert_int_equal(rl_pt_get_stats(r, &ps), RL_OK);
    assert_float_equal(ps.filter_weight, 1.0f, 0.0f);
    assert_int_equal(rl_renderer_set(r, "atrous_sigma_rt", "1e6"), RL_OK);
    rl_image *blind = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
    double e0 = rmse_disp(noisy, ref), e1 = rmse_disp(filtered, ref), e2 = rmse_disp(blind, ref);
    print_message("cornell 32x32 at 4 spp: RMSE %.4f unfiltered, %.4f a-trous, %.4f without the colour term\n", e0,
                  e1, e2);
    assert_true(e1 < 0.95 * e0);
    assert_true(e2 > e0);
    rl_image_release(blind);
    rl_renderer_release(r);
    rl_image_release(ref);
    rl_image_release(noisy);
    rl_image_release(filtered);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_atrous_is_a_named_kind_and_checks_its_parameters),
        cmocka_unit_test(test_constant_image_stays_constant),
        cmocka_unit_test(test_noise_on_a_flat_region_falls_fifty_fold),
        cmocka_unit_test(test_normal_and_position_steps_stop_the_smoothing),
        cmocka_unit_test(test_atrous_lowers_the_error_of_a_low_spp_cornell_render),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
