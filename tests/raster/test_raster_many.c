/* test_raster_many.c: rl_raster_draw_many against the same batches drawn
 * one by one with rl_raster_draw on one thread, the oracle it promises to
 * equal bit for bit (colour, depth, IDs, counters).
 *
 * The batches mimic a scene of many small objects, with what cuts a group
 * mixed in: batches big enough to be drawn alone, a layered one, changes of
 * flags, empty ones, batches with many vertices but few triangles, lazily
 * coloured ones, and more small triangles in all than one group holds. Many
 * triangles overlap at equal depth, so any change of submission order shows
 * in the image. Perspective and orthographic projections both run, because
 * the latter interpolates per-vertex eye depth that each batch of a group
 * keeps in its own part of the scratch. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "raster/raster_fixtures.h"
#include "rl/rl_common.h"
#include "rl/rl_raster.h"

#define S 128
#define ALL_LAYERS (RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID)
#define NB 2400                  /* batches */
#define MAX_TRIS 3000            /* the biggest batch; the small ones have < 40 */
#define WIDE_VERTICES 150000     /* vertices of a batch with two triangles */

static uint32_t lcg(uint64_t *s)
{
    *s = *s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(*s >> 33);
}

static float frand(uint64_t *s) { return (float)lcg(s) / 2147483648.0f; }

/* The batches and everything they point to. */
typedef struct scene {
    rl_raster_batch b[NB];
    rl_raster_lazy_colors lazy[NB];
    rl_raster_layer layer;
    rl_vec3 *pos;
    rl_vec4 *col, *lazy_col;
    uint32_t *idx, *stamps;
    size_t num_vertices;
} scene;

/* When set, shade() counts its calls per vertex of the scene whose lazy
 * colours start at shade_base. */
static uint32_t *shade_count;
static const rl_vec4 *shade_base;

/* Lazy shading: a pure function of the vertex, as rl_raster_lazy_colors asks. */
static void shade(void *user, uint32_t v)
{
    rl_vec4 *c = user;
    if (shade_count)
        __atomic_add_fetch(&shade_count[(size_t)(c - shade_base) + v], 1, __ATOMIC_RELAXED);
    c[v] = rl_v4((float)(v % 7) / 7.0f, (float)(v % 11) / 11.0f, (float)(v % 13) / 13.0f, 1.0f);
}

static uint32_t triangles_of(int k, uint64_t *seed)
{
    if (k % 10 == 9)
        return 0;                               /* empty */
    if (k == 600 || k == 1700)
        return MAX_TRIS;                        /* drawn alone */
    if (k == 1000 || k == 1001)
        return 2;                               /* many vertices, see vertices_of */
    return 1 + lcg(seed) % 39;
}

static uint32_t vertices_of(int k, uint32_t nt)
{
    return (k == 1000 || k == 1001) ? WIDE_VERTICES : 3 * nt;
}

static void make_scene(scene *sc)
{
    memset(sc, 0, sizeof *sc);
    uint64_t seed = 7;
    uint32_t nt[NB];
    size_t total_v = 0, total_i = 0;
    for (int k = 0; k < NB; ++k) {
        nt[k] = triangles_of(k, &seed);
        total_v += vertices_of(k, nt[k]);
        total_i += 3 * (size_t)nt[k];
    }
    sc->num_vertices = total_v;
    sc->pos = malloc(total_v * sizeof *sc->pos);
    sc->col = malloc(total_v * sizeof *sc->col);
    sc->lazy_col = calloc(total_v, sizeof *sc->lazy_col);
    sc->stamps = calloc(total_v, sizeof *sc->stamps);
    sc->idx = malloc((total_i + 1) * sizeof *sc->idx);
    assert_non_null(sc->pos);
    assert_non_null(sc->col);
    assert_non_null(sc->lazy_col);
    assert_non_null(sc->stamps);
    assert_non_null(sc->idx);
    size_t v0 = 0, i0 = 0;
    for (int k = 0; k < NB; ++k) {
        const uint32_t nv = vertices_of(k, nt[k]);
        /* An object: triangles around a centre, at one of a few depths, so
         * that objects overlap at equal depth. */
        float z = -2.0f - (float)(lcg(&seed) % 6);
        float cx = (frand(&seed) * 1.6f - 0.8f) * -z, cy = (frand(&seed) * 1.6f - 0.8f) * -z;
        float size = nt[k] == MAX_TRIS ? 0.6f : 0.15f;
        for (uint32_t v = 0; v < nv; ++v) {
            sc->pos[v0 + v] = rl_v3(cx + size * -z * (frand(&seed) - 0.5f),
                                    cy + size * -z * (frand(&seed) - 0.5f), z);
            sc->col[v0 + v] = rl_v4(frand(&seed), frand(&seed), frand(&seed), 1);
        }
        for (uint32_t i = 0; i < 3 * nt[k]; ++i)
            sc->idx[i0 + i] = nt[k] * 3 == nv ? i : lcg(&seed) % nv;
        rl_raster_batch *b = &sc->b[k];
        b->num_vertices = nv;
        b->positions = sc->pos + v0;
        b->num_triangles = nt[k];
        b->indices = sc->idx + i0;
        b->object_id = (uint32_t)k;
        b->first_triangle_id = (uint32_t)i0 / 3;
        b->colors = sc->col + v0;
        if (k % 5 == 3) {
            /* Lazily coloured: shade writes lazy_col + v0. */
            b->colors = sc->lazy_col + v0;
            sc->lazy[k] = (rl_raster_lazy_colors){ shade, sc->lazy_col + v0, sc->stamps + v0, 1 };
            b->lazy = &sc->lazy[k];
        } else if (k % 7 == 4) {
            b->colors = NULL;
            b->color = rl_v4(frand(&seed), frand(&seed), frand(&seed), 1);
        }
        if (k >= 300 && k < 340)
            b->flags = RL_RASTER_CULL_BACK;     /* a run with other flags */
        if (k == 1200)
            b->flags = RL_RASTER_NO_DEPTH_TEST; /* one alone */
        if (k == 1400) {
            sc->layer = (rl_raster_layer){ .colors = sc->col + v0 };
            b->num_layers = 1;
            b->layers = &sc->layer;
        }
        if (k == 19) {
            /* Empty, with vertices but no positions or indices: nothing to
             * transform. */
            b->positions = NULL;
            b->indices = NULL;
            b->num_vertices = 5;
        }
        v0 += nv;
        i0 += 3 * (size_t)nt[k];
    }
}

static void free_scene(scene *sc)
{
    free(sc->pos);
    free(sc->col);
    free(sc->lazy_col);
    free(sc->stamps);
    free(sc->idx);
}

typedef struct frame {
    rl_vec4 color[S * S];
    float depth[S * S];
    uint32_t object_id[S * S], triangle_id[S * S];
    rl_raster_counters counters;
} frame;

/* Draws list[0 .. count) of sc's batches with `threads` threads, one by
 * one or with draw_many. */
static void render_list(scene *sc, const rl_raster_batch *list, int count, bool ortho, bool many, int threads,
                        frame *out)
{
    /* Lazy colours are shaded anew in every run. */
    memset(sc->stamps, 0, sc->num_vertices * sizeof *sc->stamps);
    memset(sc->lazy_col, 0, sc->num_vertices * sizeof *sc->lazy_col);
    rl_raster *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(&(rl_raster_desc){ .threads = threads }, &r), RL_OK);
    assert_int_equal(rl_image_create(S, S, ALL_LAYERS, &img), RL_OK);
    rl_mat4 view = identity(), proj = perspective90(0.5f, 100);
    if (ortho) {
        /* x, y in [-6, 6] to NDC; z only needs to map into the clip range. */
        proj = identity();
        proj.m[0][0] = proj.m[1][1] = 1.0f / 6.0f;
        proj.m[2][2] = 0.01f;
    }
    assert_int_equal(rl_raster_set_target(r, img, &view, &proj), RL_OK);
    memset(&out->counters, 0, sizeof out->counters);
    if (many) {
        assert_int_equal(rl_raster_draw_many(r, list, (uint32_t)count, &out->counters), RL_OK);
    } else {
        for (int k = 0; k < count; ++k)
            assert_int_equal(rl_raster_draw(r, &list[k], &out->counters), RL_OK);
    }
    memcpy(out->color, img->color, sizeof out->color);
    memcpy(out->depth, img->depth, sizeof out->depth);
    memcpy(out->object_id, img->object_id, sizeof out->object_id);
    memcpy(out->triangle_id, img->triangle_id, sizeof out->triangle_id);
    rl_image_release(img);
    rl_raster_release(r);
}

static void render(scene *sc, bool ortho, bool many, int threads, frame *out)
{
    render_list(sc, sc->b, NB, ortho, many, threads, out);
}

static void check_equal_to_one_by_one(bool ortho)
{
    scene *sc = malloc(sizeof *sc);
    frame *ref = malloc(sizeof *ref), *got = malloc(sizeof *got);
    assert_non_null(sc);
    assert_non_null(ref);
    assert_non_null(got);
    make_scene(sc);
    render(sc, ortho, false, 1, ref);
    /* The scene is what it should be: most triangles drawn, most of the
     * image covered, many objects visible. */
    assert_true(ref->counters.triangles_in > (1u << 15) + 2 * MAX_TRIS);  /* > one group */
    assert_true(ref->counters.triangles_drawn > ref->counters.triangles_in / 2);
    int covered = 0;
    for (int i = 0; i < S * S; ++i)
        covered += ref->object_id[i] != RL_ID_NONE;
    assert_true(covered > S * S / 2);
    for (int threads = 1; threads <= 4; ++threads) {
        render(sc, ortho, true, threads, got);
        assert_memory_equal(ref, got, sizeof *ref);
    }
    free_scene(sc);
    free(sc);
    free(ref);
    free(got);
}

static void test_draw_many_equals_draws_one_by_one_in_perspective(void **state)
{
    (void)state;
    check_equal_to_one_by_one(false);
}

static void test_draw_many_equals_draws_one_by_one_in_orthographic(void **state)
{
    (void)state;
    check_equal_to_one_by_one(true);
}

/* A list that holds lazily coloured batches twice, side by side and far
 * apart (a caller that lists an object twice): their stamps are shared
 * between the parallel chunks of a group, which must then shade each
 * vertex once, as the draws one by one do. */
static void test_batches_listed_twice_share_their_lazy_colours(void **state)
{
    (void)state;
    enum { N = 700 };
    scene *sc = malloc(sizeof *sc);
    rl_raster_batch *list = malloc(2 * N * sizeof *list);
    frame *ref = malloc(sizeof *ref), *got = malloc(sizeof *got);
    assert_non_null(sc);
    assert_non_null(list);
    assert_non_null(ref);
    assert_non_null(got);
    make_scene(sc);
    int n = 0;
    for (int k = 0; k < N; ++k) {
        list[n++] = sc->b[k];
        if (k % 5 == 3 && k % 2)
            list[n++] = sc->b[k];          /* next to itself */
    }
    for (int k = 0; k < N && n < 2 * N; k += 5)
        list[n++] = sc->b[k + 3];          /* again, a group or more later */
    render_list(sc, list, n, false, false, 1, ref);
    assert_true(ref->counters.triangles_drawn > 1000);
    shade_count = calloc(sc->num_vertices, sizeof *shade_count);
    shade_base = sc->lazy_col;
    assert_non_null(shade_count);
    for (int threads = 2; threads <= 4; ++threads) {
        memset(shade_count, 0, sc->num_vertices * sizeof *shade_count);
        render_list(sc, list, n, false, true, threads, got);
        assert_memory_equal(ref, got, sizeof *ref);
        uint32_t most = 0;
        for (size_t v = 0; v < sc->num_vertices; ++v)
            most = shade_count[v] > most ? shade_count[v] : most;
        assert_int_equal(most, 1);
    }
    free(shade_count);
    shade_count = NULL;
    free_scene(sc);
    free(sc);
    free(list);
    free(ref);
    free(got);
}

static void test_an_invalid_batch_fails_before_anything_is_drawn(void **state)
{
    (void)state;
    scene *sc = malloc(sizeof *sc);
    assert_non_null(sc);
    make_scene(sc);
    rl_raster *r = NULL;
    rl_image *img = NULL;
    assert_int_equal(rl_raster_create(NULL, &r), RL_OK);
    assert_int_equal(rl_image_create(S, S, ALL_LAYERS, &img), RL_OK);
    rl_mat4 view = identity(), proj = perspective90(0.5f, 100);
    assert_int_equal(rl_raster_set_target(r, img, &view, &proj), RL_OK);
    rl_image_clear(img);

    const uint32_t bad_idx[3] = { 0, 1, 99 };
    sc->b[1234].indices = bad_idx;
    sc->b[1234].num_triangles = 1;
    rl_raster_counters c = { 0 };
    rl_clear_error();
    assert_int_equal(rl_raster_draw_many(r, sc->b, NB, &c), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "batch 1234 of 2400"));
    assert_non_null(strstr(rl_last_error(), "index 99 out of range"));
    assert_int_equal(c.triangles_in, 0);
    for (int i = 0; i < S * S; ++i)
        assert_int_equal(img->object_id[i], RL_ID_NONE);

    rl_clear_error();
    assert_int_equal(rl_raster_draw_many(r, NULL, 3, &c), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_draw_many(r, NULL, 0, &c), RL_OK);
    assert_int_equal(rl_raster_draw_many(NULL, sc->b, 1, &c), RL_ERR_INVALID_ARG);
    rl_image_release(img);
    rl_raster_release(r);
    free_scene(sc);
    free(sc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_draw_many_equals_draws_one_by_one_in_perspective),
        cmocka_unit_test(test_draw_many_equals_draws_one_by_one_in_orthographic),
        cmocka_unit_test(test_batches_listed_twice_share_their_lazy_colours),
        cmocka_unit_test(test_an_invalid_batch_fails_before_anything_is_drawn),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
