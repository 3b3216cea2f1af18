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
