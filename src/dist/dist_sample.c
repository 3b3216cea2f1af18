/* dist_sample.c: parallel adaptive sampling (Jähn 2015, Sec. 5.5, Alg. 5.4)
 * on the ranks of an MPI job (rl_dist.h).
 *
 * The master is the control node: it runs the sampling itself (Alg. 5.3,
 * rl_sample_property), which chooses every position before it measures
 * any of a batch; the batch's measuring (Alg. 5.4, lines 11-16) goes
 * through rl_sampling_desc.measure to the sampling nodes. The master cuts
 * a batch into chunks, keeps PREFETCH chunks queued at every worker, hands
 * the next chunk to whichever worker answered, and measures chunks itself
 * between messages. A value depends only on its position, so the
 * approximation is the one a single process makes with the same seed: the
 * same samples, regions and sets. The exception are properties that
 * measure the machine (times, RL_PROPERTY_EXCLUSIVE): their values are
 * this run's, as in any two runs.
 *
 * Messages (tags of dist_internal.h):
 *   master -> worker  TASK    chunk_header + count positions (rl_vec3)
 *   master -> worker  DONE    int32 status of the run
 *   worker -> master  RESULT  chunk_result (chunk, status, error)
 *   worker -> master  VALUES  count doubles, then count * words set words */
#define _POSIX_C_SOURCE 200809L
#include "rl/rl_dist.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "dist/dist_internal.h"
#include "rl/rl_timer.h"

#define PREFETCH 2
/* Positions per chunk at most: a visibility sample costs milliseconds, so
 * a chunk of 16 is tens of them against one message's microseconds. */
#define MAX_CHUNK 16

typedef struct chunk_header {
    int32_t chunk, count;
    int32_t words;                     /* set words per position wanted; 0: none */
    int32_t pad;
} chunk_header;

typedef struct chunk_result {
    int32_t chunk, status;
    double busy_ms;
    char error[256];
} chunk_result;

/* A worker's place in a batch: up to SLOTS chunks handed out, whose
 * answers come in order; an answered chunk's values arrive into the
 * slot's own buffers (a receive of a worker lost mid-transfer may never
 * end, so it must not write where another rank's values go). */
/* A worker holds at most PREFETCH chunks, but the values of chunks it has
 * answered may still be arriving (or, lost mid-transfer, never arrive):
 * room for both, and more. */
#define SLOTS (2 * PREFETCH + 4)
enum { SLOT_FREE, SLOT_HANDED, SLOT_RECEIVING, SLOT_CLOSED };

typedef struct slot {
    int state;
    int32_t chunk;
    MPI_Request rx[2];
    int nrx;
    double busy_ms;
    double values[MAX_CHUNK];
    uint64_t *sets;                    /* MAX_CHUNK * words, made on first use */
} slot;

typedef struct holder {
    slot slots[SLOTS];
    int pending, receiving;            /* slots handed out / receiving */
    double since;                      /* when it last answered, or got work while idle */
} holder;

typedef struct sampler {
    rl_dist *d;
    rl_property *p;
    uint64_t messages, bytes, chunks;
    int lost;                          /* workers taken for lost during this run */
    holder *h;                         /* d->size entries, kept for the run: see slot */
    size_t set_words;                  /* words of the slots' set buffers */
    char failure[320];
} sampler;

static rl_status send_chunk(sampler *s, int w, int chunk, const rl_vec3 *pos, int count, size_t words,
                            unsigned char **buf, size_t *cap)
{
    size_t bytes = sizeof(chunk_header) + (size_t)count * sizeof *pos;
    if (bytes > *cap) {
        unsigned char *b = realloc(*buf, bytes);
        if (!b)
            return RL_ERR_OUT_OF_MEMORY;
        *buf = b;
        *cap = bytes;
    }
    holder *ho = &s->h[w];
    slot *sl = NULL;
    for (int k = 0; k < SLOTS && !sl; ++k)
        if (ho->slots[k].state == SLOT_FREE)
            sl = &ho->slots[k];
    if (!sl)
        return rl_error(RL_ERR_INTERNAL, "distributed sampling: rank %d holds more chunks than it has slots", w);
    chunk_header h = { .chunk = chunk, .count = count, .words = (int32_t)words };
    memcpy(*buf, &h, sizeof h);
    memcpy(*buf + sizeof h, pos, (size_t)count * sizeof *pos);
    int code = MPI_Send(*buf, (int)bytes, MPI_BYTE, w, RL_DIST_TAG_TASK, MPI_COMM_WORLD);
    ++s->messages;
    s->bytes += bytes;
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "handing out positions");
    if (ho->pending == 0 && ho->receiving == 0)
        ho->since = rl_time_s();
    sl->state = SLOT_HANDED;
    sl->chunk = chunk;
    ++ho->pending;
    return RL_OK;
}

/* The next chunk to measure: a lost worker's first, then new ones; -1
 * when none is left. */
static int take_chunk(int *redo, int *num_redo, int *next, int chunks, const unsigned char *done)
{
    while (*num_redo > 0) {
        int c = redo[--*num_redo];
        if (!done[c])
            return c;
    }
    return *next < chunks ? (*next)++ : -1;
}

/* rl_sampling_desc.measure on the master: one batch over every rank.
 * Fault tolerance as in a distributed frame (dist.c): the master never
 * blocks on one worker; a worker that holds chunks and has not answered
 * for RL_DIST_TIMEOUT seconds is taken for lost for the rest of the job,
 * and its chunks are measured by the others. A value depends only on its
 * position, so the batch's values are the same whoever measures them. */
static rl_status measure(void *user, const rl_vec3 *pos, uint32_t n, double *values, uint64_t *sets, size_t words)
{
    sampler *s = user;
    rl_dist *d = s->d;
    /* Chunks small enough that every rank gets a few per batch, so that
     * the slowest chunk does not hold the batch up. */
    uint32_t chunk = n / (uint32_t)(4 * d->size);
    chunk = chunk < 1 ? 1 : chunk > MAX_CHUNK ? MAX_CHUNK : chunk;
    const int chunks = (int)((n + chunk - 1) / chunk);
    const double timeout = rl_dist_timeout_s();
    if (words > s->set_words) {
        /* Set buffers of a larger size (a closed slot is never used
         * again, and its buffer may still be a receive's target). */
        for (int w = 1; w < d->size; ++w)
            for (int k = 0; k < SLOTS; ++k)
                if (s->h[w].slots[k].state != SLOT_CLOSED) {
                    free(s->h[w].slots[k].sets);
                    s->h[w].slots[k].sets = NULL;
                }
        s->set_words = words;
    }
    int *redo = malloc((size_t)chunks * sizeof *redo);
    unsigned char *done = calloc((size_t)chunks, 1);
    if (!redo || !done) {
        free(redo);
        free(done);
        return RL_ERR_OUT_OF_MEMORY;
    }
    unsigned char *buf = NULL;
    size_t cap = 0;
    int next = 0, num_redo = 0, remaining = chunks, pending = 0, receiving = 0, code = MPI_SUCCESS;
    rl_status st = RL_OK, failed = RL_OK;
#define CHUNK_COUNT(c) ((int)((uint32_t)(c) * chunk + chunk <= n ? chunk : n - (uint32_t)(c) * chunk))
    for (int k = 0; k < PREFETCH && st == RL_OK; ++k)
        for (int w = 1; w < d->size && next < chunks && st == RL_OK; ++w)
            if (!d->sampling_lost[w]) {
                st = send_chunk(s, w, next, pos + (size_t)next * chunk, CHUNK_COUNT(next), words, &buf, &cap);
                ++next;
                ++pending;
            }
    if (st != RL_OK) {
        free(buf);
        free(redo);
        free(done);
        return st;           /* the CLI aborts the job: workers may hold chunks */
    }
    while (code == MPI_SUCCESS && (failed == RL_OK ? remaining > 0 : pending + receiving > 0)) {
        /* Values that have come in complete their chunks. */
        for (int w = 1; w < d->size && code == MPI_SUCCESS; ++w)
            for (int k = 0; k < SLOTS && s->h[w].receiving > 0; ++k) {
                slot *sl = &s->h[w].slots[k];
                if (sl->state != SLOT_RECEIVING)
                    continue;
                int complete = 0;
                if ((code = MPI_Testall(sl->nrx, sl->rx, &complete, MPI_STATUSES_IGNORE)) != MPI_SUCCESS)
                    break;
                if (!complete)
                    continue;
                if (!done[sl->chunk]) {          /* a lost worker's late answer may come twice */
                    size_t off = (size_t)sl->chunk * chunk, cnt = (size_t)CHUNK_COUNT(sl->chunk);
                    memcpy(values + off, sl->values, cnt * sizeof *values);
                    if (words)
                        memcpy(sets + off * words, sl->sets, cnt * words * sizeof *sets);
                    d->per_rank[w].tasks += 1;
                    d->per_rank[w].pixels += cnt;
                    d->per_rank[w].busy_ms += sl->busy_ms;
                    done[sl->chunk] = 1;
                    --remaining;
                }
                sl->state = SLOT_FREE;
                --s->h[w].receiving;
                if (!d->sampling_lost[w])
                    --receiving;
                s->h[w].since = rl_time_s();
            }
        if (code != MPI_SUCCESS)
            break;
        int arrived = 0;
        MPI_Status ms;
        if ((code = MPI_Iprobe(MPI_ANY_SOURCE, RL_DIST_TAG_RESULT, MPI_COMM_WORLD, &arrived, &ms)) != MPI_SUCCESS)
            break;
        if (!arrived) {
            int c = failed == RL_OK ? take_chunk(redo, &num_redo, &next, chunks, done) : -1;
            if (c >= 0) {
                /* Nothing to answer: measure a chunk here. */
                size_t off = (size_t)c * chunk;
                rl_timer t;
                rl_timer_start(&t);
                rl_status ms_st = rl_property_measure_sets(s->p, pos + off, (size_t)CHUNK_COUNT(c), values + off,
                                                           words ? sets + off * words : NULL, NULL, NULL);
                d->per_rank[0].busy_ms += rl_timer_ms(&t);
                d->per_rank[0].tasks += 1;
                d->per_rank[0].pixels += (uint64_t)CHUNK_COUNT(c);
                if (ms_st != RL_OK) {
                    failed = ms_st;
                    snprintf(s->failure, sizeof s->failure, "%s", rl_last_error());
                } else {
                    done[c] = 1;
                    --remaining;
                }
                continue;
            }
            /* Waiting: a worker silent past the timeout is lost. */
            double now = rl_time_s();
            for (int w = 1; w < d->size; ++w) {
                holder *ho = &s->h[w];
                if (d->sampling_lost[w] || ho->pending + ho->receiving == 0 || now - ho->since <= timeout)
                    continue;
                d->sampling_lost[w] = 1;
                ++s->lost;
                pending -= ho->pending;
                receiving -= ho->receiving;
                for (int k = 0; k < SLOTS; ++k) {
                    slot *sl = &ho->slots[k];
                    if ((sl->state == SLOT_HANDED || sl->state == SLOT_RECEIVING) && !done[sl->chunk])
                        redo[num_redo++] = sl->chunk;
                    if (sl->state == SLOT_RECEIVING) {
                        /* Values that stopped coming never will: the
                         * receives are cancelled and left, the slot closed
                         * for the run (a dead sender completes nothing). */
                        for (int j = 0; j < sl->nrx; ++j)
                            MPI_Cancel(&sl->rx[j]);
                        sl->state = SLOT_CLOSED;
                    } else if (sl->state == SLOT_HANDED) {
                        sl->state = SLOT_FREE;
                    }
                }
                ho->pending = ho->receiving = 0;
                rl_log(RL_LOG_WARN, "rank %d has not answered for %.0f s: taken for lost, its positions go to "
                       "the other ranks (RL_DIST_TIMEOUT)", w, now - ho->since);
            }
            if (pending + receiving > 0)
                rl_dist_pause();
            continue;
        }
        int w = ms.MPI_SOURCE;
        chunk_result res;
        if ((code = MPI_Recv(&res, (int)sizeof res, MPI_BYTE, w, RL_DIST_TAG_RESULT, MPI_COMM_WORLD,
                             MPI_STATUS_IGNORE)) != MPI_SUCCESS)
            break;
        ++s->messages;
        s->bytes += sizeof res;
        holder *ho = &s->h[w];
        slot *sl = NULL;
        if (res.chunk >= 0 && res.chunk < chunks)
            for (int k = 0; k < SLOTS && !sl; ++k)
                if (ho->slots[k].state == SLOT_HANDED && ho->slots[k].chunk == res.chunk)
                    sl = &ho->slots[k];
        if (!sl && d->sampling_lost[w])
            continue;        /* a lost worker's late answer, of this batch or an earlier one: redone */
        if (!sl) {
            code = MPI_ERR_OTHER;        /* an answer nobody asked for: not our protocol */
            break;
        }
        --ho->pending;
        if (!d->sampling_lost[w])
            --pending;
        ho->since = rl_time_s();
        if (res.status == RL_OK) {
            /* The values come while this rank measures on; the chunk is
             * done when they are in (above). */
            size_t cnt = (size_t)CHUNK_COUNT(res.chunk);
            if (words && !sl->sets && !(sl->sets = malloc((size_t)MAX_CHUNK * words * sizeof *sl->sets))) {
                st = RL_ERR_OUT_OF_MEMORY;
                break;
            }
            sl->state = SLOT_RECEIVING;
            sl->busy_ms = res.busy_ms;
            sl->nrx = 0;
            code = MPI_Irecv(sl->values, (int)cnt, MPI_DOUBLE, w, RL_DIST_TAG_VALUES, MPI_COMM_WORLD,
                             &sl->rx[sl->nrx++]);
            s->bytes += cnt * sizeof(double);
            ++s->messages;
            if (code == MPI_SUCCESS && words) {
                code = MPI_Irecv(sl->sets, (int)(cnt * words), MPI_UINT64_T, w, RL_DIST_TAG_VALUES,
                                 MPI_COMM_WORLD, &sl->rx[sl->nrx++]);
                s->bytes += cnt * words * sizeof(uint64_t);
                ++s->messages;
            }
            if (code != MPI_SUCCESS)
                break;
            ++ho->receiving;
            if (!d->sampling_lost[w])
                ++receiving;
        } else {
            sl->state = SLOT_FREE;
            if (failed == RL_OK) {
                failed = (rl_status)res.status;
                res.error[sizeof res.error - 1] = '\0';
                snprintf(s->failure, sizeof s->failure, "rank %d: %s", w, res.error);
            }
        }
        if (failed == RL_OK && !d->sampling_lost[w]) {
            int c = take_chunk(redo, &num_redo, &next, chunks, done);
            if (c >= 0) {
                if ((st = send_chunk(s, w, c, pos + (size_t)c * chunk, CHUNK_COUNT(c), words, &buf, &cap)) != RL_OK)
                    break;
                ++pending;
            }
        }
    }
#undef CHUNK_COUNT
    free(buf);
    free(redo);
    free(done);
    s->chunks += (uint64_t)chunks;
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, "collecting measured values");
    if (st != RL_OK)
        return st;
    return failed == RL_OK ? RL_OK : rl_error(failed, "%s", s->failure);
}

/* The status the master ends a run (DONE) or the service (END) with, as
 * this rank's: RL_OK, or an error saying who failed. */
static rl_status receive_end(int tag, const char *what, const char *who_failed)
{
    int32_t end = 0;
    int code = MPI_Recv(&end, 1, MPI_INT32_T, 0, tag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (code != MPI_SUCCESS)
        return rl_dist_mpi_failed(code, what);
    return end == RL_OK ? RL_OK : rl_error((rl_status)end, "%s (%s)", who_failed, rl_status_string((rl_status)end));
}

/* A sampling node: chunks until DONE, whose status it returns. Without
 * a property (p NULL) it answers every chunk with an error (why, or
 * MPI's), so that the control node fails the run for every rank. */
static rl_status serve(rl_dist *d, rl_property *p, const char *why)
{
    unsigned char *buf = NULL;
    double *values = NULL;
    uint64_t *sets = NULL;
    rl_status st = RL_OK;
    for (;;) {
        MPI_Status ms;
        /* A dead control node: an error. Not before the control node has
         * had the time to take another worker for lost (RL_DIST_TIMEOUT)
         * and to hand its chunks out again: until then it may well have
         * nothing for this one. */
        if ((st = rl_dist_wait_for(d, MPI_ANY_TAG, &ms, 3.0 * rl_dist_timeout_s(), "RL_DIST_TIMEOUT")) != RL_OK)
            break;
        int bytes = 0;
        int code = MPI_Get_count(&ms, MPI_BYTE, &bytes);
        if (code != MPI_SUCCESS) {
            st = rl_dist_mpi_failed(code, "receiving positions from the control node");
            break;
        }
        if (ms.MPI_TAG == RL_DIST_TAG_DONE) {
            st = receive_end(RL_DIST_TAG_DONE, "ending the sampling", "distributed sampling: another rank failed");
            break;
        }
        unsigned char *b = realloc(buf, (size_t)bytes + 1);
        if (!b) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        buf = b;
        if ((code = MPI_Recv(buf, bytes, MPI_BYTE, 0, RL_DIST_TAG_TASK, MPI_COMM_WORLD, MPI_STATUS_IGNORE)) !=
            MPI_SUCCESS) {
            st = rl_dist_mpi_failed(code, "receiving positions from the control node");
            break;
        }
        chunk_header h;
        memcpy(&h, buf, sizeof h);
        size_t words = h.words > 0 && p ? rl_property_set_words(p) : 0;
        if (h.count < 1 || (size_t)bytes != sizeof h + (size_t)h.count * sizeof(rl_vec3) ||
            (h.words > 0 && p && (size_t)h.words != words)) {
            st = rl_error(RL_ERR_INTERNAL, "distributed sampling: a malformed chunk from the control node");
            break;
        }
        double *v = realloc(values, (size_t)h.count * sizeof *v);
        uint64_t *ss = words ? realloc(sets, (size_t)h.count * words * sizeof *ss) : sets;
        if (v)
            values = v;
        if (ss)
            sets = ss;
        if (!v || (!ss && words)) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        rl_vec3 *pos = malloc((size_t)h.count * sizeof *pos);
        if (!pos) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        memcpy(pos, buf + sizeof h, (size_t)h.count * sizeof *pos);
        chunk_result res;
        memset(&res, 0, sizeof res);
        res.chunk = h.chunk;
        rl_timer t;
        rl_timer_start(&t);
        rl_clear_error();
        rl_status ms_st = !p && why ? rl_error(RL_ERR_INVALID_ARG, "%s", why)
                                    : rl_property_measure_sets(p, pos, (size_t)h.count, values, words ? sets : NULL,
                                                               NULL, NULL);
        free(pos);
        res.busy_ms = rl_timer_ms(&t);
        res.status = (int32_t)ms_st;
        if (ms_st != RL_OK)
            snprintf(res.error, sizeof res.error, "%s", rl_last_error());
        st = rl_dist_send(d, &res, (int)sizeof res, MPI_BYTE, 0, RL_DIST_TAG_RESULT);
        if (st == RL_OK && ms_st == RL_OK)
            st = rl_dist_send(d, values, h.count, MPI_DOUBLE, 0, RL_DIST_TAG_VALUES);
        if (st == RL_OK && ms_st == RL_OK && words)
            st = rl_dist_send(d, sets, (int)((size_t)h.count * words), MPI_UINT64_T, 0, RL_DIST_TAG_VALUES);
        if (st != RL_OK)
            break;
        rl_dist_fault_point(d);
    }
    free(buf);
    free(values);
    free(sets);
    return st;
}

/* The control node ends a run: every live worker gets its status (DONE).
 * A lost one does not: a send to a dead rank may never return; one that
 * was only slow gives up by its own timeout (rl_dist_wait). */
static rl_status end_run(sampler *s, rl_status st)
{
    int32_t done = (int32_t)st;
    for (int w = 1; w < s->d->size; ++w) {
        if (s->d->sampling_lost[w])
            continue;
        int code = MPI_Send(&done, 1, MPI_INT32_T, w, RL_DIST_TAG_DONE, MPI_COMM_WORLD);
        ++s->messages;
        if (code != MPI_SUCCESS && st == RL_OK)
            st = rl_dist_mpi_failed(code, "ending the sampling");
    }
    return st;
}

/* The property service (rl_dist.h): a property as text, its name on the
 * first line, then key=value per option, for the workers to make it
 * themselves. NULL (error recorded) when p cannot be described so. */
static char *property_spec(const rl_property *p)
{
    if (!p) {
        rl_error(RL_ERR_INVALID_ARG, "distributed run: no property");
        return NULL;
    }
    size_t n = 0;
    const rl_option_info *opts = rl_property_options(p, &n);
    size_t len = strlen(rl_property_name(p)) + 2;
    for (size_t i = 0; i < n; ++i) {
        const char *v = rl_property_get(p, opts[i].key);
        if (!v || strchr(v, '\n')) {
            rl_error(RL_ERR_UNSUPPORTED, "distributed run: property %s: option %s cannot be sent to the workers",
                     rl_property_name(p), opts[i].key);
            return NULL;
        }
        len += strlen(opts[i].key) + strlen(v) + 2;
    }
    char *spec = malloc(len);
    if (!spec) {
        rl_error(RL_ERR_OUT_OF_MEMORY, "distributed run: out of memory");
        return NULL;
    }
    size_t at = (size_t)snprintf(spec, len, "%s\n", rl_property_name(p));
    for (size_t i = 0; i < n; ++i)
        at += (size_t)snprintf(spec + at, len - at, "%s=%s\n", opts[i].key, rl_property_get(p, opts[i].key));
    return spec;
}

/* The master tells every live worker the run's property. A property it
 * cannot describe goes as an empty text with the reason, so that the
 * workers answer the run's chunks with it and every rank fails alike. */
static rl_status send_spec(sampler *s, const rl_property *p)
{
    char *spec = property_spec(p);
    char why[300];
    snprintf(why, sizeof why, "\n%s", rl_last_error());
    const char *text = spec ? spec : why;
    rl_status st = RL_OK;
    for (int w = 1; w < s->d->size && st == RL_OK; ++w) {
        if (s->d->sampling_lost[w])
            continue;
        st = rl_dist_send(s->d, text, (int)strlen(text) + 1, MPI_CHAR, w, RL_DIST_TAG_SPEC);
        ++s->messages;
        s->bytes += strlen(text) + 1;
    }
    free(spec);
    return st;
}

static rl_status sampler_init(sampler *s, rl_dist *d, rl_property *p)
{
    memset(s, 0, sizeof *s);
    s->d = d;
    s->p = p;
    if (!(s->h = calloc((size_t)d->size, sizeof *s->h)))
        return RL_ERR_OUT_OF_MEMORY;
    return RL_OK;
}

/* The run's totals into ds, and the slots' buffers freed. A closed slot
 * (a lost worker's receive, cancelled) is freed only where MPI has let go
 * of its receives; otherwise the holders stay allocated (a few kilobytes
 * per worker lost mid-transfer), since the receive may still write. */
static void sampler_finish(sampler *s, rl_dist_stats *ds)
{
    ds->tasks = s->chunks;
    ds->messages = s->messages;
    ds->bytes = s->bytes;
    ds->lost = s->lost;
    bool in_use = false;
    for (int w = 1; s->h && w < s->d->size; ++w)
        for (int k = 0; k < SLOTS; ++k) {
            slot *sl = &s->h[w].slots[k];
            int released = 1;
            if (sl->state == SLOT_CLOSED &&
                (MPI_Testall(sl->nrx, sl->rx, &released, MPI_STATUSES_IGNORE) != MPI_SUCCESS || !released)) {
                in_use = true;
                continue;
            }
            free(sl->sets);
            sl->sets = NULL;
        }
    if (!in_use)
        free(s->h);
    s->h = NULL;
}

rl_status rl_dist_sample_property(rl_dist *d, rl_property *p, const rl_sampling_desc *desc, rl_approx **out,
                                  rl_dist_stats *dstats)
{
    rl_dist_stats local;
    rl_dist_stats *ds = dstats ? dstats : &local;
    memset(ds, 0, sizeof *ds);
    ds->ranks = rl_dist_size(d);
    if (out)
        *out = NULL;
    if (!d || d->size == 1) {
        rl_timer t1;
        rl_timer_start(&t1);
        rl_status st1 = rl_sample_property(p, desc, out);
        ds->time_ms = rl_timer_ms(&t1);
        return st1;
    }
    if (!p || !desc || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_sample_property: property, desc and out must not be NULL");
    memset(d->per_rank, 0, (size_t)d->size * sizeof *d->per_rank);
    rl_timer t;
    rl_timer_start(&t);
    rl_status st;
    if (d->rank == 0) {
        sampler s;
        st = sampler_init(&s, d, p);
        if (st == RL_OK && d->service)
            st = send_spec(&s, p);
        rl_sampling_desc dd = *desc;
        dd.measure = measure;
        dd.measure_user = &s;
        if (st == RL_OK)
            st = rl_sample_property(p, &dd, out);
        if ((st = end_run(&s, st)) != RL_OK) {
            rl_approx_release(*out);
            *out = NULL;
        }
        sampler_finish(&s, ds);
    } else {
        st = serve(d, p, NULL);
    }
    ds->time_ms = rl_timer_ms(&t);
    ds->per_rank = d->per_rank;
    return st;
}

rl_status rl_dist_measure(rl_dist *d, rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                          rl_dist_stats *dstats)
{
    rl_dist_stats local;
    rl_dist_stats *ds = dstats ? dstats : &local;
    memset(ds, 0, sizeof *ds);
    ds->ranks = rl_dist_size(d);
    rl_timer t;
    rl_timer_start(&t);
    if (!d || d->size == 1) {
        rl_status st1 = p ? rl_property_measure(p, pos, count, values, NULL, NULL)
                          : rl_error(RL_ERR_INVALID_ARG, "rl_dist_measure: no property");
        ds->time_ms = rl_timer_ms(&t);
        return st1;
    }
    memset(d->per_rank, 0, (size_t)d->size * sizeof *d->per_rank);
    rl_status st;
    if (d->rank == 0) {
        sampler s;
        rl_status init = sampler_init(&s, d, p);
        if (init == RL_OK && d->service)
            init = send_spec(&s, p);
        /* Even a call that cannot measure ends the run on the workers,
         * which wait in serve() for it. */
        if (init != RL_OK)
            st = init;
        else if (!p)
            st = rl_error(RL_ERR_INVALID_ARG, "rl_dist_measure: no property");
        else if (count && (!pos || !values))
            st = rl_error(RL_ERR_INVALID_ARG, "rl_dist_measure: positions and values must not be NULL");
        else if (count > UINT32_MAX)
            st = rl_error(RL_ERR_LIMIT, "rl_dist_measure: %zu positions (at most %u)", count, UINT32_MAX);
        else
            st = count ? measure(&s, pos, (uint32_t)count, values, NULL, 0) : RL_OK;
        st = end_run(&s, st);
        sampler_finish(&s, ds);
    } else {
        /* A worker without the property answers every chunk with the
         * error, so that the master ends the run for all. */
        st = serve(d, p, NULL);
    }
    ds->time_ms = rl_timer_ms(&t);
    ds->per_rank = d->per_rank;
    return st;
}

rl_status rl_dist_service_begin(rl_dist *d)
{
    if (!d)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_service_begin: no job");
    if (d->rank != 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_service_begin: only the master (rank 0) leads the service");
    d->service = true;
    return RL_OK;
}

rl_status rl_dist_service_end(rl_dist *d, rl_status status)
{
    if (!d || d->rank != 0 || !d->service)
        return status;
    d->service = false;
    int32_t end = (int32_t)status;
    for (int w = 1; w < d->size; ++w) {
        if (d->sampling_lost[w])
            continue;
        rl_status st = rl_dist_send(d, &end, 1, MPI_INT32_T, w, RL_DIST_TAG_END);
        if (st != RL_OK && status == RL_OK)
            status = st;
    }
    return status;
}

/* RL_DIST_IDLE_TIMEOUT in seconds, else an hour. */
static double idle_timeout_s(void)
{
    const char *e = getenv("RL_DIST_IDLE_TIMEOUT");
    char *end = NULL;
    double t = e && *e ? strtod(e, &end) : 0.0;
    return e && *e && end && !*end && t > 0.0 && t < 1e7 ? t : 3600.0;
}

/* A worker's committed properties, by their text, the oldest replaced:
 * the sections of a benchmark come back to the same few. */
#define SERVICE_CACHE 4

rl_status rl_dist_serve_properties(rl_dist *d, const rl_scene *scene, int threads)
{
    if (!d || !scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_serve_properties: job and scene must not be NULL");
    if (d->rank == 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_serve_properties: the master (rank 0) leads, it does not serve");
    struct {
        char *spec;
        rl_property *p;
        uint64_t used;
    } cache[SERVICE_CACHE] = { { 0 } };
    uint64_t clock = 0;
    char *text = NULL;
    rl_status st = RL_OK;
    const double timeout = idle_timeout_s();
    for (;;) {
        MPI_Status ms;
        int code = MPI_SUCCESS;
        if ((st = rl_dist_wait_for(d, MPI_ANY_TAG, &ms, timeout, "RL_DIST_IDLE_TIMEOUT")) != RL_OK)
            break;
        if (ms.MPI_TAG == RL_DIST_TAG_END) {
            st = receive_end(RL_DIST_TAG_END, "ending the service", "distributed run: the master failed");
            break;
        }
        if (ms.MPI_TAG != RL_DIST_TAG_SPEC) {
            st = rl_error(RL_ERR_INTERNAL, "distributed run: message %d from the master outside a run", ms.MPI_TAG);
            break;
        }
        int bytes = 0;
        if ((code = MPI_Get_count(&ms, MPI_CHAR, &bytes)) != MPI_SUCCESS || bytes < 1 || bytes > (1 << 20)) {
            st = code != MPI_SUCCESS ? rl_dist_mpi_failed(code, "receiving a property")
                                     : rl_error(RL_ERR_INTERNAL, "distributed run: a property of %d bytes", bytes);
            break;
        }
        char *t = realloc(text, (size_t)bytes);
        if (!t) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        text = t;
        if ((code = MPI_Recv(text, bytes, MPI_CHAR, 0, RL_DIST_TAG_SPEC, MPI_COMM_WORLD, MPI_STATUS_IGNORE)) !=
            MPI_SUCCESS) {
            st = rl_dist_mpi_failed(code, "receiving a property");
            break;
        }
        text[bytes - 1] = '\0';
        /* The property of this run: from the cache, or made now. */
        rl_property *p = NULL;
        char why[320] = "";
        int slot = -1, oldest = 0;
        for (int k = 0; k < SERVICE_CACHE; ++k) {
            if (cache[k].spec && strcmp(cache[k].spec, text) == 0)
                slot = k;
            if (cache[k].used < cache[oldest].used)
                oldest = k;
        }
        if (slot >= 0) {
            p = cache[slot].p;
            cache[slot].used = ++clock;
        } else if (text[0] == '\n') {
            snprintf(why, sizeof why, "%s", text + 1);        /* the master could not describe it */
        } else {
            char *spec = strdup(text);
            char *nl = strchr(text, '\n');
            rl_status pst = spec && nl ? RL_OK : RL_ERR_OUT_OF_MEMORY;
            if (pst == RL_OK) {
                *nl = '\0';
                pst = rl_property_create(text, &p);
            }
            for (char *line = nl ? nl + 1 : NULL; pst == RL_OK && line && *line;) {
                char *next = strchr(line, '\n'), *eq = strchr(line, '=');
                if (next)
                    *next = '\0';
                if (!eq) {
                    pst = rl_error(RL_ERR_INTERNAL, "distributed run: a malformed property from the master");
                    break;
                }
                *eq = '\0';
                pst = rl_property_set(p, line, eq + 1);
                line = next ? next + 1 : NULL;
            }
            if (pst == RL_OK)
                pst = rl_property_commit(p, scene, threads);
            if (pst != RL_OK) {
                snprintf(why, sizeof why, "rank %d: %s", d->rank, rl_last_error());
                rl_property_release(p);
                p = NULL;
                free(spec);
            } else {
                free(cache[oldest].spec);
                rl_property_release(cache[oldest].p);
                cache[oldest].spec = spec;
                cache[oldest].p = p;
                cache[oldest].used = ++clock;
            }
        }
        if ((st = serve(d, p, p ? NULL : why)) != RL_OK)
            break;
    }
    for (int k = 0; k < SERVICE_CACHE; ++k) {
        free(cache[k].spec);
        rl_property_release(cache[k].p);
    }
    free(text);
    return st;
}
