/* test_raster_layers.c: multi-texturing layers and multi-pass drawing
 * (Ullmann 2003, Sec. 3.5.4 and 3.5.5) in the software rasterizer.
 *
 * Layers are checked against values known by hand (constant colours, texels
 * hit at their centres) and against the Gouraud path, which interpolates the
 * same colours another way. The second pass (DEPTH_EQUAL | BLEND_ADD) is
 * checked against the ID layer of the first: it must add exactly where the
 * first pass won, including under clipping and threaded setup. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "raster/raster_fixtures.h"
#include "rl/rl_raster.h"

#define W 64
#define H 64
#define ALL_LAYERS (RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID)
#define TOL 1e-5f

/* Pixel-space point for the identity setup: (px, py) in pixels, eye depth d. */
static rl_vec3 pix(float px, float py, float d)
{
    return rl_v3(px / (W / 2) - 1.0f, 1.0f - py / (H / 2), -d);
}

typedef struct fixture {
    rl_raster *r;
    rl_image *img;
} fixture;

static fixture make(rl_mat4 proj)
{
    fixture f = { NULL, NULL };
    assert_int_equal(rl_raster_create(NULL, &f.r), RL_OK);
    assert_int_equal(rl_image_create(W, H, ALL_LAYERS, &f.img), RL_OK);
    rl_mat4 view = identity();
    assert_int_equal(rl_raster_set_target(f.r, f.img, &view, &proj), RL_OK);
    return f;
}

static void unmake(fixture *f)
{
    rl_raster_release(f->r);
    rl_image_release(f->img);
}

static const uint32_t quad_idx[6] = { 0, 1, 2, 0, 2, 3 };

/* The pixel-space square [8, 40) x [8, 40) at depth 1, as two triangles. */
static const rl_vec3 *square(void)
{
    static rl_vec3 p[4];
    p[0] = pix(8, 8, 1);
    p[1] = pix(8, 40, 1);
    p[2] = pix(40, 40, 1);
    p[3] = pix(40, 8, 1);
    return p;
}

static rl_raster_batch quad(const rl_vec3 *pos)
{
    return tris(pos, 4, quad_idx, 2);
}

static uint64_t draw(fixture *f, rl_raster_batch b)
{
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw(f->r, &b, &c), RL_OK);
    return c.pixels_written;
}

static rl_vec4 at(const rl_image *img, int x, int y)
{
    return img->color[(size_t)y * img->width + x];
}

static void assert_color_near(rl_vec4 got, rl_vec4 want, float tol)
{
    assert_true(fabsf(got.x - want.x) <= tol);
    assert_true(fabsf(got.y - want.y) <= tol);
    assert_true(fabsf(got.z - want.z) <= tol);
    assert_true(fabsf(got.w - want.w) <= tol);
}

static bool inside_square(int x, int y)
{
    return x >= 8 && x < 40 && y >= 8 && y < 40;
}

/* 2x2 checker: row 0 is the top of the picture. */
static rl_texture *checker(void)
{
    const rl_vec4 texels[4] = { { 1, 0, 0, 1 }, { 0, 1, 0, 1 },      /* top: red, green */
                                { 0, 0, 1, 1 }, { 1, 1, 0, 0.5f } }; /* bottom: blue, yellow */
    rl_texture *t = NULL;
    assert_int_equal(rl_texture_create(2, 2, texels, &t), RL_OK);
    return t;
}

/* ---- layers ------------------------------------------------------------- */

static void test_two_layers_sum_their_colours_and_keep_layer_0_alpha(void **state)
{
    (void)state;
    fixture f = make(identity());
    const rl_vec3 *p = square();
    rl_vec4 c0[4], c1[4];
    for (int k = 0; k < 4; ++k) {
        c0[k] = rl_v4(0.25f, 0.5f, 0.0f, 0.75f);
        c1[k] = rl_v4(0.5f, 0.125f, 0.25f, 0.1f);
    }
    rl_raster_layer layers[2] = { { .colors = c0 }, { .colors = c1 } };
    rl_raster_batch b = quad(p);
    b.num_layers = 2;
    b.layers = layers;
    assert_int_equal(draw(&f, b), 32 * 32);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_color_near(at(f.img, x, y),
                              inside_square(x, y) ? rl_v4(0.75f, 0.625f, 0.25f, 0.75f)
                                                  : rl_v4(0, 0, 0, 0),
                              TOL);
    unmake(&f);
}

static void test_layer_colours_interpolate_like_gouraud(void **state)
{
    (void)state;
    /* Perspective with a triangle crossing the near plane: the layer path
     * carries barycentrics through clipping, Gouraud carries colours. */
    fixture f = make(perspective90(0.5f, 10.0f));
    fixture g = make(perspective90(0.5f, 10.0f));
    rl_vec3 p[3] = { rl_v3(-3, -2, -0.2f), rl_v3(3, -1, -6), rl_v3(-1, 3, -4) };
    rl_vec4 ca[3] = { { 1, 0, 0, 1 }, { 0, 1, 0, 0.5f }, { 0, 0, 1, 0 } };
    rl_vec4 cb[3] = { { 0, 0.5f, 0, 0 }, { 0.25f, 0, 0, 0 }, { 0, 0, 0.5f, 0 } };
    rl_vec4 sum[3];
    for (int k = 0; k < 3; ++k)
        sum[k] = rl_v4(ca[k].x + cb[k].x, ca[k].y + cb[k].y, ca[k].z + cb[k].z, ca[k].w);
    const uint32_t idx[3] = { 0, 1, 2 };
    rl_raster_batch b = tris(p, 3, idx, 1);
    rl_raster_layer layers[2] = { { .colors = ca }, { .colors = cb } };
    b.num_layers = 2;
    b.layers = layers;
    uint64_t n = draw(&f, b);
    b.num_layers = 0;
    b.layers = NULL;
    b.colors = sum;
    assert_int_equal(draw(&g, b), n);
    assert_true(n > 200);
    for (size_t i = 0; i < (size_t)W * H; ++i) {
        assert_int_equal(f.img->triangle_id[i], g.img->triangle_id[i]);
        assert_color_near(f.img->color[i], g.img->color[i], 1e-4f);
    }
    unmake(&f);
    unmake(&g);
}

static void test_textured_layer_is_modulated_by_the_texel(void **state)
{
    (void)state;
    fixture f = make(identity());
    rl_texture *tex = checker();
    rl_texture *const textures[1] = { tex };
    const rl_vec3 *p = square();
    /* uv (0,0) bottom-left of the picture: the square's top-left corner
     * (p[0]) gets v = 1. */
    const rl_vec2 uv[4] = { { 0, 1 }, { 0, 0 }, { 1, 0 }, { 1, 1 } };
    const uint32_t tri_tex[2] = { 0, 0 };
    rl_vec4 grey[4], dim[4];
    for (int k = 0; k < 4; ++k) {
        grey[k] = rl_v4(0.5f, 0.5f, 0.5f, 1.0f);
        dim[k] = rl_v4(0.125f, 0.0f, 0.0f, 0.0f);
    }
    rl_raster_layer layers[2] = {
        { .colors = grey, .uvs = uv, .triangle_texture = tri_tex, .textures = textures },
        { .colors = dim },
    };
    rl_raster_batch b = quad(p);
    b.num_layers = 2;
    b.layers = layers;
    assert_int_equal(draw(&f, b), 32 * 32);
    /* Affine projection: uv is linear in pixel position. */
    for (int y = 8; y < 40; ++y)
        for (int x = 8; x < 40; ++x) {
            rl_vec2 want_uv = rl_v2((x + 0.5f - 8) / 32, 1 - (y + 0.5f - 8) / 32);
            rl_vec4 t = rl_texture_sample(tex, want_uv);
            rl_vec4 want = rl_v4(0.5f * t.x + 0.125f, 0.5f * t.y, 0.5f * t.z, 1.0f);
            assert_color_near(at(f.img, x, y), want, 1e-4f);
        }
    /* Near the quadrant centres (uv 0.25/0.75 falls between two pixel
     * centres) the checker colour dominates. */
    assert_true(at(f.img, 15, 15).x > 0.55f && at(f.img, 15, 15).y < 0.05f);   /* red */
    assert_true(at(f.img, 32, 15).y > 0.45f && at(f.img, 32, 15).z < 0.05f);  /* green */
    assert_true(at(f.img, 15, 32).z > 0.45f && at(f.img, 15, 32).y < 0.05f);  /* blue */
    assert_true(at(f.img, 32, 32).x > 0.55f && at(f.img, 32, 32).y > 0.45f);   /* yellow */
    rl_texture_release(tex);
    unmake(&f);
}

static void test_texture_index_none_means_colour_only(void **state)
{
    (void)state;
    fixture f = make(identity());
    rl_texture *tex = checker();
    rl_texture *const textures[1] = { tex };
    const rl_vec3 *p = square();
    /* Constant uv at the green texel's centre on both triangles. */
    const rl_vec2 uv[4] = { { 0.75f, 0.75f }, { 0.75f, 0.75f }, { 0.75f, 0.75f },
                            { 0.75f, 0.75f } };
    /* Triangle 0 (0,1,2) is the lower-left half, triangle 1 the upper-right. */
    const uint32_t tri_tex[2] = { RL_ID_NONE, 0 };
    rl_vec4 c[4];
    for (int k = 0; k < 4; ++k)
        c[k] = rl_v4(0.5f, 0.25f, 1.0f, 1.0f);
    rl_raster_layer layer = { .colors = c, .uvs = uv, .triangle_texture = tri_tex,
                              .textures = textures };
    rl_raster_batch b = quad(p);
    b.num_layers = 1;
    b.layers = &layer;
    draw(&f, b);
    for (int y = 8; y < 40; ++y)
        for (int x = 8; x < 40; ++x) {
            uint32_t t = f.img->triangle_id[(size_t)y * W + x];
            assert_true(t == 0 || t == 1);
            rl_vec4 want = t == 0 ? rl_v4(0.5f, 0.25f, 1.0f, 1.0f)     /* untouched */
                                  : rl_v4(0.0f, 0.25f, 0.0f, 1.0f);    /* times green */
            assert_color_near(at(f.img, x, y), want, TOL);
        }
    assert_int_equal(f.img->triangle_id[10 * W + 38], 1);
    assert_int_equal(f.img->triangle_id[38 * W + 10], 0);
    /* Without uvs the layer is untextured everywhere. */
    layer.uvs = NULL;
    draw(&f, (rl_raster_batch){ .positions = p, .num_vertices = 4, .indices = quad_idx,
                                .num_triangles = 2, .num_layers = 1, .layers = &layer,
                                .flags = RL_RASTER_NO_DEPTH_TEST });
    assert_color_near(at(f.img, 38, 10), rl_v4(0.5f, 0.25f, 1.0f, 1.0f), TOL);
    rl_texture_release(tex);
    unmake(&f);
}

/* ---- multi-pass --------------------------------------------------------- */

/* A tilted n x n grid of quads from z = -0.2 (in front of the near plane
 * 0.5, so the nearest row is clipped, in view) to z = -8. */
static uint32_t make_grid(int n, rl_vec3 *pos, uint32_t *idx)
{
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            float u = (float)i / n, v = (float)j / n;
            pos[j * (n + 1) + i] = rl_v3(-6 + 12 * u, -0.4f - 0.6f * v, -0.2f - 7.8f * v);
        }
    uint32_t t = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)n + 1,
                     d = c + 1;
            uint32_t *q = &idx[6 * t / 2];
            q[0] = a; q[1] = b; q[2] = d;
            q[3] = a; q[4] = d; q[5] = c;
            t += 2;
        }
    return t;
}

static void test_depth_equal_add_pass_adds_exactly_where_the_first_pass_won(void **state)
{
    (void)state;
    enum { N = 40 };   /* 3200 triangles: setup runs in several chunks */
    fixture f = make(perspective90(0.5f, 20.0f));
    rl_image_fill(f.img, rl_v4(0.5f, 0.5f, 0.5f, 1.0f));
    rl_vec3 *gp = malloc(sizeof *gp * (N + 1) * (N + 1));
    uint32_t *gi = malloc(sizeof *gi * 6 * N * N);
    assert_non_null(gp);
    assert_non_null(gi);
    uint32_t nt = make_grid(N, gp, gi);
    rl_raster_batch grid = { .positions = gp, .num_vertices = (N + 1) * (N + 1), .indices = gi,
                             .num_triangles = nt, .color = rl_v4(0.25f, 0, 0, 1),
                             .object_id = 0 };
    /* A nearer triangle over part of the grid, object 1. */
    rl_vec3 occ[3] = { rl_v3(-1, -2, -2), rl_v3(2, -2, -2), rl_v3(0.5f, 1, -2) };
    const uint32_t tri[3] = { 0, 1, 2 };
    rl_raster_batch occluder = { .positions = occ, .num_vertices = 3, .indices = tri,
                                 .num_triangles = 1, .color = rl_v4(0, 0, 0.5f, 1),
                                 .object_id = 1 };
    draw(&f, grid);
    draw(&f, occluder);

    const size_t np = (size_t)W * H;
    float *depth = malloc(np * sizeof *depth);
    uint32_t *ids = malloc(np * sizeof *ids);
    assert_non_null(depth);
    assert_non_null(ids);
    memcpy(depth, f.img->depth, np * sizeof *depth);
    memcpy(ids, f.img->object_id, np * sizeof *ids);
    size_t grid_pixels = 0, occ_pixels = 0;
    for (size_t i = 0; i < np; ++i) {
        grid_pixels += ids[i] == 0;
        occ_pixels += ids[i] == 1;
    }
    assert_true(grid_pixels > 500);
    assert_true(occ_pixels > 50);

    /* Second pass over the grid only, as a multi-pass renderer would do it:
     * the same triangles, another colour, depth and IDs left alone. */
    grid.color = rl_v4(0, 0.5f, 0, 0.25f);
    grid.flags = RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD | RL_RASTER_NO_DEPTH | RL_RASTER_NO_ID;
    grid.object_id = 7;
    assert_int_equal(draw(&f, grid), grid_pixels);
    for (size_t i = 0; i < np; ++i) {
        rl_vec4 want = ids[i] == 0 ? rl_v4(0.25f, 0.5f, 0, 1)        /* first pass won: added */
                     : ids[i] == 1 ? rl_v4(0, 0, 0.5f, 1)            /* occluded: unchanged */
                                   : rl_v4(0.5f, 0.5f, 0.5f, 1);     /* background */
        assert_memory_equal(&f.img->color[i], &want, sizeof want);
    }
    assert_memory_equal(f.img->depth, depth, np * sizeof *depth);
    assert_memory_equal(f.img->object_id, ids, np * sizeof *ids);

    /* A layered third pass combines with the same flags. */
    rl_vec4 *lc = malloc(sizeof *lc * (N + 1) * (N + 1));
    assert_non_null(lc);
    for (int k = 0; k < (N + 1) * (N + 1); ++k)
        lc[k] = rl_v4(0, 0, 0.25f, 0);
    rl_raster_layer layer = { .colors = lc };
    grid.num_layers = 1;
    grid.layers = &layer;
    assert_int_equal(draw(&f, grid), grid_pixels);
    for (size_t i = 0; i < np; ++i)
        if (ids[i] == 0)
            assert_color_near(f.img->color[i], rl_v4(0.25f, 0.5f, 0.25f, 1), TOL);
    /* Without DEPTH_EQUAL the same pass fails the "<" test everywhere. */
    grid.flags = RL_RASTER_BLEND_ADD | RL_RASTER_NO_DEPTH | RL_RASTER_NO_ID;
    assert_int_equal(draw(&f, grid), 0);
    free(lc);
    free(depth);
    free(ids);
    free(gp);
    free(gi);
    unmake(&f);
}

static void test_depth_equal_query_counts_the_pixels_of_the_first_pass(void **state)
{
    (void)state;
    fixture f = make(identity());
    rl_raster_batch b = quad(square());
    draw(&f, b);
    uint64_t visible = 99;
    b.flags = RL_RASTER_DEPTH_EQUAL;
    assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_OK);
    assert_int_equal(visible, 32 * 32);
    b.flags = 0;
    assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_OK);
    assert_int_equal(visible, 0);
    unmake(&f);
}

static void test_points_honour_depth_equal_and_blend_add(void **state)
{
    (void)state;
    fixture f = make(identity());
    rl_vec3 pos = pix(20, 20, 1);
    rl_raster_points pts = { .count = 1, .positions = &pos, .color = rl_v4(0.25f, 0.5f, 0, 1),
                             .size_px = 2 };
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw_points(f.r, &pts, &c), RL_OK);
    pts.flags = RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD;
    pts.color = rl_v4(0.5f, 0, 0.25f, 0);
    assert_int_equal(rl_raster_draw_points(f.r, &pts, &c), RL_OK);
    assert_int_equal(c.pixels_written, 8);
    assert_color_near(at(f.img, 19, 19), rl_v4(0.75f, 0.5f, 0.25f, 1), 0);
    assert_color_near(at(f.img, 18, 18), rl_v4(0, 0, 0, 0), 0);
    unmake(&f);
}

/* ---- bad input ---------------------------------------------------------- */

static void test_bad_layers_are_rejected_and_leave_the_image_alone(void **state)
{
    (void)state;
    fixture f = make(identity());
    rl_vec4 c[4] = { { 1, 1, 1, 1 }, { 1, 1, 1, 1 }, { 1, 1, 1, 1 }, { 1, 1, 1, 1 } };
    rl_raster_layer layers[RL_RASTER_MAX_LAYERS + 1];
    for (int i = 0; i <= RL_RASTER_MAX_LAYERS; ++i)
        layers[i] = (rl_raster_layer){ .colors = c };
    rl_raster_batch b = quad(square());
    b.layers = layers;
    rl_raster_counters counters = { 0 };
    uint64_t visible = 0;

    b.num_layers = RL_RASTER_MAX_LAYERS + 1;
    assert_int_equal(rl_raster_draw(f.r, &b, &counters), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_ERR_INVALID_ARG);
    b.num_layers = 2;
    layers[1].colors = NULL;
    assert_int_equal(rl_raster_draw(f.r, &b, &counters), RL_ERR_INVALID_ARG);
    b.num_triangles = 0;   /* rejected even with nothing to draw */
    assert_int_equal(rl_raster_draw(f.r, &b, &counters), RL_ERR_INVALID_ARG);
    b.num_triangles = 2;
    b.layers = NULL;
    assert_int_equal(rl_raster_draw(f.r, &b, &counters), RL_ERR_INVALID_ARG);
    assert_int_equal(counters.triangles_in, 0);
    for (size_t i = 0; i < (size_t)W * H; ++i)
        assert_int_equal(f.img->object_id[i], RL_ID_NONE);

    /* The maximum is allowed. */
    layers[1].colors = c;
    b.layers = layers;
    b.num_layers = RL_RASTER_MAX_LAYERS;
    assert_int_equal(rl_raster_draw(f.r, &b, &counters), RL_OK);
    assert_color_near(at(f.img, 20, 20), rl_v4(4, 4, 4, 1), TOL);
    unmake(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_two_layers_sum_their_colours_and_keep_layer_0_alpha),
        cmocka_unit_test(test_layer_colours_interpolate_like_gouraud),
        cmocka_unit_test(test_textured_layer_is_modulated_by_the_texel),
        cmocka_unit_test(test_texture_index_none_means_colour_only),
        cmocka_unit_test(test_depth_equal_add_pass_adds_exactly_where_the_first_pass_won),
        cmocka_unit_test(test_depth_equal_query_counts_the_pixels_of_the_first_pass),
        cmocka_unit_test(test_points_honour_depth_equal_and_blend_add),
        cmocka_unit_test(test_bad_layers_are_rejected_and_leave_the_image_alone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
