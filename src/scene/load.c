/* load.c: rl_scene_load, the one entry point that turns a "source" string
 * into a committed scene: an existing ".json" file (load_json.c), any other
 * existing file through Assimp (load_assimp.c), or a built-in scene name.
 *
 * A bare mesh file brings geometry but rarely light, so when it has no
 * lights we add a key light near the default camera (rl_camera_frame_bounds,
 * the view rl_scene_get_camera falls back to) and a weaker directional fill
 * from above so that faces turned away from the key light are not black. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "scene/scene_internal.h"

#define PATH_MAX_LEN 4096

static bool is_regular_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    /* fopen succeeds on directories on Linux; reading from one fails. */
    char c;
    bool ok = fread(&c, 1, 1, f) == 1 || !ferror(f);
    fclose(f);
    return ok;
}

/* World-space bounds of the uncommitted scene: node transforms composed down
 * from the root (a parent's id is always smaller than its child's). */
static rl_aabb scene_bounds(const rl_scene *s)
{
    rl_aabb b = rl_aabb_empty();
    rl_mat4 *world = rl_calloc(s->num_nodes ? s->num_nodes : 1, sizeof *world);
    if (!world)
        return b;
    for (uint32_t n = 0; n < s->num_nodes; ++n) {
        const rl_node *node = &s->nodes[n];
        world[n] = node->parent == RL_NONE || node->parent >= n
                       ? node->local
                       : rl_mat4_mul(&world[node->parent], &node->local);
        if (node->mesh == RL_NONE || node->mesh >= s->num_meshes)
            continue;
        const rl_mesh *m = &s->meshes[node->mesh];
        for (uint32_t v = 0; v < m->num_vertices; ++v) {
            rl_vec3 p = rl_mat4_mul_point(&world[n], m->positions[v]);
            if (rl_vfinite(p))
                b = rl_aabb_grow(b, p);
        }
    }
    free(world);
    return b;
}

static rl_status add_default_lights(rl_scene *scene)
{
    rl_aabb bounds = scene_bounds(scene);
    if (rl_aabb_is_empty(bounds))
        return RL_OK;   /* commit reports the empty scene */
    rl_camera cam = rl_camera_frame_bounds(bounds, RL_CAMERA_DEFAULT_WIDTH,
                                           RL_CAMERA_DEFAULT_HEIGHT);
    rl_vec3 extent = rl_aabb_extent(bounds);
    float radius = 0.5f * rl_length(extent);
    if (!(radius > 0.0f))
        radius = 1.0f;
    /* Key light: above the eye, offset by a fraction of the scene size so
     * that shadows fall visibly behind objects. Its intensity is the squared
     * distance to the centre, so the 1/d^2 falloff gives irradiance ~1 there. */
    rl_light key = { 0 };
    key.type = RL_LIGHT_POINT;
    key.color = rl_v3s(1.0f);
    key.position = rl_add(cam.eye, rl_v3(0.25f * radius, 0.5f * radius, 0.0f));
    float d = rl_length(rl_sub(key.position, rl_aabb_center(bounds)));
    key.intensity = d > 0.0f ? 0.8f * d * d : 1.0f;
    rl_status st = rl_scene_add_light(scene, &key);
    if (st != RL_OK)
        return st;
    rl_light fill = { 0 };
    fill.type = RL_LIGHT_DIRECTIONAL;
    fill.color = rl_v3s(1.0f);
    fill.intensity = 0.25f;
    fill.direction = rl_normalize(rl_v3(-0.3f, -1.0f, -0.5f));
    return rl_scene_add_light(scene, &fill);
}

/* "models/bunny.obj" -> "bunny". */
static void file_stem(const char *path, char *out, size_t size)
{
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    snprintf(out, size, "%s", base);
    char *dot = strrchr(out, '.');
    if (dot && dot != out)
        *dot = '\0';
}

static rl_status load_mesh_file(const char *path, rl_scene **out)
{
    rl_scene *scene = NULL;
    rl_status st = rl_scene_create(&scene);
    if (st != RL_OK)
        return st;
    char stem[256], dir[PATH_MAX_LEN];
    file_stem(path, stem, sizeof stem);
    rl_path_dirname(path, dir, sizeof dir);
    st = rl_scene_set_name(scene, stem);
    if (st == RL_OK)
        st = rl_scene_set_base_dir(scene, dir);
    uint32_t root = RL_NONE;
    if (st == RL_OK)
        st = rl_scene_import(scene, path, RL_NODE_ROOT, &root);
    if (st == RL_OK && scene->num_lights == 0)
        st = add_default_lights(scene);
    if (st == RL_OK)
        st = rl_scene_commit(scene);
    if (st != RL_OK) {
        rl_scene_release(scene);
        return st;
    }
    *out = scene;
    return RL_OK;
}

static bool is_builtin(const char *name)
{
    size_t count = 0;
    const rl_builtin_info *infos = rl_builtin_scenes(&count);
    for (size_t i = 0; i < count; ++i)
        if (strcmp(infos[i].name, name) == 0)
            return true;
    return false;
}

static rl_status unknown_source(const char *source)
{
    char names[512] = "";
    size_t count = 0, len = 0;
    const rl_builtin_info *infos = rl_builtin_scenes(&count);
    for (size_t i = 0; i < count && len < sizeof names; ++i)
        len += (size_t)snprintf(names + len, sizeof names - len, "%s%s", i ? ", " : "",
                                infos[i].name);
    return rl_error(RL_ERR_IO, "no such file or built-in scene \"%s\" (built-ins: %s)", source,
                    names);
}

RL_API rl_status rl_scene_load(const char *source, const char *params, rl_scene **out)
{
    if (!source || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_load: NULL argument");
    if (source[0] == '\0')
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_load: empty scene name");
    if (is_regular_file(source)) {
        if (params && params[0] != '\0')
            return rl_error(RL_ERR_INVALID_ARG,
                            "%s: scene parameters (\"%s\") apply only to built-in scenes",
                            source, params);
        if (rl_path_has_ext(source, ".json"))
            return rl_scene_load_json(source, out);
        return load_mesh_file(source, out);
    }
    if (is_builtin(source))
        return rl_scene_create_builtin(source, params, out);
    return unknown_source(source);
}
