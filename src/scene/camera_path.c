/* camera_path.c: keyframed camera paths. Eye and target follow centripetal
 * Catmull-Rom splines (alpha = 1/2; Yuksel, Schaefer & Keyser 2011, "Parameter-
 * ization and applications of Catmull-Rom curves") evaluated with the
 * Barry-Goldman pyramid; the end keys are duplicated as outer control points.
 * Up and fov are interpolated linearly, resolution comes from the first key. */
#include "rl/rl_camera.h"
#include "core/error.h"

#include <stdlib.h>
#include <string.h>

struct rl_camera_path {
    uint32_t count;
    rl_camera_key *keys;
};

rl_status rl_camera_path_create(const rl_camera_key *keys, uint32_t count, rl_camera_path **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "camera path: out is NULL");
    if (!keys || count == 0)
        return rl_error(RL_ERR_INVALID_ARG, "camera path: no keys");
    for (uint32_t i = 0; i < count; ++i) {
        if (!isfinite(keys[i].time_s))
            return rl_error(RL_ERR_INVALID_ARG, "camera path: key %u time is not finite", i);
        if (i > 0 && !(keys[i].time_s > keys[i - 1].time_s))
            return rl_error(RL_ERR_INVALID_ARG, "camera path: key %u time %g not after %g", i,
                            keys[i].time_s, keys[i - 1].time_s);
        rl_status st = rl_camera_validate(&keys[i].camera);
        if (st != RL_OK)
            return rl_error(st, "camera path: key %u has an invalid camera", i);
    }
    rl_camera_path *p = rl_calloc(1, sizeof *p);
    rl_camera_key *copy = rl_calloc(count, sizeof *copy);
    if (!p || !copy) {
        free(p);
        free(copy);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < count; ++i) {
        copy[i].time_s = keys[i].time_s;
        copy[i].camera = rl_camera_resolve(&keys[i].camera);
    }
    p->count = count;
    p->keys = copy;
    *out = p;
    return RL_OK;
}

void rl_camera_path_release(rl_camera_path *path)
{
    if (!path)
        return;
    free(path->keys);
    free(path);
}

uint32_t rl_camera_path_key_count(const rl_camera_path *path) { return path ? path->count : 0; }

const rl_camera_key *rl_camera_path_key(const rl_camera_path *path, uint32_t i)
{
    return path && i < path->count ? &path->keys[i] : NULL;
}

double rl_camera_path_duration(const rl_camera_path *path)
{
    return path ? path->keys[path->count - 1].time_s - path->keys[0].time_s : 0.0;
}

typedef struct dvec3 { double x, y, z; } dvec3;

static dvec3 dv(rl_vec3 v) { dvec3 r = { v.x, v.y, v.z }; return r; }

/* ((b_t - t) * a + (t - a_t) * b) / (b_t - a_t); coincident knots mean
 * coincident points, so either point is the answer. */
static dvec3 blend(dvec3 a, double a_t, dvec3 b, double b_t, double t)
{
    double span = b_t - a_t;
    if (!(span > 0.0))
        return b;
    double wa = (b_t - t) / span, wb = (t - a_t) / span;
    dvec3 r = { wa * a.x + wb * b.x, wa * a.y + wb * b.y, wa * a.z + wb * b.z };
    return r;
}

static double knot_step(dvec3 a, dvec3 b)
{
    double dx = b.x - a.x, dy = b.y - a.y, dz = b.z - a.z;
    return sqrt(sqrt(dx * dx + dy * dy + dz * dz)); /* |P_i+1 - P_i|^alpha, alpha = 1/2 */
}

/* Point at fraction u in [0,1] of the segment p1 -> p2 (Barry-Goldman). */
static rl_vec3 centripetal(rl_vec3 q0, rl_vec3 q1, rl_vec3 q2, rl_vec3 q3, double u)
{
    dvec3 p0 = dv(q0), p1 = dv(q1), p2 = dv(q2), p3 = dv(q3);
    double t0 = 0.0;
    double t1 = t0 + knot_step(p0, p1);
    double t2 = t1 + knot_step(p1, p2);
    double t3 = t2 + knot_step(p2, p3);
    if (!(t2 > t1))
        return q1; /* the segment does not move */
    double t = t1 + u * (t2 - t1);
    dvec3 a1 = blend(p0, t0, p1, t1, t);
    dvec3 a2 = blend(p1, t1, p2, t2, t);
    dvec3 a3 = blend(p2, t2, p3, t3, t);
    /* With a zero first/last interval the outer point repeats its neighbour. */
    if (!(t1 > t0))
        a1 = p1;
    if (!(t3 > t2))
        a3 = p2;
    dvec3 b1 = blend(a1, t0, a2, t2, t);
    dvec3 b2 = blend(a2, t1, a3, t3, t);
    dvec3 c = blend(b1, t1, b2, t2, t);
    return rl_v3((float)c.x, (float)c.y, (float)c.z);
}

static rl_camera with_first_resolution(const rl_camera_path *path, rl_camera c)
{
    c.width = path->keys[0].camera.width;
    c.height = path->keys[0].camera.height;
    return c;
}

rl_camera rl_camera_path_eval(const rl_camera_path *path, double time_s)
{
    if (!path)
        return rl_camera_resolve(NULL);
    const rl_camera_key *k = path->keys;
    uint32_t n = path->count;
    if (!(time_s > k[0].time_s))       /* also catches NaN */
        return k[0].camera;
    if (time_s >= k[n - 1].time_s)
        return with_first_resolution(path, k[n - 1].camera);
    /* Segment i with k[i].time_s <= t < k[i+1].time_s. */
    uint32_t lo = 0, hi = n - 1;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (k[mid].time_s <= time_s)
            lo = mid;
        else
            hi = mid;
    }
    uint32_t i = lo;
    if (time_s == k[i].time_s)
        return with_first_resolution(path, k[i].camera);
    double u = (time_s - k[i].time_s) / (k[i + 1].time_s - k[i].time_s);
    const rl_camera *c0 = &k[i > 0 ? i - 1 : 0].camera, *c1 = &k[i].camera;
    const rl_camera *c2 = &k[i + 1].camera, *c3 = &k[i + 2 < n ? i + 2 : n - 1].camera;

    rl_camera c = k[0].camera;
    c.eye = centripetal(c0->eye, c1->eye, c2->eye, c3->eye, u);
    c.target = centripetal(c0->target, c1->target, c2->target, c3->target, u);
    rl_vec3 up = rl_vlerp(c1->up, c2->up, (float)u);
    c.up = rl_length2(up) > 0.0f ? up : c1->up;
    c.fov_deg = rl_lerpf(c1->fov_deg, c2->fov_deg, (float)u);
    c.z_near = rl_lerpf(c1->z_near, c2->z_near, (float)u);
    c.z_far = rl_lerpf(c1->z_far, c2->z_far, (float)u);
    return c;
}

rl_camera rl_camera_path_frame(const rl_camera_path *path, uint32_t i, uint32_t n)
{
    if (!path)
        return rl_camera_resolve(NULL);
    if (n <= 1)
        return rl_camera_path_eval(path, path->keys[0].time_s);
    if (i >= n)
        i = n - 1;
    double t0 = path->keys[0].time_s;
    return rl_camera_path_eval(path, t0 + rl_camera_path_duration(path) * (double)i / (double)(n - 1));
}
