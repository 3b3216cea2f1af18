/* pathtrace_quad.c: next-event samples on a rectangular quad light by
 * solid angle (issue 37, option quad_sampling=solid_angle), after Ureña,
 * Fajardo and King 2013, "An Area-Preserving Parametrization for Spherical
 * Rectangles".
 *
 * Why: a point drawn uniformly on the quad's area carries the weight
 * A cos(theta_E) / d^2, which swings by orders of magnitude across the
 * quad for a surface close to the light (the Cornell box's ceiling and the
 * upper walls): those pixels converge slowest. Drawn uniformly in the solid
 * angle the rectangle subtends, every sample has the same weight Omega, and
 * only the BSDF and cos(theta_R) vary.
 *
 * The construction (the paper's Sec. 3 and 4): in the rectangle's frame,
 * with the shading point at the origin and the rectangle in the plane
 * z = z0 < 0 spanning [x0, x1] x [y0, y1], the four planes through the
 * origin and an edge bound a spherical rectangle of solid angle
 * S = g0 + g1 + g2 + g3 - 2 pi (its internal angles). u picks the x of a
 * vertical strip so that the solid angle left of it is u S (closed form,
 * eq. 9-12 of the paper), v then picks y within the strip so that the
 * projected height is linear in v. The map is area-preserving, so the
 * density is 1 / S in solid angle.
 *
 * All of it in double: S is a difference of angles near 2 pi and falls to
 * 1e-6 sr for a small light a few metres away. Below MIN_SOLID_ANGLE, at
 * grazing views and for parallelograms that are not rectangles, the quad is
 * sampled by area as before (rl_pt_sph_rect_init returns false); the pdf of
 * a BSDF ray that hits the quad asks the same function, so both strategies
 * always agree on which density the light sample had. */
#include <math.h>

#include "render/pathtrace_internal.h"

/* Smallest solid angle sampled in closed form: 2 pi - (sum of four angles)
 * keeps about 1e-15 x 2 pi absolute precision, so 1e-7 sr keeps S to 1e-8. */
#define MIN_SOLID_ANGLE 1e-7
/* Edges are orthogonal when |cos| between them is below this. */
#define RECT_COS_TOL 1e-4

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double clampd(double v, double lo, double hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

bool rl_pt_sph_rect_init(pt_sph_rect *r, const rl_light *L, rl_vec3 p)
{
    double eu[3] = { L->edge_u.x, L->edge_u.y, L->edge_u.z }, ev[3] = { L->edge_v.x, L->edge_v.y, L->edge_v.z };
    double lu = sqrt(dot3(eu, eu)), lv = sqrt(dot3(ev, ev));
    if (!(lu > 0.0) || !(lv > 0.0) || fabs(dot3(eu, ev)) > RECT_COS_TOL * lu * lv)
        return false;
    for (int k = 0; k < 3; ++k) {
        r->x[k] = eu[k] / lu;
        r->y[k] = ev[k] / lv;
    }
    /* z = x cross y, the quad's front normal: it emits into +z
     * (pathtrace_path.c: cos_e = -n . l > 0). */
    r->z[0] = r->x[1] * r->y[2] - r->x[2] * r->y[1];
    r->z[1] = r->x[2] * r->y[0] - r->x[0] * r->y[2];
    r->z[2] = r->x[0] * r->y[1] - r->x[1] * r->y[0];
    r->o[0] = p.x;
    r->o[1] = p.y;
    r->o[2] = p.z;
    double d[3] = { L->position.x - r->o[0], L->position.y - r->o[1], L->position.z - r->o[2] };
    r->x0 = dot3(d, r->x);
    r->y0 = dot3(d, r->y);
    r->z0 = dot3(d, r->z);
    /* A point in front sees the quad below it (z0 < 0), the paper's frame.
     * Behind the emitting side no light arrives; in the plane the solid
     * angle is 0. */
    if (!(r->z0 < 0.0))
        return false;
    r->x1 = r->x0 + lu;
    r->y1 = r->y0 + lv;
    double z0 = r->z0, z0sq = z0 * z0;
    /* Normals of the planes through the origin and each edge (unit):
     * n0 (y = y0), n1 (x = x1), n2 (y = y1), n3 (x = x0). Only their z and
     * the pairwise dots are needed; with n0 = (0, z0, -y0) / |.| etc. the
     * dot of neighbours is the product of their z components. */
    double n0z = -r->y0 / sqrt(z0sq + r->y0 * r->y0);
    double n1z = r->x1 / sqrt(z0sq + r->x1 * r->x1);
    double n2z = r->y1 / sqrt(z0sq + r->y1 * r->y1);
    double n3z = -r->x0 / sqrt(z0sq + r->x0 * r->x0);
    double g0 = acos(clampd(-n0z * n1z, -1.0, 1.0));
    double g1 = acos(clampd(-n1z * n2z, -1.0, 1.0));
    double g2 = acos(clampd(-n2z * n3z, -1.0, 1.0));
    double g3 = acos(clampd(-n3z * n0z, -1.0, 1.0));
    r->b0 = n0z;
    r->b1 = n2z;
    r->k = 2.0 * RL_PI - g2 - g3;
    r->S = g0 + g1 - r->k;
    return r->S >= MIN_SOLID_ANGLE;
}

rl_vec3 rl_pt_sph_rect_sample(const pt_sph_rect *r, float u, float v)
{
    double z0 = r->z0, z0sq = z0 * z0;
    /* The strip: its x, so that the solid angle left of it is u S. */
    double au = (double)u * r->S + r->k;
    double sa = sin(au);
    double fu = (cos(au) * r->b0 - r->b1) / (sa != 0.0 ? sa : 1e-300);
    double cu = (fu > 0.0 ? 1.0 : -1.0) / sqrt(fu * fu + r->b0 * r->b0);
    cu = clampd(cu, -1.0, 1.0);
    double su = sqrt(fmax(0.0, 1.0 - cu * cu));
    double xu = su > 0.0 ? -(cu * z0) / su : (cu > 0.0 ? r->x1 : r->x0);
    xu = clampd(xu, r->x0, r->x1);
    /* Within the strip: y so that the projected height is linear in v. */
    double dd = sqrt(xu * xu + z0sq);
    double h0 = r->y0 / sqrt(dd * dd + r->y0 * r->y0);
    double h1 = r->y1 / sqrt(dd * dd + r->y1 * r->y1);
    double hv = h0 + (double)v * (h1 - h0), hv2 = hv * hv;
    double yv = hv2 < 1.0 - 1e-12 ? hv * dd / sqrt(1.0 - hv2) : r->y1;
    yv = clampd(yv, r->y0, r->y1);
    double q[3];
    for (int k = 0; k < 3; ++k)
        q[k] = r->o[k] + xu * r->x[k] + yv * r->y[k] + z0 * r->z[k];
    return rl_v3((float)q[0], (float)q[1], (float)q[2]);
}
