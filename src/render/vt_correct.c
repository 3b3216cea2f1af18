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
 * Both test the local term only: shadows are discontinuities (Sec. 6.1.2)
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

/* The direction from p towards light L and E, the light's irradiance scale
 * at p without the cosine (colour intensity / d^2 for point and spot,
 * colour intensity for directional; a quad as a point at its centre with
 * its radiance times its area). */
static rl_vec3 light_at(const rl_light *L, rl_vec3 p, float *E)
{
    float power = rl_vmax_comp(L->color) * L->intensity;
    if (L->type == RL_LIGHT_DIRECTIONAL) {
        *E = power;
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
    return d2 > 0.0f ? rl_scale(d, 1.0f / sqrtf(d2)) : rl_v3(0.0f, 0.0f, 0.0f);
}

/* What the extremum test needs of one end of an edge: its position, its
 * normal turned towards the eye (the side the tracer shades), the unit
 * direction a to the eye, its material. */
typedef struct edge_end {
    rl_vec3 p, n, a;
    const rl_material *m;
} edge_end;

static edge_end end_of(const vt_run *run, const vt_vertex *v)
{
    const rl_scene_data *d = run->data;
    edge_end e;
    e.p = v->p;
    e.a = rl_normalize(rl_sub(run->view.eye, v->p));
    e.n = rl_dot(v->n, e.a) < 0.0f ? rl_neg(v->n) : v->n;
    e.m = &d->materials[d->triangle_material[v->triangle]];
    return e;
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

static bool extremum_fires(const vt_run *run, const edge_end *e1, const edge_end *e2)
{
    const rl_scene_data *d = run->data;
    bool diffuse = rl_vmax_comp(e1->m->diffuse) > 0.0f || rl_vmax_comp(e2->m->diffuse) > 0.0f;
    bool specular = rl_vmax_comp(e1->m->specular) > 0.0f || rl_vmax_comp(e2->m->specular) > 0.0f;
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        float E1, E2;
        rl_vec3 l1 = light_at(&d->lights[i], e1->p, &E1), l2 = light_at(&d->lights[i], e2->p, &E2);
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

/* eps_IA of the edge (a, b), summed over the lights. */
static float interval_bound(const vt_run *run, const vt_vertex *a, const vt_vertex *b)
{
    const rl_scene_data *d = run->data;
    const edge_end ea = end_of(run, a), eb = end_of(run, b);
    /* One material for the interval: an edge between two materials is a
     * discontinuity, not a smooth term; the larger coefficients bound
     * both. */
    float kd = rl_maxf(rl_vmax_comp(ea.m->diffuse), rl_vmax_comp(eb.m->diffuse));
    float ks = rl_maxf(rl_vmax_comp(ea.m->specular), rl_vmax_comp(eb.m->specular));
    float m = rl_maxf(ea.m->shininess, 1e-3f);
    rl_vec3 eye = run->view.eye;
    ia3 ie = ia3_of(eye, eye);
    ia3 p = ia3_of(a->p, b->p), n = ia3_of(ea.n, eb.n);
    /* the normal between the ends is normalize(lerp) (eq. 3.8) */
    n = ia3_normalize(n);
    float bound = 0.0f;
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        ia f = phong_ia(L, p, n, ie, kd, ks, m);
        float f1 = phong_ia(L, ia3_of(a->p, a->p), ia3_of(ea.n, ea.n), ie, kd, ks, m).hi;
        float f2 = phong_ia(L, ia3_of(b->p, b->p), ia3_of(eb.n, eb.n), ie, kd, ks, m).hi;
        /* f' lies between f_1 and f_2, f within [lo, hi] */
        bound += rl_maxf(f.hi - rl_minf(f1, f2), rl_maxf(f1, f2) - f.lo);
    }
    return bound;
}

bool vt_nonlinear_fires(const vt_run *run, const vt_vertex *a, const vt_vertex *b)
{
    switch (run->set->nonlinear) {
    case VT_NONLINEAR_EXTREMUM: {
        const edge_end ea = end_of(run, a), eb = end_of(run, b);
        return extremum_fires(run, &ea, &eb);
    }
    case VT_NONLINEAR_INTERVAL:
        return interval_bound(run, a, b) > run->set->eps_ia;
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
