/* hash.h: one splitmix64 step (Steele, Lea & Flood 2014), inline. The
 * golden-ratio increment keeps hash(0) != 0, then the finaliser gives full
 * avalanche. rl_hash64 (core/rng.c) is this function exported; callers in
 * hot loops (pt's sampler hashes at every draw) include this header so that
 * the compiler inlines it. */
#ifndef RL_CORE_HASH_H
#define RL_CORE_HASH_H

#include <stdint.h>

static inline uint64_t rl_splitmix64(uint64_t x)
{
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
}

#endif
