/* brute.c: RL_ACCEL_BRUTE, every ray against every triangle.
 *
 * The reference the other kinds are tested against: O(N) per ray, no build,
 * the shared watertight test (watertight.c). Closest hit: triangles are
 * visited in ID order and only a strictly closer t replaces the best, so
 * among hits at equal t the lowest triangle ID wins -- the tie rule every
 * kind of ours follows, so that BVH and grid agree with this exactly. */
#include <stdlib.h>

#include "accel/accel_internal.h"
#include "accel/watertight.h"
#include "core/error.h"

typedef struct brute {
    const rl_scene_data *data;   /* borrowed: the scene outlives the accel */
} brute;

static rl_status brute_build(const rl_scene_data *data, const rl_accel_desc *desc, void **state,
                             rl_accel_stats *stats)
{
    brute *b = rl_alloc(sizeof *b);
    if (!b)
        return RL_ERR_OUT_OF_MEMORY;
    b->data = data;
    if (desc->progress && !desc->progress(desc->user, 1.0)) {
        free(b);
        return rl_error(RL_ERR_CANCELLED, "accel brute: build cancelled");
    }
    stats->memory_bytes = sizeof *b;
    *state = b;
    return RL_OK;
}

static inline void triangle(const rl_scene_data *d, uint32_t i, rl_vec3 *p0, rl_vec3 *p1, rl_vec3 *p2)
{
    const uint32_t *idx = d->indices + 3 * (size_t)i;
    *p0 = d->positions[idx[0]];
    *p1 = d->positions[idx[1]];
    *p2 = d->positions[idx[2]];
}

static bool brute_intersect(const void *state, rl_ray *ray, rl_hit *hit)
{
    const rl_scene_data *d = ((const brute *)state)->data;
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    bool found = false;
    for (uint32_t i = 0; i < d->num_triangles; ++i) {
        rl_vec3 p0, p1, p2;
        float t, u, v;
        triangle(d, i, &p0, &p1, &p2);
        /* Strictly closer only: equal t keeps the earlier (lower) ID. */
        if (rl_watertight_hit(&w, p0, p1, p2, ray->t_min, ray->t_max, &t, &u, &v)) {
            ray->t_max = t;
            hit->t = t;
            hit->u = u;
            hit->v = v;
            hit->triangle = i;
            found = true;
        }
    }
    return found;
}

static bool brute_occluded(const void *state, const rl_ray *ray)
{
    const rl_scene_data *d = ((const brute *)state)->data;
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    for (uint32_t i = 0; i < d->num_triangles; ++i) {
        rl_vec3 p0, p1, p2;
        float t, u, v;
        triangle(d, i, &p0, &p1, &p2);
        if (rl_watertight_hit(&w, p0, p1, p2, ray->t_min, ray->t_max, &t, &u, &v))
            return true;
    }
    return false;
}

static void brute_release(void *state) { free(state); }

const rl_accel_class rl_accel_brute_class = {
    .name = "brute",
    .build = brute_build,
    .intersect = brute_intersect,
    .occluded = brute_occluded,
    .release = brute_release,
};
