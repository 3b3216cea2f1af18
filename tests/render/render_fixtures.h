/* render_fixtures.h: what the renderer tests share. Everything is static
 * inline so that each test uses any subset without unused-function
 * warnings. Failures are cmocka assertions (include <cmocka.h> first). */
#ifndef RL_TESTS_RENDER_FIXTURES_H
#define RL_TESTS_RENDER_FIXTURES_H

#include "rl/rl_render.h"
#include "rl/rl_scene.h"

#define FX_ALL_LAYERS (RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID)

/* A renderer with options {key, value, ..., NULL} set (each must succeed). */
static inline rl_renderer *fx_make(const char *name, const char *const *opts)
{
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create(name, &r), RL_OK);
    for (size_t i = 0; opts && opts[i]; i += 2)
        assert_int_equal(rl_renderer_set(r, opts[i], opts[i + 1]), RL_OK);
    return r;
}

/* One frame into a new image with the given layers (the camera's size). */
static inline rl_image *fx_render_with(rl_renderer *r, const rl_scene *s, const rl_camera *cam,
                                       unsigned layers, rl_render_stats *stats)
{
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(cam->width, cam->height, layers, &img), RL_OK);
    assert_int_equal(rl_renderer_render(r, s, cam, img, stats), RL_OK);
    return img;
}

static inline rl_image *fx_render(const char *name, const rl_scene *s, const rl_camera *cam,
                                  unsigned layers, const char *const *opts, rl_render_stats *stats)
{
    rl_renderer *r = fx_make(name, opts);
    rl_image *img = fx_render_with(r, s, cam, layers, stats);
    rl_renderer_release(r);
    return img;
}

/* Bitwise equality of every layer the images have (they must have the same). */
static inline void fx_assert_images_identical(const rl_image *a, const rl_image *b)
{
    size_t n = (size_t)a->width * a->height;
    assert_int_equal(a->width, b->width);
    assert_int_equal(a->height, b->height);
    assert_int_equal(a->layers, b->layers);
    assert_memory_equal(a->color, b->color, n * sizeof *a->color);
    if (a->depth)
        assert_memory_equal(a->depth, b->depth, n * sizeof *a->depth);
    if (a->object_id) {
        assert_memory_equal(a->object_id, b->object_id, n * sizeof *a->object_id);
        assert_memory_equal(a->triangle_id, b->triangle_id, n * sizeof *a->triangle_id);
    }
}

/* The built-in Cornell box and its camera at size x size pixels. */
static inline rl_scene *fx_cornell(rl_camera *cam, int size)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    assert_int_equal(rl_scene_get_camera(s, NULL, cam), RL_OK);
    cam->width = cam->height = size;
    return s;
}

#endif
