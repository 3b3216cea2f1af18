/* bvh_wide_traverse.c: ordered traversal of the wide BVH (bvh_wide.c).
 *
 * One slab test (Kay & Kajiya 1986) covers all of a node's children: AVX
 * (8 lanes), SSE (4 lanes at a time) or a scalar loop over the same IEEE
 * operations, so all paths agree bit for bit. The per-axis near/far plane is chosen
 * once per ray by the direction's sign (Williams et al. 2005, "An Efficient
 * and Robust Ray-Box Intersection Algorithm"). A zero direction component
 * gives 1/d = ±inf; an origin exactly on that slab's plane then yields
 * 0·inf = NaN, which the max/min skip (MAXPS/MINPS and our ternaries keep
 * the second operand on NaN), so the slab counts as "inside" and no NaN
 * reaches the result. Boxes get a 2^-15 relative slack so that rounding in
 * the slab test never culls a box whose triangle the watertight test hits
 * (the BVH must agree with brute force exactly; cf. Ize 2013, "Robust BVH
 * Ray Traversal"). Hit children are sorted by entry distance, the nearest
 * is visited next and the others are pushed with their distance, so that a
 * pop can skip boxes beyond the shortened t_max. One or two hit children
 * (most steps of an incoherent ray) take a fast path without the sort, and
 * hit lanes are walked by bit scan: +12-18 % diffuse on city, +25 % on
 * Wuson (rl bench rays, interleaved A/B), primary and shadow within 5 %.
 * Three or more are sorted in place on the stack top, and the closest-hit
 * bound steps by bits (next_up) instead of calling libm's nextafterf:
 * primary +4 % on city and +18 % on Wuson, diffuse within the noise. Leaves test their
 * triangles RL_BVH_LANES at a time (SoA blocks, bvh.h), with exactly the
 * scalar test's operations, as Embree's Triangle4 does. Closest hit follows
 * the tie rule of accel.c (equal t: lowest triangle ID). */
#include <math.h>
#include <stdint.h>
#include <string.h>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "accel/bvh.h"
#include "accel/watertight.h"


typedef rl_bvh_ray_pre ray_pre;

typedef struct entry {
    uint32_t ref;             /* wide node, or first block of a leaf */
    uint32_t count;           /* leaf triangles; 0: inner node */
    float dist;               /* entry distance of its box */
} entry;

/* Pushes the hit children of n farthest first and returns the nearest in
 * *next; false when none is hit. Most steps of an incoherent ray hit one
 * or two children, so those skip the sort; the hit lanes are walked by
 * bit scan instead of testing all WIDTH lanes. */
static inline bool visit(const rl_bvh *bvh, const rl_bvh_wide_node *n, const ray_pre *r, float t_min, float t_max,
                         entry *stack, int *sp, entry *next)
{
    float dist[RL_BVH_WIDTH];
    unsigned mask = (unsigned)rl_bvh_box_n(n, r, t_min, t_max, dist);
    if (!mask)
        return false;
    int i = rl_bvh_lowest_bit(mask);
    mask &= mask - 1;
    entry a = { n->child[i], n->count[i], dist[i] };
    if (!mask) {   /* visited at once: no use prefetching it */
        *next = a;
        return true;
    }
    rl_bvh_prefetch(bvh, a.ref, a.count);
    i = rl_bvh_lowest_bit(mask);
    mask &= mask - 1;
    entry b = { n->child[i], n->count[i], dist[i] };
    rl_bvh_prefetch(bvh, b.ref, b.count);
    if (!mask) {
        if (b.dist <= a.dist) {   /* as the sort below: equal, the later lane first */
            stack[(*sp)++] = a;
            *next = b;
        } else {
            stack[(*sp)++] = b;
            *next = a;
        }
        return true;
    }
    /* Sorted in place on top of the stack (the stacks have room for one
     * entry more than the bound of bvh.h), so no copy is needed. */
    entry *hit = stack + *sp;
    int k = 1;
    hit[0] = a;
    for (mask |= 1u << i; mask; mask &= mask - 1) {
        i = rl_bvh_lowest_bit(mask);
        entry e = { n->child[i], n->count[i], dist[i] };
        if (k > 1)
            rl_bvh_prefetch(bvh, e.ref, e.count);
        int j = k++;
        while (j > 0 && hit[j - 1].dist < e.dist) {   /* descending; stable */
            hit[j] = hit[j - 1];
            --j;
        }
        hit[j] = e;
    }
    *sp += k - 1;
    *next = hit[k - 1];
    return true;
}

#define next_up rl_bvh_next_up

/* The closest hit so far, with the tie rule of accel.c (equal t: lowest
 * ID): t_test lets equal t through to the ID comparison. */
typedef rl_bvh_closest closest;

/* Lane l of a block as the scalar test's vertices. */
static inline void block_lane(const rl_bvh_block *b, int l, rl_vec3 p[3])
{
    for (int k = 0; k < 3; ++k)
        p[k] = (rl_vec3){ b->p[k][0][l], b->p[k][1][l], b->p[k][2][l] };
}

/* The watertight test (watertight.h) on all lanes of a block at once: the
 * same IEEE operations in the same order (no FMA: C11 mode contracts
 * nothing, and we use no FMA intrinsics), so each lane's t, u, v are
 * bit-identical to the scalar test's. Lanes whose edge functions hit
 * exactly 0 need the scalar test's double recompute: they go to *fallback
 * and out of the returned hit mask. Padding lanes are NaN and fail. */
RL_WT_INLINE int block_hit_k(const rl_bvh_block *b, const rl_ray_watertight *w, int kx, int ky, int kz,
                             float t_min, float t_max, float t[RL_BVH_LANES], float u[RL_BVH_LANES],
                             float v[RL_BVH_LANES], int *fallback)
{
#if defined(__SSE2__) && RL_BVH_LANES == 4
    const __m128 zero = _mm_setzero_ps(), sign = _mm_set1_ps(-0.0f);
    const __m128 ox = _mm_set1_ps(RL_WT_COMP(w->o, kx)), oy = _mm_set1_ps(RL_WT_COMP(w->o, ky));
    const __m128 oz = _mm_set1_ps(RL_WT_COMP(w->o, kz));
    const __m128 sx = _mm_set1_ps(w->sx), sy = _mm_set1_ps(w->sy), sz = _mm_set1_ps(w->sz);
    __m128 Az = _mm_sub_ps(_mm_load_ps(b->p[0][kz]), oz);
    __m128 Bz = _mm_sub_ps(_mm_load_ps(b->p[1][kz]), oz);
    __m128 Cz = _mm_sub_ps(_mm_load_ps(b->p[2][kz]), oz);
    __m128 Ax = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b->p[0][kx]), ox), _mm_mul_ps(sx, Az));
    __m128 Ay = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b->p[0][ky]), oy), _mm_mul_ps(sy, Az));
    __m128 Bx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b->p[1][kx]), ox), _mm_mul_ps(sx, Bz));
    __m128 By = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b->p[1][ky]), oy), _mm_mul_ps(sy, Bz));
    __m128 Cx = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b->p[2][kx]), ox), _mm_mul_ps(sx, Cz));
    __m128 Cy = _mm_sub_ps(_mm_sub_ps(_mm_load_ps(b->p[2][ky]), oy), _mm_mul_ps(sy, Cz));
    __m128 U = _mm_sub_ps(_mm_mul_ps(Cx, By), _mm_mul_ps(Cy, Bx));
    __m128 V = _mm_sub_ps(_mm_mul_ps(Ax, Cy), _mm_mul_ps(Ay, Cx));
    __m128 W = _mm_sub_ps(_mm_mul_ps(Bx, Ay), _mm_mul_ps(By, Ax));
    *fallback = _mm_movemask_ps(
        _mm_or_ps(_mm_or_ps(_mm_cmpeq_ps(U, zero), _mm_cmpeq_ps(V, zero)), _mm_cmpeq_ps(W, zero)));
    __m128 neg = _mm_or_ps(_mm_or_ps(_mm_cmplt_ps(U, zero), _mm_cmplt_ps(V, zero)), _mm_cmplt_ps(W, zero));
    __m128 pos = _mm_or_ps(_mm_or_ps(_mm_cmpgt_ps(U, zero), _mm_cmpgt_ps(V, zero)), _mm_cmpgt_ps(W, zero));
    __m128 det = _mm_add_ps(_mm_add_ps(U, V), W);
    /* cmpneq is unordered like C's !(det == 0): a NaN lane fails later. */
    __m128 ok = _mm_andnot_ps(_mm_and_ps(neg, pos), _mm_cmpneq_ps(det, zero));
    if (!_mm_movemask_ps(ok))
        return 0;
    Az = _mm_mul_ps(Az, sz);
    Bz = _mm_mul_ps(Bz, sz);
    Cz = _mm_mul_ps(Cz, sz);
    __m128 T = _mm_add_ps(_mm_add_ps(_mm_mul_ps(U, Az), _mm_mul_ps(V, Bz)), _mm_mul_ps(W, Cz));
    __m128 det_abs = _mm_andnot_ps(sign, det);
    __m128 T_abs = _mm_xor_ps(T, _mm_and_ps(_mm_cmplt_ps(det, zero), sign));   /* det < 0 ? -T : T */
    if (t_min >= 0.0f)
        ok = _mm_andnot_ps(_mm_cmple_ps(T_abs, zero), ok);
    __m128 bound = _mm_mul_ps(_mm_mul_ps(_mm_set1_ps(t_max), det_abs), _mm_set1_ps(1.0f + 0x1p-16f));
    ok = _mm_andnot_ps(_mm_and_ps(_mm_cmpgt_ps(bound, _mm_set1_ps(0x1p-100f)), _mm_cmpgt_ps(T_abs, bound)), ok);
    __m128 th = _mm_div_ps(T, det);
    ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(th, _mm_set1_ps(t_min)), _mm_cmplt_ps(th, _mm_set1_ps(t_max))));
    int mask = _mm_movemask_ps(ok) & ~*fallback;
    if (mask) {
        _mm_storeu_ps(t, th);
        _mm_storeu_ps(u, _mm_div_ps(V, det));
        _mm_storeu_ps(v, _mm_div_ps(W, det));
    }
    return mask;
#else
    /* No SSE: the scalar test lane by lane (it does its own fallback). */
    int mask = 0;
    *fallback = 0;
    for (int l = 0; l < RL_BVH_LANES; ++l) {
        rl_vec3 p[3];
        block_lane(b, l, p);
        if (rl_watertight_hit_k(w, kx, ky, kz, p[0], p[1], p[2], t_min, t_max, &t[l], &u[l], &v[l]))
            mask |= 1 << l;
    }
    return mask;
#endif
}

/* block_hit_k plus the scalar test (with its double recompute) on the
 * fallback lanes. */
RL_WT_INLINE int block_hits_k(const rl_bvh_block *b, const rl_ray_watertight *w, int kx, int ky, int kz,
                              float t_min, float t_max, float t[RL_BVH_LANES], float u[RL_BVH_LANES],
                              float v[RL_BVH_LANES])
{
    int fallback;
    int mask = block_hit_k(b, w, kx, ky, kz, t_min, t_max, t, u, v, &fallback);
    if (fallback) {
        for (int l = 0; l < RL_BVH_LANES; ++l) {
            rl_vec3 p[3];
            if (!(fallback & (1 << l)))
                continue;
            block_lane(b, l, p);
            if (rl_watertight_hit_k(w, kx, ky, kz, p[0], p[1], p[2], t_min, t_max, &t[l], &u[l], &v[l]))
                mask |= 1 << l;
        }
    }
    return mask;
}

/* All lanes of a block are tested against the same t_max, so a lane beyond
 * an earlier lane's hit can come back: t < t_test filters it. Acceptance
 * depends on t alone (watertight.c), so this equals testing one by one. */
RL_WT_INLINE void leaf_closest_k(const rl_bvh_block *blk, uint32_t count, const rl_ray_watertight *w, int kx,
                                 int ky, int kz, float t_min, closest *c)
{
    for (uint32_t i = 0; i < count; i += RL_BVH_LANES, ++blk) {
        float t[RL_BVH_LANES], u[RL_BVH_LANES], v[RL_BVH_LANES];
        int mask = block_hits_k(blk, w, kx, ky, kz, t_min, c->t_test, t, u, v);
        for (int l = 0; mask; ++l, mask >>= 1) {
            if (!(mask & 1) || !(t[l] < c->t_test))
                continue;
            if (t[l] < c->t || blk->id[l] < c->id)
                *c = (closest){ t[l], next_up(t[l]), u[l], v[l], blk->id[l] };
        }
    }
}

/* The ID of a triangle of the leaf in (t_min, t_max), RL_ID_NONE if none:
 * rl_accel_occluder names it, and a hit costs one bit scan more. */
RL_WT_INLINE uint32_t leaf_any_k(const rl_bvh_block *blk, uint32_t count, const rl_ray_watertight *w, int kx,
                                 int ky, int kz, float t_min, float t_max)
{
    for (uint32_t i = 0; i < count; i += RL_BVH_LANES, ++blk) {
        float t[RL_BVH_LANES], u[RL_BVH_LANES], v[RL_BVH_LANES];
        int mask = block_hits_k(blk, w, kx, ky, kz, t_min, t_max, t, u, v);
        if (mask)
            return blk->id[rl_bvh_lowest_bit((unsigned)mask)];
    }
    return RL_ID_NONE;
}

/* One loop per axis permutation (kz, then kx; ky follows), so that the
 * vertex components are picked at compile time. */
static void leaf_closest(const rl_bvh_block *tri, uint32_t count, const rl_ray_watertight *w, float t_min,
                         closest *c)
{
    switch (w->kz * 3 + w->kx) {
    case 0 * 3 + 1: leaf_closest_k(tri, count, w, 1, 2, 0, t_min, c); break;
    case 0 * 3 + 2: leaf_closest_k(tri, count, w, 2, 1, 0, t_min, c); break;
    case 1 * 3 + 2: leaf_closest_k(tri, count, w, 2, 0, 1, t_min, c); break;
    case 1 * 3 + 0: leaf_closest_k(tri, count, w, 0, 2, 1, t_min, c); break;
    case 2 * 3 + 0: leaf_closest_k(tri, count, w, 0, 1, 2, t_min, c); break;
    default: leaf_closest_k(tri, count, w, 1, 0, 2, t_min, c); break;
    }
}

static uint32_t leaf_any(const rl_bvh_block *tri, uint32_t count, const rl_ray_watertight *w, float t_min,
                         float t_max)
{
    switch (w->kz * 3 + w->kx) {
    case 0 * 3 + 1: return leaf_any_k(tri, count, w, 1, 2, 0, t_min, t_max);
    case 0 * 3 + 2: return leaf_any_k(tri, count, w, 2, 1, 0, t_min, t_max);
    case 1 * 3 + 2: return leaf_any_k(tri, count, w, 2, 0, 1, t_min, t_max);
    case 1 * 3 + 0: return leaf_any_k(tri, count, w, 0, 2, 1, t_min, t_max);
    case 2 * 3 + 0: return leaf_any_k(tri, count, w, 0, 1, 2, t_min, t_max);
    default: return leaf_any_k(tri, count, w, 1, 0, 2, t_min, t_max);
    }
}

/* The closest-hit traversal of the subtree (or leaf) start, updating *c:
 * the whole tree for a single ray, a subtree for a lane that leaves a
 * packet (bvh_packet.c). */
static inline void closest_from(const rl_bvh *bvh, const ray_pre *p, const rl_ray_watertight *w, float t_min,
                                entry cur, closest *c)
{
    entry stack[RL_BVH_WIDE_STACK + 1];
    int sp = 0;
    for (;;) {
        if (cur.count == 0) {
            if (visit(bvh, &bvh->wide[cur.ref], p, t_min, c->t, stack, &sp, &cur))
                continue;
        } else {
            leaf_closest(&bvh->blocks[cur.ref], cur.count, w, t_min, c);
        }
        /* Pop, skipping boxes that now start beyond the closest hit. */
        for (;;) {
            if (sp == 0)
                return;
            cur = stack[--sp];
            /* The same relative slack as rl_bvh_box_n, sign-safe (t may be < 0). */
            if (cur.dist - fabsf(cur.dist) * 0x1p-15f <= c->t + fabsf(c->t) * 0x1p-15f)
                break;
        }
    }
}

void rl_bvh_closest_from(const rl_bvh *bvh, const rl_bvh_ray_pre *p, const rl_ray_watertight *w, float t_min,
                         uint32_t ref, uint32_t count, rl_bvh_closest *c)
{
    closest_from(bvh, p, w, t_min, (entry){ ref, count, t_min }, c);
}

void rl_bvh_leaf_closest(const rl_bvh *bvh, uint32_t ref, uint32_t count, const rl_ray_watertight *w, float t_min,
                         rl_bvh_closest *c)
{
    leaf_closest(&bvh->blocks[ref], count, w, t_min, c);
}

bool rl_bvh_wide_intersect(const rl_bvh *bvh, rl_ray *ray, rl_hit *hit)
{
    ray_pre p;
    rl_bvh_ray_pre_setup(ray, &p);
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    const float t_min = ray->t_min;
    closest c = { ray->t_max, ray->t_max, 0.0f, 0.0f, RL_ID_NONE };
    closest_from(bvh, &p, &w, t_min, (entry){ 0, 0, t_min }, &c);
    if (c.id == RL_ID_NONE)
        return false;
    ray->t_max = c.t;
    *hit = (rl_hit){ .t = c.t, .u = c.u, .v = c.v, .triangle = c.id, .object = hit->object };
    return true;
}

bool rl_bvh_wide_occluded(const rl_bvh *bvh, const rl_ray *ray)
{
    uint32_t triangle;
    return rl_bvh_wide_occluder(bvh, ray, &triangle);
}

/* The any-hit traversal of the subtree (or leaf) start: the ID of a
 * blocking triangle, RL_ID_NONE if none. */
static inline uint32_t occluder_from(const rl_bvh *bvh, const ray_pre *p, const rl_ray_watertight *w, float t_min,
                                     float t_max, entry cur)
{
    entry stack[RL_BVH_WIDE_STACK + 1];
    int sp = 0;
    for (;;) {
        if (cur.count == 0) {
            if (visit(bvh, &bvh->wide[cur.ref], p, t_min, t_max, stack, &sp, &cur))
                continue;
        } else {
            uint32_t id = leaf_any(&bvh->blocks[cur.ref], cur.count, w, t_min, t_max);
            if (id != RL_ID_NONE)
                return id;   /* any hit will do */
        }
        if (sp == 0)
            return RL_ID_NONE;
        cur = stack[--sp];
    }
}

uint32_t rl_bvh_occluder_from(const rl_bvh *bvh, const rl_bvh_ray_pre *p, const rl_ray_watertight *w, float t_min,
                              float t_max, uint32_t ref, uint32_t count)
{
    if (count)
        return leaf_any(&bvh->blocks[ref], count, w, t_min, t_max);
    return occluder_from(bvh, p, w, t_min, t_max, (entry){ ref, count, t_min });
}

bool rl_bvh_wide_occluder(const rl_bvh *bvh, const rl_ray *ray, uint32_t *triangle)
{
    ray_pre p;
    rl_bvh_ray_pre_setup(ray, &p);
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    *triangle = occluder_from(bvh, &p, &w, ray->t_min, ray->t_max, (entry){ 0, 0, ray->t_min });
    return *triangle != RL_ID_NONE;
}
