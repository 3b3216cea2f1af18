/* load_json.c: the JSON scene format (docs/scene-format.md).
 *
 * A scene file names materials, lights, cameras, a camera path and a tree of
 * objects (mesh files imported with Assimp, procedural generators, or plain
 * groups), optionally on top of a built-in scene ("base"). The loader is
 * strict in the way pbrt-v4 is: unknown keys, wrong types, values out of
 * range and unknown names are errors that point at file:line:col and say
 * what was expected. Asset paths are relative to the scene file's folder.
 *
 * Errors in the document are RL_ERR_PARSE; problems with referenced assets
 * keep their own code (RL_ERR_IO for a missing mesh or texture file), with
 * the position of the key that referenced them. A scene without geometry is
 * RL_ERR_EMPTY_SCENE. *out is only written on success.
 *
 * This file holds the sections (materials, lights, cameras, objects) and
 * the entry point; typed reads are in load_json_read.c, transforms in
 * load_json_transform.c, "base" scenes in load_json_base.c. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "scene/load_json_internal.h"

#define PATH_MAX_LEN 4096
#define MAX_OBJECT_DEPTH 128

/* ---- materials ---------------------------------------------------------- */

static rl_status unknown_material(const rl_jscene_ctx *c, const cJSON *item, const char *name)
{
    char list[512] = "";
    size_t len = 0;
    for (uint32_t i = 0; i < c->scene->num_materials && len < sizeof list; ++i) {
        int n = snprintf(list + len, sizeof list - len, "%s%s", i ? ", " : "",
                         c->scene->materials[i].name);
        if (n < 0)
            break;
        len += (size_t)n;
    }
    return rl_json_error(c->doc, item, "unknown material \"%s\" (defined: %s)", name,
                         c->scene->num_materials ? list : "none");
}

static rl_status find_material(const rl_jscene_ctx *c, const cJSON *item, uint32_t *id)
{
    if (!cJSON_IsString(item) || !item->valuestring)
        return rl_json_error(c->doc, item, "expected a material name");
    uint32_t m = rl_scene_find_material(c->scene, item->valuestring);
    if (m == RL_NONE)
        return unknown_material(c, item, item->valuestring);
    *id = m;
    return RL_OK;
}

static const char *const material_keys[] = { "base", "diffuse", "specular", "shininess",
                                             "reflectivity", "transmissivity", "ior",
                                             "emission", "texture", "bsdf", "roughness",
                                             "metallic", "fresnel", NULL };

/* One of names[] at key (absent: *out untouched). */
static rl_status read_choice(rl_jscene_ctx *c, const cJSON *obj, const char *key, const char *const *names,
                             const char *expected, int *out)
{
    const char *text = NULL;
    rl_status st = rl_jscene_string(c, obj, key, &text);
    if (st != RL_OK || !text)
        return st;
    for (int i = 0; names[i]; ++i)
        if (strcmp(text, names[i]) == 0) {
            *out = i;
            return RL_OK;
        }
    return rl_json_error(c->doc, rl_jscene_member(obj, key), "\"%s\" must be one of: %s", key, expected);
}

/* The physically based fields (issue 37). roughness and metallic only mean
 * something to the GGX BRDF: on a Phong material they would be silently
 * ignored, so they are an error there. */
static rl_status read_material_pbr(rl_jscene_ctx *c, const cJSON *obj, rl_material *m)
{
    static const char *const bsdf_names[] = { "phong", "ggx", NULL };
    static const char *const fresnel_names[] = { "none", "schlick", NULL };
    int bsdf = (int)m->bsdf, fresnel = (int)m->fresnel;
    rl_status st;
    if ((st = read_choice(c, obj, "bsdf", bsdf_names, "phong, ggx", &bsdf)) != RL_OK ||
        (st = read_choice(c, obj, "fresnel", fresnel_names, "none, schlick", &fresnel)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "roughness", 0.0, 1.0, &m->roughness)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "metallic", 0.0, 1.0, &m->metallic)) != RL_OK)
        return st;
    m->bsdf = (rl_material_bsdf)bsdf;
    m->fresnel = (rl_fresnel_mode)fresnel;
    const char *pbr_key = rl_jscene_member(obj, "roughness") ? "roughness"
                          : rl_jscene_member(obj, "metallic") ? "metallic" : NULL;
    if (pbr_key && m->bsdf != RL_BSDF_GGX)
        return rl_json_error(c->doc, rl_jscene_member(obj, pbr_key),
                             "\"%s\" needs \"bsdf\": \"ggx\" (the Phong BRDF has no %s)", pbr_key, pbr_key);
    return RL_OK;
}

/* Reads a material object over the defaults (or over "base"). */
static rl_status read_material(rl_jscene_ctx *c, const cJSON *obj, const char *name,
                               rl_material *out)
{
    rl_status st = rl_jscene_check_object(c, obj, "material", material_keys);
    if (st != RL_OK)
        return st;
    rl_material m = rl_material_default();
    const cJSON *base = rl_jscene_member(obj, "base");
    if (base) {
        uint32_t id = RL_NONE;
        if ((st = find_material(c, base, &id)) != RL_OK)
            return st;
        m = c->scene->materials[id];
    }
    snprintf(m.name, sizeof m.name, "%s", name);
    if ((st = rl_jscene_color(c, obj, "diffuse", &m.diffuse)) != RL_OK ||
        (st = rl_jscene_color(c, obj, "specular", &m.specular)) != RL_OK ||
        (st = rl_jscene_color(c, obj, "emission", &m.emission)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "shininess", 0.0, INFINITY, &m.shininess)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "reflectivity", 0.0, 1.0, &m.reflectivity)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "transmissivity", 0.0, 1.0, &m.transmissivity)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "ior", 1.0, INFINITY, &m.ior)) != RL_OK ||
        (st = read_material_pbr(c, obj, &m)) != RL_OK)
        return st;
    /* Ullmann 2003, eq. 3.1: k_r + k_t > 1 would create energy. */
    if (m.reflectivity + m.transmissivity > 1.0f)
        return rl_json_error(c->doc, obj, "reflectivity + transmissivity must not exceed 1 "
                                          "(got %g + %g)", m.reflectivity, m.transmissivity);
    const char *texture = NULL;
    if ((st = rl_jscene_string(c, obj, "texture", &texture)) != RL_OK)
        return st;
    if (texture) {
        /* The scene's base dir is the scene file's folder. */
        st = rl_scene_load_texture(c->scene, texture, &m.diffuse_texture);
        if (st != RL_OK)
            return rl_jscene_located(c, rl_jscene_member(obj, "texture"), st);
    }
    *out = m;
    return RL_OK;
}

static rl_status read_materials(rl_jscene_ctx *c, const cJSON *obj)
{
    rl_status st = rl_jscene_expect_object(c, obj, "\"materials\" (name -> material)");
    if (st != RL_OK)
        return st;
    for (const cJSON *item = obj->child; item; item = item->next) {
        if (!item->string[0] || strlen(item->string) >= sizeof(((rl_material *)0)->name))
            return rl_json_error(c->doc, item, "material names must have 1 to 63 characters");
        rl_material m;
        if ((st = read_material(c, item, item->string, &m)) != RL_OK)
            return st;
        uint32_t existing = rl_scene_find_material(c->scene, item->string);
        if (existing != RL_NONE) {
            /* Redefining a material of the base scene restyles it everywhere. */
            if ((st = rl_material_validate(&m)) != RL_OK)
                return rl_jscene_located(c, item, st);
            c->scene->materials[existing] = m;
            continue;
        }
        if ((st = rl_scene_add_material(c->scene, &m, NULL)) != RL_OK)
            return rl_jscene_located(c, item, st);
    }
    return RL_OK;
}

/* An object's "material": a name, or an inline material (named after the
 * object) that may start from "base". */
static rl_status object_material(rl_jscene_ctx *c, const cJSON *item, const char *object_name,
                                 uint32_t *id)
{
    if (cJSON_IsString(item))
        return find_material(c, item, id);
    if (!cJSON_IsObject(item))
        return rl_json_error(c->doc, item, "\"material\" must be a material name or object");
    char name[64];
    snprintf(name, sizeof name, "%.50s/inline", object_name);
    rl_material m;
    rl_status st = read_material(c, item, name, &m);
    if (st != RL_OK)
        return st;
    st = rl_scene_add_material(c->scene, &m, id);
    return rl_jscene_located(c, item, st);
}

/* ---- lights ------------------------------------------------------------- */

static const char *const light_type_names[] = { "point", "spot", "directional", "quad", NULL };
/* Keys per type: each type accepts exactly the fields it uses. */
static const char *const light_keys[][10] = {
    { "type", "color", "intensity", "position", NULL },
    { "type", "color", "intensity", "position", "direction", "inner_deg", "outer_deg", NULL },
    { "type", "color", "intensity", "direction", NULL },
    { "type", "color", "intensity", "position", "edge_u", "edge_v", NULL },
};
static const char *const light_required[][4] = {
    { "position", NULL },
    { "position", "direction", NULL },
    { "direction", NULL },
    { "position", "edge_u", "edge_v", NULL },
};

static rl_status read_light(rl_jscene_ctx *c, const cJSON *obj)
{
    rl_status st = rl_jscene_expect_object(c, obj, "a light");
    if (st != RL_OK)
        return st;
    const cJSON *type_item;
    if ((st = rl_jscene_require(c, obj, "type", "light", &type_item)) != RL_OK)
        return st;
    int type = -1;
    if (cJSON_IsString(type_item))
        for (int i = 0; light_type_names[i]; ++i)
            if (strcmp(type_item->valuestring, light_type_names[i]) == 0)
                type = i;
    if (type < 0)
        return rl_json_error(c->doc, type_item, "\"type\" must be one of: point, spot, "
                                                "directional, quad");
    char what[32];
    snprintf(what, sizeof what, "%s light", light_type_names[type]);
    if ((st = rl_jscene_check_object(c, obj, what, light_keys[type])) != RL_OK)
        return st;
    for (int i = 0; light_required[type][i]; ++i) {
        const cJSON *unused;
        if ((st = rl_jscene_require(c, obj, light_required[type][i], what, &unused)) != RL_OK)
            return st;
    }

    rl_light l = { 0 };
    l.type = (rl_light_type)type;
    l.color = rl_v3s(1.0f);
    l.intensity = 1.0f;
    l.spot_inner_deg = 20.0f;
    l.spot_outer_deg = 30.0f;
    if ((st = rl_jscene_color(c, obj, "color", &l.color)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "intensity", 0.0, INFINITY, &l.intensity)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "position", false, &l.position)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "direction", true, &l.direction)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "edge_u", true, &l.edge_u)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "edge_v", true, &l.edge_v)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "inner_deg", 0.0, 180.0, &l.spot_inner_deg)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "outer_deg", 0.0, 180.0, &l.spot_outer_deg)) != RL_OK)
        return st;
    if (l.type == RL_LIGHT_SPOT && l.spot_inner_deg > l.spot_outer_deg)
        return rl_json_error(c->doc, obj, "spot light: inner_deg (%g) must not exceed "
                                          "outer_deg (%g)", l.spot_inner_deg, l.spot_outer_deg);
    if (l.type == RL_LIGHT_QUAD && !(rl_length2(rl_cross(l.edge_u, l.edge_v)) > 0.0f))
        return rl_json_error(c->doc, obj, "quad light: edge_u and edge_v must not be parallel");
    if (l.type == RL_LIGHT_SPOT || l.type == RL_LIGHT_DIRECTIONAL)
        l.direction = rl_normalize(l.direction);
    return rl_jscene_located(c, obj, rl_scene_add_light(c->scene, &l));
}

/* ---- cameras ------------------------------------------------------------ */

static rl_status get_size(const rl_jscene_ctx *c, const cJSON *obj, int *w, int *h)
{
    const cJSON *item = rl_jscene_member(obj, "size");
    if (!item)
        return RL_OK;
    double v[2];
    if (!cJSON_IsArray(item) || cJSON_GetArraySize(item) != 2)
        return rl_json_error(c->doc, item, "expected \"size\": [width, height]");
    for (int i = 0; i < 2; ++i) {
        const cJSON *e = cJSON_GetArrayItem(item, i);
        if (!cJSON_IsNumber(e) || !(e->valuedouble >= 1.0) ||
            e->valuedouble > RL_IMAGE_MAX_SIZE || e->valuedouble != floor(e->valuedouble))
            return rl_json_error(c->doc, e, "image size must be an integer in [1, %d]",
                                 RL_IMAGE_MAX_SIZE);
        v[i] = e->valuedouble;
    }
    *w = (int)v[0];
    *h = (int)v[1];
    return RL_OK;
}

/* Shared by cameras and camera path keys: eye, target, up, fov_deg. */
static rl_status read_view(rl_jscene_ctx *c, const cJSON *obj, const char *what, rl_camera *cam)
{
    const cJSON *unused;
    rl_status st;
    if ((st = rl_jscene_require(c, obj, "eye", what, &unused)) != RL_OK ||
        (st = rl_jscene_require(c, obj, "target", what, &unused)) != RL_OK)
        return st;
    cam->up = rl_v3(0.0f, 1.0f, 0.0f);
    cam->fov_deg = RL_CAMERA_DEFAULT_FOV_DEG;
    if ((st = rl_jscene_vec3(c, obj, "eye", false, &cam->eye)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "target", false, &cam->target)) != RL_OK ||
        (st = rl_jscene_vec3(c, obj, "up", true, &cam->up)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "fov_deg", 0.0, 180.0, &cam->fov_deg)) != RL_OK)
        return st;
    if (cam->fov_deg <= 0.0f || cam->fov_deg >= 180.0f)
        return rl_json_error(c->doc, rl_jscene_member(obj, "fov_deg"),
                             "\"fov_deg\" must lie strictly between 0 and 180");
    if (rl_camera_validate(cam) != RL_OK)
        return rl_jscene_located(c, obj, RL_ERR_INVALID_ARG);
    return RL_OK;
}

static rl_status read_camera(rl_jscene_ctx *c, const cJSON *obj, uint32_t index)
{
    static const char *const keys[] = { "name", "eye", "target", "up", "fov_deg", "size", NULL };
    rl_status st = rl_jscene_check_object(c, obj, "camera", keys);
    if (st != RL_OK)
        return st;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "camera%u", index);
    const char *name = fallback;
    rl_camera cam = { 0 };
    if ((st = rl_jscene_string(c, obj, "name", &name)) != RL_OK ||
        (st = get_size(c, obj, &cam.width, &cam.height)) != RL_OK ||
        (st = read_view(c, obj, "camera", &cam)) != RL_OK)
        return st;
    return rl_jscene_located(c, obj, rl_scene_add_camera(c->scene, name, &cam));
}

static rl_status read_camera_path(rl_jscene_ctx *c, const cJSON *obj)
{
    static const char *const path_keys[] = { "keys", NULL };
    static const char *const key_keys[] = { "time_s", "eye", "target", "up", "fov_deg", NULL };
    const cJSON *keys;
    rl_status st = rl_jscene_check_object(c, obj, "camera_path", path_keys);
    if (st == RL_OK)
        st = rl_jscene_require(c, obj, "keys", "camera_path", &keys);
    if (st == RL_OK)
        st = rl_jscene_expect_array(c, keys, "camera keys");
    if (st != RL_OK)
        return st;
    int n = cJSON_GetArraySize(keys);
    if (n < 1)
        return rl_json_error(c->doc, keys, "a camera path needs at least one key");
    rl_camera_key *ck = rl_calloc((size_t)n, sizeof *ck);
    if (!ck)
        return RL_ERR_OUT_OF_MEMORY;
    int i = 0;
    for (const cJSON *k = keys->child; k && st == RL_OK; k = k->next, ++i) {
        const cJSON *t;
        st = rl_jscene_check_object(c, k, "camera key", key_keys);
        if (st == RL_OK)
            st = rl_jscene_require(c, k, "time_s", "camera key", &t);
        if (st == RL_OK)
            st = rl_jscene_number(c, k, "time_s", -INFINITY, INFINITY, &ck[i].time_s);
        if (st == RL_OK && i > 0 && !(ck[i].time_s > ck[i - 1].time_s))
            st = rl_json_error(c->doc, t, "\"time_s\" must increase from key to key "
                                          "(%g after %g)", ck[i].time_s, ck[i - 1].time_s);
        if (st == RL_OK)
            st = read_view(c, k, "camera key", &ck[i].camera);
    }
    rl_camera_path *path = NULL;
    if (st == RL_OK)
        st = rl_jscene_located(c, keys, rl_camera_path_create(ck, (uint32_t)n, &path));
    free(ck);
    if (st == RL_OK && (st = rl_scene_set_camera_path(c->scene, path)) != RL_OK)
        rl_camera_path_release(path);
    return st;
}

/* ---- objects ------------------------------------------------------------ */

static rl_status default_material(rl_jscene_ctx *c, uint32_t *id)
{
    if (c->default_material == RL_NONE) {
        rl_material m = rl_material_default();
        snprintf(m.name, sizeof m.name, "default");
        uint32_t existing = rl_scene_find_material(c->scene, "default");
        if (existing != RL_NONE)
            c->default_material = existing;
        else {
            rl_status st = rl_scene_add_material(c->scene, &m, &c->default_material);
            if (st != RL_OK)
                return st;
        }
    }
    *id = c->default_material;
    return RL_OK;
}

static rl_status read_attributes(const rl_jscene_ctx *c, const cJSON *obj, uint32_t node)
{
    rl_status st = rl_jscene_expect_object(c, obj,
                                           "\"attributes\" (key -> string, number or bool)");
    if (st != RL_OK)
        return st;
    for (const cJSON *m = obj->child; m; m = m->next) {
        char value[512];
        if ((st = rl_jscene_scalar_text(c, m, value, sizeof value)) != RL_OK)
            return st;
        if (!m->string[0])
            return rl_json_error(c->doc, m, "attribute names must not be empty");
        if ((st = rl_scene_node_set_attr(c->scene, node, m->string, value)) != RL_OK)
            return rl_jscene_located(c, m, st);
    }
    return RL_OK;
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

static rl_status read_object(rl_jscene_ctx *c, const cJSON *obj, uint32_t parent, int depth)
{
    static const char *const keys[] = { "name", "file", "generator", "params", "transform",
                                        "material", "attributes", "children", NULL };
    rl_status st = rl_jscene_check_object(c, obj, "object", keys);
    if (st != RL_OK)
        return st;
    if (depth > MAX_OBJECT_DEPTH)
        return rl_json_error(c->doc, obj, "objects nested deeper than %d levels",
                             MAX_OBJECT_DEPTH);
    const char *name = NULL, *file = NULL, *generator = NULL;
    if ((st = rl_jscene_string(c, obj, "name", &name)) != RL_OK ||
        (st = rl_jscene_string(c, obj, "file", &file)) != RL_OK ||
        (st = rl_jscene_string(c, obj, "generator", &generator)) != RL_OK)
        return st;
    if (file && generator)
        return rl_json_error(c->doc, rl_jscene_member(obj, "generator"),
                             "an object has either \"file\" or \"generator\", not both");
    if (rl_jscene_member(obj, "params") && !generator)
        return rl_json_error(c->doc, rl_jscene_member(obj, "params"),
                             "\"params\" belongs to a \"generator\" object");
    char stem[128];
    if (!name && file) {
        file_stem(file, stem, sizeof stem);
        name = stem;
    } else if (!name) {
        name = generator ? generator : "group";
    }

    rl_mat4 m = rl_mat4_identity();
    const cJSON *transform = rl_jscene_member(obj, "transform");
    if (transform && (st = rl_jscene_transform(c, transform, &m)) != RL_OK)
        return st;
    uint32_t material = RL_NONE;
    if (rl_jscene_member(obj, "material") &&
        (st = object_material(c, rl_jscene_member(obj, "material"), name, &material)) != RL_OK)
        return st;

    uint32_t node;
    if ((st = rl_scene_add_node(c->scene, parent, name, &m, &node)) != RL_OK)
        return rl_jscene_located(c, obj, st);
    if (material != RL_NONE && (st = rl_scene_node_set_material(c->scene, node, material)) != RL_OK)
        return rl_jscene_located(c, rl_jscene_member(obj, "material"), st);

    if (generator) {
        char params[2048] = "";
        const cJSON *p = rl_jscene_member(obj, "params");
        if (p && (st = rl_jscene_params_text(c, p, params, sizeof params)) != RL_OK)
            return st;
        uint32_t mesh_material = material, mesh;
        if (mesh_material == RL_NONE && (st = default_material(c, &mesh_material)) != RL_OK)
            return st;
        st = rl_scene_add_generated(c->scene, generator, params, mesh_material, &mesh);
        if (st != RL_OK)
            return rl_jscene_located(c, p ? p : rl_jscene_member(obj, "generator"), st);
        if ((st = rl_scene_node_set_mesh(c->scene, node, mesh)) != RL_OK)
            return rl_jscene_located(c, obj, st);
    } else if (file) {
        char full[PATH_MAX_LEN];
        rl_path_join(rl_scene_base_dir(c->scene), file, full, sizeof full);
        uint32_t root = RL_NONE;
        if ((st = rl_scene_import(c->scene, full, node, &root)) != RL_OK)
            return rl_jscene_located(c, rl_jscene_member(obj, "file"), st);
    }

    const cJSON *attrs = rl_jscene_member(obj, "attributes");
    if (attrs && (st = read_attributes(c, attrs, node)) != RL_OK)
        return st;
    const cJSON *children = rl_jscene_member(obj, "children");
    if (children) {
        if ((st = rl_jscene_expect_array(c, children, "objects")) != RL_OK)
            return st;
        for (const cJSON *child = children->child; child; child = child->next)
            if ((st = read_object(c, child, node, depth + 1)) != RL_OK)
                return st;
    }
    return RL_OK;
}

static rl_status create_scene(rl_jscene_ctx *c, const cJSON *root, rl_scene **out)
{
    const cJSON *base = rl_jscene_member(root, "base"), *params = rl_jscene_member(root, "params");
    rl_status st;
    if (params && !base)
        return rl_json_error(c->doc, params, "\"params\" needs a \"base\" built-in scene");
    if (!base)
        return rl_scene_create(out);
    if (!cJSON_IsString(base) || !base->valuestring)
        return rl_json_error(c->doc, base, "\"base\" must be the name of a built-in scene");
    char text[2048] = "";
    if (params && (st = rl_jscene_params_text(c, params, text, sizeof text)) != RL_OK)
        return st;
    rl_scene *builtin = NULL, *scene = NULL;
    st = rl_scene_create_builtin(base->valuestring, text, &builtin);
    if (st != RL_OK)
        return rl_jscene_located(c, params && st == RL_ERR_INVALID_ARG ? params : base, st);
    if ((st = rl_scene_create(&scene)) == RL_OK &&
        (st = rl_jscene_copy_base(builtin, scene)) != RL_OK) {
        rl_scene_release(scene);
        scene = NULL;
    }
    rl_scene_release(builtin);
    if (st == RL_OK)
        *out = scene;
    return st;
}

/* ---- environment -------------------------------------------------------- */

static rl_status read_environment(rl_jscene_ctx *c, const cJSON *obj)
{
    static const char *const keys[] = { "file", "color", "intensity", "rotation_deg", NULL };
    rl_status st = rl_jscene_check_object(c, obj, "\"environment\"", keys);
    if (st != RL_OK)
        return st;
    rl_environment_desc desc = { .color = rl_v3s(1.0f), .intensity = 1.0f };
    if ((st = rl_jscene_string(c, obj, "file", &desc.path)) != RL_OK ||
        (st = rl_jscene_color(c, obj, "color", &desc.color)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "intensity", 0.0, INFINITY, &desc.intensity)) != RL_OK ||
        (st = rl_jscene_float(c, obj, "rotation_deg", -INFINITY, INFINITY, &desc.rotation_deg)) != RL_OK)
        return st;
    if (desc.intensity == 0.0f)
        desc.color = rl_v3s(0.0f);    /* the desc's 0 means 1 */
    st = rl_scene_set_environment(c->scene, &desc);
    return rl_jscene_located(c, desc.path ? rl_jscene_member(obj, "file") : obj, st);
}

static rl_status load(rl_jscene_ctx *c, const cJSON *root)
{
    static const char *const keys[] = { "name", "base", "params", "materials", "lights",
                                        "cameras", "camera_path", "objects", "environment", NULL };
    rl_status st = rl_jscene_check_object(c, root, "the scene", keys);
    if (st != RL_OK)
        return st;
    const char *name = NULL;
    if ((st = rl_jscene_string(c, root, "name", &name)) != RL_OK)
        return st;
    char stem[256], dir[PATH_MAX_LEN];
    file_stem(c->path, stem, sizeof stem);
    rl_path_dirname(c->path, dir, sizeof dir);
    if ((st = rl_scene_set_name(c->scene, name ? name : stem)) != RL_OK ||
        (st = rl_scene_set_base_dir(c->scene, dir)) != RL_OK)
        return st;

    const cJSON *item;
    if ((item = rl_jscene_member(root, "environment")) && (st = read_environment(c, item)) != RL_OK)
        return st;
    if ((item = rl_jscene_member(root, "materials")) && (st = read_materials(c, item)) != RL_OK)
        return st;
    /* Cameras before objects, so that the file's own cameras come first
     * even when an imported model brings some. */
    if ((item = rl_jscene_member(root, "cameras"))) {
        if ((st = rl_jscene_expect_array(c, item, "cameras")) != RL_OK)
            return st;
        uint32_t i = 0;
        for (const cJSON *cam = item->child; cam; cam = cam->next, ++i)
            if ((st = read_camera(c, cam, i)) != RL_OK)
                return st;
    }
    if ((item = rl_jscene_member(root, "camera_path")) && (st = read_camera_path(c, item)) != RL_OK)
        return st;
    if ((item = rl_jscene_member(root, "lights"))) {
        if ((st = rl_jscene_expect_array(c, item, "lights")) != RL_OK)
            return st;
        for (const cJSON *l = item->child; l; l = l->next)
            if ((st = read_light(c, l)) != RL_OK)
                return st;
    }
    if ((item = rl_jscene_member(root, "objects"))) {
        if ((st = rl_jscene_expect_array(c, item, "objects")) != RL_OK)
            return st;
        for (const cJSON *o = item->child; o; o = o->next)
            if ((st = read_object(c, o, RL_NODE_ROOT, 1)) != RL_OK)
                return st;
    }
    bool has_instance = false;
    for (uint32_t i = 0; i < c->scene->num_nodes; ++i)
        has_instance |= c->scene->nodes[i].mesh != RL_NONE;
    if (!has_instance)
        return rl_error(RL_ERR_EMPTY_SCENE, "%s: the scene has no objects with geometry",
                        c->path);
    st = rl_scene_commit(c->scene);
    if (st != RL_OK && !c->had_error) {
        /* Name the file: commit only knows the scene's name. */
        char msg[1024];
        snprintf(msg, sizeof msg, "%s", rl_last_error());
        rl_clear_error();
        return rl_error(st, "%s: %s", c->path, msg);
    }
    return st;
}

RL_API rl_status rl_scene_load_json(const char *path, rl_scene **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_load_json: NULL argument");
    rl_jscene_ctx c = { .path = path, .default_material = RL_NONE,
              .had_error = rl_last_status() != RL_OK };
    rl_json_doc *doc = NULL;
    rl_status st = rl_json_parse_file(path, &doc);
    if (st != RL_OK)
        return st;
    c.doc = doc;
    const cJSON *root = rl_json_root(doc);
    st = rl_jscene_expect_object(&c, root, "the scene");
    rl_scene *scene = NULL;
    if (st == RL_OK)
        st = create_scene(&c, root, &scene);
    if (st == RL_OK) {
        c.scene = scene;
        st = load(&c, root);
    }
    rl_json_free(doc);
    if (st != RL_OK) {
        rl_scene_release(scene);
        return st;
    }
    *out = scene;
    return RL_OK;
}
