/* material.c: Phong materials with the ray-tracing coefficients of
 * Ullmann 2003, Sec. 3.1 (eq. 3.1-3.4): defaults, validation, scene table. */
#include "scene/scene_internal.h"
#include "core/error.h"

#include <string.h>

rl_material rl_material_default(void)
{
    rl_material m;
    memset(&m, 0, sizeof m);
    strcpy(m.name, "default");
    m.diffuse = rl_v3s(0.8f);
    m.shininess = 32.0f;
    m.ior = 1.5f;
    m.diffuse_texture = RL_NONE;
    return m;
}

static bool colour_ok(rl_vec3 c)
{
    return rl_vfinite(c) && c.x >= 0.0f && c.y >= 0.0f && c.z >= 0.0f;
}

static bool coefficient_ok(float k) { return isfinite(k) && k >= 0.0f && k <= 1.0f; }

rl_status rl_material_validate(const rl_material *m)
{
    if (!m)
        return rl_error(RL_ERR_INVALID_ARG, "material: NULL");
    if (!memchr(m->name, '\0', sizeof m->name))
        return rl_error(RL_ERR_INVALID_ARG, "material: name is not terminated");
    const char *n = m->name;
    if (!colour_ok(m->diffuse) || !colour_ok(m->specular) || !colour_ok(m->emission))
        return rl_error(RL_ERR_INVALID_ARG,
                        "material \"%s\": colours must be finite and non-negative", n);
    if (!isfinite(m->shininess) || m->shininess < 0.0f)
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": shininess %g", n,
                        (double)m->shininess);
    if (!coefficient_ok(m->reflectivity) || !coefficient_ok(m->transmissivity))
        return rl_error(RL_ERR_INVALID_ARG,
                        "material \"%s\": reflectivity and transmissivity must be in [0,1]", n);
    /* eq. 3.1: the local term keeps 1 - k_r - k_t, so the sum may not pass 1. */
    if (m->reflectivity + m->transmissivity > 1.0f)
        return rl_error(RL_ERR_INVALID_ARG,
                        "material \"%s\": reflectivity + transmissivity = %g > 1", n,
                        (double)(m->reflectivity + m->transmissivity));
    if (!isfinite(m->ior) || m->ior < 1.0f)
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": ior %g < 1", n, (double)m->ior);
    return RL_OK;
}

rl_status rl_scene_add_material(rl_scene *scene, const rl_material *m, uint32_t *id)
{
    if (!scene || !m)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_material: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "add a material");
    if (st != RL_OK)
        return st;
    if ((st = rl_material_validate(m)) != RL_OK)
        return st;
    if (m->diffuse_texture != RL_NONE && m->diffuse_texture >= scene->num_textures)
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": texture %u does not exist (%u textures)",
                        m->name, m->diffuse_texture, scene->num_textures);
    if ((st = rl_scene_reserve((void **)&scene->materials, &scene->cap_materials,
                               scene->num_materials + 1, sizeof *scene->materials)) != RL_OK)
        return st;
    scene->materials[scene->num_materials] = *m;
    if (id)
        *id = scene->num_materials;
    scene->num_materials++;
    return RL_OK;
}

uint32_t rl_scene_find_material(const rl_scene *scene, const char *name)
{
    if (!scene || !name)
        return RL_NONE;
    for (uint32_t i = 0; i < scene->num_materials; ++i)
        if (strcmp(scene->materials[i].name, name) == 0)
            return i;
    return RL_NONE;
}
