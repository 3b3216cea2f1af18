/* test_bvh.c: the binned SAH BVH against oracles.
 *
 * Oracles: brute force (same watertight test, same tie rule, so results must
 * be bit-identical, not just close), BVHs built with other parameters, and
 * geometry (closed meshes that no ray from inside may escape).
 * Ray budget for the ASan Debug build (< 20 s): brute force is O(N) per ray,
 * so it sees 100k rays on cornell (36 triangles) and 2k-5k rays on the
 * larger scenes (spheres segments=16: 898, cornell-teapot triangles=2000:
 * 2028, city blocks=1 detail=0: 4350 triangles); on 100k rays per scene the
 * BVH is compared with a differently built BVH (leaf size 1, 4 bins), which
 * must agree just as exactly thanks to the tie rule. The Release build
 * (NDEBUG) gives brute force the full 100k rays on every scene. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/bvh.h"
#include "rl/rl_accel.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

static rl_scene *builtin(const char *name, const char *params)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_create_builtin(name, params, &s);
    if (st != RL_OK)
        fail_msg("%s (%s): %s", name, params ? params : "", rl_last_error());
    return s;
}

static rl_accel *make_accel(const rl_scene *s, rl_accel_desc desc)
{
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &desc, &a), RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_OK);
    return a;
}

static rl_vec3 random_direction(rl_rng *rng)
{
    /* Uniform on the sphere: z uniform in [-1,1], azimuth uniform. */
    float z = 2.0f * rl_rng_float(rng) - 1.0f;
    float phi = 2.0f * RL_PI * rl_rng_float(rng);
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return rl_v3(r * cosf(phi), r * sinf(phi), z);
}

/* Half the rays start inside the (10 % enlarged) scene bounds with uniform
 * directions; the other half are camera rays through random pixels. */
typedef struct ray_gen {
    rl_rng rng;
    rl_aabb bounds;
    rl_camera_frame frame;
} ray_gen;

static ray_gen ray_gen_make(const rl_scene *s, uint64_t seed)
{
    ray_gen g;
    rl_rng_seed(&g.rng, seed, 7);
    g.bounds = rl_scene_get_data(s)->bounds;
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    g.frame = rl_camera_frame_make(&cam);
    return g;
}

static rl_ray random_ray(ray_gen *g, uint32_t i)
{
    rl_rng *rng = &g->rng;
    if (i % 2 == 0) {
        rl_vec3 lo = g->bounds.min, ext = rl_aabb_extent(g->bounds);
        rl_vec3 o = rl_v3(lo.x + ext.x * (1.2f * rl_rng_float(rng) - 0.1f),
                          lo.y + ext.y * (1.2f * rl_rng_float(rng) - 0.1f),
                          lo.z + ext.z * (1.2f * rl_rng_float(rng) - 0.1f));
        return (rl_ray){ .o = o, .t_min = 0.0f, .d = random_direction(rng), .t_max = INFINITY };
    }
    const rl_camera_frame *f = &g->frame;
    return rl_camera_frame_ray(f, (float)f->width * rl_rng_float(rng), (float)f->height * rl_rng_float(rng));
}

/* Bit-identical closest hits (and occlusion) of two accels on n rays. */
static void assert_accels_agree(const rl_scene *s, const rl_accel *ref, const rl_accel *test, uint32_t n,
                                uint64_t seed)
{
    ray_gen g = ray_gen_make(s, seed);
    uint32_t hits = 0;
    for (uint32_t i = 0; i < n; ++i) {
        rl_ray r = random_ray(&g, i), a = r, b = r;
        rl_hit ha, hb;
        bool ga = rl_accel_intersect(ref, &a, &ha);
        bool gb = rl_accel_intersect(test, &b, &hb);
        if (ga != gb || ha.triangle != hb.triangle)
            fail_msg("ray %u: reference %s triangle %u t %.9g, test %s triangle %u t %.9g", i,
                     ga ? "hits" : "misses", ha.triangle, ga ? (double)ha.t : 0.0, gb ? "hits" : "misses",
                     hb.triangle, gb ? (double)hb.t : 0.0);
        if (!ga)
            continue;
        ++hits;
        assert_int_equal(ha.object, hb.object);
        /* The same triangle through the same test: identical numbers. */
        assert_true(ha.t == hb.t && ha.u == hb.u && ha.v == hb.v);
        assert_true(a.t_max == ha.t && b.t_max == hb.t);
    }
    /* The ray set must exercise both outcomes to mean anything. */
    assert_true(hits > n / 10 && hits < n);
}

static void assert_bvh_agrees_with_brute_force(const char *scene, const char *params, uint32_t brute_rays)
{
#ifdef NDEBUG
    brute_rays = 100000;
#endif
    rl_scene *s = builtin(scene, params);
    print_message("%s %s: %u triangles\n", scene, params ? params : "", rl_scene_get_data(s)->num_triangles);
    rl_accel *brute = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_accel *bvh = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *other = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH, .bvh_leaf_size = 1, .bvh_bins = 4 });
    assert_accels_agree(s, brute, bvh, brute_rays, 1);
    assert_accels_agree(s, other, bvh, 100000, 2);
    rl_accel_release(other);
    rl_accel_release(bvh);
    rl_accel_release(brute);
    rl_scene_release(s);
}

static void test_bvh_agrees_with_brute_force_on_cornell(void **state)
{
    (void)state;
    assert_bvh_agrees_with_brute_force("cornell", NULL, 100000);
}

static void test_bvh_agrees_with_brute_force_on_spheres(void **state)
{
    (void)state;
    assert_bvh_agrees_with_brute_force("spheres", "segments=16", 5000);
}

static void test_bvh_agrees_with_brute_force_on_cornell_teapot(void **state)
{
    (void)state;
    assert_bvh_agrees_with_brute_force("cornell-teapot", "triangles=2000", 3000);
}

static void test_bvh_agrees_with_brute_force_on_city(void **state)
{
    (void)state;
    assert_bvh_agrees_with_brute_force("city", "blocks=1,detail=0", 2000);
}

/* Random segments: occluded() is true exactly when intersect() finds a hit
 * in (t_min, t_max), for the BVH and for brute force. */
static void test_bvh_occluded_agrees_with_intersect_on_random_segments(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    rl_accel *bvh = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *brute = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    float diag = rl_length(rl_aabb_extent(rl_scene_get_data(s)->bounds));
    ray_gen g = ray_gen_make(s, 3);
    uint32_t occluded = 0, n = 20000;
    for (uint32_t i = 0; i < n; ++i) {
        rl_ray r = random_ray(&g, i);
        r.t_min = 0.05f * diag * rl_rng_float(&g.rng);
        r.t_max = r.t_min + 0.5f * diag * rl_rng_float(&g.rng);
        rl_ray c = r;
        rl_hit h;
        bool hit = rl_accel_intersect(bvh, &c, &h);
        bool occ = rl_accel_occluded(bvh, &r);
        assert_true(occ == hit);
        if (i % 8 == 0)   /* brute force is O(N): a subset keeps ASan fast */
            assert_true(rl_accel_occluded(brute, &r) == occ);
        occluded += occ;
    }
    assert_true(occluded > n / 10 && occluded < n - n / 10);
    rl_accel_release(brute);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

/* Build directly (bvh.h) to compare the trees themselves byte for byte. */
static void test_bvh_build_is_identical_with_one_and_two_threads(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=20000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_bvh t1 = { 0 }, t2 = { 0 };
    rl_accel_stats s1 = { 0 }, s2 = { 0 };
    /* 20k triangles build on one thread by default (PARALLEL_MIN): the
     * forced tuning makes the second build use two. */
    const rl_bvh_tuning two = { .small_max = 32, .par_bin_min = 4096, .parallel_min = 0 };
    assert_int_equal(rl_bvh_build(d, &(rl_accel_desc){ .threads = 1 }, &t1, &s1), RL_OK);
    assert_int_equal(rl_bvh_build_tuned(d, &(rl_accel_desc){ .threads = 2 }, &two, &t2, &s2), RL_OK);
    assert_int_equal(t1.num_nodes, t2.num_nodes);
    assert_int_equal(t1.num_tris, t2.num_tris);
    assert_int_equal(s1.leaves, s2.leaves);
    assert_int_equal(s1.max_depth, s2.max_depth);
    assert_true(s1.sah_cost == s2.sah_cost);
    assert_memory_equal(t1.nodes, t2.nodes, (size_t)t1.num_nodes * sizeof *t1.nodes);
    assert_memory_equal(t1.tris, t2.tris, (size_t)t1.num_tris * sizeof *t1.tris);
    rl_bvh_free(&t1);
    rl_bvh_free(&t2);
    /* And through the API: same stats, same answers. */
    rl_accel *a1 = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH, .threads = 1 });
    rl_accel *a2 = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH, .threads = 2 });
    rl_accel_stats st1, st2;
    rl_accel_get_stats(a1, &st1);
    rl_accel_get_stats(a2, &st2);
    assert_int_equal(st1.nodes, st2.nodes);
    assert_int_equal(st1.memory_bytes, st2.memory_bytes);
    assert_accels_agree(s, a1, a2, 20000, 4);
    rl_accel_release(a1);
    rl_accel_release(a2);
    rl_scene_release(s);
}

static bool box_contains_box(const rl_bvh_node *outer, const rl_bvh_node *inner)
{
    for (int a = 0; a < 3; ++a)
        if (inner->min[a] < outer->min[a] || inner->max[a] > outer->max[a])
            return false;
    return true;
}

static bool box_contains_point(const rl_bvh_node *n, rl_vec3 p)
{
    return p.x >= n->min[0] && p.x <= n->max[0] && p.y >= n->min[1] && p.y <= n->max[1] && p.z >= n->min[2] &&
           p.z <= n->max[2];
}

/* The wide collapse: every wide node is reached once, every binary leaf
 * appears once, packed into its own SoA blocks that hold each triangle once
 * (bit-exact vertices, NaN padding that never hits), unused lanes are
 * inverted boxes, and the nodes start on a cache line. */
static void assert_wide_tree_holds_the_same_leaves(rl_bvh *bvh, const rl_scene_data *d, uint32_t leaves)
{
    assert_int_equal(rl_bvh_widen(bvh), RL_OK);
    assert_true(bvh->num_wide >= 1 && bvh->num_wide <= bvh->num_nodes / 2 + 1);
    /* Cache-line aligned: a node touches exactly sizeof / 64 lines. */
    assert_int_equal((uintptr_t)bvh->wide % 64, 0);
    assert_int_equal((uintptr_t)bvh->blocks % 16, 0);   /* aligned SIMD loads */
    uint32_t *reached = calloc(bvh->num_wide, sizeof *reached);
    uint32_t *covered = calloc(bvh->num_tris, sizeof *covered);
    uint32_t *block_used = calloc(bvh->num_blocks, sizeof *block_used);
    assert_true(reached && covered && block_used);
    reached[0] = 1;
    uint32_t wide_leaves = 0;
    for (uint32_t i = 0; i < bvh->num_wide; ++i) {
        const rl_bvh_wide_node *n = &bvh->wide[i];
        int used = 0;
        for (int c = 0; c < RL_BVH_WIDTH; ++c) {
            if (n->bmin[0][c] > n->bmax[0][c]) {   /* unused lane */
                assert_true(isinf(n->bmin[0][c]) && isinf(n->bmax[1][c]));
                continue;
            }
            ++used;
            if (n->count[c] == 0) {
                assert_true(n->child[c] > i && n->child[c] < bvh->num_wide);
                ++reached[n->child[c]];
                continue;
            }
            ++wide_leaves;
            for (uint32_t t = 0; t < n->count[c]; ++t) {
                uint32_t b = n->child[c] + t / RL_BVH_LANES, l = t % RL_BVH_LANES;
                assert_true(b < bvh->num_blocks);
                if (l == 0)
                    ++block_used[b];
                const rl_bvh_block *blk = &bvh->blocks[b];
                uint32_t id = blk->id[l];
                assert_true(id < bvh->num_tris);
                ++covered[id];
                const uint32_t *idx = d->indices + 3 * (size_t)id;
                for (int k = 0; k < 3; ++k) {
                    rl_vec3 p = d->positions[idx[k]];
                    assert_memory_equal(&blk->p[k][0][l], &p.x, sizeof p.x);
                    assert_memory_equal(&blk->p[k][1][l], &p.y, sizeof p.y);
                    assert_memory_equal(&blk->p[k][2][l], &p.z, sizeof p.z);
                }
                assert_true(blk->p[0][0][l] >= n->bmin[0][c] && blk->p[0][0][l] <= n->bmax[0][c]);
            }
            /* Padding after the last triangle: NaN, no ID. */
            for (uint32_t t = n->count[c]; t % RL_BVH_LANES != 0; ++t) {
                const rl_bvh_block *blk = &bvh->blocks[n->child[c] + t / RL_BVH_LANES];
                assert_int_equal(blk->id[t % RL_BVH_LANES], RL_ID_NONE);
                assert_true(isnan(blk->p[1][2][t % RL_BVH_LANES]));
            }
        }
        assert_true(used >= 1);
    }
    for (uint32_t i = 0; i < bvh->num_wide; ++i)
        assert_int_equal(reached[i], 1);
    for (uint32_t t = 0; t < bvh->num_tris; ++t)
        assert_int_equal(covered[t], 1);
    for (uint32_t b = 0; b < bvh->num_blocks; ++b)
        assert_int_equal(block_used[b], 1);
    assert_int_equal(wide_leaves, leaves);
    free(reached);
    free(covered);
    free(block_used);
}

/* Structure: every node's box holds its children / triangles, every scene
 * triangle sits in exactly one leaf, leaves respect the size limits, and the
 * stats count what is there. */
static void test_bvh_structure_is_consistent_and_stats_are_sane(void **state)
{
    (void)state;
    rl_scene *s = builtin("city", "blocks=1,detail=0");
    const rl_scene_data *d = rl_scene_get_data(s);
    const int leaf_sizes[] = { 0, 1, 8 };
    for (size_t k = 0; k < sizeof leaf_sizes / sizeof leaf_sizes[0]; ++k) {
        rl_bvh bvh = { 0 };
        rl_accel_stats st = { 0 };
        assert_int_equal(rl_bvh_build(d, &(rl_accel_desc){ .bvh_leaf_size = leaf_sizes[k] }, &bvh, &st), RL_OK);
        uint32_t *seen = calloc(d->num_triangles, sizeof *seen);
        assert_non_null(seen);
        uint32_t leaves = 0;
        for (uint32_t i = 0; i < bvh.num_nodes; ++i) {
            const rl_bvh_node *n = &bvh.nodes[i];
            if (n->count == 0) {
                assert_true(n->index + 1 < bvh.num_nodes && n->index > i);
                assert_true(box_contains_box(n, &bvh.nodes[n->index]));
                assert_true(box_contains_box(n, &bvh.nodes[n->index + 1]));
                continue;
            }
            ++leaves;
            assert_true(n->count <= RL_BVH_MAX_LEAF && n->index + n->count <= bvh.num_tris);
            for (uint32_t j = n->index; j < n->index + n->count; ++j) {
                const rl_bvh_tri *t = &bvh.tris[j];
                assert_true(box_contains_point(n, t->p0) && box_contains_point(n, t->p1) &&
                            box_contains_point(n, t->p2));
                const uint32_t *idx = d->indices + 3 * (size_t)t->id;
                assert_memory_equal(&t->p0, &d->positions[idx[0]], sizeof t->p0);
                assert_memory_equal(&t->p2, &d->positions[idx[2]], sizeof t->p2);
                ++seen[t->id];
            }
        }
        for (uint32_t t = 0; t < d->num_triangles; ++t)
            assert_int_equal(seen[t], 1);
        free(seen);
        assert_int_equal(st.nodes, bvh.num_nodes);
        assert_int_equal(st.leaves, leaves);
        assert_int_equal(st.nodes, 2 * leaves - 1);
        assert_true(st.max_depth > 0 && st.max_depth < RL_BVH_MAX_DEPTH);
        assert_true(st.sah_cost > 1.0);
        assert_int_equal(st.memory_bytes, (size_t)bvh.num_nodes * 32 + (size_t)bvh.num_tris * sizeof(rl_bvh_tri));
        if (leaf_sizes[k] == 1)   /* SAH leaves need more than one triangle */
            assert_true(leaves >= d->num_triangles / RL_BVH_MAX_LEAF);
        assert_wide_tree_holds_the_same_leaves(&bvh, d, leaves);
        rl_bvh_free(&bvh);
    }
    rl_accel *a = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel_stats st;
    rl_accel_get_stats(a, &st);
    assert_int_equal(st.num_triangles, d->num_triangles);
    assert_true(st.nodes > 1 && st.leaves > 1 && st.bytes_per_triangle > 0.0 && st.build_ms >= 0.0);
    rl_accel_release(a);
    rl_scene_release(s);
}

/* A scene of one mesh given by positions and indices. */
static rl_scene *mesh_scene(const rl_vec3 *pos, uint32_t nv, const uint32_t *idx, uint32_t nt)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    rl_mesh_desc d = { .name = "mesh", .num_vertices = nv, .positions = pos, .num_triangles = nt,
                       .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &d, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "mesh", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* bvh_block_cost = 1 (leaves costed per SoA block, up to 8 triangles):
 * the same hits as brute force and as the default tree, bit for bit; its
 * leaves stay within 8 triangles (leaf size 2: the SAH's choice) and fill
 * their blocks better than the default tree's, so it needs fewer blocks
 * and less memory. */
static void test_bvh_block_cost_is_exact_and_fills_blocks(void **state)
{
    (void)state;
    const char *scenes[][2] = { { "cornell-teapot", "triangles=2000" }, { "city", "blocks=1,detail=0" } };
    for (size_t k = 0; k < sizeof scenes / sizeof scenes[0]; ++k) {
        uint32_t brute_rays = 2000;
#ifdef NDEBUG
        brute_rays = 100000;
#endif
        rl_scene *s = builtin(scenes[k][0], scenes[k][1]);
        const rl_scene_data *d = rl_scene_get_data(s);
        rl_accel *brute = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
        rl_accel *plain = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
        rl_accel *blocks = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH, .bvh_block_cost = 1 });
        assert_accels_agree(s, brute, blocks, brute_rays, 5);
        assert_accels_agree(s, plain, blocks, 100000, 6);
        rl_accel_stats ps, bs;
        rl_accel_get_stats(plain, &ps);
        rl_accel_get_stats(blocks, &bs);
        assert_true(bs.memory_bytes < ps.memory_bytes);
        assert_true(bs.leaves < ps.leaves);
        rl_accel_release(blocks);
        rl_accel_release(plain);
        rl_accel_release(brute);
        /* The widened trees: every leaf within 8 triangles, fewer blocks. */
        rl_bvh pb = { 0 }, bb = { 0 };
        rl_accel_stats st;
        assert_int_equal(rl_bvh_build_wide(d, &(rl_accel_desc){ 0 }, &pb, &st), RL_OK);
        assert_int_equal(rl_bvh_build_wide(d, &(rl_accel_desc){ .bvh_block_cost = 1 }, &bb, &st), RL_OK);
        uint32_t max_count = 0, tris = 0;
        for (uint32_t i = 0; i < bb.num_wide; ++i)
            for (int c = 0; c < RL_BVH_WIDTH; ++c) {
                max_count = bb.wide[i].count[c] > max_count ? bb.wide[i].count[c] : max_count;
                tris += bb.wide[i].count[c];
            }
        assert_int_equal(tris, d->num_triangles);
        assert_true(max_count > 2 && max_count <= 8);
        assert_true(bb.num_blocks < pb.num_blocks);
        print_message("%s: blocks %u -> %u, leaves %u -> %u, largest leaf %u\n", scenes[k][0], pb.num_blocks,
                      bb.num_blocks, ps.leaves, bs.leaves, max_count);
        rl_bvh_free(&pb);
        rl_bvh_free(&bb);
        rl_scene_release(s);
    }
}

/* Tie rule: 200 copies of one triangle (all centroids equal, so the builder
 * falls back to median splits) -- every kind must report the lowest ID. */
static void test_bvh_breaks_ties_by_lowest_triangle_id(void **state)
{
    (void)state;
    enum { COPIES = 200 };
    rl_vec3 pos[3] = { { -1, -1, 0 }, { 1, -1, 0 }, { 0, 1, 0 } };
    uint32_t idx[3 * COPIES];
    for (uint32_t i = 0; i < COPIES; ++i) {
        idx[3 * i] = 0;
        idx[3 * i + 1] = (i % 2) ? 2 : 1;   /* both windings */
        idx[3 * i + 2] = (i % 2) ? 1 : 2;
    }
    rl_scene *s = mesh_scene(pos, 3, idx, COPIES);
    rl_accel_kind kinds[] = { RL_ACCEL_BRUTE, RL_ACCEL_BVH };
    for (size_t k = 0; k < 2; ++k) {
        for (int leaf = 0; leaf <= 1; ++leaf) {
            rl_accel *a = make_accel(s, (rl_accel_desc){ .kind = kinds[k], .bvh_leaf_size = leaf });
            /* Both sides and both signs on every axis, so that front-to-back
             * order cannot happen to meet the lowest ID first. */
            for (int c = 0; c < 8; ++c) {
                float sx = (c & 1) ? -1.0f : 1.0f, sy = (c & 2) ? -1.0f : 1.0f, sz = (c & 4) ? -1.0f : 1.0f;
                rl_ray r = { .o = rl_v3(0.1f, -0.2f, 2.0f * sz), .d = rl_v3(0.01f * sx, 0.01f * sy, -sz),
                             .t_max = INFINITY };
                rl_hit h;
                assert_true(rl_accel_intersect(a, &r, &h));
                assert_int_equal(h.triangle, 0);
            }
            rl_accel_release(a);
        }
    }
    rl_scene_release(s);
}

/* RL_ACCEL_BVH builds through rl_bvh_build_wide (no binary array, no
 * triangle copies, the blocks packed from the scene); it must give exactly
 * the wide tree, blocks and statistics of rl_bvh_build + rl_bvh_widen,
 * with one thread and two, on SAH splits, on the median fallback (stacked
 * copies of one triangle: all centroids coincide) and on leaf-size and bin
 * settings off the defaults. */
/* The plain builder: every node binned over all K bins, in one pass,
 * on one thread. The tuned paths (bvh.h's rl_bvh_tuning) must give its
 * tree bit for bit. */
static const rl_bvh_tuning plain_tuning = { .small_max = 0, .par_bin_min = 0, .parallel_min = UINT32_MAX };
/* Every path on every size: the small-node path, chunked binning down to
 * ranges of 512 and two threads however small the scene. */
static const rl_bvh_tuning forced_tuning = { .small_max = 32, .par_bin_min = 512, .parallel_min = 0 };

static void assert_build_wide_matches(const rl_scene_data *d, rl_accel_desc desc)
{
    rl_bvh ref = { 0 };
    rl_accel_stats ref_st = { 0 };
    assert_int_equal(rl_bvh_build_tuned(d, &desc, &plain_tuning, &ref, &ref_st), RL_OK);
    assert_int_equal(rl_bvh_widen(&ref), RL_OK);
    const rl_bvh_tuning *tunings[] = { NULL, &forced_tuning };
    for (int threads = 1; threads <= 2; ++threads)
        for (size_t ti = 0; ti < sizeof tunings / sizeof tunings[0]; ++ti) {
            desc.threads = threads;
            rl_bvh w = { 0 };
            rl_accel_stats st = { 0 };
            assert_int_equal(rl_bvh_build_wide_tuned(d, &desc, tunings[ti], &w, &st), RL_OK);
            assert_null(w.nodes);
            assert_null(w.tris);
            assert_int_equal(w.num_tris, d->num_triangles);
            assert_int_equal(w.num_wide, ref.num_wide);
            assert_int_equal(w.num_blocks, ref.num_blocks);
            assert_memory_equal(w.wide, ref.wide, (size_t)w.num_wide * sizeof *w.wide);
            assert_memory_equal(w.blocks, ref.blocks, (size_t)w.num_blocks * sizeof *w.blocks);
            assert_int_equal(st.nodes, ref_st.nodes);
            assert_int_equal(st.leaves, ref_st.leaves);
            assert_int_equal(st.max_depth, ref_st.max_depth);
            assert_true(st.sah_cost == ref_st.sah_cost);
            assert_int_equal(st.memory_bytes,
                             (size_t)w.num_wide * sizeof *w.wide + (size_t)w.num_blocks * sizeof *w.blocks);
            rl_bvh_free(&w);
            /* The binary path too (nodes and triangles in leaf order). */
            rl_bvh bin = { 0 };
            assert_int_equal(rl_bvh_build_tuned(d, &desc, tunings[ti], &bin, &st), RL_OK);
            assert_int_equal(bin.num_nodes, ref.num_nodes);
            assert_memory_equal(bin.nodes, ref.nodes, (size_t)bin.num_nodes * sizeof *bin.nodes);
            assert_memory_equal(bin.tris, ref.tris, (size_t)bin.num_tris * sizeof *bin.tris);
            rl_bvh_free(&bin);
        }
    rl_bvh_free(&ref);
}

/* Triangles whose boxes start at +0 and at -0 alternately, in the same
 * bins: min and max keep one of two equal operands, so the sign of a zero
 * in a node's box depends on the order in which the bins are merged; the
 * chunked binning must merge as the one pass does (bvh_build.c,
 * bins_merge). */
static void test_bvh_build_keeps_signed_zeros(void **state)
{
    (void)state;
    enum { TRIS = 3000 };
    rl_vec3 *pos = malloc(3 * TRIS * sizeof *pos);
    uint32_t *idx = malloc(3 * TRIS * sizeof *idx);
    assert_true(pos && idx);
    for (uint32_t i = 0; i < TRIS; ++i) {
        float z0 = (i % 3 == 1) ? -0.0f : 0.0f, x0 = (i % 2) ? -0.0f : 0.0f;
        float y = 0.01f * (float)(i % 97), z = 0.02f * (float)(i / 97);
        pos[3 * i] = rl_v3(x0, y, z0 + z);
        pos[3 * i + 1] = rl_v3(x0 + 0.5f, y, z + 0.01f);
        pos[3 * i + 2] = rl_v3(x0, y + 0.005f, z + 0.01f);
        for (int k = 0; k < 3; ++k)
            idx[3 * i + (uint32_t)k] = 3 * i + (uint32_t)k;
    }
    rl_scene *s = mesh_scene(pos, 3 * TRIS, idx, TRIS);
    /* The scene's commit folds its transform in, which turns -0 into +0;
     * the builder gets the positions as given here instead. */
    rl_scene_data data = *rl_scene_get_data(s);
    assert_int_equal(data.num_triangles, TRIS);
    assert_int_equal(data.num_vertices, 3 * TRIS);
    data.positions = pos;
    const rl_scene_data *d = &data;
    assert_build_wide_matches(d, (rl_accel_desc){ 0 });
    assert_build_wide_matches(d, (rl_accel_desc){ .bvh_bins = 4 });
    rl_scene_release(s);
    free(pos);
    free(idx);
}

static void test_bvh_build_wide_equals_build_then_widen(void **state)
{
    (void)state;
    rl_scene *teapot = builtin("cornell-teapot", "triangles=20000");
    assert_build_wide_matches(rl_scene_get_data(teapot), (rl_accel_desc){ 0 });
    assert_build_wide_matches(rl_scene_get_data(teapot), (rl_accel_desc){ .bvh_block_cost = 1 });
    assert_build_wide_matches(rl_scene_get_data(teapot), (rl_accel_desc){ .bvh_leaf_size = 1, .bvh_bins = 4 });
    assert_build_wide_matches(rl_scene_get_data(teapot), (rl_accel_desc){ .bvh_leaf_size = 8, .bvh_bins = 256 });
    rl_scene_release(teapot);
    rl_scene *city = builtin("city", "blocks=1,detail=0");
    assert_build_wide_matches(rl_scene_get_data(city), (rl_accel_desc){ 0 });
    assert_build_wide_matches(rl_scene_get_data(city), (rl_accel_desc){ .bvh_block_cost = 1 });
    rl_scene_release(city);
    /* 5,000 copies of one triangle plus a ramp of small ones: the copies
     * reach the median fallback over a range bigger than a task's. */
    enum { COPIES = 5000, RAMP = 3000 };
    rl_vec3 *pos = malloc((3 + 3 * RAMP) * sizeof *pos);
    uint32_t *idx = malloc(3 * (COPIES + RAMP) * sizeof *idx);
    assert_true(pos && idx);
    pos[0] = rl_v3(-1, -1, 0);
    pos[1] = rl_v3(1, -1, 0);
    pos[2] = rl_v3(0, 1, 0);
    for (uint32_t i = 0; i < COPIES; ++i) {
        idx[3 * i] = 0;
        idx[3 * i + 1] = 1;
        idx[3 * i + 2] = 2;
    }
    for (uint32_t i = 0; i < RAMP; ++i) {
        float x = 2.0f + 0.01f * (float)i, z = 0.001f * (float)(i % 7);
        pos[3 + 3 * i] = rl_v3(x, 0, z);
        pos[4 + 3 * i] = rl_v3(x + 0.005f, 0, z);
        pos[5 + 3 * i] = rl_v3(x, 0.005f, z + 0.002f);
        for (int k = 0; k < 3; ++k)
            idx[3 * (COPIES + i) + (uint32_t)k] = 3 + 3 * i + (uint32_t)k;
    }
    rl_scene *stack = mesh_scene(pos, 3 + 3 * RAMP, idx, COPIES + RAMP);
    assert_build_wide_matches(rl_scene_get_data(stack), (rl_accel_desc){ 0 });
    rl_scene_release(stack);
    free(pos);
    free(idx);
}

/* A closed UV sphere (shared vertices, poles), rotated off the axes so that
 * edges are not axis-aligned. */
static void uv_sphere(uint32_t rings, uint32_t segs, rl_vec3 **pos, uint32_t *nv, uint32_t **idx, uint32_t *nt)
{
    *nv = 2 + (rings - 1) * segs;
    *nt = 2 * segs * (rings - 1);
    *pos = malloc(*nv * sizeof **pos);
    *idx = malloc(3 * (size_t)*nt * sizeof **idx);
    assert_true(*pos && *idx);
    rl_mat4 rot = rl_mat4_rotate(rl_normalize(rl_v3(0.3f, 1.0f, 0.2f)), 0.7f);
    (*pos)[0] = rl_mat4_mul_dir(&rot, rl_v3(0, 1, 0));
    (*pos)[1] = rl_mat4_mul_dir(&rot, rl_v3(0, -1, 0));
    for (uint32_t r = 1; r < rings; ++r)
        for (uint32_t sg = 0; sg < segs; ++sg) {
            float th = RL_PI * (float)r / (float)rings, ph = 2.0f * RL_PI * (float)sg / (float)segs;
            rl_vec3 p = rl_v3(sinf(th) * cosf(ph), cosf(th), sinf(th) * sinf(ph));
            (*pos)[2 + (r - 1) * segs + sg] = rl_mat4_mul_dir(&rot, p);
        }
    uint32_t *t = *idx;
#define V(r, s) (2 + ((r) - 1) * segs + ((s) % segs))
    for (uint32_t sg = 0; sg < segs; ++sg) {
        *t++ = 0; *t++ = V(1, sg + 1); *t++ = V(1, sg);
        *t++ = 1; *t++ = V(rings - 1, sg); *t++ = V(rings - 1, sg + 1);
        for (uint32_t r = 1; r + 1 < rings; ++r) {
            *t++ = V(r, sg); *t++ = V(r, sg + 1); *t++ = V(r + 1, sg);
            *t++ = V(r, sg + 1); *t++ = V(r + 1, sg + 1); *t++ = V(r + 1, sg);
        }
    }
#undef V
}

static void assert_hits(const rl_accel *a, rl_vec3 o, rl_vec3 target)
{
    rl_ray r = { .o = o, .d = rl_sub(target, o), .t_max = INFINITY };
    rl_hit h;
    if (!rl_accel_intersect(a, &r, &h))
        fail_msg("ray from (%g %g %g) at (%.9g %.9g %.9g) escaped", (double)o.x, (double)o.y, (double)o.z,
                 (double)target.x, (double)target.y, (double)target.z);
    assert_true(rl_accel_occluded(a, &(rl_ray){ .o = o, .d = rl_sub(target, o), .t_max = INFINITY }));
}

static void assert_sphere_is_watertight(rl_accel_kind kind, uint32_t rings, uint32_t segs)
{
    rl_vec3 *pos;
    uint32_t *idx, nv, nt;
    uv_sphere(rings, segs, &pos, &nv, &idx, &nt);
    rl_scene *s = mesh_scene(pos, nv, idx, nt);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_vec3 inside[] = { { 0, 0, 0 }, { 0.1f, -0.2f, 0.3f }, { -0.5f, 0.25f, 0.1f } };
    rl_accel *a = make_accel(s, (rl_accel_desc){ .kind = kind });
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        const uint32_t *ti = d->indices + 3 * (size_t)t;
        for (int e = 0; e < 3; ++e) {
            rl_vec3 p = d->positions[ti[e]], q = d->positions[ti[(e + 1) % 3]];
            rl_vec3 mid = rl_scale(rl_add(p, q), 0.5f);
            for (size_t i = 0; i < sizeof inside / sizeof inside[0]; ++i) {
                assert_hits(a, inside[i], p);
                assert_hits(a, inside[i], mid);
            }
            assert_hits(a, rl_scale(p, 3.0f), p);
            assert_hits(a, rl_scale(mid, 2.5f), mid);
        }
    }
    rl_accel_release(a);
    rl_scene_release(s);
    free(pos);
    free(idx);
}

/* Woop et al. 2013: rays exactly at shared vertices and edges must not slip
 * through the closed mesh, from inside outwards or from outside inwards.
 * Brute force (O(N) per ray) gets the coarser sphere. */
static void test_rays_at_shared_edges_and_vertices_never_escape(void **state)
{
    (void)state;
    assert_sphere_is_watertight(RL_ACCEL_BRUTE, 10, 20);
    assert_sphere_is_watertight(RL_ACCEL_BVH, 10, 20);
    assert_sphere_is_watertight(RL_ACCEL_BVH, 32, 64);
}

/* Bit-identical closest hit and occlusion of two accels on one ray. */
static void assert_same_hit(const rl_accel *ref, const rl_accel *test, rl_ray r)
{
    rl_ray a = r, b = r;
    rl_hit ha, hb;
    bool ga = rl_accel_intersect(ref, &a, &ha), gb = rl_accel_intersect(test, &b, &hb);
    assert_true(ga == gb);
    assert_true(rl_accel_occluded(test, &r) == ga);
    if (ga)
        assert_true(ha.triangle == hb.triangle && ha.t == hb.t && ha.u == hb.u && ha.v == hb.v);
}

/* Ranges that reach behind the origin (t_min < 0) are valid queries: the
 * BVH must find hits at negative t like brute force. Its box test once
 * widened [lo, hi] by scaling, which narrows a flat box (a wall, lo == hi)
 * behind the origin and lost it. Segments of random length around random
 * points inside the Cornell box. */
static void test_bvh_finds_hits_at_negative_t(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    rl_accel *brute = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_accel *bvh = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    /* The reported case first. */
    assert_same_hit(brute, bvh, (rl_ray){ .o = { 0.453212291f, 0.00355176348f, 0.170753002f },
                                          .d = { 0.492434859f, 0.471887469f, -0.233506441f },
                                          .t_min = -0.0992674f, .t_max = 0.0492569f });
    ray_gen g = ray_gen_make(s, 11);
    rl_vec3 lo = g.bounds.min, ext = rl_aabb_extent(g.bounds);
    uint32_t behind = 0;
    for (uint32_t i = 0; i < 20000; ++i) {
        rl_rng *rng = &g.rng;
        rl_vec3 o = rl_v3(lo.x + ext.x * rl_rng_float(rng), lo.y + ext.y * rl_rng_float(rng),
                          lo.z + ext.z * rl_rng_float(rng));
        float len = fmaxf(ext.x, fmaxf(ext.y, ext.z)) * rl_rng_float(rng);
        rl_ray r = { .o = o, .d = random_direction(rng), .t_min = -len * rl_rng_float(rng),
                     .t_max = len };
        rl_ray a = r;
        rl_hit h;
        if (rl_accel_intersect(brute, &a, &h) && h.t < 0.0f)
            ++behind;
        assert_same_hit(brute, bvh, r);
    }
    assert_true(behind > 1000);
    rl_accel_release(bvh);
    rl_accel_release(brute);
    rl_scene_release(s);
}

/* The SIMD leaf test hands lanes with an edge function of exactly 0 to the
 * scalar test (double recompute): rays straight down at the vertices and
 * edge midpoints of an integer grid (every edge function through them is
 * exactly 0), and at the sphere's vertices, must give the brute-force hit
 * bit for bit. */
static void test_bvh_agrees_with_brute_force_at_vertices_and_edges(void **state)
{
    (void)state;
    enum { N = 12 };
    rl_vec3 pos[(N + 1) * (N + 1)];
    uint32_t idx[6 * N * N], *t = idx;
    for (uint32_t j = 0; j <= N; ++j)
        for (uint32_t i = 0; i <= N; ++i)
            pos[j * (N + 1) + i] = rl_v3((float)i, (float)j, (float)((i * 7 + j * 3) % 5) * 0.25f);
    for (uint32_t j = 0; j < N; ++j)
        for (uint32_t i = 0; i < N; ++i) {
            uint32_t a = j * (N + 1) + i;
            *t++ = a; *t++ = a + 1; *t++ = a + N + 1;
            *t++ = a + 1; *t++ = a + N + 2; *t++ = a + N + 1;
        }
    rl_scene *s = mesh_scene(pos, (N + 1) * (N + 1), idx, 2 * N * N);
    rl_accel *brute = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_accel *bvh = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    for (uint32_t j = 0; j <= 2 * N; ++j)
        for (uint32_t i = 0; i <= 2 * N; ++i) {
            rl_vec3 o = rl_v3(0.5f * (float)i, 0.5f * (float)j, 5.0f);
            assert_same_hit(brute, bvh, (rl_ray){ .o = o, .d = rl_v3(0, 0, -1), .t_max = INFINITY });
            assert_same_hit(brute, bvh, (rl_ray){ .o = o, .d = rl_v3(0, 0, -2), .t_max = 3.0f });
        }
    rl_accel_release(bvh);
    rl_accel_release(brute);
    rl_scene_release(s);

    rl_vec3 *sp;
    uint32_t *sidx, nv, nt;
    uv_sphere(8, 16, &sp, &nv, &sidx, &nt);
    s = mesh_scene(sp, nv, sidx, nt);
    brute = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    bvh = make_accel(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    for (uint32_t v = 0; v < nv; ++v) {
        assert_same_hit(brute, bvh, (rl_ray){ .o = rl_v3(0, 0, 0), .d = sp[v], .t_max = INFINITY });
        assert_same_hit(brute, bvh, (rl_ray){ .o = rl_scale(sp[v], 3.0f), .d = rl_scale(sp[v], -1.0f),
                                              .t_max = INFINITY });
    }
    rl_accel_release(bvh);
    rl_accel_release(brute);
    rl_scene_release(s);
    free(sp);
    free(sidx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_bvh_agrees_with_brute_force_on_cornell),
        cmocka_unit_test(test_bvh_agrees_with_brute_force_on_spheres),
        cmocka_unit_test(test_bvh_agrees_with_brute_force_on_cornell_teapot),
        cmocka_unit_test(test_bvh_agrees_with_brute_force_on_city),
        cmocka_unit_test(test_bvh_occluded_agrees_with_intersect_on_random_segments),
        cmocka_unit_test(test_bvh_finds_hits_at_negative_t),
        cmocka_unit_test(test_bvh_build_is_identical_with_one_and_two_threads),
        cmocka_unit_test(test_bvh_structure_is_consistent_and_stats_are_sane),
        cmocka_unit_test(test_bvh_build_wide_equals_build_then_widen),
        cmocka_unit_test(test_bvh_build_keeps_signed_zeros),
        cmocka_unit_test(test_bvh_block_cost_is_exact_and_fills_blocks),
        cmocka_unit_test(test_bvh_breaks_ties_by_lowest_triangle_id),
        cmocka_unit_test(test_rays_at_shared_edges_and_vertices_never_escape),
        cmocka_unit_test(test_bvh_agrees_with_brute_force_at_vertices_and_edges),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
