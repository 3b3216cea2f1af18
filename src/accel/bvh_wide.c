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
    const rl_bvh_tri *tris;
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

static void plan_collapse(widener *w, uint32_t num_nodes)
{
    for (uint32_t n = num_nodes; n-- > 0;) {
        float *f = &w->cost[(size_t)n * RL_BVH_WIDTH];
        uint8_t *sp = &w->split[(size_t)n * RL_BVH_WIDTH];
        if (w->bin[n].count > 0) {
            for (int k = 0; k < RL_BVH_WIDTH; ++k) {
                f[k] = 0.0f;
                sp[k] = 0;
            }
            continue;
        }
        int j = 1;
        f[0] = node_area(&w->bin[n]) + opened_cost(w, n, RL_BVH_WIDTH, &j);
        sp[0] = 0;
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
        int j = 1;
        opened_cost(w, b, RL_BVH_WIDTH, &j);
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
    rl_bvh_block *blocks = alloc_lines(((size_t)num_blocks * sizeof *blocks + 63) / 64 * 64);
    if (!blocks) {
        free(wide);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for %u leaf blocks", (unsigned)num_blocks);
    }
    float *cost = rl_big_alloc((size_t)bvh->num_nodes * RL_BVH_WIDTH * sizeof *cost, true);
    uint8_t *split = rl_big_alloc((size_t)bvh->num_nodes * RL_BVH_WIDTH, true);
    if (!cost || !split) {
        free(cost);
        free(split);
        free(wide);
        free(blocks);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for the collapse of %u nodes",
                        (unsigned)bvh->num_nodes);
    }
    widener w = { bvh->nodes, bvh->tris, wide, 1, blocks, 0, cost, split };
    plan_collapse(&w, bvh->num_nodes);
    widen_node(&w, 0, 0);
    free(cost);
    free(split);
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
