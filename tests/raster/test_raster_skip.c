/* test_raster_skip.c: the rasterizer's ways of skipping work that cannot
 * show, which must never change an image: lazy vertex colours
 * (rl_raster_lazy_colors) and whole boxes outside the view
 * (rl_raster_box_outside). The view is a 90-degree perspective looking
 * down -z from the origin. */
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

typedef struct fixture {
    rl_raster *r;
    rl_image *img;
} fixture;

static fixture make(void)
{
    fixture f = { NULL, NULL };
    assert_int_equal(rl_raster_create(NULL, &f.r), RL_OK);
    assert_int_equal(rl_image_create(W, H, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &f.img), RL_OK);
    rl_mat4 view = identity(), proj = perspective90(0.1f, 100.0f);
    assert_int_equal(rl_raster_set_target(f.r, f.img, &view, &proj), RL_OK);
    return f;
}

static void unmake(fixture *f)
{
    rl_raster_release(f->r);
    rl_image_release(f->img);
}

static uint32_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*s >> 33);
}

static float frand(uint64_t *s) { return (float)lcg(s) / 2147483648.0f; }

/* The colour of vertex v: any pure function of v. */
static rl_vec4 colour_of(uint32_t v)
{
    return rl_v4((float)(v % 7) / 7.0f, (float)(v % 11) / 11.0f, (float)(v % 13) / 13.0f, 1.0f);
}

/* A shade callback that writes colour_of(v) and counts its calls per vertex. */
typedef struct shader {
    rl_vec4 *colors;
    uint32_t *calls;
} shader;

static void shade(void *user, uint32_t v)
{
    shader *s = user;
    s->colors[v] = colour_of(v);
    __atomic_add_fetch(&s->calls[v], 1u, __ATOMIC_RELAXED);
}

/* ---- lazy colours --------------------------------------------------------- */

/* Many triangles around the view: in it, behind the camera, across the near
 * plane, off to the sides, of both windings and all sizes. */
typedef struct soup {
    uint32_t nv, nt;
    rl_vec3 *pos;
    uint32_t *idx;
} soup;

static soup make_soup(uint32_t nt, uint64_t seed)
{
    soup s = { 3 * nt, nt, malloc(3 * nt * sizeof(rl_vec3)), malloc(3 * nt * sizeof(uint32_t)) };
    assert_non_null(s.pos);
    assert_non_null(s.idx);
    for (uint32_t t = 0; t < nt; ++t) {
        rl_vec3 c = rl_v3(frand(&seed) * 16 - 8, frand(&seed) * 16 - 8, -frand(&seed) * 12 + 1);
        float size = frand(&seed) < 0.8f ? 0.05f : 2.0f;
        for (int k = 0; k < 3; ++k) {
            s.pos[3 * t + k] = rl_v3(c.x + (frand(&seed) - 0.5f) * size, c.y + (frand(&seed) - 0.5f) * size,
                                     c.z + (frand(&seed) - 0.5f) * size);
            /* Shared vertices too: every fourth corner reuses an earlier one. */
            s.idx[3 * t + k] = (t > 0 && lcg(&seed) % 4 == 0) ? s.idx[3 * (t - 1) + k] : 3 * t + k;
        }
    }
    return s;
}

static void free_soup(soup *s)
{
    free(s->pos);
    free(s->idx);
}

static void draw_soup(fixture *f, const soup *s, const rl_vec4 *colors, const rl_raster_lazy_colors *lazy,
                      unsigned flags)
{
    rl_raster_batch b = tris(s->pos, s->nv, s->idx, s->nt);
    b.colors = colors;
    b.lazy = lazy;
    b.flags = flags;
    rl_image_clear(f->img);
    assert_int_equal(rl_raster_draw(f->r, &b, NULL), RL_OK);
}

static void test_lazy_colours_give_the_image_of_filled_colours(void **state)
{
    (void)state;
    int saved = omp_get_max_threads();
    /* More than one slab chunk per thread, so that parallel chunks share
     * vertices and race for them. */
    soup s = make_soup(20000, 7);
    rl_vec4 *filled = malloc(s.nv * sizeof *filled), *lazy_colors = calloc(s.nv, sizeof *lazy_colors);
    uint32_t *calls = calloc(s.nv, sizeof *calls), *stamps = calloc(s.nv, sizeof *stamps);
    size_t npx = (size_t)W * H;
    rl_vec4 *ref = malloc(npx * sizeof *ref);
    for (uint32_t v = 0; v < s.nv; ++v)
        filled[v] = colour_of(v);
    for (unsigned flags = 0; flags <= RL_RASTER_CULL_BACK; flags += RL_RASTER_CULL_BACK) {
        for (int threads = 1; threads <= 4; threads *= 2) {
            omp_set_num_threads(threads);
            fixture f = make();
            draw_soup(&f, &s, filled, NULL, flags);
            memcpy(ref, f.img->color, npx * sizeof *ref);
            shader sh = { lazy_colors, calls };
            static uint32_t frame = 0;
            rl_raster_lazy_colors lz = { shade, &sh, stamps, ++frame };
            memset(calls, 0, s.nv * sizeof *calls);
            draw_soup(&f, &s, lazy_colors, &lz, flags);
            assert_memory_equal(ref, f.img->color, npx * sizeof *ref);
            uint32_t shaded = 0;
            for (uint32_t v = 0; v < s.nv; ++v) {
                assert_true(calls[v] <= 1);
                shaded += calls[v];
            }
            /* Most of the soup is off-screen, tiny or back-facing. */
            assert_true(shaded > 0);
            assert_true(shaded < s.nv / 2);
            unmake(&f);
        }
    }
    omp_set_num_threads(saved);
    free(ref);
    free(filled);
    free(lazy_colors);
    free(calls);
    free(stamps);
    free_soup(&s);
}

static void test_lazy_colours_shade_only_vertices_of_drawn_triangles_once_per_frame(void **state)
{
    (void)state;
    fixture f = make();
    /* 0-2: in view, counter-clockwise (front); 3-5: behind the camera;
     * 6-8: in view, clockwise (a back face); 9-11: far right of the view;
     * 12-14: in view but smaller than a pixel, between pixel centres. */
    const float z = -2.0f, tiny = 0.002f, cx = 0.0f;   /* cx: the corner of four pixels */
    rl_vec3 pos[15] = {
        { -1, -1, z }, { 1, -1, z }, { 0, 1, z },
        { -1, -1, 2 }, { 1, -1, 2 }, { 0, 1, 2 },
        { -1, -1, z }, { 0, 1, z }, { 1, -1, z },
        { 40, -1, z }, { 42, -1, z }, { 41, 1, z },
        { cx, cx, z }, { cx + tiny, cx, z }, { cx, cx + tiny, z },
    };
    uint32_t idx[15];
    for (uint32_t i = 0; i < 15; ++i)
        idx[i] = i;
    rl_vec4 colors[15];
    uint32_t calls[15] = { 0 }, stamps[15] = { 0 };
    shader sh = { colors, calls };
    rl_raster_lazy_colors lz = { shade, &sh, stamps, 1 };
    rl_raster_batch b = tris(pos, 15, idx, 5);
    b.colors = colors;
    b.lazy = &lz;
    b.flags = RL_RASTER_CULL_BACK;
    rl_raster_counters c = { 0 };
    assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
    assert_int_equal(c.triangles_drawn, 1);
    for (uint32_t v = 0; v < 15; ++v)
        assert_int_equal(calls[v], v < 3 ? 1 : 0);
    /* The same frame again: nothing is shaded twice. */
    assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
    for (uint32_t v = 0; v < 3; ++v)
        assert_int_equal(calls[v], 1);
    /* A new frame shades again, and the image holds the shaded colour. */
    lz.frame = 2;
    rl_image_clear(f.img);
    assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
    for (uint32_t v = 0; v < 3; ++v)
        assert_int_equal(calls[v], 2);
    assert_true(f.img->color[(size_t)(H / 2) * W + W / 2].w > 0.0f);
    unmake(&f);
}

static void test_lazy_colours_with_bad_parameters_are_rejected(void **state)
{
    (void)state;
    fixture f = make();
    rl_vec3 pos[3] = { { -1, -1, -2 }, { 1, -1, -2 }, { 0, 1, -2 } };
    uint32_t idx[3] = { 0, 1, 2 }, calls[3] = { 0 }, stamps[3] = { 0 };
    rl_vec4 colors[3];
    shader sh = { colors, calls };
    rl_raster_batch b = tris(pos, 3, idx, 1);
    b.colors = colors;
    const rl_raster_lazy_colors bad[] = {
        { shade, &sh, stamps, 0 },              /* frame 0 is every stamp's start */
        { shade, &sh, stamps, 1u << 31 },       /* 2 frame would wrap */
        { NULL, &sh, stamps, 1 },
        { shade, &sh, NULL, 1 },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        b.lazy = &bad[i];
        assert_int_equal(rl_raster_draw(f.r, &b, NULL), RL_ERR_INVALID_ARG);
    }
    assert_int_equal(calls[0] + calls[1] + calls[2], 0);
    unmake(&f);
}

/* ---- boxes outside the view ----------------------------------------------- */

static rl_aabb box(float x0, float y0, float z0, float x1, float y1, float z1)
{
    rl_aabb b = { { x0, y0, z0 }, { x1, y1, z1 } };
    return b;
}

static void test_box_outside_the_view_is_recognised(void **state)
{
    (void)state;
    fixture f = make();
    assert_true(rl_raster_box_outside(f.r, box(-1, -1, 1, 1, 1, 3)));          /* behind */
    assert_true(rl_raster_box_outside(f.r, box(10, -1, -5, 11, 1, -4)));       /* right */
    assert_true(rl_raster_box_outside(f.r, box(-11, -1, -5, -10, 1, -4)));     /* left */
    assert_true(rl_raster_box_outside(f.r, box(-1, 10, -5, 1, 11, -4)));       /* above */
    assert_true(rl_raster_box_outside(f.r, box(-1, -11, -5, 1, -10, -4)));     /* below */
    assert_false(rl_raster_box_outside(f.r, box(-1, -1, -5, 1, 1, -4)));       /* in view */
    assert_false(rl_raster_box_outside(f.r, box(-1, -1, -1, 1, 1, 1)));        /* around the eye */
    assert_false(rl_raster_box_outside(f.r, box(4, -1, -5, 6, 1, -4)));        /* across the right side */
    assert_false(rl_raster_box_outside(f.r, box(-100, -1, -50, 100, 1, -40))); /* wider than the view */
    /* Not decided: empty, non-finite, or no target at all. */
    assert_false(rl_raster_box_outside(f.r, box(1, 1, 1, 0, 0, 0)));
    assert_false(rl_raster_box_outside(f.r, box(NAN, -1, 1, 1, 1, 3)));
    assert_false(rl_raster_box_outside(f.r, box(-INFINITY, -1, 1, 1, 1, 3)));
    assert_false(rl_raster_box_outside(NULL, box(-1, -1, 1, 1, 1, 3)));
    rl_raster *bare = NULL;
    assert_int_equal(rl_raster_create(NULL, &bare), RL_OK);
    assert_false(rl_raster_box_outside(bare, box(-1, -1, 1, 1, 1, 3)));
    rl_raster_release(bare);
    unmake(&f);
}

/* The contract that makes skipping safe: whatever lies in a box said to be
 * outside draws nothing. Boxes hug the view's sides, where rounding
 * matters, and many are outside, so the test cannot pass vacuously. */
static void test_triangles_in_a_box_outside_draw_nothing(void **state)
{
    (void)state;
    fixture f = make();
    uint64_t seed = 11;
    int outside = 0, inside_drawn = 0;
    for (int i = 0; i < 3000; ++i) {
        float z0 = -0.05f - frand(&seed) * 20.0f, z1 = z0 + frand(&seed) * 2.0f;
        /* At depth -z the view spans |x|, |y| <= -z: put boxes near x = -z0. */
        float side = frand(&seed) < 0.5f ? 1.0f : -1.0f, edge = -z0 * side;
        float x0 = edge + (frand(&seed) - 0.5f) * 0.01f * -z0, x1 = x0 + frand(&seed) * 0.5f;
        float y0 = (frand(&seed) - 0.5f) * -z0, y1 = y0 + frand(&seed);
        if (lcg(&seed) % 2) {   /* the same near the top and bottom sides */
            float t0 = x0, t1 = x1;
            x0 = y0, x1 = y1, y0 = t0, y1 = t1;
        }
        rl_aabb bb = box(x0, y0, z0, x1, y1, z1);
        rl_vec3 pos[24];
        uint32_t idx[24];
        for (int k = 0; k < 24; ++k) {
            /* Corners of the box among the vertices, where rounding is tightest. */
            float u = k < 8 ? (float)(k & 1) : frand(&seed), v = k < 8 ? (float)((k >> 1) & 1) : frand(&seed),
                  w = k < 8 ? (float)((k >> 2) & 1) : frand(&seed);
            pos[k] = rl_v3(x0 + u * (x1 - x0), y0 + v * (y1 - y0), z0 + w * (z1 - z0));
            pos[k] = rl_v3(fminf(fmaxf(pos[k].x, x0), x1), fminf(fmaxf(pos[k].y, y0), y1),
                           fminf(fmaxf(pos[k].z, z0), z1));
            idx[k] = (uint32_t)(lcg(&seed) % 24);
        }
        rl_raster_batch b = tris(pos, 24, idx, 8);
        rl_raster_counters c = { 0 };
        rl_image_clear(f.img);
        assert_int_equal(rl_raster_draw(f.r, &b, &c), RL_OK);
        if (rl_raster_box_outside(f.r, bb)) {
            ++outside;
            assert_int_equal(c.triangles_drawn, 0);
            assert_int_equal(c.pixels_written, 0);
        } else {
            inside_drawn += c.pixels_written > 0;
        }
    }
    assert_true(outside > 500);
    assert_true(inside_drawn > 100);
    unmake(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lazy_colours_give_the_image_of_filled_colours),
        cmocka_unit_test(test_lazy_colours_shade_only_vertices_of_drawn_triangles_once_per_frame),
        cmocka_unit_test(test_lazy_colours_with_bad_parameters_are_rejected),
        cmocka_unit_test(test_box_outside_the_view_is_recognised),
        cmocka_unit_test(test_triangles_in_a_box_outside_draw_nothing),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
