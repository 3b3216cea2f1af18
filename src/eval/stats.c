/* stats.c: weighted descriptive statistics, quantiles, Gaussian kernel density
 * estimates and Pearson correlation (rl_stats.h).
 *
 * Jähn 2015, Sec. 5.6.2: the values of the regions of an approximated scene
 * property must be weighted by the regions' areas or volumes, so every
 * statistic here takes optional weights. Quantiles use the inverted weighted
 * CDF (Hyndman & Fan 1996, definition 1, generalised to weights): no
 * interpolation, so a quantile is always a value that occurs in the data,
 * which is what a region-based property (a count of visible objects) needs.
 *
 * The KDE bandwidth follows Silverman 1986, "Density Estimation for Statistics
 * and Data Analysis", Eq. (3.31): h = 0.9 min(sd, IQR/1.34) n^(-1/5), with
 * Kish's effective sample size W^2 / sum(w^2) for n, so that weights that
 * concentrate on few values widen the kernel as fewer samples would. Kernels
 * are cut at 8 h (exp(-32) ~ 1e-14 of the peak), found by binary search in
 * the sorted values, so that large region sets stay cheap. */
#include "rl/rl_stats.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/stats_internal.h"

typedef struct weighted {
    double v, w;
} weighted;

/* Kernel cut-off in bandwidths: beyond 8 h a Gaussian contributes < 1.3e-14
 * of its peak, far below double rounding of a density sum. */
#define KDE_CUTOFF 8.0
#define INV_SQRT_2PI 0.39894228040143267794

static int cmp_weighted(const void *a, const void *b)
{
    double x = ((const weighted *)a)->v, y = ((const weighted *)b)->v;
    return (x > y) - (x < y);
}

/* Validates the input and returns the values of positive weight, sorted, in
 * *out (count in *count, total weight in *total). */
static rl_status sorted_input(const char *fn, const double *values, const double *weights,
                              size_t n, weighted **out, size_t *count, double *total)
{
    if (!values)
        return rl_error(RL_ERR_INVALID_ARG, "%s: values is NULL", fn);
    if (n == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no values", fn);
    double sum = 0.0;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(values[i]))
            return rl_error(RL_ERR_INVALID_ARG, "%s: value %zu is not finite (%g)", fn, i, values[i]);
        double w = weights ? weights[i] : 1.0;
        if (!isfinite(w) || w < 0.0)
            return rl_error(RL_ERR_INVALID_ARG, "%s: weight %zu is negative or not finite (%g)", fn, i, w);
        sum += w;
        m += w > 0.0;
    }
    if (m == 0 || !(sum > 0.0) || !isfinite(sum))
        return rl_error(RL_ERR_INVALID_ARG, "%s: total weight is %g", fn, sum);
    weighted *p = rl_calloc(m, sizeof *p);
    if (!p)
        return RL_ERR_OUT_OF_MEMORY;
    size_t k = 0;
    for (size_t i = 0; i < n; ++i) {
        double w = weights ? weights[i] : 1.0;
        if (w > 0.0)
            p[k++] = (weighted){ values[i], w };
    }
    qsort(p, m, sizeof *p, cmp_weighted);
    *out = p;
    *count = m;
    *total = sum;
    return RL_OK;
}

/* Smallest sorted value whose cumulative weight reaches q W. The relative
 * slack absorbs the rounding of the running sum, so that e.g. q = 0.3 over
 * ten weights of 0.1 lands on the third value and not the fourth. */
static double quantile_sorted(const weighted *p, size_t m, double total, double q)
{
    double target = q * total - 1e-12 * total;
    double c = 0.0;
    for (size_t i = 0; i < m; ++i) {
        c += p[i].w;
        if (c >= target)
            return p[i].v;
    }
    return p[m - 1].v;
}

/* Quantiles of ascending qs in one sweep over the sorted values. */
static void quantiles_sorted(const weighted *p, size_t m, double total, const double *qs,
                             const size_t *order, size_t nq, double *out)
{
    size_t i = 0;
    double c = p[0].w;
    for (size_t k = 0; k < nq; ++k) {
        double target = qs[order[k]] * total - 1e-12 * total;
        while (c < target && i + 1 < m)
            c += p[++i].w;
        out[order[k]] = p[i].v;
    }
}

static void moments(const weighted *p, size_t m, double total, double *mean, double *sd)
{
    /* Two passes: the one-pass formula loses all digits for large offsets. */
    double s = 0.0;
    for (size_t i = 0; i < m; ++i)
        s += p[i].w * p[i].v;
    double mu = s / total;
    double ss = 0.0;
    for (size_t i = 0; i < m; ++i)
        ss += p[i].w * (p[i].v - mu) * (p[i].v - mu);
    *mean = mu;
    *sd = sqrt(ss / total);
}

rl_status rl_stats_compute(const double *values, const double *weights, size_t n, rl_stats *out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_stats_compute: out is NULL");
    weighted *p = NULL;
    size_t m = 0;
    double total = 0.0;
    rl_status st = sorted_input("rl_stats_compute", values, weights, n, &p, &m, &total);
    if (st != RL_OK)
        return st;
    rl_stats s = { .count = m, .total_weight = total, .min = p[0].v, .max = p[m - 1].v };
    moments(p, m, total, &s.mean, &s.stddev);
    static const double qs[RL_STATS_QUANTILES] = { 0.0, 0.25, 0.5, 0.75, 1.0 };
    for (int k = 0; k < RL_STATS_QUANTILES; ++k)
        s.q[k] = quantile_sorted(p, m, total, qs[k]);
    free(p);
    *out = s;
    return RL_OK;
}

rl_status rl_stats_quantiles(const double *values, const double *weights, size_t n,
                             const double *qs, size_t nq, double *out)
{
    const char *fn = "rl_stats_quantiles";
    if (!qs || !out || nq == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: qs or out is NULL or nq is 0", fn);
    for (size_t k = 0; k < nq; ++k)
        if (!(qs[k] >= 0.0 && qs[k] <= 1.0))
            return rl_error(RL_ERR_INVALID_ARG, "%s: q[%zu] = %g outside [0, 1]", fn, k, qs[k]);
    weighted *p = NULL;
    size_t m = 0;
    double total = 0.0;
    rl_status st = sorted_input(fn, values, weights, n, &p, &m, &total);
    if (st != RL_OK)
        return st;
    /* qs may come in any order: sort (q, index) pairs so that one sweep
     * over the cumulative weights answers all of them. */
    weighted *qi = rl_calloc(nq, sizeof *qi);
    size_t *order = rl_calloc(nq, sizeof *order);
    double *res = rl_calloc(nq, sizeof *res);
    if (!qi || !order || !res) {
        free(p);
        free(qi);
        free(order);
        free(res);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (size_t k = 0; k < nq; ++k)
        qi[k] = (weighted){ qs[k], (double)k };
    qsort(qi, nq, sizeof *qi, cmp_weighted);
    for (size_t k = 0; k < nq; ++k)
        order[k] = (size_t)qi[k].w;
    free(qi);
    quantiles_sorted(p, m, total, qs, order, nq, res);
    memcpy(out, res, nq * sizeof *out);
    free(order);
    free(res);
    free(p);
    return RL_OK;
}

/* Silverman's rule with Kish's n_eff and the fallbacks of rl_stats.h. */
static double silverman(const weighted *p, size_t m, double total)
{
    double mean, sd;
    moments(p, m, total, &mean, &sd);
    double sw2 = 0.0;
    for (size_t i = 0; i < m; ++i)
        sw2 += p[i].w * p[i].w;
    double n_eff = total * total / sw2;
    double iqr = quantile_sorted(p, m, total, 0.75) - quantile_sorted(p, m, total, 0.25);
    double spread = fmin(sd, iqr / 1.34);
    if (!(spread > 0.0))
        spread = sd;
    if (!(spread > 0.0))
        return 1e-3 * fmax(1.0, fabs(mean));
    return 0.9 * spread * pow(n_eff, -0.2);
}

/* First index with p[i].v >= x. */
static size_t lower_bound(const weighted *p, size_t m, double x)
{
    size_t lo = 0, hi = m;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (p[mid].v < x)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

rl_status rl_stats_kde(const double *values, const double *weights, size_t n, double bandwidth,
                       const double *xs, size_t m, double *density, double *used_bandwidth)
{
    const char *fn = "rl_stats_kde";
    if (!xs || !density || m == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: xs or density is NULL or m is 0", fn);
    if (isnan(bandwidth) || isinf(bandwidth))
        return rl_error(RL_ERR_INVALID_ARG, "%s: bandwidth is not finite", fn);
    for (size_t j = 0; j < m; ++j)
        if (!isfinite(xs[j]))
            return rl_error(RL_ERR_INVALID_ARG, "%s: xs[%zu] is not finite", fn, j);
    weighted *p = NULL;
    size_t count = 0;
    double total = 0.0;
    rl_status st = sorted_input(fn, values, weights, n, &p, &count, &total);
    if (st != RL_OK)
        return st;
    double h = bandwidth > 0.0 ? bandwidth : silverman(p, count, total);
    double norm = INV_SQRT_2PI / (h * total);
    for (size_t j = 0; j < m; ++j) {
        double x = xs[j], sum = 0.0;
        for (size_t i = lower_bound(p, count, x - KDE_CUTOFF * h);
             i < count && p[i].v <= x + KDE_CUTOFF * h; ++i) {
            double u = (x - p[i].v) / h;
            sum += p[i].w * exp(-0.5 * u * u);
        }
        density[j] = sum * norm;
    }
    free(p);
    if (used_bandwidth)
        *used_bandwidth = h;
    return RL_OK;
}

int rl_stats_pearson(const double *x, const double *y, size_t n, double *r)
{
    double mx = 0.0, my = 0.0;
    for (size_t i = 0; i < n; ++i) {
        mx += x[i];
        my += y[i];
    }
    mx /= (double)n;
    my /= (double)n;
    double sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double dx = x[i] - mx, dy = y[i] - my;
        sxx += dx * dx;
        syy += dy * dy;
        sxy += dx * dy;
    }
    if (!(sxx > 0.0))
        return 1;
    if (!(syy > 0.0))
        return 2;
    /* Rounding can push |r| a hair past 1 for exactly linear data. */
    *r = fmax(-1.0, fmin(1.0, sxy / sqrt(sxx * syy)));
    return 0;
}

rl_status rl_stats_correlation(const double *x, const double *y, size_t n, double *r)
{
    const char *fn = "rl_stats_correlation";
    if (!x || !y || !r)
        return rl_error(RL_ERR_INVALID_ARG, "%s: x, y or r is NULL", fn);
    if (n < 2)
        return rl_error(RL_ERR_INVALID_ARG, "%s: need at least 2 pairs, got %zu", fn, n);
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(x[i]) || !isfinite(y[i]))
            return rl_error(RL_ERR_INVALID_ARG, "%s: pair %zu is not finite", fn, i);
    int constant = rl_stats_pearson(x, y, n, r);
    if (constant)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %s is constant", fn, constant == 1 ? "x" : "y");
    return RL_OK;
}
