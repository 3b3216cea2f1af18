/* accel.c: the generic acceleration-structure layer behind rl_accel.h.
 *
 * Like Embree's API: create borrows a committed scene and checks the desc,
 * commit builds (timed here, so every kind reports build_ms the same way),
 * queries are thread-safe and cannot fail. Rays that no structure could
 * answer meaningfully (NaN/Inf origin, direction or t_min, zero direction,
 * NaN t_max, t_min > t_max) are turned away here, so the per-kind classes
 * (accel_internal.h) never see them. Every kind of ours breaks ties the same
 * way: among hits at equal t, the lowest triangle ID wins. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel_internal.h"
#include "core/error.h"
#include "rl/rl_timer.h"

struct rl_accel {
    const rl_scene *scene;
    const rl_scene_data *data;
    rl_accel_desc desc;
    const rl_accel_class *cls;
    void *state;
    bool committed;
    bool masked;              /* some material has an alpha mask */
    rl_accel_stats stats;
};

static const char *const kind_names[RL_ACCEL_KIND_COUNT] = {
    [RL_ACCEL_BVH] = "bvh",
    [RL_ACCEL_GRID] = "grid",
    [RL_ACCEL_EMBREE] = "embree",
    [RL_ACCEL_BRUTE] = "brute",
};

const char *rl_accel_kind_name(rl_accel_kind kind)
{
    if ((int)kind < 0 || kind >= RL_ACCEL_KIND_COUNT)
        return "unknown";
    return kind_names[kind];
}

rl_status rl_accel_kind_parse(const char *name, rl_accel_kind *out)
{
    if (!name || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_accel_kind_parse: NULL argument");
    for (int k = 0; k < RL_ACCEL_KIND_COUNT; ++k)
        if (strcmp(name, kind_names[k]) == 0) {
            *out = (rl_accel_kind)k;
            return RL_OK;
        }
    return rl_error(RL_ERR_NOT_FOUND, "accel: unknown kind \"%s\" (known: bvh, grid, embree, brute)",
                    name);
}

bool rl_accel_kind_available(rl_accel_kind kind)
{
    switch (kind) {
    case RL_ACCEL_BVH:
    case RL_ACCEL_GRID:
    case RL_ACCEL_BRUTE:
        return true;
    case RL_ACCEL_EMBREE:
#ifdef RL_HAVE_EMBREE
        return true;
#else
        return false;
#endif
    default:
        return false;
    }
}

static const rl_accel_class *class_of(rl_accel_kind kind)
{
    switch (kind) {
    case RL_ACCEL_BVH: return &rl_accel_bvh_class;
    case RL_ACCEL_GRID: return &rl_accel_grid_class;
    case RL_ACCEL_BRUTE: return &rl_accel_brute_class;
#ifdef RL_HAVE_EMBREE
    case RL_ACCEL_EMBREE: return &rl_accel_embree_class;
#endif
    default: return NULL;
    }
}

static rl_status check_desc(const rl_accel_desc *d)
{
    if ((int)d->kind < 0 || d->kind >= RL_ACCEL_KIND_COUNT)
        return rl_error(RL_ERR_INVALID_ARG, "accel: kind %d out of range", (int)d->kind);
    if (d->threads < 0)
        return rl_error(RL_ERR_INVALID_ARG, "accel: threads %d < 0", d->threads);
    if (d->bvh_leaf_size < 0 || d->bvh_leaf_size > 64)
        return rl_error(RL_ERR_INVALID_ARG, "accel: bvh_leaf_size %d not in 0..64", d->bvh_leaf_size);
    if (d->bvh_bins != 0 && (d->bvh_bins < 2 || d->bvh_bins > 256))
        return rl_error(RL_ERR_INVALID_ARG, "accel: bvh_bins %d not 0 or in 2..256", d->bvh_bins);
    if (d->bvh_block_cost != 0 && d->bvh_block_cost != 1)
        return rl_error(RL_ERR_INVALID_ARG, "accel: bvh_block_cost %d not 0 or 1", d->bvh_block_cost);
    if (!isfinite(d->grid_lambda) || d->grid_lambda < 0.0f)
        return rl_error(RL_ERR_INVALID_ARG, "accel: grid_lambda %g must be finite and >= 0",
                        (double)d->grid_lambda);
    for (int a = 0; a < 3; ++a)
        if (d->grid_res[a] < 0 || d->grid_res[a] > 4096)
            return rl_error(RL_ERR_INVALID_ARG, "accel: grid_res[%d] = %d not in 0..4096", a,
                            d->grid_res[a]);
    return RL_OK;
}

rl_status rl_accel_create(const rl_scene *scene, const rl_accel_desc *desc, rl_accel **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_accel_create: NULL scene or out");
    rl_accel_desc d = desc ? *desc : (rl_accel_desc){ 0 };
    rl_status s = check_desc(&d);
    if (s)
        return s;
    if (!rl_accel_kind_available(d.kind))
        return rl_error(RL_ERR_UNSUPPORTED, "accel: kind \"%s\" is not in this build",
                        rl_accel_kind_name(d.kind));
    if (!rl_scene_is_committed(scene))
        return rl_error(RL_ERR_NOT_COMMITTED, "accel: the scene must be committed first");
    const rl_scene_data *data = rl_scene_get_data(scene);
    if (!data)
        return rl_error(RL_ERR_NOT_COMMITTED, "accel: the scene has no committed data");
    rl_accel *a = rl_calloc(1, sizeof *a);
    if (!a)
        return RL_ERR_OUT_OF_MEMORY;
    a->scene = scene;
    a->data = data;
    a->desc = d;
    a->cls = class_of(d.kind);
    a->stats.kind = d.kind;
    a->masked = rl_data_has_masks(data);
    *out = a;
    return RL_OK;
}

rl_status rl_accel_commit(rl_accel *accel)
{
    if (!accel)
        return rl_error(RL_ERR_INVALID_ARG, "rl_accel_commit: accel is NULL");
    if (accel->committed)
        return RL_OK;
    rl_accel_stats st = { .kind = accel->desc.kind };
    void *state = NULL;
    rl_timer timer;
    rl_timer_start(&timer);
    rl_status s = accel->cls->build(accel->data, &accel->desc, &state, &st);
    if (s)
        return s;
    st.build_ms = rl_timer_ms(&timer);
    st.kind = accel->desc.kind;
    st.num_triangles = accel->data->num_triangles;
    st.bytes_per_triangle = st.num_triangles ? (double)st.memory_bytes / (double)st.num_triangles : 0.0;
    accel->state = state;
    accel->stats = st;
    accel->committed = true;
    return RL_OK;
}

void rl_accel_release(rl_accel *accel)
{
    if (!accel)
        return;
    if (accel->committed && accel->cls->release)
        accel->cls->release(accel->state);
    free(accel);
}

void rl_accel_get_stats(const rl_accel *accel, rl_accel_stats *out)
{
    if (!out)
        return;
    if (!accel) {
        memset(out, 0, sizeof *out);
        return;
    }
    *out = accel->stats;
}

const rl_scene *rl_accel_scene(const rl_accel *accel) { return accel ? accel->scene : NULL; }

/* The contract's invalid rays. Written with positive tests so that any NaN
 * fails them: "!(t_min <= t_max)" also catches a NaN t_max. */
static bool ray_is_valid(const rl_ray *r)
{
    if (!rl_vfinite(r->o) || !rl_vfinite(r->d) || !isfinite(r->t_min))
        return false;
    if (r->d.x == 0.0f && r->d.y == 0.0f && r->d.z == 0.0f)
        return false;
    return r->t_min <= r->t_max;
}

/* The rest of rl_accel_intersect for a packet lane's first hit h of *ray:
 * the same alpha-mask retries as a single query (rl_skip_masked_hits),
 * then the object's name. */
static bool finish_hit(const rl_accel *accel, rl_ray *ray, rl_hit *hit, rl_hit h)
{
    if (!rl_skip_masked_hits(accel->data, accel->masked, accel->cls->intersect, accel->state, ray, &h, true))
        return false;
    h.object = accel->data->triangle_object[h.triangle];
    *hit = h;
    return true;
}

bool rl_accel_intersect(const rl_accel *accel, rl_ray *ray, rl_hit *hit)
{
    if (!ray || !hit)
        return false;
    hit->triangle = RL_ID_NONE;
    hit->object = RL_ID_NONE;
    if (!accel || !accel->committed || !ray_is_valid(ray))
        return false;
    if (!accel->masked) {
        /* Without alpha masks: one query straight into *ray and *hit. Every
         * kind leaves both alone on a miss and sets ray->t_max = hit->t on a
         * hit (rl_closest_hit_fn), so this returns what the copying path
         * below does. Those copies cost: the kinds and the callers write a
         * ray and a hit field by field, and reading either back as one
         * 32- or 16-byte vector fails store forwarding (perf: two stalls
         * per query, 2-3 % of pt's time on the Bitterli box). */
        if (!accel->cls->intersect(accel->state, ray, hit))
            return false;
        hit->object = accel->data->triangle_object[hit->triangle];
        return true;
    }
    /* Alpha masks here rather than in each kind's inner loop: one place for
     * all of them (Embree included), and no cost for scenes without masks. */
    rl_hit h = { .triangle = RL_ID_NONE, .object = RL_ID_NONE };
    if (!rl_closest_unmasked_hit(accel->data, accel->masked, accel->cls->intersect, accel->state, ray, &h))
        return false;
    h.object = accel->data->triangle_object[h.triangle];
    *hit = h;
    return true;
}

bool rl_accel_occluded(const rl_accel *accel, const rl_ray *ray)
{
    if (!accel || !ray || !accel->committed || !ray_is_valid(ray))
        return false;
    if (!accel->masked)
        return accel->cls->occluded(accel->state, ray);
    /* With alpha masks an any-hit query could stop at a hole: walk the
     * hits front to back instead (rl_accel_intersect skips the holes). */
    rl_ray r = *ray;
    rl_hit h;
    return rl_accel_intersect(accel, &r, &h);
}

bool rl_accel_occluder(const rl_accel *accel, const rl_ray *ray, uint32_t *triangle)
{
    if (!triangle)
        return rl_accel_occluded(accel, ray);
    *triangle = RL_ID_NONE;
    if (!accel || !ray || !accel->committed || !ray_is_valid(ray))
        return false;
    if (!accel->masked && accel->cls->occluder)
        return accel->cls->occluder(accel->state, ray, triangle);
    /* Masks (see rl_accel_occluded), or a kind that cannot name its
     * occluder: the closest hit names one, at the price of a full search. */
    rl_ray r = *ray;
    rl_hit h;
    if (!rl_accel_intersect(accel, &r, &h))
        return false;
    *triangle = h.triangle;
    return true;
}

bool rl_accel_intersect_triangle(const rl_accel *accel, const rl_ray *ray, uint32_t triangle, rl_hit *hit)
{
    if (!accel || !ray || !hit || !accel->committed || !ray_is_valid(ray) ||
        triangle >= accel->data->num_triangles)
        return false;
    const rl_scene_data *d = accel->data;
    const uint32_t *idx = &d->indices[3 * (size_t)triangle];
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    float t, u, v;
    /* The vertices in scene index order, as every kind of ours stores them:
     * the edge functions then sum in the same order and t is the same
     * float. */
    if (!rl_triangle_intersect_watertight(&w, d->positions[idx[0]], d->positions[idx[1]], d->positions[idx[2]],
                                          ray->t_min, ray->t_max, &t, &u, &v))
        return false;
    if (accel->masked && rl_alpha_masked(d, triangle, u, v))
        return false;
    *hit = (rl_hit){ .t = t, .u = u, .v = v, .triangle = triangle, .object = d->triangle_object[triangle] };
    return true;
}

/* Which rays of a group of up to RL_ACCEL_PACKET go through the kind's
 * packet query: the valid ones with t_min >= 0 whose directions lie in the
 * octant of the first such ray (a packet of mixed octants is exact too but
 * visits the union of their paths). Fewer than PACKET_MIN such rays: none,
 * single queries are then faster. The others take the single query. */
#define PACKET_MIN 4

static unsigned octant(const rl_ray *r)
{
    return (signbit(r->d.x) ? 1u : 0u) | (signbit(r->d.y) ? 2u : 0u) | (signbit(r->d.z) ? 4u : 0u);
}

static unsigned packet_lanes(const rl_ray *rays, size_t k)
{
    unsigned lanes = 0, first = 8;
    int count = 0;
    for (size_t l = 0; l < k; ++l) {
        const rl_ray *r = &rays[l];
        if (!(r->t_min >= 0.0f) || !ray_is_valid(r))
            continue;
        unsigned o = octant(r);
        first = first == 8 ? o : first;
        if (o == first) {
            lanes |= 1u << l;
            ++count;
        }
    }
    return count >= PACKET_MIN ? lanes : 0;
}

/* Closest hits of up to RL_ACCEL_PACKET rays, the lanes of packet through
 * the kind's packet query, the rest one by one. */
static void intersect_group(const rl_accel *accel, rl_ray *rays, rl_hit *hits, size_t k, unsigned packet)
{
    rl_ray r[RL_ACCEL_PACKET];
    rl_hit h[RL_ACCEL_PACKET];
    for (size_t l = 0; l < k; ++l) {
        if (!(packet & (1u << l))) {
            rl_accel_intersect(accel, &rays[l], &hits[l]);
            continue;
        }
        hits[l].triangle = RL_ID_NONE;
        hits[l].object = RL_ID_NONE;
        r[l] = rays[l];
        h[l] = (rl_hit){ .triangle = RL_ID_NONE, .object = RL_ID_NONE };
    }
    if (!packet)
        return;
    unsigned found = accel->cls->intersect8(accel->state, r, h, packet);
    for (size_t l = 0; l < k; ++l)
        if (found & (1u << l))
            finish_hit(accel, &rays[l], &hits[l], h[l]);
}

void rl_accel_intersect_n(const rl_accel *accel, rl_ray *rays, rl_hit *hits, size_t n)
{
    if (!rays || !hits)
        return;
    bool packets = accel && accel->committed && accel->cls->intersect8;
    for (size_t i = 0; i < n; i += RL_ACCEL_PACKET) {
        size_t k = n - i < RL_ACCEL_PACKET ? n - i : RL_ACCEL_PACKET;
        intersect_group(accel, rays + i, hits + i, k, packets ? packet_lanes(rays + i, k) : 0);
    }
}

void rl_accel_occluded_n(const rl_accel *accel, const rl_ray *rays, bool *occluded, size_t n)
{
    if (!rays || !occluded)
        return;
    bool packets = accel && accel->committed && accel->cls->occluded8 && accel->cls->intersect8;
    for (size_t i = 0; i < n; i += RL_ACCEL_PACKET) {
        size_t k = n - i < RL_ACCEL_PACKET ? n - i : RL_ACCEL_PACKET;
        unsigned packet = packets ? packet_lanes(rays + i, k) : 0;
        if (!packet) {
            for (size_t l = 0; l < k; ++l)
                occluded[i + l] = rl_accel_occluded(accel, &rays[i + l]);
            continue;
        }
        if (accel->masked) {
            /* As rl_accel_occluded: the closest hit beyond the holes. */
            rl_ray r[RL_ACCEL_PACKET];
            rl_hit h[RL_ACCEL_PACKET];
            memcpy(r, rays + i, k * sizeof *r);
            intersect_group(accel, r, h, k, packet);
            for (size_t l = 0; l < k; ++l)
                occluded[i + l] = h[l].triangle != RL_ID_NONE;
            continue;
        }
        unsigned blocked = accel->cls->occluded8(accel->state, rays + i, packet);
        for (size_t l = 0; l < k; ++l)
            occluded[i + l] = packet & (1u << l) ? (blocked >> l) & 1u : rl_accel_occluded(accel, &rays[i + l]);
    }
}

const struct rl_grid *rl_accel_grid_state(const rl_accel *a)
{
    if (!a || !a->committed || a->desc.kind != RL_ACCEL_GRID)
        return NULL;
    return a->state;
}

bool rl_accel_is_committed(const rl_accel *a)
{
    return a && a->committed;
}
