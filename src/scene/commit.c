/* commit.c: flattening the scene graph into world-space triangle arrays.
 *
 * World transforms and inherited material overrides are computed in node id
 * order (a parent always has a smaller id than its children). Objects are the
 * mesh-carrying nodes in depth-first order, children in insertion order, so
 * object and triangle IDs depend only on the scene description. Vertices and
 * triangles are then transformed in parallel over fixed-size chunks of the
 * global arrays, so that one huge mesh parallelises as well as many small ones.
 * Mirroring transforms (negative determinant) swap two indices per triangle
 * so that the geometric normal still agrees with the shading normal. */
#include "scene/scene_internal.h"
#include "core/error.h"

#include <stdlib.h>
#include <string.h>

#define CHUNK 16384

typedef struct object_setup {
    rl_mat4 normal_matrix;     /* inverse transpose of the world matrix */
    uint32_t material;         /* inherited override or RL_NONE */
    bool flip;                 /* negative determinant */
} object_setup;

static float det3(const rl_mat4 *m)
{
    const float (*a)[4] = m->m;
    return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
}

/* Object whose [first, first + count) range holds element e; ranges ascend. */
static uint32_t find_object(const rl_object *objs, uint32_t n, uint32_t e, bool by_vertex)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        uint32_t first = by_vertex ? objs[mid].first_vertex : objs[mid].first_triangle;
        if (first <= e)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* Depth-first order of mesh-carrying nodes, iterative so that deep graphs
 * cannot overflow the stack. Returns the number written to order. */
static uint32_t dfs_mesh_nodes(const rl_scene *s, uint32_t *stack, uint32_t *order)
{
    uint32_t top = 0, count = 0;
    stack[top++] = RL_NODE_ROOT;
    while (top > 0) {
        uint32_t id = stack[--top];
        const rl_node *n = &s->nodes[id];
        if (n->mesh != RL_NONE)
            order[count++] = id;
        /* Push the next sibling first so that the subtree of id comes before it. */
        if (id != RL_NODE_ROOT && n->next_sibling != RL_NONE)
            stack[top++] = n->next_sibling;
        if (n->first_child != RL_NONE)
            stack[top++] = n->first_child;
    }
    return count;
}

static void flatten_vertices(rl_scene *s, const object_setup *setup)
{
    rl_scene_data *d = &s->data;
    int64_t chunks = ((int64_t)d->num_vertices + CHUNK - 1) / CHUNK;
    #pragma omp parallel for schedule(dynamic, 1)
    for (int64_t c = 0; c < chunks; ++c) {
        uint32_t begin = (uint32_t)(c * CHUNK);
        uint32_t end = begin + CHUNK < d->num_vertices ? begin + CHUNK : d->num_vertices;
        uint32_t o = find_object(s->flat_objects, d->num_objects, begin, true);
        for (uint32_t v = begin; v < end; ++v) {
            while (v >= s->flat_objects[o].first_vertex + s->flat_objects[o].num_vertices)
                ++o;
            const rl_object *obj = &s->flat_objects[o];
            const rl_mesh *m = &s->meshes[obj->mesh];
            uint32_t local = v - obj->first_vertex;
            s->flat_positions[v] = rl_mat4_mul_point(&obj->world, m->positions[local]);
            rl_vec3 n = rl_mat4_mul_normal(&setup[o].normal_matrix, m->normals[local]);
            s->flat_normals[v] = rl_vfinite(n) && rl_length2(n) > 0.0f ? n : m->normals[local];
            s->flat_uvs[v] = m->uvs[local];
        }
    }
}

static void flatten_triangles(rl_scene *s, const object_setup *setup)
{
    rl_scene_data *d = &s->data;
    int64_t chunks = ((int64_t)d->num_triangles + CHUNK - 1) / CHUNK;
    #pragma omp parallel for schedule(dynamic, 1)
    for (int64_t c = 0; c < chunks; ++c) {
        uint32_t begin = (uint32_t)(c * CHUNK);
        uint32_t end = begin + CHUNK < d->num_triangles ? begin + CHUNK : d->num_triangles;
        uint32_t o = find_object(s->flat_objects, d->num_objects, begin, false);
        for (uint32_t t = begin; t < end; ++t) {
            while (t >= s->flat_objects[o].first_triangle + s->flat_objects[o].num_triangles)
                ++o;
            const rl_object *obj = &s->flat_objects[o];
            const rl_mesh *m = &s->meshes[obj->mesh];
            uint32_t local = t - obj->first_triangle;
            const uint32_t *src = m->indices + 3 * (size_t)local;
            uint32_t *dst = s->flat_indices + 3 * (size_t)t;
            dst[0] = obj->first_vertex + src[0];
            dst[1] = obj->first_vertex + (setup[o].flip ? src[2] : src[1]);
            dst[2] = obj->first_vertex + (setup[o].flip ? src[1] : src[2]);
            s->flat_tri_object[t] = o;
            s->flat_tri_material[t] = setup[o].material != RL_NONE ? setup[o].material
                                                                    : m->materials[local];
        }
    }
}

/* Builds the object table: world matrices, ranges, per-object setup. */
static rl_status build_objects(rl_scene *s, object_setup **setup_out, uint64_t *tris, uint64_t *verts)
{
    uint32_t nn = s->num_nodes;
    rl_mat4 *world = rl_alloc((size_t)nn * sizeof *world);
    uint32_t *material = rl_alloc((size_t)nn * sizeof *material);
    uint32_t *stack = rl_alloc((size_t)nn * sizeof *stack);
    uint32_t *order = rl_alloc((size_t)nn * sizeof *order);
    rl_status st = RL_ERR_OUT_OF_MEMORY;
    if (!world || !material || !stack || !order)
        goto done;
    for (uint32_t i = 0; i < nn; ++i) {
        const rl_node *n = &s->nodes[i];
        world[i] = n->parent == RL_NONE ? n->local : rl_mat4_mul(&world[n->parent], &n->local);
        material[i] = n->material != RL_NONE || n->parent == RL_NONE ? n->material
                                                                    : material[n->parent];
    }
    uint32_t count = dfs_mesh_nodes(s, stack, order);
    s->flat_objects = rl_calloc((size_t)count + 1, sizeof *s->flat_objects);
    object_setup *setup = rl_calloc((size_t)count + 1, sizeof *setup);
    if (!s->flat_objects || !setup) {
        free(setup);
        goto done;
    }
    uint64_t t_sum = 0, v_sum = 0;
    for (uint32_t o = 0; o < count; ++o) {
        const rl_node *n = &s->nodes[order[o]];
        const rl_mesh *m = &s->meshes[n->mesh];
        rl_object *obj = &s->flat_objects[o];
        obj->name = n->name;
        obj->node = order[o];
        obj->mesh = n->mesh;
        obj->first_triangle = (uint32_t)(t_sum < UINT32_MAX ? t_sum : UINT32_MAX);
        obj->num_triangles = m->num_triangles;
        obj->first_vertex = (uint32_t)(v_sum < UINT32_MAX ? v_sum : UINT32_MAX);
        obj->num_vertices = m->num_vertices;
        obj->world = world[order[o]];
        obj->bounds = rl_aabb_empty();
        t_sum += m->num_triangles;
        v_sum += m->num_vertices;
        rl_mat4 inv;
        rl_mat4_invert(&obj->world, &inv);
        setup[o].normal_matrix = rl_mat4_transpose(&inv);
        setup[o].material = material[order[o]];
        setup[o].flip = det3(&obj->world) < 0.0f;
    }
    s->data.num_objects = count;
    *setup_out = setup;
    *tris = t_sum;
    *verts = v_sum;
    st = RL_OK;
done:
    free(world);
    free(material);
    free(stack);
    free(order);
    return st;
}

static void compute_bounds(rl_scene *s)
{
    rl_scene_data *d = &s->data;
    int64_t n = d->num_objects;
    #pragma omp parallel for schedule(dynamic, 1)
    for (int64_t o = 0; o < n; ++o) {
        rl_object *obj = &s->flat_objects[o];
        rl_aabb b = rl_aabb_empty();
        for (uint32_t v = 0; v < obj->num_vertices; ++v)
            b = rl_aabb_grow(b, s->flat_positions[obj->first_vertex + v]);
        obj->bounds = b;
    }
    d->bounds = rl_aabb_empty();
    for (uint32_t o = 0; o < d->num_objects; ++o)
        d->bounds = rl_aabb_union(d->bounds, s->flat_objects[o].bounds);
    uint64_t emissive = 0;
    int64_t nt = d->num_triangles;
    #pragma omp parallel for reduction(+ : emissive)
    for (int64_t t = 0; t < nt; ++t) {
        rl_vec3 e = s->materials[s->flat_tri_material[t]].emission;
        emissive += e.x > 0.0f || e.y > 0.0f || e.z > 0.0f;
    }
    s->emissive_triangles = emissive;
}

void rl_scene_free_flat(rl_scene *s)
{
    free(s->flat_positions);
    free(s->flat_normals);
    free(s->flat_uvs);
    free(s->flat_indices);
    free(s->flat_tri_object);
    free(s->flat_tri_material);
    free(s->flat_objects);
    s->flat_positions = s->flat_normals = NULL;
    s->flat_uvs = NULL;
    s->flat_indices = s->flat_tri_object = s->flat_tri_material = NULL;
    s->flat_objects = NULL;
    memset(&s->data, 0, sizeof s->data);
}

rl_status rl_scene_commit(rl_scene *scene)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_commit: NULL scene");
    if (scene->committed)
        return RL_OK;
    object_setup *setup = NULL;
    uint64_t tris = 0, verts = 0;
    rl_status st = build_objects(scene, &setup, &tris, &verts);
    if (st != RL_OK) {
        rl_scene_free_flat(scene);
        return rl_error(st, "scene \"%s\": out of memory flattening the graph", scene->name);
    }
    if (tris == 0)
        st = rl_error(RL_ERR_EMPTY_SCENE, "scene \"%s\" has no triangles", scene->name);
    else if (tris > RL_SCENE_MAX_TRIANGLES || verts >= UINT32_MAX)
        st = rl_error(RL_ERR_LIMIT,
                      "scene \"%s\": %llu triangles / %llu vertices after instancing exceed the limit of %u",
                      scene->name, (unsigned long long)tris, (unsigned long long)verts,
                      RL_SCENE_MAX_TRIANGLES);
    if (st != RL_OK) {
        free(setup);
        rl_scene_free_flat(scene);
        return st;
    }
    rl_scene_data *d = &scene->data;
    d->num_vertices = (uint32_t)verts;
    d->num_triangles = (uint32_t)tris;
    scene->flat_positions = rl_alloc(verts * sizeof(rl_vec3));
    scene->flat_normals = rl_alloc(verts * sizeof(rl_vec3));
    scene->flat_uvs = rl_alloc(verts * sizeof(rl_vec2));
    scene->flat_indices = rl_alloc(tris * 3 * sizeof(uint32_t));
    scene->flat_tri_object = rl_alloc(tris * sizeof(uint32_t));
    scene->flat_tri_material = rl_alloc(tris * sizeof(uint32_t));
    if (!scene->flat_positions || !scene->flat_normals || !scene->flat_uvs ||
        !scene->flat_indices || !scene->flat_tri_object || !scene->flat_tri_material) {
        free(setup);
        rl_scene_free_flat(scene);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "scene \"%s\": out of memory for %llu triangles",
                        scene->name, (unsigned long long)tris);
    }

    flatten_vertices(scene, setup);
    flatten_triangles(scene, setup);
    free(setup);
    compute_bounds(scene);

    d->positions = scene->flat_positions;
    d->normals = scene->flat_normals;
    d->uvs = scene->flat_uvs;
    d->indices = scene->flat_indices;
    d->triangle_object = scene->flat_tri_object;
    d->triangle_material = scene->flat_tri_material;
    d->objects = scene->flat_objects;
    d->num_materials = scene->num_materials;
    d->materials = scene->materials;
    d->num_textures = scene->num_textures;
    d->textures = scene->textures;
    d->num_lights = scene->num_lights;
    d->lights = scene->lights;
    d->num_cameras = scene->num_cameras;
    d->cameras = scene->cameras;
    d->camera_names = (const char *const *)scene->camera_names;
    d->camera_path = scene->camera_path;
    d->environment = scene->has_environment ? &scene->environment : NULL;
    scene->committed = true;
    return RL_OK;
}
