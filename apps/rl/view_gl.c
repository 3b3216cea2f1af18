/* view_gl.c: rl view's window context shared with the GL backend
 * (docs/viewer.md, "The GL renderers and the window's context").
 *
 * The window gets an EGL context (SDL_HINT_VIDEO_X11_FORCE_EGL on X11),
 * whose display and context go to rl_gl_share_with, so that the library's
 * contexts join the window's share group. A GL renderer's frame then
 * arrives as a texture (rl_renderer_take_gl_frame) and is drawn by one
 * fragment shader, which also does what the readback path does on the CPU:
 * the sRGB encoding of draw() (the same 4096-entry quantisation as its
 * table) and the overlay, which stays a CPU bitmap (view_font.c) uploaded
 * only over the rows it covers. Nothing of the frame crosses to the CPU
 * unless a screenshot, a recording or the settle measurement asks for it
 * (view_gl_read). Where any step fails the caller keeps the readback path. */
#include "view.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(RL_HAVE_SDL2) && defined(RL_VIEW_GLSHARE)

#include <SDL.h>
#include <epoxy/egl.h>
#include <epoxy/gl.h>

struct view_gl {
    SDL_Window *win;
    SDL_GLContext ctx;
    GLuint prog, vao, overlay, frame, lut;
    GLint u_size, u_view, u_use_frame;
    int width, height;            /* of the image, the overlay and (when set) the frame */
    bool have_frame;
    int vx, vy, vw, vh;           /* the image's viewport in the drawable, letterboxed */
};

/* Overlay texels (view_gl_present): alpha 255 a text pixel; else the red
 * channel says how often view_draw_text's box quartered what lies below:
 * 0xfc never (transparent), 0x3f once, 0x0f twice. */
static const char vs_src[] =
    "#version 130\n"
    "void main() {\n"
    "    vec2 p = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);\n"
    "    gl_Position = vec4(p, 0.0, 1.0);\n"
    "}\n";
static const char fs_src[] =
    "#version 130\n"
    "uniform sampler2D u_frame;\n"
    "uniform sampler2D u_overlay;\n"
    "uniform sampler2D u_lut;\n"
    "uniform ivec2 u_size;\n"
    "uniform vec4 u_view;\n"
    "uniform bool u_use_frame;\n"
    "out vec4 o_color;\n"
    /* cmd_view.c to_byte(): the nearest of 4097 steps, its sRGB byte from
     * the same table (u_lut), so that both paths give the same bytes */
    "float to_byte(float c) {\n"
    "    if (!(c > 0.0)) return 0.0;\n"
    "    if (c >= 1.0) return 255.0;\n"
    "    return floor(texelFetch(u_lut, ivec2(int(c * 4096.0 + 0.5), 0), 0).r * 255.0 + 0.5);\n"
    "}\n"
    "void main() {\n"
    "    vec2 p = (gl_FragCoord.xy - u_view.xy) / u_view.zw;\n"
    "    ivec2 q = clamp(ivec2(floor(vec2(p.x, 1.0 - p.y) * vec2(u_size))), ivec2(0), u_size - 1);\n"
    "    vec4 o = texelFetch(u_overlay, q, 0);\n"
    "    if (o.a > 0.5) { o_color = vec4(o.rgb, 1.0); return; }\n"
    "    vec3 c = vec3(0.0);\n"
    "    if (u_use_frame) {\n"
    "        vec3 f = texelFetch(u_frame, q, 0).rgb;\n"
    "        c = vec3(to_byte(f.r), to_byte(f.g), to_byte(f.b));\n"
    "    }\n"
    "    float k = o.r > 0.9 ? 1.0 : o.r > 0.2 ? 0.25 : 0.0625;\n"
    "    o_color = vec4(floor(c * k + 0.001) / 255.0, 1.0);\n"
    "}\n";

static GLuint compile(GLenum kind, const char *src, char *why, size_t n)
{
    GLuint s = glCreateShader(kind);
    glShaderSource(s, 1, &src, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[256] = "";
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        snprintf(why, n, "the window's shader does not compile: %s", log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

static bool make_program(view_gl *g, char *why, size_t n)
{
    GLuint vs = compile(GL_VERTEX_SHADER, vs_src, why, n);
    GLuint fs = vs ? compile(GL_FRAGMENT_SHADER, fs_src, why, n) : 0;
    if (!fs) {
        if (vs)
            glDeleteShader(vs);
        return false;
    }
    g->prog = glCreateProgram();
    glAttachShader(g->prog, vs);
    glAttachShader(g->prog, fs);
    glBindFragDataLocation(g->prog, 0, "o_color");
    glLinkProgram(g->prog);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(g->prog, GL_LINK_STATUS, &ok);
    if (!ok) {
        snprintf(why, n, "the window's shader does not link");
        return false;
    }
    glUseProgram(g->prog);
    glUniform1i(glGetUniformLocation(g->prog, "u_frame"), 0);
    glUniform1i(glGetUniformLocation(g->prog, "u_overlay"), 1);
    glUniform1i(glGetUniformLocation(g->prog, "u_lut"), 2);
    g->u_size = glGetUniformLocation(g->prog, "u_size");
    g->u_view = glGetUniformLocation(g->prog, "u_view");
    g->u_use_frame = glGetUniformLocation(g->prog, "u_use_frame");
    glGenVertexArrays(1, &g->vao);
    return true;
}

view_gl *view_gl_open(void *window, char *why, size_t n)
{
    view_gl *g = calloc(1, sizeof *g);
    if (!g) {
        snprintf(why, n, "out of memory");
        return NULL;
    }
    g->win = window;
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 0);
    g->ctx = SDL_GL_CreateContext(g->win);
    if (!g->ctx) {
        snprintf(why, n, "no OpenGL context for the window: %s", SDL_GetError());
        free(g);
        return NULL;
    }
    bool ok = SDL_GL_MakeCurrent(g->win, g->ctx) == 0;
    if (!ok)
        snprintf(why, n, "the window's context cannot be made current: %s", SDL_GetError());
    /* GLX (an SDL that ignores the hint, or a driver without EGL on X11)
     * leaves no EGL context current: the library cannot share with it. */
    EGLContext ctx = ok && epoxy_has_egl() ? eglGetCurrentContext() : EGL_NO_CONTEXT;
    EGLDisplay dpy = ctx != EGL_NO_CONTEXT ? eglGetCurrentDisplay() : EGL_NO_DISPLAY;
    if (ok && (ctx == EGL_NO_CONTEXT || dpy == EGL_NO_DISPLAY)) {
        snprintf(why, n, "the window's context is not EGL (SDL made it through GLX)");
        ok = false;
    }
    if (ok && epoxy_gl_version() < 30) {
        snprintf(why, n, "the window's context is OpenGL %d.%d, below 3.0", epoxy_gl_version() / 10,
                 epoxy_gl_version() % 10);
        ok = false;
    }
    if (ok) {
        rl_clear_error();
        if (rl_gl_share_with(dpy, ctx) != RL_OK) {
            snprintf(why, n, "%s", rl_last_error());
            ok = false;
        }
        rl_clear_error();
    }
    if (ok)
        ok = make_program(g, why, n);
    if (ok) {
        glGenTextures(1, &g->overlay);
        glGenTextures(1, &g->frame);
        glGenTextures(1, &g->lut);
        GLuint tex[3] = { g->overlay, g->frame, g->lut };
        for (int i = 0; i < 3; i++) {
            glBindTexture(GL_TEXTURE_2D, tex[i]);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
            glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        }
        /* cmd_view.c init_lut()'s table, on texture unit 2 for good */
        uint8_t lut[4097];
        for (int i = 0; i <= 4096; i++)
            lut[i] = (uint8_t)lrintf(rl_linear_to_srgb((float)i / 4096.0f) * 255.0f);
        glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
        glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, 4097, 1, 0, GL_RED, GL_UNSIGNED_BYTE, lut);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, g->lut);
        glActiveTexture(GL_TEXTURE0);
        /* Frames come as fast as they come: no wait for the vertical blank. */
        SDL_GL_SetSwapInterval(0);
        ok = glGetError() == GL_NO_ERROR;
        if (!ok)
            snprintf(why, n, "the window's textures cannot be made");
    }
    if (!ok) {
        view_gl_close(g);
        return NULL;
    }
    return g;
}

void view_gl_close(view_gl *g)
{
    if (!g)
        return;
    if (g->prog) {
        glDeleteProgram(g->prog);
        glDeleteVertexArrays(1, &g->vao);
        glDeleteTextures(1, &g->overlay);
        glDeleteTextures(1, &g->frame);
        glDeleteTextures(1, &g->lut);
    }
    /* Only while no library context exists (after every GL renderer is
     * released): else it says so and nothing changes. */
    rl_gl_share_with(NULL, NULL);
    rl_clear_error();
    SDL_GL_MakeCurrent(g->win, NULL);
    SDL_GL_DeleteContext(g->ctx);
    free(g);
}

bool view_gl_resize(view_gl *g, int w, int h)
{
    glBindTexture(GL_TEXTURE_2D, g->overlay);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, w, h, 0, GL_BGRA, GL_UNSIGNED_BYTE, NULL);
    g->width = w;
    g->height = h;
    return glGetError() == GL_NO_ERROR;
}

void view_gl_delete(view_gl *g, const rl_gl_frame *f)
{
    (void)g;
    if (f->fence)
        glDeleteSync((GLsync)f->fence);
    if (f->texture)
        glDeleteTextures(1, &f->texture);
}

void view_gl_adopt(view_gl *g, const rl_gl_frame *f)
{
    /* The library flushed its fence: the GPU orders the window's reads
     * after the frame's writes without the CPU waiting. */
    glWaitSync((GLsync)f->fence, 0, GL_TIMEOUT_IGNORED);
    glDeleteSync((GLsync)f->fence);
    glDeleteTextures(1, &g->frame);
    g->frame = f->texture;
    g->have_frame = f->width == g->width && f->height == g->height;
}

void view_gl_drop_frame(view_gl *g)
{
    g->have_frame = false;
}

bool view_gl_read(view_gl *g, rl_vec4 *dst)
{
    if (!g->have_frame)
        return false;
    glBindTexture(GL_TEXTURE_2D, g->frame);
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, GL_FLOAT, dst);
    return glGetError() == GL_NO_ERROR;
}

void view_gl_viewport(const view_gl *g, int *x, int *y, int *w, int *h)
{
    *x = g->vx;
    *y = g->vy;
    *w = g->vw;
    *h = g->vh;
}

void view_gl_drawable_size(const view_gl *g, int *w, int *h)
{
    SDL_GL_GetDrawableSize(g->win, w, h);
}

/* The pass of view_gl_present into viewport (x, y, w, h) of the bound
 * framebuffer. */
static void draw_pass(view_gl *g, int x, int y, int w, int h, bool use_frame)
{
    glViewport(x, y, w, h);
    glUseProgram(g->prog);
    glUniform2i(g->u_size, g->width, g->height);
    glUniform4f(g->u_view, (float)x, (float)y, (float)w, (float)h);
    glUniform1i(g->u_use_frame, use_frame && g->have_frame);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, g->frame);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, g->overlay);
    glActiveTexture(GL_TEXTURE0);
    glBindVertexArray(g->vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
}

static void upload_overlay(view_gl *g, const uint32_t *overlay, int rows)
{
    if (rows <= 0)
        return;
    glBindTexture(GL_TEXTURE_2D, g->overlay);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, g->width, rows > g->height ? g->height : rows, GL_BGRA,
                    GL_UNSIGNED_BYTE, overlay);
}

bool view_gl_capture(view_gl *g, const uint32_t *overlay, int rows, bool use_frame, uint32_t *out)
{
    /* The window's pass at the image's size, into a framebuffer of its
     * own: the window may be scaled or smaller than the image. */
    upload_overlay(g, overlay, rows);
    GLuint fbo = 0, rb = 0;
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &rb);
    glBindRenderbuffer(GL_RENDERBUFFER, rb);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, g->width, g->height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, rb);
    bool ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    if (ok) {
        draw_pass(g, 0, 0, g->width, g->height, use_frame);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        glReadPixels(0, 0, g->width, g->height, GL_BGRA, GL_UNSIGNED_BYTE, out);
        /* GL's rows run bottom up */
        for (int y = 0; y < g->height / 2; y++)
            for (int x = 0; x < g->width; x++) {
                uint32_t *a = &out[(size_t)y * (size_t)g->width + (size_t)x];
                uint32_t *b = &out[(size_t)(g->height - 1 - y) * (size_t)g->width + (size_t)x];
                uint32_t t = *a;
                *a = *b;
                *b = t;
            }
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &rb);
    return ok && glGetError() == GL_NO_ERROR;
}

void view_gl_present(view_gl *g, const uint32_t *overlay, int rows, bool use_frame)
{
    int dw = 0, dh = 0;
    SDL_GL_GetDrawableSize(g->win, &dw, &dh);
    /* Letterboxed as SDL_RenderSetLogicalSize does on the readback path. */
    double sx = (double)dw / g->width, sy = (double)dh / g->height, s = sx < sy ? sx : sy;
    g->vw = (int)(g->width * s);
    g->vh = (int)(g->height * s);
    g->vx = (dw - g->vw) / 2;
    g->vy = (dh - g->vh) / 2;
    upload_overlay(g, overlay, rows);
    glViewport(0, 0, dw, dh);
    glClearColor(0.0f, 0.0f, 0.0f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    draw_pass(g, g->vx, g->vy, g->vw, g->vh, use_frame);
    SDL_GL_SwapWindow(g->win);
}

#else

view_gl *view_gl_open(void *window, char *why, size_t n)
{
    (void)window;
    snprintf(why, n, "this rl was built without the GL backend");
    return NULL;
}

void view_gl_close(view_gl *g) { (void)g; }
bool view_gl_resize(view_gl *g, int w, int h)
{
    (void)g;
    (void)w;
    (void)h;
    return false;
}
void view_gl_delete(view_gl *g, const rl_gl_frame *f)
{
    (void)g;
    (void)f;
}
void view_gl_adopt(view_gl *g, const rl_gl_frame *f)
{
    (void)g;
    (void)f;
}
void view_gl_drop_frame(view_gl *g) { (void)g; }
bool view_gl_read(view_gl *g, rl_vec4 *dst)
{
    (void)g;
    (void)dst;
    return false;
}
void view_gl_viewport(const view_gl *g, int *x, int *y, int *w, int *h)
{
    (void)g;
    *x = *y = 0;
    *w = *h = 1;
}
void view_gl_drawable_size(const view_gl *g, int *w, int *h)
{
    (void)g;
    *w = *h = 1;
}
bool view_gl_capture(view_gl *g, const uint32_t *overlay, int rows, bool use_frame, uint32_t *out)
{
    (void)g;
    (void)overlay;
    (void)rows;
    (void)use_frame;
    (void)out;
    return false;
}
void view_gl_present(view_gl *g, const uint32_t *overlay, int rows, bool use_frame)
{
    (void)g;
    (void)overlay;
    (void)rows;
    (void)use_frame;
}

#endif
