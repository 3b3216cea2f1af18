/* test_raster_scene.c: rl_raster_draw_scene, the "raster" renderer's scene
 * drawing shared with the hybrid renderers (Ullmann 2003, Sec. 3.5: ID/Z
 * pre-pass and non-VT objects). Oracles: the renderer itself (bitwise), a
 * full draw (what a mask keeps), a lit draw (what an unlit one writes). */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "raster/scene_drawer.h"
#include "rl/rl_drawer.h"
#include "rl/rl_raster.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render/render_fixtures.h"

#define SIZE 48

static void add_quad(rl_scene *s, float x0, float y0, float x1, float y1, float z,
                     const uint32_t *triangle_materials, uint32_t material)
{
    const rl_vec3 pos[4] = { { x0, y0, z }, { x1, y0, z }, { x1, y1, z }, { x0, y1, z } };
    const rl_vec3 nrm[4] = { { 0, 0, 1 }, { 0, 0, 1 }, { 0, 0, 1 }, { 0, 0, 1 } };
    const rl_vec2 uv[4] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
    const uint32_t idx[6] = { 0, 1, 2, 0, 2, 3 };
    rl_mesh_desc md = { .name = "quad", .num_vertices = 4, .positions = pos, .normals = nrm,
                        .uvs = uv, .num_triangles = 2, .indices = idx,
                        .triangle_materials = triangle_materials, .material = material };
    uint32_t mesh, node;
    assert_int_equal(rl_scene_add_mesh(s, &md, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "quad", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
}

/* Three overlapping quads facing +z: object 0 at the back mixes a textured
 * and a plain material, objects 1 and 2 are single-material and nearer. */
static rl_scene *stack_scene(rl_camera *cam)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    const rl_vec4 texels[4] = { { 1, 0.5f, 0.25f, 1 }, { 0.25f, 1, 0.5f, 1 },
                                { 0.5f, 0.25f, 1, 1 }, { 1, 1, 1, 1 } };
    rl_texture *tex = NULL;
    uint32_t tex_id, red, green, blue;
    assert_int_equal(rl_texture_create(2, 2, texels, &tex), RL_OK);
    assert_int_equal(rl_scene_add_texture(s, tex, &tex_id), RL_OK);
    rl_material m = rl_material_default();
    m.diffuse = rl_v3(0.8f, 0.2f, 0.2f);
    m.diffuse_texture = tex_id;
    assert_int_equal(rl_scene_add_material(s, &m, &red), RL_OK);
    m = rl_material_default();
    m.diffuse = rl_v3(0.2f, 0.8f, 0.2f);
    m.specular = rl_v3s(0.4f);
    assert_int_equal(rl_scene_add_material(s, &m, &green), RL_OK);
    m = rl_material_default();
    m.diffuse = rl_v3(0.2f, 0.2f, 0.8f);
    assert_int_equal(rl_scene_add_material(s, &m, &blue), RL_OK);
    const uint32_t mixed[2] = { red, green };
    add_quad(s, -1.0f, -1.0f, 1.0f, 1.0f, -1.0f, mixed, red);
    add_quad(s, -0.6f, -0.2f, 0.3f, 0.7f, -0.5f, NULL, blue);
    add_quad(s, 0.0f, -0.8f, 0.8f, 0.1f, 0.0f, NULL, green);
    rl_light l = { .type = RL_LIGHT_POINT, .color = { 1, 1, 1 }, .intensity = 3.0f,
                   .position = { 0.3f, 0.5f, 2.0f } };
    assert_int_equal(rl_scene_add_light(s, &l), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    *cam = (rl_camera){ .eye = { 0.1f, 0.05f, 3.0f }, .target = { 0, 0, -1 }, .up = { 0, 1, 0 },
                        .fov_deg = 45.0f, .width = SIZE, .height = SIZE };
    return s;
}

typedef struct drawn {
    rl_image *img;
    rl_raster_counters counters;
} drawn;

/* A fresh image (colour filled with fill) drawn into with draw_scene. */
static drawn draw_scene(const rl_scene *s, const rl_camera *cam, const rl_drawer_desc *desc,
                        rl_vec4 fill)
{
    const rl_scene_data *d = rl_scene_get_data(s);
    drawn out = { NULL, { 0 } };
    assert_int_equal(rl_image_create(cam->width, cam->height, FX_ALL_LAYERS, &out.img), RL_OK);
    rl_image_fill(out.img, fill);
    rl_raster *ras = NULL;
    assert_int_equal(rl_raster_create(NULL, &ras), RL_OK);
    assert_int_equal(rl_raster_set_camera(ras, out.img, cam, d->bounds), RL_OK);
    assert_int_equal(rl_raster_draw_scene(ras, d, cam->eye, desc, &out.counters, NULL, NULL),
                     RL_OK);
    rl_raster_release(ras);
    return out;
}

static size_t pixels_of(const rl_image *img, uint32_t object)
{
    size_t n = 0;
    for (size_t i = 0; i < (size_t)img->width * img->height; ++i)
        n += img->object_id[i] == object;
    return n;
}

static void test_mask_draws_only_the_selected_objects(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    rl_drawer_desc desc = { .shading = RL_SHADING_TEXTURED, .ambient = 0.05f };
    drawn all = draw_scene(s, &cam, &desc, rl_v4(0, 0, 0, 1));
    for (uint32_t o = 0; o < 3; ++o)
        assert_true(pixels_of(all.img, o) > 50);

    const uint8_t mask[3] = { 1, 0, 1 };
    desc.object_mask = mask;
    drawn some = draw_scene(s, &cam, &desc, rl_v4(0, 0, 0, 1));
    const size_t n = (size_t)SIZE * SIZE;
    for (size_t i = 0; i < n; ++i) {
        uint32_t id = some.img->object_id[i];
        assert_true(id == 0 || id == 2 || id == RL_ID_NONE);
        /* Where a selected object was in front, it still is, and looks the
         * same: lighting of an object does not depend on the others. */
        if (all.img->object_id[i] == 0 || all.img->object_id[i] == 2) {
            assert_int_equal(id, all.img->object_id[i]);
            assert_memory_equal(&some.img->color[i], &all.img->color[i], sizeof(rl_vec4));
            assert_memory_equal(&some.img->depth[i], &all.img->depth[i], sizeof(float));
        }
    }
    /* Object 1 hid part of object 0: that part shows now. */
    assert_true(pixels_of(some.img, 0) > pixels_of(all.img, 0));
    assert_int_equal(pixels_of(some.img, 1), 0);
    assert_int_equal(some.counters.triangles_in, 4);
    assert_int_equal(all.counters.triangles_in, 6);

    const uint8_t none[3] = { 0, 0, 0 };
    desc.object_mask = none;
    drawn nothing = draw_scene(s, &cam, &desc, rl_v4(0, 0, 0, 1));
    assert_int_equal(nothing.counters.pixels_written, 0);
    assert_int_equal(pixels_of(nothing.img, RL_ID_NONE), n);
    rl_image_release(all.img);
    rl_image_release(some.img);
    rl_image_release(nothing.img);
    rl_scene_release(s);
}

static void test_no_color_writes_depth_and_ids_of_a_lit_draw_and_leaves_colour_alone(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    const rl_vec4 sentinel = { 0.25f, 0.5f, 0.75f, 0.125f };
    const rl_raster_shading modes[3] = { RL_SHADING_FLAT, RL_SHADING_GOURAUD,
                                         RL_SHADING_TEXTURED };
    const size_t n = (size_t)SIZE * SIZE;
    for (int k = 0; k < 3; ++k) {
        rl_drawer_desc desc = { .shading = modes[k], .ambient = 0.1f };
        drawn lit = draw_scene(s, &cam, &desc, sentinel);
        desc.flags = RL_RASTER_NO_COLOR;
        drawn ids = draw_scene(s, &cam, &desc, sentinel);
        for (size_t i = 0; i < n; ++i)
            assert_memory_equal(&ids.img->color[i], &sentinel, sizeof sentinel);
        /* Bitwise, also for the object mixing materials, which the lit draw
         * sends through per-corner copies of its vertices. */
        assert_memory_equal(ids.img->depth, lit.img->depth, n * sizeof(float));
        assert_memory_equal(ids.img->object_id, lit.img->object_id, n * sizeof(uint32_t));
        assert_memory_equal(ids.img->triangle_id, lit.img->triangle_id, n * sizeof(uint32_t));
        assert_int_equal(ids.counters.pixels_written, lit.counters.pixels_written);
        assert_true(pixels_of(ids.img, RL_ID_NONE) < n);
        rl_image_release(lit.img);
        rl_image_release(ids.img);
    }
    rl_scene_release(s);
}

static void test_raster_renderer_output_equals_drawing_the_whole_scene(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    const char *const modes[3] = { "flat", "gouraud", "textured" };
    for (int k = 0; k < 3; ++k) {
        const char *const opts[] = { "shading", modes[k], "ambient", "0.2", "cull", "true",
                                     "background", "0.1,0.2,0.3", NULL };
        rl_render_stats stats;
        memset(&stats, 0, sizeof stats);
        rl_image *rendered = fx_render("raster", s, &cam, FX_ALL_LAYERS, opts, &stats);
        rl_drawer_desc desc = { .shading = (rl_raster_shading)k, .ambient = 0.2f,
                                      .flags = RL_RASTER_CULL_BACK };
        drawn direct = draw_scene(s, &cam, &desc, rl_v4(0.1f, 0.2f, 0.3f, 1.0f));
        fx_assert_images_identical(rendered, direct.img);
        assert_int_equal(stats.pixels_written, direct.counters.pixels_written);
        assert_int_equal(stats.triangles_rasterized, direct.counters.triangles_drawn);
        rl_image_release(rendered);
        rl_image_release(direct.img);
    }
    rl_scene_release(s);
}

/* A drawer whose objects were lit ahead in one parallel pass
 * (rl_scene_drawer_light, as surfels does) draws what
 * rl_raster_draw_scene draws, also in its next frame from another eye;
 * duplicates, unselected and out-of-range objects in the list are
 * ignored. */
static void test_lighting_ahead_draws_the_same_image(void **state)
{
    (void)state;
    rl_camera cam, moved;
    rl_scene *s = stack_scene(&cam);
    const rl_scene_data *d = rl_scene_get_data(s);
    moved = cam;
    moved.eye = rl_add(cam.eye, rl_v3(0.4f, 0.3f, 0.2f));
    uint8_t *mask = calloc(d->num_objects, 1);
    assert_non_null(mask);
    for (uint32_t o = 0; o < d->num_objects; ++o)
        mask[o] = o != 1;
    uint32_t *list = calloc(2 * (size_t)d->num_objects + 1, sizeof *list);
    assert_non_null(list);
    uint32_t n = 0;
    for (uint32_t o = d->num_objects; o-- > 0;)
        list[n++] = o;                    /* reversed: lighting order is free */
    for (uint32_t o = 0; o < d->num_objects; ++o)
        list[n++] = o;                    /* each twice */
    list[n++] = d->num_objects + 7;       /* out of range */
    for (int k = 0; k < 3; ++k) {
        rl_drawer_desc desc = { .shading = (rl_raster_shading)k, .ambient = 0.1f, .object_mask = mask };
        rl_scene_drawer *dr = NULL;
        assert_int_equal(rl_scene_drawer_create(d, cam.eye, &desc, &dr), RL_OK);
        for (int frame = 0; frame < 2; ++frame) {
            const rl_camera *c = frame ? &moved : &cam;
            if (frame)
                rl_scene_drawer_new_frame(dr, c->eye);
            rl_image *img = NULL;
            assert_int_equal(rl_image_create(c->width, c->height, FX_ALL_LAYERS, &img), RL_OK);
            rl_image_fill(img, rl_v4(0.0f, 0.0f, 0.0f, 1.0f));
            rl_raster *ras = NULL;
            assert_int_equal(rl_raster_create(NULL, &ras), RL_OK);
            assert_int_equal(rl_raster_set_camera(ras, img, c, d->bounds), RL_OK);
            rl_scene_drawer_light(dr, list, n);
            for (uint32_t o = 0; o < d->num_objects; ++o)
                assert_int_equal(rl_scene_drawer_draw(dr, ras, o, NULL), RL_OK);
            drawn direct = draw_scene(s, c, &desc, rl_v4(0.0f, 0.0f, 0.0f, 1.0f));
            fx_assert_images_identical(img, direct.img);
            rl_image_release(direct.img);
            rl_raster_release(ras);
            rl_image_release(img);
        }
        rl_scene_drawer_release(dr);
    }
    free(list);
    free(mask);
    rl_scene_release(s);
}

/* A drawer kept over frames keeps the colours of vertices without a
 * specular term while they show the eye the same side: the frames of one
 * drawer, from eyes that move in front of the quads, go behind them (every
 * side turns) and come back, equal those of a fresh drawer per frame in
 * every shading, with the specular (green) quad relit at every move. */
static void test_colours_kept_over_frames_equal_fresh_ones(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    const rl_scene_data *d = rl_scene_get_data(s);
    const rl_vec3 eyes[5] = { { 0.1f, 0.05f, 3.0f }, { 0.5f, 0.3f, 2.5f }, { 0.2f, -0.1f, -3.0f },
                              { -0.4f, 0.2f, -2.5f }, { 0.1f, 0.05f, 3.0f } };
    for (int k = 0; k < 3; ++k) {
        rl_drawer_desc desc = { .shading = (rl_raster_shading)k, .ambient = 0.1f };
        rl_scene_drawer *dr = NULL;
        assert_int_equal(rl_scene_drawer_create(d, eyes[0], &desc, &dr), RL_OK);
        for (int frame = 0; frame < 5; ++frame) {
            rl_camera c = cam;
            c.eye = eyes[frame];
            c.target = rl_v3(0.0f, 0.0f, eyes[frame].z > 0.0f ? -1.0f : 1.0f);
            rl_scene_drawer_new_frame(dr, c.eye);
            rl_image *img = NULL;
            assert_int_equal(rl_image_create(c.width, c.height, FX_ALL_LAYERS, &img), RL_OK);
            rl_image_fill(img, rl_v4(0.0f, 0.0f, 0.0f, 1.0f));
            rl_raster *ras = NULL;
            assert_int_equal(rl_raster_create(NULL, &ras), RL_OK);
            assert_int_equal(rl_raster_set_camera(ras, img, &c, d->bounds), RL_OK);
            assert_int_equal(rl_scene_drawer_draw_all(dr, ras, NULL, NULL, NULL), RL_OK);
            drawn direct = draw_scene(s, &c, &desc, rl_v4(0.0f, 0.0f, 0.0f, 1.0f));
            /* The view sees the quads, lit. */
            assert_true(pixels_of(direct.img, 0) + pixels_of(direct.img, 1) + pixels_of(direct.img, 2) >
                        SIZE * SIZE / 4);
            fx_assert_images_identical(img, direct.img);
            rl_image_release(direct.img);
            rl_raster_release(ras);
            rl_image_release(img);
        }
        rl_scene_drawer_release(dr);
    }
    rl_scene_release(s);
}

/* A list (rl_scene_drawer_draw_list) draws exactly what its objects drawn
 * one by one in the same order draw, counters included, in every shading
 * (the mixed-material object goes by corners), with a mask, and over two
 * frames; an object out of range fails the list before anything is drawn. */
static void test_a_list_draws_what_its_objects_draw_one_by_one(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    const rl_scene_data *d = rl_scene_get_data(s);
    uint8_t mask[3] = { 1, 0, 1 };
    const uint32_t list[4] = { 2, 0, 1, 2 };
    for (int k = 0; k < 6; ++k) {
        rl_drawer_desc desc = { .shading = (rl_raster_shading)(k % 3), .ambient = 0.1f,
                                      .object_mask = k >= 3 ? mask : NULL };
        rl_scene_drawer *one = NULL, *many = NULL;
        assert_int_equal(rl_scene_drawer_create(d, cam.eye, &desc, &one), RL_OK);
        assert_int_equal(rl_scene_drawer_create(d, cam.eye, &desc, &many), RL_OK);
        for (int frame = 0; frame < 2; ++frame) {
            rl_vec3 eye = rl_add(cam.eye, rl_v3(0.3f * (float)frame, 0.0f, 0.0f));
            if (frame) {
                rl_scene_drawer_new_frame(one, eye);
                rl_scene_drawer_new_frame(many, eye);
            }
            rl_image *a = NULL, *b = NULL;
            assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &a), RL_OK);
            assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &b), RL_OK);
            rl_raster *ras = NULL;
            assert_int_equal(rl_raster_create(NULL, &ras), RL_OK);
            rl_raster_counters ca = { 0 }, cb = { 0 };
            assert_int_equal(rl_raster_set_camera(ras, a, &cam, d->bounds), RL_OK);
            for (int i = 0; i < 4; ++i)
                assert_int_equal(rl_scene_drawer_draw(one, ras, list[i], &ca), RL_OK);
            assert_int_equal(rl_raster_set_camera(ras, b, &cam, d->bounds), RL_OK);
            assert_int_equal(rl_scene_drawer_draw_list(many, ras, list, 4, &cb), RL_OK);
            fx_assert_images_identical(a, b);
            assert_memory_equal(&ca, &cb, sizeof ca);
            assert_true(cb.pixels_written > 0);

            const uint32_t bad[3] = { 0, 10, 2 };
            rl_image_clear(b);
            rl_clear_error();
            cb = (rl_raster_counters){ 0 };
            assert_int_equal(rl_scene_drawer_draw_list(many, ras, bad, 3, &cb), RL_ERR_INVALID_ARG);
            assert_non_null(strstr(rl_last_error(), "object 10 of 3"));
            assert_int_equal(cb.pixels_written, 0);
            assert_int_equal(rl_scene_drawer_draw_list(many, ras, NULL, 2, &cb), RL_ERR_INVALID_ARG);
            assert_int_equal(rl_scene_drawer_draw_list(many, ras, NULL, 0, &cb), RL_OK);
            rl_raster_release(ras);
            rl_image_release(a);
            rl_image_release(b);
        }
        rl_scene_drawer_release(one);
        rl_scene_drawer_release(many);
    }
    rl_scene_release(s);
}

typedef struct progress_log {
    int calls;
    double last;
    int cancel_after;    /* 0: never */
} progress_log;

static bool log_progress(void *user, double done)
{
    progress_log *log = user;
    assert_true(done > log->last && done <= 1.0);
    log->last = done;
    return ++log->calls != log->cancel_after;
}

static void test_progress_reaches_one_and_can_cancel(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(SIZE, SIZE, FX_ALL_LAYERS, &img), RL_OK);
    rl_raster *ras = NULL;
    assert_int_equal(rl_raster_create(NULL, &ras), RL_OK);
    assert_int_equal(rl_raster_set_camera(ras, img, &cam, d->bounds), RL_OK);
    rl_drawer_desc desc = { .shading = RL_SHADING_GOURAUD };

    progress_log log = { 0, 0.0, 0 };
    assert_int_equal(rl_raster_draw_scene(ras, d, cam.eye, &desc, NULL, log_progress, &log),
                     RL_OK);
    /* Objects are drawn in lists of at least 1024 (so that small ones are
     * drawn on all threads together): three objects are one list. */
    assert_int_equal(log.calls, 1);
    assert_true(log.last == 1.0);

    log = (progress_log){ 0, 0.0, 1 };
    assert_int_equal(rl_raster_draw_scene(ras, d, cam.eye, &desc, NULL, log_progress, &log),
                     RL_ERR_CANCELLED);
    assert_int_equal(log.calls, 1);

    desc.shading = (rl_raster_shading)7;
    assert_int_equal(rl_raster_draw_scene(ras, d, cam.eye, &desc, NULL, NULL, NULL),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_raster_draw_scene(NULL, d, cam.eye, NULL, NULL, NULL, NULL),
                     RL_ERR_INVALID_ARG);
    rl_raster_release(ras);
    rl_image_release(img);
    rl_scene_release(s);
}

/* rl_drawer (rl_drawer.h), the interface the culling renderers and the
 * visibility property draw through: a kept drawer, begun frame after
 * frame, draws exactly what rl_raster_draw_scene draws; lists, queries and
 * points reach the rasterizer; misuse is refused. */
static void test_the_public_drawer_draws_what_the_scene_drawer_draws(void **state)
{
    (void)state;
    rl_camera cam;
    rl_scene *s = stack_scene(&cam);
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_drawer_desc desc = { .shading = RL_SHADING_GOURAUD, .ambient = 0.05f };
    rl_drawer *dr = NULL;
    assert_int_equal(rl_drawer_create(s, &desc, &dr), RL_OK);
    assert_string_equal(rl_drawer_backend(dr), "software");
    assert_true(rl_drawer_fits(dr, s, &desc));
    rl_drawer_desc other = desc;
    other.ambient = 0.1f;
    assert_false(rl_drawer_fits(dr, s, &other));
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &img), RL_OK);
    /* Two frames from two eyes with the same drawer: each equals a fresh
     * draw of the scene (lighting redone for the new eye). */
    for (int frame = 0; frame < 2; ++frame) {
        rl_camera c = cam;
        c.eye.x += 0.3f * (float)frame;
        drawn want = draw_scene(s, &c, &desc, rl_v4(0, 0, 0, 1));
        rl_image_clear_to(img, rl_v4(0, 0, 0, 1));
        rl_raster_counters counters = { 0 };
        assert_int_equal(rl_drawer_begin_camera(dr, img, &c, d->bounds), RL_OK);
        assert_int_equal(rl_drawer_draw_all(dr, &counters, NULL, NULL), RL_OK);
        assert_int_equal(rl_drawer_end(dr), RL_OK);
        fx_assert_images_identical(img, want.img);
        assert_int_equal(counters.triangles_drawn, want.counters.triangles_drawn);
        rl_image_release(want.img);
    }
    /* A list in back-to-front order draws the same image as all. */
    rl_image *listed = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &listed), RL_OK);
    rl_image_clear_to(listed, rl_v4(0, 0, 0, 1));
    const uint32_t order[3] = { 0, 1, 2 };
    assert_int_equal(rl_drawer_begin_camera(dr, listed, &cam, d->bounds), RL_OK);
    rl_drawer_light(dr, order, 3);
    assert_int_equal(rl_drawer_draw(dr, order, 3, NULL), RL_OK);
    /* An occlusion query of a quad hidden behind object 1 sees nothing, one
     * in front of object 0 sees its pixels; neither writes. */
    const rl_vec3 far[4] = { { -0.4f, 0.0f, -0.7f }, { 0.1f, 0.0f, -0.7f }, { 0.1f, 0.5f, -0.7f },
                             { -0.4f, 0.5f, -0.7f } };
    const rl_vec3 near[4] = { { -0.5f, -0.8f, -0.2f }, { -0.3f, -0.8f, -0.2f }, { -0.3f, -0.5f, -0.2f },
                              { -0.5f, -0.5f, -0.2f } };
    const uint32_t quad[6] = { 0, 1, 2, 0, 2, 3 };
    rl_raster_batch box = { .num_vertices = 4, .positions = far, .num_triangles = 2, .indices = quad };
    uint64_t pixels = 99;
    rl_raster_counters qc = { 0 };
    assert_int_equal(rl_drawer_query(dr, &box, &pixels, &qc), RL_OK);
    assert_int_equal(pixels, 0);
    assert_int_equal(qc.triangles_in, 2);
    box.positions = near;
    assert_int_equal(rl_drawer_query(dr, &box, &pixels, NULL), RL_OK);
    assert_true(pixels > 10);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
    rl_image *all = NULL;
    assert_int_equal(rl_image_create(cam.width, cam.height, FX_ALL_LAYERS, &all), RL_OK);
    rl_image_clear_to(all, rl_v4(0, 0, 0, 1));
    assert_int_equal(rl_drawer_begin_camera(dr, all, &cam, d->bounds), RL_OK);
    assert_int_equal(rl_drawer_draw_all(dr, NULL, NULL, NULL), RL_OK);
    /* Points land where they are drawn and count. */
    const rl_vec3 pos[1] = { { -0.4f, -0.65f, -0.1f } };
    const rl_vec4 col[1] = { { 1, 1, 0, 1 } };
    const float size[1] = { 3.0f };
    rl_raster_points pts = { .count = 1, .positions = pos, .colors = col, .sizes_px = size };
    rl_raster_counters pc = { 0 };
    assert_int_equal(rl_drawer_draw_points(dr, &pts, &pc), RL_OK);
    assert_int_equal(pc.points_drawn, 1);
    assert_int_equal(rl_drawer_end(dr), RL_OK);
    size_t yellow = 0;
    for (size_t i = 0; i < (size_t)cam.width * cam.height; ++i) {
        yellow += all->color[i].x == 1.0f && all->color[i].y == 1.0f && all->color[i].z == 0.0f;
        if (listed->color[i].x != all->color[i].x && !(all->color[i].y == 1.0f && all->color[i].z == 0.0f))
            fail_msg("pixel %zu: the list drew another colour than draw_all", i);
    }
    assert_true(yellow >= 4);
    /* Misuse: no frame begun, a target without depth, NULL arguments. */
    rl_clear_error();
    assert_int_equal(rl_drawer_draw(dr, order, 3, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_drawer_end(dr), RL_ERR_INVALID_ARG);
    rl_image *flat = NULL;
    assert_int_equal(rl_image_create(8, 8, RL_LAYER_COLOR, &flat), RL_OK);
    assert_int_equal(rl_drawer_begin_camera(dr, flat, &cam, d->bounds), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_drawer_create(NULL, &desc, &dr), RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_image_release(flat);
    rl_image_release(all);
    rl_image_release(listed);
    rl_image_release(img);
    rl_drawer_release(dr);
    rl_drawer_release(NULL);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_mask_draws_only_the_selected_objects),
        cmocka_unit_test(test_no_color_writes_depth_and_ids_of_a_lit_draw_and_leaves_colour_alone),
        cmocka_unit_test(test_raster_renderer_output_equals_drawing_the_whole_scene),
        cmocka_unit_test(test_lighting_ahead_draws_the_same_image),
        cmocka_unit_test(test_colours_kept_over_frames_equal_fresh_ones),
        cmocka_unit_test(test_a_list_draws_what_its_objects_draw_one_by_one),
        cmocka_unit_test(test_progress_reaches_one_and_can_cancel),
        cmocka_unit_test(test_the_public_drawer_draws_what_the_scene_drawer_draws),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
