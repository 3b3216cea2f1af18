/* light.c: light sources (point, spot, directional, quad area light):
 * names, validation and the scene's light list. */
#include "scene/scene_internal.h"
#include "core/error.h"

#include <string.h>

static const char *const type_names[RL_LIGHT_TYPE_COUNT] = { "point", "spot", "directional", "quad" };

const char *rl_light_type_name(rl_light_type type)
{
    return (unsigned)type < RL_LIGHT_TYPE_COUNT ? type_names[type] : "unknown";
}

static bool colour_ok(rl_vec3 c)
{
    return rl_vfinite(c) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f;
}

rl_status rl_light_validate(const rl_light *l)
{
    if (!l)
        return rl_error(RL_ERR_INVALID_ARG, "light: NULL");
    if ((unsigned)l->type >= RL_LIGHT_TYPE_COUNT)
        return rl_error(RL_ERR_INVALID_ARG, "light: unknown type %d", (int)l->type);
    const char *t = type_names[l->type];
    if (!colour_ok(l->color))
        return rl_error(RL_ERR_INVALID_ARG, "%s light: colour must be finite and non-negative", t);
    if (!isfinite(l->intensity) || l->intensity < 0.0f)
        return rl_error(RL_ERR_INVALID_ARG, "%s light: intensity %g must be >= 0", t,
                        (double)l->intensity);
    if (!rl_vfinite(l->position))
        return rl_error(RL_ERR_INVALID_ARG, "%s light: position is not finite", t);
    if (l->type == RL_LIGHT_SPOT || l->type == RL_LIGHT_DIRECTIONAL) {
        if (!rl_vfinite(l->direction) || rl_length2(l->direction) <= 0.0f)
            return rl_error(RL_ERR_INVALID_ARG, "%s light: direction must be finite and non-zero", t);
    }
    if (l->type == RL_LIGHT_SPOT) {
        float inner = l->spot_inner_deg, outer = l->spot_outer_deg;
        /* A cone wider than a half space is no longer a spot light. */
        if (!isfinite(inner) || !isfinite(outer) || inner < 0.0f || outer <= 0.0f ||
            inner > outer || outer > 90.0f)
            return rl_error(RL_ERR_INVALID_ARG,
                            "spot light: need 0 <= inner (%g) <= outer (%g) <= 90 degrees, outer > 0",
                            (double)inner, (double)outer);
    }
    if (l->type == RL_LIGHT_QUAD) {
        rl_vec3 u = l->edge_u, v = l->edge_v;
        if (!rl_vfinite(u) || !rl_vfinite(v))
            return rl_error(RL_ERR_INVALID_ARG, "quad light: edges are not finite");
        /* Relative test: |u x v| = |u||v| sin(angle); parallel edges emit from no area. */
        double area = rl_length(rl_cross(u, v));
        if (!(area > 1e-6 * (double)rl_length(u) * (double)rl_length(v)) || area <= 0.0)
            return rl_error(RL_ERR_INVALID_ARG, "quad light: edges are zero or parallel");
    }
    return RL_OK;
}

rl_status rl_scene_add_light(rl_scene *scene, const rl_light *light)
{
    if (!scene || !light)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_light: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "add a light");
    if (st != RL_OK)
        return st;
    if ((st = rl_light_validate(light)) != RL_OK)
        return st;
    if ((st = rl_scene_reserve((void **)&scene->lights, &scene->cap_lights,
                               scene->num_lights + 1, sizeof *scene->lights)) != RL_OK)
        return st;
    scene->lights[scene->num_lights++] = *light;
    return RL_OK;
}
