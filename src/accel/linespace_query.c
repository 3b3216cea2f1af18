/* linespace_query.c: Line Space traversal (Schröder 2017, Sec. 7.2-7.4).
 *
 * Every query walks the grid's voxels front to back with the 3D-DDA of
 * grid.h. In a filled voxel it extends the ray's line to the voxel box (also
 * when the origin lies inside), takes the entry and exit points and from
 * them the shaft and the direction (Sec. 4.3); points are computed in double
 * in cell units, so their rounding stays far below the shafts' growth
 * RL_LS_EPS.
 *
 * CANDIDATES. As grid.c, with the shaft's list in place of the cell's: each
 * candidate is tested with the shared watertight test against the whole ray,
 * the closest hit is kept (ties to the lower ID), and the walk stops at the
 * first voxel whose exit lies beyond the best hit by grid.c's relative
 * margin. The shaft holds every triangle that the line's piece inside the
 * voxel can meet (linespace_shaft.c is conservative), so with dynamic lists
 * the result is the grid's, and the BVH's. Fixed lists: all k slots are
 * tested (front half first), so only shafts with more than k candidates can
 * lose a hit; the thesis tests one half only. A voxel where entry and exit
 * lie on one face (grazing, a line in a face plane) or where the line misses
 * the box by rounding uses the voxel's full grid list (always exact).
 *
 * PNMT. The stored surface of the ray's shaft and direction (forward: the
 * front record, backward: the back record), at t = the stored point's
 * projection on the ray, accepted inside (t_min, t_max). In contrast to the
 * thesis, which skips the ray's origin voxel (Sec. 12.1, "Voxel-Offset")
 * against self-intersection, the origin voxel is answered exactly: the
 * closest hit among its triangles (the dynamic shaft list, or the grid list)
 * within the voxel's t-interval; only the voxels after it use records.
 *
 * PREILLUM. The stored colour of the first surface; t from the PNMT record
 * when PNMT is built too, else the middle of the ray's interval in that
 * voxel. No shading happens at query time, so the origin voxel cannot be
 * answered exactly: there a record counts only beyond t_min plus a tenth of
 * the voxel's diagonal (in ray parameter), which keeps the surface the ray
 * starts from out; otherwise the walk goes on.
 *
 * RL_LS_ORIGIN_RECORDS drops both origin-voxel rules (the caller offsets
 * t_min, as the thesis does).
 *
 * EMPTY SHAFTS. Every walk checks the shaft's occupancy bit first: a shaft
 * no triangle overlaps has no candidates and no records, and its bit sits in
 * a small array that stays in cache, where a record costs a load from
 * memory. Shadow tests (PNMT, PREILLUM) also skip decoding a filled shaft's
 * record when the whole voxel lies inside the ray's interval, since the
 * stored point lies in its voxel. Answers are the same as without both. */
#include <math.h>
#include <string.h>

#include "accel/accel_internal.h"
#include "accel/linespace_internal.h"
#include "accel/tri_list.h"
#include "core/half.h"

#define T_SLACK_REL 1e-6f          /* as grid.c: walk vs triangle-test rounding */
#define ORIGIN_MARGIN_REL 0.1f     /* PREILLUM, origin voxel: of the voxel diagonal */

static bool ray_is_valid(const rl_ray *r)
{
    if (!rl_vfinite(r->o) || !rl_vfinite(r->d) || !isfinite(r->t_min))
        return false;
    if (r->d.x == 0.0f && r->d.y == 0.0f && r->d.z == 0.0f)
        return false;
    return r->t_min <= r->t_max;
}

static bool usable(const rl_linespace *ls, const rl_ray *ray)
{
    return ls && ray && ls->committed && ray_is_valid(ray);
}

/* The ray's line in cell units of the whole grid (cell xyz is the unit
 * cube at xyz), set up once per query so that each voxel costs no
 * division. */
typedef struct cell_line {
    double o[3], d[3], inv[3];
} cell_line;

static void cell_line_setup(const rl_linespace *ls, const rl_ray *r, cell_line *l)
{
    for (int a = 0; a < 3; ++a) {
        double size = rl_vget(ls->grid->cell_size, a);
        l->o[a] = ((double)rl_vget(r->o, a) - rl_vget(ls->grid->bounds.min, a)) / size;
        l->d[a] = (double)rl_vget(r->d, a) / size;
        l->inv[a] = l->d[a] != 0.0 ? 1.0 / l->d[a] : 0.0;
    }
}

/* The shaft of the line in the voxel at cell coordinates xyz (Sec. 4.3),
 * RL_NONE if the entry and exit share a face or the line misses the box by
 * rounding. */
static uint32_t shaft_of_ray(const rl_linespace *ls, const int xyz[3], const cell_line *l, bool *forward)
{
    double o[3], tn = -INFINITY, tf = INFINITY;
    for (int a = 0; a < 3; ++a) {
        o[a] = l->o[a] - (double)xyz[a];
        if (l->d[a] == 0.0) {
            if (o[a] < 0.0 || o[a] > 1.0)
                return RL_NONE;
            continue;
        }
        double t0 = -o[a] * l->inv[a], t1 = (1.0 - o[a]) * l->inv[a];
        if (t0 > t1) {
            double s = t0; t0 = t1; t1 = s;
        }
        tn = t0 > tn ? t0 : tn;
        tf = t1 < tf ? t1 : tf;
    }
    if (!(tn <= tf) || !isfinite(tn) || !isfinite(tf))
        return RL_NONE;
    double entry[3], exit[3];
    for (int a = 0; a < 3; ++a) {
        entry[a] = o[a] + l->d[a] * tn;
        exit[a] = o[a] + l->d[a] * tf;
    }
    return rl_ls_shaft_of_unit(ls->n, entry, exit, forward);
}

/* The triangle list to test in a filled voxel: the shaft's candidates, or
 * the voxel's grid list (no candidates stored, or no shaft). */
typedef struct tri_list {
    const uint32_t *ids;
    uint32_t count;
} tri_list;

static tri_list grid_list(const rl_grid *g, uint32_t cell)
{
    tri_list l = { g->cell_tris + g->cell_start[cell], g->cell_start[cell + 1] - g->cell_start[cell] };
    return l;
}

static tri_list candidates(const rl_linespace *ls, uint32_t cell, uint32_t block, uint32_t shaft,
                           bool exact_only)
{
    if (shaft == RL_NONE || !(ls->payloads & RL_LS_CANDIDATES) || (exact_only && !ls->dynamic))
        return grid_list(ls->grid, cell);
    uint64_t r = rl_ls_shaft_rank(ls, block, shaft);   /* an occupied shaft: the callers check */
    tri_list l;
    if (ls->dynamic) {
        l.ids = ls->cand + ls->cand_start[r];
        l.count = ls->cand_start[r + 1] - ls->cand_start[r];
    } else {
        l.ids = ls->cand + r * (uint64_t)ls->k;
        l.count = (uint32_t)ls->k;
    }
    return l;
}

/* A candidate list against the whole ray (tri_list.h). */
static void test_list(const rl_linespace *ls, const rl_ray_watertight *w, const rl_ray *ray, tri_list l,
                      rl_mailbox *mailbox, rl_tri_closest *best, float *limit)
{
    rl_tri_list_closest(ls->grid->tri_verts, l.ids, l.count, w, ray->t_min, mailbox, best, limit);
}

static bool any_hit(const rl_linespace *ls, const rl_ray_watertight *w, const rl_ray *ray, tri_list l,
                    rl_mailbox *mailbox, float t_max)
{
    return rl_tri_list_any(ls->grid->tri_verts, l.ids, l.count, w, ray->t_min, t_max, mailbox);
}

/* The closest candidate hit, holes of alpha masks included (an
 * rl_closest_hit_fn: state is the rl_linespace). */
static bool closest_hit(const void *state, rl_ray *ray, rl_hit *hit)
{
    const rl_linespace *ls = state;
    hit->triangle = RL_ID_NONE;
    hit->object = RL_ID_NONE;
    if (!usable(ls, ray))
        return false;
    rl_grid_dda it;
    if (!rl_grid_dda_begin(ls->grid, ray, &it))
        return false;
    cell_line line;
    cell_line_setup(ls, ray, &line);
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    rl_mailbox mailbox;
    rl_mailbox_init(&mailbox);
    rl_tri_closest best = { RL_NONE, ray->t_max, 0.0f, 0.0f };
    float limit = ray->t_max;
    uint32_t cell;
    float t0, t1;
    while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
        uint32_t block = ls->voxel_slot[cell];
        if (block != RL_NONE) {
            bool fwd;
            uint32_t shaft = shaft_of_ray(ls, it.current, &line, &fwd);
            if (shaft == RL_NONE || rl_ls_shaft_occupied(ls, block, shaft))
                test_list(ls, &w, ray, candidates(ls, cell, block, shaft, false), &mailbox, &best, &limit);
        }
        if (best.id != RL_NONE && best.t <= t1 - T_SLACK_REL * fabsf(t1))
            break;
    }
    if (best.id == RL_NONE)
        return false;
    ray->t_max = best.t;
    hit->t = best.t;
    hit->u = best.u;
    hit->v = best.v;
    hit->triangle = best.id;
    hit->object = ls->data->triangle_object[best.id];
    return true;
}

/* Alpha masks as in rl_accel_intersect (rl_closest_unmasked_hit). */
bool rl_linespace_intersect(const rl_linespace *ls, rl_ray *ray, rl_hit *hit)
{
    if (!ray || !hit)
        return false;
    if (!ls) {
        hit->triangle = hit->object = RL_ID_NONE;
        return false;
    }
    /* closest_hit checks that ls is committed and the ray valid. */
    return rl_closest_unmasked_hit(ls->data, ls->masked, closest_hit, ls, ray, hit);
}

bool rl_linespace_occluded(const rl_linespace *ls, const rl_ray *ray)
{
    if (!usable(ls, ray))
        return false;
    if (ls->masked) {
        /* An any-hit test could stop at a hole: walk the hits instead. */
        rl_ray r = *ray;
        rl_hit h;
        return rl_linespace_intersect(ls, &r, &h);
    }
    rl_grid_dda it;
    if (!rl_grid_dda_begin(ls->grid, ray, &it))
        return false;
    cell_line line;
    cell_line_setup(ls, ray, &line);
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    rl_mailbox mailbox;
    rl_mailbox_init(&mailbox);
    uint32_t cell;
    float t0, t1;
    while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
        uint32_t block = ls->voxel_slot[cell];
        if (block == RL_NONE)
            continue;
        bool fwd;
        uint32_t shaft = shaft_of_ray(ls, it.current, &line, &fwd);
        if (shaft != RL_NONE && !rl_ls_shaft_occupied(ls, block, shaft))
            continue;
        if (any_hit(ls, &w, ray, candidates(ls, cell, block, shaft, false), &mailbox, ray->t_max))
            return true;
    }
    return false;
}

/* Sec. 7.4, eq. 9: a PNMT record back to a surface; false if empty. */
static bool decode_pnmt(const rl_linespace *ls, const int xyz[3], const uint16_t *r, rl_ls_surface *s)
{
    float m = rl_half_to_float(r[RL_LS_PNMT_MAT]);
    if (!rl_ls_pnmt_material(m, &s->material))
        return false;
    rl_aabb box = rl_grid_cell_bounds(ls->grid, xyz[0], xyz[1], xyz[2]);
    rl_vec3 ext = rl_sub(box.max, box.min);
    s->p = rl_v3(box.min.x + rl_half_to_float(r[RL_LS_PNMT_PX]) * ext.x,
                 box.min.y + rl_half_to_float(r[RL_LS_PNMT_PY]) * ext.y,
                 box.min.z + rl_half_to_float(r[RL_LS_PNMT_PZ]) * ext.z);
    float nx = rl_half_to_float(r[RL_LS_PNMT_NX]), ny = rl_half_to_float(r[RL_LS_PNMT_NY]);
    float nz = sqrtf(rl_maxf(0.0f, 1.0f - nx * nx - ny * ny));
    s->n = rl_v3(nx, ny, m < 0.0f ? -nz : nz);
    s->uv = rl_v2(rl_half_to_float(r[RL_LS_PNMT_U]), rl_half_to_float(r[RL_LS_PNMT_V]));
    return true;
}

static float project_t(const rl_ray *ray, rl_vec3 p)
{
    return rl_dot(rl_sub(p, ray->o), ray->d) / rl_dot(ray->d, ray->d);
}

/* The exact closest hit among the origin voxel's triangles within its
 * t-interval (PNMT's origin-voxel rule); fills *s. */
static bool origin_hit(const rl_linespace *ls, const rl_ray *ray, uint32_t cell, uint32_t block,
                       uint32_t shaft, float t1, rl_ls_surface *s)
{
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    rl_mailbox mailbox;
    rl_mailbox_init(&mailbox);
    float limit = rl_minf(ray->t_max, t1 + T_SLACK_REL * fabsf(t1));
    rl_tri_closest best = { RL_NONE, limit, 0.0f, 0.0f };
    const tri_list l = candidates(ls, cell, block, shaft, true);
    test_list(ls, &w, ray, l, &mailbox, &best, &limit);
    /* A hole of an alpha mask is no surface: look again behind it. */
    for (int skips = 0; best.id != RL_NONE && ls->masked && rl_alpha_masked(ls->data, best.id, best.u, best.v);
         ++skips) {
        if (skips == RL_MAX_MASK_SKIPS)
            return false;
        rl_ray behind = *ray;
        behind.t_min = best.t;
        rl_mailbox_init(&mailbox);
        limit = rl_minf(ray->t_max, t1 + T_SLACK_REL * fabsf(t1));
        best = (rl_tri_closest){ RL_NONE, limit, 0.0f, 0.0f };
        test_list(ls, &w, &behind, l, &mailbox, &best, &limit);
    }
    if (best.id == RL_NONE)
        return false;
    if (s) {
        rl_ls_surface_at(ls, best.id, best.u, best.v, s);
        s->t = best.t;
    }
    return true;
}

/* Half a voxel diagonal in the ray's parameter: how far a point of a voxel
 * can project from the voxel centre's projection. Once per query. */
static float half_diagonal_t(const rl_linespace *ls, const rl_ray *ray)
{
    return 0.5f * rl_length(ls->grid->cell_size) / rl_length(ray->d);
}

/* Whether every point of voxel xyz projects on the ray strictly inside
 * (lo, t_max): a stored point (clamped to its voxel, linespace_build.c)
 * then needs no decoding for a shadow test. The centre's projection +- r
 * (half_diagonal_t) bounds every point's; the slack covers rounding, so
 * the answer is always the one the record gives. */
static bool voxel_within(const rl_linespace *ls, const int xyz[3], const rl_ray *ray, float lo, float r)
{
    rl_aabb box = rl_grid_cell_bounds(ls->grid, xyz[0], xyz[1], xyz[2]);
    float tc = project_t(ray, rl_scale(rl_add(box.min, box.max), 0.5f));
    float slack = 1e-4f * r + 1e-6f * fabsf(tc);
    return tc - r - slack > lo && tc + r + slack < ray->t_max;
}

/* Whether the first voxel walked gets the start-voxel rule. */
static bool origin_inside(const rl_linespace *ls, const rl_ray *ray)
{
    return ls->origin == RL_LS_ORIGIN_EXACT && rl_aabb_contains(ls->grid->bounds, rl_ray_at(ray, ray->t_min));
}

static bool pnmt_walk(const rl_linespace *ls, const rl_ray *ray, rl_ls_surface *out)
{
    if (!usable(ls, ray) || !ls->pnmt)
        return false;
    rl_grid_dda it;
    if (!rl_grid_dda_begin(ls->grid, ray, &it))
        return false;
    cell_line line;
    cell_line_setup(ls, ray, &line);
    bool first = origin_inside(ls, ray);
    float r = out ? 0.0f : half_diagonal_t(ls, ray);
    uint32_t cell;
    float t0, t1;
    while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
        bool origin = first;
        first = false;
        uint32_t block = ls->voxel_slot[cell];
        if (block == RL_NONE)
            continue;
        bool fwd = true;
        uint32_t shaft = shaft_of_ray(ls, it.current, &line, &fwd);
        if (shaft != RL_NONE && !rl_ls_shaft_occupied(ls, block, shaft))
            continue;             /* no triangle in the shaft: no record either */
        if (origin || shaft == RL_NONE) {
            /* Origin voxel (our change to Sec. 12.1) and grazing lines: exact. */
            if (origin_hit(ls, ray, cell, block, shaft, t1, out))
                return true;
            continue;
        }
        /* The record lies in the voxel, inside (t_min, t_max); with alpha
         * masks it may say the shaft is empty (linespace_build.c). */
        if (!out && !ls->masked && voxel_within(ls, it.current, ray, ray->t_min, r))
            return true;
        const uint16_t *rec = ls->pnmt + rl_ls_shaft_rank(ls, block, shaft) * 16 +
                              (fwd ? 0 : RL_LS_PNMT_RECORD);
        rl_ls_surface s;
        if (!decode_pnmt(ls, it.current, rec, &s))
            continue;
        s.t = project_t(ray, s.p);
        if (s.t > ray->t_min && s.t < ray->t_max) {
            if (out)
                *out = s;
            return true;
        }
    }
    return false;
}

bool rl_linespace_pnmt_intersect(const rl_linespace *ls, const rl_ray *ray, rl_ls_surface *s)
{
    rl_ls_surface tmp;
    if (!s)
        return false;
    if (!pnmt_walk(ls, ray, &tmp))
        return false;
    *s = tmp;
    return true;
}

bool rl_linespace_pnmt_occluded(const rl_linespace *ls, const rl_ray *ray)
{
    return pnmt_walk(ls, ray, NULL);
}

/* PREILLUM walk; color NULL: a shadow test, which needs no record where a
 * filled shaft's surface must lie inside the ray's interval. */
static bool preillum_walk(const rl_linespace *ls, const rl_ray *ray, rl_vec3 *color, float *t_out)
{
    if (!usable(ls, ray) || !ls->preillum)
        return false;
    rl_grid_dda it;
    if (!rl_grid_dda_begin(ls->grid, ray, &it))
        return false;
    cell_line line;
    cell_line_setup(ls, ray, &line);
    bool first = origin_inside(ls, ray);
    float margin = ORIGIN_MARGIN_REL * rl_length(ls->grid->cell_size) / rl_length(ray->d);
    float r = color ? 0.0f : half_diagonal_t(ls, ray);
    uint32_t cell;
    float t0, t1;
    while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
        bool origin = first;
        first = false;
        uint32_t block = ls->voxel_slot[cell];
        if (block == RL_NONE)
            continue;
        bool fwd = true;
        uint32_t shaft = shaft_of_ray(ls, it.current, &line, &fwd);
        if (shaft == RL_NONE || !rl_ls_shaft_occupied(ls, block, shaft))
            continue;
        float lo = origin ? ray->t_min + margin : ray->t_min;
        uint64_t g = rl_ls_shaft_rank(ls, block, shaft);
        /* Alpha 0: the shaft's midpoint ray passes through holes only
         * (linespace_build.c), no surface. */
        if (ls->masked && rl_half_to_float(ls->preillum[g * 8 + (fwd ? 3 : 7)]) == 0.0f)
            continue;
        float t = 0.5f * (t0 + t1);
        if (ls->pnmt) {
            if (!color && !ls->masked && voxel_within(ls, it.current, ray, lo, r))
                return true;
            rl_ls_surface s;
            if (decode_pnmt(ls, it.current, ls->pnmt + g * 16 + (fwd ? 0 : RL_LS_PNMT_RECORD), &s))
                t = project_t(ray, s.p);
        }
        if (!(t > lo && t < ray->t_max))
            continue;
        if (color) {
            const uint16_t *c = ls->preillum + g * 8 + (fwd ? 0 : 4);
            *color = rl_v3(rl_half_to_float(c[0]), rl_half_to_float(c[1]), rl_half_to_float(c[2]));
        }
        if (t_out)
            *t_out = t;
        return true;
    }
    return false;
}

bool rl_linespace_preillum(const rl_linespace *ls, const rl_ray *ray, rl_vec3 *color, float *t_out)
{
    return color && preillum_walk(ls, ray, color, t_out);
}

bool rl_linespace_preillum_occluded(const rl_linespace *ls, const rl_ray *ray)
{
    return preillum_walk(ls, ray, NULL, NULL);
}

/* ---- object Line Spaces (linespace_object.c) ----
 * The walk of closest_hit/occluded on a Line Space built in an object's
 * space, with the candidates tested in world space: the shaft is found
 * from the object-space line (in double, shifted near the object by the
 * caller), the triangles are the scene's, against the world ray. Both
 * parametrise the same line by the same t (the transform is affine), up to
 * the transform's rounding, which `slack` (in t) covers: the walk goes
 * slack beyond both ends and stops only slack past the best hit. */

static bool mapped_setup(const rl_linespace *ls, const rl_ls_local_ray *lr, float t_lo, float t_hi, rl_grid_dda *it,
                         cell_line *l)
{
    rl_ray r = { rl_v3((float)lr->o[0], (float)lr->o[1], (float)lr->o[2]), t_lo - lr->t_shift - lr->slack,
                 rl_v3((float)lr->d[0], (float)lr->d[1], (float)lr->d[2]), t_hi - lr->t_shift + lr->slack };
    if (!ray_is_valid(&r) || !rl_grid_dda_begin(ls->grid, &r, it))
        return false;
    for (int a = 0; a < 3; ++a) {
        double size = rl_vget(ls->grid->cell_size, a);
        l->o[a] = (lr->o[a] - rl_vget(ls->grid->bounds.min, a)) / size;
        l->d[a] = lr->d[a] / size;
        l->inv[a] = l->d[a] != 0.0 ? 1.0 / l->d[a] : 0.0;
    }
    return true;
}

static tri_list mapped_list(const rl_linespace *ls, const rl_grid_dda *it, const cell_line *l, uint32_t cell,
                            bool *skip)
{
    uint32_t block = ls->voxel_slot[cell];
    *skip = block == RL_NONE;
    if (*skip)
        return (tri_list){ NULL, 0 };
    bool fwd;
    uint32_t shaft = shaft_of_ray(ls, it->current, l, &fwd);
    *skip = shaft != RL_NONE && !rl_ls_shaft_occupied(ls, block, shaft);
    return *skip ? (tri_list){ NULL, 0 } : candidates(ls, cell, block, shaft, true);
}

void rl_ls_mapped_closest(const rl_linespace *ls, const rl_ls_local_ray *lr, const rl_vec3 *verts,
                          uint32_t id_base, const rl_ray_watertight *w, float t_min, rl_mailbox *mailbox,
                          rl_tri_closest *best, float *limit)
{
    rl_grid_dda it;
    cell_line line;
    if (!mapped_setup(ls, lr, t_min, *limit, &it, &line))
        return;
    uint32_t cell;
    float t0, t1;
    while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
        if (t0 + lr->t_shift > *limit + lr->slack)
            break;
        bool skip;
        tri_list l = mapped_list(ls, &it, &line, cell, &skip);
        for (uint32_t j = 0; !skip && j < l.count; ++j) {
            uint32_t id = id_base + l.ids[j];
            if (rl_mailbox_seen(mailbox, id))
                continue;
            const rl_vec3 *v = verts + 3 * (size_t)id;
            float t, u, vv;
            if (!rl_watertight_hit(w, v[0], v[1], v[2], t_min, *limit, &t, &u, &vv))
                continue;
            if (best->id == RL_ID_NONE || t < best->t || (t == best->t && id < best->id)) {
                *best = (rl_tri_closest){ id, t, u, vv };
                *limit = nextafterf(t, INFINITY);
            }
        }
        if (best->id != RL_ID_NONE && best->t + lr->slack <= t1 + lr->t_shift)
            break;
    }
}

bool rl_ls_mapped_any(const rl_linespace *ls, const rl_ls_local_ray *lr, const rl_vec3 *verts, uint32_t id_base,
                      const rl_ray_watertight *w, float t_min, float t_max, rl_mailbox *mailbox)
{
    rl_grid_dda it;
    cell_line line;
    if (!mapped_setup(ls, lr, t_min, t_max, &it, &line))
        return false;
    uint32_t cell;
    float t0, t1;
    while (rl_grid_dda_next(&it, &cell, &t0, &t1)) {
        bool skip;
        tri_list l = mapped_list(ls, &it, &line, cell, &skip);
        for (uint32_t j = 0; !skip && j < l.count; ++j) {
            uint32_t id = id_base + l.ids[j];
            if (rl_mailbox_seen(mailbox, id))
                continue;
            const rl_vec3 *v = verts + 3 * (size_t)id;
            float t, u, vv;
            if (rl_watertight_hit(w, v[0], v[1], v[2], t_min, t_max, &t, &u, &vv))
                return true;
        }
    }
    return false;
}
