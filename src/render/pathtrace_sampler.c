/* pathtrace_sampler.c: the sample numbers of the path tracer "pt": either
 * the thesis' per-pixel GPU generators (Schröder 2017, Sec. 5.3; rng=lcg,
 * tausworthe, hybrid), drawn one after another, or (rng=sobol, the default)
 * a low-discrepancy sequence: the first two dimensions of Sobol's sequence
 * (Sobol 1967), Owen-scrambled (Owen 1995) by a hash (nested uniform
 * scrambling as Laine & Karras 2011 and Burley 2020, "Practical Hash-based
 * Owen Scrambling", describe it), and padded to every further dimension
 * pair by shuffling the sample index with another scramble per pair
 * (Burley 2020, Sec. 4), so that each 1D and 2D draw of a path is a
 * stratified (0,2)-sequence over the pixel's samples.
 *
 * Decorrelation and reproducibility: a pixel's scrambles are seeded by a
 * hash of (seed, pixel), a draw is addressed by (sample index in the pixel,
 * slot), so a pixel's n-th sample is the same whatever the thread count or
 * the frame it falls in. The slot of each draw is fixed by the path vertex
 * and the purpose (pathtrace_internal.h, PT_SLOT_*), not by how many draws
 * came before: a path that skips a light sample does not shift the
 * dimensions of the next bounce.
 *
 * The scramble: read x as a binary fraction, most significant bit first;
 * nested uniform scrambling flips each bit by a random function of the bits
 * above it. Reversing the bits turns "above" into "below", and there every
 * step of the chain below is a bijection in which bit j changes by a
 * function of bits 0..j-1 and the seed only: adding a constant (carries run
 * upwards), multiplying by an odd constant, and x ^= x * (even constant).
 * The constants are ours; the stratification this guarantees is tested in
 * tests/render/test_pathtrace_sampler.c. */
#include "core/hash.h"   /* rl_splitmix64: rl_hash64 inlined into every draw */
#include "render/pathtrace_internal.h"

#define TO_UNIT_24 (1.0f / 16777216.0f)   /* 2^-24: 24 bits fill a float's mantissa */

static uint32_t reverse_bits(uint32_t x)
{
    x = __builtin_bswap32(x);     /* the bytes in one instruction, then the bits within them */
    x = ((x & 0x0f0f0f0fu) << 4) | ((x >> 4) & 0x0f0f0f0fu);
    x = ((x & 0x33333333u) << 2) | ((x >> 2) & 0x33333333u);
    return ((x & 0x55555555u) << 1) | ((x >> 1) & 0x55555555u);
}

/* The scramble on reversed bits: bit j changes by a function of bits
 * 0..j-1 and the seed. */
static uint32_t scramble_reversed(uint32_t x, uint32_t seed)
{
    x += seed;
    x ^= x * 0x2c1b3c6cu;
    x *= (seed >> 1) | 1u;
    x ^= x * 0x95a4e8d2u;
    x += seed * 0x632be5abu;
    x ^= x * 0xa3d15f40u;
    x *= 0x8bb84b93u;
    x ^= x * 0x5e27a3f6u;
    return x;
}

uint32_t rl_pt_owen_scramble(uint32_t x, uint32_t seed)
{
    return reverse_bits(scramble_reversed(reverse_bits(x), seed));
}

/* Sobol's first dimension is the van der Corput sequence in base 2, the
 * reversed index (written out where it is used). The second dimension:
 * primitive polynomial x + 1 (degree 1, m_1 = 1), so the direction numbers
 * follow v_k = v_{k-1} ^ (v_{k-1} >> 1) from v_1 = 2^31: v_k's bit j,
 * counted from the top, is the binomial coefficient C(k, j) mod 2, which by
 * Lucas' theorem is 1 exactly when j's bits are a subset of k's. So output
 * bit j is the parity of the index bits k that are supersets of j, a
 * superset transform over the 5-bit bit numbers: five shift-and-xor steps
 * instead of one table lookup per set index bit (a loop of 12 data-dependent
 * iterations on average, about 40 % of the sampler's time). The result
 * is bit-reversed, the order the scramble wants it in; tests compare it
 * with the direction numbers. Index bits from the 25th on only touch output
 * bits below 2^-24, which to_unit drops, and the scramble after this keeps
 * the leading 24 bits a function of the leading 24 bits: so 24 index bits
 * suffice. */
static uint32_t sobol_dim1_reversed(uint32_t i)
{
    i &= 0xffffffu;
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0f0f0f0fu;
    i ^= (i >> 8) & 0x00ff00ffu;
    i ^= (i >> 16) & 0x0000ffffu;
    return i;
}

uint32_t rl_pt_sobol_dim1(uint32_t i)
{
    return reverse_bits(sobol_dim1_reversed(i));
}

void rl_pt_sampler_init(pt_sampler *s, rl_rng_gpu *rng, uint32_t pixel_seed, uint32_t index)
{
    s->rng = rng;
    s->pixel_seed = pixel_seed;
    s->index = index;
    s->index_reversed = reverse_bits(index);
    s->slot = 0;
}

uint32_t rl_pt_pixel_seed(uint64_t seed, uint64_t pixel)
{
    return (uint32_t)(rl_splitmix64(rl_splitmix64(seed) ^ (pixel * 0x9e3779b97f4a7c15ull)) >> 32);
}

/* Both halves of a 64-bit word bit-reversed in place: one reversal for the
 * two coordinates of a 2D draw instead of one each (a reversal is a chain
 * of 13 integer operations; x86 has no instruction for it). Reversing the
 * 64 bits swaps the halves, so the caller packs them the other way round. */
static uint64_t reverse_bits64(uint64_t x)
{
    x = __builtin_bswap64(x);
    x = ((x & 0x0f0f0f0f0f0f0f0full) << 4) | ((x >> 4) & 0x0f0f0f0f0f0f0f0full);
    x = ((x & 0x3333333333333333ull) << 2) | ((x >> 2) & 0x3333333333333333ull);
    return ((x & 0x5555555555555555ull) << 1) | ((x >> 1) & 0x5555555555555555ull);
}

/* The seeds of a slot (index shuffle, x, y) from one 64-bit hash: the
 * hashing is most of the sampler's cost, and a scramble needs no more than
 * distinct well-mixed words. */
static void slot_seeds(const pt_sampler *s, uint32_t slot, uint32_t seed[3])
{
    uint64_t h = rl_splitmix64(((uint64_t)s->pixel_seed << 32) | slot);
    seed[0] = (uint32_t)h;
    seed[1] = (uint32_t)(h >> 32);
    seed[2] = (uint32_t)((h * 0xd1342543de82ef95ull) >> 32) ^ seed[0];
}

static float to_unit(uint32_t x)
{
    return (float)(x >> 8) * TO_UNIT_24;
}

rl_vec2 rl_pt_sample_2d(pt_sampler *s)
{
    if (s->rng) {
        float a = rl_rng_gpu_float(s->rng);
        return rl_v2(a, rl_rng_gpu_float(s->rng));
    }
    uint32_t seed[3];
    slot_seeds(s, s->slot++, seed);
    /* The shuffled index i = owen(index) and, reversed, its van der Corput
     * point d0; then owen(d0) and owen(sobol_dim1(i)), each written as
     * reverse(scramble_reversed(reverse(.))) with the inner reversals
     * cancelled against the ones before them. */
    uint32_t d0 = scramble_reversed(s->index_reversed, seed[0]);
    uint32_t i = reverse_bits(d0);
    uint64_t xy = reverse_bits64((uint64_t)scramble_reversed(sobol_dim1_reversed(i), seed[2]) << 32 |
                                 scramble_reversed(i, seed[1]));
    return rl_v2(to_unit((uint32_t)(xy >> 32)), to_unit((uint32_t)xy));
}

float rl_pt_sample_1d(pt_sampler *s)
{
    if (s->rng)
        return rl_rng_gpu_float(s->rng);
    uint32_t seed[3];
    slot_seeds(s, s->slot++, seed);
    /* sobol_dim0(owen(index)) = reverse(owen(index)): one reversal less. */
    uint32_t d0 = scramble_reversed(s->index_reversed, seed[0]);
    return to_unit(rl_pt_owen_scramble(d0, seed[1]));
}
