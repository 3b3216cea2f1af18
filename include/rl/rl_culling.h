/* rl_culling.h: statistics of the visibility-culling renderers (chcpp,
 * svs, visset, select) and of the level-of-detail renderer surfels, for the last
 * frame they rendered. The generic rl_render_stats carry the triangles
 * rasterized and the occlusion queries; these add what the algorithms
 * decide per node. */
#ifndef RL_CULLING_H
#define RL_CULLING_H

#include "rl/rl_common.h"
#include "rl/rl_render.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_culling_stats {
    uint32_t octree_nodes, octree_depth;
    uint32_t nodes_visited;           /* taken from the traversal queue */
    uint32_t nodes_frustum_culled;
    uint32_t nodes_occluded;          /* chcpp: found invisible by a query; svs: drawn from
                                       * their stored sets (whose hidden objects are skipped) */
    uint32_t objects_drawn;
    uint64_t triangles_drawn;         /* of objects (queries not included) */
    uint64_t queries;                 /* occlusion queries issued (a multi-query counts once) */
    uint64_t multiqueries;            /* queries over more than one node */
    uint64_t multiqueries_failed;     /* multi-queries that found something visible */
    uint64_t query_boxes;             /* boxes rasterized by all queries */
    uint64_t points_drawn;            /* surfels */
    uint32_t surfel_nodes;            /* nodes drawn (partly) as surfels */
    double preprocess_ms;             /* building what the frame needed first (octree, surfels, visibility) */
    uint32_t selected;                /* select: 1 = its first, 2 = its second renderer drew the frame
                                       * (the other fields are that renderer's); 0 for the others */
    uint64_t queries_ready;           /* chcpp: answers found there when polled (all, in software) */
    uint64_t queries_waited;          /* chcpp: answers waited for, nothing else being left to do */
    /* chcpp's latency hiding (Mattausch et al. 2008, Sec. 4.1). Answers
     * read in the frame (queries_ready + queries_waited) include those of
     * the queries the last frame carried in: queries + queries_carried_in
     * = queries_ready + queries_waited + queries_carried. */
    uint64_t queries_carried;         /* answers not read by the frame's end, left to the next frame
                                       * (latency=frame; previously visible nodes only) */
    uint64_t queries_carried_in;      /* the last frame's queries_carried, read here or carried on */
    uint64_t queries_filled;          /* V-queue queries issued while an answer was awaited */
} rl_culling_stats;

/* RL_ERR_INVALID_ARG when r is not one of these renderers or has rendered
 * nothing yet. */
RL_API rl_status rl_culling_get_stats(const rl_renderer *r, rl_culling_stats *out);

#ifdef __cplusplus
}
#endif
#endif
