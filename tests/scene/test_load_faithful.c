/* test_load_faithful.c: what a model file means, imported as its format
 * defines it (issue 33): camera angles per format, Collada's reflective and
 * transparent terms, glTF metallic-roughness, light attenuation, texture
 * references that do not match as written, the model-file parameters
 * (cameras, lights, headlight, orbit) and one warning per file.
 *
 * Files written here are exact oracles; the assimp test models (Debian
 * assimp-testmodels, installed by make check) check the formats we cannot
 * write by hand (FBX) against values read from their text. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "rl/rl_accel.h"
#include "rl/rl_image.h"
#include "rl/rl_scene.h"
#include "scene/load_fixtures.h"

#define MODELS "/usr/share/assimp/models"
#define PI 3.14159265358979323846

static const char *dir_for(const char *sub, char *out, size_t size)
{
    return fx_dir("faithful", sub, out, size);
}

#define write_text fx_write_text
#define base64 fx_base64

static bool have(const char *path)
{
    struct stat st;
    if (stat(path, &st) == 0)
        return true;
    print_message("%s missing (Debian package assimp-testmodels); check skipped\n", path);
    return false;
}

/* Warnings captured while a test runs. */
static int warnings;
static char last_warning[1024];
static void count_warnings(void *user, rl_log_level level, const char *message)
{
    (void)user;
    if (level == RL_LOG_WARN) {
        ++warnings;
        snprintf(last_warning, sizeof last_warning, "%s", message);
    }
}

/* A Collada 1.4.1 file: one triangle under a node, a material with the
 * given <phong> body, and a camera with the given <perspective> body. */
static const char *write_dae(const char *dir, const char *name, const char *phong,
                             const char *perspective, char *out, size_t size)
{
    char text[8192];
    snprintf(text, sizeof text,
             "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n"
             "<COLLADA xmlns=\"http://www.collada.org/2005/11/COLLADASchema\" version=\"1.4.1\">\n"
             " <asset><up_axis>Y_UP</up_axis></asset>\n"
             " <library_cameras><camera id=\"cam\" name=\"cam\"><optics><technique_common>\n"
             "  <perspective>%s<znear>0.1</znear><zfar>100</zfar></perspective>\n"
             " </technique_common></optics></camera></library_cameras>\n"
             " <library_effects><effect id=\"fx\"><profile_COMMON><technique sid=\"t\">\n"
             "  <phong>%s</phong>\n"
             " </technique></profile_COMMON></effect></library_effects>\n"
             " <library_materials><material id=\"mat\" name=\"mat\"><instance_effect url=\"#fx\"/>"
             "</material></library_materials>\n"
             " <library_geometries><geometry id=\"tri\"><mesh>\n"
             "  <source id=\"p\"><float_array id=\"pa\" count=\"9\">0 0 0 1 0 0 0 1 0</float_array>\n"
             "   <technique_common><accessor source=\"#pa\" count=\"3\" stride=\"3\">\n"
             "    <param name=\"X\" type=\"float\"/><param name=\"Y\" type=\"float\"/>"
             "<param name=\"Z\" type=\"float\"/>\n"
             "   </accessor></technique_common></source>\n"
             "  <vertices id=\"v\"><input semantic=\"POSITION\" source=\"#p\"/></vertices>\n"
             "  <triangles material=\"m\" count=\"1\"><input semantic=\"VERTEX\" source=\"#v\" offset=\"0\"/>"
             "<p>0 1 2</p></triangles>\n"
             " </mesh></geometry></library_geometries>\n"
             " <library_visual_scenes><visual_scene id=\"s\">\n"
             "  <node id=\"n\" name=\"n\"><instance_geometry url=\"#tri\"><bind_material><technique_common>"
             "<instance_material symbol=\"m\" target=\"#mat\"/></technique_common></bind_material>"
             "</instance_geometry></node>\n"
             "  <node id=\"c\" name=\"c\"><translate>0 0 5</translate><instance_camera url=\"#cam\"/></node>\n"
             " </visual_scene></library_visual_scenes>\n"
             " <scene><instance_visual_scene url=\"#s\"/></scene>\n"
             "</COLLADA>\n",
             perspective, phong);
    return write_text(dir, name, text, out, size);
}

static rl_scene *load(const char *path, const char *params)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_load(path, params, &s);
    if (st != RL_OK)
        fail_msg("%s: %s", path, rl_last_error());
    return s;
}

static const rl_material *first_material(const rl_scene *s)
{
    const rl_scene_data *d = rl_scene_get_data(s);
    return &d->materials[d->triangle_material[0]];
}

static const char *white_phong =
    "<diffuse><color>0.5 0.5 0.5 1</color></diffuse>";

/* Collada: yfov and xfov are full angles in degrees (COLLADA 1.4.1,
 * <perspective>); the camera keeps the vertical one and the file's aspect. */
static void test_collada_camera_angles_are_full_angles(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("dae_fov", dir, sizeof dir);
    rl_scene *s = load(write_dae(dir, "y.dae", white_phong,
                                 "<yfov>40</yfov><aspect_ratio>1.5</aspect_ratio>", path,
                                 sizeof path), NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_cameras, 1);
    assert_true(fabsf(d->cameras[0].fov_deg - 40.0f) < 0.01f);
    assert_int_equal(d->cameras[0].width, RL_CAMERA_DEFAULT_HEIGHT * 3 / 2);
    assert_int_equal(d->cameras[0].height, RL_CAMERA_DEFAULT_HEIGHT);
    assert_true(fabsf(d->cameras[0].eye.z - 5.0f) < 1e-5f);
    rl_scene_release(s);

    /* xfov 60 at aspect 2: vertical = 2 atan(tan(30 deg) / 2). */
    s = load(write_dae(dir, "x.dae", white_phong, "<xfov>60</xfov><aspect_ratio>2</aspect_ratio>",
                       path, sizeof path), NULL);
    float want = (float)(2.0 * atan(tan(30.0 * PI / 180.0) / 2.0) * 180.0 / PI);
    assert_true(fabsf(rl_scene_get_data(s)->cameras[0].fov_deg - want) < 0.01f);
    rl_scene_release(s);

    /* The duck of the test models: yfov 37.8492 in its text. */
    if (have(MODELS "/Collada/duck.dae")) {
        s = load(MODELS "/Collada/duck.dae", NULL);
        assert_true(fabsf(rl_scene_get_data(s)->cameras[0].fov_deg - 37.8492f) < 0.01f);
        rl_scene_release(s);
    }
}

/* Collada's mirror term is reflectivity x reflective colour; a black
 * reflective colour is no mirror, whatever the reflectivity
 * (teapots.DAE rendered black as mirrors of black). */
static void test_collada_reflective_colour_scales_reflectivity(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("dae_mat", dir, sizeof dir);
    const char *persp = "<yfov>40</yfov><aspect_ratio>1</aspect_ratio>";
    rl_scene *s = load(write_dae(dir, "black.dae",
                                 "<diffuse><color>0.5 0.5 0.5 1</color></diffuse>"
                                 "<reflective><color>0 0 0 1</color></reflective>"
                                 "<reflectivity><float>1</float></reflectivity>",
                                 persp, path, sizeof path), NULL);
    assert_true(first_material(s)->reflectivity == 0.0f);
    assert_true(first_material(s)->transmissivity == 0.0f);
    rl_scene_release(s);

    s = load(write_dae(dir, "grey.dae",
                       "<diffuse><color>0.5 0.5 0.5 1</color></diffuse>"
                       "<reflective><color>0.5 0.5 0.5 1</color></reflective>"
                       "<reflectivity><float>0.8</float></reflectivity>",
                       persp, path, sizeof path), NULL);
    assert_true(fabsf(first_material(s)->reflectivity - 0.4f) < 1e-4f);
    rl_scene_release(s);

    /* Transparency 0.25 in the default A_ONE mode: opacity 0.25 x alpha 1,
     * so 75 % is transmitted. */
    s = load(write_dae(dir, "glass.dae",
                       "<diffuse><color>0.5 0.5 0.5 1</color></diffuse>"
                       "<transparent><color>1 1 1 1</color></transparent>"
                       "<transparency><float>0.25</float></transparency>"
                       "<index_of_refraction><float>1.5</float></index_of_refraction>",
                       persp, path, sizeof path), NULL);
    assert_true(fabsf(first_material(s)->transmissivity - 0.75f) < 1e-4f);
    assert_true(fabsf(first_material(s)->ior - 1.5f) < 1e-4f);
    rl_scene_release(s);

    /* Fully transparent, reflecting nothing: invisible, which in files is an
     * exporter's inverted transparency; taken as opaque with a warning. */
    warnings = 0;
    rl_log_set_callback(count_warnings, NULL);
    s = load(write_dae(dir, "inverted.dae",
                       "<diffuse><color>0.5 0.5 0.5 1</color></diffuse>"
                       "<transparent><color>1 1 1 1</color></transparent>"
                       "<transparency><float>0</float></transparency>",
                       persp, path, sizeof path), NULL);
    rl_log_set_callback(NULL, NULL);
    assert_true(first_material(s)->transmissivity == 0.0f);
    assert_int_equal(warnings, 1);
    assert_non_null(strstr(last_warning, "opacity 0 taken as opaque"));
    rl_scene_release(s);
}

/* glTF 2.0 metallic-roughness onto Phong (load_assimp.c, map_metal_roughness). */
static void test_gltf_metal_roughness_maps_onto_phong(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("gltf_pbr", dir, sizeof dir);
    /* One triangle, positions as a base64 data URI: 0 0 0, 1 0 0, 0 1 0. */
    const char *fmt =
        "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
        " \"nodes\": [{\"mesh\": 0}],"
        " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}],"
        " \"materials\": [{\"pbrMetallicRoughness\": {\"baseColorFactor\": [0.9, 0.6, 0.2, 1],"
        "   \"metallicFactor\": %s, \"roughnessFactor\": %s}}],"
        " \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,"
        "AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA\"}],"
        " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],"
        " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3,"
        "   \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}]}";
    char text[2048];

    /* A rough dielectric: diffuse = base, F0 = 0.04, a wide lobe, no mirror. */
    snprintf(text, sizeof text, fmt, "0", "1");
    rl_scene *s = load(write_text(dir, "plastic.gltf", text, path, sizeof path), NULL);
    const rl_material *m = first_material(s);
    assert_true(fabsf(m->diffuse.x - 0.9f) < 1e-4f && fabsf(m->diffuse.z - 0.2f) < 1e-4f);
    assert_true(fabsf(m->specular.y - 0.04f) < 1e-4f);
    assert_true(m->shininess == 1.0f);   /* 2/1 - 2 = 0, clamped to 1 */
    assert_true(m->reflectivity == 0.0f);
    rl_scene_release(s);

    /* A smooth metal: no diffuse, F0 = base, a narrow lobe and a mirror. */
    snprintf(text, sizeof text, fmt, "1", "0.1");
    s = load(write_text(dir, "gold.gltf", text, path, sizeof path), NULL);
    m = first_material(s);
    assert_true(m->diffuse.x == 0.0f && m->diffuse.y == 0.0f);
    assert_true(fabsf(m->specular.x - 0.9f) < 1e-4f && fabsf(m->specular.y - 0.6f) < 1e-4f);
    /* alpha = 0.01: n = 2 / 1e-4 - 2, clamped to 1e4. */
    assert_true(m->shininess == 1e4f);
    assert_true(m->reflectivity > 0.0f && m->reflectivity < 1.0f);
    assert_true(m->bsdf == RL_BSDF_PHONG);
    rl_scene_release(s);

    /* materials=ggx (issue 37): the file's values for pt's microfacet BRDF. */
    s = load(path, "materials=ggx");
    m = first_material(s);
    assert_true(m->bsdf == RL_BSDF_GGX);
    assert_true(fabsf(m->diffuse.x - 0.9f) < 1e-4f && fabsf(m->diffuse.y - 0.6f) < 1e-4f);
    assert_true(m->metallic == 1.0f && fabsf(m->roughness - 0.1f) < 1e-6f);
    assert_true(m->reflectivity == 0.0f);
    rl_scene_release(s);
}

/* Texture references that do not resolve as written: other letter case
 * beside the model, or an author's absolute path whose file name sits
 * beside it. */
static void test_texture_references_fall_back_to_case_and_file_name(void **state)
{
    (void)state;
    char dir[1100], path[1200], png[1200];
    dir_for("tex_case", dir, sizeof dir);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(1, 1, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = rl_v4(0, 1, 0, 1);
    snprintf(png, sizeof png, "%s/wood.png", dir);
    assert_int_equal(rl_image_write_png(img, png), RL_OK);
    rl_image_release(img);
    const char *obj = "mtllib m.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                      "f 1/1 2/2 3/3\n";
    const char *mtls[] = { "newmtl a\nKd 1 1 1\nmap_Kd WOOD.PNG\n",
                           "newmtl a\nKd 1 1 1\nmap_Kd C:\\\\art\\\\Wood.png\n" };
    for (int k = 0; k < 2; ++k) {
        write_text(dir, "m.mtl", mtls[k], path, sizeof path);
        write_text(dir, "model.obj", obj, path, sizeof path);
        warnings = 0;
        rl_log_set_callback(count_warnings, NULL);
        rl_scene *s = load(path, NULL);
        rl_log_set_callback(NULL, NULL);
        const rl_scene_data *d = rl_scene_get_data(s);
        assert_int_equal(d->num_textures, 1);
        assert_int_equal(first_material(s)->diffuse_texture, 0);
        assert_int_equal(warnings, 1);
        assert_non_null(strstr(last_warning, "wood.png"));
        rl_scene_release(s);
    }
    /* The 3DS test model asks for TEST.PNG; test.png sits beside it. */
    if (have(MODELS "/3DS/cube_with_diffuse_texture.3DS")) {
        rl_scene *s = load(MODELS "/3DS/cube_with_diffuse_texture.3DS", NULL);
        assert_int_equal(rl_scene_get_data(s)->num_textures, 1);
        rl_scene_release(s);
    }
}

/* FBX (not written by hand): spider.fbx's camera has FieldOfView 49.13
 * horizontal at aspect 16:9, its lamp a quadratic-only falloff q. */
static void test_fbx_camera_angle_and_light_falloff(void **state)
{
    (void)state;
    if (!have(MODELS "/FBX/spider.fbx"))
        return;
    rl_scene *s = load(MODELS "/FBX/spider.fbx", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_cameras, 1);
    float want = (float)(2.0 * atan(tan(0.5 * 0.857556) / (16.0 / 9.0)) * 180.0 / PI);
    assert_true(fabsf(d->cameras[0].fov_deg - want) < 0.01f);
    /* The lamp: 1 / (q d^2) with q = 2.2222e-7 equals ours at intensity 1/q. */
    assert_int_equal(d->num_lights, 1);
    assert_true(fabsf(d->lights[0].intensity * 2.22222e-7f - 1.0f) < 1e-3f);
    rl_scene_release(s);
}

/* The model-file parameters: cameras, lights, headlight, orbit. */
static void test_model_parameters(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("params", dir, sizeof dir);
    write_dae(dir, "tri.dae", white_phong, "<yfov>40</yfov><aspect_ratio>1</aspect_ratio>", path,
              sizeof path);
    rl_scene *s = load(path, NULL);
    assert_int_equal(rl_scene_get_data(s)->num_cameras, 1);
    assert_int_equal(rl_scene_get_data(s)->num_lights, 2);   /* no lights: the default pair */
    rl_scene_release(s);

    s = load(path, "cameras=off,headlight=true,azimuth=0,elevation=0");
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_cameras, 0);
    assert_int_equal(d->num_lights, 3);
    /* The headlight sits at the framing camera's eye: straight in front (+z)
     * of the triangle in z = 0, centred on it. */
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    const rl_light *head = &d->lights[2];
    assert_int_equal(head->type, RL_LIGHT_POINT);
    assert_true(fabsf(head->position.x - cam.eye.x) < 1e-4f && fabsf(head->position.z - cam.eye.z) < 1e-3f);
    assert_true(cam.eye.z > 0.0f && fabsf(cam.eye.x - cam.target.x) < 1e-4f);
    rl_scene_release(s);

    /* The file's lights: kept, dropped for the defaults, or both. */
    if (have(MODELS "/FBX/spider.fbx")) {
        s = load(MODELS "/FBX/spider.fbx", "lights=off");
        assert_int_equal(rl_scene_get_data(s)->num_lights, 2);
        rl_scene_release(s);
        s = load(MODELS "/FBX/spider.fbx", "lights=add");
        assert_int_equal(rl_scene_get_data(s)->num_lights, 3);
        rl_scene_release(s);
    }

    /* Bad values and keys are errors before the file is read. */
    rl_scene *bad = NULL;
    assert_int_equal(rl_scene_load(path, "lights=some", &bad), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_load(path, "elevation=90", &bad), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_scene_load(path, "headlite=true", &bad), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "headlight"));
    assert_null(bad);
    rl_clear_error();
}

/* Drops are reported once per file, not once per mesh. */
static void test_one_warning_per_file(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("warn", dir, sizeof dir);
    /* Three objects, each with one degenerate triangle beside a good one. */
    write_text(dir, "three.obj",
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\n"
               "o a\nf 1 2 3\nf 1 2 4\no b\nf 1 2 3\nf 1 2 4\no c\nf 1 2 3\nf 1 2 4\n",
               path, sizeof path);
    warnings = 0;
    rl_log_set_callback(count_warnings, NULL);
    rl_scene *s = load(path, NULL);
    rl_log_set_callback(NULL, NULL);
    assert_int_equal(warnings, 1);
    assert_non_null(strstr(last_warning, "dropped 3 degenerate and 0 non-finite triangles in 3 meshes"));
    rl_scene_release(s);
}


/* A glTF quad (-1..1)^2 in z = 0 whose base colour texture is transparent
 * on its left half (alphaMode MASK), with a normal map that tilts every
 * normal to the tangent +x (+u). Rays through the left half pass; the
 * bent normal follows the map. */
static void test_gltf_alpha_mask_and_normal_map(void **state)
{
    (void)state;
    char dir[1100], path[1200], png[1200];
    dir_for("gltf_mask", dir, sizeof dir);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 1, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = rl_v4(1, 1, 1, 0);
    img->color[1] = rl_v4(1, 1, 1, 1);
    snprintf(png, sizeof png, "%s/mask.png", dir);
    assert_int_equal(rl_image_write_png(img, png), RL_OK);
    /* Raw bytes (255, 128, 128) after the PNG's sRGB encoding. */
    img->width = 1;
    img->color[0] = rl_v4(1.0f, rl_srgb_to_linear(128.0f / 255.0f), rl_srgb_to_linear(128.0f / 255.0f), 1);
    snprintf(png, sizeof png, "%s/bump.png", dir);
    assert_int_equal(rl_image_write_png(img, png), RL_OK);
    rl_image_release(img);

    struct { float pos[12]; float uv[8]; uint16_t idx[6]; } buf = {
        { -1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0 },
        { 0, 1, 1, 1, 1, 0, 0, 0 },   /* glTF's v runs down the picture */
        { 0, 1, 2, 0, 2, 3 },
    };
    char b64[256], text[4096];
    base64((const unsigned char *)&buf, sizeof buf, b64);
    snprintf(text, sizeof text,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
             " \"nodes\": [{\"mesh\": 0}],"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0, \"TEXCOORD_0\": 1},"
             "   \"indices\": 2, \"material\": 0}]}],"
             " \"materials\": [{\"alphaMode\": \"MASK\", \"alphaCutoff\": 0.5,"
             "   \"pbrMetallicRoughness\": {\"baseColorTexture\": {\"index\": 0}},"
             "   \"normalTexture\": {\"index\": 1}}],"
             " \"textures\": [{\"source\": 0}, {\"source\": 1}],"
             " \"images\": [{\"uri\": \"mask.png\"}, {\"uri\": \"bump.png\"}],"
             " \"buffers\": [{\"byteLength\": %zu, \"uri\": \"data:application/octet-stream;base64,%s\"}],"
             " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 48},"
             "   {\"buffer\": 0, \"byteOffset\": 48, \"byteLength\": 32},"
             "   {\"buffer\": 0, \"byteOffset\": 80, \"byteLength\": 12}],"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC3\","
             "   \"min\": [-1, -1, 0], \"max\": [1, 1, 0]},"
             "  {\"bufferView\": 1, \"componentType\": 5126, \"count\": 4, \"type\": \"VEC2\"},"
             "  {\"bufferView\": 2, \"componentType\": 5123, \"count\": 6, \"type\": \"SCALAR\"}]}",
             sizeof buf, b64);
    rl_scene *s = load(write_text(dir, "leaf.gltf", text, path, sizeof path), NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_material *m = first_material(s);
    assert_true(fabsf(m->alpha_cutoff - 0.5f) < 1e-6f);
    assert_int_not_equal(m->normal_texture, RL_NONE);

    const rl_accel_kind kinds[] = { RL_ACCEL_BVH, RL_ACCEL_GRID, RL_ACCEL_BRUTE };
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; ++k) {
        rl_accel *a = NULL;
        assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = kinds[k] }, &a), RL_OK);
        assert_int_equal(rl_accel_commit(a), RL_OK);
        for (int side = 0; side < 2; ++side) {
            float x = side ? 0.5f : -0.5f;   /* u = 0.75 opaque, u = 0.25 a hole */
            rl_ray r = { rl_v3(x, 0.1f, 5.0f), 0.0f, rl_v3(0, 0, -1), INFINITY };
            rl_hit h;
            assert_int_equal(rl_accel_intersect(a, &r, &h), side == 1);
            assert_int_equal(rl_accel_occluded(a, &(rl_ray){ rl_v3(x, 0.1f, 5.0f), 0.0f,
                                                             rl_v3(0, 0, -1), 10.0f }), side == 1);
            if (side == 1) {
                /* The map's (1, 0, 0) in the frame (T = +x, B, N = +z). */
                rl_vec2 uv = rl_v2(0.75f, 0.45f);
                rl_vec3 n = rl_shading_normal(d, h.triangle, rl_v3(0, 0, 1), uv);
                assert_true(n.x > 0.99f && fabsf(rl_length(n) - 1.0f) < 1e-5f);
            }
        }
        rl_accel_release(a);
    }
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_collada_camera_angles_are_full_angles),
        cmocka_unit_test(test_collada_reflective_colour_scales_reflectivity),
        cmocka_unit_test(test_gltf_metal_roughness_maps_onto_phong),
        cmocka_unit_test(test_texture_references_fall_back_to_case_and_file_name),
        cmocka_unit_test(test_fbx_camera_angle_and_light_falloff),
        cmocka_unit_test(test_model_parameters),
        cmocka_unit_test(test_one_warning_per_file),
        cmocka_unit_test(test_gltf_alpha_mask_and_normal_map),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
