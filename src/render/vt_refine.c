/* vt_refine.c: the refinement of Vertex Tracing (Ullmann 2003, Sec. 3.3,
 * 3.4, 4.4): the ID-buffer pre-pass, the edge list sorted by projected
 * length, the subdivision criteria, forced refinement, and the stages that
 * alternate refinement with parallel sampling.
 *
 * Stages. The thesis processes the sorted edge list one edge at a time,
 * longest first, and lets secondary threads sample ahead (Sec. 4.4.2). We
 * keep "longest first" at the granularity of one octave: a stage takes every
 * edge within a factor two of the longest one (all of them were sampled in
 * earlier stages), tests them in length order, splits where a criterion
 * fires and hands the new vertices to the samplers at once; the stage ends
 * when they are all sampled. Sub-edges are at most about half as long, so
 * they land in a later stage, exactly as in the sequential order; only the
 * new inner edges (e_L, e_R of Fig. 3.5) may be longer and are then simply
 * tested first in the next stage. The result does not depend on the number
 * of threads, and the stage is the natural unit of the progressive display
 * (Sec. 3.5.1: "after k refinement stages"). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "render/renderer.h"
#include "render/vt_run.h"
#include "rl/rl_timer.h"

#define BAND 0.5f                  /* a stage: lengths within [top * BAND, top] */
/* A face lower than this over its longest side has no area (Sec. 3.3.2:
 * xi = 1, A -> 0) and is not refined: float rounding can otherwise keep a
 * sliver "refining" forever (the thesis' endless recursion). The measure is
 * the height in pixels, not xi itself: xi ~ 1 - 2 h^2 / c^2 for a sliver of
 * base c and height h, so any threshold on xi calls long slivers a few
 * pixels wide flat, and their long edges would never be split again (they
 * showed as streaks along the walls of the cups). */
#define FLAT_HEIGHT_PX 0.05f

static double now_ms(void)
{
    return rl_time_s() * 1000.0;
}

/* ------------------------------------------------------------ pre-pass -- */

rl_status vt_prepass(vt_run *run, rl_image *depth_image, uint32_t *triangle_ids)
{
    /* The target with the triangle IDs and no object IDs (a NULL layer is
     * not written, rl_raster_target_for). */
    rl_image target = *depth_image;
    target.layers |= RL_LAYER_ID;
    target.object_id = NULL;
    target.triangle_id = triangle_ids;
    rl_image *depth_ids = &target;
    const vt_settings *set = run->set;
    vt_mesh *m = run->mesh;
    rl_image frame;
    rl_status st = vt_draw_base(run);
    if (st == RL_OK)
        st = vt_draw_target(run, &frame);
    rl_raster *ras = run->ras;
    if (st == RL_OK)
        st = rl_raster_set_target(ras, depth_ids, &run->view_m, &run->proj_m);
    if (st == RL_OK) {
        /* Sec. 3.5, Fig. 3.17, first pass: the whole scene into the ID and
         * Z buffers. The rasterized objects are in the frame's depth
         * already (vt_draw_base); the VT objects go on top of a copy of
         * it. Every triangle keeps its own ID, so the non-VT objects need
         * no special colour 0: their pixels name no VT face. */
        rl_image ids = *depth_ids;
        rl_raster_counters c;
        memset(&c, 0, sizeof c);
        if (run->drawer) {
            /* The image is GL's: the software's depth of the rasterized
             * objects is drawn here (depth is that of the lit draw), so
             * that the refinement, and with it the refined mesh, is the
             * software path's whichever draws the image. */
            rl_image_clear(&ids);
            rl_drawer_desc base = { .shading = RL_SHADING_FLAT, .threads = set->threads,
                                    .flags = RL_RASTER_NO_COLOR, .object_mask = run->object_raster };
            st = rl_raster_draw_scene(ras, run->data, run->view.eye, &base, &c, NULL, NULL);
        } else {
            ids.depth = NULL;         /* overwritten by the copy below */
            rl_image_clear(&ids);
            memcpy(depth_ids->depth, frame.depth,
                   (size_t)frame.width * (size_t)frame.height * sizeof *frame.depth);
        }
        rl_drawer_desc desc = { .shading = RL_SHADING_FLAT, .threads = set->threads,
                                      .flags = RL_RASTER_NO_COLOR, .object_mask = run->object_vt };
        if (st == RL_OK)
            st = rl_raster_draw_scene(ras, run->data, run->view.eye, &desc, &c, NULL, NULL);
    }
    if (st != RL_OK)
        return st;

    /* Fig. 3.11: every pixel flags the face it shows. */
    size_t n = (size_t)depth_ids->width * (size_t)depth_ids->height;
    if (set->id_test) {
        for (size_t i = 0; i < n; ++i) {
            uint32_t tri = depth_ids->triangle_id[i];
            if (tri < run->data->num_triangles && run->tri_face[tri] != VT_NONE)
                m->faces[run->tri_face[tri]].visible = 1;
        }
    } else {
        for (uint32_t f = 0; f < m->num_primary_faces; ++f)
            m->faces[f].visible = 1;
    }
    for (uint32_t f = 0; f < m->num_primary_faces; ++f)
        run->stats.visible_primary_faces += m->faces[f].visible;
    vt_project_primary(run, depth_ids);
    return RL_OK;
}

void vt_project_primary(vt_run *run, const rl_image *depth_ids)
{
    vt_mesh *m = run->mesh;
    run->view.depth = depth_ids->depth;
    for (uint32_t v = 0; v < m->num_primary_verts; ++v) {
        vt_vertex *vx = &m->verts[v];
        vt_project_vertex(&run->view, vx);
        vx->visible = run->set->z_test ? (uint8_t)vt_vertex_visible(&run->view, vx) : 1;
    }
}

/* ---------------------------------------------------------- refinement -- */

typedef struct refine_ctx {
    vt_run *run;
    uint32_t *batch;    uint32_t batch_count, batch_cap;
    uint32_t *forced;   uint32_t forced_count, forced_cap;
    double refine_ms;   /* primary thread in refinement code, without the
                         * blocks the runtime had it sample meanwhile */
    double update_ms;   /* primary thread in progressive updates */
    /* Sec. 6.1.2, shaft_cull on: the scene's triangle boxes, and per face
     * the verdict of its shafts (0 not yet tested, 1 empty, 2 occupied):
     * each face is asked once for each of its edges */
    vt_shaft_index shafts;
    uint8_t *face_shaft;  uint32_t face_shaft_cap;
} refine_ctx;

/* Room for need edges in the stage's batch, as vt_array_resize's: a stage
 * at min_edge 1 holds hundreds of thousands, and a realloc'd batch left each
 * smaller copy behind in the heap, resident to the frame's peak. */
static bool batch_reserve(refine_ctx *ctx, uint32_t need)
{
    return vt_array_reserve((void **)&ctx->batch, &ctx->batch_cap, need, sizeof *ctx->batch, 1024, UINT32_MAX,
                            "vt refinement batch") == RL_OK;
}

/* A package of a distributed frame (run->seed) refines its own faces: an
 * edge is its business when a face on either side descends from one of
 * them (or, with dist_postpass, from a face hidden in the ID test). Splits of border edges reach into the neighbours, whose insides
 * their own packages refine; without this test a package would refine
 * the neighbours' insides too, twice the work for nothing drawn. */
static bool edge_in_package(const vt_run *run, const vt_edge *ed)
{
    if (!run->seed)
        return true;
    const vt_mesh *m = run->mesh;
    for (int k = 0; k < 2; ++k) {
        uint32_t f = ed->face[k] != VT_NONE ? vt_face_root(m, ed->face[k]) : VT_NONE;
        if (f != VT_NONE && run->seed[f])
            return true;
    }
    return false;
}

/* An edge enters the edge list (Fig. 3.4) if it is long enough to be split
 * and visible: on screen (Sec. 3.4.3) and, unless it is primary (the ID
 * buffer already decided those, Fig. 3.12), with at least one end passing
 * the z test (Sec. 3.4.2, Fig. 3.14). Its ends are queued for sampling so
 * that the criterion can be evaluated when the edge comes up. */
static void consider_edge(refine_ctx *ctx, uint32_t e, bool primary)
{
    vt_run *run = ctx->run;
    const vt_settings *set = run->set;
    vt_mesh *m = run->mesh;
    vt_edge *ed = &m->edges[e];
    const vt_vertex *a = &m->verts[ed->v[0]], *b = &m->verts[ed->v[1]];
    const float length = vt_edge_length(&run->view, a, b);
    /* pixel_split: shorter edges enter too, and are split only where a
     * criterion fires and a pixel shows it (run_stage) */
    const float shortest = set->pixel_split != VT_PIXEL_SPLIT_OFF && set->pixel_floor < set->min_edge
                               ? set->pixel_floor : set->min_edge;
    if (!(length > shortest) || vt_edge_is_split(ed) || vt_edge_queued(m, e) ||
        (!primary && !edge_in_package(run, ed)))
        return;
    if (!primary && set->z_test && !a->visible && !b->visible) {
        run->stats.edges_culled_z++;
        return;
    }
    if (set->clip_test && !vt_edge_in_viewport(&run->view, a, b)) {
        run->stats.edges_culled_viewport++;
        return;
    }
    uint32_t v0 = ed->v[0], v1 = ed->v[1];
    vt_sample_queue(run, v0);
    vt_sample_queue(run, v1);
    if (vt_heap_push(run->heap, e, length) != RL_OK) {
        run->failed = true;
        return;
    }
    vt_edge_set_queued(m, e, true);
}

/* Forced refinement (Sec. 3.3.2, Fig. 3.10): in each new sub-face the side
 * opposite the new vertex is the base; a compression xi = base / (sum of
 * the other two) above eps_Z forces the base to be split, unless it is at
 * the minimum length or the face has no area (xi = 1). */
static void check_forced(refine_ctx *ctx, uint32_t f, uint32_t mid)
{
    vt_run *run = ctx->run;
    vt_mesh *m = run->mesh;
    const vt_face *face = &m->faces[f];
    int slot = face->v[0] == mid ? 0 : face->v[1] == mid ? 1 : face->v[2] == mid ? 2 : -1;
    if (slot < 0 || !face->visible)
        return;
    uint32_t base = face->e[slot];
    const vt_edge *be = &m->edges[base];
    if (vt_edge_is_split(be))
        return;
    if (!(vt_face_xi(m, f, slot) > run->set->eps_z) || !(vt_face_height(m, f) > FLAT_HEIGHT_PX))
        return;
    if (!rl_reserve_u32((void **)&ctx->forced, &ctx->forced_cap, (uint64_t)ctx->forced_count + 1, sizeof *ctx->forced, 1024)) {
        run->failed = true;
        return;
    }
    ctx->forced[ctx->forced_count++] = base;
}

static bool budget_left(const vt_run *run)
{
    return run->mesh->num_verts < run->set->max_vertices;
}

/* Splits edge e (Sec. 3.3, eq. 3.7-3.8, Fig. 3.5): the new vertex is
 * projected, z-tested and queued; the new edges are considered for the
 * edge list; the new faces are checked for forced refinement. */
static void split_edge(refine_ctx *ctx, uint32_t e, uint8_t reason, uint16_t stage)
{
    vt_run *run = ctx->run;
    vt_mesh *m = run->mesh;
    uint32_t new_edges[4], new_faces[4], ne = 0, nf = 0;
    uint32_t mid = vt_mesh_split(m, e, stage, new_edges, &ne, new_faces, &nf);
    if (mid == VT_NONE || vt_run_reserve(run) != RL_OK) {
        run->failed = true;
        return;
    }
    run->reason[mid] = reason;
    vt_vertex *v = &m->verts[mid];
    vt_project_vertex(&run->view, v);
    v->visible = run->set->z_test ? (uint8_t)vt_vertex_visible(&run->view, v) : 1;
    run->stats.vertices_generated++;
    if (reason & VT_REASON_FORCED)
        run->stats.splits_forced++;
    vt_sample_queue_mid(run, mid, m->edges[e].v[0], m->edges[e].v[1]);
    for (uint32_t i = 0; i < ne; ++i)
        consider_edge(ctx, new_edges[i], false);
    if (run->set->forced)
        for (uint32_t i = 0; i < nf; ++i)
            check_forced(ctx, new_faces[i], mid);
}

/* Splits the bases collected by check_forced, and the bases their splits
 * force in turn, down to the minimum length. */
static void run_forced(refine_ctx *ctx, uint16_t stage)
{
    vt_run *run = ctx->run;
    const vt_settings *set = run->set;
    while (ctx->forced_count && !run->failed && budget_left(run)) {
        uint32_t e = ctx->forced[--ctx->forced_count];
        vt_mesh *m = run->mesh;
        vt_edge *ed = &m->edges[e];
        if (vt_edge_is_split(ed) || !edge_in_package(run, ed))
            continue;
        const vt_vertex *a = &m->verts[ed->v[0]], *b = &m->verts[ed->v[1]];
        if (!(vt_edge_length(&run->view, a, b) > set->min_edge))
            continue;
        /* Hidden bases are not worth rays: the same tests as the edge list. */
        if ((set->z_test && !a->visible && !b->visible) ||
            (set->clip_test && !vt_edge_in_viewport(&run->view, a, b)))
            continue;
        split_edge(ctx, e, VT_REASON_FORCED, stage);
    }
    ctx->forced_count = 0;
}

/* Sec. 3.3.2: refining where no adjacent face has projected area cannot
 * help and need not stop (the endless recursion of A -> 0). */
static bool has_area(vt_mesh *m, const vt_edge *ed)
{
    for (int k = 0; k < 2; ++k)
        if (ed->face[k] != VT_NONE && vt_face_height(m, ed->face[k]) > FLAT_HEIGHT_PX)
            return true;
    return false;
}

static uint8_t reason_of(unsigned bits)
{
    return (uint8_t)(((bits & VT_CRIT_RGB) ? VT_REASON_RGB : 0) | ((bits & VT_CRIT_HSV) ? VT_REASON_HSV : 0) |
                     ((bits & VT_CRIT_TREE) ? VT_REASON_TREE : 0));
}

/* Sec. 6.1.2: whether face f's shafts hold another object. */
static bool face_shaft_fires(refine_ctx *ctx, uint32_t f)
{
    vt_run *run = ctx->run;
    if (f == VT_NONE)
        return false;
    if (f >= ctx->face_shaft_cap) {
        uint32_t old = ctx->face_shaft_cap;
        if (!rl_reserve_u32((void **)&ctx->face_shaft, &ctx->face_shaft_cap, (uint64_t)run->mesh->num_faces,
                            sizeof *ctx->face_shaft, 4096)) {
            run->failed = true;
            return false;
        }
        memset(ctx->face_shaft + old, 0, ctx->face_shaft_cap - old);
    }
    if (!ctx->face_shaft[f]) {
        ctx->face_shaft[f] = vt_shaft_face_fires(run, &ctx->shafts, f) ? 2 : 1;
        run->stats.shaft_faces_tested++;
    }
    return ctx->face_shaft[f] == 2;
}

/* Sec. 6.1: an edge the criteria let pass may still hide a highlight or a
 * small occluder between its ends; the reason it is split for, or 0. */
static uint8_t correctness_reason(refine_ctx *ctx, const vt_edge *ed)
{
    vt_run *run = ctx->run;
    const vt_settings *set = run->set;
    vt_mesh *m = run->mesh;
    if (set->nonlinear != VT_NONLINEAR_OFF && vt_nonlinear_fires(run, &m->verts[ed->v[0]], &m->verts[ed->v[1]])) {
        run->stats.splits_nonlinear++;
        return VT_REASON_NONLINEAR;
    }
    if (set->shaft_cull != VT_SHAFT_OFF) {
        uint32_t f0 = ed->face[0], f1 = ed->face[1];
        if (face_shaft_fires(ctx, f0) || face_shaft_fires(ctx, f1)) {
            run->stats.splits_shaft++;
            return VT_REASON_SHAFT;
        }
    }
    return 0;
}

/* Option pixel_split (ours). At min_edge the refinement stops, and an edge
 * whose ends still differ is drawn as a Gouraud ramp (Sec. 3.5) over its
 * faces, where the ray tracer's pixels step: on the cup of table:variant=cup
 * these ribbons along every discontinuity are most of the VT pixels' own
 * error (docs/vertex-tracing.md, "where the SSIM on the cup is lost"). A
 * split changes the image only where a pixel centre lies in a face it
 * splits (the rasterizer samples at pixel centres), and it places the step
 * between two pixels only where centres lie on both sides of the new inner
 * edge (midpoint to the opposite corner). Whether face f of edge ed, cut
 * that way, holds such centres; faces spanning more than 64 centres' box
 * count as holding them, faces behind the eye too. */
#define PIXEL_SPLIT_MAX_CENTRES 64
static bool split_shows(const vt_run *run, uint32_t f, const vt_edge *ed)
{
    if (f == VT_NONE)
        return false;
    const vt_mesh *m = run->mesh;
    const vt_face *face = &m->faces[f];
    const vt_vertex *p[3];
    uint32_t c = VT_NONE;
    for (int k = 0; k < 3; ++k) {
        p[k] = &m->verts[face->v[k]];
        if (!(p[k]->cw > 0.0f))
            return true;
        if (face->v[k] != ed->v[0] && face->v[k] != ed->v[1])
            c = face->v[k];
    }
    if (c == VT_NONE)
        return false;
    double x0 = p[0]->sx, x1 = p[0]->sx, y0 = p[0]->sy, y1 = p[0]->sy;
    for (int k = 1; k < 3; ++k) {
        x0 = p[k]->sx < x0 ? p[k]->sx : x0;
        x1 = p[k]->sx > x1 ? p[k]->sx : x1;
        y0 = p[k]->sy < y0 ? p[k]->sy : y0;
        y1 = p[k]->sy > y1 ? p[k]->sy : y1;
    }
    /* pixel centres (i + 0.5, j + 0.5) in the box and on the screen */
    long i0 = (long)ceil(x0 - 0.5), i1 = (long)floor(x1 - 0.5);
    long j0 = (long)ceil(y0 - 0.5), j1 = (long)floor(y1 - 0.5);
    i0 = i0 < 0 ? 0 : i0;
    j0 = j0 < 0 ? 0 : j0;
    i1 = i1 > run->view.width - 1 ? run->view.width - 1 : i1;
    j1 = j1 > run->view.height - 1 ? run->view.height - 1 : j1;
    if (i1 < i0 || j1 < j0)
        return false;
    if ((i1 - i0 + 1) * (j1 - j0 + 1) > PIXEL_SPLIT_MAX_CENTRES)
        return true;
    double area = ((double)p[1]->sx - p[0]->sx) * ((double)p[2]->sy - p[0]->sy) -
                  ((double)p[1]->sy - p[0]->sy) * ((double)p[2]->sx - p[0]->sx);
    if (area == 0.0)
        return false;
    const double sign = area > 0.0 ? 1.0 : -1.0;
    const vt_vertex *a = &m->verts[ed->v[0]], *b = &m->verts[ed->v[1]], *cv = &m->verts[c];
    const double mx = 0.5 * ((double)a->sx + b->sx), my = 0.5 * ((double)a->sy + b->sy);
    bool before = false, after = false;
    for (long j = j0; j <= j1; ++j)
        for (long i = i0; i <= i1; ++i) {
            const double qx = (double)i + 0.5, qy = (double)j + 0.5;
            bool inside = true;
            for (int k = 0; k < 3 && inside; ++k) {
                const vt_vertex *u = p[k], *w = p[(k + 1) % 3];
                double e = ((double)w->sx - u->sx) * (qy - u->sy) - ((double)w->sy - u->sy) * (qx - u->sx);
                inside = e * sign >= 0.0;
            }
            if (!inside)
                continue;
            if (run->set->pixel_split == VT_PIXEL_SPLIT_INSIDE)
                return true;
            double side = ((double)cv->sx - mx) * (qy - my) - ((double)cv->sy - my) * (qx - mx);
            before |= side > 0.0;
            after |= side < 0.0;
            if (before && after)
                return true;
        }
    return false;
}

/* One stage: the edges of the top octave, tested longest first. */
static void run_stage(refine_ctx *ctx, uint16_t stage)
{
    vt_run *run = ctx->run;
    vt_mesh *m = run->mesh;
    float band = vt_heap_top(run->heap) * BAND;
    ctx->batch_count = 0;
    uint32_t e;
    float length;
    while (vt_heap_top(run->heap) >= band && vt_heap_pop(run->heap, &e, &length)) {
        if (!batch_reserve(ctx, ctx->batch_count + 1)) {
            run->failed = true;
            return;
        }
        vt_edge_set_queued(m, e, false);
        ctx->batch[ctx->batch_count++] = e;
    }
    /* The stage's edges moved from the list to the batch: the list's room
     * goes back now. Its touched pages otherwise stayed resident to the
     * end of the refinement, where the frame peaks with the whole mesh
     * (2.2 MB of that peak on table at 1024^2 with deferred_split, an RSS
     * trace; bench/README.md, "Memory, fourth pass"). */
    vt_heap_shrink(run->heap);
    for (uint32_t i = 0; i < ctx->batch_count && !run->failed; ++i) {
        if (!budget_left(run))
            break;
        vt_edge *ed = &m->edges[ctx->batch[i]];
        if (vt_edge_is_split(ed))
            continue;                       /* split meanwhile by forced refinement */
        const vt_vertex *a = &m->verts[ed->v[0]], *b = &m->verts[ed->v[1]];
        if (a->state != VT_SAMPLED || b->state != VT_SAMPLED)
            continue;                       /* cannot happen: queued when pushed */
        if (!has_area(m, ed))
            continue;
        unsigned bits = vt_criteria_test(&run->set->criteria, &m->samples[ed->v[0]], &m->samples[ed->v[1]]);
        run->stats.edges_tested++;
        if (run->set->pixel_split != VT_PIXEL_SPLIT_OFF && !(vt_edge_length(&run->view, a, b) > run->set->min_edge)) {
            /* below min_edge (pixel_split): a criterion, and a pixel to show it */
            if (!bits || !(split_shows(run, ed->face[0], ed) || split_shows(run, ed->face[1], ed)))
                continue;
            run->stats.splits_pixel++;
        } else if (!bits) {
            uint8_t why = correctness_reason(ctx, ed);
            if (why && !run->failed)
                split_edge(ctx, ctx->batch[i], why, stage);
            if (why)
                run_forced(ctx, stage);
            continue;
        }
        run->stats.splits_rgb += (bits & VT_CRIT_RGB) != 0;
        run->stats.splits_hsv += (bits & VT_CRIT_HSV) != 0;
        run->stats.splits_tree += (bits & VT_CRIT_TREE) != 0;
        split_edge(ctx, ctx->batch[i], reason_of(bits), stage);
        run_forced(ctx, stage);
    }
}

/* Progress of an adaptive process has no known total; the longest edge
 * left, on a log scale between the first stage and the minimum length,
 * is a fair guess. */
static double progress_of(float top, float first, float min_edge)
{
    if (!(top > min_edge) || !(first > min_edge))
        return 1.0;
    double done = log((double)first / (double)top) / log((double)first / (double)min_edge);
    return done < 0.0 ? 0.0 : done > 1.0 ? 1.0 : done;
}

/* Ends a refinement interval begun at (t0, busy0): an OpenMP runtime may
 * run a spawned block on the spawning thread at once (always, with one
 * thread), and that is sampling, not refinement (Fig. 5.9's split). */
static void end_interval(refine_ctx *ctx, double t0, double busy0)
{
    ctx->refine_ms += (now_ms() - t0) - (vt_sample_busy_ms(ctx->run) - busy0);
}

/* ------------------------------------------------------ sample merging -- */

static uint32_t find_root(uint32_t *parent, uint32_t v)
{
    while (parent[v] != v) {
        parent[v] = parent[parent[v]];   /* path halving */
        v = parent[v];
    }
    return v;
}

static bool primary_edge_visible(const vt_mesh *m, const vt_edge *ed)
{
    return (ed->face[0] != VT_NONE && m->faces[ed->face[0]].visible) ||
           (ed->face[1] != VT_NONE && m->faces[ed->face[1]].visible);
}

/* A primary edge starts the refinement (stage 0) when one of its faces is
 * visible, or, for a package of a distributed frame (run->seed), one of
 * its faces is in the package: the ring of visible faces around it is
 * visible only so that forced refinement checks their sub-faces as one
 * process would (vt_run.seed). */
static bool primary_edge_seeds(const vt_run *run, const vt_edge *ed)
{
    if (!run->seed)
        return primary_edge_visible(run->mesh, ed);
    return (ed->face[0] != VT_NONE && run->seed[ed->face[0]] == 1) ||
           (ed->face[1] != VT_NONE && run->seed[ed->face[1]] == 1);
}

/* Sample reduction, Ullmann Sec. 6.2.1: the two ends of a visible primary
 * edge whose projection is shorter than merge_px count as one sample.
 * Chains of short edges form one group (union-find); the lowest vertex of
 * a group is traced, the others are marked queued so that the stage-0
 * queue skips them, and take its sample after the flush (merge_finish).
 * Returns the group roots (parent[v] after path compression) or NULL when
 * nothing merges; *fail on out of memory. */
static uint32_t *merge_begin(vt_run *run, bool *fail)
{
    vt_mesh *m = run->mesh;
    const float eps = run->set->merge_px;
    *fail = false;
    if (!(eps > 0.0f) || m->num_primary_verts == 0)
        return NULL;
    uint32_t *parent = malloc((size_t)m->num_primary_verts * sizeof *parent);
    if (!parent) {
        *fail = true;
        return NULL;
    }
    for (uint32_t v = 0; v < m->num_primary_verts; ++v)
        parent[v] = v;
    bool any = false;
    for (uint32_t e = 0; e < m->num_primary_edges; ++e) {
        const vt_edge *ed = &m->edges[e];
        const vt_vertex *a = &m->verts[ed->v[0]], *b = &m->verts[ed->v[1]];
        if (!primary_edge_visible(m, ed) || !(a->cw > 0.0f) || !(b->cw > 0.0f) ||
            !(vt_edge_length(&run->view, a, b) < eps))
            continue;
        uint32_t ra = find_root(parent, ed->v[0]), rb = find_root(parent, ed->v[1]);
        if (ra != rb) {
            /* The lower index is the root: the result does not depend on
             * the order edges are visited in. */
            if (ra < rb)
                parent[rb] = ra;
            else
                parent[ra] = rb;
            any = true;
        }
    }
    if (!any) {
        free(parent);
        return NULL;
    }
    for (uint32_t v = 0; v < m->num_primary_verts; ++v)
        if (find_root(parent, v) != v && m->verts[v].state == VT_UNSAMPLED)
            m->verts[v].state = VT_QUEUED;
    return parent;
}

/* After the stage-0 flush: every merged vertex takes its root's sample.
 * The primary term's texture coordinates stay the vertex's own (the draw
 * takes them from the vertex, not the sample), so that deferred textures
 * (Sec. 3.5.3) are still looked up where it lies. */
static void merge_finish(vt_run *run, uint32_t *parent)
{
    vt_mesh *m = run->mesh;
    for (uint32_t v = 0; v < m->num_primary_verts; ++v) {
        uint32_t r = find_root(parent, v);
        if (r == v || m->verts[v].state != VT_QUEUED || m->verts[r].state != VT_SAMPLED)
            continue;
        m->samples[v] = m->samples[r];
        m->verts[v].state = VT_SAMPLED;
        run->stats.vertices_merged++;
    }
    /* A member whose root was not traced (cannot happen: a merging edge is
     * visible, so both its ends are queued) is traced after all. */
    for (uint32_t v = 0; v < m->num_primary_verts; ++v)
        if (m->verts[v].state == VT_QUEUED && find_root(parent, v) != v) {
            m->verts[v].state = VT_UNSAMPLED;
            vt_sample_queue(run, v);
        }
    vt_sample_flush(run);
    free(parent);
}

static void refine_all(refine_ctx *ctx)
{
    vt_run *run = ctx->run;
    vt_mesh *m = run->mesh;
    double t0 = now_ms(), busy0 = vt_sample_busy_ms(run);

    bool merge_failed = false;
    uint32_t *merged = merge_begin(run, &merge_failed);
    run->failed |= merge_failed;
    /* Fig. 3.12: the edges of every visible primary face; their vertices
     * are ray traced (stage 0, the initial sample pattern of Sec. 3.2). */
    for (uint32_t e = 0; e < m->num_primary_edges && !run->failed; ++e) {
        const vt_edge *ed = &m->edges[e];
        if (!primary_edge_seeds(run, ed))
            continue;
        vt_sample_queue(run, ed->v[0]);
        vt_sample_queue(run, ed->v[1]);
        consider_edge(ctx, e, true);
    }
    end_interval(ctx, t0, busy0);
    vt_sample_flush(run);
    if (merged)
        merge_finish(run, merged);

    double tu = now_ms();
    if (run->update && !run->failed && !vt_update(run, 0, false))
        run->stopped = true;
    ctx->update_ms += now_ms() - tu;
    run->stats.time_preview_ms = now_ms() - run->t_start_ms;

    float first = vt_heap_top(run->heap);
    uint16_t stage = 0;
    while (!run->failed && !run->stopped && run->heap->count && budget_left(run)) {
        if (stage == UINT16_MAX)
            break;
        ++stage;
        float top = vt_heap_top(run->heap);
        double ts = now_ms(), busy = vt_sample_busy_ms(run);
        run_stage(ctx, stage);
        end_interval(ctx, ts, busy);
        vt_sample_flush(run);
        run->stats.stages = stage;
        if (!rl_renderer_progress(run->renderer, progress_of(top, first, run->set->min_edge))) {
            run->stopped = run->cancelled = true;
            break;
        }
        tu = now_ms();
        if (run->update && run->set->progressive != VT_PROG_NONE &&
            stage % (uint16_t)run->set->update_every == 0 && !vt_update(run, stage, false))
            run->stopped = true;
        ctx->update_ms += now_ms() - tu;
    }
    vt_sample_flush(run);
}

rl_status vt_refine(vt_run *run)
{
    refine_ctx ctx;
    memset(&ctx, 0, sizeof ctx);
    ctx.run = run;
    /* A whole frame drawn once at its end reads no split face again: the
     * first child takes a split face's slot (about half of the faces of a
     * refined mesh). The progressive overdraw redraws the faces of the last
     * stages, split or not (vt_draw), the shaft test keeps a verdict per
     * face slot, and a package's result is written in index order
     * (vt_part_write): those keep every face. */
    run->mesh->drop_parents = !run->seed && run->set->shaft_cull == VT_SHAFT_OFF &&
                              !(run->update && run->set->progressive == VT_PROG_OVERDRAW);
    double t0 = now_ms();
    if (run->set->shaft_cull != VT_SHAFT_OFF) {
        rl_status st = vt_shaft_index_build(&ctx.shafts, run->data);
        if (st != RL_OK)
            return st;
    }
#pragma omp parallel num_threads(run->set->threads)
#pragma omp single
    refine_all(&ctx);
    double wall = now_ms() - t0;
    vt_array_free(ctx.batch, (size_t)ctx.batch_cap * sizeof *ctx.batch);
    free(ctx.forced);
    free(ctx.face_shaft);
    vt_shaft_index_free(&ctx.shafts);
    run->stats.time_refine_ms = ctx.refine_ms;
    run->stats.time_sampling_ms = wall - ctx.refine_ms - ctx.update_ms;
    if (run->failed)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: out of memory while refining (%u vertices)",
                        run->mesh->num_verts);
    return RL_OK;
}
