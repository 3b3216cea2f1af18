/* test_dist_balance.c: the pre-compute balancer's cut (Ullmann 2003, Sec.
 * 4.3.3; src/dist/dist_balance.c): given per-face costs and rank speeds,
 * every rank's run of faces carries its speed's share of the summed cost,
 * within one face's cost at each end of the run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>

#include "dist/dist_balance.h"
#include "rl/rl_rng.h"

#define MAX_RANKS 8

/* Every item is in exactly one run, and rank r's cost is its share of the
 * total within the largest item's cost at each of its two cuts. */
static void check_cut(const double *cost, uint32_t n, const double *speed, size_t ranks)
{
    uint32_t count[MAX_RANKS];
    rl_dist_cut_by_cost(cost, n, speed, ranks, count);
    double total = 0.0, largest = 0.0, speeds = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        double c = cost ? cost[i] : 1.0;
        total += c;
        largest = c > largest ? c : largest;
    }
    for (size_t r = 0; r < ranks; ++r)
        speeds += speed[r];
    uint32_t at = 0;
    for (size_t r = 0; r < ranks; ++r) {
        double got = 0.0;
        for (uint32_t i = at; i < at + count[r]; ++i)
            got += cost ? cost[i] : 1.0;
        at += count[r];
        double want = total * speed[r] / speeds;
        if (speed[r] == 0.0)
            assert_int_equal(count[r], 0);
        if (!(fabs(got - want) <= 2.0 * largest + 1e-9))
            fail_msg("rank %zu: cost %.6g of %.6g, its share %.6g (largest item %.3g)", r, got, total, want,
                     largest);
    }
    assert_int_equal(at, n);
}

static void test_cost_shares(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 11, 0);
    enum { N = 5000 };
    double *cost = malloc(N * sizeof *cost);
    assert_non_null(cost);
    for (int round = 0; round < 40; ++round) {
        /* Mostly cheap faces with a few expensive runs, as a glass among
         * a table's flat faces. */
        for (uint32_t i = 0; i < N; ++i)
            cost[i] = 0.01 + (rl_rng_float(&rng) < 0.05f ? 5.0 * rl_rng_float(&rng) : 0.02 * rl_rng_float(&rng));
        size_t ranks = 1 + (size_t)(rl_rng_float(&rng) * MAX_RANKS) % MAX_RANKS;
        double speed[MAX_RANKS];
        for (size_t r = 0; r < ranks; ++r)
            speed[r] = 0.2 + 3.0 * rl_rng_float(&rng);
        check_cut(cost, N, speed, ranks);
    }
    free(cost);
}

static void test_skewed_costs(void **state)
{
    (void)state;
    /* 900 cheap faces, then 100 faces of 9 times the cost: half the cost
     * lies in the last 100, so with equal speeds the cut is at face 900,
     * not at 500 as by face count. */
    double cost[1000];
    for (int i = 0; i < 1000; ++i)
        cost[i] = i < 900 ? 1.0 : 9.0;
    const double speed[2] = { 1.0, 1.0 };
    uint32_t count[2];
    rl_dist_cut_by_cost(cost, 1000, speed, 2, count);
    assert_int_equal(count[0] + count[1], 1000);
    assert_int_equal(count[0], 900);
    check_cut(cost, 1000, speed, 2);
    /* Without costs (cost=faces) the faces themselves are shared. */
    const double speed3[3] = { 1.0, 2.0, 1.0 };
    uint32_t c3[3];
    rl_dist_cut_by_cost(NULL, 1000, speed3, 3, c3);
    assert_int_equal(c3[0], 250);
    assert_int_equal(c3[1], 500);
    assert_int_equal(c3[2], 250);
}

static void test_lost_and_unmeasured(void **state)
{
    (void)state;
    double cost[10];
    for (int i = 0; i < 10; ++i)
        cost[i] = 1.0 + i;
    /* A lost rank (speed 0) gets nothing, the others share all. */
    const double speed[3] = { 1.0, 0.0, 1.0 };
    uint32_t count[3];
    rl_dist_cut_by_cost(cost, 10, speed, 3, count);
    assert_int_equal(count[1], 0);
    assert_int_equal(count[0] + count[2], 10);
    check_cut(cost, 10, speed, 3);
    /* Nothing measured: equal shares; no items: nothing for anyone. */
    const double none[3] = { 0.0, 0.0, 0.0 };
    rl_dist_cut_by_cost(NULL, 9, none, 3, count);
    assert_int_equal(count[0], 3);
    assert_int_equal(count[1], 3);
    assert_int_equal(count[2], 3);
    rl_dist_cut_by_cost(cost, 0, speed, 3, count);
    assert_int_equal(count[0] + count[1] + count[2], 0);
    /* A bad estimate (negative, NaN) counts as free, never as a step back. */
    double bad[6] = { 1.0, -5.0, NAN, 1.0, 1.0, 1.0 };
    const double two[2] = { 1.0, 1.0 };
    uint32_t c2[2];
    rl_dist_cut_by_cost(bad, 6, two, 2, c2);
    assert_int_equal(c2[0] + c2[1], 6);
    assert_in_range(c2[0], 3, 5);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cost_shares),
        cmocka_unit_test(test_skewed_costs),
        cmocka_unit_test(test_lost_and_unmeasured),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
