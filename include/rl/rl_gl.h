/* rl_gl.h: the OpenGL 4.5 backend (src/gl): a headless EGL context and the
 * GL scene drawer, the second implementation of rl_drawer.h beside the
 * software rasterizer's. The GL renderers ("gl-raster") draw through it.
 *
 * The context has no window: EGL with no config and no surface, OpenGL 4.5
 * core, rendering into framebuffer objects. The EGL device is chosen by
 * `device` (NULL or "" = the environment variable RL_EGL_DEVICE, and when
 * that is unset too, automatic):
 *   "auto"        every device of EGL_EXT_device_enumeration in order, then
 *                 Mesa's surfaceless platform; the first that gives 4.5 core
 *   "surfaceless" Mesa's EGL_PLATFORM_SURFACELESS_MESA (llvmpipe without a GPU)
 *   "N"           device N (0, 1, ...) of eglQueryDevicesEXT (EGL_PLATFORM_DEVICE_EXT,
 *                 the NVIDIA way), and no other.
 *
 * Failure: where no context can be made (a build without GL, no EGL
 * library or device, no 4.5 core context), rl_gl_available() says why and
 * the other functions fail with RL_ERR_UNSUPPORTED and that reason; the
 * renderers report themselves unavailable (rl_renderer_available). Nothing
 * crashes for want of a GPU. */
#ifndef RL_GL_H
#define RL_GL_H

#include "rl/rl_common.h"
#include "rl/rl_accel.h"
#include "rl/rl_drawer.h"
#include "rl/rl_linespace.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

/* What the context of a device reports: GL_VENDOR, GL_RENDERER, GL_VERSION
 * and the device as chosen ("surfaceless", "device 0"). */
typedef struct rl_gl_info {
    char vendor[128];
    char renderer[256];
    char version[128];
    char device[64];
} rl_gl_info;

/* Whether a GL 4.5 core context can be made on device (see above); if not,
 * why (into why, cut to n bytes; why may be NULL). The first call per
 * device makes and drops a context (tens of milliseconds); the answer is
 * kept for the process. */
RL_API bool rl_gl_available(const char *device, char *why, size_t n);
/* The strings of device's context. RL_ERR_UNSUPPORTED where it is not
 * available; RL_ERR_INVALID_ARG for a NULL out. */
RL_API rl_status rl_gl_info_get(const char *device, rl_gl_info *out);

/* A drawer of scene (committed) with OpenGL on device: rl_drawer_backend()
 * is "gl". It owns its own context, current on the calling thread from
 * rl_drawer_begin to rl_drawer_end (a frame stays on one thread; the next
 * may come from another, and release may happen on any). Its images match
 * the software drawer's (same lighting, depth and IDs) up to the
 * deviations of docs/gl.md. Also RL_ERR_LIMIT where the scene's textures or
 * arrays exceed the GL's buffer size limit, RL_ERR_INTERNAL for a GL error. */
RL_API rl_status rl_gl_drawer_create(const rl_scene *scene, const rl_drawer_desc *desc, const char *device,
                                     rl_drawer **out);

/* Sharing with the caller's context (docs/gl.md, "Sharing with a window").
 *
 * By default the backend's contexts live on a display of their own and
 * share nothing, so a GL renderer's frame reaches a caller only as an
 * rl_image read back to the CPU. rl_gl_share_with hands the backend an
 * initialised EGLDisplay and an OpenGL EGLContext of that display (a
 * window's: SDL with SDL_HINT_VIDEO_X11_FORCE_EGL, GLFW's EGL context),
 * passed as void * so that this header needs no EGL headers. From then on
 * every context the backend makes is an OpenGL 4.5 core context on that
 * display in that context's share group, whatever device the renderers
 * name, and a GL renderer can hand its frame over as a texture
 * (rl_renderer_set_gl_output, rl_render.h). EGL shares objects only
 * between contexts of one display, hence the display.
 *
 * Call it before the first GL renderer renders: RL_ERR_INVALID_ARG while
 * any context of the backend exists. It tries a context sharing with the
 * given one and fails with RL_ERR_UNSUPPORTED and EGL's error where there
 * is none (another API, a display without EGL_KHR_no_config_context or
 * EGL_KHR_surfaceless_context, a driver that refuses); sharing then stays
 * as it was. The calling thread's current context is left as it was.
 * rl_gl_share_with(NULL, NULL) stops sharing (again only while no context
 * exists). The caller keeps the display and context alive and current
 * wherever it likes until every GL renderer is released: the backend
 * never terminates the display. While sharing, the backend's contexts are
 * made current on the thread that renders and let go afterwards, the
 * thread's own context (the window's) current again.
 *
 * Objects of a backend context are shared with the caller's group: they
 * outlive the backend context until the caller's is destroyed, except the
 * frame textures (rl_renderer_take_gl_frame), which change owner. */
RL_API rl_status rl_gl_share_with(void *egl_display, void *egl_context);

/* A GL renderer's frame handed over as a texture (rl_renderer_take_gl_frame). */
typedef struct rl_gl_frame {
    /* A GL_TEXTURE_2D of internal format GL_RGBA32F, width x height, the
     * frame's linear colour exactly as the read-back rl_image would hold it
     * (alpha 1), row 0 the image's top row (texture coordinate t = 0 at the
     * top). Owned by the caller, who deletes it with glDeleteTextures in a
     * context of the share group. */
    uint32_t texture;
    int width, height;
    /* A GLsync made after the last write to texture and flushed: the caller
     * waits on it (glWaitSync, or glClientWaitSync) in its context before
     * it samples texture, then deletes it (glDeleteSync). */
    void *fence;
} rl_gl_frame;

/* Line Space generation on the GPU (Schröder 2017, Sec. 7; docs/gl.md,
 * "Line Space on GL"), for benchmarks: builds the candidate lists of
 * rl_linespace_create(grid, desc) with compute shaders in a context of its
 * own on device, with the same contents as the CPU build, and reports the
 * time; the result is dropped. desc->payloads must be RL_LS_CANDIDATES
 * (or 0); threads, progress and small_pages are ignored.
 * RL_ERR_UNSUPPORTED without GL or for other payloads and alpha-masked
 * scenes, RL_ERR_LIMIT where the buffers exceed the GL's shader storage
 * block size or 32-bit offsets. */
typedef struct rl_gl_linespace_timing {
    double gpu_ms;                /* GL_TIME_ELAPSED of the build's passes */
    double stamp_ms;              /* the same passes between GL_TIMESTAMP queries
                                   * (llvmpipe's GL_TIME_ELAPSED reads 0 for compute) */
    double wall_ms;               /* uploads, passes and the total's readback, to glFinish
                                   * (shader compilation not included) */
    uint64_t shafts, occupied, candidates;
    uint64_t gpu_bytes;           /* every buffer the build made */
} rl_gl_linespace_timing;
RL_API rl_status rl_gl_linespace_time_build(const rl_accel *grid, const rl_linespace_desc *desc, const char *device,
                                            rl_gl_linespace_timing *out);

#ifdef __cplusplus
}
#endif
#endif
