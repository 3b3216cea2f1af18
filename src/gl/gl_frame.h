/* gl_frame.h: a GL frame handed to the caller as a texture (rl_gl.h,
 * rl_gl_share_with; rl_render.h, rl_renderer_take_gl_frame), for the GL
 * renderers of src/render.
 *
 * With texture output on, a frame's colour stays on the GPU: at its end it
 * is copied into a new texture of the share group (glCopyImageSubData, no
 * trip through the CPU), a fence follows, and the colour layer of the
 * target image is not written. The texture waits for the caller until
 * taken; an untaken one is deleted by the next frame or the release. */
#ifndef RL_GL_FRAME_H
#define RL_GL_FRAME_H

#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"

/* The GL drawer's texture output on or off: RL_ERR_UNSUPPORTED for a
 * drawer of another backend. */
rl_status rl_gl_drawer_set_texture_output(rl_drawer *d, bool on);
/* The last frame's texture, now the caller's; false when there is none
 * (output off, taken already, or no frame since). */
bool rl_gl_drawer_take_frame(rl_drawer *d, rl_gl_frame *out);

#endif
