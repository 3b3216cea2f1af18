/* raster_draw.c: one triangle draw or occlusion query: validate, transform,
 * then per slab setup + binning (chunks in parallel) and fill (bands in
 * parallel). See raster_internal.h for why the result does not depend on the
 * thread count.
 *
 * An occlusion query counts what a draw with RL_RASTER_NO_DEPTH would write:
 * like a GPU query with depth writes off, fragments of the batch do not
 * occlude each other. For a batch without self-overlap that equals the
 * pixels_written of a normal draw.
 *
 * A layered batch (num_layers > 0) is validated here once, so that the fill
 * can read layer colours without checks; its prims get side records (see
 * rl_raster_prim_src) and the fill reads the layers from the batch.
 *
 * rl_raster_draw_many groups consecutive small batches: one draw of a few
 * hundred triangles is too small to split, so a scene of many small objects
 * drawn one by one would run on one thread. A group is cut into contiguous
 * runs of batches, one per thread, each transformed and set up into its own
 * chunk; the bands then walk the chunks in order, so every pixel still sees
 * the triangles in submission order, as the draws one by one would. */
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/error.h"
#include "raster/raster_internal.h"

/* Below these sizes a parallel region costs more than it saves. */
#define PARALLEL_VERTICES 8192
#define PARALLEL_TRIANGLES 2048
#define PARALLEL_PIXELS 16384

/* A group of rl_raster_draw_many holds at most this many vertices (bounded
 * scratch), and batches of at least PARALLEL_TRIANGLES are drawn alone: their
 * own setup already runs on every thread. */
#define GROUP_VERTICES (1u << 18)

/* A group is set up in this many chunks per thread, taken in turn by
 * whichever thread is free: the cost of a batch varies a lot (one lies
 * beyond the viewport and is rejected at once, the next covers it with
 * many pixels), so one equal share of the triangles per thread left one
 * thread waiting for the other most of the time. The fill walks the
 * chunks in order, so their number changes nothing in the image. */
#define CHUNKS_PER_THREAD 4

/* Writes a batch's problem to msg; every problem is an invalid argument. */
static rl_status RL_PRINTF(3, 4) problem(char *msg, size_t size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, size, fmt, ap);
    va_end(ap);
    return RL_ERR_INVALID_ARG;
}

/* Why batch b cannot be drawn, as status and message (no function name, so
 * that each caller can say where), or RL_OK. Messages are formatted only on
 * failure: rl_raster_draw_many checks thousands of batches per frame. */
static rl_status batch_problem(const rl_raster *r, const rl_raster_batch *b, char *msg, size_t size)
{
    if (!r || !b)
        return problem(msg, size, "NULL argument");
    if (!r->target)
        return problem(msg, size, "no render target set");
    if (b->num_layers > RL_RASTER_MAX_LAYERS)
        return problem(msg, size, "%u layers (at most %d)", b->num_layers, RL_RASTER_MAX_LAYERS);
    if (b->num_layers > 0 && !b->layers)
        return problem(msg, size, "%u layers but layers is NULL", b->num_layers);
    for (uint32_t i = 0; i < b->num_layers; ++i)
        if (!b->layers[i].colors)
            return problem(msg, size, "layer %u has no colors", i);
    if (b->lazy && (!b->lazy->shade || !b->lazy->stamps || b->lazy->frame < 1 ||
                    b->lazy->frame >= (1u << 31)))
        return problem(msg, size, "lazy colours need shade, stamps and 1 <= frame < 2^31 (frame %u)",
                       b->lazy->frame);
    if (b->mask_texture && (!b->uvs || !b->textures || !b->mask_cutoff))
        return problem(msg, size, "alpha masks need uvs, textures and mask_cutoff");
    if (b->num_triangles == 0)
        return RL_OK;
    if (!b->indices || !b->positions)
        return problem(msg, size, "%u triangles without indices or positions", b->num_triangles);
    /* One pass, OR-free max: cheap next to the setup that follows. */
    const size_t n = 3 * (size_t)b->num_triangles;
    uint32_t max_index = 0;
    for (size_t i = 0; i < n; ++i)
        max_index = b->indices[i] > max_index ? b->indices[i] : max_index;
    if (max_index >= b->num_vertices)
        return problem(msg, size, "index %u out of range (%u vertices)", max_index, b->num_vertices);
    return RL_OK;
}

static rl_status check_batch(const rl_raster *r, const rl_raster_batch *b, const char *fn)
{
    char msg[160];
    rl_status st = batch_problem(r, b, msg, sizeof msg);
    return st == RL_OK ? RL_OK : rl_error(st, "%s: %s", fn, msg);
}

static inline void transform_vertex(const rl_raster *r, const rl_vec3 *positions, uint32_t i,
                                    rl_vec4 *clip, float *eye_depth)
{
    rl_vec3 p = positions[i];
    clip[i] = rl_raster_xform(&r->view_proj, p);
    if (eye_depth) {
        const rl_vec4 vz = r->view_z;
        eye_depth[i] = -(vz.x * p.x + vz.y * p.y + vz.z * p.z + vz.w);
    }
}

/* Makes r->clip (and r->eye_depth for affine projections) hold n vertices. */
static rl_status reserve_vertices(rl_raster *r, size_t n)
{
    if (!rl_reserve((void **)&r->clip, &r->vert_cap, n, sizeof *r->clip, 64))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster: %zu vertices", n);
    if (!r->perspective &&
        !rl_reserve((void **)&r->eye_depth, &r->eye_depth_cap, n, sizeof *r->eye_depth, 64))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster: %zu vertices", n);
    return RL_OK;
}

static rl_status transform(rl_raster *r, const rl_vec3 *positions, uint32_t n, int threads)
{
    rl_status st = reserve_vertices(r, n);
    if (st != RL_OK)
        return st;
    rl_vec4 *clip = r->clip;
    float *eye_depth = r->perspective ? NULL : r->eye_depth;
    if (n < PARALLEL_VERTICES || threads < 2) {
        for (uint32_t i = 0; i < n; ++i)
            transform_vertex(r, positions, i, clip, eye_depth);
    } else {
        #pragma omp parallel for num_threads(threads) schedule(static)
        for (int64_t i = 0; i < (int64_t)n; ++i)
            transform_vertex(r, positions, (uint32_t)i, clip, eye_depth);
    }
    return RL_OK;
}

/* Fills one band from all chunks, in submission order. */
static uint64_t fill_band(const rl_raster *r, const rl_raster_target *t, int num_chunks, int band)
{
    const int row0 = band * RL_RASTER_BAND_ROWS, row1 = row0 + RL_RASTER_BAND_ROWS;
    uint64_t passed = 0;
    for (int c = 0; c < num_chunks; ++c) {
        const rl_raster_chunk *ch = &r->chunks[c];
        for (uint32_t k = ch->bins.off[band]; k < ch->bins.off[band + 1]; ++k) {
            const uint32_t i = ch->bins.idx[k];
            passed += rl_raster_fill_prim(t, &ch->prims[i], t->layered ? &ch->srcs[i] : NULL,
                                          row0, row1);
        }
    }
    return passed;
}

/* Fills the bands of all chunks; returns the fragments that passed. */
static uint64_t fill_bands(const rl_raster *r, const rl_raster_target *t, int num_chunks,
                           int threads)
{
    const int num_bands = rl_raster_num_bands(t->height);
    /* Bounding-box pixels, counted only up to the threshold: tiny draws
     * (most objects of a large scene) stay serial. */
    uint64_t estimate = 0;
    for (int c = 0; c < num_chunks && estimate < PARALLEL_PIXELS; ++c) {
        const rl_raster_chunk *ch = &r->chunks[c];
        for (size_t i = 0; i < ch->num_prims && estimate < PARALLEL_PIXELS; ++i) {
            const rl_raster_prim *p = &ch->prims[i];
            estimate += (uint64_t)(p->x1 - p->x0) * (uint64_t)(p->y1 - p->y0);
        }
    }
    uint64_t passed = 0;
    if (estimate < PARALLEL_PIXELS || threads < 2) {
        /* Not even an idle parallel region: per-draw overhead matters. */
        for (int band = 0; band < num_bands; ++band)
            passed += fill_band(r, t, num_chunks, band);
        return passed;
    }
    #pragma omp parallel for num_threads(threads) schedule(dynamic) reduction(+ : passed)
    for (int band = 0; band < num_bands; ++band)
        passed += fill_band(r, t, num_chunks, band);
    return passed;
}

/* Sets up and bins chunk c of num_chunks equal parts of a slab. */
static void setup_chunk(rl_raster *r, const rl_raster_batch *b, uint32_t first, uint32_t slab,
                        int c, int num_chunks, int num_bands)
{
    rl_raster_chunk *ch = &r->chunks[c];
    uint32_t lo = (uint32_t)((uint64_t)slab * (uint64_t)c / (uint64_t)num_chunks);
    uint32_t hi = (uint32_t)((uint64_t)slab * (uint64_t)(c + 1) / (uint64_t)num_chunks);
    ch->num_prims = 0;
    ch->triangles_drawn = 0;
    /* Chunks of one batch share its vertices, and so their stamps. */
    ch->lazy_alone = num_chunks == 1;
    ch->failed = !rl_raster_setup(r, b, r->clip, r->eye_depth, first + lo, hi - lo, ch) ||
                 !rl_raster_bin(&ch->bins, ch->prims, ch->num_prims, sizeof *ch->prims, num_bands);
}

/* Shared by draw and query. */
static rl_status run(rl_raster *r, const rl_raster_batch *b, bool query, uint64_t *passed_out,
                     uint64_t *drawn_out)
{
    const int threads = rl_raster_thread_count(r);
    rl_raster_target t = rl_raster_target_for(r, b->flags, query);
    if (b->num_layers > 0 && t.color)
        t.layered = b;
    const int num_bands = rl_raster_num_bands(t.height);
    rl_status st = transform(r, b->positions, b->num_vertices, threads);
    if (st != RL_OK)
        return st;
    const int max_chunks = threads > 1 ? threads * CHUNKS_PER_THREAD : 1;
    if ((st = rl_raster_reserve_chunks(r, max_chunks)) != RL_OK)
        return st;
    uint64_t passed = 0, drawn = 0;
    for (uint32_t first = 0; first < b->num_triangles; first += RL_RASTER_SLAB) {
        uint32_t rest = b->num_triangles - first;
        uint32_t slab = rest < RL_RASTER_SLAB ? rest : RL_RASTER_SLAB;
        int num_chunks = slab >= PARALLEL_TRIANGLES ? max_chunks : 1;
        if (num_chunks == 1) {
            setup_chunk(r, b, first, slab, 0, 1, num_bands);
        } else {
            #pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
            for (int c = 0; c < num_chunks; ++c)
                setup_chunk(r, b, first, slab, c, num_chunks, num_bands);
        }
        for (int c = 0; c < num_chunks; ++c) {
            if (r->chunks[c].failed)
                return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster: setup of %u triangles", slab);
            drawn += r->chunks[c].triangles_drawn;
        }
        passed += fill_bands(r, &t, num_chunks, threads);
    }
    *passed_out = passed;
    *drawn_out = drawn;
    return RL_OK;
}

/* The vertices a batch needs in a group's scratch: none without triangles
 * (such a batch may even come without positions). */
static inline size_t group_vertices(const rl_raster_batch *b)
{
    return b->num_triangles ? b->num_vertices : 0;
}

static int compare_ranges(const void *a, const void *b)
{
    const uintptr_t x = ((const uintptr_t *)a)[0], y = ((const uintptr_t *)b)[0];
    return x < y ? -1 : x > y;
}

/* Whether no two batches of a group share a lazy colour stamp: then every
 * stamp is touched only by the chunk that holds its batch, a group being
 * cut between whole batches. It fails only for a list that names an
 * object twice, whose stamps then take the locked path. */
static bool lazy_disjoint(rl_raster *r, const rl_raster_batch *batches, uint32_t count)
{
    size_t n = 0;
    for (uint32_t k = 0; k < count; ++k) {
        const rl_raster_batch *b = &batches[k];
        if (!b->lazy || !b->colors || b->num_triangles == 0)
            continue;
        if (!rl_reserve((void **)&r->lazy_ranges, &r->lazy_range_cap, 2 * (n + 1), sizeof *r->lazy_ranges, 64))
            return false;
        r->lazy_ranges[2 * n] = (uintptr_t)b->lazy->stamps;
        r->lazy_ranges[2 * n + 1] = (uintptr_t)(b->lazy->stamps + b->num_vertices);
        ++n;
    }
    if (n < 2)
        return true;
    qsort(r->lazy_ranges, n, 2 * sizeof *r->lazy_ranges, compare_ranges);
    for (size_t i = 1; i < n; ++i)
        if (r->lazy_ranges[2 * i] < r->lazy_ranges[2 * i - 1])
            return false;
    return true;
}

/* Transforms and sets up the batches of chunk c of a group (c->group_lo ..
 * group_hi), each into its own part of r->clip. */
static void setup_group_chunk(rl_raster *r, const rl_raster_batch *batches, int c, int num_bands)
{
    rl_raster_chunk *ch = &r->chunks[c];
    ch->num_prims = 0;
    ch->triangles_drawn = 0;
    ch->failed = false;
    for (uint32_t k = ch->group_lo; k < ch->group_hi && !ch->failed; ++k) {
        const rl_raster_batch *b = &batches[k];
        if (b->num_triangles == 0)
            continue;
        rl_vec4 *clip = r->clip + r->group_vertex[k];
        float *eye_depth = r->perspective ? NULL : r->eye_depth + r->group_vertex[k];
        for (uint32_t i = 0; i < b->num_vertices; ++i)
            transform_vertex(r, b->positions, i, clip, eye_depth);
        ch->failed = !rl_raster_setup(r, b, clip, eye_depth, 0, b->num_triangles, ch);
    }
    ch->failed = ch->failed || !rl_raster_bin(&ch->bins, ch->prims, ch->num_prims, sizeof *ch->prims, num_bands);
}

/* Draws batches[0 .. count) (none layered, all with the same flags, together
 * fewer than RL_RASTER_SLAB triangles and GROUP_VERTICES vertices) as one
 * draw: runs of whole batches of about equal triangle counts, one per
 * thread, filled in order. */
static rl_status run_group(rl_raster *r, const rl_raster_batch *batches, uint32_t count, uint32_t triangles,
                           size_t vertices, uint64_t *passed_out, uint64_t *drawn_out)
{
    const int threads = rl_raster_thread_count(r);
    rl_raster_target t = rl_raster_target_for(r, batches[0].flags, false);
    const int num_bands = rl_raster_num_bands(t.height);
    rl_status st = reserve_vertices(r, vertices);
    if (st != RL_OK)
        return st;
    if (!rl_reserve((void **)&r->group_vertex, &r->group_cap, count, sizeof *r->group_vertex, 64))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster_draw_many: %u batches", count);
    int num_chunks = triangles >= PARALLEL_TRIANGLES && threads > 1 ? threads * CHUNKS_PER_THREAD : 1;
    if ((uint32_t)num_chunks > count)
        num_chunks = (int)count;
    if ((st = rl_raster_reserve_chunks(r, num_chunks)) != RL_OK)
        return st;
    /* Chunk c starts with the first batch that begins at or after
     * triangles * c / num_chunks. */
    size_t v = 0;
    uint64_t before = 0;
    int c = 0;
    r->chunks[0].group_lo = 0;
    for (uint32_t k = 0; k < count; ++k) {
        while (c + 1 < num_chunks && before * (uint64_t)num_chunks >= (uint64_t)triangles * (uint64_t)(c + 1)) {
            r->chunks[c].group_hi = k;
            r->chunks[++c].group_lo = k;
        }
        r->group_vertex[k] = v;
        v += group_vertices(&batches[k]);
        before += batches[k].num_triangles;
    }
    r->chunks[c].group_hi = count;
    while (++c < num_chunks)
        r->chunks[c].group_lo = r->chunks[c].group_hi = count;
    const bool alone = num_chunks == 1 || lazy_disjoint(r, batches, count);
    for (int k = 0; k < num_chunks; ++k)
        r->chunks[k].lazy_alone = alone;
    if (num_chunks == 1) {
        setup_group_chunk(r, batches, 0, num_bands);
    } else {
        #pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
        for (int k = 0; k < num_chunks; ++k)
            setup_group_chunk(r, batches, k, num_bands);
    }
    uint64_t drawn = 0;
    for (int k = 0; k < num_chunks; ++k) {
        if (r->chunks[k].failed)
            return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster_draw_many: setup of %u triangles", triangles);
        drawn += r->chunks[k].triangles_drawn;
    }
    *passed_out = fill_bands(r, &t, num_chunks, threads);
    *drawn_out = drawn;
    return RL_OK;
}

rl_status rl_raster_draw(rl_raster *r, const rl_raster_batch *batch, rl_raster_counters *c)
{
    rl_status st = check_batch(r, batch, "rl_raster_draw");
    if (st != RL_OK)
        return st;
    uint64_t passed = 0, drawn = 0;
    if (batch->num_triangles > 0 && (st = run(r, batch, false, &passed, &drawn)) != RL_OK)
        return st;
    if (c) {
        c->triangles_in += batch->num_triangles;
        c->triangles_drawn += drawn;
        c->pixels_written += passed;
    }
    return RL_OK;
}

rl_status rl_raster_query(rl_raster *r, const rl_raster_batch *batch, uint64_t *visible_pixels)
{
    if (!visible_pixels)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_query: visible_pixels is NULL");
    rl_status st = check_batch(r, batch, "rl_raster_query");
    if (st != RL_OK)
        return st;
    uint64_t passed = 0, drawn = 0;
    if (batch->num_triangles > 0 && (st = run(r, batch, true, &passed, &drawn)) != RL_OK)
        return st;
    *visible_pixels = passed;
    return RL_OK;
}

/* Small enough to share a group with its neighbours. */
static bool groupable(const rl_raster_batch *b)
{
    return b->num_layers == 0 && b->num_triangles < PARALLEL_TRIANGLES && group_vertices(b) <= GROUP_VERTICES;
}

rl_status rl_raster_draw_many(rl_raster *r, const rl_raster_batch *batches, uint32_t count,
                              rl_raster_counters *c)
{
    if (!r || (!batches && count > 0))
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_draw_many: NULL argument");
    for (uint32_t k = 0; k < count; ++k) {
        char msg[160];
        rl_status st = batch_problem(r, &batches[k], msg, sizeof msg);
        if (st != RL_OK)
            return rl_error(st, "rl_raster_draw_many: batch %u of %u: %s", k, count, msg);
    }
    rl_raster_counters sum = { 0 };
    for (uint32_t k = 0; k < count;) {
        const rl_raster_batch *b = &batches[k];
        uint64_t passed = 0, drawn = 0;
        uint32_t n = 1, triangles = b->num_triangles;   /* of the n batches drawn now */
        rl_status st = RL_OK;
        if (!groupable(b)) {
            if (triangles > 0)
                st = run(r, b, false, &passed, &drawn);
        } else {
            size_t vertices = group_vertices(b);
            for (; k + n < count; ++n) {
                const rl_raster_batch *next = &batches[k + n];
                if (!groupable(next) || next->flags != b->flags ||
                    triangles + next->num_triangles > RL_RASTER_SLAB ||
                    vertices + group_vertices(next) > GROUP_VERTICES)
                    break;
                triangles += next->num_triangles;
                vertices += group_vertices(next);
            }
            if (triangles > 0)
                st = run_group(r, b, n, triangles, vertices, &passed, &drawn);
        }
        if (st != RL_OK)
            return st;
        sum.triangles_in += triangles;
        sum.triangles_drawn += drawn;
        sum.pixels_written += passed;
        k += n;
    }
    if (c) {
        c->triangles_in += sum.triangles_in;
        c->triangles_drawn += sum.triangles_drawn;
        c->pixels_written += sum.pixels_written;
    }
    return RL_OK;
}
