/* bvh_wide.c: collapses the binary SAH BVH into a wide BVH (RL_BVH_WIDTH).
 *
 * As in multi-branching BVHs (Dammertz et al. 2008, "Shallow Bounding
 * Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays"; Wald et
 * al. 2008, "Getting Rid of Packets"): starting from a binary node's two
 * children, the inner child with the largest surface area is replaced by
 * its own two children until the node is full or only leaves are left. The
 * binary tree's leaves and triangle order are kept, so the wide tree holds
 * exactly the same leaves. One wide node costs one SIMD slab test instead
 * of up to WIDTH - 1 binary ones, and divides the depth. Serial and depth-first,
 * hence deterministic. */
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "core/error.h"

typedef struct widener {
    const rl_bvh_node *bin;
    rl_bvh_wide_node *wide;
    uint32_t count;
} widener;

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
            node->child[i] = k->index;
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
    widener w = { bvh->nodes, wide, 1 };
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
    return RL_OK;
}
