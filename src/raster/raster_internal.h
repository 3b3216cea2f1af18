/* raster_internal.h: the rasterizer's state and the contracts between its
 * stages (see rl_raster.h for the public specification).
 *
 * One draw runs in slabs of at most RL_RASTER_SLAB triangles so that scratch
 * memory stays bounded for huge batches. A slab goes through:
 *   setup (raster_setup.c): cull, clip, snap, one rl_raster_prim per fan
 *       triangle; the slab is cut into chunks, one per thread, each chunk
 *       keeps its primitives in submission order;
 *   binning (raster_bin.c): each chunk sorts its primitive indices into
 *       horizontal bands (counting sort, order kept);
 *   fill (raster_fill.c): bands run in parallel, each walks chunk 0, 1, ...
 *       so every pixel sees the primitives in submission order, exactly as a
 *       single thread would. */
#ifndef RL_RASTER_INTERNAL_H
#define RL_RASTER_INTERNAL_H

#include <stdint.h>

#include "rl/rl_raster.h"

/* Sub-pixel precision of the snapped vertices (fixed point 24.8). */
#define RL_RASTER_SUBPIXEL_BITS 8
#define RL_RASTER_SUBPIXEL (1 << RL_RASTER_SUBPIXEL_BITS)
/* Screen coordinates are kept within +-2^20 px by the guard band, so that
 * snapped coordinates fit int32 and edge functions (products of two 29-bit
 * differences) are exact in int64. */
#define RL_RASTER_GUARD_PX (1 << 19)
#define RL_RASTER_BAND_ROWS 16
#define RL_RASTER_SLAB (1u << 15)

/* One setup triangle, oriented with positive area in y-down pixel space.
 * Binning reads y0/y1 through rl_raster_rows, which must come first. */
typedef struct rl_raster_prim {
    int32_t y0, y1;               /* pixel rows [y0, y1), clamped to the viewport */
    int32_t x0, x1;               /* pixel columns [x0, x1) */
    int32_t vx[3], vy[3];         /* snapped vertices, 24.8 fixed point */
    int32_t bias[3];              /* edge i (opposite vertex i): 0 if top-left, else -1 */
    /* Barycentric planes l_k(x, y) = lx[k] x + ly[k] y + l0[k] in pixel
     * units, from the unsnapped vertices: snapping decides coverage only, so
     * interpolated depth is that of the true triangle, not the snapped one. */
    double lx[3], ly[3], l0[3];
    float iw[3];                  /* 1/w */
    float dw[3];                  /* eye depth / w (affine projections only) */
    rl_vec4 cw[3];                /* vertex colour / w (Gouraud only) */
    rl_vec2 uvw[3];               /* uv / w (textured or masked only) */
    rl_vec4 color;                /* flat colour */
    const rl_texture *tex;        /* NULL: untextured */
    const rl_texture *mask;       /* NULL: no alpha mask */
    float cutoff;                 /* mask: drop where alpha < cutoff */
    uint32_t object_id, triangle_id;
    int gouraud;
} rl_raster_prim;

/* Side record of a prim, kept only for layered draws (num_layers > 0), one
 * per prim at the same index: layers read their attributes from the batch
 * instead of the prim, so that up to RL_RASTER_MAX_LAYERS colours and uvs
 * per vertex do not bloat every prim of every other draw. bw[k] holds the
 * barycentrics of prim vertex k in the source triangle (a clipped fan
 * vertex lies inside it) over w, so that b_j = sum_k l_k bw[k]_j / (1/w) is
 * perspective-correct like every other attribute. */
typedef struct rl_raster_prim_src {
    rl_vec3 bw[3];
    uint32_t triangle;            /* index into the batch */
} rl_raster_prim_src;

/* A point's screen square, already clipped to the viewport. */
typedef struct rl_raster_point {
    int32_t y0, y1;
    int32_t x0, x1;
    float depth;
    rl_vec4 color;
    uint32_t object_id, point_id;
} rl_raster_point;

/* Row range header shared by prims and points (their first two fields). */
typedef struct rl_raster_rows { int32_t y0, y1; } rl_raster_rows;

/* Band index lists of one chunk: items of band b are idx[off[b] .. off[b+1]). */
typedef struct rl_raster_bins {
    uint32_t *off;                /* num_bands + 1 */
    uint32_t *idx;
    size_t off_cap, idx_cap;
} rl_raster_bins;

/* Per-thread setup output, reused across draws. */
typedef struct rl_raster_chunk {
    rl_raster_prim *prims;
    size_t num_prims, prim_cap;
    rl_raster_prim_src *srcs;     /* layered draws only, parallel to prims */
    size_t src_cap;
    rl_raster_bins bins;
    uint64_t triangles_drawn;
    uint32_t group_lo, group_hi;  /* rl_raster_draw_many: this chunk's batches */
    bool failed;                  /* allocation failed inside a parallel region */
    /* Set by the caller of rl_raster_setup: no other thread touches the
     * lazy colour stamps of the batches this chunk sets up until the draw
     * ends, so that they need no atomic read-modify-write. */
    bool lazy_alone;
} rl_raster_chunk;

/* What a fill may touch: NULL pointers are layers not written (a query
 * passes none). depth_test NULL draws without a depth test. */
typedef struct rl_raster_target {
    int width, height;
    bool perspective;             /* depth = 1 / (1/w), else (depth/w) / (1/w) */
    bool depth_equal;             /* RL_RASTER_DEPTH_EQUAL: pass on ==, not < */
    bool blend_add;               /* RL_RASTER_BLEND_ADD: rgb += fragment */
    const rl_raster_batch *layered;   /* non-NULL: colour from its layers */
    const float *depth_test;
    float *depth;
    rl_vec4 *color;
    uint32_t *object_id, *triangle_id;
} rl_raster_target;

struct rl_raster {
    int threads;                  /* 0: omp_get_max_threads() at each draw */
    rl_image *target;
    rl_mat4 view_proj;            /* projection * view */
    rl_vec4 view_z;               /* row 2 of view: eye depth = -dot(view_z, p) */
    bool perspective;             /* projection's last row is not (0,0,0,1) */
    float guard_x, guard_y;       /* guard band |x| <= guard * w in clip space */
    /* scratch reused across draws */
    rl_vec4 *clip;                /* clip-space vertices */
    float *eye_depth;             /* per vertex, affine projections only */
    size_t vert_cap, eye_depth_cap;
    size_t *group_vertex;         /* rl_raster_draw_many: each batch's first clip vertex */
    size_t group_cap;
    uintptr_t *lazy_ranges;       /* rl_raster_draw_many: lazy stamp ranges, [start, end) pairs */
    size_t lazy_range_cap;
    rl_raster_chunk *chunks;
    int chunk_cap;
    rl_raster_point *points;
    size_t point_cap;
};

static inline rl_vec4 rl_raster_xform(const rl_mat4 *m, rl_vec3 p)
{
    return rl_v4(m->m[0][0] * p.x + m->m[0][1] * p.y + m->m[0][2] * p.z + m->m[0][3],
                 m->m[1][0] * p.x + m->m[1][1] * p.y + m->m[1][2] * p.z + m->m[1][3],
                 m->m[2][0] * p.x + m->m[2][1] * p.y + m->m[2][2] * p.z + m->m[2][3],
                 m->m[3][0] * p.x + m->m[3][1] * p.y + m->m[3][2] * p.z + m->m[3][3]);
}

static inline int rl_raster_num_bands(int height)
{
    return (height + RL_RASTER_BAND_ROWS - 1) / RL_RASTER_BAND_ROWS;
}

/* rasterizer.c: makes sure r->chunks holds count chunks. */
rl_status rl_raster_reserve_chunks(rl_raster *r, int count);
/* rasterizer.c: threads to use for this draw. */
int rl_raster_thread_count(const rl_raster *r);
/* rasterizer.c: the layers a draw with these flags touches. */
rl_raster_target rl_raster_target_for(const rl_raster *r, unsigned flags, bool query);

/* raster_setup.c: culls, clips and sets up triangles [first, first+count) of
 * the batch into chunk (appending, in order; for a layered batch also
 * chunk->srcs); clip holds the batch's transformed vertices and eye_depth
 * their eye depths (affine projections only). Returns false on allocation
 * failure. */
bool rl_raster_setup(const rl_raster *r, const rl_raster_batch *b, const rl_vec4 *clip,
                     const float *eye_depth, uint32_t first, uint32_t count, rl_raster_chunk *chunk);

/* raster_bin.c: sorts items (each starting with rl_raster_rows, stride bytes
 * apart) into bands of RL_RASTER_BAND_ROWS rows, keeping their order. */
bool rl_raster_bin(rl_raster_bins *bins, const void *items, size_t count, size_t stride,
                   int num_bands);

/* raster_fill.c: rasterizes p within rows [row0, row1); returns the number
 * of fragments that passed the depth test. src is p's side record when
 * t->layered is set, else ignored (may be NULL). */
uint64_t rl_raster_fill_prim(const rl_raster_target *t, const rl_raster_prim *p,
                             const rl_raster_prim_src *src, int row0, int row1);
uint64_t rl_raster_fill_point(const rl_raster_target *t, const rl_raster_point *p,
                              int row0, int row1);

#endif
