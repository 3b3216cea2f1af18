/* raster_points.c: points as screen-aligned squares (surfels, splats, debug
 * views). A point of side s centred at pixel position c covers the pixels
 * whose centres lie in [c - s/2, c + s/2) on both axes: the top-left rule of
 * triangles, so side 1 covers exactly one pixel and side 4 exactly 16
 * wherever the point lands. Depth is the point's own (constant over the
 * square); points behind the near plane are culled, not clipped. Same banded
 * threading as triangles. The triangle_id layer receives the point index. */
#include <math.h>

#include "core/error.h"
#include "raster/raster_internal.h"

#define PARALLEL_POINTS 4096

static int32_t pixel_edge(double v, int limit)
{
    double e = ceil(v);
    return e < 0.0 ? 0 : (e > limit ? limit : (int32_t)e);
}

/* Projects point i; leaves an empty square (y0 == y1) when it is culled. */
static void setup_point(const rl_raster *r, const rl_raster_points *pts, uint32_t i,
                        rl_raster_point *out)
{
    const int width = r->target->width, height = r->target->height;
    out->y0 = out->y1 = out->x0 = out->x1 = 0;
    rl_vec3 pos = pts->positions[i];
    rl_vec4 clip = rl_raster_xform(&r->view_proj, pos);
    if (!isfinite(clip.x) || !isfinite(clip.y) || !isfinite(clip.z) || !isfinite(clip.w))
        return;
    if (!(clip.w > 0.0f) || clip.z < -clip.w)
        return;
    float side = pts->sizes_px ? pts->sizes_px[i] : (pts->size_px > 0.0f ? pts->size_px : 1.0f);
    if (!(side > 0.0f) || !isfinite(side))
        return;
    double inv_w = 1.0 / clip.w;
    double cx = (clip.x * inv_w + 1.0) * 0.5 * width;
    double cy = (1.0 - clip.y * inv_w) * 0.5 * height;
    double h = 0.5 * side + 0.5;  /* half side, shifted to pixel centres */
    out->x0 = pixel_edge(cx - h, width);
    out->x1 = pixel_edge(cx + side - h, width);
    out->y0 = pixel_edge(cy - h, height);
    out->y1 = pixel_edge(cy + side - h, height);
    if (out->x0 >= out->x1 || out->y0 >= out->y1) {
        out->y0 = out->y1 = 0;
        return;
    }
    const rl_vec4 vz = r->view_z;
    out->depth = r->perspective ? clip.w
                                : -(vz.x * pos.x + vz.y * pos.y + vz.z * pos.z + vz.w);
    out->color = pts->colors ? pts->colors[i] : pts->color;
    out->object_id = pts->object_ids ? pts->object_ids[i] : pts->object_id;
    out->point_id = i;
}

rl_status rl_raster_draw_points(rl_raster *r, const rl_raster_points *pts, rl_raster_counters *c)
{
    if (!r || !pts)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_draw_points: NULL argument");
    if (!r->target)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_draw_points: no render target set");
    if (pts->count == 0)
        return RL_OK;
    if (!pts->positions)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_draw_points: %u points without positions",
                        pts->count);
    const int threads = rl_raster_thread_count(r);
    const uint32_t n = pts->count;
    rl_status st = rl_raster_reserve_chunks(r, 1);
    if (st != RL_OK)
        return st;
    if (!rl_reserve((void **)&r->points, &r->point_cap, n, sizeof *r->points, 64))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster_draw_points: %u points", n);
    const bool parallel = n >= PARALLEL_POINTS && threads > 1;
    uint64_t drawn = 0;
    #pragma omp parallel for num_threads(threads) if (parallel) schedule(static) \
        reduction(+ : drawn)
    for (int64_t i = 0; i < (int64_t)n; ++i) {
        setup_point(r, pts, (uint32_t)i, &r->points[i]);
        drawn += r->points[i].y0 < r->points[i].y1;
    }
    const rl_raster_target t = rl_raster_target_for(r, pts->flags, false);
    const int num_bands = rl_raster_num_bands(t.height);
    rl_raster_bins *bins = &r->chunks[0].bins;
    if (!rl_raster_bin(bins, r->points, n, sizeof *r->points, num_bands))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_raster_draw_points: binning %u points", n);
    uint64_t passed = 0;
    #pragma omp parallel for num_threads(threads) if (parallel) schedule(dynamic) \
        reduction(+ : passed)
    for (int band = 0; band < num_bands; ++band) {
        const int row0 = band * RL_RASTER_BAND_ROWS, row1 = row0 + RL_RASTER_BAND_ROWS;
        for (uint32_t k = bins->off[band]; k < bins->off[band + 1]; ++k)
            passed += rl_raster_fill_point(&t, &r->points[bins->idx[k]], row0, row1);
    }
    if (c) {
        c->points_drawn += drawn;
        c->pixels_written += passed;
    }
    return RL_OK;
}
