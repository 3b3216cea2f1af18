/* accel_internal.h: how an acceleration structure plugs into rl_accel.
 *
 * accel.c holds the generic layer (argument checks, NaN rays, stats, timing);
 * each kind provides one rl_accel_class with build/intersect/occluded/free on
 * its own state. Queries get rays that already passed the validity check
 * (finite origin/direction, non-zero direction, t_min <= t_max). */
#ifndef RL_ACCEL_INTERNAL_H
#define RL_ACCEL_INTERNAL_H

#include "rl/rl_accel.h"
#include "scene/masks.h"

typedef struct rl_accel_class {
    const char *name;
    /* Builds from the scene's flattened triangles; fills stats fields it
     * knows (memory, nodes, grid_res, ...). build_ms is measured by accel.c. */
    rl_status (*build)(const rl_scene_data *data, const rl_accel_desc *desc, void **state,
                       rl_accel_stats *stats);
    bool (*intersect)(const void *state, rl_ray *ray, rl_hit *hit);
    bool (*occluded)(const void *state, const rl_ray *ray);
    /* occluded naming the blocking triangle (rl_accel_occluder); may be
     * NULL: accel.c then asks intersect, which names the closest. */
    bool (*occluder)(const void *state, const rl_ray *ray, uint32_t *triangle);
    void (*release)(void *state);
    /* Packets of RL_ACCEL_PACKET rays for the batch queries (may be NULL:
     * accel.c then loops over single rays). Lanes in active (bit l: rays[l])
     * are valid rays with t_min >= 0 whose directions share one octant;
     * each lane's result must be exactly the single query's. intersect8
     * returns the lanes that hit, with their rays' t_max shortened and hits
     * filled as intersect does; occluded8 returns the blocked lanes. */
    unsigned (*intersect8)(const void *state, rl_ray *rays, rl_hit *hits, unsigned active);
    unsigned (*occluded8)(const void *state, const rl_ray *rays, unsigned active);
} rl_accel_class;

/* Rays per packet of the batch queries (as Embree's rtcIntersect8). */
#define RL_ACCEL_PACKET 8

extern const rl_accel_class rl_accel_bvh_class;
extern const rl_accel_class rl_accel_grid_class;
extern const rl_accel_class rl_accel_brute_class;
#ifdef RL_HAVE_EMBREE
extern const rl_accel_class rl_accel_embree_class;
#endif

/* Alpha masks (rl_material.alpha_cutoff): queries find a hit in a hole
 * and ask again beyond it, through at most this many holes (a ray along a
 * stack of foliage cards) before they give up. */
#define RL_MAX_MASK_SKIPS 256

/* A structure's closest hit, holes of alpha masks included: on a hit fills
 * *hit and shortens ray->t_max (rl_accel_class.intersect has this shape). */
typedef bool (*rl_closest_hit_fn)(const void *state, rl_ray *ray, rl_hit *hit);

/* The closest hit outside the holes of alpha masks (glTF MASK), for
 * rl_accel_intersect and the Line Spaces' exact queries: a hit in a hole is
 * skipped by asking closest again beyond it. Every test of ours (and
 * Embree's) takes t in the open interval (t_min, t_max), so the same
 * triangle is not found twice. masked = whether the scene has masks at all
 * (rl_data_has_masks): without them this is one call to closest. On a hit
 * shortens ray->t_max; on a miss hit->triangle and hit->object are
 * RL_ID_NONE. Inline so that each caller's closest is called directly.
 *
 * rl_skip_masked_hits is the loop after the first query, whose result
 * (found, *hit) comes from the caller: a packet lane's hit
 * (rl_accel_intersect_n) takes the same retries as a single ray's. */
static inline bool rl_skip_masked_hits(const rl_scene_data *data, bool masked, rl_closest_hit_fn closest,
                                       const void *state, rl_ray *ray, rl_hit *hit, bool found)
{
    for (int skips = 0; found && masked && rl_alpha_masked(data, hit->triangle, hit->u, hit->v); ++skips) {
        rl_ray r = *ray;
        r.t_min = hit->t;
        found = skips < RL_MAX_MASK_SKIPS && closest(state, &r, hit);
    }
    if (!found) {
        hit->triangle = hit->object = RL_ID_NONE;
        return false;
    }
    ray->t_max = hit->t;
    return true;
}

static inline bool rl_closest_unmasked_hit(const rl_scene_data *data, bool masked, rl_closest_hit_fn closest,
                                           const void *state, rl_ray *ray, rl_hit *hit)
{
    rl_ray r = *ray;
    bool found = closest(state, &r, hit);
    return rl_skip_masked_hits(data, masked, closest, state, ray, hit, found);
}

/* The grid of a committed RL_ACCEL_GRID accel (the Line Space builds on
 * it, rl_linespace.h); NULL for any other kind or an uncommitted accel. */
struct rl_grid;
const struct rl_grid *rl_accel_grid_state(const rl_accel *a);
/* Whether a has been committed (the scene Line Space borrows one). */
bool rl_accel_is_committed(const rl_accel *a);

/* The precomputed watertight ray/triangle test (Woop, Benthin, Wald 2013),
 * shared by every kind of ours so that they agree bit for bit on a hit. */
typedef struct rl_ray_watertight {
    int kx, ky, kz;           /* axis permutation: kz = largest |d| */
    float sx, sy, sz;         /* shear constants */
    rl_vec3 o;
} rl_ray_watertight;

void rl_ray_watertight_setup(const rl_ray *ray, rl_ray_watertight *w);
/* True for a hit with t in (t_min, t_max); fills *t, *u, *v. Backfaces hit too. */
bool rl_triangle_intersect_watertight(const rl_ray_watertight *w, rl_vec3 p0, rl_vec3 p1, rl_vec3 p2,
                                      float t_min, float t_max, float *t, float *u, float *v);

#endif
