/* vt_sample.c: sampling the vertices of Vertex Tracing in parallel
 * (Ullmann 2003, Sec. 4.4, Fig. 4.11-4.12), and the feeler map of temporal
 * coherence (Sec. 3.4.5).
 *
 * The thesis' primary thread refines and its secondary threads walk the
 * sorted edge list sampling vertices that are not yet sampled, with
 * InProgress/Sampled flags per vertex. Here the primary thread packs the
 * vertices it creates into blocks of VT_BLOCK and spawns each full block as
 * an OpenMP task; idle threads take tasks from the runtime's queue, and the
 * primary thread helps at the end of a stage (taskwait). The flags become
 * the vertex state (QUEUED, SAMPLED) and the queue replaces the walk over
 * the list: no locks of our own, and no thread ever skips over sampled
 * entries. A block carries copies of its inputs, so the primary thread may
 * grow (reallocate) the mesh while blocks are being sampled.
 *
 * The area-light jitter of a vertex is seeded from its key, which is the
 * same in every frame and on every thread: a vertex's sample never depends
 * on who traced it or when, which is what lets temporal coherence reuse
 * feelers exactly. */
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "render/vt_part.h"
#include "render/vt_run.h"
#include "rl/rl_rng.h"
#include "rl/rl_timer.h"

/* ---------------------------------------------------------- feeler map -- */

static size_t slot_of(uint64_t key, size_t cap)
{
    return (size_t)(rl_hash64(key) & (uint64_t)(cap - 1));
}

/* Room for count words in pool. */
static bool pool_reserve(vt_feeler_pool *pool, size_t count)
{
    if (count > UINT32_MAX)
        return false;
    if (!pool->mapped)
        return rl_reserve((void **)&pool->occluder, &pool->cap, count, sizeof *pool->occluder, 256);
    if (count <= pool->cap)
        return true;
    size_t cap = rl_grow_capacity(pool->cap, count, 1024);
    uint32_t *p = vt_array_resize(pool->occluder, pool->cap * sizeof *p, cap * sizeof *p);
    if (!p)
        return false;
    pool->occluder = p;
    pool->cap = cap;
    return true;
}

bool vt_feelers_pack(const rl_trace_feelers *f, vt_feeler_pool *pool, vt_feelers_packed *out)
{
    uint32_t n = f->count < RL_TRACE_FEELER_CACHE_MAX ? f->count : RL_TRACE_FEELER_CACHE_MAX;
    if (!pool_reserve(pool, pool->count + n))
        return false;
    *out = (vt_feelers_packed){ (uint32_t)pool->count, (uint8_t)n, f->front, f->complete };
    if (n)                    /* an empty pool has no array yet */
        memcpy(pool->occluder + pool->count, f->occluder, n * sizeof *f->occluder);
    pool->count += n;
    return true;
}

void vt_feelers_unpack(const vt_feelers_packed *p, const uint32_t *occluder, rl_trace_feelers *out)
{
    out->count = p->count;
    out->front = p->front;
    out->complete = p->complete;
    if (p->count)
        memcpy(out->occluder, occluder + p->first, p->count * sizeof *occluder);
}

/* ------------------------------------------------- intersection hints -- */

/* A sample's hint list (rl_trace_hints) into pool, like vt_feelers_pack,
 * run-length coded as (triangle, run) pairs: the feelers of an area light
 * mostly all see the light or all hit one triangle, and every sampled
 * vertex keeps its list for the frame. Maximal runs make the code
 * canonical: two lists are equal exactly when their codes are. */
_Static_assert(2 * RL_TRACE_HINT_MAX <= UINT8_MAX, "a code's length fits vt_feelers_packed.count");
static bool hints_pack(const rl_trace_hints *h, vt_feeler_pool *pool, vt_feelers_packed *out)
{
    uint32_t n = h->count < RL_TRACE_HINT_MAX ? h->count : RL_TRACE_HINT_MAX;
    uint32_t code[2 * RL_TRACE_HINT_MAX], words = 0;
    for (uint32_t i = 0; i < n; ++i) {
        if (words && code[words - 2] == h->triangle[i]) {
            code[words - 1]++;
            continue;
        }
        code[words++] = h->triangle[i];
        code[words++] = 1;
    }
    if (!pool_reserve(pool, pool->count + words))
        return false;
    *out = (vt_feelers_packed){ (uint32_t)pool->count, (uint8_t)words, 0, 1 };
    if (words)
        memcpy(pool->occluder + pool->count, code, words * sizeof *code);
    pool->count += words;
    return true;
}

static void hints_unpack(const vt_feelers_packed *p, const uint32_t *pool, rl_trace_hints *out)
{
    out->count = 0;
    for (uint32_t w = 0; w + 1 < p->count; w += 2)
        for (uint32_t k = 0; k < pool[p->first + w + 1] && out->count < RL_TRACE_HINT_MAX; ++k)
            out->triangle[out->count++] = pool[p->first + w];
}

static bool hints_equal(const vt_feelers_packed *a, const vt_feelers_packed *b, const uint32_t *pool)
{
    return a->count == b->count && memcmp(pool + a->first, pool + b->first, a->count * sizeof *pool) == 0;
}

void vt_feeler_pool_free(vt_feeler_pool *pool)
{
    if (pool->mapped)
        vt_array_free(pool->occluder, pool->cap * sizeof *pool->occluder);
    else
        free(pool->occluder);
    bool mapped = pool->mapped;
    memset(pool, 0, sizeof *pool);
    pool->mapped = mapped;    /* it stays the kind of pool it was */
}

const vt_feelers_packed *vt_feeler_map_find(const vt_feeler_map *m, uint64_t key)
{
    if (!m || !m->cap)
        return NULL;
    key = vt_key_nonzero(key);
    for (size_t i = slot_of(key, m->cap);; i = (i + 1) & (m->cap - 1)) {
        if (m->keys[i] == key)
            return &m->values[i];
        if (m->keys[i] == 0)
            return NULL;
    }
}

rl_status vt_feeler_map_rebuild(vt_feeler_map *m, const vt_mesh *mesh, const vt_feelers_packed *values,
                                vt_feeler_pool *pool)
{
    size_t count = 0;
    for (uint32_t v = 0; v < mesh->num_verts; ++v)
        count += mesh->verts[v].state == VT_SAMPLED;
    /* Load factor <= 3/4: linear probing stays short, and the map, which
     * outlives the frame's mesh, takes 16 bytes a slot. */
    size_t cap = 64;
    while (cap < count + count / 3 + 1)
        cap *= 2;
    if (cap != m->cap) {
        /* The old map goes first: nothing reads it any more, and the two
         * together would be the frame's peak. */
        vt_feeler_map_free(m);
        uint64_t *k = rl_calloc(cap, sizeof *k);
        vt_feelers_packed *v = rl_realloc_array(NULL, cap, sizeof *v);
        if (!k || !v) {
            free(k);
            free(v);
            return RL_ERR_OUT_OF_MEMORY;
        }
        m->keys = k;
        m->values = v;
        m->cap = cap;
    } else {
        memset(m->keys, 0, cap * sizeof *m->keys);
    }
    vt_feeler_pool_free(&m->pool);
    m->pool = *pool;
    memset(pool, 0, sizeof *pool);
    m->count = 0;
    for (uint32_t n = 0; n < mesh->num_verts; ++n) {
        if (mesh->verts[n].state != VT_SAMPLED)
            continue;
        uint64_t key = vt_key_nonzero(mesh->verts[n].key);
        size_t i = slot_of(key, cap);
        while (m->keys[i] != 0 && m->keys[i] != key)
            i = (i + 1) & (cap - 1);
        if (m->keys[i] == 0)
            m->count++;
        m->keys[i] = key;
        m->values[i] = values[n];
    }
    return RL_OK;
}

void vt_feeler_map_free(vt_feeler_map *m)
{
    free(m->keys);
    free(m->values);
    vt_feeler_pool_free(&m->pool);
    memset(m, 0, sizeof *m);
}

/* ------------------------------------------------------------ sampling -- */

rl_status vt_run_reserve(vt_run *run)
{
    uint32_t need = run->mesh->num_verts;
    if (need <= run->per_vertex_cap)
        return RL_OK;
    /* Three arrays under one capacity: rl_reserve's doubling, kept in 32 bits. */
    size_t grown = rl_grow_capacity(run->per_vertex_cap, need, 1024);
    uint32_t cap = grown > UINT32_MAX ? need : (uint32_t)grown;
    uint8_t *reason = rl_realloc_array(run->reason, cap, sizeof *reason);
    if (!reason)
        return RL_ERR_OUT_OF_MEMORY;
    run->reason = reason;
    if (run->set->coherence) {
        vt_feelers_packed *f = vt_array_resize(run->feelers, (size_t)run->per_vertex_cap * sizeof *f, (size_t)cap * sizeof *f);
        if (!f)
            return RL_ERR_OUT_OF_MEMORY;
        run->feelers = f;
    }
    if (run->set->hint != VT_HINT_OFF) {
        vt_feelers_packed *h = vt_array_resize(run->hints, (size_t)run->per_vertex_cap * sizeof *h, (size_t)cap * sizeof *h);
        if (!h)
            return RL_ERR_OUT_OF_MEMORY;
        run->hints = h;
        /* count 0: no hints (a vertex not sampled, or merged) */
        memset(h + run->per_vertex_cap, 0, (cap - run->per_vertex_cap) * sizeof *h);
    }
    memset(run->reason + run->per_vertex_cap, 0, cap - run->per_vertex_cap);
    run->per_vertex_cap = cap;
    return RL_OK;
}

void vt_run_free_vertex_arrays(vt_run *run)
{
    free(run->reason);
    vt_array_free(run->feelers, (size_t)run->per_vertex_cap * sizeof *run->feelers);
    vt_array_free(run->hints, (size_t)run->per_vertex_cap * sizeof *run->hints);
    run->reason = NULL;
    run->feelers = run->hints = NULL;
    run->per_vertex_cap = 0;
}

static int thread_index(void)
{
#ifdef _OPENMP
    int t = omp_get_thread_num();
    return t < RL_VT_MAX_THREADS ? t : RL_VT_MAX_THREADS - 1;
#else
    return 0;
#endif
}

/* Option deferred_split: the colour the criteria compare with the deferred
 * reflected and transmitted textures (Sec. 3.5.3) looked up at the vertex,
 * the primary texture still white. The thesis keeps every texture out of
 * the criteria (Sec. 3.5.3, Fig. 5.2e-f), so a reflected texture is drawn
 * from texture coordinates interpolated over faces that nothing refined;
 * through a curved mirror they are far from linear, and the texture comes
 * out distorted (Fig. 5.8, left open in Sec. 5.1.2). Seeing the texels, the
 * criteria split where a reflected texture changes between two vertices, so
 * its edges are placed by samples, not by the interpolation. The primary
 * texture needs no samples: its coordinates are the face's own and exact.
 * Textures modulate k_d only, so a layer's textured radiance is its flat
 * one plus diffuse * (texel - 1). */
static rl_vec3 with_deferred_texels(const rl_scene_data *d, const rl_trace_sample *s)
{
    rl_vec3 c = s->flat;
    for (int l = RL_TRACE_LAYER_REFLECTION; l <= RL_TRACE_LAYER_REFRACTION; ++l) {
        const rl_trace_layer *L = &s->layers[l];
        if (L->texture >= d->num_textures || !d->textures[L->texture])
            continue;
        rl_vec4 t = rl_texture_sample(d->textures[L->texture], L->uv);
        c = rl_add(c, rl_mul(L->diffuse, rl_v3(t.x - 1.0f, t.y - 1.0f, t.z - 1.0f)));
    }
    return c;
}

/* The work unit of Ch. 4: a set of vertices in, their samples out, nothing
 * shared. A master-worker (MPI) version would send exactly this. */
static void sample_block(vt_run *run, vt_block *b)
{
    double t0 = (rl_time_s() * 1000.0);
    vt_thread_tally *tally = &run->tally[thread_index()];
    rl_ray_tree tree;
    rl_trace_sample s;
    rl_trace_feelers in, out_feelers;
    /* The parents' lists live in run->hint_pool, which only collect()
     * grows, after its taskwait: no block runs meanwhile. */
    rl_trace_hints parent[2], own;
    const bool hint = run->set->hint != VT_HINT_OFF;
    memset(&in, 0, sizeof in);
    b->feeler_pool.count = 0;
    b->hint_pool.count = 0;
    b->failed = false;
    for (uint32_t i = 0; i < b->count; ++i) {
        if (b->cache_in[i])
            vt_feelers_unpack(b->cache_in[i], run->cache->pool.occluder, &in);
        const rl_trace_hints *hint_in[2] = { NULL, NULL };
        for (int k = 0; hint && k < 2; ++k) {
            if (b->hint_in[i][k].count) {
                hints_unpack(&b->hint_in[i][k], run->hint_pool.occluder, &parent[k]);
                hint_in[k] = &parent[k];
            }
        }
        rl_tracer_shade_point_hinted(run->tracer, run->view.eye, &b->point[i], b->key[i],
                                     b->cache_in[i] ? &in : NULL, run->set->coherence ? &out_feelers : NULL,
                                     hint_in, hint ? &own : NULL, &s, run->want_tree ? &tree : NULL);
        if (run->set->coherence && !vt_feelers_pack(&out_feelers, &b->feeler_pool, &b->feelers[i]))
            b->failed = true;
        if (hint && !hints_pack(&own, &b->hint_pool, &b->hints[i]))
            b->failed = true;
        tally->hint_tests += s.hint_tests;
        tally->hint_hits += s.hint_hits;
        vt_vertex_sample *out = &b->out[i];
        /* Without deferred textures the criteria see them too. */
        out->flat = run->set->textures == VT_TEX_SAMPLED ? s.color : s.flat;
        if (run->set->deferred_split && run->set->textures != VT_TEX_SAMPLED)
            out->flat = with_deferred_texels(run->data, &s);
        memcpy(b->layers[i], s.layers, sizeof b->layers[i]);
        vt_sample_set_tree(out, run->want_tree ? vt_tree_hash(&tree, run->set->tree_shadow, run->set->tree_depth) : 0);
        for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k) {
            b->rays[i][k] = s.rays[k];
            tally->rays += s.rays[k];
        }
        tally->feelers_reused += s.feelers_reused;
    }
    tally->busy_ms += (rl_time_s() * 1000.0) - t0;
}

double vt_sample_busy_ms(const vt_run *run)
{
    return run->tally[thread_index()].busy_ms;
}

static vt_block *take_block(vt_run *run)
{
    vt_block *b = run->free_blocks;
    if (b)
        run->free_blocks = b->next;
    else if (!(b = malloc(sizeof *b)))
        return NULL;
    else {
        memset(&b->feeler_pool, 0, sizeof b->feeler_pool);
        memset(&b->hint_pool, 0, sizeof b->hint_pool);
    }
    b->count = 0;
    b->next = NULL;
    return b;
}

static void spawn(vt_run *run, vt_block *b)
{
    b->next = run->pending;
    run->pending = b;
    run->num_pending++;
#pragma omp task firstprivate(b) shared(run)
    sample_block(run, b);
}

/* Waits for the pending blocks and copies their results into the mesh. */
static void collect(vt_run *run)
{
#pragma omp taskwait
    run->num_pending = 0;
    vt_mesh *m = run->mesh;
    while (run->pending) {
        vt_block *b = run->pending;
        run->pending = b->next;
        for (uint32_t i = 0; i < b->count; ++i) {
            if (vt_mesh_set_sample(m, b->vertex[i], &b->out[i], b->layers[i]) != RL_OK)
                run->failed = true;
            m->verts[b->vertex[i]].state = VT_SAMPLED;
            uint64_t rays = 0;
            for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                rays += b->rays[i][k];
            for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                run->rays[k] += b->rays[i][k];
            if (run->vertex_rays)
                run->vertex_rays[b->vertex[i]] = (uint32_t)(rays < UINT32_MAX ? rays : UINT32_MAX);
            run->stats.vertices_sampled++;
            if (run->set->coherence && !b->failed && b->vertex[i] < run->per_vertex_cap) {
                /* Into the frame's pool: the block's is reused by its next
                 * stage. */
                rl_trace_feelers f;
                vt_feelers_unpack(&b->feelers[i], b->feeler_pool.occluder, &f);
                if (!vt_feelers_pack(&f, &run->feeler_pool, &run->feelers[b->vertex[i]]))
                    run->failed = true;
            }
            if (run->set->hint != VT_HINT_OFF && !b->failed && b->vertex[i] < run->per_vertex_cap) {
                rl_trace_hints h;
                hints_unpack(&b->hints[i], b->hint_pool.occluder, &h);
                if (!hints_pack(&h, &run->hint_pool, &run->hints[b->vertex[i]]))
                    run->failed = true;
            }
        }
        run->failed |= b->failed;
        b->next = run->free_blocks;
        run->free_blocks = b;
    }
}

/* A vertex waiting for the presort (Sec. 6.2.2) at the stage's flush. */
typedef struct vt_queued {
    uint64_t order;           /* VT object, then screen Morton code */
    uint32_t v, a, b;         /* the vertex and its parents (VT_NONE) */
} vt_queued;

/* The hint lists of parent p for a child, or none (count 0). */
static vt_feelers_packed parent_hints(const vt_run *run, uint32_t p)
{
    if (p == VT_NONE || p >= run->per_vertex_cap || run->mesh->verts[p].state != VT_SAMPLED)
        return (vt_feelers_packed){ 0, 0, 0, 0 };
    return run->hints[p];
}

/* Into the block being filled; a full block is spawned. */
static void add_to_block(vt_run *run, uint32_t v, uint32_t pa, uint32_t pb)
{
    if (!run->filling && !(run->filling = take_block(run))) {
        run->failed = true;
        return;
    }
    const vt_vertex *vx = &run->mesh->verts[v];
    vt_block *b = run->filling;
    uint32_t i = b->count++;
    b->vertex[i] = v;
    b->point[i] = (rl_trace_point){ vx->p, vx->n, vx->uv, vx->triangle };
    b->key[i] = vx->key;
    b->cache_in[i] = run->cache ? vt_feeler_map_find(run->cache, vx->key) : NULL;
    b->hint_in[i][0] = b->hint_in[i][1] = (vt_feelers_packed){ 0, 0, 0, 0 };
    if (run->set->hint != VT_HINT_OFF) {
        vt_feelers_packed ha = parent_hints(run, pa), hb = parent_hints(run, pb);
        /* agree: the thesis' case, parents whose ray trees name the same
         * triangles in every slot (then one list says it all) */
        if (run->set->hint == VT_HINT_PARENTS) {
            b->hint_in[i][0] = ha;
            b->hint_in[i][1] = hb;
        } else if (ha.count && hints_equal(&ha, &hb, run->hint_pool.occluder)) {
            b->hint_in[i][0] = ha;
        }
    }
    if (b->count == VT_BLOCK) {
        run->filling = NULL;
        spawn(run, b);
        /* Enough to keep the other threads busy while the primary thread
         * refines on; more would only hold results back, and every block
         * pending is 9 KB of the frame's peak, which is at the end of the
         * refinement (256 blocks, the least until 2026-12-06: 2.3 MB). */
        uint32_t most = 16u * (uint32_t)run->set->threads;
        if (run->num_pending >= (most > 64 ? most : 64))
            collect(run);
    }
}

/* Morton code of the pixel coordinates, 16 bits each (a 65536-pixel-wide
 * image at most; wider ones fold, which only costs coherence). */
static uint32_t morton2(float sx, float sy)
{
    uint32_t xy[2] = { (uint32_t)(sx > 0.0f ? (sx < 65535.0f ? sx : 65535.0f) : 0.0f),
                       (uint32_t)(sy > 0.0f ? (sy < 65535.0f ? sy : 65535.0f) : 0.0f) };
    for (int k = 0; k < 2; ++k) {
        uint32_t x = xy[k] & 0xFFFFu;
        x = (x | (x << 8)) & 0x00FF00FFu;
        x = (x | (x << 4)) & 0x0F0F0F0Fu;
        x = (x | (x << 2)) & 0x33333333u;
        x = (x | (x << 1)) & 0x55555555u;
        xy[k] = x;
    }
    return xy[0] | (xy[1] << 1);
}

static void queue_vertex(vt_run *run, uint32_t v, uint32_t pa, uint32_t pb)
{
    vt_vertex *vx = &run->mesh->verts[v];
    if (vx->state != VT_UNSAMPLED)
        return;
    if (run->given) {
        /* The post-pass (Sec. 6.1.3): a package sampled this vertex. It is
         * sampled now rather than at the stage's flush, which changes no
         * decision: a stage tests only edges whose ends an earlier stage
         * queued (vt_sample_flush). */
        bool failed = false;
        if (vt_part_samples_take(run->given, run->mesh, v, &failed)) {
            vx->state = VT_SAMPLED;
            run->stats.postpass_reused++;
            return;
        }
        run->failed |= failed;
        run->stats.postpass_traced++;
    }
    vx->state = VT_QUEUED;
    if (!run->set->presort) {
        add_to_block(run, v, pa, pb);
        return;
    }
    if (!rl_reserve_u32((void **)&run->sorting, &run->cap_sorting, (uint64_t)run->num_sorting + 1,
                        sizeof *run->sorting, 1024)) {
        run->failed = true;
        return;
    }
    uint32_t object = vx->triangle < run->data->num_triangles ? run->data->triangle_object[vx->triangle] : 0;
    run->sorting[run->num_sorting++] =
        (vt_queued){ ((uint64_t)object << 32) | morton2(vx->sx, vx->sy), v, pa, pb };
}

void vt_sample_queue(vt_run *run, uint32_t v)
{
    queue_vertex(run, v, VT_NONE, VT_NONE);
}

void vt_sample_queue_mid(vt_run *run, uint32_t v, uint32_t a, uint32_t b)
{
    queue_vertex(run, v, a, b);
}

static int by_order(const void *pa, const void *pb)
{
    const vt_queued *a = pa, *b = pb;
    if (a->order != b->order)
        return a->order < b->order ? -1 : 1;
    return a->v < b->v ? -1 : a->v > b->v;
}

void vt_sample_flush(vt_run *run)
{
    if (run->num_sorting) {
        /* Sec. 6.2.2, ray presorting: the rays of a stage leave vertices
         * created all over the image in edge-length order; sampled by VT
         * object and along a Morton curve over the screen, consecutive
         * vertices (and the blocks the threads take) are neighbours, whose
         * rays touch the same BVH nodes and triangles. */
        qsort(run->sorting, run->num_sorting, sizeof *run->sorting, by_order);
        uint32_t n = run->num_sorting;
        run->num_sorting = 0;
        for (uint32_t i = 0; i < n; ++i)
            add_to_block(run, run->sorting[i].v, run->sorting[i].a, run->sorting[i].b);
    }
    if (run->filling) {
        vt_block *b = run->filling;
        run->filling = NULL;
        if (b->count)
            spawn(run, b);
        else {
            b->next = run->free_blocks;
            run->free_blocks = b;
        }
    }
    collect(run);
}

void vt_run_free_blocks(vt_run *run)
{
    vt_block *lists[3] = { run->pending, run->filling, run->free_blocks };
    for (int l = 0; l < 3; ++l) {
        while (lists[l]) {
            vt_block *next = lists[l]->next;
            vt_feeler_pool_free(&lists[l]->feeler_pool);
            vt_feeler_pool_free(&lists[l]->hint_pool);
            free(lists[l]);
            lists[l] = next;
        }
    }
    run->pending = run->filling = run->free_blocks = NULL;
}
