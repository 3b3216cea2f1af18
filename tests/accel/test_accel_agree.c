/* test_accel_agree.c: every acceleration structure answers every ray the
 * same: BVH, grid and Embree against each other and against brute force.
 *
 * Scenes are the built-ins at small sizes (cornell, spheres, cornell-teapot,
 * city); rays are 100k random rays per scene (origins uniform in the bounds
 * enlarged by 10 % per side, directions uniform on the sphere) plus the
 * pixel-centre rays of the scene's camera, and 50k random finite segments
 * for occlusion. Brute force, O(N) per ray, takes a prefix of the rays sized
 * to a fixed triangle-test budget so that the ASan build stays fast.
 *
 * Agreement, with the BVH as the reference:
 *   - our kinds (grid, brute) share the watertight test and the tie rule
 *     (lowest triangle ID wins, accel.c): same hit/miss, same triangle and
 *     t within 1e-4 relative, with no exceptions;
 *   - Embree: the same, except documented ties when it reports another
 *     triangle at the same t (within 1e-6 relative): a coplanar tie when our
 *     watertight test hits that triangle there too (overlapping faces), an
 *     edge tie when the ray meets it on its boundary (barycentric within
 *     1e-5 of an edge: shared edges and vertices). Edge ties must stay below
 *     0.1 % of the rays, coplanar ties too unless the scene overlaps faces
 *     (see cases[]); other mismatches must be 0.
 *   - Occlusion: the same answers; for Embree a differing answer is a tie
 *     only when the BVH's hit lies at the segment's end or on an edge.
 * Distances are compared relative to at least a fraction of the scene size
 * (same_t). The counts go to the log with print_message. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "accel/accel_internal.h"
#include "rl/rl_accel.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"
#include "rl/rl_timer.h"

#define RANDOM_RAYS 100000
#define SEGMENTS 50000
#define CAMERA_W 160
#define CAMERA_H 120
/* Ray-triangle tests per query type and scene given to brute force (about
 * 150 M/s in Release): in the Release build enough for every ray on cornell,
 * spheres and cornell-teapot and ~25k rays on city, in the sanitizer build a
 * prefix that keeps the test under ~20 s. test_bvh.c runs brute force on the
 * full 100k rays of every scene at smaller sizes. */
#ifdef NDEBUG
#define BRUTE_TESTS 1.1e9
#else
#define BRUTE_TESTS 4000000.0
#endif
#define T_REL 1e-4               /* t agreement for the same triangle ... */
#define T_FLOOR 1e-3             /* ... relative to at least 0.1 % of the scene */
#define TIE_REL 1e-6             /* t agreement that makes another triangle a tie ... */
#define TIE_FLOOR 1.0            /* ... relative to at least the scene diagonal */
#define EDGE_EPS 1e-5f           /* barycentric distance to an edge */
#define MAX_EDGE_TIES 1e-3       /* of the rays */

/* max_coplanar: the fraction of rays allowed to end in a coplanar tie. Ties
 * are rare (0.1 %) except where the scene itself overlaps coplanar faces:
 * cornell's blocks have bottom faces lying in the floor and the city's
 * sidewalks lie in the ground plane; there about 0.4 % of the random rays
 * (those from below the floor) meet both at one t, so we allow 1 %. */
typedef struct scene_case { const char *name, *params; double max_coplanar; } scene_case;
static const scene_case cases[] = {
    { "cornell", NULL, 1e-2 },
    { "spheres", NULL, 1e-3 },
    { "cornell-teapot", "triangles=2000", 1e-3 },
    { "city", "blocks=1", 1e-2 },
};

/* ---- rays ------------------------------------------------------------------- */

static rl_vec3 random_in(rl_rng *rng, rl_aabb box)
{
    rl_vec3 e = rl_aabb_extent(box);
    return rl_v3(box.min.x + e.x * rl_rng_float(rng), box.min.y + e.y * rl_rng_float(rng),
                 box.min.z + e.z * rl_rng_float(rng));
}

static rl_vec3 random_direction(rl_rng *rng)
{
    float z = 1.0f - 2.0f * rl_rng_float(rng);
    float r = sqrtf(fmaxf(0.0f, 1.0f - z * z)), phi = 2.0f * RL_PI * rl_rng_float(rng);
    return rl_v3(r * cosf(phi), r * sinf(phi), z);
}

static rl_aabb enlarged(rl_aabb b)
{
    rl_vec3 m = rl_scale(rl_aabb_extent(b), 0.1f);
    b.min = rl_sub(b.min, m);
    b.max = rl_add(b.max, m);
    return b;
}

/* RANDOM_RAYS random rays, then the camera's pixel-centre rays. */
static rl_ray *make_rays(const rl_scene *s, uint64_t seed, size_t *count)
{
    size_t n = RANDOM_RAYS + CAMERA_W * CAMERA_H;
    rl_ray *rays = malloc(n * sizeof *rays);
    assert_non_null(rays);
    rl_aabb box = enlarged(rl_scene_get_data(s)->bounds);
    rl_rng rng;
    rl_rng_seed(&rng, seed, 1);
    for (size_t i = 0; i < RANDOM_RAYS; ++i)
        rays[i] = (rl_ray){ .o = random_in(&rng, box), .d = random_direction(&rng),
                            .t_min = 0.0f, .t_max = INFINITY };
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = CAMERA_W;
    cam.height = CAMERA_H;
    rl_camera_frame f = rl_camera_frame_make(&cam);
    for (int y = 0; y < CAMERA_H; ++y)
        for (int x = 0; x < CAMERA_W; ++x)
            rays[RANDOM_RAYS + (size_t)y * CAMERA_W + x] =
                rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f);
    *count = n;
    return rays;
}

/* Segments between two random points of the enlarged bounds: t in (0, 1). */
static rl_ray *make_segments(const rl_scene *s, uint64_t seed)
{
    rl_ray *segs = malloc(SEGMENTS * sizeof *segs);
    assert_non_null(segs);
    rl_aabb box = enlarged(rl_scene_get_data(s)->bounds);
    rl_rng rng;
    rl_rng_seed(&rng, seed, 2);
    for (size_t i = 0; i < SEGMENTS; ++i) {
        rl_vec3 a = random_in(&rng, box), b = random_in(&rng, box);
        segs[i] = (rl_ray){ .o = a, .d = rl_sub(b, a), .t_min = 0.0f, .t_max = 1.0f };
    }
    return segs;
}

/* ---- queries ------------------------------------------------------------------ */

static rl_accel *build(const rl_scene *s, rl_accel_kind kind)
{
    rl_accel *a = NULL;
    if (rl_accel_create(s, &(rl_accel_desc){ .kind = kind }, &a) != RL_OK ||
        rl_accel_commit(a) != RL_OK)
        fail_msg("%s: %s", rl_accel_kind_name(kind), rl_last_error());
    return a;
}

static void intersect_all(const rl_accel *a, const rl_ray *rays, rl_hit *hits, size_t n)
{
    long long count = (long long)n;
#pragma omp parallel for schedule(dynamic, 1024)
    for (long long i = 0; i < count; ++i) {
        rl_ray r = rays[i];
        rl_accel_intersect(a, &r, &hits[i]);
    }
}

static void occluded_all(const rl_accel *a, const rl_ray *rays, bool *occ, size_t n)
{
    long long count = (long long)n;
#pragma omp parallel for schedule(dynamic, 1024)
    for (long long i = 0; i < count; ++i)
        occ[i] = rl_accel_occluded(a, &rays[i]);
}

/* ---- comparison --------------------------------------------------------------- */

typedef struct tally {
    size_t rays, hits;
    size_t coplanar_ties;   /* Embree's triangle hit by our test at the same t */
    size_t edge_ties;       /* Embree's triangle met on its boundary at the same t */
    size_t mismatches;
    double ms;              /* build + queries */
    char first[240];
} tally;

static void mismatch(tally *c, size_t i, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
static void mismatch(tally *c, size_t i, const char *fmt, ...)
{
    if (c->mismatches++ == 0) {
        int k = snprintf(c->first, sizeof c->first, "ray %zu: ", i);
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(c->first + k, sizeof c->first - (size_t)k, fmt, ap);
        va_end(ap);
    }
}

typedef struct compare_ctx {
    const rl_scene_data *data;
    double diagonal;        /* of the scene bounds */
    bool ties_allowed;      /* only for Embree */
} compare_ctx;

/* |a - b| <= rel * max(|a|, |b|, floor · diagonal / |d|). Embree's t carries
 * an absolute error of a few ulps of the scene's coordinates rather than of
 * t, so near a ray's origin distances are compared relative to a fraction of
 * the scene size (in units of the ray's parameter). */
static bool same_t(const compare_ctx *x, const rl_ray *r, double a, double b, double rel,
                   double floor)
{
    double scale = floor * x->diagonal / (double)rl_length(r->d);
    return fabs(a - b) <= rel * fmax(fmax(fabs(a), fabs(b)), scale);
}

static bool on_boundary(float u, float v)
{
    return u < EDGE_EPS || v < EDGE_EPS || 1.0f - u - v < EDGE_EPS;
}

/* Our watertight test of ray against one triangle, over the ray's segment. */
static bool watertight_t(const rl_scene_data *d, const rl_ray *ray, uint32_t tri, float *t)
{
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    const uint32_t *ix = d->indices + 3 * (size_t)tri;
    float u, v;
    return rl_triangle_intersect_watertight(&w, d->positions[ix[0]], d->positions[ix[1]],
                                            d->positions[ix[2]], ray->t_min, ray->t_max, t, &u, &v);
}

static void compare_hits(const compare_ctx *x, const rl_ray *rays, const rl_hit *ref,
                         const rl_hit *got, size_t n, tally *c)
{
    for (size_t i = 0; i < n; ++i) {
        bool hr = ref[i].triangle != RL_ID_NONE, hg = got[i].triangle != RL_ID_NONE;
        float t_other;
        c->rays++;
        c->hits += hg;
        if (hr != hg) {
            mismatch(c, i, "bvh %s (t = %.9g), this one %s (t = %.9g, u = %g, v = %g)",
                     hr ? "hits" : "misses", hr ? (double)ref[i].t : 0.0, hg ? "hits" : "misses",
                     hg ? (double)got[i].t : 0.0, hg ? (double)got[i].u : 0.0,
                     hg ? (double)got[i].v : 0.0);
        } else if (!hr) {
            continue;
        } else if (ref[i].triangle == got[i].triangle) {
            if (!same_t(x, &rays[i], ref[i].t, got[i].t, T_REL, T_FLOOR) ||
                ref[i].object != got[i].object)
                mismatch(c, i, "triangle %u: t %.9g vs bvh %.9g, object %u vs %u",
                         got[i].triangle, (double)got[i].t, (double)ref[i].t, got[i].object,
                         ref[i].object);
        } else if (x->ties_allowed && watertight_t(x->data, &rays[i], got[i].triangle, &t_other) &&
                   same_t(x, &rays[i], t_other, ref[i].t, TIE_REL, TIE_FLOOR)) {
            c->coplanar_ties++;
        } else if (x->ties_allowed && on_boundary(got[i].u, got[i].v) &&
                   same_t(x, &rays[i], got[i].t, ref[i].t, TIE_REL, TIE_FLOOR)) {
            c->edge_ties++;   /* our test put the ray on the neighbour's side */
        } else {
            mismatch(c, i, "triangle %u at t = %.9g (u = %g, v = %g), bvh triangle %u at t = %.9g",
                     got[i].triangle, (double)got[i].t, (double)got[i].u, (double)got[i].v,
                     ref[i].triangle, (double)ref[i].t);
        }
    }
}

static void compare_occlusion(const compare_ctx *x, const rl_ray *segs, const bool *ref,
                              const bool *got, const rl_hit *closest, size_t n, tally *c)
{
    for (size_t i = 0; i < n; ++i) {
        c->rays++;
        c->hits += got[i];
        if (ref[i] == got[i])
            continue;
        /* The documented tie for segments: the only hit sits at an end of
         * the segment or on a triangle's boundary, where Embree promises
         * nothing. */
        const rl_hit *h = &closest[i];
        bool at_end = h->triangle != RL_ID_NONE &&
                      same_t(x, &segs[i], h->t, segs[i].t_max, TIE_REL, TIE_FLOOR);
        bool at_edge = h->triangle != RL_ID_NONE && on_boundary(h->u, h->v);
        if (x->ties_allowed && (at_end || at_edge))
            c->edge_ties++;
        else
            mismatch(c, i, "occluded %d, bvh %d (bvh closest: triangle %u, t = %.9g)", got[i],
                     ref[i], h->triangle, (double)h->t);
    }
}

static void report(const char *scene, const char *what, rl_accel_kind kind, const tally *c,
                   double max_coplanar)
{
    print_message("%-14s %-8s %-6s %6zu rays %6zu hits %4zu coplanar + %zu edge ties, "
                  "%zu mismatches (%.0f ms)\n", scene, what, rl_accel_kind_name(kind), c->rays,
                  c->hits, c->coplanar_ties, c->edge_ties, c->mismatches, c->ms);
    if (c->mismatches)
        fail_msg("%s, %s, %s vs bvh: %zu mismatches; first: %s", scene, what,
                 rl_accel_kind_name(kind), c->mismatches, c->first);
    if ((double)c->edge_ties > MAX_EDGE_TIES * (double)c->rays)
        fail_msg("%s, %s, %s vs bvh: %zu edge ties in %zu rays are not rare", scene, what,
                 rl_accel_kind_name(kind), c->edge_ties, c->rays);
    if ((double)c->coplanar_ties > max_coplanar * (double)c->rays)
        fail_msg("%s, %s, %s vs bvh: %zu coplanar ties in %zu rays are more than %g %%", scene,
                 what, rl_accel_kind_name(kind), c->coplanar_ties, c->rays, 100.0 * max_coplanar);
}

/* ---- the test -------------------------------------------------------------------- */

static void agree_on_scene(const scene_case *sc, uint64_t seed)
{
    rl_scene *s = NULL;
    if (rl_scene_create_builtin(sc->name, sc->params, &s) != RL_OK)
        fail_msg("%s: %s", sc->name, rl_last_error());
    const rl_scene_data *d = rl_scene_get_data(s);
    size_t n = 0;
    rl_ray *rays = make_rays(s, seed, &n);
    rl_ray *segs = make_segments(s, seed);
    rl_hit *ref = calloc(n, sizeof *ref), *got = calloc(n, sizeof *got);
    rl_hit *seg_closest = calloc(SEGMENTS, sizeof *seg_closest);
    bool *occ_ref = calloc(SEGMENTS, sizeof *occ_ref), *occ_got = calloc(SEGMENTS, sizeof *occ_got);
    assert_true(ref && got && seg_closest && occ_ref && occ_got);

    rl_accel *bvh = build(s, RL_ACCEL_BVH);
    intersect_all(bvh, rays, ref, n);
    occluded_all(bvh, segs, occ_ref, SEGMENTS);
    intersect_all(bvh, segs, seg_closest, SEGMENTS);
    /* The BVH agrees with itself: occluded exactly when a closest hit exists. */
    for (size_t i = 0; i < SEGMENTS; ++i)
        if (occ_ref[i] != (seg_closest[i].triangle != RL_ID_NONE))
            fail_msg("%s: bvh segment %zu: occluded %d but closest hit %u", sc->name, i, occ_ref[i],
                     seg_closest[i].triangle);
    rl_accel_release(bvh);

    const rl_accel_kind others[] = { RL_ACCEL_GRID, RL_ACCEL_EMBREE, RL_ACCEL_BRUTE };
    for (size_t k = 0; k < sizeof others / sizeof others[0]; ++k) {
        rl_accel_kind kind = others[k];
        if (!rl_accel_kind_available(kind))
            continue;
        compare_ctx x = { .data = d, .diagonal = rl_length(rl_aabb_extent(d->bounds)),
                          .ties_allowed = kind == RL_ACCEL_EMBREE };
        size_t n_rays = n, n_segs = SEGMENTS;
        if (kind == RL_ACCEL_BRUTE) {
            /* A prefix within the test budget: random rays first, so even
             * the big scenes get a few hundred of them. */
            double fit = BRUTE_TESTS / (double)d->num_triangles;
            n_rays = fit < (double)n ? (size_t)fit : n;
            n_segs = fit < (double)SEGMENTS ? (size_t)fit : SEGMENTS;
        }
        tally hit_tally = { 0 }, occ_tally = { 0 };
        rl_timer timer;
        rl_timer_start(&timer);
        rl_accel *a = build(s, kind);
        intersect_all(a, rays, got, n_rays);
        hit_tally.ms = rl_timer_ms(&timer);
        rl_timer_start(&timer);
        occluded_all(a, segs, occ_got, n_segs);
        occ_tally.ms = rl_timer_ms(&timer);
        rl_accel_release(a);
        compare_hits(&x, rays, ref, got, n_rays, &hit_tally);
        compare_occlusion(&x, segs, occ_ref, occ_got, seg_closest, n_segs, &occ_tally);
        report(sc->name, "closest", kind, &hit_tally, sc->max_coplanar);
        report(sc->name, "occluded", kind, &occ_tally, sc->max_coplanar);
    }
    free(rays);
    free(segs);
    free(ref);
    free(got);
    free(seg_closest);
    free(occ_ref);
    free(occ_got);
    rl_scene_release(s);
}

static void test_accels_agree_on_cornell(void **state)
{
    (void)state;
    agree_on_scene(&cases[0], 101);
}

static void test_accels_agree_on_spheres(void **state)
{
    (void)state;
    agree_on_scene(&cases[1], 102);
}

static void test_accels_agree_on_cornell_teapot(void **state)
{
    (void)state;
    agree_on_scene(&cases[2], 103);
}

static void test_accels_agree_on_city(void **state)
{
    (void)state;
    agree_on_scene(&cases[3], 104);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_accels_agree_on_cornell),
        cmocka_unit_test(test_accels_agree_on_spheres),
        cmocka_unit_test(test_accels_agree_on_cornell_teapot),
        cmocka_unit_test(test_accels_agree_on_city),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
