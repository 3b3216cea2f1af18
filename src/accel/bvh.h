/* bvh.h: the BVH shared by its builder (bvh_build.c), the wide collapse
 * (bvh_wide.c), the traversal (bvh_wide_traverse.c) and its rl_accel class
 * (bvh.c).
 *
 * Layout for cache-friendly traversal: the binary build tree has 32-byte
 * nodes in one array, the two children of an inner node adjacent (index,
 * index + 1); the wide tree has 32 bytes per child (whole cache lines); the
 * build copies the leaves' triangles in leaf order into an array of vertex
 * triples (tris), which the widening packs into SoA blocks (blocks) and
 * bvh.c then frees: traversal reads only the wide nodes and the blocks. */
#ifndef RL_ACCEL_BVH_H
#define RL_ACCEL_BVH_H

#include <stdint.h>

#include "accel/accel_internal.h"

/* Above this depth the builder only halves (object median), so that the
 * traversal stack can never overflow: binary depth <= 48 + 31 = 79, and a
 * wide node pushes at most 3 entries per level. */
#define RL_BVH_SAH_MAX_DEPTH 48
#define RL_BVH_MAX_DEPTH 96
/* Children per wide node: 8 where AVX tests them in one go, else 4 (SSE). */
#if defined(__AVX__)
#define RL_BVH_WIDTH 8
#else
#define RL_BVH_WIDTH 4
#endif
#define RL_BVH_WIDE_STACK ((RL_BVH_WIDTH - 1) * RL_BVH_MAX_DEPTH)
/* SAH leaves may hold up to this many triangles when no split pays off. */
#define RL_BVH_MAX_LEAF 16

typedef struct rl_bvh_node {
    float min[3];
    uint32_t index;           /* inner: first child; leaf: first triangle */
    float max[3];
    uint16_t count;           /* triangles in a leaf; 0 for an inner node */
    uint16_t axis;            /* inner: split axis, orders the children */
} rl_bvh_node;

typedef struct rl_bvh_tri {
    rl_vec3 p0, p1, p2;
    uint32_t id;              /* scene triangle ID */
} rl_bvh_tri;

/* A leaf's triangles as structure of arrays, RL_BVH_LANES per block, so
 * that one SIMD watertight test covers a block (bvh_wide_traverse.c; as
 * Embree's Triangle4). A leaf of n triangles owns ceil(n / LANES)
 * consecutive blocks; unused lanes are all-NaN: NaN fails every
 * comparison, so such a lane never hits. */
#define RL_BVH_LANES 4
typedef struct rl_bvh_block {
    float p[3][3][RL_BVH_LANES];     /* [vertex][axis][lane] */
    uint32_t id[RL_BVH_LANES];       /* scene triangle ID; RL_ID_NONE in padding */
} rl_bvh_block;

/* Wide node collapsed from the binary tree (bvh_wide.c), bounds as
 * structure of arrays so that one SIMD slab test covers all children.
 * Unused slots have inverted bounds (min +inf, max -inf): never hit. */
typedef struct rl_bvh_wide_node {
    float bmin[3][RL_BVH_WIDTH];     /* [axis][child] */
    float bmax[3][RL_BVH_WIDTH];
    uint32_t child[RL_BVH_WIDTH];    /* inner: wide node index; leaf: first block */
    uint8_t count[RL_BVH_WIDTH];     /* leaf: triangles (> 0); inner: 0 */
    uint8_t pad[3 * RL_BVH_WIDTH];   /* 32 bytes per child: whole cache lines */
} rl_bvh_wide_node;
_Static_assert(sizeof(rl_bvh_wide_node) == 32 * RL_BVH_WIDTH, "wide node fills whole cache lines");

typedef struct rl_bvh {
    rl_bvh_node *nodes;       /* binary tree, NULL once widened and dropped */
    uint32_t num_nodes;
    rl_bvh_wide_node *wide;       /* wide tree the traversal uses, or NULL */
    uint32_t num_wide;
    rl_bvh_tri *tris;             /* leaf order; NULL once packed and dropped */
    uint32_t num_tris;
    rl_bvh_block *blocks;         /* leaves in SoA blocks (rl_bvh_widen) */
    uint32_t num_blocks;
} rl_bvh;

/* Binned SAH build (Wald 2007); fills nodes, leaves, max_depth, sah_cost and
 * memory_bytes of *stats. RL_ERR_OUT_OF_MEMORY, RL_ERR_CANCELLED; *bvh is
 * untouched on failure. */
rl_status rl_bvh_build(const rl_scene_data *data, const rl_accel_desc *desc, rl_bvh *bvh,
                       rl_accel_stats *stats);
void rl_bvh_free(rl_bvh *bvh);
/* Collapses the binary tree into bvh->wide (deterministic: the cut of least
 * SAH cost, bvh_wide.c) and packs the leaves into bvh->blocks, in leaf order.
 * RL_ERR_OUT_OF_MEMORY. */
rl_status rl_bvh_widen(rl_bvh *bvh);
/* rl_bvh_build and rl_bvh_widen in one, for RL_ACCEL_BVH: the same wide
 * tree and blocks, bit for bit, but neither the depth-first binary array
 * nor the triangle copies are made (bvh->nodes and bvh->tris stay NULL):
 * the collapse reads the builder's own node array and packs the blocks
 * straight from the scene, which saves writing (and first touching) about
 * 100 MB on city. stats as rl_bvh_build's, memory_bytes that of the wide
 * nodes and the blocks. */
rl_status rl_bvh_build_wide(const rl_scene_data *data, const rl_accel_desc *desc, rl_bvh *bvh,
                            rl_accel_stats *stats);

/* Between bvh_build.c and bvh_wide.c: where the collapse reads a leaf's
 * triangles, tris[first..] or else the scene triangles
 * ids[first * id_stride], ids[(first + 1) * id_stride], ... of data. */
typedef struct rl_bvh_leaf_source {
    const rl_bvh_tri *tris;
    const uint32_t *ids;
    size_t id_stride;
    const rl_scene_data *data;
} rl_bvh_leaf_source;
/* Collapses the binary tree in nodes[0..num_slots) (root at 0; sibling
 * pairs adjacent, in any order otherwise; slots that no path from the
 * root reaches are ignored) whose leaves need num_blocks blocks in all,
 * into bvh->wide and bvh->blocks (replacing them). blocks: an array from
 * rl_bvh_alloc_blocks(num_blocks) that the collapse takes over on success
 * (the caller frees it on failure), or NULL to allocate one.
 * RL_ERR_OUT_OF_MEMORY. */
rl_bvh_block *rl_bvh_alloc_blocks(uint32_t count);
rl_status rl_bvh_collapse(const rl_bvh_node *nodes, uint32_t num_slots, uint32_t num_blocks,
                          const rl_bvh_leaf_source *src, rl_bvh_block *blocks, rl_bvh *bvh);

/* Traversal of the wide tree (bvh_wide_traverse.c). */
bool rl_bvh_wide_intersect(const rl_bvh *bvh, rl_ray *ray, rl_hit *hit);
bool rl_bvh_wide_occluded(const rl_bvh *bvh, const rl_ray *ray);
/* rl_bvh_wide_occluded naming the first blocking triangle it met. */
bool rl_bvh_wide_occluder(const rl_bvh *bvh, const rl_ray *ray, uint32_t *triangle);

#endif
