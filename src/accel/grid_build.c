/* grid_build.c: building the uniform grid of grid.h (resolution heuristic,
 * parallel two-pass insertion into compressed cell lists).
 *
 * Pass 1 counts, for every cell, the triangles that overlap it; a prefix sum
 * turns the counts into cell_start; pass 2 repeats the same overlap tests and
 * scatters triangle IDs through per-cell cursors. Both passes run over
 * triangles with OpenMP and atomic cell counters, so the order inside a cell
 * depends on scheduling: a final per-cell sort by ID makes the lists
 * identical for any number of threads.
 *
 * A triangle goes into the cells its bounding box covers that its surface
 * really overlaps: the separating-axis triangle/box test of Akenine-Möller,
 * "Fast 3D Triangle-Box Overlap Testing", JGT 6(1), 2001 (box normals,
 * triangle normal, 9 edge cross products). We evaluate it in double on
 * cells grown by CELL_GROW_REL of their size (plus a few ulps of the scene's
 * coordinates): an extra reference only costs a test, a missing one loses a
 * hit. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "accel/grid.h"
#include "core/bigalloc.h"
#include "core/error.h"

#define CELL_GROW_REL 1e-4
/* Explicit resolutions (desc->grid_res) may exceed the heuristic's cap but
 * not this: cell_start alone is 4 bytes per cell. */
#define MAX_EXPLICIT_CELLS (1ull << 28)

void rl_grid_resolution(rl_vec3 extent, uint64_t n, float lambda, int res[3])
{
    double e[3] = { extent.x, extent.y, extent.z };
    double lam = lambda > 0.0f ? (double)lambda : (double)RL_GRID_DEFAULT_LAMBDA;
    bool active[3];
    for (int a = 0; a < 3; ++a) {
        res[a] = 1;
        active[a] = n > 0 && isfinite(e[a]) && e[a] > 0.0;
    }
    /* k = (λ^d N / Π e_i)^(1/d) over the active axes; an axis shorter than
     * one cell drops out and k is recomputed (at most three rounds). */
    double k = 0.0;
    for (;;) {
        int d = 0;
        double volume = 1.0;
        for (int a = 0; a < 3; ++a)
            if (active[a]) {
                ++d;
                volume *= e[a];
            }
        if (d == 0)
            break;
        double x = pow(lam, d) * (double)n / volume;
        k = d == 3 ? cbrt(x) : (d == 2 ? sqrt(x) : x);
        bool dropped = false;
        for (int a = 0; a < 3; ++a)
            if (active[a] && e[a] * k < 1.0) {
                active[a] = false;
                dropped = true;
            }
        if (!dropped)
            break;
    }
    for (int a = 0; a < 3; ++a)
        if (active[a]) {
            double r = floor(e[a] * k + 0.5);
            res[a] = r < 1.0 ? 1 : (r > RL_GRID_MAX_RES ? RL_GRID_MAX_RES : (int)r);
        }
    /* Cap the total by shrinking every axis alike; floor keeps the product
     * below the cap except where an axis is pinned at 1, hence the loop. */
    for (;;) {
        uint64_t total = (uint64_t)res[0] * (uint64_t)res[1] * (uint64_t)res[2];
        if (total <= RL_GRID_MAX_CELLS)
            break;
        double f = cbrt((double)RL_GRID_MAX_CELLS / (double)total);
        for (int a = 0; a < 3; ++a) {
            int r = (int)floor((double)res[a] * f);
            res[a] = r < 1 ? 1 : r;
        }
    }
}

/* Plain compares: fmin/fmax are library calls without -ffinite-math-only. */
static inline double min3(double a, double b, double c) { double m = a < b ? a : b; return m < c ? m : c; }
static inline double max3(double a, double b, double c) { double m = a > b ? a : b; return m > c ? m : c; }

/* Akenine-Möller 2001: does the triangle v[0..2] overlap the box with centre
 * c and half size h? Touching counts as overlap. */
static bool tri_box_overlap(const double c[3], const double h[3], const rl_vec3 v[3])
{
    double p[3][3];
    for (int i = 0; i < 3; ++i) {
        p[i][0] = (double)v[i].x - c[0];
        p[i][1] = (double)v[i].y - c[1];
        p[i][2] = (double)v[i].z - c[2];
    }
    /* Box normals: the triangle's box against the cell. */
    for (int a = 0; a < 3; ++a) {
        double lo = min3(p[0][a], p[1][a], p[2][a]), hi = max3(p[0][a], p[1][a], p[2][a]);
        if (lo > h[a] || hi < -h[a])
            return false;
    }
    double e[3][3];
    for (int a = 0; a < 3; ++a) {
        e[0][a] = p[1][a] - p[0][a];
        e[1][a] = p[2][a] - p[1][a];
        e[2][a] = p[0][a] - p[2][a];
    }
    /* Nine axes e_i x unit_j: for unit_j the axis has components
     * (j+1, j+2) = (e[j+2], -e[j+1]) and the box radius
     * h[j+1]·|e[j+2]| + h[j+2]·|e[j+1]|. */
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            int a1 = (j + 1) % 3, a2 = (j + 2) % 3;
            double ax1 = e[i][a2], ax2 = -e[i][a1];
            double s0 = ax1 * p[0][a1] + ax2 * p[0][a2];
            double s1 = ax1 * p[1][a1] + ax2 * p[1][a2];
            double s2 = ax1 * p[2][a1] + ax2 * p[2][a2];
            double lo = min3(s0, s1, s2), hi = max3(s0, s1, s2);
            double r = h[a1] * fabs(ax1) + h[a2] * fabs(ax2);
            if (lo > r || hi < -r)
                return false;
        }
    /* Triangle plane against the box: |n·p0| <= h·|n|. */
    double n[3] = { e[0][1] * e[1][2] - e[0][2] * e[1][1], e[0][2] * e[1][0] - e[0][0] * e[1][2],
                    e[0][0] * e[1][1] - e[0][1] * e[1][0] };
    double dist = n[0] * p[0][0] + n[1] * p[0][1] + n[2] * p[0][2];
    double r = h[0] * fabs(n[0]) + h[1] * fabs(n[1]) + h[2] * fabs(n[2]);
    return fabs(dist) <= r;
}

typedef struct insert_ctx {
    const rl_grid *g;
    double grow[3];           /* cell growth per axis, world units */
} insert_ctx;

/* Cells (clamped) covered by the triangle's box grown like the cells. */
static void cell_range(const insert_ctx *ctx, const rl_vec3 v[3], int lo[3], int hi[3])
{
    const rl_grid *g = ctx->g;
    for (int a = 0; a < 3; ++a) {
        double mn = min3(rl_vget(v[0], a), rl_vget(v[1], a), rl_vget(v[2], a));
        double mx = max3(rl_vget(v[0], a), rl_vget(v[1], a), rl_vget(v[2], a));
        double base = rl_vget(g->bounds.min, a), inv = rl_vget(g->inv_cell_size, a);
        double l = floor((mn - ctx->grow[a] - base) * inv);
        double h = floor((mx + ctx->grow[a] - base) * inv);
        double top = g->res[a] - 1;
        lo[a] = (int)(l < 0.0 ? 0.0 : (l > top ? top : l));
        hi[a] = (int)(h < 0.0 ? 0.0 : (h > top ? top : h));
    }
}

/* Calls visit(cell) for every cell the triangle overlaps and returns the
 * count; both passes go through here so that they agree exactly. */
typedef void (*visit_fn)(void *user, uint32_t cell, uint32_t tri);

static uint32_t insert_triangle(const insert_ctx *ctx, uint32_t tri, visit_fn visit, void *user)
{
    const rl_grid *g = ctx->g;
    const rl_vec3 *v = g->tri_verts + 3 * (size_t)tri;
    int lo[3], hi[3];
    cell_range(ctx, v, lo, hi);
    /* A box spanning cells along at most one axis needs no exact test: the
     * triangle is connected, so it crosses every slab of that row, and the
     * other two axes hold a single cell. */
    bool exact = (lo[0] < hi[0]) + (lo[1] < hi[1]) + (lo[2] < hi[2]) >= 2;
    uint32_t count = 0;
    for (int z = lo[2]; z <= hi[2]; ++z)
        for (int y = lo[1]; y <= hi[1]; ++y)
            for (int x = lo[0]; x <= hi[0]; ++x) {
                if (exact) {
                    int xyz[3] = { x, y, z };
                    double c[3], h[3];
                    for (int a = 0; a < 3; ++a) {
                        double cs = rl_vget(g->cell_size, a);
                        c[a] = rl_vget(g->bounds.min, a) + ((double)xyz[a] + 0.5) * cs;
                        h[a] = 0.5 * cs + ctx->grow[a];
                    }
                    if (!tri_box_overlap(c, h, v))
                        continue;
                }
                visit(user, rl_grid_cell_index(g, x, y, z), tri);
                ++count;
            }
    return count;
}

static void visit_count(void *user, uint32_t cell, uint32_t tri)
{
    (void)tri;
    uint32_t *counts = user;
    #pragma omp atomic
    counts[cell]++;
}

typedef struct fill_ctx { uint32_t *cursor, *cell_tris; } fill_ctx;

static void visit_fill(void *user, uint32_t cell, uint32_t tri)
{
    fill_ctx *f = user;
    uint32_t slot;
    #pragma omp atomic capture
    slot = f->cursor[cell]++;
    f->cell_tris[slot] = tri;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static void sort_ids(uint32_t *ids, uint32_t n)
{
    if (n > 24) {
        qsort(ids, n, sizeof *ids, cmp_u32);
        return;
    }
    for (uint32_t i = 1; i < n; ++i) {   /* short lists: insertion sort */
        uint32_t x = ids[i], j = i;
        for (; j > 0 && ids[j - 1] > x; --j)
            ids[j] = ids[j - 1];
        ids[j] = x;
    }
}

static bool report(const rl_accel_desc *desc, double done)
{
    return !desc || !desc->progress || desc->progress(desc->user, done);
}

/* Copies the triangles' vertices and returns their box. */
static rl_aabb gather(rl_grid *g, const rl_scene_data *data, int threads)
{
    float x0 = INFINITY, y0 = INFINITY, z0 = INFINITY;
    float x1 = -INFINITY, y1 = -INFINITY, z1 = -INFINITY;
    long n = (long)data->num_triangles;
    #pragma omp parallel for num_threads(threads) schedule(static) \
        reduction(min : x0, y0, z0) reduction(max : x1, y1, z1)
    for (long i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k) {
            rl_vec3 p = data->positions[data->indices[3 * i + k]];
            g->tri_verts[3 * i + k] = p;
            x0 = rl_minf(x0, p.x); y0 = rl_minf(y0, p.y); z0 = rl_minf(z0, p.z);
            x1 = rl_maxf(x1, p.x); y1 = rl_maxf(y1, p.y); z1 = rl_maxf(z1, p.z);
        }
    rl_aabb b = { { x0, y0, z0 }, { x1, y1, z1 } };
    return b;
}

/* Sets bounds, res and cell sizes from the triangles' box. */
static rl_status layout(rl_grid *g, rl_aabb box, const rl_accel_desc *desc, double *scale)
{
    if (rl_aabb_is_empty(box))
        box = (rl_aabb){ { 0.0f, 0.0f, 0.0f }, { 1.0f, 1.0f, 1.0f } };
    rl_vec3 ext = rl_aabb_extent(box);
    float lambda = desc ? desc->grid_lambda : 0.0f;
    rl_grid_resolution(ext, g->num_triangles, lambda, g->res);
    uint64_t total = 1;
    for (int a = 0; a < 3; ++a) {
        if (desc && desc->grid_res[a] > 0)
            g->res[a] = desc->grid_res[a];
        total *= (uint64_t)g->res[a];
    }
    if (total > MAX_EXPLICIT_CELLS)
        return rl_error(RL_ERR_LIMIT, "grid: %d x %d x %d cells exceed the limit of 2^28",
                        g->res[0], g->res[1], g->res[2]);
    g->num_cells = (uint32_t)total;
    float big = rl_maxf(rl_vmax_comp(ext), rl_maxf(rl_vmax_comp(rl_vmax(box.min, rl_neg(box.min))),
                                                    rl_vmax_comp(rl_vmax(box.max, rl_neg(box.max)))));
    float pad = rl_maxf(RL_GRID_PAD_REL * big, FLT_MIN);
    g->bounds.min = rl_sub(box.min, rl_v3s(pad));
    g->bounds.max = rl_add(box.max, rl_v3s(pad));
    rl_vec3 padded = rl_sub(g->bounds.max, g->bounds.min);
    g->cell_size = rl_v3(padded.x / (float)g->res[0], padded.y / (float)g->res[1],
                         padded.z / (float)g->res[2]);
    g->inv_cell_size = rl_v3((float)g->res[0] / padded.x, (float)g->res[1] / padded.y,
                             (float)g->res[2] / padded.z);
    *scale = big;
    return RL_OK;
}

rl_status rl_grid_build(const rl_scene_data *data, const rl_accel_desc *desc, rl_grid **out)
{
    if (!data || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_grid_build: NULL data or out");
    int threads = desc && desc->threads > 0 ? desc->threads : 1;
#ifdef _OPENMP
    if (!desc || desc->threads <= 0)
        threads = omp_get_max_threads();
#endif
    rl_grid *g = rl_calloc(1, sizeof *g);
    if (!g)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status s = RL_OK;
    uint32_t *cursor = NULL;
    g->num_triangles = data->num_triangles;
    g->tri_verts = rl_big_array(3 * (size_t)g->num_triangles + 1, sizeof *g->tri_verts, true);
    if (!g->tri_verts) {
        s = RL_ERR_OUT_OF_MEMORY;
        goto fail;
    }
    double scale = 0.0;
    s = layout(g, gather(g, data, threads), desc, &scale);
    if (s)
        goto fail;
    insert_ctx ctx = { .g = g };
    for (int a = 0; a < 3; ++a)
        ctx.grow[a] = CELL_GROW_REL * rl_vget(g->cell_size, a) + 4.0 * FLT_EPSILON * scale;
    if (!report(desc, 0.1)) {
        s = rl_error(RL_ERR_CANCELLED, "grid: build cancelled");
        goto fail;
    }

    /* Pass 1: references per cell, counted into cell_start[0..num_cells-1]. */
    g->cell_start = rl_big_array((size_t)g->num_cells + 1, sizeof *g->cell_start, true);
    if (!g->cell_start) {
        s = RL_ERR_OUT_OF_MEMORY;
        goto fail;
    }
    long n = (long)g->num_triangles;
    #pragma omp parallel for num_threads(threads) schedule(dynamic, 256)
    for (long i = 0; i < n; ++i)
        insert_triangle(&ctx, (uint32_t)i, visit_count, g->cell_start);
    if (!report(desc, 0.45)) {
        s = rl_error(RL_ERR_CANCELLED, "grid: build cancelled");
        goto fail;
    }

    /* Exclusive prefix sum; 32-bit offsets bound the total. */
    uint64_t total = 0;
    for (uint32_t c = 0; c < g->num_cells; ++c) {
        uint64_t k = g->cell_start[c];
        g->cell_start[c] = (uint32_t)total;
        total += k;
        if (total > UINT32_MAX) {
            s = rl_error(RL_ERR_LIMIT, "grid: more than 2^32-1 triangle references; lower "
                         "grid_lambda or grid_res");
            goto fail;
        }
    }
    g->cell_start[g->num_cells] = (uint32_t)total;
    g->num_references = total;

    /* Pass 2: scatter, then sort each cell so the lists do not depend on
     * the thread schedule. */
    g->cell_tris = rl_big_array((size_t)total + 1, sizeof *g->cell_tris, true);
    cursor = rl_big_array(g->num_cells, sizeof *cursor, false);
    if (!g->cell_tris || !cursor) {
        s = RL_ERR_OUT_OF_MEMORY;
        goto fail;
    }
    memcpy(cursor, g->cell_start, (size_t)g->num_cells * sizeof *cursor);
    fill_ctx fill = { cursor, g->cell_tris };
    #pragma omp parallel for num_threads(threads) schedule(dynamic, 256)
    for (long i = 0; i < n; ++i)
        insert_triangle(&ctx, (uint32_t)i, visit_fill, &fill);
    free(cursor);
    cursor = NULL;
    if (!report(desc, 0.8)) {
        s = rl_error(RL_ERR_CANCELLED, "grid: build cancelled");
        goto fail;
    }
    long cells = (long)g->num_cells;
    #pragma omp parallel for num_threads(threads) schedule(dynamic, 1024)
    for (long c = 0; c < cells; ++c)
        sort_ids(g->cell_tris + g->cell_start[c], g->cell_start[c + 1] - g->cell_start[c]);
    if (!report(desc, 1.0)) {
        s = rl_error(RL_ERR_CANCELLED, "grid: build cancelled");
        goto fail;
    }
    g->memory_bytes = sizeof *g + ((size_t)g->num_cells + 1) * sizeof *g->cell_start +
                      (size_t)total * sizeof *g->cell_tris +
                      3 * (size_t)g->num_triangles * sizeof *g->tri_verts;
    *out = g;
    return RL_OK;
fail:
    free(cursor);
    rl_grid_free(g);
    return s;
}

void rl_grid_free(rl_grid *grid)
{
    if (!grid)
        return;
    free(grid->cell_start);
    free(grid->cell_tris);
    free(grid->tri_verts);
    free(grid);
}
