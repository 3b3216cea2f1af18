/* metrics.c: RMSE, PSNR and SSIM of a test image against a reference, and a
 * false-colour difference picture (rl_metrics.h).
 *
 * SSIM follows Wang, Bovik, Sheikh & Simoncelli 2004, "Image Quality
 * Assessment: From Error Visibility to Structural Similarity", IEEE TIP
 * 13(4): Eq. (13) on the local statistics of Eqs. (14)-(16), weighted by an
 * 11x11 circular-symmetric Gaussian with sigma = 1.5, K1 = 0.01, K2 = 0.03
 * (Sec. III-B), L = 1 because values lie in [0, 1]; the mean over window
 * centres is the MSSIM of Eq. (17).
 *
 * In contrast to the paper, which keeps only windows that fit inside the
 * image, every pixel is a window centre: the window is truncated at the
 * border and its weights renormalised to sum to one. The truncated window is
 * still a rectangle, so the weights stay separable and an 11-tap horizontal
 * pass followed by an 11-tap vertical pass gives the 2D weighted sums exactly
 * (up to rounding). Statistics are accumulated in double.
 *
 * A mask selects which window centres are averaged (and which pixels enter
 * RMSE, PSNR and max_abs); the windows themselves still read every pixel,
 * masked or not, so the masked SSIM is a plain sub-average of the full SSIM
 * map and does not depend on where the mask edge cuts a window.
 *
 * Multi-scale SSIM (options.ssim_levels = L > 1) follows Wang, Simoncelli &
 * Bovik 2003, "Multi-scale structural similarity for image quality
 * assessment", Asilomar, Eq. (7): contrast x structure, c_j s_j = (2
 * sigma_xy + C2) / (sigma_x^2 + sigma_y^2 + C2), averaged over the window
 * centres of every level j < L, and the full SSIM (luminance included) of
 * the coarsest level, combined as prod_j mean(c_j s_j)^beta_j times
 * mean(SSIM_L)^beta_L with the paper's exponents for five levels (0.0448,
 * 0.2856, 0.3001, 0.2363, 0.1333), the first L of them renormalised to sum
 * to one. A negative mean (anti-correlated images) is taken as 0 before
 * the fractional power, where the paper leaves it undefined. As in the
 * paper's reference code the luminance term enters as the coarsest level's
 * mean SSIM rather than a separate mean of l. The levels are a Gaussian
 * pyramid after Burt 1981 (the thesis' [Bur81]; Burt & Adelson 1983):
 * level j+1 is level j convolved with the separable 5-tap generating kernel
 * [1 4 6 4 1] / 16 (a = 0.375) and subsampled at even pixels, so a level of
 * n pixels gives ceil(n / 2); at the borders the kernel is truncated and
 * renormalised, like the SSIM window. Each level's SSIM uses the same 11x11
 * window and constants as the single-scale SSIM. Jähn 2015, Sec. 4.2.5 uses
 * this hierarchical filtering to emphasise large-area errors.
 *
 * Work is split into bands of rows, one per OpenMP iteration; each band
 * filters its rows plus a RADIUS-row halo, so no full-size intermediate is
 * kept and the result does not depend on the thread count (sums are reduced
 * per row, then serially). */
#include "rl/rl_metrics.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

enum {
    RADIUS = 5,                 /* 11x11 window, Wang 2004 Sec. III-B */
    TAPS = 2 * RADIUS + 1,
    BAND_ROWS = 64,             /* halo overhead 2*RADIUS/64: about 16% */
    STATS = 5,                  /* x, y, x^2, y^2, xy */
    MIN_PARALLEL = 1 << 16      /* pixels */
};
#define SSIM_SIGMA 1.5
#define SSIM_C1 (0.01 * 0.01)   /* (K1 L)^2, Eq. (7) */
#define SSIM_C2 (0.03 * 0.03)   /* (K2 L)^2, Eq. (9) */

typedef enum channel { CH_R = 0, CH_G, CH_B, CH_LUMA } channel;

/* ---- input ------------------------------------------------------------- */

static rl_status check_pair(const char *fn, const rl_image *test, const rl_image *ref)
{
    if (!test || !ref)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %s image is NULL", fn, test ? "reference" : "test");
    if (!(test->layers & RL_LAYER_COLOR) || !test->color)
        return rl_error(RL_ERR_INVALID_ARG, "%s: test image has no colour layer", fn);
    if (!(ref->layers & RL_LAYER_COLOR) || !ref->color)
        return rl_error(RL_ERR_INVALID_ARG, "%s: reference image has no colour layer", fn);
    if (test->width != ref->width || test->height != ref->height)
        return rl_error(RL_ERR_INVALID_ARG, "%s: sizes differ (%dx%d test, %dx%d reference)", fn,
                        test->width, test->height, ref->width, ref->height);
    if (test->width < 1 || test->height < 1)
        return rl_error(RL_ERR_INVALID_ARG, "%s: empty image (%dx%d)", fn, test->width,
                        test->height);
    return RL_OK;
}

static rl_status count_pixels(const char *fn, const rl_image *img, const uint8_t *mask,
                              uint64_t *pixels)
{
    size_t n = (size_t)img->width * (size_t)img->height;
    uint64_t count = n;
    if (mask) {
        count = 0;
        for (size_t i = 0; i < n; ++i)
            count += mask[i] != 0;
    }
    if (count == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: mask selects no pixel", fn);
    *pixels = count;
    return RL_OK;
}

/* c^(1/2.4) = c^(5/12) to double precision. pow() in double is the largest
 * cost of a 2048x2048 comparison (six calls per pixel), so start from the
 * float powf (relative error ~1e-7) and take one Halley step on y^12 = c^5,
 * y <- y (11 y^12 + 13 a) / (13 y^12 + 11 a), whose cubic convergence lands
 * at double rounding. Only called for c in (0.0031308, 1]. */
static double root_5_12(double c)
{
    double y = (double)powf((float)c, 5.0f / 12.0f);
    double c2 = c * c, a = c2 * c2 * c;
    double y2 = y * y, y4 = y2 * y2, y12 = y4 * y4 * y4;
    return y * (11.0 * y12 + 13.0 * a) / (13.0 * y12 + 11.0 * a);
}

/* Clamp to [0, 1] (NaN counts as black, as in the PNG writer), then the
 * piecewise sRGB OETF (IEC 61966-2-1): what the 8-bit PNG holds. */
static double encode(float v, bool linear)
{
    double c = (double)v;
    if (!(c > 0.0))
        c = 0.0;
    if (c > 1.0)
        c = 1.0;
    if (linear)
        return c;
    return c <= 0.0031308 ? 12.92 * c : 1.055 * root_5_12(c) - 0.055;
}

/* ---- SSIM ------------------------------------------------------------- */

typedef struct ssim_job {
    const double *x, *y;        /* test and reference plane, width*height */
    int width, height;
    double g[TAPS];             /* g[RADIUS + t] = exp(-t^2 / (2 sigma^2)), unnormalised */
    double *col_inv, *row_inv;  /* 1 / sum of the taps a truncated window keeps */
    const uint8_t *mask;        /* NULL = every pixel */
    float *map;                 /* map[i] += map_scale * SSIM, or NULL */
    float map_scale;
    double *row_sum;            /* row_sum[y] += sum of masked SSIM in row y, or NULL */
    double *row_cs;             /* row_cs[y] += sum of c*s (Wang 2003) in row y, or NULL */
    double *scratch;            /* threads * scratch_per_thread doubles */
    size_t scratch_per_thread;
} ssim_job;

/* Renormalisation of the truncated window: centre p of n keeps taps
 * max(-R, -p) .. min(R, n-1-p). */
static void truncated_norms(const double *g, int n, double *inv)
{
    for (int p = 0; p < n; ++p) {
        int lo = p < RADIUS ? -p : -RADIUS;
        int hi = n - 1 - p < RADIUS ? n - 1 - p : RADIUS;
        double sum = 0.0;
        for (int t = lo; t <= hi; ++t)
            sum += g[RADIUS + t];
        inv[p] = 1.0 / sum;
    }
}

/* One row through the horizontal taps. The interior loop has no bounds
 * tests so that it vectorises; only the RADIUS columns at each side (all of
 * them in images narrower than the window) take the truncated path. */
static void filter_row(const ssim_job *job, const double *src, double *dst)
{
    const int w = job->width;
    const double *g = job->g + RADIUS;
    int inner_lo = w < RADIUS ? w : RADIUS;
    int inner_hi = w - RADIUS > inner_lo ? w - RADIUS : inner_lo;
    for (int j = 0; j < w; ++j) {
        if (j == inner_lo)
            j = inner_hi;
        if (j >= w)
            break;
        int lo = j < RADIUS ? -j : -RADIUS;
        int hi = w - 1 - j < RADIUS ? w - 1 - j : RADIUS;
        double s = 0.0;
        for (int t = lo; t <= hi; ++t)
            s += g[t] * src[j + t];
        dst[j] = s * job->col_inv[j];
    }
    for (int j = inner_lo; j < inner_hi; ++j) {
        double s = 0.0;
        for (int t = -RADIUS; t <= RADIUS; ++t)
            s += g[t] * src[j + t];
        dst[j] = s * job->col_inv[j];
    }
}

/* Eq. (13) from the window moments; written symmetrically in x and y so that
 * identical inputs give exactly 1. */
static double ssim_from_moments(double mx, double my, double exx, double eyy, double exy)
{
    double sxx = exx - mx * mx;     /* sigma_x^2, Eq. (14)-(15) */
    double syy = eyy - my * my;
    double sxy = exy - mx * my;     /* sigma_xy, Eq. (16) */
    double num = (2.0 * (mx * my) + SSIM_C1) * (2.0 * sxy + SSIM_C2);
    double den = (mx * mx + my * my + SSIM_C1) * (sxx + syy + SSIM_C2);
    return num / den;
}

/* Contrast x structure of Wang, Simoncelli & Bovik 2003, Eq. (3)-(4) with
 * C3 = C2 / 2 merged; symmetric, so identical inputs give exactly 1. */
static double cs_from_moments(double mx, double my, double exx, double eyy, double exy)
{
    double sxx = exx - mx * mx, syy = eyy - my * my, sxy = exy - mx * my;
    return (2.0 * sxy + SSIM_C2) / (sxx + syy + SSIM_C2);
}

static void ssim_band(const ssim_job *job, int b0, int b1, double *scratch)
{
    const int w = job->width, h = job->height;
    const size_t ws = (size_t)w;
    const int r0 = b0 - RADIUS > 0 ? b0 - RADIUS : 0;
    const int r1 = b1 + RADIUS < h ? b1 + RADIUS : h;
    const size_t rows = (size_t)(BAND_ROWS + 2 * RADIUS);
    double *hz[STATS], *acc[STATS];
    for (int s = 0; s < STATS; ++s) {
        hz[s] = scratch + (size_t)s * rows * ws;
        acc[s] = scratch + (size_t)STATS * rows * ws + (size_t)s * ws;
    }
    double *prod = scratch + (size_t)STATS * (rows + 1) * ws; /* 3 rows: x^2, y^2, xy */

    for (int r = r0; r < r1; ++r) {
        const double *x = job->x + (size_t)r * ws, *y = job->y + (size_t)r * ws;
        for (int j = 0; j < w; ++j) {
            prod[j] = x[j] * x[j];
            prod[ws + (size_t)j] = y[j] * y[j];
            prod[2 * ws + (size_t)j] = x[j] * y[j];
        }
        size_t at = (size_t)(r - r0) * ws;
        filter_row(job, x, hz[0] + at);
        filter_row(job, y, hz[1] + at);
        filter_row(job, prod, hz[2] + at);
        filter_row(job, prod + ws, hz[3] + at);
        filter_row(job, prod + 2 * ws, hz[4] + at);
    }

    const double *g = job->g + RADIUS;
    for (int i = b0; i < b1; ++i) {
        int lo = i < RADIUS ? -i : -RADIUS;
        int hi = h - 1 - i < RADIUS ? h - 1 - i : RADIUS;
        for (int s = 0; s < STATS; ++s)
            memset(acc[s], 0, ws * sizeof(double));
        for (int t = lo; t <= hi; ++t) {
            size_t at = (size_t)(i + t - r0) * ws;
            for (int s = 0; s < STATS; ++s) {
                const double *src = hz[s] + at;
                double *dst = acc[s];
                for (int j = 0; j < w; ++j)
                    dst[j] += g[t] * src[j];
            }
        }
        const double norm = job->row_inv[i];
        const size_t row = (size_t)i * ws;
        double sum = 0.0, sum_cs = 0.0;
        for (int j = 0; j < w; ++j) {
            if (job->mask && !job->mask[row + (size_t)j])
                continue;
            double v = ssim_from_moments(acc[0][j] * norm, acc[1][j] * norm, acc[2][j] * norm,
                                         acc[3][j] * norm, acc[4][j] * norm);
            sum += v;
            if (job->row_cs)
                sum_cs += cs_from_moments(acc[0][j] * norm, acc[1][j] * norm, acc[2][j] * norm,
                                          acc[3][j] * norm, acc[4][j] * norm);
            if (job->map)
                job->map[row + (size_t)j] += job->map_scale * (float)v;
        }
        if (job->row_sum)
            job->row_sum[i] += sum;
        if (job->row_cs)
            job->row_cs[i] += sum_cs;
    }
}

static void ssim_run(const ssim_job *job, int threads)
{
    const int bands = (job->height + BAND_ROWS - 1) / BAND_ROWS;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int b = 0; b < bands; ++b) {
        int b0 = b * BAND_ROWS;
        int b1 = b0 + BAND_ROWS < job->height ? b0 + BAND_ROWS : job->height;
        double *scratch = job->scratch + (size_t)omp_get_thread_num() * job->scratch_per_thread;
        ssim_band(job, b0, b1, scratch);
    }
}

/* ---- one comparison -------------------------------------------------- */

/* Everything a comparison allocates, so that it can fail before any output
 * is touched. */
typedef struct compare_ctx {
    const rl_image *test, *ref;
    rl_metric_options opt;
    ssim_job job;
    double *planes;             /* x and y */
    double *row_sq, *row_max;   /* per-row squared-error sum and max |diff|, or NULL */
    int threads;
} compare_ctx;

static void ctx_free(compare_ctx *c)
{
    free(c->planes);
    free(c->job.col_inv);
    free(c->job.row_inv);
    free(c->job.scratch);
    free(c->row_sq);
    free(c->row_max);
}

static rl_status ctx_init(compare_ctx *c, const char *fn, const rl_image *test,
                          const rl_image *ref, const rl_metric_options *opt, bool errors,
                          uint64_t *pixels)
{
    memset(c, 0, sizeof *c);
    rl_status st = check_pair(fn, test, ref);
    if (st != RL_OK)
        return st;
    c->test = test;
    c->ref = ref;
    if (opt)
        c->opt = *opt;
    st = count_pixels(fn, test, c->opt.mask, pixels);
    if (st != RL_OK)
        return st;

    const int w = test->width, h = test->height;
    const size_t n = (size_t)w * (size_t)h;
    const int bands = (h + BAND_ROWS - 1) / BAND_ROWS;
    /* below MIN_PARALLEL pixels waking a thread team costs more than it saves */
    c->threads = omp_get_max_threads() < bands ? omp_get_max_threads() : bands;
    if (n < MIN_PARALLEL)
        c->threads = 1;
    ssim_job *job = &c->job;
    job->width = w;
    job->height = h;
    job->mask = c->opt.mask;
    for (int t = -RADIUS; t <= RADIUS; ++t)
        job->g[RADIUS + t] = exp(-(double)(t * t) / (2.0 * SSIM_SIGMA * SSIM_SIGMA));
    /* per thread: STATS filtered bands, STATS accumulator rows, 3 product rows */
    job->scratch_per_thread = ((size_t)STATS * (BAND_ROWS + 2 * RADIUS + 1) + 3) * (size_t)w;
    c->planes = rl_calloc(2 * n, sizeof(double));
    job->col_inv = rl_calloc((size_t)w, sizeof(double));
    job->row_inv = rl_calloc((size_t)h, sizeof(double));
    job->scratch = rl_calloc((size_t)c->threads * job->scratch_per_thread, sizeof(double));
    bool ok = c->planes && job->col_inv && job->row_inv && job->scratch;
    if (ok && errors) {
        c->row_sq = rl_calloc((size_t)h, sizeof(double));
        c->row_max = rl_calloc((size_t)h, sizeof(double));
        ok = c->row_sq && c->row_max;
    }
    if (!ok) {
        ctx_free(c);
        return RL_ERR_OUT_OF_MEMORY;
    }
    job->x = c->planes;
    job->y = c->planes + n;
    truncated_norms(job->g, w, job->col_inv);
    truncated_norms(job->g, h, job->row_inv);
    return RL_OK;
}

/* Rec. 601 luma of encoded R'G'B' (what the header promises). */
static double luma(double r, double g, double b) { return 0.299 * r + 0.587 * g + 0.114 * b; }

/* Fills the SSIM planes for one channel (or luma) and, when asked, adds the
 * channel's squared errors of masked pixels to the per-row sums in the same
 * pass, so that each value is encoded once. */
static void fill_planes(compare_ctx *c, channel ch)
{
    const int w = c->job.width, h = c->job.height;
    const bool linear = c->opt.linear;
    double *x = c->planes, *y = c->planes + (size_t)w * (size_t)h;
#pragma omp parallel for num_threads(c->threads) schedule(static)
    for (int i = 0; i < h; ++i) {
        double sq = 0.0, mx = 0.0;
        for (int j = 0; j < w; ++j) {
            size_t k = (size_t)i * (size_t)w + (size_t)j;
            rl_vec4 a = c->test->color[k], b = c->ref->color[k];
            double ta[3], rb[3];
            int first = ch == CH_LUMA ? 0 : (int)ch, last = ch == CH_LUMA ? 2 : (int)ch;
            const float fa[3] = { a.x, a.y, a.z }, fb[3] = { b.x, b.y, b.z };
            for (int q = first; q <= last; ++q) {
                ta[q] = encode(fa[q], linear);
                rb[q] = encode(fb[q], linear);
            }
            if (ch == CH_LUMA) {
                x[k] = luma(ta[0], ta[1], ta[2]);
                y[k] = luma(rb[0], rb[1], rb[2]);
            } else {
                x[k] = ta[ch];
                y[k] = rb[ch];
            }
            if (!c->row_sq || (c->opt.mask && !c->opt.mask[k]))
                continue;
            for (int q = first; q <= last; ++q) {
                double d = fabs(ta[q] - rb[q]);
                sq += d * d;
                mx = d > mx ? d : mx;
            }
        }
        if (c->row_sq) {
            c->row_sq[i] += sq;
            c->row_max[i] = mx > c->row_max[i] ? mx : c->row_max[i];
        }
    }
}

/* Runs SSIM over the luma or the three channels in turn. */
static void ctx_run(compare_ctx *c)
{
    if (c->opt.ssim_rgb) {
        c->job.map_scale = 1.0f / 3.0f;
        for (int ch = CH_R; ch <= CH_B; ++ch) {
            fill_planes(c, (channel)ch);
            ssim_run(&c->job, c->threads);
        }
    } else {
        c->job.map_scale = 1.0f;
        fill_planes(c, CH_LUMA);
        ssim_run(&c->job, c->threads);
    }
}

/* ---- multi-scale SSIM (Wang, Simoncelli & Bovik 2003) ----------------- */

enum { MS_MAX_LEVELS = 5, PYR_RADIUS = 2 };
/* Wang 2003, Sec. 3.2: beta_j = gamma_j = alpha_5 for five scales */
static const double ms_weights[MS_MAX_LEVELS] = { 0.0448, 0.2856, 0.3001, 0.2363, 0.1333 };
/* Burt 1981 generating kernel with a = 0.375: [1 4 6 4 1] / 16 */
static const double pyr_kernel[2 * PYR_RADIUS + 1] = { 1.0, 4.0, 6.0, 4.0, 1.0 };

/* One REDUCE step along a line of n samples with stride `step`: dst gets
 * (n + 1) / 2 samples with stride dst_step, the kernel truncated and
 * renormalised at the ends. */
static void reduce_line(const double *src, int n, size_t step, double *dst, size_t dst_step)
{
    for (int i = 0; 2 * i < n; ++i) {
        double s = 0.0, wsum = 0.0;
        for (int t = -PYR_RADIUS; t <= PYR_RADIUS; ++t) {
            int k = 2 * i + t;
            if (k < 0 || k >= n)
                continue;
            s += pyr_kernel[PYR_RADIUS + t] * src[(size_t)k * step];
            wsum += pyr_kernel[PYR_RADIUS + t];
        }
        dst[(size_t)i * dst_step] = s / wsum;
    }
}

/* src (w x h) -> dst ((w+1)/2 x (h+1)/2), through tmp ((w+1)/2 x h). */
static void reduce_plane(const double *src, int w, int h, double *tmp, double *dst)
{
    const int w2 = (w + 1) / 2;
    for (int r = 0; r < h; ++r)
        reduce_line(src + (size_t)r * (size_t)w, w, 1, tmp + (size_t)r * (size_t)w2, 1);
    for (int col = 0; col < w2; ++col)
        reduce_line(tmp + col, h, (size_t)w2, dst + col, (size_t)w2);
}

/* Buffers of the coarser levels: two ping-pong pairs of planes and the
 * horizontal-pass scratch. */
typedef struct pyramid {
    double *levels[2];          /* x then y, each (w+1)/2 * (h+1)/2, per parity */
    double *tmp;
    double *row_ssim, *row_cs;  /* height rows */
} pyramid;

static void pyramid_free(pyramid *py)
{
    free(py->levels[0]);
    free(py->levels[1]);
    free(py->tmp);
    free(py->row_ssim);
    free(py->row_cs);
}

static rl_status pyramid_init(pyramid *py, int w, int h)
{
    memset(py, 0, sizeof *py);
    const size_t n1 = (size_t)((w + 1) / 2) * (size_t)((h + 1) / 2);
    py->levels[0] = rl_calloc(2 * n1, sizeof(double));
    py->levels[1] = rl_calloc(2 * n1, sizeof(double));
    py->tmp = rl_calloc((size_t)((w + 1) / 2) * (size_t)h, sizeof(double));
    py->row_ssim = rl_calloc((size_t)h, sizeof(double));
    py->row_cs = rl_calloc((size_t)h, sizeof(double));
    if (!py->levels[0] || !py->levels[1] || !py->tmp || !py->row_ssim || !py->row_cs) {
        pyramid_free(py);
        return RL_ERR_OUT_OF_MEMORY;
    }
    return RL_OK;
}

/* Multi-scale SSIM of the current planes (no mask: rejected earlier). */
static double ms_ssim(compare_ctx *c, pyramid *py, int levels)
{
    ssim_job *job = &c->job;
    const int w0 = job->width, h0 = job->height;
    const double *x = c->planes, *y = c->planes + (size_t)w0 * (size_t)h0;
    double wsum = 0.0;
    for (int j = 0; j < levels; ++j)
        wsum += ms_weights[j];
    int w = w0, h = h0;
    double result = 1.0;
    for (int j = 0; j < levels; ++j) {
        job->x = x;
        job->y = y;
        job->width = w;
        job->height = h;
        truncated_norms(job->g, w, job->col_inv);
        truncated_norms(job->g, h, job->row_inv);
        memset(py->row_ssim, 0, (size_t)h * sizeof(double));
        memset(py->row_cs, 0, (size_t)h * sizeof(double));
        job->row_sum = py->row_ssim;
        job->row_cs = py->row_cs;
        ssim_run(job, c->threads);
        double sum = 0.0;
        const double *rows = j == levels - 1 ? py->row_ssim : py->row_cs;
        for (int r = 0; r < h; ++r)
            sum += rows[r];
        double mean = sum / ((double)w * (double)h);
        /* Wang 2003, Eq. (7): c*s at every scale, luminance at the coarsest */
        result *= pow(mean > 0.0 ? mean : 0.0, ms_weights[j] / wsum);
        if (j + 1 < levels) {
            const int w2 = (w + 1) / 2, h2 = (h + 1) / 2;
            double *nx = py->levels[j % 2], *ny = nx + (size_t)w2 * (size_t)h2;
            reduce_plane(x, w, h, py->tmp, nx);
            reduce_plane(y, w, h, py->tmp, ny);
            x = nx;
            y = ny;
            w = w2;
            h = h2;
        }
    }
    /* back to the full-size planes for the next channel */
    job->x = c->planes;
    job->y = c->planes + (size_t)w0 * (size_t)h0;
    job->width = w0;
    job->height = h0;
    job->row_sum = NULL;
    job->row_cs = NULL;
    truncated_norms(job->g, w0, job->col_inv);
    truncated_norms(job->g, h0, job->row_inv);
    return result;
}

/* Mean multi-scale SSIM over luma or the three channels. */
static double ctx_run_ms(compare_ctx *c, pyramid *py)
{
    if (!c->opt.ssim_rgb) {
        fill_planes(c, CH_LUMA);
        return ms_ssim(c, py, c->opt.ssim_levels);
    }
    double sum = 0.0;
    for (int ch = CH_R; ch <= CH_B; ++ch) {
        fill_planes(c, (channel)ch);
        sum += ms_ssim(c, py, c->opt.ssim_levels);
    }
    return sum / 3.0;
}

static rl_status check_levels(const char *fn, const rl_metric_options *opt, bool map)
{
    if (!opt)
        return RL_OK;
    if (opt->ssim_levels < 0 || opt->ssim_levels > MS_MAX_LEVELS)
        return rl_error(RL_ERR_INVALID_ARG, "%s: ssim_levels %d outside [0, %d]", fn,
                        opt->ssim_levels, MS_MAX_LEVELS);
    if (opt->ssim_levels > 1 && opt->mask)
        return rl_error(RL_ERR_INVALID_ARG,
                        "%s: a mask is not supported with ssim_levels > 1 (the coarser levels "
                        "have no mask)", fn);
    if (opt->ssim_levels > 1 && map)
        return rl_error(RL_ERR_INVALID_ARG,
                        "%s: the SSIM map is single-scale; ssim_levels must be 0 or 1", fn);
    return RL_OK;
}

/* ---- public API ------------------------------------------------------- */

rl_status rl_image_compare(const rl_image *test, const rl_image *reference,
                           const rl_metric_options *opt, rl_image_metrics *out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_compare: out is NULL");
    rl_status st = check_levels("rl_image_compare", opt, false);
    if (st != RL_OK)
        return st;
    compare_ctx c;
    uint64_t pixels = 0;
    st = ctx_init(&c, "rl_image_compare", test, reference, opt, true, &pixels);
    if (st != RL_OK)
        return st;
    const int h = test->height;
    const bool multi = c.opt.ssim_levels > 1;
    double *row_ssim = rl_calloc((size_t)h, sizeof(double));
    pyramid py;
    memset(&py, 0, sizeof py);
    if (row_ssim && multi)
        st = pyramid_init(&py, test->width, h);
    if (!row_ssim || st != RL_OK) {
        free(row_ssim);
        ctx_free(&c);
        return RL_ERR_OUT_OF_MEMORY;
    }
    double ms = 0.0;
    if (multi) {
        ms = ctx_run_ms(&c, &py);
    } else {
        c.job.row_sum = row_ssim;
        ctx_run(&c);
    }

    double sq = 0.0, max_abs = 0.0, ssim = 0.0;
    for (int i = 0; i < h; ++i) {
        sq += c.row_sq[i];
        max_abs = c.row_max[i] > max_abs ? c.row_max[i] : max_abs;
        ssim += row_ssim[i];
    }
    const double count = (double)pixels;
    const double mse = sq / (3.0 * count);          /* over R, G and B */
    out->rmse = sqrt(mse);
    out->psnr = mse > 0.0 ? 10.0 * log10(1.0 / mse) : INFINITY;
    out->ssim = multi ? ms : ssim / (count * (c.opt.ssim_rgb ? 3.0 : 1.0));
    out->max_abs = max_abs;
    out->pixels = pixels;
    free(row_ssim);
    pyramid_free(&py);
    ctx_free(&c);
    return RL_OK;
}

rl_status rl_image_ssim_map(const rl_image *test, const rl_image *reference,
                            const rl_metric_options *opt, float *out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_ssim_map: out is NULL");
    rl_status st = check_levels("rl_image_ssim_map", opt, true);
    if (st != RL_OK)
        return st;
    compare_ctx c;
    uint64_t pixels = 0;
    st = ctx_init(&c, "rl_image_ssim_map", test, reference, opt, false, &pixels);
    if (st != RL_OK)
        return st;
    memset(out, 0, (size_t)test->width * (size_t)test->height * sizeof *out);
    c.job.map = out;
    ctx_run(&c);
    ctx_free(&c);
    return RL_OK;
}

/* Display ramp black -> red -> yellow -> white over v in [0, 1], returned as
 * linear colour so that the PNG writer's sRGB encoding shows the ramp. */
static rl_vec4 heat(float v)
{
    float r = fminf(1.0f, 3.0f * v);
    float g = fminf(1.0f, fmaxf(0.0f, 3.0f * v - 1.0f));
    float b = fminf(1.0f, fmaxf(0.0f, 3.0f * v - 2.0f));
    return rl_v4(rl_srgb_to_linear(r), rl_srgb_to_linear(g), rl_srgb_to_linear(b), 1.0f);
}

rl_status rl_image_difference(const rl_image *test, const rl_image *reference, float gain,
                              rl_image **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_difference: out is NULL");
    rl_status st = check_pair("rl_image_difference", test, reference);
    if (st != RL_OK)
        return st;
    if (!(gain > 0.0f) || !isfinite(gain))
        return rl_error(RL_ERR_INVALID_ARG, "rl_image_difference: gain %g must be finite and > 0",
                        (double)gain);
    rl_image *img = NULL;
    st = rl_image_create(test->width, test->height, RL_LAYER_COLOR, &img);
    if (st != RL_OK)
        return st;
    const long n = (long)test->width * (long)test->height;
#pragma omp parallel for schedule(static) if (n >= MIN_PARALLEL)
    for (long k = 0; k < n; ++k) {
        rl_vec4 a = test->color[k], b = reference->color[k];
        /* on sRGB-encoded values, like the metrics' default: what a viewer sees */
        double d = fabs(encode(a.x, false) - encode(b.x, false));
        d = fmax(d, fabs(encode(a.y, false) - encode(b.y, false)));
        d = fmax(d, fabs(encode(a.z, false) - encode(b.z, false)));
        img->color[k] = d > 0.0 ? heat((float)fmin(1.0, d * (double)gain)) : rl_v4(0, 0, 0, 1);
    }
    *out = img;
    return RL_OK;
}
