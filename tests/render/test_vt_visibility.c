/* test_vt_visibility.c: projection and visibility tests of Vertex Tracing
 * (vt_visibility.c; Ullmann 2003, Sec. 3.4.2-3.4.3). The rasterizer is the
 * oracle for the projection: pixels it covers must be exactly those whose
 * centres lie inside the triangle of the projected vertices, and its depth
 * layer must hold the vertices' depth. The z-buffer test runs on a buffer
 * drawn by the rasterizer and on hand-made ones; the viewport test on the
 * cases of Cohen-Sutherland that matter: inside, beside, past a corner,
 * through a corner, and across the near plane. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/vt_internal.h"
#include "rl/rl_raster.h"

typedef struct view_fixture {
    rl_camera cam;
    rl_mat4 view, proj;
    vt_view v;
} view_fixture;

static void make_view(view_fixture *f, rl_vec3 eye, rl_vec3 target, float fov_deg, int w, int h,
                      float z_near, float z_far)
{
    memset(f, 0, sizeof *f);
    f->cam = (rl_camera){ .eye = eye, .target = target, .fov_deg = fov_deg, .width = w,
                          .height = h, .z_near = z_near, .z_far = z_far };
    f->view = rl_camera_view(&f->cam);
    f->proj = rl_camera_projection(&f->cam, z_near, z_far);
    f->v.view_proj = rl_mat4_mul(&f->proj, &f->view);
    f->v.eye = eye;
    f->v.forward = rl_normalize(rl_sub(target, eye));
    f->v.width = w;
    f->v.height = h;
    f->v.z_near = z_near;
    f->v.depth_tolerance = 1e-3f;
}

/* The standard test camera: at the origin looking down -z, 90 degrees, square,
 * so a point at eye depth d with NDC (u, v) is (u d, v d, -d). */
static void make_axis_view(view_fixture *f)
{
    make_view(f, rl_v3(0, 0, 0), rl_v3(0, 0, -1), 90.0f, 100, 100, 0.1f, 100.0f);
}

static vt_vertex at(const vt_view *view, rl_vec3 p)
{
    vt_vertex v;
    memset(&v, 0, sizeof v);
    v.p = p;
    vt_project_vertex(view, &v);
    return v;
}

static vt_vertex at_ndc(const vt_view *view, float u, float w, float depth)
{
    return at(view, rl_v3(u * depth, w * depth, -depth));
}

static uint64_t rng_next(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static float rng_float(uint64_t *s, float lo, float hi)
{
    return lo + (hi - lo) * (float)(rng_next(s) >> 40) / (float)(1ull << 24);
}

static void draw(rl_raster *r, const rl_vec3 *p, uint32_t num_triangles, uint32_t first_id)
{
    uint32_t idx[12];
    for (uint32_t i = 0; i < 3 * num_triangles; ++i)
        idx[i] = i;
    rl_raster_batch b = { .num_vertices = 3 * num_triangles, .positions = p,
                          .num_triangles = num_triangles, .indices = idx,
                          .first_triangle_id = first_id, .color = rl_v4(1, 1, 1, 1) };
    assert_int_equal(rl_raster_draw(r, &b, NULL), RL_OK);
}

static double edge_fn(const vt_vertex *a, const vt_vertex *b, double x, double y)
{
    return ((double)b->sx - a->sx) * (y - a->sy) - ((double)b->sy - a->sy) * (x - a->sx);
}

static void test_projection_lands_where_the_rasterizer_draws(void **state)
{
    (void)state;
    view_fixture f;
    make_view(&f, rl_v3(0.3f, 0.2f, 5.0f), rl_v3(0, 0, 0), 50.0f, 64, 48, 0.1f, 50.0f);
    rl_raster *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(&(rl_raster_desc){ .threads = 1 }, &r), RL_OK);
    assert_int_equal(rl_image_create(64, 48, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &img),
                     RL_OK);
    assert_int_equal(rl_raster_set_target(r, img, &f.view, &f.proj), RL_OK);
    uint64_t seed = 42;
    int checked_in = 0, checked_out = 0;
    for (int trial = 0; trial < 60; ++trial) {
        rl_image_clear(img);
        rl_vec3 c = rl_v3(rng_float(&seed, -1.5f, 1.5f), rng_float(&seed, -1.0f, 1.0f),
                          rng_float(&seed, -2.0f, 1.0f));
        rl_vec3 p[3];
        for (int k = 0; k < 3; ++k)
            p[k] = rl_add(c, rl_v3(rng_float(&seed, -1.0f, 1.0f), rng_float(&seed, -1.0f, 1.0f),
                                   rng_float(&seed, -1.0f, 1.0f)));
        draw(r, p, 1, 7);
        vt_vertex v[3] = { at(&f.v, p[0]), at(&f.v, p[1]), at(&f.v, p[2]) };
        for (int k = 0; k < 3; ++k) {
            /* clip w is the eye depth for rl's perspective */
            assert_float_equal(v[k].cw, v[k].depth, 1e-5f * v[k].depth);
        }
        double area = edge_fn(&v[0], &v[1], v[2].sx, v[2].sy);
        double sign = area > 0 ? 1.0 : -1.0;
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 64; ++x) {
                double px = x + 0.5, py = y + 0.5;
                /* distance to each side in pixels, positive inside */
                double dmin = INFINITY;
                for (int k = 0; k < 3; ++k) {
                    const vt_vertex *a = &v[k], *b = &v[(k + 1) % 3];
                    double len = hypot((double)b->sx - a->sx, (double)b->sy - a->sy);
                    double d = sign * edge_fn(a, b, px, py) / len;
                    dmin = d < dmin ? d : dmin;
                }
                bool covered = img->triangle_id[y * 64 + x] == 7;
                if (dmin > 0.02) {
                    assert_true(covered);
                    checked_in++;
                } else if (dmin < -0.02) {
                    assert_false(covered);
                    checked_out++;
                }
            }
    }
    assert_true(checked_in > 1000);
    assert_true(checked_out > 100 * 1000);
    rl_image_release(img);
    rl_raster_release(r);
}

static void test_depth_is_what_the_rasterizer_stores(void **state)
{
    (void)state;
    view_fixture f;
    make_view(&f, rl_v3(1.0f, 2.0f, 6.0f), rl_v3(0, 0, 0), 40.0f, 80, 60, 0.5f, 30.0f);
    rl_raster *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(NULL, &r), RL_OK);
    assert_int_equal(rl_image_create(80, 60, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &img),
                     RL_OK);
    assert_int_equal(rl_raster_set_target(r, img, &f.view, &f.proj), RL_OK);
    /* a triangle parallel to the image plane at eye depth 5: constant depth */
    rl_camera_frame fr = rl_camera_frame_make(&f.cam);
    rl_vec3 centre = rl_madd(f.cam.eye, f.v.forward, 5.0f);
    rl_vec3 p[3] = { rl_add(centre, rl_scale(fr.u, -1.0f)), rl_add(centre, rl_scale(fr.u, 1.0f)),
                     rl_add(centre, rl_scale(fr.v, 1.0f)) };
    draw(r, p, 1, 0);
    for (int k = 0; k < 3; ++k) {
        vt_vertex v = at(&f.v, p[k]);
        assert_float_equal(v.depth, 5.0f, 1e-5f);
        assert_float_equal(v.cw, 5.0f, 1e-5f);
    }
    int hit = 0;
    for (int i = 0; i < 80 * 60; ++i)
        if (img->triangle_id[i] != RL_ID_NONE) {
            assert_float_equal(img->depth[i], 5.0f, 5e-5f);
            hit++;
        }
    assert_true(hit > 100);
    rl_image_release(img);
    rl_raster_release(r);
}

static void test_behind_the_eye_has_no_projection(void **state)
{
    (void)state;
    view_fixture f;
    make_axis_view(&f);
    vt_vertex v = at(&f.v, rl_v3(1, 2, 3));
    assert_true(v.cw < 0.0f);
    assert_float_equal(v.depth, -3.0f, 1e-6f);
    assert_float_equal(v.sx, 0.0f, 0.0f);
    assert_float_equal(v.sy, 0.0f, 0.0f);
    assert_false(vt_vertex_visible(&f.v, &v));
    /* the centre of the view and the top-left corner (y down) */
    v = at_ndc(&f.v, 0.0f, 0.0f, 4.0f);
    assert_float_equal(v.sx, 50.0f, 1e-4f);
    assert_float_equal(v.sy, 50.0f, 1e-4f);
    v = at_ndc(&f.v, -1.0f, 1.0f, 4.0f);
    assert_float_equal(v.sx, 0.0f, 1e-4f);
    assert_float_equal(v.sy, 0.0f, 1e-4f);
}

/* A vertex placed directly in screen space. */
static vt_vertex screen_vertex(float sx, float sy, float depth)
{
    vt_vertex v;
    memset(&v, 0, sizeof v);
    v.sx = sx;
    v.sy = sy;
    v.depth = depth;
    v.cw = depth;
    return v;
}

static void test_z_test_takes_the_farthest_of_four_pixels(void **state)
{
    (void)state;
    enum { W = 8, H = 6 };
    float depth[W * H];
    for (int i = 0; i < W * H; ++i)
        depth[i] = 10.0f;
    vt_view view;
    memset(&view, 0, sizeof view);
    view.width = W;
    view.height = H;
    view.z_near = 0.1f;
    view.depth = depth;
    view.depth_tolerance = 1e-3f;

    vt_vertex v = screen_vertex(3.2f, 2.7f, 5.0f);
    assert_true(vt_vertex_visible(&view, &v));
    v.depth = 10.009f;                    /* within the relative tolerance */
    assert_true(vt_vertex_visible(&view, &v));
    v.depth = 10.02f;
    assert_false(vt_vertex_visible(&view, &v));
    /* the four centres around (3.2, 2.7) are pixels (2..3, 2..3); the
     * farthest of them decides */
    depth[2 * W + 2] = 20.0f;
    assert_true(vt_vertex_visible(&view, &v));
    depth[2 * W + 2] = 10.0f;
    depth[3 * W + 3] = INFINITY;          /* background next to a silhouette */
    assert_true(vt_vertex_visible(&view, &v));
    depth[3 * W + 3] = 10.0f;
    depth[1 * W + 2] = 20.0f;             /* not one of the four */
    depth[2 * W + 4] = 20.0f;
    assert_false(vt_vertex_visible(&view, &v));

    /* on the border: only the pixels inside count */
    vt_vertex corner = screen_vertex(0.0f, 0.0f, 10.0f);
    assert_true(vt_vertex_visible(&view, &corner));
    corner.depth = 11.0f;
    assert_false(vt_vertex_visible(&view, &corner));
    vt_vertex edge = screen_vertex((float)W, 3.0f, 10.0f);
    assert_true(vt_vertex_visible(&view, &edge));
    /* off the screen or in front of the near plane */
    vt_vertex off = screen_vertex(-0.5f, 3.0f, 1.0f);
    assert_false(vt_vertex_visible(&view, &off));
    off = screen_vertex(3.0f, (float)H + 0.5f, 1.0f);
    assert_false(vt_vertex_visible(&view, &off));
    vt_vertex near = screen_vertex(3.0f, 3.0f, 0.05f);
    assert_false(vt_vertex_visible(&view, &near));
    /* without a z-buffer only the screen counts */
    view.depth = NULL;
    v.depth = 1e6f;
    assert_true(vt_vertex_visible(&view, &v));
}

static void test_z_test_against_a_rasterized_occluder(void **state)
{
    (void)state;
    view_fixture f;
    make_axis_view(&f);
    rl_raster *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(NULL, &r), RL_OK);
    assert_int_equal(rl_image_create(100, 100, RL_LAYER_DEPTH | RL_LAYER_ID, &img), RL_OK);
    assert_int_equal(rl_raster_set_target(r, img, &f.view, &f.proj), RL_OK);
    /* a wall at depth 10 over the whole view, an occluder square at depth 4
     * covering NDC [-0.5, 0.5]^2 */
    rl_vec3 p[12] = {
        { -20, -20, -10 }, { 20, -20, -10 }, { 20, 20, -10 },
        { -20, -20, -10 }, { 20, 20, -10 }, { -20, 20, -10 },
        { -2, -2, -4 }, { 2, -2, -4 }, { 2, 2, -4 },
        { -2, -2, -4 }, { 2, 2, -4 }, { -2, 2, -4 },
    };
    draw(r, p, 4, 0);
    f.v.depth = img->depth;
    /* wall vertices: hidden behind the occluder, visible beside it */
    vt_vertex hidden = at_ndc(&f.v, 0.1f, -0.2f, 10.0f);
    vt_vertex seen = at_ndc(&f.v, 0.8f, 0.7f, 10.0f);
    assert_false(vt_vertex_visible(&f.v, &hidden));
    assert_true(vt_vertex_visible(&f.v, &seen));
    /* the occluder's own corners (silhouette) and a point on its face */
    for (int k = 6; k < 12; ++k) {
        vt_vertex v = at(&f.v, p[k]);
        assert_true(vt_vertex_visible(&f.v, &v));
    }
    vt_vertex on = at_ndc(&f.v, 0.23f, 0.31f, 4.0f);
    assert_true(vt_vertex_visible(&f.v, &on));
    /* just inside the occluder's silhouette, on the wall: hidden */
    vt_vertex wall_edge = at_ndc(&f.v, 0.45f, 0.0f, 10.0f);
    assert_false(vt_vertex_visible(&f.v, &wall_edge));
    rl_image_release(img);
    rl_raster_release(r);
}

static void test_viewport_test_cohen_sutherland_cases(void **state)
{
    (void)state;
    view_fixture f;
    make_axis_view(&f);
    const vt_view *v = &f.v;
    vt_vertex a, b;
    /* trivially visible: one end inside */
    a = at_ndc(v, 0.2f, 0.3f, 5.0f);
    b = at_ndc(v, 4.0f, -3.0f, 5.0f);
    assert_true(vt_edge_in_viewport(v, &a, &b));
    assert_true(vt_edge_in_viewport(v, &b, &a));
    /* trivially hidden: both right, both above, both behind the near plane */
    a = at_ndc(v, 1.2f, 0.0f, 5.0f);
    b = at_ndc(v, 3.0f, -0.5f, 20.0f);
    assert_false(vt_edge_in_viewport(v, &a, &b));
    a = at_ndc(v, -0.5f, 1.5f, 5.0f);
    b = at_ndc(v, 0.5f, 1.1f, 5.0f);
    assert_false(vt_edge_in_viewport(v, &a, &b));
    a = at(v, rl_v3(0, 0, -0.05f));
    b = at(v, rl_v3(1, 0, 3.0f));
    assert_false(vt_edge_in_viewport(v, &a, &b));
    /* left to top past the corner (-1, 1): x - y = -2.1, outside */
    a = at_ndc(v, -1.5f, 0.6f, 5.0f);
    b = at_ndc(v, -0.6f, 1.5f, 5.0f);
    assert_false(vt_edge_in_viewport(v, &a, &b));
    assert_false(vt_edge_in_viewport(v, &b, &a));
    /* left to top through the corner: x - y = -1.7 cuts it off */
    a = at_ndc(v, -1.5f, 0.2f, 5.0f);
    b = at_ndc(v, -0.2f, 1.5f, 5.0f);
    assert_true(vt_edge_in_viewport(v, &a, &b));
    assert_true(vt_edge_in_viewport(v, &b, &a));
    /* left to right straight across, ends at different depths */
    a = at_ndc(v, -3.0f, 0.1f, 2.0f);
    b = at_ndc(v, 2.0f, -0.2f, 30.0f);
    assert_true(vt_edge_in_viewport(v, &a, &b));
    /* the same but passing below the bottom */
    a = at_ndc(v, -3.0f, -1.2f, 2.0f);
    b = at_ndc(v, 2.0f, -1.05f, 30.0f);
    assert_false(vt_edge_in_viewport(v, &a, &b));
}

static void test_viewport_test_across_the_near_plane(void **state)
{
    (void)state;
    view_fixture f;
    make_axis_view(&f);
    const vt_view *v = &f.v;
    /* behind the eye to in front, right of the view: x/d falls from +inf to
     * 3 and never enters */
    vt_vertex a = at(v, rl_v3(0, 0, 1)), b = at_ndc(v, 3.0f, 0.0f, 5.0f);
    assert_true(a.cw < 0.0f);
    assert_false(vt_edge_in_viewport(v, &a, &b));
    assert_false(vt_edge_in_viewport(v, &b, &a));
    /* from behind and to the left: x/d rises from -inf to 3, crossing the view */
    a = at(v, rl_v3(-10, 0, 1));
    assert_true(vt_edge_in_viewport(v, &a, &b));
    assert_true(vt_edge_in_viewport(v, &b, &a));
    /* between the eye and the near plane, both ends outside sideways but the
     * segment passes in front of the near plane */
    a = at(v, rl_v3(-0.3f, 0.0f, -0.05f));
    b = at_ndc(v, 1.5f, 0.0f, 0.5f);
    assert_true(vt_edge_in_viewport(v, &a, &b));
}

static void test_edge_length_in_pixels_and_clipped_at_near(void **state)
{
    (void)state;
    view_fixture f;
    make_axis_view(&f);
    const vt_view *v = &f.v;
    /* 100 px wide, NDC 2 wide: 1 NDC = 50 px */
    vt_vertex a = at_ndc(v, -0.5f, 0.0f, 5.0f), b = at_ndc(v, 0.1f, 0.8f, 9.0f);
    assert_float_equal(vt_edge_length(v, &a, &b), 50.0f, 1e-3f);
    assert_float_equal(vt_edge_length(v, &b, &a), 50.0f, 1e-3f);
    /* from (0.5, 0, -1) (x_ndc = 0.5) to (0.5, 0, +1): cut at depth 0.1,
     * x_ndc = 5 there: 4.5 NDC = 225 px */
    a = at(v, rl_v3(0.5f, 0.0f, -1.0f));
    b = at(v, rl_v3(0.5f, 0.0f, 1.0f));
    assert_float_equal(vt_edge_length(v, &a, &b), 225.0f, 1e-2f);
    assert_float_equal(vt_edge_length(v, &b, &a), 225.0f, 1e-2f);
    /* both behind the near plane: nothing to see */
    a = at(v, rl_v3(0.5f, 0.0f, -0.05f));
    assert_float_equal(vt_edge_length(v, &a, &b), 0.0f, 0.0f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_projection_lands_where_the_rasterizer_draws),
        cmocka_unit_test(test_depth_is_what_the_rasterizer_stores),
        cmocka_unit_test(test_behind_the_eye_has_no_projection),
        cmocka_unit_test(test_z_test_takes_the_farthest_of_four_pixels),
        cmocka_unit_test(test_z_test_against_a_rasterized_occluder),
        cmocka_unit_test(test_viewport_test_cohen_sutherland_cases),
        cmocka_unit_test(test_viewport_test_across_the_near_plane),
        cmocka_unit_test(test_edge_length_in_pixels_and_clipped_at_near),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
