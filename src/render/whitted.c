/* whitted.c: renderer "whitted", recursive ray tracing (Whitted 1980) with
 * the coefficient model of Ullmann 2003, Sec. 3.1 (eq. 3.1-3.4): one primary
 * ray per sample through rl_tracer (trace.c), Phong with hard shadows and
 * eq. 3.17's transmitted highlight (Sec. 3.5.2), k_r reflection and k_t
 * refraction.
 *
 * Options (defaults): accel = bvh (bvh | grid | embree | brute; embree only
 * in a build with Embree), max_depth = 5 (0: local shading only), ss = 1
 * (n x n samples per pixel at the stratum centres, box filtered),
 * area_samples = 4 (n x n per quad light), shadows = true,
 * transmitted_highlight = true (eq. 3.17), ambient = 0.05,
 * background = "0,0,0", threads = 0 (all), ray_trees = false (keep the ray
 * tree of every pixel's centre sample for rl_whitted_pixel_tree()).
 *
 * Frame: 16 x 16 tiles handed out dynamically to OpenMP threads. Every
 * sample's result depends only on its pixel and sample index (the tracer's
 * jitter is seeded from them), so the image is identical for any thread
 * count. Depth and IDs come from the centre sample (stratum (ss/2, ss/2):
 * the pixel centre for odd ss, as the raster renderer samples it); depth is
 * the distance along the view axis, t * dot(d, forward). The accelerator is
 * kept between frames and rebuilt only when the scene (rl_scene_uid) or the
 * accel option changes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "render/accel_cache.h"
#include "render/renderer.h"
#include "render/tracer_options.h"
#include "render/whitted.h"
#include "rl/rl_accel.h"
#include "rl/rl_trace.h"

#define TILE 16
#define MAX_TREE_BYTES ((size_t)256 << 20)   /* ray_trees: ~776 bytes per pixel */
#define BUILD_SHARE 0.1                      /* progress share of the accel build */

static const rl_option_info whitted_options[] = {
    RL_TRACER_OPTION_ROWS,
    { "ss", RL_OPT_INT, "1", "n x n samples per pixel at the stratum centres", 1, 16, NULL },
    { "ray_trees", RL_OPT_BOOL, "false", "keep every pixel's centre-sample ray tree (for tests and Vertex Tracing)",
      0, 0, NULL },
};

typedef struct whitted_state {
    rl_accel_cache accel;        /* kept between frames */
    rl_ray_tree *trees;          /* last frame's trees, or NULL */
    int tree_width, tree_height;
} whitted_state;

static void whitted_release(void *state)
{
    whitted_state *s = state;
    rl_accel_cache_release(&s->accel);
    free(s->trees);
}

rl_status rl_whitted_pixel_tree(const rl_renderer *r, int x, int y, rl_ray_tree *out)
{
    if (!r || !out || strcmp(rl_renderer_name(r), "whitted") != 0)
        return rl_error(RL_ERR_INVALID_ARG, "rl_whitted_pixel_tree: needs a \"whitted\" renderer and out");
    const whitted_state *s = rl_renderer_state(r);
    if (!s || !s->trees)
        return rl_error(RL_ERR_NOT_FOUND, "whitted: no ray trees kept (render with ray_trees=true first)");
    if (x < 0 || y < 0 || x >= s->tree_width || y >= s->tree_height)
        return rl_error(RL_ERR_INVALID_ARG, "whitted: pixel (%d, %d) is outside the last frame", x, y);
    *out = s->trees[(size_t)y * s->tree_width + x];
    return RL_OK;
}

static rl_status whitted_check(const char *key, const char *value)
{
    return rl_tracer_options_check("whitted", key, value);
}

/* The accel build reports the first BUILD_SHARE of the frame's progress. */
static bool build_progress(void *user, double done)
{
    bool go_on;
#pragma omp critical(rl_whitted_progress)
    go_on = rl_renderer_progress(user, BUILD_SHARE * done);
    return go_on;
}

/* Everything a tile needs; read-only but for its own pixels and counters. */
typedef struct frame {
    const rl_tracer *tracer;
    rl_camera_frame cam;
    rl_image *image;
    bool write_depth, write_ids;
    int ss;
    rl_ray_tree *trees;          /* or NULL */
    int tiles_x;
    rl_rect region;              /* the pixels to trace (rl_renderer_set_region) */
} frame;

static void render_tile(const frame *f, int64_t tile, uint64_t rays[RL_RAY_TYPE_COUNT])
{
    /* Tiles are numbered over the region, from its corner: a whole frame's
     * region is the image. */
    const rl_rect *g = &f->region;
    int x0 = g->x0 + (int)(tile % f->tiles_x) * TILE, y0 = g->y0 + (int)(tile / f->tiles_x) * TILE;
    int x1 = x0 + TILE < g->x1 ? x0 + TILE : g->x1;
    int y1 = y0 + TILE < g->y1 ? y0 + TILE : g->y1;
    int ss = f->ss, centre = ss / 2;
    rl_vec3 forward = rl_neg(f->cam.w);
    for (int y = y0; y < y1; ++y) {
        for (int x = x0; x < x1; ++x) {
            size_t pixel = (size_t)y * f->image->width + x;
            double sum[3] = { 0.0, 0.0, 0.0 };
            for (int sy = 0; sy < ss; ++sy) {
                for (int sx = 0; sx < ss; ++sx) {
                    bool is_centre = sx == centre && sy == centre;
                    rl_ray ray = rl_camera_frame_ray(&f->cam, (float)x + ((float)sx + 0.5f) / (float)ss,
                                                     (float)y + ((float)sy + 0.5f) / (float)ss);
                    uint64_t sample_id = (uint64_t)pixel * (uint64_t)(ss * ss) + (uint64_t)(sy * ss + sx);
                    rl_trace_result res;
                    rl_tracer_trace(f->tracer, &ray, RL_RAY_PRIMARY, sample_id, &res,
                                    is_centre && f->trees ? &f->trees[pixel] : NULL);
                    sum[0] += res.color.x;
                    sum[1] += res.color.y;
                    sum[2] += res.color.z;
                    for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
                        rays[k] += res.rays[k];
                    if (!is_centre)
                        continue;
                    bool hit = res.hit.triangle != RL_ID_NONE;
                    if (f->write_depth)
                        f->image->depth[pixel] = hit ? res.hit.t * rl_dot(ray.d, forward) : INFINITY;
                    if (f->write_ids) {
                        f->image->object_id[pixel] = hit ? res.hit.object : RL_ID_NONE;
                        f->image->triangle_id[pixel] = hit ? res.hit.triangle : RL_ID_NONE;
                    }
                }
            }
            double inv = 1.0 / (double)(ss * ss);
            f->image->color[pixel] = rl_v4((float)(sum[0] * inv), (float)(sum[1] * inv), (float)(sum[2] * inv), 1.0f);
        }
    }
}

/* Traces all tiles; false if the progress callback cancelled. */
static bool trace_tiles(rl_renderer *r, const frame *f, int threads, int64_t num_tiles,
                        uint64_t (*tile_rays)[RL_RAY_TYPE_COUNT])
{
    bool cancel = false;
    int64_t done = 0;
    double reported = 0.0;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
    for (int64_t t = 0; t < num_tiles; ++t) {
        bool stop;
#pragma omp atomic read
        stop = cancel;
        if (stop)
            continue;
        render_tile(f, t, tile_rays[t]);
        /* Serialised (callbacks need not be thread-safe) and throttled to
         * about a hundred calls per frame. */
#pragma omp critical(rl_whitted_progress)
        {
            double frac = (double)++done / (double)num_tiles;
            if (frac - reported >= 0.01 || done == num_tiles) {
                reported = frac;
                if (!rl_renderer_progress(r, BUILD_SHARE + (1.0 - BUILD_SHARE) * frac)) {
#pragma omp atomic write
                    cancel = true;
                }
            }
        }
    }
    return !cancel;
}

/* Keeps s->trees sized for this frame when ray_trees is on, frees them otherwise. */
static rl_status prepare_trees(whitted_state *s, bool keep, int width, int height)
{
    if (!keep || (s->trees && (s->tree_width != width || s->tree_height != height))) {
        free(s->trees);
        s->trees = NULL;
        s->tree_width = s->tree_height = 0;
    }
    if (!keep || s->trees)
        return RL_OK;
    size_t n = (size_t)width * (size_t)height;
    if (n > MAX_TREE_BYTES / sizeof(rl_ray_tree))
        return rl_error(RL_ERR_LIMIT, "whitted: ray_trees for %dx%d pixels would need more than %zu MiB",
                        width, height, MAX_TREE_BYTES >> 20);
    s->trees = rl_calloc(n, sizeof *s->trees);
    if (!s->trees)
        return RL_ERR_OUT_OF_MEMORY;
    s->tree_width = width;
    s->tree_height = height;
    return RL_OK;
}

static rl_status whitted_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                                rl_image *image, rl_render_stats *stats)
{
    whitted_state *s = state;
    if (!rl_scene_get_data(scene))
        return RL_ERR_NOT_COMMITTED;
    rl_accel_kind kind;
    rl_tracer_desc desc;
    rl_status st = rl_tracer_options_read(r, &desc, &kind);
    if (st != RL_OK)
        return st;
    int threads = (int)rl_renderer_opt_int(r, "threads");
#ifdef _OPENMP
    int num_threads = threads > 0 ? threads : omp_get_max_threads();
#else
    int num_threads = 1;
#endif
    if ((st = rl_accel_cache_get(&s->accel, "whitted", scene, kind, threads, build_progress, r,
                                 &stats->prep_ms)) != RL_OK)
        return st;
    if ((st = prepare_trees(s, rl_renderer_opt_bool(r, "ray_trees"), image->width, image->height)) != RL_OK)
        return st;

    rl_rect region = rl_renderer_region(r, image->width, image->height);
    int rw = region.x1 - region.x0, rh = region.y1 - region.y0;
    int tiles_x = (rw + TILE - 1) / TILE, tiles_y = (rh + TILE - 1) / TILE;
    int64_t num_tiles = (int64_t)tiles_x * tiles_y;
    rl_tracer *tracer = NULL;
    uint64_t (*tile_rays)[RL_RAY_TYPE_COUNT] = NULL;
    st = rl_tracer_create(s->accel.accel, &desc, &tracer);
    if (st == RL_OK && !(tile_rays = rl_calloc((size_t)num_tiles, sizeof *tile_rays)))
        st = RL_ERR_OUT_OF_MEMORY;
    if (st != RL_OK) {
        rl_tracer_release(tracer);
        prepare_trees(s, false, 0, 0);      /* no frame, no trees */
        return st;
    }
    frame f = {
        .tracer = tracer,
        .cam = rl_camera_frame_make(cam),
        .image = image,
        .write_depth = (image->layers & RL_LAYER_DEPTH) && image->depth,
        .write_ids = (image->layers & RL_LAYER_ID) && image->object_id && image->triangle_id,
        .ss = (int)rl_renderer_opt_int(r, "ss"),
        .trees = s->trees,
        .tiles_x = tiles_x,
        .region = region,
    };
    bool finished = rl_renderer_progress(r, BUILD_SHARE) && trace_tiles(r, &f, num_threads, num_tiles, tile_rays);
    rl_tracer_release(tracer);
    if (!finished) {
        free(tile_rays);
        prepare_trees(s, false, 0, 0);      /* half a frame of trees is no frame */
        return rl_error(RL_ERR_CANCELLED, "whitted: cancelled by the progress callback");
    }
    /* Summed in tile order: exact integers, but keep it obviously deterministic. */
    for (int64_t t = 0; t < num_tiles; ++t)
        for (int k = 0; k < RL_RAY_TYPE_COUNT; ++k)
            stats->rays[k] += tile_rays[t][k];
    free(tile_rays);
    stats->pixels_written = (uint64_t)rw * (uint64_t)rh;
    stats->samples = stats->pixels_written * (uint64_t)(f.ss * f.ss);
    return RL_OK;
}

const rl_renderer_class rl_whitted_renderer_class = {
    .info = { .name = "whitted",
              .description = "Recursive Whitted ray tracing with Phong shading, hard shadows, reflection and refraction",
              .reference = "Whitted 1980; coefficient model of Ullmann 2003, Sec. 3.1 (eq. 3.1-3.4)",
              .regions = true },
    .options = whitted_options,
    .num_options = sizeof whitted_options / sizeof whitted_options[0],
    .state_size = sizeof(whitted_state),
    .render = whitted_render,
    .release = whitted_release,
    .check = whitted_check,
};
