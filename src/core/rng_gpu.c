/* rng_gpu.c: the GPU random number generators of Schröder 2017, Sec. 5.3
 * (see rl_rng.h): a 32-bit LCG (Alg. 1, constants of Press et al. 1992), the
 * combined Tausworthe generator (Alg. 2, L'Ecuyer 1996) and their hybrid
 * from GPU Gems 3, Ch. 37 (Nguyen 2007), which the thesis uses.
 *
 * Why the seeding matters: a Tausworthe component with a state below 2^k
 * for its k (k = 1, 3, 4 bits masked off by M, i.e. states <= 128 are the
 * unsafe ones GPU Gems names) degenerates, so each component is redrawn
 * from PCG32 until it exceeds 128. */
#include "rl/rl_rng.h"

#define LCG_A 1664525u
#define LCG_C 1013904223u
#define TO_UNIT 2.3283064365387e-10       /* 2^-32, GPU Gems 3, Ch. 37 */
#define TAUS_MIN_STATE 128u

/* Schröder 2017, Alg. 1: the modulo 2^32 is the unsigned overflow. */
static uint32_t lcg_step(uint32_t x)
{
    return LCG_A * x + LCG_C;
}

/* Schröder 2017, Alg. 2: one Tausworthe component. */
static uint32_t ctg_step(uint32_t x, int s1, int s2, int s3, uint32_t m)
{
    uint32_t a = ((x << s1) ^ x) >> s2;
    return ((x & m) << s3) ^ a;
}

const char *rl_rng_gpu_kind_name(rl_rng_gpu_kind kind)
{
    static const char *const names[RL_RNG_GPU_KIND_COUNT] = { "lcg", "tausworthe", "hybrid" };
    return (unsigned)kind < RL_RNG_GPU_KIND_COUNT ? names[kind] : "unknown";
}

void rl_rng_gpu_seed(rl_rng_gpu *g, rl_rng_gpu_kind kind, uint64_t seed, uint64_t stream)
{
    rl_rng pcg;
    rl_rng_seed(&pcg, rl_hash64(seed), stream);
    for (int i = 0; i < 3; ++i) {
        uint32_t z;
        do
            z = rl_rng_u32(&pcg);
        while (z <= TAUS_MIN_STATE);
        g->z[i] = z;
    }
    g->z[3] = rl_rng_u32(&pcg);
    g->kind = (unsigned)kind < RL_RNG_GPU_KIND_COUNT ? kind : RL_RNG_GPU_HYBRID;
}

uint32_t rl_rng_gpu_u32(rl_rng_gpu *g)
{
    if (g->kind == RL_RNG_GPU_LCG)
        return g->z[3] = lcg_step(g->z[3]);
    /* The three components of GPU Gems 3, Ch. 37 (L'Ecuyer's taus88). */
    g->z[0] = ctg_step(g->z[0], 13, 19, 12, 4294967294u);
    g->z[1] = ctg_step(g->z[1], 2, 25, 4, 4294967288u);
    g->z[2] = ctg_step(g->z[2], 3, 11, 17, 4294967280u);
    uint32_t x = g->z[0] ^ g->z[1] ^ g->z[2];
    if (g->kind == RL_RNG_GPU_HYBRID)
        x ^= g->z[3] = lcg_step(g->z[3]);
    return x;
}

float rl_rng_gpu_float(rl_rng_gpu *g)
{
    /* In double the product is < 1, but outputs above 2^32 - 2^7 round to
     * 1.0f; path sampling needs [0,1), so clamp to the float below 1. */
    float f = (float)(TO_UNIT * (double)rl_rng_gpu_u32(g));
    return f < 1.0f ? f : 0x1.fffffep-1f;
}
