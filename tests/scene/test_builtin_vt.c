/* test_builtin_vt.c: the built-in scenes of the Vertex Tracing thesis
 * (Ullmann 2003): "table" (Sec. 5.1) and "cluster" (Sec. 5.4). Checks the
 * VT markings, the optical materials, that refractive parts are closed,
 * outward-wound solids (the tracer decides entering/leaving by the
 * geometric normal), the cluster's dial textures and camera path, and the
 * parameter handling. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_scene.h"

static rl_scene *build(const char *name, const char *params)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_create_builtin(name, params, &s);
    if (st != RL_OK)
        fail_msg("%s (%s): %s", name, params ? params : "", rl_last_error());
    assert_true(rl_scene_is_committed(s));
    return s;
}

static uint64_t triangles(const char *name, const char *params)
{
    rl_scene *s = build(name, params);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    assert_int_equal(st.dropped_degenerate, 0);
    assert_int_equal(st.dropped_nonfinite, 0);
    rl_scene_release(s);
    return st.triangles;
}

/* The single object drawn by the node with this name. */
static const rl_object *object_named(const rl_scene_data *d, const char *name)
{
    for (uint32_t i = 0; i < d->num_objects; ++i)
        if (strcmp(d->objects[i].name, name) == 0)
            return &d->objects[i];
    fail_msg("no object \"%s\"", name);
    return NULL;
}

/* True if the node or an ancestor carries vt=true (the renderer's rule). */
static bool is_vt(const rl_scene *s, uint32_t node)
{
    for (; node != RL_NONE; node = rl_scene_node_parent(s, node)) {
        const char *v = rl_scene_node_attr(s, node, "vt");
        if (v && strcmp(v, "true") == 0)
            return true;
    }
    return false;
}

/* The nodes that carry the attribute themselves, exactly `expected`. */
static void assert_vt_nodes(const rl_scene *s, const char *const *expected, int count)
{
    int found = 0;
    for (uint32_t n = 0; n < rl_scene_node_count(s); ++n) {
        const char *v = rl_scene_node_attr(s, n, "vt");
        if (!v)
            continue;
        assert_string_equal(v, "true");
        bool listed = false;
        for (int i = 0; i < count; ++i)
            listed |= strcmp(rl_scene_node_name(s, n), expected[i]) == 0;
        if (!listed)
            fail_msg("node \"%s\" is marked vt but should not be", rl_scene_node_name(s, n));
        ++found;
    }
    assert_int_equal(found, count);
}

/* ---- closedness: weld by position, count edge uses ---------------------- */

typedef struct welded { rl_vec3 p; uint32_t index; } welded;
typedef struct edge { uint32_t a, b; } edge;      /* directed, welded ids */

static int cmp_pos(const void *x, const void *y)
{
    const rl_vec3 *p = &((const welded *)x)->p, *q = &((const welded *)y)->p;
    if (p->x != q->x) return p->x < q->x ? -1 : 1;
    if (p->y != q->y) return p->y < q->y ? -1 : 1;
    if (p->z != q->z) return p->z < q->z ? -1 : 1;
    return 0;
}

static int cmp_edge(const void *x, const void *y)
{
    const edge *e = x, *f = y;
    uint32_t e0 = e->a < e->b ? e->a : e->b, e1 = e->a < e->b ? e->b : e->a;
    uint32_t f0 = f->a < f->b ? f->a : f->b, f1 = f->a < f->b ? f->b : f->a;
    if (e0 != f0) return e0 < f0 ? -1 : 1;
    if (e1 != f1) return e1 < f1 ? -1 : 1;
    return 0;
}

/* Every edge of the object, welded by exact position, is used by exactly two
 * triangles in opposite directions (closed, consistently wound), and the
 * enclosed signed volume is positive (outward). Returns the volume. */
static double assert_closed_outward(const rl_scene_data *d, const rl_object *o)
{
    uint32_t nt = o->num_triangles, nv = 3 * nt;
    welded *w = malloc(nv * sizeof *w);
    uint32_t *id = malloc(nv * sizeof *id);
    edge *edges = malloc(nv * sizeof *edges);
    assert_non_null(w);
    assert_non_null(id);
    assert_non_null(edges);
    double volume = 0.0;
    for (uint32_t t = 0; t < nt; ++t) {
        const uint32_t *tri = &d->indices[3 * (o->first_triangle + t)];
        rl_vec3 p0 = d->positions[tri[0]], p1 = d->positions[tri[1]], p2 = d->positions[tri[2]];
        volume += (double)rl_dot(p0, rl_cross(p1, p2)) / 6.0;
        for (int k = 0; k < 3; ++k)
            w[3 * t + (uint32_t)k] = (welded){ d->positions[tri[k]], 3 * t + (uint32_t)k };
    }
    qsort(w, nv, sizeof *w, cmp_pos);
    uint32_t unique = 0;
    for (uint32_t i = 0; i < nv; ++i) {
        if (i > 0 && cmp_pos(&w[i - 1], &w[i]) != 0)
            ++unique;
        id[w[i].index] = unique;
    }
    for (uint32_t t = 0; t < nt; ++t)
        for (uint32_t k = 0; k < 3; ++k)
            edges[3 * t + k] = (edge){ id[3 * t + k], id[3 * t + (k + 1) % 3] };
    qsort(edges, nv, sizeof *edges, cmp_edge);
    for (uint32_t i = 0; i < nv;) {
        uint32_t j = i + 1;
        while (j < nv && cmp_edge(&edges[i], &edges[j]) == 0)
            ++j;
        if (j - i != 2)
            fail_msg("%s: an edge is used by %u triangles", o->name, j - i);
        if (edges[i].a != edges[i + 1].b)
            fail_msg("%s: two neighbours wind the same way along an edge", o->name);
        i = j;
    }
    free(w);
    free(id);
    free(edges);
    if (!(volume > 0.0))
        fail_msg("%s: signed volume %g is not positive (inward winding)", o->name, volume);
    return volume;
}

/* ---- table --------------------------------------------------------------- */

static void test_table_has_about_20000_triangles_and_18_objects(void **state)
{
    (void)state;
    rl_scene *s = build("table", NULL);
    rl_scene_stats st;
    rl_scene_get_stats(s, &st);
    /* Thesis: 18 objects, about 20,000 polygons. */
    assert_int_equal(st.objects, 18);
    assert_in_range(st.triangles, 12000, 40000);
    assert_int_equal(st.dropped_degenerate, 0);
    /* One point light in the lamp shade plus the dim fill by default. */
    const rl_scene_data *d = rl_scene_get_data(s);
    assert_int_equal(d->num_lights, 2);
    const rl_object *shade = object_named(d, "lamp_shade");
    const rl_light *bulb = &d->lights[0];
    assert_int_equal(bulb->type, RL_LIGHT_POINT);
    assert_true(bulb->position.x > shade->bounds.min.x && bulb->position.x < shade->bounds.max.x);
    assert_true(bulb->position.y > shade->bounds.min.y && bulb->position.y < shade->bounds.max.y);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, "overview", &cam), RL_OK);
    rl_scene_release(s);

    rl_scene *single = build("table", "fill=0");
    assert_int_equal(rl_scene_get_data(single)->num_lights, 1);
    rl_scene_release(single);
}

static void test_table_marks_the_cups_and_the_table_top_as_vt(void **state)
{
    (void)state;
    rl_scene *s = build("table", NULL);
    static const char *const vt[] = { "table_top", "cup_blue", "glass_red" };
    assert_vt_nodes(s, vt, 3);
    const rl_scene_data *d = rl_scene_get_data(s);
    /* Every triangle of a VT object reflects or refracts. */
    int vt_objects = 0;
    for (uint32_t i = 0; i < d->num_objects; ++i) {
        const rl_object *o = &d->objects[i];
        if (!is_vt(s, o->node))
            continue;
        ++vt_objects;
        for (uint32_t t = o->first_triangle; t < o->first_triangle + o->num_triangles; ++t) {
            const rl_material *m = &d->materials[d->triangle_material[t]];
            assert_true(m->reflectivity + m->transmissivity >= 0.2f);
        }
    }
    assert_int_equal(vt_objects, 3);
    const rl_object *cup = object_named(d, "cup_blue"), *glass = object_named(d, "glass_red");
    const rl_material *mc = &d->materials[d->triangle_material[cup->first_triangle]];
    const rl_material *mg = &d->materials[d->triangle_material[glass->first_triangle]];
    const rl_material *mt = &d->materials[d->triangle_material[object_named(d, "table_top")->first_triangle]];
    assert_true(mc->reflectivity >= 0.5f && mc->transmissivity == 0.0f);
    assert_true(mg->transmissivity >= 0.6f && mg->reflectivity > 0.0f && mg->ior == 1.5f);
    assert_true(mt->reflectivity > 0.1f && mt->diffuse_texture != RL_NONE);
    /* The cups stand on the table top. */
    float top = object_named(d, "table_top")->bounds.max.y;
    assert_true(fabsf(cup->bounds.min.y - top) < 1e-4f);
    assert_true(fabsf(glass->bounds.min.y - top) < 1e-4f);
    rl_scene_release(s);
}

/* Issue 36: variant=thesis is Sec. 5.1's set-up (one light, a table top
 * that mirrors nothing, three VT objects), variant=cup the same with the
 * blue cup as the only VT object (Figs. 5.5/5.6); given fill and cloth_kr
 * win over a variant's; the default stays the mirror variant. */
static void test_table_variants(void **state)
{
    (void)state;
    static const char *const three[] = { "table_top", "cup_blue", "glass_red" };
    static const char *const cup[] = { "cup_blue" };
    struct {
        const char *params;
        uint32_t lights;
        float cloth_kr;
        const char *const *vt;
        int num_vt;
    } rows[] = {
        { NULL, 2, 0.2f, three, 3 },
        { "variant=mirror", 2, 0.2f, three, 3 },
        { "variant=thesis", 1, 0.0f, three, 3 },
        { "variant=cup", 1, 0.0f, cup, 1 },
        { "variant=cup,fill=0.15,cloth_kr=0.3", 2, 0.3f, cup, 1 },
    };
    uint64_t tris = triangles("table", NULL);
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; ++i) {
        rl_scene *s = build("table", rows[i].params);
        const rl_scene_data *d = rl_scene_get_data(s);
        assert_int_equal(d->num_lights, rows[i].lights);
        const rl_material *mt = &d->materials[d->triangle_material[object_named(d, "table_top")->first_triangle]];
        assert_float_equal(mt->reflectivity, rows[i].cloth_kr, 1e-6f);
        assert_vt_nodes(s, rows[i].vt, rows[i].num_vt);
        /* Same geometry and cameras in every variant. */
        rl_scene_stats st;
        rl_scene_get_stats(s, &st);
        assert_int_equal(st.triangles, tris);
        rl_camera cam;
        assert_int_equal(rl_scene_get_camera(s, "default", &cam), RL_OK);
        rl_scene_release(s);
    }
    rl_scene *bad = NULL;
    assert_int_equal(rl_scene_create_builtin("table", "variant=cups", &bad), RL_ERR_INVALID_ARG);
    assert_null(bad);
}

static void test_table_glass_is_a_closed_outward_solid(void **state)
{
    (void)state;
    rl_scene *s = build("table", NULL);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_object *glass = object_named(d, "glass_red");
    double v = assert_closed_outward(d, glass);
    /* A thick-walled glass: far less volume than its bounding cylinder. */
    rl_vec3 e = rl_aabb_extent(glass->bounds);
    double cylinder = 3.14159 * 0.25 * (double)e.x * (double)e.z * (double)e.y;
    assert_true(v > 0.05 * cylinder && v < 0.5 * cylinder);
    /* The other lathed solids follow the same rules. */
    assert_closed_outward(d, object_named(d, "lamp_shade"));
    assert_closed_outward(d, object_named(d, "plate"));
    rl_scene_release(s);
}

static void test_table_detail_changes_the_tessellation(void **state)
{
    (void)state;
    uint64_t coarse = triangles("table", "detail=0.5");
    uint64_t normal = triangles("table", NULL);
    uint64_t fine = triangles("table", "detail=2");
    assert_true(coarse < normal && normal < fine);
    assert_true(fine > 3 * normal / 2);
}

/* ---- cluster ------------------------------------------------------------- */

static void test_cluster_has_a_moderate_triangle_count(void **state)
{
    (void)state;
    uint64_t n = triangles("cluster", "tex=64");
    assert_in_range(n, 10000, 100000);
    assert_true(triangles("cluster", "tex=64,detail=2") > n);
    assert_true(triangles("cluster", "tex=64,detail=0.5") < n);
    /* glass_segments tessellates the glass only: 48 x 12 by default. */
    assert_true(triangles("cluster", "tex=64,glass_segments=96") > n);
}

static void test_cluster_only_the_cover_glass_is_vt_and_it_is_closed(void **state)
{
    (void)state;
    rl_scene *s = build("cluster", "tex=64");
    static const char *const vt[] = { "cover_glass" };
    assert_vt_nodes(s, vt, 1);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_object *glass = object_named(d, "cover_glass");
    const rl_material *m = &d->materials[d->triangle_material[glass->first_triangle]];
    assert_true(m->transmissivity >= 0.8f && m->reflectivity >= 0.05f && m->reflectivity <= 0.15f);
    assert_true(m->ior == 1.5f);
    /* Outer, inner, rim: 2 x 48 x 12 x 2 + 2 x 48 x 2 + 2 x 12 x 2. */
    assert_int_equal(glass->num_triangles, 2 * 48 * 12 * 2 + 2 * 48 * 2 + 2 * 12 * 2);
    double v = assert_closed_outward(d, glass);
    /* About 3 mm thick over 41 x 21 cm. */
    assert_true(v > 0.7 * 0.003 * 0.41 * 0.212 && v < 1.3 * 0.003 * 0.41 * 0.212);
    int vt_objects = 0;
    for (uint32_t i = 0; i < d->num_objects; ++i)
        vt_objects += is_vt(s, d->objects[i].node);
    assert_int_equal(vt_objects, 1);
    rl_scene_release(s);
}

static void test_cluster_has_three_cameras_and_a_4_second_head_path(void **state)
{
    (void)state;
    rl_scene *s = build("cluster", "tex=64");
    rl_camera driver, lateral, zoom;
    assert_int_equal(rl_scene_get_camera(s, NULL, &driver), RL_OK);
    rl_camera named;
    assert_int_equal(rl_scene_get_camera(s, "driver", &named), RL_OK);
    assert_true(named.eye.x == driver.eye.x && named.eye.z == driver.eye.z);
    assert_int_equal(rl_scene_get_camera(s, "lateral", &lateral), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, "zoom", &zoom), RL_OK);
    assert_true(fabsf(lateral.eye.x) > 0.2f);
    assert_true(rl_length(rl_sub(zoom.eye, zoom.target)) < rl_length(rl_sub(driver.eye, driver.target)));
    const rl_camera_path *path = rl_scene_get_data(s)->camera_path;
    assert_non_null(path);
    assert_true(rl_camera_path_duration(path) >= 3.9 && rl_camera_path_duration(path) <= 4.1);
    /* 60 frames: the head moves sideways and a little up and down, in small
     * steps (a smooth animation). */
    float min_x = 1e9f, max_x = -1e9f, min_y = 1e9f, max_y = -1e9f, max_step = 0.0f;
    rl_camera prev = rl_camera_path_frame(path, 0, 60);
    for (uint32_t i = 0; i < 60; ++i) {
        rl_camera c = rl_camera_path_frame(path, i, 60);
        min_x = rl_minf(min_x, c.eye.x), max_x = rl_maxf(max_x, c.eye.x);
        min_y = rl_minf(min_y, c.eye.y), max_y = rl_maxf(max_y, c.eye.y);
        max_step = rl_maxf(max_step, rl_length(rl_sub(c.eye, prev.eye)));
        prev = c;
    }
    assert_true(max_x - min_x > 0.15f);
    assert_true(max_y - min_y > 0.02f && max_y - min_y < max_x - min_x);
    assert_true(max_step < 0.02f);
    rl_scene_release(s);
}

/* Luminance range and share of bright texels of a material's texture. */
static void texture_contrast(const rl_scene_data *d, uint32_t material, float *lo, float *hi,
                             double *bright)
{
    uint32_t ti = d->materials[material].diffuse_texture;
    assert_int_not_equal(ti, RL_NONE);
    const rl_texture *t = d->textures[ti];
    *lo = 1e9f, *hi = -1e9f;
    size_t n = (size_t)t->width * (size_t)t->height, count = 0;
    for (size_t i = 0; i < n; ++i) {
        float y = rl_luminance(rl_v3(t->texels[i].x, t->texels[i].y, t->texels[i].z));
        *lo = rl_minf(*lo, y), *hi = rl_maxf(*hi, y);
        count += y > 0.5f;
    }
    *bright = (double)count / (double)n;
}

static void test_cluster_dials_carry_printed_scales(void **state)
{
    (void)state;
    rl_scene *s = build("cluster", "tex=512");
    const rl_scene_data *d = rl_scene_get_data(s);
    static const char *const names[2] = { "dial_speed", "dial_rpm" };
    for (int i = 0; i < 2; ++i) {
        uint32_t m = rl_scene_find_material(s, names[i]);
        assert_int_not_equal(m, RL_NONE);
        assert_int_equal(d->textures[d->materials[m].diffuse_texture]->width, 512);
        float lo, hi;
        double bright;
        texture_contrast(d, m, &lo, &hi, &bright);
        assert_true(lo < 0.05f && hi > 0.8f);         /* white print on black */
        assert_true(bright > 0.01 && bright < 0.3);   /* ticks and digits, not a fill */
    }
    /* The tachometer's red zone: strongly red texels exist. */
    const rl_texture *rpm = d->textures[d->materials[rl_scene_find_material(s, "dial_rpm")].diffuse_texture];
    size_t red = 0;
    for (size_t i = 0; i < (size_t)rpm->width * (size_t)rpm->height; ++i)
        red += rpm->texels[i].x > 0.6f && rpm->texels[i].y < 0.2f;
    assert_true(red > 100);
    rl_scene_release(s);
}

static void test_cluster_needles_follow_speed_and_rpm(void **state)
{
    (void)state;
    /* 0 km/h points to the lower left, 240 to the lower right. */
    rl_scene *lo = build("cluster", "tex=64,speed=0,rpm=0");
    rl_scene *hi = build("cluster", "tex=64,speed=240,rpm=8");
    const rl_scene_data *a = rl_scene_get_data(lo), *b = rl_scene_get_data(hi);
    rl_vec3 dial = rl_aabb_center(object_named(a, "dial_speed")->bounds);
    rl_vec3 n0 = rl_aabb_center(object_named(a, "needle_speed")->bounds);
    rl_vec3 n1 = rl_aabb_center(object_named(b, "needle_speed")->bounds);
    assert_true(n0.x < dial.x && n0.y < dial.y);
    assert_true(n1.x > dial.x && n1.y < dial.y);
    rl_scene_release(lo);
    rl_scene_release(hi);
}

/* ---- parameters ---------------------------------------------------------- */

static void test_unknown_and_out_of_range_params_are_rejected(void **state)
{
    (void)state;
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("table", "cups=3", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_create_builtin("table", "detail=100", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_create_builtin("cluster", "needles=2", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_create_builtin("cluster", "tex=16", &s), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_scene_create_builtin("cluster", "speed=300", &s), RL_ERR_INVALID_ARG);
    assert_null(s);
    /* Both are listed among the built-ins. */
    size_t n = 0;
    const rl_builtin_info *info = rl_builtin_scenes(&n);
    int listed = 0;
    for (size_t i = 0; i < n; ++i)
        listed += strcmp(info[i].name, "table") == 0 || strcmp(info[i].name, "cluster") == 0;
    assert_int_equal(listed, 2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_table_has_about_20000_triangles_and_18_objects),
        cmocka_unit_test(test_table_marks_the_cups_and_the_table_top_as_vt),
        cmocka_unit_test(test_table_variants),
        cmocka_unit_test(test_table_glass_is_a_closed_outward_solid),
        cmocka_unit_test(test_table_detail_changes_the_tessellation),
        cmocka_unit_test(test_cluster_has_a_moderate_triangle_count),
        cmocka_unit_test(test_cluster_only_the_cover_glass_is_vt_and_it_is_closed),
        cmocka_unit_test(test_cluster_has_three_cameras_and_a_4_second_head_path),
        cmocka_unit_test(test_cluster_dials_carry_printed_scales),
        cmocka_unit_test(test_cluster_needles_follow_speed_and_rpm),
        cmocka_unit_test(test_unknown_and_out_of_range_params_are_rejected),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
