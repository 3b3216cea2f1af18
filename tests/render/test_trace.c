/* test_trace.c: the Whitted tracer (rl_trace.h) against closed forms on
 * scenes built in code: Lambert under a point light on a sphere, a mirror
 * that must show what a direct ray sees, the Snell shift through a glass
 * slab, exact ray counts and trees, and bad rays. Brute-force accel: the
 * tests trace a handful of rays, and it is the reference. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_accel.h"
#include "rl/rl_scene.h"
#include "rl/rl_trace.h"

/* A committed scene, its accel and a tracer, released together. */
typedef struct fixture {
    rl_scene *scene;
    rl_accel *accel;
    rl_tracer *tracer;
} fixture;

static rl_material matte(rl_vec3 kd)
{
    rl_material m = rl_material_default();
    m.diffuse = kd;
    m.specular = rl_v3s(0.0f);
    return m;
}

static uint32_t add_material(rl_scene *s, rl_material m)
{
    uint32_t id;
    assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
    return id;
}

static void add_instance(rl_scene *s, uint32_t mesh)
{
    uint32_t node;
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "object", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

/* Parallelogram a, b, c, d (counter-clockwise seen from its front) as one
 * object; its geometric normal is cross(b - a, c - a). */
static void add_quad(rl_scene *s, rl_vec3 a, rl_vec3 b, rl_vec3 c, rl_vec3 d, uint32_t material)
{
    rl_vec3 p[4] = { a, b, c, d };
    rl_vec3 n = rl_normalize(rl_cross(rl_sub(b, a), rl_sub(c, a)));
    rl_vec3 normals[4] = { n, n, n, n };
    uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc m = { .name = "quad", .num_vertices = 4, .positions = p, .normals = normals,
                       .num_triangles = 2, .indices = idx, .material = material };
    uint32_t mesh;
    assert_int_equal(rl_scene_add_mesh(s, &m, &mesh), RL_OK);
    add_instance(s, mesh);
}

static void add_point_light(rl_scene *s, rl_vec3 pos, float intensity)
{
    rl_light l = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = intensity, .position = pos };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
}

static void finish(fixture *f, const rl_tracer_desc *desc)
{
    assert_int_equal(rl_scene_commit(f->scene), RL_OK);
    assert_int_equal(rl_accel_create(f->scene, &(rl_accel_desc){ .kind = RL_ACCEL_BRUTE }, &f->accel), RL_OK);
    assert_int_equal(rl_accel_commit(f->accel), RL_OK);
    assert_int_equal(rl_tracer_create(f->accel, desc, &f->tracer), RL_OK);
}

static void release(fixture *f)
{
    rl_tracer_release(f->tracer);
    rl_accel_release(f->accel);
    rl_scene_release(f->scene);
}

static rl_ray ray_from_to(rl_vec3 from, rl_vec3 to)
{
    rl_ray r = { from, 0.0f, rl_normalize(rl_sub(to, from)), INFINITY };
    return r;
}

static void assert_close(float got, float want, float rel)
{
    if (!(fabsf(got - want) <= rel * fabsf(want)))
        fail_msg("got %.7g, want %.7g (relative tolerance %g)", (double)got, (double)want, (double)rel);
}

static void assert_color_close(rl_vec3 got, rl_vec3 want, float rel)
{
    assert_close(got.x, want.x, rel);
    assert_close(got.y, want.y, rel);
    assert_close(got.z, want.z, rel);
}

/* (1) Lambert: L = k_d I cos(theta) / d^2 at the actual hit point, with the
 * sphere's analytic normal. */
static void test_diffuse_sphere_matches_lambert_under_a_point_light(void **state)
{
    (void)state;
    fixture f = { 0 };
    assert_int_equal(rl_scene_create(&f.scene), RL_OK);
    rl_vec3 kd = rl_v3(0.8f, 0.5f, 0.25f);
    uint32_t mat = add_material(f.scene, matte(kd));
    uint32_t mesh;
    assert_int_equal(rl_scene_add_generated(f.scene, "sphere", "radius=1,segments=192,rings=96", mat, &mesh),
                     RL_OK);
    add_instance(f.scene, mesh);
    const rl_vec3 light = rl_v3(0.0f, 4.0f, 0.0f);
    const float intensity = 10.0f;
    add_point_light(f.scene, light, intensity);
    finish(&f, &(rl_tracer_desc){ .ambient = -1.0f });

    const float angles_deg[] = { 0.0f, 20.0f, 45.0f, 70.0f };
    for (size_t i = 0; i < sizeof angles_deg / sizeof angles_deg[0]; ++i) {
        float a = rl_radians(angles_deg[i]);
        rl_vec3 on_sphere = rl_v3(sinf(a) * 0.8f, cosf(a), sinf(a) * 0.6f);
        rl_ray ray = ray_from_to(rl_scale(on_sphere, 3.0f), rl_v3s(0.0f));
        rl_trace_result res;
        rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, i, &res, NULL);
        assert_int_not_equal(res.hit.triangle, RL_ID_NONE);
        rl_vec3 p = rl_ray_at(&ray, res.hit.t);
        rl_vec3 n = rl_normalize(p);
        rl_vec3 to_light = rl_sub(light, p);
        float d2 = rl_length2(to_light);
        float cos_theta = rl_dot(n, rl_normalize(to_light));
        rl_vec3 want = rl_scale(kd, intensity * cos_theta / d2);
        assert_color_close(res.color, want, 0.01f);
        assert_int_equal(res.rays[RL_RAY_PRIMARY], 1);
        assert_int_equal(res.rays[RL_RAY_SHADOW], 1);
    }
    /* The point nearest the light: cos = 1, d = 4 - 1. */
    rl_ray top = ray_from_to(rl_v3(0.0f, 3.0f, 0.0f), rl_v3s(0.0f));
    rl_trace_result res;
    rl_tracer_trace(f.tracer, &top, RL_RAY_PRIMARY, 99, &res, NULL);
    assert_color_close(res.color, rl_scale(kd, intensity / 9.0f), 0.01f);
    release(&f);
}

/* Mirror in z = 0 (k_r = 1, k_d = 0) facing an emissive quad at x = 2 and a
 * lit diffuse quad at x = -2. */
static void mirror_scene(fixture *f, rl_vec3 emission, rl_vec3 *diffuse_kd)
{
    assert_int_equal(rl_scene_create(&f->scene), RL_OK);
    rl_material mirror = matte(rl_v3s(0.0f));
    mirror.reflectivity = 1.0f;
    rl_material glow = matte(rl_v3s(0.0f));
    glow.emission = emission;
    *diffuse_kd = rl_v3(0.3f, 0.6f, 0.9f);
    uint32_t m_mirror = add_material(f->scene, mirror), m_glow = add_material(f->scene, glow);
    uint32_t m_diffuse = add_material(f->scene, matte(*diffuse_kd));
    add_quad(f->scene, rl_v3(-1.5f, -1, 0), rl_v3(1.5f, -1, 0), rl_v3(1.5f, 1, 0), rl_v3(-1.5f, 1, 0), m_mirror);
    add_quad(f->scene, rl_v3(2, -1, 0), rl_v3(2, -1, 4), rl_v3(2, 1, 4), rl_v3(2, 1, 0), m_glow);
    add_quad(f->scene, rl_v3(-2, -1, 0), rl_v3(-2, 1, 0), rl_v3(-2, 1, 4), rl_v3(-2, -1, 4), m_diffuse);
    add_point_light(f->scene, rl_v3(0.0f, 0.5f, 3.0f), 5.0f);
}

/* (2) */
static void test_mirror_shows_what_a_direct_ray_to_the_mirrored_point_sees(void **state)
{
    (void)state;
    fixture f = { 0 };
    rl_vec3 emission = rl_v3(0.2f, 0.5f, 0.8f), kd;
    mirror_scene(&f, emission, &kd);
    finish(&f, &(rl_tracer_desc){ .ambient = -1.0f });

    /* Via the mirror at the origin onto the emitter at (2, 0, 2). */
    rl_trace_result res, direct;
    rl_ray ray = ray_from_to(rl_v3(-1.0f, 0.0f, 1.0f), rl_v3s(0.0f));
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 1, &res, NULL);
    assert_int_equal(res.hit.object, 0);
    assert_color_close(res.color, emission, 1e-6f);
    assert_int_equal(res.rays[RL_RAY_REFLECTION], 1);

    /* Via the mirror at (-0.5, 0.2, 0) onto the lit diffuse wall at
     * (-2, 0.5, 1.5): the incoming ray comes from the target's mirror image;
     * compare with the wall seen directly from elsewhere. */
    rl_vec3 at = rl_v3(-0.5f, 0.2f, 0.0f), target = rl_v3(-2.0f, 0.5f, 1.5f);
    rl_vec3 mirrored_target = rl_v3(target.x, target.y, -target.z);
    ray = ray_from_to(rl_add(at, rl_scale(rl_normalize(rl_sub(at, mirrored_target)), 1.0f)), at);
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 2, &res, NULL);
    rl_ray look = ray_from_to(rl_v3(0.0f, 0.0f, 3.5f), target);
    rl_tracer_trace(f.tracer, &look, RL_RAY_PRIMARY, 3, &direct, NULL);
    assert_int_equal(direct.hit.object, 2);
    assert_true(direct.color.x > 0.01f);
    assert_color_close(res.color, direct.color, 2e-3f);
    release(&f);
}

/* (3) Slab z in [-1, 0], ior 1.5, k_t = 1: the ray leaves parallel to itself,
 * shifted by h (tan(theta_1) - tan(theta_2)) towards the normal. A lit
 * diffuse backdrop at z = -3 with a nearby light turns position into colour. */
static void test_glass_slab_shifts_a_ray_by_the_snell_amount(void **state)
{
    (void)state;
    fixture f = { 0 };
    assert_int_equal(rl_scene_create(&f.scene), RL_OK);
    rl_material glass = matte(rl_v3s(0.0f));
    glass.transmissivity = 1.0f;
    glass.ior = 1.5f;
    uint32_t m_glass = add_material(f.scene, glass);
    uint32_t m_back = add_material(f.scene, matte(rl_v3s(0.7f)));
    const float big = 6.0f;
    add_quad(f.scene, rl_v3(-big, -big, 0), rl_v3(big, -big, 0), rl_v3(big, big, 0), rl_v3(-big, big, 0), m_glass);
    add_quad(f.scene, rl_v3(-big, -big, -1), rl_v3(-big, big, -1), rl_v3(big, big, -1), rl_v3(big, -big, -1), m_glass);
    add_quad(f.scene, rl_v3(-big, -big, -3), rl_v3(big, -big, -3), rl_v3(big, big, -3), rl_v3(-big, big, -3), m_back);
    add_point_light(f.scene, rl_v3(1.2f, 0.0f, -2.4f), 1.0f);
    /* Refraction alone: the light behind the slab would add eq. 3.17's
     * transmitted highlight on both faces (tested on its own below). */
    finish(&f, &(rl_tracer_desc){ .ambient = -1.0f, .no_transmitted_highlight = true });

    const float theta1 = rl_radians(40.0f);
    const float theta2 = asinf(sinf(theta1) / 1.5f);
    rl_vec3 d = rl_v3(sinf(theta1), 0.0f, -cosf(theta1));
    rl_vec3 entry = rl_v3(0.0f, 0.0f, 0.0f);
    rl_ray ray = { rl_sub(entry, rl_scale(d, 2.0f)), 0.0f, d, INFINITY };
    rl_trace_result res;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 7, &res, NULL);
    assert_int_equal(res.hit.object, 0);
    assert_int_equal(res.rays[RL_RAY_REFRACTION], 2);

    /* The same direction from the exit point (entry.x + h tan(theta_2)). */
    rl_vec3 exit_point = rl_v3(entry.x + tanf(theta2), 0.0f, -1.0f);
    rl_ray out_ray = { rl_add(exit_point, rl_scale(d, 0.01f)), 0.0f, d, INFINITY };
    rl_trace_result want;
    rl_tracer_trace(f.tracer, &out_ray, RL_RAY_PRIMARY, 8, &want, NULL);
    assert_int_equal(want.hit.object, 2);
    assert_color_close(res.color, want.color, 2e-3f);

    /* Sensitivity: no bending (exit at tan(theta_1)) looks clearly different. */
    rl_ray straight = { rl_add(rl_v3(tanf(theta1), 0.0f, -1.0f), rl_scale(d, 0.01f)), 0.0f, d, INFINITY };
    rl_trace_result wrong;
    rl_tracer_trace(f.tracer, &straight, RL_RAY_PRIMARY, 9, &wrong, NULL);
    assert_true(fabsf(wrong.color.x - res.color.x) > 0.05f * res.color.x);
    release(&f);
}

/* Mirror A in z = 0 and a half-mirror B in z = 2 facing it, two lights
 * between them: the primary ray at A bounces A -> B -> A. */
static void facing_mirrors(fixture *f, int max_depth, float kr_b)
{
    assert_int_equal(rl_scene_create(&f->scene), RL_OK);
    rl_material a = matte(rl_v3s(0.0f));
    a.reflectivity = 1.0f;
    rl_material b = matte(rl_v3s(0.5f));
    b.reflectivity = kr_b;
    uint32_t m_a = add_material(f->scene, a), m_b = add_material(f->scene, b);
    add_quad(f->scene, rl_v3(-2, -2, 0), rl_v3(2, -2, 0), rl_v3(2, 2, 0), rl_v3(-2, 2, 0), m_a);
    add_quad(f->scene, rl_v3(-2, -2, 2), rl_v3(-2, 2, 2), rl_v3(2, 2, 2), rl_v3(2, -2, 2), m_b);
    add_point_light(f->scene, rl_v3(1.0f, 1.0f, 1.0f), 1.0f);
    add_point_light(f->scene, rl_v3(-1.0f, -1.0f, 1.0f), 1.0f);
    finish(f, &(rl_tracer_desc){ .max_depth = max_depth });
}

static void assert_node(const rl_ray_tree_node *n, rl_ray_type type, int depth, uint32_t object, uint32_t light)
{
    assert_int_equal(n->type, type);
    assert_int_equal(n->depth, depth);
    assert_int_equal(n->object, object);
    assert_int_equal(n->light, light);
}

/* (4) */
static void test_ray_counts_and_tree_are_exact_for_two_facing_mirrors(void **state)
{
    (void)state;
    fixture f = { 0 };
    facing_mirrors(&f, 2, 0.5f);
    rl_ray ray = ray_from_to(rl_v3(0.1f, 0.2f, 1.0f), rl_v3(0.1f, 0.2f, 0.0f));
    rl_trace_result res;
    rl_ray_tree tree;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 0, &res, &tree);
    assert_int_equal(res.rays[RL_RAY_PRIMARY], 1);
    assert_int_equal(res.rays[RL_RAY_SHADOW], 6);       /* 2 lights at each of 3 hits */
    assert_int_equal(res.rays[RL_RAY_REFLECTION], 2);   /* depth 1 and 2 */
    assert_int_equal(res.rays[RL_RAY_REFRACTION], 0);
    assert_int_equal(res.rays[RL_RAY_DIFFUSE], 0);

    assert_int_equal(tree.count, 9);
    assert_false(tree.truncated);
    assert_node(&tree.nodes[0], RL_RAY_PRIMARY, 0, 0, RL_ID_NONE);
    assert_node(&tree.nodes[1], RL_RAY_SHADOW, 1, RL_ID_NONE, 0);
    assert_node(&tree.nodes[2], RL_RAY_SHADOW, 1, RL_ID_NONE, 1);
    assert_node(&tree.nodes[3], RL_RAY_REFLECTION, 1, 1, RL_ID_NONE);
    assert_node(&tree.nodes[4], RL_RAY_SHADOW, 2, RL_ID_NONE, 0);
    assert_node(&tree.nodes[5], RL_RAY_SHADOW, 2, RL_ID_NONE, 1);
    assert_node(&tree.nodes[6], RL_RAY_REFLECTION, 2, 0, RL_ID_NONE);
    assert_node(&tree.nodes[7], RL_RAY_SHADOW, 3, RL_ID_NONE, 0);
    assert_node(&tree.nodes[8], RL_RAY_SHADOW, 3, RL_ID_NONE, 1);

    /* Without a tree the counts are the same (any-hit feelers). */
    rl_trace_result plain;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 0, &plain, NULL);
    assert_memory_equal(plain.rays, res.rays, sizeof res.rays);
    assert_memory_equal(&plain.color, &res.color, sizeof res.color);
    release(&f);
}

static void test_tiny_path_weight_stops_the_recursion(void **state)
{
    (void)state;
    fixture f = { 0 };
    facing_mirrors(&f, 10, 1e-4f);   /* A -> B, then 1e-4 < 1e-3: stop */
    rl_ray ray = ray_from_to(rl_v3(0.1f, 0.2f, 1.0f), rl_v3(0.1f, 0.2f, 0.0f));
    rl_trace_result res;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 0, &res, NULL);
    assert_int_equal(res.rays[RL_RAY_REFLECTION], 1);
    release(&f);
}

static void test_tree_of_a_deep_mirror_corridor_is_truncated(void **state)
{
    (void)state;
    fixture f = { 0 };
    facing_mirrors(&f, 64, 1.0f);
    rl_ray ray = ray_from_to(rl_v3(0.1f, 0.2f, 1.0f), rl_v3(0.1f, 0.2f, 0.0f));
    rl_trace_result res;
    rl_ray_tree tree;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 0, &res, &tree);
    assert_int_equal(res.rays[RL_RAY_REFLECTION], 64);
    assert_int_equal(res.rays[RL_RAY_SHADOW], 2 * 65);
    assert_int_equal(tree.count, RL_RAY_TREE_MAX);
    assert_true(tree.truncated);
    rl_ray_tree shallow;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 0, &res, &shallow);
    assert_true(rl_ray_tree_equal(&tree, &shallow));
    shallow.truncated = false;
    assert_false(rl_ray_tree_equal(&tree, &shallow));
    release(&f);
}

/* Floor y = 0 (object 0), a small occluder at y = 1 over x in [-0.5, 0.5]
 * (object 1), a point light at y = 2. */
static void shadow_scene(fixture *f)
{
    assert_int_equal(rl_scene_create(&f->scene), RL_OK);
    uint32_t m = add_material(f->scene, matte(rl_v3s(0.6f)));
    add_quad(f->scene, rl_v3(-4, 0, -4), rl_v3(-4, 0, 4), rl_v3(4, 0, 4), rl_v3(4, 0, -4), m);
    add_quad(f->scene, rl_v3(-0.5f, 1, -0.5f), rl_v3(-0.5f, 1, 0.5f), rl_v3(0.5f, 1, 0.5f), rl_v3(0.5f, 1, -0.5f), m);
    add_point_light(f->scene, rl_v3(0.0f, 2.0f, 0.0f), 4.0f);
    finish(f, NULL);
}

/* (5) */
static void test_trees_are_equal_exactly_when_surfaces_and_shadows_agree(void **state)
{
    (void)state;
    fixture f = { 0 };
    shadow_scene(&f);
    rl_vec3 eye = rl_v3(0.0f, 3.0f, 5.0f);
    rl_ray lit_a = ray_from_to(eye, rl_v3(-3.0f, 0.0f, 0.0f));
    rl_ray lit_b = ray_from_to(eye, rl_v3(-2.5f, 0.0f, 0.5f));
    rl_ray shadowed = ray_from_to(eye, rl_v3(0.0f, 0.0f, -0.2f));
    rl_trace_result ra, rb, rs;
    rl_ray_tree ta, tb, ts;
    rl_tracer_trace(f.tracer, &lit_a, RL_RAY_PRIMARY, 1, &ra, &ta);
    rl_tracer_trace(f.tracer, &lit_b, RL_RAY_PRIMARY, 2, &rb, &tb);
    rl_tracer_trace(f.tracer, &shadowed, RL_RAY_PRIMARY, 3, &rs, &ts);
    assert_true(rl_ray_tree_equal(&ta, &tb));
    assert_false(rl_ray_tree_equal(&ta, &ts));
    assert_int_equal(ts.count, 2);
    assert_node(&ts.nodes[0], RL_RAY_PRIMARY, 0, 0, RL_ID_NONE);
    assert_node(&ts.nodes[1], RL_RAY_SHADOW, 1, 1, 0);            /* blocked by object 1 */
    assert_node(&ta.nodes[1], RL_RAY_SHADOW, 1, RL_ID_NONE, 0);
    /* In the shadow only the ambient term remains. */
    assert_color_close(rs.color, rl_v3s(0.6f * 0.05f), 1e-5f);
    assert_true(ra.color.x > rs.color.x * 2.0f);
    release(&f);
}

static void test_shade_of_a_known_hit_equals_tracing_the_ray(void **state)
{
    (void)state;
    fixture f = { 0 };
    shadow_scene(&f);
    const rl_vec3 eye = rl_v3(0.0f, 3.0f, 5.0f);
    const rl_vec3 targets[2] = { rl_v3(-3.0f, 0.0f, 0.0f), rl_v3(0.1f, 0.0f, 0.1f) };
    for (int i = 0; i < 2; ++i) {
        rl_ray ray = ray_from_to(eye, targets[i]);
        rl_trace_result traced, shaded;
        rl_ray_tree t_tree, s_tree;
        rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 5, &traced, &t_tree);
        assert_int_not_equal(traced.hit.triangle, RL_ID_NONE);
        rl_tracer_shade(f.tracer, &ray, &traced.hit, RL_RAY_PRIMARY, 5, &shaded, &s_tree);
        assert_memory_equal(&shaded.color, &traced.color, sizeof traced.color);
        assert_memory_equal(shaded.rays, traced.rays, sizeof traced.rays);
        assert_true(rl_ray_tree_equal(&s_tree, &t_tree));
    }
    /* A hit naming no triangle shades as a miss but still counts its ray. */
    rl_ray ray = ray_from_to(eye, targets[0]);
    rl_hit none = { 1.0f, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
    rl_trace_result res;
    rl_ray_tree tree;
    rl_tracer_shade(f.tracer, &ray, &none, RL_RAY_REFLECTION, 0, &res, &tree);
    assert_int_equal(res.rays[RL_RAY_REFLECTION], 1);
    assert_int_equal(tree.count, 1);
    assert_node(&tree.nodes[0], RL_RAY_REFLECTION, 0, RL_ID_NONE, RL_ID_NONE);
    release(&f);
}

static void test_no_shadows_traces_no_feelers_and_lights_everything(void **state)
{
    (void)state;
    fixture f = { 0 };
    shadow_scene(&f);
    rl_tracer *open = NULL;
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .no_shadows = true }, &open), RL_OK);
    rl_ray ray = ray_from_to(rl_v3(0.0f, 3.0f, 5.0f), rl_v3(0.0f, 0.0f, -0.2f));
    rl_trace_result res;
    rl_tracer_trace(open, &ray, RL_RAY_PRIMARY, 0, &res, NULL);
    assert_int_equal(res.rays[RL_RAY_SHADOW], 0);
    /* Lambert straight below the light: 0.6 * 4 * cos / d^2 + ambient. */
    rl_vec3 p = rl_ray_at(&ray, res.hit.t);
    rl_vec3 to_light = rl_sub(rl_v3(0.0f, 2.0f, 0.0f), p);
    float want = 0.6f * 4.0f * rl_normalize(to_light).y / rl_length2(to_light) + 0.6f * 0.05f;
    assert_close(res.color.y, want, 1e-4f);
    rl_tracer_release(open);
    release(&f);
}

/* (6) */
static void test_nan_direction_sees_the_background_and_counts_one_ray(void **state)
{
    (void)state;
    fixture f = { 0 };
    assert_int_equal(rl_scene_create(&f.scene), RL_OK);
    uint32_t m = add_material(f.scene, matte(rl_v3s(0.5f)));
    add_quad(f.scene, rl_v3(-1, -1, 0), rl_v3(1, -1, 0), rl_v3(1, 1, 0), rl_v3(-1, 1, 0), m);
    add_point_light(f.scene, rl_v3(0.0f, 0.0f, 2.0f), 1.0f);
    rl_vec3 bg = rl_v3(0.1f, 0.2f, 0.3f);
    finish(&f, &(rl_tracer_desc){ .background = bg });
    rl_ray ray = { rl_v3(0.0f, 0.0f, 1.0f), 0.0f, rl_v3(NAN, 0.0f, -1.0f), INFINITY };
    rl_trace_result res;
    rl_ray_tree tree;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 0, &res, &tree);
    assert_memory_equal(&res.color, &bg, sizeof bg);
    assert_int_equal(res.rays[RL_RAY_PRIMARY], 1);
    assert_int_equal(res.rays[RL_RAY_SHADOW] + res.rays[RL_RAY_REFLECTION] + res.rays[RL_RAY_REFRACTION], 0);
    assert_int_equal(res.hit.triangle, RL_ID_NONE);
    assert_int_equal(tree.count, 1);
    assert_node(&tree.nodes[0], RL_RAY_PRIMARY, 0, RL_ID_NONE, RL_ID_NONE);
    /* The same for shade() with a NaN direction. */
    rl_hit hit = { 1.0f, 0.2f, 0.2f, 0, 0 };
    rl_tracer_shade(f.tracer, &ray, &hit, RL_RAY_PRIMARY, 0, &res, NULL);
    assert_memory_equal(&res.color, &bg, sizeof bg);
    release(&f);
}

static void test_bad_tracer_descs_are_refused(void **state)
{
    (void)state;
    fixture f = { 0 };
    assert_int_equal(rl_scene_create(&f.scene), RL_OK);
    uint32_t m = add_material(f.scene, matte(rl_v3s(0.5f)));
    add_quad(f.scene, rl_v3(-1, -1, 0), rl_v3(1, -1, 0), rl_v3(1, 1, 0), rl_v3(-1, 1, 0), m);
    finish(&f, NULL);
    rl_tracer *t = NULL;
    assert_int_equal(rl_tracer_create(NULL, NULL, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_tracer_create(f.accel, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .max_depth = 65 }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .area_samples = 33 }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .area_samples = -1 }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .ambient = NAN }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .background = rl_v3(-1, 0, 0) }, &t),
                     RL_ERR_INVALID_ARG);
    assert_null(t);
    assert_false(rl_ray_tree_equal(&(rl_ray_tree){ .count = 0 }, &(rl_ray_tree){ .count = 1 }));
    release(&f);
}

/* A quad light: one node per jittered feeler, deterministic per sample_id. */
static void test_quad_light_traces_n_by_n_feelers_deterministically(void **state)
{
    (void)state;
    fixture f = { 0 };
    assert_int_equal(rl_scene_create(&f.scene), RL_OK);
    uint32_t m = add_material(f.scene, matte(rl_v3s(0.5f)));
    add_quad(f.scene, rl_v3(-4, 0, -4), rl_v3(-4, 0, 4), rl_v3(4, 0, 4), rl_v3(4, 0, -4), m);
    rl_light quad = { .type = RL_LIGHT_QUAD, .color = rl_v3s(1.0f), .intensity = 2.0f,
                      .position = rl_v3(-0.5f, 2.0f, -0.5f), .edge_u = rl_v3(1, 0, 0), .edge_v = rl_v3(0, 0, 1) };
    assert_int_equal(rl_scene_add_light(f.scene, &quad), RL_OK);   /* cross(u, v) = -y: down */
    finish(&f, &(rl_tracer_desc){ .area_samples = 3, .ambient = -1.0f });
    rl_ray ray = ray_from_to(rl_v3(0.0f, 5.0f, 0.5f), rl_v3(0.0f, 0.0f, 0.0f));
    rl_trace_result a, b;
    rl_ray_tree tree;
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 42, &a, &tree);
    rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, 42, &b, NULL);
    assert_int_equal(a.rays[RL_RAY_SHADOW], 9);
    assert_int_equal(tree.count, 10);
    assert_node(&tree.nodes[9], RL_RAY_SHADOW, 1, RL_ID_NONE, 0);
    assert_memory_equal(&a.color, &b.color, sizeof a.color);
    /* Irradiance of the unit square at height h = 2 straight above:
     * E = L * integral of h^2 / (h^2 + x^2 + z^2)^2 (both cosines times
     * 1/d^2), by the midpoint rule. */
    double integral = 0.0;
    const int steps = 200;
    for (int i = 0; i < steps; ++i)
        for (int j = 0; j < steps; ++j) {
            double x = -0.5 + (i + 0.5) / steps, z = -0.5 + (j + 0.5) / steps, r2 = 4.0 + x * x + z * z;
            integral += 4.0 / (r2 * r2) / ((double)steps * steps);
        }
    assert_close(a.color.x, (float)(0.5 * 2.0 * integral), 0.02f);
    release(&f);
}

/* Ullmann 2003, eq. 3.17: a light behind a transmissive pane adds
 * k_t cos^p φ_t, φ_t between the light's transmitted direction and the
 * view direction. With ior 1 the light goes on straight: at p on the pane
 * z = 0, seen from C = (0, 0, 2), lit from L = (0, 0, -1) behind it,
 *     L_o = k_t I / |p - L|^2 * max(0, dot(norm(p - L), norm(C - p)))^p
 * (here k_t = 0.5, I = 3, p = the Phong exponent 4).
 * No diffuse, specular, reflection or ambient, a black background: that is
 * the whole radiance. Off: nothing. Blocked: nothing. */
static rl_scene *pane_scene(float ior, bool blocker)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material glass = matte(rl_v3s(0.0f));
    glass.transmissivity = 0.5f;
    glass.shininess = 4.0f;
    glass.ior = ior;
    uint32_t m = add_material(s, glass);
    add_quad(s, rl_v3(-2, -2, 0), rl_v3(2, -2, 0), rl_v3(2, 2, 0), rl_v3(-2, 2, 0), m);
    if (blocker)   /* an opaque card between the pane and the light, facing it */
        add_quad(s, rl_v3(-0.2f, -0.2f, -0.5f), rl_v3(-0.2f, 0.2f, -0.5f), rl_v3(0.2f, 0.2f, -0.5f),
                 rl_v3(0.2f, -0.2f, -0.5f), add_material(s, matte(rl_v3s(0.5f))));
    add_point_light(s, rl_v3(0, 0, -1), 3.0f);
    return s;
}

static void test_transmitted_highlight_of_a_light_behind_a_pane_is_eq_3_17(void **state)
{
    (void)state;
    const rl_vec3 eye = rl_v3(0, 0, 2), light = rl_v3(0, 0, -1);
    const rl_vec3 points[] = { { 0, 0, 0 }, { 0.3f, -0.2f, 0 }, { 0.6f, 0.4f, 0 }, { -0.9f, 0.1f, 0 } };
    for (int variant = 0; variant < 3; ++variant) {
        fixture f = { pane_scene(1.0f, variant == 2), NULL, NULL };
        rl_tracer_desc desc = { .ambient = -1.0f, .no_transmitted_highlight = variant == 1 };
        finish(&f, &desc);
        for (size_t i = 0; i < sizeof points / sizeof points[0]; ++i) {
            rl_vec3 p = points[i];
            rl_ray ray = ray_from_to(eye, p);
            rl_trace_result res;
            rl_tracer_trace(f.tracer, &ray, RL_RAY_PRIMARY, i, &res, NULL);
            rl_vec3 to_p = rl_sub(p, light);
            float c = rl_maxf(0.0f, rl_dot(rl_normalize(to_p), rl_normalize(rl_sub(eye, p))));
            /* The card, halfway to the light, blocks where |p.x|, |p.y| <= 0.4. */
            bool blocked = variant == 2 && fabsf(p.x) <= 0.4f && fabsf(p.y) <= 0.4f;
            float want = variant == 1 || blocked ? 0.0f : 0.5f * 3.0f / rl_length2(to_p) * powf(c, 4.0f);
            if (want > 0.0f)
                assert_color_close(res.color, rl_v3s(want), 1e-4f);
            else
                assert_true(res.color.x == 0.0f && res.color.y == 0.0f && res.color.z == 0.0f);
        }
        release(&f);
    }
    /* Snell: on the axis the light crosses the pane straight for any ior. */
    fixture f = { pane_scene(1.5f, false), NULL, NULL };
    finish(&f, &(rl_tracer_desc){ .ambient = -1.0f });
    rl_ray axis = ray_from_to(eye, rl_v3(0, 0, 0));
    rl_trace_result res;
    rl_tracer_trace(f.tracer, &axis, RL_RAY_PRIMARY, 0, &res, NULL);
    assert_color_close(res.color, rl_v3s(0.5f * 3.0f), 1e-4f);
    /* Off the axis the refracted light bends away from the straight line:
     * leaving glass (eta = 1.5) it leaves the normal, so at p the viewer
     * sees less of it than with ior 1. */
    rl_vec3 p = rl_v3(0.3f, 0.0f, 0.0f);
    rl_ray off = ray_from_to(eye, p);
    rl_tracer_trace(f.tracer, &off, RL_RAY_PRIMARY, 1, &res, NULL);
    float straight = 0.5f * 3.0f / rl_length2(rl_sub(p, light)) *
                     powf(rl_dot(rl_normalize(rl_sub(p, light)), rl_normalize(rl_sub(eye, p))), 4.0f);
    assert_true(res.color.x > 0.0f && res.color.x < straight);
    release(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_diffuse_sphere_matches_lambert_under_a_point_light),
        cmocka_unit_test(test_mirror_shows_what_a_direct_ray_to_the_mirrored_point_sees),
        cmocka_unit_test(test_glass_slab_shifts_a_ray_by_the_snell_amount),
        cmocka_unit_test(test_transmitted_highlight_of_a_light_behind_a_pane_is_eq_3_17),
        cmocka_unit_test(test_ray_counts_and_tree_are_exact_for_two_facing_mirrors),
        cmocka_unit_test(test_tiny_path_weight_stops_the_recursion),
        cmocka_unit_test(test_tree_of_a_deep_mirror_corridor_is_truncated),
        cmocka_unit_test(test_trees_are_equal_exactly_when_surfaces_and_shadows_agree),
        cmocka_unit_test(test_shade_of_a_known_hit_equals_tracing_the_ray),
        cmocka_unit_test(test_no_shadows_traces_no_feelers_and_lights_everything),
        cmocka_unit_test(test_nan_direction_sees_the_background_and_counts_one_ray),
        cmocka_unit_test(test_bad_tracer_descs_are_refused),
        cmocka_unit_test(test_quad_light_traces_n_by_n_feelers_deterministically),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
