/* vt_part.h: a package's result of a distributed Vertex Tracing frame
 * (vt_part.c; the public side is rl_vt.h's rl_vt_refine_faces,
 * rl_vt_draw_parts and rl_vt_part_check). */
#ifndef RL_RENDER_VT_PART_H
#define RL_RENDER_VT_PART_H

#include <stddef.h>

#include "render/vt_internal.h"

/* The drawable leaf faces of m whose primary ancestor f has mine[f] != 0,
 * with their vertices, into a malloc'd buffer (*out, *size bytes). */
rl_status vt_part_write(const vt_mesh *m, const rl_scene_data *d, const uint8_t *mine, void **out, size_t *size);
/* Checks a part without a scene: header, sizes, checksum, vertex indices.
 * RL_ERR_PARSE with the reason. */
rl_status vt_part_check(const void *part, size_t size, uint32_t *num_verts, uint32_t *num_faces);
/* Appends the part's vertices (sampled) and faces (leaves) to m, after
 * vt_part_check and a check of its triangles and objects against d; on
 * failure m is unchanged. */
rl_status vt_part_import(vt_mesh *m, const rl_scene_data *d, const void *part, size_t size);

#endif
