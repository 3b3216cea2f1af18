/* rasterizer.c: the rasterizer object: creation, render target and matrices, and
 * the scratch buffers that are reused across draws (many small draws per
 * frame must not pay for allocation). The pipeline is in raster_draw.c. */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "raster/raster_internal.h"

rl_status rl_raster_create(const rl_raster_desc *desc, rl_raster **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_create: out is NULL");
    if (desc && desc->threads < 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_create: threads %d < 0", desc->threads);
    rl_raster *r = rl_calloc(1, sizeof *r);
    if (!r)
        return RL_ERR_OUT_OF_MEMORY;
    r->threads = desc ? desc->threads : 0;
    r->view_proj = rl_mat4_identity();
    r->perspective = false;
    *out = r;
    return RL_OK;
}

void rl_raster_release(rl_raster *r)
{
    if (!r)
        return;
    for (int i = 0; i < r->chunk_cap; ++i) {
        free(r->chunks[i].prims);
        free(r->chunks[i].srcs);
        free(r->chunks[i].bins.off);
        free(r->chunks[i].bins.idx);
    }
    free(r->chunks);
    free(r->clip);
    free(r->eye_depth);
    free(r->group_vertex);
    free(r->lazy_ranges);
    free(r->points);
    free(r);
}

static bool mat4_finite(const rl_mat4 *m)
{
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j)
            if (!isfinite(m->m[i][j]))
                return false;
    return true;
}

rl_status rl_raster_set_target(rl_raster *r, rl_image *target, const rl_mat4 *view,
                               const rl_mat4 *projection)
{
    if (!r || !target || !view || !projection)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_set_target: NULL argument");
    if (target->width < 1 || target->height < 1 || target->width > RL_IMAGE_MAX_SIZE ||
        target->height > RL_IMAGE_MAX_SIZE)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_set_target: bad target size %dx%d",
                        target->width, target->height);
    if (!mat4_finite(view) || !mat4_finite(projection))
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_set_target: non-finite matrix");
    r->target = target;
    r->view_proj = rl_mat4_mul(projection, view);
    r->view_z = rl_v4(view->m[2][0], view->m[2][1], view->m[2][2], view->m[2][3]);
    /* An affine projection (orthographic) keeps w = 1: depth must then be
     * interpolated itself instead of being recovered from 1/w. */
    const float *row3 = projection->m[3];
    r->perspective = !(row3[0] == 0.0f && row3[1] == 0.0f && row3[2] == 0.0f && row3[3] == 1.0f);
    /* Guard band: x_pix = (x/w + 1) W/2 stays within W/2 + 2^19 < 2^20. */
    r->guard_x = (float)(2.0 * RL_RASTER_GUARD_PX / target->width);
    r->guard_y = (float)(2.0 * RL_RASTER_GUARD_PX / target->height);
    return RL_OK;
}

rl_status rl_raster_camera_matrices(const rl_camera *cam, rl_aabb scene_bounds, rl_mat4 *view, rl_mat4 *proj)
{
    if (!cam || !view || !proj)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_camera_matrices: NULL argument");
    rl_status st = rl_camera_validate(cam);
    if (st != RL_OK)
        return st;
    rl_camera c = rl_camera_resolve(cam);
    float z_near = c.z_near, z_far = c.z_far;
    if (!(z_near > 0.0f))
        rl_camera_clip_range(&c, scene_bounds, &z_near, &z_far);
    else if (!(z_far > z_near))
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_set_camera: z_far %g <= z_near %g",
                        (double)z_far, (double)z_near);
    *view = rl_camera_view(&c);
    *proj = rl_camera_projection(&c, z_near, z_far);
    return RL_OK;
}

rl_status rl_raster_set_camera(rl_raster *r, rl_image *target, const rl_camera *cam,
                               rl_aabb scene_bounds)
{
    if (!r || !target || !cam)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_set_camera: NULL argument");
    rl_mat4 view, proj;
    rl_status st = rl_raster_camera_matrices(cam, scene_bounds, &view, &proj);
    return st == RL_OK ? rl_raster_set_target(r, target, &view, &proj) : st;
}

rl_status rl_raster_reserve_chunks(rl_raster *r, int count)
{
    if (count <= r->chunk_cap)
        return RL_OK;
    rl_raster_chunk *c = rl_realloc_array(r->chunks, (size_t)count, sizeof *c);
    if (!c)
        return RL_ERR_OUT_OF_MEMORY;
    memset(c + r->chunk_cap, 0, (size_t)(count - r->chunk_cap) * sizeof *c);
    r->chunks = c;
    r->chunk_cap = count;
    return RL_OK;
}

int rl_raster_thread_count(const rl_raster *r)
{
    int t = r->threads > 0 ? r->threads : omp_get_max_threads();
    return t < 1 ? 1 : t;
}

rl_raster_target rl_raster_target_for(const rl_raster *r, unsigned flags, bool query)
{
    rl_image *img = r->target;
    rl_raster_target t = { .width = img->width, .height = img->height,
                           .perspective = r->perspective,
                           .depth_equal = (flags & RL_RASTER_DEPTH_EQUAL) != 0,
                           .blend_add = (flags & RL_RASTER_BLEND_ADD) != 0 };
    if (!(flags & RL_RASTER_NO_DEPTH_TEST))
        t.depth_test = img->depth;
    if (query)
        return t;
    if (!(flags & RL_RASTER_NO_DEPTH))
        t.depth = img->depth;
    if (!(flags & RL_RASTER_NO_COLOR))
        t.color = img->color;
    if (!(flags & RL_RASTER_NO_ID)) {
        t.object_id = img->object_id;
        t.triangle_id = img->triangle_id;
    }
    return t;
}
