/* test_math.c: matrices, camera transforms, bases, optics and colour
 * conversions in rl_math.h, checked against closed-form answers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>

#include "rl/rl_math.h"
#include "rl/rl_rng.h"

static void assert_near(double a, double b, double eps)
{
    if (!(fabs(a - b) <= eps))
        fail_msg("%.9g != %.9g (eps %g)", a, b, eps);
}

static void assert_vec3_near(rl_vec3 a, rl_vec3 b, double eps)
{
    assert_near(a.x, b.x, eps);
    assert_near(a.y, b.y, eps);
    assert_near(a.z, b.z, eps);
}

static rl_mat4 random_affine(rl_rng *rng)
{
    rl_vec3 axis = rl_v3(rl_rng_float(rng) - 0.5f, rl_rng_float(rng) - 0.5f, rl_rng_float(rng) + 0.1f);
    rl_mat4 r = rl_mat4_rotate(axis, 6.0f * rl_rng_float(rng));
    rl_mat4 s = rl_mat4_scale(rl_v3(0.5f + rl_rng_float(rng), 0.5f + rl_rng_float(rng), 0.5f + rl_rng_float(rng)));
    rl_mat4 t = rl_mat4_translate(rl_v3(10 * rl_rng_float(rng), -3, 2 * rl_rng_float(rng)));
    rl_mat4 rs = rl_mat4_mul(&r, &s);
    return rl_mat4_mul(&t, &rs);
}

static void test_matrix_inverse_round_trips_to_identity(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 7, 1);
    for (int n = 0; n < 50; ++n) {
        rl_mat4 a = random_affine(&rng);
        /* A projective last row too, so the general path is exercised. */
        a.m[3][0] = 0.1f * rl_rng_float(&rng);
        a.m[3][2] = -0.3f;
        rl_mat4 inv;
        assert_true(rl_mat4_invert(&a, &inv));
        rl_mat4 p = rl_mat4_mul(&a, &inv), q = rl_mat4_mul(&inv, &a);
        for (int i = 0; i < 4; ++i)
            for (int j = 0; j < 4; ++j) {
                assert_near(p.m[i][j], i == j, 1e-4);
                assert_near(q.m[i][j], i == j, 1e-4);
            }
    }
}

static void test_singular_matrix_is_not_inverted(void **state)
{
    (void)state;
    rl_mat4 a = rl_mat4_scale(rl_v3(1, 0, 1)), inv;
    inv.m[0][0] = 42;
    assert_false(rl_mat4_invert(&a, &inv));
    assert_near(inv.m[0][0], 1, 0); /* identity on failure, as documented */
}

static void test_rotation_is_right_handed(void **state)
{
    (void)state;
    /* +90 degrees about z takes x to y; about x takes y to z. */
    rl_mat4 rz = rl_mat4_rotate(rl_v3(0, 0, 1), RL_PI / 2);
    assert_vec3_near(rl_mat4_mul_dir(&rz, rl_v3(1, 0, 0)), rl_v3(0, 1, 0), 1e-6);
    rl_mat4 rx = rl_mat4_rotate(rl_v3(2, 0, 0), RL_PI / 2);
    assert_vec3_near(rl_mat4_mul_dir(&rx, rl_v3(0, 1, 0)), rl_v3(0, 0, 1), 1e-6);
    rl_mat4 t = rl_mat4_transpose(&rz), p = rl_mat4_mul(&rz, &t);
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            assert_near(p.m[i][j], i == j, 1e-6);
}

static void test_look_at_maps_target_onto_negative_z(void **state)
{
    (void)state;
    rl_vec3 eye = rl_v3(1, 2, 3), target = rl_v3(1, 2, -7);
    rl_mat4 v = rl_mat4_look_at(eye, target, rl_v3(0, 1, 0));
    assert_vec3_near(rl_mat4_mul_point(&v, eye), rl_v3(0, 0, 0), 1e-6);
    assert_vec3_near(rl_mat4_mul_point(&v, target), rl_v3(0, 0, -10), 1e-5);
    /* World up stays up, world +x stays to the right for this camera. */
    assert_vec3_near(rl_mat4_mul_dir(&v, rl_v3(0, 1, 0)), rl_v3(0, 1, 0), 1e-6);
    assert_vec3_near(rl_mat4_mul_dir(&v, rl_v3(1, 0, 0)), rl_v3(1, 0, 0), 1e-6);
    /* Looking along +x from the origin: +x becomes -z, +z becomes +x. */
    rl_mat4 w = rl_mat4_look_at(rl_v3(0, 0, 0), rl_v3(5, 0, 0), rl_v3(0, 1, 0));
    assert_vec3_near(rl_mat4_mul_dir(&w, rl_v3(1, 0, 0)), rl_v3(0, 0, -1), 1e-6);
    assert_vec3_near(rl_mat4_mul_dir(&w, rl_v3(0, 0, 1)), rl_v3(1, 0, 0), 1e-6);
}

static rl_vec3 project(const rl_mat4 *p, rl_vec3 eye_pt, float *w)
{
    rl_vec4 c = rl_mat4_mul_vec4(p, rl_v4_from3(eye_pt, 1));
    *w = c.w;
    return rl_v3(c.x / c.w, c.y / c.w, c.z / c.w);
}

static void test_perspective_maps_frustum_corners_to_ndc(void **state)
{
    (void)state;
    float n = 0.5f, f = 20.0f, aspect = 2.0f, fov = rl_radians(60.0f);
    rl_mat4 p = rl_mat4_perspective(fov, aspect, n, f);
    float w, th = tanf(fov / 2);
    rl_vec3 a = project(&p, rl_v3(0, 0, -n), &w);
    assert_near(w, n, 1e-6);                       /* clip w = -z_eye */
    assert_vec3_near(a, rl_v3(0, 0, -1), 1e-5);
    rl_vec3 b = project(&p, rl_v3(0, 0, -f), &w);
    assert_near(b.z, 1, 1e-4);
    /* Top-right corner of the far plane. */
    rl_vec3 c = project(&p, rl_v3(f * th * aspect, f * th, -f), &w);
    assert_vec3_near(c, rl_v3(1, 1, 1), 1e-4);
    rl_vec3 d = project(&p, rl_v3(-n * th * aspect, -n * th, -n), &w);
    assert_vec3_near(d, rl_v3(-1, -1, -1), 1e-4);
}

static void test_orthographic_maps_the_box_to_ndc_with_w_one(void **state)
{
    (void)state;
    rl_mat4 p = rl_mat4_orthographic(2.0f, 0.5f, 1.0f, 9.0f);
    float w;
    rl_vec3 a = project(&p, rl_v3(2.0f, 0.5f, -1.0f), &w);
    assert_near(w, 1, 0);                          /* affine: clip w = 1 */
    assert_vec3_near(a, rl_v3(1, 1, -1), 1e-6);
    rl_vec3 b = project(&p, rl_v3(-2.0f, -0.5f, -9.0f), &w);
    assert_near(w, 1, 0);
    assert_vec3_near(b, rl_v3(-1, -1, 1), 1e-6);
    rl_vec3 c = project(&p, rl_v3(1.0f, 0.25f, -5.0f), &w);
    assert_vec3_near(c, rl_v3(0.5f, 0.5f, 0), 1e-6);
}

static void test_normals_transform_with_inverse_transpose(void **state)
{
    (void)state;
    /* A plane x = y is squashed in y; its normal must stay perpendicular. */
    rl_mat4 m = rl_mat4_scale(rl_v3(1, 4, 1)), inv, it;
    assert_true(rl_mat4_invert(&m, &inv));
    it = rl_mat4_transpose(&inv);
    rl_vec3 tangent = rl_mat4_mul_dir(&m, rl_v3(1, 1, 0));
    rl_vec3 n = rl_mat4_mul_normal(&it, rl_normalize(rl_v3(1, -1, 0)));
    assert_near(rl_dot(n, tangent), 0, 1e-6);
    assert_near(rl_length(n), 1, 1e-6);
}

static void test_aabb_transform_matches_transformed_corners(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 3, 9);
    rl_aabb b = { { -1, 2, 0.5f }, { 3, 2.5f, 4 } };
    for (int n = 0; n < 20; ++n) {
        rl_mat4 m = random_affine(&rng);
        rl_aabb ref = rl_aabb_empty();
        for (int c = 0; c < 8; ++c) {
            rl_vec3 p = rl_v3(c & 1 ? b.max.x : b.min.x, c & 2 ? b.max.y : b.min.y, c & 4 ? b.max.z : b.min.z);
            ref = rl_aabb_grow(ref, rl_mat4_mul_point(&m, p));
        }
        rl_aabb got = rl_mat4_mul_aabb(&m, b);
        assert_vec3_near(got.min, ref.min, 1e-4);
        assert_vec3_near(got.max, ref.max, 1e-4);
    }
    assert_true(rl_aabb_is_empty(rl_mat4_mul_aabb(&(rl_mat4){ { { 1 } } }, rl_aabb_empty())));
}

static void test_onb_is_orthonormal_and_right_handed(void **state)
{
    (void)state;
    rl_rng rng;
    rl_rng_seed(&rng, 11, 0);
    rl_vec3 ns[] = { { 0, 0, 1 }, { 0, 0, -1 }, { 1, 0, 0 }, { 0, -1, 0 } };
    for (int k = 0; k < 104; ++k) {
        rl_vec3 n = k < 4 ? ns[k]
                          : rl_normalize(rl_v3(rl_rng_float(&rng) - 0.5f, rl_rng_float(&rng) - 0.5f,
                                               rl_rng_float(&rng) - 0.5f));
        rl_onb o = rl_onb_from_normal(n);
        assert_near(rl_length(o.t), 1, 1e-5);
        assert_near(rl_length(o.b), 1, 1e-5);
        assert_near(rl_dot(o.t, o.b), 0, 1e-5);
        assert_near(rl_dot(o.t, n), 0, 1e-5);
        assert_near(rl_dot(o.b, n), 0, 1e-5);
        assert_vec3_near(rl_cross(o.t, o.b), n, 1e-5);
        rl_vec3 v = rl_v3(0.3f, -0.2f, 0.9f);
        assert_vec3_near(rl_onb_to_local(&o, rl_onb_to_world(&o, v)), v, 1e-5);
    }
}

static void test_reflect_and_refract_follow_snell(void **state)
{
    (void)state;
    rl_vec3 n = rl_v3(0, 1, 0);
    rl_vec3 d = rl_normalize(rl_v3(1, -1, 0));
    assert_vec3_near(rl_reflect(d, n), rl_normalize(rl_v3(1, 1, 0)), 1e-6);
    /* Air to glass at 45 degrees: sin(t) = sin(i) / 1.5. */
    rl_vec3 t;
    assert_true(rl_refract(d, n, 1.0f / 1.5f, &t));
    assert_near(rl_length(t), 1, 1e-5);
    assert_near(t.x, sinf(RL_PI / 4) / 1.5f, 1e-5);
    assert_true(t.y < 0);
    /* Glass to air beyond the critical angle (41.8 deg): total internal reflection. */
    rl_vec3 steep = rl_normalize(rl_v3(1, -0.5f, 0)); /* 63 deg from the normal */
    t = rl_v3(7, 7, 7);
    assert_false(rl_refract(steep, n, 1.5f, &t));
    assert_vec3_near(t, rl_v3(7, 7, 7), 0); /* untouched */
    /* Head-on passes straight through. */
    assert_true(rl_refract(rl_v3(0, -1, 0), n, 1.5f, &t));
    assert_vec3_near(t, rl_v3(0, -1, 0), 1e-6);
}

static void test_hsv_round_trips_and_knows_primaries(void **state)
{
    (void)state;
    assert_vec3_near(rl_rgb_to_hsv(rl_v3(1, 0, 0)), rl_v3(0, 1, 1), 1e-6);
    assert_vec3_near(rl_rgb_to_hsv(rl_v3(0, 1, 0)), rl_v3(120, 1, 1), 1e-4);
    assert_vec3_near(rl_rgb_to_hsv(rl_v3(0, 0, 0.5f)), rl_v3(240, 1, 0.5f), 1e-4);
    assert_vec3_near(rl_rgb_to_hsv(rl_v3(1, 0, 0.5f)), rl_v3(330, 1, 1), 1e-4);
    assert_vec3_near(rl_rgb_to_hsv(rl_v3(0.4f, 0.4f, 0.4f)), rl_v3(0, 0, 0.4f), 1e-6);
    rl_rng rng;
    rl_rng_seed(&rng, 5, 5);
    for (int k = 0; k < 1000; ++k) {
        rl_vec3 c = rl_v3(rl_rng_float(&rng), rl_rng_float(&rng), rl_rng_float(&rng));
        rl_vec3 hsv = rl_rgb_to_hsv(c);
        assert_true(hsv.x >= 0 && hsv.x < 360);
        assert_vec3_near(rl_hsv_to_rgb(hsv), c, 1e-5);
    }
}

static void test_srgb_curve_round_trips_and_hits_reference_points(void **state)
{
    (void)state;
    assert_near(rl_linear_to_srgb(0), 0, 0);
    assert_near(rl_linear_to_srgb(1), 1, 1e-6);
    assert_near(rl_linear_to_srgb(0.18f), 0.46135613, 1e-5); /* middle grey */
    assert_near(rl_srgb_to_linear(0.5f), 0.21404114, 1e-6);
    assert_near(rl_srgb_to_linear(0.04045f), 0.04045 / 12.92, 1e-7); /* linear segment */
    for (int k = 0; k <= 1000; ++k) {
        float x = (float)k / 1000.0f;
        assert_near(rl_srgb_to_linear(rl_linear_to_srgb(x)), x, 1e-5);
    }
    assert_near(rl_luminance(rl_v3(1, 1, 1)), 1, 1e-6);
    assert_near(rl_luminance(rl_v3(0, 1, 0)), 0.7152, 1e-6);
}

static void test_aabb_slab_test_hits_misses_and_clips(void **state)
{
    (void)state;
    rl_aabb b = { { -1, -1, -1 }, { 1, 1, 1 } };
    rl_ray r = { { -5, 0, 0 }, 0, { 1, 0, 0 }, INFINITY };
    float t0 = -1, t1 = -1;
    assert_true(rl_aabb_intersect_ray(b, &r, &t0, &t1));
    assert_near(t0, 4, 1e-6);
    assert_near(t1, 6, 1e-6);
    r.t_max = 3.5f; /* segment ends before the box */
    assert_false(rl_aabb_intersect_ray(b, &r, &t0, &t1));
    rl_ray miss = { { -5, 2, 0 }, 0, { 1, 0, 0 }, INFINITY };
    assert_false(rl_aabb_intersect_ray(b, &miss, &t0, &t1));
    /* Origin inside: t0 stays t_min. */
    rl_ray inside = { { 0, 0, 0 }, 0, { 0, 0, -2 }, INFINITY };
    assert_true(rl_aabb_intersect_ray(b, &inside, &t0, &t1));
    assert_near(t0, 0, 0);
    assert_near(t1, 0.5, 1e-6);
    /* Diagonal through a corner region. */
    rl_ray diag = { { -2, -2, -2 }, 0, { 1, 1, 1 }, INFINITY };
    assert_true(rl_aabb_intersect_ray(b, &diag, &t0, &t1));
    assert_near(t0, 1, 1e-6);
    assert_near(t1, 3, 1e-6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_matrix_inverse_round_trips_to_identity),
        cmocka_unit_test(test_singular_matrix_is_not_inverted),
        cmocka_unit_test(test_rotation_is_right_handed),
        cmocka_unit_test(test_look_at_maps_target_onto_negative_z),
        cmocka_unit_test(test_perspective_maps_frustum_corners_to_ndc),
        cmocka_unit_test(test_orthographic_maps_the_box_to_ndc_with_w_one),
        cmocka_unit_test(test_normals_transform_with_inverse_transpose),
        cmocka_unit_test(test_aabb_transform_matches_transformed_corners),
        cmocka_unit_test(test_onb_is_orthonormal_and_right_handed),
        cmocka_unit_test(test_reflect_and_refract_follow_snell),
        cmocka_unit_test(test_hsv_round_trips_and_knows_primaries),
        cmocka_unit_test(test_srgb_curve_round_trips_and_hits_reference_points),
        cmocka_unit_test(test_aabb_slab_test_hits_misses_and_clips),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
