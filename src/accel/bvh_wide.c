/* bvh_wide.c: collapses the binary SAH BVH into a wide BVH (RL_BVH_WIDTH).
 *
 * As in multi-branching BVHs (Dammertz et al. 2008, "Shallow Bounding
 * Volume Hierarchies for Fast SIMD Ray Tracing of Incoherent Rays"; Wald et
 * al. 2008, "Getting Rid of Packets") a wide node's children are a cut
 * through the binary subtree below it. Which binary nodes to open is chosen
 * by a dynamic programme that minimises the SAH cost of the wide tree
 * (plan_collapse, after Ylitie et al. 2017) instead of greedily opening the
 * largest-area inner child until the node is full: interleaved A/B (4 runs
 * each, rl bench rays) diffuse on city 0.76-0.79x -> 0.82-0.85x Embree,
 * Wuson 0.94-0.97x -> 1.03-1.04x, primary and shadow +5 %, city memory
 * 146 -> 137 MiB (fewer, fuller wide nodes), build +0.1 s. The
 * binary tree's leaves and triangle order are kept, so the wide tree holds
 * exactly the same leaves (each packed into SoA blocks of RL_BVH_LANES
 * triangles for the SIMD leaf test). One wide node costs one SIMD slab test instead
 * of up to WIDTH - 1 binary ones, and divides the depth. Serial and depth-first,
 * hence deterministic. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh.h"
#include "core/bigalloc.h"
#include "core/error.h"

typedef struct widener {
    const rl_bvh_node *bin;
    rl_bvh_leaf_source src;
    rl_bvh_wide_node *wide;
    uint32_t count;
    rl_bvh_block *blocks;
    uint32_t num_blocks;
    float *cost;       /* [binary node][k - 1]: F(n, k), see plan_collapse */
    uint8_t *split;    /* [binary node][k - 1]: slots given to the left child; 0: n is one slot */
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
            rl_vec3 p[3];
            uint32_t id;
            if (w->src.tris) {
                const rl_bvh_tri *t = &w->src.tris[first + i + l];
                p[0] = t->p0;
                p[1] = t->p1;
                p[2] = t->p2;
                id = t->id;
            } else {
                id = w->src.ids[(size_t)(first + i + l) * w->src.id_stride];
                const uint32_t *idx = w->src.data->indices + 3 * (size_t)id;
                for (int k = 0; k < 3; ++k)
                    p[k] = w->src.data->positions[idx[k]];
            }
            for (int k = 0; k < 3; ++k)
                for (int a = 0; a < 3; ++a)
                    b->p[k][a][l] = rl_vget(p[k], a);
            b->id[l] = id;
        }
    }
    return start;
}

static float node_area(const rl_bvh_node *n)
{
    rl_aabb b = { { n->min[0], n->min[1], n->min[2] }, { n->max[0], n->max[1], n->max[2] } };
    return rl_aabb_area(b);
}

/* Optimal collapse (the dynamic programme of Ylitie et al. 2017, "Efficient
 * Incoherent Ray Traversal on GPUs Through Compressed Wide BVHs", without
 * their leaf merging: the binary leaves stay the wide leaves). Under the
 * SAH a leaf costs the same wherever it hangs, so a collapse only decides
 * which binary inner nodes become wide nodes, and the cost to minimise is
 * the sum of their areas. F(n, k) = the least cost of covering n's subtree
 * with at most k child slots of the parent: F(n, 1) = area(n) + F'(n, W) for
 * an inner n (n becomes a wide node whose W slots are split between its
 * children), F(n, k) = min(F(n, 1), min_j F(l, j) + F(r, k - j)) (n is
 * opened), and 0 for a leaf. Children have higher indices than their parent
 * (bvh_build.c), so a reverse sweep sees them first. Strict comparisons:
 * the first of equal choices wins, deterministic. */
static float opened_cost(const widener *w, uint32_t n, int k, int *best_j)
{
    uint32_t l = w->bin[n].index, r = l + 1;
    float best = INFINITY;
    for (int j = 1; j < k; ++j) {
        float c = w->cost[(size_t)l * RL_BVH_WIDTH + (j - 1)] + w->cost[(size_t)r * RL_BVH_WIDTH + (k - j - 1)];
        if (c < best) {
            best = c;
            *best_j = j;
        }
    }
    return best;
}

static void plan_node(widener *w, uint32_t n)
{
    float *f = &w->cost[(size_t)n * RL_BVH_WIDTH];
    uint8_t *sp = &w->split[(size_t)n * RL_BVH_WIDTH];
    if (w->bin[n].count > 0) {
        for (int k = 0; k < RL_BVH_WIDTH; ++k) {
            f[k] = 0.0f;
            sp[k] = 0;
        }
        return;
    }
    int j = 1;
    f[0] = node_area(&w->bin[n]) + opened_cost(w, n, RL_BVH_WIDTH, &j);
    /* k = 1 never splits, so sp[0] keeps the split of n's own W slots
     * when n becomes a wide node: the cut then needs no costs, and they
     * are freed before the wide nodes and blocks are written. */
    sp[0] = (uint8_t)j;
    for (int k = 2; k <= RL_BVH_WIDTH; ++k) {
        float c = opened_cost(w, n, k, &j);
        if (c < f[0]) {
            f[k - 1] = c;
            sp[k - 1] = (uint8_t)j;
        } else {
            f[k - 1] = f[0];
            sp[k - 1] = 0;
        }
    }
}

/* Children before their parent: a post-order walk from the root, so that
 * any slot order of the binary nodes will do (the builder's own array is in
 * allocation order, where a child may sit before its parent). The stack
 * holds at most two entries per level of the binary tree (depth <
 * RL_BVH_MAX_DEPTH, bvh.h). */
static void plan_collapse(widener *w)
{
    struct { uint32_t node, children_done; } stack[2 * RL_BVH_MAX_DEPTH + 4];
    size_t sp = 0;
    stack[sp].node = 0;
    stack[sp++].children_done = 0;
    while (sp > 0) {
        --sp;
        uint32_t n = stack[sp].node;
        const rl_bvh_node *node = &w->bin[n];
        if (stack[sp].children_done || node->count > 0) {
            plan_node(w, n);
            continue;
        }
        stack[sp++].children_done = 1;
        stack[sp].node = node->index + 1;
        stack[sp++].children_done = 0;
        stack[sp].node = node->index;
        stack[sp++].children_done = 0;
    }
}

/* The child slots of binary node n given k of them (plan_collapse). */
static void cut(const widener *w, uint32_t n, int k, uint32_t *kids, int *count)
{
    int j = k > 1 ? w->split[(size_t)n * RL_BVH_WIDTH + (k - 1)] : 0;
    if (j == 0) {
        kids[(*count)++] = n;
        return;
    }
    uint32_t l = w->bin[n].index;
    cut(w, l, j, kids, count);
    cut(w, l + 1, k - j, kids, count);
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
        int j = w->split[(size_t)b * RL_BVH_WIDTH];
        cut(w, bn->index, j, kids, &n);
        cut(w, bn->index + 1, RL_BVH_WIDTH - j, kids, &n);
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

/* Cache-line aligned arrays: malloc aligns large blocks to 16 bytes only,
 * so a 256-byte node would touch 5 lines instead of 4. Large ones come on
 * huge pages (rl_big_alloc, 2 MiB-aligned); bytes is a multiple of 64. */
static void *alloc_lines(size_t bytes)
{
    return bytes >= RL_BIG_ALLOC_MIN ? rl_big_alloc(bytes, true) : aligned_alloc(64, bytes ? bytes : 64);
}

static rl_bvh_wide_node *alloc_wide(uint32_t count)
{
    return alloc_lines((size_t)count * sizeof(rl_bvh_wide_node));   /* a multiple of 64 */
}

/* Wide nodes below and including the one made from binary node b: the
 * exact size of the wide array, so it is allocated once, not allocated for
 * the bound num_nodes / 2 + 1 and copied into a smaller one. */
static uint32_t count_wide(const widener *w, uint32_t b)
{
    uint32_t kids[RL_BVH_WIDTH];
    int n = 0;
    const rl_bvh_node *bn = &w->bin[b];
    if (bn->count > 0)
        return 1;   /* a leaf root: one wide node holding it */
    int j = w->split[(size_t)b * RL_BVH_WIDTH];
    cut(w, bn->index, j, kids, &n);
    cut(w, bn->index + 1, RL_BVH_WIDTH - j, kids, &n);
    uint32_t total = 1;
    for (int i = 0; i < n; ++i)
        if (w->bin[kids[i]].count == 0)
            total += count_wide(w, kids[i]);
    return total;
}

rl_bvh_block *rl_bvh_alloc_blocks(uint32_t count)
{
    return alloc_lines(((size_t)count * sizeof(rl_bvh_block) + 63) / 64 * 64);
}

rl_status rl_bvh_collapse(const rl_bvh_node *nodes, uint32_t num_slots, uint32_t num_blocks,
                          const rl_bvh_leaf_source *src, rl_bvh_block *blocks, rl_bvh *bvh)
{
    /* Allocation order: the costs are freed before the wide nodes are
     * allocated, so these reuse their pages (first touches of fresh pages
     * are the expensive part on a VM: bvh_build.c). */
    float *cost = rl_big_alloc((size_t)num_slots * RL_BVH_WIDTH * sizeof *cost, true);
    uint8_t *split = rl_big_alloc((size_t)num_slots * RL_BVH_WIDTH, true);
    rl_bvh_block *own = blocks ? NULL : rl_bvh_alloc_blocks(num_blocks);
    if (!blocks)
        blocks = own;
    if (!cost || !split || !blocks) {
        free(cost);
        free(split);
        free(own);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for the collapse of %u nodes",
                        (unsigned)num_slots);
    }
    widener w = { nodes, *src, NULL, 1, blocks, 0, cost, split };
    plan_collapse(&w);
    free(cost);
    w.cost = NULL;
    uint32_t num_wide = count_wide(&w, 0);
    rl_bvh_wide_node *wide = alloc_wide(num_wide);
    if (!wide) {
        free(split);
        free(own);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for %u wide nodes", (unsigned)num_wide);
    }
    w.wide = wide;
    widen_node(&w, 0, 0);
    free(split);
    free(bvh->wide);
    bvh->wide = wide;
    bvh->num_wide = w.count;
    free(bvh->blocks);
    bvh->blocks = blocks;
    bvh->num_blocks = w.num_blocks;
    return RL_OK;
}

rl_status rl_bvh_widen(rl_bvh *bvh)
{
    uint32_t num_blocks = 0;
    for (uint32_t i = 0; i < bvh->num_nodes; ++i)
        num_blocks += leaf_blocks(bvh->nodes[i].count);
    rl_bvh_leaf_source src = { .tris = bvh->tris };
    return rl_bvh_collapse(bvh->nodes, bvh->num_nodes, num_blocks, &src, NULL, bvh);
}
