/* vt.c: renderer "vt", Vertex Tracing (Ullmann 2003, Ch. 3-4): adaptive
 * progressive ray tracing in object space, hybrid with rasterization.
 *
 * A frame (Fig. 3.17): the ID-buffer pre-pass flags the visible faces of the
 * VT objects (Sec. 3.4.1); their vertices are ray traced straight from the
 * eye (eq. 3.1, no primary intersection test) with shadow feelers and
 * recursive reflection and refraction (eq. 3.2-3.4) through the exact tracer
 * (rl_trace.h); edges are refined longest first while the chosen criteria
 * find the samples at their ends too different (Sec. 3.3.1), with forced
 * refinement (Sec. 3.3.2), the z-buffer and viewport tests on new edges
 * (Sec. 3.4.2-3.4.3), down to a minimum projected length; the result is
 * drawn by Gouraud interpolation with deferred textures (Sec. 3.5) over the
 * rasterized non-VT objects. Sampling runs in parallel (Sec. 4.4, see
 * vt_sample.c); refinement stages are described in vt_refine.c.
 *
 * VT objects (Sec. 3.5): option `objects`:
 *   auto   nodes with the attribute vt (inherited by descendants; "true"/
 *          "false"), or, when no node has it, every object with a
 *          reflective or refractive material (the thesis' choice);
 *   all / none, or a comma-separated list of node names (with descendants).
 *
 * Temporal coherence (Sec. 3.4.5): the depth-0 shadow feelers of every
 * sampled vertex are kept by vertex key and replayed in the next frame while
 * the scene and the light settings stay the same. The thesis does this for
 * the primary vertices; our keys also identify refined vertices (an edge's
 * midpoint has the same key whatever the order of splits), so they are
 * reused too. Everything view-dependent is traced anew. Replay is exact:
 * a frame with coherence is bit-identical to one without.
 *
 * Collision detection (Sec. 3.4.4, the thesis' OOB hierarchy for ray-object
 * intersection) is the accel option: any rl_accel, BVH by default. Its
 * speed-ups of Sec. 6.2.2 are options, both exact: hint (a refined vertex's
 * rays test its parents' hit triangles first, trace.c) and presort (a
 * stage's vertices sampled in object and Morton order, vt_sample.c).
 *
 * reconstruct = gl (device: the EGL device) draws the image, the non-VT
 * objects and the refined mesh with its deferred textures, with a GL
 * drawer of src/gl (vt_draw.c; docs/gl.md) kept while scene, objects,
 * shading and device stay; the pre-pass and the refinement stay on the
 * CPU, so the refined mesh is the software path's. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif
#if defined(__GLIBC__)
#include <malloc.h>
#endif

#include "core/error.h"
#include "render/accel_cache.h"
#include "render/renderer.h"
#include "render/tracer_options.h"
#include "render/vt_part.h"
#include "render/vt_run.h"
#include "rl/rl_gl.h"
#include "rl/rl_timer.h"
#include "rl/rl_vt.h"

static const char *const criteria_choices[] = { "rgb", "hsv", "tree", "tree+rgb", "tree+hsv", NULL };
static const char *const texture_choices[] = { "multitexture", "multipass", "sampled", NULL };
static const char *const progressive_choices[] = { "none", "overdraw", "redraw", NULL };
static const char *const shading_choices[] = { "flat", "gouraud", "textured", NULL };
static const char *const overlay_choices[] = { "none", "wire", "samples", NULL };
static const char *const reconstruct_choices[] = { "software", "gl", NULL };
static const char *const balance_choices[] = { "queue", "precompute", NULL };
static const char *const cost_choices[] = { "faces", "estimate", NULL };
static const char *const nonlinear_choices[] = { "off", "extremum", "interval", "derivative", "affine", NULL };   /* VT_NONLINEAR_* */
static const char *const shaft_choices[] = { "off", "shadow", "all", NULL };
static const char *const hint_choices[] = { "off", "agree", "parents", NULL };   /* VT_HINT_* */
static const char *const tree_shadow_choices[] = { "blocked", "visible", "occluder", "none", NULL };   /* VT_TREE_SHADOW_* */
static const char *const pixel_split_choices[] = { "off", "inside", "both", NULL };   /* VT_PIXEL_SPLIT_* */
enum { RECONSTRUCT_SOFTWARE, RECONSTRUCT_GL };

static const rl_option_info vt_options[] = {
    { "objects", RL_OPT_STRING, "auto",
      "VT objects: auto (attribute vt, else reflective/refractive objects), all, none, or node names a,b,c",
      0, 0, NULL },
    { "criteria", RL_OPT_ENUM, "tree+hsv", "subdivision criteria (Sec. 3.3.1), combined with OR",
      0, 0, criteria_choices },
    { "eps_rgb", RL_OPT_FLOAT, "0.1", "RGB: L1 distance of display values (0..3) that splits an edge", 0, 3, NULL },
    { "eps_h", RL_OPT_FLOAT, "0.05", "HSV: hue difference (fraction of the circle) that splits", 0, 0.5, NULL },
    { "eps_s", RL_OPT_FLOAT, "0.1", "HSV: saturation difference that splits", 0, 1, NULL },
    { "eps_v", RL_OPT_FLOAT, "0.05", "HSV: value difference that splits", 0, 1, NULL },
    { "min_edge", RL_OPT_FLOAT, "1", "minimum projected edge length in pixels: shorter edges are not split",
      0.25, 1e6, NULL },
    { "forced", RL_OPT_BOOL, "true", "forced refinement of compressed triangles (Sec. 3.3.2)", 0, 0, NULL },
    { "eps_z", RL_OPT_FLOAT, "0.999", "forced refinement threshold on xi = c / (a + b)", 0.5, 1, NULL },
    { "id_test", RL_OPT_BOOL, "true", "ID-buffer visibility pre-pass (Sec. 3.4.1; false: all faces)", 0, 0, NULL },
    { "z_test", RL_OPT_BOOL, "true", "z-buffer test of new edges (Sec. 3.4.2)", 0, 0, NULL },
    { "clip_test", RL_OPT_BOOL, "true", "viewport test of new edges (Sec. 3.4.3)", 0, 0, NULL },
    { "merge_px", RL_OPT_FLOAT, "0",
      "sample reduction (Sec. 6.2.1): the ends of a primary edge projected shorter than this many pixels "
      "share one sample (0 = off; the thesis suggests <= 1)", 0, 16, NULL },
    { "nonlinear", RL_OPT_ENUM, "off",
      "Sec. 6.1.1, highlights between an edge's samples: off | extremum (split where a light's diffuse or "
      "specular peak lies between the ends, eq. 6.4-6.5) | interval (split where interval arithmetic bounds the "
      "interpolation error of the local Phong term above eps_ia, Fig. 6.4) | derivative (split where the slope "
      "of a light's diffuse or specular term along the edge changes sign, eq. 6.3) | affine (as interval, in "
      "affine arithmetic [CS93]: a tighter bound)", 0, 0, nonlinear_choices },
    { "eps_ia", RL_OPT_FLOAT, "0.05",
      "nonlinear=interval|affine: bound eps_IA on the interpolation error (linear radiance, sum over lights) "
      "that splits",
      1e-4, 1e6, NULL },
    { "shaft_cull", RL_OPT_ENUM, "off",
      "Sec. 6.1.2, small occluders between an edge's samples: off | shadow (split the edges of a face whose "
      "shaft to a light holds another object's triangles, [HW91], Fig. 6.6a) | all (also its reflection and "
      "transmission shafts, Fig. 6.6b)", 0, 0, shaft_choices },
    { "hint", RL_OPT_ENUM, "off",
      "intersection hints (Sec. 3.3.1, 6.2.2): a refined vertex's rays first test the triangles its parent "
      "vertices' rays hit: off | agree (parents whose ray trees name the same triangles) | parents (both "
      "parents' triangles, ray by ray); exact: the image does not change", 0, 0, hint_choices },
    { "presort", RL_OPT_BOOL, "false",
      "ray presorting (Sec. 6.2.2): sample the vertices of a refinement stage by VT object and along a "
      "Morton curve on the screen; the image does not change", 0, 0, NULL },
    { "tree_shadow", RL_OPT_ENUM, "blocked",
      "ray-tree criterion (Sec. 3.3.1), the shadow feelers' nodes: blocked (one per feeler sent: the light lit "
      "or blocked) | visible (only lights the feeler reaches: a blocked light and one behind the surface are "
      "alike) | occluder (blocked feelers name their occluder) | none (no light nodes)", 0, 0,
      tree_shadow_choices },
    { "tree_depth", RL_OPT_INT, "0",
      "ray-tree criterion: compare the rays down to this recursion depth and the feelers of their hits "
      "(0 = the whole tree)", 0, 64, NULL },
    { "deferred_split", RL_OPT_BOOL, "false",
      "the criteria also see the deferred reflected and transmitted textures, looked up at the vertices "
      "(ours, against the distortion of Fig. 5.8; false: the thesis, Sec. 3.5.3, refines on untextured "
      "radiance)", 0, 0, NULL },
    { "pixel_split", RL_OPT_ENUM, "off",
      "ours, against Gouraud ramps over the last face at a discontinuity (Sec. 3.5): an edge at or below "
      "min_edge whose ends a criterion tells apart is still split, down to pixel_floor, where one of its faces "
      "holds a pixel centre (inside) or pixel centres on both sides of the split (both); off: the thesis, "
      "nothing below min_edge", 0, 0, pixel_split_choices },
    { "pixel_floor", RL_OPT_FLOAT, "0.25", "pixel_split: edges this short or shorter are not split (px)",
      0.05, 1e6, NULL },
    { "textures", RL_OPT_ENUM, "multitexture",
      "deferred textures: multitexture (eq. 3.20, one pass), multipass (eq. 3.22), sampled (no deferral)",
      0, 0, texture_choices },
    { "defer_through", RL_OPT_BOOL, "true",
      "deferred textures pass through untextured glass and mirrors to the textured surface behind (ours; "
      "false: the thesis, first surface only)", 0, 0, NULL },
    { "progressive", RL_OPT_ENUM, "none", "intermediate images for the update callback (Sec. 3.5.1)",
      0, 0, progressive_choices },
    { "update_every", RL_OPT_INT, "1", "k: refinement stages between progressive updates", 1, 1000000, NULL },
    { "overdraw_f", RL_OPT_FLOAT, "0.0001", "f of eq. 3.14: overdraw offset per stage towards the eye",
      0, 0.01, NULL },
    { "coherence", RL_OPT_BOOL, "true", "reuse shadow feelers between frames (Sec. 3.4.5)", 0, 0, NULL },
    { "max_vertices", RL_OPT_INT, "16000000", "refinement stops when the mesh has this many vertices",
      100, 1000000000, NULL },
    { "overlay", RL_OPT_ENUM, "none", "draw the refined mesh (wire) or samples by reason over the image",
      0, 0, overlay_choices },
    { "shading", RL_OPT_ENUM, "textured", "shading of the rasterized non-VT objects", 0, 0, shading_choices },
    { "reconstruct", RL_OPT_ENUM, "software",
      "drawing of the image (Sec. 3.5): software (the CPU rasterizer) | gl (OpenGL 4.5, docs/gl.md)", 0, 0,
      reconstruct_choices },
    { "device", RL_OPT_STRING, "", "reconstruct=gl: EGL device auto, surfaceless or a number; empty: "
      "$RL_EGL_DEVICE, else auto", 0, 0, NULL },
    { "balance", RL_OPT_ENUM, "queue",
      "rl --dist: load balancing of the face packages (Sec. 4.3.3): queue (equal packages on demand, Fig. 4.8) "
      "| precompute (one package per rank, sized by its measured speed)", 0, 0, balance_choices },
    { "package", RL_OPT_INT, "0",
      "rl --dist, balance=queue: visible primary faces per package (0: 1/32 of an equal share per rank)",
      0, 1000000000, NULL },
    { "cost", RL_OPT_ENUM, "faces",
      "rl --dist, balance=precompute: what the packages share by speed: faces (visible primary faces) | estimate "
      "(the thesis' per-face cost b_f from the primary vertices' samples, Sec. 4.3.3)", 0, 0, cost_choices },
    { "dist_halo", RL_OPT_BOOL, "true",
      "rl --dist: a package also flags the visible faces around it, so that forced refinement crosses package "
      "borders as in one process (Sec. 4.3.3)", 0, 0, NULL },
    { "dist_postpass", RL_OPT_BOOL, "false",
      "rl --dist: the master's post-pass (Sec. 6.1.3): it replays one process' refinement over the packages' "
      "samples and traces what differs at package borders, so the image is the one-process image; the parts "
      "carry every sample (20 bytes more a vertex)", 0, 0, NULL },
    { "dist_overlap", RL_OPT_FLOAT, "0",
      "rl --dist with dist_postpass: the master, with no package left to refine, starts the post-pass once at "
      "most this share of the visible faces is still out; it takes their samples as their parts come and traces "
      "what is not in yet (the same samples: the same image, more rays); 0: after the last part", 0, 1, NULL },
    RL_TRACER_OPTION_ROWS,
};

typedef struct vt_state {
    rl_accel_cache accel;
    /* the VT meshes, kept while the scene and the object selection stay */
    uint64_t mesh_scene;
    char *mesh_objects;
    uint8_t *object_vt, *object_raster;
    vt_mesh mesh;                 /* its tri_face maps triangles to primary faces */
    bool mesh_valid;
    vt_heap heap;
    /* temporal coherence */
    vt_feeler_map feelers;
    uint64_t feelers_scene;
    uint64_t feelers_signature;
    /* the last frame */
    bool have_frame;
    rl_vt_stats stats;
    /* rl_vt_get_mesh's copy of the refined mesh, made when first asked
     * for: every frame copying it would add 36 bytes per vertex to the
     * frame's peak for a view few callers take */
    bool have_copy;
    rl_vt_vertex_info *vinfo;
    uint32_t *finfo;
    size_t num_vinfo, num_finfo;
    uint8_t *reason;          /* per vertex of the mesh (run->reason's) */
    uint32_t num_reason;
    rl_vt_update_fn update;
    void *update_user;
    /* frame buffers kept across frames, so that a frame does not fault in
     * fresh pages (a 1024² frame touches tens of MB) */
    rl_raster *ras;
    int ras_threads;
    rl_drawer *gl;            /* reconstruct = gl, on gl_device */
    char gl_device[64];
    rl_image *depth_ids;      /* the pre-pass' depth */
    uint32_t *prepass_ids;    /* the pre-pass' triangle IDs, width*height,
                               * kept between frames while they are small
                               * (small_frames), else made for each pre-pass */
    size_t prepass_pixels;
    bool small_frames;        /* the last frame generated fewer than
                               * VT_LARGE_FRAME_VERTICES vertices */
    float *scratch_depth;     /* the frame's depth when the image has none */
    size_t scratch_pixels;
    vt_corners corners;
    vt_base base;             /* progressive frames' copy of the rasterized half */
    /* distributed frames (rl_vt_prepare): the pre-pass kept for the camera
     * in depth_ids, with what it was made for */
    bool prepared;
    rl_camera prep_cam;
    int prep_width, prep_height;
    uint64_t prep_scene;
    char *prep_signature;
    uint8_t *prep_visible;    /* per primary face: passed the ID test */
    uint32_t *prep_list;      /* the visible ones, ascending */
    size_t prep_count;
    uint8_t *package;         /* per primary face: in the package being refined */
    /* the master's post-pass (dist_postpass): the samples of the parts
     * added so far (rl_vt_postpass_add), by vertex key; it points into
     * the caller's parts and is emptied after every post-pass drawing */
    vt_part_samples pp_map;
} vt_state;

/* Temporal coherence (Sec. 3.4.5) is the only state a frame leaves for the
 * next one; the BVH is per scene and stays. */
static void vt_reset(void *state)
{
    vt_state *s = state;
    if (s)
        vt_feeler_map_free(&s->feelers);
}

static void vt_release(void *state)
{
    vt_state *s = state;
    rl_accel_cache_release(&s->accel);
    free(s->mesh_objects);
    free(s->object_vt);
    free(s->object_raster);
    vt_mesh_free(&s->mesh);
    vt_heap_free(&s->heap);
    vt_feeler_map_free(&s->feelers);
    free(s->vinfo);
    free(s->finfo);
    free(s->reason);
    rl_raster_release(s->ras);
    rl_drawer_release(s->gl);
    rl_image_release(s->depth_ids);
    free(s->prepass_ids);
    free(s->scratch_depth);
    vt_corners_free(&s->corners);
    vt_base_free(&s->base);
    free(s->prep_signature);
    free(s->prep_visible);
    free(s->prep_list);
    free(s->package);
    vt_part_samples_free(&s->pp_map);
}

/* The kept rasterizer, pre-pass image and scratch depth (for an image
 * without a depth layer), (re)made when the thread count or the frame size
 * changed. */
static rl_status frame_buffers(vt_state *s, int threads, const rl_image *image)
{
    const int width = image->width, height = image->height;
    const size_t n = (size_t)width * (size_t)height;
    if ((!(image->layers & RL_LAYER_DEPTH) || !image->depth) && s->scratch_pixels != n) {
        free(s->scratch_depth);
        s->scratch_pixels = 0;
        if (!(s->scratch_depth = rl_realloc_array(NULL, n, sizeof *s->scratch_depth)))
            return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: depth of %dx%d pixels", width, height);
        s->scratch_pixels = n;
    }
    rl_status st;
    if (!s->ras || s->ras_threads != threads) {
        rl_raster_release(s->ras);
        s->ras = NULL;
        if ((st = rl_raster_create(&(rl_raster_desc){ .threads = threads }, &s->ras)) != RL_OK)
            return st;
        s->ras_threads = threads;
    }
    if (!s->depth_ids || s->depth_ids->width != width || s->depth_ids->height != height) {
        rl_image_release(s->depth_ids);
        s->depth_ids = NULL;
        if ((st = rl_image_create(width, height, RL_LAYER_DEPTH, &s->depth_ids)) != RL_OK)
            return st;
    }
    return RL_OK;
}

static rl_status vt_check(const char *key, const char *value)
{
    if (strcmp(key, "objects") == 0 && value[0] == '\0')
        return rl_error(RL_ERR_INVALID_ARG, "vt: objects must be auto, all, none or a list of node names");
    return rl_tracer_options_check("vt", key, value);
}

/* ------------------------------------------------------- VT objects -- */

/* The vt attribute of node or its nearest ancestor that has one: 1 true,
 * 0 false, -1 none. */
static int vt_attr(const rl_scene *scene, uint32_t node)
{
    for (uint32_t n = node; n != RL_NONE; n = rl_scene_node_parent(scene, n)) {
        const char *a = rl_scene_node_attr(scene, n, "vt");
        if (a)
            return strcmp(a, "true") == 0 || strcmp(a, "1") == 0 || strcmp(a, "yes") == 0;
    }
    return -1;
}

static bool under(const rl_scene *scene, uint32_t node, uint32_t ancestor)
{
    for (uint32_t n = node; n != RL_NONE; n = rl_scene_node_parent(scene, n))
        if (n == ancestor)
            return true;
    return false;
}

static rl_status select_objects(const rl_scene *scene, const rl_scene_data *d, const char *spec, uint8_t *vt)
{
    memset(vt, 0, d->num_objects);
    if (strcmp(spec, "none") == 0)
        return RL_OK;
    if (strcmp(spec, "all") == 0) {
        memset(vt, 1, d->num_objects);
        return RL_OK;
    }
    if (strcmp(spec, "auto") == 0) {
        bool any_attr = false;
        for (uint32_t o = 0; o < d->num_objects; ++o) {
            int a = vt_attr(scene, d->objects[o].node);
            any_attr |= a >= 0;
            vt[o] = a > 0;
        }
        if (any_attr)
            return RL_OK;
        /* Sec. 3.5: specular objects are the VT objects. */
        for (uint32_t o = 0; o < d->num_objects; ++o) {
            const rl_object *obj = &d->objects[o];
            for (uint32_t t = obj->first_triangle; t < obj->first_triangle + obj->num_triangles && !vt[o]; ++t) {
                const rl_material *m = &d->materials[d->triangle_material[t]];
                vt[o] = m->reflectivity > 0.0f || m->transmissivity > 0.0f;
            }
        }
        return RL_OK;
    }
    /* A list of node names, each with its subtree. */
    const char *p = spec;
    while (*p) {
        const char *end = strchr(p, ',');
        size_t len = end ? (size_t)(end - p) : strlen(p);
        char name[256];
        if (len == 0 || len >= sizeof name)
            return rl_error(RL_ERR_INVALID_ARG, "vt: objects: empty or overlong node name in \"%s\"", spec);
        memcpy(name, p, len);
        name[len] = '\0';
        uint32_t node = rl_scene_find_node(scene, name);
        if (node == RL_NONE)
            return rl_error(RL_ERR_NOT_FOUND, "vt: objects: no node named \"%s\" in scene \"%s\"", name,
                            rl_scene_name(scene));
        for (uint32_t o = 0; o < d->num_objects; ++o)
            if (under(scene, d->objects[o].node, node))
                vt[o] = 1;
        p = end ? end + 1 : p + len;
    }
    return RL_OK;
}

/* Rebuilds the VT meshes when the scene or the selection changed. */
static rl_status ensure_mesh(vt_state *s, const rl_scene *scene, const rl_scene_data *d, const char *spec,
                             bool *built)
{
    uint64_t uid = rl_scene_uid(scene);
    if (s->mesh_valid && s->mesh_scene == uid && s->mesh_objects && strcmp(s->mesh_objects, spec) == 0)
        return RL_OK;
    *built = true;
    s->mesh_valid = false;
    free(s->object_vt);
    free(s->object_raster);
    free(s->mesh_objects);
    s->object_raster = s->object_vt = NULL;
    s->mesh_objects = NULL;
    vt_mesh_free(&s->mesh);
    size_t no = d->num_objects ? d->num_objects : 1;
    s->object_vt = rl_calloc(no, 1);
    s->object_raster = rl_calloc(no, 1);
    size_t len = strlen(spec);
    s->mesh_objects = malloc(len + 1);
    if (!s->object_vt || !s->object_raster || !s->mesh_objects)
        return RL_ERR_OUT_OF_MEMORY;
    memcpy(s->mesh_objects, spec, len + 1);
    rl_status st = select_objects(scene, d, spec, s->object_vt);
    if (st == RL_OK)
        st = vt_mesh_build(&s->mesh, d, s->object_vt);
    if (st != RL_OK)
        return st;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        s->object_raster[o] = !s->object_vt[o];
    s->mesh_scene = uid;
    s->mesh_valid = true;
    return RL_OK;
}

/* ------------------------------------------------------------- frame -- */

static bool build_progress(void *user, double done)
{
    bool go_on;
#pragma omp critical(rl_vt_progress)
    go_on = rl_renderer_progress(user, 0.05 * done);
    return go_on;
}

static void read_settings(rl_renderer *r, vt_settings *set)
{
    memset(set, 0, sizeof *set);
    vt_criteria_parse(criteria_choices[rl_renderer_opt_enum(r, "criteria")], &set->criteria.bits);
    set->criteria.eps_rgb = (float)rl_renderer_opt_float(r, "eps_rgb");
    set->criteria.eps_h = (float)rl_renderer_opt_float(r, "eps_h");
    set->criteria.eps_s = (float)rl_renderer_opt_float(r, "eps_s");
    set->criteria.eps_v = (float)rl_renderer_opt_float(r, "eps_v");
    set->min_edge = (float)rl_renderer_opt_float(r, "min_edge");
    set->forced = rl_renderer_opt_bool(r, "forced");
    set->eps_z = (float)rl_renderer_opt_float(r, "eps_z");
    set->id_test = rl_renderer_opt_bool(r, "id_test");
    set->z_test = rl_renderer_opt_bool(r, "z_test");
    set->clip_test = rl_renderer_opt_bool(r, "clip_test");
    set->merge_px = (float)rl_renderer_opt_float(r, "merge_px");
    set->nonlinear = rl_renderer_opt_enum(r, "nonlinear");
    set->eps_ia = (float)rl_renderer_opt_float(r, "eps_ia");
    set->shaft_cull = rl_renderer_opt_enum(r, "shaft_cull");
    set->textures = rl_renderer_opt_enum(r, "textures");
    set->progressive = rl_renderer_opt_enum(r, "progressive");
    set->update_every = (int)rl_renderer_opt_int(r, "update_every");
    set->overdraw_f = (float)rl_renderer_opt_float(r, "overdraw_f");
    set->coherence = rl_renderer_opt_bool(r, "coherence");
    set->max_vertices = (uint32_t)rl_renderer_opt_int(r, "max_vertices");
    int threads = (int)rl_renderer_opt_int(r, "threads");
#ifdef _OPENMP
    set->threads = threads > 0 ? threads : omp_get_max_threads();
#else
    (void)threads;
    set->threads = 1;
#endif
    if (set->threads > RL_VT_MAX_THREADS)
        set->threads = RL_VT_MAX_THREADS;
    set->shading = (rl_raster_shading)rl_renderer_opt_enum(r, "shading");
    set->ambient = (float)rl_renderer_opt_float(r, "ambient");
    set->background = rl_renderer_opt_color(r, "background");
    set->overlay = rl_renderer_opt_enum(r, "overlay");
    set->hint = rl_renderer_opt_enum(r, "hint");
    set->presort = rl_renderer_opt_bool(r, "presort");
    set->tree_shadow = rl_renderer_opt_enum(r, "tree_shadow");
    set->tree_depth = (int)rl_renderer_opt_int(r, "tree_depth");
    set->deferred_split = rl_renderer_opt_bool(r, "deferred_split");
    set->pixel_split = rl_renderer_opt_enum(r, "pixel_split");
    set->pixel_floor = (float)rl_renderer_opt_float(r, "pixel_floor");
}

/* What the cached feelers depend on besides the scene. */
static uint64_t feeler_signature(const rl_tracer_desc *desc)
{
    return ((uint64_t)(unsigned)desc->area_samples << 8) ^ (desc->no_shadows ? 1u : 0u) ^
           (desc->no_transmitted_highlight ? 2u : 0u) ^ (desc->tree_shadow_any_hit ? 0u : 4u) ^
           (desc->seed << 20);
}

/* Keeps this frame's feelers for the next one (the map takes the frame's
 * pool of occluders over). */
static rl_status keep_feelers(vt_state *s, vt_run *run)
{
    return vt_feeler_map_rebuild(&s->feelers, run->mesh, run->feelers, &run->feeler_pool);
}

/* The last frame goes: the mesh will be reset, so its copy for
 * rl_vt_get_mesh and the vertices' reasons are dropped too. */
static void forget_frame(vt_state *s)
{
    s->have_frame = false;
    s->have_copy = false;
    free(s->vinfo);
    free(s->finfo);
    free(s->reason);
    s->vinfo = NULL;
    s->finfo = NULL;
    s->reason = NULL;
    s->num_vinfo = s->num_finfo = 0;
    s->num_reason = 0;
}

/* Keeps what rl_vt_get_mesh needs of the frame besides the mesh: the
 * reasons the run recorded (taken over, not copied). */
static void keep_mesh(vt_state *s, vt_run *run)
{
    free(s->reason);
    s->reason = run->reason;
    s->num_reason = run->reason ? run->per_vertex_cap : 0;
    run->reason = NULL;       /* per_vertex_cap stays: it sizes the feelers */
}

/* Copies the refined mesh out for rl_vt_get_mesh. */
static bool pick_leaf(const void *user, const vt_face *f)
{
    (void)user;
    return f->leaf;
}

static rl_status copy_mesh(vt_state *s)
{
    const vt_mesh *m = &s->mesh;
    /* The leaves in creation order (vt_mesh.drop_parents reuses slots). */
    uint32_t *order = NULL;
    size_t order_cap = 0, faces = 0;
    if (vt_mesh_pick_in_order(m, pick_leaf, NULL, &order, &order_cap, &faces) != RL_OK)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_vt_get_mesh: %u faces", m->num_faces);
    rl_vt_vertex_info *vi = rl_realloc_array(s->vinfo, m->num_verts ? m->num_verts : 1, sizeof *vi);
    if (!vi) {
        free(order);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_vt_get_mesh: %u vertices", m->num_verts);
    }
    s->vinfo = vi;
    uint32_t *fi = rl_realloc_array(s->finfo, faces ? 3 * faces : 1, sizeof *fi);
    if (!fi) {
        free(order);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_vt_get_mesh: %zu faces", faces);
    }
    s->finfo = fi;
    for (uint32_t v = 0; v < m->num_verts; ++v) {
        const vt_vertex *x = &m->verts[v];
        vi[v] = (rl_vt_vertex_info){ x->sx, x->sy, x->stage, x->state == VT_SAMPLED,
                                     v < s->num_reason ? s->reason[v] : 0 };
    }
    size_t k = 0;
    for (size_t i = 0; i < faces; ++i)
        for (int j = 0; j < 3; ++j)
            fi[k++] = m->faces[order[i]].v[j];
    free(order);
    s->num_vinfo = m->num_verts;
    s->num_finfo = faces;
    s->have_copy = true;
    return RL_OK;
}

/* The frame's tracer (exact shading, eq. 3.1-3.4, 3.17), the kept
 * structures made or reused for the scene, and the feeler cache forgotten
 * when what the feelers depend on changed (Sec. 3.4.5). *prep_ms: the time
 * building the kept structures took (0 when they were reused). */
static rl_status prepare_tracer(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_scene_data *d,
                                const vt_settings *set, rl_tracer **tracer, double *prep_ms)
{
    rl_accel_kind kind;
    rl_tracer_desc desc;
    rl_status st = rl_tracer_options_read(r, &desc, &kind);
    if (st != RL_OK)
        return st;
    /* Shadow nodes say lit or blocked (Sec. 3.3.1), unless the occluder
     * reading asks for the occluder's identity (a full search per feeler). */
    desc.tree_shadow_any_hit = set->tree_shadow != VT_TREE_SHADOW_OCCLUDER;
    desc.defer_through = rl_renderer_opt_bool(r, "defer_through");
    double accel_ms = 0.0;
    if ((st = rl_accel_cache_get(&s->accel, "vt", scene, kind, set->threads, build_progress, r, &accel_ms)) !=
        RL_OK)
        return st;
    bool built = false;
    rl_timer t;
    rl_timer_start(&t);
    if ((st = ensure_mesh(s, scene, d, rl_renderer_opt_string(r, "objects"), &built)) != RL_OK)
        return st;
    *prep_ms = accel_ms + (built ? rl_timer_ms(&t) : 0.0);
    if ((st = rl_tracer_create(s->accel.accel, &desc, tracer)) != RL_OK)
        return st;
    uint64_t signature = feeler_signature(&desc);
    if (!set->coherence || s->feelers_scene != rl_scene_uid(scene) || s->feelers_signature != signature) {
        vt_feeler_map_free(&s->feelers);
        s->feelers_scene = rl_scene_uid(scene);
        s->feelers_signature = signature;
    }
    return RL_OK;
}

/* A frame's run over the kept state: the camera's matrices and the view
 * the visibility tests use (Sec. 3.4), the state's buffers. */
static void setup_run(vt_run *run, rl_renderer *r, vt_state *s, const rl_scene_data *d, const vt_settings *set,
                      rl_tracer *tracer, rl_camera *cam, rl_image *image)
{
    memset(run, 0, sizeof *run);
    run->t_start_ms = rl_time_s() * 1000.0;
    run->set = set;
    run->data = d;
    run->tracer = tracer;
    run->mesh = &s->mesh;
    run->heap = &s->heap;
    run->object_vt = s->object_vt;
    run->object_raster = s->object_raster;
    run->tri_face = s->mesh.tri_face;
    run->want_tree = (set->criteria.bits & VT_CRIT_TREE) != 0;
    run->feeler_pool.mapped = run->hint_pool.mapped = true;
    run->cache = set->coherence && s->feelers.count ? &s->feelers : NULL;
    run->renderer = r;
    run->update = s->update;
    run->update_user = s->update_user;
    run->image = image;
    run->camera = cam;

    float z_near = cam->z_near, z_far = cam->z_far;
    if (!(z_near > 0.0f))
        rl_camera_clip_range(cam, d->bounds, &z_near, &z_far);
    run->view_m = rl_camera_view(cam);
    run->proj_m = rl_camera_projection(cam, z_near, z_far);
    run->view = (vt_view){
        .view_proj = rl_mat4_mul(&run->proj_m, &run->view_m),
        .eye = cam->eye,
        .forward = rl_normalize(rl_sub(cam->target, cam->eye)),
        .width = image->width,
        .height = image->height,
        .z_near = z_near,
        .depth = NULL,
        .depth_tolerance = 1e-3f,
    };
    run->stats.threads = (uint32_t)set->threads;
    run->stats.primary_vertices = s->mesh.num_primary_verts;
    run->stats.primary_faces = s->mesh.num_primary_faces;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        run->stats.vt_objects += s->object_vt[o];
}

/* reconstruct = gl: the kept GL drawer, made anew where it does not fit
 * (another scene, object selection, shading, ID layer or device). */
static rl_status gl_drawer_for(rl_renderer *r, vt_state *s, const rl_scene *scene, const vt_settings *set,
                               const rl_image *image, rl_drawer **out)
{
    *out = NULL;
    if (rl_renderer_opt_enum(r, "reconstruct") != RECONSTRUCT_GL)
        return RL_OK;
    const char *device = rl_renderer_opt_string(r, "device");
    if (strlen(device) >= sizeof s->gl_device)
        return rl_error(RL_ERR_INVALID_ARG, "vt: device \"%.40s...\" is too long", device);
    const bool ids = (image->layers & RL_LAYER_ID) && image->object_id && image->triangle_id;
    rl_drawer_desc desc = { .shading = set->shading, .ambient = set->ambient,
                            .flags = ids ? 0u : RL_RASTER_NO_ID, .object_mask = s->object_raster };
    if (!s->gl || !rl_drawer_fits(s->gl, scene, &desc) || strcmp(s->gl_device, device) != 0) {
        rl_drawer_release(s->gl);
        s->gl = NULL;
        rl_status st = rl_gl_drawer_create(scene, &desc, device, &s->gl);
        if (st != RL_OK)
            return st;
        snprintf(s->gl_device, sizeof s->gl_device, "%s", device);
    }
    *out = s->gl;
    return RL_OK;
}

/* Unavailable with reconstruct = gl where no GL 4.5 context can be made. */
static bool vt_available(const rl_renderer *r, char *why, size_t n)
{
    if (rl_renderer_opt_enum(r, "reconstruct") != RECONSTRUCT_GL)
        return true;
    char reason[400];
    if (rl_gl_available(rl_renderer_opt_string(r, "device"), reason, sizeof reason))
        return true;
    if (why && n)
        snprintf(why, n, "reconstruct=gl: %s", reason);
    return false;
}

/* Hands freed heap pages back to the system (glibc keeps freed chunks
 * below the top of the heap resident); elsewhere a no-op. */
static void give_back_freed(void)
{
#if defined(__GLIBC__)
    malloc_trim(0);
#endif
}

/* Generated vertices from which a frame gives its pre-pass image, edge
 * list and draw corners back once it is done with them (run_frame). */
#define VT_LARGE_FRAME_VERTICES 65536u

/* The ID-buffer pre-pass (vt_prepass) with a triangle-ID buffer that lives
 * only as long as it is read, unless the last frame was small: a frame
 * that refines far peaks later, with the whole mesh, and has no use for 4
 * bytes a pixel meanwhile (4 MB at 1024^2); small frames of a preview keep
 * it instead of faulting it in again. */
static rl_status run_prepass(vt_state *s, vt_run *run)
{
    const size_t n = (size_t)s->depth_ids->width * (size_t)s->depth_ids->height;
    if (s->prepass_pixels != n) {
        free(s->prepass_ids);
        s->prepass_pixels = 0;
        if (!(s->prepass_ids = rl_realloc_array(NULL, n ? n : 1, sizeof *s->prepass_ids)))
            return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: triangle IDs of %zu pixels", n);
        s->prepass_pixels = n;
    }
    rl_status st = vt_prepass(run, s->depth_ids, s->prepass_ids);
    if (!s->small_frames) {
        free(s->prepass_ids);
        s->prepass_ids = NULL;
        s->prepass_pixels = 0;
    }
    return st;
}

/* Fig. 3.17: the ID/Z pre-pass with the rasterized half, the refinement
 * with its sampling, the final draw; then what the next frame keeps
 * (feelers, the refined mesh). */
static rl_status run_frame(vt_run *run, vt_state *s, const vt_settings *set, rl_image *image)
{
    rl_status st = vt_run_reserve(run);
    if (st == RL_OK)
        st = frame_buffers(s, set->threads, image);
    run->ras = s->ras;
    run->corners = &s->corners;
    run->scratch_depth = s->scratch_depth;
    run->base = &s->base;
    double t0 = rl_time_s() * 1000.0;
    if (st == RL_OK)
        st = run_prepass(s, run);
    /* The rasterizer is not used again until the final draw unless an
     * update callback draws meanwhile. Its scratch (set-up triangles of
     * the pre-pass' largest draw, their bins, clip-space vertices) and the
     * scene drawer's freed buffers would stay resident through a long
     * refinement, to its end, where such a frame peaks with the whole mesh;
     * a frame expected to refine far (as the pre-pass image, s->small_frames)
     * gives them back and makes a rasterizer anew for the final draw
     * (bench/README.md, "Memory, fourth pass"). */
    const bool drop_raster = st == RL_OK && !s->small_frames && !run->update;
    /* So does the frame's depth where the image has none (the scratch
     * depth, 4 MB at 1024^2): it holds the rasterized half's depth, which
     * only the final draw reads again. That half (Fig. 3.17) is drawn again
     * before the final draw instead, the same pixels (the draw is
     * deterministic), its counters not counted twice: a few tens of ms of a
     * frame that samples for seconds. */
    const bool drop_base = drop_raster && !run->drawer && s->scratch_depth &&
                           (!(image->layers & RL_LAYER_DEPTH) || !image->depth);
    if (drop_raster) {
        rl_raster_release(s->ras);
        s->ras = run->ras = NULL;
        if (drop_base) {
            free(s->scratch_depth);
            s->scratch_depth = run->scratch_depth = NULL;
            s->scratch_pixels = 0;
        }
        give_back_freed();
    }
    /* The rasterized half drawn inside the pre-pass counts as drawing. */
    run->stats.time_visibility_ms = rl_time_s() * 1000.0 - t0 - run->stats.time_draw_ms;
    if (st == RL_OK)
        st = vt_refine(run);
    run->stats.mesh_bytes = vt_mesh_bytes(run->mesh);
    /* A frame that refined far keeps its buffers only as long as it needs
     * them: the peak is at the frame's end, with the whole mesh, the draw's
     * corners and the feeler map being rebuilt (heaptrack). The pre-pass
     * image (12 MB at 1024^2) and the emptied edge list are not read after
     * the refinement (a distributed frame's pre-pass is made again after a
     * frame, s->prepared), the corners not after the final draw. Faulting
     * them in again costs the next frame a few ms, where a frame of this
     * size samples for seconds; a small frame keeps them (warm frames of
     * an interactive preview). */
    const bool large = run->mesh->num_verts - run->mesh->num_primary_verts >= VT_LARGE_FRAME_VERTICES;
    s->small_frames = !large;
    if (large) {
        rl_image_release(s->depth_ids);
        s->depth_ids = NULL;
        run->view.depth = NULL;
        vt_heap_free(run->heap);
        /* The refined edges too (a quarter of the mesh, 29 MB at the
         * defaults at 1024^2): the draw and the feeler map read vertices,
         * samples and faces only, and the next frame starts from the
         * primary edges (vt_mesh_reset). */
        vt_mesh_drop_refined_edges(run->mesh);
        give_back_freed();
    }
    if (st == RL_OK && !s->ras) {
        st = rl_raster_create(&(rl_raster_desc){ .threads = set->threads }, &s->ras);
        run->ras = s->ras;
    }
    if (st == RL_OK && drop_base) {
        const size_t n = (size_t)image->width * (size_t)image->height;
        if (!(s->scratch_depth = rl_realloc_array(NULL, n, sizeof *s->scratch_depth))) {
            st = rl_error(RL_ERR_OUT_OF_MEMORY, "vt: depth of %dx%d pixels", image->width, image->height);
        } else {
            s->scratch_pixels = n;
            run->scratch_depth = s->scratch_depth;
            const rl_raster_counters counted = run->counters;
            st = vt_draw_base(run);
            run->counters = counted;
        }
    }
    if (st == RL_OK) {
        double td = rl_time_s() * 1000.0;
        if (!vt_update(run, run->stats.stages, true) && run->failed)
            st = RL_ERR_OUT_OF_MEMORY;
        run->stats.time_draw_ms += rl_time_s() * 1000.0 - td;
    }
    if (large) {
        vt_corners_free(&s->corners);
        give_back_freed();
    }
    if (st == RL_OK && set->coherence)
        st = keep_feelers(s, run);
    if (st == RL_OK)
        keep_mesh(s, run);
    vt_run_free_blocks(run);
    vt_run_free_vertex_arrays(run);
    vt_feeler_pool_free(&run->feeler_pool);
    vt_feeler_pool_free(&run->hint_pool);
    free(run->sorting);
    return st;
}

static rl_status vt_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam_in,
                           rl_image *image, rl_render_stats *stats)
{
    vt_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    rl_status st = rl_camera_validate(cam_in);
    if (st != RL_OK)
        return st;
    rl_camera cam = rl_camera_resolve(cam_in);
    vt_settings set;
    read_settings(r, &set);
    forget_frame(s);
    s->prepared = false;      /* depth_ids is this frame's now */

    rl_tracer *tracer = NULL;
    if ((st = prepare_tracer(r, s, scene, d, &set, &tracer, &stats->prep_ms)) != RL_OK)
        return st;
    vt_mesh_reset(&s->mesh);
    vt_heap_clear(&s->heap);
    rl_drawer *gl = NULL;
    if ((st = gl_drawer_for(r, s, scene, &set, image, &gl)) != RL_OK) {
        rl_tracer_release(tracer);
        return st;
    }
    vt_run run;
    setup_run(&run, r, s, d, &set, tracer, &cam, image);
    run.drawer = gl;
    st = run_frame(&run, s, &set, image);
    rl_tracer_release(tracer);
    if (st != RL_OK)
        return st;

    for (int t = 0; t < set.threads && t < RL_VT_MAX_THREADS; ++t) {
        run.stats.thread_rays[t] = run.tally[t].rays;
        run.stats.thread_busy_ms[t] = run.tally[t].busy_ms;
        run.stats.feelers_reused += run.tally[t].feelers_reused;
        run.stats.hint_tests += run.tally[t].hint_tests;
        run.stats.hint_hits += run.tally[t].hint_hits;
    }
    s->stats = run.stats;
    s->have_frame = true;
    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
        stats->rays[k] = run.rays[k];
    stats->triangles_rasterized = run.counters.triangles_drawn;
    stats->pixels_written = run.counters.pixels_written;
    stats->samples = run.stats.vertices_sampled;
    if (run.cancelled)
        return rl_error(RL_ERR_CANCELLED, "vt: cancelled by the progress callback");
    return RL_OK;
}

/* ---------------------------------------------------------- accessors -- */

static vt_state *vt_of(const rl_renderer *r, const char *fn)
{
    if (!r || strcmp(rl_renderer_name(r), "vt") != 0) {
        rl_error(RL_ERR_INVALID_ARG, "%s: needs a \"vt\" renderer", fn);
        return NULL;
    }
    return rl_renderer_state(r);
}

rl_status rl_vt_get_stats(const rl_renderer *r, rl_vt_stats *out)
{
    vt_state *s = vt_of(r, "rl_vt_get_stats");
    if (!s || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_get_stats: needs a \"vt\" renderer and out");
    if (!s->have_frame)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_get_stats: no frame rendered yet");
    *out = s->stats;
    return RL_OK;
}

rl_status rl_vt_get_mesh(const rl_renderer *r, const rl_vt_vertex_info **vertices, size_t *num_vertices,
                         const uint32_t **faces, size_t *num_faces)
{
    vt_state *s = vt_of(r, "rl_vt_get_mesh");
    if (!s || !vertices || !num_vertices || !faces || !num_faces)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_get_mesh: needs a \"vt\" renderer and outputs");
    if (!s->have_frame)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_get_mesh: no frame rendered yet");
    rl_status st = s->have_copy ? RL_OK : copy_mesh(s);
    if (st != RL_OK)
        return st;
    *vertices = s->vinfo;
    *num_vertices = s->num_vinfo;
    *faces = s->finfo;
    *num_faces = s->num_finfo;
    return RL_OK;
}

rl_status rl_vt_set_update_callback(rl_renderer *r, rl_vt_update_fn fn, void *user)
{
    vt_state *s = vt_of(r, "rl_vt_set_update_callback");
    if (!s)
        return RL_ERR_INVALID_ARG;
    s->update = fn;
    s->update_user = user;
    return RL_OK;
}

/* ------------------------------------------------- distributed frames -- */

static void dist_end(vt_run *run, rl_tracer *tracer)
{
    vt_run_free_blocks(run);
    vt_run_free_vertex_arrays(run);
    vt_feeler_pool_free(&run->feeler_pool);
    vt_feeler_pool_free(&run->hint_pool);
    free(run->sorting);
    rl_tracer_release(tracer);
}

/* What the distributed entry points share: the kept structures for the
 * scene, a fresh mesh, a run over image with the kept buffers. No update
 * callback: a package is no picture, the master draws once. */
static rl_status dist_begin(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_camera *cam_in,
                            rl_image *image, vt_settings *set, rl_camera *cam, rl_tracer **tracer, vt_run *run)
{
    memset(run, 0, sizeof *run);
    *tracer = NULL;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    rl_status st = rl_camera_validate(cam_in);
    if (st != RL_OK)
        return st;
    if (image->width <= 0 || image->height <= 0 || !image->color)
        return rl_error(RL_ERR_INVALID_ARG, "vt: a distributed frame needs an image with colour");
    *cam = rl_camera_resolve(cam_in);
    read_settings(r, set);
    forget_frame(s);
    double prep_ms = 0.0;
    if ((st = prepare_tracer(r, s, scene, d, set, tracer, &prep_ms)) != RL_OK)
        return st;
    vt_mesh_reset(&s->mesh);
    vt_heap_clear(&s->heap);
    setup_run(run, r, s, d, set, *tracer, cam, image);
    run->update = NULL;
    if ((st = vt_run_reserve(run)) == RL_OK)
        st = frame_buffers(s, set->threads, image);
    run->ras = s->ras;
    run->corners = &s->corners;
    run->scratch_depth = s->scratch_depth;
    run->base = &s->base;
    return st;
}

/* The ID pre-pass for the run's camera, unless the kept one is for the
 * same scene, camera, size and options: a worker refines many packages
 * of one frame and needs the pre-pass' depth and face flags for each. */
static rl_status dist_prepass(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_camera *cam,
                              vt_run *run)
{
    char *sig = rl_renderer_option_signature(r, NULL);
    if (!sig)
        return RL_ERR_OUT_OF_MEMORY;
    if (s->prepared && s->prep_scene == rl_scene_uid(scene) && memcmp(&s->prep_cam, cam, sizeof *cam) == 0 &&
        s->prep_width == run->image->width && s->prep_height == run->image->height && s->prep_signature &&
        strcmp(sig, s->prep_signature) == 0) {
        free(sig);
        return RL_OK;
    }
    s->prepared = false;
    free(s->prep_signature);
    s->prep_signature = sig;
    const vt_mesh *m = run->mesh;
    size_t nf = m->num_primary_faces ? m->num_primary_faces : 1;
    uint8_t *vis = rl_realloc_array(s->prep_visible, nf, 1);
    if (vis)
        s->prep_visible = vis;
    uint32_t *list = rl_realloc_array(s->prep_list, nf, sizeof *list);
    if (list)
        s->prep_list = list;
    uint8_t *pkg = rl_realloc_array(s->package, nf, 1);
    if (pkg)
        s->package = pkg;
    if (!vis || !list || !pkg)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "vt: face flags of %zu faces", nf);
    rl_status st = run_prepass(s, run);
    if (st != RL_OK)
        return st;
    s->prep_count = 0;
    for (uint32_t f = 0; f < m->num_primary_faces; ++f) {
        vis[f] = m->faces[f].visible;
        if (vis[f])
            list[s->prep_count++] = f;
    }
    s->prep_cam = *cam;
    s->prep_width = run->image->width;
    s->prep_height = run->image->height;
    s->prep_scene = rl_scene_uid(scene);
    s->prepared = true;
    return RL_OK;
}

rl_status rl_vt_prepare(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                        const uint32_t **faces, size_t *count)
{
    vt_state *s = vt_of(r, "rl_vt_prepare");
    if (!s || !scene || !cam || !image || !faces || !count)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_prepare: needs a \"vt\" renderer, scene, camera, image and "
                        "outputs");
    *faces = NULL;
    *count = 0;
    vt_settings set;
    rl_camera c;
    rl_tracer *tracer;
    vt_run run;
    rl_status st = dist_begin(r, s, scene, cam, image, &set, &c, &tracer, &run);
    if (st == RL_OK)
        st = dist_prepass(r, s, scene, &c, &run);
    dist_end(&run, tracer);
    if (st == RL_OK) {
        *faces = s->prep_list;
        *count = s->prep_count;
    }
    return st;
}

/* The package's faces and, with dist_halo, the visible faces sharing a
 * primary edge with them are flagged visible: splits reach those
 * neighbours anyway (a split edge splits both its faces), and forced
 * refinement checks only visible faces' children, so without the ring a
 * border sub-edge that one process splits by force from the other side
 * stays whole here (Sec. 4.3.3). */
static uint64_t flag_package(vt_state *s, vt_mesh *m, const uint32_t *faces, size_t count, bool halo, bool postpass)
{
    memset(s->package, 0, m->num_primary_faces);
    /* With the post-pass (Sec. 6.1.3), the faces that lost the ID test are
     * every package's (2): one process refines the hidden faces its
     * splits reach, and every such vertex a package leaves out the master
     * traces in its post-pass, alone. A hidden face between two packages
     * is refined by both, to the same samples. */
    for (uint32_t f = 0; postpass && f < m->num_primary_faces; ++f)
        s->package[f] = s->prep_visible[f] ? 0 : 2;
    uint64_t visible = 0;
    for (size_t i = 0; i < count; ++i) {
        uint32_t f = faces[i];
        s->package[f] = 1;
        if (s->prep_visible[f] && !m->faces[f].visible) {
            m->faces[f].visible = 1;
            ++visible;
        }
    }
    for (size_t i = 0; halo && i < count; ++i) {
        uint32_t f = faces[i];
        if (!s->prep_visible[f])
            continue;
        for (int k = 0; k < 3; ++k) {
            const vt_edge *e = &m->edges[m->faces[f].e[k]];
            for (int side = 0; side < 2; ++side) {
                uint32_t g = e->face[side];
                if (g != VT_NONE && g < m->num_primary_faces && s->prep_visible[g])
                    m->faces[g].visible = 1;
            }
        }
    }
    return visible;
}

/* dist_begin and the pre-pass for a package's faces, which must be
 * primary faces of the scene. */
static rl_status dist_open(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_camera *cam,
                           rl_image *image, const uint32_t *faces, size_t count, const char *what, vt_settings *set,
                           rl_camera *c, rl_tracer **tracer, vt_run *run)
{
    rl_status st = dist_begin(r, s, scene, cam, image, set, c, tracer, run);
    if (st == RL_OK)
        st = dist_prepass(r, s, scene, c, run);
    const vt_mesh *m = &s->mesh;
    for (size_t i = 0; st == RL_OK && i < count; ++i)
        if (faces[i] >= m->num_primary_faces)
            st = rl_error(RL_ERR_INVALID_ARG, "%s: face %u of %u primary faces", what, faces[i],
                          m->num_primary_faces);
    return st;
}

rl_status rl_vt_refine_faces(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                             const uint32_t *faces, size_t count, void **part, size_t *part_size,
                             rl_render_stats *stats)
{
    vt_state *s = vt_of(r, "rl_vt_refine_faces");
    if (!s || !scene || !cam || !image || (!faces && count) || !part || !part_size)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_refine_faces: needs a \"vt\" renderer, scene, camera, image, "
                        "faces and outputs");
    *part = NULL;
    *part_size = 0;
    vt_settings set;
    rl_camera c;
    rl_tracer *tracer;
    vt_run run;
    rl_status st = dist_open(r, s, scene, cam, image, faces, count, "rl_vt_refine_faces", &set, &c, &tracer, &run);
    vt_mesh *m = &s->mesh;
    if (st == RL_OK) {
        /* The pre-pass flagged the whole frame's faces. */
        vt_mesh_reset(m);
        vt_heap_clear(&s->heap);
        run.stats.visible_primary_faces = flag_package(s, m, faces, count, rl_renderer_opt_bool(r, "dist_halo"),
                                                       rl_renderer_opt_bool(r, "dist_postpass"));
        run.seed = s->package;
        vt_project_primary(&run, s->depth_ids);
        st = vt_refine(&run);
        run.stats.mesh_bytes = vt_mesh_bytes(m);
    }
    if (st == RL_OK)
        st = vt_part_write(m, run.data, s->package, rl_renderer_opt_bool(r, "dist_postpass"), part, part_size);
    if (st == RL_OK) {
        for (int t = 0; t < set.threads && t < RL_VT_MAX_THREADS; ++t) {
            run.stats.thread_rays[t] = run.tally[t].rays;
            run.stats.thread_busy_ms[t] = run.tally[t].busy_ms;
            run.stats.feelers_reused += run.tally[t].feelers_reused;
            run.stats.hint_tests += run.tally[t].hint_tests;
            run.stats.hint_hits += run.tally[t].hint_hits;
        }
        s->stats = run.stats;
        if (stats) {
            for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                stats->rays[k] += run.rays[k];
            stats->samples += run.stats.vertices_sampled;
        }
    }
    dist_end(&run, tracer);
    if (st == RL_OK && run.cancelled) {
        free(*part);
        *part = NULL;
        *part_size = 0;
        return rl_error(RL_ERR_CANCELLED, "vt: cancelled by the progress callback");
    }
    return st;
}

/* Eq. 4.4-4.5 for one primary edge: its ends' sample difference (1 for
 * different ray trees, else the mean channel difference of the criteria's
 * colours) times its projected length over the viewport's diagonal;
 * weighted by the rays of its ends' samples (below). */
static double edge_cost(const vt_run *run, const vt_mesh *m, const vt_edge *ed, double diagonal)
{
    const vt_vertex *a = &m->verts[ed->v[0]], *b = &m->verts[ed->v[1]];
    if (a->state != VT_SAMPLED || b->state != VT_SAMPLED)
        return 0.0;
    const vt_vertex_sample *sa = &m->samples[ed->v[0]], *sb = &m->samples[ed->v[1]];
    const unsigned bits = run->set->criteria.bits;
    double delta;
    if ((bits & VT_CRIT_TREE) && vt_sample_tree(sa) != vt_sample_tree(sb)) {
        delta = 1.0;
    } else if (bits & VT_CRIT_RGB || !(bits & VT_CRIT_HSV)) {
        rl_vec3 da = vt_sample_display(sa), db = vt_sample_display(sb);
        delta = (fabsf(da.x - db.x) + fabsf(da.y - db.y) + fabsf(da.z - db.z)) / 3.0;
    } else {
        float ha, sat_a, va, hb, sat_b, vb;
        vt_rgb_to_hsv(vt_sample_display(sa), &ha, &sat_a, &va);
        vt_rgb_to_hsv(vt_sample_display(sb), &hb, &sat_b, &vb);
        float dh = fabsf(ha - hb);
        dh = dh > 0.5f ? 1.0f - dh : dh;
        delta = (2.0 * dh + fabsf(sat_a - sat_b) + fabsf(va - vb)) / 3.0;  /* hue circle: 0.5 at most */
    }
    /* An end behind the eye has no projection: the edge counts as the
     * longest possible. */
    double l = a->cw > 0.0f && b->cw > 0.0f ? vt_edge_length(&run->view, a, b) : diagonal;
    double rays = 0.5 * ((double)run->vertex_rays[ed->v[0]] + (double)run->vertex_rays[ed->v[1]]);
    return delta * (l < diagonal ? l : diagonal) / diagonal * rays;
}

rl_status rl_vt_estimate_costs(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                               const uint32_t *faces, size_t count, double *cost, rl_render_stats *stats)
{
    vt_state *s = vt_of(r, "rl_vt_estimate_costs");
    if (!s || !scene || !cam || !image || (count && (!faces || !cost)))
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_estimate_costs: needs a \"vt\" renderer, scene, camera, "
                        "image, faces and costs");
    vt_settings set;
    rl_camera c;
    rl_tracer *tracer;
    vt_run run;
    rl_status st = dist_open(r, s, scene, cam, image, faces, count, "rl_vt_estimate_costs", &set, &c, &tracer, &run);
    vt_mesh *m = &s->mesh;
    uint32_t *vertex_rays = NULL;
    if (st == RL_OK && !(vertex_rays = calloc(m->num_primary_verts ? m->num_primary_verts : 1, sizeof *vertex_rays)))
        st = rl_error(RL_ERR_OUT_OF_MEMORY, "vt: the rays of %u primary vertices", m->num_primary_verts);
    run.vertex_rays = vertex_rays;
    if (st == RL_OK) {
        vt_mesh_reset(m);
        vt_project_primary(&run, s->depth_ids);
        /* The primary vertices of the faces, sampled as a refinement's
         * stage 0 would (Sec. 4.3.3: the estimate needs their samples). */
#pragma omp parallel num_threads(set.threads)
#pragma omp single
        {
            for (size_t i = 0; i < count && !run.failed; ++i)
                for (int k = 0; k < 3; ++k)
                    vt_sample_queue(&run, m->faces[faces[i]].v[k]);
            vt_sample_flush(&run);
        }
        if (run.failed)
            st = rl_error(RL_ERR_OUT_OF_MEMORY, "vt: out of memory while sampling %zu faces' vertices", count);
    }
    if (st == RL_OK) {
        const double diagonal = hypot((double)image->width, (double)image->height);
        /* b_f = 1/3 sum b_e, with two changes: b_e is weighted by the
         * rays of its ends' samples, since the samples that refine an
         * edge cost about what its ends did (a glass' samples trace tens
         * of rays, a wall's a few: with the thesis' b_f the glass' package
         * of three took 2.2 times its share on table); and the face
         * pays its own share of the primary samples (a vertex serves
         * about six faces: half a sample each, in the unit of eq. 4.4, a
         * sample per min_edge pixels), so that a run of uniform faces is
         * not free. */
        const double own = 0.5 * (set.min_edge > 0.0f ? set.min_edge : 1.0) / diagonal;
        for (size_t i = 0; i < count; ++i) {
            const vt_face *f = &m->faces[faces[i]];
            double b = 0.0, rays = 0.0;
            for (int k = 0; k < 3; ++k) {
                b += edge_cost(&run, m, &m->edges[f->e[k]], diagonal);
                rays += vertex_rays[f->v[k]] / 3.0;
            }
            cost[i] = b / 3.0 + own * rays;
        }
        if (stats) {
            for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                stats->rays[k] += run.rays[k];
            stats->samples += run.stats.vertices_sampled;
        }
    }
    free(vertex_rays);
    dist_end(&run, tracer);
    return st;
}

/* The caller's progress while the post-pass runs: its packages are all
 * in, so the frame stays at "done" (the replay's stages would otherwise
 * take the bar back to 0), and a cancel still stops it. */
typedef struct postpass_progress {
    rl_progress_fn fn;
    void *user;
} postpass_progress;

static bool postpass_progress_fn(void *user, double done)
{
    (void)done;
    const postpass_progress *p = user;
    return p->fn ? p->fn(p->user, 1.0) : true;
}

/* The post-pass of a distributed frame (Ullmann 2003, Sec. 6.1.3; option
 * dist_postpass), on the master once all parts are in. The thesis
 * proposes that the master collect the forced splits a border stopped and
 * have the slaves redo them, iterated until none is left. Here the master
 * replays one process' refinement of the whole frame (the same pre-pass,
 * edge list, criteria and forced refinement, stage by stage until the
 * edge list is empty) and takes every vertex's sample from the parts,
 * which carry all the samples their packages traced (part version 2);
 * only a vertex no package sampled is traced, by the master itself with
 * its threads. Those are exactly the places where the merged packages
 * differ from one process: a forced chain a border stopped, an edge split
 * on one side only, a hidden face's vertices. Since a vertex's sample
 * depends only on the vertex (vt_sample.c) and the refinement's decisions
 * only on the samples and the geometry, the mesh, and with it the image,
 * is one process' bit for bit, whatever the packages and ranks.
 * The master traces rather than sending a second round of tasks: the
 * missing vertices come one forced chain at a time (each stage's splits
 * decide the next), so a second round would be a round trip per stage,
 * for 0.5-10 % of a frame's samples spread over its stages
 * (docs/distributed.md, "The post-pass"). Overlapped (dist_overlap,
 * rl_vt_postpass_add), the replay starts before the last part: s->pp_map
 * then grows between stages, and a vertex whose part is not in yet is
 * traced here like one no part has, to the same sample. */
static rl_status draw_postpass(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_camera *cam,
                               vt_run *run)
{
    rl_timer t;
    rl_timer_start(&t);
    rl_status st = dist_prepass(r, s, scene, cam, run);
    vt_mesh *m = &s->mesh;
    if (st == RL_OK) {
        /* As vt_prepass leaves the mesh: the ID test's faces visible. */
        vt_mesh_reset(m);
        vt_heap_clear(&s->heap);
        run->stats.visible_primary_faces = 0;
        for (uint32_t f = 0; f < m->num_primary_faces; ++f) {
            m->faces[f].visible = s->prep_visible[f];
            run->stats.visible_primary_faces += s->prep_visible[f];
        }
        vt_project_primary(run, s->depth_ids);
        /* The map may grow while the replay runs: the caller's progress
         * callback, called after every stage, may add parts that came
         * meanwhile (rl_vt_postpass_add; the overlapped post-pass). */
        run->given = &s->pp_map;
        postpass_progress pp;
        rl_renderer_get_progress(r, &pp.fn, &pp.user);
        rl_renderer_set_progress(r, postpass_progress_fn, &pp);
        st = vt_refine(run);
        rl_renderer_set_progress(r, pp.fn, pp.user);
        run->given = NULL;
    }
    run->stats.time_visibility_ms = rl_timer_ms(&t) - run->stats.time_refine_ms - run->stats.time_sampling_ms;
    if (st == RL_OK)
        st = vt_draw_base(run);
    if (st == RL_OK)
        st = vt_run_reserve(run);
    if (st == RL_OK && !vt_update(run, run->stats.stages, true))
        st = run->failed ? RL_ERR_OUT_OF_MEMORY : RL_OK;
    if (st == RL_OK) {
        for (int k = 0; k < run->set->threads && k < RL_VT_MAX_THREADS; ++k) {
            run->stats.thread_rays[k] = run->tally[k].rays;
            run->stats.thread_busy_ms[k] = run->tally[k].busy_ms;
            run->stats.hint_tests += run->tally[k].hint_tests;
            run->stats.hint_hits += run->tally[k].hint_hits;
        }
        keep_mesh(s, run);
    }
    if (st == RL_OK && run->cancelled)
        st = rl_error(RL_ERR_CANCELLED, "vt: cancelled by the progress callback");
    return st;
}

/* dist_begin for the master's drawing of a distributed frame (the
 * post-pass or the parts' faces). Only the master draws, so only it needs
 * the GL drawer of reconstruct = gl: the workers' pre-pass and refinement
 * are the CPU's in either mode, as in one process. */
static rl_status master_begin(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_camera *cam,
                              rl_image *image, vt_settings *set, rl_camera *c, rl_tracer **tracer, vt_run *run)
{
    rl_status st = dist_begin(r, s, scene, cam, image, set, c, tracer, run);
    rl_drawer *gl = NULL;
    if (st == RL_OK && (st = gl_drawer_for(r, s, scene, set, image, &gl)) == RL_OK)
        run->drawer = gl;
    return st;
}

/* The post-pass' frame over the samples in s->pp_map, which it empties
 * at its end (the map points into the caller's parts). */
static rl_status postpass_frame(rl_renderer *r, vt_state *s, const rl_scene *scene, const rl_camera *cam,
                                rl_image *image, rl_render_stats *stats)
{
    vt_settings set;
    rl_camera c;
    rl_tracer *tracer;
    vt_run run;
    rl_status st = master_begin(r, s, scene, cam, image, &set, &c, &tracer, &run);
    if (st == RL_OK)
        st = draw_postpass(r, s, scene, &c, &run);
    if (st == RL_OK) {
        run.stats.mesh_bytes = vt_mesh_bytes(&s->mesh);
        s->stats = run.stats;
        s->have_frame = true;
        if (stats) {
            for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                stats->rays[k] += run.rays[k];
            stats->samples += run.stats.vertices_sampled;
            stats->triangles_rasterized += run.counters.triangles_drawn;
            stats->pixels_written += run.counters.pixels_written;
        }
    }
    dist_end(&run, tracer);
    vt_part_samples_free(&s->pp_map);
    return st;
}

rl_status rl_vt_postpass_add(rl_renderer *r, const void *part, size_t size)
{
    vt_state *s = vt_of(r, "rl_vt_postpass_add");
    if (!s)
        return RL_ERR_INVALID_ARG;
    uint32_t nv, nf;
    rl_status st = vt_part_check(part, size, &nv, &nf);
    if (st != RL_OK)
        return st;
    return vt_part_samples_add(&s->pp_map, part, size);
}

void rl_vt_postpass_clear(rl_renderer *r)
{
    vt_state *s = r && strcmp(rl_renderer_name(r), "vt") == 0 ? rl_renderer_state(r) : NULL;
    if (s)
        vt_part_samples_free(&s->pp_map);
}

rl_status rl_vt_postpass_draw(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                              rl_render_stats *stats)
{
    vt_state *s = vt_of(r, "rl_vt_postpass_draw");
    if (!s || !scene || !cam || !image)
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_postpass_draw: needs a \"vt\" renderer, scene, camera and "
                        "image");
    return postpass_frame(r, s, scene, cam, image, stats);
}

rl_status rl_vt_draw_parts(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *image,
                           const void *const *parts, const size_t *sizes, size_t count, rl_render_stats *stats)
{
    vt_state *s = vt_of(r, "rl_vt_draw_parts");
    if (!s || !scene || !cam || !image || (count && (!parts || !sizes)))
        return rl_error(RL_ERR_INVALID_ARG, "rl_vt_draw_parts: needs a \"vt\" renderer, scene, camera, image and "
                        "parts");
    /* Every part is checked before anything is drawn. */
    for (size_t i = 0; i < count; ++i) {
        uint32_t nv, nf;
        rl_status st = vt_part_check(parts[i], sizes[i], &nv, &nf);
        if (st != RL_OK) {
            char why[256];
            snprintf(why, sizeof why, "%s", rl_last_error());
            rl_clear_error();         /* the part's number goes first */
            return rl_error(st, "rl_vt_draw_parts: part %zu: %s", i, why);
        }
    }
    if (rl_renderer_opt_bool(r, "dist_postpass")) {
        /* The post-pass over exactly these parts (the overlapped one adds
         * them as they come, rl_vt_postpass_add). */
        vt_part_samples_free(&s->pp_map);
        for (size_t i = 0; i < count; ++i) {
            rl_status st = vt_part_samples_add(&s->pp_map, parts[i], sizes[i]);
            if (st != RL_OK) {
                vt_part_samples_free(&s->pp_map);
                return st;
            }
        }
        return postpass_frame(r, s, scene, cam, image, stats);
    }
    vt_settings set;
    rl_camera c;
    rl_tracer *tracer;
    vt_run run;
    rl_status st = master_begin(r, s, scene, cam, image, &set, &c, &tracer, &run);
    /* The parts' faces go after the primary ones. */
    for (size_t i = 0; st == RL_OK && i < count; ++i)
        if ((st = vt_part_import(&s->mesh, run.data, parts[i], sizes[i])) != RL_OK) {
            char why[256];
            snprintf(why, sizeof why, "%s", rl_last_error());
            rl_clear_error();
            st = rl_error(st, "rl_vt_draw_parts: part %zu: %s", i, why);
        }
    /* The primary faces are drawn from the parts' leaves only. */
    for (uint32_t f = 0; st == RL_OK && f < s->mesh.num_primary_faces; ++f)
        s->mesh.faces[f].leaf = 0;
    if (st == RL_OK)
        st = vt_draw_base(&run);
    if (st == RL_OK)
        st = vt_run_reserve(&run);
    if (st == RL_OK)
        st = vt_draw(&run, false);
    if (st == RL_OK)
        vt_draw_overlay(&run);
    if (st == RL_OK)
        keep_mesh(s, &run);
    if (st == RL_OK) {
        run.stats.mesh_bytes = vt_mesh_bytes(&s->mesh);
        s->stats = run.stats;
        s->have_frame = true;
        if (stats) {
            stats->triangles_rasterized += run.counters.triangles_drawn;
            stats->pixels_written += run.counters.pixels_written;
        }
    }
    dist_end(&run, tracer);
    return st;
}

rl_status rl_vt_part_check(const void *part, size_t size, size_t *vertices, size_t *faces)
{
    uint32_t nv, nf;
    rl_status st = vt_part_check(part, size, &nv, &nf);
    if (vertices)
        *vertices = st == RL_OK ? nv : 0;
    if (faces)
        *faces = st == RL_OK ? nf : 0;
    return st;
}

const rl_renderer_class rl_vt_renderer_class = {
    .info = { .name = "vt",
              .description = "Vertex Tracing: adaptive progressive ray tracing in object space, hybrid with rasterization",
              .reference = "Ullmann 2003, Ch. 3-4",
              /* frame_buffers(): scratch depth, and depth and triangle IDs of the pre-pass */
              .frame_bytes_per_pixel = 2 * sizeof(float) + sizeof(uint32_t) },
    .options = vt_options,
    .num_options = sizeof vt_options / sizeof vt_options[0],
    .state_size = sizeof(vt_state),
    .render = vt_render,
    .release = vt_release,
    .check = vt_check,
    .reset = vt_reset,
    .available = vt_available,
};
