/* rl_linespace.h: the Line Space (Keul, Müller, Lemke 2016) as built and
 * used by Schröder 2017, Ch. 4 and 7, on the CPU.
 *
 * A Line Space lives inside each voxel of a uniform grid (the grid of
 * RL_ACCEL_GRID, Sec. 6.1). Each of the voxel's 6 faces is split into N x N
 * patches; a shaft joins two patches on different faces. Of the 36·N^4
 * ordered patch pairs, 15·N^4 are unique and relevant (a pair and its
 * reverse are one shaft; pairs on one face hold nothing), Sec. 4.2. A ray
 * crossing a voxel enters through one patch and leaves through another, so
 * it lies inside exactly that shaft, and only what the shaft holds can
 * stop it there.
 *
 * Payloads, each with its own queries (Sec. 7.1-7.4):
 *   CANDIDATES  the triangles overlapping the shaft, ordered along the
 *               shaft ("front" first, the thesis' front/back buffers).
 *               Fixed: k slots per shaft, the k/2 front-most and k/2
 *               back-most (Alg. 3); a fuller shaft loses triangles and the
 *               query may miss them (the thesis' artefacts). Dynamic: a
 *               counting pass and a prefix sum size each shaft's list
 *               exactly (proposed in Sec. 7.1.1, built here), so queries
 *               are exact: the same hit as the BVH.
 *   PNMT        position, normal, material and texcoord of the front-most
 *               and back-most surface in the shaft, 8 half floats each
 *               (16 per shaft), n_z rebuilt from its sign (eq. 9).
 *               Queries return that stored surface: no triangle test.
 *   PREILLUM    the front and back surfaces' colour under direct light
 *               (shadow feelers to every light), from a caller-supplied
 *               shading function. Queries return a colour.
 *
 * Index mapping (explicit, tested bijective over the 15·N^4 shafts):
 *   faces      0 -x, 1 +x, 2 -y, 3 +y, 4 -z, 5 +z;
 *   patch      p = i + N·j on a face, (i, j) the patch's cell along the
 *              face's two other axes in increasing axis order
 *              (face ±x: (y, z); ±y: (x, z); ±z: (x, y));
 *   face pair  (a, b) with a < b, numbered 0..14 in lexicographic order
 *              ((0,1)=0, (0,2)=1, ..., (4,5)=14);
 *   shaft      pair·N^4 + p_a·N^2 + p_b.
 *   A ray going from face a to face b (a < b) runs the shaft "forward";
 *   from b to a "backward" (it meets the back list first).
 *
 * Data layout (flat arrays, close to the thesis' textures, so that a GPU
 * version can upload them unchanged; see rl_linespace_data):
 *   voxel_slot[cell]  per grid cell, the index of its Line Space block, or
 *                     RL_NONE for a voxel without triangles (an empty voxel
 *                     needs no shafts: every ray crosses it freely);
 *   occupancy[2w], w = b·W + s/64, bit s%64 (W = ceil(15·N^4 / 64)
 *                  words per block): whether any triangle overlaps shaft
 *                  s of block b; occupancy[2w + 1]: the occupied shafts
 *                  before word w. Only occupied shafts have lists and
 *                  records, stored at the shaft's rank among all occupied
 *                  shafts, r = occupancy[2w + 1] + popcount(occupancy[2w] &
 *                  ((1 << s%64) - 1)) (our change: the thesis stores every
 *                  shaft; about half are empty, so this halves the
 *                  memory);
 *   fixed lists:   cand[r·k .. r·k + k-1], front half then back half,
 *                  RL_NONE padded;
 *   dynamic lists: cand[start[r] .. start[r+1]-1], ordered front to back;
 *   pnmt[r·16 .. r·16 + 15] (uint16 half floats), front record then back:
 *                  position (voxel-relative, in [0,1]^3 of the voxel box:
 *                  our change, it keeps half-float precision independent
 *                  of the scene's size), normal x, y, material ID + 1 with
 *                  the sign of n_z, texcoord u, v;
 *   preillum[r·8 .. r·8 + 7] (half floats), front RGBA then back RGBA.
 *
 * Lifecycle as rl_accel: create (borrowing a committed RL_ACCEL_GRID accel,
 * which must outlive the Line Space), optionally set the shading function,
 * commit (builds), then thread-safe queries that cannot fail.
 *
 * Memory pages: the arrays of 4 MiB or more (and the build's temporary
 * lists) are 2 MiB-aligned and advised for transparent huge pages on Linux
 * (madvise MADV_HUGEPAGE; a no-op where the kernel has them off). A build
 * writes gigabytes once, and first-touch faults of 4 KiB pages were 35-50 %
 * of it on our 2-core VM; with huge pages teapot 32^3 built in 1.5-2.7 s
 * instead of 3.5-3.8 s (docs/line-space.md). On a machine whose kernel
 * compacts memory on every huge fault this can be slower (seen on another
 * VM of ours): desc.small_pages keeps plain malloc. Loaded Line Spaces
 * always ask for huge pages. */
#ifndef RL_LINESPACE_H
#define RL_LINESPACE_H

#include "rl/rl_accel.h"
#include "rl/rl_common.h"
#include "rl/rl_math.h"

#ifdef __cplusplus
extern "C" {
#endif

#define RL_LS_DEFAULT_N 5      /* Schröder 2017, Sec. 9.2: N = 5 in all tests */
#define RL_LS_MAX_N 16
#define RL_LS_DEFAULT_K 8      /* fixed slots per shaft (not stated in the thesis) */
#define RL_LS_MAX_K 256
#define RL_LS_FACE_PAIRS 15

typedef enum rl_ls_payload {
    RL_LS_CANDIDATES = 1u << 0,
    RL_LS_PNMT       = 1u << 1,
    RL_LS_PREILLUM   = 1u << 2
} rl_ls_payload;

typedef struct rl_linespace rl_linespace;       /* opaque */

typedef struct rl_linespace_desc {              /* zero = default */
    int n;                    /* patches per face side; 0 -> RL_LS_DEFAULT_N */
    int k;                    /* fixed candidate slots per shaft (even);
                               * 0 -> RL_LS_DEFAULT_K; unused when dynamic */
    bool dynamic;             /* exact per-shaft lists (prefix sums) */
    unsigned payloads;        /* rl_ls_payload bits; 0 -> RL_LS_CANDIDATES */
    int threads;              /* build threads; 0 -> all */
    bool small_pages;         /* don't advise the arrays for transparent
                               * huge pages (see above) */
    rl_progress_fn progress;  /* may be NULL; false cancels the build */
    void *user;
} rl_linespace_desc;

/* A surface point as a PNMT record holds it, or as an exact hit yields it. */
typedef struct rl_ls_surface {
    float t;                  /* along the query ray */
    rl_vec3 p;                /* world position */
    rl_vec3 n;                /* unit shading normal */
    rl_vec2 uv;
    uint32_t material;        /* scene material index */
} rl_ls_surface;

/* Direct light leaving surface s towards -dir (dir: the direction the ray
 * travels when it reaches s), for PREILLUM. Called from build threads. */
typedef rl_vec3 (*rl_ls_shade_fn)(void *user, const rl_ls_surface *s, rl_vec3 dir);

typedef struct rl_linespace_stats {
    int n, k;
    bool dynamic;
    unsigned payloads;
    int grid_res[3];
    uint32_t voxels, filled_voxels;    /* grid cells; cells with a block */
    uint64_t shafts;                   /* filled_voxels · 15·N^4 */
    uint64_t empty_shafts;             /* no triangle overlaps the shaft */
    uint64_t candidates;               /* stored candidate references */
    uint32_t max_candidates;           /* in one shaft, before truncation */
    double mean_candidates;            /* per non-empty shaft, before truncation */
    uint64_t truncated_shafts;         /* fixed lists that lost triangles */
    double build_ms;                   /* all payloads, without the grid */
    double candidates_ms, pnmt_ms, preillum_ms;
    size_t memory_bytes;               /* all arrays */
} rl_linespace_stats;

/* RL_ERR_INVALID_ARG: NULL, an accel that is not RL_ACCEL_GRID or not
 * committed, n outside 1..RL_LS_MAX_N, k odd or outside 2..RL_LS_MAX_K,
 * unknown payload bits. */
RL_API rl_status rl_linespace_create(const rl_accel *grid, const rl_linespace_desc *desc,
                                     rl_linespace **out);
/* Required before commit when PREILLUM is requested (else RL_ERR_INVALID_ARG
 * at commit). */
RL_API rl_status rl_linespace_set_shader(rl_linespace *ls, rl_ls_shade_fn fn, void *user);
/* Builds; RL_ERR_OUT_OF_MEMORY, RL_ERR_LIMIT (more than 2^32-1 shafts or
 * candidates), RL_ERR_CANCELLED. A second commit is a no-op. */
RL_API rl_status rl_linespace_commit(rl_linespace *ls);
RL_API void rl_linespace_release(rl_linespace *ls);       /* NULL is a no-op */
RL_API void rl_linespace_get_stats(const rl_linespace *ls, rl_linespace_stats *out);
RL_API const rl_accel *rl_linespace_grid(const rl_linespace *ls);

/* ---- index mapping (pure functions) ---- */
static inline uint32_t rl_ls_shafts_per_voxel(int n) { return 15u * (uint32_t)(n * n) * (uint32_t)(n * n); }
/* Shaft index for patches pa on face fa and pb on face fb (fa != fb, either
 * order); *forward (may be NULL) says whether fa < fb. RL_NONE if fa == fb. */
RL_API uint32_t rl_ls_shaft_index(int n, int fa, int pa, int fb, int pb, bool *forward);
/* Inverse: the faces (fa < fb) and patches of shaft s < 15·N^4. */
RL_API void rl_ls_shaft_decode(int n, uint32_t s, int *fa, int *pa, int *fb, int *pb);
/* The shaft a line crosses in a voxel, from its entry and exit points on
 * the voxel box (as the query does); RL_NONE when both lie on one face. */
RL_API uint32_t rl_ls_shaft_of_segment(int n, rl_aabb voxel, rl_vec3 entry, rl_vec3 exit,
                                       bool *forward);

/* ---- queries (committed Line Space; thread-safe; bad rays miss) ----
 * All walk the grid's voxels front to back with the 3D-DDA and consult
 * each filled voxel's shaft for the ray. */

/* CANDIDATES: closest hit among the shaft candidates, as rl_accel_intersect
 * (shortens ray->t_max on a hit). Exact with dynamic lists; with fixed
 * lists a truncated shaft may miss. */
RL_API bool rl_linespace_intersect(const rl_linespace *ls, rl_ray *ray, rl_hit *hit);
RL_API bool rl_linespace_occluded(const rl_linespace *ls, const rl_ray *ray);
/* PNMT: the first stored surface along the ray within (t_min, t_max),
 * without a triangle test; its t is the stored point projected on the ray. */
RL_API bool rl_linespace_pnmt_intersect(const rl_linespace *ls, const rl_ray *ray,
                                        rl_ls_surface *s);
/* PNMT shadow test: whether a stored surface lies within (t_min, t_max). */
RL_API bool rl_linespace_pnmt_occluded(const rl_linespace *ls, const rl_ray *ray);
/* PREILLUM: the stored colour of the first surface along the ray; *t as
 * for PNMT (may be NULL). False (colour untouched) if none. */
RL_API bool rl_linespace_preillum(const rl_linespace *ls, const rl_ray *ray, rl_vec3 *color,
                                  float *t);
/* PREILLUM shadow test: whether rl_linespace_preillum finds a surface (the
 * same answer, without loading the colours). */
RL_API bool rl_linespace_preillum_occluded(const rl_linespace *ls, const rl_ray *ray);

/* What the PNMT and PREILLUM queries do in the voxel that holds the ray's
 * point at t_min (the voxel it starts in), where a stored surface is most
 * often the one the ray leaves:
 *   RL_LS_ORIGIN_EXACT    PNMT: the closest hit among the voxel's triangles;
 *                         PREILLUM: records only beyond a tenth of the voxel
 *                         diagonal (the default, for rays from a surface);
 *   RL_LS_ORIGIN_RECORDS  records as in every other voxel, for callers that
 *                         move t_min past the voxel of their surface
 *                         themselves (the thesis' voxel offset, Sec. 12.1).
 * A query policy, not build data (a loaded Line Space starts EXACT); not to
 * be changed while queries run. RL_ERR_INVALID_ARG for NULL or an unknown
 * rule. */
typedef enum rl_ls_origin { RL_LS_ORIGIN_EXACT = 0, RL_LS_ORIGIN_RECORDS } rl_ls_origin;
RL_API rl_status rl_linespace_set_origin(rl_linespace *ls, rl_ls_origin origin);

/* ---- raw arrays, for a GPU upload and for tests ---- */
typedef struct rl_linespace_data {
    int n, k;
    bool dynamic;
    uint32_t shafts_per_voxel;         /* 15·N^4 */
    uint32_t num_cells, num_blocks;
    const uint32_t *voxel_slot;        /* num_cells entries */
    const uint32_t *cand;              /* candidate triangle IDs */
    const uint32_t *cand_start;        /* dynamic: num_occupied + 1 entries; else NULL */
    uint64_t num_cand;
    const uint16_t *pnmt;              /* num_occupied records, or NULL */
    const uint16_t *preillum;          /* num_occupied records, or NULL */
    uint32_t occ_words;                /* W: occupancy words per block */
    uint64_t num_occupied;             /* shafts with triangles */
    const uint64_t *occupancy;         /* 2·num_blocks·W words: bits, rank */
} rl_linespace_data;
RL_API void rl_linespace_get_data(const rl_linespace *ls, rl_linespace_data *out);

/* ---- save and load (Schröder 2017, Sec. 13.3) ----
 * A versioned little-endian file with a checksum over its contents and a
 * fingerprint of the scene's triangles and the grid (resolution, bounds).
 * Load refuses (RL_ERR_PARSE: corrupt/truncated/wrong version; RL_ERR_INVALID_ARG:
 * another scene or grid) with a message saying which. A loaded Line Space
 * is committed and answers queries bit-identically to the saved one. */
RL_API rl_status rl_linespace_save(const rl_linespace *ls, const char *path);
RL_API rl_status rl_linespace_load(const rl_accel *grid, const char *path, rl_linespace **out);


/* ---- scene and object Line Spaces (Schröder 2017, Sec. 13.1, 13.2) ----
 * docs/line-space.md has the design and the measurements.
 *
 * SCENE LINE SPACE (Sec. 13.1). One Line Space whose single "voxel" is the
 * scene's box: N x N patches per face, 15·N^4 shafts, and per shaft a
 * signature of M bits (M segments of equal length in λ, the parameter that
 * runs from 0 on the shaft's patch A (lower face) to 1 on patch B): bit j is
 * set when geometry may lie in the part of the shaft with λ in
 * [j/M, (j+1)/M]. A line through patches A and B at points a and b is, at
 * λ, in the box (1-λ)·A + λ·B (a Minkowski sum of two axis-aligned
 * rectangles), so the λ-range over which a shaft meets an axis-aligned
 * cell is an interval found from six linear inequalities, exactly. The
 * build marks the segments of every filled cell of an occupancy grid
 * (the cells of RL_ACCEL_GRID's exact triangle/box test, `cells` per axis)
 * in every shaft: conservative, so a ray's hits all lie in set segments.
 * A query maps the ray to its shaft (its line's entry and exit on the
 * box), turns the runs of set bits within (t_min, t_max) into t-intervals
 * and asks the inner structure about each in ray order, stopping at the
 * first hit: the same hit as the inner structure alone, and for shadow
 * rays often no inner query at all.
 *
 * OBJECT LINE SPACE (Sec. 13.2). One per-voxel Line Space (dynamic
 * candidates, on a grid of `res` voxels per axis) per mesh, built in the
 * mesh's object space (the flattened world triangles mapped back by the
 * inverse of the instance transform); instances of one mesh whose object-
 * space vertices agree share it. A top level (a BVH over the instances'
 * world boxes) orders the instances; a ray is transformed into the
 * instance's object space, walks its Line Space there, and the candidates
 * are tested in world space against the scene's triangles with the shared
 * watertight test, so answers are the BVH's bit for bit. A transform that
 * cannot be inverted (a flattened instance) gets a Line Space of its own
 * in world space. */

typedef struct rl_ls_objects rl_ls_objects;     /* opaque */

#define RL_LS_OBJECT_DEFAULT_RES 8   /* voxels per axis and object (measured: docs/line-space.md) */
#define RL_LS_OBJECT_MAX_RES 64

typedef struct rl_ls_objects_desc {             /* zero = default */
    int n;                    /* patches per voxel face side; 0 -> RL_LS_DEFAULT_N */
    int res;                  /* voxels per axis of each object's grid;
                               * 0 -> RL_LS_OBJECT_DEFAULT_RES */
    int threads;              /* build threads; 0 -> all */
} rl_ls_objects_desc;

typedef struct rl_ls_objects_stats {
    int n, res;
    uint32_t objects;                  /* instances with triangles */
    uint32_t linespaces;               /* built (instances may share one) */
    uint32_t world_space;              /* of these, built in world space */
    uint64_t shafts, candidates;       /* summed over the Line Spaces */
    double build_ms;
    size_t memory_bytes;               /* Line Spaces, their grids, the top level */
} rl_ls_objects_stats;

/* RL_ERR_INVALID_ARG: NULL, a scene that is not committed, n outside
 * 1..RL_LS_MAX_N, res outside 1..RL_LS_OBJECT_MAX_RES, threads < 0. */
RL_API rl_status rl_ls_objects_create(const rl_scene *scene, const rl_ls_objects_desc *desc,
                                      rl_ls_objects **out);
/* Builds; RL_ERR_OUT_OF_MEMORY, RL_ERR_LIMIT. A second commit is a no-op. */
RL_API rl_status rl_ls_objects_commit(rl_ls_objects *o);
RL_API void rl_ls_objects_release(rl_ls_objects *o);     /* NULL is a no-op */
RL_API void rl_ls_objects_get_stats(const rl_ls_objects *o, rl_ls_objects_stats *out);
/* Exact queries, as rl_accel_intersect / rl_accel_occluded (alpha masks
 * included); thread-safe; bad rays miss. */
RL_API bool rl_ls_objects_intersect(const rl_ls_objects *o, rl_ray *ray, rl_hit *hit);
RL_API bool rl_ls_objects_occluded(const rl_ls_objects *o, const rl_ray *ray);

typedef struct rl_ls_scene rl_ls_scene;         /* opaque */

#define RL_LS_SCENE_DEFAULT_N 4      /* N and cells measured: docs/line-space.md */
#define RL_LS_SCENE_MAX_N 24
#define RL_LS_SCENE_DEFAULT_SEGMENTS 64
#define RL_LS_SCENE_MAX_SEGMENTS 64  /* one 64-bit signature per shaft */
#define RL_LS_SCENE_DEFAULT_CELLS 16
#define RL_LS_SCENE_MAX_CELLS 256

/* What answers the filled intervals; exactly one is set, borrowed (it
 * must be committed, on the same scene, and outlive the scene Line Space). */
typedef struct rl_ls_scene_inner {
    const rl_accel *accel;            /* any kind: BVH, grid, Embree */
    const rl_linespace *linespace;    /* per-voxel, CANDIDATES payload */
    const rl_ls_objects *objects;     /* object Line Spaces */
} rl_ls_scene_inner;

typedef struct rl_ls_scene_desc {               /* zero = default */
    int n;                    /* patches per face side of the scene box;
                               * 0 -> RL_LS_SCENE_DEFAULT_N */
    int segments;             /* signature bits per shaft, M;
                               * 0 -> RL_LS_SCENE_DEFAULT_SEGMENTS */
    int cells;                /* occupancy cells per axis;
                               * 0 -> RL_LS_SCENE_DEFAULT_CELLS */
    int threads;              /* build threads; 0 -> all */
    rl_ls_scene_inner inner;
} rl_ls_scene_desc;

typedef struct rl_ls_scene_stats {
    int n, segments, cells;
    uint64_t shafts;                   /* 15·N^2·N^2 */
    uint64_t filled_bits;              /* set signature bits over all shafts */
    uint32_t filled_cells;
    double build_ms;                   /* occupancy grid and signatures */
    size_t memory_bytes;               /* signatures and occupancy grid */
} rl_ls_scene_stats;

/* RL_ERR_INVALID_ARG: NULL, a scene that is not committed, parameters out
 * of range (n 1..RL_LS_SCENE_MAX_N, segments 1..64, cells
 * 1..RL_LS_SCENE_MAX_CELLS, threads >= 0), not exactly one inner
 * structure, an inner one not committed, of another scene, or a per-voxel
 * Line Space without CANDIDATES. */
RL_API rl_status rl_ls_scene_create(const rl_scene *scene, const rl_ls_scene_desc *desc,
                                    rl_ls_scene **out);
RL_API rl_status rl_ls_scene_commit(rl_ls_scene *s);     /* builds; a second is a no-op */
RL_API void rl_ls_scene_release(rl_ls_scene *s);         /* NULL is a no-op */
RL_API void rl_ls_scene_get_stats(const rl_ls_scene *s, rl_ls_scene_stats *out);
/* The signature of shaft `shaft` (< 15·N^4; 0 beyond), bit j = segment j. */
RL_API uint64_t rl_ls_scene_signature(const rl_ls_scene *s, uint32_t shaft);
/* Exact queries (the inner structure's answers); thread-safe; bad rays miss. */
RL_API bool rl_ls_scene_intersect(const rl_ls_scene *s, rl_ray *ray, rl_hit *hit);
RL_API bool rl_ls_scene_occluded(const rl_ls_scene *s, const rl_ray *ray);

#ifdef __cplusplus
}
#endif
#endif
