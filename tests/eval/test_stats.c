/* test_stats.c: weighted statistics (src/eval/stats.c) against values
 * computed by hand: inverted-CDF quantiles, weighted moments, Silverman's
 * bandwidth; the KDE integrates to one and is symmetric; bad input leaves
 * the outputs untouched. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl_stats.h"

#define assert_near(a, b, eps)                                                       \
    do {                                                                             \
        double a_ = (a), b_ = (b);                                                   \
        if (!(fabs(a_ - b_) <= (eps)))                                               \
            fail_msg("%.17g != %.17g (eps %g)", a_, b_, (double)(eps));              \
    } while (0)

static void test_unweighted_quantiles_follow_the_inverted_cdf(void **state)
{
    (void)state;
    const double v[] = { 3, 1, 2, 4 };
    rl_stats s;
    assert_int_equal(rl_stats_compute(v, NULL, 4, &s), RL_OK);
    assert_near(s.q[0], 1, 0);
    assert_near(s.q[1], 1, 0);
    assert_near(s.q[2], 2, 0);
    assert_near(s.q[3], 3, 0);
    assert_near(s.q[4], 4, 0);
    assert_near(s.min, 1, 0);
    assert_near(s.max, 4, 0);
    assert_int_equal(s.count, 4);
    assert_near(s.total_weight, 4, 0);
    assert_near(s.mean, 2.5, 1e-15);
    assert_near(s.stddev, sqrt(1.25), 1e-15); /* (2.25 + 0.25 + 0.25 + 2.25) / 4 */

    /* Any order of qs, one answer each; 0.3 of ten unit weights is the 3rd. */
    const double w[] = { 1, 2, 3, 4, 5, 6, 7, 8, 9, 10 };
    const double qs[] = { 1.0, 0.3, 0.0, 0.31, 0.5 };
    double q[5];
    assert_int_equal(rl_stats_quantiles(w, NULL, 10, qs, 5, q), RL_OK);
    assert_near(q[0], 10, 0);
    assert_near(q[1], 3, 0);
    assert_near(q[2], 1, 0);
    assert_near(q[3], 4, 0);
    assert_near(q[4], 5, 0);
}

static void test_heavy_value_dominates_weighted_quantiles(void **state)
{
    (void)state;
    /* Values 1, 2, 3 with weights 1, 1, 8: C = 1, 2, 10 of W = 10. */
    const double v[] = { 3, 1, 2 };
    const double w[] = { 8, 1, 1 };
    rl_stats s;
    assert_int_equal(rl_stats_compute(v, w, 3, &s), RL_OK);
    assert_near(s.q[0], 1, 0);
    assert_near(s.q[1], 3, 0); /* C >= 2.5 first at the 3 */
    assert_near(s.q[2], 3, 0);
    assert_near(s.q[4], 3, 0);
    assert_near(s.mean, 2.7, 1e-15);            /* (1 + 2 + 24) / 10 */
    assert_near(s.stddev, sqrt(0.41), 1e-15);   /* (1.7^2 + 0.7^2 + 8 * 0.3^2) / 10 */
    const double qs[] = { 0.1, 0.2, 0.21 };
    double q[3];
    assert_int_equal(rl_stats_quantiles(v, w, 3, qs, 3, q), RL_OK);
    assert_near(q[0], 1, 0);
    assert_near(q[1], 2, 0);
    assert_near(q[2], 3, 0);
}

static void test_zero_weights_are_ignored(void **state)
{
    (void)state;
    const double v[] = { 100, 1, 2, -50 };
    const double w[] = { 0, 1, 1, 0 };
    rl_stats s;
    assert_int_equal(rl_stats_compute(v, w, 4, &s), RL_OK);
    assert_int_equal(s.count, 2);
    assert_near(s.min, 1, 0);
    assert_near(s.max, 2, 0);
    assert_near(s.mean, 1.5, 0);
    assert_near(s.stddev, 0.5, 1e-15);
    assert_near(s.q[4], 2, 0);
    assert_near(s.q[0], 1, 0);
}

static void test_bad_input_leaves_outputs_untouched(void **state)
{
    (void)state;
    const double v[] = { 1, 2, 3 };
    const double nan_v[] = { 1, NAN, 3 };
    const double neg_w[] = { 1, -1, 1 };
    const double zero_w[] = { 0, 0, 0 };
    const double inf_w[] = { 1, INFINITY, 1 };
    rl_stats s, sentinel;
    memset(&sentinel, 0xA5, sizeof sentinel);
    memcpy(&s, &sentinel, sizeof s);
    assert_int_equal(rl_stats_compute(v, NULL, 0, &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_compute(NULL, NULL, 3, &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_compute(nan_v, NULL, 3, &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_compute(v, neg_w, 3, &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_compute(v, zero_w, 3, &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_compute(v, inf_w, 3, &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_compute(v, NULL, 3, NULL), RL_ERR_INVALID_ARG);
    assert_memory_equal(&s, &sentinel, sizeof s);

    double q[2] = { -7, -7 };
    const double bad_q[] = { 0.5, 1.5 };
    const double neg_q[] = { -0.1 };
    const double nan_q[] = { NAN };
    assert_int_equal(rl_stats_quantiles(v, NULL, 3, bad_q, 2, q), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_quantiles(v, NULL, 3, neg_q, 1, q), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_quantiles(v, NULL, 3, nan_q, 1, q), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_quantiles(nan_v, NULL, 3, bad_q, 1, q), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_quantiles(v, zero_w, 3, bad_q, 1, q), RL_ERR_INVALID_ARG);
    assert_near(q[0], -7, 0);
    assert_near(q[1], -7, 0);

    double xs[2] = { 0, 1 }, d[2] = { -7, -7 }, h = -7;
    assert_int_equal(rl_stats_kde(v, NULL, 0, 0, xs, 2, d, &h), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_kde(nan_v, NULL, 3, 0, xs, 2, d, &h), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_kde(v, neg_w, 3, 0, xs, 2, d, &h), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_kde(v, NULL, 3, NAN, xs, 2, d, &h), RL_ERR_INVALID_ARG);
    assert_near(d[0], -7, 0);
    assert_near(h, -7, 0);

    const double c[] = { 5, 5, 5 };
    double r = -7;
    assert_int_equal(rl_stats_correlation(v, c, 3, &r), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_correlation(c, v, 3, &r), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_correlation(v, v, 1, &r), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_stats_correlation(v, nan_v, 3, &r), RL_ERR_INVALID_ARG);
    assert_near(r, -7, 0);
}

static double trapezoid(const double *x, const double *y, size_t n)
{
    double s = 0.0;
    for (size_t i = 1; i < n; ++i)
        s += 0.5 * (y[i] + y[i - 1]) * (x[i] - x[i - 1]);
    return s;
}

enum { GRID = 4501 };

static void test_kde_integrates_to_one(void **state)
{
    (void)state;
    const double v[] = { 0, 1, 5, 5.5, 12 };
    const double w[] = { 1, 2, 0.5, 3, 1 };
    static double xs[GRID], d[GRID];
    for (int i = 0; i < GRID; ++i)
        xs[i] = -30.0 + 75.0 * i / (GRID - 1);
    double h = 0;
    assert_int_equal(rl_stats_kde(v, w, 5, 0, xs, GRID, d, &h), RL_OK);
    assert_true(h > 0);
    assert_near(trapezoid(xs, d, GRID), 1.0, 1e-6);
    assert_int_equal(rl_stats_kde(v, NULL, 5, 0.3, xs, GRID, d, &h), RL_OK);
    assert_near(h, 0.3, 0);
    assert_near(trapezoid(xs, d, GRID), 1.0, 1e-6);
}

static void test_kde_is_symmetric_for_symmetric_data(void **state)
{
    (void)state;
    const double v[] = { -2, -1, -1, 0, 1, 1, 2 };
    double xs[41], d[41];
    for (int i = 0; i < 41; ++i)
        xs[i] = -4.0 + 0.2 * i;
    assert_int_equal(rl_stats_kde(v, NULL, 7, 0, xs, 41, d, NULL), RL_OK);
    for (int i = 0; i < 41; ++i)
        assert_near(d[i], d[40 - i], 1e-14);
}

static void test_silverman_bandwidth_matches_hand_value(void **state)
{
    (void)state;
    /* 1..5: sd = sqrt(2) = 1.41421, IQR = 4 - 2 = 2, 2 / 1.34 = 1.49254, so
     * h = 0.9 * 1.41421 * 5^(-1/5) = 0.922494. */
    const double v[] = { 1, 2, 3, 4, 5 };
    double x = 0, d, h;
    assert_int_equal(rl_stats_kde(v, NULL, 5, 0, &x, 1, &d, &h), RL_OK);
    assert_near(h, 0.9224939070946869, 1e-12);
    /* Equal weights of any size: n_eff stays 5. */
    const double w[] = { 3, 3, 3, 3, 3 };
    assert_int_equal(rl_stats_kde(v, w, 5, 0, &x, 1, &d, &h), RL_OK);
    assert_near(h, 0.9224939070946869, 1e-12);
    /* An outlier inflates sd; IQR / 1.34 = (3 - 1) / 1.34 wins. */
    const double o[] = { 0, 1, 2, 3, 100 };
    assert_int_equal(rl_stats_kde(o, NULL, 5, 0, &x, 1, &d, &h), RL_OK);
    assert_near(h, 0.9735846228506357, 1e-12); /* 0.9 * 1.49254 * 0.72478 */
    const double c[] = { 4, 4, 4, 4 };
    assert_int_equal(rl_stats_kde(c, NULL, 4, 0, &x, 1, &d, &h), RL_OK);
    assert_near(h, 4e-3, 1e-15); /* constant: 1e-3 * max(1, |mean|) */
}

static void test_weights_shift_the_mode(void **state)
{
    (void)state;
    const double v[] = { 0, 10 };
    const double w[] = { 1, 3 };
    double xs[201], d[201];
    for (int i = 0; i < 201; ++i)
        xs[i] = -5.0 + 0.1 * i;
    assert_int_equal(rl_stats_kde(v, w, 2, 1.0, xs, 201, d, NULL), RL_OK);
    int mode = 0;
    for (int i = 1; i < 201; ++i)
        if (d[i] > d[mode])
            mode = i;
    assert_near(xs[mode], 10.0, 1e-9);
    assert_near(d[50] / d[150], 1.0 / 3.0, 1e-9); /* peaks of 1/4 and 3/4 mass */
}

static void test_correlation_of_linear_data_is_one(void **state)
{
    (void)state;
    double x[20], y[20], z[20];
    for (int i = 0; i < 20; ++i) {
        x[i] = i * 0.37 - 2;
        y[i] = 2 * x[i] + 1;
        z[i] = -3 * x[i] + 4;
    }
    double r = 0;
    assert_int_equal(rl_stats_correlation(x, y, 20, &r), RL_OK);
    assert_near(r, 1.0, 1e-12);
    assert_int_equal(rl_stats_correlation(x, z, 20, &r), RL_OK);
    assert_near(r, -1.0, 1e-12);
    const double a[] = { 1, 2, 3, 4 }, b[] = { 1, 3, 2, 4 };
    assert_int_equal(rl_stats_correlation(a, b, 4, &r), RL_OK);
    assert_near(r, 0.8, 1e-12); /* sxy = 4, sxx = syy = 5 */
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_unweighted_quantiles_follow_the_inverted_cdf),
        cmocka_unit_test(test_heavy_value_dominates_weighted_quantiles),
        cmocka_unit_test(test_zero_weights_are_ignored),
        cmocka_unit_test(test_bad_input_leaves_outputs_untouched),
        cmocka_unit_test(test_kde_integrates_to_one),
        cmocka_unit_test(test_kde_is_symmetric_for_symmetric_data),
        cmocka_unit_test(test_silverman_bandwidth_matches_hand_value),
        cmocka_unit_test(test_weights_shift_the_mode),
        cmocka_unit_test(test_correlation_of_linear_data_is_one),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
