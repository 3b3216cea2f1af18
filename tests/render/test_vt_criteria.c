/* test_vt_criteria.c: the subdivision criteria of Vertex Tracing
 * (vt_criteria.c; Ullmann 2003, Sec. 3.3.1): sRGB display values against
 * the closed form, HSV of the primaries and a mixed colour, and each
 * criterion firing just above its threshold and not just below it, with the
 * hue wrapping round the circle and ignored for greys; the pieces of
 * Sec. 6.1.1 (vt_correct.c): the interval and affine enclosures of the local
 * Phong term against sampled values, and the derivative test (eq. 6.3)
 * against the extremum test (eq. 6.4-6.5); and the shaft of [HW91] that
 * Sec. 6.1.2's shaft culling builds; the readings of the ray tree the
 * ray-tree criterion compares (vt_tree_hash, options tree_shadow and
 * tree_depth). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include <cmocka.h>

#include "render/vt_run.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

/* Linear value whose display value is d (inverse sRGB transfer). */
static float linear_of(float d)
{
    return d <= 0.04045f ? d / 12.92f : powf((d + 0.055f) / 1.055f, 2.4f);
}

static vt_vertex_sample sample_display(float r, float g, float b)
{
    vt_vertex_sample v;
    memset(&v, 0, sizeof v);
    v.flat = rl_v3(linear_of(r), linear_of(g), linear_of(b));
    return v;
}

static void test_display_is_clamped_srgb(void **state)
{
    (void)state;
    assert_float_equal(vt_display(0.0f), 0.0f, 0.0f);
    assert_float_equal(vt_display(-3.0f), 0.0f, 0.0f);
    assert_float_equal(vt_display(NAN), 0.0f, 0.0f);
    assert_float_equal(vt_display(1.0f), 1.0f, 1e-6f);
    assert_float_equal(vt_display(7.5f), 1.0f, 0.0f);
    assert_float_equal(vt_display(INFINITY), 1.0f, 0.0f);
    /* the linear toe and the power segment meet at 0.0031308 */
    assert_float_equal(vt_display(0.002f), 12.92f * 0.002f, 1e-7f);
    assert_float_equal(vt_display(0.0031308f), 0.04045f, 1e-5f);
    assert_float_equal(vt_display(0.5f), 0.735357f, 1e-5f);
    assert_float_equal(vt_display(0.18f), 0.461356f, 1e-5f);
    for (int i = 0; i <= 100; ++i) {
        float d = (float)i / 100.0f;
        assert_float_equal(vt_display(linear_of(d)), d, 2e-6f);
    }
}

static void check_hsv(rl_vec3 rgb, float h, float s, float v)
{
    float hh, ss, vv;
    vt_rgb_to_hsv(rgb, &hh, &ss, &vv);
    assert_float_equal(hh, h, 1e-6f);
    assert_float_equal(ss, s, 1e-6f);
    assert_float_equal(vv, v, 1e-6f);
}

static void test_hsv_of_primaries_and_greys(void **state)
{
    (void)state;
    check_hsv(rl_v3(1, 0, 0), 0.0f, 1.0f, 1.0f);
    check_hsv(rl_v3(1, 1, 0), 1.0f / 6.0f, 1.0f, 1.0f);
    check_hsv(rl_v3(0, 0.5f, 0), 1.0f / 3.0f, 1.0f, 0.5f);
    check_hsv(rl_v3(0, 1, 1), 0.5f, 1.0f, 1.0f);
    check_hsv(rl_v3(0, 0, 1), 2.0f / 3.0f, 1.0f, 1.0f);
    check_hsv(rl_v3(1, 0, 1), 5.0f / 6.0f, 1.0f, 1.0f);
    check_hsv(rl_v3(1, 0, 0.3f), 0.95f, 1.0f, 1.0f);
    check_hsv(rl_v3(0.5f, 0.25f, 0.0f), 1.0f / 12.0f, 1.0f, 0.5f);
    check_hsv(rl_v3(0.8f, 0.4f, 0.4f), 0.0f, 0.5f, 0.8f);
    check_hsv(rl_v3(0.3f, 0.3f, 0.3f), 0.0f, 0.0f, 0.3f);
    check_hsv(rl_v3(0, 0, 0), 0.0f, 0.0f, 0.0f);
    /* h stays in [0, 1) just below red */
    float h, s, v;
    vt_rgb_to_hsv(rl_v3(1.0f, 0.0f, 1e-7f), &h, &s, &v);
    assert_true(h >= 0.0f && h < 1.0f);
}

static void test_parse_accepts_the_documented_names_only(void **state)
{
    (void)state;
    static const struct { const char *text; unsigned bits; } ok[] = {
        { "rgb", VT_CRIT_RGB },
        { "hsv", VT_CRIT_HSV },
        { "tree", VT_CRIT_TREE },
        { "tree+rgb", VT_CRIT_TREE | VT_CRIT_RGB },
        { "rgb+tree", VT_CRIT_TREE | VT_CRIT_RGB },
        { "tree+hsv", VT_CRIT_TREE | VT_CRIT_HSV },
        { "hsv+tree", VT_CRIT_TREE | VT_CRIT_HSV },
        { "rgb+hsv", VT_CRIT_RGB | VT_CRIT_HSV },
    };
    for (size_t i = 0; i < sizeof ok / sizeof ok[0]; ++i) {
        unsigned bits = 0;
        assert_true(vt_criteria_parse(ok[i].text, &bits));
        assert_int_equal(bits, ok[i].bits);
    }
    static const char *const bad[] = { "", "RGB", "rgb+", "+rgb", "tree+tree", "rgb hsv",
                                       "rgb+hsv+tree", "l1", "rgbx" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        unsigned bits = 12345;
        assert_false(vt_criteria_parse(bad[i], &bits));
        assert_int_equal(bits, 12345);
    }
    unsigned bits;
    assert_false(vt_criteria_parse(NULL, &bits));
}

static void test_rgb_fires_on_l1_of_display_values(void **state)
{
    (void)state;
    vt_vertex_sample a = sample_display(0.5f, 0.5f, 0.5f);
    vt_vertex_sample b = sample_display(0.6f, 0.45f, 0.5f);      /* L1 = 0.15 */
    vt_criteria c = { .bits = VT_CRIT_RGB, .eps_rgb = 0.149f };
    assert_int_equal(vt_criteria_test(&c, &a, &b), VT_CRIT_RGB);
    assert_int_equal(vt_criteria_test(&c, &b, &a), VT_CRIT_RGB);
    c.eps_rgb = 0.151f;
    assert_int_equal(vt_criteria_test(&c, &a, &b), 0);
    /* overexposure clamps: 2 and 50 are both white */
    vt_vertex_sample w1 = sample_display(1, 1, 1), w2 = sample_display(1, 1, 1);
    w1.flat = rl_v3s(2.0f);
    w2.flat = rl_v3s(50.0f);
    c.eps_rgb = 0.0f;
    assert_int_equal(vt_criteria_test(&c, &w1, &w2), 0);
    /* only the flat (untextured) radiance counts, Sec. 3.5.3: the terms
     * the reconstruction modulates with textures change nothing */
    vt_vertex_sample t1 = sample_display(0.2f, 0.2f, 0.2f), t2 = t1;
    t1.diffuse = rl_v3(0.1f, 0.1f, 0.1f);
    t2.diffuse = rl_v3(0.9f, 0.0f, 0.4f);
    t1.deferred[0] = VT_NONE;
    t2.deferred[0] = 3;
    assert_int_equal(vt_criteria_test(&c, &t1, &t2), 0);
}

static void test_hsv_hue_wraps_and_is_ignored_for_greys(void **state)
{
    (void)state;
    /* hues 0.95 and 0.05: 0.1 apart across red, same S and V */
    vt_vertex_sample a = sample_display(1.0f, 0.0f, 0.3f), b = sample_display(1.0f, 0.3f, 0.0f);
    vt_criteria c = { .bits = VT_CRIT_HSV, .eps_h = 0.11f, .eps_s = 0.01f, .eps_v = 0.01f };
    assert_int_equal(vt_criteria_test(&c, &a, &b), 0);
    c.eps_h = 0.09f;
    assert_int_equal(vt_criteria_test(&c, &a, &b), VT_CRIT_HSV);

    /* nearly grey: hues far apart but saturation below 1e-3 */
    vt_vertex_sample g1 = sample_display(0.5f, 0.5f, 0.5f), g2 = sample_display(0.5f, 0.5f, 0.5f);
    g1.flat.x *= 1.0004f;                 /* reddish */
    g2.flat.z *= 1.0004f;                 /* bluish */
    float h1, s1, v1, h2, s2, v2;
    vt_rgb_to_hsv(rl_v3(vt_display(g1.flat.x), vt_display(g1.flat.y), vt_display(g1.flat.z)),
                  &h1, &s1, &v1);
    vt_rgb_to_hsv(rl_v3(vt_display(g2.flat.x), vt_display(g2.flat.y), vt_display(g2.flat.z)),
                  &h2, &s2, &v2);
    assert_true(s1 > 0.0f && s1 < 1e-3f);
    assert_true(fabsf(h1 - h2) > 0.3f);
    c.eps_h = 0.01f;
    assert_int_equal(vt_criteria_test(&c, &g1, &g2), 0);

    /* saturation and value on their own */
    vt_vertex_sample p = sample_display(0.8f, 0.4f, 0.4f), q = sample_display(0.8f, 0.6f, 0.6f);
    c = (vt_criteria){ .bits = VT_CRIT_HSV, .eps_h = 0.5f, .eps_s = 0.2f, .eps_v = 1.0f };
    assert_int_equal(vt_criteria_test(&c, &p, &q), VT_CRIT_HSV);   /* dS = 0.25 */
    c.eps_s = 0.3f;
    assert_int_equal(vt_criteria_test(&c, &p, &q), 0);
    vt_vertex_sample r = sample_display(0.6f, 0.3f, 0.3f);                /* dV = 0.2 */
    c = (vt_criteria){ .bits = VT_CRIT_HSV, .eps_h = 0.5f, .eps_s = 1.0f, .eps_v = 0.19f };
    assert_int_equal(vt_criteria_test(&c, &p, &r), VT_CRIT_HSV);
    c.eps_v = 0.21f;
    assert_int_equal(vt_criteria_test(&c, &p, &r), 0);
}

static void test_tree_and_combinations_report_what_fired(void **state)
{
    (void)state;
    vt_vertex_sample a = sample_display(0.5f, 0.5f, 0.5f), b = sample_display(0.9f, 0.5f, 0.5f);
    vt_sample_set_tree(&a, 0x1111);
    vt_sample_set_tree(&b, 0x1111);
    vt_criteria c = { .bits = VT_CRIT_TREE, .eps_rgb = 0.1f, .eps_h = 0.5f, .eps_s = 1.0f,
                      .eps_v = 1.0f };
    assert_int_equal(vt_criteria_test(&c, &a, &b), 0);        /* colours differ, trees don't */
    vt_sample_set_tree(&b, 0x2222);
    assert_int_equal(vt_criteria_test(&c, &a, &b), VT_CRIT_TREE);
    c.bits = VT_CRIT_TREE | VT_CRIT_RGB;
    assert_int_equal(vt_criteria_test(&c, &a, &b), VT_CRIT_TREE | VT_CRIT_RGB);
    c.bits = VT_CRIT_RGB | VT_CRIT_HSV;
    assert_int_equal(vt_criteria_test(&c, &a, &b), VT_CRIT_RGB);
    c.eps_v = 0.1f;
    assert_int_equal(vt_criteria_test(&c, &a, &b), VT_CRIT_RGB | VT_CRIT_HSV);
    c.bits = 0;
    assert_int_equal(vt_criteria_test(&c, &a, &b), 0);
}

static rl_aabb box_around(rl_vec3 p, float h)
{
    return (rl_aabb){ rl_v3(p.x - h, p.y - h, p.z - h), rl_v3(p.x + h, p.y + h, p.z + h) };
}

/* Sec. 6.1.2, [HW91]: the shaft of two boxes holds every point between
 * them (no occluder is ever culled), and leaves out what lies in their
 * joint extent but off the hull: past the slanted planes in the (x, y) and
 * the (x, z) projection. */
static void test_shaft_is_the_hull_of_two_boxes(void **state)
{
    (void)state;
    vt_shaft s;
    rl_aabb unit = { rl_v3(0.0f, 0.0f, 0.0f), rl_v3(1.0f, 1.0f, 1.0f) };
    rl_vec3 light = rl_v3(3.0f, 3.0f, 0.5f);
    vt_shaft_build(&s, unit, (rl_aabb){ light, light });
    assert_true(s.num_planes > 0 && s.num_planes <= 12);
    assert_true(vt_shaft_meets_box(&s, box_around(rl_v3(1.5f, 1.5f, 0.5f), 0.01f)));
    assert_true(vt_shaft_meets_box(&s, box_around(rl_v3(2.9f, 2.9f, 0.5f), 0.01f)));
    assert_false(vt_shaft_meets_box(&s, box_around(rl_v3(2.9f, 0.1f, 0.5f), 0.01f)));   /* (x, y) */
    assert_false(vt_shaft_meets_box(&s, box_around(rl_v3(2.8f, 2.8f, 0.95f), 0.01f)));  /* (x, z) */
    assert_false(vt_shaft_meets_box(&s, box_around(rl_v3(5.0f, 5.0f, 0.5f), 0.01f)));   /* past the extent */

    /* Random pairs of boxes: a point between a point of each is inside. */
    uint32_t seed = 12345u;
    for (int trial = 0; trial < 200; ++trial) {
        float v[12];
        for (int k = 0; k < 12; ++k) {
            seed = seed * 1664525u + 1013904223u;
            v[k] = (float)(seed >> 8) / 16777216.0f * 10.0f - 5.0f;
        }
        rl_aabb a = { rl_vmin(rl_v3(v[0], v[1], v[2]), rl_v3(v[3], v[4], v[5])),
                      rl_vmax(rl_v3(v[0], v[1], v[2]), rl_v3(v[3], v[4], v[5])) };
        rl_aabb b = { rl_vmin(rl_v3(v[6], v[7], v[8]), rl_v3(v[9], v[10], v[11])),
                      rl_vmax(rl_v3(v[6], v[7], v[8]), rl_v3(v[9], v[10], v[11])) };
        vt_shaft_build(&s, a, b);
        for (int k = 0; k < 20; ++k) {
            float u[7];
            for (int c = 0; c < 7; ++c) {
                seed = seed * 1664525u + 1013904223u;
                u[c] = (float)(seed >> 8) / 16777216.0f;
            }
            rl_vec3 pa = rl_v3(a.min.x + u[0] * (a.max.x - a.min.x), a.min.y + u[1] * (a.max.y - a.min.y),
                               a.min.z + u[2] * (a.max.z - a.min.z));
            rl_vec3 pb = rl_v3(b.min.x + u[3] * (b.max.x - b.min.x), b.min.y + u[4] * (b.max.y - b.min.y),
                               b.min.z + u[5] * (b.max.z - b.min.z));
            rl_vec3 p = rl_vlerp(pa, pb, u[6]);
            assert_true(vt_shaft_meets_box(&s, (rl_aabb){ p, p }));
        }
    }
}

/* ------------------------------------------------------ Sec. 6.1.1 -- */

static float urand(rl_rng *g, float lo, float hi)
{
    return lo + (hi - lo) * rl_rng_float(g);
}

static rl_vec3 tilted_up(rl_rng *g, float spread)
{
    return rl_normalize(rl_v3(urand(g, -spread, spread), 1.0f, urand(g, -spread, spread)));
}

/* The term as the tracer adds it (trace_shade.c), written out on its own:
 * E (k_d n.l + k_s max(0, r.a)^m) where n.l > 0. */
static float phong_ref(const rl_light *L, rl_vec3 p, rl_vec3 n, rl_vec3 eye, float kd, float ks, float m)
{
    rl_vec3 l;
    float E = L->intensity * rl_vmax_comp(L->color);
    if (L->type == RL_LIGHT_DIRECTIONAL) {
        l = rl_normalize(rl_neg(L->direction));
    } else {
        rl_vec3 d = rl_sub(L->position, p);
        E /= rl_dot(d, d);
        l = rl_normalize(d);
    }
    rl_vec3 a = rl_normalize(rl_sub(eye, p));
    float nl = rl_dot(n, l);
    if (nl <= 0.0f)
        return 0.0f;
    float ra = rl_dot(rl_sub(rl_scale(n, 2.0f * nl), l), a);
    return E * (kd * nl + (ra > 0.0f ? ks * powf(ra, m) : 0.0f));
}

/* A random edge over the floor y = 0 (normals within ~30 degrees of up),
 * seen from (0, 4, 3), lit by a random point or directional light, with a
 * random Phong material; lengths from 1 mm to 2 m. */
static void random_edge(rl_rng *g, rl_light *L, vt_edge_end e[2], rl_vec3 eye)
{
    rl_material mat = rl_material_default();
    float kd = urand(g, 0.0f, 1.0f), ks = urand(g, 0.0f, 1.0f);
    static const float exps[] = { 1.0f, 4.0f, 20.0f, 80.0f, 200.0f };
    mat.diffuse = rl_v3(kd, kd, kd);
    mat.specular = rl_v3(ks, ks, ks);
    mat.shininess = exps[rl_rng_bounded(g, 5)];
    memset(L, 0, sizeof *L);
    L->color = rl_v3(1.0f, 1.0f, 1.0f);
    if (rl_rng_bounded(g, 2)) {
        L->type = RL_LIGHT_POINT;
        L->position = rl_v3(urand(g, -2.0f, 2.0f), urand(g, 0.5f, 3.0f), urand(g, -2.0f, 2.0f));
        L->intensity = 4.0f;
    } else {
        L->type = RL_LIGHT_DIRECTIONAL;
        L->direction = rl_neg(tilted_up(g, 1.0f));
        L->intensity = 1.0f;
    }
    rl_vec3 p1 = rl_v3(urand(g, -2.0f, 2.0f), 0.0f, urand(g, -2.0f, 2.0f));
    float len = powf(10.0f, urand(g, -3.0f, 0.3f)), phi = urand(g, 0.0f, 6.2831853f);
    rl_vec3 p2 = rl_add(p1, rl_v3(len * cosf(phi), 0.0f, len * sinf(phi)));
    float spread = rl_rng_bounded(g, 2) ? 0.0f : 0.6f;
    e[0] = vt_edge_end_of(p1, tilted_up(g, spread), eye, &mat);
    e[1] = vt_edge_end_of(p2, tilted_up(g, spread), eye, &mat);
}

/* Sec. 6.1.1, Fig. 6.4, [CS93]: along random edges, every sampled value of
 * the local term (checked against the term written out here) lies in both
 * enclosures, both bounds eps_IA hold the largest error of the linear
 * interpolant, and the affine enclosure and bound are no wider than the
 * interval ones, the bound under half of it on most edges: it shrinks with
 * the square of the edge, the interval's linearly. */
static void test_affine_encloses_the_term_and_is_tighter_than_intervals(void **state)
{
    (void)state;
    const rl_vec3 eye = rl_v3(0.0f, 4.0f, 3.0f);
    rl_rng g;
    rl_rng_seed(&g, 2003u, 61u);
    int tighter = 0, n_lit = 0;
    double width_ratio_sum = 0.0, eps_ratio_sum = 0.0;
    for (int trial = 0; trial < 4000; ++trial) {
        rl_light L;
        vt_edge_end e[2];
        random_edge(&g, &L, e, eye);
        vt_term_bound ia, af;
        vt_term_bound_of(VT_NONLINEAR_INTERVAL, &L, eye, &e[0], &e[1], &ia);
        vt_term_bound_of(VT_NONLINEAR_AFFINE, &L, eye, &e[0], &e[1], &af);
        float scale = 1e-4f * (1.0f + ia.hi);          /* float rounding of the samples */
        float worst_af = 0.0f, worst_ia = 0.0f;
        for (int k = 0; k <= 64; ++k) {
            float t = (float)k / 64.0f;
            float f = vt_term_at(&L, eye, &e[0], &e[1], t);
            rl_vec3 p = rl_vlerp(e[0].p, e[1].p, t), n = rl_normalize(rl_vlerp(e[0].n, e[1].n, t));
            float ref = phong_ref(&L, p, n, eye, e[0].kd, e[0].ks, rl_maxf(e[0].m, 1e-3f));
            assert_float_equal(f, ref, 1e-4f * (1.0f + fabsf(ref)));
            assert_true(f >= ia.lo - scale && f <= ia.hi + scale);
            assert_true(f >= af.lo - scale && f <= af.hi + scale);
            /* the interpolant f' of the ends' values */
            worst_af = rl_maxf(worst_af, fabsf(f - (af.f1 + t * (af.f2 - af.f1))));
            worst_ia = rl_maxf(worst_ia, fabsf(f - (ia.f1 + t * (ia.f2 - ia.f1))));
        }
        assert_true(worst_af <= af.eps + scale);
        assert_true(worst_ia <= ia.eps + scale);
        /* no wider, up to rounding */
        assert_true(af.lo >= ia.lo && af.hi <= ia.hi);
        assert_true(af.eps <= ia.eps);
        if (ia.eps > 1e-6f && ia.eps < INFINITY) {
            n_lit++;
            tighter += af.eps < 0.5f * ia.eps;
            width_ratio_sum += (af.hi - af.lo) / (ia.hi - ia.lo);
            eps_ratio_sum += af.eps / ia.eps;
        }
    }
    print_message("affine vs interval on %d lit random edges: bound under half on %d, mean width ratio %.3f, "
                  "mean bound ratio %.3f\n", n_lit, tighter, width_ratio_sum / n_lit, eps_ratio_sum / n_lit);
    assert_true(n_lit > 1000);
    assert_true(tighter > n_lit / 2);

    /* The error bound's order: halving a short edge across a highlight
     * quarters the affine bound, only halves the interval one. */
    rl_material shiny = rl_material_default();
    shiny.diffuse = rl_v3(0.3f, 0.3f, 0.3f);
    shiny.specular = rl_v3(1.0f, 1.0f, 1.0f);
    shiny.shininess = 20.0f;
    rl_light sun = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(1, 1, 1), .intensity = 1.0f,
                     .direction = rl_v3(0.3f, -1.0f, 0.2f) };
    rl_vec3 up = rl_v3(0.0f, 1.0f, 0.0f), c = rl_v3(0.2f, 0.0f, 0.1f), dir = rl_v3(0.6f, 0.0f, 0.8f);
    float prev_ia = 0.0f, prev_af = 0.0f;
    for (int k = 0; k < 4; ++k) {
        float h = 0.02f / (float)(1 << k);
        vt_edge_end e1 = vt_edge_end_of(rl_madd(c, dir, -h), up, eye, &shiny);
        vt_edge_end e2 = vt_edge_end_of(rl_madd(c, dir, h), up, eye, &shiny);
        vt_term_bound ia, af;
        vt_term_bound_of(VT_NONLINEAR_INTERVAL, &sun, eye, &e1, &e2, &ia);
        vt_term_bound_of(VT_NONLINEAR_AFFINE, &sun, eye, &e1, &e2, &af);
        print_message("half-length %.5f: eps interval %.3g, affine %.3g\n", h, ia.eps, af.eps);
        if (k > 0) {
            assert_true(ia.eps > 0.4f * prev_ia);
            assert_true(af.eps < 0.3f * prev_af);
        }
        prev_ia = ia.eps;
        prev_af = af.eps;
    }
}

/* Ends on the floor y = 0 with the normal up, lit by light L, seen from
 * eye; material k_d, k_s, m. */
static int tests_agree(const rl_light *L, rl_vec3 eye, rl_vec3 p1, rl_vec3 p2, float kd, float ks, float m,
                       bool *ext, bool *der)
{
    rl_material mat = rl_material_default();
    mat.diffuse = rl_v3(kd, kd, kd);
    mat.specular = rl_v3(ks, ks, ks);
    mat.shininess = m;
    rl_vec3 up = rl_v3(0.0f, 1.0f, 0.0f);
    vt_edge_end e1 = vt_edge_end_of(p1, up, eye, &mat), e2 = vt_edge_end_of(p2, up, eye, &mat);
    *ext = vt_extremum_test(L, 1, &e1, &e2);
    *der = vt_derivative_test(L, 1, eye, &e1, &e2);
    return *ext == *der;
}

/* Sec. 6.1.1: the derivative test (eq. 6.3) and the geometric one (eq.
 * 6.4-6.5) agree where the peak lies on the edge or far off it, and on
 * most random edges; they differ, as they must, where the edge passes
 * beside the peak: the slope along the edge turns at its point nearest the
 * peak (eq. 6.3 sees that maximum of the restriction to the edge), while
 * the lobe's direction across the axis turns by less than 90 degrees (eq.
 * 6.5 does not). */
static void test_derivative_agrees_with_extremum(void **state)
{
    (void)state;
    const rl_vec3 eye = rl_v3(0.0f, 4.0f, 3.0f);
    const rl_vec3 h = rl_v3(0.8f, 0.0f, 0.6f);      /* where the sun mirrors into the eye */
    rl_vec3 a = rl_normalize(rl_sub(eye, h));
    rl_light sun = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(1, 1, 1), .intensity = 1.0f,
                     .direction = rl_v3(a.x, -a.y, a.z) };
    bool ext, der;
    /* specular only: the highlight on the edge, off its end, far off */
    assert_true(tests_agree(&sun, eye, rl_v3(0.3f, 0.0f, 0.6f), rl_v3(1.3f, 0.0f, 0.6f), 0.0f, 1.0f, 50.0f, &ext, &der));
    assert_true(ext && der);
    assert_true(tests_agree(&sun, eye, rl_v3(0.8f, 0.0f, 0.1f), rl_v3(0.8f, 0.0f, 1.1f), 0.0f, 1.0f, 50.0f, &ext, &der));
    assert_true(ext && der);
    assert_true(tests_agree(&sun, eye, rl_v3(1.0f, 0.0f, 0.6f), rl_v3(1.9f, 0.0f, 0.6f), 0.0f, 1.0f, 50.0f, &ext, &der));
    assert_true(!ext && !der);
    assert_true(tests_agree(&sun, eye, rl_v3(-1.9f, 0.0f, -1.0f), rl_v3(-1.0f, 0.0f, -1.9f), 0.0f, 1.0f, 50.0f, &ext, &der));
    assert_true(!ext && !der);
    /* beside the highlight: the edge's nearest point to it is inside */
    tests_agree(&sun, eye, rl_v3(0.3f, 0.0f, 1.2f), rl_v3(1.3f, 0.0f, 1.2f), 0.0f, 1.0f, 50.0f, &ext, &der);
    assert_true(der && !ext);

    /* diffuse under a point light 1 m over (0.5, 0, -0.5): across its foot
     * both fire, beside it only the derivative, away from it neither */
    rl_light bulb = { .type = RL_LIGHT_POINT, .color = rl_v3(1, 1, 1), .intensity = 4.0f,
                      .position = rl_v3(0.5f, 1.0f, -0.5f) };
    assert_true(tests_agree(&bulb, eye, rl_v3(0.0f, 0.0f, -0.5f), rl_v3(1.2f, 0.0f, -0.5f), 0.7f, 0.0f, 1.0f, &ext, &der));
    assert_true(ext && der);
    assert_true(tests_agree(&bulb, eye, rl_v3(1.0f, 0.0f, -0.5f), rl_v3(1.8f, 0.0f, -0.5f), 0.7f, 0.0f, 1.0f, &ext, &der));
    assert_true(!ext && !der);
    tests_agree(&bulb, eye, rl_v3(0.0f, 0.0f, 0.5f), rl_v3(1.0f, 0.0f, 0.5f), 0.7f, 0.0f, 1.0f, &ext, &der);
    assert_true(der && !ext);
    /* a directional light onto a plane: both terms constant or monotone */
    rl_light down = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(1, 1, 1), .intensity = 1.0f,
                      .direction = rl_v3(0.0f, -1.0f, 0.0f) };
    assert_true(tests_agree(&down, eye, rl_v3(-1.0f, 0.0f, 1.0f), rl_v3(1.0f, 0.0f, 1.0f), 0.7f, 0.0f, 1.0f, &ext, &der));
    assert_true(!ext && !der);

    /* random edges, random lights and materials: mostly the same answer;
     * every edge with one normal that the extremum test splits, the
     * derivative test splits too (a peak between the ends is a turn of the
     * slope) */
    rl_rng g;
    rl_rng_seed(&g, 2003u, 63u);
    int agree = 0, n = 0, only_ext = 0, only_der = 0, only_ext_flat = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        rl_light L;
        vt_edge_end e[2];
        random_edge(&g, &L, e, eye);
        bool x = vt_extremum_test(&L, 1, &e[0], &e[1]), d = vt_derivative_test(&L, 1, eye, &e[0], &e[1]);
        n++;
        agree += x == d;
        only_ext += x && !d;
        only_ext_flat += x && !d && rl_dot(e[0].n, e[1].n) > 0.99999f;
        only_der += d && !x;
    }
    print_message("derivative vs extremum on %d random edges: agree %d, only extremum %d, only derivative %d\n",
                  n, agree, only_ext, only_der);
    assert_true(agree > 8 * n / 10);
    /* where the normals swing across a short edge the term can turn twice
     * inside it (equal slopes at the ends) while the lobe passes the axis */
    assert_int_equal(only_ext_flat, 0);
    assert_true(only_ext < n / 100);
}

/* Sec. 6.1.1, eq. 6.3: the derivative test is the sign of the slope of the
 * term along the edge: on random edges lit at both ends, with one term at
 * a time (k_d or k_s), it fires exactly where finite differences of the
 * term at the two ends have opposite signs (slopes too flat to tell by
 * differences are left out). */
/* A ray tree of a mirror hit: primary (object 1) lit by light 0, its
 * reflection (depth 1) on object 2 lit by light 0, that one's reflection
 * (depth 2) on object 3 with its feeler. Feeler occluders: RL_ID_NONE =
 * lit, else blocked. */
static rl_ray_tree mirror_tree(uint32_t occ0, uint32_t occ1, uint32_t occ2, uint32_t deep_object)
{
    rl_ray_tree t;
    memset(&t, 0, sizeof t);
    const rl_ray_tree_node n[] = {
        { RL_RAY_PRIMARY, 0, 1, RL_ID_NONE },   { RL_RAY_SHADOW, 1, occ0, 0 },
        { RL_RAY_REFLECTION, 1, 2, RL_ID_NONE }, { RL_RAY_SHADOW, 2, occ1, 0 },
        { RL_RAY_REFLECTION, 2, deep_object, RL_ID_NONE }, { RL_RAY_SHADOW, 3, occ2, 0 },
    };
    for (size_t i = 0; i < sizeof n / sizeof n[0]; ++i)
        t.nodes[t.count++] = n[i];
    return t;
}

static void test_tree_readings_keep_what_they_say(void **state)
{
    (void)state;
    const uint32_t lit = RL_ID_NONE, blocked = 7;
    rl_ray_tree base = mirror_tree(lit, lit, lit, 3);
    /* The default reading is the tree as traced. */
    assert_true(vt_tree_hash(&base, VT_TREE_SHADOW_BLOCKED, 0) == rl_ray_tree_hash(&base));
    assert_true(vt_tree_hash(&base, VT_TREE_SHADOW_OCCLUDER, 0) == rl_ray_tree_hash(&base));
    assert_true(vt_tree_hash(NULL, VT_TREE_SHADOW_VISIBLE, 2) == 0);

    /* The reflected object in shadow (Fig. 3.7): every reading but none
     * sees it. */
    rl_ray_tree shadowed = mirror_tree(lit, blocked, lit, 3);
    for (int r = VT_TREE_SHADOW_BLOCKED; r <= VT_TREE_SHADOW_OCCLUDER; ++r)
        assert_true(vt_tree_hash(&base, r, 0) != vt_tree_hash(&shadowed, r, 0));
    assert_true(vt_tree_hash(&base, VT_TREE_SHADOW_NONE, 0) == vt_tree_hash(&shadowed, VT_TREE_SHADOW_NONE, 0));
    /* Depth 1 keeps the rays of depth 1 and the feelers of their hits. */
    assert_true(vt_tree_hash(&base, VT_TREE_SHADOW_BLOCKED, 1) != vt_tree_hash(&shadowed, VT_TREE_SHADOW_BLOCKED, 1));

    /* A blocked light and one the surface faces away from (no feeler):
     * equal only in the visible reading. */
    rl_ray_tree away = base, blocked_tree = mirror_tree(blocked, lit, lit, 3);
    memmove(&away.nodes[1], &away.nodes[2], 4 * sizeof away.nodes[0]);
    away.count--;
    assert_true(vt_tree_hash(&away, VT_TREE_SHADOW_VISIBLE, 0) == vt_tree_hash(&blocked_tree, VT_TREE_SHADOW_VISIBLE, 0));
    assert_true(vt_tree_hash(&away, VT_TREE_SHADOW_BLOCKED, 0) != vt_tree_hash(&blocked_tree, VT_TREE_SHADOW_BLOCKED, 0));
    assert_true(vt_tree_hash(&away, VT_TREE_SHADOW_VISIBLE, 0) != vt_tree_hash(&base, VT_TREE_SHADOW_VISIBLE, 0));

    /* Another object at depth 2, or its feeler blocked: seen at depth 0
     * (all) and 2, not at depth 1. */
    rl_ray_tree deep = mirror_tree(lit, lit, lit, 4), deep_shadow = mirror_tree(lit, lit, blocked, 3);
    for (int depth = 0; depth <= 3; ++depth) {
        bool seen = depth != 1;
        assert_true((vt_tree_hash(&base, VT_TREE_SHADOW_BLOCKED, depth) != vt_tree_hash(&deep, VT_TREE_SHADOW_BLOCKED, depth)) == seen);
        assert_true((vt_tree_hash(&base, VT_TREE_SHADOW_BLOCKED, depth) != vt_tree_hash(&deep_shadow, VT_TREE_SHADOW_BLOCKED, depth)) == seen);
    }
    /* Truncation still counts. */
    rl_ray_tree cut = base;
    cut.truncated = true;
    assert_true(vt_tree_hash(&base, VT_TREE_SHADOW_VISIBLE, 1) != vt_tree_hash(&cut, VT_TREE_SHADOW_VISIBLE, 1));
}

static void test_derivative_test_is_the_sign_of_the_slope(void **state)
{
    (void)state;
    const rl_vec3 eye = rl_v3(0.0f, 4.0f, 3.0f);
    rl_rng g;
    rl_rng_seed(&g, 2003u, 62u);
    int checked = 0, turns = 0;
    for (int trial = 0; trial < 4000; ++trial) {
        rl_light L;
        vt_edge_end e[2];
        random_edge(&g, &L, e, eye);
        bool diffuse = trial & 1;
        for (int k = 0; k < 2; ++k) {
            if (diffuse)
                e[k].ks = 0.0f;
            else
                e[k].kd = 0.0f;
        }
        if (!((diffuse ? e[0].kd : e[0].ks) > 0.0f))
            continue;
        const float h = 1e-3f;
        float f0 = vt_term_at(&L, eye, &e[0], &e[1], 0.0f), f1 = vt_term_at(&L, eye, &e[0], &e[1], 1.0f);
        float s0 = (vt_term_at(&L, eye, &e[0], &e[1], h) - f0) / h;
        float s1 = (f1 - vt_term_at(&L, eye, &e[0], &e[1], 1.0f - h)) / h;
        float flat = 1e-2f * rl_maxf(f0, f1);
        if (!(f0 > 1e-6f && f1 > 1e-6f) || fabsf(s0) < flat || fabsf(s1) < flat)
            continue;
        bool turn = (s0 > 0.0f) != (s1 > 0.0f);
        checked++;
        turns += turn;
        assert_int_equal(vt_derivative_test(&L, 1, eye, &e[0], &e[1]), turn);
    }
    print_message("derivative test against finite differences: %d edges, %d turns\n", checked, turns);
    assert_true(checked > 1000 && turns > 20);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_display_is_clamped_srgb),
        cmocka_unit_test(test_hsv_of_primaries_and_greys),
        cmocka_unit_test(test_parse_accepts_the_documented_names_only),
        cmocka_unit_test(test_rgb_fires_on_l1_of_display_values),
        cmocka_unit_test(test_hsv_hue_wraps_and_is_ignored_for_greys),
        cmocka_unit_test(test_tree_and_combinations_report_what_fired),
        cmocka_unit_test(test_shaft_is_the_hull_of_two_boxes),
        cmocka_unit_test(test_affine_encloses_the_term_and_is_tighter_than_intervals),
        cmocka_unit_test(test_derivative_agrees_with_extremum),
        cmocka_unit_test(test_derivative_test_is_the_sign_of_the_slope),
        cmocka_unit_test(test_tree_readings_keep_what_they_say),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
