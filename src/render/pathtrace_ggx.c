/* pathtrace_ggx.c: the Cook-Torrance microfacet BRDF of materials with
 * bsdf = ggx (issue 37; the thesis' outlook, Schröder 2017, Sec. 13.4),
 * and the dispatch between it and the modified Phong BRDF of
 * pathtrace_bsdf.c that pt and bdpt call.
 *
 *   f(wi, wo) = f_d + F(wi.h) D(h) G2(wi, wo) / (4 |wi.n| |wo.n|)
 *
 * D: the GGX / Trowbridge-Reitz distribution (Walter et al. 2007) with
 * alpha = roughness^2 (the perceptual mapping of Burley 2012), clamped to
 * ALPHA_MIN so a roughness of 0 stays a very sharp lobe rather than a
 * delta the light samples could never hit.
 * G2: Smith's height-correlated masking-shadowing 1 / (1 + Lambda(wo) +
 * Lambda(wi)) (Heitz 2014, eq. 99), not the separable product G1 G1.
 * F: Schlick 1994 with F0 = lerp(((ior - 1) / (ior + 1))^2, k_d, metallic).
 * f_d: (1 - metallic) k_d / pi (1 - F_d(wi.n)) (1 - F_d(wo.n)), F_d the
 * scalar dielectric Schlick term: the light the coat does not reflect on
 * the way in and out. The product is symmetric, so f stays reciprocal.
 *
 * Sampling: the specular lobe by the distribution of visible normals
 * (Heitz 2018, "Sampling the GGX Distribution of Visible Normals"), the
 * diffuse one by the cosine, picked by estimates of their albedos, with
 * the mixture pdf in the weight (one-sample MIS, as pathtrace_bsdf.c).
 * Single scattering: the light that microfacets send below the horizon or
 * into each other is lost. With F = 1 at normal view that is 0.4 % at
 * roughness 0.25, 8 % at 0.5, 38 % at 0.75 and 69 % at 1 (alpha = 1;
 * tests/render/test_pathtrace_bsdf.c, docs/path-tracing.md).
 *
 * Energy compensation (pt_surface.ggx_ms, the renderers' option ggx_ms;
 * Kulla & Conty 2017, "Revisiting Physically Based Shading at
 * Imageworks"): the lost light comes back as a diffuse-like lobe
 *     f_ms(wi, wo) = F_ms (1 - E(wo.n)) (1 - E(wi.n)) / (pi (1 - E_avg)),
 * E(mu) the albedo of the specular lobe with F = 1, E_avg = 2 int E mu dmu
 * its hemispherical average, so that int f_ms cos dwi = 1 - E(wo.n) when
 * F_ms = 1. Coloured Fresnel: each bounce between microfacets keeps
 * F_avg = 2 int F mu dmu = F0 + (1 - F0) / 21 (Schlick), and the series of
 * bounces gives F_ms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)) per channel.
 * f_ms is symmetric, so f stays reciprocal. It is sampled by the cosine,
 * with the diffuse lobe, its albedo F_ms (1 - E) added to theirs in the
 * lobe choice. E is tabulated over roughness and mu once per process (see
 * ms_build); E_avg is the exact integral of the table's interpolant, so
 * the added lobe returns exactly 1 - E of the table. */
#include <math.h>
#include <pthread.h>

#include "render/pathtrace_internal.h"

#define ALPHA_MIN 1e-3f

static float mean3(rl_vec3 c)
{
    return (c.x + c.y + c.z) * (1.0f / 3.0f);
}

float rl_pt_ggx_alpha(float roughness)
{
    return rl_maxf(roughness * roughness, ALPHA_MIN);
}

float rl_pt_ggx_d(float alpha, float cos_m)
{
    if (!(cos_m > 0.0f))
        return 0.0f;
    float a2 = alpha * alpha, c2 = cos_m * cos_m;
    float k = (a2 - 1.0f) * c2 + 1.0f;
    return a2 / (RL_PI * k * k);
}

/* Smith's Lambda for GGX at a direction whose cosine to the normal is c. */
static float ggx_lambda(float alpha, float c)
{
    if (!(c > 0.0f))
        return INFINITY;
    float tan2 = rl_maxf(0.0f, 1.0f - c * c) / (c * c);
    return 0.5f * (sqrtf(1.0f + alpha * alpha * tan2) - 1.0f);
}

float rl_pt_ggx_g1(float alpha, float cos_w)
{
    return 1.0f / (1.0f + ggx_lambda(alpha, cos_w));
}

float rl_pt_ggx_g2(float alpha, float cos_i, float cos_o)
{
    return 1.0f / (1.0f + ggx_lambda(alpha, cos_i) + ggx_lambda(alpha, cos_o));
}

rl_vec3 rl_pt_ggx_sample_vndf(rl_vec3 wo, float alpha, float u1, float u2)
{
    /* Heitz 2018, Sec. 3-4: stretch the view into the frame of the unit
     * hemisphere configuration, sample the projected disk of that
     * hemisphere (a disk and a half-disk warped by the view's cosine),
     * lift onto the hemisphere and unstretch the normal. */
    rl_vec3 vh = rl_normalize(rl_v3(alpha * wo.x, alpha * wo.y, wo.z));
    float len2 = vh.x * vh.x + vh.y * vh.y;
    rl_vec3 t1 = len2 > 0.0f ? rl_scale(rl_v3(-vh.y, vh.x, 0.0f), 1.0f / sqrtf(len2)) : rl_v3(1.0f, 0.0f, 0.0f);
    rl_vec3 t2 = rl_cross(vh, t1);
    float r = sqrtf(u1), phi = 2.0f * RL_PI * u2;
    float p1 = r * cosf(phi), p2 = r * sinf(phi);
    float blend = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - blend) * sqrtf(rl_maxf(0.0f, 1.0f - p1 * p1)) + blend * p2;
    float p3 = sqrtf(rl_maxf(0.0f, 1.0f - p1 * p1 - p2 * p2));
    rl_vec3 nh = rl_add(rl_add(rl_scale(t1, p1), rl_scale(t2, p2)), rl_scale(vh, p3));
    return rl_normalize(rl_v3(alpha * nh.x, alpha * nh.y, rl_maxf(1e-7f, nh.z)));
}

/* ------------------------------------------------ energy compensation -- */

/* E(mu) is smooth in roughness r (alpha = r^2) and mu except near mu = 0,
 * where it changes fastest: MS_NODES x MS_NODES nodes, evenly spaced in r
 * and in x = sqrt(mu) over [0, 1] (dense at grazing), linear in mu in
 * between. Each
 * node is a midpoint quadrature of MS_QUAD x MS_QUAD cells over the
 * visible-normal sampling (its weight G2 / G1 is in [0, 1] and smooth but
 * for the horizon). The errors against 512^2 cells and between nodes:
 * tests/render/test_pathtrace_bsdf.c. */
#define MS_NODES RL_PT_GGX_MS_NODES
#define MS_QUAD 32
#define MS_MU_MIN 1e-3f          /* node mu = 0: G1 and G2 vanish at the horizon, their ratio does not */

static float ms_e[MS_NODES][MS_NODES];     /* [roughness node][mu node] */
static float ms_eavg[MS_NODES];
static pthread_once_t ms_once = PTHREAD_ONCE_INIT;

double rl_pt_ggx_albedo_quadrature(float alpha, float mu, int cells)
{
    mu = rl_clampf(mu, MS_MU_MIN, 1.0f);
    rl_vec3 wo = rl_v3(sqrtf(rl_maxf(0.0f, 1.0f - mu * mu)), 0.0f, mu);
    float g1 = rl_pt_ggx_g1(alpha, mu);
    double sum = 0.0;
    for (int i = 0; i < cells; ++i) {
        /* u1 = 1 - (1 - x)^2 with x at midpoints: the disk's rim (u1 near
         * 1), where the steepest normals and all of the masking lie and
         * the lift onto the hemisphere is steepest, gets most cells. */
        double x = ((double)i + 0.5) / cells;
        float u1 = (float)(1.0 - (1.0 - x) * (1.0 - x));
        double jac = 2.0 * (1.0 - x);
        double row = 0.0;
        for (int j = 0; j < cells; ++j) {
            float u2 = ((float)j + 0.5f) / (float)cells;
            rl_vec3 m = rl_pt_ggx_sample_vndf(wo, alpha, u1, u2);
            float wi_z = 2.0f * rl_dot(wo, m) * m.z - wo.z;
            if (wi_z > 0.0f)
                row += rl_pt_ggx_g2(alpha, wi_z, mu) / g1;
        }
        sum += row * jac;
    }
    return sum / ((double)cells * (double)cells);
}

static float ms_mu(int j)
{
    float x = (float)j / (float)(MS_NODES - 1);
    return x * x;
}

static void ms_build(void)
{
    for (int i = 0; i < MS_NODES; ++i) {
        float alpha = rl_pt_ggx_alpha((float)i / (float)(MS_NODES - 1));
        for (int j = 0; j < MS_NODES; ++j)
            ms_e[i][j] = (float)rl_pt_ggx_albedo_quadrature(alpha, ms_mu(j), MS_QUAD);
        /* 2 int E(mu) mu dmu of the piecewise-linear E, exactly: on
         * [a, b] the segment adds (b - a) / 6 (E_a (2a + b) + E_b (a + 2b)). */
        double avg = 0.0;
        for (int j = 0; j + 1 < MS_NODES; ++j) {
            double a = ms_mu(j), b = ms_mu(j + 1);
            avg += (b - a) / 6.0 * (ms_e[i][j] * (2.0 * a + b) + ms_e[i][j + 1] * (a + 2.0 * b));
        }
        ms_eavg[i] = (float)(2.0 * avg);
    }
}

/* Roughness r's node below and the weight of the one above. */
static int ms_row(float roughness, float *t)
{
    float x = (roughness > 0.0f ? rl_minf(roughness, 1.0f) : 0.0f) * (float)(MS_NODES - 1);
    int i = (int)x;
    if (i > MS_NODES - 2)
        i = MS_NODES - 2;
    *t = x - (float)i;
    return i;
}

float rl_pt_ggx_ms_albedo(float roughness, float mu)
{
    pthread_once(&ms_once, ms_build);
    float t;
    int i = ms_row(roughness, &t);
    mu = mu > 0.0f ? rl_minf(mu, 1.0f) : 0.0f;     /* a NaN must not index the table */
    int j = (int)(sqrtf(mu) * (float)(MS_NODES - 1));
    if (j > MS_NODES - 2)
        j = MS_NODES - 2;
    float a = ms_mu(j), b = ms_mu(j + 1);
    float v = rl_clampf((mu - a) / (b - a), 0.0f, 1.0f);
    float e0 = ms_e[i][j] + (ms_e[i][j + 1] - ms_e[i][j]) * v;
    float e1 = ms_e[i + 1][j] + (ms_e[i + 1][j + 1] - ms_e[i + 1][j]) * v;
    return e0 + (e1 - e0) * t;
}

void rl_pt_ggx_ms_tables(float *e, float *e_avg)
{
    pthread_once(&ms_once, ms_build);
    for (int i = 0; i < MS_NODES; ++i) {
        for (int j = 0; j < MS_NODES; ++j)
            e[i * MS_NODES + j] = ms_e[i][j];
        e_avg[i] = ms_eavg[i];
    }
}

float rl_pt_ggx_ms_average(float roughness)
{
    pthread_once(&ms_once, ms_build);
    float t;
    int i = ms_row(roughness, &t);
    return ms_eavg[i] + (ms_eavg[i + 1] - ms_eavg[i]) * t;
}

/* The parameters of s's GGX material at its outgoing direction. */
typedef struct ggx_lobe {
    rl_onb frame;              /* n = the shading normal */
    rl_vec3 wo;                /* s->v in the frame */
    float alpha;
    rl_vec3 f0;                /* Schlick F0 of the specular lobe, per channel */
    float f0_dielectric;       /* the scalar one of the diffuse lobe's coat */
    rl_vec3 diffuse;           /* (1 - metallic) k_d */
    float p_spec;              /* probability of sampling the specular lobe; < 0: black */
    /* Energy compensation: f_ms(wi) = ms (1 - E(wi.z)); zero without it. */
    rl_vec3 ms;
    float roughness;
} ggx_lobe;

static float schlick_weight(float c)
{
    float k = 1.0f - rl_clampf(c, 0.0f, 1.0f), k2 = k * k;
    return k2 * k2 * k;
}

static rl_vec3 schlick3(rl_vec3 f0, float c)
{
    float w = schlick_weight(c);
    return rl_add(f0, rl_scale(rl_sub(rl_v3s(1.0f), f0), w));
}

static ggx_lobe ggx_setup(const pt_surface *s)
{
    const rl_material *m = s->m;
    ggx_lobe g;
    g.frame = rl_onb_from_normal(s->ns);
    g.wo = rl_onb_to_local(&g.frame, s->v);
    g.alpha = rl_pt_ggx_alpha(m->roughness);
    float r0 = (m->ior - 1.0f) / (m->ior + 1.0f);
    g.f0_dielectric = r0 * r0;
    float metal = rl_clampf(m->metallic, 0.0f, 1.0f);
    g.f0 = rl_add(rl_scale(rl_v3s(g.f0_dielectric), 1.0f - metal), rl_scale(s->kd, metal));
    g.diffuse = rl_scale(s->kd, 1.0f - metal);
    /* The lobes' albedos at wo, roughly: the specular one is about F at
     * normal-ish microfacets, the diffuse one what the coat lets through. */
    float w_spec = mean3(schlick3(g.f0, g.wo.z));
    float w_diff = mean3(g.diffuse) * (1.0f - (g.f0_dielectric + (1.0f - g.f0_dielectric) * schlick_weight(g.wo.z)));
    g.roughness = m->roughness;
    g.ms = rl_v3s(0.0f);
    if (s->ggx_ms) {
        float e_avg = rl_pt_ggx_ms_average(m->roughness);
        float e_o = rl_pt_ggx_ms_albedo(m->roughness, g.wo.z);
        /* Smooth surfaces lose nothing, and 1 - E_avg would only be the
         * tables' rounding. */
        if (1.0f - e_avg > 1e-4f && e_o < 1.0f) {
            rl_vec3 f_avg = rl_add(g.f0, rl_scale(rl_sub(rl_v3s(1.0f), g.f0), 1.0f / 21.0f));
            rl_vec3 f_ms = rl_mul(rl_mul(f_avg, f_avg), rl_v3s(e_avg));
            f_ms = rl_mul(f_ms, rl_v3(1.0f / (1.0f - f_avg.x * (1.0f - e_avg)), 1.0f / (1.0f - f_avg.y * (1.0f - e_avg)),
                                      1.0f / (1.0f - f_avg.z * (1.0f - e_avg))));
            g.ms = rl_scale(f_ms, (1.0f - e_o) / (RL_PI * (1.0f - e_avg)));
            /* Its albedo at wo is F_ms (1 - E(wo)) = pi ms. */
            w_diff += RL_PI * mean3(g.ms);
        }
    }
    g.p_spec = w_spec + w_diff > 0.0f ? w_spec / (w_spec + w_diff) : -1.0f;
    return g;
}

static rl_vec3 ggx_eval_local(const ggx_lobe *g, rl_vec3 wi)
{
    float ci = wi.z, co = g->wo.z;
    if (!(ci > 0.0f) || !(co > 0.0f))
        return rl_v3s(0.0f);
    float fd0 = g->f0_dielectric;
    float coat = (1.0f - (fd0 + (1.0f - fd0) * schlick_weight(ci))) * (1.0f - (fd0 + (1.0f - fd0) * schlick_weight(co)));
    rl_vec3 f = rl_scale(g->diffuse, coat / RL_PI);
    if (rl_vmax_comp(g->ms) > 0.0f)
        f = rl_add(f, rl_scale(g->ms, rl_maxf(0.0f, 1.0f - rl_pt_ggx_ms_albedo(g->roughness, ci))));
    rl_vec3 h = rl_add(wi, g->wo);
    if (!(rl_length2(h) > 0.0f))
        return f;
    h = rl_normalize(h);
    float spec = rl_pt_ggx_d(g->alpha, h.z) * rl_pt_ggx_g2(g->alpha, ci, co) / (4.0f * ci * co);
    return rl_add(f, rl_scale(schlick3(g->f0, rl_dot(wi, h)), spec));
}

static float ggx_pdf_local(const ggx_lobe *g, rl_vec3 wi)
{
    float ci = wi.z, co = g->wo.z;
    if (g->p_spec < 0.0f || !(ci > 0.0f) || !(co > 0.0f))
        return 0.0f;
    float pdf = (1.0f - g->p_spec) * ci / RL_PI;
    rl_vec3 h = rl_add(wi, g->wo);
    if (g->p_spec > 0.0f && rl_length2(h) > 0.0f) {
        h = rl_normalize(h);
        /* Heitz 2018, eq. 17 with the reflection's Jacobian 1 / (4 wo.h):
         * D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 wo.n). */
        pdf += g->p_spec * rl_pt_ggx_g1(g->alpha, co) * rl_pt_ggx_d(g->alpha, h.z) / (4.0f * co);
    }
    return pdf;
}

rl_vec3 rl_pt_ggx_eval(const pt_surface *s, rl_vec3 wi)
{
    ggx_lobe g = ggx_setup(s);
    return ggx_eval_local(&g, rl_onb_to_local(&g.frame, wi));
}

float rl_pt_ggx_pdf(const pt_surface *s, rl_vec3 wi)
{
    ggx_lobe g = ggx_setup(s);
    return ggx_pdf_local(&g, rl_onb_to_local(&g.frame, wi));
}

bool rl_pt_ggx_sample(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight)
{
    ggx_lobe g = ggx_setup(s);
    if (g.p_spec < 0.0f || !(g.wo.z > 0.0f))
        return false;
    rl_vec3 local;
    if (u_lobe < g.p_spec) {
        rl_vec3 m = rl_pt_ggx_sample_vndf(g.wo, g.alpha, u1, u2);
        local = rl_sub(rl_scale(m, 2.0f * rl_dot(g.wo, m)), g.wo);
    } else {
        float r = sqrtf(u1), phi = 2.0f * RL_PI * u2;
        local = rl_v3(r * cosf(phi), r * sinf(phi), sqrtf(rl_maxf(0.0f, 1.0f - u1)));
    }
    if (!(local.z > 0.0f))
        return false;          /* reflected below the horizon: single scattering loses it */
    rl_vec3 dir = rl_normalize(rl_onb_to_world(&g.frame, local));
    if (rl_dot(s->ng, dir) <= 0.0f)
        return false;
    float pdf = ggx_pdf_local(&g, local);
    if (!(pdf > 0.0f) || !isfinite(pdf))
        return false;
    *wi = dir;
    *weight = rl_scale(ggx_eval_local(&g, local), local.z / pdf);
    return true;
}

rl_vec3 rl_pt_bsdf_eval(const pt_surface *s, rl_vec3 wi)
{
    return s->m->bsdf == RL_BSDF_GGX ? rl_pt_ggx_eval(s, wi) : rl_pt_phong_eval(s, wi);
}

float rl_pt_bsdf_pdf(const pt_surface *s, rl_vec3 wi)
{
    return s->m->bsdf == RL_BSDF_GGX ? rl_pt_ggx_pdf(s, wi) : rl_pt_phong_pdf(s, wi);
}

bool rl_pt_bsdf_sample(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight)
{
    return s->m->bsdf == RL_BSDF_GGX ? rl_pt_ggx_sample(s, u_lobe, u1, u2, wi, weight)
                                     : rl_pt_phong_sample(s, u_lobe, u1, u2, wi, weight);
}

bool rl_pt_bsdf_sample_pdf(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight,
                           float *pdf)
{
    if (s->m->bsdf != RL_BSDF_GGX)
        return rl_pt_phong_sample_pdf(s, u_lobe, u1, u2, wi, weight, pdf);
    if (!rl_pt_ggx_sample(s, u_lobe, u1, u2, wi, weight))
        return false;
    if (pdf)
        *pdf = rl_pt_ggx_pdf(s, *wi);
    return true;
}

bool rl_pt_bsdf_needs_lobe(const rl_material *m)
{
    return m->bsdf == RL_BSDF_GGX || rl_vmax_comp(m->specular) > 0.0f;
}

/* ------------------------------------------------------ specular events -- */

void rl_pt_specular_event(const pt_surface *s, float u_event, rl_vec3 *dir, rl_vec3 *weight, bool *refracted)
{
    const rl_material *m = s->m;
    float k_r = m->reflectivity, k_t = m->transmissivity;
    rl_vec3 d = rl_neg(s->v);
    float ior = m->ior >= 1.0f ? m->ior : 1.0f;
    float eta = s->front ? ior : 1.0f / ior;       /* n_t / n_i */
    float cos_i = rl_dot(s->ns, s->v);
    *dir = rl_reflect(d, s->ns);
    *weight = rl_v3s(1.0f);
    *refracted = false;
    if (u_event < k_r) {
        /* A mirror reflects F of the light; F0 = k_s (a metal's colour). */
        if (m->fresnel == RL_FRESNEL_SCHLICK)
            *weight = schlick3(m->specular, cos_i);
        return;
    }
    if (m->fresnel == RL_FRESNEL_SCHLICK) {
        /* Within the k_t event, reflect with probability F and refract
         * otherwise: each keeps the weight 1 (R + T = 1). u_event is
         * uniform in [k_r, k_r + k_t) here, so it is rescaled for reuse. */
        float F = rl_fresnel_schlick(cos_i, eta);
        float u = k_t > 0.0f ? (u_event - k_r) / k_t : 0.0f;
        if (u < F)
            return;
    }
    /* Entering when the geometric normal faced the ray, as trace.c; total
     * internal reflection mirrors instead. */
    rl_vec3 t;
    if (rl_refract(d, s->ns, s->front ? 1.0f / ior : ior, &t)) {
        *dir = rl_normalize(t);
        *refracted = true;
    }
}
