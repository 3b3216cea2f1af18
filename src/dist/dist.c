/* dist.c: rl_dist on Open MPI (rl_dist.h).
 *
 * A frame is cut into bands of BAND_ROWS image rows, handed out on demand
 * as in Ullmann 2003, Sec. 4.3.2's queue balancing (Fig. 4.8): the master
 * keeps PREFETCH bands queued at every worker, so that a worker finds its
 * next band waiting when it returns one, and hands out the next band to
 * whichever worker returned one. Between messages the master renders bands
 * itself: with one rank per node it would otherwise leave a node idle.
 * Bands are image rows, not squares, because a band's pixels are one
 * contiguous run per layer: no packing on either side.
 *
 * Messages (tags of dist_internal.h), all on the job's world communicator:
 *   master -> worker  TASK    int32 band
 *   master -> worker  DONE    int32 status of the frame
 *   worker -> master  RESULT  band_result (band, status, counts, error)
 *   worker -> master  PIXELS  the band's layers, present ones in order
 *                             colour, depth, object ID, triangle ID
 * A worker keeps its answers in flight (MPI_Isend) while it renders its
 * next band; the master posts a band's pixel receives when its header
 * comes and tests them between its own bands, so that it never blocks on
 * one worker, not even on one killed mid-transfer (docs/distributed.md).
 * Only the calling thread talks to MPI (MPI_THREAD_FUNNELED); OpenMP
 * threads render inside each rank. */
#include "rl/rl_dist.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "core/error.h"
#include "dist/dist_internal.h"
#include "render/renderer.h"
#include "rl/rl_timer.h"


/* 16 rows: whitted's tile height, so a band is whole tiles of it; small
 * enough that a 1024-row frame has 64 bands to balance over the ranks. */
#define BAND_ROWS 16
#define PREFETCH 2


typedef struct band_result {
    int32_t band;
    int32_t status;                    /* rl_status of the worker's render */
    uint64_t rays[RL_RAY_TYPE_COUNT];
    uint64_t samples, pixels;
    double busy_ms;
    char error[256];                   /* rl_last_error() when status failed */
} band_result;

static bool dist_initialised;

bool rl_dist_available(char *why, size_t n)
{
    (void)why;
    (void)n;
    return true;
}

rl_status rl_dist_init(int *argc, char ***argv, rl_dist **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_init: out is NULL");
    *out = NULL;
    if (dist_initialised)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_init: this process has joined its job already");
    rl_dist *d = calloc(1, sizeof *d);
    if (!d)
        return RL_ERR_OUT_OF_MEMORY;
    int ready = 0, provided = 0;
    MPI_Initialized(&ready);
    if (!ready) {
        if (MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
            free(d);
            return rl_error(RL_ERR_UNSUPPORTED, "MPI_Init_thread failed: cannot join the MPI job");
        }
        d->own_mpi = true;
    }
    /* Errors come back as codes, so a failed send is this run's error
     * with its message rather than an abort deep inside MPI. */
    MPI_Comm_set_errhandler(MPI_COMM_WORLD, MPI_ERRORS_RETURN);
    MPI_Comm_rank(MPI_COMM_WORLD, &d->rank);
    MPI_Comm_size(MPI_COMM_WORLD, &d->size);
    d->per_rank = calloc((size_t)d->size, sizeof *d->per_rank);
    d->sampling_lost = calloc((size_t)d->size, 1);
    d->vt_speed = calloc((size_t)d->size, sizeof *d->vt_speed);
    if (!d->per_rank || !d->sampling_lost || !d->vt_speed) {
        free(d->per_rank);
        free(d->sampling_lost);
        free(d->vt_speed);
        if (d->own_mpi)
            MPI_Finalize();
        free(d);
        return RL_ERR_OUT_OF_MEMORY;
    }
    dist_initialised = true;
    *out = d;
    return RL_OK;
}

int rl_dist_rank(const rl_dist *d) { return d ? d->rank : 0; }
int rl_dist_size(const rl_dist *d) { return d ? d->size : 1; }

void rl_dist_release(rl_dist *d, rl_status status)
{
    if (!d)
        return;
    bool own = d->own_mpi;
    int size = d->size;
    free(d->per_rank);
    free(d->sampling_lost);
    free(d->vt_speed);
    free(d);
    if (!own)
        return;
    if (status != RL_OK && size > 1)
        MPI_Abort(MPI_COMM_WORLD, 1);      /* ends every rank: nobody waits for this one */
    /* In Open MPI 4.1's recovery mode (docs/distributed.md) a rank may be
     * gone, and MPI_Finalize then waits on it (1 job in 5 after a lost
     * worker, in our tests), although every result is in and written. A
     * job that runs in that mode ends without it: the runtime reaps the
     * ranks as they exit. */
    const char *recovery = getenv("OMPI_MCA_orte_enable_recovery");
    if (size > 1 && recovery && (strcmp(recovery, "1") == 0 || strcmp(recovery, "true") == 0))
        return;
    MPI_Finalize();
}

double rl_dist_timeout_s(void)
{
    const char *e = getenv("RL_DIST_TIMEOUT");
    char *end = NULL;
    double t = e && *e ? strtod(e, &end) : 0.0;
    return e && *e && end && !*end && t > 0.0 && t < 1e7 ? t : RL_DIST_DEFAULT_TIMEOUT_S;
}

void rl_dist_pause(void)
{
    /* Long enough not to spin a core away from the rank's own threads,
     * short against a band's milliseconds. */
    struct timespec ts = { 0, 200000 };
    nanosleep(&ts, NULL);
}

rl_status rl_dist_wait(const rl_dist *d, int tag, MPI_Status *ms)
{
    return rl_dist_wait_for(d, tag, ms, rl_dist_timeout_s(), "RL_DIST_TIMEOUT");
}

rl_status rl_dist_wait_for(const rl_dist *d, int tag, MPI_Status *ms, double timeout, const char *setting)
{
    const double t0 = rl_time_s();
    for (;;) {
        int arrived = 0;
        int code = MPI_Iprobe(0, tag, MPI_COMM_WORLD, &arrived, ms);
        if (code != MPI_SUCCESS)
            return rl_dist_mpi_failed(code, "waiting for the master");
        if (arrived)
            return RL_OK;
        if (rl_time_s() - t0 > timeout)
            return rl_error(RL_ERR_IO, "rank %d: no word from the master (rank 0) for %.0f s: it is gone or "
                            "stuck; giving up (%s)", d->rank, timeout, setting);
        rl_dist_pause();
    }
}

rl_status rl_dist_send(const rl_dist *d, const void *buf, int count, MPI_Datatype type, int dest, int tag)
{
    MPI_Request req;
    int code = MPI_Isend(buf, count, type, dest, tag, MPI_COMM_WORLD, &req);
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "sending");
    const double timeout = rl_dist_timeout_s(), t0 = rl_time_s();
    for (;;) {
        int finished = 0;
        if ((code = MPI_Test(&req, &finished, MPI_STATUS_IGNORE)) != MPI_SUCCESS)
            return rl_dist_mpi_failed(code, "sending");
        if (finished)
            return RL_OK;
        if (rl_time_s() - t0 > timeout) {
            /* The request stays: the job ends anyway (rl_dist_release). */
            return rl_error(RL_ERR_IO, "rank %d: rank %d has not taken a message for %.0f s: it is gone or "
                            "stuck; giving up (RL_DIST_TIMEOUT)", d->rank, dest, timeout);
        }
        rl_dist_pause();
    }
}

void rl_dist_fault_point(rl_dist *d)
{
    ++d->tasks_done;
    const char *e = getenv("RL_DIST_FAULT");
    int rank = -1;
    unsigned long long after = 0;
    if (e && sscanf(e, "%d:%llu", &rank, &after) == 2 && rank == d->rank && d->tasks_done == after)
        raise(SIGKILL);
}

rl_status rl_dist_mpi_failed(int code, const char *what)
{
    char text[MPI_MAX_ERROR_STRING];
    int len = 0;
    if (MPI_Error_string(code, text, &len) != MPI_SUCCESS)
        snprintf(text, sizeof text, "MPI error %d", code);
    return rl_error(RL_ERR_IO, "distributed run: %s: %s", what, text);
}

/* The band's rows of image: where each present layer's run starts, its
 * bytes, and the total. */
typedef struct band_layout {
    void *part[4];
    size_t bytes[4];
    size_t total;
} band_layout;

static band_layout layout_of(rl_image *image, int band)
{
    int y0 = band * BAND_ROWS, y1 = y0 + BAND_ROWS < image->height ? y0 + BAND_ROWS : image->height;
    size_t first = (size_t)y0 * (size_t)image->width, n = (size_t)(y1 - y0) * (size_t)image->width;
    band_layout l = { { 0 }, { 0 }, 0 };
    if (image->color) {
        l.part[0] = image->color + first;
        l.bytes[0] = n * sizeof *image->color;
    }
    if (image->depth) {
        l.part[1] = image->depth + first;
        l.bytes[1] = n * sizeof *image->depth;
    }
    if (image->object_id) {
        l.part[2] = image->object_id + first;
        l.bytes[2] = n * sizeof *image->object_id;
    }
    if (image->triangle_id) {
        l.part[3] = image->triangle_id + first;
        l.bytes[3] = n * sizeof *image->triangle_id;
    }
    for (int k = 0; k < 4; ++k)
        l.total += l.bytes[k];
    return l;
}

/* The master's progress: the caller's callback sees the whole frame, the
 * bands done anywhere plus the share of the band rendering here. */
typedef struct frame_progress {
    rl_progress_fn fn;
    void *user;
    int bands, done;
    uint64_t frame, frames;      /* of the band rendering here */
    bool cancelled;
} frame_progress;

static bool band_progress(void *user, double done)
{
    frame_progress *p = user;
    double band = ((double)p->frame + done) / (double)p->frames;
    if (p->fn && !p->fn(p->user, ((double)p->done + band) / (double)p->bands))
        p->cancelled = true;
    return !p->cancelled;
}

static void band_done(frame_progress *p)
{
    ++p->done;
    p->frame = 0;
    band_progress(p, 0.0);
}

/* Renders band into image with r restricted to its rows: frames frames of
 * a new accumulation, so that a band is the same pixels whichever rank
 * rendered what before it. stats: their counters summed over the frames
 * (as a caller's loop over frames sums them). fp: the master's progress, else NULL. */
static rl_status render_band(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, uint64_t frames,
                             rl_image *image, int band, rl_render_stats *stats, frame_progress *fp)
{
    int y0 = band * BAND_ROWS, y1 = y0 + BAND_ROWS < image->height ? y0 + BAND_ROWS : image->height;
    rl_rect rows = { 0, y0, image->width, y1 };
    rl_status st = rl_renderer_set_region(r, &rows);
    rl_renderer_reset(r);
    for (uint64_t k = 0; st == RL_OK && k < frames; ++k) {
        rl_render_stats fs = { 0 };
        if (fp)
            fp->frame = k;
        if ((st = rl_renderer_render(r, scene, cam, image, &fs)) != RL_OK)
            break;
        for (int t = 0; t < RL_RAY_TYPE_COUNT; ++t)
            stats->rays[t] += fs.rays[t];
        stats->samples += fs.samples;
        stats->prep_ms += fs.prep_ms;
        stats->pixels_written += fs.pixels_written;
    }
    rl_renderer_set_region(r, NULL);
    return st;
}

static void add_band(rl_render_stats *to, const uint64_t rays[RL_RAY_TYPE_COUNT], uint64_t samples,
                     uint64_t pixels)
{
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        to->rays[k] += rays[k];
    to->samples += samples;
    to->pixels_written += pixels;
}

/* A band's answer on its way to the master: its header and layers, sent
 * while the worker renders its next band. */
typedef struct outgoing {
    band_result res;
    MPI_Request req[5];
    int n;
} outgoing;

/* Waits (up to the timeout: the master may be gone) until o has gone out. */
static rl_status finish_send(const rl_dist *d, outgoing *o)
{
    const double timeout = rl_dist_timeout_s(), t0 = rl_time_s();
    while (o->n > 0) {
        int finished = 0;
        int code = MPI_Testall(o->n, o->req, &finished, MPI_STATUSES_IGNORE);
        if (code != MPI_SUCCESS)
            return rl_dist_mpi_failed(code, "sending a band");
        if (finished) {
            o->n = 0;
            break;
        }
        if (rl_time_s() - t0 > timeout)
            return rl_error(RL_ERR_IO, "rank %d: the master (rank 0) has not taken a band for %.0f s: it is gone "
                            "or stuck; giving up (RL_DIST_TIMEOUT)", d->rank, timeout);
        rl_dist_pause();
    }
    return RL_OK;
}

/* A worker's frame: bands until RL_DIST_TAG_DONE, whose status it returns. */
static rl_status work(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam, uint64_t frames,
                      rl_image *image)
{
    outgoing out[PREFETCH];
    memset(out, 0, sizeof out);
    int slot = 0;
    for (;;) {
        MPI_Status ms;
        int32_t value = 0;
        rl_status wst = rl_dist_wait(d, MPI_ANY_TAG, &ms);
        if (wst != RL_OK)
            return wst;
        int code = MPI_Recv(&value, 1, MPI_INT32_T, 0, ms.MPI_TAG, MPI_COMM_WORLD, &ms);
        if (code != MPI_SUCCESS)
            return rl_dist_mpi_failed(code, "receiving a band from the master");
        for (int k = 0; ms.MPI_TAG == RL_DIST_TAG_DONE && k < PREFETCH; ++k)
            if ((wst = finish_send(d, &out[k])) != RL_OK)
                return wst;
        if (ms.MPI_TAG == RL_DIST_TAG_DONE)
            return value == RL_OK ? RL_OK
                                  : rl_error((rl_status)value, "distributed frame: another rank failed (%s)",
                                             rl_status_string((rl_status)value));
        /* The slot's last band must be out before its header is reused. */
        outgoing *o = &out[slot];
        slot = (slot + 1) % PREFETCH;
        if ((wst = finish_send(d, o)) != RL_OK)
            return wst;
        band_result res;
        memset(&res, 0, sizeof res);
        res.band = value;
        rl_render_stats bs = { 0 };
        rl_timer t;
        rl_timer_start(&t);
        rl_clear_error();
        rl_status st = render_band(r, scene, cam, frames, image, value, &bs, NULL);
        res.busy_ms = rl_timer_ms(&t);
        res.status = (int32_t)st;
        if (st != RL_OK)
            snprintf(res.error, sizeof res.error, "%s", rl_last_error());
        memcpy(res.rays, bs.rays, sizeof res.rays);
        res.samples = bs.samples;
        res.pixels = bs.pixels_written;
        /* In flight while the next band renders: a band's pixels go by
         * rendezvous, which completes only when the master takes them. */
        o->res = res;
        int code2 = MPI_Isend(&o->res, (int)sizeof o->res, MPI_BYTE, 0, RL_DIST_TAG_RESULT, MPI_COMM_WORLD,
                              &o->req[o->n++]);
        band_layout l = layout_of(image, value);
        for (int k = 0; code2 == MPI_SUCCESS && st == RL_OK && k < 4; ++k)
            if (l.bytes[k])
                code2 = MPI_Isend(l.part[k], (int)l.bytes[k], MPI_BYTE, 0, RL_DIST_TAG_PIXELS, MPI_COMM_WORLD,
                                  &o->req[o->n++]);
        if (code2 != MPI_SUCCESS)
            return rl_dist_mpi_failed(code2, "sending a band");
        rl_dist_fault_point(d);
    }
}

/* A worker's bands in the master's hands: PREFETCH queued, and as many
 * answered whose pixels are still coming (the worker sends them while it
 * renders on). */
#define SLOTS (2 * PREFETCH)

/* The master's view of a worker during a frame. */
typedef struct worker_state {
    int32_t bands[SLOTS];        /* handed out, pixels not yet in (-1: free slot) */
    bool answered[SLOTS];        /* its header is in, its pixels are coming */
    band_result res[SLOTS];
    MPI_Request rx[SLOTS][4];    /* the pixels' receives */
    int nrx[SLOTS];
    int pending;                 /* bands not yet answered */
    int receiving;               /* bands answered, pixels coming */
    double since;                /* when it last answered, or got work while idle */
    bool lost;                   /* silent past the timeout: its bands went elsewhere */
} worker_state;

/* The next band to render: a lost worker's first, then new ones. */
static int take_band(int *redo, int *num_redo, int *next, int bands)
{
    if (*num_redo > 0)
        return redo[--*num_redo];
    return *next < bands ? (*next)++ : -1;
}

static rl_status give_band(rl_dist_stats *ds, worker_state *ws, int w, int band)
{
    int32_t b = band;
    int code = MPI_Send(&b, 1, MPI_INT32_T, w, RL_DIST_TAG_TASK, MPI_COMM_WORLD);
    ++ds->messages;
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "handing out a band");
    if (ws->pending == 0 && ws->receiving == 0)
        ws->since = rl_time_s();
    for (int k = 0; k < SLOTS; ++k)
        if (ws->bands[k] < 0) {
            ws->bands[k] = b;
            ws->answered[k] = false;
            break;
        }
    ++ws->pending;
    return RL_OK;
}

/* The slot of w's band (answered or not), or a free one; -1 if neither. */
static int slot_of(const worker_state *ws, int band, bool answered)
{
    for (int k = 0; k < SLOTS; ++k)
        if (ws->bands[k] == band && ws->answered[k] == answered)
            return k;
    for (int k = 0; k < SLOTS; ++k)
        if (ws->bands[k] < 0)
            return k;
    return -1;
}

/* The master's frame. A worker that stays silent past the timeout with
 * bands in hand is taken for lost (killed, its node gone): its bands go to
 * the others and it gets no more. Should it answer after all, its bands
 * are the same pixels and are taken as they come. */
static rl_status lead(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam, uint64_t frames,
                      rl_image *image, rl_render_stats *stats, rl_dist_stats *ds)
{
    const int bands = (image->height + BAND_ROWS - 1) / BAND_ROWS;
    const double timeout = rl_dist_timeout_s();
    int next = 0, num_redo = 0, code = MPI_SUCCESS, remaining = bands;
    worker_state *ws = calloc((size_t)d->size, sizeof *ws);
    int *redo = calloc((size_t)bands + 1, sizeof *redo);
    unsigned char *done = calloc((size_t)bands + 1, 1);
    if (!ws || !redo || !done) {
        free(ws);
        free(redo);
        free(done);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (int w = 0; w < d->size; ++w)
        for (int k = 0; k < SLOTS; ++k)
            ws[w].bands[k] = -1;
    rl_status st = RL_OK;
    char failure[320] = "";
    frame_progress fp = { .bands = bands, .frames = frames };
    rl_renderer_get_progress(r, &fp.fn, &fp.user);
    rl_renderer_set_progress(r, band_progress, &fp);
    /* Queue PREFETCH bands at every worker first. */
    for (int k = 0; k < PREFETCH && st == RL_OK; ++k)
        for (int w = 1; w < d->size && next < bands && st == RL_OK; ++w)
            st = give_band(ds, &ws[w], w, next++);
    if (st != RL_OK)
        snprintf(failure, sizeof failure, "%s", rl_last_error());
    int pending = 0, receiving = 0;
    for (int w = 1; w < d->size; ++w)
        pending += ws[w].pending;
    while (code == MPI_SUCCESS && (st == RL_OK ? remaining > 0 : pending + receiving > 0)) {
        if (fp.cancelled && st == RL_OK) {
            st = RL_ERR_CANCELLED;          /* no more bands out; drain the rest */
            snprintf(failure, sizeof failure, "cancelled by the progress callback");
        }
        /* Pixels that have come in complete their bands. */
        for (int w = 1; w < d->size && code == MPI_SUCCESS; ++w)
            for (int k = 0; k < SLOTS && ws[w].receiving > 0; ++k) {
                if (ws[w].bands[k] < 0 || !ws[w].answered[k])
                    continue;
                int complete = 0;
                if ((code = MPI_Testall(ws[w].nrx[k], ws[w].rx[k], &complete, MPI_STATUSES_IGNORE)) != MPI_SUCCESS)
                    break;
                if (!complete)
                    continue;
                const band_result *res = &ws[w].res[k];
                if (!done[res->band]) {          /* a late answer of a lost worker may come twice */
                    add_band(stats, res->rays, res->samples, res->pixels);
                    ++d->per_rank[w].tasks;
                    d->per_rank[w].pixels += res->pixels;
                    d->per_rank[w].busy_ms += res->busy_ms;
                    done[res->band] = 1;
                    --remaining;
                    band_done(&fp);
                }
                ws[w].bands[k] = -1;
                --ws[w].receiving;
                if (!ws[w].lost)
                    --receiving;
                ws[w].since = rl_time_s();
            }
        if (code != MPI_SUCCESS)
            break;
        int arrived = 0;
        MPI_Status ms;
        if ((code = MPI_Iprobe(MPI_ANY_SOURCE, RL_DIST_TAG_RESULT, MPI_COMM_WORLD, &arrived, &ms)) != MPI_SUCCESS)
            break;
        if (!arrived) {
            int band = st == RL_OK ? take_band(redo, &num_redo, &next, bands) : -1;
            if (band >= 0 && !done[band]) {
                /* Nothing to answer: render a band here. */
                rl_render_stats bs = { 0 };
                rl_timer t;
                rl_timer_start(&t);
                st = render_band(r, scene, cam, frames, image, band, &bs, &fp);
                d->per_rank[0].busy_ms += rl_timer_ms(&t);
                if (st == RL_OK) {
                    add_band(stats, bs.rays, bs.samples, bs.pixels_written);
                    stats->prep_ms += bs.prep_ms;
                    ++d->per_rank[0].tasks;
                    d->per_rank[0].pixels += bs.pixels_written;
                    done[band] = 1;
                    --remaining;
                    band_done(&fp);
                    rl_dist_fault_point(d);
                } else {
                    snprintf(failure, sizeof failure, "%s", rl_last_error());
                }
                continue;
            }
            /* Waiting: a worker silent past the timeout is lost. */
            double now = rl_time_s();
            for (int w = 1; w < d->size; ++w) {
                if (ws[w].lost || ws[w].pending + ws[w].receiving == 0 || now - ws[w].since <= timeout)
                    continue;
                ws[w].lost = true;
                ++ds->lost;
                pending -= ws[w].pending;
                receiving -= ws[w].receiving;
                for (int k = 0; k < SLOTS; ++k) {
                    if (ws[w].bands[k] >= 0 && !done[ws[w].bands[k]])
                        redo[num_redo++] = ws[w].bands[k];
                    if (ws[w].bands[k] >= 0 && ws[w].answered[k]) {
                        /* Pixels that stopped coming never will: the
                         * receives are cancelled and left, their slot
                         * closed (a dead sender completes nothing). */
                        for (int j = 0; j < ws[w].nrx[k]; ++j)
                            MPI_Cancel(&ws[w].rx[k][j]);
                        ws[w].bands[k] = -2;
                        ws[w].answered[k] = false;
                    } else if (ws[w].bands[k] >= 0) {
                        ws[w].bands[k] = -1;
                    }
                }
                ws[w].pending = ws[w].receiving = 0;
                rl_log(RL_LOG_WARN, "rank %d has not answered for %.0f s: taken for lost, its bands go to the "
                       "other ranks (RL_DIST_TIMEOUT)", w, now - ws[w].since);
            }
            if (pending + receiving > 0 || st != RL_OK)
                rl_dist_pause();
            continue;
        }
        int w = ms.MPI_SOURCE;
        band_result res;
        if ((code = MPI_Recv(&res, (int)sizeof res, MPI_BYTE, w, RL_DIST_TAG_RESULT, MPI_COMM_WORLD,
                             MPI_STATUS_IGNORE)) != MPI_SUCCESS)
            break;
        ++ds->messages;
        ds->bytes += sizeof res;
        if (res.band < 0 || res.band >= bands) {
            code = MPI_ERR_OTHER;
            break;
        }
        int slot = slot_of(&ws[w], res.band, false);
        bool queued = slot >= 0 && ws[w].bands[slot] == res.band;
        if (queued) {
            ws[w].bands[slot] = -1;
            --ws[w].pending;
            if (!ws[w].lost)
                --pending;
        }
        ws[w].since = rl_time_s();
        if (res.status == RL_OK && slot < 0 && ws[w].lost)
            continue;                        /* a lost worker's late answer with no slot left: its band is redone */
        if (res.status == RL_OK && slot < 0) {
            code = MPI_ERR_OTHER;            /* more answers than bands: not our protocol */
            break;
        }
        if (res.status == RL_OK) {
            /* The pixels come while this rank renders on; the band is done
             * when they are in (above). */
            band_layout l = layout_of(image, res.band);
            ws[w].bands[slot] = res.band;
            ws[w].answered[slot] = true;
            ws[w].res[slot] = res;
            ws[w].nrx[slot] = 0;
            for (int k = 0; code == MPI_SUCCESS && k < 4; ++k)
                if (l.bytes[k]) {
                    code = MPI_Irecv(l.part[k], (int)l.bytes[k], MPI_BYTE, w, RL_DIST_TAG_PIXELS, MPI_COMM_WORLD,
                                     &ws[w].rx[slot][ws[w].nrx[slot]++]);
                    ++ds->messages;
                    ds->bytes += l.bytes[k];
                }
            if (code != MPI_SUCCESS)
                break;
            ++ws[w].receiving;
            if (!ws[w].lost)
                ++receiving;
        } else if (st == RL_OK) {
            st = (rl_status)res.status;
            res.error[sizeof res.error - 1] = '\0';
            snprintf(failure, sizeof failure, "rank %d: %s", w, res.error);
        }
        if (st == RL_OK && !ws[w].lost) {
            int band = take_band(redo, &num_redo, &next, bands);
            if (band >= 0) {
                if ((st = give_band(ds, &ws[w], w, band)) != RL_OK)
                    snprintf(failure, sizeof failure, "%s", rl_last_error());
                else
                    ++pending;
            }
        }
    }
    rl_renderer_set_progress(r, fp.fn, fp.user);
    /* A worker taken for lost that answered late after all sends its
     * pixels into the image: they must be in before the image may go. */
    const double t_end = rl_time_s();
    for (int w = 1; w < d->size && code == MPI_SUCCESS; ++w)
        for (int k = 0; k < SLOTS && ws[w].lost; ++k)
            while (ws[w].bands[k] >= 0 && ws[w].answered[k] && rl_time_s() - t_end <= timeout) {
                int complete = 0;
                if ((code = MPI_Testall(ws[w].nrx[k], ws[w].rx[k], &complete, MPI_STATUSES_IGNORE)) != MPI_SUCCESS)
                    break;
                if (complete)
                    ws[w].bands[k] = -1;
                else
                    rl_dist_pause();
            }
    if (code == MPI_SUCCESS) {
        /* Every live worker hears the end. A lost one does not: a send to
         * a dead rank may never return; one that was only slow gives up
         * by its own timeout (rl_dist_wait). */
        int32_t end = (int32_t)st;
        for (int w = 1; w < d->size && code == MPI_SUCCESS; ++w)
            if (!ws[w].lost) {
                code = MPI_Send(&end, 1, MPI_INT32_T, w, RL_DIST_TAG_DONE, MPI_COMM_WORLD);
                ++ds->messages;
            }
    }
    free(ws);
    free(redo);
    free(done);
    ds->tasks = (uint64_t)bands;
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "collecting the bands");   /* the CLI then aborts the job */
    if (st != RL_OK)
        return rl_error(st, "%s", failure);
    return RL_OK;
}

/* frames 0: one frame that continues the renderer's accumulation in a job
 * of one (rl_dist_render). */
static rl_status render_frames(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                               uint64_t frames, rl_image *image, rl_render_stats *stats, rl_dist_stats *dstats)
{
    rl_dist_stats ds_local;
    rl_dist_stats *ds = dstats ? dstats : &ds_local;
    memset(ds, 0, sizeof *ds);
    ds->ranks = rl_dist_size(d);
    rl_render_stats local;
    rl_render_stats *rs = stats ? stats : &local;
    memset(rs, 0, sizeof *rs);
    if (!r || !scene || !cam || !image)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_render: renderer, scene, camera and image must not be NULL");
    if (frames > RL_DIST_MAX_FRAMES)
        return rl_error(RL_ERR_LIMIT, "rl_dist_render_frames: %llu frames (at most %d)", (unsigned long long)frames,
                        RL_DIST_MAX_FRAMES);
    if (!d || d->size == 1) {
        if (frames == 0) {
            rl_status st0 = rl_renderer_render(r, scene, cam, image, rs);
            ds->time_ms = rs->time_ms;
            return st0;
        }
        rl_timer t;
        rl_timer_start(&t);
        rl_renderer_reset(r);
        rl_status st = RL_OK;
        for (uint64_t k = 0; k < frames && st == RL_OK; ++k) {
            rl_render_stats fs = { 0 };
            if ((st = rl_renderer_render(r, scene, cam, image, &fs)) == RL_OK) {
                add_band(rs, fs.rays, fs.samples, 0);
                rs->prep_ms += fs.prep_ms;
                rs->pixels_written += fs.pixels_written;
            }
        }
        rs->time_ms = ds->time_ms = rl_timer_ms(&t);
        return st;
    }
    if (strcmp(rl_renderer_name(r), "vt") == 0) {
        /* Vertex Tracing splits the frame by faces, not pixels (dist_vt.c). */
        if (frames > 1)
            return rl_error(RL_ERR_UNSUPPORTED, "vt renders single frames (no accumulation over frames)");
        memset(d->per_rank, 0, (size_t)d->size * sizeof *d->per_rank);
        rl_timer t;
        rl_timer_start(&t);
        rl_status st = rl_dist_vt_frame(d, r, scene, cam, image, rs, ds);
        rs->time_ms = ds->time_ms = rl_timer_ms(&t);
        ds->per_rank = d->per_rank;
        ds->task_kind = "package";
        return st;
    }
    if (frames == 0)
        frames = 1;
    /* Every rank decides alike from what every rank has, so that all of
     * them refuse together and none waits for a band. */
    const rl_renderer_info *info = NULL;
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    for (size_t i = 0; i < n; ++i)
        if (strcmp(list[i].name, rl_renderer_name(r)) == 0)
            info = &list[i];
    if (!info || !info->regions)
        return rl_error(RL_ERR_UNSUPPORTED, "%s renders whole images only and cannot be distributed "
                        "(distributed renderers render image regions: rl algos marks them)", rl_renderer_name(r));
    memset(d->per_rank, 0, (size_t)d->size * sizeof *d->per_rank);
    rl_timer t;
    rl_timer_start(&t);
    /* Whole-image passes (pt's filter) wait for the assembled image. */
    rl_renderer_defer_whole_passes(r, true);
    rl_status st = d->rank == 0 ? lead(d, r, scene, cam, frames, image, rs, ds)
                                : work(d, r, scene, cam, frames, image);
    rl_renderer_defer_whole_passes(r, false);
    if (st == RL_OK && d->rank == 0)
        st = rl_renderer_finish_regions(r, scene, cam, image, rs->samples);
    rs->time_ms = ds->time_ms = rl_timer_ms(&t);
    ds->per_rank = d->per_rank;
    return st;
}

rl_status rl_dist_render(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                         rl_image *image, rl_render_stats *stats, rl_dist_stats *dstats)
{
    return render_frames(d, r, scene, cam, 0, image, stats, dstats);
}

rl_status rl_dist_render_frames(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                                uint64_t frames, rl_image *image, rl_render_stats *stats, rl_dist_stats *dstats)
{
    if (frames == 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_render_frames: frames must be at least 1");
    return render_frames(d, r, scene, cam, frames, image, stats, dstats);
}
