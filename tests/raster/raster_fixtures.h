/* raster_fixtures.h: the matrices every rasterizer test sets up (included
 * by tests/raster/test_*.c; header-only, so that each test stays one
 * executable). */
#ifndef RL_TEST_RASTER_FIXTURES_H
#define RL_TEST_RASTER_FIXTURES_H

#include "rl/rl_math.h"

static inline rl_mat4 identity(void)
{
    rl_mat4 m = { { { 1, 0, 0, 0 }, { 0, 1, 0, 0 }, { 0, 0, 1, 0 }, { 0, 0, 0, 1 } } };
    return m;
}

/* OpenGL perspective, 90 degrees vertical, square aspect. */
static inline rl_mat4 perspective90(float n, float f)
{
    rl_mat4 m = { { { 1, 0, 0, 0 },
                    { 0, 1, 0, 0 },
                    { 0, 0, (f + n) / (n - f), 2 * f * n / (n - f) },
                    { 0, 0, -1, 0 } } };
    return m;
}

#endif
