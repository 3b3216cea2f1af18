/* pathtrace_lights.c: the light table of "pt" with mis=on: which light a
 * next-event sample goes to, chosen in proportion to the light's power
 * (a cumulative distribution searched by bisection), so the dim lamps of a
 * scene do not cost as many shadow rays as the bright ones.
 *
 * Power, in the mean of the colour channels (any positive choice is
 * unbiased; this one only steers the variance):
 *   point            4 pi I
 *   spot             2 pi (1 - cos(outer)) I: the cone's solid angle
 *   directional      pi r^2 I, r the radius of the scene's bounding sphere
 *   quad             pi A L (one-sided Lambertian emitter)
 *   emissive triangle not covered by a quad light: 2 pi A L_e (it emits on
 *                    both sides, pathtrace_path.c's emission rule)
 *
 * A quad light is "hittable" when the emissive triangles it covers fill
 * its whole parallelogram: then a BSDF ray can find it and the two
 * strategies are weighted by MIS; otherwise only light sampling reaches it
 * and its samples keep the full weight. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/pathtrace_internal.h"

/* Covered triangles must fill the quad to this relative tolerance. */
#define HITTABLE_AREA_TOL 1e-3f

static float mean3(rl_vec3 c)
{
    return (c.x + c.y + c.z) * (1.0f / 3.0f);
}

float rl_pt_triangle_area(const rl_scene_data *d, uint32_t t, rl_vec3 *normal)
{
    const uint32_t *idx = &d->indices[3 * (size_t)t];
    rl_vec3 p0 = d->positions[idx[0]];
    rl_vec3 n = rl_cross(rl_sub(d->positions[idx[1]], p0), rl_sub(d->positions[idx[2]], p0));
    float len = rl_length(n);
    if (normal)
        *normal = len > 0.0f ? rl_scale(n, 1.0f / len) : rl_v3(0.0f, 0.0f, 1.0f);
    return 0.5f * len;
}

static float light_power(const rl_light *L, float radius)
{
    float I = L->intensity * mean3(L->color);
    switch (L->type) {
    case RL_LIGHT_POINT:
        return 4.0f * RL_PI * I;
    case RL_LIGHT_SPOT: {
        float outer = rl_radians(rl_clampf(L->spot_outer_deg, 0.0f, 180.0f));
        return 2.0f * RL_PI * (1.0f - cosf(outer)) * I;
    }
    case RL_LIGHT_DIRECTIONAL:
        return RL_PI * radius * radius * I;
    case RL_LIGHT_QUAD:
        return RL_PI * rl_length(rl_cross(L->edge_u, L->edge_v)) * I;
    default:
        return 0.0f;
    }
}

void rl_pt_lights_release(pt_lights *l)
{
    free(l->source);
    free(l->cdf);
    free(l->light_pmf);
    free(l->light_hittable);
    free(l->light_area);
    free(l->light_normal);
    free(l->tri_pmf);
    memset(l, 0, sizeof *l);
}

rl_status rl_pt_lights_build(pt_backends *b, const rl_scene_data *d)
{
    pt_lights *l = &b->lights;
    rl_pt_lights_release(l);
    size_t entries = (size_t)d->num_lights + d->num_triangles;
    double *power = rl_calloc(entries ? entries : 1, sizeof *power);
    double *covered = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *covered);
    l->source = rl_calloc(entries ? entries : 1, sizeof *l->source);
    l->cdf = rl_calloc(entries + 1, sizeof *l->cdf);
    l->light_pmf = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *l->light_pmf);
    l->light_hittable = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *l->light_hittable);
    l->light_area = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *l->light_area);
    l->light_normal = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *l->light_normal);
    l->tri_pmf = rl_calloc(d->num_triangles ? d->num_triangles : 1, sizeof *l->tri_pmf);
    if (!power || !covered || !l->source || !l->cdf || !l->light_pmf || !l->light_hittable || !l->light_area ||
        !l->light_normal || !l->tri_pmf) {
        free(power);
        free(covered);
        rl_pt_lights_release(l);
        return RL_ERR_OUT_OF_MEMORY;
    }
    bool bounded = !rl_aabb_is_empty(d->bounds) && rl_vfinite(d->bounds.min) && rl_vfinite(d->bounds.max);
    l->centre = bounded ? rl_scale(rl_add(d->bounds.min, d->bounds.max), 0.5f) : rl_v3s(0.0f);
    l->radius = bounded ? rl_maxf(0.5f * rl_length(rl_aabb_extent(d->bounds)), 1e-6f) : 1.0f;

    double total = 0.0;
    uint32_t n = 0;
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        float p = light_power(&d->lights[i], l->radius);
        if (!(p > 0.0f) || !isfinite(p))
            continue;
        l->source[n] = i;
        power[n++] = p;
        total += p;
    }
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        rl_vec3 e = d->materials[d->triangle_material[t]].emission;
        if (!(rl_vmax_comp(e) > 0.0f))
            continue;
        float area = rl_pt_triangle_area(d, t, NULL);
        if (b->tri_cover[t] != RL_NONE) {
            covered[b->tri_cover[t]] += area;
            continue;
        }
        float p = 2.0f * RL_PI * area * mean3(e);
        if (!(p > 0.0f) || !isfinite(p))
            continue;
        l->source[n] = d->num_lights + t;
        power[n++] = p;
        total += p;
    }
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        rl_vec3 n_e = rl_cross(L->edge_u, L->edge_v);
        float area = rl_length(n_e);
        l->light_area[i] = area;
        l->light_normal[i] = rl_scale(n_e, 1.0f / area);
        l->light_hittable[i] = L->type == RL_LIGHT_QUAD && area > 0.0f &&
                               fabs(covered[i] - area) <= HITTABLE_AREA_TOL * area;
    }
    free(covered);
    if (!(total > 0.0)) {
        free(power);
        l->count = 0;
        return RL_OK;
    }
    double run = 0.0;
    for (uint32_t k = 0; k < n; ++k) {
        l->cdf[k] = (float)(run / total);
        run += power[k];
        float pmf = (float)(power[k] / total);
        if (l->source[k] < d->num_lights)
            l->light_pmf[l->source[k]] = pmf;
        else
            l->tri_pmf[l->source[k] - d->num_lights] = pmf;
    }
    l->cdf[n] = 1.0f;
    l->count = n;
    free(power);
    return RL_OK;
}

uint32_t rl_pt_lights_pick(const pt_lights *l, float u)
{
    /* The last k with cdf[k] <= u; entries of zero width are never hit
     * because their cdf equals the next one's. */
    uint32_t lo = 0, hi = l->count;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (l->cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}
