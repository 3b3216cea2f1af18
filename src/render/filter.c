/* filter.c: noise-reduction filters for path-traced images (Schröder 2017,
 * Sec. 8.2; the thesis follows Priese 2015): Gauss (Sec. 8.2.1), bilateral
 * (Sec. 8.2.2, Tomasi & Manduchi 1998), anisotropic diffusion (Sec. 8.2.3,
 * Perona & Malik 1990) and Kuwahara (Sec. 8.2.4, Kuwahara et al. 1976);
 * and, beyond the thesis (issue 37), the edge-avoiding a-trous wavelet
 * filter of Dammertz, Sewtz, Hanika and Lensch 2010.
 *
 * Parameters and defaults are those of rl_filter.h. All filters work on the
 * RGB of RL_LAYER_COLOR; alpha is copied from the input. Pixels outside the
 * image are replaced by the nearest border pixel (clamping), so a constant
 * image stays constant everywhere. Every output pixel is computed from the
 * input (or the previous diffusion step) alone, so rows are shared among
 * OpenMP threads without locks and results do not depend on the thread
 * count.
 *
 * G-buffer guidance (a deviation: the thesis filters colour only). With a
 * G-buffer the bilateral weight and the diffusion conductance between two
 * pixels are multiplied by
 *     [same object] * exp(-((1 - n·n') / sigma_n)^2 / 2) * exp(-(dz / sigma_z)^2 / 2),
 * dz = |z - z'| / min(z, z') the relative depth difference; a pixel that
 * sees nothing is only similar to another that sees nothing. Absent arrays
 * (NULL) drop their term. Across object or crease edges the factor is zero
 * or vanishingly small, so noise is smoothed up to geometric edges but not
 * across them. Gauss and Kuwahara ignore the G-buffer. */
#include "rl/rl_filter.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#define FILTER_MAX_RADIUS 64          /* caps absurd windows (stb style) */
#define FILTER_MAX_ITERATIONS 10000
/* A-trous holes grow as 2^i: 12 levels already reach 2 x 2048 pixels. */
#define ATROUS_MAX_ITERATIONS 12

static const char *const kind_names[RL_FILTER_KIND_COUNT] = {
    "none", "gauss", "bilateral", "aniso", "kuwahara", "atrous"
};

const char *rl_filter_kind_name(rl_filter_kind kind)
{
    return (unsigned)kind < RL_FILTER_KIND_COUNT ? kind_names[kind] : "unknown";
}

rl_status rl_filter_kind_parse(const char *name, rl_filter_kind *out)
{
    if (!name || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_kind_parse: NULL argument");
    for (int k = 0; k < RL_FILTER_KIND_COUNT; ++k)
        if (strcmp(name, kind_names[k]) == 0) {
            *out = (rl_filter_kind)k;
            return RL_OK;
        }
    return rl_error(RL_ERR_INVALID_ARG, "unknown filter \"%s\" (known: none, gauss, bilateral, "
                                        "aniso, kuwahara, atrous)", name);
}

/* ---- parameters ---------------------------------------------------------- */

typedef struct filter_params {
    rl_filter_kind kind;
    float sigma_s, sigma_r, sigma_n, sigma_z, lambda, kappa, sigma_x;
    int radius, iterations;
} filter_params;

static bool positive(float x) { return isfinite(x) && x > 0.0f; }

static rl_status resolve(const rl_filter_desc *d, filter_params *p)
{
    if ((unsigned)d->kind >= RL_FILTER_KIND_COUNT)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: unknown kind %d", (int)d->kind);
    p->kind = d->kind;
    p->sigma_s = d->sigma_s == 0.0f ? 1.5f : d->sigma_s;
    p->sigma_r = d->sigma_r == 0.0f ? 0.1f : d->sigma_r;
    p->sigma_n = d->sigma_n == 0.0f ? 0.1f : d->sigma_n;
    p->sigma_z = d->sigma_z == 0.0f ? 0.05f : d->sigma_z;
    p->lambda = d->lambda == 0.0f ? 0.2f : d->lambda;
    p->kappa = d->kappa == 0.0f ? 0.1f : d->kappa;
    p->iterations = d->iterations != 0 ? d->iterations : d->kind == RL_FILTER_ATROUS ? 5 : 20;
    p->sigma_x = d->sigma_x;
    if (!(isfinite(p->sigma_x) && p->sigma_x >= 0.0f))
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: sigma_x %g must be finite and >= 0 "
                        "(0: from the pixel footprint)", (double)p->sigma_x);
    if (p->kind == RL_FILTER_ATROUS && (p->iterations < 1 || p->iterations > ATROUS_MAX_ITERATIONS))
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: a-trous iterations %d outside 1..%d",
                        p->iterations, ATROUS_MAX_ITERATIONS);
    if (!positive(p->sigma_s) || !positive(p->sigma_r) || !positive(p->sigma_n) ||
        !positive(p->sigma_z) || !positive(p->kappa))
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: sigma_s %g, sigma_r %g, sigma_n "
                        "%g, sigma_z %g and kappa %g must be finite and > 0",
                        (double)p->sigma_s, (double)p->sigma_r, (double)p->sigma_n,
                        (double)p->sigma_z, (double)p->kappa);
    /* Perona & Malik's explicit scheme is stable for lambda <= 1/4 with
     * four neighbours. */
    if (!(p->lambda > 0.0f && p->lambda <= 0.25f))
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: lambda %g outside (0, 0.25]",
                        (double)p->lambda);
    if (p->iterations < 1 || p->iterations > FILTER_MAX_ITERATIONS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: iterations %d outside 1..%d",
                        p->iterations, FILTER_MAX_ITERATIONS);
    if (d->radius < 0 || d->radius > FILTER_MAX_RADIUS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: radius %d outside 0..%d",
                        d->radius, FILTER_MAX_RADIUS);
    if (d->radius > 0)
        p->radius = d->radius;
    else if (p->kind == RL_FILTER_KUWAHARA)
        p->radius = 1;    /* Sec. 8.2.4: four 2x2 groups of the 3x3 neighbourhood */
    else
        p->radius = (int)ceilf(2.0f * p->sigma_s);
    if (p->radius > FILTER_MAX_RADIUS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: sigma_s %g needs a radius above %d",
                        (double)p->sigma_s, FILTER_MAX_RADIUS);
    return RL_OK;
}

static inline int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

static inline rl_vec3 rgb(rl_vec4 c) { return rl_v3(c.x, c.y, c.z); }

/* ---- G-buffer guidance --------------------------------------------------- */

typedef struct guide {
    const rl_gbuffer *g;              /* NULL: unguided */
    float inv_sigma_n, inv_sigma_z;
} guide;

/* Similarity of pixels i and j in the G-buffer, in [0,1] (see the top). */
static float guide_weight(const guide *gd, size_t i, size_t j)
{
    const rl_gbuffer *g = gd->g;
    if (!g || i == j)
        return 1.0f;
    if (g->object && g->object[i] != g->object[j])
        return 0.0f;
    /* Background (nothing seen) is alike only to background; its normals
     * and depths mean nothing. */
    bool seen_i = g->depth ? isfinite(g->depth[i]) : !g->object || g->object[i] != RL_ID_NONE;
    bool seen_j = g->depth ? isfinite(g->depth[j]) : !g->object || g->object[j] != RL_ID_NONE;
    if (seen_i != seen_j)
        return 0.0f;
    if (!seen_i)
        return 1.0f;
    float w = 1.0f;
    if (g->depth) {
        float zi = g->depth[i], zj = g->depth[j];
        float zmin = fminf(fabsf(zi), fabsf(zj));
        float dz = fabsf(zi - zj) / fmaxf(zmin, 1e-20f) * gd->inv_sigma_z;
        w *= expf(-0.5f * dz * dz);
    }
    if (g->normal) {
        float dn = (1.0f - rl_dot(g->normal[i], g->normal[j])) * gd->inv_sigma_n;
        w *= expf(-0.5f * dn * dn);
    }
    return w;
}

/* ---- Gauss (Sec. 8.2.1) -------------------------------------------------- */

/* Separable: a horizontal pass into tmp, a vertical pass into out; the
 * truncated kernel is normalised so that it preserves energy. */
static rl_status gauss(const filter_params *p, const rl_image *in, rl_image *out)
{
    const int w = in->width, h = in->height, r = p->radius;
    float kernel[2 * FILTER_MAX_RADIUS + 1];
    double sum = 0.0;
    for (int k = -r; k <= r; ++k) {
        kernel[k + r] = expf(-0.5f * (float)(k * k) / (p->sigma_s * p->sigma_s));
        sum += kernel[k + r];
    }
    for (int k = 0; k <= 2 * r; ++k)
        kernel[k] = (float)(kernel[k] / sum);
    rl_vec3 *tmp = rl_calloc((size_t)w * (size_t)h, sizeof *tmp);
    if (!tmp)
        return RL_ERR_OUT_OF_MEMORY;
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        const rl_vec4 *row = in->color + (size_t)y * w;
        for (int x = 0; x < w; ++x) {
            rl_vec3 acc = rl_v3s(0.0f);
            for (int k = -r; k <= r; ++k)
                acc = rl_madd(acc, rgb(row[clampi(x + k, 0, w - 1)]), kernel[k + r]);
            tmp[(size_t)y * w + x] = acc;
        }
    }
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            rl_vec3 acc = rl_v3s(0.0f);
            for (int k = -r; k <= r; ++k)
                acc = rl_madd(acc, tmp[(size_t)clampi(y + k, 0, h - 1) * w + x], kernel[k + r]);
            size_t i = (size_t)y * w + x;
            out->color[i] = rl_v4_from3(acc, in->color[i].w);
        }
    }
    free(tmp);
    return RL_OK;
}

/* ---- bilateral (Sec. 8.2.2) ---------------------------------------------- */

static rl_status bilateral(const filter_params *p, const rl_image *in, const guide *gd,
                           rl_image *out)
{
    const int w = in->width, h = in->height, r = p->radius, side = 2 * r + 1;
    float *spatial = rl_alloc((size_t)side * side * sizeof *spatial);
    if (!spatial)
        return RL_ERR_OUT_OF_MEMORY;
    for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx)
            spatial[(dy + r) * side + dx + r] =
                expf(-0.5f * (float)(dx * dx + dy * dy) / (p->sigma_s * p->sigma_s));
    const float inv_2sr2 = 0.5f / (p->sigma_r * p->sigma_r);
    #pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            rl_vec3 c = rgb(in->color[i]), acc = rl_v3s(0.0f);
            float wsum = 0.0f;
            for (int dy = -r; dy <= r; ++dy) {
                int yy = clampi(y + dy, 0, h - 1);
                for (int dx = -r; dx <= r; ++dx) {
                    size_t j = (size_t)yy * w + clampi(x + dx, 0, w - 1);
                    rl_vec3 cj = rgb(in->color[j]);
                    /* Gaussian in distance times Gaussian in colour
                     * difference: similar pixels mix, edges stay. */
                    float wt = spatial[(dy + r) * side + dx + r] *
                               expf(-rl_length2(rl_sub(cj, c)) * inv_2sr2);
                    if (gd->g && wt > 0.0f)
                        wt *= guide_weight(gd, i, j);
                    acc = rl_madd(acc, cj, wt);
                    wsum += wt;
                }
            }
            /* The centre weighs 1, so wsum >= 1 (a NaN input stays NaN). */
            out->color[i] = rl_v4_from3(rl_scale(acc, 1.0f / wsum), in->color[i].w);
        }
    }
    free(spatial);
    return RL_OK;
}

/* ---- anisotropic diffusion (Sec. 8.2.3) ---------------------------------- */

/* Perona & Malik: I += lambda * sum over the 4 neighbours of g(|dI|) dI with
 * g(d) = exp(-(d/kappa)^2), d the RGB distance (one conductance for all
 * channels, so colour edges stop diffusion in every channel alike). A
 * clamped neighbour is the pixel itself: no flux over the border. The
 * G-buffer factor between pixel pairs is fixed, so it is computed once. */
static rl_status aniso(const filter_params *p, const rl_image *in, const guide *gd,
                       rl_image *out)
{
    const int w = in->width, h = in->height;
    const size_t n = (size_t)w * (size_t)h;
    rl_vec3 *a = rl_alloc(n * sizeof *a), *b = rl_alloc(n * sizeof *b);
    /* conduct[2i]: pixel i to its right neighbour, [2i+1]: to the one below. */
    float *conduct = gd->g ? rl_alloc(2 * n * sizeof *conduct) : NULL;
    if (!a || !b || (gd->g && !conduct)) {
        free(a);
        free(b);
        free(conduct);
        return RL_ERR_OUT_OF_MEMORY;
    }
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            a[i] = rgb(in->color[i]);
            if (conduct) {
                conduct[2 * i] = x + 1 < w ? guide_weight(gd, i, i + 1) : 0.0f;
                conduct[2 * i + 1] = y + 1 < h ? guide_weight(gd, i, i + (size_t)w) : 0.0f;
            }
        }
    const float inv_k2 = 1.0f / (p->kappa * p->kappa);
    for (int it = 0; it < p->iterations; ++it) {
        #pragma omp parallel for schedule(static)
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                size_t i = (size_t)y * w + x;
                rl_vec3 c = a[i], flux = rl_v3s(0.0f);
                /* Neighbours: left, right, up, down, with the pair's
                 * G-buffer factor (stored at the left/upper pixel). */
                size_t nb[4] = { x > 0 ? i - 1 : i, x + 1 < w ? i + 1 : i,
                                 y > 0 ? i - (size_t)w : i, y + 1 < h ? i + (size_t)w : i };
                for (int k = 0; k < 4; ++k) {
                    if (nb[k] == i)
                        continue;
                    rl_vec3 d = rl_sub(a[nb[k]], c);
                    float g = expf(-rl_length2(d) * inv_k2);
                    if (conduct)
                        g *= k == 0 ? conduct[2 * (i - 1)] : k == 1 ? conduct[2 * i]
                           : k == 2 ? conduct[2 * (i - (size_t)w) + 1] : conduct[2 * i + 1];
                    flux = rl_madd(flux, d, g);
                }
                b[i] = rl_madd(c, flux, p->lambda);
            }
        }
        rl_vec3 *t = a;
        a = b;
        b = t;
    }
    for (size_t i = 0; i < n; ++i)
        out->color[i] = rl_v4_from3(a[i], in->color[i].w);
    free(a);
    free(b);
    free(conduct);
    return RL_OK;
}

/* ---- Kuwahara (Sec. 8.2.4) ----------------------------------------------- */

/* The four (r+1)x(r+1) quadrants that share the pixel as a corner; the
 * pixel takes the mean of the one with the smallest variance (summed over
 * RGB). Ties go to the first quadrant in the order top-left, top-right,
 * bottom-left, bottom-right, which keeps the result deterministic. */
static rl_status kuwahara(const filter_params *p, const rl_image *in, rl_image *out)
{
    const int w = in->width, h = in->height, r = p->radius;
    const float inv_count = 1.0f / (float)((r + 1) * (r + 1));
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            rl_vec3 best_mean = rl_v3s(0.0f);
            float best_var = INFINITY;
            for (int q = 0; q < 4; ++q) {
                int x0 = q & 1 ? x : x - r, y0 = q & 2 ? y : y - r;
                rl_vec3 mean = rl_v3s(0.0f);
                for (int dy = 0; dy <= r; ++dy)
                    for (int dx = 0; dx <= r; ++dx)
                        mean = rl_add(mean, rgb(in->color[(size_t)clampi(y0 + dy, 0, h - 1) * w +
                                                          clampi(x0 + dx, 0, w - 1)]));
                mean = rl_scale(mean, inv_count);
                /* Two passes (mean, then squared deviations) avoid the
                 * cancellation of E[x^2] - E[x]^2 on bright pixels. */
                float var = 0.0f;
                for (int dy = 0; dy <= r; ++dy)
                    for (int dx = 0; dx <= r; ++dx)
                        var += rl_length2(rl_sub(
                            rgb(in->color[(size_t)clampi(y0 + dy, 0, h - 1) * w +
                                          clampi(x0 + dx, 0, w - 1)]), mean));
                if (var < best_var || q == 0) {
                    best_var = var;
                    best_mean = mean;
                }
            }
            size_t i = (size_t)y * w + x;
            out->color[i] = rl_v4_from3(best_mean, in->color[i].w);
        }
    }
    return RL_OK;
}

/* ---- edge-avoiding a-trous wavelets (Dammertz et al. 2010) --------------- */

/* Whether pixel i of g sees a surface (as guide_weight decides it). */
static bool seen(const rl_gbuffer *g, size_t i)
{
    return g->depth ? isfinite(g->depth[i]) : !g->object || g->object[i] != RL_ID_NONE;
}

/* 1 / sigma_x^2 per pixel when sigma_x is derived (0 in the description):
 * the position scale then follows the pixel footprint, so the filter needs
 * no scene unit. At level i the taps lie 2^i footprints apart on a surface
 * facing the camera; with sigma_x = 2^iterations footprints the farthest
 * taps of the last level (2 * 2^(n-1) = 2^n footprints) still weigh
 * exp(-1), while a depth jump of many footprints weighs nothing. A pixel
 * with no seen neighbour keeps 0 (no position term; it has no surface
 * neighbour to protect). */
static void footprint_inv_sigma2(const rl_gbuffer *g, int iterations, float *inv)
{
    const int w = g->width, h = g->height;
    const float scale = (float)(1 << iterations);
    #pragma omp parallel for schedule(static)
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * w + x;
            inv[i] = 0.0f;
            if (!seen(g, i))
                continue;
            size_t nb[4] = { x > 0 ? i - 1 : i, x + 1 < w ? i + 1 : i,
                             y > 0 ? i - (size_t)w : i, y + 1 < h ? i + (size_t)w : i };
            float best = INFINITY;
            for (int k = 0; k < 4; ++k) {
                float d = rl_length(rl_sub(g->position[nb[k]], g->position[i]));
                if (nb[k] != i && seen(g, nb[k]) && d > 0.0f && d < best)
                    best = d;
            }
            if (isfinite(best))
                inv[i] = 1.0f / (scale * best * scale * best);
        }
    }
}

/* c_{i+1}(p) = sum_q h_i(q) w(p,q) c_i(q) / sum_q h_i(q) w(p,q) over the 25
 * taps q = p + 2^i (dx, dy), dx, dy in -2..2, h the separable B3 spline
 * (1, 4, 6, 4, 1) / 16 and w the product of the colour, normal and
 * position edge-stopping functions. The three Gaussians share one exp.
 * Taps that see a surface and taps that see nothing never mix. */
static rl_status atrous(const filter_params *p, const rl_image *in, const rl_gbuffer *g, rl_image *out)
{
    static const float h5[5] = { 1.0f / 16.0f, 4.0f / 16.0f, 6.0f / 16.0f, 4.0f / 16.0f, 1.0f / 16.0f };
    const int w = in->width, h = in->height;
    const size_t n = (size_t)w * (size_t)h;
    const bool use_n = g && g->normal, use_x = g && g->position;
    rl_vec3 *a = rl_alloc(n * sizeof *a), *b = rl_alloc(n * sizeof *b);
    float *inv_x = use_x && p->sigma_x == 0.0f ? rl_alloc(n * sizeof *inv_x) : NULL;
    if (!a || !b || (use_x && p->sigma_x == 0.0f && !inv_x)) {
        free(a);
        free(b);
        free(inv_x);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (size_t i = 0; i < n; ++i)
        a[i] = rgb(in->color[i]);
    if (inv_x)
        footprint_inv_sigma2(g, p->iterations, inv_x);
    const float fixed_inv_x = p->sigma_x > 0.0f ? 1.0f / (p->sigma_x * p->sigma_x) : 0.0f;
    const float inv_n = 1.0f / (p->sigma_n * p->sigma_n);
    for (int it = 0; it < p->iterations; ++it) {
        const int step = 1 << it;
        /* The paper's colour sigma halves per level: each level has
         * averaged away part of the noise the colour term must tolerate. */
        const float sr = p->sigma_r / (float)step;
        const float inv_c = 1.0f / (sr * sr);
        #pragma omp parallel for schedule(static)
        for (int y = 0; y < h; ++y) {
            for (int x = 0; x < w; ++x) {
                size_t i = (size_t)y * w + x;
                rl_vec3 c = a[i], acc = rl_v3s(0.0f);
                bool seen_i = g ? seen(g, i) : true;
                float ix = inv_x ? inv_x[i] : fixed_inv_x, wsum = 0.0f;
                for (int ky = 0; ky < 5; ++ky) {
                    int yy = y + (ky - 2) * step;
                    if (yy < 0 || yy >= h)
                        continue;
                    for (int kx = 0; kx < 5; ++kx) {
                        int xx = x + (kx - 2) * step;
                        if (xx < 0 || xx >= w)
                            continue;
                        size_t j = (size_t)yy * w + xx;
                        float e = rl_length2(rl_sub(a[j], c)) * inv_c;
                        if (g) {
                            if (seen(g, j) != seen_i)
                                continue;
                            if (seen_i && use_n)
                                e += rl_length2(rl_sub(g->normal[j], g->normal[i])) * inv_n;
                            if (seen_i && use_x)
                                e += rl_length2(rl_sub(g->position[j], g->position[i])) * ix;
                        }
                        float wt = h5[kx] * h5[ky] * expf(-e);
                        acc = rl_madd(acc, a[j], wt);
                        wsum += wt;
                    }
                }
                /* The centre tap weighs 36/256 whatever the guide says. */
                b[i] = rl_scale(acc, 1.0f / wsum);
            }
        }
        rl_vec3 *t = a;
        a = b;
        b = t;
    }
    for (size_t i = 0; i < n; ++i)
        out->color[i] = rl_v4_from3(a[i], in->color[i].w);
    free(a);
    free(b);
    free(inv_x);
    return RL_OK;
}

/* ---- entry point --------------------------------------------------------- */

rl_status rl_filter_apply(const rl_filter_desc *desc, const rl_image *in, const rl_gbuffer *g,
                          rl_image *out)
{
    if (!desc || !in || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: NULL argument");
    if (in == out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: in and out must be different "
                                            "images");
    if (!in->color || !out->color)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: both images need a colour layer");
    if (in->width != out->width || in->height != out->height || in->width < 1 ||
        in->height < 1)
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: size mismatch: in %dx%d, out %dx%d",
                        in->width, in->height, out->width, out->height);
    if (g && (g->width != in->width || g->height != in->height))
        return rl_error(RL_ERR_INVALID_ARG, "rl_filter_apply: G-buffer is %dx%d, image %dx%d",
                        g->width, g->height, in->width, in->height);
    filter_params p;
    rl_status s = resolve(desc, &p);
    if (s)
        return s;
    guide gd = { .g = g, .inv_sigma_n = 1.0f / p.sigma_n, .inv_sigma_z = 1.0f / p.sigma_z };
    switch (p.kind) {
    case RL_FILTER_GAUSS:     return gauss(&p, in, out);
    case RL_FILTER_BILATERAL: return bilateral(&p, in, &gd, out);
    case RL_FILTER_ANISO:     return aniso(&p, in, &gd, out);
    case RL_FILTER_KUWAHARA:  return kuwahara(&p, in, out);
    case RL_FILTER_ATROUS:    return atrous(&p, in, g, out);
    default:
        memcpy(out->color, in->color, (size_t)in->width * (size_t)in->height * sizeof *in->color);
        return RL_OK;
    }
}
