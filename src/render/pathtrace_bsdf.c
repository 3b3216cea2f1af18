/* pathtrace_bsdf.c: the Phong sampling of the path tracer (Schröder 2017,
 * Sec. 6.4.3): directions follow the Phong lobe, uniform-ish (cosine) for
 * shininess 0, concentrated around the mirrored incoming ray as the
 * shininess grows (Phong 1975).
 *
 * The thesis gives no formula; we use the energy-conserving modified Phong
 * BRDF of Lafortune & Willems 1994,
 *     f(wi, wo) = k_d / pi + k_s (n + 2) / (2 pi) cos^n(alpha),
 * alpha the angle between wi and the mirror direction r of wo about the
 * shading normal, and sample it as their mixture: the diffuse lobe
 * (cos(theta) / pi) with probability P_d = mean(k_d) / (mean(k_d) +
 * mean(k_s)), else the lobe (n + 1) / (2 pi) cos^n(alpha) around r. The
 * weight f cos(theta) / pdf uses the full mixture pdf, so a direction that
 * either lobe could have produced is weighted correctly (one-sample MIS
 * over the lobes, balance heuristic). A pure Lambertian surface gets the
 * weight k_d exactly. Directions below the shading or geometric surface
 * end the path (weight 0): no light leaks through a surface. */
#include <math.h>

#include "render/pathtrace_internal.h"

static float mean3(rl_vec3 c)
{
    return (c.x + c.y + c.z) * (1.0f / 3.0f);
}

/* r = 2 (n.v) n - v: the direction mirroring the viewer about n. */
static rl_vec3 mirror_dir(const pt_surface *s)
{
    return rl_sub(rl_scale(s->ns, 2.0f * rl_dot(s->ns, s->v)), s->v);
}

/* cos^n(alpha), zero behind the lobe (and no 0^0 for shininess 0). */
static float lobe(rl_vec3 r, rl_vec3 wi, float n)
{
    float c = rl_dot(r, wi);
    return c > 0.0f ? powf(c, n) : 0.0f;
}

rl_vec3 rl_pt_phong_eval(const pt_surface *s, rl_vec3 wi)
{
    const float inv_pi = 1.0f / RL_PI;
    rl_vec3 f = rl_scale(s->kd, inv_pi);
    if (rl_vmax_comp(s->m->specular) > 0.0f) {
        float n = rl_maxf(s->m->shininess, 0.0f);
        float spec = (n + 2.0f) * 0.5f * inv_pi * lobe(mirror_dir(s), wi, n);
        f = rl_add(f, rl_scale(s->m->specular, spec));
    }
    return f;
}

/* Lobe selection probability of the diffuse lobe; < 0 when both are black. */
static float diffuse_probability(const pt_surface *s)
{
    float wd = mean3(s->kd), ws = mean3(s->m->specular);
    if (!(wd + ws > 0.0f))
        return -1.0f;
    return wd / (wd + ws);
}

float rl_pt_phong_pdf(const pt_surface *s, rl_vec3 wi)
{
    float pd = diffuse_probability(s);
    float cos_theta = rl_dot(s->ns, wi);
    if (pd < 0.0f || cos_theta <= 0.0f)
        return 0.0f;
    float n = rl_maxf(s->m->shininess, 0.0f);
    float pdf = pd * cos_theta / RL_PI;
    if (pd < 1.0f)
        pdf += (1.0f - pd) * (n + 1.0f) * 0.5f / RL_PI * lobe(mirror_dir(s), wi, n);
    return pdf;
}

/* Unit vector in the frame of axis a: polar angle with cosine cos_t,
 * azimuth phi. */
static rl_vec3 around(rl_vec3 a, float cos_t, float phi)
{
    rl_onb onb = rl_onb_from_normal(a);
    float sin_t = sqrtf(rl_maxf(0.0f, 1.0f - cos_t * cos_t));
    return rl_onb_to_world(&onb, rl_v3(cosf(phi) * sin_t, sinf(phi) * sin_t, cos_t));
}

bool rl_pt_phong_sample(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight)
{
    return rl_pt_phong_sample_pdf(s, u_lobe, u1, u2, wi, weight, NULL);
}

bool rl_pt_surface_lambert(const pt_surface *s)
{
    float wd = mean3(s->kd);
    return s->m->bsdf != RL_BSDF_GGX && !(rl_vmax_comp(s->m->specular) > 0.0f) && wd > 0.0f && isfinite(wd);
}

/* rl_pt_phong_sample_pdf on a Lambertian surface: the diffuse lobe is
 * chosen whatever u_lobe (P_d = 1), the pdf is 1 * cos / pi and f = k_d / pi,
 * written so that every float is the general path's. */
static bool lambert_sample(const pt_surface *s, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight, float *pdf_out)
{
    rl_vec3 dir = around(s->ns, sqrtf(1.0f - u1), 2.0f * RL_PI * u2);
    float cos_theta = rl_dot(s->ns, dir);
    if (cos_theta <= 0.0f || rl_dot(s->ng, dir) <= 0.0f)
        return false;
    float pdf = cos_theta / RL_PI;
    if (!(pdf > 0.0f))
        return false;
    *wi = dir;
    *weight = rl_scale(rl_scale(s->kd, 1.0f / RL_PI), cos_theta / pdf);
    if (pdf_out)
        *pdf_out = pdf;
    return true;
}

bool rl_pt_phong_sample_pdf(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight,
                            float *pdf_out)
{
    if (s->lambert)
        return lambert_sample(s, u1, u2, wi, weight, pdf_out);
    float pd = diffuse_probability(s);
    if (pd < 0.0f)
        return false;
    float phi = 2.0f * RL_PI * u2;
    rl_vec3 dir;
    if (u_lobe < pd) {
        dir = around(s->ns, sqrtf(1.0f - u1), phi);          /* cosine-weighted */
    } else {
        float n = rl_maxf(s->m->shininess, 0.0f);
        dir = around(mirror_dir(s), powf(u1, 1.0f / (n + 1.0f)), phi);   /* cos^n lobe */
    }
    float cos_theta = rl_dot(s->ns, dir);
    if (cos_theta <= 0.0f || rl_dot(s->ng, dir) <= 0.0f)
        return false;
    float pdf = rl_pt_phong_pdf(s, dir);
    if (!(pdf > 0.0f))
        return false;
    *wi = dir;
    *weight = rl_scale(rl_pt_phong_eval(s, dir), cos_theta / pdf);
    if (pdf_out)
        *pdf_out = pdf;
    return true;
}
