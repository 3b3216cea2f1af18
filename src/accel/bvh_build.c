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
 * gained a little, city lost (shadow -10 %), so the costs stay per triangle
 * by default. desc bvh_block_cost = 1 counts blocks instead, as Embree's
 * builder does: the cost of n triangles is C_isect·ceil(n/4), in the sweep
 * and in the leaf test, and leaves hold up to BLOCK_MAX_LEAF triangles
 * (two blocks). Measured on 2026-12-06 (bench/README.md, "Diffuse rays
 * against Embree", interleaved, CPU-time ratios to Embree): memory 104 ->
 * 58 B/triangle on city, build 1.52x -> 0.79x Embree's, diffuse rays
 * spider.obj 0.81x -> 0.91x, teapots.DAE 0.90x -> 0.98x, but city 0.75x
 * -> 0.73x and cornell 1.46x -> 1.14x (larger leaves are hit more often,
 * and the chain of node fetches, where the time goes, is not shorter), so
 * it is not the default.
 * Termination: N <= desc bvh_leaf_size (default 2) is always a leaf; larger
 * nodes become a leaf when the best split does not beat the leaf cost
 * C_isect·N (C_isect·ceil(N/4) with block costs), up to RL_BVH_MAX_LEAF
 * triangles (BLOCK_MAX_LEAF with block costs; so a leaf may exceed
 * bvh_leaf_size when the SAH says so). Beyond that, when all centroids
 * coincide (no bins), or deeper than RL_BVH_SAH_MAX_DEPTH, we split at the
 * object median.
 *
 * Parallelism (subtrees are independent once partitioned): OpenMP
 * tasks for subtrees above TASK_MIN triangles. Each thread takes the slots
 * of the node pairs it creates from chunks of a shared counter, so which
 * slot a node gets depends on the scheduling; the tree itself does not (the
 * partitions and splits are a function of the triangles alone), and a
 * serial depth-first pass lays it out (compact) or the collapse walks it
 * from the root (rl_bvh_build_wide), so the result is the same for any
 * schedule and thread count.
 *
 * Speed (issue 37, bench/README.md "BVH build time", 2026-12-06): the
 * triangles' boxes are 32-byte records sorted in place (no index array
 * into separate box and centroid arrays, whose gathers slowed the binning,
 * 38 % of the build's CPU time on city); one pass bins all three axes; the children's centroid
 * boxes come from the partition; RL_ACCEL_BVH makes neither the
 * depth-first binary array nor the triangle copies. Second pass
 * (bench/README.md "BVH build time, second pass"): nodes of up to SMALL_MAX triangles bin only
 * their occupied bins, the top levels bin in chunks on all threads, and
 * the triangle records lie in the blocks' array (build_wide), whose
 * pages they touch first. Every step keeps the tree bit for bit. */
#include <math.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "accel/bvh.h"
#include "core/bigalloc.h"
#include "core/error.h"

#define C_TRAV 0.5f
#define DEFAULT_LEAF 2
#define C_ISECT 1.0f
#define BLOCK_MAX_LEAF 8
#define TASK_MIN 4096u
#define MAX_BINS 256
/* Node pairs are handed out to each thread in chunks of this many slots
 * (even, so a pair never straddles two chunks). */
#define SLOT_CHUNK 4096u
/* Below this many triangles the build runs on one thread: waking and
 * waiting for a second one costs more than it saves on the shared 2-core
 * VM, where the first thread spins in OpenMP's barriers while the second
 * waits for a core. Measured there on 2026-12-06 (load 7-13, build ms,
 * one thread vs two, interleaved): cornell (36 triangles) 0.1 vs 70-95
 * (nearly all of it libgomp's spin loop), cornell-teapot 70k 39-64 vs
 * 62-120, 2CylinderEngine.glb 110k 113-168 vs 160-196, city 1.38M
 * 1,781-1,824 vs 1,603-1,709. On an idle machine the crossover is likely
 * lower. Rechecked with the top levels binned on both threads (load
 * 24-28, 6 interleaved builds each, wall ms medians, one vs two threads):
 * cornell-teapot 70k 190 vs 217, 2CylinderEngine.glb 289 vs 366, so the
 * threshold stays. The tree does not depend on the thread count. */
#define PARALLEL_MIN 262144u
/* Nodes of up to SMALL_MAX triangles (with K <= 64 bins) bin without
 * clearing all 3K bins and without scanning them for the occupied ones:
 * a first pass computes the bin indices and a bit mask of the occupied
 * bins per axis, only those bins are cleared, and the sweep walks the
 * mask's bits. The bins, hence costs, plane and child boxes, are those
 * of the full binning bit for bit (the same min, max and counts in the
 * same order). Most nodes of a tree with leaves of 2 are this small, and
 * for them clearing and scanning 3K bins cost more than the binning. */
#define SMALL_MAX 32
/* Nodes of at least this many triangles (the top levels) bin in chunks on
 * all build threads, merged afterwards (min, max and counts are exact, so
 * the bins are those of one pass): otherwise the root's binning, over all
 * triangles, and the next levels' run on one thread while the other waits
 * for the first subtree task. */
#define PAR_BIN_MIN 65536u
#define PAR_BIN_CHUNKS 8

/* One triangle's box, 32 bytes, read as two 4-float vectors: the build
 * sorts these in place instead of an index array into separate box and
 * centroid arrays, so binning and partitioning stream through memory
 * instead of gathering. The centroid is recomputed as (lo + hi) / 2, exactly what
 * rl_aabb_center gives, so the tree is bit for bit the one of before. */
typedef struct prim {
    float lo[3];
    float zero;              /* 0: keeps the fourth lane of lo harmless */
    float hi[3];
    uint32_t id;             /* scene triangle ID */
} prim;
_Static_assert(sizeof(prim) == 32, "prim is two vectors");

/* Per-thread source of node-pair slots (SLOT_CHUNK at a time from a shared
 * counter); a cache line each so that the threads do not share one. */
typedef struct cursor {
    uint32_t next, end;
    uint32_t pairs;          /* pairs handed out by this thread */
    uint32_t blocks;         /* leaf blocks of the leaves it made */
    uint8_t pad[48];
} cursor;

typedef struct builder {
    prim *prims;                 /* partitioned in place */
    rl_bvh_node *sparse;         /* node pairs in allocation order */
    cursor *cursors;             /* one per thread */
    uint32_t num_tris;
    int bins, leaf_size;
    bool block_cost;             /* desc bvh_block_cost: leaves cost per SoA block */
    uint32_t max_leaf;           /* largest leaf the SAH may choose */
    int threads;
    uint32_t small_max, par_bin_min;
    rl_progress_fn progress;
    void *user;
    atomic_bool cancelled;
    atomic_uint_fast32_t next_slot;
    atomic_uint_fast64_t done;   /* triangles in finished leaves (with progress only) */
    double last_report;          /* touched by OpenMP thread 0 only */
} builder;

/* Four floats, the last one unused: SSE where there is SSE2, else scalar
 * (identical results: the same IEEE operations per lane, min/max as
 * rl_minf/rl_maxf, a < b ? a : b). */
#if defined(__SSE2__)
typedef __m128 v4;
static inline v4 v4_load(const float *p) { return _mm_load_ps(p); }
static inline v4 v4_set1(float a) { return _mm_set1_ps(a); }
static inline v4 v4_add(v4 a, v4 b) { return _mm_add_ps(a, b); }
static inline v4 v4_sub(v4 a, v4 b) { return _mm_sub_ps(a, b); }
static inline v4 v4_mul(v4 a, v4 b) { return _mm_mul_ps(a, b); }
static inline v4 v4_min(v4 a, v4 b) { return _mm_min_ps(a, b); }
static inline v4 v4_max(v4 a, v4 b) { return _mm_max_ps(a, b); }
static inline v4 v4_make(float x, float y, float z) { return _mm_setr_ps(x, y, z, 0.0f); }
static inline void v4_store(float *out, v4 a) { _mm_storeu_ps(out, a); }
static inline v4 v4_clear3(v4 a) { return _mm_and_ps(a, _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0))); }
/* (int) of each lane (truncation, as the scalar cast). */
static inline void v4_trunc(v4 a, int32_t out[4]) { _mm_storeu_si128((__m128i *)out, _mm_cvttps_epi32(a)); }
#else
typedef struct v4 { float v[4]; } v4;
static inline v4 v4_load(const float *p) { return (v4){ { p[0], p[1], p[2], p[3] } }; }
static inline v4 v4_set1(float a) { return (v4){ { a, a, a, a } }; }
#define V4_OP(name, expr) \
    static inline v4 name(v4 a, v4 b) { v4 r; for (int i = 0; i < 4; ++i) { float x = a.v[i], y = b.v[i]; r.v[i] = (expr); } return r; }
V4_OP(v4_add, x + y)
V4_OP(v4_sub, x - y)
V4_OP(v4_mul, x * y)
V4_OP(v4_min, x < y ? x : y)
V4_OP(v4_max, x > y ? x : y)
#undef V4_OP
static inline v4 v4_make(float x, float y, float z) { return (v4){ { x, y, z, 0.0f } }; }
static inline void v4_store(float *out, v4 a) { memcpy(out, a.v, sizeof a.v); }
static inline v4 v4_clear3(v4 a) { a.v[3] = 0.0f; return a; }
static inline void v4_trunc(v4 a, int32_t out[4])
{
    for (int i = 0; i < 4; ++i)   /* out of int range: INT32_MIN, as cvttps2dq */
        out[i] = a.v[i] > -2147483520.0f && a.v[i] < 2147483520.0f ? (int32_t)a.v[i] : INT32_MIN;
}
#endif

static inline v4 prim_lo(const prim *p) { return v4_load(p->lo); }
/* Lane 3 holds the ID's bits, which read as a float are mostly denormals:
 * arithmetic on them is slow (a microcode assist per operation, which made
 * the binning 2.5x slower), so the lane is cleared. */
static inline v4 prim_hi(const prim *p) { return v4_clear3(v4_load(p->hi)); }
/* rl_aabb_center's (min + max) * 0.5f per axis; lane 3 is 0. */
static inline v4 prim_centroid(const prim *p) { return v4_mul(v4_add(prim_lo(p), prim_hi(p)), v4_set1(0.5f)); }

static rl_aabb v4_box(v4 lo, v4 hi)
{
    float l[4], h[4];
    v4_store(l, lo);
    v4_store(h, hi);
    return (rl_aabb){ { l[0], l[1], l[2] }, { h[0], h[1], h[2] } };
}

static void set_bounds(rl_bvh_node *node, rl_aabb b)
{
    node->min[0] = b.min.x; node->min[1] = b.min.y; node->min[2] = b.min.z;
    node->max[0] = b.max.x; node->max[1] = b.max.y; node->max[2] = b.max.z;
}

static uint32_t leaf_blocks(uint32_t count)
{
    return (count + RL_BVH_LANES - 1) / RL_BVH_LANES;
}

static void make_leaf(builder *b, uint32_t slot, uint32_t begin, uint32_t n, rl_aabb bounds)
{
    rl_bvh_node *node = &b->sparse[slot];
    set_bounds(node, bounds);
    node->index = begin;
    node->count = (uint16_t)n;
    node->axis = 0;
    b->cursors[omp_get_thread_num()].blocks += leaf_blocks(n);   /* the collapse's block count */
    if (!b->progress)
        return;
    uint64_t done = atomic_fetch_add(&b->done, n) + n;
    /* The callback need not be thread-safe: only thread 0 reports, at most
     * every 1 % (tasks land on thread 0 too, so it keeps reporting). */
    if (omp_get_thread_num() == 0) {
        double f = (double)done / (double)b->num_tris;
        if (f - b->last_report >= 0.01) {
            b->last_report = f;
            if (!b->progress(b->user, 0.99 * f))
                atomic_store(&b->cancelled, true);
        }
    }
}

/* Two adjacent slots for the children of a split node. Which slots a node
 * gets depends on the scheduling; compact() then lays the tree out depth
 * first, so the final array does not. A tied OpenMP task stays on its
 * thread, and there is no scheduling point in here. */
static uint32_t alloc_pair(builder *b)
{
    cursor *c = &b->cursors[omp_get_thread_num()];
    if (c->next == c->end) {
        c->next = (uint32_t)atomic_fetch_add(&b->next_slot, SLOT_CHUNK);
        c->end = c->next + SLOT_CHUNK;
    }
    uint32_t slot = c->next;
    c->next += 2;
    c->pairs++;
    return slot;
}

/* Wald 2007: bin index k = K(1-ε)(c - cmin)/(cmax - cmin); the
 * clamp guards the last bin against rounding. */
static inline int bin_of(float c, float cmin, float k1, int bins)
{
    int k = (int)(k1 * (c - cmin));
    return k < 0 ? 0 : (k >= bins ? bins - 1 : k);
}

static inline int clamp_bin(int32_t k, int bins)
{
    return k < 0 ? 0 : (k >= bins ? bins - 1 : k);
}

typedef struct split {
    int axis, bin;               /* axis -1: none found */
    float cost;                  /* A_L·N_L + A_R·N_R */
    rl_aabb left, right;
    float cmin, k1;
} split;

typedef struct bin_set {
    v4 lo[3][MAX_BINS], hi[3][MAX_BINS];
    uint32_t count[3][MAX_BINS];
} bin_set;

static void bins_clear(bin_set *bs, int K)
{
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < K; ++k) {
            bs->lo[a][k] = v4_set1(INFINITY);
            bs->hi[a][k] = v4_set1(-INFINITY);
            bs->count[a][k] = 0;
        }
}

static inline void bin_prim(bin_set *bs, const prim *p, v4 vmin, v4 vk1, int K)
{
    v4 lo = prim_lo(p), hi = prim_hi(p);
    int32_t k[4];
    v4_trunc(v4_mul(vk1, v4_sub(v4_mul(v4_add(lo, hi), v4_set1(0.5f)), vmin)), k);
    for (int a = 0; a < 3; ++a) {
        int j = clamp_bin(k[a], K);
        bs->lo[a][j] = v4_min(bs->lo[a][j], lo);
        bs->hi[a][j] = v4_max(bs->hi[a][j], hi);
        bs->count[a][j]++;
    }
}

/* into = min/max/sum of into and from, per bin. min and max keep the later
 * operand of equals (a < b ? a : b), which matters for +0 and -0 only: a
 * fold over a sequence keeps the last of its equal extremes, so merging
 * consecutive parts in order gives the bins of one pass, bit for bit. */
static void bins_merge(bin_set *into, const bin_set *from, int K)
{
    for (int a = 0; a < 3; ++a)
        for (int k = 0; k < K; ++k) {
            into->lo[a][k] = v4_min(into->lo[a][k], from->lo[a][k]);
            into->hi[a][k] = v4_max(into->hi[a][k], from->hi[a][k]);
            into->count[a][k] += from->count[a][k];
        }
}

/* Bins [lo, hi) into even (offsets from `from` even) and odd, both cleared
 * first: the alternation of bin_range below. */
static void bin_pairs(const builder *b, uint32_t from, uint32_t lo, uint32_t hi, v4 vmin, v4 vk1, bin_set *even,
                      bin_set *odd)
{
    int K = b->bins;
    bins_clear(even, K);
    bins_clear(odd, K);
    uint32_t i = lo;
    if (i < hi && ((i - from) & 1u))
        bin_prim(odd, &b->prims[i++], vmin, vk1, K);
    for (; i + 1 < hi; i += 2) {
        bin_prim(even, &b->prims[i], vmin, vk1, K);
        bin_prim(odd, &b->prims[i + 1], vmin, vk1, K);
    }
    if (i < hi)
        bin_prim(even, &b->prims[i], vmin, vk1, K);
}

/* One pass over the range bins every triangle on all three axes at once
 * (the same bin index per axis as bin_of: k1·(c - cmin), truncated). Long
 * ranges alternate between two bin sets, merged at the end (min, max and
 * counts are exact, so the bins are the same): neighbouring triangles
 * mostly fall into the same bin, and each update would otherwise wait for
 * the previous one's store. */
static void bin_range(const builder *b, uint32_t begin, uint32_t end, const float cmin[3], const float k1[3],
                      bin_set *bs, bin_set *spare)
{
    int K = b->bins;
    v4 vmin = v4_make(cmin[0], cmin[1], cmin[2]), vk1 = v4_make(k1[0], k1[1], k1[2]);
    if (end - begin < 256) {
        bins_clear(bs, K);
        for (uint32_t i = begin; i < end; ++i)
            bin_prim(bs, &b->prims[i], vmin, vk1, K);
        return;
    }
    bin_pairs(b, begin, begin, end, vmin, vk1, bs, spare);
    bins_merge(bs, spare, K);
}

/* bin_range over PAR_BIN_CHUNKS chunks as OpenMP tasks (any thread of the
 * team takes any chunk; the one waiting runs chunks itself). Each chunk
 * keeps bin_range's two alternating sets apart; the even sets are merged
 * in chunk order, the odd ones too, then odd into even, as bin_range does:
 * the bins of one pass bit for bit (bins_merge), whatever the schedule.
 * Without memory for the chunks' bins it is bin_range. */
static void bin_range_parallel(const builder *b, uint32_t begin, uint32_t end, const float cmin[3],
                               const float k1[3], bin_set *bs, bin_set *spare)
{
    bin_set *parts = malloc(2 * PAR_BIN_CHUNKS * sizeof *parts);
    if (!parts) {
        bin_range(b, begin, end, cmin, k1, bs, spare);
        return;
    }
    v4 vmin = v4_make(cmin[0], cmin[1], cmin[2]), vk1 = v4_make(k1[0], k1[1], k1[2]);
    uint32_t n = end - begin;
    for (int c = 0; c < PAR_BIN_CHUNKS; ++c) {
        uint32_t lo = begin + (uint32_t)((uint64_t)n * (uint64_t)c / PAR_BIN_CHUNKS);
        uint32_t hi = begin + (uint32_t)((uint64_t)n * (uint64_t)(c + 1) / PAR_BIN_CHUNKS);
#pragma omp task firstprivate(b, begin, lo, hi, c, vmin, vk1, parts)
        bin_pairs(b, begin, lo, hi, vmin, vk1, &parts[2 * c], &parts[2 * c + 1]);
    }
#pragma omp taskwait
    for (int c = 1; c < PAR_BIN_CHUNKS; ++c) {
        bins_merge(&parts[0], &parts[2 * c], b->bins);
        bins_merge(&parts[1], &parts[2 * c + 1], b->bins);
    }
    bins_merge(&parts[0], &parts[1], b->bins);
    memcpy(bs, &parts[0], sizeof *bs);
    free(parts);
}

/* The SAH cost term A·N of a box given as two vectors: rl_aabb_area of
 * the same box, so the costs are bit for bit those of before. */
static inline float v4_area(v4 lo, v4 hi)
{
    return rl_aabb_area(v4_box(lo, hi));
}

/* Keeps the cheaper of a candidate plane (strict: the first of equal
 * costs wins, deterministically, in the order axis 0..2, planes left to
 * right, as the sweep over the bins visits them). */
static inline void consider(split *best, int axis, int bin, float cost, v4 llo, v4 lhi, v4 rlo, v4 rhi,
                            float cmin, float k1)
{
    if (cost < best->cost)
        *best = (split){ axis, bin, cost, v4_box(llo, lhi), v4_box(rlo, rhi), cmin, k1 };
}

/* The SAH's intersection count of n triangles: n, or with block costs the
 * blocks of RL_BVH_LANES they fill (a block costs one SIMD test). */
static inline float isect_units(uint32_t n, bool block_cost)
{
    return block_cost ? (float)((n + RL_BVH_LANES - 1) / RL_BVH_LANES) : (float)n;
}

/* The SAH sweep over one axis's occupied bins used[0..m) (ascending):
 * planes between two of them with only empty bins in between all split
 * alike, at the same cost, and the strict comparison keeps the first of
 * them, the one right after the left bin, so only that one is evaluated
 * (bit for bit the choice of a sweep over all K - 1 planes; deep nodes of
 * a few triangles fill only a few of the K bins). Suffix boxes from the
 * right, then the planes from the left; the boxes stay vectors (union =
 * min/max, exact). */
static void sweep_axis(split *best, int axis, const v4 *blo, const v4 *bhi, const uint32_t *bcnt, const int *used,
                       int m, float cmin, float k1, bool block_cost)
{
    v4 rlo[MAX_BINS], rhi[MAX_BINS];
    uint32_t right_n[MAX_BINS];
    v4 alo = v4_set1(INFINITY), ahi = v4_set1(-INFINITY);
    uint32_t cnt = 0;
    for (int u = m - 1; u > 0; --u) {
        int k = used[u];
        alo = v4_min(alo, blo[k]);
        ahi = v4_max(ahi, bhi[k]);
        cnt += bcnt[k];
        rlo[u] = alo;
        rhi[u] = ahi;
        right_n[u] = cnt;
    }
    alo = v4_set1(INFINITY);
    ahi = v4_set1(-INFINITY);
    cnt = 0;
    for (int u = 1; u < m; ++u) {   /* plane right after bin used[u - 1] */
        int k = used[u - 1];
        alo = v4_min(alo, blo[k]);
        ahi = v4_max(ahi, bhi[k]);
        cnt += bcnt[k];
        float cost = v4_area(alo, ahi) * isect_units(cnt, block_cost) +
                     v4_area(rlo[u], rhi[u]) * isect_units(right_n[u], block_cost);
        consider(best, axis, k + 1, cost, alo, ahi, rlo[u], rhi[u], cmin, k1);
    }
}


static split find_split_small(const builder *b, uint32_t begin, uint32_t end, const float cmin[3],
                              const float k1[3], const bool live[3])
{
    split best = { .axis = -1, .cost = INFINITY };
    int K = b->bins;
    uint32_t n = end - begin;
    v4 lo[SMALL_MAX], hi[SMALL_MAX];
    uint8_t key[SMALL_MAX][3];
    uint64_t mask[3] = { 0, 0, 0 };
    v4 blo[3][64], bhi[3][64];
    uint32_t bcnt[3][64];
    v4 vmin = v4_make(cmin[0], cmin[1], cmin[2]), vk1 = v4_make(k1[0], k1[1], k1[2]);
    for (uint32_t i = 0; i < n; ++i) {
        const prim *p = &b->prims[begin + i];
        lo[i] = prim_lo(p);
        hi[i] = prim_hi(p);
        int32_t k[4];   /* bin_prim's index, computed the same way */
        v4_trunc(v4_mul(vk1, v4_sub(v4_mul(v4_add(lo[i], hi[i]), v4_set1(0.5f)), vmin)), k);
        for (int a = 0; a < 3; ++a) {
            int j = clamp_bin(k[a], K);
            key[i][a] = (uint8_t)j;
            mask[a] |= (uint64_t)1 << j;
        }
    }
    for (int a = 0; a < 3; ++a)
        for (uint64_t m = mask[a]; m; m &= m - 1) {
            int j = __builtin_ctzll(m);
            blo[a][j] = v4_set1(INFINITY);
            bhi[a][j] = v4_set1(-INFINITY);
            bcnt[a][j] = 0;
        }
    for (uint32_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            int j = key[i][a];
            blo[a][j] = v4_min(blo[a][j], lo[i]);
            bhi[a][j] = v4_max(bhi[a][j], hi[i]);
            bcnt[a][j]++;
        }
    for (int axis = 0; axis < 3; ++axis) {
        if (!live[axis])
            continue;
        int used[SMALL_MAX], m = 0;
        for (uint64_t bits = mask[axis]; bits; bits &= bits - 1)
            used[m++] = __builtin_ctzll(bits);
        sweep_axis(&best, axis, blo[axis], bhi[axis], bcnt[axis], used, m, cmin[axis], k1[axis], b->block_cost);
    }
    return best;
}

static split find_split(const builder *b, uint32_t begin, uint32_t end, rl_aabb cb)
{
    split best = { .axis = -1, .cost = INFINITY };
    int K = b->bins;
    float cmin[3], k1[3];
    bool live[3], any = false;
    for (int axis = 0; axis < 3; ++axis) {
        cmin[axis] = rl_vget(cb.min, axis);
        float ext = rl_vget(cb.max, axis) - cmin[axis];
        live[axis] = ext > 0.0f;
        k1[axis] = live[axis] ? (float)K * (1.0f - 1e-6f) / ext : 0.0f;
        any = any || live[axis];
    }
    if (!any)
        return best;
    if (end - begin <= b->small_max && K <= 64)
        return find_split_small(b, begin, end, cmin, k1, live);
    bin_set bs, spare;
    if (b->threads > 1 && b->par_bin_min > 0 && end - begin >= b->par_bin_min)
        bin_range_parallel(b, begin, end, cmin, k1, &bs, &spare);
    else
        bin_range(b, begin, end, cmin, k1, &bs, &spare);
    for (int axis = 0; axis < 3; ++axis) {
        if (!live[axis])
            continue;
        int used[MAX_BINS], m = 0;
        for (int k = 0; k < K; ++k) {
            used[m] = k;
            m += bs.count[axis][k] > 0;
        }
        sweep_axis(&best, axis, bs.lo[axis], bs.hi[axis], bs.count[axis], used, m, cmin[axis], k1[axis],
                   b->block_cost);
    }
    return best;
}

/* Box and centroid box of a range (the median fallback's halves). */
static void range_bounds(const builder *b, uint32_t begin, uint32_t end, rl_aabb *box, rl_aabb *cbox)
{
    v4 lo = v4_set1(INFINITY), hi = v4_set1(-INFINITY), clo = lo, chi = hi;
    for (uint32_t i = begin; i < end; ++i) {
        const prim *p = &b->prims[i];
        lo = v4_min(lo, prim_lo(p));
        hi = v4_max(hi, prim_hi(p));
        v4 c = prim_centroid(p);
        clo = v4_min(clo, c);
        chi = v4_max(chi, c);
    }
    *box = v4_box(lo, hi);
    *cbox = v4_box(clo, chi);
}

/* cb: the centroid box of the range, computed by the parent's partition. */
static void build_node(builder *b, uint32_t slot, uint32_t begin, uint32_t end, rl_aabb bounds, rl_aabb cb,
                       int depth)
{
    if (atomic_load_explicit(&b->cancelled, memory_order_relaxed))
        return;
    uint32_t n = end - begin;
    if (n <= (uint32_t)b->leaf_size) {
        make_leaf(b, slot, begin, n, bounds);
        return;
    }
    split s = { .axis = -1 };
    if (depth < RL_BVH_SAH_MAX_DEPTH)
        s = find_split(b, begin, end, cb);
    if (n <= b->max_leaf) {
        float area = rl_aabb_area(bounds);
        bool pays = s.axis >= 0 &&
                    (area > 0.0f ? C_TRAV + C_ISECT * s.cost / area < C_ISECT * isect_units(n, b->block_cost) : true);
        if (!pays) {
            make_leaf(b, slot, begin, n, bounds);
            return;
        }
    }
    uint32_t mid;
    rl_aabb left, right, cleft, cright;
    if (s.axis >= 0) {
        /* The partition of before, element for element (so the leaves keep
         * their triangle order), and every triangle is classified exactly
         * once, so the children's centroid boxes come for free. */
        v4 llo = v4_set1(INFINITY), lhi = v4_set1(-INFINITY), rlo = llo, rhi = lhi;
        uint32_t i = begin, j = end;
        while (i < j) {
            prim *p = &b->prims[i];
            float c = (p->lo[s.axis] + p->hi[s.axis]) * 0.5f;
            v4 cv = prim_centroid(p);
            if (bin_of(c, s.cmin, s.k1, b->bins) < s.bin) {
                llo = v4_min(llo, cv);
                lhi = v4_max(lhi, cv);
                ++i;
            } else {
                rlo = v4_min(rlo, cv);
                rhi = v4_max(rhi, cv);
                prim t = *p;
                *p = b->prims[--j];
                b->prims[j] = t;
            }
        }
        mid = i;
        left = s.left;
        right = s.right;
        cleft = v4_box(llo, lhi);
        cright = v4_box(rlo, rhi);
    } else {
        /* Coinciding centroids or too deep: halve the range. */
        mid = begin + n / 2;
        range_bounds(b, begin, mid, &left, &cleft);
        range_bounds(b, mid, end, &right, &cright);
    }
    uint32_t pair = alloc_pair(b);
    rl_bvh_node *node = &b->sparse[slot];
    set_bounds(node, bounds);
    node->index = pair;
    node->count = 0;
    node->axis = (uint16_t)(s.axis >= 0 ? s.axis : 0);
    if (n >= TASK_MIN) {
#pragma omp task firstprivate(b, pair, begin, mid, left, cleft, depth)
        build_node(b, pair, begin, mid, left, cleft, depth + 1);
    } else {
        build_node(b, pair, begin, mid, left, cleft, depth + 1);
    }
    build_node(b, pair + 1, mid, end, right, cright, depth + 1);
}

typedef struct frame {
    uint32_t old_slot, new_index, depth;
} frame;

/* Depth-first compaction (sibling pairs stay adjacent) into dense, or with
 * dense NULL only the walk, plus the statistics:
 * SAH cost = Σ_inner C_trav·A/A_root + Σ_leaf C_isect·N·A/A_root. */
static rl_status compact(const rl_bvh_node *sparse, uint32_t count, rl_bvh_node *dense, rl_accel_stats *stats)
{
    frame *stack = rl_alloc(((size_t)RL_BVH_SAH_MAX_DEPTH + 64) * 2 * sizeof *stack);
    if (!stack)
        return RL_ERR_OUT_OF_MEMORY;
    float root_area = rl_aabb_area((rl_aabb){ { sparse[0].min[0], sparse[0].min[1], sparse[0].min[2] },
                                              { sparse[0].max[0], sparse[0].max[1], sparse[0].max[2] } });
    double inv_root = root_area > 0.0f ? 1.0 / (double)root_area : 0.0;
    uint32_t next = 1, leaves = 0, max_depth = 0;
    double sah = 0.0;
    size_t sp = 0;
    stack[sp++] = (frame){ 0, 0, 0 };
    while (sp > 0) {
        frame f = stack[--sp];
        rl_bvh_node node = sparse[f.old_slot];
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
        if (dense)
            dense[f.new_index] = node;
    }
    free(stack);
    stats->nodes = count;
    stats->leaves = leaves;
    stats->max_depth = max_depth;
    stats->sah_cost = sah;
    return RL_OK;
}

/* The binary tree as the builder leaves it: prims in leaf order, the nodes
 * in sparse[0..num_slots) in allocation order (root at 0). */
typedef struct tree {
    prim *prims;
    rl_bvh_node *sparse;
    uint32_t num_slots, num_nodes, num_blocks;
    bool own_prims;          /* false: prims lie in the caller's memory */
} tree;

static void tree_free(tree *t)
{
    if (t->own_prims)
        free(t->prims);
    free(t->sparse);
    memset(t, 0, sizeof *t);
}

static const rl_bvh_tuning default_tuning = { SMALL_MAX, PAR_BIN_MIN, PARALLEL_MIN };

/* room: memory for the N triangle records, or NULL to allocate them. */
static rl_status build_tree(const rl_scene_data *data, const rl_accel_desc *desc, const rl_bvh_tuning *tuning,
                            int threads, void *room, tree *out)
{
    uint32_t N = data->num_triangles;
    if (N == 0)
        return rl_error(RL_ERR_EMPTY_SCENE, "accel bvh: the scene has no triangles");
    builder b = {
        .num_tris = N,
        .bins = desc->bvh_bins > 0 ? desc->bvh_bins : 16,
        .leaf_size = desc->bvh_leaf_size > 0 ? desc->bvh_leaf_size : DEFAULT_LEAF,
        .block_cost = desc->bvh_block_cost == 1,
        .max_leaf = desc->bvh_block_cost == 1 ? BLOCK_MAX_LEAF : RL_BVH_MAX_LEAF,
        .threads = threads,
        .small_max = tuning->small_max < SMALL_MAX ? tuning->small_max : SMALL_MAX,
        .par_bin_min = tuning->par_bin_min,
        .progress = desc->progress,
        .user = desc->user,
    };
    atomic_init(&b.cancelled, false);
    atomic_init(&b.next_slot, 1);   /* slot 0: the root */
    atomic_init(&b.done, 0);
    /* 2N - 1 nodes at most, plus each thread's last chunk, partly unused;
     * only the slots handed out are ever touched. */
    size_t capacity = (size_t)2 * N - 1 + (size_t)threads * SLOT_CHUNK;
    prim *prims = room ? room : rl_big_array(N, sizeof *prims, false);
    rl_bvh_node *sparse = rl_big_array(capacity, sizeof *sparse, false);
    cursor *cursors = rl_calloc((size_t)threads, sizeof *cursors);
    if (!prims || !sparse || !cursors) {
        if (!room)
            free(prims);
        free(sparse);
        free(cursors);
        return RL_ERR_OUT_OF_MEMORY;
    }
    v4 root_lo = v4_set1(INFINITY), root_hi = v4_set1(-INFINITY), croot_lo = root_lo, croot_hi = root_hi;
#pragma omp parallel num_threads(threads)
    {
        v4 lo_mine = v4_set1(INFINITY), hi_mine = v4_set1(-INFINITY), clo_mine = lo_mine, chi_mine = hi_mine;
#pragma omp for schedule(static)
        for (int64_t i = 0; i < (int64_t)N; ++i) {
            const uint32_t *idx = data->indices + 3 * i;
            rl_aabb box = rl_aabb_empty();
            box = rl_aabb_grow(box, data->positions[idx[0]]);
            box = rl_aabb_grow(box, data->positions[idx[1]]);
            box = rl_aabb_grow(box, data->positions[idx[2]]);
            prim *p = &prims[i];
            *p = (prim){ { box.min.x, box.min.y, box.min.z }, 0.0f, { box.max.x, box.max.y, box.max.z }, (uint32_t)i };
            lo_mine = v4_min(lo_mine, prim_lo(p));
            hi_mine = v4_max(hi_mine, prim_hi(p));
            v4 c = prim_centroid(p);
            clo_mine = v4_min(clo_mine, c);
            chi_mine = v4_max(chi_mine, c);
        }
        /* min/max are exact, so merging in any order gives the same box. */
#pragma omp critical(rl_bvh_root_bounds)
        {
            root_lo = v4_min(root_lo, lo_mine);
            root_hi = v4_max(root_hi, hi_mine);
            croot_lo = v4_min(croot_lo, clo_mine);
            croot_hi = v4_max(croot_hi, chi_mine);
        }
#pragma omp barrier
#pragma omp single
        {
            b.prims = prims;
            b.sparse = sparse;
            b.cursors = cursors;
            build_node(&b, 0, 0, N, v4_box(root_lo, root_hi), v4_box(croot_lo, croot_hi), 0);
        }
    }
    if (!atomic_load(&b.cancelled) && b.progress && !b.progress(b.user, 1.0))
        atomic_store(&b.cancelled, true);
    if (atomic_load(&b.cancelled)) {
        if (!room)
            free(prims);
        free(sparse);
        free(cursors);
        return rl_error(RL_ERR_CANCELLED, "accel bvh: build cancelled");
    }
    uint32_t pairs = 0, blocks = 0;
    for (int t = 0; t < threads; ++t) {
        pairs += cursors[t].pairs;
        blocks += cursors[t].blocks;
    }
    free(cursors);
    *out = (tree){ prims, sparse, (uint32_t)atomic_load(&b.next_slot), 1 + 2 * pairs, blocks, !room };
    return RL_OK;
}

static int build_threads(const rl_accel_desc *desc, const rl_bvh_tuning *tuning, uint32_t num_tris)
{
    if (num_tris < tuning->parallel_min)
        return 1;
    return desc->threads > 0 ? desc->threads : omp_get_max_threads();
}

rl_status rl_bvh_build(const rl_scene_data *data, const rl_accel_desc *desc, rl_bvh *bvh,
                       rl_accel_stats *stats)
{
    return rl_bvh_build_tuned(data, desc, NULL, bvh, stats);
}

rl_status rl_bvh_build_tuned(const rl_scene_data *data, const rl_accel_desc *desc, const rl_bvh_tuning *tuning,
                             rl_bvh *bvh, rl_accel_stats *stats)
{
    if (!tuning)
        tuning = &default_tuning;
    int threads = build_threads(desc, tuning, data->num_triangles);
    tree t;
    rl_status st = build_tree(data, desc, tuning, threads, NULL, &t);
    if (st)
        return st;
    uint32_t N = data->num_triangles;
    rl_bvh_node *nodes = rl_big_array(t.num_nodes, sizeof *nodes, false);
    rl_bvh_tri *tris = rl_big_array(N, sizeof *tris, false);
    if (!nodes || !tris) {
        st = RL_ERR_OUT_OF_MEMORY;
        goto fail;
    }
    st = compact(t.sparse, t.num_nodes, nodes, stats);
    if (st)
        goto fail;
    const prim *prims = t.prims;
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int64_t i = 0; i < (int64_t)N; ++i) {
        uint32_t id = prims[i].id;
        const uint32_t *idx = data->indices + 3 * (size_t)id;
        tris[i] = (rl_bvh_tri){ data->positions[idx[0]], data->positions[idx[1]], data->positions[idx[2]], id };
    }
    tree_free(&t);
    bvh->nodes = nodes;
    bvh->num_nodes = stats->nodes;
    bvh->wide = NULL;
    bvh->num_wide = 0;
    bvh->blocks = NULL;
    bvh->num_blocks = 0;
    bvh->tris = tris;
    bvh->num_tris = N;
    stats->memory_bytes = (size_t)bvh->num_nodes * sizeof *nodes + (size_t)N * sizeof *bvh->tris;
    return RL_OK;
fail:
    tree_free(&t);
    free(nodes);
    free(tris);
    return st;
}

/* The steps after the parallel build: the statistics walk, the IDs in
 * leaf order (so that the 32-byte prims can go before the collapse
 * allocates its costs, which then reuse their pages), the collapse, which
 * takes blocks over on success. */
static rl_status finish_wide(const rl_scene_data *data, tree *t, rl_bvh_block *blocks, rl_bvh *bvh,
                             rl_accel_stats *stats)
{
    rl_status st = compact(t->sparse, t->num_nodes, NULL, stats);
    uint32_t N = data->num_triangles;
    uint32_t *ids = st ? NULL : rl_big_array(N, sizeof *ids, false);
    if (!ids)
        return st ? st : RL_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; i < N; ++i)
        ids[i] = t->prims[i].id;
    if (t->own_prims)
        free(t->prims);
    t->prims = NULL;   /* from here on, blocks may overwrite them */
    rl_bvh_leaf_source src = { .ids = ids, .id_stride = 1, .data = data };
    st = rl_bvh_collapse(t->sparse, t->num_slots, t->num_blocks, &src, blocks, bvh);
    free(ids);
    return st;
}

rl_status rl_bvh_build_wide(const rl_scene_data *data, const rl_accel_desc *desc, rl_bvh *bvh,
                            rl_accel_stats *stats)
{
    return rl_bvh_build_wide_tuned(data, desc, NULL, bvh, stats);
}

rl_status rl_bvh_build_wide_tuned(const rl_scene_data *data, const rl_accel_desc *desc,
                                  const rl_bvh_tuning *tuning, rl_bvh *bvh, rl_accel_stats *stats)
{
    if (!tuning)
        tuning = &default_tuning;
    int threads = build_threads(desc, tuning, data->num_triangles);
    /* The leaf blocks are the largest array written (city: 107 MB), and on
     * this VM a page's first touch costs about as much as the work done in
     * it (bench/README.md, "BVH build time"). A leaf holds at least one
     * triangle, so there are at most N blocks: the blocks' array is
     * allocated for N (address space only; untouched pages cost nothing)
     * before the build, and the build's triangle records (32 of the 160
     * bytes per triangle) lie at its start. Their pages are then touched
     * already when the blocks overwrite them, after the collapse has taken
     * the IDs out (finish_wide). What follows the build is serial, so a
     * second thread faults the rest of the blocks' pages in meanwhile
     * (rl_big_prefault), and the serial writer finds them present.
     * Without the room for N blocks the records get their own array. */
    uint32_t N = data->num_triangles;
    rl_bvh_block *room = N > 0 ? rl_bvh_alloc_blocks(N) : NULL;
    tree t;
    rl_status st = build_tree(data, desc, tuning, threads, room, &t);
    if (st) {
        free(room);
        return st;
    }
    rl_bvh_block *blocks = room ? room : rl_bvh_alloc_blocks(t.num_blocks);
    if (!blocks) {
        tree_free(&t);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "accel bvh: out of memory for %u leaf blocks", (unsigned)t.num_blocks);
    }
    size_t touched = room ? (size_t)N * sizeof(prim) : 0, bytes = (size_t)t.num_blocks * sizeof *blocks;
    if (threads > 1 && bytes > touched) {
#pragma omp parallel sections num_threads(2)
        {
#pragma omp section
            st = finish_wide(data, &t, blocks, bvh, stats);
#pragma omp section
            rl_big_prefault((char *)blocks + touched, bytes - touched);
        }
    } else {
        st = finish_wide(data, &t, blocks, bvh, stats);
    }
    tree_free(&t);
    if (st) {
        free(blocks);   /* joined: the prefault is done with it */
        return st;
    }
    bvh->num_tris = data->num_triangles;
    stats->memory_bytes = (size_t)bvh->num_wide * sizeof *bvh->wide + (size_t)bvh->num_blocks * sizeof *bvh->blocks;
    return RL_OK;
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
