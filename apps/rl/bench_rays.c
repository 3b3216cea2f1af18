/* bench_rays.c: generates the primary, shadow and diffuse ray workloads of
 * `rl bench rays` and times an accelerator on them (see bench_rays.h).
 *
 * Secondary rays start at the primary hit point moved along the geometric
 * normal (turned towards the viewer) by 1e-4 of the point's magnitude, so no
 * accelerator re-hits the surface it starts on and every one sees exactly the
 * same rays. Diffuse directions are cosine-weighted (Malley's method: uniform
 * points on the unit disk projected up to the hemisphere), one PCG stream per
 * pixel, so the workload does not depend on the thread count. */
#define _POSIX_C_SOURCE 200809L
#include "bench_rays.h"

#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rl/rl_timer.h"

#define TILE 8          /* primary rays: 8x8 pixel tiles in scanline order */
#define CHUNK 512       /* rays per unit of work handed to a thread */

const char *bench_workload_name(int workload)
{
    static const char *const names[RL_BENCH_WORKLOADS] = { "primary", "shadow", "diffuse" };
    return workload >= 0 && workload < RL_BENCH_WORKLOADS ? names[workload] : "?";
}

/* What a primary ray found: the offset origin for secondary rays and the
 * geometric normal facing the viewer. */
typedef struct surface {
    rl_vec3 origin, normal;
    bool hit;
} surface;

static float max_abs(rl_vec3 p)
{
    return rl_maxf(fabsf(p.x), rl_maxf(fabsf(p.y), fabsf(p.z)));
}

static surface surface_at(const rl_scene_data *data, const rl_ray *ray, const rl_hit *hit)
{
    const uint32_t *idx = data->indices + 3u * (size_t)hit->triangle;
    rl_vec3 p0 = data->positions[idx[0]], p1 = data->positions[idx[1]], p2 = data->positions[idx[2]];
    rl_vec3 n = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
    if (rl_dot(n, ray->d) > 0.0f)
        n = rl_neg(n);
    rl_vec3 p = rl_ray_at(ray, hit->t);
    /* The float error of p grows with |p|; 1e-4 relative clears it by ~1000 ulp. */
    float eps = 1e-4f * rl_maxf(1.0f, max_abs(p));
    surface s = { rl_madd(p, n, eps), n, true };
    return s;
}

/* Where shadow rays go: the first light's position (a quad light's centre),
 * or for a directional light a direction. Without lights: a point above the
 * scene, so the workload still exists. */
typedef struct shadow_target {
    bool directional;
    rl_vec3 point, direction;
} shadow_target;

static shadow_target shadow_target_of(const rl_scene_data *data)
{
    shadow_target t = { false, rl_v3s(0.0f), rl_v3s(0.0f) };
    if (data->num_lights == 0) {
        rl_vec3 e = rl_aabb_extent(data->bounds);
        t.point = rl_add(rl_aabb_center(data->bounds), rl_v3(0.0f, rl_vmax_comp(e), 0.0f));
        return t;
    }
    const rl_light *l = &data->lights[0];
    switch (l->type) {
    case RL_LIGHT_DIRECTIONAL:
        t.directional = true;
        t.direction = rl_normalize(rl_neg(l->direction));
        break;
    case RL_LIGHT_QUAD:
        t.point = rl_madd(l->position, rl_add(l->edge_u, l->edge_v), 0.5f);
        break;
    default:
        t.point = l->position;
        break;
    }
    return t;
}

static rl_ray shadow_ray(const surface *s, const shadow_target *target)
{
    rl_ray r = { s->origin, 0.0f, target->direction, 1e30f };
    if (!target->directional) {
        rl_vec3 to = rl_sub(target->point, s->origin);
        float dist = rl_length(to);
        r.d = dist > 0.0f ? rl_scale(to, 1.0f / dist) : to;
        /* Stop just short of the light so that geometry at the light itself
         * (the emitter of a quad light) does not count as a blocker. */
        r.t_max = dist * (1.0f - 1e-4f);
    }
    return r;
}

static rl_ray diffuse_ray(const surface *s, uint64_t seed, uint64_t pixel)
{
    rl_rng rng;
    rl_rng_seed(&rng, seed, pixel);
    float u1 = rl_rng_float(&rng), u2 = rl_rng_float(&rng);
    float r = sqrtf(u1), phi = 2.0f * RL_PI * u2;
    rl_vec3 local = rl_v3(r * cosf(phi), r * sinf(phi), sqrtf(rl_maxf(0.0f, 1.0f - u1)));
    rl_onb onb = rl_onb_from_normal(s->normal);
    rl_ray ray = { s->origin, 0.0f, rl_onb_to_world(&onb, local), INFINITY };
    return ray;
}

/* Primary rays in scanline order of tile_w x tile_h tiles; pixel_of[i] is
 * the row-major pixel of ray i. */
static void make_primary(const rl_camera *cam, int tile_w, int tile_h, rl_ray *rays, uint32_t *pixel_of)
{
    rl_camera_frame f = rl_camera_frame_make(cam);
    int w = f.width, h = f.height;
    size_t i = 0;
    for (int ty = 0; ty < h; ty += tile_h)
        for (int tx = 0; tx < w; tx += tile_w)
            for (int y = ty; y < ty + tile_h && y < h; y++)
                for (int x = tx; x < tx + tile_w && x < w; x++) {
                    rays[i] = rl_camera_frame_ray(&f, (float)x + 0.5f, (float)y + 0.5f);
                    pixel_of[i++] = (uint32_t)y * (uint32_t)w + (uint32_t)x;
                }
}

bool bench_make_rays(const rl_scene *scene, const rl_camera *cam, const rl_accel *reference,
                        uint64_t seed, int threads, bench_rays *out)
{
    const rl_scene_data *data = rl_scene_get_data(scene);
    rl_camera c = rl_camera_resolve(cam);
    size_t n = (size_t)c.width * (size_t)c.height;
    rl_ray *primary = malloc(n * sizeof *primary);
    uint32_t *pixel_of = malloc(n * sizeof *pixel_of);
    surface *surf = calloc(n, sizeof *surf);            /* by pixel */
    rl_ray *shadow = NULL, *diffuse = NULL;
    bool ok = data && primary && pixel_of && surf;
    size_t hits = 0;
    if (ok) {
        make_primary(&c, TILE, TILE, primary, pixel_of);
        long long count = (long long)n;
#pragma omp parallel for num_threads(threads) schedule(dynamic, CHUNK) reduction(+ : hits)
        for (long long i = 0; i < count; i++) {
            rl_ray r = primary[i];
            rl_hit hit;
            if (rl_accel_intersect(reference, &r, &hit)) {
                surf[pixel_of[i]] = surface_at(data, &primary[i], &hit);
                hits++;
            }
        }
        /* malloc(0) may return NULL: ask for one ray at least. */
        shadow = malloc((hits ? hits : 1) * sizeof *shadow);
        diffuse = malloc((hits ? hits : 1) * sizeof *diffuse);
        ok = shadow && diffuse;
    }
    if (ok) {
        /* Shadow rays keep the coherent tile order of their primary rays;
         * diffuse rays go in pixel order, where neighbours share nothing. */
        shadow_target target = shadow_target_of(data);
        size_t k = 0;
        for (size_t i = 0; i < n; i++)
            if (surf[pixel_of[i]].hit)
                shadow[k++] = shadow_ray(&surf[pixel_of[i]], &target);
        k = 0;
        for (size_t p = 0; p < n; p++)
            if (surf[p].hit)
                diffuse[k++] = diffuse_ray(&surf[p], seed, p);
        memset(out, 0, sizeof *out);
        out->rays[RL_BENCH_PRIMARY] = primary;
        out->count[RL_BENCH_PRIMARY] = n;
        out->rays[RL_BENCH_SHADOW] = shadow;
        out->count[RL_BENCH_SHADOW] = hits;
        out->rays[RL_BENCH_DIFFUSE] = diffuse;
        out->count[RL_BENCH_DIFFUSE] = hits;
        primary = shadow = diffuse = NULL;
    }
    free(primary);
    free(pixel_of);
    free(surf);
    free(shadow);
    free(diffuse);
    return ok;
}

bool bench_make_packet_rays(const rl_scene *scene, const rl_camera *cam, const rl_accel *reference,
                            int threads, bench_rays *out)
{
    const rl_scene_data *data = rl_scene_get_data(scene);
    rl_camera c = rl_camera_resolve(cam);
    size_t n = (size_t)c.width * (size_t)c.height;
    rl_ray *primary = malloc(n * sizeof *primary);
    uint32_t *pixel_of = malloc(n * sizeof *pixel_of);
    surface *surf = calloc(n, sizeof *surf);            /* in ray order */
    rl_ray *shadow = NULL;
    if (!data || !primary || !pixel_of || !surf)
        goto fail;
    make_primary(&c, RL_BENCH_PACKET_TILE_W, RL_BENCH_PACKET_TILE_H, primary, pixel_of);
    size_t hits = 0;
    long long count = (long long)n;
#pragma omp parallel for num_threads(threads) schedule(dynamic, CHUNK) reduction(+ : hits)
    for (long long i = 0; i < count; i++) {
        rl_ray r = primary[i];
        rl_hit hit;
        if (rl_accel_intersect(reference, &r, &hit)) {
            surf[i] = surface_at(data, &primary[i], &hit);
            hits++;
        }
    }
    shadow = malloc((hits ? hits : 1) * sizeof *shadow);
    if (!shadow)
        goto fail;
    /* In the tiles' order: consecutive shadow rays start at neighbouring
     * pixels' hit points and go to one light, as a renderer's would. */
    shadow_target target = shadow_target_of(data);
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        if (surf[i].hit)
            shadow[k++] = shadow_ray(&surf[i], &target);
    memset(out, 0, sizeof *out);
    out->rays[RL_BENCH_PRIMARY] = primary;
    out->count[RL_BENCH_PRIMARY] = n;
    out->rays[RL_BENCH_SHADOW] = shadow;
    out->count[RL_BENCH_SHADOW] = k;
    free(pixel_of);
    free(surf);
    return true;
fail:
    free(primary);
    free(pixel_of);
    free(surf);
    free(shadow);
    return false;
}

void bench_rays_free(bench_rays *rays)
{
    if (!rays)
        return;
    for (int w = 0; w < RL_BENCH_WORKLOADS; w++)
        free(rays->rays[w]);
    memset(rays, 0, sizeof *rays);
}

/* CPU time of the calling thread: unlike wall time it does not grow while
 * the thread waits for a core that someone else's job is using. */
static double thread_cpu_s(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One pass over all rays on all threads; returns the number of hits and in
 * *cpu_s the CPU seconds the threads spent tracing (barrier waits excluded). */
static uint64_t trace_pass(const rl_accel *accel, const rl_ray *rays, size_t count, bool any_hit,
                           bool batched, int threads, double *cpu_s)
{
    uint64_t hits = 0;
    double cpu = 0.0;
    long long chunks = (long long)((count + CHUNK - 1) / CHUNK);
#pragma omp parallel num_threads(threads) reduction(+ : hits, cpu)
    {
        double t0 = thread_cpu_s();
        /* Dynamic chunks: rays differ wildly in cost (sky vs. a dense city). */
#pragma omp for schedule(dynamic, 1) nowait
        for (long long c = 0; c < chunks; c++) {
            size_t begin = (size_t)c * CHUNK;
            size_t end = begin + CHUNK < count ? begin + CHUNK : count;
            uint64_t local = 0;
            if (batched) {
                /* The batch queries (packets of 8 where they pay, accel.c)
                 * on the chunk; intersect shortens t_max: keep the workload. */
                rl_ray r[CHUNK];
                rl_hit hit[CHUNK];
                bool occluded[CHUNK];
                size_t k = end - begin;
                if (any_hit) {
                    rl_accel_occluded_n(accel, rays + begin, occluded, k);
                    for (size_t i = 0; i < k; i++)
                        local += occluded[i];
                } else {
                    memcpy(r, rays + begin, k * sizeof *r);
                    rl_accel_intersect_n(accel, r, hit, k);
                    for (size_t i = 0; i < k; i++)
                        local += hit[i].triangle != RL_ID_NONE;
                }
            } else if (any_hit) {
                for (size_t i = begin; i < end; i++)
                    local += rl_accel_occluded(accel, &rays[i]);
            } else {
                for (size_t i = begin; i < end; i++) {
                    rl_ray r = rays[i];    /* intersect shortens t_max: keep the workload */
                    rl_hit hit;
                    local += rl_accel_intersect(accel, &r, &hit);
                }
            }
            hits += local;
        }
        cpu += thread_cpu_s() - t0;
    }
    *cpu_s = cpu;
    return hits;
}

void bench_time_rays(const rl_accel *const *accels, const bool *batched, int num_accels,
                     const rl_ray *rays, size_t count, bool any_hit, int threads, int min_runs,
                     int max_runs, double min_total_s, bench_timing *out)
{
    for (int a = 0; a < num_accels; a++) {
        out[a] = (bench_timing){ .best_s = INFINITY, .best_cpu_s = INFINITY,
                                     .deterministic = true };
        /* The warm-up pass faults in the structure and the rays, fills the
         * caches, and counts the hits. */
        double cpu_s;
        out[a].hits = trace_pass(accels[a], rays, count, any_hit, batched && batched[a], threads, &cpu_s);
    }
    /* Round robin: on a shared machine a burst of foreign load then slows
     * one pass of every accelerator instead of all passes of one, and the
     * best-of keeps the ratios honest. */
    double *total_s = calloc((size_t)num_accels, sizeof *total_s);
    for (bool more = true; more;) {
        more = false;
        for (int a = 0; a < num_accels; a++) {
            bench_timing *t = &out[a];
            double spent = total_s ? total_s[a] : INFINITY;
            if (t->runs >= max_runs || (t->runs >= min_runs && spent >= min_total_s))
                continue;
            double cpu_s, t0 = rl_time_s();
            uint64_t hits = trace_pass(accels[a], rays, count, any_hit, batched && batched[a], threads,
                                       &cpu_s);
            double dt = rl_time_s() - t0;
            if (hits != t->hits)
                t->deterministic = false;
            t->best_s = dt < t->best_s ? dt : t->best_s;
            t->best_cpu_s = cpu_s < t->best_cpu_s ? cpu_s : t->best_cpu_s;
            if (total_s)
                total_s[a] += dt;
            t->runs++;
            more = true;
        }
    }
    free(total_s);
    for (int a = 0; a < num_accels; a++)
        if (out[a].runs == 0)
            out[a].best_s = out[a].best_cpu_s = 0.0;
}
