/* rl_stats.h: weighted descriptive statistics and kernel density estimates,
 * for evaluating sampled properties (Jähn 2015, Sec. 5.6.2: region values
 * must be weighted by the region's area or volume) and benchmark series.
 *
 * Weighted quantile, the definition used everywhere in renderlab (the
 * inverted weighted CDF): sort the values ascending; with W the total weight
 * and C_i the cumulative weight up to and including value i, the q-quantile
 * is the smallest value v_i with C_i >= q * W (q = 0 gives the minimum, q = 1
 * the maximum). With all weights equal this is the classic "inverted CDF"
 * quantile (Hyndman & Fan 1996, definition 1). Values with weight 0 are
 * ignored; NaN values are an error.
 *
 * Failure: RL_ERR_INVALID_ARG for NULL arrays, n = 0, a NaN or infinite
 * value, a negative or non-finite weight, total weight 0, q outside [0, 1].
 * Outputs stay untouched on failure. */
#ifndef RL_STATS_H
#define RL_STATS_H

#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_STATS_QUANTILES 5

typedef struct rl_stats {
    size_t count;                     /* values with weight > 0 */
    double total_weight;
    double min, max;
    double mean;                      /* weighted */
    double stddev;                    /* weighted population standard deviation */
    /* Weighted quantiles at 0, 0.25, 0.5, 0.75, 1 (q[2] = median). */
    double q[RL_STATS_QUANTILES];
} rl_stats;

/* weights may be NULL (all 1). */
RL_API rl_status rl_stats_compute(const double *values, const double *weights, size_t n,
                                  rl_stats *out);
/* Several quantiles at once (qs ascending or not), one sort; nq >= 1. */
RL_API rl_status rl_stats_quantiles(const double *values, const double *weights, size_t n,
                                    const double *qs, size_t nq, double *out);

/* Gaussian kernel density estimate of the weighted values at m points xs.
 * bandwidth <= 0 chooses Silverman's rule of thumb
 *     h = 0.9 * min(sd, IQR / 1.34) * n_eff^(-1/5)
 * with n_eff = W^2 / sum(w^2) (Kish's effective sample size); when the IQR
 * is 0 the min is replaced by sd, and for constant data (sd = 0)
 * h = 1e-3 * max(1, |mean|). sd is the weighted population standard
 * deviation, IQR the difference of the weighted quartiles defined above.
 * The density integrates to 1 over the real line. *used_bandwidth may be
 * NULL. Also RL_ERR_INVALID_ARG for xs or density NULL, m = 0, a
 * non-finite xs or bandwidth. */
RL_API rl_status rl_stats_kde(const double *values, const double *weights, size_t n,
                              double bandwidth, const double *xs, size_t m, double *density,
                              double *used_bandwidth);

/* Pearson correlation of x and y (n >= 2); RL_ERR_INVALID_ARG when either
 * is constant. */
RL_API rl_status rl_stats_correlation(const double *x, const double *y, size_t n, double *r);

#ifdef __cplusplus
}
#endif
#endif
