/* environment.c: the scene's environment (issue 37; the skybox item of
 * Schröder 2017, Sec. 13.4): a constant radiance or a lat-long map, the
 * radiance of directions that leave the scene. The path tracer samples it
 * by its own distribution (pathtrace_env.c); here are the map, its
 * parametrisation and the lookup, which must agree exactly with that
 * distribution: nearest texel, no filtering. */
#include <math.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_path.h"
#include "scene/scene_internal.h"

#define PATH_MAX_LEN 4096

static bool colour_ok(rl_vec3 c)
{
    return rl_vfinite(c) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f;
}

rl_status rl_scene_set_environment(rl_scene *scene, const rl_environment_desc *desc)
{
    if (!scene || !desc)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_set_environment: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "set the environment");
    if (st != RL_OK)
        return st;
    float intensity = desc->intensity == 0.0f ? 1.0f : desc->intensity;
    if (!colour_ok(desc->color) || !isfinite(intensity) || intensity < 0.0f || !isfinite(desc->rotation_deg))
        return rl_error(RL_ERR_INVALID_ARG, "environment: colour and intensity must be finite and non-negative, "
                                            "rotation finite");
    rl_texture *map = NULL;
    if (desc->path) {
        char full[PATH_MAX_LEN];
        rl_path_join(rl_scene_base_dir(scene), desc->path, full, sizeof full);
        if ((st = rl_texture_load_linear(full, &map)) != RL_OK)
            return st;
        for (size_t i = 0; i < (size_t)map->width * (size_t)map->height; ++i) {
            rl_vec4 t = map->texels[i];
            if (!colour_ok(rl_v3(t.x, t.y, t.z))) {
                rl_texture_release(map);
                return rl_error(RL_ERR_PARSE, "%s: environment texel %zu is negative or not finite", full, i);
            }
        }
        if (map->width != 2 * map->height)
            rl_warn("%s: environment map is %dx%d, not 2:1; its width still spans 360 and its height "
                    "180 degrees, so its texels are stretched", full, map->width, map->height);
    }
    rl_texture_release((rl_texture *)scene->environment.map);
    scene->environment = (rl_environment){ .radiance = rl_scale(desc->color, intensity), .map = map,
                                           .rotation_deg = desc->rotation_deg };
    scene->has_environment = true;
    return RL_OK;
}

rl_vec2 rl_environment_uv(const rl_environment *env, rl_vec3 dir)
{
    float theta = acosf(rl_clampf(dir.y, -1.0f, 1.0f));
    float phi = atan2f(-dir.z, dir.x) - rl_radians(env->rotation_deg);
    float u = phi / (2.0f * RL_PI);
    u -= floorf(u);
    if (u >= 1.0f)
        u = 0.0f;
    return rl_v2(u, rl_clampf(theta / RL_PI, 0.0f, 1.0f));
}

rl_vec3 rl_environment_direction(const rl_environment *env, float u, float v)
{
    float theta = RL_PI * v, phi = 2.0f * RL_PI * u + rl_radians(env->rotation_deg);
    float st = sinf(theta);
    return rl_v3(st * cosf(phi), cosf(theta), -st * sinf(phi));
}

rl_vec3 rl_environment_radiance(const rl_environment *env, rl_vec3 dir)
{
    const rl_texture *m = env->map;
    if (!m)
        return env->radiance;
    rl_vec2 uv = rl_environment_uv(env, dir);
    int x = (int)(uv.x * (float)m->width), y = (int)(uv.y * (float)m->height);
    x = x < 0 ? 0 : (x >= m->width ? m->width - 1 : x);
    y = y < 0 ? 0 : (y >= m->height ? m->height - 1 : y);
    rl_vec4 t = m->texels[(size_t)y * (size_t)m->width + (size_t)x];
    return rl_mul(env->radiance, rl_v3(t.x, t.y, t.z));
}
