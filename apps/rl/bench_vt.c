/* bench_vt.c: `rl bench vt`: the measurements of Ullmann 2003, Ch. 5
 * (Sec. 5.1-5.3) for the renderer "vt", each against the renderer "whitted"
 * of the same run with the same tracer options (max_depth, area_samples,
 * shadows, threads), as tables on stdout and one JSON record:
 *   criteria    Fig. 5.5/5.6: vertices and splits per refinement criterion
 *   resolution  Fig. 5.10-5.12: rays, samples and time vs resolution, preview
 *   quality     min_edge sweep for tree+hsv and hsv: the fastest setting with
 *               SSIM >= 0.95 and its time relative to Whitted (target: <= 0.1)
 *   threads     Fig. 5.9/5.15: speed-up, rays per thread, time split
 *   visibility  Fig. 5.13: the ID, Z and clipping tests switched off in turn
 *   animation   Sec. 3.4.5: the `cluster` camera path with and without
 *               temporal coherence, which must give identical images
 *   correctness Sec. 6.1: the options nonlinear (6.1.1) and shaft_cull
 *               (6.1.2) on the table (at the defaults and at hsv/min_edge
 *               14) and on two small scenes built so that the defaults
 *               miss a highlight and a shadow inside a face; only with
 *               --only
 *   reconstruct Sec. 3.5 on OpenGL (issue 35, part 5): per texture mode the
 *               drawing time (time_draw_ms) and frame time of
 *               reconstruct=software and =gl in the same run, and the SSIM
 *               between their images; the record names the GL renderer
 *   hint        Sec. 6.2.2: intersection hints and ray presorting on the
 *               table and cluster scenes, one thread, CPU time; the images
 *               must not change
 *   deferred    Fig. 5.8: the error of deferred reflected/transmitted
 *               textures against Whitted per criterion and min_edge, one
 *               untimed render per setting
 *   scenario    Sec. 5.4, Fig. 5.16-5.21: the cluster at 1280x1024 per
 *               view and shading mode, times against the thesis' figures
 * The static sections use the built-in scene `table` (Sec. 5.1) with its
 * default camera.
 *
 * Quality: SSIM, RMSE and PSNR (rl_metrics.h) of the VT image against the
 * Whitted image, over the VT-object pixels and over the whole frame. The VT
 * pixels are those whose object ID in Whitted's ID layer is a VT object. The
 * vt renderer does not export its object set, so the bench derives it by the
 * rule its option objects=auto documents: an object is a VT object when the
 * attribute vt of its node, or of the nearest ancestor that has one, says
 * true; when no node has the attribute, the objects with a reflective or
 * refractive material are (Sec. 3.5).
 *
 * Timing: per configuration one warm-up render (it builds and caches the
 * accelerator and the VT meshes, which a frame of an interactive session
 * does not pay), then the fastest of 2 renders (--quick: 1). Static frames
 * run with coherence=false: a repeated frame would otherwise reuse its own
 * shadow feelers. Temporal coherence is measured in the animation section,
 * where each frame is rendered once, for the same reason. */
#define _POSIX_C_SOURCE 200809L
#include "bench_vt.h"

#include "bench_args.h"
#include "bench_rays.h"
#include "bench_util.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "rl/rl_gl.h"
#include "rl/rl_options.h"
#include "rl/rl_metrics.h"
#include "rl/rl_vt.h"

static const char bench_vt_help[] =
    "usage: rl bench vt [options]\n"
    "\n"
    "Measures Vertex Tracing (renderer vt, Ullmann 2003) as in the thesis, Ch. 5,\n"
    "always against the Whitted ray tracer of the same run with the same tracer\n"
    "options, and writes a table and JSON. Sections:\n"
    "  criteria    table scene: vertices, splits, rays, time and SSIM/RMSE/PSNR\n"
    "              per criterion rgb, hsv, tree, tree+rgb, tree+hsv (Fig. 5.5/5.6);\n"
    "              ownVT (criteria, modes): SSIM on the VT pixels with the rest of\n"
    "              the frame Whitted's, the VT objects' own error\n"
    "  resolution  512, 1024, 2048 square: rays and samples as % of Whitted's,\n"
    "              time and preview time (Fig. 5.10-5.12)\n"
    "  quality     min_edge 1, 2, ... 32 for tree+hsv and for hsv, each until two\n"
    "              settings in a row miss SSIM 0.95 on the VT pixels: the fastest\n"
    "              setting that reaches it, as a multiple of Whitted's time\n"
    "  threads     1, 2, 4, ... threads: speed-up, rays per thread, load imbalance,\n"
    "              time split (Fig. 5.9, 5.15)\n"
    "  visibility  ID/Z/clip tests on and off (Fig. 5.13)\n"
    "  modes       the shading modes +-S +-R +-T (shadow, reflection, transmission\n"
    "              rays on or off) for both renderers: time split, VT against\n"
    "              Whitted in time and rays, samples, SSIM (Fig. 5.9, 5.10)\n"
    "  forced      forced refinement on and off at tree+hsv/min_edge 1 and at\n"
    "              hsv/min_edge 14: vertices, forced splits, rays, time, SSIM (Fig. 5.3)\n"
    "  preview     the preview alone (refinement stopped after the primary\n"
    "              vertices) at 512, 1024, 2048 square: its time by phase (Fig. 5.12b)\n"
    "  reduction   sample reduction (Sec. 6.2.1, merge_px 0, 0.5, 1, 2): the preview\n"
    "              and the full frame: samples, merged vertices, time, SSIM\n"
    "  correctness (only with --only) Sec. 6.1: nonlinear=extremum|interval|\n"
    "              derivative|affine and shaft_cull=shadow|all against off, on the\n"
    "              table at the defaults and at hsv/min_edge 14, and on two small\n"
    "              scenes whose highlight\n"
    "              and shadow fall inside a face (the miss of Fig. 6.1/6.5): vertices,\n"
    "              splits, rays, time, SSIM/RMSE against Whitted\n"
    "  overdraw    progressive overdraw against redraw, per stage k and for\n"
    "              f = 0, 1e-5, 1e-4, 1e-3, 1e-2 (eq. 3.16): the rasterization error\n"
    "              of overdrawing (Fig. 5.7)\n"
    "  equalrays   the preview and the converged frame against Whitted with as many\n"
    "              rays (a smaller image scaled up): SSIM on the VT pixels (Fig. 5.4)\n"
    "  deferred    the perspective error of deferred reflected and transmitted\n"
    "              textures: criteria tree and tree+hsv, min_edge 1..16, textures\n"
    "              multitexture and sampled against Whitted on the pixels that show\n"
    "              a reflection or refraction (Fig. 5.8)\n"
    "  animation   cluster scene camera path with and without temporal coherence\n"
    "  reconstruct the drawing (Sec. 3.5) on the CPU rasterizer and on OpenGL\n"
    "              (reconstruct=gl) per texture mode: draw and frame time, SSIM\n"
    "  hint        intersection hints and ray presorting (Sec. 6.2.2) on and off on\n"
    "              the table and cluster scenes, one thread: hint tests and hits,\n"
    "              CPU time (least of 3, interleaved); the images must not change\n"
    "              (--quick: table only, off against hint=parents presort=true)\n"
    "  scenario    the cluster instrument (Sec. 5.4, Fig. 5.16-5.21) at 1280x1024\n"
    "              (or --size; --quick 80x64): driver, lateral and zoom views,\n"
    "              without reflection or transmission, the preview; VT and\n"
    "              Whitted times, preview time, rays, samples, SSIM on the glass\n"
    "\n"
    "options:\n"
    "  --scene SPEC      scene of the static sections; default table (its variant\n"
    "                    mirror: fill light, mirroring tablecloth); table:variant=thesis\n"
    "                    is Sec. 5.1's set-up, table:variant=cup its blue cup as the\n"
    "                    only VT object (Figs. 5.5/5.6)\n"
    "  --set KEY=VALUE   vt option every renderer starts from (repeatable, up to 16);\n"
    "                    tracer keys such as max_depth go to Whitted too; sections\n"
    "                    still set what they vary. The thesis' counts of Figs. 5.5/5.6:\n"
    "                    --scene table:variant=cup --set min_edge=2 --set max_depth=4\n"
    "  --size WxH        static sections (not resolution); default 1024x1024\n"
    "  --anim-size WxH   animation frames; default 640x480\n"
    "  --frames N        animation frames along the path; default 60\n"
    "  --threads N       threads of both renderers and the largest count of the\n"
    "                    threads section; default all cores\n"
    "  --only LIST       comma-separated subset of the sections above; default all\n"
    "                    but correctness, and without --quick also but deferred,\n"
    "                    scenario and hint (minutes each at full size)\n"
    "  --out FILE.json   default bench/results/vt-YYYYMMDD-HHMMSS.json\n"
    "  --images DIR      write the images of Fig. 5.8 and 5.16-5.21 into DIR as PNG\n"
    "                    (made when missing); default none\n"
    "  --quick           tiny run: 128x128, resolutions 64 and 128, threads 1 and 2,\n"
    "                    3 frames, one timed render\n"
    "\n"
    "Timing: one warm-up render per configuration, then the fastest of 2.\n"
    "SSIM etc. are measured over the VT-object pixels and over the whole frame.\n"
    "\n"
    "example:\n"
    "  rl bench vt --only criteria,quality --size 512x512\n";

/* The static sections (the table scene) come before animation. */
enum { SEC_CRITERIA, SEC_RESOLUTION, SEC_QUALITY, SEC_THREADS, SEC_VISIBILITY, SEC_MODES, SEC_FORCED,
       SEC_PREVIEW, SEC_REDUCTION, SEC_OVERDRAW, SEC_EQUAL_RAYS, SEC_DEFERRED, SEC_ANIMATION,
       SEC_RECONSTRUCT, SEC_CORRECTNESS, SEC_HINT, SEC_SCENARIO, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "criteria", "resolution", "quality", "threads",
                                                      "visibility", "modes", "forced", "preview",
                                                      "reduction", "overdraw", "equalrays", "deferred",
                                                      "animation", "reconstruct", "correctness", "hint",
                                                      "scenario" };

/* The shading modes of Ullmann 2003, Figs. 5.9/5.10, as bits: shadow
 * feelers (S), reflection rays (R), transmission rays (T). */
enum { MODE_S = 1, MODE_R = 2, MODE_T = 4, MODE_ALL = 7 };

/* Tracer options set on both renderers (their defaults, set explicitly so
 * that a changed default cannot make the comparison unfair). */
#define TRACE_MAX_DEPTH "5"
#define TRACE_AREA_SAMPLES "4"
#define TRACE_SHADOWS "true"

#define MAX_FRAMES 100000
#define SSIM_GOAL 0.95          /* "equal quality" for the min_edge sweep */
#define TIME_RATIO_GOAL 0.1     /* VT time / Whitted time at equal quality */
#define MAX_REFS 32

/* Ullmann 2003, Fig. 5.5/5.6: generated vertices on the table scene. */
static const struct {
    const char *name;
    double thesis_generated;
} criteria[] = {
    { "rgb", 23220 }, { "hsv", 23058 }, { "tree", 22470 }, { "tree+rgb", 28535 },
    { "tree+hsv", 28037 },
};

/* --set KEY=VALUE (issue 36): vt options every renderer of the run starts
 * from, after the bench's own settings; a section still sets what it
 * varies (criteria, min_edge, ...). A key Whitted has too (the tracer's:
 * max_depth, area_samples, shadows, ...) goes to Whitted as well, so that
 * both renderers keep the same tracer. */
#define MAX_SETS 16
typedef struct bvt_sets {
    int count;
    char key[MAX_SETS][64];
    const char *value[MAX_SETS];   /* points into argv */
    const char *text[MAX_SETS];    /* the whole KEY=VALUE, for the record */
} bvt_sets;

/* The run's --set list; make_renderer reads it (one bench per process). */
static const bvt_sets *run_sets;

typedef struct bvt_args {
    int width, height, anim_width, anim_height;
    long long frames, threads;     /* threads 0 = all */
    bool has_size, has_anim_size, has_frames, quick;
    unsigned sections;             /* bit per SEC_ */
    const char *out;
    const char *scene;             /* static sections; NULL: "table" */
    const char *images;            /* folder for the figures' images; NULL: none */
    bvt_sets sets;                 /* --set */
} bvt_args;

/* A Whitted frame, the reference of every comparison at its size. */
typedef struct ref_frame {
    int width, height, threads, mode;
    rl_image *image;               /* colour and IDs */
    uint8_t *mask;                 /* VT-object pixels */
    uint64_t mask_pixels;
    rl_render_stats stats;         /* of the fastest timed render */
} ref_frame;

typedef struct bvt {
    const bvt_args *a;
    int threads;                   /* both renderers, static sections */
    int max_threads;               /* largest count of the threads section */
    int runs;                      /* timed renders after the warm-up */
    rl_scene *table, *cluster;
    uint8_t *table_vt, *cluster_vt;        /* per object: a VT object */
    rl_camera table_cam;
    ref_frame refs[MAX_REFS];
    int num_refs;
    char reason[256];              /* why a section failed, when not the library's */
} bvt;

/* The fastest timed render of a configuration. */
typedef struct timed_frame {
    rl_render_stats stats;
    rl_vt_stats vt;                /* vt renderers only */
} timed_frame;

typedef struct quality {
    rl_image_metrics vt_px, full;  /* VT-object pixels, whole frame */
    /* The VT pixels again, in the frame with every other pixel taken from
     * the reference: SSIM's windows reach 5 pixels past an object's
     * outline, and vt draws the non-VT objects with local lighting (Sec.
     * 3.5: no shadows, no mirror images), so vt_px also counts how the
     * table around the cup differs. This is the VT objects' own error. */
    rl_image_metrics vt_own;
} quality;

/* ------------------------------------------------------------ output -- */

/* "bench vt: criteria rgb 1024x1024: ..." on stderr, one per measurement. */
#define note(...) bench_note("vt", __VA_ARGS__)
#define add_num bench_add_num
#define rays_total bench_rays_total
#define rays_json bench_rays_json
#define metrics_json bench_metrics_json
#define ratio bench_ratio

static cJSON *quality_json(const quality *q)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddItemToObject(o, "vt_pixels", metrics_json(&q->vt_px));
    cJSON_AddItemToObject(o, "vt_pixels_own", metrics_json(&q->vt_own));
    cJSON_AddItemToObject(o, "full", metrics_json(&q->full));
    return o;
}

static cJSON *vt_stats_json(const rl_vt_stats *s)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    const struct {
        const char *key;
        uint64_t value;
    } counts[] = {
        { "vt_objects", s->vt_objects },
        { "primary_vertices", s->primary_vertices },
        { "primary_faces", s->primary_faces },
        { "visible_primary_faces", s->visible_primary_faces },
        { "vertices_sampled", s->vertices_sampled },
        { "vertices_generated", s->vertices_generated },
        { "splits_rgb", s->splits_rgb },
        { "splits_hsv", s->splits_hsv },
        { "splits_tree", s->splits_tree },
        { "splits_forced", s->splits_forced },
        { "edges_tested", s->edges_tested },
        { "edges_culled_z", s->edges_culled_z },
        { "edges_culled_viewport", s->edges_culled_viewport },
        { "faces_drawn", s->faces_drawn },
        { "feelers_reused", s->feelers_reused },
        { "vertices_merged", s->vertices_merged },
        { "splits_nonlinear", s->splits_nonlinear },
        { "splits_shaft", s->splits_shaft },
        { "splits_pixel", s->splits_pixel },
        { "shaft_faces_tested", s->shaft_faces_tested },
        { "hint_tests", s->hint_tests },
        { "hint_hits", s->hint_hits },
        { "mesh_bytes", s->mesh_bytes },
        { "stages", s->stages },
        { "threads", s->threads },
    };
    for (size_t i = 0; i < sizeof counts / sizeof counts[0]; i++)
        cJSON_AddNumberToObject(o, counts[i].key, (double)counts[i].value);
    add_num(o, "time_visibility_ms", s->time_visibility_ms);
    add_num(o, "time_sampling_ms", s->time_sampling_ms);
    add_num(o, "time_refine_ms", s->time_refine_ms);
    add_num(o, "time_draw_ms", s->time_draw_ms);
    add_num(o, "time_preview_ms", s->time_preview_ms);
    return o;
}

/* Whitted's figures of a reference frame. */
static cJSON *ref_json(const ref_frame *ref)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    add_num(o, "time_ms", ref->stats.time_ms);
    cJSON_AddItemToObject(o, "rays", rays_json(&ref->stats));
    cJSON_AddNumberToObject(o, "vt_pixels", (double)ref->mask_pixels);
    return o;
}

/* A failure the bench itself finds; returns st. */
static rl_status bench_error(bvt *b, rl_status st, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 3, 4)))
#endif
    ;
static rl_status bench_error(bvt *b, rl_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(b->reason, sizeof b->reason, fmt, ap);
    va_end(ap);
    return st;
}

/* ------------------------------------------------------- VT objects -- */

/* The attribute vt of node or its nearest ancestor that has one: 1 true,
 * 0 false, -1 none (the rule of the vt renderer's objects=auto). */
static int vt_attribute(const rl_scene *scene, uint32_t node)
{
    for (uint32_t n = node; n != RL_NONE; n = rl_scene_node_parent(scene, n)) {
        const char *v = rl_scene_node_attr(scene, n, "vt");
        if (v)
            return strcmp(v, "true") == 0 || strcmp(v, "1") == 0 || strcmp(v, "yes") == 0;
    }
    return -1;
}

/* One byte per object: 1 for a VT object. NULL when out of memory. */
static uint8_t *vt_objects(const rl_scene *scene)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    uint8_t *vt = calloc(d->num_objects ? d->num_objects : 1, 1);
    if (!vt)
        return NULL;
    bool any = false;
    for (uint32_t o = 0; o < d->num_objects; o++) {
        int a = vt_attribute(scene, d->objects[o].node);
        any = any || a >= 0;
        vt[o] = a > 0;
    }
    if (any)
        return vt;
    /* Sec. 3.5: without attributes, the specular objects are traced. */
    for (uint32_t o = 0; o < d->num_objects; o++) {
        const rl_object *obj = &d->objects[o];
        for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->num_triangles; t++) {
            const rl_material *m = &d->materials[d->triangle_material[t]];
            if (m->reflectivity > 0.0f || m->transmissivity > 0.0f) {
                vt[o] = 1;
                break;
            }
        }
    }
    return vt;
}

/* mask[i] = 1 where Whitted saw a VT object; returns the count. */
static uint64_t fill_mask(const rl_image *ref, const uint8_t *object_vt, uint32_t num_objects,
                          uint8_t *mask)
{
    uint64_t n = 0;
    size_t pixels = (size_t)ref->width * (size_t)ref->height;
    for (size_t i = 0; i < pixels; i++) {
        uint32_t id = ref->object_id[i];
        mask[i] = id != RL_ID_NONE && id < num_objects && object_vt[id];
        n += mask[i];
    }
    return n;
}

/* --------------------------------------------------------- rendering -- */

static bool has_option(const rl_renderer *r, const char *key)
{
    size_t count = 0;
    const rl_option_info *opts = rl_renderer_options(r, &count);
    for (size_t i = 0; i < count; i++)
        if (strcmp(opts[i].key, key) == 0)
            return true;
    return false;
}

static rl_status make_renderer(const char *name, int threads, rl_renderer **out)
{
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create(name, &r);
    char t[16];
    snprintf(t, sizeof t, "%d", threads);
    const char *const keys[] = { "max_depth", "area_samples", "shadows", "threads" };
    const char *const values[] = { TRACE_MAX_DEPTH, TRACE_AREA_SAMPLES, TRACE_SHADOWS, t };
    for (size_t i = 0; st == RL_OK && i < sizeof keys / sizeof keys[0]; i++)
        st = rl_renderer_set(r, keys[i], values[i]);
    if (st == RL_OK && strcmp(name, "vt") == 0)
        st = rl_renderer_set(r, "coherence", "false");
    bool vt = strcmp(name, "vt") == 0;
    for (int i = 0; st == RL_OK && run_sets && i < run_sets->count; i++)
        if (vt || has_option(r, run_sets->key[i]))
            st = rl_renderer_set(r, run_sets->key[i], run_sets->value[i]);
    if (st != RL_OK) {
        rl_renderer_release(r);
        r = NULL;
    }
    *out = r;
    return st;
}

/* "+S-R+T" */
static void mode_name(int mode, char out[8])
{
    snprintf(out, 8, "%cS%cR%cT", mode & MODE_S ? '+' : '-', mode & MODE_R ? '+' : '-', mode & MODE_T ? '+' : '-');
}

static rl_status set_mode(rl_renderer *r, int mode)
{
    rl_status st = rl_renderer_set(r, "shadows", mode & MODE_S ? "true" : "false");
    if (st == RL_OK)
        st = rl_renderer_set(r, "reflections", mode & MODE_R ? "true" : "false");
    if (st == RL_OK)
        st = rl_renderer_set(r, "transmission", mode & MODE_T ? "true" : "false");
    return st;
}

/* The scene of the static sections (--scene). */
static const char *table_spec(const bvt *b)
{
    return b->a->scene ? b->a->scene : "table";
}

static rl_status set_int(rl_renderer *r, const char *key, double value)
{
    char text[32];
    snprintf(text, sizeof text, "%g", value);
    return rl_renderer_set(r, key, text);
}

static rl_camera sized(const rl_camera *cam, int width, int height)
{
    rl_camera c = *cam;
    c.width = width;
    c.height = height;
    return c;
}

/* One warm-up render, then the fastest of runs; img holds the last frame
 * (all frames of a configuration are the same: nothing is random). */
static rl_status render_timed(rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                              rl_image *img, int runs, timed_frame *out)
{
    bool vt = strcmp(rl_renderer_name(r), "vt") == 0;
    rl_render_stats stats;
    rl_clear_error();
    rl_status st = rl_renderer_render(r, scene, cam, img, &stats);
    memset(out, 0, sizeof *out);
    out->stats.time_ms = INFINITY;
    for (int i = 0; st == RL_OK && i < runs; i++) {
        st = rl_renderer_render(r, scene, cam, img, &stats);
        if (st == RL_OK && stats.time_ms < out->stats.time_ms) {
            out->stats = stats;
            if (vt)
                st = rl_vt_get_stats(r, &out->vt);
        }
    }
    return st;
}

/* The Whitted frame at width x height with threads, rendered on first use. */
/* Whitted on the table at img's size: warm-up, then the fastest timed run. */
static rl_status time_whitted(bvt *b, int threads, int mode, rl_image *img, timed_frame *t)
{
    rl_renderer *r = NULL;
    rl_camera cam = sized(&b->table_cam, img->width, img->height);
    rl_status st = make_renderer("whitted", threads, &r);
    if (st == RL_OK)
        st = set_mode(r, mode);
    if (st == RL_OK)
        st = render_timed(r, b->table, &cam, img, b->runs, t);
    rl_renderer_release(r);
    return st;
}

static rl_status reference(bvt *b, int width, int height, int threads, int mode, ref_frame **out)
{
    for (int i = 0; i < b->num_refs; i++) {
        ref_frame *f = &b->refs[i];
        if (f->width == width && f->height == height && f->threads == threads && f->mode == mode) {
            *out = f;
            return RL_OK;
        }
    }
    if (b->num_refs == MAX_REFS)      /* never with the fixed section lists */
        return bench_error(b, RL_ERR_LIMIT, "more than %d reference frames", MAX_REFS);
    ref_frame *f = &b->refs[b->num_refs];
    memset(f, 0, sizeof *f);
    timed_frame t;
    rl_status st = rl_image_create(width, height, RL_LAYER_COLOR | RL_LAYER_ID, &f->image);
    if (st == RL_OK && !(f->mask = malloc((size_t)width * (size_t)height)))
        st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        st = time_whitted(b, threads, mode, f->image, &t);
    if (st != RL_OK) {
        rl_image_release(f->image);
        free(f->mask);
        return st;
    }
    f->width = width;
    f->height = height;
    f->threads = threads;
    f->mode = mode;
    f->stats = t.stats;
    f->mask_pixels = fill_mask(f->image, b->table_vt, rl_scene_get_data(b->table)->num_objects,
                               f->mask);
    b->num_refs++;
    note("whitted %dx%d, %d threads: %.1f ms, %llu rays, %llu VT pixels", width, height, threads,
         t.stats.time_ms, (unsigned long long)rays_total(&t.stats),
         (unsigned long long)f->mask_pixels);
    *out = f;
    return RL_OK;
}

/* The start of a static section at --size: the Whitted reference (made
 * once per size and kept), the section's scene and size in the record, and
 * with with_ref the reference's own figures. */
static rl_status table_section(bvt *b, cJSON *sec, bool with_ref, ref_frame **ref, char size[32])
{
    int w = b->a->width, h = b->a->height;
    rl_status st = reference(b, w, h, b->threads, MODE_ALL, ref);
    if (st != RL_OK)
        return st;
    snprintf(size, 32, "%dx%d", w, h);
    cJSON_AddStringToObject(sec, "scene", table_spec(b));
    cJSON_AddStringToObject(sec, "size", size);
    if (with_ref)
        cJSON_AddItemToObject(sec, "whitted", ref_json(*ref));
    return RL_OK;
}

/* What most table sections share: the reference and the section's scene
 * and size (table_section), the "runs" array, the table camera at --size,
 * an image and, with with_renderer, a vt renderer. table_end releases them
 * (whatever table_begin got to) and passes st on. */
typedef struct table_run {
    ref_frame *ref;
    char size[32];
    cJSON *rows;
    rl_camera cam;
    rl_image *img;
    rl_renderer *r;
} table_run;

static rl_status table_begin(bvt *b, cJSON *sec, bool with_ref, bool with_renderer, table_run *tr)
{
    *tr = (table_run){ 0 };
    rl_status st = table_section(b, sec, with_ref, &tr->ref, tr->size);
    if (st != RL_OK)
        return st;
    tr->rows = cJSON_AddArrayToObject(sec, "runs");
    tr->cam = sized(&b->table_cam, b->a->width, b->a->height);
    if (with_renderer)
        st = make_renderer("vt", b->threads, &tr->r);
    if (st == RL_OK)
        st = rl_image_create(b->a->width, b->a->height, RL_LAYER_COLOR, &tr->img);
    return st;
}

static rl_status table_end(table_run *tr, rl_status st)
{
    rl_image_release(tr->img);
    rl_renderer_release(tr->r);
    return st;
}

static void nan_metrics(rl_image_metrics *m)
{
    *m = (rl_image_metrics){ .rmse = NAN, .psnr = NAN, .ssim = NAN, .max_abs = NAN };
}

/* img against the reference, over the VT pixels (when there are any) and
 * over the whole frame. */
static rl_status compare(const rl_image *img, const rl_image *ref, const uint8_t *mask,
                         uint64_t mask_pixels, quality *q)
{
    nan_metrics(&q->vt_px);
    nan_metrics(&q->vt_own);
    rl_status st = rl_image_compare(img, ref, &(rl_metric_options){ 0 }, &q->full);
    if (st == RL_OK && mask_pixels)
        st = rl_image_compare(img, ref, &(rl_metric_options){ .mask = mask }, &q->vt_px);
    rl_image *own = NULL;
    if (st == RL_OK && mask_pixels)
        st = rl_image_create(img->width, img->height, RL_LAYER_COLOR, &own);
    if (st == RL_OK && own) {
        size_t n = (size_t)img->width * (size_t)img->height;
        for (size_t i = 0; i < n; i++)
            own->color[i] = mask[i] ? img->color[i] : ref->color[i];
        st = rl_image_compare(own, ref, &(rl_metric_options){ .mask = mask }, &q->vt_own);
    }
    rl_image_release(own);
    return st;
}

/* The fields of every VT run row: vertices, rays, time (and its ratio to
 * Whitted's), quality and the renderer's statistics. */
static void add_run_fields(cJSON *row, const timed_frame *t, const quality *q, double whitted_ms)
{
    cJSON_AddNumberToObject(row, "vertices_sampled", (double)t->vt.vertices_sampled);
    cJSON_AddNumberToObject(row, "vertices_generated", (double)t->vt.vertices_generated);
    cJSON_AddItemToObject(row, "rays", rays_json(&t->stats));
    add_num(row, "time_ms", t->stats.time_ms);
    add_num(row, "time_ratio_to_whitted", ratio(t->stats.time_ms, whitted_ms));
    cJSON_AddItemToObject(row, "quality", quality_json(q));
    cJSON_AddItemToObject(row, "vt_stats", vt_stats_json(&t->vt));
}

/* ---------------------------------------------------------- criteria -- */

/* Fig. 5.5/5.6: the same frame refined by each criterion. */
static rl_status sec_criteria(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    table_run tr;
    rl_status st = table_begin(b, sec, true, true, &tr);
    if (st != RL_OK)
        return table_end(&tr, st);

    printf("\ncriteria (Fig. 5.5/5.6): %s %s, whitted %.1f ms, %llu rays, %llu VT pixels\n",
           table_spec(b), tr.size, tr.ref->stats.time_ms, (unsigned long long)rays_total(&tr.ref->stats),
           (unsigned long long)tr.ref->mask_pixels);
    printf("%-9s %9s %9s %9s %8s %8s %8s %7s %8s %10s %9s  %6s %7s %6s  %6s %7s  %6s\n", "criteria",
           "sampled", "generated", "thesis", "rgb", "hsv", "tree", "forced", "faces", "rays",
           "ms", "ssimVT", "rmseVT", "psnrVT", "ssim", "rmse", "ownVT");
    for (size_t c = 0; st == RL_OK && c < sizeof criteria / sizeof criteria[0]; c++) {
        timed_frame t;
        quality q;
        const rl_vt_vertex_info *verts;
        const uint32_t *faces;
        size_t num_verts = 0, num_faces = 0;
        rl_clear_error();
        st = rl_renderer_set(tr.r, "criteria", criteria[c].name);
        if (st == RL_OK)
            st = render_timed(tr.r, b->table, &tr.cam, tr.img, b->runs, &t);
        if (st == RL_OK)
            st = rl_vt_get_mesh(tr.r, &verts, &num_verts, &faces, &num_faces);
        if (st == RL_OK)
            st = compare(tr.img, tr.ref->image, tr.ref->mask, tr.ref->mask_pixels, &q);
        if (st != RL_OK)
            break;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(tr.rows, row);
        cJSON_AddStringToObject(row, "criteria", criteria[c].name);
        add_run_fields(row, &t, &q, tr.ref->stats.time_ms);
        cJSON_AddNumberToObject(row, "thesis_vertices_generated", criteria[c].thesis_generated);
        cJSON *splits = cJSON_AddObjectToObject(row, "splits");
        cJSON_AddNumberToObject(splits, "rgb", (double)t.vt.splits_rgb);
        cJSON_AddNumberToObject(splits, "hsv", (double)t.vt.splits_hsv);
        cJSON_AddNumberToObject(splits, "tree", (double)t.vt.splits_tree);
        cJSON_AddNumberToObject(splits, "forced", (double)t.vt.splits_forced);
        cJSON_AddNumberToObject(row, "faces", (double)num_faces);
        cJSON_AddNumberToObject(row, "mesh_vertices", (double)num_verts);
        printf("%-9s %9llu %9llu %9.0f %8llu %8llu %8llu %7llu %8zu %10llu %9.1f  %6.3f %7.4f "
               "%6.2f  %6.3f %7.4f  %6.3f\n",
               criteria[c].name, (unsigned long long)t.vt.vertices_sampled,
               (unsigned long long)t.vt.vertices_generated, criteria[c].thesis_generated,
               (unsigned long long)t.vt.splits_rgb, (unsigned long long)t.vt.splits_hsv,
               (unsigned long long)t.vt.splits_tree, (unsigned long long)t.vt.splits_forced,
               num_faces, (unsigned long long)rays_total(&t.stats), t.stats.time_ms, q.vt_px.ssim,
               q.vt_px.rmse, q.vt_px.psnr, q.full.ssim, q.full.rmse, q.vt_own.ssim);
        fflush(stdout);
        note("criteria %s %s: %.1f ms, %llu vertices generated, SSIM %.3f (VT pixels)",
             criteria[c].name, tr.size, t.stats.time_ms, (unsigned long long)t.vt.vertices_generated,
             q.vt_px.ssim);
    }
    return table_end(&tr, st);
}

/* -------------------------------------------------------- resolution -- */

static bool count_update(void *user, const rl_image *image, uint32_t stage, bool final)
{
    (void)image;
    (void)stage;
    (void)final;
    ++*(int *)user;
    return true;
}

/* Fig. 5.10-5.12: default criteria at growing square resolutions. */
static rl_status sec_resolution(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const int full_sizes[] = { 512, 1024, 2048 }, quick_sizes[] = { 64, 128 };
    const int *sizes = b->a->quick ? quick_sizes : full_sizes;
    int num_sizes = b->a->quick ? 2 : 3;
    cJSON_AddStringToObject(sec, "scene", table_spec(b));
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    printf("\nresolution (Fig. 5.10-5.12): %s, default criteria; %% of Whitted's rays and "
           "of the pixels\n", table_spec(b));
    printf("%-9s %10s %10s %6s %9s %6s %6s  %6s %7s %9s %9s %6s %10s\n", "size", "VT rays",
           "Whitted", "rays%", "samples", "smpl%", "growth", "ssimVT", "rmseVT", "VT ms",
           "Whitted ms", "VT/W", "preview ms");
    rl_status st = RL_OK;
    double prev_samples = NAN;
    bool within_5 = true, sublinear = true;
    for (int i = 0; st == RL_OK && i < num_sizes; i++) {
        int n = sizes[i];
        ref_frame *ref = NULL;
        rl_renderer *r = NULL;
        rl_image *img = NULL;
        rl_camera cam = sized(&b->table_cam, n, n);
        timed_frame t;
        rl_vt_stats preview;
        quality q;
        int updates = 0;
        st = reference(b, n, n, b->threads, MODE_ALL, &ref);
        if (st == RL_OK)
            st = make_renderer("vt", b->threads, &r);
        if (st == RL_OK)
            st = rl_image_create(n, n, RL_LAYER_COLOR, &img);
        if (st == RL_OK)
            st = render_timed(r, b->table, &cam, img, b->runs, &t);
        if (st == RL_OK)
            st = compare(img, ref->image, ref->mask, ref->mask_pixels, &q);
        /* One more frame with an update callback, so that the preview of
         * Sec. 3.5.1 (the primary vertices only) is really drawn; its time
         * is not part of the timed frames. */
        if (st == RL_OK)
            st = rl_vt_set_update_callback(r, count_update, &updates);
        if (st == RL_OK)
            st = rl_renderer_render(r, b->table, &cam, img, NULL);
        if (st == RL_OK)
            st = rl_vt_get_stats(r, &preview);
        rl_image_release(img);
        rl_renderer_release(r);
        if (st != RL_OK)
            break;
        double pixels = (double)n * n;
        double vt_rays = (double)rays_total(&t.stats), wh_rays = (double)rays_total(&ref->stats);
        double samples = (double)t.vt.vertices_sampled;
        double growth = ratio(samples, prev_samples);
        double pixel_growth = i ? pixels / ((double)sizes[i - 1] * sizes[i - 1]) : NAN;
        within_5 = within_5 && samples <= 0.05 * pixels;
        if (i)
            sublinear = sublinear && growth < pixel_growth;
        prev_samples = samples;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        char size[32];
        snprintf(size, sizeof size, "%dx%d", n, n);
        cJSON_AddStringToObject(row, "size", size);
        cJSON_AddNumberToObject(row, "pixels", pixels);
        cJSON_AddItemToObject(row, "vt_rays", rays_json(&t.stats));
        cJSON_AddItemToObject(row, "whitted_rays", rays_json(&ref->stats));
        add_num(row, "rays_percent_of_whitted", 100.0 * ratio(vt_rays, wh_rays));
        cJSON_AddNumberToObject(row, "vertices_sampled", samples);
        add_num(row, "samples_percent_of_pixels", 100.0 * samples / pixels);
        add_num(row, "samples_growth", growth);
        add_num(row, "pixel_growth", pixel_growth);
        cJSON_AddItemToObject(row, "quality", quality_json(&q));
        add_num(row, "vt_time_ms", t.stats.time_ms);
        add_num(row, "whitted_time_ms", ref->stats.time_ms);
        add_num(row, "time_ratio_to_whitted", ratio(t.stats.time_ms, ref->stats.time_ms));
        add_num(row, "preview_ms", preview.time_preview_ms);
        cJSON_AddNumberToObject(row, "preview_updates", updates);
        cJSON_AddItemToObject(row, "vt_stats", vt_stats_json(&t.vt));
        printf("%-9s %10.0f %10.0f %6.2f %9.0f %6.2f %6.2f  %6.3f %7.4f %9.1f %9.1f %6.3f %10.1f\n",
               size, vt_rays, wh_rays, 100.0 * ratio(vt_rays, wh_rays), samples,
               100.0 * samples / pixels, growth, q.vt_px.ssim, q.vt_px.rmse, t.stats.time_ms,
               ref->stats.time_ms, ratio(t.stats.time_ms, ref->stats.time_ms),
               preview.time_preview_ms);
        fflush(stdout);
        note("resolution %s: %.1f ms (whitted %.1f ms), %.0f samples, preview %.1f ms", size,
             t.stats.time_ms, ref->stats.time_ms, samples, preview.time_preview_ms);
    }
    if (st == RL_OK) {
        cJSON_AddBoolToObject(sec, "samples_within_5_percent", within_5);
        cJSON_AddBoolToObject(sec, "samples_sublinear", sublinear);
        printf("samples <= 5%% of the pixels (thesis): %s; sub-linear growth: %s\n",
               within_5 ? "yes" : "no", sublinear ? "yes" : "no");
    }
    return st;
}

/* ----------------------------------------------------------- quality -- */

/* Whitted's time for ref once more, now: the quality section compares
 * against the faster of this and the reference's own time, so that a slow
 * moment of a shared machine at the section's start cannot flatter VT. */
static rl_status retime_reference(bvt *b, const ref_frame *ref, double *ms)
{
    rl_image *img = NULL;
    timed_frame t;
    rl_status st = rl_image_create(ref->width, ref->height, RL_LAYER_COLOR, &img);
    if (st == RL_OK)
        st = time_whitted(b, ref->threads, ref->mode, img, &t);
    rl_image_release(img);
    if (st == RL_OK)
        *ms = t.stats.time_ms;
    return st;
}

/* The min_edge sweep: how fast is VT at Whitted's quality? For the default
 * criteria and for HSV alone (the cheapest criterion of Fig. 5.5), min_edge
 * grows until two settings in a row miss the SSIM goal: a coarser mesh is
 * faster, so the fastest setting that meets the goal is the last one
 * before quality drops below it. Whitted is timed at the section's start
 * and end, and the faster time is the reference of every ratio. */
typedef struct quality_row {
    const char *criteria;
    double min_edge;
    timed_frame t;
    quality q;
} quality_row;

static rl_status sec_quality(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const char *const crits[] = { "tree+hsv", "hsv" };
    static const double min_edges[] = { 1, 2, 3, 4, 6, 8, 10, 12, 14, 16, 20, 24, 28, 32 };
    enum { NUM_CRITS = sizeof crits / sizeof crits[0], NUM_EDGES = sizeof min_edges / sizeof min_edges[0] };
    int w = b->a->width, h = b->a->height;
    ref_frame *ref = NULL;
    char size[32];
    rl_status st = table_section(b, sec, true, &ref, size);
    if (st != RL_OK)
        return st;
    add_num(sec, "ssim_goal", SSIM_GOAL);
    add_num(sec, "time_ratio_goal", TIME_RATIO_GOAL);

    quality_row rows[NUM_CRITS * NUM_EDGES];
    int n = 0;
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam = sized(&b->table_cam, w, h);
    st = make_renderer("vt", b->threads, &r);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
    for (int c = 0; st == RL_OK && c < NUM_CRITS; c++) {
        rl_clear_error();
        st = rl_renderer_set(r, "criteria", crits[c]);
        int misses = 0;
        for (int i = 0; st == RL_OK && misses < 2 && i < NUM_EDGES; i++) {
            quality_row *row = &rows[n];
            row->criteria = crits[c];
            row->min_edge = min_edges[i];
            rl_clear_error();
            st = set_int(r, "min_edge", min_edges[i]);
            if (st == RL_OK)
                st = render_timed(r, b->table, &cam, img, b->runs, &row->t);
            if (st == RL_OK)
                st = compare(img, ref->image, ref->mask, ref->mask_pixels, &row->q);
            if (st != RL_OK)
                break;
            misses = row->q.vt_px.ssim >= SSIM_GOAL ? 0 : misses + 1;
            n++;
            note("quality %s min_edge=%g %s: %.1f ms, SSIM %.3f (VT pixels)", crits[c],
                 min_edges[i], size, row->t.stats.time_ms, row->q.vt_px.ssim);
        }
    }
    rl_image_release(img);
    rl_renderer_release(r);
    double again = NAN;
    if (st == RL_OK)
        st = retime_reference(b, ref, &again);
    if (st != RL_OK)
        return st;
    double whitted_ms = again < ref->stats.time_ms ? again : ref->stats.time_ms;
    add_num(sec, "whitted_time_ms_end", again);
    add_num(sec, "whitted_time_ms", whitted_ms);

    printf("\nquality: min_edge sweep, %s %s, whitted %.1f ms (faster of %.1f at the start and "
           "%.1f at the end)\n", table_spec(b), size, whitted_ms, ref->stats.time_ms, again);
    printf("%-9s %-8s %9s %6s %9s %10s  %6s %7s  %6s\n", "criteria", "min_edge", "VT ms", "VT/W",
           "sampled", "rays", "ssimVT", "rmseVT", "ssim");
    cJSON *runs = cJSON_AddArrayToObject(sec, "runs");
    const quality_row *best = NULL;
    for (int i = 0; i < n; i++) {
        const quality_row *row = &rows[i];
        double ms = row->t.stats.time_ms;
        if (row->q.vt_px.ssim >= SSIM_GOAL && (!best || ms < best->t.stats.time_ms))
            best = row;
        cJSON *o = cJSON_CreateObject();
        cJSON_AddItemToArray(runs, o);
        cJSON_AddStringToObject(o, "criteria", row->criteria);
        cJSON_AddNumberToObject(o, "min_edge", row->min_edge);
        add_num(o, "time_ms", ms);
        add_num(o, "time_ratio_to_whitted", ratio(ms, whitted_ms));
        cJSON_AddNumberToObject(o, "vertices_sampled", (double)row->t.vt.vertices_sampled);
        cJSON_AddItemToObject(o, "rays", rays_json(&row->t.stats));
        cJSON_AddItemToObject(o, "quality", quality_json(&row->q));
        printf("%-9s %-8g %9.1f %6.3f %9llu %10llu  %6.3f %7.4f  %6.3f\n", row->criteria,
               row->min_edge, ms, ratio(ms, whitted_ms),
               (unsigned long long)row->t.vt.vertices_sampled,
               (unsigned long long)rays_total(&row->t.stats), row->q.vt_px.ssim, row->q.vt_px.rmse,
               row->q.full.ssim);
    }
    double best_ratio = best ? ratio(best->t.stats.time_ms, whitted_ms) : NAN;
    bool met = best && best_ratio <= TIME_RATIO_GOAL;
    if (best) {
        cJSON *o = cJSON_AddObjectToObject(sec, "best");
        cJSON_AddStringToObject(o, "criteria", best->criteria);
        cJSON_AddNumberToObject(o, "min_edge", best->min_edge);
        add_num(o, "time_ms", best->t.stats.time_ms);
        add_num(o, "ssim_vt_pixels", best->q.vt_px.ssim);
        add_num(o, "time_ratio_to_whitted", best_ratio);
        printf("fastest with SSIM >= %.2f: %s, min_edge=%g, %.1f ms = %.3f x Whitted: "
               "target <= %.1f %s\n", SSIM_GOAL, best->criteria, best->min_edge,
               best->t.stats.time_ms, best_ratio, TIME_RATIO_GOAL, met ? "met" : "not met");
    } else {
        cJSON_AddNullToObject(sec, "best");
        printf("no setting reached SSIM >= %.2f on the VT pixels: target not met\n", SSIM_GOAL);
    }
    cJSON_AddBoolToObject(sec, "met", met);
    return RL_OK;
}

/* ----------------------------------------------------------- threads -- */

/* Fig. 5.15 (and the time split of Fig. 5.9): 1, 2, 4, ... threads. */
static rl_status sec_threads(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    int counts[16], num = 0;
    for (int n = 1; n < b->max_threads && num < 15; n *= 2)
        counts[num++] = n;
    counts[num++] = b->max_threads;
    int w = b->a->width, h = b->a->height;
    char size[32];
    snprintf(size, sizeof size, "%dx%d", w, h);
    cJSON_AddStringToObject(sec, "scene", table_spec(b));
    cJSON_AddStringToObject(sec, "size", size);
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    printf("\nthreads (Fig. 5.9, 5.15): %s %s; VT time split in ms; imbalance = (max - min) / "
           "mean of the rays per thread\n", table_spec(b), size);
    printf("%-7s %9s %7s %10s %7s %9s  %8s %8s %8s %8s  %s\n", "threads", "VT ms", "speedup",
           "Whitted ms", "speedup", "imbalance", "visib.", "sampling", "refine", "draw",
           "rays per thread");
    rl_status st = RL_OK;
    double vt_one = NAN, wh_one = NAN;
    for (int i = 0; st == RL_OK && i < num; i++) {
        int n = counts[i];
        ref_frame *ref = NULL;
        rl_renderer *r = NULL;
        rl_image *img = NULL;
        rl_camera cam = sized(&b->table_cam, w, h);
        timed_frame t;
        st = reference(b, w, h, n, MODE_ALL, &ref);
        if (st == RL_OK)
            st = make_renderer("vt", n, &r);
        if (st == RL_OK)
            st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
        if (st == RL_OK)
            st = render_timed(r, b->table, &cam, img, b->runs, &t);
        rl_image_release(img);
        rl_renderer_release(r);
        if (st != RL_OK)
            break;
        if (i == 0) {
            vt_one = t.stats.time_ms;
            wh_one = ref->stats.time_ms;
        }
        uint32_t used = t.vt.threads < RL_VT_MAX_THREADS ? t.vt.threads : RL_VT_MAX_THREADS;
        double lo = INFINITY, hi = 0.0, sum = 0.0;
        for (uint32_t k = 0; k < used; k++) {
            double x = (double)t.vt.thread_rays[k];
            lo = x < lo ? x : lo;
            hi = x > hi ? x : hi;
            sum += x;
        }
        double imbalance = used && sum > 0.0 ? (hi - lo) / (sum / used) : NAN;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddNumberToObject(row, "threads", n);
        add_num(row, "vt_time_ms", t.stats.time_ms);
        add_num(row, "vt_speedup", ratio(vt_one, t.stats.time_ms));
        add_num(row, "whitted_time_ms", ref->stats.time_ms);
        add_num(row, "whitted_speedup", ratio(wh_one, ref->stats.time_ms));
        add_num(row, "time_ratio_to_whitted", ratio(t.stats.time_ms, ref->stats.time_ms));
        cJSON *rays = cJSON_AddArrayToObject(row, "thread_rays");
        cJSON *busy = cJSON_AddArrayToObject(row, "thread_busy_ms");
        for (uint32_t k = 0; k < used; k++) {
            cJSON_AddItemToArray(rays, cJSON_CreateNumber((double)t.vt.thread_rays[k]));
            cJSON_AddItemToArray(busy, cJSON_CreateNumber(t.vt.thread_busy_ms[k]));
        }
        add_num(row, "load_imbalance", imbalance);
        cJSON *split = cJSON_AddObjectToObject(row, "time_split_ms");
        add_num(split, "visibility", t.vt.time_visibility_ms);
        add_num(split, "sampling", t.vt.time_sampling_ms);
        add_num(split, "refine", t.vt.time_refine_ms);
        add_num(split, "draw", t.vt.time_draw_ms);
        add_num(split, "other", t.stats.time_ms - t.vt.time_visibility_ms - t.vt.time_sampling_ms
                                    - t.vt.time_refine_ms - t.vt.time_draw_ms);
        cJSON_AddItemToObject(row, "vt_rays", rays_json(&t.stats));
        printf("%-7d %9.1f %7.2f %10.1f %7.2f %9.3f  %8.1f %8.1f %8.1f %8.1f  ", n, t.stats.time_ms,
               ratio(vt_one, t.stats.time_ms), ref->stats.time_ms,
               ratio(wh_one, ref->stats.time_ms), imbalance, t.vt.time_visibility_ms,
               t.vt.time_sampling_ms, t.vt.time_refine_ms, t.vt.time_draw_ms);
        for (uint32_t k = 0; k < used && k < 8; k++)
            printf("%s%llu", k ? " " : "", (unsigned long long)t.vt.thread_rays[k]);
        printf("%s\n", used > 8 ? " ..." : "");
        fflush(stdout);
        note("threads %d %s: VT %.1f ms, whitted %.1f ms, imbalance %.3f", n, size,
             t.stats.time_ms, ref->stats.time_ms, imbalance);
    }
    return st;
}

/* -------------------------------------------------------- visibility -- */

/* Fig. 5.13: the visibility tests switched off one after the other. */
static rl_status sec_visibility(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const struct {
        const char *name, *id, *z, *clip;
    } configs[] = {
        { "ID+Z+C", "true", "true", "true" },
        { "ID+Z", "true", "true", "false" },
        { "ID", "true", "false", "false" },
        { "none", "false", "false", "false" },
    };
    table_run tr;
    rl_status st = table_begin(b, sec, false, true, &tr);
    if (st != RL_OK)
        return table_end(&tr, st);
    printf("\nvisibility tests (Fig. 5.13): %s %s, ID buffer, Z buffer, viewport clipping\n",
           table_spec(b), tr.size);
    printf("%-7s %9s %9s %9s %9s %9s %10s  %6s\n", "tests", "VT ms", "sampled", "vis.faces",
           "culled Z", "culled C", "rays", "ssimVT");
    for (size_t i = 0; st == RL_OK && i < sizeof configs / sizeof configs[0]; i++) {
        timed_frame t;
        quality q;
        rl_clear_error();
        st = rl_renderer_set(tr.r, "id_test", configs[i].id);
        if (st == RL_OK)
            st = rl_renderer_set(tr.r, "z_test", configs[i].z);
        if (st == RL_OK)
            st = rl_renderer_set(tr.r, "clip_test", configs[i].clip);
        if (st == RL_OK)
            st = render_timed(tr.r, b->table, &tr.cam, tr.img, b->runs, &t);
        if (st == RL_OK)
            st = compare(tr.img, tr.ref->image, tr.ref->mask, tr.ref->mask_pixels, &q);
        if (st != RL_OK)
            break;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(tr.rows, row);
        cJSON_AddStringToObject(row, "tests", configs[i].name);
        cJSON_AddBoolToObject(row, "id_test", configs[i].id[0] == 't');
        cJSON_AddBoolToObject(row, "z_test", configs[i].z[0] == 't');
        cJSON_AddBoolToObject(row, "clip_test", configs[i].clip[0] == 't');
        add_num(row, "time_ms", t.stats.time_ms);
        cJSON_AddNumberToObject(row, "vertices_sampled", (double)t.vt.vertices_sampled);
        cJSON_AddNumberToObject(row, "visible_primary_faces", (double)t.vt.visible_primary_faces);
        cJSON_AddNumberToObject(row, "edges_culled_z", (double)t.vt.edges_culled_z);
        cJSON_AddNumberToObject(row, "edges_culled_viewport", (double)t.vt.edges_culled_viewport);
        cJSON_AddItemToObject(row, "rays", rays_json(&t.stats));
        cJSON_AddItemToObject(row, "quality", quality_json(&q));
        printf("%-7s %9.1f %9llu %9llu %9llu %9llu %10llu  %6.3f\n", configs[i].name,
               t.stats.time_ms, (unsigned long long)t.vt.vertices_sampled,
               (unsigned long long)t.vt.visible_primary_faces,
               (unsigned long long)t.vt.edges_culled_z,
               (unsigned long long)t.vt.edges_culled_viewport,
               (unsigned long long)rays_total(&t.stats), q.vt_px.ssim);
        fflush(stdout);
        note("visibility %s %s: %.1f ms, %llu vertices sampled", configs[i].name, tr.size,
             t.stats.time_ms, (unsigned long long)t.vt.vertices_sampled);
    }
    return table_end(&tr, st);
}

/* ------------------------------------------------------------- modes -- */

/* Figs. 5.9/5.10: every shading mode, VT against Whitted in the same mode.
 * The thesis gives VT 6.8x (+S+R+T) to 86x (+S-R-T) Whitted's speed. */
static rl_status sec_modes(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const int modes[] = { MODE_ALL, MODE_S | MODE_R, MODE_S | MODE_T, MODE_S,
                                 MODE_R | MODE_T, MODE_R, MODE_T, 0 };
    int w = b->a->width, h = b->a->height;
    char size[32];
    snprintf(size, sizeof size, "%dx%d", w, h);
    cJSON_AddStringToObject(sec, "scene", table_spec(b));
    cJSON_AddStringToObject(sec, "size", size);
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam = sized(&b->table_cam, w, h);
    rl_status st = make_renderer("vt", b->threads, &r);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
    printf("\nshading modes (Fig. 5.9/5.10): %s %s, S shadow feelers, R reflection rays, T transmission "
           "rays\n", table_spec(b), size);
    printf("%-7s %9s %9s %7s %7s %7s %7s %7s %8s %8s  %6s %6s  %6s\n", "mode", "whitted", "VT ms", "vis",
           "sample", "refine", "draw", "x", "rays %", "samp %", "ssimVT", "thesis", "ownVT");
    for (size_t i = 0; st == RL_OK && i < sizeof modes / sizeof modes[0]; i++) {
        char name[8];
        mode_name(modes[i], name);
        ref_frame *ref = NULL;
        timed_frame t;
        quality q;
        rl_clear_error();
        st = reference(b, w, h, b->threads, modes[i], &ref);
        if (st == RL_OK)
            st = set_mode(r, modes[i]);
        if (st == RL_OK)
            st = render_timed(r, b->table, &cam, img, b->runs, &t);
        if (st == RL_OK)
            st = compare(img, ref->image, ref->mask, ref->mask_pixels, &q);
        if (st != RL_OK)
            break;
        double speedup = ratio(ref->stats.time_ms, t.stats.time_ms);
        double rays_pct = 100.0 * ratio((double)rays_total(&t.stats), (double)rays_total(&ref->stats));
        double samples_pct = 100.0 * (double)t.vt.vertices_sampled / ((double)w * h);
        double thesis = modes[i] == MODE_ALL ? 6.8 : modes[i] == MODE_S ? 86.0 : NAN;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "mode", name);
        cJSON_AddBoolToObject(row, "shadows", modes[i] & MODE_S);
        cJSON_AddBoolToObject(row, "reflections", modes[i] & MODE_R);
        cJSON_AddBoolToObject(row, "transmission", modes[i] & MODE_T);
        cJSON_AddItemToObject(row, "whitted", ref_json(ref));
        add_num(row, "time_ms", t.stats.time_ms);
        cJSON_AddItemToObject(row, "rays", rays_json(&t.stats));
        add_num(row, "whitted_over_vt_time", speedup);
        add_num(row, "rays_percent_of_whitted", rays_pct);
        add_num(row, "samples_percent_of_pixels", samples_pct);
        add_num(row, "thesis_whitted_over_vt_time", thesis);
        cJSON_AddItemToObject(row, "quality", quality_json(&q));
        cJSON_AddItemToObject(row, "vt_stats", vt_stats_json(&t.vt));
        printf("%-7s %9.1f %9.1f %7.1f %7.1f %7.1f %7.1f %7.2f %8.1f %8.2f  %6.3f %6s  %6.3f\n", name,
               ref->stats.time_ms, t.stats.time_ms, t.vt.time_visibility_ms, t.vt.time_sampling_ms,
               t.vt.time_refine_ms, t.vt.time_draw_ms, speedup, rays_pct, samples_pct, q.vt_px.ssim,
               isnan(thesis) ? "" : (modes[i] == MODE_ALL ? "6.8" : "86"), q.vt_own.ssim);
        fflush(stdout);
        note("mode %s %s: VT %.1f ms, whitted %.1f ms (%.2fx), SSIM %.3f (VT pixels)", name, size,
             t.stats.time_ms, ref->stats.time_ms, speedup, q.vt_px.ssim);
    }
    rl_image_release(img);
    rl_renderer_release(r);
    return st;
}

/* ------------------------------------------------------------ forced -- */

/* Fig. 5.3: forced refinement (Sec. 3.3.2) on and off. The thesis shows
 * the fork's shadow found completely with it and broken without it; here
 * at the default setting and at the coarse equal-quality one, where the
 * criteria alone leave more to forced refinement. */
static rl_status sec_forced(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const struct {
        const char *criteria;
        double min_edge;
    } settings[] = { { "tree+hsv", 1 }, { "hsv", 14 } };
    table_run tr;
    rl_status st = table_begin(b, sec, true, true, &tr);
    if (st != RL_OK)
        return table_end(&tr, st);
    printf("\nforced refinement (Fig. 5.3): %s %s, whitted %.1f ms\n", table_spec(b), tr.size,
           tr.ref->stats.time_ms);
    printf("%-9s %8s %6s %9s %9s %7s %10s %9s  %6s %7s\n", "criteria", "min_edge", "forced", "sampled",
           "generated", "splits", "rays", "VT ms", "ssimVT", "rmseVT");
    for (size_t i = 0; st == RL_OK && i < sizeof settings / sizeof settings[0]; i++) {
        for (int on = 1; st == RL_OK && on >= 0; on--) {
            timed_frame t;
            quality q;
            rl_clear_error();
            st = rl_renderer_set(tr.r, "criteria", settings[i].criteria);
            if (st == RL_OK)
                st = set_int(tr.r, "min_edge", settings[i].min_edge);
            if (st == RL_OK)
                st = rl_renderer_set(tr.r, "forced", on ? "true" : "false");
            if (st == RL_OK)
                st = render_timed(tr.r, b->table, &tr.cam, tr.img, b->runs, &t);
            if (st == RL_OK)
                st = compare(tr.img, tr.ref->image, tr.ref->mask, tr.ref->mask_pixels, &q);
            if (st != RL_OK)
                break;
            cJSON *row = cJSON_CreateObject();
            cJSON_AddItemToArray(tr.rows, row);
            cJSON_AddStringToObject(row, "criteria", settings[i].criteria);
            cJSON_AddNumberToObject(row, "min_edge", settings[i].min_edge);
            cJSON_AddBoolToObject(row, "forced", on);
            cJSON_AddNumberToObject(row, "splits_forced", (double)t.vt.splits_forced);
            add_run_fields(row, &t, &q, tr.ref->stats.time_ms);
            printf("%-9s %8g %6s %9llu %9llu %7llu %10llu %9.1f  %6.3f %7.4f\n", settings[i].criteria,
                   settings[i].min_edge, on ? "on" : "off", (unsigned long long)t.vt.vertices_sampled,
                   (unsigned long long)t.vt.vertices_generated, (unsigned long long)t.vt.splits_forced,
                   (unsigned long long)rays_total(&t.stats), t.stats.time_ms, q.vt_px.ssim, q.vt_px.rmse);
            fflush(stdout);
            note("forced %s %s/%g %s: %.1f ms, %llu vertices generated, SSIM %.3f (VT pixels)",
                 on ? "on" : "off", settings[i].criteria, settings[i].min_edge, tr.size, t.stats.time_ms,
                 (unsigned long long)t.vt.vertices_generated, q.vt_px.ssim);
        }
    }
    return table_end(&tr, st);
}

/* ----------------------------------------------------------- preview -- */

/* Stops the refinement at the preview (stage 0). */
static bool stop_at_preview(void *user, const rl_image *image, uint32_t stage, bool final)
{
    (void)user;
    (void)image;
    (void)final;
    return stage > 0;
}

/* Fig. 5.12b: the preview (Sec. 3.5.1, the primary vertices sampled and
 * drawn) alone, by phase, against the resolution. The thesis' preview
 * takes nearly constant time: its rasterization runs on graphics hardware
 * and only the read-back of the ID and Z buffers grows with the pixels. */
static rl_status sec_preview(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const int full_sizes[] = { 512, 1024, 2048 }, quick_sizes[] = { 64, 128 };
    const int *sizes = b->a->quick ? quick_sizes : full_sizes;
    int num_sizes = b->a->quick ? 2 : 3;
    cJSON_AddStringToObject(sec, "scene", table_spec(b));
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    printf("\npreview (Fig. 5.12b): %s, refinement stopped after the primary vertices; ms by phase\n",
           table_spec(b));
    printf("%-9s %9s %9s %9s %9s %9s %9s %9s\n", "size", "preview", "frame", "visib.", "sampling",
           "draw", "other", "sampled");
    rl_status st = RL_OK;
    for (int i = 0; st == RL_OK && i < num_sizes; i++) {
        int n = sizes[i];
        rl_renderer *r = NULL;
        rl_image *img = NULL;
        rl_camera cam = sized(&b->table_cam, n, n);
        timed_frame t;
        st = make_renderer("vt", b->threads, &r);
        if (st == RL_OK)
            st = rl_vt_set_update_callback(r, stop_at_preview, NULL);
        if (st == RL_OK)
            st = rl_image_create(n, n, RL_LAYER_COLOR, &img);
        if (st == RL_OK)
            st = render_timed(r, b->table, &cam, img, b->runs, &t);
        rl_image_release(img);
        rl_renderer_release(r);
        if (st != RL_OK)
            break;
        double other = t.stats.time_ms - t.vt.time_visibility_ms - t.vt.time_sampling_ms -
                       t.vt.time_refine_ms - t.vt.time_draw_ms;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        char size[32];
        snprintf(size, sizeof size, "%dx%d", n, n);
        cJSON_AddStringToObject(row, "size", size);
        cJSON_AddNumberToObject(row, "pixels", (double)n * n);
        add_num(row, "preview_ms", t.vt.time_preview_ms);
        add_num(row, "frame_ms", t.stats.time_ms);
        cJSON *split = cJSON_AddObjectToObject(row, "time_split_ms");
        add_num(split, "visibility", t.vt.time_visibility_ms);
        add_num(split, "sampling", t.vt.time_sampling_ms);
        add_num(split, "refine", t.vt.time_refine_ms);
        add_num(split, "draw", t.vt.time_draw_ms);
        add_num(split, "other", other);
        cJSON_AddItemToObject(row, "vt_stats", vt_stats_json(&t.vt));
        printf("%-9s %9.1f %9.1f %9.1f %9.1f %9.1f %9.1f %9llu\n", size, t.vt.time_preview_ms,
               t.stats.time_ms, t.vt.time_visibility_ms, t.vt.time_sampling_ms, t.vt.time_draw_ms, other,
               (unsigned long long)t.vt.vertices_sampled);
        fflush(stdout);
        note("preview %s: %.1f ms (visibility %.1f, sampling %.1f, draw %.1f)", size, t.vt.time_preview_ms,
             t.vt.time_visibility_ms, t.vt.time_sampling_ms, t.vt.time_draw_ms);
    }
    return st;
}

/* ------------------------------------------------------- correctness -- */

/* Ullmann 2003, Sec. 6.1: the options against the misses of Fig. 6.1 and
 * 6.5, in the order of the record's rows. */
static const struct {
    const char *name, *key, *value;
} correctness_runs[] = {
    { "off", NULL, NULL },
    { "nonlinear=extremum", "nonlinear", "extremum" },
    { "nonlinear=interval", "nonlinear", "interval" },
    { "nonlinear=derivative", "nonlinear", "derivative" },
    { "nonlinear=affine", "nonlinear", "affine" },
    { "shaft_cull=shadow", "shaft_cull", "shadow" },
    { "shaft_cull=all", "shaft_cull", "all" },
};

/* A 4 x 4 m floor of one quad (two triangles; the VT object) under a
 * directional light, seen from (0, 4, 3). highlight: k_d 0.3, k_s 1 at
 * n 200, and the light mirrors into the eye at (0.8, 0, 0.6), about a
 * metre from every vertex (Fig. 6.1). Else: a diffuse floor and a small
 * box (not VT) over it whose shadow falls around (0.3, 0, 0.6), inside a
 * face where no corner's feeler meets the box (Fig. 6.5a). */
static rl_status miss_scene(bool highlight, rl_scene **out)
{
    rl_scene *s = NULL;
    rl_status st = rl_scene_create(&s);
    rl_material m = rl_material_default();
    snprintf(m.name, sizeof m.name, "floor");
    m.diffuse = highlight ? rl_v3(0.3f, 0.3f, 0.3f) : rl_v3(0.7f, 0.7f, 0.7f);
    if (highlight) {
        m.specular = rl_v3(1.0f, 1.0f, 1.0f);
        m.shininess = 200.0f;
    }
    uint32_t mat = 0, mesh = 0, node = 0;
    if (st == RL_OK)
        st = rl_scene_add_material(s, &m, &mat);
    const rl_vec3 pos[4] = { { -2.0f, 0.0f, -2.0f }, { 2.0f, 0.0f, -2.0f }, { -2.0f, 0.0f, 2.0f }, { 2.0f, 0.0f, 2.0f } };
    const rl_vec2 uv[4] = { { 0.0f, 0.0f }, { 1.0f, 0.0f }, { 0.0f, 1.0f }, { 1.0f, 1.0f } };
    const uint32_t idx[6] = { 0, 2, 1, 1, 2, 3 };
    rl_mesh_desc md = { .name = "floor", .num_vertices = 4, .positions = pos, .uvs = uv, .num_triangles = 2,
                        .indices = idx, .material = mat };
    if (st == RL_OK)
        st = rl_scene_add_mesh(s, &md, &mesh);
    if (st == RL_OK)
        st = rl_scene_add_node(s, RL_NODE_ROOT, "floor", NULL, &node);
    if (st == RL_OK)
        st = rl_scene_node_set_mesh(s, node, mesh);
    if (st == RL_OK)
        st = rl_scene_node_set_attr(s, node, "vt", "true");
    rl_light l = { .type = RL_LIGHT_DIRECTIONAL, .color = rl_v3(1.0f, 1.0f, 1.0f), .intensity = 1.0f };
    if (highlight) {
        rl_vec3 a = rl_normalize(rl_sub(rl_v3(0.0f, 4.0f, 3.0f), rl_v3(0.8f, 0.0f, 0.6f)));
        l.direction = rl_v3(a.x, -a.y, a.z);    /* the view direction there, mirrored */
    } else {
        l.direction = rl_v3(-0.5f, -1.0f, 0.0f);
        rl_mat4 at = rl_mat4_translate(rl_v3(0.8f, 1.0f, 0.6f));
        m.specular = rl_v3(0.0f, 0.0f, 0.0f);
        snprintf(m.name, sizeof m.name, "box");
        if (st == RL_OK)
            st = rl_scene_add_material(s, &m, &mat);
        if (st == RL_OK)
            st = rl_scene_add_generated(s, "box", "size=0.3", mat, &mesh);
        if (st == RL_OK)
            st = rl_scene_add_node(s, RL_NODE_ROOT, "box", &at, &node);
        if (st == RL_OK)
            st = rl_scene_node_set_mesh(s, node, mesh);
    }
    if (st == RL_OK)
        st = rl_scene_add_light(s, &l);
    if (st == RL_OK)
        st = rl_scene_commit(s);
    if (st != RL_OK) {
        rl_scene_release(s);
        s = NULL;
    }
    *out = s;
    return st;
}

/* The settings the table is measured at: the defaults (full convergence)
 * and the equal-quality setting of the quality section, whose long edges
 * leave more room between samples for a miss. */
static const struct {
    const char *name, *criteria, *min_edge;
} correctness_settings[] = {
    { "tree+hsv/1", "tree+hsv", "1" },
    { "hsv/14", "hsv", "14" },
};

/* One configuration of correctness_runs on scene at setting k of
 * correctness_settings: the row of the record and of the table. */
static rl_status correctness_row(bvt *b, const char *label, const rl_scene *scene, const rl_camera *cam,
                                 const rl_image *ref, const uint8_t *mask, uint64_t mask_pixels, double ref_ms,
                                 size_t k, size_t i, rl_image *img, cJSON *rows)
{
    rl_renderer *r = NULL;
    timed_frame t;
    quality q;
    rl_status st = make_renderer("vt", b->threads, &r);
    if (st == RL_OK)
        st = rl_renderer_set(r, "criteria", correctness_settings[k].criteria);
    if (st == RL_OK)
        st = rl_renderer_set(r, "min_edge", correctness_settings[k].min_edge);
    if (st == RL_OK && correctness_runs[i].key)
        st = rl_renderer_set(r, correctness_runs[i].key, correctness_runs[i].value);
    if (st == RL_OK)
        st = render_timed(r, scene, cam, img, b->runs, &t);
    rl_renderer_release(r);
    if (st == RL_OK)
        st = compare(img, ref, mask, mask_pixels, &q);
    if (st != RL_OK)
        return st;
    cJSON *row = cJSON_CreateObject();
    cJSON_AddItemToArray(rows, row);
    cJSON_AddStringToObject(row, "scene", label);
    cJSON_AddStringToObject(row, "setting", correctness_settings[k].name);
    cJSON_AddStringToObject(row, "option", correctness_runs[i].name);
    cJSON_AddNumberToObject(row, "splits_nonlinear", (double)t.vt.splits_nonlinear);
    cJSON_AddNumberToObject(row, "splits_shaft", (double)t.vt.splits_shaft);
    add_num(row, "time_refine_ms", t.vt.time_refine_ms);
    add_run_fields(row, &t, &q, ref_ms);
    printf("%-9s %-10s %-20s %9llu %9llu %8llu %8llu %10llu %9.1f %8.1f %6.3f  %6.3f %7.4f\n", label,
           correctness_settings[k].name, correctness_runs[i].name, (unsigned long long)t.vt.vertices_sampled,
           (unsigned long long)t.vt.vertices_generated, (unsigned long long)t.vt.splits_nonlinear,
           (unsigned long long)t.vt.splits_shaft, (unsigned long long)rays_total(&t.stats), t.stats.time_ms,
           t.vt.time_refine_ms, ratio(t.stats.time_ms, ref_ms), q.vt_px.ssim, q.vt_px.rmse);
    fflush(stdout);
    note("correctness %s %s %s: %llu generated, %.1f ms, SSIM %.3f RMSE %.4f (VT pixels)", label,
         correctness_settings[k].name, correctness_runs[i].name, (unsigned long long)t.vt.vertices_generated, t.stats.time_ms, q.vt_px.ssim,
         q.vt_px.rmse);
    return RL_OK;
}

/* Sec. 6.1: each option against off, on the table at --size at both
 * correctness_settings and on the two miss scenes at the defaults at
 * 256 x 256 (64 x 64 with --quick). */
static rl_status sec_correctness(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    int w = b->a->width, h = b->a->height;
    ref_frame *ref = NULL;
    char size[32];
    rl_status st = table_section(b, sec, true, &ref, size);
    if (st != RL_OK)
        return st;
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    const size_t n = sizeof correctness_runs / sizeof correctness_runs[0];
    rl_camera cam = sized(&b->table_cam, w, h);
    rl_image *img = NULL;
    st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
    printf("\ncorrectness (Sec. 6.1): %s %s, whitted %.1f ms; miss scenes %s\n", table_spec(b), size,
           ref->stats.time_ms, b->a->quick ? "64x64" : "256x256");
    printf("%-9s %-10s %-20s %9s %9s %8s %8s %10s %9s %8s %6s  %6s %7s\n", "scene", "setting", "option",
           "sampled", "generated", "nonlin", "shaft", "rays", "VT ms", "refine", "xWhit", "ssimVT", "rmseVT");
    for (size_t k = 0; k < sizeof correctness_settings / sizeof correctness_settings[0]; k++)
        for (size_t i = 0; st == RL_OK && i < n; i++)
            st = correctness_row(b, "table", b->table, &cam, ref->image, ref->mask, ref->mask_pixels,
                                 ref->stats.time_ms, k, i, img, rows);
    rl_image_release(img);
    img = NULL;

    int ms = b->a->quick ? 64 : 256;
    for (int k = 0; st == RL_OK && k < 2; k++) {
        rl_scene *s = NULL;
        rl_image *wimg = NULL;
        uint8_t *mask = NULL, *vt = NULL;
        timed_frame wt;
        rl_camera mc = { .eye = rl_v3(0.0f, 4.0f, 3.0f), .target = rl_v3(0.0f, 0.0f, 0.0f),
                         .up = rl_v3(0.0f, 1.0f, 0.0f), .fov_deg = 45.0f, .width = ms, .height = ms };
        const char *label = k == 0 ? "highlight" : "shadow";
        st = miss_scene(k == 0, &s);
        if (st == RL_OK)
            st = rl_image_create(ms, ms, RL_LAYER_COLOR | RL_LAYER_ID, &wimg);
        if (st == RL_OK)
            st = rl_image_create(ms, ms, RL_LAYER_COLOR, &img);
        rl_renderer *r = NULL;
        if (st == RL_OK)
            st = make_renderer("whitted", b->threads, &r);
        if (st == RL_OK)
            st = render_timed(r, s, &mc, wimg, b->runs, &wt);
        rl_renderer_release(r);
        if (st == RL_OK && (!(mask = malloc((size_t)ms * (size_t)ms)) || !(vt = vt_objects(s))))
            st = RL_ERR_OUT_OF_MEMORY;
        uint64_t mask_pixels = st == RL_OK ? fill_mask(wimg, vt, rl_scene_get_data(s)->num_objects, mask) : 0;
        if (st == RL_OK) {
            cJSON *wr = cJSON_CreateObject();
            cJSON_AddStringToObject(wr, "scene", label);
            cJSON_AddStringToObject(wr, "option", "whitted");
            add_num(wr, "time_ms", wt.stats.time_ms);
            cJSON_AddItemToObject(wr, "rays", rays_json(&wt.stats));
            cJSON_AddNumberToObject(wr, "vt_pixels", (double)mask_pixels);
            cJSON_AddItemToArray(rows, wr);
        }
        for (size_t i = 0; st == RL_OK && i < n; i++)
            st = correctness_row(b, label, s, &mc, wimg, mask, mask_pixels, wt.stats.time_ms, 0, i, img, rows);
        free(mask);
        free(vt);
        rl_image_release(img);
        img = NULL;
        rl_image_release(wimg);
        rl_scene_release(s);
    }
    return st;
}

/* ------------------------------------------------------- reconstruct -- */

/* Ullmann 2003, Sec. 3.5 on OpenGL: the same frame (the refinement is the
 * CPU's either way) drawn by the rasterizer and by GL, per texture mode.
 * draw is vt's time_draw_ms: the rasterized half, the final draw of the
 * refined mesh and, on GL, the uploads and read-backs of its frames. */
static rl_status sec_reconstruct(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const char *const modes[] = { "multitexture", "multipass", "sampled" };
    int w = b->a->width, h = b->a->height;
    char size[32], why[512];
    snprintf(size, sizeof size, "%dx%d", w, h);
    cJSON_AddStringToObject(sec, "scene", table_spec(b));
    cJSON_AddStringToObject(sec, "size", size);
    rl_gl_info info;
    bool ok = rl_gl_available(NULL, why, sizeof why);
    if (ok && rl_gl_info_get(NULL, &info) != RL_OK) {
        ok = false;
        snprintf(why, sizeof why, "%s", rl_last_error());
    }
    printf("\nreconstruction (Sec. 3.5) on the CPU and on OpenGL: %s %s\n", table_spec(b), size);
    if (!ok) {
        printf("OpenGL unavailable: %s\n", why);
        cJSON_AddStringToObject(sec, "gl_unavailable", why);
        return RL_OK;
    }
    cJSON *g = cJSON_AddObjectToObject(sec, "gl");
    cJSON_AddStringToObject(g, "vendor", info.vendor);
    cJSON_AddStringToObject(g, "renderer", info.renderer);
    cJSON_AddStringToObject(g, "version", info.version);
    cJSON_AddStringToObject(g, "device", info.device);
    printf("GL: %s | %s | %s\n", info.vendor, info.renderer, info.version);
    printf("%-13s %12s %12s %12s %12s %8s %8s\n", "textures", "draw sw ms", "draw gl ms", "frame sw", "frame gl",
           "sw/gl", "SSIM");
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    rl_camera cam = sized(&b->table_cam, w, h);
    rl_status st = RL_OK;
    for (int m = 0; st == RL_OK && m < 3; ++m) {
        timed_frame t[2];
        rl_image *img[2] = { NULL, NULL };
        for (int k = 0; st == RL_OK && k < 2; ++k) {
            rl_renderer *r = NULL;
            st = make_renderer("vt", b->threads, &r);
            if (st == RL_OK)
                st = rl_renderer_set(r, "textures", modes[m]);
            if (st == RL_OK)
                st = rl_renderer_set(r, "reconstruct", k ? "gl" : "software");
            if (st == RL_OK)
                st = rl_image_create(w, h, RL_LAYER_COLOR, &img[k]);
            if (st == RL_OK)
                st = render_timed(r, b->table, &cam, img[k], b->runs, &t[k]);
            rl_renderer_release(r);
        }
        rl_image_metrics q;
        if (st == RL_OK)
            st = rl_image_compare(img[1], img[0], NULL, &q);
        rl_image_release(img[0]);
        rl_image_release(img[1]);
        if (st != RL_OK)
            break;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "textures", modes[m]);
        add_num(row, "software_draw_ms", t[0].vt.time_draw_ms);
        add_num(row, "gl_draw_ms", t[1].vt.time_draw_ms);
        add_num(row, "software_frame_ms", t[0].stats.time_ms);
        add_num(row, "gl_frame_ms", t[1].stats.time_ms);
        add_num(row, "software_over_gl_draw", ratio(t[0].vt.time_draw_ms, t[1].vt.time_draw_ms));
        cJSON_AddNumberToObject(row, "faces_drawn", (double)t[0].vt.faces_drawn);
        cJSON_AddItemToObject(row, "gl_vs_software", metrics_json(&q));
        printf("%-13s %12.1f %12.1f %12.1f %12.1f %8.2f %8.5f\n", modes[m], t[0].vt.time_draw_ms,
               t[1].vt.time_draw_ms, t[0].stats.time_ms, t[1].stats.time_ms,
               ratio(t[0].vt.time_draw_ms, t[1].vt.time_draw_ms), q.ssim);
        fflush(stdout);
        note("reconstruct %s %s: draw %.1f ms software, %.1f ms GL, SSIM %.5f", modes[m], size,
             t[0].vt.time_draw_ms, t[1].vt.time_draw_ms, q.ssim);
    }
    return st;
}

/* --------------------------------------------------------- reduction -- */

/* Ullmann Sec. 6.2.1, sample reduction: the ends of a primary edge shorter
 * than merge_px share one sample. The thesis expects the gain at the
 * preview of scenes with high depth complexity; the full frame shows what
 * is left of it once refinement adds its vertices. */
static rl_status sec_reduction(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const double merges[] = { 0.0, 0.5, 1.0, 2.0 };
    table_run tr;
    rl_status st = table_begin(b, sec, true, false, &tr);
    if (st != RL_OK)
        return table_end(&tr, st);
    printf("\nsample reduction (Sec. 6.2.1): %s %s, whitted %.1f ms\n", table_spec(b), tr.size, tr.ref->stats.time_ms);
    printf("%-8s %-8s %9s %9s %9s %9s  %6s %7s\n", "merge_px", "frame", "sampled", "merged", "VT ms", "preview",
           "ssimVT", "rmseVT");
    for (size_t i = 0; st == RL_OK && i < sizeof merges / sizeof merges[0]; i++) {
        for (int preview = 1; st == RL_OK && preview >= 0; preview--) {
            rl_renderer *r = NULL;
            timed_frame t;
            quality q;
            st = make_renderer("vt", b->threads, &r);
            if (st == RL_OK)
                st = set_int(r, "merge_px", merges[i]);
            if (st == RL_OK && preview)
                st = rl_vt_set_update_callback(r, stop_at_preview, NULL);
            if (st == RL_OK)
                st = render_timed(r, b->table, &tr.cam, tr.img, b->runs, &t);
            rl_renderer_release(r);
            if (st == RL_OK)
                st = compare(tr.img, tr.ref->image, tr.ref->mask, tr.ref->mask_pixels, &q);
            if (st != RL_OK)
                break;
            cJSON *row = cJSON_CreateObject();
            cJSON_AddItemToArray(tr.rows, row);
            cJSON_AddNumberToObject(row, "merge_px", merges[i]);
            cJSON_AddStringToObject(row, "frame", preview ? "preview" : "full");
            cJSON_AddNumberToObject(row, "vertices_merged", (double)t.vt.vertices_merged);
            add_num(row, "preview_ms", t.vt.time_preview_ms);
            add_run_fields(row, &t, &q, tr.ref->stats.time_ms);
            printf("%-8g %-8s %9llu %9llu %9.1f %9.1f  %6.3f %7.4f\n", merges[i], preview ? "preview" : "full",
                   (unsigned long long)t.vt.vertices_sampled, (unsigned long long)t.vt.vertices_merged,
                   t.stats.time_ms, t.vt.time_preview_ms, q.vt_px.ssim, q.vt_px.rmse);
            fflush(stdout);
            note("merge_px %g %s %s: %llu sampled, %llu merged, %.1f ms, SSIM %.3f (VT pixels)", merges[i],
                 preview ? "preview" : "full", tr.size, (unsigned long long)t.vt.vertices_sampled,
                 (unsigned long long)t.vt.vertices_merged, t.stats.time_ms, q.vt_px.ssim);
        }
    }
    return table_end(&tr, st);
}

/* -------------------------------------------------------------- hint -- */

static double cpu_ms(void)
{
    struct timespec t;
    return clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) == 0 ? 1e3 * (double)t.tv_sec + 1e-6 * (double)t.tv_nsec
                                                             : NAN;
}

/* One configuration of the hint section: its renderer, last image and the
 * least times over the rounds. */
typedef struct hint_run {
    const char *hint, *presort;
    rl_renderer *r;
    rl_image *img;
    double cpu_ms, wall_ms, sampling_ms, refine_ms, preview_ms;
    rl_render_stats stats;
    rl_vt_stats vt;
} hint_run;

/* Ullmann Sec. 6.2.2, efficient collision detection: intersection hints
 * from the parents' ray trees (Sec. 3.3.1) and ray presorting, each on and
 * off. Exact, so every configuration must give the off image bit for bit;
 * what changes is the work. One thread: the CPU time of the process is
 * then the frame's, and the configurations take turns round by round, so
 * that a load change on the shared machine hits them all alike; the least
 * of each is kept. */
static rl_status hint_scene(bvt *b, cJSON *rows, const char *name, const rl_scene *scene, const rl_camera *cam0)
{
    static const struct {
        const char *hint, *presort;
    } cfg[] = { { "off", "false" }, { "agree", "false" }, { "parents", "false" }, { "off", "true" },
                { "parents", "true" } };
    enum { N = sizeof cfg / sizeof cfg[0] };
    const int rounds = b->runs > 1 ? 3 : 1;
    /* --quick (ctest): off against both on, enough to check the record */
    const int n = b->a->quick ? 2 : N;
    const int pick[N] = { 0, b->a->quick ? N - 1 : 1, 2, 3, 4 };
    int w = b->a->width, h = b->a->height;
    rl_camera cam = sized(cam0, w, h);
    hint_run x[N];
    memset(x, 0, sizeof x);
    rl_status st = RL_OK;
    for (int i = 0; st == RL_OK && i < n; i++) {
        x[i].hint = cfg[pick[i]].hint;
        x[i].presort = cfg[pick[i]].presort;
        x[i].cpu_ms = x[i].wall_ms = x[i].sampling_ms = x[i].refine_ms = x[i].preview_ms = INFINITY;
        st = make_renderer("vt", 1, &x[i].r);
        if (st == RL_OK)
            st = rl_renderer_set(x[i].r, "hint", x[i].hint);
        if (st == RL_OK)
            st = rl_renderer_set(x[i].r, "presort", x[i].presort);
        if (st == RL_OK)
            st = rl_image_create(w, h, RL_LAYER_COLOR, &x[i].img);
        if (st == RL_OK)   /* warm-up: accelerator and VT meshes */
            st = rl_renderer_render(x[i].r, scene, &cam, x[i].img, NULL);
    }
    for (int k = 0; st == RL_OK && k < rounds; k++) {
        for (int j = 0; st == RL_OK && j < n; j++) {
            hint_run *c = &x[(j + k) % n];   /* a different one first each round */
            rl_render_stats stats;
            double c0 = cpu_ms();
            st = rl_renderer_render(c->r, scene, &cam, c->img, &stats);
            double cpu = cpu_ms() - c0;
            rl_vt_stats vt;
            if (st == RL_OK)
                st = rl_vt_get_stats(c->r, &vt);
            if (st != RL_OK)
                break;
            c->cpu_ms = fmin(c->cpu_ms, cpu);
            c->sampling_ms = fmin(c->sampling_ms, vt.time_sampling_ms);
            c->refine_ms = fmin(c->refine_ms, vt.time_refine_ms);
            c->preview_ms = fmin(c->preview_ms, vt.time_preview_ms);
            if (stats.time_ms < c->wall_ms) {
                c->wall_ms = stats.time_ms;
                c->stats = stats;
                c->vt = vt;
            }
        }
    }
    char size[32];
    snprintf(size, sizeof size, "%dx%d", w, h);
    if (st == RL_OK) {
        printf("\nintersection hints and presorting (Sec. 6.2.2): %s %s, 1 thread, least of %d interleaved\n",
               name, size, rounds);
        printf("%-8s %-7s %10s %10s %10s %9s %8s %9s %9s %8s %s\n", "hint", "presort", "rays", "hint tests",
               "hint hits", "CPU ms", "/off", "sample ms", "refine ms", "wall ms", "image");
    }
    size_t pixels = (size_t)w * (size_t)h;
    for (int i = 0; st == RL_OK && i < n; i++) {
        bool same = memcmp(x[i].img->color, x[0].img->color, pixels * sizeof *x[0].img->color) == 0;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "scene", name);
        cJSON_AddStringToObject(row, "size", size);
        cJSON_AddStringToObject(row, "hint", x[i].hint);
        cJSON_AddBoolToObject(row, "presort", strcmp(x[i].presort, "true") == 0);
        cJSON_AddBoolToObject(row, "image_identical_to_off", same);
        cJSON_AddItemToObject(row, "rays", rays_json(&x[i].stats));
        cJSON_AddNumberToObject(row, "hint_tests", (double)x[i].vt.hint_tests);
        cJSON_AddNumberToObject(row, "hint_hits", (double)x[i].vt.hint_hits);
        add_num(row, "min_cpu_ms", x[i].cpu_ms);
        add_num(row, "cpu_ratio_to_off", ratio(x[i].cpu_ms, x[0].cpu_ms));
        add_num(row, "min_wall_ms", x[i].wall_ms);
        add_num(row, "min_sampling_ms", x[i].sampling_ms);
        add_num(row, "min_refine_ms", x[i].refine_ms);
        add_num(row, "min_preview_ms", x[i].preview_ms);
        cJSON_AddItemToObject(row, "vt_stats", vt_stats_json(&x[i].vt));
        printf("%-8s %-7s %10llu %10llu %10llu %9.1f %8.3f %9.1f %9.1f %8.1f %s\n", x[i].hint, x[i].presort,
               (unsigned long long)rays_total(&x[i].stats), (unsigned long long)x[i].vt.hint_tests,
               (unsigned long long)x[i].vt.hint_hits, x[i].cpu_ms, ratio(x[i].cpu_ms, x[0].cpu_ms),
               x[i].sampling_ms, x[i].refine_ms, x[i].wall_ms, same ? "same" : "DIFFERS");
        fflush(stdout);
        note("hint %s presort %s %s %s: %.1f ms CPU (%.3f of off), %llu hint hits of %llu tests", x[i].hint,
             x[i].presort, name, size, x[i].cpu_ms, ratio(x[i].cpu_ms, x[0].cpu_ms),
             (unsigned long long)x[i].vt.hint_hits, (unsigned long long)x[i].vt.hint_tests);
        if (!same)
            st = bench_error(b, RL_ERR_INTERNAL, "hint %s presort %s changed the image of %s", x[i].hint,
                             x[i].presort, name);
    }
    for (int i = 0; i < N; i++) {
        rl_renderer_release(x[i].r);
        rl_image_release(x[i].img);
    }
    return st;
}

static rl_status sec_hint(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    cJSON_AddStringToObject(sec, "note", "one thread; CPU time of the process per frame, least of the rounds, "
                                         "configurations interleaved; the machine may be shared, so ratios "
                                         "within a scene are what to compare");
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    rl_status st = hint_scene(b, rows, table_spec(b), b->table, &b->table_cam);
    rl_camera cam;
    if (st == RL_OK && !b->a->quick)
        st = rl_scene_get_camera(b->cluster, NULL, &cam);
    if (st == RL_OK && !b->a->quick)
        st = hint_scene(b, rows, "cluster", b->cluster, &cam);
    return st;
}

/* ---------------------------------------------------------- overdraw -- */

#define OD_STAGES 12

/* The intermediate images of one progressive run, stage by stage. */
typedef struct stage_grab {
    rl_image *img[OD_STAGES];
    uint32_t stage[OD_STAGES];
    int n;
    bool failed;
} stage_grab;

static bool grab_stage(void *user, const rl_image *image, uint32_t stage, bool final)
{
    stage_grab *g = user;
    if (final || g->n >= OD_STAGES)
        return true;
    if (!g->img[g->n] && rl_image_create(image->width, image->height, RL_LAYER_COLOR, &g->img[g->n]) != RL_OK) {
        g->failed = true;
        return false;
    }
    memcpy(g->img[g->n]->color, image->color, (size_t)image->width * (size_t)image->height * sizeof *image->color);
    g->stage[g->n++] = stage;
    return true;
}

static void grab_free(stage_grab *g)
{
    for (int i = 0; i < OD_STAGES; i++)
        rl_image_release(g->img[i]);
    memset(g, 0, sizeof *g);
}

/* One progressive run (redraw or overdraw with f) into g; the final image
 * into img. */
static rl_status progressive_run(bvt *b, const rl_camera *cam, const char *mode, double f, rl_image *img,
                                 stage_grab *g)
{
    rl_renderer *r = NULL;
    rl_status st = make_renderer("vt", b->threads, &r);
    if (st == RL_OK)
        st = rl_renderer_set(r, "progressive", mode);
    if (st == RL_OK)
        st = set_int(r, "overdraw_f", f);
    if (st == RL_OK)
        st = rl_vt_set_update_callback(r, grab_stage, g);
    if (st == RL_OK) {
        g->n = 0;
        rl_render_stats stats;
        st = rl_renderer_render(r, b->table, cam, img, &stats);
    }
    if (st == RL_OK && g->failed)
        st = bench_error(b, RL_ERR_OUT_OF_MEMORY, "out of memory for the stage images");
    rl_renderer_release(r);
    return st;
}

/* Share of the masked pixels (all without a mask) where a channel differs
 * by more than one 8-bit step. */
static double differing(const rl_image *a, const rl_image *b, const uint8_t *mask)
{
    size_t n = (size_t)a->width * (size_t)a->height, count = 0, diff = 0;
    for (size_t i = 0; i < n; i++) {
        if (mask && !mask[i])
            continue;
        count++;
        rl_vec4 p = a->color[i], q = b->color[i];
        diff += fabsf(p.x - q.x) > 1.0f / 255.0f || fabsf(p.y - q.y) > 1.0f / 255.0f ||
                fabsf(p.z - q.z) > 1.0f / 255.0f;
    }
    return count ? (double)diff / (double)count : 0.0;
}

/* Fig. 5.7: progressive overdraw (Sec. 3.5.1) draws each stage's faces over
 * the last image, moved towards the eye by eq. 3.16, v_k = v - (v - p_a) f k,
 * so that children win the depth test against their parents. Too small an
 * f leaves parents showing through; too large lets faces win against what
 * lies in front of them. The error is the difference to redraw (the same
 * stages drawn anew), per stage k and for each f, over the VT pixels. */
static rl_status sec_overdraw(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const double fs[] = { 0.0, 1e-5, 1e-4, 1e-3, 1e-2 };
    int w = b->a->width, h = b->a->height;
    ref_frame *ref = NULL;
    char size[32];
    rl_status st = table_section(b, sec, false, &ref, size);
    if (st != RL_OK)
        return st;
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    rl_camera cam = sized(&b->table_cam, w, h);
    rl_image *redraw_img = NULL, *over_img = NULL;
    stage_grab redraw, over;
    memset(&redraw, 0, sizeof redraw);
    memset(&over, 0, sizeof over);
    st = rl_image_create(w, h, RL_LAYER_COLOR, &redraw_img);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &over_img);
    if (st == RL_OK)
        st = progressive_run(b, &cam, "redraw", 0.0, redraw_img, &redraw);
    printf("\nprogressive overdraw against redraw (Fig. 5.7): %s %s, RMSE on the VT pixels per stage k\n",
           table_spec(b), size);
    printf("%-7s", "f");
    for (int k = 0; st == RL_OK && k < redraw.n; k++)
        printf(" %7s%-2u", "k=", redraw.stage[k]);
    printf(" %9s %8s %8s\n", "final", "ssimVT", "differ");
    for (size_t i = 0; st == RL_OK && i < sizeof fs / sizeof fs[0]; i++) {
        st = progressive_run(b, &cam, "overdraw", fs[i], over_img, &over);
        if (st == RL_OK && over.n != redraw.n)
            st = bench_error(b, RL_ERR_INTERNAL, "overdraw made %d stages, redraw %d", over.n, redraw.n);
        if (st != RL_OK)
            break;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddNumberToObject(row, "overdraw_f", fs[i]);
        cJSON *stages = cJSON_AddArrayToObject(row, "stages");
        printf("%-7g", fs[i]);
        for (int k = 0; st == RL_OK && k < over.n; k++) {
            quality q;
            st = compare(over.img[k], redraw.img[k], ref->mask, ref->mask_pixels, &q);
            if (st != RL_OK)
                break;
            cJSON *o = cJSON_CreateObject();
            cJSON_AddItemToArray(stages, o);
            cJSON_AddNumberToObject(o, "k", over.stage[k]);
            add_num(o, "rmse_vt_pixels", q.vt_px.rmse);
            add_num(o, "ssim_vt_pixels", q.vt_px.ssim);
            add_num(o, "differing_vt_pixels", differing(over.img[k], redraw.img[k], ref->mask_pixels ? ref->mask : NULL));
            printf(" %9.5f", q.vt_px.rmse);
        }
        quality q;
        if (st == RL_OK)
            st = compare(over_img, redraw_img, ref->mask, ref->mask_pixels, &q);
        if (st != RL_OK)
            break;
        double diff = differing(over_img, redraw_img, ref->mask_pixels ? ref->mask : NULL);
        cJSON *fin = cJSON_AddObjectToObject(row, "final");
        add_num(fin, "rmse_vt_pixels", q.vt_px.rmse);
        add_num(fin, "ssim_vt_pixels", q.vt_px.ssim);
        add_num(fin, "differing_vt_pixels", diff);
        printf(" %9.5f %8.4f %7.2f%%\n", q.vt_px.rmse, q.vt_px.ssim, 100.0 * diff);
        fflush(stdout);
        note("overdraw f %g %s: final RMSE %.5f, SSIM %.4f, %.2f %% of the VT pixels differ from redraw", fs[i],
             size, q.vt_px.rmse, q.vt_px.ssim, 100.0 * diff);
    }
    grab_free(&redraw);
    grab_free(&over);
    rl_image_release(redraw_img);
    rl_image_release(over_img);
    return st;
}

/* --------------------------------------------------------- equalrays -- */

static int clampi(int v, int lo, int hi)
{
    return v < lo ? lo : v > hi ? hi : v;
}

static rl_vec4 mix4(rl_vec4 a, rl_vec4 b, float t)
{
    return rl_v4(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z + (b.z - a.z) * t, 1.0f);
}

/* src scaled to dst's size by bilinear interpolation between pixel centres. */
static void upscale(const rl_image *src, rl_image *dst)
{
    for (int y = 0; y < dst->height; y++) {
        float fy = ((float)y + 0.5f) * (float)src->height / (float)dst->height - 0.5f;
        int y0 = (int)floorf(fy);
        float ty = fy - (float)y0;
        const rl_vec4 *r0 = src->color + (size_t)clampi(y0, 0, src->height - 1) * (size_t)src->width;
        const rl_vec4 *r1 = src->color + (size_t)clampi(y0 + 1, 0, src->height - 1) * (size_t)src->width;
        for (int x = 0; x < dst->width; x++) {
            float fx = ((float)x + 0.5f) * (float)src->width / (float)dst->width - 0.5f;
            int x0 = (int)floorf(fx);
            float tx = fx - (float)x0;
            int xa = clampi(x0, 0, src->width - 1), xb = clampi(x0 + 1, 0, src->width - 1);
            dst->color[(size_t)y * (size_t)dst->width + (size_t)x] =
                mix4(mix4(r0[xa], r0[xb], tx), mix4(r1[xa], r1[xb], tx), ty);
        }
    }
}

/* Fig. 5.4: VT's preview (and its converged frame) against a ray tracer
 * that spends the same number of rays. Whitted traces about rho rays per
 * pixel of the whole image; with VT's ray count R it can afford R / rho
 * pixels, so it renders an image of that many pixels in the frame's aspect
 * and scales it up bilinearly. Both are compared with the full-resolution
 * Whitted frame on the VT pixels. Whitted's rays go to every object, VT's
 * to the VT objects only: that is the trade the thesis' figure shows. */
static rl_status sec_equal_rays(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    int w = b->a->width, h = b->a->height;
    ref_frame *ref = NULL;
    char size[32];
    rl_status st = table_section(b, sec, true, &ref, size);
    if (st != RL_OK)
        return st;
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    double rho = (double)rays_total(&ref->stats) / ((double)w * h);
    rl_camera cam = sized(&b->table_cam, w, h);
    rl_image *img = NULL, *up = NULL;
    st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &up);
    printf("\nequal rays (Fig. 5.4): %s %s, whitted %.2f rays per pixel; SSIM / RMSE on the VT pixels\n",
           table_spec(b), size, rho);
    printf("%-8s %10s %8s %8s  %-11s %8s %8s\n", "VT", "rays", "ssimVT", "rmseVT", "whitted at", "ssimVT",
           "rmseVT");
    for (int preview = 1; st == RL_OK && preview >= 0; preview--) {
        rl_renderer *r = NULL;
        timed_frame t;
        quality q_vt, q_rt;
        st = make_renderer("vt", b->threads, &r);
        if (st == RL_OK && preview)
            st = rl_vt_set_update_callback(r, stop_at_preview, NULL);
        if (st == RL_OK)
            st = render_timed(r, b->table, &cam, img, 1, &t);
        rl_renderer_release(r);
        if (st == RL_OK)
            st = compare(img, ref->image, ref->mask, ref->mask_pixels, &q_vt);
        if (st != RL_OK)
            break;
        /* The ray tracer's image with as many rays, in the frame's aspect. */
        uint64_t rays = rays_total(&t.stats);
        double pixels = rho > 0.0 ? (double)rays / rho : 0.0;
        double scale = sqrt(pixels / ((double)w * h));
        int lw = (int)fmax(1.0, fmin((double)w, round(w * scale)));
        int lh = (int)fmax(1.0, fmin((double)h, round(h * scale)));
        rl_image *low = NULL;
        timed_frame lt;
        st = rl_image_create(lw, lh, RL_LAYER_COLOR, &low);
        if (st == RL_OK)
            st = time_whitted(b, b->threads, MODE_ALL, low, &lt);
        if (st == RL_OK) {
            upscale(low, up);
            st = compare(up, ref->image, ref->mask, ref->mask_pixels, &q_rt);
        }
        rl_image_release(low);
        if (st != RL_OK)
            break;
        char at[32];
        snprintf(at, sizeof at, "%dx%d", lw, lh);
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "frame", preview ? "preview" : "converged");
        cJSON_AddNumberToObject(row, "vt_rays", (double)rays);
        cJSON_AddNumberToObject(row, "vt_samples", (double)t.vt.vertices_sampled);
        cJSON_AddItemToObject(row, "vt_quality", quality_json(&q_vt));
        cJSON_AddStringToObject(row, "whitted_size", at);
        cJSON_AddNumberToObject(row, "whitted_rays", (double)rays_total(&lt.stats));
        cJSON_AddItemToObject(row, "whitted_quality", quality_json(&q_rt));
        printf("%-8s %10llu %8.4f %8.5f  %-11s %8.4f %8.5f\n", preview ? "preview" : "full",
               (unsigned long long)rays, q_vt.vt_px.ssim, q_vt.vt_px.rmse, at, q_rt.vt_px.ssim, q_rt.vt_px.rmse);
        fflush(stdout);
        note("equal rays %s %s: VT %llu rays SSIM %.3f, whitted %s (%llu rays) SSIM %.3f (VT pixels)",
             preview ? "preview" : "full", size, (unsigned long long)rays, q_vt.vt_px.ssim, at,
             (unsigned long long)rays_total(&lt.stats), q_rt.vt_px.ssim);
    }
    rl_image_release(img);
    rl_image_release(up);
    return st;
}

/* ---------------------------------------------------------- deferred -- */

/* Writes img to DIR/name when --images was given. */
static rl_status save_image(bvt *b, const rl_image *img, const char *name)
{
    if (!b->a->images)
        return RL_OK;
    char path[4096];
    if (snprintf(path, sizeof path, "%s/%s", b->a->images, name) >= (int)sizeof path)
        return bench_error(b, RL_ERR_INVALID_ARG, "--images: path too long");
    rl_clear_error();
    return rl_image_write(img, path);
}

/* Where a deferred reflected or transmitted texture can show (Sec. 3.5.3):
 * VT pixels whose own surface has no texture, so that any texture there is
 * seen in a reflection or through a refraction, and whose Whitted colour
 * changes when reflection and transmission rays are switched off (local
 * is that frame), so that light does come from elsewhere. The VT pixels'
 * other errors (Gouraud interpolation of shading, shadow and highlight
 * edges) count here too wherever such a pixel has them. */
static uint64_t deferred_mask(const rl_scene_data *d, const ref_frame *all, const ref_frame *local,
                              uint8_t *mask)
{
    const float step = 1.0f / 255.0f;
    size_t pixels = (size_t)all->width * (size_t)all->height;
    uint64_t n = 0;
    for (size_t i = 0; i < pixels; i++) {
        uint32_t tri = all->image->triangle_id[i];
        bool textured = tri < d->num_triangles &&
                        d->materials[d->triangle_material[tri]].diffuse_texture < d->num_textures;
        rl_vec4 p = all->image->color[i], q = local->image->color[i];
        bool specular = fabsf(p.x - q.x) > step || fabsf(p.y - q.y) > step || fabsf(p.z - q.z) > step;
        mask[i] = all->mask[i] && !textured && specular;
        n += mask[i];
    }
    return n;
}

/* Mean projected edge length (pixels) of the leaf faces whose centroid
 * lies on a masked pixel: the resolution of the refined mesh over the
 * pixels measured; NaN when no face does. */
static double mesh_edge_px(const rl_renderer *r, const uint8_t *mask, int w, int h, uint64_t *faces_on)
{
    const rl_vt_vertex_info *v = NULL;
    const uint32_t *f = NULL;
    size_t nv = 0, nf = 0;
    *faces_on = 0;
    if (rl_vt_get_mesh(r, &v, &nv, &f, &nf) != RL_OK)
        return NAN;
    double sum = 0.0;
    for (size_t i = 0; i < nf; i++) {
        const rl_vt_vertex_info *a = &v[f[3 * i]], *b = &v[f[3 * i + 1]], *c = &v[f[3 * i + 2]];
        int x = (int)floorf((a->x + b->x + c->x) / 3.0f), y = (int)floorf((a->y + b->y + c->y) / 3.0f);
        if (x < 0 || y < 0 || x >= w || y >= h || !mask[(size_t)y * (size_t)w + (size_t)x])
            continue;
        sum += hypotf(a->x - b->x, a->y - b->y) + hypotf(b->x - c->x, b->y - c->y) +
               hypotf(c->x - a->x, c->y - a->y);
        ++*faces_on;
    }
    return *faces_on ? sum / (3.0 * (double)*faces_on) : NAN;
}

/* |a - b| on the masked pixels, times gain, black elsewhere: where the
 * error of Fig. 5.8 sits. */
static rl_status error_image(const rl_image *a, const rl_image *b, const uint8_t *mask, float gain,
                             rl_image **out)
{
    rl_status st = rl_image_create(a->width, a->height, RL_LAYER_COLOR, out);
    if (st != RL_OK)
        return st;
    size_t pixels = (size_t)a->width * (size_t)a->height;
    for (size_t i = 0; i < pixels; i++) {
        rl_vec4 p = a->color[i], q = b->color[i];
        (*out)->color[i] = mask[i] ? rl_v4(fminf(1.0f, gain * fabsf(p.x - q.x)), fminf(1.0f, gain * fabsf(p.y - q.y)),
                                           fminf(1.0f, gain * fabsf(p.z - q.z)), 1.0f)
                                   : rl_v4(0.0f, 0.0f, 0.0f, 1.0f);
    }
    return RL_OK;
}

/* Fig. 5.8: the perspective error of deferred reflected and transmitted
 * textures. The deferred path (Sec. 3.5.3) keeps per vertex the texture
 * coordinates where a reflection or refraction ray hit a textured surface
 * and interpolates them over the VT face with the face's own perspective;
 * the true coordinates follow the reflected surface's perspective through
 * the curved mirror, so between vertices the texture is drawn distorted,
 * the more the fewer vertices carry it. The criteria do not see the
 * texture (that is the point of deferring), so only the ray tree or the
 * untextured colour refines there: the thesis' figure uses the ray-tree
 * criterion alone. Per criterion and min_edge, the frame with deferred
 * textures (multitexture) and with the textured radiance sampled at the
 * vertices instead (sampled, where the criteria do see the texture), both
 * against Whitted, which looks the texture up per pixel: RMSE and SSIM on
 * the pixels of deferred_mask, and the mesh's edge length there. */
static rl_status sec_deferred(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    static const char *const crits[] = { "tree", "tree+hsv" };
    static const char *const textures[] = { "multitexture", "sampled" };
    static const double full_edges[] = { 1, 2, 4, 8, 16 }, quick_edges[] = { 1, 8 };
    const double *edges = b->a->quick ? quick_edges : full_edges;
    size_t num_edges = b->a->quick ? 2 : 5;
    int w = b->a->width, h = b->a->height;
    ref_frame *ref = NULL, *local = NULL;
    char size[32];
    rl_status st = table_section(b, sec, true, &ref, size);
    if (st == RL_OK)
        st = reference(b, w, h, b->threads, MODE_S, &local);
    if (st != RL_OK)
        return st;
    const rl_scene_data *d = rl_scene_get_data(b->table);
    uint8_t *mask = malloc((size_t)w * (size_t)h);
    if (!mask)
        return RL_ERR_OUT_OF_MEMORY;
    uint64_t mask_pixels = deferred_mask(d, ref, local, mask);
    cJSON_AddNumberToObject(sec, "deferred_pixels", (double)mask_pixels);
    cJSON_AddStringToObject(sec, "deferred_pixels_are",
                            "VT pixels on an untextured surface whose Whitted colour changes with "
                            "reflection and transmission rays off (+S-R-T)");
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam = sized(&b->table_cam, w, h);
    st = make_renderer("vt", b->threads, &r);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
    printf("\ndeferred textures (Fig. 5.8): %s %s, %llu deferred pixels of %llu VT pixels; against Whitted\n",
           table_spec(b), size, (unsigned long long)mask_pixels, (unsigned long long)ref->mask_pixels);
    printf("%-9s %8s %-13s %9s %9s %8s  %8s %7s  %8s %7s\n", "criteria", "min_edge", "textures", "sampled",
           "faces on", "edge px", "rmseDef", "ssimDef", "rmseVT", "ssimVT");
    for (size_t c = 0; st == RL_OK && c < sizeof crits / sizeof crits[0]; c++) {
        for (size_t e = 0; st == RL_OK && e < num_edges; e++) {
            for (size_t t = 0; st == RL_OK && t < sizeof textures / sizeof textures[0]; t++) {
                rl_render_stats stats;
                rl_vt_stats vs;
                quality q;
                rl_image_metrics def;
                uint64_t faces_on = 0;
                rl_clear_error();
                st = rl_renderer_set(r, "criteria", crits[c]);
                if (st == RL_OK)
                    st = set_int(r, "min_edge", edges[e]);
                if (st == RL_OK)
                    st = rl_renderer_set(r, "textures", textures[t]);
                /* One render each: the figure is the error, not the time. */
                if (st == RL_OK)
                    st = rl_renderer_render(r, b->table, &cam, img, &stats);
                if (st == RL_OK)
                    st = rl_vt_get_stats(r, &vs);
                if (st == RL_OK)
                    st = compare(img, ref->image, ref->mask, ref->mask_pixels, &q);
                nan_metrics(&def);
                if (st == RL_OK && mask_pixels)
                    st = rl_image_compare(img, ref->image, &(rl_metric_options){ .mask = mask }, &def);
                if (st != RL_OK)
                    break;
                double edge = mask_pixels ? mesh_edge_px(r, mask, w, h, &faces_on) : NAN;
                cJSON *row = cJSON_CreateObject();
                cJSON_AddItemToArray(rows, row);
                cJSON_AddStringToObject(row, "criteria", crits[c]);
                cJSON_AddNumberToObject(row, "min_edge", edges[e]);
                cJSON_AddStringToObject(row, "textures", textures[t]);
                cJSON_AddNumberToObject(row, "vertices_sampled", (double)vs.vertices_sampled);
                cJSON_AddNumberToObject(row, "vertices_generated", (double)vs.vertices_generated);
                cJSON_AddNumberToObject(row, "faces_on_deferred_pixels", (double)faces_on);
                add_num(row, "edge_px_on_deferred_pixels", edge);
                cJSON_AddItemToObject(row, "rays", rays_json(&stats));
                cJSON_AddItemToObject(row, "deferred_pixels", metrics_json(&def));
                cJSON_AddItemToObject(row, "quality", quality_json(&q));
                printf("%-9s %8g %-13s %9llu %9llu %8.2f  %8.5f %7.4f  %8.5f %7.4f\n", crits[c], edges[e],
                       textures[t], (unsigned long long)vs.vertices_sampled, (unsigned long long)faces_on, edge,
                       def.rmse, def.ssim, q.vt_px.rmse, q.vt_px.ssim);
                fflush(stdout);
                note("deferred %s/%g %s %s: RMSE %.5f SSIM %.4f on %llu deferred pixels, edge %.2f px", crits[c],
                     edges[e], textures[t], size, def.rmse, def.ssim, (unsigned long long)mask_pixels, edge);
                /* Fig. 5.8a: the thesis' setting, ray tree alone, at the
                 * finest and the coarsest mesh; 5.8b is Whitted's frame. */
                if (c == 0 && (e == 0 || e == num_edges - 1) && t == 0 && b->a->images) {
                    rl_image *err = NULL;
                    char file[64];
                    snprintf(file, sizeof file, "fig5.8a-vt-min_edge-%g.png", edges[e]);
                    st = save_image(b, img, file);
                    if (st == RL_OK && e == 0)
                        st = save_image(b, ref->image, "fig5.8b-whitted.png");
                    if (st == RL_OK)
                        st = error_image(img, ref->image, mask, 4.0f, &err);
                    snprintf(file, sizeof file, "fig5.8-error-x4-min_edge-%g.png", edges[e]);
                    if (st == RL_OK)
                        st = save_image(b, err, file);
                    rl_image_release(err);
                }
            }
        }
    }
    rl_image_release(img);
    rl_renderer_release(r);
    free(mask);
    return st;
}

/* ---------------------------------------------------------- scenario -- */

/* The fastest of runs renders (no warm-up: the caller made one), with the
 * process CPU time of the fastest one; img holds the last frame. */
static rl_status render_best(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *img, int runs,
                             timed_frame *out, double *cpu_ms)
{
    bool vt = strcmp(rl_renderer_name(r), "vt") == 0;
    rl_status st = RL_OK;
    memset(out, 0, sizeof *out);
    out->stats.time_ms = INFINITY;
    *cpu_ms = NAN;
    for (int i = 0; st == RL_OK && i < runs; i++) {
        rl_render_stats stats;
        struct timespec c0, c1;
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
        rl_clear_error();
        st = rl_renderer_render(r, scene, cam, img, &stats);
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
        if (st == RL_OK && stats.time_ms < out->stats.time_ms) {
            out->stats = stats;
            *cpu_ms = 1e3 * (double)(c1.tv_sec - c0.tv_sec) + 1e-6 * (double)(c1.tv_nsec - c0.tv_nsec);
            if (vt)
                st = rl_vt_get_stats(r, &out->vt);
        }
    }
    return st;
}

/* Ullmann 2003, Sec. 5.4: the frames of Figs. 5.16-5.21. */
static const struct {
    const char *fig, *camera, *what;
    int mode;
    bool preview;              /* refinement stopped after the primary vertices */
    const char *criteria;      /* and min_edge: VT's settings */
    double min_edge;
    const char *file;          /* the image's name: fig<file>-vt.png */
} scenario_views[] = {
    { "5.16", "driver", "the driver's view", MODE_ALL, false, "tree+hsv", 1, "5.16" },
    /* The thesis does not give its settings; the equal-quality setting of
     * the quality section on table, for comparison. */
    { "5.16", "driver", "the driver's view at criteria=hsv min_edge=14", MODE_ALL, false, "hsv", 14,
      "5.16-hsv14" },
    { "5.17", "driver", "the preview (primary vertices only)", MODE_ALL, true, "tree+hsv", 1, "5.17" },
    { "5.18", "lateral", "the lateral view", MODE_ALL, false, "tree+hsv", 1, "5.18" },
    { "5.19", "driver", "without the cover glass' reflection", MODE_S | MODE_T, false, "tree+hsv", 1, "5.19" },
    { "5.20", "driver", "without the cover glass' transmission", MODE_S | MODE_R, false, "tree+hsv", 1, "5.20" },
    { "5.21", "zoom", "zoomed in", MODE_ALL, false, "tree+hsv", 1, "5.21" },
};

/* Sec. 5.4: "2.5 s to full refinement, the preview in about 0.2 s, about
 * 340,000 polygons at 1280x1024, dual Athlon 1.4 GHz, GeForce4 Ti 4600". */
#define THESIS_SCENARIO_FULL_MS 2500.0
#define THESIS_SCENARIO_PREVIEW_MS 200.0
#define THESIS_SCENARIO_POLYGONS 340000

static cJSON *scenario_thesis_json(void)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    add_num(o, "full_refinement_ms", THESIS_SCENARIO_FULL_MS);
    add_num(o, "preview_ms", THESIS_SCENARIO_PREVIEW_MS);
    cJSON_AddNumberToObject(o, "polygons", THESIS_SCENARIO_POLYGONS);
    cJSON_AddStringToObject(o, "size", "1280x1024");
    cJSON_AddStringToObject(o, "machine", "dual Athlon 1.4 GHz, GeForce4 Ti 4600 (rasterization on the GPU)");
    cJSON_AddStringToObject(o, "source", "Ullmann 2003, Sec. 5.4, Fig. 5.16-5.21");
    return o;
}

/* Sec. 5.4, the application: the readability of an instrument cluster in
 * VR, where only the cover glass is vertex traced and everything else is
 * rasterized. Per figure the frame of VT and of Whitted (which traces the
 * whole frame) with the figure's camera and shading mode: the full frame's
 * time and the time until its preview was drawn, rays, samples, SSIM on
 * the glass' pixels; Fig. 5.17 is a frame stopped at the preview. At
 * 1280x1024 unless --size says otherwise. */
static rl_status sec_scenario(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    int w = b->a->has_size ? b->a->width : b->a->quick ? 80 : 1280;
    int h = b->a->has_size ? b->a->height : b->a->quick ? 64 : 1024;
    const rl_scene_data *d = rl_scene_get_data(b->cluster);
    char size[32];
    snprintf(size, sizeof size, "%dx%d", w, h);
    cJSON_AddStringToObject(sec, "scene", "cluster");
    cJSON_AddStringToObject(sec, "size", size);
    cJSON_AddNumberToObject(sec, "triangles", d->num_triangles);
    cJSON_AddItemToObject(sec, "thesis", scenario_thesis_json());
    cJSON_AddStringToObject(sec, "timing",
                            "one warm-up render per renderer at a quarter of the width and height, then "
                            "per view the fastest of timed_renders (wall) and that render's process CPU "
                            "time (all threads); preview_ms of a full frame: until its primary vertices "
                            "were sampled; Fig. 5.17's time_ms: the whole frame stopped at the preview, "
                            "drawn");
    cJSON *rows = cJSON_AddArrayToObject(sec, "runs");
    rl_renderer *vt = NULL, *rt = NULL;
    rl_image *img = NULL, *ref = NULL;
    uint8_t *mask = malloc((size_t)w * (size_t)h);
    rl_status st = mask ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        st = make_renderer("vt", b->threads, &vt);
    if (st == RL_OK)
        st = make_renderer("whitted", b->threads, &rt);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &img);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR | RL_LAYER_ID, &ref);
    /* One warm-up per renderer, at a sixteenth of the size: it builds the
     * accelerator and the glass' mesh, which the views share; a full-size
     * warm-up per view would cost as much as a timed frame. */
    rl_camera warm;
    memset(&warm, 0, sizeof warm);
    if (st == RL_OK)
        st = rl_scene_get_camera(b->cluster, scenario_views[0].camera, &warm);
    warm = sized(&warm, w / 4 > 0 ? w / 4 : 1, h / 4 > 0 ? h / 4 : 1);
    rl_image *warm_img = NULL;
    if (st == RL_OK)
        st = rl_image_create(warm.width, warm.height, RL_LAYER_COLOR, &warm_img);
    if (st == RL_OK)
        st = rl_renderer_render(vt, b->cluster, &warm, warm_img, NULL);
    if (st == RL_OK)
        st = rl_renderer_render(rt, b->cluster, &warm, warm_img, NULL);
    rl_image_release(warm_img);
    printf("\napplication scenario (Sec. 5.4, Fig. 5.16-5.21): cluster %s, %u triangles, only the cover glass "
           "traced; thesis: 2.5 s full, 0.2 s preview\n", size, d->num_triangles);
    printf("%-5s %-8s %-7s %-3s %-11s %9s %9s %9s %7s %8s %8s %8s  %6s\n", "fig", "camera", "mode", "pv",
           "criteria", "whitted", "VT ms", "preview", "x", "rays %", "samp %", "glass px", "ssimVT");
    timed_frame tr;
    double cpu_rt = NAN;
    uint64_t mask_pixels = 0;
    const char *ref_camera = NULL;
    int ref_mode = -1;
    for (size_t i = 0; st == RL_OK && i < sizeof scenario_views / sizeof scenario_views[0]; i++) {
        const char *fig = scenario_views[i].fig, *camera = scenario_views[i].camera;
        int mode = scenario_views[i].mode;
        bool preview = scenario_views[i].preview;
        rl_camera cam;
        memset(&cam, 0, sizeof cam);
        timed_frame tv;
        double cpu_vt = NAN;
        quality q;
        rl_clear_error();
        st = rl_scene_get_camera(b->cluster, camera, &cam);
        cam = sized(&cam, w, h);
        /* Fig. 5.17 is 5.16's frame stopped early: the same reference. */
        bool same_ref = ref_camera && strcmp(ref_camera, camera) == 0 && ref_mode == mode;
        if (st == RL_OK && !same_ref) {
            st = set_mode(rt, mode);
            if (st == RL_OK)
                st = render_best(rt, b->cluster, &cam, ref, b->runs, &tr, &cpu_rt);
            if (st == RL_OK) {
                mask_pixels = fill_mask(ref, b->cluster_vt, d->num_objects, mask);
                ref_camera = camera;
                ref_mode = mode;
            }
        }
        if (st == RL_OK)
            st = set_mode(vt, mode);
        if (st == RL_OK)
            st = rl_renderer_set(vt, "criteria", scenario_views[i].criteria);
        if (st == RL_OK)
            st = set_int(vt, "min_edge", scenario_views[i].min_edge);
        if (st == RL_OK)
            st = rl_vt_set_update_callback(vt, preview ? stop_at_preview : NULL, NULL);
        if (st == RL_OK)
            st = render_best(vt, b->cluster, &cam, img, b->runs, &tv, &cpu_vt);
        if (st == RL_OK)
            st = compare(img, ref, mask, mask_pixels, &q);
        char name[8], file[64];
        mode_name(mode, name);
        snprintf(file, sizeof file, "fig%s-vt.png", scenario_views[i].file);
        if (st == RL_OK)
            st = save_image(b, img, file);
        snprintf(file, sizeof file, "fig%s-whitted.png", fig);
        if (st == RL_OK && !same_ref)
            st = save_image(b, ref, file);
        if (st != RL_OK)
            break;
        double speedup = ratio(tr.stats.time_ms, tv.stats.time_ms);
        double rays_pct = 100.0 * ratio((double)rays_total(&tv.stats), (double)rays_total(&tr.stats));
        double samples_pct = 100.0 * (double)tv.vt.vertices_sampled / ((double)w * h);
        double thesis_ms = preview ? THESIS_SCENARIO_PREVIEW_MS : THESIS_SCENARIO_FULL_MS;
        cJSON *row = cJSON_CreateObject();
        cJSON_AddItemToArray(rows, row);
        cJSON_AddStringToObject(row, "fig", fig);
        cJSON_AddStringToObject(row, "what", scenario_views[i].what);
        cJSON_AddStringToObject(row, "camera", camera);
        cJSON_AddStringToObject(row, "mode", name);
        cJSON_AddBoolToObject(row, "preview", preview);
        cJSON_AddStringToObject(row, "criteria", scenario_views[i].criteria);
        cJSON_AddNumberToObject(row, "min_edge", scenario_views[i].min_edge);
        cJSON *rj = cJSON_AddObjectToObject(row, "whitted");
        add_num(rj, "time_ms", tr.stats.time_ms);
        add_num(rj, "cpu_ms", cpu_rt);
        cJSON_AddItemToObject(rj, "rays", rays_json(&tr.stats));
        cJSON_AddNumberToObject(rj, "vt_pixels", (double)mask_pixels);
        add_num(row, "time_ms", tv.stats.time_ms);
        add_num(row, "cpu_ms", cpu_vt);
        add_num(row, "preview_ms", tv.vt.time_preview_ms);
        add_num(row, "thesis_ms", thesis_ms);
        add_num(row, "time_over_thesis", ratio(tv.stats.time_ms, thesis_ms));
        cJSON_AddItemToObject(row, "rays", rays_json(&tv.stats));
        add_num(row, "whitted_over_vt_time", speedup);
        add_num(row, "rays_percent_of_whitted", rays_pct);
        add_num(row, "samples_percent_of_pixels", samples_pct);
        add_num(row, "samples_percent_of_vt_pixels",
                100.0 * ratio((double)tv.vt.vertices_sampled, (double)mask_pixels));
        cJSON_AddItemToObject(row, "quality", quality_json(&q));
        cJSON_AddItemToObject(row, "vt_stats", vt_stats_json(&tv.vt));
        char crit[32];
        snprintf(crit, sizeof crit, "%s/%g", scenario_views[i].criteria, scenario_views[i].min_edge);
        printf("%-5s %-8s %-7s %-3s %-11s %9.1f %9.1f %9.1f %7.2f %8.1f %8.3f %8llu  %6.3f\n", fig, camera, name,
               preview ? "yes" : "", crit, tr.stats.time_ms, tv.stats.time_ms, tv.vt.time_preview_ms, speedup,
               rays_pct, samples_pct, (unsigned long long)mask_pixels, q.vt_px.ssim);
        fflush(stdout);
        note("scenario fig %s %s %s %s %s: VT %.1f ms (preview %.1f ms), whitted %.1f ms, SSIM %.3f (glass pixels)",
             fig, camera, name, crit, size, tv.stats.time_ms, tv.vt.time_preview_ms, tr.stats.time_ms, q.vt_px.ssim);
    }
    rl_image_release(img);
    rl_image_release(ref);
    rl_renderer_release(vt);
    rl_renderer_release(rt);
    free(mask);
    return st;
}

/* --------------------------------------------------------- animation -- */

typedef struct series {
    double sum, lo, hi;
    int n;
} series;

static void series_add(series *s, double x)
{
    if (!isfinite(x))
        return;
    s->lo = s->n && s->lo < x ? s->lo : x;
    s->hi = s->n && s->hi > x ? s->hi : x;
    s->sum += x;
    s->n++;
}

static cJSON *series_json(const series *s)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    add_num(o, "mean", s->n ? s->sum / s->n : NAN);
    add_num(o, "min", s->n ? s->lo : NAN);
    add_num(o, "max", s->n ? s->hi : NAN);
    return o;
}

static double series_mean(const series *s)
{
    return s->n ? s->sum / s->n : NAN;
}

/* The renderers of the animation: Whitted, VT with and without coherence. */
typedef struct anim {
    rl_renderer *whitted, *coherent, *plain;
    rl_image *ref, *a, *b;
    uint8_t *mask;
} anim;

static void anim_free(anim *x)
{
    rl_renderer_release(x->whitted);
    rl_renderer_release(x->coherent);
    rl_renderer_release(x->plain);
    rl_image_release(x->ref);
    rl_image_release(x->a);
    rl_image_release(x->b);
    free(x->mask);
}


/* What one frame of the path gave. */
typedef struct anim_result {
    rl_render_stats whitted, coherent, plain;
    rl_vt_stats vt;                /* of the coherent renderer */
    quality q;
    uint64_t vt_pixels;
    bool identical;
} anim_result;

/* One frame of the path for the three renderers. */
static rl_status anim_frame(bvt *b, anim *x, const rl_camera *cam, anim_result *res)
{
    const rl_scene_data *d = rl_scene_get_data(b->cluster);
    rl_clear_error();
    rl_status st = rl_renderer_render(x->whitted, b->cluster, cam, x->ref, &res->whitted);
    if (st == RL_OK)
        st = rl_renderer_render(x->coherent, b->cluster, cam, x->a, &res->coherent);
    if (st == RL_OK)
        st = rl_vt_get_stats(x->coherent, &res->vt);
    if (st == RL_OK)
        st = rl_renderer_render(x->plain, b->cluster, cam, x->b, &res->plain);
    if (st == RL_OK) {
        res->vt_pixels = fill_mask(x->ref, b->cluster_vt, d->num_objects, x->mask);
        st = compare(x->a, x->ref, x->mask, res->vt_pixels, &res->q);
    }
    if (st != RL_OK)
        return st;
    /* Sec. 3.4.5: replaying the feelers must not change a single bit. */
    size_t bytes = (size_t)x->a->width * (size_t)x->a->height * sizeof *x->a->color;
    res->identical = memcmp(x->a->color, x->b->color, bytes) == 0;
    return RL_OK;
}

static cJSON *anim_json(uint32_t frame, const anim_result *r)
{
    cJSON *row = cJSON_CreateObject();
    if (!row)
        return NULL;
    cJSON_AddNumberToObject(row, "frame", frame);
    add_num(row, "vt_coherent_ms", r->coherent.time_ms);
    add_num(row, "vt_plain_ms", r->plain.time_ms);
    add_num(row, "whitted_ms", r->whitted.time_ms);
    add_num(row, "ssim_vt_pixels", r->q.vt_px.ssim);
    add_num(row, "rmse_vt_pixels", r->q.vt_px.rmse);
    add_num(row, "ssim_full", r->q.full.ssim);
    cJSON_AddNumberToObject(row, "vt_pixels", (double)r->vt_pixels);
    cJSON_AddNumberToObject(row, "feelers_reused", (double)r->vt.feelers_reused);
    cJSON_AddNumberToObject(row, "vertices_sampled", (double)r->vt.vertices_sampled);
    cJSON_AddNumberToObject(row, "vt_rays", (double)rays_total(&r->coherent));
    cJSON_AddNumberToObject(row, "vt_plain_rays", (double)rays_total(&r->plain));
    cJSON_AddNumberToObject(row, "whitted_rays", (double)rays_total(&r->whitted));
    cJSON_AddBoolToObject(row, "identical", r->identical);
    return row;
}

/* Sec. 3.4.5 on the cluster's camera path: each VT renderer renders the
 * whole path in order (two renderers: one keeps the feelers between frames,
 * the other does not), interleaved frame by frame with Whitted, so that
 * every frame has its reference and load changes hit all three alike. */
static rl_status sec_animation(void *ctx, cJSON *sec)
{
    bvt *b = ctx;
    const rl_camera_path *path = rl_scene_get_data(b->cluster)->camera_path;
    if (!path)
        return bench_error(b, RL_ERR_NOT_FOUND, "scene cluster has no camera path");
    int w = b->a->anim_width, h = b->a->anim_height;
    uint32_t n = (uint32_t)b->a->frames;
    char size[32];
    snprintf(size, sizeof size, "%dx%d", w, h);
    cJSON_AddStringToObject(sec, "scene", "cluster");
    cJSON_AddStringToObject(sec, "size", size);
    cJSON_AddNumberToObject(sec, "frames", n);
    add_num(sec, "path_duration_s", rl_camera_path_duration(path));
    cJSON *rows = cJSON_AddArrayToObject(sec, "per_frame");

    anim x;
    memset(&x, 0, sizeof x);
    rl_camera first = rl_camera_path_frame(path, 0, n);
    first = sized(&first, w, h);
    rl_clear_error();
    rl_status st = make_renderer("whitted", b->threads, &x.whitted);
    if (st == RL_OK)
        st = make_renderer("vt", b->threads, &x.coherent);
    if (st == RL_OK)
        st = make_renderer("vt", b->threads, &x.plain);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR | RL_LAYER_ID, &x.ref);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &x.a);
    if (st == RL_OK)
        st = rl_image_create(w, h, RL_LAYER_COLOR, &x.b);
    if (st == RL_OK && !(x.mask = malloc((size_t)w * (size_t)h)))
        st = RL_ERR_OUT_OF_MEMORY;
    /* Warm-up (accelerators, meshes), still without coherence, so that the
     * first frame of the path finds no feelers of its own. */
    if (st == RL_OK)
        st = rl_renderer_render(x.whitted, b->cluster, &first, x.ref, NULL);
    if (st == RL_OK)
        st = rl_renderer_render(x.coherent, b->cluster, &first, x.a, NULL);
    if (st == RL_OK)
        st = rl_renderer_render(x.plain, b->cluster, &first, x.b, NULL);
    if (st == RL_OK)
        st = rl_renderer_set(x.coherent, "coherence", "true");

    series acc[4];      /* coherent ms, plain ms, Whitted ms, SSIM */
    memset(acc, 0, sizeof acc);
    uint64_t reused = 0;
    bool identical = true;
    for (uint32_t i = 0; st == RL_OK && i < n; i++) {
        rl_camera cam = rl_camera_path_frame(path, i, n);
        cam = sized(&cam, w, h);
        anim_result res;
        st = anim_frame(b, &x, &cam, &res);
        if (st != RL_OK)
            break;
        cJSON_AddItemToArray(rows, anim_json(i, &res));
        identical = identical && res.identical;
        reused += res.vt.feelers_reused;
        series_add(&acc[0], res.coherent.time_ms);
        series_add(&acc[1], res.plain.time_ms);
        series_add(&acc[2], res.whitted.time_ms);
        series_add(&acc[3], res.q.vt_px.ssim);
        note("animation frame %u/%u %s: VT %.1f ms coherent, %.1f ms plain, whitted %.1f ms, "
             "SSIM %.3f, %llu feelers reused, %s",
             i + 1, n, size, res.coherent.time_ms, res.plain.time_ms, res.whitted.time_ms,
             res.q.vt_px.ssim, (unsigned long long)res.vt.feelers_reused,
             res.identical ? "identical" : "DIFFERENT");
    }
    anim_free(&x);
    if (st != RL_OK)
        return st;
    cJSON *sum = cJSON_AddObjectToObject(sec, "summary");
    cJSON_AddItemToObject(sum, "vt_coherent_ms", series_json(&acc[0]));
    cJSON_AddItemToObject(sum, "vt_plain_ms", series_json(&acc[1]));
    cJSON_AddItemToObject(sum, "whitted_ms", series_json(&acc[2]));
    cJSON_AddItemToObject(sum, "ssim_vt_pixels", series_json(&acc[3]));
    cJSON_AddNumberToObject(sum, "feelers_reused", (double)reused);
    add_num(sum, "coherence_speedup", ratio(series_mean(&acc[1]), series_mean(&acc[0])));
    add_num(sum, "time_ratio_to_whitted", ratio(series_mean(&acc[0]), series_mean(&acc[2])));
    cJSON_AddBoolToObject(sec, "identical", identical);
    printf("\nanimation (Sec. 3.4.5): cluster, %u frames of the camera path at %s\n", n, size);
    printf("%-14s %9s %9s %9s\n", "", "mean", "min", "max");
    const char *labels[4] = { "VT coherent ms", "VT plain ms", "Whitted ms", "SSIM VT px" };
    for (int k = 0; k < 4; k++)
        printf("%-14s %9.3f %9.3f %9.3f\n", labels[k], series_mean(&acc[k]),
               acc[k].n ? acc[k].lo : NAN, acc[k].n ? acc[k].hi : NAN);
    printf("feelers reused %llu; coherence speed-up %.3f; VT/Whitted %.3f; coherent and plain "
           "images %s\n",
           (unsigned long long)reused, ratio(series_mean(&acc[1]), series_mean(&acc[0])),
           ratio(series_mean(&acc[0]), series_mean(&acc[2])),
           identical ? "identical" : "DIFFER");
    fflush(stdout);
    return RL_OK;
}

/* ------------------------------------------------------- the command -- */

/* --set KEY=VALUE: checked on a vt renderer at once, so that a typo fails
 * before minutes of rendering. */
static bool take_set(void *ctx, const char *v)
{
    bvt_sets *sets = ctx;
    const char *eq = strchr(v, '=');
    size_t n = eq ? (size_t)(eq - v) : 0;
    if (!eq || n == 0 || n >= sizeof sets->key[0]) {
        cli_fail(RL_CLI_USAGE, "--set: expected KEY=VALUE (a vt option, see rl algos), got '%s'", v);
        return false;
    }
    if (sets->count >= MAX_SETS) {
        cli_fail(RL_CLI_USAGE, "--set: at most %d options", MAX_SETS);
        return false;
    }
    int i = sets->count;
    memcpy(sets->key[i], v, n);
    sets->key[i][n] = '\0';
    rl_renderer *r = NULL;
    rl_clear_error();
    rl_status st = rl_renderer_create("vt", &r);
    if (st == RL_OK)
        st = rl_renderer_set(r, sets->key[i], eq + 1);
    rl_renderer_release(r);
    if (st != RL_OK) {
        cli_fail(RL_CLI_USAGE, "--set %s: %s", v, rl_last_error());
        return false;
    }
    sets->value[i] = eq + 1;
    sets->text[i] = v;
    sets->count++;
    return true;
}

/* Returns RL_CLI_OK, an exit code, or RL_BENCH_HELP_SHOWN. */
static int parse_args(int argc, char **argv, bvt_args *a)
{
    a->sections = 0;               /* no --only: chosen below (--only "" is refused) */
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_SIZE("--size", &a->width, &a->height, &a->has_size),
        RL_BENCH_SIZE("--anim-size", &a->anim_width, &a->anim_height, &a->has_anim_size),
        RL_BENCH_COUNT("--frames", MAX_FRAMES, &a->frames, &a->has_frames),
        RL_BENCH_COUNT("--threads", RL_VT_MAX_THREADS, &a->threads, NULL),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_OUT(&a->out),
        RL_BENCH_STRING("--scene", &a->scene),
        RL_BENCH_STRING("--images", &a->images),
        RL_BENCH_CUSTOM("--set", take_set, &a->sets, NULL),
    };
    int rc = bench_parse_args(argc, argv, "bench vt", bench_vt_help, rows,
                                 (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    /* Defaults; --quick changes only what was not given. The thesis
     * measured the table scene at 1024x1024 (Sec. 5.1). */
    if (!a->has_size)
        a->width = a->height = a->quick ? 128 : 1024;
    if (!a->has_anim_size) {
        a->anim_width = a->quick ? 128 : 640;
        a->anim_height = a->quick ? 128 : 480;
    }
    if (!a->has_frames)
        a->frames = a->quick ? 3 : 60;
    /* Without --only: Sec. 6.1 is an extension study, not a figure of
     * Ch. 5, so it runs only on request. The Fig. 5.8 and Sec. 5.4 studies
     * and the hints of Sec. 6.2.2 take minutes each at full size:
     * the full run leaves them out too (it stays about 8 min), --quick
     * runs them at toy sizes so that one quick run covers them. */
    if (!a->sections) {
        a->sections = ((1u << SEC_COUNT) - 1) & ~(1u << SEC_CORRECTNESS);
        if (!a->quick)
            a->sections &= ~((1u << SEC_DEFERRED) | (1u << SEC_SCENARIO) | (1u << SEC_HINT));
    }
    return RL_CLI_OK;
}

static bool wants(const bvt_args *a, int section)
{
    return (a->sections >> section) & 1u;
}

/* Loads a built-in scene and its VT object set. */
static int load(const char *name, rl_scene **scene, uint8_t **object_vt)
{
    int rc = cli_load_scene(name, scene);
    if (rc != RL_CLI_OK)
        return rc;
    if (!(*object_vt = vt_objects(*scene)))
        return cli_fail(RL_CLI_FAIL, "out of memory");
    return RL_CLI_OK;
}

/* Every vt option with the value the sections start from. */
static cJSON *vt_options_json(int threads)
{
    rl_renderer *r = NULL;
    if (make_renderer("vt", threads, &r) != RL_OK)
        return NULL;
    cJSON *o = cJSON_CreateObject();
    size_t count = 0;
    const rl_option_info *opts = rl_renderer_options(r, &count);
    for (size_t i = 0; o && i < count; i++)
        cJSON_AddStringToObject(o, opts[i].key, rl_renderer_get(r, opts[i].key));
    rl_renderer_release(r);
    return o;
}

static cJSON *params_json(const bvt *b)
{
    const bvt_args *a = b->a;
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    char text[64];
    snprintf(text, sizeof text, "%dx%d", a->width, a->height);
    cJSON_AddStringToObject(o, "size", text);
    snprintf(text, sizeof text, "%dx%d", a->anim_width, a->anim_height);
    cJSON_AddStringToObject(o, "anim_size", text);
    cJSON_AddStringToObject(o, "scene", table_spec(b));
    cJSON_AddNumberToObject(o, "frames", (double)a->frames);
    cJSON_AddNumberToObject(o, "threads", b->threads);
    cJSON_AddNumberToObject(o, "max_threads", b->max_threads);
    cJSON_AddBoolToObject(o, "quick", a->quick);
    cJSON *only = cJSON_AddArrayToObject(o, "sections");
    for (int k = 0; only && k < SEC_COUNT; k++)
        if (wants(a, k))
            cJSON_AddItemToArray(only, cJSON_CreateString(section_names[k]));
    cJSON_AddNumberToObject(o, "warmup_renders", 1);
    cJSON_AddNumberToObject(o, "timed_renders", b->runs);
    /* The tracer as Whitted has it, --set included. */
    cJSON *tracer = cJSON_AddObjectToObject(o, "tracer");
    rl_renderer *w = NULL;
    if (make_renderer("whitted", b->threads, &w) == RL_OK) {
        cJSON_AddNumberToObject(tracer, "max_depth", atoi(rl_renderer_get(w, "max_depth")));
        cJSON_AddNumberToObject(tracer, "area_samples", atoi(rl_renderer_get(w, "area_samples")));
        cJSON_AddBoolToObject(tracer, "shadows", strcmp(rl_renderer_get(w, "shadows"), "true") == 0);
    }
    rl_renderer_release(w);
    cJSON *set = cJSON_AddArrayToObject(o, "set");
    for (int i = 0; set && i < a->sets.count; i++)
        cJSON_AddItemToArray(set, cJSON_CreateString(a->sets.text[i]));
    cJSON_AddItemToObject(o, "vt_options", vt_options_json(b->threads));
    cJSON_AddStringToObject(o, "timing",
                            "wall time of rl_renderer_render; per configuration one warm-up "
                            "render, then the fastest of timed_renders; static sections with "
                            "coherence=false; animation frames rendered once each");
    cJSON_AddStringToObject(o, "vt_pixels",
                            "pixels whose object in Whitted's ID layer is a VT object: node or "
                            "nearest ancestor with attribute vt=true, else (no vt attribute in "
                            "the scene) reflective or refractive objects");
    cJSON_AddStringToObject(o, "metrics",
                            "rl_image_compare: sRGB, SSIM on luma (Wang et al. 2004)");
    return o;
}

/* Figures of Ullmann 2003, Ch. 5, for the reader of the record. */
static cJSON *thesis_json(void)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON *gen = cJSON_AddObjectToObject(o, "vertices_generated");
    for (size_t c = 0; gen && c < sizeof criteria / sizeof criteria[0]; c++)
        cJSON_AddNumberToObject(gen, criteria[c].name, criteria[c].thesis_generated);
    cJSON_AddNumberToObject(o, "samples_percent_of_pixels_at_most", 5);
    cJSON *factor = cJSON_AddArrayToObject(o, "whitted_over_vt_time_factor");
    cJSON_AddItemToArray(factor, cJSON_CreateNumber(6.8));
    cJSON_AddItemToArray(factor, cJSON_CreateNumber(86));
    cJSON_AddNumberToObject(o, "speedup_two_cpus", 1.6);
    cJSON_AddStringToObject(o, "source", "Ullmann 2003, Fig. 5.5, 5.6, Sec. 3.2, Fig. 5.10, 5.15");
    return o;
}

static cJSON *report_root(const bvt *b)
{
    cJSON *root = bench_record_json("vt", b->threads);
    if (!root)
        return NULL;
    cJSON_AddItemToObject(root, "parameters", params_json(b));
    cJSON_AddItemToObject(root, "thesis", thesis_json());
    return root;
}

static int run(bvt *b)
{
    const bvt_args *a = b->a;
    char out[4096];
    if (!bench_out_path(a->out, "vt", out, sizeof out))
        return RL_CLI_FAIL;
    if (a->images && !cli_make_dirs(a->images))
        return RL_CLI_FAIL;
    /* The renderers first: the record is worthless without them. */
    const char *const names[] = { "vt", "whitted" };
    for (int i = 0; i < 2; i++) {
        rl_renderer *r = NULL;
        rl_clear_error();
        rl_status st = rl_renderer_create(names[i], &r);
        /* Issue 34: a --size that cannot fit is refused with the estimate
         * before the scene is loaded, not found out by the OOM killer. */
        int fits = st == RL_OK ? cli_check_frame_memory(r, a->width, a->height, RL_LAYER_COLOR, 0.0, 0.0)
                               : RL_CLI_OK;
        rl_renderer_release(r);
        if (st != RL_OK)
            return cli_fail_status(RL_CLI_FAIL, st, "bench vt");
        if (fits != RL_CLI_OK)
            return fits;
    }
    /* Every section but animation renders the table. */
    bool static_sections = wants(a, SEC_RECONSTRUCT) || wants(a, SEC_CORRECTNESS) || wants(a, SEC_HINT);
    for (int k = 0; k < SEC_ANIMATION; k++)
        static_sections = static_sections || wants(a, k);
    int rc = RL_CLI_OK;
    if (static_sections && (rc = load(table_spec(b), &b->table, &b->table_vt)) != RL_CLI_OK)
        return rc;
    if (static_sections) {
        rl_clear_error();
        rl_status st = rl_scene_get_camera(b->table, NULL, &b->table_cam);
        if (st != RL_OK)
            return cli_fail_status(RL_CLI_FAIL, st, "bench vt: table camera");
    }
    if ((wants(a, SEC_ANIMATION) || wants(a, SEC_SCENARIO) || (wants(a, SEC_HINT) && !a->quick)) &&
        (rc = load("cluster", &b->cluster, &b->cluster_vt)) != RL_CLI_OK)
        return rc;

    cJSON *root = report_root(b);
    if (!root)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    static const bench_section_fn fns[SEC_COUNT] = { sec_criteria, sec_resolution, sec_quality, sec_threads,
                                                     sec_visibility, sec_modes, sec_forced, sec_preview,
                                                     sec_reduction, sec_overdraw, sec_equal_rays,
                                                     sec_deferred, sec_animation, sec_reconstruct,
                                                     sec_correctness, sec_hint, sec_scenario };
    printf("rl bench vt: Vertex Tracing vs Whitted, %d threads, max_depth %s, area_samples %s, "
           "shadows %s", b->threads, TRACE_MAX_DEPTH, TRACE_AREA_SAMPLES, TRACE_SHADOWS);
    for (int i = 0; i < a->sets.count; i++)
        printf("%s --set %s", i ? "" : ", then", a->sets.text[i]);
    printf("\n");
    rc = bench_run_sections("vt", root, section_names, fns, SEC_COUNT, a->sections, b,
                               b->reason, b->threads, out);
    cJSON_Delete(root);
    return rc;
}

int bench_vt(int argc, char **argv)
{
    bvt_args a;
    memset(&a, 0, sizeof a);
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    bvt b;
    memset(&b, 0, sizeof b);
    b.a = &a;
    run_sets = &a.sets;
    b.threads = a.threads ? (int)a.threads : omp_get_max_threads();
    b.threads = b.threads < RL_VT_MAX_THREADS ? b.threads : RL_VT_MAX_THREADS;
    b.max_threads = a.threads ? (int)a.threads : omp_get_num_procs();
    b.max_threads = b.max_threads < RL_VT_MAX_THREADS ? b.max_threads : RL_VT_MAX_THREADS;
    if (a.quick && !a.threads)
        b.max_threads = 2;      /* threads 1 and 2 */
    b.runs = a.quick ? 1 : 2;
    rc = run(&b);
    for (int i = 0; i < b.num_refs; i++) {
        rl_image_release(b.refs[i].image);
        free(b.refs[i].mask);
    }
    rl_scene_release(b.table);
    rl_scene_release(b.cluster);
    free(b.table_vt);
    free(b.cluster_vt);
    run_sets = NULL;
    return rc;
}
