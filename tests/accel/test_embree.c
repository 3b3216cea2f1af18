/* test_embree.c: the Embree 3 adapter (src/accel/embree.c) through the
 * public rl_accel API: exact hits on a known triangle (t, Embree's u/v
 * convention = rl_hit's, triangle and object IDs), misses, occlusion, the
 * generic layer's invalid rays, negative t_min, stats, build threads and
 * cancelling. Every case skips when the build has no Embree. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_accel.h"
#include "rl/rl_scene.h"

static void skip_without_embree(void)
{
    if (!rl_accel_kind_available(RL_ACCEL_EMBREE))
        skip();
}

/* Two single-triangle objects: object 0 (triangle 0) in the plane z = 0,
 * object 1 (triangle 1) in z = -1, both with p0 at the origin of their
 * plane, p1 along +x (length 2), p2 along +y (length 4), so that a hit at
 * (x, y) has u = x/2 and v = y/4 exactly. */
static rl_scene *two_triangles(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat = 0;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    for (int k = 0; k < 2; ++k) {
        float z = -(float)k;
        rl_vec3 p[3] = { rl_v3(0, 0, z), rl_v3(2, 0, z), rl_v3(0, 4, z) };
        uint32_t idx[3] = { 0, 1, 2 };
        rl_mesh_desc md = { .name = k ? "back" : "front", .num_vertices = 3, .positions = p,
                            .num_triangles = 1, .indices = idx, .material = mat };
        uint32_t mesh = 0, node = 0;
        assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
        assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, md.name, NULL, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static rl_accel *build(const rl_scene *s, rl_accel_desc desc)
{
    rl_accel *a = NULL;
    rl_status st = rl_accel_create(s, &desc, &a);
    if (st != RL_OK)
        fail_msg("create: %s", rl_last_error());
    st = rl_accel_commit(a);
    if (st != RL_OK)
        fail_msg("commit: %s", rl_last_error());
    return a;
}

static rl_ray ray(rl_vec3 o, rl_vec3 d, float t_min, float t_max)
{
    return (rl_ray){ .o = o, .d = d, .t_min = t_min, .t_max = t_max };
}

static void test_embree_hits_a_known_triangle_with_exact_t_u_v_and_ids(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = two_triangles();
    rl_accel *a = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });

    /* From z = +3 straight down: the front triangle at t = 3, point (0.5, 1). */
    rl_ray r = ray(rl_v3(0.5f, 1.0f, 3.0f), rl_v3(0, 0, -1), 0.0f, INFINITY);
    rl_hit h;
    assert_true(rl_accel_intersect(a, &r, &h));
    assert_float_equal(h.t, 3.0f, 1e-6f);
    assert_float_equal(r.t_max, h.t, 0.0f);
    /* p = (1-u-v)·p0 + u·p1 + v·p2: u = x/2, v = y/4 (not swapped). */
    assert_float_equal(h.u, 0.25f, 1e-6f);
    assert_float_equal(h.v, 0.25f, 1e-6f);
    assert_int_equal(h.triangle, 0);
    assert_int_equal(h.object, 0);

    /* From below, up: the back triangle first (backfaces are hit too). */
    r = ray(rl_v3(1.0f, 0.5f, -4.0f), rl_v3(0, 0, 2), 0.0f, INFINITY);
    assert_true(rl_accel_intersect(a, &r, &h));
    assert_float_equal(h.t, 1.5f, 1e-6f);
    assert_float_equal(h.u, 0.5f, 1e-6f);
    assert_float_equal(h.v, 0.125f, 1e-6f);
    assert_int_equal(h.triangle, 1);
    assert_int_equal(h.object, 1);

    rl_accel_release(a);
    rl_scene_release(s);
}

static void test_embree_misses_beside_behind_and_beyond_t_max(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = two_triangles();
    rl_accel *a = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });
    const rl_ray misses[] = {
        ray(rl_v3(1.9f, 3.9f, 3.0f), rl_v3(0, 0, -1), 0.0f, INFINITY),  /* beside the hypotenuse */
        ray(rl_v3(0.5f, 1.0f, 3.0f), rl_v3(0, 0, 1), 0.0f, INFINITY),   /* pointing away */
        ray(rl_v3(0.5f, 1.0f, 3.0f), rl_v3(0, 0, -1), 0.0f, 2.5f),      /* ends before z = 0 */
        ray(rl_v3(0.5f, 1.0f, 3.0f), rl_v3(0, 0, -1), 4.5f, INFINITY),  /* starts past both */
        ray(rl_v3(0.5f, 1.0f, 3.0f), rl_v3(1, 0, 0), 0.0f, INFINITY),   /* parallel */
    };
    for (size_t i = 0; i < sizeof misses / sizeof misses[0]; ++i) {
        rl_ray r = misses[i];
        rl_hit h = { .t = 123.0f };
        if (rl_accel_intersect(a, &r, &h))
            fail_msg("ray %zu hit triangle %u at t = %g", i, h.triangle, (double)h.t);
        assert_int_equal(h.triangle, RL_ID_NONE);
        assert_int_equal(h.object, RL_ID_NONE);
        assert_memory_equal(&r, &misses[i], sizeof r);   /* ray left as it was */
        assert_false(rl_accel_occluded(a, &misses[i]));
    }
    rl_accel_release(a);
    rl_scene_release(s);
}

static void test_embree_occluded_sees_any_hit_inside_the_segment(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = two_triangles();
    rl_accel *a = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });
    rl_vec3 o = rl_v3(0.5f, 1.0f, 3.0f), down = rl_v3(0, 0, -1);
    assert_true(rl_accel_occluded(a, &(rl_ray){ .o = o, .d = down, .t_max = INFINITY }));
    assert_true(rl_accel_occluded(a, &(rl_ray){ .o = o, .d = down, .t_min = 3.5f, .t_max = 5.0f }));
    assert_false(rl_accel_occluded(a, &(rl_ray){ .o = o, .d = down, .t_min = 0.0f, .t_max = 2.9f }));
    assert_false(rl_accel_occluded(a, &(rl_ray){ .o = o, .d = down, .t_min = 3.1f, .t_max = 3.9f }));
    rl_accel_release(a);
    rl_scene_release(s);
}

static void test_embree_invalid_rays_miss_through_the_generic_layer(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = two_triangles();
    rl_accel *a = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });
    rl_vec3 o = rl_v3(0.5f, 1.0f, 3.0f), down = rl_v3(0, 0, -1);
    const rl_ray bad[] = {
        ray(rl_v3(NAN, 1.0f, 3.0f), down, 0.0f, INFINITY),
        ray(rl_v3(0.5f, INFINITY, 3.0f), down, 0.0f, INFINITY),
        ray(o, rl_v3(0, NAN, -1), 0.0f, INFINITY),
        ray(o, rl_v3(0, 0, -INFINITY), 0.0f, INFINITY),
        ray(o, rl_v3(0, 0, 0), 0.0f, INFINITY),
        ray(o, down, 5.0f, 1.0f),                  /* t_min > t_max */
        ray(o, down, NAN, INFINITY),
        ray(o, down, 0.0f, NAN),
        ray(o, down, -INFINITY, INFINITY),
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rl_ray r = bad[i];
        rl_hit h;
        if (rl_accel_intersect(a, &r, &h))
            fail_msg("invalid ray %zu hit triangle %u", i, h.triangle);
        assert_int_equal(h.triangle, RL_ID_NONE);
        assert_memory_equal(&r, &bad[i], sizeof r);
        if (rl_accel_occluded(a, &bad[i]))
            fail_msg("invalid ray %zu is occluded", i);
    }
    rl_accel_release(a);
    rl_scene_release(s);
}

/* Embree only takes segments in [0, inf]; the adapter shifts the origin. */
static void test_embree_honours_a_negative_t_min(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = two_triangles();
    rl_accel *a = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });
    /* Origin between the planes, looking down, segment reaching back. */
    rl_ray r = ray(rl_v3(0.5f, 1.0f, -0.5f), rl_v3(0, 0, -1), -2.0f, INFINITY);
    rl_hit h;
    assert_true(rl_accel_intersect(a, &r, &h));
    assert_int_equal(h.triangle, 0);            /* z = 0 lies at t = -0.5 */
    assert_float_equal(h.t, -0.5f, 1e-6f);
    assert_float_equal(h.u, 0.25f, 1e-6f);
    r = ray(rl_v3(0.5f, 1.0f, -0.5f), rl_v3(0, 0, -1), -0.25f, INFINITY);
    assert_true(rl_accel_intersect(a, &r, &h));
    assert_int_equal(h.triangle, 1);            /* z = -1 at t = +0.5 */
    assert_float_equal(h.t, 0.5f, 1e-6f);
    assert_true(rl_accel_occluded(a, &(rl_ray){ .o = rl_v3(0.5f, 1.0f, -0.5f),
                                                .d = rl_v3(0, 0, -1), .t_min = -1.0f, .t_max = 0.0f }));
    assert_false(rl_accel_occluded(a, &(rl_ray){ .o = rl_v3(0.5f, 1.0f, -0.5f),
                                                 .d = rl_v3(0, 0, -1), .t_min = -0.4f, .t_max = 0.4f }));
    rl_accel_release(a);
    rl_scene_release(s);
}

static void test_embree_reports_kind_size_memory_and_build_time(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell-teapot", "triangles=2000", &s), RL_OK);
    rl_accel *a = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });
    rl_accel_stats st;
    rl_accel_get_stats(a, &st);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(st.kind, RL_ACCEL_EMBREE);
    assert_int_equal(st.num_triangles, d->num_triangles);
    assert_true(st.build_ms >= 0.0 && st.build_ms < 60000.0);
    /* At least Embree's own copy of the vertex and index buffers. */
    size_t buffers = (size_t)d->num_vertices * 12 + (size_t)d->num_triangles * 12;
    if (st.memory_bytes < buffers)
        fail_msg("memory_bytes %zu < buffer bytes %zu", st.memory_bytes, buffers);
    assert_true(st.memory_bytes < 64 * buffers + (1u << 24));   /* and nothing absurd */
    assert_float_equal(st.bytes_per_triangle, (double)st.memory_bytes / d->num_triangles, 1e-9);
    assert_string_equal(rl_accel_kind_name(RL_ACCEL_EMBREE), "embree");
    assert_ptr_equal(rl_accel_scene(a), s);
    rl_accel_release(a);
    rl_scene_release(s);
}

/* desc.threads = 1 goes to Embree as "threads=1"; the structure answers the
 * same (closest hits are unique up to ties, and the pixel-centre rays of
 * this small view meet no shared edge of the teapot or the box). */
static void test_embree_with_one_build_thread_answers_the_same(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell-teapot", "triangles=2000", &s), RL_OK);
    rl_accel *all = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE });
    rl_accel *one = build(s, (rl_accel_desc){ .kind = RL_ACCEL_EMBREE, .threads = 1 });
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = 40;
    cam.height = 30;
    rl_camera_frame f = rl_camera_frame_make(&cam);
    int hits = 0;
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            rl_ray r1 = rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f), r2 = r1;
            rl_hit h1, h2;
            bool b1 = rl_accel_intersect(all, &r1, &h1), b2 = rl_accel_intersect(one, &r2, &h2);
            assert_int_equal(b1, b2);
            if (b1) {
                ++hits;
                assert_int_equal(h1.triangle, h2.triangle);
                assert_float_equal(h1.t, h2.t, 1e-6f * h1.t);
            }
        }
    assert_true(hits > cam.width * cam.height / 2);   /* the box fills most of the view */
    rl_accel_release(all);
    rl_accel_release(one);
    rl_scene_release(s);
}

typedef struct progress_log { int calls; double last; bool in_range; } progress_log;

static bool cancel_at_once(void *user, double done)
{
    progress_log *p = user;
    p->calls++;
    if (!(done >= 0.0 && done <= 1.0))
        p->in_range = false;
    p->last = done;
    return false;
}

static bool keep_going(void *user, double done)
{
    progress_log *p = user;
    p->calls++;
    if (!(done >= 0.0 && done <= 1.0))
        p->in_range = false;
    p->last = done;
    return true;
}

static void test_embree_build_can_be_cancelled_by_progress(void **state)
{
    (void)state;
    skip_without_embree();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell-teapot", "triangles=20000", &s), RL_OK);

    progress_log log = { .in_range = true };
    rl_accel *a = NULL;
    rl_accel_desc desc = { .kind = RL_ACCEL_EMBREE, .progress = cancel_at_once, .user = &log };
    assert_int_equal(rl_accel_create(s, &desc, &a), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_accel_commit(a), RL_ERR_CANCELLED);
    assert_int_equal(rl_last_status(), RL_ERR_CANCELLED);
    assert_true(log.calls >= 1);
    assert_true(log.in_range);
    /* Not committed: queries miss instead of touching a half-built scene. */
    rl_ray r = ray(rl_v3(0.3f, 0.3f, 0.3f), rl_v3(0, -1, 0), 0.0f, INFINITY);
    rl_hit h;
    assert_false(rl_accel_intersect(a, &r, &h));
    rl_accel_release(a);
    rl_clear_error();

    progress_log ok = { .in_range = true };
    desc = (rl_accel_desc){ .kind = RL_ACCEL_EMBREE, .progress = keep_going, .user = &ok };
    a = build(s, desc);
    assert_true(ok.calls >= 1);
    assert_true(ok.in_range);
    r = ray(rl_v3(0.3f, 0.3f, 0.3f), rl_v3(0, -1, 0), 0.0f, INFINITY);
    assert_true(rl_accel_intersect(a, &r, &h));   /* the floor or the teapot */
    rl_accel_release(a);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_embree_hits_a_known_triangle_with_exact_t_u_v_and_ids),
        cmocka_unit_test(test_embree_misses_beside_behind_and_beyond_t_max),
        cmocka_unit_test(test_embree_occluded_sees_any_hit_inside_the_segment),
        cmocka_unit_test(test_embree_invalid_rays_miss_through_the_generic_layer),
        cmocka_unit_test(test_embree_honours_a_negative_t_min),
        cmocka_unit_test(test_embree_reports_kind_size_memory_and_build_time),
        cmocka_unit_test(test_embree_with_one_build_thread_answers_the_same),
        cmocka_unit_test(test_embree_build_can_be_cancelled_by_progress),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
