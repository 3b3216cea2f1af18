/* rl_dist.h: one run spread over the processes of an MPI job (Open MPI).
 *
 * Every process of the job ("rank") loads the same scene, makes the same
 * renderer with the same options and calls the same functions in the same
 * order; rank 0 is the master (Ullmann 2003, Sec. 4.3: master/slave) and
 * hands out the work on demand, the others are workers. OpenMP threads run
 * inside every rank (Sec. 4.5). A process that was not started by mpirun,
 * or a job of one rank, runs exactly as without distribution.
 *
 *     rl_dist *d;
 *     rl_dist_init(&argc, &argv, &d);            // every rank, first thing
 *     ... load the scene, make the renderer, the camera and the image ...
 *     rl_dist_render(d, r, scene, &cam, img, &stats, &ds);   // collective
 *     if (rl_dist_rank(d) == 0) ... img holds the whole frame ...
 *     rl_dist_release(d, status);                // every rank, last thing
 *
 * Frames (rl_dist_render) go out as bands of image rows to renderers that
 * can render regions (rl_renderer_info.regions: every pixel depends only on
 * its own position), so the assembled image equals the one-process image
 * bit for bit. */
#ifndef RL_DIST_H
#define RL_DIST_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rl/rl_render.h"
#include "rl/rl_sampling.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_dist rl_dist;     /* opaque: this process's place in the job */

/* Whether this build can join MPI jobs; if not, the reason into why (n bytes). */
RL_API bool rl_dist_available(char *why, size_t n);
/* Joins the job this process was started in (MPI_Init_thread, funneled:
 * only the calling thread talks to MPI), or makes a job of one for a
 * process started on its own. argc and argv may be NULL. Once per
 * process. RL_ERR_UNSUPPORTED in a build without MPI. */
RL_API rl_status rl_dist_init(int *argc, char ***argv, rl_dist **out);
/* This process's rank (0: the master) and the job's size; 0 and 1 for NULL. */
RL_API int rl_dist_rank(const rl_dist *d);
RL_API int rl_dist_size(const rl_dist *d);
/* Leaves the job: MPI_Finalize when status is RL_OK, else MPI_Abort, so
 * that a rank that failed (a scene it could not load) ends the whole job
 * with its error instead of leaving the others waiting for it. NULL is a
 * no-op. */
RL_API void rl_dist_release(rl_dist *d, rl_status status);

/* What one rank did in a distributed frame (the master's view). */
typedef struct rl_dist_rank_stats {
    uint64_t tasks;          /* bands rendered, or chunks of positions measured */
    uint64_t pixels;         /* pixels rendered, or positions measured */
    double busy_ms;          /* rendering or measuring */
} rl_dist_rank_stats;

typedef struct rl_dist_stats {
    int ranks;
    uint64_t tasks;          /* bands of the frame, chunks of the sampling */
    uint64_t messages;       /* point-to-point messages of the frame, both ways */
    uint64_t bytes;          /* their payload */
    double time_ms;          /* the frame, on the master */
    int lost;                /* workers taken for lost (silent past RL_DIST_TIMEOUT); their work was redone */
    uint64_t dropped;        /* Vertex Tracing: results of an older camera dropped (Ullmann Sec. 4.3.2) */
    const char *task_kind;   /* "package" for Vertex Tracing's face packages; NULL: bands or chunks */
    /* Vertex Tracing with option dist_postpass (Ullmann Sec. 6.1.3): the
     * master's post-pass ran; the samples it took from the parts, the
     * vertices it traced itself (where the packages differ from one
     * process) and its time (the replayed refinement and those samples,
     * without the drawing). */
    bool postpass;
    uint64_t postpass_reused, postpass_traced;
    double postpass_ms;
    /* ... overlapped with the packages still out (option dist_overlap):
     * whether it started before the last part came, the time it ran
     * before the last part came, and the master's time from the last part
     * (or the master's own last package) to the finished image: what the
     * overlap shortens. */
    bool postpass_overlapped;
    double postpass_early_ms, postpass_tail_ms;
    /* Per rank, rank 0 (the master, which renders bands between its
     * messages) first; NULL when the frame ran in one process. Owned by
     * the rl_dist, valid until its next frame or release. */
    const rl_dist_rank_stats *per_rank;
} rl_dist_stats;

/* The renderer "vt" (Vertex Tracing) has no regions: its frames are split
 * by primary faces instead (Ullmann 2003, Sec. 4.3; rl_vt.h's
 * rl_vt_prepare, rl_vt_refine_faces and rl_vt_draw_parts): the master
 * runs the ID pre-pass and hands out packages of visible faces, by the
 * renderer's option balance (queue: equal packages of `package` faces on
 * demand; precompute: one package per rank sized by its measured speed);
 * every task and result carries the frame's camera ID, and results of an
 * older camera are dropped (dstats->dropped). Its image is close to one
 * process', not equal at package borders (docs/distributed.md), unless
 * the option dist_postpass is on: then the master's post-pass makes it
 * the one-process image (dstats->postpass*). */
/* Renders cam's frame into image with every rank's copy of r: collective,
 * every rank calls it with the same renderer options, scene, camera and
 * image size. On the master, image receives the whole frame (every layer
 * it has) and stats the sum of every rank's rays and samples; the workers'
 * images hold only their own bands. With one rank this is
 * rl_renderer_render. RL_ERR_UNSUPPORTED for a renderer without
 * info.regions in a job of several ranks; a rank's failure is the frame's
 * status on the master. dstats may be NULL. With several ranks every band
 * is a new accumulation (a progressive renderer's frame 1; see
 * rl_dist_render_frames); with one, the renderer's accumulation goes on. */
RL_API rl_status rl_dist_render(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                                rl_image *image, rl_render_stats *stats, rl_dist_stats *dstats);

/* A progressive renderer's frames (pt's accumulation) spread as bands:
 * every band renders all frames frames of a new accumulation
 * (rl_renderer_reset, then frames renders with the band as region) and
 * goes back to the master accumulated, so that the image equals frames
 * frames of one process after rl_renderer_reset, bit for bit, for the same
 * options (seed). stats: the rays and samples of every frame summed.
 * Collective, as rl_dist_render; with one rank the frames render here.
 * frames in 1..RL_DIST_MAX_FRAMES. */
#define RL_DIST_MAX_FRAMES 1000000
RL_API rl_status rl_dist_render_frames(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                                       uint64_t frames, rl_image *image, rl_render_stats *stats,
                                       rl_dist_stats *dstats);

/* Parallel adaptive sampling (Jähn 2015, Sec. 5.5, Alg. 5.4): collective,
 * every rank calls it with the same committed property (the same scene
 * and options) and the same desc. The master is the control node and runs
 * rl_sample_property; the batches of positions it chooses are measured on
 * every rank (rl_sampling_desc.measure, rl_property_measure_sets), the
 * master measuring too between messages. *out, on the master only, is the
 * approximation one process makes with the same seed, sample for sample,
 * except for properties that measure the machine (times): their values
 * are this run's. The workers' *out is NULL. With one rank this is
 * rl_sample_property. dstats may be NULL; its per-rank counts are chunks
 * and positions. */
RL_API rl_status rl_dist_sample_property(rl_dist *d, rl_property *p, const rl_sampling_desc *desc, rl_approx **out,
                                         rl_dist_stats *dstats);

/* The same sampling nodes for positions chosen beforehand (rl compare
 * measures every renderer at the positions one sampling placed): count
 * values of p at pos, measured in chunks on every rank, into values on
 * the master (rl_property_measure there); the workers pass NULL pos and
 * values, and any count. Collective: every rank calls it with the same
 * property (scene and options). A rank whose property could not be
 * committed passes NULL for p, so that the ranks stay in step: the call
 * then fails on every rank. Times are this run's, as above. With one rank
 * this is rl_property_measure. dstats may be NULL. */
RL_API rl_status rl_dist_measure(rl_dist *d, rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                                 rl_dist_stats *dstats);

/* The property service, for commands whose sampling runs the workers
 * cannot follow step by step (rl bench culling: many properties, sections
 * that resume from files only the master reads). Between
 * rl_dist_service_begin and rl_dist_service_end on the master, every
 * rl_dist_sample_property and rl_dist_measure first tells the workers its
 * property by name and option values; the workers sit in
 * rl_dist_serve_properties, which makes and commits each property on their
 * own copy of the scene (a few are kept for the next runs) and measures
 * for it, until the master ends the service with its status. Only
 * properties made by rl_property_create and rl_property_set can be
 * described this way; a combined or custom one fails the run on every
 * rank. Between runs a worker waits up to RL_DIST_IDLE_TIMEOUT seconds
 * (default 3600: the master may render for a long time between two runs)
 * before it takes the master for gone. */
RL_API rl_status rl_dist_service_begin(rl_dist *d);
RL_API rl_status rl_dist_service_end(rl_dist *d, rl_status status);
RL_API rl_status rl_dist_serve_properties(rl_dist *d, const rl_scene *scene, int threads);

#ifdef __cplusplus
}
#endif

#endif
