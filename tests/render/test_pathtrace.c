/* test_pathtrace.c: renderer "pt" (Schröder 2017) against analytic answers
 * (the white furnace inside a closed emissive sphere, a Lambertian quad
 * under a point light), against itself (exact backends, thread counts,
 * reset), for convergence of the accumulation (eq. 8), for the emission
 * rule (NEE on a covered emitter vs. hitting an uncovered one), and for
 * option validation and statistics. Small images so ASan stays fast. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_accel.h"
#include "rl/rl_pt.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render/render_fixtures.h"

#define SIZE 24

/* Values are clamped to the display range [0, 1] where the tests compare
 * noisy images: a pixel that sees the Cornell light (radiance 17) only
 * partly would otherwise dominate means and errors by its coverage noise. */
static float disp(float v)
{
    return v < 1.0f ? v : 1.0f;
}

static rl_vec3 mean_color(const rl_image *img)
{
    double s[3] = { 0.0, 0.0, 0.0 };
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; ++i) {
        s[0] += disp(img->color[i].x);
        s[1] += disp(img->color[i].y);
        s[2] += disp(img->color[i].z);
    }
    return rl_v3((float)(s[0] / n), (float)(s[1] / n), (float)(s[2] / n));
}

static double rmse(const rl_image *a, const rl_image *b)
{
    double e = 0.0;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; ++i) {
        double dx = disp(a->color[i].x) - disp(b->color[i].x), dy = disp(a->color[i].y) - disp(b->color[i].y),
               dz = disp(a->color[i].z) - disp(b->color[i].z);
        e += dx * dx + dy * dy + dz * dz;
    }
    return sqrt(e / (3.0 * n));
}

static void assert_images_close(const rl_image *a, const rl_image *b, float tol)
{
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; ++i) {
        assert_float_equal(a->color[i].x, b->color[i].x, tol);
        assert_float_equal(a->color[i].y, b->color[i].y, tol);
        assert_float_equal(a->color[i].z, b->color[i].z, tol);
    }
}

static void test_pt_is_registered_and_refuses_bad_options(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("pt", NULL);
    assert_string_equal(rl_renderer_get(r, "rng"), "sobol");
    assert_string_equal(rl_renderer_get(r, "mis"), "on");
    assert_int_equal(rl_renderer_set(r, "mis", "maybe"), RL_ERR_INVALID_ARG);
    assert_string_equal(rl_renderer_get(r, "shadow"), "bvh");
    assert_string_equal(rl_renderer_get(r, "max_depth"), "-1");
    assert_int_equal(rl_renderer_set(r, "spp", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "max_depth", "-2"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "rng", "mersenne"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "shadow", "octree"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "diffuse", "shadowmap"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "primary", "both"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "light_samples", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "filter_fade", "-1"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "bounces", "2"), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_renderer_set(r, "ls_k", "7"), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "ls_k"));
    rl_clear_error();
    assert_int_equal(rl_renderer_set(r, "rng", "mt"), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "lcg, tausworthe, hybrid"));
    rl_clear_error();
    assert_int_equal(rl_renderer_set(r, "pt.spp", "4"), RL_OK);
    assert_int_equal(rl_renderer_set(r, "shadow", "embree"),
                     rl_accel_kind_available(RL_ACCEL_EMBREE) ? RL_OK : RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_pt_stats st;
    assert_int_equal(rl_pt_get_stats(r, &st), RL_ERR_INVALID_ARG);   /* nothing rendered */
    assert_null(rl_pt_gbuffer(r));
    rl_renderer_release(r);
    rl_renderer *w = fx_make("whitted", NULL);
    assert_int_equal(rl_pt_reset(w), RL_ERR_INVALID_ARG);
    assert_null(rl_pt_gbuffer(w));
    rl_renderer_release(w);
    rl_clear_error();
}

/* A closed sphere of albedo a emitting E everywhere, seen from inside with
 * no lights: every path gathers E (1 + a + a^2 + ...) = E / (1 - a). */
static void test_white_furnace_converges_to_e_over_one_minus_albedo(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse = rl_v3s(0.5f);
    m.emission = rl_v3(0.3f, 0.6f, 0.9f);
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "sphere", "radius=1,segments=96,rings=48", mat, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "sphere", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_camera cam = { .eye = rl_v3(0.0f, 0.0f, 0.0f), .target = rl_v3(0.0f, 0.0f, 1.0f), .fov_deg = 90.0f,
                      .width = 8, .height = 8 };
    /* The thesis' estimator without roulette: every path is the same
     * geometric series, cut at 64, but for the rare bounce that leaves
     * below the geometric surface of the tessellated sphere (shading
     * normals): within 1 %. */
    rl_image *img = fx_render("pt", s, &cam, RL_LAYER_COLOR,
                              (const char *const[]){ "max_depth", "64", "rr", "false", "mis", "off", "rng", "hybrid",
                                                     NULL }, NULL);
    for (int i = 0; i < 8 * 8; ++i) {
        assert_float_equal(img->color[i].x, 0.6f, 0.6f * 0.01f);
        assert_float_equal(img->color[i].z, 1.8f, 1.8f * 0.01f);
    }
    rl_image_release(img);
    /* With MIS the sphere's triangles are lights too: light samples and
     * BSDF hits share each bounce's emission, so a path is no longer the
     * bare series, but its expectation is (pixels within 3 %, the mean
     * within 1 %). */
    img = fx_render("pt", s, &cam, RL_LAYER_COLOR,
                    (const char *const[]){ "spp", "64", "max_depth", "64", "rr", "false", NULL }, NULL);
    double mis_mean = 0.0;
    for (int i = 0; i < 8 * 8; ++i) {
        assert_float_equal(img->color[i].x, 0.6f, 0.6f * 0.03f);
        assert_float_equal(img->color[i].z, 1.8f, 1.8f * 0.03f);
        mis_mean += img->color[i].y / 64.0;
    }
    assert_float_equal(mis_mean, 1.2, 1.2 * 0.01);
    rl_image_release(img);
    /* With roulette (unbiased, noisier): a few % per pixel, 1-2 % overall. */
    img = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "256", "max_depth", "64", NULL },
                    NULL);
    double mean[3] = { 0.0, 0.0, 0.0 };
    for (int i = 0; i < 8 * 8; ++i) {
        assert_float_equal(img->color[i].x, 0.6f, 0.6f * 0.15f);
        assert_float_equal(img->color[i].y, 1.2f, 1.2f * 0.15f);
        assert_float_equal(img->color[i].z, 1.8f, 1.8f * 0.15f);
        mean[0] += img->color[i].x / 64.0;
        mean[1] += img->color[i].y / 64.0;
        mean[2] += img->color[i].z / 64.0;
    }
    assert_float_equal(mean[0], 0.6, 0.6 * 0.02);
    assert_float_equal(mean[1], 1.2, 1.2 * 0.02);
    assert_float_equal(mean[2], 1.8, 1.8 * 0.02);
    rl_image_release(img);
    rl_scene_release(s);
}

/* A Lambertian floor (y = 0, two triangles) under a point light. */
static rl_scene *floor_scene(rl_vec3 kd, const rl_light *light, bool emissive_quad)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse = kd;
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    rl_vec3 pos[4] = { { -2, 0, -2 }, { 2, 0, -2 }, { 2, 0, 2 }, { -2, 0, 2 } };
    uint32_t idx[6] = { 0, 2, 1, 0, 3, 2 };
    rl_mesh_desc md = { .name = "floor", .num_vertices = 4, .positions = pos, .num_triangles = 2,
                        .indices = idx, .material = mat };
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "floor", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    if (emissive_quad) {
        /* The emitter of the quad light below, as a mesh at the same place. */
        rl_material e = rl_material_default();
        e.diffuse = rl_v3s(0.0f);
        e.emission = rl_v3s(4.0f);
        uint32_t emat, emesh, enode;
        assert_int_equal(rl_scene_add_material(s, &e, &emat), RL_OK);
        rl_vec3 q[4] = { { -0.5f, 1, -0.5f }, { 0.5f, 1, -0.5f }, { 0.5f, 1, 0.5f }, { -0.5f, 1, 0.5f } };
        uint32_t qi[6] = { 0, 1, 2, 0, 2, 3 };
        rl_mesh_desc ed = { .name = "lamp", .num_vertices = 4, .positions = q, .num_triangles = 2,
                            .indices = qi, .material = emat };
        assert_int_equal(rl_scene_add_mesh(s, &ed, &emesh), RL_OK);
        assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "lamp", NULL, &enode), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, enode, emesh), RL_OK);
    }
    if (light)
        assert_int_equal(rl_scene_add_light(s, light), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* L = k_d / pi * I cos(theta) / d^2 at every pixel centre (primary=raster:
 * no jitter), whatever max_depth: the bounces leave the open scene. */
static void test_lambertian_floor_under_point_light_matches_closed_form(void **state)
{
    (void)state;
    rl_light light = { .type = RL_LIGHT_POINT, .color = rl_v3(1.0f, 0.5f, 0.25f), .intensity = 3.0f,
                       .position = rl_v3(0.3f, 1.5f, 0.2f) };
    rl_vec3 kd = rl_v3(0.7f, 0.5f, 0.3f);
    rl_scene *s = floor_scene(kd, &light, false);
    rl_camera cam = { .eye = rl_v3(0.0f, 3.0f, 3.0f), .target = rl_v3(0.0f, 0.0f, 0.0f), .fov_deg = 50.0f,
                      .width = SIZE, .height = SIZE };
    const char *const depths[] = { "0", "3" };
    for (int k = 0; k < 2; ++k) {
        rl_renderer *r = fx_make("pt", (const char *const[]){ "primary", "raster", "max_depth", depths[k], NULL });
        rl_image *img = fx_render_with(r, s, &cam, FX_ALL_LAYERS, NULL);
        const rl_gbuffer *g = rl_pt_gbuffer(r);
        assert_non_null(g);
        int hits = 0;
        for (int i = 0; i < SIZE * SIZE; ++i) {
            if (g->object[i] == RL_ID_NONE) {
                assert_float_equal(img->color[i].x, 0.0f, 0.0f);
                continue;
            }
            ++hits;
            rl_vec3 to = rl_sub(light.position, g->position[i]);
            float d2 = rl_length2(to), cos_t = to.y / sqrtf(d2);
            rl_vec3 want = rl_scale(rl_mul(kd, light.color), light.intensity * cos_t / (d2 * RL_PI));
            assert_float_equal(img->color[i].x, want.x, 1e-4f + 1e-3f * want.x);
            assert_float_equal(img->color[i].y, want.y, 1e-4f + 1e-3f * want.y);
            assert_float_equal(img->color[i].z, want.z, 1e-4f + 1e-3f * want.z);
        }
        assert_true(hits > SIZE * SIZE / 2);
        rl_image_release(img);
        rl_renderer_release(r);
    }
    rl_scene_release(s);
}

/* A uniform environment of radiance E (option background) over a
 * Lambertian floor without lights: every bounce leaves the open scene, so
 * every path carries exactly k_d E (f cos / pdf = k_d for cosine sampling),
 * and the camera rays that miss carry E. */
static void test_uniform_environment_lights_a_lambertian_floor(void **state)
{
    (void)state;
    rl_vec3 kd = rl_v3(0.7f, 0.5f, 0.3f), E = rl_v3(0.8f, 1.0f, 1.25f);
    rl_scene *s = floor_scene(kd, NULL, false);
    rl_camera cam = { .eye = rl_v3(0.0f, 1.0f, 3.0f), .target = rl_v3(0.0f, 0.0f, 0.0f), .fov_deg = 60.0f,
                      .width = SIZE, .height = SIZE };
    const char *const depths[] = { "1", "3" };
    for (int k = 0; k < 2; ++k) {
        rl_renderer *r = fx_make("pt", (const char *const[]){ "primary", "raster", "max_depth", depths[k],
                                                              "background", "0.8,1,1.25", NULL });
        rl_image *img = fx_render_with(r, s, &cam, FX_ALL_LAYERS, NULL);
        const rl_gbuffer *g = rl_pt_gbuffer(r);
        int hits = 0, misses = 0;
        for (int i = 0; i < SIZE * SIZE; ++i) {
            rl_vec3 want = g->object[i] == RL_ID_NONE ? E : rl_mul(kd, E);
            hits += g->object[i] != RL_ID_NONE;
            misses += g->object[i] == RL_ID_NONE;
            assert_float_equal(img->color[i].x, want.x, 1e-5f);
            assert_float_equal(img->color[i].y, want.y, 1e-5f);
            assert_float_equal(img->color[i].z, want.z, 1e-5f);
        }
        assert_true(hits > 0 && misses > 0);
        rl_image_release(img);
        rl_renderer_release(r);
    }
    /* The default background is black. */
    rl_image *img = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "max_depth", "3", NULL }, NULL);
    assert_float_equal(mean_color(img).x, 0.0f, 0.0f);
    rl_image_release(img);
    rl_scene_release(s);
}

static bool cancel_after_build(void *user, double done)
{
    int *calls = user;
    ++*calls;
    return done <= 0.5;   /* the build share passes, the first sample cancels */
}

/* A cancel by the progress callback stops the frame with RL_ERR_CANCELLED
 * and leaves no half-accumulated frame behind: the next frame equals the
 * first frame of a fresh renderer. */
static void test_progress_callback_cancels_and_leaves_no_partial_frame(void **state)
{
    (void)state;
    rl_light light = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = 3.0f,
                       .position = rl_v3(0.3f, 1.5f, 0.2f) };
    rl_scene *s = floor_scene(rl_v3s(0.5f), &light, false);
    rl_camera cam = { .eye = rl_v3(0.0f, 3.0f, 3.0f), .target = rl_v3(0.0f, 0.0f, 0.0f), .width = SIZE,
                      .height = SIZE };
    const char *const opts[] = { "spp", "4", "max_depth", "3", NULL };
    rl_renderer *r = fx_make("pt", opts);
    int calls = 0;
    rl_renderer_set_progress(r, cancel_after_build, &calls);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(SIZE, SIZE, RL_LAYER_COLOR, &img), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_ERR_CANCELLED);
    assert_true(calls >= 2);
    rl_renderer_set_progress(r, NULL, NULL);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    rl_image *fresh = fx_render("pt", s, &cam, RL_LAYER_COLOR, opts, NULL);
    fx_assert_images_identical(img, fresh);
    rl_image_release(fresh);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* The emission rule: the same lamp as a quad light over its emissive mesh
 * (NEE, the mesh covered) and as the bare emissive mesh (found by BRDF
 * sampling only) must light the floor alike: no double counting, no gap. */
static void test_nee_on_covered_emitter_matches_hitting_the_bare_emitter(void **state)
{
    (void)state;
    rl_light quad = { .type = RL_LIGHT_QUAD, .color = rl_v3s(1.0f), .intensity = 4.0f,
                      .position = rl_v3(-0.5f, 1.0f, -0.5f), .edge_u = rl_v3(1.0f, 0.0f, 0.0f),
                      .edge_v = rl_v3(0.0f, 0.0f, 1.0f) };   /* cross(u, v) = -y: facing the floor */
    rl_scene *with_light = floor_scene(rl_v3s(0.5f), &quad, true);
    rl_scene *bare = floor_scene(rl_v3s(0.5f), NULL, true);
    rl_camera cam = { .eye = rl_v3(0.0f, 0.25f, 2.2f), .target = rl_v3(0.0f, 0.4f, 0.0f), .fov_deg = 80.0f,
                      .width = 16, .height = 16 };
    /* Raster primaries: pixel centres, so a lamp pixel is all lamp. */
    const char *const opts[] = { "spp", "96", "max_depth", "2", "primary", "raster", NULL };
    rl_renderer *ra = fx_make("pt", opts), *rb = fx_make("pt", opts);
    rl_image *a = fx_render_with(ra, with_light, &cam, RL_LAYER_COLOR, NULL);
    rl_image *b = fx_render_with(rb, bare, &cam, RL_LAYER_COLOR, NULL);
    const rl_gbuffer *g = rl_pt_gbuffer(ra);
    double sa = 0.0, sb = 0.0;
    int floor_px = 0, lamp_px = 0;
    for (int i = 0; i < 16 * 16; ++i) {
        if (g->object[i] == 0) {
            sa += a->color[i].x;
            sb += b->color[i].x;
            ++floor_px;
        } else if (g->object[i] == 1) {
            /* Seen from the camera the lamp shows its emission either way. */
            assert_float_equal(a->color[i].x, 4.0f, 1e-3f);
            assert_float_equal(b->color[i].x, 4.0f, 1e-3f);
            ++lamp_px;
        }
    }
    assert_true(floor_px > 64);
    assert_true(lamp_px > 0);
    assert_true(fabs(sa - sb) < 0.04 * sb);
    rl_image_release(a);
    rl_image_release(b);
    rl_renderer_release(ra);
    rl_renderer_release(rb);
    rl_scene_release(with_light);
    rl_scene_release(bare);
}

static void test_exact_backends_give_the_same_image(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    rl_render_stats st;
    rl_image *bvh = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "2", NULL }, &st);
    rl_image *grid = fx_render("pt", s, &cam, RL_LAYER_COLOR,
                               (const char *const[]){ "spp", "2", "shadow", "grid", "diffuse", "grid", NULL }, NULL);
    assert_images_close(bvh, grid, 1e-6f);
    if (rl_accel_kind_available(RL_ACCEL_EMBREE)) {
        rl_image *emb = fx_render("pt", s, &cam, RL_LAYER_COLOR,
                                  (const char *const[]){ "spp", "2", "shadow", "embree", "diffuse", "embree", NULL },
                                  NULL);
        /* Embree's own triangle test rounds differently: a path may turn
         * another way in a rare pixel, so compare the images as a whole. */
        assert_true(rmse(bvh, emb) < 0.02);
        rl_image_release(emb);
    }
    assert_int_equal(st.rays[RL_RAY_PRIMARY], 2 * SIZE * SIZE);
    assert_true(st.rays[RL_RAY_SHADOW] > 0 && st.rays[RL_RAY_DIFFUSE] > 0);
    assert_int_equal(st.samples, 2 * SIZE * SIZE);
    rl_image_release(bvh);
    rl_image_release(grid);
    rl_scene_release(s);
}

static void test_image_does_not_depend_on_the_thread_count(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, SIZE);
    rl_image *one = fx_render("pt", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "threads", "1", "spp", "2", NULL },
                              NULL);
    rl_image *two = fx_render("pt", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "threads", "2", "spp", "2", NULL },
                              NULL);
    fx_assert_images_identical(one, two);
    rl_image_release(one);
    rl_image_release(two);
    rl_scene_release(s);
}

/* Eq. 8: after a reset the error against a converged image falls with the
 * frames; the same frames repeat after rl_pt_reset. */
static void test_accumulation_converges_and_reset_repeats(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_image *ref = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "1024", "seed", "9", NULL },
                              NULL);
    rl_renderer *r = fx_make("pt", NULL);
    rl_image *img = NULL, *first = NULL;
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &first), RL_OK);
    const int checkpoints[3] = { 1, 8, 64 };
    double err[3];
    rl_pt_stats st;
    for (int frame = 1, k = 0; frame <= 64; ++frame) {
        assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
        assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
        assert_int_equal(st.frames, frame);
        assert_true(st.reset == (frame == 1));
        if (frame == 1)
            memcpy(first->color, img->color, 16 * 16 * sizeof *img->color);
        if (frame == checkpoints[k])
            err[k++] = rmse(img, ref);
    }
    assert_float_equal(st.spp, 64.0, 1e-9);
    assert_true(err[1] < 0.6 * err[0]);
    assert_true(err[2] < 0.6 * err[1]);
    /* A reset starts over with the same generator states. */
    assert_int_equal(rl_pt_reset(r), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_memory_equal(img->color, first->color, 16 * 16 * sizeof *img->color);
    /* The generic rl_renderer_reset (Jähn 2015's unconditioned state) does
     * the same. */
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    rl_renderer_reset(r);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_memory_equal(img->color, first->color, 16 * 16 * sizeof *img->color);
    /* So does any option change, and a camera change. */
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_int_equal(rl_renderer_set(r, "light_samples", "2"), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
    assert_true(st.reset && st.frames == 1);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    cam.eye.x += 0.01f;
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
    assert_true(st.reset && st.frames == 1);
    /* accumulate = false: every frame stands alone. */
    assert_int_equal(rl_renderer_set(r, "accumulate", "false"), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
    assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
    assert_true(st.reset && st.frames == 1);
    rl_image_release(img);
    rl_image_release(first);
    rl_image_release(ref);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* sample_offset: two renders of Sobol points 0-3 and 4-7 are one render of
 * points 0-7 (their mean equals it but for the float rounding of each
 * image), which is what lets `rl bench pt` resume a reference; the
 * per-pixel generators cannot skip ahead and refuse an offset. */
static void test_sample_offset_splits_one_render_into_two(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_image *whole = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "8", NULL }, NULL);
    rl_image *a = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "4", NULL }, NULL);
    rl_image *b = fx_render("pt", s, &cam, RL_LAYER_COLOR,
                            (const char *const[]){ "spp", "4", "sample_offset", "4", NULL }, NULL);
    bool differ = false;
    for (size_t i = 0; i < 16 * 16; ++i) {
        const float *w = &whole->color[i].x, *pa = &a->color[i].x, *pb = &b->color[i].x;
        for (int k = 0; k < 3; ++k) {
            float mean = 0.5f * (pa[k] + pb[k]);
            assert_true(fabsf(mean - w[k]) <= 1e-5f * fmaxf(1.0f, fabsf(w[k])));
            differ = differ || pa[k] != pb[k];
        }
    }
    assert_true(differ);
    rl_renderer *r = fx_make("pt", (const char *const[]){ "rng", "lcg", "sample_offset", "4", NULL });
    assert_int_equal(rl_renderer_prepare_inputs(r, s), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_render(r, s, &cam, whole, NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "sample_offset"));
    rl_renderer_release(r);
    rl_image_release(whole);
    rl_image_release(a);
    rl_image_release(b);
    rl_scene_release(s);
}

/* Sec. 8.5: half the pixels per frame; the first frame fills the rest from
 * the neighbours, the second completes the image. */
static void test_checkerboard_renders_half_and_fills_the_first_frame(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_renderer *r = fx_make("pt", (const char *const[]){ "checkerboard", "true", NULL });
    rl_render_stats rs;
    rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, &rs);
    rl_pt_stats st;
    assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
    assert_int_equal(st.pixels_traced, 16 * 16 / 2);
    assert_int_equal(rs.rays[RL_RAY_PRIMARY], 16 * 16 / 2);
    /* Frame 0 traces (x + y) even; the others are their 4-neighbours' mean. */
    for (int y = 0; y < 16; ++y)
        for (int x = (y + 1) % 2; x < 16; x += 2) {
            float sum = 0.0f;
            int n = 0;
            for (int j = 0; j < 4; ++j) {
                int nx = x + (j == 0) - (j == 1), ny = y + (j == 2) - (j == 3);
                if (nx >= 0 && ny >= 0 && nx < 16 && ny < 16) {
                    sum += img->color[ny * 16 + nx].y;
                    ++n;
                }
            }
            assert_float_equal(img->color[y * 16 + x].y, sum / (float)n, 1e-5f * (1.0f + sum));
        }
    assert_int_equal(rl_renderer_render(r, s, &cam, img, &rs), RL_OK);
    assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
    assert_int_equal(st.frames, 2);
    assert_float_equal(st.spp, 1.0, 1e-12);
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* Sec. 8.1: rasterized primary visibility converges to the same image as
 * traced primaries (up to the jitter at edges). */
static void test_raster_primary_agrees_with_traced_primary(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 16);
    rl_render_stats rs;
    rl_image *tr = fx_render("pt", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "spp", "64", NULL }, NULL);
    rl_image *ra = fx_render("pt", s, &cam, FX_ALL_LAYERS, (const char *const[]){ "spp", "64", "primary", "raster",
                                                                                  NULL }, &rs);
    assert_int_equal(rs.rays[RL_RAY_PRIMARY], 0);
    rl_vec3 a = mean_color(tr), b = mean_color(ra);
    assert_float_equal(a.x, b.x, 0.05f * a.x);
    assert_float_equal(a.y, b.y, 0.05f * a.y);
    int same = 0;
    for (int i = 0; i < 16 * 16; ++i)
        same += tr->object_id[i] == ra->object_id[i];
    assert_true(same >= 16 * 16 - 3);
    rl_image_release(tr);
    rl_image_release(ra);
    rl_scene_release(s);
}

static void test_every_rng_renders_the_same_expectation(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 12);
    const char *const kinds[] = { "lcg", "tausworthe", "hybrid", "sobol" };
    rl_vec3 mean[4];
    for (int k = 0; k < 4; ++k) {
        rl_renderer *r = fx_make("pt", (const char *const[]){ "rng", kinds[k], "spp", "64", NULL });
        rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
        rl_pt_stats st;
        assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
        assert_int_equal(st.sobol, k == 3);
        if (k < 3)
            assert_int_equal(st.rng, (rl_rng_gpu_kind)k);
        mean[k] = mean_color(img);
        rl_image_release(img);
        rl_renderer_release(r);
    }
    for (int k = 1; k < 4; ++k) {
        assert_float_equal(mean[k].x, mean[0].x, 0.05f * mean[0].x);
        assert_float_equal(mean[k].z, mean[0].z, 0.05f * mean[0].z);
    }
    rl_scene_release(s);
}

static void test_stats_count_queries_by_backend(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = fx_cornell(&cam, 12);
    rl_renderer *r = fx_make("pt", (const char *const[]){ "shadow", "grid", "spp", "2", NULL });
    rl_render_stats rs;
    rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, &rs);
    rl_pt_stats st;
    assert_int_equal(rl_pt_get_stats(r, &st), RL_OK);
    assert_int_equal(st.shadow_queries[RL_PT_BACKEND_GRID], rs.rays[RL_RAY_SHADOW]);
    assert_int_equal(st.shadow_queries[RL_PT_BACKEND_BVH], 0);
    assert_int_equal(st.trace_queries[RL_PT_BACKEND_BVH],
                     rs.rays[RL_RAY_PRIMARY] + rs.rays[RL_RAY_DIFFUSE] + rs.rays[RL_RAY_REFLECTION] +
                         rs.rays[RL_RAY_REFRACTION]);
    assert_int_equal(st.gbuffer_rays, 12 * 12);
    assert_true(st.build_bvh_ms > 0.0 && st.build_grid_ms > 0.0);
    assert_true(st.mrays_per_s > 0.0);
    assert_true(st.time_paths_ms > 0.0);
    assert_int_equal(st.samples, 2 * 12 * 12);
    assert_string_equal(rl_pt_backend_name(RL_PT_BACKEND_LS_PNMT), "ls-pnmt");
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(s);
}

/* Mirrors and glass take the reflection and refraction paths. */
static void test_specular_materials_trace_reflection_and_refraction_rays(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("spheres", NULL, &s), RL_OK);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = cam.height = 16;
    rl_render_stats rs;
    rl_image *img = fx_render("pt", s, &cam, RL_LAYER_COLOR, (const char *const[]){ "spp", "4", NULL }, &rs);
    assert_true(rs.rays[RL_RAY_REFLECTION] > 0);
    for (int i = 0; i < 16 * 16; ++i)
        assert_true(isfinite(img->color[i].x) && img->color[i].x >= 0.0f);
    rl_image_release(img);
    rl_scene_release(s);
}

/* max_depth = -1 takes the path length the scene carries (Sec. 9.3: the
 * built-ins store the thesis' value in the root attribute max_path_length),
 * and 3 for a scene without it. */
static void test_max_depth_default_comes_from_the_scene(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("ls-cornell", NULL, &s), RL_OK);
    assert_string_equal(rl_scene_node_attr(s, 0, "max_path_length"), "3");
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = 32;
    cam.height = 18;
    const char *const by_scene[] = { "seed", "5", NULL };
    const char *const three[] = { "seed", "5", "max_depth", "3", NULL };
    const char *const two[] = { "seed", "5", "max_depth", "2", NULL };
    rl_image *a = fx_render("pt", s, &cam, RL_LAYER_COLOR, by_scene, NULL);
    rl_image *b = fx_render("pt", s, &cam, RL_LAYER_COLOR, three, NULL);
    rl_image *c = fx_render("pt", s, &cam, RL_LAYER_COLOR, two, NULL);
    fx_assert_images_identical(a, b);
    /* The option matters at all: one bounce less is a different image. */
    bool differ = false;
    for (int i = 0; i < cam.width * cam.height; ++i)
        differ = differ || a->color[i].x != c->color[i].x;
    assert_true(differ);
    rl_image_release(a);
    rl_image_release(b);
    rl_image_release(c);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pt_is_registered_and_refuses_bad_options),
        cmocka_unit_test(test_max_depth_default_comes_from_the_scene),
        cmocka_unit_test(test_white_furnace_converges_to_e_over_one_minus_albedo),
        cmocka_unit_test(test_lambertian_floor_under_point_light_matches_closed_form),
        cmocka_unit_test(test_uniform_environment_lights_a_lambertian_floor),
        cmocka_unit_test(test_progress_callback_cancels_and_leaves_no_partial_frame),
        cmocka_unit_test(test_nee_on_covered_emitter_matches_hitting_the_bare_emitter),
        cmocka_unit_test(test_exact_backends_give_the_same_image),
        cmocka_unit_test(test_image_does_not_depend_on_the_thread_count),
        cmocka_unit_test(test_accumulation_converges_and_reset_repeats),
        cmocka_unit_test(test_sample_offset_splits_one_render_into_two),
        cmocka_unit_test(test_checkerboard_renders_half_and_fills_the_first_frame),
        cmocka_unit_test(test_raster_primary_agrees_with_traced_primary),
        cmocka_unit_test(test_every_rng_renders_the_same_expectation),
        cmocka_unit_test(test_stats_count_queries_by_backend),
        cmocka_unit_test(test_specular_materials_trace_reflection_and_refraction_rays),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
