/* vt_part.h: a package's result of a distributed Vertex Tracing frame
 * (vt_part.c; the public side is rl_vt.h's rl_vt_refine_faces,
 * rl_vt_draw_parts and rl_vt_part_check). */
#ifndef RL_RENDER_VT_PART_H
#define RL_RENDER_VT_PART_H

#include <stddef.h>

#include "render/vt_internal.h"

/* The drawable leaf faces of m whose primary ancestor f has mine[f] == 1,
 * with their vertices, into a malloc'd buffer (*out, *size bytes).
 * all_samples (option dist_postpass): version 2, which also carries every
 * other sampled vertex of m and each vertex's key, triangle and ray-tree
 * hash, for the master's post-pass (Ullmann 2003, Sec. 6.1.3). */
rl_status vt_part_write(const vt_mesh *m, const rl_scene_data *d, const uint8_t *mine, bool all_samples, void **out,
                        size_t *size);
/* Checks a part without a scene: header, sizes, checksum, vertex indices.
 * RL_ERR_PARSE with the reason. */
rl_status vt_part_check(const void *part, size_t size, uint32_t *num_verts, uint32_t *num_faces);
/* Appends the part's vertices (sampled) and faces (leaves) to m, after
 * vt_part_check and a check of its triangles and objects against d; on
 * failure m is unchanged. */
rl_status vt_part_import(vt_mesh *m, const rl_scene_data *d, const void *part, size_t size);

/* The samples of checked version-2 parts by vertex key, for the master's
 * post-pass: it replays one process' refinement and takes a vertex's
 * sample from the parts instead of tracing it. The map points into the
 * parts, which must outlive it. */
typedef struct vt_part_samples {
    uint64_t *keys;           /* vt_key_nonzero(key), 0 = empty slot */
    const unsigned char **rec;/* the vertex's record in its part */
    size_t cap, count;
} vt_part_samples;

/* Adds the samples of a checked part to the map (a version-1 part adds
 * nothing); the part must outlive the map's use. Parts may come one by
 * one, also while a replay reads the map (between its stages: the
 * overlapped post-pass, rl_vt_postpass_add). A vertex two parts carry
 * keeps the first part's record (the same sample, vt_sample.c). */
rl_status vt_part_samples_add(vt_part_samples *ps, const void *part, size_t size);
/* Stores the parts' sample of vertex v of m (its key, position and
 * triangle must all match) and returns true; false when no part has it
 * (the caller traces it), or, with *failed set, when out of memory. */
bool vt_part_samples_take(const vt_part_samples *ps, vt_mesh *m, uint32_t v, bool *failed);
void vt_part_samples_free(vt_part_samples *ps);

#endif
