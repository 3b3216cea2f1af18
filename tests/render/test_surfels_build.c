/* test_surfels_build.c: the Progressive Blue Surfels preprocessing (Jähn
 * 2015, Sec. 6.1; rl_surfels.h) against what it must deliver, on scenes
 * built here (a unit cube with flat face normals, a sphere, a textured
 * cube): surfels are 20 bytes; the sequence depends on the seed only, not on
 * the thread count; every surfel lies on the surface with the outward
 * normal and the unlit k_d x texture colour; the cube's relative coverage
 * is its analytic projected area from a corner (sqrt(3) a^2) over the view
 * square framing its bounding sphere; every power-of-two prefix is blue
 * noise (its minimum nearest-neighbour distance is a good fraction of the
 * expected spacing sqrt(area / n), far above a random order's); relative
 * sizes are ~1 inside flat faces and smaller at sharp edges; bad input,
 * object subsets and cancelling behave as documented. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/surfels_internal.h"
#include "rl/rl_scene.h"
#include "rl/rl_surfels.h"

#define CUBE_EDGE 1.0f

/* An axis-aligned cube of edge CUBE_EDGE centred at `at`, 4 vertices per
 * face so that normals are flat, uv = the face's corner square. */
static void add_cube(rl_scene *s, rl_vec3 at, uint32_t material, const char *name)
{
    rl_vec3 pos[24], nrm[24];
    rl_vec2 uv[24];
    uint32_t idx[36];
    float h = 0.5f * CUBE_EDGE;
    for (int f = 0; f < 6; ++f) {
        int a = f / 2, b = (a + 1) % 3, c = (a + 2) % 3;
        float sg = f % 2 ? -1.0f : 1.0f;
        for (int k = 0; k < 4; ++k) {
            float q[3];
            q[a] = sg * h;
            q[b] = (k == 1 || k == 2) ? h : -h;
            q[c] = (k >= 2) ? h : -h;
            pos[4 * f + k] = rl_v3(at.x + q[0], at.y + q[1], at.z + q[2]);
            float nv[3] = { 0, 0, 0 };
            nv[a] = sg;
            nrm[4 * f + k] = rl_v3(nv[0], nv[1], nv[2]);
            uv[4 * f + k] = (rl_vec2){ (k == 1 || k == 2) ? 1.0f : 0.0f, k >= 2 ? 1.0f : 0.0f };
        }
        const uint32_t quad[6] = { 0, 1, 2, 0, 2, 3 };
        for (int k = 0; k < 6; ++k)
            idx[6 * f + k] = 4 * (uint32_t)f + quad[k];
    }
    rl_mesh_desc md = { .name = name, .num_vertices = 24, .positions = pos, .normals = nrm,
                        .uvs = uv, .num_triangles = 12, .indices = idx, .material = material };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, name, NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

static uint32_t add_material(rl_scene *s, rl_vec3 kd, uint32_t texture)
{
    rl_material m = rl_material_default();
    m.diffuse = kd;
    m.diffuse_texture = texture;
    uint32_t id;
    assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
    return id;
}

static rl_scene *cube_scene(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    add_cube(s, rl_v3(0, 0, 0), add_material(s, rl_v3(0.8f, 0.4f, 0.2f), RL_NONE), "cube");
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static void build(const rl_scene *s, const rl_surfel_desc *d, rl_surfel_set *out)
{
    rl_status st = rl_surfels_build(s, NULL, 0, d, out);
    if (st != RL_OK)
        fail_msg("rl_surfels_build: %s", rl_last_error());
}

static double cube_spacing(uint32_t n)
{
    return sqrt(6.0 * CUBE_EDGE * CUBE_EDGE / n);
}

/* ---- tests --------------------------------------------------------------- */

static void test_surfel_is_20_bytes_and_decodes(void **state)
{
    (void)state;
    assert_int_equal(sizeof(rl_surfel), 20);
    rl_surfel s = { { 1, 2, 3 }, { 127, 0, 0, 0 }, { 255, 0, 51 }, 128 };
    rl_vec3 n = rl_surfel_normal(&s), c = rl_surfel_color(&s);
    assert_float_equal(n.x, 1.0f, 1e-6f);
    assert_float_equal(n.y, 0.0f, 1e-6f);
    assert_float_equal(c.x, 1.0f, 1e-6f);
    assert_float_equal(c.z, 0.2f, 1e-6f);
    assert_float_equal(rl_surfel_size(&s), 128.0f / 255.0f, 1e-6f);
}

static void test_same_seed_gives_the_same_sequence_for_any_thread_count(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    const rl_surfel_sampling kinds[] = { RL_SURFEL_PROGRESSIVE, RL_SURFEL_CONSTANT, RL_SURFEL_RANDOM };
    for (int k = 0; k < 3; ++k) {
        rl_surfel_desc d = { .resolution = 64, .count = 600, .rounds_step = 50, .seed = 7,
                             .sampling = kinds[k], .threads = 1 };
        rl_surfel_set a, b, c;
        build(s, &d, &a);
        d.threads = 2;
        build(s, &d, &b);
        d.seed = 8;
        build(s, &d, &c);
        assert_int_equal(a.count, 600);
        assert_int_equal(b.count, a.count);
        assert_int_equal(a.candidates, b.candidates);
        assert_memory_equal(a.surfels, b.surfels, a.count * sizeof *a.surfels);
        assert_int_equal(c.count, a.count);
        assert_true(memcmp(a.surfels, c.surfels, a.count * sizeof *a.surfels) != 0);
        rl_surfel_set_free(&a);
        rl_surfel_set_free(&b);
        rl_surfel_set_free(&c);
        assert_null(a.surfels);
        assert_int_equal(a.count, 0);
    }
    rl_scene_release(s);
}

static void test_surfels_lie_on_the_cube_with_outward_normals_and_unlit_colour(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    const uint32_t res = 128;
    rl_surfel_set set;
    build(s, &(rl_surfel_desc){ .resolution = res, .count = 2000, .seed = 1 }, &set);
    assert_int_equal(set.count, 2000);
    /* The view square's side is the bounding sphere's diameter. */
    double pixel = sqrt(3.0) * CUBE_EDGE / res, h = 0.5 * CUBE_EDGE;
    for (uint32_t i = 0; i < set.count; ++i) {
        const rl_surfel *p = &set.surfels[i];
        double ax[3] = { fabs(p->position[0]), fabs(p->position[1]), fabs(p->position[2]) };
        double m = fmax(ax[0], fmax(ax[1], ax[2]));
        assert_true(fabs(m - h) < pixel);
        assert_true(m <= h + 1e-5);
        /* The normal is the one of a face the surfel lies on. */
        rl_vec3 n = rl_surfel_normal(p);
        const float nc[3] = { n.x, n.y, n.z };
        bool ok = false;
        for (int a = 0; a < 3; ++a)
            if (ax[a] > h - 1e-4 && nc[a] * (p->position[a] > 0 ? 1.0f : -1.0f) > 0.99f)
                ok = true;
        if (!ok)
            fail_msg("surfel %u at (%g %g %g) has normal (%g %g %g)", i, p->position[0],
                     p->position[1], p->position[2], n.x, n.y, n.z);
        assert_int_equal(p->normal[3], 0);
        assert_int_equal(p->color[0], 204);
        assert_int_equal(p->color[1], 102);
        assert_int_equal(p->color[2], 51);
    }
    assert_true(set.timing.total_ms >= set.timing.sampling_ms);
    assert_true(set.timing.atlas_ms > 0.0 && set.timing.candidates_ms > 0.0);
    rl_vec3 lo = set.bounds.min, hi = set.bounds.max;
    assert_float_equal(lo.x, -0.5f, 1e-6f);
    assert_float_equal(hi.z, 0.5f, 1e-6f);
    rl_surfel_set_free(&set);
    rl_scene_release(s);
}

static void test_cube_coverage_is_its_projected_area_from_a_corner(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    const uint32_t res = 256;
    rl_surfel_set set;
    build(s, &(rl_surfel_desc){ .resolution = res, .count = 10, .seed = 3 }, &set);
    /* sqrt(3) a^2 over the square of the sphere's diameter sqrt(3) a. */
    double expected = sqrt(3.0) / 3.0;
    assert_true(fabs(set.coverage - expected) < 0.02 * expected);
    /* One candidate per covered pixel of the 8 views. */
    assert_int_equal(set.candidates, (uint32_t)lround(set.coverage * 8.0 * res * res));
    rl_surfel_set_free(&set);
    rl_scene_release(s);
}

static void prefix_min_distances(const rl_surfel_set *set, double *out, int *num)
{
    *num = 0;
    for (uint32_t m = 16; m <= set->count; m *= 2) {
        double lo, mean;
        assert_int_equal(rl_surfels_prefix_spacing(set->surfels, m, 0, &lo, &mean), RL_OK);
        assert_true(mean >= lo);
        out[(*num)++] = lo;
    }
}

static void test_every_power_of_two_prefix_is_blue_noise(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    const uint32_t count = 2048;
    rl_surfel_desc d = { .resolution = 128, .count = count, .rounds_step = 100, .seed = 11 };
    rl_surfel_set prog, cons, rnd;
    build(s, &d, &prog);
    d.sampling = RL_SURFEL_CONSTANT;
    build(s, &d, &cons);
    d.sampling = RL_SURFEL_RANDOM;
    build(s, &d, &rnd);
    double dp[16], dc[16], dr[16];
    int np, nc, nr;
    prefix_min_distances(&prog, dp, &np);
    prefix_min_distances(&cons, dc, &nc);
    prefix_min_distances(&rnd, dr, &nr);
    assert_int_equal(np, 8);    /* 16 .. 2048 */
    assert_int_equal(nc, np);
    assert_int_equal(nr, np);
    for (int i = 0; i < np; ++i) {
        double expected = cube_spacing(16u << i);
        if (!(dp[i] >= 0.45 * expected && dc[i] >= 0.45 * expected))
            fail_msg("prefix %u: min distance %g (progressive), %g (constant) vs spacing %g",
                     16u << i, dp[i], dc[i], expected);
        /* A random order clumps: a fraction of the blue-noise minimum. */
        if (!(dr[i] < 0.5 * dp[i]))
            fail_msg("prefix %u: random %g not clearly below progressive %g", 16u << i, dr[i], dp[i]);
    }
    rl_surfel_set_free(&prog);
    rl_surfel_set_free(&cons);
    rl_surfel_set_free(&rnd);
    rl_scene_release(s);
}

static void test_relative_size_is_one_on_flat_faces_and_smaller_at_edges(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    const uint32_t count = 3000;
    rl_surfel_set set;
    build(s, &(rl_surfel_desc){ .resolution = 128, .count = count, .seed = 5 }, &set);
    double sp = cube_spacing(count), h = 0.5 * CUBE_EDGE;
    double edge_sum = 0.0;
    int inner = 0, edge = 0;
    for (uint32_t i = 0; i < set.count; ++i) {
        const rl_surfel *p = &set.surfels[i];
        double ax[3] = { fabs(p->position[0]), fabs(p->position[1]), fabs(p->position[2]) };
        int a = ax[0] >= ax[1] && ax[0] >= ax[2] ? 0 : ax[1] >= ax[2] ? 1 : 2;
        double to_edge = fmin(h - ax[(a + 1) % 3], h - ax[(a + 2) % 3]);
        float size = rl_surfel_size(p);
        if (to_edge > 3.0 * sp) {
            ++inner;
            assert_true(size > 0.97f);
        } else if (to_edge < 0.3 * sp) {
            ++edge;
            edge_sum += size;
        }
    }
    assert_true(inner > 100 && edge > 20);
    /* About a third of an edge surfel's neighbours are on the other face. */
    assert_true(edge_sum / edge < 0.85);
    rl_surfel_set_free(&set);
    rl_scene_release(s);

    /* A smooth sphere: neighbours' normals almost agree everywhere. */
    rl_scene *sp_scene = NULL;
    uint32_t mesh, node;
    assert_int_equal(rl_scene_create(&sp_scene), RL_OK);
    uint32_t mat = add_material(sp_scene, rl_v3(0.5f, 0.5f, 0.5f), RL_NONE);
    assert_int_equal(rl_scene_add_generated(sp_scene, "sphere", "segments=64,rings=32", mat, &mesh),
                     RL_OK);
    assert_int_equal(rl_scene_add_node(sp_scene, RL_NODE_ROOT, "sphere", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(sp_scene, node, mesh), RL_OK);
    assert_int_equal(rl_scene_commit(sp_scene), RL_OK);
    build(sp_scene, &(rl_surfel_desc){ .resolution = 96, .count = 2000, .seed = 5 }, &set);
    double sum = 0.0;
    for (uint32_t i = 0; i < set.count; ++i) {
        rl_vec3 n = rl_surfel_normal(&set.surfels[i]);
        rl_vec3 p = rl_v3(set.surfels[i].position[0], set.surfels[i].position[1],
                          set.surfels[i].position[2]);
        assert_true(rl_dot(n, rl_normalize(p)) > 0.98f);   /* outward */
        sum += rl_surfel_size(&set.surfels[i]);
    }
    assert_true(sum / set.count > 0.95);
    /* The views frame the sphere around the bounds (radius sqrt(3) r): the
     * sphere fills pi r^2 / (2 sqrt(3) r)^2 = pi / 12 of every view. */
    double expected = 3.14159265358979 / 12.0;
    assert_true(fabs(set.coverage - expected) < 0.03 * expected);
    rl_surfel_set_free(&set);
    rl_scene_release(sp_scene);
}

static void test_colour_is_kd_times_the_texture(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_vec4 texel = { 0.5f, 1.0f, 0.25f, 1.0f };
    rl_texture *tex = NULL;
    uint32_t tid;
    assert_int_equal(rl_texture_create(1, 1, &texel, &tex), RL_OK);
    assert_int_equal(rl_scene_add_texture(s, tex, &tid), RL_OK);
    add_cube(s, rl_v3(0, 0, 0), add_material(s, rl_v3(1.0f, 0.5f, 1.0f), tid), "cube");
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_surfel_set set;
    build(s, &(rl_surfel_desc){ .resolution = 32, .count = 100 }, &set);
    /* 0.5 x 1, 1 x 0.5, 1 x 0.25 in 8 bits (bilinear lookup: +-1). */
    assert_true(set.count == 100);
    for (uint32_t i = 0; i < set.count; ++i) {
        assert_in_range(set.surfels[i].color[0], 127, 128);
        assert_in_range(set.surfels[i].color[1], 127, 128);
        assert_in_range(set.surfels[i].color[2], 63, 64);
    }
    rl_surfel_set_free(&set);
    rl_scene_release(s);
}

static void test_an_object_subset_gets_only_its_surface(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t mat = add_material(s, rl_v3(0.5f, 0.5f, 0.5f), RL_NONE);
    add_cube(s, rl_v3(0, 0, 0), mat, "a");
    add_cube(s, rl_v3(5, 0, 0), mat, "b");
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const uint32_t objects[1] = { 1 };
    rl_surfel_set set;
    assert_int_equal(rl_surfels_build(s, objects, 1, &(rl_surfel_desc){ .resolution = 64, .count = 300 },
                                      &set), RL_OK);
    assert_int_equal(set.count, 300);
    assert_float_equal(set.bounds.min.x, 4.5f, 1e-5f);
    for (uint32_t i = 0; i < set.count; ++i)
        assert_true(set.surfels[i].position[0] > 4.49f);
    rl_surfel_set_free(&set);
    /* More surfels wanted than candidates: every candidate, once. */
    assert_int_equal(rl_surfels_build(s, objects, 1, &(rl_surfel_desc){ .resolution = 8, .count = 100000 },
                                      &set), RL_OK);
    assert_true(set.count > 0);
    assert_int_equal(set.count, set.candidates);
    rl_surfel_set_free(&set);
    rl_scene_release(s);
}

static void assert_fails(rl_status expected, const rl_scene *s, const uint32_t *objects,
                         uint32_t n, const rl_surfel_desc *d)
{
    rl_surfel_set set;
    memset(&set, 0xAB, sizeof set);
    assert_int_equal(rl_surfels_build(s, objects, n, d, &set), expected);
    rl_surfel_set zero;
    memset(&zero, 0, sizeof zero);
    assert_memory_equal(&set, &zero, sizeof set);
    rl_clear_error();
}

static void test_bad_input_is_refused_with_outputs_zeroed(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    assert_int_equal(rl_surfels_build(s, NULL, 0, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_fails(RL_ERR_INVALID_ARG, NULL, NULL, 0, NULL);
    assert_fails(RL_ERR_INVALID_ARG, s, NULL, 0, &(rl_surfel_desc){ .resolution = 16385 });
    assert_fails(RL_ERR_INVALID_ARG, s, NULL, 0, &(rl_surfel_desc){ .count = (1u << 26) + 1 });
    assert_fails(RL_ERR_INVALID_ARG, s, NULL, 0, &(rl_surfel_desc){ .start_sample = 2000000 });
    assert_fails(RL_ERR_INVALID_ARG, s, NULL, 0, &(rl_surfel_desc){ .neighbours = 5000 });
    assert_fails(RL_ERR_INVALID_ARG, s, NULL, 0, &(rl_surfel_desc){ .sampling = (rl_surfel_sampling)7 });
    assert_fails(RL_ERR_INVALID_ARG, s, NULL, 0, &(rl_surfel_desc){ .threads = -1 });
    const uint32_t bad[2] = { 0, 1 };
    assert_fails(RL_ERR_INVALID_ARG, s, bad, 2, NULL);
    assert_fails(RL_ERR_INVALID_ARG, s, bad, 0, NULL);
    rl_scene *open = NULL;
    assert_int_equal(rl_scene_create(&open), RL_OK);
    add_cube(open, rl_v3(0, 0, 0), add_material(open, rl_v3(1, 1, 1), RL_NONE), "cube");
    assert_fails(RL_ERR_NOT_COMMITTED, open, NULL, 0, NULL);
    rl_scene_release(open);
    rl_scene_release(s);
}

typedef struct progress_log {
    int calls, cancel_at;
    double last;
    bool monotonic;
} progress_log;

static bool on_progress(void *user, double done)
{
    progress_log *l = user;
    l->monotonic = l->monotonic && done >= l->last && done <= 1.0;
    l->last = done;
    return ++l->calls != l->cancel_at;
}

static void test_progress_is_reported_and_false_cancels(void **state)
{
    (void)state;
    rl_scene *s = cube_scene();
    progress_log log = { .monotonic = true, .cancel_at = -1 };
    rl_surfel_desc d = { .resolution = 64, .count = 5000, .progress = on_progress, .user = &log };
    rl_surfel_set set;
    build(s, &d, &set);
    rl_surfel_set_free(&set);
    assert_true(log.calls >= 9 && log.monotonic);
    assert_float_equal(log.last, 1.0, 0.0);
    const int total = log.calls;
    for (int at = 1; at <= total; at += total / 4 > 0 ? total / 4 : 1) {
        log = (progress_log){ .monotonic = true, .cancel_at = at };
        assert_fails(RL_ERR_CANCELLED, s, NULL, 0, &d);
    }
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_surfel_is_20_bytes_and_decodes),
        cmocka_unit_test(test_same_seed_gives_the_same_sequence_for_any_thread_count),
        cmocka_unit_test(test_surfels_lie_on_the_cube_with_outward_normals_and_unlit_colour),
        cmocka_unit_test(test_cube_coverage_is_its_projected_area_from_a_corner),
        cmocka_unit_test(test_every_power_of_two_prefix_is_blue_noise),
        cmocka_unit_test(test_relative_size_is_one_on_flat_faces_and_smaller_at_edges),
        cmocka_unit_test(test_colour_is_kd_times_the_texture),
        cmocka_unit_test(test_an_object_subset_gets_only_its_surface),
        cmocka_unit_test(test_bad_input_is_refused_with_outputs_zeroed),
        cmocka_unit_test(test_progress_is_reported_and_false_cancels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
