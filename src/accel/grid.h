/* grid.h: the uniform voxel grid and its 3D-DDA walk (Amanatides & Woo,
 * "A Fast Voxel Traversal Algorithm for Ray Tracing", Eurographics 1987).
 *
 * Internal: RL_ACCEL_GRID is built on it (grid.c), and the Line Space of
 * Schröder 2017 (Sec. 4.2) is built inside its voxels and walks them with
 * the same iterator, so the layout below is a contract.
 *
 * Layout. The grid covers `bounds` (the triangles' box, padded, see
 * RL_GRID_PAD_REL) with res[0] x res[1] x res[2] cells of size cell_size.
 * Cell (x, y, z) has index x + res[0]*(y + res[1]*z) and the box
 *     bounds.min + (x, y, z) * cell_size  ..  bounds.min + (x+1, y+1, z+1) * cell_size
 * (rl_grid_cell_bounds). Its triangles are
 *     cell_tris[cell_start[i] .. cell_start[i+1]-1]
 * (compressed sparse rows; cell_start has num_cells + 1 entries), sorted by
 * triangle ID whatever the number of build threads. A triangle is listed in
 * every cell its surface overlaps (the exact triangle/box test of
 * Akenine-Möller 2001), with each cell grown by a small epsilon so that a
 * point on a shared face always finds the triangle on both sides. Triangle
 * i's vertices are tri_verts[3i .. 3i+2] (a copy in scene index order).
 *
 * Resolution (the usual λ·∛N density rule, scaled to the box): with N
 * triangles, λ = desc->grid_lambda (0 -> 2) and e the extent of the
 * triangles' box,
 *     k     = (λ^d · N / Π_{active} e_i)^(1/d)     cells per unit length,
 *     res_i = round(e_i · k)                        for an active axis,
 * where an axis is active while e_i · k >= 1: an axis shorter than one cell
 * (and a flat axis, e_i = 0) gets exactly one cell and leaves the product,
 * and k is recomputed over the d remaining axes. A cube thus gets
 * λ·∛N cells per axis (≈ λ³N cells), a flat square λ·√N per side (≈ λ²N).
 * res_i is clamped to 1..RL_GRID_MAX_RES; if the total exceeds
 * RL_GRID_MAX_CELLS every axis is scaled down by the same factor.
 * desc->grid_res[i] > 0 overrides axis i (accel.c limits it to 4096; more
 * than 2^28 cells in total are RL_ERR_LIMIT).
 * Example: e = (4, 2, 1), N = 1000, λ = 2: k = (8000/8)^(1/3) = 10,
 * res = (40, 20, 10).
 *
 * Walking a ray (what the Line Space does per voxel):
 *     rl_grid_dda it;
 *     if (rl_grid_dda_begin(grid, &ray, &it)) {
 *         uint32_t cell; float t0, t1;
 *         while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
 *             ... the ray is inside cell `cell` (coordinates it.current)
 *             for t in [t0, t1]; stop early as you like ...
 *         }
 *     }
 * Cells come front to back, each once, with t0 <= t1 (equal only where the
 * ray just touches a cell at an edge or corner, or for rounding at the
 * entry), and consecutive intervals share their end points. The walk
 * starts at max(ray.t_min, entry into bounds) and ends at min(ray.t_max,
 * exit from bounds), the bounds part widened by a relative 1e-6 so that a
 * ray grazing the bounds within its own rounding is still walked. Any ray
 * the accel layer accepts (finite origin and direction, some component
 * non-zero) may be walked; zero components are fine. Interval ends carry
 * rounding of a few ulps of the origin's distance: callers that compare
 * them with triangle hits need a relative margin (grid.c uses 1e-6; with
 * it the grid matches brute force for origins 10^4 grid sizes away). */
#ifndef RL_ACCEL_GRID_H
#define RL_ACCEL_GRID_H

#include <stdbool.h>
#include <stdint.h>

#include "rl/rl_accel.h"

#define RL_GRID_DEFAULT_LAMBDA 2.0f
#define RL_GRID_MAX_RES 512              /* per axis, from the heuristic */
#define RL_GRID_MAX_CELLS (1u << 24)     /* in total, from the heuristic */
/* The grid box is the triangles' box grown on every side by this fraction
 * of max(largest extent, largest |coordinate|), so that no triangle lies on
 * the outer faces and a flat box still has a positive extent. */
#define RL_GRID_PAD_REL 1e-5f

typedef struct rl_grid {
    rl_aabb bounds;           /* padded box the cells tile */
    int res[3];               /* cells per axis, >= 1 */
    uint32_t num_cells;       /* res[0] * res[1] * res[2] */
    rl_vec3 cell_size, inv_cell_size;
    uint32_t *cell_start;     /* num_cells + 1 prefix offsets into cell_tris */
    uint32_t *cell_tris;      /* triangle IDs, sorted within each cell */
    uint64_t num_references;  /* = cell_start[num_cells] */
    uint32_t num_triangles;
    rl_vec3 *tri_verts;       /* 3 per triangle */
    size_t memory_bytes;      /* all of the above */
} rl_grid;

/* The documented heuristic on its own: cells per axis for a box of the given
 * extent holding n triangles, λ = lambda (<= 0 -> 2). */
void rl_grid_resolution(rl_vec3 extent, uint64_t n, float lambda, int res[3]);

/* Builds from the scene's triangles; desc may be NULL (defaults) and its
 * threads, grid_lambda, grid_res and progress are used. RL_ERR_CANCELLED,
 * RL_ERR_OUT_OF_MEMORY, RL_ERR_LIMIT (more than 2^32-1 references),
 * RL_ERR_INVALID_ARG (NULL data or out). *out stays untouched on failure. */
rl_status rl_grid_build(const rl_scene_data *data, const rl_accel_desc *desc, rl_grid **out);
void rl_grid_free(rl_grid *grid);                   /* NULL is a no-op */

static inline uint32_t rl_grid_cell_index(const rl_grid *g, int x, int y, int z)
{
    return (uint32_t)x + (uint32_t)g->res[0] * ((uint32_t)y + (uint32_t)g->res[1] * (uint32_t)z);
}
void rl_grid_cell_coords(const rl_grid *g, uint32_t index, int cell[3]);
rl_aabb rl_grid_cell_bounds(const rl_grid *g, int x, int y, int z);
/* Cell containing p, clamped into the grid; returns whether p lies inside
 * the bounds (a point on a face between two cells belongs to the upper one). */
bool rl_grid_cell_of(const rl_grid *g, rl_vec3 p, int cell[3]);

/* 3D-DDA state (Amanatides & Woo 1987, Sec. 3): the current cell, and per
 * axis the step (-1, 0, +1), t_max (the ray parameter at which the walk
 * crosses the next cell boundary on that axis) and t_delta (the parameter
 * length of one cell along the ray). In contrast to the paper, t_max is
 * recomputed from the boundary plane at every step instead of adding
 * t_delta, so that long walks do not accumulate rounding error. */
typedef struct rl_grid_dda {
    const rl_grid *grid;
    int current[3];           /* the cell the last next() returned */
    int cell[3];              /* the cell the next next() returns */
    int step[3];
    float t_max[3], t_delta[3];
    float t;                  /* where the current cell is entered */
    float t_end;              /* min(ray.t_max, exit from the bounds) */
    rl_vec3 o, inv_d;         /* the ray, for the boundary planes */
    bool done;
} rl_grid_dda;

/* Clips the ray to the grid bounds and sets up the walk. False if the ray
 * segment misses the grid (the iterator then yields nothing). */
bool rl_grid_dda_begin(const rl_grid *g, const rl_ray *ray, rl_grid_dda *it);
/* Next cell along the ray with its parameter interval [*t_enter, *t_exit];
 * false once the walk has left the grid or passed ray.t_max. */
bool rl_grid_dda_next(rl_grid_dda *it, uint32_t *cell, float *t_enter, float *t_exit);

#endif
