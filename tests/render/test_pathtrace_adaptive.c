/* test_pathtrace_adaptive.c: per-pixel adaptive sampling of the path
 * tracer "pt" (adaptive=on, issue 37): it converges to the same means as
 * uniform sampling, spends fewer samples on a uniformly lit wall than at
 * geometric edges, keeps a frame's budget, stops converged pixels, gives
 * the same image for any thread count, and in its uniform start is the
 * uniform image bit for bit (the Sobol numbering of a pixel's samples
 * continues). Small images so ASan stays fast. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_pt.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render/render_fixtures.h"

/* Renders `frames` frames with the options and returns the last image;
 * *rr gets the renderer (released by the caller). */
static rl_image *render_frames(const rl_scene *s, const rl_camera *cam, const char *const *opts, int frames,
                               rl_renderer **rr)
{
    rl_renderer *r = fx_make("pt", opts);
    rl_image *img = NULL;
    for (int k = 0; k < frames; ++k) {
        rl_image_release(img);
        img = fx_render_with(r, s, cam, RL_LAYER_COLOR, NULL);
    }
    *rr = r;
    return img;
}

/* Image mean per channel, values clamped to the display range (the lamp's
 * partly covered pixels would otherwise decide it). */
static void mean_color(const rl_image *img, double m[3])
{
    size_t n = (size_t)img->width * img->height;
    m[0] = m[1] = m[2] = 0.0;
    for (size_t i = 0; i < n; ++i) {
        m[0] += fmin(img->color[i].x, 1.0) / (double)n;
        m[1] += fmin(img->color[i].y, 1.0) / (double)n;
        m[2] += fmin(img->color[i].z, 1.0) / (double)n;
    }
}

static void test_options_are_checked(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("pt", NULL);
    assert_int_equal(rl_renderer_set(r, "adaptive", "maybe"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "adaptive_min_spp", "1"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "adaptive_threshold", "-0.1"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "atrous_iterations", "13"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "adaptive", "on"), RL_OK);
    assert_null(rl_pt_sample_counts(r));
    rl_renderer_release(r);
}

/* Until every pixel has adaptive_min_spp samples, adaptive sampling is the
 * uniform image bit for bit: same sample numbers, same order. */
static void test_uniform_start_is_the_uniform_image(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_renderer *ru, *ra;
    rl_image *u = render_frames(s, &cam, (const char *const[]){ "spp", "3", NULL }, 3, &ru);
    rl_image *a = render_frames(s, &cam,
                                (const char *const[]){ "spp", "3", "adaptive", "on", "adaptive_min_spp", "9", NULL },
                                3, &ra);
    fx_assert_images_identical(u, a);
    /* The same holds for the thesis' per-pixel generators. */
    rl_image_release(u);
    rl_image_release(a);
    rl_renderer_release(ru);
    rl_renderer_release(ra);
    u = render_frames(s, &cam, (const char *const[]){ "spp", "2", "rng", "hybrid", NULL }, 2, &ru);
    a = render_frames(s, &cam,
                      (const char *const[]){ "spp", "2", "rng", "hybrid", "adaptive", "on", "adaptive_min_spp", "4",
                                             NULL },
                      2, &ra);
    fx_assert_images_identical(u, a);
    rl_image_release(u);
    rl_image_release(a);
    rl_renderer_release(ru);
    rl_renderer_release(ra);
    rl_scene_release(s);
}

/* The per-pixel shares are computed in pixel order and each sample keeps
 * its number, so threads change nothing, the sample counts included. */
static void test_image_does_not_depend_on_the_thread_count(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 24);
    rl_renderer *r1, *r2;
    const char *o1[] = { "spp", "8", "adaptive", "on", "adaptive_min_spp", "4", "threads", "1", NULL };
    const char *o2[] = { "spp", "8", "adaptive", "on", "adaptive_min_spp", "4", "threads", "2", NULL };
    rl_image *one = render_frames(s, &cam, o1, 3, &r1), *two = render_frames(s, &cam, o2, 3, &r2);
    fx_assert_images_identical(one, two);
    assert_memory_equal(rl_pt_sample_counts(r1), rl_pt_sample_counts(r2), 24 * 24 * sizeof(uint32_t));
    rl_image_release(one);
    rl_image_release(two);
    rl_renderer_release(r1);
    rl_renderer_release(r2);
    rl_scene_release(s);
}

/* A frame spends spp x pixels (threshold 0: no pixel converges), unevenly;
 * with a threshold no pixel reaches, nothing beyond the uniform start. */
static void test_frame_budget_and_convergence_stop(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_renderer *r;
    rl_image *img = render_frames(
        s, &cam, (const char *const[]){ "spp", "8", "adaptive", "on", "adaptive_threshold", "0", NULL }, 4, &r);
    rl_pt_stats ps;
    assert_int_equal(rl_pt_get_stats(r, &ps), RL_OK);
    assert_float_equal(ps.spp, 32.0, 1e-9);
    assert_int_equal(ps.samples, 8 * 16 * 16);
    assert_int_equal(ps.adaptive_converged, 0);
    const uint32_t *cnt = rl_pt_sample_counts(r);
    uint32_t lo = UINT32_MAX, hi = 0;
    uint64_t total = 0;
    for (size_t i = 0; i < 16 * 16; ++i) {
        lo = cnt[i] < lo ? cnt[i] : lo;
        hi = cnt[i] > hi ? cnt[i] : hi;
        total += cnt[i];
    }
    assert_int_equal(total, 32 * 16 * 16);
    assert_true(lo >= 8 && hi > 2 * lo);
    rl_image_release(img);
    rl_renderer_release(r);

    img = render_frames(s, &cam, (const char *const[]){ "spp", "8", "adaptive", "on", "adaptive_threshold", "1e6",
                                                        NULL },
                        3, &r);
    assert_int_equal(rl_pt_get_stats(r, &ps), RL_OK);
    assert_float_equal(ps.spp, 8.0, 1e-9);
    assert_int_equal(ps.samples, 0);
    assert_int_equal(ps.pixels_traced, 0);
    assert_int_equal(ps.adaptive_converged, 16 * 16);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* Adaptive and uniform sampling at the same budget converge to the same
 * image means: six seeds each at 128 spp (16 x 16); the difference of the
 * means must lie within 4 sigma of its spread over the seeds (plus 1e-4
 * for a spread that happens to come out tiny). */
static void test_adaptive_converges_to_the_uniform_means(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    enum { SEEDS = 6 };
    double m[2][SEEDS][3];
    for (int mode = 0; mode < 2; ++mode)
        for (int k = 0; k < SEEDS; ++k) {
            char seed[16];
            snprintf(seed, sizeof seed, "%d", 10 + k);
            const char *opts[] = { "spp", "32", "seed", seed, "adaptive", mode ? "on" : "off", NULL };
            rl_renderer *r;
            rl_image *img = render_frames(s, &cam, opts, 4, &r);
            mean_color(img, m[mode][k]);
            rl_image_release(img);
            rl_renderer_release(r);
        }
    for (int c = 0; c < 3; ++c) {
        double mu[2] = { 0.0, 0.0 }, var[2] = { 0.0, 0.0 };
        for (int mode = 0; mode < 2; ++mode) {
            for (int k = 0; k < SEEDS; ++k)
                mu[mode] += m[mode][k][c] / SEEDS;
            for (int k = 0; k < SEEDS; ++k)
                var[mode] += (m[mode][k][c] - mu[mode]) * (m[mode][k][c] - mu[mode]) / (SEEDS - 1);
        }
        double sigma = sqrt(var[0] / SEEDS + var[1] / SEEDS);
        print_message("channel %d: uniform %.5f, adaptive %.5f, sigma %.2g\n", c, mu[0], mu[1], sigma);
        assert_true(fabs(mu[0] - mu[1]) < 4.0 * sigma + 1e-4);
    }
    rl_scene_release(s);
}

/* Where the samples go: pixels at a geometric edge of the G-buffer (a
 * neighbour with another normal or object: coverage noise, penumbrae in
 * corners) against pixels deep inside one flat face (5 x 5 neighbourhood
 * on the same plane), on the Cornell box after 64 spp. The edges must get
 * at least 1.2 times the flat faces' mean count (measured: 1.32; the
 * uniform start of 8 spp and the 3 x 3 averaging of the error flatten the
 * contrast). */
static void test_edges_get_more_samples_than_flat_walls(void **state)
{
    (void)state;
    const int size = 32;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, size);
    rl_renderer *r;
    rl_image *img = render_frames(s, &cam, (const char *const[]){ "spp", "16", "adaptive", "on", NULL }, 4, &r);
    const uint32_t *cnt = rl_pt_sample_counts(r);
    const rl_gbuffer *g = rl_pt_gbuffer(r);
    assert_non_null(cnt);
    assert_non_null(g);
    double edge = 0.0, flat = 0.0;
    int n_edge = 0, n_flat = 0;
    for (int y = 2; y < size - 2; ++y)
        for (int x = 2; x < size - 2; ++x) {
            size_t i = (size_t)y * size + x;
            if (g->object[i] == RL_ID_NONE)
                continue;
            int differ1 = 0, differ2 = 0;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    size_t j = (size_t)(y + dy) * size + x + dx;
                    bool same = g->object[j] == g->object[i] && rl_dot(g->normal[j], g->normal[i]) > 0.999f;
                    if (!same && abs(dx) <= 1 && abs(dy) <= 1)
                        ++differ1;
                    if (!same)
                        ++differ2;
                }
            if (differ1 > 0) {
                edge += cnt[i];
                ++n_edge;
            } else if (differ2 == 0) {
                flat += cnt[i];
                ++n_flat;
            }
        }
    assert_true(n_edge > 20 && n_flat > 20);
    edge /= n_edge;
    flat /= n_flat;
    print_message("mean samples: %.1f at %d edge pixels, %.1f at %d flat pixels\n", edge, n_edge, flat, n_flat);
    assert_true(edge > 1.2 * flat);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_options_are_checked),
        cmocka_unit_test(test_uniform_start_is_the_uniform_image),
        cmocka_unit_test(test_image_does_not_depend_on_the_thread_count),
        cmocka_unit_test(test_frame_budget_and_convergence_stop),
        cmocka_unit_test(test_adaptive_converges_to_the_uniform_means),
        cmocka_unit_test(test_edges_get_more_samples_than_flat_walls),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
