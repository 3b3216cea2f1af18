/* test_bdpt.c: the bidirectional path tracer "bdpt" against pt, which was
 * validated on its own (test_pathtrace_mis.c): the same mean image on the
 * Cornell box and under a point light, every strategy alone converging to
 * the same value as their MIS combination, the same image for any thread
 * count, the error falling with the samples, and lower error than pt at
 * equal samples in a room lit only through a lamp shade. Small images, so
 * the file runs in seconds. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render/render_fixtures.h"

/* Channel means over the rows from first_row on. */
static void means_from(const rl_image *img, int first_row, double out[3])
{
    size_t n = (size_t)img->width * img->height;
    out[0] = out[1] = out[2] = 0.0;
    for (size_t i = (size_t)first_row * img->width; i < n; ++i) {
        out[0] += img->color[i].x;
        out[1] += img->color[i].y;
        out[2] += img->color[i].z;
    }
    for (int k = 0; k < 3; ++k)
        out[k] /= (double)(n - (size_t)first_row * img->width);
}

static double rmse(const rl_image *a, const rl_image *b)
{
    size_t n = (size_t)a->width * a->height;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double dx = a->color[i].x - b->color[i].x, dy = a->color[i].y - b->color[i].y,
               dz = a->color[i].z - b->color[i].z;
        sum += (dx * dx + dy * dy + dz * dz) / 3.0;
    }
    return sqrt(sum / (double)n);
}

static void assert_rows_close(const rl_image *a, const rl_image *b, int first_row, double tol, const char *what)
{
    double ma[3], mb[3];
    means_from(a, first_row, ma);
    means_from(b, first_row, mb);
    for (int k = 0; k < 3; ++k) {
        double rel = fabs(ma[k] - mb[k]) / mb[k];
        print_message("%s: channel %d: %.5f vs %.5f (%+.3f %%)\n", what, k, ma[k], mb[k], 100.0 * (ma[k] / mb[k] - 1.0));
        assert_true(rel < tol);
    }
}

static void assert_means_close(const rl_image *a, const rl_image *b, double tol, const char *what)
{
    assert_rows_close(a, b, 0, tol, what);
}

static rl_image *render(const char *algo, const rl_scene *s, const rl_camera *cam, const char *const *opts)
{
    return fx_render(algo, s, cam, RL_LAYER_COLOR, opts, NULL);
}

/* The room under a point light near the ceiling. */
static rl_scene *point_room(rl_camera *cam, int size)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    fx_add_room(s);
    rl_light p = { .type = RL_LIGHT_POINT, .color = rl_v3(1.0f, 0.9f, 0.8f), .intensity = 2.0f,
                   .position = rl_v3(0.2f, 1.7f, -0.1f) };
    assert_int_equal(rl_scene_add_light(s, &p), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    *cam = (rl_camera){ .eye = rl_v3(0.0f, 1.0f, 0.95f), .target = rl_v3(0.0f, 0.9f, -1.0f), .fov_deg = 70.0f,
                        .width = size, .height = size };
    return s;
}

static void test_converges_to_pt_on_cornell(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 32);
    const char *pt_opts[] = { "spp", "256", "seed", "3", NULL };
    const char *bd_opts[] = { "spp", "128", "seed", "5", NULL };
    rl_image *ref = render("pt", s, &cam, pt_opts);
    rl_image *img = render("bdpt", s, &cam, bd_opts);
    /* Below the lamp (rows 4-5): its edge pixels (radiance 17 or 0) would dominate
     * the noise of a 32 x 32 mean. */
    assert_rows_close(img, ref, cam.height / 4, 0.005, "cornell bdpt vs pt");
    rl_image_release(ref);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_converges_to_pt_under_a_point_light(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = point_room(&cam, 24);
    const char *pt_opts[] = { "spp", "256", "seed", "3", NULL };
    const char *bd_opts[] = { "spp", "128", "seed", "5", NULL };
    rl_image *ref = render("pt", s, &cam, pt_opts);
    rl_image *img = render("bdpt", s, &cam, bd_opts);
    assert_means_close(img, ref, 0.005, "point light bdpt vs pt");
    rl_image_release(ref);
    rl_image_release(img);
    rl_scene_release(s);
}

/* Paths of three vertices (max_depth = 0: the camera, a surface, a light):
 * strategies (0,3), (1,2) and (2,1) each estimate all of them, so alone and
 * unweighted they agree; the weighted sum over all strategies adds the
 * lamp seen directly, (0,2), which with the same seed and samples sees the
 * lamp through the same camera rays. Uniform weights give the same mean.
 * Tolerances: (0,3) rarely finds the small lamp, its mean is within 1.6 %
 * (one sigma) at these samples. */
static void test_each_strategy_alone_is_unbiased(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 32);
    const char *strategies[] = { "0,3", "1,2", "2,1" };
    rl_image *one[3];
    for (int k = 0; k < 3; ++k) {
        const char *opts[] = { "spp", "256", "max_depth", "0", "strategy", strategies[k], NULL };
        one[k] = render("bdpt", s, &cam, opts);
    }
    const char *direct_opts[] = { "spp", "128", "max_depth", "0", "strategy", "0,2", NULL };
    const char *all_opts[] = { "spp", "128", "max_depth", "0", NULL };
    const char *uni_opts[] = { "spp", "128", "max_depth", "0", "mis", "uniform", NULL };
    rl_image *direct = render("bdpt", s, &cam, direct_opts);
    rl_image *all = render("bdpt", s, &cam, all_opts);
    rl_image *uni = render("bdpt", s, &cam, uni_opts);
    /* (1,2) has the least noise here: the others are compared with it. */
    assert_means_close(one[0], one[1], 0.05, "strategy 0,3 vs 1,2");
    assert_means_close(one[2], one[1], 0.02, "strategy 2,1 vs 1,2");
    size_t n = (size_t)cam.width * cam.height;
    for (size_t i = 0; i < n; ++i) {
        one[1]->color[i].x += direct->color[i].x;
        one[1]->color[i].y += direct->color[i].y;
        one[1]->color[i].z += direct->color[i].z;
    }
    assert_means_close(all, one[1], 0.005, "MIS vs (0,2) + (1,2)");
    assert_means_close(uni, all, 0.01, "uniform vs power heuristic");
    for (int k = 0; k < 3; ++k)
        rl_image_release(one[k]);
    rl_image_release(direct);
    rl_image_release(all);
    rl_image_release(uni);
    rl_scene_release(s);
}

static void test_same_image_for_one_and_two_threads(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 40);
    const char *one[] = { "spp", "2", "threads", "1", NULL };
    const char *two[] = { "spp", "2", "threads", "2", NULL };
    rl_image *a = render("bdpt", s, &cam, one);
    rl_image *b = render("bdpt", s, &cam, two);
    fx_assert_images_identical(a, b);
    rl_image_release(a);
    rl_image_release(b);
    rl_scene_release(s);
}

/* Accumulating frames continues the samples (frame by frame = one call). */
static void test_frames_accumulate(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 24);
    const char *two[] = { "spp", "2", NULL };
    rl_renderer *r = fx_make("bdpt", NULL);
    assert_int_equal(rl_renderer_set(r, "spp", "1"), RL_OK);
    rl_image *a = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
    rl_image_release(a);
    a = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
    rl_image *b = render("bdpt", s, &cam, two);
    fx_assert_images_identical(a, b);
    assert_int_equal(rl_renderer_set(r, "strategy", "1"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "strategy", "2,0"), RL_ERR_INVALID_ARG);
    rl_image_release(a);
    rl_image_release(b);
    rl_renderer_release(r);
    rl_scene_release(s);
}

static void test_error_falls_with_samples(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 32);
    const char *ref_opts[] = { "spp", "256", "seed", "9", NULL };
    rl_image *ref = render("pt", s, &cam, ref_opts);
    double e[3];
    const char *spps[] = { "4", "16", "64" };
    for (int k = 0; k < 3; ++k) {
        const char *opts[] = { "spp", spps[k], NULL };
        rl_image *img = render("bdpt", s, &cam, opts);
        e[k] = rmse(img, ref);
        print_message("bdpt %s spp: RMSE %.5f against pt 256 spp\n", spps[k], e[k]);
        rl_image_release(img);
    }
    assert_true(e[1] < 0.7 * e[0]);
    assert_true(e[2] < 0.7 * e[1]);
    rl_image_release(ref);
    rl_scene_release(s);
}

static void test_beats_pt_in_a_room_lit_through_a_shade(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_shade_room(&cam, 24);
    const char *ref_opts[] = { "spp", "512", "seed", "11", NULL };
    const char *eq[] = { "spp", "16", NULL };
    rl_image *ref = render("bdpt", s, &cam, ref_opts);
    rl_image *pt = render("pt", s, &cam, eq);
    rl_image *bd = render("bdpt", s, &cam, eq);
    double e_pt = rmse(pt, ref), e_bd = rmse(bd, ref);
    print_message("shade room, 16 spp: RMSE pt %.5f, bdpt %.5f (ratio %.2f)\n", e_pt, e_bd, e_pt / e_bd);
    assert_true(e_bd < 0.7 * e_pt);
    /* and a long pt agrees with the reference's mean (pt's own noise is
     * about 1.5 % of the mean here) */
    const char *pt_long[] = { "spp", "1024", "seed", "4", NULL };
    rl_image *ptl = render("pt", s, &cam, pt_long);
    assert_means_close(ptl, ref, 0.04, "shade room pt 1024 vs bdpt 512");
    rl_image_release(ref);
    rl_image_release(pt);
    rl_image_release(bd);
    rl_image_release(ptl);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_converges_to_pt_on_cornell),
        cmocka_unit_test(test_converges_to_pt_under_a_point_light),
        cmocka_unit_test(test_each_strategy_alone_is_unbiased),
        cmocka_unit_test(test_same_image_for_one_and_two_threads),
        cmocka_unit_test(test_frames_accumulate),
        cmocka_unit_test(test_error_falls_with_samples),
        cmocka_unit_test(test_beats_pt_in_a_room_lit_through_a_shade),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
