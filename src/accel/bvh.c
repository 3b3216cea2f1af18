/* bvh.c: RL_ACCEL_BVH, the binned SAH BVH behind the rl_accel interface.
 *
 * Build: bvh_build.c (binary, Wald 2007), collapsed to RL_BVH_WIDTH (8
 * with AVX, else 4) wide by bvh_wide.c; traversal: bvh_wide_traverse.c;
 * watertight triangle test: watertight.h (Woop et al. 2013). The wide
 * tree measured about 2x the binary traversal's throughput on incoherent
 * rays (city, teapot), so the binary tree is only build scaffolding. This
 * file adapts them to rl_accel_class. */
#include <stdlib.h>

#include "accel/bvh.h"
#include "core/error.h"

static rl_status bvh_build(const rl_scene_data *data, const rl_accel_desc *desc, void **state,
                           rl_accel_stats *stats)
{
    rl_bvh *bvh = rl_calloc(1, sizeof *bvh);
    if (!bvh)
        return RL_ERR_OUT_OF_MEMORY;
    /* The binary tree and the triangle copies are build scaffolding that
     * rl_bvh_build_wide never keeps; its shape stays in the stats (nodes,
     * leaves, depth, SAH cost). */
    rl_status s = rl_bvh_build_wide(data, desc, bvh, stats);
    if (s) {
        rl_bvh_free(bvh);
        free(bvh);
        return s;
    }
    stats->memory_bytes += sizeof *bvh;
    *state = bvh;
    return RL_OK;
}

static bool bvh_intersect(const void *state, rl_ray *ray, rl_hit *hit)
{
    return rl_bvh_wide_intersect(state, ray, hit);
}

static bool bvh_occluded(const void *state, const rl_ray *ray) {
    return rl_bvh_wide_occluded(state, ray);
}

static bool bvh_occluder(const void *state, const rl_ray *ray, uint32_t *triangle)
{
    return rl_bvh_wide_occluder(state, ray, triangle);
}

#if RL_BVH_PACKETS
static unsigned bvh_intersect8(const void *state, rl_ray *rays, rl_hit *hits, unsigned active)
{
    return rl_bvh_packet_intersect(state, rays, hits, active);
}

static unsigned bvh_occluded8(const void *state, const rl_ray *rays, unsigned active)
{
    return rl_bvh_packet_occluded(state, rays, active);
}
#endif

static void bvh_release(void *state)
{
    rl_bvh_free(state);
    free(state);
}

const rl_accel_class rl_accel_bvh_class = {
    .name = "bvh",
    .build = bvh_build,
    .intersect = bvh_intersect,
    .occluded = bvh_occluded,
    .occluder = bvh_occluder,
    .release = bvh_release,
#if RL_BVH_PACKETS
    .intersect8 = bvh_intersect8,
    .occluded8 = bvh_occluded8,
#endif
};
