/* test_linespace.c: the Line Space (src/accel/linespace*.c, Schröder 2017):
 * index mapping, half floats, candidate lists against the BVH, fixed lists,
 * PNMT/PREILLUM agreement rates, determinism, bad arguments. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel_internal.h"
#include "accel/linespace_internal.h"
#include "core/half.h"
#include "rl/rl_accel.h"
#include "rl/rl_linespace.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

#if defined(__SANITIZE_ADDRESS__)
#define RAYS_SCALE 10               /* ASan: a tenth of the rays */
#else
#define RAYS_SCALE 1
#endif

/* ---- helpers --------------------------------------------------------- */

static rl_scene *builtin(const char *name, const char *params)
{
    rl_scene *s = NULL;
    if (rl_scene_create_builtin(name, params, &s) != RL_OK)
        fail_msg("%s (%s): %s", name, params ? params : "", rl_last_error());
    return s;
}

static rl_accel *accel_of(const rl_scene *s, rl_accel_desc desc)
{
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &desc, &a), RL_OK);
    if (rl_accel_commit(a) != RL_OK)
        fail_msg("commit: %s", rl_last_error());
    return a;
}

static rl_linespace *ls_of(const rl_accel *grid, rl_linespace_desc d, rl_ls_shade_fn shade)
{
    rl_linespace *ls = NULL;
    assert_int_equal(rl_linespace_create(grid, &d, &ls), RL_OK);
    if (shade)
        assert_int_equal(rl_linespace_set_shader(ls, shade, NULL), RL_OK);
    if (rl_linespace_commit(ls) != RL_OK)
        fail_msg("linespace commit: %s", rl_last_error());
    return ls;
}

static float uniform(rl_rng *r, float lo, float hi) { return lo + (hi - lo) * rl_rng_float(r); }

static rl_vec3 random_in(rl_rng *r, rl_aabb b)
{
    return rl_v3(uniform(r, b.min.x, b.max.x), uniform(r, b.min.y, b.max.y), uniform(r, b.min.z, b.max.z));
}

static rl_vec3 random_dir(rl_rng *r)
{
    for (;;) {
        rl_vec3 d = rl_v3(uniform(r, -1, 1), uniform(r, -1, 1), uniform(r, -1, 1));
        float l2 = rl_length2(d);
        if (l2 > 1e-4f && l2 <= 1.0f)
            return d;
    }
}

static rl_vec3 point_on(rl_rng *r, const rl_scene_data *d, uint32_t tri)
{
    float u = rl_rng_float(r), v = rl_rng_float(r);
    if (u + v > 1.0f) {
        u = 1.0f - u;
        v = 1.0f - v;
    }
    const uint32_t *i = d->indices + 3 * (size_t)tri;
    rl_vec3 p0 = d->positions[i[0]], p1 = d->positions[i[1]], p2 = d->positions[i[2]];
    return rl_add(p0, rl_add(rl_scale(rl_sub(p1, p0), u), rl_scale(rl_sub(p2, p0), v)));
}

/* Inside and outside the scene, at triangles and vertices, axis-parallel,
 * along voxel planes, finite segments. */
static rl_ray random_ray(rl_rng *r, const rl_scene_data *d)
{
    rl_aabb b = d->bounds;
    float s = rl_vmax_comp(rl_aabb_extent(b));
    rl_aabb wide = { rl_sub(b.min, rl_v3s(0.5f * s)), rl_add(b.max, rl_v3s(0.5f * s)) };
    rl_ray ray = { .o = random_in(r, wide), .t_min = 0.0f, .t_max = INFINITY };
    switch (rl_rng_bounded(r, 6)) {
    case 0:
        ray.o = random_in(r, b);
        ray.d = random_dir(r);
        break;
    case 1:
        ray.d = rl_sub(point_on(r, d, rl_rng_bounded(r, d->num_triangles)), ray.o);
        break;
    case 2:
        ray.d = rl_sub(d->positions[d->indices[rl_rng_bounded(r, 3 * d->num_triangles)]], ray.o);
        break;
    case 3: {
        ray.o = random_in(r, b);
        float sign = rl_rng_bounded(r, 2) ? 1.0f : -1.0f;
        uint32_t kind = rl_rng_bounded(r, 3);
        ray.d = kind == 0 ? rl_v3(sign, 0, 0) : (kind == 1 ? rl_v3(0.5f, sign, 0) : rl_v3(0, 0.3f, sign));
        break;
    }
    case 4:
        ray.o = random_in(r, b);
        ray.d = random_dir(r);
        ray.t_min = uniform(r, -0.2f, 0.3f) * s;
        ray.t_max = ray.t_min + uniform(r, 0.0f, 1.0f) * s;
        break;
    default:
        ray.d = rl_sub(random_in(r, b), ray.o);
        break;
    }
    if (rl_length2(ray.d) == 0.0f)
        ray.d = rl_v3(0, 1, 0);
    return ray;
}

/* The reference answer: the BVH, or brute force for rays with t_min < 0
 * (the BVH misses hits at negative t, which grid and brute force report;
 * see docs/line-space.md). */
static const rl_accel *reference(const rl_accel *bvh, const rl_accel *brute, const rl_ray *ray)
{
    return ray->t_min < 0.0f ? brute : bvh;
}

/* ---- index mapping --------------------------------------------------- */

static void test_linespace_index_mapping_is_a_bijection_for_n_1_to_6(void **state)
{
    (void)state;
    for (int n = 1; n <= 6; ++n) {
        uint32_t S = rl_ls_shafts_per_voxel(n);
        assert_int_equal(S, 15u * (uint32_t)(n * n * n * n));
        unsigned char *seen = calloc(S, 1);
        assert_non_null(seen);
        for (uint32_t s = 0; s < S; ++s) {
            int fa, pa, fb, pb;
            rl_ls_shaft_decode(n, s, &fa, &pa, &fb, &pb);
            assert_true(fa >= 0 && fa < fb && fb < 6);
            assert_true(pa >= 0 && pa < n * n && pb >= 0 && pb < n * n);
            bool fwd = false;
            assert_int_equal(rl_ls_shaft_index(n, fa, pa, fb, pb, &fwd), s);
            assert_true(fwd);
            assert_int_equal(rl_ls_shaft_index(n, fb, pb, fa, pa, &fwd), s);
            assert_false(fwd);
        }
        /* Every ordered pair of patches on different faces maps into range,
         * and each shaft is reached exactly twice (once per direction). */
        for (int fa = 0; fa < 6; ++fa)
            for (int fb = 0; fb < 6; ++fb)
                for (int pa = 0; pa < n * n; ++pa)
                    for (int pb = 0; pb < n * n; ++pb) {
                        uint32_t s = rl_ls_shaft_index(n, fa, pa, fb, pb, NULL);
                        if (fa == fb) {
                            assert_int_equal(s, RL_NONE);
                            continue;
                        }
                        assert_true(s < S);
                        ++seen[s];
                    }
        for (uint32_t s = 0; s < S; ++s)
            assert_int_equal(seen[s], 2);
        free(seen);
    }
    /* The documented numbers: (0,1) = 0, (0,2) = 1, (4,5) = 14. */
    assert_int_equal(rl_ls_shaft_index(2, 0, 0, 1, 0, NULL), 0u);
    assert_int_equal(rl_ls_shaft_index(2, 0, 0, 2, 0, NULL), 16u);
    assert_int_equal(rl_ls_shaft_index(2, 4, 3, 5, 1, NULL), 14u * 16u + 3u * 4u + 1u);
    assert_int_equal(rl_ls_shaft_index(0, 0, 0, 1, 0, NULL), RL_NONE);
}

/* A point on face f of box b at patch cell (i, j) with offsets in (0.05, 0.95). */
static rl_vec3 on_face(rl_rng *r, rl_aabb b, int n, int f, int i, int j)
{
    int u, v;
    rl_ls_face_uv(f, &u, &v);
    float c[3];
    c[f >> 1] = (f & 1) ? 1.0f : 0.0f;
    c[u] = ((float)i + uniform(r, 0.05f, 0.95f)) / (float)n;
    c[v] = ((float)j + uniform(r, 0.05f, 0.95f)) / (float)n;
    rl_vec3 e = rl_sub(b.max, b.min);
    return rl_v3(b.min.x + c[0] * e.x, b.min.y + c[1] * e.y, b.min.z + c[2] * e.z);
}

static void test_linespace_shaft_of_segment_agrees_with_the_mapping(void **state)
{
    (void)state;
    rl_rng r;
    rl_rng_seed(&r, 7, 1);
    rl_aabb box = { { -1.5f, 2.0f, 0.25f }, { -0.5f, 2.5f, 3.25f } };
    for (int n = 1; n <= 6; ++n)
        for (int it = 0; it < 4000; ++it) {
            int fa = (int)rl_rng_bounded(&r, 6), fb = (int)rl_rng_bounded(&r, 5);
            fb += fb >= fa;
            int ia = (int)rl_rng_bounded(&r, (uint32_t)n), ja = (int)rl_rng_bounded(&r, (uint32_t)n);
            int ib = (int)rl_rng_bounded(&r, (uint32_t)n), jb = (int)rl_rng_bounded(&r, (uint32_t)n);
            rl_vec3 a = on_face(&r, box, n, fa, ia, ja), b = on_face(&r, box, n, fb, ib, jb);
            bool fwd_expect, fwd;
            uint32_t expect = rl_ls_shaft_index(n, fa, ia + n * ja, fb, ib + n * jb, &fwd_expect);
            assert_int_equal(rl_ls_shaft_of_segment(n, box, a, b, &fwd), expect);
            assert_true(fwd == fwd_expect);
            assert_int_equal(rl_ls_shaft_of_segment(n, box, b, a, &fwd), expect);
            assert_true(fwd != fwd_expect);
            assert_int_equal(rl_ls_shaft_of_segment(n, box, a, on_face(&r, box, n, fa, ib, jb), NULL),
                             RL_NONE);
        }
}

/* The Möller-Trumbore hit of shaft's midpoint ray (patch centre to patch
 * centre) with triangle t. */
static bool reference_hit(const rl_ls_geometry *g, uint32_t shaft, const rl_ls_tri *t, double *s,
                          double *u, double *w)
{
    int fa, pa, fb, pb, np = g->n * g->n;
    rl_ls_shaft_decode(g->n, shaft, &fa, &pa, &fb, &pb);
    const float *ca = g->patch_center + ((size_t)fa * (size_t)np + (size_t)pa) * 3;
    const float *cb = g->patch_center + ((size_t)fb * (size_t)np + (size_t)pb) * 3;
    double a[3] = { ca[0], ca[1], ca[2] }, b[3] = { cb[0], cb[1], cb[2] };
    return rl_ls_segment_hit(a, b, t->v, s, u, w);
}

/* The build orders a shaft's entries by where its midpoint ray meets the
 * triangle, found from per-patch plane distances and barycentrics instead of
 * a ray/triangle test per shaft; both must name the same hits. Fails when
 * the precomputed barycentric gradients or the interpolation go wrong. */
static void test_linespace_enumerated_hits_equal_the_ray_triangle_test(void **state)
{
    (void)state;
    rl_rng r;
    rl_rng_seed(&r, 11, 3);
    const int ns[] = { 1, 3, 6 };
    uint64_t hits = 0, agree = 0, misses_checked = 0;
    for (size_t ni = 0; ni < sizeof ns / sizeof ns[0]; ++ni) {
        int n = ns[ni];
        rl_ls_geometry g;
        assert_int_equal(rl_ls_geometry_init(&g, n), RL_OK);
        rl_ls_entry *out = malloc(g.shafts * sizeof *out);
        double *scratch = malloc(RL_LS_ENUM_SCRATCH(n) * sizeof *scratch);
        int *iscratch = malloc((size_t)4 * (size_t)(n * n) * sizeof *iscratch);
        unsigned char *listed = malloc(g.shafts);
        assert_true(out && scratch && iscratch && listed);
        for (int it = 0; it < 60; ++it) {
            /* Triangles inside, across and much larger than the voxel. */
            double spread = it % 3 == 0 ? 0.5 : it % 3 == 1 ? 1.5 : 6.0;
            double p[3][3];
            for (int i = 0; i < 3; ++i)
                for (int k = 0; k < 3; ++k)
                    p[i][k] = 0.5 + spread * (2.0 * rl_rng_float(&r) - 1.0);
            rl_ls_tri t;
            if (!rl_ls_tri_setup(&t, p))
                continue;
            uint32_t count = rl_ls_enumerate(&g, &t, 7u, out, scratch, iscratch);
            memset(listed, 0, g.shafts);
            for (uint32_t e = 0; e < count; ++e) {
                uint32_t shaft = out[e].shaft & ~RL_LS_ENTRY_HIT;
                assert_true(shaft < g.shafts);
                assert_int_equal(out[e].tri, 7u);
                listed[shaft] = 1;
                double s, u, w;
                bool ref = reference_hit(&g, shaft, &t, &s, &u, &w);
                bool got = (out[e].shaft & RL_LS_ENTRY_HIT) != 0;
                if (!got && !ref)
                    continue;
                ++hits;
                /* Rays grazing an edge may fall either side of the tolerance. */
                if (got == ref && fabs(s - out[e].key_front) < 1e-5 &&
                    fabs(u - out[e].u) < 1e-5 && fabs(w - out[e].w) < 1e-5)
                    ++agree;
            }
            /* A midpoint ray that hits the triangle lies in a listed shaft. */
            for (uint32_t sh = 0; sh < g.shafts; sh += 1 + sh % 5) {
                if (listed[sh])
                    continue;
                double s, u, w;
                if (reference_hit(&g, sh, &t, &s, &u, &w))
                    assert_true(s < 1e-3 || s > 1.0 - 1e-3 || u < 1e-6 || w < 1e-6 ||
                                u + w > 1.0 - 1e-6);
                ++misses_checked;
            }
        }
        free(listed);
        free(iscratch);
        free(scratch);
        free(out);
        rl_ls_geometry_free(&g);
    }
    assert_true(hits > 1000 && misses_checked > 1000);
    if ((double)agree < 0.999 * (double)hits)
        fail_msg("%llu of %llu midpoint hits agree with the ray/triangle test",
                 (unsigned long long)agree, (unsigned long long)hits);
}

/* ---- half floats ----------------------------------------------------- */

static void test_half_conversion_rounds_to_nearest_even_and_round_trips(void **state)
{
    (void)state;
    assert_int_equal(rl_half_from_float(1.0f), 0x3c00);
    assert_int_equal(rl_half_from_float(-2.0f), 0xc000);
    assert_int_equal(rl_half_from_float(65504.0f), 0x7bff);
    assert_int_equal(rl_half_from_float(65519.0f), 0x7bff);
    assert_int_equal(rl_half_from_float(65520.0f), 0x7c00);
    assert_int_equal(rl_half_from_float(0x1p-24f), 0x0001);
    assert_int_equal(rl_half_from_float(0x1p-25f), 0x0000);            /* tie to even: 0 */
    assert_int_equal(rl_half_from_float(0x1.8p-24f), 0x0002);          /* tie to even: 2 */
    assert_int_equal(rl_half_from_float(1.0f + 0x1p-11f), 0x3c00);     /* tie to even */
    assert_int_equal(rl_half_from_float(1.0f + 0x1.8p-10f), 0x3c02);   /* tie, odd -> up */
    assert_int_equal(rl_half_from_float(INFINITY), 0x7c00);
    assert_true((rl_half_from_float(NAN) & 0x7c00) == 0x7c00 && (rl_half_from_float(NAN) & 0x3ff));
    for (uint32_t h = 0; h < 65536; ++h) {
        if ((h & 0x7c00) == 0x7c00 && (h & 0x3ff))
            continue;                                                   /* NaN */
        assert_int_equal(rl_half_from_float(rl_half_to_float((uint16_t)h)), h);
    }
}

/* ---- candidate lists against the BVH ---------------------------------- */

static void agree_with_bvh(const char *name, const char *params, int grid_res, int num_rays)
{
    rl_scene *s = builtin(name, params);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_accel_desc gd = { .kind = RL_ACCEL_GRID };
    if (grid_res > 0)
        gd.grid_res[0] = gd.grid_res[1] = gd.grid_res[2] = grid_res;
    rl_accel *grid = accel_of(s, gd);
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .dynamic = true }, NULL);
    rl_linespace_stats st;
    rl_linespace_get_stats(ls, &st);
    assert_int_equal(st.truncated_shafts, 0);
    assert_true(st.filled_voxels > 0 && st.candidates > 0);
    rl_rng r;
    rl_rng_seed(&r, 42, 3);
    int hits = 0;
    for (int i = 0; i < num_rays; ++i) {
        rl_ray ray = random_ray(&r, d);
        rl_ray rb = ray, rl = ray;
        rl_hit hb, hl;
        const rl_accel *ref = reference(bvh, brute, &ray);
        bool b = rl_accel_intersect(ref, &rb, &hb), l = rl_linespace_intersect(ls, &rl, &hl);
        hits += b;
        /* Same watertight test and tie rule (lowest ID at equal t) as the
         * BVH, so the same triangle; t within 1e-4 relative. */
        if (b != l || hb.triangle != hl.triangle || hb.object != hl.object ||
            (b && fabsf(hb.t - hl.t) > 1e-4f * fabsf(hb.t)))
            fail_msg("%s ray %d o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) t=(%g %g): bvh %d tri %u t %.9g, "
                     "ls %d tri %u t %.9g",
                     name, i, (double)ray.o.x, (double)ray.o.y, (double)ray.o.z, (double)ray.d.x,
                     (double)ray.d.y, (double)ray.d.z, (double)ray.t_min, (double)ray.t_max, b,
                     hb.triangle, (double)hb.t, l, hl.triangle, (double)hl.t);
        if (rl_accel_occluded(ref, &ray) != rl_linespace_occluded(ls, &ray))
            fail_msg("%s ray %d: occluded differs", name, i);
    }
    print_message("%s (%d^3 or default grid): %d rays, %d hits, %u filled voxels, mean %.1f candidates\n",
                  name, grid_res, num_rays, hits, st.filled_voxels, st.mean_candidates);
    assert_true(hits > num_rays / 10);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_accel_release(brute);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

static void test_linespace_dynamic_candidates_equal_the_bvh_on_cornell_teapot(void **state)
{
    (void)state;
    agree_with_bvh("cornell-teapot", "triangles=5000", 8, 100000 / RAYS_SCALE);
    agree_with_bvh("cornell-teapot", "triangles=5000", 16, 30000 / RAYS_SCALE);
}

static void test_linespace_dynamic_candidates_equal_the_bvh_on_cornell(void **state)
{
    (void)state;
    agree_with_bvh("cornell", NULL, 0, 100000 / RAYS_SCALE);
    agree_with_bvh("cornell", NULL, 5, 20000 / RAYS_SCALE);
}

/* ---- fixed lists ------------------------------------------------------ */

static void test_linespace_fixed_lists_report_truncation_and_return_only_true_hits(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=5000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 6, 6, 6 } });
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .n = 4, .k = 4 }, NULL);
    rl_linespace_stats st;
    rl_linespace_get_stats(ls, &st);
    assert_true(st.truncated_shafts > 0);
    assert_true(st.max_candidates > 4);
    rl_linespace_data data;
    rl_linespace_get_data(ls, &data);
    assert_null(data.cand_start);
    assert_int_equal(data.num_cand, data.num_occupied * 4);   /* k slots per occupied shaft */
    assert_true(data.num_occupied < (uint64_t)data.num_blocks * data.shafts_per_voxel);
    rl_rng r;
    rl_rng_seed(&r, 5, 5);
    int n = 30000 / RAYS_SCALE, missed = 0, same = 0;
    for (int i = 0; i < n; ++i) {
        rl_ray ray = random_ray(&r, d);
        rl_ray rb = ray, rl = ray;
        rl_hit hb, hl;
        bool b = rl_accel_intersect(reference(bvh, brute, &ray), &rb, &hb);
        bool l = rl_linespace_intersect(ls, &rl, &hl);
        if (!l) {
            missed += b;
            continue;
        }
        /* A hit is real: the triangle is hit there, and nothing is closer. */
        assert_true(b);
        assert_true(hl.t >= hb.t);
        const rl_vec3 *v = d->positions;
        const uint32_t *idx = d->indices + 3 * (size_t)hl.triangle;
        rl_ray_watertight w;
        rl_ray_watertight_setup(&ray, &w);
        float t, u, vv;
        assert_true(rl_triangle_intersect_watertight(&w, v[idx[0]], v[idx[1]], v[idx[2]], ray.t_min,
                                                     ray.t_max, &t, &u, &vv));
        assert_true(t == hl.t);
        same += hl.triangle == hb.triangle;
    }
    print_message("fixed k=4: %llu of %llu shafts truncated; %d of %d rays missed a hit, %d same hit\n",
                  (unsigned long long)st.truncated_shafts, (unsigned long long)st.shafts, missed, n, same);
    assert_true(missed > 0);
    rl_linespace_release(ls);
    rl_accel_release(brute);
    rl_accel_release(grid);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

/* ---- PNMT and PREILLUM ------------------------------------------------ */

static rl_vec3 shade_by_normal(void *user, const rl_ls_surface *s, rl_vec3 dir)
{
    (void)user;
    (void)dir;
    return rl_v3(0.5f + 0.5f * s->n.x, 0.5f + 0.5f * s->n.y, (float)s->material);
}

/* Shadow-ray-like segments between random points inside the box; the rate
 * at which the stored surfaces give the exact occlusion answer. */
static void measure_agreement(const char *name, const char *params, int res, double min_pnmt,
                              double min_pre)
{
    rl_scene *s = builtin(name, params);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { res, res, res } });
    rl_linespace *ls = ls_of(grid,
                             (rl_linespace_desc){ .dynamic = true,
                                                  .payloads = RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM },
                             shade_by_normal);
    rl_rng r;
    rl_rng_seed(&r, 11, 2);
    int n = 40000 / RAYS_SCALE, agree_p = 0, agree_c = 0, occl = 0, surf_same = 0, surf_hits = 0;
    rl_vec3 shrink = rl_scale(rl_aabb_extent(d->bounds), 0.02f);
    rl_aabb inner = { rl_add(d->bounds.min, shrink), rl_sub(d->bounds.max, shrink) };
    for (int i = 0; i < n; ++i) {
        rl_vec3 a = random_in(&r, inner), b = random_in(&r, inner);
        rl_ray ray = { .o = a, .d = rl_sub(b, a), .t_min = 0.0f, .t_max = 1.0f };
        bool exact = rl_accel_occluded(bvh, &ray);
        occl += exact;
        agree_p += rl_linespace_pnmt_occluded(ls, &ray) == exact;
        rl_vec3 c;
        agree_c += rl_linespace_preillum(ls, &ray, &c, NULL) == exact;
        /* PNMT closest surface vs the exact hit: same material? */
        rl_ray full = { .o = a, .d = rl_sub(b, a), .t_min = 0.0f, .t_max = INFINITY };
        rl_hit h;
        rl_ls_surface sf;
        if (rl_accel_intersect(bvh, &full, &h) && rl_linespace_pnmt_intersect(ls, &full, &sf)) {
            ++surf_hits;
            surf_same += sf.material == d->triangle_material[h.triangle];
        }
    }
    double rp = (double)agree_p / n, rc = (double)agree_c / n;
    print_message("%s %d^3 N=5: PNMT occlusion agrees %.2f %%, PREILLUM %.2f %% (%d segments, %.1f %% "
                  "occluded); PNMT material = exact on %.2f %% of hits\n",
                  name, res, 100.0 * rp, 100.0 * rc, n, 100.0 * occl / n,
                  surf_hits ? 100.0 * surf_same / surf_hits : 0.0);
    assert_true(rp >= min_pnmt);
    assert_true(rc >= min_pre);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

static void test_linespace_pnmt_and_preillum_occlusion_agree_at_the_measured_rate(void **state)
{
    (void)state;
    /* Measured (40k segments): teapot 94.6 % / 94.3 %, cornell 93.4 % / 93.0 %. */
    measure_agreement("cornell-teapot", "triangles=5000", 8, 0.93, 0.93);
    measure_agreement("cornell", NULL, 8, 0.92, 0.915);
}

static void test_linespace_pnmt_records_decode_to_unit_normals_in_the_voxel(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 4, 4, 4 } });
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .n = 3, .payloads = RL_LS_PNMT }, NULL);
    rl_linespace_data data;
    rl_linespace_get_data(ls, &data);
    assert_non_null(data.pnmt);
    assert_null(data.cand);
    uint64_t filled = 0, shafts = (uint64_t)data.num_blocks * data.shafts_per_voxel;
    assert_true(data.num_occupied > 0 && data.num_occupied < shafts);
    for (uint64_t g = 0; g < 2 * data.num_occupied; ++g) {
        const uint16_t *rec = data.pnmt + g * 8;
        float m = rl_half_to_float(rec[RL_LS_PNMT_MAT]);
        assert_true(m != 0.0f);               /* only occupied shafts have records */
        ++filled;
        for (int k = 0; k < 3; ++k) {
            float p = rl_half_to_float(rec[k]);
            assert_true(p >= 0.0f && p <= 1.0f);
        }
        float nx = rl_half_to_float(rec[RL_LS_PNMT_NX]), ny = rl_half_to_float(rec[RL_LS_PNMT_NY]);
        assert_true(nx * nx + ny * ny <= 1.002f);
        assert_true(fabsf(m) >= 1.0f && fabsf(m) <= (float)rl_scene_get_data(s)->num_materials);
    }
    assert_true(filled > 0);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_scene_release(s);
}

/* The triangles the point p lies on (within tol of the plane, inside
 * with a barycentric margin), up to max; their count. */
static int triangles_at(const rl_scene_data *d, rl_vec3 p, float tol, float margin, uint32_t *out, float (*bary)[2],
                        int max)
{
    int n = 0;
    for (uint32_t t = 0; t < d->num_triangles && n < max; ++t) {
        const uint32_t *i = d->indices + 3 * (size_t)t;
        rl_vec3 a = d->positions[i[0]], e1 = rl_sub(d->positions[i[1]], a), e2 = rl_sub(d->positions[i[2]], a);
        rl_vec3 nn = rl_cross(e1, e2);
        float len = rl_length(nn);
        if (!(len > 0.0f))
            continue;
        rl_vec3 q = rl_sub(p, a);
        if (fabsf(rl_dot(q, nn)) / len > tol)
            continue;
        /* Barycentrics of q in (e1, e2) by the normal equations. */
        float d11 = rl_dot(e1, e1), d12 = rl_dot(e1, e2), d22 = rl_dot(e2, e2);
        float q1 = rl_dot(q, e1), q2 = rl_dot(q, e2), det = d11 * d22 - d12 * d12;
        float u = (d22 * q1 - d12 * q2) / det, v = (d11 * q2 - d12 * q1) / det;
        if (u < -margin || v < -margin || u + v > 1.0f + margin)
            continue;
        out[n] = t;
        bary[n][0] = u;
        bary[n][1] = v;
        ++n;
    }
    return n;
}

/* Sec. 7.4, eq. 9: a PNMT record keeps n_x, n_y and the sign of n_z (on
 * the material field); n_z is rebuilt from them. A surface a query returns
 * lies on the triangle its record was made from, so its rebuilt normal
 * must be that triangle's interpolated normal there (rl_ls_surface_at,
 * which the build uses too), up to half-float rounding, with n_z of the
 * right sign. Points on an edge between faces of different normals are
 * skipped (either face may have made them). The rotated boxes of `cornell`
 * and its walls face every direction, +z and -z included. */
static void test_linespace_pnmt_normals_rebuild_n_z_with_its_sign(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 8, 8, 8 } });
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .dynamic = true, .payloads = RL_LS_PNMT }, NULL);
    float tol = 2e-4f * rl_vmax_comp(rl_aabb_extent(d->bounds));
    rl_rng r;
    rl_rng_seed(&r, 77, 1);
    int n = 40000 / RAYS_SCALE, checked = 0, edges = 0, off = 0, plus_z = 0, minus_z = 0;
    float worst = 1.0f;
    for (int i = 0; i < n; ++i) {
        rl_ray ray = { .o = random_in(&r, d->bounds), .d = random_dir(&r), .t_min = 0.0f, .t_max = INFINITY };
        rl_ls_surface sf;
        if (!rl_linespace_pnmt_intersect(ls, &ray, &sf))
            continue;
        uint32_t tris[8];
        float bary[8][2];
        int m = triangles_at(d, sf.p, tol, 1e-3f, tris, bary, 8);
        if (m == 0) {
            ++off;
            continue;
        }
        rl_ls_surface on[8];
        rl_ls_surface_at(ls, tris[0], bary[0][0], bary[0][1], &on[0]);
        /* Near an edge (10x the tolerances) a face of another normal may
         * have made the record, its point rounded onto this face. */
        uint32_t near[8];
        float nb[8][2];
        int mn = triangles_at(d, sf.p, 10.0f * tol, 1e-2f, near, nb, 8);
        bool unique = true;
        for (int j = 0; j < mn; ++j) {
            rl_ls_surface o;
            rl_ls_surface_at(ls, near[j], nb[j][0], nb[j][1], &o);
            unique &= rl_dot(o.n, on[0].n) > 0.999f;
        }
        if (!unique) {
            ++edges;
            continue;
        }
        ++checked;
        assert_int_equal(sf.material, on[0].material);
        float c = rl_dot(sf.n, on[0].n);
        worst = c < worst ? c : worst;
        if (fabsf(on[0].n.z) > 0.05f) {
            /* The sign of n_z, which the record keeps only as the sign of
             * its material field. */
            assert_true((sf.n.z > 0.0f) == (on[0].n.z > 0.0f));
            plus_z += on[0].n.z > 0.0f;
            minus_z += on[0].n.z < 0.0f;
        }
    }
    print_message("PNMT normals: %d surfaces checked, %d on edges and %d off every triangle skipped (n_z > 0: "
                  "%d, < 0: %d); worst cos to the surface's normal %.5f\n", checked, edges, off, plus_z, minus_z,
                  worst);
    assert_true(checked > n / 2);
    assert_true(off < checked / 50);      /* clamped to the voxel, or not on a surface */
    assert_true(plus_z > 100 && minus_z > 100);
    assert_true(worst > 0.998f);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_scene_release(s);
}

/* Sec. 7.4 / Alg. 3: a shaft's front PNMT record is the first surface its
 * midpoint ray (patch centre A to patch centre B, A on the lower face)
 * hits, the back record the first the reversed ray hits. Any triangle the
 * segment A-B meets lies in the shaft, so the BVH's closest hits on the
 * segment, both ways, must be where the records say (up to half-float
 * rounding of the voxel-relative position). Shafts whose midpoint ray
 * meets nothing (the records then take the nearest candidate, our
 * fallback) or only at an end point are skipped. */
static void test_linespace_pnmt_records_are_the_midpoint_rays_first_hits(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 4, 4, 4 } });
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .n = 3, .dynamic = true, .payloads = RL_LS_PNMT }, NULL);
    const rl_grid *g = ls->grid;
    const int n = ls->n;
    uint64_t compared = 0, agree = 0, skipped = 0;
    for (int z = 0; z < g->res[2]; ++z)
        for (int y = 0; y < g->res[1]; ++y)
            for (int x = 0; x < g->res[0]; ++x) {
                uint32_t block = ls->voxel_slot[rl_grid_cell_index(g, x, y, z)];
                if (block == RL_NONE)
                    continue;
                rl_aabb box = rl_grid_cell_bounds(g, x, y, z);
                rl_vec3 ext = rl_aabb_extent(box);
                for (uint32_t sh = 0; sh < ls->shafts_per_voxel; ++sh) {
                    if (!rl_ls_shaft_occupied(ls, block, sh))
                        continue;
                    int f[2], p[2];
                    rl_ls_shaft_decode(n, sh, &f[0], &p[0], &f[1], &p[1]);
                    rl_vec3 end[2];
                    for (int e = 0; e < 2; ++e) {
                        int u, v;
                        rl_ls_face_uv(f[e], &u, &v);
                        float c[3];
                        c[f[e] >> 1] = (float)(f[e] & 1);
                        c[u] = ((float)(p[e] % n) + 0.5f) / (float)n;
                        c[v] = ((float)(p[e] / n) + 0.5f) / (float)n;
                        end[e] = rl_add(box.min, rl_mul(rl_v3(c[0], c[1], c[2]), ext));
                    }
                    const uint16_t *rec = ls->pnmt + rl_ls_shaft_rank(ls, block, sh) * 16;
                    for (int side = 0; side < 2; ++side) {
                        rl_vec3 a = end[side], b = end[1 - side];
                        rl_ray ray = { .o = a, .d = rl_sub(b, a), .t_min = 0.0f, .t_max = 1.0f };
                        rl_hit h;
                        if (!rl_accel_intersect(bvh, &ray, &h) || h.t < 1e-3f || h.t > 1.0f - 1e-3f) {
                            ++skipped;
                            continue;
                        }
                        rl_vec3 hit = rl_ray_at(&ray, h.t);
                        const uint16_t *r = rec + side * RL_LS_PNMT_RECORD;
                        rl_vec3 stored = rl_add(box.min, rl_mul(rl_v3(rl_half_to_float(r[RL_LS_PNMT_PX]),
                                                                      rl_half_to_float(r[RL_LS_PNMT_PY]),
                                                                      rl_half_to_float(r[RL_LS_PNMT_PZ])),
                                                                ext));
                        ++compared;
                        agree += rl_length(rl_sub(stored, hit)) <= 2e-3f * rl_length(ext);
                    }
                }
            }
    print_message("PNMT records against the midpoint rays' first hits: %llu of %llu agree (%llu sides "
                  "without an inner hit skipped)\n", (unsigned long long)agree, (unsigned long long)compared,
                  (unsigned long long)skipped);
    assert_true(compared > 5000);
    assert_true(agree == compared);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

/* Alg. 3's fixed lists: k/2 slots for the front-most candidates in front
 * order, then k/2 for the back-most. Against the exact dynamic list of the
 * same shaft (sorted front to back): the front half is its prefix, the
 * back half holds distinct members of it, and a shaft with at most k/2
 * candidates has all of them in both halves (padded with RL_NONE). */
static void test_linespace_fixed_lists_hold_the_front_prefix_and_back_members_of_the_exact_list(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=3000");
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 6, 6, 6 } });
    const int k = 6, half = k / 2;
    rl_linespace *dyn = ls_of(grid, (rl_linespace_desc){ .n = 3, .dynamic = true }, NULL);
    rl_linespace *fix = ls_of(grid, (rl_linespace_desc){ .n = 3, .k = k }, NULL);
    rl_linespace_data dd, fd;
    rl_linespace_get_data(dyn, &dd);
    rl_linespace_get_data(fix, &fd);
    assert_int_equal(dd.num_occupied, fd.num_occupied);   /* the same shafts are occupied */
    assert_memory_equal(dd.occupancy, fd.occupancy, 2 * (size_t)dd.num_blocks * dd.occ_words * sizeof(uint64_t));
    uint64_t full = 0, truncated = 0;
    for (uint64_t q = 0; q < dd.num_occupied; ++q) {
        const uint32_t *list = dd.cand + dd.cand_start[q], *slots = fd.cand + q * (uint64_t)k;
        uint32_t m = dd.cand_start[q + 1] - dd.cand_start[q];
        assert_true(m >= 1);
        uint32_t shown = m < (uint32_t)half ? m : (uint32_t)half;
        for (uint32_t i = 0; i < (uint32_t)half; ++i)
            assert_int_equal(slots[i], i < shown ? list[i] : RL_NONE);
        for (uint32_t i = 0; i < (uint32_t)half; ++i) {
            uint32_t id = slots[half + i];
            if (i >= shown) {
                assert_int_equal(id, RL_NONE);
                continue;
            }
            bool member = false;
            for (uint32_t j = 0; j < m; ++j)
                member |= list[j] == id;
            assert_true(member);
            for (uint32_t j = 0; j < i; ++j)
                assert_int_not_equal(slots[half + j], id);
        }
        if (m <= (uint32_t)half) {
            /* All of them in the back half too (as a set). */
            for (uint32_t j = 0; j < m; ++j) {
                bool found = false;
                for (int i = 0; i < half; ++i)
                    found |= slots[half + i] == list[j];
                assert_true(found);
            }
            ++full;
        }
        truncated += m > (uint32_t)k;
    }
    rl_linespace_stats fs;
    rl_linespace_get_stats(fix, &fs);
    assert_int_equal(fs.truncated_shafts, truncated);
    print_message("fixed k=%d against dynamic: %llu of %llu occupied shafts fit a half, %llu truncated\n", k,
                  (unsigned long long)full, (unsigned long long)dd.num_occupied, (unsigned long long)truncated);
    assert_true(full > 0 && truncated > 0);
    rl_linespace_release(fix);
    rl_linespace_release(dyn);
    rl_accel_release(grid);
    rl_scene_release(s);
}

/* The occupancy bits the build sets (one per shaft with triangles) count
 * the empty shafts of the stats, every occupied shaft has a non-empty
 * payload at its rank (and there is no payload beyond them), and each
 * word's rank counts the bits before it (what a load checks). */
static void check_occupancy(rl_linespace *ls)
{
    const uint32_t S = ls->shafts_per_voxel;
    uint64_t set = 0, shafts = (uint64_t)ls->num_blocks * S;
    for (uint64_t g = 0; g < shafts; ++g) {
        uint32_t b = (uint32_t)(g / S), sh = (uint32_t)(g % S);
        if (!rl_ls_shaft_occupied(ls, b, sh))
            continue;
        uint64_t r = rl_ls_shaft_rank(ls, b, sh);
        assert_int_equal(r, set);             /* ranks follow the shaft order */
        ++set;
        if (ls->dynamic && ls->cand_start)
            assert_true(ls->cand_start[r + 1] > ls->cand_start[r]);
        if (!ls->dynamic && ls->cand)
            assert_int_not_equal(ls->cand[r * (uint64_t)ls->k], RL_NONE);
        if (ls->pnmt)
            assert_true(rl_half_to_float(ls->pnmt[r * 16 + RL_LS_PNMT_MAT]) != 0.0f);
        if (ls->preillum)
            assert_true(rl_half_to_float(ls->preillum[r * 8 + 3]) != 0.0f);
    }
    assert_int_equal(set, shafts - ls->stats.empty_shafts);
    assert_int_equal(set, ls->num_occupied);
    if (ls->dynamic && ls->cand_start)
        assert_int_equal(ls->cand_start[set], ls->num_cand);
    if (!ls->dynamic && ls->cand)
        assert_int_equal(ls->num_cand, set * (uint64_t)ls->k);
    /* Each word's rank counts the bits of all words before it. */
    size_t words = (size_t)ls->num_blocks * ls->occ_words;
    uint64_t before = 0;
    for (size_t i = 0; i < words; ++i) {
        assert_int_equal(ls->occupied[2 * i + 1], before);
        before += (uint64_t)__builtin_popcountll(ls->occupied[2 * i]);
    }
    assert_int_equal(before, set);
}

static void test_linespace_occupancy_bits_match_every_payload(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 6, 6, 6 } });
    rl_linespace *all = ls_of(grid,
                              (rl_linespace_desc){ .n = 3, .dynamic = true,
                                                   .payloads = RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM },
                              shade_by_normal);
    rl_linespace *fixed = ls_of(grid, (rl_linespace_desc){ .n = 3, .k = 4 }, NULL);
    rl_linespace *pre = ls_of(grid, (rl_linespace_desc){ .n = 3, .payloads = RL_LS_PREILLUM }, shade_by_normal);
    check_occupancy(all);
    check_occupancy(fixed);
    check_occupancy(pre);
    assert_true(all->stats.empty_shafts > 0 && all->stats.empty_shafts < all->stats.shafts);
    rl_linespace_release(pre);
    rl_linespace_release(fixed);
    rl_linespace_release(all);
    rl_accel_release(grid);
    rl_scene_release(s);
}

/* The shadow tests' shortcuts (no record decoded where a filled shaft's
 * voxel lies inside the ray's interval) give the answers of the full
 * queries, in both origin rules. */
static void test_linespace_shadow_tests_equal_the_full_queries(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 8, 8, 8 } });
    rl_linespace *ls = ls_of(grid,
                             (rl_linespace_desc){ .n = 3, .dynamic = true,
                                                  .payloads = RL_LS_PNMT | RL_LS_PREILLUM },
                             shade_by_normal);
    rl_linespace *pre = ls_of(grid, (rl_linespace_desc){ .n = 3, .payloads = RL_LS_PREILLUM }, shade_by_normal);
    rl_rng r;
    rl_rng_seed(&r, 5, 9);
    int n = 20000 / RAYS_SCALE, occluded = 0;
    for (int rule = 0; rule < 2; ++rule) {
        rl_ls_origin o = rule ? RL_LS_ORIGIN_RECORDS : RL_LS_ORIGIN_EXACT;
        assert_int_equal(rl_linespace_set_origin(ls, o), RL_OK);
        assert_int_equal(rl_linespace_set_origin(pre, o), RL_OK);
        for (int i = 0; i < n; ++i) {
            rl_ray ray = random_ray(&r, d);
            if (i % 2)
                ray.t_max = uniform(&r, 0.1f, 1.0f);   /* segments, as shadow rays */
            rl_ls_surface sf;
            rl_vec3 c;
            bool p = rl_linespace_pnmt_occluded(ls, &ray);
            assert_int_equal(p, rl_linespace_pnmt_intersect(ls, &ray, &sf));
            assert_int_equal(rl_linespace_preillum_occluded(ls, &ray), rl_linespace_preillum(ls, &ray, &c, NULL));
            assert_int_equal(rl_linespace_preillum_occluded(pre, &ray), rl_linespace_preillum(pre, &ray, &c, NULL));
            occluded += p;
        }
    }
    assert_true(occluded > n / 4 && occluded < 2 * n - n / 4);
    assert_int_equal(rl_linespace_set_origin(ls, (rl_ls_origin)7), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_set_origin(NULL, RL_LS_ORIGIN_EXACT), RL_ERR_INVALID_ARG);
    rl_linespace_release(pre);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_scene_release(s);
}

/* The origin rules differ only in the voxel a ray starts in: rays from
 * outside the grid get the same answers; a hit inside the start voxel is
 * exact under EXACT (that voxel's triangles answer) and, under RECORDS, is
 * mostly a stored point instead. */
static void test_linespace_origin_rules_differ_only_in_the_start_voxel(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 8, 8, 8 } });
    const rl_grid *g = rl_accel_grid_state(grid);
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .n = 3, .dynamic = true, .payloads = RL_LS_PNMT }, NULL);
    rl_rng r;
    rl_rng_seed(&r, 3, 4);
    float scale = rl_vmax_comp(rl_aabb_extent(d->bounds));
    int n = 40000 / RAYS_SCALE, outside = 0, in_start = 0, exact_same = 0, records_same = 0;
    for (int i = 0; i < n; ++i) {
        rl_ray ray = random_ray(&r, d);
        rl_ls_surface a, b;
        assert_int_equal(rl_linespace_set_origin(ls, RL_LS_ORIGIN_EXACT), RL_OK);
        bool ha = rl_linespace_pnmt_intersect(ls, &ray, &a);
        assert_int_equal(rl_linespace_set_origin(ls, RL_LS_ORIGIN_RECORDS), RL_OK);
        bool hb = rl_linespace_pnmt_intersect(ls, &ray, &b);
        rl_vec3 start = rl_ray_at(&ray, ray.t_min);
        if (!rl_aabb_contains(d->bounds, start)) {
            ++outside;
            assert_int_equal(ha, hb);
            if (ha)
                assert_true(a.t == b.t && a.material == b.material);
            continue;
        }
        /* The exact hit, if it lies well inside the start voxel. */
        rl_ray full = ray;
        rl_hit h;
        if (ray.t_min < 0.0f || !rl_accel_intersect(bvh, &full, &h))
            continue;
        int c[3];
        rl_grid_cell_of(g, start, c);
        rl_aabb box = rl_grid_cell_bounds(g, c[0], c[1], c[2]);
        float t_exit = INFINITY;
        for (int k = 0; k < 3; ++k) {
            float dk = rl_vget(ray.d, k);
            if (dk != 0.0f) {
                float t = ((dk > 0.0f ? rl_vget(box.max, k) : rl_vget(box.min, k)) - rl_vget(ray.o, k)) / dk;
                t_exit = rl_minf(t_exit, t);
            }
        }
        if (!(h.t < t_exit - 1e-3f * scale / rl_length(ray.d)))
            continue;
        ++in_start;
        float tol = 1e-5f * scale / rl_length(ray.d);
        exact_same += ha && fabsf(a.t - h.t) <= tol;
        records_same += hb && fabsf(b.t - h.t) <= tol;
    }
    print_message("origin rules: %d rays from outside agree; of %d exact hits in the start voxel, EXACT "
                  "gives %d, RECORDS %d\n", outside, in_start, exact_same, records_same);
    assert_true(outside > n / 10);
    assert_true(in_start > n / 100);
    assert_int_equal(exact_same, in_start);
    assert_true(records_same < in_start / 2);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

/* ---- build ------------------------------------------------------------ */

static void test_linespace_build_is_identical_with_1_2_and_7_threads_and_either_page_size(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 5, 5, 5 } });
    for (int dyn = 0; dyn < 2; ++dyn) {
        rl_linespace_desc d = { .n = 3, .k = 6, .dynamic = dyn, .payloads = RL_LS_CANDIDATES | RL_LS_PNMT,
                                .threads = 1 };
        rl_linespace *a = ls_of(grid, d, NULL);
        /* 7 threads on this 2-core machine: blocks finish far out of order,
         * so many are staged before their rank is known. The second build
         * also keeps plain malloc (the first has its arrays and the dynamic
         * lists' arena on huge pages). */
        d.threads = dyn ? 7 : 2;
        d.small_pages = true;
        rl_linespace *b = ls_of(grid, d, NULL);
        rl_linespace_data da, db;
        rl_linespace_get_data(a, &da);
        rl_linespace_get_data(b, &db);
        assert_int_equal(da.num_cand, db.num_cand);
        assert_int_equal(da.num_occupied, db.num_occupied);
        uint64_t occ = da.num_occupied, words = 2 * (uint64_t)da.num_blocks * da.occ_words;
        assert_memory_equal(da.occupancy, db.occupancy, (size_t)words * 8);
        assert_memory_equal(da.cand, db.cand, (size_t)da.num_cand * 4);
        assert_memory_equal(da.pnmt, db.pnmt, (size_t)occ * 32);
        if (dyn)
            assert_memory_equal(da.cand_start, db.cand_start, (size_t)(occ + 1) * 4);
        rl_linespace_stats sa, sb;
        rl_linespace_get_stats(a, &sa);
        rl_linespace_get_stats(b, &sb);
        assert_int_equal(sa.candidates, sb.candidates);
        assert_true(sa.memory_bytes > 0 && sa.memory_bytes == sb.memory_bytes);
        rl_linespace_release(a);
        rl_linespace_release(b);
    }
    rl_accel_release(grid);
    rl_scene_release(s);
}

static bool cancel_at_once(void *user, double done)
{
    (void)done;
    ++*(int *)user;
    return false;
}

static rl_vec3 black(void *user, const rl_ls_surface *s, rl_vec3 dir)
{
    (void)user;
    (void)s;
    (void)dir;
    return rl_v3(0, 0, 0);
}

static void test_linespace_rejects_bad_arguments(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID });
    rl_accel *raw = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_GRID }, &raw), RL_OK);
    rl_linespace *ls = NULL;
    rl_clear_error();
    assert_int_equal(rl_linespace_create(bvh, NULL, &ls), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "GRID"));
    assert_int_equal(rl_linespace_create(raw, NULL, &ls), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(NULL, NULL, &ls), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(grid, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .n = -1 }, &ls), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .n = RL_LS_MAX_N + 1 }, &ls),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .k = 3 }, &ls), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .k = RL_LS_MAX_K + 2 }, &ls),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .payloads = 8 }, &ls),
                     RL_ERR_INVALID_ARG);
    assert_null(ls);
    /* PREILLUM without a shader: refused at commit. */
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .n = 2, .payloads = RL_LS_PREILLUM }, &ls),
                     RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_set_shader(ls, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_linespace_set_shader(ls, black, NULL), RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_OK);
    rl_linespace_release(ls);
    ls = NULL;
    /* Cancel. */
    int calls = 0;
    assert_int_equal(rl_linespace_create(grid,
                                         &(rl_linespace_desc){ .n = 2, .progress = cancel_at_once, .user = &calls },
                                         &ls),
                     RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_ERR_CANCELLED);
    assert_true(calls > 0);
    /* Queries on an uncommitted Line Space and bad rays miss. */
    rl_ray ray = { .o = rl_v3(0.2f, 0.2f, 0.2f), .d = rl_v3(0, 0, 0), .t_max = INFINITY };
    rl_hit h;
    assert_false(rl_linespace_intersect(ls, &ray, &h));
    assert_false(rl_linespace_occluded(NULL, &ray));
    rl_linespace_release(ls);
    rl_linespace_release(NULL);
    rl_accel_release(raw);
    rl_accel_release(grid);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

/* ---- scene and object Line Spaces (Sec. 13.1, 13.2) --------------------- */

static rl_ls_objects *objects_of(const rl_scene *s, rl_ls_objects_desc d)
{
    rl_ls_objects *o = NULL;
    assert_int_equal(rl_ls_objects_create(s, &d, &o), RL_OK);
    if (rl_ls_objects_commit(o) != RL_OK)
        fail_msg("objects commit: %s", rl_last_error());
    return o;
}

static rl_ls_scene *scene_ls_of(const rl_scene *s, rl_ls_scene_desc d)
{
    rl_ls_scene *ls = NULL;
    if (rl_ls_scene_create(s, &d, &ls) != RL_OK)
        fail_msg("scene Line Space create: %s", rl_last_error());
    if (rl_ls_scene_commit(ls) != RL_OK)
        fail_msg("scene Line Space commit: %s", rl_last_error());
    return ls;
}

typedef bool (*closest_fn)(const void *st, rl_ray *ray, rl_hit *hit);
typedef bool (*occluded_fn)(const void *st, const rl_ray *ray);
static bool objects_closest(const void *st, rl_ray *ray, rl_hit *hit) { return rl_ls_objects_intersect(st, ray, hit); }
static bool objects_occl(const void *st, const rl_ray *ray) { return rl_ls_objects_occluded(st, ray); }
static bool scene_closest(const void *st, rl_ray *ray, rl_hit *hit) { return rl_ls_scene_intersect(st, ray, hit); }
static bool scene_occl(const void *st, const rl_ray *ray) { return rl_ls_scene_occluded(st, ray); }

/* Same triangle, object and t (bit for bit: the same watertight test on
 * the same vertices) and the same shadow answer as the reference on
 * num_rays random rays; ref NULL: the BVH, or brute force for t_min < 0. */
static int agree_exactly(const char *what, const rl_scene *s, const void *st, closest_fn closest,
                         occluded_fn occluded, const rl_accel *ref_fixed, int num_rays, uint64_t seed)
{
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *brute = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BRUTE });
    rl_rng r;
    rl_rng_seed(&r, seed, 5);
    int hits = 0;
    for (int i = 0; i < num_rays; ++i) {
        rl_ray ray = random_ray(&r, d);
        rl_ray rb = ray, rl = ray;
        rl_hit hb, hl;
        const rl_accel *ref = ref_fixed ? ref_fixed : reference(bvh, brute, &ray);
        bool b = rl_accel_intersect(ref, &rb, &hb), l = closest(st, &rl, &hl);
        hits += b;
        if (b != l || (b && (hb.triangle != hl.triangle || hb.object != hl.object || hb.t != hl.t ||
                             rb.t_max != rl.t_max)))
            fail_msg("%s ray %d o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g) t=(%g %g): ref %d tri %u t %.9g, "
                     "ls %d tri %u t %.9g",
                     what, i, (double)ray.o.x, (double)ray.o.y, (double)ray.o.z, (double)ray.d.x, (double)ray.d.y,
                     (double)ray.d.z, (double)ray.t_min, (double)ray.t_max, b, hb.triangle, (double)hb.t, l,
                     hl.triangle, (double)hl.t);
        if (rl_accel_occluded(ref, &ray) != occluded(st, &ray))
            fail_msg("%s ray %d: occluded differs", what, i);
    }
    rl_accel_release(brute);
    rl_accel_release(bvh);
    assert_true(hits > num_rays / 10);
    return hits;
}

/* A scene of several objects: one mesh instanced five times (moved,
 * rotated, scaled, mirrored, squashed to a thousandth in y: the scene
 * refuses singular transforms) beside a floor. */
static rl_scene *instanced_scene(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, teapot, floor, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "teapot", "triangles=800", mat, &teapot), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "quad", NULL, mat, &floor), RL_OK);
    rl_mat4 big = rl_mat4_scale(rl_v3(6.0f, 6.0f, 6.0f));
    assert_int_equal(rl_scene_add_node(s, 0, "floor", &big, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, floor), RL_OK);
    rl_mat4 t[5];
    t[0] = rl_mat4_translate(rl_v3(-1.5f, 0.0f, 0.0f));
    rl_mat4 rot = rl_mat4_rotate(rl_normalize(rl_v3(1.0f, 2.0f, 0.5f)), 0.7f), tr = rl_mat4_translate(rl_v3(1.5f, 0.3f, 0.2f));
    t[1] = rl_mat4_mul(&tr, &rot);
    rl_mat4 sc = rl_mat4_scale(rl_v3(0.5f, 1.5f, 0.8f)), tr2 = rl_mat4_translate(rl_v3(0.0f, 0.2f, 1.8f));
    t[2] = rl_mat4_mul(&tr2, &sc);
    rl_mat4 mir = rl_mat4_scale(rl_v3(-1.0f, 1.0f, 1.0f)), tr3 = rl_mat4_translate(rl_v3(0.0f, 0.5f, -1.8f));
    t[3] = rl_mat4_mul(&tr3, &mir);
    rl_mat4 flat = rl_mat4_scale(rl_v3(1.0f, 1e-3f, 1.0f)), tr4 = rl_mat4_translate(rl_v3(2.0f, 1.0f, 2.0f));
    t[4] = rl_mat4_mul(&tr4, &flat);
    for (int i = 0; i < 5; ++i) {
        assert_int_equal(rl_scene_add_node(s, 0, "teapot", &t[i], &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, teapot), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static void test_linespace_objects_equal_the_bvh_on_instanced_objects(void **state)
{
    (void)state;
    rl_scene *s = instanced_scene();
    rl_ls_objects *o = objects_of(s, (rl_ls_objects_desc){ .n = 3, .res = 4 });
    rl_ls_objects_stats st;
    rl_ls_objects_get_stats(o, &st);
    /* Floor and five teapots: the first four share one Line Space; the
     * squashed one shares it too unless the inverse's factor 1000 pushed
     * its object-space vertices beyond the sharing tolerance. */
    assert_int_equal(st.objects, 6);
    assert_true(st.linespaces == 2 || st.linespaces == 3);
    assert_int_equal(st.world_space, 0);
    int hits = agree_exactly("objects/instanced", s, o, objects_closest, objects_occl, NULL, 15000 / RAYS_SCALE, 11);
    print_message("object Line Space, instanced teapots: %d hits, %u Line Spaces for %u objects, %.1f MiB\n",
                  hits, st.linespaces, st.objects, st.memory_bytes / 1048576.0);
    rl_ls_objects_release(o);
    rl_scene_release(s);
    /* The built-ins: several objects in a box (teapot, blocks, bunny). */
    s = builtin("cornell-teapot", "triangles=5000");
    o = objects_of(s, (rl_ls_objects_desc){ .n = 3, .res = 4 });
    agree_exactly("objects/cornell-teapot", s, o, objects_closest, objects_occl, NULL, 8000 / RAYS_SCALE, 12);
    rl_ls_objects_release(o);
    rl_scene_release(s);
}

/* The thesis' point for object Line Spaces (Sec. 13.2): an object moves
 * without a rebuild. Our committed scenes are immutable, so the same mesh
 * at five places is the test: one Line Space, built once, answers all of
 * them exactly (above); here also moved far from the origin. */
static void test_linespace_objects_share_one_line_space_across_moved_instances(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "sphere", NULL, mat, &mesh), RL_OK);
    for (int i = 0; i < 8; ++i) {
        rl_mat4 rot = rl_mat4_rotate(rl_v3(0.0f, 1.0f, 0.0f), 0.4f * (float)i);
        rl_mat4 tr = rl_mat4_translate(rl_v3(100.0f + 2.5f * (float)i, 50.0f, -3.0f * (float)(i % 3)));
        rl_mat4 t = rl_mat4_mul(&tr, &rot);
        assert_int_equal(rl_scene_add_node(s, 0, "ball", &t, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    }
    assert_int_equal(rl_scene_commit(s), RL_OK);
    rl_ls_objects *o = objects_of(s, (rl_ls_objects_desc){ .n = 4, .res = 3 });
    rl_ls_objects_stats st;
    rl_ls_objects_get_stats(o, &st);
    assert_int_equal(st.objects, 8);
    assert_int_equal(st.linespaces, 1);
    assert_int_equal(st.world_space, 0);
    agree_exactly("objects/moved spheres", s, o, objects_closest, objects_occl, NULL, 10000 / RAYS_SCALE, 13);
    rl_ls_objects_release(o);
    rl_scene_release(s);
}

static void test_linespace_scene_signatures_are_conservative_and_answers_exact(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell-teapot", "triangles=5000");
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *grid = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 8, 8, 8 } });
    rl_linespace *ls = ls_of(grid, (rl_linespace_desc){ .n = 3, .dynamic = true }, NULL);
    rl_ls_objects *o = objects_of(s, (rl_ls_objects_desc){ .n = 3, .res = 4 });
    rl_ls_scene *sb = scene_ls_of(s, (rl_ls_scene_desc){ .n = 8, .cells = 32, .inner.accel = bvh });
    rl_ls_scene_stats st;
    rl_ls_scene_get_stats(sb, &st);
    assert_int_equal(st.shafts, 15u * 8 * 8 * 8 * 8);
    /* Some shafts have empty stretches, else the signature is useless. */
    assert_true(st.filled_bits > 0 && st.filled_bits < st.shafts * 64u * 9 / 10);
    int hits = agree_exactly("scene/bvh", s, sb, scene_closest, scene_occl, bvh, 15000 / RAYS_SCALE, 21);
    print_message("scene Line Space: %d hits, %.1f %% of the signature bits set, %u filled cells\n", hits,
                  100.0 * (double)st.filled_bits / ((double)st.shafts * 64.0), st.filled_cells);
    /* Coarse and odd parameters, the per-voxel and the object Line Spaces
     * inside: each gives its inner structure's answer (the BVH's). */
    rl_ls_scene *sv = scene_ls_of(s, (rl_ls_scene_desc){ .n = 3, .segments = 5, .cells = 7, .inner.linespace = ls });
    agree_exactly("scene/per-voxel", s, sv, scene_closest, scene_occl, NULL, 8000 / RAYS_SCALE, 22);
    rl_ls_scene *so = scene_ls_of(s, (rl_ls_scene_desc){ .n = 1, .segments = 64, .cells = 64, .inner.objects = o });
    agree_exactly("scene/objects", s, so, scene_closest, scene_occl, NULL, 8000 / RAYS_SCALE, 23);
    /* Conservative: every hit of a ray through the box lies in a set
     * segment of its shaft (checked from the hit point itself). */
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_rng r;
    rl_rng_seed(&r, 24, 1);
    rl_aabb box = d->bounds;
    for (int i = 0; i < 5000 / RAYS_SCALE; ++i) {
        rl_vec3 a = random_in(&r, box), b = random_in(&r, box);
        rl_ray ray = { a, 0.0f, rl_sub(b, a), 1.0f };
        rl_hit h;
        if (rl_accel_intersect(bvh, &ray, &h) != rl_ls_scene_occluded(sb, &(rl_ray){ a, 0.0f, rl_sub(b, a), 1.0f }))
            fail_msg("segment %d: the scene Line Space's shadow answer differs", i);
    }
    rl_ls_scene_release(so);
    rl_ls_scene_release(sv);
    rl_ls_scene_release(sb);
    rl_ls_objects_release(o);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_accel_release(bvh);
    rl_scene_release(s);
}

/* A scene of one flat quad (a degenerate box axis) and one of a single
 * tiny triangle far from the origin: both structures still exact. */
static void test_linespace_scene_and_objects_handle_flat_and_tiny_scenes(void **state)
{
    (void)state;
    for (int k = 0; k < 2; ++k) {
        rl_scene *s = NULL;
        assert_int_equal(rl_scene_create(&s), RL_OK);
        rl_material m = rl_material_default();
        uint32_t mat, mesh, node;
        assert_int_equal(rl_scene_add_material(s, &m, &mat), RL_OK);
        if (k == 0) {
            assert_int_equal(rl_scene_add_generated(s, "quad", NULL, mat, &mesh), RL_OK);
        } else {
            rl_vec3 p[3] = { rl_v3(1000.0f, 2000.0f, 0.0f), rl_v3(1000.001f, 2000.0f, 0.0f),
                             rl_v3(1000.0f, 2000.001f, 0.0005f) };
            uint32_t idx[3] = { 0, 1, 2 };
            rl_mesh_desc md = { .num_vertices = 3, .positions = p, .num_triangles = 1, .indices = idx, .material = mat };
            assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
        }
        assert_int_equal(rl_scene_add_node(s, 0, "it", NULL, &node), RL_OK);
        assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
        assert_int_equal(rl_scene_commit(s), RL_OK);
        rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
        rl_ls_objects *o = objects_of(s, (rl_ls_objects_desc){ .n = 3 });
        rl_ls_scene *sl = scene_ls_of(s, (rl_ls_scene_desc){ .n = 4, .inner.objects = o });
        const char *what = k == 0 ? "flat quad" : "tiny triangle";
        agree_exactly(what, s, o, objects_closest, objects_occl, NULL, 5000 / RAYS_SCALE, 31 + (uint64_t)k);
        agree_exactly(what, s, sl, scene_closest, scene_occl, NULL, 5000 / RAYS_SCALE, 33 + (uint64_t)k);
        rl_ls_scene_release(sl);
        rl_ls_objects_release(o);
        rl_accel_release(bvh);
        rl_scene_release(s);
    }
}

static void test_linespace_scene_and_objects_reject_bad_arguments(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL), *other = builtin("cornell", NULL), *raw = NULL;
    assert_int_equal(rl_scene_create(&raw), RL_OK);
    rl_accel *bvh = accel_of(s, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *bvh_other = accel_of(other, (rl_accel_desc){ .kind = RL_ACCEL_BVH });
    rl_accel *uncommitted = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &uncommitted), RL_OK);
    rl_ls_objects *o = NULL;
    assert_int_equal(rl_ls_objects_create(NULL, NULL, &o), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_objects_create(raw, NULL, &o), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_objects_create(s, &(rl_ls_objects_desc){ .n = RL_LS_MAX_N + 1 }, &o), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_objects_create(s, &(rl_ls_objects_desc){ .res = -2 }, &o), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_objects_create(s, &(rl_ls_objects_desc){ .res = RL_LS_OBJECT_MAX_RES + 1 }, &o),
                     RL_ERR_INVALID_ARG);
    assert_null(o);
    /* Uncommitted: queries miss, and it cannot serve as an inner structure. */
    assert_int_equal(rl_ls_objects_create(s, &(rl_ls_objects_desc){ .n = 2, .res = 2 }, &o), RL_OK);
    rl_ray ray = { rl_v3(0.1f, 0.2f, 0.3f), 0.0f, rl_v3(0, 1, 0), INFINITY };
    rl_hit h;
    assert_false(rl_ls_objects_intersect(o, &ray, &h));
    rl_ls_scene *sl = NULL;
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .inner.objects = o }, &sl), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_objects_commit(o), RL_OK);
    assert_int_equal(rl_ls_objects_commit(o), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ 0 }, &sl), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "exactly one"));
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .inner.accel = bvh, .inner.objects = o }, &sl),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .inner.accel = uncommitted }, &sl), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .inner.accel = bvh_other }, &sl), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "another scene"));
    assert_int_equal(rl_ls_scene_create(raw, &(rl_ls_scene_desc){ .inner.accel = bvh }, &sl), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .n = RL_LS_SCENE_MAX_N + 1, .inner.accel = bvh }, &sl),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .segments = 65, .inner.accel = bvh }, &sl),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_ls_scene_create(s, &(rl_ls_scene_desc){ .cells = -1, .inner.accel = bvh }, &sl),
                     RL_ERR_INVALID_ARG);
    assert_null(sl);
    /* Bad rays miss; signatures beyond the last shaft are empty. */
    sl = scene_ls_of(s, (rl_ls_scene_desc){ .n = 2, .inner.objects = o });
    rl_ray bad = { rl_v3(0.1f, 0.2f, 0.3f), 0.0f, rl_v3(0, 0, 0), INFINITY };
    assert_false(rl_ls_scene_intersect(sl, &bad, &h));
    assert_false(rl_ls_scene_occluded(sl, &bad));
    assert_false(rl_ls_objects_occluded(o, &bad));
    bad.d = rl_v3(NAN, 1, 0);
    assert_false(rl_ls_scene_occluded(sl, &bad));
    assert_int_equal(rl_ls_scene_signature(sl, 15u * 16), 0);
    rl_ls_scene_release(sl);
    rl_ls_scene_release(NULL);
    rl_ls_objects_release(o);
    rl_ls_objects_release(NULL);
    rl_accel_release(uncommitted);
    rl_accel_release(bvh_other);
    rl_accel_release(bvh);
    rl_scene_release(raw);
    rl_scene_release(other);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_linespace_index_mapping_is_a_bijection_for_n_1_to_6),
        cmocka_unit_test(test_linespace_shaft_of_segment_agrees_with_the_mapping),
        cmocka_unit_test(test_linespace_enumerated_hits_equal_the_ray_triangle_test),
        cmocka_unit_test(test_half_conversion_rounds_to_nearest_even_and_round_trips),
        cmocka_unit_test(test_linespace_dynamic_candidates_equal_the_bvh_on_cornell_teapot),
        cmocka_unit_test(test_linespace_dynamic_candidates_equal_the_bvh_on_cornell),
        cmocka_unit_test(test_linespace_fixed_lists_report_truncation_and_return_only_true_hits),
        cmocka_unit_test(test_linespace_pnmt_and_preillum_occlusion_agree_at_the_measured_rate),
        cmocka_unit_test(test_linespace_pnmt_records_decode_to_unit_normals_in_the_voxel),
        cmocka_unit_test(test_linespace_pnmt_normals_rebuild_n_z_with_its_sign),
        cmocka_unit_test(test_linespace_pnmt_records_are_the_midpoint_rays_first_hits),
        cmocka_unit_test(test_linespace_fixed_lists_hold_the_front_prefix_and_back_members_of_the_exact_list),
        cmocka_unit_test(test_linespace_occupancy_bits_match_every_payload),
        cmocka_unit_test(test_linespace_shadow_tests_equal_the_full_queries),
        cmocka_unit_test(test_linespace_origin_rules_differ_only_in_the_start_voxel),
        cmocka_unit_test(test_linespace_build_is_identical_with_1_2_and_7_threads_and_either_page_size),
        cmocka_unit_test(test_linespace_rejects_bad_arguments),
        cmocka_unit_test(test_linespace_objects_equal_the_bvh_on_instanced_objects),
        cmocka_unit_test(test_linespace_objects_share_one_line_space_across_moved_instances),
        cmocka_unit_test(test_linespace_scene_signatures_are_conservative_and_answers_exact),
        cmocka_unit_test(test_linespace_scene_and_objects_handle_flat_and_tiny_scenes),
        cmocka_unit_test(test_linespace_scene_and_objects_reject_bad_arguments),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
