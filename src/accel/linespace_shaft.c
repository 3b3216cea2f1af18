/* linespace_shaft.c: shaft indexing and shaft geometry of the Line Space
 * (Keul, Müller, Lemke 2016; Schröder 2017, Sec. 4.2), and the
 * conservative triangle/shaft overlap test ("ObjectShaftClipping" of
 * Schröder 2017, Alg. 3).
 *
 * Index mapping: rl_linespace.h. Geometry is in cell units (the voxel is
 * [0,1]^3), so one set of tables serves every voxel.
 *
 * Overlap. A shaft is the convex hull of its two patch rectangles. Instead
 * of clipping the triangle against each of the 15·N^4 hulls (Alg. 3 loops
 * over all of them), we enumerate per face pair only the patch pairs that
 * can overlap, with separating axes that factor over the patch indices:
 *   opposite faces (axis c, in-face axes u, v): the hull's cross-section at
 *     height c is a rectangle whose u-interval and v-interval move linearly
 *     with c, so the hull is the intersection of two 2D shafts in the (c, u)
 *     and (c, v) planes. A patch pair (i_a, i_b) along u survives if the
 *     clipped polygon is not wholly below or above the 2D shaft's two edges;
 *     same for v; the candidates are the product of the two lists;
 *   perpendicular faces (A normal to axis p, B normal to q, r the common
 *     axis): the hull projects onto the (p, q) plane as the quad between two
 *     lines, tested per (A's q-patch, B's p-patch); writing a hull point as
 *     (1-λ)·a + λ·b bounds λ from the polygon's p and q ranges, and its r
 *     coordinate then lies in a 2D shaft over λ, tested per (A's r-patch,
 *     B's r-patch) against the polygon's r range;
 *   both: last the triangle's plane as a separating axis against the two
 *     patches (their support in the normal direction).
 * Edge/edge axes are omitted, so a few shafts that do not overlap pass
 * (false positives cost a test in the query, never a wrong answer). All
 * half-space tests allow RL_LS_EPS, and the triangle is clipped to the
 * voxel grown by RL_LS_EPS, so triangles in a face plane and points on patch
 * borders are kept on both sides. */
#include <float.h>
#include <math.h>
#include <stdlib.h>

#include "accel/linespace_internal.h"
#include "core/error.h"

/* fmin/fmax are library calls (NaN rules); the inputs here are finite. */
#define MIN2(a, b) ((a) < (b) ? (a) : (b))
#define MAX2(a, b) ((a) > (b) ? (a) : (b))

/* ---- index mapping (rl_linespace.h) ---- */

int rl_ls_pair_index(int a, int b)
{
    /* Pairs starting with face a are preceded by 5 + 4 + ... pairs. */
    return a * 5 - a * (a - 1) / 2 + (b - a - 1);
}

void rl_ls_pair_faces(int pair, int *a, int *b)
{
    int fa = 0;
    while (pair >= 5 - fa) {
        pair -= 5 - fa;
        ++fa;
    }
    *a = fa;
    *b = fa + 1 + pair;
}

uint32_t rl_ls_shaft_index(int n, int fa, int pa, int fb, int pb, bool *forward)
{
    int np = n * n;
    if (n < 1 || n > RL_LS_MAX_N || fa < 0 || fa > 5 || fb < 0 || fb > 5 || fa == fb || pa < 0 ||
        pa >= np || pb < 0 || pb >= np)
        return RL_NONE;
    bool fwd = fa < fb;
    if (!fwd) {
        int t = fa; fa = fb; fb = t;
        t = pa; pa = pb; pb = t;
    }
    if (forward)
        *forward = fwd;
    return (uint32_t)rl_ls_pair_index(fa, fb) * (uint32_t)(np * np) + (uint32_t)pa * (uint32_t)np +
           (uint32_t)pb;
}

void rl_ls_shaft_decode(int n, uint32_t s, int *fa, int *pa, int *fb, int *pb)
{
    uint32_t np = (uint32_t)(n * n), n4 = np * np;
    int a, b;
    rl_ls_pair_faces((int)(s / n4), &a, &b);
    uint32_t rem = s % n4;
    if (fa) *fa = a;
    if (fb) *fb = b;
    if (pa) *pa = (int)(rem / np);
    if (pb) *pb = (int)(rem % np);
}

/* Face of a point on the unit cube: the nearest face plane; `second` is the
 * next nearest (for points on an edge). */
static void nearest_faces(const double e[3], int *best, double *best_d, int *second, double *second_d)
{
    *best = -1;
    *second = -1;
    *best_d = *second_d = INFINITY;
    for (int f = 0; f < 6; ++f) {
        double d = fabs((f & 1) ? 1.0 - e[f >> 1] : e[f >> 1]);
        if (d < *best_d) {
            *second = *best;
            *second_d = *best_d;
            *best = f;
            *best_d = d;
        } else if (d < *second_d) {
            *second = f;
            *second_d = d;
        }
    }
}

static int patch_of(int n, int f, const double e[3])
{
    int u, v;
    rl_ls_face_uv(f, &u, &v);
    double fu = floor(e[u] * n), fv = floor(e[v] * n);
    int i = fu < 0.0 ? 0 : (fu > n - 1 ? n - 1 : (int)fu);
    int j = fv < 0.0 ? 0 : (fv > n - 1 ? n - 1 : (int)fv);
    return i + n * j;
}

/* The shaft of the segment from entry to exit, both in cell units. A point
 * within 1e-5 of an edge may belong to either face: if both points chose
 * the same face, the one with a close second face switches (the shafts are
 * grown by RL_LS_EPS, so either patch holds the line). */
uint32_t rl_ls_shaft_of_unit(int n, const double entry[3], const double exit[3], bool *forward)
{
    int f0, f1, s0, s1;
    double d0, d1, sd0, sd1;
    nearest_faces(entry, &f0, &d0, &s0, &sd0);
    nearest_faces(exit, &f1, &d1, &s1, &sd1);
    if (f0 == f1) {
        const double tol = 1e-5;
        if (sd0 <= sd1 && sd0 <= tol)
            f0 = s0;
        else if (sd1 <= tol)
            f1 = s1;
        else
            return RL_NONE;
    }
    return rl_ls_shaft_index(n, f0, patch_of(n, f0, entry), f1, patch_of(n, f1, exit), forward);
}

uint32_t rl_ls_shaft_of_segment(int n, rl_aabb voxel, rl_vec3 entry, rl_vec3 exit, bool *forward)
{
    if (n < 1 || n > RL_LS_MAX_N)
        return RL_NONE;
    double a[3], b[3];
    for (int k = 0; k < 3; ++k) {
        double lo = rl_vget(voxel.min, k), ext = (double)rl_vget(voxel.max, k) - lo;
        if (!(ext > 0.0))
            return RL_NONE;
        a[k] = ((double)rl_vget(entry, k) - lo) / ext;
        b[k] = ((double)rl_vget(exit, k) - lo) / ext;
    }
    return rl_ls_shaft_of_unit(n, a, b, forward);
}

/* ---- per-build geometry ---- */

rl_status rl_ls_geometry_init(rl_ls_geometry *g, int n)
{
    g->n = n;
    g->shafts = rl_ls_shafts_per_voxel(n);
    int np = n * n;
    g->patch_center = rl_calloc((size_t)6 * (size_t)np * 3, sizeof *g->patch_center);
    if (!g->patch_center)
        return RL_ERR_OUT_OF_MEMORY;
    for (int f = 0; f < 6; ++f) {
        int u, v;
        rl_ls_face_uv(f, &u, &v);
        for (int p = 0; p < np; ++p) {
            float *c = g->patch_center + ((size_t)f * (size_t)np + (size_t)p) * 3;
            c[f >> 1] = (float)(f & 1);
            c[u] = ((float)(p % n) + 0.5f) / (float)n;
            c[v] = ((float)(p / n) + 0.5f) / (float)n;
        }
    }
    return RL_OK;
}

void rl_ls_geometry_free(rl_ls_geometry *g)
{
    free(g->patch_center);
    g->patch_center = NULL;
}

/* ---- the triangle in cell units ---- */

/* Sutherland-Hodgman against one plane: keeps sign·x[axis] <= bound. */
static int clip_plane(double in[][3], int n, double out[][3], int axis, double sign, double bound)
{
    int m = 0;
    for (int i = 0; i < n; ++i) {
        const double *a = in[i], *b = in[(i + 1) % n];
        double da = sign * a[axis] - bound, db = sign * b[axis] - bound;
        if (da <= 0.0) {
            out[m][0] = a[0]; out[m][1] = a[1]; out[m][2] = a[2];
            ++m;
        }
        if ((da < 0.0 && db > 0.0) || (da > 0.0 && db < 0.0)) {
            double t = da / (da - db);
            for (int k = 0; k < 3; ++k)
                out[m][k] = a[k] + (b[k] - a[k]) * t;
            out[m][axis] = sign * bound;   /* exactly on the plane */
            ++m;
        }
    }
    return m;
}

bool rl_ls_tri_setup(rl_ls_tri *t, const double p[3][3])
{
    double buf[2][9][3];
    for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
            t->v[i][k] = buf[0][i][k] = p[i][k];
    int n = 3, cur = 0;
    for (int axis = 0; axis < 3 && n > 0; ++axis) {
        n = clip_plane(buf[cur], n, buf[cur ^ 1], axis, 1.0, 1.0 + RL_LS_EPS);
        cur ^= 1;
        if (n > 0) {
            n = clip_plane(buf[cur], n, buf[cur ^ 1], axis, -1.0, RL_LS_EPS);
            cur ^= 1;
        }
    }
    if (n == 0)
        return false;
    t->npoly = n;
    for (int k = 0; k < 3; ++k) {
        t->lo[k] = INFINITY;
        t->hi[k] = -INFINITY;
    }
    for (int i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            t->poly[i][k] = buf[cur][i][k];
            t->lo[k] = MIN2(t->lo[k], buf[cur][i][k]);
            t->hi[k] = MAX2(t->hi[k], buf[cur][i][k]);
        }
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = p[1][k] - p[0][k];
        e2[k] = p[2][k] - p[0][k];
    }
    t->normal[0] = e1[1] * e2[2] - e1[2] * e2[1];
    t->normal[1] = e1[2] * e2[0] - e1[0] * e2[2];
    t->normal[2] = e1[0] * e2[1] - e1[1] * e2[0];
    double len = sqrt(t->normal[0] * t->normal[0] + t->normal[1] * t->normal[1] +
                      t->normal[2] * t->normal[2]);
    if (len > 0.0 && isfinite(len))
        for (int k = 0; k < 3; ++k)
            t->normal[k] /= len;
    else
        t->normal[0] = t->normal[1] = t->normal[2] = 0.0;   /* no plane test */
    t->d = t->normal[0] * p[0][0] + t->normal[1] * p[0][1] + t->normal[2] * p[0][2];
    return true;
}

/* ---- midpoint ray and closest point ---- */

/* Möller-Trumbore in double; the tolerances keep hits on edges and at the
 * segment's ends (a triangle in a face plane). The triangle's edges e1, e2
 * are passed in so that the enumeration computes them once per triangle
 * instead of once per shaft (same operations, so the same bits). */
static inline bool segment_hit_edges(const double a[3], const double b[3], const double v0[3],
                                     const double e1[3], const double e2[3], double *s, double *u,
                                     double *w)
{
    double dir[3], tv[3];
    for (int k = 0; k < 3; ++k) {
        dir[k] = b[k] - a[k];
        tv[k] = a[k] - v0[k];
    }
    double pv[3] = { dir[1] * e2[2] - dir[2] * e2[1], dir[2] * e2[0] - dir[0] * e2[2],
                     dir[0] * e2[1] - dir[1] * e2[0] };
    double det = e1[0] * pv[0] + e1[1] * pv[1] + e1[2] * pv[2];
    if (fabs(det) < 1e-300)
        return false;
    double inv = 1.0 / det;
    double uu = (tv[0] * pv[0] + tv[1] * pv[1] + tv[2] * pv[2]) * inv;
    if (uu < -1e-9 || uu > 1.0 + 1e-9)
        return false;
    double qv[3] = { tv[1] * e1[2] - tv[2] * e1[1], tv[2] * e1[0] - tv[0] * e1[2],
                     tv[0] * e1[1] - tv[1] * e1[0] };
    double ww = (dir[0] * qv[0] + dir[1] * qv[1] + dir[2] * qv[2]) * inv;
    if (ww < -1e-9 || uu + ww > 1.0 + 1e-9)
        return false;
    double ss = (e2[0] * qv[0] + e2[1] * qv[1] + e2[2] * qv[2]) * inv;
    if (ss < -1e-3 || ss > 1.0 + 1e-3)
        return false;
    *s = ss;
    *u = uu;
    *w = ww;
    return true;
}

bool rl_ls_segment_hit(const double a[3], const double b[3], const double v[3][3], double *s,
                       double *u, double *w)
{
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = v[1][k] - v[0][k];
        e2[k] = v[2][k] - v[0][k];
    }
    return segment_hit_edges(a, b, v[0], e1, e2, s, u, w);
}

void rl_ls_closest_point(const double v[3][3], const double q[3], double *u, double *w)
{
    /* Region test over the triangle's Voronoi regions (vertices, edges,
     * face), with barycentrics p = (1-u-w)·v0 + u·v1 + w·v2. */
    double ab[3], ac[3], ap[3], bp[3], cp[3];
    for (int k = 0; k < 3; ++k) {
        ab[k] = v[1][k] - v[0][k];
        ac[k] = v[2][k] - v[0][k];
        ap[k] = q[k] - v[0][k];
        bp[k] = q[k] - v[1][k];
        cp[k] = q[k] - v[2][k];
    }
#define DOT3(x, y) ((x)[0] * (y)[0] + (x)[1] * (y)[1] + (x)[2] * (y)[2])
    double d1 = DOT3(ab, ap), d2 = DOT3(ac, ap), d3 = DOT3(ab, bp), d4 = DOT3(ac, bp);
    double d5 = DOT3(ab, cp), d6 = DOT3(ac, cp);
#undef DOT3
    if (d1 <= 0.0 && d2 <= 0.0) { *u = 0.0; *w = 0.0; return; }
    if (d3 >= 0.0 && d4 <= d3) { *u = 1.0; *w = 0.0; return; }
    double vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) { *u = d1 / (d1 - d3); *w = 0.0; return; }
    if (d6 >= 0.0 && d5 <= d6) { *u = 0.0; *w = 1.0; return; }
    double vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) { *u = 0.0; *w = d2 / (d2 - d6); return; }
    double va = d3 * d6 - d5 * d4;
    if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
        double x = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        *u = 1.0 - x;
        *w = x;
        return;
    }
    double den = va + vb + vc;
    if (!(fabs(den) > 0.0)) { *u = 0.0; *w = 0.0; return; }
    *u = vb / den;
    *w = vc / den;
}

/* ---- enumeration ---- */

/* The λ with c0 + c1·λ <= 0, as a bound: kind 1 an upper bound *x,
 * -1 a lower bound, 2 none at all (c1 = 0 < c0), 0 every λ. */
static void lambda_bound(double c0, double c1, double *x, signed char *kind)
{
    *x = 0.0;
    if (c1 > 0.0) {
        *x = -c0 / c1;
        *kind = 1;
    } else if (c1 < 0.0) {
        *x = -c0 / c1;
        *kind = -1;
    } else {
        *kind = c0 > 0.0 ? 2 : 0;
    }
}

/* Narrows [*lo, *hi] by a bound from lambda_bound. */
static inline void apply_bound(double x, signed char kind, double *lo, double *hi)
{
    if (kind == 1)
        *hi = MIN2(*hi, x);
    else if (kind == -1)
        *lo = MAX2(*lo, x);
    else if (kind == 2)
        *hi = -INFINITY;
}

/* Per-patch values of one triangle, computed once per triangle so that a
 * shaft's midpoint ray costs a division and a few multiply-adds instead of
 * a Möller-Trumbore test: for patch centre c (cell units),
 *   lo, hi  the support of the triangle's plane over the patch (signed
 *           distances of its nearest and farthest corner, unit normal);
 *   d       the signed distance of c itself;
 *   u, w    the barycentrics of c's projection onto the plane.
 * The barycentrics are affine in the point and constant along the normal,
 * so the midpoint ray a->b meets the plane at s = d_a / (d_a - d_b) with
 * barycentrics (1-s)·u_a + s·u_b and (1-s)·w_a + s·w_b: the same hit as the
 * ray/triangle test up to rounding, with its tolerances. */
typedef struct patch_planes {
    double *lo, *hi, *d, *u, *w;  /* 6·N^2 each, by f·N^2 + p */
} patch_planes;

static inline bool midpoint_hit(const patch_planes *pp, int ia, int ib, double *s, double *u,
                                double *w)
{
    double da = pp->d[ia], den = da - pp->d[ib];
    if (!(fabs(den) > 1e-300))
        return false;   /* parallel to the plane, or no plane */
    double ss = da / den;
    if (ss < -1e-3 || ss > 1.0 + 1e-3)
        return false;
    double uu = pp->u[ia] + (pp->u[ib] - pp->u[ia]) * ss;
    if (uu < -1e-9 || uu > 1.0 + 1e-9)
        return false;
    double ww = pp->w[ia] + (pp->w[ib] - pp->w[ia]) * ss;
    if (ww < -1e-9 || uu + ww > 1.0 + 1e-9)
        return false;
    *s = ss;
    *u = uu;
    *w = ww;
    return true;
}

static inline void emit(const rl_ls_geometry *g, const rl_ls_tri *t, const patch_planes *pp,
                        uint32_t tri_id, int fa, int pa, int fb, int pb, uint32_t base,
                        rl_ls_entry *out, uint32_t *count)
{
    int n = g->n, np = n * n;
    /* Schröder 2017, Alg. 3: the triangle's plane against both patches. */
    int ia = fa * np + pa, ib = fb * np + pb;
    if (MIN2(pp->lo[ia], pp->lo[ib]) > RL_LS_EPS || MAX2(pp->hi[ia], pp->hi[ib]) < -RL_LS_EPS)
        return;
    rl_ls_entry *e = &out[(*count)++];
    e->shaft = base + (uint32_t)pa * (uint32_t)np + (uint32_t)pb;
    e->tri = tri_id;
    double s, u, w;
    if (midpoint_hit(pp, ia, ib, &s, &u, &w)) {
        /* Alg. 3: ordered by the midpoint ray's hit. */
        e->key_front = e->key_back = (float)s;
        e->u = (float)u;
        e->w = (float)w;
        e->shaft |= RL_LS_ENTRY_HIT;
        return;
    }
    /* Our stand-in for a triangle the midpoint ray misses: its clipped
     * part's extent along the shaft axis. */
    const float *ca = g->patch_center + (size_t)ia * 3, *cb = g->patch_center + (size_t)ib * 3;
    double a[3] = { ca[0], ca[1], ca[2] };
    double ax[3] = { cb[0] - a[0], cb[1] - a[1], cb[2] - a[2] };
    double inv = 1.0 / (ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2]);
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < t->npoly; ++i) {
        double p = ((t->poly[i][0] - a[0]) * ax[0] + (t->poly[i][1] - a[1]) * ax[1] +
                    (t->poly[i][2] - a[2]) * ax[2]) * inv;
        lo = MIN2(lo, p);
        hi = MAX2(hi, p);
    }
    e->key_front = (float)lo;
    e->key_back = (float)hi;
}

uint32_t rl_ls_enumerate(const rl_ls_geometry *g, const rl_ls_tri *t, uint32_t tri_id,
                         rl_ls_entry *out, double *scratch, int *iscratch)
{
    const int n = g->n, np = n * n;
    const double eps = RL_LS_EPS, h = 0.5 / n;
    uint32_t count = 0;
    double e1[3], e2[3];
    for (int k = 0; k < 3; ++k) {
        e1[k] = t->v[1][k] - t->v[0][k];
        e2[k] = t->v[2][k] - t->v[0][k];
    }
    /* Gradients of the barycentrics: u(x) = (x - v0)·(e2 x m)/|m|^2 and
     * w(x) = (x - v0)·(m x e1)/|m|^2 with m = e1 x e2 (1 at v1, resp. v2,
     * 0 at the other two vertices, constant along m). */
    double m[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0] };
    double mm = m[0] * m[0] + m[1] * m[1] + m[2] * m[2];
    double gu[3] = { 0.0, 0.0, 0.0 }, gw[3] = { 0.0, 0.0, 0.0 };
    if (mm > 0.0 && isfinite(mm)) {
        double im = 1.0 / mm;
        gu[0] = (e2[1] * m[2] - e2[2] * m[1]) * im;
        gu[1] = (e2[2] * m[0] - e2[0] * m[2]) * im;
        gu[2] = (e2[0] * m[1] - e2[1] * m[0]) * im;
        gw[0] = (m[1] * e1[2] - m[2] * e1[1]) * im;
        gw[1] = (m[2] * e1[0] - m[0] * e1[2]) * im;
        gw[2] = (m[0] * e1[1] - m[1] * e1[0]) * im;
    }
    /* The plane's support, distance and barycentrics over every patch. */
    const int nf = 6 * np;
    patch_planes pp = { scratch, scratch + nf, scratch + 2 * nf, scratch + 3 * nf, scratch + 4 * nf };
    const double *nn = t->normal, *v0 = t->v[0];
    for (int f = 0; f < 6; ++f) {
        int u, v;
        rl_ls_face_uv(f, &u, &v);
        double ext = h * (fabs(nn[u]) + fabs(nn[v]));
        for (int p = 0; p < np; ++p) {
            const float *c = g->patch_center + ((size_t)f * (size_t)np + (size_t)p) * 3;
            double x[3] = { c[0] - v0[0], c[1] - v0[1], c[2] - v0[2] };
            double d = nn[0] * c[0] + nn[1] * c[1] + nn[2] * c[2] - t->d;
            int i = f * np + p;
            pp.lo[i] = d - ext;
            pp.hi[i] = d + ext;
            pp.d[i] = d;
            pp.u[i] = x[0] * gu[0] + x[1] * gu[1] + x[2] * gu[2];
            pp.w[i] = x[0] * gw[0] + x[1] * gw[1] + x[2] * gw[2];
        }
    }
    int *list_u = iscratch, *list_v = iscratch + 2 * np;
    const int nv = t->npoly;
    for (int fa = 0; fa < 6; ++fa)
        for (int fb = fa + 1; fb < 6; ++fb) {
            uint32_t base = (uint32_t)rl_ls_pair_index(fa, fb) * (uint32_t)(np * np);
            int ca = fa >> 1, cb = fb >> 1;
            if (ca == cb) {
                /* Opposite faces: two 2D shafts over c = λ. */
                int axes[2];
                rl_ls_face_uv(fa, &axes[0], &axes[1]);
                int nu[2] = { 0, 0 };
                for (int q = 0; q < 2; ++q) {
                    int ax = axes[q];
                    int *list = q ? list_v : list_u;
                    for (int i = 0; i < n; ++i)
                        for (int j = 0; j < n; ++j) {
                            double a0 = (double)i / n, a1 = (double)(i + 1) / n;
                            double b0 = (double)j / n, b1 = (double)(j + 1) / n;
                            double below = -INFINITY, above = INFINITY;
                            for (int k = 0; k < nv; ++k) {
                                double c = t->poly[k][ca], x = t->poly[k][ax];
                                below = MAX2(below, x - (a0 + (b0 - a0) * c));
                                above = MIN2(above, x - (a1 + (b1 - a1) * c));
                            }
                            if (below < -1.5 * eps || above > 1.5 * eps)
                                continue;
                            list[2 * nu[q]] = i;
                            list[2 * nu[q] + 1] = j;
                            ++nu[q];
                        }
                }
                for (int x = 0; x < nu[0]; ++x)
                    for (int y = 0; y < nu[1]; ++y) {
                        int pa = list_u[2 * x] + n * list_v[2 * y];
                        int pb = list_u[2 * x + 1] + n * list_v[2 * y + 1];
                        emit(g, t, &pp, tri_id, fa, pa, fb, pb, base, out, &count);
                    }
                continue;
            }
            /* Perpendicular faces: A on axis ca (side sa), B on axis cb. */
            int r = 3 - ca - cb, sa = fa & 1, sb = fb & 1;
            double P[9], Q[9];
            double pmin = INFINITY, pmax = -INFINITY, qmin = INFINITY, qmax = -INFINITY;
            for (int k = 0; k < nv; ++k) {
                P[k] = sa ? 1.0 - t->poly[k][ca] : t->poly[k][ca];
                Q[k] = sb ? 1.0 - t->poly[k][cb] : t->poly[k][cb];
                pmin = MIN2(pmin, P[k]); pmax = MAX2(pmax, P[k]);
                qmin = MIN2(qmin, Q[k]); qmax = MAX2(qmax, Q[k]);
            }
            pmin -= eps; pmax += eps; qmin -= eps; qmax += eps;
            double rmin = t->lo[r] - eps, rmax = t->hi[r] + eps;
            /* The two λ bounds of each (A's r-patch, B's r-patch) depend on
             * the triangle but not on (iq, jp): computed once here rather
             * than per surviving (iq, jp) (two divisions each). */
            double rlam[RL_LS_MAX_N * RL_LS_MAX_N][2];
            signed char rkind[RL_LS_MAX_N * RL_LS_MAX_N][2];
            for (int ir = 0; ir < n; ++ir)
                for (int jr = 0; jr < n; ++jr) {
                    double ar0 = (double)ir / n, ar1 = (double)(ir + 1) / n;
                    double br0 = (double)jr / n, br1 = (double)(jr + 1) / n;
                    lambda_bound(ar0 - rmax, br0 - ar0, &rlam[ir * n + jr][0], &rkind[ir * n + jr][0]);
                    lambda_bound(rmin - ar1, ar1 - br1, &rlam[ir * n + jr][1], &rkind[ir * n + jr][1]);
                }
            for (int iq = 0; iq < n; ++iq)
                for (int jp = 0; jp < n; ++jp) {
                    /* A's extent in Q (its cb coordinate), B's in P. */
                    double q0 = sb ? 1.0 - (double)(iq + 1) / n : (double)iq / n;
                    double q1 = q0 + 1.0 / n;
                    double p0 = sa ? 1.0 - (double)(jp + 1) / n : (double)jp / n;
                    double p1 = p0 + 1.0 / n;
                    double outer_tol = eps * sqrt(q1 * q1 + p1 * p1);
                    double inner_tol = eps * sqrt(q0 * q0 + p0 * p0);
                    double outer_min = INFINITY, inner_max = -INFINITY;
                    for (int k = 0; k < nv; ++k) {
                        outer_min = MIN2(outer_min, P[k] * q1 + Q[k] * p1 - p1 * q1);
                        inner_max = MAX2(inner_max, P[k] * q0 + Q[k] * p0 - p0 * q0);
                    }
                    if (outer_min > outer_tol || inner_max < -inner_tol)
                        continue;
                    /* λ from P = λ·b_p and Q = (1-λ)·a_q. */
                    double l0 = MAX2(0.0, pmin / p1), l1 = MIN2(1.0, 1.0 - qmin / q1);
                    if (q0 > 0.0)
                        l0 = MAX2(l0, 1.0 - qmax / q0);
                    if (p0 > 0.0)
                        l1 = MIN2(l1, pmax / p0);
                    if (l0 > l1)
                        continue;
                    for (int ir = 0; ir < n; ++ir)
                        for (int jr = 0; jr < n; ++jr) {
                            /* Some λ with lower(λ) <= rmax and upper(λ) >= rmin. */
                            double lo = l0, hi = l1;
                            apply_bound(rlam[ir * n + jr][0], rkind[ir * n + jr][0], &lo, &hi);
                            apply_bound(rlam[ir * n + jr][1], rkind[ir * n + jr][1], &lo, &hi);
                            if (lo > hi + 1e-12)
                                continue;
                            int pa = cb < r ? iq + n * ir : ir + n * iq;
                            int pb = ca < r ? jp + n * jr : jr + n * jp;
                            emit(g, t, &pp, tri_id, fa, pa, fb, pb, base, out, &count);
                        }
                }
        }
    return count;
}
