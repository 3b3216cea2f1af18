/* dist_none.c: rl_dist in a build without Open MPI (rl_dist.h): no job to
 * join, every frame renders in this process. */
#include "rl/rl_dist.h"

#include <stdio.h>

#include "core/error.h"

#define WHY "this build has no Open MPI (install libopenmpi-dev openmpi-bin and rebuild)"

bool rl_dist_available(char *why, size_t n)
{
    if (why && n)
        snprintf(why, n, "%s", WHY);
    return false;
}

rl_status rl_dist_init(int *argc, char ***argv, rl_dist **out)
{
    (void)argc;
    (void)argv;
    if (out)
        *out = NULL;
    return rl_error(RL_ERR_UNSUPPORTED, "distributed runs: %s", WHY);
}

int rl_dist_rank(const rl_dist *d) { return (void)d, 0; }
int rl_dist_size(const rl_dist *d) { return (void)d, 1; }
void rl_dist_release(rl_dist *d, rl_status status) { (void)d, (void)status; }

rl_status rl_dist_render(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                         rl_image *image, rl_render_stats *stats, rl_dist_stats *dstats)
{
    (void)d;
    if (dstats)
        *dstats = (rl_dist_stats){ .ranks = 1 };
    rl_status st = rl_renderer_render(r, scene, cam, image, stats);
    if (dstats && stats)
        dstats->time_ms = stats->time_ms;
    return st;
}

rl_status rl_dist_render_frames(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                                uint64_t frames, rl_image *image, rl_render_stats *stats, rl_dist_stats *dstats)
{
    (void)d;
    if (frames == 0 || frames > RL_DIST_MAX_FRAMES)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_render_frames: frames must be in 1..%d", RL_DIST_MAX_FRAMES);
    if (dstats)
        *dstats = (rl_dist_stats){ .ranks = 1 };
    rl_render_stats sum = { 0 };
    rl_status st = RL_OK;
    rl_renderer_reset(r);
    for (uint64_t k = 0; k < frames && st == RL_OK; ++k) {
        rl_render_stats fs = { 0 };
        if ((st = rl_renderer_render(r, scene, cam, image, &fs)) != RL_OK)
            break;
        for (int t = 0; t < RL_RAY_TYPE_COUNT; ++t)
            sum.rays[t] += fs.rays[t];
        sum.samples += fs.samples;
        sum.prep_ms += fs.prep_ms;
        sum.time_ms += fs.time_ms;
        sum.pixels_written += fs.pixels_written;
    }
    if (stats)
        *stats = sum;
    if (dstats)
        dstats->time_ms = sum.time_ms;
    return st;
}

rl_status rl_dist_sample_property(rl_dist *d, rl_property *p, const rl_sampling_desc *desc, rl_approx **out,
                                  rl_dist_stats *dstats)
{
    (void)d;
    if (dstats)
        *dstats = (rl_dist_stats){ .ranks = 1 };
    return rl_sample_property(p, desc, out);
}

rl_status rl_dist_measure(rl_dist *d, rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                          rl_dist_stats *dstats)
{
    (void)d;
    if (dstats)
        *dstats = (rl_dist_stats){ .ranks = 1 };
    if (!p)
        return rl_error(RL_ERR_INVALID_ARG, "rl_dist_measure: no property");
    return rl_property_measure(p, pos, count, values, NULL, NULL);
}

/* Without MPI every job is one process: nobody to serve, nothing to end. */
rl_status rl_dist_service_begin(rl_dist *d)
{
    (void)d;
    return RL_OK;
}

rl_status rl_dist_service_end(rl_dist *d, rl_status status)
{
    (void)d;
    return status;
}

rl_status rl_dist_serve_properties(rl_dist *d, const rl_scene *scene, int threads)
{
    (void)d;
    (void)scene;
    (void)threads;
    return rl_error(RL_ERR_UNSUPPORTED, "rl_dist_serve_properties: this build has no MPI (a job of one has no "
                    "workers)");
}
