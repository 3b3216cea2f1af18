/* gl_shaders.h: the GLSL 4.50 programs of the GL drawer (gl_shaders.c) and
 * the layout of the buffers they read, shared with gl_drawer.c. */
#ifndef RL_GL_SHADERS_H
#define RL_GL_SHADERS_H

#include <epoxy/gl.h>

#include "rl/rl_common.h"
#include "rl/rl_scene.h"

/* Shader storage bindings. */
enum {
    RL_GL_SSBO_MATERIALS = 0,
    RL_GL_SSBO_LIGHTS,
    RL_GL_SSBO_TEX_INFO,
    RL_GL_SSBO_TEXELS,
    RL_GL_SSBO_TRI_MATERIAL,
    RL_GL_SSBO_INDICES,
    RL_GL_SSBO_POSITIONS,
    RL_GL_SSBO_UVS,
};

/* Light kinds as the shaders number them. */
enum { RL_GL_LIGHT_POINT = 0, RL_GL_LIGHT_SPOT, RL_GL_LIGHT_DIRECTIONAL, RL_GL_LIGHT_QUAD };

/* What u_mode selects in the triangle program. */
enum { RL_GL_MODE_QUERY = -1, RL_GL_MODE_UNLIT, RL_GL_MODE_FLAT, RL_GL_MODE_GOURAUD, RL_GL_MODE_TEXTURED };

/* std430 records: every member a vec4 or uvec4, so C and GLSL agree on
 * the layout without padding rules. */
typedef struct rl_gl_material {
    float diffuse[4];
    float specular[4];            /* w: shininess */
    float emission[4];            /* w: normal_scale */
    uint32_t tex[4];              /* diffuse, normal, mask texture (RL_NONE: none), cutoff's bits */
} rl_gl_material;

typedef struct rl_gl_light {
    float pos[4];                 /* point/spot position or quad centre; w: kind */
    float power[4];               /* colour * intensity; w: quad area */
    float dir[4];                 /* spot axis, directional l, quad normal (unit); w: cos outer */
    float extra[4];               /* x: cos inner; y: 1 where a directional light is valid */
} rl_gl_light;

typedef struct rl_gl_tex_info {
    uint32_t offset;              /* first texel in the texel buffer */
    int32_t width, height, pad;
} rl_gl_tex_info;

/* An immutable buffer of bytes from data (NULL: zeros where the buffer is
 * padded, else undefined), at least 16 bytes so that empty arrays still
 * bind; flags as glNamedBufferStorage's. */
GLuint rl_gl_make_buffer(const void *data, size_t bytes, GLbitfield flags);
/* Every texture of d in one texel buffer (*texels, vec4 per texel, updatable
 * by glNamedBufferSubData) and where each starts (*tex_info,
 * rl_gl_tex_info), as tex_sample reads them: any number of textures of any
 * size is one binding. RL_ERR_LIMIT ("WHO: the scene's textures ...") when
 * they exceed max_block (GL_MAX_SHADER_STORAGE_BLOCK_SIZE) or 2^32 texels;
 * RL_ERR_OUT_OF_MEMORY. Nothing is made on failure. */
rl_status rl_gl_upload_textures(const rl_scene_data *d, GLint64 max_block, const char *who, GLuint *tex_info,
                                GLuint *texels);

/* The first GL error since the last check, as RL_ERR_INTERNAL (or
 * RL_ERR_OUT_OF_MEMORY) "gl: GL error 0x.. in WHERE"; clears the rest. */
rl_status rl_gl_check(const char *where);
/* A shader of stage from parts[0..count-1] (concatenated); 0 with the
 * compiler's log in the recorded error. */
GLuint rl_gl_compile(GLenum stage, const char *const *parts, int count, const char *what);
/* A program of shaders a and b (b may be 0, as for a compute program),
 * which it deletes; 0 (also for a == 0) with the linker's log recorded. */
GLuint rl_gl_link(GLuint a, GLuint b, const char *what);

/* The three programs: triangles (every shading mode, queries), points
 * (surfels) and the depth upload at a frame's begin. Zero on failure, with
 * the compiler's log in the recorded error. */
/* The GLSL of tex_sample(uint tex, vec2 uv) (core/texture_sample.h), for
 * programs that declare TexInfo, tex_info[] and texel_at() before it. */
extern const char *const rl_gl_glsl_tex_sample;

/* The GLSL of light_delta(Light L, vec3 p, out E, out l, out dist)
 * (scene/light_eval.c rl_light_eval_delta: point, spot, directional), for
 * programs that declare struct Light as rl_gl_light before it. */
extern const char *const rl_gl_glsl_light_delta;

GLuint rl_gl_program_triangles(void);
GLuint rl_gl_program_points(void);
GLuint rl_gl_program_depth_upload(void);
/* Caller-made batches (rl_drawer_draw_batch): unshared corners of
 * gl_batch_corner, colour from up to four texture layers or Gouraud. */
GLuint rl_gl_program_batch(void);

/* One corner of a batch as the batch program reads it (attribute
 * locations in order: position, the face's textures per layer, its
 * triangle and object IDs, four layer colours, four uv pairs). */
typedef struct rl_gl_batch_corner {
    float pos[3];
    uint32_t tex[4];              /* per layer, RL_NONE: untextured */
    uint32_t ids[2];              /* triangle, object */
    float col[4][4];
    float uv[4][2];
} rl_gl_batch_corner;

#endif
