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

#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

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
 * nodes and the blocks. bvh->blocks is allocated with room for N blocks
 * (the bound; the build's triangle records use its first pages, which the
 * blocks then reuse): address space only beyond num_blocks. */
rl_status rl_bvh_build_wide(const rl_scene_data *data, const rl_accel_desc *desc, rl_bvh *bvh,
                            rl_accel_stats *stats);

/* How the builder works, not what it builds: every setting gives the same
 * tree, bit for bit (test_bvh checks this against the plain settings).
 * rl_bvh_build and rl_bvh_build_wide use the defaults (NULL below); the
 * tests set them to reach each path on small scenes. */
typedef struct rl_bvh_tuning {
    uint32_t small_max;       /* nodes of up to this many triangles bin only their
                               * occupied bins (bins <= 64); 0: never */
    uint32_t par_bin_min;     /* nodes of at least this many triangles bin in
                               * chunks on all build threads; 0: never */
    uint32_t parallel_min;    /* builds of fewer triangles run on one thread */
} rl_bvh_tuning;
rl_status rl_bvh_build_tuned(const rl_scene_data *data, const rl_accel_desc *desc, const rl_bvh_tuning *tuning,
                             rl_bvh *bvh, rl_accel_stats *stats);
rl_status rl_bvh_build_wide_tuned(const rl_scene_data *data, const rl_accel_desc *desc,
                                  const rl_bvh_tuning *tuning, rl_bvh *bvh, rl_accel_stats *stats);

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
/* A ray's slab-test constants (Williams et al. 2005: the near plane per axis
 * by the direction's sign). */
typedef struct rl_bvh_ray_pre {
    float o[3], inv[3];
    int neg[3];
} rl_bvh_ray_pre;

static inline void rl_bvh_ray_pre_setup(const rl_ray *r, rl_bvh_ray_pre *p)
{
    const float d[3] = { r->d.x, r->d.y, r->d.z };
    p->o[0] = r->o.x;
    p->o[1] = r->o.y;
    p->o[2] = r->o.z;
    for (int a = 0; a < 3; ++a) {
        p->inv[a] = 1.0f / d[a];
        p->neg[a] = signbit(d[a]) ? 1 : 0;
    }
}

/* The boxes' relative slack (bvh_wide_traverse.c). */
#define RL_BVH_SLACK_LO (1.0f - 0x1p-15f)
#define RL_BVH_SLACK_HI (1.0f + 0x1p-15f)

/* Entry distances of the children; returns the mask of hit lanes. The
 * interval [lo, hi] is widened by a relative 2^-15 so that rounding never
 * loses a flat box (a wall: lo == hi). Scaling by (1 -+ eps) widens it only
 * for lo, hi >= 0, which holds whenever t_min >= 0 (else lo >= 0 > hi and
 * the box is rejected anyway); a range reaching back (t_min < 0) takes the
 * sign-safe form. */
static inline int rl_bvh_box_n(const rl_bvh_wide_node *n, const rl_bvh_ray_pre *r, float t_min, float t_max, float dist[RL_BVH_WIDTH])
{
#if defined(__AVX__) && RL_BVH_WIDTH == 8
    __m256 lo = _mm256_set1_ps(t_min), hi = _mm256_set1_ps(t_max);
    for (int a = 0; a < 3; ++a) {
        __m256 o = _mm256_set1_ps(r->o[a]), inv = _mm256_set1_ps(r->inv[a]);
        __m256 near = _mm256_loadu_ps(r->neg[a] ? n->bmax[a] : n->bmin[a]);
        __m256 far = _mm256_loadu_ps(r->neg[a] ? n->bmin[a] : n->bmax[a]);
        lo = _mm256_max_ps(_mm256_mul_ps(_mm256_sub_ps(near, o), inv), lo);
        hi = _mm256_min_ps(_mm256_mul_ps(_mm256_sub_ps(far, o), inv), hi);
    }
    _mm256_storeu_ps(dist, lo);
    if (t_min < 0.0f) {
        /* The slack must widen the interval whatever the signs (below). */
        const __m256 abs = _mm256_castsi256_ps(_mm256_set1_epi32(0x7fffffff));
        const __m256 eps = _mm256_set1_ps(0x1p-15f);
        lo = _mm256_sub_ps(lo, _mm256_mul_ps(_mm256_and_ps(lo, abs), eps));
        hi = _mm256_add_ps(hi, _mm256_mul_ps(_mm256_and_ps(hi, abs), eps));
        return _mm256_movemask_ps(_mm256_cmp_ps(lo, hi, _CMP_LE_OQ));
    }
    return _mm256_movemask_ps(_mm256_cmp_ps(_mm256_mul_ps(lo, _mm256_set1_ps(RL_BVH_SLACK_LO)),
                                            _mm256_mul_ps(hi, _mm256_set1_ps(RL_BVH_SLACK_HI)), _CMP_LE_OQ));
#elif defined(__SSE2__)
    int mask = 0;
    for (int c = 0; c < RL_BVH_WIDTH; c += 4) {
        __m128 lo = _mm_set1_ps(t_min), hi = _mm_set1_ps(t_max);
        for (int a = 0; a < 3; ++a) {
            __m128 o = _mm_set1_ps(r->o[a]), inv = _mm_set1_ps(r->inv[a]);
            __m128 near = _mm_loadu_ps((r->neg[a] ? n->bmax[a] : n->bmin[a]) + c);
            __m128 far = _mm_loadu_ps((r->neg[a] ? n->bmin[a] : n->bmax[a]) + c);
            lo = _mm_max_ps(_mm_mul_ps(_mm_sub_ps(near, o), inv), lo);
            hi = _mm_min_ps(_mm_mul_ps(_mm_sub_ps(far, o), inv), hi);
        }
        _mm_storeu_ps(dist + c, lo);
        if (t_min < 0.0f) {
            const __m128 abs = _mm_castsi128_ps(_mm_set1_epi32(0x7fffffff));
            const __m128 eps = _mm_set1_ps(0x1p-15f);
            lo = _mm_sub_ps(lo, _mm_mul_ps(_mm_and_ps(lo, abs), eps));
            hi = _mm_add_ps(hi, _mm_mul_ps(_mm_and_ps(hi, abs), eps));
            mask |= _mm_movemask_ps(_mm_cmple_ps(lo, hi)) << c;
            continue;
        }
        mask |= _mm_movemask_ps(_mm_cmple_ps(_mm_mul_ps(lo, _mm_set1_ps(RL_BVH_SLACK_LO)),
                                             _mm_mul_ps(hi, _mm_set1_ps(RL_BVH_SLACK_HI)))) << c;
    }
    return mask;
#else
    int mask = 0;
    for (int i = 0; i < RL_BVH_WIDTH; ++i) {
        float lo = t_min, hi = t_max;
        for (int a = 0; a < 3; ++a) {
            float near = r->neg[a] ? n->bmax[a][i] : n->bmin[a][i];
            float far = r->neg[a] ? n->bmin[a][i] : n->bmax[a][i];
            float tn = (near - r->o[a]) * r->inv[a];
            float tf = (far - r->o[a]) * r->inv[a];
            lo = tn > lo ? tn : lo;
            hi = tf < hi ? tf : hi;
        }
        dist[i] = lo;
        if (lo - fabsf(lo) * 0x1p-15f <= hi + fabsf(hi) * 0x1p-15f)
            mask |= 1 << i;
    }
    return mask;
#endif
}

/* Memory latency bounds traversal on large scenes: start fetching an entry
 * as soon as it is known to be visited. ref, count as in a traversal
 * entry: count 0 is wide node ref (all its cache lines, a whole number of
 * them), else the leaf's blocks from ref (every 64 bytes and the last). */
static inline void rl_bvh_prefetch(const rl_bvh *bvh, uint32_t ref, uint32_t count)
{
#if defined(__GNUC__)
    const char *p;
    size_t bytes;
    if (count == 0) {
        p = (const char *)&bvh->wide[ref];
        bytes = sizeof(rl_bvh_wide_node);
    } else {
        p = (const char *)&bvh->blocks[ref];
        bytes = (count + RL_BVH_LANES - 1) / RL_BVH_LANES * sizeof(rl_bvh_block);
    }
    for (size_t off = 0; off < bytes; off += 64)
        __builtin_prefetch(p + off);
    if (count != 0)
        __builtin_prefetch(p + bytes - 1);
#else
    (void)bvh;
    (void)ref;
    (void)count;
#endif
}

/* Index of the lowest set bit of m != 0 (a hit child, a packet lane). */
static inline int rl_bvh_lowest_bit(unsigned m)
{
#if defined(__GNUC__)
    return __builtin_ctz(m);
#else
    int i = 0;
    while (!(m & 1u)) {
        m >>= 1;
        ++i;
    }
    return i;
#endif
}

/* nextafterf(t, INFINITY) for a finite t, without the libm call. */
static inline float rl_bvh_next_up(float t)
{
    uint32_t u;
    memcpy(&u, &t, sizeof u);
    if (u == 0x80000000u)   /* -0 */
        u = 1u;
    else if (u & 0x80000000u)
        u -= 1u;
    else
        u += 1u;
    memcpy(&t, &u, sizeof t);
    return t;
}

/* The closest hit so far, with the tie rule of accel.c (equal t: lowest
 * ID): t_test = next_up(t) lets equal t through to the ID comparison. */
typedef struct rl_bvh_closest {
    float t, t_test, u, v;
    uint32_t id;
} rl_bvh_closest;

bool rl_bvh_wide_intersect(const rl_bvh *bvh, rl_ray *ray, rl_hit *hit);
bool rl_bvh_wide_occluded(const rl_bvh *bvh, const rl_ray *ray);
/* rl_bvh_wide_occluded naming the first blocking triangle it met. */
bool rl_bvh_wide_occluder(const rl_bvh *bvh, const rl_ray *ray, uint32_t *triangle);
/* The single-ray traversal from one entry of the tree (ref, count as in a
 * wide node's child: count 0 = inner node ref, else a leaf's first block),
 * for the packet traversal's lanes (bvh_packet.c). Updates *c / returns a
 * blocking triangle or RL_ID_NONE. */
void rl_bvh_closest_from(const rl_bvh *bvh, const rl_bvh_ray_pre *p, const rl_ray_watertight *w, float t_min,
                         uint32_t ref, uint32_t count, rl_bvh_closest *c);
void rl_bvh_leaf_closest(const rl_bvh *bvh, uint32_t ref, uint32_t count, const rl_ray_watertight *w, float t_min,
                         rl_bvh_closest *c);
uint32_t rl_bvh_occluder_from(const rl_bvh *bvh, const rl_bvh_ray_pre *p, const rl_ray_watertight *w, float t_min,
                              float t_max, uint32_t ref, uint32_t count);

/* Packet traversal of up to RL_BVH_PACKET coherent rays (bvh_packet.c):
 * lanes in active (bit l: rays[l]; valid rays with t_min >= 0 only). The
 * same hits, bit for bit, as the single-ray traversal of each lane:
 * intersect returns the lanes that hit and shortens their t_max and fills
 * their hits as rl_bvh_wide_intersect does; occluded returns the blocked
 * lanes. */
#define RL_BVH_PACKET 8
/* Compile-time switch: -DRL_BVH_PACKETS=0 sends the batch queries down the
 * single-ray path (accel.c loops). */
#ifndef RL_BVH_PACKETS
#define RL_BVH_PACKETS 1
#endif
unsigned rl_bvh_packet_intersect(const rl_bvh *bvh, rl_ray *rays, rl_hit *hits, unsigned active);
unsigned rl_bvh_packet_occluded(const rl_bvh *bvh, const rl_ray *rays, unsigned active);

#endif
