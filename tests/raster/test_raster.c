/* test_raster.c: the software rasterizer against exact and analytic oracles.
 *
 * Two setups: "pixel space" (identity view and projection, so that NDC maps
 * to pixels exactly and expected coverage follows from the fill rule by hand)
 * and a 90-degree perspective looking down -z from the origin, where
 * coverage and depth follow from rays through pixel centres. */
#include <math.h>
#include <omp.h>
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

/* ---- helpers ------------------------------------------------------------ */

/* Pixel-space point for the identity setup: (px, py) in pixels, eye depth d. */
static rl_vec3 pix(float px, float py, float d)
{
    return rl_v3(px / (W / 2) - 1.0f, 1.0f - py / (H / 2), -d);
}

/* Direction (eye space) through image position (px, py) for perspective90. */
static rl_vec3 ray_dir(double px, double py)
{
    return rl_v3((float)(px / (W / 2) - 1.0), (float)(1.0 - py / (H / 2)), -1.0f);
}

typedef struct fixture {
    rl_raster *r;
    rl_image *img;
} fixture;

static fixture make(unsigned layers, rl_mat4 proj)
{
    fixture f = { NULL, NULL };
    assert_int_equal(rl_raster_create(NULL, &f.r), RL_OK);
    assert_int_equal(rl_image_create(W, H, layers, &f.img), RL_OK);
    rl_mat4 view = identity();
    assert_int_equal(rl_raster_set_target(f.r, f.img, &view, &proj), RL_OK);
    return f;
}

static void unmake(fixture *f)
{
    rl_raster_release(f->r);
    rl_image_release(f->img);
}

static const uint32_t tri012[3] = { 0, 1, 2 };
static const uint32_t quad_idx[6] = { 0, 1, 2, 0, 2, 3 };

static uint64_t draw(fixture *f, rl_raster_batch b)
{
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw(f->r, &b, &c), RL_OK);
    return c.pixels_written;
}

static bool covered(const rl_image *img, int x, int y)
{
    return img->object_id[(size_t)y * img->width + x] != RL_ID_NONE;
}

static int count_covered(const rl_image *img)
{
    int n = 0;
    for (int y = 0; y < img->height; ++y)
        for (int x = 0; x < img->width; ++x)
            n += covered(img, x, y);
    return n;
}

static uint32_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*s >> 33);
}

static float frand(uint64_t *s) { return (float)lcg(s) / 2147483648.0f; }

/* ---- (a) exact coverage ------------------------------------------------- */

static void test_right_triangle_covers_exactly_the_pixels_the_fill_rule_predicts(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    /* Legs on x = 8 and y = 8, hypotenuse x + y = 32. Centres on the
     * hypotenuse (x + y = 31) lie on a bottom-right edge: excluded. */
    rl_vec3 p[3] = { pix(8, 8, 1), pix(24, 8, 1), pix(8, 24, 1) };
    uint64_t n = draw(&f, tris(p, 3, tri012, 1));
    assert_int_equal(n, 120);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_int_equal(covered(f.img, x, y), x >= 8 && y >= 8 && x + y <= 30);
    assert_int_equal(count_covered(f.img), 120);
    unmake(&f);
}

static void test_rectangle_includes_top_left_edges_and_excludes_bottom_right(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    /* Edges through pixel centres: x in [10.5, 20.5], y in [4.5, 9.5]. */
    rl_vec3 p[4] = { pix(10.5f, 4.5f, 1), pix(10.5f, 9.5f, 1), pix(20.5f, 9.5f, 1),
                     pix(20.5f, 4.5f, 1) };
    uint64_t n = draw(&f, tris(p, 4, quad_idx, 2));
    assert_int_equal(n, 50);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_int_equal(covered(f.img, x, y), x >= 10 && x <= 19 && y >= 4 && y <= 8);
    unmake(&f);
}

/* ---- (b) shared edges ---------------------------------------------------- */

/* Draws each triangle alone into a cleared image and counts, per pixel, how
 * many triangles covered it: overlaps cannot hide behind overwrites. */
static void coverage_counts(const rl_vec3 *pos, uint32_t nv, const uint32_t *idx, uint32_t nt,
                            int *counts)
{
    fixture f = make(RL_LAYER_ID, identity());
    memset(counts, 0, sizeof(int) * W * H);
    for (uint32_t t = 0; t < nt; ++t) {
        rl_image_clear(f.img);
        rl_raster_batch b = tris(pos, nv, idx + 3 * t, 1);
        b.flags = RL_RASTER_NO_DEPTH_TEST;
        draw(&f, b);
        for (int i = 0; i < W * H; ++i)
            counts[i] += f.img->object_id[i] != RL_ID_NONE;
    }
    unmake(&f);
}

static void test_two_triangles_sharing_a_diagonal_cover_a_square_exactly_once(void **state)
{
    (void)state;
    rl_vec3 p[4] = { pix(8, 8, 1), pix(24, 8, 1), pix(24, 24, 1), pix(8, 24, 1) };
    /* The diagonal 8,24 - 24,8 passes through pixel centres (x + y = 31). */
    const uint32_t idx[6] = { 0, 1, 3, 1, 2, 3 };
    int counts[W * H];
    coverage_counts(p, 4, idx, 2, counts);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_int_equal(counts[y * W + x], x >= 8 && x < 24 && y >= 8 && y < 24);
}

/* Side of point q relative to directed edge a->b (pixel units). */
static double side(const double *a, const double *b, const double *q)
{
    return (b[0] - a[0]) * (q[1] - a[1]) - (b[1] - a[1]) * (q[0] - a[0]);
}

/* Signed distance of q into triangle (a, b, c): > 0 inside, < 0 outside. */
static double inside_margin(const double *a, const double *b, const double *c, const double *q)
{
    double area = side(a, b, c), s = area > 0 ? 1 : -1, m = INFINITY;
    if (area == 0)
        return -INFINITY;
    const double *v[3] = { a, b, c };
    for (int k = 0; k < 3; ++k) {
        const double *p0 = v[k], *p1 = v[(k + 1) % 3];
        double d = s * side(p0, p1, q) / hypot(p1[0] - p0[0], p1[1] - p0[1]);
        m = d < m ? d : m;
    }
    return m;
}

static void test_random_fans_cover_their_polygon_without_gaps_or_overlaps(void **state)
{
    (void)state;
    uint64_t seed = 12345;
    for (int fan = 0; fan < 24; ++fan) {
        enum { MAXV = 32 };
        rl_vec3 pos[MAXV];
        double v[MAXV][2];
        /* A centre and a ring at increasing angles (steps < pi, so the
         * centre is inside); odd fans snap the vertices to pixel centres so
         * that many edges run through centres. Steps >= 0.25 rad at radius
         * >= 16 px keep the snapped fan from folding over. */
        double cx = 26 + 12 * frand(&seed), cy = 26 + 12 * frand(&seed);
        double radius = 16 + 32 * frand(&seed);
        int n = 0;
        v[0][0] = cx;
        v[0][1] = cy;
        for (double a = frand(&seed); a < 2 * RL_PI - 0.25 && n < MAXV - 2;
             a += 0.25 + 0.6 * frand(&seed)) {
            ++n;
            v[n][0] = cx + radius * cos(a);
            v[n][1] = cy - radius * sin(a);
        }
        for (int i = 0; i <= n; ++i) {
            if (fan % 2) {
                v[i][0] = floor(v[i][0]) + 0.5;
                v[i][1] = floor(v[i][1]) + 0.5;
            }
            pos[i] = pix((float)v[i][0], (float)v[i][1], 1);
            v[i][0] = (pos[i].x + 1.0) * (W / 2);   /* what the rasterizer sees */
            v[i][1] = (1.0 - pos[i].y) * (H / 2);
        }
        uint32_t idx[3 * MAXV];
        for (int k = 0; k < n; ++k) {
            idx[3 * k] = 0;
            idx[3 * k + 1] = (uint32_t)(1 + k);
            idx[3 * k + 2] = (uint32_t)(1 + (k + 1) % n);
        }
        int counts[W * H];
        coverage_counts(pos, (uint32_t)n + 1, idx, (uint32_t)n, counts);
        int inside = 0;
        for (int y = 0; y < H; ++y) {
            for (int x = 0; x < W; ++x) {
                int c = counts[y * W + x];
                assert_true(c <= 1);   /* never twice */
                double q[2] = { x + 0.5, y + 0.5 }, best = -INFINITY;
                for (int k = 0; k < n; ++k) {
                    double m = inside_margin(v[idx[3 * k]], v[idx[3 * k + 1]], v[idx[3 * k + 2]], q);
                    best = m > best ? m : best;
                }
                if (best > 1e-3) {
                    assert_int_equal(c, 1);   /* no gaps */
                    ++inside;
                } else if (best < -1e-3) {
                    assert_int_equal(c, 0);
                }
            }
        }
        assert_true(inside > 300);
    }
}

/* Rows are filled over spans bounded in floating point and trimmed by the
 * exact edge test (raster_fill.c): long slivers, shallow or steep, up to
 * far off screen, must still cover every pixel well inside them and none
 * well outside. */
static void test_long_slivers_cover_exactly_their_pixels(void **state)
{
    (void)state;
    uint64_t seed = 777;
    int inside_total = 0;
    for (int k = 0; k < 200; ++k) {
        /* A long edge from one far point to another across the image, and
         * an apex 0.2..4 px off its middle. */
        double a[2], b[2], c[2];
        double reach = k % 4 == 0 ? 4000.0 : 40.0;
        double ang = 2 * RL_PI * frand(&seed);
        double mx = 8 + 48 * frand(&seed), my = 8 + 48 * frand(&seed);
        double ux = cos(ang), uy = sin(ang), h = 0.2 + 3.8 * frand(&seed);
        a[0] = mx - reach * ux; a[1] = my - reach * uy;
        b[0] = mx + reach * ux; b[1] = my + reach * uy;
        c[0] = mx - h * uy;     c[1] = my + h * ux;
        const double *v[3] = { a, b, c };
        rl_vec3 pos[3];
        double seen[3][2];
        for (int i = 0; i < 3; ++i) {
            pos[i] = pix((float)v[i][0], (float)v[i][1], 1);
            seen[i][0] = (pos[i].x + 1.0) * (W / 2);   /* what the rasterizer sees */
            seen[i][1] = (1.0 - pos[i].y) * (H / 2);
        }
        int counts[W * H];
        coverage_counts(pos, 3, tri012, 1, counts);
        for (int y = 0; y < H; ++y) {
            for (int x = 0; x < W; ++x) {
                double q[2] = { x + 0.5, y + 0.5 };
                double m = inside_margin(seen[0], seen[1], seen[2], q);
                if (m > 1e-2) {
                    assert_int_equal(counts[y * W + x], 1);
                    ++inside_total;
                } else if (m < -1e-2) {
                    assert_int_equal(counts[y * W + x], 0);
                }
            }
        }
    }
    assert_true(inside_total > 2000);
}

/* ---- (c) depth ---------------------------------------------------------- */

static void test_nearer_triangle_wins_regardless_of_draw_order(void **state)
{
    (void)state;
    rl_vec3 near_tri[3] = { rl_v3(-1, -1, -2), rl_v3(1, -1, -2), rl_v3(0, 1, -2) };
    rl_vec3 far_tri[3] = { rl_v3(-40, -40, -4), rl_v3(40, -40, -4), rl_v3(0, 40, -4) };
    for (int order = 0; order < 2; ++order) {
        fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
        rl_raster_batch bn = tris(near_tri, 3, tri012, 1), bf = tris(far_tri, 3, tri012, 1);
        bn.object_id = 1;
        bf.object_id = 2;
        if (order == 0) {
            draw(&f, bn);
            draw(&f, bf);
        } else {
            draw(&f, bf);
            draw(&f, bn);
        }
        size_t centre = (size_t)(H / 2) * W + W / 2;
        assert_int_equal(f.img->object_id[centre], 1);
        assert_float_equal(f.img->depth[centre], 2.0f, 1e-5f);
        assert_int_equal(f.img->object_id[0], 2);   /* corner: only the far one */
        assert_float_equal(f.img->depth[0], 4.0f, 1e-5f);
        unmake(&f);
    }
}

static void test_depth_is_the_perspective_correct_eye_depth_of_the_plane(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    rl_vec3 p[3] = { rl_v3(-3, -1, -1.5f), rl_v3(3, -1.5f, -1.5f), rl_v3(0.5f, 2, -9) };
    draw(&f, tris(p, 3, tri012, 1));
    rl_vec3 n = rl_cross(rl_sub(p[1], p[0]), rl_sub(p[2], p[0]));
    int checked = 0;
    for (int y = 0; y < H; ++y) {
        for (int x = 0; x < W; ++x) {
            if (!covered(f.img, x, y))
                continue;
            rl_vec3 d = ray_dir(x + 0.5, y + 0.5);
            double t = (double)rl_dot(n, p[0]) / rl_dot(n, d);   /* d.z = -1: t = depth */
            assert_float_equal(f.img->depth[(size_t)y * W + x], t, 2e-5 * t);
            ++checked;
        }
    }
    assert_true(checked > 300);
    unmake(&f);
}

static void test_orthographic_depth_is_the_interpolated_eye_depth(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    /* Depth varies linearly in x: 0.25 at x = 0 to 0.75 at x = 64. */
    rl_vec3 p[3] = { pix(0, 0, 0.25f), pix(64, 0, 0.75f), pix(0, 64, 0.25f) };
    draw(&f, tris(p, 3, tri012, 1));
    for (int x = 0; x < 30; ++x)
        assert_float_equal(f.img->depth[(size_t)10 * W + x], 0.25 + 0.5 * (x + 0.5) / 64, 1e-6);
    unmake(&f);
}

/* ---- (d) IDs ------------------------------------------------------------ */

static void test_id_layers_hold_object_and_triangle_ids(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    rl_vec3 p[6] = { pix(2, 2, 1), pix(12, 2, 1), pix(2, 12, 1),
                     pix(40, 40, 1), pix(60, 40, 1), pix(40, 60, 1) };
    const uint32_t idx[6] = { 0, 1, 2, 3, 4, 5 };
    const uint32_t tri_ids[2] = { 42, 7 }, obj_ids[2] = { 3, 9 };
    rl_raster_batch b = tris(p, 6, idx, 2);
    b.triangle_ids = tri_ids;
    b.object_ids = obj_ids;
    draw(&f, b);
    size_t a = (size_t)4 * W + 4, c = (size_t)44 * W + 44;
    assert_int_equal(f.img->triangle_id[a], 42);
    assert_int_equal(f.img->object_id[a], 3);
    assert_int_equal(f.img->triangle_id[c], 7);
    assert_int_equal(f.img->object_id[c], 9);
    assert_int_equal(f.img->triangle_id[30 * W + 30], RL_ID_NONE);

    rl_image_clear(f.img);
    b.triangle_ids = NULL;
    b.object_ids = NULL;
    b.first_triangle_id = 100;
    b.object_id = 5;
    draw(&f, b);
    assert_int_equal(f.img->triangle_id[a], 100);
    assert_int_equal(f.img->triangle_id[c], 101);
    assert_int_equal(f.img->object_id[a], 5);
    assert_int_equal(f.img->object_id[c], 5);

    /* NO_ID leaves the ID layers alone but still writes colour. */
    rl_image_clear(f.img);
    b.flags = RL_RASTER_NO_ID;
    assert_true(draw(&f, b) > 0);
    assert_int_equal(f.img->triangle_id[a], RL_ID_NONE);
    assert_float_equal(f.img->color[a].x, 1.0f, 0.0f);
    unmake(&f);
}

/* ---- (e) clipping --------------------------------------------------------- */

static void test_triangle_crossing_the_near_plane_covers_only_its_visible_part(void **state)
{
    (void)state;
    /* Floor y = -0.3 from z = +5 (behind) to z = -100; near = 1. Rows whose
     * centre ray hits the floor in front of the near plane: ndc y in
     * (-0.3, 0), i.e. rows 32..41 (row 41.5: z = -1.0105; 42.5: z = -0.914). */
    fixture f = make(ALL_LAYERS, perspective90(1.0f, 1000));
    rl_vec3 p[3] = { rl_v3(-50, -0.3f, 5), rl_v3(50, -0.3f, 5), rl_v3(0, -0.3f, -100) };
    rl_raster_counters c = { 0 };
    rl_raster_batch b = tris(p, 3, tri012, 1);
    assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
    assert_int_equal(c.triangles_in, 1);
    assert_int_equal(c.triangles_drawn, 1);
    assert_int_equal(c.pixels_written, 640);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_int_equal(covered(f.img, x, y), y >= 32 && y <= 41);
    for (int y = 32; y <= 41; ++y) {   /* depth on the floor: 0.3 / -ndc_y */
        double ndc_y = 1.0 - (y + 0.5) / 32.0;
        assert_float_equal(f.img->depth[(size_t)y * W + 7], 0.3 / -ndc_y, 1e-4 * (0.3 / -ndc_y));
    }
    unmake(&f);
}

static void test_triangle_behind_the_camera_draws_nothing(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    rl_vec3 p[3] = { rl_v3(-1, -1, 2), rl_v3(1, -1, 2), rl_v3(0, 1, 0.2f) };
    rl_raster_counters c = { 0 };
    rl_raster_batch b = tris(p, 3, tri012, 1);
    assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
    assert_int_equal(c.triangles_drawn, 0);
    assert_int_equal(c.pixels_written, 0);
    assert_int_equal(count_covered(f.img), 0);
    unmake(&f);
}

static void test_huge_triangles_cover_the_screen_without_overflow(void **state)
{
    (void)state;
    /* In front of the camera, a million units wide: every pixel. */
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    rl_vec3 wall[3] = { rl_v3(-1e6f, -1e6f, -5), rl_v3(1e6f, -1e6f, -5), rl_v3(0, 1e6f, -5) };
    assert_int_equal(draw(&f, tris(wall, 3, tri012, 1)), W * H);
    for (int i = 0; i < W * H; ++i)
        assert_float_equal(f.img->depth[i], 5.0f, 1e-4f);

    /* A floor y = -1 from z = +1e6 to -1e6: near- and guard-band-clipped;
     * covers exactly the rows below the horizon. */
    rl_image_clear(f.img);
    rl_vec3 floor_tri[3] = { rl_v3(-1e6f, -1, 1e6f), rl_v3(1e6f, -1, 1e6f), rl_v3(0, -1, -1e6f) };
    assert_int_equal(draw(&f, tris(floor_tri, 3, tri012, 1)), W * H / 2);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_int_equal(covered(f.img, x, y), y >= H / 2);
    unmake(&f);

    /* Pixel space, vertices at +-1e6 NDC (screen coordinates ~3e7 px). */
    f = make(ALL_LAYERS, identity());
    rl_vec3 big[3] = { rl_v3(-1e6f, -1e6f, -0.5f), rl_v3(1e6f, -1e6f, -0.5f), rl_v3(0, 1e6f, -0.5f) };
    assert_int_equal(draw(&f, tris(big, 3, tri012, 1)), W * H);
    unmake(&f);
}

static void test_non_finite_positions_skip_only_their_triangles(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    rl_vec3 p[6] = { pix(2, 2, 1), pix(12, 2, 1), pix(2, 12, 1),
                     pix(40, 40, 1), rl_v3(NAN, 0, -1), rl_v3(INFINITY, 0, -1) };
    const uint32_t idx[9] = { 0, 1, 2, 3, 4, 1, 3, 5, 0 };
    rl_raster_counters c = { 0 };
    rl_raster_batch b = tris(p, 6, idx, 3);
    assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
    assert_int_equal(c.triangles_in, 3);
    assert_int_equal(c.triangles_drawn, 1);
    assert_int_equal(c.pixels_written, 45);   /* x, y >= 2, x + y <= 12 */
    unmake(&f);
}

/* ---- (f) occlusion queries ------------------------------------------------ */

static void test_query_counts_what_a_draw_then_writes(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    /* Occluder: x in [-10, 0.3], the left ~57% of the screen, at depth 2. */
    rl_vec3 occluder[4] = { rl_v3(-10, -10, -2), rl_v3(0.3f, -10, -2), rl_v3(0.3f, 10, -2),
                            rl_v3(-10, 10, -2) };
    draw(&f, tris(occluder, 4, quad_idx, 2));

    rl_vec3 target[3] = { rl_v3(-2, -2, -4), rl_v3(2.5f, -2, -4), rl_v3(0, 3, -4) };
    rl_raster_batch b = tris(target, 3, tri012, 1);
    size_t bytes = (size_t)W * H;
    rl_vec4 *color_before = malloc(bytes * sizeof(rl_vec4));
    float *depth_before = malloc(bytes * sizeof(float));
    memcpy(color_before, f.img->color, bytes * sizeof(rl_vec4));
    memcpy(depth_before, f.img->depth, bytes * sizeof(float));
    uint64_t visible = 0;
    assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_OK);
    assert_memory_equal(color_before, f.img->color, bytes * sizeof(rl_vec4));
    assert_memory_equal(depth_before, f.img->depth, bytes * sizeof(float));
    assert_true(visible > 100);
    b.object_id = 77;
    uint64_t written = draw(&f, b);
    assert_int_equal(visible, written);

    /* Behind the occluder's covered part only: nothing visible. */
    rl_vec3 hidden[3] = { rl_v3(-2, -1, -6), rl_v3(-1, -1, -6), rl_v3(-2, 1, -6) };
    b = tris(hidden, 3, tri012, 1);
    assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_OK);
    assert_int_equal(visible, 0);
    free(color_before);
    free(depth_before);
    unmake(&f);
}

static void test_query_agrees_with_draw_for_random_triangles(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    uint64_t seed = 7;
    for (int i = 0; i < 60; ++i) {
        rl_vec3 p[3];
        float z = -1 - 8 * frand(&seed);
        for (int k = 0; k < 3; ++k)
            p[k] = rl_v3((frand(&seed) * 2 - 1) * -z * 1.2f, (frand(&seed) * 2 - 1) * -z * 1.2f,
                         z - frand(&seed));
        rl_raster_batch b = tris(p, 3, tri012, 1);
        b.object_id = (uint32_t)i;
        uint64_t visible = 0;
        assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_OK);
        assert_int_equal(draw(&f, b), visible);
    }
    /* A self-overlapping batch counts like a draw that writes no depth. */
    rl_vec3 p[6] = { rl_v3(-2, -2, -3), rl_v3(2, -2, -3), rl_v3(0, 2, -3),
                     rl_v3(-2, -2, -3.5f), rl_v3(2, -2, -3.5f), rl_v3(0, 2, -3.5f) };
    const uint32_t idx[6] = { 0, 1, 2, 3, 4, 5 };
    rl_raster_batch b = tris(p, 6, idx, 2);
    uint64_t visible = 0;
    assert_int_equal(rl_raster_query(f.r, &b, &visible), RL_OK);
    b.flags = RL_RASTER_NO_DEPTH;
    assert_int_equal(draw(&f, b), visible);
    unmake(&f);
}

/* ---- (g) culling ---------------------------------------------------------- */

static void test_back_faces_are_culled_and_front_faces_kept(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    /* Counter-clockwise with y up (as the camera sees it): front. */
    rl_vec3 ccw[3] = { rl_v3(-0.5f, -0.5f, -0.5f), rl_v3(0.5f, -0.5f, -0.5f), rl_v3(0, 0.5f, -0.5f) };
    rl_vec3 cw[3] = { ccw[0], ccw[2], ccw[1] };
    rl_raster_batch b = tris(ccw, 3, tri012, 1);
    b.flags = RL_RASTER_CULL_BACK | RL_RASTER_NO_DEPTH_TEST;
    uint64_t front = draw(&f, b);
    assert_true(front > 200);
    b.positions = cw;
    assert_int_equal(draw(&f, b), 0);
    b.flags = RL_RASTER_NO_DEPTH_TEST;
    assert_int_equal(draw(&f, b), front);
    unmake(&f);
}

/* ---- (h) points ----------------------------------------------------------- */

static void test_points_of_size_1_and_4_cover_1_and_16_pixels(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    const float where[4][2] = { { 20.5f, 20.5f }, { 20, 20 }, { 33.37f, 9.81f }, { 0.2f, 63.9f } };
    for (int i = 0; i < 4; ++i) {
        for (int s = 1; s <= 4; s += 3) {
            rl_image_clear(f.img);
            rl_vec3 p = pix(where[i][0], where[i][1], 1);
            rl_raster_points pts = { .count = 1, .positions = &p, .size_px = (float)s,
                                     .object_id = 4 };
            rl_raster_counters c = { 0 };
            assert_int_equal(rl_raster_draw_points(f.r, &pts, &c), RL_OK);
            int expect = s * s;
            if (i == 3)   /* at the image corner: a quarter of the big one is clipped */
                expect = s == 1 ? 1 : 4;
            assert_int_equal(c.pixels_written, (uint64_t)expect);
            assert_int_equal(count_covered(f.img), expect);
            assert_int_equal(c.points_drawn, 1);
        }
    }
    /* Side 4 at a pixel centre: columns and rows 18..21. */
    rl_image_clear(f.img);
    rl_vec3 p = pix(20.5f, 20.5f, 1);
    rl_raster_points pts = { .count = 1, .positions = &p, .size_px = 4, .object_id = 4 };
    assert_int_equal(rl_raster_draw_points(f.r, &pts, NULL), RL_OK);
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x)
            assert_int_equal(covered(f.img, x, y), x >= 18 && x <= 21 && y >= 18 && y <= 21);
    assert_int_equal(f.img->object_id[20 * W + 20], 4);
    assert_int_equal(f.img->triangle_id[20 * W + 20], 0);   /* the point index */
    unmake(&f);
}

static void test_points_are_depth_tested_and_culled_at_the_near_plane(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    rl_vec3 p[3] = { rl_v3(0, 0, -3), rl_v3(0, 0, -2), rl_v3(0, 0, -0.25f) };
    const uint32_t ids[3] = { 1, 2, 3 };
    rl_raster_points pts = { .count = 3, .positions = p, .size_px = 2, .object_ids = ids };
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw_points(f.r, &pts, &c), RL_OK);
    assert_int_equal(c.points_drawn, 2);
    assert_int_equal(c.pixels_written, 8);
    assert_int_equal(f.img->object_id[32 * W + 32], 2);
    assert_float_equal(f.img->depth[32 * W + 32], 2.0f, 1e-6f);
    unmake(&f);
}

/* ---- (i) threads ---------------------------------------------------------- */

typedef struct frame_copy {
    rl_vec4 color[128 * 128];
    float depth[128 * 128];
    uint32_t object_id[128 * 128], triangle_id[128 * 128];
} frame_copy;

static void render_random_scene(int threads, frame_copy *out)
{
    enum { NT = 40000, NP = 5000, S = 128 };
    omp_set_num_threads(threads);
    rl_raster *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(NULL, &r), RL_OK);
    assert_int_equal(rl_image_create(S, S, ALL_LAYERS, &img), RL_OK);
    rl_mat4 view = identity(), proj = perspective90(0.5f, 100);
    assert_int_equal(rl_raster_set_target(r, img, &view, &proj), RL_OK);
    rl_vec3 *pos = malloc(sizeof(rl_vec3) * 3 * NT);
    rl_vec4 *col = malloc(sizeof(rl_vec4) * 3 * NT);
    uint32_t *idx = malloc(sizeof(uint32_t) * 3 * NT);
    uint64_t seed = 99;
    for (int t = 0; t < NT; ++t) {
        /* Mostly small triangles, some large, at random depths; many overlap
         * at equal depth so that submission order matters. */
        float z = -1.0f - (float)(lcg(&seed) % 16), size = (t % 97 == 0) ? 3.0f : 0.2f;
        float cx = (frand(&seed) * 2 - 1) * -z, cy = (frand(&seed) * 2 - 1) * -z;
        for (int k = 0; k < 3; ++k) {
            pos[3 * t + k] = rl_v3(cx + size * -z * (frand(&seed) - 0.5f),
                                   cy + size * -z * (frand(&seed) - 0.5f), z);
            col[3 * t + k] = rl_v4(frand(&seed), frand(&seed), frand(&seed), 1);
            idx[3 * t + k] = (uint32_t)(3 * t + k);
        }
    }
    rl_raster_batch b = { .num_vertices = 3 * NT, .positions = pos, .colors = col,
                          .num_triangles = NT, .indices = idx, .object_id = 1 };
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw(r, &b, &c), RL_OK);
    assert_true(c.triangles_drawn > NT / 2);
    rl_raster_points pts = { .count = NP, .positions = pos, .colors = col, .size_px = 3,
                             .object_id = 2 };
    assert_int_equal(rl_raster_draw_points(r, &pts, &c), RL_OK);
    memcpy(out->color, img->color, sizeof out->color);
    memcpy(out->depth, img->depth, sizeof out->depth);
    memcpy(out->object_id, img->object_id, sizeof out->object_id);
    memcpy(out->triangle_id, img->triangle_id, sizeof out->triangle_id);
    free(pos);
    free(col);
    free(idx);
    rl_image_release(img);
    rl_raster_release(r);
}

static void test_multithreaded_result_is_identical_to_single_threaded(void **state)
{
    (void)state;
    int saved = omp_get_max_threads();
    frame_copy *ref = malloc(sizeof *ref), *got = malloc(sizeof *got);
    render_random_scene(1, ref);
    for (int threads = 2; threads <= 4; ++threads) {
        render_random_scene(threads, got);
        assert_memory_equal(ref, got, sizeof *ref);
    }
    free(ref);
    free(got);
    omp_set_num_threads(saved);
}

/* ---- (j) attributes ------------------------------------------------------- */

static void test_gouraud_colour_at_a_vertex_pixel_is_the_vertex_colour(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    /* Vertex 0 at the centre of pixel (10, 10), on the triangle's top and
     * left edges, so that its pixel is covered. */
    rl_vec3 d0 = ray_dir(10.5, 10.5), d1 = ray_dir(40.5, 10.5), d2 = ray_dir(10.5, 50.5);
    rl_vec3 p[3] = { rl_scale(d0, 2), rl_scale(d1, 7), rl_scale(d2, 4) };
    rl_vec4 col[3] = { rl_v4(1, 0, 0, 1), rl_v4(0, 1, 0, 0.5f), rl_v4(0, 0, 1, 0) };
    rl_raster_batch b = tris(p, 3, tri012, 1);
    b.colors = col;
    draw(&f, b);
    rl_vec4 c = f.img->color[10 * W + 10];
    assert_float_equal(c.x, 1.0f, 1e-6f);
    assert_float_equal(c.y, 0.0f, 1e-6f);
    assert_float_equal(c.z, 0.0f, 1e-6f);
    assert_float_equal(c.w, 1.0f, 1e-6f);
    unmake(&f);
}

static void test_uv_is_perspective_correct_on_a_receding_quad(void **state)
{
    (void)state;
    enum { T = 64 };
    rl_vec4 texels[T * T];
    for (int j = 0; j < T; ++j)          /* row 0 is the top: v = 1 */
        for (int i = 0; i < T; ++i)
            texels[j * T + i] = rl_v4((i + 0.5f) / T, 1.0f - (j + 0.5f) / T, 0, 1);
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(T, T, texels, &tex), RL_OK);

    /* Floor y = -1, x in [-2, 2], z from -2 (v = 0) to -6 (v = 1). */
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    rl_vec3 p[4] = { rl_v3(-2, -1, -2), rl_v3(2, -1, -2), rl_v3(2, -1, -6), rl_v3(-2, -1, -6) };
    rl_vec2 uv[4] = { rl_v2(0, 0), rl_v2(1, 0), rl_v2(1, 1), rl_v2(0, 1) };
    rl_raster_batch b = tris(p, 4, quad_idx, 2);
    b.uvs = uv;
    b.texture = tex;
    draw(&f, b);
    /* Rows 37.3 (far edge) .. 48 (near edge); row 42 is midway on screen. */
    for (int x = 28; x <= 36; x += 4) {
        rl_vec3 d = ray_dir(x + 0.5, 42.5);
        float t = -1.0f / d.y;                       /* hit the floor */
        rl_vec2 exact = rl_v2((t * d.x + 2) / 4, (t - 2) / 4);
        rl_vec4 want = rl_texture_sample(tex, exact);
        rl_vec4 got = f.img->color[42 * W + x];
        assert_float_equal(got.x, want.x, 1e-3f);
        assert_float_equal(got.y, want.y, 1e-3f);
        assert_true(fabsf(got.y - 0.5f) > 0.2f);   /* far from affine interpolation */
    }
    /* Gouraud colours follow the same perspective-correct interpolation. */
    rl_vec4 col[4] = { rl_v4(0, 0, 0, 1), rl_v4(1, 0, 0, 1), rl_v4(1, 1, 0, 1), rl_v4(0, 1, 0, 1) };
    b.uvs = NULL;
    b.colors = col;
    b.flags = RL_RASTER_NO_DEPTH_TEST;
    draw(&f, b);
    rl_vec3 d = ray_dir(32.5, 42.5);
    assert_float_equal(f.img->color[42 * W + 32].y, (-1.0f / d.y - 2) / 4, 1e-4f);
    unmake(&f);
    rl_texture_release(tex);
}

static void test_per_triangle_textures_modulate_the_colour(void **state)
{
    (void)state;
    rl_vec4 texel = rl_v4(0.5f, 0.25f, 1, 1);
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(1, 1, &texel, &tex), RL_OK);
    rl_texture *const textures[1] = { tex };
    fixture f = make(ALL_LAYERS, identity());
    rl_vec3 p[4] = { pix(4, 4, 1), pix(4, 20, 1), pix(20, 20, 1), pix(20, 4, 1) };
    rl_vec2 uv[4] = { rl_v2(0, 0), rl_v2(0, 1), rl_v2(1, 1), rl_v2(1, 0) };
    const uint32_t which[2] = { 0, RL_ID_NONE };
    rl_raster_batch b = tris(p, 4, quad_idx, 2);
    b.color = rl_v4(0.5f, 1, 1, 0.5f);
    b.uvs = uv;
    b.textures = textures;
    b.triangle_texture = which;
    draw(&f, b);
    rl_vec4 textured = f.img->color[15 * W + 6], plain = f.img->color[6 * W + 15];
    assert_float_equal(textured.x, 0.25f, 1e-6f);
    assert_float_equal(textured.y, 0.25f, 1e-6f);
    assert_float_equal(textured.w, 0.5f, 1e-6f);
    assert_float_equal(plain.x, 0.5f, 0.0f);
    assert_float_equal(plain.y, 1.0f, 0.0f);
    unmake(&f);
    rl_texture_release(tex);
}

static void test_flat_face_colours_and_no_color_flag(void **state)
{
    (void)state;
    fixture f = make(ALL_LAYERS, identity());
    rl_vec3 p[4] = { pix(4, 4, 1), pix(4, 20, 1), pix(20, 20, 1), pix(20, 4, 1) };
    rl_vec4 face[2] = { rl_v4(0.25f, 0.5f, 0.75f, 1), rl_v4(0.1f, 0.2f, 0.3f, 0.4f) };
    rl_raster_batch b = tris(p, 4, quad_idx, 2);
    b.face_colors = face;
    draw(&f, b);
    assert_memory_equal(&f.img->color[15 * W + 6], &face[0], sizeof(rl_vec4));
    assert_memory_equal(&f.img->color[6 * W + 15], &face[1], sizeof(rl_vec4));
    /* NO_COLOR | NO_DEPTH: IDs only. */
    rl_image_clear(f.img);
    b.flags = RL_RASTER_NO_COLOR | RL_RASTER_NO_DEPTH;
    assert_int_equal(draw(&f, b), 256);
    assert_float_equal(f.img->color[15 * W + 6].w, 0.0f, 0.0f);
    assert_true(isinf(f.img->depth[15 * W + 6]));
    assert_int_equal(f.img->triangle_id[15 * W + 6], 0);
    unmake(&f);
}

/* ---- camera convenience --------------------------------------------------- */

static void test_set_camera_matches_the_equivalent_matrices(void **state)
{
    (void)state;
    /* Eye at the origin looking down -z with 90 degrees: perspective90. */
    rl_camera cam = { .eye = rl_v3(0, 0, 0), .target = rl_v3(0, 0, -1), .fov_deg = 90,
                      .width = W, .height = H, .z_near = 0.5f, .z_far = 100 };
    rl_vec3 p[3] = { rl_v3(-3, -1, -1.5f), rl_v3(3, -1.5f, -1.5f), rl_v3(0.5f, 2, -9) };
    fixture f = make(ALL_LAYERS, perspective90(0.5f, 100));
    uint64_t want = draw(&f, tris(p, 3, tri012, 1));
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(W, H, ALL_LAYERS, &img), RL_OK);
    rl_aabb bounds = { rl_v3(-3, -2, -9), rl_v3(3, 2, -1) };
    assert_int_equal(rl_raster_set_camera(f.r, img, &cam, bounds), RL_OK);
    assert_int_equal(draw(&f, tris(p, 3, tri012, 1)), want);
    for (int i = 0; i < W * H; ++i) {
        assert_int_equal(img->object_id[i], f.img->object_id[i]);
        if (img->object_id[i] != RL_ID_NONE)
            assert_float_equal(img->depth[i], f.img->depth[i], 1e-4f * f.img->depth[i]);
    }
    /* z_near = 0: clip range from the bounds; everything still in view. */
    rl_image_clear(img);
    cam.z_near = cam.z_far = 0;
    assert_int_equal(rl_raster_set_camera(f.r, img, &cam, bounds), RL_OK);
    assert_int_equal(draw(&f, tris(p, 3, tri012, 1)), want);
    cam.eye = cam.target;
    assert_int_equal(rl_raster_set_camera(f.r, img, &cam, bounds), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_set_camera(f.r, NULL, &cam, bounds), RL_ERR_INVALID_ARG);
    rl_image_release(img);
    unmake(&f);
}

/* ---- errors --------------------------------------------------------------- */

static void test_bad_arguments_are_rejected_and_leave_the_image_alone(void **state)
{
    (void)state;
    rl_raster *r = NULL;
    assert_int_equal(rl_raster_create(NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_create(&(rl_raster_desc){ .threads = -1 }, &r), RL_ERR_INVALID_ARG);
    assert_null(r);
    assert_int_equal(rl_raster_create(&(rl_raster_desc){ .threads = 2 }, &r), RL_OK);
    rl_vec3 p[3] = { pix(2, 2, 1), pix(12, 2, 1), pix(2, 12, 1) };
    rl_raster_batch b = tris(p, 3, tri012, 1);
    uint64_t visible = 0;
    rl_raster_points pts = { .count = 1, .positions = p, .size_px = 1 };
    /* No target yet. */
    assert_int_equal(rl_raster_draw(r, &b, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_query(r, &b, &visible), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_draw_points(r, &pts, NULL), RL_ERR_INVALID_ARG);

    rl_image *img = NULL;
    assert_int_equal(rl_image_create(W, H, ALL_LAYERS, &img), RL_OK);
    rl_mat4 m = identity();
    assert_int_equal(rl_raster_set_target(r, NULL, &m, &m), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_set_target(NULL, img, &m, &m), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_set_target(r, img, NULL, &m), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_set_target(r, img, &m, &m), RL_OK);
    assert_int_equal(rl_raster_draw(NULL, &b, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_draw(r, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_query(r, &b, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_draw_points(r, NULL, NULL), RL_ERR_INVALID_ARG);

    const uint32_t bad_idx[3] = { 0, 1, 3 };
    b.indices = bad_idx;
    rl_raster_counters c = { 0 };
    visible = 12345;
    assert_int_equal(rl_raster_draw(r, &b, &c), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_query(r, &b, &visible), RL_ERR_INVALID_ARG);
    assert_int_equal(visible, 12345);
    assert_int_equal(c.triangles_in, 0);
    b.indices = NULL;
    assert_int_equal(rl_raster_draw(r, &b, &c), RL_ERR_INVALID_ARG);
    assert_int_equal(count_covered(img), 0);
    assert_true(isinf(img->depth[0]));
    /* An empty batch is fine. */
    b.num_triangles = 0;
    assert_int_equal(rl_raster_draw(r, &b, &c), RL_OK);
    rl_image_release(img);
    rl_raster_release(r);
    rl_raster_release(NULL);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_right_triangle_covers_exactly_the_pixels_the_fill_rule_predicts),
        cmocka_unit_test(test_rectangle_includes_top_left_edges_and_excludes_bottom_right),
        cmocka_unit_test(test_two_triangles_sharing_a_diagonal_cover_a_square_exactly_once),
        cmocka_unit_test(test_random_fans_cover_their_polygon_without_gaps_or_overlaps),
        cmocka_unit_test(test_long_slivers_cover_exactly_their_pixels),
        cmocka_unit_test(test_nearer_triangle_wins_regardless_of_draw_order),
        cmocka_unit_test(test_depth_is_the_perspective_correct_eye_depth_of_the_plane),
        cmocka_unit_test(test_orthographic_depth_is_the_interpolated_eye_depth),
        cmocka_unit_test(test_id_layers_hold_object_and_triangle_ids),
        cmocka_unit_test(test_triangle_crossing_the_near_plane_covers_only_its_visible_part),
        cmocka_unit_test(test_triangle_behind_the_camera_draws_nothing),
        cmocka_unit_test(test_huge_triangles_cover_the_screen_without_overflow),
        cmocka_unit_test(test_non_finite_positions_skip_only_their_triangles),
        cmocka_unit_test(test_query_counts_what_a_draw_then_writes),
        cmocka_unit_test(test_query_agrees_with_draw_for_random_triangles),
        cmocka_unit_test(test_back_faces_are_culled_and_front_faces_kept),
        cmocka_unit_test(test_points_of_size_1_and_4_cover_1_and_16_pixels),
        cmocka_unit_test(test_points_are_depth_tested_and_culled_at_the_near_plane),
        cmocka_unit_test(test_multithreaded_result_is_identical_to_single_threaded),
        cmocka_unit_test(test_gouraud_colour_at_a_vertex_pixel_is_the_vertex_colour),
        cmocka_unit_test(test_uv_is_perspective_correct_on_a_receding_quad),
        cmocka_unit_test(test_per_triangle_textures_modulate_the_colour),
        cmocka_unit_test(test_flat_face_colours_and_no_color_flag),
        cmocka_unit_test(test_set_camera_matches_the_equivalent_matrices),
        cmocka_unit_test(test_bad_arguments_are_rejected_and_leave_the_image_alone),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
