/* rng.c: PCG32 random numbers (O'Neill 2014, "PCG: A family of simple fast
 * space-efficient statistically good algorithms for random number
 * generation"): 64-bit LCG state, XSH RR output permutation to 32 bits.
 * Seeding follows the reference pcg32_srandom_r(initstate=seed,
 * initseq=stream) so sequences match the published demo output. Bounded
 * integers use Lemire's multiply-shift with rejection (Lemire 2019, "Fast
 * random integer generation in an interval"), which has no modulo bias.
 * Jump-ahead is Brown 1994, "Random number generation with arbitrary
 * strides". */
#include "core/hash.h"
#include "rl/rl_rng.h"

#define PCG_MULT 6364136223846793005ULL

static void step(rl_rng *rng) { rng->state = rng->state * PCG_MULT + rng->inc; }

void rl_rng_seed(rl_rng *rng, uint64_t seed, uint64_t stream)
{
    /* The increment must be odd for the LCG to have full period. */
    rng->state = 0;
    rng->inc = (stream << 1) | 1u;
    step(rng);
    rng->state += seed;
    step(rng);
}

uint32_t rl_rng_u32(rl_rng *rng)
{
    uint64_t old = rng->state;
    step(rng);
    /* XSH RR: xorshift the high bits down, then rotate by the top 5 bits. */
    uint32_t xorshifted = (uint32_t)(((old >> 18) ^ old) >> 27);
    uint32_t rot = (uint32_t)(old >> 59);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
}

uint32_t rl_rng_bounded(rl_rng *rng, uint32_t bound)
{
    if (bound == 0)
        return 0;
    /* Lemire: the high word of x*bound is uniform once the low words that
     * fall in the short first interval (below 2^32 mod bound) are rejected. */
    uint64_t m = (uint64_t)rl_rng_u32(rng) * bound;
    uint32_t low = (uint32_t)m;
    if (low < bound) {
        uint32_t threshold = (uint32_t)(-bound) % bound;
        while (low < threshold) {
            m = (uint64_t)rl_rng_u32(rng) * bound;
            low = (uint32_t)m;
        }
    }
    return (uint32_t)(m >> 32);
}

float rl_rng_float(rl_rng *rng)
{
    /* 24 bits fill the float mantissa exactly, so the result is < 1. */
    return (float)(rl_rng_u32(rng) >> 8) * 0x1.0p-24f;
}

double rl_rng_double(rl_rng *rng)
{
    uint64_t hi = rl_rng_u32(rng) >> 5;   /* 27 bits */
    uint64_t lo = rl_rng_u32(rng) >> 6;   /* 26 bits */
    return (double)((hi << 26) | lo) * 0x1.0p-53;
}

void rl_rng_advance(rl_rng *rng, uint64_t delta)
{
    /* Brown 1994: compose the affine map x -> a*x + c with itself by
     * repeated squaring, applying it for each set bit of delta. */
    uint64_t cur_mult = PCG_MULT, cur_plus = rng->inc;
    uint64_t acc_mult = 1, acc_plus = 0;
    while (delta > 0) {
        if (delta & 1) {
            acc_mult *= cur_mult;
            acc_plus = acc_plus * cur_mult + cur_plus;
        }
        cur_plus = (cur_mult + 1) * cur_plus;
        cur_mult *= cur_mult;
        delta >>= 1;
    }
    rng->state = acc_mult * rng->state + acc_plus;
}

uint64_t rl_hash64(uint64_t x)
{
    return rl_splitmix64(x);
}
