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
    m.normal_texture = RL_NONE;
    m.normal_scale = 1.0f;
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
    if ((unsigned)m->bsdf >= RL_BSDF_COUNT || (unsigned)m->fresnel >= RL_FRESNEL_COUNT)
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": unknown bsdf (%d) or fresnel (%d)", n,
                        (int)m->bsdf, (int)m->fresnel);
    if (!coefficient_ok(m->roughness) || !coefficient_ok(m->metallic))
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": roughness and metallic must be in [0,1]", n);
    return RL_OK;
}

float rl_fresnel_schlick(float cos_i, float eta)
{
    if (!(eta > 0.0f))
        return 1.0f;
    float c = rl_clampf(cos_i, 0.0f, 1.0f);
    if (eta < 1.0f) {
        /* From the denser side Schlick's formula needs the angle on the
         * rarer side, which makes F the same for both directions through
         * the interface (Fresnel reflectance is reciprocal). */
        float sin2_t = (1.0f - c * c) / (eta * eta);
        if (sin2_t >= 1.0f)
            return 1.0f;      /* total internal reflection */
        c = sqrtf(1.0f - sin2_t);
    }
    float r0 = (eta - 1.0f) / (eta + 1.0f);
    r0 *= r0;
    float k = 1.0f - c, k2 = k * k;
    return r0 + (1.0f - r0) * k2 * k2 * k;
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
    if (m->normal_texture != RL_NONE && m->normal_texture >= scene->num_textures)
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": normal map %u does not exist (%u textures)",
                        m->name, m->normal_texture, scene->num_textures);
    if (!(m->alpha_cutoff >= 0.0f && m->alpha_cutoff <= 1.0f))
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": alpha cutoff %g not in [0, 1]", m->name,
                        (double)m->alpha_cutoff);
    if (!isfinite(m->normal_scale))
        return rl_error(RL_ERR_INVALID_ARG, "material \"%s\": normal scale is not finite", m->name);
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

/* Normal mapping (Blinn 1978's perturbed normals; the tangent-space
 * convention of glTF 2.0, "normalTexture"): the map stores a unit vector
 * in the frame (T, B, N) as (v + 1) / 2. Without stored tangents the frame
 * comes from the triangle: solving p1 - p0 = du1 T + dv1 B and
 * p2 - p0 = du2 T + dv2 B for T and B (the UV derivative of position, as in
 * pbrt's triangle dpdu), T made orthogonal to the shading normal, and B's
 * sign kept from the solve so mirrored UVs stay right. One frame per
 * triangle: smooth surfaces show faint facets in the bent normals, which
 * per-vertex tangents (MikkTSpace) would remove. */
rl_vec3 rl_shading_normal(const rl_scene_data *d, uint32_t tri, rl_vec3 ns, rl_vec2 uv)
{
    const rl_material *m = &d->materials[d->triangle_material[tri]];
    uint32_t tex = m->normal_texture;
    if (tex == RL_NONE || tex >= d->num_textures || !d->textures[tex])
        return ns;   /* untouched, bit for bit: images without maps stay the same */
    rl_vec3 n = rl_normalize(ns);
    if (!rl_vfinite(n))
        return ns;
    const uint32_t *idx = &d->indices[3 * (size_t)tri];
    rl_vec3 e1 = rl_sub(d->positions[idx[1]], d->positions[idx[0]]);
    rl_vec3 e2 = rl_sub(d->positions[idx[2]], d->positions[idx[0]]);
    rl_vec2 t0 = d->uvs[idx[0]], t1 = d->uvs[idx[1]], t2 = d->uvs[idx[2]];
    float du1 = t1.x - t0.x, dv1 = t1.y - t0.y, du2 = t2.x - t0.x, dv2 = t2.y - t0.y;
    float det = du1 * dv2 - du2 * dv1;
    if (!(fabsf(det) > 1e-20f))
        return n;
    float inv = 1.0f / det;
    rl_vec3 T = rl_scale(rl_sub(rl_scale(e1, dv2), rl_scale(e2, dv1)), inv);
    rl_vec3 B = rl_scale(rl_sub(rl_scale(e2, du1), rl_scale(e1, du2)), inv);
    T = rl_sub(T, rl_scale(n, rl_dot(n, T)));
    if (!(rl_length2(T) > 0.0f) || !rl_vfinite(T))
        return n;
    T = rl_normalize(T);
    rl_vec3 Bo = rl_cross(n, T);
    if (rl_dot(Bo, B) < 0.0f)
        Bo = rl_neg(Bo);
    rl_vec4 texel = rl_texture_sample(d->textures[tex], uv);
    float x = (2.0f * texel.x - 1.0f) * m->normal_scale, y = (2.0f * texel.y - 1.0f) * m->normal_scale;
    float z = 2.0f * texel.z - 1.0f;
    rl_vec3 bent = rl_add(rl_add(rl_scale(T, x), rl_scale(Bo, y)), rl_scale(n, z));
    return rl_length2(bent) > 0.0f && rl_vfinite(bent) ? rl_normalize(bent) : n;
}

bool rl_alpha_masked(const rl_scene_data *d, uint32_t tri, float u, float v)
{
    const rl_material *m = &d->materials[d->triangle_material[tri]];
    uint32_t tex = m->diffuse_texture;
    if (!(m->alpha_cutoff > 0.0f) || tex >= d->num_textures || !d->textures[tex])
        return false;
    const uint32_t *idx = &d->indices[3 * (size_t)tri];
    rl_vec2 t0 = d->uvs[idx[0]], t1 = d->uvs[idx[1]], t2 = d->uvs[idx[2]];
    float w = 1.0f - u - v;
    rl_vec2 uv = rl_v2(w * t0.x + u * t1.x + v * t2.x, w * t0.y + u * t1.y + v * t2.y);
    return rl_texture_sample(d->textures[tex], uv).w < m->alpha_cutoff;
}
