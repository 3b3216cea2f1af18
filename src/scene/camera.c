/* camera.c: perspective pinhole camera: defaults, validation, the ray frame,
 * OpenGL-style view/projection matrices built from that same frame (so that
 * rasterizers and ray tracers agree pixel for pixel), clip ranges and a
 * default camera that frames a bounding box. */
#include <string.h>

#include "rl/rl_camera.h"
#include "rl/rl_image.h"
#include "core/error.h"

rl_camera rl_camera_resolve(const rl_camera *cam)
{
    rl_camera c = { 0 };
    if (cam)
        c = *cam;
    if (c.up.x == 0.0f && c.up.y == 0.0f && c.up.z == 0.0f)
        c.up = rl_v3(0.0f, 1.0f, 0.0f);
    if (c.fov_deg == 0.0f)
        c.fov_deg = RL_CAMERA_DEFAULT_FOV_DEG;
    if (c.width == 0)
        c.width = RL_CAMERA_DEFAULT_WIDTH;
    if (c.height == 0)
        c.height = RL_CAMERA_DEFAULT_HEIGHT;
    return c;
}

bool rl_camera_equal(const rl_camera *a, const rl_camera *b)
{
    if (!a || !b)
        return a == b;
    return memcmp(&a->eye, &b->eye, sizeof a->eye) == 0 && memcmp(&a->target, &b->target, sizeof a->target) == 0 &&
           memcmp(&a->up, &b->up, sizeof a->up) == 0 && a->fov_deg == b->fov_deg && a->width == b->width &&
           a->height == b->height && a->z_near == b->z_near && a->z_far == b->z_far;
}

rl_status rl_camera_validate(const rl_camera *cam)
{
    if (!cam)
        return rl_error(RL_ERR_INVALID_ARG, "camera: NULL");
    rl_camera c = rl_camera_resolve(cam);
    if (!rl_vfinite(c.eye) || !rl_vfinite(c.target) || !rl_vfinite(c.up) || !isfinite(c.fov_deg) ||
        !isfinite(c.z_near) || !isfinite(c.z_far))
        return rl_error(RL_ERR_INVALID_ARG, "camera: non-finite value");
    rl_vec3 dir = rl_sub(c.target, c.eye);
    float dist = rl_length(dir);
    float scale = rl_maxf(rl_vmax_comp(rl_vmax(c.eye, rl_neg(c.eye))),
                          rl_vmax_comp(rl_vmax(c.target, rl_neg(c.target))));
    /* Relative to the coordinates: below that, eye and target round together. */
    if (!(dist > 1e-6f * rl_maxf(scale, 1e-30f)) || !(rl_length2(dir) > 0.0f))
        return rl_error(RL_ERR_INVALID_ARG, "camera: eye and target coincide");
    /* In units of the largest component, so that huge coordinates (an eye
     * at 1e30) do not overflow the lengths into a NaN that reads as
     * "parallel". */
    rl_vec3 dn = rl_scale(dir, 1.0f / rl_vmax_comp(rl_vmax(dir, rl_neg(dir))));
    rl_vec3 un = rl_scale(c.up, 1.0f / rl_maxf(rl_vmax_comp(rl_vmax(c.up, rl_neg(c.up))), 1e-30f));
    float sin_up = rl_length(rl_cross(dn, un)) / (rl_length(dn) * rl_length(un));
    if (!(sin_up > 1e-6f))
        return rl_error(RL_ERR_INVALID_ARG, "camera: up is parallel to the view direction");
    if (!(c.fov_deg > 0.0f && c.fov_deg < 180.0f))
        return rl_error(RL_ERR_INVALID_ARG, "camera: fov %g outside (0,180) degrees",
                        (double)c.fov_deg);
    if (c.width < 1 || c.height < 1 || c.width > RL_IMAGE_MAX_SIZE || c.height > RL_IMAGE_MAX_SIZE)
        return rl_error(RL_ERR_LIMIT, "camera: resolution %dx%d outside 1..%d", c.width, c.height,
                        RL_IMAGE_MAX_SIZE);
    if (c.z_near < 0.0f || c.z_far < 0.0f || (c.z_near > 0.0f && c.z_far > 0.0f && c.z_near >= c.z_far))
        return rl_error(RL_ERR_INVALID_ARG, "camera: need 0 < z_near (%g) < z_far (%g) or zeros",
                        (double)c.z_near, (double)c.z_far);
    return RL_OK;
}

rl_camera_frame rl_camera_frame_make(const rl_camera *cam)
{
    rl_camera c = rl_camera_resolve(cam);
    rl_camera_frame f;
    f.eye = c.eye;
    f.w = rl_normalize(rl_sub(c.eye, c.target));
    f.u = rl_normalize(rl_cross(c.up, f.w));
    f.v = rl_cross(f.w, f.u);
    f.tan_half_fov_y = tanf(rl_radians(c.fov_deg) * 0.5f);
    f.width = c.width;
    f.height = c.height;
    f.aspect = (float)c.width / (float)c.height;
    return f;
}

rl_ray rl_camera_frame_ray(const rl_camera_frame *f, float px, float py)
{
    /* Image plane at distance 1: x right, y up, pixel rows run downwards. */
    float sx = (2.0f * px / (float)f->width - 1.0f) * f->tan_half_fov_y * f->aspect;
    float sy = (1.0f - 2.0f * py / (float)f->height) * f->tan_half_fov_y;
    rl_vec3 d = rl_sub(rl_add(rl_scale(f->u, sx), rl_scale(f->v, sy)), f->w);
    rl_ray r;
    r.o = f->eye;
    r.d = rl_normalize(d);
    r.t_min = 0.0f;
    r.t_max = INFINITY;
    return r;
}

rl_mat4 rl_camera_view(const rl_camera *cam)
{
    rl_camera_frame f = rl_camera_frame_make(cam);
    rl_vec3 rows[3] = { f.u, f.v, f.w };
    rl_mat4 m = rl_mat4_identity();
    for (int r = 0; r < 3; ++r) {
        m.m[r][0] = rows[r].x;
        m.m[r][1] = rows[r].y;
        m.m[r][2] = rows[r].z;
        m.m[r][3] = -rl_dot(rows[r], f.eye);
    }
    return m;
}

rl_mat4 rl_camera_projection(const rl_camera *cam, float z_near, float z_far)
{
    rl_camera c = rl_camera_resolve(cam);
    return rl_mat4_perspective(rl_radians(c.fov_deg), (float)c.width / (float)c.height, z_near, z_far);
}

void rl_camera_clip_range(const rl_camera *cam, rl_aabb bounds, float *z_near, float *z_far)
{
    rl_camera c = rl_camera_resolve(cam);
    rl_camera_frame f = rl_camera_frame_make(&c);
    float lo = INFINITY, hi = -INFINITY;
    if (!rl_aabb_is_empty(bounds) && rl_vfinite(bounds.min) && rl_vfinite(bounds.max)) {
        for (int k = 0; k < 8; ++k) {
            rl_vec3 p = rl_v3(k & 1 ? bounds.max.x : bounds.min.x, k & 2 ? bounds.max.y : bounds.min.y,
                              k & 4 ? bounds.max.z : bounds.min.z);
            float depth = -rl_dot(rl_sub(p, f.eye), f.w);
            lo = rl_minf(lo, depth);
            hi = rl_maxf(hi, depth);
        }
    }
    float far_d, near_d;
    if (!(hi > 0.0f)) {
        /* Nothing in front of the camera: any sane range will do. */
        far_d = 1000.0f;
        near_d = 0.01f;
    } else {
        /* Enlarged so that the farthest corner is not clipped by rounding. */
        far_d = hi * 1.01f + 1e-6f;
        /* Depth precision: a 24-bit buffer loses everything beyond far/near ~ 1e5. */
        near_d = rl_maxf(lo * 0.99f, far_d * 1e-5f);
    }
    if (c.z_far > 0.0f)
        far_d = c.z_far;
    if (c.z_near > 0.0f)
        near_d = c.z_near;
    if (near_d >= far_d)
        near_d = far_d * 1e-5f;
    if (z_near)
        *z_near = near_d;
    if (z_far)
        *z_far = far_d;
}

/* Tight orbit framing. In the view basis (u right, v up, d forward) a point
 * (x, y, z) lies between the left and right planes of an eye at (ex, ez)
 * when ex - tx ez <= x + tx z and ex + tx ez >= x - tx z, tx being the
 * tangent of the horizontal half angle. With
 * A = min(x + tx z) and B = max(x - tx z) the farthest-forward eye that keeps
 * every point inside is ex = (A + B) / 2, ez = (A - B) / (2 tx); the same
 * for y. The eye takes the smaller (farther back) of the two depths and
 * stays centred on both axes, so the points touch the frame on one axis
 * and are centred on the other. */
rl_camera rl_camera_fit_points(const rl_vec3 *points, size_t count, float azimuth_deg,
                               float elevation_deg, int width, int height)
{
    rl_camera c = { 0 };
    c.width = width > 0 ? width : RL_CAMERA_DEFAULT_WIDTH;
    c.height = height > 0 ? height : RL_CAMERA_DEFAULT_HEIGHT;
    c.fov_deg = RL_CAMERA_DEFAULT_FOV_DEG;
    float az = rl_radians(isfinite(azimuth_deg) ? azimuth_deg : RL_CAMERA_FIT_AZIMUTH_DEG);
    /* Straight up or down leaves no up vector; 89 degrees is as steep as the
     * basis stays well defined. */
    float el = rl_radians(rl_clampf(isfinite(elevation_deg) ? elevation_deg
                                                             : RL_CAMERA_FIT_ELEVATION_DEG,
                                    -89.0f, 89.0f));
    /* From the target towards the eye: azimuth about +y from +z, elevation
     * above the xz plane. */
    rl_vec3 back = rl_v3(sinf(az) * cosf(el), sinf(el), cosf(az) * cosf(el));
    rl_vec3 d = rl_scale(back, -1.0f);
    rl_vec3 u = rl_normalize(rl_cross(d, rl_v3(0.0f, 1.0f, 0.0f)));
    rl_vec3 v = rl_cross(u, d);
    c.up = rl_v3(0.0f, 1.0f, 0.0f);
    /* A 4 % margin keeps silhouettes off the image border. */
    const float fill = 0.96f;
    float ty = tanf(rl_radians(c.fov_deg) * 0.5f) * fill;
    float tx = tanf(rl_radians(c.fov_deg) * 0.5f) * (float)c.width / (float)c.height * fill;
    /* Relative to the first finite point, in double: far-away models lose
     * no precision, and huge ones do not overflow. */
    rl_vec3 origin = rl_v3s(0.0f);
    bool have = false;
    double A = INFINITY, B = -INFINITY, C = INFINITY, D = -INFINITY, zmin = INFINITY, zmax = -INFINITY;
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
    for (size_t i = 0; i < count; ++i) {
        if (!rl_vfinite(points[i]))
            continue;
        if (!have) {
            origin = points[i];
            have = true;
        }
        rl_vec3 p = rl_sub(points[i], origin);
        double x = rl_dot(p, u), y = rl_dot(p, v), z = rl_dot(p, d);
        A = fmin(A, x + tx * z);
        B = fmax(B, x - tx * z);
        C = fmin(C, y + ty * z);
        D = fmax(D, y - ty * z);
        zmin = fmin(zmin, z);
        zmax = fmax(zmax, z);
        xlo = fmin(xlo, x), xhi = fmax(xhi, x), ylo = fmin(ylo, y), yhi = fmax(yhi, y);
    }
    if (!have) {
        c.target = rl_v3s(0.0f);
        c.eye = back;
        return c;
    }
    double ezx = (A - B) / (2.0 * tx), ezy = (C - D) / (2.0 * ty);
    double ez = fmin(ezx, ezy);
    double ex = 0.5 * (A + B), ey = 0.5 * (C + D);
    /* A single point, or points on a line along d: step back by their depth
     * range, or by 1 when there is none. */
    double depth = zmax - zmin;
    bool degenerate = !(ez < zmin - 1e-6 * fmax(depth, 1e-30));
    if (degenerate)
        ez = zmin - (depth > 0.0 ? depth : 1.0);
    /* On the axis with room to spare the planes are centred, not the
     * picture: centre the projected extent instead (the projected offset
     * (x - e) / (z - ez) falls as e grows, so bisection finds it). */
    if (!degenerate) {
        bool slack_x = ezx > ez;
        /* Every point is in front of the eye, so e at the smallest
         * coordinate makes every offset >= 0 and e at the largest <= 0. */
        double lo = slack_x ? xlo : ylo, hi = slack_x ? xhi : yhi;
        for (int it = 0; it < 40; ++it) {
            double e = 0.5 * (lo + hi), pmin = INFINITY, pmax = -INFINITY;
            for (size_t i = 0; i < count; ++i) {
                if (!rl_vfinite(points[i]))
                    continue;
                rl_vec3 p = rl_sub(points[i], origin);
                double z = rl_dot(p, d), w = slack_x ? rl_dot(p, u) : rl_dot(p, v);
                double q = (w - e) / (z - ez);
                pmin = fmin(pmin, q);
                pmax = fmax(pmax, q);
            }
            if (pmin + pmax > 0.0)
                lo = e;
            else
                hi = e;
        }
        if (slack_x)
            ex = 0.5 * (lo + hi);
        else
            ey = 0.5 * (lo + hi);
    }
    c.eye = rl_add(origin, rl_add(rl_add(rl_scale(u, (float)ex), rl_scale(v, (float)ey)),
                                  rl_scale(d, (float)ez)));
    /* The target at the middle of the depth range: orbiting tools rotate
     * about it. */
    c.target = rl_add(c.eye, rl_scale(d, (float)(0.5 * (zmin + zmax) - ez)));
    return c;
}

rl_camera rl_camera_frame_bounds(rl_aabb bounds, int width, int height)
{
    rl_camera c = { 0 };
    c.width = width > 0 ? width : RL_CAMERA_DEFAULT_WIDTH;
    c.height = height > 0 ? height : RL_CAMERA_DEFAULT_HEIGHT;
    c.fov_deg = RL_CAMERA_DEFAULT_FOV_DEG;
    c.up = rl_v3(0.0f, 1.0f, 0.0f);
    rl_vec3 centre = rl_v3s(0.0f);
    float radius = 1.0f;
    if (!rl_aabb_is_empty(bounds) && rl_vfinite(bounds.min) && rl_vfinite(bounds.max)) {
        centre = rl_aabb_center(bounds);
        /* In double: the squared diagonal of a huge box overflows float. */
        rl_vec3 e = rl_aabb_extent(bounds);
        radius = (float)(0.5 * sqrt((double)e.x * e.x + (double)e.y * e.y + (double)e.z * e.z));
        if (!(radius > 0.0f))
            radius = 1.0f;
    }
    /* The bounding sphere fits a cone of half angle theta at distance
     * r / sin(theta); theta is the narrower of the vertical and horizontal
     * half fields of view. */
    float tan_y = tanf(rl_radians(c.fov_deg) * 0.5f);
    float tan_x = tan_y * (float)c.width / (float)c.height;
    float half = atanf(rl_minf(tan_x, tan_y));
    float dist = radius / sinf(half) * 1.05f;
    rl_vec3 dir = rl_normalize(rl_v3(0.4f, 0.3f, 1.0f));
    c.target = centre;
    c.eye = rl_madd(centre, dir, dist);
    return c;
}
