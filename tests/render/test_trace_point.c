/* test_trace_point.c: Vertex Tracing samples on the exact tracer
 * (rl_tracer_shade_point, Ullmann 2003, Sec. 3.1, 3.4.5, 3.5.3). Oracle:
 * a mesh vertex shaded as a point must equal rl_tracer_shade() of the ray
 * from the eye hitting that vertex, with the same ray tree; the deferred
 * texture layers must recombine to that colour and name the surfaces the
 * mirror sees; a replayed feeler cache must change nothing but the shadow
 * ray count. Scenes are small grids built here; brute-force accel. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/trace_internal.h"
#include "rl/rl_accel.h"
#include "rl/rl_scene.h"
#include "rl/rl_trace.h"

#define GRID 4                    /* cells per grid side */

typedef struct fixture {
    rl_scene *scene;
    rl_accel *accel;
    rl_tracer *tracer;
    const rl_scene_data *data;
} fixture;

static rl_material plain(rl_vec3 kd)
{
    rl_material m = rl_material_default();
    m.diffuse = kd;
    m.specular = rl_v3s(0.0f);
    return m;
}

static uint32_t add_material(rl_scene *s, rl_material m)
{
    uint32_t id;
    assert_int_equal(rl_scene_add_material(s, &m, &id), RL_OK);
    return id;
}

/* 4x4 two-colour checker, distinct in every channel so a wrong texel shows. */
static uint32_t add_checker(rl_scene *s)
{
    rl_vec4 texels[16];
    for (int i = 0; i < 16; ++i)
        texels[i] = ((i / 4 + i % 4) % 2) ? (rl_vec4){ 0.9f, 0.2f, 0.1f, 1.0f } : (rl_vec4){ 0.1f, 0.5f, 0.9f, 1.0f };
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(4, 4, texels, &tex), RL_OK);
    uint32_t id;
    assert_int_equal(rl_scene_add_texture(s, tex, &id), RL_OK);
    return id;
}

/* GRID x GRID cells spanning origin + [0,1] eu + [0,1] ev as one object,
 * front side cross(eu, ev), uv = 2 (s, t). bend tilts the vertex normals
 * along eu so shading and geometric normals differ. */
static void add_grid(rl_scene *s, rl_vec3 origin, rl_vec3 eu, rl_vec3 ev, float bend, uint32_t material)
{
    enum { NV = (GRID + 1) * (GRID + 1) };
    rl_vec3 pos[NV], nrm[NV];
    rl_vec2 uv[NV];
    uint32_t idx[6 * GRID * GRID];
    rl_vec3 n = rl_normalize(rl_cross(eu, ev)), tu = rl_normalize(eu);
    for (int j = 0; j <= GRID; ++j) {
        for (int i = 0; i <= GRID; ++i) {
            float fs = (float)i / GRID, ft = (float)j / GRID;
            int k = j * (GRID + 1) + i;
            pos[k] = rl_add(origin, rl_add(rl_scale(eu, fs), rl_scale(ev, ft)));
            nrm[k] = rl_normalize(rl_add(n, rl_scale(tu, bend * (fs - 0.5f))));
            uv[k] = rl_v2(2.0f * fs, 2.0f * ft);
        }
    }
    uint32_t *w = idx;
    for (uint32_t j = 0; j < GRID; ++j) {
        for (uint32_t i = 0; i < GRID; ++i) {
            uint32_t a = j * (GRID + 1) + i, b = a + 1, c = a + GRID + 2, d = a + GRID + 1;
            *w++ = a; *w++ = b; *w++ = c;
            *w++ = a; *w++ = c; *w++ = d;
        }
    }
    rl_mesh_desc m = { .name = "grid", .num_vertices = NV, .positions = pos, .normals = nrm, .uvs = uv,
                       .num_triangles = 2 * GRID * GRID, .indices = idx, .material = material };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &m, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "grid", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

static void add_point_light(rl_scene *s, rl_vec3 pos, float intensity)
{
    rl_light l = { .type = RL_LIGHT_POINT, .color = rl_v3s(1.0f), .intensity = intensity, .position = pos };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
}

/* Unit square light at height y centred over the origin, shining down. */
static void add_quad_light(rl_scene *s, float y, float intensity)
{
    rl_light l = { .type = RL_LIGHT_QUAD, .color = rl_v3s(1.0f), .intensity = intensity,
                   .position = rl_v3(-0.5f, y, -0.5f), .edge_u = rl_v3(1, 0, 0), .edge_v = rl_v3(0, 0, 1) };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
}

static void finish(fixture *f, const rl_tracer_desc *desc)
{
    assert_int_equal(rl_scene_commit(f->scene), RL_OK);
    assert_int_equal(rl_accel_create(f->scene, &(rl_accel_desc){ .kind = RL_ACCEL_BRUTE }, &f->accel), RL_OK);
    assert_int_equal(rl_accel_commit(f->accel), RL_OK);
    assert_int_equal(rl_tracer_create(f->accel, desc, &f->tracer), RL_OK);
    f->data = rl_scene_get_data(f->scene);
}

static void release(fixture *f)
{
    rl_tracer_release(f->tracer);
    rl_accel_release(f->accel);
    rl_scene_release(f->scene);
}

/* Objects: 0 floor y = 0 (x, z in [-2, 2], checker, glossy), 1 mirror
 * z = -2 (k_r 0.7, checker too), 2 glass pane x = 1.5 (k_t 0.8, k_r 0.1,
 * bent normals). A point light and a quad light. */
static void showroom(fixture *f, bool textured)
{
    assert_int_equal(rl_scene_create(&f->scene), RL_OK);
    uint32_t tex = textured ? add_checker(f->scene) : RL_NONE;
    rl_material floor = plain(rl_v3(0.8f, 0.7f, 0.6f));
    floor.specular = rl_v3s(0.3f);
    floor.shininess = 20.0f;
    floor.diffuse_texture = tex;
    rl_material mirror = plain(rl_v3s(0.25f));
    mirror.reflectivity = 0.7f;
    mirror.diffuse_texture = tex;
    rl_material glass = plain(rl_v3s(0.05f));
    glass.transmissivity = 0.8f;
    glass.reflectivity = 0.1f;
    glass.ior = 1.5f;
    add_grid(f->scene, rl_v3(-2, 0, 2), rl_v3(4, 0, 0), rl_v3(0, 0, -4), 0.0f, add_material(f->scene, floor));
    add_grid(f->scene, rl_v3(-2, 0, -2), rl_v3(4, 0, 0), rl_v3(0, 3, 0), 0.3f, add_material(f->scene, mirror));
    add_grid(f->scene, rl_v3(1.5f, 0, -1.5f), rl_v3(0, 0, 3), rl_v3(0, 2, 0), 0.4f, add_material(f->scene, glass));
    add_point_light(f->scene, rl_v3(-1.0f, 2.5f, 1.0f), 6.0f);
    add_quad_light(f->scene, 2.8f, 4.0f);
    finish(f, &(rl_tracer_desc){ .area_samples = 2, .seed = 11 });
}

static void assert_close(float got, float want, float rel)
{
    if (!(fabsf(got - want) <= rel * fmaxf(fabsf(want), 1e-6f)))
        fail_msg("got %.9g, want %.9g (relative tolerance %g)", (double)got, (double)want, (double)rel);
}

static void assert_color_close(rl_vec3 got, rl_vec3 want, float rel)
{
    assert_close(got.x, want.x, rel);
    assert_close(got.y, want.y, rel);
    assert_close(got.z, want.z, rel);
}

/* Corner c of triangle t as a point, and as the hit rl_tracer_shade takes. */
static rl_trace_point vertex_point(const rl_scene_data *d, uint32_t t, int c, rl_hit *hit)
{
    uint32_t k = d->indices[3 * t + (uint32_t)c];
    *hit = (rl_hit){ .t = 1.0f, .u = c == 1 ? 1.0f : 0.0f, .v = c == 2 ? 1.0f : 0.0f, .triangle = t,
                     .object = d->triangle_object[t] };
    return (rl_trace_point){ d->positions[k], d->normals[k], d->uvs[k], t };
}

/* Shades every vertex of every object from eye both ways and compares
 * colour, ray counts and tree. Returns how many saw textures. */
static int assert_vertices_match_shade(const fixture *f, rl_vec3 eye, uint64_t seed)
{
    int textured = 0;
    for (uint32_t t = 0; t < f->data->num_triangles; ++t) {
        for (int c = 0; c < 3; ++c) {
            rl_hit hit;
            rl_trace_point pt = vertex_point(f->data, t, c, &hit);
            /* Unnormalised direction: the tracer normalises it once, as
             * shade_point does eye - p, so both see the same bits. */
            rl_ray ray = { eye, 0.0f, rl_sub(pt.p, eye), INFINITY };
            uint64_t id = seed + 3 * t + (uint64_t)c;
            rl_trace_result want;
            rl_ray_tree want_tree, got_tree;
            rl_tracer_shade(f->tracer, &ray, &hit, RL_RAY_PRIMARY, id, &want, &want_tree);
            rl_trace_sample got;
            rl_tracer_shade_point(f->tracer, eye, &pt, id, NULL, NULL, &got, &got_tree);
            assert_color_close(got.color, want.color, 1e-5f);
            assert_memory_equal(got.rays, want.rays, sizeof got.rays);
            assert_true(rl_ray_tree_equal(&got_tree, &want_tree));
            assert_int_equal(got.feelers_reused, 0);
            for (int i = 0; i < RL_TRACE_LAYER_COUNT; ++i)
                textured += got.layers[i].texture != RL_NONE;
        }
    }
    return textured;
}

static void test_a_vertex_shaded_as_a_point_equals_shading_its_hit(void **state)
{
    (void)state;
    fixture f = { 0 };
    showroom(&f, true);
    int textured = assert_vertices_match_shade(&f, rl_v3(0.3f, 1.6f, 3.0f), 0);
    textured += assert_vertices_match_shade(&f, rl_v3(-1.2f, 0.9f, 1.1f), 1000);
    assert_true(textured > 100);   /* the checker was actually deferred */
    release(&f);
}

static void test_flat_equals_color_exactly_without_textures(void **state)
{
    (void)state;
    fixture f = { 0 };
    showroom(&f, false);
    assert_vertices_match_shade(&f, rl_v3(0.3f, 1.6f, 3.0f), 0);
    rl_vec3 eye = rl_v3(0.3f, 1.6f, 3.0f);
    for (uint32_t t = 0; t < f.data->num_triangles; ++t) {
        rl_hit hit;
        rl_trace_point pt = vertex_point(f.data, t, 0, &hit);
        rl_trace_sample s;
        rl_tracer_shade_point(f.tracer, eye, &pt, t, NULL, NULL, &s, NULL);
        assert_memory_equal(&s.flat, &s.color, sizeof s.color);
        assert_true(s.color.x > 0.0f);
    }
    release(&f);

    /* Sensitivity: with the checker the two differ on the floor. */
    showroom(&f, true);
    rl_hit hit;
    rl_trace_point pt = vertex_point(f.data, 0, 0, &hit);
    rl_trace_sample s;
    rl_tracer_shade_point(f.tracer, eye, &pt, 0, NULL, NULL, &s, NULL);
    assert_true(fabsf(s.flat.x - s.color.x) > 0.01f * s.color.x);
    release(&f);
}

/* The mirror vertex (0, 0.75, -2) seen from (0, 2, 2) reflects the ray onto
 * the floor at (0, 0, 0.4), where the floor's uv is 2 ((x+2)/4, (2-z)/4). */
static void test_mirror_layer_defers_the_floor_texture_at_the_reflected_uv(void **state)
{
    (void)state;
    fixture f = { 0 };
    showroom(&f, true);
    const rl_vec3 eye = rl_v3(0.0f, 2.0f, 2.0f);
    const uint32_t mirror = 1;
    const rl_object *o = &f.data->objects[mirror];
    rl_trace_point pt = { rl_v3(0.0f, 0.75f, -2.0f), rl_v3(0, 0, 1), rl_v2(1.0f, 0.5f), o->first_triangle };
    rl_trace_sample s;
    rl_ray_tree tree;
    rl_tracer_shade_point(f.tracer, eye, &pt, 5, NULL, NULL, &s, &tree);

    const rl_trace_layer *prim = &s.layers[RL_TRACE_LAYER_PRIMARY];
    const rl_trace_layer *refl = &s.layers[RL_TRACE_LAYER_REFLECTION];
    assert_int_equal(prim->texture, 0);
    assert_close(prim->uv.x, 1.0f, 1e-6f);
    assert_close(prim->uv.y, 0.5f, 1e-6f);
    assert_int_equal(refl->texture, 0);
    assert_close(refl->uv.x, 1.0f, 1e-4f);
    assert_close(refl->uv.y, 0.8f, 1e-4f);
    assert_true(refl->diffuse.x > 0.0f);
    assert_int_equal(s.layers[RL_TRACE_LAYER_REFRACTION].texture, RL_NONE);
    assert_memory_equal(&s.layers[RL_TRACE_LAYER_REFRACTION].diffuse, &(rl_vec3){ 0 }, sizeof(rl_vec3));
    assert_int_equal(tree.nodes[0].object, mirror);

    /* Recombined by hand, the layers give the colour. */
    rl_vec3 sum = rl_v3s(0.0f);
    for (int i = 0; i < RL_TRACE_LAYER_COUNT; ++i) {
        const rl_trace_layer *l = &s.layers[i];
        rl_vec3 texel = rl_v3s(1.0f);
        if (l->texture != RL_NONE) {
            rl_vec4 t4 = rl_texture_sample(f.data->textures[l->texture], l->uv);
            texel = rl_v3(t4.x, t4.y, t4.z);
        }
        sum = rl_add(sum, rl_add(rl_mul(l->diffuse, texel), l->rest));
    }
    assert_color_close(sum, s.color, 1e-6f);
    /* The reflected texel is the floor's checker, not white. */
    rl_vec4 t4 = rl_texture_sample(f.data->textures[0], refl->uv);
    assert_true(rl_vmax_comp(rl_v3(t4.x, t4.y, t4.z)) < 0.95f);
    release(&f);
}

/* A layer recombined by hand: diffuse x texel + rest. */
static rl_vec3 layer_sum(const rl_scene_data *d, const rl_trace_layer *l)
{
    rl_vec3 texel = rl_v3s(1.0f);
    if (l->texture != RL_NONE) {
        rl_vec4 t4 = rl_texture_sample(d->textures[l->texture], l->uv);
        texel = rl_v3(t4.x, t4.y, t4.z);
    }
    return rl_add(rl_mul(l->diffuse, texel), l->rest);
}

/* A checkered floor y = 0 under a glass shell: two clear panes y = 1 and
 * y = 0.9 (k_t 0.9, ior 1, so rays go straight). The refraction layer of a
 * point on the upper pane defers the floor's texture through the lower,
 * untextured pane (rl_tracer_desc.defer_through), at the uv of the floor
 * point on the straight line from the eye; without it the layer stops at
 * the pane (the thesis). Either way every vertex recombines to the colour
 * rl_tracer_shade gives. */
static void shell(fixture *f, bool defer_through)
{
    assert_int_equal(rl_scene_create(&f->scene), RL_OK);
    rl_material floor = plain(rl_v3(0.8f, 0.8f, 0.8f));
    floor.diffuse_texture = add_checker(f->scene);
    rl_material glass = plain(rl_v3s(0.05f));
    glass.transmissivity = 0.9f;
    glass.ior = 1.0f;
    add_grid(f->scene, rl_v3(-2, 0, 2), rl_v3(4, 0, 0), rl_v3(0, 0, -4), 0.0f, add_material(f->scene, floor));
    uint32_t g = add_material(f->scene, glass);
    add_grid(f->scene, rl_v3(-2, 1.0f, 2), rl_v3(4, 0, 0), rl_v3(0, 0, -4), 0.0f, g);
    add_grid(f->scene, rl_v3(-2, 0.9f, 2), rl_v3(4, 0, 0), rl_v3(0, 0, -4), 0.0f, g);
    add_point_light(f->scene, rl_v3(0.5f, 4.0f, 0.5f), 10.0f);
    finish(f, &(rl_tracer_desc){ .no_shadows = true, .defer_through = defer_through });
}

static void test_deferred_textures_pass_through_an_untextured_glass_shell(void **state)
{
    (void)state;
    const rl_vec3 eye = rl_v3(0.2f, 3.0f, 0.3f);
    int textured[2];
    for (int k = 0; k < 2; ++k) {
        fixture f = { 0 };
        shell(&f, k == 1);
        const rl_object *upper = &f.data->objects[1];
        rl_trace_point pt = { rl_v3(0.0f, 1.0f, 0.0f), rl_v3(0, 1, 0), rl_v2(1.0f, 1.0f), upper->first_triangle };
        rl_trace_sample s;
        rl_tracer_shade_point(f.tracer, eye, &pt, 9, NULL, NULL, &s, NULL);
        const rl_trace_layer *refr = &s.layers[RL_TRACE_LAYER_REFRACTION];
        if (k == 1) {
            /* The floor point (-0.1, 0, -0.15): uv = 2 ((x + 2) / 4, (2 - z) / 4). */
            assert_int_equal(refr->texture, 0);
            assert_close(refr->uv.x, 0.95f, 1e-4f);
            assert_close(refr->uv.y, 1.075f, 1e-4f);
            assert_true(refr->diffuse.x > 0.0f);
        } else {
            assert_int_equal(refr->texture, RL_NONE);
        }
        assert_color_close(rl_add(rl_add(layer_sum(f.data, &s.layers[0]),
                                         layer_sum(f.data, &s.layers[1])),
                                  layer_sum(f.data, refr)),
                           s.color, 1e-5f);
        textured[k] = assert_vertices_match_shade(&f, eye, 77);
        release(&f);
    }
    assert_true(textured[1] > textured[0]);
}

/* Glass pane z = 0 (front +z); from below it (inside the glass) at 60°
 * from the normal, sin 60° * 1.5 > 1: total internal reflection folds k_t
 * into the reflection. From above at the same angle the ray refracts. */
static void test_total_internal_reflection_folds_refraction_into_the_mirror_layer(void **state)
{
    (void)state;
    fixture f = { 0 };
    assert_int_equal(rl_scene_create(&f.scene), RL_OK);
    rl_material glass = plain(rl_v3s(0.1f));
    glass.transmissivity = 0.6f;
    glass.reflectivity = 0.2f;
    glass.ior = 1.5f;
    add_grid(f.scene, rl_v3(-2, -2, 0), rl_v3(4, 0, 0), rl_v3(0, 4, 0), 0.0f, add_material(f.scene, glass));
    add_grid(f.scene, rl_v3(-5, -5, -2), rl_v3(10, 0, 0), rl_v3(0, 10, 0), 0.0f,
             add_material(f.scene, plain(rl_v3s(0.6f))));
    add_grid(f.scene, rl_v3(-5, 5, 2), rl_v3(10, 0, 0), rl_v3(0, -10, 0), 0.0f,
             add_material(f.scene, plain(rl_v3s(0.4f))));
    add_point_light(f.scene, rl_v3(0.5f, 0.5f, 1.0f), 2.0f);
    add_point_light(f.scene, rl_v3(0.5f, -0.5f, -1.0f), 2.0f);
    finish(&f, &(rl_tracer_desc){ .background = rl_v3(0.1f, 0.2f, 0.3f) });

    const float a = rl_radians(60.0f);
    for (int side = 0; side < 2; ++side) {
        float z = side == 0 ? -1.0f : 1.0f;
        rl_vec3 eye = rl_v3(0.0f, -tanf(a), z);   /* looks at the vertex (0, 0, 0) */
        for (uint32_t t = 0; t < f.data->objects[0].num_triangles; ++t) {
            for (int c = 0; c < 3; ++c) {
                rl_hit hit;
                rl_trace_point pt = vertex_point(f.data, t, c, &hit);
                if (rl_length2(pt.p) != 0.0f)
                    continue;
                rl_ray ray = { eye, 0.0f, rl_sub(pt.p, eye), INFINITY };
                rl_trace_result want;
                rl_ray_tree want_tree, got_tree;
                rl_tracer_shade(f.tracer, &ray, &hit, RL_RAY_PRIMARY, 3, &want, &want_tree);
                rl_trace_sample got;
                rl_tracer_shade_point(f.tracer, eye, &pt, 3, NULL, NULL, &got, &got_tree);
                assert_color_close(got.color, want.color, 1e-5f);
                assert_true(rl_ray_tree_equal(&got_tree, &want_tree));
                assert_memory_equal(&got.flat, &got.color, sizeof got.color);
                const rl_trace_layer *refr = &got.layers[RL_TRACE_LAYER_REFRACTION];
                if (side == 0) {
                    assert_int_equal(got.rays[RL_RAY_REFRACTION], 0);
                    assert_int_equal(got.rays[RL_RAY_REFLECTION], 1);
                    assert_memory_equal(refr, &(rl_trace_layer){ .texture = RL_NONE }, sizeof *refr);
                    assert_true(got.layers[RL_TRACE_LAYER_REFLECTION].diffuse.x > 0.0f);
                    assert_int_equal(got_tree.nodes[0].object, 0);
                } else {
                    assert_int_equal(got.rays[RL_RAY_REFRACTION], 1);
                    assert_true(refr->diffuse.x > 0.0f);
                }
            }
        }
    }
    release(&f);
}

/* Objects: 0 floor y = 0 (k_r 0.2) under the unit quad light at y = 3;
 * 1 an occluder y = 1.5 over x < 0 that puts the origin in the penumbra
 * (half the light samples blocked, the first one among them); 2 a wall
 * x = -2 facing +x, lit, which the floor reflects towards an eye at +x.
 * A point light below the floor lights the floor's underside. */
static void penumbra(fixture *f, int area_samples)
{
    assert_int_equal(rl_scene_create(&f->scene), RL_OK);
    rl_material floor = plain(rl_v3s(0.7f));
    floor.specular = rl_v3s(0.2f);
    floor.reflectivity = 0.2f;
    uint32_t grey = add_material(f->scene, plain(rl_v3s(0.5f)));
    add_grid(f->scene, rl_v3(-2, 0, 2), rl_v3(4, 0, 0), rl_v3(0, 0, -4), 0.0f, add_material(f->scene, floor));
    add_grid(f->scene, rl_v3(-2, 1.5f, 2), rl_v3(2, 0, 0), rl_v3(0, 0, -4), 0.0f, grey);
    add_grid(f->scene, rl_v3(-2, 0, 2), rl_v3(0, 0, -4), rl_v3(0, 3, 0), 0.0f, grey);
    add_quad_light(f->scene, 3.0f, 5.0f);
    add_point_light(f->scene, rl_v3(0.3f, -1.0f, 0.2f), 1.0f);
    finish(f, &(rl_tracer_desc){ .area_samples = area_samples, .seed = 3 });
}

static void assert_samples_identical(const rl_trace_sample *a, const rl_trace_sample *b)
{
    assert_memory_equal(&a->color, &b->color, sizeof a->color);
    assert_memory_equal(&a->flat, &b->flat, sizeof a->flat);
    for (int i = 0; i < RL_TRACE_LAYER_COUNT; ++i) {
        assert_memory_equal(&a->layers[i].diffuse, &b->layers[i].diffuse, sizeof(rl_vec3));
        assert_memory_equal(&a->layers[i].rest, &b->layers[i].rest, sizeof(rl_vec3));
        assert_int_equal(a->layers[i].texture, b->layers[i].texture);
    }
}

static void test_replayed_feelers_are_bit_identical_and_save_shadow_rays(void **state)
{
    (void)state;
    fixture f = { 0 };
    penumbra(&f, 4);
    const rl_vec3 eye = rl_v3(3.0f, 1.0f, 0.0f);
    rl_trace_point pt = { rl_v3s(0.0f), rl_v3(0, 1, 0), rl_v2(1, 1), f.data->objects[0].first_triangle };

    for (int with_tree = 0; with_tree < 2; ++with_tree) {
        rl_ray_tree t1, t2;
        rl_trace_feelers cache;
        rl_trace_sample traced, replayed;
        rl_tracer_shade_point(f.tracer, eye, &pt, 42, NULL, &cache, &traced, with_tree ? &t1 : NULL);
        assert_int_equal(cache.count, 16);
        assert_true(cache.complete);
        assert_true(cache.front);
        uint32_t blocked = 0;
        for (uint32_t i = 0; i < cache.count; ++i)
            blocked += cache.occluder[i] != RL_ID_NONE;
        assert_true(blocked > 0 && blocked < cache.count);   /* a real penumbra */
        if (with_tree)
            for (uint32_t i = 0; i < cache.count; ++i)
                assert_true(cache.occluder[i] == RL_ID_NONE || cache.occluder[i] == 1);

        /* Replay through the same struct as in and out: nothing changes. */
        rl_trace_feelers copy = cache;
        rl_tracer_shade_point(f.tracer, eye, &pt, 42, &cache, &cache, &replayed, with_tree ? &t2 : NULL);
        assert_samples_identical(&traced, &replayed);
        assert_int_equal(replayed.feelers_reused, 16);
        assert_int_equal(replayed.rays[RL_RAY_SHADOW], traced.rays[RL_RAY_SHADOW] - 16);
        assert_int_equal(replayed.rays[RL_RAY_REFLECTION], traced.rays[RL_RAY_REFLECTION]);
        assert_true(replayed.rays[RL_RAY_SHADOW] > 0);   /* the wall's feelers: traced */
        assert_true(replayed.layers[RL_TRACE_LAYER_REFLECTION].diffuse.x > 0.0f);
        assert_int_equal(copy.count, cache.count);
        assert_true(copy.front == cache.front && copy.complete == cache.complete);
        assert_memory_equal(copy.occluder, cache.occluder, sizeof cache.occluder);
        if (with_tree) {
            assert_true(rl_ray_tree_equal(&t1, &t2));
            assert_int_equal(rl_ray_tree_hash(&t1), rl_ray_tree_hash(&t2));
        }
    }

    /* A cache filled without a tree does not name its occluders: replayed
     * into a tree it is traced afresh, and the tree stays exact. */
    rl_trace_feelers anon;
    rl_trace_sample s1, s2;
    rl_ray_tree want, got;
    rl_tracer_shade_point(f.tracer, eye, &pt, 42, NULL, &anon, &s1, NULL);
    rl_tracer_shade_point(f.tracer, eye, &pt, 42, &anon, NULL, &s2, &got);
    assert_int_equal(s2.feelers_reused, 0);
    rl_tracer_shade_point(f.tracer, eye, &pt, 42, NULL, NULL, &s1, &want);
    assert_true(rl_ray_tree_equal(&got, &want));
    release(&f);
}

static void test_a_cache_from_the_other_side_or_incomplete_is_not_used(void **state)
{
    (void)state;
    fixture f = { 0 };
    penumbra(&f, 9);              /* 81 depth-0 feelers: more than the cache holds */
    rl_trace_point pt = { rl_v3s(0.0f), rl_v3(0, 1, 0), rl_v2(1, 1), f.data->objects[0].first_triangle };
    rl_trace_feelers cache;
    rl_trace_sample s, fresh;
    rl_tracer_shade_point(f.tracer, rl_v3(0.5f, 2.0f, 3.0f), &pt, 1, NULL, &cache, &s, NULL);
    assert_int_equal(cache.count, RL_TRACE_FEELER_CACHE_MAX);
    assert_false(cache.complete);
    rl_tracer_shade_point(f.tracer, rl_v3(0.5f, 2.0f, 3.0f), &pt, 1, &cache, NULL, &fresh, NULL);
    assert_int_equal(fresh.feelers_reused, 0);
    assert_int_equal(fresh.rays[RL_RAY_SHADOW], s.rays[RL_RAY_SHADOW]);
    release(&f);

    penumbra(&f, 2);
    pt.triangle = f.data->objects[0].first_triangle;
    rl_tracer_shade_point(f.tracer, rl_v3(0.5f, 2.0f, 3.0f), &pt, 1, NULL, &cache, &s, NULL);
    assert_true(cache.complete);
    assert_true(cache.front);
    /* From below the floor only the point light underneath is in front of
     * the surface; replaying the upper side's first feeler (blocked) for it
     * would darken the point. */
    assert_int_not_equal(cache.occluder[0], RL_ID_NONE);
    const rl_vec3 below = rl_v3(0.5f, -2.0f, 3.0f);
    rl_trace_feelers other;
    rl_trace_sample replayed;
    rl_tracer_shade_point(f.tracer, below, &pt, 1, NULL, &other, &fresh, NULL);
    rl_tracer_shade_point(f.tracer, below, &pt, 1, &cache, NULL, &replayed, NULL);
    assert_int_equal(replayed.feelers_reused, 0);
    assert_false(other.front);
    assert_int_equal(other.count, 1);
    assert_int_equal(other.occluder[0], RL_ID_NONE);
    assert_samples_identical(&fresh, &replayed);
    assert_memory_equal(replayed.rays, fresh.rays, sizeof fresh.rays);
    release(&f);
}

/* Intersection hints (Ullmann 2003, Sec. 3.3.1, 6.2.2): a point traced with
 * the hints of a neighbour, or with hints naming arbitrary triangles, gives
 * bit for bit the sample, ray counts and ray tree it gives without, with
 * closest-hit and with any-hit feelers, on brute force and on the BVH; the
 * neighbour's hints are hit often (else they would be dead code). */
static void test_hints_change_nothing_and_neighbours_hints_hit(void **state)
{
    (void)state;
    fixture f = { 0 };
    penumbra(&f, 4);
    rl_accel *bvh = NULL;
    assert_int_equal(rl_accel_create(f.scene, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &bvh), RL_OK);
    assert_int_equal(rl_accel_commit(bvh), RL_OK);
    rl_tracer *tracers[3] = { f.tracer, NULL, NULL };
    const rl_tracer_desc closest = { .area_samples = 4, .seed = 3 };
    const rl_tracer_desc any = { .area_samples = 4, .seed = 3, .tree_shadow_any_hit = true };
    assert_int_equal(rl_tracer_create(bvh, &closest, &tracers[1]), RL_OK);
    assert_int_equal(rl_tracer_create(bvh, &any, &tracers[2]), RL_OK);
    const rl_vec3 eye = rl_v3(3.0f, 1.0f, 0.0f);
    const rl_scene_data *d = f.data;
    uint32_t seed = 99u;
    for (int k = 0; k < 3; ++k) {
        uint32_t tests = 0, hits = 0;
        const rl_object *floor = &d->objects[0];
        for (uint32_t t = floor->first_triangle; t < floor->first_triangle + floor->num_triangles; ++t) {
            rl_hit unused;
            /* The neighbour: the midpoint of the triangle's first edge, as
             * a refined vertex would be between two parents. */
            rl_trace_point a = vertex_point(d, t, 0, &unused), b = vertex_point(d, t, 1, &unused);
            rl_trace_point mid = { rl_scale(rl_add(a.p, b.p), 0.5f), rl_v3(0, 1, 0), rl_v2(0.5f, 0.5f), t };
            rl_trace_hints ha, hb, junk, own;
            rl_trace_sample sa, sb, want, got;
            rl_tracer_shade_point_hinted(tracers[k], eye, &a, 7, NULL, NULL, NULL, &ha, &sa, NULL);
            rl_tracer_shade_point_hinted(tracers[k], eye, &b, 8, NULL, NULL, NULL, &hb, &sb, NULL);
            assert_true(ha.count > 0 && ha.count <= RL_TRACE_HINT_MAX);
            junk.count = RL_TRACE_HINT_MAX;
            for (uint32_t i = 0; i < junk.count; ++i) {
                seed = seed * 1664525u + 1013904223u;
                junk.triangle[i] = (seed >> 8) % (d->num_triangles + 2);   /* some out of range */
            }
            for (int with_tree = 0; with_tree < 2; ++with_tree) {
                rl_ray_tree tw, tg;
                rl_tracer_shade_point(tracers[k], eye, &mid, 9, NULL, NULL, &want, with_tree ? &tw : NULL);
                const rl_trace_hints *parents[2] = { &ha, &hb }, *bad[2] = { &junk, NULL };
                for (int h = 0; h < 2; ++h) {
                    rl_tracer_shade_point_hinted(tracers[k], eye, &mid, 9, NULL, NULL, h ? bad : parents, &own,
                                                 &got, with_tree ? &tg : NULL);
                    assert_samples_identical(&want, &got);
                    assert_memory_equal(want.rays, got.rays, sizeof want.rays);
                    if (with_tree)
                        assert_true(rl_ray_tree_equal(&tw, &tg));
                    assert_true(got.hint_hits <= got.hint_tests);
                    if (!h) {
                        tests += got.hint_tests;
                        hits += got.hint_hits;
                    }
                }
            }
        }
        print_message("tracer %d: %u of %u hinted rays hit their hint\n", k, hits, tests);
        assert_true(tests > 0 && hits > tests / 4);
    }
    rl_tracer_release(tracers[1]);
    rl_tracer_release(tracers[2]);
    rl_accel_release(bvh);
    release(&f);
}

/* The hint is a guess: one naming a triangle behind the closest hit only
 * bounds the search, which still finds the closer one; a feeler ends at a
 * hinted triangle only if it lies within the feeler's reach. Straight down
 * at x = -1 a ray meets the occluder (y = 1.5) before the floor. */
static void test_a_far_hint_only_bounds_the_search(void **state)
{
    (void)state;
    fixture f = { 0 };
    penumbra(&f, 1);
    rl_accel *bvh = NULL;
    assert_int_equal(rl_accel_create(f.scene, &(rl_accel_desc){ .kind = RL_ACCEL_BVH }, &bvh), RL_OK);
    assert_int_equal(rl_accel_commit(bvh), RL_OK);
    rl_tracer *tr = NULL;
    assert_int_equal(rl_tracer_create(bvh, NULL, &tr), RL_OK);
    rl_hit near, far;
    rl_ray down = { rl_v3(-1.1f, 2.5f, 0.3f), 0.0f, rl_v3(0, -1, 0), INFINITY };
    rl_ray below = { rl_v3(-1.1f, 1.0f, 0.3f), 0.0f, rl_v3(0, -1, 0), INFINITY };
    assert_true(rl_accel_intersect(bvh, &(rl_ray){ down.o, 0.0f, down.d, INFINITY }, &near));
    assert_true(rl_accel_intersect(bvh, &below, &far));
    assert_int_equal(near.object, 1);
    assert_int_equal(far.object, 0);

    rl_trace_hints hint = { .count = 2, .triangle = { far.triangle, far.triangle } }, out;
    uint64_t rays[RL_RAY_TYPE_COUNT];
    rl_trace_ctx ctx;
    rl_trace_begin(tr, 1, rays, NULL, &ctx);
    ctx.hint_in[0] = &hint;
    ctx.hint_out = &out;
    out.count = 0;
    rl_ray r = down;
    rl_hit got;
    assert_true(rl_trace_intersect(&ctx, rl_trace_slot(&ctx), &r, &got));
    assert_int_equal(got.triangle, near.triangle);
    assert_true(got.t == near.t && got.u == near.u && got.v == near.v && r.t_max == near.t);
    assert_int_equal(ctx.hint_tests, 1);
    assert_int_equal(ctx.hint_hits, 1);   /* the far hit bounded the search */
    assert_int_equal(out.triangle[0], near.triangle);

    /* Any hit: the far floor is within a feeler to y = -1 (blocked, at once),
     * not within one that ends at y = 0.5 above it (the search decides:
     * the occluder blocks). */
    rl_ray feeler = down;
    feeler.t_max = 3.5f;
    assert_true(rl_trace_occluded(&ctx, rl_trace_slot(&ctx), &feeler));
    assert_int_equal(ctx.hint_hits, 2);
    assert_int_equal(out.triangle[1], far.triangle);
    feeler.t_max = 2.0f;
    ctx.slot = 1;
    assert_true(rl_trace_occluded(&ctx, rl_trace_slot(&ctx), &feeler));
    assert_int_equal(ctx.hint_tests, 3);
    assert_int_equal(ctx.hint_hits, 2);
    assert_int_equal(out.triangle[1], near.triangle);
    rl_tracer_release(tr);
    rl_accel_release(bvh);
    release(&f);
}

static void test_degenerate_points_shade_as_the_background(void **state)
{
    (void)state;
    fixture f = { 0 };
    penumbra(&f, 2);
    rl_tracer_release(f.tracer);
    const rl_vec3 bg = rl_v3(0.25f, 0.5f, 0.75f);
    assert_int_equal(rl_tracer_create(f.accel, &(rl_tracer_desc){ .background = bg }, &f.tracer), RL_OK);
    const rl_trace_point good = { rl_v3(0.5f, 0.0f, 0.5f), rl_v3(0, 1, 0), rl_v2(0, 0), 0 };
    rl_trace_point bad[3] = { good, good, good };
    rl_vec3 eyes[3] = { rl_v3(0, 2, 2), good.p, rl_v3(0, 2, 2) };
    bad[0].triangle = f.data->num_triangles;
    bad[2].p = rl_v3(NAN, 0.0f, 0.0f);
    for (int i = 0; i < 3; ++i) {
        rl_trace_sample s;
        rl_ray_tree tree;
        rl_trace_feelers cache;
        memset(&cache, 0x5a, sizeof cache);
        rl_tracer_shade_point(f.tracer, eyes[i], &bad[i], 9, NULL, &cache, &s, &tree);
        assert_memory_equal(&s.color, &bg, sizeof bg);
        assert_memory_equal(&s.flat, &bg, sizeof bg);
        assert_int_equal(s.rays[RL_RAY_PRIMARY], 1);
        assert_int_equal(s.rays[RL_RAY_SHADOW] + s.rays[RL_RAY_REFLECTION] + s.rays[RL_RAY_REFRACTION], 0);
        assert_int_equal(tree.count, 1);
        assert_int_equal(tree.nodes[0].object, RL_ID_NONE);
        assert_int_equal(cache.count, 0);
        assert_false(cache.complete);
    }
    /* The normal with no length falls back to the geometric normal. */
    rl_trace_point flat_n = good;
    flat_n.n = rl_v3s(0.0f);
    rl_trace_sample a, b;
    rl_tracer_shade_point(f.tracer, rl_v3(0, 2, 2), &good, 9, NULL, NULL, &a, NULL);
    rl_tracer_shade_point(f.tracer, rl_v3(0, 2, 2), &flat_n, 9, NULL, NULL, &b, NULL);
    assert_samples_identical(&a, &b);
    assert_true(a.color.x > bg.x);
    release(&f);
}

static void test_tree_hash_follows_tree_equality(void **state)
{
    (void)state;
    fixture f = { 0 };
    penumbra(&f, 2);
    rl_trace_point pt = { rl_v3s(0.0f), rl_v3(0, 1, 0), rl_v2(1, 1), f.data->objects[0].first_triangle };
    rl_trace_sample s;
    rl_ray_tree a;
    rl_tracer_shade_point(f.tracer, rl_v3(0.5f, 2.0f, 3.0f), &pt, 1, NULL, NULL, &s, &a);
    assert_true(a.count > 3);

    /* Same fields, different padding and unused nodes: same hash. */
    rl_ray_tree b;
    memset(&b, 0xa5, sizeof b);
    b.count = a.count;
    b.truncated = a.truncated;
    for (uint32_t i = 0; i < a.count; ++i) {
        b.nodes[i].type = a.nodes[i].type;
        b.nodes[i].depth = a.nodes[i].depth;
        b.nodes[i].object = a.nodes[i].object;
        b.nodes[i].light = a.nodes[i].light;
    }
    assert_true(rl_ray_tree_equal(&a, &b));
    assert_int_equal(rl_ray_tree_hash(&a), rl_ray_tree_hash(&b));

    uint64_t h = rl_ray_tree_hash(&a);
    for (uint32_t i = 0; i < a.count; ++i) {
        rl_ray_tree c = b;
        c.nodes[i].object ^= 1u;
        assert_false(rl_ray_tree_equal(&a, &c));
        assert_int_not_equal(rl_ray_tree_hash(&c), h);
        c = b;
        c.nodes[i].light = c.nodes[i].light == RL_ID_NONE ? 0u : RL_ID_NONE;
        assert_int_not_equal(rl_ray_tree_hash(&c), h);
        c = b;
        c.nodes[i].depth++;
        assert_int_not_equal(rl_ray_tree_hash(&c), h);
    }
    rl_ray_tree c = b;
    c.truncated = !c.truncated;
    assert_int_not_equal(rl_ray_tree_hash(&c), h);
    c = b;
    c.count--;
    assert_int_not_equal(rl_ray_tree_hash(&c), h);
    release(&f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_a_vertex_shaded_as_a_point_equals_shading_its_hit),
        cmocka_unit_test(test_flat_equals_color_exactly_without_textures),
        cmocka_unit_test(test_mirror_layer_defers_the_floor_texture_at_the_reflected_uv),
        cmocka_unit_test(test_deferred_textures_pass_through_an_untextured_glass_shell),
        cmocka_unit_test(test_total_internal_reflection_folds_refraction_into_the_mirror_layer),
        cmocka_unit_test(test_replayed_feelers_are_bit_identical_and_save_shadow_rays),
        cmocka_unit_test(test_a_cache_from_the_other_side_or_incomplete_is_not_used),
        cmocka_unit_test(test_hints_change_nothing_and_neighbours_hints_hit),
        cmocka_unit_test(test_a_far_hint_only_bounds_the_search),
        cmocka_unit_test(test_degenerate_points_shade_as_the_background),
        cmocka_unit_test(test_tree_hash_follows_tree_equality),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
