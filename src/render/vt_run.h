/* vt_run.h: one Vertex Tracing frame as vt.c, vt_refine.c, vt_sample.c and
 * vt_draw.c share it (the building blocks are in vt_internal.h).
 *
 * Threads (Ullmann 2003, Ch. 4.4): one thread, the primary thread in the
 * thesis' words, owns the mesh and the edge list and does all refinement;
 * the vertices it creates are handed out in blocks as OpenMP tasks that the
 * other (secondary) threads sample while it goes on refining. A block owns
 * copies of everything its rays need and its results, so sampling never
 * reads the mesh the primary thread is growing. A refinement stage ends
 * when all its blocks are sampled (the sequential dependency Sampling_k ->
 * Refinement_k -> Sampling_k+1 of Sec. 4.2). Every vertex's sample depends
 * only on the vertex, so the image is the same for any number of threads. */
#ifndef RL_RENDER_VT_RUN_H
#define RL_RENDER_VT_RUN_H

#include "raster/scene_drawer.h"
#include "render/vt_internal.h"
#include "rl/rl_raster.h"
#include "rl/rl_vt.h"

enum { VT_TEX_MULTITEXTURE = 0, VT_TEX_MULTIPASS, VT_TEX_SAMPLED };
enum { VT_PROG_NONE = 0, VT_PROG_OVERDRAW, VT_PROG_REDRAW };
enum { VT_OVERLAY_NONE = 0, VT_OVERLAY_WIRE, VT_OVERLAY_SAMPLES };

/* Why a vertex exists (rl_vt_vertex_info.reason). */
enum { VT_REASON_RGB = 1, VT_REASON_HSV = 2, VT_REASON_TREE = 4, VT_REASON_FORCED = 8 };
/* Sec. 6.1 (vt_correct.c): a nonlinearity or a shaft's occluder split it. */
enum { VT_REASON_NONLINEAR = 16, VT_REASON_SHAFT = 32 };
enum { VT_NONLINEAR_OFF = 0, VT_NONLINEAR_EXTREMUM, VT_NONLINEAR_INTERVAL, VT_NONLINEAR_DERIVATIVE, VT_NONLINEAR_AFFINE };
enum { VT_SHAFT_OFF = 0, VT_SHAFT_SHADOW, VT_SHAFT_ALL };

/* The options of one frame, validated and resolved (vt.c). */
typedef struct vt_settings {
    vt_criteria criteria;
    float min_edge;           /* px: edges this short or shorter are not split */
    bool forced;              /* forced refinement (Sec. 3.3.2) */
    float eps_z;              /* its threshold on xi */
    bool id_test, z_test, clip_test;   /* Sec. 3.4.1-3.4.3 */
    float merge_px;           /* Sec. 6.2.1: primary edges shorter than this
                               * sample one end only; 0 = off */
    int nonlinear;            /* Sec. 6.1.1: VT_NONLINEAR_* */
    float eps_ia;             /* its interval bound that splits */
    int shaft_cull;           /* Sec. 6.1.2: VT_SHAFT_* */
    int textures;             /* VT_TEX_* (Sec. 3.5.3-3.5.5) */
    int progressive;          /* VT_PROG_* (Sec. 3.5.1) */
    int update_every;         /* k */
    float overdraw_f;         /* f of eq. 3.14 */
    bool coherence;           /* temporal coherence (Sec. 3.4.5) */
    uint32_t max_vertices;    /* refinement stops growing the mesh here */
    int threads;              /* resolved, >= 1 */
    rl_raster_shading shading;/* of the non-VT objects */
    float ambient;
    rl_vec3 background;
    int overlay;              /* VT_OVERLAY_* */
    int hint;                 /* VT_HINT_* (Sec. 3.3.1, 6.2.2) */
    bool presort;             /* sample a stage's vertices in VT-object and
                               * screen Morton order (Sec. 6.2.2) */
    int tree_shadow;          /* VT_TREE_SHADOW_* (vt_internal.h): the
                               * feeler nodes the ray-tree criterion compares */
    int tree_depth;           /* the ray tree compared down to this
                               * recursion depth; 0 = all of it */
    bool deferred_split;      /* the criteria see the deferred reflected and
                               * transmitted textures (vt_sample.c) */
    int pixel_split;          /* VT_PIXEL_SPLIT_*: criterion splits below
                               * min_edge where a pixel centre shows them */
    float pixel_floor;        /* px: ... down to this edge length */
} vt_settings;

/* Option pixel_split (vt_refine.c): an edge at or below min_edge whose ends
 * a criterion tells apart is still split, down to pixel_floor, when one of
 * its faces holds a pixel centre (INSIDE), or pixel centres on both sides of
 * the split (BOTH). */
enum { VT_PIXEL_SPLIT_OFF = 0, VT_PIXEL_SPLIT_INSIDE, VT_PIXEL_SPLIT_BOTH };

/* Intersection hints (Sec. 3.3.1, 6.2.2): which triangles a refined
 * vertex's rays test first. agree: those of its two parent vertices when
 * their ray trees name the same triangles throughout (the thesis' case);
 * parents: those of both parents slot by slot, whether or not they agree. */
enum { VT_HINT_OFF = 0, VT_HINT_AGREE, VT_HINT_PARENTS };

/* Depth-0 shadow feelers of one vertex, packed: rl_trace_feelers has room
 * for 64 occluders (264 bytes) where a vertex under two point lights
 * records two, and a frame at min_edge 1 keeps them for 360,000 vertices
 * three times over (this frame's, the map of the last, the rebuild). The
 * occluders live in a pool; this says where. */
typedef struct vt_feelers_packed {
    uint32_t first;           /* index of the first occluder in the pool */
    uint8_t count;            /* <= RL_TRACE_FEELER_CACHE_MAX */
    uint8_t front, complete;  /* as rl_trace_feelers */
} vt_feelers_packed;

typedef struct vt_feeler_pool {
    uint32_t *occluder;
    size_t count, cap;
    /* The array is vt_array_resize's (a frame's pools, which grow to
     * megabytes), not malloc's (the blocks' small ones) */
    bool mapped;
} vt_feeler_pool;

/* Appends the occluders of f to pool and describes them in *out; false
 * when out of memory or past 2^32 occluders. */
bool vt_feelers_pack(const rl_trace_feelers *f, vt_feeler_pool *pool, vt_feelers_packed *out);
/* The rl_trace_feelers that p describes (occluders past count untouched). */
void vt_feelers_unpack(const vt_feelers_packed *p, const uint32_t *occluder, rl_trace_feelers *out);
void vt_feeler_pool_free(vt_feeler_pool *pool);

/* Temporal coherence: depth-0 shadow feelers by vertex key, from the last
 * frame. Open addressing; read-only while a frame samples. */
typedef struct vt_feeler_map {
    uint64_t *keys;           /* 0 = empty slot (keys are never 0, see vt_key_nonzero) */
    vt_feelers_packed *values;
    vt_feeler_pool pool;      /* the occluders the values point into */
    size_t cap, count;        /* cap a power of two */
} vt_feeler_map;

const vt_feelers_packed *vt_feeler_map_find(const vt_feeler_map *m, uint64_t key);
/* Replaces the map's contents with the feelers of the sampled vertices of
 * mesh, by key: values[v] for vertex v, whose occluders are in pool; the
 * map takes pool's arrays over and leaves it empty. */
rl_status vt_feeler_map_rebuild(vt_feeler_map *m, const vt_mesh *mesh, const vt_feelers_packed *values,
                                vt_feeler_pool *pool);
void vt_feeler_map_free(vt_feeler_map *m);
static inline uint64_t vt_key_nonzero(uint64_t key) { return key ? key : 0x9E3779B97F4A7C15ull; }

#define VT_BLOCK 32

/* A block of vertices to sample: inputs copied from the mesh by the primary
 * thread, outputs read back by it after the stage's taskwait. */
typedef struct vt_block {
    uint32_t count;
    uint32_t vertex[VT_BLOCK];
    rl_trace_point point[VT_BLOCK];
    uint64_t key[VT_BLOCK];
    const vt_feelers_packed *cache_in[VT_BLOCK];   /* into run->cache */
    vt_vertex_sample out[VT_BLOCK];                /* deferred[] not yet set, */
    rl_trace_layer layers[VT_BLOCK][RL_TRACE_LAYER_COUNT];  /* ... the layers instead */
    uint64_t rays[VT_BLOCK][RL_RAY_TYPE_COUNT];
    vt_feelers_packed feelers[VT_BLOCK];           /* coherence: the new ones, */
    vt_feeler_pool feeler_pool;                    /* ... their occluders */
    /* hints: the parents' lists in run->hint_pool (count 0: none) and the
     * block's own, in hint_pool */
    vt_feelers_packed hint_in[VT_BLOCK][2];
    vt_feelers_packed hints[VT_BLOCK];
    vt_feeler_pool hint_pool;
    bool failed;              /* out of memory in the sampling thread */
    struct vt_block *next;
} vt_block;

/* Per-thread tallies (indexed by omp_get_thread_num, padded apart). */
typedef struct vt_thread_tally {
    uint64_t rays;
    uint64_t feelers_reused;
    double busy_ms;
    uint64_t hint_tests, hint_hits;
    char pad[24];
} vt_thread_tally;

/* The VT leaf faces as a layered raster batch (vt_draw.c): three corners
 * per face, four layers (Sec. 3.5.5). Kept by the renderer across frames
 * and only grown, so that a frame does not fault in fresh pages. */
#define VT_NUM_LAYERS 4
typedef struct vt_corners {
    size_t cap;               /* faces the corner arrays hold (one chunk) */
    rl_vec3 *pos;
    rl_vec4 *col[VT_NUM_LAYERS];
    rl_vec2 *uv[VT_NUM_LAYERS];
    uint32_t *tex[VT_NUM_LAYERS];    /* per face */
    uint32_t *idx;
    uint32_t *tri_ids, *obj_ids;     /* per face */
    uint32_t *faces;          /* the faces to draw, all chunks */
    size_t faces_cap;
} vt_corners;
void vt_corners_free(vt_corners *b);

/* The rasterized half of a frame (vt_draw_base), copied aside for redraws
 * when an update callback may ask for more than one full draw. The
 * buffers are kept by the renderer across frames (vt_state), so that a
 * progressive frame does not allocate and fault them in again. */
typedef struct vt_base {
    rl_vec4 *color;
    float *depth;
    uint32_t *object_id, *triangle_id;
    size_t color_cap, depth_cap, object_id_cap, triangle_id_cap;   /* pixels */
} vt_base;

typedef struct vt_run {
    const vt_settings *set;
    const rl_scene_data *data;
    const rl_tracer *tracer;
    vt_mesh *mesh;
    vt_heap *heap;
    vt_view view;
    uint8_t *object_vt;       /* per object: vertex traced */
    const uint8_t *object_raster; /* per object: rasterized (not VT) */
    const uint32_t *tri_face; /* scene triangle -> primary face, VT_NONE */
    /* A package of a distributed frame (vt_part.c): per primary face, 1
     * for the package's faces, whose edges start the refinement; visible
     * faces outside it are refined only where splits reach them; 2 (with
     * dist_postpass) for the faces hidden in the ID test, which any
     * package refines where its splits reach them, as one process does.
     * NULL: a whole frame, every visible face starts. */
    const uint8_t *seed;
    /* The master's post-pass of a distributed frame (vt_part.h, option
     * dist_postpass): a vertex queued for sampling takes its sample from
     * the packages' parts when one carries it, else it is traced. NULL:
     * every queued vertex is traced. */
    const struct vt_part_samples *given;
    rl_mat4 view_m, proj_m;   /* the rasterizer's matrices for this camera */
    /* per vertex, grown by the primary thread alongside mesh->verts */
    uint8_t *reason;
    vt_feelers_packed *feelers;   /* coherence only: this frame's feelers, */
    vt_feeler_pool feeler_pool;   /* ... and their occluders */
    vt_feelers_packed *hints;     /* hint only: each sampled vertex's ray */
    vt_feeler_pool hint_pool;     /* ... triangles (rl_trace_hints), packed */
    uint32_t per_vertex_cap;
    /* presort: the vertices queued this stage, sorted and sampled at the
     * flush */
    struct vt_queued *sorting;
    uint32_t num_sorting, cap_sorting;
    bool want_tree;           /* the ray-tree criterion is on */
    /* temporal coherence */
    const vt_feeler_map *cache;   /* or NULL */
    /* sampling */
    vt_block *pending;        /* blocks spawned this stage, to read back */
    uint32_t num_pending;
    vt_block *filling;        /* block the primary thread is filling */
    vt_block *free_blocks;
    uint64_t rays[RL_RAY_TYPE_COUNT];  /* summed by the primary thread */
    uint32_t *vertex_rays;    /* or NULL: rays of each vertex's sample, per vertex
                               * index below num_verts (the cost estimate) */
    vt_thread_tally tally[RL_VT_MAX_THREADS];
    bool failed;              /* out of memory inside the parallel region */
    /* progress and updates */
    rl_renderer *renderer;
    rl_vt_update_fn update;
    void *update_user;
    rl_image *image;          /* the frame's target */
    const rl_camera *camera;
    bool stopped;             /* update callback or progress asked to stop */
    bool cancelled;           /* ... and it was the progress callback */
    uint32_t drawn_stage;     /* overdraw: faces of stages <= this are drawn */
    bool drawn;               /* the image holds a frame (overdraw may add to it) */
    float *scratch_depth;     /* when the image has no depth layer */
    /* kept by the renderer across frames (vt_state) */
    rl_raster *ras;           /* every draw of the frame; its scratch stays */
    rl_drawer *drawer;        /* reconstruct = gl: the GL drawer that draws
                               * the image (vt_draw.c); NULL: ras does */
    vt_corners *corners;
    vt_base *base;            /* the rasterized half of the frame */
    bool have_base;           /* base holds this frame's */
    rl_raster_counters counters;  /* reconstruction draws */
    /* statistics */
    double t_start_ms;        /* rl_time_s() * 1000 at the frame's start */
    rl_vt_stats stats;
} vt_run;

/* vt_sample.c ------------------------------------------------------------ */
/* Marks vertex v queued and adds it to the block being filled; a full block
 * is spawned as a task. Call from the primary thread inside the parallel
 * region (or outside it: then the block is sampled at vt_sample_flush). */
void vt_sample_queue(vt_run *run, uint32_t v);
/* vt_sample_queue for the midpoint v of the edge (a, b): with hints on, its
 * rays test the triangles of a's and b's first (VT_HINT_*). */
void vt_sample_queue_mid(vt_run *run, uint32_t v, uint32_t a, uint32_t b);
/* Spawns the partly filled block, waits for all blocks of this stage and
 * copies their results into the mesh (state VT_SAMPLED). vt_sample_queue
 * does the same for the full blocks alone when too many are pending: a
 * stage at min_edge 1 makes up to 90,000 vertices, 2,800 blocks of 9 KB.
 * That is exact: a stage tests only edges whose ends an earlier stage
 * sampled, so no decision depends on when within a stage a vertex's
 * sample arrives. */
void vt_sample_flush(vt_run *run);
/* Time the calling thread has spent sampling blocks so far (ms): the
 * refinement subtracts what its thread sampled inside its own intervals. */
double vt_sample_busy_ms(const vt_run *run);
/* Makes room for per-vertex arrays up to mesh->num_verts. */
rl_status vt_run_reserve(vt_run *run);
void vt_run_free_blocks(vt_run *run);
/* Frees the per-vertex arrays (reason, feelers, hints; vt_array_resize's
 * for the last two, sized by per_vertex_cap). */
void vt_run_free_vertex_arrays(vt_run *run);

/* vt_refine.c ------------------------------------------------------------ */
/* The ID-buffer pre-pass (Sec. 3.4.1, Fig. 3.12, 3.17): draws the
 * rasterized half of the frame (vt_draw_base), then the VT objects into a
 * copy of its depth with IDs, flags the visible primary faces, projects the
 * primary vertices, z-tests them. depth_ids is a scratch image with depth;
 * triangle_ids (width*height) takes the triangle IDs, which are read only
 * here (no object IDs are written: the triangle names the face). */
rl_status vt_prepass(vt_run *run, rl_image *depth_ids, uint32_t *triangle_ids);
/* Projects and z-tests the primary vertices against the pre-pass' depth
 * (the second half of vt_prepass; a package of a distributed frame redoes
 * it after vt_mesh_reset, from the kept pre-pass). */
void vt_project_primary(vt_run *run, const rl_image *depth_ids);
/* Fills the edge list with the edges of visible primary faces and queues
 * their vertices; then all refinement stages until the list is empty, the
 * vertex budget is spent or an update/progress callback stops it. Runs the
 * parallel region. */
rl_status vt_refine(vt_run *run);

/* vt_correct.c (Sec. 6.1) ----------------------------------------------- */
/* Sec. 6.1.1: whether the local term of some light may have an extremum
 * (extremum, eq. 6.4-6.5; derivative, eq. 6.3) or a larger interpolation
 * error than eps_ia (interval, Fig. 6.4; affine) between the ends a and b
 * of an edge, under the frame's setting nonlinear (false when off). */
bool vt_nonlinear_fires(const vt_run *run, const vt_vertex *a, const vt_vertex *b);

/* The pieces of Sec. 6.1.1, on their own for the tests. One end of an
 * edge: its position, its normal turned towards the eye (the side the
 * tracer shades), the unit direction a to the eye, and the material's
 * largest diffuse and specular channel and its Phong exponent. */
typedef struct vt_edge_end {
    rl_vec3 p, n, a;
    float kd, ks, m;
} vt_edge_end;
vt_edge_end vt_edge_end_of(rl_vec3 p, rl_vec3 n, rl_vec3 eye, const rl_material *mat);
/* eq. 6.4-6.5 and eq. 6.3 over the lights: whether the edge hides an
 * extremum of a light's diffuse or specular term. */
bool vt_extremum_test(const rl_light *lights, uint32_t num_lights, const vt_edge_end *e1, const vt_edge_end *e2);
bool vt_derivative_test(const rl_light *lights, uint32_t num_lights, rl_vec3 eye, const vt_edge_end *e1,
                        const vt_edge_end *e2);
/* The unshadowed local Phong term of one light over the edge (positions
 * linear, normals normalize(lerp), eq. 3.8): its enclosure [lo, hi] in
 * interval (mode VT_NONLINEAR_INTERVAL) or affine arithmetic
 * (VT_NONLINEAR_AFFINE), its values at the ends and the bound eps_IA >=
 * max |f - f'| on the error of the linear interpolant f'. */
typedef struct vt_term_bound {
    float lo, hi, f1, f2, eps;
} vt_term_bound;
void vt_term_bound_of(int mode, const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2,
                      vt_term_bound *out);
/* The same term at t in [0, 1] along the edge. */
float vt_term_at(const rl_light *L, rl_vec3 eye, const vt_edge_end *e1, const vt_edge_end *e2, float t);

/* Sec. 6.1.2: the scene's triangles for the shaft test, per object in runs
 * of VT_SHAFT_GROUP with their boxes (a two-level hierarchy below the
 * objects' boxes), and the scene's extent d (Fig. 6.6b). */
#define VT_SHAFT_GROUP 32
typedef struct vt_shaft_index {
    uint32_t *first;          /* per object + 1: its first group */
    rl_aabb *box;             /* per group */
    float extent;             /* diagonal of the scene's bounds */
} vt_shaft_index;
rl_status vt_shaft_index_build(vt_shaft_index *ix, const rl_scene_data *d);
void vt_shaft_index_free(vt_shaft_index *ix);

/* The shaft of [HW91]: the convex hull of two boxes, as their joint
 * extent and up to 12 planes n.x <= offset. */
typedef struct vt_shaft {
    rl_aabb extent;
    int num_planes;
    rl_vec3 normal[12];
    float offset[12];
} vt_shaft;
void vt_shaft_build(vt_shaft *s, rl_aabb a, rl_aabb b);
/* false only when box x lies outside the shaft (conservative: a box near
 * an edge of the hull may be called inside). */
bool vt_shaft_meets_box(const vt_shaft *s, rl_aabb x);
/* Fig. 6.6: whether a shaft of face (to a light; with shaft_cull = all
 * also along its reflected and transmitted rays) holds geometry of
 * another object: then all its edges are to be split. */
bool vt_shaft_face_fires(const vt_run *run, const vt_shaft_index *ix, uint32_t face);

/* vt_draw.c -------------------------------------------------------------- */
/* Fig. 3.17, the rasterized half of the frame, drawn once per frame before
 * the ID pre-pass: background and the non-VT objects through the raster
 * renderer's code, into run->image (colour, depth, IDs). The pre-pass
 * starts from its depth; with an update callback a copy is kept, from
 * which every later full draw starts. Adds its time to stats.time_draw_ms. */
rl_status vt_draw_base(vt_run *run);
/* Frees the buffers of a kept base. */
void vt_base_free(vt_base *b);
/* The frame's target: run->image, with the scratch depth layer when the
 * image has none (the rasterizer needs one). */
rl_status vt_draw_target(vt_run *run, rl_image *target);
/* Draws the frame into run->image: the rasterized half (vt_draw_base's,
 * restored after an earlier full draw), then the VT leaf faces whose
 * vertices are all sampled, by Gouraud interpolation with deferred
 * textures (Sec. 3.5).
 * only_new: overdraw (Sec. 3.5.1): draw just the faces of stages after
 * run->drawn_stage onto the existing image, offset towards the eye by
 * eq. 3.16. Counts VT faces in run->stats.faces_drawn (full draws). */
rl_status vt_draw(vt_run *run, bool only_new);
/* Paints the refined mesh (wire) or its vertices coloured by reason
 * (samples) over the image, like Fig. 5.1e and 5.2c-d. */
void vt_draw_overlay(vt_run *run);
/* Called after the preview and every k-th stage: draws and hands the image
 * to the update callback. Returns false when the callback asked to stop. */
bool vt_update(vt_run *run, uint32_t stage, bool final);

#endif
