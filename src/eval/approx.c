/* approx.c: the global approximation of a scene property (Jähn 2015,
 * Sec. 5.2.1): a hierarchy of axis-aligned regions whose leaves carry the
 * combined value of the samples inside them (Alg. 5.1, lines 6-9; Alg. 5.3,
 * lines 23-27), with point queries in time logarithmic in the leaves
 * (Sec. 5.1.3).
 *
 * Inner nodes split in 2 along one axis, into 4/8 at the midpoints (the
 * quadtree / octree of Sec. 5.2.1) or into a regular grid (Alg. 5.2), so a
 * point query computes each child index directly instead of testing boxes.
 * As an extension of Sec. 5.2.1 ("alternatively a value gradient"), a leaf
 * can carry a least-squares linear fit of its samples. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/sampling_internal.h"

rl_status rl_approx_alloc(int dims, float height, rl_aabb bounds, const char *property,
                          const char *unit, uint32_t set_size, rl_approx **out)
{
    rl_approx *a = rl_calloc(1, sizeof *a);
    if (!a)
        return RL_ERR_OUT_OF_MEMORY;
    a->dims = dims;
    a->height = height;
    if (dims == 2)
        bounds.min.y = bounds.max.y = height;
    a->bounds = bounds;
    a->set_size = set_size;
    a->set_words = ((size_t)set_size + 63) / 64;
    a->property = rl_strdup(property ? property : "");
    a->unit = rl_strdup(unit ? unit : "");
    if (!a->property || !a->unit) {
        rl_approx_release(a);
        return RL_ERR_OUT_OF_MEMORY;
    }
    *out = a;
    return RL_OK;
}

void rl_approx_release(rl_approx *a)
{
    if (!a)
        return;
    free(a->property);
    free(a->unit);
    free(a->nodes);
    free(a->leaves);
    free(a->leaf_sets);
    free(a->leaf_first);
    free(a->leaf_samples);
    free(a->sample_pos);
    free(a->sample_value);
    free(a->sample_sets);
    free(a);
}

uint32_t rl_approx_add_node(rl_approx *a, rl_aabb box, uint32_t parent, uint32_t depth)
{
    if (a->node_count == a->node_cap) {
        uint32_t cap = a->node_cap ? a->node_cap * 2 : 64;
        if (cap < a->node_cap || cap >= RL_APPROX_NONE) {
            rl_error(RL_ERR_LIMIT, "approximation: too many regions");
            return RL_APPROX_NONE;
        }
        rl_approx_node *n = rl_realloc_array(a->nodes, cap, sizeof *n);
        if (!n)
            return RL_APPROX_NONE;
        a->nodes = n;
        a->node_cap = cap;
    }
    uint32_t i = a->node_count++;
    a->nodes[i] = (rl_approx_node){ .box = box, .parent = parent, .first_child = 0, .depth = depth,
                                    .leaf = RL_APPROX_NONE, .kind = RL_NODE_LEAF };
    return i;
}

uint32_t rl_approx_child_count(const rl_approx *a, const rl_approx_node *n)
{
    switch (n->kind) {
    case RL_NODE_SPLIT2: return 2;
    case RL_NODE_SPLIT_ALL: return a->dims == 2 ? 4 : 8;
    case RL_NODE_GRID: return (uint32_t)n->res[0] * (uint32_t)n->res[1] * (uint32_t)n->res[2];
    default: return 0;
    }
}

/* The box of child c of a node split as described, from the parent's box
 * alone, so that the loader rebuilds bit-identical boxes. */
static rl_aabb child_box(const rl_approx *a, rl_aabb b, rl_approx_node_kind kind, int axis,
                         const int res[3], uint32_t c)
{
    rl_aabb r = b;
    if (kind == RL_NODE_SPLIT2) {
        float mid = rl_split_mid(rl_v3_get(b.min, axis), rl_v3_get(b.max, axis));
        rl_v3_set(c ? &r.min : &r.max, axis, mid);
    } else if (kind == RL_NODE_SPLIT_ALL) {
        for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
            int ax = rl_approx_axis(a->dims, k);
            float mid = rl_split_mid(rl_v3_get(b.min, ax), rl_v3_get(b.max, ax));
            rl_v3_set((c >> k) & 1u ? &r.min : &r.max, ax, mid);
        }
    } else {
        uint32_t idx[3] = { c % (uint32_t)res[0], (c / (uint32_t)res[0]) % (uint32_t)res[1],
                            c / ((uint32_t)res[0] * (uint32_t)res[1]) };
        for (int ax = 0; ax < 3; ++ax) {
            if (a->dims == 2 && ax == 1)
                continue;
            float lo = rl_v3_get(b.min, ax), hi = rl_v3_get(b.max, ax);
            rl_v3_set(&r.min, ax, rl_grid_edge(lo, hi, (int)idx[ax], res[ax]));
            rl_v3_set(&r.max, ax, rl_grid_edge(lo, hi, (int)idx[ax] + 1, res[ax]));
        }
    }
    return r;
}

uint32_t rl_approx_split(rl_approx *a, uint32_t node, rl_approx_node_kind kind, int axis,
                         const int res[3])
{
    int r[3] = { 1, 1, 1 };
    if (kind == RL_NODE_GRID)
        memcpy(r, res, sizeof r);
    rl_approx_node proto = a->nodes[node];
    proto.kind = (uint8_t)kind;
    proto.axis = (uint8_t)axis;
    memcpy(proto.res, r, sizeof r);
    uint32_t count = rl_approx_child_count(a, &proto);
    uint32_t old_count = a->node_count;
    uint32_t first = RL_APPROX_NONE;
    for (uint32_t c = 0; c < count; ++c) {
        rl_aabb box = child_box(a, proto.box, kind, axis, r, c);
        uint32_t i = rl_approx_add_node(a, box, node, proto.depth + 1);
        if (i == RL_APPROX_NONE) {
            a->node_count = old_count;
            return RL_APPROX_NONE;
        }
        if (c == 0)
            first = i;
    }
    proto.first_child = first;
    a->nodes[node] = proto;
    return first;
}

uint32_t rl_approx_add_sample(rl_approx *a, rl_vec3 pos, double value, const uint64_t *set)
{
    if (a->sample_count == a->sample_cap) {
        uint32_t cap = a->sample_cap ? a->sample_cap * 2 : 256;
        rl_vec3 *p = rl_realloc_array(a->sample_pos, cap, sizeof *p);
        if (!p)
            return RL_APPROX_NONE;
        a->sample_pos = p;
        double *v = rl_realloc_array(a->sample_value, cap, sizeof *v);
        if (!v)
            return RL_APPROX_NONE;
        a->sample_value = v;
        if (a->set_words) {
            if ((size_t)cap > SIZE_MAX / a->set_words) {
                rl_error(RL_ERR_LIMIT, "approximation: sets too large");
                return RL_APPROX_NONE;
            }
            uint64_t *s = rl_realloc_array(a->sample_sets, (size_t)cap * a->set_words, sizeof *s);
            if (!s)
                return RL_APPROX_NONE;
            a->sample_sets = s;
        }
        a->sample_cap = cap;
    }
    uint32_t i = a->sample_count++;
    a->sample_pos[i] = pos;
    a->sample_value[i] = value;
    if (a->set_words) {
        uint64_t *dst = a->sample_sets + (size_t)i * a->set_words;
        if (set)
            memcpy(dst, set, a->set_words * sizeof *dst);
        else
            memset(dst, 0, a->set_words * sizeof *dst);
    }
    return i;
}

rl_status rl_approx_number_leaves(rl_approx *a)
{
    if (a->node_count == 0)
        return rl_error(RL_ERR_INTERNAL, "approximation: no regions");
    uint32_t *stack = rl_calloc(a->node_count, sizeof *stack);
    if (!stack)
        return RL_ERR_OUT_OF_MEMORY;
    /* Depth first, children low before high, so that on a shared boundary
     * the lower child's leaves precede the higher child's (rl_sampling.h). */
    uint32_t top = 0, leaves = 0;
    stack[top++] = 0;
    while (top) {
        uint32_t i = stack[--top];
        rl_approx_node *n = &a->nodes[i];
        if (n->kind == RL_NODE_LEAF) {
            n->leaf = leaves++;
            continue;
        }
        n->leaf = RL_APPROX_NONE;
        uint32_t count = rl_approx_child_count(a, n);
        for (uint32_t c = count; c-- > 0;)
            stack[top++] = n->first_child + c;
    }
    free(stack);
    free(a->leaves);
    free(a->leaf_sets);
    a->leaf_sets = NULL;
    a->leaf_count = leaves;
    a->leaves = rl_calloc(leaves, sizeof *a->leaves);
    if (!a->leaves)
        return RL_ERR_OUT_OF_MEMORY;
    if (a->set_words) {
        a->leaf_sets = rl_calloc((size_t)leaves * a->set_words, sizeof *a->leaf_sets);
        if (!a->leaf_sets)
            return RL_ERR_OUT_OF_MEMORY;
    }
    return RL_OK;
}

/* value = offset + gradient . (pos - centre) by least squares over the
 * samples, in coordinates scaled to [-1, 1] per axis so that the normal
 * equations stay well conditioned; solved by Cholesky, whose pivots reveal a
 * rank-deficient fit (all samples on a line or plane). */
static void fit_linear(const rl_approx *a, const uint32_t *list, uint32_t n, rl_approx_region *r)
{
    int axes = rl_approx_axis_count(a->dims), k = axes + 1;
    if (n < (uint32_t)k)
        return;
    double c[3], h[3];
    for (int j = 0; j < axes; ++j) {
        int ax = rl_approx_axis(a->dims, j);
        double lo = rl_v3_get(r->box.min, ax), hi = rl_v3_get(r->box.max, ax);
        c[j] = 0.5 * (lo + hi);
        h[j] = 0.5 * (hi - lo);
        if (!(h[j] > 0.0))
            return;
    }
    double A[4][4] = { { 0 } }, b[4] = { 0 };
    for (uint32_t s = 0; s < n; ++s) {
        rl_vec3 p = a->sample_pos[list[s]];
        double v = a->sample_value[list[s]];
        if (!isfinite(v))
            return;
        double row[4] = { 1.0, 0, 0, 0 };
        for (int j = 0; j < axes; ++j)
            row[1 + j] = ((double)rl_v3_get(p, rl_approx_axis(a->dims, j)) - c[j]) / h[j];
        for (int i = 0; i < k; ++i) {
            for (int m = 0; m < k; ++m)
                A[i][m] += row[i] * row[m];
            b[i] += row[i] * v;
        }
    }
    double L[4][4] = { { 0 } };
    for (int i = 0; i < k; ++i) {
        for (int m = 0; m <= i; ++m) {
            double sum = A[i][m];
            for (int q = 0; q < m; ++q)
                sum -= L[i][q] * L[m][q];
            if (m == i) {
                if (!(sum > 1e-10 * A[i][i]))
                    return; /* rank-deficient: keep the constant value */
                L[i][i] = sqrt(sum);
            } else {
                L[i][m] = sum / L[m][m];
            }
        }
    }
    double y[4], x[4];
    for (int i = 0; i < k; ++i) {
        double sum = b[i];
        for (int q = 0; q < i; ++q)
            sum -= L[i][q] * y[q];
        y[i] = sum / L[i][i];
    }
    for (int i = k; i-- > 0;) {
        double sum = y[i];
        for (int q = i + 1; q < k; ++q)
            sum -= L[q][i] * x[q];
        x[i] = sum / L[i][i];
    }
    r->linear = true;
    r->offset = x[0];
    r->gradient[0] = r->gradient[1] = r->gradient[2] = 0.0;
    for (int j = 0; j < axes; ++j)
        r->gradient[rl_approx_axis(a->dims, j)] = x[1 + j] / h[j];
}

/* Alg. 5.3, line 24: combine the values (and sets, by union) of a leaf. */
static void combine_samples(const rl_approx *a, const uint32_t *list, uint32_t n, rl_combine combine,
                            rl_approx_region *r, uint64_t *set)
{
    double sum = 0.0, mn = INFINITY, mx = -INFINITY;
    for (uint32_t s = 0; s < n; ++s) {
        double v = a->sample_value[list[s]];
        sum += v;
        mn = fmin(mn, v);
        mx = fmax(mx, v);
        if (set) {
            const uint64_t *src = a->sample_sets + (size_t)list[s] * a->set_words;
            for (size_t w = 0; w < a->set_words; ++w)
                set[w] |= src[w];
        }
    }
    if (n == 0) {
        r->value = r->min = r->max = NAN;
        return;
    }
    r->min = mn;
    r->max = mx;
    r->value = combine == RL_COMBINE_MAX ? mx : combine == RL_COMBINE_MIN ? mn : sum / (double)n;
}

static int cmp_u32(const void *x, const void *y)
{
    uint32_t a = *(const uint32_t *)x, b = *(const uint32_t *)y;
    return (a > b) - (a < b);
}

typedef struct gather_ctx {
    rl_approx *a;
    uint32_t *const *lists;
    const uint32_t *counts;
    uint32_t *stamp, now;      /* per sample: last gather that took it */
    uint32_t *out, *stack;
} gather_ctx;

/* The samples in node's closed box: the union of its leaves' lists, whose
 * closed boxes cover it (each list holds every sample in its closed box). */
static uint32_t gather(gather_ctx *g, uint32_t node)
{
    rl_approx *a = g->a;
    uint32_t n = 0, top = 0;
    ++g->now;
    g->stack[top++] = node;
    while (top) {
        const rl_approx_node *nd = &a->nodes[g->stack[--top]];
        if (nd->kind != RL_NODE_LEAF) {
            for (uint32_t c = 0; c < rl_approx_child_count(a, nd); ++c)
                g->stack[top++] = nd->first_child + c;
            continue;
        }
        uint32_t i = (uint32_t)(nd - a->nodes);
        for (uint32_t k = 0; k < g->counts[i]; ++k) {
            uint32_t id = g->lists[i][k];
            if (g->stamp[id] != g->now && rl_box_holds(a->nodes[node].box, a->sample_pos[id])) {
                g->stamp[id] = g->now;
                g->out[n++] = id;
            }
        }
    }
    qsort(g->out, n, sizeof *g->out, cmp_u32);
    return n;
}

rl_status rl_approx_finish(rl_approx *a, uint32_t *const *lists, const uint32_t *counts,
                           rl_combine combine, bool linear)
{
    rl_status st = rl_approx_number_leaves(a);
    if (st != RL_OK)
        return st;
    size_t ns = a->sample_count ? a->sample_count : 1;
    gather_ctx g = { .a = a, .lists = lists, .counts = counts, .stamp = rl_calloc(ns, sizeof *g.stamp),
                     .out = rl_calloc(ns, sizeof *g.out), .stack = rl_calloc(a->node_count, sizeof *g.stack) };
    if (!g.stamp || !g.out || !g.stack) {
        free(g.stamp);
        free(g.out);
        free(g.stack);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < a->node_count; ++i) {
        const rl_approx_node *nd = &a->nodes[i];
        if (nd->kind != RL_NODE_LEAF)
            continue;
        rl_approx_region *r = &a->leaves[nd->leaf];
        uint64_t *set = a->leaf_sets ? a->leaf_sets + (size_t)nd->leaf * a->set_words : NULL;
        r->box = nd->box;
        r->depth = nd->depth;
        r->samples = counts[i];
        const uint32_t *list = lists[i];
        uint32_t n = counts[i];
        /* A leaf left without samples by the budget takes the samples of its
         * nearest ancestor that has some (rl_sampling.h, "Budgets"). */
        for (uint32_t anc = nd->parent; n == 0 && anc != RL_APPROX_NONE; anc = a->nodes[anc].parent) {
            n = gather(&g, anc);
            list = g.out;
        }
        combine_samples(a, list, n, combine, r, set);
        r->quality = rl_sampling_quality(counts[i], rl_sampling_size(a->dims, a->desc.quality_size, r->box),
                                         r->min, r->max);
        if (!linear)
            continue;
        fit_linear(a, list, n, r);
        /* Too few samples for a fit (the budget cut the last split): the
         * nearest ancestor's samples give the gradient instead. */
        for (uint32_t anc = nd->parent; !r->linear && anc != RL_APPROX_NONE; anc = a->nodes[anc].parent)
            fit_linear(a, g.out, gather(&g, anc), r);
    }
    free(g.stamp);
    free(g.out);
    free(g.stack);
    return rl_approx_index_samples(a);
}

/* Calls fn(a, leaf, sample, user) for every leaf whose closed box holds
 * the sample, descending only into children that hold it. */
static void for_leaves_holding(const rl_approx *a, uint32_t sample, uint32_t *stack,
                               void (*fn)(rl_approx *, uint32_t, uint32_t), rl_approx *w)
{
    uint32_t top = 0;
    rl_vec3 p = a->sample_pos[sample];
    if (a->node_count == 0 || !rl_box_holds(a->nodes[0].box, p))
        return;
    stack[top++] = 0;
    while (top) {
        const rl_approx_node *nd = &a->nodes[stack[--top]];
        if (nd->kind == RL_NODE_LEAF) {
            fn(w, nd->leaf, sample);
            continue;
        }
        for (uint32_t c = 0; c < rl_approx_child_count(a, nd); ++c)
            if (rl_box_holds(a->nodes[nd->first_child + c].box, p))
                stack[top++] = nd->first_child + c;
    }
}

static void count_sample(rl_approx *a, uint32_t leaf, uint32_t sample)
{
    (void)sample;
    a->leaf_first[leaf + 1]++;
}

static void place_sample(rl_approx *a, uint32_t leaf, uint32_t sample)
{
    /* leaf_first[leaf] is used as the fill cursor, restored afterwards */
    a->leaf_samples[a->leaf_first[leaf]++] = sample;
}

rl_status rl_approx_index_samples(rl_approx *a)
{
    free(a->leaf_first);
    free(a->leaf_samples);
    a->leaf_samples = NULL;
    a->leaf_first = rl_calloc((size_t)a->leaf_count + 1, sizeof *a->leaf_first);
    /* The deepest path holds at most one node per level; the stack needs
     * room for all children of every node on it. */
    uint32_t *stack = rl_calloc((size_t)a->node_count + 1, sizeof *stack);
    if (!a->leaf_first || !stack) {
        free(stack);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t s = 0; s < a->sample_count; ++s)
        for_leaves_holding(a, s, stack, count_sample, a);
    for (uint32_t i = 0; i < a->leaf_count; ++i)
        a->leaf_first[i + 1] += a->leaf_first[i];
    size_t total = a->leaf_first[a->leaf_count];
    a->leaf_samples = rl_calloc(total ? total : 1, sizeof *a->leaf_samples);
    if (!a->leaf_samples) {
        free(stack);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t s = 0; s < a->sample_count; ++s)
        for_leaves_holding(a, s, stack, place_sample, a);
    /* The cursors now stand at each leaf's end, which is the next leaf's
     * start: shift back by one leaf. */
    for (uint32_t i = a->leaf_count; i > 0; --i)
        a->leaf_first[i] = a->leaf_first[i - 1];
    a->leaf_first[0] = 0;
    free(stack);
    return RL_OK;
}

/* Index of the cell of n equal cells of [lo, hi] that holds x, the lower one
 * on a shared edge; the estimate is corrected against the very edges that
 * built the cell boxes, so queries and boxes agree bit for bit. */
static int grid_cell(float lo, float hi, int n, float x)
{
    int i = (int)floorf((x - lo) / (hi - lo) * (float)n);
    i = i < 0 ? 0 : i > n - 1 ? n - 1 : i;
    while (i > 0 && x <= rl_grid_edge(lo, hi, i, n))
        --i;
    while (i < n - 1 && x > rl_grid_edge(lo, hi, i + 1, n))
        ++i;
    return i;
}

uint32_t rl_approx_find_leaf(const rl_approx *a, rl_vec3 p)
{
    if (!a || a->node_count == 0)
        return RL_APPROX_NONE;
    for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
        int ax = rl_approx_axis(a->dims, k);
        float x = rl_v3_get(p, ax);
        if (!(x >= rl_v3_get(a->bounds.min, ax) && x <= rl_v3_get(a->bounds.max, ax)))
            return RL_APPROX_NONE;
    }
    uint32_t i = 0;
    for (;;) {
        const rl_approx_node *n = &a->nodes[i];
        if (n->kind == RL_NODE_LEAF)
            return i;
        uint32_t c = 0;
        if (n->kind == RL_NODE_SPLIT2) {
            c = rl_v3_get(p, n->axis) > rl_v3_get(a->nodes[n->first_child].box.max, n->axis);
        } else if (n->kind == RL_NODE_SPLIT_ALL) {
            const rl_aabb low = a->nodes[n->first_child].box;
            for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
                int ax = rl_approx_axis(a->dims, k);
                c |= (uint32_t)(rl_v3_get(p, ax) > rl_v3_get(low.max, ax)) << k;
            }
        } else {
            uint32_t idx[3] = { 0, 0, 0 };
            for (int ax = 0; ax < 3; ++ax)
                if (!(a->dims == 2 && ax == 1))
                    idx[ax] = (uint32_t)grid_cell(rl_v3_get(n->box.min, ax), rl_v3_get(n->box.max, ax),
                                                  n->res[ax], rl_v3_get(p, ax));
            c = idx[0] + (uint32_t)n->res[0] * (idx[1] + (uint32_t)n->res[1] * idx[2]);
        }
        i = n->first_child + c;
    }
}

/* ---- public accessors ---- */

int rl_approx_dims(const rl_approx *a) { return a ? a->dims : 0; }
rl_aabb rl_approx_bounds(const rl_approx *a) { return a ? a->bounds : rl_aabb_empty(); }
const char *rl_approx_property(const rl_approx *a) { return a ? a->property : ""; }
const char *rl_approx_unit(const rl_approx *a) { return a ? a->unit : ""; }
uint32_t rl_approx_set_size(const rl_approx *a) { return a ? a->set_size : 0; }
double rl_approx_seconds(const rl_approx *a) { return a ? a->seconds : 0.0; }
uint32_t rl_approx_region_count(const rl_approx *a) { return a ? a->leaf_count : 0; }
uint32_t rl_approx_sample_count(const rl_approx *a) { return a ? a->sample_count : 0; }

double rl_approx_measure(const rl_approx *a)
{
    if (!a)
        return 0.0;
    double m = 1.0;
    for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
        int ax = rl_approx_axis(a->dims, k);
        m *= (double)rl_v3_get(a->bounds.max, ax) - rl_v3_get(a->bounds.min, ax);
    }
    return m;
}

rl_status rl_approx_get_region(const rl_approx *a, uint32_t i, rl_approx_region *out)
{
    if (!a || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_get_region: approximation or out is NULL");
    if (i >= a->leaf_count)
        return rl_error(RL_ERR_NOT_FOUND, "rl_approx_get_region: region %u of %u", i, a->leaf_count);
    *out = a->leaves[i];
    return RL_OK;
}

const uint64_t *rl_approx_region_set(const rl_approx *a, uint32_t i)
{
    if (!a || !a->leaf_sets || i >= a->leaf_count)
        return NULL;
    return a->leaf_sets + (size_t)i * a->set_words;
}

rl_status rl_approx_sample(const rl_approx *a, uint32_t i, rl_vec3 *pos, double *value)
{
    if (!a)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_sample: approximation is NULL");
    if (i >= a->sample_count)
        return rl_error(RL_ERR_NOT_FOUND, "rl_approx_sample: sample %u of %u", i, a->sample_count);
    if (pos)
        *pos = a->sample_pos[i];
    if (value)
        *value = a->sample_value[i];
    return RL_OK;
}

const uint64_t *rl_approx_sample_set(const rl_approx *a, uint32_t i)
{
    if (!a || !a->sample_sets || i >= a->sample_count)
        return NULL;
    return a->sample_sets + (size_t)i * a->set_words;
}

/* ------------------------------------------------- nearest samples -- */

/* The k nearest samples so far, nearest first; ties by sample index, so
 * that answers do not depend on the search order. A sample on a shared
 * border is in several leaves and is kept once. */
typedef struct knn {
    uint32_t k, n;
    double d2[RL_SAMPLING_MAX_IDW_NEIGHBORS];
    uint32_t sample[RL_SAMPLING_MAX_IDW_NEIGHBORS];
} knn;

/* Squared distance of the k-th nearest so far: nothing farther can enter. */
static double knn_bound(const knn *b) { return b->n < b->k ? INFINITY : b->d2[b->n - 1]; }

static void knn_offer(knn *b, uint32_t s, double d2)
{
    if (b->n == b->k && (d2 > b->d2[b->n - 1] || (d2 == b->d2[b->n - 1] && s > b->sample[b->n - 1])))
        return;
    for (uint32_t i = 0; i < b->n; ++i)
        if (b->sample[i] == s)
            return;
    uint32_t i = b->n < b->k ? b->n++ : b->n - 1;
    for (; i > 0 && (b->d2[i - 1] > d2 || (b->d2[i - 1] == d2 && b->sample[i - 1] > s)); --i) {
        b->d2[i] = b->d2[i - 1];
        b->sample[i] = b->sample[i - 1];
    }
    b->d2[i] = d2;
    b->sample[i] = s;
}

static double dist2_to_sample(const rl_approx *a, uint32_t s, rl_vec3 pos)
{
    double dx = (double)a->sample_pos[s].x - pos.x, dz = (double)a->sample_pos[s].z - pos.z;
    double dy = a->dims == 3 ? (double)a->sample_pos[s].y - pos.y : 0.0;
    return dx * dx + dy * dy + dz * dz;
}

static void scan_leaf(const rl_approx *a, uint32_t leaf, rl_vec3 pos, knn *best)
{
    for (uint32_t k = a->leaf_first[leaf]; k < a->leaf_first[leaf + 1]; ++k) {
        uint32_t s = a->leaf_samples[k];
        knn_offer(best, s, dist2_to_sample(a, s, pos));
    }
}

/* Squared distance from pos to the box over the active axes. */
static double box_dist2(const rl_approx *a, rl_aabb b, rl_vec3 pos)
{
    double d2 = 0.0;
    for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
        int ax = rl_approx_axis(a->dims, k);
        double x = rl_v3_get(pos, ax), lo = rl_v3_get(b.min, ax), hi = rl_v3_get(b.max, ax);
        double d = x < lo ? lo - x : x > hi ? x - hi : 0.0;
        d2 += d * d;
    }
    return d2;
}

static void knn_in(const rl_approx *a, uint32_t node, rl_vec3 pos, uint32_t skip_leaf, knn *best);

/* The cells of a grid node in rings of growing Chebyshev distance around
 * the cell that holds pos (clamped into the grid): a cell r rings away is
 * at least (r - 1) cell sides away, so the search stops at the first ring
 * beyond the k-th best distance, or when a ring leaves the grid. */
static void knn_in_grid(const rl_approx *a, const rl_approx_node *n, rl_vec3 pos, uint32_t skip_leaf,
                        knn *best)
{
    int c[3] = { 0, 0, 0 }, res[3] = { 1, 1, 1 };
    double side = INFINITY;
    for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
        int ax = rl_approx_axis(a->dims, k);
        double lo = rl_v3_get(n->box.min, ax), hi = rl_v3_get(n->box.max, ax);
        res[ax] = n->res[ax];
        double t = floor(((double)rl_v3_get(pos, ax) - lo) / (hi - lo) * res[ax]);
        c[ax] = t < 0.0 ? 0 : t > res[ax] - 1 ? res[ax] - 1 : (int)t;
        double sd = (hi - lo) / res[ax];
        side = sd < side ? sd : side;
    }
    side *= 0.999;   /* the cells' float edges are not exactly equal */
    for (int r = 0;; ++r) {
        if (r >= 2) {
            double lb = (r - 1) * side;
            if (lb * lb > knn_bound(best))
                return;
        }
        bool inside = false;
        int lo[3], hi[3];
        for (int ax = 0; ax < 3; ++ax) {
            lo[ax] = c[ax] - r < 0 ? 0 : c[ax] - r;
            hi[ax] = c[ax] + r > res[ax] - 1 ? res[ax] - 1 : c[ax] + r;
            inside |= res[ax] > 1 && (c[ax] - r >= 0 || c[ax] + r <= res[ax] - 1);
        }
        if (!inside && r > 0)
            return;
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    int dx = abs(x - c[0]), dy = abs(y - c[1]), dz = abs(z - c[2]);
                    int cheb = dx > dy ? dx : dy;
                    if ((cheb > dz ? cheb : dz) != r)
                        continue;
                    uint32_t i = (uint32_t)x + (uint32_t)res[0] * ((uint32_t)y + (uint32_t)res[1] * (uint32_t)z);
                    if (box_dist2(a, a->nodes[n->first_child + i].box, pos) <= knn_bound(best))
                        knn_in(a, n->first_child + i, pos, skip_leaf, best);
                }
    }
}

/* Branch and bound over the region tree, nearer children first; a box
 * farther than the k-th best sample so far cannot hold a nearer one (boxes
 * are closed and hold every sample inside them). skip_leaf was scanned. */
static void knn_in(const rl_approx *a, uint32_t node, rl_vec3 pos, uint32_t skip_leaf, knn *best)
{
    const rl_approx_node *n = &a->nodes[node];
    if (n->kind == RL_NODE_LEAF) {
        if (n->leaf != skip_leaf)
            scan_leaf(a, n->leaf, pos, best);
        return;
    }
    if (n->kind == RL_NODE_GRID) {
        knn_in_grid(a, n, pos, skip_leaf, best);
        return;
    }
    uint32_t count = rl_approx_child_count(a, n);
    uint32_t order[8];
    double dist[8];
    for (uint32_t c = 0; c < count; ++c) {
        double d = box_dist2(a, a->nodes[n->first_child + c].box, pos);
        uint32_t i = c;
        for (; i > 0 && dist[i - 1] > d; --i) {
            dist[i] = dist[i - 1];
            order[i] = order[i - 1];
        }
        dist[i] = d;
        order[i] = c;
    }
    for (uint32_t i = 0; i < count; ++i) {
        if (dist[i] > knn_bound(best))
            break;
        knn_in(a, n->first_child + order[i], pos, skip_leaf, best);
    }
}

/* The k nearest samples of all, across leaf borders. */
static void find_knn(const rl_approx *a, uint32_t leaf, rl_vec3 pos, uint32_t k, knn *best)
{
    best->k = k;
    best->n = 0;
    scan_leaf(a, leaf, pos, best);         /* a good first bound */
    /* The grid method has one sample per cell, at its centre: a lattice's
     * Voronoi cells are its grid cells, so the nearest one is the cell's. */
    if (k == 1 && a->nodes[0].kind == RL_NODE_GRID && !a->desc.grid_shift)
        return;
    knn_in(a, 0, pos, leaf, best);
}

/* Shepard's inverse distance weighting (power 2) of the k nearest samples;
 * a query on a sample returns that sample's value. */
static double idw_value(const rl_approx *a, const knn *b)
{
    if (b->d2[0] == 0.0 || b->n == 1)
        return a->sample_value[b->sample[0]];
    double ws = 0.0, vs = 0.0;
    for (uint32_t i = 0; i < b->n; ++i) {
        double w = 1.0 / b->d2[i];
        ws += w;
        vs += w * a->sample_value[b->sample[i]];
    }
    return vs / ws;
}

rl_status rl_approx_query(const rl_approx *a, rl_vec3 pos, double *value, uint32_t *region)
{
    if (!a || !value)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_query: approximation or value is NULL");
    uint32_t node = rl_approx_find_leaf(a, pos);
    if (node == RL_APPROX_NONE)
        return rl_error(RL_ERR_NOT_FOUND, "rl_approx_query: (%g, %g, %g) is outside the sampled region",
                        (double)pos.x, (double)pos.y, (double)pos.z);
    uint32_t leaf = a->nodes[node].leaf;
    const rl_approx_region *r = &a->leaves[leaf];
    double v = r->value;
    rl_interpolation in = a->desc.interpolation;
    if (!r->linear && in != RL_INTERP_REGION && a->leaf_first && a->sample_count) {
        /* The nearest sample (rl_sampling.h: the Voronoi alternative), or
         * Shepard's weighting of the nearest few. */
        knn best;
        uint32_t k = a->desc.idw_neighbors;
        k = in == RL_INTERP_NEAREST ? 1u : k == 0 ? RL_SAMPLING_DEFAULT_IDW_NEIGHBORS
                                      : k > RL_SAMPLING_MAX_IDW_NEIGHBORS ? RL_SAMPLING_MAX_IDW_NEIGHBORS : k;
        find_knn(a, leaf, pos, k, &best);
        if (best.n > 0)
            v = in == RL_INTERP_NEAREST ? a->sample_value[best.sample[0]] : idw_value(a, &best);
    } else if (r->linear) {
        v = r->offset;
        for (int k = 0; k < rl_approx_axis_count(a->dims); ++k) {
            int ax = rl_approx_axis(a->dims, k);
            double c = 0.5 * ((double)rl_v3_get(r->box.min, ax) + rl_v3_get(r->box.max, ax));
            v += r->gradient[ax] * ((double)rl_v3_get(pos, ax) - c);
        }
    }
    *value = v;
    if (region)
        *region = a->nodes[node].leaf;
    return RL_OK;
}

rl_status rl_approx_set_interpolation(rl_approx *a, rl_interpolation interpolation, uint32_t idw_neighbors)
{
    if (!a)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_set_interpolation: approximation is NULL");
    if ((unsigned)interpolation > RL_INTERP_REGION)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_set_interpolation: unknown interpolation %d",
                        (int)interpolation);
    if (idw_neighbors > RL_SAMPLING_MAX_IDW_NEIGHBORS)
        return rl_error(RL_ERR_LIMIT, "rl_approx_set_interpolation: %u neighbours, at most %d", idw_neighbors,
                        RL_SAMPLING_MAX_IDW_NEIGHBORS);
    a->desc.interpolation = interpolation;
    a->desc.idw_neighbors = idw_neighbors ? idw_neighbors : RL_SAMPLING_DEFAULT_IDW_NEIGHBORS;
    return RL_OK;
}

rl_status rl_approx_with_values(const rl_approx *a, const double *values, const char *property,
                                const char *unit, rl_approx **out)
{
    if (!a || !values || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_with_values: NULL argument");
    for (uint32_t i = 0; i < a->sample_count; ++i)
        if (!isfinite(values[i]))
            return rl_error(RL_ERR_INVALID_ARG, "rl_approx_with_values: value %u is not finite", i);
    rl_approx *b = NULL;
    rl_status st = rl_approx_alloc(a->dims, a->height, a->bounds, property, unit, 0, &b);
    if (st != RL_OK)
        return st;
    b->desc = a->desc;
    b->seconds = a->seconds;
    uint32_t **lists = rl_calloc(a->node_count ? a->node_count : 1, sizeof *lists);
    uint32_t *counts = rl_calloc(a->node_count ? a->node_count : 1, sizeof *counts);
    st = lists && counts ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    /* Same tree: the nodes are plain data (boxes, links, kinds). */
    for (uint32_t i = 0; st == RL_OK && i < a->node_count; ++i) {
        const rl_approx_node *n = &a->nodes[i];
        if (rl_approx_add_node(b, n->box, n->parent, n->depth) == RL_APPROX_NONE)
            st = RL_ERR_OUT_OF_MEMORY;
        else {
            b->nodes[i] = *n;
            b->nodes[i].leaf = RL_APPROX_NONE;
        }
    }
    for (uint32_t i = 0; st == RL_OK && i < a->sample_count; ++i)
        if (rl_approx_add_sample(b, a->sample_pos[i], values[i], NULL) == RL_APPROX_NONE)
            st = RL_ERR_OUT_OF_MEMORY;
    /* Every leaf's list holds the samples in its closed box, as the sampler
     * built them (shared boundary samples included). */
    for (uint32_t i = 0; st == RL_OK && i < b->node_count; ++i) {
        if (b->nodes[i].kind != RL_NODE_LEAF)
            continue;
        uint32_t n = 0;
        for (uint32_t k = 0; k < b->sample_count; ++k)
            n += rl_box_holds(b->nodes[i].box, b->sample_pos[k]);
        lists[i] = rl_calloc(n ? n : 1, sizeof **lists);
        if (!lists[i]) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        for (uint32_t k = 0; k < b->sample_count; ++k)
            if (rl_box_holds(b->nodes[i].box, b->sample_pos[k]))
                lists[i][counts[i]++] = k;
    }
    if (st == RL_OK)
        st = rl_approx_finish(b, lists, counts, a->desc.combine, a->desc.linear);
    for (uint32_t i = 0; lists && i < a->node_count; ++i)
        free(lists[i]);
    free(lists);
    free(counts);
    if (st != RL_OK) {
        rl_approx_release(b);
        return st == RL_ERR_OUT_OF_MEMORY ? rl_error(st, "rl_approx_with_values: out of memory") : st;
    }
    *out = b;
    return RL_OK;
}
