/* sampling_positions.c: where a new region of the adaptive sampler takes its
 * samples (Jähn 2015, Sec. 5.4.2, "Positionsauswahlfunktion", Fig. 5.1):
 *   random       uniform in the region;
 *   blue noise   best of `candidates` (200) uniform candidates, the one
 *                farthest from its nearest sample taken so far anywhere,
 *                also outside the region (McCool & Fiume 1992: dart
 *                throwing without a fixed radius);
 *   corners      the region's corners first when not yet sampled, then blue
 *                noise, so boundary samples inform every adjacent region;
 *   lattice      cell centres of the smallest k^d lattice with k^d >= count.
 * The thesis finds nearest samples with an octree; we reuse the region tree
 * itself, whose leaves hold their samples and which is finest exactly where
 * samples are dense. A candidate's search stops as soon as it finds a
 * sample closer than the best candidate so far, since it cannot win.
 * Everything here runs on the calling thread from one seeded generator, so
 * positions never depend on the number of workers. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/sampling_internal.h"

static bool same_pos(rl_vec3 a, rl_vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

static bool push_pending(rl_sampler *s, rl_vec3 p)
{
    if (s->pending_count == s->pending_cap) {
        uint32_t cap = s->pending_cap ? s->pending_cap * 2 : 64;
        rl_vec3 *v = rl_realloc_array(s->pending, cap, sizeof *v);
        if (!v)
            return false;
        s->pending = v;
        s->pending_cap = cap;
    }
    s->pending[s->pending_count++] = p;
    return true;
}

uint32_t rl_sampling_held(const rl_sampler *s, uint32_t node)
{
    rl_aabb b = s->a->nodes[node].box;
    uint32_t n = s->lists[node].n;
    for (uint32_t i = 0; i < s->pending_count; ++i)
        n += rl_box_holds(b, s->pending[i]);
    return n;
}

/* Exact equality suffices: split coordinates are computed one way only
 * (rl_split_mid), so a corner shared by two regions is the same float. */
static bool already_sampled(const rl_sampler *s, uint32_t node, rl_vec3 p)
{
    const rl_idx_list *l = &s->lists[node];
    for (uint32_t i = 0; i < l->n; ++i)
        if (same_pos(s->a->sample_pos[l->v[i]], p))
            return true;
    for (uint32_t i = 0; i < s->pending_count; ++i)
        if (same_pos(s->pending[i], p))
            return true;
    return false;
}

static rl_vec3 uniform_in(rl_sampler *s, rl_aabb b)
{
    rl_vec3 p = b.min;
    for (int k = 0; k < rl_approx_axis_count(s->a->dims); ++k) {
        int ax = rl_approx_axis(s->a->dims, k);
        float lo = rl_v3_get(b.min, ax), hi = rl_v3_get(b.max, ax);
        float x = lo + (hi - lo) * rl_rng_float(&s->rng);
        rl_v3_set(&p, ax, x < hi ? x : hi);
    }
    return p;
}

static double dist2(rl_vec3 a, rl_vec3 b)
{
    double x = (double)a.x - b.x, y = (double)a.y - b.y, z = (double)a.z - b.z;
    return x * x + y * y + z * z;
}

static double box_dist2(rl_aabb b, rl_vec3 p)
{
    double d = 0.0;
    for (int ax = 0; ax < 3; ++ax) {
        double x = rl_v3_get(p, ax), lo = rl_v3_get(b.min, ax), hi = rl_v3_get(b.max, ax);
        double e = x < lo ? lo - x : x > hi ? x - hi : 0.0;
        d += e * e;
    }
    return d;
}

static bool stack_reserve(rl_sampler *s, uint32_t need)
{
    if (need <= s->stack_cap)
        return true;
    uint32_t cap = s->stack_cap ? s->stack_cap : 64;
    while (cap < need)
        cap *= 2;
    uint32_t *v = rl_realloc_array(s->stack, cap, sizeof *v);
    if (!v)
        return false;
    s->stack = v;
    s->stack_cap = cap;
    return true;
}

/* Squared distance from p to its nearest sample (committed or pending), or
 * any value <= floor2 as soon as one that close is found. NAN when out of
 * memory. */
static double nearest2(rl_sampler *s, rl_vec3 p, double floor2)
{
    double best = INFINITY;
    for (uint32_t i = 0; i < s->pending_count; ++i) {
        double d = dist2(p, s->pending[i]);
        if (d < best) {
            best = d;
            if (best <= floor2)
                return best;
        }
    }
    const rl_approx *a = s->a;
    uint32_t top = 0;
    if (!stack_reserve(s, 16))
        return NAN;
    s->stack[top++] = 0;
    while (top) {
        uint32_t i = s->stack[--top];
        const rl_approx_node *n = &a->nodes[i];
        if (box_dist2(n->box, p) >= best)
            continue;
        if (n->kind == RL_NODE_LEAF) {
            const rl_idx_list *l = &s->lists[i];
            for (uint32_t k = 0; k < l->n; ++k) {
                double d = dist2(p, a->sample_pos[l->v[k]]);
                if (d < best) {
                    best = d;
                    if (best <= floor2)
                        return best;
                }
            }
            continue;
        }
        /* Visit the nearest child first: it usually holds the nearest
         * sample, which then prunes the others. */
        uint32_t count = rl_approx_child_count(a, n);
        if (!stack_reserve(s, top + count))
            return NAN;
        uint32_t order[8];
        double dist[8];
        uint32_t m = 0;
        for (uint32_t c = 0; c < count; ++c) {
            uint32_t child = n->first_child + c;
            double d = box_dist2(a->nodes[child].box, p);
            if (d >= best)
                continue;
            if (count > 8) {
                s->stack[top++] = child;
                continue;
            }
            uint32_t j = m++;
            for (; j > 0 && dist[j - 1] < d; --j) {
                dist[j] = dist[j - 1];
                order[j] = order[j - 1];
            }
            dist[j] = d;
            order[j] = child;
        }
        for (uint32_t j = 0; j < m; ++j)
            s->stack[top++] = order[j];
    }
    return best;
}

static uint32_t choose_lattice(rl_sampler *s, rl_aabb b, uint32_t count, uint32_t cap)
{
    if (count == 0)
        return 0;
    int axes = rl_approx_axis_count(s->a->dims);
    uint32_t k = 1;
    for (;;) {
        uint64_t total = k;
        for (int j = 1; j < axes; ++j)
            total *= k;
        if (total >= count)
            break;
        ++k;
    }
    uint32_t added = 0;
    uint32_t idx[3] = { 0, 0, 0 };
    for (;;) {
        if (added == cap)
            return added;
        rl_vec3 p = b.min;
        for (int j = 0; j < axes; ++j) {
            int ax = rl_approx_axis(s->a->dims, j);
            float lo = rl_v3_get(b.min, ax), hi = rl_v3_get(b.max, ax);
            rl_v3_set(&p, ax, lo + (hi - lo) * (((float)idx[j] + 0.5f) / (float)k));
        }
        if (!push_pending(s, p))
            return RL_APPROX_NONE;
        ++added;
        int j = 0;
        while (j < axes && ++idx[j] == k)
            idx[j++] = 0;
        if (j == axes)
            return added;
    }
}

uint32_t rl_sampling_choose(rl_sampler *s, uint32_t node, uint32_t count, uint32_t cap)
{
    rl_aabb b = s->a->nodes[node].box;
    rl_position_variant v = s->d.positions;
    if (v == RL_POSITIONS_GRID)
        return choose_lattice(s, b, count, cap);
    uint32_t m = count < cap ? count : cap, added = 0;
    if (v == RL_POSITIONS_BLUE_NOISE_CORNERS) {
        int axes = rl_approx_axis_count(s->a->dims);
        for (uint32_t c = 0; c < (1u << axes) && added < m; ++c) {
            rl_vec3 p = b.min;
            for (int j = 0; j < axes; ++j)
                if ((c >> j) & 1u) {
                    int ax = rl_approx_axis(s->a->dims, j);
                    rl_v3_set(&p, ax, rl_v3_get(b.max, ax));
                }
            if (already_sampled(s, node, p))
                continue;
            if (!push_pending(s, p))
                return RL_APPROX_NONE;
            ++added;
        }
    }
    for (; added < m; ++added) {
        rl_vec3 best_p = b.min;
        if (v == RL_POSITIONS_RANDOM) {
            best_p = uniform_in(s, b);
        } else {
            double best = -1.0;
            for (uint32_t c = 0; c < s->d.candidates; ++c) {
                rl_vec3 p = uniform_in(s, b);
                double d = nearest2(s, p, best);
                if (isnan(d))
                    return RL_APPROX_NONE;
                if (d > best) {
                    best = d;
                    best_p = p;
                }
            }
        }
        if (!push_pending(s, best_p))
            return RL_APPROX_NONE;
    }
    return added;
}
