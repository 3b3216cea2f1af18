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

#ifdef __cplusplus
}
#endif
#endif
