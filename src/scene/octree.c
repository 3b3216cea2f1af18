/* octree.c: the loose octree of rl_octree.h (Ulrich 2000; Jähn 2015, Sec.
 * 7.3 with enlargement factor 2.0).
 *
 * Top-down build: a node that holds more than leaf_objects objects and is
 * above max_depth hands every object to the child cell containing the
 * centre of its bounds, if that child's loose box contains the bounds;
 * the others stay. A child's slots are allocated for all non-empty
 * children at once, so siblings are contiguous; then each child is built in
 * turn. Deterministic: objects keep their index order in every list. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_octree.h"

struct rl_octree {
    rl_octree_desc desc;
    rl_octree_node *nodes;
    uint32_t num_nodes, cap_nodes;
    uint32_t *objects;            /* grouped by node */
    uint32_t num_objects;
    uint32_t depth;
};

typedef struct builder {
    rl_octree *tree;
    const rl_scene_data *data;
    uint32_t *scratch;            /* per-level object lists, see build_node */
} builder;

rl_octree_desc rl_octree_desc_default(void)
{
    return (rl_octree_desc){ .max_depth = 5, .looseness = 2.0f, .leaf_objects = 1 };
}

static rl_aabb loose_of(rl_aabb cell, float k)
{
    rl_vec3 c = rl_scale(rl_add(cell.min, cell.max), 0.5f);
    rl_vec3 h = rl_scale(rl_sub(cell.max, cell.min), 0.5f * k);
    return (rl_aabb){ rl_sub(c, h), rl_add(c, h) };
}

static bool contains(rl_aabb outer, rl_aabb inner)
{
    return inner.min.x >= outer.min.x && inner.min.y >= outer.min.y && inner.min.z >= outer.min.z &&
           inner.max.x <= outer.max.x && inner.max.y <= outer.max.y && inner.max.z <= outer.max.z;
}

static rl_aabb child_cell(rl_aabb cell, int i)
{
    rl_vec3 c = rl_scale(rl_add(cell.min, cell.max), 0.5f);
    rl_aabb r;
    r.min.x = (i & 1) ? c.x : cell.min.x;
    r.max.x = (i & 1) ? cell.max.x : c.x;
    r.min.y = (i & 2) ? c.y : cell.min.y;
    r.max.y = (i & 2) ? cell.max.y : c.y;
    r.min.z = (i & 4) ? c.z : cell.min.z;
    r.max.z = (i & 4) ? cell.max.z : c.z;
    return r;
}

static int child_index(rl_aabb cell, rl_aabb b)
{
    rl_vec3 c = rl_scale(rl_add(cell.min, cell.max), 0.5f);
    rl_vec3 o = rl_scale(rl_add(b.min, b.max), 0.5f);
    return (o.x >= c.x ? 1 : 0) | (o.y >= c.y ? 2 : 0) | (o.z >= c.z ? 4 : 0);
}

static rl_status grow_nodes(rl_octree *t, uint32_t extra)
{
    return rl_reserve_u32((void **)&t->nodes, &t->cap_nodes, (uint64_t)t->num_nodes + extra, sizeof *t->nodes, 64)
               ? RL_OK : RL_ERR_OUT_OF_MEMORY;
}

/* Fills node `slot` (already allocated, cell/loose/parent/depth set) from
 * the n objects in list. list is owned by the caller and may be reordered;
 * children's lists are carved from scratch space after it. */
static rl_status build_node(builder *b, uint32_t slot, uint32_t *list, uint32_t n)
{
    rl_octree *t = b->tree;
    const rl_scene_data *d = b->data;
    rl_octree_node node = t->nodes[slot];
    node.bounds = rl_aabb_empty();
    node.subtree_objects = n;
    node.subtree_triangles = 0;
    for (uint32_t i = 0; i < n; ++i) {
        node.bounds = rl_aabb_union(node.bounds, d->objects[list[i]].bounds);
        node.subtree_triangles += d->objects[list[i]].num_triangles;
    }
    node.first_child = RL_NONE;
    node.num_children = 0;

    /* Stable partition: objects that stay first, then by child index. */
    uint32_t stay = 0, per_child[8] = { 0 };
    uint8_t *where = NULL;
    bool split = (int)node.depth < t->desc.max_depth && n > t->desc.leaf_objects;
    if (split) {
        where = malloc(n ? n : 1);
        if (!where)
            return RL_ERR_OUT_OF_MEMORY;
        for (uint32_t i = 0; i < n; ++i) {
            rl_aabb ob = d->objects[list[i]].bounds;
            int c = child_index(node.cell, ob);
            bool fits = contains(loose_of(child_cell(node.cell, c), t->desc.looseness), ob);
            where[i] = fits ? (uint8_t)c : 8;
            if (fits)
                per_child[c]++;
            else
                stay++;
        }
        split = stay < n;
    }

    /* This node's own objects go to the shared object array now. */
    node.first_object = t->num_objects;
    node.num_objects = split ? stay : n;
    for (uint32_t i = 0; i < n; ++i)
        if (!split || where[i] == 8)
            t->objects[t->num_objects++] = list[i];
    if (!split) {
        free(where);
        t->nodes[slot] = node;
        return RL_OK;
    }

    /* Children lists in list order, reusing list's storage. */
    uint32_t start[8], fill[8], acc = 0, kids = 0;
    for (int c = 0; c < 8; ++c) {
        start[c] = acc;
        fill[c] = acc;
        acc += per_child[c];
        kids += per_child[c] > 0;
    }
    uint32_t *tmp = b->scratch;   /* at least n entries, free while we copy */
    for (uint32_t i = 0; i < n; ++i)
        if (where[i] != 8)
            tmp[fill[where[i]]++] = list[i];
    memcpy(list, tmp, (size_t)acc * sizeof *list);
    free(where);

    rl_status st = grow_nodes(t, kids);
    if (st != RL_OK)
        return st;
    node.first_child = t->num_nodes;
    node.num_children = kids;
    t->nodes[slot] = node;
    uint32_t k = t->num_nodes;
    for (int c = 0; c < 8; ++c) {
        if (!per_child[c])
            continue;
        rl_octree_node *ch = &t->nodes[k++];
        memset(ch, 0, sizeof *ch);
        ch->cell = child_cell(node.cell, c);
        ch->loose = loose_of(ch->cell, t->desc.looseness);
        ch->parent = slot;
        ch->depth = node.depth + 1;
        if (ch->depth > t->depth)
            t->depth = ch->depth;
    }
    t->num_nodes = k;
    k = node.first_child;
    for (int c = 0; c < 8 && st == RL_OK; ++c)
        if (per_child[c])
            st = build_node(b, k++, list + start[c], per_child[c]);
    return st;
}

rl_status rl_octree_build(const rl_scene *scene, const rl_octree_desc *desc, rl_octree **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_octree_build: NULL argument");
    *out = NULL;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_octree_build: scene is not committed");
    rl_octree_desc p = rl_octree_desc_default();
    if (desc) {
        if (desc->max_depth < RL_OCTREE_DEPTH_ZERO || desc->max_depth > RL_OCTREE_MAX_DEPTH)
            return rl_error(RL_ERR_INVALID_ARG, "rl_octree_build: max_depth %d outside 0..%d",
                            desc->max_depth, RL_OCTREE_MAX_DEPTH);
        if (desc->looseness != 0.0f && !(desc->looseness >= 1.0f && isfinite(desc->looseness)))
            return rl_error(RL_ERR_INVALID_ARG, "rl_octree_build: looseness %g must be >= 1",
                            (double)desc->looseness);
        if (desc->max_depth != 0)
            p.max_depth = desc->max_depth == RL_OCTREE_DEPTH_ZERO ? 0 : desc->max_depth;
        if (desc->looseness != 0.0f)
            p.looseness = desc->looseness;
        if (desc->leaf_objects)
            p.leaf_objects = desc->leaf_objects;
    }

    rl_octree *t = rl_calloc(1, sizeof *t);
    uint32_t *list = rl_calloc((size_t)d->num_objects + 1, sizeof *list);
    uint32_t *scratch = rl_calloc((size_t)d->num_objects + 1, sizeof *scratch);
    rl_status st = t && list && scratch ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK) {
        t->desc = p;
        t->objects = rl_calloc((size_t)d->num_objects + 1, sizeof *t->objects);
        st = t->objects ? grow_nodes(t, 1) : RL_ERR_OUT_OF_MEMORY;
    }
    uint32_t n = 0;
    rl_aabb all = rl_aabb_empty();
    if (st == RL_OK) {
        for (uint32_t o = 0; o < d->num_objects; ++o) {
            if (d->objects[o].num_triangles == 0)
                continue;
            list[n++] = o;
            all = rl_aabb_union(all, d->objects[o].bounds);
        }
        /* The root cube: the scene's longest side, a hair larger so that
         * objects on the scene's faces lie inside every cell test. */
        rl_vec3 c = rl_scale(rl_add(all.min, all.max), 0.5f);
        rl_vec3 e = rl_sub(all.max, all.min);
        float side = rl_maxf(rl_maxf(e.x, e.y), e.z);
        float half = 0.5f * side * (1.0f + 1e-5f) + 1e-30f;
        rl_octree_node *root = &t->nodes[0];
        memset(root, 0, sizeof *root);
        root->cell = (rl_aabb){ rl_sub(c, rl_v3(half, half, half)), rl_add(c, rl_v3(half, half, half)) };
        root->loose = loose_of(root->cell, p.looseness);
        root->parent = RL_NONE;
        t->num_nodes = 1;
        builder b = { t, d, scratch };
        st = build_node(&b, 0, list, n);
    }
    free(list);
    free(scratch);
    if (st != RL_OK) {
        rl_octree_release(t);
        return rl_error(st, "rl_octree_build: %u objects", d->num_objects);
    }
    *out = t;
    return RL_OK;
}

void rl_octree_release(rl_octree *tree)
{
    if (!tree)
        return;
    free(tree->nodes);
    free(tree->objects);
    free(tree);
}

const rl_octree_node *rl_octree_nodes(const rl_octree *tree, uint32_t *count)
{
    if (count)
        *count = tree ? tree->num_nodes : 0;
    return tree ? tree->nodes : NULL;
}

const uint32_t *rl_octree_objects(const rl_octree *tree, uint32_t *count)
{
    if (count)
        *count = tree ? tree->num_objects : 0;
    return tree ? tree->objects : NULL;
}

rl_octree_desc rl_octree_get_desc(const rl_octree *tree)
{
    return tree ? tree->desc : rl_octree_desc_default();
}

uint32_t rl_octree_depth(const rl_octree *tree)
{
    return tree ? tree->depth : 0;
}

size_t rl_octree_memory_bytes(const rl_octree *tree)
{
    if (!tree)
        return 0;
    return sizeof *tree + (size_t)tree->cap_nodes * sizeof *tree->nodes +
           ((size_t)tree->num_objects + 1) * sizeof *tree->objects;
}
