/* lathe.c: surfaces of revolution, torus arcs and extruded convex outlines
 * (see lathe.h). The thesis' table scene (Ullmann 2003, Sec. 5.1, Fig. 5.1)
 * is made of such turned and swept parts: cups, lamp, handle.
 *
 * Angles on a closed loop are computed from the index modulo the loop
 * length, so the duplicated seam vertices get bit-identical positions and
 * the solids weld watertight. */
#include "scene/lathe.h"

#include <math.h>

/* Outward normal of the profile segment p0 -> p1 in the (r, y) plane: the
 * material is on the right, so outward is on the left, (-dy, dr). */
static rl_vec2 segment_normal(rl_vec2 p0, rl_vec2 p1)
{
    float dr = p1.x - p0.x, dy = p1.y - p0.y;
    float len = sqrtf(dr * dr + dy * dy);
    return len > 0.0f ? rl_v2(-dy / len, dr / len) : rl_v2(0.0f, 0.0f);
}

/* Shared normal at a profile corner, or the segment's own across a crease. */
static rl_vec2 corner_normal(rl_vec2 own, rl_vec2 other)
{
    float cos_crease = cosf(rl_radians(RL_LATHE_CREASE_DEG));
    if (own.x * other.x + own.y * other.y < cos_crease)
        return own;
    rl_vec2 n = rl_v2(own.x + other.x, own.y + other.y);
    float len = sqrtf(n.x * n.x + n.y * n.y);
    return len > 0.0f ? rl_v2(n.x / len, n.y / len) : own;
}

static bool same_point(rl_vec2 a, rl_vec2 b) { return a.x == b.x && a.y == b.y; }

/* One ring of segments+1 vertices at profile point p with profile normal n. */
static uint32_t ring(rl_meshbuf *b, rl_vec2 p, rl_vec2 n, float v, uint32_t segments)
{
    uint32_t first = b->num_vertices;
    for (uint32_t s = 0; s <= segments; ++s) {
        /* phi grows towards -z: counter-clockwise seen from +y, like
         * rl_gen_sphere, which makes the material-on-the-right rule hold. */
        float phi = 2.0f * RL_PI * (float)(s % segments) / (float)segments;
        float c = cosf(phi), sn = sinf(phi);
        rl_vec3 pos = p.x > 0.0f ? rl_v3(p.x * c, p.y, -p.x * sn) : rl_v3(0.0f, p.y, 0.0f);
        rl_meshbuf_vertex(b, pos, rl_v3(n.x * c, n.y, -n.x * sn),
                          rl_v2((float)s / (float)segments, v));
    }
    return first;
}

void rl_lathe(rl_meshbuf *b, const rl_vec2 *profile, uint32_t count, uint32_t segments)
{
    if (count < 2 || segments < 3)
        return;
    if (!rl_meshbuf_reserve(b, 2ull * (count - 1) * (segments + 1), 2ull * (count - 1) * segments))
        return;
    double total = 0.0;
    for (uint32_t k = 0; k + 1 < count; ++k)
        total += hypot(profile[k + 1].x - profile[k].x, profile[k + 1].y - profile[k].y);
    if (!(total > 0.0))
        return;
    double walked = 0.0;
    for (uint32_t k = 0; k + 1 < count; ++k) {
        rl_vec2 p0 = profile[k], p1 = profile[k + 1];
        if (same_point(p0, p1))
            continue;
        rl_vec2 n = segment_normal(p0, p1), n0 = n, n1 = n;
        if (k > 0 && !same_point(profile[k - 1], p0))
            n0 = corner_normal(n, segment_normal(profile[k - 1], p0));
        if (k + 2 < count && !same_point(p1, profile[k + 2]))
            n1 = corner_normal(n, segment_normal(p1, profile[k + 2]));
        float v0 = (float)(walked / total);
        walked += hypot(p1.x - p0.x, p1.y - p0.y);
        float v1 = (float)(walked / total);
        uint32_t r0 = ring(b, p0, n0, v0, segments);
        uint32_t r1 = ring(b, p1, n1, v1, segments);
        for (uint32_t s = 0; s < segments; ++s) {
            uint32_t a = r0 + s, c = a + 1, d = r1 + s, e = d + 1;
            /* On the axis a ring collapses to a point: keep only the fan. */
            if (p0.x > 0.0f)
                rl_meshbuf_triangle(b, a, d, c);
            if (p1.x > 0.0f)
                rl_meshbuf_triangle(b, c, d, e);
        }
    }
}

void rl_lathe_arc(rl_vec2 *profile, uint32_t *count, rl_vec2 c, float radius, float a0,
                  float a1, uint32_t n)
{
    for (uint32_t i = 0; i <= n; ++i) {
        float a = a0 + (a1 - a0) * (float)i / (float)n;
        profile[(*count)++] = rl_v2(c.x + radius * cosf(a), c.y + radius * sinf(a));
    }
}

/* Point and normal of the torus at arc angle theta, tube angle index j. */
static rl_vec3 torus_point(float major_r, float minor_r, float theta, uint32_t j,
                           uint32_t tube_segments, rl_vec3 *normal)
{
    float psi = 2.0f * RL_PI * (float)(j % tube_segments) / (float)tube_segments;
    rl_vec3 radial = rl_v3(cosf(theta), sinf(theta), 0.0f);
    /* psi = 0 points away from the axis, psi = 90 degrees along +z; then
     * cross(d/dtheta, d/dpsi) is outward, so (i, j) quads wind outward. */
    *normal = rl_add(rl_scale(radial, cosf(psi)), rl_v3(0.0f, 0.0f, sinf(psi)));
    return rl_add(rl_scale(radial, major_r), rl_scale(*normal, minor_r));
}

void rl_torus_arc(rl_meshbuf *b, float major_r, float minor_r, float a0, float a1,
                  uint32_t arc_segments, uint32_t tube_segments, bool caps)
{
    if (arc_segments < 1 || tube_segments < 3)
        return;
    uint64_t nv = (uint64_t)(arc_segments + 1) * (tube_segments + 1) + 2ull * (tube_segments + 1);
    uint64_t nt = 2ull * arc_segments * tube_segments + 2ull * tube_segments;
    if (!rl_meshbuf_reserve(b, nv, nt))
        return;
    uint32_t base = b->num_vertices, row = tube_segments + 1;
    for (uint32_t i = 0; i <= arc_segments; ++i) {
        float theta = a0 + (a1 - a0) * (float)i / (float)arc_segments;
        for (uint32_t j = 0; j <= tube_segments; ++j) {
            rl_vec3 n;
            rl_vec3 p = torus_point(major_r, minor_r, theta, j, tube_segments, &n);
            rl_meshbuf_vertex(b, p, n, rl_v2((float)i / (float)arc_segments,
                                             (float)j / (float)tube_segments));
        }
    }
    for (uint32_t i = 0; i < arc_segments; ++i)
        for (uint32_t j = 0; j < tube_segments; ++j) {
            uint32_t v00 = base + i * row + j, v10 = v00 + row;
            rl_meshbuf_triangle(b, v00, v10, v10 + 1);
            rl_meshbuf_triangle(b, v00, v10 + 1, v00 + 1);
        }
    if (!caps)
        return;
    for (int end = 0; end < 2; ++end) {
        float theta = end ? a1 : a0;
        /* The tube circle runs counter-clockwise about -tangent, so the start
         * cap (facing -tangent) fans forwards and the end cap backwards. */
        rl_vec3 tangent = rl_v3(-sinf(theta), cosf(theta), 0.0f);
        rl_vec3 n = end ? tangent : rl_neg(tangent);
        uint32_t centre = rl_meshbuf_vertex(b, rl_scale(rl_v3(cosf(theta), sinf(theta), 0.0f), major_r),
                                            n, rl_v2(0.5f, 0.5f));
        uint32_t rim = b->num_vertices;
        for (uint32_t j = 0; j < tube_segments; ++j) {
            rl_vec3 unused;
            rl_vec3 p = torus_point(major_r, minor_r, theta, j, tube_segments, &unused);
            rl_meshbuf_vertex(b, p, n, rl_v2(0.5f, 0.5f));
        }
        for (uint32_t j = 0; j < tube_segments; ++j) {
            uint32_t p = rim + j, q = rim + (j + 1) % tube_segments;
            if (end)
                rl_meshbuf_triangle(b, centre, q, p);
            else
                rl_meshbuf_triangle(b, centre, p, q);
        }
    }
}

void rl_extrude_convex(rl_meshbuf *b, const rl_vec2 *outline, uint32_t count, float y0,
                       float y1)
{
    rl_vec3 top[RL_EXTRUDE_MAX_POINTS], bottom[RL_EXTRUDE_MAX_POINTS];
    if (count < 3 || count > RL_EXTRUDE_MAX_POINTS)
        return;
    /* y component of the polygon's area normal; negative means clockwise
     * about +y, and the outline is then walked backwards. */
    float area_y = 0.0f;
    for (uint32_t i = 0; i < count; ++i) {
        rl_vec2 p = outline[i], q = outline[(i + 1) % count];
        area_y += p.y * q.x - p.x * q.y;
    }
    bool reverse = area_y < 0.0f;
    if (!rl_meshbuf_reserve(b, 2ull * count + 4ull * count, 2ull * (count - 2) + 2ull * count))
        return;
    for (uint32_t i = 0; i < count; ++i) {
        rl_vec2 o = outline[reverse ? count - 1 - i : i];
        top[i] = rl_v3(o.x, y1, o.y);
        bottom[i] = rl_v3(o.x, y0, o.y);
    }
    uint32_t t0 = b->num_vertices;
    for (uint32_t i = 0; i < count; ++i)
        rl_meshbuf_vertex(b, top[i], rl_v3(0.0f, 1.0f, 0.0f), rl_v2(top[i].x, top[i].z));
    uint32_t b0 = b->num_vertices;
    for (uint32_t i = 0; i < count; ++i)
        rl_meshbuf_vertex(b, bottom[i], rl_v3(0.0f, -1.0f, 0.0f), rl_v2(bottom[i].x, bottom[i].z));
    for (uint32_t i = 1; i + 1 < count; ++i) {
        rl_meshbuf_triangle(b, t0, t0 + i, t0 + i + 1);
        rl_meshbuf_triangle(b, b0, b0 + i + 1, b0 + i);
    }
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t j = (i + 1) % count;
        /* cross(edge, up) points out of a counter-clockwise outline. */
        rl_meshbuf_quad(b, bottom[i], bottom[j], top[j], top[i], rl_v2(1.0f, 1.0f));
    }
}
