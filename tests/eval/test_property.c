/* test_property.c: the generic rl_property layer and the renderer-based
 * properties (Jähn 2015, Ch. 4): time (Sec. 4.2.3), ops (Sec. 4.2.4),
 * quality (Sec. 4.2.5), combined (Sec. 4.2.6) and custom properties, and
 * bad input. Scenes are a few quads; images 16 x 16, so that every test
 * runs in milliseconds. Times are never compared with numbers. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "eval/property_internal.h"
#include "rl/rl.h"
#include "rl/rl_property.h"

/* ---- scenes ------------------------------------------------------------ */

static uint32_t add_material(rl_scene *s)
{
    rl_material m = rl_material_default();
    uint32_t id;
    assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
    return id;
}

static void add_quad(rl_scene *s, uint32_t material, rl_vec3 a, rl_vec3 b, rl_vec3 c, rl_vec3 d)
{
    const rl_vec3 pos[4] = { a, b, c, d };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc md = { .name = "quad", .num_vertices = 4, .positions = pos,
                        .num_triangles = 2, .indices = idx, .material = material };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "quad", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

static void add_point_light(rl_scene *s, rl_vec3 at)
{
    rl_light l = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = 6.0f,
                   .position = at };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
}

/* Two quads (4 triangles) at x = 5 and x = 6, well inside the +x frustum
 * of a viewer at the origin (several pixels each even at 16 x 16 and
 * 120°), lit from the viewer's side. */
static rl_scene *ahead_scene(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t m = add_material(s);
    add_quad(s, m, rl_v3(5, -2, -2), rl_v3(5, 2, -2), rl_v3(5, 2, 2), rl_v3(5, -2, 2));
    add_quad(s, m, rl_v3(6, 2.5f, -2), rl_v3(6, 4, -2), rl_v3(6, 4, 2), rl_v3(6, 2.5f, 2));
    add_point_light(s, rl_v3(1, 2, 0));
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* A floor (y = 0) under an occluder (y = 1) under a point light (y = 3):
 * Whitted casts the occluder's shadow on the floor, the rasterizer cannot. */
static rl_scene *shadow_scene(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t m = add_material(s);
    add_quad(s, m, rl_v3(-3, 0, -3), rl_v3(-3, 0, 3), rl_v3(3, 0, 3), rl_v3(3, 0, -3));
    add_quad(s, m, rl_v3(-0.5f, 1, -0.5f), rl_v3(-0.5f, 1, 0.5f), rl_v3(0.5f, 1, 0.5f),
             rl_v3(0.5f, 1, -0.5f));
    add_point_light(s, rl_v3(0, 3, 0));
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static const rl_vec3 viewer = { 0.0f, 0.0f, 0.0f };
static const rl_vec3 shadow_viewer = { 0.3f, 0.5f, 0.2f };

/* A property with options {key, value, ..., NULL} set and committed. */
static rl_property *make(const char *name, const char *const *opts, const rl_scene *s, int workers)
{
    rl_property *p = NULL;
    assert_int_equal(rl_property_create(name, &p), RL_OK);
    for (size_t i = 0; opts && opts[i]; i += 2) {
        rl_clear_error();
        if (rl_property_set(p, opts[i], opts[i + 1]) != RL_OK)
            fail_msg("%s=%s: %s", opts[i], opts[i + 1], rl_last_error());
    }
    rl_clear_error();
    if (rl_property_commit(p, s, workers) != RL_OK)
        fail_msg("commit %s: %s", name, rl_last_error());
    return p;
}

static rl_property_sample evaluate_at(rl_property *p, rl_vec3 pos)
{
    rl_property_sample smp;
    memset(&smp, 0, sizeof smp);
    rl_clear_error();
    if (rl_property_evaluate(p, 0, pos, &smp) != RL_OK)
        fail_msg("evaluate %s: %s", rl_property_name(p), rl_last_error());
    return smp;
}

static double max_of(const double *v)
{
    double m = v[0];
    for (int i = 1; i < 6; ++i)
        m = v[i] > m ? v[i] : m;
    return m;
}

static double min_of(const double *v)
{
    double m = v[0];
    for (int i = 1; i < 6; ++i)
        m = v[i] < m ? v[i] : m;
    return m;
}

/* ---- the list and bad input -------------------------------------------- */

static void test_list_names_the_four_built_in_properties(void **state)
{
    (void)state;
    size_t n = 0;
    const rl_property_info *info = rl_property_list(&n);
    assert_int_equal(n, 4);
    const char *const want[] = { "visibility", "time", "ops", "quality" };
    for (size_t i = 0; i < n; ++i) {
        assert_string_equal(info[i].name, want[i]);
        assert_true(strlen(info[i].description) > 0);
        assert_non_null(strstr(info[i].reference, "Jähn 2015"));
    }
}

static void test_unknown_property_is_not_found_and_lists_the_known_ones(void **state)
{
    (void)state;
    rl_property *p = (rl_property *)0x1;
    rl_clear_error();
    assert_int_equal(rl_property_create("visibilty", &p), RL_ERR_NOT_FOUND);
    assert_true(p == (rl_property *)0x1);
    assert_non_null(strstr(rl_last_error(), "visibility"));
    assert_non_null(strstr(rl_last_error(), "quality"));
    assert_int_equal(rl_property_create(NULL, &p), RL_ERR_INVALID_ARG);
}

static void test_evaluate_needs_a_commit_a_worker_and_a_finite_position(void **state)
{
    (void)state;
    rl_scene *s = ahead_scene();
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("visibility", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "resolution", "16"), RL_OK);
    rl_property_sample smp = { .value = 42.0 };
    assert_int_equal(rl_property_evaluate(p, 0, viewer, &smp), RL_ERR_NOT_COMMITTED);
    assert_int_equal(rl_property_workers(p), 0);
    assert_int_equal(rl_property_commit(p, s, 2), RL_OK);
    assert_int_equal(rl_property_workers(p), 2);
    assert_int_equal(rl_property_evaluate(p, 2, viewer, &smp), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_evaluate(p, -1, viewer, &smp), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_evaluate(p, 0, rl_v3(NAN, 0, 0), &smp), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_evaluate(p, 0, rl_v3(0, INFINITY, 0), &smp), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_evaluate(p, 0, viewer, NULL), RL_ERR_INVALID_ARG);
    assert_true(smp.value == 42.0);                 /* untouched on failure */
    /* options are frozen once committed */
    assert_int_equal(rl_property_set(p, "resolution", "32"), RL_ERR_INVALID_ARG);
    assert_string_equal(rl_property_get(p, "resolution"), "16");
    assert_int_equal(rl_property_evaluate(p, 1, viewer, &smp), RL_OK);
    assert_true(smp.value == 2.0);
    rl_property_release(p);
    rl_scene_release(s);
}

static void test_commit_needs_a_committed_non_empty_scene(void **state)
{
    (void)state;
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("ops", &p), RL_OK);
    assert_int_equal(rl_property_commit(p, NULL, 1), RL_ERR_INVALID_ARG);

    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t m = add_material(s);
    add_quad(s, m, rl_v3(1, 0, 0), rl_v3(1, 1, 0), rl_v3(1, 1, 1), rl_v3(1, 0, 1));
    assert_int_equal(rl_property_commit(p, s, 1), RL_ERR_NOT_COMMITTED);
    rl_scene_release(s);

    /* a scene without triangles cannot be committed, so it stays
     * uncommitted for the property too */
    assert_int_equal(rl_scene_create(&s), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_ERR_EMPTY_SCENE);
    assert_int_equal(rl_property_commit(p, s, 1), RL_ERR_NOT_COMMITTED);
    rl_scene_release(s);

    s = ahead_scene();
    assert_int_equal(rl_property_commit(p, s, -1), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_commit(p, s, 100000), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_workers(p), 0);
    rl_property_release(p);
    rl_scene_release(s);
}

static void test_out_of_range_options_are_invalid(void **state)
{
    (void)state;
    const char *const bad[][3] = {
        { "time", "width", "0" },          { "time", "height", "5000" },
        { "time", "fov_deg", "180" },      { "time", "repeats", "0" },
        { "time", "conditioned", "maybe" }, { "time", "condition_frames", "-1" },
        { "time", "threads", "x" },        { "ops", "counter", "bananas" },
        { "ops", "reduce", "mean" },       { "ops", "repeats", "3" },
        { "quality", "metric", "mse" },    { "quality", "hssim_levels", "1" },
        { "quality", "reference", "nope" }, { "visibility", "resolution", "-3" },
    };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rl_property *p = NULL;
        assert_int_equal(rl_property_create(bad[i][0], &p), RL_OK);
        rl_clear_error();
        assert_int_equal(rl_property_set(p, bad[i][1], bad[i][2]), RL_ERR_INVALID_ARG);
        assert_true(strlen(rl_last_error()) > 0);
        rl_property_release(p);
    }
}

/* ---- time (Sec. 4.2.3) ------------------------------------------------- */

/* Scripted frames for rl_time_measure: each render takes the next time of
 * the script and logs its direction; resets are logged as -1. */
typedef struct script {
    const double *times;
    int n, next;
    int log[256], logged;
    int fail_at;                /* render call that fails, or -1 */
} script;

static rl_status script_render(void *ctx, int direction, double *ms)
{
    script *s = ctx;
    assert_true(s->next < s->n);
    if (s->next == s->fail_at)
        return RL_ERR_INVALID_ARG;
    *ms = s->times[s->next++];
    s->log[s->logged++] = direction;
    return RL_OK;
}

static void script_reset(void *ctx)
{
    script *s = ctx;
    s->log[s->logged++] = -1;
}

static int log_count(const script *s, int what)
{
    int n = 0;
    for (int i = 0; i < s->logged; ++i)
        n += s->log[i] == what;
    return n;
}

/* Def. 6, unconditioned: the median of the repeats per direction, the
 * maximum over directions, a reset before every measured frame; the first
 * sample of a worker renders once unmeasured (the scene's build). */
static void test_time_rule_unconditioned_takes_medians_resets_and_skips_the_build(void **state)
{
    (void)state;
    double times[1 + 18 + 18];
    times[0] = 1000.0;                                   /* the build: never counted */
    for (int i = 0; i < 6; ++i) {
        times[1 + 3 * i] = 10.0 * i + 100.0;             /* an outlier first */
        times[2 + 3 * i] = 10.0 * i + 1.0;
        times[3 + 3 * i] = 10.0 * i + 3.0;               /* the median, last */
        for (int k = 0; k < 3; ++k)
            times[19 + 3 * i + k] = 7.0;
    }
    script sc = { .times = times, .n = 37, .fail_at = -1 };
    rl_time_frames f = { script_render, script_reset, &sc };
    rl_time_rule rule = { .repeats = 3 };
    bool built = false;
    double scratch[3], dir[6], value = 0.0;
    assert_int_equal(rl_time_measure(&f, &rule, &built, scratch, dir, &value), RL_OK);
    assert_true(built);
    for (int i = 0; i < 6; ++i)
        assert_true(dir[i] == 10.0 * i + 3.0);
    assert_true(value == 53.0);
    /* render(0) reset, then (reset render) x 3 per direction */
    assert_int_equal(sc.logged, 2 + 6 * 3 * 2);
    assert_int_equal(sc.log[0], 0);
    assert_int_equal(sc.log[1], -1);
    for (int i = 0; i < 6; ++i)
        for (int k = 0; k < 3; ++k) {
            assert_int_equal(sc.log[2 + 6 * i + 2 * k], -1);
            assert_int_equal(sc.log[3 + 6 * i + 2 * k], i);
        }
    /* The next sample of the same worker: no build frame. */
    sc.logged = 0;
    assert_int_equal(rl_time_measure(&f, &rule, &built, scratch, dir, &value), RL_OK);
    assert_int_equal(sc.logged, 6 * 3 * 2);
    assert_true(value == 7.0);
}

/* Def. 6, conditioned: unmeasured frames until one is not 2 % faster than
 * the one before, at most condition_frames of them, no resets. */
static void test_time_rule_conditioned_stops_at_two_percent_or_the_frame_limit(void **state)
{
    (void)state;
    double times[64];
    int n = 0;
    /* direction 0: 100, 50, 30, 29.5 (1.7 % faster: the last unmeasured), measured 20 */
    const double d0[] = { 100.0, 50.0, 30.0, 29.5, 20.0 };
    for (int k = 0; k < 5; ++k)
        times[n++] = d0[k];
    /* direction 1: always 10 % faster: the limit of 4 frames, measured 40 */
    for (int k = 0; k < 4; ++k)
        times[n++] = 100.0 * pow(0.9, k);
    times[n++] = 40.0;
    /* directions 2-5: 5, 5 (not faster), measured 7 */
    for (int i = 2; i < 6; ++i) {
        times[n++] = 5.0;
        times[n++] = 5.0;
        times[n++] = 7.0;
    }
    script sc = { .times = times, .n = n, .fail_at = -1 };
    rl_time_frames f = { script_render, script_reset, &sc };
    rl_time_rule rule = { .repeats = 1, .conditioned = true, .condition_frames = 4 };
    bool built = true;
    double scratch[1], dir[6], value = 0.0;
    assert_int_equal(rl_time_measure(&f, &rule, &built, scratch, dir, &value), RL_OK);
    assert_int_equal(sc.next, n);                       /* every scripted frame, no more */
    assert_int_equal(log_count(&sc, -1), 0);
    assert_int_equal(log_count(&sc, 0), 5);
    assert_int_equal(log_count(&sc, 1), 5);
    assert_true(dir[0] == 20.0 && dir[1] == 40.0 && dir[2] == 7.0 && dir[5] == 7.0);
    assert_true(value == 40.0);

    /* A failing frame's status comes back. */
    sc = (script){ .times = times, .n = n, .fail_at = 2 };
    f.ctx = &sc;
    assert_int_equal(rl_time_measure(&f, &rule, &built, scratch, dir, &value), RL_ERR_INVALID_ARG);
}

static void test_time_is_positive_exclusive_and_the_max_over_directions(void **state)
{
    (void)state;
    rl_scene *s = ahead_scene();
    const char *const opts[] = { "renderer", "raster", "width", "16", "height", "16",
                                 "repeats", "3", NULL };
    rl_property *p = make("time", opts, s, 1);
    assert_true(rl_property_get_flags(p) & RL_PROPERTY_EXCLUSIVE);
    assert_false(rl_property_get_flags(p) & RL_PROPERTY_HIGHER_IS_BETTER);
    assert_string_equal(rl_property_unit(p), "ms");
    assert_int_equal(rl_property_set_size(p), 0);
    rl_property_sample smp = evaluate_at(p, viewer);
    assert_true(smp.value > 0.0 && isfinite(smp.value));
    for (int i = 0; i < 6; ++i)
        assert_true(smp.direction[i] > 0.0);
    assert_true(smp.value == max_of(smp.direction));
    rl_property_release(p);

    const char *const cond[] = { "width", "16", "height", "16", "repeats", "2",
                                 "conditioned", "true", "condition_frames", "3", NULL };
    p = make("time", cond, s, 2);
    smp = evaluate_at(p, viewer);
    assert_true(smp.value > 0.0 && smp.value == max_of(smp.direction));
    rl_property_release(p);
    rl_scene_release(s);
}

static void test_time_rejects_unknown_renderers_and_bad_renderer_options(void **state)
{
    (void)state;
    rl_scene *s = ahead_scene();
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("time", &p), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_property_set(p, "renderer", "rasterizer"), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "rasterizer"));
    assert_non_null(strstr(rl_last_error(), "whitted"));
    assert_string_equal(rl_property_get(p, "renderer"), "raster");

    /* renderer_options are only text until commit configures a renderer */
    const char *const bad[] = { "bogus=1", "shading=wobbly", "threads=-4", "noequals" };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        assert_int_equal(rl_property_set(p, "renderer_options", bad[i]), RL_OK);
        rl_clear_error();
        assert_int_equal(rl_property_commit(p, s, 1), RL_ERR_INVALID_ARG);
        assert_true(strlen(rl_last_error()) > 0);
        assert_int_equal(rl_property_workers(p), 0);
    }
    assert_int_equal(rl_property_set(p, "renderer_options", "shading=flat,threads=1"), RL_OK);
    assert_int_equal(rl_property_commit(p, s, 1), RL_OK);
    rl_property_release(p);
    rl_scene_release(s);
}

/* ---- ops (Sec. 4.2.4) -------------------------------------------------- */

/* Triangles the raster renderer draws in direction i, rendered directly. */
static double raster_triangles(const rl_scene *s, rl_vec3 pos, int i)
{
    rl_vec3 dir, up;
    rl_property_direction(i, &dir, &up);
    rl_camera cam = { .eye = pos, .target = rl_add(pos, dir), .up = up, .fov_deg = 120.0f,
                      .width = 16, .height = 16 };
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_render_stats st;
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    assert_int_equal(rl_image_create(16, 16, RL_LAYER_COLOR, &img), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, &st), RL_OK);
    rl_image_release(img);
    rl_renderer_release(r);
    return (double)st.triangles_rasterized;
}

static void test_ops_counts_the_triangles_the_rasterizer_draws(void **state)
{
    (void)state;
    rl_scene *s = ahead_scene();
    const char *const max_opts[] = { "width", "16", "height", "16", NULL };
    const char *const sum_opts[] = { "width", "16", "height", "16", "reduce", "sum", NULL };
    rl_property *pmax = make("ops", max_opts, s, 1);
    rl_property *psum = make("ops", sum_opts, s, 1);
    assert_string_equal(rl_property_unit(pmax), "triangles");
    rl_property_sample a = evaluate_at(pmax, viewer), b = evaluate_at(psum, viewer);
    /* +x sees the whole scene, unclipped: all 4 triangles */
    assert_true(a.direction[0] == 4.0);
    double sum = 0.0;
    for (int i = 0; i < 6; ++i) {
        double want = raster_triangles(s, viewer, i);
        assert_true(a.direction[i] == want);
        assert_true(b.direction[i] == want);
        sum += want;
    }
    assert_true(a.value == max_of(a.direction));
    assert_true(a.value >= 4.0);
    assert_true(b.value == sum);
    rl_property_release(pmax);
    rl_property_release(psum);
    rl_scene_release(s);
}

/* Every counter has its own unit: the table of units once ended early and
 * read past its end for points and primitives. */
static void test_every_ops_counter_has_its_unit(void **state)
{
    (void)state;
    static const char *const want[][2] = {
        { "triangles", "triangles" }, { "rays", "rays" }, { "primary_rays", "rays" },
        { "shadow_rays", "rays" }, { "secondary_rays", "rays" }, { "pixels", "pixels" },
        { "samples", "samples" }, { "occlusion_queries", "queries" }, { "points", "points" },
        { "primitives", "primitives" } };
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("ops", &p), RL_OK);
    size_t count = 0;
    const rl_option_info *opts = rl_property_options(p, &count);
    const char *const *choices = NULL;
    for (size_t i = 0; i < count; ++i)
        if (strcmp(opts[i].key, "counter") == 0)
            choices = opts[i].choices;
    assert_non_null(choices);
    size_t n = 0;
    for (; choices[n]; ++n) {
        assert_true(n < sizeof want / sizeof want[0]);
        assert_string_equal(choices[n], want[n][0]);
        assert_int_equal(rl_property_set(p, "counter", choices[n]), RL_OK);
        assert_string_equal(rl_property_unit(p), want[n][1]);
    }
    assert_int_equal(n, sizeof want / sizeof want[0]);
    rl_property_release(p);
}

static void test_ops_counts_whitted_rays(void **state)
{
    (void)state;
    rl_scene *s = ahead_scene();
    const char *const opts[] = { "renderer", "whitted", "counter", "rays", "width", "16",
                                 "height", "16", "reduce", "sum", NULL };
    rl_property *p = make("ops", opts, s, 1);
    assert_string_equal(rl_property_unit(p), "rays");
    rl_property_sample smp = evaluate_at(p, viewer);
    assert_true(smp.value >= 6.0 * 16 * 16);        /* at least one primary ray per pixel */
    rl_property_release(p);
    rl_scene_release(s);
}

/* CHC++ keeps what was visible in the last frame (temporal coherence), so
 * one frame at a position counts partly what the previous position left;
 * the ops property must count the position itself, independent of where
 * the renderer was before. */
static void test_ops_of_a_coherent_renderer_do_not_depend_on_the_previous_position(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("city", "blocks=1", &s), RL_OK);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_vec3 lo = d->bounds.min, hi = d->bounds.max;
    rl_vec3 a = rl_v3(lo.x + 0.3f * (hi.x - lo.x), lo.y + 2.0f, lo.z + 0.3f * (hi.z - lo.z));
    rl_vec3 b = rl_v3(lo.x + 0.5f * (hi.x - lo.x), hi.y + 20.0f, lo.z + 0.5f * (hi.z - lo.z));
    const char *const opts[] = { "renderer", "chcpp", "counter", "triangles", "width", "32", "height", "32",
                                 NULL };
    rl_property *p = make("ops", opts, s, 1);
    rl_property_sample first = evaluate_at(p, a);
    rl_property_sample other = evaluate_at(p, b);
    rl_property_sample again = evaluate_at(p, a);
    assert_true(other.value != first.value);          /* b sees another city */
    for (int i = 0; i < 6; ++i)
        assert_true(again.direction[i] == first.direction[i]);
    rl_property_release(p);
    rl_scene_release(s);
}

/* ---- quality (Sec. 4.2.5) ---------------------------------------------- */

static void test_quality_of_the_reference_against_itself_is_perfect(void **state)
{
    (void)state;
    rl_scene *s = shadow_scene();
    const char *const metrics[] = { "ssim", "hssim", "psnr", "rmse" };
    for (int k = 0; k < 4; ++k) {
        const char *const opts[] = { "renderer", "raster", "reference", "raster", "width", "16",
                                     "height", "16", "metric", metrics[k], NULL };
        rl_property *p = make("quality", opts, s, 1);
        rl_property_sample smp = evaluate_at(p, shadow_viewer);
        if (k < 2)
            assert_true(smp.value == 1.0);
        else if (k == 2)   /* equal images: capped, so statistics stay finite */
            assert_true(smp.value == RL_PROPERTY_PSNR_MAX);
        else
            assert_true(smp.value == 0.0);
        bool higher = (rl_property_get_flags(p) & RL_PROPERTY_HIGHER_IS_BETTER) != 0;
        assert_true(higher == (k < 3));
        rl_property_release(p);
    }
    rl_scene_release(s);
}

static void test_quality_of_unshadowed_raster_against_whitted_is_below_one(void **state)
{
    (void)state;
    rl_scene *s = shadow_scene();
    const char *const opts[] = { "renderer", "raster", "reference", "whitted",
                                 "reference_options", "max_depth=0", "width", "16",
                                 "height", "16", NULL };
    rl_property *p = make("quality", opts, s, 1);
    assert_string_equal(rl_property_unit(p), "SSIM");
    assert_string_equal(rl_property_get(p, "metric"), "hssim");   /* the thesis' */
    rl_property_sample smp = evaluate_at(p, shadow_viewer);
    assert_true(smp.value < 1.0);
    /* Def. 7: the worst direction; looking down (-y) sees the shadow */
    assert_true(smp.value == min_of(smp.direction));
    assert_true(smp.direction[3] < 1.0);
    rl_property_release(p);

    const char *const rmse[] = { "renderer", "raster", "reference", "whitted", "width", "16",
                                 "height", "16", "metric", "rmse", NULL };
    p = make("quality", rmse, s, 1);
    smp = evaluate_at(p, shadow_viewer);
    assert_true(smp.value > 0.0 && smp.value == max_of(smp.direction));
    rl_property_release(p);
    rl_scene_release(s);
}

/* ---- custom and combined ----------------------------------------------- */

typedef struct probe {
    double scale, offset;       /* value = scale * (pos.x + pos.y + pos.z) + offset */
    int commits, evaluations, releases;
    bool need_scene;
    uint32_t set_size;
} probe;

static rl_status probe_commit(void *user, const rl_scene *scene, int workers, uint32_t *set_size)
{
    probe *pr = user;
    (void)workers;
    if (pr->need_scene && !scene)
        return RL_ERR_INVALID_ARG;
    ++pr->commits;
    *set_size = pr->set_size;
    return RL_OK;
}

static rl_status probe_evaluate(void *user, int worker, rl_vec3 pos, double *value, uint64_t *set)
{
    probe *pr = user;
    (void)worker;
    ++pr->evaluations;
    *value = pr->scale * (double)(pos.x + pos.y + pos.z) + pr->offset;
    if (set) {
        for (uint32_t w = 0; w < (pr->set_size + 63) / 64; ++w)
            set[w] = 0;
        set[pr->set_size - 1 >= 64 ? 1 : 0] |= UINT64_C(1) << ((pr->set_size - 1) % 64);
    }
    return RL_OK;
}

static void probe_release(void *user) { ++((probe *)user)->releases; }

static rl_property *make_probe(probe *pr, const char *name)
{
    rl_property_callbacks cb = { .name = name, .unit = "u", .commit = probe_commit,
                                 .evaluate = probe_evaluate, .release = probe_release };
    rl_property *p = NULL;
    assert_int_equal(rl_property_create_custom(&cb, pr, &p), RL_OK);
    return p;
}

static void test_custom_property_calls_back_and_checks_its_arguments(void **state)
{
    (void)state;
    probe pr = { .scale = 2.0, .offset = 1.0, .set_size = 70 };
    rl_property *p = make_probe(&pr, "probe");
    assert_string_equal(rl_property_name(p), "probe");
    assert_string_equal(rl_property_unit(p), "u");
    size_t n = 99;
    assert_null(rl_property_options(p, &n));
    assert_int_equal(n, 0);
    assert_int_equal(rl_property_set(p, "anything", "1"), RL_ERR_INVALID_ARG);

    /* a scene-free property accepts a NULL scene */
    assert_int_equal(rl_property_commit(p, NULL, 3), RL_OK);
    assert_int_equal(pr.commits, 1);
    assert_int_equal(rl_property_set_size(p), 70);
    assert_int_equal(rl_property_set_words(p), 2);
    uint64_t set[2] = { 7, 7 };
    rl_property_sample smp = { .set = set };
    assert_int_equal(rl_property_evaluate(p, 2, rl_v3(1, 2, 3), &smp), RL_OK);
    assert_true(smp.value == 13.0);
    assert_true(isnan(smp.direction[0]));
    assert_true(set[0] == 0 && set[1] == UINT64_C(1) << 5);

    smp.value = -1.0;
    assert_int_equal(rl_property_evaluate(p, 3, rl_v3(1, 2, 3), &smp), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_evaluate(p, 0, rl_v3(1, NAN, 3), &smp), RL_ERR_INVALID_ARG);
    assert_true(smp.value == -1.0);
    assert_int_equal(pr.evaluations, 1);
    rl_property_release(p);
    assert_int_equal(pr.releases, 1);

    /* a commit callback that needs a scene refuses NULL */
    probe strict = { .need_scene = true };
    p = make_probe(&strict, "strict");
    assert_int_equal(rl_property_commit(p, NULL, 1), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_property_workers(p), 0);
    rl_property_release(p);

    /* a name and an evaluate callback are required */
    rl_property_callbacks cb = { .name = "x" };
    p = NULL;
    assert_int_equal(rl_property_create_custom(&cb, NULL, &p), RL_ERR_INVALID_ARG);
    cb = (rl_property_callbacks){ .evaluate = probe_evaluate };
    assert_int_equal(rl_property_create_custom(&cb, NULL, &p), RL_ERR_INVALID_ARG);
    assert_null(p);
}

static void test_combined_properties_apply_their_operation(void **state)
{
    (void)state;
    const rl_vec3 pos = rl_v3(1, 1, 1);             /* a = 3 + 3 = 6, b = 3 * 0.5 + 1 = 2.5 */
    const struct { rl_property_op op; double want; const char *name; } cases[] = {
        { RL_PROPERTY_DIFFERENCE, 3.5, "difference(a, b)" },
        { RL_PROPERTY_RATIO, 2.4, "ratio(a, b)" },
        { RL_PROPERTY_MIN, 2.5, "min(a, b)" },
        { RL_PROPERTY_MAX, 6.0, "max(a, b)" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; ++i) {
        probe pa = { .scale = 1.0, .offset = 3.0 }, pb = { .scale = 0.5, .offset = 1.0 };
        rl_property *c = NULL;
        assert_int_equal(rl_property_create_combined(cases[i].op, make_probe(&pa, "a"),
                                                     make_probe(&pb, "b"), &c),
                         RL_OK);
        assert_string_equal(rl_property_name(c), cases[i].name);
        assert_int_equal(rl_property_commit(c, NULL, 2), RL_OK);
        assert_int_equal(pa.commits, 1);
        assert_int_equal(pb.commits, 1);
        rl_property_sample smp;
        memset(&smp, 0, sizeof smp);
        assert_int_equal(rl_property_evaluate(c, 1, pos, &smp), RL_OK);
        assert_true(fabs(smp.value - cases[i].want) < 1e-12);
        rl_property_release(c);
        assert_int_equal(pa.releases, 1);
        assert_int_equal(pb.releases, 1);
    }
    /* a / 0 is NaN */
    probe pa = { .scale = 1.0 }, pz = { .scale = 0.0 };
    rl_property *c = NULL;
    assert_int_equal(rl_property_create_combined(RL_PROPERTY_RATIO, make_probe(&pa, "a"),
                                                 make_probe(&pz, "zero"), &c),
                     RL_OK);
    assert_string_equal(rl_property_unit(c), "");
    assert_int_equal(rl_property_commit(c, NULL, 1), RL_OK);
    rl_property_sample smp;
    memset(&smp, 0, sizeof smp);
    assert_int_equal(rl_property_evaluate(c, 0, pos, &smp), RL_OK);
    assert_true(isnan(smp.value));
    rl_property_release(c);
}

static void test_combined_owns_both_even_when_creation_fails(void **state)
{
    (void)state;
    probe pa = { 0 }, pb = { 0 };
    rl_property *c = (rl_property *)0x1;
    assert_int_equal(rl_property_create_combined((rl_property_op)42, make_probe(&pa, "a"),
                                                 make_probe(&pb, "b"), &c),
                     RL_ERR_INVALID_ARG);
    assert_true(c == (rl_property *)0x1);
    assert_int_equal(pa.releases, 1);
    assert_int_equal(pb.releases, 1);

    probe pc = { 0 };
    assert_int_equal(rl_property_create_combined(RL_PROPERTY_MIN, make_probe(&pc, "c"), NULL, &c),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(pc.releases, 1);

    /* flags are the union; the set is a's */
    probe px = { .set_size = 3 }, py = { 0 };
    rl_property_callbacks cb = { .name = "timed", .flags = RL_PROPERTY_EXCLUSIVE,
                                 .commit = probe_commit, .evaluate = probe_evaluate,
                                 .release = probe_release };
    rl_property *timed = NULL;
    assert_int_equal(rl_property_create_custom(&cb, &py, &timed), RL_OK);
    assert_int_equal(rl_property_create_combined(RL_PROPERTY_MAX, make_probe(&px, "x"), timed, &c),
                     RL_OK);
    assert_true(rl_property_get_flags(c) & RL_PROPERTY_EXCLUSIVE);
    assert_string_equal(rl_property_unit(c), "u");
    assert_int_equal(rl_property_commit(c, NULL, 1), RL_OK);
    assert_int_equal(rl_property_set_size(c), 3);
    uint64_t set = 0;
    rl_property_sample smp = { .set = &set };
    assert_int_equal(rl_property_evaluate(c, 0, viewer, &smp), RL_OK);
    assert_true(set == 4u);
    rl_property_release(c);
    assert_int_equal(px.releases, 1);
    assert_int_equal(py.releases, 1);
}

static void test_combined_difference_of_two_built_ins(void **state)
{
    (void)state;
    rl_scene *s = ahead_scene();
    rl_property *a = NULL, *b = NULL, *c = NULL;
    assert_int_equal(rl_property_create("visibility", &a), RL_OK);
    assert_int_equal(rl_property_set(a, "resolution", "16"), RL_OK);
    assert_int_equal(rl_property_set(a, "measure", "polygons"), RL_OK);
    assert_int_equal(rl_property_create("visibility", &b), RL_OK);
    assert_int_equal(rl_property_set(b, "resolution", "16"), RL_OK);
    assert_int_equal(rl_property_create_combined(RL_PROPERTY_DIFFERENCE, a, b, &c), RL_OK);
    assert_int_equal(rl_property_commit(c, s, 1), RL_OK);
    rl_property_sample smp = evaluate_at(c, viewer);
    assert_true(smp.value == 4.0 - 2.0);            /* triangles minus objects */
    assert_true(smp.direction[0] == 2.0 && smp.direction[1] == 0.0);
    rl_property_release(c);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_list_names_the_four_built_in_properties),
        cmocka_unit_test(test_unknown_property_is_not_found_and_lists_the_known_ones),
        cmocka_unit_test(test_evaluate_needs_a_commit_a_worker_and_a_finite_position),
        cmocka_unit_test(test_commit_needs_a_committed_non_empty_scene),
        cmocka_unit_test(test_out_of_range_options_are_invalid),
        cmocka_unit_test(test_time_rule_unconditioned_takes_medians_resets_and_skips_the_build),
        cmocka_unit_test(test_time_rule_conditioned_stops_at_two_percent_or_the_frame_limit),
        cmocka_unit_test(test_time_is_positive_exclusive_and_the_max_over_directions),
        cmocka_unit_test(test_time_rejects_unknown_renderers_and_bad_renderer_options),
        cmocka_unit_test(test_ops_counts_the_triangles_the_rasterizer_draws),
        cmocka_unit_test(test_every_ops_counter_has_its_unit),
        cmocka_unit_test(test_ops_counts_whitted_rays),
        cmocka_unit_test(test_ops_of_a_coherent_renderer_do_not_depend_on_the_previous_position),
        cmocka_unit_test(test_quality_of_the_reference_against_itself_is_perfect),
        cmocka_unit_test(test_quality_of_unshadowed_raster_against_whitted_is_below_one),
        cmocka_unit_test(test_custom_property_calls_back_and_checks_its_arguments),
        cmocka_unit_test(test_combined_properties_apply_their_operation),
        cmocka_unit_test(test_combined_owns_both_even_when_creation_fails),
        cmocka_unit_test(test_combined_difference_of_two_built_ins),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
