/* vt_part.c: the result of one package of a distributed Vertex Tracing
 * frame (Ullmann 2003, Sec. 4.3): the refined leaf faces of the package's
 * primary faces and their vertices' samples, in a compact checked form
 * that a worker sends and the master draws (rl_vt.h, src/dist/dist_vt.c).
 *
 * The part carries what the reconstruction reads (vt_draw.c) and nothing
 * of the refinement (no edges, keys or feelers): the master only draws.
 * Layout, host byte order (every rank of a job runs the same build):
 *   header  "RLVP", version, vertices, faces, payload bytes, FNV-1a of the payload
 *   vertex  position 3f, uv 2f, flat 3f, per trace layer (3): diffuse 3f,
 *           rest 3f, texture u32, uv 2f                   (140 bytes)
 *   face    vertex u32 x3, triangle u32, object u32, stage u16, 0 u16  (24 bytes)
 * A vertex shared by several faces of the part is written once.
 *
 * Version 2 (option dist_postpass, Sec. 6.1.3): every vertex the package
 * sampled, also those of no drawn face, and per vertex 20 bytes more:
 *           key u64, triangle u32, ray-tree hash u64       (160 bytes)
 * so that the master's post-pass can take the samples by vertex identity
 * instead of tracing them again (vt_part_samples_*). */
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/vt_part.h"
#include "render/vt_run.h"
#include "rl/rl_rng.h"

#define PART_MAGIC "RLVP"
#define PART_VERSION 1u
#define PART_VERSION_SAMPLES 2u
#define HEADER_BYTES 32u
#define VERTEX_BYTES (8u * 4u + RL_TRACE_LAYER_COUNT * 9u * 4u)
#define VERTEX_EXTRA_BYTES 20u      /* version 2: key, triangle, tree hash */
#define FACE_BYTES 24u

static uint32_t vertex_bytes(uint32_t version)
{
    return VERTEX_BYTES + (version == PART_VERSION_SAMPLES ? VERTEX_EXTRA_BYTES : 0u);
}

static uint64_t fnv1a(const unsigned char *b, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ull;
    for (size_t i = 0; i < n; ++i) {
        h ^= b[i];
        h *= 0x100000001b3ull;
    }
    return h;
}

static unsigned char *put(unsigned char *p, const void *x, size_t n)
{
    memcpy(p, x, n);
    return p + n;
}

static const unsigned char *get(const unsigned char *p, void *x, size_t n)
{
    memcpy(x, p, n);
    return p + n;
}

static unsigned char *put_vec3(unsigned char *p, rl_vec3 v)
{
    float f[3] = { v.x, v.y, v.z };
    return put(p, f, sizeof f);
}

static const unsigned char *get_vec3(const unsigned char *p, rl_vec3 *v)
{
    float f[3];
    p = get(p, f, sizeof f);
    *v = rl_v3(f[0], f[1], f[2]);
    return p;
}

static unsigned char *put_vec2(unsigned char *p, rl_vec2 v)
{
    float f[2] = { v.x, v.y };
    return put(p, f, sizeof f);
}

static const unsigned char *get_vec2(const unsigned char *p, rl_vec2 *v)
{
    float f[2];
    p = get(p, f, sizeof f);
    *v = rl_v2(f[0], f[1]);
    return p;
}

/* The start of a vertex record, the same in both part formats: position,
 * uv, flat radiance and the trace layers, into a cleared sample; the
 * pointer past them. The import and the post-pass' sample map both read
 * it. */
static const unsigned char *get_vertex_sample(const unsigned char *p, rl_vec3 *pos, rl_vec2 *uv,
                                              vt_vertex_sample *s, rl_trace_layer layers[RL_TRACE_LAYER_COUNT])
{
    memset(s, 0, sizeof *s);
    p = get_vec3(p, pos);
    p = get_vec2(p, uv);
    p = get_vec3(p, &s->flat);
    for (int l = 0; l < RL_TRACE_LAYER_COUNT; ++l) {
        p = get_vec3(p, &layers[l].diffuse);
        p = get_vec3(p, &layers[l].rest);
        p = get(p, &layers[l].texture, 4);
        p = get_vec2(p, &layers[l].uv);
    }
    return p;
}

rl_status vt_part_write(const vt_mesh *m, const rl_scene_data *d, const uint8_t *mine, bool all_samples, void **out,
                        size_t *size)
{
    const uint32_t version = all_samples ? PART_VERSION_SAMPLES : PART_VERSION;
    const uint32_t vbytes = vertex_bytes(version);
    *out = NULL;
    *size = 0;
    /* A leaf belongs to the package of its primary ancestor. A package's
     * mesh keeps its split parents (vt_refine), so the index order is the
     * creation order. */
    uint32_t *root = rl_realloc_array(NULL, m->num_faces ? m->num_faces : 1, sizeof *root);
    uint32_t *remap = rl_realloc_array(NULL, m->num_verts ? m->num_verts : 1, sizeof *remap);
    if (m->num_created != m->num_faces) {
        free(root);
        free(remap);
        return rl_error(RL_ERR_INTERNAL, "vt: a package's mesh dropped its split faces");
    }
    if (!root || !remap) {
        free(root);
        free(remap);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: a package's result (%u faces)", m->num_faces);
    }
    for (uint32_t v = 0; v < m->num_verts; ++v)
        remap[v] = VT_NONE;
    uint32_t nv = 0, nf = 0;
    for (uint32_t f = 0; f < m->num_faces; ++f) {
        const vt_face *face = &m->faces[f];
        root[f] = vt_face_root(m, f);
        if (!face->leaf || root[f] == VT_NONE || mine[root[f]] != 1)
            continue;
        bool sampled = true;
        for (int k = 0; k < 3; ++k)
            sampled &= m->verts[face->v[k]].state == VT_SAMPLED;
        if (!sampled)
            continue;                 /* not drawn in one process either (vt_draw.c) */
        ++nf;
        for (int k = 0; k < 3; ++k)
            if (remap[face->v[k]] == VT_NONE)
                remap[face->v[k]] = nv++;
    }
    /* Version 2: the samples of no drawn face too (a hidden face's, a
     * halo face's): the post-pass replays one process' refinement, which
     * needs them as well. */
    for (uint32_t v = 0; all_samples && v < m->num_verts; ++v)
        if (remap[v] == VT_NONE && m->verts[v].state == VT_SAMPLED)
            remap[v] = nv++;
    uint64_t payload = (uint64_t)nv * vbytes + (uint64_t)nf * FACE_BYTES;
    unsigned char *buf = malloc((size_t)(HEADER_BYTES + payload));
    if (!buf) {
        free(root);
        free(remap);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: a package's result of %u faces", nf);
    }
    /* Vertices in the order of their new numbers: the inverse of remap. */
    unsigned char *vp = buf + HEADER_BYTES, *fp = vp + (size_t)nv * vbytes;
    for (uint32_t v = 0; v < m->num_verts; ++v) {
        if (remap[v] == VT_NONE)
            continue;
        const vt_vertex *x = &m->verts[v];
        rl_trace_layer layers[RL_TRACE_LAYER_COUNT];
        vt_mesh_sample_layers(m, v, layers);
        unsigned char *p = vp + (size_t)remap[v] * vbytes;
        p = put_vec3(p, x->p);
        p = put_vec2(p, x->uv);
        p = put_vec3(p, m->samples[v].flat);
        for (int l = 0; l < RL_TRACE_LAYER_COUNT; ++l) {
            p = put_vec3(p, layers[l].diffuse);
            p = put_vec3(p, layers[l].rest);
            p = put(p, &layers[l].texture, 4);
            p = put_vec2(p, layers[l].uv);
        }
        if (all_samples) {
            p = put(p, &x->key, 8);
            p = put(p, &x->triangle, 4);
            uint64_t tree = vt_sample_tree(&m->samples[v]);
            put(p, &tree, 8);
        }
    }
    for (uint32_t f = 0; f < m->num_faces; ++f) {
        const vt_face *face = &m->faces[f];
        if (!face->leaf || root[f] == VT_NONE || mine[root[f]] != 1)
            continue;
        uint32_t idx[3] = { remap[face->v[0]], remap[face->v[1]], remap[face->v[2]] };
        if (idx[0] == VT_NONE || idx[1] == VT_NONE || idx[2] == VT_NONE)
            continue;
        uint16_t stage[2] = { face->stage, 0 };
        fp = put(fp, idx, sizeof idx);
        fp = put(fp, &face->triangle, 4);
        fp = put(fp, &d->triangle_object[face->triangle], 4);
        fp = put(fp, stage, sizeof stage);
    }
    uint32_t head[4] = { version, nv, nf, 0 };
    uint64_t sum = fnv1a(buf + HEADER_BYTES, (size_t)payload);
    unsigned char *p = put(buf, PART_MAGIC, 4);
    p = put(p, head, 3 * sizeof head[0]);
    p = put(p, &payload, 8);
    put(p, &sum, 8);
    free(root);
    free(remap);
    *out = buf;
    *size = (size_t)(HEADER_BYTES + payload);
    return RL_OK;
}

/* The header of a part: its fields, read once for vt_part_check and the
 * post-pass' map (vt_part_samples_add). */
typedef struct part_header {
    uint32_t version, num_verts, num_faces;
    uint64_t payload, sum;
} part_header;

/* The header's fields after its size, magic and version checks (the
 * payload is vt_part_check's). */
static rl_status read_header(const void *part, size_t size, part_header *h)
{
    memset(h, 0, sizeof *h);
    if (!part || size < HEADER_BYTES)
        return rl_error(RL_ERR_PARSE, "vt part: %zu bytes, shorter than its %u-byte header", size, HEADER_BYTES);
    const unsigned char *p = part;
    if (memcmp(p, PART_MAGIC, 4) != 0)
        return rl_error(RL_ERR_PARSE, "vt part: not a Vertex Tracing part (no \"" PART_MAGIC "\")");
    uint32_t head[3];
    p = get(p + 4, head, sizeof head);
    p = get(p, &h->payload, 8);
    get(p, &h->sum, 8);
    h->version = head[0];
    h->num_verts = head[1];
    h->num_faces = head[2];
    if (h->version != PART_VERSION && h->version != PART_VERSION_SAMPLES)
        return rl_error(RL_ERR_PARSE, "vt part: version %u (this build reads %u and %u)", h->version, PART_VERSION,
                        PART_VERSION_SAMPLES);
    return RL_OK;
}

rl_status vt_part_check(const void *part, size_t size, uint32_t *num_verts, uint32_t *num_faces)
{
    *num_verts = *num_faces = 0;
    part_header h;
    rl_status st = read_header(part, size, &h);
    if (st != RL_OK)
        return st;
    const uint32_t head[3] = { h.version, h.num_verts, h.num_faces };
    const uint64_t payload = h.payload, sum = h.sum;
    const uint32_t vbytes = vertex_bytes(head[0]);
    /* Counts below 2^32 keep the products far from overflowing 64 bits. */
    uint64_t want = (uint64_t)head[1] * vbytes + (uint64_t)head[2] * FACE_BYTES;
    if (payload != want || payload != size - HEADER_BYTES)
        return rl_error(RL_ERR_PARSE, "vt part: %u vertices and %u faces need %llu bytes; the header says %llu, "
                        "%zu came", head[1], head[2], (unsigned long long)want, (unsigned long long)payload,
                        size - HEADER_BYTES);
    const unsigned char *body = (const unsigned char *)part + HEADER_BYTES;
    if (fnv1a(body, (size_t)payload) != sum)
        return rl_error(RL_ERR_PARSE, "vt part: checksum mismatch (damaged in transit)");
    const unsigned char *fp = body + (size_t)head[1] * vbytes;
    for (uint32_t f = 0; f < head[2]; ++f) {
        uint32_t idx[3];
        get(fp + (size_t)f * FACE_BYTES, idx, sizeof idx);
        if (idx[0] >= head[1] || idx[1] >= head[1] || idx[2] >= head[1])
            return rl_error(RL_ERR_PARSE, "vt part: face %u names vertex %u of %u", f,
                            idx[0] >= head[1] ? idx[0] : idx[1] >= head[1] ? idx[1] : idx[2], head[1]);
    }
    *num_verts = head[1];
    *num_faces = head[2];
    return RL_OK;
}

rl_status vt_part_import(vt_mesh *m, const rl_scene_data *d, const void *part, size_t size)
{
    uint32_t nv, nf;
    rl_status st = vt_part_check(part, size, &nv, &nf);
    if (st != RL_OK)
        return st;
    if ((st = vt_mesh_reserve(m, nv, 0, nf)) != RL_OK)
        return st;
    part_header h;
    if ((st = read_header(part, size, &h)) != RL_OK)
        return st;
    const uint32_t version = h.version;
    const unsigned char *p = (const unsigned char *)part + HEADER_BYTES;
    const uint32_t first = m->num_verts;
    for (uint32_t v = 0; v < nv; ++v) {
        vt_vertex *x = &m->verts[first + v];
        vt_vertex_sample s;
        rl_trace_layer layers[RL_TRACE_LAYER_COUNT];
        memset(x, 0, sizeof *x);
        p = get_vertex_sample(p, &x->p, &x->uv, &s, layers);
        if (version == PART_VERSION_SAMPLES)
            p += VERTEX_EXTRA_BYTES;  /* the post-pass' identity; drawing needs none */
        /* Before any face names it: a failure leaves the mesh as it was
         * but for unused room in the layer pool. */
        if ((st = vt_mesh_set_sample(m, first + v, &s, layers)) != RL_OK)
            return st;
        x->state = VT_SAMPLED;
        x->visible = 1;
    }
    /* Faces last: a bad one leaves the mesh as it was (the vertices past
     * num_verts are not the mesh's yet). */
    const uint32_t first_face = m->num_faces;
    for (uint32_t f = 0; f < nf; ++f) {
        uint32_t idx[3], tri, obj;
        uint16_t stage[2];
        p = get(p, idx, sizeof idx);
        p = get(p, &tri, 4);
        p = get(p, &obj, 4);
        p = get(p, stage, sizeof stage);
        /* The object is the triangle's; a part that says otherwise is
         * not of this scene. */
        if (tri >= d->num_triangles)
            return rl_error(RL_ERR_PARSE, "vt part: face %u names triangle %u; the scene has %u (a part of another "
                            "scene?)", f, tri, d->num_triangles);
        if (obj != d->triangle_object[tri])
            return rl_error(RL_ERR_PARSE, "vt part: face %u puts triangle %u in object %u; the scene has it in %u "
                            "(a part of another scene?)", f, tri, obj, d->triangle_object[tri]);
        vt_face *face = &m->faces[first_face + f];
        memset(face, 0, sizeof *face);
        for (int k = 0; k < 3; ++k) {
            face->v[k] = first + idx[k];
            face->e[k] = VT_NONE;
        }
        face->triangle = tri;
        face->seq = m->num_created++;
        face->stage = stage[0];
        face->leaf = 1;
        face->visible = 1;
        face->height = -1.0f;
    }
    m->num_verts += nv;
    m->num_faces += nf;
    return RL_OK;
}

/* ------------------------------------------- the post-pass' samples -- */

/* Moves the map's entries into a table of cap slots (a power of two). */
static rl_status samples_rehash(vt_part_samples *ps, size_t cap)
{
    uint64_t *keys = rl_calloc(cap, sizeof *keys);
    const unsigned char **rec = rl_realloc_array(NULL, cap, sizeof *rec);
    if (!keys || !rec) {
        free(keys);
        free(rec);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: the post-pass' map of %zu samples", cap / 2);
    }
    for (size_t i = 0; i < ps->cap; ++i) {
        if (!ps->keys[i])
            continue;
        size_t k = (size_t)(rl_hash64(ps->keys[i]) & (uint64_t)(cap - 1));
        while (keys[k])
            k = (k + 1) & (cap - 1);
        keys[k] = ps->keys[i];
        rec[k] = ps->rec[i];
    }
    free(ps->keys);
    free(ps->rec);
    ps->keys = keys;
    ps->rec = rec;
    ps->cap = cap;
    return RL_OK;
}

rl_status vt_part_samples_add(vt_part_samples *ps, const void *part, size_t size)
{
    part_header h;
    rl_status st = read_header(part, size, &h);
    if (st != RL_OK)
        return st;
    if (h.version != PART_VERSION_SAMPLES || !h.num_verts)
        return RL_OK;           /* no samples: the post-pass traces what it needs */
    /* Load factor <= 1/2: every vertex the frame's refinement makes is
     * looked up once, most of them found. The table doubles as parts come
     * (a part at a time while the replay runs, rl_vt_postpass_add). */
    const uint64_t need = 2 * ((uint64_t)ps->count + h.num_verts);
    if (need > ps->cap) {
        size_t cap = ps->cap ? ps->cap : 64;
        while (cap < need)
            cap *= 2;
        if ((st = samples_rehash(ps, cap)) != RL_OK)
            return st;
    }
    const size_t cap = ps->cap;
    const uint32_t vbytes = vertex_bytes(PART_VERSION_SAMPLES);
    const unsigned char *body = (const unsigned char *)part + HEADER_BYTES;
    for (uint32_t v = 0; v < h.num_verts; ++v) {
        const unsigned char *rec = body + (size_t)v * vbytes;
        uint64_t key;
        memcpy(&key, rec + VERTEX_BYTES, 8);
        key = vt_key_nonzero(key);
        size_t k = (size_t)(rl_hash64(key) & (uint64_t)(cap - 1));
        while (ps->keys[k] && ps->keys[k] != key)
            k = (k + 1) & (cap - 1);
        if (ps->keys[k])
            continue;     /* a border vertex both sides sampled: the same sample */
        ps->keys[k] = key;
        ps->rec[k] = rec;
        ps->count++;
    }
    return RL_OK;
}

bool vt_part_samples_take(const vt_part_samples *ps, vt_mesh *m, uint32_t v, bool *failed)
{
    if (!ps || !ps->cap)
        return false;
    const vt_vertex *x = &m->verts[v];
    const uint64_t key = vt_key_nonzero(x->key);
    size_t k = (size_t)(rl_hash64(key) & (uint64_t)(ps->cap - 1));
    while (ps->keys[k] && ps->keys[k] != key)
        k = (k + 1) & (ps->cap - 1);
    if (!ps->keys[k])
        return false;
    /* The key is a hash: the position and triangle must agree too, or the
     * vertex is traced (a sample depends only on those, Sec. 4.4). */
    const unsigned char *p = ps->rec[k];
    float pos[3];
    uint32_t tri;
    memcpy(pos, p, sizeof pos);
    memcpy(&tri, p + VERTEX_BYTES + 8, 4);
    const float mine[3] = { x->p.x, x->p.y, x->p.z };
    if (memcmp(pos, mine, sizeof pos) != 0 || tri != x->triangle)
        return false;
    vt_vertex_sample s;
    rl_trace_layer layers[RL_TRACE_LAYER_COUNT];
    rl_vec3 skip3;
    rl_vec2 skip2;
    p = get_vertex_sample(p, &skip3, &skip2, &s, layers);
    uint64_t tree;
    memcpy(&tree, p + 12, 8);
    vt_sample_set_tree(&s, tree);
    if (vt_mesh_set_sample(m, v, &s, layers) != RL_OK) {
        *failed = true;
        return false;
    }
    return true;
}

void vt_part_samples_free(vt_part_samples *ps)
{
    free(ps->keys);
    free(ps->rec);
    memset(ps, 0, sizeof *ps);
}
