/* test_camera.c: the pinhole camera (ray frame vs view/projection, validation,
 * framing a box) and keyframed camera paths. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <cmocka.h>

#include <string.h>

#include "rl/rl.h"

static void assert_vec3_near(rl_vec3 a, rl_vec3 b, float eps)
{
    assert_true(fabsf(a.x - b.x) <= eps);
    assert_true(fabsf(a.y - b.y) <= eps);
    assert_true(fabsf(a.z - b.z) <= eps);
}

/* Pixel position of a world point through view, projection and a y-down viewport. */
static rl_vec2 project(const rl_camera *c, rl_vec3 p, float z_near, float z_far)
{
    rl_mat4 view = rl_camera_view(c), proj = rl_camera_projection(c, z_near, z_far);
    rl_mat4 vp = rl_mat4_mul(&proj, &view);
    rl_vec4 clip = rl_mat4_mul_vec4(&vp, rl_v4_from3(p, 1.0f));
    float x = clip.x / clip.w, y = clip.y / clip.w;
    return rl_v2((x + 1.0f) * 0.5f * (float)c->width, (1.0f - y) * 0.5f * (float)c->height);
}

static void test_points_on_pixel_rays_project_back_to_the_pixel(void **state)
{
    (void)state;
    const rl_camera cams[3] = {
        { .eye = { 1, 2, 3 }, .target = { -2, 0.5f, -4 }, .up = { 0, 1, 0 }, .fov_deg = 60,
          .width = 320, .height = 200 },
        { .eye = { 0, 10, 0.1f }, .target = { 0, 0, 0 }, .up = { 0, 0, -1 }, .fov_deg = 20,
          .width = 64, .height = 256 },
        { .eye = { -5, 1, 7 }, .target = { 3, 2, 1 }, .up = { 0.2f, 1, 0.1f }, .fov_deg = 110,
          .width = 1000, .height = 999 },
    };
    srand(7);
    for (int c = 0; c < 3; ++c) {
        rl_camera cam = cams[c];
        assert_int_equal(rl_camera_validate(&cam), RL_OK);
        rl_camera_frame f = rl_camera_frame_make(&cam);
        for (int i = 0; i < 200; ++i) {
            float px = (float)rand() / (float)RAND_MAX * (float)cam.width;
            float py = (float)rand() / (float)RAND_MAX * (float)cam.height;
            float t = 0.5f + 20.0f * (float)rand() / (float)RAND_MAX;
            rl_ray r = rl_camera_frame_ray(&f, px, py);
            assert_true(fabsf(rl_length(r.d) - 1.0f) < 1e-5f);
            assert_true(r.t_min == 0.0f && isinf(r.t_max));
            rl_vec2 back = project(&cam, rl_ray_at(&r, t), 0.1f, 100.0f);
            assert_true(fabsf(back.x - px) < 2e-3f * (float)cam.width);
            assert_true(fabsf(back.y - py) < 2e-3f * (float)cam.height);
        }
        /* The centre ray looks straight at the target. */
        rl_ray mid = rl_camera_frame_ray(&f, 0.5f * (float)cam.width, 0.5f * (float)cam.height);
        assert_vec3_near(mid.d, rl_normalize(rl_sub(cam.target, cam.eye)), 1e-5f);
    }
}

static void test_top_left_pixel_ray_points_up_and_left(void **state)
{
    (void)state;
    rl_camera cam = { .eye = { 0, 0, 0 }, .target = { 0, 0, -1 }, .fov_deg = 90, .width = 200,
                      .height = 100 };
    rl_camera_frame f = rl_camera_frame_make(&cam);
    rl_ray r = rl_camera_frame_ray(&f, 0.0f, 0.0f);
    /* tan(45 deg) = 1 vertically, aspect 2 horizontally: corner direction (-2, 1, -1). */
    assert_vec3_near(r.d, rl_normalize(rl_v3(-2, 1, -1)), 1e-6f);
}

static void test_validate_rejects_degenerate_cameras(void **state)
{
    (void)state;
    rl_camera ok = { .eye = { 0, 0, 5 } };
    assert_int_equal(rl_camera_validate(&ok), RL_OK);
    rl_camera resolved = rl_camera_resolve(&ok);
    assert_true(resolved.fov_deg == RL_CAMERA_DEFAULT_FOV_DEG && resolved.up.y == 1.0f);
    assert_int_equal(resolved.width, RL_CAMERA_DEFAULT_WIDTH);
    assert_int_equal(resolved.height, RL_CAMERA_DEFAULT_HEIGHT);

    rl_camera c = ok;
    c.target = c.eye;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    c = ok;
    c.up = rl_v3(0, 0, 2);     /* parallel to the view direction */
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    c = ok;
    c.fov_deg = 180.0f;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    c.fov_deg = -10.0f;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    c.fov_deg = 179.0f;
    assert_int_equal(rl_camera_validate(&c), RL_OK);
    /* fov 0 means default, which is valid */
    c.fov_deg = 0.0f;
    assert_int_equal(rl_camera_validate(&c), RL_OK);
    c = ok;
    c.width = 16385;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_LIMIT);
    c.width = 16384;
    assert_int_equal(rl_camera_validate(&c), RL_OK);
    c.height = -1;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_LIMIT);
    c = ok;
    c.eye.y = NAN;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    c = ok;
    c.fov_deg = INFINITY;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    c = ok;
    c.z_near = 10.0f;
    c.z_far = 1.0f;
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_camera_validate(NULL), RL_ERR_INVALID_ARG);
    rl_clear_error();
    /* Huge coordinates: the angle test works in units of the largest
     * component, so no length overflows into a false "parallel". */
    c = ok;
    c.eye = rl_v3s(1e30f);
    assert_int_equal(rl_camera_validate(&c), RL_OK);
    c.up = rl_v3s(1.0f);   /* along the view direction */
    assert_int_equal(rl_camera_validate(&c), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "parallel"));
    rl_clear_error();
}

/* rl_camera_fit_points: every point inside the frame with the 4 % margin,
 * and the fit tight: the extreme points touch the margin on one axis and
 * are centred on the other. */
/* Every field takes part: a progressive renderer that missed a change
 * would keep accumulating the old view. */
static void test_equal_sees_every_field(void **state)
{
    (void)state;
    const rl_camera a = { .eye = { 1, 2, 3 }, .target = { 0, 0, 0 }, .up = { 0, 1, 0 }, .fov_deg = 40.0f,
                          .width = 64, .height = 48, .z_near = 0.1f, .z_far = 100.0f };
    assert_true(rl_camera_equal(&a, &a));
    rl_camera b = a;
    assert_true(rl_camera_equal(&a, &b));
    for (int k = 0; k < 10; ++k) {
        b = a;
        switch (k) {
        case 0: b.eye.x += 0.5f; break;
        case 1: b.target.z = -1.0f; break;
        case 2: b.up = rl_v3(0.0f, 0.0f, 1.0f); break;
        case 3: b.fov_deg = 41.0f; break;
        case 4: b.width = 65; break;
        case 5: b.height = 47; break;
        case 6: b.z_near = 0.2f; break;
        case 7: b.z_far = 99.0f; break;
        case 8: b.up = rl_v3(0.0f, 0.0f, 0.0f); break;   /* zero means +y, yet is another camera as given */
        default: b.eye.y = nextafterf(a.eye.y, 3.0f); break;   /* one ulp */
        }
        assert_false(rl_camera_equal(&a, &b));
    }
    assert_false(rl_camera_equal(&a, NULL));
    assert_true(rl_camera_equal(NULL, NULL));
}

static void test_fit_points_is_tight_from_every_orbit(void **state)
{
    (void)state;
    rl_vec3 pts[200];
    uint32_t seed = 12345;
    for (int i = 0; i < 200; ++i) {
        float v[3];
        for (int k = 0; k < 3; ++k) {
            seed = seed * 1664525u + 1013904223u;
            v[k] = (float)(seed >> 8) / 16777216.0f;
        }
        /* A long, flat, off-centre cloud. */
        pts[i] = rl_v3(1000.0f + 40.0f * v[0], -3.0f + 2.0f * v[1], 7.0f + 10.0f * v[2]);
    }
    const float orbits[4][2] = { { 25, 20 }, { 0, 0 }, { -120, 60 }, { 200, -45 } };
    const int sizes[3][2] = { { 640, 480 }, { 100, 400 }, { 800, 200 } };
    for (int o = 0; o < 4; ++o)
        for (int sz = 0; sz < 3; ++sz) {
            rl_camera cam = rl_camera_fit_points(pts, 200, orbits[o][0], orbits[o][1],
                                                 sizes[sz][0], sizes[sz][1]);
            assert_int_equal(rl_camera_validate(&cam), RL_OK);
            rl_camera_frame f = rl_camera_frame_make(&cam);
            float ty = f.tan_half_fov_y, tx = ty * f.aspect;
            float xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
            for (int i = 0; i < 200; ++i) {
                rl_vec3 q = rl_sub(pts[i], f.eye);
                float depth = -rl_dot(q, f.w);
                assert_true(depth > 0.0f);
                float x = rl_dot(q, f.u) / (depth * tx), y = rl_dot(q, f.v) / (depth * ty);
                xmin = fminf(xmin, x), xmax = fmaxf(xmax, x);
                ymin = fminf(ymin, y), ymax = fmaxf(ymax, y);
            }
            /* Inside the 0.96 margin, up to rounding. */
            assert_true(xmin >= -0.9601f && xmax <= 0.9601f);
            assert_true(ymin >= -0.9601f && ymax <= 0.9601f);
            /* Centred on both axes. */
            assert_true(fabsf(xmin + xmax) < 2e-3f && fabsf(ymin + ymax) < 2e-3f);
            /* Touching on one. */
            assert_true(fmaxf(xmax, ymax) > 0.958f);
        }
    /* No finite point: a valid camera looking at the origin. */
    rl_vec3 bad = rl_v3(NAN, 0, 0);
    rl_camera cam = rl_camera_fit_points(&bad, 1, 25, 20, 64, 64);
    assert_int_equal(rl_camera_validate(&cam), RL_OK);
    /* One point: a valid camera in front of it. */
    rl_vec3 one = rl_v3(5, 5, 5);
    cam = rl_camera_fit_points(&one, 1, 25, 20, 64, 64);
    assert_int_equal(rl_camera_validate(&cam), RL_OK);
    assert_true(rl_length(rl_sub(cam.target, one)) < 1e-4f);
}

static void test_frame_bounds_sees_all_corners_of_the_box(void **state)
{
    (void)state;
    const rl_aabb boxes[3] = {
        { { -1, -1, -1 }, { 1, 1, 1 } },
        { { 100, 0, -3 }, { 140, 2, 5 } },       /* flat and wide */
        { { 0, -50, 0 }, { 1, 50, 1 } },         /* tall */
    };
    const int sizes[3][2] = { { 640, 480 }, { 100, 400 }, { 800, 200 } };
    for (int b = 0; b < 3; ++b)
        for (int s = 0; s < 3; ++s) {
            rl_camera cam = rl_camera_frame_bounds(boxes[b], sizes[s][0], sizes[s][1]);
            assert_int_equal(rl_camera_validate(&cam), RL_OK);
            assert_int_equal(cam.width, sizes[s][0]);
            float z_near, z_far;
            rl_camera_clip_range(&cam, boxes[b], &z_near, &z_far);
            assert_true(z_near > 0.0f && z_near < z_far);
            rl_camera_frame f = rl_camera_frame_make(&cam);
            for (int k = 0; k < 8; ++k) {
                rl_aabb bx = boxes[b];
                rl_vec3 p = rl_v3(k & 1 ? bx.max.x : bx.min.x, k & 2 ? bx.max.y : bx.min.y,
                                  k & 4 ? bx.max.z : bx.min.z);
                rl_vec2 px = project(&cam, p, z_near, z_far);
                assert_true(px.x >= 0.0f && px.x <= (float)cam.width);
                assert_true(px.y >= 0.0f && px.y <= (float)cam.height);
                /* and inside the clip range along the view axis */
                float depth = -rl_dot(rl_sub(p, f.eye), f.w);
                assert_true(depth >= z_near && depth <= z_far);
            }
        }
}

static void test_clip_range_keeps_near_at_least_far_times_1e_minus_5(void **state)
{
    (void)state;
    /* Eye inside the box: the nearest corner is behind the camera. */
    rl_camera cam = { .eye = { 0, 0, 0 }, .target = { 0, 0, -1 } };
    rl_aabb box = { { -10, -10, -1000 }, { 10, 10, 10 } };
    float z_near, z_far;
    rl_camera_clip_range(&cam, box, &z_near, &z_far);
    assert_true(z_far >= 1000.0f && z_far < 1020.0f);
    assert_true(fabsf(z_near - z_far * 1e-5f) <= 1e-6f * z_far);
}

static rl_camera key_camera(float x, float fov)
{
    rl_camera c = { .eye = { x, 1.0f + x * x * 0.1f, 5 }, .target = { x * 0.5f, 0, 0 },
                    .fov_deg = fov, .width = 100, .height = 50 };
    return c;
}

static void test_path_eval_hits_keys_exactly_at_key_times(void **state)
{
    (void)state;
    rl_camera_key keys[4] = { { 0.0, key_camera(0, 40) }, { 1.0, key_camera(2, 50) },
                              { 1.5, key_camera(3, 60) }, { 4.0, key_camera(-1, 30) } };
    keys[3].camera.width = 999;    /* resolution comes from the first key */
    rl_camera_path *p = NULL;
    assert_int_equal(rl_camera_path_create(keys, 4, &p), RL_OK);
    assert_int_equal(rl_camera_path_key_count(p), 4);
    assert_true(rl_camera_path_duration(p) == 4.0);
    assert_true(rl_camera_path_key(p, 2)->time_s == 1.5);
    assert_null(rl_camera_path_key(p, 4));
    for (int k = 0; k < 4; ++k) {
        rl_camera c = rl_camera_path_eval(p, keys[k].time_s);
        assert_vec3_near(c.eye, keys[k].camera.eye, 0.0f);
        assert_vec3_near(c.target, keys[k].camera.target, 0.0f);
        assert_true(c.fov_deg == keys[k].camera.fov_deg);
        assert_int_equal(c.width, 100);
    }
    /* Clamped outside the time range. */
    rl_camera before = rl_camera_path_eval(p, -3.0), after = rl_camera_path_eval(p, 9.0);
    assert_vec3_near(before.eye, keys[0].camera.eye, 0.0f);
    assert_vec3_near(after.eye, keys[3].camera.eye, 0.0f);
    /* Frames spread from the first to the last key. */
    assert_vec3_near(rl_camera_path_frame(p, 0, 5).eye, keys[0].camera.eye, 0.0f);
    assert_vec3_near(rl_camera_path_frame(p, 4, 5).eye, keys[3].camera.eye, 0.0f);
    assert_vec3_near(rl_camera_path_frame(p, 2, 5).eye, rl_camera_path_eval(p, 2.0).eye, 0.0f);
    assert_vec3_near(rl_camera_path_frame(p, 0, 1).eye, keys[0].camera.eye, 0.0f);
    /* Linear fov between keys. */
    assert_true(fabsf(rl_camera_path_eval(p, 0.5).fov_deg - 45.0f) < 1e-4f);
    rl_camera_path_release(p);
}

static void test_path_eval_is_continuous_and_stays_near_the_keys(void **state)
{
    (void)state;
    rl_camera_key keys[5] = { { 0.0, key_camera(0, 45) }, { 1.0, key_camera(2, 45) },
                              { 2.0, key_camera(2.1f, 45) }, { 2.2, key_camera(6, 45) },
                              { 5.0, key_camera(-3, 45) } };
    rl_camera_path *p = NULL;
    assert_int_equal(rl_camera_path_create(keys, 5, &p), RL_OK);
    const int steps = 20000;
    rl_camera prev = rl_camera_path_eval(p, 0.0);
    float max_jump = 0.0f;
    for (int i = 1; i <= steps; ++i) {
        rl_camera c = rl_camera_path_eval(p, 5.0 * i / steps);
        assert_true(rl_vfinite(c.eye) && rl_vfinite(c.target));
        max_jump = rl_maxf(max_jump, rl_length(rl_sub(c.eye, prev.eye)));
        max_jump = rl_maxf(max_jump, rl_length(rl_sub(c.target, prev.target)));
        prev = c;
    }
    /* Total eye travel is a few tens of units: steps of 1/20000 of the time
     * must move little, also across key times (no jumps at segment joins). */
    assert_true(max_jump < 0.01f);
    rl_camera_path_release(p);
}

static void test_path_create_rejects_bad_keys(void **state)
{
    (void)state;
    rl_camera_path *p = NULL;
    rl_camera_key keys[2] = { { 1.0, key_camera(0, 45) }, { 1.0, key_camera(1, 45) } };
    assert_int_equal(rl_camera_path_create(keys, 2, &p), RL_ERR_INVALID_ARG);
    keys[1].time_s = 0.5;
    assert_int_equal(rl_camera_path_create(keys, 2, &p), RL_ERR_INVALID_ARG);
    keys[1].time_s = 2.0;
    keys[1].camera.fov_deg = 200.0f;
    assert_int_equal(rl_camera_path_create(keys, 2, &p), RL_ERR_INVALID_ARG);
    keys[1].camera.fov_deg = 45.0f;
    keys[0].time_s = NAN;
    assert_int_equal(rl_camera_path_create(keys, 2, &p), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_camera_path_create(keys, 0, &p), RL_ERR_INVALID_ARG);
    assert_null(p);
    keys[0].time_s = 0.0;
    assert_int_equal(rl_camera_path_create(keys, 1, &p), RL_OK);
    assert_vec3_near(rl_camera_path_eval(p, 0.7).eye, keys[0].camera.eye, 0.0f);
    assert_true(rl_camera_path_duration(p) == 0.0);
    rl_camera_path_release(p);
    rl_camera_path_release(NULL);
    rl_clear_error();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_points_on_pixel_rays_project_back_to_the_pixel),
        cmocka_unit_test(test_top_left_pixel_ray_points_up_and_left),
        cmocka_unit_test(test_validate_rejects_degenerate_cameras),
        cmocka_unit_test(test_frame_bounds_sees_all_corners_of_the_box),
        cmocka_unit_test(test_fit_points_is_tight_from_every_orbit),
        cmocka_unit_test(test_equal_sees_every_field),
        cmocka_unit_test(test_clip_range_keeps_near_at_least_far_times_1e_minus_5),
        cmocka_unit_test(test_path_eval_hits_keys_exactly_at_key_times),
        cmocka_unit_test(test_path_eval_is_continuous_and_stays_near_the_keys),
        cmocka_unit_test(test_path_create_rejects_bad_keys),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
