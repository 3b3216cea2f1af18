/* builtin_cornell.c: the Cornell box ("cornell") and the box with the Utah
 * teapot instead of the blocks ("cornell-teapot").
 *
 * Geometry and camera are the Cornell University measured data set
 * ("Cornell Box Data", Program of Computer Graphics), given there in
 * millimetres and converted here to metres (divided by 1000): the box spans
 * about x 0..0.556, y 0..0.549, z 0..0.559, the opening faces -z, red wall at
 * x = 0.55, green wall at x = 0. Deviations from the data: the blocks get a
 * bottom face (so each is a closed box: 12 triangles), and the ceiling light
 * is lowered 0.5 mm below the ceiling so the two are not coplanar. The light
 * is both an emissive quad mesh and an RL_LIGHT_QUAD at the same place, for
 * renderers that sample lights and renderers that hit emitters. Reflectances
 * are the usual RGB fits of the measured spectra: white 0.73, red
 * (0.65, 0.05, 0.05), green (0.12, 0.45, 0.15); emitted radiance (17, 12, 4).
 * Camera: eye (0.278, 0.273, -0.8) looking along +z, 35 mm lens on a 25 mm
 * film, i.e. vertical fov 2*atan(12.5/35) = 39.3 degrees, square image.
 *
 * variant=bitterli takes the material settings of Bitterli's "cornell-box"
 * (Rendering Resources, 2016), on which issue 37 compares path tracers:
 * white (0.725, 0.71, 0.68), red (0.63, 0.065, 0.05), green (0.14, 0.45,
 * 0.091), a black lamp (the one-sided emitter reflects nothing; ours
 * reflects 0.78) and paths of up to 8 scattering vertices (root attribute
 * max_path_length = 7: interactions after the camera hit, as pt counts
 * them). The geometry and camera stay the measured data's above, not
 * Bitterli's mesh.
 *
 * variant=shade (issue 37, bdpt) hangs a white plate 30 mm wider than the
 * lamp on each side 44 mm below it: the classic box lit by a lamp with a
 * shade, where the room sees the lamp only through bounces off the plate
 * and the ceiling (and a grazing strip of the walls' tops), the case
 * bidirectional path tracing is for. */
#include "scene/builtin.h"

#include <stdio.h>

#include "core/error.h"
#include "scene/generators.h"

#define MM 0.001f                       /* data units -> metres */
#define LIGHT_DROP_MM 0.5f              /* light below the ceiling */

typedef struct part {
    const char *name;
    int material;                       /* index into the box materials */
    int num_quads;
    float quads[6][4][3];               /* mm */
} part;

enum { WHITE, RED, GREEN, LIGHT, NUM_MATERIALS };

static const part walls[] = {
    { "floor", WHITE, 1,
      { { { 552.8f, 0.0f, 0.0f }, { 0.0f, 0.0f, 0.0f }, { 0.0f, 0.0f, 559.2f }, { 549.6f, 0.0f, 559.2f } } } },
    { "ceiling", WHITE, 1,
      { { { 556.0f, 548.8f, 0.0f }, { 556.0f, 548.8f, 559.2f }, { 0.0f, 548.8f, 559.2f }, { 0.0f, 548.8f, 0.0f } } } },
    { "back_wall", WHITE, 1,
      { { { 549.6f, 0.0f, 559.2f }, { 0.0f, 0.0f, 559.2f }, { 0.0f, 548.8f, 559.2f }, { 556.0f, 548.8f, 559.2f } } } },
    { "right_wall", GREEN, 1,
      { { { 0.0f, 0.0f, 559.2f }, { 0.0f, 0.0f, 0.0f }, { 0.0f, 548.8f, 0.0f }, { 0.0f, 548.8f, 559.2f } } } },
    { "left_wall", RED, 1,
      { { { 552.8f, 0.0f, 0.0f }, { 549.6f, 0.0f, 559.2f }, { 556.0f, 548.8f, 559.2f }, { 556.0f, 548.8f, 0.0f } } } },
    { "light", LIGHT, 1,
      { { { 343.0f, 548.8f - LIGHT_DROP_MM, 227.0f }, { 343.0f, 548.8f - LIGHT_DROP_MM, 332.0f },
          { 213.0f, 548.8f - LIGHT_DROP_MM, 332.0f }, { 213.0f, 548.8f - LIGHT_DROP_MM, 227.0f } } } },
};

static const part blocks[] = {
    { "short_block", WHITE, 6,
      { { { 130.0f, 165.0f, 65.0f }, { 82.0f, 165.0f, 225.0f }, { 240.0f, 165.0f, 272.0f }, { 290.0f, 165.0f, 114.0f } },
        { { 290.0f, 0.0f, 114.0f }, { 290.0f, 165.0f, 114.0f }, { 240.0f, 165.0f, 272.0f }, { 240.0f, 0.0f, 272.0f } },
        { { 130.0f, 0.0f, 65.0f }, { 130.0f, 165.0f, 65.0f }, { 290.0f, 165.0f, 114.0f }, { 290.0f, 0.0f, 114.0f } },
        { { 82.0f, 0.0f, 225.0f }, { 82.0f, 165.0f, 225.0f }, { 130.0f, 165.0f, 65.0f }, { 130.0f, 0.0f, 65.0f } },
        { { 240.0f, 0.0f, 272.0f }, { 240.0f, 165.0f, 272.0f }, { 82.0f, 165.0f, 225.0f }, { 82.0f, 0.0f, 225.0f } },
        { { 130.0f, 0.0f, 65.0f }, { 82.0f, 0.0f, 225.0f }, { 240.0f, 0.0f, 272.0f }, { 290.0f, 0.0f, 114.0f } } } },
    { "tall_block", WHITE, 6,
      { { { 423.0f, 330.0f, 247.0f }, { 265.0f, 330.0f, 296.0f }, { 314.0f, 330.0f, 456.0f }, { 472.0f, 330.0f, 406.0f } },
        { { 423.0f, 0.0f, 247.0f }, { 423.0f, 330.0f, 247.0f }, { 472.0f, 330.0f, 406.0f }, { 472.0f, 0.0f, 406.0f } },
        { { 472.0f, 0.0f, 406.0f }, { 472.0f, 330.0f, 406.0f }, { 314.0f, 330.0f, 456.0f }, { 314.0f, 0.0f, 456.0f } },
        { { 314.0f, 0.0f, 456.0f }, { 314.0f, 330.0f, 456.0f }, { 265.0f, 330.0f, 296.0f }, { 265.0f, 0.0f, 296.0f } },
        { { 265.0f, 0.0f, 296.0f }, { 265.0f, 330.0f, 296.0f }, { 423.0f, 330.0f, 247.0f }, { 423.0f, 0.0f, 247.0f } },
        { { 423.0f, 0.0f, 247.0f }, { 265.0f, 0.0f, 296.0f }, { 314.0f, 0.0f, 456.0f }, { 472.0f, 0.0f, 406.0f } } } },
};

static rl_vec3 mm(const float p[3]) { return rl_v3(p[0] * MM, p[1] * MM, p[2] * MM); }

/* The data's quads are not consistently wound; orient each by a point it
 * must face (box interior for walls, away from the block centre for blocks). */
static rl_status add_part(rl_scene *scene, const part *pt, const uint32_t *materials,
                          bool outward)
{
    rl_vec3 centre = rl_v3s(0.0f);
    for (int q = 0; q < pt->num_quads; ++q)
        for (int k = 0; k < 4; ++k)
            centre = rl_add(centre, rl_scale(mm(pt->quads[q][k]), 0.25f / (float)pt->num_quads));
    if (!outward)
        centre = rl_v3(0.278f, 0.2744f, 0.2796f);  /* middle of the box */
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = materials[pt->material];
    for (int q = 0; q < pt->num_quads; ++q) {
        rl_vec3 p[4];
        for (int k = 0; k < 4; ++k)
            p[k] = mm(pt->quads[q][k]);
        rl_vec3 n = rl_cross(rl_sub(p[1], p[0]), rl_sub(p[3], p[0]));
        float facing = rl_dot(n, rl_sub(centre, p[0]));
        if (outward ? facing > 0.0f : facing < 0.0f)
            rl_meshbuf_quad(&b, p[0], p[3], p[2], p[1], rl_v2(1.0f, 1.0f));
        else
            rl_meshbuf_quad(&b, p[0], p[1], p[2], p[3], rl_v2(1.0f, 1.0f));
    }
    uint32_t mesh;
    rl_status s = rl_meshbuf_add_to_scene(scene, &b, pt->name, &mesh);
    rl_meshbuf_free(&b);
    if (!s)
        s = rl_builtin_instance(scene, RL_NODE_ROOT, pt->name, mesh,
                                pt->material == LIGHT ? "light" : "box", NULL, NULL);
    return s;
}

enum { VARIANT_CLASSIC, VARIANT_BITTERLI, VARIANT_SHADE, NUM_VARIANTS };

static const part shade = {
    "shade", WHITE, 6,
    { { { 183.0f, 505.0f, 197.0f }, { 373.0f, 505.0f, 197.0f }, { 373.0f, 505.0f, 362.0f }, { 183.0f, 505.0f, 362.0f } },
      { { 183.0f, 500.0f, 197.0f }, { 373.0f, 500.0f, 197.0f }, { 373.0f, 500.0f, 362.0f }, { 183.0f, 500.0f, 362.0f } },
      { { 183.0f, 500.0f, 197.0f }, { 373.0f, 500.0f, 197.0f }, { 373.0f, 505.0f, 197.0f }, { 183.0f, 505.0f, 197.0f } },
      { { 183.0f, 500.0f, 362.0f }, { 373.0f, 500.0f, 362.0f }, { 373.0f, 505.0f, 362.0f }, { 183.0f, 505.0f, 362.0f } },
      { { 183.0f, 500.0f, 197.0f }, { 183.0f, 500.0f, 362.0f }, { 183.0f, 505.0f, 362.0f }, { 183.0f, 505.0f, 197.0f } },
      { { 373.0f, 500.0f, 197.0f }, { 373.0f, 500.0f, 362.0f }, { 373.0f, 505.0f, 362.0f }, { 373.0f, 505.0f, 197.0f } } },
};

/* Walls, light (mesh + quad light), camera: everything but the contents. */
static rl_status add_box(rl_scene *scene, int variant)
{
    static const char *const names[NUM_MATERIALS] = { "white", "red", "green", "light" };
    static const float colours[NUM_VARIANTS][NUM_MATERIALS][3] = {
        { { 0.73f, 0.73f, 0.73f }, { 0.65f, 0.05f, 0.05f }, { 0.12f, 0.45f, 0.15f }, { 0.78f, 0.78f, 0.78f } },
        { { 0.725f, 0.71f, 0.68f }, { 0.63f, 0.065f, 0.05f }, { 0.14f, 0.45f, 0.091f }, { 0.0f, 0.0f, 0.0f } },
        { { 0.73f, 0.73f, 0.73f }, { 0.65f, 0.05f, 0.05f }, { 0.12f, 0.45f, 0.15f }, { 0.78f, 0.78f, 0.78f } },
    };
    uint32_t materials[NUM_MATERIALS];
    rl_status s = RL_OK;
    for (int i = 0; i < NUM_MATERIALS && !s; ++i) {
        rl_material m = rl_material_default();
        snprintf(m.name, sizeof m.name, "%s", names[i]);
        const float *c = colours[variant][i];
        m.diffuse = rl_v3(c[0], c[1], c[2]);
        if (i == LIGHT)
            m.emission = rl_v3(17.0f, 12.0f, 4.0f);
        s = rl_scene_add_material(scene, &m, &materials[i]);
    }
    for (size_t i = 0; i < sizeof walls / sizeof walls[0] && !s; ++i)
        s = add_part(scene, &walls[i], materials, false);
    if (s)
        return s;

    const float y = (548.8f - LIGHT_DROP_MM) * MM;
    rl_light light = {
        .type = RL_LIGHT_QUAD,
        .color = rl_v3(1.0f, 12.0f / 17.0f, 4.0f / 17.0f),
        .intensity = 17.0f,
        .position = rl_v3(0.343f, y, 0.227f),
        .edge_u = rl_v3(0.0f, 0.0f, 0.105f),     /* cross(u, v) = -y: facing down */
        .edge_v = rl_v3(-0.130f, 0.0f, 0.0f),
    };
    if ((s = rl_scene_add_light(scene, &light)))
        return s;
    rl_camera cam = {
        .eye = rl_v3(0.278f, 0.273f, -0.800f),
        .target = rl_v3(0.278f, 0.273f, 0.0f),
        .up = rl_v3(0.0f, 1.0f, 0.0f),
        .fov_deg = 39.3f,
        .width = 512,
        .height = 512,
    };
    return rl_scene_add_camera(scene, "default", &cam);
}

static rl_status build_cornell(rl_scene *scene, const rl_option_store *params)
{
    int variant = rl_option_store_enum(params, "variant");
    rl_status s = add_box(scene, variant);
    if (!s && variant == VARIANT_BITTERLI)
        s = rl_scene_node_set_attr(scene, RL_NODE_ROOT, "max_path_length", "7");
    uint32_t white = rl_scene_find_material(scene, "white");
    uint32_t materials[NUM_MATERIALS] = { white, white, white, white };
    for (size_t i = 0; i < sizeof blocks / sizeof blocks[0] && !s; ++i)
        s = add_part(scene, &blocks[i], materials, true);
    if (!s && variant == VARIANT_SHADE)
        s = add_part(scene, &shade, materials, true);
    return s;
}

static rl_status build_cornell_teapot(rl_scene *scene, const rl_option_store *params)
{
    long long triangles = rl_option_store_int(params, "triangles");
    double size = rl_option_store_float(params, "size"), shininess = rl_option_store_float(params, "shininess"),
           rotate = rl_option_store_float(params, "rotate");
    rl_status s = add_box(scene, VARIANT_CLASSIC);
    if (s)
        return s;

    /* Slightly glossy: a weak Phong highlight and a faint mirror term. */
    rl_material m = rl_material_default();
    snprintf(m.name, sizeof m.name, "teapot");
    m.diffuse = rl_v3(0.60f, 0.62f, 0.68f);
    m.specular = rl_v3s(0.25f);
    m.shininess = (float)shininess;
    m.reflectivity = 0.05f;
    uint32_t material, mesh;
    if ((s = rl_scene_add_material(scene, &m, &material)))
        return s;
    rl_meshbuf b;
    rl_meshbuf_init(&b);
    b.material = material;
    rl_gen_teapot(&b, (uint32_t)triangles, (float)size);
    s = rl_meshbuf_add_to_scene(scene, &b, "teapot", &mesh);
    rl_meshbuf_free(&b);
    /* On the floor, in the middle of the box, turned so the spout shows. */
    rl_mat4 t = rl_mat4_translate(rl_v3(0.278f, 0.0f, 0.28f));
    rl_mat4 r = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), rl_radians((float)rotate));
    rl_mat4 world = rl_mat4_mul(&t, &r);
    if (!s)
        s = rl_builtin_instance(scene, RL_NODE_ROOT, "teapot", mesh, "teapot", &world, NULL);
    return s;
}

static const char *const variant_names[] = { "classic", "bitterli", "shade", NULL };
static const rl_option_info cornell_options[] = {
    { "variant", RL_OPT_ENUM, "classic",
      "classic (the usual RGB fits, a lamp of albedo 0.78) or bitterli (Bitterli's cornell-box albedos, a "
      "black lamp, max_path_length 7) or shade (classic with a plate under the lamp: lit by bounces)", 0, 0,
      variant_names },
};

const rl_builtin_class rl_builtin_cornell_class = {
    { "cornell",
      "Cornell box from the Cornell measured data (metres): 5 walls, short and tall block, ceiling quad light; "
      "36 triangles",
      RL_BUILTIN_OPTIONS(cornell_options) },
    build_cornell,
};

_Static_assert(RL_TEAPOT_DEFAULT_TRIANGLES == 15704, "the table's default is the teapot's");
static const rl_option_info teapot_options[] = {
    { "triangles", RL_OPT_INT, "15704", "teapot triangles (the closest patch grid is used)", 1,
      RL_TEAPOT_MAX_TRIANGLES, NULL },
    { "size", RL_OPT_FLOAT, "0.2", "teapot height, m", 0.01, 0.5, NULL },
    { "shininess", RL_OPT_FLOAT, "64", "Phong exponent of the teapot", 0, 1e4, NULL },
    { "rotate", RL_OPT_FLOAT, "-30", "turn about y, degrees", -360, 360, NULL },
};

const rl_builtin_class rl_builtin_cornell_teapot_class = {
    { "cornell-teapot", "Cornell box without the blocks, a slightly glossy Utah teapot on the floor",
      RL_BUILTIN_OPTIONS(teapot_options) },
    build_cornell_teapot,
};
