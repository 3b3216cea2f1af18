/* bvh_wide.c: collapses the binary SAH BVH into a wide BVH (RL_BVH_WIDTH).
 *
 * As in multi-branching BVHs (Dammertz et al. 2008, "Shallow Bounding
 * Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays"; Wald et
 * al. 2008, "Getting Rid of Packets"): starting from a binary node's two
 * children, the inner child with the largest surface area is replaced by
 * its own two children until the node is full or only leaves are left. The
 * binary tree's leaves and triangle order are kept, so the wide tree holds
 * exactly the same leaves (each packed into SoA blocks of RL_BVH_LANES
 * triangles for the SIMD leaf test). One wide node costs one SIMD slab test instead
 * of up to WIDTH - 1 binary ones, and divides the depth. Serial and depth-first,
 * hence deterministic. */
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "core/error.h"

typedef struct widener {
    const rl_bvh_node *bin;
    const rl_bvh_tri *tris;
    rl_bvh_wide_node *wide;
    uint32_t count;
    rl_bvh_block *blocks;
    uint32_t num_blocks;
} widener;

static uint32_t leaf_blocks(uint32_t count)
{
    return (count + RL_BVH_LANES - 1) / RL_BVH_LANES;
}

/* Packs a leaf's triangles into the next blocks; returns the first. */
static uint32_t pack_leaf(widener *w, uint32_t first, uint32_t count)
{
    uint32_t start = w->num_blocks;
    for (uint32_t i = 0; i < count; i += RL_BVH_LANES) {
        rl_bvh_block *b = &w->blocks[w->num_blocks++];
        for (uint32_t l = 0; l < RL_BVH_LANES; ++l) {
            if (i + l >= count) {   /* padding: NaN fails every comparison */
                for (int k = 0; k < 3; ++k)
                    for (int a = 0; a < 3; ++a)
                        b->p[k][a][l] = NAN;
                b->id[l] = RL_ID_NONE;
                continue;
            }
            const rl_bvh_tri *t = &w->tris[first + i + l];
            const rl_vec3 p[3] = { t->p0, t->p1, t->p2 };
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a)
                    b->p[k][a][l] = rl_vget(p[k], a);
            b->id[l] = t->id;
        }
    }
    return start;
}

static float node_area(const rl_bvh_node *n)
{
    rl_aabb b = { { n->min[0], n->min[1], n->min[2] }, { n->max[0], n->max[1], n->max[2] } };
    return rl_aabb_area(b);
}

/* Fills wide node `slot` from binary node `b` (inner, or a leaf root). */
static void widen_node(widener *w, uint32_t slot, uint32_t b)
{
    uint32_t kids[RL_BVH_WIDTH];
    int n = 0;
    const rl_bvh_node *bn = &w->bin[b];
    if (bn->count > 0) {
        kids[n++] = b;
    } else {
        kids[n++] = bn->index;
        kids[n++] = bn->index + 1;
    }
    while (n < RL_BVH_WIDTH) {
        int open = -1;
        float best = -1.0f;
        for (int i = 0; i < n; ++i) {
            const rl_bvh_node *k = &w->bin[kids[i]];
            if (k->count == 0 && node_area(k) > best) {   /* strict: first of equals */
                best = node_area(k);
                open = i;
            }
        }
        if (open < 0)
            break;
        uint32_t first = w->bin[kids[open]].index;
        kids[open] = first;
        kids[n++] = first + 1;
    }
    rl_bvh_wide_node *node = &w->wide[slot];
    *node = (rl_bvh_wide_node){ 0 };
    for (int i = 0; i < RL_BVH_WIDTH; ++i)
        for (int a = 0; a < 3; ++a) {
            node->bmin[a][i] = INFINITY;   /* empty slot: never hit */
            node->bmax[a][i] = -INFINITY;
        }
    /* Reserve the inner children's slots first so that siblings sit together. */
    uint32_t child_slot[RL_BVH_WIDTH];
    for (int i = 0; i < n; ++i) {
        const rl_bvh_node *k = &w->bin[kids[i]];
        for (int a = 0; a < 3; ++a) {
            node->bmin[a][i] = k->min[a];
            node->bmax[a][i] = k->max[a];
        }
        if (k->count > 0) {
            node->child[i] = pack_leaf(w, k->index, k->count);
            node->count[i] = (uint8_t)k->count;
        } else {
            child_slot[i] = w->count++;
            node->child[i] = child_slot[i];
        }
    }
    for (int i = 0; i < n; ++i)
        if (w->bin[kids[i]].count == 0)
            widen_node(w, child_slot[i], kids[i]);
}

/* Wide nodes on cache-line boundaries: malloc aligns large blocks to 16
 * bytes only, so a 256-byte node would touch 5 lines instead of 4. */
static rl_bvh_wide_node *alloc_wide(uint32_t count)
{
    return aligned_alloc(64, (size_t)count * sizeof(rl_bvh_wide_node));   /* a multiple of 64 */
}

rl_status rl_bvh_widen(rl_bvh *bvh)
{
    /* Every wide node consumes at least one binary inner node. */
    uint32_t bound = bvh->num_nodes / 2 + 1;
    rl_bvh_wide_node *wide = alloc_wide(bound);
    if (!wide)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for %u wide nodes", (unsigned)bound);
    uint32_t num_blocks = 0;
    for (uint32_t i = 0; i < bvh->num_nodes; ++i)
        num_blocks += leaf_blocks(bvh->nodes[i].count);
    rl_bvh_block *blocks = aligned_alloc(64, ((size_t)num_blocks * sizeof *blocks + 63) / 64 * 64);
    if (!blocks) {
        free(wide);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for %u leaf blocks", (unsigned)num_blocks);
    }
    widener w = { bvh->nodes, bvh->tris, wide, 1, blocks, 0 };
    widen_node(&w, 0, 0);
    /* Shrink by copying: realloc would not keep the alignment. */
    rl_bvh_wide_node *shrunk = w.count < bound ? alloc_wide(w.count) : NULL;
    if (shrunk) {
        memcpy(shrunk, wide, (size_t)w.count * sizeof *wide);
        free(wide);
        wide = shrunk;
    }
    free(bvh->wide);
    bvh->wide = wide;
    bvh->num_wide = w.count;
    free(bvh->blocks);
    bvh->blocks = blocks;
    bvh->num_blocks = w.num_blocks;
    return RL_OK;
}
