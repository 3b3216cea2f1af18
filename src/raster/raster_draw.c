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
 * rl_raster_prim_src) and the fill reads the layers from the batch. */
#include <omp.h>

#include "core/error.h"
#include "raster/raster_internal.h"

/* Below these sizes a parallel region costs more than it saves. */
#define PARALLEL_VERTICES 8192
#define PARALLEL_TRIANGLES 2048
#define PARALLEL_PIXELS 16384

static rl_status check_batch(const rl_raster *r, const rl_raster_batch *b, const char *fn)
{
    if (!r || !b)
        return rl_error(RL_ERR_INVALID_ARG, "%s: NULL argument", fn);
    if (!r->target)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no render target set", fn);
    if (b->num_layers > RL_RASTER_MAX_LAYERS)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %u layers (at most %d)", fn, b->num_layers,
                        RL_RASTER_MAX_LAYERS);
    if (b->num_layers > 0 && !b->layers)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %u layers but layers is NULL", fn,
                        b->num_layers);
    for (uint32_t i = 0; i < b->num_layers; ++i)
        if (!b->layers[i].colors)
            return rl_error(RL_ERR_INVALID_ARG, "%s: layer %u has no colors", fn, i);
    if (b->lazy && (!b->lazy->shade || !b->lazy->stamps || b->lazy->frame < 1 ||
                    b->lazy->frame >= (1u << 31)))
        return rl_error(RL_ERR_INVALID_ARG, "%s: lazy colours need shade, stamps and 1 <= frame < 2^31 "
                        "(frame %u)", fn, b->lazy->frame);
    if (b->num_triangles == 0)
        return RL_OK;
    if (!b->indices || !b->positions)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %u triangles without indices or positions",
                        fn, b->num_triangles);
    /* One pass, OR-free max: cheap next to the setup that follows. */
    const size_t n = 3 * (size_t)b->num_triangles;
    uint32_t max_index = 0;
    for (size_t i = 0; i < n; ++i)
        max_index = b->indices[i] > max_index ? b->indices[i] : max_index;
    if (max_index >= b->num_vertices)
        return rl_error(RL_ERR_INVALID_ARG, "%s: index %u out of range (%u vertices)", fn,
                        max_index, b->num_vertices);
    return RL_OK;
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

static rl_status transform(rl_raster *r, const rl_vec3 *positions, uint32_t n, int threads)
{
    if (!rl_reserve((void **)&r->clip, &r->vert_cap, n, sizeof *r->clip, 64))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster: %u vertices", n);
    if (!r->perspective &&
        !rl_reserve((void **)&r->eye_depth, &r->eye_depth_cap, n, sizeof *r->eye_depth, 64))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster: %u vertices", n);
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
    ch->failed = !rl_raster_setup(r, b, first + lo, hi - lo, ch) ||
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
    if ((st = rl_raster_reserve_chunks(r, threads)) != RL_OK)
        return st;
    uint64_t passed = 0, drawn = 0;
    for (uint32_t first = 0; first < b->num_triangles; first += RL_RASTER_SLAB) {
        uint32_t rest = b->num_triangles - first;
        uint32_t slab = rest < RL_RASTER_SLAB ? rest : RL_RASTER_SLAB;
        int num_chunks = slab >= PARALLEL_TRIANGLES ? threads : 1;
        if (num_chunks == 1) {
            setup_chunk(r, b, first, slab, 0, 1, num_bands);
        } else {
            #pragma omp parallel for num_threads(num_chunks) schedule(static)
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
