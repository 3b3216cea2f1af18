/* vt_mesh.c: the refinement mesh of Vertex Tracing in object space
 * (Ullmann 2003, Sec. 3.3): primary vertices, edges and faces built from the
 * scene's triangles, edge-based subdivision (Fig. 3.5) and the compression
 * factor xi = c/(a+b) of forced refinement (Sec. 3.3.2).
 *
 * Edge orientation: an edge is created by the first face that uses it, with
 * v[0] -> v[1] in that face's counter-clockwise order; that face is face[0].
 * The second face is face[1]; in a consistently wound mesh the edge runs
 * v[1] -> v[0] there. A mesh with inconsistent winding still shares the
 * edge (so that refinement never opens a crack), which is why vt_mesh_split
 * finds its way round each face from the face's own vertices, never from the
 * slot the face sits in. Sub-edges keep their parent's direction and the new
 * inner edge (v', c) runs v' -> c in child (a, v', c), so the convention
 * survives any number of splits.
 *
 * Building is O(n): vertices are welded and edges paired through open
 * addressing hash tables, one object at a time (nothing is shared across
 * objects, so the tables only need to hold one object). */
#define _GNU_SOURCE            /* mremap */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

#include "core/error.h"
#include "render/vt_internal.h"

/* Element counts stay below 2^31 so that VT_NONE and index arithmetic in
 * uint32_t can never collide with a real index. */
#define VT_MESH_MAX_ELEMENTS (1u << 31)

static uint64_t mix64(uint64_t x)
{
    /* SplitMix64 finaliser (Steele et al. 2014): a bijection, so distinct
     * inputs keep distinct keys. */
    x ^= x >> 30;
    x *= 0xbf58476d1ce4e5b9ull;
    x ^= x >> 27;
    x *= 0x94d049bb133111ebull;
    x ^= x >> 31;
    return x;
}

uint64_t vt_vertex_key_primary(uint32_t object, uint32_t index)
{
    return mix64(((uint64_t)object << 32 | index) + 0x9e3779b97f4a7c15ull);
}

uint64_t vt_vertex_key_mid(uint64_t a, uint64_t b)
{
    /* Ordering the pair makes the key independent of the edge's direction;
     * the inner mix keeps (a, b) and (b, a') from colliding by xor. */
    uint64_t lo = a < b ? a : b, hi = a < b ? b : a;
    return mix64(lo ^ mix64(hi + 0x632be59bd9b4e019ull));
}

/* The mesh's growing arrays (vertices, samples, edges, their queued bits,
 * faces, deferred layers) live in mappings of their own where the system
 * has mremap (Linux): growing one moves its pages without copying them,
 * and shrinking one (vt_mesh_drop_refined_edges) gives the pages back at
 * once. Through malloc, glibc serves an array below its mmap threshold
 * from the heap, and that threshold rises to the largest mapped block
 * freed so far (up to 32 MB; the BVH build frees several): a doubling
 * there copies the array and leaves the old block behind as free heap,
 * resident until reused or trimmed. On table at 1024^2 (defaults) that
 * was 12 MB of the frame's peak, which is at the end of the refinement
 * (an RSS trace every 20 ms: 193.8 MB through malloc, 182.0 MB with
 * MALLOC_MMAP_THRESHOLD_=131072). Elsewhere, and under AddressSanitizer,
 * the arrays use realloc. */
#if defined(__SANITIZE_ADDRESS__)
#define VT_UNDER_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define VT_UNDER_ASAN 1
#endif
#endif
/* Not under AddressSanitizer: it checks heap blocks, not mappings, and the
 * sanitizer builds are there to check these arrays. */
#if defined(__linux__) && defined(MREMAP_MAYMOVE) && !defined(VT_UNDER_ASAN)
#define VT_MAPPED_ARRAYS 1
static size_t mapped_size(size_t bytes)
{
    size_t page = (size_t)sysconf(_SC_PAGESIZE);
    if (page == 0 || page == (size_t)-1)
        page = 4096;
    if (bytes == 0)
        return page;
    return bytes > SIZE_MAX - (page - 1) ? 0 : (bytes + page - 1) / page * page;
}
#endif

void *vt_array_resize(void *p, size_t old_bytes, size_t new_bytes)
{
#if VT_MAPPED_ARRAYS
    size_t to = mapped_size(new_bytes);
    if (!to)
        return NULL;
    if (!p) {
        void *q = mmap(NULL, to, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
        return q == MAP_FAILED ? NULL : q;
    }
    size_t from = mapped_size(old_bytes);
    if (from == to)
        return p;
    void *q = mremap(p, from, to, MREMAP_MAYMOVE);
    return q == MAP_FAILED ? NULL : q;
#else
    (void)old_bytes;
    return realloc(p, new_bytes ? new_bytes : 1);
#endif
}

void vt_array_free(void *p, size_t bytes)
{
    if (!p)
        return;
#if VT_MAPPED_ARRAYS
    munmap(p, mapped_size(bytes));
#else
    (void)bytes;
    free(p);
#endif
}

rl_status vt_array_reserve(void **array, uint32_t *cap, uint64_t need, size_t item_size, uint32_t first,
                           uint32_t max_items, const char *what)
{
    if (need <= *cap)
        return RL_OK;
    if (need > max_items)
        return rl_error(RL_ERR_LIMIT, "%s: more than %u", what, max_items);
    uint64_t n = *cap ? *cap : first;
    while (n < need)
        n *= 2;
    if (n > max_items)
        n = max_items;
    if ((size_t)n > SIZE_MAX / item_size)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: %llu overflow the address space", what,
                        (unsigned long long)n);
    void *p = vt_array_resize(*array, (size_t)*cap * item_size, (size_t)n * item_size);
    if (!p)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: out of memory for %llu", what, (unsigned long long)n);
    *array = p;
    *cap = (uint32_t)n;
    return RL_OK;
}

/* The mesh's arrays grow from 256 elements (a multiple of 32: the queued
 * bits below stay whole words). */
static rl_status grow(void **array, uint32_t *cap, uint32_t need, size_t item_size, const char *what)
{
    return vt_array_reserve(array, cap, need, item_size, 256, VT_MESH_MAX_ELEMENTS, what);
}

static rl_status reserve(vt_mesh *m, uint32_t verts, uint32_t edges, uint32_t faces)
{
    /* Checked before adding so that a failure leaves the mesh unchanged. */
    if (verts > VT_MESH_MAX_ELEMENTS - m->num_verts || edges > VT_MESH_MAX_ELEMENTS - m->num_edges ||
        faces > VT_MESH_MAX_ELEMENTS - m->num_faces)
        return rl_error(RL_ERR_LIMIT, "vt mesh: more than 2^31 elements");
    rl_status st = grow((void **)&m->verts, &m->cap_verts, m->num_verts + verts, sizeof *m->verts,
                        "vt mesh vertices");
    if (st == RL_OK)
        st = grow((void **)&m->samples, &m->cap_samples, m->num_verts + verts, sizeof *m->samples,
                  "vt mesh vertices");
    if (st == RL_OK)
        st = grow((void **)&m->edges, &m->cap_edges, m->num_edges + edges, sizeof *m->edges, "vt mesh edges");
    if (st == RL_OK && m->cap_queued < m->cap_edges / 32) {
        /* The queued bits follow the edges' capacity (a multiple of 256,
         * so of 32); new words start clear. On failure the edges keep
         * their new room and the bits follow at the next reserve: no split
         * happens before one succeeds. */
        uint32_t words = m->cap_edges / 32, old_words = m->cap_queued;
        uint32_t *q = vt_array_resize(m->edge_queued, (size_t)old_words * sizeof *q, (size_t)words * sizeof *q);
        if (!q)
            return rl_error(RL_ERR_OUT_OF_MEMORY, "vt mesh: out of memory for %u edges' bits", m->cap_edges);
        memset(q + old_words, 0, (size_t)(words - old_words) * sizeof *q);
        m->edge_queued = q;
        m->cap_queued = words;
    }
    if (st == RL_OK)
        st = grow((void **)&m->faces, &m->cap_faces, m->num_faces + faces, sizeof *m->faces, "vt mesh faces");
    return st;
}

rl_status vt_mesh_reserve(vt_mesh *m, uint32_t verts, uint32_t edges, uint32_t faces)
{
    return reserve(m, verts, edges, faces);
}

uint64_t vt_mesh_bytes(const vt_mesh *m)
{
    return (uint64_t)m->num_verts * (sizeof *m->verts + sizeof *m->samples) +
           (uint64_t)m->num_edges * sizeof *m->edges + (uint64_t)m->num_faces * sizeof *m->faces +
           (uint64_t)m->num_layers * sizeof *m->layers + (uint64_t)m->num_plain * sizeof *m->plain +
           ((uint64_t)m->num_edges + 7) / 8;
}

rl_status vt_mesh_pick_in_order(const vt_mesh *m, bool (*pick)(const void *user, const vt_face *f),
                                const void *user, uint32_t **list, size_t *cap, size_t *count)
{
    *count = 0;
    size_t n = 0;
    for (uint32_t f = 0; f < m->num_faces; ++f)
        n += pick(user, &m->faces[f]);
    if (!n)
        return RL_OK;
    if (!rl_reserve((void **)list, cap, n, sizeof **list, 1024))
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t *out = *list;
    if (m->num_created == m->num_faces) {
        /* No slot was reused: seq is the index. */
        for (uint32_t f = 0; f < m->num_faces; ++f)
            if (pick(user, &m->faces[f]))
                out[(*count)++] = f;
        return RL_OK;
    }
    /* A face's place is the number of picked faces created before it: a
     * bit per seq and a running count per 64 of them (a fraction of a
     * list indexed by seq, which would be twice the faces drawn). */
    size_t words = ((size_t)m->num_created + 63) / 64;
    uint64_t *bits = rl_calloc(words, sizeof *bits);
    uint32_t *before = rl_realloc_array(NULL, words, sizeof *before);
    if (!bits || !before) {
        free(bits);
        free(before);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t f = 0; f < m->num_faces; ++f)
        if (pick(user, &m->faces[f]))
            bits[m->faces[f].seq >> 6] |= 1ull << (m->faces[f].seq & 63);
    uint32_t sum = 0;
    for (size_t w = 0; w < words; ++w) {
        before[w] = sum;
        sum += (uint32_t)__builtin_popcountll(bits[w]);
    }
    for (uint32_t f = 0; f < m->num_faces; ++f) {
        uint32_t q = m->faces[f].seq;
        if (!((bits[q >> 6] >> (q & 63)) & 1u))
            continue;
        uint64_t below = bits[q >> 6] & ((1ull << (q & 63)) - 1u);
        out[before[q >> 6] + (uint32_t)__builtin_popcountll(below)] = f;
    }
    free(bits);
    free(before);
    *count = n;
    return RL_OK;
}

/* ------------------------------------------------------------- samples -- */

/* What rl_tracer_shade_point leaves in a layer it has nothing for. */
static const rl_trace_layer no_layer = { { 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 0.0f }, RL_NONE, { 0.0f, 0.0f } };

static bool layer_empty(const rl_trace_layer *L)
{
    /* Bitwise: a -0 term is kept as it came, so an unpacked layer is
     * always the packed one. */
    return memcmp(L, &no_layer, sizeof no_layer) == 0;
}

/* A layer without texture: its uv is never read (rl_trace_layer_color,
 * vt_draw's lookups, the rasterizer's layers sample only a texture), so it
 * is not kept; it comes back as 0. */
static bool layer_plain(const rl_trace_layer *L)
{
    return L->texture == RL_NONE;
}

rl_status vt_mesh_set_sample(vt_mesh *m, uint32_t v, const vt_vertex_sample *s,
                             const rl_trace_layer layers[RL_TRACE_LAYER_COUNT])
{
    const rl_trace_layer *deferred[2] = { &layers[RL_TRACE_LAYER_REFLECTION], &layers[RL_TRACE_LAYER_REFRACTION] };
    uint32_t need = 0, need_plain = 0;
    for (int k = 0; k < 2; ++k)
        if (!layer_empty(deferred[k])) {
            if (layer_plain(deferred[k]))
                ++need_plain;
            else
                ++need;
        }
    if (need > VT_MESH_MAX_ELEMENTS - m->num_layers || need_plain > VT_MESH_MAX_ELEMENTS - m->num_plain)
        return rl_error(RL_ERR_LIMIT, "vt mesh: more than 2^31 deferred layers");
    rl_status st = grow((void **)&m->layers, &m->cap_layers, m->num_layers + need, sizeof *m->layers, "vt mesh layers");
    if (st == RL_OK)
        st = grow((void **)&m->plain, &m->cap_plain, m->num_plain + need_plain, sizeof *m->plain, "vt mesh layers");
    if (st != RL_OK)
        return st;
    vt_vertex_sample *out = &m->samples[v];
    *out = *s;
    out->diffuse = layers[RL_TRACE_LAYER_PRIMARY].diffuse;
    out->rest = layers[RL_TRACE_LAYER_PRIMARY].rest;
    for (int k = 0; k < 2; ++k) {
        out->deferred[k] = VT_NONE;
        if (layer_empty(deferred[k]))
            continue;
        if (layer_plain(deferred[k])) {
            out->deferred[k] = VT_PLAIN_LAYER | m->num_plain;
            m->plain[m->num_plain++] = (vt_plain_layer){ deferred[k]->diffuse, deferred[k]->rest };
        } else {
            out->deferred[k] = m->num_layers;
            m->layers[m->num_layers++] = *deferred[k];
        }
    }
    return RL_OK;
}

static rl_trace_layer unpack_layer(const vt_mesh *m, uint32_t index)
{
    if (index == VT_NONE)
        return no_layer;
    if (index & VT_PLAIN_LAYER) {
        const vt_plain_layer *p = &m->plain[index & ~VT_PLAIN_LAYER];
        return (rl_trace_layer){ p->diffuse, p->rest, RL_NONE, { 0.0f, 0.0f } };
    }
    return m->layers[index];
}

void vt_mesh_sample_layers(const vt_mesh *m, uint32_t v, rl_trace_layer out[RL_TRACE_LAYER_COUNT])
{
    const vt_vertex_sample *s = &m->samples[v];
    out[RL_TRACE_LAYER_PRIMARY] = (rl_trace_layer){ s->diffuse, s->rest, RL_NONE, { 0.0f, 0.0f } };
    out[RL_TRACE_LAYER_REFLECTION] = unpack_layer(m, s->deferred[0]);
    out[RL_TRACE_LAYER_REFRACTION] = unpack_layer(m, s->deferred[1]);
}

/* ------------------------------------------------------------- building -- */

static uint64_t hash_bits(const void *data, size_t size)
{
    /* FNV-1a over the bytes, then mixed: the inputs are bit patterns of
     * floats, whose low bytes carry most of the variation. */
    const unsigned char *b = data;
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < size; ++i)
        h = (h ^ b[i]) * 0x100000001b3ull;
    return mix64(h);
}

/* Welding key: the exact bits of position, normal and uv, and the material
 * of the face using the vertex. A vertex's sample is shaded with one
 * material, so where materials meet (a checkerboard made of per-triangle
 * materials) each side gets its own vertex, as each side's pixels get their
 * own material in the ray tracer; the seam becomes a boundary on both. */
typedef struct weld_attr {
    rl_vec3 p, n;
    rl_vec2 uv;
    uint32_t material;
} weld_attr;

static weld_attr attr_of(const rl_scene_data *d, uint32_t s, uint32_t material)
{
    weld_attr a;
    memset(&a, 0, sizeof a);
    a.p = d->positions[s];
    a.n = d->normals[s];
    a.uv = d->uvs[s];
    a.material = material;
    return a;
}

/* Scratch of one build: hash tables sized for the largest object, of which
 * each object uses (and clears) only a power-of-two prefix. */
typedef struct build_scratch {
    uint32_t *weld;           /* slot -> source vertex, VT_NONE empty */
    uint32_t *weld_material;  /* slot -> material of that weld */
    uint32_t *weld_vertex;    /* slot -> mesh vertex */
    uint32_t *edge;           /* slot -> edge index, VT_NONE empty */
    size_t weld_cap, edge_cap;
} build_scratch;

static size_t table_size(uint64_t items)
{
    /* Load factor at most 1/2 keeps linear probing short. */
    size_t n = 16;
    while (n < 2 * items)
        n *= 2;
    return n;
}

static uint32_t weld_vertex(vt_mesh *m, const rl_scene_data *d, build_scratch *s, size_t mask,
                            uint32_t src, uint32_t object, uint32_t triangle, uint32_t *next_index)
{
    weld_attr a = attr_of(d, src, d->triangle_material ? d->triangle_material[triangle] : 0u);
    size_t slot = (size_t)hash_bits(&a, sizeof a) & mask;
    for (;; slot = (slot + 1) & mask) {
        uint32_t other = s->weld[slot];
        if (other == VT_NONE)
            break;
        weld_attr b = attr_of(d, other, s->weld_material[slot]);
        if (memcmp(&a, &b, sizeof a) == 0)
            return s->weld_vertex[slot];
    }
    uint32_t vi = m->num_verts++;
    s->weld[slot] = src;
    s->weld_material[slot] = a.material;
    s->weld_vertex[slot] = vi;
    vt_vertex *v = &m->verts[vi];
    memset(v, 0, sizeof *v);
    v->p = a.p;
    v->n = a.n;
    v->uv = a.uv;
    v->triangle = triangle;
    v->key = vt_vertex_key_primary(object, (*next_index)++);
    v->state = VT_UNSAMPLED;
    return vi;
}

static uint32_t new_edge(vt_mesh *m, uint32_t a, uint32_t b, uint32_t face)
{
    uint32_t ei = m->num_edges++;
    vt_edge *e = &m->edges[ei];
    memset(e, 0, sizeof *e);
    e->v[0] = a;
    e->v[1] = b;
    e->face[0] = face;
    e->face[1] = VT_NONE;
    e->child = VT_NONE;
    vt_edge_set_queued(m, ei, false);
    return ei;
}

/* The edge a -> b of face f: paired with the face that created it, or a new
 * boundary edge when that one already has two faces (non-manifold) or when
 * it is f itself (a face using a vertex twice). */
static uint32_t pair_edge(vt_mesh *m, build_scratch *s, size_t mask, uint32_t a, uint32_t b,
                          uint32_t f)
{
    uint32_t lo = a < b ? a : b, hi = a < b ? b : a;
    size_t slot = (size_t)mix64((uint64_t)lo << 32 | hi) & mask;
    for (;; slot = (slot + 1) & mask) {
        uint32_t ei = s->edge[slot];
        if (ei == VT_NONE)
            break;
        vt_edge *e = &m->edges[ei];
        uint32_t elo = e->v[0] < e->v[1] ? e->v[0] : e->v[1];
        uint32_t ehi = e->v[0] < e->v[1] ? e->v[1] : e->v[0];
        if (elo != lo || ehi != hi)
            continue;
        if (e->face[1] == VT_NONE && e->face[0] != f) {
            e->face[1] = f;
            return ei;
        }
        /* Third and later faces: a boundary copy of their own; the table
         * keeps pointing at the first so that lookups stay O(1). */
        return new_edge(m, a, b, f);
    }
    uint32_t ei = new_edge(m, a, b, f);
    s->edge[slot] = ei;
    return ei;
}

static rl_status build_object(vt_mesh *m, const rl_scene_data *d, uint32_t o, build_scratch *s)
{
    const rl_object *obj = &d->objects[o];
    if (obj->num_triangles == 0)
        return RL_OK;
    if ((uint64_t)obj->first_triangle + obj->num_triangles > d->num_triangles ||
        (uint64_t)obj->first_vertex + obj->num_vertices > d->num_vertices)
        return rl_error(RL_ERR_INVALID_ARG, "vt mesh: object %u out of the scene's arrays", o);
    /* Worst case per object: every corner a new vertex, every side a new
     * edge; reserving it up front keeps pointers stable inside the loop. */
    uint64_t corners = 3ull * obj->num_triangles;
    uint64_t max_verts = corners;      /* one per corner when materials alternate */
    if (max_verts >= VT_MESH_MAX_ELEMENTS || corners >= VT_MESH_MAX_ELEMENTS)
        return rl_error(RL_ERR_LIMIT, "vt mesh: object %u exceeds 2^31 elements", o);
    rl_status st = reserve(m, (uint32_t)max_verts, (uint32_t)corners, obj->num_triangles);
    if (st != RL_OK)
        return st;

    size_t weld_size = table_size(max_verts), edge_size = table_size(corners);
    memset(s->weld, 0xff, weld_size * sizeof *s->weld);
    memset(s->edge, 0xff, edge_size * sizeof *s->edge);

    uint32_t next_index = 0;
    for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->num_triangles; ++t) {
        uint32_t fv[3];
        for (int k = 0; k < 3; ++k) {
            uint32_t src = d->indices[3 * (size_t)t + (size_t)k];
            if (src < obj->first_vertex || src - obj->first_vertex >= obj->num_vertices)
                return rl_error(RL_ERR_INVALID_ARG,
                                "vt mesh: triangle %u uses vertex %u outside object %u", t, src, o);
            fv[k] = weld_vertex(m, d, s, weld_size - 1, src, o, t, &next_index);
        }
        uint32_t fi = m->num_faces++;
        vt_face *f = &m->faces[fi];
        memset(f, 0, sizeof *f);
        memcpy(f->v, fv, sizeof fv);
        f->triangle = t;
        f->seq = fi;
        f->leaf = 1;
        m->tri_face[t] = fi;
        f->height = -1.0f;
        for (int i = 0; i < 3; ++i)
            f->e[i] = pair_edge(m, s, edge_size - 1, fv[(i + 1) % 3], fv[(i + 2) % 3], fi);
    }
    return RL_OK;
}

rl_status vt_mesh_build(vt_mesh *m, const rl_scene_data *d, const uint8_t *object_mask)
{
    if (!m || !d || (d->num_objects > 0 && (!object_mask || !d->objects)))
        return rl_error(RL_ERR_INVALID_ARG, "vt_mesh_build: NULL argument");
    vt_mesh_free(m);

    uint32_t max_triangles = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        if (!object_mask[o])
            continue;
        if (d->objects[o].num_triangles > max_triangles)
            max_triangles = d->objects[o].num_triangles;
    }
    m->tri_face = rl_realloc_array(NULL, d->num_triangles ? d->num_triangles : 1, sizeof *m->tri_face);
    if (!m->tri_face)
        return RL_ERR_OUT_OF_MEMORY;
    m->num_tri_face = d->num_triangles;
    for (uint32_t t = 0; t < d->num_triangles; ++t)
        m->tri_face[t] = VT_NONE;
    if (max_triangles == 0)
        return RL_OK;
    uint64_t corners = 3ull * max_triangles;
    build_scratch s = { 0 };
    s.weld_cap = table_size(corners);
    s.edge_cap = table_size(corners);
    s.weld = rl_calloc(s.weld_cap, sizeof *s.weld);
    s.weld_material = rl_calloc(s.weld_cap, sizeof *s.weld_material);
    s.weld_vertex = rl_calloc(s.weld_cap, sizeof *s.weld_vertex);
    s.edge = rl_calloc(s.edge_cap, sizeof *s.edge);
    rl_status st = (s.weld && s.weld_material && s.weld_vertex && s.edge) ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (uint32_t o = 0; st == RL_OK && o < d->num_objects; ++o)
        if (object_mask[o])
            st = build_object(m, d, o, &s);
    free(s.weld);
    free(s.weld_material);
    free(s.weld_vertex);
    free(s.edge);
    if (st != RL_OK) {
        vt_mesh_free(m);
        return st;
    }
    m->num_primary_verts = m->num_verts;
    m->num_primary_edges = m->num_edges;
    m->num_primary_faces = m->num_faces;
    m->num_created = m->num_faces;
    return RL_OK;
}

void vt_mesh_free(vt_mesh *m)
{
    if (!m)
        return;
    vt_array_free(m->verts, (size_t)m->cap_verts * sizeof *m->verts);
    vt_array_free(m->samples, (size_t)m->cap_samples * sizeof *m->samples);
    vt_array_free(m->edges, (size_t)m->cap_edges * sizeof *m->edges);
    vt_array_free(m->edge_queued, (size_t)m->cap_queued * sizeof *m->edge_queued);
    vt_array_free(m->faces, (size_t)m->cap_faces * sizeof *m->faces);
    vt_array_free(m->layers, (size_t)m->cap_layers * sizeof *m->layers);
    vt_array_free(m->plain, (size_t)m->cap_plain * sizeof *m->plain);
    free(m->tri_face);
    memset(m, 0, sizeof *m);
}

void vt_mesh_drop_refined_edges(vt_mesh *m)
{
    /* Room rounded up to 256 as grow() keeps it, so that the queued bits
     * stay whole words and the next frame grows from here as from a build. */
    uint64_t cap = ((uint64_t)m->num_primary_edges + 255u) / 256u * 256u;
    if (cap < 256u)
        cap = 256u;
    m->num_edges = m->num_primary_edges;
    if (cap >= m->cap_edges)
        return;
    /* Shrinking keeps the first cap elements (the primary ones) and gives
     * the rest back; should it fail, the larger array stays, which is only
     * memory. */
    vt_edge *e = vt_array_resize(m->edges, (size_t)m->cap_edges * sizeof *m->edges, (size_t)cap * sizeof *m->edges);
    if (e) {
        m->edges = e;
        m->cap_edges = (uint32_t)cap;
    }
    uint32_t words = m->cap_edges / 32;
    if (m->cap_queued > words) {
        uint32_t *q = vt_array_resize(m->edge_queued, (size_t)m->cap_queued * sizeof *q, (size_t)words * sizeof *q);
        if (q) {
            m->edge_queued = q;
            m->cap_queued = words;
        }
    }
}

void vt_mesh_reset(vt_mesh *m)
{
    /* Splits moved the primary edges' face references down to descendants;
     * a descendant's triangle names its primary face, so the original
     * adjacency needs no copy. (Primary faces never give their slot away,
     * so their corners and edges are still the built ones.) */
    for (uint32_t i = 0; i < m->num_primary_edges; ++i) {
        vt_edge *e = &m->edges[i];
        for (int s = 0; s < 2; ++s)
            if (e->face[s] != VT_NONE)
                e->face[s] = vt_face_root(m, e->face[s]);
        e->child = VT_NONE;
        vt_edge_set_queued(m, i, false);
    }
    for (uint32_t i = 0; i < m->num_primary_faces; ++i) {
        m->faces[i].leaf = 1;
        m->faces[i].visible = 0;
        m->faces[i].height = -1.0f;
    }
    for (uint32_t i = 0; i < m->num_primary_verts; ++i) {
        m->verts[i].state = VT_UNSAMPLED;
        m->verts[i].visible = 0;
    }
    m->num_verts = m->num_primary_verts;
    m->num_edges = m->num_primary_edges;
    m->num_faces = m->num_primary_faces;
    m->num_created = m->num_primary_faces;
    m->num_layers = 0;
    m->num_plain = 0;
}

/* ------------------------------------------------------------ splitting -- */

static void replace_face(vt_edge *e, uint32_t from, uint32_t to)
{
    if (e->face[0] == from)
        e->face[0] = to;
    else if (e->face[1] == from)
        e->face[1] = to;
}

/* A child of parent into slot fi (a new one, or the parent's own). */
static uint32_t add_face(vt_mesh *m, const vt_face *parent, uint32_t fi, uint32_t a, uint32_t b,
                         uint32_t c, uint32_t ea, uint32_t eb, uint32_t ec, uint16_t stage)
{
    vt_face *f = &m->faces[fi];
    memset(f, 0, sizeof *f);
    f->v[0] = a; f->v[1] = b; f->v[2] = c;
    f->e[0] = ea; f->e[1] = eb; f->e[2] = ec;
    f->triangle = parent->triangle;
    f->seq = m->num_created++;
    f->stage = stage;
    f->leaf = 1;
    f->visible = parent->visible;
    f->height = -1.0f;
    return fi;
}

uint32_t vt_mesh_split(vt_mesh *m, uint32_t e, uint16_t stage, uint32_t new_edges[4],
                       uint32_t *num_new_edges, uint32_t new_faces[4], uint32_t *num_new_faces)
{
    *num_new_edges = 0;
    *num_new_faces = 0;
    if (e >= m->num_edges)
        return VT_NONE;
    if (vt_edge_is_split(&m->edges[e]))
        return vt_edge_mid(m, e);
    const vt_edge old = m->edges[e];
    int sides = 0;
    for (int s = 0; s < 2; ++s)
        if (old.face[s] != VT_NONE && m->faces[old.face[s]].leaf)
            ++sides;
    if (reserve(m, 1, 2 + (uint32_t)sides, 2 * (uint32_t)sides) != RL_OK)
        return VT_NONE;

    /* Sec. 3.3, eq. 3.7 and 3.8: the midpoint in object space. */
    const vt_vertex *va = &m->verts[old.v[0]], *vb = &m->verts[old.v[1]];
    uint32_t first_face = old.face[0] != VT_NONE ? old.face[0] : old.face[1];
    uint32_t mid = m->num_verts++;
    vt_vertex *v = &m->verts[mid];
    memset(v, 0, sizeof *v);
    v->p = rl_scale(rl_add(va->p, vb->p), 0.5f);
    rl_vec3 n = rl_add(va->n, vb->n);
    v->n = rl_length2(n) > 0.0f ? rl_normalize(n) : va->n;
    v->uv = rl_v2(0.5f * (va->uv.x + vb->uv.x), 0.5f * (va->uv.y + vb->uv.y));
    v->triangle = first_face != VT_NONE ? m->faces[first_face].triangle : va->triangle;
    v->key = vt_vertex_key_mid(va->key, vb->key);
    v->stage = stage;
    v->state = VT_UNSAMPLED;

    /* Sub-edges keep the parent's direction, so a face's slot carries over. */
    uint32_t sub[2];
    sub[0] = new_edge(m, old.v[0], mid, VT_NONE);
    sub[1] = new_edge(m, mid, old.v[1], VT_NONE);
    m->edges[e].child = sub[0];           /* sub[1] is sub[0] + 1; mid is sub[0].v[1] */
    new_edges[(*num_new_edges)++] = sub[0];
    new_edges[(*num_new_edges)++] = sub[1];

    for (int s = 0; s < 2; ++s) {
        uint32_t fi = old.face[s];
        if (fi == VT_NONE || !m->faces[fi].leaf)
            continue;
        const vt_face parent = m->faces[fi];
        int k = 0;                /* slot of c, the corner opposite the edge */
        while (k < 2 && parent.e[k] != e)
            ++k;
        uint32_t c = parent.v[k];
        uint32_t a = parent.v[(k + 1) % 3], b = parent.v[(k + 2) % 3];
        uint32_t e_ca = parent.e[(k + 2) % 3], e_bc = parent.e[(k + 1) % 3];
        /* Fig. 3.5: the edge from v' to the opposite corner; v' -> c is
         * counter-clockwise in (a, v', c), the first child. */
        uint32_t inner = new_edge(m, mid, c, VT_NONE);
        uint32_t sub_a = old.v[0] == a ? sub[0] : sub[1];
        uint32_t sub_b = sub_a == sub[0] ? sub[1] : sub[0];
        /* (a, v', c): e[0] = (v', c), e[1] = (c, a), e[2] = (a, v');
         * (v', b, c): e[0] = (b, c), e[1] = (c, v'), e[2] = (v', b). */
        /* A primary parent stays: vt_mesh_reset starts from it again. */
        const bool reuse = m->drop_parents && fi >= m->num_primary_faces;
        uint32_t f1 = add_face(m, &parent, reuse ? fi : m->num_faces++, a, mid, c, inner, e_ca, sub_a, stage);
        uint32_t f2 = add_face(m, &parent, m->num_faces++, mid, b, c, e_bc, inner, sub_b, stage);
        if (!reuse)
            m->faces[fi].leaf = 0;
        m->edges[inner].face[0] = f1;
        m->edges[inner].face[1] = f2;
        m->edges[sub_a].face[s] = f1;
        m->edges[sub_b].face[s] = f2;
        replace_face(&m->edges[e_ca], fi, f1);
        replace_face(&m->edges[e_bc], fi, f2);
        new_edges[(*num_new_edges)++] = inner;
        new_faces[(*num_new_faces)++] = f1;
        new_faces[(*num_new_faces)++] = f2;
    }
    return mid;
}

/* ------------------------------------------------- forced refinement -- */

static double side_px(const vt_mesh *m, uint32_t a, uint32_t b)
{
    double dx = (double)m->verts[a].sx - m->verts[b].sx;
    double dy = (double)m->verts[a].sy - m->verts[b].sy;
    return sqrt(dx * dx + dy * dy);
}

float vt_face_xi(const vt_mesh *m, uint32_t f, int i)
{
    /* Ullmann 2003, Sec. 3.3.2: xi = c / (a + b), c the base opposite v[i]. */
    const uint32_t *v = m->faces[f].v;
    double c = side_px(m, v[(i + 1) % 3], v[(i + 2) % 3]);
    double a = side_px(m, v[i], v[(i + 1) % 3]);
    double b = side_px(m, v[i], v[(i + 2) % 3]);
    return a + b > 0.0 ? (float)(c / (a + b)) : 0.0f;
}

static double side2_px(const vt_vertex *a, const vt_vertex *b)
{
    double dx = (double)a->sx - b->sx, dy = (double)a->sy - b->sy;
    return dx * dx + dy * dy;
}

/* fmax without the library call it compiles to here. */
static inline double max_d(double a, double b)
{
    return a > b || b != b ? a : b;
}

float vt_face_height_px(const vt_mesh *m, uint32_t f)
{
    const uint32_t *v = m->faces[f].v;
    const vt_vertex *a = &m->verts[v[0]], *b = &m->verts[v[1]], *c = &m->verts[v[2]];
    double ux = (double)b->sx - a->sx, uy = (double)b->sy - a->sy;
    double wx = (double)c->sx - a->sx, wy = (double)c->sy - a->sy;
    double twice_area = fabs(ux * wy - uy * wx);
    /* One root instead of three: the refinement asks this of every face it
     * tests or creates, and sqrt is monotonic, so the root of the largest
     * square is exactly the largest root. */
    double longest = sqrt(max_d(side2_px(a, b), max_d(side2_px(b, c), side2_px(c, a))));
    return longest > 0.0 ? (float)(twice_area / longest) : 0.0f;
}

float vt_face_height(vt_mesh *m, uint32_t f)
{
    vt_face *face = &m->faces[f];
    if (face->height < 0.0f)
        face->height = vt_face_height_px(m, f);
    return face->height;
}
