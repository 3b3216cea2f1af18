/* gl_raster.c: renderer "gl-raster", the "raster" renderer on OpenGL 4.5:
 * the same scene drawing (local Phong lighting, flat / Gouraud / textured,
 * alpha masks, normal maps, IDs and eye depth) through the GL drawer of
 * src/gl instead of the software rasterizer. This is the hardware path the
 * thesis renderers assume (Ullmann 2003, Sec. 3.5: OpenGL Gouraud shading);
 * raster.c is its reference, and the two agree up to the rasterization
 * rules (docs/gl.md).
 *
 * The drawer, and with it the GL context, is made on the first render and
 * kept while scene, options and device stay the same: creating a context
 * and uploading the scene cost more than a frame. Unavailable (no GL 4.5
 * context on the device) is reported by rl_renderer_available, never a
 * crash.
 *
 * Options (defaults): shading = textured, cull = false, ambient = 0.05,
 * background = "0,0,0" (as raster), device = "" (RL_EGL_DEVICE, else
 * auto: rl_gl.h). */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/culling.h"
#include "gl/gl_frame.h"
#include "render/renderer.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "rl/rl_timer.h"

static const rl_option_info gl_raster_options[] = {
    RL_RASTER_OPTIONS,
    { "device", RL_OPT_STRING, "",
      "EGL device: auto, surfaceless or a device number; empty: $RL_EGL_DEVICE, else auto", 0, 0, NULL },
};

typedef struct gl_raster_state {
    rl_drawer *drawer;
    bool texture_out;             /* rl_renderer_set_gl_output */
    char device[64];              /* the device option the drawer was made on */
    char info[528];               /* rl_render_stats.device: the three strings of rl_gl_info */
} gl_raster_state;

static void gl_raster_release(void *state)
{
    gl_raster_state *s = state;
    rl_drawer_release(s->drawer);
}

static bool gl_raster_available(const rl_renderer *r, char *why, size_t n)
{
    return rl_gl_available(rl_renderer_opt_string(r, "device"), why, n);
}

static rl_status gl_raster_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                                  rl_image *image, rl_render_stats *stats)
{
    gl_raster_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    const char *device = rl_renderer_opt_string(r, "device");
    rl_drawer_desc desc = {
        .shading = (rl_raster_shading)rl_renderer_opt_enum(r, "shading"),
        .ambient = (float)rl_renderer_opt_float(r, "ambient"),
        .flags = rl_renderer_opt_bool(r, "cull") ? RL_RASTER_CULL_BACK : 0u,
    };

    /* The drawer needs a depth layer; borrowed as raster does, and the
     * target cleared before the frame begins (the GL drawer uploads it). */
    rl_cull_target target;
    const rl_vec3 bg = rl_renderer_opt_color(r, "background");
    /* With texture output the colour never visits the CPU: the GL drawer
     * clears it to the background itself (rl_gl_drawer_set_clear), so the
     * image's colour is neither filled nor uploaded. */
    rl_image view = *image;
    if (s->texture_out)
        view.color = NULL;
    rl_status st = rl_cull_target_begin(&view, bg, &target);
    if (st != RL_OK)
        return st;
    target.image.color = image->color;
    desc.flags |= target.flags;
    if (!rl_drawer_fits(s->drawer, scene, &desc) || strcmp(s->device, device) != 0) {
        rl_drawer_release(s->drawer);
        s->drawer = NULL;
        if (strlen(device) >= sizeof s->device)
            st = rl_error(RL_ERR_INVALID_ARG, "gl-raster: device \"%.40s...\" is too long", device);
        rl_timer timer;
        rl_timer_start(&timer);
        if (st == RL_OK)
            st = rl_gl_drawer_create(scene, &desc, device, &s->drawer);
        if (st == RL_OK)
            st = rl_gl_drawer_set_texture_output(s->drawer, s->texture_out);
        stats->prep_ms = rl_timer_ms(&timer);
        if (st == RL_OK) {
            snprintf(s->device, sizeof s->device, "%s", device);
            rl_gl_info info;
            if (rl_gl_info_get(device, &info) == RL_OK)
                snprintf(s->info, sizeof s->info, "%s | %s | %s", info.vendor, info.renderer, info.version);
        }
    }
    const float clear[4] = { bg.x, bg.y, bg.z, 1.0f };
    if (st == RL_OK)
        rl_gl_drawer_set_clear(s->drawer, s->texture_out ? clear : NULL);
    if (st == RL_OK)
        st = rl_cull_draw_all(r, s->drawer, &target, cam, d->bounds, stats);
    rl_cull_target_end(&target);
    if (st == RL_OK)
        stats->device = s->info[0] ? s->info : NULL;
    return st;
}

static void gl_raster_gl_output(void *state, bool on)
{
    gl_raster_state *s = state;
    s->texture_out = on;
    if (s->drawer)
        rl_gl_drawer_set_texture_output(s->drawer, on);
}

static bool gl_raster_take_gl_frame(void *state, rl_gl_frame *out)
{
    gl_raster_state *s = state;
    return s->drawer && rl_gl_drawer_take_frame(s->drawer, out);
}

const rl_renderer_class rl_gl_raster_renderer_class = {
    .info = { .name = "gl-raster",
              .description = "raster on OpenGL 4.5 (headless EGL): the same local Phong shading, IDs and depth",
              .reference = "Ullmann 2003, Sec. 3.1 (Phong model), Sec. 3.5 (hardware Gouraud path)" },
    .options = gl_raster_options,
    .num_options = sizeof gl_raster_options / sizeof gl_raster_options[0],
    .state_size = sizeof(gl_raster_state),
    .render = gl_raster_render,
    .release = gl_raster_release,
    .check = NULL,
    .available = gl_raster_available,
    .gl_output = gl_raster_gl_output,
    .take_gl_frame = gl_raster_take_gl_frame,
};
