/* test_filter.c: the noise-reduction filters of Schröder 2017, Sec. 8.2
 * (rl_filter.h) against properties they must have: constants stay
 * constant, Gauss preserves energy and symmetry, the edge-preserving
 * filters keep a noise-free step, every filter lowers the error of a noisy
 * piecewise-constant image, and G-buffer guidance helps where the image's
 * edges are the G-buffer's object edges. */
#include <math.h>
#include <omp.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_filter.h"
#include "rl/rl_rng.h"

static const rl_filter_kind all_kinds[] = {
    RL_FILTER_GAUSS, RL_FILTER_BILATERAL, RL_FILTER_ANISO, RL_FILTER_KUWAHARA
};
#define NUM_KINDS (sizeof all_kinds / sizeof all_kinds[0])

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
        fail_msg("%s: %s", rl_filter_kind_name(d->kind), rl_last_error());
}

/* A hand-made G-buffer (rl_gbuffer_create lives with the path tracer):
 * only the arrays the filters read; the others stay NULL. */
typedef struct test_gbuffer {
    rl_gbuffer g;
} test_gbuffer;

static test_gbuffer *gbuffer(int w, int h)
{
    test_gbuffer *t = calloc(1, sizeof *t);
    size_t n = (size_t)w * (size_t)h;
    t->g.width = w;
    t->g.height = h;
    t->g.normal = calloc(n, sizeof *t->g.normal);
    t->g.depth = calloc(n, sizeof *t->g.depth);
    t->g.object = calloc(n, sizeof *t->g.object);
    assert_non_null(t->g.normal);
    assert_non_null(t->g.depth);
    assert_non_null(t->g.object);
    return t;
}

static void gbuffer_free(test_gbuffer *t)
{
    free(t->g.normal);
    free(t->g.depth);
    free(t->g.object);
    free(t);
}

/* ---- the piecewise-constant test picture -------------------------------- */

/* Three regions: left half, right half, and a square in the middle, each a
 * different object in the G-buffer with its own normal and depth. */
static int region(int x, int y, int w, int h)
{
    if (x >= w / 4 && x < 3 * w / 4 && y >= h / 4 && y < 3 * h / 4)
        return 2;
    return x < w / 2 ? 0 : 1;
}

static const rl_vec3 region_colour[3] = { { 0.2f, 0.3f, 0.4f }, { 0.6f, 0.5f, 0.3f },
                                          { 0.45f, 0.7f, 0.6f } };

static rl_image *clean_picture(int w, int h)
{
    rl_image *img = image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            *rl_image_pixel(img, x, y) = rl_v4_from3(region_colour[region(x, y, w, h)], 1.0f);
    return img;
}

static test_gbuffer *picture_gbuffer(int w, int h)
{
    static const rl_vec3 normals[3] = { { 0, 0, 1 }, { 0.6f, 0, 0.8f }, { 0, 0.6f, 0.8f } };
    static const float depths[3] = { 5.0f, 5.0f, 3.0f };
    test_gbuffer *t = gbuffer(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int r = region(x, y, w, h);
            size_t i = (size_t)y * w + x;
            t->g.normal[i] = normals[r];
            t->g.depth[i] = depths[r];
            t->g.object[i] = (uint32_t)r;
        }
    return t;
}

static float gauss_noise(rl_rng *rng)
{
    /* Box-Muller. */
    double u1 = 1.0 - rl_rng_double(rng), u2 = rl_rng_double(rng);
    return (float)(sqrt(-2.0 * log(u1)) * cos(2.0 * 3.14159265358979323846 * u2));
}

static rl_image *noisy(const rl_image *clean, float sigma, uint64_t seed)
{
    rl_image *img = image(clean->width, clean->height);
    rl_rng rng;
    rl_rng_seed(&rng, seed, 7);
    size_t n = (size_t)clean->width * clean->height;
    for (size_t i = 0; i < n; ++i) {
        rl_vec4 c = clean->color[i];
        img->color[i] = rl_v4(c.x + sigma * gauss_noise(&rng), c.y + sigma * gauss_noise(&rng),
                              c.z + sigma * gauss_noise(&rng), c.w);
    }
    return img;
}

static double rmse(const rl_image *a, const rl_image *b)
{
    size_t n = (size_t)a->width * a->height;
    double sum = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double dx = a->color[i].x - b->color[i].x, dy = a->color[i].y - b->color[i].y,
               dz = a->color[i].z - b->color[i].z;
        sum += dx * dx + dy * dy + dz * dz;
    }
    return sqrt(sum / (3.0 * (double)n));
}

/* ---- tests --------------------------------------------------------------- */

static void test_filters_keep_a_constant_image_constant(void **state)
{
    (void)state;
    const int w = 23, h = 17;
    rl_image *in = image(w, h), *out = image(w, h);
    rl_image_fill(in, rl_v4(0.3f, 0.6f, 0.9f, 0.5f));
    test_gbuffer *t = picture_gbuffer(w, h);
    /* The top rows see nothing (background): no normal, infinite depth. */
    for (int i = 0; i < 3 * w; ++i) {
        t->g.normal[i] = rl_v3s(0.0f);
        t->g.depth[i] = INFINITY;
        t->g.object[i] = RL_ID_NONE;
    }
    for (size_t k = 0; k < NUM_KINDS; ++k)
        for (int guided = 0; guided < 2; ++guided) {
            rl_image_fill(out, rl_v4(-1.0f, -1.0f, -1.0f, -1.0f));
            apply(&(rl_filter_desc){ .kind = all_kinds[k] }, in, guided ? &t->g : NULL, out);
            for (int i = 0; i < w * h; ++i) {
                rl_vec4 c = out->color[i];
                if (fabsf(c.x - 0.3f) > 1e-5f || fabsf(c.y - 0.6f) > 1e-5f ||
                    fabsf(c.z - 0.9f) > 1e-5f || c.w != 0.5f)
                    fail_msg("%s (guided %d): pixel %d is (%g %g %g %g)",
                             rl_filter_kind_name(all_kinds[k]), guided, i, (double)c.x,
                             (double)c.y, (double)c.z, (double)c.w);
            }
        }
    gbuffer_free(t);
    rl_image_release(in);
    rl_image_release(out);
}

static void test_gauss_preserves_an_impulse_and_is_symmetric(void **state)
{
    (void)state;
    const int n = 31, c = 15;
    rl_image *in = image(n, n), *out = image(n, n);
    rl_image_pixel(in, c, c)->x = 1.0f;
    apply(&(rl_filter_desc){ .kind = RL_FILTER_GAUSS, .sigma_s = 2.0f }, in, NULL, out);
    double sum = 0.0;
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            float v = rl_image_pixel(out, x, y)->x;
            sum += v;
            /* Mirror images about both axes and the diagonal. */
            assert_float_equal(v, rl_image_pixel(out, 2 * c - x, y)->x, 1e-7);
            assert_float_equal(v, rl_image_pixel(out, x, 2 * c - y)->x, 1e-7);
            assert_float_equal(v, rl_image_pixel(out, y, x)->x, 1e-7);
        }
    assert_float_equal(sum, 1.0, 1e-5);
    /* The peak spreads: the centre keeps only (1/(sqrt(2 pi) sigma))^2. */
    assert_true(rl_image_pixel(out, c, c)->x < 0.05f);
    assert_true(rl_image_pixel(out, c + 2, c)->x > 0.0f);
    rl_image_release(in);
    rl_image_release(out);
}

static void test_edge_preserving_filters_keep_a_step_sharp_while_gauss_blurs_it(void **state)
{
    (void)state;
    const int w = 32, h = 24, edge = 16;     /* columns < 16 dark, >= 16 bright */
    rl_image *in = image(w, h), *out = image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            *rl_image_pixel(in, x, y) = x < edge ? rl_v4(0.2f, 0.2f, 0.2f, 1.0f)
                                                 : rl_v4(0.8f, 0.8f, 0.8f, 1.0f);
    for (size_t k = 0; k < NUM_KINDS; ++k) {
        apply(&(rl_filter_desc){ .kind = all_kinds[k] }, in, NULL, out);
        /* Columns 14 and 17 lie 2 px from the edge. */
        float change = 0.0f;
        for (int y = 0; y < h; ++y)
            for (int x = edge - 2; x <= edge + 1; x += 3)
                change = fmaxf(change, fabsf(rl_image_pixel(out, x, y)->x -
                                             rl_image_pixel(in, x, y)->x));
        print_message("step edge: %-9s max change 2 px from the edge %.3g\n",
                      rl_filter_kind_name(all_kinds[k]), (double)change);
        if (all_kinds[k] == RL_FILTER_GAUSS)
            assert_true(change > 0.01f);
        else
            assert_true(change < 1e-3f);
    }
    rl_image_release(in);
    rl_image_release(out);
}

static void test_every_filter_lowers_the_error_of_a_noisy_image(void **state)
{
    (void)state;
    const int w = 96, h = 96;
    rl_image *clean = clean_picture(w, h), *in = noisy(clean, 0.1f, 2017), *out = image(w, h);
    test_gbuffer *t = picture_gbuffer(w, h);
    double before = rmse(in, clean);
    print_message("noisy input: RMSE %.4f\n", before);
    /* Defaults, then a colour sigma / conductance scale (0.3) wide enough
     * for the noise: then colour alone also mixes across the region edges
     * (colour steps 0.25..0.46), which the G-buffer prevents. */
    const rl_filter_desc descs[] = {
        { .kind = RL_FILTER_GAUSS },
        { .kind = RL_FILTER_BILATERAL },
        { .kind = RL_FILTER_ANISO },
        { .kind = RL_FILTER_KUWAHARA },
        { .kind = RL_FILTER_BILATERAL, .sigma_r = 0.3f },
        { .kind = RL_FILTER_ANISO, .kappa = 0.3f },
    };
    double unguided[6], guided[6];
    for (size_t k = 0; k < 6; ++k) {
        apply(&descs[k], in, NULL, out);
        unguided[k] = rmse(out, clean);
        apply(&descs[k], in, &t->g, out);
        guided[k] = rmse(out, clean);
        print_message("%-9s %-12s RMSE %.4f, G-buffer guided %.4f\n",
                      rl_filter_kind_name(descs[k].kind), k < 4 ? "(defaults)" : "(wide 0.3)",
                      unguided[k], guided[k]);
        assert_true(unguided[k] < before);
        assert_true(guided[k] < before);
        assert_true(guided[k] <= unguided[k] + 1e-6);
    }
    /* Image edges = object edges: guidance stops mixing across them. */
    assert_true(guided[1] < unguided[1]);
    assert_true(guided[4] < 0.95 * unguided[4]);
    assert_true(guided[5] < 0.5 * unguided[5]);
    gbuffer_free(t);
    rl_image_release(clean);
    rl_image_release(in);
    rl_image_release(out);
}

static void test_filters_do_not_depend_on_the_thread_count(void **state)
{
    (void)state;
    const int w = 40, h = 37;
    rl_image *clean = clean_picture(w, h), *in = noisy(clean, 0.1f, 5);
    rl_image *a = image(w, h), *b = image(w, h);
    test_gbuffer *t = picture_gbuffer(w, h);
    int threads = omp_get_max_threads();
    for (size_t k = 0; k < NUM_KINDS; ++k) {
        rl_filter_desc d = { .kind = all_kinds[k] };
        omp_set_num_threads(1);
        apply(&d, in, &t->g, a);
        omp_set_num_threads(threads > 1 ? threads : 2);
        apply(&d, in, &t->g, b);
        assert_memory_equal(a->color, b->color, (size_t)w * h * sizeof *a->color);
    }
    omp_set_num_threads(threads);
    gbuffer_free(t);
    rl_image_release(clean);
    rl_image_release(in);
    rl_image_release(a);
    rl_image_release(b);
}

static void test_filter_rejects_bad_arguments(void **state)
{
    (void)state;
    rl_image *a = image(8, 8), *b = image(8, 8), *small = image(7, 8);
    test_gbuffer *t = gbuffer(8, 7);
    rl_filter_desc ok = { .kind = RL_FILTER_BILATERAL };
    rl_clear_error();
    assert_int_equal(rl_filter_apply(NULL, a, NULL, b), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_filter_apply(&ok, NULL, NULL, b), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_filter_apply(&ok, a, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_filter_apply(&ok, a, NULL, a), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_filter_apply(&ok, a, NULL, small), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_filter_apply(&ok, a, &t->g, b), RL_ERR_INVALID_ARG);
    const rl_filter_desc bad[] = {
        { .kind = RL_FILTER_KIND_COUNT },
        { .kind = (rl_filter_kind)-1 },
        { .kind = RL_FILTER_GAUSS, .sigma_s = -1.0f },
        { .kind = RL_FILTER_GAUSS, .sigma_s = NAN },
        { .kind = RL_FILTER_GAUSS, .sigma_s = 100.0f },     /* radius would exceed 64 */
        { .kind = RL_FILTER_GAUSS, .radius = -2 },
        { .kind = RL_FILTER_KUWAHARA, .radius = 65 },
        { .kind = RL_FILTER_BILATERAL, .sigma_r = -0.1f },
        { .kind = RL_FILTER_BILATERAL, .sigma_n = INFINITY },
        { .kind = RL_FILTER_BILATERAL, .sigma_z = -1.0f },
        { .kind = RL_FILTER_ANISO, .lambda = 0.3f },
        { .kind = RL_FILTER_ANISO, .lambda = -0.1f },
        { .kind = RL_FILTER_ANISO, .iterations = -1 },
        { .kind = RL_FILTER_ANISO, .iterations = 1000000 },
        { .kind = RL_FILTER_ANISO, .kappa = -1.0f },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i)
        if (rl_filter_apply(&bad[i], a, NULL, b) != RL_ERR_INVALID_ARG)
            fail_msg("bad desc %zu accepted", i);
    assert_int_equal(rl_last_status(), RL_ERR_INVALID_ARG);
    assert_true(strstr(rl_last_error(), "rl_filter_apply") != NULL);
    rl_clear_error();
    /* Kind none copies. */
    rl_image_fill(a, rl_v4(0.25f, 0.5f, 0.75f, 1.0f));
    assert_int_equal(rl_filter_apply(&(rl_filter_desc){ 0 }, a, NULL, b), RL_OK);
    assert_memory_equal(a->color, b->color, 64 * sizeof *a->color);
    gbuffer_free(t);
    rl_image_release(a);
    rl_image_release(b);
    rl_image_release(small);
}

static void test_filter_kind_names_round_trip(void **state)
{
    (void)state;
    for (int k = 0; k < RL_FILTER_KIND_COUNT; ++k) {
        rl_filter_kind parsed = RL_FILTER_KIND_COUNT;
        const char *name = rl_filter_kind_name((rl_filter_kind)k);
        assert_int_equal(rl_filter_kind_parse(name, &parsed), RL_OK);
        assert_int_equal(parsed, k);
    }
    assert_string_equal(rl_filter_kind_name(RL_FILTER_KUWAHARA), "kuwahara");
    rl_filter_kind out = RL_FILTER_GAUSS;
    rl_clear_error();
    assert_int_equal(rl_filter_kind_parse("median", &out), RL_ERR_INVALID_ARG);
    assert_int_equal(out, RL_FILTER_GAUSS);
    assert_int_equal(rl_filter_kind_parse(NULL, &out), RL_ERR_INVALID_ARG);
    rl_clear_error();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_filters_keep_a_constant_image_constant),
        cmocka_unit_test(test_gauss_preserves_an_impulse_and_is_symmetric),
        cmocka_unit_test(test_edge_preserving_filters_keep_a_step_sharp_while_gauss_blurs_it),
        cmocka_unit_test(test_every_filter_lowers_the_error_of_a_noisy_image),
        cmocka_unit_test(test_filters_do_not_depend_on_the_thread_count),
        cmocka_unit_test(test_filter_rejects_bad_arguments),
        cmocka_unit_test(test_filter_kind_names_round_trip),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
