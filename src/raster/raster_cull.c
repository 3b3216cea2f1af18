/* raster_cull.c: whole boxes against the view volume, so that a caller can
 * skip an object (its lighting, its vertex transform, its setup) that the
 * per-triangle trivial reject of raster_setup.c would drop entirely anyway.
 *
 * The planes are those of that reject, in homogeneous clip space, where
 * they are linear: near z + w >= 0 and the viewport sides |x| <= w,
 * |y| <= w. A point of the box is a convex combination of its corners, so
 * when all eight corners lie beyond one plane every vertex inside does too,
 * and each of its triangles has that plane's bit in the AND of its outcodes.
 * Vertices are transformed in float, corners here in double: the margin
 * covers the rounding of a float transform (a few ulps of the sum of the
 * terms' magnitudes), so the test only ever says "outside" when the
 * rasterizer would have drawn nothing, and images stay bit-identical. */
#include <math.h>

#include "raster/raster_internal.h"

/* Relative to the terms' magnitudes: float rounding of a 4-term dot product
 * is below 4 * 2^-24, about 2.4e-7; this leaves a factor of 40. */
#define MARGIN 1e-5

bool rl_raster_box_outside(const rl_raster *r, rl_aabb box)
{
    if (!r || !r->target)
        return false;
    /* Empty or non-finite boxes are not decided here. */
    const float lo[3] = { box.min.x, box.min.y, box.min.z }, hi[3] = { box.max.x, box.max.y, box.max.z };
    for (int a = 0; a < 3; ++a)
        if (!(lo[a] <= hi[a]) || !isfinite(lo[a]) || !isfinite(hi[a]))
            return false;
    const rl_mat4 *m = &r->view_proj;
    double mag[4];
    for (int i = 0; i < 4; ++i) {
        mag[i] = fabs((double)m->m[i][3]);
        for (int a = 0; a < 3; ++a)
            mag[i] += fabs((double)m->m[i][a]) * fmax(fabs((double)lo[a]), fabs((double)hi[a]));
    }
    const double tol_x = MARGIN * (mag[0] + mag[3]), tol_y = MARGIN * (mag[1] + mag[3]),
                 tol_z = MARGIN * (mag[2] + mag[3]);
    /* Bit k set: every corner so far lies beyond plane k by the margin. */
    unsigned all_out = 0x1f;
    for (int c = 0; c < 8 && all_out; ++c) {
        const double p[3] = { c & 1 ? hi[0] : lo[0], c & 2 ? hi[1] : lo[1], c & 4 ? hi[2] : lo[2] };
        double q[4];
        for (int i = 0; i < 4; ++i)
            q[i] = m->m[i][0] * p[0] + m->m[i][1] * p[1] + m->m[i][2] * p[2] + (double)m->m[i][3];
        unsigned out = 0;
        if (q[2] + q[3] < -tol_z) out |= 1u << 0;        /* in front of the near plane */
        if (q[0] - q[3] > tol_x) out |= 1u << 1;         /* right of the viewport */
        if (-q[0] - q[3] > tol_x) out |= 1u << 2;        /* left */
        if (q[1] - q[3] > tol_y) out |= 1u << 3;         /* above */
        if (-q[1] - q[3] > tol_y) out |= 1u << 4;        /* below */
        all_out &= out;
    }
    return all_out != 0;
}
