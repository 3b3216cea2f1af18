/* test_rng_gpu.c: the GPU generators of Schröder 2017, Sec. 5.3 (LCG,
 * combined Tausworthe, hybrid): uniform by a chi-square test, mean 1/2,
 * floats in [0,1), the LCG step against its formula, Tausworthe seeds above
 * 128, and exact repetition for the same seed and stream. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "rl/rl_rng.h"

#define DRAWS 1000000
#define BINS 64
/* 63 degrees of freedom: mean 63, sd sqrt(126) ~ 11.2; 120 is ~5 sd, a
 * false alarm about once in a million runs (the seeds are fixed anyway). */
#define CHI2_LIMIT 120.0

static void check_uniform(rl_rng_gpu_kind kind)
{
    rl_rng_gpu g;
    rl_rng_gpu_seed(&g, kind, 2017, 7);
    static unsigned bins[BINS];
    for (int b = 0; b < BINS; ++b)
        bins[b] = 0;
    double sum = 0.0;
    for (int i = 0; i < DRAWS; ++i) {
        float x = rl_rng_gpu_float(&g);
        assert_true(x >= 0.0f && x < 1.0f);
        sum += x;
        bins[(int)(x * BINS)]++;
    }
    double expected = (double)DRAWS / BINS, chi2 = 0.0;
    for (int b = 0; b < BINS; ++b)
        chi2 += ((double)bins[b] - expected) * ((double)bins[b] - expected) / expected;
    assert_true(chi2 < CHI2_LIMIT);
    double mean = sum / DRAWS;
    assert_true(mean > 0.499 && mean < 0.501);
}

static void test_lcg_is_uniform(void **state)
{
    (void)state;
    check_uniform(RL_RNG_GPU_LCG);
}

static void test_tausworthe_is_uniform(void **state)
{
    (void)state;
    check_uniform(RL_RNG_GPU_TAUSWORTHE);
}

static void test_hybrid_is_uniform(void **state)
{
    (void)state;
    check_uniform(RL_RNG_GPU_HYBRID);
}

static void test_lcg_follows_numerical_recipes(void **state)
{
    (void)state;
    rl_rng_gpu g;
    rl_rng_gpu_seed(&g, RL_RNG_GPU_LCG, 1, 2);
    uint32_t x = g.z[3];
    for (int i = 0; i < 100; ++i) {
        x = 1664525u * x + 1013904223u;
        assert_int_equal(rl_rng_gpu_u32(&g), x);
    }
}

static void test_seeding_keeps_tausworthe_states_above_128(void **state)
{
    (void)state;
    for (uint64_t stream = 0; stream < 10000; ++stream) {
        rl_rng_gpu g;
        rl_rng_gpu_seed(&g, RL_RNG_GPU_HYBRID, 3, stream);
        for (int i = 0; i < 3; ++i)
            assert_true(g.z[i] > 128u);
    }
}

static void test_same_seed_repeats_and_streams_differ(void **state)
{
    (void)state;
    for (int k = 0; k < RL_RNG_GPU_KIND_COUNT; ++k) {
        rl_rng_gpu a, b, c;
        rl_rng_gpu_seed(&a, (rl_rng_gpu_kind)k, 99, 5);
        rl_rng_gpu_seed(&b, (rl_rng_gpu_kind)k, 99, 5);
        rl_rng_gpu_seed(&c, (rl_rng_gpu_kind)k, 99, 6);
        int same = 0;
        for (int i = 0; i < 1000; ++i) {
            uint32_t x = rl_rng_gpu_u32(&a);
            assert_int_equal(x, rl_rng_gpu_u32(&b));
            same += x == rl_rng_gpu_u32(&c);
        }
        assert_true(same < 5);
    }
}

static void test_kinds_have_names(void **state)
{
    (void)state;
    assert_string_equal(rl_rng_gpu_kind_name(RL_RNG_GPU_LCG), "lcg");
    assert_string_equal(rl_rng_gpu_kind_name(RL_RNG_GPU_TAUSWORTHE), "tausworthe");
    assert_string_equal(rl_rng_gpu_kind_name(RL_RNG_GPU_HYBRID), "hybrid");
    assert_string_equal(rl_rng_gpu_kind_name(RL_RNG_GPU_KIND_COUNT), "unknown");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lcg_is_uniform),
        cmocka_unit_test(test_tausworthe_is_uniform),
        cmocka_unit_test(test_hybrid_is_uniform),
        cmocka_unit_test(test_lcg_follows_numerical_recipes),
        cmocka_unit_test(test_seeding_keeps_tausworthe_states_above_128),
        cmocka_unit_test(test_same_seed_repeats_and_streams_differ),
        cmocka_unit_test(test_kinds_have_names),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
