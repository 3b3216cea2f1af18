/* builtin_linespace.c: the test scenes of Schröder 2017, Sec. 9.3, for the
 * Line Space path tracer: "ls-open" (scenes 1-3) and "ls-cornell" (4-7).
 *
 *   ls-open     an open scene: one object on a floor (2 triangles) under
 *               three quad lights (2 triangles each): object + 8
 *               triangles; the thesis traces paths of length <= 2.
 *   ls-cornell  a closed Cornell box: 5 walls (10 triangles) and a ceiling
 *               light (2); inside either a diffuse and a mirror cuboid (12
 *               triangles each, 36 in all, scene 4) or one model (+12,
 *               scenes 5-7); paths of length <= 3.
 * The thesis' maximum path length is left on the root node as attribute
 * "max_path_length" for renderers that want it.
 *
 * Models (model=): the Utah teapot at the thesis' 15,704 triangles
 * (13 x 19 grid per patch, teapot.c), and generated closed blobs (blob.c)
 * standing in for the Stanford bunny (69,450 triangles) and dragon
 * (871,306). Deviation: the thesis' bunny has 69,451 triangles, an odd
 * count that no closed triangle mesh can have (3T = 2E), so the blob has
 * 69,450. triangles=N overrides the count: the teapot takes the patch grid
 * closest to N, a blob exactly N (even).
 *
 * Materials (Sec. 9.2): the central object is always 90 % diffuse and 10 %
 * specular with shininess 50: k_d = 0.9 * base colour, k_s = 0.1. In the
 * box scene the diffuse cuboid is the central object; the mirror cuboid
 * reflects perfectly (k_r = 1, no local term). Every light is both an
 * emissive quad mesh and an RL_LIGHT_QUAD at exactly the same place (as in
 * builtin_cornell.c), so renderers that sample lights and renderers that
 * hit emitters see the same light. Cameras: 1280 x 720, the thesis'
 * viewport (Sec. 9.2). Units: metres; y up; the box opens towards +z. */
#include "scene/builtin.h"

#include <stdio.h>
#include <string.h>

#include "core/error.h"
#include "scene/blob.h"
#include "scene/generators.h"

enum model { MODEL_BOXES, MODEL_TEAPOT, MODEL_BUNNY, MODEL_DRAGON };
static const char *const model_names[] = { "boxes", "teapot", "bunny", "dragon", NULL };

/* Base colour of the central object; k_d = 0.9 of it (Sec. 9.2). */
static const rl_vec3 object_base = { 1.0f, 0.85f, 0.6f };

/* The central object's material, added to the scene. */
static rl_status add_object_material(rl_scene *scene, uint32_t *id)
{
    rl_material m = rl_builtin_phong("ls_object", rl_scale(object_base, 0.9f), 0.1f, 50.0f);
    return rl_scene_add_material(scene, &m, id);
}

/* model= and triangles=, checked before any geometry is built: the table
 * takes triangles in the widest range, the model narrows it. Without
 * triangles *triangles stays 0, the model's default. */
static rl_status read_model(const rl_option_store *params, const char *ctx, int *model, long long *triangles)
{
    *model = rl_option_store_enum(params, "model");
    if (!rl_option_store_given(params, "triangles"))
        return RL_OK;   /* *triangles stays 0: the model's default */
    *triangles = rl_option_store_int(params, "triangles");
    if (*model == MODEL_BOXES)
        return rl_error(RL_ERR_INVALID_ARG, "%s: triangles applies to model=teapot, bunny or "
                        "dragon, not boxes", ctx);
    long long lo = *model == MODEL_TEAPOT ? 1 : RL_BLOB_MIN_TRIANGLES;
    long long hi = *model == MODEL_TEAPOT ? RL_TEAPOT_MAX_TRIANGLES : RL_BLOB_MAX_TRIANGLES;
    if (*triangles < lo || *triangles > hi)
        return rl_error(RL_ERR_INVALID_ARG, "%s: option triangles=%lld is outside [%lld, %lld] for model=%s", ctx,
                        *triangles, lo, hi, model_names[*model]);
    if (*model != MODEL_TEAPOT && *triangles % 2)
        return rl_error(RL_ERR_INVALID_ARG, "%s: triangles=%lld for model=%s is odd; the model "
                        "is a closed mesh, whose triangle count is even", ctx, *triangles,
                        model_names[*model]);
    return RL_OK;
}

static rl_status add_model(rl_scene *scene, int model, long long triangles, uint32_t material,
                           float height)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = material;
    rl_status s = RL_OK;
    if (model == MODEL_TEAPOT) {
        rl_gen_teapot(&b, triangles ? (uint32_t)triangles : RL_TEAPOT_DEFAULT_TRIANGLES, height);
    } else {
        uint32_t count = triangles ? (uint32_t)triangles
                       : model == MODEL_BUNNY ? RL_LS_BUNNY_TRIANGLES : RL_LS_DRAGON_TRIANGLES;
        /* Fixed seeds: the two stand-ins differ in shape, not only count. */
        rl_blob_desc blob = { .triangles = count, .seed = model == MODEL_BUNNY ? 5 : 3,
                              .scale = 1.0f, .lumps = model == MODEL_BUNNY ? 8 : 14 };
        s = rl_gen_blob(&b, &blob);
    }
    rl_mat4 world = rl_mat4_identity();
    if (!s && b.status == RL_OK && model != MODEL_TEAPOT) {
        rl_aabb box = rl_aabb_empty();
        for (uint32_t i = 0; i < b.num_vertices; ++i)
            box = rl_aabb_grow(box, b.positions[i]);
        float k = height / (box.max.y - box.min.y);
        rl_vec3 c = rl_aabb_center(box);
        rl_mat4 t = rl_mat4_translate(rl_v3(-c.x * k, -box.min.y * k, -c.z * k));
        rl_mat4 sc = rl_mat4_scale(rl_v3s(k));
        world = rl_mat4_mul(&t, &sc);
    }
    uint32_t mesh = RL_NONE;
    if (!s)
        s = rl_meshbuf_add_to_scene(scene, &b, model_names[model], &mesh);
    rl_meshbuf_free(&b);
    if (!s)
        s = rl_builtin_instance(scene, RL_NODE_ROOT, model_names[model], mesh, "object", &world,
                                NULL);
    return s;
}

/* An emissive quad mesh plus an RL_LIGHT_QUAD on the same parallelogram:
 * corner + s edge_u + t edge_v, emitting towards cross(edge_u, edge_v). */
static rl_status add_quad_light(rl_scene *scene, const char *name, uint32_t material,
                                rl_vec3 corner, rl_vec3 edge_u, rl_vec3 edge_v, rl_vec3 color,
                                float intensity)
{
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = material;
    rl_meshbuf_quad(&b, corner, rl_add(corner, edge_u), rl_add(rl_add(corner, edge_u), edge_v),
                    rl_add(corner, edge_v), rl_v2(1.0f, 1.0f));
    uint32_t mesh;
    rl_status s = rl_meshbuf_add_to_scene(scene, &b, name, &mesh);
    rl_meshbuf_free(&b);
    if (!s) s = rl_builtin_instance(scene, RL_NODE_ROOT, name, mesh, "light", NULL, NULL);
    rl_light l = { .type = RL_LIGHT_QUAD, .color = color, .intensity = intensity,
                   .position = corner, .edge_u = edge_u, .edge_v = edge_v };
    if (!s) s = rl_scene_add_light(scene, &l);
    return s;
}

static rl_status add_light_material(rl_scene *scene, rl_vec3 emission, uint32_t *id)
{
    rl_material m = rl_material_default();
    snprintf(m.name, sizeof m.name, "ls_light");
    m.diffuse = rl_v3s(0.78f);
    m.emission = emission;
    return rl_scene_add_material(scene, &m, id);
}

static rl_status add_camera(rl_scene *scene, rl_vec3 eye, rl_vec3 target, float fov_deg)
{
    rl_camera cam = { .eye = eye, .target = target, .up = rl_v3(0.0f, 1.0f, 0.0f),
                      .fov_deg = fov_deg, .width = 1280, .height = 720 };
    return rl_scene_add_camera(scene, "default", &cam);
}

/* ---- ls-open (Sec. 9.3, scenes 1-3) -------------------------------------- */

static rl_status build_ls_open(rl_scene *scene, const rl_option_store *params)
{
    const char *ctx = "ls-open";
    int model = MODEL_TEAPOT;
    long long triangles = 0;
    rl_status s = read_model(params, ctx, &model, &triangles);
    if (!s && model == MODEL_BOXES)
        s = rl_error(RL_ERR_INVALID_ARG, "%s: model=boxes belongs to ls-cornell (expected "
                     "teapot, bunny or dragon)", ctx);
    if (s)
        return s;

    uint32_t floor_mat, object_mat, light_mat, floor_mesh;
    const float intensity = 20.0f;
    s = rl_builtin_material(scene, "ls_floor", rl_v3s(0.7f), &floor_mat);
    if (!s) s = add_object_material(scene, &object_mat);
    if (!s) s = add_light_material(scene, rl_v3s(intensity), &light_mat);
    if (!s) {
        rl_meshbuf b;
        rl_meshbuf_init(&b);
        b.material = floor_mat;
        rl_gen_quad(&b, 8.0f, 8.0f, 1.0f);
        s = rl_meshbuf_add_to_scene(scene, &b, "floor", &floor_mesh);
        rl_meshbuf_free(&b);
    }
    if (!s) s = rl_builtin_instance(scene, RL_NODE_ROOT, "floor", floor_mesh, "floor", NULL, NULL);
    if (!s) s = add_model(scene, model, triangles, object_mat, 1.0f);

    /* Three 0.6 m square lights, 2.2 m from the axis and 2.5 m up, each
     * facing the object's middle: key (front left), fill (front right),
     * rim (behind). */
    static const float angles_deg[3] = { 120.0f, 30.0f, 270.0f };
    static const char *const names[3] = { "light_key", "light_fill", "light_rim" };
    const rl_vec3 aim = rl_v3(0.0f, 0.5f, 0.0f);
    for (int i = 0; i < 3 && !s; ++i) {
        float a = rl_radians(angles_deg[i]);
        rl_vec3 centre = rl_v3(2.2f * cosf(a), 2.5f, 2.2f * sinf(a));
        rl_vec3 n = rl_normalize(rl_sub(aim, centre));
        rl_vec3 eu = rl_scale(rl_normalize(rl_cross(rl_v3(0.0f, 1.0f, 0.0f), n)), 0.6f);
        rl_vec3 ev = rl_scale(rl_normalize(rl_cross(n, eu)), 0.6f);  /* cross(eu, ev) ~ n */
        rl_vec3 corner = rl_sub(centre, rl_scale(rl_add(eu, ev), 0.5f));
        s = add_quad_light(scene, names[i], light_mat, corner, eu, ev, rl_v3s(1.0f), intensity);
    }
    if (!s) s = rl_scene_node_set_attr(scene, RL_NODE_ROOT, "max_path_length", "2");
    if (!s) s = add_camera(scene, rl_v3(0.0f, 1.6f, 4.2f), rl_v3(0.0f, 0.45f, 0.0f), 40.0f);
    return s;
}

/* ---- ls-cornell (Sec. 9.3, scenes 4-7) ----------------------------------- */

enum { WALL_WHITE, WALL_RED, WALL_GREEN, NUM_WALL_MATERIALS };

static rl_status build_ls_cornell(rl_scene *scene, const rl_option_store *params)
{
    const char *ctx = "ls-cornell";
    int model = MODEL_BOXES;
    long long triangles = 0;
    rl_status s = read_model(params, ctx, &model, &triangles);
    if (s)
        return s;

    /* The box: x -1..1, y 0..2, z -1..1, open towards +z; quads wound so
     * that they face the inside (normal cross(p1 - p0, p3 - p0)). */
    static const struct { int material; float p[4][3]; } walls[5] = {
        { WALL_WHITE, { { -1, 0, 1 }, { 1, 0, 1 }, { 1, 0, -1 }, { -1, 0, -1 } } },    /* floor */
        { WALL_WHITE, { { -1, 2, -1 }, { 1, 2, -1 }, { 1, 2, 1 }, { -1, 2, 1 } } },    /* ceiling */
        { WALL_WHITE, { { -1, 0, -1 }, { 1, 0, -1 }, { 1, 2, -1 }, { -1, 2, -1 } } },  /* back */
        { WALL_RED, { { -1, 0, 1 }, { -1, 0, -1 }, { -1, 2, -1 }, { -1, 2, 1 } } },    /* left */
        { WALL_GREEN, { { 1, 0, -1 }, { 1, 0, 1 }, { 1, 2, 1 }, { 1, 2, -1 } } },      /* right */
    };
    static const char *const wall_names[NUM_WALL_MATERIALS] = { "white", "red", "green" };
    static const float wall_colours[NUM_WALL_MATERIALS][3] = {
        { 0.73f, 0.73f, 0.73f }, { 0.65f, 0.05f, 0.05f }, { 0.12f, 0.45f, 0.15f }
    };
    uint32_t wall_mat[NUM_WALL_MATERIALS], object_mat, light_mat, walls_mesh;
    for (int i = 0; i < NUM_WALL_MATERIALS && !s; ++i)
        s = rl_builtin_material(scene, wall_names[i],
                                rl_v3(wall_colours[i][0], wall_colours[i][1], wall_colours[i][2]),
                                &wall_mat[i]);
    if (!s) s = add_object_material(scene, &object_mat);
    const rl_vec3 light_color = rl_v3(1.0f, 0.8f, 0.55f);
    const float intensity = 12.0f;
    if (!s) s = add_light_material(scene, rl_scale(light_color, intensity), &light_mat);
    if (!s) {
        rl_meshbuf b;
        rl_meshbuf_init(&b);
        for (int w = 0; w < 5; ++w) {
            const float (*p)[3] = walls[w].p;
            b.material = wall_mat[walls[w].material];
            rl_meshbuf_quad(&b, rl_v3(p[0][0], p[0][1], p[0][2]), rl_v3(p[1][0], p[1][1], p[1][2]),
                            rl_v3(p[2][0], p[2][1], p[2][2]), rl_v3(p[3][0], p[3][1], p[3][2]),
                            rl_v2(1.0f, 1.0f));
        }
        s = rl_meshbuf_add_to_scene(scene, &b, "walls", &walls_mesh);
        rl_meshbuf_free(&b);
    }
    if (!s) s = rl_builtin_instance(scene, RL_NODE_ROOT, "walls", walls_mesh, "box", NULL, NULL);
    /* Ceiling light 0.5 m square, 1 mm below the ceiling so that the two
     * are not coplanar; cross((0,0,.5), (-.5,0,0)) points down. */
    if (!s)
        s = add_quad_light(scene, "light", light_mat, rl_v3(0.25f, 1.999f, -0.25f),
                           rl_v3(0.0f, 0.0f, 0.5f), rl_v3(-0.5f, 0.0f, 0.0f), light_color,
                           intensity);

    if (!s && model == MODEL_BOXES) {
        rl_material mirror = rl_material_default();
        snprintf(mirror.name, sizeof mirror.name, "ls_mirror");
        mirror.diffuse = rl_v3s(0.0f);
        mirror.specular = rl_v3s(0.0f);
        mirror.reflectivity = 1.0f;
        uint32_t mirror_mat, tall_mesh, short_mesh;
        s = rl_scene_add_material(scene, &mirror, &mirror_mat);
        const struct { const char *name; uint32_t material; rl_vec3 size, at; float turn_deg;
                       uint32_t *mesh; } boxes[2] = {
            { "diffuse_box", object_mat, { 0.6f, 1.2f, 0.6f }, { -0.35f, 0.6f, -0.3f }, 18.0f,
              &tall_mesh },
            { "mirror_box", mirror_mat, { 0.6f, 0.6f, 0.6f }, { 0.4f, 0.3f, 0.3f }, -35.0f,
              &short_mesh },
        };
        for (int i = 0; i < 2 && !s; ++i) {
            rl_meshbuf b;
            rl_meshbuf_init(&b);
            b.material = boxes[i].material;
            rl_gen_box(&b, boxes[i].size);
            s = rl_meshbuf_add_to_scene(scene, &b, boxes[i].name, boxes[i].mesh);
            rl_meshbuf_free(&b);
            rl_mat4 t = rl_mat4_translate(boxes[i].at);
            rl_mat4 r = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), rl_radians(boxes[i].turn_deg));
            rl_mat4 world = rl_mat4_mul(&t, &r);
            if (!s)
                s = rl_builtin_instance(scene, RL_NODE_ROOT, boxes[i].name, *boxes[i].mesh,
                                        "object", &world, NULL);
        }
    } else if (!s) {
        /* Teapot 0.7 m tall (about 1.4 m wide with spout and handle), blobs
         * 1 m tall: well inside the 2 m box. */
        s = add_model(scene, model, triangles, object_mat, model == MODEL_TEAPOT ? 0.7f : 1.0f);
    }
    if (!s) s = rl_scene_node_set_attr(scene, RL_NODE_ROOT, "max_path_length", "3");
    if (!s) s = add_camera(scene, rl_v3(0.0f, 1.0f, 3.9f), rl_v3(0.0f, 1.0f, 0.0f), 40.0f);
    return s;
}

#define LS_TRIANGLES_OPTION                                                                                     \
    { "triangles", RL_OPT_INT, "",                                                                              \
      "model triangles; not given: the model's own (teapot 15704, the closest patch grid to N, 1..4000000; "   \
      "bunny 69450, dragon 871306, exactly N, even, 4..16000000); not for boxes",                             \
      1, RL_BLOB_MAX_TRIANGLES, NULL }

static const rl_option_info ls_open_options[] = {
    { "model", RL_OPT_ENUM, "teapot", "the object: teapot, bunny or dragon (closed blobs standing in for the "
      "thesis' scans; boxes belongs to ls-cornell)", 0, 0, model_names },
    LS_TRIANGLES_OPTION,
};

static const rl_option_info ls_cornell_options[] = {
    { "model", RL_OPT_ENUM, "boxes", "boxes: a diffuse and a mirror cuboid; or one model as in ls-open", 0, 0,
      model_names },
    LS_TRIANGLES_OPTION,
};

const rl_builtin_class rl_builtin_ls_open_class = {
    { "ls-open",
      "Schröder 2017, Sec. 9.3, scenes 1-3: one object (90 % diffuse, 10 % specular, shininess 50) on a floor "
      "under three quad lights; object + 8 triangles; max path length 2 (root attribute max_path_length); camera "
      "1280x720",
      RL_BUILTIN_OPTIONS(ls_open_options) },
    build_ls_open,
};

const rl_builtin_class rl_builtin_ls_cornell_class = {
    { "ls-cornell",
      "Schröder 2017, Sec. 9.3, scenes 4-7: Cornell box (5 walls, ceiling quad light: 12 triangles) with a "
      "diffuse and a mirror cuboid (36 triangles) or one model (+12); max path length 3 (root attribute "
      "max_path_length); camera 1280x720",
      RL_BUILTIN_OPTIONS(ls_cornell_options) },
    build_ls_cornell,
};
