/* mesh.c: copying meshes into a scene. Validates indices and materials,
 * drops triangles with NaN/Inf vertices or zero area (counted, one warning per
 * mesh), keeps only referenced vertices, repairs bad normals/uvs and computes
 * area-weighted smooth normals where the caller gives none. */
#include "scene/scene_internal.h"
#include "core/error.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void rl_mesh_compute_normals(uint32_t num_vertices, const rl_vec3 *positions,
                             uint32_t num_triangles, const uint32_t *indices, rl_vec3 *normals)
{
    for (uint32_t v = 0; v < num_vertices; ++v)
        normals[v] = rl_v3s(0.0f);
    /* The unnormalised cross product is twice the area, so summing it weights
     * each face by its area. */
    for (uint32_t t = 0; t < num_triangles; ++t) {
        const uint32_t *i = indices + 3 * (size_t)t;
        rl_vec3 p0 = positions[i[0]], p1 = positions[i[1]], p2 = positions[i[2]];
        rl_vec3 n = rl_cross(rl_sub(p1, p0), rl_sub(p2, p0));
        for (int k = 0; k < 3; ++k)
            normals[i[k]] = rl_add(normals[i[k]], n);
    }
    for (uint32_t v = 0; v < num_vertices; ++v) {
        rl_vec3 n = rl_normalize(normals[v]);
        normals[v] = rl_length2(n) > 0.0f && rl_vfinite(n) ? n : rl_v3(0.0f, 0.0f, 1.0f);
    }
}

/* Zero area in the relative sense: sin(angle between the edges) below 1e-6,
 * computed in double so that large coordinates do not overflow. Repeated
 * indices give a zero edge and land here too. */
static bool is_degenerate(rl_vec3 p0, rl_vec3 p1, rl_vec3 p2)
{
    double e1[3] = { (double)p1.x - p0.x, (double)p1.y - p0.y, (double)p1.z - p0.z };
    double e2[3] = { (double)p2.x - p0.x, (double)p2.y - p0.y, (double)p2.z - p0.z };
    double c[3] = { e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2],
                    e1[0] * e2[1] - e1[1] * e2[0] };
    double c2 = c[0] * c[0] + c[1] * c[1] + c[2] * c[2];
    double l1 = e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2];
    double l2 = e2[0] * e2[0] + e2[1] * e2[1] + e2[2] * e2[2];
    return c2 <= 1e-12 * l1 * l2;
}

static rl_status check_desc(const rl_scene *scene, const rl_mesh_desc *d, const char *name)
{
    if (d->num_vertices > 0 && !d->positions)
        return rl_error(RL_ERR_INVALID_ARG, "mesh \"%s\": positions are NULL", name);
    if (d->num_triangles > 0 && !d->indices)
        return rl_error(RL_ERR_INVALID_ARG, "mesh \"%s\": indices are NULL", name);
    if (d->num_triangles > RL_SCENE_MAX_TRIANGLES)
        return rl_error(RL_ERR_LIMIT, "mesh \"%s\": %u triangles exceed the limit of %u", name,
                        d->num_triangles, RL_SCENE_MAX_TRIANGLES);
    for (uint32_t t = 0; t < d->num_triangles; ++t)
        for (int k = 0; k < 3; ++k) {
            uint32_t i = d->indices[3 * (size_t)t + k];
            if (i >= d->num_vertices)
                return rl_error(RL_ERR_INVALID_ARG,
                                "mesh \"%s\": triangle %u index %u out of range (%u vertices)",
                                name, t, i, d->num_vertices);
        }
    if (d->triangle_materials) {
        for (uint32_t t = 0; t < d->num_triangles; ++t)
            if (d->triangle_materials[t] >= scene->num_materials)
                return rl_error(RL_ERR_INVALID_ARG,
                                "mesh \"%s\": triangle %u material %u does not exist (%u materials)",
                                name, t, d->triangle_materials[t], scene->num_materials);
    } else if (d->material >= scene->num_materials) {
        return rl_error(RL_ERR_INVALID_ARG, "mesh \"%s\": material %u does not exist (%u materials)",
                        name, d->material, scene->num_materials);
    }
    return RL_OK;
}

static void mesh_free(rl_mesh *m)
{
    free(m->name);
    free(m->positions);
    free(m->normals);
    free(m->uvs);
    free(m->indices);
    free(m->materials);
    memset(m, 0, sizeof *m);
}

/* Copies the kept triangles and their vertices (in original order) into m. */
static rl_status copy_geometry(const rl_mesh_desc *d, const uint8_t *keep, uint32_t kept,
                               rl_mesh *m, uint32_t *bad_normals, uint32_t *bad_uvs)
{
    uint32_t *remap = rl_alloc(((size_t)d->num_vertices + 1) * sizeof *remap);
    if (!remap)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t v = 0; v < d->num_vertices; ++v)
        remap[v] = RL_NONE;
    for (uint32_t t = 0; t < d->num_triangles; ++t)
        if (keep[t])
            for (int k = 0; k < 3; ++k)
                remap[d->indices[3 * (size_t)t + k]] = 0;
    uint32_t nv = 0;
    for (uint32_t v = 0; v < d->num_vertices; ++v)
        if (remap[v] == 0)
            remap[v] = nv++;
        else
            remap[v] = RL_NONE;

    m->num_vertices = nv;
    m->num_triangles = kept;
    m->positions = rl_calloc((size_t)nv + 1, sizeof *m->positions);
    m->normals = rl_calloc((size_t)nv + 1, sizeof *m->normals);
    m->uvs = rl_calloc((size_t)nv + 1, sizeof *m->uvs);
    m->indices = rl_calloc(3 * (size_t)kept + 1, sizeof *m->indices);
    m->materials = rl_calloc((size_t)kept + 1, sizeof *m->materials);
    if (!m->positions || !m->normals || !m->uvs || !m->indices || !m->materials) {
        free(remap);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t v = 0; v < d->num_vertices; ++v) {
        uint32_t o = remap[v];
        if (o == RL_NONE)
            continue;
        m->positions[o] = d->positions[v];
        if (d->uvs) {
            rl_vec2 uv = d->uvs[v];
            bool ok = isfinite(uv.x) && isfinite(uv.y);
            m->uvs[o] = ok ? uv : rl_v2(0.0f, 0.0f);
            *bad_uvs += !ok;
        }
    }
    uint32_t o = 0;
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        if (!keep[t])
            continue;
        for (int k = 0; k < 3; ++k)
            m->indices[3 * (size_t)o + k] = remap[d->indices[3 * (size_t)t + k]];
        m->materials[o] = d->triangle_materials ? d->triangle_materials[t] : d->material;
        ++o;
    }
    rl_mesh_compute_normals(nv, m->positions, kept, m->indices, m->normals);
    /* Caller normals win where they are usable; zero or NaN ones keep the
     * computed normal so that shading never sees a non-unit vector. */
    if (d->normals) {
        for (uint32_t v = 0; v < d->num_vertices; ++v) {
            uint32_t r = remap[v];
            if (r == RL_NONE)
                continue;
            rl_vec3 n = d->normals[v];
            if (!rl_vfinite(n)) {
                ++*bad_normals;
                continue;
            }
            n = rl_normalize(n);
            if (rl_length2(n) > 0.0f && rl_vfinite(n))
                m->normals[r] = n;
        }
    }
    free(remap);
    return RL_OK;
}

rl_status rl_scene_add_mesh(rl_scene *scene, const rl_mesh_desc *desc, uint32_t *mesh_id)
{
    if (!scene || !desc)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_add_mesh: NULL argument");
    rl_status st = rl_scene_check_mutable(scene, "add a mesh");
    if (st != RL_OK)
        return st;
    char fallback[32];
    snprintf(fallback, sizeof fallback, "mesh%u", scene->num_meshes);
    const char *name = desc->name && desc->name[0] ? desc->name : fallback;
    if ((st = check_desc(scene, desc, name)) != RL_OK)
        return st;
    if ((st = rl_scene_reserve((void **)&scene->meshes, &scene->cap_meshes, scene->num_meshes + 1,
                               sizeof *scene->meshes)) != RL_OK)
        return st;

    uint8_t *keep = rl_calloc((size_t)desc->num_triangles + 1, 1);
    if (!keep)
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t kept = 0, nonfinite = 0, degenerate = 0;
    for (uint32_t t = 0; t < desc->num_triangles; ++t) {
        const uint32_t *i = desc->indices + 3 * (size_t)t;
        rl_vec3 p0 = desc->positions[i[0]], p1 = desc->positions[i[1]], p2 = desc->positions[i[2]];
        if (!rl_vfinite(p0) || !rl_vfinite(p1) || !rl_vfinite(p2))
            ++nonfinite;
        else if (is_degenerate(p0, p1, p2))
            ++degenerate;
        else {
            keep[t] = 1;
            ++kept;
        }
    }

    rl_mesh m;
    memset(&m, 0, sizeof m);
    uint32_t bad_normals = 0, bad_uvs = 0;
    m.name = rl_strdup(name);
    st = m.name ? copy_geometry(desc, keep, kept, &m, &bad_normals, &bad_uvs) : RL_ERR_OUT_OF_MEMORY;
    free(keep);
    if (st != RL_OK) {
        mesh_free(&m);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "mesh \"%s\": out of memory", name);
    }

    if (desc->num_triangles == 0)
        rl_warn("mesh \"%s\": has no triangles", name);
    if ((degenerate || nonfinite) && !scene->quiet_mesh_warnings)
        rl_warn("mesh \"%s\": dropped %u degenerate and %u non-finite triangles", name, degenerate,
                nonfinite);
    if (bad_normals)
        rl_warn("mesh \"%s\": %u non-finite normals replaced by computed ones", name, bad_normals);
    if (bad_uvs)
        rl_warn("mesh \"%s\": %u non-finite uvs replaced by (0,0)", name, bad_uvs);
    scene->dropped_degenerate += degenerate;
    scene->dropped_nonfinite += nonfinite;
    scene->meshes[scene->num_meshes] = m;
    if (mesh_id)
        *mesh_id = scene->num_meshes;
    scene->num_meshes++;
    return RL_OK;
}
