/* rl_gbuffer.h: a geometry buffer (Saito & Takahashi 1990), per pixel the
 * first surface seen through the pixel centre.
 *
 * The path tracer fills it with its primary hits, or, with primary=raster
 * (rasterized primary visibility, Schröder 2017, Sec. 8.1; not the hybrid
 * CPU/GPU path tracing of Sec. 8.4), from rasterized visibility: the rasterizer
 * decides which triangle covers each pixel, and the exact point is the
 * pixel ray's intersection with that triangle (no traversal). The noise
 * filters (rl_filter.h) use it as guidance. Plain arrays, row-major,
 * pixel (0,0) top-left, as rl_image. */
#ifndef RL_GBUFFER_H
#define RL_GBUFFER_H

#include "rl/rl_accel.h"
#include "rl/rl_camera.h"
#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_scene.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_gbuffer {
    int width, height;
    rl_vec3 *position;        /* world position (0 where nothing is seen) */
    rl_vec3 *normal;          /* unit shading normal, facing the camera */
    rl_vec3 *albedo;          /* k_d times the texture */
    rl_vec2 *uv;
    float *depth;             /* eye-space distance along the view axis;
                               * INFINITY where nothing is seen */
    uint32_t *object;         /* RL_ID_NONE where nothing is seen */
    uint32_t *triangle;       /* RL_ID_NONE where nothing is seen */
    uint32_t *material;       /* RL_NONE where nothing is seen */
} rl_gbuffer;
/* Bytes per pixel of the layers above, for memory estimates. */
#define RL_GBUFFER_BYTES_PER_PIXEL (3 * sizeof(rl_vec3) + sizeof(rl_vec2) + sizeof(float) + 3 * sizeof(uint32_t))

/* RL_ERR_LIMIT for a size outside 1..RL_IMAGE_MAX_SIZE. Cleared to "nothing seen". */
RL_API rl_status rl_gbuffer_create(int width, int height, rl_gbuffer **out);
RL_API void rl_gbuffer_release(rl_gbuffer *g);           /* NULL is a no-op */
RL_API void rl_gbuffer_clear(rl_gbuffer *g);
/* Fills g (camera resolution = g's size) by tracing the pixel-centre rays. */
RL_API rl_status rl_gbuffer_trace(rl_gbuffer *g, const rl_accel *accel, const rl_camera *cam);
/* rl_gbuffer_trace for the pixels x0 <= x < x1, y0 <= y < y1 only (a
 * renderer's region, rl_renderer_set_region); the others keep what they
 * hold. RL_ERR_INVALID_ARG for a part that is empty or leaves g. */
RL_API rl_status rl_gbuffer_trace_part(rl_gbuffer *g, const rl_accel *accel, const rl_camera *cam, int x0, int y0,
                                       int x1, int y1);
/* Fills g from rasterized visibility (see above). Pixels agree with
 * rl_gbuffer_trace except where the rasterizer's coverage rule and the
 * ray disagree at triangle edges. */
RL_API rl_status rl_gbuffer_raster(rl_gbuffer *g, const rl_scene *scene, const rl_camera *cam);
/* The second half of rl_gbuffer_raster for a triangle-ID layer drawn by
 * another rasterizer (gl-pt's raster pass on GL): triangles holds per
 * pixel (g's size, row 0 the top row) the scene triangle drawn there, or
 * RL_ID_NONE. */
RL_API rl_status rl_gbuffer_from_ids(rl_gbuffer *g, const rl_scene *scene, const rl_camera *cam,
                                     const uint32_t *triangles);

#ifdef __cplusplus
}
#endif
#endif
