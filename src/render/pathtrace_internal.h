/* pathtrace_internal.h: what the parts of the path tracer "pt" share
 * (Schröder 2017, Ch. 6 and 8).
 *
 * pathtrace.c          the renderer: options, frame loop, accumulation
 *                      (Sec. 6.5), checkerboard (Sec. 8.5), filter (Sec. 8.2),
 *                      per-pixel adaptive sampling (issue 37)
 * pathtrace_path.c     one camera path (Sec. 3.3, 6.4): Trace, Shade (NEE),
 *                      emission rule, Russian roulette; the pre-illumination
 *                      shader for the Line Space (Sec. 7.4)
 * pathtrace_bsdf.c     importance sampling of the modified Phong BRDF
 *                      (Sec. 6.4.3; Lafortune & Willems 1994)
 * pathtrace_ggx.c      the GGX microfacet BRDF with visible-normal sampling
 *                      and Schlick's Fresnel on specular events (issue 37)
 * pathtrace_lights.c   the lights chosen by power for next-event estimation
 *                      with MIS (Veach 1997): scene lights and emissive
 *                      triangles, their pdfs
 * pathtrace_sampler.c  the sample numbers: the thesis' GPU generators
 *                      (Sec. 5.3) or Owen-scrambled Sobol points
 * pathtrace_backend.c  the acceleration structures the backends need (BVH,
 *                      grid, Embree, Line Space, shadow maps), built lazily
 *                      and kept between frames; query routing */
#ifndef RL_RENDER_PATHTRACE_INTERNAL_H
#define RL_RENDER_PATHTRACE_INTERNAL_H

#include "rl/rl_accel.h"
#include "rl/rl_filter.h"
#include "rl/rl_gbuffer.h"
#include "rl/rl_linespace.h"
#include "rl/rl_options.h"
#include "rl/rl_pt.h"
#include "rl/rl_render.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"
#include "rl/rl_shadowmap.h"

/* ------------------------------------------------------------ settings -- */

typedef enum pt_primary { PT_PRIMARY_TRACE = 0, PT_PRIMARY_RASTER } pt_primary;
/* What answers the filled intervals of ls-scene (option ls_scene_inner). */
typedef enum pt_ls_scene_inner { PT_LS_INNER_OBJECT = 0, PT_LS_INNER_BVH, PT_LS_INNER_CANDIDATES } pt_ls_scene_inner;

typedef struct pt_settings {
    int spp, max_depth, rr_depth, light_samples, threads;
    bool rr, checkerboard, accumulate, ls_dynamic;
    bool ls_origin_exact;          /* ls_origin=exact, else the voxel offset */
    bool mis;                      /* mis=on: lights by power, MIS with the BSDF */
    bool quad_solid_angle;         /* quad_sampling=solid_angle (pathtrace_quad.c) */
    bool sobol;                    /* rng=sobol, else the GPU generator rng */
    rl_rng_gpu_kind rng;
    uint64_t seed;
    uint32_t sample_offset;        /* rng=sobol: Sobol index of an accumulation's first sample */
    rl_pt_backend shadow, diffuse;
    rl_pt_backend specular;        /* mirror and refraction rays (option specular) */
    pt_primary primary;
    rl_filter_kind filter;
    double filter_fade;
    int atrous_iterations;         /* filter=atrous (rl_filter.h) */
    double atrous_sigma_rt, atrous_sigma_n, atrous_sigma_x;   /* 0 (rt, x): derived */
    bool adaptive;                 /* per-pixel adaptive sampling (pathtrace.c) */
    double adaptive_threshold;
    int adaptive_min_spp;
    int grid_res, ls_n, ls_k, shadowmap_size;
    int ls_scene_n, ls_scene_segments, ls_scene_cells, ls_object_res;
    int ls_scene_inner;            /* pt_ls_scene_inner */
    const char *ls_file;           /* Line Space cache file; "" none (valid for one frame) */
    rl_vec3 background;            /* environment radiance of escaping rays */
    int env_sampling;              /* pt_env_sampling: light samples of a scene environment */
    bool ggx_ms;                   /* GGX energy compensation (pathtrace_ggx.c) */
} pt_settings;

typedef enum pt_env_sampling { PT_ENV_IMPORTANCE = 0, PT_ENV_UNIFORM, PT_ENV_BSDF } pt_env_sampling;

/* pt's noise filter (Sec. 8.2) on image, guided by gbuf: set's filter and
 * its parameters, the edge-stopping scales following the noise of spp
 * samples per pixel (the mean over the image), the filtered image blended
 * in with the weight 1 / (1 + spp / filter_fade) (*weight). gl-pt filters
 * its read-back image with it. */
rl_status rl_pt_filter_image(const pt_settings *set, const rl_gbuffer *gbuf, double spp, rl_image *image,
                             float *weight);

/* What gl-pt shares of the filter's options with pt: the choices of
 * "filter" (in the order of rl_filter_kind), the rows of its parameters
 * (placed after "filter" in an rl_option_info table), and the reading of
 * "filter" and those parameters into set. */
extern const char *const rl_pt_filter_choices[];
/* The other choice lists gl-pt shares with pt (orders: pathtrace.c). */
extern const char *const rl_pt_rng_choices[], *const rl_pt_mis_choices[], *const rl_pt_shadow_choices[],
    *const rl_pt_diffuse_choices[], *const rl_pt_specular_choices[], *const rl_pt_primary_choices[],
    *const rl_pt_ls_origin_choices[], *const rl_pt_env_sampling_choices[], *const rl_pt_adaptive_choices[];
#define RL_PT_FILTER_PARAM_OPTIONS                                                                                 \
    { "filter_fade", RL_OPT_FLOAT, "16",                                                                           \
      "filter weight 1/(1 + spp/filter_fade) with spp the samples so far; 0 = never fade", 0, 1e9, NULL },         \
    { "atrous_iterations", RL_OPT_INT, "5", "a-trous levels (holes 2^i pixels apart; Dammertz et al. 2010)",       \
      1, 12, NULL },                                                                                              \
    { "atrous_sigma_rt", RL_OPT_FLOAT, "0",                                                                        \
      "a-trous colour sigma at the first level, halved per level; 0 = from the samples per pixel", 0, 1e9, NULL }, \
    { "atrous_sigma_n", RL_OPT_FLOAT, "0.1", "a-trous normal sigma (|n - n'|)", 1e-6, 1e9, NULL },                \
    { "atrous_sigma_x", RL_OPT_FLOAT, "0",                                                                         \
      "a-trous position sigma in world units; 0 = 2^atrous_iterations pixel footprints", 0, 1e9, NULL }
void rl_pt_read_filter_settings(const rl_renderer *r, pt_settings *set);
/* The rows of the grid's and the per-voxel Line Space's options (Schröder
 * 2017, Sec. 7.1-7.4, 9.2, 12.1) that pt and gl-pt share: the same names,
 * defaults, ranges and help, in this order. */
#define RL_PT_LINE_SPACE_OPTIONS                                                                                   \
    { "grid_res", RL_OPT_INT, "0", "voxels per axis of the grid and the Line Space (0 = grid heuristic)",          \
      0, 1024, NULL },                                                                                             \
    { "ls_n", RL_OPT_INT, "5", "Line Space patches per voxel face side (Sec. 9.2: 5)", 1, RL_LS_MAX_N, NULL },     \
    { "ls_k", RL_OPT_INT, "8", "Line Space fixed candidate slots per shaft (even; ls_dynamic=false only)", 2,      \
      RL_LS_MAX_K, NULL },                                                                                         \
    { "ls_origin", RL_OPT_ENUM, "offset",                                                                          \
      "PNMT/preillum rays: offset (start one voxel diagonal away, Sec. 12.1) or exact (start at the "              \
      "surface; the start voxel's triangles answer PNMT rays exactly)", 0, 0, rl_pt_ls_origin_choices },         \
    { "ls_dynamic", RL_OPT_BOOL, "true", "exact per-shaft candidate lists (prefix sums, Sec. 7.1.1)", 0, 0, NULL }
/* The rows of adaptive sampling's options (issue 37; pathtrace.c, "Adaptive
 * sampling"), the same names, defaults and ranges in pt and gl-pt; where is
 * a string literal appended to the help of "adaptive" (gl-pt: where its
 * errors and shares are computed), "" for none. */
#define RL_PT_ADAPTIVE_OPTIONS(where)                                                                              \
    { "adaptive", RL_OPT_ENUM, "off",                                                                              \
      "per-pixel adaptive sampling: a frame's paths go where the estimated relative error is largest" where,       \
      0, 0, rl_pt_adaptive_choices },                                                                              \
    { "adaptive_threshold", RL_OPT_FLOAT, "0.01",                                                                  \
      "adaptive: relative error of a pixel's mean below which it gets no more samples", 0, 1e9, NULL },            \
    { "adaptive_min_spp", RL_OPT_INT, "8", "adaptive: samples every pixel gets before the error decides",          \
      2, 65536, NULL }

/* The path length a scene asks for when max_depth is -1, for pt, gl-pt and
 * bdpt alike: the thesis' "max_path_length" root attribute (Sec. 9.3; the
 * built-ins ls-open, ls-cornell and cornell:variant=bitterli set it), else 3. */
int rl_pt_scene_max_depth(const rl_scene *scene);

/* ------------------------------------------------------------ backends -- */

/* The lights next-event estimation chooses from with mis=on, by power: the
 * scene's lights, then the emissive triangles no quad light covers. */
typedef struct pt_lights {
    uint32_t count;                /* entries with power > 0 */
    uint32_t *source;              /* per entry: a light index, or num_lights + triangle */
    float *cdf;                    /* count + 1 running sums, cdf[count] = 1 */
    float *light_pmf;              /* per scene light: its probability */
    bool *light_hittable;          /* per scene light: a quad whose covering mesh a ray can hit */
    /* Per scene light: |edge_u x edge_v| (a quad's area) and that cross
     * product over it (its unit front normal), as next-event estimation
     * computed them at every vertex before. */
    float *light_area;
    rl_vec3 *light_normal;
    float *tri_pmf;                /* per triangle: the probability of an uncovered emitter, else 0 */
    rl_vec3 centre;                /* bounding sphere of the scene (directional lights) */
    float radius;
} pt_lights;

/* The scene environment's sampling distribution (pathtrace_env.c). */
typedef struct pt_env {
    const rl_environment *env;     /* NULL: the scene has none */
    int width, height;             /* the grid of texels */
    float *weight;                 /* per texel: mean radiance * sin(theta) */
    float *conditional;            /* per row: width + 1 running sums, last 1 */
    float *marginal;               /* height + 1 running sums over the rows */
    double sum;                    /* of the weights */
    bool sampled;                  /* some weight > 0: light samples go to it */
    bool uniform;                  /* weights sin(theta) alone (env_sampling=uniform) */
} pt_env;

/* Everything built for one scene, kept between frames (Sec. 5.1: "built
 * once and reused; only a new scene rebuilds them"). */
typedef struct pt_backends {
    uint64_t scene_uid;
    const rl_scene_data *data;
    rl_accel *exact[3];            /* by rl_accel_kind: BVH, GRID, EMBREE */
    double exact_ms[3];
    int grid_res;                  /* the option the grid was built with */
    rl_linespace *ls;
    int ls_n, ls_k;
    bool ls_dynamic;
    unsigned ls_payloads;
    char *ls_file;                 /* the cache file the Line Space came from or went to; NULL none */
    double ls_ms;                  /* its build, or load, time */
    float ls_offset;               /* one voxel diagonal (Sec. 12.1-12.2: "Voxel-Offset") */
    float ls_start;                /* where PNMT / preillum rays start: ls_offset,
                                    * or 0 with ls_origin=exact */
    /* Scene and object Line Spaces (Sec. 13.1, 13.2), with the options they
     * were built with; the scene one borrows its inner structure. */
    rl_ls_objects *lso;
    int lso_n, lso_res;
    double lso_ms;
    rl_ls_scene *lss;
    int lss_n, lss_segments, lss_cells;
    const void *lss_inner;         /* the structure it was created on */
    double lss_ms;
    rl_shadowmap *sm;
    int sm_size;
    double sm_ms;
    uint32_t *tri_cover;           /* per triangle: covering quad light or RL_NONE */
    pt_lights lights;
    pt_env env;
    float eps;                     /* ray origin offset */
} pt_backends;

/* Makes sure the structures that set's backends and primary mode need exist
 * for scene (building what is missing or stale); *built_ms gets the time
 * spent building. RL_ERR_UNSUPPORTED names a backend missing in this build. */
rl_status rl_pt_backends_prepare(pt_backends *b, const rl_scene *scene, const pt_settings *set,
                                 int threads, double *built_ms);
void rl_pt_backends_release(pt_backends *b);
/* The part of rl_pt_backends_prepare that depends on the scene alone: the
 * ray offset, the covering quad light of every triangle and the light
 * table (what gl-pt uploads; it builds its structures itself). */
rl_status rl_pt_backends_prepare_scene(pt_backends *b, const rl_scene *scene);
/* Builds b->lights from the scene and b->tri_cover. */
rl_status rl_pt_lights_build(pt_backends *b, const rl_scene_data *d);
void rl_pt_lights_release(pt_lights *l);
/* Builds e for env (NULL: none), by its radiance or, with uniform, by
 * solid angle alone; RL_ERR_OUT_OF_MEMORY. */
rl_status rl_pt_env_build(pt_env *e, const rl_environment *env, bool uniform);
void rl_pt_env_release(pt_env *e);
/* A direction drawn from the environment's distribution and its density in
 * solid angle; false when the environment is black or the draw hit a pole. */
bool rl_pt_env_sample(const pt_env *e, float u1, float u2, rl_vec3 *dir, float *pdf);
/* That density for unit dir (0 without a sampled environment). */
float rl_pt_env_pdf(const pt_env *e, rl_vec3 dir);
/* The entry of the light table whose cdf interval holds u in [0,1). */
uint32_t rl_pt_lights_pick(const pt_lights *l, float u);
/* Triangle t's area, and its unit geometric normal by its winding. */
float rl_pt_triangle_area(const rl_scene_data *d, uint32_t t, rl_vec3 *normal);
/* The quad light whose parallelogram contains p (within tol of its plane
 * and of its edges), or RL_NONE: the emission rule of pathtrace_path.c. */
uint32_t rl_pt_cover_point(const rl_scene_data *d, rl_vec3 p, float tol);
/* A rectangular quad light seen from a point, for sampling by solid angle
 * (pathtrace_quad.c, Ureña et al. 2013): the rectangle's frame (x, y along
 * its edges, z its front normal), the point o, the rectangle's extent in
 * that frame and the constants of the paper's eq. 9-12; S is the solid
 * angle, the sample density 1 / S. */
typedef struct pt_sph_rect {
    double o[3], x[3], y[3], z[3];
    double x0, x1, y0, y1, z0;
    double b0, b1, k, S;
} pt_sph_rect;
/* Sets r up for quad light L seen from p. False, and the quad is to be
 * sampled by area, when L is not a rectangle, p is behind or in its
 * emitting plane, or the solid angle is below 1e-7 sr. */
bool rl_pt_sph_rect_init(pt_sph_rect *r, const rl_light *L, rl_vec3 p);
/* The point on the rectangle for (u, v) in [0,1)^2; density 1 / r->S in
 * solid angle at r->o. */
rl_vec3 rl_pt_sph_rect_sample(const pt_sph_rect *r, float u, float v);
/* Whether backend can be used in this build (Embree is optional) for shadow
 * tests (shadow = true: all) or secondary rays (not shadow maps). */
bool rl_pt_backend_available(rl_pt_backend backend, bool shadow);

/* --------------------------------------------------------------- paths -- */

/* Per-tile counters, summed in tile order after a pass. */
typedef struct pt_counters {
    uint64_t rays[RL_RAY_TYPE_COUNT];
    uint64_t shadow_q[RL_PT_BACKEND_COUNT];
    uint64_t trace_q[RL_PT_BACKEND_COUNT];
    uint64_t preillum_ends;
} pt_counters;

/* What a path needs; read-only during a pass. */
typedef struct pt_ctx {
    const rl_scene_data *data;
    const pt_backends *b;
    rl_pt_backend shadow, diffuse;
    rl_pt_backend specular;        /* mirror and refraction rays */
    int max_depth, rr_depth, light_samples;
    bool rr;
    bool mis;                      /* lights by power, MIS weights (pathtrace_path.c) */
    bool mis_hits;                 /* with mis: BSDF rays find emitters exactly (an exact
                                    * diffuse backend), so both strategies are weighted */
    bool quad_solid_angle;         /* with mis: rectangular quads sampled by solid angle */
    bool tri_lights;               /* with mis_hits: emissive triangles are sampled too
                                    * (not with shadow maps, which know scene lights only) */
    uint32_t vertex_slots;         /* sampler slots per path vertex */
    rl_vec3 background;            /* radiance of rays that leave the scene */
    /* The scene's environment replaces background: BSDF rays that leave
     * the scene see it, and with env_nee every BRDF vertex also samples it
     * (one 2D sample at slot env_slot of its block), weighted against the
     * BSDF by the power heuristic. */
    const rl_environment *env;     /* NULL: background */
    bool env_nee;                  /* an environment to sample and a shadow ray that can test it */
    uint32_t env_slot;
    bool ggx_ms;                   /* GGX energy compensation at every vertex */
} pt_ctx;

/* The radiance a ray leaving the scene along unit dir brings: the scene's
 * environment or the background. */
rl_vec3 rl_pt_escape_radiance(const pt_ctx *ctx, rl_vec3 dir);

/* ------------------------------------------------------------ sampler -- */

/* The numbers of one sample of one pixel: rng != NULL draws from the
 * thesis' generator in call order; otherwise Owen-scrambled Sobol points
 * addressed by (index, slot). */
typedef struct pt_sampler {
    rl_rng_gpu *rng;
    uint32_t pixel_seed;
    uint32_t index;                /* the sample's number within its pixel */
    uint32_t index_reversed;       /* its bits reversed: every Sobol draw starts from it */
    uint32_t slot;                 /* the next dimension (1D) or pair (2D) */
} pt_sampler;

/* Dimension layout of rng=sobol: the pixel filter, then per path vertex
 * (depth 0 = the camera hit) a block of PT_SLOTS_VERTEX + PT_SLOTS_LIGHT *
 * light_samples slots: the material event, the BSDF lobe, the BSDF
 * direction (2D), Russian roulette, and per light sample the light choice,
 * the point on it (2D) and the shadow-map jitter (2D). */
enum {
    PT_SLOT_PIXEL = 0,
    PT_SLOT_FIRST_VERTEX = 1,
    PT_SLOT_EVENT = 0, PT_SLOT_LOBE, PT_SLOT_BSDF, PT_SLOT_RR,
    PT_SLOTS_VERTEX,
    PT_SLOT_LIGHT_PICK = 0, PT_SLOT_LIGHT_POINT, PT_SLOT_LIGHT_JITTER,
    PT_SLOTS_LIGHT
};

void rl_pt_sampler_init(pt_sampler *s, rl_rng_gpu *rng, uint32_t pixel_seed, uint32_t index);
/* A pixel's scramble seed from the option seed and the pixel's number. */
uint32_t rl_pt_pixel_seed(uint64_t seed, uint64_t pixel);
/* Moves to a slot (ignored by the GPU generators, which run in order).
 * Inline: a path makes several seeks per vertex, each one store. */
static inline void rl_pt_sampler_seek(pt_sampler *s, uint32_t slot)
{
    s->slot = slot;
}
float rl_pt_sample_1d(pt_sampler *s);
rl_vec2 rl_pt_sample_2d(pt_sampler *s);
/* Nested uniform scrambling of x read as a binary fraction (MSB first);
 * exposed for the tests of its stratification. */
uint32_t rl_pt_owen_scramble(uint32_t x, uint32_t seed);
/* The second dimension of Sobol's sequence for index i (only its 24 low
 * bits count; see pathtrace_sampler.c), as a 0.32 binary fraction; exposed
 * for the tests against its direction numbers. */
uint32_t rl_pt_sobol_dim1(uint32_t i);

/* A surface point being shaded. Normals are unit and face the side the
 * ray came from; tri is RL_ID_NONE for a Line Space PNMT record. */
typedef struct pt_surface {
    rl_vec3 p;
    rl_vec3 ng;               /* geometric normal (PNMT: the stored normal) */
    rl_vec3 ns;               /* shading normal */
    rl_vec3 v;                /* unit direction back along the incoming ray */
    bool front;               /* the unflipped geometric normal faced the ray */
    rl_vec3 kd;               /* k_d times the diffuse texture */
    rl_vec2 uv;               /* at exact hits only where a texture reads it, else 0 */
    const rl_material *m;
    uint32_t tri;
    bool ggx_ms;              /* GGX with Kulla-Conty energy compensation (option ggx_ms) */
    /* Phong with k_s = 0 and a finite mean(k_d) > 0: f = k_d / pi, the
     * cosine lobe alone. Set with the surface (rl_pt_surface_lambert); a
     * surface built by hand leaves it false and takes the general path,
     * which gives the same numbers, bit for bit, only slower. */
    bool lambert;
} pt_surface;

/* Surface on triangle tri at p with raw shading normal ns and texture
 * coordinates uv, seen along unit v. tri must be in range. */
void rl_pt_surface_finish(const rl_scene_data *d, uint32_t tri, rl_vec3 p, rl_vec3 ns, rl_vec2 uv, rl_vec3 v,
                          pt_surface *s);
/* Surface at an exact hit of a ray along unit dir; false if the hit names
 * no triangle. */
bool rl_pt_surface_at_hit(const rl_scene_data *d, const rl_hit *hit, rl_vec3 o, rl_vec3 dir, pt_surface *s);

/* Radiance arriving along the camera path whose first vertex is *first
 * (overwritten: it is one of the two vertex buffers the path swaps)
 * (Sec. 6.4: Trace, Shade, Phong sampling, until max_depth or roulette). */
rl_vec3 rl_pt_trace_path(const pt_ctx *ctx, pt_surface *first, pt_sampler *sampler, pt_counters *c);

/* Closest surface along ray through backend `backend` (exact kinds, Line
 * Space candidates, PNMT), counted as `type`. False on a miss. */
bool rl_pt_closest(const pt_ctx *ctx, rl_pt_backend backend, rl_ray *ray, pt_surface *s, pt_counters *c);

/* rl_ls_shade_fn for PREILLUM (user = the pt_backends): the direct light
 * leaving a stored surface, with exact shadow rays through the grid. */
rl_vec3 rl_pt_preillum_shade(void *user, const rl_ls_surface *s, rl_vec3 dir);

/* -------------------------------------------------------------- BSDF ---- */

/* Modified Phong BRDF (Lafortune & Willems 1994) at s for the outgoing
 * direction s->v: f(wi) without the cosine. */
rl_vec3 rl_pt_phong_eval(const pt_surface *s, rl_vec3 wi);
/* Importance samples wi from the lobe mixture (diffuse cosine lobe or
 * cos^n lobe around the mirror direction, chosen by their reflectances);
 * *weight = f cos / pdf with the mixture pdf. False when the sample points
 * below the surface or the material reflects nothing. */
bool rl_pt_phong_sample(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight);
/* The same, and *pdf (pdf may be NULL) = rl_pt_phong_pdf(s, *wi), which
 * the sampling has computed anyway. */
bool rl_pt_phong_sample_pdf(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight,
                            float *pdf);
/* The mixture pdf of rl_pt_phong_sample in solid angle (for tests). */
float rl_pt_phong_pdf(const pt_surface *s, rl_vec3 wi);

/* The Cook-Torrance GGX BRDF of bsdf = ggx materials (pathtrace_ggx.c),
 * with the same contract as the Phong functions above. */
rl_vec3 rl_pt_ggx_eval(const pt_surface *s, rl_vec3 wi);
bool rl_pt_ggx_sample(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight);
float rl_pt_ggx_pdf(const pt_surface *s, rl_vec3 wi);
/* Its parts, for the tests: alpha = max(roughness^2, 1e-3); the GGX normal
 * distribution D at a microfacet normal with cosine cos_m; Smith G1 and the
 * height-correlated G2; a visible normal (Heitz 2018) for the local view wo
 * (z = the normal). */
float rl_pt_ggx_alpha(float roughness);
float rl_pt_ggx_d(float alpha, float cos_m);
float rl_pt_ggx_g1(float alpha, float cos_w);
float rl_pt_ggx_g2(float alpha, float cos_i, float cos_o);
rl_vec3 rl_pt_ggx_sample_vndf(rl_vec3 wo, float alpha, float u1, float u2);
/* Energy compensation (Kulla & Conty 2017): the albedo E(mu) of the
 * specular lobe with F = 1 at a view with cosine mu, and its average
 * E_avg = 2 int E mu dmu, from the tables built on first use; and E by
 * the quadrature of cells x cells visible normals that builds them. */
float rl_pt_ggx_ms_albedo(float roughness, float mu);
float rl_pt_ggx_ms_average(float roughness);
/* The tables themselves, for gl-pt's shader (gl_pathtrace.c uploads them
 * rather than building its own): E at RL_PT_GGX_MS_NODES roughness nodes
 * (rows, r = i / (nodes - 1)) x as many mu nodes (mu = (j / (nodes - 1))^2),
 * row-major into e; E_avg per roughness node into e_avg. */
#define RL_PT_GGX_MS_NODES 32
void rl_pt_ggx_ms_tables(float *e, float *e_avg);
double rl_pt_ggx_albedo_quadrature(float alpha, float mu, int cells);

/* The material's BRDF, Phong or GGX by rl_material.bsdf: what pt and bdpt
 * call at a non-specular event. */
rl_vec3 rl_pt_bsdf_eval(const pt_surface *s, rl_vec3 wi);
bool rl_pt_bsdf_sample(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight);
/* rl_pt_bsdf_sample, and *pdf = rl_pt_bsdf_pdf(s, *wi) bit for bit (pdf
 * may be NULL; Phong has it from the sampling, GGX, which samples in its
 * local frame, asks rl_pt_ggx_pdf). */
bool rl_pt_bsdf_sample_pdf(const pt_surface *s, float u_lobe, float u1, float u2, rl_vec3 *wi, rl_vec3 *weight,
                           float *pdf);
float rl_pt_bsdf_pdf(const pt_surface *s, rl_vec3 wi);
/* Whether sampling m's BRDF uses the lobe number (more than one lobe). */
bool rl_pt_bsdf_needs_lobe(const rl_material *m);
/* Whether s's BRDF is Lambertian (pt_surface.lambert): the Phong model
 * with no specular lobe and a diffuse reflectance whose mean is finite and
 * positive, so that the lobe choice's probability of the diffuse lobe,
 * mean(k_d) / (mean(k_d) + 0), is exactly 1. */
bool rl_pt_surface_lambert(const pt_surface *s);

/* The fast path of a Lambertian vertex (issue 37, the cost of a sample):
 * the values of rl_pt_bsdf_eval and rl_pt_bsdf_pdf, bit for bit, without
 * the call, the GGX dispatch, the specular test and the lobe mixture
 * (Phong's f = k_d / pi + 0 and pdf = 1 * cos / pi). */
static inline rl_vec3 rl_pt_bsdf_f(const pt_surface *s, rl_vec3 wi)
{
    return s->lambert ? rl_scale(s->kd, 1.0f / RL_PI) : rl_pt_bsdf_eval(s, wi);
}
static inline float rl_pt_bsdf_density(const pt_surface *s, rl_vec3 wi)
{
    if (!s->lambert)
        return rl_pt_bsdf_pdf(s, wi);
    float cos_theta = rl_dot(s->ns, wi);
    return cos_theta > 0.0f ? cos_theta / RL_PI : 0.0f;
}

/* The specular event chosen by u_event < k_r + k_t: the mirror (k_r) or
 * the refraction (k_t; total internal reflection mirrors), with Schlick's
 * Fresnel when the material asks for it (the mirror's weight becomes F
 * with F0 = k_s; within k_t, reflection with probability F). *weight
 * multiplies the throughput; *refracted tells the ray type. */
void rl_pt_specular_event(const pt_surface *s, float u_event, rl_vec3 *dir, rl_vec3 *weight, bool *refracted);

/* gl-pt's per-pixel sample counts after an adaptive frame (gl_pathtrace.c,
 * rl_gl_pt_sample_counts; width x height, row 0 the top row): what
 * rl_pt_sample_counts gives for pt. */
rl_status rl_gl_pt_renderer_sample_counts(const rl_renderer *r, uint32_t *counts);

#endif
