/* grid.c: RL_ACCEL_GRID, the uniform grid with 3D-DDA traversal (Amanatides
 * & Woo 1987); layout, resolution heuristic and iterator contract in grid.h,
 * the build in grid_build.c.
 *
 * Closest hit walks the cells front to back and tests each cell's triangles
 * with the shared watertight test (watertight.h, inlined) against the whole
 * ray (not the cell's piece of it), keeping the closest hit so far. A
 * triangle that spans several cells may thus be hit beyond the current cell;
 * such a hit is kept but the walk goes on, and it stops only at the first
 * cell whose exit lies at or beyond the best hit: every triangle that could
 * be hit closer overlaps a cell visited by then. Each cell's list is tested
 * by tri_list.h (mailbox, ties to the lower triangle ID). */
#include <math.h>
#include <string.h>

#include "accel/accel_internal.h"
#include "accel/grid.h"
#include "accel/tri_list.h"
/* Relative rounding allowance on ray parameters: t computed by the walk and
 * t computed by the triangle test differ by a few ulps of the origin's
 * distance (grows with that distance; see grid.h). */
#define T_SLACK_REL 1e-6f

void rl_grid_cell_coords(const rl_grid *g, uint32_t index, int cell[3])
{
    uint32_t rx = (uint32_t)g->res[0], ry = (uint32_t)g->res[1];
    cell[0] = (int)(index % rx);
    cell[1] = (int)((index / rx) % ry);
    cell[2] = (int)(index / (rx * ry));
}

/* Boundary plane k on axis a; the one formula for cells and the walk. */
static inline float plane(const rl_grid *g, int a, int k)
{
    return rl_vget(g->bounds.min, a) + (float)k * rl_vget(g->cell_size, a);
}

rl_aabb rl_grid_cell_bounds(const rl_grid *g, int x, int y, int z)
{
    rl_aabb b = { { plane(g, 0, x), plane(g, 1, y), plane(g, 2, z) },
                  { plane(g, 0, x + 1), plane(g, 1, y + 1), plane(g, 2, z + 1) } };
    return b;
}

static inline int clamp_cell(float f, int res)
{
    if (!(f >= 0.0f))          /* also NaN */
        return 0;
    return f >= (float)(res - 1) ? res - 1 : (int)f;
}

bool rl_grid_cell_of(const rl_grid *g, rl_vec3 p, int cell[3])
{
    for (int a = 0; a < 3; ++a) {
        float f = floorf((rl_vget(p, a) - rl_vget(g->bounds.min, a)) * rl_vget(g->inv_cell_size, a));
        cell[a] = clamp_cell(f, g->res[a]);
    }
    return rl_aabb_contains(g->bounds, p);
}

bool rl_grid_dda_begin(const rl_grid *g, const rl_ray *ray, rl_grid_dda *it)
{
    /* Slab clip (Kay & Kajiya); a zero direction component is a slab the
     * ray is either always inside or never. */
    float t_in = -INFINITY, t_out = INFINITY;
    float inv[3];
    for (int a = 0; a < 3; ++a) {
        float o = rl_vget(ray->o, a), d = rl_vget(ray->d, a);
        float lo = rl_vget(g->bounds.min, a), hi = rl_vget(g->bounds.max, a);
        if (d == 0.0f) {
            if (o < lo || o > hi)
                return false;
            inv[a] = INFINITY;
            continue;
        }
        inv[a] = 1.0f / d;
        float tn = (lo - o) * inv[a], tf = (hi - o) * inv[a];
        if (tn > tf) {
            float s = tn;
            tn = tf;
            tf = s;
        }
        t_in = tn > t_in ? tn : t_in;
        t_out = tf < t_out ? tf : t_out;
    }
    /* Widened by T_SLACK_REL: a ray that grazes the bounds by less than its
     * own rounding may still hit a triangle on the outer cells. */
    float slack = T_SLACK_REL * rl_maxf(fabsf(t_in), fabsf(t_out));
    float t0 = rl_maxf(ray->t_min, t_in - slack), t1 = rl_minf(ray->t_max, t_out + slack);
    if (!(t0 <= t1))
        return false;
    it->grid = g;
    it->t = t0;
    it->t_end = t1;
    it->o = ray->o;
    it->inv_d = rl_v3(inv[0], inv[1], inv[2]);
    it->done = false;
    /* Amanatides & Woo, Sec. 3: the entry cell, then per axis the step, the
     * parameter of the next boundary crossing and the length of one cell. */
    for (int a = 0; a < 3; ++a) {
        float o = rl_vget(ray->o, a), d = rl_vget(ray->d, a);
        float entry = d == 0.0f ? o : o + d * t0;
        float f = floorf((entry - rl_vget(g->bounds.min, a)) * rl_vget(g->inv_cell_size, a));
        it->cell[a] = clamp_cell(f, g->res[a]);
        it->current[a] = it->cell[a];
        if (d == 0.0f) {
            it->step[a] = 0;
            it->t_max[a] = INFINITY;
            it->t_delta[a] = INFINITY;
        } else {
            it->step[a] = d > 0.0f ? 1 : -1;
            it->t_delta[a] = fabsf(rl_vget(g->cell_size, a) * inv[a]);
            it->t_max[a] = (plane(g, a, it->cell[a] + (d > 0.0f)) - o) * inv[a];
        }
    }
    return true;
}

bool rl_grid_dda_next(rl_grid_dda *it, uint32_t *cell, float *t_enter, float *t_exit)
{
    if (it->done)
        return false;
    const rl_grid *g = it->grid;
    memcpy(it->current, it->cell, sizeof it->current);
    *cell = rl_grid_cell_index(g, it->cell[0], it->cell[1], it->cell[2]);
    *t_enter = it->t;
    /* The axis whose boundary comes first; equal crossings (an edge or a
     * corner) step one axis at a time, visiting a touched cell with an
     * empty interval. */
    int a = it->t_max[0] < it->t_max[1] ? (it->t_max[0] < it->t_max[2] ? 0 : 2)
                                        : (it->t_max[1] < it->t_max[2] ? 1 : 2);
    float cross = it->t_max[a];
    if (!(cross < it->t_end)) {
        *t_exit = it->t_end;
        it->done = true;
        return true;
    }
    /* Rounding at the entry may put the crossing a hair before t. */
    float t = cross > it->t ? cross : it->t;
    *t_exit = t;
    it->t = t;
    it->cell[a] += it->step[a];
    if (it->cell[a] < 0 || it->cell[a] >= g->res[a]) {
        it->done = true;
        return true;
    }
    /* In contrast to the paper (t_max += t_delta): from the plane itself. */
    int k = it->cell[a] + (it->step[a] > 0);
    it->t_max[a] = (plane(g, a, k) - rl_vget(it->o, a)) * rl_vget(it->inv_d, a);
    return true;
}

static bool grid_intersect(const void *state, rl_ray *ray, rl_hit *hit)
{
    const rl_grid *g = state;
    rl_grid_dda it;
    if (!rl_grid_dda_begin(g, ray, &it))
        return false;
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    rl_mailbox mailbox;
    rl_mailbox_init(&mailbox);
    rl_tri_closest best = { RL_ID_NONE, ray->t_max, 0.0f, 0.0f };
    float limit = ray->t_max;
    uint32_t cell;
    float t_enter, t_exit;
    while (rl_grid_dda_next(&it, &cell, &t_enter, &t_exit)) {
        uint32_t first = g->cell_start[cell];
        rl_tri_list_closest(g->tri_verts, g->cell_tris + first, g->cell_start[cell + 1] - first, &w, ray->t_min,
                            &mailbox, &best, &limit);
        /* Done once the best hit lies inside the cells walked so far; the
         * margin hands hits within rounding of the exit to the next cell. */
        if (best.id != RL_ID_NONE && best.t <= t_exit - T_SLACK_REL * fabsf(t_exit))
            break;
    }
    if (best.id == RL_ID_NONE)
        return false;
    ray->t_max = best.t;
    hit->t = best.t;
    hit->u = best.u;
    hit->v = best.v;
    hit->triangle = best.id;
    return true;
}

static bool grid_occluded(const void *state, const rl_ray *ray)
{
    const rl_grid *g = state;
    rl_grid_dda it;
    if (!rl_grid_dda_begin(g, ray, &it))
        return false;
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    rl_mailbox mailbox;
    rl_mailbox_init(&mailbox);
    uint32_t cell;
    float t_enter, t_exit;
    while (rl_grid_dda_next(&it, &cell, &t_enter, &t_exit)) {
        uint32_t first = g->cell_start[cell];
        if (rl_tri_list_any(g->tri_verts, g->cell_tris + first, g->cell_start[cell + 1] - first, &w, ray->t_min,
                            ray->t_max, &mailbox))
            return true;
    }
    return false;
}

static rl_status grid_build(const rl_scene_data *data, const rl_accel_desc *desc, void **state,
                            rl_accel_stats *stats)
{
    rl_grid *g = NULL;
    rl_status s = rl_grid_build(data, desc, &g);
    if (s)
        return s;
    stats->memory_bytes = g->memory_bytes;
    for (int a = 0; a < 3; ++a)
        stats->grid_res[a] = g->res[a];
    stats->grid_references = g->num_references;
    *state = g;
    return RL_OK;
}

static void grid_release(void *state) { rl_grid_free(state); }

const rl_accel_class rl_accel_grid_class = {
    .name = "grid",
    .build = grid_build,
    .intersect = grid_intersect,
    .occluded = grid_occluded,
    .release = grid_release,
};
