/* half.h: IEEE 754 binary16 ("half float") conversion, as the Line Space
 * stores its PNMT and PREILLUM payloads (Schröder 2017, Sec. 7.3-7.4: RGBA16F
 * textures). Bit manipulation rather than _Float16 so that the result does
 * not depend on compiler support; float -> half rounds to nearest, ties to
 * even (what a GPU's texture upload does), overflows to infinity, keeps NaN
 * a NaN and produces subnormals. half -> float is exact. */
#ifndef RL_CORE_HALF_H
#define RL_CORE_HALF_H

#include <stdint.h>
#include <string.h>

static inline uint16_t rl_half_from_float(float f)
{
    uint32_t x;
    memcpy(&x, &f, sizeof x);
    uint32_t sign = (x >> 16) & 0x8000u, ax = x & 0x7fffffffu;
    if (ax >= 0x7f800000u)                        /* Inf, NaN (quiet, payload dropped) */
        return (uint16_t)(sign | 0x7c00u | (ax > 0x7f800000u ? 0x200u : 0u));
    if (ax >= 0x477ff000u)                        /* >= 65520 rounds to Inf */
        return (uint16_t)(sign | 0x7c00u);
    if (ax < 0x38800000u) {                       /* below 2^-14: subnormal or zero */
        if (ax < 0x33000000u)                     /* <= 2^-25 rounds to 0 (tie to even) */
            return (uint16_t)sign;
        uint32_t e = ax >> 23, m = (ax & 0x7fffffu) | 0x800000u;
        uint32_t shift = 126u - e;                /* value / 2^-24 = m >> shift */
        uint32_t r = m >> shift, rem = m & ((1u << shift) - 1u), halfway = 1u << (shift - 1u);
        if (rem > halfway || (rem == halfway && (r & 1u)))
            ++r;
        return (uint16_t)(sign | r);
    }
    uint32_t r = ((ax >> 23) - 112u) << 10 | ((ax & 0x7fffffu) >> 13);
    uint32_t rem = ax & 0x1fffu;
    if (rem > 0x1000u || (rem == 0x1000u && (r & 1u)))
        ++r;                                      /* a carry into the exponent is right */
    return (uint16_t)(sign | r);
}

static inline float rl_half_to_float(uint16_t h)
{
    uint32_t sign = (uint32_t)(h & 0x8000u) << 16, e = (h >> 10) & 0x1fu, m = h & 0x3ffu, x;
    if (e == 0x1fu) {
        x = sign | 0x7f800000u | (m << 13);
    } else if (e != 0u) {
        x = sign | ((e + 112u) << 23) | (m << 13);
    } else if (m == 0u) {
        x = sign;
    } else {                                      /* subnormal: normalise */
        e = 113u;
        while (!(m & 0x400u)) {
            m <<= 1;
            --e;
        }
        x = sign | (e << 23) | ((m & 0x3ffu) << 13);
    }
    float f;
    memcpy(&f, &x, sizeof f);
    return f;
}

#endif
