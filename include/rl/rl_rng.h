/* rl_rng.h: seeded, reproducible random numbers (PCG32, O'Neill 2014).
 *
 * The generator state is a plain value passed explicitly: no globals, so two
 * threads with the same (seed, stream) produce the same sequence, and a
 * renderer seeds one generator per pixel and pass for deterministic output. */
#ifndef RL_RNG_H
#define RL_RNG_H

#include <stdint.h>
#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_rng { uint64_t state, inc; } rl_rng;

/* Seeds a generator; different streams give independent sequences. */
RL_API void rl_rng_seed(rl_rng *rng, uint64_t seed, uint64_t stream);
RL_API uint32_t rl_rng_u32(rl_rng *rng);
/* Uniform integer in [0, bound) without modulo bias; bound 0 returns 0. */
RL_API uint32_t rl_rng_bounded(rl_rng *rng, uint32_t bound);
/* Uniform float in [0,1), 24 random bits. */
RL_API float rl_rng_float(rl_rng *rng);
/* Uniform double in [0,1), 53 random bits. */
RL_API double rl_rng_double(rl_rng *rng);
/* Advances by delta steps in O(log delta) (Brown 1994). */
RL_API void rl_rng_advance(rl_rng *rng, uint64_t delta);

/* A well-mixed 64-bit hash (splitmix64 finaliser), for per-pixel seeds. */
RL_API uint64_t rl_hash64(uint64_t x);


/* ---- GPU-style generators (Schröder 2017, Sec. 5.3) ----
 * The three 32-bit generators the thesis discusses for per-pixel random
 * numbers on the GPU, for the path tracer "pt" (and for comparing them):
 *   RL_RNG_GPU_LCG         x = a x + c mod 2^32, a = 1664525, c = 1013904223
 *                          (Numerical Recipes; Sec. 5.3.1, Alg. 1);
 *   RL_RNG_GPU_TAUSWORTHE  three combined Tausworthe components (Alg. 2,
 *                          L'Ecuyer 1996) XORed: the CTG of Sec. 5.3.2;
 *   RL_RNG_GPU_HYBRID      those three plus one LCG, XORed (Nguyen 2007,
 *                          GPU Gems 3, Ch. 37; Sec. 5.3.3), period ~2^121.
 * The state is four 32-bit words, the thesis' four-channel state texel;
 * it is seeded once per pixel from PCG32 (the thesis fills the texture
 * from the CPU's generator) and then only advanced. */
typedef enum rl_rng_gpu_kind {
    RL_RNG_GPU_LCG = 0,
    RL_RNG_GPU_TAUSWORTHE,
    RL_RNG_GPU_HYBRID,
    RL_RNG_GPU_KIND_COUNT
} rl_rng_gpu_kind;

typedef struct rl_rng_gpu {
    uint32_t z[4];            /* z[0..2]: Tausworthe components (> 128), z[3]: LCG */
    rl_rng_gpu_kind kind;
} rl_rng_gpu;

/* "lcg", "tausworthe", "hybrid"; "unknown" for anything else. */
RL_API const char *rl_rng_gpu_kind_name(rl_rng_gpu_kind kind);
/* Seeds from PCG32 (seed, stream), e.g. stream = pixel index. An unknown
 * kind falls back to RL_RNG_GPU_HYBRID. */
RL_API void rl_rng_gpu_seed(rl_rng_gpu *g, rl_rng_gpu_kind kind, uint64_t seed, uint64_t stream);
/* Next 32-bit output (the state advances). */
RL_API uint32_t rl_rng_gpu_u32(rl_rng_gpu *g);
/* Next float in [0,1): the output times 2.3283064365387e-10 (2^-32), as in
 * GPU Gems 3, clamped below 1 where float rounding would reach it. */
RL_API float rl_rng_gpu_float(rl_rng_gpu *g);

#ifdef __cplusplus
}
#endif
#endif
