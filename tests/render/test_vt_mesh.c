/* test_vt_mesh.c: the Vertex Tracing refinement mesh (vt_mesh.c): welding
 * and edge pairing on meshes built in code, the exact shape of one split
 * (Ullmann 2003, Fig. 3.5), and a full consistency check (adjacency both
 * ways, orientation, areas, no T-junctions, Euler characteristic of a closed
 * mesh) after thousands of random splits on a grid, a closed cube and a
 * committed UV sphere. Reset must give back the freshly built mesh. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/vt_internal.h"

/* ------------------------------------------------------- scene builders -- */

/* Hand-made rl_scene_data: owns its arrays. */
typedef struct toy {
    rl_scene_data d;
    rl_vec3 *p, *n;
    rl_vec2 *uv;
    uint32_t *idx, *tri_obj;
    rl_object *obj;
    uint32_t nv, nt, no;
} toy;

static void toy_init(toy *t, uint32_t max_v, uint32_t max_t, uint32_t max_o)
{
    memset(t, 0, sizeof *t);
    t->p = calloc(max_v, sizeof *t->p);
    t->n = calloc(max_v, sizeof *t->n);
    t->uv = calloc(max_v, sizeof *t->uv);
    t->idx = calloc(3 * (size_t)max_t, sizeof *t->idx);
    t->tri_obj = calloc(max_t, sizeof *t->tri_obj);
    t->obj = calloc(max_o, sizeof *t->obj);
    assert_non_null(t->p);
    assert_non_null(t->n);
    assert_non_null(t->uv);
    assert_non_null(t->idx);
    assert_non_null(t->tri_obj);
    assert_non_null(t->obj);
}

static void toy_free(toy *t)
{
    free(t->p);
    free(t->n);
    free(t->uv);
    free(t->idx);
    free(t->tri_obj);
    free(t->obj);
}

static void toy_begin_object(toy *t)
{
    t->obj[t->no].first_triangle = t->nt;
    t->obj[t->no].first_vertex = t->nv;
    t->no++;
}

static uint32_t toy_vertex(toy *t, rl_vec3 p, rl_vec3 n, rl_vec2 uv)
{
    t->p[t->nv] = p;
    t->n[t->nv] = n;
    t->uv[t->nv] = uv;
    t->obj[t->no - 1].num_vertices++;
    return t->nv++;
}

static void toy_triangle(toy *t, uint32_t a, uint32_t b, uint32_t c)
{
    t->idx[3 * t->nt] = a;
    t->idx[3 * t->nt + 1] = b;
    t->idx[3 * t->nt + 2] = c;
    t->tri_obj[t->nt] = t->no - 1;
    t->obj[t->no - 1].num_triangles++;
    t->nt++;
}

static const rl_scene_data *toy_data(toy *t)
{
    t->d.num_vertices = t->nv;
    t->d.positions = t->p;
    t->d.normals = t->n;
    t->d.uvs = t->uv;
    t->d.num_triangles = t->nt;
    t->d.indices = t->idx;
    t->d.triangle_object = t->tri_obj;
    t->d.num_objects = t->no;
    t->d.objects = t->obj;
    return &t->d;
}

/* n x n quads in the z = 0 plane, counter-clockwise seen from +z. */
static void toy_grid(toy *t, uint32_t n)
{
    toy_init(t, (n + 1) * (n + 1), 2 * n * n, 1);
    toy_begin_object(t);
    for (uint32_t j = 0; j <= n; ++j)
        for (uint32_t i = 0; i <= n; ++i)
            toy_vertex(t, rl_v3((float)i, (float)j, 0.0f), rl_v3(0, 0, 1),
                       rl_v2((float)i / (float)n, (float)j / (float)n));
    for (uint32_t j = 0; j < n; ++j)
        for (uint32_t i = 0; i < n; ++i) {
            uint32_t a = j * (n + 1) + i, b = a + 1, c = a + n + 2, d = a + n + 1;
            toy_triangle(t, a, b, c);
            toy_triangle(t, a, c, d);
        }
}

/* A unit cube as a loader delivers it: every triangle with its own three
 * vertices, which weld to the 8 corners (smooth normals, uv 0). Outward
 * facing, counter-clockwise. */
static void toy_cube_soup(toy *t)
{
    static const int quads[6][4] = {
        { 0, 2, 3, 1 }, { 4, 5, 7, 6 }, { 0, 1, 5, 4 },
        { 2, 6, 7, 3 }, { 0, 4, 6, 2 }, { 1, 3, 7, 5 },
    };
    toy_init(t, 36, 12, 1);
    toy_begin_object(t);
    for (int q = 0; q < 6; ++q) {
        const int tri[2][3] = { { quads[q][0], quads[q][1], quads[q][2] },
                                { quads[q][0], quads[q][2], quads[q][3] } };
        for (int k = 0; k < 2; ++k) {
            uint32_t v[3];
            for (int c = 0; c < 3; ++c) {
                int corner = tri[k][c];
                rl_vec3 p = rl_v3((float)(corner & 1), (float)((corner >> 1) & 1),
                                  (float)((corner >> 2) & 1));
                rl_vec3 n = rl_normalize(rl_sub(p, rl_v3s(0.5f)));
                v[c] = toy_vertex(t, p, n, rl_v2(0, 0));
            }
            toy_triangle(t, v[0], v[1], v[2]);
        }
    }
}

/* --------------------------------------------------- consistency check -- */

static rl_vec3 face_cross(const vt_mesh *m, uint32_t f)
{
    const vt_face *fc = &m->faces[f];
    rl_vec3 a = m->verts[fc->v[0]].p, b = m->verts[fc->v[1]].p, c = m->verts[fc->v[2]].p;
    return rl_cross(rl_sub(b, a), rl_sub(c, a));
}

/* In double from the float positions: children of a sliver must add up to
 * their parent beyond float rounding. */
static double face_area(const vt_mesh *m, uint32_t f)
{
    const vt_face *fc = &m->faces[f];
    double p[3][3];
    for (int k = 0; k < 3; ++k) {
        rl_vec3 v = m->verts[fc->v[k]].p;
        p[k][0] = v.x;
        p[k][1] = v.y;
        p[k][2] = v.z;
    }
    double u[3], w[3];
    for (int i = 0; i < 3; ++i) {
        u[i] = p[1][i] - p[0][i];
        w[i] = p[2][i] - p[0][i];
    }
    double cx = u[1] * w[2] - u[2] * w[1], cy = u[2] * w[0] - u[0] * w[2];
    double cz = u[0] * w[1] - u[1] * w[0];
    return 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
}

static bool face_has_edge_ccw(const vt_face *f, uint32_t a, uint32_t b)
{
    for (int i = 0; i < 3; ++i)
        if (f->v[i] == a && f->v[(i + 1) % 3] == b)
            return true;
    return false;
}

/* Every invariant of the refinement mesh (the input is consistently wound,
 * so the orientation convention is checked strictly). closed: every live
 * edge must have two faces and V - E + F = 2. */
static void check_mesh(const vt_mesh *m, bool closed)
{
    uint32_t split_edges = 0, live_edges = 0, leaf_faces = 0;
    /* per primary face: the area of its leaves */
    double *leaf_area = calloc(m->num_primary_faces ? m->num_primary_faces : 1, sizeof *leaf_area);
    uint8_t *seq_seen = calloc(m->num_created ? m->num_created : 1, 1);
    assert_non_null(leaf_area);
    assert_non_null(seq_seen);

    for (uint32_t f = 0; f < m->num_faces; ++f) {
        const vt_face *fc = &m->faces[f];
        /* seq: unique, below num_created; the index when nothing was dropped */
        assert_true(fc->seq < m->num_created);
        assert_false(seq_seen[fc->seq]);
        seq_seen[fc->seq] = 1;
        if (!m->drop_parents)
            assert_int_equal(fc->seq, f);
        uint32_t root = vt_face_root(m, f);
        assert_true(root < m->num_primary_faces);
        assert_int_equal(m->faces[root].triangle, fc->triangle);
        if (f >= m->num_primary_faces) {
            /* same orientation as its primary face; a dropped parent
             * leaves only leaves behind */
            assert_true(rl_dot(face_cross(m, f), face_cross(m, root)) > 0.0f);
            if (m->drop_parents)
                assert_true(fc->leaf);
        }
        if (!fc->leaf)
            continue;
        leaf_faces++;
        leaf_area[root] += face_area(m, f);
        for (int i = 0; i < 3; ++i) {
            assert_true(fc->v[i] < m->num_verts);
            assert_true(fc->e[i] < m->num_edges);
            const vt_edge *e = &m->edges[fc->e[i]];
            /* a leaf face's edges are unsplit, join the right corners and
             * reference the face back */
            assert_int_equal(e->child, VT_NONE);
            uint32_t a = fc->v[(i + 1) % 3], b = fc->v[(i + 2) % 3];
            assert_true((e->v[0] == a && e->v[1] == b) || (e->v[0] == b && e->v[1] == a));
            assert_true(e->face[0] == f || e->face[1] == f);
        }
    }
    /* the leaves of each primary face cover it exactly */
    for (uint32_t f = 0; f < m->num_primary_faces; ++f) {
        double a = face_area(m, f);
        if (!(fabs(leaf_area[f] - a) <= 1e-4 * a + 1e-12))
            fail_msg("face %u: area %g, leaves %g", f, a, leaf_area[f]);
    }

    for (uint32_t ei = 0; ei < m->num_edges; ++ei) {
        const vt_edge *e = &m->edges[ei];
        assert_true(e->v[0] < m->num_verts && e->v[1] < m->num_verts);
        assert_true(e->v[0] != e->v[1]);
        if (e->child != VT_NONE) {
            split_edges++;
            const uint32_t mid = vt_edge_mid(m, ei);
            assert_true(mid < m->num_verts);
            const vt_edge *c0 = &m->edges[e->child], *c1 = &m->edges[e->child + 1];
            assert_int_equal(c0->v[0], e->v[0]);
            assert_int_equal(c0->v[1], mid);
            assert_int_equal(c1->v[0], mid);
            assert_int_equal(c1->v[1], e->v[1]);
            rl_vec3 want = rl_scale(rl_add(m->verts[e->v[0]].p, m->verts[e->v[1]].p), 0.5f);
            assert_float_equal(m->verts[mid].p.x, want.x, 1e-6);
            assert_float_equal(m->verts[mid].p.y, want.y, 1e-6);
            assert_float_equal(m->verts[mid].p.z, want.z, 1e-6);
            /* no T-junction: every face beside a split edge was split too
             * (with drop_parents its slot may hold its first child: a split
             * edge's faces are read only for their primary face, which the
             * child shares) */
            for (int s = 0; s < 2; ++s)
                if (e->face[s] != VT_NONE) {
                    if (!m->drop_parents || e->face[s] < m->num_primary_faces)
                        assert_false(m->faces[e->face[s]].leaf);
                    else
                        assert_true(vt_face_root(m, e->face[s]) < m->num_primary_faces);
                }
            continue;
        }
        assert_int_equal(e->child, VT_NONE);
        live_edges++;
        assert_true(e->face[0] != VT_NONE);
        if (closed)
            assert_true(e->face[1] != VT_NONE);
        for (int s = 0; s < 2; ++s) {
            if (e->face[s] == VT_NONE)
                continue;
            const vt_face *fc = &m->faces[e->face[s]];
            assert_true(fc->leaf);
            assert_true(fc->e[0] == ei || fc->e[1] == ei || fc->e[2] == ei);
            /* face[0] runs v[0] -> v[1], face[1] the other way round */
            if (s == 0)
                assert_true(face_has_edge_ccw(fc, e->v[0], e->v[1]));
            else
                assert_true(face_has_edge_ccw(fc, e->v[1], e->v[0]));
        }
        assert_true(e->face[0] != e->face[1]);
    }
    assert_int_equal(m->num_verts, m->num_primary_verts + split_edges);
    if (closed)
        assert_int_equal((int64_t)m->num_verts - live_edges + leaf_faces, 2);

    double primary = 0.0, leaves = 0.0;
    for (uint32_t f = 0; f < m->num_faces; ++f) {
        if (f < m->num_primary_faces)
            primary += face_area(m, f);
        if (m->faces[f].leaf)
            leaves += face_area(m, f);
    }
    assert_true(fabs(primary - leaves) <= 1e-5 * primary);
    free(leaf_area);
    free(seq_seen);
}

static uint64_t rng_next(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

/* Splits count random unsplit edges, checking each split's report and the
 * whole mesh every check_every splits. */
static void random_splits(vt_mesh *m, int count, uint64_t seed, bool closed, int check_every)
{
    for (int i = 0; i < count; ++i) {
        uint32_t e;
        do
            e = (uint32_t)(rng_next(&seed) % m->num_edges);
        while (m->edges[e].child != VT_NONE);
        int sides = (m->edges[e].face[0] != VT_NONE) + (m->edges[e].face[1] != VT_NONE);
        uint32_t a = m->edges[e].v[0], b = m->edges[e].v[1];
        uint32_t verts = m->num_verts, faces = m->num_faces;
        uint32_t ne[4], nf[4], num_e = 99, num_f = 99;
        uint32_t mid = vt_mesh_split(m, e, (uint16_t)(1 + i % 7), ne, &num_e, nf, &num_f);
        assert_int_equal(mid, verts);
        assert_int_equal(m->num_verts, verts + 1);
        assert_int_equal(num_e, 2 + (uint32_t)sides);
        assert_int_equal(num_f, 2 * (uint32_t)sides);
        if (m->drop_parents)     /* a split face that is not primary gives its slot */
            assert_true(m->num_faces >= faces + (uint32_t)sides && m->num_faces <= faces + 2 * (uint32_t)sides);
        else
            assert_int_equal(m->num_faces, faces + 2 * (uint32_t)sides);
        assert_int_equal(ne[0], m->edges[e].child);
        assert_int_equal(ne[1], m->edges[e].child + 1);
        for (uint32_t k = 0; k < num_f; ++k) {
            assert_true(m->faces[nf[k]].leaf);
            assert_int_equal(m->faces[nf[k]].stage, 1 + i % 7);
        }
        assert_true(m->verts[mid].key == vt_vertex_key_mid(m->verts[a].key, m->verts[b].key));
        assert_int_equal(m->verts[mid].state, VT_UNSAMPLED);
        if ((i + 1) % check_every == 0)
            check_mesh(m, closed);
    }
    check_mesh(m, closed);
}

/* -------------------------------------------------------------- tests -- */

static void test_grid_builds_shared_edges(void **state)
{
    (void)state;
    toy t;
    toy_grid(&t, 10);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    assert_int_equal(m.num_verts, 121);
    assert_int_equal(m.num_faces, 200);
    /* 10 x 11 horizontal + 11 x 10 vertical + 100 diagonals */
    assert_int_equal(m.num_edges, 320);
    assert_int_equal(m.num_primary_verts, 121);
    assert_int_equal(m.num_primary_edges, 320);
    assert_int_equal(m.num_primary_faces, 200);
    uint32_t boundary = 0;
    for (uint32_t e = 0; e < m.num_edges; ++e)
        boundary += m.edges[e].face[1] == VT_NONE;
    assert_int_equal(boundary, 40);
    for (uint32_t f = 0; f < m.num_faces; ++f) {
        assert_int_equal(m.faces[f].triangle, f);
        assert_int_equal(m.faces[f].leaf, 1);
        assert_int_equal(m.faces[f].visible, 0);
        assert_int_equal(m.faces[f].stage, 0);
        for (int i = 0; i < 3; ++i) {
            rl_vec3 want = t.p[t.idx[3 * f + (uint32_t)i]];
            assert_memory_equal(&m.verts[m.faces[f].v[i]].p, &want, sizeof want);
        }
    }
    for (uint32_t v = 0; v < m.num_verts; ++v)
        assert_true(m.verts[v].key == vt_vertex_key_primary(0, v));
    check_mesh(&m, false);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_cube_soup_welds_into_a_closed_mesh(void **state)
{
    (void)state;
    toy t;
    toy_cube_soup(&t);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    assert_int_equal(m.num_verts, 8);
    assert_int_equal(m.num_edges, 18);
    assert_int_equal(m.num_faces, 12);
    /* keys number the welded vertices in order of first use */
    for (uint32_t v = 0; v < 8; ++v)
        assert_true(m.verts[v].key == vt_vertex_key_primary(0, v));
    assert_int_equal(m.verts[0].triangle, 0);
    check_mesh(&m, true);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_weld_needs_equal_normal_and_uv(void **state)
{
    (void)state;
    /* Two triangles sharing positions a, b but with a different uv at b: a
     * texture seam is a boundary, not a shared edge. */
    toy t;
    toy_init(&t, 6, 2, 1);
    toy_begin_object(&t);
    rl_vec3 n = rl_v3(0, 0, 1);
    uint32_t a = toy_vertex(&t, rl_v3(0, 0, 0), n, rl_v2(0, 0));
    uint32_t b = toy_vertex(&t, rl_v3(1, 0, 0), n, rl_v2(1, 0));
    uint32_t c = toy_vertex(&t, rl_v3(0, 1, 0), n, rl_v2(0, 1));
    uint32_t a2 = toy_vertex(&t, rl_v3(0, 0, 0), n, rl_v2(0, 0));
    uint32_t b2 = toy_vertex(&t, rl_v3(1, 0, 0), n, rl_v2(0.5f, 0));
    uint32_t d = toy_vertex(&t, rl_v3(0, -1, 0), n, rl_v2(0, -1));
    toy_triangle(&t, a, c, b);
    toy_triangle(&t, a2, b2, d);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    assert_int_equal(m.num_verts, 5);    /* a2 welds to a, b2 does not */
    assert_int_equal(m.num_edges, 6);
    vt_mesh_free(&m);

    t.uv[b2] = rl_v2(1, 0);
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    assert_int_equal(m.num_verts, 4);
    assert_int_equal(m.num_edges, 5);
    check_mesh(&m, false);

    t.n[b2] = rl_normalize(rl_v3(0, 0.1f, 1));
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    assert_int_equal(m.num_verts, 5);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_objects_are_masked_and_never_welded_together(void **state)
{
    (void)state;
    toy t;
    toy_init(&t, 9, 3, 3);
    rl_vec3 n = rl_v3(0, 0, 1);
    for (uint32_t o = 0; o < 3; ++o) {
        toy_begin_object(&t);
        uint32_t a = toy_vertex(&t, rl_v3(0, 0, 0), n, rl_v2(0, 0));
        uint32_t b = toy_vertex(&t, rl_v3(1, 0, 0), n, rl_v2(0, 0));
        uint32_t c = toy_vertex(&t, rl_v3(0, 1, 0), n, rl_v2(0, 0));
        toy_triangle(&t, a, b, c);
    }
    vt_mesh m = { 0 };
    uint8_t all[3] = { 1, 1, 1 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), all), RL_OK);
    assert_int_equal(m.num_verts, 9);
    assert_int_equal(m.num_edges, 9);
    assert_int_equal(m.num_faces, 3);

    uint8_t some[3] = { 0, 0, 1 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), some), RL_OK);
    assert_int_equal(m.num_verts, 3);
    assert_int_equal(m.num_faces, 1);
    assert_int_equal(m.faces[0].triangle, 2);
    assert_int_equal(m.verts[0].triangle, 2);
    assert_true(m.verts[1].key == vt_vertex_key_primary(2, 1));

    uint8_t none[3] = { 0, 0, 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), none), RL_OK);
    assert_int_equal(m.num_verts, 0);
    assert_int_equal(m.num_edges, 0);
    assert_int_equal(m.num_faces, 0);
    vt_mesh_reset(&m);
    vt_mesh_free(&m);

    rl_scene_data empty;
    memset(&empty, 0, sizeof empty);
    assert_int_equal(vt_mesh_build(&m, &empty, NULL), RL_OK);
    assert_int_equal(m.num_faces, 0);
    assert_int_equal(vt_mesh_build(NULL, &empty, NULL), RL_ERR_INVALID_ARG);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_non_manifold_edge_gets_boundary_copies(void **state)
{
    (void)state;
    /* Four fins on the edge (a, b). */
    toy t;
    toy_init(&t, 6, 4, 1);
    toy_begin_object(&t);
    rl_vec3 n = rl_v3(0, 0, 1);
    uint32_t a = toy_vertex(&t, rl_v3(0, 0, 0), n, rl_v2(0, 0));
    uint32_t b = toy_vertex(&t, rl_v3(1, 0, 0), n, rl_v2(0, 0));
    uint32_t c = toy_vertex(&t, rl_v3(0, 1, 0), n, rl_v2(0, 0));
    uint32_t d = toy_vertex(&t, rl_v3(0, -1, 0), n, rl_v2(0, 0));
    uint32_t e = toy_vertex(&t, rl_v3(0, 0, 1), n, rl_v2(0, 0));
    uint32_t g = toy_vertex(&t, rl_v3(0, 0, -1), n, rl_v2(0, 0));
    toy_triangle(&t, a, b, c);
    toy_triangle(&t, b, a, d);
    toy_triangle(&t, a, b, e);
    toy_triangle(&t, b, a, g);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    /* (a,b) shared once, then two copies; 8 outer sides */
    assert_int_equal(m.num_edges, 11);
    uint32_t ab_shared = 0, ab_single = 0;
    for (uint32_t i = 0; i < m.num_edges; ++i) {
        const vt_edge *ed = &m.edges[i];
        bool is_ab = (ed->v[0] == 0 && ed->v[1] == 1) || (ed->v[0] == 1 && ed->v[1] == 0);
        if (!is_ab)
            continue;
        if (ed->face[1] != VT_NONE)
            ab_shared++;
        else
            ab_single++;
    }
    assert_int_equal(ab_shared, 1);
    assert_int_equal(ab_single, 2);
    check_mesh(&m, false);
    random_splits(&m, 60, 99, false, 1);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_split_of_one_edge_follows_fig_3_5(void **state)
{
    (void)state;
    /* Two triangles (0,1,2) and (1,0,3) sharing the edge 0-1. */
    toy t;
    toy_init(&t, 4, 2, 1);
    toy_begin_object(&t);
    toy_vertex(&t, rl_v3(0, 0, 0), rl_v3(1, 0, 0), rl_v2(0, 0));
    toy_vertex(&t, rl_v3(2, 0, 0), rl_v3(0, 1, 0), rl_v2(1, 0.5f));
    toy_vertex(&t, rl_v3(1, 1, 0), rl_v3(0, 0, 1), rl_v2(0, 1));
    toy_vertex(&t, rl_v3(1, -1, 0), rl_v3(0, 0, 1), rl_v2(1, 1));
    toy_triangle(&t, 0, 1, 2);
    toy_triangle(&t, 1, 0, 3);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    m.faces[1].visible = 1;
    uint32_t e = m.faces[0].e[2];         /* opposite vertex 2: 0 -> 1 */
    assert_int_equal(m.edges[e].v[0], 0);
    assert_int_equal(m.edges[e].v[1], 1);
    assert_int_equal(m.edges[e].face[0], 0);
    assert_int_equal(m.edges[e].face[1], 1);

    uint32_t ne[4], nf[4], num_e, num_f;
    uint32_t v = vt_mesh_split(&m, e, 3, ne, &num_e, nf, &num_f);
    assert_int_equal(v, 4);
    const vt_vertex *mv = &m.verts[v];
    assert_float_equal(mv->p.x, 1.0f, 0.0f);
    assert_float_equal(mv->p.y, 0.0f, 0.0f);
    /* eq. 3.8: normalize((1,0,0) + (0,1,0)) */
    assert_float_equal(mv->n.x, sqrtf(0.5f), 1e-6f);
    assert_float_equal(mv->n.y, sqrtf(0.5f), 1e-6f);
    assert_float_equal(mv->n.z, 0.0f, 0.0f);
    assert_float_equal(mv->uv.x, 0.5f, 0.0f);
    assert_float_equal(mv->uv.y, 0.25f, 0.0f);
    assert_int_equal(mv->stage, 3);
    assert_int_equal(mv->triangle, 0);
    assert_true(mv->key == vt_vertex_key_mid(m.verts[0].key, m.verts[1].key));

    assert_int_equal(num_e, 4);
    assert_int_equal(num_f, 4);
    assert_int_equal(vt_edge_mid(&m, e), 4);
    assert_false(m.faces[0].leaf);
    assert_false(m.faces[1].leaf);
    /* (a, b, c) = (0, 1, 2): children (0, v', 2) and (v', 1, 2) */
    const vt_face *f1 = &m.faces[nf[0]], *f2 = &m.faces[nf[1]];
    assert_int_equal(f1->v[0], 0);
    assert_int_equal(f1->v[1], 4);
    assert_int_equal(f1->v[2], 2);
    assert_int_equal(f2->v[0], 4);
    assert_int_equal(f2->v[1], 1);
    assert_int_equal(f2->v[2], 2);
    assert_int_equal(vt_face_root(&m, nf[0]), 0);
    assert_int_equal(f1->seq, nf[0]);
    assert_int_equal(f2->seq, nf[1]);
    assert_int_equal(f1->stage, 3);
    assert_int_equal(f1->visible, 0);
    /* the other side (1, 0, 3) split on (1, 0): (1, v', 3) and (v', 0, 3),
     * and they inherit its visible flag */
    const vt_face *f3 = &m.faces[nf[2]], *f4 = &m.faces[nf[3]];
    assert_int_equal(f3->v[0], 1);
    assert_int_equal(f3->v[1], 4);
    assert_int_equal(f3->v[2], 3);
    assert_int_equal(f4->v[0], 4);
    assert_int_equal(f4->v[1], 0);
    assert_int_equal(f4->v[2], 3);
    assert_int_equal(f3->visible, 1);
    assert_int_equal(vt_face_root(&m, nf[3]), 1);
    /* inner edges v' -> c */
    assert_int_equal(m.edges[ne[2]].v[0], 4);
    assert_int_equal(m.edges[ne[2]].v[1], 2);
    assert_int_equal(m.edges[ne[3]].v[0], 4);
    assert_int_equal(m.edges[ne[3]].v[1], 3);
    check_mesh(&m, false);

    /* splitting it again changes nothing */
    uint32_t faces = m.num_faces, edges = m.num_edges;
    assert_int_equal(vt_mesh_split(&m, e, 5, ne, &num_e, nf, &num_f), 4);
    assert_int_equal(num_e, 0);
    assert_int_equal(num_f, 0);
    assert_int_equal(m.num_faces, faces);
    assert_int_equal(m.num_edges, edges);

    /* a boundary edge splits one face: 3 edges, 2 faces */
    uint32_t outer = f1->e[1];            /* (2, 0) */
    assert_int_equal(m.edges[outer].face[1], VT_NONE);
    v = vt_mesh_split(&m, outer, 4, ne, &num_e, nf, &num_f);
    assert_int_equal(v, 5);
    assert_int_equal(num_e, 3);
    assert_int_equal(num_f, 2);
    check_mesh(&m, false);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_midpoint_normal_falls_back_when_normals_cancel(void **state)
{
    (void)state;
    toy t;
    toy_init(&t, 3, 1, 1);
    toy_begin_object(&t);
    toy_vertex(&t, rl_v3(0, 0, 0), rl_v3(0, 0, 1), rl_v2(0, 0));
    toy_vertex(&t, rl_v3(1, 0, 0), rl_v3(0, 0, -1), rl_v2(0, 0));
    toy_vertex(&t, rl_v3(0, 1, 0), rl_v3(0, 0, 1), rl_v2(0, 0));
    toy_triangle(&t, 0, 1, 2);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    uint32_t ne[4], nf[4], num_e, num_f;
    uint32_t v = vt_mesh_split(&m, m.faces[0].e[2], 1, ne, &num_e, nf, &num_f);
    assert_float_equal(m.verts[v].n.z, 1.0f, 0.0f);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_random_splits_keep_grid_consistent(void **state)
{
    (void)state;
    toy t;
    toy_grid(&t, 10);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    random_splits(&m, 2000, 0x1234567u, false, 97);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_random_splits_keep_cube_closed(void **state)
{
    (void)state;
    toy t;
    toy_cube_soup(&t);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    random_splits(&m, 2000, 0xabcdefu, true, 101);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_random_splits_on_committed_sphere(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material mat = rl_material_default();
    uint32_t mat_id, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &mat, &mat_id), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "sphere", "segments=16,rings=8", mat_id, &mesh),
                     RL_OK);
    for (int i = 0; i < 2; ++i) {
        assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "ball", NULL, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_non_null(d);
    assert_int_equal(d->num_objects, 2);
    uint8_t mask[2] = { 1, 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, d, mask), RL_OK);
    assert_int_equal(m.num_faces, d->num_triangles);
    assert_true(m.num_verts <= d->num_vertices);
    /* Per instance, the uv seam (7 edges on either side) and the poles (one
     * vertex per segment, so both sides of the 2 x 16 pole triangles) stay
     * open; the seam's pole edges are counted twice by that: 14 + 64 - 2. */
    uint32_t shared = 0;
    for (uint32_t e = 0; e < m.num_edges; ++e)
        shared += m.edges[e].face[1] != VT_NONE;
    assert_int_equal(m.num_edges - shared, 2 * (14 + 64 - 2));
    check_mesh(&m, false);
    random_splits(&m, 2000, 0x5eed, false, 250);
    vt_mesh_free(&m);
    rl_scene_release(s);
}

static bool pick_leaf(const void *user, const vt_face *f)
{
    (void)user;
    return f->leaf;
}

/* vt_mesh.drop_parents: the same splits give the same leaves, in the same
 * creation order (the draw order), with about half the faces; reset
 * restores the primary mesh. */
static void dropped_parents_match(toy *t, bool closed, uint64_t seed)
{
    uint8_t mask[1] = { 1 };
    vt_mesh keep = { 0 }, drop = { 0 }, fresh = { 0 };
    assert_int_equal(vt_mesh_build(&keep, toy_data(t), mask), RL_OK);
    assert_int_equal(vt_mesh_build(&drop, toy_data(t), mask), RL_OK);
    assert_int_equal(vt_mesh_build(&fresh, toy_data(t), mask), RL_OK);
    for (int round = 0; round < 2; ++round) {
        drop.drop_parents = true;
        for (uint32_t f = 0; f < keep.num_faces; ++f)
            keep.faces[f].visible = drop.faces[f].visible = (uint8_t)(f % 3 != 0);
        uint64_t s = seed + (uint64_t)round;
        for (int i = 0; i < 3000; ++i) {
            uint32_t e;
            do
                e = (uint32_t)(rng_next(&s) % keep.num_edges);
            while (keep.edges[e].child != VT_NONE);
            uint32_t ne[4], nf[4], num_e, num_f, ne2[4], nf2[4], num_e2, num_f2;
            uint32_t v1 = vt_mesh_split(&keep, e, (uint16_t)(1 + i % 5), ne, &num_e, nf, &num_f);
            uint32_t v2 = vt_mesh_split(&drop, e, (uint16_t)(1 + i % 5), ne2, &num_e2, nf2, &num_f2);
            /* edges and vertices do not depend on the faces' slots */
            assert_int_equal(v1, v2);
            assert_int_equal(num_e, num_e2);
            assert_int_equal(num_f, num_f2);
            assert_memory_equal(ne, ne2, num_e * sizeof *ne);
            for (uint32_t k = 0; k < num_f; ++k) {
                assert_memory_equal(keep.faces[nf[k]].v, drop.faces[nf2[k]].v, sizeof keep.faces[0].v);
                assert_int_equal(keep.faces[nf[k]].seq, drop.faces[nf2[k]].seq);
            }
            if ((i + 1) % 500 == 0)
                check_mesh(&drop, closed);
        }
        check_mesh(&drop, closed);
        check_mesh(&keep, closed);
        assert_int_equal(keep.num_verts, drop.num_verts);
        assert_int_equal(keep.num_edges, drop.num_edges);
        assert_int_equal(keep.num_created, drop.num_created);
        /* 3000 splits of a small mesh: most split faces are not primary */
        assert_true(drop.num_faces < keep.num_faces * 2 / 3);
        uint32_t *lk = NULL, *ld = NULL;
        size_t ck = 0, cd = 0, nk = 0, nd = 0;
        assert_int_equal(vt_mesh_pick_in_order(&keep, pick_leaf, NULL, &lk, &ck, &nk), RL_OK);
        assert_int_equal(vt_mesh_pick_in_order(&drop, pick_leaf, NULL, &ld, &cd, &nd), RL_OK);
        assert_int_equal(nk, nd);
        for (size_t i = 0; i < nk; ++i) {
            const vt_face *a = &keep.faces[lk[i]], *b = &drop.faces[ld[i]];
            assert_memory_equal(a->v, b->v, sizeof a->v);
            assert_memory_equal(a->e, b->e, sizeof a->e);
            assert_int_equal(a->triangle, b->triangle);
            assert_int_equal(a->seq, b->seq);
            assert_int_equal(a->stage, b->stage);
            assert_int_equal(a->visible, b->visible);
            assert_int_equal(vt_face_root(&keep, lk[i]), vt_face_root(&drop, ld[i]));
            if (i > 0)
                assert_true(drop.faces[ld[i - 1]].seq < b->seq);
        }
        free(lk);
        free(ld);
        vt_mesh_reset(&keep);
        vt_mesh_reset(&drop);
        assert_int_equal(drop.num_faces, fresh.num_faces);
        assert_int_equal(drop.num_created, fresh.num_faces);
        for (uint32_t e = 0; e < drop.num_edges; ++e) {
            assert_int_equal(drop.edges[e].face[0], fresh.edges[e].face[0]);
            assert_int_equal(drop.edges[e].face[1], fresh.edges[e].face[1]);
        }
        for (uint32_t f = 0; f < drop.num_faces; ++f) {
            assert_memory_equal(drop.faces[f].v, fresh.faces[f].v, sizeof drop.faces[f].v);
            assert_memory_equal(drop.faces[f].e, fresh.faces[f].e, sizeof drop.faces[f].e);
        }
    }
    vt_mesh_free(&keep);
    vt_mesh_free(&drop);
    vt_mesh_free(&fresh);
}

static void test_dropped_parents_keep_the_leaves_and_their_order(void **state)
{
    (void)state;
    toy t;
    toy_grid(&t, 8);
    dropped_parents_match(&t, false, 0x77aa);
    toy_free(&t);
    toy_cube_soup(&t);
    dropped_parents_match(&t, true, 0x1357);
    toy_free(&t);
}

static void test_reset_restores_the_primary_mesh(void **state)
{
    (void)state;
    toy t;
    toy_grid(&t, 6);
    uint8_t mask[1] = { 1 };
    vt_mesh fresh = { 0 }, m = { 0 };
    assert_int_equal(vt_mesh_build(&fresh, toy_data(&t), mask), RL_OK);
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    for (int round = 0; round < 3; ++round) {
        for (uint32_t f = 0; f < m.num_faces; ++f)
            m.faces[f].visible = 1;
        for (uint32_t v = 0; v < m.num_verts; ++v)
            m.verts[v].state = VT_SAMPLED;
        for (uint32_t e = 0; e < m.num_edges; ++e)
            vt_edge_set_queued(&m, e, true);
        random_splits(&m, 500, 77 + (uint64_t)round, false, 1000);
        uint32_t cap = m.cap_faces;
        vt_mesh_reset(&m);
        assert_int_equal(m.cap_faces, cap);
        assert_int_equal(m.num_verts, fresh.num_verts);
        assert_int_equal(m.num_edges, fresh.num_edges);
        assert_int_equal(m.num_faces, fresh.num_faces);
        for (uint32_t e = 0; e < m.num_edges; ++e) {
            const vt_edge *a = &m.edges[e], *b = &fresh.edges[e];
            assert_int_equal(a->v[0], b->v[0]);
            assert_int_equal(a->v[1], b->v[1]);
            assert_int_equal(a->face[0], b->face[0]);
            assert_int_equal(a->face[1], b->face[1]);
            assert_int_equal(a->child, VT_NONE);
            assert_int_equal(vt_edge_queued(&m, e), 0);
        }
        for (uint32_t f = 0; f < m.num_faces; ++f) {
            assert_memory_equal(m.faces[f].v, fresh.faces[f].v, sizeof m.faces[f].v);
            assert_memory_equal(m.faces[f].e, fresh.faces[f].e, sizeof m.faces[f].e);
            assert_int_equal(m.faces[f].leaf, 1);
            assert_int_equal(m.faces[f].visible, 0);
        }
        for (uint32_t v = 0; v < m.num_verts; ++v) {
            assert_int_equal(m.verts[v].state, VT_UNSAMPLED);
            assert_true(m.verts[v].key == fresh.verts[v].key);
        }
        check_mesh(&m, false);
    }
    vt_mesh_free(&m);
    vt_mesh_free(&fresh);
    toy_free(&t);
}

/* vt_mesh_drop_refined_edges (run at the end of a large frame's
 * refinement): the refined edges go, their room with them, the faces and
 * vertices stay as they were, and a reset and the next frame's splits give
 * what a mesh that never dropped its edges gives, edge for edge (the
 * arrays grow again from the smaller room, with the queued bits clear). */
static void test_dropped_edges_keep_faces_and_the_next_frame(void **state)
{
    (void)state;
    toy t;
    toy_grid(&t, 12);
    uint8_t mask[1] = { 1 };
    vt_mesh kept = { 0 }, m = { 0 };
    assert_int_equal(vt_mesh_build(&kept, toy_data(&t), mask), RL_OK);
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    for (int round = 0; round < 3; ++round) {
        vt_mesh *both[2] = { &kept, &m };
        for (int k = 0; k < 2; ++k) {
            for (uint32_t e = 0; e < both[k]->num_edges; ++e)
                vt_edge_set_queued(both[k], e, (e + (uint32_t)round) % 3 == 0);
            random_splits(both[k], 3000, 0x5eed + (uint64_t)round, false, 1000);
        }
        assert_int_equal(m.num_edges, kept.num_edges);
        assert_true(m.num_edges > 4 * m.num_primary_edges);
        uint32_t cap = m.cap_edges;
        vt_face *faces = malloc((size_t)m.num_faces * sizeof *faces);
        vt_vertex *verts = malloc((size_t)m.num_verts * sizeof *verts);
        assert_non_null(faces);
        assert_non_null(verts);
        memcpy(faces, m.faces, (size_t)m.num_faces * sizeof *faces);
        memcpy(verts, m.verts, (size_t)m.num_verts * sizeof *verts);
        vt_mesh_drop_refined_edges(&m);
        assert_int_equal(m.num_edges, m.num_primary_edges);
        assert_true(m.cap_edges < cap);
        assert_true(m.cap_edges >= m.num_primary_edges && m.cap_edges % 256 == 0);
        assert_true(m.cap_queued * 32 >= m.cap_edges);
        assert_memory_equal(m.faces, faces, (size_t)m.num_faces * sizeof *faces);
        assert_memory_equal(m.verts, verts, (size_t)m.num_verts * sizeof *verts);
        free(faces);
        free(verts);
        vt_mesh_reset(&m);
        vt_mesh_reset(&kept);
        assert_int_equal(m.num_edges, kept.num_edges);
        assert_memory_equal(m.edges, kept.edges, (size_t)m.num_edges * sizeof *m.edges);
        for (uint32_t e = 0; e < m.num_edges; ++e)
            assert_int_equal(vt_edge_queued(&m, e), 0);
        check_mesh(&m, false);
    }
    vt_mesh_free(&m);
    vt_mesh_free(&kept);
    toy_free(&t);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return (x > y) - (x < y);
}

/* The kept sample (vt_mesh_set_sample): empty deferred layers take no room
 * in the pool, the others come back bit for bit, and a reset empties the
 * pool. */
static void test_samples_keep_only_deferred_layers_that_are_not_empty(void **state)
{
    (void)state;
    toy t;
    toy_grid(&t, 2);
    uint8_t mask[1] = { 1 };
    vt_mesh m = { 0 };
    assert_int_equal(vt_mesh_build(&m, toy_data(&t), mask), RL_OK);
    const rl_trace_layer none = { { 0, 0, 0 }, { 0, 0, 0 }, RL_NONE, { 0, 0 } };
    rl_trace_layer in[4][RL_TRACE_LAYER_COUNT];
    for (int v = 0; v < 4; ++v)
        for (int l = 0; l < RL_TRACE_LAYER_COUNT; ++l)
            in[v][l] = none;
    /* 0: primary only; 1: a reflection; 2: both, one of them -0 only (not
     * empty bitwise); 3: a refraction with a texture and nothing else */
    in[0][RL_TRACE_LAYER_PRIMARY] = (rl_trace_layer){ { 0.5f, 0.25f, 1 }, { 0.125f, 0, 0 }, 7, { 0.3f, 0.6f } };
    in[1][RL_TRACE_LAYER_REFLECTION] = (rl_trace_layer){ { 0.1f, 0.2f, 0.3f }, { 1, 2, 3 }, RL_NONE, { 0.5f, 0.25f } };
    in[2][RL_TRACE_LAYER_REFLECTION] = (rl_trace_layer){ { -0.0f, 0, 0 }, { 0, 0, 0 }, RL_NONE, { 0, 0 } };
    in[2][RL_TRACE_LAYER_REFRACTION] = (rl_trace_layer){ { 4, 5, 6 }, { 7, 8, 9 }, 2, { 0.75f, 0.5f } };
    in[3][RL_TRACE_LAYER_REFRACTION] = (rl_trace_layer){ { 0, 0, 0 }, { 0, 0, 0 }, 1, { 0, 0 } };
    for (uint32_t v = 0; v < 4; ++v) {
        vt_vertex_sample s;
        memset(&s, 0, sizeof s);
        s.flat = rl_v3((float)v, 1, 2);
        vt_sample_set_tree(&s, 1000 + v);
        assert_int_equal(vt_mesh_set_sample(&m, v, &s, in[v]), RL_OK);
    }
    /* untextured ones (1's reflection, 2's -0 reflection) in the plain pool */
    assert_int_equal(m.num_layers, 2);
    assert_int_equal(m.num_plain, 2);
    assert_true(m.samples[1].deferred[0] & VT_PLAIN_LAYER);
    assert_false(m.samples[3].deferred[1] & VT_PLAIN_LAYER);
    assert_int_equal(m.samples[0].deferred[0], VT_NONE);
    assert_int_equal(m.samples[0].deferred[1], VT_NONE);
    assert_int_equal(m.samples[1].deferred[1], VT_NONE);
    assert_true(m.samples[2].deferred[0] != VT_NONE && m.samples[2].deferred[1] != VT_NONE);
    for (uint32_t v = 0; v < 4; ++v) {
        rl_trace_layer out[RL_TRACE_LAYER_COUNT];
        vt_mesh_sample_layers(&m, v, out);
        /* the primary layer's texture and uv are the face's and the
         * vertex's, not kept */
        rl_trace_layer want = in[v][RL_TRACE_LAYER_PRIMARY];
        want.texture = RL_NONE;
        want.uv = rl_v2(0, 0);
        assert_memory_equal(&out[RL_TRACE_LAYER_PRIMARY], &want, sizeof want);
        /* a deferred layer without texture: its uv (never read) is 0 */
        for (int l = RL_TRACE_LAYER_REFLECTION; l <= RL_TRACE_LAYER_REFRACTION; ++l) {
            want = in[v][l];
            if (want.texture == RL_NONE)
                want.uv = rl_v2(0, 0);
            assert_memory_equal(&out[l], &want, sizeof want);
        }
        assert_true(m.samples[v].flat.x == (float)v && vt_sample_tree(&m.samples[v]) == 1000 + v);
    }
    vt_mesh_reset(&m);
    assert_int_equal(m.num_layers, 0);
    assert_int_equal(m.num_plain, 0);
    vt_mesh_free(&m);
    toy_free(&t);
}

static void test_keys_are_distinct_and_mid_is_symmetric(void **state)
{
    (void)state;
    enum { OBJECTS = 40, INDICES = 500 };
    uint64_t *keys = malloc(sizeof *keys * OBJECTS * INDICES);
    assert_non_null(keys);
    size_t n = 0;
    for (uint32_t o = 0; o < OBJECTS; ++o)
        for (uint32_t i = 0; i < INDICES; ++i)
            keys[n++] = vt_vertex_key_primary(o, i);
    qsort(keys, n, sizeof *keys, cmp_u64);
    for (size_t i = 1; i < n; ++i)
        assert_true(keys[i - 1] != keys[i]);
    uint64_t a = vt_vertex_key_primary(0, 0), b = vt_vertex_key_primary(0, 1);
    assert_true(a != b);
    assert_true(vt_vertex_key_primary(1, 0) != vt_vertex_key_primary(0, 1));
    assert_true(vt_vertex_key_mid(a, b) == vt_vertex_key_mid(b, a));
    assert_true(vt_vertex_key_mid(a, b) != a && vt_vertex_key_mid(a, b) != b);
    uint64_t ab = vt_vertex_key_mid(a, b);
    assert_true(vt_vertex_key_mid(a, ab) != vt_vertex_key_mid(b, ab));
    assert_true(vt_vertex_key_mid(a, a) != vt_vertex_key_mid(b, b));
    free(keys);
}

static void test_xi_and_height_of_a_face(void **state)
{
    (void)state;
    vt_vertex v[3];
    memset(v, 0, sizeof v);
    /* 3-4-5 right triangle in pixels */
    v[0].sx = 0; v[0].sy = 0;
    v[1].sx = 3; v[1].sy = 0;
    v[2].sx = 0; v[2].sy = 4;
    vt_face f;
    memset(&f, 0, sizeof f);
    f.v[0] = 0; f.v[1] = 1; f.v[2] = 2;
    vt_mesh m = { .verts = v, .num_verts = 3, .faces = &f, .num_faces = 1 };
    assert_float_equal(vt_face_xi(&m, 0, 0), 5.0f / 7.0f, 1e-6f);
    assert_float_equal(vt_face_xi(&m, 0, 1), 4.0f / 8.0f, 1e-6f);
    assert_float_equal(vt_face_xi(&m, 0, 2), 3.0f / 9.0f, 1e-6f);
    /* height over the longest side: 2 * area / 5 */
    assert_float_equal(vt_face_height_px(&m, 0), 12.0f / 5.0f, 1e-6f);
    /* a long sliver 2 pixels high: xi = 200 / (2 sqrt(100^2 + 2^2)) is
     * 0.9998, "flat" by any threshold on xi; its height says otherwise */
    v[1].sx = 200; v[1].sy = 0;
    v[2].sx = 100; v[2].sy = 2;
    assert_true(vt_face_xi(&m, 0, 2) > 0.999f);
    assert_float_equal(vt_face_height_px(&m, 0), 2.0f, 1e-5f);
    /* collinear: no area, xi = 1, height 0 */
    v[2].sx = 6; v[2].sy = 0;
    assert_float_equal(vt_face_xi(&m, 0, 2), 1.0f, 1e-6f);
    assert_float_equal(vt_face_height_px(&m, 0), 0.0f, 0.0f);
    /* all in one point: 0 by definition */
    v[1].sx = v[2].sx = 0;
    assert_float_equal(vt_face_xi(&m, 0, 0), 0.0f, 0.0f);
    assert_float_equal(vt_face_height_px(&m, 0), 0.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_builds_shared_edges),
        cmocka_unit_test(test_cube_soup_welds_into_a_closed_mesh),
        cmocka_unit_test(test_weld_needs_equal_normal_and_uv),
        cmocka_unit_test(test_objects_are_masked_and_never_welded_together),
        cmocka_unit_test(test_non_manifold_edge_gets_boundary_copies),
        cmocka_unit_test(test_split_of_one_edge_follows_fig_3_5),
        cmocka_unit_test(test_midpoint_normal_falls_back_when_normals_cancel),
        cmocka_unit_test(test_random_splits_keep_grid_consistent),
        cmocka_unit_test(test_random_splits_keep_cube_closed),
        cmocka_unit_test(test_random_splits_on_committed_sphere),
        cmocka_unit_test(test_dropped_parents_keep_the_leaves_and_their_order),
        cmocka_unit_test(test_reset_restores_the_primary_mesh),
        cmocka_unit_test(test_dropped_edges_keep_faces_and_the_next_frame),
        cmocka_unit_test(test_samples_keep_only_deferred_layers_that_are_not_empty),
        cmocka_unit_test(test_keys_are_distinct_and_mid_is_symmetric),
        cmocka_unit_test(test_xi_and_height_of_a_face),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
