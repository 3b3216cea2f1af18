/* test_load_assimp.c: mesh files through Assimp (rl_scene_import and
 * rl_scene_load on a bare mesh file). Every file is written by the test into
 * $RL_TEST_TMP; checks use exact oracles (triangle counts, total area,
 * transformed positions) and status codes for broken input. */
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
#include <unistd.h>

#include "rl/rl_image.h"
#include "rl/rl_scene.h"
#include "scene/load_fixtures.h"

/* $RL_TEST_TMP/assimp/<sub>/ (created). */
static const char *dir_for(const char *sub, char *out, size_t size)
{
    return fx_dir("assimp", sub, out, size);
}

#define write_bytes fx_write_bytes
#define write_text fx_write_text
#define base64 fx_base64

static double total_area(const rl_scene_data *d)
{
    double area = 0.0;
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        rl_vec3 a = d->positions[d->indices[3 * t]], b = d->positions[d->indices[3 * t + 1]];
        rl_vec3 c = d->positions[d->indices[3 * t + 2]];
        area += 0.5 * rl_length(rl_cross(rl_sub(b, a), rl_sub(c, a)));
    }
    return area;
}

/* Imports path into a fresh scene and commits it. */
static rl_status import_committed(const char *path, rl_scene **out)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t root = RL_NONE;
    rl_status st = rl_scene_import(s, path, RL_NODE_ROOT, &root);
    if (st == RL_OK)
        st = rl_scene_commit(s);
    if (st != RL_OK) {
        rl_scene_release(s);
        return st;
    }
    *out = s;
    return RL_OK;
}

static void expect_parse_error(const char *path)
{
    rl_clear_error();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_load(path, NULL, &s), RL_ERR_PARSE);
    assert_null(s);
    /* The message names the file. */
    const char *base = strrchr(path, '/') + 1;
    assert_non_null(strstr(rl_last_error(), base));
}

static void test_obj_quad_and_pentagon_split_into_five_triangles(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("ngon", dir, sizeof dir);
    write_text(dir, "ngon.obj",
               "# unit quad and a pentagon of area 5\n"
               "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
               "v 2 0 0\nv 4 0 0\nv 4 2 0\nv 3 3 0\nv 2 2 0\n"
               "f 1 2 3 4\nf 5 6 7 8 9\n",
               path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 2 + 3);
    /* Splitting preserves the area exactly: 1 + (2*2 + 1). */
    assert_true(fabs(total_area(d) - 6.0) < 1e-5);
    /* Every vertex is one of the file's vertices. */
    for (uint32_t v = 0; v < d->num_vertices; ++v) {
        rl_vec3 p = d->positions[v];
        assert_true(p.z == 0.0f && p.x >= 0.0f && p.x <= 4.0f && p.y >= 0.0f && p.y <= 3.0f);
        assert_true(p.x == floorf(p.x) && p.y == floorf(p.y));
    }
    assert_true(d->bounds.max.x == 4.0f && d->bounds.max.y == 3.0f);
    rl_scene_release(s);
}

static void test_obj_material_and_texture_resolve_relative_to_the_obj(void **state)
{
    (void)state;
    char dir[1100], path[1200], png[1200], cwd[1024];
    dir_for("textured", dir, sizeof dir);
    /* A 2x2 texture: red, green / blue, white. */
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 2, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = rl_v4(1, 0, 0, 1);
    img->color[1] = rl_v4(0, 1, 0, 1);
    img->color[2] = rl_v4(0, 0, 1, 1);
    img->color[3] = rl_v4(1, 1, 1, 1);
    snprintf(png, sizeof png, "%s/checker.png", dir);
    assert_int_equal(rl_image_write_png(img, png), RL_OK);
    rl_image_release(img);
    write_text(dir, "box.mtl",
               "newmtl paint\nKd 0.2 0.4 0.6\nKs 0.5 0.5 0.5\nNs 50\nd 0.75\nNi 1.3\n"
               "map_Kd checker.png\n",
               path, sizeof path);
    write_text(dir, "box.obj",
               "mtllib box.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
               "usemtl paint\nf 1/1 2/2 3/3\n",
               path, sizeof path);

    /* Load from the temp root, so that the model's folder is not the cwd. */
    assert_non_null(getcwd(cwd, sizeof cwd));
    char root[1200];
    snprintf(root, sizeof root, "%s/..", dir);
    assert_int_equal(chdir(root), 0);
    rl_scene *s = NULL;
    rl_status st = rl_scene_load("textured/box.obj", NULL, &s);
    assert_int_equal(chdir(cwd), 0);
    assert_int_equal(st, RL_OK);

    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 1);
    const rl_material *m = &d->materials[d->triangle_material[0]];
    assert_string_equal(m->name, "paint");
    assert_true(fabsf(m->diffuse.x - 0.2f) < 1e-6f && fabsf(m->diffuse.z - 0.6f) < 1e-6f);
    assert_true(fabsf(m->specular.y - 0.5f) < 1e-6f);
    assert_true(fabsf(m->shininess - 50.0f) < 1e-4f);
    assert_true(fabsf(m->transmissivity - 0.25f) < 1e-6f);
    assert_true(fabsf(m->ior - 1.3f) < 1e-6f);
    assert_int_equal(d->num_textures, 1);
    assert_int_equal(m->diffuse_texture, 0);
    const rl_texture *t = d->textures[0];
    assert_int_equal(t->width, 2);
    assert_int_equal(t->height, 2);
    assert_true(fabsf(t->texels[0].x - 1.0f) < 1e-3f && fabsf(t->texels[0].y) < 1e-3f);
    assert_true(fabsf(t->texels[3].z - 1.0f) < 1e-3f);
    /* OBJ texture coordinates arrive unchanged. */
    for (uint32_t v = 0; v < 3; ++v)
        assert_true(d->uvs[v].x == d->positions[v].x && d->uvs[v].y == d->positions[v].y);
    rl_scene_release(s);
}

static void test_ascii_ply_loads_with_its_quad_split(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("ply", dir, sizeof dir);
    write_text(dir, "square.ply",
               "ply\nformat ascii 1.0\ncomment two units wide\nelement vertex 4\n"
               "property float x\nproperty float y\nproperty float z\n"
               "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
               "0 0 0\n2 0 0\n2 0 2\n0 0 2\n4 0 3 2 1\n",
               path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 2);
    assert_true(fabs(total_area(d) - 4.0) < 1e-6);
    /* Winding 0 3 2 1 faces +y: normals computed by the scene follow it. */
    for (uint32_t v = 0; v < d->num_vertices; ++v)
        assert_true(d->normals[v].y > 0.99f);
    rl_scene_release(s);
}

static void test_ply_header_free_text_line_is_skipped_like_assimp_does(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("ply", dir, sizeof dir);
    /* Blender 2.4x wrote this line without the "comment" keyword. */
    write_text(dir, "blender24.ply",
               "ply\nformat ascii 1.0\nCreated by Blender3D 247 - www.blender.org, source file: \n"
               "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
               "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
               "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
               path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 1);
    rl_scene_release(s);
}

static void put_f32(unsigned char **p, float f)
{
    memcpy(*p, &f, 4);   /* STL is little-endian, as is every machine we run on */
    *p += 4;
}

static void test_binary_stl_loads(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("stl", dir, sizeof dir);
    static const float tris[2][3][3] = {
        { { 0, 0, 0 }, { 3, 0, 0 }, { 0, 4, 0 } },
        { { 0, 0, 1 }, { 3, 0, 1 }, { 0, 4, 1 } },
    };
    unsigned char buf[84 + 2 * 50] = { 0 };
    memcpy(buf, "binary stl written by test_load_assimp", 38);
    uint32_t count = 2;
    memcpy(buf + 80, &count, 4);
    unsigned char *p = buf + 84;
    for (int t = 0; t < 2; ++t) {
        put_f32(&p, 0), put_f32(&p, 0), put_f32(&p, 1);   /* facet normal */
        for (int v = 0; v < 3; ++v)
            for (int k = 0; k < 3; ++k)
                put_f32(&p, tris[t][v][k]);
        p += 2;                                          /* attribute bytes */
    }
    snprintf(path, sizeof path, "%s/two.stl", dir);
    write_bytes(path, buf, sizeof buf);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 2);
    assert_true(fabs(total_area(d) - 12.0) < 1e-5);
    assert_true(d->bounds.max.x == 3.0f && d->bounds.max.y == 4.0f && d->bounds.max.z == 1.0f);
    rl_scene_release(s);
}

/* A glTF 2.0 file with one triangle whose buffer is a base64 data URI; the
 * mesh node "tri" (translation 1,2,3) sits under "parent" (translation 10,0,0). */
static const char *write_gltf(const char *dir, const char *name, const char *buffer_uri,
                              char *out, size_t size)
{
    static const float pos[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    char b64[64], uri[128], text[2048];
    base64((const unsigned char *)pos, sizeof pos, b64);
    snprintf(uri, sizeof uri, "data:application/octet-stream;base64,%s", b64);
    snprintf(text, sizeof text,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0,"
             " \"scenes\": [{\"nodes\": [0]}],"
             " \"nodes\": [{\"name\": \"parent\", \"translation\": [10, 0, 0], \"children\": [1, 2]},"
             "             {\"name\": \"tri\", \"mesh\": 0, \"translation\": [1, 2, 3]},"
             "             {\"name\": \"cam\", \"camera\": 0, \"translation\": [0, 0, 10]}],"
             " \"cameras\": [{\"type\": \"perspective\", \"perspective\":"
             "   {\"yfov\": 0.8, \"znear\": 0.1, \"aspectRatio\": 1.5}}],"
             " \"meshes\": [{\"name\": \"trimesh\", \"primitives\": [{\"attributes\": {\"POSITION\": 0}}]}],"
             " \"buffers\": [{\"byteLength\": 36, \"uri\": \"%s\"}],"
             " \"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": 36}],"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3,"
             "   \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}]}",
             buffer_uri ? buffer_uri : uri);
    return write_text(dir, name, text, out, size);
}

static void test_gltf_triangle_keeps_its_node_hierarchy_and_transforms(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("gltf", dir, sizeof dir);
    write_gltf(dir, "tri.gltf", NULL, path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_triangles, 1);
    assert_int_equal(d->num_objects, 1);
    uint32_t parent = rl_scene_find_node(s, "parent"), tri = rl_scene_find_node(s, "tri");
    assert_int_not_equal(parent, RL_NONE);
    assert_int_not_equal(tri, RL_NONE);
    assert_int_equal(rl_scene_node_parent(s, tri), parent);
    assert_int_equal(d->objects[0].node, tri);
    /* World position = parent translation + node translation + local. */
    assert_true(d->bounds.min.x == 11.0f && d->bounds.min.y == 2.0f && d->bounds.min.z == 3.0f);
    assert_true(d->bounds.max.x == 12.0f && d->bounds.max.y == 3.0f && d->bounds.max.z == 3.0f);
    /* The camera sits at its node (under "parent") and looks down its -z. */
    assert_int_equal(d->num_cameras, 1);
    rl_camera cam = d->cameras[0];
    assert_true(fabsf(cam.eye.x - 10.0f) < 1e-5f && fabsf(cam.eye.y) < 1e-5f &&
                fabsf(cam.eye.z - 10.0f) < 1e-5f);
    rl_vec3 view = rl_normalize(rl_sub(cam.target, cam.eye));
    assert_true(view.z < -0.999f);
    /* glTF's yfov is the full vertical angle: 0.8 rad. */
    assert_true(fabsf(cam.fov_deg - 45.8366f) < 0.01f);
    assert_string_equal(d->camera_names[0], "cam");
    rl_scene_release(s);

    /* Imported twice into one scene, the camera names stay unique. */
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t root;
    assert_int_equal(rl_scene_import(s, path, RL_NODE_ROOT, &root), RL_OK);
    assert_int_equal(rl_scene_import(s, path, RL_NODE_ROOT, &root), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    d = rl_scene_get_data(s);
    assert_int_equal(d->num_cameras, 2);
    assert_string_equal(d->camera_names[1], "cam#2");
    assert_int_equal(d->num_objects, 2);
    rl_scene_release(s);
}

static void test_gltf_embedded_png_texture_is_decoded(void **state)
{
    (void)state;
    char dir[1100], path[1200], png[1200];
    dir_for("gltf_tex", dir, sizeof dir);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(2, 1, RL_LAYER_COLOR, &img), RL_OK);
    img->color[0] = rl_v4(1, 0, 0, 1);
    img->color[1] = rl_v4(0, 0, 1, 1);
    snprintf(png, sizeof png, "%s/t.png", dir);
    assert_int_equal(rl_image_write_png(img, png), RL_OK);
    rl_image_release(img);
    unsigned char bytes[4096];
    FILE *f = fopen(png, "rb");
    assert_non_null(f);
    size_t n = fread(bytes, 1, sizeof bytes, f);
    fclose(f);
    assert_true(n > 0 && n < sizeof bytes);

    static const float pos[9] = { 0, 0, 0, 1, 0, 0, 0, 1, 0 };
    char b64_pos[64], b64_png[4096 * 4 / 3 + 8], text[8192];
    base64((const unsigned char *)pos, sizeof pos, b64_pos);
    base64(bytes, n, b64_png);
    snprintf(text, sizeof text,
             "{\"asset\": {\"version\": \"2.0\"}, \"scene\": 0, \"scenes\": [{\"nodes\": [0]}],"
             " \"nodes\": [{\"mesh\": 0}],"
             " \"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0}, \"material\": 0}]}],"
             " \"materials\": [{\"name\": \"painted\", \"pbrMetallicRoughness\":"
             "   {\"baseColorTexture\": {\"index\": 0}}}],"
             " \"textures\": [{\"source\": 0}],"
             " \"images\": [{\"uri\": \"data:image/png;base64,%s\"}],"
             " \"buffers\": [{\"byteLength\": 36, \"uri\": \"data:application/octet-stream;base64,%s\"}],"
             " \"bufferViews\": [{\"buffer\": 0, \"byteLength\": 36}],"
             " \"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3,"
             "   \"type\": \"VEC3\", \"min\": [0, 0, 0], \"max\": [1, 1, 0]}]}",
             b64_png, b64_pos);
    write_text(dir, "painted.gltf", text, path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_material *m = &d->materials[d->triangle_material[0]];
    assert_string_equal(m->name, "painted");
    assert_int_equal(d->num_textures, 1);
    assert_int_equal(m->diffuse_texture, 0);
    const rl_texture *t = d->textures[0];
    assert_int_equal(t->width, 2);
    assert_int_equal(t->height, 1);
    assert_true(fabsf(t->texels[0].x - 1.0f) < 1e-3f && fabsf(t->texels[0].z) < 1e-3f);
    assert_true(fabsf(t->texels[1].z - 1.0f) < 1e-3f && fabsf(t->texels[1].x) < 1e-3f);
    rl_scene_release(s);
}

static void test_import_under_a_parent_applies_the_parent_transform(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("parent", dir, sizeof dir);
    write_text(dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_mat4 t = rl_mat4_translate(rl_v3(0, 0, -5));
    uint32_t group, root = RL_NONE;
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "group", &t, &group), RL_OK);
    assert_int_equal(rl_scene_import(s, path, group, &root), RL_OK);
    assert_int_equal(rl_scene_node_parent(s, root), group);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_true(d->bounds.min.z == -5.0f && d->bounds.max.z == -5.0f);
    rl_scene_release(s);
}

static void test_bare_mesh_file_gets_default_lights_name_and_camera(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("bare", dir, sizeof dir);
    write_text(dir, "plate.obj", "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 4 3 2\n", path,
               sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_load(path, NULL, &s), RL_OK);
    assert_true(rl_scene_is_committed(s));
    assert_string_equal(rl_scene_name(s), "plate");
    assert_string_equal(rl_scene_base_dir(s), dir);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_lights, 2);
    assert_int_equal(d->lights[0].type, RL_LIGHT_POINT);
    assert_int_equal(d->lights[1].type, RL_LIGHT_DIRECTIONAL);
    /* The key light is above the plate, so the plate's top is lit. */
    assert_true(d->lights[0].position.y > 0.0f);
    assert_int_equal(d->num_cameras, 0);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    assert_int_equal(rl_camera_validate(&cam), RL_OK);
    rl_scene_release(s);
}

static void test_parameters_for_a_mesh_file_are_rejected(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("params", dir, sizeof dir);
    write_text(dir, "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", path, sizeof path);
    rl_clear_error();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_load(path, "triangles=5", &s), RL_ERR_INVALID_ARG);
    assert_null(s);
}

static void test_missing_file_is_an_io_error_naming_it(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("missing", dir, sizeof dir);
    snprintf(path, sizeof path, "%s/nothing-here.obj", dir);
    rl_clear_error();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t root = 77;
    assert_int_equal(rl_scene_import(s, path, RL_NODE_ROOT, &root), RL_ERR_IO);
    assert_int_equal(root, 77);
    assert_non_null(strstr(rl_last_error(), "nothing-here.obj"));
    assert_int_equal(rl_scene_node_count(s), 1);
    rl_scene_release(s);
}

static void test_truncated_obj_is_a_parse_error(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    /* Cut in the middle of the second face line. */
    expect_parse_error(write_text(dir, "cut_face.obj",
                                  "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3", path,
                                  sizeof path));
    /* ... and the message points at the cut line. */
    assert_non_null(strstr(rl_last_error(), "cut_face.obj:6: face with 2 corners"));
    /* Cut in the vertex list: faces refer to vertices that never came. */
    expect_parse_error(write_text(dir, "cut_vertices.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\n",
                                  path, sizeof path));
    /* Cut before any face. */
    expect_parse_error(write_text(dir, "no_faces.obj", "v 0 0 0\nv 1 0 0\nv 1", path,
                                  sizeof path));
}

static void test_obj_with_garbage_bytes_is_a_parse_error(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    static const char data[] = "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n\x01\x02\xff\xfe\x00zz 1 2\n";
    snprintf(path, sizeof path, "%s/garbage.obj", dir);
    write_bytes(path, data, sizeof data - 1);
    expect_parse_error(path);
}

static void test_ply_with_fewer_vertices_than_its_header_is_a_parse_error(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    static const char header[] =
        "ply\nformat %s 1.0\nelement vertex %d\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    char text[1024];
    snprintf(text, sizeof text, header, "ascii", 4);
    strcat(text, "0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n");
    expect_parse_error(write_text(dir, "short_ascii.ply", text, path, sizeof path));

    /* Binary: 8 vertices promised, 3 given, then the face. */
    unsigned char bin[1024];
    int n = snprintf((char *)bin, sizeof bin, header, "binary_little_endian", 8);
    float v[9] = { 0, 0, 0, 1, 0, 0, 1, 1, 0 };
    memcpy(bin + n, v, sizeof v);
    n += (int)sizeof v;
    bin[n++] = 3;
    int32_t idx[3] = { 0, 1, 2 };
    memcpy(bin + n, idx, sizeof idx);
    n += (int)sizeof idx;
    snprintf(path, sizeof path, "%s/short_binary.ply", dir);
    write_bytes(path, bin, (size_t)n);
    expect_parse_error(path);
    assert_non_null(strstr(rl_last_error(), "ends after 4 of 8"));
}

static void test_ply_content_under_another_extension_is_still_checked(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    /* Assimp falls back to its PLY reader by content, which would accept this. */
    expect_parse_error(write_text(dir, "ply_inside.gltf",
                                  "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                  "property float y\nproperty float z\nelement face 1\n"
                                  "property list uchar int vertex_indices\nend_header\n"
                                  "0 0 0\n1 0 0\n1 1 0\n3 0 1 2\n",
                                  path, sizeof path));
    assert_non_null(strstr(rl_last_error(), "PLY"));
    /* A non-numeric token in an ascii body. */
    expect_parse_error(write_text(dir, "word.ply",
                                  "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n"
                                  "property float y\nproperty float z\nend_header\n"
                                  "0 0 0\n1 zero 0\n1 1 0\n",
                                  path, sizeof path));
}

static void test_ply_faces_with_bad_corners_are_parse_errors(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    static const char header[] =
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n1 1 0\n";
    char text[1024];
    snprintf(text, sizeof text, "%s%s", header, "3 0 1 3\n");
    expect_parse_error(write_text(dir, "index_range.ply", text, path, sizeof path));
    snprintf(text, sizeof text, "%s%s", header, "2 0 1\n");
    expect_parse_error(write_text(dir, "two_corners.ply", text, path, sizeof path));
}

static void test_corrupted_gltf_is_a_parse_error(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    expect_parse_error(write_text(dir, "bad_json.gltf",
                                  "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [", path,
                                  sizeof path));
    expect_parse_error(write_gltf(dir, "missing_buffer.gltf", "no-such-buffer.bin", path,
                                  sizeof path));
}

static void test_nan_vertex_drops_its_triangle_and_is_counted(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("nan", dir, sizeof dir);
    write_text(dir, "nan.obj", "v 0 0 0\nv 1 0 0\nv nan 1 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
               path, sizeof path);
    rl_scene *s = NULL;
    assert_int_equal(import_committed(path, &s), RL_OK);
    rl_scene_stats stats;
    rl_scene_get_stats(s, &stats);
    assert_int_equal(stats.triangles, 1);
    assert_int_equal(stats.dropped_nonfinite, 1);
    rl_scene_release(s);
}

static void test_lines_only_file_has_no_triangles(void **state)
{
    (void)state;
    char dir[1100], path[1200];
    dir_for("broken", dir, sizeof dir);
    expect_parse_error(write_text(dir, "lines.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nl 1 2 3\n",
                                  path, sizeof path));
    assert_non_null(strstr(rl_last_error(), "no triangles"));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_obj_quad_and_pentagon_split_into_five_triangles),
        cmocka_unit_test(test_obj_material_and_texture_resolve_relative_to_the_obj),
        cmocka_unit_test(test_ascii_ply_loads_with_its_quad_split),
        cmocka_unit_test(test_ply_header_free_text_line_is_skipped_like_assimp_does),
        cmocka_unit_test(test_binary_stl_loads),
        cmocka_unit_test(test_gltf_triangle_keeps_its_node_hierarchy_and_transforms),
        cmocka_unit_test(test_gltf_embedded_png_texture_is_decoded),
        cmocka_unit_test(test_import_under_a_parent_applies_the_parent_transform),
        cmocka_unit_test(test_bare_mesh_file_gets_default_lights_name_and_camera),
        cmocka_unit_test(test_parameters_for_a_mesh_file_are_rejected),
        cmocka_unit_test(test_missing_file_is_an_io_error_naming_it),
        cmocka_unit_test(test_truncated_obj_is_a_parse_error),
        cmocka_unit_test(test_obj_with_garbage_bytes_is_a_parse_error),
        cmocka_unit_test(test_ply_with_fewer_vertices_than_its_header_is_a_parse_error),
        cmocka_unit_test(test_ply_faces_with_bad_corners_are_parse_errors),
        cmocka_unit_test(test_ply_content_under_another_extension_is_still_checked),
        cmocka_unit_test(test_corrupted_gltf_is_a_parse_error),
        cmocka_unit_test(test_nan_vertex_drops_its_triangle_and_is_counted),
        cmocka_unit_test(test_lines_only_file_has_no_triangles),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
