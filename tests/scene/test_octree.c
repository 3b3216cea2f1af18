/* test_octree.c: the loose octree's invariants (rl_octree.h) on the city
 * and on a hand-built scene whose placement is known. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl.h"
#include "rl/rl_octree.h"

static bool inside(rl_aabb outer, rl_aabb inner)
{
    return inner.min.x >= outer.min.x && inner.min.y >= outer.min.y && inner.min.z >= outer.min.z &&
           inner.max.x <= outer.max.x && inner.max.y <= outer.max.y && inner.max.z <= outer.max.z;
}

static bool point_in(rl_aabb b, rl_vec3 p)
{
    return p.x >= b.min.x && p.y >= b.min.y && p.z >= b.min.z && p.x <= b.max.x && p.y <= b.max.y &&
           p.z <= b.max.z;
}

static bool same_box(rl_aabb a, rl_aabb b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

/* Every invariant of rl_octree.h; returns the number of nodes. */
static uint32_t check_invariants(const rl_scene *scene, const rl_octree *t)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    rl_octree_desc desc = rl_octree_get_desc(t);
    uint32_t nn, no;
    const rl_octree_node *nodes = rl_octree_nodes(t, &nn);
    const uint32_t *objects = rl_octree_objects(t, &no);
    assert_true(nn >= 1);
    assert_int_equal(nodes[0].parent, RL_NONE);
    assert_int_equal(nodes[0].depth, 0);

    /* Every object with triangles exactly once. */
    uint8_t *seen = calloc(d->num_objects, 1);
    uint32_t with_tris = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        with_tris += d->objects[o].num_triangles > 0;
    assert_int_equal(no, with_tris);
    assert_int_equal(nodes[0].subtree_objects, with_tris);

    uint32_t max_depth = 0;
    for (uint32_t i = 0; i < nn; ++i) {
        const rl_octree_node *n = &nodes[i];
        assert_true((int)n->depth <= desc.max_depth);
        if (n->depth > max_depth)
            max_depth = n->depth;
        /* The loose box is the cell scaled by k about its centre. */
        rl_vec3 c = rl_aabb_center(n->cell), h = rl_scale(rl_aabb_extent(n->cell), 0.5f);
        rl_vec3 hl = rl_scale(rl_aabb_extent(n->loose), 0.5f);
        assert_float_equal(hl.x, h.x * desc.looseness, 1e-4f * hl.x);
        assert_float_equal(rl_aabb_center(n->loose).y, c.y, 1e-3f * (1.0f + hl.y));
        assert_float_equal(h.x, h.y, 1e-5f * h.x);   /* cubes */
        assert_float_equal(h.x, h.z, 1e-5f * h.x);

        rl_aabb tight = rl_aabb_empty();
        uint32_t count = n->num_objects;
        uint64_t tris = 0;
        for (uint32_t k = 0; k < n->num_objects; ++k) {
            uint32_t o = objects[n->first_object + k];
            assert_true(o < d->num_objects);
            assert_false(seen[o]);
            seen[o] = 1;
            rl_aabb ob = d->objects[o].bounds;
            tight = rl_aabb_union(tight, ob);
            tris += d->objects[o].num_triangles;
            /* Loose-octree placement: centre in the cell, bounds in the loose box. */
            assert_true(point_in(n->cell, rl_aabb_center(ob)));
            assert_true(inside(n->loose, ob));
            /* An object stays at an inner node only where its child's loose box is too small. */
            if (n->num_children > 0) {
                for (uint32_t j = 0; j < n->num_children; ++j) {
                    const rl_octree_node *ch = &nodes[n->first_child + j];
                    if (point_in(ch->cell, rl_aabb_center(ob)))
                        assert_false(inside(ch->loose, ob) &&
                                     !(rl_aabb_center(ob).x == c.x || rl_aabb_center(ob).y == c.y ||
                                       rl_aabb_center(ob).z == c.z));
                }
            }
        }
        if (n->num_children == 0) {
            assert_int_equal(n->first_child, RL_NONE);
            /* A leaf above max depth holds at most leaf_objects, or only
             * objects that fit no child: the loose box of the octant
             * holding an object's centre does not hold the object. */
            if ((int)n->depth < desc.max_depth && n->num_objects > desc.leaf_objects) {
                for (uint32_t k = 0; k < n->num_objects; ++k) {
                    rl_aabb ob = d->objects[objects[n->first_object + k]].bounds;
                    rl_vec3 oc = rl_aabb_center(ob);
                    rl_aabb oct = n->cell;
                    if (oc.x >= c.x) oct.min.x = c.x; else oct.max.x = c.x;
                    if (oc.y >= c.y) oct.min.y = c.y; else oct.max.y = c.y;
                    if (oc.z >= c.z) oct.min.z = c.z; else oct.max.z = c.z;
                    rl_vec3 oh = rl_scale(rl_aabb_extent(oct), 0.5f * desc.looseness);
                    rl_vec3 occ = rl_aabb_center(oct);
                    assert_false(inside((rl_aabb){ rl_sub(occ, oh), rl_add(occ, oh) }, ob));
                }
            }
        } else {
            assert_true(n->num_children <= 8);
            for (uint32_t j = 0; j < n->num_children; ++j) {
                const rl_octree_node *ch = &nodes[n->first_child + j];
                assert_int_equal(ch->parent, i);
                assert_int_equal(ch->depth, n->depth + 1);
                assert_true(inside(n->cell, ch->cell));
                assert_true(ch->subtree_objects > 0);
                tight = rl_aabb_union(tight, ch->bounds);
                count += ch->subtree_objects;
                tris += ch->subtree_triangles;
            }
        }
        assert_true(same_box(tight, n->bounds));
        assert_int_equal(count, n->subtree_objects);
        assert_int_equal(tris, n->subtree_triangles);
    }
    for (uint32_t o = 0; o < d->num_objects; ++o)
        assert_int_equal(seen[o], d->objects[o].num_triangles > 0);
    assert_int_equal(max_depth, rl_octree_depth(t));
    assert_true(rl_octree_memory_bytes(t) >= nn * sizeof(rl_octree_node));
    free(seen);
    return nn;
}

static void test_octree_invariants_hold_on_city_for_every_depth(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("city", "blocks=3", &s), RL_OK);
    uint32_t prev = 0;
    for (int depth = 0; depth <= 8; ++depth) {
        rl_octree *t = NULL;
        rl_octree_desc desc = { .max_depth = depth ? depth : RL_OCTREE_DEPTH_ZERO };
        assert_int_equal(rl_octree_build(s, &desc, &t), RL_OK);
        assert_int_equal(rl_octree_get_desc(t).max_depth, depth);
        uint32_t nn = check_invariants(s, t);
        if (depth == 0)
            assert_int_equal(nn, 1);
        assert_true(nn >= prev);   /* deeper limits only split more */
        prev = nn;
        rl_octree_release(t);
    }
    assert_true(prev > 50);
    rl_scene_release(s);
}

/* Three small boxes in corners and one box spanning the scene: the big one
 * stays at the root, each small one goes to the child of its corner, where
 * it is alone and so is not split further (leaf_objects 1). */
static void add_box(rl_scene *s, uint32_t mat, rl_vec3 lo, rl_vec3 hi)
{
    rl_vec3 p[8];
    for (int i = 0; i < 8; ++i)
        p[i] = rl_v3((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
    static const uint32_t idx[36] = { 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                      2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5 };
    uint32_t mesh, node;
    rl_mesh_desc md = { .name = "box", .num_vertices = 8, .positions = p, .num_triangles = 12,
                        .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "box", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

static void test_octree_places_objects_by_size(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t mat;
    rl_material m = rl_material_default();
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    add_box(s, mat, rl_v3(0, 0, 0), rl_v3(1, 1, 1));
    add_box(s, mat, rl_v3(98, 98, 98), rl_v3(100, 100, 100));
    add_box(s, mat, rl_v3(10, 10, 10), rl_v3(90, 90, 90));
    add_box(s, mat, rl_v3(0, 0, 98), rl_v3(1, 1, 100));
    assert_int_equal(rl_scene_commit(s), RL_OK);

    rl_octree *t = NULL;
    assert_int_equal(rl_octree_build(s, &(rl_octree_desc){ .max_depth = 4 }, &t), RL_OK);
    check_invariants(s, t);
    uint32_t nn;
    const rl_octree_node *nodes = rl_octree_nodes(t, &nn);
    const uint32_t *objects = rl_octree_objects(t, NULL);
    /* Object 2 (80 m wide) fits no child (50 m cells, 100 m loose boxes
     * would hold it, but its centre at 50 is the split plane: child 7 has
     * loose box [25, 125], too small on the low side). */
    assert_int_equal(nodes[0].num_objects, 1);
    assert_int_equal(objects[nodes[0].first_object], 2);
    for (uint32_t i = 0; i < nn; ++i)
        for (uint32_t k = 0; k < nodes[i].num_objects; ++k)
            if (objects[nodes[i].first_object + k] != 2)
                assert_int_equal(nodes[i].depth, 1);
    rl_octree_release(t);

    /* leaf_objects = 8: nothing is split. */
    assert_int_equal(rl_octree_build(s, &(rl_octree_desc){ .leaf_objects = 8 }, &t), RL_OK);
    rl_octree_nodes(t, &nn);
    assert_int_equal(nn, 1);
    rl_octree_release(t);
    rl_scene_release(s);
}

static void test_octree_refuses_bad_input(void **state)
{
    (void)state;
    rl_octree *t = (rl_octree *)&t;
    assert_int_equal(rl_octree_build(NULL, NULL, &t), RL_ERR_INVALID_ARG);
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    assert_int_equal(rl_octree_build(s, NULL, &t), RL_ERR_NOT_COMMITTED);
    assert_null(t);
    rl_scene_release(s);
    assert_int_equal(rl_scene_create_builtin("cornell", "", &s), RL_OK);
    assert_int_equal(rl_octree_build(s, &(rl_octree_desc){ .max_depth = 21 }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_octree_build(s, &(rl_octree_desc){ .max_depth = -2 }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_octree_build(s, &(rl_octree_desc){ .looseness = 0.5f }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_octree_build(s, &(rl_octree_desc){ .looseness = NAN }, &t), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_octree_build(s, NULL, &t), RL_OK);
    check_invariants(s, t);
    rl_octree_release(t);
    rl_octree_release(NULL);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_octree_invariants_hold_on_city_for_every_depth),
        cmocka_unit_test(test_octree_places_objects_by_size),
        cmocka_unit_test(test_octree_refuses_bad_input),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
