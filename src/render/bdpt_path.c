/* bdpt_path.c: one sample of the bidirectional path tracer "bdpt" (Veach
 * 1997, Ch. 10; the outlook of Schröder 2017, Sec. 8.3).
 *
 * A sample traces a camera subpath z_0 (the pinhole) .. z_{t-1} and a light
 * subpath y_0 (a point on a light chosen by power) .. y_{s-1}, and adds
 * every strategy (s, t) that makes a path of at most max_depth + 2 edges
 * (pt's longest path: the camera edge, max_depth bounces, the light edge):
 *   s = 0   the camera subpath hits an emitter;
 *   s = 1   next-event estimation: a fresh point on a light chosen by power
 *           is joined to z_{t-1};
 *   t = 1   light tracing: y_{s-1} is joined to the pinhole and the result
 *           lands in the pixel the point projects to (a splat);
 *   else    y_{s-1} and z_{t-1} are joined by a shadow ray.
 * (s, t) = (1, 1), a light point seen straight by the camera, is left out:
 * the camera sees emitters by s = 0 alone, so a light no ray can hit (a
 * quad light without an emissive mesh) stays invisible, as with pt.
 *
 * Weights: the power heuristic over all strategies that can make the same
 * path (Veach 1997, Sec. 10.2), from the ratios of the area densities with
 * which each vertex is made from the light side (pl) and from the camera
 * side (pe): p_{i+1} / p_i = pl(x_i) / pe(x_i). A vertex that scattered by
 * a mirror or refraction event is a delta vertex: no strategy joins at it,
 * and the delta densities it gives its neighbours (stored as 1) cancel in
 * the ratios of the strategies that remain. mis=uniform weights each
 * strategy by one over the number that can make the path (unbiased too,
 * for the test that the weights do not bias).
 *
 * Materials as pt (pathtrace_path.c): at a vertex the event is mirror with
 * k_r, refraction with k_t, else the Phong BRDF; the BRDF part of the
 * scattering function is (1 - k_r - k_t) f_Phong, and its sampling density
 * carries the same factor, so a Phong bounce keeps pt's weight. The BRDF
 * is pt's (Phong or GGX, pathtrace_ggx.c; both reciprocal, so light
 * subpaths use it unchanged) and so is the specular event with Schlick's
 * Fresnel.
 *
 * Emitters, as pt's light table (pathtrace_lights.c): a quad light whose
 * emissive mesh covers it ("hittable") emits its radiance colour *
 * intensity on its front, from the light table's point and from the mesh a
 * ray hits; an uncovered emissive triangle emits its material's emission
 * on both sides; point and spot lights are delta positions (their intensity
 * by light_eval.h); a directional light is reached by next-event estimation
 * only (a light subpath that picks one is empty, and s = 1 gets the full
 * weight); covered triangles of a quad that is not hittable emit nothing.
 *
 * The scene's environment is an emitter at infinity (the construction of
 * pbrt's bidirectional path tracer, Pharr et al. 2016): a light
 * subpath picks it with probability env_pick, draws a direction w from its
 * importance distribution (pathtrace_env.c) and starts on a disk of the
 * bounding sphere's radius R across w, outside the scene, travelling along
 * -w. Its vertex y_0 has no position: its density is that of the direction,
 * env_pick p_env(w), in solid angle, and the next vertex's is the disk's
 * 1 / (pi R^2) times its cosine to w, with no distance (parallel rays).
 * The camera side makes the same vertex when a BSDF ray leaves the scene,
 * with the BSDF's density in solid angle. So s = 0 is a camera path that
 * escapes, s = 1 a direction drawn from the environment at z_{t-1} and a
 * shadow ray to infinity, and s >= 2 joins light subpaths that came in
 * from the sky; one set of ratios weighs them all.
 *
 * Light subpaths carry importance: at surfaces with shading normals their
 * scattering takes the adjoint factor |v.ns| |wi.ng| / (|v.ng| |wi.ns|)
 * (Veach 1997, Sec. 5.3). Refraction keeps pt's weight 1 both ways (no
 * eta^2). Russian roulette as pt on the camera side; on the light side on
 * the throughput relative to the first bounce's. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/bdpt_internal.h"
#include "scene/light_eval.h"

#define SHADOW_T_SHRINK 1e-4f

rl_status bd_scratch_init(bd_scratch *sc, int max_depth)
{
    size_t n = (size_t)max_depth + 4;
    sc->camera = rl_calloc(n, sizeof *sc->camera);
    sc->light = rl_calloc(n, sizeof *sc->light);
    sc->pl = rl_calloc(2 * n, sizeof *sc->pl);
    sc->pe = rl_calloc(2 * n, sizeof *sc->pe);
    sc->delta = rl_calloc(2 * n, sizeof *sc->delta);
    if (!sc->camera || !sc->light || !sc->pl || !sc->pe || !sc->delta) {
        bd_scratch_release(sc);
        return RL_ERR_OUT_OF_MEMORY;
    }
    return RL_OK;
}

void bd_scratch_release(bd_scratch *sc)
{
    free(sc->camera);
    free(sc->light);
    free(sc->pl);
    free(sc->pe);
    free(sc->delta);
    memset(sc, 0, sizeof *sc);
}

/* ------------------------------------------------------------ emitters -- */

/* The emitter surface s is, if any (see the top of the file). */
static bd_light surface_emitter(const bd_ctx *ctx, const pt_surface *s)
{
    bd_light e = { 0 };
    if (!(rl_vmax_comp(s->m->emission) > 0.0f) || s->tri == RL_ID_NONE)
        return e;
    const pt_backends *b = ctx->b;
    const pt_lights *lt = &b->lights;
    uint32_t cover = b->tri_cover[s->tri];
    if (cover == RL_NONE) {
        float area = rl_pt_triangle_area(ctx->data, s->tri, &e.n);
        if (!(area > 0.0f) || !(lt->tri_pmf[s->tri] > 0.0f))
            return e;
        e.kind = BD_LIGHT_TRI;
        e.le = s->m->emission;
        e.pdf_pos = ctx->light_share * lt->tri_pmf[s->tri] / area;
        e.hittable = true;
        return e;
    }
    const rl_light *L = &ctx->data->lights[cover];
    rl_vec3 nq = rl_cross(L->edge_u, L->edge_v);
    float area = rl_length(nq);
    if (!lt->light_hittable[cover] || !(area > 0.0f) || !(lt->light_pmf[cover] > 0.0f))
        return e;
    e.kind = BD_LIGHT_QUAD;
    e.n = rl_scale(nq, 1.0f / area);
    e.le = rl_scale(L->color, L->intensity);
    e.pdf_pos = ctx->light_share * lt->light_pmf[cover] / area;
    e.hittable = true;
    return e;
}

/* Radiance (area) or intensity (delta position) leaving the emitter
 * towards unit w. */
static rl_vec3 emitter_le(const bd_light *e, rl_vec3 p, rl_vec3 w)
{
    switch (e->kind) {
    case BD_LIGHT_QUAD:
        return rl_dot(e->n, w) > 0.0f ? e->le : rl_v3s(0.0f);
    case BD_LIGHT_TRI:
        return e->le;
    case BD_LIGHT_POINT: {
        rl_vec3 E, l;
        float dist;
        /* The intensity is the irradiance-like scale at distance 1. */
        if (!rl_light_eval_delta(e->L, rl_add(p, w), &E, &l, &dist))
            return rl_v3s(0.0f);
        return E;
    }
    default:
        return rl_v3s(0.0f);
    }
}

static float spot_cos_outer(const rl_light *L)
{
    return cosf(rl_radians(rl_clampf(L->spot_outer_deg, 0.0f, 180.0f)));
}

/* Solid-angle density with which a light subpath leaves the emitter along w. */
static float emitter_pdf_dir(const bd_light *e, rl_vec3 w)
{
    switch (e->kind) {
    case BD_LIGHT_QUAD:
        return rl_maxf(0.0f, rl_dot(e->n, w)) / RL_PI;
    case BD_LIGHT_TRI:
        return fabsf(rl_dot(e->n, w)) / (2.0f * RL_PI);
    case BD_LIGHT_POINT:
        if (e->L->type == RL_LIGHT_SPOT) {
            float c = spot_cos_outer(e->L);
            rl_vec3 axis = rl_normalize(e->L->direction);
            return rl_dot(axis, w) >= c && c < 1.0f ? 1.0f / (2.0f * RL_PI * (1.0f - c)) : 0.0f;
        }
        return 1.0f / (4.0f * RL_PI);
    default:
        return 0.0f;
    }
}

/* Cosine at a light vertex towards w (delta positions: 1). */
static float emitter_cos(const bd_light *e, rl_vec3 w)
{
    return e->kind == BD_LIGHT_QUAD || e->kind == BD_LIGHT_TRI ? fabsf(rl_dot(e->n, w)) : 1.0f;
}

/* A light chosen by power and a point on it: *e and *p; false if the
 * table is empty. */
static bool sample_light(const bd_ctx *ctx, float u_pick, rl_vec2 x, bd_light *e, rl_vec3 *p)
{
    const rl_scene_data *d = ctx->data;
    const pt_lights *lt = &ctx->b->lights;
    memset(e, 0, sizeof *e);
    if (u_pick < ctx->env_pick) {
        float pdf;
        if (!rl_pt_env_sample(ctx->env, x.x, x.y, &e->dir, &pdf))
            return false;
        e->kind = BD_LIGHT_ENV;
        e->le = rl_environment_radiance(ctx->environment, e->dir);
        e->pdf_pos = ctx->env_pick * pdf;
        e->hittable = true;
        *p = rl_madd(ctx->env_centre, e->dir, ctx->env_radius);
        return true;
    }
    if (lt->count == 0 || !(ctx->light_share > 0.0f))
        return false;
    /* The rest of [env_pick, 1) picks from the table. */
    u_pick = rl_minf((u_pick - ctx->env_pick) / ctx->light_share, 0.99999994f);
    uint32_t src = lt->source[rl_pt_lights_pick(lt, u_pick)];
    if (src < d->num_lights) {
        const rl_light *L = &d->lights[src];
        float pmf = ctx->light_share * lt->light_pmf[src];
        e->L = L;
        if (L->type == RL_LIGHT_QUAD) {
            rl_vec3 nq = rl_cross(L->edge_u, L->edge_v);
            float area = rl_length(nq);
            if (!(area > 0.0f))
                return false;
            e->kind = BD_LIGHT_QUAD;
            e->n = rl_scale(nq, 1.0f / area);
            e->le = rl_scale(L->color, L->intensity);
            e->pdf_pos = pmf / area;
            e->hittable = lt->light_hittable[src];
            *p = rl_add(L->position, rl_add(rl_scale(L->edge_u, x.x), rl_scale(L->edge_v, x.y)));
            return true;
        }
        e->kind = L->type == RL_LIGHT_DIRECTIONAL ? BD_LIGHT_DIRECTIONAL : BD_LIGHT_POINT;
        e->pdf_pos = pmf;
        *p = L->position;
        return true;
    }
    uint32_t t = src - d->num_lights;
    const uint32_t *idx = &d->indices[3 * (size_t)t];
    float area = rl_pt_triangle_area(d, t, &e->n);
    if (!(area > 0.0f))
        return false;
    /* Uniform on the triangle: barycentrics (1 - sqrt(u), v sqrt(u)). */
    float r = sqrtf(x.x), b1 = x.y * r, b0 = 1.0f - r;
    rl_vec3 p0 = d->positions[idx[0]], p1 = d->positions[idx[1]], p2 = d->positions[idx[2]];
    *p = rl_add(rl_add(rl_scale(p0, b0), rl_scale(p1, b1)), rl_scale(p2, 1.0f - b0 - b1));
    e->kind = BD_LIGHT_TRI;
    e->le = d->materials[d->triangle_material[t]].emission;
    e->pdf_pos = ctx->light_share * lt->tri_pmf[t] / area;
    e->hittable = true;
    return true;
}

/* ----------------------------------------------------------- scattering -- */

static float brdf_share(const pt_surface *s)
{
    return rl_maxf(0.0f, 1.0f - s->m->reflectivity - s->m->transmissivity);
}

/* s seen from unit v instead: the normals turn to face it. */
static pt_surface seen_from(const pt_surface *s, rl_vec3 v)
{
    pt_surface r = *s;
    r.v = v;
    if (rl_dot(r.ng, v) < 0.0f) {
        r.ng = rl_neg(r.ng);
        r.front = !r.front;
    }
    if (rl_dot(r.ns, v) < 0.0f)
        r.ns = rl_neg(r.ns);
    return r;
}

/* The non-delta part of the scattering function at s (towards s->v) for
 * unit wi: zero below the shading or the geometric surface, as pt. */
static rl_vec3 bsdf_f(const pt_surface *s, rl_vec3 wi)
{
    float k = brdf_share(s);
    if (!(k > 0.0f) || rl_dot(s->ns, wi) <= 0.0f || rl_dot(s->ng, wi) <= 0.0f)
        return rl_v3s(0.0f);
    return rl_scale(rl_pt_bsdf_eval(s, wi), k);
}

/* Solid-angle density of sampling wi at s (event and lobe). */
static float bsdf_pdf(const pt_surface *s, rl_vec3 wi)
{
    float k = brdf_share(s);
    if (!(k > 0.0f) || rl_dot(s->ng, wi) <= 0.0f)
        return 0.0f;
    return k * rl_pt_bsdf_pdf(s, wi);
}

/* The factor that turns the BRDF into its adjoint with shading normals
 * (Veach 1997, Sec. 5.3): light subpaths only. */
static float adjoint_factor(const pt_surface *s, rl_vec3 wi)
{
    float num = fabsf(rl_dot(s->v, s->ns)) * fabsf(rl_dot(wi, s->ng));
    float den = fabsf(rl_dot(s->v, s->ng)) * fabsf(rl_dot(wi, s->ns));
    return den > 0.0f ? num / den : 0.0f;
}

/* ------------------------------------------------------------ geometry -- */

static rl_vec3 offset_point(const bd_ctx *ctx, rl_vec3 p, rl_vec3 ng, rl_vec3 dir)
{
    if (!(rl_length2(ng) > 0.0f))
        return p;
    float side = rl_dot(dir, ng) >= 0.0f ? 1.0f : -1.0f;
    return rl_madd(p, ng, side * ctx->b->eps);
}

/* Whether the segment between the vertices' points is free; each end
 * leaves its surface by the epsilon on the side of the other. */
static bool unoccluded(const bd_ctx *ctx, rl_vec3 a, rl_vec3 na, rl_vec3 b, rl_vec3 nb, uint64_t *rays)
{
    rl_vec3 ab = rl_sub(b, a);
    rl_vec3 o = offset_point(ctx, a, na, ab);
    rl_vec3 e = offset_point(ctx, b, nb, rl_neg(ab));
    rl_vec3 to = rl_sub(e, o);
    float len = rl_length(to);
    if (!(len > 0.0f))
        return true;
    rl_ray ray = { o, 0.0f, rl_scale(to, 1.0f / len), len * (1.0f - SHADOW_T_SHRINK) };
    (*rays)++;
    return !rl_accel_occluded(ctx->b->exact[RL_ACCEL_BVH], &ray);
}

static bool is_env(const bd_vertex *v)
{
    return v->kind == BD_V_LIGHT && v->light.kind == BD_LIGHT_ENV;
}

/* Unit direction from vertex a to vertex b; an environment vertex lies at
 * infinity along its direction. */
static rl_vec3 dir_between(const bd_vertex *a, const bd_vertex *b)
{
    if (is_env(b))
        return b->light.dir;
    if (is_env(a))
        return rl_neg(a->light.dir);
    return rl_normalize(rl_sub(b->p, a->p));
}

/* Solid-angle density of the pinhole sampling unit w (the film uniform). */
static float camera_pdf_dir(const bd_ctx *ctx, rl_vec3 w)
{
    float c = rl_dot(w, ctx->forward);
    if (!(c > 0.0f))
        return 0.0f;
    return 1.0f / (ctx->film_area * c * c * c);
}

/* Density in area at vertex to of a direction density at `from`. */
static float to_area(float pdf_dir, rl_vec3 from, const bd_vertex *to)
{
    if (is_env(to))
        return pdf_dir;            /* the environment's vertex is measured by direction */
    rl_vec3 d = rl_sub(to->p, from);
    float d2 = rl_length2(d);
    if (!(d2 > 0.0f))
        return 0.0f;
    float c = rl_length2(to->ng) > 0.0f ? fabsf(rl_dot(to->ng, d)) / sqrtf(d2) : 1.0f;
    return pdf_dir * c / d2;
}

/* Area density at `to` of vertex v sampling towards it, v having been
 * reached from prev (NULL for the camera and light ends). */
static float pdf_area(const bd_ctx *ctx, const bd_vertex *v, const bd_vertex *prev, const bd_vertex *to)
{
    rl_vec3 w = dir_between(v, to);
    float pdf;
    if (is_env(v)) {
        /* Parallel rays through the disk: its density projected onto to. */
        float c = rl_length2(to->ng) > 0.0f ? fabsf(rl_dot(to->ng, w)) : 1.0f;
        return ctx->env_disk_pdf * c;
    }
    if (v->kind == BD_V_CAMERA) {
        pdf = camera_pdf_dir(ctx, w);
    } else if (v->kind == BD_V_LIGHT || !prev) {
        pdf = emitter_pdf_dir(&v->light, w);     /* a light end, or an emitter hit (s = 0) */
    } else {
        pt_surface s = seen_from(&v->s, dir_between(v, prev));
        pdf = bsdf_pdf(&s, w);
    }
    return to_area(pdf, v->p, to);
}

/* ------------------------------------------------------------- subpaths -- */

/* Extends a subpath whose last vertex is path[n - 1] along ray with
 * throughput beta, the direction's density pdf_dir (solid angle; 1 after a
 * delta event), until max_vertices; returns the vertex count. A ray that
 * leaves the scene sets *escaped and leaves in path[n] (not counted) the
 * environment's vertex as this side made it: its direction, throughput
 * and density. */
static int walk(const bd_ctx *ctx, rl_rng *rng, rl_ray ray, rl_vec3 beta, float pdf_dir, bool delta_dir,
                bool importance, bd_vertex *path, int n, int max_vertices, bool *escaped, uint64_t *rays)
{
    float rr_ref = rl_vmax_comp(beta);
    *escaped = false;
    while (n < max_vertices) {
        rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
        (*rays)++;
        bd_vertex *v = &path[n], *prev = &path[n - 1];
        memset(v, 0, sizeof *v);
        if (!rl_accel_intersect(ctx->b->exact[RL_ACCEL_BVH], &ray, &hit)) {
            *escaped = true;
            v->kind = BD_V_LIGHT;
            v->light.kind = BD_LIGHT_ENV;
            v->light.dir = ray.d;
            v->beta = beta;
            v->pdf_fwd = delta_dir ? 1.0f : pdf_dir;
            return n;
        }
        if (!rl_pt_surface_at_hit(ctx->data, &hit, ray.o, ray.d, &v->s))
            return n;
        v->s.ggx_ms = ctx->ggx_ms;
        v->kind = BD_V_SURFACE;
        v->p = v->s.p;
        v->ng = v->s.ng;
        v->beta = beta;
        if (delta_dir)
            v->pdf_fwd = 1.0f;
        else if (is_env(prev))
            v->pdf_fwd = ctx->env_disk_pdf * fabsf(rl_dot(v->ng, ray.d));
        else
            v->pdf_fwd = to_area(pdf_dir, prev->p, v);
        v->light = surface_emitter(ctx, &v->s);
        ++n;
        if (n >= max_vertices)
            break;

        const pt_surface *s = &v->s;
        float k_r = s->m->reflectivity, k_t = s->m->transmissivity;
        float u_event = rl_rng_float(rng);
        float u0 = rl_rng_float(rng), u1 = rl_rng_float(rng), u2 = rl_rng_float(rng);
        rl_vec3 dir;
        if (u_event < k_r + k_t) {
            /* pt's event, Schlick's Fresnel included: F is the same from
             * either end of the path, so light subpaths may use it too. */
            rl_vec3 w;
            bool refracted;
            rl_pt_specular_event(s, u_event, &dir, &w, &refracted);
            beta = rl_mul(beta, w);
            v->delta = true;
            delta_dir = true;
            pdf_dir = 1.0f;
            prev->pdf_rev = 1.0f;
        } else {
            rl_vec3 w;
            if (!rl_pt_bsdf_sample(s, u0, u1, u2, &dir, &w))
                break;
            if (importance)
                w = rl_scale(w, adjoint_factor(s, dir));
            beta = rl_mul(beta, w);
            delta_dir = false;
            pdf_dir = bsdf_pdf(s, dir);
            pt_surface back = seen_from(s, dir);
            prev->pdf_rev = to_area(bsdf_pdf(&back, s->v), v->p, prev);
        }
        /* Russian roulette (Sec. 3.2.4) on the throughput, as pt. */
        int depth = n - 2;             /* 0 = the first surface */
        if (ctx->rr && depth >= ctx->rr_depth) {
            float q = rl_minf(1.0f, rl_vmax_comp(beta) / rr_ref);
            float xi = rl_rng_float(rng);
            if (!(xi < q))
                break;
            beta = rl_scale(beta, 1.0f / q);
        }
        if (!(rl_vmax_comp(beta) > 0.0f) || !rl_vfinite(beta))
            break;
        ray = (rl_ray){ offset_point(ctx, s->p, s->ng, dir), 0.0f, dir, INFINITY };
    }
    return n;
}

/* The light subpath: y_0 on a light chosen by power, then the walk
 * (bdpt_internal.h; gl-pt's hybrid light paths trace theirs with it). */
int bd_light_subpath(const bd_ctx *ctx, rl_rng *rng, bd_vertex *y, int max_vertices, uint64_t *rays)
{
    float u_pick = rl_rng_float(rng);
    rl_vec2 x = rl_v2(rl_rng_float(rng), rl_rng_float(rng));
    rl_vec2 u = rl_v2(rl_rng_float(rng), rl_rng_float(rng));
    bd_vertex *v = &y[0];
    memset(v, 0, sizeof *v);
    if (max_vertices < 1 || !sample_light(ctx, u_pick, x, &v->light, &v->p))
        return 0;
    if (v->light.kind == BD_LIGHT_DIRECTIONAL || !(v->light.pdf_pos > 0.0f))
        return 0;                  /* directional: next-event estimation only */
    v->kind = BD_V_LIGHT;
    bool escaped;
    if (v->light.kind == BD_LIGHT_ENV) {
        /* From the disk of radius R across dir, centred R beyond the
         * bounding sphere's centre: every ray along -dir that meets the
         * scene crosses it once. */
        rl_vec3 dir = v->light.dir;
        rl_onb onb = rl_onb_from_normal(dir);
        float r = ctx->env_radius * sqrtf(u.x), phi = 2.0f * RL_PI * u.y;
        rl_vec3 o = rl_madd(ctx->env_centre, dir, ctx->env_radius);
        o = rl_add(o, rl_onb_to_world(&onb, rl_v3(r * cosf(phi), r * sinf(phi), 0.0f)));
        v->p = o;
        v->pdf_fwd = v->light.pdf_pos;
        v->beta = rl_v3s(1.0f / v->light.pdf_pos);
        if (!(rl_vmax_comp(v->light.le) > 0.0f))
            return 1;
        rl_vec3 beta = rl_scale(v->light.le, 1.0f / (v->light.pdf_pos * ctx->env_disk_pdf));
        rl_ray ray = { o, 0.0f, rl_neg(dir), INFINITY };
        return walk(ctx, rng, ray, beta, 0.0f, false, true, y, 1, max_vertices, &escaped, rays);
    }
    v->ng = v->light.kind == BD_LIGHT_POINT ? rl_v3s(0.0f) : v->light.n;
    v->pdf_fwd = v->light.pdf_pos;
    v->beta = rl_v3s(1.0f / v->light.pdf_pos);
    /* The direction: cosine-weighted on the emitting side (a two-sided
     * triangle picks its side with u.x), uniform in the sphere or cone of a
     * point or spot light. */
    rl_vec3 w;
    if (v->light.kind == BD_LIGHT_POINT) {
        float c_min = v->light.L->type == RL_LIGHT_SPOT ? spot_cos_outer(v->light.L) : -1.0f;
        float cos_t = 1.0f - u.x * (1.0f - c_min);
        rl_vec3 axis = v->light.L->type == RL_LIGHT_SPOT ? rl_normalize(v->light.L->direction) : rl_v3(0, 0, 1);
        rl_onb onb = rl_onb_from_normal(axis);
        float sin_t = sqrtf(rl_maxf(0.0f, 1.0f - cos_t * cos_t)), phi = 2.0f * RL_PI * u.y;
        w = rl_onb_to_world(&onb, rl_v3(cosf(phi) * sin_t, sinf(phi) * sin_t, cos_t));
    } else {
        rl_vec3 n = v->light.n;
        float ux = u.x;
        if (v->light.kind == BD_LIGHT_TRI) {
            if (ux < 0.5f) {
                n = rl_neg(n);
                ux *= 2.0f;
            } else {
                ux = 2.0f * ux - 1.0f;
            }
        }
        rl_onb onb = rl_onb_from_normal(n);
        float r = sqrtf(ux), phi = 2.0f * RL_PI * u.y;
        w = rl_onb_to_world(&onb, rl_v3(r * cosf(phi), r * sinf(phi), sqrtf(rl_maxf(0.0f, 1.0f - ux))));
    }
    float pdf_dir = emitter_pdf_dir(&v->light, w);
    rl_vec3 le = emitter_le(&v->light, v->p, w);
    if (!(pdf_dir > 0.0f) || !(rl_vmax_comp(le) > 0.0f))
        return 1;
    rl_vec3 beta = rl_scale(le, emitter_cos(&v->light, w) / (v->light.pdf_pos * pdf_dir));
    rl_ray ray = { offset_point(ctx, v->p, v->ng, w), 0.0f, w, INFINITY };
    return walk(ctx, rng, ray, beta, pdf_dir, false, true, y, 1, max_vertices, &escaped, rays);
}

/* ------------------------------------------------------------------ MIS -- */

/* Whether strategy s' can make a path of n vertices with these delta
 * flags; x_0 a light that a ray can hit (hittable) or not. */
static bool strategy_possible(int sp, int n, const bool *delta, bool hittable)
{
    int tp = n - sp;
    if (tp < 1 || (sp == 1 && tp == 1))
        return false;
    if (sp == 0)
        return hittable;
    return !delta[sp - 1] && !delta[sp];
}

/* The weight of strategy (s, t) for the path y_0..y_{s-1} z_{t-1}..z_0;
 * for s = 0, z_{t-1} is the emitter. y_{s-1}, z_{t-1} may be temporaries
 * (the fresh light point of s = 1). */
static float mis_weight(const bd_ctx *ctx, bd_scratch *sc, const bd_vertex *y, int s, const bd_vertex *z, int t)
{
    if (ctx->only_s >= 0)
        return 1.0f;
    int n = s + t;
    float *pl = sc->pl, *pe = sc->pe;
    bool *delta = sc->delta;
    for (int i = 0; i < s; ++i) {
        pl[i] = y[i].pdf_fwd;
        pe[i] = y[i].pdf_rev;
        delta[i] = y[i].delta;
    }
    for (int j = 0; j < t; ++j) {
        pe[n - 1 - j] = z[j].pdf_fwd;
        pl[n - 1 - j] = z[j].pdf_rev;
        delta[n - 1 - j] = z[j].delta;
    }
    bool hittable;
    const bd_vertex *ze = &z[t - 1], *zp = t >= 2 ? &z[t - 2] : NULL;
    if (s == 0) {
        /* z_{t-1} is x_0 as the light would have made it. */
        pl[0] = ze->light.pdf_pos;
        if (zp)
            pl[1] = pdf_area(ctx, ze, NULL, zp);
        delta[0] = false;
        hittable = true;
    } else {
        const bd_vertex *ye = &y[s - 1], *yp = s >= 2 ? &y[s - 2] : NULL;
        pe[s - 1] = pdf_area(ctx, ze, zp, ye);
        if (yp)
            pe[s - 2] = pdf_area(ctx, ye, ze, yp);
        pl[s] = pdf_area(ctx, ye, yp, ze);
        if (zp)
            pl[s + 1] = pdf_area(ctx, ze, ye, zp);
        delta[s - 1] = delta[s] = false;
        hittable = y[0].light.hittable;
        if (s == 1)
            pe[0] = hittable ? pe[0] : 0.0f;
    }
    /* p_{s'} / p_s as running products of the density ratios. */
    float sum = 0.0f;
    int count = 1;
    float r = 1.0f;
    for (int i = s - 1; i >= 0; --i) {
        r *= pe[i] / (pl[i] > 0.0f ? pl[i] : 1.0f);
        if (strategy_possible(i, n, delta, hittable)) {
            sum += r * r;
            count += r > 0.0f;
        }
    }
    r = 1.0f;
    for (int i = s; i <= n - 2; ++i) {
        r *= pl[i] / (pe[i] > 0.0f ? pe[i] : 1.0f);
        if (strategy_possible(i + 1, n, delta, hittable)) {
            sum += r * r;
            count += r > 0.0f;
        }
    }
    if (ctx->mis == BD_MIS_UNIFORM)
        return 1.0f / (float)count;
    return isfinite(sum) ? 1.0f / (1.0f + sum) : 0.0f;
}

/* ------------------------------------------------------------ strategies -- */

static bool wanted(const bd_ctx *ctx, int s, int t)
{
    return ctx->only_s < 0 || (ctx->only_s == s && ctx->only_t == t);
}

/* The pixel the point p projects to and the splat factor W_e cos / ... :
 * returns false outside the image. *cos_cam: cosine at the pinhole. */
static bool project(const bd_ctx *ctx, rl_vec3 p, int *px, int *py, float *cos_cam)
{
    const rl_camera_frame *f = &ctx->cam;
    rl_vec3 d = rl_sub(p, f->eye);
    float z = -rl_dot(d, f->w);
    if (!(z > 0.0f))
        return false;
    float sx = rl_dot(d, f->u) / z, sy = rl_dot(d, f->v) / z;
    float fx = (sx / (f->tan_half_fov_y * f->aspect) + 1.0f) * 0.5f * (float)f->width;
    float fy = (1.0f - sy / f->tan_half_fov_y) * 0.5f * (float)f->height;
    if (!(fx >= 0.0f && fx < (float)f->width && fy >= 0.0f && fy < (float)f->height))
        return false;
    *px = (int)fx;
    *py = (int)fy;
    *cos_cam = z / rl_length(d);
    return true;
}

static void push_splat(bd_splats *sp, int px, int py, int width, rl_vec3 c)
{
    if (sp->failed || !rl_vfinite(c))
        return;
    if (sp->n == sp->cap) {
        size_t cap = sp->cap ? 2 * sp->cap : 256;
        bd_splat *v = realloc(sp->v, cap * sizeof *v);
        if (!v) {
            sp->failed = true;
            return;
        }
        sp->v = v;
        sp->cap = cap;
    }
    sp->v[sp->n++] = (bd_splat){ (uint32_t)py * (uint32_t)width + (uint32_t)px, c.x, c.y, c.z };
}

/* t = 1: y_{s-1} (s >= 2) seen by the pinhole, into the splats. */
static void connect_camera(const bd_ctx *ctx, bd_scratch *sc, const bd_vertex *y, int s, const bd_vertex *cam,
                           bd_splats *splats, uint64_t *rays)
{
    const bd_vertex *ye = &y[s - 1];
    if (ye->kind != BD_V_SURFACE)
        return;
    int px, py;
    float cos_cam;
    if (!project(ctx, ye->p, &px, &py, &cos_cam))
        return;
    rl_vec3 to_cam = rl_sub(cam->p, ye->p);
    float d2 = rl_length2(to_cam);
    rl_vec3 w = rl_scale(to_cam, 1.0f / sqrtf(d2));
    rl_vec3 f = bsdf_f(&ye->s, w);
    if (!(rl_vmax_comp(f) > 0.0f))
        return;
    f = rl_scale(f, adjoint_factor(&ye->s, w));
    /* W_e cos_cam / d^2 with W_e = 1 / (A cos^4) of a pinhole whose film
     * has area A at distance 1 (Veach 1997, Sec. 10.3.3); the pixel's sum
     * takes it as it is, one light subpath per camera sample. */
    float g = fabsf(rl_dot(ye->s.ns, w)) / (d2 * ctx->film_area * cos_cam * cos_cam * cos_cam);
    rl_vec3 c = rl_scale(rl_mul(ye->beta, f), g);
    if (!(rl_vmax_comp(c) > 0.0f) || !unoccluded(ctx, ye->p, ye->ng, cam->p, rl_v3s(0.0f), rays))
        return;
    c = rl_scale(c, mis_weight(ctx, sc, y, s, cam, 1));
    push_splat(splats, px, py, ctx->cam.width, c);
}

/* s = 1: a fresh light point joined to z_{t-1}. */
static rl_vec3 connect_light(const bd_ctx *ctx, bd_scratch *sc, rl_rng *rng, const bd_vertex *z, int t,
                             uint64_t *rays)
{
    float u_pick = rl_rng_float(rng);
    rl_vec2 x = rl_v2(rl_rng_float(rng), rl_rng_float(rng));
    const bd_vertex *ze = &z[t - 1];
    /* z_{t-1} joins by its BRDF part whatever event it chose next: the
     * event comes after the prefix, so skipping would bias. */
    if (ze->kind != BD_V_SURFACE)
        return rl_v3s(0.0f);
    bd_vertex lv;
    memset(&lv, 0, sizeof lv);
    if (!sample_light(ctx, u_pick, x, &lv.light, &lv.p) || !(lv.light.pdf_pos > 0.0f))
        return rl_v3s(0.0f);
    lv.kind = BD_V_LIGHT;
    lv.pdf_fwd = lv.light.pdf_pos;
    lv.beta = rl_v3s(1.0f / lv.light.pdf_pos);
    if (lv.light.kind == BD_LIGHT_ENV) {
        rl_vec3 l = lv.light.dir;
        rl_vec3 f = bsdf_f(&ze->s, l);
        if (!(rl_vmax_comp(f) > 0.0f) || !(rl_vmax_comp(lv.light.le) > 0.0f))
            return rl_v3s(0.0f);
        rl_vec3 c = rl_scale(rl_mul(rl_mul(ze->beta, f), lv.light.le), fabsf(rl_dot(ze->s.ns, l)) / lv.light.pdf_pos);
        rl_vec3 far = rl_madd(ze->p, l, 2.0f * (ctx->env_radius + rl_length(rl_sub(ze->p, ctx->env_centre))));
        if (!(rl_vmax_comp(c) > 0.0f) || !unoccluded(ctx, ze->p, ze->ng, far, rl_v3s(0.0f), rays))
            return rl_v3s(0.0f);
        return rl_scale(c, mis_weight(ctx, sc, &lv, 1, z, t));
    }
    if (lv.light.kind == BD_LIGHT_DIRECTIONAL) {
        /* Only this strategy reaches it: full weight. */
        rl_vec3 E, l;
        float dist;
        if (!rl_light_eval_delta(lv.light.L, ze->p, &E, &l, &dist))
            return rl_v3s(0.0f);
        rl_vec3 f = bsdf_f(&ze->s, l);
        float cos_z = rl_dot(ze->s.ns, l);
        if (!(rl_vmax_comp(f) > 0.0f) || cos_z <= 0.0f)
            return rl_v3s(0.0f);
        rl_vec3 far = rl_madd(ze->p, l, 2.0f * (ctx->b->lights.radius + rl_length(rl_sub(ze->p, ctx->b->lights.centre))));
        if (!unoccluded(ctx, ze->p, ze->ng, far, rl_v3s(0.0f), rays))
            return rl_v3s(0.0f);
        return rl_scale(rl_mul(rl_mul(ze->beta, f), E), cos_z / lv.light.pdf_pos);
    }
    lv.ng = lv.light.kind == BD_LIGHT_POINT ? rl_v3s(0.0f) : lv.light.n;
    rl_vec3 to = rl_sub(lv.p, ze->p);
    float d2 = rl_length2(to);
    if (!(d2 > 0.0f))
        return rl_v3s(0.0f);
    rl_vec3 l = rl_scale(to, 1.0f / sqrtf(d2));
    rl_vec3 le = emitter_le(&lv.light, lv.p, rl_neg(l));
    rl_vec3 f = bsdf_f(&ze->s, l);
    if (!(rl_vmax_comp(le) > 0.0f) || !(rl_vmax_comp(f) > 0.0f))
        return rl_v3s(0.0f);
    float g = fabsf(rl_dot(ze->s.ns, l)) * emitter_cos(&lv.light, l) / d2;
    rl_vec3 c = rl_scale(rl_mul(rl_mul(ze->beta, f), rl_mul(lv.beta, le)), g);
    if (!(rl_vmax_comp(c) > 0.0f) || !unoccluded(ctx, ze->p, ze->ng, lv.p, lv.ng, rays))
        return rl_v3s(0.0f);
    return rl_scale(c, mis_weight(ctx, sc, &lv, 1, z, t));
}

/* s, t >= 2: y_{s-1} and z_{t-1} joined. */
static rl_vec3 connect_inner(const bd_ctx *ctx, bd_scratch *sc, const bd_vertex *y, int s, const bd_vertex *z,
                             int t, uint64_t *rays)
{
    const bd_vertex *ye = &y[s - 1], *ze = &z[t - 1];
    if (ye->kind != BD_V_SURFACE || ze->kind != BD_V_SURFACE)
        return rl_v3s(0.0f);
    rl_vec3 to = rl_sub(ye->p, ze->p);
    float d2 = rl_length2(to);
    if (!(d2 > 0.0f))
        return rl_v3s(0.0f);
    rl_vec3 l = rl_scale(to, 1.0f / sqrtf(d2));
    rl_vec3 fz = bsdf_f(&ze->s, l);
    rl_vec3 fy = bsdf_f(&ye->s, rl_neg(l));
    if (!(rl_vmax_comp(fz) > 0.0f) || !(rl_vmax_comp(fy) > 0.0f))
        return rl_v3s(0.0f);
    fy = rl_scale(fy, adjoint_factor(&ye->s, rl_neg(l)));
    float g = fabsf(rl_dot(ze->s.ns, l)) * fabsf(rl_dot(ye->s.ns, l)) / d2;
    rl_vec3 c = rl_scale(rl_mul(rl_mul(ze->beta, fz), rl_mul(ye->beta, fy)), g);
    if (!(rl_vmax_comp(c) > 0.0f) || !unoccluded(ctx, ze->p, ze->ng, ye->p, ye->ng, rays))
        return rl_v3s(0.0f);
    return rl_scale(c, mis_weight(ctx, sc, y, s, z, t));
}

rl_vec3 bd_sample(const bd_ctx *ctx, bd_scratch *sc, rl_rng *rng, int x, int y, bd_splats *splats,
                  uint64_t *rays)
{
    /* pt's longest path has max_depth + 2 edges: max_depth + 3 vertices. */
    int max_vertices = ctx->max_depth + 3;
    bd_vertex *z = sc->camera, *yv = sc->light;
    rl_vec2 j = rl_v2(rl_rng_float(rng), rl_rng_float(rng));   /* box filter: uniform in the pixel */
    rl_ray ray = rl_camera_frame_ray(&ctx->cam, (float)x + j.x, (float)y + j.y);
    memset(&z[0], 0, sizeof z[0]);
    z[0].kind = BD_V_CAMERA;
    z[0].p = ctx->cam.eye;
    z[0].beta = rl_v3s(1.0f);
    bool escaped;
    int nz = walk(ctx, rng, ray, rl_v3s(1.0f), camera_pdf_dir(ctx, ray.d), false, false, z, 1, max_vertices,
                  &escaped, rays);
    int ny = bd_light_subpath(ctx, rng, yv, max_vertices - 1, rays);

    rl_vec3 L = rl_v3s(0.0f);
    if (escaped && wanted(ctx, 0, nz + 1)) {
        /* z[nz]: the direction the camera path left by, with its throughput. */
        bd_vertex *ze = &z[nz];
        if (ctx->environment) {
            ze->light.le = rl_environment_radiance(ctx->environment, ze->light.dir);
            ze->light.pdf_pos = ctx->env_pick * rl_pt_env_pdf(ctx->env, ze->light.dir);
            ze->light.hittable = true;
            if (rl_vmax_comp(ze->light.le) > 0.0f)
                L = rl_add(L, rl_scale(rl_mul(ze->beta, ze->light.le), mis_weight(ctx, sc, NULL, 0, z, nz + 1)));
        } else {
            L = rl_add(L, rl_mul(ze->beta, ctx->background));   /* no light samples it */
        }
    }
    for (int t = 1; t <= nz; ++t) {
        for (int s = 0; s <= (ny > 1 ? ny : 1); ++s) {
            if (s + t > max_vertices || (s == 1 && t == 1) || (s == 0 && t < 2) || !wanted(ctx, s, t))
                continue;
            if (s == 0) {
                const bd_vertex *ze = &z[t - 1];
                if (ze->light.kind == BD_LIGHT_NONE)
                    continue;
                rl_vec3 w = rl_normalize(rl_sub(z[t - 2].p, ze->p));
                rl_vec3 le = emitter_le(&ze->light, ze->p, w);
                if (rl_vmax_comp(le) > 0.0f)
                    L = rl_add(L, rl_scale(rl_mul(ze->beta, le), mis_weight(ctx, sc, NULL, 0, z, t)));
            } else if (t == 1) {
                connect_camera(ctx, sc, yv, s, &z[0], splats, rays);
            } else if (s == 1) {
                L = rl_add(L, connect_light(ctx, sc, rng, z, t, rays));
            } else {
                L = rl_add(L, connect_inner(ctx, sc, yv, s, z, t, rays));
            }
        }
    }
    return L;
}
