/* test_watertight.c: no ray slips through a closed mesh, for every kind
 * (bvh, grid, embree when built, brute), and the shared watertight
 * ray/triangle test of Woop, Benthin and Wald 2013 itself.
 *
 * Closed meshes: the generated box and UV sphere (rl_scene_add_generated)
 * and an indexed icosphere built here with every edge shared by exactly two
 * triangles, all under a rotation + scale + translation so that the world
 * coordinates are not round numbers. Rays are aimed exactly (in float) at
 * every edge midpoint and every vertex, from two interior points outwards
 * and from outside towards the interior point; a ray that escapes through a
 * crack either misses (inside) or hits the far side (outside), so both
 * checks assert the hit distance, not only a hit. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel_internal.h"
#include "rl/rl_accel.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

/* ---- meshes ---------------------------------------------------------------- */

typedef struct mesh {
    rl_vec3 *p;
    uint32_t *idx;
    uint32_t nv, nt, cap_v, cap_t;
} mesh;

static uint32_t mesh_vertex(mesh *m, rl_vec3 p)
{
    assert_true(m->nv < m->cap_v);
    m->p[m->nv] = p;
    return m->nv++;
}

static void mesh_triangle(mesh *m, uint32_t a, uint32_t b, uint32_t c)
{
    assert_true(m->nt < m->cap_t);
    m->idx[3 * m->nt] = a;
    m->idx[3 * m->nt + 1] = b;
    m->idx[3 * m->nt + 2] = c;
    m->nt++;
}

/* Index of the midpoint vertex of edge (a, b), created once per edge so that
 * both triangles of the edge use the same vertex (no T-junctions). */
typedef struct edge_mid { uint32_t a, b, mid; } edge_mid;

static uint32_t midpoint(mesh *m, edge_mid *edges, uint32_t *n_edges, uint32_t a, uint32_t b)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    for (uint32_t i = 0; i < *n_edges; ++i)
        if (edges[i].a == lo && edges[i].b == hi)
            return edges[i].mid;
    rl_vec3 p = rl_normalize(rl_add(m->p[a], m->p[b]));   /* onto the unit sphere */
    edges[*n_edges] = (edge_mid){ lo, hi, mesh_vertex(m, p) };
    return edges[(*n_edges)++].mid;
}

/* The regular icosahedron (vertices are the cyclic permutations of
 * (0, ±1, ±φ)), subdivided `levels` times by splitting every triangle into
 * four and pushing the new vertices onto the unit sphere. */
static mesh icosphere(int levels)
{
    uint32_t nt = 20u << (2 * levels);
    mesh m = { .cap_v = nt / 2 + 2, .cap_t = nt };
    m.p = calloc(m.cap_v, sizeof *m.p);
    m.idx = calloc(3 * (size_t)m.cap_t, sizeof *m.idx);
    assert_non_null(m.p);
    assert_non_null(m.idx);
    const float phi = 1.6180339887f;
    const float base[12][3] = {
        { -1, phi, 0 }, { 1, phi, 0 }, { -1, -phi, 0 }, { 1, -phi, 0 },
        { 0, -1, phi }, { 0, 1, phi }, { 0, -1, -phi }, { 0, 1, -phi },
        { phi, 0, -1 }, { phi, 0, 1 }, { -phi, 0, -1 }, { -phi, 0, 1 },
    };
    const uint32_t faces[20][3] = {
        { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 },
        { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
        { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 },
        { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 },
    };
    for (int i = 0; i < 12; ++i)
        mesh_vertex(&m, rl_normalize(rl_v3(base[i][0], base[i][1], base[i][2])));
    for (int f = 0; f < 20; ++f)
        mesh_triangle(&m, faces[f][0], faces[f][1], faces[f][2]);
    uint32_t *next = calloc(3 * (size_t)m.cap_t, sizeof *next);
    edge_mid *edges = calloc(3 * (size_t)m.cap_t / 2, sizeof *edges);
    assert_non_null(next);
    assert_non_null(edges);
    for (int l = 0; l < levels; ++l) {
        uint32_t n_old = m.nt, n_edges = 0;
        memcpy(next, m.idx, 3 * (size_t)n_old * sizeof *next);
        m.nt = 0;
        for (uint32_t t = 0; t < n_old; ++t) {
            uint32_t a = next[3 * t], b = next[3 * t + 1], c = next[3 * t + 2];
            uint32_t ab = midpoint(&m, edges, &n_edges, a, b);
            uint32_t bc = midpoint(&m, edges, &n_edges, b, c);
            uint32_t ca = midpoint(&m, edges, &n_edges, c, a);
            mesh_triangle(&m, a, ab, ca);
            mesh_triangle(&m, b, bc, ab);
            mesh_triangle(&m, c, ca, bc);
            mesh_triangle(&m, ab, bc, ca);
        }
    }
    free(next);
    free(edges);
    return m;
}

/* Closed and consistently wound: every directed edge (a, b) appears once and
 * its reverse (b, a) once. Checks the test's own mesh. */
static void assert_closed(const mesh *m)
{
    for (uint32_t t = 0; t < m->nt; ++t)
        for (int e = 0; e < 3; ++e) {
            uint32_t a = m->idx[3 * t + e], b = m->idx[3 * t + (e + 1) % 3];
            int same = 0, reverse = 0;
            for (uint32_t s = 0; s < m->nt; ++s)
                for (int f = 0; f < 3; ++f) {
                    uint32_t c = m->idx[3 * s + f], d = m->idx[3 * s + (f + 1) % 3];
                    same += c == a && d == b;
                    reverse += c == b && d == a;
                }
            if (same != 1 || reverse != 1)
                fail_msg("edge %u-%u: %d times, reverse %d times", a, b, same, reverse);
        }
}

/* Rotation by 0.7 rad about (1,2,3)/|.| (Rodrigues), scale 1.3, then a
 * translation: world coordinates that are nowhere exact. */
static const float placement_scale = 1.3f;
static rl_vec3 placement_origin(void) { return rl_v3(0.3f, -0.2f, 0.1f); }

static rl_mat4 placement(void)
{
    double k[3] = { 1, 2, 3 }, len = sqrt(14.0), th = 0.7, c = cos(th), s = sin(th);
    for (int i = 0; i < 3; ++i)
        k[i] /= len;
    double kx[3][3] = { { 0, -k[2], k[1] }, { k[2], 0, -k[0] }, { -k[1], k[0], 0 } };
    rl_mat4 m = { { { 0 } } };
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double r = (i == j ? c : 0.0) + s * kx[i][j] + (1.0 - c) * k[i] * k[j];
            m.m[i][j] = (float)(placement_scale * r);
        }
    rl_vec3 t = placement_origin();
    m.m[0][3] = t.x;
    m.m[1][3] = t.y;
    m.m[2][3] = t.z;
    m.m[3][3] = 1.0f;
    return m;
}

typedef enum { SHAPE_ICOSPHERE, SHAPE_SPHERE, SHAPE_BOX, SHAPE_COUNT } shape;
static const char *const shape_names[SHAPE_COUNT] = { "icosphere", "generated sphere",
                                                      "generated box" };

static rl_scene *closed_scene(shape which)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material mat = rl_material_default();
    uint32_t mat_id = 0, mesh_id = 0, node = 0;
    assert_int_equal(rl_scene_add_material(s, &mat, &mat_id), RL_OK);
    if (which == SHAPE_ICOSPHERE) {
        mesh m = icosphere(3);
        assert_int_equal(m.nt, 1280);
        assert_int_equal(m.nv, 642);
        assert_closed(&m);
        rl_mesh_desc d = { .name = "icosphere", .num_vertices = m.nv, .positions = m.p,
                           .num_triangles = m.nt, .indices = m.idx, .material = mat_id };
        assert_int_equal(rl_scene_add_mesh(s, &d, &mesh_id), RL_OK);
        free(m.p);
        free(m.idx);
    } else {
        const char *gen = which == SHAPE_SPHERE ? "sphere" : "box";
        const char *params = which == SHAPE_SPHERE ? "segments=32,rings=17" : "size=1";
        assert_int_equal(rl_scene_add_generated(s, gen, params, mat_id, &mesh_id), RL_OK);
    }
    rl_mat4 xf = placement();
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "closed", &xf, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh_id), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* ---- rays at edges and vertices ------------------------------------------- */

typedef struct escape_count {
    unsigned rays, escapes;
    char first[200];
} escape_count;

static void note_escape(escape_count *c, const char *what, rl_vec3 target, bool hit, float t)
{
    if (c->escapes++ == 0)
        snprintf(c->first, sizeof c->first, "%s ray at (%.9g, %.9g, %.9g): %s t = %.9g", what,
                 (double)target.x, (double)target.y, (double)target.z, hit ? "hit at" : "missed,",
                 (double)t);
}

/* Inside out: o = centre, d = target - centre, so the surface is at t ≈ 1.
 * Outside in: o = target + (target - centre), d = centre - target: the near
 * surface at t ≈ 1, the far one near t = 3; a crack shows as t ≈ 3. */
static void shoot_at(const rl_accel *a, rl_vec3 centre, rl_vec3 target, escape_count *c)
{
    rl_vec3 d = rl_sub(target, centre);
    rl_ray in = { .o = centre, .d = d, .t_min = 0.0f, .t_max = INFINITY };
    rl_hit h;
    bool hit = rl_accel_intersect(a, &in, &h);
    c->rays++;
    if (!hit || fabsf(h.t - 1.0f) > 0.05f)
        note_escape(c, "inside-out", target, hit, hit ? h.t : 0.0f);
    rl_ray seg = { .o = centre, .d = d, .t_min = 0.0f, .t_max = 2.0f };
    c->rays++;
    if (!rl_accel_occluded(a, &seg))
        note_escape(c, "inside-out occlusion", target, false, 0.0f);

    rl_ray out = { .o = rl_add(target, d), .d = rl_neg(d), .t_min = 0.0f, .t_max = INFINITY };
    hit = rl_accel_intersect(a, &out, &h);
    c->rays++;
    if (!hit || fabsf(h.t - 1.0f) > 0.05f)
        note_escape(c, "outside-in", target, hit, hit ? h.t : 0.0f);
}

static int compare_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* Every vertex once and every edge once (by index pair). */
static void shoot_at_every_edge_and_vertex(const rl_accel *a, const rl_scene_data *d,
                                           rl_vec3 centre, escape_count *c)
{
    for (uint32_t v = 0; v < d->num_vertices; ++v)
        shoot_at(a, centre, d->positions[v], c);
    size_t n = 3 * (size_t)d->num_triangles;
    uint64_t *edges = malloc(n * sizeof *edges);
    assert_non_null(edges);
    for (size_t i = 0; i < n; ++i) {
        uint32_t p = d->indices[i], q = d->indices[i - i % 3 + (i + 1) % 3];
        edges[i] = p < q ? (uint64_t)p << 32 | q : (uint64_t)q << 32 | p;
    }
    qsort(edges, n, sizeof *edges, compare_u64);
    for (size_t i = 0; i < n; ++i) {
        if (i > 0 && edges[i] == edges[i - 1])
            continue;
        rl_vec3 p = d->positions[edges[i] >> 32], q = d->positions[edges[i] & 0xFFFFFFFFu];
        shoot_at(a, centre, rl_scale(rl_add(p, q), 0.5f), c);
    }
    free(edges);
}

static void test_no_kind_lets_rays_escape_through_closed_meshes(void **state)
{
    (void)state;
    const rl_vec3 origin = placement_origin();
    /* The centre, and a point off every symmetry of the meshes. */
    const rl_vec3 centres[2] = {
        origin, rl_add(origin, rl_scale(rl_v3(0.11f, 0.047f, -0.073f), placement_scale)),
    };
    for (int sh = 0; sh < SHAPE_COUNT; ++sh) {
        rl_scene *s = closed_scene((shape)sh);
        const rl_scene_data *d = rl_scene_get_data(s);
        for (int k = 0; k < RL_ACCEL_KIND_COUNT; ++k) {
            if (!rl_accel_kind_available((rl_accel_kind)k))
                continue;
            rl_accel *a = NULL;
            assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = (rl_accel_kind)k }, &a),
                             RL_OK);
            if (rl_accel_commit(a) != RL_OK)
                fail_msg("%s on %s: %s", rl_accel_kind_name((rl_accel_kind)k), shape_names[sh],
                         rl_last_error());
            escape_count c = { 0 };
            for (int i = 0; i < 2; ++i)
                shoot_at_every_edge_and_vertex(a, d, centres[i], &c);
            rl_accel_release(a);
            if (c.escapes)
                fail_msg("%s, %s: %u of %u rays escaped; first: %s",
                         rl_accel_kind_name((rl_accel_kind)k), shape_names[sh], c.escapes, c.rays,
                         c.first);
            print_message("%-6s %-16s %u edge/vertex rays, none escaped\n",
                          rl_accel_kind_name((rl_accel_kind)k), shape_names[sh], c.rays);
        }
        rl_scene_release(s);
    }
}

/* ---- the triangle test itself ---------------------------------------------- */

static rl_vec3 random_point(rl_rng *rng, float half)
{
    return rl_v3((2.0f * rl_rng_float(rng) - 1.0f) * half, (2.0f * rl_rng_float(rng) - 1.0f) * half,
                 (2.0f * rl_rng_float(rng) - 1.0f) * half);
}

static bool hits(rl_vec3 o, rl_vec3 d, rl_vec3 a, rl_vec3 b, rl_vec3 c)
{
    rl_ray r = { .o = o, .d = d, .t_min = 0.0f, .t_max = INFINITY };
    rl_ray_watertight w;
    rl_ray_watertight_setup(&r, &w);
    float t, u, v;
    return rl_triangle_intersect_watertight(&w, a, b, c, r.t_min, r.t_max, &t, &u, &v);
}

/* Side of point p relative to the plane through o, a and b, in double. */
static double side(rl_vec3 o, rl_vec3 a, rl_vec3 b, rl_vec3 p)
{
    double ax = (double)a.x - o.x, ay = (double)a.y - o.y, az = (double)a.z - o.z;
    double bx = (double)b.x - o.x, by = (double)b.y - o.y, bz = (double)b.z - o.z;
    double px = (double)p.x - o.x, py = (double)p.y - o.y, pz = (double)p.z - o.z;
    return (ay * bz - az * by) * px + (az * bx - ax * bz) * py + (ax * by - ay * bx) * pz;
}

static void test_watertight_test_never_lets_a_ray_through_a_quads_diagonal(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 2013, 1);
    int tested = 0, both = 0;
    for (int quad = 0; quad < 400; ++quad) {
        /* A slightly non-planar quad p0 p1 p3 p2 split along p1-p2 into
         * (p0, p1, p2) and (p3, p2, p1), wound consistently. */
        rl_vec3 p0 = random_point(&rng, 1.0f), p1 = random_point(&rng, 1.0f);
        rl_vec3 p2 = random_point(&rng, 1.0f);
        rl_vec3 p3 = rl_add(rl_sub(rl_add(p1, p2), p0), random_point(&rng, 0.1f));
        for (int k = 0; k < 20; ++k) {
            /* Inside the diagonal: its ends are corners of the quad, where
             * a ray may pass outside both (the fan test covers vertices). */
            float s = 0.001f + 0.998f * rl_rng_float(&rng);
            rl_vec3 q = rl_add(p1, rl_scale(rl_sub(p2, p1), s));   /* on the edge, in float */
            rl_vec3 o = random_point(&rng, 4.0f);
            /* Only rays that cross the surface at the edge: p0 and p3 on
             * opposite sides of the plane of o and the edge (a ray grazing
             * a fold may touch neither triangle). */
            double s0 = side(o, p1, p2, p0), s3 = side(o, p1, p2, p3);
            if (!(s0 * s3 < 0.0))
                continue;
            rl_vec3 d = rl_sub(q, o);
            bool h1 = hits(o, d, p0, p1, p2), h2 = hits(o, d, p3, p2, p1);
            ++tested;
            both += h1 && h2;
            if (!h1 && !h2)
                fail_msg("quad %d, edge point %d (s = %.9g): the ray slipped through", quad, k,
                         (double)s);
        }
    }
    assert_true(tested > 3000);   /* "thousands of edge points" */
    print_message("%d rays through shared edges: none slipped, %d hit both triangles\n", tested,
                  both);
}

static void test_watertight_test_closes_a_fan_around_a_shared_vertex(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 2013, 2);
    int tested = 0;
    for (int fan = 0; fan < 300; ++fan) {
        /* Seven triangles around a random centre c in a wobbly disc. */
        enum { N = 7 };
        rl_vec3 c = random_point(&rng, 1.0f), ring[N];
        float phase = rl_rng_float(&rng);
        for (int i = 0; i < N; ++i) {
            float a = 2.0f * RL_PI * ((float)i + phase + 0.3f * rl_rng_float(&rng)) / (float)N;
            ring[i] = rl_add(c, rl_v3(cosf(a), 0.15f * (2.0f * rl_rng_float(&rng) - 1.0f), sinf(a)));
        }
        for (int k = 0; k < 10; ++k) {
            /* From well above or below the disc, so no fold hides c. */
            rl_vec3 o = rl_add(c, rl_v3(1.5f * (2.0f * rl_rng_float(&rng) - 1.0f),
                                        k % 2 ? 3.0f : -3.0f, 1.5f * (2.0f * rl_rng_float(&rng) - 1.0f)));
            rl_vec3 d = rl_sub(c, o);
            int n_hits = 0;
            for (int i = 0; i < N; ++i)
                n_hits += hits(o, d, c, ring[i], ring[(i + 1) % N]);
            ++tested;
            if (n_hits == 0)
                fail_msg("fan %d, ray %d: slipped through the shared vertex", fan, k);
        }
    }
    assert_int_equal(tested, 3000);
}

/* The negative control: the same machinery reports misses just outside. */
static void test_watertight_test_misses_just_outside_a_quad(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 2013, 3);
    for (int quad = 0; quad < 1000; ++quad) {
        rl_vec3 p0 = random_point(&rng, 1.0f), p1 = random_point(&rng, 1.0f);
        rl_vec3 p2 = random_point(&rng, 1.0f);
        rl_vec3 p3 = rl_sub(rl_add(p1, p2), p0);                   /* a parallelogram */
        rl_vec3 centre = rl_scale(rl_add(p1, p2), 0.5f);
        rl_vec3 corner = quad % 2 ? p1 : p0;
        rl_vec3 q = rl_add(centre, rl_scale(rl_sub(corner, centre), 1.02f));
        rl_vec3 o = random_point(&rng, 4.0f);
        rl_vec3 d = rl_sub(q, o);
        /* Skip near-grazing views where 2 % beyond a corner is below float
         * resolution in the projection. */
        rl_vec3 n = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
        if (fabsf(rl_dot(n, rl_normalize(d))) < 0.05f)
            continue;
        if (hits(o, d, p0, p1, p2) || hits(o, d, p3, p2, p1))
            fail_msg("quad %d: a ray 2 %% beyond a corner hit", quad);
    }
}

static void test_watertight_test_gives_t_u_v_in_the_rl_hit_convention(void **state)
{
    (void)state;
    rl_vec3 p0 = rl_v3(0, 0, 0), p1 = rl_v3(2, 0, 0), p2 = rl_v3(0, 4, 0);
    rl_ray r = { .o = rl_v3(0.5f, 1.0f, 3.0f), .d = rl_v3(0, 0, -1), .t_min = 0, .t_max = INFINITY };
    rl_ray_watertight w;
    rl_ray_watertight_setup(&r, &w);
    float t = -1, u = -1, v = -1;
    assert_true(rl_triangle_intersect_watertight(&w, p0, p1, p2, 0.0f, INFINITY, &t, &u, &v));
    assert_float_equal(t, 3.0f, 0.0f);
    assert_float_equal(u, 0.25f, 0.0f);      /* weight of p1: x / 2 */
    assert_float_equal(v, 0.25f, 0.0f);      /* weight of p2: y / 4 */
    /* Backfaces hit too: reversed winding gives the same t, swapped u/v. */
    assert_true(rl_triangle_intersect_watertight(&w, p0, p2, p1, 0.0f, INFINITY, &t, &u, &v));
    assert_float_equal(t, 3.0f, 0.0f);
    assert_float_equal(u, 0.25f, 0.0f);
    /* The segment is open: (t_min, t_max) excludes both ends. */
    assert_false(rl_triangle_intersect_watertight(&w, p0, p1, p2, 0.0f, 3.0f, &t, &u, &v));
    assert_false(rl_triangle_intersect_watertight(&w, p0, p1, p2, 3.0f, INFINITY, &t, &u, &v));
    assert_true(rl_triangle_intersect_watertight(&w, p0, p1, p2, 2.999f, 3.001f, &t, &u, &v));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_watertight_test_gives_t_u_v_in_the_rl_hit_convention),
        cmocka_unit_test(test_watertight_test_never_lets_a_ray_through_a_quads_diagonal),
        cmocka_unit_test(test_watertight_test_closes_a_fan_around_a_shared_vertex),
        cmocka_unit_test(test_watertight_test_misses_just_outside_a_quad),
        cmocka_unit_test(test_no_kind_lets_rays_escape_through_closed_meshes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
