/* shadowmap.c: cube shadow maps (Williams 1978) for the path tracer's fast
 * shadow test (Schröder 2017, Sec. 8.6).
 *
 * Build: per light six 90-degree square depth maps, one per cube face
 * (+x, -x, +y, -y, +z, -z), rendered by renderlab's rasterizer from the
 * light's position: a point or spot light's position, a quad light's centre
 * (the thesis renders "from each light source"; for a quad this gives point
 * light shadows, its Fig. 20). A texel stores the rasterizer's depth, the
 * eye-space distance along the face's axis. All triangles are drawn, both
 * sides, except a quad light's own emitter (emissive triangles lying in the
 * light's parallelogram): the light sits on that surface and must not
 * shadow itself. The lights x 6 faces are independent jobs run in parallel
 * (OpenMP), each with a single-threaded rasterizer, so a build is
 * deterministic.
 *
 * Lookup (rl_shadowmap_visible): the face is the major axis of p - light;
 * the texel is p's projection moved by ((2 ju - 1), (2 jv - 1)) * pcf_radius
 * texels, the thesis' random PCF-like offset, clamped to the face. p is lit
 * when its depth d minus the bias is not behind the stored depth, with
 *     bias = bias_rel * d + slope_bias * texel(d) * tan(theta),
 * texel(d) = 2 d / size the texel footprint at depth d and theta the angle
 * between n and the direction to the light (the thesis' slope-scaled depth
 * bias against shadow acne; tan is capped at 1000 only to stay finite).
 * Grazing receivers thus get a large bias and may be lit next to an
 * occluder that shadows them, but their cosine factor makes them nearly
 * black anyway; a cap of 10 misclassified 3 % of the Cornell box (its
 * ceiling, 0.5 mm above the light, is seen edge-on). A point whose normal
 * n faces away from the light (n·l <= 0) is in shadow, as a shadow ray
 * started at p + n·eps would be: it leaves through p's own surface.
 *
 * Measured on the Cornell box (tests/raster/test_shadowmap.c): 99.6 % of
 * random surface points agree with an exact shadow ray; the rest lie within
 * a texel or two of silhouettes, where the jitter reaches the occluder. */
#include "raster/shadowmap_internal.h"
#include "scene/masks.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_raster.h"
#include "rl/rl_timer.h"

#define SM_MAX_SIZE 8192
#define SM_MAX_TAN 1000.0f       /* keeps the bias finite at cos(theta) -> 0 */

typedef struct sm_face {
    rl_vec3 s, u, axis;     /* right, up and view axis (the look-at rows) */
    rl_image *depth;        /* size x size, depth layer only */
} sm_face;

typedef struct sm_light {
    rl_vec3 position;
    sm_face faces[6];
} sm_light;

struct rl_shadowmap {
    int size;
    float bias, slope_bias, pcf_radius;
    uint32_t num_lights;
    sm_light *lights;
    double build_ms;
    size_t memory;
};

/* Cube face frames: axis, and an up that is not parallel to it. Right =
 * axis x up, so each face is an exact look-at frame of 0/±1 entries. */
void rl_shadowmap_face_frame(int face, rl_vec3 *s, rl_vec3 *u, rl_vec3 *axis)
{
    static const float axes[6][3] = { { 1, 0, 0 }, { -1, 0, 0 }, { 0, 1, 0 },
                                      { 0, -1, 0 }, { 0, 0, 1 }, { 0, 0, -1 } };
    static const float ups[6][3] = { { 0, 1, 0 }, { 0, 1, 0 }, { 0, 0, -1 },
                                     { 0, 0, 1 }, { 0, 1, 0 }, { 0, 1, 0 } };
    *axis = rl_v3(axes[face][0], axes[face][1], axes[face][2]);
    rl_vec3 up = rl_v3(ups[face][0], ups[face][1], ups[face][2]);
    *s = rl_cross(*axis, up);
    *u = rl_cross(*s, *axis);
}

static void face_frame(int face, sm_face *f) { rl_shadowmap_face_frame(face, &f->s, &f->u, &f->axis); }

/* gluLookAt rows (s, u, -axis) and a 90-degree square gluPerspective with
 * exact unit focal length, so that lookups can project without matrices. */
static void face_matrices(const sm_face *f, rl_vec3 eye, float z_near, float z_far,
                          rl_mat4 *view, rl_mat4 *proj)
{
    *view = rl_mat4_identity();
    const rl_vec3 rows[3] = { f->s, f->u, rl_neg(f->axis) };
    for (int r = 0; r < 3; ++r) {
        view->m[r][0] = rows[r].x;
        view->m[r][1] = rows[r].y;
        view->m[r][2] = rows[r].z;
        view->m[r][3] = -rl_dot(rows[r], eye);
    }
    memset(proj, 0, sizeof *proj);
    proj->m[0][0] = 1.0f;
    proj->m[1][1] = 1.0f;
    proj->m[2][2] = (z_far + z_near) / (z_near - z_far);
    proj->m[2][3] = 2.0f * z_far * z_near / (z_near - z_far);
    proj->m[3][2] = -1.0f;
}

/* Whether triangle t is part of quad light l's own emitter. */
static bool own_emitter(const rl_scene_data *d, const rl_light *l, uint32_t t, float tol)
{
    if (l->type != RL_LIGHT_QUAD)
        return false;
    rl_vec3 e = d->materials[d->triangle_material[t]].emission;
    if (!(e.x > 0.0f || e.y > 0.0f || e.z > 0.0f))
        return false;
    rl_vec3 n = rl_cross(l->edge_u, l->edge_v);
    float area = rl_length(n);
    if (!(area > 0.0f))
        return false;
    n = rl_scale(n, 1.0f / area);
    /* Parallelogram coordinates from the Gram matrix of the edges. */
    float uu = rl_dot(l->edge_u, l->edge_u), uv = rl_dot(l->edge_u, l->edge_v),
          vv = rl_dot(l->edge_v, l->edge_v), det = uu * vv - uv * uv;
    float slack = 1e-3f;
    for (int k = 0; k < 3; ++k) {
        rl_vec3 q = rl_sub(d->positions[d->indices[3 * t + k]], l->position);
        if (fabsf(rl_dot(q, n)) > tol)
            return false;
        float qu = rl_dot(q, l->edge_u), qv = rl_dot(q, l->edge_v);
        float s = (vv * qu - uv * qv) / det, r = (uu * qv - uv * qu) / det;
        if (s < -slack || s > 1.0f + slack || r < -slack || r > 1.0f + slack)
            return false;
    }
    return true;
}

rl_vec3 rl_shadowmap_light_point(const rl_light *l)
{
    if (l->type == RL_LIGHT_QUAD)
        return rl_add(l->position, rl_scale(rl_add(l->edge_u, l->edge_v), 0.5f));
    return l->position;
}

void rl_shadowmap_depth_range(const rl_scene_data *d, rl_vec3 eye, float *z_near, float *z_far)
{
    rl_vec3 ext = rl_aabb_extent(d->bounds);
    float diag = rl_length(ext);
    float far_d = 0.0f;
    for (int c = 0; c < 8; ++c) {
        rl_vec3 corner = rl_v3(c & 1 ? d->bounds.max.x : d->bounds.min.x,
                               c & 2 ? d->bounds.max.y : d->bounds.min.y,
                               c & 4 ? d->bounds.max.z : d->bounds.min.z);
        far_d = fmaxf(far_d, rl_length(rl_sub(corner, eye)));
    }
    *z_near = fmaxf(diag * 1e-5f, 1e-30f);
    *z_far = fmaxf(far_d * 1.01f, *z_near * 2.0f);
}

/* mask_texture, mask_cutoff: per drawn triangle, or NULL (no alpha masks). */
static rl_status render_face(const rl_scene_data *d, const uint32_t *indices, const uint32_t *mask_texture,
                             const float *mask_cutoff, uint32_t count, rl_vec3 eye, int size, sm_face *f)
{
    /* Near plane far below any sensible feature size (depth is recovered
     * from 1/w, so a small near costs no precision); far encloses the
     * scene. */
    float z_near, z_far;
    rl_shadowmap_depth_range(d, eye, &z_near, &z_far);
    rl_mat4 view, proj;
    face_matrices(f, eye, z_near, z_far, &view, &proj);
    rl_raster *r = NULL;
    rl_status s = rl_image_create(size, size, RL_LAYER_DEPTH, &f->depth);
    if (!s) s = rl_raster_create(&(rl_raster_desc){ .threads = 1 }, &r);
    if (!s) s = rl_raster_set_target(r, f->depth, &view, &proj);
    if (!s && count > 0) {
        rl_raster_batch batch = {
            .num_vertices = d->num_vertices,
            .positions = d->positions,
            .num_triangles = count,
            .indices = indices,
            .flags = RL_RASTER_NO_COLOR | RL_RASTER_NO_ID,
            /* Light passes through the holes of alpha masks, as rays do. */
            .uvs = mask_texture ? d->uvs : NULL,
            .textures = mask_texture ? d->textures : NULL,
            .mask_texture = mask_texture,
            .mask_cutoff = mask_cutoff,
        };
        s = rl_raster_draw(r, &batch, NULL);
    }
    rl_raster_release(r);
    return s;
}

rl_status rl_shadowmap_resolve_desc(const rl_shadowmap_desc *desc, const char *who, rl_shadowmap_desc *out)
{
    rl_shadowmap_desc p = desc ? *desc : (rl_shadowmap_desc){ 0 };
    if (p.size == 0) p.size = 1024;                /* Schröder 2017, Sec. 9.2 */
    if (p.bias == 0.0f) p.bias = 1e-3f;
    if (p.slope_bias == 0.0f) p.slope_bias = 2.0f;
    if (p.pcf_radius == 0.0f) p.pcf_radius = 1.0f;
    if (p.size < 1 || p.size > SM_MAX_SIZE)
        return rl_error(RL_ERR_INVALID_ARG, "%s: size %d outside 1..%d", who, p.size, SM_MAX_SIZE);
    if (!(p.bias >= 0.0f && p.bias < 1.0f) || !(p.slope_bias >= 0.0f && p.slope_bias < 1e4f) ||
        !(p.pcf_radius >= 0.0f && p.pcf_radius <= 64.0f))
        return rl_error(RL_ERR_INVALID_ARG, "%s: bias %g (0..1), slope_bias %g "
                        "(0..1e4) or pcf_radius %g (0..64) out of range", who, (double)p.bias,
                        (double)p.slope_bias, (double)p.pcf_radius);
    *out = p;
    return RL_OK;
}

rl_status rl_shadowmap_check_lights(const rl_scene_data *d, const char *who)
{
    for (uint32_t i = 0; i < d->num_lights; ++i)
        if (d->lights[i].type == RL_LIGHT_DIRECTIONAL)
            return rl_error(RL_ERR_UNSUPPORTED, "%s: light %u is directional; "
                            "cube shadow maps need a light position", who, i);
    return RL_OK;
}

/* The tolerance of own_emitter: the plane distance that still counts as on
 * the light, relative to the scene's size. */
static float emitter_tol(const rl_scene_data *d)
{
    return 1e-4f * fmaxf(rl_length(rl_aabb_extent(d->bounds)), 1e-30f);
}

bool rl_shadowmap_casts(const rl_scene_data *d, const rl_light *l, uint32_t t)
{
    return !own_emitter(d, l, t, emitter_tol(d));
}

rl_status rl_shadowmap_create(const rl_scene *scene, const rl_shadowmap_desc *desc,
                              rl_shadowmap **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_shadowmap_create: NULL argument");
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_shadowmap_create: scene is not committed");
    rl_shadowmap_desc p;
    rl_status checked = rl_shadowmap_resolve_desc(desc, "rl_shadowmap_create", &p);
    if (checked == RL_OK)
        checked = rl_shadowmap_check_lights(d, "rl_shadowmap_create");
    if (checked != RL_OK)
        return checked;

    rl_timer timer;
    rl_timer_start(&timer);
    rl_shadowmap *sm = rl_calloc(1, sizeof *sm);
    sm_light *lights = d->num_lights ? rl_calloc(d->num_lights, sizeof *lights) : NULL;
    uint32_t *indices = rl_alloc((size_t)d->num_triangles * 3 * sizeof *indices + 1);
    const bool masked = rl_data_has_masks(d);
    uint32_t *mask_texture = masked ? rl_alloc((size_t)d->num_triangles * sizeof *mask_texture + 1) : NULL;
    float *mask_cutoff = masked ? rl_alloc((size_t)d->num_triangles * sizeof *mask_cutoff + 1) : NULL;
    if (!sm || (d->num_lights && !lights) || !indices || (masked && (!mask_texture || !mask_cutoff))) {
        free(sm);
        free(lights);
        free(indices);
        free(mask_texture);
        free(mask_cutoff);
        return RL_ERR_OUT_OF_MEMORY;
    }
    sm->size = p.size;
    sm->bias = p.bias;
    sm->slope_bias = p.slope_bias;
    sm->pcf_radius = p.pcf_radius;
    sm->num_lights = d->num_lights;
    sm->lights = lights;
    sm->memory = sizeof *sm + d->num_lights * sizeof *lights;

    rl_status status = RL_OK;
    const float tol = emitter_tol(d);
    for (uint32_t li = 0; li < d->num_lights && !status; ++li) {
        const rl_light *l = &d->lights[li];
        lights[li].position = rl_shadowmap_light_point(l);
        /* Triangles to draw for this light (all but its own emitter). */
        uint32_t count = 0;
        for (uint32_t t = 0; t < d->num_triangles; ++t)
            if (!own_emitter(d, l, t, tol)) {
                memcpy(&indices[3 * count], &d->indices[3 * t], 3 * sizeof *indices);
                if (masked) {
                    mask_texture[count] = rl_material_mask(d, d->triangle_material[t]);
                    mask_cutoff[count] = d->materials[d->triangle_material[t]].alpha_cutoff;
                }
                ++count;
            }
        rl_status face_status[6] = { RL_OK };
        /* The six faces are independent (Sec. 8.6: one depth texture per
         * direction); each job owns its rasterizer and target. */
        #pragma omp parallel for schedule(dynamic, 1)
        for (int f = 0; f < 6; ++f) {
            face_frame(f, &lights[li].faces[f]);
            face_status[f] = render_face(d, indices, mask_texture, mask_cutoff, count, lights[li].position,
                                         p.size, &lights[li].faces[f]);
        }
        for (int f = 0; f < 6 && !status; ++f)
            if (face_status[f])
                status = rl_error(face_status[f], "rl_shadowmap_create: light %u, cube face %d: "
                                  "%s", li, f, rl_status_string(face_status[f]));
        sm->memory += 6 * (size_t)p.size * (size_t)p.size * sizeof(float);
    }
    free(indices);
    free(mask_texture);
    free(mask_cutoff);
    if (status) {
        rl_shadowmap_release(sm);
        return status;
    }
    sm->build_ms = rl_timer_ms(&timer);
    *out = sm;
    return RL_OK;
}

void rl_shadowmap_release(rl_shadowmap *sm)
{
    if (!sm)
        return;
    for (uint32_t i = 0; i < sm->num_lights; ++i)
        for (int f = 0; f < 6; ++f)
            rl_image_release(sm->lights[i].faces[f].depth);
    free(sm->lights);
    free(sm);
}

bool rl_shadowmap_visible(const rl_shadowmap *sm, uint32_t light, rl_vec3 p, rl_vec3 n,
                          float ju, float jv)
{
    if (!sm || light >= sm->num_lights)
        return false;
    const sm_light *l = &sm->lights[light];
    rl_vec3 d = rl_sub(p, l->position);
    float dist = rl_length(d);
    if (!(dist > 0.0f))
        return true;                        /* at the light itself */
    /* Back-facing receivers see nothing (a shadow ray from that side of the
     * surface would leave through the surface itself). */
    float n_len = rl_length(n);
    float cos_t = n_len > 0.0f ? -rl_dot(n, d) / (n_len * dist) : 1.0f;
    if (cos_t <= 0.0f)
        return false;
    /* Cube face: the major axis of p - light. */
    float ax = fabsf(d.x), ay = fabsf(d.y), az = fabsf(d.z);
    int face = ax >= ay && ax >= az ? (d.x < 0.0f) : ay >= az ? 2 + (d.y < 0.0f) : 4 + (d.z < 0.0f);
    const sm_face *f = &l->faces[face];
    float depth = rl_dot(d, f->axis);       /* >= dist / sqrt(3) > 0 */
    const int size = sm->size;
    float half = 0.5f * (float)size;
    /* Sec. 8.6: PCF-like random offset of the texture coordinates. */
    float px = (rl_dot(d, f->s) / depth + 1.0f) * half + (2.0f * ju - 1.0f) * sm->pcf_radius;
    float py = (1.0f - rl_dot(d, f->u) / depth) * half + (2.0f * jv - 1.0f) * sm->pcf_radius;
    int tx = (int)floorf(px), ty = (int)floorf(py);
    tx = tx < 0 ? 0 : (tx >= size ? size - 1 : tx);
    ty = ty < 0 ? 0 : (ty >= size ? size - 1 : ty);
    float stored = f->depth->depth[(size_t)ty * size + tx];
    /* Sec. 8.6: slope-scaled depth bias from the angle between the normal
     * and the light vector, plus a bias relative to the depth. */
    float sin_t = sqrtf(fmaxf(0.0f, 1.0f - cos_t * cos_t));
    float tan_t = sin_t < SM_MAX_TAN * cos_t ? sin_t / cos_t : SM_MAX_TAN;
    float texel = 2.0f * depth / (float)size;
    float bias = sm->bias * depth + sm->slope_bias * texel * tan_t;
    return depth - bias <= stored;
}

double rl_shadowmap_build_ms(const rl_shadowmap *sm) { return sm ? sm->build_ms : 0.0; }

size_t rl_shadowmap_memory(const rl_shadowmap *sm) { return sm ? sm->memory : 0; }
