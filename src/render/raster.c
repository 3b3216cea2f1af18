/* raster.c: renderer "raster", software rasterization with local Phong
 * lighting; the reference for the hardware path of the thesis renderers
 * (Ullmann 2003, Sec. 3.5 uses OpenGL Gouraud shading for the same role).
 *
 * The lighting model and its deviations from the thesis are those of the
 * scene drawer (src/raster/scene_drawer.c), which the hybrid and culling
 * renderers share. raster_render() only sets up the target, clears it and
 * draws every object with the drawer (rl_drawer.h) it keeps between
 * frames: the buffers for the whole scene are made once, the lighting is
 * redone every frame where it can change (the drawer keeps the colours of
 * vertices without a specular term while they show the eye the same side).
 *
 * Options (defaults): shading = textured (flat | gouraud | textured),
 * cull = false, ambient = 0.05, background = "0,0,0", threads = 0 (all). */
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_drawer.h"
#include "render/culling.h"
#include "render/renderer.h"
#include "rl/rl_raster.h"

static const rl_option_info raster_options[] = {
    RL_RASTER_OPTIONS,
    { "threads", RL_OPT_INT, "0", "OpenMP threads for lighting and rasterization (0 = all)", 0, 1024, NULL },
};

/* The renderer's state: its rasterizer and drawer, kept between frames
 * (the drawer's buffers span the whole scene). Every frame still lights
 * every object whose light depends on the eye. */
typedef struct raster_state {
    rl_drawer *drawer;
} raster_state;

static void raster_release(void *state)
{
    raster_state *s = state;
    rl_drawer_release(s->drawer);
}

static rl_status raster_render(rl_renderer *r, void *state, const rl_scene *scene,
                               const rl_camera *cam, rl_image *image, rl_render_stats *stats)
{
    raster_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    rl_drawer_desc desc = {
        .shading = (rl_raster_shading)rl_renderer_opt_enum(r, "shading"),
        .ambient = (float)rl_renderer_opt_float(r, "ambient"),
        .threads = (int)rl_renderer_opt_int(r, "threads"),
        .flags = rl_renderer_opt_bool(r, "cull") ? RL_RASTER_CULL_BACK : 0u,
    };

    /* The rasterizer depth-tests against the target's depth layer: the
     * culling renderers' target borrows a private one when the caller did
     * not ask for depth, and clears it to the background. */
    rl_cull_target target;
    rl_status st = rl_cull_target_begin(image, rl_renderer_opt_color(r, "background"), &target);
    if (st != RL_OK)
        return st;
    desc.flags |= target.flags;
    if (!rl_drawer_fits(s->drawer, scene, &desc)) {
        rl_drawer_release(s->drawer);
        s->drawer = NULL;
        st = rl_drawer_create(scene, &desc, &s->drawer);
    }
    if (st == RL_OK)
        st = rl_cull_draw_all(r, s->drawer, &target, cam, d->bounds, stats);
    rl_cull_target_end(&target);
    return st;
}

const rl_renderer_class rl_raster_renderer_class = {
    .info = { .name = "raster",
              .description = "Software rasterization with local Phong lighting; the hardware-path reference",
              .reference = "Ullmann 2003, Sec. 3.1 (Phong model), Sec. 3.5 (hardware path)",
              .frame_bytes_per_pixel = sizeof(float) },   /* a depth buffer when the image has none */
    .options = raster_options,
    .num_options = sizeof raster_options / sizeof raster_options[0],
    .state_size = sizeof(raster_state),
    .render = raster_render,
    .release = raster_release,
    .check = NULL,
};
