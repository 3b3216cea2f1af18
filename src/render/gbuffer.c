/* gbuffer.c: the geometry buffer of rl_gbuffer.h (Saito & Takahashi 1990)
 * as the path tracer uses it (Schröder 2017, Sec. 8.1): per pixel the first
 * surface through the pixel centre, either traced (rl_gbuffer_trace) or
 * from rasterized visibility (rl_gbuffer_raster: pt's primary=raster, Sec. 8.1).
 *
 * The raster path draws the scene's IDs with the shared rasterizer
 * (rl_raster_draw_scene, unlit), then intersects each pixel's centre ray
 * with the one triangle the rasterizer found there: no traversal. The
 * thesis reads position and normal straight from interpolated textures;
 * we compute them from the ray so that both paths give the same point for
 * the same triangle (up to the ray/plane rounding), which lets the tests
 * compare them and lets the path tracer start from either. Where the ray
 * grazes the triangle's edge the barycentrics are clamped onto it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "raster/scene_drawer.h"
#include "rl/rl_gbuffer.h"
#include "rl/rl_image.h"
#include "rl/rl_raster.h"
#include "scene/tri_plane.h"

static void clear_pixel(rl_gbuffer *g, size_t i)
{
    g->position[i] = rl_v3s(0.0f);
    g->normal[i] = rl_v3s(0.0f);
    g->albedo[i] = rl_v3s(0.0f);
    g->uv[i] = rl_v2(0.0f, 0.0f);
    g->depth[i] = INFINITY;
    g->object[i] = RL_ID_NONE;
    g->triangle[i] = RL_ID_NONE;
    g->material[i] = RL_NONE;
}

void rl_gbuffer_clear(rl_gbuffer *g)
{
    if (!g)
        return;
    size_t n = (size_t)g->width * (size_t)g->height;
    for (size_t i = 0; i < n; ++i)
        clear_pixel(g, i);
}

rl_status rl_gbuffer_create(int width, int height, rl_gbuffer **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gbuffer_create: out must not be NULL");
    *out = NULL;
    if (width < 1 || height < 1 || width > RL_IMAGE_MAX_SIZE || height > RL_IMAGE_MAX_SIZE)
        return rl_error(RL_ERR_LIMIT, "rl_gbuffer_create: size %dx%d outside 1..%d", width, height,
                        RL_IMAGE_MAX_SIZE);
    size_t n = (size_t)width * (size_t)height;
    rl_gbuffer *g = rl_calloc(1, sizeof *g);
    if (!g)
        return RL_ERR_OUT_OF_MEMORY;
    g->width = width;
    g->height = height;
    g->position = rl_calloc(n, sizeof *g->position);
    g->normal = rl_calloc(n, sizeof *g->normal);
    g->albedo = rl_calloc(n, sizeof *g->albedo);
    g->uv = rl_calloc(n, sizeof *g->uv);
    g->depth = rl_calloc(n, sizeof *g->depth);
    g->object = rl_calloc(n, sizeof *g->object);
    g->triangle = rl_calloc(n, sizeof *g->triangle);
    g->material = rl_calloc(n, sizeof *g->material);
    if (!g->position || !g->normal || !g->albedo || !g->uv || !g->depth || !g->object || !g->triangle ||
        !g->material) {
        rl_gbuffer_release(g);
        return RL_ERR_OUT_OF_MEMORY;
    }
    rl_gbuffer_clear(g);
    *out = g;
    return RL_OK;
}

void rl_gbuffer_release(rl_gbuffer *g)
{
    if (!g)
        return;
    free(g->position);
    free(g->normal);
    free(g->albedo);
    free(g->uv);
    free(g->depth);
    free(g->object);
    free(g->triangle);
    free(g->material);
    free(g);
}

/* Pixel i sees triangle tri at barycentrics (u, v), distance t along the
 * unit ray direction dir; forward is the view axis. */
static void fill_pixel(rl_gbuffer *g, size_t i, const rl_scene_data *d, rl_vec3 dir, rl_vec3 forward, uint32_t tri,
                       float t, float u, float v)
{
    const uint32_t *idx = &d->indices[3 * (size_t)tri];
    float w = 1.0f - u - v;
    g->position[i] = rl_add(rl_add(rl_scale(d->positions[idx[0]], w), rl_scale(d->positions[idx[1]], u)),
                            rl_scale(d->positions[idx[2]], v));
    rl_vec3 n = rl_add(rl_add(rl_scale(d->normals[idx[0]], w), rl_scale(d->normals[idx[1]], u)),
                       rl_scale(d->normals[idx[2]], v));
    n = rl_normalize(n);
    if (!(rl_length2(n) > 0.0f) || !rl_vfinite(n)) {
        rl_vec3 p0 = d->positions[idx[0]];
        n = rl_normalize(rl_cross(rl_sub(d->positions[idx[1]], p0), rl_sub(d->positions[idx[2]], p0)));
    }
    g->normal[i] = rl_dot(n, dir) > 0.0f ? rl_neg(n) : n;      /* towards the camera */
    rl_vec2 t0 = d->uvs[idx[0]], t1 = d->uvs[idx[1]], t2 = d->uvs[idx[2]];
    g->uv[i] = rl_v2(w * t0.x + u * t1.x + v * t2.x, w * t0.y + u * t1.y + v * t2.y);
    uint32_t mat = d->triangle_material[tri];
    const rl_material *m = &d->materials[mat];
    rl_vec3 kd = m->diffuse;
    if (m->diffuse_texture < d->num_textures && d->textures[m->diffuse_texture]) {
        rl_vec4 texel = rl_texture_sample(d->textures[m->diffuse_texture], g->uv[i]);
        kd = rl_mul(kd, rl_v3(texel.x, texel.y, texel.z));
    }
    g->albedo[i] = kd;
    g->depth[i] = t * rl_dot(dir, forward);
    g->object[i] = d->triangle_object[tri];
    g->triangle[i] = tri;
    g->material[i] = mat;
}

static rl_status check_args(const rl_gbuffer *g, const rl_camera *cam, const char *who, rl_camera *resolved)
{
    if (!g || !cam)
        return rl_error(RL_ERR_INVALID_ARG, "%s: NULL argument", who);
    *resolved = rl_camera_resolve(cam);
    rl_status st = rl_camera_validate(resolved);
    if (st != RL_OK)
        return st;
    if (resolved->width != g->width || resolved->height != g->height)
        return rl_error(RL_ERR_INVALID_ARG, "%s: G-buffer is %dx%d but the camera renders %dx%d", who, g->width,
                        g->height, resolved->width, resolved->height);
    return RL_OK;
}

rl_status rl_gbuffer_trace(rl_gbuffer *g, const rl_accel *accel, const rl_camera *cam)
{
    if (!g)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gbuffer_trace: NULL argument");
    return rl_gbuffer_trace_part(g, accel, cam, 0, 0, g->width, g->height);
}

rl_status rl_gbuffer_trace_part(rl_gbuffer *g, const rl_accel *accel, const rl_camera *cam, int x0, int y0,
                                int x1, int y1)
{
    rl_camera c;
    rl_status st = check_args(g, cam, "rl_gbuffer_trace", &c);
    if (st != RL_OK)
        return st;
    if (!accel)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gbuffer_trace: accel must not be NULL");
    if (x0 < 0 || y0 < 0 || x1 > g->width || y1 > g->height || x1 <= x0 || y1 <= y0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gbuffer_trace_part: [%d,%d)x[%d,%d) is empty or leaves the %dx%d "
                        "G-buffer", x0, x1, y0, y1, g->width, g->height);
    const rl_scene *scene = rl_accel_scene(accel);
    const rl_scene_data *d = scene ? rl_scene_get_data(scene) : NULL;
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_gbuffer_trace: the accel's scene is not committed");
    rl_camera_frame f = rl_camera_frame_make(&c);
    rl_vec3 forward = rl_neg(f.w);
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            size_t i = (size_t)y * g->width + x;
            rl_ray ray = rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f);
            rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
            if (rl_accel_intersect(accel, &ray, &hit) && hit.triangle < d->num_triangles)
                fill_pixel(g, i, d, ray.d, forward, hit.triangle, hit.t, hit.u, hit.v);
            else
                clear_pixel(g, i);
        }
    }
    return RL_OK;
}

/* Each pixel from the triangle drawn there: its centre ray cut with the
 * triangle's plane (no traversal). */
static void fill_from_ids(rl_gbuffer *g, const rl_scene_data *d, const rl_camera *c, const uint32_t *triangles)
{
    rl_camera_frame f = rl_camera_frame_make(c);
    rl_vec3 forward = rl_neg(f.w);
#pragma omp parallel for schedule(dynamic, 4)
    for (int y = 0; y < g->height; ++y) {
        for (int x = 0; x < g->width; ++x) {
            size_t i = (size_t)y * g->width + x;
            uint32_t tri = triangles[i];
            rl_ray ray = rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f);
            float t, u, v;
            if (tri < d->num_triangles && rl_tri_plane_hit(d, tri, &ray, &t, &u, &v))
                fill_pixel(g, i, d, ray.d, forward, tri, t, u, v);
            else
                clear_pixel(g, i);
        }
    }
}

rl_status rl_gbuffer_raster(rl_gbuffer *g, const rl_scene *scene, const rl_camera *cam)
{
    rl_camera c;
    rl_status st = check_args(g, cam, "rl_gbuffer_raster", &c);
    if (st != RL_OK)
        return st;
    const rl_scene_data *d = scene ? rl_scene_get_data(scene) : NULL;
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_gbuffer_raster: the scene must be committed");
    rl_image *ids = NULL;
    rl_raster *ras = NULL;
    st = rl_image_create(g->width, g->height, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &ids);
    if (st == RL_OK)
        st = rl_raster_create(NULL, &ras);
    if (st == RL_OK)
        st = rl_raster_set_camera(ras, ids, &c, d->bounds);
    if (st == RL_OK) {
        /* Visibility only: no lighting, as the ID pass of the hybrid renderers. */
        rl_drawer_desc desc = { .flags = RL_RASTER_NO_COLOR };
        st = rl_raster_draw_scene(ras, d, c.eye, &desc, NULL, NULL, NULL);
    }
    rl_raster_release(ras);
    if (st == RL_OK)
        fill_from_ids(g, d, &c, ids->triangle_id);
    rl_image_release(ids);
    return st;
}

rl_status rl_gbuffer_from_ids(rl_gbuffer *g, const rl_scene *scene, const rl_camera *cam, const uint32_t *triangles)
{
    rl_camera c;
    rl_status st = check_args(g, cam, "rl_gbuffer_from_ids", &c);
    if (st != RL_OK)
        return st;
    const rl_scene_data *d = scene ? rl_scene_get_data(scene) : NULL;
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_gbuffer_from_ids: the scene must be committed");
    if (!triangles)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gbuffer_from_ids: NULL triangle IDs");
    fill_from_ids(g, d, &c, triangles);
    return RL_OK;
}
