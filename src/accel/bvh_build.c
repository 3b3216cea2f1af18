/* bvh_build.c: binned SAH BVH construction (Wald 2007, "On fast
 * Construction of SAH-based Bounding Volume Hierarchies", IEEE RT 2007).
 *
 * Per node: centroid bounds, K equal bins per axis over them (K = desc
 * bvh_bins, default 16), bin bounds and counts, one sweep
 * from each side, and the plane with the lowest SAH cost
 *     C = C_trav + C_isect · (A_L·N_L + A_R·N_R) / A
 * with C_trav = 0.5, C_isect = 1 (only the ratio matters). One binary
 * node is only part of a wide node's single SIMD slab test (bvh_wide.c), so
 * traversal is cheap next to our watertight test; the 1:2 ratio and the
 * default leaf size 2 (instead of 1:1 and 4) measured +15-25 % on
 * incoherent rays (rl bench rays, diffuse; cornell-teapot 70k and city).
 * With the SIMD leaf test (4 triangles per block, bvh_wide_traverse.c),
 * costing leaves per block and default leaf sizes 3-4 were tried: Wuson
 * gained a little, city lost (shadow -10 %), so the costs stay per triangle.
 * Termination: N <= desc bvh_leaf_size (default 2) is always a leaf; larger
 * nodes become a leaf when the best split does not beat the leaf cost
 * C_isect·N, up to RL_BVH_MAX_LEAF triangles (so a leaf may exceed
 * bvh_leaf_size when the SAH says so). Beyond that, when all centroids
 * coincide (no bins), or deeper than RL_BVH_SAH_MAX_DEPTH, we split at the
 * object median.
 *
 * Parallelism (subtrees are independent once partitioned): OpenMP
 * tasks for subtrees above TASK_MIN triangles. The result must not depend on
 * scheduling, so no node is allocated from a shared counter: a node over n
 * triangles owns the 2n - 2 slots after its children's pair in a sparse
 * array (a binary tree whose leaves partition n triangles has at most 2n - 1
 * nodes), and a serial depth-first pass then compacts the sparse array
 * into the final one with adjacent sibling pairs. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "accel/bvh.h"
#include "core/bigalloc.h"
#include "core/error.h"

#define C_TRAV 0.5f
#define DEFAULT_LEAF 2
#define C_ISECT 1.0f
#define TASK_MIN 4096u
#define MAX_BINS 256

typedef struct builder {
    const rl_aabb *tri_bounds;   /* by triangle ID */
    const rl_vec3 *centroids;    /* by triangle ID */
    uint32_t *ref;               /* triangle IDs, partitioned in place */
    rl_bvh_node *sparse;         /* 2N - 1 slots */
    uint32_t num_tris;
    int bins, leaf_size;
    rl_progress_fn progress;
    void *user;
    atomic_bool cancelled;
    atomic_uint_fast32_t nodes;  /* written sparse slots */
    atomic_uint_fast64_t done;   /* triangles in finished leaves */
    double last_report;          /* touched by OpenMP thread 0 only */
} builder;

typedef struct bin {
    rl_aabb bounds;
    uint32_t count;
} bin;

static void set_bounds(rl_bvh_node *node, rl_aabb b)
{
    node->min[0] = b.min.x; node->min[1] = b.min.y; node->min[2] = b.min.z;
    node->max[0] = b.max.x; node->max[1] = b.max.y; node->max[2] = b.max.z;
}

static void make_leaf(builder *b, uint32_t slot, uint32_t begin, uint32_t n, rl_aabb bounds)
{
    rl_bvh_node *node = &b->sparse[slot];
    set_bounds(node, bounds);
    node->index = begin;
    node->count = (uint16_t)n;
    node->axis = 0;
    atomic_fetch_add(&b->nodes, 1);
    uint64_t done = atomic_fetch_add(&b->done, n) + n;
    /* The callback need not be thread-safe: only thread 0 reports, at most
     * every 1 % (tasks land on thread 0 too, so it keeps reporting). */
    if (b->progress && omp_get_thread_num() == 0) {
        double f = (double)done / (double)b->num_tris;
        if (f - b->last_report >= 0.01) {
            b->last_report = f;
            if (!b->progress(b->user, 0.99 * f))
                atomic_store(&b->cancelled, true);
        }
    }
}

/* Wald 2007: bin index k = K(1-ε)(c - cmin)/(cmax - cmin); the
 * clamp guards the last bin against rounding. */
static inline int bin_of(float c, float cmin, float k1, int bins)
{
    int k = (int)(k1 * (c - cmin));
    return k < 0 ? 0 : (k >= bins ? bins - 1 : k);
}

typedef struct split {
    int axis, bin;               /* axis -1: none found */
    float cost;                  /* A_L·N_L + A_R·N_R */
    rl_aabb left, right;
    float cmin, k1;
} split;

static split find_split(const builder *b, uint32_t begin, uint32_t end, rl_aabb cb)
{
    split best = { .axis = -1, .cost = INFINITY };
    int K = b->bins;
    for (int axis = 0; axis < 3; ++axis) {
        float cmin = rl_vget(cb.min, axis), ext = rl_vget(cb.max, axis) - cmin;
        if (!(ext > 0.0f))
            continue;
        float k1 = (float)K * (1.0f - 1e-6f) / ext;
        bin bins[MAX_BINS];
        for (int k = 0; k < K; ++k)
            bins[k] = (bin){ rl_aabb_empty(), 0 };
        for (uint32_t i = begin; i < end; ++i) {
            uint32_t t = b->ref[i];
            int k = bin_of(rl_vget(b->centroids[t], axis), cmin, k1, K);
            bins[k].bounds = rl_aabb_union(bins[k].bounds, b->tri_bounds[t]);
            bins[k].count++;
        }
        /* Sweep from the right storing suffix boxes, then from the left. */
        rl_aabb right_box[MAX_BINS];
        uint32_t right_n[MAX_BINS];
        rl_aabb acc = rl_aabb_empty();
        uint32_t n = 0;
        for (int k = K - 1; k > 0; --k) {
            acc = rl_aabb_union(acc, bins[k].bounds);
            n += bins[k].count;
            right_box[k] = acc;
            right_n[k] = n;
        }
        acc = rl_aabb_empty();
        n = 0;
        for (int k = 1; k < K; ++k) {   /* plane between bin k-1 and bin k */
            acc = rl_aabb_union(acc, bins[k - 1].bounds);
            n += bins[k - 1].count;
            if (n == 0 || right_n[k] == 0)
                continue;
            float cost = rl_aabb_area(acc) * (float)n + rl_aabb_area(right_box[k]) * (float)right_n[k];
            if (cost < best.cost) {   /* strict: the first of equals wins, deterministically */
                best = (split){ axis, k, cost, acc, right_box[k], cmin, k1 };
            }
        }
    }
    return best;
}

static rl_aabb range_bounds(const builder *b, uint32_t begin, uint32_t end)
{
    rl_aabb box = rl_aabb_empty();
    for (uint32_t i = begin; i < end; ++i)
        box = rl_aabb_union(box, b->tri_bounds[b->ref[i]]);
    return box;
}

static void build_node(builder *b, uint32_t slot, uint32_t region, uint32_t begin, uint32_t end,
                       rl_aabb bounds, int depth)
{
    if (atomic_load_explicit(&b->cancelled, memory_order_relaxed))
        return;
    uint32_t n = end - begin;
    if (n <= (uint32_t)b->leaf_size) {
        make_leaf(b, slot, begin, n, bounds);
        return;
    }
    rl_aabb cb = rl_aabb_empty();
    for (uint32_t i = begin; i < end; ++i)
        cb = rl_aabb_grow(cb, b->centroids[b->ref[i]]);
    split s = { .axis = -1 };
    if (depth < RL_BVH_SAH_MAX_DEPTH)
        s = find_split(b, begin, end, cb);
    if (n <= RL_BVH_MAX_LEAF) {
        float area = rl_aabb_area(bounds);
        bool pays = s.axis >= 0 && (area > 0.0f ? C_TRAV + C_ISECT * s.cost / area < C_ISECT * (float)n : true);
        if (!pays) {
            make_leaf(b, slot, begin, n, bounds);
            return;
        }
    }
    uint32_t mid;
    rl_aabb left, right;
    if (s.axis >= 0) {
        uint32_t i = begin, j = end;
        while (i < j) {
            float c = rl_vget(b->centroids[b->ref[i]], s.axis);
            if (bin_of(c, s.cmin, s.k1, b->bins) < s.bin) {
                ++i;
            } else {
                uint32_t t = b->ref[i];
                b->ref[i] = b->ref[--j];
                b->ref[j] = t;
            }
        }
        mid = i;
        left = s.left;
        right = s.right;
    } else {
        /* Coinciding centroids or too deep: halve the range. */
        mid = begin + n / 2;
        left = range_bounds(b, begin, mid);
        right = range_bounds(b, mid, end);
    }
    rl_bvh_node *node = &b->sparse[slot];
    set_bounds(node, bounds);
    node->index = region;
    node->count = 0;
    node->axis = (uint16_t)(s.axis >= 0 ? s.axis : 0);
    atomic_fetch_add(&b->nodes, 1);
    uint32_t nl = mid - begin;
    /* Left subtree's own slots follow the pair; the right's follow those. */
    uint32_t left_region = region + 2, right_region = region + 2 * nl;
    if (n >= TASK_MIN) {
#pragma omp task firstprivate(b, region, left_region, begin, mid, left, depth)
        build_node(b, region, left_region, begin, mid, left, depth + 1);
    } else {
        build_node(b, region, left_region, begin, mid, left, depth + 1);
    }
    build_node(b, region + 1, right_region, mid, end, right, depth + 1);
}

typedef struct frame {
    uint32_t old_slot, new_index, depth;
} frame;

/* Depth-first compaction (sibling pairs stay adjacent) plus the statistics:
 * SAH cost = Σ_inner C_trav·A/A_root + Σ_leaf C_isect·N·A/A_root. */
static rl_status compact(const builder *b, uint32_t count, rl_bvh_node **out, rl_accel_stats *stats)
{
    rl_bvh_node *dense = rl_big_array(count, sizeof *dense, false);
    frame *stack = rl_alloc(((size_t)RL_BVH_SAH_MAX_DEPTH + 64) * 2 * sizeof *stack);
    if (!dense || !stack) {
        free(dense);
        free(stack);
        return RL_ERR_OUT_OF_MEMORY;
    }
    float root_area = rl_aabb_area((rl_aabb){ { b->sparse[0].min[0], b->sparse[0].min[1], b->sparse[0].min[2] },
                                              { b->sparse[0].max[0], b->sparse[0].max[1], b->sparse[0].max[2] } });
    double inv_root = root_area > 0.0f ? 1.0 / (double)root_area : 0.0;
    uint32_t next = 1, leaves = 0, max_depth = 0;
    double sah = 0.0;
    size_t sp = 0;
    stack[sp++] = (frame){ 0, 0, 0 };
    while (sp > 0) {
        frame f = stack[--sp];
        rl_bvh_node node = b->sparse[f.old_slot];
        rl_aabb box = { { node.min[0], node.min[1], node.min[2] }, { node.max[0], node.max[1], node.max[2] } };
        double rel_area = inv_root > 0.0 ? (double)rl_aabb_area(box) * inv_root : 1.0;
        if (f.depth > max_depth)
            max_depth = f.depth;
        if (node.count > 0) {
            ++leaves;
            sah += C_ISECT * (double)node.count * rel_area;
        } else {
            sah += C_TRAV * rel_area;
            uint32_t old_child = node.index;
            node.index = next;
            stack[sp++] = (frame){ old_child + 1, next + 1, f.depth + 1 };
            stack[sp++] = (frame){ old_child, next, f.depth + 1 };
            next += 2;
        }
        dense[f.new_index] = node;
    }
    free(stack);
    *out = dense;
    stats->nodes = count;
    stats->leaves = leaves;
    stats->max_depth = max_depth;
    stats->sah_cost = sah;
    return RL_OK;
}

rl_status rl_bvh_build(const rl_scene_data *data, const rl_accel_desc *desc, rl_bvh *bvh,
                       rl_accel_stats *stats)
{
    uint32_t N = data->num_triangles;
    if (N == 0)
        return rl_error(RL_ERR_EMPTY_SCENE, "accel bvh: the scene has no triangles");
    builder b = {
        .num_tris = N,
        .bins = desc->bvh_bins > 0 ? desc->bvh_bins : 16,
        .leaf_size = desc->bvh_leaf_size > 0 ? desc->bvh_leaf_size : DEFAULT_LEAF,
        .progress = desc->progress,
        .user = desc->user,
    };
    atomic_init(&b.cancelled, false);
    atomic_init(&b.nodes, 0);
    atomic_init(&b.done, 0);
    rl_aabb *tri_bounds = rl_big_array(N, sizeof *tri_bounds, false);
    rl_vec3 *centroids = rl_big_array(N, sizeof *centroids, false);
    uint32_t *ref = rl_big_array(N, sizeof *ref, false);
    rl_bvh_node *sparse = rl_big_array((size_t)2 * N - 1, sizeof *sparse, false);
    rl_bvh_tri *tris = rl_big_array(N, sizeof *tris, false);
    rl_bvh_node *nodes = NULL;
    rl_status st = RL_OK;
    if (!tri_bounds || !centroids || !ref || !sparse || !tris) {
        st = RL_ERR_OUT_OF_MEMORY;
        goto done;
    }
    int threads = desc->threads > 0 ? desc->threads : omp_get_max_threads();
    rl_aabb root = rl_aabb_empty();
#pragma omp parallel num_threads(threads)
    {
        rl_aabb mine = rl_aabb_empty();
#pragma omp for schedule(static)
        for (int64_t i = 0; i < (int64_t)N; ++i) {
            const uint32_t *idx = data->indices + 3 * i;
            rl_aabb box = rl_aabb_empty();
            box = rl_aabb_grow(box, data->positions[idx[0]]);
            box = rl_aabb_grow(box, data->positions[idx[1]]);
            box = rl_aabb_grow(box, data->positions[idx[2]]);
            tri_bounds[i] = box;
            centroids[i] = rl_aabb_center(box);
            ref[i] = (uint32_t)i;
            mine = rl_aabb_union(mine, box);
        }
        /* min/max are exact, so merging in any order gives the same box. */
#pragma omp critical(rl_bvh_root_bounds)
        root = rl_aabb_union(root, mine);
#pragma omp barrier
#pragma omp single
        {
            b.tri_bounds = tri_bounds;
            b.centroids = centroids;
            b.ref = ref;
            b.sparse = sparse;
            build_node(&b, 0, 1, 0, N, root, 0);
        }
    }
    if (!atomic_load(&b.cancelled) && b.progress && !b.progress(b.user, 1.0))
        atomic_store(&b.cancelled, true);
    if (atomic_load(&b.cancelled)) {
        st = rl_error(RL_ERR_CANCELLED, "accel bvh: build cancelled");
        goto done;
    }
    st = compact(&b, (uint32_t)atomic_load(&b.nodes), &nodes, stats);
    if (st)
        goto done;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int64_t i = 0; i < (int64_t)N; ++i) {
        const uint32_t *idx = data->indices + 3 * (size_t)ref[i];
        tris[i] = (rl_bvh_tri){ data->positions[idx[0]], data->positions[idx[1]], data->positions[idx[2]], ref[i] };
    }
    bvh->nodes = nodes;
    bvh->num_nodes = stats->nodes;
    bvh->wide = NULL;
    bvh->num_wide = 0;
    bvh->blocks = NULL;
    bvh->num_blocks = 0;
    bvh->tris = tris;
    bvh->num_tris = N;
    tris = NULL;
    stats->memory_bytes = (size_t)bvh->num_nodes * sizeof *nodes + (size_t)N * sizeof *bvh->tris;
done:
    free(tri_bounds);
    free(centroids);
    free(ref);
    free(sparse);
    free(tris);
    return st;
}

void rl_bvh_free(rl_bvh *bvh)
{
    if (!bvh)
        return;
    free(bvh->nodes);
    free(bvh->wide);
    free(bvh->tris);
    free(bvh->blocks);
    memset(bvh, 0, sizeof *bvh);
}
