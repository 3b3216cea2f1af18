/* chcpp.c: renderer "chcpp", CHC++ occlusion culling (Mattausch, Bittner &
 * Wimmer 2008, "CHC++: Coherent Hierarchical Culling Revisited"), the
 * conservative reference of Jähn 2015 (Sec. 2.1.2, 7.3-7.5), over the
 * loose octree of rl_octree.h and the rasterizer's occlusion queries.
 *
 * Per frame the octree is traversed front to back (a priority queue on the
 * eye-box distance). Temporal coherence, as in CHC/CHC++:
 *  - a node visible in the previous frame is traversed at once: its
 *    objects are drawn, its children queued. A node holding objects is
 *    queried only every n_av frames (option assumed_visible), at a random
 *    offset so that the queries of many nodes do not fall due together;
 *    otherwise it is assumed visible;
 *  - a node that was invisible (or not reached) in the previous frame goes
 *    to the I-queue; when `batch` nodes have gathered, or the traversal
 *    queue runs dry, they are queried as multi-queries: consecutive nodes
 *    are grouped while the value |M| / C(M) grows, with the expected cost
 *    C(M) = 1 + (1 - prod p_k) |M| (a failed multi-query costs one query
 *    per node again) and the probability that a node invisible for i
 *    frames stays invisible p(i) = 0.99 - 0.7 exp(-i) (CHC++, Sec. 4.2).
 *    A node found visible is drawn and its children queued;
 *  - visibility is pulled up: a visible node makes all its ancestors
 *    visible; inner nodes are reset before their subtree reports.
 * Tighter bounds (CHC++, Sec. 4.4): a node is queried with the tight box
 * of its subtree's objects (rl_octree_node.bounds), or with the objects'
 * own boxes where they are few (<= 8) and their surface is smaller; the
 * classic loose box with tight = false. Query boxes are grown by a
 * relative 1e-3 and nodes whose box reaches the near plane are never
 * queried, so culling stays conservative: the image equals "raster"'s
 * wherever no two surfaces fight for the same depth (coplanar overlaps are
 * resolved by drawing order, here front to back, there by object index).
 *
 * Latency (CHC++'s main loop, Sec. 3-4.1): queries are issued without
 * waiting (rl_drawer_query_issue). Those of the I-queue go into the query
 * queue: while there is something to draw, the answers at its front are
 * taken only when they are there (a non-blocking poll), and otherwise the
 * next node of the distance queue is drawn; when the distance queue and
 * the I-queue are empty, the traversal needs an answer, and while it is
 * not there a query of the V-queue is issued to fill the wait; only with
 * the V-queue empty does it wait. The V-queue (option vqueue) gathers the
 * queries of previously visible nodes, which are drawn at once without
 * their answers (those decide only the next frame's classification); what
 * is left of it is issued at the frame's end. Their answers are taken as
 * they come; those not there at the frame's end are, with latency=frame
 * (the default), kept open into the next frame (rl_drawer_query_keep) and
 * taken there, the node staying visible meanwhile, or, with latency=wait,
 * waited for. An answer a frame late for a node the next frame has not
 * reached yet says "invisible": the node then goes to the I-queue, so its
 * objects are queried in that frame before they are drawn. With vqueue
 * false such a query is issued just before its node's objects are drawn,
 * as in CHC. A failed multi-query's nodes are queried again one by one,
 * as CHC++ does. rl_culling_stats counts the answers found ready, waited
 * for and carried, and the V-queue's queries that filled a wait.
 *
 * Conservative in any order: every I-queue query is answered within its
 * frame, against the depth buffer as it is at its issue (a subset of the
 * frame's final occluders), and only those answers keep objects from
 * being drawn; a previously visible node is drawn whatever its answer,
 * early or late. With the software drawer (the default, drawer=software)
 * every answer is there at its issue, so the first frame (all queries in
 * the I-queue) is exactly the synchronous CHC order: each query is
 * resolved before the next is issued; the V-queue's queries, never needed
 * to fill a wait, are all issued at the frame's end, against its final
 * depth buffer, and none is carried. With drawer=gl the queries are GL
 * query objects (GL_SAMPLES_PASSED) and the answers come when the GPU has
 * them; query_delay simulates such latency on any drawer (the first n
 * polls of each query find no answer, rl_drawer_desc.query_delay).
 *
 * Answers of previously invisible nodes are always read within their
 * frame: they decide what it draws, and drawing such a node before its
 * answer could only add objects, never culling more. Deviation: CHC++
 * queries previously visible leaves; here every previously visible node
 * holding objects is queried (the loose octree keeps objects in inner
 * nodes too). Batching of the I-queue keeps its purpose: later queries see
 * more occluders, and multi-queries save query fill.
 *
 * Options: the raster renderer's (shading, cull, ambient, background,
 * threads), drawer (software | gl) and device (for gl), plus
 * max_depth 5 (Jähn 2015, Sec. 7.3), looseness 2.0, batch 50,
 * assumed_visible 10, multiquery true, tight true, seed 1, vqueue true,
 * latency frame, query_delay 0. The defaults for batch and assumed_visible
 * are ours, in the range the CHC++ paper explores. latency=frame is the
 * default because an answer it carries changes no pixel of its frame (the
 * node is drawn either way) and waiting for it would stall the GPU at
 * every frame's end; in software it carries nothing. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/culling.h"
#include "render/overlay.h"
#include "rl/rl_drawer.h"
#include "render/renderer.h"
#include "rl/rl_rng.h"
#include "rl/rl_timer.h"

/* Query boxes grow by this share of their longest side, so that rounding
 * never lets the bounded geometry poke through their faces. */
#define QUERY_MARGIN 1e-3f

static const char *const overlay_choices[] = { "none", "nodes", NULL };
static const char *const latency_choices[] = { "frame", "wait", NULL };
enum { LATENCY_FRAME, LATENCY_WAIT };

static const rl_option_info chcpp_options[] = {
    RL_CULL_RASTER_OPTIONS,
    { "max_depth", RL_OPT_INT, "5", "maximum depth of the loose octree (0: all objects in the root)", 0,
      RL_OCTREE_MAX_DEPTH, NULL },
    { "looseness", RL_OPT_FLOAT, "2", "loose octree enlargement factor k", 1, 8, NULL },
    { "batch", RL_OPT_INT, "50", "previously invisible nodes gathered before they are queried", 1, 100000,
      NULL },
    { "assumed_visible", RL_OPT_INT, "10", "a visible node is queried again about every n frames", 1, 100000,
      NULL },
    { "multiquery", RL_OPT_BOOL, "true", "query batched invisible nodes together (CHC++ Sec. 4.2)", 0, 0,
      NULL },
    { "tight", RL_OPT_BOOL, "true", "query the tight bounds of a node's objects, not its loose box", 0, 0,
      NULL },
    { "seed", RL_OPT_INT, "1", "seed of the random query offsets", 0, 4294967295.0, NULL },
    { "vqueue", RL_OPT_BOOL, "true",
      "gather previously visible nodes' queries in the V-queue, issued while an answer is awaited and at the "
      "frame's end (CHC++ Sec. 4.1); false: each just before its node is drawn (CHC)", 0, 0, NULL },
    { "latency", RL_OPT_ENUM, "frame",
      "previously visible nodes' answers not there at the frame's end: frame (read in the next frame, the "
      "node staying visible) | wait (waited for)", 0, 0, latency_choices },
    { "query_delay", RL_OPT_INT, "0",
      "simulated query latency: the first n polls of each query find no answer (0: as the drawer has it)", 0,
      1000000, NULL },
    { "overlay", RL_OPT_ENUM, "none",
      "draw the octree nodes of the frame over the image: visible green, occluded red (nodes)", 0, 0,
      overlay_choices },
};

typedef struct node_state {
    uint64_t last_visited;        /* frame; 0 = never */
    uint64_t next_query;          /* frame when a visible node is queried again */
    uint32_t invisible_frames;    /* consecutive frames found invisible */
    uint8_t visible;
    uint8_t in_flight;            /* its own query (as previously visible) waits in the V-queue
                                   * or for its answer, maybe since the last frame */
} node_state;

typedef struct heap_item {
    float dist;
    uint32_t node;
} heap_item;

/* An issued query of a group of the I-queue whose answer is not read yet. */
typedef struct pending {
    uint32_t handle;              /* rl_drawer_query_issue's */
    uint32_t first, count;        /* its nodes: qnodes[first .. first + count) */
} pending;

/* A previously visible node's own query, issued: its answer holds up
 * nothing (the node is drawn) and may be read a frame later. */
typedef struct vpending {
    uint32_t handle;
    uint32_t node;
} vpending;

typedef struct chcpp_state {
    rl_culling_head head;         /* first: rl_culling_get_stats */
    rl_octree_cache oc;
    node_state *ns;
    uint32_t num_ns;
    uint64_t frame;
    heap_item *heap;
    uint32_t heap_n, heap_cap;
    uint32_t *iqueue;
    uint32_t iq_n, iq_cap;
    rl_box_query query;
    /* The query queue of CHC++, in issue order (head .. tail), and the
     * nodes of its queries; both emptied every frame. */
    pending *queue;
    uint32_t q_head, q_tail, q_cap;
    uint32_t *qnodes;
    uint32_t qn_n, qn_cap;
    /* CHC++'s V-queue: previously visible nodes whose queries wait to be
     * issued (emptied every frame); and the issued ones whose answers are
     * not read yet, in issue order, carried into the next frame with
     * latency=frame (kept open with rl_drawer_query_keep). */
    uint32_t *vqueue;
    uint32_t vq_head, vq_n, vq_cap;
    vpending *vpend;
    uint32_t vp_head, vp_tail, vp_cap;
} chcpp_state;

/* One frame's working set. */
typedef struct frame_ctx {
    chcpp_state *s;
    const rl_scene_data *d;
    const rl_octree_node *nodes;
    const uint32_t *objects;
    rl_cull_frame cf;
    bool tight, multiquery, vqueue, wait;
    uint32_t batch, n_av;
    uint64_t seed;
    int draining;                 /* nesting of drain() */
} frame_ctx;

static void chcpp_release(void *state)
{
    chcpp_state *s = state;
    rl_octree_cache_release(&s->oc);
    rl_drawer_release(s->head.drawer);
    rl_box_query_free(&s->query);
    free(s->ns);
    free(s->heap);
    free(s->iqueue);
    free(s->queue);
    free(s->qnodes);
    free(s->vqueue);
    free(s->vpend);
}

/* Forgets the queries carried from the last frame (their nodes no longer
 * wait for them): the drawer drops them at the end of the frame that does
 * not keep them again. */
static void forget_carried(chcpp_state *s)
{
    for (uint32_t i = s->vp_head; i < s->vp_tail; ++i)
        if (s->vpend[i].node < s->num_ns)
            s->ns[s->vpend[i].node].in_flight = 0;
    s->vp_head = s->vp_tail = 0;
}

static void chcpp_reset(void *state)
{
    chcpp_state *s = state;
    if (!s)
        return;
    forget_carried(s);
    if (s->ns)
        memset(s->ns, 0, (size_t)s->num_ns * sizeof *s->ns);
}

/* --- the traversal queue: a binary min-heap on distance, ties by node --- */

static bool heap_less(heap_item a, heap_item b)
{
    return a.dist < b.dist || (a.dist == b.dist && a.node < b.node);
}

static rl_status heap_push(chcpp_state *s, heap_item it)
{
    if (!rl_reserve_u32((void **)&s->heap, &s->heap_cap, (uint64_t)s->heap_n + 1, sizeof *s->heap, 256))
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t i = s->heap_n++;
    while (i > 0 && heap_less(it, s->heap[(i - 1) / 2])) {
        s->heap[i] = s->heap[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    s->heap[i] = it;
    return RL_OK;
}

static heap_item heap_pop(chcpp_state *s)
{
    heap_item top = s->heap[0], last = s->heap[--s->heap_n];
    uint32_t i = 0, n = s->heap_n;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= n)
            break;
        if (c + 1 < n && heap_less(s->heap[c + 1], s->heap[c]))
            ++c;
        if (!heap_less(s->heap[c], last))
            break;
        s->heap[i] = s->heap[c];
        i = c;
    }
    if (n > 0)
        s->heap[i] = last;
    return top;
}

/* --- CHC++ --- */

/* CHC++, Sec. 4.2: probability that a node invisible for i frames stays so. */
static double p_stay_invisible(uint32_t i)
{
    return 0.99 - 0.7 * exp(-(double)i);
}

static void pull_up(frame_ctx *f, uint32_t n)
{
    while (n != RL_NONE && !f->s->ns[n].visible) {
        f->s->ns[n].visible = 1;
        n = f->nodes[n].parent;
    }
}

/* The next frame at which a visible node is queried again: n_av frames on,
 * minus a random part so that nodes spread over the frames. */
static void schedule_query(frame_ctx *f, uint32_t n)
{
    uint64_t r = rl_hash64(f->seed ^ ((uint64_t)n << 32) ^ f->s->frame);
    f->s->ns[n].next_query = f->s->frame + 1 + r % f->n_av;
}

/* Draws the node's own objects and queues its children. */
static rl_status traverse(frame_ctx *f, uint32_t n)
{
    const rl_octree_node *node = &f->nodes[n];
    const uint32_t *objects = f->objects + node->first_object;
    rl_status st = rl_drawer_draw(f->cf.drawer, objects, node->num_objects, &f->cf.counters);
    for (uint32_t k = 0; k < node->num_objects && st == RL_OK; ++k) {
        f->s->head.stats.objects_drawn++;
        f->s->head.stats.triangles_drawn += f->d->objects[objects[k]].num_triangles;
    }
    for (uint32_t c = 0; c < node->num_children && st == RL_OK; ++c) {
        uint32_t ch = node->first_child + c;
        st = heap_push(f->s, (heap_item){ rl_cull_box_distance(f->cf.view.eye, f->nodes[ch].bounds), ch });
    }
    return st;
}

/* Collects the boxes of the objects below n into the query while there
 * are at most `room` of them; false when there are more. */
static bool object_boxes(frame_ctx *f, uint32_t n, uint32_t *room, double *area)
{
    const rl_octree_node *node = &f->nodes[n];
    if (node->num_objects > *room)
        return false;
    *room -= node->num_objects;
    for (uint32_t k = 0; k < node->num_objects; ++k)
        *area += rl_aabb_area(f->d->objects[f->objects[node->first_object + k]].bounds);
    for (uint32_t c = 0; c < node->num_children; ++c)
        if (!object_boxes(f, node->first_child + c, room, area))
            return false;
    return true;
}

static rl_status add_object_boxes(frame_ctx *f, uint32_t n)
{
    const rl_octree_node *node = &f->nodes[n];
    rl_status st = RL_OK;
    for (uint32_t k = 0; k < node->num_objects && st == RL_OK; ++k)
        st = rl_box_query_add(&f->s->query, f->d->objects[f->objects[node->first_object + k]].bounds, QUERY_MARGIN);
    for (uint32_t c = 0; c < node->num_children && st == RL_OK; ++c)
        st = add_object_boxes(f, node->first_child + c);
    return st;
}

/* Adds node n's query geometry (tighter bounds, CHC++ Sec. 4.4). */
static rl_status add_node_boxes(frame_ctx *f, uint32_t n)
{
    const rl_octree_node *node = &f->nodes[n];
    if (!f->tight)
        return rl_box_query_add(&f->s->query, node->loose, QUERY_MARGIN);
    uint32_t room = 8;
    double area = 0.0;
    if (node->subtree_objects > 1 && object_boxes(f, n, &room, &area) && area < rl_aabb_area(node->bounds))
        return add_object_boxes(f, n);
    return rl_box_query_add(&f->s->query, node->bounds, QUERY_MARGIN);
}

static rl_status drain(frame_ctx *f, bool block);

/* Issues one occlusion query over the nodes list[0..count) into *handle. */
static rl_status issue_query(frame_ctx *f, const uint32_t *list, uint32_t count, uint32_t *handle)
{
    chcpp_state *s = f->s;
    rl_box_query_reset(&s->query);
    rl_status st = RL_OK;
    for (uint32_t i = 0; i < count && st == RL_OK; ++i)
        st = add_node_boxes(f, list[i]);
    if (st == RL_OK)
        st = rl_box_query_issue(&s->query, f->cf.drawer, handle, NULL);
    if (st != RL_OK)
        return st;
    s->head.stats.queries++;
    s->head.stats.query_boxes += s->query.boxes;
    if (count > 1)
        s->head.stats.multiqueries++;
    return RL_OK;
}

/* Issues the query of a group of the I-queue and queues it; then takes
 * the answers that are there (drain), so that with answers at the issue
 * (the software drawer) every node is resolved right after its query,
 * before the next is issued, as the synchronous CHC. */
static rl_status issue_nodes(frame_ctx *f, const uint32_t *list, uint32_t count)
{
    chcpp_state *s = f->s;
    if (!rl_reserve_u32((void **)&s->qnodes, &s->qn_cap, (uint64_t)s->qn_n + count, sizeof *s->qnodes, 256) ||
        !rl_reserve_u32((void **)&s->queue, &s->q_cap, (uint64_t)s->q_tail + 1, sizeof *s->queue, 64))
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t handle = 0;
    rl_status st = issue_query(f, list, count, &handle);
    if (st != RL_OK)
        return st;
    /* list never points into qnodes, which the reserve may have moved:
     * take() hands a failed multi-query's nodes one by one as copies. */
    memcpy(s->qnodes + s->qn_n, list, (size_t)count * sizeof *list);
    s->queue[s->q_tail++] = (pending){ .handle = handle, .first = s->qn_n, .count = count };
    s->qn_n += count;
    return drain(f, false);
}

/* Issues a previously visible node's own query; its answer is awaited by
 * nothing but the node's classification. */
static rl_status issue_visible(frame_ctx *f, uint32_t n)
{
    chcpp_state *s = f->s;
    if (!rl_reserve_u32((void **)&s->vpend, &s->vp_cap, (uint64_t)s->vp_tail + 1, sizeof *s->vpend, 64))
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t handle = 0;
    rl_status st = issue_query(f, &n, 1, &handle);
    if (st == RL_OK)
        s->vpend[s->vp_tail++] = (vpending){ .handle = handle, .node = n };
    return st;
}

/* A previously invisible node found visible (or invisible) by its query. */
static rl_status resolve(frame_ctx *f, uint32_t n, bool visible)
{
    node_state *ns = &f->s->ns[n];
    if (!visible) {
        ns->visible = 0;
        ns->invisible_frames++;
        f->s->head.stats.nodes_occluded++;
        return RL_OK;
    }
    ns->invisible_frames = 0;
    pull_up(f, n);
    schedule_query(f, n);
    return traverse(f, n);
}

/* What an answer means for the nodes of an I-queue query. */
static rl_status take(frame_ctx *f, pending p, bool visible)
{
    chcpp_state *s = f->s;
    rl_status st = RL_OK;
    if (p.count > 1 && visible) {
        /* A failed multi-query: each node is asked again on its own. */
        s->head.stats.multiqueries_failed++;
        for (uint32_t k = 0; k < p.count && st == RL_OK; ++k) {
            uint32_t n = s->qnodes[p.first + k];
            st = issue_nodes(f, &n, 1);
        }
        return st;
    }
    for (uint32_t k = 0; k < p.count && st == RL_OK; ++k)
        st = resolve(f, s->qnodes[p.first + k], visible);
    return st;
}

/* What a previously visible node's answer means: the node was drawn
 * already; the answer decides only whether it stays in the coherent set
 * (its subtree may pull it up anyway). One a frame late for a node this
 * frame has not reached yet sends it to the I-queue when reached, where
 * its objects are queried before they are drawn. */
static void take_visible(frame_ctx *f, vpending p, bool visible)
{
    chcpp_state *s = f->s;
    node_state *ns = &s->ns[p.node];
    ns->in_flight = 0;
    if (visible) {
        pull_up(f, p.node);
        return;
    }
    ns->invisible_frames++;
    if (ns->last_visited != s->frame)
        ns->visible = 0;
}

/* Reads an answer (polled ready or waited for) and counts it. */
static rl_status read_answer(frame_ctx *f, uint32_t handle, bool ready, bool *visible)
{
    if (ready)
        f->s->head.stats.queries_ready++;
    else
        f->s->head.stats.queries_waited++;
    uint64_t pixels = 0;
    rl_status st = rl_drawer_query_result(f->cf.drawer, handle, &pixels);
    *visible = pixels > 0;
    return st;
}

/* Takes the previously visible nodes' answers at the front of their queue
 * while they are there; with all, waits for every one. */
static rl_status drain_visible(frame_ctx *f, bool all)
{
    chcpp_state *s = f->s;
    rl_status st = RL_OK;
    while (st == RL_OK && s->vp_head < s->vp_tail) {
        vpending p = s->vpend[s->vp_head];
        bool ready = false, visible = false;
        st = rl_drawer_query_poll(f->cf.drawer, p.handle, &ready);
        if (st != RL_OK || (!ready && !all))
            break;
        s->vp_head++;
        st = read_answer(f, p.handle, ready, &visible);
        if (st == RL_OK)
            take_visible(f, p, visible);
    }
    return st;
}

/* Takes the answers at the front of the query queue while they are there
 * (CHC++: finished queries first), then those of previously visible nodes;
 * with block, waits for the first one of the query queue, for when nothing
 * else is left to do. A nested call (an answer's nodes issue queries) goes
 * one level deep: deeper ones leave their answers to the loops above them. */
static rl_status drain(frame_ctx *f, bool block)
{
    chcpp_state *s = f->s;
    if (f->draining >= 2)
        return RL_OK;
    f->draining++;
    rl_status st = RL_OK;
    while (st == RL_OK && s->q_head < s->q_tail) {
        pending p = s->queue[s->q_head];
        bool ready = false, visible = false;
        st = rl_drawer_query_poll(f->cf.drawer, p.handle, &ready);
        if (st != RL_OK || (!ready && !block))
            break;
        block = false;
        s->q_head++;
        st = read_answer(f, p.handle, ready, &visible);
        if (st == RL_OK)
            st = take(f, p, visible);
    }
    if (st == RL_OK)
        st = drain_visible(f, false);
    f->draining--;
    return st;
}

/* Nothing to draw or to query until an answer of the query queue comes:
 * CHC++ fills the wait with a query of the V-queue while the answer is not
 * there (Sec. 4.1), and waits only when the V-queue is empty. */
static rl_status await_answer(frame_ctx *f)
{
    chcpp_state *s = f->s;
    if (s->vq_head == s->vq_n)
        return drain(f, true);
    const uint32_t head = s->q_head;
    rl_status st = drain(f, false);
    if (st != RL_OK || s->q_head != head)
        return st;
    s->head.stats.queries_filled++;
    return issue_visible(f, s->vqueue[s->vq_head++]);
}

/* Queries the I-queue: multi-queries grouped by the CHC++ cost model (a
 * failed one node by node, in take). */
static rl_status flush_iqueue(frame_ctx *f)
{
    chcpp_state *s = f->s;
    rl_status st = RL_OK;
    uint32_t i = 0;
    while (i < s->iq_n && st == RL_OK) {
        uint32_t m = 1;
        if (f->multiquery) {
            double p_all = p_stay_invisible(s->ns[s->iqueue[i]].invisible_frames);
            double best = 1.0 / (1.0 + (1.0 - p_all));
            while (i + m < s->iq_n) {
                double p = p_all * p_stay_invisible(s->ns[s->iqueue[i + m]].invisible_frames);
                double value = (double)(m + 1) / (1.0 + (1.0 - p) * (double)(m + 1));
                if (!(value > best))
                    break;
                best = value;
                p_all = p;
                ++m;
            }
        }
        st = issue_nodes(f, s->iqueue + i, m);
        i += m;
    }
    s->iq_n = 0;
    return st;
}

static rl_status iqueue_push(chcpp_state *s, uint32_t n)
{
    if (!rl_reserve_u32((void **)&s->iqueue, &s->iq_cap, (uint64_t)s->iq_n + 1, sizeof *s->iqueue, 256))
        return RL_ERR_OUT_OF_MEMORY;
    s->iqueue[s->iq_n++] = n;
    return RL_OK;
}

static rl_status vqueue_push(chcpp_state *s, uint32_t n)
{
    if (!rl_reserve_u32((void **)&s->vqueue, &s->vq_cap, (uint64_t)s->vq_n + 1, sizeof *s->vqueue, 256))
        return RL_ERR_OUT_OF_MEMORY;
    s->vqueue[s->vq_n++] = n;
    return RL_OK;
}

/* The frame's end: the rest of the V-queue is issued (CHC++); with
 * latency=wait every answer is read, with latency=frame those there now
 * and the rest kept for the next frame, their nodes staying visible
 * meanwhile (they are drawn this frame, whatever the answer). */
static rl_status end_visible(frame_ctx *f)
{
    chcpp_state *s = f->s;
    rl_status st = RL_OK;
    while (st == RL_OK && s->vq_head < s->vq_n)
        st = issue_visible(f, s->vqueue[s->vq_head++]);
    if (st == RL_OK)
        st = drain_visible(f, f->wait);
    for (uint32_t i = s->vp_head; i < s->vp_tail && st == RL_OK; ++i) {
        st = rl_drawer_query_keep(f->cf.drawer, s->vpend[i].handle);
        s->head.stats.queries_carried++;
        if (s->ns[s->vpend[i].node].last_visited == s->frame)
            pull_up(f, s->vpend[i].node);
    }
    /* The carried ones first in the queue, for the next frame. */
    if (s->vp_head > 0) {
        memmove(s->vpend, s->vpend + s->vp_head, (size_t)(s->vp_tail - s->vp_head) * sizeof *s->vpend);
        s->vp_tail -= s->vp_head;
        s->vp_head = 0;
    }
    return st;
}

/* The CHC++ main loop over one frame. */
static rl_status chcpp_frame(frame_ctx *f)
{
    chcpp_state *s = f->s;
    rl_culling_stats *stats = &s->head.stats;
    s->q_head = s->q_tail = s->qn_n = 0;
    s->vq_head = s->vq_n = 0;
    stats->queries_carried_in = s->vp_tail - s->vp_head;
    rl_status st = heap_push(s, (heap_item){ rl_cull_box_distance(f->cf.view.eye, f->nodes[0].bounds), 0 });
    while (st == RL_OK && (s->heap_n > 0 || s->iq_n > 0 || s->q_head < s->q_tail)) {
        if (s->heap_n == 0) {
            /* Nothing to draw: query what waits, else wait for an answer
             * (either may queue the children of visible nodes). */
            st = s->iq_n > 0 ? flush_iqueue(f) : await_answer(f);
            continue;
        }
        st = drain(f, false);
        if (st != RL_OK || s->heap_n == 0)
            continue;
        uint32_t n = heap_pop(s).node;
        const rl_octree_node *node = &f->nodes[n];
        node_state *ns = &s->ns[n];
        stats->nodes_visited++;
        bool was_visible = ns->visible && ns->last_visited + 1 == s->frame;
        ns->last_visited = s->frame;
        if (!rl_cull_box_in_frustum(&f->cf.view, node->bounds)) {
            ns->visible = 0;
            stats->nodes_frustum_culled++;
            continue;
        }
        /* The grown box a query draws: it holds the node's object boxes
         * grown likewise (each no larger than the node's bounds). */
        if (rl_cull_box_near_eye(&f->cf.view,
                                 rl_box_query_bounds(f->tight ? node->bounds : node->loose, QUERY_MARGIN))) {
            /* No query can be trusted where the near plane cuts the box, or
             * where the eye is inside it (only back faces face the eye). */
            ns->visible = 0;
            if (node->num_objects)
                pull_up(f, n);
            st = traverse(f, n);
            continue;
        }
        if (!was_visible) {
            st = iqueue_push(s, n);
            if (st == RL_OK && s->iq_n >= f->batch)
                st = flush_iqueue(f);
            continue;
        }
        /* Previously visible: reset, then let the node's own query (when
         * due, or still in flight from the last frame) or its subtree pull
         * the visibility up again. */
        ns->visible = 0;
        if (node->num_objects && !ns->in_flight) {
            if (s->frame >= ns->next_query) {
                /* Drawn without waiting for the answer. In the V-queue the
                 * query waits for a moment when the GPU would idle; without
                 * it, it is issued before the node's objects are drawn, as
                 * in CHC (the grown box stays in front of them anyway). */
                ns->in_flight = 1;
                if (f->vqueue) {
                    st = vqueue_push(s, n);
                } else {
                    st = issue_visible(f, n);
                    if (st == RL_OK)
                        st = drain(f, false);
                }
                schedule_query(f, n);
            } else {
                pull_up(f, n);
            }
        }
        if (st == RL_OK)
            st = traverse(f, n);
    }
    if (st == RL_OK)
        st = end_visible(f);
    if (st != RL_OK) {
        /* The drawer drops what this frame does not keep. */
        for (uint32_t i = 0; i < s->vq_n; ++i)
            s->ns[s->vqueue[i]].in_flight = 0;
        forget_carried(s);
    }
    s->heap_n = 0;
    s->iq_n = 0;
    s->vq_head = s->vq_n = 0;
    s->q_head = s->q_tail = s->qn_n = 0;
    return st;
}

/* overlay=nodes: the frame's outcome per octree node. Green: a visible
 * node whose own objects were drawn. Red: a node in the frustum found
 * occluded whose subtree the traversal did not enter, the boundary where
 * the queries stopped it (an occluded node inside it is not drawn again).
 * Drawn after the frame's end, when a GL drawer has read the image back. */
static void draw_nodes(const frame_ctx *f, rl_image *image)
{
    const chcpp_state *s = f->s;
    for (uint32_t n = 0; n < s->num_ns; ++n) {
        const rl_octree_node *node = &f->nodes[n];
        const node_state *ns = &s->ns[n];
        if (ns->last_visited != s->frame || !rl_cull_box_in_frustum(&f->cf.view, node->bounds))
            continue;
        bool entered = false;
        for (uint32_t c = 0; c < node->num_children && !entered; ++c)
            entered = s->ns[node->first_child + c].last_visited == s->frame;
        if (ns->visible && node->num_objects > 0)
            rl_overlay_box(image, &f->cf.view.view_proj, f->cf.view.z_near, node->bounds,
                           rl_v4(0.2f, 1.0f, 0.2f, 1.0f));
        else if (!ns->visible && !entered)
            rl_overlay_box(image, &f->cf.view.view_proj, f->cf.view.z_near, node->bounds,
                           rl_v4(1.0f, 0.2f, 0.2f, 1.0f));
    }
}

static rl_status chcpp_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                              rl_image *image, rl_render_stats *stats)
{
    chcpp_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    memset(&s->head.stats, 0, sizeof s->head.stats);
    s->head.have_frame = false;

    rl_timer t0;
    rl_timer_start(&t0);
    int depth = (int)rl_renderer_opt_int(r, "max_depth");
    rl_octree_desc od = { .max_depth = depth ? depth : RL_OCTREE_DEPTH_ZERO,
                          .looseness = (float)rl_renderer_opt_float(r, "looseness") };
    bool rebuilt = false;
    rl_status st = rl_octree_cache_get(&s->oc, scene, &od, &rebuilt);
    if (st != RL_OK)
        return st;
    uint32_t nn;
    const rl_octree_node *nodes = rl_octree_nodes(s->oc.tree, &nn);
    if (rebuilt || s->num_ns != nn) {
        free(s->ns);
        s->ns = rl_calloc(nn, sizeof *s->ns);
        s->num_ns = s->ns ? nn : 0;
        s->vp_head = s->vp_tail = 0;   /* their nodes are gone */
        if (!s->ns)
            return RL_ERR_OUT_OF_MEMORY;
        s->head.stats.preprocess_ms = rl_timer_ms(&t0);
    }
    s->head.stats.octree_nodes = nn;
    s->head.stats.octree_depth = rl_octree_depth(s->oc.tree);

    frame_ctx f;
    memset(&f, 0, sizeof f);
    f.s = s;
    f.d = d;
    f.nodes = nodes;
    f.objects = rl_octree_objects(s->oc.tree, NULL);
    f.tight = rl_renderer_opt_bool(r, "tight");
    f.multiquery = rl_renderer_opt_bool(r, "multiquery");
    f.batch = (uint32_t)rl_renderer_opt_int(r, "batch");
    f.n_av = (uint32_t)rl_renderer_opt_int(r, "assumed_visible");
    f.seed = (uint64_t)rl_renderer_opt_int(r, "seed");
    f.vqueue = rl_renderer_opt_bool(r, "vqueue");
    f.wait = rl_renderer_opt_enum(r, "latency") == LATENCY_WAIT;
    s->head.query_delay = (uint32_t)rl_renderer_opt_int(r, "query_delay");
    st = rl_cull_frame_begin(r, scene, &s->head, cam, image, true, &f.cf);
    if (st != RL_OK)
        return st;
    if (f.cf.new_drawer)
        forget_carried(s);   /* they went with the old drawer */
    s->frame++;
    st = rl_cull_frame_end(&f.cf, chcpp_frame(&f), image, stats);
    if (st != RL_OK)
        return st;
    if (rl_renderer_opt_enum(r, "overlay") == 1)
        draw_nodes(&f, image);
    stats->occlusion_queries = s->head.stats.queries;
    stats->prep_ms = s->head.stats.preprocess_ms;
    s->head.have_frame = true;
    return RL_OK;
}

const rl_renderer_class rl_chcpp_renderer_class = {
    .info = { .name = "chcpp",
              .description = "CHC++ occlusion culling over a loose octree; the same image as raster",
              .reference = "Mattausch, Bittner & Wimmer 2008; Jähn 2015, Sec. 2.1.2, 7.3",
              .frame_bytes_per_pixel = RL_CULL_FRAME_BYTES_PER_PIXEL },
    .options = chcpp_options,
    .num_options = sizeof chcpp_options / sizeof chcpp_options[0],
    .state_size = sizeof(chcpp_state),
    .render = chcpp_render,
    .release = chcpp_release,
    .check = NULL,
    .reset = chcpp_reset,
    .available = rl_cull_available,
};
