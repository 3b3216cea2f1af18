/* surfels_grid.c: the hashed uniform grid of the Progressive Blue Surfels
 * preprocessing (surfels_internal.h): nearest-chosen-surfel queries of the
 * progressive sampling and the k nearest neighbours of the relative point
 * sizes (Jähn 2015, Sec. 6.1.1), and the prefix spacing of Sec. 6.4.
 *
 * Why hashed: the surfels lie on surfaces, so a dense 3-D array of cells
 * of the spacing's size would be mostly empty (40000 surfels of a city
 * would need ~10^7 cells); a bucket table of twice the capacity keeps the
 * memory linear in the points whatever the cell size. */
#include "render/surfels_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"

#define GRID_MAX_CELLS_PER_SIDE (1 << 20)

int rl_surfel_thread_count(int threads)
{
#ifdef _OPENMP
    return threads > 0 ? threads : omp_get_max_threads();
#else
    (void)threads;
    return 1;
#endif
}

static uint32_t bucket_of(const rl_surfel_grid *g, int32_t x, int32_t y, int32_t z)
{
    uint32_t h = (uint32_t)x * 73856093u ^ (uint32_t)y * 19349663u ^ (uint32_t)z * 83492791u;
    h ^= h >> 15;
    return h & g->mask;
}

static int32_t cell_coord(const rl_surfel_grid *g, float v, float lo, int axis)
{
    float f = (v - lo) * g->inv_cell;
    /* Points on the bounds (or a rounding step outside) join the edge cell. */
    if (!(f > 0.0f))
        return 0;
    int32_t c = f >= (float)g->hi[axis] ? g->hi[axis] : (int32_t)f;
    return c;
}

void rl_surfel_grid_reset(rl_surfel_grid *g, float cell)
{
    rl_vec3 ext = rl_aabb_extent(g->bounds);
    float side = fmaxf(ext.x, fmaxf(ext.y, ext.z));
    float min_cell = side / (float)GRID_MAX_CELLS_PER_SIDE;
    if (!(cell > min_cell))
        cell = min_cell > 0.0f ? min_cell : 1.0f;
    g->cell = cell;
    g->inv_cell = 1.0f / cell;
    const float e[3] = { ext.x, ext.y, ext.z };
    for (int a = 0; a < 3; ++a) {
        float n = floorf(e[a] * g->inv_cell);
        g->hi[a] = n >= (float)GRID_MAX_CELLS_PER_SIDE ? GRID_MAX_CELLS_PER_SIDE : (int32_t)n;
    }
    memset(g->head, 0xFF, ((size_t)g->mask + 1) * sizeof *g->head);
}

rl_status rl_surfel_grid_init(rl_surfel_grid *g, rl_aabb bounds, float cell, uint32_t capacity)
{
    memset(g, 0, sizeof *g);
    uint32_t buckets = 16;
    while (buckets < 2u * capacity && buckets < (1u << 31))
        buckets <<= 1;
    g->head = rl_alloc((size_t)buckets * sizeof *g->head);
    g->next = rl_alloc(((size_t)capacity + 1) * sizeof *g->next);
    if (!g->head || !g->next) {
        rl_surfel_grid_free(g);
        return RL_ERR_OUT_OF_MEMORY;
    }
    g->bounds = rl_aabb_is_empty(bounds) ? (rl_aabb){ { 0, 0, 0 }, { 0, 0, 0 } } : bounds;
    g->mask = buckets - 1;
    g->capacity = capacity;
    rl_surfel_grid_reset(g, cell);
    return RL_OK;
}

void rl_surfel_grid_insert(rl_surfel_grid *g, const rl_vec3 *points, uint32_t i)
{
    rl_vec3 p = points[i];
    uint32_t b = bucket_of(g, cell_coord(g, p.x, g->bounds.min.x, 0),
                           cell_coord(g, p.y, g->bounds.min.y, 1),
                           cell_coord(g, p.z, g->bounds.min.z, 2));
    g->next[i] = g->head[b];
    g->head[b] = i;
}

/* Keeps the k best (idx, d2) sorted by d2; ties keep the earlier one, so
 * the result depends only on the visiting order, which is fixed. */
static void offer(uint32_t k, uint32_t *found, uint32_t *idx, float *d2, uint32_t i, float d)
{
    uint32_t n = *found;
    if (n == k && !(d < d2[k - 1]))
        return;
    uint32_t j = n < k ? n++ : k - 1;
    while (j > 0 && d2[j - 1] > d) {
        d2[j] = d2[j - 1];
        idx[j] = idx[j - 1];
        --j;
    }
    d2[j] = d;
    idx[j] = i;
    *found = n;
}

static void visit(const rl_surfel_grid *g, const rl_vec3 *points, rl_vec3 p, uint32_t skip,
                  uint32_t k, uint32_t *found, uint32_t *idx, float *d2, int32_t x, int32_t y,
                  int32_t z)
{
    for (uint32_t i = g->head[bucket_of(g, x, y, z)]; i != RL_SURFEL_GRID_NONE; i = g->next[i]) {
        if (i == skip)
            continue;
        rl_vec3 q = points[i];
        float dx = q.x - p.x, dy = q.y - p.y, dz = q.z - p.z;
        float d = dx * dx + dy * dy + dz * dz;
        if (*found < k || d < d2[k - 1]) {
            /* A bucket shared by several ring cells is walked once per cell:
             * do not take the same point twice. */
            bool seen = false;
            for (uint32_t j = 0; j < *found && !seen; ++j)
                seen = idx[j] == i;
            if (!seen)
                offer(k, found, idx, d2, i, d);
        }
    }
}

uint32_t rl_surfel_grid_knn(const rl_surfel_grid *g, const rl_vec3 *points, rl_vec3 p,
                            uint32_t skip, uint32_t k, uint32_t *idx, float *d2)
{
    if (k == 0)
        return 0;
    const int32_t c[3] = { cell_coord(g, p.x, g->bounds.min.x, 0),
                           cell_coord(g, p.y, g->bounds.min.y, 1),
                           cell_coord(g, p.z, g->bounds.min.z, 2) };
    const float pv[3] = { p.x, p.y, p.z };
    const float lo_w[3] = { g->bounds.min.x, g->bounds.min.y, g->bounds.min.z };
    uint32_t found = 0;
    for (int32_t r = 0;; ++r) {
        int32_t lo[3], hi[3];
        /* Distance from p to the outside of the block of cells visited so
         * far; an axis whose block reaches both ends of the grid bounds
         * nothing. */
        float reach = INFINITY;
        for (int a = 0; a < 3; ++a) {
            lo[a] = c[a] - r < 0 ? 0 : c[a] - r;
            hi[a] = c[a] + r > g->hi[a] ? g->hi[a] : c[a] + r;
            if (c[a] - r > 0)
                reach = fminf(reach, pv[a] - (lo_w[a] + (float)(c[a] - r) * g->cell));
            if (c[a] + r < g->hi[a])
                reach = fminf(reach, lo_w[a] + (float)(c[a] + r + 1) * g->cell - pv[a]);
        }
        /* The shell of Chebyshev radius r: full z columns where x or y is on
         * the shell, else only its two z caps. */
        for (int32_t x = lo[0]; x <= hi[0]; ++x) {
            bool xs = abs(x - c[0]) == r;
            for (int32_t y = lo[1]; y <= hi[1]; ++y) {
                if (xs || abs(y - c[1]) == r) {
                    for (int32_t z = lo[2]; z <= hi[2]; ++z)
                        visit(g, points, p, skip, k, &found, idx, d2, x, y, z);
                } else {
                    if (c[2] - r >= 0)
                        visit(g, points, p, skip, k, &found, idx, d2, x, y, c[2] - r);
                    if (c[2] + r <= g->hi[2])
                        visit(g, points, p, skip, k, &found, idx, d2, x, y, c[2] + r);
                }
            }
        }
        /* Every point not visited yet lies outside the block. */
        if (reach == INFINITY || (found == k && d2[k - 1] <= reach * reach))
            break;
    }
    return found;
}

float rl_surfel_grid_nearest2(const rl_surfel_grid *g, const rl_vec3 *points, rl_vec3 p)
{
    uint32_t i;
    float d2;
    return rl_surfel_grid_knn(g, points, p, RL_SURFEL_GRID_NONE, 1, &i, &d2) ? d2 : INFINITY;
}

void rl_surfel_grid_free(rl_surfel_grid *g)
{
    if (!g)
        return;
    free(g->head);
    free(g->next);
    memset(g, 0, sizeof *g);
}

rl_status rl_surfels_prefix_spacing(const rl_surfel *s, uint32_t m, int threads, double *min_dist,
                                    double *mean_dist)
{
    if (!min_dist || !mean_dist)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_prefix_spacing: min_dist and mean_dist must not be NULL");
    *min_dist = 0.0;
    *mean_dist = 0.0;
    if (!s || m < 2)
        return RL_OK;
    rl_vec3 *p = rl_alloc((size_t)m * sizeof *p);
    float *nn = rl_alloc((size_t)m * sizeof *nn);
    rl_aabb b = rl_aabb_empty();
    for (uint32_t i = 0; p && i < m; ++i) {
        p[i] = rl_v3(s[i].position[0], s[i].position[1], s[i].position[2]);
        b = rl_aabb_grow(b, p[i]);
    }
    /* Surface points: spacing ~ size / sqrt(m), one or two per cell. */
    rl_surfel_grid g;
    rl_status st = p && nn ? rl_surfel_grid_init(&g, b, rl_length(rl_aabb_extent(b)) / sqrtf((float)m), m)
                           : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK) {
        for (uint32_t i = 0; i < m; ++i)
            rl_surfel_grid_insert(&g, p, i);
#pragma omp parallel for schedule(dynamic, 256) num_threads(rl_surfel_thread_count(threads))
        for (int64_t i = 0; i < (int64_t)m; ++i) {
            uint32_t j;
            float d2;
            nn[i] = rl_surfel_grid_knn(&g, p, p[i], (uint32_t)i, 1, &j, &d2) ? sqrtf(d2) : 0.0f;
        }
        double lo = INFINITY, sum = 0.0;
        for (uint32_t i = 0; i < m; ++i) {
            lo = fmin(lo, nn[i]);
            sum += nn[i];
        }
        *min_dist = lo;
        *mean_dist = sum / m;
        rl_surfel_grid_free(&g);
    }
    free(p);
    free(nn);
    return st;
}
