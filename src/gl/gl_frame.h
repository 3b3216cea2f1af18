/* gl_frame.h: a GL frame handed to the caller as a texture (rl_gl.h,
 * rl_gl_share_with; rl_render.h, rl_renderer_take_gl_frame), for the GL
 * renderers of src/render.
 *
 * With texture output on, a frame's colour stays on the GPU: at its end the
 * texture it was drawn into goes to the caller (the GL drawer attaches a
 * new one; gl-pt copies the image's part of its accumulation), a fence
 * follows, and the colour layer of the target image is not written. The texture waits for the caller until
 * taken; an untaken one is deleted by the next frame or the release. */
#ifndef RL_GL_FRAME_H
#define RL_GL_FRAME_H

#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"

/* The GL drawer's texture output on or off: RL_ERR_UNSUPPORTED for a
 * drawer of another backend. */
rl_status rl_gl_drawer_set_texture_output(rl_drawer *d, bool on);
/* With texture output: the target's colour at the frame's begin is rgba
 * (4 floats) everywhere, cleared on the GPU instead of uploaded (the
 * caller need not fill the image's colour); NULL: uploaded as always. */
void rl_gl_drawer_set_clear(rl_drawer *d, const float *rgba);
/* The last frame's texture, now the caller's; false when there is none
 * (output off, taken already, or no frame since). */
bool rl_gl_drawer_take_frame(rl_drawer *d, rl_gl_frame *out);

#endif
