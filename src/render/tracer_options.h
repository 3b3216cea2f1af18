/* tracer_options.h: what the ray-tracing renderers (whitted, vt) share of
 * their options: the rows of their option tables that configure the exact
 * tracer and the accelerator, the Embree availability check, and reading
 * them back into an rl_tracer_desc. One definition, so the renderers cannot
 * drift apart in what the same option means (Vertex Tracing is measured
 * against Whitted with the same tracer settings, Ullmann 2003, Ch. 5). */
#ifndef RL_RENDER_TRACER_OPTIONS_H
#define RL_RENDER_TRACER_OPTIONS_H

#include "render/renderer.h"
#include "rl/rl_accel.h"
#include "rl/rl_trace.h"

extern const char *const rl_tracer_accel_choices[];

#define RL_TRACER_OPTION_ROWS                                                                         \
    { "accel", RL_OPT_ENUM, "bvh", "acceleration structure (embree only in builds with Embree)",     \
      0, 0, rl_tracer_accel_choices },                                                                \
    { "max_depth", RL_OPT_INT, "5", "reflection/refraction recursion depth (0: local shading only)", \
      0, 64, NULL },                                                                                  \
    { "area_samples", RL_OPT_INT, "4", "n x n jittered shadow feelers per quad light", 1, 32, NULL }, \
    { "shadows", RL_OPT_BOOL, "true", "trace shadow feelers (false: every light is visible; -S)",    \
      0, 0, NULL },                                                                                   \
    { "reflections", RL_OPT_BOOL, "true",                                                             \
      "trace reflection rays (false: the k_r term is left out; -R of Ullmann 2003, Fig. 5.10)",       \
      0, 0, NULL },                                                                                   \
    { "transmission", RL_OPT_BOOL, "true",                                                            \
      "trace transmission rays (false: the k_t term is left out; -T of Ullmann 2003, Fig. 5.10)",     \
      0, 0, NULL },                                                                                   \
    { "transmitted_highlight", RL_OPT_BOOL, "true",                                                   \
      "eq. 3.17: lights behind a transmissive surface add k_t cos^n of the angle between their "      \
      "refracted direction and the viewer's (false: classic Phong)", 0, 0, NULL },                    \
    { "ambient", RL_OPT_FLOAT, "0.05", "ambient light, multiplied by k_d", 0, 1, NULL },             \
    { "background", RL_OPT_COLOR, "0,0,0",                                                            \
      "radiance of rays that leave the scene: \"r,g,b\" or one grey value", 0, 0, NULL },             \
    { "threads", RL_OPT_INT, "0", "OpenMP threads (0 = all)", 0, 1024, NULL }

/* The renderer class's check for these rows: accel=embree in a build
 * without Embree is RL_ERR_INVALID_ARG naming `who`. */
rl_status rl_tracer_options_check(const char *who, const char *key, const char *value);
/* The tracer description and accelerator kind the rows ask for (option
 * zeros mean "none" here but "default" in the desc, hence the mapping). */
rl_status rl_tracer_options_read(const rl_renderer *r, rl_tracer_desc *desc, rl_accel_kind *kind);

#endif
