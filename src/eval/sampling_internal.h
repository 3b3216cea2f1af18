/* sampling_internal.h: what the sampler (sampling.c), the position variants
 * (sampling_positions.c), the approximation (approx.c) and its JSON form
 * (approx_io.c) share (Jähn 2015, Ch. 5). Not part of the public API. */
#ifndef RL_EVAL_SAMPLING_INTERNAL_H
#define RL_EVAL_SAMPLING_INTERNAL_H

#include "rl/rl_rng.h"
#include "rl/rl_sampling.h"

/* ---- the region tree ---- */

typedef enum rl_approx_node_kind {
    RL_NODE_LEAF = 0,
    RL_NODE_SPLIT2,      /* 2 children along `axis` (Sec. 5.4.2: long side) */
    RL_NODE_SPLIT_ALL,   /* 4 (2-D) or 8 (3-D) children at the midpoints */
    RL_NODE_GRID,        /* res[0] x res[1] x res[2] children (Alg. 5.2) */
} rl_approx_node_kind;

#define RL_APPROX_NONE UINT32_MAX

typedef struct rl_approx_node {
    rl_aabb box;               /* 2-D: min.y = max.y = height */
    uint32_t parent;           /* RL_APPROX_NONE for the root */
    uint32_t first_child;      /* children are contiguous; unused for leaves */
    uint32_t depth;
    uint32_t leaf;             /* leaf index (depth-first order) or NONE */
    uint8_t kind;              /* rl_approx_node_kind */
    uint8_t axis;              /* RL_NODE_SPLIT2 */
    int32_t res[3];            /* RL_NODE_GRID */
} rl_approx_node;

struct rl_approx {
    int dims;
    float height;
    rl_aabb bounds;            /* the root box */
    char *property, *unit;
    uint32_t set_size;
    size_t set_words;
    double seconds;
    rl_sampling_desc desc;     /* resolved; callbacks cleared */

    rl_approx_node *nodes;
    uint32_t node_count, node_cap;

    rl_approx_region *leaves;  /* in depth-first order */
    uint32_t leaf_count;
    uint64_t *leaf_sets;       /* leaf_count * set_words */

    /* Per leaf, the samples in its closed box (CSR: leaf_first[i] ..
     * leaf_first[i + 1] index leaf_samples); for nearest-sample queries. */
    uint32_t *leaf_first, *leaf_samples;

    rl_vec3 *sample_pos;
    double *sample_value;
    uint64_t *sample_sets;     /* sample_count * set_words */
    uint32_t sample_count, sample_cap;
};

/* Active axes: x, z for 2-D slices; x, y, z for 3-D. */
static inline int rl_approx_axis_count(int dims) { return dims == 2 ? 2 : 3; }
static inline int rl_approx_axis(int dims, int k) { return dims == 2 ? (k == 0 ? 0 : 2) : k; }
static inline float rl_v3_get(rl_vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }
static inline void rl_v3_set(rl_vec3 *v, int axis, float f)
{
    if (axis == 0)
        v->x = f;
    else if (axis == 1)
        v->y = f;
    else
        v->z = f;
}
/* Closed-box containment: a sample on a boundary belongs to every region
 * whose closed box holds it (Alg. 5.3, line 16). */
static inline bool rl_box_holds(rl_aabb b, rl_vec3 p)
{
    return p.x >= b.min.x && p.x <= b.max.x && p.y >= b.min.y && p.y <= b.max.y &&
           p.z >= b.min.z && p.z <= b.max.z;
}
static inline double rl_box_diameter(rl_aabb b)
{
    double x = (double)b.max.x - b.min.x, y = (double)b.max.y - b.min.y, z = (double)b.max.z - b.min.z;
    return sqrt(x * x + y * y + z * z);
}
/* q = n / (size * (max - min)) (Sec. 5.4.2: size = diameter); no samples:
 * 0, flat: +inf. */
static inline double rl_sampling_quality(uint32_t n, double size, double min, double max)
{
    if (n == 0)
        return 0.0;
    double range = max - min;
    if (!(range > 0.0))
        return INFINITY;
    return (double)n / (size * range);
}
/* The size in q (rl_quality_size): the box's diameter, or its area (2-D,
 * x and z) or volume (3-D). */
static inline double rl_sampling_size(int dims, rl_quality_size kind, rl_aabb b)
{
    if (kind == RL_QUALITY_DIAMETER)
        return rl_box_diameter(b);
    double x = (double)b.max.x - b.min.x, y = (double)b.max.y - b.min.y, z = (double)b.max.z - b.min.z;
    return dims == 2 ? x * z : x * y * z;
}
/* The split coordinate of [lo, hi]: always computed this way, so that
 * neighbouring regions share bit-identical corners (Sec. 5.4.2, corners). */
static inline float rl_split_mid(float lo, float hi) { return 0.5f * (lo + hi); }
/* Edge i of n equal cells of [lo, hi]; monotone in i, exact at 0 and n. */
static inline float rl_grid_edge(float lo, float hi, int i, int n)
{
    if (i <= 0)
        return lo;
    if (i >= n)
        return hi;
    return lo + (hi - lo) * ((float)i / (float)n);
}

/* rl_approx_load_json for the sets of a scene of set_size objects: a file
 * with sets of another size is refused (RL_ERR_INVALID_ARG) before they
 * are allocated. RL_APPROX_ANY_SET_SIZE: any size, as the public loader. */
#define RL_APPROX_ANY_SET_SIZE UINT32_MAX
rl_status rl_approx_load_json_sets(const char *path, uint32_t set_size, rl_approx **out);

/* Empty approximation (no nodes): copies name/unit, sets dims etc. */
rl_status rl_approx_alloc(int dims, float height, rl_aabb bounds, const char *property,
                          const char *unit, uint32_t set_size, rl_approx **out);
/* Appends a node; returns its index or RL_APPROX_NONE (out of memory). */
uint32_t rl_approx_add_node(rl_approx *a, rl_aabb box, uint32_t parent, uint32_t depth);
/* Turns leaf node into an inner node with children (boxes from the split
 * rule above); returns the first child or RL_APPROX_NONE (out of memory,
 * nothing changed). res is used for RL_NODE_GRID only. */
uint32_t rl_approx_split(rl_approx *a, uint32_t node, rl_approx_node_kind kind, int axis,
                         const int res[3]);
uint32_t rl_approx_child_count(const rl_approx *a, const rl_approx_node *n);
/* Appends a sample; RL_APPROX_NONE when out of memory. set may be NULL. */
uint32_t rl_approx_add_sample(rl_approx *a, rl_vec3 pos, double value, const uint64_t *set);
/* Numbers leaves depth first and fills leaves[] from per-node sample index
 * lists (lists[node], counts[node], ascending sample indices). Leaves
 * without samples take those of their nearest ancestor that has some. */
rl_status rl_approx_finish(rl_approx *a, uint32_t *const *lists, const uint32_t *counts,
                           rl_combine combine, bool linear);
/* Numbers leaves depth first (sets node.leaf, leaf_count; allocates
 * leaves[] and leaf_sets[] zeroed). Used by finish and by the loader. */
rl_status rl_approx_number_leaves(rl_approx *a);
/* Builds leaf_first/leaf_samples from the tree and the samples (closed
 * boxes). Called by finish and by the loader. */
rl_status rl_approx_index_samples(rl_approx *a);
/* Leaf node containing p (closed boxes, the lower child on a boundary);
 * RL_APPROX_NONE outside the root box. For 2-D, p.y is ignored. */
uint32_t rl_approx_find_leaf(const rl_approx *a, rl_vec3 p);

/* ---- the adaptive sampler's state, shared with the position variants ---- */

typedef struct rl_idx_list { uint32_t *v; uint32_t n, cap; } rl_idx_list;

typedef struct rl_sampler {
    rl_approx *a;
    rl_sampling_desc d;        /* resolved desc */
    rl_idx_list *lists;        /* per node: samples in its closed box (leaves) */
    uint32_t lists_cap;
    rl_vec3 *pending;          /* positions chosen for the current batch */
    uint32_t pending_count, pending_cap;
    rl_rng rng;
    uint32_t *stack;           /* scratch for tree walks */
    uint32_t stack_cap;
} rl_sampler;

/* Sec. 5.4.2, "Positionsauswahlfunktion": appends `count` new positions
 * inside node's box to s->pending (the lattice variant: the smallest k^d >=
 * count), but never more than cap (the budget left). Returns how many were
 * appended, or RL_APPROX_NONE when out of memory. */
uint32_t rl_sampling_choose(rl_sampler *s, uint32_t node, uint32_t count, uint32_t cap);
/* Samples already in node's closed box: committed ones plus pending ones. */
uint32_t rl_sampling_held(const rl_sampler *s, uint32_t node);

#endif
