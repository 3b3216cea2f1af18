/* The Line Space on OpenGL (src/gl/gl_linespace*.c, Schröder 2017, Sec. 7):
 * the GPU build against the CPU build (the same arrays: voxel slots,
 * occupancy bits and ranks, candidate lists in the same order, list starts;
 * dynamic lists and fixed k), the GLSL walk on the uploaded and on the
 * GPU-built structure against linespace_query.c ray for ray, and clear
 * errors for limits and what the GPU build does not make. Runs on llvmpipe;
 * without a GL 4.5 context the cases skip. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "gl/gl_context.h"
#include "gl/gl_linespace.h"
#include "rl/rl.h"
#include "rl/rl_gl.h"
#include "rl/rl_linespace.h"
#include "rl/rl_rng.h"

#include "gl_fixtures.h"


#define RAYS 1024

static rl_scene *builtin(const char *name, const char *params)
{
    rl_scene *s = NULL;
    if (rl_scene_create_builtin(name, params, &s) != RL_OK)
        fail_msg("%s: %s", name, rl_last_error());
    return s;
}

static rl_accel *grid_of(const rl_scene *s, int res)
{
    rl_accel *a = NULL;
    rl_accel_desc d = { .kind = RL_ACCEL_GRID, .grid_res = { res, res, res } };
    assert_int_equal(rl_accel_create(s, &d, &a), RL_OK);
    if (rl_accel_commit(a) != RL_OK)
        fail_msg("grid: %s", rl_last_error());
    return a;
}

static rl_vec3 shade(void *user, const rl_ls_surface *s, rl_vec3 dir);

static rl_linespace *cpu_ls(const rl_accel *grid, rl_linespace_desc d)
{
    rl_linespace *ls = NULL;
    assert_int_equal(rl_linespace_create(grid, &d, &ls), RL_OK);
    if (d.payloads & RL_LS_PREILLUM)
        assert_int_equal(rl_linespace_set_shader(ls, shade, NULL), RL_OK);
    if (rl_linespace_commit(ls) != RL_OK)
        fail_msg("linespace: %s", rl_last_error());
    return ls;
}

static rl_gl_context *context(void)
{
    rl_gl_context *ctx = NULL;
    if (rl_gl_context_create(NULL, &ctx) != RL_OK)
        fail_msg("context: %s", rl_last_error());
    return ctx;
}

/* The scenes: the Cornell box (36 triangles) and the teapot in it (1000
 * teapot triangles), at small grids and N. */
typedef struct setup {
    const char *name, *params;
    int res, n;
} setup;

static const setup setups[] = {
    { "cornell", NULL, 4, 3 },
    { "cornell-teapot", "triangles=1000", 5, 2 },
};

/* ---- (a) the GPU build equals the CPU build ---- */

static void compare_arrays(const char *what, const rl_linespace *ls, const rl_gl_ls_arrays *a)
{
    rl_linespace_data d;
    rl_linespace_get_data(ls, &d);
    assert_int_equal(a->num_cells, d.num_cells);
    assert_int_equal(a->num_blocks, d.num_blocks);
    assert_int_equal(a->occ_words, d.occ_words);
    assert_memory_equal(a->voxel_slot, d.voxel_slot, (size_t)d.num_cells * 4);
    const uint64_t words = (uint64_t)d.num_blocks * d.occ_words;
    for (uint64_t w = 0; w < words; ++w)
        if (a->occupancy[2 * w] != d.occupancy[2 * w] || a->occupancy[2 * w + 1] != d.occupancy[2 * w + 1])
            fail_msg("%s: occupancy word %llu (block %llu): gpu %016llx rank %llu, cpu %016llx rank %llu", what,
                     (unsigned long long)w, (unsigned long long)(w / d.occ_words),
                     (unsigned long long)a->occupancy[2 * w], (unsigned long long)a->occupancy[2 * w + 1],
                     (unsigned long long)d.occupancy[2 * w], (unsigned long long)d.occupancy[2 * w + 1]);
    assert_int_equal(a->num_occupied, d.num_occupied);
    assert_int_equal(a->num_cand, d.num_cand);
    /* Same order, not only the same sets: both sort by the same keys with
     * the triangle breaking ties, so any difference is a real one (the
     * fixed lists' front/back halves depend on the order, too). */
    for (uint64_t i = 0; i < d.num_cand; ++i)
        if (a->cand[i] != d.cand[i])
            fail_msg("%s: candidate %llu: gpu %u, cpu %u", what, (unsigned long long)i, a->cand[i], d.cand[i]);
    if (d.dynamic)
        assert_memory_equal(a->cand_start, d.cand_start, (size_t)(d.num_occupied + 1) * 4);
}

static void gpu_build_equals_cpu(void **state)
{
    (void)state;
    NEED_GL();
    rl_gl_context *ctx = context();
    for (size_t i = 0; i < sizeof setups / sizeof setups[0]; ++i) {
        const setup *su = &setups[i];
        rl_scene *s = builtin(su->name, su->params);
        rl_accel *grid = grid_of(s, su->res);
        const rl_linespace_desc descs[] = {
            { .n = su->n, .dynamic = true },
            { .n = su->n, .k = 4 },
            { .n = su->n, .k = 8 },
        };
        for (size_t j = 0; j < sizeof descs / sizeof descs[0]; ++j) {
            rl_linespace *ls = cpu_ls(grid, descs[j]);
            rl_gl_ls *g = NULL;
            if (rl_gl_ls_build(grid, &descs[j], NULL, &g) != RL_OK)
                fail_msg("gpu build: %s", rl_last_error());
            rl_gl_ls_arrays a;
            assert_int_equal(rl_gl_ls_read(g, &a), RL_OK);
            char what[128];
            snprintf(what, sizeof what, "%s %d^3 N=%d %s k=%d", su->name, su->res, su->n,
                     descs[j].dynamic ? "dynamic" : "fixed", descs[j].k);
            compare_arrays(what, ls, &a);
            rl_gl_ls_stats gs;
            rl_gl_ls_get_stats(g, &gs);
            rl_linespace_stats cs;
            rl_linespace_get_stats(ls, &cs);
            assert_true(gs.gpu_built && gs.occupied > 0 && gs.gpu_ms >= 0.0 && gs.wall_ms > 0.0);
            print_message("%s: %llu occupied shafts, %llu candidates; gpu %.1f ms (stamps %.1f, wall %.1f), cpu %.1f ms\n",
                          what, (unsigned long long)gs.occupied, (unsigned long long)gs.candidates, gs.gpu_ms,
                          gs.stamp_ms, gs.wall_ms,
                          cs.build_ms);
            rl_gl_ls_arrays_free(&a);
            rl_gl_ls_release(g);
            rl_linespace_release(ls);
        }
        rl_accel_release(grid);
        rl_scene_release(s);
    }
    rl_gl_context_release(ctx);
}

/* ---- (b) the GLSL walk answers as linespace_query.c ---- */

static float uni(rl_rng *r, float lo, float hi) { return lo + (hi - lo) * rl_rng_float(r); }

/* Rays from inside and outside the scene's box: random directions, towards
 * vertices and triangle points, axis-parallel, and segments (shadow rays)
 * ending short of or at a surface. */
static void make_rays(const rl_scene_data *d, rl_ray *rays, int count)
{
    rl_rng r;
    rl_rng_seed(&r, 35, 4);
    rl_aabb b = d->bounds;
    rl_vec3 e = rl_aabb_extent(b);
    for (int i = 0; i < count; ++i) {
        rl_vec3 o = rl_v3(uni(&r, b.min.x - 0.3f * e.x, b.max.x + 0.3f * e.x),
                          uni(&r, b.min.y - 0.3f * e.y, b.max.y + 0.3f * e.y),
                          uni(&r, b.min.z - 0.3f * e.z, b.max.z + 0.3f * e.z));
        if (i % 2)
            o = rl_v3(uni(&r, b.min.x, b.max.x), uni(&r, b.min.y, b.max.y), uni(&r, b.min.z, b.max.z));
        uint32_t tri = rl_rng_bounded(&r, d->num_triangles);
        const uint32_t *idx = d->indices + 3 * (size_t)tri;
        float u = rl_rng_float(&r), v = rl_rng_float(&r);
        if (u + v > 1.0f) {
            u = 1.0f - u;
            v = 1.0f - v;
        }
        rl_vec3 p = rl_add(rl_add(rl_scale(d->positions[idx[0]], 1.0f - u - v), rl_scale(d->positions[idx[1]], u)),
                           rl_scale(d->positions[idx[2]], v));
        rl_ray ray = { .o = o, .t_min = 0.0f, .t_max = INFINITY };
        switch (i % 5) {
        case 0:
            ray.d = rl_v3(uni(&r, -1, 1), uni(&r, -1, 1), uni(&r, -1, 1));
            break;
        case 1:
            ray.d = rl_sub(p, o);
            break;
        case 2:
            ray.d = rl_sub(d->positions[idx[i % 3]], o);
            break;
        case 3:
            ray.d = (i / 5) % 3 == 0 ? rl_v3(1, 0, 0) : ((i / 5) % 3 == 1 ? rl_v3(0, -1, 0) : rl_v3(0, 0.25f, 1));
            break;
        default:
            ray.d = rl_sub(p, o);
            ray.t_min = 1e-4f;
            ray.t_max = (i / 5) % 2 ? 0.999f : 0.5f;
            break;
        }
        rays[i] = ray;
    }
}

static void compare_queries(const char *what, const rl_linespace *ls, const rl_gl_ls *g, const rl_scene_data *d)
{
    static rl_ray rays[RAYS];
    make_rays(d, rays, RAYS);
    static rl_gl_ls_hit res[RAYS];
    if (rl_gl_ls_trace(g, rays, RAYS, RL_GL_LS_QUERY_CANDIDATES, res) != RL_OK)
        fail_msg("%s: trace: %s", what, rl_last_error());
    int hits = 0, occluded = 0;
    for (int i = 0; i < RAYS; ++i) {
        rl_ray r = rays[i];
        rl_hit h;
        bool hit = rl_linespace_intersect(ls, &r, &h);
        bool occ = rl_linespace_occluded(ls, &rays[i]);
        uint32_t tri = res[i].tri;
        float t = res[i].t;
        hits += hit;
        occluded += occ;
        if ((tri != RL_NONE) != hit || (hit && (tri != h.triangle || fabsf(t - h.t) > 1e-4f * fabsf(h.t) ||
                                              fabsf(res[i].u - h.u) > 1e-4f || fabsf(res[i].v - h.v) > 1e-4f)))
            fail_msg("%s ray %d o=(%.9g %.9g %.9g) d=(%.9g %.9g %.9g): cpu %d tri %u t %.9g, gl tri %u t %.9g", what,
                     i, (double)rays[i].o.x, (double)rays[i].o.y, (double)rays[i].o.z, (double)rays[i].d.x,
                     (double)rays[i].d.y, (double)rays[i].d.z, hit, hit ? h.triangle : RL_NONE, (double)h.t, tri,
                     (double)t);
        if (res[i].occluded != occ)
            fail_msg("%s ray %d: occluded cpu %d, gl %d", what, i, occ, res[i].occluded);
    }
    print_message("%s: %d rays, %d hits, %d occluded, all equal\n", what, RAYS, hits, occluded);
    assert_true(hits > RAYS / 4 && occluded > RAYS / 4 && occluded < RAYS);
}

/* PNMT: the same first surface (record or start-voxel triangle) and the
 * same occlusion answers, under both origin rules. */
static void compare_pnmt(const char *what, const rl_linespace *ls, const rl_gl_ls *g, const rl_scene_data *d)
{
    static rl_ray rays[RAYS];
    make_rays(d, rays, RAYS);
    static rl_gl_ls_hit res[RAYS];
    if (rl_gl_ls_trace(g, rays, RAYS, RL_GL_LS_QUERY_PNMT, res) != RL_OK)
        fail_msg("%s: trace: %s", what, rl_last_error());
    int hits = 0, records = 0, occluded = 0;
    for (int i = 0; i < RAYS; ++i) {
        rl_ls_surface s;
        bool hit = rl_linespace_pnmt_intersect(ls, &rays[i], &s);
        bool occ = rl_linespace_pnmt_occluded(ls, &rays[i]);
        hits += hit;
        records += res[i].record;
        occluded += occ;
        /* A record's material is the stored one; a start-voxel hit is a
         * triangle, whose material the CPU looked up. */
        bool same = res[i].hit == hit &&
                    (!hit || (fabsf(res[i].t - s.t) <= 1e-4f * fabsf(s.t) &&
                              (res[i].record ? res[i].material == s.material
                                             : d->triangle_material[res[i].tri] == s.material)));
        if (!same)
            fail_msg("%s ray %d: cpu %d t %.9g material %u, gl %d t %.9g tri %u record %d material %u", what, i, hit,
                     (double)s.t, hit ? s.material : 0u, res[i].hit, (double)res[i].t, res[i].tri, res[i].record,
                     res[i].material);
        if (res[i].occluded != occ)
            fail_msg("%s ray %d: pnmt occluded cpu %d, gl %d", what, i, occ, res[i].occluded);
    }
    print_message("%s: %d rays, %d PNMT hits (%d from records), %d occluded, all equal\n", what, RAYS, hits,
                  records, occluded);
    assert_true(hits > RAYS / 4 && records > 0 && occluded > RAYS / 4);
}

/* A shading function for PREILLUM: any colour that varies over the
 * surfaces does. */
static rl_vec3 shade(void *user, const rl_ls_surface *s, rl_vec3 dir)
{
    (void)user;
    return rl_v3(fabsf(s->n.x) + 0.1f * (float)s->material, fabsf(s->n.y) + s->uv.x, fabsf(dir.z) + s->p.y);
}

static void compare_preillum(const char *what, const rl_linespace *ls, const rl_gl_ls *g, const rl_scene_data *d)
{
    static rl_ray rays[RAYS];
    make_rays(d, rays, RAYS);
    static rl_gl_ls_hit res[RAYS];
    if (rl_gl_ls_trace(g, rays, RAYS, RL_GL_LS_QUERY_PREILLUM, res) != RL_OK)
        fail_msg("%s: trace: %s", what, rl_last_error());
    int hits = 0, occluded = 0;
    for (int i = 0; i < RAYS; ++i) {
        rl_vec3 c = rl_v3(0, 0, 0);
        float t = 0.0f;
        bool hit = rl_linespace_preillum(ls, &rays[i], &c, &t);
        bool occ = rl_linespace_preillum_occluded(ls, &rays[i]);
        hits += hit;
        occluded += occ;
        /* Colours are the stored half floats: equal bit for bit. */
        if (res[i].hit != hit || (hit && (fabsf(res[i].t - t) > 1e-4f * fabsf(t) || res[i].color[0] != c.x ||
                                          res[i].color[1] != c.y || res[i].color[2] != c.z)))
            fail_msg("%s ray %d: cpu %d t %.9g (%g %g %g), gl %d t %.9g (%g %g %g)", what, i, hit, (double)t,
                     (double)c.x, (double)c.y, (double)c.z, res[i].hit, (double)res[i].t, (double)res[i].color[0],
                     (double)res[i].color[1], (double)res[i].color[2]);
        if (res[i].occluded != occ)
            fail_msg("%s ray %d: preillum occluded cpu %d, gl %d", what, i, occ, res[i].occluded);
    }
    print_message("%s: %d rays, %d PREILLUM hits, %d occluded, all equal\n", what, RAYS, hits, occluded);
    assert_true(hits > RAYS / 4 && occluded > RAYS / 4);
}

static void walk_equals_cpu(void **state)
{
    (void)state;
    NEED_GL();
    rl_gl_context *ctx = context();
    for (size_t i = 0; i < sizeof setups / sizeof setups[0]; ++i) {
        const setup *su = &setups[i];
        rl_scene *s = builtin(su->name, su->params);
        rl_accel *grid = grid_of(s, su->res);
        const rl_linespace_desc descs[] = {
            { .n = su->n, .dynamic = true },
            { .n = su->n, .k = 4 },
            { .n = su->n, .dynamic = true, .payloads = RL_LS_CANDIDATES | RL_LS_PNMT },
            { .n = su->n, .dynamic = true, .payloads = RL_LS_CANDIDATES | RL_LS_PREILLUM },
            { .n = su->n, .dynamic = true, .payloads = RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM },
        };
        for (size_t j = 0; j < sizeof descs / sizeof descs[0]; ++j) {
            rl_linespace *ls = cpu_ls(grid, descs[j]);
            char what[160];
            rl_gl_ls *up = NULL;
            if (rl_gl_ls_upload(ls, NULL, &up) != RL_OK)
                fail_msg("upload: %s", rl_last_error());
            snprintf(what, sizeof what, "%s uploaded, %s k=%d payloads 0x%x", su->name,
                     descs[j].dynamic ? "dynamic" : "fixed", descs[j].k, descs[j].payloads);
            compare_queries(what, ls, up, rl_scene_get_data(s));
            rl_gl_ls_release(up);
            if (descs[j].payloads & RL_LS_PREILLUM)
                for (int rule = 0; rule < 2; ++rule) {
                    assert_int_equal(rl_linespace_set_origin(ls, rule ? RL_LS_ORIGIN_RECORDS : RL_LS_ORIGIN_EXACT),
                                     RL_OK);
                    if (rl_gl_ls_upload(ls, NULL, &up) != RL_OK)
                        fail_msg("upload: %s", rl_last_error());
                    snprintf(what, sizeof what, "%s uploaded PREILLUM%s, origin %s", su->name,
                             descs[j].payloads & RL_LS_PNMT ? " +PNMT" : "", rule ? "records" : "exact");
                    compare_preillum(what, ls, up, rl_scene_get_data(s));
                    rl_gl_ls_release(up);
                }
            if ((descs[j].payloads & RL_LS_PNMT) && !(descs[j].payloads & RL_LS_PREILLUM))
                for (int rule = 0; rule < 2; ++rule) {
                    assert_int_equal(rl_linespace_set_origin(ls, rule ? RL_LS_ORIGIN_RECORDS : RL_LS_ORIGIN_EXACT),
                                     RL_OK);
                    if (rl_gl_ls_upload(ls, NULL, &up) != RL_OK)
                        fail_msg("upload: %s", rl_last_error());
                    snprintf(what, sizeof what, "%s uploaded PNMT, origin %s", su->name, rule ? "records" : "exact");
                    compare_pnmt(what, ls, up, rl_scene_get_data(s));
                    rl_gl_ls_release(up);
                }
            if (descs[j].payloads == RL_LS_CANDIDATES || descs[j].payloads == 0) {
                rl_gl_ls *built = NULL;
                if (rl_gl_ls_build(grid, &descs[j], NULL, &built) != RL_OK)
                    fail_msg("gpu build: %s", rl_last_error());
                snprintf(what, sizeof what, "%s gpu-built, %s k=%d", su->name, descs[j].dynamic ? "dynamic" : "fixed",
                         descs[j].k);
                compare_queries(what, ls, built, rl_scene_get_data(s));
                rl_gl_ls_release(built);
            }
            rl_linespace_release(ls);
        }
        rl_accel_release(grid);
        rl_scene_release(s);
    }
    rl_gl_context_release(ctx);
}

/* ---- (c) limits and what the GPU build refuses ---- */

static void limits_are_errors(void **state)
{
    (void)state;
    NEED_GL();
    rl_gl_context *ctx = context();
    rl_scene *s = builtin("cornell-teapot", "triangles=1000");
    rl_accel *grid = grid_of(s, 5);
    const rl_linespace_desc desc = { .n = 2, .dynamic = true };
    rl_linespace *ls = cpu_ls(grid, desc);
    /* A cap far below the arrays, as a small GPU would have. */
    const rl_gl_ls_limits small = { .max_buffer_bytes = 4096 };
    rl_gl_ls *g = (rl_gl_ls *)&g;
    assert_int_equal(rl_gl_ls_upload(ls, &small, &g), RL_ERR_LIMIT);
    assert_null(g);
    assert_non_null(strstr(rl_last_error(), "shader storage block size"));
    g = (rl_gl_ls *)&g;
    assert_int_equal(rl_gl_ls_build(grid, &desc, &small, &g), RL_ERR_LIMIT);
    assert_null(g);
    assert_non_null(strstr(rl_last_error(), "shader storage block size"));
    /* Just above what the triangles and cell lists need: the build fails
     * later, at the shaft counts, and still cleanly. */
    const rl_gl_ls_limits mid = { .max_buffer_bytes = 64 * 1024 };
    rl_clear_error();
    assert_int_equal(rl_gl_ls_build(grid, &desc, &mid, &g), RL_ERR_LIMIT);
    assert_null(g);
    print_message("limit: %s\n", rl_last_error());
    /* Records are uploaded, not built on the GPU; bad N and k as the CPU. */
    const rl_linespace_desc pnmt = { .n = 2, .dynamic = true, .payloads = RL_LS_CANDIDATES | RL_LS_PNMT };
    assert_int_equal(rl_gl_ls_build(grid, &pnmt, NULL, &g), RL_ERR_UNSUPPORTED);
    const rl_linespace_desc bad_n = { .n = RL_LS_MAX_N + 1 }, bad_k = { .k = 3 };
    assert_int_equal(rl_gl_ls_build(grid, &bad_n, NULL, &g), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_gl_ls_build(grid, &bad_k, NULL, &g), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_gl_ls_build(NULL, &desc, NULL, &g), RL_ERR_INVALID_ARG);
    /* The public timing call gives the same counts as the CPU build. */
    rl_gl_linespace_timing t;
    assert_int_equal(rl_gl_linespace_time_build(grid, &desc, NULL, &t), RL_OK);
    rl_linespace_stats cs;
    rl_linespace_get_stats(ls, &cs);
    assert_int_equal(t.candidates, cs.candidates);
    assert_int_equal(t.occupied, cs.shafts - cs.empty_shafts);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_scene_release(s);
    rl_gl_context_release(ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(gpu_build_equals_cpu),
        cmocka_unit_test(walk_equals_cpu),
        cmocka_unit_test(limits_are_errors),
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
