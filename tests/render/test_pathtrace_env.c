/* test_pathtrace_env.c: issue 37's environment in pt (pathtrace_env.c,
 * environment.c) and its materials in whole images. The importance
 * sampling must draw the density it reports (quadrature over the sphere,
 * chi-square over texel blocks); the irradiance of an upward plane must
 * come out the same by importance sampling, by uniform sampling and by
 * quadrature; and white furnaces, which need no reference image: a
 * diffuse sphere under a constant sky has radiance k_d L everywhere, and
 * glass with Schlick's Fresnel (R + T = 1, nothing absorbed) or a sharp
 * F = 1 GGX metal disappear into it. Small images: seconds. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "render/pathtrace_internal.h"
#include "rl/rl_render.h"
#include "rl/rl_rng.h"
#include "render/render_fixtures.h"

#define PI_D 3.14159265358979323846
#define MAP_W 32
#define MAP_H 16

/* A sky: a bright "sun" texel block, a gradient towards the horizon and a
 * dark ground; nothing is zero (every texel reachable) except one black
 * column, which light samples must never pick. */
static rl_texture *sky_map(void)
{
    rl_vec4 t[MAP_W * MAP_H];
    for (int y = 0; y < MAP_H; ++y)
        for (int x = 0; x < MAP_W; ++x) {
            float v = ((float)y + 0.5f) / MAP_H;
            rl_vec3 c = y < MAP_H / 2 ? rl_v3(0.3f + v, 0.5f + v, 1.0f) : rl_v3(0.2f, 0.15f, 0.1f);
            if (x >= 20 && x < 22 && y >= 3 && y < 5)
                c = rl_v3(60.0f, 50.0f, 40.0f);
            if (x == 7)
                c = rl_v3s(0.0f);
            t[y * MAP_W + x] = rl_v4(c.x, c.y, c.z, 1.0f);
        }
    rl_texture *tex = NULL;
    assert_int_equal(rl_texture_create(MAP_W, MAP_H, t, &tex), RL_OK);
    return tex;
}

static double lum(rl_vec3 c)
{
    return (c.x + c.y + c.z) / 3.0;
}

/* Quadrature over the sphere in (u, v), SUB x SUB points per texel. */
#define SUB 8

static void test_environment_pdf_integrates_to_one_and_matches_its_samples(void **state)
{
    (void)state;
    rl_texture *map = sky_map();
    rl_environment env = { .radiance = rl_v3s(1.0f), .map = map, .rotation_deg = 30.0f };
    pt_env e;
    memset(&e, 0, sizeof e);
    assert_int_equal(rl_pt_env_build(&e, &env, false), RL_OK);
    assert_true(e.sampled);

    /* Mass of the pdf per block of 4 x 4 texels (in u, v) and in all. */
    enum { BX = MAP_W / 4, BY = MAP_H / 4 };
    double mass[BX * BY] = { 0 }, total = 0.0;
    for (int y = 0; y < MAP_H * SUB; ++y) {
        double v = (y + 0.5) / (MAP_H * SUB);
        for (int x = 0; x < MAP_W * SUB; ++x) {
            double u = (x + 0.5) / (MAP_W * SUB);
            rl_vec3 d = rl_environment_direction(&env, (float)u, (float)v);
            double dw = 2.0 * PI_D * PI_D * sin(PI_D * v) / ((double)MAP_W * SUB * MAP_H * SUB);
            double p = rl_pt_env_pdf(&e, d) * dw;
            total += p;
            mass[(y / SUB / 4) * BX + x / SUB / 4] += p;
        }
    }
    assert_float_equal(total, 1.0, 0.003);

    rl_rng r;
    rl_rng_seed(&r, 9, 9);
    const int n = 100000;
    double count[BX * BY] = { 0 };
    for (int k = 0; k < n; ++k) {
        rl_vec3 d;
        float pdf;
        if (!rl_pt_env_sample(&e, rl_rng_float(&r), rl_rng_float(&r), &d, &pdf))
            continue;
        assert_float_equal(rl_length(d), 1.0f, 1e-4f);
        assert_float_equal(pdf, rl_pt_env_pdf(&e, d), 1e-5f * pdf);
        /* The black column is never drawn. */
        assert_true(lum(rl_environment_radiance(&env, d)) > 0.0);
        rl_vec2 uv = rl_environment_uv(&env, d);
        int bx = (int)(uv.x * MAP_W) / 4, by = (int)(uv.y * MAP_H) / 4;
        bx = bx >= BX ? BX - 1 : bx;
        by = by >= BY ? BY - 1 : by;
        count[by * BX + bx] += 1.0;
    }
    double chi2 = 0.0;
    int used = 0;
    for (int b = 0; b < BX * BY; ++b) {
        double want = n * mass[b];
        if (want < 5.0)
            continue;
        chi2 += (count[b] - want) * (count[b] - want) / want;
        ++used;
    }
    print_message("env pdf: mass %.5f, chi2 %.1f over %d blocks\n", total, chi2, used);
    /* used - 1 degrees of freedom; 31 -> the 99.9 % quantile is 61.1. */
    assert_true(used >= 20);
    assert_true(chi2 < 2.0 * used);
    rl_pt_env_release(&e);
    rl_texture_release(map);
}

/* The irradiance of a plane facing +y, E = int L(w) cos(theta) dw over the
 * upper hemisphere: by quadrature, by the environment's importance
 * sampling and by uniform sampling of the hemisphere; the estimates agree
 * within their noise, and importance sampling has the lower variance. */
static void test_irradiance_by_importance_and_uniform_sampling_agree_with_quadrature(void **state)
{
    (void)state;
    rl_texture *map = sky_map();
    rl_environment env = { .radiance = rl_v3s(1.0f), .map = map, .rotation_deg = -75.0f };
    pt_env e;
    memset(&e, 0, sizeof e);
    assert_int_equal(rl_pt_env_build(&e, &env, false), RL_OK);

    double quad = 0.0;
    for (int y = 0; y < MAP_H * SUB; ++y) {
        double v = (y + 0.5) / (MAP_H * SUB);
        for (int x = 0; x < MAP_W * SUB; ++x) {
            double u = (x + 0.5) / (MAP_W * SUB);
            rl_vec3 d = rl_environment_direction(&env, (float)u, (float)v);
            if (d.y <= 0.0f)
                continue;
            double dw = 2.0 * PI_D * PI_D * sin(PI_D * v) / ((double)MAP_W * SUB * MAP_H * SUB);
            quad += lum(rl_environment_radiance(&env, d)) * d.y * dw;
        }
    }

    rl_rng r;
    rl_rng_seed(&r, 4, 2);
    const int n = 50000;
    double is = 0.0, is2 = 0.0, un = 0.0, un2 = 0.0;
    for (int k = 0; k < n; ++k) {
        rl_vec3 d;
        float pdf;
        double x = 0.0;
        if (rl_pt_env_sample(&e, rl_rng_float(&r), rl_rng_float(&r), &d, &pdf) && d.y > 0.0f)
            x = lum(rl_environment_radiance(&env, d)) * d.y / pdf;
        is += x;
        is2 += x * x;
        /* Uniform on the upper hemisphere: pdf 1 / (2 pi). */
        float cy = rl_rng_float(&r), phi = 2.0f * RL_PI * rl_rng_float(&r), sy = sqrtf(1.0f - cy * cy);
        rl_vec3 w = rl_v3(sy * cosf(phi), cy, sy * sinf(phi));
        double z = lum(rl_environment_radiance(&env, w)) * cy * 2.0 * PI_D;
        un += z;
        un2 += z * z;
    }
    is /= n;
    un /= n;
    double var_is = is2 / n - is * is, var_un = un2 / n - un * un;
    double se_is = sqrt(var_is / n), se_un = sqrt(var_un / n);
    print_message("irradiance: quadrature %.4f, importance %.4f +- %.4f, uniform %.4f +- %.4f; "
                  "variance ratio uniform / importance %.1f\n", quad, is, se_is, un, se_un, var_un / var_is);
    assert_float_equal(is, quad, 4.0 * se_is + 0.002 * quad);
    assert_float_equal(un, quad, 4.0 * se_un + 0.002 * quad);
    assert_true(var_is < var_un);
    rl_pt_env_release(&e);
    rl_texture_release(map);
}

/* A unit sphere of material m under a constant environment L, seen whole. */
static rl_scene *sphere_under_sky(const rl_material *m, float L)
{
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    uint32_t mat, mesh, node;
    assert_int_equal(rl_scene_add_material(s, m, &mat), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "sphere", "segments=48,rings=24", mat, &mesh), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "ball", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, mesh), RL_OK);
    assert_int_equal(rl_scene_set_environment(s, &(rl_environment_desc){ .color = rl_v3s(L) }), RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    return s;
}

/* Mean radiance over the sphere's pixels (ID layer of a raster pass is not
 * pt's, so the pixels are told by their distance from the image centre)
 * and over the background's. */
static double furnace_with(const char *algo, const rl_material *m, const char *max_depth, const char *ggx_ms,
                           double want_ball, double tol)
{
    const float L = 1.5f;
    rl_scene *s = sphere_under_sky(m, L);
    const int size = 32;
    rl_camera cam = { .eye = rl_v3(0.0f, 0.0f, 4.0f), .target = rl_v3(0.0f, 0.0f, 0.0f), .up = rl_v3(0, 1, 0),
                      .fov_deg = 40.0f, .width = size, .height = size };
    rl_renderer *r = fx_make(algo, (const char *const[]){ "spp", "32", "max_depth", max_depth, "ggx_ms", ggx_ms,
                                                          NULL });
    rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
    rl_renderer_release(r);
    /* The sphere's radius on screen: 1 / (4 tan 20 deg) of the half-height. */
    double r_px = 0.5 * size / (sqrt(15.0) * tan(20.0 * PI_D / 180.0));
    double ball = 0.0, sky = 0.0;
    int nb = 0, ns = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            double dx = x + 0.5 - 0.5 * size, dy = y + 0.5 - 0.5 * size, rr = sqrt(dx * dx + dy * dy);
            rl_vec4 c = img->color[y * size + x];
            if (rr < r_px - 1.5) {
                ball += (c.x + c.y + c.z) / 3.0;
                ++nb;
            } else if (rr > r_px + 1.5) {
                sky += (c.x + c.y + c.z) / 3.0;
                ++ns;
            }
        }
    ball /= nb;
    sky /= ns;
    print_message("furnace %s %s ggx_ms=%s: ball %.4f (want %.4f), sky %.4f (want %.4f)\n", algo, m->name, ggx_ms,
                  ball / L, want_ball, sky / L, 1.0);
    assert_true(nb > 150 && ns > 300);
    assert_float_equal(sky / L, 1.0, 1e-5);
    assert_float_equal(ball / L, want_ball, tol);
    rl_image_release(img);
    rl_scene_release(s);
    return ball / L;
}

static void furnace(const rl_material *m, const char *max_depth, double want_ball, double tol)
{
    furnace_with("pt", m, max_depth, "true", want_ball, tol);
}

static void test_white_furnaces_under_a_constant_environment(void **state)
{
    (void)state;
    /* Lambertian: a convex object sees only the sky, L_o = k_d L. */
    rl_material diffuse = rl_material_default();
    snprintf(diffuse.name, sizeof diffuse.name, "diffuse");
    diffuse.diffuse = rl_v3s(0.8f);
    furnace(&diffuse, "2", 0.8, 0.01);
    /* Glass with Schlick's Fresnel: reflected and refracted light add up to
     * all of it, so the sphere vanishes (paths cut at max_depth 24 inside
     * lose a negligible share). */
    rl_material glass = rl_material_default();
    snprintf(glass.name, sizeof glass.name, "glass");
    glass.diffuse = rl_v3s(0.0f);
    glass.transmissivity = 1.0f;
    glass.fresnel = RL_FRESNEL_SCHLICK;
    furnace(&glass, "24", 1.0, 0.01);
    /* A GGX metal with F = 1 and roughness 0.1 keeps > 99.9 % per bounce. */
    rl_material metal = rl_material_default();
    snprintf(metal.name, sizeof metal.name, "metal");
    metal.diffuse = rl_v3s(1.0f);
    metal.bsdf = RL_BSDF_GGX;
    metal.roughness = 0.1f;
    metal.metallic = 1.0f;
    furnace(&metal, "2", 1.0, 0.01);
    /* A plastic: k_d = 0.5 under a dielectric coat (F0 = 0.04). Its
     * albedo lies near k_d: the coat lets about (1 - F)^2 of the diffuse
     * light through (0.5 * 0.91 * 0.96 = 0.44 at normal view) and reflects
     * about F (0.04, more towards the rim). A loose check: the exact
     * albedo is test_pathtrace_bsdf.c's quadrature. */
    rl_material plastic = metal;
    snprintf(plastic.name, sizeof plastic.name, "plastic");
    plastic.diffuse = rl_v3s(0.5f);
    plastic.metallic = 0.0f;
    plastic.roughness = 0.4f;
    furnace(&plastic, "2", 0.48, 0.04);
}

/* What single scattering keeps of the sky over the pixels furnace_with
 * counts as the ball: the albedo table E at each pixel centre's view
 * cosine on the unit sphere, seen from (0, 0, 4) with 40 degrees. */
static double ball_single_scattering(float roughness)
{
    const int size = 32;
    double r_px = 0.5 * size / (sqrt(15.0) * tan(20.0 * PI_D / 180.0)), t = tan(20.0 * PI_D / 180.0);
    double sum = 0.0;
    int n = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            double dx = x + 0.5 - 0.5 * size, dy = y + 0.5 - 0.5 * size;
            if (sqrt(dx * dx + dy * dy) >= r_px - 1.5)
                continue;
            double d[3] = { dx / (0.5 * size) * t, -dy / (0.5 * size) * t, -1.0 };
            double len = sqrt(d[0] * d[0] + d[1] * d[1] + 1.0);
            double b = 4.0 * d[2] / len, c = 16.0 - 1.0;      /* |o + s d|^2 = 1, o = (0, 0, 4) */
            double s_hit = -b - sqrt(b * b - c);
            double pz = 4.0 + s_hit * d[2] / len;
            double px = s_hit * d[0] / len, py = s_hit * d[1] / len;
            double mu = -(px * d[0] + py * d[1] + pz * d[2]) / len;
            sum += rl_pt_ggx_ms_albedo(roughness, (float)mu);
            ++n;
        }
    return sum / n;
}

/* GGX's energy compensation in whole images (pathtrace_ggx.c): an F = 1
 * metal sphere of roughness 0.5 and 1 vanishes into the sky with ggx_ms
 * (the default), and without it keeps what single scattering keeps. */
static void test_ggx_energy_compensation_furnace(void **state)
{
    (void)state;
    rl_material metal = rl_material_default();
    snprintf(metal.name, sizeof metal.name, "metal");
    metal.diffuse = rl_v3s(1.0f);
    metal.bsdf = RL_BSDF_GGX;
    metal.metallic = 1.0f;
    const float roughness[] = { 0.5f, 1.0f };
    for (int i = 0; i < 2; ++i) {
        metal.roughness = roughness[i];
        furnace_with("pt", &metal, "2", "true", 1.0, 0.015);
        furnace_with("pt", &metal, "2", "false", ball_single_scattering(roughness[i]), 0.015);
    }
}

/* The Cornell box restyled from JSON: GGX walls (glossy plastic) and a
 * Schlick chrome-and-glass mix would bias next-event estimation or the
 * BSDF hits if the GGX pdf or its MIS weights were wrong; mis=on (light
 * samples and BSDF hits weighted by the power heuristic) and mis=off (the
 * thesis' light samples alone, hits of the lamp not counted) are two
 * independent estimators of the same image, whose channel means agree. */
static void test_ggx_cornell_box_mis_on_and_off_agree(void **state)
{
    (void)state;
    const char *base = getenv("RL_TEST_TMP");
    char path[1100];
    snprintf(path, sizeof path, "%s/ggx_cornell.json", base && base[0] ? base : ".");
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    fputs("{ \"base\": \"cornell\", \"materials\": {\n"
          "  \"white\": { \"diffuse\": 0.7, \"bsdf\": \"ggx\", \"roughness\": 0.35 },\n"
          "  \"red\": { \"diffuse\": [0.8, 0.1, 0.05], \"bsdf\": \"ggx\", \"roughness\": 0.2, \"metallic\": 1 },\n"
          "  \"green\": { \"diffuse\": [0.1, 0.5, 0.1], \"bsdf\": \"ggx\", \"roughness\": 0.6,\n"
          "             \"reflectivity\": 0.3, \"specular\": 0.9, \"fresnel\": \"schlick\" } } }\n", f);
    assert_int_equal(fclose(f), 0);
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_load(path, NULL, &s), RL_OK);
    rl_camera cam;
    assert_int_equal(rl_scene_get_camera(s, NULL, &cam), RL_OK);
    cam.width = cam.height = 16;
    double mean[2][3] = { { 0 } };
    const char *mis[2] = { "on", "off" };
    for (int k = 0; k < 2; ++k) {
        rl_renderer *r = fx_make("pt", (const char *const[]){ "spp", "256", "mis", mis[k], NULL });
        rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
        rl_renderer_release(r);
        /* Below the lamp's rows: the lamp itself is counted alike. */
        for (int y = 3; y < 16; ++y)
            for (int x = 0; x < 16; ++x) {
                rl_vec4 c = img->color[y * 16 + x];
                mean[k][0] += c.x / (13.0 * 16.0);
                mean[k][1] += c.y / (13.0 * 16.0);
                mean[k][2] += c.z / (13.0 * 16.0);
            }
        rl_image_release(img);
    }
    print_message("ggx cornell: mis=on %.4f %.4f %.4f, mis=off %.4f %.4f %.4f\n", mean[0][0], mean[0][1], mean[0][2],
                  mean[1][0], mean[1][1], mean[1][2]);
    /* 16 x 13 pixels at 256 spp: about 1 % noise per mean (fixed seeds);
     * a wrong pdf or weight shows as a bias of many per cent. */
    for (int c = 0; c < 3; ++c)
        assert_float_equal(mean[0][c], mean[1][c], 0.03 * mean[1][c]);
    rl_scene_release(s);
}

/* whitted does not light with the environment but shows it where its rays
 * leave the scene. */
static void test_whitted_shows_the_environment(void **state)
{
    (void)state;
    rl_material m = rl_material_default();
    rl_scene *s = sphere_under_sky(&m, 0.75f);
    rl_camera cam = { .eye = rl_v3(0.0f, 0.0f, 4.0f), .target = rl_v3(0.0f, 0.0f, 0.0f), .up = rl_v3(0, 1, 0),
                      .fov_deg = 40.0f, .width = 16, .height = 16 };
    rl_image *img = fx_render("whitted", s, &cam, RL_LAYER_COLOR, NULL, NULL);
    assert_float_equal(img->color[0].x, 0.75f, 1e-6f);            /* a corner: the sky */
    assert_float_equal(img->color[16 * 16 - 1].z, 0.75f, 1e-6f);
    rl_image_release(img);
    rl_scene_release(s);
}

/* bdpt with the environment as an emitter at infinity (bdpt_path.c):
 * white furnaces as pt's (a Lambertian sphere k_d L, an F = 1 GGX metal
 * with the compensation vanishing) and, under the test's sky map, the
 * same image as pt: a grey sphere on a plate, lit by the map alone (the
 * channel means within 1 %, 40 x 40 pixels at 32 samples). */
static void test_bdpt_furnaces_under_a_constant_environment(void **state)
{
    (void)state;
    rl_material diffuse = rl_material_default();
    snprintf(diffuse.name, sizeof diffuse.name, "diffuse");
    diffuse.diffuse = rl_v3s(0.8f);
    furnace_with("bdpt", &diffuse, "2", "true", 0.8, 0.01);
    rl_material metal = rl_material_default();
    snprintf(metal.name, sizeof metal.name, "metal");
    metal.diffuse = rl_v3s(1.0f);
    metal.bsdf = RL_BSDF_GGX;
    metal.metallic = 1.0f;
    metal.roughness = 0.5f;
    furnace_with("bdpt", &metal, "2", "true", 1.0, 0.015);
}

static void channel_means(const rl_image *img, double mean[3])
{
    mean[0] = mean[1] = mean[2] = 0.0;
    size_t n = (size_t)img->width * img->height;
    for (size_t i = 0; i < n; ++i) {
        mean[0] += img->color[i].x;
        mean[1] += img->color[i].y;
        mean[2] += img->color[i].z;
    }
    for (int c = 0; c < 3; ++c)
        mean[c] /= (double)n;
}

static void test_bdpt_and_pt_agree_under_an_environment_map(void **state)
{
    (void)state;
    /* The sky map as a file: a scene takes its environment by path. */
    rl_image *sky = NULL;
    assert_int_equal(rl_image_create(MAP_W, MAP_H, RL_LAYER_COLOR, &sky), RL_OK);
    rl_texture *map = sky_map();
    for (int i = 0; i < MAP_W * MAP_H; ++i)
        sky->color[i] = map->texels[i];
    rl_texture_release(map);
    const char *base = getenv("RL_TEST_TMP");
    char path[1024];
    snprintf(path, sizeof path, "%s/bdpt_sky.exr", base && base[0] ? base : ".");
    assert_int_equal(rl_image_write_exr(sky, path), RL_OK);
    rl_image_release(sky);
    rl_scene *s = NULL;
    assert_int_equal(rl_scene_create(&s), RL_OK);
    rl_material grey = rl_material_default(), floor = rl_material_default();
    snprintf(grey.name, sizeof grey.name, "grey");
    grey.diffuse = rl_v3(0.7f, 0.6f, 0.5f);
    snprintf(floor.name, sizeof floor.name, "floor");
    floor.diffuse = rl_v3s(0.5f);
    uint32_t mg, mf, ball, plate, node;
    assert_int_equal(rl_scene_add_material(s, &grey, &mg), RL_OK);
    assert_int_equal(rl_scene_add_material(s, &floor, &mf), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "sphere", "segments=32,rings=16", mg, &ball), RL_OK);
    assert_int_equal(rl_scene_add_generated(s, "quad", "sx=40,sz=40", mf, &plate), RL_OK);
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "ball", NULL, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, ball), RL_OK);
    rl_mat4 down = rl_mat4_translate(rl_v3(0.0f, -1.0f, 0.0f));
    assert_int_equal(rl_scene_add_node(s, RL_NODE_ROOT, "plate", &down, &node), RL_OK);
    assert_int_equal(rl_scene_node_set_mesh(s, node, plate), RL_OK);
    assert_int_equal(rl_scene_set_environment(s, &(rl_environment_desc){ .path = path, .color = rl_v3s(1.0f) }),
                     RL_OK);
    assert_int_equal(rl_scene_commit(s), RL_OK);
    /* Looking down: no pixel sees the sky straight, all its light comes
     * by the surfaces. */
    rl_camera cam = { .eye = rl_v3(0.0f, 4.0f, 3.0f), .target = rl_v3(0.0f, -0.5f, 0.0f), .up = rl_v3(0, 1, 0),
                      .fov_deg = 45.0f, .width = 40, .height = 40 };
    double mean[2][3];
    const char *algos[] = { "pt", "bdpt" };
    for (int a = 0; a < 2; ++a) {
        rl_renderer *r = fx_make(algos[a], (const char *const[]){ "spp", "32", "max_depth", "3", NULL });
        rl_image *img = fx_render_with(r, s, &cam, RL_LAYER_COLOR, NULL);
        channel_means(img, mean[a]);
        rl_image_release(img);
        rl_renderer_release(r);
    }
    print_message("environment only: pt %.4f %.4f %.4f, bdpt %.4f %.4f %.4f\n", mean[0][0], mean[0][1], mean[0][2],
                  mean[1][0], mean[1][1], mean[1][2]);
    for (int c = 0; c < 3; ++c)
        assert_float_equal(mean[1][c], mean[0][c], 0.01 * mean[0][c]);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_environment_pdf_integrates_to_one_and_matches_its_samples),
        cmocka_unit_test(test_irradiance_by_importance_and_uniform_sampling_agree_with_quadrature),
        cmocka_unit_test(test_white_furnaces_under_a_constant_environment),
        cmocka_unit_test(test_ggx_energy_compensation_furnace),
        cmocka_unit_test(test_ggx_cornell_box_mis_on_and_off_agree),
        cmocka_unit_test(test_whitted_shows_the_environment),
        cmocka_unit_test(test_bdpt_furnaces_under_a_constant_environment),
        cmocka_unit_test(test_bdpt_and_pt_agree_under_an_environment_map),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
