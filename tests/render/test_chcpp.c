/* test_chcpp.c: CHC++ (renderer "chcpp") is conservative: on walks through
 * a box city built here, where no two surfaces are coplanar, every frame
 * equals "raster" in colour, depth and IDs, pixel for pixel, also with
 * query latency simulated (answers a frame later, the V-queue); and it
 * culls: at street level it draws a fraction of the triangles; its overlay
 * shows the visible and occluded nodes. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render_fixtures.h"
#include "rl/rl.h"

static rl_camera street_camera(float t)
{
    /* Down a street between building rows, turning slowly. */
    rl_camera c = { .eye = rl_v3(9.5f + 0.8f * t, 1.7f, -2.0f + 6.0f * t),
                    .target = rl_v3(9.5f + 3.0f * sinf(0.2f * t), 1.5f, 60.0f),
                    .fov_deg = 60.0f, .width = 160, .height = 120 };
    return c;
}

/* The latency figures of a walk, summed over its frames. */
typedef struct latency_sums {
    uint64_t queries, ready, waited, carried, carried_in, filled;
    uint32_t max_carried;
} latency_sums;

/* Every frame's answers add up: each query issued or carried in is read
 * (found ready or waited for) or carried on, and what a frame carries the
 * next one takes over. */
static void add_latency(latency_sums *w, const rl_renderer *chc, uint64_t *carried)
{
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(chc, &cs), RL_OK);
    assert_int_equal(cs.queries_carried_in, *carried);
    assert_int_equal(cs.queries + cs.queries_carried_in, cs.queries_ready + cs.queries_waited + cs.queries_carried);
    *carried = cs.queries_carried;
    w->queries += cs.queries;
    w->ready += cs.queries_ready;
    w->waited += cs.queries_waited;
    w->carried += cs.queries_carried;
    w->carried_in += cs.queries_carried_in;
    w->filled += cs.queries_filled;
    if (cs.queries_carried > w->max_carried)
        w->max_carried = (uint32_t)cs.queries_carried;
}

/* Frames of a walk, each rendered by raster and by one chcpp per option
 * list of opts (n of them, kept across the frames): every chcpp frame
 * equals raster's; sums[i] gets the latency figures of the i-th. */
static void check_walk_all(const rl_scene *s, const char *const *const *opts, int n,
                           const char *const *raster_opts, int frames, uint64_t seed, bool street,
                           latency_sums *sums)
{
    rl_renderer *chc[8];
    uint64_t carried[8] = { 0 };
    assert_true(n <= 8);
    for (int i = 0; i < n; ++i) {
        chc[i] = fx_make("chcpp", opts[i]);
        sums[i] = (latency_sums){ 0 };
    }
    rl_rng rng;
    rl_rng_seed(&rng, seed, 3);
    rl_vec3 eye = rl_v3(60, 20, -30), dir = rl_v3(0, -0.3f, 1);
    for (int f = 0; f < frames; ++f) {
        rl_camera cam;
        if (street) {
            cam = street_camera((float)f);
        } else {
            /* A random walk with random turns, inside and above the city. */
            eye = rl_add(eye, rl_v3(6.0f * (rl_rng_float(&rng) - 0.5f), 4.0f * (rl_rng_float(&rng) - 0.5f),
                                    6.0f * (rl_rng_float(&rng) - 0.3f)));
            eye.y = rl_maxf(eye.y, 0.5f);
            dir = rl_normalize(rl_add(dir, rl_v3(0.6f * (rl_rng_float(&rng) - 0.5f),
                                                 0.3f * (rl_rng_float(&rng) - 0.5f),
                                                 0.6f * (rl_rng_float(&rng) - 0.5f))));
            cam = (rl_camera){ .eye = eye, .target = rl_add(eye, dir), .fov_deg = 70.0f, .width = 128,
                               .height = 96 };
        }
        rl_render_stats a, b;
        rl_image *ref = fx_render("raster", s, &cam, FX_ALL_LAYERS, raster_opts, &a);
        for (int i = 0; i < n; ++i) {
            rl_image *img = fx_render_with(chc[i], s, &cam, FX_ALL_LAYERS, &b);
            fx_assert_images_identical(ref, img);
            assert_true(b.triangles_rasterized <= a.triangles_rasterized);
            add_latency(&sums[i], chc[i], &carried[i]);
            rl_image_release(img);
        }
        rl_image_release(ref);
    }
    for (int i = 0; i < n; ++i)
        rl_renderer_release(chc[i]);
}

static void check_walk(const rl_scene *s, const char *const *opts, const char *const *raster_opts, int frames,
                       uint64_t seed, bool street)
{
    latency_sums w;
    check_walk_all(s, &opts, 1, raster_opts, frames, seed, street, &w);
}

static void print_latency(const char *what, latency_sums w)
{
    print_message("%-30s %5llu queries, %5llu found ready, %4llu waited for, %4llu carried (at most %u), %4llu "
                  "filled a wait\n", what, (unsigned long long)w.queries, (unsigned long long)w.ready,
                  (unsigned long long)w.waited, (unsigned long long)w.carried, w.max_carried,
                  (unsigned long long)w.filled);
}

/* The 26 frames (16 of a random walk, 10 down a street) with the defaults
 * and with the drawer's query latency simulated (query_delay: the first n
 * polls of each query find no answer), and the street also with the other
 * latency variants, each frame equal to raster's.
 * Latency hiding (Mattausch et al. 2008, Sec. 4.1): the software drawer
 * answers at the issue, so by default nothing is waited for or carried and
 * the V-queue never fills a wait (it goes at each frame's end). With
 * latency, the V-queue's queries fill the waits for the I-queue's answers
 * and previously visible nodes' answers not there at a frame's end are
 * carried into the next (latency=frame); with latency=wait nothing is
 * carried; CHC's order (vqueue=false) neither carries nor fills. An answer
 * that never comes in a poll (query_delay huge) is waited for where the
 * frame needs it and otherwise carried on, never piling up beyond one per
 * node. */
static void test_chcpp_equals_raster_on_random_walks(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    static const char *const delay_frame[] = { "query_delay", "4", NULL };
    static const char *const delay_wait[] = { "query_delay", "4", "latency", "wait", NULL };
    static const char *const delay_chc[] = { "query_delay", "4", "vqueue", "false", "latency", "wait", NULL };
    static const char *const never[] = { "query_delay", "1000000", NULL };
    const char *const *opts[] = { NULL, delay_frame, delay_wait, delay_chc, never };
    static const char *const what[] = { "defaults", "query_delay 4, latency=frame", "query_delay 4, latency=wait",
                                        "query_delay 4, CHC order, wait", "query_delay 1000000" };
    enum { N = sizeof opts / sizeof opts[0] };
    latency_sums walk[2], w[N];
    check_walk_all(s, opts, 2, NULL, 16, 11, false, walk);
    assert_true(walk[0].queries > 0);
    assert_int_equal(walk[0].ready, walk[0].queries);
    assert_int_equal(walk[0].waited + walk[0].carried + walk[0].filled, 0);
    assert_true(walk[1].carried > 0);
    /* The street with every kind of latency (the others on it only, to
     * stay quick). */
    check_walk_all(s, opts, N, NULL, 10, 0, true, w);
    for (int i = 0; i < N; ++i)
        print_latency(what[i], w[i]);
    assert_true(w[0].queries > 0);
    assert_int_equal(w[0].ready, w[0].queries);
    assert_int_equal(w[0].waited + w[0].carried + w[0].filled, 0);

    assert_true(w[1].filled > 0 && w[1].carried > 0 && w[1].carried_in > 0);
    assert_true(w[1].ready > 0 && w[1].waited > 0);
    assert_true(w[2].filled > 0 && w[2].waited > 0);
    assert_int_equal(w[2].carried + w[2].carried_in, 0);
    assert_int_equal(w[3].carried + w[3].filled, 0);

    rl_renderer *probe = fx_make("chcpp", NULL);
    rl_camera cam = street_camera(0.0f);
    rl_image *img = fx_render_with(probe, s, &cam, RL_LAYER_COLOR, NULL);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(probe, &cs), RL_OK);
    assert_int_equal(w[4].ready, 0);
    assert_true(w[4].carried > 0);
    assert_true(w[4].max_carried <= cs.octree_nodes);
    rl_image_release(img);
    rl_renderer_release(probe);
    rl_scene_release(s);
}

/* Every variant must stay conservative: no multi-queries, loose boxes, a
 * flat tree, a deep one, queries every frame, batch 1. */
static void test_chcpp_variants_stay_conservative(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    static const char *const variants[][7] = {
        { "multiquery", "false", NULL },
        { "tight", "false", NULL },
        { "max_depth", "0", NULL },
        { "max_depth", "9", "looseness", "1.5", NULL },
        { "assumed_visible", "1", "batch", "1", NULL },
        { "shading", "flat", "cull", "true", "background", "0.2,0.3,0.4", NULL },
    };
    static const char *const shaded[] = { "shading", "flat", "cull", "true", "background", "0.2,0.3,0.4", NULL };
    const size_t n = sizeof variants / sizeof variants[0];
    for (size_t v = 0; v < n; ++v)
        check_walk(s, variants[v], v + 1 == n ? shaded : NULL, 5, 100 + v, v % 2 == 0);
    rl_scene_release(s);
}

/* A viewer just outside a box but inside the grown box its query draws
 * (by 1e-3 of the longest side) sees only back faces, which count no
 * pixel: CHC++ once dropped a 100 m building seen from 0.5-8 cm. Fresh
 * renderers (first frames) and one kept across the views, tight and loose
 * query boxes, several faces. */
static void test_chcpp_is_conservative_for_viewers_at_a_wall(void **state)
{
    (void)state;
    uint32_t mat;
    rl_scene *s = fx_scene_with_material(&mat);
    fx_add_box(s, mat, rl_v3(0, 0, 0), rl_v3(100, 20, 100), 1);
    fx_add_box(s, mat, rl_v3(-200, 0, -200), rl_v3(-199, 1, -199), 1);
    rl_light l = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3s(1.0f), .intensity = 1.0f,
                   .direction = rl_normalize(rl_v3(0.4f, -1.0f, 0.3f)) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    static const float gaps[] = { 0.005f, 0.02f, 0.05f, 0.08f, 0.2f };
    static const char *const loose[] = { "tight", "false", NULL };
    const char *const *variants[] = { NULL, loose };
    for (int v = 0; v < 2; ++v) {
        rl_renderer *kept = fx_make("chcpp", variants[v]);
        for (int g = 0; g < 5; ++g)
            for (int face = 0; face < 3; ++face) {
                /* in front of the -x face, above the top, beyond the +z face */
                rl_vec3 eye = face == 0 ? rl_v3(-gaps[g], 10, 50)
                            : face == 1 ? rl_v3(50, 20 + gaps[g], 50) : rl_v3(30, 8, 100 + gaps[g]);
                rl_vec3 at = face == 0 ? rl_v3(10, 10, 50) : face == 1 ? rl_v3(55, 0, 58) : rl_v3(30, 8, 0);
                rl_camera cam = { .eye = eye, .target = at, .fov_deg = 60.0f, .width = 64, .height = 48 };
                rl_image *ref = fx_render("raster", s, &cam, FX_ALL_LAYERS, NULL, NULL);
                rl_image *fresh = fx_render("chcpp", s, &cam, FX_ALL_LAYERS, variants[v], NULL);
                rl_image *img = fx_render_with(kept, s, &cam, FX_ALL_LAYERS, NULL);
                fx_assert_images_identical(ref, fresh);
                fx_assert_images_identical(ref, img);
                rl_image_release(ref);
                rl_image_release(fresh);
                rl_image_release(img);
            }
        rl_renderer_release(kept);
    }
    rl_scene_release(s);
}

static void test_chcpp_culls_at_street_level(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_renderer *chc = fx_make("chcpp", NULL);
    rl_render_stats full, st;
    rl_camera cam = street_camera(2.0f);
    rl_image *ref = fx_render("raster", s, &cam, RL_LAYER_COLOR, NULL, &full);
    for (int f = 0; f < 3; ++f) {   /* the third frame is temporally coherent */
        rl_image *img = fx_render_with(chc, s, &cam, RL_LAYER_COLOR, &st);
        rl_image_release(img);
    }
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(chc, &cs), RL_OK);
    assert_true(st.triangles_rasterized * 3 < full.triangles_rasterized);
    assert_true(cs.objects_drawn < 60);
    assert_true(cs.nodes_occluded + cs.nodes_frustum_culled > 0);
    assert_int_equal(st.occlusion_queries, cs.queries);
    /* A coherent frame needs fewer queries than the first one after a reset. */
    uint64_t coherent = cs.queries;
    rl_renderer_reset(chc);
    rl_image *img = fx_render_with(chc, s, &cam, RL_LAYER_COLOR, &st);
    assert_int_equal(rl_culling_get_stats(chc, &cs), RL_OK);
    assert_true(cs.queries > coherent);
    assert_true(cs.octree_nodes > 1 && cs.octree_depth <= 5);
    rl_image_release(img);
    rl_image_release(ref);
    rl_renderer_release(chc);
    rl_scene_release(s);
}

/* overlay=nodes draws the node boxes over the colour and changes nothing
 * else: depth and IDs stay raster's; at street level both kinds appear,
 * green visible nodes and red occluded ones. */
static void test_chcpp_overlay_draws_visible_and_occluded_nodes(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    rl_renderer *plain = fx_make("chcpp", NULL);
    rl_renderer *boxes = fx_make("chcpp", (const char *const[]){ "overlay", "nodes", NULL });
    rl_camera cam = street_camera(2.0f);
    rl_image *a = NULL, *b = NULL;
    for (int f = 0; f < 2; ++f) {
        rl_image_release(a);
        rl_image_release(b);
        a = fx_render_with(plain, s, &cam, FX_ALL_LAYERS, NULL);
        b = fx_render_with(boxes, s, &cam, FX_ALL_LAYERS, NULL);
    }
    size_t n = (size_t)cam.width * (size_t)cam.height, green = 0, red = 0, changed = 0;
    for (size_t i = 0; i < n; ++i) {
        assert_int_equal(a->object_id[i], b->object_id[i]);
        assert_true(a->depth[i] == b->depth[i] || (a->depth[i] != a->depth[i] && b->depth[i] != b->depth[i]));
        rl_vec4 p = a->color[i], q = b->color[i];
        if (p.x != q.x || p.y != q.y || p.z != q.z) {
            changed++;
            green += q.x == 0.2f && q.y == 1.0f && q.z == 0.2f;
            red += q.x == 1.0f && q.y == 0.2f && q.z == 0.2f;
        }
    }
    assert_true(green > 0 && red > 0);
    assert_int_equal(green + red, changed);
    assert_true(changed < n / 2);
    rl_image_release(a);
    rl_image_release(b);
    rl_renderer_release(plain);
    rl_renderer_release(boxes);
    rl_scene_release(s);
}

/* Sums of a street walk's culling statistics (frames after the first). */
typedef struct walk_sums {
    uint64_t queries, multiqueries, occluded, triangles;
} walk_sums;

static walk_sums street_walk(const rl_scene *s, const char *const *opts)
{
    rl_renderer *chc = fx_make("chcpp", opts);
    walk_sums w = { 0 };
    for (int f = 0; f < 12; ++f) {
        rl_camera cam = street_camera(0.5f * (float)f);
        rl_image *img = fx_render_with(chc, s, &cam, RL_LAYER_COLOR, NULL);
        rl_culling_stats cs;
        assert_int_equal(rl_culling_get_stats(chc, &cs), RL_OK);
        if (f > 0) {
            w.queries += cs.queries;
            w.multiqueries += cs.multiqueries;
            w.occluded += cs.nodes_occluded;
            w.triangles += cs.triangles_drawn;
        }
        rl_image_release(img);
    }
    rl_renderer_release(chc);
    return w;
}

/* CHC++'s additions are in use and do what they are for (Mattausch et al.
 * 2008, Sec. 4): multi-queries answer batches of previously invisible
 * nodes with fewer queries, and the tight bounds of a node's objects find
 * at least as much occluded as its loose box. */
static void test_chcpp_multiqueries_and_tight_bounds_are_used(void **state)
{
    (void)state;
    rl_scene *s = fx_box_city();
    walk_sums def = street_walk(s, NULL);
    walk_sums single = street_walk(s, (const char *const[]){ "multiquery", "false", NULL });
    walk_sums loose = street_walk(s, (const char *const[]){ "tight", "false", NULL });
    print_message("street walk: default %llu queries (%llu multi), %llu occluded, %llu triangles; without "
                  "multi-queries %llu queries; loose boxes %llu occluded, %llu triangles\n",
                  (unsigned long long)def.queries, (unsigned long long)def.multiqueries,
                  (unsigned long long)def.occluded, (unsigned long long)def.triangles,
                  (unsigned long long)single.queries, (unsigned long long)loose.occluded,
                  (unsigned long long)loose.triangles);
    assert_true(def.multiqueries > 0);
    assert_int_equal(single.multiqueries, 0);
    assert_true(single.queries > def.queries);
    assert_true(loose.triangles >= def.triangles);
    rl_scene_release(s);
}

static void test_chcpp_refuses_bad_options(void **state)
{
    (void)state;
    rl_renderer *r = fx_make("chcpp", NULL);
    assert_int_equal(rl_renderer_set(r, "max_depth", "21"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "looseness", "0.5"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "batch", "0"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "assumed_visible", "-1"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "latency", "never"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "query_delay", "-1"), RL_ERR_INVALID_ARG);
    rl_culling_stats cs;
    assert_int_equal(rl_culling_get_stats(r, &cs), RL_ERR_INVALID_ARG);   /* nothing rendered */
    rl_renderer *raster = fx_make("raster", NULL);
    assert_int_equal(rl_culling_get_stats(raster, &cs), RL_ERR_INVALID_ARG);
    rl_renderer_release(raster);
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_chcpp_equals_raster_on_random_walks),
        cmocka_unit_test(test_chcpp_variants_stay_conservative),
        cmocka_unit_test(test_chcpp_is_conservative_for_viewers_at_a_wall),
        cmocka_unit_test(test_chcpp_culls_at_street_level),
        cmocka_unit_test(test_chcpp_multiqueries_and_tight_bounds_are_used),
        cmocka_unit_test(test_chcpp_refuses_bad_options),
        cmocka_unit_test(test_chcpp_overlay_draws_visible_and_occluded_nodes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
