/* tracer_options.c: see tracer_options.h. */
#include "render/tracer_options.h"

#include <string.h>

#include "core/error.h"

const char *const rl_tracer_accel_choices[] = { "bvh", "grid", "embree", "brute", NULL };

rl_status rl_tracer_options_check(const char *who, const char *key, const char *value)
{
    if (strcmp(key, "accel") == 0 && strcmp(value, "embree") == 0 &&
        !rl_accel_kind_available(RL_ACCEL_EMBREE))
        return rl_error(RL_ERR_INVALID_ARG,
                        "%s: accel=embree is not available in this build (configure with -DRL_EMBREE=ON)", who);
    return RL_OK;
}

rl_status rl_tracer_options_read(const rl_renderer *r, rl_tracer_desc *desc, rl_accel_kind *kind)
{
    int max_depth = (int)rl_renderer_opt_int(r, "max_depth");
    float ambient = (float)rl_renderer_opt_float(r, "ambient");
    memset(desc, 0, sizeof *desc);
    desc->max_depth = max_depth > 0 ? max_depth : -1;
    desc->area_samples = (int)rl_renderer_opt_int(r, "area_samples");
    desc->ambient = ambient > 0.0f ? ambient : -1.0f;
    desc->background = rl_renderer_opt_color(r, "background");
    desc->no_shadows = !rl_renderer_opt_bool(r, "shadows");
    desc->no_reflections = !rl_renderer_opt_bool(r, "reflections");
    desc->no_transmission = !rl_renderer_opt_bool(r, "transmission");
    desc->no_transmitted_highlight = !rl_renderer_opt_bool(r, "transmitted_highlight");
    return rl_accel_kind_parse(rl_tracer_accel_choices[rl_renderer_opt_enum(r, "accel")], kind);
}
