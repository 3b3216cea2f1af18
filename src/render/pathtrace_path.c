/* pathtrace_path.c: one camera path of the path tracer "pt" (Schröder 2017,
 * Sec. 3.3 and 6.4): Trace finds the next surface through the chosen
 * backend; at the surface Russian roulette over the material's coefficients
 * picks the mirror ray (k_r), the refracted ray (k_t, Snell without Fresnel
 * as in trace.c) or the Phong BRDF (the rest); only in the BRDF case does
 * Shade gather the lights with shadow rays (next-event estimation) and the
 * Phong sampling (pathtrace_bsdf.c) choose the next direction. The path
 * ends on a miss, where it gathers the option background as the radiance
 * of a uniform environment (black by default; no light samples it, so
 * counting it on every escape is unbiased), after max_depth interactions
 * behind the camera hit, or by Russian roulette on the throughput.
 *
 * Shade (Sec. 6.4.2, 6.3): per light and BRDF vertex
 *  - point / spot / directional: one hard shadow ray, f E cos(theta_R) with
 *    E from light_eval.h (colour intensity / d^2, spot cone);
 *  - quad: light_samples points uniform on the parallelogram, each
 *    f L_e A cos(theta_E) cos(theta_R) / (d^2 light_samples): for a
 *    Lambertian f = k_d / pi this is eq. 7 times the surface colour.
 *
 * Emission rule (no double counting): an emissive surface adds its
 * emission when the path reached it from the camera or by a mirror or
 * refraction event. After a BRDF bounce it adds it only if NEE does not
 * also sample it: a surface is "covered" when it lies in a quad light's
 * plane and inside its parallelogram (pathtrace_backend.c; the builtin
 * cornell box has such an emissive quad mesh with an RL_LIGHT_QUAD on it).
 * Covered surfaces emit on the quad's emitting side only, as the quad light
 * does; uncovered ones emit on both sides on every hit (as trace.c).
 *
 * Russian roulette (Sec. 3.2.4): from the rr_depth-th bounce on, a path
 * survives with q = min(1, max throughput component) and its throughput is
 * divided by q: unbiased.
 *
 * Line Space backends: ls-pnmt returns a stored surface (position, normal,
 * material, uv; no triangle) which is shaded like a hit; ls-preillum
 * returns the stored direct light of the first surface along a secondary
 * ray, which is added with the throughput and ends the path (Sec. 7.4).
 * Both start one voxel diagonal away from the surface a ray leaves (the
 * thesis' voxel offset against self-illumination, Sec. 12.1-12.2, Fig. 19, 21):
 * occluders closer than that are missed, as the thesis reports.
 *
 * With mis=on (issue 37; docs/path-tracing.md) next-event estimation
 * instead takes light_samples lights chosen by power (pathtrace_lights.c),
 * emissive triangles included, and weights each light sample and each BSDF
 * ray that hits an emitter by the power heuristic (Veach 1997).
 *
 * A scene environment (issue 37) replaces the background: escaping rays
 * see its radiance, and every BRDF vertex also samples it by its
 * importance (pathtrace_env.c), both weighted by the power heuristic,
 * whatever the mis option says (the environment is new, no thesis image
 * depends on it). Its sample takes one more slot at the end of a vertex's
 * block, only in scenes that have an environment.
 *
 * Random numbers come from the pixel's sampler only (pathtrace_sampler.c),
 * in an order, or at slots, that do not depend on which shadow rays are
 * traced, so exact backends give the same image. */
#include <math.h>
#include <string.h>

#include "scene/light_eval.h"
#include "render/pathtrace_internal.h"

#define SHADOW_T_SHRINK 1e-4f     /* stop feelers short of the light itself */
#define PREILLUM_QUAD_SAMPLES 16  /* points per quad light for a stored value */

static rl_vec3 offset_origin(const pt_ctx *ctx, const pt_surface *s, rl_vec3 dir)
{
    float side = rl_dot(dir, s->ng) >= 0.0f ? 1.0f : -1.0f;
    return rl_madd(s->p, s->ng, side * ctx->b->eps);
}

static rl_vec3 textured_kd(const rl_scene_data *d, const rl_material *m, rl_vec2 uv)
{
    rl_vec3 kd = m->diffuse;
    uint32_t tex = m->diffuse_texture;
    if (tex < d->num_textures && d->textures[tex]) {
        rl_vec4 texel = rl_texture_sample(d->textures[tex], uv);
        kd = rl_mul(kd, rl_v3(texel.x, texel.y, texel.z));
    }
    return kd;
}

void rl_pt_surface_finish(const rl_scene_data *d, uint32_t tri, rl_vec3 p, rl_vec3 ns, rl_vec2 uv, rl_vec3 v,
                          pt_surface *s)
{
    const uint32_t *idx = &d->indices[3 * (size_t)tri];
    rl_vec3 p0 = d->positions[idx[0]], p1 = d->positions[idx[1]], p2 = d->positions[idx[2]];
    rl_vec3 ng = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
    const rl_material *m = &d->materials[d->triangle_material[tri]];
    /* rl_shading_normal returns ns untouched, bit for bit, without a normal
     * map: the test here saves the call at most hits. */
    if (m->normal_texture < d->num_textures)
        ns = rl_shading_normal(d, tri, ns, uv);
    ns = rl_normalize(ns);
    if (!(rl_length2(ns) > 0.0f) || !rl_vfinite(ns))
        ns = ng;
    s->p = p;
    s->v = v;
    s->front = rl_dot(ng, v) > 0.0f;
    s->ng = s->front ? ng : rl_neg(ng);
    s->ns = rl_dot(ns, v) < 0.0f ? rl_neg(ns) : ns;
    s->m = m;
    s->uv = uv;
    s->kd = textured_kd(d, m, uv);
    s->tri = tri;
    s->ggx_ms = false;             /* the renderer's option: set where the path uses s */
    s->lambert = rl_pt_surface_lambert(s);
}

bool rl_pt_surface_at_hit(const rl_scene_data *d, const rl_hit *hit, rl_vec3 o, rl_vec3 dir, pt_surface *s)
{
    (void)o;
    if (hit->triangle >= d->num_triangles)
        return false;
    const uint32_t *idx = &d->indices[3 * (size_t)hit->triangle];
    float u = hit->u, v = hit->v, w = 1.0f - u - v;
    /* The point from the barycentrics, as trace.c, so every exact backend
     * that reports the same (triangle, u, v) shades the same point. */
    rl_vec3 p = rl_add(rl_add(rl_scale(d->positions[idx[0]], w), rl_scale(d->positions[idx[1]], u)),
                       rl_scale(d->positions[idx[2]], v));
    rl_vec3 ns = rl_add(rl_add(rl_scale(d->normals[idx[0]], w), rl_scale(d->normals[idx[1]], u)),
                        rl_scale(d->normals[idx[2]], v));
    /* The texture coordinates only where a texture reads them (a diffuse
     * or a normal map): three more vertex loads and six products at every
     * hit otherwise. */
    rl_vec2 uv = rl_v2(0.0f, 0.0f);
    const rl_material *m = &d->materials[d->triangle_material[hit->triangle]];
    if (m->diffuse_texture < d->num_textures || m->normal_texture < d->num_textures) {
        rl_vec2 t0 = d->uvs[idx[0]], t1 = d->uvs[idx[1]], t2 = d->uvs[idx[2]];
        uv = rl_v2(w * t0.x + u * t1.x + v * t2.x, w * t0.y + u * t1.y + v * t2.y);
    }
    rl_pt_surface_finish(d, hit->triangle, p, ns, uv, rl_neg(rl_normalize(dir)), s);
    return true;
}

/* A PNMT record (Sec. 7.2) as a surface: only the stored shading normal is
 * known, so it serves as the geometric one too. */
static bool surface_of_record(const rl_scene_data *d, const rl_ls_surface *r, rl_vec3 v, pt_surface *s)
{
    if (r->material >= d->num_materials || !rl_vfinite(r->p))
        return false;
    rl_vec3 n = rl_normalize(r->n);
    if (!(rl_length2(n) > 0.0f) || !rl_vfinite(n))
        n = v;
    bool faces = rl_dot(n, v) >= 0.0f;
    s->p = r->p;
    s->v = v;
    s->front = faces;
    s->ns = s->ng = faces ? n : rl_neg(n);
    s->m = &d->materials[r->material];
    s->uv = r->uv;
    s->kd = textured_kd(d, s->m, r->uv);
    s->tri = RL_ID_NONE;
    s->ggx_ms = false;
    s->lambert = rl_pt_surface_lambert(s);
    return true;
}

bool rl_pt_closest(const pt_ctx *ctx, rl_pt_backend backend, rl_ray *ray, pt_surface *s, pt_counters *c)
{
    const pt_backends *b = ctx->b;
    c->trace_q[backend]++;
    rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
    switch (backend) {
    case RL_PT_BACKEND_BVH:
    case RL_PT_BACKEND_GRID:
    case RL_PT_BACKEND_EMBREE:
        if (!rl_accel_intersect(b->exact[backend], ray, &hit))
            return false;
        return rl_pt_surface_at_hit(ctx->data, &hit, ray->o, ray->d, s);
    case RL_PT_BACKEND_LS_CANDIDATES:
        if (!rl_linespace_intersect(b->ls, ray, &hit))
            return false;
        return rl_pt_surface_at_hit(ctx->data, &hit, ray->o, ray->d, s);
    case RL_PT_BACKEND_LS_SCENE:
        if (!rl_ls_scene_intersect(b->lss, ray, &hit))
            return false;
        return rl_pt_surface_at_hit(ctx->data, &hit, ray->o, ray->d, s);
    case RL_PT_BACKEND_LS_OBJECT:
        if (!rl_ls_objects_intersect(b->lso, ray, &hit))
            return false;
        return rl_pt_surface_at_hit(ctx->data, &hit, ray->o, ray->d, s);
    case RL_PT_BACKEND_LS_PNMT: {
        rl_ls_surface rec;
        ray->t_min = rl_maxf(ray->t_min, b->ls_start);
        if (!rl_linespace_pnmt_intersect(b->ls, ray, &rec))
            return false;
        return surface_of_record(ctx->data, &rec, rl_neg(rl_normalize(ray->d)), s);
    }
    default:
        return false;             /* preillum and shadow maps find no surface */
    }
}

/* Shadow test from s towards unit l over dist (light index for the shadow
 * maps); true if the light is visible. ju, jv: the shadow-map jitter. */
static bool visible(const pt_ctx *ctx, const pt_surface *s, rl_vec3 l, float dist, uint32_t light, float ju,
                    float jv, pt_counters *c)
{
    const pt_backends *b = ctx->b;
    rl_pt_backend k = ctx->shadow;
    c->shadow_q[k]++;
    if (k == RL_PT_BACKEND_SHADOWMAP)
        return rl_shadowmap_visible(b->sm, light, s->p, s->ng, ju, jv);
    c->rays[RL_RAY_SHADOW]++;
    rl_ray ray = { offset_origin(ctx, s, l), 0.0f, l, INFINITY };
    if (!isinf(dist)) {
        /* Aim from the offset origin at the light point itself: the ray
         * along l from there would end eps beyond the light's plane when
         * it leaves the surface at a grazing angle to that plane, and the
         * light's own emissive mesh then shadowed it (issue 37: a floor
         * 4 m wide under a lamp mesh went black). */
        rl_vec3 to = rl_sub(rl_madd(s->p, l, dist), ray.o);
        float len = rl_length(to);
        if (len > 0.0f)
            ray.d = rl_scale(to, 1.0f / len);
        ray.t_max = len * (1.0f - SHADOW_T_SHRINK);
    }
    switch (k) {
    case RL_PT_BACKEND_BVH:
    case RL_PT_BACKEND_GRID:
    case RL_PT_BACKEND_EMBREE:
        return !rl_accel_occluded(b->exact[k], &ray);
    case RL_PT_BACKEND_LS_CANDIDATES:
        return !rl_linespace_occluded(b->ls, &ray);
    case RL_PT_BACKEND_LS_SCENE:
        return !rl_ls_scene_occluded(b->lss, &ray);
    case RL_PT_BACKEND_LS_OBJECT:
        return !rl_ls_objects_occluded(b->lso, &ray);
    case RL_PT_BACKEND_LS_PNMT:
        /* Voxel offset at the light's end always (its voxel holds the lamp
         * and what it is mounted on, which no stored point can tell apart
         * from an occluder), at the surface's with ls_origin=offset
         * (pathtrace_backend.c). */
        ray.t_min = rl_maxf(ray.t_min, b->ls_start);
        ray.t_max -= b->ls_offset;
        return !(ray.t_min < ray.t_max && rl_linespace_pnmt_occluded(b->ls, &ray));
    case RL_PT_BACKEND_LS_PREILLUM: {
        /* The pre-illuminated Line Space knows the first stored surface
         * along the ray and its distance: occluded if one lies before the
         * light. */
        ray.t_min = rl_maxf(ray.t_min, b->ls_start);
        ray.t_max -= b->ls_offset;
        return !(ray.t_min < ray.t_max && rl_linespace_preillum_occluded(b->ls, &ray));
    }
    default:
        return true;
    }
}

/* Shade (Sec. 6.4.2): the light of all lights reflected at s towards s->v
 * (mis=off, the thesis: every light, light_samples points per quad). */
static rl_vec3 direct_light(const pt_ctx *ctx, const pt_surface *s, pt_sampler *sp, uint32_t base, pt_counters *c)
{
    const rl_scene_data *d = ctx->data;
    bool jitter = ctx->shadow == RL_PT_BACKEND_SHADOWMAP;
    rl_vec3 sum = rl_v3s(0.0f);
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        uint32_t light_base = base + PT_SLOTS_VERTEX + PT_SLOTS_LIGHT * i * (uint32_t)ctx->light_samples;
        if (L->type == RL_LIGHT_QUAD) {
            float area = ctx->b->lights.light_area[i];
            if (!(area > 0.0f))
                continue;
            rl_vec3 nq = ctx->b->lights.light_normal[i];
            int n = ctx->light_samples;
            rl_vec3 le = rl_scale(L->color, L->intensity * area / (float)n);
            for (int k = 0; k < n; ++k) {
                /* Sec. 6.3: a random point P_rnd on the light. Both numbers
                 * are drawn before any test, so the sequence does not
                 * depend on the outcome. */
                uint32_t slot = light_base + PT_SLOTS_LIGHT * (uint32_t)k;
                rl_pt_sampler_seek(sp, slot + PT_SLOT_LIGHT_POINT);
                rl_vec2 x = rl_pt_sample_2d(sp);
                rl_pt_sampler_seek(sp, slot + PT_SLOT_LIGHT_JITTER);
                rl_vec2 j = jitter ? rl_pt_sample_2d(sp) : rl_v2(0.0f, 0.0f);
                rl_vec3 q = rl_add(L->position, rl_add(rl_scale(L->edge_u, x.x), rl_scale(L->edge_v, x.y)));
                rl_vec3 to = rl_sub(q, s->p);
                float d2 = rl_length2(to);
                if (!(d2 > 0.0f))
                    continue;
                float dist = sqrtf(d2);
                rl_vec3 l = rl_scale(to, 1.0f / dist);
                float cos_e = -rl_dot(nq, l), cos_r = rl_dot(s->ns, l);
                if (cos_e <= 0.0f || cos_r <= 0.0f || !visible(ctx, s, l, dist, i, j.x, j.y, c))
                    continue;
                rl_vec3 f = rl_pt_bsdf_f(s, l);
                sum = rl_add(sum, rl_mul(f, rl_scale(le, cos_e * cos_r / d2)));   /* eq. 7 */
            }
            continue;
        }
        rl_pt_sampler_seek(sp, light_base + PT_SLOT_LIGHT_JITTER);
        rl_vec2 j = jitter ? rl_pt_sample_2d(sp) : rl_v2(0.0f, 0.0f);
        rl_vec3 E, l;
        float dist;
        if (!rl_light_eval_delta(L, s->p, &E, &l, &dist))
            continue;
        float cos_r = rl_dot(s->ns, l);
        if (cos_r <= 0.0f || !visible(ctx, s, l, dist, i, j.x, j.y, c))
            continue;
        sum = rl_add(sum, rl_mul(rl_pt_bsdf_f(s, l), rl_scale(E, cos_r)));
    }
    return sum;
}

/* Power heuristic with beta = 2 (Veach 1997, Sec. 9.2.4) for the strategy
 * whose pdf times sample count is a, against b; written as a ratio so that
 * a pdf that overflows at a grazing light still gives 0 or 1. */
static float power_heuristic(float a, float b)
{
    if (!(a > 0.0f))
        return 0.0f;
    float r = b / a;
    return 1.0f / (1.0f + r * r);
}

/* The pdf, in solid angle at s, with which the BSDF strategy produces wi:
 * the Phong or GGX mixture, zero below the geometric surface where
 * rl_pt_bsdf_sample refuses directions. */
static float bsdf_pdf(const pt_surface *s, rl_vec3 wi)
{
    return rl_dot(s->ng, wi) > 0.0f ? rl_pt_bsdf_density(s, wi) : 0.0f;
}

/* Next-event estimation with mis=on: light_samples lights chosen by power
 * (pathtrace_lights.c), a uniform point on an area light, and the power
 * heuristic against the BSDF sample that follows (bsdf_follows; at the last
 * vertex none does, and the light sample keeps the full weight). Delta
 * lights cannot be hit and keep the full weight too. */
static rl_vec3 direct_light_mis(const pt_ctx *ctx, const pt_surface *s, pt_sampler *sp, uint32_t base,
                                bool bsdf_follows, pt_counters *c)
{
    const rl_scene_data *d = ctx->data;
    const pt_lights *lt = &ctx->b->lights;
    if (lt->count == 0)
        return rl_v3s(0.0f);
    bool jitter = ctx->shadow == RL_PT_BACKEND_SHADOWMAP;
    int n = ctx->light_samples;
    rl_vec3 sum = rl_v3s(0.0f);
    for (int k = 0; k < n; ++k) {
        uint32_t slot = base + PT_SLOTS_VERTEX + PT_SLOTS_LIGHT * (uint32_t)k;
        rl_pt_sampler_seek(sp, slot + PT_SLOT_LIGHT_PICK);
        float u_pick = lt->count > 1 ? rl_pt_sample_1d(sp) : 0.0f;
        rl_pt_sampler_seek(sp, slot + PT_SLOT_LIGHT_POINT);
        rl_vec2 x = rl_pt_sample_2d(sp);
        rl_pt_sampler_seek(sp, slot + PT_SLOT_LIGHT_JITTER);
        rl_vec2 j = jitter ? rl_pt_sample_2d(sp) : rl_v2(0.0f, 0.0f);
        uint32_t src = lt->source[rl_pt_lights_pick(lt, u_pick)];
        rl_vec3 q, n_e, le;
        float area, pmf, p_sa = 0.0f;   /* p_sa: the density in solid angle where sampled so */
        bool hittable;
        if (src < d->num_lights) {
            const rl_light *L = &d->lights[src];
            pmf = lt->light_pmf[src];
            if (L->type != RL_LIGHT_QUAD) {
                rl_vec3 E, l;
                float dist;
                if (!rl_light_eval_delta(L, s->p, &E, &l, &dist))
                    continue;
                float cos_r = rl_dot(s->ns, l);
                if (cos_r <= 0.0f || !visible(ctx, s, l, dist, src, j.x, j.y, c))
                    continue;
                sum = rl_add(sum, rl_mul(rl_pt_bsdf_f(s, l), rl_scale(E, cos_r / (pmf * (float)n))));
                continue;
            }
            n_e = lt->light_normal[src];
            area = lt->light_area[src];
            pt_sph_rect rect;
            if (ctx->quad_solid_angle && rl_pt_sph_rect_init(&rect, L, s->p)) {
                q = rl_pt_sph_rect_sample(&rect, x.x, x.y);
                p_sa = pmf / (float)rect.S;
            } else {
                q = rl_add(L->position, rl_add(rl_scale(L->edge_u, x.x), rl_scale(L->edge_v, x.y)));
            }
            le = rl_scale(L->color, L->intensity);
            hittable = ctx->mis_hits && lt->light_hittable[src];
        } else {
            if (!ctx->tri_lights)
                continue;             /* counted where rays hit it (emission rule) */
            uint32_t t = src - d->num_lights;
            const uint32_t *idx = &d->indices[3 * (size_t)t];
            pmf = lt->tri_pmf[t];
            area = rl_pt_triangle_area(d, t, &n_e);
            /* Uniform on the triangle: barycentrics (1 - sqrt(u), v sqrt(u)). */
            float r = sqrtf(x.x), b1 = x.y * r, b0 = 1.0f - r;
            rl_vec3 p0 = d->positions[idx[0]], p1 = d->positions[idx[1]], p2 = d->positions[idx[2]];
            q = rl_add(rl_add(rl_scale(p0, b0), rl_scale(p1, b1)), rl_scale(p2, 1.0f - b0 - b1));
            le = d->materials[d->triangle_material[t]].emission;
            hittable = true;
        }
        rl_vec3 to = rl_sub(q, s->p);
        float d2 = rl_length2(to);
        if (!(d2 > 0.0f))
            continue;
        float dist = sqrtf(d2);
        rl_vec3 l = rl_scale(to, 1.0f / dist);
        /* Quads emit on their front only; uncovered triangles on both sides. */
        float cos_e = src < d->num_lights ? -rl_dot(n_e, l) : fabsf(rl_dot(n_e, l));
        float cos_r = rl_dot(s->ns, l);
        if (cos_e <= 0.0f || cos_r <= 0.0f || !visible(ctx, s, l, dist, src < d->num_lights ? src : 0, j.x, j.y, c))
            continue;
        float p_light = p_sa > 0.0f ? p_sa : pmf * d2 / (area * cos_e);   /* solid angle at s */
        float w = bsdf_follows && hittable ? power_heuristic((float)n * p_light, bsdf_pdf(s, l)) : 1.0f;
        rl_vec3 f = rl_pt_bsdf_f(s, l);
        sum = rl_add(sum, rl_mul(f, rl_scale(le, w * cos_r / (p_light * (float)n))));
    }
    return sum;
}

/* Next-event estimation of the scene's environment (issue 37): one
 * direction from its distribution (pathtrace_env.c), weighted by the power
 * heuristic against the BSDF sample that follows, as the area lights. */
static rl_vec3 environment_light(const pt_ctx *ctx, const pt_surface *s, pt_sampler *sp, uint32_t base,
                                 bool bsdf_follows, pt_counters *c)
{
    rl_pt_sampler_seek(sp, base + ctx->env_slot);
    rl_vec2 x = rl_pt_sample_2d(sp);
    rl_vec3 l;
    float p_env;
    if (!rl_pt_env_sample(&ctx->b->env, x.x, x.y, &l, &p_env))
        return rl_v3s(0.0f);
    float cos_r = rl_dot(s->ns, l);
    if (cos_r <= 0.0f || !visible(ctx, s, l, INFINITY, 0, 0.0f, 0.0f, c))
        return rl_v3s(0.0f);
    float w = bsdf_follows ? power_heuristic(p_env, bsdf_pdf(s, l)) : 1.0f;
    rl_vec3 L = rl_environment_radiance(ctx->env, l);
    return rl_mul(rl_pt_bsdf_f(s, l), rl_scale(L, w * cos_r / p_env));
}

rl_vec3 rl_pt_escape_radiance(const pt_ctx *ctx, rl_vec3 dir)
{
    return ctx->env ? rl_environment_radiance(ctx->env, dir) : ctx->background;
}

/* A ray that left the scene along dir; after a BRDF bounce whose direction
 * had density pdf_bsdf, the environment gets the BSDF strategy's weight
 * when light samples also reach it. */
static rl_vec3 escaped(const pt_ctx *ctx, rl_vec3 dir, bool after_brdf, float pdf_bsdf)
{
    rl_vec3 L = rl_pt_escape_radiance(ctx, dir);
    if (!ctx->env || !ctx->env_nee || !after_brdf)
        return L;
    return rl_scale(L, power_heuristic(pdf_bsdf, rl_pt_env_pdf(&ctx->b->env, dir)));
}

/* The emission rule (see the top of the file). */
static rl_vec3 emitted(const pt_ctx *ctx, const pt_surface *s, bool after_brdf)
{
    rl_vec3 e = s->m->emission;
    if (!(rl_vmax_comp(e) > 0.0f))
        return rl_v3s(0.0f);
    const pt_backends *b = ctx->b;
    uint32_t cover = s->tri != RL_ID_NONE ? b->tri_cover[s->tri] : rl_pt_cover_point(ctx->data, s->p, 10.0f * b->eps);
    if (cover == RL_NONE)
        return e;
    const rl_light *L = &ctx->data->lights[cover];
    bool emitting_side = rl_dot(s->v, rl_cross(L->edge_u, L->edge_v)) > 0.0f;
    return emitting_side && !after_brdf ? e : rl_v3s(0.0f);
}

/* The emission rule with mis=on: after a BSDF bounce from prev (with
 * direction pdf bsdf_pdf) an emitter that light sampling also reaches gets
 * the power-heuristic weight of the BSDF strategy, and a covered triangle
 * stands for its quad light (radiance colour * intensity, the value light
 * sampling uses). From the camera or a mirror / refraction event the
 * emission counts in full, as with mis=off. */
static rl_vec3 emitted_mis(const pt_ctx *ctx, const pt_surface *s, bool after_brdf, rl_vec3 prev, float pdf_bsdf)
{
    if (!after_brdf || !ctx->mis_hits)
        return emitted(ctx, s, after_brdf);
    rl_vec3 e = s->m->emission;
    if (!(rl_vmax_comp(e) > 0.0f))
        return rl_v3s(0.0f);       /* what emitted() returns for it, without the call */
    if (s->tri == RL_ID_NONE)
        return emitted(ctx, s, after_brdf);
    const pt_backends *b = ctx->b;
    const pt_lights *lt = &b->lights;
    uint32_t cover = b->tri_cover[s->tri];
    float pmf, area;
    if (cover == RL_NONE) {
        if (!ctx->tri_lights)
            return e;
        pmf = lt->tri_pmf[s->tri];
        area = rl_pt_triangle_area(ctx->data, s->tri, NULL);
    } else {
        const rl_light *L = &ctx->data->lights[cover];
        rl_vec3 nq = rl_cross(L->edge_u, L->edge_v);
        if (!(rl_dot(s->v, nq) > 0.0f) || !lt->light_hittable[cover])
            return rl_v3s(0.0f);    /* its back, or a quad only NEE reaches */
        e = rl_scale(L->color, L->intensity);
        pmf = lt->light_pmf[cover];
        area = lt->light_area[cover];
        /* The density light sampling had at prev: by solid angle where
         * pathtrace_quad.c samples this quad from there. */
        pt_sph_rect rect;
        if (ctx->quad_solid_angle && pmf > 0.0f && rl_pt_sph_rect_init(&rect, L, prev))
            return rl_scale(e, power_heuristic(pdf_bsdf, (float)ctx->light_samples * pmf / (float)rect.S));
    }
    float cos_e = rl_dot(s->ng, s->v);     /* ng faces v */
    float d2 = rl_length2(rl_sub(s->p, prev));
    if (!(pmf > 0.0f) || !(cos_e > 0.0f) || !(area > 0.0f))
        return e;                  /* light sampling never picks it */
    float p_light = pmf * d2 / (area * cos_e);
    return rl_scale(e, power_heuristic(pdf_bsdf, (float)ctx->light_samples * p_light));
}

rl_vec3 rl_pt_trace_path(const pt_ctx *ctx, pt_surface *first, pt_sampler *sp, pt_counters *c)
{
    rl_vec3 radiance = rl_v3s(0.0f), T = rl_v3s(1.0f);
    /* The vertices in two buffers that swap roles (first is one): copying
     * the 80-byte surface that rl_pt_closest has just written field by
     * field, as "s = next", read it back as vectors that fail store
     * forwarding (perf: 0.7 % of the time in one stall per bounce). */
    pt_surface other, *s = first, *next = &other;
    bool after_brdf = false;
    rl_vec3 prev = s->p;
    float prev_pdf = 0.0f;
    for (int depth = 0;; ++depth) {
        uint32_t base = PT_SLOT_FIRST_VERTEX + (uint32_t)depth * ctx->vertex_slots;
        s->ggx_ms = ctx->ggx_ms;
        rl_vec3 e = ctx->mis ? emitted_mis(ctx, s, after_brdf, prev, prev_pdf) : emitted(ctx, s, after_brdf);
        radiance = rl_add(radiance, rl_mul(T, e));

        /* Sec. 6.4.1: Russian roulette over reflect / refract / diffuse,
         * each chosen with its coefficient, so the weight stays 1. */
        float k_r = s->m->reflectivity, k_t = s->m->transmissivity;
        /* A slot is fixed, so the Sobol sampler may skip the draws a
         * material does not need; the thesis' generators must draw them to
         * keep their sequence. */
        rl_pt_sampler_seek(sp, base + PT_SLOT_EVENT);
        float u_event = sp->rng || k_r + k_t > 0.0f ? rl_pt_sample_1d(sp) : 1.0f;
        rl_vec3 dir;
        rl_ray_type type;
        if (u_event < k_r + k_t) {
            if (depth >= ctx->max_depth)
                break;
            rl_vec3 w;
            bool refracted;
            rl_pt_specular_event(s, u_event, &dir, &w, &refracted);
            T = rl_mul(T, w);
            type = refracted ? RL_RAY_REFRACTION : RL_RAY_REFLECTION;
            after_brdf = false;
        } else {
            bool last = depth >= ctx->max_depth;
            rl_vec3 direct = ctx->mis ? direct_light_mis(ctx, s, sp, base, !last, c)
                                      : direct_light(ctx, s, sp, base, c);
            radiance = rl_add(radiance, rl_mul(T, direct));
            if (ctx->env_nee)
                radiance = rl_add(radiance, rl_mul(T, environment_light(ctx, s, sp, base, !last, c)));
            if (last)
                break;
            rl_pt_sampler_seek(sp, base + PT_SLOT_LOBE);
            float u0 = sp->rng || (!s->lambert && rl_pt_bsdf_needs_lobe(s->m)) ? rl_pt_sample_1d(sp) : 0.0f;
            rl_pt_sampler_seek(sp, base + PT_SLOT_BSDF);
            rl_vec2 u12 = rl_pt_sample_2d(sp);
            rl_vec3 w;
            prev_pdf = 0.0f;          /* the BSDF strategy's density, for MIS only */
            if (!rl_pt_bsdf_sample_pdf(s, u0, u12.x, u12.y, &dir, &w, ctx->mis || ctx->env_nee ? &prev_pdf : NULL))
                break;
            T = rl_mul(T, w);
            type = RL_RAY_DIFFUSE;
            after_brdf = true;
        }
        prev = s->p;

        /* Sec. 3.3: Russian roulette on the path length. */
        if (ctx->rr && depth >= ctx->rr_depth) {
            float q = rl_minf(1.0f, rl_vmax_comp(T));
            rl_pt_sampler_seek(sp, base + PT_SLOT_RR);
            float xi = rl_pt_sample_1d(sp);
            if (!(xi < q))
                break;
            T = rl_scale(T, 1.0f / q);
        }
        if (!(rl_vmax_comp(T) > 0.0f))
            break;

        rl_ray ray = { offset_origin(ctx, s, dir), 0.0f, dir, INFINITY };
        c->rays[type]++;
        /* Sec. 11.2, 12.3: mirror and refraction rays may take another
         * (exact) backend than the diffuse bounces. */
        rl_pt_backend backend = type == RL_RAY_DIFFUSE ? ctx->diffuse : ctx->specular;
        if (backend == RL_PT_BACKEND_LS_PREILLUM) {
            rl_vec3 col;
            ray.t_min = rl_maxf(ray.t_min, ctx->b->ls_start);
            c->trace_q[RL_PT_BACKEND_LS_PREILLUM]++;
            if (rl_linespace_preillum(ctx->b->ls, &ray, &col, NULL)) {
                radiance = rl_add(radiance, rl_mul(T, col));
                c->preillum_ends++;
            } else {
                radiance = rl_add(radiance, rl_mul(T, escaped(ctx, dir, after_brdf, prev_pdf)));
            }
            break;
        }
        if (!rl_pt_closest(ctx, backend, &ray, next, c)) {
            radiance = rl_add(radiance, rl_mul(T, escaped(ctx, dir, after_brdf, prev_pdf)));
            break;
        }
        pt_surface *done = s;
        s = next;
        next = done;
    }
    return radiance;
}

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

rl_vec3 rl_pt_preillum_shade(void *user, const rl_ls_surface *rec, rl_vec3 dir)
{
    const pt_backends *b = user;
    /* Exact shadow rays through the BVH, which the backends build first
     * for this (pathtrace_backend.c): the fastest exact structure here, and
     * the build's cost is almost all shadow rays. */
    rl_pt_backend exact = b->exact[RL_ACCEL_BVH] ? RL_PT_BACKEND_BVH : RL_PT_BACKEND_GRID;
    pt_ctx ctx = { .data = b->data, .b = b, .shadow = exact, .diffuse = exact, .specular = exact,
                   .light_samples = PREILLUM_QUAD_SAMPLES };
    pt_surface s;
    if (!surface_of_record(b->data, rec, rl_neg(rl_normalize(dir)), &s))
        return rl_v3s(0.0f);
    /* Seeded from the record itself: the stored value does not depend on
     * the build's thread schedule. */
    uint64_t key = rl_hash64(((uint64_t)float_bits(s.p.x) << 32) ^ float_bits(s.p.y));
    key = rl_hash64(key ^ ((uint64_t)float_bits(s.p.z) << 32) ^ float_bits(dir.x + 2.0f * dir.y + 4.0f * dir.z));
    rl_rng_gpu rng;
    rl_rng_gpu_seed(&rng, RL_RNG_GPU_HYBRID, key, 0);
    pt_sampler sp;
    rl_pt_sampler_init(&sp, &rng, 0, 0);
    pt_counters c;
    memset(&c, 0, sizeof c);
    /* What a path arriving by a BRDF bounce would gather here: uncovered
     * emission, and the direct light of the BRDF event (probability
     * 1 - k_r - k_t). */
    float brdf = rl_maxf(0.0f, 1.0f - s.m->reflectivity - s.m->transmissivity);
    return rl_add(emitted(&ctx, &s, true), rl_scale(direct_light(&ctx, &s, &sp, 0, &c), brdf));
}
