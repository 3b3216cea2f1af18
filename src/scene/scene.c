/* scene.c: scene lifetime, names, textures, cameras, statistics and the
 * read-only view of a committed scene. The graph lives in scene_graph.c,
 * meshes in mesh.c, flattening in commit.c. */
#include "scene/scene_internal.h"
#include "core/error.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PATH_MAX_LEN 4096

rl_status rl_scene_reserve(void **array, uint32_t *cap, uint32_t need, size_t elem_size)
{
    if (need <= *cap)
        return RL_OK;
    if (need > (1u << 31))
        return rl_error(RL_ERR_LIMIT, "scene: more than 2^31 items of one kind");
    /* Doubling keeps appends amortised O(1) for meshes loaded triangle soup style. */
    uint64_t grown = *cap < 8 ? 8 : (uint64_t)*cap * 2;
    if (grown < need)
        grown = need;
    if (grown > (1u << 31))
        grown = 1u << 31;
    void *p = rl_realloc_array(*array, (size_t)grown, elem_size);
    if (!p)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "scene: out of memory growing an array");
    *array = p;
    *cap = (uint32_t)grown;
    return RL_OK;
}

rl_status rl_scene_check_mutable(const rl_scene *scene, const char *what)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "scene: NULL scene (cannot %s)", what);
    if (scene->committed)
        return rl_error(RL_ERR_INVALID_ARG, "scene \"%s\": committed scenes are immutable (cannot %s)",
                        scene->name, what);
    return RL_OK;
}

static _Atomic uint64_t next_uid = 1;

uint64_t rl_scene_uid(const rl_scene *scene) { return scene ? scene->uid : 0; }

rl_status rl_scene_create(rl_scene **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_create: out is NULL");
    rl_scene *s = rl_calloc(1, sizeof *s);
    if (!s)
        return RL_ERR_OUT_OF_MEMORY;
    s->uid = next_uid++;
    s->view_azimuth_deg = RL_CAMERA_FIT_AZIMUTH_DEG;
    s->view_elevation_deg = RL_CAMERA_FIT_ELEVATION_DEG;
    s->name = rl_strdup("scene");
    s->base_dir = rl_strdup("");
    uint32_t root;
    if (!s->name || !s->base_dir || rl_scene_add_node(s, RL_NONE, "root", NULL, &root) != RL_OK) {
        rl_scene_release(s);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_scene_create: out of memory");
    }
    *out = s;
    return RL_OK;
}

void rl_scene_release(rl_scene *scene)
{
    if (!scene)
        return;
    for (uint32_t i = 0; i < scene->num_nodes; ++i) {
        rl_node *n = &scene->nodes[i];
        free(n->name);
        for (uint32_t a = 0; a < n->num_attrs; ++a) {
            free(n->attrs[a].key);
            free(n->attrs[a].value);
        }
        free(n->attrs);
    }
    free(scene->nodes);
    for (uint32_t i = 0; i < scene->num_meshes; ++i) {
        rl_mesh *m = &scene->meshes[i];
        free(m->name);
        free(m->positions);
        free(m->normals);
        free(m->uvs);
        free(m->indices);
        free(m->materials);
    }
    free(scene->meshes);
    free(scene->materials);
    for (uint32_t i = 0; i < scene->num_textures; ++i) {
        rl_texture_release(scene->textures[i]);
        free(scene->texture_paths[i]);
    }
    free(scene->textures);
    free(scene->texture_paths);
    free(scene->lights);
    for (uint32_t i = 0; i < scene->num_cameras; ++i)
        free(scene->camera_names[i]);
    free(scene->cameras);
    free(scene->camera_names);
    rl_camera_path_release(scene->camera_path);
    rl_texture_release((rl_texture *)scene->environment.map);
    rl_scene_free_flat(scene);
    free(scene->name);
    free(scene->base_dir);
    free(scene);
}

static rl_status replace_string(char **slot, const char *value, const char *what)
{
    if (!value)
        return rl_error(RL_ERR_INVALID_ARG, "scene: %s is NULL", what);
    char *copy = rl_strdup(value);
    if (!copy)
        return RL_ERR_OUT_OF_MEMORY;
    free(*slot);
    *slot = copy;
    return RL_OK;
}

/* Name and base dir are metadata, not geometry, so they may change after commit. */
rl_status rl_scene_set_name(rl_scene *scene, const char *name)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_set_name: NULL scene");
    return replace_string(&scene->name, name, "name");
}

const char *rl_scene_name(const rl_scene *scene) { return scene ? scene->name : ""; }

rl_status rl_scene_set_base_dir(rl_scene *scene, const char *dir)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_set_base_dir: NULL scene");
    return replace_string(&scene->base_dir, dir, "base dir");
}

const char *rl_scene_base_dir(const rl_scene *scene) { return scene ? scene->base_dir : ""; }

/* Textures and their resolved paths share cap_textures; grow both arrays. */
static rl_status reserve_texture(rl_scene *s)
{
    uint32_t cap_tex = s->cap_textures, cap_paths = s->cap_textures;
    rl_status st = rl_scene_reserve((void **)&s->textures, &cap_tex, s->num_textures + 1,
                                    sizeof *s->textures);
    if (st == RL_OK)
        st = rl_scene_reserve((void **)&s->texture_paths, &cap_paths, s->num_textures + 1,
                              sizeof *s->texture_paths);
    s->cap_textures = cap_tex < cap_paths ? cap_tex : cap_paths;
    return st;
}

rl_status rl_scene_push_texture(rl_scene *scene, rl_texture *tex, const char *resolved, uint32_t *id)
{
    char *path = NULL;
    if (resolved && !(path = rl_strdup(resolved)))
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st = reserve_texture(scene);
    if (st != RL_OK) {
        free(path);
        return st;
    }
    scene->textures[scene->num_textures] = tex;
    scene->texture_paths[scene->num_textures] = path;
    if (id)
        *id = scene->num_textures;
    scene->num_textures++;
    return RL_OK;
}

rl_status rl_scene_add_texture(rl_scene *scene, rl_texture *tex, uint32_t *id)
{
    if (!scene || !tex)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_texture: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "add a texture");
    if (st != RL_OK)
        return st;
    return rl_scene_push_texture(scene, tex, NULL, id);
}

rl_status rl_scene_load_texture(rl_scene *scene, const char *path, uint32_t *id)
{
    if (!scene || !path || !path[0])
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_load_texture: NULL or empty path");
    rl_status st = rl_scene_check_mutable(scene, "load a texture");
    if (st != RL_OK)
        return st;
    char resolved[PATH_MAX_LEN];
    rl_path_join(scene->base_dir, path, resolved, sizeof resolved);
    for (uint32_t i = 0; i < scene->num_textures; ++i)
        if (scene->texture_paths[i] && strcmp(scene->texture_paths[i], resolved) == 0) {
            if (id)
                *id = i;
            return RL_OK;
        }
    rl_texture *tex = NULL;
    if ((st = rl_texture_load(resolved, &tex)) != RL_OK)
        return st;
    if ((st = rl_scene_push_texture(scene, tex, resolved, id)) != RL_OK)
        rl_texture_release(tex);
    return st;
}

static uint32_t find_camera(const rl_scene *scene, const char *name)
{
    for (uint32_t i = 0; i < scene->num_cameras; ++i)
        if (strcmp(scene->camera_names[i], name) == 0)
            return i;
    return RL_NONE;
}

rl_status rl_scene_add_camera(rl_scene *scene, const char *name, const rl_camera *cam)
{
    if (!scene || !cam)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_camera: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "add a camera");
    if (st != RL_OK)
        return st;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "camera%u", scene->num_cameras);
    if (!name || !name[0])
        name = fallback;
    if ((st = rl_camera_validate(cam)) != RL_OK)
        return st;
    /* Imported files often repeat a name ("Camera"); suffix rather than fail
     * so that every camera stays addressable by name. */
    char unique[256];
    snprintf(unique, sizeof unique, "%s", name);
    for (uint32_t k = 2; find_camera(scene, unique) != RL_NONE; ++k)
        snprintf(unique, sizeof unique, "%.200s.%u", name, k);
    if (strcmp(unique, name) != 0)
        rl_warn("scene \"%s\": camera \"%s\" exists already, added as \"%s\"", scene->name, name,
                unique);
    char *copy = rl_strdup(unique);
    if (!copy)
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t cap_cam = scene->cap_cameras, cap_names = scene->cap_cameras;
    st = rl_scene_reserve((void **)&scene->cameras, &cap_cam, scene->num_cameras + 1,
                          sizeof *scene->cameras);
    if (st == RL_OK)
        st = rl_scene_reserve((void **)&scene->camera_names, &cap_names, scene->num_cameras + 1,
                              sizeof *scene->camera_names);
    scene->cap_cameras = cap_cam < cap_names ? cap_cam : cap_names;
    if (st != RL_OK) {
        free(copy);
        return st;
    }
    scene->cameras[scene->num_cameras] = rl_camera_resolve(cam);
    scene->camera_names[scene->num_cameras] = copy;
    scene->num_cameras++;
    return RL_OK;
}

rl_status rl_scene_set_camera_path(rl_scene *scene, rl_camera_path *path)
{
    if (!scene || !path)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_set_camera_path: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "set a camera path");
    if (st != RL_OK)
        return st;
    rl_camera_path_release(scene->camera_path);
    scene->camera_path = path;
    return RL_OK;
}

bool rl_scene_is_committed(const rl_scene *scene) { return scene && scene->committed; }

const rl_scene_data *rl_scene_get_data(const rl_scene *scene)
{
    if (!scene || !scene->committed) {
        rl_error(RL_ERR_NOT_COMMITTED, "scene \"%s\": not committed", scene ? scene->name : "(null)");
        return NULL;
    }
    return &scene->data;
}

rl_status rl_scene_get_camera(const rl_scene *scene, const char *name, rl_camera *out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_get_camera: NULL argument");
    if (name) {
        uint32_t i = find_camera(scene, name);
        if (i != RL_NONE) {
            *out = scene->cameras[i];
            return RL_OK;
        }
        /* List what exists so that a typo on the command line is easy to fix. */
        char list[512] = "";
        size_t len = 0;
        for (uint32_t i = 0; i < scene->num_cameras && len < sizeof list; ++i) {
            int n = snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "",
                             scene->camera_names[i]);
            if (n < 0)
                break;
            len += (size_t)n;
        }
        return rl_error(RL_ERR_NOT_FOUND, "no camera \"%s\" (scene has: %s)", name,
                        scene->num_cameras ? list : "none");
    }
    if (scene->num_cameras > 0) {
        *out = scene->cameras[0];
        return RL_OK;
    }
    if (!scene->committed)
        return rl_error(RL_ERR_NOT_COMMITTED,
                        "scene \"%s\": has no camera, and framing its bounds needs a commit",
                        scene->name);
    return rl_scene_fit_camera(scene, RL_CAMERA_DEFAULT_WIDTH, RL_CAMERA_DEFAULT_HEIGHT, out);
}

rl_status rl_scene_set_default_view(rl_scene *scene, float azimuth_deg, float elevation_deg)
{
    if (!scene)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_set_default_view: NULL scene");
    rl_status st = rl_scene_check_mutable(scene, "rl_scene_set_default_view");
    if (st != RL_OK)
        return st;
    if (!isfinite(azimuth_deg) || !(elevation_deg >= -89.0f && elevation_deg <= 89.0f))
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_scene_set_default_view: azimuth %g, elevation %g (finite, elevation in -89..89)",
                        (double)azimuth_deg, (double)elevation_deg);
    scene->view_azimuth_deg = azimuth_deg;
    scene->view_elevation_deg = elevation_deg;
    return RL_OK;
}

rl_status rl_scene_fit_camera(const rl_scene *scene, int width, int height, rl_camera *out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_fit_camera: NULL argument");
    if (!scene->committed)
        return rl_error(RL_ERR_NOT_COMMITTED, "scene \"%s\": framing its geometry needs a commit",
                        scene->name);
    *out = rl_camera_fit_points(scene->data.positions, scene->data.num_vertices,
                                scene->view_azimuth_deg, scene->view_elevation_deg, width, height);
    return RL_OK;
}

void rl_scene_get_stats(const rl_scene *scene, rl_scene_stats *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    out->bounds = rl_aabb_empty();
    if (!scene)
        return;
    out->nodes = scene->num_nodes;
    out->meshes = scene->num_meshes;
    out->materials = scene->num_materials;
    out->textures = scene->num_textures;
    out->lights = scene->num_lights;
    out->cameras = scene->num_cameras;
    out->dropped_degenerate = scene->dropped_degenerate;
    out->dropped_nonfinite = scene->dropped_nonfinite;
    size_t bytes = sizeof *scene + (size_t)scene->cap_nodes * sizeof(rl_node) +
                   (size_t)scene->cap_meshes * sizeof(rl_mesh) +
                   (size_t)scene->cap_materials * sizeof(rl_material) +
                   (size_t)scene->cap_lights * sizeof(rl_light) +
                   (size_t)scene->cap_cameras * (sizeof(rl_camera) + sizeof(char *));
    for (uint32_t i = 0; i < scene->num_nodes; ++i)
        out->objects += scene->nodes[i].mesh != RL_NONE;
    for (uint32_t i = 0; i < scene->num_meshes; ++i) {
        const rl_mesh *m = &scene->meshes[i];
        out->mesh_triangles += m->num_triangles;
        bytes += (size_t)m->num_vertices * (2 * sizeof(rl_vec3) + sizeof(rl_vec2)) +
                 (size_t)m->num_triangles * 4 * sizeof(uint32_t);
    }
    for (uint32_t i = 0; i < scene->num_textures; ++i) {
        const rl_texture *t = scene->textures[i];
        bytes += (size_t)t->width * (size_t)t->height * sizeof(rl_vec4);
    }
    if (scene->committed) {
        const rl_scene_data *d = &scene->data;
        out->triangles = d->num_triangles;
        out->vertices = d->num_vertices;
        out->objects = d->num_objects;
        out->emissive_triangles = scene->emissive_triangles;
        out->bounds = d->bounds;
        bytes += (size_t)d->num_vertices * (2 * sizeof(rl_vec3) + sizeof(rl_vec2)) +
                 (size_t)d->num_triangles * 5 * sizeof(uint32_t) +
                 (size_t)d->num_objects * sizeof(rl_object);
    }
    out->memory_bytes = bytes;
}
