/* test_load_json.c: the JSON scene format (docs/scene-format.md) and
 * rl_scene_load's choice between JSON, Assimp and built-in scenes. Scene
 * files are written into $RL_TEST_TMP by the tests; bad input is checked by
 * status code, and positions by the "file:line:col" in rl_last_error(). */
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

#include "rl/rl_scene.h"

static char dir[1024];

static int setup(void **state)
{
    (void)state;
    const char *base = getenv("RL_TEST_TMP");
    snprintf(dir, sizeof dir, "%s/json", base && base[0] ? base : ".");
    mkdir(dir, 0777);
    char models[1100];
    snprintf(models, sizeof models, "%s/models", dir);
    mkdir(models, 0777);
    return 0;
}

static const char *write_file(const char *name, const char *text)
{
    static char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, strlen(text), f), strlen(text));
    assert_int_equal(fclose(f), 0);
    return path;
}

/* Loads text as name; returns the status and checks that failures leave
 * *out alone. */
static rl_status load_text(const char *name, const char *text, rl_scene **out)
{
    rl_clear_error();
    rl_scene *s = NULL;
    rl_status st = rl_scene_load_json(write_file(name, text), &s);
    if (st != RL_OK)
        assert_null(s);
    *out = s;
    return st;
}

static void expect_error(const char *name, const char *text, rl_status want, const char *part)
{
    rl_scene *s = NULL;
    rl_status st = load_text(name, text, &s);
    if (st != want || (part && !strstr(rl_last_error(), part)))
        print_error("%s: status %d, message: %s\n", name, (int)st, rl_last_error());
    assert_int_equal(st, want);
    if (part)
        assert_non_null(strstr(rl_last_error(), part));
    rl_scene_release(s);
}

static const rl_object *object_named(const rl_scene_data *d, const char *name)
{
    for (uint32_t i = 0; i < d->num_objects; ++i)
        if (strcmp(d->objects[i].name, name) == 0)
            return &d->objects[i];
    for (uint32_t i = 0; i < d->num_objects; ++i)
        print_error("object %u: %s\n", i, d->objects[i].name);
    fail_msg("no object \"%s\"", name);
    return NULL;
}

/* The first object whose node lies below the node called name. */
static const rl_object *object_below(const rl_scene *s, const rl_scene_data *d, const char *name)
{
    uint32_t ancestor = rl_scene_find_node(s, name);
    for (uint32_t i = 0; i < d->num_objects; ++i)
        for (uint32_t n = d->objects[i].node; n != RL_NONE; n = rl_scene_node_parent(s, n))
            if (n == ancestor)
                return &d->objects[i];
    fail_msg("no object below \"%s\"", name);
    return NULL;
}

static bool near(float a, float b) { return fabsf(a - b) < 1e-4f; }

static const char full_scene[] =
    "{\n"
    "  \"name\": \"demo\",\n"
    "  \"materials\": {\n"
    "    \"red\": {\"diffuse\": [0.8, 0.1, 0.1], \"specular\": 0.2, \"shininess\": 40},\n"
    "    \"mirror\": {\"base\": \"red\", \"reflectivity\": 0.9},\n"
    "    \"glow\": {\"diffuse\": 0, \"emission\": [5, 5, 5]}\n"
    "  },\n"
    "  \"lights\": [\n"
    "    {\"type\": \"point\", \"position\": [0, 5, 0], \"intensity\": 10},\n"
    "    {\"type\": \"spot\", \"position\": [0, 5, 0], \"direction\": [0, -2, 0],\n"
    "     \"inner_deg\": 10, \"outer_deg\": 20},\n"
    "    {\"type\": \"directional\", \"direction\": [0, -1, 0], \"color\": [1, 0.9, 0.8]},\n"
    "    {\"type\": \"quad\", \"position\": [-0.5, 4, -0.5], \"edge_u\": [1, 0, 0],\n"
    "     \"edge_v\": [0, 0, 1]}\n"
    "  ],\n"
    "  \"cameras\": [\n"
    "    {\"name\": \"front\", \"eye\": [0, 1, 5], \"target\": [0, 0, 0], \"fov_deg\": 60,\n"
    "     \"size\": [320, 240]},\n"
    "    {\"eye\": [5, 5, 5], \"target\": [0, 0, 0]}\n"
    "  ],\n"
    "  \"camera_path\": {\"keys\": [\n"
    "    {\"time_s\": 0, \"eye\": [0, 1, 5], \"target\": [0, 0, 0]},\n"
    "    {\"time_s\": 2, \"eye\": [5, 1, 0], \"target\": [0, 0, 0], \"fov_deg\": 50}\n"
    "  ]},\n"
    "  \"objects\": [\n"
    "    {\"name\": \"floor\", \"generator\": \"quad\", \"params\": {\"sx\": 10, \"sz\": 10},\n"
    "     \"material\": \"red\"},\n"
    "    {\"name\": \"group\", \"transform\": {\"translate\": [0, 1, 0]},\n"
    "     \"attributes\": {\"vt\": true, \"lod\": 2, \"tag\": \"x\"},\n"
    "     \"children\": [\n"
    "       {\"name\": \"ball\", \"generator\": \"sphere\",\n"
    "        \"params\": {\"radius\": 0.5, \"segments\": 8, \"rings\": 4},\n"
    "        \"transform\": {\"translate\": [2, 0, 0], \"scale\": 2},\n"
    "        \"material\": {\"base\": \"mirror\", \"diffuse\": [0, 0, 1]}},\n"
    "       {\"name\": \"model\", \"file\": \"models/tri.obj\",\n"
    "        \"transform\": {\"rotate_deg\": [0, 90, 0]}, \"material\": \"glow\"}\n"
    "     ]}\n"
    "  ]\n"
    "}\n";

static void test_full_scene_loads_every_section(void **state)
{
    (void)state;
    write_file("models/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    rl_scene *s = NULL;
    assert_int_equal(load_text("full.json", full_scene, &s), RL_OK);
    assert_true(rl_scene_is_committed(s));
    assert_string_equal(rl_scene_name(s), "demo");
    assert_string_equal(rl_scene_base_dir(s), dir);
    const rl_scene_data *d = rl_scene_get_data(s);

    /* Materials: "mirror" starts from "red". */
    const rl_material *mirror = &d->materials[rl_scene_find_material(s, "mirror")];
    assert_true(near(mirror->diffuse.x, 0.8f) && near(mirror->reflectivity, 0.9f));
    assert_true(near(mirror->specular.y, 0.2f) && near(mirror->shininess, 40.0f));

    /* Lights, in file order, with normalised directions and defaults. */
    assert_int_equal(d->num_lights, 4);
    assert_int_equal(d->lights[0].type, RL_LIGHT_POINT);
    assert_true(near(d->lights[0].intensity, 10.0f) && near(d->lights[0].color.x, 1.0f));
    assert_int_equal(d->lights[1].type, RL_LIGHT_SPOT);
    assert_true(near(d->lights[1].direction.y, -1.0f) && near(d->lights[1].spot_outer_deg, 20.0f));
    assert_int_equal(d->lights[2].type, RL_LIGHT_DIRECTIONAL);
    assert_true(near(d->lights[2].color.z, 0.8f));
    assert_int_equal(d->lights[3].type, RL_LIGHT_QUAD);
    assert_true(near(d->lights[3].edge_v.z, 1.0f));

    /* Cameras: named and default-named, and the path. */
    assert_int_equal(d->num_cameras, 2);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, "front", &cam), RL_OK);
    assert_int_equal(cam.width, 320);
    assert_int_equal(cam.height, 240);
    assert_true(near(cam.fov_deg, 60.0f));
    assert_int_equal(rl_scene_get_camera(s, "camera1", &cam), RL_OK);
    assert_true(near(cam.eye.x, 5.0f));
    assert_non_null(d->camera_path);
    assert_int_equal(rl_camera_path_key_count(d->camera_path), 2);
    assert_true(fabs(rl_camera_path_duration(d->camera_path) - 2.0) < 1e-9);

    /* Objects: generator with params, nested transforms, a file, overrides. */
    assert_int_equal(d->num_objects, 3);
    const rl_object *floor_obj = object_named(d, "floor");
    assert_true(near(floor_obj->bounds.min.x, -5.0f) && near(floor_obj->bounds.max.z, 5.0f));
    assert_int_equal(d->triangle_material[floor_obj->first_triangle],
                     rl_scene_find_material(s, "red"));
    const rl_object *ball = object_named(d, "ball");
    /* radius 0.5 scaled by 2, at (0,1,0) + (2,0,0); the poles are exact. */
    assert_true(near(ball->bounds.min.y, 0.0f) && near(ball->bounds.max.y, 2.0f));
    assert_true(near(ball->bounds.max.x, 3.0f) && near(ball->bounds.min.x, 1.0f));
    const rl_material *inline_m = &d->materials[d->triangle_material[ball->first_triangle]];
    assert_true(near(inline_m->diffuse.z, 1.0f) && near(inline_m->reflectivity, 0.9f));
    const rl_object *model = object_below(s, d, "model");
    assert_int_equal(model->num_triangles, 1);
    /* rotate_deg y = 90 maps (1,0,0) to (0,0,-1); then up by 1. */
    assert_true(near(model->bounds.min.z, -1.0f) && near(model->bounds.max.z, 0.0f));
    assert_true(near(model->bounds.min.y, 1.0f) && near(model->bounds.max.y, 2.0f));
    assert_true(near(model->bounds.max.x, 0.0f));
    assert_string_equal(d->materials[d->triangle_material[model->first_triangle]].name, "glow");

    uint32_t group = rl_scene_find_node(s, "group");
    assert_int_not_equal(group, RL_NONE);
    assert_string_equal(rl_scene_node_attr(s, group, "vt"), "true");
    assert_string_equal(rl_scene_node_attr(s, group, "lod"), "2");
    assert_string_equal(rl_scene_node_attr(s, group, "tag"), "x");
    rl_scene_release(s);
}

static void test_base_builtin_scene_is_extended(void **state)
{
    (void)state;
    rl_scene *plain = NULL, *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &plain), RL_OK);
    const rl_scene_data *p = rl_scene_get_data(plain);
    assert_int_equal(load_text("based.json",
                               "{\"base\": \"cornell\",\n"
                               " \"materials\": {\"white\": {\"diffuse\": [0.5, 0.5, 0.5]}},\n"
                               " \"objects\": [{\"generator\": \"box\", \"params\": {\"size\": 0.1},\n"
                               "   \"transform\": {\"translate\": [0.3, 0.05, 0.3]}}]}\n",
                               &s),
                     RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_string_equal(rl_scene_name(s), "based");
    assert_int_equal(d->num_triangles, p->num_triangles + 12);
    assert_int_equal(d->num_objects, p->num_objects + 1);
    assert_int_equal(d->num_lights, p->num_lights);
    assert_int_equal(d->num_cameras, p->num_cameras);
    /* The base's "white" is restyled in place, not duplicated. */
    assert_int_equal(rl_scene_find_material(s, "white"), rl_scene_find_material(plain, "white"));
    assert_true(near(d->materials[rl_scene_find_material(s, "white")].diffuse.x, 0.5f));
    /* The base's geometry is unchanged. */
    for (uint32_t v = 0; v < p->num_vertices; ++v)
        assert_memory_equal(&d->positions[v], &p->positions[v], sizeof(rl_vec3));
    rl_scene_release(s);
    rl_scene_release(plain);

    expect_error("bad_base.json", "{\"base\": \"moon\"}", RL_ERR_PARSE, "bad_base.json:1:");
    expect_error("base_params.json", "{\"base\": \"cornell\", \"params\": {\"bounces\": 2}}",
                 RL_ERR_PARSE, "base_params.json:1:");
}

static void test_transform_matrix_and_axis_rotation(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(
        load_text("matrix.json",
                  "{\"objects\": [\n"
                  " {\"name\": \"m\", \"generator\": \"box\",\n"
                  "  \"transform\": {\"matrix\": [2,0,0,10, 0,1,0,0, 0,0,1,0, 0,0,0,1]}},\n"
                  " {\"name\": \"r\", \"generator\": \"quad\", \"params\": {\"sx\": 2, \"sz\": 1},\n"
                  "  \"transform\": {\"rotate\": {\"axis\": [0, 0, 2], \"deg\": 90}}}]}\n",
                  &s),
        RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_object *m = object_named(d, "m");
    assert_true(near(m->bounds.min.x, 9.0f) && near(m->bounds.max.x, 11.0f));
    /* The quad (2 along x) turned about z stands 2 tall along y. */
    const rl_object *r = object_named(d, "r");
    assert_true(near(r->bounds.min.y, -1.0f) && near(r->bounds.max.y, 1.0f));
    assert_true(near(r->bounds.min.x, 0.0f) && near(r->bounds.max.x, 0.0f));
    rl_scene_release(s);
}

static void test_syntax_error_names_file_and_line(void **state)
{
    (void)state;
    expect_error("syntax.json", "{\n  \"objects\": [\n    {\"generator\": \"box\",}\n  ]\n}\n",
                 RL_ERR_PARSE, "syntax.json:3:");
}

static void test_unknown_key_is_reported_with_line_and_column(void **state)
{
    (void)state;
    expect_error("unknown.json", "{\n  \"objects\": [\n    {\"generator\": \"box\", \"colour\": 1}\n  ]\n}\n",
                 RL_ERR_PARSE, "unknown.json:3:26: unknown key \"colour\"");
    expect_error("unknown_top.json", "{\"objects\": [], \"lamps\": []}", RL_ERR_PARSE,
                 "unknown key \"lamps\"");
    /* Keys that belong to another light type are unknown too. */
    expect_error("unknown_light.json",
                 "{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"edge_u\": [1,0,0]}]}",
                 RL_ERR_PARSE, "unknown key \"edge_u\"");
}

static void test_unknown_material_lists_the_defined_ones(void **state)
{
    (void)state;
    expect_error("chrome.json",
                 "{\"materials\": {\"gold\": {}},\n"
                 " \"objects\": [{\"generator\": \"box\", \"material\": \"chrome\"}]}",
                 RL_ERR_PARSE, "chrome.json:2:35: unknown material \"chrome\" (defined: gold)");
    expect_error("chrome_base.json",
                 "{\"materials\": {\"gold\": {\"base\": \"chrome\"}},\n"
                 " \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "unknown material \"chrome\"");
}

static void test_wrong_types_and_values_are_parse_errors(void **state)
{
    (void)state;
    static const struct { const char *name, *text, *part; } cases[] = {
        { "t1.json", "{\"lights\": [{\"type\": \"point\", \"position\": [0,0,0], \"intensity\": \"bright\"}], \"objects\": [{\"generator\": \"box\"}]}", "t1.json:1:" },
        { "t2.json", "{\"objects\": [{\"generator\": \"box\", \"transform\": {\"translate\": [1, 2]}}]}", "array of 3 numbers" },
        { "t3.json", "{\"objects\": {\"generator\": \"box\"}}", "expected an array" },
        { "t4.json", "{\"cameras\": [{\"eye\": [0,0,5], \"target\": [0,0,0], \"size\": [-640, 480]}], \"objects\": [{\"generator\": \"box\"}]}", "image size" },
        { "t5.json", "{\"lights\": [{\"type\": \"laser\"}], \"objects\": [{\"generator\": \"box\"}]}", "one of: point" },
        { "t6.json", "{\"objects\": [{\"generator\": \"box\", \"transform\": {\"translate\": [1e999, 0, 0]}}]}", "t6.json:1:" },
        { "t7.json", "{\"materials\": {\"m\": {\"reflectivity\": 0.7, \"transmissivity\": 0.6}}, \"objects\": [{\"generator\": \"box\"}]}", "exceed 1" },
        { "t8.json", "{\"materials\": {\"m\": {\"ior\": 0.5}}, \"objects\": [{\"generator\": \"box\"}]}", "\"ior\"" },
        { "t9.json", "{\"objects\": [{\"generator\": \"box\", \"transform\": {\"scale\": 0}}]}", "non-zero" },
        { "t10.json", "{\"objects\": [{\"generator\": \"box\", \"file\": \"x.obj\"}]}", "not both" },
        { "t11.json", "{\"objects\": [{\"generator\": \"pyramid\"}]}", "t11.json:1:" },
        { "t12.json", "{\"objects\": [{\"generator\": \"box\", \"params\": {\"size\": -1}}]}", "t12.json:1:" },
        { "t13.json", "{\"camera_path\": {\"keys\": [{\"time_s\": 1, \"eye\": [0,0,1], \"target\": [0,0,0]}, {\"time_s\": 0, \"eye\": [0,0,1], \"target\": [0,0,0]}]}, \"objects\": [{\"generator\": \"box\"}]}", "must increase" },
        { "t14.json", "{\"cameras\": [{\"eye\": [0,0,0], \"target\": [0,0,0]}], \"objects\": [{\"generator\": \"box\"}]}", "t14.json:1:" },
        { "t15.json", "[1, 2]", "expected an object" },
        { "t16.json", "{\"objects\": [{\"generator\": \"box\", \"attributes\": {\"a\": [1]}}]}", "number, string or bool" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i)
        expect_error(cases[i].name, cases[i].text, RL_ERR_PARSE, cases[i].part);
}

static void test_missing_required_keys_are_named(void **state)
{
    (void)state;
    expect_error("req1.json", "{\"lights\": [{\"position\": [0,0,0]}], \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "missing required key \"type\"");
    expect_error("req2.json", "{\"lights\": [{\"type\": \"spot\", \"position\": [0,0,0]}], \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "missing required key \"direction\"");
    expect_error("req3.json", "{\"cameras\": [{\"target\": [0,0,0]}], \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "missing required key \"eye\"");
}

static void test_scene_without_geometry_is_empty(void **state)
{
    (void)state;
    expect_error("empty.json", "{}", RL_ERR_EMPTY_SCENE, "empty.json");
    expect_error("groups.json", "{\"objects\": [{\"name\": \"g\", \"children\": [{}]}]}",
                 RL_ERR_EMPTY_SCENE, NULL);
}

static void test_missing_asset_files_are_io_errors_at_their_key(void **state)
{
    (void)state;
    expect_error("nofile.json", "{\"objects\": [\n {\"file\": \"models/none.obj\"}]}", RL_ERR_IO,
                 "nofile.json:2:");
    expect_error("notex.json",
                 "{\"materials\": {\"m\": {\"texture\": \"none.png\"}},\n"
                 " \"objects\": [{\"generator\": \"box\", \"material\": \"m\"}]}",
                 RL_ERR_IO, "notex.json:1:");
}

static void test_scene_load_picks_json_mesh_file_or_builtin(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    const char *json = write_file("pick.json", "{\"objects\": [{\"generator\": \"box\"}]}");
    assert_int_equal(rl_scene_load(json, NULL, &s), RL_OK);
    assert_string_equal(rl_scene_name(s), "pick");
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 12);
    assert_int_equal(rl_scene_get_data(s)->num_lights, 0);   /* JSON gets no default lights */
    rl_scene_release(s);

    const char *obj = write_file("pick.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
    assert_int_equal(rl_scene_load(obj, NULL, &s), RL_OK);
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 1);
    assert_int_equal(rl_scene_get_data(s)->num_lights, 2);    /* defaults for bare meshes */
    rl_scene_release(s);

    assert_int_equal(rl_scene_load("cornell", NULL, &s), RL_OK);
    assert_string_equal(rl_scene_name(s), "cornell");
    rl_scene_release(s);

    rl_clear_error();
    s = NULL;
    assert_int_equal(rl_scene_load("no-such-scene", NULL, &s), RL_ERR_IO);
    assert_null(s);
    assert_non_null(strstr(rl_last_error(), "\"no-such-scene\""));
    assert_non_null(strstr(rl_last_error(), "cornell"));

    rl_clear_error();
    assert_int_equal(rl_scene_load(json, "size=2", &s), RL_ERR_INVALID_ARG);
    assert_null(s);
}

/* Issue 37: the physically based material fields and the environment. */
static void test_pbr_materials_load_and_are_checked(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(load_text("pbr.json",
                               "{\"materials\": {\"gold\": {\"diffuse\": [1, 0.8, 0.3], \"bsdf\": \"ggx\", "
                               "\"roughness\": 0.3, \"metallic\": 1},\n"
                               " \"glass\": {\"transmissivity\": 1, \"fresnel\": \"schlick\"}},\n"
                               " \"objects\": [{\"generator\": \"box\", \"material\": \"gold\"},\n"
                               "  {\"generator\": \"sphere\", \"material\": \"glass\"}]}",
                               &s),
                     RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    uint32_t gold = rl_scene_find_material(s, "gold"), glass = rl_scene_find_material(s, "glass");
    assert_true(d->materials[gold].bsdf == RL_BSDF_GGX && near(d->materials[gold].roughness, 0.3f) &&
                near(d->materials[gold].metallic, 1.0f) && d->materials[gold].fresnel == RL_FRESNEL_NONE);
    assert_true(d->materials[glass].bsdf == RL_BSDF_PHONG && d->materials[glass].fresnel == RL_FRESNEL_SCHLICK);
    assert_null(d->environment);
    rl_scene_release(s);
    /* Defaults are the Phong model without Fresnel: older scenes unchanged. */
    rl_material m = rl_material_default();
    assert_true(m.bsdf == RL_BSDF_PHONG && m.fresnel == RL_FRESNEL_NONE && m.roughness == 0.0f);
    m.roughness = 1.5f;
    assert_int_equal(rl_material_validate(&m), RL_ERR_INVALID_ARG);

    expect_error("pbr1.json", "{\"materials\": {\"m\": {\"roughness\": 0.5}}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "needs \"bsdf\": \"ggx\"");
    expect_error("pbr2.json", "{\"materials\": {\"m\": {\"bsdf\": \"cook\"}}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "one of: phong, ggx");
    expect_error("pbr3.json",
                 "{\"materials\": {\"m\": {\"bsdf\": \"ggx\", \"metallic\": 2}}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "pbr3.json:1:");
    expect_error("pbr4.json", "{\"materials\": {\"m\": {\"fresnel\": \"exact\"}}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "one of: none, schlick");
}

static void write_exr(const char *name, int w, int h, rl_vec4 (*texel)(int x, int y))
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(w, h, RL_LAYER_COLOR, &img), RL_OK);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            img->color[(size_t)y * w + x] = texel(x, y);
    char path[1200];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    assert_int_equal(rl_image_write_exr(img, path), RL_OK);
    rl_image_release(img);
}

/* Bright top row, dark rest; column x adds x / 8 to red. */
static rl_vec4 sky_texel(int x, int y)
{
    return y == 0 ? rl_v4(4.0f + 0.125f * (float)x, 4.0f, 4.0f, 1.0f) : rl_v4(0.5f, 0.25f, 0.125f, 1.0f);
}

static void test_environment_loads_and_bad_maps_are_refused(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(load_text("envc.json",
                               "{\"environment\": {\"color\": [0.5, 0.25, 1], \"intensity\": 2},"
                               " \"objects\": [{\"generator\": \"box\"}]}", &s),
                     RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_non_null(d->environment);
    rl_vec3 L = rl_environment_radiance(d->environment, rl_v3(0.3f, 0.8f, -0.52f));
    assert_true(near(L.x, 1.0f) && near(L.y, 0.5f) && near(L.z, 2.0f));
    rl_scene_release(s);

    write_exr("sky.exr", 8, 4, sky_texel);
    assert_int_equal(load_text("envm.json",
                               "{\"environment\": {\"file\": \"sky.exr\", \"intensity\": 0.5},"
                               " \"objects\": [{\"generator\": \"box\"}]}", &s),
                     RL_OK);
    d = rl_scene_get_data(s);
    const rl_environment *env = d->environment;
    assert_non_null(env->map);
    L = rl_environment_radiance(env, rl_v3(0.0f, 1.0f, 0.0f));          /* straight up: row 0 */
    assert_true(near(L.y, 2.0f));
    L = rl_environment_radiance(env, rl_v3(0.0f, -1.0f, 0.0f));
    assert_true(near(L.x, 0.25f) && near(L.z, 0.0625f));
    /* The parametrisation goes both ways. */
    for (int i = 0; i < 16; ++i) {
        float u = ((float)i + 0.5f) / 16.0f, v = ((float)(i % 5) + 0.5f) / 5.0f;
        rl_vec2 uv = rl_environment_uv(env, rl_environment_direction(env, u, v));
        assert_float_equal(uv.x, u, 1e-4f);
        assert_float_equal(uv.y, v, 1e-4f);
    }
    rl_scene_release(s);

    /* Not 2:1 is taken (with a warning); every column still spans 360 degrees. */
    write_exr("square.exr", 4, 4, sky_texel);
    assert_int_equal(load_text("envq.json", "{\"environment\": {\"file\": \"square.exr\"},"
                                            " \"objects\": [{\"generator\": \"box\"}]}", &s),
                     RL_OK);
    rl_scene_release(s);

    expect_error("envx.json", "{\"environment\": {\"file\": \"none.exr\"}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_IO, "none.exr");
    expect_error("envk.json", "{\"environment\": {\"map\": \"sky.exr\"}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "envk.json:1:");
    write_file("notexr.exr", "this is not an EXR file at all");
    expect_error("envp.json", "{\"environment\": {\"file\": \"notexr.exr\"}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_PARSE, "notexr.exr");
    /* A map larger than the texture limit is refused from its header. */
    rl_texture_set_max_pixels(16);
    expect_error("envl.json", "{\"environment\": {\"file\": \"sky.exr\"}, \"objects\": [{\"generator\": \"box\"}]}",
                 RL_ERR_LIMIT, "sky.exr");
    rl_texture_set_max_pixels(0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_full_scene_loads_every_section),
        cmocka_unit_test(test_base_builtin_scene_is_extended),
        cmocka_unit_test(test_transform_matrix_and_axis_rotation),
        cmocka_unit_test(test_syntax_error_names_file_and_line),
        cmocka_unit_test(test_unknown_key_is_reported_with_line_and_column),
        cmocka_unit_test(test_unknown_material_lists_the_defined_ones),
        cmocka_unit_test(test_wrong_types_and_values_are_parse_errors),
        cmocka_unit_test(test_missing_required_keys_are_named),
        cmocka_unit_test(test_scene_without_geometry_is_empty),
        cmocka_unit_test(test_missing_asset_files_are_io_errors_at_their_key),
        cmocka_unit_test(test_scene_load_picks_json_mesh_file_or_builtin),
        cmocka_unit_test(test_pbr_materials_load_and_are_checked),
        cmocka_unit_test(test_environment_loads_and_bad_maps_are_refused),
    };
    return cmocka_run_group_tests(tests, setup, NULL);
}
