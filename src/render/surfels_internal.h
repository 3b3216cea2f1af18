/* surfels_internal.h: the spatial helpers of the Progressive Blue Surfels
 * preprocessing (Jähn 2015, Sec. 6.1.1; rl_surfels.h), shared by
 * surfels_build.c, its test and `rl bench surfels`, and the renderer's
 * level-of-detail rule (Sec. 6.2, surfels_lod.c).
 *
 * rl_surfel_grid is a uniform grid over a box whose cells are hashed into a
 * power-of-two bucket table, with one singly linked list of point indices
 * per bucket. Points are inserted one at a time (the progressive sampling
 * adds every chosen surfel at once), the table is cleared and refilled with
 * a new cell size when the spacing has shrunk (reset). Queries walk
 * Chebyshev rings of cells around the query point until the k-th best
 * distance is within the ring radius; cells of other cells that share a
 * bucket are looked at too, which costs time but never correctness. */
#ifndef RL_RENDER_SURFELS_INTERNAL_H
#define RL_RENDER_SURFELS_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "rl/rl_surfels.h"

#define RL_SURFEL_GRID_NONE 0xFFFFFFFFu

typedef struct rl_surfel_grid {
    rl_aabb bounds;               /* cell (0,0,0) starts at bounds.min */
    float cell, inv_cell;
    int32_t hi[3];                /* last cell index per axis */
    uint32_t mask;                /* buckets - 1 */
    uint32_t capacity;            /* points that may be inserted */
    uint32_t *head;               /* per bucket: first point, or NONE */
    uint32_t *next;               /* per point: next point of its bucket */
} rl_surfel_grid;

/* Room for capacity points (indices 0..capacity-1) in bounds with the given
 * cell size (clamped so that a side has at most 2^20 cells). */
rl_status rl_surfel_grid_init(rl_surfel_grid *g, rl_aabb bounds, float cell, uint32_t capacity);
/* Empties the grid and sets a new cell size; keeps the allocation. */
void rl_surfel_grid_reset(rl_surfel_grid *g, float cell);
void rl_surfel_grid_insert(rl_surfel_grid *g, const rl_vec3 *points, uint32_t i);
/* The up to k nearest inserted points of p other than `skip` (may be NONE),
 * nearest first, into idx/d2 (squared distances); returns how many. */
uint32_t rl_surfel_grid_knn(const rl_surfel_grid *g, const rl_vec3 *points, rl_vec3 p,
                            uint32_t skip, uint32_t k, uint32_t *idx, float *d2);
/* Squared distance from p to the nearest inserted point (INFINITY if none). */
float rl_surfel_grid_nearest2(const rl_surfel_grid *g, const rl_vec3 *points, rl_vec3 p);
void rl_surfel_grid_free(rl_surfel_grid *g);
/* The threads of a parallel region for a threads option: as asked where
 * > 0, else OpenMP's default; 1 in a build without OpenMP. */
int rl_surfel_thread_count(int threads);


/* Sec. 6.2: what a frame draws of an octree node with `count` surfels
 * whose bounding box projects to `area` pixels (the area of its screen
 * rectangle), for the renderer's options min_size/max_size (sides in
 * pixels), overdraw and point_size:
 *   area > max_size^2 (or count 0): no surfels, descend (meshes);
 *   area <= min_size^2: a prefix of area * coverage * overdraw surfels at
 *     point_size, no descent; when that exceeds count, all count surfels
 *     at point_size * sqrt(area * coverage * overdraw / count);
 *   in between: prefix and point size of the case above times
 *     t = (max^2 - area) / (max^2 - min^2), and descend as well.
 * The prefix is rounded up and never exceeds count. */
typedef struct rl_surfel_lod {
    uint32_t prefix;              /* surfels to draw (0: none) */
    float point_size;             /* the node's point size in pixels */
    bool descend;                 /* draw the node's meshes and children too */
} rl_surfel_lod;
rl_surfel_lod rl_surfels_node_lod(double area, double coverage, uint32_t count, float min_size,
                                  float max_size, float overdraw, float point_size);
/* Sec. 6.2.1: a surfel's side in pixels, point_size * relative_size *
 * cos_view and at least 1, or 0 (hidden) when cos_view <= 0 (it faces
 * away from the viewer) or is NaN. */
float rl_surfel_point_side(float point_size, float relative_size, float cos_view);

#endif
