/* test_accel_api.c: the generic rl_accel layer (accel.c) and the shared
 * watertight test (watertight.c): kind names, desc validation, lifecycle,
 * invalid rays, the barycentric convention, t_max shortening, batches and
 * the queries of intersection hints (one triangle, a named occluder).
 * Runs against our own kinds (brute, bvh); scenes are built in code. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel_internal.h"
#include "rl/rl_accel.h"
#include "rl/rl_scene.h"

static const rl_accel_kind our_kinds[] = { RL_ACCEL_BRUTE, RL_ACCEL_BVH };
#define NUM_OUR_KINDS (sizeof our_kinds / sizeof our_kinds[0])

/* A scene of the given triangles (3 vertices each), committed unless asked. */
static rl_scene *triangles_scene(const rl_vec3 *pos, uint32_t num_tris, bool commit)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    uint32_t idx[3 * 64];
    assert_true(num_tris <= 64);
    for (uint32_t i = 0; i < 3 * num_tris; ++i)
        idx[i] = i;
    rl_mesh_desc d = { .name = "tris", .num_vertices = 3 * num_tris, .positions = pos,
                       .num_triangles = num_tris, .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &d, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "tris", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    if (commit)
        assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* Two triangles: one at z = 0 and a parallel one at z = -1 behind it. */
static const rl_vec3 two_tris[6] = {
    { -1, -1, 0 }, { 1, -1, 0 }, { 0, 1, 0 },
    { -1, -1, -1 }, { 1, -1, -1 }, { 0, 1, -1 },
};

static rl_accel *make_accel(const rl_scene *s, rl_accel_kind kind)
{
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = kind }, &a), RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_OK);
    return a;
}

static rl_ray ray_of(rl_vec3 o, rl_vec3 d)
{
    return (rl_ray){ .o = o, .t_min = 0.0f, .d = d, .t_max = INFINITY };
}

static void test_kind_names_round_trip_through_parse(void **state)
{
    (void)state;
    const char *names[] = { "bvh", "grid", "embree", "brute" };
    for (int k = 0; k < RL_ACCEL_KIND_COUNT; ++k) {
        assert_string_equal(rl_accel_kind_name((rl_accel_kind)k), names[k]);
        rl_accel_kind out = RL_ACCEL_KIND_COUNT;
        assert_int_equal(rl_accel_kind_parse(names[k], &out), RL_OK);
        assert_int_equal(out, k);
    }
    rl_accel_kind out = RL_ACCEL_BRUTE;
    assert_int_equal(rl_accel_kind_parse("kdtree", &out), RL_ERR_NOT_FOUND);
    assert_int_equal(out, RL_ACCEL_BRUTE);
    assert_non_null(strstr(rl_last_error(), "bvh"));
    rl_clear_error();
    assert_int_equal(rl_accel_kind_parse(NULL, &out), RL_ERR_INVALID_ARG);
    rl_clear_error();
}

static void test_embree_is_available_exactly_in_embree_builds(void **state)
{
    (void)state;
    assert_true(rl_accel_kind_available(RL_ACCEL_BVH));
    assert_true(rl_accel_kind_available(RL_ACCEL_BRUTE));
#ifdef RL_HAVE_EMBREE
    assert_true(rl_accel_kind_available(RL_ACCEL_EMBREE));
#else
    assert_false(rl_accel_kind_available(RL_ACCEL_EMBREE));
#endif
    assert_false(rl_accel_kind_available(RL_ACCEL_KIND_COUNT));
}

static void test_create_rejects_bad_descs_and_leaves_out_null(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, true);
    rl_accel_desc bad[] = {
        { .threads = -1 },
        { .bvh_leaf_size = -1 }, { .bvh_leaf_size = 65 },
        { .bvh_bins = 1 }, { .bvh_bins = 257 }, { .bvh_bins = -3 },
        { .bvh_block_cost = -1 }, { .bvh_block_cost = 2 },
        { .grid_lambda = -1.0f }, { .grid_lambda = NAN }, { .grid_lambda = INFINITY },
        { .grid_res = { 4097, 0, 0 } }, { .grid_res = { 0, -1, 0 } },
        { .kind = RL_ACCEL_KIND_COUNT }, { .kind = (rl_accel_kind)-1 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rl_accel *a = NULL;
        assert_int_equal(rl_accel_create(s, &bad[i], &a), RL_ERR_INVALID_ARG);
        assert_null(a);
        rl_clear_error();
    }
    /* The limits themselves are fine. */
    rl_accel_desc good[] = {
        { .bvh_leaf_size = 64, .bvh_bins = 256, .grid_res = { 4096, 1, 1 } },
        { .bvh_leaf_size = 1, .bvh_bins = 2, .threads = 1, .grid_lambda = 0.5f },
        { .bvh_block_cost = 1 },
        { 0 },
    };
    for (size_t i = 0; i < sizeof good / sizeof good[0]; ++i) {
        rl_accel *a = NULL;
        assert_int_equal(rl_accel_create(s, &good[i], &a), RL_OK);
        rl_accel_release(a);
    }
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(NULL, NULL, &a), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_accel_create(s, NULL, NULL), RL_ERR_INVALID_ARG);
    /* NULL desc = all defaults: a BVH. */
    assert_int_equal(rl_accel_create(s, NULL, &a), RL_OK);
    rl_accel_stats st;
    rl_accel_get_stats(a, &st);
    assert_int_equal(st.kind, RL_ACCEL_BVH);
    assert_ptr_equal(rl_accel_scene(a), s);
    rl_accel_release(a);
    rl_accel_release(NULL);
    rl_clear_error();
    rl_scene_release(s);
}

static void test_create_requires_a_committed_scene(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, false);
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &a), RL_ERR_NOT_COMMITTED);
    assert_null(a);
    rl_clear_error();
    rl_scene_release(s);
}

static void test_uncommitted_accel_queries_miss(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, true);
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        rl_accel *a = NULL;
        assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = our_kinds[k] }, &a), RL_OK);
        rl_ray r = ray_of(rl_v3(0, 0, 5), rl_v3(0, 0, -1));
        rl_hit h = { .triangle = 7, .object = 7 };
        assert_false(rl_accel_intersect(a, &r, &h));
        assert_int_equal(h.triangle, RL_ID_NONE);
        assert_int_equal(h.object, RL_ID_NONE);
        assert_true(isinf(r.t_max));
        assert_false(rl_accel_occluded(a, &r));
        assert_false(rl_accel_intersect(NULL, &r, &h));
        assert_false(rl_accel_occluded(NULL, &r));
        /* Committing makes the same ray hit; a second commit is a no-op. */
        assert_int_equal(rl_accel_commit(a), RL_OK);
        assert_int_equal(rl_accel_commit(a), RL_OK);
        assert_true(rl_accel_intersect(a, &r, &h));
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

static void test_invalid_rays_miss_and_are_not_occluded(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, true);
    rl_vec3 o = rl_v3(0, 0, 5), d = rl_v3(0, 0, -1);
    rl_ray bad[] = {
        { .o = o, .d = rl_v3(NAN, 0, -1), .t_max = INFINITY },
        { .o = o, .d = rl_v3(0, 0, 0), .t_max = INFINITY },
        { .o = o, .d = rl_v3(0, INFINITY, -1), .t_max = INFINITY },
        { .o = rl_v3(0, NAN, 5), .d = d, .t_max = INFINITY },
        { .o = rl_v3(-INFINITY, 0, 5), .d = d, .t_max = INFINITY },
        { .o = o, .d = d, .t_min = 10.0f, .t_max = 1.0f },
        { .o = o, .d = d, .t_min = NAN, .t_max = INFINITY },
        { .o = o, .d = d, .t_min = -INFINITY, .t_max = INFINITY },
        { .o = o, .d = d, .t_min = 0.0f, .t_max = NAN },
    };
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        rl_accel *a = make_accel(s, our_kinds[k]);
        for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
            rl_ray r = bad[i];
            rl_hit h = { .t = 42.0f };
            assert_false(rl_accel_intersect(a, &r, &h));
            assert_int_equal(h.triangle, RL_ID_NONE);
            assert_int_equal(h.object, RL_ID_NONE);
            assert_true(h.t == 42.0f);
            assert_false(rl_accel_occluded(a, &bad[i]));
        }
        /* The same ray with valid values hits the front triangle. */
        rl_ray r = ray_of(o, d);
        rl_hit h;
        assert_true(rl_accel_intersect(a, &r, &h));
        assert_int_equal(h.triangle, 0);
        assert_int_equal(h.object, 0);
        assert_true(rl_accel_occluded(a, &(rl_ray){ .o = o, .d = d, .t_max = INFINITY }));
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

/* p = (1-u-v)·p0 + u·p1 + v·p2 as rl_hit documents, for both our kinds and
 * for the watertight test itself, from either side of the triangle. */
static void test_barycentrics_follow_the_documented_convention(void **state)
{
    (void)state;
    const rl_vec3 tri[3] = { { 0.5f, 0.25f, 2.0f }, { 3.0f, -0.5f, 2.5f }, { 1.0f, 2.0f, 1.5f } };
    rl_scene *s = triangles_scene(tri, 1, true);
    const float uv[][2] = { { 0.2f, 0.3f }, { 0.6f, 0.1f }, { 0.05f, 0.9f }, { 1.0f / 3.0f, 1.0f / 3.0f } };
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        rl_accel *a = make_accel(s, our_kinds[k]);
        for (size_t i = 0; i < sizeof uv / sizeof uv[0]; ++i)
            for (int side = -1; side <= 1; side += 2) {
                float u = uv[i][0], v = uv[i][1];
                rl_vec3 p = rl_add(rl_add(rl_scale(tri[0], 1.0f - u - v), rl_scale(tri[1], u)),
                                   rl_scale(tri[2], v));
                rl_vec3 o = rl_add(p, rl_v3(0.3f, -0.2f, 4.0f * (float)side));
                rl_ray r = ray_of(o, rl_sub(p, o));     /* hits at t = 1 */
                rl_hit h;
                assert_true(rl_accel_intersect(a, &r, &h));
                assert_float_equal(h.u, u, 1e-5);
                assert_float_equal(h.v, v, 1e-5);
                assert_float_equal(h.t, 1.0f, 1e-5);
                rl_ray_watertight w;
                float t, hu, hv;
                rl_ray_watertight_setup(&r, &w);
                assert_true(rl_triangle_intersect_watertight(&w, tri[0], tri[1], tri[2], 0.0f, 2.0f, &t, &hu, &hv));
                assert_true(hu == h.u && hv == h.v && t == h.t);
            }
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

static void test_watertight_test_respects_the_open_interval(void **state)
{
    (void)state;
    const rl_vec3 p0 = { -1, -1, 0 }, p1 = { 1, -1, 0 }, p2 = { 0, 1, 0 };
    rl_ray r = ray_of(rl_v3(0, 0, 2), rl_v3(0, 0, -1));
    rl_ray_watertight w;
    rl_ray_watertight_setup(&r, &w);
    float t = -1.0f, u = -1.0f, v = -1.0f;
    assert_true(rl_triangle_intersect_watertight(&w, p0, p1, p2, 0.0f, INFINITY, &t, &u, &v));
    assert_true(t == 2.0f);
    /* t == t_max and t == t_min are outside (t_min, t_max). */
    assert_false(rl_triangle_intersect_watertight(&w, p0, p1, p2, 0.0f, 2.0f, &t, &u, &v));
    assert_false(rl_triangle_intersect_watertight(&w, p0, p1, p2, 2.0f, 3.0f, &t, &u, &v));
    assert_true(rl_triangle_intersect_watertight(&w, p0, p1, p2, 1.999f, 2.001f, &t, &u, &v));
    /* Behind the origin, and a ray in the triangle's plane (det = 0). */
    rl_ray back = ray_of(rl_v3(0, 0, -2), rl_v3(0, 0, -1));
    rl_ray_watertight_setup(&back, &w);
    assert_false(rl_triangle_intersect_watertight(&w, p0, p1, p2, 0.0f, INFINITY, &t, &u, &v));
    assert_true(rl_triangle_intersect_watertight(&w, p0, p1, p2, -INFINITY, INFINITY, &t, &u, &v));
    assert_true(t == -2.0f);
    rl_ray flat = ray_of(rl_v3(-5, 0, 0), rl_v3(1, 0, 0));
    rl_ray_watertight_setup(&flat, &w);
    assert_false(rl_triangle_intersect_watertight(&w, p0, p1, p2, -INFINITY, INFINITY, &t, &u, &v));
}

static void test_intersect_shortens_t_max_and_occluded_respects_it(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, true);
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        rl_accel *a = make_accel(s, our_kinds[k]);
        rl_ray r = ray_of(rl_v3(0.1f, 0.0f, 3.0f), rl_v3(0, 0, -2));
        rl_hit h;
        assert_true(rl_accel_intersect(a, &r, &h));
        assert_true(r.t_max == 1.5f && h.t == 1.5f);
        assert_int_equal(h.triangle, 0);
        /* Past the first triangle the second one is hit. */
        rl_ray r2 = { .o = r.o, .d = r.d, .t_min = 1.6f, .t_max = INFINITY };
        assert_true(rl_accel_intersect(a, &r2, &h));
        assert_int_equal(h.triangle, 1);
        assert_true(h.t == 2.0f);
        /* A segment that stops short is not occluded; t_max = +inf is valid. */
        assert_false(rl_accel_occluded(a, &(rl_ray){ .o = r.o, .d = r.d, .t_max = 1.4f }));
        assert_true(rl_accel_occluded(a, &(rl_ray){ .o = r.o, .d = r.d, .t_max = 1.6f }));
        assert_true(rl_accel_occluded(a, &(rl_ray){ .o = r.o, .d = r.d, .t_max = INFINITY }));
        /* A miss leaves the ray alone. */
        rl_ray miss = ray_of(rl_v3(5, 5, 3), rl_v3(0, 0, -1));
        assert_false(rl_accel_intersect(a, &miss, &h));
        assert_true(isinf(miss.t_max));
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

static void test_batches_equal_single_queries(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, true);
    enum { N = 64 };
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        rl_accel *a = make_accel(s, our_kinds[k]);
        rl_ray rays[N], single[N];
        rl_hit hits[N];
        bool occ[N];
        for (int i = 0; i < N; ++i) {
            float x = -1.5f + 3.0f * (float)(i % 8) / 7.0f, y = -1.5f + 3.0f * (float)(i / 8) / 7.0f;
            rays[i] = ray_of(rl_v3(x, y, 3.0f), rl_v3(0.05f * (float)(i % 3), 0.0f, -1.0f));
            if (i == 5)
                rays[i].d = rl_v3(0, 0, 0);   /* invalid rays take part too */
            if (i % 4 == 1)
                rays[i].t_max = 3.5f;
            single[i] = rays[i];
        }
        rl_accel_occluded_n(a, rays, occ, N);
        rl_accel_intersect_n(a, rays, hits, N);
        int hit_count = 0;
        for (int i = 0; i < N; ++i) {
            assert_true(occ[i] == rl_accel_occluded(a, &single[i]));
            rl_hit h;
            bool got = rl_accel_intersect(a, &single[i], &h);
            assert_int_equal(hits[i].triangle, got ? h.triangle : RL_ID_NONE);
            if (got) {
                ++hit_count;
                assert_true(hits[i].t == h.t && hits[i].u == h.u && hits[i].v == h.v);
                assert_true(rays[i].t_max == single[i].t_max);
            }
        }
        assert_true(hit_count > 8 && hit_count < N);
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

/* Intersection hints (rl_accel.h): the one-triangle test gives bit for bit
 * what the structure's closest hit gives for that triangle, never a closer
 * hit than it, and the occluder a query names really blocks the ray. */
static void test_triangle_test_and_occluder_agree_with_the_queries(void **state)
{
    (void)state;
    enum { T = 48 };
    rl_vec3 pos[3 * T];
    uint32_t seed = 12345u;
    for (int i = 0; i < 3 * T; ++i) {
        float c[3];
        for (int k = 0; k < 3; ++k) {
            seed = seed * 1664525u + 1013904223u;
            c[k] = (float)(seed >> 8) / 16777216.0f;
        }
        /* triangles about a quarter of the box wide, scattered through it */
        rl_vec3 centre = i % 3 == 0 ? rl_v3(4.0f * c[0] - 2.0f, 4.0f * c[1] - 2.0f, 4.0f * c[2] - 2.0f)
                                    : pos[i - i % 3];
        rl_vec3 offset = rl_v3(2.0f * c[0] - 1.0f, 2.0f * c[1] - 1.0f, 2.0f * c[2] - 1.0f);
        pos[i] = i % 3 == 0 ? centre : rl_add(centre, offset);
    }
    rl_scene *s = triangles_scene(pos, T, true);
    const rl_accel_kind kinds[] = { RL_ACCEL_BRUTE, RL_ACCEL_BVH, RL_ACCEL_GRID };
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; ++k) {
        rl_accel *a = make_accel(s, kinds[k]);
        int hits = 0, blocked = 0;
        for (int i = 0; i < 400; ++i) {
            float x = -2.0f + 4.0f * (float)(i % 20) / 19.0f, y = -2.0f + 4.0f * (float)(i / 20) / 19.0f;
            rl_ray ray = ray_of(rl_v3(x, y, 4.0f), rl_v3(0.1f * (float)(i % 7) - 0.3f, 0.05f * (float)(i % 5), -1.0f));
            if (i % 3 == 1)
                ray.t_max = 5.0f;   /* shadow-like: ends inside the box */
            rl_ray r = ray;
            rl_hit full;
            bool got = rl_accel_intersect(a, &r, &full);
            for (uint32_t t = 0; t < T; ++t) {
                rl_hit h;
                if (!rl_accel_intersect_triangle(a, &ray, t, &h))
                    continue;
                assert_true(got);
                assert_int_equal(h.object, 0);
                assert_true(h.t > full.t || (h.t == full.t && t >= full.triangle));
                if (t == full.triangle)
                    assert_true(h.t == full.t && h.u == full.u && h.v == full.v);
            }
            if (got) {
                ++hits;
                rl_hit h;
                assert_true(rl_accel_intersect_triangle(a, &ray, full.triangle, &h));
            }
            uint32_t by = 7;
            bool occ = rl_accel_occluder(a, &ray, &by);
            assert_true(occ == rl_accel_occluded(a, &ray));
            assert_true(occ == got);
            if (occ) {
                ++blocked;
                rl_hit h;
                assert_true(by < T && rl_accel_intersect_triangle(a, &ray, by, &h));
            } else {
                assert_int_equal(by, RL_ID_NONE);
            }
            rl_hit h;
            assert_false(rl_accel_intersect_triangle(a, &ray, T, &h));   /* out of range */
        }
        print_message("%s: %d of 400 rays hit, %d blocked\n", rl_accel_kind_name(kinds[k]), hits, blocked);
        assert_true(hits > 40 && hits < 400);
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

static bool cancel_at_once(void *user, double done)
{
    (void)done;
    ++*(int *)user;
    return false;
}

static void test_cancelled_build_fails_and_leaves_the_accel_uncommitted(void **state)
{
    (void)state;
    rl_scene *s = triangles_scene(two_tris, 2, true);
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        int calls = 0;
        rl_accel *a = NULL;
        rl_accel_desc d = { .kind = our_kinds[k], .progress = cancel_at_once, .user = &calls };
        assert_int_equal(rl_accel_create(s, &d, &a), RL_OK);
        assert_int_equal(rl_accel_commit(a), RL_ERR_CANCELLED);
        assert_true(calls >= 1);
        rl_clear_error();
        rl_ray r = ray_of(rl_v3(0, 0, 3), rl_v3(0, 0, -1));
        rl_hit h;
        assert_false(rl_accel_intersect(a, &r, &h));
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

static void test_stats_describe_the_structure(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    for (size_t k = 0; k < NUM_OUR_KINDS; ++k) {
        rl_accel *a = make_accel(s, our_kinds[k]);
        rl_accel_stats st;
        rl_accel_get_stats(a, &st);
        assert_int_equal(st.kind, our_kinds[k]);
        assert_int_equal(st.num_triangles, 36);
        assert_true(st.build_ms >= 0.0);
        assert_true(st.memory_bytes > 0 && st.bytes_per_triangle > 0.0);
        assert_true(fabs(st.bytes_per_triangle - (double)st.memory_bytes / 36.0) < 1e-9);
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_kind_names_round_trip_through_parse),
        cmocka_unit_test(test_embree_is_available_exactly_in_embree_builds),
        cmocka_unit_test(test_create_rejects_bad_descs_and_leaves_out_null),
        cmocka_unit_test(test_create_requires_a_committed_scene),
        cmocka_unit_test(test_uncommitted_accel_queries_miss),
        cmocka_unit_test(test_invalid_rays_miss_and_are_not_occluded),
        cmocka_unit_test(test_barycentrics_follow_the_documented_convention),
        cmocka_unit_test(test_watertight_test_respects_the_open_interval),
        cmocka_unit_test(test_intersect_shortens_t_max_and_occluded_respects_it),
        cmocka_unit_test(test_batches_equal_single_queries),
        cmocka_unit_test(test_triangle_test_and_occluder_agree_with_the_queries),
        cmocka_unit_test(test_cancelled_build_fails_and_leaves_the_accel_uncommitted),
        cmocka_unit_test(test_stats_describe_the_structure),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
