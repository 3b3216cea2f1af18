/* gl_context.c: headless OpenGL 4.5 core contexts through EGL and epoxy
 * (gl_context.h, rl_gl.h).
 *
 * No window and no config: EGL_KHR_no_config_context and
 * EGL_KHR_surfaceless_context let a context be current with no surface,
 * and every GL renderer draws into its own framebuffer objects. Displays
 * come from EGL_EXT_platform_base: EGL_PLATFORM_DEVICE_EXT over the
 * devices of EGL_EXT_device_enumeration (NVIDIA's headless path, and
 * Mesa's software device) or EGL_PLATFORM_SURFACELESS_MESA (Mesa without
 * a GPU: llvmpipe). Without RL_HAVE_GL (configured without epoxy and EGL)
 * every device is unavailable, with that as the reason. */
#include "gl/gl_context.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"

/* The device argument as the user meant it: NULL or "" defer to
 * RL_EGL_DEVICE, and an unset variable means "auto". */
static const char *resolve_device(const char *device)
{
    if (!device || !*device)
        device = getenv("RL_EGL_DEVICE");
    return device && *device ? device : "auto";
}

static void copy_text(char *dst, size_t n, const char *src)
{
    if (dst && n)
        snprintf(dst, n, "%s", src);
}

#ifdef RL_HAVE_GL

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <pthread.h>

struct rl_gl_context {
    EGLDisplay dpy;
    EGLContext ctx;
    const rl_gl_info *info;
    /* What was current on the thread before make_current, restored by
     * done: with rl_gl_share_with the calling thread may hold the caller's
     * context (a viewer's window), which a frame must not take away. */
    EGLDisplay prev_dpy;
    EGLSurface prev_draw, prev_read;
    EGLContext prev_ctx;
    bool have_prev;
};

/* One entry per device name asked for: whether it works, its display
 * (initialised and kept) and its strings, or why it does not. */
#define MAX_DEVICES 8
typedef struct device_entry {
    char name[32];
    bool ok;
    EGLDisplay dpy;
    rl_gl_info info;
    char why[256];
} device_entry;

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static device_entry devices[MAX_DEVICES];
static int num_devices;

/* rl_gl_share_with: the caller's display and context. While on, every
 * context is made on that display in the caller's share group, whatever
 * device was asked for, and the entry stands for all devices. */
static struct {
    bool on;
    EGLContext ctx;
    device_entry entry;
} share;
/* Contexts made and not yet released (rl_gl_share_with refuses to switch
 * while any lives: they would sit in two share groups at once). */
static int live_contexts;

static bool has_word(const char *list, const char *word)
{
    size_t n = strlen(word);
    for (const char *p = list; p && (p = strstr(p, word)) != NULL; p += n)
        if ((p == list || p[-1] == ' ') && (p[n] == ' ' || p[n] == '\0'))
            return true;
    return false;
}

static EGLContext make_context(EGLDisplay dpy, EGLContext share_with)
{
    static const EGLint attribs[] = {
        EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
        EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE,
    };
    if (!eglBindAPI(EGL_OPENGL_API))
        return EGL_NO_CONTEXT;
    return eglCreateContext(dpy, EGL_NO_CONFIG_KHR, share_with, attribs);
}

/* Initialises dpy and proves it with a 4.5 core context, whose strings go
 * to e; false with the reason in e->why, dpy terminated again. */
static bool try_display(EGLDisplay dpy, const char *label, device_entry *e)
{
    EGLint major = 0, minor = 0;
    if (dpy == EGL_NO_DISPLAY || !eglInitialize(dpy, &major, &minor)) {
        snprintf(e->why, sizeof e->why, "%s: eglInitialize failed (EGL error 0x%x)", label, (unsigned)eglGetError());
        return false;
    }
    const char *ext = eglQueryString(dpy, EGL_EXTENSIONS);
    if (!has_word(ext, "EGL_KHR_no_config_context") && !has_word(ext, "EGL_MESA_configless_context")) {
        snprintf(e->why, sizeof e->why, "%s: EGL %d.%d has no EGL_KHR_no_config_context", label, major, minor);
        eglTerminate(dpy);
        return false;
    }
    if (!has_word(ext, "EGL_KHR_surfaceless_context")) {
        snprintf(e->why, sizeof e->why, "%s: EGL %d.%d has no EGL_KHR_surfaceless_context", label, major, minor);
        eglTerminate(dpy);
        return false;
    }
    EGLContext ctx = make_context(dpy, EGL_NO_CONTEXT);
    if (ctx == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        snprintf(e->why, sizeof e->why, "%s: no OpenGL 4.5 core context (EGL error 0x%x)", label,
                 (unsigned)eglGetError());
        if (ctx != EGL_NO_CONTEXT)
            eglDestroyContext(dpy, ctx);
        eglTerminate(dpy);
        return false;
    }
    const char *vendor = (const char *)glGetString(GL_VENDOR);
    const char *renderer = (const char *)glGetString(GL_RENDERER);
    const char *version = (const char *)glGetString(GL_VERSION);
    copy_text(e->info.vendor, sizeof e->info.vendor, vendor ? vendor : "?");
    copy_text(e->info.renderer, sizeof e->info.renderer, renderer ? renderer : "?");
    copy_text(e->info.version, sizeof e->info.version, version ? version : "?");
    copy_text(e->info.device, sizeof e->info.device, label);
    eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(dpy, ctx);
    e->dpy = dpy;
    return true;
}

static bool open_surfaceless(device_entry *e)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_word(client, "EGL_MESA_platform_surfaceless")) {
        copy_text(e->why, sizeof e->why, "surfaceless: EGL has no EGL_MESA_platform_surfaceless");
        return false;
    }
    return try_display(eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, NULL),
                       "surfaceless", e);
}

/* Device index (or every device in order, index < 0) of the device
 * platform. */
static bool open_device(int index, device_entry *e)
{
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_word(client, "EGL_EXT_device_enumeration") && !has_word(client, "EGL_EXT_device_base")) {
        copy_text(e->why, sizeof e->why, "EGL has no EGL_EXT_device_enumeration");
        return false;
    }
    if (!has_word(client, "EGL_EXT_platform_device")) {
        copy_text(e->why, sizeof e->why, "EGL has no EGL_EXT_platform_device");
        return false;
    }
    EGLDeviceEXT list[16];
    EGLint count = 0;
    if (!eglQueryDevicesEXT(16, list, &count) || count <= 0) {
        copy_text(e->why, sizeof e->why, "eglQueryDevicesEXT found no EGL device");
        return false;
    }
    if (index >= count) {
        snprintf(e->why, sizeof e->why, "EGL device %d does not exist (%d device%s: 0..%d)", index, count,
                 count == 1 ? "" : "s", count - 1);
        return false;
    }
    for (int i = index < 0 ? 0 : index; i < (index < 0 ? count : index + 1); ++i) {
        char label[32];
        snprintf(label, sizeof label, "device %d", i);
        if (try_display(eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT, list[i], NULL), label, e))
            return true;
    }
    return false;
}

static void open_entry(device_entry *e)
{
    if (!epoxy_has_egl()) {
        copy_text(e->why, sizeof e->why, "no EGL library (libEGL.so.1) could be loaded");
        return;
    }
    const char *client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!has_word(client, "EGL_EXT_platform_base")) {
        copy_text(e->why, sizeof e->why, "EGL has no EGL_EXT_platform_base");
        return;
    }
    if (strcmp(e->name, "surfaceless") == 0) {
        e->ok = open_surfaceless(e);
    } else if (strcmp(e->name, "auto") == 0) {
        char first[256];
        e->ok = open_device(-1, e);
        if (!e->ok) {
            copy_text(first, sizeof first, e->why);
            e->ok = open_surfaceless(e);
            if (!e->ok) {
                char second[256];
                copy_text(second, sizeof second, e->why);
                snprintf(e->why, sizeof e->why, "%.120s; %.120s", first, second);
            }
        }
    } else {
        char *end = NULL;
        long index = strtol(e->name, &end, 10);
        if (end == e->name || *end || index < 0 || index > 15)
            snprintf(e->why, sizeof e->why,
                     "EGL device \"%s\" (RL_EGL_DEVICE or the device option) is not auto, surfaceless or "
                     "a device number 0..15", e->name);
        else
            e->ok = open_device((int)index, e);
    }
}

/* The entry of a device name, opened on first use; NULL when the table is
 * full (the why of a stack entry then says so). */
static const device_entry *find_device(const char *device, device_entry *scratch)
{
    const char *name = resolve_device(device);
    const device_entry *found = NULL;
    pthread_mutex_lock(&lock);
    if (share.on)
        found = &share.entry;
    for (int i = 0; i < num_devices && !found; ++i)
        if (strcmp(devices[i].name, name) == 0)
            found = &devices[i];
    if (!found) {
        device_entry *e = num_devices < MAX_DEVICES ? &devices[num_devices] : scratch;
        memset(e, 0, sizeof *e);
        if (strlen(name) >= sizeof e->name) {
            copy_text(e->name, sizeof e->name, "?");
            snprintf(e->why, sizeof e->why, "EGL device name \"%.40s...\" is too long", name);
        } else {
            copy_text(e->name, sizeof e->name, name);
            open_entry(e);
        }
        if (e != scratch)
            num_devices++;
        found = e;
    }
    pthread_mutex_unlock(&lock);
    return found;
}

bool rl_gl_available(const char *device, char *why, size_t n)
{
    device_entry scratch;
    const device_entry *e = find_device(device, &scratch);
    if (!e->ok)
        copy_text(why, n, e->why);
    return e->ok;
}

rl_status rl_gl_info_get(const char *device, rl_gl_info *out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_info_get: NULL argument");
    device_entry scratch;
    const device_entry *e = find_device(device, &scratch);
    if (!e->ok)
        return rl_error(RL_ERR_UNSUPPORTED, "OpenGL unavailable: %s", e->why);
    *out = e->info;
    return RL_OK;
}

rl_status rl_gl_context_create(const char *device, rl_gl_context **out)
{
    *out = NULL;
    device_entry scratch;
    const device_entry *e = find_device(device, &scratch);
    if (!e->ok)
        return rl_error(RL_ERR_UNSUPPORTED, "OpenGL unavailable: %s", e->why);
    rl_gl_context *c = rl_calloc(1, sizeof *c);
    if (!c)
        return RL_ERR_OUT_OF_MEMORY;
    pthread_mutex_lock(&lock);
    /* e is the share entry exactly while sharing is on (find_device). */
    EGLContext share_with = share.on && e == &share.entry ? share.ctx : EGL_NO_CONTEXT;
    c->dpy = e->dpy;
    c->info = &e->info;
    c->ctx = make_context(e->dpy, share_with);
    if (c->ctx != EGL_NO_CONTEXT)
        live_contexts++;
    pthread_mutex_unlock(&lock);
    if (c->ctx == EGL_NO_CONTEXT) {
        free(c);
        return rl_error(RL_ERR_UNSUPPORTED, "OpenGL unavailable: %s: eglCreateContext failed (EGL error 0x%x)",
                        e->info.device, (unsigned)eglGetError());
    }
    rl_status st = rl_gl_context_make_current(c);
    if (st != RL_OK) {
        rl_gl_context_release(c);
        return st;
    }
    *out = c;
    return RL_OK;
}

rl_status rl_gl_context_make_current(rl_gl_context *c)
{
    EGLContext cur = eglGetCurrentContext();
    if (cur == c->ctx)
        return RL_OK;
    EGLDisplay prev_dpy = eglGetCurrentDisplay();
    EGLSurface prev_draw = eglGetCurrentSurface(EGL_DRAW), prev_read = eglGetCurrentSurface(EGL_READ);
    if (!eglBindAPI(EGL_OPENGL_API) || !eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, c->ctx))
        return rl_error(RL_ERR_INTERNAL, "gl: eglMakeCurrent failed (EGL error 0x%x): is the drawer in use on "
                        "another thread?", (unsigned)eglGetError());
    c->have_prev = cur != EGL_NO_CONTEXT;
    c->prev_dpy = prev_dpy;
    c->prev_draw = prev_draw;
    c->prev_read = prev_read;
    c->prev_ctx = cur;
    return RL_OK;
}

void rl_gl_context_done(rl_gl_context *c)
{
    if (!c || eglGetCurrentContext() != c->ctx)
        return;
    /* The caller's own context (a window's, rl_gl_share_with) comes back. */
    if (!c->have_prev || !eglMakeCurrent(c->prev_dpy, c->prev_draw, c->prev_read, c->prev_ctx))
        eglMakeCurrent(c->dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    c->have_prev = false;
}

const rl_gl_info *rl_gl_context_info(const rl_gl_context *c) { return c->info; }

void rl_gl_context_release(rl_gl_context *c)
{
    if (!c)
        return;
    rl_gl_context_done(c);
    if (c->ctx != EGL_NO_CONTEXT) {
        eglDestroyContext(c->dpy, c->ctx);
        pthread_mutex_lock(&lock);
        live_contexts--;
        pthread_mutex_unlock(&lock);
    }
    free(c);
}

bool rl_gl_share_active(void)
{
    pthread_mutex_lock(&lock);
    bool on = share.on;
    pthread_mutex_unlock(&lock);
    return on;
}

rl_status rl_gl_share_with(void *egl_display, void *egl_context)
{
    if (!egl_display != !egl_context)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_share_with: the display and the context go together (both "
                        "NULL to stop sharing)");
    pthread_mutex_lock(&lock);
    if (live_contexts > 0) {
        int n = live_contexts;
        pthread_mutex_unlock(&lock);
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_share_with: %d GL context%s of the library exist%s already; "
                        "call it before the first GL renderer renders", n, n == 1 ? "" : "s", n == 1 ? "s" : "");
    }
    if (!egl_display) {
        share.on = false;
        pthread_mutex_unlock(&lock);
        return RL_OK;
    }
    device_entry e = { .name = "shared" };
    EGLDisplay dpy = (EGLDisplay)egl_display;
    rl_status st = RL_OK;
    const char *ext = epoxy_has_egl() ? eglQueryString(dpy, EGL_EXTENSIONS) : NULL;
    if (!ext)
        st = rl_error(RL_ERR_UNSUPPORTED, "rl_gl_share_with: not an initialised EGL display (EGL error 0x%x)",
                      epoxy_has_egl() ? (unsigned)eglGetError() : 0u);
    else if (!has_word(ext, "EGL_KHR_no_config_context") && !has_word(ext, "EGL_MESA_configless_context"))
        st = rl_error(RL_ERR_UNSUPPORTED, "rl_gl_share_with: the display has no EGL_KHR_no_config_context");
    else if (!has_word(ext, "EGL_KHR_surfaceless_context"))
        st = rl_error(RL_ERR_UNSUPPORTED, "rl_gl_share_with: the display has no EGL_KHR_surfaceless_context");
    if (st == RL_OK) {
        /* A probe context in the caller's share group: EGL refuses one
         * whose share context is of another display or API. The caller's
         * binding on this thread comes back afterwards. */
        EGLDisplay prev_dpy = eglGetCurrentDisplay();
        EGLSurface prev_draw = eglGetCurrentSurface(EGL_DRAW), prev_read = eglGetCurrentSurface(EGL_READ);
        EGLContext prev_ctx = eglGetCurrentContext();
        EGLenum prev_api = eglQueryAPI();
        EGLContext probe = make_context(dpy, (EGLContext)egl_context);
        if (probe == EGL_NO_CONTEXT || !eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, probe)) {
            st = rl_error(RL_ERR_UNSUPPORTED, "rl_gl_share_with: no OpenGL 4.5 core context sharing with the "
                          "given one (EGL error 0x%x)", (unsigned)eglGetError());
        } else {
            const char *vendor = (const char *)glGetString(GL_VENDOR);
            const char *renderer = (const char *)glGetString(GL_RENDERER);
            const char *version = (const char *)glGetString(GL_VERSION);
            copy_text(e.info.vendor, sizeof e.info.vendor, vendor ? vendor : "?");
            copy_text(e.info.renderer, sizeof e.info.renderer, renderer ? renderer : "?");
            copy_text(e.info.version, sizeof e.info.version, version ? version : "?");
            copy_text(e.info.device, sizeof e.info.device, "shared");
        }
        if (prev_ctx != EGL_NO_CONTEXT)
            eglMakeCurrent(prev_dpy, prev_draw, prev_read, prev_ctx);
        else
            eglMakeCurrent(dpy, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (probe != EGL_NO_CONTEXT)
            eglDestroyContext(dpy, probe);
        eglBindAPI(prev_api);
    }
    if (st == RL_OK) {
        e.ok = true;
        e.dpy = dpy;
        share.entry = e;
        share.ctx = (EGLContext)egl_context;
        share.on = true;
    }
    pthread_mutex_unlock(&lock);
    return st;
}

#else /* !RL_HAVE_GL */

#define NO_GL "this build has no OpenGL (configure with -DRL_GL=ON; needs libepoxy-dev and libegl-dev)"

bool rl_gl_available(const char *device, char *why, size_t n)
{
    (void)resolve_device(device);
    copy_text(why, n, NO_GL);
    return false;
}

rl_status rl_gl_info_get(const char *device, rl_gl_info *out)
{
    (void)device;
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_info_get: NULL argument");
    return rl_error(RL_ERR_UNSUPPORTED, "OpenGL unavailable: " NO_GL);
}

rl_status rl_gl_context_create(const char *device, rl_gl_context **out)
{
    (void)device;
    *out = NULL;
    return rl_error(RL_ERR_UNSUPPORTED, "OpenGL unavailable: " NO_GL);
}

rl_status rl_gl_context_make_current(rl_gl_context *ctx)
{
    (void)ctx;
    return rl_error(RL_ERR_UNSUPPORTED, "OpenGL unavailable: " NO_GL);
}

void rl_gl_context_done(rl_gl_context *ctx) { (void)ctx; }

const rl_gl_info *rl_gl_context_info(const rl_gl_context *ctx)
{
    (void)ctx;
    return NULL;
}

void rl_gl_context_release(rl_gl_context *ctx) { (void)ctx; }

bool rl_gl_share_active(void) { return false; }

rl_status rl_gl_share_with(void *egl_display, void *egl_context)
{
    if (!egl_display && !egl_context)
        return RL_OK;
    return rl_error(RL_ERR_UNSUPPORTED, "rl_gl_share_with: " NO_GL);
}

#endif
