/* raster_fixtures.h: the matrices and batches every rasterizer test sets up (included
 * by tests/raster/test_*.c; header-only, so that each test stays one
 * executable). */
#ifndef RL_TEST_RASTER_FIXTURES_H
#define RL_TEST_RASTER_FIXTURES_H

#include "rl/rl_math.h"
#include "rl/rl_raster.h"

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

/* A white batch of nt triangles over nv vertices; the rest zero. */
static inline rl_raster_batch tris(const rl_vec3 *pos, uint32_t nv, const uint32_t *idx, uint32_t nt)
{
    rl_raster_batch b = { 0 };
    b.positions = pos;
    b.num_vertices = nv;
    b.indices = idx;
    b.num_triangles = nt;
    b.color = rl_v4(1, 1, 1, 1);
    return b;
}

#endif
