/* dist_vt.c: distributed Vertex Tracing (Ullmann 2003, Sec. 4.3-4.5) on
 * rl_dist: rl_dist_render's backend for the renderer "vt", which has no
 * image regions (its ID pre-pass sees the whole frame).
 *
 * The master runs the ID pre-pass (rl_vt_prepare) and cuts the visible
 * primary faces, in their mesh order (an object's faces lie together, so
 * a package is a patch of surface with few borders), into packages. Every
 * rank refines packages (rl_vt_refine_faces, OpenMP threads inside, Sec.
 * 4.5) into parts, the master draws the frame from all parts
 * (rl_vt_draw_parts), in package order whoever refined them.
 *
 * Load balancing (option balance of vt, Sec. 4.3.3):
 *   queue       equal packages of `package` faces on demand (Fig. 4.8):
 *               PREFETCH at every worker, the next to whichever answers,
 *               the master refining packages between messages;
 *   precompute  one package per rank sized by its speed v_i (cost per
 *               busy millisecond): the share v_i / sum_j v_j of the faces'
 *               summed cost (the thesis' equation), a face costing 1
 *               (cost=faces) or its estimate b_f (cost=estimate,
 *               rl_vt_estimate_costs on the master first; the cut is
 *               rl_dist_cut_by_cost). The speeds are the last frame's; a
 *               first frame measures them with a calibration package of
 *               N / (8 ranks) faces per rank and splits the rest once all
 *               are back.
 * A lost worker's packages (silent past RL_DIST_TIMEOUT) go to whoever is
 * free, as the tiles' bands do.
 *
 * Camera ID (Sec. 4.3.2): every rank counts its distributed VT frames, and
 * every task and result carries the count of its frame; a result of an
 * older camera (a slow worker answering late) is dropped, counted in
 * rl_dist_stats.dropped. A worker refuses a task of a camera it is not at.
 *
 * Messages:
 *   master -> worker  TASK     uint32: camera (2 words), package, first, count:
 *                              a range of the visible faces, which every
 *                              rank's own pre-pass lists alike (20 bytes:
 *                              a larger task to a dead rank never left,
 *                              and its pending send held MPI_Finalize up)
 *   master -> worker  DONE     int32 status of the frame
 *   worker -> master  VT_PART  vt_result (the package, camera, counts, the
 *                              part's size)
 *   worker -> master  VT_DATA  the part (rl_vt.h), received in flight
 *                              (MPI_Irecv, tested between packages), so
 *                              that the master never blocks on one worker. */
#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "dist/dist_balance.h"
#include "dist/dist_internal.h"
#include "render/renderer.h"
#include "rl/rl_timer.h"
#include "rl/rl_vt.h"

#ifdef _OPENMP
#include <omp.h>
#endif

#define PREFETCH 2
#define SLOTS (4 * PREFETCH)    /* per worker: queued packages, parts coming, a stale answer */
#define TASK_WORDS 5            /* camera lo, camera hi, package, first, count */

typedef struct vt_result {
    uint64_t camera;
    int32_t package;
    int32_t status;
    uint64_t rays[RL_RAY_TYPE_COUNT];
    uint64_t samples, faces;
    uint64_t part_bytes;         /* the part that follows (RL_DIST_TAG_VT_DATA) */
    double busy_ms;
    char error[256];
} vt_result;

typedef struct package {
    uint32_t first, count;       /* into the visible faces */
    double cost;                 /* the sum of its faces' costs (count with cost=faces) */
    int owner;                   /* precompute: the rank it was sized for; -1: anyone */
    int state;                   /* 0 free, 1 out, 2 done */
    int rank;                    /* out to / done by */
    void *part;                  /* the result's buffer (part at part_offset) */
    size_t part_offset, part_size;
} package;

/* A worker's answer on its way: header and part in one buffer. */
typedef struct outgoing {
    unsigned char *buf;
    MPI_Request req[2];
    int n;
    bool busy;
} outgoing;

static rl_status out_finish(const rl_dist *d, outgoing *o)
{
    const double timeout = rl_dist_timeout_s(), t0 = rl_time_s();
    while (o->busy) {
        int finished = 0;
        int code = MPI_Testall(o->n, o->req, &finished, MPI_STATUSES_IGNORE);
        if (code != MPI_SUCCESS)
            return rl_dist_mpi_failed(code, "sending a package's result");
        if (finished) {
            o->busy = false;
            break;
        }
        if (rl_time_s() - t0 > timeout)
            return rl_error(RL_ERR_IO, "rank %d: the master (rank 0) has not taken a result for %.0f s: it is gone "
                            "or stuck; giving up (RL_DIST_TIMEOUT)", d->rank, timeout);
        rl_dist_pause();
    }
    free(o->buf);
    o->buf = NULL;
    return RL_OK;
}

/* Header and part into one buffer, sent in flight (MPI_Isend) as two
 * messages: the small header goes eagerly, and the master posts the
 * part's receive when it has read it, as the tiles' pixels go. */
static rl_status out_post(outgoing *o, const vt_result *res, const void *part, size_t part_size)
{
    if (part_size > (size_t)INT_MAX)
        return rl_error(RL_ERR_LIMIT, "vt: a package's part of %zu bytes (MPI counts end at 2^31)", part_size);
    if (!(o->buf = malloc(sizeof *res + part_size)))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: a package's part of %zu bytes", part_size);
    vt_result *head = (vt_result *)o->buf;
    memcpy(head, res, sizeof *res);
    head->part_bytes = part_size;
    if (part_size)
        memcpy(o->buf + sizeof *res, part, part_size);
    o->n = 0;
    int code = MPI_Isend(o->buf, (int)sizeof *res, MPI_BYTE, 0, RL_DIST_TAG_VT_PART, MPI_COMM_WORLD, &o->req[o->n++]);
    if (code == MPI_SUCCESS && part_size)
        code = MPI_Isend(o->buf + sizeof *res, (int)part_size, MPI_BYTE, 0, RL_DIST_TAG_VT_DATA, MPI_COMM_WORLD,
                         &o->req[o->n++]);
    o->busy = true;
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "sending a package's result");
    return RL_OK;
}

/* Test hook of the camera ID (docs/distributed.md): RL_DIST_STALE=RANK:N
 * makes rank RANK answer its N-th package first with an empty part
 * marked with the previous camera, as a worker answering late from the
 * last frame would; the master must drop it or lose the package's faces. */
static bool stale_point(const rl_dist *d, uint64_t tasks)
{
    const char *e = getenv("RL_DIST_STALE");
    int rank = -1;
    unsigned long long after = 0;
    return e && sscanf(e, "%d:%llu", &rank, &after) == 2 && rank == d->rank && tasks == after;
}

/* Test hook of the overlapped post-pass (docs/distributed.md):
 * RL_DIST_DELAY=RANK:MS makes rank RANK wait MS ms before it sends each
 * package's result, as a slow worker would, so that the master's
 * post-pass starts while its parts are still out and takes them late.
 * The image must not change. */
static double delay_ms(const rl_dist *d)
{
    const char *e = getenv("RL_DIST_DELAY");
    int rank = -1;
    double ms = 0.0;
    return e && sscanf(e, "%d:%lf", &rank, &ms) == 2 && rank == d->rank && ms > 0.0 ? ms : 0.0;
}

/* A worker's frame: packages until DONE, whose status it returns. */
static rl_status vt_work(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                         rl_image *image, uint64_t camera)
{
    outgoing out[PREFETCH + 1];
    memset(out, 0, sizeof out);
    int slot = 0;
    uint64_t tasks = 0;
    uint32_t *task = NULL;
    rl_status result = RL_OK;
    /* The pre-pass (and the first frame's BVH) while the master runs its
     * own, not on the first package's critical path; a failure is the
     * first package's answer. */
    const uint32_t *visible;
    size_t num_visible;
    char prep_error[256] = "";
    rl_clear_error();
    rl_status prep = rl_vt_prepare(r, scene, cam, image, &visible, &num_visible);
    /* The same pre-pass as the master's gives the same visible faces, so
     * a task names a range of them (r owns its list only until its next
     * call: a copy). */
    uint32_t *mine = prep == RL_OK ? malloc((num_visible ? num_visible : 1) * sizeof *mine) : NULL;
    if (prep == RL_OK && !mine)
        prep = rl_error(RL_ERR_OUT_OF_MEMORY, "rank %d: the visible faces", d->rank);
    else if (mine && num_visible)
        memcpy(mine, visible, num_visible * sizeof *mine);
    if (prep != RL_OK)
        snprintf(prep_error, sizeof prep_error, "%s", rl_last_error());
    for (;;) {
        /* All packages may be out while the master waits out a lost
         * worker's timeout before it hands them on: twice the timeout
         * tells a master that waits from one that is gone. */
        MPI_Status ms;
        rl_status wst = rl_dist_wait_for(d, MPI_ANY_TAG, &ms, 2.0 * rl_dist_timeout_s(), "RL_DIST_TIMEOUT");
        if (wst != RL_OK) {
            result = wst;
            break;
        }
        if (ms.MPI_TAG == RL_DIST_TAG_DONE) {
            int32_t value = 0;
            int code = MPI_Recv(&value, 1, MPI_INT32_T, 0, RL_DIST_TAG_DONE, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
            for (int k = 0; k <= PREFETCH && result == RL_OK; ++k)
                result = out_finish(d, &out[k]);
            if (result == RL_OK && code != MPI_SUCCESS)
                result = rl_dist_mpi_failed(code, "receiving the end of the frame");
            else if (result == RL_OK && value != RL_OK)
                result = rl_error((rl_status)value, "distributed frame: another rank failed (%s)",
                                  rl_status_string((rl_status)value));
            break;
        }
        int words = 0;
        MPI_Get_count(&ms, MPI_UINT32_T, &words);
        if (ms.MPI_TAG != RL_DIST_TAG_TASK || words != TASK_WORDS) {
            result = rl_error(RL_ERR_IO, "rank %d: a message of tag %d and %d words from the master is no "
                              "Vertex Tracing task", d->rank, ms.MPI_TAG, words);
            break;
        }
        uint32_t *t = realloc(task, (size_t)words * sizeof *t);
        if (!t) {
            result = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        task = t;
        int code = MPI_Recv(task, words, MPI_UINT32_T, 0, RL_DIST_TAG_TASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
        if (code != MPI_SUCCESS) {
            result = rl_dist_mpi_failed(code, "receiving a package");
            break;
        }
        vt_result res;
        memset(&res, 0, sizeof res);
        res.camera = (uint64_t)task[0] | (uint64_t)task[1] << 32;
        res.package = (int32_t)task[2];
        uint32_t first = task[3], count = task[4];
        outgoing *o = &out[slot];
        slot = (slot + 1) % (PREFETCH + 1);
        if ((result = out_finish(d, o)) != RL_OK)
            break;
        void *part = NULL;
        size_t part_size = 0;
        rl_render_stats ps = { 0 };
        rl_timer tm;
        rl_timer_start(&tm);
        rl_clear_error();
        rl_status st;
        if (prep != RL_OK)
            st = rl_error(prep, "%s", prep_error);
        else if (res.camera != camera)
            st = rl_error(RL_ERR_INTERNAL, "rank %d: a package of camera %llu while at camera %llu (out of step)",
                          d->rank, (unsigned long long)res.camera, (unsigned long long)camera);
        else if (first > num_visible || count > num_visible - first)
            st = rl_error(RL_ERR_IO, "rank %d: a package of faces %u..%u of %zu visible (out of step)", d->rank,
                          first, first + count, num_visible);
        else
            st = rl_vt_refine_faces(r, scene, cam, image, mine + first, count, &part, &part_size, &ps);
        res.busy_ms = rl_timer_ms(&tm);
        res.status = (int32_t)st;
        if (st != RL_OK)
            snprintf(res.error, sizeof res.error, "%s", rl_last_error());
        memcpy(res.rays, ps.rays, sizeof res.rays);
        res.samples = ps.samples;
        res.faces = count;
        ++tasks;
        if (st == RL_OK && stale_point(d, tasks)) {
            vt_result old = res;
            --old.camera;
            void *empty = NULL;
            size_t empty_size = 0;
            outgoing extra = { 0 };
            rl_status xs = rl_vt_refine_faces(r, scene, cam, image, NULL, 0, &empty, &empty_size, NULL);
            if (xs == RL_OK)
                xs = out_post(&extra, &old, empty, empty_size);
            if (xs == RL_OK)
                xs = out_finish(d, &extra);
            free(empty);
            free(extra.buf);
            if (xs != RL_OK) {
                free(part);
                result = xs;
                break;
            }
        }
        const double delay = delay_ms(d);
        for (const double t0 = rl_time_s(); delay > 0.0 && (rl_time_s() - t0) * 1000.0 < delay;)
            rl_dist_pause();
        st = out_post(o, &res, part, part_size);
        free(part);
        if (st != RL_OK) {
            result = st;
            break;
        }
        rl_dist_fault_point(d);
    }
    free(task);
    free(mine);
    for (int k = 0; k <= PREFETCH; ++k)
        if (!out[k].busy)
            free(out[k].buf);        /* a send still in flight keeps its buffer: the job ends anyway */
    return result;
}

/* The master's view of a worker. */
typedef struct vt_worker {
    int pending;                 /* packages handed out, not answered */
    int out[SLOTS];              /* their indices, -1: free */
    MPI_Request rx[SLOTS];       /* answers being received */
    unsigned char *rxbuf[SLOTS];
    size_t rxsize[SLOTS];
    int receiving;
    bool lost_rx[SLOTS];         /* cancelled with its worker: never tested again */
    double since;                /* last answer, or work handed to it while idle */
    bool lost;
} vt_worker;

typedef struct vt_lead_ctx {
    rl_dist *d;
    rl_dist_stats *ds;
    rl_render_stats *stats;
    const uint32_t *faces;
    const double *cost;          /* per visible face (cost=estimate), else NULL: a face is the unit */
    double *cost_done;           /* per rank: the cost of its packages done this frame */
    package *pkg;
    size_t num_pkg, cap_pkg;
    vt_worker *ws;
    uint64_t camera;
    int remaining;
    /* The overlapped post-pass (option dist_overlap): every part goes into
     * r's sample map as it comes (rl_vt_postpass_add), so that a replay
     * started before the last part takes it when it is in. */
    rl_renderer *r;
    bool feed;
    double last_part_s;          /* when the last part came (or the master's own was done) */
} vt_lead_ctx;

static rl_status add_package(vt_lead_ctx *c, uint32_t first, uint32_t count, int owner)
{
    if (count == 0)
        return RL_OK;
    if (!rl_reserve((void **)&c->pkg, &c->cap_pkg, c->num_pkg + 1, sizeof *c->pkg, 16))
        return RL_ERR_OUT_OF_MEMORY;
    double cost = count;
    if (c->cost) {
        cost = 0.0;
        for (uint32_t i = first; i < first + count; ++i)
            cost += c->cost[i];
    }
    c->pkg[c->num_pkg++] = (package){ .first = first, .count = count, .cost = cost, .owner = owner, .rank = -1 };
    ++c->remaining;
    return RL_OK;
}

/* Sec. 4.3.3: rank i's package from first on holds the share v_i / sum
 * v_j of the faces' summed cost (b_Slave_i = c_Slave_i / c_total *
 * b_total): of their number with cost=faces, of their estimates b_f with
 * cost=estimate. Ranks lost or unmeasured (v_i = 0) get none; none
 * measured: equal shares. */
static rl_status split_by_speed(vt_lead_ctx *c, uint32_t first, uint32_t n, const double *speed)
{
    const size_t size = (size_t)(c->d->size > 0 ? c->d->size : 1);
    double *v = calloc(size, sizeof *v);
    uint32_t *share = calloc(size, sizeof *share);
    if (!v || !share) {
        free(v);
        free(share);
        return RL_ERR_OUT_OF_MEMORY;
    }
    bool any = false;
    for (size_t i = 0; i < size; ++i) {
        bool live = i == 0 || !c->ws[i].lost;
        v[i] = live && speed[i] > 0.0 ? speed[i] : 0.0;
        any |= v[i] > 0.0;
    }
    if (!any)
        for (size_t i = 0; i < size; ++i)
            v[i] = i == 0 || !c->ws[i].lost ? 1.0 : 0.0;
    rl_dist_cut_by_cost(c->cost ? c->cost + first : NULL, n, v, size, share);
    rl_status st = RL_OK;
    uint32_t at = first;
    for (size_t i = 0; i < size && st == RL_OK; ++i) {
        st = add_package(c, at, share[i], (int)i);
        at += share[i];
    }
    free(v);
    free(share);
    return st;
}

/* The first free package w may take: its own (precompute), else anyone's. */
static int next_for(const vt_lead_ctx *c, int w)
{
    int any = -1;
    for (size_t i = 0; i < c->num_pkg; ++i) {
        if (c->pkg[i].state != 0)
            continue;
        if (c->pkg[i].owner == w)
            return (int)i;
        if (c->pkg[i].owner < 0 && any < 0)
            any = (int)i;
    }
    return any;
}

static rl_status give(vt_lead_ctx *c, int w, int p)
{
    vt_worker *ws = &c->ws[w];
    package *pk = &c->pkg[p];
    uint32_t task[TASK_WORDS];
    const size_t words = TASK_WORDS;
    task[0] = (uint32_t)c->camera;
    task[1] = (uint32_t)(c->camera >> 32);
    task[2] = (uint32_t)p;
    task[3] = pk->first;
    task[4] = pk->count;
    /* A blocking send, as the tiles' bands: 20 bytes go eagerly, also to
     * a rank that died (a pending MPI_Isend to one, cancelled, held
     * MPI_Finalize up now and then). */
    int code = MPI_Send(task, (int)words, MPI_UINT32_T, w, RL_DIST_TAG_TASK, MPI_COMM_WORLD);
    ++c->ds->messages;
    c->ds->bytes += words * sizeof *task;
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "handing out a package");
    if (ws->pending == 0 && ws->receiving == 0)
        ws->since = rl_time_s();
    for (int k = 0; k < SLOTS; ++k)
        if (ws->out[k] < 0) {
            ws->out[k] = p;
            break;
        }
    ++ws->pending;
    pk->state = 1;
    pk->rank = w;
    return RL_OK;
}

/* Receive slots left for w's answers: every package handed out needs one
 * (its part may still be coming when its header frees the queue). */
static int slots_free(const vt_worker *ws)
{
    int used = ws->pending;
    for (int k = 0; k < SLOTS; ++k)
        used += ws->rxbuf[k] != NULL;
    return SLOTS - used;
}

/* Tops every live worker up to PREFETCH packages. */
static rl_status hand_out(vt_lead_ctx *c)
{
    rl_status st = RL_OK;
    for (int w = 1; w < c->d->size && st == RL_OK; ++w)
        while (st == RL_OK && !c->ws[w].lost && c->ws[w].pending < PREFETCH && slots_free(&c->ws[w]) > 1) {
            int p = next_for(c, w);
            if (p < 0)
                break;
            st = give(c, w, p);
        }
    return st;
}

/* A worker's answer, received whole: the camera checked, the part kept
 * (buf is taken over) or dropped. */
static rl_status take_answer(vt_lead_ctx *c, int w, unsigned char *buf, size_t size, char *failure, size_t n)
{
    vt_result res;
    if (size < sizeof res) {
        free(buf);
        return rl_error(RL_ERR_IO, "rank %d: an answer of %zu bytes", w, size);
    }
    memcpy(&res, buf, sizeof res);
    c->ws[w].since = rl_time_s();
    if (res.camera != c->camera) {
        /* Sec. 4.3.2: a result of another camera is not this frame's. */
        ++c->ds->dropped;
        free(buf);
        return RL_OK;
    }
    if (res.package < 0 || (size_t)res.package >= c->num_pkg) {
        free(buf);
        return rl_error(RL_ERR_IO, "rank %d: an answer for package %d of %zu", w, res.package, c->num_pkg);
    }
    package *pk = &c->pkg[res.package];
    if (res.status != RL_OK) {
        res.error[sizeof res.error - 1] = '\0';
        snprintf(failure, n, "rank %d: %s", w, res.error);
        free(buf);
        return (rl_status)res.status;
    }
    if (pk->state == 2) {
        free(buf);                   /* a lost worker's late answer: redone meanwhile */
        return RL_OK;
    }
    /* Fed to the post-pass' map at once (which checks it as
     * rl_vt_part_check does), or checked now and used at the end. */
    rl_status st = c->feed ? rl_vt_postpass_add(c->r, buf + sizeof res, size - sizeof res)
                           : rl_vt_part_check(buf + sizeof res, size - sizeof res, NULL, NULL);
    if (st != RL_OK) {
        free(buf);
        snprintf(failure, n, "rank %d: package %d: %s", w, res.package, rl_last_error());
        return st;
    }
    pk->part = buf;
    pk->part_offset = sizeof res;
    pk->part_size = size - sizeof res;
    pk->state = 2;
    pk->rank = w;
    --c->remaining;
    c->last_part_s = rl_time_s();
    c->d->per_rank[w].tasks++;
    c->d->per_rank[w].pixels += res.faces;
    c->d->per_rank[w].busy_ms += res.busy_ms;
    c->cost_done[w] += pk->cost;
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        c->stats->rays[k] += res.rays[k];
    c->stats->samples += res.samples;
    return RL_OK;
}

/* The headers that have come: each one's part receive posted (tested
 * between packages) and its package off the worker's queue, so that the
 * worker's next one goes out now, not when the part is in. A worker that
 * dies mid-transfer leaves a receive that is cancelled, never a blocked
 * master (a matched receive, MPI_Improbe + MPI_Imrecv, from a dead rank
 * cannot be cancelled and held MPI_Finalize up). *arrived: any came. */
static int take_headers(vt_lead_ctx *c, int *arrived)
{
    *arrived = 0;
    for (;;) {
        int any = 0;
        MPI_Status ms;
        int code = MPI_Iprobe(MPI_ANY_SOURCE, RL_DIST_TAG_VT_PART, MPI_COMM_WORLD, &any, &ms);
        if (code != MPI_SUCCESS || !any)
            return code;
        *arrived = 1;
        const int w = ms.MPI_SOURCE;
        vt_worker *ws = &c->ws[w];
        vt_result head;
        if ((code = MPI_Recv(&head, (int)sizeof head, MPI_BYTE, w, RL_DIST_TAG_VT_PART, MPI_COMM_WORLD,
                             MPI_STATUS_IGNORE)) != MPI_SUCCESS)
            return code;
        ++c->ds->messages;
        c->ds->bytes += sizeof head;
        ws->since = rl_time_s();
        for (int k = 0; head.camera == c->camera && k < SLOTS; ++k)
            if (ws->out[k] >= 0 && ws->out[k] == head.package) {
                ws->out[k] = -1;
                --ws->pending;
                break;
            }
        int k = 0;
        while (k < SLOTS && ws->rxbuf[k])
            ++k;
        unsigned char *buf = k < SLOTS && head.part_bytes <= (uint64_t)INT_MAX
                                 ? malloc(sizeof head + (size_t)head.part_bytes) : NULL;
        if (!buf)
            return MPI_ERR_NO_MEM;       /* more answers than packages, a huge part, or no memory */
        memcpy(buf, &head, sizeof head);
        ws->rxbuf[k] = buf;
        ws->rxsize[k] = sizeof head + (size_t)head.part_bytes;
        ws->lost_rx[k] = false;
        ++ws->receiving;
        ws->rx[k] = MPI_REQUEST_NULL;    /* no part: tests complete at once */
        if (head.part_bytes) {
            code = MPI_Irecv(buf + sizeof head, (int)head.part_bytes, MPI_BYTE, w, RL_DIST_TAG_VT_DATA,
                             MPI_COMM_WORLD, &ws->rx[k]);
            ++c->ds->messages;
            c->ds->bytes += head.part_bytes;
            if (code != MPI_SUCCESS)
                return code;
        }
    }
}

/* The parts that are in complete their packages (take_answer); the
 * first failure into *st and failure, unless *st has one. *completed:
 * how many came. */
static int take_parts(vt_lead_ctx *c, rl_status *st, char *failure, size_t n, int *completed)
{
    *completed = 0;
    int code = MPI_SUCCESS;
    for (int w = 1; w < c->d->size && code == MPI_SUCCESS; ++w)
        for (int k = 0; k < SLOTS && c->ws[w].receiving > 0 && code == MPI_SUCCESS; ++k) {
            vt_worker *ws = &c->ws[w];
            if (!ws->rxbuf[k] || ws->lost_rx[k])
                continue;
            int complete = 0;
            if ((code = MPI_Test(&ws->rx[k], &complete, MPI_STATUS_IGNORE)) != MPI_SUCCESS || !complete)
                continue;
            unsigned char *buf = ws->rxbuf[k];
            ws->rxbuf[k] = NULL;
            --ws->receiving;
            char why[320] = "";
            rl_status as = take_answer(c, w, buf, ws->rxsize[k], why, sizeof why);
            if (as == RL_OK) {
                ++*completed;
            } else if (*st == RL_OK) {
                *st = as;
                snprintf(failure, n, "%s", why[0] ? why : rl_last_error());
            }
        }
    return code;
}

/* The master's progress: the caller's callback sees the frame's faces,
 * those done anywhere plus the share of the package refined here. */
typedef struct vt_progress {
    rl_progress_fn fn;
    void *user;
    double total, done, current;
    bool cancelled;
    /* While the master refines a package of its own it answers the
     * workers from here (after every refinement stage): a package can
     * take a second where a worker's queue lasts milliseconds. */
    vt_lead_ctx *serve;
    int code;                    /* the first MPI failure in here */
    rl_status st;
    char failure[320];
} vt_progress;

static bool package_progress(void *user, double done)
{
    vt_progress *p = user;
#ifdef _OPENMP
    const bool main_thread = omp_get_thread_num() == 0;   /* MPI_THREAD_FUNNELED */
#else
    const bool main_thread = true;
#endif
    if (p->serve && main_thread && p->code == MPI_SUCCESS && p->st == RL_OK) {
        int arrived = 0, completed = 0;
        p->code = take_parts(p->serve, &p->st, p->failure, sizeof p->failure, &completed);
        if (completed) {
            p->done = 0.0;
            for (size_t i = 0; i < p->serve->num_pkg; ++i)
                p->done += p->serve->pkg[i].state == 2 ? p->serve->pkg[i].count : 0;
        }
        if (p->code == MPI_SUCCESS)
            p->code = take_headers(p->serve, &arrived);
        if (p->code == MPI_SUCCESS && p->st == RL_OK && arrived && (p->st = hand_out(p->serve)) != RL_OK)
            snprintf(p->failure, sizeof p->failure, "%s", rl_last_error());
    }
    double f = p->total > 0.0 ? (p->done + done * p->current) / p->total : 1.0;
    if (p->fn && !p->fn(p->user, f > 1.0 ? 1.0 : f))
        p->cancelled = true;
    return !p->cancelled;
}

/* What the serving inside package_progress left after a refinement or the
 * post-pass: its first status becomes the frame's if that has none yet;
 * the return is its MPI failure (MPI_SUCCESS if none), which ends the
 * master's loop. */
static int serve_result(const vt_progress *vp, rl_status *st, char *failure, size_t size)
{
    if (vp->code == MPI_SUCCESS && vp->st != RL_OK && *st == RL_OK) {
        *st = vp->st;
        snprintf(failure, size, "%s", vp->failure);
    }
    return vp->code;
}

/* Whether the calibration packages (the first size ones) are all back. */
static bool calibrated(const vt_lead_ctx *c, size_t calibration)
{
    for (size_t i = 0; i < calibration && i < c->num_pkg; ++i)
        if (c->pkg[i].state != 2)
            return false;
    return true;
}

/* The share of the visible faces whose packages are not in yet. */
static double share_out(const vt_lead_ctx *c, uint32_t n)
{
    uint64_t out = 0;
    for (size_t i = 0; i < c->num_pkg; ++i)
        out += c->pkg[i].state != 2 ? c->pkg[i].count : 0;
    return n ? (double)out / n : 0.0;
}

/* The master's frame. A worker silent past the timeout with packages in
 * hand is taken for lost: they go to whoever is free, it gets no more.
 *
 * The overlapped post-pass (dist_postpass with dist_overlap > 0; Ullmann
 * 2003, Sec. 6.1.3; docs/distributed.md, "The post-pass overlapped"): the
 * replay of one process' refinement runs stage by stage over the whole
 * frame (its stages are octaves of the frame's longest edge, and the
 * order of splits decides the mesh), so it cannot be cut into the
 * packages' regions, and its first stage needs every package's primary
 * vertices: waiting for the parts a stage needs would start it after the
 * last one. Instead, once the master has no package of its own left and
 * at most the share dist_overlap of the faces is out, it starts the
 * replay with the parts in so far, takes every part that comes meanwhile
 * into the replay's map (between stages, package_progress) and traces a
 * vertex whose part is not in yet: a sample depends only on its vertex,
 * so it is the sample the part brings, and the image is the one-process
 * image whenever the parts come. What the master traces twice is bounded
 * by the faces still out when it starts. */
static rl_status vt_lead(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                         rl_image *image, uint64_t camera, rl_render_stats *stats, rl_dist_stats *ds)
{
    const uint32_t *faces = NULL;
    size_t nfaces = 0;
    char failure[320] = "";
    /* Only the master draws: a drawing it cannot make (reconstruct = gl
     * without GL) ends the frame before any package is refined. The
     * workers never ask, so they need no GL. */
    char why[512];
    rl_status st = rl_renderer_available(r, why, sizeof why)
                       ? RL_OK : rl_error(RL_ERR_UNSUPPORTED, "%s: unavailable: %s", rl_renderer_name(r), why);
    if (st == RL_OK)
        st = rl_vt_prepare(r, scene, cam, image, &faces, &nfaces);
    if (st == RL_OK && nfaces > UINT32_MAX / 2)
        st = rl_error(RL_ERR_LIMIT, "vt: %zu visible faces to distribute", nfaces);
    if (st != RL_OK)
        snprintf(failure, sizeof failure, "%s", rl_last_error());
    /* r owns the list until its next call, and the master refines with r. */
    uint32_t *own_faces = malloc((nfaces ? nfaces : 1) * sizeof *own_faces);
    if (own_faces && nfaces)
        memcpy(own_faces, faces, nfaces * sizeof *own_faces);
    vt_lead_ctx c = { .d = d, .ds = ds, .stats = stats, .faces = own_faces, .camera = camera };
    c.ws = calloc((size_t)d->size, sizeof *c.ws);
    c.cost_done = calloc((size_t)d->size, sizeof *c.cost_done);
    const bool precompute = strcmp(rl_renderer_get(r, "balance"), "precompute") == 0;
    const bool estimate = precompute && strcmp(rl_renderer_get(r, "cost"), "estimate") == 0;
    double *face_cost = estimate ? malloc((nfaces ? nfaces : 1) * sizeof *face_cost) : NULL;
    if (!c.ws || !own_faces || !c.cost_done || (estimate && !face_cost)) {
        free(c.ws);
        free(c.cost_done);
        free(face_cost);
        free(own_faces);
        return RL_ERR_OUT_OF_MEMORY;         /* the CLI aborts the job */
    }
    faces = own_faces;
    const bool postpass = rl_renderer_opt_bool(r, "dist_postpass");
    const double overlap = postpass ? rl_renderer_opt_float(r, "dist_overlap") : 0.0;
    c.r = r;
    c.feed = postpass && overlap > 0.0;
    c.last_part_s = rl_time_s();
    if (postpass)
        rl_vt_postpass_clear(r);     /* nothing of an earlier frame */
    bool replayed = false;
    double replay_start = 0.0, replay_end = 0.0;
    for (int w = 0; w < d->size; ++w)
        for (int k = 0; k < SLOTS; ++k)
            c.ws[w].out[k] = -1;
    /* Sec. 4.3.3's sequential pre-compute step: the workers wait for
     * their packages meanwhile (they run their own pre-pass first). */
    double estimate_ms = 0.0;
    if (st == RL_OK && estimate) {
        rl_timer tm;
        rl_timer_start(&tm);
        if ((st = rl_vt_estimate_costs(r, scene, cam, image, own_faces, nfaces, face_cost, stats)) != RL_OK)
            snprintf(failure, sizeof failure, "%s", rl_last_error());
        c.cost = face_cost;
        estimate_ms = rl_timer_ms(&tm);
    }
    /* Speeds of another unit (cost=faces, cost=estimate) say nothing. */
    if (d->vt_speed_estimate != estimate)
        d->vt_speed_valid = false;
    const uint32_t n = (uint32_t)nfaces, ranks = (uint32_t)d->size;
    size_t calibration = 0;
    uint32_t rest_first = 0, rest_count = 0;
    if (st == RL_OK && !precompute) {
        long long opt = rl_renderer_opt_int(r, "package");
        uint32_t size = opt > 0 ? (uint32_t)(opt < (long long)n ? opt : (long long)(n ? n : 1))
                                : (n + 32 * ranks - 1) / (32 * ranks);
        if (size == 0)
            size = 1;
        for (uint32_t first = 0; first < n && st == RL_OK; first += size)
            st = add_package(&c, first, n - first < size ? n - first : size, -1);
    } else if (st == RL_OK && d->vt_speed_valid) {
        st = split_by_speed(&c, 0, n, d->vt_speed);
    } else if (st == RL_OK) {
        uint32_t cal = n / (8 * ranks);
        if (cal == 0) {
            double *equal = calloc(ranks, sizeof *equal);
            st = equal ? RL_OK : RL_ERR_OUT_OF_MEMORY;
            for (uint32_t i = 0; equal && i < ranks; ++i)
                equal[i] = 1.0;
            if (st == RL_OK)
                st = split_by_speed(&c, 0, n, equal);
            free(equal);
        } else {
            for (uint32_t i = 0; i < ranks && st == RL_OK; ++i)
                st = add_package(&c, i * cal, cal, (int)i);
            calibration = ranks;
            rest_first = cal * ranks;
            rest_count = n - rest_first;
        }
    }
    if (st != RL_OK && !failure[0])
        snprintf(failure, sizeof failure, "%s", rl_last_error());
    ds->tasks = 0;
    vt_progress vp = { .total = (double)n };
    rl_renderer_get_progress(r, &vp.fn, &vp.user);
    rl_renderer_set_progress(r, package_progress, &vp);
    const double timeout = rl_dist_timeout_s();
    int code = MPI_SUCCESS;
    if (st == RL_OK && (st = hand_out(&c)) != RL_OK)
        snprintf(failure, sizeof failure, "%s", rl_last_error());
    for (;;) {
        int outstanding = 0;
        for (int w = 1; w < d->size; ++w)
            if (!c.ws[w].lost)
                outstanding += c.ws[w].pending + c.ws[w].receiving;
        /* After an overlapped post-pass the image is drawn: the packages
         * still out are only collected (their workers wait for that). */
        if (st == RL_OK ? (c.remaining == 0 && rest_count == 0) || (replayed && outstanding == 0)
                        : outstanding == 0)
            break;
        if (vp.cancelled && st == RL_OK) {
            st = RL_ERR_CANCELLED;           /* no more packages out; drain the rest */
            snprintf(failure, sizeof failure, "cancelled by the progress callback");
        }
        /* Answers that are in. */
        int completed = 0;
        if ((code = take_parts(&c, &st, failure, sizeof failure, &completed)) != MPI_SUCCESS)
            break;
        if (completed) {
            vp.done = 0.0;
            for (size_t i = 0; i < c.num_pkg; ++i)
                vp.done += c.pkg[i].state == 2 ? c.pkg[i].count : 0;
            package_progress(&vp, 0.0);
        }
        /* precompute, first frame: the rest by the calibrated speeds. */
        if (st == RL_OK && rest_count && calibrated(&c, calibration)) {
            double *speed = calloc(ranks, sizeof *speed);
            st = speed ? RL_OK : RL_ERR_OUT_OF_MEMORY;
            for (uint32_t i = 0; speed && i < ranks; ++i)
                speed[i] = d->per_rank[i].busy_ms > 0.0 ? c.cost_done[i] / d->per_rank[i].busy_ms : 0.0;
            if (st == RL_OK)
                st = split_by_speed(&c, rest_first, rest_count, speed);
            free(speed);
            rest_count = 0;
            if (st != RL_OK)
                snprintf(failure, sizeof failure, "%s", rl_last_error());
        }
        if (st == RL_OK && !replayed && (st = hand_out(&c)) != RL_OK)
            snprintf(failure, sizeof failure, "%s", rl_last_error());
        int arrived = 0;
        if ((code = take_headers(&c, &arrived)) != MPI_SUCCESS)
            break;
        if (arrived)
            continue;
        /* Nothing to answer: refine a package here. */
        int p = st == RL_OK && !replayed ? next_for(&c, 0) : -1;
        if (p >= 0) {
            package *pk = &c.pkg[p];
            rl_render_stats ps = { 0 };
            rl_timer tm;
            rl_timer_start(&tm);
            vp.current = pk->count;
            vp.serve = &c;
            pk->state = 1;
            st = rl_vt_refine_faces(r, scene, cam, image, faces + pk->first, pk->count, &pk->part, &pk->part_size,
                                    &ps);
            vp.current = 0.0;
            vp.serve = NULL;
            d->per_rank[0].busy_ms += rl_timer_ms(&tm);
            if ((code = serve_result(&vp, &st, failure, sizeof failure)) != MPI_SUCCESS)
                break;
            if (st != RL_OK) {
                snprintf(failure, sizeof failure, "%s", rl_last_error());
                continue;
            }
            pk->state = 2;
            pk->rank = 0;
            pk->part_offset = 0;
            --c.remaining;
            c.last_part_s = rl_time_s();
            if (c.feed && (st = rl_vt_postpass_add(r, pk->part, pk->part_size)) != RL_OK) {
                snprintf(failure, sizeof failure, "%s", rl_last_error());
                continue;
            }
            ++d->per_rank[0].tasks;
            d->per_rank[0].pixels += pk->count;
            c.cost_done[0] += pk->cost;
            for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                stats->rays[k] += ps.rays[k];
            stats->samples += ps.samples;
            vp.done += pk->count;
            package_progress(&vp, 0.0);
            rl_dist_fault_point(d);
            continue;
        }
        /* Nothing of its own left: the post-pass, overlapped with the
         * packages still out once few are (above). */
        if (p < 0 && c.feed && !replayed && st == RL_OK && rest_count == 0 && share_out(&c, n) <= overlap) {
            vp.current = 0.0;
            vp.serve = &c;
            replay_start = rl_time_s();
            rl_status rs = rl_vt_postpass_draw(r, scene, cam, image, stats);
            replay_end = rl_time_s();
            vp.serve = NULL;
            replayed = true;
            if ((code = serve_result(&vp, &st, failure, sizeof failure)) != MPI_SUCCESS)
                break;
            if (rs != RL_OK && st == RL_OK) {
                st = rs;
                snprintf(failure, sizeof failure, "%s", rl_last_error());
            }
            continue;
        }
        /* Waiting: a worker silent past the timeout is lost. */
        const double now = rl_time_s();
        for (int w = 1; w < d->size; ++w) {
            vt_worker *ws = &c.ws[w];
            if (ws->lost || ws->pending + ws->receiving == 0 || now - ws->since <= timeout)
                continue;
            ws->lost = true;
            ++ds->lost;
            for (int k = 0; k < SLOTS; ++k) {
                if (ws->out[k] >= 0 && c.pkg[ws->out[k]].state == 1) {
                    c.pkg[ws->out[k]].state = 0;
                    c.pkg[ws->out[k]].owner = -1;
                }
                ws->out[k] = -1;
            }
            ws->pending = 0;
            /* Parts that stopped coming never will: their receives are
             * cancelled (a dead sender completes nothing). */
            for (int k = 0; k < SLOTS; ++k)
                if (ws->rxbuf[k] && !ws->lost_rx[k]) {
                    MPI_Cancel(&ws->rx[k]);
                    ws->lost_rx[k] = true;
                    /* answered, but its part never came: redone */
                    vt_result head;
                    memcpy(&head, ws->rxbuf[k], sizeof head);
                    if (head.camera == c.camera && head.package >= 0 && (size_t)head.package < c.num_pkg &&
                        c.pkg[head.package].state == 1) {
                        c.pkg[head.package].state = 0;
                        c.pkg[head.package].owner = -1;
                    }
                }
            ws->receiving = 0;
            rl_log(RL_LOG_WARN, "rank %d has not answered for %.0f s: taken for lost, its packages go to the "
                   "other ranks (RL_DIST_TIMEOUT)", w, now - ws->since);
        }
        rl_dist_pause();
    }
    rl_renderer_set_progress(r, vp.fn, vp.user);
    if (code == MPI_SUCCESS) {
        /* Every live worker hears the end; a lost one gives up by its own
         * timeout (rl_dist_wait). */
        int32_t end = (int32_t)st;
        for (int w = 1; w < d->size && code == MPI_SUCCESS; ++w)
            if (!c.ws[w].lost) {
                code = MPI_Send(&end, 1, MPI_INT32_T, w, RL_DIST_TAG_DONE, MPI_COMM_WORLD);
                ++ds->messages;
            }
    }
    ds->tasks = c.num_pkg;
    if (code == MPI_SUCCESS && st == RL_OK) {
        /* The next frame's precompute speeds, in the unit of cost; a rank
         * without a package this frame keeps its last speed. */
        for (int i = 0; i < d->size; ++i)
            if (d->per_rank[i].busy_ms > 0.0 && d->per_rank[i].pixels > 0)
                d->vt_speed[i] = c.cost_done[i] / d->per_rank[i].busy_ms;
        d->vt_speed_valid = precompute;
        d->vt_speed_estimate = estimate;
        const void **parts = calloc(c.num_pkg ? c.num_pkg : 1, sizeof *parts);
        size_t *sizes = calloc(c.num_pkg ? c.num_pkg : 1, sizeof *sizes);
        if (!parts || !sizes) {
            st = RL_ERR_OUT_OF_MEMORY;
            snprintf(failure, sizeof failure, "the parts of %zu packages", c.num_pkg);
        }
        for (size_t i = 0; st == RL_OK && i < c.num_pkg; ++i) {
            parts[i] = (const unsigned char *)c.pkg[i].part + c.pkg[i].part_offset;
            sizes[i] = c.pkg[i].part_size;
        }
        rl_timer tm;
        rl_timer_start(&tm);
        /* Drawn already by the overlapped post-pass; else now, from the
         * parts fed to the post-pass' map as they came, or from all. */
        if (st == RL_OK && !replayed &&
            (st = c.feed ? rl_vt_postpass_draw(r, scene, cam, image, stats)
                         : rl_vt_draw_parts(r, scene, cam, image, parts, sizes, c.num_pkg, stats)) != RL_OK)
            snprintf(failure, sizeof failure, "%s", rl_last_error());
        const double image_s = replayed ? replay_end : rl_time_s();
        rl_vt_stats vs;
        if (st == RL_OK && postpass && rl_vt_get_stats(r, &vs) == RL_OK) {
            ds->postpass = true;
            ds->postpass_reused = vs.postpass_reused;
            ds->postpass_traced = vs.postpass_traced;
            ds->postpass_ms = vs.time_refine_ms + vs.time_sampling_ms;
            ds->postpass_overlapped = replayed && replay_start < c.last_part_s;
            const double early = replayed ? (replay_end < c.last_part_s ? replay_end : c.last_part_s) - replay_start
                                          : 0.0;
            ds->postpass_early_ms = early > 0.0 ? 1000.0 * early : 0.0;
            ds->postpass_tail_ms = image_s > c.last_part_s ? 1000.0 * (image_s - c.last_part_s) : 0.0;
        }
        if (replayed)
            d->per_rank[0].busy_ms += 1000.0 * (replay_end - replay_start);
        d->per_rank[0].busy_ms += rl_timer_ms(&tm) + estimate_ms;
        free(parts);
        free(sizes);
    }
    if (postpass)
        rl_vt_postpass_clear(r);     /* its map points into the parts */
    for (size_t i = 0; i < c.num_pkg; ++i)
        free(c.pkg[i].part);
    free(c.pkg);
    for (int w = 1; w < d->size; ++w)
        for (int k = 0; k < SLOTS; ++k)
            if (c.ws[w].rxbuf[k]) {
                /* A lost worker's part that stopped coming (cancelled
                 * above): a dead sender writes nothing more. */
                if (!c.ws[w].lost_rx[k])
                    MPI_Cancel(&c.ws[w].rx[k]);
                free(c.ws[w].rxbuf[k]);
            }
    free(c.ws);
    free(c.cost_done);
    free(face_cost);
    free(own_faces);
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "collecting the packages");
    if (st != RL_OK)
        return rl_error(st, "%s", failure);
    return RL_OK;
}

rl_status rl_dist_vt_frame(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                           rl_image *image, rl_render_stats *stats, rl_dist_stats *ds)
{
    /* Every rank counts alike: the frames are collective. */
    const uint64_t camera = ++d->vt_camera;
    return d->rank == 0 ? vt_lead(d, r, scene, cam, image, camera, stats, ds)
                        : vt_work(d, r, scene, cam, image, camera);
}

