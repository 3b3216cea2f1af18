/* culling.h: what the visibility-culling and level-of-detail renderers
 * (chcpp.c, svs.c, surfels.c) share: the view of one frame with its
 * frustum, bounding-box occlusion queries through the rasterizer, the
 * render target with a private depth layer, and a loose octree kept
 * between frames. */
#ifndef RL_RENDER_CULLING_H
#define RL_RENDER_CULLING_H

#include "rl/rl_drawer.h"
#include "rl/rl_culling.h"
#include "rl/rl_octree.h"
#include "rl/rl_raster.h"
#include "rl/rl_scene.h"

/* One frame's camera, exactly as rl_raster_set_camera() sets it up. */
typedef struct rl_cull_view {
    rl_camera cam;                /* resolved */
    rl_vec3 eye;
    float z_near, z_far;
    rl_mat4 view, proj, view_proj;
    rl_vec4 planes[6];            /* inward: dot(n, p) + d >= 0 inside */
    float near_radius;            /* eye to the near plane's corners */
} rl_cull_view;

void rl_cull_view_make(const rl_camera *cam, rl_aabb scene_bounds, rl_cull_view *v);
/* False only where the box is certainly outside the frustum. */
bool rl_cull_box_in_frustum(const rl_cull_view *v, rl_aabb b);
/* True where a box query could be wrong because the near plane cuts the
 * box's front (the eye is inside the box grown by near_radius). */
bool rl_cull_box_near_eye(const rl_cull_view *v, rl_aabb b);
/* Distance from the eye to the box (0 inside): the front-to-back key. */
float rl_cull_box_distance(rl_vec3 eye, rl_aabb b);

/* Several boxes as one occlusion query (a multi-query, Mattausch et al.
 * 2008): front faces only, each box grown by a relative margin so that
 * the geometry it bounds can never poke through its faces by rounding. */
typedef struct rl_box_query {
    rl_vec3 *positions;
    uint32_t *indices;
    uint32_t boxes;
    size_t cap_boxes;
} rl_box_query;

void rl_box_query_reset(rl_box_query *q);
/* The box a query draws for b: grown by margin times its longest side (plus
 * 1e-6). Near-eye tests must use it, not b: an eye outside b but inside
 * the grown box sees only its back faces, which count no pixel. */
rl_aabb rl_box_query_bounds(rl_aabb b, float margin);
rl_status rl_box_query_add(rl_box_query *q, rl_aabb b, float margin);
/* Visible pixels of all boxes added since the last reset (0 boxes: 0). */
rl_status rl_box_query_run(rl_box_query *q, rl_drawer *dr, uint64_t *pixels, rl_raster_counters *c);
/* The same query issued without waiting (rl_drawer_query_issue): its
 * answer comes with rl_drawer_query_poll / _result on *handle. */
rl_status rl_box_query_issue(rl_box_query *q, rl_drawer *dr, uint32_t *handle, rl_raster_counters *c);
void rl_box_query_free(rl_box_query *q);

/* The caller's image as the rasterizer's target, with a private depth
 * layer if the caller asked for none, cleared to the background. That
 * layer is what a culling renderer's frame adds to the caller's image
 * (rl_renderer_info.frame_bytes_per_pixel). */
#define RL_CULL_FRAME_BYTES_PER_PIXEL sizeof(float)
typedef struct rl_cull_target {
    rl_image image;
    float *own_depth;
    unsigned flags;               /* RL_RASTER_NO_ID when the caller has no ID layer */
} rl_cull_target;

rl_status rl_cull_target_begin(rl_image *image, rl_vec3 background, rl_cull_target *t);
void rl_cull_target_end(rl_cull_target *t);
/* One frame of every selected object, in index order, with drawer dr into
 * t (begun with cam over bounds, then ended), the counts into stats: the
 * whole frame of raster and gl-raster, which differ only in the drawer's
 * backend. Progress goes to r's callback. */
rl_status rl_cull_draw_all(rl_renderer *r, rl_drawer *dr, rl_cull_target *t, const rl_camera *cam, rl_aabb bounds,
                           rl_render_stats *stats);

/* A loose octree rebuilt only when the scene or its parameters change. */
typedef struct rl_octree_cache {
    rl_octree *tree;
    uint64_t scene_uid;
    rl_octree_desc desc;
} rl_octree_cache;

/* *rebuilt tells whether per-node state must be reset. */
rl_status rl_octree_cache_get(rl_octree_cache *c, const rl_scene *scene, const rl_octree_desc *desc,
                              bool *rebuilt);
void rl_octree_cache_release(rl_octree_cache *c);

/* raster's first rows, which gl-raster repeats (the same drawing on GL):
 * the shading (rl_cull_shading_choices, in rl_raster_shading's order), back
 * faces, the ambient term and the background. */
#define RL_RASTER_OPTIONS                                                                               \
    { "shading", RL_OPT_ENUM, "textured",                                                               \
      "flat: per triangle; gouraud: per vertex; textured: gouraud times the diffuse texture",           \
      0, 0, rl_cull_shading_choices },                                                                  \
    { "cull", RL_OPT_BOOL, "false", "drop back faces (counter-clockwise = front)", 0, 0, NULL },        \
    { "ambient", RL_OPT_FLOAT, "0.05", "ambient light, multiplied by k_d", 0, 1, NULL },                \
    { "background", RL_OPT_COLOR, "0,0,0", "colour where nothing is hit: \"r,g,b\" or one grey value",   \
      0, 0, NULL }

/* The option rows every culling renderer shares with raster (its mesh
 * drawing), first in its table; rl_cull_frame_begin() reads them. */
extern const char *const rl_cull_shading_choices[];
extern const char *const rl_cull_drawer_choices[];
enum { RL_CULL_DRAWER_SOFTWARE, RL_CULL_DRAWER_GL };
#define RL_CULL_RASTER_OPTIONS                                                                          \
    { "shading", RL_OPT_ENUM, "textured", "meshes: flat | gouraud | textured, as raster", 0, 0,          \
      rl_cull_shading_choices },                                                                        \
    { "cull", RL_OPT_BOOL, "false", "drop back faces (counter-clockwise = front)", 0, 0, NULL },        \
    { "ambient", RL_OPT_FLOAT, "0.05", "ambient light, multiplied by k_d", 0, 1, NULL },                \
    { "background", RL_OPT_COLOR, "0,0,0", "colour where nothing is drawn", 0, 0, NULL },              \
    { "threads", RL_OPT_INT, "0", "OpenMP threads (0 = all)", 0, 1024, NULL },                          \
    { "drawer", RL_OPT_ENUM, "software",                                                                \
      "the frame's drawing and queries: software (the CPU rasterizer) | gl (OpenGL 4.5, docs/gl.md)",   \
      0, 0, rl_cull_drawer_choices },                                                                   \
    { "device", RL_OPT_STRING, "",                                                                      \
      "drawer=gl: EGL device auto, surfaceless or a number; empty: $RL_EGL_DEVICE, else auto", 0, 0,    \
      NULL }

/* rl_renderer_class.available of the culling renderers: always with the
 * software drawer, where a GL 4.5 context can be made with drawer=gl. */
bool rl_cull_available(const rl_renderer *r, char *why, size_t n);

/* One frame of a culling renderer: the caller's image as target, the view,
 * and the renderer's kept drawer (rl_drawer.h, any backend) begun on them,
 * from the shared options. */
typedef struct rl_cull_frame {
    rl_cull_target target;
    rl_cull_view view;
    rl_drawer *drawer;            /* the renderer's kept one, begun on the target */
    rl_raster_counters counters;
    int threads_opt;              /* the option: 0 = all */
    int threads;                  /* resolved, >= 1 */
    float ambient;
    const char *device;           /* drawer=gl: the head's info, for rl_render_stats.device */
    bool new_drawer;              /* the drawer was made for this frame: queries kept open by
                                   * the last frame (rl_drawer_query_keep) went with the old one */
} rl_cull_frame;

typedef struct rl_culling_head rl_culling_head;
/* The drawer is the head's, kept while the scene, the options and the
 * drawer's backend and device stay. deferred: every draw counts into
 * f->counters, which rl_cull_frame_end reads after the drawer's end
 * (rl_drawer_desc.deferred_counts: a GL drawer never waits for a draw). */
rl_status rl_cull_frame_begin(rl_renderer *r, const rl_scene *scene, rl_culling_head *head, const rl_camera *cam,
                              rl_image *image, bool deferred, rl_cull_frame *f);
/* Ends the drawer's frame and releases what begin made (not the kept
 * drawer); with st == RL_OK fills stats (triangles, points, pixels
 * written, samples, the GL device). Returns st, or the end's failure. */
rl_status rl_cull_frame_end(rl_cull_frame *f, rl_status st, const rl_image *image, rl_render_stats *stats);

/* Every culling renderer's state starts with this, so that
 * rl_culling_get_stats() can read any of them. */
struct rl_culling_head {
    rl_culling_stats stats;
    bool have_frame;
    rl_drawer *drawer;            /* kept across frames; released by the renderer's release */
    char device[64];              /* drawer=gl: the device option the drawer was made on */
    char info[528];               /* and its "vendor | renderer | version" */
    uint32_t query_delay;         /* rl_drawer_desc.query_delay of the drawer to make (chcpp's
                                   * option; 0 for the others) */
};

/* The statistics of r's last frame, or NULL when r is not a culling
 * renderer or has rendered nothing yet (rl_culling_get_stats without
 * recording an error). */
const rl_culling_stats *rl_cull_stats_of(const rl_renderer *r);

#endif
