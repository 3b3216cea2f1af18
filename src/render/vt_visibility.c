/* vt_visibility.c: where a vertex of the refinement mesh lands on the
 * screen, and whether refinement there can be seen (Ullmann 2003, Sec. 3.4):
 * the z-buffer test of a vertex (Sec. 3.4.2) and the viewport test of an
 * edge by a Cohen-Sutherland clipper that stops as soon as the answer is
 * known (Sec. 3.4.3, Fig. 3.16).
 *
 * The mapping to pixels is the rasterizer's (src/raster/raster_setup.c):
 * x_pix = (x/w + 1) W/2, y_pix = (1 - y/w) H/2, pixel (i, j) covering
 * [i, i+1) x [j, j+1) with its centre at +0.5, so a vertex lands in the
 * pixel the reconstruction draws it into. With rl's perspective (gluPerspective
 * after a look-at) clip w is the eye depth, the quantity the rasterizer
 * writes into the depth layer, so vertex and z-buffer depths compare
 * directly. The near plane is w >= z_near, the same plane as the
 * rasterizer's z >= -w for that projection.
 *
 * A vertex with cw <= 0 (at or behind the eye) has no projection: its sx,
 * sy are set to 0 and must not be used. */
#include <math.h>

#include "render/vt_internal.h"

static rl_vec4 to_clip(const rl_mat4 *m, rl_vec3 p)
{
    /* Same expression order as the rasterizer's transform, so that both
     * produce bit-identical clip coordinates. */
    return rl_v4(m->m[0][0] * p.x + m->m[0][1] * p.y + m->m[0][2] * p.z + m->m[0][3],
                 m->m[1][0] * p.x + m->m[1][1] * p.y + m->m[1][2] * p.z + m->m[1][3],
                 m->m[2][0] * p.x + m->m[2][1] * p.y + m->m[2][2] * p.z + m->m[2][3],
                 m->m[3][0] * p.x + m->m[3][1] * p.y + m->m[3][2] * p.z + m->m[3][3]);
}

/* Pixel position of a clip-space point with w > 0. */
static void to_pixels(const vt_view *view, rl_vec4 c, double *x, double *y)
{
    double inv_w = 1.0 / c.w;
    *x = (c.x * inv_w + 1.0) * 0.5 * view->width;
    *y = (1.0 - c.y * inv_w) * 0.5 * view->height;
}

void vt_project_vertex(const vt_view *view, vt_vertex *v)
{
    rl_vec4 c = to_clip(&view->view_proj, v->p);
    v->cw = c.w;
    v->depth = rl_dot(rl_sub(v->p, view->eye), view->forward);
    if (c.w > 0.0f) {
        double x, y;
        to_pixels(view, c, &x, &y);
        v->sx = (float)x;
        v->sy = (float)y;
    } else {
        v->sx = 0.0f;
        v->sy = 0.0f;
    }
}

bool vt_vertex_visible(const vt_view *view, const vt_vertex *v)
{
    if (!(v->cw >= view->z_near))
        return false;
    if (!(v->sx >= 0.0f && v->sx <= (float)view->width && v->sy >= 0.0f &&
          v->sy <= (float)view->height))
        return false;
    if (!view->depth)
        return true;
    /* Sec. 3.4.2: compare against the z-buffer. A vertex lies between up to
     * four pixel centres; the farthest stored depth among them decides, so
     * a vertex on a silhouette, or on the VT surface itself, is not hidden
     * by its own neighbourhood. */
    int x0 = (int)floorf(v->sx - 0.5f), y0 = (int)floorf(v->sy - 0.5f);
    float stored = -INFINITY;
    for (int y = y0; y <= y0 + 1; ++y) {
        if (y < 0 || y >= view->height)
            continue;
        for (int x = x0; x <= x0 + 1; ++x) {
            if (x < 0 || x >= view->width)
                continue;
            float d = view->depth[(size_t)y * (size_t)view->width + (size_t)x];
            stored = d > stored ? d : stored;
        }
    }
    if (stored == -INFINITY)
        return true;          /* no pixel centre around it (1-pixel targets) */
    return v->depth <= stored * (1.0f + view->depth_tolerance);
}

/* Clip-space half-spaces of the viewport test; distance < 0 is outside. */
enum { PLANE_LEFT, PLANE_RIGHT, PLANE_BOTTOM, PLANE_TOP, PLANE_NEAR, PLANE_COUNT };

static float plane_dist(int plane, rl_vec4 p, float z_near)
{
    switch (plane) {
    case PLANE_LEFT:   return p.w + p.x;
    case PLANE_RIGHT:  return p.w - p.x;
    case PLANE_BOTTOM: return p.w + p.y;
    case PLANE_TOP:    return p.w - p.y;
    default:           return p.w - z_near;
    }
}

static unsigned outcode(rl_vec4 p, float z_near)
{
    unsigned oc = 0;
    for (int k = 0; k < PLANE_COUNT; ++k)
        if (!(plane_dist(k, p, z_near) >= 0.0f))
            oc |= 1u << k;
    return oc;
}

static rl_vec4 lerp4(rl_vec4 a, rl_vec4 b, float t)
{
    return rl_v4(rl_lerpf(a.x, b.x, t), rl_lerpf(a.y, b.y, t), rl_lerpf(a.z, b.z, t),
                 rl_lerpf(a.w, b.w, t));
}

bool vt_edge_in_viewport(const vt_view *view, const vt_vertex *a, const vt_vertex *b)
{
    rl_vec4 p[2] = { to_clip(&view->view_proj, a->p), to_clip(&view->view_proj, b->p) };
    unsigned oc[2] = { outcode(p[0], view->z_near), outcode(p[1], view->z_near) };
    /* Cohen-Sutherland in homogeneous clip space: every plane is linear
     * there, so clipping is exact even for ends behind the eye. Each round
     * moves one outside end onto one of its outside planes and removes that
     * bit for good, so at most 2 * PLANE_COUNT rounds run. */
    for (int round = 0; round <= 2 * PLANE_COUNT; ++round) {
        /* Sec. 3.4.3, the thesis' modification: decide and stop; an end
         * inside means part of the edge is visible, no full clip needed. */
        if (oc[0] == 0 || oc[1] == 0)
            return true;
        if (oc[0] & oc[1])
            return false;
        int i = 0;
        int plane = 0;
        while (!(oc[i] & (1u << plane)))
            ++plane;
        /* oc[1 - i] lacks this bit (no shared bit), so its end is inside
         * the plane and the cut lies on the segment. */
        float di = plane_dist(plane, p[i], view->z_near);
        float dj = plane_dist(plane, p[1 - i], view->z_near);
        float t = di / (di - dj);
        p[i] = lerp4(p[i], p[1 - i], t);
        /* The cut lies on the plane; rounding must not bring the bit back. */
        oc[i] = outcode(p[i], view->z_near) & ~(1u << plane);
    }
    return false;
}

float vt_edge_length(const vt_view *view, const vt_vertex *a, const vt_vertex *b)
{
    bool a_in = a->cw >= view->z_near, b_in = b->cw >= view->z_near;
    if (a_in && b_in) {
        double dx = (double)a->sx - b->sx, dy = (double)a->sy - b->sy;
        return (float)sqrt(dx * dx + dy * dy);
    }
    if (!a_in && !b_in)
        return 0.0f;
    /* One end behind the near plane: measure the part in front of it, cut
     * where w = z_near, as the rasterizer's near clipping would draw it. */
    const vt_vertex *in = a_in ? a : b, *out = a_in ? b : a;
    rl_vec4 ci = to_clip(&view->view_proj, in->p), co = to_clip(&view->view_proj, out->p);
    float di = ci.w - view->z_near, d_out = co.w - view->z_near;
    rl_vec4 cut = lerp4(ci, co, di / (di - d_out));
    cut.w = rl_maxf(cut.w, view->z_near);
    double xi, yi, xc, yc;
    to_pixels(view, ci, &xi, &yi);
    to_pixels(view, cut, &xc, &yc);
    return (float)sqrt((xi - xc) * (xi - xc) + (yi - yc) * (yi - yc));
}
