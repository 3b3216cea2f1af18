/* trace_shade.c: the local term of the Whitted tracer, Phong with hard
 * shadows (Ullmann 2003, Sec. 3.1: shadow feeler r_s = p_l - v_i, eq. 3.2)
 * and the transmitted highlight of eq. 3.17 (Sec. 3.5.2):
 *     emission + ambient k_d + sum over lights, visible:
 *         in front (n.l > 0):      E (k_d n.l + k_s max(0, r.v)^n)
 *         behind, k_t > 0:         E k_t max(0, t.v)^n
 * where t is the light's direction refracted through the surface into the
 * viewer's side (Snell with the material's ior: leaving the object when the
 * viewer is outside) and v points to the viewer: the thesis' cos^p φ_t, "φ_t
 * the angle between the transmitted ray and the view direction", with our
 * one Phong exponent n as p and the thesis' k_t as its coefficient. A
 * light is either in front of the surface or behind it, so each light adds
 * one of the two highlights (Sec. 3.5.2). The feeler to a light behind
 * leaves from the back side; like every feeler it is blocked by any surface,
 * also the far side of a closed glass object, so the term shows on thin
 * transmissive sheets (panes, the cluster's cover glass).
 * with the same light model as the raster renderer (raster.c), so that both
 * agree on unshadowed diffuse scenes:
 *  - point and spot: E = colour intensity / d^2, the spot cone fading with
 *    a smoothstep between the outer and inner half angles;
 *  - directional: E = colour intensity from -direction, feeler unbounded;
 *  - quad: an n x n grid of jittered points, each a small emitter of
 *    radiance colour intensity and area A/n^2 seen under cos_light, i.e.
 *    E_j = L A cos_light / (n^2 d^2). (raster.c approximates the same with
 *    one point at the centre.)
 * A feeler is traced only where it could change the result: the light
 * reaches the point (inside the cone, on the emitting side) and lies above
 * the shading normal. Transmissive occluders block like opaque ones: hard
 * shadows, as the thesis' ray tracer. With a ray tree the feeler asks for the
 * closest occluder (rl_accel_intersect) so the node names a well-defined
 * object; without one the cheaper any-hit query (rl_accel_occluded) does.
 *
 * The sum is returned in two parts for deferred texturing (Ullmann 2003,
 * Sec. 3.5.3): irr, the light k_d modulates (ambient included), and rest,
 * emission plus specular; the caller forms k_d irr + rest, with k_d
 * textured or not.
 *
 * Feeler cache (Sec. 3.4.5): the thesis keeps the shadow-feeler results of
 * primary vertices for the next frame while the lights stay. We cache the
 * depth-0 feelers of one point in tracing order and replay them instead of
 * tracing. The area-light jitter is drawn before the feeler either way, so a
 * replayed sample consumes the generator exactly like a traced one and the
 * results stay bit-identical. */
#include <math.h>

#include "scene/light_eval.h"
#include "render/trace_internal.h"

#define SHADOW_T_SHRINK 1e-4f     /* stop feelers short of the light itself */

/* Adds one visible light sample of irradiance E from unit l to the parts:
 * the cosine-weighted E to irr, the Phong highlight (k_s max(0, r.v)^n E)
 * to rest. */
static void add_light(rl_trace_local *acc, const rl_trace_surface *s, rl_vec3 l, float n_dot_l, rl_vec3 E)
{
    acc->irr = rl_add(acc->irr, rl_scale(E, n_dot_l));
    if (rl_vmax_comp(s->m->specular) > 0.0f) {
        rl_vec3 r = rl_sub(rl_scale(s->ns, 2.0f * n_dot_l), l);   /* l mirrored about n */
        float r_dot_v = rl_maxf(0.0f, rl_dot(r, s->v));
        acc->rest = rl_add(acc->rest, rl_mul(rl_scale(s->m->specular, powf(r_dot_v, s->m->shininess)), E));
    }
}

/* eq. 3.17: cos φ_t of a light in unit direction l behind the surface
 * (n.l < 0), or 0 (total internal reflection, or the transmitted light
 * leaves away from the viewer). */
static float transmitted_cos(const rl_trace_surface *s, rl_vec3 l)
{
    float ior = s->m->ior >= 1.0f ? s->m->ior : 1.0f;
    /* The light crosses from the far side into the viewer's: out of the
     * object when the viewer is outside it. */
    float eta = s->front ? ior : 1.0f / ior;
    rl_vec3 t;
    if (!rl_refract(rl_neg(l), rl_neg(s->ns), eta, &t))
        return 0.0f;
    float len = rl_length(t);
    return len > 0.0f ? rl_maxf(0.0f, rl_dot(t, s->v) / len) : 0.0f;
}

/* Adds the transmitted highlight k_t cos^n φ_t E of a light behind s
 * (eq. 3.17) to rest. */
static void add_transmitted(rl_trace_local *acc, const rl_trace_surface *s, float cos_t, rl_vec3 E)
{
    acc->rest = rl_add(acc->rest, rl_scale(E, s->m->transmissivity * powf(cos_t, s->m->shininess)));
}

/* Whether a light behind s could add eq. 3.17's term there: the surface
 * transmits and the term is on. */
static bool transmits(const rl_trace_ctx *ctx, const rl_trace_surface *s)
{
    return ctx->tracer->transmitted_highlight && s->m->transmissivity > 0.0f;
}

/* Occluder of a feeler by tracing it; RL_ID_NONE if the light is visible. */
static uint32_t trace_feeler(rl_trace_ctx *ctx, uint32_t slot, const rl_trace_surface *s, rl_vec3 l, float dist)
{
    const rl_tracer *tr = ctx->tracer;
    ctx->rays[RL_RAY_SHADOW]++;
    rl_ray ray = { rl_trace_offset(tr, s, l), 0.0f, l, isinf(dist) ? INFINITY : dist * (1.0f - SHADOW_T_SHRINK) };
    if (!ctx->tree || tr->tree_shadow_any_hit)
        return rl_trace_occluded(ctx, slot, &ray) ? RL_TRACE_OCCLUDER_UNKNOWN : RL_ID_NONE;
    rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
    return rl_trace_intersect(ctx, slot, &ray, &hit) ? hit.object : RL_ID_NONE;
}

/* One feeler from s towards unit l over dist; true if the light is visible.
 * Records the shadow ray and its node (occluder or RL_ID_NONE), one level
 * below the ray whose hit it lights, like a reflection would be. Depth-0
 * feelers are answered from and recorded into the cache. */
static bool feeler(rl_trace_ctx *ctx, const rl_trace_surface *s, rl_vec3 l, float dist, int depth,
                   uint32_t light)
{
    if (!ctx->tracer->shadows)
        return true;
    uint32_t occluder;
    uint32_t slot = rl_trace_slot(ctx);
    if (depth == 0 && ctx->cache_in && ctx->feelers < ctx->cache_in->count) {
        occluder = ctx->cache_in->occluder[ctx->feelers];
        ctx->reused++;
        rl_trace_record(ctx, slot, RL_ID_NONE);   /* the cache names no triangle */
    } else {
        occluder = trace_feeler(ctx, slot, s, l, dist);
    }
    rl_trace_tree_push(ctx, RL_RAY_SHADOW, depth + 1, occluder, light);
    if (depth == 0) {
        if (ctx->cache_out && ctx->feelers < RL_TRACE_FEELER_CACHE_MAX)
            ctx->cache_out->occluder[ctx->feelers] = occluder;
        ctx->feelers++;
    }
    return occluder == RL_ID_NONE;
}

/* Quad light (n x n jittered grid): the visible samples E_j into acc. */
static void quad_light(rl_trace_ctx *ctx, rl_trace_local *acc, const rl_trace_surface *s, const rl_light *L,
                       int depth, uint32_t index)
{
    rl_vec3 normal = rl_cross(L->edge_u, L->edge_v);
    float area = rl_length(normal);
    if (!(area > 0.0f))
        return;
    normal = rl_scale(normal, 1.0f / area);
    int n = ctx->tracer->area_samples;
    rl_vec3 radiance = rl_scale(L->color, L->intensity * area / (float)(n * n));
    for (int j = 0; j < n; ++j) {
        for (int i = 0; i < n; ++i) {
            /* Draw both numbers first so the sequence does not depend on
             * which samples are skipped, nor on whether the feeler is
             * traced or replayed from the cache. */
            float xi_u = rl_rng_float(&ctx->rng), xi_v = rl_rng_float(&ctx->rng);
            rl_vec3 q = rl_add(L->position, rl_add(rl_scale(L->edge_u, ((float)i + xi_u) / (float)n),
                                                   rl_scale(L->edge_v, ((float)j + xi_v) / (float)n)));
            rl_vec3 to_light = rl_sub(q, s->p);
            float d2 = rl_length2(to_light);
            if (!(d2 > 0.0f))
                continue;
            float dist = sqrtf(d2);
            rl_vec3 l = rl_scale(to_light, 1.0f / dist);
            float cos_light = -rl_dot(normal, l);
            float n_dot_l = rl_dot(s->ns, l);
            if (cos_light <= 0.0f)
                continue;
            if (n_dot_l <= 0.0f) {
                /* Behind the surface: eq. 3.17's transmitted highlight. */
                float cos_t = transmits(ctx, s) ? transmitted_cos(s, l) : 0.0f;
                if (cos_t > 0.0f && feeler(ctx, s, l, dist, depth, index))
                    add_transmitted(acc, s, cos_t, rl_scale(radiance, cos_light / d2));
                continue;
            }
            if (!feeler(ctx, s, l, dist, depth, index))
                continue;
            add_light(acc, s, l, n_dot_l, rl_scale(radiance, cos_light / d2));
        }
    }
}

rl_trace_local rl_trace_local_term(rl_trace_ctx *ctx, const rl_trace_surface *s, int depth)
{
    const rl_scene_data *data = ctx->tracer->data;
    rl_trace_local acc = { rl_v3s(ctx->tracer->ambient), s->m->emission };
    for (uint32_t i = 0; i < data->num_lights; ++i) {
        const rl_light *L = &data->lights[i];
        if (L->type == RL_LIGHT_QUAD) {
            quad_light(ctx, &acc, s, L, depth, i);
            continue;
        }
        rl_vec3 E, l;
        float dist;
        if (!rl_light_eval_delta(L, s->p, &E, &l, &dist))
            continue;
        float n_dot_l = rl_dot(s->ns, l);
        if (n_dot_l <= 0.0f) {
            /* Behind the surface: eq. 3.17's transmitted highlight. */
            float cos_t = transmits(ctx, s) ? transmitted_cos(s, l) : 0.0f;
            if (cos_t > 0.0f && feeler(ctx, s, l, dist, depth, i))
                add_transmitted(&acc, s, cos_t, E);
            continue;
        }
        if (!feeler(ctx, s, l, dist, depth, i))
            continue;
        add_light(&acc, s, l, n_dot_l, E);
    }
    return acc;
}
