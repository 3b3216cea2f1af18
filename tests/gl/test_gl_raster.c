/* The GL backend against the software one: gl-raster draws every built-in
 * scene as raster does (SSIM >= 0.99, object IDs equal at >= 99.9 % of
 * pixels, eye depth to float rounding), the GL drawer honours every draw
 * flag, answers occlusion queries and draws points as the software drawer
 * does, and a device that cannot be opened makes the renderer unavailable
 * with a reason, not a crash. Runs on llvmpipe (Mesa's surfaceless EGL);
 * where no GL 4.5 context can be made the GL cases say so and skip. */
#include <math.h>
#include <pthread.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "render/render_fixtures.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "rl/rl_metrics.h"

#include "gl_fixtures.h"

#define W 96
#define H 72

/* How two frames of the same view agree. */
typedef struct agreement {
    double ssim;
    double ids;                   /* share of pixels with equal object IDs */
    double depth;                 /* largest relative eye-depth difference where both drew */
} agreement;

static agreement compare(const rl_image *gl, const rl_image *sw)
{
    agreement a = { 0 };
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(gl, sw, NULL, &m), RL_OK);
    a.ssim = m.ssim;
    const size_t n = (size_t)gl->width * (size_t)gl->height;
    size_t same = 0;
    for (size_t i = 0; i < n; ++i) {
        same += gl->object_id[i] == sw->object_id[i];
        if (gl->object_id[i] == sw->object_id[i] && isfinite(sw->depth[i]) && sw->depth[i] > 0.0f) {
            double rel = fabs((double)gl->depth[i] - sw->depth[i]) / sw->depth[i];
            a.depth = rel > a.depth ? rel : a.depth;
        }
    }
    a.ids = (double)same / (double)n;
    return a;
}

static void test_gl_raster_matches_raster_on_every_builtin_scene(void **state)
{
    (void)state;
    NEED_GL();
    static const char *const shadings[] = { "flat", "gouraud", "textured" };
    size_t count = 0;
    const rl_builtin_info *scenes = rl_builtin_scenes(&count);
    assert_true(count >= 8);
    for (size_t i = 0; i < count; ++i) {
        /* city at its default size is 1.4 M triangles: seconds per frame
         * on llvmpipe; two blocks keep every kind of its geometry. */
        const char *params = strcmp(scenes[i].name, "city") == 0 ? "blocks=2" : NULL;
        rl_scene *s = NULL;
        assert_int_equal(rl_scene_create_builtin(scenes[i].name, params, &s), RL_OK);
        rl_camera cam;
        assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
        cam.width = W;
        cam.height = H;
        for (int k = 0; k < 3; ++k) {
            const char *opts[] = { "shading", shadings[k], NULL };
            rl_render_stats gs = { 0 }, ss = { 0 };
            rl_image *gl = fx_render("gl-raster", s, &cam, FX_ALL_LAYERS, opts, &gs);
            rl_image *sw = fx_render("raster", s, &cam, FX_ALL_LAYERS, opts, &ss);
            agreement a = compare(gl, sw);
            print_message("%-14s %-8s SSIM %.5f, IDs %.4f %%, depth %.1e, pixels %llu / %llu\n", scenes[i].name,
                          shadings[k], a.ssim, 100.0 * a.ids, a.depth, (unsigned long long)gs.pixels_written,
                          (unsigned long long)ss.pixels_written);
            assert_true(a.ssim >= 0.99);
            assert_true(a.ids >= 0.999);
            assert_true(a.depth < 1e-4);
            assert_non_null(gs.device);
            assert_null(ss.device);
            rl_image_release(gl);
            rl_image_release(sw);
        }
        rl_scene_release(s);
    }
}

/* One frame of drawer dr into img (cleared to grey first unless keep). */
static void draw_frame(rl_drawer *dr, rl_image *img, const rl_camera *cam, const rl_scene *s, bool keep)
{
    if (!keep)
        rl_image_clear_to(img, rl_v4(0.25f, 0.25f, 0.25f, 1.0f));
    assert_int_equal(rl_drawer_begin_camera(dr, img, cam, rl_scene_get_data(s)->bounds), RL_OK);
    assert_int_equal(rl_drawer_draw_all(dr, NULL, NULL, NULL), RL_OK);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
}

static rl_image *new_image(void)
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(W, H, FX_ALL_LAYERS, &img), RL_OK);
    return img;
}

/* Every flag of rl_raster_flags that a drawer's desc may carry, each on
 * both backends: the layers a flag leaves alone stay as they were, the
 * others agree. The last case adds a second DEPTH_EQUAL | BLEND_ADD pass
 * (Ullmann 2003, Sec. 3.5.4) over the first. */
static void test_gl_drawer_honours_the_draw_flags(void **state)
{
    (void)state;
    NEED_GL();
    rl_camera cam;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell-teapot", NULL, &s), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = W;
    cam.height = H;
    const unsigned cases[] = { 0, RL_RASTER_CULL_BACK, RL_RASTER_NO_COLOR, RL_RASTER_NO_ID, RL_RASTER_NO_DEPTH,
                               RL_RASTER_NO_DEPTH_TEST };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        rl_drawer_desc desc = { .shading = RL_SHADING_GOURAUD, .ambient = 0.05f, .flags = cases[c] };
        rl_drawer *gd = NULL, *sd = NULL;
        assert_int_equal(rl_gl_drawer_create(s, &desc, NULL, &gd), RL_OK);
        assert_int_equal(rl_drawer_create(s, &desc, &sd), RL_OK);
        assert_string_equal(rl_drawer_backend(gd), "gl");
        rl_image *gl = new_image(), *sw = new_image();
        draw_frame(gd, gl, &cam, s, false);
        draw_frame(sd, sw, &cam, s, false);
        agreement a = compare(gl, sw);
        print_message("flags 0x%02x: SSIM %.5f, IDs %.4f %%\n", cases[c], a.ssim, 100.0 * a.ids);
        assert_true(a.ssim >= 0.99);
        assert_true(a.ids >= 0.999);
        const size_t n = (size_t)W * H;
        size_t touched_color = 0, touched_id = 0, touched_depth = 0;
        for (size_t i = 0; i < n; ++i) {
            touched_color += gl->color[i].x != 0.25f;
            touched_id += gl->object_id[i] != RL_ID_NONE;
            touched_depth += !isinf(gl->depth[i]);
        }
        assert_int_equal(touched_color == 0, (cases[c] & RL_RASTER_NO_COLOR) != 0);
        assert_int_equal(touched_id == 0, (cases[c] & RL_RASTER_NO_ID) != 0);
        assert_int_equal(touched_depth == 0, (cases[c] & RL_RASTER_NO_DEPTH) != 0);
        if (cases[c] == 0) {
            /* The additive second pass: every visible surface twice. */
            rl_drawer_desc add = desc;
            add.flags = RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD;
            rl_drawer *ga = NULL, *sa = NULL;
            assert_int_equal(rl_gl_drawer_create(s, &add, NULL, &ga), RL_OK);
            assert_int_equal(rl_drawer_create(s, &add, &sa), RL_OK);
            rl_image *once = new_image();
            memcpy(once->color, gl->color, n * sizeof *once->color);
            draw_frame(ga, gl, &cam, s, true);
            draw_frame(sa, sw, &cam, s, true);
            a = compare(gl, sw);
            print_message("second pass DEPTH_EQUAL | BLEND_ADD: SSIM %.5f\n", a.ssim);
            assert_true(a.ssim >= 0.99);
            size_t doubled = 0, drawn = 0;
            for (size_t i = 0; i < n; ++i) {
                if (gl->object_id[i] == RL_ID_NONE)
                    continue;
                drawn++;
                doubled += fabsf(gl->color[i].x - 2.0f * once->color[i].x) <= 1e-5f * (1.0f + once->color[i].x);
            }
            assert_true(doubled >= drawn * 999 / 1000);
            rl_image_release(once);
            rl_drawer_release(ga);
            rl_drawer_release(sa);
        }
        rl_image_release(gl);
        rl_image_release(sw);
        rl_drawer_release(gd);
        rl_drawer_release(sd);
    }
    rl_scene_release(s);
}

/* Occlusion queries and points, the two other things culling and
 * level-of-detail renderers ask of a drawer, against the software one. */
static void test_gl_drawer_queries_and_points(void **state)
{
    (void)state;
    NEED_GL();
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, W);
    cam.height = H;
    cam = rl_camera_resolve(&cam);
    const float dist = rl_length(rl_sub(cam.target, cam.eye));
    rl_drawer_desc desc = { .shading = RL_SHADING_GOURAUD };
    rl_drawer *dr[2] = { NULL, NULL };
    assert_int_equal(rl_gl_drawer_create(s, &desc, NULL, &dr[0]), RL_OK);
    assert_int_equal(rl_drawer_create(s, &desc, &dr[1]), RL_OK);
    rl_image *img[2] = { new_image(), new_image() };
    uint64_t front[2], behind[2];
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_vec3 near_quad[4], far_quad[4];
    /* Inside the box's opening (the clip range starts at the box), and
     * just behind its back wall. */
    fx_view_quad(&cam, 1.06f * dist, 0.06f * dist, near_quad);
    fx_view_quad(&cam, 1.9f * dist, 0.1f * dist, far_quad);
    for (int b = 0; b < 2; ++b) {
        rl_image_clear(img[b]);
        assert_int_equal(rl_drawer_begin_camera(dr[b], img[b], &cam, rl_scene_get_data(s)->bounds), RL_OK);
        assert_int_equal(rl_drawer_draw_all(dr[b], NULL, NULL, NULL), RL_OK);
        rl_raster_batch q = { .num_vertices = 4, .positions = near_quad, .num_triangles = 2, .indices = idx };
        rl_raster_counters c = { 0 };
        assert_int_equal(rl_drawer_query(dr[b], &q, &front[b], &c), RL_OK);
        assert_int_equal(c.triangles_in, 2);
        q.positions = far_quad;
        assert_int_equal(rl_drawer_query(dr[b], &q, &behind[b], NULL), RL_OK);
        assert_int_equal(rl_drawer_end(dr[b]), RL_OK);
    }
    print_message("query: near quad %llu (software %llu) pixels, quad behind the box %llu (%llu)\n",
                  (unsigned long long)front[0], (unsigned long long)front[1], (unsigned long long)behind[0],
                  (unsigned long long)behind[1]);
    assert_true(front[1] > 50);
    assert_true(llabs((long long)front[0] - (long long)front[1]) <= (long long)front[1] / 50);
    assert_int_equal(behind[0], 0);
    assert_int_equal(behind[1], 0);
    /* Nothing written by the queries: the frames still agree. */
    agreement a = compare(img[0], img[1]);
    assert_true(a.ids >= 0.999);

    /* Points of sizes 1..4 px inside the box, each its own object. */
    enum { NP = 200 };
    rl_vec3 pos[NP];
    rl_vec4 col[NP];
    float size[NP];
    uint32_t obj[NP];
    const rl_aabb box = rl_scene_get_data(s)->bounds;
    rl_rng rng;
    rl_rng_seed(&rng, 7, 0);
    for (int i = 0; i < NP; ++i) {
        rl_vec3 t = rl_v3(0.1f + 0.8f * rl_rng_float(&rng), 0.1f + 0.8f * rl_rng_float(&rng),
                          0.1f + 0.8f * rl_rng_float(&rng));
        pos[i] = rl_add(box.min, rl_mul(t, rl_sub(box.max, box.min)));
        col[i] = rl_v4(rl_rng_float(&rng), 0.5f, 0.25f, 1.0f);
        size[i] = (float)(1 + i % 4);
        obj[i] = 100 + (uint32_t)i;
    }
    rl_raster_points pts = { .count = NP, .positions = pos, .colors = col, .sizes_px = size, .object_ids = obj };
    for (int b = 0; b < 2; ++b) {
        rl_image_clear(img[b]);
        rl_raster_counters c = { 0 };
        assert_int_equal(rl_drawer_begin_camera(dr[b], img[b], &cam, rl_scene_get_data(s)->bounds), RL_OK);
        assert_int_equal(rl_drawer_draw_points(dr[b], &pts, &c), RL_OK);
        assert_int_equal(rl_drawer_end(dr[b]), RL_OK);
        assert_int_equal(c.points_drawn, NP);
    }
    size_t covered = 0, same = 0;
    for (size_t i = 0; i < (size_t)W * H; ++i) {
        if (img[0]->object_id[i] == RL_ID_NONE && img[1]->object_id[i] == RL_ID_NONE)
            continue;
        covered++;
        same += img[0]->object_id[i] == img[1]->object_id[i] && img[0]->triangle_id[i] == img[1]->triangle_id[i] &&
                img[0]->color[i].x == img[1]->color[i].x;
    }
    print_message("points: %zu of %zu covered pixels agree\n", same, covered);
    assert_true(covered > NP);
    /* GL rasterizes a point's square by its own rule; pixels on the edge
     * of a square may fall the other way (about 1.5 % of them here). */
    assert_true(same >= covered * 97 / 100);
    for (int b = 0; b < 2; ++b) {
        rl_image_release(img[b]);
        rl_drawer_release(dr[b]);
    }
    rl_scene_release(s);
}

/* What a worker thread renders: one frame of r (the renderer's drawer and
 * context made on whichever thread renders first). */
typedef struct frame_job {
    rl_renderer *r;
    const rl_scene *s;
    const rl_camera *cam;
    rl_image *img;
    rl_status st;
} frame_job;

static void *render_job(void *arg)
{
    frame_job *j = arg;
    j->st = rl_renderer_render(j->r, j->s, j->cam, j->img, NULL);
    return NULL;
}

/* A renderer moves between threads (rl compare evaluates positions on an
 * OpenMP pool and releases its renderers on the main thread): every frame
 * on another thread works, and releasing on a third frees the context
 * (LSan in the sanitizer build sees a leak otherwise). */
static void test_gl_renderer_moves_between_threads(void **state)
{
    (void)state;
    NEED_GL();
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 32);
    rl_renderer *r = fx_make("gl-raster", NULL);
    rl_image *ref = fx_render_with(r, s, &cam, FX_ALL_LAYERS, NULL);
    for (int k = 0; k < 2; ++k) {
        frame_job job = { r, s, &cam, NULL, RL_ERR_INTERNAL };
        assert_int_equal(rl_image_create(32, 32, FX_ALL_LAYERS, &job.img), RL_OK);
        pthread_t t;
        assert_int_equal(pthread_create(&t, NULL, render_job, &job), 0);
        assert_int_equal(pthread_join(t, NULL), 0);
        if (job.st != RL_OK)
            print_error("frame on thread %d: %s\n", k, rl_last_error());
        assert_int_equal(job.st, RL_OK);
        fx_assert_images_identical(job.img, ref);
        rl_image_release(job.img);
    }
    rl_renderer_release(r);
    rl_image_release(ref);
    rl_scene_release(s);
}

/* A device that cannot be opened: unavailable with a reason, both from the
 * platform and from the renderer; rendering fails cleanly. Needs no GL. */
static void test_gl_unopenable_device_is_reported_unavailable(void **state)
{
    (void)state;
    char why[256] = "";
    assert_false(rl_gl_available("bogus", why, sizeof why));
    assert_non_null(strstr(why, "bogus"));
    assert_false(rl_gl_available("15", why, sizeof why));
    assert_true(strlen(why) > 0);
    rl_gl_info info;
    assert_int_equal(rl_gl_info_get("bogus", &info), RL_ERR_UNSUPPORTED);

    rl_renderer *r = fx_make("gl-raster", (const char *const[]){ "device", "bogus", NULL });
    assert_false(rl_renderer_available(r, why, sizeof why));
    assert_non_null(strstr(why, "bogus"));
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_UNSUPPORTED);
    assert_non_null(strstr(rl_last_error(), "unavailable"));
    rl_drawer *dr = NULL;
    assert_int_equal(rl_gl_drawer_create(s, NULL, "bogus", &dr), RL_ERR_UNSUPPORTED);
    assert_null(dr);
    /* The CPU renderers are always available. */
    rl_renderer *raster = fx_make("raster", NULL);
    assert_true(rl_renderer_available(raster, why, sizeof why));
    rl_renderer_release(raster);
    rl_image_release(img);
    rl_scene_release(s);
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gl_raster_matches_raster_on_every_builtin_scene),
        cmocka_unit_test(test_gl_drawer_honours_the_draw_flags),
        cmocka_unit_test(test_gl_drawer_queries_and_points),
        cmocka_unit_test(test_gl_renderer_moves_between_threads),
        cmocka_unit_test(test_gl_unopenable_device_is_reported_unavailable),
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
