/* gl_pathtrace.c: renderer "gl-pt", the path tracer "pt" (pathtrace.c) in
 * GLSL compute shaders on OpenGL 4.5 (src/gl/gl_pt.c), as Schröder 2017
 * runs it on the GPU (Ch. 5, 6): one thread per pixel, the per-pixel
 * generator states in an image (Sec. 5.3), progressive accumulation in an
 * rgba32f image (Sec. 6.5, eq. 8), shadow and secondary rays through the
 * BVH, the uniform grid (Sec. 5.4) or the Line Space (Sec. 7).
 *
 * Same estimator as pt: this file builds what pt builds on the CPU for it
 * (pathtrace_backend.c: the ray offset, the covering quad light of every
 * emissive triangle, the light table of mis=on) and seeds the per-pixel
 * states exactly as pt seeds them (rl_rng_gpu_seed per pixel; for sobol
 * the scramble seed rl_pt_pixel_seed), so that with the same options the
 * two converge to the same image; with rng=lcg, tausworthe or hybrid they
 * even draw the same numbers per pixel.
 *
 * Options: pt's names and defaults where ported (spp, max_depth, rr,
 * rr_depth, rng, mis, seed, shadow, diffuse, specular, primary,
 * checkerboard, accumulate, filter, filter_fade, atrous_*, grid_res, ls_n,
 * ls_k, ls_dynamic, ls_origin, light_samples, background, env_sampling,
 * ggx_ms, adaptive, adaptive_threshold, adaptive_min_spp, threads,
 * shadowmap_size), device (rl_gl.h) and ls_build. Values pt has and gl-pt
 * has not ported are refused with an option error naming what is ported:
 * shadow=embree, diffuse=embree; pt's ls_file is not in the table, and
 * adaptive=on with checkerboard is refused at render time.
 *
 * Adaptive sampling (adaptive=on): pt's algorithm (pathtrace.c
 * adaptive_passes) with the per-pixel counts, the squared luminance, the
 * errors and the shares on the GPU (gl_pt.c adaptive_frame).
 *
 * shadow=shadowmap (Sec. 8.6): pt's cube shadow maps (raster/shadowmap.c,
 * the same size, bias and jitter) drawn by GL, depth-only passes per light
 * and face (gl_pt.c rl_gl_pt_set_shadowmaps), looked up in the shader as
 * rl_shadowmap_visible looks them up; as in pt, emissive triangles are
 * then no light source of their own (no triangle lights).
 *
 * primary=raster (Sec. 8.1): every frame a GL drawer (gl_drawer.c) draws
 * the scene's triangle IDs, unlit, as rl_gbuffer_raster draws them with
 * the software rasterizer; the compute shader starts each pixel's path
 * where the pixel-centre ray meets the plane of the triangle drawn there.
 * checkerboard (Sec. 8.5): the shader traces the pixels with x + y +
 * frame even, each class numbering its own samples, and the first frame's
 * holes are the mean of their traced 4-neighbours, as pt's resolve().
 * Filters (Sec. 8.2): pt's own (rl_pt_filter_image, the library's CPU
 * filters) on the read-back image, guided by the G-buffer pt would use:
 * traced at the pixel centres, or with primary=raster made from the GL
 * pass's triangle IDs (rl_gbuffer_from_ids). Ray counts come from atomic
 * counters in the shader (gl_pt.h).
 *
 * The Line Space backends (ls-candidates, ls-pnmt, ls-preillum) walk the
 * Line Space pt builds (pathtrace_backend.c, the same rl_linespace and
 * voxel offsets), uploaded to the GPU (gl_linespace.h); ls_build=gpu builds
 * the candidate lists on the GPU instead, from pt's CPU grid.
 *
 * The scene's environment (issue 37): the distribution pt builds for it
 * (rl_pt_env_build, pathtrace_env.c; by radiance, or with
 * env_sampling=uniform by solid angle) and the map's radiance go to the
 * tracer as plain arrays (rl_gl_pt_set_environment); the shader looks it up
 * and samples it as pt does, at pt's slot with pt's MIS weights. Schlick's
 * Fresnel on mirrors and dielectrics is the shader's too (pt's
 * rl_pt_specular_event), and so is the GGX BRDF (pathtrace_ggx.c) with
 * its energy compensation (ggx_ms): the shader reads pt's own tables,
 * handed to the tracer as plain floats (rl_gl_pt_desc.ggx_ms).
 *
 * Depth and ID layers, where the image has them, come from that G-buffer,
 * as pt writes them. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <math.h>
#include <omp.h>

#include "core/error.h"
#include "core/params.h"
#include "gl/gl_pt.h"
#include "render/bdpt_internal.h"
#include "render/pathtrace_internal.h"
#include "render/renderer.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "rl/rl_timer.h"

_Static_assert(RL_GL_PT_RAY_TYPES == RL_RAY_TYPE_COUNT, "gl-pt counts rays in rl_ray_type's order");

/* The choices it shares with pt are pt's lists (pathtrace_internal.h), so
 * that a value pt knows gets "not ported" rather than "unknown" where
 * gl-pt lacks it (gl_pt_check). */
static const char *const ls_build_choices[] = { "cpu", "gpu", NULL };

static const rl_option_info gl_pt_options[] = {
    { "spp", RL_OPT_INT, "1", "paths per pixel and frame (one compute dispatch each)", 1, 65536, NULL },
    { "max_depth", RL_OPT_INT, "-1",
      "surface interactions after the camera hit (0: direct light only; -1: the scene's root attribute "
      "max_path_length, else 3)", -1, 1024, NULL },
    { "rr", RL_OPT_BOOL, "true", "Russian roulette on the path length (Sec. 3.2.4)", 0, 0, NULL },
    { "rr_depth", RL_OPT_INT, "4", "bounce from which Russian roulette may end a path", 0, 1024, NULL },
    { "rng", RL_OPT_ENUM, "sobol",
      "sample numbers: sobol (Owen-scrambled Sobol points) or the thesis' per-pixel state textures (Sec. 5.3): "
      "lcg, tausworthe or their hybrid", 0, 0, rl_pt_rng_choices },
    { "mis", RL_OPT_ENUM, "on",
      "on: lights chosen by power, light and BSDF samples weighted by the power heuristic; off: every light",
      0, 0, rl_pt_mis_choices },
    { "seed", RL_OPT_INT, "0", "seed of the per-pixel generator states", 0, 9007199254740991.0, NULL },
    { "shadow", RL_OPT_ENUM, "bvh",
      "shadow rays on the GPU: bvh, grid, a Line Space payload (ls-candidates, ls-preillum, ls-pnmt) or "
      "shadowmap (cube shadow maps drawn by GL, Sec. 8.6)", 0, 0, rl_pt_shadow_choices },
    { "diffuse", RL_OPT_ENUM, "bvh",
      "secondary rays on the GPU: bvh, grid or a Line Space payload (ls-candidates, ls-preillum, ls-pnmt)",
      0, 0, rl_pt_diffuse_choices },
    { "specular", RL_OPT_ENUM, "exact",
      "mirror and refraction rays: exact (the grid under a Line Space payload, else the diffuse structure) or "
      "diffuse (the diffuse structure, payloads included)", 0, 0, rl_pt_specular_choices },
    { "primary", RL_OPT_ENUM, "trace",
      "primary visibility: trace (jittered rays, GPU BVH) or raster (triangle IDs drawn by GL, Sec. 8.1)", 0, 0,
      rl_pt_primary_choices },
    { "checkerboard", RL_OPT_BOOL, "false", "render alternate halves of the pixels per frame (Sec. 8.5)",
      0, 0, NULL },
    { "accumulate", RL_OPT_BOOL, "true", "progressive accumulation across frames (Sec. 6.5, eq. 8)", 0, 0, NULL },
    { "filter", RL_OPT_ENUM, "none",
      "noise filter on the accumulated image (Sec. 8.2): pt's, on the CPU after the read-back", 0, 0,
      rl_pt_filter_choices },
    RL_PT_FILTER_PARAM_OPTIONS,
    /* pt's (pathtrace.c), the same meaning and defaults */
    RL_PT_ADAPTIVE_OPTIONS(" (errors and shares computed on the GPU)"),
    RL_PT_LINE_SPACE_OPTIONS,
    { "ls_build", RL_OPT_ENUM, "cpu",
      "where the Line Space is built: cpu (pt's build, uploaded) or gpu (compute shaders; ls-candidates only)",
      0, 0, ls_build_choices },
    { "light_samples", RL_OPT_INT, "1", "shadow rays per quad light and vertex", 1, 1024, NULL },
    { "shadowmap_size", RL_OPT_INT, "1024", "texels per shadow-map face side (Sec. 8.6)", 16, 16384, NULL },
    { "background", RL_OPT_COLOR, "0,0,0",
      "radiance arriving from every direction where a ray leaves the scene (a uniform environment); a scene "
      "\"environment\" replaces it", 0, 0, NULL },
    { "env_sampling", RL_OPT_ENUM, "importance",
      "light samples of a scene environment (issue 37): importance (by its radiance x sin(theta)), uniform "
      "(by solid angle) or bsdf (none: BSDF rays alone find it)", 0, 0, rl_pt_env_sampling_choices },
    { "ggx_ms", RL_OPT_BOOL, "true",
      "GGX energy compensation (Kulla & Conty 2017, pt's tables): the light single scattering loses returns as "
      "a diffuse-like lobe; false: single scattering alone", 0, 0, NULL },
    { "light_paths", RL_OPT_INT, "0",
      "hybrid light paths (Sec. 8.4): light subpaths the CPU traces per frame (bdpt's) for the shader to join "
      "to its camera vertices, weighted by MIS; 0: off", 0, 1048576, NULL },
    { "light_connect", RL_OPT_INT, "1", "light paths drawn per camera vertex, all their vertices joined", 1, 64,
      NULL },
    { "light_overlap", RL_OPT_BOOL, "true",
      "trace the next frame's light paths on a CPU thread while the GPU renders this one (false: before it)", 0, 0,
      NULL },
    { "threads", RL_OPT_INT, "0", "CPU threads of the structure builds and of light paths traced before a frame "
      "(0 = all)", 0, 1024, NULL },
    { "device", RL_OPT_STRING, "",
      "EGL device: auto, surfaceless or a device number; empty: $RL_EGL_DEVICE, else auto", 0, 0, NULL },
};
#define NUM_OPTIONS (sizeof gl_pt_options / sizeof gl_pt_options[0])

/* One frame's light vertices (rl_gl_pt_light_vertices), for frame index
 * `frame` of the accumulation. */
typedef struct lv_set {
    bool ready;
    uint64_t frame;
    uint32_t paths;
    uint32_t *offsets;             /* paths + 1 */
    float *data;                   /* RL_GL_PT_LV_FLOATS per vertex */
    size_t cap;                    /* vertices data holds */
    uint32_t *count;               /* per path, while tracing */
    double ms;                     /* CPU time of the trace */
    uint64_t rays;
    rl_status st;
} lv_set;

typedef struct gl_pt_state {
    pt_backends b;                /* the light set, offsets; a CPU BVH for depth and ID layers */
    rl_gl_pt *gpu;
    uint64_t gpu_scene;           /* the scene uid the GPU tracer holds */
    char ls_key[160];             /* what the tracer's Line Space was made from; "" none */
    bool env_set;                 /* the tracer holds b.env (for the scene it was made for) */
    bool env_uniform;             /* which distribution it holds */
    char device[64];
    char info[528];
    /* the accumulation and what it depends on */
    bool valid, force_reset;
    uint64_t scene_uid;
    rl_camera cam;
    char *signature;
    rl_gbuffer *gbuf;
    bool gbuf_traced;             /* gbuf holds the traced G-buffer of this accumulation */
    float *rgba;
    uint64_t frames;
    /* primary=raster: the GL drawer of the ID pass and its target */
    rl_drawer *drawer;
    char drawer_device[64];
    rl_image *ids;
    bool texture_out;             /* rl_renderer_set_gl_output */
    /* light_paths: this frame's and the next frame's light vertices */
    lv_set lv[2];
    double lv_trace_ms;           /* CPU time of the last frame's traces (tests, bench) */
} gl_pt_state;

static void lv_set_free(lv_set *l)
{
    free(l->offsets);
    free(l->data);
    free(l->count);
    memset(l, 0, sizeof *l);
}

static void gl_pt_release(void *state)
{
    gl_pt_state *s = state;
    lv_set_free(&s->lv[0]);
    lv_set_free(&s->lv[1]);
    rl_gl_pt_release(s->gpu);
    rl_pt_backends_release(&s->b);
    rl_gbuffer_release(s->gbuf);
    rl_drawer_release(s->drawer);
    rl_image_release(s->ids);
    free(s->rgba);
    free(s->signature);
}

static void gl_pt_reset_state(void *state)
{
    gl_pt_state *s = state;
    if (s)
        s->force_reset = true;
}

static bool gl_pt_available(const rl_renderer *r, char *why, size_t n)
{
    return rl_gl_available(rl_renderer_opt_string(r, "device"), why, n);
}

static rl_status gl_pt_check(const char *key, const char *value)
{
    if ((strcmp(key, "shadow") == 0 || strcmp(key, "diffuse") == 0) &&
        (strcmp(value, "embree") == 0 || strcmp(value, "ls-scene") == 0 || strcmp(value, "ls-object") == 0))
        return rl_error(RL_ERR_INVALID_ARG,
                        "gl-pt: %s=%s is not ported to GL yet (bvh, grid, ls-candidates, ls-preillum or ls-pnmt%s; "
                        "pt has it)", key, value, strcmp(key, "shadow") == 0 ? ", shadowmap" : "");
    if (strcmp(key, "ls_k") == 0 && atoi(value) % 2 != 0)
        return rl_error(RL_ERR_INVALID_ARG, "gl-pt: ls_k=%s must be even (front and back halves, Alg. 3)", value);
    return RL_OK;
}

/* The tracer for this scene and device, made anew when either changed. */
static rl_status ensure_gpu(gl_pt_state *s, const rl_scene *scene, const char *device, int threads,
                            rl_render_stats *stats)
{
    if (s->gpu && s->gpu_scene == rl_scene_uid(scene) && strcmp(s->device, device) == 0)
        return RL_OK;
    rl_gl_pt_release(s->gpu);
    s->gpu = NULL;
    s->valid = false;
    s->ls_key[0] = '\0';
    s->env_set = false;
    if (strlen(device) >= sizeof s->device)
        return rl_error(RL_ERR_INVALID_ARG, "gl-pt: device \"%.40s...\" is too long", device);
    const pt_lights *l = &s->b.lights;
    /* pt's energy-compensation tables, built (once per process) only for
     * a scene with a GGX material */
    _Static_assert(RL_GL_PT_GGX_NODES == RL_PT_GGX_MS_NODES, "gl-pt reads pt's GGX tables as they are");
    float ggx_tables[RL_PT_GGX_MS_NODES * RL_PT_GGX_MS_NODES + RL_PT_GGX_MS_NODES];
    const rl_scene_data *d = rl_scene_get_data(scene);
    bool ggx = false;
    for (uint32_t i = 0; d && i < d->num_materials; ++i)
        ggx = ggx || d->materials[i].bsdf == RL_BSDF_GGX;
    if (ggx)
        rl_pt_ggx_ms_tables(ggx_tables, ggx_tables + RL_PT_GGX_MS_NODES * RL_PT_GGX_MS_NODES);
    rl_gl_pt_desc desc = {
        .device = device, .threads = threads, .eps = s->b.eps,
        .lights = { .count = l->count, .source = l->source, .cdf = l->cdf, .light_pmf = l->light_pmf,
                    .light_hittable = l->light_hittable, .tri_pmf = l->tri_pmf, .tri_cover = s->b.tri_cover },
        .ggx_ms = ggx ? ggx_tables : NULL,
    };
    rl_timer timer;
    rl_timer_start(&timer);
    rl_status st = rl_gl_pt_create(scene, &desc, &s->gpu);
    stats->prep_ms += rl_timer_ms(&timer);
    if (st != RL_OK)
        return st;
    s->gpu_scene = rl_scene_uid(scene);
    snprintf(s->device, sizeof s->device, "%s", device);
    const rl_gl_info *info = rl_gl_pt_info(s->gpu);
    if (info)
        snprintf(s->info, sizeof s->info, "%s | %s | %s", info->vendor, info->renderer, info->version);
    return RL_OK;
}

/* gl-pt's structure for pt's backend (the shadow and diffuse choices). */
static rl_gl_pt_structure structure_of(rl_pt_backend k)
{
    switch (k) {
    case RL_PT_BACKEND_GRID: return RL_GL_PT_GRID;
    case RL_PT_BACKEND_LS_CANDIDATES: return RL_GL_PT_LS_CANDIDATES;
    case RL_PT_BACKEND_LS_PNMT: return RL_GL_PT_LS_PNMT;
    case RL_PT_BACKEND_LS_PREILLUM: return RL_GL_PT_LS_PREILLUM;
    case RL_PT_BACKEND_SHADOWMAP: return RL_GL_PT_SHADOWMAP;
    default: return RL_GL_PT_BVH;
    }
}

static bool is_ls(rl_pt_backend k)
{
    return k == RL_PT_BACKEND_LS_CANDIDATES || k == RL_PT_BACKEND_LS_PNMT || k == RL_PT_BACKEND_LS_PREILLUM;
}

/* The Line Space of the ls-* backends in the tracer: pt's own (built by
 * rl_pt_backends_prepare, so structure and offsets are pt's) uploaded, or
 * with ls_build=gpu the candidate lists built on the GPU from pt's grid.
 * Done again only when what it is made from changes. */
static rl_status ensure_linespace(gl_pt_state *s, const rl_renderer *r, const rl_scene *scene, rl_pt_backend shadow,
                                  rl_pt_backend diffuse, int threads, rl_render_stats *stats)
{
    const bool gpu = rl_renderer_opt_enum(r, "ls_build") == 1;
    if (gpu && (!(shadow == RL_PT_BACKEND_LS_CANDIDATES || !is_ls(shadow)) ||
                !(diffuse == RL_PT_BACKEND_LS_CANDIDATES || !is_ls(diffuse))))
        return rl_error(RL_ERR_INVALID_ARG, "gl-pt: ls_build=gpu builds the candidate lists only: ls-pnmt and "
                        "ls-preillum need ls_build=cpu");
    /* pt's settings for its Line Space alone: the other side takes the Line
     * Space side's backend so that no unneeded exact structure is built */
    pt_settings set;
    memset(&set, 0, sizeof set);
    set.shadow = is_ls(shadow) ? shadow : diffuse;
    set.diffuse = is_ls(diffuse) ? diffuse : shadow;
    if (gpu)
        set.shadow = set.diffuse = RL_PT_BACKEND_GRID;   /* the grid the GPU build reads */
    set.primary = PT_PRIMARY_RASTER;                     /* no CPU BVH for primary rays */
    set.grid_res = (int)rl_renderer_opt_int(r, "grid_res");
    set.ls_n = (int)rl_renderer_opt_int(r, "ls_n");
    set.ls_k = (int)rl_renderer_opt_int(r, "ls_k");
    set.ls_dynamic = rl_renderer_opt_bool(r, "ls_dynamic");
    set.ls_origin_exact = rl_renderer_opt_enum(r, "ls_origin") == 1;
    set.ls_file = "";
    double built = 0.0;
    rl_timer timer;
    rl_timer_start(&timer);
    rl_status st = rl_pt_backends_prepare(&s->b, scene, &set, threads, &built);
    if (st != RL_OK)
        return st;
    char key[sizeof s->ls_key];
    snprintf(key, sizeof key, "%s n=%d k=%d dyn=%d payloads=%d/%d origin=%d grid=%d scene=%llu ls=%p",
             gpu ? "gpu" : "cpu", set.ls_n, set.ls_dynamic ? 0 : set.ls_k, set.ls_dynamic, (int)set.shadow,
             (int)set.diffuse, set.ls_origin_exact, set.grid_res, (unsigned long long)rl_scene_uid(scene),
             gpu ? (void *)s->b.exact[RL_ACCEL_GRID] : (void *)s->b.ls);
    if (strcmp(key, s->ls_key) != 0) {
        s->ls_key[0] = '\0';
        rl_linespace_desc desc = { .n = set.ls_n, .k = set.ls_k, .dynamic = set.ls_dynamic,
                                   .payloads = RL_LS_CANDIDATES };
        st = gpu ? rl_gl_pt_set_linespace(s->gpu, NULL, s->b.exact[RL_ACCEL_GRID], &desc)
                 : rl_gl_pt_set_linespace(s->gpu, s->b.ls, NULL, NULL);
        if (st != RL_OK)
            return st;
        snprintf(s->ls_key, sizeof s->ls_key, "%s", key);
    }
    stats->prep_ms += rl_timer_ms(&timer);
    return RL_OK;
}

/* pt's per-pixel states (pathtrace.c reset, pixel_sampler). */
static uint32_t *seed_states(int rng, uint64_t seed, size_t n)
{
    uint32_t *st = rl_calloc(n ? n : 1, 4 * sizeof *st);
    if (!st)
        return NULL;
    for (size_t i = 0; i < n; ++i) {
        if (rng == 0) {
            st[4 * i] = rl_pt_pixel_seed(seed, i);
            continue;
        }
        rl_rng_gpu g;
        rl_rng_gpu_seed(&g, (rl_rng_gpu_kind)(rng - 1), seed, i);
        memcpy(&st[4 * i], g.z, sizeof g.z);
    }
    return st;
}

/* The scene's environment in the tracer: pt's distribution for
 * env_sampling (importance or uniform; bsdf samples none but keeps the
 * importance one for nothing, as pt) and the radiance of every map texel,
 * rl_environment_radiance's product colour x texel, computed here in C so
 * that the shader's lookup returns pt's values exactly. Uploaded again only
 * when the tracer or the distribution changes. */
static rl_status ensure_environment(gl_pt_state *s, const rl_scene_data *d, bool uniform)
{
    const rl_environment *env = d->environment;
    if (!env)
        return RL_OK;
    rl_status st;
    if (s->b.env.uniform != uniform && (st = rl_pt_env_build(&s->b.env, env, uniform)) != RL_OK)
        return st;
    if (s->env_set && s->env_uniform == uniform)
        return RL_OK;
    const rl_texture *m = env->map;
    const int mw = m ? m->width : 1, mh = m ? m->height : 1;
    float *rad = rl_calloc((size_t)mw * (size_t)mh, 3 * sizeof *rad);
    if (!rad)
        return RL_ERR_OUT_OF_MEMORY;
    for (size_t i = 0; i < (size_t)mw * (size_t)mh; ++i) {
        rl_vec3 c = m ? rl_mul(env->radiance, rl_v3(m->texels[i].x, m->texels[i].y, m->texels[i].z)) : env->radiance;
        rad[3 * i] = c.x;
        rad[3 * i + 1] = c.y;
        rad[3 * i + 2] = c.z;
    }
    const pt_env *e = &s->b.env;
    const rl_gl_pt_env ge = { .radiance = rad, .map_width = mw, .map_height = mh,
                              .rotation = rl_radians(env->rotation_deg), .width = e->width, .height = e->height,
                              .weight = e->weight, .conditional = e->conditional, .marginal = e->marginal,
                              .sum = e->sampled ? e->sum : 0.0 };   /* an overflowing map: not sampled, as pt */
    st = rl_gl_pt_set_environment(s->gpu, &ge);
    free(rad);
    if (st != RL_OK)
        return st;
    s->env_set = true;
    s->env_uniform = uniform;
    return RL_OK;
}

/* primary=raster (Sec. 8.1): the triangle IDs of the scene drawn by a GL
 * drawer, unlit, into s->ids, as rl_gbuffer_raster draws them with the
 * software rasterizer; every frame, as the thesis' extra render pass. The
 * drawer is kept while scene and device stay. */
static rl_status raster_pass(gl_pt_state *s, const rl_scene *scene, const rl_camera *cam, const char *device,
                             rl_render_stats *stats)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    const rl_drawer_desc desc = { .flags = RL_RASTER_NO_COLOR };
    rl_status st = RL_OK;
    if (!rl_drawer_fits(s->drawer, scene, &desc) || strcmp(s->drawer_device, device) != 0) {
        rl_drawer_release(s->drawer);
        s->drawer = NULL;
        s->drawer_device[0] = '\0';
        if (strlen(device) >= sizeof s->drawer_device)
            return rl_error(RL_ERR_INVALID_ARG, "gl-pt: device \"%.40s...\" is too long", device);
        rl_timer timer;
        rl_timer_start(&timer);
        st = rl_gl_drawer_create(scene, &desc, device, &s->drawer);
        stats->prep_ms += rl_timer_ms(&timer);
        if (st != RL_OK)
            return st;
        snprintf(s->drawer_device, sizeof s->drawer_device, "%s", device);
    }
    if (!s->ids || s->ids->width != cam->width || s->ids->height != cam->height) {
        rl_image_release(s->ids);
        s->ids = NULL;
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &s->ids);
        if (st != RL_OK)
            return st;
    }
    rl_image_clear(s->ids);
    st = rl_drawer_begin_camera(s->drawer, s->ids, cam, d->bounds);
    if (st == RL_OK)
        st = rl_drawer_draw_all(s->drawer, NULL, NULL, NULL);
    if (st == RL_OK)
        st = rl_drawer_end(s->drawer);
    return st;
}

/* The accumulated means into the image; pixels of a class not traced yet
 * (checkerboard's first frame) the mean of their traced 4-neighbours, as
 * pt's resolve() (Sec. 8.5, Fig. 17). */
static void resolve(const float *rgba, const uint64_t held[2], int w, int h, rl_image *image)
{
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            size_t i = (size_t)y * (size_t)w + (size_t)x;
            if (held[(x + y) & 1] > 0) {
                image->color[i] = rl_v4(rgba[4 * i], rgba[4 * i + 1], rgba[4 * i + 2], 1.0f);
                continue;
            }
            static const int dx[4] = { -1, 1, 0, 0 }, dy[4] = { 0, 0, -1, 1 };
            double c[3] = { 0.0, 0.0, 0.0 };
            int n = 0;
            for (int j = 0; j < 4; ++j) {
                int nx = x + dx[j], ny = y + dy[j];
                if (nx < 0 || ny < 0 || nx >= w || ny >= h || held[(nx + ny) & 1] == 0)
                    continue;
                size_t q = (size_t)ny * (size_t)w + (size_t)nx;
                for (int k = 0; k < 3; ++k)
                    c[k] += rgba[4 * q + k];
                ++n;
            }
            for (int k = 0; k < 3 && n > 0; ++k)
                c[k] /= n;
            image->color[i] = rl_v4((float)c[0], (float)c[1], (float)c[2], 1.0f);
        }
    }
}

/* A CPU BVH (for the G-buffer and the light paths), kept with the
 * scene's data. */
static rl_status ensure_cpu_bvh(gl_pt_state *s, const rl_scene *scene, int threads, rl_render_stats *stats)
{
    if (s->b.exact[RL_ACCEL_BVH])
        return RL_OK;
    rl_timer timer;
    rl_timer_start(&timer);
    rl_status st = rl_accel_create(scene, &(rl_accel_desc){ .kind = RL_ACCEL_BVH, .threads = threads },
                                   &s->b.exact[RL_ACCEL_BVH]);
    if (st == RL_OK)
        st = rl_accel_commit(s->b.exact[RL_ACCEL_BVH]);
    if (st != RL_OK) {
        rl_accel_release(s->b.exact[RL_ACCEL_BVH]);
        s->b.exact[RL_ACCEL_BVH] = NULL;
        return st;
    }
    stats->prep_ms += rl_timer_ms(&timer);
    return RL_OK;
}

/* ------------------------------------------------------------------------
 * Hybrid light paths (Schröder 2017 Sec. 8.4): per frame a CPU thread
 * traces light_paths light subpaths with bdpt's tracer (bd_light_subpath)
 * and stores their surface vertices with the MIS quantities the shader's
 * joins need (gl_pt_shaders.c, "light vertices", has the derivation);
 * frame k's paths depend only on (seed, k), path j's generator on j, so
 * the set is the same whatever the threads. */

/* The counts relative to light_connect (M) of the strategies s' = 0
 * (emitter hit; 1 sample, hittable lights only), s' = 1 (light_samples
 * light samples) and s' >= 2 (joins, M): nu. */
typedef struct lv_params {
    const bd_ctx *ctx;
    uint64_t seed;
    int max_depth;
    float nu0, nu1;                /* 1 / M (before the hittable test), light_samples / M */
} lv_params;

static double sq(double x) { return x * x; }

/* The strategy count of s' = j (j >= 1) on path y: 0 where a delta vertex
 * ends the joining edge y_{j-1} y_j. y_j as the stored vertex (end) is
 * joined by its BRDF part whatever event its walk chose next, so its own
 * flag does not count there. */
static double lv_nu(const lv_params *p, const bd_vertex *y, int j, bool end)
{
    if ((!end && y[j].delta) || (j >= 2 && y[j - 1].delta))
        return 0.0;
    return j == 1 ? p->nu1 : 1.0;
}

/* The record of vertex y_i (i >= 1) into out
 * (RL_GL_PT_LV_FLOATS floats; layout in gl_pt.h). */
static void lv_record(const lv_params *p, const bd_vertex *y, int i, float *out)
{
    const rl_scene_data *d = p->ctx->data;
    const bd_vertex *v = &y[i];
    const double nu0 = y[0].light.hittable ? p->nu0 : 0.0;
    /* R_j = (pE_j / pL_j)^2 (nu_j^2 + R_{j-1}) up to j = i - 2, the part
     * with s' = 0 (rb) apart */
    double ra = 0.0, rb = 0.0;
    for (int j = 0; j <= i - 2; ++j) {
        double pl = y[j].pdf_fwd > 0.0f ? y[j].pdf_fwd : 1.0, q = sq(y[j].pdf_rev / pl);
        if (j == 0) {
            rb = q * nu0 * nu0;
        } else {
            ra = q * (sq(lv_nu(p, y, j, false)) + ra);
            rb = q * rb;
        }
    }
    const double pli = v->pdf_fwd > 0.0f ? v->pdf_fwd : 1.0;
    const double plp = y[i - 1].pdf_fwd > 0.0f ? y[i - 1].pdf_fwd : 1.0;
    rl_vec3 e = rl_sub(v->p, y[i - 1].p);
    double d2 = rl_length2(e);
    double cosp = rl_length2(y[i - 1].ng) > 0.0f ? fabs(rl_dot(y[i - 1].ng, e)) / sqrt(d2) : 1.0;
    double g2 = sq(cosp / d2) / sq(pli * plp);
    double l1 = sq(lv_nu(p, y, i, true)) / sq(pli);
    double l2a = i == 1 ? 0.0 : g2 * (sq(lv_nu(p, y, i - 1, false)) + ra);
    double l2b = i == 1 ? g2 * nu0 * nu0 : g2 * rb;
    const pt_surface *s = &v->s;
    float k = rl_maxf(0.0f, 1.0f - s->m->reflectivity - s->m->transmissivity);
    float vng = fabsf(rl_dot(s->v, s->ng));
    /* the adjoint BRDF's shading-normal factor |v.ns| / |v.ng| (Veach 1997
     * Sec. 5.3; bdpt's connect_inner) and the event's share in the
     * throughput: the shader then needs only f |wo.ng| */
    float scale = vng > 0.0f ? k * fabsf(rl_dot(s->v, s->ns)) / vng : 0.0f;
    rl_vec3 beta = rl_scale(v->beta, scale);
    uint32_t mat = (uint32_t)(s->m - d->materials);
    float mat_bits;
    memcpy(&mat_bits, &mat, sizeof mat_bits);
    const float rec[RL_GL_PT_LV_FLOATS] = {
        s->p.x, s->p.y, s->p.z, mat_bits,
        s->ng.x, s->ng.y, s->ng.z, (float)l1,
        s->ns.x, s->ns.y, s->ns.z, (float)l2a,
        s->v.x, s->v.y, s->v.z, (float)l2b,
        beta.x, beta.y, beta.z, (float)i,
        s->kd.x, s->kd.y, s->kd.z, 0.0f,
    };
    memcpy(out, rec, sizeof rec);
}

/* Frame `frame`'s n light paths into l, with `threads` threads. */
static rl_status lv_trace(const lv_params *p, uint64_t frame, uint32_t n, int threads, lv_set *l)
{
    rl_timer timer;
    rl_timer_start(&timer);
    const int per = p->max_depth > 0 ? p->max_depth : 1;   /* stored vertices of a path: y_1 .. y_max_depth */
    const size_t cap = (size_t)n * (size_t)per;
    l->ready = false;
    if (l->paths != n || l->cap < cap) {
        free(l->offsets);
        free(l->data);
        free(l->count);
        l->offsets = rl_calloc((size_t)n + 1, sizeof *l->offsets);
        l->count = rl_calloc(n, sizeof *l->count);
        l->data = rl_calloc(cap, RL_GL_PT_LV_FLOATS * sizeof *l->data);
        l->cap = cap;
        l->paths = n;
        if (!l->offsets || !l->count || !l->data) {
            lv_set_free(l);
            return l->st = RL_ERR_OUT_OF_MEMORY;
        }
    }
    const uint64_t key = rl_hash64(p->seed * 0x9e3779b97f4a7c15ull + 0x6c76ull + frame);
    uint64_t rays = 0;
    int failed = 0;
#pragma omp parallel num_threads(threads) reduction(+ : rays) reduction(| : failed)
    {
        bd_scratch sc;
        if (bd_scratch_init(&sc, p->max_depth) != RL_OK) {
            failed = 1;
        } else {
#pragma omp for schedule(dynamic, 64)
            for (int64_t j = 0; j < (int64_t)n; ++j) {
                rl_rng rng;
                rl_rng_seed(&rng, key, (uint64_t)j);
                int nv = bd_light_subpath(p->ctx, &rng, sc.light, p->max_depth + 1, &rays);
                uint32_t c = 0;
                for (int i = 1; i < nv; ++i) {
                    const bd_vertex *v = &sc.light[i];
                    if (v->kind != BD_V_SURFACE || !rl_vfinite(v->beta) ||
                        !(rl_vmax_comp(v->beta) > 0.0f))
                        continue;
                    lv_record(p, sc.light, i, l->data + ((size_t)j * (size_t)per + c) * RL_GL_PT_LV_FLOATS);
                    ++c;
                }
                l->count[j] = c;
            }
            bd_scratch_release(&sc);
        }
    }
    if (failed)
        return l->st = RL_ERR_OUT_OF_MEMORY;
    /* packed in path order */
    uint32_t at = 0;
    for (uint32_t j = 0; j < n; ++j) {
        l->offsets[j] = at;
        if (l->count[j] && at != j * (uint32_t)per)
            memmove(l->data + (size_t)at * RL_GL_PT_LV_FLOATS, l->data + (size_t)j * per * RL_GL_PT_LV_FLOATS,
                    (size_t)l->count[j] * RL_GL_PT_LV_FLOATS * sizeof *l->data);
        at += l->count[j];
    }
    l->offsets[n] = at;
    l->frame = frame;
    l->rays = rays;
    l->ms = rl_timer_ms(&timer);
    l->ready = true;
    return l->st = RL_OK;
}

/* What light_paths cannot do is refused by name. */
static rl_status lv_check(const rl_renderer *r, const rl_scene_data *d)
{
    if (rl_renderer_opt_enum(r, "mis") != 1)
        return rl_error(RL_ERR_INVALID_ARG, "gl-pt: light_paths needs mis=on (its weights extend pt's MIS)");
    static const char *const keys[2] = { "shadow", "diffuse" };
    for (int k = 0; k < 2; ++k) {
        rl_pt_backend b = (rl_pt_backend)rl_renderer_opt_enum(r, keys[k]);
        if (b != RL_PT_BACKEND_BVH && b != RL_PT_BACKEND_GRID && b != RL_PT_BACKEND_LS_CANDIDATES)
            return rl_error(RL_ERR_INVALID_ARG, "gl-pt: light_paths needs exact rays (%s=bvh, grid or "
                            "ls-candidates), not %s=%s", keys[k], keys[k], rl_renderer_opt_string(r, keys[k]));
    }
    if (d->environment)
        return rl_error(RL_ERR_UNSUPPORTED, "gl-pt: light_paths does not start light paths at a scene "
                        "environment (bdpt does; use light_paths=0 or bdpt)");
    /* GGX needs nothing of its own (Sec. 13.4): a light vertex's record
     * holds what its lobe is set up from (position, normals, the direction
     * it was reached from, kd, the material), so the shader's joins
     * evaluate GGX's BRDF and densities at both ends (lv_pdf_at), and
     * bd_light_subpath's densities in the record are already GGX's. */
    /* adaptive=on needs nothing of its own: each of a pixel's samples is a
     * camera path that joins paths drawn uniformly from the frame's set,
     * and the MIS weights count the strategies of one camera path (its
     * BRDF hit, light_samples light samples, light_connect joins), never
     * the pixel's samples, since no strategy splats to the image (light
     * tracing to the pinhole, bdpt's t = 1, is not done). So the samples
     * adaptive sampling gives a pixel each estimate its value unbiased,
     * however many it gets; all rounds of a frame join that frame's set. */
    for (uint32_t i = 0; i < d->num_lights; ++i)
        if (d->lights[i].type != RL_LIGHT_QUAD)
            return rl_error(RL_ERR_UNSUPPORTED, "gl-pt: light_paths does not support point, spot or directional "
                            "lights (light %u: delta light vertices; bdpt does)", i);
    return RL_OK;
}

/* The G-buffer pt would have for this frame: with primary=raster made from
 * the GL pass's IDs (every frame, as pt rasterizes its own every frame),
 * else traced at the pixel centres through a CPU BVH once per
 * accumulation. */
static rl_status frame_gbuffer(gl_pt_state *s, const rl_scene *scene, const rl_camera *cam, bool raster, int threads,
                               rl_render_stats *stats)
{
    rl_status st = RL_OK;
    if (!s->gbuf)
        st = rl_gbuffer_create(cam->width, cam->height, &s->gbuf);
    if (st != RL_OK)
        return st;
    if (raster) {
        s->gbuf_traced = false;
        return rl_gbuffer_from_ids(s->gbuf, scene, cam, s->ids->triangle_id);
    }
    if (s->gbuf_traced)
        return RL_OK;
    st = ensure_cpu_bvh(s, scene, threads, stats);
    if (st != RL_OK)
        return st;
    st = rl_gbuffer_trace(s->gbuf, s->b.exact[RL_ACCEL_BVH], cam);
    s->gbuf_traced = st == RL_OK;
    return st;
}

/* pt's filter settings (pathtrace.c read_settings) from the same options. */
static void filter_settings(const rl_renderer *r, pt_settings *set)
{
    memset(set, 0, sizeof *set);
    rl_pt_read_filter_settings(r, set);
}

static rl_status gl_pt_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                              rl_image *image, rl_render_stats *stats)
{
    gl_pt_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    const int threads = (int)rl_renderer_opt_int(r, "threads");
    /* What pt prepares for the GPU's estimator: offsets, covers, light
     * table (the GPU builds its own structures). */
    rl_timer prep;
    rl_timer_start(&prep);
    rl_status st = rl_pt_backends_prepare_scene(&s->b, scene);
    stats->prep_ms = rl_timer_ms(&prep);
    if (st == RL_OK)
        st = ensure_gpu(s, scene, rl_renderer_opt_string(r, "device"), threads, stats);
    const int env_sampling = (int)rl_renderer_opt_enum(r, "env_sampling");
    if (st == RL_OK)
        st = ensure_environment(s, d, env_sampling == PT_ENV_UNIFORM);
    if (st != RL_OK)
        return st;

    /* Any option change restarts the accumulation (threads and device only
     * change how it runs, not the image, but a device change makes a new
     * tracer anyway). */
    char *sig = rl_renderer_option_signature(r, NULL);
    if (!sig)
        return RL_ERR_OUT_OF_MEMORY;
    const bool accumulate = rl_renderer_opt_bool(r, "accumulate");
    bool reset = s->force_reset || !s->valid || !accumulate || s->scene_uid != rl_scene_uid(scene) ||
                 !rl_camera_equal(&s->cam, cam) || strcmp(s->signature, sig) != 0;
    const size_t n = (size_t)cam->width * (size_t)cam->height;
    const int rng = rl_renderer_opt_enum(r, "rng");
    uint32_t *states = NULL;
    if (reset) {
        free(s->rgba);
        rl_gbuffer_release(s->gbuf);
        s->gbuf = NULL;
        s->gbuf_traced = false;
        s->valid = false;
        s->rgba = rl_calloc(n, 4 * sizeof *s->rgba);
        states = seed_states(rng, (uint64_t)rl_renderer_opt_int(r, "seed"), n);
        if (!s->rgba || !states) {
            free(states);
            free(sig);
            return RL_ERR_OUT_OF_MEMORY;
        }
        free(s->signature);
        s->signature = sig;
        s->scene_uid = rl_scene_uid(scene);
        s->cam = *cam;
        s->frames = 0;
    } else {
        free(sig);
    }

    const rl_pt_backend shadow = (rl_pt_backend)rl_renderer_opt_enum(r, "shadow");
    const rl_pt_backend diffuse = (rl_pt_backend)rl_renderer_opt_enum(r, "diffuse");
    /* pathtrace.c: specular rays leave the approximate payloads for the
     * exact grid the Line Space lives in */
    const bool payload = diffuse == RL_PT_BACKEND_LS_PNMT || diffuse == RL_PT_BACKEND_LS_PREILLUM;
    const rl_pt_backend specular =
        rl_renderer_opt_enum(r, "specular") == 0 && payload ? RL_PT_BACKEND_GRID : diffuse;
    if (is_ls(shadow) || is_ls(diffuse)) {
        st = ensure_linespace(s, r, scene, shadow, diffuse, threads, stats);
        if (st != RL_OK) {
            free(states);
            s->force_reset = true;
            return st;
        }
    }
    if (shadow == RL_PT_BACKEND_SHADOWMAP) {
        rl_timer timer;
        rl_timer_start(&timer);
        const rl_shadowmap_desc sm = { .size = (int)rl_renderer_opt_int(r, "shadowmap_size") };
        st = rl_gl_pt_set_shadowmaps(s->gpu, &sm);
        stats->prep_ms += rl_timer_ms(&timer);
        if (st != RL_OK) {
            free(states);
            s->force_reset = true;
            return st;
        }
    }
    /* pt's exact_backend: BSDF rays find emitters exactly */
    const bool exact = !payload;
    const int max_depth = (int)rl_renderer_opt_int(r, "max_depth");
    const bool mis = rl_renderer_opt_enum(r, "mis") == 1;
    rl_gl_pt_frame f = {
        .cam = rl_camera_frame_make(cam),
        .spp = (int)rl_renderer_opt_int(r, "spp"),
        .max_depth = max_depth >= 0 ? max_depth : rl_pt_scene_max_depth(scene),
        .rr_depth = (int)rl_renderer_opt_int(r, "rr_depth"),
        .light_samples = (int)rl_renderer_opt_int(r, "light_samples"),
        .rr = rl_renderer_opt_bool(r, "rr"),
        /* pathtrace.c: shadow maps are rendered per light; no triangle lights */
        .mis = mis, .mis_hits = mis && exact, .tri_lights = mis && exact && shadow != RL_PT_BACKEND_SHADOWMAP,
        .rng = rng,
        .shadow = structure_of(shadow),
        .diffuse = structure_of(diffuse),
        .specular = structure_of(specular),
        .ls_start = s->b.ls_start,
        .ls_offset = s->b.ls_offset,
        .grid_res = (int)rl_renderer_opt_int(r, "grid_res"),
        .background = rl_renderer_opt_color(r, "background"),
        /* pathtrace.c: env_nee */
        .env_nee = d->environment && s->b.env.sampled && env_sampling != PT_ENV_BSDF &&
                   shadow != RL_PT_BACKEND_SHADOWMAP,
        .reset_states = states,
        .ggx_ms = rl_renderer_opt_bool(r, "ggx_ms"),
        .adaptive = rl_renderer_opt_enum(r, "adaptive") == 1,
        .adaptive_threshold = (float)rl_renderer_opt_float(r, "adaptive_threshold"),
        .adaptive_min_spp = (int)rl_renderer_opt_int(r, "adaptive_min_spp"),
    };
    const bool raster = rl_renderer_opt_enum(r, "primary") == 1;
    const char *device = rl_renderer_opt_string(r, "device");
    if (raster) {
        st = raster_pass(s, scene, cam, device, stats);
        if (st != RL_OK) {
            free(states);
            s->force_reset = true;
            return st;
        }
        f.raster_ids = s->ids->triangle_id;
    }
    f.checkerboard = rl_renderer_opt_bool(r, "checkerboard");
    if (f.adaptive && f.checkerboard) {
        free(states);
        s->force_reset = true;
        return rl_error(RL_ERR_UNSUPPORTED, "gl-pt: adaptive=on with checkerboard is not ported to GL (pt has it)");
    }
    pt_settings fs;
    filter_settings(r, &fs);
    /* Texture output (rl_renderer_set_gl_output) where the GPU's mean is
     * the image: not with a filter (CPU, on the read-back image) nor on a
     * checkerboard accumulation's first frame, whose untraced half
     * resolve() fills in from the neighbours. */
    const bool texture = s->texture_out && fs.filter == RL_FILTER_NONE && !(f.checkerboard && reset);
    rl_gl_pt_set_texture_output(s->gpu, texture);

    /* light_paths (Sec. 8.4): this frame's light vertices (traced during
     * the previous frame, else now), and the next frame's traced on a CPU
     * thread while the GPU renders this one */
    const uint32_t light_paths = (uint32_t)rl_renderer_opt_int(r, "light_paths");
    const int cpu_threads = threads > 0 ? threads : omp_get_max_threads();
    bd_ctx lctx;
    lv_params lp;
    lv_set *next = NULL;
    s->lv_trace_ms = 0.0;
    if (reset)
        s->lv[0].ready = s->lv[1].ready = false;
    if (light_paths > 0) {
        st = lv_check(r, d);
        if (st == RL_OK)
            st = ensure_cpu_bvh(s, scene, threads, stats);
        const int connect = (int)rl_renderer_opt_int(r, "light_connect");
        memset(&lctx, 0, sizeof lctx);
        lctx.data = d;
        lctx.b = &s->b;
        lctx.max_depth = f.max_depth;
        lctx.rr_depth = f.rr_depth;
        lctx.rr = f.rr;
        lctx.mis = BD_MIS_POWER;
        lctx.only_s = lctx.only_t = -1;
        lctx.ggx_ms = f.ggx_ms;    /* the light paths scatter at GGX as the shader evaluates it */
        lctx.light_share = 1.0f;   /* no environment (lv_check) */
        lp = (lv_params){ .ctx = &lctx, .seed = (uint64_t)rl_renderer_opt_int(r, "seed"), .max_depth = f.max_depth,
                          .nu0 = 1.0f / (float)connect, .nu1 = (float)f.light_samples / (float)connect };
        const uint64_t k = s->frames;
        int cur = s->lv[0].ready && s->lv[0].frame == k ? 0 : s->lv[1].ready && s->lv[1].frame == k ? 1 : -1;
        if (st == RL_OK && cur < 0) {
            cur = 0;
            st = lv_trace(&lp, k, light_paths, cpu_threads, &s->lv[0]);
            s->lv_trace_ms += s->lv[0].ms;
        }
        if (st == RL_OK) {
            const rl_gl_pt_light_vertices lv = { .paths = light_paths, .offsets = s->lv[cur].offsets,
                                                 .data = s->lv[cur].data };
            st = rl_gl_pt_set_light_vertices(s->gpu, &lv);
        }
        if (st != RL_OK) {
            free(states);
            s->force_reset = true;
            return st;
        }
        f.light_connect = connect;
        f.light_nu1 = lp.nu1;
        if (accumulate)
            next = &s->lv[1 - cur];
    }
    rl_gl_pt_result res;
    rl_status next_st = RL_OK;
    if (next && rl_renderer_opt_bool(r, "light_overlap")) {
        /* the GL context is current on the calling thread: thread 0 */
#pragma omp parallel num_threads(2)
        {
            if (omp_get_thread_num() == 0)
                st = rl_gl_pt_render(s->gpu, &f, texture ? NULL : s->rgba, &res);
            if (omp_get_thread_num() == 1 || omp_get_num_threads() == 1)
                next_st = lv_trace(&lp, s->frames + 1, light_paths, 1, next);
        }
    } else {
        st = rl_gl_pt_render(s->gpu, &f, texture ? NULL : s->rgba, &res);
        if (next && st == RL_OK)
            next_st = lv_trace(&lp, s->frames + 1, light_paths, cpu_threads, next);
    }
    if (next)
        s->lv_trace_ms += next->ms;
    if (st == RL_OK)
        st = next_st;
    free(states);
    if (st != RL_OK) {
        s->force_reset = true;
        return st;
    }
    s->valid = true;
    s->force_reset = false;
    s->frames++;
    if (!texture)
        resolve(s->rgba, res.held, cam->width, cam->height, image);

    /* pathtrace.c active(): x + y + frame even holds for the larger half
     * when both sides are odd */
    const uint64_t even = (cam->width & cam->height & 1) ? (n + 1) / 2 : n / 2;
    const uint64_t traced = !f.checkerboard ? n : (res.frames - 1) % 2 == 0 ? even : n - even;
    bool layers = ((image->layers & RL_LAYER_DEPTH) && image->depth) ||
                  ((image->layers & RL_LAYER_ID) && image->object_id && image->triangle_id);
    if (layers || fs.filter != RL_FILTER_NONE) {
        st = frame_gbuffer(s, scene, cam, raster, threads, stats);
        if (st != RL_OK)
            return st;
    }
    if (fs.filter != RL_FILTER_NONE) {
        /* pt's mean samples per pixel over the image */
        double spp = ((double)res.held[0] * (double)even + (double)res.held[1] * (double)(n - even)) / (double)n;
        float weight;
        st = rl_pt_filter_image(&fs, s->gbuf, spp, image, &weight);
        if (st != RL_OK)
            return st;
    }
    if ((image->layers & RL_LAYER_DEPTH) && image->depth)
        memcpy(image->depth, s->gbuf->depth, n * sizeof *image->depth);
    if ((image->layers & RL_LAYER_ID) && image->object_id && image->triangle_id) {
        memcpy(image->object_id, s->gbuf->object, n * sizeof *image->object_id);
        memcpy(image->triangle_id, s->gbuf->triangle, n * sizeof *image->triangle_id);
    }
    stats->pixels_written = n;
    stats->samples = f.adaptive ? res.samples : traced * (uint64_t)f.spp;
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        stats->rays[k] = res.rays[k];
    stats->device = s->info[0] ? s->info : NULL;
    if (!rl_renderer_progress(r, 1.0)) {
        s->force_reset = true;
        return rl_error(RL_ERR_CANCELLED, "gl-pt: cancelled by the progress callback");
    }
    return RL_OK;
}

rl_status rl_gl_pt_renderer_sample_counts(const rl_renderer *r, uint32_t *counts)
{
    if (!r || strcmp(rl_renderer_name(r), "gl-pt") != 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_renderer_sample_counts: needs a \"gl-pt\" renderer");
    gl_pt_state *s = rl_renderer_state(r);
    if (!s || !s->gpu)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_renderer_sample_counts: no frame rendered");
    return rl_gl_pt_sample_counts(s->gpu, counts);
}

static void gl_pt_gl_output(void *state, bool on)
{
    gl_pt_state *s = state;
    s->texture_out = on;
}

static bool gl_pt_take_gl_frame(void *state, rl_gl_frame *out)
{
    gl_pt_state *s = state;
    return s->gpu && rl_gl_pt_take_frame(s->gpu, out);
}

const rl_renderer_class rl_gl_pt_renderer_class = {
    .info = { .name = "gl-pt",
              .description = "pt on OpenGL 4.5 compute shaders (headless EGL): the same estimator, BVH, grid "
                             "or Line Space on the GPU",
              .reference = "Schröder 2017, Ch. 5-6 (GPU path tracing, Sec. 5.3 RNG textures, Sec. 6.5)",
              .progressive = true, .default_time_s = 10.0,
              /* the read-back mean, the states, the G-buffer, and with
               * primary=raster the ID pass's target (colour, depth, IDs) */
              .frame_bytes_per_pixel = 4 * sizeof(float) + 16 + 16 + RL_GBUFFER_BYTES_PER_PIXEL + 16 + 4 + 8 +
                                       /* adaptive: counts and shares, two errors */
                                       8 + 8 },
    .options = gl_pt_options,
    .num_options = NUM_OPTIONS,
    .state_size = sizeof(gl_pt_state),
    .render = gl_pt_render,
    .release = gl_pt_release,
    .check = gl_pt_check,
    .reset = gl_pt_reset_state,
    .available = gl_pt_available,
    .gl_output = gl_pt_gl_output,
    .take_gl_frame = gl_pt_take_gl_frame,
};
