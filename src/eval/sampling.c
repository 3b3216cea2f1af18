/* sampling.c: global approximation of a position-dependent scene property by
 * sampling (Jähn 2015, Ch. 5).
 *
 * Regular sampling (Sec. 5.3, Alg. 5.2): one sample at the centre of each
 * cell of a res.x x res.y x res.z grid; res from the sample budget with cells
 * as close to cubes as possible.
 *
 * Adaptive sampling (Sec. 5.4, Alg. 5.3) with the thesis' parameters
 * (Sec. 5.4.2): the region of lowest quality q = n / (size * (max - min))
 * is split (in 2 along its longest side when longest / shortest > sqrt(2),
 * else into 4 or 8), no side below min_side (1 m); each new region gets
 * 5 + 0.05 / m * diameter samples; stop on the sample budget (default) or
 * the time budget. Two defaults deviate (rl_sampling.h): size is the
 * region's area or volume (the thesis: its diameter), and positions are
 * blue noise without the corners the thesis takes first.
 *
 * Parallel sampling (Sec. 5.5, Alg. 5.4): the new positions of all regions
 * of one split form a batch evaluated by the property's workers with
 * OpenMP; positions are chosen before, so results do not depend on the
 * worker count.
 *
 * In contrast to Alg. 5.3 the whole region is sampled first, before its
 * first split (see rl_sampling.h), and samples on region boundaries count
 * in every region whose closed box holds them, including neighbours outside
 * the split, whose quality is then updated in the queue. */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/sampling_internal.h"
#include "eval/sampling_journal.h"
#include "rl/rl_timer.h"

#define DEFAULT_MAX_SAMPLES 1024u
#define DEFAULT_MIN_SIDE 1.0f            /* m, Sec. 5.4.2 */
#define DEFAULT_SAMPLES_BASE 5.0f        /* Sec. 5.4.2 */
#define DEFAULT_SAMPLES_PER_METER 0.05f  /* Sec. 5.4.2 */
#define DEFAULT_CANDIDATES 200u          /* Sec. 5.4.2, blue noise */

/* ---- desc validation ---- */

static bool finite3(rl_vec3 v) { return isfinite(v.x) && isfinite(v.y) && isfinite(v.z); }

static rl_status resolve(rl_property *p, const rl_sampling_desc *in, rl_sampling_desc *d, int *workers)
{
    *d = *in;
    if (d->dims == 0)
        d->dims = 3;
    if (d->dims != 2 && d->dims != 3)
        return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: dims %d (expected 2 or 3)", in->dims);
    rl_aabb r = d->region;
    if (d->dims == 2) {
        if (!isfinite(d->height))
            return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: height is not finite");
        r.min.y = r.max.y = d->height;
    }
    if (!finite3(r.min) || !finite3(r.max))
        return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: region is not finite");
    for (int k = 0; k < rl_approx_axis_count(d->dims); ++k) {
        int ax = rl_approx_axis(d->dims, k);
        if (!(rl_v3_get(r.max, ax) > rl_v3_get(r.min, ax)))
            return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: region is empty or inverted along %c",
                            "xyz"[ax]);
    }
    d->region = r;
    if ((unsigned)d->method > RL_SAMPLING_GRID || (unsigned)d->positions > RL_POSITIONS_GRID ||
        (unsigned)d->combine > RL_COMBINE_MIN || (unsigned)d->interpolation > RL_INTERP_REGION ||
        (unsigned)d->quality_size > RL_QUALITY_DIAMETER)
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_sample_property: unknown method, positions, combine, interpolation or quality size");
    if (isnan(d->max_seconds) || d->max_seconds < 0.0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: max_seconds %g (expected >= 0)",
                        d->max_seconds);
    const struct { float v; const char *name; } nonneg[] = {
        { d->min_side, "min_side" }, { d->samples_base, "samples_base" },
        { d->samples_per_meter, "samples_per_meter" } };
    for (size_t i = 0; i < sizeof nonneg / sizeof nonneg[0]; ++i)
        if (!isfinite(nonneg[i].v) || nonneg[i].v < 0.0f)
            return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: %s %g (expected finite, >= 0)",
                            nonneg[i].name, (double)nonneg[i].v);
    if (d->max_samples > RL_SAMPLING_MAX_SAMPLES)
        return rl_error(RL_ERR_LIMIT, "rl_sample_property: max_samples %u above the limit %u",
                        d->max_samples, RL_SAMPLING_MAX_SAMPLES);
    if (d->candidates > RL_SAMPLING_MAX_CANDIDATES)
        return rl_error(RL_ERR_LIMIT, "rl_sample_property: candidates %u above the limit %u",
                        d->candidates, RL_SAMPLING_MAX_CANDIDATES);
    for (int ax = 0; ax < 3; ++ax)
        if (d->grid_res[ax] < 0)
            return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: grid_res[%d] = %d", ax, d->grid_res[ax]);
    if (d->max_samples == 0)
        d->max_samples = DEFAULT_MAX_SAMPLES;
    if (d->min_side == 0.0f)
        d->min_side = DEFAULT_MIN_SIDE;
    if (d->samples_base == 0.0f)
        d->samples_base = DEFAULT_SAMPLES_BASE;
    if (d->samples_per_meter == 0.0f)
        d->samples_per_meter = DEFAULT_SAMPLES_PER_METER;
    if (d->candidates == 0)
        d->candidates = DEFAULT_CANDIDATES;
    if (d->idw_neighbors > RL_SAMPLING_MAX_IDW_NEIGHBORS)
        return rl_error(RL_ERR_LIMIT, "rl_sample_property: idw_neighbors %u (at most %d)", d->idw_neighbors,
                        RL_SAMPLING_MAX_IDW_NEIGHBORS);
    if (d->idw_neighbors == 0)
        d->idw_neighbors = RL_SAMPLING_DEFAULT_IDW_NEIGHBORS;

    int committed = rl_property_workers(p);
    if (committed < 1)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_sample_property: property \"%s\" is not committed",
                        rl_property_name(p));
    if (d->workers < 0 || d->workers > committed)
        return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: workers %d (the property has %d)",
                        d->workers, committed);
    *workers = d->workers ? d->workers : committed;
    d->workers = *workers;
    return RL_OK;
}

/* ---- batch evaluation (Alg. 5.4, lines 11-16) ---- */

typedef struct batch {
    double *values;
    uint64_t *sets;
    uint32_t cap;
} batch;

static rl_status batch_reserve(batch *b, uint32_t n, size_t words)
{
    if (n <= b->cap)
        return RL_OK;
    uint32_t cap = b->cap ? b->cap : 64;
    while (cap < n)
        cap *= 2;
    double *v = rl_realloc_array(b->values, cap, sizeof *v);
    if (!v)
        return RL_ERR_OUT_OF_MEMORY;
    b->values = v;
    if (words) {
        if ((size_t)cap > SIZE_MAX / words)
            return rl_error(RL_ERR_LIMIT, "rl_sample_property: sets too large");
        uint64_t *s = rl_realloc_array(b->sets, (size_t)cap * words, sizeof *s);
        if (!s)
            return RL_ERR_OUT_OF_MEMORY;
        b->sets = s;
    }
    b->cap = cap;
    return RL_OK;
}

static rl_status evaluate_one(rl_property *p, int worker, rl_vec3 pos, double *value, uint64_t *set)
{
    rl_property_sample s = { .value = NAN, .set = set };
    rl_status st = rl_property_evaluate(p, worker, pos, &s);
    if (st == RL_OK)
        *value = s.value;
    return st;
}

/* Evaluates n positions into b. Every position is evaluated (or skipped
 * after a failure) independently of the others, so the values do not depend
 * on which worker took which position. On failure returns the status of the
 * lowest failing index seen, with the worker's message moved to this
 * thread. */
static rl_status evaluate_batch(const rl_sampling_desc *d, rl_property *p, int workers, bool exclusive,
                                const rl_vec3 *pos, uint32_t n, double *values, uint64_t *sets, size_t words)
{
    if (n == 0)
        return RL_OK;
    if (d && d->measure)        /* elsewhere: a distributed run's sampling nodes */
        return d->measure(d->measure_user, pos, n, values, words ? sets : NULL, words);
    if (exclusive || workers <= 1 || n == 1) {
        /* RL_PROPERTY_EXCLUSIVE (timings): one position at a time, since the
         * property itself uses all threads and concurrency would distort it. */
        for (uint32_t i = 0; i < n; ++i) {
            rl_status st = evaluate_one(p, 0, pos[i], &values[i], words ? sets + (size_t)i * words : NULL);
            if (st != RL_OK)
                return st;
        }
        return RL_OK;
    }
    uint32_t fail_index = UINT32_MAX;
    rl_status fail_status = RL_OK;
    char fail_message[1024] = "";
    bool message_here = false;
    int failed = 0;
#pragma omp parallel for num_threads(workers) schedule(dynamic, 1)
    for (uint32_t i = 0; i < n; ++i) {
        int skip;
#pragma omp atomic read
        skip = failed;
        if (skip)
            continue;
        int worker = omp_get_thread_num();
        bool caller = worker == 0;
        /* The caller's error state is the user's; worker threads' state is
         * ours, cleared so that a failure's message is its own. */
        if (!caller)
            rl_clear_error();
        rl_status st = evaluate_one(p, worker, pos[i], &values[i], words ? sets + (size_t)i * words : NULL);
        if (st != RL_OK) {
#pragma omp critical(rl_sampling_fail)
            {
                if (i < fail_index) {
                    fail_index = i;
                    fail_status = st;
                    message_here = caller;
                    if (!caller)
                        snprintf(fail_message, sizeof fail_message, "%s", rl_last_error());
                }
            }
#pragma omp atomic write
            failed = 1;
        }
    }
    if (fail_status == RL_OK)
        return RL_OK;
    if (!message_here)
        rl_error(fail_status, "%s", fail_message[0] ? fail_message : rl_status_string(fail_status));
    return fail_status;
}

rl_status rl_property_measure(rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                              rl_progress_fn progress, void *user)
{
    return rl_property_measure_sets(p, pos, count, values, NULL, progress, user);
}

rl_status rl_property_measure_sets(rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                                   uint64_t *sets, rl_progress_fn progress, void *user)
{
    if (!p || (count && (!pos || !values)))
        return rl_error(RL_ERR_INVALID_ARG, "rl_property_measure: property, positions and values must not be NULL");
    int workers = rl_property_workers(p);
    if (workers < 1)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_property_measure: property \"%s\" is not committed",
                        rl_property_name(p));
    bool exclusive = rl_property_get_flags(p) & RL_PROPERTY_EXCLUSIVE;
    /* Batches of a few positions per worker: progress between them, on the
     * calling thread; exclusive properties one position at a time. */
    size_t chunk = exclusive || workers <= 1 ? 1 : (size_t)workers * 8;
    for (size_t i = 0; i < count;) {
        uint32_t n = (uint32_t)(count - i < chunk ? count - i : chunk);
        size_t words = sets ? rl_property_set_words(p) : 0;
        rl_status st = evaluate_batch(NULL, p, workers, exclusive, pos + i, n, values + i,
                                      words ? sets + i * words : NULL, words);
        if (st != RL_OK)
            return st;
        i += n;
        if (progress && !progress(user, (double)i / (double)count))
            return rl_error(RL_ERR_CANCELLED, "rl_property_measure: cancelled after %zu of %zu positions", i, count);
    }
    return RL_OK;
}

/* ---- regular sampling (Sec. 5.3, Alg. 5.2) ---- */

static double grid_cells(const double ext[3], int axes, double s, int res[3])
{
    double prod = 1.0;
    for (int k = 0; k < axes; ++k) {
        double r = floor(ext[k] / s);
        r = r < 1.0 ? 1.0 : r > (double)RL_SAMPLING_MAX_SAMPLES ? (double)RL_SAMPLING_MAX_SAMPLES + 1.0 : r;
        res[k] = (int)r;
        prod *= r;
    }
    return prod;
}

/* The largest grid of near-cubic cells with at most n cells: the smallest
 * cell size s whose floor(extent / s) counts fit, then one more cell along
 * the axes with the longest cells while the product still fits. */
static void grid_auto(const rl_sampling_desc *d, int out[3])
{
    int axes = rl_approx_axis_count(d->dims);
    double ext[3], n = d->max_samples, hi = 0.0, lo = 0.0;
    for (int k = 0; k < axes; ++k) {
        int ax = rl_approx_axis(d->dims, k);
        ext[k] = (double)rl_v3_get(d->region.max, ax) - rl_v3_get(d->region.min, ax);
        hi = fmax(hi, ext[k]);
    }
    int res[3] = { 1, 1, 1 };
    for (int it = 0; it < 200; ++it) {
        double mid = 0.5 * (lo + hi);
        if (mid <= lo || mid >= hi)
            break;
        if (grid_cells(ext, axes, mid, res) <= n)
            hi = mid;
        else
            lo = mid;
    }
    grid_cells(ext, axes, hi, res);
    for (;;) {
        double prod = 1.0;
        for (int k = 0; k < axes; ++k)
            prod *= res[k];
        int best = -1;
        for (int k = 0; k < axes; ++k)
            if (prod / res[k] * (res[k] + 1) <= n && (best < 0 || ext[k] / res[k] > ext[best] / res[best]))
                best = k;
        if (best < 0)
            break;
        ++res[best];
    }
    out[0] = out[1] = out[2] = 1;
    for (int k = 0; k < axes; ++k)
        out[rl_approx_axis(d->dims, k)] = res[k];
}

static rl_status progress(const rl_sampling_desc *d, uint32_t samples)
{
    if (d->progress && !d->progress(d->progress_user, (double)samples / (double)d->max_samples))
        return rl_error(RL_ERR_CANCELLED, "rl_sample_property: cancelled by the progress callback");
    return RL_OK;
}

static bool out_of_time(const rl_sampling_desc *d, double t0)
{
    return d->max_seconds > 0.0 && rl_time_s() - t0 >= d->max_seconds;
}

static rl_status run_grid(rl_property *p, const rl_sampling_desc *d, int workers, double t0, rl_approx *a)
{
    int res[3];
    if (d->grid_res[0] == 0 && d->grid_res[2] == 0 && (d->dims == 2 || d->grid_res[1] == 0)) {
        grid_auto(d, res);
    } else {
        for (int ax = 0; ax < 3; ++ax) {
            res[ax] = d->dims == 2 && ax == 1 ? 1 : d->grid_res[ax];
            if (res[ax] < 1)
                return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: grid_res[%d] = 0 beside non-zero ones", ax);
        }
        if ((double)res[0] * res[1] * res[2] > (double)RL_SAMPLING_MAX_SAMPLES)
            return rl_error(RL_ERR_LIMIT, "rl_sample_property: grid %d x %d x %d above the limit %u", res[0],
                            res[1], res[2], RL_SAMPLING_MAX_SAMPLES);
    }
    if (rl_approx_add_node(a, a->bounds, RL_APPROX_NONE, 0) == RL_APPROX_NONE ||
        rl_approx_split(a, 0, RL_NODE_GRID, 0, res) == RL_APPROX_NONE)
        return rl_last_status() != RL_OK ? rl_last_status() : RL_ERR_OUT_OF_MEMORY;
    uint32_t cells = (uint32_t)res[0] * (uint32_t)res[1] * (uint32_t)res[2];
    uint32_t nodes = a->node_count;
    uint32_t *counts = rl_calloc(nodes, sizeof *counts);
    uint32_t **lists = rl_calloc(nodes, sizeof *lists);
    uint32_t *ids = rl_calloc(cells, sizeof *ids);
    rl_vec3 *pos = rl_calloc(cells, sizeof *pos);
    batch b = { 0 };
    rl_status st = counts && lists && ids && pos ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    /* Alg. 5.2: the cell centres; or one random offset for every cell (a
     * shifted lattice, Cranley & Patterson 1976), which keeps the lattice's
     * even cover but not its fixed alignment with the scene. */
    float shift[3] = { 0.0f, 0.0f, 0.0f };
    if (d->grid_shift) {
        rl_rng rng;
        rl_rng_seed(&rng, d->seed, 0x9a1d5f7u);
        for (int ax = 0; ax < 3; ++ax)
            shift[ax] = rl_rng_float(&rng);
    }
    for (uint32_t c = 0; c < cells && st == RL_OK; ++c) {
        rl_aabb box = a->nodes[1 + c].box;
        if (!d->grid_shift) {
            pos[c] = (rl_vec3){ rl_split_mid(box.min.x, box.max.x), rl_split_mid(box.min.y, box.max.y),
                                rl_split_mid(box.min.z, box.max.z) };
            continue;
        }
        for (int ax = 0; ax < 3; ++ax) {
            float lo = rl_v3_get(box.min, ax), hi = rl_v3_get(box.max, ax);
            float x = lo + (hi - lo) * shift[ax];
            rl_v3_set(&pos[c], ax, x < hi ? x : hi);
        }
    }
    /* Batches of a few positions per worker keep the time budget and the
     * progress callback responsive. */
    uint32_t per_batch = (uint32_t)workers * 8u;
    bool exclusive = rl_property_get_flags(p) & RL_PROPERTY_EXCLUSIVE;
    for (uint32_t c0 = 0; c0 < cells && st == RL_OK;) {
        uint32_t n = cells - c0 < per_batch ? cells - c0 : per_batch;
        st = batch_reserve(&b, n, a->set_words);
        if (st == RL_OK)
            st = evaluate_batch(d, p, workers, exclusive, pos + c0, n, b.values, b.sets, a->set_words);
        for (uint32_t i = 0; i < n && st == RL_OK; ++i) {
            uint32_t s = rl_approx_add_sample(a, pos[c0 + i], b.values[i],
                                              a->set_words ? b.sets + (size_t)i * a->set_words : NULL);
            if (s == RL_APPROX_NONE) {
                st = RL_ERR_OUT_OF_MEMORY;
                break;
            }
            ids[c0 + i] = s;
            lists[1 + c0 + i] = &ids[c0 + i];
            counts[1 + c0 + i] = 1;
        }
        c0 += n;
        if (st == RL_OK)
            st = progress(d, a->sample_count);
        if (st == RL_OK && out_of_time(d, t0))
            break;
    }
    if (st == RL_OK)
        st = rl_approx_finish(a, lists, counts, d->combine, d->linear);
    free(counts);
    free(lists);
    free(ids);
    free(pos);
    free(b.values);
    free(b.sets);
    return st;
}

/* ---- adaptive sampling (Sec. 5.4, Alg. 5.3) ---- */

typedef struct node_state {
    double vmin, vmax;         /* of the samples in the closed box */
    uint32_t version;          /* queue entries with another version are stale */
    bool splittable;
} node_state;

typedef struct queue_entry {
    double q;
    uint32_t node, version;
} queue_entry;

typedef struct queue {
    queue_entry *e;
    uint32_t n, cap;
} queue;

/* Alg. 5.3, line 9: lowest quality first; ties go to the region created
 * first, so runs are reproducible. */
static bool before(queue_entry a, queue_entry b) { return a.q < b.q || (a.q == b.q && a.node < b.node); }

static bool queue_push(queue *h, queue_entry x)
{
    if (h->n == h->cap) {
        uint32_t cap = h->cap ? h->cap * 2 : 256;
        queue_entry *e = rl_realloc_array(h->e, cap, sizeof *e);
        if (!e)
            return false;
        h->e = e;
        h->cap = cap;
    }
    uint32_t i = h->n++;
    while (i > 0 && before(x, h->e[(i - 1) / 2])) {
        h->e[i] = h->e[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    h->e[i] = x;
    return true;
}

static queue_entry queue_pop(queue *h)
{
    queue_entry top = h->e[0], x = h->e[--h->n];
    uint32_t i = 0;
    for (;;) {
        uint32_t c = 2 * i + 1;
        if (c >= h->n)
            break;
        if (c + 1 < h->n && before(h->e[c + 1], h->e[c]))
            ++c;
        if (!before(h->e[c], x))
            break;
        h->e[i] = h->e[c];
        i = c;
    }
    if (h->n)
        h->e[i] = x;
    return top;
}

typedef struct adaptive {
    rl_sampler s;
    node_state *ns;
    queue q;
    batch b;
    uint32_t *touched;
    uint32_t touched_n, touched_cap;
} adaptive;

static rl_status grow_nodes(adaptive *ad)
{
    uint32_t need = ad->s.a->node_count;
    if (need <= ad->s.lists_cap)
        return RL_OK;
    uint32_t cap = ad->s.lists_cap ? ad->s.lists_cap : 64;
    while (cap < need)
        cap *= 2;
    rl_idx_list *l = rl_realloc_array(ad->s.lists, cap, sizeof *l);
    if (!l)
        return RL_ERR_OUT_OF_MEMORY;
    ad->s.lists = l;
    node_state *ns = rl_realloc_array(ad->ns, cap, sizeof *ns);
    if (!ns)
        return RL_ERR_OUT_OF_MEMORY;
    ad->ns = ns;
    memset(l + ad->s.lists_cap, 0, (cap - ad->s.lists_cap) * sizeof *l);
    memset(ns + ad->s.lists_cap, 0, (cap - ad->s.lists_cap) * sizeof *ns);
    ad->s.lists_cap = cap;
    return RL_OK;
}

static bool list_push(rl_idx_list *l, uint32_t v)
{
    if (l->n == l->cap) {
        uint32_t cap = l->cap ? l->cap * 2 : 8;
        uint32_t *p = rl_realloc_array(l->v, cap, sizeof *p);
        if (!p)
            return false;
        l->v = p;
        l->cap = cap;
    }
    l->v[l->n++] = v;
    return true;
}

/* Sec. 5.4.2, "Regionsunterteilungsfunktion": in 2 along the longest side
 * when longest / shortest > sqrt(2), else along all axes; no split when a
 * side would fall below min_side (or the midpoint is not representable). */
static bool plan_split(const rl_approx *a, const rl_sampling_desc *d, uint32_t node, rl_approx_node_kind *kind,
                       int *axis)
{
    rl_aabb b = a->nodes[node].box;
    int axes = rl_approx_axis_count(a->dims), longest = -1;
    double lmax = 0.0, lmin = INFINITY;
    for (int k = 0; k < axes; ++k) {
        int ax = rl_approx_axis(a->dims, k);
        double e = (double)rl_v3_get(b.max, ax) - rl_v3_get(b.min, ax);
        if (e > lmax) {
            lmax = e;
            longest = ax;
        }
        lmin = fmin(lmin, e);
    }
    bool two = lmax > sqrt(2.0) * lmin;
    *kind = two ? RL_NODE_SPLIT2 : RL_NODE_SPLIT_ALL;
    *axis = two ? longest : 0;
    for (int k = 0; k < axes; ++k) {
        int ax = rl_approx_axis(a->dims, k);
        float lo = rl_v3_get(b.min, ax), hi = rl_v3_get(b.max, ax);
        if (two && ax != longest) {
            if ((double)hi - lo < d->min_side)
                return false;
            continue;
        }
        float mid = rl_split_mid(lo, hi);
        if (!(mid > lo && mid < hi) || (double)mid - lo < d->min_side || (double)hi - mid < d->min_side)
            return false;
    }
    return true;
}

static rl_status push_region(adaptive *ad, uint32_t node)
{
    const rl_approx *a = ad->s.a;
    node_state *st = &ad->ns[node];
    if (!st->splittable)
        return RL_OK;
    double size = rl_sampling_size(a->dims, ad->s.d.quality_size, a->nodes[node].box);
    double q = rl_sampling_quality(ad->s.lists[node].n, size, st->vmin, st->vmax);
    if (!queue_push(&ad->q, (queue_entry){ q, node, ++st->version }))
        return RL_ERR_OUT_OF_MEMORY;
    return RL_OK;
}

static void new_region_state(adaptive *ad, uint32_t node)
{
    rl_approx_node_kind kind;
    int axis;
    ad->ns[node] = (node_state){ .vmin = INFINITY, .vmax = -INFINITY,
                                 .splittable = plan_split(ad->s.a, &ad->s.d, node, &kind, &axis) };
}

/* Adds the batch's samples to the approximation and to every leaf whose
 * closed box holds them (Alg. 5.3, line 16), remembering the leaves whose
 * quality changed. */
static rl_status commit_batch(adaptive *ad)
{
    rl_sampler *s = &ad->s;
    rl_approx *a = s->a;
    ad->touched_n = 0;
    for (uint32_t i = 0; i < s->pending_count; ++i) {
        rl_vec3 p = s->pending[i];
        double v = ad->b.values[i];
        uint32_t id = rl_approx_add_sample(a, p, v, a->set_words ? ad->b.sets + (size_t)i * a->set_words : NULL);
        if (id == RL_APPROX_NONE)
            return RL_ERR_OUT_OF_MEMORY;
        uint32_t top = 0;
        s->stack[top++] = 0;
        while (top) {
            uint32_t n = s->stack[--top];
            const rl_approx_node *nd = &a->nodes[n];
            if (!rl_box_holds(nd->box, p))
                continue;
            if (nd->kind == RL_NODE_LEAF) {
                if (!list_push(&s->lists[n], id))
                    return RL_ERR_OUT_OF_MEMORY;
                ad->ns[n].vmin = fmin(ad->ns[n].vmin, v);
                ad->ns[n].vmax = fmax(ad->ns[n].vmax, v);
                bool seen = false;
                for (uint32_t t = 0; t < ad->touched_n && !seen; ++t)
                    seen = ad->touched[t] == n;
                if (!seen) {
                    if (ad->touched_n == ad->touched_cap) {
                        uint32_t cap = ad->touched_cap ? ad->touched_cap * 2 : 32;
                        uint32_t *t = rl_realloc_array(ad->touched, cap, sizeof *t);
                        if (!t)
                            return RL_ERR_OUT_OF_MEMORY;
                        ad->touched = t;
                        ad->touched_cap = cap;
                    }
                    ad->touched[ad->touched_n++] = n;
                }
                continue;
            }
            uint32_t count = rl_approx_child_count(a, nd);
            if (top + count > s->stack_cap) {
                uint32_t cap = s->stack_cap ? s->stack_cap : 64;
                while (cap < top + count)
                    cap *= 2;
                uint32_t *st = rl_realloc_array(s->stack, cap, sizeof *st);
                if (!st)
                    return RL_ERR_OUT_OF_MEMORY;
                s->stack = st;
                s->stack_cap = cap;
            }
            for (uint32_t c = count; c-- > 0;)
                s->stack[top++] = nd->first_child + c;
        }
    }
    return RL_OK;
}

static rl_status evaluate_pending(adaptive *ad, rl_property *p, int workers, bool exclusive)
{
    rl_status st = batch_reserve(&ad->b, ad->s.pending_count, ad->s.a->set_words);
    if (st == RL_OK)
        st = evaluate_batch(&ad->s.d, p, workers, exclusive, ad->s.pending, ad->s.pending_count, ad->b.values,
                            ad->b.sets, ad->s.a->set_words);
    if (st == RL_OK)
        st = commit_batch(ad);
    return st;
}

/* Sec. 5.4.2: samples_base + samples_per_meter * diameter, rounded up. */
static uint32_t region_target(const rl_sampling_desc *d, rl_aabb box)
{
    double t = ceil((double)d->samples_base + (double)d->samples_per_meter * rl_box_diameter(box));
    return t >= (double)RL_SAMPLING_MAX_SAMPLES ? RL_SAMPLING_MAX_SAMPLES : (uint32_t)t;
}

static rl_status run_adaptive(rl_property *p, const rl_sampling_desc *d, int workers, double t0, rl_approx *a)
{
    adaptive ad = { .s = { .a = a, .d = *d } };
    rl_rng_seed(&ad.s.rng, d->seed, 0x5a3b1e5u);
    bool exclusive = rl_property_get_flags(p) & RL_PROPERTY_EXCLUSIVE;
    /* Regions that take no new sample can still be split; this cap on the
     * tree keeps a degenerate parameter choice from splitting forever. */
    uint64_t max_nodes = 64u * (uint64_t)d->max_samples + 1024u;
    rl_status st = RL_OK;
    if (rl_approx_add_node(a, a->bounds, RL_APPROX_NONE, 0) == RL_APPROX_NONE)
        st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        st = grow_nodes(&ad);
    if (st == RL_OK && !(ad.s.stack = rl_calloc(64, sizeof *ad.s.stack)))
        st = RL_ERR_OUT_OF_MEMORY;
    ad.s.stack_cap = ad.s.stack ? 64 : 0;
    if (st == RL_OK) {
        new_region_state(&ad, 0);
        if (rl_sampling_choose(&ad.s, 0, region_target(d, a->bounds), d->max_samples) == RL_APPROX_NONE)
            st = RL_ERR_OUT_OF_MEMORY;
    }
    if (st == RL_OK)
        st = evaluate_pending(&ad, p, workers, exclusive);
    if (st == RL_OK)
        st = push_region(&ad, 0);
    if (st == RL_OK)
        st = progress(d, a->sample_count);
    while (st == RL_OK && a->sample_count < d->max_samples && ad.q.n > 0 && a->node_count < max_nodes &&
           !out_of_time(d, t0)) {
        /* Alg. 5.3, line 9: the region of lowest quality. */
        queue_entry e = queue_pop(&ad.q);
        if (a->nodes[e.node].kind != RL_NODE_LEAF || e.version != ad.ns[e.node].version)
            continue;
        rl_approx_node_kind kind;
        int axis;
        plan_split(a, d, e.node, &kind, &axis);
        /* Alg. 5.3, line 10 */
        uint32_t first = rl_approx_split(a, e.node, kind, axis, NULL);
        if (first == RL_APPROX_NONE || (st = grow_nodes(&ad)) != RL_OK) {
            st = st != RL_OK ? st : rl_last_status() != RL_OK ? rl_last_status() : RL_ERR_OUT_OF_MEMORY;
            break;
        }
        uint32_t count = rl_approx_child_count(a, &a->nodes[e.node]);
        rl_idx_list *parent = &ad.s.lists[e.node];
        for (uint32_t c = first; c < first + count && st == RL_OK; ++c) {
            new_region_state(&ad, c);
            for (uint32_t k = 0; k < parent->n; ++k) {
                uint32_t id = parent->v[k];
                if (!rl_box_holds(a->nodes[c].box, a->sample_pos[id]))
                    continue;
                if (!list_push(&ad.s.lists[c], id)) {
                    st = RL_ERR_OUT_OF_MEMORY;
                    break;
                }
                ad.ns[c].vmin = fmin(ad.ns[c].vmin, a->sample_value[id]);
                ad.ns[c].vmax = fmax(ad.ns[c].vmax, a->sample_value[id]);
            }
        }
        parent = &ad.s.lists[e.node];
        free(parent->v);
        *parent = (rl_idx_list){ 0 };
        /* Alg. 5.4, lines 6-10: all new positions first, region by region
         * in order, cut to the budget left. */
        ad.s.pending_count = 0;
        uint32_t left = d->max_samples - a->sample_count;
        for (uint32_t c = first; c < first + count && st == RL_OK; ++c) {
            uint32_t target = region_target(d, a->nodes[c].box), held = rl_sampling_held(&ad.s, c);
            uint32_t need = target > held ? target - held : 0;
            if (need && rl_sampling_choose(&ad.s, c, need, left - ad.s.pending_count) == RL_APPROX_NONE)
                st = RL_ERR_OUT_OF_MEMORY;
        }
        if (st == RL_OK)
            st = evaluate_pending(&ad, p, workers, exclusive);
        /* Alg. 5.4, lines 17-19, and the neighbours whose boundary got a
         * sample. */
        for (uint32_t c = first; c < first + count && st == RL_OK; ++c)
            st = push_region(&ad, c);
        for (uint32_t t = 0; t < ad.touched_n && st == RL_OK; ++t)
            if (ad.touched[t] < first || ad.touched[t] >= first + count)
                st = push_region(&ad, ad.touched[t]);
        if (st == RL_OK && ad.s.pending_count)
            st = progress(d, a->sample_count);
    }
    if (st == RL_OK) {
        uint32_t **lists = rl_calloc(a->node_count, sizeof *lists);
        uint32_t *counts = rl_calloc(a->node_count, sizeof *counts);
        if (lists && counts) {
            for (uint32_t i = 0; i < a->node_count; ++i) {
                lists[i] = ad.s.lists[i].v;
                counts[i] = ad.s.lists[i].n;
            }
            st = rl_approx_finish(a, lists, counts, d->combine, d->linear);
        } else {
            st = RL_ERR_OUT_OF_MEMORY;
        }
        free(lists);
        free(counts);
    }
    for (uint32_t i = 0; i < ad.s.lists_cap; ++i)
        free(ad.s.lists[i].v);
    free(ad.s.lists);
    free(ad.ns);
    free(ad.s.pending);
    free(ad.s.stack);
    free(ad.q.e);
    free(ad.b.values);
    free(ad.b.sets);
    free(ad.touched);
    return st;
}

/* The checkpoint (rl_sampling_desc.checkpoint) sits between the sampler
 * and whatever measures its batches: recorded batches are replayed, the
 * others measured (by the property's workers or desc.measure) and
 * recorded. */
typedef struct journaled {
    rl_journal *j;
    rl_sampling_desc inner;             /* the run's desc with its own measure */
    rl_property *p;
    int workers;
    bool exclusive, told;
} journaled;

static rl_status journaled_measure(void *user, const rl_vec3 *pos, uint32_t n, double *values, uint64_t *sets,
                                   size_t words)
{
    journaled *jm = user;
    bool hit = false;
    rl_status st = rl_journal_replay(jm->j, pos, n, values, sets, words, &hit);
    if (st != RL_OK || hit)
        return st;
    if (!jm->told && rl_journal_replayed(jm->j) > 0)
        rl_info("checkpoint %s: %llu samples replayed; measuring on from there", jm->inner.checkpoint,
                (unsigned long long)rl_journal_replayed(jm->j));
    jm->told = true;
    st = evaluate_batch(&jm->inner, jm->p, jm->workers, jm->exclusive, pos, n, values, sets, words);
    return st == RL_OK ? rl_journal_append(jm->j, pos, n, values, sets, words) : st;
}

/* What a checkpoint must agree on beside its positions: the property and
 * its options (a value depends on them, not only on its position), the
 * set size and the sampling settings, and the caller's key. */
static char *checkpoint_key(const rl_property *p, const rl_sampling_desc *d)
{
    size_t cap = 1024, len = 0;
    char *k = malloc(cap);
    if (!k)
        return NULL;
#define KEY_ADD(...)                                                                                             \
    do {                                                                                                         \
        int m_ = snprintf(k + len, cap - len, __VA_ARGS__);                                                      \
        if (m_ < 0) {                                                                                            \
            free(k);                                                                                             \
            return NULL;                                                                                         \
        }                                                                                                        \
        if ((size_t)m_ >= cap - len) {                                                                           \
            size_t c_ = 2 * cap + (size_t)m_;                                                                    \
            char *b_ = realloc(k, c_);                                                                           \
            if (!b_) {                                                                                           \
                free(k);                                                                                         \
                return NULL;                                                                                     \
            }                                                                                                    \
            k = b_;                                                                                              \
            cap = c_;                                                                                            \
            m_ = snprintf(k + len, cap - len, __VA_ARGS__);                                                      \
        }                                                                                                        \
        len += (size_t)m_;                                                                                       \
    } while (0)
    KEY_ADD("renderlab sampling checkpoint\nproperty %s\n", rl_property_name(p));
    size_t n = 0;
    const rl_option_info *opts = rl_property_options(p, &n);
    for (size_t i = 0; i < n; ++i) {
        const char *v = rl_property_get(p, opts[i].key);
        KEY_ADD("option %s=%s\n", opts[i].key, v ? v : "");
    }
    KEY_ADD("set_size %u\nmethod %d positions %d dims %d height %.9g samples %u seconds %.17g seed %llu\n",
            rl_property_set_size(p), (int)d->method, (int)d->positions, d->dims, (double)d->height,
            d->max_samples, d->max_seconds, (unsigned long long)d->seed);
    KEY_ADD("region %.9g %.9g %.9g %.9g %.9g %.9g\n", (double)d->region.min.x, (double)d->region.min.y,
            (double)d->region.min.z, (double)d->region.max.x, (double)d->region.max.y, (double)d->region.max.z);
    KEY_ADD("user %s\n", d->checkpoint_key ? d->checkpoint_key : "");
#undef KEY_ADD
    return k;
}

rl_status rl_sample_property(rl_property *p, const rl_sampling_desc *desc, rl_approx **out)
{
    if (!p || !desc || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_sample_property: property, desc or out is NULL");
    rl_sampling_desc d;
    int workers = 0;
    rl_status st = resolve(p, desc, &d, &workers);
    if (st != RL_OK)
        return st;
    double t0 = rl_time_s();
    rl_approx *a = NULL;
    st = rl_approx_alloc(d.dims, d.height, d.region, rl_property_name(p), rl_property_unit(p),
                         rl_property_set_size(p), &a);
    if (st != RL_OK)
        return st;
    journaled jm = { .inner = d, .p = p, .workers = workers,
                     .exclusive = (rl_property_get_flags(p) & RL_PROPERTY_EXCLUSIVE) != 0 };
    rl_sampling_desc run = d;
    if (d.checkpoint) {
        char *key = checkpoint_key(p, &d);
        st = key ? rl_journal_open(d.checkpoint, key, &jm.j) : RL_ERR_OUT_OF_MEMORY;
        free(key);
        if (st != RL_OK) {
            rl_approx_release(a);
            return st;
        }
        run.measure = journaled_measure;
        run.measure_user = &jm;
    }
    st = d.method == RL_SAMPLING_GRID ? run_grid(p, &run, workers, t0, a) : run_adaptive(p, &run, workers, t0, a);
    if (st == RL_OK && jm.j && !jm.told)
        rl_info("checkpoint %s: all %llu samples replayed", d.checkpoint,
                (unsigned long long)rl_journal_replayed(jm.j));
    rl_journal_close(jm.j);
    if (st != RL_OK) {
        rl_approx_release(a);
        return st;
    }
    a->desc = d;
    a->desc.progress = NULL;
    a->desc.progress_user = NULL;
    a->desc.measure = NULL;
    a->desc.measure_user = NULL;
    a->desc.checkpoint = NULL;
    a->desc.checkpoint_key = NULL;
    a->seconds = rl_time_s() - t0;
    *out = a;
    return RL_OK;
}
