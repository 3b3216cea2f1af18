/* linespace_build.c: generating the Line Space payloads per filled voxel
 * (Schröder 2017, Sec. 7.1, Alg. 3; dynamic lists as proposed in Sec. 7.1.1;
 * PREILLUM Sec. 7.3; PNMT Sec. 7.4).
 *
 * Per voxel (a grid cell with at least one triangle; OpenMP threads claim
 * voxels in order): every triangle of the cell is clipped to the voxel and
 * rl_ls_enumerate (linespace_shaft.c) lists the shafts it may overlap, with
 * its position along each shaft. A counting sort groups the entries by
 * shaft; each shaft's list is then sorted front to back by the midpoint ray
 * (Alg. 3), ties by triangle ID. From the sorted list:
 *   fixed k:  the k/2 front-most (front order) and the k/2 back-most (back
 *             to front), RL_NONE padded; a shaft with more than k
 *             candidates counts as truncated (Sec. 7.1.1's "holes");
 *   dynamic:  counting pass, prefix sum, fill pass (Sec. 7.1.1). In contrast
 *             to the proposal, the counting pass keeps each voxel's lists in
 *             a temporary block and the fill pass copies them to their
 *             prefix-sum offsets instead of clipping everything again: twice
 *             the list memory for a moment, half the build time. The prefix
 *             sum over the blocks runs during the pass (rank_chain);
 *   PNMT:     the front record is the first triangle the shaft's midpoint
 *             ray hits, the back record the first the reversed ray hits
 *             (Sec. 7.4). If the midpoint ray hits none of the shaft's
 *             candidates (they only graze the shaft), we store the point of
 *             the front-most (back-most) candidate closest to the axis point
 *             at that candidate's key: a shaft with geometry then never
 *             reads as empty;
 *   PREILLUM: the same two surfaces, coloured by the caller's shading
 *             function (Sec. 7.3), alpha 1.
 * Only occupied shafts (a non-empty list) get lists and records, at their
 * rank among all occupied shafts (rl_linespace.h): a block's records start
 * at the sum of the occupied shafts of the blocks before it, which a chain
 * of published counts provides during the pass (rank_chain below). The
 * arrays are allocated for every shaft and shrunk at the end; the pages
 * never written are never faulted in. Positions depend only on the
 * voxels, so the output is the same for any number of threads. */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <sched.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif
#ifdef __F16C__
#include <immintrin.h>
#endif

#include "accel/linespace_internal.h"
#include "core/bigalloc.h"
#include "core/error.h"
#include "core/half.h"
#include "rl/rl_timer.h"

/* What the records need of one triangle of the voxel, gathered once per
 * voxel: entries carry the triangle's local index in the cell's (sorted)
 * list, so a shaft's record reads this instead of the scene's index,
 * normal, uv and vertex arrays and the cell-unit conversion per shaft. */
typedef struct tri_info {
    double v[3][3];               /* vertices in cell units */
    rl_vec3 n[3];                 /* vertex normals */
    rl_vec2 uv[3];
    float mat1;                   /* material ID + 1, as the record stores it */
    uint32_t id;                  /* scene triangle ID */
} tri_info;

/* A block whose records wait in a thread's staging area for its base
 * (rank_chain below). */
typedef struct staged_block {
    uint32_t block, count;
    size_t at;                    /* first staged record */
} staged_block;

typedef struct staging {
    uint32_t *start, *fixed;      /* as rec_dst, `capacity` records each */
    uint16_t *pnmt, *preillum;
    size_t capacity, used;
    staged_block *pending;
    size_t npending, pending_cap;
} staging;

/* Per-thread workspace, allocated once per thread (no allocation inside
 * the per-triangle loops; the entry buffers grow between triangles). */
typedef struct workspace {
    rl_ls_entry *entries, *sorted;
    size_t capacity;
    uint32_t *offset;             /* S + 1 */
    rl_ls_entry *back;            /* k entries, for the back half */
    double *scratch;
    int *iscratch;
    tri_info *tris;               /* the voxel's triangles, by local index */
    size_t tri_capacity;
    double pnmt_s, preillum_s;     /* ms spent on the PNMT / PREILLUM records */
    /* The block between build_lists and write_records. */
    uint32_t cell, occupied;
    double lo[3], ext[3];         /* the voxel's box */
    staging stage;
} workspace;

static bool ws_init(workspace *w, uint32_t S, int n, int k)
{
    memset(w, 0, sizeof *w);
    w->offset = malloc(((size_t)S + 1) * sizeof *w->offset);
    w->back = malloc((size_t)(k > 0 ? k : 1) * sizeof *w->back);
    w->scratch = malloc(RL_LS_ENUM_SCRATCH(n) * sizeof *w->scratch);
    w->iscratch = malloc((size_t)4 * (size_t)(n * n) * sizeof *w->iscratch);
    return w->offset && w->back && w->scratch && w->iscratch;
}

static void ws_free(workspace *w)
{
    free(w->entries);
    free(w->sorted);
    free(w->offset);
    free(w->back);
    free(w->scratch);
    free(w->iscratch);
    free(w->tris);
    free(w->stage.start);
    free(w->stage.fixed);
    free(w->stage.pnmt);
    free(w->stage.preillum);
    free(w->stage.pending);
}

static bool ws_reserve(workspace *w, size_t need)
{
    if (need <= w->capacity)
        return true;
    size_t cap = w->capacity ? w->capacity : 4096;
    while (cap < need)
        cap *= 2;
    rl_ls_entry *a = realloc(w->entries, cap * sizeof *a);
    if (!a)
        return false;
    w->entries = a;
    rl_ls_entry *b = realloc(w->sorted, cap * sizeof *b);
    if (!b)
        return false;
    w->sorted = b;
    w->capacity = cap;
    return true;
}

static bool ws_reserve_tris(workspace *w, size_t need)
{
    if (need <= w->tri_capacity)
        return true;
    size_t cap = w->tri_capacity ? w->tri_capacity : 256;
    while (cap < need)
        cap *= 2;
    tri_info *t = realloc(w->tris, cap * sizeof *t);
    if (!t)
        return false;
    w->tris = t;
    w->tri_capacity = cap;
    return true;
}

static inline bool front_less(const rl_ls_entry *a, const rl_ls_entry *b)
{
    return a->key_front < b->key_front || (a->key_front == b->key_front && a->tri < b->tri);
}

static inline bool back_less(const rl_ls_entry *a, const rl_ls_entry *b)
{
    return a->key_back > b->key_back || (a->key_back == b->key_back && a->tri < b->tri);
}

static void insertion_sort(rl_ls_entry *e, uint32_t m, bool back);

/* Bottom-up merge sort through tmp (m entries); no allocation. */
static void merge_sort(rl_ls_entry *e, uint32_t m, rl_ls_entry *tmp)
{
    const uint32_t run = 16;
    for (uint32_t i = 0; i < m; i += run)
        insertion_sort(e + i, m - i < run ? m - i : run, false);
    rl_ls_entry *src = e, *dst = tmp;
    for (uint32_t width = run; width < m; width *= 2) {
        for (uint32_t i = 0; i < m; i += 2 * width) {
            uint32_t mid = i + width < m ? i + width : m, end = i + 2 * width < m ? i + 2 * width : m;
            uint32_t a = i, b = mid, o = i;
            while (a < mid && b < end)
                dst[o++] = front_less(&src[b], &src[a]) ? src[b++] : src[a++];
            while (a < mid)
                dst[o++] = src[a++];
            while (b < end)
                dst[o++] = src[b++];
        }
        rl_ls_entry *t = src;
        src = dst;
        dst = t;
    }
    if (src != e)
        memcpy(e, src, m * sizeof *e);
}

static void sort_entries(rl_ls_entry *e, uint32_t m, bool back)
{
    insertion_sort(e, m, back);
}

static void insertion_sort(rl_ls_entry *e, uint32_t m, bool back)
{
    for (uint32_t i = 1; i < m; ++i) {
        rl_ls_entry x = e[i];
        uint32_t j = i;
        for (; j > 0 && (back ? back_less(&x, &e[j - 1]) : front_less(&x, &e[j - 1])); --j)
            e[j] = e[j - 1];
        e[j] = x;
    }
}

void rl_ls_surface_at(const rl_linespace *ls, uint32_t tri, float u, float v, rl_ls_surface *s)
{
    const rl_scene_data *d = ls->data;
    const uint32_t *idx = d->indices + 3 * (size_t)tri;
    float w = 1.0f - u - v;
    const rl_vec3 *p = ls->grid->tri_verts + 3 * (size_t)tri;
    s->p = rl_add(rl_add(rl_scale(p[0], w), rl_scale(p[1], u)), rl_scale(p[2], v));
    rl_vec3 n = rl_add(rl_add(rl_scale(d->normals[idx[0]], w), rl_scale(d->normals[idx[1]], u)),
                       rl_scale(d->normals[idx[2]], v));
    float len = rl_length(n);
    if (!(len > 0.0f)) {
        n = rl_cross(rl_sub(p[1], p[0]), rl_sub(p[2], p[0]));
        len = rl_length(n);
    }
    s->n = len > 0.0f ? rl_scale(n, 1.0f / len) : rl_v3(0.0f, 0.0f, 1.0f);
    rl_vec2 a = d->uvs[idx[0]], b = d->uvs[idx[1]], c = d->uvs[idx[2]];
    s->uv = rl_v2(a.x * w + b.x * u + c.x * v, a.y * w + b.y * u + c.y * v);
    s->material = d->triangle_material[tri];
}

/* The barycentrics a record stores for shaft entry e: the midpoint ray's
 * hit, or (no hit) those of the point closest to the axis at the entry's
 * key. */
static void record_bary(const double v[3][3], const double a[3], const double b[3],
                        const rl_ls_entry *e, bool front, double *u, double *w)
{
    *u = e->u;
    *w = e->w;
    if (!(e->shaft & RL_LS_ENTRY_HIT)) {
        double key = front ? e->key_front : e->key_back;
        key = key < 0.0 ? 0.0 : (key > 1.0 ? 1.0 : key);
        double q[3] = { a[0] + (b[0] - a[0]) * key, a[1] + (b[1] - a[1]) * key,
                        a[2] + (b[2] - a[2]) * key };
        rl_ls_closest_point(v, q, u, w);
    }
}

/* The stored point in cell units, clamped to the voxel. */
static inline void record_unit(const double v[3][3], double u, double w, double unit[3])
{
    for (int k = 0; k < 3; ++k) {
        double x = (1.0 - u - w) * v[0][k] + u * v[1][k] + w * v[2][k];
        unit[k] = x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
    }
}

/* 8 floats to half floats, as rl_half_from_float does one by one: with
 * F16C one instruction (round to nearest even, the same rounding, overflow
 * and subnormals); a NaN takes the scalar path, which drops its payload. */
static inline void halves8(uint16_t *r, const float f[8])
{
#ifdef __F16C__
    __m256 x = _mm256_loadu_ps(f);
    if (!_mm256_movemask_ps(_mm256_cmp_ps(x, x, _CMP_UNORD_Q))) {
        _mm_storeu_si128((__m128i *)(void *)r, _mm256_cvtps_ph(x, _MM_FROUND_TO_NEAREST_INT));
        return;
    }
#endif
    for (int i = 0; i < 8; ++i)
        r[i] = rl_half_from_float(f[i]);
}

/* One PNMT record (Sec. 7.4, eq. 9: n_z's sign rides on the material ID +
 * 1) at barycentrics (u, w) of triangle t. The normal and uv use the same
 * float operations as rl_ls_surface_at, from the cached vertex data. */
static void pnmt_record(const rl_linespace *ls, const tri_info *t, double u, double w, uint16_t *r)
{
    float fu = (float)u, fv = (float)w, fw = 1.0f - fu - fv;
    rl_vec3 n = rl_add(rl_add(rl_scale(t->n[0], fw), rl_scale(t->n[1], fu)), rl_scale(t->n[2], fv));
    float len = rl_length(n);
    if (!(len > 0.0f)) {
        const rl_vec3 *p = ls->grid->tri_verts + 3 * (size_t)t->id;
        n = rl_cross(rl_sub(p[1], p[0]), rl_sub(p[2], p[0]));
        len = rl_length(n);
    }
    n = len > 0.0f ? rl_scale(n, 1.0f / len) : rl_v3(0.0f, 0.0f, 1.0f);
    double unit[3];
    record_unit(t->v, u, w, unit);
    float f[8];
    f[RL_LS_PNMT_PX] = (float)unit[0];
    f[RL_LS_PNMT_PY] = (float)unit[1];
    f[RL_LS_PNMT_PZ] = (float)unit[2];
    f[RL_LS_PNMT_NX] = n.x;
    f[RL_LS_PNMT_NY] = n.y;
    f[RL_LS_PNMT_MAT] = n.z < 0.0f ? -t->mat1 : t->mat1;
    f[RL_LS_PNMT_U] = t->uv[0].x * fw + t->uv[1].x * fu + t->uv[2].x * fv;
    f[RL_LS_PNMT_V] = t->uv[0].y * fw + t->uv[1].y * fu + t->uv[2].y * fv;
    halves8(r, f);
}

/* Whether entry e's midpoint-ray hit lies in a hole of an alpha mask. */
static inline bool in_hole(const rl_linespace *ls, const tri_info *tris, const rl_ls_entry *e)
{
    return ls->masked && rl_alpha_masked(ls->data, tris[e->tri].id, e->u, e->w);
}

/* Front and back picks of a list sorted front to back: the first midpoint
 * ray hit in front order; the hit with the largest parameter (lowest ID on
 * ties); without hits the front-most and back-most candidates. Hits in the
 * holes of alpha masks are no surfaces: where the midpoint ray meets only
 * holes there is none, and pick_records returns false (the records say
 * "empty", which the queries read as a free shaft). */
static inline bool pick_records(const rl_linespace *ls, const tri_info *tris, const rl_ls_entry *list,
                                uint32_t m, const rl_ls_entry **ef_out, const rl_ls_entry **eb_out)
{
    const rl_ls_entry *ef = NULL, *eb = NULL;
    bool holes = false;
    for (uint32_t i = 0; i < m; ++i)
        if (list[i].shaft & RL_LS_ENTRY_HIT) {
            if (in_hole(ls, tris, &list[i])) {
                holes = true;
                continue;
            }
            if (!ef)
                ef = &list[i];
            if (!eb || list[i].key_back > eb->key_back)
                eb = &list[i];
        }
    if (!ef && holes)
        return false;
    if (!ef) {
        ef = eb = &list[0];
        for (uint32_t i = 1; i < m; ++i)
            if (back_less(&list[i], eb))
                eb = &list[i];
    }
    *ef_out = ef;
    *eb_out = eb;
    return true;
}

/* The PNMT record of an occupied shaft (pn: 16 halves) from its list of m
 * >= 1 entries sorted front to back; a, b: the patch centres (midpoint ray)
 * in cell units. */
static void shaft_pnmt(const rl_linespace *ls, const tri_info *tris, const rl_ls_entry *list,
                       uint32_t m, uint16_t *pn, const double a[3], const double b[3])
{
    const rl_ls_entry *ef, *eb;
    if (!pick_records(ls, tris, list, m, &ef, &eb)) {
        memset(pn, 0, 2 * RL_LS_PNMT_RECORD * sizeof *pn);   /* material 0: empty */
        return;
    }
    double u, w;
    const tri_info *t = &tris[ef->tri];
    record_bary(t->v, a, b, ef, true, &u, &w);
    pnmt_record(ls, t, u, w, pn);
    /* One triangle hit by the midpoint ray both ways: the same record. */
    if (ef == eb && (ef->shaft & RL_LS_ENTRY_HIT)) {
        memcpy(pn + RL_LS_PNMT_RECORD, pn, RL_LS_PNMT_RECORD * sizeof *pn);
        return;
    }
    t = &tris[eb->tri];
    record_bary(t->v, a, b, eb, false, &u, &w);
    pnmt_record(ls, t, u, w, pn + RL_LS_PNMT_RECORD);
}

/* The PREILLUM record (pi: 8 halves) of an occupied shaft, as shaft_pnmt. */
static void shaft_preillum(const rl_linespace *ls, const tri_info *tris, const rl_ls_entry *list,
                           uint32_t m, uint16_t *pi, const double a[3], const double bb[3],
                           const double lo[3], const double ext[3])
{
    const rl_ls_entry *pick[2];
    if (!pick_records(ls, tris, list, m, &pick[0], &pick[1])) {
        memset(pi, 0, 8 * sizeof *pi);                       /* alpha 0: empty */
        return;
    }
    for (int side = 0; side < 2; ++side) {
        const tri_info *t = &tris[pick[side]->tri];
        double u, w;
        record_bary(t->v, a, bb, pick[side], side == 0, &u, &w);
        rl_ls_surface surf;
        rl_ls_surface_at(ls, t->id, (float)u, (float)w, &surf);
        /* Sec. 7.3: shaded for the direction the ray travels when it
         * reaches the surface. */
        rl_vec3 wa = rl_v3((float)(lo[0] + a[0] * ext[0]), (float)(lo[1] + a[1] * ext[1]),
                           (float)(lo[2] + a[2] * ext[2]));
        rl_vec3 wb = rl_v3((float)(lo[0] + bb[0] * ext[0]), (float)(lo[1] + bb[1] * ext[1]),
                           (float)(lo[2] + bb[2] * ext[2]));
        rl_vec3 dir = rl_normalize(side == 0 ? rl_sub(wb, wa) : rl_sub(wa, wb));
        surf.t = rl_length(rl_sub(surf.p, side == 0 ? wa : wb));
        rl_vec3 c = ls->shade(ls->shade_user, &surf, dir);
        uint16_t *q = pi + side * 4;
        q[0] = rl_half_from_float(c.x);
        q[1] = rl_half_from_float(c.y);
        q[2] = rl_half_from_float(c.z);
        q[3] = rl_half_from_float(1.0f);
    }
}

/* One thread's store for the dynamic lists of its blocks until they are
 * copied into place: chunks of RL_LS_ARENA_CHUNK entries or more (on huge
 * pages, rl_big_alloc) instead of one malloc per block, whose fresh pages
 * cost a 4 KiB fault each; the lists are 4 bytes per candidate, as much
 * as the final array. */
#define RL_LS_ARENA_CHUNK ((size_t)4 << 20)

typedef struct list_arena {
    uint32_t **chunk;
    size_t count, cap;
    size_t used, size;            /* entries of the last chunk */
} list_arena;

/* Room for n contiguous entries, or NULL when out of memory. */
static uint32_t *arena_take(list_arena *a, size_t n, bool huge)
{
    if (a->count == 0 || a->size - a->used < n) {
        if (a->count == a->cap) {
            size_t cap = a->cap ? 2 * a->cap : 16;
            uint32_t **c = realloc(a->chunk, cap * sizeof *c);
            if (!c)
                return NULL;
            a->chunk = c;
            a->cap = cap;
        }
        size_t size = n > RL_LS_ARENA_CHUNK ? n : RL_LS_ARENA_CHUNK;
        uint32_t *c = rl_big_alloc(size * sizeof *c, huge);
        if (!c)
            return NULL;
        a->chunk[a->count++] = c;
        a->size = size;
        a->used = 0;
    }
    uint32_t *p = a->chunk[a->count - 1] + a->used;
    a->used += n;
    return p;
}

static void arena_free(list_arena *a)
{
    for (size_t i = 0; i < a->count; ++i)
        free(a->chunk[i]);
    free(a->chunk);
}

typedef struct voxel_stats {
    uint64_t empty, stored, truncated, sum;
    uint32_t max;
} voxel_stats;

/* Step 1 of a block (grid cell `cell`): the sorted list of every shaft in
 * w->sorted / w->offset and the block's occupancy bits; w->occupied gets
 * the number of occupied shafts. Dynamic lists: the block's lists go to
 * *dyn_block in the thread's arena (rl_ls_build copies them into place)
 * and *dyn_count gets their total. Returns false on out of memory. */
static bool build_lists(rl_linespace *ls, const rl_ls_geometry *geo, workspace *w, uint32_t b,
                        uint32_t cell, list_arena *arena, uint32_t **dyn_block, uint64_t *dyn_count,
                        voxel_stats *vs)
{
    const rl_grid *g = ls->grid;
    const rl_scene_data *d = ls->data;
    const uint32_t S = ls->shafts_per_voxel;
    int xyz[3];
    rl_grid_cell_coords(g, cell, xyz);
    rl_aabb box = rl_grid_cell_bounds(g, xyz[0], xyz[1], xyz[2]);
    double inv_ext[3];
    for (int a = 0; a < 3; ++a) {
        w->lo[a] = rl_vget(box.min, a);
        w->ext[a] = (double)rl_vget(box.max, a) - w->lo[a];
        inv_ext[a] = 1.0 / w->ext[a];
    }
    /* Alg. 3's loops, turned around: per triangle, the shafts it overlaps.
     * Entries carry the triangle's index in the cell's list, which is sorted
     * by ID, so ties by local index are ties by ID. */
    const uint32_t first = g->cell_start[cell], ntri = g->cell_start[cell + 1] - first;
    const uint32_t *ids = g->cell_tris + first;
    if (!ws_reserve_tris(w, ntri))
        return false;
    const bool records = ls->pnmt || ls->preillum;
    size_t nent = 0;
    for (uint32_t j = 0; j < ntri; ++j) {
        uint32_t id = ids[j];
        if (!ws_reserve(w, nent + S))
            return false;
        tri_info *ti = &w->tris[j];
        const rl_vec3 *p = g->tri_verts + 3 * (size_t)id;
        double pu[3][3];
        for (int i = 0; i < 3; ++i)
            for (int a = 0; a < 3; ++a)
                ti->v[i][a] = pu[i][a] = ((double)rl_vget(p[i], a) - w->lo[a]) * inv_ext[a];
        ti->id = id;
        if (records) {
            const uint32_t *idx = d->indices + 3 * (size_t)id;
            for (int i = 0; i < 3; ++i) {
                ti->n[i] = d->normals[idx[i]];
                ti->uv[i] = d->uvs[idx[i]];
            }
            ti->mat1 = (float)d->triangle_material[id] + 1.0f;
        }
        rl_ls_tri t;
        if (!rl_ls_tri_setup(&t, pu))
            continue;
        nent += rl_ls_enumerate(geo, &t, j, w->entries + nent, w->scratch, w->iscratch);
    }
    /* Counting sort by shaft. */
    uint32_t *off = w->offset;
    memset(off, 0, ((size_t)S + 1) * sizeof *off);
    for (size_t i = 0; i < nent; ++i)
        ++off[(w->entries[i].shaft & ~RL_LS_ENTRY_HIT) + 1];
    for (uint32_t s = 0; s < S; ++s)
        off[s + 1] += off[s];
    for (size_t i = 0; i < nent; ++i) {
        uint32_t s = w->entries[i].shaft & ~RL_LS_ENTRY_HIT;
        w->sorted[off[s]++] = w->entries[i];
    }
    for (uint32_t s = S; s > 0; --s)
        off[s] = off[s - 1];
    off[0] = 0;

    uint32_t *dyn = NULL;
    if ((ls->payloads & RL_LS_CANDIDATES) && ls->dynamic) {
        dyn = arena_take(arena, nent ? nent : 1, ls->huge_pages);
        if (!dyn)
            return false;
        *dyn_block = dyn;
        *dyn_count = nent;
    }
    uint32_t occupied = 0;
    for (uint32_t s = 0; s < S; ++s) {
        rl_ls_entry *list = w->sorted + off[s];
        uint32_t m = off[s + 1] - off[s];
        if (m > 16)
            merge_sort(list, m, w->entries);   /* free after the scatter */
        else if (m > 1)
            insertion_sort(list, m, false);
        if (m == 0) {
            ++vs->empty;
            continue;
        }
        rl_ls_shaft_mark(ls, b, s);
        ++occupied;
        vs->sum += m;
        if (m > vs->max)
            vs->max = m;
        if (dyn) {
            for (uint32_t i = 0; i < m; ++i)
                dyn[off[s] + i] = ids[list[i].tri];
            vs->stored += m;
        }
    }
    w->occupied = occupied;
    return true;
}

/* Where step 2 writes a block's per-shaft data: the final arrays at the
 * block's rank (its base known), or the thread's staging area. */
typedef struct rec_dst {
    uint32_t *start;              /* dynamic: start[j] = start_base + offset in the block */
    uint32_t start_base;
    uint32_t *fixed;              /* fixed lists, k per occupied shaft */
    uint16_t *pnmt, *preillum;
} rec_dst;

/* Step 2 of a block: the lists and records of its occupied shafts, in
 * shaft order, from step 1's sorted lists. */
static void write_records(const rl_linespace *ls, const rl_ls_geometry *geo, workspace *w,
                          const rec_dst *dst, voxel_stats *vs)
{
    const uint32_t S = ls->shafts_per_voxel;
    const uint32_t *off = w->offset;
    const uint32_t *ids = ls->grid->cell_tris + ls->grid->cell_start[w->cell];
    if (dst->start || dst->fixed) {
        const int k = ls->k;
        uint32_t j = 0;
        for (uint32_t s = 0; s < S; ++s) {
            uint32_t m = off[s + 1] - off[s];
            if (m == 0)
                continue;
            if (dst->start) {
                dst->start[j++] = dst->start_base + off[s];
                continue;
            }
            const rl_ls_entry *list = w->sorted + off[s];
            uint32_t *slot = dst->fixed + (size_t)j++ * (size_t)k;
            uint32_t half = (uint32_t)k / 2, nf = m < half ? m : half;
            for (uint32_t i = 0; i < half; ++i)
                slot[i] = i < nf ? ids[list[i].tri] : RL_NONE;
            /* Alg. 3: the back buffer holds the k/2 back-most, back to front. */
            uint32_t cnt = 0;
            for (uint32_t i = 0; i < m; ++i) {
                if (cnt < half) {
                    w->back[cnt++] = list[i];
                    sort_entries(w->back, cnt, true);
                } else if (back_less(&list[i], &w->back[half - 1])) {
                    w->back[half - 1] = list[i];
                    sort_entries(w->back, half, true);
                }
            }
            for (uint32_t i = 0; i < half; ++i)
                slot[half + i] = i < nf ? ids[w->back[i].tri] : RL_NONE;
            vs->stored += 2 * (uint64_t)nf;
            if (m > (uint32_t)k)
                ++vs->truncated;
        }
    }
    /* PNMT and PREILLUM in separate passes over the sorted lists (still in
     * cache), so that each gets its own time. */
    for (int payload = 0; payload < 2; ++payload) {
        bool pnmt = payload == 0;
        if (pnmt ? !dst->pnmt : !dst->preillum)
            continue;
        rl_timer timer;
        rl_timer_start(&timer);
        /* Shafts in index order: face pair, then patch A, then patch B. */
        const int np = ls->n * ls->n;
        uint32_t s = 0, j = 0;
        for (int pair = 0; pair < RL_LS_FACE_PAIRS; ++pair) {
            int fa, fb;
            rl_ls_pair_faces(pair, &fa, &fb);
            for (int pa = 0; pa < np; ++pa) {
                const float *ca = geo->patch_center + ((size_t)fa * (size_t)np + (size_t)pa) * 3;
                double a[3] = { ca[0], ca[1], ca[2] };
                for (int pb = 0; pb < np; ++pb, ++s) {
                    uint32_t m = off[s + 1] - off[s];
                    if (m == 0)
                        continue;
                    const float *cb = geo->patch_center + ((size_t)fb * (size_t)np + (size_t)pb) * 3;
                    double bb[3] = { cb[0], cb[1], cb[2] };
                    const rl_ls_entry *list = w->sorted + off[s];
                    if (pnmt)
                        shaft_pnmt(ls, w->tris, list, m, dst->pnmt + (size_t)j * 16, a, bb);
                    else
                        shaft_preillum(ls, w->tris, list, m, dst->preillum + (size_t)j * 8, a, bb,
                                       w->lo, w->ext);
                    ++j;
                }
            }
        }
        *(pnmt ? &w->pnmt_s : &w->preillum_s) += rl_timer_ms(&timer);
    }
}

/* The ranks of the blocks' occupied shafts. Blocks are built in parallel
 * and in any order, but a block's records go to the rank of its first
 * occupied shaft, the sum over all blocks before it. Each block publishes
 * its counts after step 1; the frontier F is the number of leading blocks
 * whose counts are all known, so base[b] is final for b <= F. A block
 * behind the frontier is written straight into place; one ahead of it is
 * staged by its thread and copied once its base is known (no thread ever
 * waits for another inside the pass). */
typedef struct rank_chain {
    uint32_t blocks;
    uint32_t *occ;                /* per block: occupied shafts */
    uint64_t *cand;               /* per block: dynamic candidates */
    unsigned char *known;
    uint64_t *base_occ, *base_cand;   /* blocks + 1 */
    atomic_uint frontier;
} rank_chain;

static uint32_t chain_publish(rank_chain *c, uint32_t b, uint32_t occ, uint64_t cand)
{
    uint32_t f;
    #pragma omp critical(rl_ls_chain)
    {
        c->occ[b] = occ;
        c->cand[b] = cand;
        c->known[b] = 1;
        f = atomic_load_explicit(&c->frontier, memory_order_relaxed);
        while (f < c->blocks && c->known[f]) {
            c->base_occ[f + 1] = c->base_occ[f] + c->occ[f];
            c->base_cand[f + 1] = c->base_cand[f] + c->cand[f];
            ++f;
        }
        atomic_store_explicit(&c->frontier, f, memory_order_release);
    }
    return f;
}

static void final_dst(const rl_linespace *ls, const rank_chain *c, uint32_t b, rec_dst *d)
{
    uint64_t r = c->base_occ[b];
    d->start = ls->dynamic && ls->cand_start ? ls->cand_start + r : NULL;
    d->start_base = (uint32_t)c->base_cand[b];
    d->fixed = !ls->dynamic && ls->cand ? ls->cand + r * (uint64_t)ls->k : NULL;
    d->pnmt = ls->pnmt ? ls->pnmt + r * 16 : NULL;
    d->preillum = ls->preillum ? ls->preillum + r * 8 : NULL;
}

/* The rank of each occupancy word of block b. */
static void write_rank(rl_linespace *ls, uint32_t b, uint64_t base)
{
    uint64_t *w = ls->occupied + 2 * (uint64_t)b * ls->occ_words;
    for (uint32_t i = 0; i < ls->occ_words; ++i) {
        w[2 * i + 1] = base;
        base += (uint64_t)__builtin_popcountll(w[2 * i]);
    }
}

/* realloc of *p to count items; false (and *p kept) when out of memory. */
#define grow(p, count, size) grow_to((void **)(p), (count), (size))
static bool grow_to(void **p, size_t count, size_t size)
{
    void *q = rl_realloc_array(*p, count, size);
    if (!q)
        return false;
    *p = q;
    return true;
}

/* Room for `count` more staged records; false when out of memory. */
static bool stage_reserve(const rl_linespace *ls, staging *st, size_t count)
{
    size_t cap = rl_grow_capacity(st->capacity, st->used + count, 1024);
    if (cap == st->capacity)
        return true;
    if (ls->dynamic && ls->cand_start && !grow(&st->start, cap, sizeof *st->start))
        return false;
    if (!ls->dynamic && ls->cand && !grow(&st->fixed, cap * (size_t)ls->k, sizeof *st->fixed))
        return false;
    if (ls->pnmt && !grow(&st->pnmt, cap * 16, sizeof *st->pnmt))
        return false;
    if (ls->preillum && !grow(&st->preillum, cap * 8, sizeof *st->preillum))
        return false;
    st->capacity = cap;
    return true;
}

static bool stage_block(const rl_linespace *ls, staging *st, uint32_t b, uint32_t count, rec_dst *d)
{
    if (!stage_reserve(ls, st, count) ||
        !rl_reserve((void **)&st->pending, &st->pending_cap, st->npending + 1, sizeof *st->pending, 16))
        return false;
    size_t at = st->used;
    st->pending[st->npending++] = (staged_block){ b, count, at };
    st->used += count;
    d->start = st->start ? st->start + at : NULL;
    d->start_base = 0;
    d->fixed = st->fixed ? st->fixed + at * (size_t)ls->k : NULL;
    d->pnmt = st->pnmt ? st->pnmt + at * 16 : NULL;
    d->preillum = st->preillum ? st->preillum + at * 8 : NULL;
    return true;
}

/* Copies the staged blocks whose base is known into place. */
static void stage_flush(rl_linespace *ls, staging *st, const rank_chain *c)
{
    uint32_t f = atomic_load_explicit(&c->frontier, memory_order_acquire);
    uint32_t kept = 0;
    for (uint32_t i = 0; i < st->npending; ++i) {
        staged_block p = st->pending[i];
        if (p.block > f) {
            st->pending[kept++] = p;
            continue;
        }
        rec_dst d;
        final_dst(ls, c, p.block, &d);
        if (d.start)
            for (uint32_t j = 0; j < p.count; ++j)
                d.start[j] = d.start_base + st->start[p.at + j];
        if (d.fixed)
            memcpy(d.fixed, st->fixed + p.at * (size_t)ls->k, (size_t)p.count * (size_t)ls->k * sizeof *d.fixed);
        if (d.pnmt)
            memcpy(d.pnmt, st->pnmt + p.at * 16, (size_t)p.count * 16 * sizeof *d.pnmt);
        if (d.preillum)
            memcpy(d.preillum, st->preillum + p.at * 8, (size_t)p.count * 8 * sizeof *d.preillum);
        write_rank(ls, p.block, c->base_occ[p.block]);
    }
    st->npending = kept;
    if (kept == 0)
        st->used = 0;
}

void rl_ls_free_arrays(rl_linespace *ls)
{
    free(ls->voxel_slot);
    free(ls->cand);
    free(ls->cand_start);
    free(ls->pnmt);
    free(ls->preillum);
    free(ls->occupied);
    ls->voxel_slot = ls->cand = ls->cand_start = NULL;
    ls->pnmt = ls->preillum = NULL;
    ls->occupied = NULL;
}

/* Shrinks an array allocated for every shaft to the occupied ones (the
 * untouched tail was never faulted in; realloc gives it back). */
static void shrink(void **p, uint64_t count, size_t size)
{
    if (!*p)
        return;
    void *q = realloc(*p, (size_t)(count ? count : 1) * size);
    if (q)
        *p = q;
}

static void chain_free(rank_chain *c)
{
    free(c->occ);
    free(c->cand);
    free(c->known);
    free(c->base_occ);
    free(c->base_cand);
}

/* What one build holds besides the Line Space itself, released together
 * by build_free(). */
typedef struct build_ctx {
    uint32_t blocks;              /* filled voxels */
    uint64_t shafts;              /* blocks x shafts per voxel */
    bool want_cand;
    int threads;
    uint32_t *cells;              /* block -> grid cell */
    uint32_t **dyn;               /* dynamic lists per block, or NULL */
    uint64_t *dyn_count;
    list_arena *arenas;           /* per thread, with dynamic lists */
    rank_chain chain;
    rl_ls_geometry geo;
} build_ctx;

static void build_free(build_ctx *b)
{
    if (b->arenas)
        for (int t = 0; t < b->threads; ++t)
            arena_free(&b->arenas[t]);
    free(b->arenas);
    free(b->dyn);
    free(b->dyn_count);
    free(b->cells);
    chain_free(&b->chain);
    rl_ls_geometry_free(&b->geo);
}

/* The voxel slots (a block per filled voxel), the rank chain and every
 * per-shaft array, sized for all shafts: they are shrunk to the occupied
 * ones afterwards, and only the pages written are ever faulted in. */
static rl_status build_alloc(rl_linespace *ls, build_ctx *b)
{
    const rl_grid *g = ls->grid;
    ls->num_cells = g->num_cells;
    ls->voxel_slot = malloc((size_t)g->num_cells * sizeof *ls->voxel_slot);
    if (!ls->voxel_slot)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "linespace: out of memory for %u voxel slots", g->num_cells);
    uint32_t blocks = 0;
    for (uint32_t c = 0; c < g->num_cells; ++c)
        ls->voxel_slot[c] = g->cell_start[c + 1] > g->cell_start[c] ? blocks++ : RL_NONE;
    ls->num_blocks = blocks;
    b->blocks = blocks;
    b->shafts = (uint64_t)blocks * ls->shafts_per_voxel;
    if (b->shafts > UINT32_MAX - 1u)
        return rl_error(RL_ERR_LIMIT, "linespace: %u filled voxels x %u shafts = %llu shafts exceed 2^32-1", blocks,
                        ls->shafts_per_voxel, (unsigned long long)b->shafts);
    b->want_cand = (ls->payloads & RL_LS_CANDIDATES) != 0;
#ifdef _OPENMP
    b->threads = ls->threads > 0 ? ls->threads : omp_get_max_threads();
#else
    b->threads = 1;
#endif
    size_t nb = (size_t)(blocks ? blocks : 1), shafts = (size_t)(b->shafts ? b->shafts : 1);
    b->cells = malloc(nb * sizeof *b->cells);
    b->chain = (rank_chain){ .blocks = blocks };
    b->chain.occ = malloc(nb * sizeof *b->chain.occ);
    b->chain.cand = malloc(nb * sizeof *b->chain.cand);
    b->chain.known = calloc(nb, 1);
    b->chain.base_occ = malloc((nb + 1) * sizeof *b->chain.base_occ);
    b->chain.base_cand = malloc((nb + 1) * sizeof *b->chain.base_cand);
    atomic_init(&b->chain.frontier, 0u);
    bool ok = b->cells && b->chain.occ && b->chain.cand && b->chain.known && b->chain.base_occ &&
              b->chain.base_cand;
    if (ok) {
        for (uint32_t c = 0; c < g->num_cells; ++c)
            if (ls->voxel_slot[c] != RL_NONE)
                b->cells[ls->voxel_slot[c]] = c;
        b->chain.base_occ[0] = b->chain.base_cand[0] = 0;
    }
    if (ok && b->want_cand && ls->dynamic) {
        ls->cand_start = rl_big_alloc((shafts + 1) * sizeof *ls->cand_start, ls->huge_pages);
        b->dyn = calloc(nb, sizeof *b->dyn);
        b->dyn_count = calloc(nb, sizeof *b->dyn_count);
        b->arenas = calloc((size_t)b->threads, sizeof *b->arenas);
        ok = ls->cand_start && b->dyn && b->dyn_count && b->arenas;
    } else if (ok && b->want_cand) {
        ok = (ls->cand = rl_big_alloc(shafts * (size_t)ls->k * sizeof *ls->cand, ls->huge_pages)) != NULL;
    }
    if (ok && (ls->payloads & RL_LS_PNMT))
        ok = (ls->pnmt = rl_big_alloc(shafts * 16 * sizeof *ls->pnmt, ls->huge_pages)) != NULL;
    if (ok && (ls->payloads & RL_LS_PREILLUM))
        ok = (ls->preillum = rl_big_alloc(shafts * 8 * sizeof *ls->preillum, ls->huge_pages)) != NULL;
    if (ok)
        ok = rl_ls_occupancy_alloc(ls);
    if (ok)
        ok = rl_ls_geometry_init(&b->geo, ls->n) == RL_OK;
    return ok ? RL_OK
              : rl_error(RL_ERR_OUT_OF_MEMORY, "linespace: out of memory for %llu shafts",
                         (unsigned long long)b->shafts);
}

/* The pass over the filled voxels (Sec. 7.1, 7.4): per block its shafts'
 * lists, published to the rank chain, and its records. Returns 0, or 1 (out
 * of memory) or 2 (cancelled); fills the fill statistics and the threads'
 * time spent in the payloads. */
static int build_pass(rl_linespace *ls, build_ctx *b, voxel_stats *total_vs, double *pnmt_s, double *preillum_s)
{
    const uint32_t S = ls->shafts_per_voxel, blocks = b->blocks;
    rank_chain *chain = &b->chain;
    atomic_int failed = 0;        /* 1: out of memory, 2: cancelled */
    atomic_uint next = 0, done = 0;
    #pragma omp parallel num_threads(b->threads)
    {
        workspace w;
        voxel_stats vs = { 0 };
        if (!ws_init(&w, S, ls->n, ls->k))
            atomic_store(&failed, 1);
        bool main_thread = true;
        list_arena *arena = b->arenas;
#ifdef _OPENMP
        main_thread = omp_get_thread_num() == 0;
        if (b->arenas)
            arena += omp_get_thread_num();
#endif
        /* Blocks are claimed in increasing order, so the frontier always
         * advances: every claimed block publishes its counts right after
         * step 1, without waiting. */
        for (;;) {
            uint32_t bi = atomic_fetch_add(&next, 1u);
            if (bi >= blocks || atomic_load(&failed))
                break;
            w.cell = b->cells[bi];
            if (!build_lists(ls, &b->geo, &w, bi, b->cells[bi], arena, b->dyn ? &b->dyn[bi] : NULL,
                             b->dyn ? &b->dyn_count[bi] : NULL, &vs)) {
                atomic_store(&failed, 1);
                break;
            }
            uint32_t f = chain_publish(chain, bi, w.occupied, b->dyn ? b->dyn_count[bi] : 0);
            rec_dst dst;
            bool placed = bi <= f;
            if (placed)
                final_dst(ls, chain, bi, &dst);
            else if (!stage_block(ls, &w.stage, bi, w.occupied, &dst)) {
                atomic_store(&failed, 1);
                break;
            }
            write_records(ls, &b->geo, &w, &dst, &vs);
            if (placed)
                write_rank(ls, bi, chain->base_occ[bi]);
            if (w.stage.npending)
                stage_flush(ls, &w.stage, chain);
            unsigned d = atomic_fetch_add(&done, 1u) + 1u;
            if (ls->progress && main_thread && !ls->progress(ls->user, 0.95 * d / (double)blocks))
                atomic_store(&failed, 2);
        }
        /* The staged blocks wait only for blocks other threads have
         * already claimed. */
        while (w.stage.npending && !atomic_load(&failed)) {
            stage_flush(ls, &w.stage, chain);
            if (w.stage.npending)
                sched_yield();
        }
        #pragma omp critical(rl_ls_stats)
        {
            total_vs->empty += vs.empty;
            total_vs->stored += vs.stored;
            total_vs->truncated += vs.truncated;
            total_vs->sum += vs.sum;
            if (vs.max > total_vs->max)
                total_vs->max = vs.max;
            *pnmt_s += w.pnmt_s;
            *preillum_s += w.preillum_s;
        }
        ws_free(&w);
    }
    int fail = atomic_load(&failed);
    /* Only the main thread reports inside the pass, and under dynamic
     * scheduling it may have built no block at all (a busy machine, few
     * blocks): report the pass's end once more, so that a cancel is never
     * missed. */
    if (!fail && ls->progress && !ls->progress(ls->user, 0.95))
        fail = 2;
    return fail;
}

/* After the pass: the dynamic lists copied into place (Sec. 7.1.1's prefix
 * sum: the chain has summed the blocks' list lengths and the offsets are
 * already global), then every per-shaft array shrunk to the occupied
 * shafts. Returns 0, 1 (out of memory) or 3 (over 2^32-1 candidates). */
static int build_gather(rl_linespace *ls, build_ctx *b)
{
    uint64_t occupied = b->chain.base_occ[b->blocks];
    if (b->dyn) {
        uint64_t sum = b->chain.base_cand[b->blocks];
        if (sum > UINT32_MAX)
            return 3;
        ls->num_cand = sum;
        ls->cand_start[occupied] = (uint32_t)sum;
        ls->cand = rl_big_alloc((size_t)(sum ? sum : 1) * sizeof *ls->cand, ls->huge_pages);
        if (!ls->cand)
            return 1;
        #pragma omp parallel for num_threads(b->threads) schedule(dynamic, 16)
        for (long bi = 0; bi < (long)b->blocks; ++bi)
            memcpy(ls->cand + b->chain.base_cand[bi], b->dyn[bi], (size_t)b->dyn_count[bi] * sizeof *ls->cand);
    }
    ls->num_occupied = occupied;
    shrink((void **)&ls->cand_start, ls->cand_start ? occupied + 1 : 0, sizeof *ls->cand_start);
    shrink((void **)&ls->pnmt, occupied * 16, sizeof *ls->pnmt);
    shrink((void **)&ls->preillum, occupied * 8, sizeof *ls->preillum);
    if (b->want_cand && !ls->dynamic) {
        ls->num_cand = occupied * (uint64_t)ls->k;
        shrink((void **)&ls->cand, ls->num_cand, sizeof *ls->cand);
    }
    return 0;
}

rl_status rl_ls_build(rl_linespace *ls)
{
    rl_timer total;
    rl_timer_start(&total);
    build_ctx b = { 0 };
    rl_status st = build_alloc(ls, &b);
    if (st != RL_OK) {
        build_free(&b);
        return st;
    }
    voxel_stats vs = { 0 };
    double pnmt_s = 0.0, preillum_s = 0.0;
    rl_timer pass;
    rl_timer_start(&pass);
    int fail = build_pass(ls, &b, &vs, &pnmt_s, &preillum_s);
    double pass_ms = rl_timer_ms(&pass);
    if (!fail)
        fail = build_gather(ls, &b);
    build_free(&b);
    if (fail == 1)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "linespace: out of memory during the build");
    if (fail == 2)
        return rl_error(RL_ERR_CANCELLED, "linespace: build cancelled");
    if (fail == 3)
        return rl_error(RL_ERR_LIMIT, "linespace: more than 2^32-1 candidates");
    if (ls->progress)
        ls->progress(ls->user, 1.0);
    rl_linespace_stats *out = &ls->stats;
    out->filled_voxels = b.blocks;
    out->shafts = b.shafts;
    out->empty_shafts = vs.empty;
    out->candidates = vs.stored;
    out->max_candidates = vs.max;
    out->mean_candidates = b.shafts > vs.empty ? (double)vs.sum / (double)(b.shafts - vs.empty) : 0.0;
    out->truncated_shafts = vs.truncated;
    out->build_ms = rl_timer_ms(&total);
    /* The payloads share one pass over the voxels: split its wall time by
     * the threads' time shares. */
    double thread_ms = pass_ms * b.threads;
    out->pnmt_ms = thread_ms > 0.0 ? pass_ms * (pnmt_s / thread_ms) : 0.0;
    out->preillum_ms = thread_ms > 0.0 ? pass_ms * (preillum_s / thread_ms) : 0.0;
    out->candidates_ms = out->build_ms - out->pnmt_ms - out->preillum_ms;
    return RL_OK;
}
