/* load.c: rl_scene_load, the one entry point that turns a "source" string
 * into a committed scene: an existing ".json" file (load_json.c), any other
 * existing file through Assimp (load_assimp.c), or a built-in scene name.
 *
 * A bare mesh file brings geometry but rarely light, so when it has no
 * lights we add a key light near the default view (its first camera, or the
 * tight orbit framing rl_scene_get_camera falls back to) and a weaker
 * directional fill from above so that faces turned away from the key light
 * are not black. Its parameters (model_options: file cameras and lights on
 * or off, a headlight, the framing orbit) come as "file.obj:key=value". */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/options.h"
#include "core/params.h"
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

/* The options of a model file ("model.obj:lights=add,headlight=true"),
 * printed by `rl scenes`. */
static const char *const camera_choices[] = { "file", "off", NULL };
static const char *const light_choices[] = { "file", "off", "add", NULL };
static const char *const material_choices[] = { "phong", "ggx", NULL };
static const rl_option_info model_options[] = {
    { "cameras", RL_OPT_ENUM, "file",
      "file: the file's cameras, the first one the default view; off: none (the model is framed "
      "from the orbit below)", 0, 0, camera_choices },
    { "lights", RL_OPT_ENUM, "file",
      "file: the file's lights, or the default key and fill lights when it has none; off: the "
      "default lights only; add: both", 0, 0, light_choices },
    { "headlight", RL_OPT_BOOL, "false",
      "a point light at the default view's eye (placed once, it does not follow --camera or "
      "--eye)", 0, 0, NULL },
    { "azimuth", RL_OPT_FLOAT, "25", "orbit of the framing camera: degrees about +y from +z",
      -360, 360, NULL },
    { "elevation", RL_OPT_FLOAT, "20", "orbit of the framing camera: degrees above the xz plane",
      -89, 89, NULL },
    { "materials", RL_OPT_ENUM, "phong",
      "glTF metallic-roughness materials: phong (mapped onto the Phong model, all renderers) or ggx "
      "(pt's microfacet BRDF with the file's values, issue 37)", 0, 0, material_choices },
};
#define NUM_MODEL_OPTIONS (sizeof model_options / sizeof model_options[0])

const rl_option_info *rl_model_options(size_t *count)
{
    if (count)
        *count = NUM_MODEL_OPTIONS;
    return model_options;
}

/* World-space vertex positions of the uncommitted scene, node transforms
 * composed down from the root (a parent's id is always smaller than its
 * child's): what the framing camera will see (rl_scene_fit_camera fits the
 * committed data alike). NULL when out of memory. */
static rl_vec3 *scene_points(const rl_scene *s, size_t *count)
{
    size_t n = 0;
    for (uint32_t i = 0; i < s->num_nodes; ++i)
        if (s->nodes[i].mesh != RL_NONE && s->nodes[i].mesh < s->num_meshes)
            n += s->meshes[s->nodes[i].mesh].num_vertices;
    rl_vec3 *points = rl_calloc(n ? n : 1, sizeof *points);
    rl_mat4 *world = rl_calloc(s->num_nodes ? s->num_nodes : 1, sizeof *world);
    if (!points || !world) {
        free(points);
        free(world);
        return NULL;
    }
    size_t k = 0;
    for (uint32_t i = 0; i < s->num_nodes; ++i) {
        const rl_node *node = &s->nodes[i];
        world[i] = node->parent == RL_NONE || node->parent >= i
                       ? node->local
                       : rl_mat4_mul(&world[node->parent], &node->local);
        if (node->mesh == RL_NONE || node->mesh >= s->num_meshes)
            continue;
        const rl_mesh *m = &s->meshes[node->mesh];
        for (uint32_t v = 0; v < m->num_vertices; ++v)
            points[k++] = rl_mat4_mul_point(&world[i], m->positions[v]);
    }
    free(world);
    *count = k;
    return points;
}

/* Where the lights of a model file go: its bounds and the view a render
 * gets by default (the first camera, else the fit), from one pass over the
 * vertices. An empty bounds means no geometry: nothing is added, and
 * commit reports the empty scene. */
typedef struct model_view {
    rl_aabb bounds;
    rl_camera cam;
} model_view;

static rl_status view_of(const rl_scene *scene, model_view *mv)
{
    size_t n = 0;
    rl_vec3 *points = scene_points(scene, &n);
    if (!points)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "scene \"%s\": out of memory", scene->name);
    mv->bounds = rl_aabb_empty();
    for (size_t i = 0; i < n; ++i)
        if (rl_vfinite(points[i]))
            mv->bounds = rl_aabb_grow(mv->bounds, points[i]);
    mv->cam = scene->num_cameras > 0
                  ? rl_camera_resolve(&scene->cameras[0])
                  : rl_camera_fit_points(points, n, scene->view_azimuth_deg, scene->view_elevation_deg,
                                         RL_CAMERA_DEFAULT_WIDTH, RL_CAMERA_DEFAULT_HEIGHT);
    free(points);
    return RL_OK;
}

/* A point light at the default view's eye, of intensity d^2 to the
 * model's centre (irradiance ~1 there), as viewers' headlights. */
static rl_status add_headlight(rl_scene *scene, const model_view *mv)
{
    if (rl_aabb_is_empty(mv->bounds))
        return RL_OK;
    rl_light l = { 0 };
    l.type = RL_LIGHT_POINT;
    l.color = rl_v3s(1.0f);
    l.position = mv->cam.eye;
    float d = rl_length(rl_sub(mv->cam.eye, rl_aabb_center(mv->bounds)));
    l.intensity = d > 0.0f && isfinite(d) ? d * d : 1.0f;
    return rl_scene_add_light(scene, &l);
}

static rl_status add_default_lights(rl_scene *scene, const model_view *mv)
{
    if (rl_aabb_is_empty(mv->bounds))
        return RL_OK;
    rl_vec3 extent = rl_aabb_extent(mv->bounds);
    float radius = 0.5f * rl_length(extent);
    if (!(radius > 0.0f))
        radius = 1.0f;
    /* Key light: above the eye, offset by a fraction of the scene size so
     * that shadows fall visibly behind objects. Its intensity is the squared
     * distance to the centre, so the 1/d^2 falloff gives irradiance ~1 there. */
    rl_light key = { 0 };
    key.type = RL_LIGHT_POINT;
    key.color = rl_v3s(1.0f);
    key.position = rl_add(mv->cam.eye, rl_v3(0.25f * radius, 0.5f * radius, 0.0f));
    float d = rl_length(rl_sub(key.position, rl_aabb_center(mv->bounds)));
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

/* A model's default lights, view and bounds come from its coordinates: for
 * a model whose coordinates reach the float limit, the error ("point
 * light: position is not finite") must name the file the user gave, not
 * a light they never wrote. */
static rl_status name_the_file(const char *path, rl_status st)
{
    if (strstr(rl_last_error(), path))
        return st;
    char msg[768];
    snprintf(msg, sizeof msg, "%s", rl_last_error());
    rl_clear_error();
    /* The file's fault, as rl_jscene_located says for JSON scenes. */
    return rl_error(st == RL_ERR_INVALID_ARG ? RL_ERR_PARSE : st, "%s: %s (are its coordinates within float range?)",
                    path, msg);
}

static rl_status load_mesh_file(const char *path, const char *params, rl_scene **out)
{
    /* Every key=value checked before the file is read. */
    rl_params list;
    rl_status st = rl_params_parse(params, &list);
    if (st != RL_OK)
        return st;
    rl_option_store opts;
    st = rl_option_store_init(&opts, model_options, NUM_MODEL_OPTIONS, NULL);
    for (uint32_t i = 0; st == RL_OK && i < list.count; ++i)
        st = rl_option_store_set(&opts, list.items[i].key, list.items[i].value, path, NULL);
    rl_params_free(&list);
    if (st != RL_OK) {
        rl_option_store_free(&opts);
        return st;
    }
    int lights = rl_option_store_enum(&opts, "lights");   /* 0 file, 1 off, 2 add */
    rl_scene_import_desc desc = {
        .no_cameras = rl_option_store_enum(&opts, "cameras") == 1,
        .no_lights = lights == 1,
        .ggx_materials = rl_option_store_enum(&opts, "materials") == 1,
    };
    bool headlight = rl_option_store_bool(&opts, "headlight");
    float azimuth = (float)rl_option_store_float(&opts, "azimuth");
    float elevation = (float)rl_option_store_float(&opts, "elevation");
    rl_option_store_free(&opts);

    rl_scene *scene = NULL;
    st = rl_scene_create(&scene);
    if (st != RL_OK)
        return st;
    st = rl_scene_set_default_view(scene, azimuth, elevation);
    char stem[256], dir[PATH_MAX_LEN];
    file_stem(path, stem, sizeof stem);
    rl_path_dirname(path, dir, sizeof dir);
    if (st == RL_OK)
        st = rl_scene_set_name(scene, stem);
    if (st == RL_OK)
        st = rl_scene_set_base_dir(scene, dir);
    uint32_t root = RL_NONE;
    if (st == RL_OK)
        st = rl_scene_import_with(scene, path, RL_NODE_ROOT, &desc, &root);
    bool rig = scene->num_lights == 0 || lights == 2;
    model_view mv;
    memset(&mv, 0, sizeof mv);   /* only read after view_of() succeeds */
    if (st == RL_OK && (rig || headlight))
        st = view_of(scene, &mv);
    if (st == RL_OK && rig)
        st = add_default_lights(scene, &mv);
    if (st == RL_OK && headlight)
        st = add_headlight(scene, &mv);
    if (st == RL_OK)
        st = rl_scene_commit(scene);
    if (st != RL_OK) {
        rl_scene_release(scene);
        return root != RL_NONE && st != RL_ERR_OUT_OF_MEMORY ? name_the_file(path, st) : st;
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
        if (rl_path_has_ext(source, ".json")) {
            if (params && params[0] != '\0')
                return rl_error(RL_ERR_INVALID_ARG,
                                "%s: a JSON scene takes no parameters (\"%s\"); built-in scenes "
                                "and model files do", source, params);
            return rl_scene_load_json(source, out);
        }
        return load_mesh_file(source, params, out);
    }
    if (is_builtin(source))
        return rl_scene_create_builtin(source, params, out);
    return unknown_source(source);
}
