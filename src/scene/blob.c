/* blob.c: a closed genus-0 triangle mesh with exactly the requested (even)
 * number of triangles, shaped like an organic object: a sphere with a few
 * smooth random lumps. It replaces the Stanford bunny (69,451 triangles)
 * and dragon (871,306) of Schröder 2017, Sec. 9.3, where only the count
 * and a closed, irregular surface matter.
 *
 * Why even: a closed 2-manifold has 3T = 2E, so T is even (T = 2V - 4 for
 * genus 0); the thesis' 69,451-triangle bunny is the open scanned mesh.
 *
 * Construction (all on the unit sphere of directions, displaced last):
 *  1. Base: the octahedron |x|+|y|+|z| = K on the integer lattice, each face
 *     cut into K^2 triangles (8 K^2 in all, K = floor(sqrt(T/8))); for
 *     T < 8 the tetrahedron. Lattice points get their index from their
 *     latitude ring, so shared edges share vertices without welding.
 *  2. Exact count: each split of an edge shared by two triangles (a new
 *     vertex in its middle, both triangles halved) adds exactly 2
 *     triangles; (T - base) / 2 splits are made, longest chord first with
 *     ties broken by vertex index, at most one split per triangle per
 *     round (rounds repeat only for tiny meshes). Long edges first keeps
 *     the added vertices where the projected lattice is coarsest.
 *  3. Shape: vertex v = dir * R(dir) with R = scale * max(0.3, 1 + sum of
 *     lumps a_i exp((dir·c_i - 1) / w_i^2)) (seeded centres c_i, heights
 *     a_i in [-0.2, 0.45], angular widths w_i in [0.2, 0.55] rad), then a
 *     fixed mild anisotropic scale (1, 0.85, 0.9).
 * No self-intersections, by construction: every spherical triangle (a, b,
 * c) is positively oriented (det > 0; a split keeps this since
 * det(a, (a+b)/|a+b|, c) = det(a, b, c) / |a+b|), so the triangle through
 * r_a a, r_b b, r_c c faces away from the origin for any positive radii
 * (its normal · r_a a = r_a r_b r_c det(a, b, c)); the surface is a radial
 * graph, star-shaped from the origin, and a positive diagonal scale keeps
 * it embedded. Normals are area-weighted vertex normals; uv is the
 * longitude/latitude of the direction. */
#include "scene/blob.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_rng.h"

typedef struct mesh {
    rl_vec3 *dirs;            /* unit directions */
    uint32_t *tris;           /* 3 per triangle, counter-clockwise from outside */
    uint32_t nv, nt, cap_v, cap_t;
} mesh;

/* ---- 1. base meshes ------------------------------------------------------ */

/* Index of lattice point (x, y, z), |x|+|y|+|z| = K: rings of constant y
 * from y = -K upwards; ring r = K - |y| holds 4r points (1 at the poles),
 * walked counter-clockwise seen from +y starting at (r, y, 0). */
static uint32_t lattice_index(const uint32_t *ring_offset, int K, int x, int y, int z)
{
    int r = K - abs(y);
    uint32_t base = ring_offset[y + K];
    if (r == 0)
        return base;
    int t;
    if (x > 0 && z >= 0)
        t = z;
    else if (x <= 0 && z > 0)
        t = r - x;
    else if (x < 0 && z <= 0)
        t = 2 * r - z;
    else
        t = 3 * r + x;
    return base + (uint32_t)t;
}

static rl_vec3 ring_point(int K, int y, int t)
{
    int r = K - abs(y), x, z;
    if (r == 0)
        return rl_v3(0.0f, (float)y, 0.0f);
    int q = t / r, s = t % r;
    switch (q) {
    case 0:  x = r - s; z = s; break;
    case 1:  x = -s; z = r - s; break;
    case 2:  x = -(r - s); z = -s; break;
    default: x = s; z = -(r - s); break;
    }
    return rl_v3((float)x, (float)y, (float)z);
}

static int64_t det3(const int p[3][3])
{
    return (int64_t)p[0][0] * ((int64_t)p[1][1] * p[2][2] - (int64_t)p[1][2] * p[2][1]) -
           (int64_t)p[0][1] * ((int64_t)p[1][0] * p[2][2] - (int64_t)p[1][2] * p[2][0]) +
           (int64_t)p[0][2] * ((int64_t)p[1][0] * p[2][1] - (int64_t)p[1][1] * p[2][0]);
}

static void octahedron(mesh *m, int K, uint32_t *ring_offset)
{
    uint32_t off = 0;
    for (int y = -K; y <= K; ++y) {
        ring_offset[y + K] = off;
        int r = K - abs(y);
        uint32_t size = r == 0 ? 1u : 4u * (uint32_t)r;
        for (uint32_t t = 0; t < size; ++t)
            m->dirs[off + t] = rl_normalize(ring_point(K, y, (int)t));
        off += size;
    }
    m->nv = off;
    uint32_t nt = 0;
    for (int oct = 0; oct < 8; ++oct) {
        const int sx = oct & 1 ? -1 : 1, sy = oct & 2 ? -1 : 1, sz = oct & 4 ? -1 : 1;
        for (int a = 0; a < K; ++a)
            for (int c = 0; c < K - a; ++c) {
                const int b = K - a - c;
                /* The "up" triangle, then (where it fits) the "down" one,
                 * in (a, b, c) lattice coordinates of this octant. */
                const int tri[2][3][3] = {
                    { { a, b, c }, { a + 1, b - 1, c }, { a, b - 1, c + 1 } },
                    { { a + 1, b - 1, c }, { a + 1, b - 2, c + 1 }, { a, b - 1, c + 1 } },
                };
                for (int k = 0; k < (b >= 2 ? 2 : 1); ++k) {
                    int p[3][3];
                    for (int v = 0; v < 3; ++v) {
                        p[v][0] = sx * tri[k][v][0];
                        p[v][1] = sy * tri[k][v][1];
                        p[v][2] = sz * tri[k][v][2];
                    }
                    /* Mirrored octants flip the winding: orient outwards by
                     * the exact integer determinant. */
                    int order[3] = { 0, 1, 2 };
                    if (det3(p) < 0) {
                        order[1] = 2;
                        order[2] = 1;
                    }
                    for (int v = 0; v < 3; ++v)
                        m->tris[3 * nt + v] = lattice_index(ring_offset, K, p[order[v]][0],
                                                            p[order[v]][1], p[order[v]][2]);
                    ++nt;
                }
            }
    }
    m->nt = nt;
}

static void tetrahedron(mesh *m)
{
    const float s = 1.0f / sqrtf(3.0f);
    m->dirs[0] = rl_v3(s, s, s);
    m->dirs[1] = rl_v3(s, -s, -s);
    m->dirs[2] = rl_v3(-s, s, -s);
    m->dirs[3] = rl_v3(-s, -s, s);
    /* Counter-clockwise seen from outside (det > 0). */
    static const uint32_t t[4][3] = { { 0, 1, 2 }, { 0, 3, 1 }, { 0, 2, 3 }, { 1, 3, 2 } };
    memcpy(m->tris, t, sizeof t);
    m->nv = 4;
    m->nt = 4;
}

/* ---- 2. edge splits to the exact count ---------------------------------- */

typedef struct edge_ref {
    float len2;
    uint32_t a, b;            /* a < b */
    uint32_t he;              /* half-edge a -> b: 3 * triangle + corner */
} edge_ref;

static int by_length_desc(const void *pa, const void *pb)
{
    const edge_ref *x = pa, *y = pb;
    if (x->len2 != y->len2)
        return x->len2 < y->len2 ? 1 : -1;
    if (x->a != y->a)
        return x->a < y->a ? -1 : 1;
    return x->b < y->b ? -1 : (x->b > y->b);
}

/* Open-addressing map from a directed edge (a << 32 | b) to its half-edge. */
typedef struct edge_map {
    uint64_t *keys;
    uint32_t *values;
    uint64_t mask;
} edge_map;

#define EMPTY_KEY UINT64_MAX

static uint64_t slot_of(const edge_map *h, uint64_t key) { return rl_hash64(key) & h->mask; }

static void map_put(edge_map *h, uint64_t key, uint32_t value)
{
    uint64_t i = slot_of(h, key);
    while (h->keys[i] != EMPTY_KEY)
        i = (i + 1) & h->mask;
    h->keys[i] = key;
    h->values[i] = value;
}

static uint32_t map_get(const edge_map *h, uint64_t key)
{
    for (uint64_t i = slot_of(h, key);; i = (i + 1) & h->mask) {
        if (h->keys[i] == key)
            return h->values[i];
        if (h->keys[i] == EMPTY_KEY)
            return UINT32_MAX;
    }
}

/* One round: as many independent splits (no triangle touched twice) as
 * needed and possible. Returns the number made, or UINT32_MAX on OOM. */
static uint32_t split_round(mesh *m, uint32_t need)
{
    const uint32_t nhe = 3 * m->nt;
    uint64_t cap = 16;
    while (cap < 2ull * nhe)
        cap *= 2;
    edge_map h = { rl_alloc(cap * sizeof *h.keys), rl_alloc(cap * sizeof *h.values), cap - 1 };
    edge_ref *edges = rl_alloc((size_t)nhe / 2 * sizeof *edges + sizeof *edges);
    uint8_t *used = rl_calloc(m->nt, 1);
    uint32_t made = UINT32_MAX;
    if (!h.keys || !h.values || !edges || !used)
        goto done;
    memset(h.keys, 0xFF, cap * sizeof *h.keys);
    uint32_t ne = 0;
    for (uint32_t he = 0; he < nhe; ++he) {
        uint32_t t = he / 3, k = he % 3;
        uint32_t a = m->tris[3 * t + k], b = m->tris[3 * t + (k + 1) % 3];
        map_put(&h, (uint64_t)a << 32 | b, he);
        if (a < b)
            edges[ne++] = (edge_ref){ rl_length2(rl_sub(m->dirs[a], m->dirs[b])), a, b, he };
    }
    qsort(edges, ne, sizeof *edges, by_length_desc);
    made = 0;
    for (uint32_t i = 0; i < ne && made < need; ++i) {
        uint32_t he1 = edges[i].he, he2 = map_get(&h, (uint64_t)edges[i].b << 32 | edges[i].a);
        uint32_t t1 = he1 / 3, t2 = he2 / 3;
        if (he2 == UINT32_MAX || used[t1] || used[t2])
            continue;
        used[t1] = used[t2] = 1;
        /* t1 = (a, b, c), t2 = (b, a, d) in their own corner order. */
        uint32_t a = edges[i].a, b = edges[i].b;
        uint32_t c = m->tris[3 * t1 + (he1 % 3 + 2) % 3], d = m->tris[3 * t2 + (he2 % 3 + 2) % 3];
        uint32_t mid = m->nv++;
        m->dirs[mid] = rl_normalize(rl_add(m->dirs[a], m->dirs[b]));
        uint32_t n1 = m->nt++, n2 = m->nt++;
        const uint32_t quad[4][3] = { { a, mid, c }, { mid, b, c }, { b, mid, d }, { mid, a, d } };
        const uint32_t where[4] = { t1, n1, t2, n2 };
        for (int q = 0; q < 4; ++q)
            memcpy(&m->tris[3 * where[q]], quad[q], sizeof quad[q]);
        ++made;
    }
done:
    free(h.keys);
    free(h.values);
    free(edges);
    free(used);
    return made;
}

/* ---- 3. shape ------------------------------------------------------------ */

typedef struct lump {
    rl_vec3 centre;
    float height, inv_w2;
} lump;

static rl_vec3 random_direction(rl_rng *rng)
{
    float z = 2.0f * rl_rng_float(rng) - 1.0f, phi = 2.0f * RL_PI * rl_rng_float(rng);
    float s = sqrtf(fmaxf(0.0f, 1.0f - z * z));
    return rl_v3(s * cosf(phi), z, s * sinf(phi));
}

static rl_vec3 displace(rl_vec3 dir, const lump *lumps, int count, float scale)
{
    float r = 1.0f;
    for (int i = 0; i < count; ++i)
        r += lumps[i].height * expf((rl_dot(dir, lumps[i].centre) - 1.0f) * lumps[i].inv_w2);
    r = scale * fmaxf(r, 0.3f);
    return rl_v3(dir.x * r, dir.y * r * 0.85f, dir.z * r * 0.9f);
}

/* ---- entry point --------------------------------------------------------- */

rl_status rl_gen_blob(rl_meshbuf *b, const rl_blob_desc *desc)
{
    if (!b || !desc)
        return rl_error(RL_ERR_INVALID_ARG, "blob: NULL argument");
    const uint32_t T = desc->triangles;
    if (T < RL_BLOB_MIN_TRIANGLES || T > RL_BLOB_MAX_TRIANGLES)
        return rl_error(RL_ERR_INVALID_ARG, "blob: triangles=%u outside %u..%u", T,
                        RL_BLOB_MIN_TRIANGLES, RL_BLOB_MAX_TRIANGLES);
    if (T % 2)
        return rl_error(RL_ERR_INVALID_ARG, "blob: triangles=%u is odd; a closed triangle "
                        "mesh has an even count (3T = 2E; T = 2V - 4 for a sphere)", T);
    if (!(desc->scale > 0.0f) || !isfinite(desc->scale))
        return rl_error(RL_ERR_INVALID_ARG, "blob: scale %g must be finite and > 0",
                        (double)desc->scale);
    if (desc->lumps < 0 || desc->lumps > RL_BLOB_MAX_LUMPS)
        return rl_error(RL_ERR_INVALID_ARG, "blob: lumps=%d outside 0..%d", desc->lumps,
                        RL_BLOB_MAX_LUMPS);

    int K = 0;
    if (T >= 8) {
        K = (int)sqrt((double)T / 8.0);
        while (8ull * (uint64_t)(K + 1) * (uint64_t)(K + 1) <= T)
            ++K;
        while (8ull * (uint64_t)K * (uint64_t)K > T)
            --K;
    }
    /* Genus 0: V = T/2 + 2. */
    mesh m = { .cap_v = T / 2 + 2, .cap_t = T };
    m.dirs = rl_alloc((size_t)m.cap_v * sizeof *m.dirs);
    m.tris = rl_alloc((size_t)m.cap_t * 3 * sizeof *m.tris);
    uint32_t *ring_offset = rl_alloc((size_t)(2 * K + 1) * sizeof *ring_offset);
    rl_status s = RL_OK;
    if (!m.dirs || !m.tris || !ring_offset) {
        s = RL_ERR_OUT_OF_MEMORY;
        goto done;
    }
    if (K == 0)
        tetrahedron(&m);
    else
        octahedron(&m, K, ring_offset);
    while (m.nt < T) {
        uint32_t made = split_round(&m, (T - m.nt) / 2);
        if (made == UINT32_MAX) {
            s = RL_ERR_OUT_OF_MEMORY;
            goto done;
        }
        if (made == 0) {
            s = rl_error(RL_ERR_INTERNAL, "blob: no edge left to split at %u triangles", m.nt);
            goto done;
        }
    }

    /* Lumps: seeded, so a seed always gives the same shape. */
    lump lumps[RL_BLOB_MAX_LUMPS];
    rl_rng rng;
    rl_rng_seed(&rng, desc->seed, 0xB10B);
    for (int i = 0; i < desc->lumps; ++i) {
        lumps[i].centre = random_direction(&rng);
        lumps[i].height = -0.2f + 0.65f * rl_rng_float(&rng);
        float w = 0.2f + 0.35f * rl_rng_float(&rng);
        lumps[i].inv_w2 = 1.0f / (w * w);
    }

    if (!rl_meshbuf_reserve(b, m.nv, m.nt)) {
        s = b->status;
        goto done;
    }
    const uint32_t base = b->num_vertices;
    rl_vec3 *pos = b->positions + base, *nrm = b->normals + base;
    rl_vec2 *uv = b->uvs + base;
    const int nv = (int)m.nv, nt = (int)m.nt;
    #pragma omp parallel for schedule(static)
    for (int i = 0; i < nv; ++i) {
        rl_vec3 d = m.dirs[i];
        pos[i] = displace(d, lumps, desc->lumps, desc->scale);
        nrm[i] = rl_v3s(0.0f);
        uv[i] = rl_v2(0.5f + atan2f(-d.z, d.x) / (2.0f * RL_PI),
                      1.0f - acosf(rl_clampf(d.y, -1.0f, 1.0f)) / RL_PI);
    }
    /* Area-weighted vertex normals (the cross product's length is twice
     * the area); serial scatter keeps the sums deterministic. */
    for (int t = 0; t < nt; ++t) {
        const uint32_t *v = &m.tris[3 * t];
        rl_vec3 n = rl_cross(rl_sub(pos[v[1]], pos[v[0]]), rl_sub(pos[v[2]], pos[v[0]]));
        for (int k = 0; k < 3; ++k)
            nrm[v[k]] = rl_add(nrm[v[k]], n);
    }
    #pragma omp parallel for schedule(static)
    for (int i = 0; i < nv; ++i)
        nrm[i] = rl_normalize(nrm[i]);
    uint32_t *idx = b->indices + 3 * (size_t)b->num_triangles;
    for (size_t i = 0; i < 3 * (size_t)m.nt; ++i)
        idx[i] = m.tris[i] + base;
    for (uint32_t t = 0; t < m.nt; ++t)
        b->materials[b->num_triangles + t] = b->material;
    b->num_vertices += m.nv;
    b->num_triangles += m.nt;
done:
    free(m.dirs);
    free(m.tris);
    free(ring_offset);
    return s;
}
