/* import_stream.c: the result of an isolated import (load_isolate.c) as
 * bytes from the child process to the parent, and their complete check
 * before the parent's scene is touched.
 *
 * The child imports into its own copy of the parent's scene (fork), so an
 * id it hands out is the id the same item gets when the parent appends the
 * items in the same order; the stream carries only what the import
 * appended, as our own plain data (no Assimp structure crosses). Layout, in
 * host byte order (both ends are one binary):
 *     header  "RLIMPORT", u32 version, u32 0
 *     record  u32 tag, u32 0, u64 length, length bytes of payload
 * BASE comes first (the counts of the scene the child started from), then
 * WARNING records as the import logs them, then either one ERROR or the
 * data (TEXTURE, MATERIAL, MESH, NODE, CAMERA, LIGHT records, DROPS, ROOT),
 * and END last, with the number of records before it.
 *
 * The parent reads the stream twice: first checking everything (each
 * payload's size against its counts, ids against what exists by then,
 * floats finite, the validators the scene's setters run) without touching
 * the scene, then applying it. So a truncated or corrupted stream, or one
 * from a child that was taken over by a hostile file, costs an error and
 * leaves the scene as it was. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/error.h"
#include "scene/load_internal.h"
#include "scene/scene_internal.h"

#define STREAM_MAGIC "RLIMPORT"
#define STREAM_VERSION 1u
#define MAX_TEXT 4096u             /* names, paths and messages, with the NUL */
#define WRITE_CHUNK (1u << 20)     /* the child's write buffer */

enum {
    TAG_BASE = 1, TAG_WARNING, TAG_ERROR, TAG_TEXTURE, TAG_MATERIAL, TAG_MESH, TAG_NODE,
    TAG_CAMERA, TAG_LIGHT, TAG_DROPS, TAG_ROOT, TAG_END
};

static rl_import_counts counts_of(const rl_scene *s)
{
    rl_import_counts c = { s->num_nodes, s->num_meshes, s->num_materials,
                           s->num_textures, s->num_cameras, s->num_lights };
    return c;
}

/* ---- writing, in the child ---------------------------------------------- */

static void write_all(rl_import_writer *w, const uint8_t *p, size_t n)
{
    while (n > 0 && !w->failed) {
        ssize_t k = write(w->fd, p, n);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0) {
            w->failed = true;
            break;
        }
        p += k;
        n -= (size_t)k;
    }
}

bool rl_import_writer_flush(rl_import_writer *w)
{
    if (w->fd >= 0 && w->len > 0) {
        write_all(w, w->buf, w->len);
        w->len = 0;
    }
    return !w->failed;
}

static void put(rl_import_writer *w, const void *data, size_t n)
{
    if (w->failed || n == 0)
        return;
    if (w->fd >= 0) {
        if (w->len + n > w->cap && !rl_import_writer_flush(w))
            return;
        if (n >= w->cap) {   /* a big array goes out directly, not copied */
            write_all(w, data, n);
            return;
        }
    } else if (!rl_reserve((void **)&w->buf, &w->cap, w->len + n, 1, 4096)) {
        w->failed = true;
        return;
    }
    memcpy(w->buf + w->len, data, n);
    w->len += n;
}

static void put_u32(rl_import_writer *w, uint32_t v) { put(w, &v, sizeof v); }
static void put_u64(rl_import_writer *w, uint64_t v) { put(w, &v, sizeof v); }

static uint32_t text_len(const char *s)
{
    size_t n = s ? strlen(s) : 0;
    return n < MAX_TEXT ? (uint32_t)n : MAX_TEXT - 1;
}

static uint64_t text_size(const char *s) { return 4u + text_len(s); }

static void put_text(rl_import_writer *w, const char *s)
{
    uint32_t n = text_len(s);
    put_u32(w, n);
    put(w, s, n);
}

static void begin_record(rl_import_writer *w, uint32_t tag, uint64_t length)
{
    put_u32(w, tag);
    put_u32(w, 0);
    put_u64(w, length);
    w->records++;
}

void rl_import_writer_init(rl_import_writer *w, int fd, const rl_scene *scene)
{
    memset(w, 0, sizeof *w);
    w->fd = fd;
    if (fd >= 0) {
        w->cap = WRITE_CHUNK;
        w->buf = malloc(w->cap);
        w->failed = !w->buf;
    }
    w->base = counts_of(scene);
    w->degenerate0 = scene->dropped_degenerate;
    w->nonfinite0 = scene->dropped_nonfinite;
    put(w, STREAM_MAGIC, 8);
    put_u32(w, STREAM_VERSION);
    put_u32(w, 0);
    begin_record(w, TAG_BASE, 6 * 4);
    const rl_import_counts *b = &w->base;
    uint32_t fields[6] = { b->nodes, b->meshes, b->materials, b->textures, b->cameras, b->lights };
    put(w, fields, sizeof fields);
}

void rl_import_writer_warning(rl_import_writer *w, rl_log_level level, const char *text)
{
    begin_record(w, TAG_WARNING, 4 + text_size(text));
    put_u32(w, (uint32_t)level);
    put_text(w, text);
}

static void write_texture(rl_import_writer *w, const rl_scene *s, uint32_t i)
{
    const rl_texture *t = s->textures[i];
    uint64_t texels = (uint64_t)t->width * (uint64_t)t->height * sizeof *t->texels;
    begin_record(w, TAG_TEXTURE, 8 + text_size(s->texture_paths[i]) + text_size(t->path) + texels);
    put_u32(w, (uint32_t)t->width);
    put_u32(w, (uint32_t)t->height);
    put_text(w, s->texture_paths[i]);
    put_text(w, t->path);
    put(w, t->texels, (size_t)texels);
}

static void write_mesh(rl_import_writer *w, const rl_mesh *m)
{
    uint64_t nv = m->num_vertices, nt = m->num_triangles;
    begin_record(w, TAG_MESH, text_size(m->name) + 8 + nv * 32 + nt * 16);
    put_text(w, m->name);
    put_u32(w, m->num_vertices);
    put_u32(w, m->num_triangles);
    put(w, m->positions, (size_t)nv * sizeof *m->positions);
    put(w, m->normals, (size_t)nv * sizeof *m->normals);
    put(w, m->uvs, (size_t)nv * sizeof *m->uvs);
    put(w, m->indices, (size_t)nt * 3 * sizeof *m->indices);
    put(w, m->materials, (size_t)nt * sizeof *m->materials);
}

static void write_node(rl_import_writer *w, const rl_node *n)
{
    begin_record(w, TAG_NODE, text_size(n->name) + 12 + sizeof n->local);
    put_text(w, n->name);
    put_u32(w, n->parent);
    put_u32(w, n->mesh);
    put_u32(w, n->material);
    put(w, &n->local, sizeof n->local);
}

void rl_import_writer_finish(rl_import_writer *w, const rl_scene *s, rl_status status,
                             const char *message, uint32_t root)
{
    if (status != RL_OK) {
        begin_record(w, TAG_ERROR, 4 + text_size(message));
        put_u32(w, (uint32_t)status);
        put_text(w, message);
    } else {
        const rl_import_counts *b = &w->base;
        for (uint32_t i = b->textures; i < s->num_textures; ++i)
            write_texture(w, s, i);
        for (uint32_t i = b->materials; i < s->num_materials; ++i) {
            begin_record(w, TAG_MATERIAL, sizeof s->materials[i]);
            put(w, &s->materials[i], sizeof s->materials[i]);
        }
        for (uint32_t i = b->meshes; i < s->num_meshes; ++i)
            write_mesh(w, &s->meshes[i]);
        for (uint32_t i = b->nodes; i < s->num_nodes; ++i)
            write_node(w, &s->nodes[i]);
        for (uint32_t i = b->cameras; i < s->num_cameras; ++i) {
            begin_record(w, TAG_CAMERA, text_size(s->camera_names[i]) + sizeof s->cameras[i]);
            put_text(w, s->camera_names[i]);
            put(w, &s->cameras[i], sizeof s->cameras[i]);
        }
        for (uint32_t i = b->lights; i < s->num_lights; ++i) {
            begin_record(w, TAG_LIGHT, sizeof s->lights[i]);
            put(w, &s->lights[i], sizeof s->lights[i]);
        }
        begin_record(w, TAG_DROPS, 16);
        put_u64(w, s->dropped_degenerate - w->degenerate0);
        put_u64(w, s->dropped_nonfinite - w->nonfinite0);
        begin_record(w, TAG_ROOT, 4);
        put_u32(w, root);
    }
    uint32_t before = w->records;
    begin_record(w, TAG_END, 4);
    put_u32(w, before);
    rl_import_writer_flush(w);
}

void rl_import_writer_free(rl_import_writer *w)
{
    free(w->buf);
    memset(w, 0, sizeof *w);
    w->fd = -1;
}

/* ---- reading, in the parent --------------------------------------------- */

typedef struct cursor {
    const uint8_t *p;
    size_t left;
} cursor;

static bool take(cursor *c, void *out, size_t n)
{
    if (c->left < n)
        return false;
    if (out)
        memcpy(out, c->p, n);
    c->p += n;
    c->left -= n;
    return true;
}

static bool take_u32(cursor *c, uint32_t *v) { return take(c, v, sizeof *v); }

/* A length-prefixed string without NUL bytes, into out[MAX_TEXT]. */
static bool take_text(cursor *c, char *out)
{
    uint32_t n;
    if (!take_u32(c, &n) || n >= MAX_TEXT || c->left < n || memchr(c->p, '\0', n))
        return false;
    take(c, out, n);
    out[n] = '\0';
    return true;
}

typedef struct reader {
    rl_scene *scene;
    const char *path;
    uint32_t parent;
    bool apply;                   /* false: check only */
    rl_import_counts base, seen;  /* seen: items of the stream so far */
    bool has_base, has_data, has_root, ended;
    rl_status child_status;       /* RL_OK unless an ERROR record came */
    char child_message[MAX_TEXT];
    uint32_t root;
    uint32_t records;
    char why[256];                /* what is malformed */
} reader;

static bool bad(reader *r, const char *fmt, ...) RL_PRINTF(2, 3);
static bool bad(reader *r, const char *fmt, ...)
{
    if (!r->why[0]) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(r->why, sizeof r->why, fmt, ap);
        va_end(ap);
    }
    return false;
}

static bool finite_floats(const uint8_t *p, size_t count)
{
    for (size_t i = 0; i < count; ++i) {
        float f;
        memcpy(&f, p + 4 * i, 4);
        if (!isfinite(f))
            return false;
    }
    return true;
}

/* Ids a record may refer to: those that existed (base) plus those the
 * stream has added so far. */
static bool known(uint32_t id, uint32_t base, uint32_t seen) { return id < base + seen; }

static bool read_base(reader *r, cursor *c)
{
    uint32_t f[6];
    if (r->records != 0 || !take(c, f, sizeof f))
        return bad(r, "no BASE record first");
    rl_import_counts now = counts_of(r->scene);
    rl_import_counts b = { f[0], f[1], f[2], f[3], f[4], f[5] };
    if (memcmp(&b, &now, sizeof b) != 0)
        return bad(r, "it started from another scene (%u nodes, this one has %u)", b.nodes,
                   now.nodes);
    r->base = b;
    r->has_base = true;
    return true;
}

static bool read_warning(reader *r, cursor *c)
{
    uint32_t level;
    char text[MAX_TEXT];
    if (!take_u32(c, &level) || !take_text(c, text) || level > RL_LOG_DEBUG)
        return bad(r, "bad warning record");
    if (r->apply)
        rl_log((rl_log_level)level, "%s", text);
    return true;
}

static bool read_error(reader *r, cursor *c)
{
    uint32_t status;
    if (!take_u32(c, &status) || !take_text(c, r->child_message) || status == RL_OK ||
        status >= RL_STATUS_COUNT)
        return bad(r, "bad error record");
    if (r->child_status != RL_OK || r->has_data)
        return bad(r, "an error record besides data");
    r->child_status = (rl_status)status;
    return true;
}

static bool read_texture(reader *r, cursor *c)
{
    uint32_t w, h;
    char resolved[MAX_TEXT], origin[MAX_TEXT];
    if (!take_u32(c, &w) || !take_u32(c, &h) || !take_text(c, resolved) || !take_text(c, origin))
        return bad(r, "texture %u: truncated", r->seen.textures);
    if (w > RL_IMAGE_MAX_SIZE || h > RL_IMAGE_MAX_SIZE ||
        rl_texture_check_size(r->path, w, h) != RL_OK)
        return bad(r, "texture %u: size %ux%u", r->seen.textures, w, h);
    size_t n = (size_t)w * h;
    if (c->left != n * sizeof(rl_vec4) || !finite_floats(c->p, 4 * n))
        return bad(r, "texture %u: texels do not match its %ux%u size or are not finite",
                   r->seen.textures, w, h);
    if (r->apply) {
        rl_texture *tex = NULL;
        rl_vec4 *texels = rl_alloc(n * sizeof *texels);
        if (!texels)
            return false;
        memcpy(texels, c->p, n * sizeof *texels);
        rl_status st = rl_texture_create((int)w, (int)h, texels, &tex);
        free(texels);
        if (st == RL_OK && origin[0] && !(tex->path = rl_strdup(origin)))
            st = RL_ERR_OUT_OF_MEMORY;
        if (st == RL_OK)
            st = rl_scene_push_texture(r->scene, tex, resolved[0] ? resolved : NULL, NULL);
        if (st != RL_OK) {
            rl_texture_release(tex);
            return false;
        }
    }
    c->left = 0;
    r->seen.textures++;
    return true;
}

static bool texture_ok(const reader *r, uint32_t id)
{
    return id == RL_NONE || known(id, r->base.textures, r->seen.textures);
}

static bool read_material(reader *r, cursor *c)
{
    rl_material m;
    if (!take(c, &m, sizeof m))
        return bad(r, "material %u: truncated", r->seen.materials);
    if (!memchr(m.name, '\0', sizeof m.name) || rl_material_validate(&m) != RL_OK ||
        !texture_ok(r, m.diffuse_texture) || !texture_ok(r, m.normal_texture) ||
        !(m.alpha_cutoff >= 0.0f && m.alpha_cutoff <= 1.0f) || !isfinite(m.normal_scale))
        return bad(r, "material %u: invalid", r->seen.materials);
    if (r->apply && rl_scene_add_material(r->scene, &m, NULL) != RL_OK)
        return false;
    r->seen.materials++;
    return true;
}

/* Checks what rl_scene_add_mesh guarantees of a stored mesh: indices in
 * range, positions finite, normals finite and non-zero, uvs finite,
 * materials that exist. The parent takes the arrays as they are (running
 * them through rl_scene_add_mesh again would renormalise the normals and
 * change their last bits). */
static bool read_mesh(reader *r, cursor *c)
{
    char name[MAX_TEXT];
    uint32_t nv, nt, id = r->seen.meshes;
    if (!take_text(c, name) || !take_u32(c, &nv) || !take_u32(c, &nt))
        return bad(r, "mesh %u: truncated", id);
    if (nt > RL_SCENE_MAX_TRIANGLES)
        return bad(r, "mesh %u: %u triangles", id, nt);
    uint64_t need = (uint64_t)nv * 32u + (uint64_t)nt * 16u;
    if (c->left != need)
        return bad(r, "mesh %u: %u vertices and %u triangles need %llu bytes, not %zu", id, nv,
                   nt, (unsigned long long)need, c->left);
    const uint8_t *pos = c->p, *nor = pos + (size_t)nv * 12, *uv = nor + (size_t)nv * 12;
    const uint8_t *idx = uv + (size_t)nv * 8, *mat = idx + (size_t)nt * 12;
    if (!finite_floats(pos, 3 * (size_t)nv) || !finite_floats(nor, 3 * (size_t)nv) ||
        !finite_floats(uv, 2 * (size_t)nv))
        return bad(r, "mesh %u: non-finite vertex data", id);
    for (uint32_t v = 0; v < nv; ++v) {
        rl_vec3 n;
        memcpy(&n, nor + (size_t)v * 12, sizeof n);
        if (!(rl_length2(n) > 0.0f))
            return bad(r, "mesh %u: normal %u is zero", id, v);
    }
    for (size_t k = 0; k < 3 * (size_t)nt; ++k) {
        uint32_t i;
        memcpy(&i, idx + 4 * k, 4);
        if (i >= nv)
            return bad(r, "mesh %u: index %u of %u vertices", id, i, nv);
    }
    for (uint32_t t = 0; t < nt; ++t) {
        uint32_t m;
        memcpy(&m, mat + 4 * (size_t)t, 4);
        if (!known(m, r->base.materials, r->seen.materials))
            return bad(r, "mesh %u: material %u does not exist", id, m);
    }
    if (r->apply) {
        rl_scene *s = r->scene;
        rl_mesh m = { 0 };
        m.num_vertices = nv;
        m.num_triangles = nt;
        m.name = rl_strdup(name[0] ? name : "mesh");
        m.positions = rl_alloc((size_t)nv * 12 + 1);
        m.normals = rl_alloc((size_t)nv * 12 + 1);
        m.uvs = rl_alloc((size_t)nv * 8 + 1);
        m.indices = rl_alloc((size_t)nt * 12 + 1);
        m.materials = rl_alloc((size_t)nt * 4 + 1);
        bool ok = m.name && m.positions && m.normals && m.uvs && m.indices && m.materials &&
                  rl_scene_reserve((void **)&s->meshes, &s->cap_meshes, s->num_meshes + 1,
                                   sizeof *s->meshes) == RL_OK;
        if (!ok) {
            free(m.name);
            free(m.positions);
            free(m.normals);
            free(m.uvs);
            free(m.indices);
            free(m.materials);
            return false;
        }
        memcpy(m.positions, pos, (size_t)nv * 12);
        memcpy(m.normals, nor, (size_t)nv * 12);
        memcpy(m.uvs, uv, (size_t)nv * 8);
        memcpy(m.indices, idx, (size_t)nt * 12);
        memcpy(m.materials, mat, (size_t)nt * 4);
        s->meshes[s->num_meshes++] = m;
    }
    c->left = 0;
    r->seen.meshes++;
    return true;
}

/* The first node hangs under the import's parent, every later one under a
 * node of the stream: an import adds one subtree and nothing else. */
static bool read_node(reader *r, cursor *c)
{
    char name[MAX_TEXT];
    uint32_t parent, mesh, material, id = r->seen.nodes;
    rl_mat4 local;
    if (!take_text(c, name) || !take_u32(c, &parent) || !take_u32(c, &mesh) ||
        !take_u32(c, &material) || !take(c, &local, sizeof local))
        return bad(r, "node %u: truncated", id);
    bool parent_ok = id == 0 ? parent == r->parent
                             : parent >= r->base.nodes && known(parent, r->base.nodes, id);
    if (!parent_ok)
        return bad(r, "node %u: parent %u", id, parent);
    if (mesh != RL_NONE && (mesh < r->base.meshes || !known(mesh, r->base.meshes, r->seen.meshes)))
        return bad(r, "node %u: mesh %u", id, mesh);
    if (material != RL_NONE)
        return bad(r, "node %u: a material override", id);
    if (rl_node_check_transform(&local, name) != RL_OK)
        return bad(r, "node %u: transform", id);
    if (r->apply) {
        uint32_t node;
        if (rl_scene_add_node(r->scene, parent, name, &local, &node) != RL_OK ||
            (mesh != RL_NONE && rl_scene_node_set_mesh(r->scene, node, mesh) != RL_OK))
            return false;
    }
    r->seen.nodes++;
    return true;
}

static bool read_camera(reader *r, cursor *c)
{
    char name[MAX_TEXT];
    rl_camera cam;
    if (!take_text(c, name) || !take(c, &cam, sizeof cam) || rl_camera_validate(&cam) != RL_OK)
        return bad(r, "camera %u: invalid", r->seen.cameras);
    if (r->apply && rl_scene_add_camera(r->scene, name, &cam) != RL_OK)
        return false;
    r->seen.cameras++;
    return true;
}

static bool read_light(reader *r, cursor *c)
{
    rl_light l;
    if (!take(c, &l, sizeof l) || rl_light_validate(&l) != RL_OK)
        return bad(r, "light %u: invalid", r->seen.lights);
    if (r->apply && rl_scene_add_light(r->scene, &l) != RL_OK)
        return false;
    r->seen.lights++;
    return true;
}

static bool read_drops(reader *r, cursor *c)
{
    uint64_t degenerate, nonfinite;
    if (!take(c, &degenerate, 8) || !take(c, &nonfinite, 8))
        return bad(r, "bad drops record");
    if (r->apply) {
        r->scene->dropped_degenerate += degenerate;
        r->scene->dropped_nonfinite += nonfinite;
    }
    return true;
}

static bool read_root(reader *r, cursor *c)
{
    if (r->has_root || !take_u32(c, &r->root) || r->root < r->base.nodes ||
        !known(r->root, r->base.nodes, r->seen.nodes))
        return bad(r, "bad root record");
    r->has_root = true;
    return true;
}

static bool read_record(reader *r, uint32_t tag, cursor *c)
{
    if (tag != TAG_BASE && !r->has_base)
        return bad(r, "no BASE record first");
    bool data = tag >= TAG_TEXTURE && tag <= TAG_ROOT;
    if (data && r->child_status != RL_OK)
        return bad(r, "data after an error record");
    r->has_data |= data;
    switch (tag) {
    case TAG_BASE: return read_base(r, c);
    case TAG_WARNING: return read_warning(r, c);
    case TAG_ERROR: return read_error(r, c);
    case TAG_TEXTURE: return read_texture(r, c);
    case TAG_MATERIAL: return read_material(r, c);
    case TAG_MESH: return read_mesh(r, c);
    case TAG_NODE: return read_node(r, c);
    case TAG_CAMERA: return read_camera(r, c);
    case TAG_LIGHT: return read_light(r, c);
    case TAG_DROPS: return read_drops(r, c);
    case TAG_ROOT: return read_root(r, c);
    default: return bad(r, "unknown record tag %u", tag);
    }
}

/* One pass over the stream; false when it is malformed (r->why) or, while
 * applying, when a setter failed (its error is recorded). */
static bool read_stream(reader *r, const uint8_t *bytes, size_t size)
{
    cursor c = { bytes, size };
    char magic[8];
    uint32_t version, zero;
    if (!take(&c, magic, 8) || memcmp(magic, STREAM_MAGIC, 8) != 0 || !take_u32(&c, &version) ||
        !take_u32(&c, &zero))
        return bad(r, "no stream header");
    if (version != STREAM_VERSION || zero != 0)
        return bad(r, "stream version %u, expected %u", version, STREAM_VERSION);
    while (c.left > 0) {
        uint32_t tag, pad;
        uint64_t length;
        if (!take_u32(&c, &tag) || !take_u32(&c, &pad) || !take(&c, &length, 8) || pad != 0)
            return bad(r, "record %u: truncated header", r->records);
        if (length > c.left)
            return bad(r, "record %u: %llu bytes announced, %zu left", r->records,
                       (unsigned long long)length, c.left);
        cursor payload = { c.p, (size_t)length };
        take(&c, NULL, (size_t)length);
        if (tag == TAG_END) {
            uint32_t count = 0;
            if (!take_u32(&payload, &count) || count != r->records || payload.left != 0)
                return bad(r, "END after %u records claims %u", r->records, count);
            if (c.left != 0)
                return bad(r, "%zu bytes after END", c.left);
            r->ended = true;
            return true;
        }
        if (!read_record(r, tag, &payload))
            return false;
        if (payload.left != 0)
            return bad(r, "record %u (tag %u): %zu bytes left over", r->records, tag,
                       payload.left);
        r->records++;
    }
    return bad(r, "no END record (the stream is cut short)");
}

rl_status rl_import_stream_apply(rl_scene *scene, const uint8_t *bytes, size_t size,
                                 const char *path, uint32_t parent, uint32_t memory_mib,
                                 uint32_t *root_node)
{
    /* Validators record their own message; a malformed stream is reported
     * as such, with theirs as the detail, unless an earlier error of the
     * caller's is pending (the first error is kept). */
    bool clean = rl_last_status() == RL_OK;
    reader check = { .scene = scene, .path = path, .parent = parent };
    if (!read_stream(&check, bytes, size) || (check.child_status == RL_OK && !check.has_root)) {
        char detail[512];
        snprintf(detail, sizeof detail, "%s", check.why[0] ? check.why : "no root node");
        if (clean && rl_last_status() != RL_OK) {
            snprintf(detail + strlen(detail), sizeof detail - strlen(detail), ": %s",
                     rl_last_error());
            rl_clear_error();
        }
        return rl_error(RL_ERR_PARSE, "%s: the importer's result is malformed (%s)", path, detail);
    }
    reader use = { .scene = scene, .path = path, .parent = parent, .apply = true };
    if (!read_stream(&use, bytes, size)) {
        rl_status st = rl_last_status();
        return rl_error(st != RL_OK ? st : RL_ERR_INTERNAL, "%s: applying the import failed",
                        path);
    }
    if (use.child_status == RL_ERR_OUT_OF_MEMORY && memory_mib > 0)
        return rl_error(RL_ERR_LIMIT, "%s: the importer exceeded its memory limit (%u MiB)", path,
                        memory_mib);
    if (use.child_status != RL_OK)
        return rl_error(use.child_status, "%s", use.child_message);
    *root_node = use.root;
    return RL_OK;
}
