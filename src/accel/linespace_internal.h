/* linespace_internal.h: the Line Space object and the pieces its files share
 * (rl_linespace.h documents the public contract and the array layout).
 *
 *   linespace.c        create / commit / release / stats / raw arrays
 *   linespace_shaft.c  index mapping, per-build shaft geometry in cell units,
 *                      the conservative triangle/shaft overlap enumeration
 *   linespace_build.c  per-voxel candidate lists (fixed k and dynamic with a
 *                      prefix sum), PNMT and PREILLUM records
 *   linespace_query.c  the 3D-DDA walk and the per-shaft queries
 *   linespace_io.c     save / load
 *
 * Geometry is handled in "cell units": a voxel is the unit cube [0,1]^3 in
 * them, so one table of shaft geometry serves every voxel of the grid (all
 * cells have the same size, grid.h). */
#ifndef RL_ACCEL_LINESPACE_INTERNAL_H
#define RL_ACCEL_LINESPACE_INTERNAL_H

#include "accel/grid.h"
#include "accel/tri_list.h"
#include "rl/rl_linespace.h"

/* Growth of shafts and of the voxel a triangle is clipped to, in cell units:
 * covers the grid's own cell growth (CELL_GROW_REL 1e-4 in grid_build.c) and
 * the rounding of the query's entry/exit points, so that the overlap test
 * stays conservative (a shaft never misses a triangle its lines can hit). */
#define RL_LS_EPS 3e-4

/* One PNMT record: 8 half floats (Schröder 2017, Sec. 7.4, Fig. 15). */
enum { RL_LS_PNMT_PX, RL_LS_PNMT_PY, RL_LS_PNMT_PZ, RL_LS_PNMT_NX, RL_LS_PNMT_NY,
       RL_LS_PNMT_MAT, RL_LS_PNMT_U, RL_LS_PNMT_V, RL_LS_PNMT_RECORD };

/* The material ID in a PNMT record's signed "ID + 1" (decoded to a float);
 * false for an empty record (0) and for what no build writes (NaN, |m| <
 * 1), whose conversion to an integer would be undefined behaviour. */
static inline bool rl_ls_pnmt_material(float m, uint32_t *id)
{
    float a = m < 0.0f ? -m : m;
    if (!(a >= 1.0f && a <= 65504.0f))      /* 65504: the largest half float */
        return false;
    *id = (uint32_t)(a - 1.0f + 0.5f);
    return true;
}

struct rl_linespace {
    const rl_accel *accel;
    const rl_grid *grid;
    const rl_scene_data *data;
    int n, k, threads;
    bool dynamic;
    bool huge_pages;              /* arrays on transparent huge pages */
    bool masked;                  /* some material has an alpha mask */
    unsigned payloads;
    rl_progress_fn progress;
    void *user;
    rl_ls_shade_fn shade;
    void *shade_user;
    bool committed;
    rl_ls_origin origin;          /* query rule in the start voxel */
    uint32_t shafts_per_voxel;    /* S = 15·N^4 */
    uint32_t num_cells, num_blocks;
    uint32_t *voxel_slot;         /* num_cells */
    /* Per-shaft data exists for occupied shafts only (a shaft any triangle
     * overlaps), at the shaft's rank r among them (rl_ls_shaft_rank):
     * about half the shafts are empty at high voxel resolutions, and their
     * records were most of the memory (and of the build's first-touch
     * page faults). rl_linespace.h documents the layout. */
    uint32_t *cand;               /* fixed: num_occupied·k; dynamic: num_cand */
    uint32_t *cand_start;         /* dynamic: num_occupied + 1 */
    uint64_t num_cand;            /* entries of cand */
    uint16_t *pnmt;               /* num_occupied·16 */
    uint16_t *preillum;           /* num_occupied·8 */
    /* Two words per 64 shafts: [2w] one bit per shaft, set if any
     * triangle overlaps it; [2w+1] the occupied shafts before word w (over
     * all blocks), its rank. Interleaved, so the walk's bit test and the
     * rank of a record share a cache line; 2 bits per shaft are 1/128 of
     * the PNMT records, so empty shafts are skipped in cache and a record
     * is found with one popcount. */
    uint64_t *occupied;           /* 2·blocks·occ_words */
    uint32_t occ_words;           /* per block: ceil(S / 64) */
    uint64_t num_occupied;
    rl_linespace_stats stats;
};

static inline uint64_t rl_ls_occ_word(const rl_linespace *ls, uint32_t block, uint32_t shaft)
{
    return 2 * ((uint64_t)block * ls->occ_words + (shaft >> 6));
}
static inline bool rl_ls_shaft_occupied(const rl_linespace *ls, uint32_t block, uint32_t shaft)
{
    return (ls->occupied[rl_ls_occ_word(ls, block, shaft)] >> (shaft & 63u)) & 1u;
}
/* Sets the bit (each block's words belong to one build thread). */
static inline void rl_ls_shaft_mark(rl_linespace *ls, uint32_t block, uint32_t shaft)
{
    ls->occupied[rl_ls_occ_word(ls, block, shaft)] |= 1ull << (shaft & 63u);
}
/* Index of an occupied shaft's records: its rank among occupied shafts. */
static inline uint64_t rl_ls_shaft_rank(const rl_linespace *ls, uint32_t block, uint32_t shaft)
{
    const uint64_t *w = ls->occupied + rl_ls_occ_word(ls, block, shaft);
    return w[1] + (uint64_t)__builtin_popcountll(w[0] & ((1ull << (shaft & 63u)) - 1u));
}

/* ---- shaft geometry (linespace_shaft.c) ---- */

/* Face f's plane axis and the two in-face axes in increasing order. */
static inline int rl_ls_face_axis(int f) { return f >> 1; }
static inline void rl_ls_face_uv(int f, int *u, int *v)
{
    int a = f >> 1;
    *u = a == 0 ? 1 : 0;
    *v = a == 2 ? 1 : 2;
}
/* Face pair number of (a, b), a < b: lexicographic, (0,1) = 0 .. (4,5) = 14. */
int rl_ls_pair_index(int a, int b);
void rl_ls_pair_faces(int pair, int *a, int *b);

/* Per-build tables in cell units. */
typedef struct rl_ls_geometry {
    int n;
    uint32_t shafts;              /* S */
    float *patch_center;          /* 6·N^2 x 3: centre of patch p on face f at [(f·N^2 + p)·3] */
} rl_ls_geometry;

rl_status rl_ls_geometry_init(rl_ls_geometry *g, int n);
void rl_ls_geometry_free(rl_ls_geometry *g);

/* A triangle in cell units, clipped to the voxel grown by RL_LS_EPS. */
typedef struct rl_ls_tri {
    double v[3][3];               /* the whole triangle */
    double poly[9][3];            /* the clipped polygon */
    int npoly;
    double lo[3], hi[3];          /* the polygon's box */
    double normal[3], d;          /* plane: normal·x = d (unnormalised) */
} rl_ls_tri;

/* Clips triangle (p0, p1, p2), already in cell units, to the grown voxel;
 * false if nothing is left. */
bool rl_ls_tri_setup(rl_ls_tri *t, const double p[3][3]);

/* One shaft a triangle overlaps, with its ordering along the shaft
 * (Schröder 2017, Alg. 3): key_front/key_back are the midpoint ray's
 * parameter (0 at patch A's centre, 1 at B's) of the hit, or for a triangle
 * the midpoint ray misses, the smallest / largest projection of the clipped
 * polygon on the shaft axis. */
typedef struct rl_ls_entry {
    uint32_t shaft;               /* bit 31: the midpoint ray hits the triangle */
    uint32_t tri;                 /* tri_id as given to rl_ls_enumerate: the build
                                   * passes the index in the cell's sorted list */
    float key_front, key_back;
    float u, w;                   /* barycentrics of the midpoint ray's hit */
} rl_ls_entry;
#define RL_LS_ENTRY_HIT 0x80000000u

/* rl_ls_shaft_of_segment on points already in cell units. */
uint32_t rl_ls_shaft_of_unit(int n, const double entry[3], const double exit[3], bool *forward);

/* Appends one entry per shaft that may overlap the triangle (conservative:
 * never misses one) to out, which has room for S entries; returns the
 * number appended. scratch: RL_LS_ENUM_SCRATCH(N) doubles (6·N^2 for
 * each of five per-patch values) + 4·N^2 ints. */
#define RL_LS_ENUM_SCRATCH(n) ((size_t)30 * (size_t)(n) * (size_t)(n))
uint32_t rl_ls_enumerate(const rl_ls_geometry *g, const rl_ls_tri *t, uint32_t tri_id,
                         rl_ls_entry *out, double *scratch, int *iscratch);

/* Midpoint ray parameter and barycentrics where the segment a->b meets the
 * triangle (cell units); false if it does not (within a small tolerance).
 * The build finds the same hits from per-patch values (rl_ls_enumerate);
 * this Möller-Trumbore test is their reference in the tests. */
bool rl_ls_segment_hit(const double a[3], const double b[3], const double v[3][3], double *s,
                       double *u, double *w);
/* Barycentrics (u, w) of the triangle's point closest to q (cell units). */
void rl_ls_closest_point(const double v[3][3], const double q[3], double *u, double *w);

/* The surface at barycentrics (u, v) of triangle tri (p = (1-u-v)·p0 +
 * u·p1 + v·p2): position, interpolated unit normal, uv, material. */
void rl_ls_surface_at(const rl_linespace *ls, uint32_t tri, float u, float v, rl_ls_surface *s);

/* ---- build and queries ---- */
/* The checksum of a Line Space file (linespace_io.c), continued from h
 * over n bytes; a file ends with the sum over all bytes before it. */
uint64_t rl_ls_file_hash(uint64_t h, const void *data, size_t n);

rl_status rl_ls_build(rl_linespace *ls);
/* Allocates ls->occupied (zeroed); false when out of memory. */
bool rl_ls_occupancy_alloc(rl_linespace *ls);
size_t rl_ls_memory_bytes(const rl_linespace *ls);
void rl_ls_free_arrays(rl_linespace *ls);

/* ---- object Line Spaces (linespace_object.c, walks in linespace_query.c) ---- */
/* A world ray in an object's space: the object-space point at world
 * parameter t is o + (t - t_shift)·d (o is taken near the object so that
 * its rounding stays small against the voxels); slack bounds, in t, how far
 * the object-space and the world parametrisation may disagree. */
typedef struct rl_ls_local_ray {
    double o[3], d[3];
    float t_shift, slack;
} rl_ls_local_ray;

/* The closest hit among the candidates of ls (dynamic lists, built in
 * object space, local triangle i = scene triangle id_base + i with world
 * vertices verts[3(id_base + i) ..]) along lr, tested against the world
 * ray's w within (t_min, *limit), as rl_tri_list_closest. */
void rl_ls_mapped_closest(const rl_linespace *ls, const rl_ls_local_ray *lr, const rl_vec3 *verts,
                          uint32_t id_base, const rl_ray_watertight *w, float t_min, rl_mailbox *mailbox,
                          rl_tri_closest *best, float *limit);
/* For the scene Line Space, whose inner structure may be object Line
 * Spaces: their scene, and whether they are committed. */
const rl_scene *rl_ls_objects_scene(const rl_ls_objects *o);
bool rl_ls_objects_committed(const rl_ls_objects *o);

/* Whether any candidate is hit within (t_min, t_max). */
bool rl_ls_mapped_any(const rl_linespace *ls, const rl_ls_local_ray *lr, const rl_vec3 *verts, uint32_t id_base,
                      const rl_ray_watertight *w, float t_min, float t_max, rl_mailbox *mailbox);

#endif
