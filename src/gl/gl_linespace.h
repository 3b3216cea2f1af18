/* gl_linespace.h: the Line Space (rl_linespace.h) on OpenGL 4.5
 * (gl_linespace.c, gl_linespace_glsl.c; Schröder 2017, Sec. 7): uploaded
 * from a CPU build, or built on the GPU by compute shaders, and walked in
 * GLSL by the snippet rl_gl_linespace_glsl() returns.
 *
 * Everything here works in the GL context current on the calling thread:
 * a GL renderer (gl-pt) makes its context current, calls rl_gl_ls_upload
 * or rl_gl_ls_build, and before each dispatch rl_gl_ls_bind and
 * rl_gl_ls_set_uniforms on its program. Buffers live in that context and
 * are deleted by rl_gl_ls_release (with the context current).
 *
 * Layout: the CPU arrays of rl_linespace.h unchanged, at shader storage
 * bindings 16-23 (gl-pt uses 0-15):
 *   16 voxel_slot[cell]        uint, RL_NONE for an empty voxel
 *   17 occupancy[word]         uvec4 (bits 0-31, bits 32-63, rank, 0) per
 *                              64 shafts of a block (the CPU's two uint64
 *                              words; the rank fits 32 bits, see limits)
 *   18 cand[]                  uint: fixed k per occupied shaft, or the
 *                              dynamic lists
 *   19 cand_start[r]           uint, dynamic lists only (num_occupied + 1)
 *   20 pnmt[r·8 .. r·8 + 7]    uint: the CPU's 16 half floats, two per word
 *                              (element 2i in the low half: unpackHalf2x16)
 *   21 preillum[r·4 .. r·4+3]  uint: the 8 half floats, two per word
 *   22 tri_verts[9·tri ..]     float: the grid's vertex copy (grid.h)
 *   23 cells[]                 uint: cell_start (num_cells + 1), then
 *                              cell_tris from u_ls_cell_tris_at on
 * A buffer a variant lacks (no PNMT, fixed lists without cand_start) is
 * bound as a 16-byte placeholder, so that every binding is valid.
 *
 * The GPU build (rl_gl_ls_build) produces the CANDIDATES payload, fixed k
 * or dynamic lists, with the same contents and order as the CPU build
 * (linespace_build.c); PNMT and PREILLUM are upload only. It uses bindings
 * 16-23 for its own buffers while it runs: bind again afterwards. */
#ifndef RL_GL_LINESPACE_H
#define RL_GL_LINESPACE_H

#include <stddef.h>
#include <stdint.h>

#include "rl/rl_linespace.h"

enum {
    RL_GL_LS_SSBO_VOXELS = 16,
    RL_GL_LS_SSBO_OCCUPANCY = 17,
    RL_GL_LS_SSBO_CAND = 18,
    RL_GL_LS_SSBO_CAND_START = 19,
    RL_GL_LS_SSBO_PNMT = 20,
    RL_GL_LS_SSBO_PREILLUM = 21,
    RL_GL_LS_SSBO_TRIS = 22,
    RL_GL_LS_SSBO_CELLS = 23,
};

typedef struct rl_gl_ls rl_gl_ls;

/* Limits: max_buffer_bytes caps every buffer (0: the GL's
 * GL_MAX_SHADER_STORAGE_BLOCK_SIZE; a smaller value is taken as given, for
 * tests). Over it, or over 32-bit indices, RL_ERR_LIMIT says which. */
typedef struct rl_gl_ls_limits {
    uint64_t max_buffer_bytes;
} rl_gl_ls_limits;

/* Timings of a GPU build: GL_TIME_ELAPSED of its passes (count, scan,
 * occupancy, fill) and the wall time from the first upload to the result
 * in GPU memory (glFinish), uploads and the readback of the total
 * included, the shaders' compilation (before it) not. */
typedef struct rl_gl_ls_stats {
    bool gpu_built;
    int n, k;
    bool dynamic;
    unsigned payloads;
    uint32_t blocks;
    uint64_t shafts, occupied, candidates;
    uint64_t gpu_bytes;           /* every buffer */
    double gpu_ms, wall_ms;       /* GPU build only */
    double stamp_ms;              /* the same passes between GL_TIMESTAMP
                                   * queries (llvmpipe's GL_TIME_ELAPSED
                                   * times draws only and reads 0 for compute) */
} rl_gl_ls_stats;

/* The arrays of a CPU build (committed ls) into buffers. RL_ERR_LIMIT
 * where they exceed the limits, RL_ERR_INTERNAL for a GL error. */
rl_status rl_gl_ls_upload(const rl_linespace *ls, const rl_gl_ls_limits *lim, rl_gl_ls **out);
/* Builds on the GPU (Sec. 7): grid is a committed RL_ACCEL_GRID accel,
 * desc as rl_linespace_create's (payloads must be CANDIDATES only;
 * threads, progress and small_pages are ignored). */
rl_status rl_gl_ls_build(const rl_accel *grid, const rl_linespace_desc *desc, const rl_gl_ls_limits *lim,
                         rl_gl_ls **out);
void rl_gl_ls_release(rl_gl_ls *g);                     /* NULL is a no-op */
void rl_gl_ls_get_stats(const rl_gl_ls *g, rl_gl_ls_stats *out);

/* Binds the eight buffers at 16-23. */
void rl_gl_ls_bind(const rl_gl_ls *g);
/* Sets the u_ls_* uniforms of the snippet in program (a GLuint that
 * includes it). */
void rl_gl_ls_set_uniforms(const rl_gl_ls *g, unsigned program);

/* The GLSL 4.50 snippet of the walk (gl_linespace_glsl.c): the buffers at
 * 16-23, the u_ls_* uniforms and
 *   bool rl_ls_intersect(vec3 o, vec3 d, float t_min, float t_max,
 *                        out uint tri, out float t, out float u, out float v)
 *   bool rl_ls_occluded(vec3 o, vec3 d, float t_min, float t_max)
 * as rl_linespace_intersect / rl_linespace_occluded (CANDIDATES; without
 * that payload every filled voxel tests its grid list), and
 *   bool rl_ls_pnmt_intersect(vec3 o, vec3 d, float t_min, float t_max,
 *                             out float t, out uint tri, out vec3 p,
 *                             out vec3 n, out vec2 uv, out uint material)
 *   bool rl_ls_pnmt_occluded(vec3 o, vec3 d, float t_min, float t_max)
 * as rl_linespace_pnmt_intersect / _occluded (uploaded PNMT records; the
 * Line Space's origin rule at upload): a record gives tri = 0xffffffff and
 * p, n, uv, material; the start voxel under RL_LS_ORIGIN_EXACT gives the
 * exact hit's triangle and t, which the caller shades itself; and
 *   bool rl_ls_preillum(vec3 o, vec3 d, float t_min, float t_max,
 *                       out vec3 color, out float t)
 *   bool rl_ls_preillum_occluded(vec3 o, vec3 d, float t_min, float t_max)
 * as rl_linespace_preillum / _preillum_occluded (uploaded records). Include it after
 * "#version 450 core" and before the program's own code. */
const char *rl_gl_linespace_glsl(void);

/* Traces rays[0..count) through the walk in one compute pass (buffers at
 * bindings 0 and 1, then 16-23), what a GL renderer does per pixel, for
 * tests and measurements. CANDIDATES: per ray the closest hit (tri, t, u,
 * v) and the occlusion answer; PNMT (uploaded records): the first stored
 * surface (record: its material and t; in the start voxel under the exact
 * origin rule a triangle) and the PNMT occlusion answer; PREILLUM: the
 * stored colour and t, and the PREILLUM occlusion answer.
 * RL_ERR_INVALID_ARG for a NULL argument, count outside 1..2^24, or PNMT
 * without records. */
typedef enum rl_gl_ls_query {
    RL_GL_LS_QUERY_CANDIDATES,
    RL_GL_LS_QUERY_PNMT,
    RL_GL_LS_QUERY_PREILLUM
} rl_gl_ls_query;
typedef struct rl_gl_ls_hit {
    bool hit;
    uint32_t tri;                 /* RL_NONE for none, or a PNMT record */
    float t, u, v;
    uint32_t material;            /* PNMT records */
    bool record;                  /* PNMT: the answer is a record */
    float color[3];               /* PREILLUM */
    bool occluded;
} rl_gl_ls_hit;
rl_status rl_gl_ls_trace(const rl_gl_ls *g, const rl_ray *rays, uint32_t count, rl_gl_ls_query query,
                         rl_gl_ls_hit *out);

/* The arrays back from GPU memory, in rl_linespace_data's layout (for
 * tests); free with rl_gl_ls_arrays_free. */
typedef struct rl_gl_ls_arrays {
    uint32_t num_cells, num_blocks, occ_words;
    uint64_t num_occupied, num_cand;
    uint32_t *voxel_slot;
    uint64_t *occupancy;          /* 2·num_blocks·occ_words: bits, rank */
    uint32_t *cand;
    uint32_t *cand_start;         /* dynamic only, else NULL */
} rl_gl_ls_arrays;
rl_status rl_gl_ls_read(const rl_gl_ls *g, rl_gl_ls_arrays *out);
void rl_gl_ls_arrays_free(rl_gl_ls_arrays *a);

#endif
