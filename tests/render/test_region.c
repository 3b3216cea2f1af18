/* test_region.c: rl_renderer_set_region, what a distributed frame
 * (rl_dist.h) builds on. A renderer with info.regions renders a region with
 * exactly the pixels of a whole frame there and leaves the others alone; the
 * image assembled from regions is the whole frame bit for bit. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl_pt.h"

#define SENTINEL 12345.0f

static bool has_regions(const char *name)
{
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    for (size_t i = 0; i < n; ++i)
        if (strcmp(list[i].name, name) == 0)
            return list[i].regions;
    fail_msg("no renderer %s", name);
    return false;
}

/* Odd bands and a region that does not start on a tile corner: the region
 * renders what the whole frame has there, the rest keeps the sentinel. */
static void test_whitted_region_equals_whole_frame(void **state)
{
    (void)state;
    assert_true(has_regions("whitted"));
    rl_camera cam;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("spheres", NULL, &s), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = 53;
    cam.height = 37;
    rl_render_stats whole_stats;
    rl_image *whole = fx_render("whitted", s, &cam, FX_ALL_LAYERS, NULL, &whole_stats);

    rl_renderer *r = fx_make("whitted", NULL);
    rl_image *part = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &part), RL_OK);
    rl_image_fill(part, rl_v4(SENTINEL, SENTINEL, SENTINEL, SENTINEL));
    const rl_rect region = { 5, 7, 41, 30 };
    assert_int_equal(rl_renderer_set_region(r, &region), RL_OK);
    rl_render_stats stats;
    assert_int_equal(rl_renderer_render(r, s, &cam, part, &stats), RL_OK);
    assert_int_equal(stats.pixels_written, (uint64_t)(36 * 23));
    assert_true(stats.rays[RL_RAY_PRIMARY] < whole_stats.rays[RL_RAY_PRIMARY]);
    for (int y = 0; y < cam.height; ++y)
        for (int x = 0; x < cam.width; ++x) {
            size_t i = (size_t)y * cam.width + x;
            bool inside = x >= region.x0 && x < region.x1 && y >= region.y0 && y < region.y1;
            if (inside) {
                assert_memory_equal(&part->color[i], &whole->color[i], sizeof part->color[i]);
                assert_memory_equal(&part->depth[i], &whole->depth[i], sizeof part->depth[i]);
                assert_int_equal(part->object_id[i], whole->object_id[i]);
                assert_int_equal(part->triangle_id[i], whole->triangle_id[i]);
            } else {
                assert_true(part->color[i].x == SENTINEL);
            }
        }

    /* Bands of rows that tile the image assemble the whole frame, and the
     * ray counts of the bands add up to the whole frame's. */
    rl_image_fill(part, rl_v4(SENTINEL, SENTINEL, SENTINEL, SENTINEL));
    uint64_t rays[RL_RAY_TYPE_COUNT] = { 0 };
    for (int y0 = 0; y0 < cam.height; y0 += 16) {
        rl_rect band = { 0, y0, cam.width, y0 + 16 < cam.height ? y0 + 16 : cam.height };
        assert_int_equal(rl_renderer_set_region(r, &band), RL_OK);
        assert_int_equal(rl_renderer_render(r, s, &cam, part, &stats), RL_OK);
        for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
            rays[k] += stats.rays[k];
    }
    fx_assert_images_identical(part, whole);
    assert_memory_equal(rays, whole_stats.rays, sizeof rays);

    /* NULL returns to whole frames. */
    assert_int_equal(rl_renderer_set_region(r, NULL), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, part, &stats), RL_OK);
    assert_int_equal(stats.pixels_written, (uint64_t)cam.width * cam.height);
    rl_image_release(part);
    rl_image_release(whole);
    rl_renderer_release(r);
    rl_scene_release(s);
}

static void test_bad_regions_are_refused(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_renderer *r = fx_make("whitted", NULL);
    assert_int_equal(rl_renderer_set_region(r, &(rl_rect){ 4, 4, 4, 8 }), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set_region(r, &(rl_rect){ -1, 0, 4, 8 }), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set_region(NULL, NULL), RL_ERR_INVALID_ARG);
    /* A region past the image is found at render time, when the image is known. */
    assert_int_equal(rl_renderer_set_region(r, &(rl_rect){ 0, 0, 17, 8 }), RL_OK);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    if (!strstr(rl_last_error(), "outside the 16x16 image"))
        fail_msg("%s", rl_last_error());
    rl_renderer_release(r);

    /* A renderer whose pixels depend on each other renders whole images only. */
    assert_false(has_regions("raster"));
    r = fx_make("raster", NULL);
    assert_int_equal(rl_renderer_set_region(r, &(rl_rect){ 0, 0, 8, 8 }), RL_ERR_UNSUPPORTED);
    assert_int_equal(rl_renderer_set_region(r, NULL), RL_OK);
    rl_renderer_release(r);
    rl_image_release(img);
    rl_scene_release(s);
}

/* pt: N frames of a region are the region of N whole frames, bit for bit,
 * in every layer, for each generator and with checkerboard (whose first
 * frame fills its holes from neighbours outside a band). Bands rendered
 * one after another by the same renderer (each its own accumulation, as a
 * rank of rl --dist renders them) assemble the whole image. */
static void check_pt_bands(const char *const *opts, int frames, const rl_scene *s, const rl_camera *cam)
{
    rl_renderer *whole_r = fx_make("pt", opts);
    rl_image *whole = NULL;
    rl_render_stats ws = { 0 };
    uint64_t whole_samples = 0;
    assert_int_equal(rl_image_create(cam->width, cam->height, FX_ALL_LAYERS, &whole), RL_OK);
    for (int k = 0; k < frames; ++k) {
        assert_int_equal(rl_renderer_render(whole_r, s, cam, whole, &ws), RL_OK);
        whole_samples += ws.samples;
        /* What rl --dist fixes the frames of a sample target with. */
        assert_int_equal(ws.samples, rl_pt_frame_samples(whole_r, cam->width, cam->height, (uint64_t)k));
    }

    rl_renderer *r = fx_make("pt", opts);
    rl_image *part = NULL;
    assert_int_equal(rl_image_create(cam->width, cam->height, FX_ALL_LAYERS, &part), RL_OK);
    rl_image_fill(part, rl_v4(SENTINEL, SENTINEL, SENTINEL, SENTINEL));
    uint64_t samples = 0;
    /* Bands of 7 rows, not a multiple of the 16-pixel tiles. */
    for (int y0 = 0; y0 < cam->height; y0 += 7) {
        rl_rect band = { 0, y0, cam->width, y0 + 7 < cam->height ? y0 + 7 : cam->height };
        assert_int_equal(rl_renderer_set_region(r, &band), RL_OK);
        rl_render_stats bs = { 0 };
        for (int k = 0; k < frames; ++k) {
            assert_int_equal(rl_renderer_render(r, s, cam, part, &bs), RL_OK);
            samples += bs.samples;
        }
        assert_int_equal(bs.pixels_written, (uint64_t)(band.y1 - band.y0) * (uint64_t)cam->width);
    }
    fx_assert_images_identical(part, whole);
    assert_int_equal(samples, whole_samples);

    /* A region off the corner, rendered after the bands: its own
     * accumulation again; the rest of the image is left alone. */
    rl_image_fill(part, rl_v4(SENTINEL, SENTINEL, SENTINEL, SENTINEL));
    const rl_rect region = { 3, 5, 29, 17 };
    assert_int_equal(rl_renderer_set_region(r, &region), RL_OK);
    for (int k = 0; k < frames; ++k)
        assert_int_equal(rl_renderer_render(r, s, cam, part, NULL), RL_OK);
    for (int y = 0; y < cam->height; ++y)
        for (int x = 0; x < cam->width; ++x) {
            size_t i = (size_t)y * cam->width + x;
            if (x >= region.x0 && x < region.x1 && y >= region.y0 && y < region.y1) {
                assert_memory_equal(&part->color[i], &whole->color[i], sizeof part->color[i]);
                assert_memory_equal(&part->depth[i], &whole->depth[i], sizeof part->depth[i]);
                assert_int_equal(part->triangle_id[i], whole->triangle_id[i]);
            } else {
                assert_true(part->color[i].x == SENTINEL);
            }
        }

    /* Back to whole frames: a new accumulation over the image. */
    assert_int_equal(rl_renderer_set_region(r, NULL), RL_OK);
    for (int k = 0; k < frames; ++k)
        assert_int_equal(rl_renderer_render(r, s, cam, part, NULL), RL_OK);
    fx_assert_images_identical(part, whole);
    assert_int_equal(rl_pt_frame_samples(NULL, cam->width, cam->height, 0), 0);
    rl_image_release(part);
    rl_image_release(whole);
    rl_renderer_release(r);
    rl_renderer_release(whole_r);
}

static void test_pt_region_equals_whole_frames(void **state)
{
    (void)state;
    assert_true(has_regions("pt"));
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    cam.width = 37;
    cam.height = 23;
    check_pt_bands((const char *const[]){ "spp", "2", "seed", "5", NULL }, 3, s, &cam);
    check_pt_bands((const char *const[]){ "rng", "hybrid", "checkerboard", "true", NULL }, 1, s, &cam);
    check_pt_bands((const char *const[]){ "rng", "lcg", "checkerboard", "true", "spp", "2", NULL }, 3, s, &cam);
    rl_scene_release(s);
}

/* What needs the whole image is refused for a region, with the reason. */
static void test_pt_region_refusals(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, RL_LAYER_COLOR, &img), RL_OK);
    const struct {
        const char *opts[3];
        const char *why;
    } cases[] = {
        { { "filter", "bilateral", NULL }, "pt: filter=bilateral filters the whole image" },
        { { "primary", "raster", NULL }, "pt: primary=raster rasterizes the whole image" },
        { { "adaptive", "on", NULL }, "pt: adaptive=on shares a frame's paths over the whole image" },
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        rl_renderer *r = fx_make("pt", cases[k].opts);
        assert_int_equal(rl_renderer_set_region(r, &(rl_rect){ 0, 0, 8, 8 }), RL_OK);
        rl_clear_error();
        assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_UNSUPPORTED);
        if (!strstr(rl_last_error(), cases[k].why))
            fail_msg("%s", rl_last_error());
        /* The whole image renders as ever. */
        assert_int_equal(rl_renderer_set_region(r, NULL), RL_OK);
        assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
        rl_renderer_release(r);
    }
    rl_image_release(img);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_whitted_region_equals_whole_frame),
        cmocka_unit_test(test_bad_regions_are_refused),
        cmocka_unit_test(test_pt_region_equals_whole_frames),
        cmocka_unit_test(test_pt_region_refusals),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
