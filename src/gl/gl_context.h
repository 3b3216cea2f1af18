/* gl_context.h: headless OpenGL 4.5 core contexts over EGL (gl_context.c),
 * one per GL drawer. The EGL display of a device is opened once per
 * process and kept: eglTerminate would end every context on it, the other
 * drawers' too. */
#ifndef RL_GL_CONTEXT_H
#define RL_GL_CONTEXT_H

#include "rl/rl_gl.h"

typedef struct rl_gl_context rl_gl_context;

/* A context on device (rl_gl.h: NULL or "" = RL_EGL_DEVICE, else auto),
 * current on the calling thread when this returns RL_OK.
 * RL_ERR_UNSUPPORTED with the reason where none can be made. */
rl_status rl_gl_context_create(const char *device, rl_gl_context **out);
/* Makes ctx current on the calling thread (a no-op when it is already);
 * RL_ERR_INTERNAL when another thread holds it. What was current there
 * before (another library context, or the caller's own with
 * rl_gl_share_with) is current again after rl_gl_context_done. */
rl_status rl_gl_context_make_current(rl_gl_context *ctx);
/* Lets ctx go if it is current on the calling thread, so that another
 * thread may make it current next. */
void rl_gl_context_done(rl_gl_context *ctx);
const rl_gl_info *rl_gl_context_info(const rl_gl_context *ctx);
/* Whether contexts are made in the caller's share group (rl_gl_share_with):
 * only then is a frame texture of use to anyone (rl_renderer_set_gl_output). */
bool rl_gl_share_active(void);
/* Destroys ctx and the GL objects made in it (at once where it is current
 * on the calling thread or on none, else when that thread lets it go).
 * NULL is a no-op. */
void rl_gl_context_release(rl_gl_context *ctx);

#endif
