/* meshbuf.c: growable triangle mesh with a sticky error, used by the
 * procedural generators and built-in scenes before handing geometry to
 * rl_scene_add_mesh(). */
#include "scene/generators.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

void rl_meshbuf_init(rl_meshbuf *b)
{
    memset(b, 0, sizeof *b);
    b->material = RL_NONE;
    b->status = RL_OK;
}

void rl_meshbuf_free(rl_meshbuf *b)
{
    free(b->positions);
    free(b->normals);
    free(b->uvs);
    free(b->indices);
    free(b->materials);
    rl_meshbuf_init(b);
}

/* Doubling growth so that appending one quad at a time stays linear. */
static uint32_t grown(uint32_t cap, uint64_t need)
{
    uint64_t c = cap ? cap : 64;
    while (c < need)
        c *= 2;
    return c > RL_SCENE_MAX_TRIANGLES * 3ull ? (uint32_t)(RL_SCENE_MAX_TRIANGLES * 3ull) : (uint32_t)c;
}

static bool fail(rl_meshbuf *b, rl_status s)
{
    if (b->status == RL_OK)
        b->status = s;
    return false;
}

bool rl_meshbuf_reserve(rl_meshbuf *b, uint64_t more_vertices, uint64_t more_triangles)
{
    if (b->status != RL_OK)
        return false;
    uint64_t nv = (uint64_t)b->num_vertices + more_vertices;
    uint64_t nt = (uint64_t)b->num_triangles + more_triangles;
    /* Vertices are bounded by 3 per triangle; both by the scene's cap. */
    if (nt > RL_SCENE_MAX_TRIANGLES || nv > RL_SCENE_MAX_TRIANGLES * 3ull)
        return fail(b, rl_error(RL_ERR_LIMIT, "mesh: %llu triangles exceed the limit of %u",
                                (unsigned long long)nt, RL_SCENE_MAX_TRIANGLES));
    if (nv > b->cap_vertices) {
        uint32_t cap = grown(b->cap_vertices, nv);
        rl_vec3 *p = rl_realloc_array(b->positions, cap, sizeof *p);
        if (p)
            b->positions = p;
        rl_vec3 *n = p ? rl_realloc_array(b->normals, cap, sizeof *n) : NULL;
        if (n)
            b->normals = n;
        rl_vec2 *uv = n ? rl_realloc_array(b->uvs, cap, sizeof *uv) : NULL;
        if (!uv)
            return fail(b, RL_ERR_OUT_OF_MEMORY);
        b->uvs = uv;
        b->cap_vertices = cap;
    }
    if (nt > b->cap_triangles) {
        uint32_t cap = grown(b->cap_triangles, nt);
        uint32_t *idx = rl_realloc_array(b->indices, (size_t)cap * 3, sizeof *idx);
        if (idx)
            b->indices = idx;
        uint32_t *mat = idx ? rl_realloc_array(b->materials, cap, sizeof *mat) : NULL;
        if (!mat)
            return fail(b, RL_ERR_OUT_OF_MEMORY);
        b->materials = mat;
        b->cap_triangles = cap;
    }
    return true;
}

uint32_t rl_meshbuf_vertex(rl_meshbuf *b, rl_vec3 p, rl_vec3 n, rl_vec2 uv)
{
    if (!rl_meshbuf_reserve(b, 1, 0))
        return 0;
    uint32_t i = b->num_vertices++;
    b->positions[i] = p;
    b->normals[i] = n;
    b->uvs[i] = uv;
    return i;
}

void rl_meshbuf_triangle(rl_meshbuf *b, uint32_t a, uint32_t c, uint32_t d)
{
    if (!rl_meshbuf_reserve(b, 0, 1))
        return;
    uint32_t t = b->num_triangles++;
    b->indices[3 * t + 0] = a;
    b->indices[3 * t + 1] = c;
    b->indices[3 * t + 2] = d;
    b->materials[t] = b->material;
}

void rl_meshbuf_quad(rl_meshbuf *b, rl_vec3 p0, rl_vec3 p1, rl_vec3 p2, rl_vec3 p3,
                     rl_vec2 uv_scale)
{
    if (!rl_meshbuf_reserve(b, 4, 2))
        return;
    rl_vec3 n = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p3, p0)));
    uint32_t v0 = rl_meshbuf_vertex(b, p0, n, rl_v2(0.0f, 0.0f));
    uint32_t v1 = rl_meshbuf_vertex(b, p1, n, rl_v2(uv_scale.x, 0.0f));
    uint32_t v2 = rl_meshbuf_vertex(b, p2, n, rl_v2(uv_scale.x, uv_scale.y));
    uint32_t v3 = rl_meshbuf_vertex(b, p3, n, rl_v2(0.0f, uv_scale.y));
    rl_meshbuf_triangle(b, v0, v1, v2);
    rl_meshbuf_triangle(b, v0, v2, v3);
}

void rl_meshbuf_box(rl_meshbuf *b, rl_vec3 lo, rl_vec3 hi)
{
    /* Corners indexed by bits (x, y, z): bit set = hi. */
    rl_vec3 c[8];
    for (int i = 0; i < 8; ++i)
        c[i] = rl_v3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
    rl_vec2 one = rl_v2(1.0f, 1.0f);
    rl_meshbuf_quad(b, c[1], c[3], c[7], c[5], one);  /* +x */
    rl_meshbuf_quad(b, c[0], c[4], c[6], c[2], one);  /* -x */
    rl_meshbuf_quad(b, c[2], c[6], c[7], c[3], one);  /* +y */
    rl_meshbuf_quad(b, c[0], c[1], c[5], c[4], one);  /* -y */
    rl_meshbuf_quad(b, c[4], c[5], c[7], c[6], one);  /* +z */
    rl_meshbuf_quad(b, c[0], c[2], c[3], c[1], one);  /* -z */
}

rl_status rl_meshbuf_add_to_scene(rl_scene *scene, const rl_meshbuf *b, const char *name,
                                  uint32_t *mesh_id)
{
    if (b->status != RL_OK)
        return b->status;
    bool uniform = true;
    for (uint32_t t = 1; t < b->num_triangles && uniform; ++t)
        uniform = b->materials[t] == b->materials[0];
    rl_mesh_desc d = {
        .name = name,
        .num_vertices = b->num_vertices,
        .positions = b->positions,
        .normals = b->normals,
        .uvs = b->uvs,
        .num_triangles = b->num_triangles,
        .indices = b->indices,
        .triangle_materials = uniform ? NULL : b->materials,
        .material = b->num_triangles ? b->materials[0] : b->material,
    };
    return rl_scene_add_mesh(scene, &d, mesh_id);
}
