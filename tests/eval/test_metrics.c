/* test_metrics.c: RMSE/PSNR/SSIM against known values and against a
 * brute-force SSIM that visits every truncated 11x11 window directly (Wang
 * et al. 2004, Eq. (13)-(16), two-pass moments), so that the separable
 * filter, the border renormalisation, the band halos and the mask are all
 * checked against an independent oracle. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl.h"

#define C1 (0.01 * 0.01)
#define C2 (0.03 * 0.03)

/* A macro so that a failure names the line; %.17g shows the last digit. */
#define assert_near(a, b, eps)                                                       \
    do {                                                                             \
        double a_ = (a), b_ = (b);                                                   \
        if (!(fabs(a_ - b_) <= (eps)))                                               \
            fail_msg("%.17g != %.17g (eps %g)", a_, b_, (double)(eps));              \
    } while (0)

/* ---- fixtures ---------------------------------------------------------- */

static uint32_t lcg_next(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

static float lcg_unit(uint32_t *s) { return (float)lcg_next(s) / (float)(1u << 24); }

static rl_image *make_image(int w, int h)
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(w, h, RL_LAYER_COLOR, &img), RL_OK);
    return img;
}

/* Smooth structure plus noise, with values slightly outside [0, 1] so that
 * clamping is exercised too. */
static rl_image *make_pattern(int w, int h, uint32_t seed)
{
    rl_image *img = make_image(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float base = 0.5f + 0.4f * sinf(0.3f * (float)x) * cosf(0.2f * (float)y);
            rl_vec4 *p = rl_image_pixel(img, x, y);
            *p = rl_v4(base + 0.3f * (lcg_unit(&seed) - 0.5f), base * lcg_unit(&seed),
                       1.1f * lcg_unit(&seed) - 0.05f, 1.0f);
        }
    return img;
}

/* A distorted copy: noise on every channel, different per pixel. */
static rl_image *make_distorted(const rl_image *src, uint32_t seed)
{
    rl_image *img = make_image(src->width, src->height);
    for (int k = 0; k < src->width * src->height; ++k) {
        rl_vec4 c = src->color[k];
        img->color[k] = rl_v4(c.x + 0.2f * (lcg_unit(&seed) - 0.5f),
                              c.y * (0.7f + 0.6f * lcg_unit(&seed)), 1.0f - c.z, 1.0f);
    }
    return img;
}

/* ---- the oracle -------------------------------------------------------- */

static double oracle_encode(float v, bool linear)
{
    double c = v > 0.0f ? (double)v : 0.0;
    c = c > 1.0 ? 1.0 : c;
    if (linear)
        return c;
    return c <= 0.0031308 ? 12.92 * c : 1.055 * pow(c, 1.0 / 2.4) - 0.055;
}

/* channel 0..2, or 3 for Rec. 601 luma */
static double oracle_value(const rl_image *img, int k, int channel, bool linear)
{
    rl_vec4 c = img->color[k];
    double r = oracle_encode(c.x, linear), g = oracle_encode(c.y, linear),
           b = oracle_encode(c.z, linear);
    if (channel == 3)
        return 0.299 * r + 0.587 * g + 0.114 * b;
    return channel == 0 ? r : channel == 1 ? g : b;
}

/* One channel of both images, encoded once (the oracle revisits each pixel
 * up to 121 times). */
typedef struct oracle_planes {
    int w, h;
    double *t, *r;
} oracle_planes;

static oracle_planes oracle_planes_make(const rl_image *t, const rl_image *r, int channel,
                                        bool linear)
{
    oracle_planes p = { t->width, t->height, NULL, NULL };
    size_t n = (size_t)p.w * (size_t)p.h;
    p.t = malloc(n * sizeof(double));
    p.r = malloc(n * sizeof(double));
    assert_non_null(p.t);
    assert_non_null(p.r);
    for (size_t k = 0; k < n; ++k) {
        p.t[k] = oracle_value(t, (int)k, channel, linear);
        p.r[k] = oracle_value(r, (int)k, channel, linear);
    }
    return p;
}

static void oracle_planes_free(oracle_planes *p)
{
    free(p->t);
    free(p->r);
}

/* SSIM of the single window centred on (px, py), straight from the 2D
 * definition: truncated Gaussian weights divided by their sum, means first,
 * then central moments. */
static double oracle_window(const oracle_planes *p, int px, int py)
{
    double wsum = 0.0, mx = 0.0, my = 0.0;
    for (int dy = -5; dy <= 5; ++dy)
        for (int dx = -5; dx <= 5; ++dx) {
            int x = px + dx, y = py + dy;
            if (x < 0 || y < 0 || x >= p->w || y >= p->h)
                continue;
            double g = exp(-(double)(dx * dx + dy * dy) / (2.0 * 1.5 * 1.5));
            wsum += g;
            mx += g * p->t[y * p->w + x];
            my += g * p->r[y * p->w + x];
        }
    mx /= wsum;
    my /= wsum;
    double sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (int dy = -5; dy <= 5; ++dy)
        for (int dx = -5; dx <= 5; ++dx) {
            int x = px + dx, y = py + dy;
            if (x < 0 || y < 0 || x >= p->w || y >= p->h)
                continue;
            double g = exp(-(double)(dx * dx + dy * dy) / (2.0 * 1.5 * 1.5)) / wsum;
            double a = p->t[y * p->w + x] - mx, b = p->r[y * p->w + x] - my;
            sxx += g * a * a;
            syy += g * b * b;
            sxy += g * a * b;
        }
    return ((2.0 * mx * my + C1) * (2.0 * sxy + C2)) / ((mx * mx + my * my + C1) * (sxx + syy + C2));
}

/* The oracle's SSIM map for the given options: luma, or RGB averaged. */
static double *oracle_map(const rl_image *t, const rl_image *r, const rl_metric_options *o)
{
    const int w = t->width, h = t->height;
    double *map = calloc((size_t)w * (size_t)h, sizeof(double));
    assert_non_null(map);
    const int first = o->ssim_rgb ? 0 : 3, last = o->ssim_rgb ? 2 : 3;
    for (int c = first; c <= last; ++c) {
        oracle_planes p = oracle_planes_make(t, r, c, o->linear);
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x)
                map[y * w + x] += oracle_window(&p, x, y) / (double)(last - first + 1);
        oracle_planes_free(&p);
    }
    return map;
}

/* SSIM of one pixel through the library, in double: a one-pixel mask. */
static double library_pixel(const rl_image *t, const rl_image *r, const rl_metric_options *o,
                            uint8_t *mask, int px, int py)
{
    size_t n = (size_t)t->width * (size_t)t->height;
    memset(mask, 0, n);
    mask[(size_t)py * (size_t)t->width + (size_t)px] = 1;
    rl_metric_options one = *o;
    one.mask = mask;
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(t, r, &one, &m), RL_OK);
    assert_int_equal(m.pixels, 1);
    return m.ssim;
}

/* ---- multi-scale oracle (Wang, Simoncelli & Bovik 2003) ---------------- */

/* Mean SSIM and mean contrast x structure of all windows of one level,
 * from the same direct window sums as oracle_window. */
static void oracle_level_means(const oracle_planes *p, double *ssim, double *cs)
{
    double sum_ssim = 0.0, sum_cs = 0.0;
    for (int py = 0; py < p->h; ++py)
        for (int px = 0; px < p->w; ++px) {
            double wsum = 0.0, mx = 0.0, my = 0.0;
            for (int dy = -5; dy <= 5; ++dy)
                for (int dx = -5; dx <= 5; ++dx) {
                    int x = px + dx, y = py + dy;
                    if (x < 0 || y < 0 || x >= p->w || y >= p->h)
                        continue;
                    double g = exp(-(double)(dx * dx + dy * dy) / (2.0 * 1.5 * 1.5));
                    wsum += g;
                    mx += g * p->t[y * p->w + x];
                    my += g * p->r[y * p->w + x];
                }
            mx /= wsum;
            my /= wsum;
            double sxx = 0.0, syy = 0.0, sxy = 0.0;
            for (int dy = -5; dy <= 5; ++dy)
                for (int dx = -5; dx <= 5; ++dx) {
                    int x = px + dx, y = py + dy;
                    if (x < 0 || y < 0 || x >= p->w || y >= p->h)
                        continue;
                    double g = exp(-(double)(dx * dx + dy * dy) / (2.0 * 1.5 * 1.5)) / wsum;
                    double a = p->t[y * p->w + x] - mx, b = p->r[y * p->w + x] - my;
                    sxx += g * a * a;
                    syy += g * b * b;
                    sxy += g * a * b;
                }
            double l = (2.0 * mx * my + C1) / (mx * mx + my * my + C1);
            double c = (2.0 * sxy + C2) / (sxx + syy + C2);
            sum_ssim += l * c;
            sum_cs += c;
        }
    *ssim = sum_ssim / (p->w * p->h);
    *cs = sum_cs / (p->w * p->h);
}

/* Burt 1981 REDUCE in 2D, straight from the definition: the 5x5 weights
 * w(m) w(n) with w = [1 4 6 4 1] / 16 over the taps inside the image,
 * divided by their sum, at every even pixel. */
static double *oracle_reduce(const double *src, int w, int h)
{
    static const double k[5] = { 1, 4, 6, 4, 1 };
    const int w2 = (w + 1) / 2, h2 = (h + 1) / 2;
    double *dst = malloc((size_t)w2 * (size_t)h2 * sizeof(double));
    assert_non_null(dst);
    for (int i = 0; i < h2; ++i)
        for (int j = 0; j < w2; ++j) {
            double s = 0.0, wsum = 0.0;
            for (int m = -2; m <= 2; ++m)
                for (int n = -2; n <= 2; ++n) {
                    int y = 2 * i + m, x = 2 * j + n;
                    if (x < 0 || y < 0 || x >= w || y >= h)
                        continue;
                    s += k[m + 2] * k[n + 2] * src[y * w + x];
                    wsum += k[m + 2] * k[n + 2];
                }
            dst[i * w2 + j] = s / wsum;
        }
    return dst;
}

/* Eq. (7) of Wang et al. 2003 with their five exponents, the first
 * `levels` renormalised; luma or RGB averaged. */
static double oracle_ms_ssim(const rl_image *t, const rl_image *r, const rl_metric_options *o,
                             int levels)
{
    static const double beta[5] = { 0.0448, 0.2856, 0.3001, 0.2363, 0.1333 };
    double bsum = 0.0;
    for (int j = 0; j < levels; ++j)
        bsum += beta[j];
    const int first = o->ssim_rgb ? 0 : 3, last = o->ssim_rgb ? 2 : 3;
    double total = 0.0;
    for (int c = first; c <= last; ++c) {
        oracle_planes p = oracle_planes_make(t, r, c, o->linear);
        double ms = 1.0;
        for (int j = 0; j < levels; ++j) {
            double ssim, cs;
            oracle_level_means(&p, &ssim, &cs);
            double v = j == levels - 1 ? ssim : cs;
            ms *= pow(v > 0.0 ? v : 0.0, beta[j] / bsum);
            if (j + 1 < levels) {
                double *nt = oracle_reduce(p.t, p.w, p.h), *nr = oracle_reduce(p.r, p.w, p.h);
                oracle_planes_free(&p);
                p.t = nt;
                p.r = nr;
                p.w = (p.w + 1) / 2;
                p.h = (p.h + 1) / 2;
            }
        }
        oracle_planes_free(&p);
        total += ms;
    }
    return total / (last - first + 1);
}

/* ---- cases ------------------------------------------------------------- */

static void test_identical_images_give_ssim_one_and_zero_error(void **state)
{
    (void)state;
    rl_image *a = make_pattern(50, 77, 1u);
    rl_image *b = make_image(50, 77);
    memcpy(b->color, a->color, 50 * 77 * sizeof *a->color);
    const rl_metric_options opts[] = { { 0 }, { .linear = true }, { .ssim_rgb = true } };
    for (size_t i = 0; i < sizeof opts / sizeof opts[0]; ++i) {
        rl_image_metrics m;
        assert_int_equal(rl_image_compare(a, b, &opts[i], &m), RL_OK);
        assert_true(m.ssim == 1.0);
        assert_true(m.rmse == 0.0 && m.max_abs == 0.0);
        assert_true(isinf(m.psnr) && m.psnr > 0);
        assert_int_equal(m.pixels, 50 * 77);
    }
    float *map = malloc(50 * 77 * sizeof *map);
    assert_int_equal(rl_image_ssim_map(a, a, NULL, map), RL_OK);
    for (int k = 0; k < 50 * 77; ++k)
        assert_true(map[k] == 1.0f);
    free(map);
    rl_image_release(a);
    rl_image_release(b);
}

static void test_constant_images_match_the_closed_form(void **state)
{
    (void)state;
    const double a = 0.25, b = 0.75;
    rl_image *ta = make_image(23, 17), *tb = make_image(23, 17);
    rl_image_fill(ta, rl_v4((float)a, (float)a, (float)a, 1));
    rl_image_fill(tb, rl_v4((float)b, (float)b, (float)b, 1));
    rl_image_metrics m;
    const rl_metric_options opts[] = { { .linear = true }, { .linear = true, .ssim_rgb = true } };
    for (int i = 0; i < 2; ++i) {
        assert_int_equal(rl_image_compare(ta, tb, &opts[i], &m), RL_OK);
        /* no structure: only the luminance term of Eq. (13) remains */
        assert_near(m.ssim, (2 * a * b + C1) / (a * a + b * b + C1), 1e-9);
        assert_near(m.rmse, fabs(a - b), 1e-12);
        assert_near(m.psnr, 20.0 * log10(1.0 / fabs(a - b)), 1e-9);
        assert_near(m.max_abs, fabs(a - b), 1e-12);
    }
    /* default: both encoded to sRGB first */
    assert_int_equal(rl_image_compare(ta, tb, NULL, &m), RL_OK);
    double ea = oracle_encode((float)a, false), eb = oracle_encode((float)b, false);
    assert_near(m.rmse, fabs(ea - eb), 1e-12);
    assert_near(m.ssim, (2 * ea * eb + C1) / (ea * ea + eb * eb + C1), 1e-9);
    rl_image_release(ta);
    rl_image_release(tb);
}

static void test_mirrored_contrast_gives_negative_ssim(void **state)
{
    (void)state;
    uint32_t seed = 7u;
    rl_image *x = make_image(40, 40), *y = make_image(40, 40);
    for (int k = 0; k < 40 * 40; ++k) {
        float v = 0.2f + 0.6f * lcg_unit(&seed);
        x->color[k] = rl_v4(v, v, v, 1);
        y->color[k] = rl_v4(1.0f - v, 1.0f - v, 1.0f - v, 1);   /* mirrored around 0.5 */
    }
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(x, y, &(rl_metric_options){ .linear = true }, &m), RL_OK);
    assert_true(m.ssim < -0.5);
    assert_true(m.ssim >= -1.0);
    rl_image_release(x);
    rl_image_release(y);
}

static void test_ssim_agrees_with_brute_force_windows(void **state)
{
    (void)state;
    /* narrower and shorter than the window, a single pixel, and taller than
     * one band (64 rows) so that band halos are crossed */
    const int sizes[][2] = { { 37, 29 }, { 7, 5 }, { 1, 1 }, { 12, 3 }, { 23, 150 } };
    const rl_metric_options opts[] = { { 0 }, { .linear = true }, { .ssim_rgb = true } };
    for (size_t s = 0; s < sizeof sizes / sizeof sizes[0]; ++s) {
        const int w = sizes[s][0], h = sizes[s][1];
        rl_image *t = make_pattern(w, h, 11u + (uint32_t)s);
        rl_image *r = make_distorted(t, 99u + (uint32_t)s);
        uint8_t *mask = malloc((size_t)w * (size_t)h);
        float *map = malloc((size_t)w * (size_t)h * sizeof *map);
        for (size_t o = 0; o < sizeof opts / sizeof opts[0]; ++o) {
            double sum = 0.0;
            double *want_map = oracle_map(t, r, &opts[o]);
            assert_int_equal(rl_image_ssim_map(t, r, &opts[o], map), RL_OK);
            for (int py = 0; py < h; ++py)
                for (int px = 0; px < w; ++px) {
                    double want = want_map[py * w + px];
                    sum += want;
                    assert_near(map[py * w + px], want, 1e-6);
                    /* every pixel of the small images; rows near borders and
                     * band edges and a sparse grid of the tall one */
                    bool check = w * h < 1200 || py < 6 || py > h - 7 ||
                                 (py >= 58 && py <= 70) || (px % 5 == 0 && py % 9 == 0);
                    if (check)
                        assert_near(library_pixel(t, r, &opts[o], mask, px, py), want, 1e-9);
                }
            rl_image_metrics m;
            assert_int_equal(rl_image_compare(t, r, &opts[o], &m), RL_OK);
            assert_near(m.ssim, sum / (double)(w * h), 1e-9);
            assert_true(m.ssim < 1.0);
            free(want_map);
        }
        free(map);
        free(mask);
        rl_image_release(t);
        rl_image_release(r);
    }
}

/* Large enough for bands to run on several threads: the same bits with one
 * thread or three, and band edges (rows 63/64, 127/128) still match the
 * oracle. */
static void test_result_does_not_depend_on_thread_count(void **state)
{
    (void)state;
    const int w = 300, h = 260;
    rl_image *t = make_pattern(w, h, 31u);
    rl_image *r = make_distorted(t, 32u);
    float *map1 = malloc((size_t)(w * h) * sizeof *map1), *map3 = malloc((size_t)(w * h) * sizeof *map3);
    rl_image_metrics m1, m3;
    const int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    assert_int_equal(rl_image_compare(t, r, NULL, &m1), RL_OK);
    assert_int_equal(rl_image_ssim_map(t, r, NULL, map1), RL_OK);
    omp_set_num_threads(3);
    assert_int_equal(rl_image_compare(t, r, NULL, &m3), RL_OK);
    assert_int_equal(rl_image_ssim_map(t, r, NULL, map3), RL_OK);
    omp_set_num_threads(saved);
    assert_true(m1.ssim == m3.ssim && m1.rmse == m3.rmse && m1.max_abs == m3.max_abs);
    assert_memory_equal(map1, map3, (size_t)(w * h) * sizeof *map1);

    oracle_planes p = oracle_planes_make(t, r, 3, false);
    const int rows[] = { 0, 63, 64, 127, 128, 191, 192, 255, 259 };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i)
        for (int x = 0; x < w; x += 37)
            assert_near(map3[rows[i] * w + x], oracle_window(&p, x, rows[i]), 1e-6);
    oracle_planes_free(&p);
    free(map1);
    free(map3);
    rl_image_release(t);
    rl_image_release(r);
}

static void test_rmse_and_max_abs_follow_their_definitions(void **state)
{
    (void)state;
    rl_image *t = make_pattern(31, 19, 5u);
    rl_image *r = make_distorted(t, 6u);
    double sq = 0.0, mx = 0.0;
    for (int k = 0; k < 31 * 19; ++k)
        for (int c = 0; c < 3; ++c) {
            double d = fabs(oracle_value(t, k, c, false) - oracle_value(r, k, c, false));
            sq += d * d;
            mx = fmax(mx, d);
        }
    double mse = sq / (3.0 * 31 * 19);
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(t, r, NULL, &m), RL_OK);
    assert_near(m.rmse, sqrt(mse), 1e-12);
    assert_near(m.psnr, 10.0 * log10(1.0 / mse), 1e-9);
    assert_near(m.max_abs, mx, 1e-12);
    rl_image_release(t);
    rl_image_release(r);
}

static void test_mask_averages_only_selected_window_centres(void **state)
{
    (void)state;
    const int w = 40, h = 30;
    rl_image *ref = make_pattern(w, h, 21u);
    rl_image *t = make_image(w, h);
    memcpy(t->color, ref->color, (size_t)(w * h) * sizeof *t->color);
    for (int y = 0; y < h; ++y)
        for (int x = 20; x < w; ++x)
            rl_image_pixel(t, x, y)->x += 0.3f;       /* right half differs */
    uint8_t *mask = calloc((size_t)(w * h), 1);

    /* Unchanged columns 14..19: their windows reach the changed half, so
     * SSIM < 1 there while RMSE over the masked pixels is 0. */
    double want = 0.0;
    double *want_map = oracle_map(t, ref, &(rl_metric_options){ 0 });
    for (int y = 0; y < h; ++y)
        for (int x = 14; x < 20; ++x) {
            mask[y * w + x] = 1;
            want += want_map[y * w + x];
        }
    want /= 6.0 * h;
    free(want_map);
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(t, ref, &(rl_metric_options){ .mask = mask }, &m), RL_OK);
    assert_int_equal(m.pixels, 6 * h);
    assert_true(m.rmse == 0.0 && m.max_abs == 0.0 && isinf(m.psnr));
    assert_near(m.ssim, want, 1e-9);
    assert_true(m.ssim < 0.999);

    float *map = malloc((size_t)(w * h) * sizeof *map);
    assert_int_equal(rl_image_ssim_map(t, ref, &(rl_metric_options){ .mask = mask }, map), RL_OK);
    for (int k = 0; k < w * h; ++k)
        if (!mask[k])
            assert_true(map[k] == 0.0f);
    free(map);

    /* Columns 0..7: every window stays inside the unchanged half. */
    memset(mask, 0, (size_t)(w * h));
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < 8; ++x)
            mask[y * w + x] = 1;
    assert_int_equal(rl_image_compare(t, ref, &(rl_metric_options){ .mask = mask }, &m), RL_OK);
    assert_true(m.ssim == 1.0 && m.rmse == 0.0);

    /* The unmasked comparison sees the change. */
    assert_int_equal(rl_image_compare(t, ref, NULL, &m), RL_OK);
    assert_true(m.rmse > 0.0);
    assert_true(m.ssim < 0.995);   /* 0.9913: mostly the luminance term */
    free(mask);
    rl_image_release(t);
    rl_image_release(ref);
}

/* ---- third-party reference values -------------------------------------- */

/* Grey images from 8-bit codes, so that both sides read the same floats: a
 * base of ramps that wrap (edges) over a block checkerboard, and the
 * standard distortions of Wang et al. 2004, Fig. 2 as integer code maps. */
enum { TP_W = 64, TP_H = 48 };

static int tp_clip(int c) { return c < 0 ? 0 : c > 255 ? 255 : c; }
static int tp_base(int x, int y) { return (3 * x + 2 * y) % 200 + ((x / 8 + y / 6) % 2) * 50; }

static uint32_t tp_lcg(uint32_t *s)
{
    *s = *s * 1664525u + 1013904223u;
    return *s >> 8;
}

/* Distortion k of the base, as codes (blur: 9x the mean, see tp_image). */
static void tp_codes(int k, int *out)
{
    uint32_t s = k == 2 ? 12345u : 777u;
    for (int y = 0; y < TP_H; ++y)
        for (int x = 0; x < TP_W; ++x) {
            int c = tp_base(x, y), v = c;
            uint32_t r;
            switch (k) {
            case 0: v = tp_clip(c + 26); break;                         /* mean shift */
            case 1: v = tp_clip((c * 13 + 1000) / 10 - 138); break;     /* contrast stretch */
            case 2: r = tp_lcg(&s); v = tp_clip(c + (int)(r % 61u) - 30); break;   /* noise */
            case 3: r = tp_lcg(&s) % 100u; v = r < 3 ? 0 : r < 6 ? 255 : c; break; /* impulses */
            case 4: v = (c / 32) * 32 + 16; break;                      /* quantisation */
            case 5:                                                     /* 3x3 box blur */
                v = 0;
                for (int j = -1; j <= 1; ++j)
                    for (int i = -1; i <= 1; ++i) {
                        int xx = x + i < 0 ? 0 : x + i >= TP_W ? TP_W - 1 : x + i;
                        int yy = y + j < 0 ? 0 : y + j >= TP_H ? TP_H - 1 : y + j;
                        v += tp_base(xx, yy);
                    }
                break;
            default: break;                                             /* the base */
            }
            out[y * TP_W + x] = v;
        }
}

static rl_image *tp_image(int k)
{
    static int codes[TP_W * TP_H];
    tp_codes(k, codes);
    rl_image *img = make_image(TP_W, TP_H);
    float scale = k == 5 ? 2295.0f : 255.0f;    /* blur: the sum of 9 codes */
    for (int i = 0; i < TP_W * TP_H; ++i) {
        float v = (float)codes[i] / scale;
        img->color[i] = rl_v4(v, v, v, 1.0f);
    }
    return img;
}

/* SSIM of the standard distortions against scikit-image 0.19.3's
 * structural_similarity (data_range 1, gaussian_weights, sigma 1.5,
 * use_sample_covariance False: Wang et al. 2004's setting) on the same
 * float32 values, an implementation independent of ours. It averages the
 * centres at least 5 pixels from the border (full windows), which a mask
 * selects here; values printed with 16 digits, agreement to 1e-9. */
static void test_ssim_matches_scikit_image_on_standard_distortions(void **state)
{
    (void)state;
    static const struct { const char *name; double want; } cases[] = {
        { "mean shift", 0.9727585840679142 }, { "contrast", 0.9512160215875682 },
        { "noise", 0.7850194609681952 },      { "impulses", 0.578671740663025 },
        { "quantisation", 0.9354280907686695 }, { "blur", 0.7963968650554716 } };
    rl_image *ref = tp_image(-1);
    uint8_t *mask = calloc(TP_W * TP_H, 1);
    for (int y = 5; y < TP_H - 5; ++y)
        for (int x = 5; x < TP_W - 5; ++x)
            mask[y * TP_W + x] = 1;
    for (int k = 0; k < 6; ++k) {
        rl_image *t = tp_image(k);
        rl_image_metrics m;
        assert_int_equal(rl_image_compare(t, ref, &(rl_metric_options){ .mask = mask, .linear = true }, &m),
                         RL_OK);
        if (!(fabs(m.ssim - cases[k].want) <= 1e-9))
            fail_msg("%s: SSIM %.16g, scikit-image %.16g", cases[k].name, m.ssim, cases[k].want);
        rl_image_release(t);
    }
    free(mask);
    rl_image_release(ref);
}

/* A checkerboard x = m + d s and y = m + a d s (s = (-1)^(i+j)): in a full
 * 11x11 window with Gaussian weights g_t (sigma 1.5), the weighted mean of
 * s is s0 e with e = (sum g_t (-1)^t / sum g_t)^2 and s0 the centre's sign,
 * and s^2 = 1, so by hand
 *   mu_x = m + d s0 e,  mu_y = m + a d s0 e,
 *   sigma_x^2 = d^2 (1 - e^2),  sigma_y^2 = a^2 d^2 (1 - e^2),
 *   sigma_xy = a d^2 (1 - e^2),
 * and SSIM = l * cs with l = (2 mu_x mu_y + C1) / (mu_x^2 + mu_y^2 + C1),
 * cs = (2 a d^2 (1 - e^2) + C2) / ((1 + a^2) d^2 (1 - e^2) + C2)
 * (Wang et al. 2004, Eq. (13)). Checked at every centre whose window lies
 * inside the image. */
static void test_checkerboard_contrast_matches_the_closed_form_in_full_windows(void **state)
{
    (void)state;
    const int w = 29, h = 24;
    const double m = 0.5, d = 0.25, a = 0.5;    /* all values exact in float */
    rl_image *x = make_image(w, h), *y = make_image(w, h);
    for (int i = 0; i < h; ++i)
        for (int j = 0; j < w; ++j) {
            double sgn = (i + j) % 2 ? -1.0 : 1.0;
            float vx = (float)(m + d * sgn), vy = (float)(m + a * d * sgn);
            *rl_image_pixel(x, j, i) = rl_v4(vx, vx, vx, 1);
            *rl_image_pixel(y, j, i) = rl_v4(vy, vy, vy, 1);
        }
    double alt = 0.0, sum = 0.0;
    for (int t = -5; t <= 5; ++t) {
        double g = exp(-(double)(t * t) / (2.0 * 1.5 * 1.5));
        alt += (t % 2 ? -1.0 : 1.0) * g;
        sum += g;
    }
    const double e = (alt / sum) * (alt / sum);
    const double var = d * d * (1.0 - e * e);
    const double cs = (2.0 * a * var + C2) / ((1.0 + a * a) * var + C2);
    float *map = malloc((size_t)w * (size_t)h * sizeof *map);
    assert_non_null(map);
    assert_int_equal(rl_image_ssim_map(x, y, &(rl_metric_options){ .linear = true }, map), RL_OK);
    int checked = 0;
    for (int i = 5; i < h - 5; ++i)
        for (int j = 5; j < w - 5; ++j) {
            double s0 = (i + j) % 2 ? -1.0 : 1.0;
            double mx = m + d * s0 * e, my = m + a * d * s0 * e;
            double l = (2.0 * mx * my + C1) / (mx * mx + my * my + C1);
            assert_near(map[i * w + j], l * cs, 2e-7);
            ++checked;
        }
    assert_int_equal(checked, (w - 10) * (h - 10));
    free(map);
    rl_image_release(x);
    rl_image_release(y);
}

static void test_multiscale_ssim_of_constant_images_is_the_coarsest_luminance(void **state)
{
    (void)state;
    /* No structure at any level: every c*s is 1, so Eq. (7) of Wang et al.
     * 2003 leaves l^(beta_L / sum beta) of the coarsest level, and a
     * constant stays constant through the normalised pyramid filter. */
    const double a = 0.25, b = 0.75;
    rl_image *ta = make_image(23, 17), *tb = make_image(23, 17);
    rl_image_fill(ta, rl_v4((float)a, (float)a, (float)a, 1));
    rl_image_fill(tb, rl_v4((float)b, (float)b, (float)b, 1));
    const double l = (2 * a * b + C1) / (a * a + b * b + C1);
    const double beta[5] = { 0.0448, 0.2856, 0.3001, 0.2363, 0.1333 };
    double bsum = 0.0;
    for (int levels = 1; levels <= 5; ++levels) {
        bsum += beta[levels - 1];
        rl_image_metrics m;
        rl_metric_options o = { .linear = true, .ssim_levels = levels };
        assert_int_equal(rl_image_compare(ta, tb, &o, &m), RL_OK);
        double want = levels == 1 ? l : pow(l, beta[levels - 1] / bsum);
        assert_near(m.ssim, want, 1e-12);
        assert_near(m.rmse, fabs(a - b), 1e-12);    /* the errors stay single-scale */
    }
    rl_image_release(ta);
    rl_image_release(tb);
}

static void test_multiscale_ssim_agrees_with_the_direct_pyramid(void **state)
{
    (void)state;
    rl_image *t = make_pattern(41, 35, 11u);
    rl_image *ref = make_distorted(t, 12u);
    rl_image *same = make_image(41, 35);
    memcpy(same->color, t->color, 41 * 35 * sizeof *t->color);
    const rl_metric_options base[] = { { 0 }, { .linear = true }, { .ssim_rgb = true } };
    for (size_t i = 0; i < sizeof base / sizeof base[0]; ++i)
        for (int levels = 2; levels <= 5; ++levels) {
            rl_metric_options o = base[i];
            o.ssim_levels = levels;
            rl_image_metrics m;
            assert_int_equal(rl_image_compare(t, ref, &o, &m), RL_OK);
            assert_near(m.ssim, oracle_ms_ssim(t, ref, &o, levels), 1e-9);
            assert_true(m.ssim > 0.0 && m.ssim < 1.0);
            assert_int_equal(rl_image_compare(t, same, &o, &m), RL_OK);
            assert_true(m.ssim == 1.0);     /* identical: exactly one */
        }
    /* levels 0 and 1 are the single-scale SSIM, bit for bit */
    rl_image_metrics m0, m1;
    assert_int_equal(rl_image_compare(t, ref, NULL, &m0), RL_OK);
    assert_int_equal(rl_image_compare(t, ref, &(rl_metric_options){ .ssim_levels = 1 }, &m1),
                     RL_OK);
    assert_true(m0.ssim == m1.ssim);
    rl_image_release(t);
    rl_image_release(ref);
    rl_image_release(same);
}

static void test_multiscale_options_are_checked(void **state)
{
    (void)state;
    rl_image *a = make_pattern(8, 6, 1u), *b = make_pattern(8, 6, 2u);
    uint8_t mask[48];
    memset(mask, 1, sizeof mask);
    rl_image_metrics m = { .ssim = 42.0 };
    float map[48] = { 7.0f };
    assert_int_equal(rl_image_compare(a, b, &(rl_metric_options){ .ssim_levels = -1 }, &m),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_compare(a, b, &(rl_metric_options){ .ssim_levels = 6 }, &m),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_compare(a, b, &(rl_metric_options){ .ssim_levels = 3, .mask = mask },
                                      &m),
                     RL_ERR_INVALID_ARG);
    assert_true(m.ssim == 42.0);
    assert_int_equal(rl_image_ssim_map(a, b, &(rl_metric_options){ .ssim_levels = 2 }, map),
                     RL_ERR_INVALID_ARG);
    assert_true(map[0] == 7.0f);
    /* a level of one pixel is still a valid SSIM window */
    assert_int_equal(rl_image_compare(a, b, &(rl_metric_options){ .ssim_levels = 5 }, &m), RL_OK);
    assert_true(m.ssim <= 1.0);
    rl_clear_error();
    rl_image_release(a);
    rl_image_release(b);
}

static void test_bad_arguments_are_invalid_and_leave_outputs_alone(void **state)
{
    (void)state;
    rl_image *a = make_pattern(8, 6, 1u), *b = make_pattern(8, 6, 2u), *c = make_pattern(6, 8, 3u);
    rl_image *depth_only = NULL;
    assert_int_equal(rl_image_create(8, 6, RL_LAYER_DEPTH, &depth_only), RL_OK);
    uint8_t none[48] = { 0 };
    rl_image_metrics m = { .ssim = 42.0 };
    float map[48] = { 7.0f };

    rl_clear_error();
    assert_int_equal(rl_image_compare(NULL, b, NULL, &m), RL_ERR_INVALID_ARG);
    assert_true(strlen(rl_last_error()) > 0);
    rl_clear_error();
    assert_int_equal(rl_image_compare(a, NULL, NULL, &m), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_compare(a, b, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_compare(a, c, NULL, &m), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_compare(a, depth_only, NULL, &m), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_compare(a, b, &(rl_metric_options){ .mask = none }, &m),
                     RL_ERR_INVALID_ARG);
    assert_true(m.ssim == 42.0);

    assert_int_equal(rl_image_ssim_map(a, b, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_ssim_map(a, c, NULL, map), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_ssim_map(a, b, &(rl_metric_options){ .mask = none }, map),
                     RL_ERR_INVALID_ARG);
    assert_true(map[0] == 7.0f);

    rl_image *d = NULL;
    assert_int_equal(rl_image_difference(a, c, 1.0f, &d), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_difference(NULL, b, 1.0f, &d), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_difference(a, b, 0.0f, &d), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_difference(a, b, NAN, &d), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_image_difference(a, b, 1.0f, NULL), RL_ERR_INVALID_ARG);
    assert_null(d);
    rl_clear_error();
    rl_image_release(a);
    rl_image_release(b);
    rl_image_release(c);
    rl_image_release(depth_only);
}

static void test_difference_is_black_where_equal(void **state)
{
    (void)state;
    rl_image *a = make_pattern(16, 9, 4u);
    rl_image *b = make_image(16, 9);
    memcpy(b->color, a->color, 16 * 9 * sizeof *a->color);
    rl_image_pixel(b, 3, 2)->y += 0.25f;
    rl_image_pixel(b, 15, 8)->z = rl_image_pixel(a, 15, 8)->z > 0.5f ? 0.0f : 1.0f;
    rl_image *d = NULL;
    assert_int_equal(rl_image_difference(a, b, 1.0f, &d), RL_OK);
    assert_int_equal(d->width, 16);
    assert_int_equal(d->height, 9);
    for (int y = 0; y < 9; ++y)
        for (int x = 0; x < 16; ++x) {
            rl_vec4 p = *rl_image_pixel(d, x, y);
            bool changed = (x == 3 && y == 2) || (x == 15 && y == 8);
            if (changed)
                assert_true(p.x > 0.0f);
            else
                assert_true(p.x == 0.0f && p.y == 0.0f && p.z == 0.0f);
        }
    rl_image_release(d);
    /* a large gain saturates any difference to white */
    assert_int_equal(rl_image_difference(a, b, 1e6f, &d), RL_OK);
    rl_vec4 p = *rl_image_pixel(d, 3, 2);
    assert_true(p.x == 1.0f && p.y == 1.0f && p.z == 1.0f);
    rl_image_release(d);
    rl_image_release(a);
    rl_image_release(b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_identical_images_give_ssim_one_and_zero_error),
        cmocka_unit_test(test_constant_images_match_the_closed_form),
        cmocka_unit_test(test_mirrored_contrast_gives_negative_ssim),
        cmocka_unit_test(test_ssim_agrees_with_brute_force_windows),
        cmocka_unit_test(test_result_does_not_depend_on_thread_count),
        cmocka_unit_test(test_rmse_and_max_abs_follow_their_definitions),
        cmocka_unit_test(test_mask_averages_only_selected_window_centres),
        cmocka_unit_test(test_ssim_matches_scikit_image_on_standard_distortions),
        cmocka_unit_test(test_checkerboard_contrast_matches_the_closed_form_in_full_windows),
        cmocka_unit_test(test_multiscale_ssim_of_constant_images_is_the_coarsest_luminance),
        cmocka_unit_test(test_multiscale_ssim_agrees_with_the_direct_pyramid),
        cmocka_unit_test(test_multiscale_options_are_checked),
        cmocka_unit_test(test_bad_arguments_are_invalid_and_leave_outputs_alone),
        cmocka_unit_test(test_difference_is_black_where_equal),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
