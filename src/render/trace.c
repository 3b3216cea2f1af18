/* trace.c: the exact recursive ray tracer of rl_trace.h (Whitted 1980) with
 * the coefficient model of Ullmann 2003, Sec. 3.1, eq. 3.1-3.4:
 *     L = local Phong with shadow feelers (trace_shade.c)
 *       + k_r L(r_r),   r_r = r_p - 2 (r_p.n) n                  (eq. 3.3)
 *       + k_t L(r_t),   r_t by Snell with eta = eta_1/eta_2       (eq. 3.4)
 * recursively up to max_depth, or until the product of the coefficients
 * along the path drops below 1e-3 (it could not change the 8-bit result).
 *
 * Choices where the thesis leaves freedom:
 *  - the hit point is rebuilt from the barycentrics, p = (1-u-v)p0 + u p1 +
 *    v p2, so that rl_tracer_shade() on a vertex (u, v at a corner) shades
 *    exactly that vertex, and trace and shade agree bit for bit;
 *  - two-sided shading: the interpolated normal is flipped towards the
 *    incoming ray, as the raster renderer does for the viewer;
 *  - refraction enters when the geometric normal faces the ray (eta =
 *    1/ior) and leaves otherwise (eta = ior); total internal reflection adds
 *    k_t to the reflection coefficient;
 *  - self-intersection: secondary rays start offset along the geometric
 *    normal by eps = 1e-5 times the scene's size (largest absolute bound
 *    coordinate or diagonal), i.e. ~100 float ulps at that scale: enough for
 *    the barycentric point's rounding, far below any feature of our scenes.
 *
 * Ray tree (rl_trace.h): every ray actually traced gets one node, in the
 * order traced: a ray, then its shadow feelers (light order; a quad light
 * contributes one node per jittered sample traced), then its reflection
 * subtree, then its refraction subtree. Misses record RL_ID_NONE; a shadow
 * node names the closest occluder and sits one level below the ray whose hit
 * it lights, as that hit's reflection and refraction do.
 *
 * The local term comes back split (k_d irr + rest, trace_shade.c) so that
 * trace_point.c can defer the texture lookup of a hit (Sec. 3.5.3); here the
 * two are recombined at once with the textured k_d. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/trace_internal.h"

#define MIN_WEIGHT 1e-3f
#define MAX_DEPTH_LIMIT 64        /* recursion depth and rl_ray_tree_node.depth */
#define MAX_AREA_SAMPLES 32       /* 32 x 32 = 1024 feelers per quad light */
#define EPS_SCALE 1e-5f

bool rl_ray_tree_equal(const rl_ray_tree *a, const rl_ray_tree *b)
{
    if (!a || !b)
        return a == b;
    if (a->count != b->count || a->truncated != b->truncated)
        return false;
    /* Field by field: the node struct has padding bytes memcmp would see. */
    for (uint32_t i = 0; i < a->count && i < RL_RAY_TREE_MAX; ++i) {
        const rl_ray_tree_node *x = &a->nodes[i], *y = &b->nodes[i];
        if (x->type != y->type || x->depth != y->depth || x->object != y->object || x->light != y->light)
            return false;
    }
    return true;
}

/* Chains the splitmix64 finaliser over the fields rl_ray_tree_equal()
 * compares (never the padding), one 64-bit word at a time: each step is a
 * bijection of the running state, so trees differing in one word differ in
 * the hash except with probability ~2^-64. */
uint64_t rl_ray_tree_hash(const rl_ray_tree *tree)
{
    if (!tree)
        return 0;
    uint64_t h = rl_hash64(0x52544852ull ^ ((uint64_t)tree->count << 1) ^ (tree->truncated ? 1u : 0u));
    for (uint32_t i = 0; i < tree->count && i < RL_RAY_TREE_MAX; ++i) {
        const rl_ray_tree_node *n = &tree->nodes[i];
        h = rl_hash64(h ^ (((uint64_t)n->object << 32) | n->light));
        h = rl_hash64(h ^ ((uint64_t)n->type | ((uint64_t)n->depth << 8)));
    }
    return h;
}

uint32_t rl_trace_tree_push(rl_trace_ctx *ctx, rl_ray_type type, int depth, uint32_t object,
                            uint32_t light)
{
    rl_ray_tree *tree = ctx->tree;
    if (!tree)
        return RL_ID_NONE;
    if (tree->count >= RL_RAY_TREE_MAX) {
        tree->truncated = true;
        return RL_ID_NONE;
    }
    rl_ray_tree_node *n = &tree->nodes[tree->count];
    n->type = (uint8_t)type;
    n->depth = (uint8_t)depth;
    n->object = object;
    n->light = light;
    return tree->count++;
}

static float scene_scale(rl_aabb b)
{
    if (rl_aabb_is_empty(b) || !rl_vfinite(b.min) || !rl_vfinite(b.max))
        return 1.0f;
    float coord = rl_maxf(rl_vmax_comp(rl_vmax(b.min, rl_neg(b.min))), rl_vmax_comp(rl_vmax(b.max, rl_neg(b.max))));
    float s = rl_maxf(coord, rl_length(rl_aabb_extent(b)));
    return s > 0.0f ? s : 1.0f;
}

float rl_trace_origin_eps(rl_aabb bounds)
{
    return EPS_SCALE * scene_scale(bounds);
}

rl_status rl_tracer_create(const rl_accel *accel, const rl_tracer_desc *desc, rl_tracer **out)
{
    if (!accel || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_tracer_create: accel and out must not be NULL");
    rl_tracer_desc d;
    memset(&d, 0, sizeof d);
    if (desc)
        d = *desc;
    if (d.max_depth > MAX_DEPTH_LIMIT)
        return rl_error(RL_ERR_INVALID_ARG, "tracer: max_depth %d exceeds %d", d.max_depth, MAX_DEPTH_LIMIT);
    if (d.area_samples < 0 || d.area_samples > MAX_AREA_SAMPLES)
        return rl_error(RL_ERR_INVALID_ARG, "tracer: area_samples %d outside 0..%d", d.area_samples,
                        MAX_AREA_SAMPLES);
    if (!isfinite(d.ambient))
        return rl_error(RL_ERR_INVALID_ARG, "tracer: ambient is not finite");
    if (!rl_vfinite(d.background) || d.background.x < 0.0f || d.background.y < 0.0f ||
        d.background.z < 0.0f)
        return rl_error(RL_ERR_INVALID_ARG, "tracer: background must be finite and >= 0");
    const rl_scene *scene = rl_accel_scene(accel);
    const rl_scene_data *data = scene ? rl_scene_get_data(scene) : NULL;
    if (!data)
        return rl_error(RL_ERR_NOT_COMMITTED, "tracer: the accel's scene is not committed");

    rl_tracer *t = rl_calloc(1, sizeof *t);
    if (!t)
        return RL_ERR_OUT_OF_MEMORY;
    t->accel = accel;
    t->data = data;
    t->max_depth = d.max_depth == 0 ? 5 : (d.max_depth < 0 ? 0 : d.max_depth);
    t->area_samples = d.area_samples == 0 ? 4 : d.area_samples;
    t->ambient = d.ambient == 0.0f ? 0.05f : rl_maxf(d.ambient, 0.0f);
    t->background = d.background;
    t->shadows = !d.no_shadows;
    t->reflections = !d.no_reflections;
    t->transmission = !d.no_transmission;
    t->transmitted_highlight = !d.no_transmitted_highlight;
    t->tree_shadow_any_hit = d.tree_shadow_any_hit;
    t->defer_through = d.defer_through;
    /* Hints rely on the triangle test being the accelerator's own. */
    rl_accel_stats st;
    rl_accel_get_stats(accel, &st);
    t->hints = st.kind != RL_ACCEL_EMBREE;
    t->seed = d.seed;
    t->eps = rl_trace_origin_eps(data->bounds);
    *out = t;
    return RL_OK;
}

void rl_tracer_release(rl_tracer *tracer)
{
    free(tracer);
}

rl_vec3 rl_trace_offset(const rl_tracer *tracer, const rl_trace_surface *s, rl_vec3 dir)
{
    float side = rl_dot(dir, s->ng) >= 0.0f ? 1.0f : -1.0f;
    return rl_madd(s->p, s->ng, side * tracer->eps);
}

void rl_trace_surface_finish(const rl_tracer *tr, uint32_t tri_index, rl_vec3 ns, rl_vec2 uv, rl_vec3 v,
                             rl_trace_surface *s)
{
    const rl_scene_data *data = tr->data;
    const uint32_t *tri = &data->indices[3 * (size_t)tri_index];
    rl_vec3 p0 = data->positions[tri[0]], p1 = data->positions[tri[1]], p2 = data->positions[tri[2]];
    s->v = v;
    rl_vec3 ng = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
    ns = rl_normalize(rl_shading_normal(data, tri_index, ns, uv));
    if (!(rl_length2(ns) > 0.0f) || !rl_vfinite(ns))
        ns = ng;
    s->front = rl_dot(ng, v) > 0.0f;
    s->ns_front = !(rl_dot(ns, v) < 0.0f);
    s->ng = s->front ? ng : rl_neg(ng);
    s->ns = s->ns_front ? ns : rl_neg(ns);

    s->m = &data->materials[data->triangle_material[tri_index]];
    s->kd = s->m->diffuse;
    s->uv = uv;
    s->texture = RL_NONE;
    uint32_t tex = s->m->diffuse_texture;
    if (tex < data->num_textures && data->textures[tex]) {
        s->texture = tex;
        rl_vec4 texel = rl_texture_sample(data->textures[tex], uv);
        s->kd = rl_mul(s->kd, rl_v3(texel.x, texel.y, texel.z));
    }
}

/* Fills the surface at hit for a ray travelling along unit d; false for a
 * hit that names no triangle of the scene. */
static bool surface_at(const rl_tracer *tr, const rl_hit *hit, rl_vec3 d, rl_trace_surface *s)
{
    const rl_scene_data *data = tr->data;
    if (hit->triangle >= data->num_triangles)
        return false;
    const uint32_t *tri = &data->indices[3 * (size_t)hit->triangle];
    float u = hit->u, v = hit->v, w = 1.0f - u - v;
    rl_vec3 p0 = data->positions[tri[0]], p1 = data->positions[tri[1]], p2 = data->positions[tri[2]];
    s->p = rl_add(rl_add(rl_scale(p0, w), rl_scale(p1, u)), rl_scale(p2, v));
    rl_vec3 ns = rl_add(rl_add(rl_scale(data->normals[tri[0]], w), rl_scale(data->normals[tri[1]], u)),
                        rl_scale(data->normals[tri[2]], v));
    rl_vec2 t0 = data->uvs[tri[0]], t1 = data->uvs[tri[1]], t2 = data->uvs[tri[2]];
    rl_vec2 uv = rl_v2(w * t0.x + u * t1.x + v * t2.x, w * t0.y + u * t1.y + v * t2.y);
    rl_trace_surface_finish(tr, hit->triangle, ns, uv, rl_neg(d), s);
    return true;
}

int rl_trace_secondary_rays(const rl_tracer *tr, const rl_trace_surface *s, rl_vec3 d, float weight,
                            rl_trace_secondary out[2])
{
    float k_r = tr->reflections ? s->m->reflectivity : 0.0f;
    float k_t = tr->transmission ? s->m->transmissivity : 0.0f;
    rl_vec3 refracted = rl_v3s(0.0f);
    if (k_t > 0.0f) {
        /* Entering when the geometric normal faced the ray (eq. 3.4 with
         * eta_1/eta_2 = 1/ior), leaving into air otherwise. */
        float ior = s->m->ior >= 1.0f ? s->m->ior : 1.0f;
        float eta = s->front ? 1.0f / ior : ior;
        if (!rl_refract(d, s->ns, eta, &refracted)) {
            k_r += tr->reflections ? k_t : 0.0f;   /* total internal reflection */
            k_t = 0.0f;
        }
    }
    int n = 0;
    if (k_r > 0.0f && weight * k_r >= MIN_WEIGHT) {
        rl_vec3 dir = rl_reflect(d, s->ns);
        out[n++] = (rl_trace_secondary){ { rl_trace_offset(tr, s, dir), 0.0f, dir, INFINITY },
                                         RL_RAY_REFLECTION, k_r };
    }
    if (k_t > 0.0f && weight * k_t >= MIN_WEIGHT) {
        rl_vec3 dir = rl_normalize(refracted);
        out[n++] = (rl_trace_secondary){ { rl_trace_offset(tr, s, dir), 0.0f, dir, INFINITY },
                                         RL_RAY_REFRACTION, k_t };
    }
    return n;
}

/* Radiance leaving s back along unit d (eq. 3.1-3.4), local term then the
 * weighted reflection and refraction; layer (may be NULL) gets it split as
 * rl_trace_ray() documents. */
static rl_vec3 shade_surface(rl_trace_ctx *ctx, const rl_trace_surface *s, rl_vec3 d, int depth, float weight,
                             rl_trace_layer *layer)
{
    const rl_tracer *tr = ctx->tracer;
    rl_trace_local local = rl_trace_local_term(ctx, s, depth);
    rl_vec3 color = rl_add(rl_mul(s->kd, local.irr), local.rest);
    rl_vec3 rest = local.rest;
    rl_trace_secondary sec[2];
    int n = depth < tr->max_depth ? rl_trace_secondary_rays(tr, s, d, weight, sec) : 0;
    if (layer && tr->defer_through && s->texture == RL_NONE && n > 0) {
        /* Deferral through an untextured surface (rl_tracer_desc): its own
         * terms need no texel and go to rest; the strongest secondary ray
         * that ends on a textured surface hands its layer on, scaled by its
         * coefficient; the other ray is looked up here. */
        rl_trace_layer sub[2];
        int pick = -1;
        float best = 0.0f;
        for (int i = 0; i < n; ++i) {
            rl_vec3 c = rl_trace_ray(ctx, sec[i].ray, sec[i].type, depth + 1, weight * sec[i].k, &sub[i]);
            color = rl_add(color, rl_scale(c, sec[i].k));
            float strength = sec[i].k * rl_vmax_comp(sub[i].diffuse);
            if (sub[i].texture != RL_NONE && (pick < 0 || strength > best)) {
                pick = i;
                best = strength;
            }
        }
        rest = rl_add(rest, rl_mul(s->m->diffuse, local.irr));
        for (int i = 0; i < n; ++i)
            if (i != pick)
                rest = rl_add(rest, rl_scale(rl_trace_layer_color(tr->data, &sub[i]), sec[i].k));
        if (pick < 0) {
            *layer = (rl_trace_layer){ rl_v3s(0.0f), rest, RL_NONE, s->uv };
        } else {
            *layer = (rl_trace_layer){ rl_scale(sub[pick].diffuse, sec[pick].k),
                                       rl_add(rest, rl_scale(sub[pick].rest, sec[pick].k)), sub[pick].texture,
                                       sub[pick].uv };
        }
        return color;
    }
    for (int i = 0; i < n; ++i) {
        rl_vec3 c = rl_trace_ray(ctx, sec[i].ray, sec[i].type, depth + 1, weight * sec[i].k, NULL);
        c = rl_scale(c, sec[i].k);
        color = rl_add(color, c);
        rest = rl_add(rest, c);
    }
    if (layer)
        *layer = (rl_trace_layer){ rl_mul(s->m->diffuse, local.irr), rest, s->texture, s->uv };
    return color;
}

/* What a ray along dir that leaves the scene sees: the scene's environment
 * (issue 37; pt samples it as a light, here it is only seen in mirrors,
 * through glass and past the objects) or the background option. */
static rl_vec3 escape(const rl_tracer *tr, rl_vec3 dir)
{
    const rl_environment *env = tr->data->environment;
    if (!env || !(rl_length2(dir) > 0.0f) || !rl_vfinite(dir))
        return tr->background;
    return rl_environment_radiance(env, rl_normalize(dir));
}

static rl_vec3 miss(const rl_tracer *tr, rl_vec3 dir, rl_trace_layer *layer)
{
    rl_vec3 bg = escape(tr, dir);
    if (layer)
        *layer = (rl_trace_layer){ rl_v3s(0.0f), bg, RL_NONE, rl_v2(0.0f, 0.0f) };
    return bg;
}

/* Radiance leaving the surface at hit back along ray. */
static rl_vec3 shade_hit(rl_trace_ctx *ctx, const rl_ray *ray, const rl_hit *hit, int depth, float weight,
                         rl_trace_layer *layer)
{
    rl_vec3 d = rl_normalize(ray->d);
    rl_trace_surface s;
    if (!surface_at(ctx->tracer, hit, d, &s))
        return miss(ctx->tracer, d, layer);
    return shade_surface(ctx, &s, d, depth, weight, layer);
}

/* ---------------------------------------------- intersection hints -- */

/* Ullmann 2003, Sec. 3.3.1 (Fig. 3.7: the ray tree also serves object-space
 * coherence) and Sec. 6.2.2 (faster collision detection for the samples of
 * refinement, which lie between samples already traced). A hinted
 * triangle is a guess, so each use must give what the full query gives:
 *  - any hit (shadow feelers without a tree): the query asks whether some
 *    triangle not in a hole is hit in (t_min, t_max). A hinted triangle
 *    hit there by the very test the accelerator runs (watertight.h, the
 *    same floats) is such a triangle: the answer is yes, and the search is
 *    skipped.
 *  - closest hit: the accelerators of ours return the hit of least t, ties
 *    to the lowest triangle ID (accel.c), whatever the t_max they start
 *    from, as long as that hit is below it; a hinted hit at t_h proves the
 *    closest one is at t <= t_h, so a search up to nextafter(t_h), which
 *    still admits ties at t_h, finds the same hit; its boxes beyond t_h are
 *    culled, which is the whole gain (the traversal is built to be exact
 *    from any bound, since it shrinks its own as it goes). Should that
 *    search come back empty (an alpha-mask hole at t_h hides the rest of
 *    its interval), the full search runs after all.
 * The hinted hit itself is never returned: the search finds it again, so
 * the result cannot depend on the hint. */

uint32_t rl_trace_slot(rl_trace_ctx *ctx)
{
    return ctx->slot++;
}

void rl_trace_record(rl_trace_ctx *ctx, uint32_t slot, uint32_t triangle)
{
    rl_trace_hints *h = ctx->hint_out;
    if (!h || slot >= RL_TRACE_HINT_MAX)
        return;
    while (h->count < slot)
        h->triangle[h->count++] = RL_ID_NONE;
    h->triangle[slot] = triangle;
    if (h->count <= slot)
        h->count = slot + 1;
}

/* The distinct triangles the hint lists name in slot (0-2). */
static int hints_at(const rl_trace_ctx *ctx, uint32_t slot, uint32_t cand[2])
{
    int n = 0;
    for (int i = 0; i < 2; ++i) {
        const rl_trace_hints *h = ctx->hint_in[i];
        if (!h || slot >= h->count || slot >= RL_TRACE_HINT_MAX)
            continue;
        uint32_t t = h->triangle[slot];
        if (t != RL_ID_NONE && (n == 0 || cand[0] != t))
            cand[n++] = t;
    }
    return n;
}

bool rl_trace_intersect(rl_trace_ctx *ctx, uint32_t slot, rl_ray *ray, rl_hit *hit)
{
    const rl_accel *accel = ctx->tracer->accel;
    uint32_t cand[2];
    int n = hints_at(ctx, slot, cand);
    bool found = false;
    if (n) {
        ctx->hint_tests++;
        float t_h = INFINITY;
        for (int i = 0; i < n; ++i) {
            rl_hit h;
            if (rl_accel_intersect_triangle(accel, ray, cand[i], &h) && h.t < t_h)
                t_h = h.t;
        }
        if (t_h < INFINITY) {
            ctx->hint_hits++;
            rl_ray bounded = *ray;
            bounded.t_max = nextafterf(t_h, INFINITY);   /* <= ray->t_max, as t_h < it */
            if ((found = rl_accel_intersect(accel, &bounded, hit)))
                ray->t_max = bounded.t_max;
        }
    }
    if (!found)
        found = rl_accel_intersect(accel, ray, hit);
    rl_trace_record(ctx, slot, found ? hit->triangle : RL_ID_NONE);
    return found;
}

bool rl_trace_occluded(rl_trace_ctx *ctx, uint32_t slot, const rl_ray *ray)
{
    const rl_accel *accel = ctx->tracer->accel;
    uint32_t cand[2];
    int n = hints_at(ctx, slot, cand);
    if (n)
        ctx->hint_tests++;
    for (int i = 0; i < n; ++i) {
        rl_hit h;
        if (rl_accel_intersect_triangle(accel, ray, cand[i], &h)) {
            ctx->hint_hits++;
            rl_trace_record(ctx, slot, cand[i]);
            return true;
        }
    }
    if (!ctx->hint_out)
        return rl_accel_occluded(accel, ray);
    uint32_t tri;
    bool blocked = rl_accel_occluder(accel, ray, &tri);
    rl_trace_record(ctx, slot, tri);
    return blocked;
}

rl_vec3 rl_trace_ray(rl_trace_ctx *ctx, rl_ray ray, rl_ray_type type, int depth, float weight,
                     rl_trace_layer *layer)
{
    ctx->rays[type]++;
    uint32_t node = rl_trace_tree_push(ctx, type, depth, RL_ID_NONE, RL_ID_NONE);
    rl_hit hit = { INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
    if (!rl_trace_intersect(ctx, rl_trace_slot(ctx), &ray, &hit))
        return miss(ctx->tracer, ray.d, layer);
    if (node != RL_ID_NONE)
        ctx->tree->nodes[node].object = hit.object;
    return shade_hit(ctx, &ray, &hit, depth, weight, layer);
}

void rl_trace_begin(const rl_tracer *tracer, uint64_t sample_id, uint64_t *rays, rl_ray_tree *tree,
                    rl_trace_ctx *ctx)
{
    memset(rays, 0, RL_RAY_TYPE_COUNT * sizeof *rays);
    if (tree) {
        tree->count = 0;
        tree->truncated = false;
    }
    memset(ctx, 0, sizeof *ctx);
    ctx->tracer = tracer;
    ctx->rays = rays;
    ctx->tree = tree;
    rl_rng_seed(&ctx->rng, rl_hash64(tracer->seed ^ rl_hash64(sample_id)), sample_id);
}

/* Shared start of trace and shade: result zeroed, then rl_trace_begin. */
static void begin(const rl_tracer *tracer, uint64_t sample_id, rl_trace_result *out, rl_ray_tree *tree,
                  rl_trace_ctx *ctx)
{
    memset(out, 0, sizeof *out);
    out->hit = (rl_hit){ INFINITY, 0.0f, 0.0f, RL_ID_NONE, RL_ID_NONE };
    rl_trace_begin(tracer, sample_id, out->rays, tree, ctx);
}

static rl_ray_type valid_type(rl_ray_type type)
{
    return (unsigned)type < RL_RAY_TYPE_COUNT ? type : RL_RAY_PRIMARY;
}

void rl_tracer_trace(const rl_tracer *tracer, const rl_ray *ray, rl_ray_type type, uint64_t sample_id,
                     rl_trace_result *out, rl_ray_tree *tree)
{
    if (!tracer || !ray || !out)
        return;
    rl_trace_ctx ctx;
    begin(tracer, sample_id, out, tree, &ctx);
    type = valid_type(type);
    ctx.rays[type]++;
    uint32_t node = rl_trace_tree_push(&ctx, type, 0, RL_ID_NONE, RL_ID_NONE);
    rl_ray r = *ray;
    rl_hit hit = out->hit;
    if (!rl_accel_intersect(tracer->accel, &r, &hit)) {
        out->color = escape(tracer, r.d);
        return;
    }
    if (node != RL_ID_NONE)
        tree->nodes[node].object = hit.object;
    out->hit = hit;
    out->color = shade_hit(&ctx, &r, &hit, 0, 1.0f, NULL);
}

void rl_tracer_shade(const rl_tracer *tracer, const rl_ray *ray, const rl_hit *hit, rl_ray_type type,
                     uint64_t sample_id, rl_trace_result *out, rl_ray_tree *tree)
{
    if (!tracer || !ray || !hit || !out)
        return;
    rl_trace_ctx ctx;
    begin(tracer, sample_id, out, tree, &ctx);
    type = valid_type(type);
    ctx.rays[type]++;
    /* A hit naming no triangle, or a ray with no usable direction, is a miss:
     * there is no surface (or no viewer direction) to shade. */
    bool usable = hit->triangle < tracer->data->num_triangles && rl_vfinite(ray->d) &&
                  rl_length2(ray->d) > 0.0f;
    uint32_t object = usable ? tracer->data->triangle_object[hit->triangle] : RL_ID_NONE;
    rl_trace_tree_push(&ctx, type, 0, object, RL_ID_NONE);
    if (!usable) {
        out->color = tracer->background;
        return;
    }
    out->hit = *hit;
    out->hit.object = object;
    out->color = shade_hit(&ctx, ray, &out->hit, 0, 1.0f, NULL);
}
