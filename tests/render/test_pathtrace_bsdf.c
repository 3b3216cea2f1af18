/* test_pathtrace_bsdf.c: the path tracer's Phong importance sampling
 * (pathtrace_bsdf.c; Schröder 2017, Sec. 6.4.3), and issue 37's GGX BRDF
 * and Schlick Fresnel (pathtrace_ggx.c). The sampler must draw
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
            double p = rl_pt_bsdf_pdf(s, w) * cell;
            bins[bin_of(w)] += p;
            *pdf_total += p;
            rl_vec3 f = rl_pt_bsdf_eval(s, w);
            albedo[0] += f.x * mu * cell;
            albedo[1] += f.y * mu * cell;
            albedo[2] += f.z * mu * cell;
        }
    }
}

/* check_sampling for any BRDF of the dispatch (rl_pt_bsdf_*): Phong, or
 * GGX, whose visible-normal sampling sends some directions below the
 * horizon (pdf_total < 1, the single-scattering loss), so the pdf's mass
 * over the hemisphere is only required to match the share of samples
 * taken, and to reach min_mass. */
static void check_sampling_mass(const rl_material *m, float view_deg, double min_mass, bool ms);

static void check_sampling(const rl_material *m, float view_deg)
{
    check_sampling_mass(m, view_deg, 0.97, false);
}

/* ms: GGX with its energy compensation lobe. */
static void check_sampling_mass(const rl_material *m, float view_deg, double min_mass, bool ms)
{
    pt_surface s = surface(m, view_deg);
    s.ggx_ms = ms;
    double expect[BINS_MU * BINS_PHI], pdf_total, albedo[3];
    quadrature(&s, expect, &pdf_total, albedo);

    rl_rng r;
    rl_rng_seed(&r, 42, (uint64_t)view_deg);
    /* Fewer samples for GGX, whose evaluation costs more (ASan runs). */
    const int n = m->bsdf == RL_BSDF_GGX ? 200000 : 400000;
    double count[BINS_MU * BINS_PHI] = { 0 }, sum[3] = { 0 };
    int taken = 0;
    for (int k = 0; k < n; ++k) {
        rl_vec3 wi, w;
        if (!rl_pt_bsdf_sample(&s, rl_rng_float(&r), rl_rng_float(&r), rl_rng_float(&r), &wi, &w))
            continue;                     /* below the surface: weight 0 */
        ++taken;
        assert_float_equal(rl_length(wi), 1.0f, 1e-4f);
        assert_true(wi.z > 0.0f);
        /* The weight is f cos / pdf with the reported pdf. */
        float pdf = rl_pt_bsdf_pdf(&s, wi);
        rl_vec3 f = rl_pt_bsdf_eval(&s, wi);
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
    if (m->bsdf == RL_BSDF_GGX)
        print_message("ggx%s kd %.2f roughness %.2f metallic %.1f, view %.0f deg: pdf integrates to %.4f, %d of %d "
                      "samples taken, chi2 %.1f over %d bins; albedo %.4f (quadrature %.4f)\n", ms ? " ms" : "",
                      m->diffuse.x, m->roughness, m->metallic, view_deg, pdf_total, taken, n, chi2, used, est[0],
                      albedo[0]);
    else
        print_message("phong kd %.2f ks %.2f n %.0f, view %.0f deg: pdf integrates to %.4f, %d of %d "
                      "samples taken, chi2 %.1f over %d bins; albedo %.4f (quadrature %.4f)\n",
                      m->diffuse.x, m->specular.x, m->shininess, view_deg, pdf_total, taken, n, chi2, used,
                      est[0], albedo[0]);
    assert_true(pdf_total > min_mass && pdf_total < 1.001);
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

/* The Lambertian fast path (pt_surface.lambert, issue 37's cost of a
 * sample) returns what the general Phong path returns, bit for bit:
 * directions, weights, the pdf handed to MIS, f and the pdf of a light
 * sample's direction; and only Lambertian surfaces take it. */
static void test_lambert_fast_path_equals_the_general_path_bit_for_bit(void **state)
{
    (void)state;
    rl_rng r;
    rl_rng_seed(&r, 11, 5);
    int sampled = 0;
    for (int k = 0; k < 20000; ++k) {
        rl_material m = { .diffuse = { rl_rng_float(&r), rl_rng_float(&r), rl_rng_float(&r) } };
        rl_vec3 ns = rl_normalize(rl_v3(rl_rng_float(&r) - 0.5f, rl_rng_float(&r) - 0.5f, 1.0f));
        rl_vec3 ng = rl_normalize(rl_v3(0.3f * (rl_rng_float(&r) - 0.5f), 0.3f * (rl_rng_float(&r) - 0.5f), 1.0f));
        rl_vec3 v = rl_normalize(rl_v3(rl_rng_float(&r) - 0.5f, rl_rng_float(&r) - 0.5f, rl_rng_float(&r)));
        pt_surface slow = { .ng = ng, .ns = ns, .v = v, .front = true, .kd = m.diffuse, .m = &m, .tri = 0 };
        pt_surface fast = slow;
        fast.lambert = true;
        assert_true(rl_pt_surface_lambert(&slow));
        /* u_lobe up to the largest float below 1: P_d is exactly 1. */
        float u0 = k % 7 == 0 ? 0.99999994f : rl_rng_float(&r), u1 = rl_rng_float(&r), u2 = rl_rng_float(&r);
        rl_vec3 wi_s = rl_v3s(0.0f), w_s = rl_v3s(0.0f), wi_f = rl_v3s(1.0f), w_f = rl_v3s(1.0f);
        float pdf_s = -1.0f, pdf_f = -2.0f;
        bool ok_s = rl_pt_bsdf_sample_pdf(&slow, u0, u1, u2, &wi_s, &w_s, &pdf_s);
        bool ok_f = rl_pt_bsdf_sample_pdf(&fast, u0, u1, u2, &wi_f, &w_f, &pdf_f);
        assert_true(ok_s == ok_f);
        if (ok_s) {
            ++sampled;
            assert_memory_equal(&wi_s, &wi_f, sizeof wi_s);
            assert_memory_equal(&w_s, &w_f, sizeof w_s);
            assert_memory_equal(&pdf_s, &pdf_f, sizeof pdf_s);
        }
        rl_vec3 l = rl_normalize(rl_v3(rl_rng_float(&r) - 0.5f, rl_rng_float(&r) - 0.5f, rl_rng_float(&r) - 0.2f));
        rl_vec3 f_s = rl_pt_bsdf_eval(&slow, l), f_f = rl_pt_bsdf_f(&fast, l);
        float p_s = rl_pt_bsdf_pdf(&slow, l), p_f = rl_pt_bsdf_density(&fast, l);
        assert_memory_equal(&f_s, &f_f, sizeof f_s);
        assert_memory_equal(&p_s, &p_f, sizeof p_s);
    }
    assert_true(sampled > 15000);
    /* Not Lambertian: a specular lobe, GGX, black, or a reflectance whose
     * mean is not finite. */
    rl_material spec = thesis_mat, ggx = { .diffuse = { 0.5f, 0.5f, 0.5f }, .bsdf = RL_BSDF_GGX, .roughness = 0.5f };
    rl_material black = { 0 }, huge = { .diffuse = { INFINITY, 0.5f, 0.5f } };
    const rl_material *not_lambert[] = { &spec, &ggx, &black, &huge };
    for (int k = 0; k < 4; ++k) {
        pt_surface s = surface(not_lambert[k], 20.0f);
        assert_false(rl_pt_surface_lambert(&s));
    }
}

/* ------------------------------------------------ Schlick and GGX (issue 37) */

static void test_schlick_fresnel_has_its_limits_and_is_reciprocal(void **state)
{
    (void)state;
    const float n = 1.5f, f0 = (n - 1.0f) * (n - 1.0f) / ((n + 1.0f) * (n + 1.0f));
    /* Normal incidence, from either side: ((n - 1) / (n + 1))^2 = 0.04. */
    assert_float_equal(rl_fresnel_schlick(1.0f, n), f0, 1e-6f);
    assert_float_equal(rl_fresnel_schlick(1.0f, 1.0f / n), f0, 1e-6f);
    /* Grazing incidence reflects everything; F grows monotonically. */
    assert_float_equal(rl_fresnel_schlick(0.0f, n), 1.0f, 1e-6f);
    assert_true(rl_fresnel_schlick(1e-3f, n) > 0.99f);
    float last = 0.0f;
    for (int i = 100; i >= 0; --i) {
        float f = rl_fresnel_schlick((float)i / 100.0f, n);
        assert_true(f >= last - 1e-7f && f <= 1.0f);
        last = f;
    }
    /* Beyond the critical angle inside the glass: total internal reflection. */
    float cos_crit = sqrtf(1.0f - 1.0f / (n * n));
    assert_float_equal(rl_fresnel_schlick(cos_crit - 1e-3f, 1.0f / n), 1.0f, 0.0f);
    assert_true(rl_fresnel_schlick(cos_crit + 1e-2f, 1.0f / n) < 1.0f);
    /* Reciprocal: the same F for a ray and its reverse through the
     * interface (theta_i outside, theta_t inside, Snell). */
    for (int i = 1; i < 20; ++i) {
        float ci = (float)i / 20.0f, si = sqrtf(1.0f - ci * ci);
        float ct = sqrtf(1.0f - si * si / (n * n));
        assert_float_equal(rl_fresnel_schlick(ci, n), rl_fresnel_schlick(ct, 1.0f / n), 1e-5f);
    }
    /* The exact Fresnel equations for unpolarised light agree to a few
     * hundredths (Schlick 1994's claim), here from 0 to 80 degrees. */
    for (int deg = 0; deg <= 80; deg += 5) {
        double ti = deg * PI_D / 180.0, tt = asin(sin(ti) / n);
        double rs = (cos(ti) - n * cos(tt)) / (cos(ti) + n * cos(tt));
        double rp = (n * cos(ti) - cos(tt)) / (n * cos(ti) + cos(tt));
        double exact = 0.5 * (rs * rs + rp * rp);
        assert_float_equal(rl_fresnel_schlick((float)cos(ti), n), exact, 0.03);
    }
}

/* Glass with Schlick's Fresnel: reflection is chosen with probability F
 * and refraction with 1 - F, each with weight 1, so R + T = 1 (nothing is
 * created or lost); a Schlick mirror reflects F(k_s) of the light. */
static void test_specular_event_splits_by_fresnel_and_conserves_energy(void **state)
{
    (void)state;
    rl_material glass = { .transmissivity = 1.0f, .ior = 1.5f, .fresnel = RL_FRESNEL_SCHLICK };
    for (int view = 0; view <= 80; view += 40) {
        pt_surface s = surface(&glass, (float)view);
        const int n = 20000;
        int reflected = 0;
        for (int k = 0; k < n; ++k) {
            rl_vec3 dir, w;
            bool refracted;
            rl_pt_specular_event(&s, ((float)k + 0.5f) / (float)n, &dir, &w, &refracted);
            assert_float_equal(w.x + w.y + w.z, 3.0f, 0.0f);   /* R + T = 1: no weight */
            assert_float_equal(rl_length(dir), 1.0f, 1e-5f);
            if (!refracted) {
                ++reflected;
                assert_true(dir.z > 0.0f);
            } else {
                assert_true(dir.z < 0.0f);
            }
        }
        float F = rl_fresnel_schlick(cosf((float)view * RL_PI / 180.0f), 1.5f);
        print_message("glass at %d deg: reflected %.4f, Schlick F %.4f\n", view, (double)reflected / n, F);
        assert_float_equal((double)reflected / n, F, 1.5 / n + 1e-4);
    }
    /* Without the Fresnel field the event is the thesis': always refract. */
    rl_material plain = { .transmissivity = 1.0f, .ior = 1.5f };
    pt_surface p = surface(&plain, 80.0f);
    rl_vec3 dir, w;
    bool refracted;
    rl_pt_specular_event(&p, 0.01f, &dir, &w, &refracted);
    assert_true(refracted);

    rl_material gold = { .reflectivity = 1.0f, .specular = { 1.0f, 0.78f, 0.34f }, .fresnel = RL_FRESNEL_SCHLICK };
    pt_surface g = surface(&gold, 0.0f);
    rl_pt_specular_event(&g, 0.5f, &dir, &w, &refracted);
    assert_false(refracted);
    assert_float_equal(w.y, 0.78f, 1e-6f);        /* F0 = k_s at normal incidence */
    g = surface(&gold, 89.9f);
    rl_pt_specular_event(&g, 0.5f, &dir, &w, &refracted);
    assert_true(w.z > 0.99f);                      /* white at grazing */
}

static rl_material ggx_material(float kd, float roughness, float metallic)
{
    rl_material m = { .diffuse = { kd, kd, kd }, .ior = 1.5f, .bsdf = RL_BSDF_GGX, .roughness = roughness,
                      .metallic = metallic };
    return m;
}

static void test_ggx_is_reciprocal(void **state)
{
    (void)state;
    rl_rng r;
    rl_rng_seed(&r, 7, 1);
    rl_material mats[] = { ggx_material(0.6f, 0.3f, 0.0f), ggx_material(0.9f, 0.7f, 1.0f),
                           ggx_material(0.4f, 1.0f, 0.5f) };
    assert_int_equal(sizeof mats / sizeof mats[0], 3);
    for (size_t k = 0; k < 2 * sizeof mats / sizeof mats[0]; ++k) {
        for (int i = 0; i < 2000; ++i) {
            float a = acosf(rl_rng_float(&r)), b = acosf(rl_rng_float(&r));
            float pa = 2.0f * RL_PI * rl_rng_float(&r), pb = 2.0f * RL_PI * rl_rng_float(&r);
            rl_vec3 wa = rl_v3(sinf(a) * cosf(pa), sinf(a) * sinf(pa), cosf(a));
            rl_vec3 wb = rl_v3(sinf(b) * cosf(pb), sinf(b) * sinf(pb), cosf(b));
            if (wa.z < 1e-3f || wb.z < 1e-3f)
                continue;
            /* The second round with the energy compensation lobe. */
            pt_surface sa = surface(&mats[k % 3], 0.0f), sb;
            sa.ggx_ms = k >= 3;
            sb = sa;
            sa.v = wa;
            sb.v = wb;
            rl_vec3 fab = rl_pt_ggx_eval(&sa, wb), fba = rl_pt_ggx_eval(&sb, wa);
            assert_true(fab.x >= 0.0f);
            assert_float_equal(fab.x, fba.x, 1e-4f * (1.0f + fab.x));
            assert_float_equal(fab.z, fba.z, 1e-4f * (1.0f + fab.z));
        }
    }
}

/* Visible-normal sampling draws exactly the reported density and its
 * mean weight is the quadrature's albedo within 1 %: a dielectric over a
 * diffuse base and a metal, rough and glossy, near-normal and grazing. */
static void test_ggx_samples_follow_the_reported_pdf(void **state)
{
    (void)state;
    rl_material plastic = ggx_material(0.5f, 0.5f, 0.0f);
    rl_material metal = ggx_material(0.9f, 0.45f, 1.0f);
    rl_material rough = ggx_material(0.8f, 1.0f, 1.0f);
    check_sampling_mass(&plastic, 60.0f, 0.95, false);
    check_sampling_mass(&metal, 75.0f, 0.7, false);
    check_sampling_mass(&rough, 30.0f, 0.5, false);
    /* With the compensation lobe: drawn by the cosine, the same mixture. */
    rl_material gold = ggx_material(0.9f, 0.7f, 1.0f);
    gold.diffuse = rl_v3(1.0f, 0.78f, 0.34f);
    check_sampling_mass(&gold, 45.0f, 0.7, true);
}

/* The white furnace of one microfacet lobe: F = 1 (metallic, k_d = 1),
 * so the albedo E[f cos / pdf] = E[G2 / G1] is the share of light single
 * scattering keeps. It never passes 1, reaches 1 as the roughness goes to
 * 0 and falls as it grows: GGX's long tail sends a share of the
 * reflections below the horizon (at normal view the microfacets beyond
 * 45 degrees, 1 - 1 / (1 + alpha^2): 5.9 % at roughness 0.5), and masking
 * takes more, the energy that multiple scattering between microfacets
 * would return. */
static void test_ggx_white_furnace(void **state)
{
    (void)state;
    const float roughness[] = { 0.05f, 0.25f, 0.5f, 0.75f, 1.0f };
    const float views[] = { 0.0f, 45.0f, 80.0f };
    double last[3] = { 1.0, 1.0, 1.0 };
    for (size_t i = 0; i < sizeof roughness / sizeof roughness[0]; ++i) {
        rl_material m = ggx_material(1.0f, roughness[i], 1.0f);
        for (size_t j = 0; j < sizeof views / sizeof views[0]; ++j) {
            pt_surface s = surface(&m, views[j]);
            rl_rng r;
            rl_rng_seed(&r, 11, (uint64_t)(i * 10 + j));
            const int n = 40000;
            double sum = 0.0;
            for (int k = 0; k < n; ++k) {
                rl_vec3 wi, w;
                if (rl_pt_ggx_sample(&s, 0.0f, rl_rng_float(&r), rl_rng_float(&r), &wi, &w)) {
                    assert_true(w.x <= 1.0f + 1e-4f);
                    sum += w.x;
                }
            }
            double albedo = sum / n;
            print_message("ggx furnace roughness %.2f view %2.0f deg: albedo %.4f (loss %.1f %%)\n",
                          roughness[i], views[j], albedo, 100.0 * (1.0 - albedo));
            assert_true(albedo <= 1.0 + 1e-6);
            assert_true(albedo <= last[j] + 0.002);      /* rougher loses more */
            last[j] = albedo;
            if (roughness[i] <= 0.05f)
                assert_true(albedo > 0.999);
            if (roughness[i] <= 0.25f && views[j] <= 45.0f)
                assert_true(albedo > 0.99);
            if (views[j] == 0.0f) {
                /* At least the reflections below the horizon are lost. An
                 * independent estimate: normals drawn from D cos (Walter
                 * et al. 2007's sampling, tan^2 = alpha^2 x / (1 - x)),
                 * where at normal view the weight is G2 alone. */
                double a = rl_pt_ggx_alpha(roughness[i]), a2 = a * a;
                assert_true(albedo <= 1.0 / (1.0 + a2) + 0.003);
                double ref = 0.0;
                for (int k = 0; k < n; ++k) {
                    double x = ((double)k + 0.5) / n, t = atan(a * sqrt(x / (1.0 - x)));
                    double cz = 2.0 * cos(t) * cos(t) - 1.0;       /* wi.z, reflected about m */
                    if (cz > 0.0)
                        ref += rl_pt_ggx_g2((float)a, (float)cz, 1.0f);
                }
                ref /= n;
                print_message("  independent (D cos sampling): %.4f\n", ref);
                assert_float_equal(albedo, ref, 0.01);
            }
            assert_true(albedo > 0.25);
        }
    }
}

/* The energy compensation's tables (pathtrace_ggx.c): E(mu) at nodes and
 * between them against a quadrature of 256^2 visible normals (8x the
 * tables' cells per side), and E_avg against 2 int E mu dmu by 96^2 at 32
 * midpoints of mu. */
static void test_ggx_ms_tables_match_the_quadrature(void **state)
{
    (void)state;
    const float roughness[] = { 0.2f, 0.25f, 0.5f, 0.8f, 1.0f };
    const float mus[] = { 0.02f, 0.1f, 0.17f, 0.3f, 0.55f, 0.8f, 1.0f };
    double worst = 0.0, worst_avg = 0.0;
    for (size_t i = 0; i < sizeof roughness / sizeof roughness[0]; ++i) {
        float alpha = rl_pt_ggx_alpha(roughness[i]);
        for (size_t j = 0; j < sizeof mus / sizeof mus[0]; ++j) {
            double ref = rl_pt_ggx_albedo_quadrature(alpha, mus[j], 256);
            double e = rl_pt_ggx_ms_albedo(roughness[i], mus[j]);
            assert_true(e >= 0.0 && e <= 1.0);
            if (fabs(e - ref) > worst)
                print_message("  E(%.2f) at roughness %.2f: %.4f, quadrature %.4f\n", mus[j], roughness[i], e, ref);
            worst = fmax(worst, fabs(e - ref));
        }
        double avg = 0.0;
        const int n = 32;
        for (int k = 0; k < n; ++k) {
            double mu = (k + 0.5) / n;
            avg += 2.0 * rl_pt_ggx_albedo_quadrature(alpha, (float)mu, 96) * mu / n;
        }
        double e_avg = rl_pt_ggx_ms_average(roughness[i]);
        print_message("ggx ms roughness %.2f: E_avg %.4f (quadrature %.4f), E(1) %.4f\n", roughness[i], e_avg, avg,
                      rl_pt_ggx_ms_albedo(roughness[i], 1.0f));
        worst_avg = fmax(worst_avg, fabs(e_avg - avg));
    }
    print_message("ggx ms tables: largest error of E %.5f, of E_avg %.5f\n", worst, worst_avg);
    assert_true(worst < 0.005);
    assert_true(worst_avg < 0.002);
    /* Smooth: no loss; rough: the average loss of the single-scattering
     * furnace below. */
    assert_true(rl_pt_ggx_ms_average(0.0f) > 0.999f);
    assert_true(rl_pt_ggx_ms_average(1.0f) < 0.6f);
}

/* The white furnace with the compensation (F = 1): the albedo, by the
 * sampler's mean weight over its whole mixture and by quadrature, is 1
 * within 1 % from normal to grazing view, where single scattering loses
 * up to 69 %. (Below roughness 0.5 the returned light comes from rare
 * grazing cosine samples; the tables' test covers those rows.) A gold of roughness 1 keeps more than single scattering
 * and less than its F_avg allows. */
static void test_ggx_ms_white_furnace(void **state)
{
    (void)state;
    const float roughness[] = { 0.5f, 0.75f, 1.0f };
    const float views[] = { 0.0f, 45.0f, 80.0f };
    for (size_t i = 0; i < sizeof roughness / sizeof roughness[0]; ++i) {
        rl_material m = ggx_material(1.0f, roughness[i], 1.0f);
        for (size_t j = 0; j < sizeof views / sizeof views[0]; ++j) {
            pt_surface s = surface(&m, views[j]), single = s;
            s.ggx_ms = true;
            rl_rng r;
            rl_rng_seed(&r, 13, (uint64_t)(i * 10 + j));
            const int n = 40000;
            double sum = 0.0, sum_single = 0.0;
            for (int k = 0; k < n; ++k) {
                rl_vec3 wi, w;
                float u0 = rl_rng_float(&r), u1 = rl_rng_float(&r), u2 = rl_rng_float(&r);
                if (rl_pt_ggx_sample(&s, u0, u1, u2, &wi, &w))
                    sum += w.x;
                if (rl_pt_ggx_sample(&single, u0, u1, u2, &wi, &w))
                    sum_single += w.x;
            }
            double albedo = sum / n, albedo_single = sum_single / n;
            double quad = 0.0;
            const int QM = 200, QP = 400;
            for (int a = 0; a < QM; ++a) {
                double mu = (a + 0.5) / QM;
                for (int b = 0; b < QP; ++b)
                    quad += rl_pt_ggx_eval(&s, dir_of(mu, (b + 0.5) * 2.0 * PI_D / QP)).x * mu;
            }
            quad *= (1.0 / QM) * (2.0 * PI_D / QP);
            print_message("ggx ms furnace roughness %.2f view %2.0f deg: albedo %.4f (quadrature %.4f), "
                          "single scattering %.4f\n", roughness[i], views[j], albedo, quad, albedo_single);
            assert_float_equal(albedo, 1.0, 0.01);
            assert_float_equal(quad, 1.0, 0.01);
            assert_true(albedo_single < 0.95);
        }
    }
    rl_material gold = ggx_material(1.0f, 1.0f, 1.0f);
    gold.diffuse = rl_v3(1.0f, 0.78f, 0.34f);
    pt_surface s = surface(&gold, 0.0f), single = s;
    s.ggx_ms = true;
    rl_rng r;
    rl_rng_seed(&r, 17, 0);
    double sum[3] = { 0 }, sum_single[3] = { 0 };
    const int n = 40000;
    for (int k = 0; k < n; ++k) {
        rl_vec3 wi, w;
        float u0 = rl_rng_float(&r), u1 = rl_rng_float(&r), u2 = rl_rng_float(&r);
        if (rl_pt_ggx_sample(&s, u0, u1, u2, &wi, &w)) {
            sum[0] += w.x;
            sum[2] += w.z;
        }
        if (rl_pt_ggx_sample(&single, u0, u1, u2, &wi, &w)) {
            sum_single[0] += w.x;
            sum_single[2] += w.z;
        }
    }
    print_message("ggx ms gold roughness 1: albedo r %.4f b %.4f, single scattering r %.4f b %.4f\n", sum[0] / n,
                  sum[2] / n, sum_single[0] / n, sum_single[2] / n);
    assert_float_equal(sum[0] / n, 1.0, 0.01);                /* F0 = 1 in red */
    assert_true(sum[2] > sum_single[2] * 1.05 && sum[2] / n < 0.34 + (1.0 - 0.34) / 21.0 + 0.01);
}

/* Heitz 2018's sampled normals follow D_wo(m) = G1(wo) max(0, wo.m) D(m)
 * / wo.z: the mean of any function of m agrees with its integral against
 * that density (here the mean of m.z and of D itself, by quadrature over
 * the hemisphere of normals). */
static void test_ggx_visible_normals_follow_the_distribution(void **state)
{
    (void)state;
    const float alpha = 0.4f;
    rl_vec3 wo = rl_v3(sinf(1.0f), 0.0f, cosf(1.0f));
    double q_mz = 0.0, q_mass = 0.0;
    const int MUQ = 500, PHIQ = 500;
    double cell = (1.0 / MUQ) * (2.0 * PI_D / PHIQ);
    for (int i = 0; i < MUQ; ++i) {
        double mu = (i + 0.5) / MUQ;
        for (int j = 0; j < PHIQ; ++j) {
            rl_vec3 m = dir_of(mu, (j + 0.5) * 2.0 * PI_D / PHIQ);
            double dwo = rl_pt_ggx_g1(alpha, wo.z) * fmax(0.0, rl_dot(wo, m)) * rl_pt_ggx_d(alpha, m.z) / wo.z;
            q_mass += dwo * cell;
            q_mz += m.z * dwo * cell;
        }
    }
    rl_rng r;
    rl_rng_seed(&r, 5, 5);
    const int n = 200000;
    double mz = 0.0;
    for (int k = 0; k < n; ++k) {
        rl_vec3 m = rl_pt_ggx_sample_vndf(wo, alpha, rl_rng_float(&r), rl_rng_float(&r));
        assert_float_equal(rl_length(m), 1.0f, 1e-4f);
        assert_true(rl_dot(m, wo) >= -1e-5f);
        mz += m.z;
    }
    print_message("vndf: density mass %.4f, mean m.z %.5f (quadrature %.5f)\n", q_mass, mz / n, q_mz);
    assert_float_equal(q_mass, 1.0, 0.005);
    assert_float_equal(mz / n, q_mz, 0.003);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_phong_samples_follow_the_reported_pdf_for_the_thesis_material),
        cmocka_unit_test(test_phong_samples_follow_the_reported_pdf_for_a_glossy_material),
        cmocka_unit_test(test_lambertian_weight_is_kd_and_black_is_refused),
        cmocka_unit_test(test_lambert_fast_path_equals_the_general_path_bit_for_bit),
        cmocka_unit_test(test_schlick_fresnel_has_its_limits_and_is_reciprocal),
        cmocka_unit_test(test_specular_event_splits_by_fresnel_and_conserves_energy),
        cmocka_unit_test(test_ggx_is_reciprocal),
        cmocka_unit_test(test_ggx_samples_follow_the_reported_pdf),
        cmocka_unit_test(test_ggx_white_furnace),
        cmocka_unit_test(test_ggx_ms_tables_match_the_quadrature),
        cmocka_unit_test(test_ggx_ms_white_furnace),
        cmocka_unit_test(test_ggx_visible_normals_follow_the_distribution),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
