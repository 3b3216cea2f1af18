/* linespace_scene.c: the scene Line Space (Schröder 2017, Sec. 13.1, an
 * outlook the thesis attributes to S. Müller): one Line Space spanning the
 * whole scene, whose shafts store a "signature", the intervals along the
 * shaft that are filled or empty, so that a ray skips long empty stretches
 * without walking voxels.
 *
 * Signature: M bits per shaft (segments, default 64, one word); bit j
 * covers λ in [j/M, (j+1)/M], λ the parameter from the shaft's patch A on
 * its lower face (λ = 0) to patch B (λ = 1). The thesis leaves the
 * signature's form open; equal λ steps make the mapping from a ray's t
 * linear. Shafts: N x N patches per face of the scene box, indexed as the
 * per-voxel Line Space's (rl_linespace.h), default N = 4.
 *
 * Build. The points at λ of all lines from A to B fill the axis-aligned
 * box (1-λ)·A + λ·B, so a shaft meets an axis-aligned cell exactly for the
 * λ where that box overlaps the cell: six inequalities linear in λ, an
 * interval. Occupancy comes from a uniform grid over the scene (`cells`
 * per axis, default 16) whose cells list the triangles their surface
 * overlaps (grid.h, exact triangle/box test, cells grown); per shaft every
 * filled cell's interval sets its segments. Cells are visited in bricks
 * of 4³, and bricks in super-bricks of 4³ bricks, so that a (super-)brick
 * whose interval is empty, or whose segments are set already, is skipped
 * whole. Conservative: a point of a triangle on a line
 * through the shaft lies in a filled cell at that line's λ, so its segment
 * is set; cells and patches are grown by small margins against rounding.
 *
 * Query. The ray's line is clipped to the box (double, unit coordinates),
 * entry and exit give the shaft as in a voxel of the per-voxel Line Space;
 * the runs of set bits met within (t_min, t_max) become t-intervals (grown
 * by a margin) and the inner structure (BVH, grid, per-voxel or object Line
 * Spaces) answers them in ray order; the first run with a hit ends the
 * search. Every hit lies in a run, and the runs come front to back, so the
 * answer is the inner structure's. A line whose entry and exit share a
 * face, or that misses the box by rounding, asks the inner structure for
 * the whole ray. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "accel/accel_internal.h"
#include "accel/linespace_internal.h"
#include "core/error.h"
#include "rl/rl_timer.h"

#define BRICK 4                   /* cells per brick side */
#define SUPER 4                   /* bricks per super-brick side */
#define CELL_GROW 1e-3            /* of a cell, against rounding (grid cells grow 1e-4) */
#define PATCH_GROW 1e-6           /* unit coordinates of the box */
#define RUN_GROW_REL 1e-4         /* of the line's t-span inside the box */
#define RUN_GROW_T 1e-6           /* of |t|: the triangle test's own rounding */

typedef struct cell_box {
    float lo[3], hi[3];           /* unit coordinates of the scene box */
} cell_box;

typedef struct brick {
    cell_box box;                 /* union of its filled cells (super-brick: of its bricks) */
    uint32_t first, count;        /* into the cell boxes (super-brick: into the bricks) */
} brick;

struct rl_ls_scene {
    const rl_scene *scene;
    const rl_scene_data *data;
    int n, segments, cells, threads;
    rl_ls_scene_inner inner;
    bool committed;
    rl_aabb box;                  /* the occupancy grid's padded box */
    double lo[3], ext[3];
    uint32_t shafts;
    uint64_t *sig;
    cell_box *cell;               /* filled cells, brick by brick */
    brick *bricks, *supers;
    uint32_t num_cells, num_bricks, num_supers;
    rl_ls_scene_stats stats;
};

static rl_status check_inner(const rl_scene *scene, const rl_ls_scene_inner *in)
{
    int set = (in->accel != NULL) + (in->linespace != NULL) + (in->objects != NULL);
    if (set != 1)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: needs exactly one inner structure (accel, "
                        "linespace or objects), got %d", set);
    const rl_scene *of;
    bool committed;
    if (in->accel) {
        of = rl_accel_scene(in->accel);
        committed = rl_accel_is_committed(in->accel);
    } else if (in->linespace) {
        of = rl_accel_scene(in->linespace->accel);
        committed = in->linespace->committed;
        if (!(in->linespace->payloads & RL_LS_CANDIDATES))
            return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: the inner per-voxel Line Space has no "
                            "candidates payload");
    } else {
        of = rl_ls_objects_scene(in->objects);
        committed = rl_ls_objects_committed(in->objects);
    }
    if (!committed)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: the inner structure is not committed");
    if (of != scene)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: the inner structure was built for another scene");
    return RL_OK;
}

rl_status rl_ls_scene_create(const rl_scene *scene, const rl_ls_scene_desc *desc, rl_ls_scene **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_ls_scene_create: NULL scene or out");
    *out = NULL;
    const rl_scene_data *data = rl_scene_is_committed(scene) ? rl_scene_get_data(scene) : NULL;
    if (!data)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: the scene is not committed");
    rl_ls_scene_desc d = desc ? *desc : (rl_ls_scene_desc){ 0 };
    int n = d.n ? d.n : RL_LS_SCENE_DEFAULT_N;
    int m = d.segments ? d.segments : RL_LS_SCENE_DEFAULT_SEGMENTS;
    int c = d.cells ? d.cells : RL_LS_SCENE_DEFAULT_CELLS;
    if (n < 1 || n > RL_LS_SCENE_MAX_N)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: n = %d not in 1..%d", d.n, RL_LS_SCENE_MAX_N);
    if (m < 1 || m > RL_LS_SCENE_MAX_SEGMENTS)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: segments = %d not in 1..%d", d.segments,
                        RL_LS_SCENE_MAX_SEGMENTS);
    if (c < 1 || c > RL_LS_SCENE_MAX_CELLS)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: cells = %d not in 1..%d", d.cells,
                        RL_LS_SCENE_MAX_CELLS);
    if (d.threads < 0)
        return rl_error(RL_ERR_INVALID_ARG, "scene Line Space: threads %d < 0", d.threads);
    rl_status st = check_inner(scene, &d.inner);
    if (st != RL_OK)
        return st;
    rl_ls_scene *s = rl_calloc(1, sizeof *s);
    if (!s)
        return RL_ERR_OUT_OF_MEMORY;
    s->scene = scene;
    s->data = data;
    s->n = n;
    s->segments = m;
    s->cells = c;
    s->threads = d.threads;
    s->inner = d.inner;
    s->shafts = rl_ls_shafts_per_voxel(n);
    s->stats.n = n;
    s->stats.segments = m;
    s->stats.cells = c;
    s->stats.shafts = s->shafts;
    *out = s;
    return RL_OK;
}

void rl_ls_scene_release(rl_ls_scene *s)
{
    if (!s)
        return;
    free(s->sig);
    free(s->cell);
    free(s->bricks);
    free(s->supers);
    free(s);
}

void rl_ls_scene_get_stats(const rl_ls_scene *s, rl_ls_scene_stats *out)
{
    if (out)
        *out = s ? s->stats : (rl_ls_scene_stats){ 0 };
}

uint64_t rl_ls_scene_signature(const rl_ls_scene *s, uint32_t shaft)
{
    return s && s->committed && shaft < s->shafts ? s->sig[shaft] : 0;
}

/* The filled cells of the occupancy grid as boxes in unit coordinates,
 * grouped by brick. */
static rl_status gather_cells(rl_ls_scene *s, const rl_grid *g)
{
    int nb[3], ns[3];
    for (int a = 0; a < 3; ++a) {
        nb[a] = (g->res[a] + BRICK - 1) / BRICK;
        ns[a] = (nb[a] + SUPER - 1) / SUPER;
    }
    uint32_t filled = 0;
    for (uint32_t i = 0; i < g->num_cells; ++i)
        filled += g->cell_start[i + 1] > g->cell_start[i];
    s->cell = rl_calloc(filled ? filled : 1, sizeof *s->cell);
    s->bricks = rl_calloc((size_t)nb[0] * nb[1] * nb[2], sizeof *s->bricks);
    s->supers = rl_calloc((size_t)ns[0] * ns[1] * ns[2], sizeof *s->supers);
    if (!s->cell || !s->bricks || !s->supers)
        return RL_ERR_OUT_OF_MEMORY;
    const brick none = { { { 2.0f, 2.0f, 2.0f }, { -1.0f, -1.0f, -1.0f } }, 0, 0 };
    for (int q = 0; q < ns[0] * ns[1] * ns[2]; ++q) {
        int sq[3] = { q % ns[0], (q / ns[0]) % ns[1], q / (ns[0] * ns[1]) };
        brick sup = none;
        sup.first = s->num_bricks;
        for (int k = 0; k < SUPER * SUPER * SUPER; ++k) {
            int bq[3] = { sq[0] * SUPER + k % SUPER, sq[1] * SUPER + (k / SUPER) % SUPER,
                          sq[2] * SUPER + k / (SUPER * SUPER) };
            if (bq[0] >= nb[0] || bq[1] >= nb[1] || bq[2] >= nb[2])
                continue;
            brick b = none;
            b.first = s->num_cells;
            for (int c = 0; c < BRICK * BRICK * BRICK; ++c) {
                int xyz[3] = { bq[0] * BRICK + c % BRICK, bq[1] * BRICK + (c / BRICK) % BRICK,
                               bq[2] * BRICK + c / (BRICK * BRICK) };
                if (xyz[0] >= g->res[0] || xyz[1] >= g->res[1] || xyz[2] >= g->res[2])
                    continue;
                uint32_t i = rl_grid_cell_index(g, xyz[0], xyz[1], xyz[2]);
                if (g->cell_start[i + 1] == g->cell_start[i])
                    continue;
                cell_box *cb = &s->cell[s->num_cells++];
                for (int a = 0; a < 3; ++a) {
                    double r = (double)g->res[a];
                    cb->lo[a] = (float)((xyz[a] - CELL_GROW) / r);
                    cb->hi[a] = (float)((xyz[a] + 1 + CELL_GROW) / r);
                    b.box.lo[a] = rl_minf(b.box.lo[a], cb->lo[a]);
                    b.box.hi[a] = rl_maxf(b.box.hi[a], cb->hi[a]);
                }
                b.count++;
            }
            if (!b.count)
                continue;
            s->bricks[s->num_bricks++] = b;
            sup.count++;
            for (int a = 0; a < 3; ++a) {
                sup.box.lo[a] = rl_minf(sup.box.lo[a], b.box.lo[a]);
                sup.box.hi[a] = rl_maxf(sup.box.hi[a], b.box.hi[a]);
            }
        }
        if (sup.count)
            s->supers[s->num_supers++] = sup;
    }
    s->stats.filled_cells = s->num_cells;
    return RL_OK;
}

/* The λ in [0, 1] where the box (1-λ)·A + λ·B overlaps c; false if none. */
static bool lambda_range(const double alo[3], const double ahi[3], const double blo[3], const double bhi[3],
                         const cell_box *c, double *l0, double *l1)
{
    double lo = 0.0, hi = 1.0;
    for (int a = 0; a < 3; ++a) {
        /* lower side: alo + λ(blo - alo) <= c.hi; upper: ahi + λ(bhi - ahi) >= c.lo */
        double s = blo[a] - alo[a], r = c->hi[a] - alo[a];
        if (s > 0.0)
            hi = fmin(hi, r / s);
        else if (s < 0.0)
            lo = fmax(lo, r / s);
        else if (r < 0.0)
            return false;
        s = bhi[a] - ahi[a];
        r = c->lo[a] - ahi[a];
        if (s > 0.0)
            lo = fmax(lo, r / s);
        else if (s < 0.0)
            hi = fmin(hi, r / s);
        else if (r > 0.0)
            return false;
        if (lo > hi)
            return false;
    }
    *l0 = lo;
    *l1 = hi;
    return true;
}

static uint64_t segment_mask(int m, double l0, double l1)
{
    int j0 = (int)floor(l0 * m), j1 = (int)floor(l1 * m);
    j0 = j0 < 0 ? 0 : (j0 > m - 1 ? m - 1 : j0);
    j1 = j1 < 0 ? 0 : (j1 > m - 1 ? m - 1 : j1);
    uint64_t hi = j1 == 63 ? ~0ull : (1ull << (j1 + 1)) - 1u;
    return hi & ~((1ull << j0) - 1u);
}

/* Patch p of face f as an axis-aligned rectangle in unit coordinates. */
static void patch_rect(int n, int f, int p, double lo[3], double hi[3])
{
    int axis = rl_ls_face_axis(f), u, v;
    rl_ls_face_uv(f, &u, &v);
    lo[axis] = hi[axis] = (double)(f & 1);
    int i = p % n, j = p / n;
    lo[u] = (double)i / n - PATCH_GROW;
    hi[u] = (double)(i + 1) / n + PATCH_GROW;
    lo[v] = (double)j / n - PATCH_GROW;
    hi[v] = (double)(j + 1) / n + PATCH_GROW;
}

static uint64_t shaft_signature(const rl_ls_scene *s, uint32_t shaft)
{
    int fa, pa, fb, pb;
    rl_ls_shaft_decode(s->n, shaft, &fa, &pa, &fb, &pb);
    double alo[3], ahi[3], blo[3], bhi[3];
    patch_rect(s->n, fa, pa, alo, ahi);
    patch_rect(s->n, fb, pb, blo, bhi);
    uint64_t sig = 0, full = segment_mask(s->segments, 0.0, 1.0);
    for (uint32_t q = 0; q < s->num_supers && sig != full; ++q) {
        const brick *sb = &s->supers[q];
        double l0, l1;
        if (!lambda_range(alo, ahi, blo, bhi, &sb->box, &l0, &l1) || !(segment_mask(s->segments, l0, l1) & ~sig))
            continue;
        for (uint32_t k = sb->first; k < sb->first + sb->count; ++k) {
            const brick *b = &s->bricks[k];
            if (!lambda_range(alo, ahi, blo, bhi, &b->box, &l0, &l1) || !(segment_mask(s->segments, l0, l1) & ~sig))
                continue;
            for (uint32_t i = b->first; i < b->first + b->count; ++i)
                if (lambda_range(alo, ahi, blo, bhi, &s->cell[i], &l0, &l1))
                    sig |= segment_mask(s->segments, l0, l1);
        }
    }
    return sig;
}

rl_status rl_ls_scene_commit(rl_ls_scene *s)
{
    if (!s)
        return rl_error(RL_ERR_INVALID_ARG, "rl_ls_scene_commit: NULL");
    if (s->committed)
        return RL_OK;
    rl_timer timer;
    rl_timer_start(&timer);
    /* A flat axis gets one cell, as the object grids. */
    rl_vec3 ext = rl_aabb_extent(s->data->bounds);
    float big = rl_vmax_comp(ext);
    rl_accel_desc gd = { .kind = RL_ACCEL_GRID, .threads = s->threads };
    for (int a = 0; a < 3; ++a)
        gd.grid_res[a] = rl_vget(ext, a) > 1e-3f * big ? s->cells : 1;
    rl_grid *g = NULL;
    rl_status st = rl_grid_build(s->data, &gd, &g);
    if (st != RL_OK)
        return st;
    s->box = g->bounds;
    for (int a = 0; a < 3; ++a) {
        s->lo[a] = rl_vget(g->bounds.min, a);
        s->ext[a] = (double)rl_vget(g->bounds.max, a) - s->lo[a];
    }
    /* A failed commit may be retried: start from nothing. */
    free(s->cell);
    free(s->bricks);
    free(s->supers);
    free(s->sig);
    s->cell = NULL;
    s->bricks = s->supers = NULL;
    s->sig = NULL;
    s->num_cells = s->num_bricks = s->num_supers = 0;
    st = gather_cells(s, g);
    rl_grid_free(g);
    if (st != RL_OK)
        return st;
    s->sig = rl_calloc(s->shafts, sizeof *s->sig);
    if (!s->sig)
        return RL_ERR_OUT_OF_MEMORY;
#ifdef _OPENMP
    int threads = s->threads > 0 ? s->threads : omp_get_max_threads();
#endif
    /* Each shaft is written by one thread: the same bits for any count. */
    #pragma omp parallel for schedule(dynamic, 64) num_threads(threads)
    for (int64_t k = 0; k < (int64_t)s->shafts; ++k)
        s->sig[k] = shaft_signature(s, (uint32_t)k);
    uint64_t bits = 0;
    for (uint32_t k = 0; k < s->shafts; ++k)
        bits += (uint64_t)__builtin_popcountll(s->sig[k]);
    s->stats.filled_bits = bits;
    s->stats.memory_bytes = (size_t)s->shafts * sizeof *s->sig + (size_t)s->num_cells * sizeof(cell_box) +
                            (size_t)(s->num_bricks + s->num_supers) * sizeof(brick);
    s->committed = true;
    s->stats.build_ms = rl_timer_ms(&timer);
    return RL_OK;
}

static bool ray_ok(const rl_ray *r)
{
    if (!rl_vfinite(r->o) || !rl_vfinite(r->d) || !isfinite(r->t_min) || isnan(r->t_max))
        return false;
    return (r->d.x != 0.0f || r->d.y != 0.0f || r->d.z != 0.0f) && r->t_min <= r->t_max;
}

static bool inner_intersect(const rl_ls_scene *s, rl_ray *ray, rl_hit *hit)
{
    if (s->inner.accel)
        return rl_accel_intersect(s->inner.accel, ray, hit);
    if (s->inner.linespace)
        return rl_linespace_intersect(s->inner.linespace, ray, hit);
    return rl_ls_objects_intersect(s->inner.objects, ray, hit);
}

static bool inner_occluded(const rl_ls_scene *s, const rl_ray *ray)
{
    if (s->inner.accel)
        return rl_accel_occluded(s->inner.accel, ray);
    if (s->inner.linespace)
        return rl_linespace_occluded(s->inner.linespace, ray);
    return rl_ls_objects_occluded(s->inner.objects, ray);
}

/* The ray's shaft and the runs of its set segments, front to back. */
typedef struct run_walk {
    uint64_t sig;
    int m, j, step, end;          /* next segment, direction, one past the last */
    double t_a, dt;               /* t = t_a + λ·dt */
    double grow;
    bool whole;                   /* no shaft: ask the inner structure once */
    bool done;
} run_walk;

/* False when the ray's segment misses the box (no hit possible). */
static bool walk_begin(const rl_ls_scene *s, const rl_ray *ray, run_walk *w)
{
    memset(w, 0, sizeof *w);
    double o[3], d[3], tn = -INFINITY, tf = INFINITY;
    for (int a = 0; a < 3; ++a) {
        o[a] = ((double)rl_vget(ray->o, a) - s->lo[a]) / s->ext[a];
        d[a] = (double)rl_vget(ray->d, a) / s->ext[a];
        if (d[a] == 0.0) {
            if (o[a] < -PATCH_GROW || o[a] > 1.0 + PATCH_GROW)
                return false;
            continue;
        }
        double t0 = -o[a] / d[a], t1 = (1.0 - o[a]) / d[a];
        if (t0 > t1) {
            double x = t0; t0 = t1; t1 = x;
        }
        tn = fmax(tn, t0);
        tf = fmin(tf, t1);
    }
    if (!isfinite(tn) || !isfinite(tf)) {
        w->whole = true;
        return true;
    }
    if (tn > tf) {
        /* A clear miss holds no hit (the box holds every triangle); one
         * by rounding at an edge of the box is left to the inner
         * structure. */
        if (tn - tf > 1e-9 * (fabs(tn) + fabs(tf)))
            return false;
        w->whole = true;
        return true;
    }
    double grow = RUN_GROW_REL * (tf - tn);
    if (tf + grow < ray->t_min || tn - grow > ray->t_max)
        return false;
    double entry[3], exit[3];
    for (int a = 0; a < 3; ++a) {
        entry[a] = o[a] + d[a] * tn;
        exit[a] = o[a] + d[a] * tf;
    }
    bool fwd;
    uint32_t shaft = rl_ls_shaft_of_unit(s->n, entry, exit, &fwd);
    if (shaft == RL_NONE || !(tf - tn > 0.0)) {
        w->whole = true;
        return true;
    }
    w->sig = s->sig[shaft];
    w->m = s->segments;
    w->t_a = fwd ? tn : tf;
    w->dt = fwd ? tf - tn : tn - tf;
    w->grow = grow;
    /* The segments the ray's (t_min, t_max) covers, in the ray's order. */
    double lmin = ((double)ray->t_min - w->t_a) / w->dt, lmax = isinf(ray->t_max) ? (fwd ? 2.0 : -1.0)
                                                                                   : ((double)ray->t_max - w->t_a) / w->dt;
    int m = w->m;
    int j0 = (int)floor(fmin(fmax(lmin, -1.0), 2.0) * m), j1 = (int)floor(fmin(fmax(lmax, -1.0), 2.0) * m);
    j0 = j0 < 0 ? 0 : (j0 > m - 1 ? m - 1 : j0);
    j1 = j1 < 0 ? 0 : (j1 > m - 1 ? m - 1 : j1);
    /* One segment more at either end, against rounding of λ at a
     * segment border; runs are clipped to (t_min, t_max) anyway. */
    w->step = fwd ? 1 : -1;
    j0 = j0 - w->step < 0 || j0 - w->step > m - 1 ? j0 : j0 - w->step;
    j1 = j1 + w->step < 0 || j1 + w->step > m - 1 ? j1 : j1 + w->step;
    w->j = j0;
    w->end = j1 + w->step;
    return true;
}

/* The next run of set segments as a t-interval grown by the margins. */
static bool walk_next(run_walk *w, double *t0, double *t1)
{
    if (w->whole) {
        if (w->done)
            return false;
        w->done = true;
        *t0 = -INFINITY;
        *t1 = INFINITY;
        return true;
    }
    while (w->j != w->end && !((w->sig >> w->j) & 1u))
        w->j += w->step;
    if (w->j == w->end)
        return false;
    int first = w->j;
    while (w->j != w->end && ((w->sig >> w->j) & 1u))
        w->j += w->step;
    int last = w->j - w->step;
    int lo = first < last ? first : last, hi = first < last ? last : first;
    double ta = w->t_a + (double)lo / w->m * w->dt, tb = w->t_a + (double)(hi + 1) / w->m * w->dt;
    if (ta > tb) {
        double x = ta; ta = tb; tb = x;
    }
    *t0 = ta - w->grow - RUN_GROW_T * fabs(ta);
    *t1 = tb + w->grow + RUN_GROW_T * fabs(tb);
    return true;
}

/* The walk of both queries: each run of set segments, front to back, is
 * asked of the inner structure with the ray clipped to it. hit NULL: any
 * hit (occluded); else the closest, its t in *t_hit. Inline with a constant
 * hit at both calls, so that each query gets its own loop without the
 * mode's test. */
static inline bool walk_runs(const rl_ls_scene *s, const rl_ray *ray, rl_hit *hit, float *t_hit)
{
    run_walk w;
    if (!walk_begin(s, ray, &w))
        return false;
    double t0, t1;
    while (walk_next(&w, &t0, &t1)) {
        rl_ray r = *ray;
        if (t0 > r.t_min)
            r.t_min = (float)t0;
        if (t1 < r.t_max)
            r.t_max = (float)t1;
        if (r.t_min > r.t_max)
            continue;
        if (!hit) {
            if (inner_occluded(s, &r))
                return true;
        } else if (inner_intersect(s, &r, hit)) {
            *t_hit = r.t_max;
            return true;
        }
    }
    return false;
}

bool rl_ls_scene_intersect(const rl_ls_scene *s, rl_ray *ray, rl_hit *hit)
{
    if (!s || !ray || !hit || !s->committed || !ray_ok(ray))
        return false;
    return walk_runs(s, ray, hit, &ray->t_max);
}

bool rl_ls_scene_occluded(const rl_ls_scene *s, const rl_ray *ray)
{
    if (!s || !ray || !s->committed || !ray_ok(ray))
        return false;
    return walk_runs(s, ray, NULL, NULL);
}
