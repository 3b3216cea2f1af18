/* rl_accel.h: ray queries against a committed scene.
 *
 * One interface over several acceleration structures:
 *   RL_ACCEL_BVH    binned SAH BVH (Wald 2007), watertight ray/triangle test
 *                   (Woop, Benthin, Wald 2013), ordered traversal;
 *   RL_ACCEL_GRID   uniform voxel grid with 3D-DDA traversal (Amanatides &
 *                   Woo 1987); its voxels also host the Line Space
 *                   (Schröder 2017, Sec. 4.2);
 *   RL_ACCEL_EMBREE Embree 3 (rtcIntersect1/rtcOccluded1; rtcIntersect8/
 *                   rtcOccluded8 in the batch queries), the correctness
 *                   oracle and performance anchor, when built with Embree;
 *   RL_ACCEL_BRUTE  every ray against every triangle with the same watertight
 *                   test: the reference for tests, O(N) per ray.
 *
 * Lifecycle (as Embree's): create borrows the committed scene (which must
 * outlive the accel), commit builds, queries are then thread-safe and cannot
 * fail: a ray with a NaN/Inf origin or direction, a zero direction or
 * t_min > t_max simply misses. Triangle IDs are the scene's flattened
 * triangle indices, object IDs its object indices (rl_scene.h). */
#ifndef RL_ACCEL_H
#define RL_ACCEL_H

#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_accel rl_accel;                   /* opaque */

typedef enum rl_accel_kind {
    RL_ACCEL_BVH = 0,
    RL_ACCEL_GRID,
    RL_ACCEL_EMBREE,
    RL_ACCEL_BRUTE,
    RL_ACCEL_KIND_COUNT
} rl_accel_kind;

typedef struct rl_accel_desc {                      /* zero = default */
    rl_accel_kind kind;
    int threads;              /* build threads; 0 -> all */
    int bvh_leaf_size;        /* max triangles per leaf; 0 -> 2 */
    int bvh_bins;             /* SAH bins per axis; 0 -> 16 */
    int bvh_block_cost;       /* 1: the SAH counts a leaf's SoA blocks of 4 triangles
                               * (ceil(n/4)) instead of its triangles, leaves of up to
                               * 8: about half the memory, a faster build on large
                               * scenes, diffuse rays faster on some meshes, slower on
                               * others (bench/README.md, "Diffuse rays against
                               * Embree"); 0 (default): per triangle */
    float grid_lambda;        /* grid density λ: cells per axis ≈ λ·∛N scaled to
                               * the box's aspect; 0 -> 2 */
    int grid_res[3];          /* explicit cells per axis; 0 -> from grid_lambda */
    rl_progress_fn progress;  /* may be NULL; false cancels the build */
    void *user;
} rl_accel_desc;

/* Closest hit. Barycentrics: p = (1-u-v)·p0 + u·p1 + v·p2 for the
 * triangle's vertices in scene index order. */
typedef struct rl_hit {
    float t, u, v;
    uint32_t triangle;        /* RL_ID_NONE on a miss */
    uint32_t object;          /* RL_ID_NONE on a miss */
} rl_hit;

typedef struct rl_accel_stats {
    rl_accel_kind kind;
    uint32_t num_triangles;
    double build_ms;
    size_t memory_bytes;      /* of the structure, not of the scene */
    double bytes_per_triangle;
    uint32_t nodes, leaves, max_depth;   /* BVH */
    double sah_cost;                     /* BVH */
    int grid_res[3];                     /* grid */
    uint64_t grid_references;            /* grid: triangle references in cells */
} rl_accel_stats;

RL_API const char *rl_accel_kind_name(rl_accel_kind kind);        /* "bvh", ... */
/* RL_ERR_NOT_FOUND naming the known kinds. */
RL_API rl_status rl_accel_kind_parse(const char *name, rl_accel_kind *out);
/* False for RL_ACCEL_EMBREE in a build without Embree. */
RL_API bool rl_accel_kind_available(rl_accel_kind kind);

/* RL_ERR_INVALID_ARG (NULL, bad desc values), RL_ERR_NOT_COMMITTED (scene),
 * RL_ERR_UNSUPPORTED (kind not in this build). *out stays NULL on failure. */
RL_API rl_status rl_accel_create(const rl_scene *scene, const rl_accel_desc *desc, rl_accel **out);
/* Builds; RL_ERR_CANCELLED, RL_ERR_OUT_OF_MEMORY. A second commit is a no-op. */
RL_API rl_status rl_accel_commit(rl_accel *accel);
RL_API void rl_accel_release(rl_accel *accel);                    /* NULL is a no-op */
RL_API void rl_accel_get_stats(const rl_accel *accel, rl_accel_stats *out);
RL_API const rl_scene *rl_accel_scene(const rl_accel *accel);

/* Closest hit in (t_min, t_max): on a hit shortens ray->t_max to the hit
 * distance, fills *hit and returns true; on a miss leaves both and returns
 * false (hit->triangle = RL_ID_NONE). Requires a committed accel. */
RL_API bool rl_accel_intersect(const rl_accel *accel, rl_ray *ray, rl_hit *hit);
/* Any hit in (t_min, t_max): shadow and visibility rays. */
RL_API bool rl_accel_occluded(const rl_accel *accel, const rl_ray *ray);
/* Intersection hints (Ullmann 2003, Sec. 3.3.1, 6.2.2: the ray tree of
 * neighbouring samples names the surfaces a ray will likely hit).
 * rl_accel_intersect_triangle runs the watertight test of the kinds of ours
 * against one scene triangle alone: true for a hit with t in (t_min, t_max)
 * that is not in an alpha-mask hole, with *hit filled (object too) and the
 * ray left as it is. Its t, u, v are bit for bit those the BVH, grid and
 * brute force compute for that triangle (not necessarily Embree's). False
 * for a triangle out of range or an invalid ray.
 * rl_accel_occluder is rl_accel_occluded that also names a triangle that
 * blocks the ray (any one in range, not necessarily the closest), or
 * RL_ID_NONE when the ray is not occluded; what it returns is exactly what
 * rl_accel_occluded returns. */
RL_API bool rl_accel_intersect_triangle(const rl_accel *accel, const rl_ray *ray, uint32_t triangle,
                                        rl_hit *hit);
RL_API bool rl_accel_occluder(const rl_accel *accel, const rl_ray *ray, uint32_t *triangle);
/* Batches: the same as calling the single-ray query for each ray in order
 * (same results, bit for bit for our kinds), possibly faster.
 * Single-threaded: callers parallelise. The rays go in groups of 8; in a
 * group, the valid rays with t_min >= 0 whose directions share the octant
 * of the first such ray form a packet when there are at least 4 of them,
 * the rest are single queries. RL_ACCEL_BVH traces a packet with its
 * packet traversal (one traversal for all lanes, src/accel/bvh_packet.c),
 * RL_ACCEL_EMBREE with rtcIntersect8 / rtcOccluded8; the others loop.
 * Coherent rays pay: neighbouring pixels' primary rays (a 4x2 tile per
 * group), shadow rays from neighbouring points to one light. */
RL_API void rl_accel_intersect_n(const rl_accel *accel, rl_ray *rays, rl_hit *hits, size_t n);
RL_API void rl_accel_occluded_n(const rl_accel *accel, const rl_ray *rays, bool *occluded, size_t n);

#ifdef __cplusplus
}
#endif
#endif
