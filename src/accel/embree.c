/* embree.c: RL_ACCEL_EMBREE, Intel Embree 3 behind rl_accel (Wald et al.
 * 2014, "Embree: A Kernel Framework for Efficient CPU Ray Tracing").
 *
 * The correctness oracle and performance anchor for our own structures: one
 * device and one scene per accel, holding one triangle geometry with copies
 * of the scene's world-space vertex and index arrays. The scene is built with
 * RTC_BUILD_QUALITY_HIGH (spatial splits) and RTC_SCENE_FLAG_ROBUST, which
 * selects Embree's watertight triangle test, so that rays through shared
 * edges and vertices cannot slip through, as with our Woop et al. 2013 test.
 *
 * Conventions match rl_hit without conversion: Embree's barycentrics are
 * p = (1-u-v)·p0 + u·p1 + v·p2 and primID is the index in our index buffer,
 * i.e. the scene's flattened triangle ID.
 *
 * Deviations from our own kinds, on purpose:
 *  - Embree accepts only segments in [0, inf] and tests t in (tnear, tfar]:
 *    a ray with t_min < 0 is traced from its point at t_min (so its t may
 *    differ from ours in the last bits), and a hit exactly at t_max may be
 *    reported. Embree itself makes no promise at the segment's ends.
 *  - When two triangles are hit at the same t (shared edges, coplanar
 *    overlaps) Embree may report the other one than our traversals.
 *  - memory_bytes is what Embree's memory monitor reports for the device's
 *    buffers and BVH while building: its own accounting of its larger
 *    blocks, so approximate (small allocations and TBB are not counted).
 *  - desc->progress is called from Embree's build threads; calls are
 *    serialised here, and one that would overlap another is skipped.
 *
 * Builds use TBB; desc->threads > 0 becomes the device config "threads=N".
 * Queries are thread-safe (Embree's rtcIntersect1/rtcOccluded1 and the
 * packet calls rtcIntersect8/rtcOccluded8 of the batch queries are). */
#ifdef RL_HAVE_EMBREE

#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <embree3/rtcore.h>

#include "accel/accel_internal.h"
#include "core/error.h"

typedef struct embree_accel {
    RTCDevice device;
    RTCScene scene;
    const uint32_t *triangle_object;     /* borrowed from the scene data */
    atomic_llong monitored_bytes;        /* memory monitor running total */
    /* Build-time progress forwarding (Embree calls from several threads). */
    rl_progress_fn progress;
    void *user;
    atomic_flag progress_busy;
    atomic_bool cancelled;
    bool ray8;                           /* rtcIntersect8 in this Embree build */
} embree_accel;

static const char *error_text(enum RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE:              return "no error";
    case RTC_ERROR_UNKNOWN:           return "unknown error";
    case RTC_ERROR_INVALID_ARGUMENT:  return "invalid argument";
    case RTC_ERROR_INVALID_OPERATION: return "invalid operation";
    case RTC_ERROR_OUT_OF_MEMORY:     return "out of memory";
    case RTC_ERROR_UNSUPPORTED_CPU:   return "unsupported CPU (Embree needs at least SSE2)";
    case RTC_ERROR_CANCELLED:         return "cancelled";
    }
    return "unrecognised error code";
}

static rl_status status_of(enum RTCError code)
{
    switch (code) {
    case RTC_ERROR_NONE:              return RL_OK;
    case RTC_ERROR_INVALID_ARGUMENT:  return RL_ERR_INVALID_ARG;
    case RTC_ERROR_OUT_OF_MEMORY:     return RL_ERR_OUT_OF_MEMORY;
    case RTC_ERROR_UNSUPPORTED_CPU:   return RL_ERR_UNSUPPORTED;
    case RTC_ERROR_CANCELLED:         return RL_ERR_CANCELLED;
    default:                          return RL_ERR_INTERNAL;
    }
}

/* Embree's per-device error callback runs on the thread that made the
 * failing call; recording it there keeps Embree's own, more specific text
 * as that thread's first error. */
static void on_error(void *user, enum RTCError code, const char *str)
{
    (void)user;
    rl_error(status_of(code), "embree: %s: %s", error_text(code), str ? str : "");
}

static bool on_memory(void *user, ssize_t bytes, bool post)
{
    (void)post;   /* each (de)allocation is reported once, pre or post */
    embree_accel *e = user;
    atomic_fetch_add_explicit(&e->monitored_bytes, (long long)bytes, memory_order_relaxed);
    return true;
}

static bool on_progress(void *user, double done)
{
    embree_accel *e = user;
    if (atomic_load(&e->cancelled))
        return false;
    /* The user's callback need not be thread-safe: let one thread in at a
     * time; a report that finds it busy is dropped, later ones follow. */
    if (atomic_flag_test_and_set(&e->progress_busy))
        return true;
    bool go_on = e->progress(e->user, done < 0.0 ? 0.0 : (done > 1.0 ? 1.0 : done));
    atomic_flag_clear(&e->progress_busy);
    if (!go_on)
        atomic_store(&e->cancelled, true);
    return go_on;
}

static void embree_release(void *state)
{
    embree_accel *e = state;
    if (!e)
        return;
    if (e->scene)
        rtcReleaseScene(e->scene);
    if (e->device)
        rtcReleaseDevice(e->device);
    free(e);
}

/* Fails with the device's pending error (already recorded by on_error). */
static rl_status fail(embree_accel *e, const char *what)
{
    enum RTCError code = rtcGetDeviceError(e->device);
    rl_status s = code == RTC_ERROR_NONE ? RL_ERR_INTERNAL : status_of(code);
    if (e->cancelled)
        s = RL_ERR_CANCELLED;
    embree_release(e);
    return rl_error(s, "embree: %s failed: %s", what, error_text(code));
}

static rl_status add_triangles(embree_accel *e, const rl_scene_data *data)
{
    RTCGeometry geom = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    if (!geom)
        return RL_ERR_INTERNAL;
    /* Copies rather than shared buffers: Embree reads vertices with 16-byte
     * loads, and its own buffers are over-allocated for that. */
    float *vertices = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                              3 * sizeof(float), data->num_vertices);
    unsigned *indices = rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                3 * sizeof(unsigned), data->num_triangles);
    if (!vertices || !indices) {
        rtcReleaseGeometry(geom);
        return RL_ERR_OUT_OF_MEMORY;
    }
    _Static_assert(sizeof(rl_vec3) == 3 * sizeof(float), "rl_vec3 is three packed floats");
    memcpy(vertices, data->positions, (size_t)data->num_vertices * sizeof(rl_vec3));
    memcpy(indices, data->indices, (size_t)data->num_triangles * 3 * sizeof(uint32_t));
    rtcCommitGeometry(geom);
    rtcAttachGeometry(e->scene, geom);   /* geomID 0, the only one */
    rtcReleaseGeometry(geom);            /* the scene holds it now */
    return rtcGetDeviceError(e->device) == RTC_ERROR_NONE ? RL_OK : RL_ERR_INTERNAL;
}

static rl_status embree_build(const rl_scene_data *data, const rl_accel_desc *desc, void **state,
                              rl_accel_stats *stats)
{
    embree_accel *e = rl_calloc(1, sizeof *e);
    if (!e)
        return RL_ERR_OUT_OF_MEMORY;
    atomic_init(&e->monitored_bytes, 0);
    atomic_init(&e->cancelled, false);
    atomic_flag_clear(&e->progress_busy);
    e->triangle_object = data->triangle_object;
    e->progress = desc->progress;
    e->user = desc->user;

    char config[32] = "";
    if (desc->threads > 0)
        snprintf(config, sizeof config, "threads=%d", desc->threads);
    e->device = rtcNewDevice(config[0] ? config : NULL);
    if (!e->device) {
        enum RTCError code = rtcGetDeviceError(NULL);
        free(e);
        return rl_error(RL_ERR_UNSUPPORTED, "embree: rtcNewDevice(\"%s\") failed: %s", config,
                        error_text(code));
    }
    rtcSetDeviceErrorFunction(e->device, on_error, NULL);
    e->ray8 = rtcGetDeviceProperty(e->device, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
    rtcSetDeviceMemoryMonitorFunction(e->device, on_memory, e);

    e->scene = rtcNewScene(e->device);
    if (!e->scene)
        return fail(e, "rtcNewScene");
    rtcSetSceneBuildQuality(e->scene, RTC_BUILD_QUALITY_HIGH);
    rtcSetSceneFlags(e->scene, RTC_SCENE_FLAG_ROBUST);
    if (add_triangles(e, data) != RL_OK)
        return fail(e, "creating the triangle geometry");

    if (e->progress)
        rtcSetSceneProgressMonitorFunction(e->scene, on_progress, e);
    rtcCommitScene(e->scene);
    if (rtcGetDeviceError(e->device) != RTC_ERROR_NONE || e->cancelled)
        return fail(e, "rtcCommitScene");
    /* The callback must not outlive this build (desc->user is the caller's). */
    rtcSetSceneProgressMonitorFunction(e->scene, NULL, NULL);

    long long bytes = atomic_load(&e->monitored_bytes);
    stats->memory_bytes = bytes > 0 ? (size_t)bytes : 0;
    stats->bytes_per_triangle =
        data->num_triangles ? (double)stats->memory_bytes / data->num_triangles : 0.0;
    *state = e;
    return RL_OK;
}

/* Embree wants tnear >= 0: start a backwards-reaching segment at its
 * beginning instead. Returns the offset to add to Embree's t. */
static float setup_ray(const rl_ray *ray, struct RTCRay *r)
{
    float shift = ray->t_min < 0.0f ? ray->t_min : 0.0f;
    rl_vec3 o = rl_madd(ray->o, ray->d, shift);
    r->org_x = o.x;
    r->org_y = o.y;
    r->org_z = o.z;
    r->dir_x = ray->d.x;
    r->dir_y = ray->d.y;
    r->dir_z = ray->d.z;
    r->tnear = ray->t_min - shift;
    r->tfar = ray->t_max - shift;
    r->time = 0.0f;
    r->mask = 0xFFFFFFFFu;
    r->id = 0;
    r->flags = 0;
    return shift;
}

static bool embree_intersect(const void *state, rl_ray *ray, rl_hit *hit)
{
    const embree_accel *e = state;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRayHit rh;   /* RTC_ALIGN(16) by declaration, as Embree requires */
    float shift = setup_ray(ray, &rh.ray);
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(e->scene, &ctx, &rh);
    if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID)
        return false;
    float t = rh.ray.tfar + shift;
    ray->t_max = t;
    hit->t = t;
    hit->u = rh.hit.u;
    hit->v = rh.hit.v;
    hit->triangle = rh.hit.primID;
    hit->object = e->triangle_object[rh.hit.primID];
    return true;
}

static bool embree_occluded(const void *state, const rl_ray *ray)
{
    const embree_accel *e = state;
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    struct RTCRay r;
    setup_ray(ray, &r);
    rtcOccluded1(e->scene, &ctx, &r);
    return r.tfar == -INFINITY;   /* Embree's mark for "something was hit" */
}

/* Packets (accel.c's batch queries): Embree's own 8-wide packet traversal,
 * rtcIntersect8 / rtcOccluded8, with the coherent-rays hint, so that `rl
 * bench rays` compares our packets with Embree's. Lanes are set up as by
 * setup_ray. Without packet support in this Embree build, single rays. */
static void setup_ray8(const rl_ray *ray, struct RTCRay8 *r, int l, float *shift)
{
    struct RTCRay one;
    *shift = setup_ray(ray, &one);
    r->org_x[l] = one.org_x;
    r->org_y[l] = one.org_y;
    r->org_z[l] = one.org_z;
    r->dir_x[l] = one.dir_x;
    r->dir_y[l] = one.dir_y;
    r->dir_z[l] = one.dir_z;
    r->tnear[l] = one.tnear;
    r->tfar[l] = one.tfar;
    r->time[l] = 0.0f;
    r->mask[l] = 0xFFFFFFFFu;
    r->id[l] = 0;
    r->flags[l] = 0;
}

static unsigned embree_intersect8(const void *state, rl_ray *rays, rl_hit *hits, unsigned active)
{
    const embree_accel *e = state;
    unsigned found = 0;
    if (!e->ray8) {
        for (int l = 0; l < 8; ++l)
            if ((active & (1u << l)) && embree_intersect(state, &rays[l], &hits[l]))
                found |= 1u << l;
        return found;
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    struct RTCRayHit8 rh;   /* RTC_ALIGN(32) by declaration */
    int valid[8];
    float shift[8] = { 0.0f };
    memset(&rh, 0, sizeof rh);
    for (int l = 0; l < 8; ++l) {
        valid[l] = active & (1u << l) ? -1 : 0;
        if (valid[l])
            setup_ray8(&rays[l], &rh.ray, l, &shift[l]);
        rh.hit.geomID[l] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID[l] = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0][l] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect8(valid, e->scene, &ctx, &rh);
    for (int l = 0; l < 8; ++l) {
        if (!valid[l] || rh.hit.geomID[l] == RTC_INVALID_GEOMETRY_ID)
            continue;
        float t = rh.ray.tfar[l] + shift[l];
        rays[l].t_max = t;
        hits[l].t = t;
        hits[l].u = rh.hit.u[l];
        hits[l].v = rh.hit.v[l];
        hits[l].triangle = rh.hit.primID[l];
        hits[l].object = e->triangle_object[rh.hit.primID[l]];
        found |= 1u << l;
    }
    return found;
}

static unsigned embree_occluded8(const void *state, const rl_ray *rays, unsigned active)
{
    const embree_accel *e = state;
    unsigned blocked = 0;
    if (!e->ray8) {
        for (int l = 0; l < 8; ++l)
            if ((active & (1u << l)) && embree_occluded(state, &rays[l]))
                blocked |= 1u << l;
        return blocked;
    }
    struct RTCIntersectContext ctx;
    rtcInitIntersectContext(&ctx);
    ctx.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    struct RTCRay8 r;
    int valid[8];
    memset(&r, 0, sizeof r);
    for (int l = 0; l < 8; ++l) {
        float shift;
        valid[l] = active & (1u << l) ? -1 : 0;
        if (valid[l])
            setup_ray8(&rays[l], &r, l, &shift);
    }
    rtcOccluded8(valid, e->scene, &ctx, &r);
    for (int l = 0; l < 8; ++l)
        if (valid[l] && r.tfar[l] == -INFINITY)
            blocked |= 1u << l;
    return blocked;
}

const rl_accel_class rl_accel_embree_class = {
    .name = "embree",
    .build = embree_build,
    .intersect = embree_intersect,
    .occluded = embree_occluded,
    .release = embree_release,
    .intersect8 = embree_intersect8,
    .occluded8 = embree_occluded8,
};

#endif /* RL_HAVE_EMBREE */
