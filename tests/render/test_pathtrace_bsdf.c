/* test_pathtrace_bsdf.c: the path tracer's Phong importance sampling
 * (pathtrace_bsdf.c; Schröder 2017, Sec. 6.4.3). The sampler must draw
 * directions with exactly the density rl_pt_phong_pdf reports, and its
 * weight must be f cos / pdf, or the path tracer is biased on glossy
 * surfaces (the furnace test only sees the diffuse lobe). Checked against
 * a quadrature of the hemisphere, which needs neither function's help. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "render/pathtrace_internal.h"
#include "rl/rl_rng.h"

/* The thesis' object material (Sec. 9.3): 90 % diffuse, 10 % specular,
 * shininess 50; and a glossier one whose lobe dominates. */
static const rl_material thesis_mat = { .diffuse = { 0.63f, 0.54f, 0.45f }, .specular = { 0.07f, 0.06f, 0.05f },
                                        .shininess = 50.0f };
static const rl_material glossy_mat = { .diffuse = { 0.1f, 0.1f, 0.1f }, .specular = { 0.8f, 0.7f, 0.6f },
                                        .shininess = 20.0f };

/* A surface with normal +z, seen from `view_deg` off the normal. */
static pt_surface surface(const rl_material *m, float view_deg)
{
    float a = view_deg * RL_PI / 180.0f;
    pt_surface s = { .ng = rl_v3(0, 0, 1), .ns = rl_v3(0, 0, 1), .v = rl_v3(sinf(a), 0.0f, cosf(a)),
                     .front = true, .kd = m->diffuse, .m = m, .tri = 0 };
    return s;
}

/* Quadrature over the upper hemisphere in (mu = cos theta, phi): MU x PHI
 * midpoint cells of equal solid angle (d omega = d mu d phi). */
#define PI_D 3.14159265358979323846
#define MU 800
#define PHI 1600
#define BINS_MU 8
#define BINS_PHI 8

static rl_vec3 dir_of(double mu, double phi)
{
    double st = sqrt(1.0 - mu * mu);
    return rl_v3((float)(st * cos(phi)), (float)(st * sin(phi)), (float)mu);
}

static int bin_of(rl_vec3 w)
{
    double mu = w.z, phi = atan2(w.y, w.x);
    if (phi < 0.0)
        phi += 2.0 * PI_D;
    int i = (int)(mu * BINS_MU), j = (int)(phi / (2.0 * PI_D) * BINS_PHI);
    i = i < 0 ? 0 : (i >= BINS_MU ? BINS_MU - 1 : i);
    j = j < 0 ? 0 : (j >= BINS_PHI ? BINS_PHI - 1 : j);
    return i * BINS_PHI + j;
}

/* Integrals of the pdf per bin, of the pdf over the hemisphere and of
 * f cos (the directional albedo, per channel). */
static void quadrature(const pt_surface *s, double bins[BINS_MU * BINS_PHI], double *pdf_total, double albedo[3])
{
    double cell = (1.0 / MU) * (2.0 * PI_D / PHI);
    *pdf_total = 0.0;
    albedo[0] = albedo[1] = albedo[2] = 0.0;
    for (int b = 0; b < BINS_MU * BINS_PHI; ++b)
        bins[b] = 0.0;
    for (int i = 0; i < MU; ++i) {
        double mu = (i + 0.5) / MU;
        for (int j = 0; j < PHI; ++j) {
            rl_vec3 w = dir_of(mu, (j + 0.5) * 2.0 * PI_D / PHI);
            double p = rl_pt_phong_pdf(s, w) * cell;
            bins[bin_of(w)] += p;
            *pdf_total += p;
            rl_vec3 f = rl_pt_phong_eval(s, w);
            albedo[0] += f.x * mu * cell;
            albedo[1] += f.y * mu * cell;
            albedo[2] += f.z * mu * cell;
        }
    }
}

static void check_sampling(const rl_material *m, float view_deg)
{
    pt_surface s = surface(m, view_deg);
    double expect[BINS_MU * BINS_PHI], pdf_total, albedo[3];
    quadrature(&s, expect, &pdf_total, albedo);

    rl_rng r;
    rl_rng_seed(&r, 42, (uint64_t)view_deg);
    const int n = 400000;
    double count[BINS_MU * BINS_PHI] = { 0 }, sum[3] = { 0 };
    int taken = 0;
    for (int k = 0; k < n; ++k) {
        rl_vec3 wi, w;
        if (!rl_pt_phong_sample(&s, rl_rng_float(&r), rl_rng_float(&r), rl_rng_float(&r), &wi, &w))
            continue;                     /* below the surface: weight 0 */
        ++taken;
        assert_float_equal(rl_length(wi), 1.0f, 1e-4f);
        assert_true(wi.z > 0.0f);
        /* The weight is f cos / pdf with the reported pdf. */
        float pdf = rl_pt_phong_pdf(&s, wi);
        rl_vec3 f = rl_pt_phong_eval(&s, wi);
        assert_true(pdf > 0.0f);
        assert_float_equal(w.x, f.x * wi.z / pdf, 1e-4f * (1.0f + w.x));
        assert_float_equal(w.z, f.z * wi.z / pdf, 1e-4f * (1.0f + w.z));
        count[bin_of(wi)] += 1.0;
        sum[0] += w.x;
        sum[1] += w.y;
        sum[2] += w.z;
    }
    /* Directions follow the pdf: chi-square over 64 bins of equal mu and
     * phi width against n times each bin's pdf mass (the mass below the
     * horizon is where samples are refused). 63 degrees of freedom: the
     * 99.9 % quantile is 103.4. */
    double chi2 = 0.0;
    int used = 0;
    for (int b = 0; b < BINS_MU * BINS_PHI; ++b) {
        double e = n * expect[b];
        if (e < 5.0)
            continue;                     /* too few expected to count */
        chi2 += (count[b] - e) * (count[b] - e) / e;
        ++used;
    }
    /* The mean weight is the directional albedo integral of f cos. */
    double est[3] = { sum[0] / n, sum[1] / n, sum[2] / n };
    print_message("phong kd %.2f ks %.2f n %.0f, view %.0f deg: pdf integrates to %.4f, %d of %d "
                  "samples taken, chi2 %.1f over %d bins; albedo %.4f (quadrature %.4f)\n",
                  m->diffuse.x, m->specular.x, m->shininess, view_deg, pdf_total, taken, n, chi2, used,
                  est[0], albedo[0]);
    assert_true(pdf_total > 0.97 && pdf_total < 1.001);
    assert_float_equal((double)taken / n, pdf_total, 0.005);
    assert_true(used >= 30);
    assert_true(chi2 < 103.4 * used / 63.0 + 10.0);
    for (int c = 0; c < 3; ++c)
        assert_float_equal(est[c], albedo[c], 0.01 * albedo[c] + 1e-4);
}

static void test_phong_samples_follow_the_reported_pdf_for_the_thesis_material(void **state)
{
    (void)state;
    check_sampling(&thesis_mat, 0.0f);
    check_sampling(&thesis_mat, 35.0f);
    check_sampling(&thesis_mat, 70.0f);
}

static void test_phong_samples_follow_the_reported_pdf_for_a_glossy_material(void **state)
{
    (void)state;
    check_sampling(&glossy_mat, 20.0f);
    check_sampling(&glossy_mat, 60.0f);
}

/* A Lambertian surface: the weight is k_d exactly (no noise from the
 * sampler), and a black one is never sampled. */
static void test_lambertian_weight_is_kd_and_black_is_refused(void **state)
{
    (void)state;
    rl_material lam = { .diffuse = { 0.5f, 0.25f, 0.75f } };
    pt_surface s = surface(&lam, 10.0f);
    rl_rng r;
    rl_rng_seed(&r, 3, 3);
    for (int k = 0; k < 1000; ++k) {
        rl_vec3 wi, w;
        if (!rl_pt_phong_sample(&s, rl_rng_float(&r), rl_rng_float(&r), rl_rng_float(&r), &wi, &w))
            continue;
        assert_float_equal(w.x, 0.5f, 1e-5f);
        assert_float_equal(w.y, 0.25f, 1e-5f);
        assert_float_equal(w.z, 0.75f, 1e-5f);
    }
    rl_material black = { 0 };
    pt_surface b = surface(&black, 10.0f);
    rl_vec3 wi, w;
    assert_false(rl_pt_phong_sample(&b, 0.5f, 0.5f, 0.5f, &wi, &w));
    assert_true(rl_pt_phong_pdf(&b, rl_v3(0, 0, 1)) == 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_phong_samples_follow_the_reported_pdf_for_the_thesis_material),
        cmocka_unit_test(test_phong_samples_follow_the_reported_pdf_for_a_glossy_material),
        cmocka_unit_test(test_lambertian_weight_is_kd_and_black_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
