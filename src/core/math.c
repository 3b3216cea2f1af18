/* math.c: 4x4 matrices and colour conversions declared in rl_math.h.
 *
 * Matrices are row-major, column vectors (M * v). The inverse is the general
 * adjugate / determinant in double, so that near-singular camera matrices
 * keep their precision. Bounding boxes are transformed with Arvo's method
 * ("Transforming axis-aligned bounding boxes", Graphics Gems, 1990), which
 * gives the same box as transforming all 8 corners in a fraction of the work.
 * sRGB follows IEC 61966-2-1 exactly (piecewise, not a 2.2 gamma); luminance
 * uses the Rec. 709 primaries. */
#include "rl/rl_math.h"

#include <math.h>

rl_mat4 rl_mat4_identity(void)
{
    rl_mat4 r = { { { 1, 0, 0, 0 }, { 0, 1, 0, 0 }, { 0, 0, 1, 0 }, { 0, 0, 0, 1 } } };
    return r;
}

rl_mat4 rl_mat4_mul(const rl_mat4 *a, const rl_mat4 *b)
{
    rl_mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            float s = 0.0f;
            for (int k = 0; k < 4; ++k)
                s += a->m[i][k] * b->m[k][j];
            r.m[i][j] = s;
        }
    return r;
}

rl_mat4 rl_mat4_translate(rl_vec3 t)
{
    rl_mat4 r = rl_mat4_identity();
    r.m[0][3] = t.x;
    r.m[1][3] = t.y;
    r.m[2][3] = t.z;
    return r;
}

rl_mat4 rl_mat4_scale(rl_vec3 s)
{
    rl_mat4 r = rl_mat4_identity();
    r.m[0][0] = s.x;
    r.m[1][1] = s.y;
    r.m[2][2] = s.z;
    return r;
}

rl_mat4 rl_mat4_rotate(rl_vec3 axis, float angle_rad)
{
    /* Rodrigues: R = cos(a) I + sin(a) [k]x + (1 - cos(a)) k k^T; a positive
     * angle turns counter-clockwise looking down the axis (right-handed). */
    rl_vec3 k = rl_normalize(axis);
    float c = cosf(angle_rad), s = sinf(angle_rad), t = 1.0f - c;
    rl_mat4 r = rl_mat4_identity();
    r.m[0][0] = c + t * k.x * k.x;
    r.m[0][1] = t * k.x * k.y - s * k.z;
    r.m[0][2] = t * k.x * k.z + s * k.y;
    r.m[1][0] = t * k.y * k.x + s * k.z;
    r.m[1][1] = c + t * k.y * k.y;
    r.m[1][2] = t * k.y * k.z - s * k.x;
    r.m[2][0] = t * k.z * k.x - s * k.y;
    r.m[2][1] = t * k.z * k.y + s * k.x;
    r.m[2][2] = c + t * k.z * k.z;
    return r;
}

rl_mat4 rl_mat4_transpose(const rl_mat4 *a)
{
    rl_mat4 r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            r.m[i][j] = a->m[j][i];
    return r;
}

bool rl_mat4_invert(const rl_mat4 *a, rl_mat4 *out)
{
    /* Cofactors via 2x2 sub-determinants of the top and bottom row pairs
     * (Laplace expansion along rows 0-1 vs 2-3), all in double. */
    double m[4][4];
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            m[i][j] = a->m[i][j];
    double s0 = m[0][0] * m[1][1] - m[1][0] * m[0][1];
    double s1 = m[0][0] * m[1][2] - m[1][0] * m[0][2];
    double s2 = m[0][0] * m[1][3] - m[1][0] * m[0][3];
    double s3 = m[0][1] * m[1][2] - m[1][1] * m[0][2];
    double s4 = m[0][1] * m[1][3] - m[1][1] * m[0][3];
    double s5 = m[0][2] * m[1][3] - m[1][2] * m[0][3];
    double c5 = m[2][2] * m[3][3] - m[3][2] * m[2][3];
    double c4 = m[2][1] * m[3][3] - m[3][1] * m[2][3];
    double c3 = m[2][1] * m[3][2] - m[3][1] * m[2][2];
    double c2 = m[2][0] * m[3][3] - m[3][0] * m[2][3];
    double c1 = m[2][0] * m[3][2] - m[3][0] * m[2][2];
    double c0 = m[2][0] * m[3][1] - m[3][0] * m[2][1];
    double det = s0 * c5 - s1 * c4 + s2 * c3 + s3 * c2 - s4 * c1 + s5 * c0;
    if (det == 0.0 || !isfinite(det)) {
        *out = rl_mat4_identity();
        return false;
    }
    double id = 1.0 / det;
    double r[4][4];
    r[0][0] = ( m[1][1] * c5 - m[1][2] * c4 + m[1][3] * c3) * id;
    r[0][1] = (-m[0][1] * c5 + m[0][2] * c4 - m[0][3] * c3) * id;
    r[0][2] = ( m[3][1] * s5 - m[3][2] * s4 + m[3][3] * s3) * id;
    r[0][3] = (-m[2][1] * s5 + m[2][2] * s4 - m[2][3] * s3) * id;
    r[1][0] = (-m[1][0] * c5 + m[1][2] * c2 - m[1][3] * c1) * id;
    r[1][1] = ( m[0][0] * c5 - m[0][2] * c2 + m[0][3] * c1) * id;
    r[1][2] = (-m[3][0] * s5 + m[3][2] * s2 - m[3][3] * s1) * id;
    r[1][3] = ( m[2][0] * s5 - m[2][2] * s2 + m[2][3] * s1) * id;
    r[2][0] = ( m[1][0] * c4 - m[1][1] * c2 + m[1][3] * c0) * id;
    r[2][1] = (-m[0][0] * c4 + m[0][1] * c2 - m[0][3] * c0) * id;
    r[2][2] = ( m[3][0] * s4 - m[3][1] * s2 + m[3][3] * s0) * id;
    r[2][3] = (-m[2][0] * s4 + m[2][1] * s2 - m[2][3] * s0) * id;
    r[3][0] = (-m[1][0] * c3 + m[1][1] * c1 - m[1][2] * c0) * id;
    r[3][1] = ( m[0][0] * c3 - m[0][1] * c1 + m[0][2] * c0) * id;
    r[3][2] = (-m[3][0] * s3 + m[3][1] * s1 - m[3][2] * s0) * id;
    r[3][3] = ( m[2][0] * s3 - m[2][1] * s1 + m[2][2] * s0) * id;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            out->m[i][j] = (float)r[i][j];
    return true;
}

rl_mat4 rl_mat4_look_at(rl_vec3 eye, rl_vec3 target, rl_vec3 up)
{
    /* gluLookAt: rows are the camera axes (side, up, -forward) so the camera
     * looks down its -z; the last column moves eye to the origin. */
    rl_vec3 f = rl_normalize(rl_sub(target, eye));
    rl_vec3 s = rl_normalize(rl_cross(f, up));
    rl_vec3 u = rl_cross(s, f);
    rl_mat4 r = rl_mat4_identity();
    r.m[0][0] = s.x;  r.m[0][1] = s.y;  r.m[0][2] = s.z;  r.m[0][3] = -rl_dot(s, eye);
    r.m[1][0] = u.x;  r.m[1][1] = u.y;  r.m[1][2] = u.z;  r.m[1][3] = -rl_dot(u, eye);
    r.m[2][0] = -f.x; r.m[2][1] = -f.y; r.m[2][2] = -f.z; r.m[2][3] = rl_dot(f, eye);
    return r;
}

rl_mat4 rl_mat4_perspective(float fov_y_rad, float aspect, float z_near, float z_far)
{
    /* gluPerspective: z_eye = -near maps to NDC -1, -far to +1. */
    float f = 1.0f / tanf(0.5f * fov_y_rad);
    rl_mat4 r = { { { 0 } } };
    r.m[0][0] = f / aspect;
    r.m[1][1] = f;
    r.m[2][2] = (z_far + z_near) / (z_near - z_far);
    r.m[2][3] = 2.0f * z_far * z_near / (z_near - z_far);
    r.m[3][2] = -1.0f;
    return r;
}

rl_mat4 rl_mat4_orthographic(float half_width, float half_height, float z_near, float z_far)
{
    /* glOrtho, centred: x, y in [-half, half] and z_eye = -near .. -far map
     * to NDC -1 .. +1; w stays 1 (the rasterizer then interpolates eye depth
     * affinely). */
    rl_mat4 r = { { { 0 } } };
    r.m[0][0] = 1.0f / half_width;
    r.m[1][1] = 1.0f / half_height;
    r.m[2][2] = -2.0f / (z_far - z_near);
    r.m[2][3] = -(z_far + z_near) / (z_far - z_near);
    r.m[3][3] = 1.0f;
    return r;
}

rl_vec4 rl_mat4_mul_vec4(const rl_mat4 *a, rl_vec4 v)
{
    const float (*m)[4] = a->m;
    return rl_v4(m[0][0] * v.x + m[0][1] * v.y + m[0][2] * v.z + m[0][3] * v.w,
                 m[1][0] * v.x + m[1][1] * v.y + m[1][2] * v.z + m[1][3] * v.w,
                 m[2][0] * v.x + m[2][1] * v.y + m[2][2] * v.z + m[2][3] * v.w,
                 m[3][0] * v.x + m[3][1] * v.y + m[3][2] * v.z + m[3][3] * v.w);
}

rl_vec3 rl_mat4_mul_point(const rl_mat4 *a, rl_vec3 p)
{
    const float (*m)[4] = a->m;
    return rl_v3(m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3],
                 m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3],
                 m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3]);
}

rl_vec3 rl_mat4_mul_dir(const rl_mat4 *a, rl_vec3 d)
{
    const float (*m)[4] = a->m;
    return rl_v3(m[0][0] * d.x + m[0][1] * d.y + m[0][2] * d.z,
                 m[1][0] * d.x + m[1][1] * d.y + m[1][2] * d.z,
                 m[2][0] * d.x + m[2][1] * d.y + m[2][2] * d.z);
}

rl_vec3 rl_mat4_mul_normal(const rl_mat4 *inv_transpose, rl_vec3 n)
{
    return rl_normalize(rl_mat4_mul_dir(inv_transpose, n));
}

rl_aabb rl_mat4_mul_aabb(const rl_mat4 *a, rl_aabb b)
{
    if (rl_aabb_is_empty(b))
        return b;
    /* Affine matrices only (the last row is ignored, no divide).
     * Arvo 1990: each output extreme is the translation plus, per input axis,
     * the smaller (for min) or larger (for max) of m_ij*min_j and m_ij*max_j. */
    float lo_in[3] = { b.min.x, b.min.y, b.min.z };
    float hi_in[3] = { b.max.x, b.max.y, b.max.z };
    float lo[3], hi[3];
    for (int i = 0; i < 3; ++i) {
        lo[i] = hi[i] = a->m[i][3];
        for (int j = 0; j < 3; ++j) {
            float e = a->m[i][j] * lo_in[j];
            float f = a->m[i][j] * hi_in[j];
            lo[i] += e < f ? e : f;
            hi[i] += e < f ? f : e;
        }
    }
    rl_aabb r = { { lo[0], lo[1], lo[2] }, { hi[0], hi[1], hi[2] } };
    return r;
}

float rl_luminance(rl_vec3 rgb)
{
    return 0.2126f * rgb.x + 0.7152f * rgb.y + 0.0722f * rgb.z;
}

rl_vec3 rl_rgb_to_hsv(rl_vec3 rgb)
{
    float mx = rl_vmax_comp(rgb);
    float mn = rl_minf(rgb.x, rl_minf(rgb.y, rgb.z));
    float c = mx - mn; /* chroma */
    float h = 0.0f;
    if (c > 0.0f) {
        if (mx == rgb.x)
            h = 60.0f * fmodf((rgb.y - rgb.z) / c, 6.0f);
        else if (mx == rgb.y)
            h = 60.0f * ((rgb.z - rgb.x) / c + 2.0f);
        else
            h = 60.0f * ((rgb.x - rgb.y) / c + 4.0f);
        if (h < 0.0f)
            h += 360.0f;
        if (h >= 360.0f)
            h -= 360.0f;
    }
    float s = mx > 0.0f ? c / mx : 0.0f;
    return rl_v3(h, s, mx);
}

rl_vec3 rl_hsv_to_rgb(rl_vec3 hsv)
{
    float h = fmodf(hsv.x, 360.0f);
    if (h < 0.0f)
        h += 360.0f;
    float v = hsv.z, c = v * hsv.y;
    float hp = h / 60.0f;
    float x = c * (1.0f - fabsf(fmodf(hp, 2.0f) - 1.0f));
    float m = v - c;
    rl_vec3 r;
    switch ((int)hp) {
    case 0: r = rl_v3(c, x, 0); break;
    case 1: r = rl_v3(x, c, 0); break;
    case 2: r = rl_v3(0, c, x); break;
    case 3: r = rl_v3(0, x, c); break;
    case 4: r = rl_v3(x, 0, c); break;
    default: r = rl_v3(c, 0, x); break;
    }
    return rl_add(r, rl_v3s(m));
}

float rl_linear_to_srgb(float c)
{
    if (c <= 0.0031308f)
        return 12.92f * c;
    return 1.055f * powf(c, 1.0f / 2.4f) - 0.055f;
}

float rl_srgb_to_linear(float c)
{
    if (c <= 0.04045f)
        return c / 12.92f;
    return powf((c + 0.055f) / 1.055f, 2.4f);
}
