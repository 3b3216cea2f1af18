/* surfels_build.c: the preprocessing of Progressive Blue Surfels (Jähn 2015,
 * Sec. 6.1.1, 6.1.3): one surfel sequence for a set of objects, every
 * prefix a blue-noise sample of the outside-visible surface (rl_surfels.h).
 *
 * Steps, timed separately as the rows of Table 6.1:
 *   atlas       the objects rendered by src/raster (or desc.atlas_drawer, e.g.
 *               the GL drawer of src/gl), orthographically, from the
 *               8 corners of a cube around their bounds towards its centre
 *               (Sec. 6.1.1: the 6 face directions leave holes even on simple
 *               objects), each view framing the bounding sphere of the bounds
 *               at resolution^2 pixels; depth and triangle IDs only.
 *   candidates  one candidate per covered pixel: the pixel's orthographic ray
 *               cut with the plane of the triangle whose ID the pixel holds,
 *               the barycentrics clamped so the point lies on the triangle;
 *               the vertex normals interpolated and turned towards the view;
 *               colour = k_d times the diffuse texture at the interpolated uv,
 *               unlit (Sec. 6.1.1: "außer der Beleuchtung" every surface
 *               property). relative coverage = covered pixels / 8 resolution^2.
 *   sampling    the progressive best-candidate sequence (Sec. 6.1.1,
 *               "Progressives Sampling"): one random candidate first; then a
 *               random sample of start_sample remaining candidates is drawn and
 *               its member farthest from every chosen surfel is taken; the
 *               same sample serves r rounds (r = 1, +1 every rounds_step
 *               rounds, at most half the sample), each taking the best
 *               remaining member, whose distances are lowered by every newly
 *               chosen surfel. RL_SURFEL_CONSTANT draws a fresh sample every
 *               round, RL_SURFEL_RANDOM takes a uniform random order.
 *   sizes       relative point size (Sec. 6.1.1, "Bestimmung der relativen
 *               Punktgrößen"): the mean cosine between a surfel's normal and
 *               those of its `neighbours` nearest surfels of the sequence,
 *               clamped to [0, 1]: ~1 in the middle of a flat face, lower on
 *               edges and filigree parts.
 * Then the 20-byte packing of Sec. 6.1.3 (rl_surfel).
 *
 * Nearest-chosen queries use a hashed uniform grid (surfels_internal.h)
 * whose cell is the expected spacing sqrt(A / n) of the n surfels chosen so
 * far; it is rebuilt each time n has grown 4x, so a cell keeps holding a
 * handful of surfels while the spacing shrinks. The visible area A is
 * estimated from the views by Cauchy's formula (a convex body's mean
 * projected area is a quarter of its surface): A ~ 4 x mean covered area.
 *
 * Deviations from the thesis:
 *  - it renders positions, normals and colours into textures on the GPU and
 *    reads them back (Table 6.1: 111 ms transfer); we render depth + IDs (on
 *    the CPU, or on GL where only they are read back) and reconstruct each
 *    candidate from its triangle, so positions are exact rather than
 *    texel-rounded;
 *  - no normal maps (our scenes have none);
 *  - a "round" is one chosen surfel, so with the defaults r reaches half the
 *    sample (80) exactly at the 40000th surfel.
 *
 *
 * With an atlas_drawer the views are frames of that drawer: the objects
 * drawn one by one in index order (object and scene triangle IDs, as the
 * batch gives), depth and IDs read back. On GL (docs/gl.md, "The surfel
 * atlas on GL") the pixels on shared edges and silhouettes follow GL's
 * rasterization rules, so a few candidates differ from the software
 * atlas' and the sequence drawn from them differs after the first one
 * that does; each candidate is still made from its pixel's triangle by
 * the same code.
 *
 * Determinism: the atlas and the candidate order do not depend on the
 * thread count (the rasterizer is band-parallel and deterministic, the
 * candidates are written row by row at prefix-summed offsets); sampling is
 * sequential on one PCG32 stream (parallel distance queries for large
 * samples write disjoint slots); sizes are independent per surfel. */
#include "rl/rl_surfels.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "render/surfels_internal.h"
#include "rl/rl_raster.h"
#include "rl/rl_rng.h"
#include "rl/rl_timer.h"

#define SURFEL_MAX_RESOLUTION RL_IMAGE_MAX_SIZE
#define SURFEL_MAX_COUNT (1u << 26)
#define SURFEL_MAX_SAMPLE 1000000u
#define SURFEL_MAX_NEIGHBOURS 1024u
#define SURFEL_MAX_THREADS 4096
#define SURFEL_VIEWS 8
/* Distance queries of a sample this big run in parallel; smaller ones do not
 * pay for a parallel region per sample (on a busy machine they lose). */
#define SURFEL_PARALLEL_SAMPLE 4096

/* Share of the progress bar per step. */
#define PROGRESS_ATLAS 0.35
#define PROGRESS_SAMPLING 0.55

typedef struct build {
    const rl_scene_data *d;
    rl_surfel_desc p;
    int threads;
    rl_aabb bounds;
    rl_vec3 centre;
    float radius;                  /* bounding sphere of the bounds */
    rl_surfel *cand;
    uint32_t num_cand;
    uint64_t covered;
    rl_surfel_timing timing;
} build;

static int thread_id(void)
{
#ifdef _OPENMP
    return omp_get_thread_num();
#else
    return 0;
#endif
}

static bool report(const build *b, double done)
{
    return !b->p.progress || b->p.progress(b->p.user, done);
}

static rl_vec3 surfel_pos(const rl_surfel *s)
{
    return rl_v3(s->position[0], s->position[1], s->position[2]);
}

static int8_t snorm8(float v)
{
    float q = roundf(v * 127.0f);
    return (int8_t)(q > 127.0f ? 127 : q < -127.0f ? -127 : q);
}

static uint8_t unorm8(float v)
{
    if (!(v > 0.0f))
        return 0;
    return v >= 1.0f ? 255 : (uint8_t)(v * 255.0f + 0.5f);
}

/* ---- atlas and candidates ---------------------------------------------- */

/* An orthographic view from cube corner k towards the centre: a look-at
 * frame (s, u, -dir) and the ray origin plane through the eye. */
typedef struct view {
    rl_vec3 dir, s, u, eye;
    float half;                    /* half side of the view square, world units */
} view;

static view make_view(const build *b, int k)
{
    view v;
    rl_vec3 corner = rl_v3(k & 1 ? 1.0f : -1.0f, k & 2 ? 1.0f : -1.0f, k & 4 ? 1.0f : -1.0f);
    v.dir = rl_normalize(rl_neg(corner));
    /* No corner direction is parallel to y, so y is a valid up. */
    v.s = rl_normalize(rl_cross(v.dir, rl_v3(0.0f, 1.0f, 0.0f)));
    v.u = rl_cross(v.s, v.dir);
    v.eye = rl_sub(b->centre, rl_scale(v.dir, 2.0f * b->radius));
    v.half = b->radius;
    return v;
}

static void view_matrices(const view *v, rl_mat4 *vm, rl_mat4 *pm)
{
    *vm = rl_mat4_identity();
    const rl_vec3 rows[3] = { v->s, v->u, rl_neg(v->dir) };
    for (int r = 0; r < 3; ++r) {
        vm->m[r][0] = rows[r].x;
        vm->m[r][1] = rows[r].y;
        vm->m[r][2] = rows[r].z;
        vm->m[r][3] = -rl_dot(rows[r], v->eye);
    }
    /* Over the sphere: it spans depths [R, 3R] from the eye. */
    *pm = rl_mat4_orthographic(v->half, v->half, 0.5f * v->half, 3.5f * v->half);
}

/* The candidate of pixel (x, y) of view v, which shows triangle t at depth. */
static void reconstruct(const build *b, const view *v, int res, int x, int y, uint32_t t,
                        float depth, rl_surfel *out)
{
    const rl_scene_data *d = b->d;
    const uint32_t *tri = &d->indices[3 * (size_t)t];
    rl_vec3 a = d->positions[tri[0]], pb = d->positions[tri[1]], pc = d->positions[tri[2]];
    /* The pixel centre's ray (the rasterizer's pixel mapping: row 0 on top). */
    float sx = (2.0f * ((float)x + 0.5f) / (float)res - 1.0f) * v->half;
    float sy = (1.0f - 2.0f * ((float)y + 0.5f) / (float)res) * v->half;
    rl_vec3 o = rl_add(v->eye, rl_add(rl_scale(v->s, sx), rl_scale(v->u, sy)));
    rl_vec3 e1 = rl_sub(pb, a), e2 = rl_sub(pc, a), ng = rl_cross(e1, e2);
    float denom = rl_dot(ng, v->dir);
    /* Exact plane hit; a triangle seen edge-on keeps the rasterized depth. */
    float t_hit = fabsf(denom) > 1e-6f * rl_length(ng) ? rl_dot(ng, rl_sub(a, o)) / denom : depth;
    rl_vec3 p = rl_add(o, rl_scale(v->dir, t_hit));
    /* Barycentrics of p (Cramer on the edge Gram matrix), clamped onto the
     * triangle: a pixel centre just outside it (fill rule, snapping) must
     * not produce a point off the surface. */
    rl_vec3 q = rl_sub(p, a);
    float d00 = rl_dot(e1, e1), d01 = rl_dot(e1, e2), d11 = rl_dot(e2, e2);
    float d20 = rl_dot(q, e1), d21 = rl_dot(q, e2), det = d00 * d11 - d01 * d01;
    float w1 = det > 0.0f ? (d11 * d20 - d01 * d21) / det : 1.0f / 3.0f;
    float w2 = det > 0.0f ? (d00 * d21 - d01 * d20) / det : 1.0f / 3.0f;
    float w0 = 1.0f - w1 - w2;
    w0 = fmaxf(w0, 0.0f);
    w1 = fmaxf(w1, 0.0f);
    w2 = fmaxf(w2, 0.0f);
    float sum = w0 + w1 + w2;
    w0 /= sum;
    w1 /= sum;
    w2 /= sum;
    p = rl_add(rl_add(rl_scale(a, w0), rl_scale(pb, w1)), rl_scale(pc, w2));

    rl_vec3 n = rl_add(rl_add(rl_scale(d->normals[tri[0]], w0), rl_scale(d->normals[tri[1]], w1)),
                       rl_scale(d->normals[tri[2]], w2));
    float nl = rl_length(n);
    n = nl > 1e-12f ? rl_scale(n, 1.0f / nl) : rl_normalize(ng);
    if (rl_dot(n, v->dir) > 0.0f)
        n = rl_neg(n);

    const rl_material *m = &d->materials[d->triangle_material[t]];
    rl_vec3 col = m->diffuse;
    if (m->diffuse_texture != RL_NONE && m->diffuse_texture < d->num_textures &&
        d->textures[m->diffuse_texture]) {
        rl_vec2 uv0 = d->uvs[tri[0]], uv1 = d->uvs[tri[1]], uv2 = d->uvs[tri[2]];
        rl_vec2 uv = { w0 * uv0.x + w1 * uv1.x + w2 * uv2.x, w0 * uv0.y + w1 * uv1.y + w2 * uv2.y };
        rl_vec4 tx = rl_texture_sample(d->textures[m->diffuse_texture], uv);
        col = rl_v3(col.x * tx.x, col.y * tx.y, col.z * tx.z);
    }

    out->position[0] = p.x;
    out->position[1] = p.y;
    out->position[2] = p.z;
    out->normal[0] = snorm8(n.x);
    out->normal[1] = snorm8(n.y);
    out->normal[2] = snorm8(n.z);
    out->normal[3] = 0;
    out->color[0] = unorm8(col.x);
    out->color[1] = unorm8(col.y);
    out->color[2] = unorm8(col.z);
    out->size = 255;
}

/* Appends the candidates of one rendered view, row by row. */
static rl_status extract(build *b, const view *v, const rl_image *img, uint32_t *row_start,
                         size_t *cap)
{
    const int res = img->width;
#pragma omp parallel for schedule(dynamic, 8) num_threads(b->threads)
    for (int y = 0; y < res; ++y) {
        const uint32_t *ids = &img->triangle_id[(size_t)y * res];
        uint32_t n = 0;
        for (int x = 0; x < res; ++x)
            n += ids[x] != RL_ID_NONE;
        row_start[y + 1] = n;
    }
    row_start[0] = 0;
    for (int y = 0; y < res; ++y)
        row_start[y + 1] += row_start[y];
    size_t total = (size_t)b->num_cand + row_start[res];
    if (total > UINT32_MAX)
        return rl_error(RL_ERR_LIMIT, "rl_surfels_build: more than 2^32 candidates");
    if (total > *cap) {
        size_t want = *cap ? *cap : 1024;
        while (want < total)
            want *= 2;
        rl_surfel *c = rl_realloc_array(b->cand, want, sizeof *c);
        if (!c)
            return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_surfels_build: %zu candidates", total);
        b->cand = c;
        *cap = want;
    }
    rl_surfel *base = b->cand + b->num_cand;
#pragma omp parallel for schedule(dynamic, 8) num_threads(b->threads)
    for (int y = 0; y < res; ++y) {
        size_t row = (size_t)y * res;
        uint32_t k = row_start[y];
        for (int x = 0; x < res; ++x) {
            uint32_t t = img->triangle_id[row + x];
            if (t != RL_ID_NONE)
                reconstruct(b, v, res, x, y, t, img->depth[row + x], &base[k++]);
        }
    }
    b->num_cand = (uint32_t)total;
    b->covered += row_start[res];
    return RL_OK;
}

/* The triangles of the selected objects as one batch, or for a drawer the
 * objects as a list. */
typedef struct selection {
    rl_raster_batch batch;
    uint32_t *indices, *triangle_ids, *object_ids;   /* owned, NULL when all objects */
    uint32_t *objects, num_objects;                  /* owned, only for a drawer */
} selection;

static rl_status select_list(const rl_scene_data *d, const uint8_t *mask, selection *sel)
{
    memset(sel, 0, sizeof *sel);
    sel->objects = rl_alloc(((size_t)d->num_objects + 1) * sizeof *sel->objects);
    if (!sel->objects)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        if (mask[o] && d->objects[o].num_triangles > 0)
            sel->objects[sel->num_objects++] = o;
    return RL_OK;
}

static rl_status select_objects(const rl_scene_data *d, const uint8_t *mask, bool all, selection *sel)
{
    memset(sel, 0, sizeof *sel);
    rl_raster_batch *bt = &sel->batch;
    bt->num_vertices = d->num_vertices;
    bt->positions = d->positions;
    bt->flags = RL_RASTER_NO_COLOR;
    if (all) {
        bt->num_triangles = d->num_triangles;
        bt->indices = d->indices;
        bt->object_ids = d->triangle_object;
        return RL_OK;
    }
    size_t n = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        if (mask[o])
            n += d->objects[o].num_triangles;
    sel->indices = rl_alloc((3 * n + 1) * sizeof *sel->indices);
    sel->triangle_ids = rl_alloc((n + 1) * sizeof *sel->triangle_ids);
    sel->object_ids = rl_alloc((n + 1) * sizeof *sel->object_ids);
    if (!sel->indices || !sel->triangle_ids || !sel->object_ids)
        return RL_ERR_OUT_OF_MEMORY;
    size_t k = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        if (!mask[o])
            continue;
        const rl_object *ob = &d->objects[o];
        memcpy(&sel->indices[3 * k], &d->indices[3 * (size_t)ob->first_triangle],
               3 * (size_t)ob->num_triangles * sizeof *sel->indices);
        for (uint32_t t = 0; t < ob->num_triangles; ++t) {
            sel->triangle_ids[k + t] = ob->first_triangle + t;
            sel->object_ids[k + t] = o;
        }
        k += ob->num_triangles;
    }
    bt->num_triangles = (uint32_t)n;
    bt->indices = sel->indices;
    bt->triangle_ids = sel->triangle_ids;
    bt->object_ids = sel->object_ids;
    return RL_OK;
}

static void free_selection(selection *sel)
{
    free(sel->indices);
    free(sel->triangle_ids);
    free(sel->object_ids);
    free(sel->objects);
}

/* One view into img (cleared) by the drawer: a frame of its own. */
static rl_status drawer_view(rl_drawer *dr, const selection *sel, const view *v, const rl_mat4 *vm,
                             const rl_mat4 *pm, rl_image *img)
{
    rl_status st = rl_drawer_begin(dr, img, vm, pm, v->eye);
    if (st == RL_OK && sel->num_objects > 0)
        st = rl_drawer_draw(dr, sel->objects, sel->num_objects, NULL);
    if (st == RL_OK)
        st = rl_drawer_end(dr);
    return st;
}

static rl_status atlas_and_candidates(build *b, const selection *sel)
{
    const int res = (int)b->p.resolution;
    rl_image *img = NULL;
    rl_raster *ras = NULL;
    uint32_t *row_start = rl_alloc(((size_t)res + 1) * sizeof *row_start);
    size_t cap = 0;
    rl_status st = row_start ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        st = rl_image_create(res, res, RL_LAYER_DEPTH | RL_LAYER_ID, &img);
    if (st == RL_OK && !b->p.atlas_drawer)
        st = rl_raster_create(&(rl_raster_desc){ .threads = b->threads }, &ras);
    for (int k = 0; k < SURFEL_VIEWS && st == RL_OK; ++k) {
        rl_timer t;
        rl_timer_start(&t);
        view v = make_view(b, k);
        rl_mat4 vm, pm;
        view_matrices(&v, &vm, &pm);
        rl_image_clear(img);
        if (b->p.atlas_drawer) {
            st = drawer_view(b->p.atlas_drawer, sel, &v, &vm, &pm, img);
        } else {
            st = rl_raster_set_target(ras, img, &vm, &pm);
            if (st == RL_OK && sel->batch.num_triangles > 0)
                st = rl_raster_draw(ras, &sel->batch, NULL);
        }
        b->timing.atlas_ms += rl_timer_ms(&t);
        if (st != RL_OK)
            break;
        rl_timer_start(&t);
        st = extract(b, &v, img, row_start, &cap);
        b->timing.candidates_ms += rl_timer_ms(&t);
        if (st == RL_OK && !report(b, PROGRESS_ATLAS * (k + 1) / SURFEL_VIEWS))
            st = rl_error(RL_ERR_CANCELLED, "rl_surfels_build: cancelled in view %d of 8", k + 1);
    }
    rl_raster_release(ras);
    rl_image_release(img);
    free(row_start);
    return st;
}

/* ---- progressive sampling ---------------------------------------------- */

/* Visible area from the views (Cauchy: mean projected area = area / 4). */
static double visible_area(const build *b)
{
    double px = 2.0 * b->radius / b->p.resolution;
    return 4.0 * ((double)b->covered / SURFEL_VIEWS) * px * px;
}

static float spacing(double area, uint32_t n)
{
    return (float)sqrt(area / (n > 0 ? n : 1));
}

/* Draws the sequence into seq (indices into b->cand); chosen receives their
 * positions. Returns the status; *count the surfels chosen. */
static rl_status sample_sequence(build *b, uint32_t *seq, rl_vec3 *chosen, uint32_t *count)
{
    const uint32_t want = b->p.count < b->num_cand ? b->p.count : b->num_cand;
    *count = 0;
    if (want == 0)
        return RL_OK;
    uint32_t *pool = rl_alloc((size_t)b->num_cand * sizeof *pool);
    if (!pool)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; i < b->num_cand; ++i)
        pool[i] = i;
    rl_rng rng;
    rl_rng_seed(&rng, b->p.seed, 0x5eed5u);
    uint32_t m = b->num_cand;           /* pool[0, m) are the remaining candidates */
    rl_status st = RL_OK;

    if (b->p.sampling == RL_SURFEL_RANDOM) {
        /* The reference of Sec. 6.4.2/6.4.3: a uniform random order. */
        for (uint32_t i = 0; i < want; ++i) {
            uint32_t j = i + rl_rng_bounded(&rng, m - i);
            uint32_t tmp = pool[i];
            pool[i] = pool[j];
            pool[j] = tmp;
            seq[i] = pool[i];
            chosen[i] = surfel_pos(&b->cand[seq[i]]);
            if ((i & 4095u) == 4095u && !report(b, PROGRESS_ATLAS + PROGRESS_SAMPLING * i / want)) {
                st = rl_error(RL_ERR_CANCELLED, "rl_surfels_build: cancelled while sampling");
                break;
            }
        }
        free(pool);
        *count = st == RL_OK ? want : 0;
        return st;
    }

    const double area = visible_area(b);
    const uint32_t sample = b->p.start_sample;
    const uint32_t max_rounds = sample / 2 > 0 ? sample / 2 : 1;
    /* The sample's squared distances to the chosen surfels and its
     * positions, side by side with members[]: the incremental update walks
     * them every round, so they must not be random reads of the candidates. */
    float *d2 = rl_alloc((size_t)sample * sizeof *d2);
    rl_vec3 *mpos = rl_alloc((size_t)sample * sizeof *mpos);
    rl_surfel_grid g;
    st = d2 && mpos ? rl_surfel_grid_init(&g, b->bounds, spacing(area, 1), want) : RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        free(pool);
        free(d2);
        free(mpos);
        return st;
    }
    /* Sec. 6.1.1: any random candidate starts the sequence. */
    uint32_t n = 0, next_rebuild = 4;
    {
        uint32_t j = rl_rng_bounded(&rng, m);
        seq[0] = pool[j];
        pool[j] = pool[--m];
        chosen[0] = surfel_pos(&b->cand[seq[0]]);
        rl_surfel_grid_insert(&g, chosen, 0);
        n = 1;
    }
    uint32_t uses = 1, next_report = 1024;
    while (n < want && m > 0) {
        /* A random sample without replacement, moved to the pool's end and
         * out of it; its unchosen members go back afterwards. */
        uint32_t s = sample < m ? sample : m;
        for (uint32_t i = 0; i < s; ++i) {
            uint32_t j = rl_rng_bounded(&rng, m - i), last = m - 1 - i;
            uint32_t tmp = pool[j];
            pool[j] = pool[last];
            pool[last] = tmp;
        }
        m -= s;
        uint32_t *members = pool + m;
#pragma omp parallel for schedule(static) num_threads(b->threads) if (s >= SURFEL_PARALLEL_SAMPLE)
        for (int64_t i = 0; i < (int64_t)s; ++i) {
            mpos[i] = surfel_pos(&b->cand[members[i]]);
            d2[i] = rl_surfel_grid_nearest2(&g, chosen, mpos[i]);
        }
        /* RL_SURFEL_CONSTANT: one round per sample (no heuristic). */
        uint32_t rounds = b->p.sampling == RL_SURFEL_CONSTANT ? 1 : uses;
        uint32_t alive = s;
        for (uint32_t r = 0; r < rounds && alive > 0 && n < want; ++r) {
            uint32_t best = 0;
            for (uint32_t i = 1; i < alive; ++i)
                if (d2[i] > d2[best])
                    best = i;
            uint32_t c = members[best];
            seq[n] = c;
            chosen[n] = mpos[best];
            rl_surfel_grid_insert(&g, chosen, n);
            rl_vec3 pc = chosen[n];
            ++n;
            --alive;
            members[best] = members[alive];
            d2[best] = d2[alive];
            mpos[best] = mpos[alive];
            /* Incremental update: only the new surfel can be nearer. */
            for (uint32_t i = 0; i < alive; ++i) {
                rl_vec3 q = mpos[i];
                float dx = q.x - pc.x, dy = q.y - pc.y, dz = q.z - pc.z;
                float dd = dx * dx + dy * dy + dz * dz;
                if (dd < d2[i])
                    d2[i] = dd;
            }
            /* Sec. 6.1.1: one more round per sample every rounds_step
             * rounds, up to half the sample. */
            uint32_t u = 1 + (n - 1) / b->p.rounds_step;
            uses = u < max_rounds ? u : max_rounds;
            if (n >= next_rebuild) {
                /* The spacing has halved since the last rebuild. */
                rl_surfel_grid_reset(&g, spacing(area, n));
                for (uint32_t i = 0; i < n; ++i)
                    rl_surfel_grid_insert(&g, chosen, i);
                next_rebuild = next_rebuild > UINT32_MAX / 4 ? UINT32_MAX : next_rebuild * 4;
            }
        }
        m += alive;                      /* members[0, alive) follow pool[0, m) */
        if (n >= next_report) {
            next_report += 1024;
            if (!report(b, PROGRESS_ATLAS + PROGRESS_SAMPLING * n / want)) {
                st = rl_error(RL_ERR_CANCELLED, "rl_surfels_build: cancelled while sampling");
                break;
            }
        }
    }
    rl_surfel_grid_free(&g);
    free(d2);
    free(mpos);
    free(pool);
    *count = st == RL_OK ? n : 0;
    return st;
}

/* ---- relative point sizes ---------------------------------------------- */

static rl_status relative_sizes(build *b, rl_surfel *s, const rl_vec3 *pos, uint32_t n)
{
    const uint32_t k = b->p.neighbours;
    if (n < 2) {
        for (uint32_t i = 0; i < n; ++i)
            s[i].size = 255;
        return RL_OK;
    }
    int nt = b->threads;
    rl_vec3 *nrm = rl_alloc((size_t)n * sizeof *nrm);
    uint32_t *idx = rl_alloc((size_t)nt * k * sizeof *idx);
    float *d2 = rl_alloc((size_t)nt * k * sizeof *d2);
    rl_surfel_grid g;
    /* k neighbours lie within ~sqrt(k / pi) spacings: a cell of about half
     * that keeps the search to two or three rings. */
    float cell = spacing(visible_area(b), n) * fmaxf(1.0f, 0.5f * sqrtf((float)k));
    rl_status st = nrm && idx && d2 ? rl_surfel_grid_init(&g, b->bounds, cell, n)
                                    : RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        free(nrm);
        free(idx);
        free(d2);
        return st;
    }
    for (uint32_t i = 0; i < n; ++i) {
        nrm[i] = rl_surfel_normal(&s[i]);
        rl_surfel_grid_insert(&g, pos, i);
    }
#pragma omp parallel for schedule(dynamic, 256) num_threads(nt)
    for (int64_t i = 0; i < (int64_t)n; ++i) {
        uint32_t *ti = idx + (size_t)thread_id() * k;
        float *td = d2 + (size_t)thread_id() * k;
        uint32_t found = rl_surfel_grid_knn(&g, pos, pos[i], (uint32_t)i, k, ti, td);
        double sum = 0.0;
        for (uint32_t j = 0; j < found; ++j)
            sum += rl_dot(nrm[i], nrm[ti[j]]);
        /* Sec. 6.1.1: the mean cosine to the neighbours, clamped to [0, 1]. */
        s[i].size = found ? unorm8((float)(sum / found)) : 255;
    }
    rl_surfel_grid_free(&g);
    free(nrm);
    free(idx);
    free(d2);
    return RL_OK;
}

/* ---- public ------------------------------------------------------------ */

static rl_status check_desc(const rl_surfel_desc *in, rl_surfel_desc *p)
{
    *p = in ? *in : (rl_surfel_desc){ 0 };
    /* Defaults of Sec. 6.3. */
    if (p->resolution == 0) p->resolution = 1024;
    if (p->count == 0) p->count = 40000;
    if (p->start_sample == 0) p->start_sample = 160;
    if (p->rounds_step == 0) p->rounds_step = 500;
    if (p->neighbours == 0) p->neighbours = 20;
    if (p->resolution > SURFEL_MAX_RESOLUTION)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: resolution %u outside 1..%d",
                        p->resolution, SURFEL_MAX_RESOLUTION);
    if (p->count > SURFEL_MAX_COUNT)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: count %u outside 1..%u", p->count,
                        SURFEL_MAX_COUNT);
    if (p->start_sample > SURFEL_MAX_SAMPLE)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: start_sample %u outside 1..%u",
                        p->start_sample, SURFEL_MAX_SAMPLE);
    if (p->neighbours > SURFEL_MAX_NEIGHBOURS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: neighbours %u outside 1..%u",
                        p->neighbours, SURFEL_MAX_NEIGHBOURS);
    if ((unsigned)p->sampling > (unsigned)RL_SURFEL_RANDOM)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: unknown sampling %d",
                        (int)p->sampling);
    if (p->threads < 0 || p->threads > SURFEL_MAX_THREADS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: threads %d outside 0..%d",
                        p->threads, SURFEL_MAX_THREADS);
    return RL_OK;
}

rl_status rl_surfels_build(const rl_scene *scene, const uint32_t *objects, uint32_t num_objects,
                           const rl_surfel_desc *desc, rl_surfel_set *out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: NULL output");
    memset(out, 0, sizeof *out);
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: NULL scene");
    rl_timer total;
    rl_timer_start(&total);
    build b = { 0 };
    rl_status st = check_desc(desc, &b.p);
    if (st != RL_OK)
        return st;
    if (!rl_scene_is_committed(scene))
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_surfels_build: scene is not committed");
    b.d = rl_scene_get_data(scene);
    if (!b.d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_surfels_build: scene is not committed");
    if (objects && num_objects == 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: an empty object list (NULL means all)");
    b.threads = rl_surfel_thread_count(b.p.threads);
    const rl_drawer_desc atlas_desc = RL_SURFEL_ATLAS_DRAWER_DESC;
    if (b.p.atlas_drawer && !rl_drawer_fits(b.p.atlas_drawer, scene, &atlas_desc))
        return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: the atlas drawer was not made for this "
                        "scene with RL_SURFEL_ATLAS_DRAWER_DESC");

    uint8_t *mask = rl_calloc(b.d->num_objects ? b.d->num_objects : 1, 1);
    if (!mask)
        return RL_ERR_OUT_OF_MEMORY;
    b.bounds = rl_aabb_empty();
    for (uint32_t i = 0; i < (objects ? num_objects : b.d->num_objects); ++i) {
        uint32_t o = objects ? objects[i] : i;
        if (o >= b.d->num_objects) {
            free(mask);
            return rl_error(RL_ERR_INVALID_ARG, "rl_surfels_build: object %u of the list is %u, "
                            "the scene has %u", i, o, b.d->num_objects);
        }
        mask[o] = 1;
        b.bounds = rl_aabb_union(b.bounds, b.d->objects[o].bounds);
    }
    b.centre = rl_aabb_center(b.bounds);
    b.radius = 0.5f * rl_length(rl_aabb_extent(b.bounds));

    rl_surfel *surfels = NULL;
    uint32_t *seq = NULL;
    rl_vec3 *chosen = NULL;
    uint32_t n = 0;
    selection sel;
    st = b.p.atlas_drawer ? select_list(b.d, mask, &sel) : select_objects(b.d, mask, objects == NULL, &sel);
    free(mask);
    /* Degenerate bounds (nothing with area) cover no pixel: an empty set. */
    if (st == RL_OK && b.radius > 0.0f && isfinite(b.radius))
        st = atlas_and_candidates(&b, &sel);
    free_selection(&sel);

    rl_timer t;
    rl_timer_start(&t);
    uint32_t want = b.p.count < b.num_cand ? b.p.count : b.num_cand;
    if (st == RL_OK && want > 0) {
        seq = rl_alloc((size_t)want * sizeof *seq);
        chosen = rl_alloc((size_t)want * sizeof *chosen);
        st = seq && chosen ? sample_sequence(&b, seq, chosen, &n) : RL_ERR_OUT_OF_MEMORY;
    }
    b.timing.sampling_ms = rl_timer_ms(&t);
    if (st == RL_OK && n > 0) {
        surfels = rl_alloc((size_t)n * sizeof *surfels);
        if (!surfels)
            st = RL_ERR_OUT_OF_MEMORY;
        for (uint32_t i = 0; st == RL_OK && i < n; ++i)
            surfels[i] = b.cand[seq[i]];
    }
    free(b.cand);
    free(seq);
    b.cand = NULL;
    rl_timer_start(&t);
    if (st == RL_OK && n > 0)
        st = relative_sizes(&b, surfels, chosen, n);
    b.timing.sizes_ms = rl_timer_ms(&t);
    free(chosen);
    if (st == RL_OK && !report(&b, 1.0))
        st = rl_error(RL_ERR_CANCELLED, "rl_surfels_build: cancelled");
    if (st != RL_OK) {
        free(surfels);
        if (st == RL_ERR_OUT_OF_MEMORY)
            rl_error(st, "rl_surfels_build: out of memory (%u candidates, %u surfels)", b.num_cand,
                     b.p.count);
        return st;
    }
    out->surfels = surfels;
    out->count = n;
    out->candidates = b.num_cand;
    out->coverage = (float)((double)b.covered /
                            ((double)SURFEL_VIEWS * b.p.resolution * b.p.resolution));
    out->bounds = b.bounds;
    b.timing.total_ms = rl_timer_ms(&total);
    out->timing = b.timing;
    return RL_OK;
}

void rl_surfel_set_free(rl_surfel_set *set)
{
    if (!set)
        return;
    free(set->surfels);
    memset(set, 0, sizeof *set);
}

rl_vec3 rl_surfel_normal(const rl_surfel *s)
{
    rl_vec3 n = rl_v3(s->normal[0] / 127.0f, s->normal[1] / 127.0f, s->normal[2] / 127.0f);
    float l = rl_length(n);
    return l > 0.0f ? rl_scale(n, 1.0f / l) : n;
}

rl_vec3 rl_surfel_color(const rl_surfel *s)
{
    return rl_v3(s->color[0] / 255.0f, s->color[1] / 255.0f, s->color[2] / 255.0f);
}

float rl_surfel_size(const rl_surfel *s)
{
    return s->size / 255.0f;
}
