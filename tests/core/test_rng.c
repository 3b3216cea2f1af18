/* test_rng.c: PCG32 against the reference demo output, reproducibility,
 * stream independence, unbiased bounded integers and jump-ahead. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "rl/rl_rng.h"

static void test_seed_42_stream_54_matches_pcg_reference_output(void **state)
{
    (void)state;
    /* pcg32-demo: pcg32_srandom_r(&rng, 42u, 54u) then six pcg32_random_r. */
    static const uint32_t expected[] = { 0xa15c02b7, 0x7b47f409, 0xba1d3330,
                                         0x83d2f293, 0xbfa4784b, 0xcbed606e };
    rl_rng rng;
    rl_rng_seed(&rng, 42, 54);
    for (int i = 0; i < 6; ++i)
        assert_int_equal(rl_rng_u32(&rng), expected[i]);
}

static void test_same_seed_and_stream_repeat_the_sequence(void **state)
{
    (void)state;
    rl_rng a, b;
    rl_rng_seed(&a, 1234, 5);
    rl_rng_seed(&b, 1234, 5);
    for (int i = 0; i < 1000; ++i)
        assert_int_equal(rl_rng_u32(&a), rl_rng_u32(&b));
}

static void test_different_streams_give_different_sequences(void **state)
{
    (void)state;
    rl_rng a, b;
    rl_rng_seed(&a, 1234, 5);
    rl_rng_seed(&b, 1234, 6);
    int same = 0;
    for (int i = 0; i < 1000; ++i)
        same += rl_rng_u32(&a) == rl_rng_u32(&b);
    assert_true(same < 3);
}

static void test_bounded_stays_in_range_and_is_roughly_uniform(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 99, 1);
    enum { BINS = 7, N = 70000 };
    int count[BINS] = { 0 };
    for (int i = 0; i < N; ++i) {
        uint32_t v = rl_rng_bounded(&rng, BINS);
        assert_true(v < BINS);
        count[v]++;
    }
    /* Chi-square with 6 degrees of freedom: 22.5 is p ~ 0.001. */
    double chi2 = 0, e = (double)N / BINS;
    for (int k = 0; k < BINS; ++k)
        chi2 += (count[k] - e) * (count[k] - e) / e;
    assert_true(chi2 < 22.5);
    assert_int_equal(rl_rng_bounded(&rng, 0), 0);
    assert_int_equal(rl_rng_bounded(&rng, 1), 0);
    /* A bound just above 2^31 is where modulo bias would be largest. */
    uint32_t big = 0x80000001u;
    int upper = 0;
    for (int i = 0; i < 10000; ++i) {
        uint32_t v = rl_rng_bounded(&rng, big);
        assert_true(v < big);
        upper += v >= big / 2;
    }
    assert_true(upper > 4700 && upper < 5300);
}

static void test_advance_equals_stepping(void **state)
{
    (void)state;
    rl_rng a, b;
    rl_rng_seed(&a, 7, 3);
    b = a;
    for (int i = 0; i < 12345; ++i)
        rl_rng_u32(&a);
    rl_rng_advance(&b, 12345);
    assert_true(a.state == b.state && a.inc == b.inc);
    assert_int_equal(rl_rng_u32(&a), rl_rng_u32(&b));
    /* Advancing by 2^64 - 1 then 1 is a full period: back to the start. */
    rl_rng c = b;
    rl_rng_advance(&c, UINT64_MAX);
    rl_rng_advance(&c, 1);
    assert_true(c.state == b.state);
    rl_rng_advance(&c, 0);
    assert_true(c.state == b.state);
}

static void test_float_and_double_are_in_unit_interval(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 1, 1);
    double sum = 0;
    for (int i = 0; i < 100000; ++i) {
        float f = rl_rng_float(&rng);
        double d = rl_rng_double(&rng);
        assert_true(f >= 0.0f && f < 1.0f);
        assert_true(d >= 0.0 && d < 1.0);
        sum += f;
    }
    assert_true(sum / 100000 > 0.49 && sum / 100000 < 0.51);
    /* The largest possible draw (all 24 bits set) must still be below one. */
    assert_true((float)(0xFFFFFFu) * 0x1.0p-24f < 1.0f);
}

static void test_hash64_mixes_neighbouring_inputs(void **state)
{
    (void)state;
    assert_true(rl_hash64(0) != 0);
    assert_true(rl_hash64(1) != rl_hash64(2));
    /* Avalanche: flipping one input bit flips about half the output bits. */
    int total = 0;
    for (uint64_t x = 0; x < 64; ++x)
        total += __builtin_popcountll(rl_hash64(x) ^ rl_hash64(x ^ 1));
    assert_true(total > 64 * 24 && total < 64 * 40);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_seed_42_stream_54_matches_pcg_reference_output),
        cmocka_unit_test(test_same_seed_and_stream_repeat_the_sequence),
        cmocka_unit_test(test_different_streams_give_different_sequences),
        cmocka_unit_test(test_bounded_stays_in_range_and_is_roughly_uniform),
        cmocka_unit_test(test_advance_equals_stepping),
        cmocka_unit_test(test_float_and_double_are_in_unit_interval),
        cmocka_unit_test(test_hash64_mixes_neighbouring_inputs),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
