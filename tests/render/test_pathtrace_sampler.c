/* test_pathtrace_sampler.c: the Owen-scrambled Sobol sampler of "pt"
 * (pathtrace_sampler.c): the scramble is nested (an output's leading bits
 * depend on the input's leading bits only) and a bijection, the first 2^m
 * samples of every 2D slot of every pixel form a (0,m,2)-net (one point in
 * each elementary interval of area 2^-m), 1D slots are stratified,
 * pixels and slots are decorrelated, and the draws equal their
 * straightforward evaluation. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/pathtrace_internal.h"

static uint32_t next_u32(uint64_t *state)
{
    *state = *state * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*state >> 32);
}

static void test_owen_scramble_is_nested(void **state)
{
    (void)state;
    uint64_t g = 7;
    for (int trial = 0; trial < 2000; ++trial) {
        uint32_t seed = next_u32(&g), x = next_u32(&g), y = next_u32(&g);
        int k = trial % 32;
        /* y shares x's leading k bits: so must their scrambles. */
        uint32_t mask = k ? ~0u << (32 - k) : 0u;
        y = (x & mask) | (y & ~mask);
        uint32_t sx = rl_pt_owen_scramble(x, seed), sy = rl_pt_owen_scramble(y, seed);
        assert_int_equal(sx & mask, sy & mask);
    }
}

static void test_owen_scramble_permutes_every_prefix_block(void **state)
{
    (void)state;
    /* The 2^12 values with the same leading 20 bits map onto 2^12 values
     * with a common leading 20 bits, each once: a bijection. */
    enum { BITS = 12, N = 1 << BITS };
    static unsigned char seen[N];
    uint64_t g = 11;
    for (int trial = 0; trial < 8; ++trial) {
        uint32_t seed = next_u32(&g), high = next_u32(&g) & ~(uint32_t)(N - 1);
        memset(seen, 0, sizeof seen);
        uint32_t lead = rl_pt_owen_scramble(high, seed) & ~(uint32_t)(N - 1);
        for (uint32_t i = 0; i < N; ++i) {
            uint32_t s = rl_pt_owen_scramble(high | i, seed);
            assert_int_equal(s & ~(uint32_t)(N - 1), lead);
            assert_int_equal(seen[s & (N - 1)], 0);
            seen[s & (N - 1)] = 1;
        }
    }
}

/* Whether n = 2^m points form a (0,m,2)-net: for every split m = a + b,
 * each of the 2^a x 2^b boxes holds exactly one point. */
static void assert_net(const rl_vec2 *p, int m)
{
    int n = 1 << m;
    int *count = calloc((size_t)n, sizeof *count);
    assert_non_null(count);
    for (int a = 0; a <= m; ++a) {
        memset(count, 0, (size_t)n * sizeof *count);
        for (int i = 0; i < n; ++i) {
            int cx = (int)(p[i].x * (float)(1 << a)), cy = (int)(p[i].y * (float)(1 << (m - a)));
            assert_true(cx >= 0 && cx < (1 << a) && cy >= 0 && cy < (1 << (m - a)));
            count[cx * (1 << (m - a)) + cy]++;
        }
        for (int c = 0; c < n; ++c)
            assert_int_equal(count[c], 1);
    }
    free(count);
}

static void test_every_2d_slot_is_a_net_in_every_pixel(void **state)
{
    (void)state;
    enum { M = 8, N = 1 << M };
    rl_vec2 p[N];
    for (uint32_t pixel = 0; pixel < 6; ++pixel) {
        uint32_t seed = rl_pt_pixel_seed(3, pixel);
        for (uint32_t slot = 0; slot < 40; slot += 3) {
            for (int m = 1; m <= M; ++m) {
                for (uint32_t i = 0; i < (1u << m); ++i) {
                    pt_sampler sp;
                    rl_pt_sampler_init(&sp, NULL, seed, i);
                    rl_pt_sampler_seek(&sp, slot);
                    p[i] = rl_pt_sample_2d(&sp);
                }
                assert_net(p, m);
            }
        }
    }
}

static void test_1d_slots_are_stratified(void **state)
{
    (void)state;
    enum { N = 64 };
    for (uint32_t slot = 1; slot < 30; ++slot) {
        int count[N] = { 0 };
        for (uint32_t i = 0; i < N; ++i) {
            pt_sampler sp;
            rl_pt_sampler_init(&sp, NULL, rl_pt_pixel_seed(0, 99), i);
            rl_pt_sampler_seek(&sp, slot);
            float u = rl_pt_sample_1d(&sp);
            assert_true(u >= 0.0f && u < 1.0f);
            count[(int)(u * N)]++;
        }
        for (int k = 0; k < N; ++k)
            assert_int_equal(count[k], 1);
    }
}

static void test_pixels_and_slots_are_decorrelated(void **state)
{
    (void)state;
    /* Sample 0 of many pixels: uniform over [0,1) (mean 1/2, variance
     * 1/12), and two slots of the same pixel uncorrelated. A sampler that
     * forgot the pixel or the slot repeats one value. */
    enum { PIXELS = 20000 };
    double sum = 0.0, sum2 = 0.0, cross = 0.0, sum_b = 0.0;
    for (uint32_t pixel = 0; pixel < PIXELS; ++pixel) {
        pt_sampler sp;
        rl_pt_sampler_init(&sp, NULL, rl_pt_pixel_seed(5, pixel), 0);
        rl_pt_sampler_seek(&sp, 4);
        double a = rl_pt_sample_1d(&sp);
        rl_pt_sampler_seek(&sp, 5);
        double b = rl_pt_sample_1d(&sp);
        sum += a;
        sum2 += a * a;
        sum_b += b;
        cross += a * b;
    }
    double mean = sum / PIXELS, var = sum2 / PIXELS - mean * mean;
    double cov = cross / PIXELS - mean * (sum_b / PIXELS);
    /* 5 sigma of the mean of 20000 uniforms: 5 * 0.289 / sqrt(20000) = 0.0102. */
    assert_true(fabs(mean - 0.5) < 0.0102);
    assert_true(fabs(var - 1.0 / 12.0) < 0.004);
    assert_true(fabs(cov) < 5.0 / 12.0 / sqrt(PIXELS));
}

static void test_gpu_generators_draw_in_call_order(void **state)
{
    (void)state;
    rl_rng_gpu a, b;
    rl_rng_gpu_seed(&a, RL_RNG_GPU_HYBRID, 4, 17);
    b = a;
    pt_sampler sp;
    rl_pt_sampler_init(&sp, &a, 0, 0);
    rl_pt_sampler_seek(&sp, 30);        /* ignored: the thesis' generators run in order */
    float x = rl_pt_sample_1d(&sp);
    rl_vec2 y = rl_pt_sample_2d(&sp);
    assert_true(x == rl_rng_gpu_float(&b));
    assert_true(y.x == rl_rng_gpu_float(&b));
    assert_true(y.y == rl_rng_gpu_float(&b));
}

/* The straightforward evaluations the sampler's shortcuts must agree with,
 * bit for bit (pathtrace_sampler.c): Sobol's second dimension by its
 * direction numbers, one XOR per set index bit, and each draw as the
 * composition it stands for. */
static uint32_t sobol_dim1_by_directions(uint32_t i)
{
    uint32_t v = 0x80000000u, r = 0;
    for (int k = 0; k < 24; ++k, v ^= v >> 1)
        if (i >> k & 1u)
            r ^= v;
    return r;
}

static uint32_t reversed(uint32_t x)
{
    uint32_t r = 0;
    for (int k = 0; k < 32; ++k)
        r |= (x >> k & 1u) << (31 - k);
    return r;
}

static float unit24(uint32_t x)
{
    return (float)(x >> 8) * (1.0f / 16777216.0f);
}

static void test_sobol_dim1_matches_its_direction_numbers(void **state)
{
    (void)state;
    /* Every index below 2^16, then random ones, whose bits from the 25th
     * on must not count. */
    for (uint32_t i = 0; i < 65536; ++i)
        assert_int_equal(rl_pt_sobol_dim1(i), sobol_dim1_by_directions(i));
    uint64_t g = 23;
    for (int k = 0; k < 100000; ++k) {
        uint32_t i = next_u32(&g);
        assert_int_equal(rl_pt_sobol_dim1(i), sobol_dim1_by_directions(i));
    }
    assert_int_equal(rl_pt_sobol_dim1(1u << 23), 0xff00ff00u);   /* the 24th direction number */
}

static void test_draws_match_the_straightforward_evaluation(void **state)
{
    (void)state;
    for (uint32_t pixel = 0; pixel < 4; ++pixel) {
        uint32_t seed = rl_pt_pixel_seed(9, pixel * 1237u);
        /* The sampler's own copy of the hash is rl_hash64's. */
        assert_int_equal(seed, (uint32_t)(rl_hash64(rl_hash64(9) ^ (pixel * 1237ull * 0x9e3779b97f4a7c15ull)) >> 32));
        for (uint32_t index = 0; index < 300; index += 7) {
            for (uint32_t slot = 0; slot < 40; ++slot) {
                /* The slot's three scramble seeds, the shuffled index, and
                 * dimensions 0 (van der Corput: the reversed index) and 1. */
                uint64_t h = rl_hash64(((uint64_t)seed << 32) | slot);
                uint32_t s0 = (uint32_t)h, s1 = (uint32_t)(h >> 32);
                uint32_t s2 = (uint32_t)((h * 0xd1342543de82ef95ull) >> 32) ^ s0;
                uint32_t shuffled = rl_pt_owen_scramble(index, s0);
                float x = unit24(rl_pt_owen_scramble(reversed(shuffled), s1));
                float y = unit24(rl_pt_owen_scramble(sobol_dim1_by_directions(shuffled), s2));
                pt_sampler sp;
                rl_pt_sampler_init(&sp, NULL, seed, index);
                rl_pt_sampler_seek(&sp, slot);
                rl_vec2 p = rl_pt_sample_2d(&sp);
                assert_true(p.x == x && p.y == y);
                rl_pt_sampler_seek(&sp, slot);
                assert_true(rl_pt_sample_1d(&sp) == x);
            }
        }
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_owen_scramble_is_nested),
        cmocka_unit_test(test_owen_scramble_permutes_every_prefix_block),
        cmocka_unit_test(test_every_2d_slot_is_a_net_in_every_pixel),
        cmocka_unit_test(test_1d_slots_are_stratified),
        cmocka_unit_test(test_pixels_and_slots_are_decorrelated),
        cmocka_unit_test(test_gpu_generators_draw_in_call_order),
        cmocka_unit_test(test_sobol_dim1_matches_its_direction_numbers),
        cmocka_unit_test(test_draws_match_the_straightforward_evaluation),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
