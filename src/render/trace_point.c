/* trace_point.c: Vertex Tracing samples (Ullmann 2003) on the exact tracer.
 *
 * A VT vertex is shaded where it lies: the primary ray eye -> v_i (eq. 3.1)
 * is not traced, its hit is the vertex with the refined position and normal
 * (eq. 3.7, 3.8). The result is I(v_i) = I_local + k_r I_refl + k_t I_trans
 * (eq. 3.18, 3.19), kept as three deferred-texture layers (Sec. 3.5.3): the
 * thesis stores only texture coordinates for the primary surface and the
 * surfaces the first reflection and refraction see, and the rasterizer looks
 * the texels up per fragment (eq. 3.20, 3.21). Levels > 1 are sampled with
 * their textures, as the thesis does. Each layer is diffuse * texel + rest:
 *  - diffuse = k (k_r, k_t or 1) * untextured k_d * the light k_d modulates,
 *  - rest = k * (emission + specular + that surface's deeper recursion),
 *    i.e. C_comb of eq. 3.21 lands in the untextured part, which is eq. 3.20
 *    exactly, not the approximation eq. 3.22 the thesis adopts for its
 *    fixed-function blending.
 * Because the split is exact, the recombined colour equals what
 * rl_tracer_shade() returns for the same surface point up to float rounding;
 * flat (texels taken as white) drives refinement without texture noise.
 *
 * Feeler cache (Sec. 3.4.5): see trace_shade.c. The cache is keyed on the
 * side of the shading normal the viewer is on, since that side alone decides
 * which feelers are shot (n.l > 0 with the flipped normal); their origins do
 * not depend on the view. A cache filled without a ray tree knows blocked
 * feelers only as RL_TRACE_OCCLUDER_UNKNOWN; replaying it into a tree would
 * make the tree inexact, so such a cache is traced afresh then. */
#include <string.h>

#include "render/trace_internal.h"

static bool cache_matches(const rl_trace_feelers *c, bool front, bool with_tree)
{
    if (!c->complete || c->front != front || c->count > RL_TRACE_FEELER_CACHE_MAX)
        return false;
    for (uint32_t i = 0; with_tree && i < c->count; ++i)
        if (c->occluder[i] == RL_TRACE_OCCLUDER_UNKNOWN)
            return false;
    return true;
}

rl_vec3 rl_trace_layer_color(const rl_scene_data *data, const rl_trace_layer *layer)
{
    rl_vec3 diffuse = layer->diffuse;
    if (layer->texture != RL_NONE && layer->texture < data->num_textures && data->textures[layer->texture]) {
        rl_vec4 texel = rl_texture_sample(data->textures[layer->texture], layer->uv);
        diffuse = rl_mul(diffuse, rl_v3(texel.x, texel.y, texel.z));
    }
    return rl_add(diffuse, layer->rest);
}

/* Depth-0 local term and first-level secondary rays of the usable point s. */
static void shade_layers(rl_trace_ctx *ctx, const rl_trace_surface *s, rl_trace_sample *out)
{
    const rl_tracer *tr = ctx->tracer;
    rl_trace_local local = rl_trace_local_term(ctx, s, 0);
    out->layers[RL_TRACE_LAYER_PRIMARY] =
        (rl_trace_layer){ rl_mul(s->m->diffuse, local.irr), local.rest, s->texture, s->uv };
    if (tr->max_depth <= 0)
        return;
    rl_trace_secondary sec[2];
    int n = rl_trace_secondary_rays(tr, s, rl_neg(s->v), 1.0f, sec);
    for (int i = 0; i < n; ++i) {
        rl_trace_layer hit;
        rl_trace_ray(ctx, sec[i].ray, sec[i].type, 1, sec[i].k, &hit);
        hit.diffuse = rl_scale(hit.diffuse, sec[i].k);
        hit.rest = rl_scale(hit.rest, sec[i].k);
        int slot = sec[i].type == RL_RAY_REFLECTION ? RL_TRACE_LAYER_REFLECTION : RL_TRACE_LAYER_REFRACTION;
        out->layers[slot] = hit;
    }
}

void rl_tracer_shade_point(const rl_tracer *tracer, rl_vec3 eye, const rl_trace_point *pt, uint64_t sample_id,
                           const rl_trace_feelers *cache_in, rl_trace_feelers *cache_out, rl_trace_sample *out,
                           rl_ray_tree *tree)
{
    rl_tracer_shade_point_hinted(tracer, eye, pt, sample_id, cache_in, cache_out, NULL, NULL, out, tree);
}

void rl_tracer_shade_point_hinted(const rl_tracer *tracer, rl_vec3 eye, const rl_trace_point *pt,
                                  uint64_t sample_id, const rl_trace_feelers *cache_in, rl_trace_feelers *cache_out,
                                  const rl_trace_hints *const hint_in[2], rl_trace_hints *hint_out,
                                  rl_trace_sample *out, rl_ray_tree *tree)
{
    if (!tracer || !pt || !out)
        return;
    const rl_scene_data *data = tracer->data;
    memset(out, 0, sizeof *out);
    for (int i = 0; i < RL_TRACE_LAYER_COUNT; ++i)
        out->layers[i].texture = RL_NONE;
    rl_trace_ctx ctx;
    rl_trace_begin(tracer, sample_id, out->rays, tree, &ctx);
    ctx.rays[RL_RAY_PRIMARY]++;
    if (hint_out)
        hint_out->count = 0;
    if (tracer->hints) {
        if (hint_in) {
            ctx.hint_in[0] = hint_in[0];
            ctx.hint_in[1] = hint_in[1];
        }
        ctx.hint_out = hint_out;
    }

    /* Like rl_tracer_shade(): no triangle, or no direction to the eye, is a
     * miss; the point's own object names the primary node otherwise. */
    rl_vec3 v = rl_normalize(rl_sub(eye, pt->p));
    bool usable = pt->triangle < data->num_triangles && rl_vfinite(v) && rl_length2(v) > 0.0f;
    rl_trace_tree_push(&ctx, RL_RAY_PRIMARY, 0, usable ? data->triangle_object[pt->triangle] : RL_ID_NONE,
                       RL_ID_NONE);
    if (!usable) {
        out->layers[RL_TRACE_LAYER_PRIMARY].rest = tracer->background;
        out->color = out->flat = tracer->background;
        if (cache_out)
            *cache_out = (rl_trace_feelers){ .count = 0, .front = false, .complete = false };
        return;
    }

    rl_trace_surface s;
    s.p = pt->p;
    rl_trace_surface_finish(tracer, pt->triangle, pt->n, pt->uv, v, &s);
    /* Replay from a copy: cache_in may be cache_out, which the feelers
     * overwrite as they go. */
    rl_trace_feelers replay;
    if (cache_in && cache_matches(cache_in, s.ns_front, tree != NULL && !tracer->tree_shadow_any_hit)) {
        replay = *cache_in;
        ctx.cache_in = &replay;
    }
    ctx.cache_out = cache_out;
    shade_layers(&ctx, &s, out);
    if (cache_out) {
        cache_out->count = ctx.feelers < RL_TRACE_FEELER_CACHE_MAX ? ctx.feelers : RL_TRACE_FEELER_CACHE_MAX;
        cache_out->front = s.ns_front;
        cache_out->complete = ctx.feelers <= RL_TRACE_FEELER_CACHE_MAX;
    }
    out->feelers_reused = ctx.reused;
    out->hint_tests = ctx.hint_tests;
    out->hint_hits = ctx.hint_hits;

    for (int i = 0; i < RL_TRACE_LAYER_COUNT; ++i) {
        const rl_trace_layer *layer = &out->layers[i];
        out->color = rl_add(out->color, rl_trace_layer_color(data, layer));
        out->flat = rl_add(out->flat, rl_add(layer->diffuse, layer->rest));
    }
}
