/* test_grid.c: the uniform grid (src/accel/grid.h): resolution heuristic,
 * exact cell lists, the 3D-DDA walk against a brute-force list of cells, and
 * closest/any hit against RL_ACCEL_BRUTE on random and degenerate rays. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/grid.h"
#include "rl/rl_accel.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

/* ---- scenes ---------------------------------------------------------- */

static rl_scene *builtin(const char *name, const char *params)
{
    rl_scene *s = NULL;
    if (rl_scene_create_builtin(name, params, &s) != RL_OK)
        fail_msg("%s (%s): %s", name, params ? params : "", rl_last_error());
    return s;
}

/* A committed scene of the given triangles (3 vertices each), one object. */
static rl_scene *scene_of(const rl_vec3 *verts, uint32_t num_triangles)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    uint32_t *idx = malloc(3 * (size_t)num_triangles * sizeof *idx);
    assert_non_null(idx);
    for (uint32_t i = 0; i < 3 * num_triangles; ++i)
        idx[i] = i;
    rl_mesh_desc d = { .name = "tris", .num_vertices = 3 * num_triangles, .positions = verts,
                       .num_triangles = num_triangles, .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &d, &mesh), RL_OK);
    free(idx);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "tris", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static rl_accel *accel_of(const rl_scene *s, rl_accel_desc desc)
{
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &desc, &a), RL_OK);
    if (rl_accel_commit(a) != RL_OK)
        fail_msg("commit %s: %s", rl_accel_kind_name(desc.kind), rl_last_error());
    return a;
}

/* ---- rays ------------------------------------------------------------ */

static float uniform(rl_rng *r, float lo, float hi) { return lo + (hi - lo) * rl_rng_float(r); }

static rl_vec3 random_dir(rl_rng *r)
{
    for (;;) {
        rl_vec3 d = rl_v3(uniform(r, -1, 1), uniform(r, -1, 1), uniform(r, -1, 1));
        float l2 = rl_length2(d);
        if (l2 > 1e-4f && l2 <= 1.0f)
            return d;
    }
}

static rl_vec3 random_in(rl_rng *r, rl_aabb b)
{
    return rl_v3(uniform(r, b.min.x, b.max.x), uniform(r, b.min.y, b.max.y), uniform(r, b.min.z, b.max.z));
}

static rl_vec3 random_on_triangle(rl_rng *r, const rl_scene_data *d, uint32_t tri)
{
    float u = rl_rng_float(r), v = rl_rng_float(r);
    if (u + v > 1.0f) {
        u = 1.0f - u;
        v = 1.0f - v;
    }
    const uint32_t *i = d->indices + 3 * (size_t)tri;
    rl_vec3 p0 = d->positions[i[0]], p1 = d->positions[i[1]], p2 = d->positions[i[2]];
    return rl_add(p0, rl_add(rl_scale(rl_sub(p1, p0), u), rl_scale(rl_sub(p2, p0), v)));
}

/* A mix: inside or outside the box, aimed at a triangle, at a vertex (ties
 * and edges), axis-parallel (zero components), segments with finite t. */
static rl_ray random_ray(rl_rng *r, const rl_scene_data *d)
{
    rl_aabb b = d->bounds;
    rl_vec3 e = rl_aabb_extent(b);
    float s = rl_vmax_comp(e);
    rl_aabb wide = { rl_sub(b.min, rl_v3s(0.5f * s)), rl_add(b.max, rl_v3s(0.5f * s)) };
    rl_ray ray = { .o = random_in(r, wide), .t_min = 0.0f, .t_max = INFINITY };
    uint32_t kind = rl_rng_bounded(r, 6);
    if (kind == 0) {
        ray.o = random_in(r, b);
        ray.d = random_dir(r);
    } else if (kind == 1) {
        ray.d = rl_sub(random_on_triangle(r, d, rl_rng_bounded(r, d->num_triangles)), ray.o);
    } else if (kind == 2) {
        ray.d = rl_sub(d->positions[d->indices[rl_rng_bounded(r, 3 * d->num_triangles)]], ray.o);
    } else if (kind == 3) {
        ray.o = random_in(r, wide);
        ray.d = rl_v3(0, 0, 0);
        float sign = rl_rng_bounded(r, 2) ? 1.0f : -1.0f;
        uint32_t axes = rl_rng_bounded(r, 3);
        if (axes == 0)
            ray.d.x = sign;                        /* one non-zero component */
        else if (axes == 1)
            ray.d = rl_v3(sign, 0.5f, 0.0f);       /* one zero component */
        else
            ray.d = rl_v3(0.0f, sign * 0.3f, -0.7f);
    } else if (kind == 4) {
        ray.o = random_in(r, b);
        ray.d = random_dir(r);
        ray.t_min = uniform(r, -0.2f, 0.3f) * s;
        ray.t_max = ray.t_min + uniform(r, 0.0f, 1.0f) * s;
    } else {
        ray.d = rl_sub(random_in(r, b), ray.o);
    }
    if (rl_length2(ray.d) == 0.0f)
        ray.d = rl_v3(0, 1, 0);
    return ray;
}

/* Same hit or miss, same triangle and object, t within 1e-4 (relative),
 * and the grid's any-hit answer equals the brute-force closest-hit one (the
 * same question; asking brute force twice would double the test's time). */
static void assert_same_answer(const rl_accel *grid, const rl_accel *brute, rl_ray ray, int i)
{
    rl_ray rg = ray, rb = ray;
    rl_hit hg, hb;
    bool g = rl_accel_intersect(grid, &rg, &hg), b = rl_accel_intersect(brute, &rb, &hb);
    if (g != b || hg.triangle != hb.triangle || hg.object != hb.object)
        fail_msg("ray %d o=(%g %g %g) d=(%g %g %g) t=(%g %g): grid %d tri %u t %g, brute %d tri %u t %g",
                 i, (double)ray.o.x, (double)ray.o.y, (double)ray.o.z, (double)ray.d.x,
                 (double)ray.d.y, (double)ray.d.z, (double)ray.t_min, (double)ray.t_max, g,
                 hg.triangle, (double)hg.t, b, hb.triangle, (double)hb.t);
    if (g) {
        assert_true(fabsf(hg.t - hb.t) <= 1e-4f * fabsf(hb.t));
        assert_true(rg.t_max == hg.t);
    }
    if (rl_accel_occluded(grid, &ray) != b)
        fail_msg("ray %d: occluded differs", i);
}

/* 104000 rays over the four scenes below, weighted by brute force's cost. */
static void agree_on_random_rays(const char *name, const char *params, int num_rays, uint64_t seed)
{
    rl_scene *s = builtin(name, params);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_rng r;
    rl_rng_seed(&r, seed, 7);
    int hits = 0;
    for (int i = 0; i < num_rays; ++i) {
        rl_ray ray = random_ray(&r, d);
        assert_same_answer(grid, brute, ray, i);
        rl_hit h;
        hits += rl_accel_intersect(grid, &ray, &h);
    }
    /* The rays must exercise hits as well as misses. */
    assert_true(hits > num_rays / 5 && hits < num_rays);
    rl_accel_release(grid);
    rl_accel_release(brute);
    rl_scene_release(s);
}

/* ---- tests ------------------------------------------------------------ */

static void test_grid_resolution_follows_the_documented_rule(void **state)
{
    (void)state;
    int res[3];
    /* k = (λ³N/V)^(1/3) = (8·1000/8)^(1/3) = 10: the example in grid.h. */
    rl_grid_resolution(rl_v3(4, 2, 1), 1000, 2.0f, res);
    assert_int_equal(res[0], 40); assert_int_equal(res[1], 20); assert_int_equal(res[2], 10);
    rl_grid_resolution(rl_v3(4, 2, 1), 1000, 0.0f, res);      /* λ 0 -> 2 */
    assert_int_equal(res[0], 40); assert_int_equal(res[1], 20); assert_int_equal(res[2], 10);
    rl_grid_resolution(rl_v3(4, 2, 1), 1000, 1.0f, res);
    assert_int_equal(res[0], 20); assert_int_equal(res[1], 10); assert_int_equal(res[2], 5);
    /* Flat square: 2D rule, k = sqrt(λ²N/A) = sqrt(4·2/4), round(2·1.414) = 3. */
    rl_grid_resolution(rl_v3(2, 0, 2), 2, 2.0f, res);
    assert_int_equal(res[0], 3); assert_int_equal(res[1], 1); assert_int_equal(res[2], 3);
    /* Thin slab: z would get 0.05 cells, drops out; k = sqrt(4·2000/10^4). */
    rl_grid_resolution(rl_v3(100, 100, 0.01f), 2000, 2.0f, res);
    assert_int_equal(res[0], 89); assert_int_equal(res[1], 89); assert_int_equal(res[2], 1);
    /* Per-axis clamp: k = (8·10^6/1000)^(1/3) = 20, x would be 20000. */
    rl_grid_resolution(rl_v3(1000, 1, 1), 1000000, 2.0f, res);
    assert_int_equal(res[0], RL_GRID_MAX_RES); assert_int_equal(res[1], 20); assert_int_equal(res[2], 20);
    /* Total cap: 431³ cells scaled down to at most 2^24, still a cube. */
    rl_grid_resolution(rl_v3(1, 1, 1), 10000000, 2.0f, res);
    assert_true((uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2] <= RL_GRID_MAX_CELLS);
    assert_true(res[0] == res[1] && res[1] == res[2] && res[0] >= 250);
    rl_grid_resolution(rl_v3(1, 1, 1), 0, 2.0f, res);
    assert_int_equal(res[0] * res[1] * res[2], 1);
}

/* 1000 small random triangles in [0,4]x[0,2]x[0,1], two of them pinning
 * the box corners, so the triangles' box is exactly the known one. */
static rl_scene *known_box_scene(void)
{
    enum { N = 1000 };
    rl_vec3 *v = malloc(3 * N * sizeof *v);
    assert_non_null(v);
    rl_rng r;
    rl_rng_seed(&r, 3, 1);
    rl_aabb inner = { { 0.2f, 0.2f, 0.2f }, { 3.8f, 1.8f, 0.8f } };
    for (int i = 0; i < N; ++i) {
        rl_vec3 c = random_in(&r, inner);
        for (int k = 0; k < 3; ++k)
            v[3 * i + k] = rl_add(c, rl_scale(random_dir(&r), 0.15f));
    }
    v[0] = rl_v3(0, 0, 0); v[1] = rl_v3(0.1f, 0, 0); v[2] = rl_v3(0, 0.1f, 0.1f);
    v[3] = rl_v3(4, 2, 1); v[4] = rl_v3(3.9f, 2, 1); v[5] = rl_v3(4, 1.9f, 0.9f);
    rl_scene *s = scene_of(v, N);
    free(v);
    return s;
}

static void test_grid_stats_report_the_heuristic_resolution_and_overrides_win(void **state)
{
    (void)state;
    rl_scene *s = known_box_scene();
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 1000);
    rl_accel *a = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID });
    rl_accel_stats st;
    rl_accel_get_stats(a, &st);
    assert_int_equal(st.grid_res[0], 40);
    assert_int_equal(st.grid_res[1], 20);
    assert_int_equal(st.grid_res[2], 10);
    assert_true(st.grid_references >= 1000);
    /* CSR arrays + vertex copy at least. */
    assert_true(st.memory_bytes >= 8000 * 4 + st.grid_references * 4 + 1000 * 36);
    rl_accel_release(a);

    a = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_lambda = 1.0f });
    rl_accel_get_stats(a, &st);
    assert_int_equal(st.grid_res[0], 20);
    assert_int_equal(st.grid_res[2], 5);
    rl_accel_release(a);

    a = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 7, 0, 3 } });
    rl_accel_get_stats(a, &st);
    assert_int_equal(st.grid_res[0], 7);
    assert_int_equal(st.grid_res[1], 20);   /* 0: from the heuristic */
    assert_int_equal(st.grid_res[2], 3);
    rl_accel_release(a);
    rl_scene_release(s);
}

static bool cancel(void *user, double done)
{
    (void)done;
    ++*(int *)user;
    return false;
}

static void test_grid_build_rejects_bad_input_and_keeps_out_untouched(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_grid *g = NULL;
    assert_int_equal(rl_grid_build(NULL, NULL, &g), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_grid_build(d, NULL, NULL), RL_ERR_INVALID_ARG);
    rl_accel_desc desc = { .kind = RL_ACCEL_GRID, .grid_res = { 4096, 4096, 4096 } };
    assert_int_equal(rl_grid_build(d, &desc, &g), RL_ERR_LIMIT);
    assert_null(g);
    int calls = 0;
    desc = (rl_accel_desc){ .kind = RL_ACCEL_GRID, .progress = cancel, .user = &calls };
    assert_int_equal(rl_grid_build(d, &desc, &g), RL_ERR_CANCELLED);
    assert_null(g);
    assert_int_equal(calls, 1);
    /* Through the public API the same codes arrive. */
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &desc, &a), RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_ERR_CANCELLED);
    rl_accel_release(a);
    a = NULL;
    desc = (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 4096, 4096, 4096 } };
    assert_int_equal(rl_accel_create(s, &desc, &a), RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_ERR_LIMIT);
    rl_accel_release(a);
    rl_grid_free(NULL);
    rl_clear_error();
    rl_scene_release(s);
}

static void test_grid_cell_lists_are_sorted_and_identical_with_1_and_2_threads(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_grid *g1 = NULL, *g2 = NULL;
    assert_int_equal(rl_grid_build(d, &(rl_accel_desc){ .threads = 1 }, &g1), RL_OK);
    assert_int_equal(rl_grid_build(d, &(rl_accel_desc){ .threads = 2 }, &g2), RL_OK);
    assert_memory_equal(g1->res, g2->res, sizeof g1->res);
    assert_int_equal(g1->num_references, g2->num_references);
    assert_int_equal(g1->cell_start[g1->num_cells], g1->num_references);
    assert_memory_equal(g1->cell_start, g2->cell_start, ((size_t)g1->num_cells + 1) * sizeof(uint32_t));
    assert_memory_equal(g1->cell_tris, g2->cell_tris, (size_t)g1->num_references * sizeof(uint32_t));
    for (uint32_t c = 0; c < g1->num_cells; ++c)
        for (uint32_t j = g1->cell_start[c] + 1; j < g1->cell_start[c + 1]; ++j)
            assert_true(g1->cell_tris[j - 1] < g1->cell_tris[j]);
    rl_grid_free(g1);
    rl_grid_free(g2);
    rl_scene_release(s);
}

static bool cell_lists(const rl_grid *g, uint32_t cell, uint32_t tri)
{
    for (uint32_t j = g->cell_start[cell]; j < g->cell_start[cell + 1]; ++j)
        if (g->cell_tris[j] == tri)
            return true;
    return false;
}

static void test_grid_lists_a_triangle_wherever_its_surface_is_and_skips_far_cells(void **state)
{
    (void)state;
    rl_scene *s = builtin("spheres", "segments=16");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_grid *g = NULL;
    assert_int_equal(rl_grid_build(d, NULL, &g), RL_OK);
    rl_rng r;
    rl_rng_seed(&r, 11, 2);
    for (int i = 0; i < 20000; ++i) {
        uint32_t tri = rl_rng_bounded(&r, d->num_triangles);
        rl_vec3 p = random_on_triangle(&r, d, tri);
        int c[3];
        assert_true(rl_grid_cell_of(g, p, c));
        assert_true(cell_lists(g, rl_grid_cell_index(g, c[0], c[1], c[2]), tri));
    }
    /* No reference to a cell the triangle's box does not come near: the
     * exact overlap test only removes references, never adds far ones. */
    for (uint32_t c = 0; c < g->num_cells; ++c) {
        int xyz[3];
        rl_grid_cell_coords(g, c, xyz);
        assert_int_equal(rl_grid_cell_index(g, xyz[0], xyz[1], xyz[2]), c);
        rl_aabb cb = rl_grid_cell_bounds(g, xyz[0], xyz[1], xyz[2]);
        rl_vec3 slack = rl_scale(g->cell_size, 0.01f);
        cb.min = rl_sub(cb.min, slack);
        cb.max = rl_add(cb.max, slack);
        for (uint32_t j = g->cell_start[c]; j < g->cell_start[c + 1]; ++j) {
            const rl_vec3 *v = g->tri_verts + 3 * (size_t)g->cell_tris[j];
            rl_aabb tb = rl_aabb_grow(rl_aabb_grow(rl_aabb_grow(rl_aabb_empty(), v[0]), v[1]), v[2]);
            assert_false(rl_aabb_is_empty((rl_aabb){ rl_vmax(tb.min, cb.min), rl_vmin(tb.max, cb.max) }));
        }
    }
    /* The exact overlap test pays off: fewer references than the cells
     * the triangles' boxes cover (the floor's checker triangles cover half
     * of their boxes). */
    uint64_t box_refs = 0;
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        const rl_vec3 *v = g->tri_verts + 3 * (size_t)t;
        int lo[3], hi[3];
        rl_grid_cell_of(g, rl_vmin(v[0], rl_vmin(v[1], v[2])), lo);
        rl_grid_cell_of(g, rl_vmax(v[0], rl_vmax(v[1], v[2])), hi);
        box_refs += (uint64_t)(hi[0] - lo[0] + 1) * (uint64_t)(hi[1] - lo[1] + 1) * (uint64_t)(hi[2] - lo[2] + 1);
    }
    assert_true(g->num_references >= d->num_triangles);
    assert_true(g->num_references < box_refs);
    rl_grid_free(g);
    rl_scene_release(s);
}

/* Brute-force oracle for the walk: the parameter interval of the ray
 * segment inside a cell's box, if any. */
static bool segment_in_cell(const rl_grid *g, int x, int y, int z, const rl_ray *ray, double *t0, double *t1)
{
    rl_aabb b = rl_grid_cell_bounds(g, x, y, z);
    double lo = ray->t_min, hi = ray->t_max;
    for (int a = 0; a < 3; ++a) {
        double o = rl_vget(ray->o, a), dd = rl_vget(ray->d, a);
        double bl = rl_vget(b.min, a), bh = rl_vget(b.max, a);
        if (dd == 0.0) {
            if (o < bl || o > bh)
                return false;
            continue;
        }
        double tn = (bl - o) / dd, tf = (bh - o) / dd;
        if (tn > tf) {
            double s = tn;
            tn = tf;
            tf = s;
        }
        lo = tn > lo ? tn : lo;
        hi = tf < hi ? tf : hi;
    }
    *t0 = lo;
    *t1 = hi;
    return lo <= hi;
}

static void check_walk(const rl_grid *g, const rl_ray *ray, double tol)
{
    enum { MAX_VISITS = 4096 };
    static uint32_t cells[MAX_VISITS];
    static float enter[MAX_VISITS], leave[MAX_VISITS];
    int n = 0;
    rl_grid_dda it;
    if (rl_grid_dda_begin(g, ray, &it)) {
        uint32_t c;
        float t0, t1;
        while (rl_grid_dda_next(&it, &c, &t0, &t1)) {
            assert_true(n < MAX_VISITS);
            assert_int_equal(rl_grid_cell_index(g, it.current[0], it.current[1], it.current[2]), c);
            cells[n] = c;
            enter[n] = t0;
            leave[n] = t1;
            assert_true(t0 <= t1);
            if (n > 0)
                assert_true(t0 == leave[n - 1]);   /* contiguous, front to back */
            ++n;
        }
    }
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < i; ++j)
            assert_int_not_equal(cells[i], cells[j]);    /* each cell once */
    /* Every cell the segment really passes is visited with its interval;
     * a visited cell is at most touched (length within tol) if not. */
    for (uint32_t c = 0; c < g->num_cells; ++c) {
        int xyz[3];
        rl_grid_cell_coords(g, c, xyz);
        double t0 = 0.0, t1 = -1.0;
        bool passes = segment_in_cell(g, xyz[0], xyz[1], xyz[2], ray, &t0, &t1) && t1 - t0 > tol;
        int found = -1;
        for (int i = 0; i < n; ++i)
            if (cells[i] == c)
                found = i;
        if (passes) {
            if (found < 0)
                fail_msg("cell %u (%d %d %d) with [%g, %g] not visited", c, xyz[0], xyz[1], xyz[2], t0, t1);
            assert_true(fabs(enter[found] - t0) <= tol && fabs(leave[found] - t1) <= tol);
        } else if (found >= 0) {
            assert_true(leave[found] - enter[found] <= tol);
        }
    }
}

static void test_grid_dda_visits_exactly_the_cells_the_ray_passes(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_grid *g = NULL;
    assert_int_equal(rl_grid_build(d, &(rl_accel_desc){ .grid_res = { 7, 5, 6 } }, &g), RL_OK);
    assert_int_equal(g->num_cells, 210);
    rl_rng r;
    rl_rng_seed(&r, 5, 3);
    for (int i = 0; i < 3000; ++i) {
        rl_ray ray = random_ray(&r, d);
        /* 10 µm along the ray in a 0.55 m box, as a tolerance in t. */
        check_walk(g, &ray, 1e-5 / rl_length(ray.d));
    }
    /* Leaving through a corner, ending inside, starting past the end. */
    rl_vec3 lo = g->bounds.min, hi = g->bounds.max;
    rl_ray diag = { .o = rl_sub(lo, rl_v3s(0.1f)), .d = rl_sub(hi, lo), .t_min = 0, .t_max = INFINITY };
    check_walk(g, &diag, 1e-5);
    diag.t_max = 0.5f;
    check_walk(g, &diag, 1e-5);
    diag.t_min = 2.0f;
    diag.t_max = 3.0f;
    rl_grid_dda it;
    assert_false(rl_grid_dda_begin(g, &diag, &it));
    rl_grid_free(g);
    rl_scene_release(s);
}

static void test_grid_cell_of_clamps_and_says_whether_the_point_is_inside(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    rl_grid *g = NULL;
    assert_int_equal(rl_grid_build(rl_scene_get_data(s), &(rl_accel_desc){ .grid_res = { 4, 4, 4 } }, &g),
                     RL_OK);
    int c[3];
    assert_true(rl_grid_cell_of(g, g->bounds.min, c));
    assert_int_equal(c[0] + c[1] + c[2], 0);
    assert_true(rl_grid_cell_of(g, g->bounds.max, c));
    assert_true(c[0] == 3 && c[1] == 3 && c[2] == 3);
    assert_false(rl_grid_cell_of(g, rl_add(g->bounds.max, rl_v3s(1.0f)), c));
    assert_true(c[0] == 3 && c[1] == 3 && c[2] == 3);
    assert_false(rl_grid_cell_of(g, rl_v3(-100.0f, 0.2f, 0.2f), c));
    assert_int_equal(c[0], 0);
    /* A point on an inner face belongs to the upper cell. */
    rl_aabb b = rl_grid_cell_bounds(g, 1, 2, 3);
    assert_true(rl_grid_cell_of(g, b.min, c));
    assert_true(c[0] == 1 && c[1] == 2 && c[2] == 3);
    rl_grid_free(g);
    rl_scene_release(s);
}

static void test_grid_agrees_with_brute_force_on_cornell(void **state)
{
    (void)state;
    agree_on_random_rays("cornell", NULL, 90000, 1);
}

static void test_grid_agrees_with_brute_force_on_spheres(void **state)
{
    (void)state;
    agree_on_random_rays("spheres", "segments=16", 8000, 2);
}

static void test_grid_agrees_with_brute_force_on_cornell_teapot(void **state)
{
    (void)state;
    agree_on_random_rays("cornell-teapot", "triangles=2000", 4000, 3);
}

static void test_grid_agrees_with_brute_force_on_city(void **state)
{
    (void)state;
    agree_on_random_rays("city", "blocks=1,detail=0", 2000, 4);
}

/* Rays on cell boundary planes with a zero direction component there, and
 * through cell corners, starting inside, outside, and on the grid's faces. */
static void test_grid_agrees_with_brute_force_on_rays_along_cell_boundaries(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel_desc desc = { .kind = RL_ACCEL_GRID, .grid_res = { 6, 6, 6 } };
    rl_grid *g = NULL;
    assert_int_equal(rl_grid_build(d, &desc, &g), RL_OK);
    rl_accel *grid = accel_of(s, desc);
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_rng r;
    rl_rng_seed(&r, 9, 4);
    int count = 0;
    for (int i = 0; i < 6000; ++i) {
        /* A random grid vertex (inner or on the faces). */
        int k[3] = { (int)rl_rng_bounded(&r, 7), (int)rl_rng_bounded(&r, 7), (int)rl_rng_bounded(&r, 7) };
        rl_aabb cb = rl_grid_cell_bounds(g, k[0], k[1], k[2]);
        rl_vec3 corner = cb.min;
        rl_ray ray = { .o = corner, .t_min = 0.0f, .t_max = INFINITY };
        uint32_t kind = rl_rng_bounded(&r, 4);
        if (kind == 0) {            /* in a boundary plane: one zero component */
            int axis = (int)rl_rng_bounded(&r, 3);
            ray.d = random_dir(&r);
            if (axis == 0) ray.d.x = 0.0f;
            else if (axis == 1) ray.d.y = 0.0f;
            else ray.d.z = 0.0f;
            float shift = uniform(&r, -0.2f, 0.2f);   /* start anywhere on the plane */
            if (axis != 0) ray.o.x += shift;
            if (axis != 1) ray.o.y += shift;
            if (axis != 2) ray.o.z += shift;
        } else if (kind == 1) {     /* along a grid line: two zero components */
            ray.d = rl_v3(0, 0, 0);
            float sign = rl_rng_bounded(&r, 2) ? 1.0f : -1.0f;
            uint32_t axis = rl_rng_bounded(&r, 3);
            if (axis == 0) ray.d.x = sign;
            else if (axis == 1) ray.d.y = sign;
            else ray.d.z = sign;
            ray.o = rl_sub(ray.o, rl_scale(ray.d, 0.3f));   /* from outside or inside */
        } else if (kind == 2) {     /* diagonal through grid vertices */
            ray.d = rl_mul(g->cell_size, rl_v3(rl_rng_bounded(&r, 2) ? 1.0f : -1.0f,
                                               rl_rng_bounded(&r, 2) ? 1.0f : -1.0f, 1.0f));
            ray.o = rl_sub(ray.o, rl_scale(ray.d, (float)rl_rng_bounded(&r, 8)));
        } else {                    /* from a vertex to another vertex */
            int m[3] = { (int)rl_rng_bounded(&r, 7), (int)rl_rng_bounded(&r, 7), (int)rl_rng_bounded(&r, 7) };
            ray.d = rl_sub(rl_grid_cell_bounds(g, m[0], m[1], m[2]).min, corner);
        }
        if (rl_length2(ray.d) == 0.0f)
            continue;
        assert_same_answer(grid, brute, ray, i);
        ++count;
    }
    assert_true(count > 5000);
    rl_grid_free(g);
    rl_accel_release(grid);
    rl_accel_release(brute);
    rl_scene_release(s);
}

/* Origins 10 to 10^4 box sizes away, aimed exactly at vertices and edge
 * midpoints (many on the outer faces of the grid): the walk's rounding
 * grows with the distance and must not lose what the triangle test finds. */
static void test_grid_agrees_with_brute_force_for_origins_far_away(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_vec3 c = rl_aabb_center(d->bounds);
    float size = rl_vmax_comp(rl_aabb_extent(d->bounds));
    rl_rng r;
    rl_rng_seed(&r, 17, 6);
    for (int i = 0; i < 8000; ++i) {
        float dist = size * powf(10.0f, 1.0f + (float)(i % 4));
        rl_vec3 o = rl_add(c, rl_scale(rl_normalize(random_dir(&r)), dist));
        const uint32_t *t = d->indices + 3 * (size_t)rl_rng_bounded(&r, d->num_triangles);
        rl_vec3 target = d->positions[t[i % 3]];
        if (i % 2)
            target = rl_scale(rl_add(d->positions[t[0]], d->positions[t[1]]), 0.5f);
        rl_ray ray = { .o = o, .d = rl_sub(target, o), .t_min = 0.0f, .t_max = INFINITY };
        assert_same_answer(grid, brute, ray, i);
    }
    rl_accel_release(grid);
    rl_accel_release(brute);
    rl_scene_release(s);
}

static void test_grid_handles_a_flat_scene_of_one_quad(void **state)
{
    (void)state;
    /* A 2 m square at y = 0.5: the box is flat in y. */
    const rl_vec3 v[6] = { { -1, 0.5f, -1 }, { 1, 0.5f, -1 }, { 1, 0.5f, 1 },
                           { -1, 0.5f, -1 }, { 1, 0.5f, 1 }, { -1, 0.5f, 1 } };
    rl_scene *s = scene_of(v, 2);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_accel_stats st;
    rl_accel_get_stats(grid, &st);
    assert_int_equal(st.grid_res[0], 3);       /* round(2 * sqrt(2)) */
    assert_int_equal(st.grid_res[1], 1);
    assert_int_equal(st.grid_res[2], 3);
    /* Straight down onto the quad's diagonal: the lower ID of a tie. */
    rl_ray down = { .o = rl_v3(0.25f, 2.0f, 0.25f), .d = rl_v3(0, -1, 0), .t_min = 0, .t_max = INFINITY };
    rl_hit h;
    assert_true(rl_accel_intersect(grid, &down, &h));
    assert_true(h.t == 1.5f);
    assert_int_equal(h.triangle, 0);
    /* In the quad's plane: no hit (coplanar), from above and below: hits. */
    rl_ray in_plane = { .o = rl_v3(-3, 0.5f, 0), .d = rl_v3(1, 0, 0), .t_min = 0, .t_max = INFINITY };
    assert_false(rl_accel_intersect(grid, &in_plane, &h));
    rl_rng r;
    rl_rng_seed(&r, 13, 5);
    int hits = 0;
    for (int i = 0; i < 5000; ++i) {
        rl_ray ray = { .o = rl_v3(uniform(&r, -2, 2), uniform(&r, -1, 2), uniform(&r, -2, 2)),
                       .t_min = 0, .t_max = INFINITY };
        ray.d = rl_sub(rl_v3(uniform(&r, -1.2f, 1.2f), 0.5f, uniform(&r, -1.2f, 1.2f)), ray.o);
        if (i % 7 == 0)
            ray.d = random_dir(&r);
        assert_same_answer(grid, brute, ray, i);
        rl_hit hh;
        hits += rl_accel_intersect(grid, &ray, &hh);
    }
    assert_true(hits > 2000);
    rl_accel_release(grid);
    rl_accel_release(brute);
    rl_scene_release(s);
}

static void test_grid_answers_rays_inside_outside_and_parallel_to_axes(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_vec3 c = rl_aabb_center(d->bounds);
    const rl_vec3 dirs[6] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 }, { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
    for (int i = 0; i < 6; ++i) {
        rl_ray inside = { .o = c, .d = dirs[i], .t_min = 0, .t_max = INFINITY };
        rl_hit h;
        /* The box is closed except at the front (-z). */
        assert_int_equal(rl_accel_intersect(grid, &inside, &h), i != 5);
        assert_same_answer(grid, brute, inside, i);
        rl_ray outside = { .o = rl_sub(c, rl_scale(dirs[i], 3.0f)), .d = dirs[i], .t_min = 0, .t_max = INFINITY };
        assert_true(rl_accel_intersect(grid, &outside, &h));
        assert_same_answer(grid, brute, outside, i);
        rl_ray away = { .o = rl_add(c, rl_scale(dirs[i], 3.0f)), .d = dirs[i], .t_min = 0, .t_max = INFINITY };
        assert_false(rl_accel_intersect(grid, &away, &h));
        assert_int_equal(h.triangle, RL_ID_NONE);
        assert_false(rl_accel_occluded(grid, &away));
        /* A segment that ends before anything: no hit, not occluded. */
        rl_ray short_seg = { .o = c, .d = dirs[i], .t_min = 0, .t_max = 0.001f };
        assert_false(rl_accel_intersect(grid, &short_seg, &h));
        assert_false(rl_accel_occluded(grid, &short_seg));
    }
    rl_accel_release(grid);
    rl_accel_release(brute);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_grid_resolution_follows_the_documented_rule),
        cmocka_unit_test(test_grid_stats_report_the_heuristic_resolution_and_overrides_win),
        cmocka_unit_test(test_grid_build_rejects_bad_input_and_keeps_out_untouched),
        cmocka_unit_test(test_grid_cell_lists_are_sorted_and_identical_with_1_and_2_threads),
        cmocka_unit_test(test_grid_lists_a_triangle_wherever_its_surface_is_and_skips_far_cells),
        cmocka_unit_test(test_grid_dda_visits_exactly_the_cells_the_ray_passes),
        cmocka_unit_test(test_grid_cell_of_clamps_and_says_whether_the_point_is_inside),
        cmocka_unit_test(test_grid_agrees_with_brute_force_on_cornell),
        cmocka_unit_test(test_grid_agrees_with_brute_force_on_spheres),
        cmocka_unit_test(test_grid_agrees_with_brute_force_on_cornell_teapot),
        cmocka_unit_test(test_grid_agrees_with_brute_force_on_city),
        cmocka_unit_test(test_grid_agrees_with_brute_force_on_rays_along_cell_boundaries),
        cmocka_unit_test(test_grid_agrees_with_brute_force_for_origins_far_away),
        cmocka_unit_test(test_grid_handles_a_flat_scene_of_one_quad),
        cmocka_unit_test(test_grid_answers_rays_inside_outside_and_parallel_to_axes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
