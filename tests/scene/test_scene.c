/* test_scene.c: scene graph, instancing, flattening (commit), bad geometry and
 * the scene helpers. Scenes are built in code; checks are exact where the
 * arithmetic is exact (translations, mirrors) and tight otherwise. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "rl/rl.h"
#include "scene/scene_internal.h"

static int warnings;

static void count_warnings(void *user, rl_log_level level, const char *message)
{
    (void)user;
    (void)message;
    warnings += level == RL_LOG_WARN;
}

static rl_scene *new_scene(uint32_t num_materials)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    for (uint32_t i = 0; i < num_materials; ++i) {
        rl_material m = rl_material_default();
        snprintf(m.name, sizeof m.name, "m%u", i);
        m.diffuse = rl_v3((float)i / 8.0f, 0.5f, 0.5f);
        uint32_t id;
        assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
        assert_int_equal(id, i);
    }
    return s;
}

static const rl_vec3 tri_pos[3] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
static const uint32_t tri_idx[3] = { 0, 1, 2 };

static uint32_t add_triangle(rl_scene *s, uint32_t material)
{
    rl_mesh_desc d = { .name = "tri", .num_vertices = 3, .positions = tri_pos,
                       .num_triangles = 1, .indices = tri_idx, .material = material };
    uint32_t id = RL_NONE;
    assert_int_equal(rl_scene_add_mesh(s, &d, &id), RL_OK);
    return id;
}

/* Unit quad in the xy plane, two triangles facing +z. */
static uint32_t add_quad(rl_scene *s, uint32_t material)
{
    static const rl_vec3 p[4] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } };
    static const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc d = { .name = "quad", .num_vertices = 4, .positions = p,
                       .num_triangles = 2, .indices = idx, .material = material };
    uint32_t id = RL_NONE;
    assert_int_equal(rl_scene_add_mesh(s, &d, &id), RL_OK);
    return id;
}

static uint32_t add_node(rl_scene *s, uint32_t parent, const char *name, rl_mat4 t, uint32_t mesh)
{
    uint32_t id = RL_NONE;
    assert_int_equal(rl_scene_add_node(s, parent, name, &t, &id), RL_OK);
    if (mesh != RL_NONE)
        assert_int_equal(rl_scene_node_set_mesh(s, id, mesh), RL_OK);
    return id;
}

static void assert_vec3_near(rl_vec3 a, rl_vec3 b, float eps)
{
    assert_true(fabsf(a.x - b.x) <= eps);
    assert_true(fabsf(a.y - b.y) <= eps);
    assert_true(fabsf(a.z - b.z) <= eps);
}

static void test_scene_uids_are_never_reused(void **state)
{
    (void)state;
    rl_scene *a = new_scene(0);
    uint64_t first = rl_scene_uid(a);
    assert_true(first != 0);
    rl_scene_release(a);
    /* A new scene may get the released one's address, never its uid. */
    rl_scene *b = new_scene(0);
    rl_scene *c = new_scene(0);
    assert_true(rl_scene_uid(b) != first);
    assert_true(rl_scene_uid(c) != rl_scene_uid(b));
    assert_int_equal(rl_scene_uid(NULL), 0);
    rl_scene_release(b);
    rl_scene_release(c);
}

static void test_new_scene_has_only_a_root_node(void **state)
{
    (void)state;
    rl_scene *s = new_scene(0);
    assert_int_equal(rl_scene_node_count(s), 1);
    assert_string_equal(rl_scene_node_name(s, RL_NODE_ROOT), "root");
    assert_int_equal(rl_scene_node_parent(s, RL_NODE_ROOT), RL_NONE);
    assert_int_equal(rl_scene_find_node(s, "root"), 0);
    assert_int_equal(rl_scene_find_node(s, "nope"), RL_NONE);
    assert_false(rl_scene_is_committed(s));
    assert_null(rl_scene_get_data(s));
    assert_int_equal(rl_last_status(), RL_ERR_NOT_COMMITTED);
    rl_clear_error();
    rl_scene_release(s);
    rl_scene_release(NULL);
}

static void test_one_mesh_in_three_nodes_gives_three_objects_in_depth_first_order(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    uint32_t tri = add_triangle(s, 0);
    uint32_t a = add_node(s, RL_NODE_ROOT, "a", rl_mat4_translate(rl_v3(10, 0, 0)), tri);
    uint32_t b = add_node(s, RL_NODE_ROOT, "b", rl_mat4_translate(rl_v3(0, 0, 3)), tri);
    uint32_t empty = add_node(s, a, "empty", rl_mat4_identity(), RL_NONE);
    /* Added last but a grandchild of a: depth-first order puts it before b. */
    uint32_t a1 = add_node(s, empty, "a1", rl_mat4_translate(rl_v3(0, 5, 0)), tri);
    assert_int_equal(rl_scene_node_parent(s, a1), empty);
    assert_int_equal(rl_scene_commit(s), RL_OK);

    const rl_scene_data *d = rl_scene_get_data(s);
    assert_non_null(d);
    assert_int_equal(d->num_objects, 3);
    assert_int_equal(d->num_triangles, 3);
    assert_int_equal(d->num_vertices, 9);
    const uint32_t nodes[3] = { a, a1, b };
    const char *names[3] = { "a", "a1", "b" };
    const rl_vec3 offset[3] = { { 10, 0, 0 }, { 10, 5, 0 }, { 0, 0, 3 } };
    for (uint32_t o = 0; o < 3; ++o) {
        const rl_object *obj = &d->objects[o];
        assert_int_equal(obj->node, nodes[o]);
        assert_string_equal(obj->name, names[o]);
        assert_int_equal(obj->mesh, tri);
        assert_int_equal(obj->first_triangle, o);
        assert_int_equal(obj->num_triangles, 1);
        assert_int_equal(obj->first_vertex, 3 * o);
        assert_int_equal(d->triangle_object[o], o);
        for (int k = 0; k < 3; ++k) {
            rl_vec3 p = d->positions[d->indices[3 * o + k]];
            assert_vec3_near(p, rl_add(tri_pos[k], offset[o]), 0.0f);
        }
        assert_vec3_near(obj->bounds.min, offset[o], 0.0f);
        assert_vec3_near(obj->bounds.max, rl_add(offset[o], rl_v3(1, 1, 0)), 0.0f);
    }
    assert_vec3_near(d->bounds.min, rl_v3(0, 0, 0), 0.0f);
    assert_vec3_near(d->bounds.max, rl_v3(11, 6, 3), 0.0f);
    rl_scene_release(s);
}

static void test_material_override_is_inherited_until_a_descendant_sets_its_own(void **state)
{
    (void)state;
    rl_scene *s = new_scene(3);
    /* Per-triangle materials 0 and 2 in the mesh itself. */
    static const uint32_t tri_mats[2] = { 0, 2 };
    static const rl_vec3 p[4] = { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0 }, { 0, 1, 0 } };
    static const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc md = { .name = "two", .num_vertices = 4, .positions = p, .num_triangles = 2,
                        .indices = idx, .triangle_materials = tri_mats };
    uint32_t mesh;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    rl_mat4 id = rl_mat4_identity();
    uint32_t parent = add_node(s, RL_NODE_ROOT, "parent", id, mesh);
    uint32_t child = add_node(s, parent, "child", id, mesh);
    uint32_t grandchild = add_node(s, child, "grandchild", id, mesh);
    add_node(s, RL_NODE_ROOT, "plain", id, mesh);
    assert_int_equal(rl_scene_node_set_material(s, parent, 1), RL_OK);
    assert_int_equal(rl_scene_node_set_material(s, grandchild, 2), RL_OK);
    assert_int_equal(rl_scene_node_set_material(s, child, 3), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    /* objects: parent, child, grandchild, plain; two triangles each */
    const uint32_t expect[8] = { 1, 1, 1, 1, 2, 2, 0, 2 };
    assert_int_equal(d->num_triangles, 8);
    for (int t = 0; t < 8; ++t)
        assert_int_equal(d->triangle_material[t], expect[t]);
    rl_scene_release(s);
}

static void test_node_attributes_can_be_set_replaced_and_removed(void **state)
{
    (void)state;
    rl_scene *s = new_scene(0);
    uint32_t n = add_node(s, RL_NODE_ROOT, "n", rl_mat4_identity(), RL_NONE);
    assert_null(rl_scene_node_attr(s, n, "vt"));
    assert_int_equal(rl_scene_node_set_attr(s, n, "vt", "true"), RL_OK);
    assert_int_equal(rl_scene_node_set_attr(s, n, "lod", "2"), RL_OK);
    assert_string_equal(rl_scene_node_attr(s, n, "vt"), "true");
    assert_int_equal(rl_scene_node_set_attr(s, n, "vt", "false"), RL_OK);
    assert_string_equal(rl_scene_node_attr(s, n, "vt"), "false");
    assert_int_equal(rl_scene_node_set_attr(s, n, "vt", NULL), RL_OK);
    assert_null(rl_scene_node_attr(s, n, "vt"));
    assert_string_equal(rl_scene_node_attr(s, n, "lod"), "2");
    assert_int_equal(rl_scene_node_set_attr(s, n, "missing", NULL), RL_OK);
    assert_null(rl_scene_node_attr(s, RL_NODE_ROOT, "lod"));
    assert_int_equal(rl_scene_node_set_attr(s, n, "", "x"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_node_set_attr(s, 99, "k", "x"), RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_scene_release(s);
}

static void test_commit_flattens_instances_into_counts_and_bounds(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    uint32_t quad = add_quad(s, 0);
    add_node(s, RL_NODE_ROOT, "q0", rl_mat4_translate(rl_v3(-2, 0, 0)), quad);
    add_node(s, RL_NODE_ROOT, "q1", rl_mat4_scale(rl_v3(2, 3, 1)), quad);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.nodes, 3);
    assert_int_equal(st.meshes, 1);
    assert_int_equal(st.objects, 2);
    assert_int_equal(st.mesh_triangles, 2);
    assert_int_equal(st.triangles, 0);
    assert_int_equal(st.vertices, 0);
    size_t before = st.memory_bytes;
    assert_true(before > 0);

    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.triangles, 4);
    assert_int_equal(st.vertices, 8);
    assert_int_equal(st.objects, 2);
    assert_int_equal(st.emissive_triangles, 0);
    assert_true(st.memory_bytes > before);
    assert_vec3_near(st.bounds.min, rl_v3(-2, 0, 0), 0.0f);
    assert_vec3_near(st.bounds.max, rl_v3(2, 3, 0), 0.0f);
    const rl_scene_data *d = rl_scene_get_data(s);
    for (uint32_t v = 0; v < d->num_vertices; ++v) {
        assert_vec3_near(d->normals[v], rl_v3(0, 0, 1), 1e-6f);
        assert_true(d->uvs[v].x == 0.0f && d->uvs[v].y == 0.0f);
    }
    for (uint32_t t = 0; t < 3 * d->num_triangles; ++t)
        assert_true(d->indices[t] < d->num_vertices);
    rl_scene_release(s);
}

static rl_vec3 geometric_normal(const rl_scene_data *d, uint32_t t)
{
    rl_vec3 p0 = d->positions[d->indices[3 * t]], p1 = d->positions[d->indices[3 * t + 1]];
    rl_vec3 p2 = d->positions[d->indices[3 * t + 2]];
    return rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
}

static void test_mirrored_transform_flips_winding_so_front_faces_stay_front(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    uint32_t tri = add_triangle(s, 0);
    add_node(s, RL_NODE_ROOT, "plain", rl_mat4_identity(), tri);
    add_node(s, RL_NODE_ROOT, "mirror_x", rl_mat4_scale(rl_v3(-1, 1, 1)), tri);
    rl_mat4 rot = rl_mat4_rotate(rl_v3(0, 1, 0), 0.7f);
    rl_mat4 mirror_z = rl_mat4_scale(rl_v3(1, 2, -1));
    add_node(s, RL_NODE_ROOT, "rot_mirror_z", rl_mat4_mul(&rot, &mirror_z), tri);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 3);
    for (uint32_t t = 0; t < 3; ++t) {
        rl_vec3 g = geometric_normal(d, t);
        for (int k = 0; k < 3; ++k) {
            rl_vec3 n = d->normals[d->indices[3 * t + k]];
            assert_true(fabsf(rl_length(n) - 1.0f) < 1e-5f);
            assert_true(rl_dot(g, n) > 0.999f);
        }
    }
    /* Mirroring x keeps the +z normal; only the winding had to change. */
    assert_vec3_near(d->positions[d->indices[3]], rl_v3(0, 0, 0), 0.0f);
    assert_vec3_near(d->normals[3], rl_v3(0, 0, 1), 1e-6f);
    rl_scene_release(s);
}

static void test_nonfinite_and_degenerate_triangles_are_dropped_and_counted(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    const rl_vec3 p[7] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { NAN, 0, 0 },
                           { 2, 0, 0 }, { 0, INFINITY, 0 }, { 1e6f, 1e6f, 1e6f } };
    const uint32_t idx[] = {
        0, 1, 2,   /* good */
        0, 1, 3,   /* NaN vertex */
        0, 1, 4,   /* collinear */
        2, 2, 1,   /* repeated index */
        5, 0, 1,   /* Inf vertex */
        1, 6, 6,   /* repeated far vertex */
    };
    rl_mesh_desc md = { .name = "bad", .num_vertices = 7, .positions = p, .num_triangles = 6,
                        .indices = idx, .material = 0 };
    warnings = 0;
    rl_log_set_callback(count_warnings, NULL);
    uint32_t mesh;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    rl_log_set_callback(NULL, NULL);
    assert_int_equal(warnings, 1);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.mesh_triangles, 1);
    assert_int_equal(st.dropped_degenerate, 3);
    assert_int_equal(st.dropped_nonfinite, 2);
    add_node(s, RL_NODE_ROOT, "n", rl_mat4_identity(), mesh);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 1);
    /* Unreferenced vertices go too, so nothing non-finite reaches the bounds. */
    assert_int_equal(d->num_vertices, 3);
    assert_vec3_near(d->bounds.max, rl_v3(1, 1, 0), 0.0f);
    rl_scene_release(s);
}

static void test_bad_normals_and_uvs_are_repaired(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    const rl_vec3 n[3] = { { 0, 0, 5 }, { NAN, 0, 1 }, { 0, 0, 0 } };
    const rl_vec2 uv[3] = { { 0.5f, 0.25f }, { INFINITY, 0 }, { 1, 1 } };
    rl_mesh_desc md = { .num_vertices = 3, .positions = tri_pos, .normals = n, .uvs = uv,
                        .num_triangles = 1, .indices = tri_idx, .material = 0 };
    uint32_t mesh;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    const rl_mesh *m = &s->meshes[mesh];
    for (int v = 0; v < 3; ++v)
        assert_vec3_near(m->normals[v], rl_v3(0, 0, 1), 1e-6f);
    assert_true(m->uvs[0].x == 0.5f && m->uvs[0].y == 0.25f);
    assert_true(m->uvs[1].x == 0.0f && m->uvs[1].y == 0.0f);
    assert_true(m->uvs[2].x == 1.0f);
    rl_scene_release(s);
}

static void test_invalid_meshes_are_rejected_with_status_codes(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    const uint32_t bad_idx[3] = { 0, 1, 99 };
    rl_mesh_desc md = { .name = "m", .num_vertices = 3, .positions = tri_pos, .num_triangles = 1,
                        .indices = bad_idx };
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "triangle 0 index 99 out of range (3 vertices)"));
    rl_clear_error();
    md.indices = tri_idx;
    md.material = 1;
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_INVALID_ARG);
    const uint32_t tri_mat = 7;
    md.material = 0;
    md.triangle_materials = &tri_mat;
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_INVALID_ARG);
    md.triangle_materials = NULL;
    md.positions = NULL;
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_INVALID_ARG);
    md.positions = tri_pos;
    md.indices = NULL;
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_INVALID_ARG);
    md.num_triangles = RL_SCENE_MAX_TRIANGLES + 1u;
    md.indices = tri_idx;
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_LIMIT);
    assert_int_equal(rl_scene_add_mesh(s, NULL, NULL), RL_ERR_INVALID_ARG);
    /* Zero triangles is allowed (with a warning). */
    md.num_triangles = 0;
    uint32_t id = RL_NONE;
    assert_int_equal(rl_scene_add_mesh(s, &md, &id), RL_OK);
    assert_int_equal(id, 0);
    rl_clear_error();
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.meshes, 1);
    rl_scene_release(s);
}

static void test_singular_and_nonfinite_transforms_are_rejected(void **state)
{
    (void)state;
    rl_scene *s = new_scene(0);
    rl_mat4 flat = rl_mat4_scale(rl_v3(1, 0, 1));
    rl_mat4 nan = rl_mat4_identity();
    nan.m[0][3] = NAN;
    uint32_t id = 1234;
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "flat", &flat, &id), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "nan", &nan, &id), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_node(s, 5, "orphan", NULL, &id), RL_ERR_INVALID_ARG);
    assert_int_equal(id, 1234);
    assert_int_equal(rl_scene_node_count(s), 1);
    assert_int_equal(rl_scene_node_set_mesh(s, RL_NODE_ROOT, 0), RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_scene_release(s);
}

static void test_committing_a_scene_without_triangles_is_an_empty_scene(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    assert_int_equal(rl_scene_commit(s), RL_ERR_EMPTY_SCENE);
    rl_clear_error();
    /* A mesh that is never instanced does not count. */
    add_triangle(s, 0);
    add_node(s, RL_NODE_ROOT, "no_mesh", rl_mat4_identity(), RL_NONE);
    assert_int_equal(rl_scene_commit(s), RL_ERR_EMPTY_SCENE);
    assert_false(rl_scene_is_committed(s));
    rl_clear_error();
    rl_scene_release(s);
}

static void test_committed_scene_refuses_every_mutation(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    uint32_t tri = add_triangle(s, 0);
    uint32_t n = add_node(s, RL_NODE_ROOT, "n", rl_mat4_identity(), tri);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    assert_true(rl_scene_is_committed(s));

    rl_material m = rl_material_default();
    rl_light l = { .type = RL_LIGHT_POINT, .color = { 1, 1, 1 }, .intensity = 1 };
    rl_camera c = { .eye = { 0, 0, 5 } };
    rl_mesh_desc md = { .num_vertices = 3, .positions = tri_pos, .num_triangles = 1, .indices = tri_idx };
    rl_camera_key key = { 0.0, c };
    rl_camera_path *path = NULL;
    assert_int_equal(rl_camera_path_create(&key, 1, &path), RL_OK);
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(1, 1, &(rl_vec4){ 1, 1, 1, 1 }, &tex), RL_OK);

    assert_int_equal(rl_scene_add_material(s, &m, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_mesh(s, &md, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_light(s, &l), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_camera(s, "c", &c), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_texture(s, tex, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_load_texture(s, "x.png", NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_set_camera_path(s, path), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "x", NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_node_set_mesh(s, n, RL_NONE), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_node_set_material(s, n, 0), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_node_set_attr(s, n, "k", "v"), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_scene_node_count(s), 2);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_materials, 1);
    assert_int_equal(d->num_lights, 0);
    assert_null(d->camera_path);
    rl_camera_path_release(path);
    rl_texture_release(tex);
    rl_scene_release(s);
}

static void test_smooth_normals_of_a_cube_corner_point_along_its_diagonal(void **state)
{
    (void)state;
    /* Three equal faces of a cube meeting at the origin, facing outwards (-x, -y, -z). */
    const rl_vec3 p[4] = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    const uint32_t idx[9] = { 0, 3, 2, 0, 1, 3, 0, 2, 1 };
    rl_vec3 n[4];
    rl_mesh_compute_normals(4, p, 3, idx, n);
    float c = -1.0f / sqrtf(3.0f);
    assert_vec3_near(n[0], rl_v3(c, c, c), 1e-6f);
    assert_vec3_near(n[1], rl_normalize(rl_v3(0, -1, -1)), 1e-6f);
    /* A quad split into two triangles: every vertex gets the face normal. */
    const rl_vec3 q[5] = { { 0, 0, 0 }, { 2, 0, 0 }, { 2, 3, 0 }, { 0, 3, 0 }, { 9, 9, 9 } };
    const uint32_t qi[6] = { 0, 1, 2, 0, 2, 3 };
    rl_vec3 qn[5];
    rl_mesh_compute_normals(5, q, 2, qi, qn);
    for (int v = 0; v < 4; ++v)
        assert_vec3_near(qn[v], rl_v3(0, 0, 1), 0.0f);
    /* A vertex without any triangle falls back to +z. */
    assert_vec3_near(qn[4], rl_v3(0, 0, 1), 0.0f);
}

static void test_area_weighting_favours_the_larger_face(void **state)
{
    (void)state;
    /* Vertex 0 shared by a big triangle facing +z and a small one facing +x. */
    const rl_vec3 p[5] = { { 0, 0, 0 }, { 4, 0, 0 }, { 0, 4, 0 }, { 0, 1, 0 }, { 0, 0, 1 } };
    const uint32_t idx[6] = { 0, 1, 2, 0, 3, 4 };
    rl_vec3 n[5];
    rl_mesh_compute_normals(5, p, 2, idx, n);
    /* cross products: (0,0,16) and (1,0,0) */
    assert_vec3_near(n[0], rl_normalize(rl_v3(1, 0, 16)), 1e-6f);
}

static void test_materials_and_lights_are_validated(void **state)
{
    (void)state;
    rl_material m = rl_material_default();
    assert_int_equal(rl_material_validate(&m), RL_OK);
    assert_true(m.diffuse.x == 0.8f && m.ior == 1.5f && m.shininess == 32.0f);
    assert_int_equal(m.diffuse_texture, RL_NONE);
    m.reflectivity = 0.6f;
    m.transmissivity = 0.6f;
    assert_int_equal(rl_material_validate(&m), RL_ERR_INVALID_ARG);
    m = rl_material_default();
    m.ior = 0.9f;
    assert_int_equal(rl_material_validate(&m), RL_ERR_INVALID_ARG);
    m = rl_material_default();
    m.diffuse.y = NAN;
    assert_int_equal(rl_material_validate(&m), RL_ERR_INVALID_ARG);
    m = rl_material_default();
    m.specular.z = -0.1f;
    assert_int_equal(rl_material_validate(&m), RL_ERR_INVALID_ARG);
    m = rl_material_default();
    m.diffuse_texture = 0;
    rl_scene *s = new_scene(0);
    assert_int_equal(rl_scene_add_material(s, &m, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_find_material(s, "default"), RL_NONE);
    m.diffuse_texture = RL_NONE;
    assert_int_equal(rl_scene_add_material(s, &m, NULL), RL_OK);
    assert_int_equal(rl_scene_find_material(s, "default"), 0);

    rl_light spot = { .type = RL_LIGHT_SPOT, .color = { 1, 1, 1 }, .intensity = 2,
                      .direction = { 0, -1, 0 }, .spot_inner_deg = 0, .spot_outer_deg = 30 };
    assert_int_equal(rl_light_validate(&spot), RL_OK);
    spot.spot_inner_deg = 40;
    assert_int_equal(rl_light_validate(&spot), RL_ERR_INVALID_ARG);
    spot.spot_inner_deg = 10;
    spot.spot_outer_deg = 95;
    assert_int_equal(rl_light_validate(&spot), RL_ERR_INVALID_ARG);
    spot.spot_outer_deg = 30;
    spot.intensity = -1;
    assert_int_equal(rl_light_validate(&spot), RL_ERR_INVALID_ARG);
    rl_light quad = { .type = RL_LIGHT_QUAD, .color = { 1, 1, 1 }, .intensity = 1,
                      .edge_u = { 1, 0, 0 }, .edge_v = { 2, 0, 0 } };
    assert_int_equal(rl_light_validate(&quad), RL_ERR_INVALID_ARG);
    quad.edge_v = rl_v3(0, 0, 1);
    assert_int_equal(rl_light_validate(&quad), RL_OK);
    assert_int_equal(rl_scene_add_light(s, &quad), RL_OK);
    rl_light bad = { .type = RL_LIGHT_TYPE_COUNT };
    assert_int_equal(rl_scene_add_light(s, &bad), RL_ERR_INVALID_ARG);
    assert_string_equal(rl_light_type_name(RL_LIGHT_DIRECTIONAL), "directional");
    rl_clear_error();
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.lights, 1);
    assert_int_equal(st.materials, 1);
    rl_scene_release(s);
}

static void test_get_camera_finds_by_name_first_or_frames_the_bounds(void **state)
{
    (void)state;
    rl_scene *s = new_scene(1);
    add_node(s, RL_NODE_ROOT, "n", rl_mat4_identity(), add_quad(s, 0));
    rl_camera out;
    assert_int_equal(rl_scene_get_camera(s, NULL, &out), RL_ERR_NOT_COMMITTED);
    rl_clear_error();
    rl_camera a = { .eye = { 0, 0, 5 }, .width = 32, .height = 16 };
    rl_camera b = { .eye = { 0, 0, -5 } };
    rl_camera bad = { .eye = { 1, 1, 1 }, .target = { 1, 1, 1 } };
    assert_int_equal(rl_scene_add_camera(s, "a", &a), RL_OK);
    assert_int_equal(rl_scene_add_camera(s, "b", &b), RL_OK);
    assert_int_equal(rl_scene_add_camera(s, "a", &b), RL_OK);   /* stored as "a.2" */
    assert_int_equal(rl_scene_add_camera(s, "bad", &bad), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_scene_commit(s), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, NULL, &out), RL_OK);
    assert_int_equal(out.width, 32);
    assert_int_equal(rl_scene_get_camera(s, "b", &out), RL_OK);
    assert_true(out.eye.z == -5.0f && out.width == RL_CAMERA_DEFAULT_WIDTH);
    out.eye.z = 42.0f;
    assert_int_equal(rl_scene_get_camera(s, "c", &out), RL_ERR_NOT_FOUND);
    assert_true(out.eye.z == 42.0f);
    assert_non_null(strstr(rl_last_error(), "no camera \"c\" (scene has: a, b, a.2)"));
    rl_clear_error();
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_cameras, 3);
    assert_string_equal(d->camera_names[1], "b");
    assert_string_equal(d->camera_names[2], "a.2");
    assert_int_equal(rl_scene_get_camera(s, "a.2", &out), RL_OK);
    assert_true(out.eye.z == -5.0f);
    rl_scene_release(s);

    /* No camera at all: the tight fit of the committed vertices from the
     * scene's default view, at the default size. */
    s = new_scene(1);
    add_node(s, RL_NODE_ROOT, "n", rl_mat4_identity(), add_quad(s, 0));
    rl_camera framed;
    assert_int_equal(rl_scene_fit_camera(s, 64, 64, &framed), RL_ERR_NOT_COMMITTED);
    assert_int_equal(rl_scene_set_default_view(s, 10.0f, 95.0f), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_scene_set_default_view(s, 0.0f, 0.0f), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    assert_int_equal(rl_scene_set_default_view(s, 0.0f, 0.0f), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_scene_get_camera(s, NULL, &out), RL_OK);
    assert_int_equal(rl_scene_fit_camera(s, RL_CAMERA_DEFAULT_WIDTH, RL_CAMERA_DEFAULT_HEIGHT,
                                         &framed), RL_OK);
    assert_memory_equal(&out, &framed, sizeof out);
    /* Azimuth 0, elevation 0: straight down -z at the quad in z = 0. */
    assert_vec3_near(out.target, rl_v3(0.5f, 0.5f, 0.0f), 1e-5f);
    assert_true(out.eye.z > 0.0f && fabsf(out.eye.x - 0.5f) < 1e-5f);
    rl_scene_release(s);
}

static void test_loading_a_texture_twice_shares_it(void **state)
{
    (void)state;
    const char *tmp = getenv("RL_TEST_TMP");
    if (!tmp)
        tmp = "/tmp";   /* absolute, like the ctest scratch dir */
    char file[1024];
    snprintf(file, sizeof file, "%s/scene_tex.png", tmp);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 2, RL_LAYER_COLOR, &img), RL_OK);
    rl_image_fill(img, rl_v4(1, 0, 0, 1));
    assert_int_equal(rl_image_write_png(img, file), RL_OK);
    rl_image_release(img);

    rl_scene *s = new_scene(0);
    assert_int_equal(rl_scene_set_base_dir(s, tmp), RL_OK);
    assert_string_equal(rl_scene_base_dir(s), tmp);
    uint32_t a = RL_NONE, b = RL_NONE, c = RL_NONE;
    assert_int_equal(rl_scene_load_texture(s, "scene_tex.png", &a), RL_OK);
    assert_int_equal(rl_scene_load_texture(s, "scene_tex.png", &b), RL_OK);
    assert_int_equal(rl_scene_load_texture(s, file, &c), RL_OK);   /* absolute path, same file */
    assert_int_equal(a, 0);
    assert_int_equal(b, 0);
    assert_int_equal(c, 0);
    uint32_t missing = 77;
    assert_int_equal(rl_scene_load_texture(s, "does_not_exist.png", &missing), RL_ERR_IO);
    assert_int_equal(missing, 77);
    rl_clear_error();
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.textures, 1);
    rl_scene_release(s);
}

static void test_paths_join_and_split(void **state)
{
    (void)state;
    char out[64];
    rl_path_join("scenes", "tex/a.png", out, sizeof out);
    assert_string_equal(out, "scenes/tex/a.png");
    rl_path_join("scenes/", "a.png", out, sizeof out);
    assert_string_equal(out, "scenes/a.png");
    rl_path_join("scenes", "/abs/a.png", out, sizeof out);
    assert_string_equal(out, "/abs/a.png");
    rl_path_join("", "a.png", out, sizeof out);
    assert_string_equal(out, "a.png");
    rl_path_dirname("scenes/tex/a.png", out, sizeof out);
    assert_string_equal(out, "scenes/tex");
    rl_path_dirname("a.png", out, sizeof out);
    assert_string_equal(out, "");
    rl_path_dirname("/a.png", out, sizeof out);
    assert_string_equal(out, "/");
    char tiny[4];
    rl_path_join("abcdef", "g", tiny, sizeof tiny);
    assert_string_equal(tiny, "abc");
}

/* Many instances of meshes of different sizes (some empty) so that the
 * chunked parallel flattening crosses object boundaries everywhere; the
 * oracle transforms every vertex serially. */
static void test_parallel_flattening_agrees_with_a_serial_transform(void **state)
{
    (void)state;
    rl_scene *s = new_scene(2);
    enum { MESHES = 5 };
    uint32_t mesh[MESHES];
    for (int k = 0; k < MESHES; ++k) {
        uint32_t grid = k == 2 ? 0 : (uint32_t)(10 + 17 * k); /* grid x grid quads */
        uint32_t nv = (grid + 1) * (grid + 1), nt = 2 * grid * grid;
        rl_vec3 *p = calloc(nv + 1, sizeof *p);
        uint32_t *idx = calloc(3 * (size_t)nt + 1, sizeof *idx);
        for (uint32_t y = 0; y <= grid; ++y)
            for (uint32_t x = 0; x <= grid; ++x)
                p[y * (grid + 1) + x] = rl_v3((float)x, (float)y, 0.1f * (float)((x * y) % 5));
        uint32_t t = 0;
        for (uint32_t y = 0; y < grid; ++y)
            for (uint32_t x = 0; x < grid; ++x) {
                uint32_t i0 = y * (grid + 1) + x, i1 = i0 + 1, i2 = i0 + grid + 2, i3 = i0 + grid + 1;
                uint32_t q[6] = { i0, i1, i2, i0, i2, i3 };
                memcpy(idx + 3 * (size_t)t, q, sizeof q);
                t += 2;
            }
        rl_mesh_desc md = { .num_vertices = grid ? nv : 0, .positions = p, .num_triangles = nt,
                            .indices = idx, .material = (uint32_t)k % 2 };
        assert_int_equal(rl_scene_add_mesh(s, &md, &mesh[k]), RL_OK);
        free(p);
        free(idx);
    }
    uint32_t group = RL_NODE_ROOT;
    for (int i = 0; i < 120; ++i) {
        rl_mat4 r = rl_mat4_rotate(rl_normalize(rl_v3(1, (float)i, 2)), 0.1f * (float)i);
        rl_mat4 t = rl_mat4_translate(rl_v3((float)i, -(float)i, 0.5f * (float)i));
        rl_mat4 sc = rl_mat4_scale(rl_v3(i % 3 == 0 ? -1.0f : 1.0f, 1.0f, 1.5f));
        rl_mat4 tr = rl_mat4_mul(&t, &r);
        rl_mat4 m = rl_mat4_mul(&tr, &sc);
        if (i % 10 == 0)
            group = add_node(s, RL_NODE_ROOT, "group", rl_mat4_translate(rl_v3(0, 0, (float)i)), RL_NONE);
        add_node(s, group, "inst", m, mesh[i % MESHES]);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_objects, 120);
    uint32_t next_tri = 0, next_vert = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *obj = &d->objects[o];
        const rl_mesh *m = &s->meshes[obj->mesh];
        assert_int_equal(obj->first_triangle, next_tri);
        assert_int_equal(obj->first_vertex, next_vert);
        next_tri += obj->num_triangles;
        next_vert += obj->num_vertices;
        rl_mat4 parent = s->nodes[s->nodes[obj->node].parent].local;
        rl_mat4 world = rl_mat4_mul(&parent, &s->nodes[obj->node].local);
        for (uint32_t v = 0; v < obj->num_vertices; ++v) {
            rl_vec3 expect = rl_mat4_mul_point(&world, m->positions[v]);
            assert_vec3_near(d->positions[obj->first_vertex + v], expect, 1e-3f);
            assert_true(rl_aabb_contains(obj->bounds, d->positions[obj->first_vertex + v]));
        }
        for (uint32_t t = 0; t < obj->num_triangles; ++t) {
            uint32_t g = obj->first_triangle + t;
            assert_int_equal(d->triangle_object[g], o);
            assert_int_equal(d->triangle_material[g], m->materials[t]);
            assert_int_equal(d->indices[3 * g], obj->first_vertex + m->indices[3 * t]);
        }
    }
    assert_int_equal(next_tri, d->num_triangles);
    assert_int_equal(next_vert, d->num_vertices);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_new_scene_has_only_a_root_node),
        cmocka_unit_test(test_scene_uids_are_never_reused),
        cmocka_unit_test(test_one_mesh_in_three_nodes_gives_three_objects_in_depth_first_order),
        cmocka_unit_test(test_material_override_is_inherited_until_a_descendant_sets_its_own),
        cmocka_unit_test(test_node_attributes_can_be_set_replaced_and_removed),
        cmocka_unit_test(test_commit_flattens_instances_into_counts_and_bounds),
        cmocka_unit_test(test_mirrored_transform_flips_winding_so_front_faces_stay_front),
        cmocka_unit_test(test_nonfinite_and_degenerate_triangles_are_dropped_and_counted),
        cmocka_unit_test(test_bad_normals_and_uvs_are_repaired),
        cmocka_unit_test(test_invalid_meshes_are_rejected_with_status_codes),
        cmocka_unit_test(test_singular_and_nonfinite_transforms_are_rejected),
        cmocka_unit_test(test_committing_a_scene_without_triangles_is_an_empty_scene),
        cmocka_unit_test(test_committed_scene_refuses_every_mutation),
        cmocka_unit_test(test_smooth_normals_of_a_cube_corner_point_along_its_diagonal),
        cmocka_unit_test(test_area_weighting_favours_the_larger_face),
        cmocka_unit_test(test_materials_and_lights_are_validated),
        cmocka_unit_test(test_get_camera_finds_by_name_first_or_frames_the_bounds),
        cmocka_unit_test(test_loading_a_texture_twice_shares_it),
        cmocka_unit_test(test_paths_join_and_split),
        cmocka_unit_test(test_parallel_flattening_agrees_with_a_serial_transform),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
