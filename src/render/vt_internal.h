/* vt_internal.h: the parts of Vertex Tracing (Ullmann 2003, Ch. 3-4) and
 * the contracts between them.
 *
 *   vt_mesh.c       the refinement mesh in object space: vertices, edges
 *                   with their left/right faces, faces; edge-based
 *                   subdivision (Sec. 3.3, Fig. 3.5) and the compression
 *                   factor xi of forced refinement (Sec. 3.3.2).
 *   vt_criteria.c   the subdivision criteria (Sec. 3.3.1): RGB L1, HSV,
 *                   ray tree, and their combinations.
 *   vt_visibility.c projection to the screen, the z-buffer test of a vertex
 *                   (Sec. 3.4.2) and the modified Cohen-Sutherland viewport
 *                   test of an edge (Sec. 3.4.3).
 *   vt_heap.c       the edge list sorted by projected length (Sec. 3.3,
 *                   Fig. 3.4), longest first.
 *   vt_refine.c     the refinement stages and the parallel sampling (Ch. 4).
 *   vt_draw.c       reconstruction through the rasterizer (Sec. 3.5).
 *   vt.c            the renderer "vt": options, frames, temporal coherence.
 *
 * Everything here is single-threaded unless said otherwise; vt_refine.c
 * runs the vertex sampling in parallel, never the mesh updates. */
#ifndef RL_RENDER_VT_INTERNAL_H
#define RL_RENDER_VT_INTERNAL_H

#include <stdbool.h>
#include <stdint.h>

#include "rl/rl_math.h"
#include "rl/rl_scene.h"
#include "rl/rl_trace.h"

#define VT_NONE 0xFFFFFFFFu

/* The refinement's large growing arrays (the mesh's, the edge list, the
 * frame's per-vertex feelers and hints and its pools) in mappings of their
 * own where the system has mremap (Linux), through realloc elsewhere and
 * under AddressSanitizer: growth moves pages instead of copying them and
 * leaves no freed block behind in the heap (why: vt_mesh.c).
 * vt_array_resize: p of old_bytes (the size it was made or last resized
 * with; p NULL: a new one) to new_bytes, contents kept up to the smaller
 * size, new room undefined; NULL when out of memory, p unchanged.
 * vt_array_free: p made with bytes; NULL is ignored. Never mixed with
 * malloc/free. */
void *vt_array_resize(void *p, size_t old_bytes, size_t new_bytes);
void vt_array_free(void *p, size_t bytes);
/* Room for need items of item_size in *array (vt_array_resize's, *cap
 * items), doubled from *cap, or from first when empty, and capped at
 * max_items: one growth rule for the mesh, the edge list and the batches.
 * RL_ERR_LIMIT when need is above max_items, else RL_ERR_OUT_OF_MEMORY; the
 * error names `what`, and *array and *cap stay as they were. */
rl_status vt_array_reserve(void **array, uint32_t *cap, uint64_t need, size_t item_size, uint32_t first,
                           uint32_t max_items, const char *what);

/* ---------------------------------------------------------------- mesh -- */

enum vt_vertex_state {
    VT_UNSAMPLED = 0,         /* no rays yet */
    VT_QUEUED,                /* waiting for the sampling of this stage */
    VT_SAMPLED,               /* sample fields valid */
};

/* A vertex as the refinement sees it. The fields it reads for every edge
 * and face it touches come first, and the sample (vt_vertex_sample) lives
 * in an array of its own: the refinement walks the mesh in no particular
 * order, and a 64-byte vertex keeps more of them in the cache than one
 * with its sample inside. Its object is its triangle's
 * (rl_scene_data.triangle_object), not stored. */
typedef struct vt_vertex {
    /* screen, filled by vt_project_vertex */
    float sx, sy;             /* pixel coordinates (x right, y down, pixel
                               * centres at +0.5); 0 when cw <= 0 */
    float depth;              /* eye depth along the view axis */
    float cw;                 /* clip w; <= 0: behind the eye */
    uint8_t state;            /* vt_vertex_state */
    uint8_t visible;          /* z-buffer test passed (Sec. 3.4.2) */
    uint16_t stage;           /* refinement stage that created it (0 = primary) */
    uint32_t triangle;        /* scene triangle the vertex lies on */
    uint64_t key;             /* identity across frames: see vt_vertex_key */
    rl_vec3 p;                /* world position (eq. 3.7: edge midpoint) */
    rl_vec3 n;                /* unit shading normal (eq. 3.8) */
    rl_vec2 uv;               /* interpolated like p */
} vt_vertex;

/* The sample of a vertex, valid once its state is VT_SAMPLED: what the
 * criteria compare (flat, tree_hash) and what the reconstruction
 * draws. A refined mesh holds hundreds of thousands of them, so only what
 * is read later is kept: of the primary layer its diffuse and rest terms
 * (its texture and uv are the face's and the vertex's, Sec. 3.5.3), and
 * the deferred layers (reflection, refraction) only where they are not
 * empty, in the mesh's layer pool (vt_mesh_set_sample). */
typedef struct vt_vertex_sample {
    rl_vec3 flat;             /* radiance with deferred textures white; with
                               * textures=sampled the textured radiance;
                               * with deferred_split the reflected and
                               * transmitted textures applied (vt_sample.c) */
    /* Neither flat's display values nor their HSV are kept: the criteria
     * compute them per test (vt_sample_display, vt_rgb_to_hsv; three powf
     * per end), the same numbers as stored ones. 12 bytes of each of a
     * refined mesh's hundreds of thousands of samples, at the frame's peak
     * (the end of the refinement), cost more than the powf (2026-12-06,
     * bench/README.md "Memory at the defaults, third pass"). */
    rl_vec3 diffuse, rest;    /* of the primary layer */
    uint32_t deferred[2];     /* reflection, refraction: index into
                               * vt_mesh.layers, or with VT_PLAIN_LAYER
                               * set into vt_mesh.plain; VT_NONE when empty */
    uint32_t tree_hash[2];    /* rl_ray_tree_hash of its ray tree, low word
                               * first (vt_sample_tree): as a uint64_t it
                               * would pad the 52-byte sample to 56 */
} vt_vertex_sample;

static inline uint64_t vt_sample_tree(const vt_vertex_sample *s)
{
    return (uint64_t)s->tree_hash[1] << 32 | s->tree_hash[0];
}
static inline void vt_sample_set_tree(vt_vertex_sample *s, uint64_t hash)
{
    s->tree_hash[0] = (uint32_t)hash;
    s->tree_hash[1] = (uint32_t)(hash >> 32);
}

typedef struct vt_edge {
    uint32_t v[2];            /* end vertices */
    uint32_t face[2];         /* adjacent faces, VT_NONE on a boundary:
                               * face[0] has v[0] -> v[1] counter-clockwise
                               * (it created the edge), face[1] the other
                               * (v[1] -> v[0] when consistently wound);
                               * sub-edges keep the direction and slots.
                               * Once the edge is split, a slot may hold the
                               * face's first child (vt_mesh.drop_parents):
                               * then only its primary face is read */
    uint32_t child;           /* sub-edge (v[0],mid) once split, else VT_NONE;
                               * (mid,v[1]) is child + 1, so the midpoint is
                               * the sub-edge's v[1] (vt_edge_mid) */
} vt_edge;
/* 20 bytes, four per generated vertex: whether an edge is in the edge
 * list is a bit of vt_mesh.edge_queued, not a byte here that would pad
 * the edge to 24. */

typedef struct vt_face {
    uint32_t v[3];            /* counter-clockwise, as the source triangle */
    uint32_t e[3];            /* e[i] joins v[(i+1)%3] and v[(i+2)%3] (opposite v[i]) */
    uint32_t triangle;        /* source scene triangle (its object is
                               * rl_scene_data.triangle_object's); its
                               * primary face is the face's primary
                               * ancestor (vt_face_root) */
    uint32_t seq;             /* creation number since the last reset: the
                               * draw order (equals the index unless the mesh
                               * drops split parents, vt_mesh.drop_parents) */
    uint16_t stage;           /* stage that created it (overdraw offset k, Sec. 3.5.1) */
    uint8_t leaf;             /* not split (drawn) */
    uint8_t visible;          /* its primary ancestor passed the ID-buffer test */
    float height;             /* vt_face_height_px once vt_face_height asked
                               * for it this frame, else negative */
} vt_face;

/* A deferred layer without texture (RL_NONE): most reflected and
 * refracted terms (only textured surfaces seen in a mirror have more), 24
 * bytes instead of rl_trace_layer's 36; its uv is never read. */
typedef struct vt_plain_layer {
    rl_vec3 diffuse, rest;
} vt_plain_layer;
#define VT_PLAIN_LAYER 0x80000000u   /* vt_vertex_sample.deferred: in vt_mesh.plain */

typedef struct vt_mesh {
    vt_vertex *verts;  uint32_t num_verts, cap_verts;
    vt_vertex_sample *samples;  uint32_t cap_samples;   /* per vertex, like verts */
    vt_edge *edges;    uint32_t num_edges, cap_edges;
    uint32_t *edge_queued;    /* bit e: edge e is in the edge list (vt_heap);
                               * cap_queued words, at least cap_edges bits
                               * once a reserve succeeded */
    uint32_t cap_queued;
    vt_face *faces;    uint32_t num_faces, cap_faces;
    uint32_t num_created;     /* faces created since the last reset, primary
                               * ones included: the next face's seq */
    /* When set, a split face that is not primary gives its slot to its
     * first child instead of staying behind as a non-leaf: nothing reads
     * it again (its edges' face references move to the children, and the
     * primary ancestor is found through the triangle). About half a refined
     * mesh's faces are such parents. Unset (the default), every face stays
     * (vt_draw's progressive overdraw redraws the faces of the last
     * stages, split or not; the shaft test keeps a verdict per face). */
    bool drop_parents;
    uint32_t *tri_face;       /* scene triangle -> its primary face, VT_NONE */
    uint32_t num_tri_face;
    rl_trace_layer *layers;  uint32_t num_layers, cap_layers;   /* the samples' deferred layers */
    vt_plain_layer *plain;   uint32_t num_plain, cap_plain;     /* ... those without texture and uv */
    uint32_t num_primary_verts, num_primary_edges, num_primary_faces;
} vt_mesh;

/* Builds the primary mesh of the VT objects (object_mask[o] != 0) of a
 * committed scene: one face per scene triangle, vertices welded within an
 * object when position, normal and uv are all equal (loaders often repeat
 * them), edges shared by exactly two faces get both as neighbours; an edge
 * with more than two faces (non-manifold) is kept once per extra face as a
 * boundary edge. Primary vertex keys are vt_vertex_key_primary(object,
 * index of the welded vertex within the object). Faces are visible = 0,
 * leaf = 1, stage 0. RL_ERR_OUT_OF_MEMORY, or RL_ERR_LIMIT past 2^31
 * elements. */
rl_status vt_mesh_build(vt_mesh *m, const rl_scene_data *d, const uint8_t *object_mask);
void vt_mesh_free(vt_mesh *m);
/* Drops everything but the primary elements and resets their refinement
 * state (edges unsplit and unqueued, faces leaf and invisible, vertices
 * unsampled): the start of a new camera frame. Keeps the allocations. */
void vt_mesh_reset(vt_mesh *m);

/* Gives back the edges the refinement made, keeping the primary ones (and
 * the arrays' room for them): once a frame's refinement is over nothing
 * reads them (the draw reads faces, vertices and samples, rl_vt_get_mesh
 * vertices and leaves, the feeler map vertices), and vt_mesh_reset keeps
 * only the primary edges. A refined mesh has four edges per generated
 * vertex, a quarter of its bytes. Afterwards the refined faces' e[] name
 * edges that are gone: only the draw, vt_mesh_pick_in_order and
 * vt_mesh_reset may follow, no split. num_edges is num_primary_edges then. */
void vt_mesh_drop_refined_edges(vt_mesh *m);

/* The primary face that face f descends from (f itself when primary);
 * VT_NONE for a face that is not of the mesh's triangles (vt_part_import). */
static inline uint32_t vt_face_root(const vt_mesh *m, uint32_t f)
{
    if (f < m->num_primary_faces)
        return f;
    uint32_t t = m->faces[f].triangle;
    return t < m->num_tri_face ? m->tri_face[t] : VT_NONE;
}

/* The faces for which pick(user, face) holds, in creation order (vt_face.seq),
 * into *list (grown as needed, capacity *cap); their number in *count.
 * The order is the one faces had when every split parent stayed: children
 * after all faces created before them. RL_ERR_OUT_OF_MEMORY. */
rl_status vt_mesh_pick_in_order(const vt_mesh *m, bool (*pick)(const void *user, const vt_face *f),
                                const void *user, uint32_t **list, size_t *cap, size_t *count);

/* Bytes the mesh's elements take (counts times sizes, without the arrays'
 * spare room). */
uint64_t vt_mesh_bytes(const vt_mesh *m);

/* Room for this many more vertices (and samples), edges and faces; on
 * failure the mesh is unchanged. RL_ERR_OUT_OF_MEMORY or RL_ERR_LIMIT. */
rl_status vt_mesh_reserve(vt_mesh *m, uint32_t verts, uint32_t edges, uint32_t faces);

/* Stores the sample of vertex v: s with its deferred indices set from
 * layers (all RL_TRACE_LAYER_COUNT of them, as rl_tracer_shade_point gives
 * them); a deferred layer that is empty (zero, no texture) takes no room.
 * RL_ERR_OUT_OF_MEMORY or RL_ERR_LIMIT (the sample is then unchanged). */
rl_status vt_mesh_set_sample(vt_mesh *m, uint32_t v, const vt_vertex_sample *s,
                             const rl_trace_layer layers[RL_TRACE_LAYER_COUNT]);
/* The layers of vertex v's sample as vt_mesh_set_sample got them, but for
 * the primary layer's texture (RL_NONE) and uv (0), and the uv (0) of a
 * deferred layer without texture, which are not kept. */
void vt_mesh_sample_layers(const vt_mesh *m, uint32_t v, rl_trace_layer out[RL_TRACE_LAYER_COUNT]);

/* The midpoint vertex of edge e once split, else VT_NONE. */
static inline uint32_t vt_edge_mid(const vt_mesh *m, uint32_t e)
{
    uint32_t c = m->edges[e].child;
    return c != VT_NONE ? m->edges[c].v[1] : VT_NONE;
}
static inline bool vt_edge_is_split(const vt_edge *e)
{
    return e->child != VT_NONE;
}
static inline bool vt_edge_queued(const vt_mesh *m, uint32_t e)
{
    return (m->edge_queued[e >> 5] >> (e & 31)) & 1u;
}
static inline void vt_edge_set_queued(vt_mesh *m, uint32_t e, bool queued)
{
    uint32_t bit = 1u << (e & 31);
    m->edge_queued[e >> 5] = queued ? m->edge_queued[e >> 5] | bit : m->edge_queued[e >> 5] & ~bit;
}

uint64_t vt_vertex_key_primary(uint32_t object, uint32_t index);
/* Symmetric in a and b: the midpoint of an edge has the same key whichever
 * way round or in whichever order the edge was split. */
uint64_t vt_vertex_key_mid(uint64_t a, uint64_t b);

/* Splits edge e at its midpoint (Sec. 3.3, Fig. 3.5): new vertex v' =
 * (v_i + v_j)/2 (eq. 3.7), n' = normalize(n_i + n_j) (eq. 3.8; n_i if the
 * sum vanishes), uv averaged, triangle from the edge's first
 * adjacent face, key vt_vertex_key_mid, stage as given, state UNSAMPLED.
 * Each adjacent leaf face (a, b, c) with the edge (a, b) opposite c becomes
 * two leaf children (a, v', c) and (v', b, c), joined by a new edge (v', c);
 * the parent stops being a leaf, or, with drop_parents and when it is not
 * primary, the first child takes its slot; the children inherit its visible
 * flag and triangle, get the given stage and the next two seq numbers. Edge e gets its child set (vt_edge_mid is v'). The faces' old edges
 * get their face references moved to the children. Returns the new vertex
 * index, or VT_NONE when out of memory (the mesh is unchanged then) or when
 * e is already split (returns its mid then, no change).
 * new_edges receives up to 4 edge indices: the two sub-edges, then the new
 * inner edges; new_faces up to 4 face indices; counts through the pointers.
 * Pointers into the mesh arrays are invalidated (they may grow). */
uint32_t vt_mesh_split(vt_mesh *m, uint32_t e, uint16_t stage, uint32_t new_edges[4],
                       uint32_t *num_new_edges, uint32_t new_faces[4], uint32_t *num_new_faces);

/* Compression factor of face f with the side opposite vertex slot i as base
 * (Sec. 3.3.2): xi = |base| / (|side 1| + |side 2|), from the projected
 * pixel coordinates of the vertices. 0 when both other sides have zero
 * length. */
float vt_face_xi(const vt_mesh *m, uint32_t f, int i);
/* Projected height of the face over its longest side, in pixels: the
 * measure of "no area" (Sec. 3.3.2, A -> 0) that does not depend on the
 * face's length, unlike xi (a 100-pixel sliver 2 pixels wide has xi
 * 0.9996). */
float vt_face_height_px(const vt_mesh *m, uint32_t f);
/* vt_face_height_px, computed once per face and frame: the refinement asks
 * it of a face for each of its edges it tests, and each time it would load
 * three vertices from all over the mesh. Valid once the face's vertices
 * are projected; they are not projected again within a frame. */
float vt_face_height(vt_mesh *m, uint32_t f);

/* ------------------------------------------------------------ criteria -- */

enum vt_criterion_bits {
    VT_CRIT_RGB  = 1 << 0,    /* L1 of the two colours > eps_rgb (eq. 3.11) */
    VT_CRIT_HSV  = 1 << 1,    /* |dH| > eps_h or |dS| > eps_s or |dV| > eps_v */
    VT_CRIT_TREE = 1 << 2,    /* the ray trees differ */
};

typedef struct vt_criteria {
    unsigned bits;            /* vt_criterion_bits, OR-combined: split if any fires */
    float eps_rgb;            /* on display values: sRGB-encoded, clamped to [0,1] */
    float eps_h;              /* hue difference as a fraction of the circle, [0, 0.5] */
    float eps_s, eps_v;       /* in [0, 1] */
} vt_criteria;

/* Parses "rgb", "hsv", "tree", "tree+rgb", "tree+hsv" (also "rgb+tree",
 * "hsv+tree", and "rgb+hsv"); false for anything else. */
bool vt_criteria_parse(const char *text, unsigned *bits);
/* The display values of a sample's flat colour (vt_display per channel):
 * what the colour criteria compare. */
rl_vec3 vt_sample_display(const vt_vertex_sample *sample);
/* The criteria that fire for the samples a and b, as
 * vt_criterion_bits; 0 = interpolation along the edge is acceptable.
 * Colours compared are the vertices' flat colours (deferred textures left
 * out, Sec. 3.5.3). HSV: hue is ignored when either saturation is below
 * 1e-3 (it is undefined for greys); the hue difference wraps around. */
unsigned vt_criteria_test(const vt_criteria *c, const vt_vertex_sample *a, const vt_vertex_sample *b);
/* Which shadow-feeler nodes the ray-tree criterion compares (Sec. 3.3.1,
 * option tree_shadow). BLOCKED: every feeler sent, lit or blocked, as the
 * tracer records it with tree_shadow_any_hit (the default). VISIBLE: only
 * the lights a feeler reaches, the thesis' "sichtbare ... Lichtquellen";
 * a blocked light then equals one the surface faces away from (no feeler
 * sent). OCCLUDER: blocked feelers name their occluder (the tracer must
 * record it: tree_shadow_any_hit off). NONE: no light nodes at all. */
enum { VT_TREE_SHADOW_BLOCKED = 0, VT_TREE_SHADOW_VISIBLE, VT_TREE_SHADOW_OCCLUDER, VT_TREE_SHADOW_NONE };
/* The hash the ray-tree criterion compares: rl_ray_tree_hash of the tree
 * as the reading (shadow: VT_TREE_SHADOW_*; depth: rays of recursion depth
 * <= depth and the feelers of their hits, 0 = all) keeps it. BLOCKED and
 * OCCLUDER with depth 0 keep the tree as traced. */
uint64_t vt_tree_hash(const rl_ray_tree *tree, int shadow, int depth);
/* sRGB display value of one linear channel, clamped to [0, 1]. */
float vt_display(float linear);
/* HSV of a display-space colour: h in [0, 1), s, v in [0, 1]. */
void vt_rgb_to_hsv(rl_vec3 rgb, float *h, float *s, float *v);

/* ---------------------------------------------------------- visibility -- */

/* The camera as the refinement sees it. */
typedef struct vt_view {
    rl_mat4 view_proj;        /* projection * view, as rl_raster_set_camera uses */
    rl_vec3 eye;
    rl_vec3 forward;          /* unit view axis */
    int width, height;
    float z_near;             /* clip w below this is behind the near plane */
    const float *depth;       /* z-buffer of the pre-pass (eye depth per pixel,
                               * +INFINITY where empty), width*height */
    float depth_tolerance;    /* relative, for the z test; e.g. 1e-3 */
} vt_view;

/* Fills sx, sy, depth and cw of vertex v. */
void vt_project_vertex(const vt_view *view, vt_vertex *v);
/* Z-buffer test (Sec. 3.4.2): the vertex is in front of the near plane, on
 * the screen, and not behind the stored depth at any of the (up to) four
 * pixel centres around its projection: depth <= stored * (1 + tolerance).
 * Taking the farthest of the four keeps vertices on silhouettes and on the
 * VT surface itself (which is in the z-buffer) visible. */
bool vt_vertex_visible(const vt_view *view, const vt_vertex *v);
/* Viewport test (Sec. 3.4.3): Cohen-Sutherland outcodes of both ends in
 * clip space (left, right, bottom, top, near); trivially visible when one
 * end is inside, trivially hidden when both share an outside bit, otherwise
 * the edge is clipped plane by plane only until one of the two decisions
 * can be made (the thesis' modification: no full clip). */
bool vt_edge_in_viewport(const vt_view *view, const vt_vertex *a, const vt_vertex *b);
/* Projected length in pixels of the edge (both ends projected); for an edge
 * crossing the near plane, the length of its part in front of the near
 * plane, clipped there. */
float vt_edge_length(const vt_view *view, const vt_vertex *a, const vt_vertex *b);

/* ---------------------------------------------------------- edge list -- */

/* Max-heap of edge indices by length; ties broken by the smaller edge index
 * first, so the order is fully deterministic. (The thesis uses a binary tree
 * with a linked list through it, Fig. 4.10; a heap has the same O(log n)
 * insertion and gives the longest edge in O(1).) */
typedef struct vt_heap_item {
    float length;
    uint32_t edge;
} vt_heap_item;

/* Key and edge side by side: a sift step reads one cache line, not two. */
typedef struct vt_heap {
    vt_heap_item *items;
    uint32_t count, cap;
} vt_heap;

rl_status vt_heap_push(vt_heap *h, uint32_t edge, float length);
/* false when empty. */
bool vt_heap_pop(vt_heap *h, uint32_t *edge, float *length);
/* Length of the top element; -INFINITY when empty. */
float vt_heap_top(const vt_heap *h);
/* Gives back the room of an edge list that emptied: down to the smallest
 * room (1024 times a power of two) at most half full, when that frees
 * 32 KB or more. The items and their order stay. Through
 * vt_array_resize, shrinking returns the pages at once. The refinement
 * calls it once a stage has taken its edges off the list: the pages of
 * the list's longest moment otherwise stay resident to the refinement's
 * end, where the frame peaks (bench/README.md, "Memory, fourth pass"). */
void vt_heap_shrink(vt_heap *h);
void vt_heap_clear(vt_heap *h);
void vt_heap_free(vt_heap *h);

#endif
