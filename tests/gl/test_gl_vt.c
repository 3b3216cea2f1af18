/* Vertex Tracing's reconstruction on GL (issue 35, part 5; Ullmann 2003,
 * Sec. 3.5): vt with reconstruct=gl draws the image of reconstruct=software
 * (the refined mesh is the same: the pre-pass and the refinement stay on
 * the CPU) within SSIM 0.99, in every texture mode (multitexture, eq.
 * 3.20; multipass, eq. 3.22; sampled), progressive overdraw (eq. 3.16)
 * and redraw, on table (the hybrid: glass and mirror traced, the rest
 * rasterized) and cornell (every object traced), and on a mirror floor
 * whose faces see two different textures in their reflection (undefined
 * faces, Fig. 3.21); rl_drawer_draw_batch on GL draws what the rasterizer
 * draws; without GL, vt says why. Runs on llvmpipe; the GL cases skip
 * without a GL 4.5 context. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "render/render_fixtures.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "rl/rl_metrics.h"
#include "rl/rl_vt.h"

#include "gl_fixtures.h"

#define MAX_OPTS 16

/* vt on s with opts, software and GL; returns the SSIM and checks the
 * object IDs agree at 99 % of the pixels. */
static double vt_both(const rl_scene *s, const rl_camera *cam, const char *const *opts, const char *what)
{
    const char *sw_opts[MAX_OPTS + 1] = { NULL }, *gl_opts[MAX_OPTS + 3] = { NULL };
    size_t n = 0;
    for (; opts && opts[n]; ++n) {
        assert_true(n < MAX_OPTS);
        sw_opts[n] = gl_opts[n] = opts[n];
    }
    gl_opts[n] = "reconstruct";
    gl_opts[n + 1] = "gl";
    rl_render_stats a, b;
    rl_image *sw = fx_render("vt", s, cam, FX_ALL_LAYERS, sw_opts, &a);
    rl_image *gl = fx_render("vt", s, cam, FX_ALL_LAYERS, gl_opts, &b);
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(gl, sw, NULL, &m), RL_OK);
    size_t px = (size_t)cam->width * (size_t)cam->height, same = 0, differ = 0;
    float worst = 0.0f;
    for (size_t i = 0; i < px; ++i) {
        same += gl->object_id[i] == sw->object_id[i];
        float d = fmaxf(fabsf(gl->color[i].x - sw->color[i].x),
                        fmaxf(fabsf(gl->color[i].y - sw->color[i].y), fabsf(gl->color[i].z - sw->color[i].z)));
        differ += d > 0.0f;
        worst = fmaxf(worst, d);
    }
    print_message("%-44s SSIM %.5f, RMSE %.2g, %zu pixels differ (at most %.2g), object IDs %.3f %%, "
                  "primary rays %llu\n", what, m.ssim, m.rmse, differ, (double)worst,
                  100.0 * (double)same / (double)px, (unsigned long long)a.rays[RL_RAY_PRIMARY]);
    /* The same refinement traces the same rays. */
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        assert_int_equal(a.rays[k], b.rays[k]);
    assert_true((double)same >= 0.99 * (double)px);
    rl_image_release(sw);
    rl_image_release(gl);
    return m.ssim;
}

static void test_vt_gl_matches_software_on_table_and_cornell(void **state)
{
    (void)state;
    NEED_GL();
    static const char *const modes[] = { "multitexture", "multipass", "sampled" };
    for (int i = 0; i < 2; ++i) {
        rl_scene *s = NULL;
        rl_camera cam;
        assert_int_equal(rl_scene_create_builtin(i ? "cornell" : "table", NULL, &s), RL_OK);
        assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
        cam.width = 96;
        cam.height = 72;
        const char *objects = i ? "all" : "auto";
        for (int m = 0; m < 3; ++m) {
            char what[96];
            snprintf(what, sizeof what, "%s, objects=%s, textures=%s", i ? "cornell" : "table", objects, modes[m]);
            const char *const opts[] = { "objects", objects, "textures", modes[m], "min_edge", "2", NULL };
            assert_true(vt_both(s, &cam, opts, what) >= 0.99);
        }
        rl_scene_release(s);
    }
}

/* Sec. 3.5.1: the progressive modes draw through the update callback;
 * overdraw moves each stage's faces towards the eye by eq. 3.16, redraw
 * starts each update again from the kept rasterized half. */
static void test_vt_gl_progressive(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = NULL;
    rl_camera cam;
    assert_int_equal(rl_scene_create_builtin("table", NULL, &s), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = 96;
    cam.height = 72;
    static const char *const prog[] = { "overdraw", "redraw" };
    for (int p = 0; p < 2; ++p) {
        char what[64];
        snprintf(what, sizeof what, "table, progressive=%s", prog[p]);
        const char *const opts[] = { "progressive", prog[p], "update_every", "2", "min_edge", "2", NULL };
        assert_true(vt_both(s, &cam, opts, what) >= 0.99);
    }
    rl_scene_release(s);
}

/* A w x w grid of quads of side 2 * half in the plane y = 0 (facing +y),
 * placed by the node transform m, of material mat: Vertex Tracing starts
 * from the mesh's vertices. */
static void add_grid(rl_scene *s, const char *name, int w, float half, uint32_t mat, const rl_mat4 *m)
{
    const size_t nv = (size_t)(w + 1) * (size_t)(w + 1);
    rl_vec3 *pos = calloc(nv, sizeof *pos);
    rl_vec2 *uv = calloc(nv, sizeof *uv);
    uint32_t *idx = calloc((size_t)(6 * w * w), sizeof *idx);
    assert_true(pos && uv && idx);
    for (int z = 0; z <= w; ++z)
        for (int x = 0; x <= w; ++x) {
            size_t v = (size_t)z * (size_t)(w + 1) + (size_t)x;
            pos[v] = rl_v3(-half + 2.0f * half * (float)x / (float)w, 0.0f, -half + 2.0f * half * (float)z / (float)w);
            uv[v] = rl_v2((float)x / (float)w, (float)z / (float)w);
        }
    size_t k = 0;
    for (int z = 0; z < w; ++z)
        for (int x = 0; x < w; ++x) {
            uint32_t a = (uint32_t)(z * (w + 1) + x), b = a + 1, c = a + (uint32_t)(w + 1), d = c + 1;
            /* Counter-clockwise seen from +y. */
            const uint32_t q[6] = { a, c, b, b, c, d };
            memcpy(&idx[k], q, sizeof q);
            k += 6;
        }
    rl_mesh_desc md = { .name = name, .num_vertices = (uint32_t)nv, .positions = pos, .uvs = uv,
                        .num_triangles = (uint32_t)(2 * w * w), .indices = idx, .material = mat };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, name, m, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    free(pos);
    free(uv);
    free(idx);
}

static uint32_t checker(rl_scene *s, const char *name, rl_vec4 a, rl_vec4 b, float reflect)
{
    enum { T = 16 };
    rl_vec4 texels[T * T];
    for (int y = 0; y < T; ++y)
        for (int x = 0; x < T; ++x)
            texels[y * T + x] = ((x / 2 + y / 2) % 2) ? a : b;
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(T, T, texels, &tex), RL_OK);
    uint32_t tex_id, mat;
    assert_int_equal(rl_scene_add_texture(s, tex, &tex_id), RL_OK);
    rl_material m = rl_material_default();
    snprintf(m.name, sizeof m.name, "%s", name);
    m.diffuse = rl_v3(0.8f, 0.8f, 0.8f);
    m.reflectivity = reflect;
    m.diffuse_texture = tex_id;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    return mat;
}

/* Fig. 3.21: a textured mirror floor (2 x 2 coarse faces) reflecting two
 * walls side by side with different textures: the faces whose vertices
 * see both walls (or a wall and nothing) are undefined for the reflection
 * term, whose looked-up radiance is interpolated instead (vt_draw.c
 * defined_texture). Counted once with a probe in fill_face: 24 of the 108
 * faces drawn per frame are undefined in their reflection. */
static void test_vt_gl_undefined_faces(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t floor = checker(s, "floor", rl_v4(0.9f, 0.9f, 0.9f, 1.0f), rl_v4(0.2f, 0.2f, 0.2f, 1.0f), 0.5f);
    uint32_t red = checker(s, "red", rl_v4(0.9f, 0.1f, 0.1f, 1.0f), rl_v4(0.3f, 0.0f, 0.0f, 1.0f), 0.0f);
    uint32_t blue = checker(s, "blue", rl_v4(0.1f, 0.2f, 0.9f, 1.0f), rl_v4(0.0f, 0.0f, 0.3f, 1.0f), 0.0f);
    rl_mat4 id = rl_mat4_identity();
    add_grid(s, "floor", 2, 2.0f, floor, &id);
    rl_mat4 turn = rl_mat4_rotate(rl_v3(1.0f, 0.0f, 0.0f), 1.5707963f);
    for (int side = 0; side < 2; ++side) {
        rl_mat4 move = rl_mat4_translate(rl_v3(side ? 1.0f : -1.0f, 1.0f, -2.0f));
        rl_mat4 m = rl_mat4_mul(&move, &turn);
        rl_mat4 scale = rl_mat4_scale(rl_v3(0.5f, 1.0f, 0.5f));
        m = rl_mat4_mul(&m, &scale);
        add_grid(s, side ? "right" : "left", 4, 2.0f, side ? blue : red, &m);
    }
    rl_light l = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(1, 1, 1), .intensity = 1.0f,
                   .direction = rl_normalize(rl_v3(0.2f, -1.0f, -0.5f)) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_camera cam = { .eye = rl_v3(0.0f, 1.6f, 3.2f), .target = rl_v3(0.0f, 0.3f, -0.5f), .up = rl_v3(0, 1, 0),
                      .fov_deg = 50.0f, .width = 96, .height = 96 };
    static const char *const modes[] = { "multitexture", "multipass" };
    for (int m = 0; m < 2; ++m) {
        char what[64];
        snprintf(what, sizeof what, "undefined faces, textures=%s", modes[m]);
        /* A coarse mesh (min_edge 24 px) keeps faces that span both walls'
         * reflections. */
        const char *const opts[] = { "objects", "all", "textures", modes[m], "min_edge", "24", NULL };
        assert_true(vt_both(s, &cam, opts, what) >= 0.99);
    }
    rl_scene_release(s);
}

/* rl_drawer_draw_batch: a layered batch (two layers, one textured) and a
 * Gouraud one on the software and the GL drawer give the same image; a
 * batch the GL drawer cannot draw is refused with RL_ERR_UNSUPPORTED. */
static void test_draw_batch_on_both_drawers(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t mat = checker(s, "floor", rl_v4(0.9f, 0.9f, 0.9f, 1.0f), rl_v4(0.2f, 0.3f, 0.6f, 1.0f), 0.0f);
    rl_mat4 id = rl_mat4_identity();
    add_grid(s, "floor", 1, 2.0f, mat, &id);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_camera cam = { .eye = rl_v3(0.0f, 2.0f, 3.0f), .target = rl_v3(0.0f, 0.0f, 0.0f), .up = rl_v3(0, 1, 0),
                      .fov_deg = 50.0f, .width = 64, .height = 48 };
    const rl_vec3 pos[4] = { { -1, 0, -1 }, { -1, 0, 1 }, { 1, 0, -1 }, { 1, 0, 1 } };
    const uint32_t idx[6] = { 0, 1, 2, 2, 1, 3 };
    const rl_vec4 col0[4] = { { 1, 0, 0, 1 }, { 0, 1, 0, 1 }, { 0, 0, 1, 1 }, { 1, 1, 1, 1 } };
    const rl_vec4 col1[4] = { { 0.1f, 0.1f, 0.1f, 1 }, { 0.2f, 0, 0, 1 }, { 0, 0.2f, 0, 1 }, { 0, 0, 0.2f, 1 } };
    const rl_vec2 uv[4] = { { 0, 0 }, { 0, 3 }, { 3, 0 }, { 3, 3 } };
    const uint32_t tex[2] = { 0, RL_NONE };
    const uint32_t tri_ids[2] = { 7, 9 };
    rl_raster_layer layers[2] = { { col0, uv, tex, d->textures }, { col1, NULL, NULL, NULL } };
    rl_raster_batch layered = { .num_vertices = 4, .positions = pos, .num_triangles = 2, .indices = idx,
                                .triangle_ids = tri_ids, .object_id = 3, .num_layers = 2, .layers = layers };
    rl_raster_batch gouraud = { .num_vertices = 4, .positions = pos, .colors = col0, .num_triangles = 2,
                                .indices = idx, .first_triangle_id = 20, .object_id = 5 };
    rl_drawer *dr[2] = { NULL, NULL };
    assert_int_equal(rl_drawer_create(s, NULL, &dr[0]), RL_OK);
    assert_int_equal(rl_gl_drawer_create(s, NULL, NULL, &dr[1]), RL_OK);
    const rl_raster_batch *batches[2] = { &layered, &gouraud };
    for (int b = 0; b < 2; ++b) {
        rl_image *img[2];
        for (int k = 0; k < 2; ++k) {
            assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &img[k]), RL_OK);
            rl_image_clear(img[k]);
            assert_int_equal(rl_drawer_begin_camera(dr[k], img[k], &cam, d->bounds), RL_OK);
            rl_raster_counters c = { 0 };
            assert_int_equal(rl_drawer_draw_batch(dr[k], batches[b], &c), RL_OK);
            print_message("draw_batch %d on %s: %llu pixels\n", b, rl_drawer_backend(dr[k]),
                          (unsigned long long)c.pixels_written);
            assert_int_equal(c.triangles_in, 2);
            assert_true(c.pixels_written > 300);
            assert_int_equal(rl_drawer_end(dr[k]), RL_OK);
        }
        rl_image_metrics m;
        assert_int_equal(rl_image_compare(img[1], img[0], NULL, &m), RL_OK);
        size_t px = (size_t)cam.width * (size_t)cam.height, same = 0;
        for (size_t i = 0; i < px; ++i)
            same += img[0]->triangle_id[i] == img[1]->triangle_id[i] && img[0]->object_id[i] == img[1]->object_id[i];
        print_message("draw_batch %s: SSIM %.5f, IDs %.3f %%\n", b ? "gouraud" : "layered", m.ssim,
                      100.0 * (double)same / (double)px);
        assert_true(m.ssim >= 0.99);
        assert_true((double)same >= 0.99 * (double)px);
        rl_image_release(img[0]);
        rl_image_release(img[1]);
    }
    /* Face colours are the software's alone. */
    const rl_vec4 faces[2] = { { 1, 0, 0, 1 }, { 0, 1, 0, 1 } };
    rl_raster_batch flat = { .num_vertices = 4, .positions = pos, .face_colors = faces, .num_triangles = 2,
                             .indices = idx };
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &img), RL_OK);
    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(dr[1], img, &cam, d->bounds), RL_OK);
    assert_int_equal(rl_drawer_draw_batch(dr[1], &flat, NULL), RL_ERR_UNSUPPORTED);
    /* An index past the vertices is refused before anything is drawn. */
    const uint32_t bad[6] = { 0, 1, 2, 2, 1, 4 };
    gouraud.indices = bad;
    assert_int_equal(rl_drawer_begin_camera(dr[1], img, &cam, d->bounds), RL_OK);
    assert_int_equal(rl_drawer_draw_batch(dr[1], &gouraud, NULL), RL_ERR_INVALID_ARG);
    rl_image_release(img);
    rl_drawer_release(dr[0]);
    rl_drawer_release(dr[1]);
    rl_scene_release(s);
}

static void test_vt_reconstruct_gl_unavailable_says_why(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("vt", (const char *const[]){ "reconstruct", "gl", "device", "99", NULL });
    char why[512];
    assert_false(rl_renderer_available(r, why, sizeof why));
    print_message("reconstruct=gl on device 99: %s\n", why);
    assert_non_null(strstr(why, "reconstruct=gl"));
    rl_renderer_release(r);
    r = fx_make("vt", (const char *const[]){ "device", "99", NULL });
    assert_true(rl_renderer_available(r, why, sizeof why));
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_vt_gl_matches_software_on_table_and_cornell),
        cmocka_unit_test(test_vt_gl_progressive),
        cmocka_unit_test(test_vt_gl_undefined_faces),
        cmocka_unit_test(test_draw_batch_on_both_drawers),
        cmocka_unit_test(test_vt_reconstruct_gl_unavailable_says_why),
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
