/* gl_pt.h: the path tracer of Schröder 2017 (Ch. 5, 6) in GLSL compute
 * shaders (gl_pt.c, gl_pt_shaders.c), the GPU side of renderer "gl-pt"
 * (src/render/gl_pathtrace.c). It computes pt's estimator (pathtrace*.c):
 * the same BSDFs, next-event estimation with or without MIS, Russian
 * roulette, emission rule and sample numbers, so that the two converge to
 * the same image.
 *
 * What the scene needs on the GPU is uploaded once per tracer: triangles,
 * normals, uvs, materials, textures, lights, the light table of MIS, the
 * binary BVH of accel/bvh_build.c (nodes and triangles in leaf order); the
 * uniform grid of accel/grid.h is built and uploaded on the first use of
 * RL_GL_PT_GRID (and again for another grid_res).
 *
 * Bindings: shader storage 0-15, texture units 0-8 (6 the raster IDs,
 * 7 the shadow maps, 8 the environment) and image units 0-1
 * are gl-pt's; storage 16-23 the Line Space's (gl_linespace.h, docs/gl.md).
 *
 * A tracer owns its own GL context (gl_context.h), current on the calling
 * thread for the length of one call: calls must not overlap, but
 * consecutive ones may come from different threads. */
#ifndef RL_GL_PT_H
#define RL_GL_PT_H

#include "rl/rl_accel.h"
#include "rl/rl_camera.h"
#include "rl/rl_gl.h"
#include "rl/rl_linespace.h"
#include "rl/rl_scene.h"
#include "rl/rl_shadowmap.h"

typedef struct rl_gl_pt rl_gl_pt;

/* The structures shadow and secondary rays can go through: the exact ones,
 * and the Line Space's payloads (gl_linespace.h; rl_gl_pt_set_linespace
 * gives the tracer one) as pt uses them (pathtrace_path.c). SHADOWMAP is
 * for shadow rays only: the cube shadow maps of rl_gl_pt_set_shadowmaps,
 * looked up as rl_shadowmap_visible looks up the CPU's. */
typedef enum rl_gl_pt_structure {
    RL_GL_PT_BVH = 0, RL_GL_PT_GRID, RL_GL_PT_LS_CANDIDATES, RL_GL_PT_LS_PNMT, RL_GL_PT_LS_PREILLUM,
    RL_GL_PT_SHADOWMAP, RL_GL_PT_STRUCTURE_COUNT
} rl_gl_pt_structure;

/* The light set of pt's next-event estimation (pathtrace_lights.c: the
 * table of lights chosen by power with mis=on) and the emission rule's
 * covering quad light per triangle, as plain arrays the caller keeps. */
typedef struct rl_gl_pt_lights {
    uint32_t count;                /* table entries */
    const uint32_t *source;        /* count: a light index, or num_lights + triangle */
    const float *cdf;              /* count + 1 */
    const float *light_pmf;        /* per scene light */
    const bool *light_hittable;    /* per scene light */
    const float *tri_pmf;          /* per triangle */
    const uint32_t *tri_cover;     /* per triangle: covering quad light or RL_NONE */
} rl_gl_pt_lights;

typedef struct rl_gl_pt_desc {
    const char *device;            /* rl_gl.h */
    int threads;                   /* BVH and grid build threads (0: all) */
    float eps;                     /* ray origin offset (pt's) */
    rl_gl_pt_lights lights;
    /* The tables of GGX's energy compensation (issue 37; pathtrace_ggx.c,
     * Kulla & Conty 2017) as pt builds them: E(mu) at RL_GL_PT_GGX_NODES
     * roughness x RL_GL_PT_GGX_NODES mu nodes, row-major, then E_avg per
     * roughness node. NULL: zeros (a scene without GGX never reads them). */
    const float *ggx_ms;
} rl_gl_pt_desc;
#define RL_GL_PT_GGX_NODES 32

/* One frame's settings; the names are pt's options (pathtrace.c). */
typedef struct rl_gl_pt_frame {
    rl_camera_frame cam;
    int spp, max_depth, rr_depth, light_samples;
    bool rr, mis;
    bool mis_hits, tri_lights;     /* pt_ctx's: exact backends, so both true with mis */
    int rng;                       /* 0: sobol, else rl_rng_gpu_kind + 1 */
    rl_gl_pt_structure shadow, diffuse;
    rl_gl_pt_structure specular;   /* mirror and refraction rays (pt's specular routing) */
    float ls_start, ls_offset;     /* pt_backends': where PNMT / preillum rays start; the
                                    * voxel offset at a shadow ray's light end */
    int grid_res;                  /* 0: the grid heuristic */
    rl_vec3 background;            /* escaping rays without an environment */
    /* With an environment (rl_gl_pt_set_environment): every BRDF vertex
     * also samples it by its distribution (pt's env_nee: the distribution
     * has weight and shadow rays are traced, not looked up in shadow maps). */
    bool env_nee;
    /* GGX materials (rl_material.bsdf) with pt's energy compensation
     * (option ggx_ms); the tables come with the desc */
    bool ggx_ms;
    /* Per-pixel adaptive sampling (pt's adaptive=on, pathtrace.c): the
     * frame's spp x pixels paths go out by each pixel's estimated relative
     * error, after a uniform start of adaptive_min_spp; pixels below
     * adaptive_threshold get none. Not with checkerboard. */
    bool adaptive;
    float adaptive_threshold;
    int adaptive_min_spp;
    /* Sec. 8.5: this frame traces only the pixels whose x + y has the
     * parity of the frames since the reset (pathtrace.c active()) */
    bool checkerboard;
    /* Non-NULL: primary=raster (Sec. 8.1): per pixel (row 0 the top row)
     * the triangle the raster pass drew there, RL_ID_NONE where none; the
     * paths start where the pixel-centre ray meets its plane, as pt's
     * rasterized G-buffer (gbuffer.c). NULL: jittered camera rays. */
    const uint32_t *raster_ids;
    /* Non-NULL: a new accumulation of cam.width x cam.height pixels starts
     * from these per-pixel states (4 words each, row 0 the top row: the
     * generator state, or for sobol the scramble seed in the first). */
    const uint32_t *reset_states;
    /* Hybrid light paths (Schröder 2017 Sec. 8.4; rl_gl_pt_set_light_vertices):
     * 0 off (the shader as without them); else every BRDF vertex of a camera
     * path joins all vertices of this many light paths drawn from the
     * uploaded set, and the emitter hits and light samples take the MIS
     * weights that count these strategies (gl_pt_shaders.c, "light
     * vertices"). Needs mis, mis_hits and tri_lights, no environment. */
    int light_connect;
    float light_nu1;               /* light_samples / light_connect (the NEE strategy's count ratio) */
} rl_gl_pt_frame;

/* A tracer of scene (committed). RL_ERR_UNSUPPORTED where no GL 4.5
 * context can be made (with the reason), RL_ERR_LIMIT where the scene's
 * arrays exceed the GL's storage block size, RL_ERR_INTERNAL for a GL or
 * shader error. desc's arrays are copied. The path program is compiled
 * by the first frame that needs it, in one of its compile-time variants
 * (with or without GGX, the light-vertex joins, the environment: gl_pt.c
 * V_*), so rl_gl_pt_render can also fail with RL_ERR_INTERNAL for a
 * shader error. */
rl_status rl_gl_pt_create(const rl_scene *scene, const rl_gl_pt_desc *desc, rl_gl_pt **out);
void rl_gl_pt_release(rl_gl_pt *pt);      /* NULL is a no-op */
const rl_gl_info *rl_gl_pt_info(const rl_gl_pt *pt);

/* What a frame did: the samples the pixels hold after it, by the parity of
 * x + y (the two are equal without checkerboard; a pixel of a class that
 * holds none has not been traced yet and its rgba is 0), the frames since
 * the reset, and the rays the frame traced by rl_ray_type, counted by
 * atomic counters in the shader where pt counts them (pathtrace*.c):
 * primary rays of primary=trace, shadow rays, and the reflection,
 * refraction and diffuse rays that continue a path. The 32-bit counters
 * are read and cleared between dispatches before they could wrap, so the
 * counts are exact as long as one dispatch traces fewer than 2^32 rays of
 * a type. */
/* Ray types in rl_ray_type's order (primary, shadow, reflection,
 * refraction, diffuse); the render layer's enum is above this layer, so
 * gl_pathtrace.c checks that the two agree. */
#define RL_GL_PT_RAY_TYPES 5

typedef struct rl_gl_pt_result {
    uint64_t held[2];              /* adaptive: both the mean samples per pixel, rounded down */
    uint64_t frames;
    uint64_t rays[RL_GL_PT_RAY_TYPES];
    uint64_t samples;              /* adaptive: paths traced in this frame (else 0) */
    uint64_t converged;            /* adaptive: pixels below the threshold at the last round */
} rl_gl_pt_result;

/* Traces frame->spp samples per pixel (of the frame's checkerboard half)
 * and adds them to the accumulation (Sec. 6.5, eq. 8); rgba (4 floats per
 * pixel, may be NULL) gets the accumulated mean. RL_ERR_INVALID_ARG
 * without reset_states on the first frame or a size change. res may be
 * NULL. */
rl_status rl_gl_pt_render(rl_gl_pt *pt, const rl_gl_pt_frame *frame, float *rgba, rl_gl_pt_result *res);
/* Texture output (gl_frame.h): a render with rgba NULL copies the mean of
 * the image's w x h into a new texture with a fence (rl_gl.h, rl_gl_frame)
 * instead of only finishing; take hands it over (false: none waiting). An
 * untaken one is deleted by the next such render or the release. */
void rl_gl_pt_set_texture_output(rl_gl_pt *pt, bool on);
bool rl_gl_pt_take_frame(rl_gl_pt *pt, rl_gl_frame *out);

/* The samples every pixel of the accumulation holds (width x height, row 0
 * the top row), kept per pixel only by adaptive frames: RL_ERR_INVALID_ARG
 * before one. */
rl_status rl_gl_pt_sample_counts(rl_gl_pt *pt, uint32_t *counts);

/* The Line Space the LS structures walk, replacing the tracer's: uploaded
 * from ls (committed, its origin rule as set) when ls is non-NULL, else
 * built on the GPU from grid (a committed RL_ACCEL_GRID accel) and desc
 * (CANDIDATES only, gl_linespace.h). Until one succeeds, a frame with an
 * LS structure is RL_ERR_INVALID_ARG. */
rl_status rl_gl_pt_set_linespace(rl_gl_pt *pt, const rl_linespace *ls, const rl_accel *grid,
                                 const rl_linespace_desc *desc);

/* The cube shadow maps of RL_GL_PT_SHADOWMAP (Schröder 2017, Sec. 8.6), the
 * ones rl_shadowmap_create makes on the CPU (desc the same, zeros the
 * defaults) but drawn by GL: per light six depth-only raster passes from
 * the light's point (a quad light's centre) with the same face frames,
 * depth range and casters (all triangles but a quad light's own emitter,
 * alpha masks' holes let light through), each face's eye depths copied on
 * the GPU into one buffer the path program reads. Made again only when
 * desc changes. RL_ERR_UNSUPPORTED for a directional light (as the CPU's),
 * RL_ERR_LIMIT where the maps exceed the GL's buffer texture size. Until
 * one succeeds, a frame with shadow = SHADOWMAP is RL_ERR_INVALID_ARG. */
rl_status rl_gl_pt_set_shadowmaps(rl_gl_pt *pt, const rl_shadowmap_desc *desc);

/* Hybrid light paths (Schröder 2017 Sec. 8.4): the light vertices that
 * the CPU traced for the next frames, in RL_GL_PT_LV_FLOATS floats each
 * (gl_pathtrace.c fills them; gl_pt_shaders.c reads them: position and
 * material, geometric normal, shading normal, direction to the previous
 * vertex, throughput and index on its path, diffuse colour, each with the
 * MIS quantities in the fourth float), grouped by path: path j holds
 * vertices [offsets[j], offsets[j + 1]). paths = 0 removes them. */
#define RL_GL_PT_LV_FLOATS 24
typedef struct rl_gl_pt_light_vertices {
    uint32_t paths;
    const uint32_t *offsets;       /* paths + 1, offsets[0] = 0, non-decreasing */
    const float *data;             /* offsets[paths] vertices */
} rl_gl_pt_light_vertices;

rl_status rl_gl_pt_set_light_vertices(rl_gl_pt *pt, const rl_gl_pt_light_vertices *lv);

/* The scene's environment (issue 37; pt's pathtrace_env.c,
 * scene/environment.c) as plain arrays the caller keeps: the radiance of
 * each texel of the lat-long map (rl_environment_radiance's product of the
 * colour and the texel; 1 x 1 for a constant environment) and the
 * sampling distribution rl_pt_env_build made for it (the grid of weights,
 * per row width + 1 running sums, height + 1 over the rows, their sum in
 * double), so that the shader looks up and samples it as pt does. */
typedef struct rl_gl_pt_env {
    const float *radiance;         /* map_width * map_height rgb triples, row 0 at v = 0 (up) */
    int map_width, map_height;
    float rotation;                /* about +y, radians (rl_radians(rotation_deg)) */
    int width, height;             /* the distribution's grid */
    const float *weight;           /* width * height */
    const float *conditional;      /* height * (width + 1) */
    const float *marginal;         /* height + 1 */
    double sum;                    /* of the weights; the density's normaliser */
} rl_gl_pt_env;

/* Gives the tracer env (copied), or with NULL takes its environment away
 * (escaping rays then see the frame's background). RL_ERR_INVALID_ARG for
 * inconsistent sizes, RL_ERR_LIMIT past the GL's buffer texture size. The
 * arrays live in one r32f buffer texture (without an environment a
 * 12-byte one is bound, see no_maps in gl_pt.c); frames with and without
 * an environment use the path program's variants with and without it. */
rl_status rl_gl_pt_set_environment(rl_gl_pt *pt, const rl_gl_pt_env *env);

/* Traces n rays through structure on the GPU (closest hit, or with any the
 * first hit found) into hits (t, u, v, triangle; the object is left
 * RL_ID_NONE; t = INFINITY and triangle RL_ID_NONE on a miss): the ray set
 * the tests compare with the CPU's structures (BVH or GRID only). grid_res
 * as in the frame. */
rl_status rl_gl_pt_trace(rl_gl_pt *pt, rl_gl_pt_structure structure, int grid_res, bool any, const rl_ray *rays,
                         uint32_t n, rl_hit *hits);

/* The shader texts (gl_pt_shaders.c). */
extern const char *const rl_gl_pt_glsl_header;
/* common, then rl_gl_glsl_tex_sample (gl_shaders.h), then common2 */
extern const char *const rl_gl_pt_glsl_common;
extern const char *const rl_gl_pt_glsl_common2;
extern const char *const rl_gl_pt_glsl_path;
extern const char *const rl_gl_pt_glsl_rays;
/* adaptive sampling's passes (errors, shares): after the header alone */
extern const char *const rl_gl_pt_glsl_adapt;
/* the shadow maps' depth pass: after header, defines and common */
extern const char *const rl_gl_pt_glsl_shadow_vs;
/* after header, defines, common and rl_gl_glsl_tex_sample */
extern const char *const rl_gl_pt_glsl_shadow_fs;

#endif
