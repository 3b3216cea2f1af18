/* The culling renderers on the GL drawer (drawer=gl) and the asynchronous
 * occlusion queries that chcpp hides its latency with: the software
 * backend answers issue / poll / result as the synchronous query does; on
 * GL, queries in flight are answered against the depth buffer of their
 * issue; chcpp on GL stays conservative (the IDs of gl-raster on the walks
 * of tests/render/test_chcpp.c, 26 frames); svs, visset, select and surfels
 * on GL draw what their software versions draw; with a device that cannot
 * be opened each of them says why instead of rendering. Runs on llvmpipe;
 * where no GL 4.5 context can be made the GL cases skip. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "render/render_fixtures.h"
#include "rl/rl_culling.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "rl/rl_metrics.h"

#include "gl_fixtures.h"

/* Queries on one drawer: a quad behind the Cornell box's back wall issued
 * before the box is drawn, and again after; both read after the second
 * issue. Each answers for the depth buffer of its issue: visible, then
 * hidden. The synchronous query and the pool's reuse of slots agree. */
static void check_async_queries(rl_drawer *dr, const rl_scene *s, const rl_camera *cam, uint64_t *before_px)
{
    const float dist = rl_length(rl_sub(cam->target, cam->eye));
    rl_vec3 quad[4];
    fx_view_quad(cam, 1.9f * dist, 0.1f * dist, quad);
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_raster_batch q = { .num_vertices = 4, .positions = quad, .num_triangles = 2, .indices = idx };
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam->width, cam->height, FX_ALL_LAYERS, &img), RL_OK);
    rl_image_clear(img);
    uint32_t h = 0;
    bool ready = false;
    uint64_t px = 0;
    /* Outside a frame nothing is open. */
    assert_int_equal(rl_drawer_query_issue(dr, &q, &h, NULL), RL_ERR_INVALID_ARG);
    for (int frame = 0; frame < 2; ++frame) {
        rl_image_clear(img);
        assert_int_equal(rl_drawer_begin_camera(dr, img, cam, rl_scene_get_data(s)->bounds), RL_OK);
        rl_raster_counters c = { 0 };
        uint32_t before = 0, after = 0;
        assert_int_equal(rl_drawer_query_issue(dr, &q, &before, &c), RL_OK);
        assert_int_equal(c.triangles_in, 2);
        assert_int_equal(rl_drawer_draw_all(dr, NULL, NULL, NULL), RL_OK);
        assert_int_equal(rl_drawer_query_issue(dr, &q, &after, NULL), RL_OK);
        assert_int_not_equal(before, after);
        uint64_t sync_px = 1;
        assert_int_equal(rl_drawer_query(dr, &q, &sync_px, NULL), RL_OK);
        assert_int_equal(sync_px, 0);
        /* Polling never blocks and, once true, stays true. */
        assert_int_equal(rl_drawer_query_poll(dr, after, &ready), RL_OK);
        assert_int_equal(rl_drawer_query_result(dr, after, &px), RL_OK);
        assert_int_equal(px, 0);
        assert_int_equal(rl_drawer_query_result(dr, before, before_px), RL_OK);
        assert_true(*before_px > 50);
        /* A read handle is closed; an unknown one never was. */
        assert_int_equal(rl_drawer_query_poll(dr, after, &ready), RL_ERR_INVALID_ARG);
        assert_int_equal(rl_drawer_query_result(dr, before, &px), RL_ERR_INVALID_ARG);
        assert_int_equal(rl_drawer_query_result(dr, 12345, &px), RL_ERR_INVALID_ARG);
        assert_int_equal(rl_drawer_query_poll(dr, 0, NULL), RL_ERR_INVALID_ARG);
        /* One left unread: the frame's end drops it. */
        assert_int_equal(rl_drawer_query_issue(dr, &q, &h, NULL), RL_OK);
        assert_int_equal(rl_drawer_end(dr), RL_OK);
    }
    assert_int_equal(rl_drawer_query_poll(dr, h, &ready), RL_ERR_INVALID_ARG);
    rl_image_release(img);
}

/* A kept query outlives its frame (CHC++ reads previously visible nodes'
 * answers a frame later): the next frame reads the answer of its own
 * frame's depth buffer; kept again it lives one more frame; one never kept
 * or not kept again is dropped at the frame's end. */
static void check_kept_queries(rl_drawer *dr, const rl_scene *s, const rl_camera *cam)
{
    const float dist = rl_length(rl_sub(cam->target, cam->eye));
    rl_vec3 quad[4];
    fx_view_quad(cam, 1.9f * dist, 0.1f * dist, quad);
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_raster_batch q = { .num_vertices = 4, .positions = quad, .num_triangles = 2, .indices = idx };
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam->width, cam->height, FX_ALL_LAYERS, &img), RL_OK);
    const rl_aabb bounds = rl_scene_get_data(s)->bounds;
    uint32_t seen = 0, hidden = 0, lost = 0, fresh = 0;
    uint64_t px = 0;
    bool ready = false;
    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(dr, img, cam, bounds), RL_OK);
    assert_int_equal(rl_drawer_query_issue(dr, &q, &seen, NULL), RL_OK);
    assert_int_equal(rl_drawer_draw_all(dr, NULL, NULL, NULL), RL_OK);
    assert_int_equal(rl_drawer_query_issue(dr, &q, &hidden, NULL), RL_OK);
    assert_int_equal(rl_drawer_query_issue(dr, &q, &lost, NULL), RL_OK);
    assert_int_equal(rl_drawer_query_keep(dr, seen), RL_OK);
    assert_int_equal(rl_drawer_query_keep(dr, hidden), RL_OK);
    assert_int_equal(rl_drawer_query_keep(dr, 12345), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
    assert_int_equal(rl_drawer_query_keep(dr, seen), RL_ERR_INVALID_ARG);   /* no frame */

    /* The next frame draws nothing: a query issued now sees the quad. */
    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(dr, img, cam, bounds), RL_OK);
    assert_int_equal(rl_drawer_query_poll(dr, lost, &ready), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_drawer_query_result(dr, seen, &px), RL_OK);
    assert_true(px > 50);
    assert_int_equal(rl_drawer_query_issue(dr, &q, &fresh, NULL), RL_OK);
    assert_int_not_equal(fresh, hidden);
    assert_int_equal(rl_drawer_query_result(dr, fresh, &px), RL_OK);
    assert_true(px > 50);
    assert_int_equal(rl_drawer_query_keep(dr, hidden), RL_OK);
    assert_int_equal(rl_drawer_query_issue(dr, &q, &lost, NULL), RL_OK);
    assert_int_equal(rl_drawer_end(dr), RL_OK);

    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(dr, img, cam, bounds), RL_OK);
    assert_int_equal(rl_drawer_query_poll(dr, lost, &ready), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_drawer_query_result(dr, hidden, &px), RL_OK);
    assert_int_equal(px, 0);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
    /* The last frame kept nothing. */
    assert_int_equal(rl_drawer_begin_camera(dr, img, cam, bounds), RL_OK);
    assert_int_equal(rl_drawer_query_poll(dr, hidden, &ready), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
    rl_image_release(img);
}

static void test_async_queries_on_the_software_drawer(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 64);
    cam = rl_camera_resolve(&cam);
    rl_drawer *dr = NULL;
    assert_int_equal(rl_drawer_create(s, &(rl_drawer_desc){ .shading = RL_SHADING_GOURAUD }, &dr), RL_OK);
    uint64_t px = 0;
    check_async_queries(dr, s, &cam, &px);
    /* The software drawer answers at the issue: every poll is true. */
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(64, 64, FX_ALL_LAYERS, &img), RL_OK);
    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(dr, img, &cam, rl_scene_get_data(s)->bounds), RL_OK);
    const uint32_t idx[3] = { 0, 1, 2 };
    rl_vec3 tri[3] = { cam.target, rl_add(cam.target, rl_v3(0.2f, 0, 0)), rl_add(cam.target, rl_v3(0, 0.2f, 0)) };
    rl_raster_batch q = { .num_vertices = 3, .positions = tri, .num_triangles = 1, .indices = idx };
    uint32_t h[100];
    for (int i = 0; i < 100; ++i) {
        assert_int_equal(rl_drawer_query_issue(dr, &q, &h[i], NULL), RL_OK);
        bool ready = false;
        assert_int_equal(rl_drawer_query_poll(dr, h[i], &ready), RL_OK);
        assert_true(ready);
    }
    uint64_t first = 0, sync = 0;
    assert_int_equal(rl_drawer_query(dr, &q, &sync, NULL), RL_OK);
    for (int i = 0; i < 100; ++i) {
        assert_int_equal(rl_drawer_query_result(dr, h[i], &first), RL_OK);
        assert_int_equal(first, sync);
    }
    assert_true(sync > 0);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
    check_kept_queries(dr, s, &cam);

    /* Simulated latency: the first query_delay polls of each query find no
     * answer, also across a frame's end; result answers anyway (a wait). */
    rl_drawer *late = NULL;
    const rl_drawer_desc delayed = { .shading = RL_SHADING_GOURAUD, .query_delay = 3 };
    assert_int_equal(rl_drawer_create(s, &delayed, &late), RL_OK);
    assert_false(rl_drawer_fits(late, s, &(rl_drawer_desc){ .shading = RL_SHADING_GOURAUD }));
    assert_true(rl_drawer_fits(late, s, &delayed));
    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(late, img, &cam, rl_scene_get_data(s)->bounds), RL_OK);
    uint32_t a = 0, b = 0;
    bool ready = true;
    assert_int_equal(rl_drawer_query_issue(late, &q, &a, NULL), RL_OK);
    assert_int_equal(rl_drawer_query_issue(late, &q, &b, NULL), RL_OK);
    for (int i = 0; i < 3; ++i) {
        assert_int_equal(rl_drawer_query_poll(late, a, &ready), RL_OK);
        assert_false(ready);
    }
    assert_int_equal(rl_drawer_query_poll(late, a, &ready), RL_OK);
    assert_true(ready);
    assert_int_equal(rl_drawer_query_poll(late, b, &ready), RL_OK);
    assert_false(ready);                  /* a's polls are not b's */
    assert_int_equal(rl_drawer_query_keep(late, b), RL_OK);
    assert_int_equal(rl_drawer_end(late), RL_OK);
    rl_image_clear(img);
    assert_int_equal(rl_drawer_begin_camera(late, img, &cam, rl_scene_get_data(s)->bounds), RL_OK);
    for (int i = 0; i < 2; ++i) {
        assert_int_equal(rl_drawer_query_poll(late, b, &ready), RL_OK);
        assert_false(ready);
    }
    assert_int_equal(rl_drawer_query_poll(late, b, &ready), RL_OK);
    assert_true(ready);
    assert_int_equal(rl_drawer_query_issue(late, &q, &a, NULL), RL_OK);
    assert_int_equal(rl_drawer_query_result(late, b, &first), RL_OK);
    assert_int_equal(first, sync);
    assert_int_equal(rl_drawer_query_result(late, a, &first), RL_OK);   /* not polled: waited for */
    assert_int_equal(first, sync);
    assert_int_equal(rl_drawer_end(late), RL_OK);
    rl_drawer_release(late);
    rl_image_release(img);
    rl_drawer_release(dr);
    rl_scene_release(s);
}

static void test_async_queries_on_the_gl_drawer(void **state)
{
    (void)state;
    NEED_GL();
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 64);
    cam = rl_camera_resolve(&cam);
    rl_drawer *gd = NULL, *sd = NULL;
    const rl_drawer_desc desc = { .shading = RL_SHADING_GOURAUD };
    assert_int_equal(rl_gl_drawer_create(s, &desc, NULL, &gd), RL_OK);
    assert_int_equal(rl_drawer_create(s, &desc, &sd), RL_OK);
    uint64_t gl_px = 0, sw_px = 0;
    check_async_queries(gd, s, &cam, &gl_px);
    check_async_queries(sd, s, &cam, &sw_px);
    check_kept_queries(gd, s, &cam);
    print_message("quad before the box: %llu pixels on GL, %llu in software\n", (unsigned long long)gl_px,
                  (unsigned long long)sw_px);
    assert_true(llabs((long long)gl_px - (long long)sw_px) <= (long long)sw_px / 50);

    /* Deferred counts: the pixels of each draw reach its counters at the
     * frame's end, the same number as read at once. */
    rl_drawer *dd = NULL;
    assert_int_equal(rl_gl_drawer_create(s, &(rl_drawer_desc){ .shading = RL_SHADING_GOURAUD,
                                                               .deferred_counts = true }, NULL, &dd), RL_OK);
    assert_false(rl_drawer_fits(dd, s, &desc));
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &img), RL_OK);
    uint64_t counted[2][2];
    rl_drawer *both[2] = { gd, dd };
    for (int k = 0; k < 2; ++k) {
        rl_raster_counters c[2] = { { 0 }, { 0 } };
        const uint32_t half = rl_scene_get_data(s)->num_objects / 2, rest[] = { half, half + 1 };
        rl_image_clear(img);
        assert_int_equal(rl_drawer_begin_camera(both[k], img, &cam, rl_scene_get_data(s)->bounds), RL_OK);
        assert_int_equal(rl_drawer_draw_all(both[k], &c[0], NULL, NULL), RL_OK);
        assert_int_equal(rl_drawer_draw(both[k], rest, 2, &c[1]), RL_OK);
        if (k == 1)
            assert_int_equal(c[0].pixels_written + c[1].pixels_written, 0);
        assert_int_equal(rl_drawer_end(both[k]), RL_OK);
        counted[k][0] = c[0].pixels_written;
        counted[k][1] = c[1].pixels_written;
    }
    assert_true(counted[0][0] > 1000);
    assert_int_equal(counted[1][0], counted[0][0]);
    assert_int_equal(counted[1][1], counted[0][1]);
    rl_image_release(img);
    rl_drawer_release(dd);
    rl_drawer_release(gd);
    rl_drawer_release(sd);
    rl_scene_release(s);
}

static rl_camera street_camera(float t)
{
    rl_camera c = { .eye = rl_v3(9.5f + 0.8f * t, 1.7f, -2.0f + 6.0f * t),
                    .target = rl_v3(9.5f + 3.0f * sinf(0.2f * t), 1.5f, 60.0f),
                    .fov_deg = 60.0f, .width = 64, .height = 64 };
    return c;
}

/* The 26 frames of test_chcpp.c's first case (16 of a random walk, 10 down
 * a street), at 64x64. */
static rl_camera walk_camera(int f, rl_rng *rng, rl_vec3 *eye, rl_vec3 *dir)
{
    if (f >= 16)
        return street_camera((float)(f - 16));
    *eye = rl_add(*eye, rl_v3(6.0f * (rl_rng_float(rng) - 0.5f), 4.0f * (rl_rng_float(rng) - 0.5f),
                              6.0f * (rl_rng_float(rng) - 0.3f)));
    eye->y = rl_maxf(eye->y, 0.5f);
    *dir = rl_normalize(rl_add(*dir, rl_v3(0.6f * (rl_rng_float(rng) - 0.5f), 0.3f * (rl_rng_float(rng) - 0.5f),
                                           0.6f * (rl_rng_float(rng) - 0.5f))));
    return (rl_camera){ .eye = *eye, .target = rl_add(*eye, *dir), .fov_deg = 70.0f, .width = 64, .height = 64 };
}

/* CHC++ on GL: the IDs (and, the draws being the same, every layer) of
 * gl-raster in each frame, fewer triangles, and every answer counted as
 * found ready, waited for or carried into the next frame. The default
 * (V-queue, latency=frame) on all 26 frames; the variants on the random
 * walk's first frames: without multi-queries, CHC's order waiting for
 * every answer, and latency simulated on top of the GPU's so that answers
 * are surely carried. The software chcpp never waits. */
static void test_chcpp_on_gl_is_conservative_on_the_walks(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = fx_box_city();
    static const char *const variants[][9] = { { "drawer", "gl", NULL },
                                               { "drawer", "gl", "multiquery", "false", NULL },
                                               { "drawer", "gl", "vqueue", "false", "latency", "wait", NULL },
                                               { "drawer", "gl", "query_delay", "3", "assumed_visible", "1",
                                                 NULL } };
    static const char *const what[] = { "", " without multi-queries", " (CHC order, latency=wait)",
                                        " (query_delay 3, assumed_visible 1)" };
    enum { V = sizeof variants / sizeof variants[0] };
    rl_renderer *chc[V], *ref = fx_make("gl-raster", NULL), *sw = fx_make("chcpp", NULL);
    uint64_t queries[V] = { 0 }, waited[V] = { 0 }, ready[V] = { 0 }, carried[V] = { 0 }, filled[V] = { 0 },
             culled[V] = { 0 }, all[V] = { 0 }, last[V] = { 0 };
    for (int v = 0; v < V; ++v)
        chc[v] = fx_make("chcpp", variants[v]);
    rl_rng rng;
    rl_rng_seed(&rng, 11, 3);
    rl_vec3 eye = rl_v3(60, 20, -30), dir = rl_v3(0, -0.3f, 1);
    /* The variants: the random walk's first frames, to stay quick. */
    const int frames = 26, variant_frames = 6;
    for (int f = 0; f < frames; ++f) {
        rl_camera cam = walk_camera(f, &rng, &eye, &dir);
        rl_render_stats a, b, c;
        rl_image *want = fx_render_with(ref, s, &cam, FX_ALL_LAYERS, &a);
        for (int v = 0; v < (f < variant_frames ? V : 1); ++v) {
            rl_image *img = fx_render_with(chc[v], s, &cam, FX_ALL_LAYERS, &b);
            const size_t n = (size_t)cam.width * cam.height;
            assert_memory_equal(want->object_id, img->object_id, n * sizeof *img->object_id);
            fx_assert_images_identical(want, img);
            assert_true(b.triangles_rasterized <= a.triangles_rasterized);
            assert_non_null(b.device);
            assert_string_equal(a.device, b.device);
            rl_culling_stats cs;
            assert_int_equal(rl_culling_get_stats(chc[v], &cs), RL_OK);
            assert_int_equal(cs.queries_carried_in, last[v]);
            assert_int_equal(cs.queries + cs.queries_carried_in,
                             cs.queries_ready + cs.queries_waited + cs.queries_carried);
            assert_int_equal(b.occlusion_queries, cs.queries);
            last[v] = cs.queries_carried;
            queries[v] += cs.queries;
            waited[v] += cs.queries_waited;
            ready[v] += cs.queries_ready;
            carried[v] += cs.queries_carried;
            filled[v] += cs.queries_filled;
            culled[v] += a.triangles_rasterized - b.triangles_rasterized;
            all[v] += a.triangles_rasterized;
            rl_image_release(img);
        }
        rl_image *soft = fx_render_with(sw, s, &cam, RL_LAYER_COLOR, &c);
        assert_null(c.device);
        rl_culling_stats cs;
        assert_int_equal(rl_culling_get_stats(sw, &cs), RL_OK);
        assert_int_equal(cs.queries_waited + cs.queries_carried, 0);
        assert_int_equal(cs.queries_ready, cs.queries);
        rl_image_release(soft);
        rl_image_release(want);
    }
    for (int v = 0; v < V; ++v) {
        print_message("chcpp%s on GL, %d frames: %llu queries, %llu found ready, %llu waited for, %llu carried, "
                      "%llu filled a wait; %.1f %% of gl-raster's triangles culled\n", what[v],
                      v ? variant_frames : frames, (unsigned long long)queries[v], (unsigned long long)ready[v],
                      (unsigned long long)waited[v], (unsigned long long)carried[v], (unsigned long long)filled[v],
                      100.0 * (double)culled[v] / (double)all[v]);
        assert_true(queries[v] > 0);
        assert_true(culled[v] > 0);
        rl_renderer_release(chc[v]);
    }
    assert_int_equal(carried[2] + filled[2], 0);
    assert_true(carried[3] > 0);
    rl_renderer_release(ref);
    rl_renderer_release(sw);
    rl_scene_release(s);
}

/* How a GL frame agrees with the software one. */
static void agree(const rl_image *gl, const rl_image *sw, double min_ssim, double min_ids, const char *what)
{
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(gl, sw, NULL, &m), RL_OK);
    const size_t n = (size_t)gl->width * gl->height;
    size_t same = 0;
    for (size_t i = 0; i < n; ++i)
        same += gl->object_id[i] == sw->object_id[i];
    print_message("%-36s SSIM %.5f, IDs %.3f %%\n", what, m.ssim, 100.0 * (double)same / (double)n);
    assert_true(m.ssim >= min_ssim);
    assert_true((double)same >= min_ids * (double)n);
}

/* One frame of name with opts, in software and with drawer=gl (and device
 * set by the test); the GL frame's stats name the device. */
static void render_both(const char *name, const char *const *opts, const rl_scene *s, const rl_camera *cam,
                        rl_image **gl, rl_image **sw, rl_culling_stats *gcs, rl_culling_stats *scs)
{
    const char *o[16];
    size_t k = 0;
    for (; opts && opts[k]; ++k)
        o[k] = opts[k];
    o[k] = NULL;
    rl_renderer *rs = fx_make(name, o);
    o[k] = "drawer";
    o[k + 1] = "gl";
    o[k + 2] = NULL;
    rl_renderer *rg = fx_make(name, o);
    rl_render_stats gst, sst;
    *sw = fx_render_with(rs, s, cam, FX_ALL_LAYERS, &sst);
    *gl = fx_render_with(rg, s, cam, FX_ALL_LAYERS, &gst);
    assert_non_null(gst.device);
    assert_null(sst.device);
    assert_int_equal(rl_culling_get_stats(rg, gcs), RL_OK);
    assert_int_equal(rl_culling_get_stats(rs, scs), RL_OK);
    rl_renderer_release(rs);
    rl_renderer_release(rg);
}

/* svs and visset draw the same object sets on GL (their preprocessing and
 * sampling stay on the CPU), so their frames agree as gl-raster's with
 * raster's (tests/gl/test_gl_raster.c: SSIM >= 0.99, IDs >= 99.9 %); select
 * draws its chosen renderer's frame; surfels' points agree within the
 * tolerance of GL's point rule, and without approximation surfels are
 * gl-raster exactly. */
static void test_culling_renderers_on_gl_agree_with_software(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = fx_box_city();
    rl_image *gl, *sw;
    rl_culling_stats gcs, scs;

    rl_camera far = { .eye = rl_v3(-120.0f, 90.0f, -110.0f), .target = rl_v3(60, 0, 60), .fov_deg = 40.0f,
                      .width = 128, .height = 96 };
    render_both("svs", (const char *const[]){ "max_depth", "3", "levels", "0", "resolution", "48", NULL }, s, &far, &gl, &sw, &gcs, &scs);
    agree(gl, sw, 0.99, 0.999, "svs from far");
    assert_int_equal(gcs.objects_drawn, scs.objects_drawn);
    rl_image_release(gl);
    rl_image_release(sw);

    rl_camera street = { .eye = rl_v3(9.5f, 1.7f, 8.0f), .target = rl_v3(14.0f, 1.5f, 70.0f), .fov_deg = 60.0f,
                         .width = 128, .height = 96 };
    render_both("visset", (const char *const[]){ "samples", "48", "resolution", "32", NULL }, s, &street, &gl, &sw,
                &gcs, &scs);
    agree(gl, sw, 0.99, 0.999, "visset in a street");
    assert_int_equal(gcs.objects_drawn, scs.objects_drawn);
    rl_image_release(gl);
    rl_image_release(sw);

    /* Two chcpp: the other renderer of the first frame builds quickly. */
    render_both("select", (const char *const[]){ "second", "chcpp", "samples", "4", "resolution", "16", NULL }, s, &street, &gl, &sw,
                &gcs, &scs);
    agree(gl, sw, 0.99, 0.999, "select in a street");
    assert_true(gcs.selected == 1 || gcs.selected == 2);
    rl_image_release(gl);
    rl_image_release(sw);

#define SMALL "count", "1500", "resolution", "64", "min_triangles", "2000"
    rl_camera distant = { .eye = rl_v3(-200.0f, 208.0f, -200.0f), .target = rl_v3(60, 5, 60), .fov_deg = 40.0f,
                          .width = 128, .height = 96 };
    render_both("surfels", (const char *const[]){ SMALL, "min_size", "400", "max_size", "800", NULL }, s, &distant,
                &gl, &sw, &gcs, &scs);
    assert_true(gcs.points_drawn > 500);
    assert_int_equal(gcs.points_drawn, scs.points_drawn);
    /* GL's point rule may move edge pixels of the squares (1.4 % of the
     * covered pixels in test_gl_raster.c); measured here: SSIM 1.0000,
     * IDs 100 %. */
    agree(gl, sw, 0.98, 0.98, "surfels, points only");
    rl_render_stats st;
    rl_image *ref = fx_render("gl-raster", s, &distant, FX_ALL_LAYERS, NULL, &st);
    rl_image_metrics m;
    assert_int_equal(rl_image_compare(gl, ref, NULL, &m), RL_OK);
    print_message("surfels on GL against gl-raster: SSIM %.4f\n", m.ssim);
    assert_true(m.ssim > 0.85);   /* tests/render/test_surfels.c's bound for software against raster */
    rl_image_release(gl);
    rl_image_release(sw);
    rl_image_release(ref);

    rl_camera mid = { .eye = rl_v3(-90.0f, 120.0f, -90.0f), .target = rl_v3(60, 5, 60), .fov_deg = 40.0f,
                      .width = 128, .height = 96 };
    rl_image *img = fx_render("surfels", s, &mid, FX_ALL_LAYERS,
                              (const char *const[]){ "count", "200", "resolution", "32", "min_triangles", "2000",
                                                     "min_size", "0", "max_size", "0", "drawer", "gl", NULL },
                              NULL);
    ref = fx_render("gl-raster", s, &mid, FX_ALL_LAYERS, NULL, NULL);
    fx_assert_images_identical(ref, img);
    rl_image_release(img);
    rl_image_release(ref);
    rl_scene_release(s);
}

/* A device that cannot be opened: every culling renderer with drawer=gl is
 * unavailable with the reason and fails to render with it; the software
 * drawer needs no device. Needs no GL. */
static void test_culling_renderers_report_gl_unavailable(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    static const char *const names[] = { "chcpp", "svs", "visset", "select", "surfels" };
    for (size_t i = 0; i < sizeof names / sizeof names[0]; ++i) {
        char why[256] = "";
        rl_renderer *r = fx_make(names[i], (const char *const[]){ "drawer", "gl", "device", "bogus", NULL });
        assert_false(rl_renderer_available(r, why, sizeof why));
        assert_non_null(strstr(why, "bogus"));
        rl_clear_error();
        assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_UNSUPPORTED);
        assert_non_null(strstr(rl_last_error(), "unavailable"));
        assert_non_null(strstr(rl_last_error(), names[i]));
        assert_int_equal(rl_renderer_set(r, "drawer", "software"), RL_OK);
        assert_true(rl_renderer_available(r, why, sizeof why));
        assert_int_equal(rl_renderer_set(r, "drawer", "vulkan"), RL_ERR_INVALID_ARG);
        rl_renderer_release(r);
    }
    /* select hands drawer=gl only to renderers that have the option. */
    rl_renderer *r = fx_make("select", (const char *const[]){ "first", "raster", "second", "svs", "drawer", "gl",
                                                              "samples", "2", "resolution", "8", NULL });
    if (have_gl) {
        rl_clear_error();
        assert_int_not_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
        assert_non_null(strstr(rl_last_error(), "has no option drawer"));
    }
    rl_renderer_release(r);
    rl_image_release(img);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_async_queries_on_the_software_drawer),
        cmocka_unit_test(test_async_queries_on_the_gl_drawer),
        cmocka_unit_test(test_chcpp_on_gl_is_conservative_on_the_walks),
        cmocka_unit_test(test_culling_renderers_on_gl_agree_with_software),
        cmocka_unit_test(test_culling_renderers_report_gl_unavailable),
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
