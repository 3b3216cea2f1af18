/* teapot.c: tessellates Newell's Utah teapot (teapot_data.c) from its 32
 * bicubic Bezier patches.
 *
 * Each patch is evaluated on a regular nu x nv grid with analytic normals,
 * n = dP/du x dP/dv (the data set's patches are oriented so this points
 * outwards). The lid knob and the bottom each collapse one patch edge to a
 * point; the grid triangles touching such an edge with two vertices are
 * degenerate and are not emitted, so a patch with a collapsed edge yields
 * 2*nu*nv - nu triangles. The default 13 x 19 grid gives the 15,704
 * triangles of the teapot in Schröder 2017. The mesh is not watertight
 * where the original model is not (the lid sits in the rim; handle and spout
 * pierce the body). Output is y-up (z-up data rotated by -90 degrees about x)
 * and scaled to the requested height. */
#include "scene/generators.h"

#include <math.h>
#include <stdlib.h>

#define TEAPOT_HEIGHT 3.15f    /* z range of the data set: 0 .. 3.15 */

/* Cubic Bernstein weights and derivatives at t = i/n. Written so that the
 * weights at (n-i)/n are exactly those at i/n reversed (s and t swap, and
 * products are formed in the same order), which makes a boundary curve that
 * two patches traverse in opposite directions evaluate bitwise equal. */
static void bernstein(uint32_t i, uint32_t n, float b[4], float db[4])
{
    float t = (float)i / (float)n, s = (float)(n - i) / (float)n;
    float ts = t * s;
    b[0] = s * s * s;
    b[1] = 3.0f * ts * s;
    b[2] = 3.0f * ts * t;
    b[3] = t * t * t;
    db[0] = -3.0f * s * s;
    db[1] = 3.0f * s * s - 6.0f * ts;
    db[2] = 6.0f * ts - 3.0f * t * t;
    db[3] = 3.0f * t * t;
}

static rl_vec3 point(int index)
{
    const float *p = rl_teapot_points[index];
    return rl_v3(p[0], p[1], p[2]);
}

/* sum w[k] * p[k], paired outside-in so the reversed sequence gives the same
 * bits (float addition is commutative but not associative). */
static rl_vec3 blend(const float w[4], const rl_vec3 p[4])
{
    rl_vec3 outer = rl_add(rl_scale(p[0], w[0]), rl_scale(p[3], w[3]));
    rl_vec3 inner = rl_add(rl_scale(p[1], w[1]), rl_scale(p[2], w[2]));
    return rl_add(outer, inner);
}

/* Position and partial derivatives at grid point (iu/nu, iv/nv); u runs
 * along a row of the 4x4 control net (fastest index), v across rows. Rows
 * are blended along u first, then across v, so a shared boundary evaluates
 * from the same four control points with the same weights on both sides. */
static void evaluate(const uint16_t patch[16], uint32_t iu, uint32_t nu, uint32_t iv,
                     uint32_t nv, rl_vec3 *p, rl_vec3 *du, rl_vec3 *dv)
{
    float bu[4], dbu[4], bv[4], dbv[4];
    bernstein(iu, nu, bu, dbu);
    bernstein(iv, nv, bv, dbv);
    rl_vec3 row[4], drow[4];
    for (int i = 0; i < 4; ++i) {
        rl_vec3 c[4];
        for (int j = 0; j < 4; ++j)
            c[j] = point(patch[4 * i + j]);
        row[i] = blend(bu, c);
        drow[i] = blend(dbu, c);
    }
    *p = blend(bv, row);
    *du = blend(bv, drow);
    *dv = blend(dbv, row);
}

/* Unit normal at (u, v). Where a partial derivative vanishes (a collapsed
 * edge) the cross product is zero; the normal there is the limit from the
 * patch interior, so we step a little inwards and retry. */
static rl_vec3 normal_at(const uint16_t patch[16], uint32_t iu, uint32_t nu, uint32_t iv,
                         uint32_t nv)
{
    /* Evaluate on a 1024x finer grid so that the steps are exact fractions. */
    static const uint32_t steps[] = { 0, 1, 8, 64 };
    const uint32_t fine = 1024;
    for (size_t k = 0; k < sizeof steps / sizeof steps[0]; ++k) {
        uint32_t fu = iu * fine, fv = iv * fine;
        fu = 2 * iu < nu ? fu + steps[k] : fu - steps[k];
        fv = 2 * iv < nv ? fv + steps[k] : fv - steps[k];
        rl_vec3 p, du, dv;
        evaluate(patch, fu, nu * fine, fv, nv * fine, &p, &du, &dv);
        /* Control points are O(1): a partial shorter than 1e-4 is rounding
         * noise around zero and its direction is meaningless. */
        float lu = rl_length(du), lv = rl_length(dv);
        rl_vec3 n = rl_cross(du, dv);
        float len = rl_length(n);
        if (lu > 1e-4f && lv > 1e-4f && len > 1e-6f * lu * lv && isfinite(len))
            return rl_scale(n, 1.0f / len);
    }
    return rl_v3(0.0f, 0.0f, 1.0f);
}

static bool same_point(int a, int b)
{
    const float *p = rl_teapot_points[a], *q = rl_teapot_points[b];
    return p[0] == q[0] && p[1] == q[1] && p[2] == q[2];
}

/* Collapsed boundary rows (v = 0 or 1) and columns (u = 0 or 1). */
static bool row_collapsed(const uint16_t patch[16], int row)
{
    const uint16_t *r = patch + 4 * row;
    return same_point(r[0], r[1]) && same_point(r[0], r[2]) && same_point(r[0], r[3]);
}

static bool column_collapsed(const uint16_t patch[16], int col)
{
    return same_point(patch[col], patch[4 + col]) && same_point(patch[col], patch[8 + col]) &&
           same_point(patch[col], patch[12 + col]);
}

uint32_t rl_teapot_grid(uint32_t triangles, uint32_t *nu_out, uint32_t *nv_out)
{
    /* Triangles(nu, nv) = 64 nu nv - rows * nu - cols * nv, where rows and
     * cols count collapsed edges over all patches. */
    uint64_t rows = 0, cols = 0;
    for (int k = 0; k < RL_TEAPOT_PATCHES; ++k) {
        rows += row_collapsed(rl_teapot_patches[k], 0) + row_collapsed(rl_teapot_patches[k], 3);
        cols += column_collapsed(rl_teapot_patches[k], 0) +
                column_collapsed(rl_teapot_patches[k], 3);
    }
    uint64_t best_count = 0, best_err = UINT64_MAX;
    uint32_t best_u = 1, best_v = 1;
    /* Near-square grids only (aspect within 2:1), so the mesh stays even;
     * for each nu the best nv is one of the two around the exact solution. */
    for (uint32_t nu = 1; nu <= 1024; ++nu) {
        double exact = ((double)triangles + (double)rows * nu) / (64.0 * nu - (double)cols);
        uint32_t lo = exact < 1.0 ? 1u : (uint32_t)exact;
        for (uint32_t nv = lo; nv <= lo + 1; ++nv) {
            if (nv > 2 * nu || nu > 2 * nv)
                continue;
            uint64_t count = 64ull * nu * nv - rows * nu - cols * nv;
            uint64_t err = count > triangles ? count - triangles : triangles - count;
            /* Ties go to the squarer grid. */
            bool squarer = (nu > nv ? nu - nv : nv - nu) < (best_u > best_v ? best_u - best_v
                                                                           : best_v - best_u);
            if (err < best_err || (err == best_err && squarer)) {
                best_err = err;
                best_count = count;
                best_u = nu;
                best_v = nv;
            }
        }
    }
    *nu_out = best_u;
    *nv_out = best_v;
    return (uint32_t)best_count;
}

/* z-up data -> y-up scene: (x, y, z) -> (x, z, -y), a proper rotation. */
static rl_vec3 to_y_up(rl_vec3 p) { return rl_v3(p.x, p.z, -p.y); }

static void tessellate_patch(rl_meshbuf *b, const uint16_t patch[16], uint32_t nu, uint32_t nv,
                             float scale)
{
    bool collapsed_row[2] = { row_collapsed(patch, 0), row_collapsed(patch, 3) };
    bool collapsed_col[2] = { column_collapsed(patch, 0), column_collapsed(patch, 3) };
    uint32_t base = b->num_vertices;
    for (uint32_t i = 0; i <= nv; ++i) {
        float v = (float)i / (float)nv;
        for (uint32_t j = 0; j <= nu; ++j) {
            float u = (float)j / (float)nu;
            rl_vec3 p, du, dv;
            evaluate(patch, j, nu, i, nv, &p, &du, &dv);
            /* Snap collapsed edges to their control point so the triangles
             * we skip are exactly degenerate and the pole is one point. */
            if ((i == 0 && collapsed_row[0]) || (j == 0 && collapsed_col[0]))
                p = point(patch[0]);
            else if (i == nv && collapsed_row[1])
                p = point(patch[12]);
            else if (j == nu && collapsed_col[1])
                p = point(patch[3]);
            rl_vec3 n = normal_at(patch, j, nu, i, nv);
            rl_meshbuf_vertex(b, rl_scale(to_y_up(p), scale), to_y_up(n), rl_v2(u, v));
        }
    }
    uint32_t row = nu + 1;
    for (uint32_t i = 0; i < nv; ++i) {
        for (uint32_t j = 0; j < nu; ++j) {
            uint32_t a = base + i * row + j, c = a + 1, d = a + row + 1, e = a + row;
            /* Triangle (a, c, d) has edge a-c on row i and edge c-d on
             * column j+1; (a, d, e) has d-e on row i+1 and e-a on column j. */
            bool skip1 = (i == 0 && collapsed_row[0]) || (j == nu - 1 && collapsed_col[1]);
            bool skip2 = (i == nv - 1 && collapsed_row[1]) || (j == 0 && collapsed_col[0]);
            if (!skip1)
                rl_meshbuf_triangle(b, a, c, d);
            if (!skip2)
                rl_meshbuf_triangle(b, a, d, e);
        }
    }
}

void rl_gen_teapot(rl_meshbuf *b, uint32_t triangles, float size)
{
    uint32_t nu, nv;
    uint32_t count = rl_teapot_grid(triangles, &nu, &nv);
    if (!rl_meshbuf_reserve(b, (uint64_t)RL_TEAPOT_PATCHES * (nu + 1) * (nv + 1), count))
        return;
    float scale = size / TEAPOT_HEIGHT;
    for (int k = 0; k < RL_TEAPOT_PATCHES; ++k)
        tessellate_patch(b, rl_teapot_patches[k], nu, nv, scale);
}
