/* test_generators.c: procedural meshes (box, quad, sphere, cylinder) and the
 * Utah teapot tessellation, checked against exact geometry: counts, bounds,
 * radii, outward normals, closed patch seams. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_scene.h"
#include "scene/generators.h"

/* Builds a committed scene holding one generated mesh at the origin. */
static rl_status generate(const char *gen, const char *params, rl_scene **out)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_create(&s);
    uint32_t mat, mesh, node;
    rl_material m = rl_material_default();
    if (!st) st = rl_scene_add_material(s, &m, &mat);
    if (!st) st = rl_scene_add_generated(s, gen, params, mat, &mesh);
    if (!st) st = rl_scene_add_node(s, RL_NODE_ROOT, gen, NULL, &node);
    if (!st) st = rl_scene_node_set_mesh(s, node, mesh);
    if (!st) st = rl_scene_commit(s);
    if (st) {
        rl_scene_release(s);
        return st;
    }
    *out = s;
    return RL_OK;
}

static void assert_near(float a, float b, float eps)
{
    if (!(fabsf(a - b) <= eps))
        fail_msg("%g differs from %g by more than %g", (double)a, (double)b, (double)eps);
}

/* Fraction of triangles whose geometric normal points away from `centre`
 * and agrees with the shading normals. */
static double outward_fraction(const rl_vec3 *p, const rl_vec3 *n, const uint32_t *idx,
                               uint32_t tris, rl_vec3 centre)
{
    uint32_t good = 0;
    for (uint32_t t = 0; t < tris; ++t) {
        rl_vec3 a = p[idx[3 * t]], b = p[idx[3 * t + 1]], c = p[idx[3 * t + 2]];
        rl_vec3 g = rl_cross(rl_sub(b, a), rl_sub(c, a));
        rl_vec3 mid = rl_scale(rl_add(rl_add(a, b), c), 1.0f / 3.0f);
        rl_vec3 sn = rl_add(rl_add(n[idx[3 * t]], n[idx[3 * t + 1]]), n[idx[3 * t + 2]]);
        if (rl_dot(g, rl_sub(mid, centre)) > 0.0f && rl_dot(g, sn) > 0.0f)
            ++good;
    }
    return (double)good / (double)tris;
}

static void test_box_has_12_outward_triangles_and_exact_bounds(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(generate("box", "size=2x1x3", &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 12);
    assert_near(d->bounds.min.x, -1.0f, 0.0f);
    assert_near(d->bounds.max.y, 0.5f, 0.0f);
    assert_near(d->bounds.max.z, 1.5f, 0.0f);
    assert_true(outward_fraction(d->positions, d->normals, d->indices, 12, rl_v3s(0.0f)) == 1.0);
    rl_scene_release(s);

    /* Per-axis keys override size. */
    assert_int_equal(generate("box", "size=4, sy=0.5", &s), RL_OK);
    d = rl_scene_get_data(s);
    assert_near(d->bounds.max.x, 2.0f, 0.0f);
    assert_near(d->bounds.max.y, 0.25f, 0.0f);
    rl_scene_release(s);
}

static void test_quad_faces_up_with_repeated_uvs(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(generate("quad", "sx=4,sz=2,repeat=3", &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 2);
    float umax = 0.0f;
    for (uint32_t v = 0; v < d->num_vertices; ++v) {
        assert_near(d->positions[v].y, 0.0f, 0.0f);
        assert_near(d->normals[v].y, 1.0f, 1e-6f);
        umax = rl_maxf(umax, d->uvs[v].x);
    }
    assert_near(umax, 3.0f, 0.0f);
    assert_near(d->bounds.max.x, 2.0f, 0.0f);
    assert_near(d->bounds.min.z, -1.0f, 0.0f);
    /* Both triangles face +y. */
    assert_true(outward_fraction(d->positions, d->normals, d->indices, 2, rl_v3(0, -1, 0)) == 1.0);
    rl_scene_release(s);
}

static void test_sphere_vertices_lie_on_the_radius(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(generate("sphere", "radius=2.5,segments=24,rings=12", &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 2 * 24 * (12 - 1));
    for (uint32_t v = 0; v < d->num_vertices; ++v) {
        assert_near(rl_length(d->positions[v]), 2.5f, 2.5e-6f * 4);
        rl_vec3 n = d->normals[v];
        assert_near(rl_dot(n, rl_scale(d->positions[v], 1.0f / 2.5f)), 1.0f, 1e-5f);
    }
    assert_true(outward_fraction(d->positions, d->normals, d->indices, d->num_triangles,
                                 rl_v3s(0.0f)) == 1.0);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.dropped_degenerate, 0);
    rl_scene_release(s);
}

static void test_cylinder_has_caps_unless_disabled(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(generate("cylinder", "radius=0.5,height=3,segments=16", &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 4 * 16);
    assert_near(d->bounds.max.y, 1.5f, 0.0f);
    assert_near(d->bounds.min.y, -1.5f, 0.0f);
    assert_near(d->bounds.max.x, 0.5f, 1e-6f);
    assert_true(outward_fraction(d->positions, d->normals, d->indices, d->num_triangles,
                                 rl_v3s(0.0f)) == 1.0);
    rl_scene_release(s);
    assert_int_equal(generate("cylinder", "segments=16,caps=false", &s), RL_OK);
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 2 * 16);
    rl_scene_release(s);
}

static void test_generators_reject_bad_parameters(void **state)
{
    (void)state;
    rl_scene *s = (rl_scene *)&s;   /* must stay untouched */
    rl_scene *const sentinel = s;
    assert_int_equal(generate("sphere", "segments=0", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("sphere", "radius=-1", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("box", "size=0", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("box", "size=1x2", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("box", "colour=red", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("teapot", "triangles=-5", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("teapot", "triangles=1000000000", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("cylinder", "caps=maybe", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(generate("torus", NULL, &s), RL_ERR_NOT_FOUND);
    assert_ptr_equal(s, sentinel);
    rl_clear_error();

    size_t n = 0;
    const char *const *names = rl_generator_names(&n);
    assert_int_equal(n, 6);
    assert_string_equal(names[4], "teapot");
    assert_string_equal(names[5], "blob");
    assert_null(names[6]);
}

static void test_teapot_data_matches_the_published_set(void **state)
{
    (void)state;
    rl_aabb box = rl_aabb_empty();
    for (int i = 0; i < RL_TEAPOT_POINTS; ++i)
        box = rl_aabb_grow(box, rl_v3(rl_teapot_points[i][0], rl_teapot_points[i][1],
                                      rl_teapot_points[i][2]));
    assert_near(box.min.x, -3.0f, 0.0f);
    assert_near(box.max.x, 3.525f, 0.0f);
    assert_near(box.min.y, -2.0f, 0.0f);
    assert_near(box.max.y, 2.0f, 0.0f);
    assert_near(box.min.z, 0.0f, 0.0f);
    assert_near(box.max.z, 3.15f, 0.0f);
    bool used[RL_TEAPOT_POINTS] = { false };
    for (int k = 0; k < RL_TEAPOT_PATCHES; ++k)
        for (int j = 0; j < 16; ++j) {
            assert_true(rl_teapot_patches[k][j] < RL_TEAPOT_POINTS);
            used[rl_teapot_patches[k][j]] = true;
        }
    /* The body of revolution is mirror-symmetric in x and y: every body
     * point has its mirror images in the table (catches transcription typos). */
    for (int k = 0; k < RL_TEAPOT_PATCHES; ++k) {
        if (k >= 12 && k < 20)
            continue;   /* handle and spout are only symmetric in y */
        for (int j = 0; j < 16; ++j) {
            const float *p = rl_teapot_points[rl_teapot_patches[k][j]];
            bool mx = false, my = false;
            for (int i = 0; i < RL_TEAPOT_POINTS; ++i) {
                const float *q = rl_teapot_points[i];
                mx |= q[0] == -p[0] && q[1] == p[1] && q[2] == p[2];
                my |= q[0] == p[0] && q[1] == -p[1] && q[2] == p[2];
            }
            assert_true(mx && my);
        }
    }
    int unused = 0;
    for (int i = 0; i < RL_TEAPOT_POINTS; ++i)
        unused += !used[i];
    assert_true(unused < 10);   /* a few points of the published set are spare */
}

static void test_teapot_triangle_count_is_near_requested(void **state)
{
    (void)state;
    static const uint32_t requests[] = { 1000, 5000, 15704, 70000, 250000 };
    for (size_t i = 0; i < sizeof requests / sizeof requests[0]; ++i) {
        uint32_t nu, nv;
        uint32_t predicted = rl_teapot_grid(requests[i], &nu, &nv);
        double err = fabs((double)predicted - requests[i]) / requests[i];
        if (err > 0.02)
            fail_msg("%u triangles requested, grid gives %u", requests[i], predicted);
        rl_meshbuf b;
        rl_meshbuf_init(&b);
        b.material = 0;
        rl_gen_teapot(&b, requests[i], 1.0f);
        assert_int_equal(b.status, RL_OK);
        assert_int_equal(b.num_triangles, predicted);
        rl_meshbuf_free(&b);
    }
    uint32_t nu, nv;
    assert_int_equal(rl_teapot_grid(RL_TEAPOT_DEFAULT_TRIANGLES, &nu, &nv), 15704);
    assert_int_equal(rl_teapot_grid(1, &nu, &nv), 56);   /* one quad per patch */

    /* Through the public API: the scene core drops nothing. */
    rl_scene *s = NULL;
    assert_int_equal(generate("teapot", "triangles=20000", &s), RL_OK);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.dropped_degenerate, 0);
    assert_int_equal(st.dropped_nonfinite, 0);
    assert_int_equal(st.triangles, rl_teapot_grid(20000, &nu, &nv));
    rl_scene_release(s);
}

static void test_teapot_is_finite_and_faces_outward(void **state)
{
    (void)state;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = 0;
    const float size = 2.0f;
    rl_gen_teapot(&b, 15704, size);
    assert_int_equal(b.status, RL_OK);
    rl_aabb box = rl_aabb_empty();
    for (uint32_t v = 0; v < b.num_vertices; ++v) {
        assert_true(rl_vfinite(b.positions[v]) && rl_vfinite(b.normals[v]));
        assert_near(rl_length(b.normals[v]), 1.0f, 1e-4f);
        box = rl_aabb_grow(box, b.positions[v]);
    }
    /* y-up, standing on y = 0, spout towards +x (surface, not control net). */
    float k = size / 3.15f;
    assert_near(box.min.y, 0.0f, 1e-6f);
    assert_near(box.max.y, 3.15f * k, 1e-5f);
    assert_true(box.max.x > 3.3f * k && box.max.x < 3.53f * k);
    assert_true(box.min.x < -2.8f * k && box.min.x >= -3.0f * k);
    assert_near(box.max.z, 2.0f * k, 1e-4f);

    /* Each patch owns (nu+1)(nv+1) consecutive vertices. Body (patches
     * 4-11): normals point away from the axis. Lid dome and bottom (24-31):
     * away from mid-height on the axis. Everything: mostly away from the
     * middle of the bounding box (the rim's inner lip, the knob's underside
     * and the inside of the handle legitimately face it). */
    uint32_t nu, nv;
    rl_teapot_grid(15704, &nu, &nv);
    uint32_t per_patch = (nu + 1) * (nv + 1), outward = 0;
    rl_vec3 middle = rl_aabb_center(box);
    for (uint32_t patch = 0; patch < RL_TEAPOT_PATCHES; ++patch)
        for (uint32_t v = patch * per_patch; v < (patch + 1) * per_patch; ++v) {
            rl_vec3 p = b.positions[v], n = b.normals[v];
            if (patch >= 4 && patch < 12)
                assert_true(rl_dot(n, rl_v3(p.x, 0.0f, p.z)) > 0.0f);
            if (patch >= 24)
                assert_true(rl_dot(n, rl_sub(p, rl_v3(0.0f, 1.5f * k, 0.0f))) > 0.0f);
            outward += rl_dot(n, rl_sub(p, middle)) > 0.0f;
        }
    if (outward < 0.75 * b.num_vertices)   /* flipped normals would give ~0.2 */
        fail_msg("only %u of %u normals face outward", outward, b.num_vertices);
    /* Winding agrees with the normals everywhere. */
    uint32_t agree = 0;
    for (uint32_t t = 0; t < b.num_triangles; ++t) {
        const uint32_t *i = &b.indices[3 * t];
        rl_vec3 g = rl_cross(rl_sub(b.positions[i[1]], b.positions[i[0]]),
                             rl_sub(b.positions[i[2]], b.positions[i[0]]));
        agree += rl_dot(g, rl_add(rl_add(b.normals[i[0]], b.normals[i[1]]), b.normals[i[2]])) > 0.0f;
    }
    assert_int_equal(agree, b.num_triangles);
    rl_meshbuf_free(&b);
}

typedef struct edge { uint32_t a, b; } edge;

static int edge_cmp(const void *x, const void *y)
{
    const edge *e = x, *f = y;
    if (e->a != f->a)
        return e->a < f->a ? -1 : 1;
    return e->b < f->b ? -1 : (e->b > f->b);
}

static int point_cmp(const void *x, const void *y)
{
    const rl_vec3 *p = x, *q = y;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    if (p->y != q->y) return p->y < q->y ? -1 : 1;
    return p->z < q->z ? -1 : (p->z > q->z);
}

static void test_teapot_seams_close_except_the_known_openings(void **state)
{
    (void)state;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = 0;
    rl_gen_teapot(&b, 15704, 1.0f);
    assert_int_equal(b.status, RL_OK);
    /* Weld by exact position: shared patch boundaries evaluate bitwise equal. */
    rl_vec3 *sorted = malloc(b.num_vertices * sizeof *sorted);
    uint32_t *weld = malloc(b.num_vertices * sizeof *weld);
    edge *edges = malloc(3 * (size_t)b.num_triangles * sizeof *edges);
    assert_non_null(sorted);
    assert_non_null(weld);
    assert_non_null(edges);
    memcpy(sorted, b.positions, b.num_vertices * sizeof *sorted);
    qsort(sorted, b.num_vertices, sizeof *sorted, point_cmp);
    for (uint32_t v = 0; v < b.num_vertices; ++v) {
        const rl_vec3 *hit = bsearch(&b.positions[v], sorted, b.num_vertices, sizeof *sorted, point_cmp);
        assert_non_null(hit);
        /* bsearch may land on any duplicate: walk to the first. */
        while (hit > sorted && point_cmp(hit - 1, hit) == 0)
            --hit;
        weld[v] = (uint32_t)(hit - sorted);
    }
    size_t ne = 0;
    for (uint32_t t = 0; t < b.num_triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t a = weld[b.indices[3 * t + k]], c = weld[b.indices[3 * t + (k + 1) % 3]];
            edges[ne++] = (edge){ a < c ? a : c, a < c ? c : a };
        }
    qsort(edges, ne, sizeof *edges, edge_cmp);
    uint32_t boundary = 0, nonmanifold = 0;
    for (size_t i = 0; i < ne;) {
        size_t j = i;
        while (j < ne && edge_cmp(&edges[i], &edges[j]) == 0)
            ++j;
        boundary += j - i == 1;
        nonmanifold += j - i > 2;
        i = j;
    }
    /* Open loops of the original model, each 4 patch rows of nu edges: rim
     * inner edge, lid outer edge, both handle ends, both spout ends. */
    uint32_t nu, nv;
    rl_teapot_grid(15704, &nu, &nv);
    (void)nv;
    assert_int_equal(boundary, 16 * nu);
    assert_int_equal(nonmanifold, 0);
    free(sorted);
    free(weld);
    free(edges);
    rl_meshbuf_free(&b);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_box_has_12_outward_triangles_and_exact_bounds),
        cmocka_unit_test(test_quad_faces_up_with_repeated_uvs),
        cmocka_unit_test(test_sphere_vertices_lie_on_the_radius),
        cmocka_unit_test(test_cylinder_has_caps_unless_disabled),
        cmocka_unit_test(test_generators_reject_bad_parameters),
        cmocka_unit_test(test_teapot_data_matches_the_published_set),
        cmocka_unit_test(test_teapot_triangle_count_is_near_requested),
        cmocka_unit_test(test_teapot_is_finite_and_faces_outward),
        cmocka_unit_test(test_teapot_seams_close_except_the_known_openings),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
