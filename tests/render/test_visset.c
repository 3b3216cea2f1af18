/* test_visset.c: the global-visibility renderer of Jähn 2015, Sec. 7.6
 * ("visset") draws the sampled set of visible objects: at street level a
 * fraction of the triangles at good quality; a budget is never exceeded;
 * an approximation saved by the evaluator gives the same frames; outside
 * the sampled region it draws everything (= raster). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl.h"

static const char *const good[] = { "samples", "256", "resolution", "64", NULL };
static const char *const coarse[] = { "samples", "48", "resolution", "48", NULL };

static rl_camera street(float t)
{
    rl_camera c = { .eye = rl_v3(9.5f, 1.7f, 3.0f + 5.0f * t), .target = rl_v3(12.0f + 2.0f * t, 1.5f, 70.0f),
                    .fov_deg = 60.0f, .width = 128, .height = 96 };
    return c;
}

static void test_visset_draws_the_sampled_set(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_renderer *vis = fx_make("visset", good);
    double ssim_sum = 0.0;
    for (int i = 0; i < 4; ++i) {
        rl_camera cam = street((float)i);
        rl_render_stats full, st;
        rl_image *ref = fx_render("raster", s, &cam, RL_LAYER_COLOR, NULL, &full);
        rl_image *img = fx_render_with(vis, s, &cam, RL_LAYER_COLOR, &st);
        assert_true(st.triangles_rasterized * 2 < full.triangles_rasterized);
        rl_image_metrics m;
        assert_int_equal(rl_image_compare(img, ref, NULL, &m), RL_OK);
        ssim_sum += m.ssim;
        rl_image_release(img);
        rl_image_release(ref);
    }
    assert_true(ssim_sum / 4.0 > 0.95);   /* measured 0.986 */

    /* Budgets: never exceeded, counted by the rasterizer (not the
     * renderer's own counter), at several views; a bigger budget draws at
     * least as much, and the image gets closer to raster's (mean SSIM over
     * the views; the highest-impact objects come first, so a budget that
     * drew the wrong ones, or none, would not rise). */
    static const char *const budgets[] = { "300", "3000", "30000" };
    double budget_ssim[3] = { 0.0, 0.0, 0.0 };
    for (int v = 0; v < 4; ++v) {
        uint64_t prev = 0;
        rl_camera view = street(0.7f * (float)v);
        rl_image *full = fx_render("raster", s, &view, RL_LAYER_COLOR, NULL, NULL);
        for (int b = 0; b < 3; ++b) {
            /* The same renderer: its sets are sampled once, a budget only
             * ranks them (rebuilt with nothing else when it changes). */
            rl_renderer *rb = vis;
            assert_int_equal(rl_renderer_set(rb, "budget", budgets[b]), RL_OK);
            rl_camera cam = street(0.7f * (float)v);
            rl_render_stats rs;
            rl_image *img = fx_render_with(rb, s, &cam, RL_LAYER_COLOR, &rs);
            rl_image_metrics bm;
            assert_int_equal(rl_image_compare(img, full, NULL, &bm), RL_OK);
            budget_ssim[b] += bm.ssim / 4.0;
            rl_culling_stats cs;
            assert_int_equal(rl_culling_get_stats(rb, &cs), RL_OK);
            assert_true(rs.triangles_rasterized <= (uint64_t)atoll(budgets[b]));
            assert_true(rs.triangles_rasterized <= cs.triangles_drawn);   /* frustum-clipped ones drop out */
            assert_true(cs.triangles_drawn <= (uint64_t)atoll(budgets[b]));
            assert_true(cs.triangles_drawn >= prev);
            prev = cs.triangles_drawn;
            rl_image_release(img);
        }
        rl_image_release(full);
        assert_true(prev > 0);
    }
    print_message("visset budget 300 / 3000 / 30000: mean SSIM vs raster %.4f / %.4f / %.4f\n", budget_ssim[0],
                  budget_ssim[1], budget_ssim[2]);
    assert_true(budget_ssim[1] >= budget_ssim[0] && budget_ssim[2] >= budget_ssim[1]);
    assert_true(budget_ssim[2] > budget_ssim[0] + 0.1);

    assert_int_equal(rl_renderer_set(vis, "budget", "0"), RL_OK);
    /* Outside the slice's x-z extent: everything, as raster. */
    rl_camera out = { .eye = rl_v3(-40, 30, -40), .target = rl_v3(60, 0, 60), .width = 96, .height = 72 };
    rl_image *ref = fx_render("raster", s, &out, FX_ALL_LAYERS, NULL, NULL);
    rl_image *img = fx_render_with(vis, s, &out, FX_ALL_LAYERS, NULL);
    fx_assert_images_identical(img, ref);
    rl_image_release(img);
    rl_image_release(ref);
    rl_renderer_release(vis);
    rl_scene_release(s);
}

static void test_visset_reads_the_evaluators_approximation(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "resolution", "48"), RL_OK);
    assert_int_equal(rl_property_commit(p, s, 0), RL_OK);
    rl_sampling_desc sd = { .region = d->bounds, .dims = 2, .height = d->bounds.min.y + 1.7f,
                            .max_samples = 48, .seed = 1 };
    rl_approx *a = NULL;
    assert_int_equal(rl_sample_property(p, &sd, &a), RL_OK);
    const char *dir = getenv("RL_TEST_TMP");
    char path[1024];
    snprintf(path, sizeof path, "%s/visset_approx.json", dir ? dir : "/tmp");
    assert_int_equal(rl_approx_save_json(a, path), RL_OK);
    rl_approx_release(a);
    rl_property_release(p);

    rl_renderer *own = fx_make("visset", coarse);
    rl_renderer *file = fx_make("visset", (const char *const[]){ "approx", path, NULL });
    /* The same file handed in by the caller as a lookup (rl_approx_lookup),
     * without rl_renderer_prepare_inputs: the same frames. */
    rl_renderer *handed = fx_make("visset", NULL);
    rl_approx *loaded = NULL;
    assert_int_equal(rl_approx_load_json(path, &loaded), RL_OK);
    rl_position_lookup l;
    assert_int_equal(rl_approx_lookup(loaded, &l), RL_OK);
    assert_true(l.set_size == d->num_objects && l.num_regions > 0 && !l.object_pixels);
    assert_int_equal(rl_renderer_set_input(handed, "approx", &l, NULL), RL_OK);
    for (int i = 0; i < 3; ++i) {
        rl_camera cam = street((float)i);
        rl_image *x = fx_render_with(own, s, &cam, FX_ALL_LAYERS, NULL);
        rl_image *y = fx_render_with(file, s, &cam, FX_ALL_LAYERS, NULL);
        rl_image *z = NULL;
        assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &z), RL_OK);
        assert_int_equal(rl_renderer_render(handed, s, &cam, z, NULL), RL_OK);
        fx_assert_images_identical(x, y);
        fx_assert_images_identical(x, z);
        rl_image_release(x);
        rl_image_release(y);
        rl_image_release(z);
    }
    rl_renderer_release(handed);
    assert_int_equal(rl_approx_lookup(NULL, &l), RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_renderer_release(file);
    rl_renderer_release(own);

    /* The same file for another scene (refused on loading, before its sets
     * are allocated), and a missing file, are refused. */
    rl_scene *other = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", "", &other), RL_OK);
    rl_renderer *bad = fx_make("visset", (const char *const[]){ "approx", path, NULL });
    rl_camera cam = { .eye = rl_v3(0, 1, 3), .target = rl_v3(0, 1, 0), .width = 32, .height = 32 };
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(32, 32, RL_LAYER_COLOR, &img), RL_OK);
    assert_int_equal(rl_renderer_prepare_inputs(bad, other), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "the scene has"));
    rl_clear_error();
    assert_int_equal(rl_renderer_render(bad, other, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(bad, "approx", "/nonexistent/approx.json"), RL_OK);
    assert_int_not_equal(rl_renderer_prepare_inputs(bad, other), RL_OK);
    rl_image_release(img);
    rl_renderer_release(bad);
    rl_scene_release(other);
    rl_scene_release(s);
}

/* The budgeted variant draws in decreasing impact (visible pixels at the
 * region's centre): three boxes of 12 triangles each, added smallest
 * first, one region sampled at its centre; a budget of one box draws the
 * biggest, of two the two biggest. */
static bool has_object(const rl_image *img, uint32_t id)
{
    for (int k = 0; k < img->width * img->height; ++k)
        if (img->object_id[k] == id)
            return true;
    return false;
}

/* Three boxes of 12 triangles, small and far, medium, big and near, seen
 * from the origin looking along +x; their object ids by size. */
static rl_scene *three_boxes(uint32_t *small_out, uint32_t *medium_out, uint32_t *big_out)
{
    uint32_t mat;
    rl_scene *s = fx_scene_with_material(&mat);
    fx_add_box(s, mat, rl_v3(9, 1, 6), rl_v3(9.5f, 1.5f, 6.5f), 1);       /* small, far */
    fx_add_box(s, mat, rl_v3(6, 0, 0.5f), rl_v3(7, 2, 2.5f), 1);          /* medium */
    fx_add_box(s, mat, rl_v3(3, -3, -4), rl_v3(4, 5, -0.5f), 1);          /* big, near */
    rl_light l = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3s(1.0f), .intensity = 1.0f,
                   .direction = rl_normalize(rl_v3(1, -1, 0.2f)) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_objects, 3);
    for (uint32_t o = 0; o < 3; ++o) {
        float x = d->objects[o].bounds.min.x;
        *(x > 8 ? small_out : x > 5 ? medium_out : big_out) = o;
    }
    return s;
}

static const rl_camera three_boxes_camera = { .eye = { 0.3f, 1.0f, -0.2f }, .target = { 5, 1, 0 },
                                              .fov_deg = 110.0f, .width = 96, .height = 72 };

/* A lookup of the test's own: one region everywhere whose set is fixed. */
static int fixed_released;
static bool fixed_query(void *user, rl_vec3 p, double *value, uint32_t *region)
{
    (void)user, (void)p;
    *value = 0.0;
    *region = 0;
    return true;
}
static const uint64_t *fixed_set(void *user, uint32_t region)
{
    (void)region;
    return user;
}
static void fixed_release(void *user)
{
    (void)user;
    fixed_released++;
}

/* The renderer reads its sets only through the lookup (rl_render.h): one
 * handed in by the caller, with no sampling anywhere, draws exactly its
 * set; without one the frame is refused with a message that says how to
 * get one; the renderer releases the lookup it owns. */
static void test_visset_draws_a_lookup_of_its_own(void **state)
{
    (void)state;
    uint32_t small = 0, medium = 0, big = 0;
    rl_scene *s = three_boxes(&small, &medium, &big);
    rl_camera cam = three_boxes_camera;
    rl_renderer *r = fx_make("visset", NULL);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &img), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "no visible sets"));

    static uint64_t set[1];
    set[0] = (1ull << small) | (1ull << big);
    rl_position_lookup l = { .user = set, .property = "visibility", .set_size = 3, .num_regions = 1,
                             .query = fixed_query, .region_set = fixed_set, .release = fixed_release };
    assert_int_equal(rl_renderer_set_input(r, "sets", &l, NULL), RL_ERR_INVALID_ARG);   /* unknown slot */
    /* Sets of another property (a custom one may have any) are not drawn. */
    rl_position_lookup other = l;
    other.property = "ops";
    other.release = NULL;
    assert_int_equal(rl_renderer_set_input(r, "approx", &other, NULL), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "'ops', not visibility"));
    rl_clear_error();
    fixed_released = 0;
    assert_int_equal(rl_renderer_set_input(r, "approx", &l, "mine"), RL_OK);
    assert_string_equal(rl_renderer_input_key(r, "approx"), "mine");
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_true(has_object(img, small) && has_object(img, big));
    assert_false(has_object(img, medium));
    /* Budgets need pixels per object, which this lookup does not offer. */
    assert_int_equal(rl_renderer_set(r, "budget", "12"), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(fixed_released, 0);
    rl_renderer_release(r);
    assert_int_equal(fixed_released, 1);
    rl_image_release(img);
    rl_scene_release(s);
}

static void test_visset_budget_draws_the_highest_impact_first(void **state)
{
    (void)state;
    uint32_t small = 0, medium = 0, big = 0;
    rl_scene *s = three_boxes(&small, &medium, &big);
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "resolution", "64"), RL_OK);
    assert_int_equal(rl_property_commit(p, s, 1), RL_OK);
    rl_sampling_desc sd = { .region = { { -1, 0, -1 }, { 1, 2, 1 } }, .dims = 2, .height = 1.0f,
                            .method = RL_SAMPLING_GRID, .grid_res = { 1, 1, 1 }, .seed = 1 };
    rl_approx *a = NULL;
    assert_int_equal(rl_sample_property(p, &sd, &a), RL_OK);
    const char *dir = getenv("RL_TEST_TMP");
    char path[1024];
    snprintf(path, sizeof path, "%s/visset_impact.json", dir ? dir : "/tmp");
    assert_int_equal(rl_approx_save_json(a, path), RL_OK);
    rl_approx_release(a);
    rl_property_release(p);

    rl_camera cam = three_boxes_camera;
    rl_image *ref = fx_render("raster", s, &cam, FX_ALL_LAYERS, NULL, NULL);
    assert_true(has_object(ref, small) && has_object(ref, medium) && has_object(ref, big));
    rl_image_release(ref);
    static const char *const budgets[] = { "12", "24", "36" };
    for (int b = 0; b < 3; ++b) {
        rl_renderer *r = fx_make("visset", (const char *const[]){ "approx", path, "budget", budgets[b], NULL });
        rl_image *img = fx_render_with(r, s, &cam, FX_ALL_LAYERS, NULL);
        assert_true(has_object(img, big));
        assert_true(has_object(img, medium) == (b >= 1));
        assert_true(has_object(img, small) == (b >= 2));
        rl_image_release(img);
        rl_renderer_release(r);
    }
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_visset_draws_the_sampled_set),
        cmocka_unit_test(test_visset_reads_the_evaluators_approximation),
        cmocka_unit_test(test_visset_budget_draws_the_highest_impact_first),
        cmocka_unit_test(test_visset_draws_a_lookup_of_its_own),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
