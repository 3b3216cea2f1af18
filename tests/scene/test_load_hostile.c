/* test_load_hostile.c: small model files that made Assimp hang or allocate
 * gigabytes (issue 34), refused by our pre-checks (load_validate.c) before
 * Assimp reads them: PLY element counts the file cannot hold (ASCII and
 * binary), PLY headers that Assimp reads otherwise than a word-cutting
 * parser would, GLB chunk lengths beyond the file, OFF indices past the
 * vertices, node hierarchies Assimp recurses through without bound (glTF
 * and Collada: cycles, depth, instancing blow-ups; load_validate_graph.c),
 * and paths that are not regular files. Each must fail with a clear error, quickly. */
#define _POSIX_C_SOURCE 200809L
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "rl/rl_image.h"
#include "rl/rl_scene.h"
#include "scene/load_fixtures.h"

static const char *tmp_path(const char *name, char *out, size_t size)
{
    char dir[1024];
    fx_dir("hostile", ".", dir, sizeof dir);
    snprintf(out, size, "%s/%s", dir, name);
    return out;
}

static const char *write_bytes(const char *name, const void *data, size_t len, char *out, size_t size)
{
    fx_write_bytes(tmp_path(name, out, size), data, len);
    return out;
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Loads path and expects code with want in the message, within seconds. */
static void expect_refused(const char *path, rl_status code, const char *want)
{
    rl_clear_error();
    rl_scene *s = NULL;
    double t0 = now_s();
    rl_status st = rl_scene_load(path, NULL, &s);
    double dt = now_s() - t0;
    if (st != code || !strstr(rl_last_error(), want))
        fail_msg("%s: got %s \"%s\", want %s with \"%s\"", path, rl_status_name(st), rl_last_error(),
                 rl_status_name(code), want);
    assert_null(s);
    /* A bound that only a hang would break (the test's whole point is that
     * no Assimp loop runs); the checks themselves take microseconds. */
    assert_true(dt < 10.0);
    rl_clear_error();
}

static void test_ply_counts_beyond_the_file_are_refused(void **state)
{
    (void)state;
    char path[1200];
    /* The 121-byte file: an element of four billion items without
     * properties, which Assimp loops over forever. */
    const char *endless = "ply\nformat ascii 1.0\nelement vertex 4000000000\nend_header\n";
    expect_refused(write_bytes("endless.ply", endless, strlen(endless), path, sizeof path),
                   RL_ERR_PARSE, "declares 4000000000 items");
    /* Its binary twin with properties (Assimp took 28 s to fail). */
    const char *binary = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n"
                         "property float x\nproperty float y\nproperty float z\n"
                         "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
                         "\x00\x00\x00\x00";
    expect_refused(write_bytes("endless_bin.ply", binary, strlen(binary) + 4, path, sizeof path),
                   RL_ERR_PARSE, "PLY body ends after 0 of 4000000000 \"vertex\" elements");
    /* ASCII with properties: the body ends early. */
    const char *ascii = "ply\nformat ascii 1.0\nelement vertex 10\nproperty float x\n"
                        "property float y\nproperty float z\nend_header\n0 0 0\n";
    expect_refused(write_bytes("short.ply", ascii, strlen(ascii), path, sizeof path), RL_ERR_PARSE,
                   "PLY body ends after 1 of 10 \"vertex\" elements");
}

/* The header is read as Assimp reads it, word by word (fuzz_load_mesh
 * found a 323-byte PLY for which Assimp allocated 6 GB): an element name of
 * 97 bytes was cut into 31-byte words by the old sscanf, so its tail became
 * a count of 0 where Assimp read 3, and a NUL byte ended a header line
 * before the control-byte check saw the rest. */
static void test_ply_header_is_read_whole(void **state)
{
    (void)state;
    char path[1200];
    static const char nul[] = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float\0\0\0\3 x\n"
                              "property float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n";
    expect_refused(write_bytes("nul.ply", nul, sizeof nul - 1, path, sizeof path), RL_ERR_PARSE,
                   "control byte in the PLY header");
    char header[1024];
    char name[98];
    memset(name, '0', 97);
    name[97] = '\0';
    snprintf(header, sizeof header, "ply\nformat ascii 1.0\nelement %s 3\nproperty float x\nend_header\n0\n1\n2\n",
             name);
    expect_refused(write_bytes("long_name.ply", header, strlen(header), path, sizeof path), RL_ERR_PARSE,
                   "has a word of 64 bytes or more");
    char spaces[600];
    memset(spaces, ' ', 599);
    spaces[599] = '\0';
    snprintf(header, sizeof header, "ply\nformat ascii 1.0\nelement vertex 3%s\nproperty float x\nend_header\n",
             spaces);
    expect_refused(write_bytes("long_line.ply", header, strlen(header), path, sizeof path), RL_ERR_PARSE,
                   "is longer than 511 bytes");
    /* Long free text and a 40-byte property name (cut in two before) load. */
    snprintf(header, sizeof header,
             "ply\nformat ascii 1.0\ncomment %s a long comment\nelement vertex 3\nproperty float x\n"
             "property float y\nproperty float z\nproperty float confidence_of_the_scanner_at_this_point\n"
             "element face 1\nproperty list uchar int vertex_indices\nend_header\n"
             "0 0 0 1\n1 0 0 1\n0 1 0 1\n3 0 1 2\n",
             spaces);
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_load(write_bytes("good.ply", header, strlen(header), path, sizeof path), NULL, &s),
                     RL_OK);
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 1);
    rl_scene_release(s);
}

static void put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)v;
    p[1] = (unsigned char)(v >> 8);
    p[2] = (unsigned char)(v >> 16);
    p[3] = (unsigned char)(v >> 24);
}

static void test_glb_lengths_beyond_the_file_are_refused(void **state)
{
    (void)state;
    char path[1200];
    unsigned char glb[300];
    memset(glb, ' ', sizeof glb);
    memcpy(glb, "glTF", 4);
    put32(glb + 4, 2);
    put32(glb + 8, sizeof glb);
    /* A JSON chunk that claims 2 GB (Assimp allocated it). */
    put32(glb + 12, 0x80000000u);
    memcpy(glb + 16, "JSON", 4);
    expect_refused(write_bytes("huge_chunk.glb", glb, sizeof glb, path, sizeof path), RL_ERR_PARSE,
                   "chunk 0 claims 2147483648 bytes");
    /* A header whose total length is larger than the file. */
    put32(glb + 8, 1u << 30);
    put32(glb + 12, 8);
    expect_refused(write_bytes("huge_total.glb", glb, sizeof glb, path, sizeof path), RL_ERR_PARSE,
                   "claims 1073741824 bytes");
    /* A chunk a few bytes longer than the file. */
    put32(glb + 8, sizeof glb);
    put32(glb + 12, 284);
    expect_refused(write_bytes("cut_chunk.glb", glb, sizeof glb, path, sizeof path), RL_ERR_PARSE,
                   "GLB chunk 0 claims 284 bytes, 280 remain");
}

/* Assimp clamps an OFF index past the vertices onto the last one, which
 * hid the broken file; the pre-check refuses it, as the docs say. */
static void test_off_indices_out_of_range_are_refused(void **state)
{
    (void)state;
    char path[1200];
    static const struct {
        const char *name, *text, *want;
    } refused[] = {
        { "bad.off", "OFF\n# a comment\n3 1 0\n0 0 0\n1 0 0\n\n0 1 0\n3 0 1 7\n", "OFF face 0 uses vertex 7 of 3" },
        { "negative.off", "OFF 3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 -1 2\n", "uses vertex -1 of 3" },
        /* Counts the file cannot hold: Assimp would size its arrays by
         * them first (fuzz_load_mesh found 53 GB asked for by a 90-byte
         * file whose face count overflows any integer). */
        { "huge.off", "OFF\n4 1111111111111111111111111111111111111112 0\n0 0 0\n1 0 10 1\n1 1 0\n0 1 0\n3 0 2\n",
          "more than its 33 bytes after the header can hold" },
        /* fuzz_load_mesh: no edge count after a face count of 10^62
         * (Assimp reads two counts and asked for 22 GB). */
        { "no_edges.off", "OFF\n4 333333333333333333333333333333333333333333333333333333333333333???\n",
          "OFF declares 4 vertices and 9223372036854775807 faces" },
        /* fuzz_load_mesh: counts right after the header word, no space
         * (Assimp read 33 fours as the vertex count and asked for 5.7 GB). */
        { "glued.off", "OFF444444444444444444444444444444444\n4 0\n0",
          "OFF declares 9223372036854775807 vertices and 4 faces" },
        /* fuzz_load_mesh: no header word at all; Assimp reads the counts
         * from the first line (it asked for 28 GB). */
        { "headless.off", "\t\t22222222222222222222222222222222222222\t\t1\n",
          "OFF declares 9223372036854775807 vertices and 1 faces" },
        /* Geomview's prefixes; "nOFF" has a dimension count before the counts. */
        { "dimension.off", "CnOFF\n3\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "OFF face 0 uses vertex 9 of 3" },
        { "counts_below.off", "OFF\n3\n1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 9\n", "OFF face 0 uses vertex 9 of 3" },
        { "many.off", "OFF\n3 40 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n", "OFF declares 3 vertices and 40 faces" },
    };
    for (size_t i = 0; i < sizeof refused / sizeof refused[0]; ++i)
        expect_refused(write_bytes(refused[i].name, refused[i].text, strlen(refused[i].text), path, sizeof path),
                       RL_ERR_PARSE, refused[i].want);
    const char *good = "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2";   /* no end after the last line */
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_load(write_bytes("good.off", good, strlen(good), path, sizeof path), NULL, &s),
                     RL_OK);
    assert_int_equal(rl_scene_get_data(s)->num_triangles, 1);
    rl_scene_release(s);
}

/* A small PNG can claim a huge picture; the header is read first and the
 * pixel limit applies before any decoding (here lowered so that a 16 x 16
 * texture stands for one of 16384 x 16384). */
static void test_texture_pixel_limit_applies_before_decoding(void **state)
{
    (void)state;
    char png[1200], obj[1200], mtl[1200];
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    rl_image_fill(img, rl_v4(0.5f, 0.5f, 0.5f, 1.0f));
    assert_int_equal(rl_image_write_png(img, tmp_path("big.png", png, sizeof png)), RL_OK);
    rl_image_release(img);
    assert_true(rl_texture_max_pixels() == RL_TEXTURE_MAX_PIXELS);
    rl_texture_set_max_pixels(100);
    rl_texture *tex = NULL;
    rl_clear_error();
    assert_int_equal(rl_texture_load(png, &tex), RL_ERR_LIMIT);
    assert_null(tex);
    assert_non_null(strstr(rl_last_error(), "16x16 pixels exceeds the limit of 100"));
    /* Through a model file too: its material names the texture. */
    const char *m = "newmtl a\nmap_Kd big.png\n";
    const char *o = "mtllib big.mtl\nusemtl a\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
    write_bytes("big.mtl", m, strlen(m), mtl, sizeof mtl);
    expect_refused(write_bytes("big.obj", o, strlen(o), obj, sizeof obj), RL_ERR_LIMIT, "exceeds the limit");
    rl_texture_set_max_pixels(0);   /* back to the default */
    assert_int_equal(rl_texture_load(png, &tex), RL_OK);
    rl_texture_release(tex);
}

/* Issue 34: a model whose coordinates reach the float limit has no default
 * lights to give; the error names the file (it named a point light the
 * user never wrote). */
static void test_a_model_at_the_float_limit_is_refused_naming_the_file(void **state)
{
    (void)state;
    static const char huge[] = "v -3e38 -3e38 -3e38\nv 3e38 0 0\nv 0 3e38 3e38\nf 1 2 3\n";
    char path[1200];
    write_bytes("float_limit.obj", huge, strlen(huge), path, sizeof path);
    expect_refused(path, RL_ERR_PARSE, path);
}

static void test_a_device_is_not_read(void **state)
{
    (void)state;
    char path[1200];
    tmp_path("zero.obj", path, sizeof path);
    unlink(path);
    if (symlink("/dev/zero", path) != 0) {
        print_message("cannot make a symlink here; check skipped\n");
        return;
    }
    expect_refused(path, RL_ERR_IO, "not a regular file");
    unlink(path);
}

/* A Collada file with library nodes lib and visual-scene nodes scene. */
static const char *write_dae(const char *name, const char *lib, const char *scene, char *out,
                             size_t size)
{
    size_t n = strlen(lib) + strlen(scene) + 512;
    char *text = malloc(n);
    assert_non_null(text);
    snprintf(text, n,
             "<?xml version=\"1.0\"?>\n<COLLADA xmlns=\"http://www.collada.org/2005/11/"
             "COLLADASchema\" version=\"1.4.1\">\n<library_nodes>%s</library_nodes>\n"
             "<library_visual_scenes><visual_scene id=\"s\">%s</visual_scene>"
             "</library_visual_scenes>\n<scene><instance_visual_scene url=\"#s\"/></scene>"
             "</COLLADA>\n", lib, scene);
    write_bytes(name, text, strlen(text), out, size);
    free(text);
    return out;
}

/* nodes[i] is "children": [children[i]] or none (-1). */
static const char *write_gltf_nodes(const char *name, const char *nodes, char *out, size_t size)
{
    size_t n = strlen(nodes) + 256;
    char *text = malloc(n);
    assert_non_null(text);
    snprintf(text, n, "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,"
             "\"scenes\":[{\"nodes\":[0]}],\"nodes\":[%s]}", nodes);
    write_bytes(name, text, strlen(text), out, size);
    free(text);
    return out;
}

static void test_node_hierarchies_assimp_recurses_through_are_refused(void **state)
{
    (void)state;
    char path[1200];
    /* Each of these overflowed Assimp's stack or ran it out of memory. */
    expect_refused(write_dae("self.dae", "", "<node id=\"a\"><instance_node url=\"#a\"/></node>",
                             path, sizeof path),
                   RL_ERR_PARSE, "<node id=\"a\"> instances itself or an ancestor");
    expect_refused(write_dae("ancestor.dae", "",
                             "<node id=\"a\"><node id=\"b\"><instance_node url=\"#a\"/></node></node>",
                             path, sizeof path),
                   RL_ERR_PARSE, "a cycle in the node hierarchy");
    expect_refused(write_dae("mutual.dae",
                             "<node id=\"p\"><instance_node url=\"#q\"/></node>"
                             "<node id=\"q\"><instance_node url=\"#p\"/></node>",
                             "<node><instance_node url=\"#p\"/></node>", path, sizeof path),
                   RL_ERR_PARSE, "a cycle in the node hierarchy");
    enum { DEEP = 100000 };
    char *nest = malloc(13 * DEEP + 1);
    assert_non_null(nest);
    for (int i = 0; i < DEEP; ++i)
        memcpy(nest + 6 * i, "<node>", 6);
    for (int i = 0; i < DEEP; ++i)
        memcpy(nest + 6 * DEEP + 7 * i, "</node>", 7);
    nest[13 * DEEP] = '\0';
    expect_refused(write_dae("deep.dae", "", nest, path, sizeof path), RL_ERR_LIMIT,
                   "nested deeper than 1024 levels");
    free(nest);
    /* 40 levels, each instancing the next twice: 2^40 nodes. */
    char lib[4096] = "";
    for (int i = 0; i < 40; ++i)
        snprintf(lib + strlen(lib), sizeof lib - strlen(lib),
                 "<node id=\"n%d\"><instance_node url=\"#n%d\"/><instance_node url='#n%d'/></node>",
                 i, i + 1, i + 1);
    snprintf(lib + strlen(lib), sizeof lib - strlen(lib), "<node id=\"n40\"/>");
    expect_refused(write_dae("doubling.dae", lib, "<node><instance_node url=\"#n0\"/></node>",
                             path, sizeof path),
                   RL_ERR_LIMIT, "expands to more than 10000000 nodes");

    /* glTF: a chain 100,000 deep, a cycle, two parents, a bad index. */
    char *chain = malloc(32 * (size_t)DEEP);
    assert_non_null(chain);
    size_t at = 0;
    for (int i = 0; i + 1 < DEEP; ++i)
        at += (size_t)sprintf(chain + at, "{\"children\":[%d]},", i + 1);
    sprintf(chain + at, "{}");
    expect_refused(write_gltf_nodes("chain.gltf", chain, path, sizeof path), RL_ERR_LIMIT,
                   "node hierarchy deeper than 1024 levels");
    free(chain);
    expect_refused(write_gltf_nodes("cycle.gltf", "{\"children\":[1]},{\"children\":[0]}", path,
                                    sizeof path),
                   RL_ERR_PARSE, "node 0 is its own ancestor");
    expect_refused(write_gltf_nodes("loop.gltf", "{\"children\":[0]}", path, sizeof path),
                   RL_ERR_PARSE, "node 0 is its own ancestor");
    expect_refused(write_gltf_nodes("shared.gltf",
                                    "{\"children\":[1,2]},{\"children\":[3]},{\"children\":[3]},{}",
                                    path, sizeof path),
                   RL_ERR_PARSE, "node 3 has two parents (1 and 2)");
    expect_refused(write_gltf_nodes("index.gltf", "{\"children\":[1.5]},{}", path, sizeof path),
                   RL_ERR_PARSE, "node 0 has a child that is not a node index");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ply_counts_beyond_the_file_are_refused),
        cmocka_unit_test(test_ply_header_is_read_whole),
        cmocka_unit_test(test_glb_lengths_beyond_the_file_are_refused),
        cmocka_unit_test(test_off_indices_out_of_range_are_refused),
        cmocka_unit_test(test_texture_pixel_limit_applies_before_decoding),
        cmocka_unit_test(test_node_hierarchies_assimp_recurses_through_are_refused),
        cmocka_unit_test(test_a_model_at_the_float_limit_is_refused_naming_the_file),
        cmocka_unit_test(test_a_device_is_not_read),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
