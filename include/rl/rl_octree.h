/* rl_octree.h: a loose octree over the objects of a committed scene, the
 * spatial hierarchy of the culling and level-of-detail renderers (chcpp,
 * svs, surfels).
 *
 * Loose octree (Ulrich 2000, "Loose Octrees"): a node's loose box is its
 * cell scaled by the enlargement factor k about the cell's centre, and an
 * object lives in the deepest node whose cell contains the centre of the
 * object's bounds and whose loose box contains all of them. With Jähn
 * 2015's k = 2.0 (Sec. 7.3) an object of size s sinks to the depth whose
 * cells are at least s wide, so big objects stay high and small ones low.
 * Depth 0 is the root cube around the scene; max_depth = 0 puts every
 * object directly under the root, as in the thesis' sweep (Fig. 7.6).
 *
 * Only non-empty nodes are stored, in depth-first order, each node's
 * children contiguous. A node is split only while it holds more than
 * leaf_objects objects (the objects that fit no child stay in it). */
#ifndef RL_OCTREE_H
#define RL_OCTREE_H

#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_OCTREE_MAX_DEPTH 20
/* max_depth value for a tree of depth 0 (0 itself means the default). */
#define RL_OCTREE_DEPTH_ZERO (-1)

typedef struct rl_octree_desc {   /* zero = default */
    int max_depth;                /* 0 -> 5 (Jähn 2015, Sec. 7.3: best for CHC++);
                                   * RL_OCTREE_DEPTH_ZERO: every object under the root */
    float looseness;              /* enlargement factor k >= 1; 0 -> 2.0 */
    uint32_t leaf_objects;        /* split nodes holding more than this; 0 -> 1 */
} rl_octree_desc;

/* rl_octree_desc with the defaults resolved (max_depth 5). */
RL_API rl_octree_desc rl_octree_desc_default(void);

typedef struct rl_octree_node {
    rl_aabb cell;                 /* the octree cell (a cube) */
    rl_aabb loose;                /* cell scaled by k about its centre */
    rl_aabb bounds;               /* tight bounds of every object in the subtree */
    uint32_t parent;              /* RL_NONE for the root */
    uint32_t first_child;         /* index of the first child; RL_NONE for a leaf */
    uint32_t num_children;        /* 0..8, contiguous */
    uint32_t first_object;        /* into rl_octree_objects() */
    uint32_t num_objects;         /* stored at this node itself */
    uint32_t subtree_objects;     /* in the node and all its descendants */
    uint64_t subtree_triangles;
    uint32_t depth;
} rl_octree_node;

typedef struct rl_octree rl_octree;

/* RL_ERR_INVALID_ARG (NULL, max_depth > RL_OCTREE_MAX_DEPTH or < RL_OCTREE_DEPTH_ZERO,
 * looseness < 1 or not finite), RL_ERR_NOT_COMMITTED, RL_ERR_OUT_OF_MEMORY.
 * Objects without triangles are left out. */
RL_API rl_status rl_octree_build(const rl_scene *scene, const rl_octree_desc *desc, rl_octree **out);
RL_API void rl_octree_release(rl_octree *tree);        /* NULL is a no-op */
/* Node 0 is the root. */
RL_API const rl_octree_node *rl_octree_nodes(const rl_octree *tree, uint32_t *count);
/* Object indices, grouped by node (rl_octree_node.first_object). */
RL_API const uint32_t *rl_octree_objects(const rl_octree *tree, uint32_t *count);
/* Defaults resolved; max_depth is the real limit (0 for RL_OCTREE_DEPTH_ZERO). */
RL_API rl_octree_desc rl_octree_get_desc(const rl_octree *tree);
RL_API uint32_t rl_octree_depth(const rl_octree *tree);            /* deepest node's depth */
RL_API size_t rl_octree_memory_bytes(const rl_octree *tree);

#ifdef __cplusplus
}
#endif
#endif
