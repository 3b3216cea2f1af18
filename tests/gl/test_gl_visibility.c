/* The visibility property on OpenGL (backend=gl, src/gl/gl_visibility.c)
 * against the software property: the same values, per-face values and
 * sets on every built-in scene at several positions in all three measures,
 * and per object the same pixels up to the ties of coplanar faces, the
 * GPU's counts equal to counting the same frame's ID images on the CPU,
 * alpha masks honoured, workers sharing the one GL counter, and a clear
 * error where there is no GL. Runs on llvmpipe (Mesa's surfaceless EGL);
 * where no GL 4.5 context can be made the GL cases say so and skip. */
#include <math.h>
#include <omp.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "gl/gl_visibility.h"
#include "rl/rl.h"
#include "rl/rl_gl.h"
#include "rl/rl_property.h"

#include "gl_fixtures.h"

#define RES 64

static rl_property *make_vis(const rl_scene *s, const char *backend, const char *measure, int res, int workers)
{
    rl_property *p = NULL;
    char num[16];
    snprintf(num, sizeof num, "%d", res);
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "resolution", num), RL_OK);
    assert_int_equal(rl_property_set(p, "measure", measure), RL_OK);
    assert_int_equal(rl_property_set(p, "backend", backend), RL_OK);
    assert_int_equal(rl_property_commit(p, s, workers), RL_OK);
    return p;
}

/* Positions inside and around a scene: the bounds' centre, a point a
 * quarter of the way up the diagonal, and the scene's own camera. */
static int positions(const rl_scene *s, rl_vec3 pos[3])
{
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_vec3 lo = d->bounds.min, hi = d->bounds.max;
    pos[0] = rl_scale(rl_add(lo, hi), 0.5f);
    pos[1] = rl_add(lo, rl_scale(rl_sub(hi, lo), 0.25f));
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    pos[2] = cam.eye;
    return 3;
}

/* How far the GL counts are from the software's at one position. */
typedef struct difference {
    uint64_t pixels;              /* sum over objects of |gl - software| pixels */
    uint64_t total;               /* software's covered pixels */
    uint32_t objects;             /* objects whose pixel counts differ */
    uint32_t visibility;          /* objects visible in one and not the other */
} difference;

static difference object_difference(rl_property *gl, rl_property *sw, rl_vec3 pos, uint32_t n)
{
    uint32_t *a = calloc(n, sizeof *a), *b = calloc(n, sizeof *b);
    assert_non_null(a);
    assert_non_null(b);
    assert_int_equal(rl_property_object_pixels(gl, 0, pos, a), RL_OK);
    assert_int_equal(rl_property_object_pixels(sw, 0, pos, b), RL_OK);
    difference d = { 0 };
    for (uint32_t o = 0; o < n; ++o) {
        d.pixels += a[o] > b[o] ? a[o] - b[o] : b[o] - a[o];
        d.total += b[o];
        d.objects += a[o] != b[o];
        d.visibility += (a[o] > 0) != (b[o] > 0);
    }
    free(a);
    free(b);
    return d;
}

/* Every built-in scene (city with two blocks), three positions each: the
 * values, the six per-face values and the set of all three measures, and
 * the pixels of every object. */
static void test_gl_visibility_matches_software_on_every_builtin_scene(void **state)
{
    (void)state;
    NEED_GL();
    static const char *const measures[] = { "objects", "polygons", "pixels" };
    size_t count = 0;
    const rl_builtin_info *scenes = rl_builtin_scenes(&count);
    assert_true(count >= 8);
    uint64_t all_diff = 0, all_total = 0;
    for (size_t i = 0; i < count; ++i) {
        const char *params = strcmp(scenes[i].name, "city") == 0 ? "blocks=2" : NULL;
        rl_scene *s = NULL;
        assert_int_equal(rl_scene_create_builtin(scenes[i].name, params, &s), RL_OK);
        const uint32_t n = rl_scene_get_data(s)->num_objects;
        rl_vec3 pos[3];
        const int np = positions(s, pos);
        rl_property *gl[3], *sw[3];
        for (int m = 0; m < 3; ++m) {
            gl[m] = make_vis(s, "gl", measures[m], RES, 1);
            sw[m] = make_vis(s, "software", measures[m], RES, 1);
        }
        const size_t words = rl_property_set_words(gl[0]);
        uint64_t *set_gl = calloc(words, sizeof *set_gl), *set_sw = calloc(words, sizeof *set_sw);
        for (int k = 0; k < np; ++k) {
            difference d = object_difference(gl[0], sw[0], pos[k], n);
            print_message("%-14s pos %d: %llu of %llu pixels differ (%u objects' counts, %u visible in one only)\n",
                          scenes[i].name, k, (unsigned long long)d.pixels, (unsigned long long)d.total, d.objects,
                          d.visibility);
            all_diff += d.pixels;
            all_total += d.total;
            /* Coplanar faces (a box's bottom on the floor) tie in depth;
             * which wins a pixel is the rounding of each triangle's depth
             * interpolation, not the same on GL (docs/gl.md). No object
             * becomes visible or hidden by it on these scenes. */
            assert_true(d.pixels * 200 <= d.total);
            assert_int_equal(d.visibility, 0);
            for (int m = 0; m < 3; ++m) {
                rl_property_sample a = { .set = set_gl }, b = { .set = set_sw };
                assert_int_equal(rl_property_evaluate(gl[m], 0, pos[k], &a), RL_OK);
                assert_int_equal(rl_property_evaluate(sw[m], 0, pos[k], &b), RL_OK);
                assert_true(a.value == b.value && a.value > 0.0);
                for (int f = 0; f < 6; ++f)
                    assert_true(a.direction[f] == b.direction[f]);
                assert_memory_equal(set_gl, set_sw, words * sizeof *set_gl);
            }
        }
        free(set_gl);
        free(set_sw);
        for (int m = 0; m < 3; ++m) {
            rl_property_release(gl[m]);
            rl_property_release(sw[m]);
        }
        rl_scene_release(s);
    }
    print_message("all scenes: %llu of %llu pixels differ\n", (unsigned long long)all_diff,
                  (unsigned long long)all_total);
    /* Measured: 62 of 301317 (cornell and ls-cornell, one position each). */
    assert_true(all_diff * 1000 <= all_total);
}

/* The GPU's counts against the CPU's count of the ID images of the same
 * frame, read back after the count: equal to the pixel. */
static void test_gpu_counts_equal_cpu_counts_of_the_same_frame(void **state)
{
    (void)state;
    NEED_GL();
    static const char *const names[] = { "cornell-teapot", "table" };
    for (int sc = 0; sc < 2; ++sc) {
        rl_scene *s = NULL;
        assert_int_equal(rl_scene_create_builtin(names[sc], NULL, &s), RL_OK);
        const rl_scene_data *d = rl_scene_get_data(s);
        /* An odd size, so that the last run of each row is short. */
        const int res = 75;
        rl_gl_visibility *v = NULL;
        assert_int_equal(rl_gl_visibility_create(s, res, NULL, &v), RL_OK);
        uint32_t ids[75 * 75];
        assert_int_equal(rl_gl_visibility_read_ids(v, 0, ids), RL_ERR_INVALID_ARG);
        const rl_vec3 pos = rl_scale(rl_add(d->bounds.min, d->bounds.max), 0.5f);
        rl_mat4 vp[6];
        for (int f = 0; f < 6; ++f) {
            rl_vec3 dir, up;
            rl_property_direction(f, &dir, &up);
            rl_camera cam = { .eye = pos, .target = rl_add(pos, dir), .up = up, .fov_deg = 90.0f,
                              .width = res, .height = res };
            rl_mat4 view = rl_camera_view(&cam), proj = rl_camera_projection(&cam, 0.1f, 100.0f);
            vp[f] = rl_mat4_mul(&proj, &view);
        }
        uint32_t *pixels = calloc(d->num_objects, sizeof *pixels);
        uint32_t *cpu = calloc(d->num_objects, sizeof *cpu);
        uint32_t *last = calloc(d->num_objects, sizeof *last);
        rl_gl_view_counts views[6];
        assert_int_equal(rl_gl_visibility_count(v, vp, NULL, pixels, views), RL_OK);
        uint32_t covered_all = 0;
        for (int f = 0; f < 6; ++f) {
            assert_int_equal(rl_gl_visibility_read_ids(v, f, ids), RL_OK);
            rl_gl_view_counts c = { 0 };
            for (int k = 0; k < res * res; ++k) {
                uint32_t o = ids[k];
                if (o == RL_ID_NONE)
                    continue;
                assert_true(o < d->num_objects);
                ++cpu[o];
                ++c.pixels;
                if (last[o] != (uint32_t)f + 1) {
                    last[o] = (uint32_t)f + 1;
                    ++c.objects;
                    c.polygons += d->objects[o].num_triangles;
                }
            }
            print_message("%s view %d: %u objects, %u triangles, %u pixels (GPU: %u, %u, %u)\n", names[sc], f,
                          c.objects, c.polygons, c.pixels, views[f].objects, views[f].polygons, views[f].pixels);
            assert_int_equal(c.objects, views[f].objects);
            assert_int_equal(c.polygons, views[f].polygons);
            assert_int_equal(c.pixels, views[f].pixels);
            covered_all += c.pixels;
        }
        assert_true(covered_all > 0);
        assert_memory_equal(cpu, pixels, d->num_objects * sizeof *cpu);
        assert_int_equal(rl_gl_visibility_read_ids(v, 6, ids), RL_ERR_INVALID_ARG);
        free(pixels);
        free(cpu);
        free(last);
        rl_gl_visibility_release(v);
        rl_scene_release(s);
    }
}

/* A quad whose texture is opaque only where u > 1/2 (cutoff 0.5) in front
 * of a larger one: the GL pass drops the mask's holes as the software
 * rasterizer does. */
static void test_gl_visibility_honours_alpha_masks(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    const rl_vec4 texels[8] = { { 1, 1, 1, 0 }, { 1, 1, 1, 0 }, { 1, 1, 1, 0 }, { 1, 1, 1, 0 },
                                { 1, 1, 1, 1 }, { 1, 1, 1, 1 }, { 1, 1, 1, 1 }, { 1, 1, 1, 1 } };
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(8, 1, texels, &tex), RL_OK);
    uint32_t tex_id, mats[2];
    assert_int_equal(rl_scene_add_texture(s, tex, &tex_id), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse_texture = tex_id;
    m.alpha_cutoff = 0.5f;
    assert_int_equal(rl_scene_add_material(s, &m, &mats[0]), RL_OK);
    m = rl_material_default();
    assert_int_equal(rl_scene_add_material(s, &m, &mats[1]), RL_OK);
    const float half[2] = { 0.5f, 2.5f }, z[2] = { 1.0f, 2.0f };
    for (int q = 0; q < 2; ++q) {
        const float h = half[q];
        const rl_vec3 p[4] = { { -h, -h, z[q] }, { h, -h, z[q] }, { h, h, z[q] }, { -h, h, z[q] } };
        const rl_vec2 uv[4] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
        const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
        rl_mesh_desc md = { .name = "quad", .num_vertices = 4, .positions = p, .uvs = uv,
                            .num_triangles = 2, .indices = idx, .material = mats[q] };
        uint32_t mesh, node;
        assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
        assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, q ? "back" : "leaf", NULL, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_property *gl = make_vis(s, "gl", "objects", RES, 1);
    rl_property *sw = make_vis(s, "software", "objects", RES, 1);
    const rl_vec3 pos = rl_v3(0.0f, 0.0f, 0.0f);
    uint32_t a[2], b[2];
    assert_int_equal(rl_property_object_pixels(gl, 0, pos, a), RL_OK);
    assert_int_equal(rl_property_object_pixels(sw, 0, pos, b), RL_OK);
    print_message("leaf %u / %u pixels, back %u / %u (GL / software)\n", a[0], b[0], a[1], b[1]);
    /* The leaf covers the +z face's middle half; its transparent half
     * shows the back quad. */
    assert_true(a[0] > 0 && a[1] > 0);
    assert_true(a[0] < a[1]);
    assert_int_equal(a[0], b[0]);
    assert_int_equal(a[1], b[1]);
    rl_property_release(gl);
    rl_property_release(sw);
    rl_scene_release(s);
}

/* A wall 0.05 beside the viewer, closer than the near plane (0.1) in the
 * +x face (whose frustum test leaves it out) and crossing it in the four
 * faces that see it edge-on: there the near plane, a clip distance on GL,
 * cuts off the part in front of it as the software rasterizer clips.
 * (llvmpipe applies a written gl_ClipDistance even where GL_CLIP_DISTANCE0
 * is not enabled, as measured; GPUs follow the spec and need the enable.) */
static void test_gl_visibility_clips_at_the_near_plane(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    const rl_vec3 p[4] = { { 0.05f, -2, -2 }, { 0.05f, 2, -2 }, { 0.05f, 2, 2 }, { 0.05f, -2, 2 } };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc md = { .name = "wall", .num_vertices = 4, .positions = p, .num_triangles = 2, .indices = idx,
                        .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "wall", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_property *gl = make_vis(s, "gl", "pixels", RES, 1);
    rl_property *sw = make_vis(s, "software", "pixels", RES, 1);
    rl_property_sample a = { 0 }, b = { 0 };
    assert_int_equal(rl_property_evaluate(gl, 0, rl_v3s(0.0f), &a), RL_OK);
    assert_int_equal(rl_property_evaluate(sw, 0, rl_v3s(0.0f), &b), RL_OK);
    print_message("wall: %g / %g pixels (GL / software); +z face %g / %g\n", a.value, b.value, a.direction[4],
                  b.direction[4]);
    /* Unclipped, the wall would fill the +z face's right half from x/z =
     * 1/2 on; clipped, only beyond z = 0.1, i.e. up to x/z = 1/2. */
    assert_true(b.direction[4] > 0.0 && b.direction[4] < 0.35 * RES * RES);
    assert_true(a.value == b.value);
    for (int f = 0; f < 6; ++f)
        assert_true(a.direction[f] == b.direction[f]);
    rl_property_release(gl);
    rl_property_release(sw);
    rl_scene_release(s);
}

/* Several workers evaluating at once share the one GL counter: each gets
 * what one worker alone gets. */
static void test_gl_visibility_workers_share_the_counter(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("spheres", NULL, &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_property *one = make_vis(s, "gl", "pixels", 48, 1);
    rl_property *many = make_vis(s, "gl", "pixels", 48, 3);
    enum { N = 12 };
    double expect[N], got[N];
    rl_vec3 pos[N];
    for (int k = 0; k < N; ++k) {
        float t = (float)k / (N - 1);
        pos[k] = rl_add(d->bounds.min, rl_scale(rl_sub(d->bounds.max, d->bounds.min), 0.2f + 0.6f * t));
        rl_property_sample smp = { 0 };
        assert_int_equal(rl_property_evaluate(one, 0, pos[k], &smp), RL_OK);
        expect[k] = smp.value;
    }
    int failures = 0;
#pragma omp parallel for num_threads(3) schedule(static, 1) reduction(+ : failures)
    for (int k = 0; k < N; ++k) {
        rl_property_sample smp = { 0 };
        failures += rl_property_evaluate(many, omp_get_thread_num(), pos[k], &smp) != RL_OK;
        got[k] = smp.value;
    }
    assert_int_equal(failures, 0);
    for (int k = 0; k < N; ++k)
        assert_true(got[k] == expect[k] && expect[k] > 0.0);
    rl_property_release(one);
    rl_property_release(many);
    rl_scene_release(s);
}

/* A device that cannot be opened: commit fails with one clear message and
 * the property stays uncommitted; the software backend does not care. */
static void test_gl_visibility_unavailable_is_a_clear_error(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "backend", "gl"), RL_OK);
    assert_int_equal(rl_property_set(p, "device", "bogus"), RL_OK);
    assert_int_equal(rl_property_set(p, "resolution", "16"), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_property_commit(p, s, 1), RL_ERR_UNSUPPORTED);
    print_message("%s\n", rl_last_error());
    assert_non_null(strstr(rl_last_error(), "visibility: backend gl: OpenGL unavailable: "));
    /* A build without GL says that instead of naming the device. */
    if (have_gl)
        assert_non_null(strstr(rl_last_error(), "bogus"));
    assert_int_equal(rl_property_workers(p), 0);
    assert_int_equal(rl_property_set(p, "backend", "vulkan"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_set(p, "backend", "software"), RL_OK);
    assert_int_equal(rl_property_commit(p, s, 1), RL_OK);
    rl_property_sample smp = { 0 };
    assert_int_equal(rl_property_evaluate(p, 0, rl_v3(0.0f, 1.0f, 0.0f), &smp), RL_OK);
    assert_true(smp.value > 0.0);
    rl_property_release(p);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gl_visibility_matches_software_on_every_builtin_scene),
        cmocka_unit_test(test_gpu_counts_equal_cpu_counts_of_the_same_frame),
        cmocka_unit_test(test_gl_visibility_honours_alpha_masks),
        cmocka_unit_test(test_gl_visibility_clips_at_the_near_plane),
        cmocka_unit_test(test_gl_visibility_workers_share_the_counter),
        cmocka_unit_test(test_gl_visibility_unavailable_is_a_clear_error),
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
