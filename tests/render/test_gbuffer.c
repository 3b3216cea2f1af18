/* test_gbuffer.c: the G-buffer (rl_gbuffer.h; Schröder 2017, Sec. 8.1):
 * traced and rasterized visibility agree on the Cornell box, the fields
 * are consistent with the scene, and bad arguments are refused. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_accel.h"
#include "rl/rl_gbuffer.h"
#include "rl/rl_scene.h"

#define SIZE 64

static void test_trace_and_raster_agree_on_the_cornell_box(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = cam.height = SIZE;
    rl_accel *bvh = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &bvh), RL_OK);
    assert_int_equal(rl_accel_commit(bvh), RL_OK);
    rl_gbuffer *tr = NULL, *ra = NULL;
    assert_int_equal(rl_gbuffer_create(SIZE, SIZE, &tr), RL_OK);
    assert_int_equal(rl_gbuffer_create(SIZE, SIZE, &ra), RL_OK);
    assert_int_equal(rl_gbuffer_trace(tr, bvh, &cam), RL_OK);
    assert_int_equal(rl_gbuffer_raster(ra, s, &cam), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    int n = SIZE * SIZE, same = 0, hits = 0;
    for (int i = 0; i < n; ++i) {
        if (tr->triangle[i] != ra->triangle[i])
            continue;
        ++same;
        if (tr->triangle[i] == RL_ID_NONE) {
            assert_true(isinf(ra->depth[i]));
            assert_int_equal(ra->material[i], RL_NONE);
            continue;
        }
        ++hits;
        /* The same triangle gives the same point, normal and material. */
        assert_float_equal(tr->depth[i], ra->depth[i], 1e-4f * tr->depth[i]);
        assert_float_equal(rl_length(rl_sub(tr->position[i], ra->position[i])), 0.0f, 1e-4f);
        assert_float_equal(rl_dot(tr->normal[i], ra->normal[i]), 1.0f, 1e-5f);
        assert_int_equal(tr->material[i], d->triangle_material[tr->triangle[i]]);
        assert_int_equal(tr->object[i], d->triangle_object[tr->triangle[i]]);
        rl_vec3 kd = d->materials[tr->material[i]].diffuse;
        assert_float_equal(tr->albedo[i].x, kd.x, 1e-6f);
        /* Normals face the camera. */
        assert_true(rl_dot(tr->normal[i], rl_sub(cam.eye, tr->position[i])) > 0.0f);
    }
    assert_true(hits > n / 2);
    assert_true(same * 100 > 99 * n);
    rl_gbuffer_release(tr);
    rl_gbuffer_release(ra);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

static void test_clear_and_bad_arguments(void **state)
{
    (void)state;
    rl_gbuffer *g = NULL;
    assert_int_equal(rl_gbuffer_create(0, 4, &g), RL_ERR_LIMIT);
    assert_null(g);
    assert_int_equal(rl_gbuffer_create(4, RL_IMAGE_MAX_SIZE + 1, &g), RL_ERR_LIMIT);
    assert_int_equal(rl_gbuffer_create(4, 3, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_gbuffer_create(4, 3, &g), RL_OK);
    for (int i = 0; i < 12; ++i) {
        assert_true(isinf(g->depth[i]));
        assert_int_equal(g->object[i], RL_ID_NONE);
        assert_int_equal(g->triangle[i], RL_ID_NONE);
        assert_int_equal(g->material[i], RL_NONE);
    }
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = cam.height = 8;                 /* not the G-buffer's size */
    rl_clear_error();
    assert_int_equal(rl_gbuffer_raster(g, s, &cam), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "4x3"));
    rl_clear_error();
    assert_int_equal(rl_gbuffer_raster(NULL, s, &cam), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_gbuffer_trace(g, NULL, &cam), RL_ERR_INVALID_ARG);
    cam.width = 4;
    cam.height = 3;
    assert_int_equal(rl_gbuffer_raster(g, s, &cam), RL_OK);
    rl_gbuffer_clear(g);
    assert_int_equal(g->triangle[5], RL_ID_NONE);
    rl_clear_error();
    rl_gbuffer_release(g);
    rl_gbuffer_release(NULL);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_trace_and_raster_agree_on_the_cornell_box),
        cmocka_unit_test(test_clear_and_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
