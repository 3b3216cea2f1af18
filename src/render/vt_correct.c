/* vt_correct.c: the correctness extensions of Vertex Tracing that Ullmann
 * 2003 proposes in Sec. 6.1 against features that fall between the two
 * samples of an edge, so that the criteria of Sec. 3.3.1 see two equal
 * ends and never split it (Fig. 3.8, 6.1, 6.5).
 *
 * Sec. 6.1.1, nonlinearities (option nonlinear):
 *   extremum  the geometric test of eq. 6.4-6.5: at each end the lobe
 *             direction is turned into the plane normal to its axis,
 *             g = -(a.r) a + r; the peak of the lobe lies between the ends
 *             when cos(gamma) = g_1 . g_2 <= 0. For the specular term
 *             (Phong, eq. 6.1) the axis is the view direction a and the
 *             lobe the mirrored light direction r, as in Fig. 6.2-6.3. The
 *             thesis works the geometry out "beispielhaft" for the
 *             specular angle phi and asks the same of the diffuse angle
 *             theta (eq. 6.3): there the axis is the normal n and the lobe
 *             the light direction l. Per light (the thesis: "für jede
 *             Lichtquelle").
 *   interval  standard interval arithmetic (Fig. 6.4): the unshadowed local
 *             Phong term of each light, sum over lights, is evaluated with
 *             every quantity an interval over the edge (positions and
 *             normals between the two ends' values); the enclosure
 *             [lo, hi] of f bounds the error of the linear interpolant f'
 *             by eps_IA = max(hi - min(f_1, f_2), max(f_1, f_2) - lo) >=
 *             eps_A, and an edge with eps_IA > eps_ia is split.
 *   derivative eq. 6.3: the sign of the derivative of each light's diffuse
 *             and specular term along the edge at both ends; opposite
 *             signs put an extremum between them. The thesis offers it
 *             first and the geometric test as the faster alternative.
 *   affine    the interval bound in affine arithmetic ([CS93], which the
 *             thesis names as the tighter form): every quantity keeps its
 *             linear dependence on the edge parameter, so the linear
 *             interpolant cancels out of the error bound, which then
 *             shrinks with the square of the edge; same eps_ia.
 * All test the local term only: shadows are discontinuities (Sec. 6.1.2)
 * and reflections are the ray tree's business (Sec. 3.3.1).
 *
 * Sec. 6.1.2, discontinuities (option shaft_cull), after [HW91] (Fig. 6.6):
 * a face's shaft is the convex hull of its bounding box and the light's
 * (shadow feelers), or of its box and the box of the face moved along the
 * reflected or transmitted view rays by the scene's extent d
 * (reflection/transmission); a face whose shaft holds geometry of another
 * object has all its edges split. The thesis tests the shaft against the
 * objects' boxes (its footnote 3); a box around a whole object is too
 * coarse where a light sits inside a lamp shade (every shaft would hold the
 * shade), so we go one level further down the same kind of hierarchy:
 * object box, then boxes of runs of VT_SHAFT_GROUP consecutive triangles,
 * then each triangle's box. Still conservative: a box that meets the shaft
 * counts, whether or not its triangle does. The face's own object is left
 * out (its box always meets the face's shaft), so self-shadowing stays with
 * the ray-tree criterion. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/vt_run.h"

/* ------------------------------------------------ Sec. 6.1.1 extremum -- */

/* The unit direction from p towards light L, E, the light's irradiance
 * scale at p without the cosine (colour intensity / d^2 for point and spot,
 * colour intensity for directional; a quad as a point at its centre with
 * its radiance times its area), and the distance d (0 for directional). */
static rl_vec3 light_geom(const rl_light *L, rl_vec3 p, float *E, float *dist)
{
    float power = rl_vmax_comp(L->color) * L->intensity;
    if (L->type == RL_LIGHT_DIRECTIONAL) {
        *E = power;
        *dist = 0.0f;
        return rl_normalize(rl_neg(L->direction));
    }
    rl_vec3 at = L->position;
    if (L->type == RL_LIGHT_QUAD) {
        at = rl_add(at, rl_scale(rl_add(L->edge_u, L->edge_v), 0.5f));
        power *= rl_length(rl_cross(L->edge_u, L->edge_v));
    }
    rl_vec3 d = rl_sub(at, p);
    float d2 = rl_dot(d, d);
    *E = d2 > 0.0f ? power / d2 : 0.0f;
    *dist = sqrtf(d2);
    return d2 > 0.0f ? rl_scale(d, 1.0f / *dist) : rl_v3(0.0f, 0.0f, 0.0f);
}

static rl_vec3 light_at(const rl_light *L, rl_vec3 p, float *E)
{
    float dist;
    return light_geom(L, p, E, &dist);
}

vt_edge_end vt_edge_end_of(rl_vec3 p, rl_vec3 n, rl_vec3 eye, const rl_material *mat)
{
    vt_edge_end e;
    e.p = p;
    e.a = rl_normalize(rl_sub(eye, p));
    e.n = rl_dot(n, e.a) < 0.0f ? rl_neg(n) : n;
    e.kd = rl_vmax_comp(mat->diffuse);
    e.ks = rl_vmax_comp(mat->specular);
    e.m = mat->shininess;
    return e;
}

static vt_edge_end end_of(const vt_run *run, const vt_vertex *v)
{
    const rl_scene_data *d = run->data;
    return vt_edge_end_of(v->p, v->n, run->view.eye, &d->materials[d->triangle_material[v->triangle]]);
}

/* eq. 6.4-6.5 for one lobe: g_i = -(x_i . y_i) x_i + y_i with axis x and
 * lobe y, split when g_1 . g_2 <= 0. An end whose lobe lies on its axis
 * (g = 0) is the peak itself, already sampled; and where both are (a
 * directional light straight onto a plane) the term is constant, not a
 * hidden extremum. */
static bool lobes_part(rl_vec3 x1, rl_vec3 y1, rl_vec3 x2, rl_vec3 y2)
{
    const float tiny = 1e-4f;
    rl_vec3 g1 = rl_sub(y1, rl_scale(x1, rl_dot(x1, y1)));
    rl_vec3 g2 = rl_sub(y2, rl_scale(x2, rl_dot(x2, y2)));
    if (!(rl_length(g1) > tiny) || !(rl_length(g2) > tiny))
        return false;
    return rl_dot(g1, g2) <= 0.0f;
}

bool vt_extremum_test(const rl_light *lights, uint32_t num_lights, const vt_edge_end *e1, const vt_edge_end *e2)
{
    bool diffuse = e1->kd > 0.0f || e2->kd > 0.0f;
    bool specular = e1->ks > 0.0f || e2->ks > 0.0f;
    for (uint32_t i = 0; i < num_lights; ++i) {
        float E1, E2;
        rl_vec3 l1 = light_at(&lights[i], e1->p, &E1), l2 = light_at(&lights[i], e2->p, &E2);
        float nl1 = rl_dot(e1->n, l1), nl2 = rl_dot(e2->n, l2);
        if (!(nl1 > 0.0f) && !(nl2 > 0.0f))
            continue;                       /* the light is behind both ends */
        if (diffuse && lobes_part(e1->n, l1, e2->n, l2))
            return true;
        if (specular) {
            /* r: l mirrored about n, as the tracer's Phong term */
            rl_vec3 r1 = rl_sub(rl_scale(e1->n, 2.0f * nl1), l1);
            rl_vec3 r2 = rl_sub(rl_scale(e2->n, 2.0f * nl2), l2);
            if ((rl_dot(r1, e1->a) > 0.0f || rl_dot(r2, e2->a) > 0.0f) && lobes_part(e1->a, r1, e2->a, r2))
                return true;
        }
    }
    return false;
}

/* ---------------------------------------------- Sec. 6.1.1 derivative -- */

/* One light at one end of an edge: the cosines of eq. 6.1 and the slopes
 * of the diffuse and specular terms along the edge, up to positive factors. */
typedef struct term_slopes {
    float cd, sd;             /* cos(theta) = n.l and the slope of I_d */
    float cs, ss;             /* cos(phi) = r.a and the slope of I_s */
    float tol;                /* a slope within +-tol is zero: rounding */
} term_slopes;

/* eq. 6.3 differentiates I_d = I_source k_d cos(theta) and I_s = I_source
 * k_s cos^m(phi) by the angles; the sign that tells a hidden extremum is
 * that of the derivative along the edge, which the chain rule gives. With
 * p(t) = p_1 + t dp, n(t) = (n_1 + t dn) / |n_1 + t dn| (the midpoint
 * normal of eq. 3.8 at every t), ' = d/dt at an end, where |n| = 1:
 *
 *   n' = dn - n (n.dn)
 *   l' = (-dp + l (l.dp)) / d_l            point light at distance d_l
 *   a' = (-dp + a (a.dp)) / d_a            the eye at distance d_a
 *   (cos theta)' = n'.l + n.l'
 *   (cos phi)'   = 2 ((cos theta)' n.a + cos theta (n'.a + n.a')) - (l'.a + l.a')
 *                  (cos phi = r.a = 2 (n.l)(n.a) - l.a, r = l mirrored about n)
 *   E' = 2 E (l.dp) / d_l = kappa E        E = I / d_l^2, the light's falloff
 *
 *   dI_d/dt = dI_d/dtheta dtheta/dt + E' k_d cos theta
 *           = -E k_d sin theta dtheta/dt + kappa E k_d cos theta     (eq. 6.3)
 *           = E k_d ((cos theta)' + kappa cos theta),
 *   dI_s/dt = -E k_s (cos^m phi m sin phi / cos phi) dphi/dt + kappa E k_s cos^m phi   (eq. 6.3)
 *           = E k_s cos^(m-1) phi (m (cos phi)' + kappa cos phi).
 *
 * E, k and cos^(m-1) phi are positive where the term is lit, so each sign
 * is that of the bracket. The thesis holds I_source constant; with kappa
 * the slope is that of the term the tracer computes (kappa = 0 for a
 * directional light). Where the cosine is not positive the term is clamped
 * to zero at that end; the cosine's own slope then says whether the lobe
 * comes towards the other end. */
static term_slopes slopes_at(const rl_light *L, const vt_edge_end *e, rl_vec3 eye, rl_vec3 dp, rl_vec3 dn, float m)
{
    term_slopes s;
    float E, dl;
    const rl_vec3 zero = rl_v3(0.0f, 0.0f, 0.0f);
    rl_vec3 l = light_geom(L, e->p, &E, &dl), n = e->n, a = e->a;
    float da = rl_length(rl_sub(eye, e->p));
    rl_vec3 n_d = rl_sub(dn, rl_scale(n, rl_dot(n, dn)));
    rl_vec3 l_d = dl > 0.0f ? rl_scale(rl_sub(rl_scale(l, rl_dot(l, dp)), dp), 1.0f / dl) : zero;
    rl_vec3 a_d = da > 0.0f ? rl_scale(rl_sub(rl_scale(a, rl_dot(a, dp)), dp), 1.0f / da) : zero;
    float kappa = dl > 0.0f ? 2.0f * rl_dot(l, dp) / dl : 0.0f;
    float nl = rl_dot(n, l), na = rl_dot(n, a), la = rl_dot(l, a);
    float nl_d = rl_dot(n_d, l) + rl_dot(n, l_d);
    float na_d = rl_dot(n_d, a) + rl_dot(n, a_d);
    float la_d = rl_dot(l_d, a) + rl_dot(l, a_d);
    float cs_d = 2.0f * (nl_d * na + nl * na_d) - la_d;
    s.cd = nl;
    s.sd = nl > 0.0f ? nl_d + kappa * nl : nl_d;
    s.cs = 2.0f * nl * na - la;
    s.ss = s.cs > 0.0f ? m * cs_d + kappa * s.cs : cs_d;
    /* the slopes are sums of products of unit vectors with dn and dp / d:
     * float rounding leaves them a few 1e-7 of that size */
    s.tol = 1e-4f * (rl_length(dn) + rl_length(dp) * ((dl > 0.0f ? 1.0f / dl : 0.0f) + (da > 0.0f ? 1.0f / da : 0.0f)));
    return s;
}

/* Opposite signs at the two ends (eq. 6.3): a maximum of the term lies
 * between them (rising at t = 0, falling at t = 1), or a minimum between
 * two ends where the term is lit (a minimum next to an unlit end is the
 * clamp at zero, at the end itself). */
static bool slopes_turn(float s1, float s2, float c1, float c2, float tol)
{
    if (s1 > tol && s2 < -tol)
        return true;
    return s1 < -tol && s2 > tol && c1 > 0.0f && c2 > 0.0f;
}

bool vt_derivative_test(const rl_light *lights, uint32_t num_lights, rl_vec3 eye, const vt_edge_end *e1,
                        const vt_edge_end *e2)
{
    bool diffuse = e1->kd > 0.0f || e2->kd > 0.0f;
    bool specular = e1->ks > 0.0f || e2->ks > 0.0f;
    rl_vec3 dp = rl_sub(e2->p, e1->p), dn = rl_sub(e2->n, e1->n);
    float m = rl_maxf(e1->m, 1e-3f);
    for (uint32_t i = 0; i < num_lights; ++i) {
        term_slopes s1 = slopes_at(&lights[i], e1, eye, dp, dn, m), s2 = slopes_at(&lights[i], e2, eye, dp, dn, m);
        if (!(s1.cd > 0.0f) && !(s2.cd > 0.0f))
            continue;                       /* the light is behind both ends, as for extremum */
        float tol = rl_maxf(s1.tol, s2.tol);
        if (diffuse && slopes_turn(s1.sd, s2.sd, s1.cd, s2.cd, tol))
            return true;
        if (specular && (s1.cs > 0.0f || s2.cs > 0.0f) &&
            slopes_turn(s1.ss, s2.ss, s1.cs, s2.cs, tol * (m + 2.0f)))
            return true;
    }
    return false;
}

/* ------------------------------------------------ Sec. 6.1.1 interval -- */

/* Standard interval arithmetic ([Han75]; the thesis' footnote 2). Float
 * rounding is not directed outwards: the bound can be off by a few ulps,
 * far below any threshold that makes sense here. */
typedef struct ia {
    float lo, hi;
} ia;

typedef struct ia3 {
    ia x, y, z;
} ia3;

static ia ia_of(float a, float b)
{
    return (ia){ rl_minf(a, b), rl_maxf(a, b) };
}

static ia ia_add(ia a, ia b)
{
    return (ia){ a.lo + b.lo, a.hi + b.hi };
}

static ia ia_sub(ia a, ia b)
{
    return (ia){ a.lo - b.hi, a.hi - b.lo };
}

static ia ia_mul(ia a, ia b)
{
    float p[4] = { a.lo * b.lo, a.lo * b.hi, a.hi * b.lo, a.hi * b.hi };
    ia r = { p[0], p[0] };
    for (int i = 1; i < 4; ++i) {
        r.lo = rl_minf(r.lo, p[i]);
        r.hi = rl_maxf(r.hi, p[i]);
    }
    return r;
}

static ia ia_scale(ia a, float s)
{
    return s >= 0.0f ? (ia){ a.lo * s, a.hi * s } : (ia){ a.hi * s, a.lo * s };
}

/* x^2 knows both factors are the same x: tighter than ia_mul(x, x). */
static ia ia_sqr(ia a)
{
    if (a.lo >= 0.0f)
        return (ia){ a.lo * a.lo, a.hi * a.hi };
    if (a.hi <= 0.0f)
        return (ia){ a.hi * a.hi, a.lo * a.lo };
    return (ia){ 0.0f, rl_maxf(a.lo * a.lo, a.hi * a.hi) };
}

/* 1 / a for a > 0; an interval reaching 0 has no finite bound. */
static ia ia_recip_pos(ia a)
{
    if (!(a.lo > 0.0f))
        return (ia){ 0.0f, INFINITY };
    return (ia){ 1.0f / a.hi, 1.0f / a.lo };
}

static ia ia_clamp(ia a, float lo, float hi)
{
    return (ia){ rl_minf(rl_maxf(a.lo, lo), hi), rl_minf(rl_maxf(a.hi, lo), hi) };
}

/* a^m for a in [0, 1], m > 0: monotone. */
static ia ia_pow01(ia a, float m)
{
    return (ia){ powf(a.lo, m), powf(a.hi, m) };
}

static ia3 ia3_of(rl_vec3 a, rl_vec3 b)
{
    return (ia3){ ia_of(a.x, b.x), ia_of(a.y, b.y), ia_of(a.z, b.z) };
}

static ia3 ia3_sub(ia3 a, ia3 b)
{
    return (ia3){ ia_sub(a.x, b.x), ia_sub(a.y, b.y), ia_sub(a.z, b.z) };
}

static ia ia3_dot(ia3 a, ia3 b)
{
    return ia_add(ia_add(ia_mul(a.x, b.x), ia_mul(a.y, b.y)), ia_mul(a.z, b.z));
}

static ia ia3_len2(ia3 a)
{
    return ia_add(ia_add(ia_sqr(a.x), ia_sqr(a.y)), ia_sqr(a.z));
}

/* a / |a|; a unit vector's components also lie in [-1, 1], which the
 * quotient of two wide intervals forgets. */
static ia3 ia3_normalize(ia3 a)
{
    ia len2 = ia3_len2(a);
    ia inv = ia_recip_pos((ia){ sqrtf(rl_maxf(len2.lo, 0.0f)), sqrtf(rl_maxf(len2.hi, 0.0f)) });
    return (ia3){ ia_clamp(ia_mul(a.x, inv), -1.0f, 1.0f), ia_clamp(ia_mul(a.y, inv), -1.0f, 1.0f),
                  ia_clamp(ia_mul(a.z, inv), -1.0f, 1.0f) };
}

/* The unshadowed local Phong term of light L as the tracer adds it
 * (trace_shade.c): E (k_d n.l + k_s max(0, r.a)^m) where n.l > 0, with
 * r.a = 2 (n.l)(n.a) - l.a, over positions p and normals n. k_d, k_s and
 * the light's colour enter through their largest channel. */
static ia phong_ia(const rl_light *L, ia3 p, ia3 n, ia3 eye, float kd, float ks, float m)
{
    ia3 a = ia3_normalize(ia3_sub(eye, p));
    ia3 l;
    ia E;
    float power = rl_vmax_comp(L->color) * L->intensity;
    if (L->type == RL_LIGHT_DIRECTIONAL) {
        rl_vec3 dir = rl_normalize(rl_neg(L->direction));
        l = ia3_of(dir, dir);
        E = (ia){ power, power };
    } else {
        rl_vec3 at = L->position;
        if (L->type == RL_LIGHT_QUAD) {
            at = rl_add(at, rl_scale(rl_add(L->edge_u, L->edge_v), 0.5f));
            power *= rl_length(rl_cross(L->edge_u, L->edge_v));
        }
        ia3 to = ia3_sub(ia3_of(at, at), p);
        l = ia3_normalize(to);
        E = ia_scale(ia_recip_pos(ia3_len2(to)), power);
    }
    ia nl = ia_clamp(ia3_dot(n, l), -1.0f, 1.0f);
    if (!(nl.hi > 0.0f))
        return (ia){ 0.0f, 0.0f };
    ia f = ia_scale(ia_clamp(nl, 0.0f, 1.0f), kd);
    if (ks > 0.0f) {
        ia ra = ia_sub(ia_scale(ia_mul(nl, ia_clamp(ia3_dot(n, a), -1.0f, 1.0f)), 2.0f),
                       ia_clamp(ia3_dot(l, a), -1.0f, 1.0f));
        f = ia_add(f, ia_scale(ia_pow01(ia_clamp(ra, 0.0f, 1.0f), m), ks));
    }
    f = ia_mul(f, E);
    if (nl.lo <= 0.0f)
        f.lo = 0.0f;                        /* part of the edge is unlit */
    return f;
}

/* The enclosure of light L's term over the edge by standard interval
 * arithmetic, and its bound on the interpolation error (Fig. 6.4). */
static void interval_term(const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2,
                          vt_term_bound *out)
{
    /* One material for the interval: an edge between two materials is a
     * discontinuity, not a smooth term; the larger coefficients bound
     * both. */
    float kd = rl_maxf(e1->kd, e2->kd), ks = rl_maxf(e1->ks, e2->ks), m = rl_maxf(e1->m, 1e-3f);
    ia3 ie = ia3_of(eye, eye);
    /* the normal between the ends is normalize(lerp) (eq. 3.8) */
    ia3 p = ia3_of(e1->p, e2->p), n = ia3_normalize(ia3_of(e1->n, e2->n));
    ia f = phong_ia(L, p, n, ie, kd, ks, m);
    float f1 = phong_ia(L, ia3_of(e1->p, e1->p), ia3_of(e1->n, e1->n), ie, kd, ks, m).hi;
    float f2 = phong_ia(L, ia3_of(e2->p, e2->p), ia3_of(e2->n, e2->n), ie, kd, ks, m).hi;
    out->lo = f.lo;
    out->hi = f.hi;
    out->f1 = f1;
    out->f2 = f2;
    /* f' lies between f_1 and f_2, f within [lo, hi] */
    out->eps = rl_maxf(f.hi - rl_minf(f1, f2), rl_maxf(f1, f2) - f.lo);
}

/* -------------------------------------------------- Sec. 6.1.1 affine -- */

/* Affine arithmetic ([CS93]; de Figueiredo & Stolfi 2004) over the edge: a
 * quantity is x = c + a e + [-r, r], e in [-1, 1] the edge's one noise
 * symbol (t = (1 + e) / 2), r the radius of all approximation errors so
 * far, folded into one term: what must cancel is the edge parameter, which
 * keeps its symbol; the folded errors lose their correlation (that of one
 * normalisation shared by a vector's three components, say), the price of
 * a form of fixed size. Unlike
 * an interval, the form remembers how each quantity goes along the edge:
 * the linear interpolant is itself an affine form in e, so the
 * interpolation error keeps only what is not linear in e, and it shrinks
 * with the square of the edge where an interval's shrinks linearly.
 * Doubles keep rounding far below the terms; it is not directed outwards
 * (as for intervals). */
typedef struct aa {
    double c, a, r;
} aa;

typedef struct aa3 {
    aa x, y, z;
} aa3;

/* A quantity without a finite form (a distance that may reach 0): NaN
 * passes through every operation below, and the edge is split. */
static const aa AA_NONE = { NAN, NAN, NAN };

static aa aa_const(double c)
{
    return (aa){ c, 0.0, 0.0 };
}

/* x(t) from x_1 at t = 0 to x_2 at t = 1 */
static aa aa_lerp(double x1, double x2)
{
    return (aa){ 0.5 * (x1 + x2), 0.5 * (x2 - x1), 0.0 };
}

static double aa_lo(aa x)
{
    return x.c - fabs(x.a) - x.r;
}

static double aa_hi(aa x)
{
    return x.c + fabs(x.a) + x.r;
}

static aa aa_add(aa x, aa y)
{
    return (aa){ x.c + y.c, x.a + y.a, x.r + y.r };
}

static aa aa_sub(aa x, aa y)
{
    return (aa){ x.c - y.c, x.a - y.a, x.r + y.r };
}

static aa aa_scale(aa x, double s)
{
    return (aa){ s * x.c, s * x.a, fabs(s) * x.r };
}

/* x y: the product's e^2 is 1/2 + (e^2 - 1/2), the second part within
 * +-1/2; every product with an error term goes to the error term. */
static aa aa_mul(aa x, aa y)
{
    return (aa){ x.c * y.c + 0.5 * x.a * y.a, x.c * y.a + y.c * x.a,
                 0.5 * fabs(x.a * y.a) + (fabs(x.c) + fabs(x.a)) * y.r + (fabs(y.c) + fabs(y.a)) * x.r +
                     x.r * y.r };
}

/* x^2, tighter than x x: the error's square r^2 h^2 lies in [0, r^2]. */
static aa aa_sqr(aa x)
{
    return (aa){ x.c * x.c + 0.5 * x.a * x.a + 0.5 * x.r * x.r, 2.0 * x.c * x.a,
                 0.5 * x.a * x.a + 2.0 * (fabs(x.c) + fabs(x.a)) * x.r + 0.5 * x.r * x.r };
}

/* f(x) for f monotone and convex or concave on [lo, hi], the values x can
 * take, cut to the domain dlo..dhi that the true quantity keeps (a clamped
 * cosine lies in [0, 1]; rounding can push the form's range past it). The
 * Chebyshev approximation of de Figueiredo & Stolfi 2004: the chord (slope
 * alpha) and the tangent of the same slope at u, where f'(u) = alpha,
 * bracket f; the line halfway between them is off by at most half their
 * distance. u_of gives u for alpha. */
static aa aa_apply(aa x, double dlo, double dhi, double (*f)(double, double), double (*u_of)(double, double),
                   double param)
{
    if (!isfinite(aa_hi(x)))
        return AA_NONE;                     /* fmin and fmax would drop a NaN */
    double lo = fmin(fmax(aa_lo(x), dlo), dhi), hi = fmax(fmin(aa_hi(x), dhi), dlo);
    double flo = f(lo, param), fhi = f(hi, param);
    if (hi - lo <= 1e-12 * fmax(fabs(lo), fabs(hi)))
        return (aa){ 0.5 * (flo + fhi), 0.0, 0.5 * fabs(fhi - flo) };   /* a point: its range */
    double alpha = (fhi - flo) / (hi - lo);
    double u = fmin(fmax(u_of(alpha, param), lo), hi);
    double d1 = flo - alpha * lo, d2 = f(u, param) - alpha * u;     /* the lines' intercepts */
    return (aa){ alpha * x.c + 0.5 * (d1 + d2), alpha * x.a, fabs(alpha) * x.r + 0.5 * fabs(d1 - d2) };
}

static double f_recip(double x, double unused)
{
    (void)unused;
    return 1.0 / x;
}

static double u_recip(double alpha, double unused)   /* -1 / u^2 = alpha */
{
    (void)unused;
    return 1.0 / sqrt(-alpha);
}

static double f_rsqrt(double x, double unused)
{
    (void)unused;
    return 1.0 / sqrt(x);
}

static double u_rsqrt(double alpha, double unused)   /* -u^(-3/2) / 2 = alpha */
{
    (void)unused;
    return pow(-2.0 * alpha, -2.0 / 3.0);
}

static double f_pow(double x, double m)
{
    return pow(x, m);
}

static double u_pow(double alpha, double m)          /* m u^(m-1) = alpha */
{
    return pow(alpha / m, 1.0 / (m - 1.0));
}

/* 1 / x and 1 / sqrt(x) for x > 0 */
static aa aa_recip(aa x)
{
    return aa_lo(x) > 0.0 ? aa_apply(x, 0.0, INFINITY, f_recip, u_recip, 0.0) : AA_NONE;
}

static aa aa_rsqrt(aa x)
{
    return aa_lo(x) > 0.0 ? aa_apply(x, 0.0, INFINITY, f_rsqrt, u_rsqrt, 0.0) : AA_NONE;
}

/* x^m for the true x in [0, 1] (a clamped cosine), m > 0: convex for
 * m > 1, concave below; one Chebyshev step, not repeated squaring, whose
 * errors would compound over log2(m) products. */
static aa aa_pow01(aa x, double m)
{
    return m == 1.0 ? x : aa_apply(x, 0.0, 1.0, f_pow, u_pow, m);
}

/* max(0, x): where x changes sign, the chord from (lo, 0) to (hi, hi) lies
 * above and the function lowest under it at 0, by alpha (-lo): the line
 * half that below the chord is off by at most half that. */
static aa aa_relu(aa x)
{
    double lo = aa_lo(x), hi = aa_hi(x);
    if (lo >= 0.0)
        return x;
    if (hi <= 0.0)
        return aa_const(0.0);
    double alpha = hi / (hi - lo), half = -0.5 * alpha * lo;
    return (aa){ alpha * x.c + half, alpha * x.a, alpha * x.r + half };
}

static aa3 aa3_const(rl_vec3 v)
{
    return (aa3){ aa_const(v.x), aa_const(v.y), aa_const(v.z) };
}

static aa3 aa3_lerp(rl_vec3 v1, rl_vec3 v2)
{
    return (aa3){ aa_lerp(v1.x, v2.x), aa_lerp(v1.y, v2.y), aa_lerp(v1.z, v2.z) };
}

static aa3 aa3_sub(aa3 u, aa3 v)
{
    return (aa3){ aa_sub(u.x, v.x), aa_sub(u.y, v.y), aa_sub(u.z, v.z) };
}

static aa3 aa3_mul(aa3 v, aa s)
{
    return (aa3){ aa_mul(v.x, s), aa_mul(v.y, s), aa_mul(v.z, s) };
}

static aa aa3_dot(aa3 u, aa3 v)
{
    return aa_add(aa_add(aa_mul(u.x, v.x), aa_mul(u.y, v.y)), aa_mul(u.z, v.z));
}

static aa aa3_len2(aa3 v)
{
    return aa_add(aa_add(aa_sqr(v.x), aa_sqr(v.y)), aa_sqr(v.z));
}

static aa3 aa3_normalize(aa3 v)
{
    return aa3_mul(v, aa_rsqrt(aa3_len2(v)));
}

/* The unshadowed local Phong term of light L as phong_ia, in affine forms:
 * E (k_d max(0, n.l) + k_s max(0, r.a)^m) where n.l > 0. */
static aa phong_aa(const rl_light *L, aa3 p, aa3 n, rl_vec3 eye, double kd, double ks, double m)
{
    aa3 a = aa3_normalize(aa3_sub(aa3_const(eye), p));
    aa3 l;
    aa E;
    float power = rl_vmax_comp(L->color) * L->intensity;
    if (L->type == RL_LIGHT_DIRECTIONAL) {
        l = aa3_const(rl_normalize(rl_neg(L->direction)));
        E = aa_const(power);
    } else {
        rl_vec3 at = L->position;
        if (L->type == RL_LIGHT_QUAD) {
            at = rl_add(at, rl_scale(rl_add(L->edge_u, L->edge_v), 0.5f));
            power *= rl_length(rl_cross(L->edge_u, L->edge_v));
        }
        aa3 to = aa3_sub(aa3_const(at), p);
        aa d2 = aa3_len2(to);
        l = aa3_mul(to, aa_rsqrt(d2));
        E = aa_scale(aa_recip(d2), power);
    }
    aa nl = aa3_dot(n, l);
    if (!isfinite(aa_hi(nl)))
        return AA_NONE;
    if (!(aa_hi(nl) > 0.0))
        return aa_const(0.0);               /* the light is behind the whole edge */
    aa f = aa_scale(aa_relu(nl), kd);
    if (ks > 0.0) {
        aa ra = aa_sub(aa_scale(aa_mul(nl, aa3_dot(n, a)), 2.0), aa3_dot(l, a));
        aa s = aa_scale(aa_pow01(aa_relu(ra), m), ks);
        if (aa_lo(nl) <= 0.0) {
            /* the tracer adds the highlight only where n.l > 0: on the
             * part of the edge where it does not, the term is 0, so only
             * the range [0, hi] is known, not the form */
            double hi = fmax(aa_hi(s), 0.0);
            s = (aa){ 0.5 * hi, 0.0, 0.5 * hi };
        }
        f = aa_add(f, s);
    }
    return aa_mul(f, E);
}

/* The term at the point t of the edge (p and n as the enclosures take
 * them), in plain double arithmetic: the forms of a point have a = r = 0. */
static double affine_point(const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2, double t,
                           double kd, double ks, double m)
{
    aa3 p = { aa_const(e1->p.x + t * (e2->p.x - e1->p.x)), aa_const(e1->p.y + t * (e2->p.y - e1->p.y)),
              aa_const(e1->p.z + t * (e2->p.z - e1->p.z)) };
    aa3 n = { aa_const(e1->n.x + t * (e2->n.x - e1->n.x)), aa_const(e1->n.y + t * (e2->n.y - e1->n.y)),
              aa_const(e1->n.z + t * (e2->n.z - e1->n.z)) };
    return phong_aa(L, p, aa3_normalize(n), eye, kd, ks, m).c;
}

/* The enclosure of light L's term over the edge in affine arithmetic and
 * its bound on the interpolation error: with f = c + a e + [-r, r] and the
 * interpolant f' = (f_1 + f_2)/2 + (f_2 - f_1)/2 e,
 *   eps_AA = |c - (f_1 + f_2)/2| + |a - (f_2 - f_1)/2| + r >= eps_A.
 * Affine ranges are not always narrower than intervals: 1 / d^2 of a point
 * light over a long edge, or the product of two wide forms, can overshoot
 * (on a fifth of the random edges of test_vt_criteria). Both enclosures
 * hold the term, so their intersection does; and the bound of Fig. 6.4 on
 * it holds as well as eps_AA: the smallest of them is used. */
static void affine_term(const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2,
                        vt_term_bound *out)
{
    double kd = rl_maxf(e1->kd, e2->kd), ks = rl_maxf(e1->ks, e2->ks), m = rl_maxf(e1->m, 1e-3f);
    aa f = phong_aa(L, aa3_lerp(e1->p, e2->p), aa3_normalize(aa3_lerp(e1->n, e2->n)), eye, kd, ks, m);
    double f1 = affine_point(L, eye, e1, e2, 0.0, kd, ks, m), f2 = affine_point(L, eye, e1, e2, 1.0, kd, ks, m);
    vt_term_bound ia;
    interval_term(L, eye, e1, e2, &ia);
    double eps_aa = fabs(f.c - 0.5 * (f1 + f2)) + fabs(f.a - 0.5 * (f2 - f1)) + f.r;
    if (!isfinite(eps_aa)) {
        *out = ia;                          /* no finite form: the interval's answer */
        if (!(out->eps >= 0.0f))
            out->eps = INFINITY;            /* nor a finite interval: split */
        return;
    }
    double lo = fmax(aa_lo(f), ia.lo), hi = fmin(aa_hi(f), ia.hi);
    double eps_range = fmax(hi - fmin(f1, f2), fmax(f1, f2) - lo);
    out->lo = (float)lo;
    out->hi = (float)hi;
    out->f1 = (float)f1;
    out->f2 = (float)f2;
    out->eps = (float)fmin(fmin(eps_aa, eps_range), ia.eps);
}

void vt_term_bound_of(int mode, const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2,
                      vt_term_bound *out)
{
    if (mode == VT_NONLINEAR_AFFINE)
        affine_term(L, eye, e1, e2, out);
    else
        interval_term(L, eye, e1, e2, out);
}

float vt_term_at(const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2, float t)
{
    double kd = rl_maxf(e1->kd, e2->kd), ks = rl_maxf(e1->ks, e2->ks), m = rl_maxf(e1->m, 1e-3f);
    return (float)affine_point(L, eye, e1, e2, t, kd, ks, m);
}

/* eps_IA of the edge (a, b) in interval or affine arithmetic, summed over
 * the lights. */
static float nonlinear_bound(const vt_run *run, int mode, const vt_vertex *a, const vt_vertex *b)
{
    const rl_scene_data *d = run->data;
    const vt_edge_end ea = end_of(run, a), eb = end_of(run, b);
    float bound = 0.0f;
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        vt_term_bound tb;
        vt_term_bound_of(mode, &d->lights[i], run->view.eye, &ea, &eb, &tb);
        bound += tb.eps;
    }
    return bound;
}

bool vt_nonlinear_fires(const vt_run *run, const vt_vertex *a, const vt_vertex *b)
{
    const rl_scene_data *d = run->data;
    switch (run->set->nonlinear) {
    case VT_NONLINEAR_EXTREMUM:
    case VT_NONLINEAR_DERIVATIVE: {
        const vt_edge_end ea = end_of(run, a), eb = end_of(run, b);
        return run->set->nonlinear == VT_NONLINEAR_EXTREMUM
                   ? vt_extremum_test(d->lights, d->num_lights, &ea, &eb)
                   : vt_derivative_test(d->lights, d->num_lights, run->view.eye, &ea, &eb);
    }
    case VT_NONLINEAR_INTERVAL:
    case VT_NONLINEAR_AFFINE: {
        float eps = run->set->eps_ia, ib = nonlinear_bound(run, VT_NONLINEAR_INTERVAL, a, b);
        if (run->set->nonlinear == VT_NONLINEAR_INTERVAL)
            return ib > eps;
        /* the affine bound is never above the interval one (affine_term):
         * what the interval lets pass, affine does too, and the forms are
         * only worked out where the interval bound would split */
        return !(ib <= eps) && nonlinear_bound(run, VT_NONLINEAR_AFFINE, a, b) > eps;
    }
    default:
        return false;
    }
}

/* ------------------------------------------------------ Sec. 6.1.2 -- */

rl_status vt_shaft_index_build(vt_shaft_index *ix, const rl_scene_data *d)
{
    memset(ix, 0, sizeof *ix);
    uint64_t groups = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        groups += (d->objects[o].num_triangles + VT_SHAFT_GROUP - 1) / VT_SHAFT_GROUP;
    if (groups > UINT32_MAX - 1)
        return rl_error(RL_ERR_LIMIT, "vt: shaft_cull: %llu triangle groups", (unsigned long long)groups);
    ix->first = malloc(((size_t)d->num_objects + 1) * sizeof *ix->first);
    ix->box = malloc((groups ? (size_t)groups : 1) * sizeof *ix->box);
    if (!ix->first || !ix->box) {
        vt_shaft_index_free(ix);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: shaft_cull: %llu triangle groups", (unsigned long long)groups);
    }
    uint32_t g = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *ob = &d->objects[o];
        ix->first[o] = g;
        for (uint32_t t0 = 0; t0 < ob->num_triangles; t0 += VT_SHAFT_GROUP, ++g) {
            rl_aabb b = rl_aabb_empty();
            uint32_t t1 = ob->num_triangles - t0 < VT_SHAFT_GROUP ? ob->num_triangles : t0 + VT_SHAFT_GROUP;
            for (uint32_t t = t0; t < t1; ++t)
                for (int k = 0; k < 3; ++k)
                    b = rl_aabb_grow(b, d->positions[d->indices[3 * (size_t)(ob->first_triangle + t) + k]]);
            ix->box[g] = b;
        }
    }
    ix->first[d->num_objects] = g;
    rl_vec3 ext = rl_sub(d->bounds.max, d->bounds.min);
    ix->extent = rl_vfinite(ext) ? rl_length(ext) : 0.0f;
    return RL_OK;
}

void vt_shaft_index_free(vt_shaft_index *ix)
{
    free(ix->first);
    free(ix->box);
    memset(ix, 0, sizeof *ix);
}

void vt_shaft_build(vt_shaft *s, rl_aabb a, rl_aabb b)
{
    s->extent = (rl_aabb){ rl_vmin(a.min, b.min), rl_vmax(a.max, b.max) };
    s->num_planes = 0;
    /* [HW91]: every face of the hull of two boxes holds an edge of one of
     * them, so it is parallel to an axis k; for the axes i, j across it,
     * there is one at a corner of the extent where one box sticks out
     * along i and the other along j. It passes through both boxes' edges
     * at that corner, its normal points into the corner. */
    for (int i = 0; i < 3; ++i) {
        for (int j = i + 1; j < 3; ++j) {
            for (int side = 0; side < 4; ++side) {
                bool hi_i = side & 1, hi_j = side & 2;
                float ai = rl_vget(hi_i ? a.max : a.min, i), bi = rl_vget(hi_i ? b.max : b.min, i);
                float aj = rl_vget(hi_j ? a.max : a.min, j), bj = rl_vget(hi_j ? b.max : b.min, j);
                bool a_out_i = hi_i ? ai > bi : ai < bi, b_out_i = hi_i ? bi > ai : bi < ai;
                bool a_out_j = hi_j ? aj > bj : aj < bj, b_out_j = hi_j ? bj > aj : bj < aj;
                if (!((a_out_i && b_out_j) || (b_out_i && a_out_j)))
                    continue;
                float ni = bj - aj, nj = ai - bi;          /* normal to (b - a) in the (i, j) plane */
                float ci = hi_i ? 1.0f : -1.0f, cj = hi_j ? 1.0f : -1.0f;
                if (ni * ci + nj * cj < 0.0f) {
                    ni = -ni;
                    nj = -nj;
                }
                float nv[3] = { 0.0f, 0.0f, 0.0f };
                nv[i] = ni;
                nv[j] = nj;
                s->normal[s->num_planes] = rl_v3(nv[0], nv[1], nv[2]);
                s->offset[s->num_planes] = ni * ai + nj * aj;
                s->num_planes++;
            }
        }
    }
}

bool vt_shaft_meets_box(const vt_shaft *s, rl_aabb x)
{
    if (x.min.x > s->extent.max.x || x.max.x < s->extent.min.x || x.min.y > s->extent.max.y ||
        x.max.y < s->extent.min.y || x.min.z > s->extent.max.z || x.max.z < s->extent.min.z)
        return false;
    for (int k = 0; k < s->num_planes; ++k) {
        rl_vec3 n = s->normal[k];
        /* the box's corner deepest inside the plane */
        rl_vec3 c = rl_v3(n.x > 0.0f ? x.min.x : x.max.x, n.y > 0.0f ? x.min.y : x.max.y,
                          n.z > 0.0f ? x.min.z : x.max.z);
        /* a box just touching the plane meets the shaft: rounding must not
         * cull the occluder that stands on the face */
        float slack = 1e-5f * (fabsf(s->offset[k]) + fabsf(n.x) + fabsf(n.y) + fabsf(n.z));
        if (rl_dot(n, c) > s->offset[k] + slack)
            return false;
    }
    return true;
}

static bool box_inside(rl_aabb x, rl_aabb in)
{
    return x.min.x >= in.min.x && x.min.y >= in.min.y && x.min.z >= in.min.z && x.max.x <= in.max.x &&
           x.max.y <= in.max.y && x.max.z <= in.max.z;
}

/* Whether geometry of an object other than skip meets the shaft. A
 * triangle inside the box emitter (when not NULL) is the light's own
 * geometry (the emitting quad of an area light drawn as a mesh): a feeler
 * stops short of it (trace_shade.c), so it casts no shadow. */
static bool shaft_occupied(const vt_shaft_index *ix, const rl_scene_data *d, const vt_shaft *s, uint32_t skip,
                           const rl_aabb *emitter)
{
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *ob = &d->objects[o];
        if (o == skip || !ob->num_triangles || !vt_shaft_meets_box(s, ob->bounds))
            continue;
        for (uint32_t g = ix->first[o]; g < ix->first[o + 1]; ++g) {
            if (!vt_shaft_meets_box(s, ix->box[g]))
                continue;
            uint32_t t0 = (g - ix->first[o]) * VT_SHAFT_GROUP;
            uint32_t t1 = ob->num_triangles - t0 < VT_SHAFT_GROUP ? ob->num_triangles : t0 + VT_SHAFT_GROUP;
            for (uint32_t t = t0; t < t1; ++t) {
                const uint32_t *idx = &d->indices[3 * (size_t)(ob->first_triangle + t)];
                rl_aabb tb = rl_aabb_empty();
                for (int k = 0; k < 3; ++k)
                    tb = rl_aabb_grow(tb, d->positions[idx[k]]);
                if (vt_shaft_meets_box(s, tb) && !(emitter && box_inside(tb, *emitter)))
                    return true;
            }
        }
    }
    return false;
}

static rl_aabb box_of(const rl_vec3 *p, int n)
{
    rl_aabb b = rl_aabb_empty();
    for (int i = 0; i < n; ++i)
        b = rl_aabb_grow(b, p[i]);
    return b;
}

/* Fig. 6.6b: the face moved along each corner's secondary ray by d. */
static rl_aabb moved_box(const vt_run *run, const vt_face *f, bool transmit, float dist)
{
    const rl_scene_data *d = run->data;
    const vt_mesh *m = run->mesh;
    rl_vec3 q[3];
    for (int k = 0; k < 3; ++k) {
        const vt_vertex *v = &m->verts[f->v[k]];
        rl_vec3 w = rl_normalize(rl_sub(v->p, run->view.eye));
        bool front = rl_dot(w, v->n) < 0.0f;
        rl_vec3 n = front ? v->n : rl_neg(v->n);
        rl_vec3 dir = rl_reflect(w, n);
        if (transmit) {
            float ior = d->materials[d->triangle_material[v->triangle]].ior;
            ior = ior >= 1.0f ? ior : 1.0f;
            rl_vec3 t;
            if (rl_refract(w, n, front ? 1.0f / ior : ior, &t))
                dir = t;                    /* else total internal reflection */
        }
        q[k] = rl_madd(v->p, dir, dist);
    }
    return box_of(q, 3);
}

bool vt_shaft_face_fires(const vt_run *run, const vt_shaft_index *ix, uint32_t face)
{
    const rl_scene_data *d = run->data;
    const vt_mesh *m = run->mesh;
    const vt_face *f = &m->faces[face];
    const uint32_t own = d->triangle_object[f->triangle];
    const rl_material *mat = &d->materials[d->triangle_material[f->triangle]];
    rl_vec3 p[3], n[3];
    for (int k = 0; k < 3; ++k) {
        const vt_vertex *v = &m->verts[f->v[k]];
        p[k] = v->p;
        rl_vec3 a = rl_sub(run->view.eye, v->p);
        n[k] = rl_dot(v->n, a) < 0.0f ? rl_neg(v->n) : v->n;
    }
    const rl_aabb fb = box_of(p, 3);
    const float dist = ix->extent;
    vt_shaft s;
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        /* A face turned away from the light at all three corners is lit by
         * it nowhere inside (the normal between them is a positive mix),
         * unless the transmitted highlight (eq. 3.17) comes through it. */
        bool lit = mat->transmissivity > 0.0f;
        for (int k = 0; k < 3 && !lit; ++k) {
            float E;
            lit = rl_dot(n[k], light_at(L, p[k], &E)) > 0.0f;
        }
        if (!lit)
            continue;
        rl_aabb lb;
        bool area = false;
        if (L->type == RL_LIGHT_DIRECTIONAL) {
            rl_vec3 off = rl_scale(rl_normalize(rl_neg(L->direction)), dist);
            lb = (rl_aabb){ rl_add(fb.min, off), rl_add(fb.max, off) };
        } else if (L->type == RL_LIGHT_QUAD) {
            rl_vec3 c[4] = { L->position, rl_add(L->position, L->edge_u), rl_add(L->position, L->edge_v),
                             rl_add(rl_add(L->position, L->edge_u), L->edge_v) };
            lb = box_of(c, 4);
            area = true;
        } else {
            lb = (rl_aabb){ L->position, L->position };
        }
        vt_shaft_build(&s, fb, lb);
        /* the quad's box, grown by a hair of the scene's size for the
         * rounding of a mesh placed on it */
        float hair = 1e-4f * dist;
        rl_aabb em = { rl_sub(lb.min, rl_v3(hair, hair, hair)), rl_add(lb.max, rl_v3(hair, hair, hair)) };
        if (shaft_occupied(ix, d, &s, own, area ? &em : NULL))
            return true;
    }
    if (run->set->shaft_cull == VT_SHAFT_ALL) {
        for (int t = 0; t < 2; ++t) {
            if (!(t ? mat->transmissivity : mat->reflectivity) || !(dist > 0.0f))
                continue;
            vt_shaft_build(&s, fb, moved_box(run, f, t == 1, dist));
            if (shaft_occupied(ix, d, &s, own, NULL))
                return true;
        }
    }
    return false;
}
