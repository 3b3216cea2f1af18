/* The GL backend sharing a caller's EGL context (rl_gl_share_with) and
 * handing a GL renderer's frame over as a texture (rl_renderer_set_gl_output,
 * rl_renderer_take_gl_frame; docs/gl.md, "Sharing with a window"): the
 * caller's context stays current, the texture read in the caller's context
 * equals the read-back image bit for bit, a texture is handed over once,
 * and the misuses (half an argument pair, a switch while contexts live, a
 * CPU renderer, texture output without sharing) are refused with a status.
 * The caller's context here is one of Mesa's surfaceless display, as a
 * window's would be of the X11 one. One gl-raster program set, 24 x 16. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "rl/rl_gl.h"
#include "rl/rl_image.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"

#include "gl_fixtures.h"

#ifdef RL_TEST_EGL
#include <epoxy/egl.h>
#include <epoxy/gl.h>
#endif

#define W 24
#define H 16

static rl_scene *cornell(void)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create_builtin("cornell", NULL, &s), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

static void render(rl_renderer *r, const rl_scene *s, rl_image *img)
{
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = W;
    cam.height = H;
    cam = rl_camera_resolve(&cam);
    assert_int_equal(rl_renderer_render(r, s, &cam, img, NULL), RL_OK);
}

static void test_share_refuses_misuse(void **state)
{
    (void)state;
    int dummy = 0;
    assert_int_equal(rl_gl_share_with(&dummy, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_gl_share_with(NULL, &dummy), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_gl_share_with(NULL, NULL), RL_OK);
    rl_clear_error();

    rl_renderer *cpu = NULL, *gl = NULL;
    assert_int_equal(rl_renderer_create("raster", &cpu), RL_OK);
    assert_int_equal(rl_renderer_set_gl_output(cpu, true), RL_ERR_UNSUPPORTED);
    rl_gl_frame f;
    assert_int_equal(rl_renderer_take_gl_frame(cpu, &f), RL_ERR_UNSUPPORTED);
    assert_int_equal(rl_renderer_create("gl-raster", &gl), RL_OK);
    /* without sharing nobody could use a texture */
    assert_int_equal(rl_renderer_set_gl_output(gl, true), RL_ERR_UNSUPPORTED);
    assert_int_equal(rl_renderer_set_gl_output(gl, false), RL_OK);
    assert_int_equal(rl_renderer_take_gl_frame(gl, &f), RL_ERR_NOT_FOUND);
    assert_int_equal(rl_renderer_take_gl_frame(gl, NULL), RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_renderer_release(cpu);
    rl_renderer_release(gl);
}

#ifdef RL_TEST_EGL
static void test_gl_raster_texture_equals_readback(void **state)
{
    (void)state;
    NEED_GL();
    rl_scene *s = cornell();
    rl_image *readback = NULL, *img = NULL;
    assert_int_equal(rl_image_create(W, H, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &readback), RL_OK);
    assert_int_equal(rl_image_create(W, H, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &img), RL_OK);
    rl_renderer *r = NULL;
    /* The reference: today's path, its context gone before sharing starts. */
    assert_int_equal(rl_renderer_create("gl-raster", &r), RL_OK);
    render(r, s, readback);
    rl_renderer_release(r);

    /* The caller's context: a 4.5 core one on the surfaceless display. */
    EGLDisplay dpy = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL);
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, NULL, NULL))
        skip();
    static const EGLint attribs[] = { EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5, EGL_NONE };
    assert_true(eglBindAPI(EGL_OPENGL_API));
    EGLContext mine = eglCreateContext(dpy, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, attribs);
    assert_true(mine != EGL_NO_CONTEXT);
    assert_true(eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, mine));
    assert_int_equal(rl_gl_share_with(dpy, mine), RL_OK);
    assert_ptr_equal(eglGetCurrentContext(), mine);

    assert_int_equal(rl_renderer_create("gl-raster", &r), RL_OK);
    assert_int_equal(rl_renderer_set_gl_output(r, true), RL_OK);
    render(r, s, img);
    /* rendering on this thread gave the caller's context back */
    assert_ptr_equal(eglGetCurrentContext(), mine);
    /* a context of the backend lives: no switch now */
    assert_int_equal(rl_gl_share_with(NULL, NULL), RL_ERR_INVALID_ARG);
    rl_clear_error();
    /* the layers other than colour are written as before */
    assert_memory_equal(img->depth, readback->depth, sizeof(float) * W * H);
    assert_memory_equal(img->object_id, readback->object_id, sizeof(uint32_t) * W * H);

    rl_gl_frame f = { 0 };
    assert_int_equal(rl_renderer_take_gl_frame(r, &f), RL_OK);
    assert_int_equal(f.width, W);
    assert_int_equal(f.height, H);
    assert_true(f.texture != 0 && f.fence != NULL);
    rl_gl_frame again;
    assert_int_equal(rl_renderer_take_gl_frame(r, &again), RL_ERR_NOT_FOUND);
    rl_clear_error();
    glWaitSync((GLsync)f.fence, 0, GL_TIMEOUT_IGNORED);
    glDeleteSync((GLsync)f.fence);
    float *px = calloc((size_t)W * H, 4 * sizeof *px);
    assert_non_null(px);
    glGetTextureImage(f.texture, 0, GL_RGBA, GL_FLOAT, (GLsizei)(W * H * 4 * sizeof *px), px);
    assert_int_equal(glGetError(), GL_NO_ERROR);
    assert_memory_equal(px, readback->color, (size_t)W * H * 4 * sizeof *px);
    glDeleteTextures(1, &f.texture);

    /* texture output off: the image again, and no texture */
    assert_int_equal(rl_renderer_set_gl_output(r, false), RL_OK);
    memset(img->color, 0, (size_t)W * H * sizeof *img->color);
    render(r, s, img);
    assert_memory_equal(img->color, readback->color, (size_t)W * H * sizeof *img->color);
    assert_int_equal(rl_renderer_take_gl_frame(r, &f), RL_ERR_NOT_FOUND);
    rl_clear_error();
    rl_renderer_release(r);
    assert_ptr_equal(eglGetCurrentContext(), mine);
    assert_int_equal(rl_gl_share_with(NULL, NULL), RL_OK);
    free(px);
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(dpy, mine);
    rl_image_release(img);
    rl_image_release(readback);
    rl_scene_release(s);
}
#endif

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_share_refuses_misuse),
#ifdef RL_TEST_EGL
        cmocka_unit_test(test_gl_raster_texture_equals_readback),
#endif
    };
    return cmocka_run_group_tests(tests, find_gl, NULL);
}
