/* dist_internal.h: what the files of src/dist share on MPI: the job, the
 * message tags and the error of a failed MPI call. */
#ifndef RL_DIST_INTERNAL_H
#define RL_DIST_INTERNAL_H

#include <mpi.h>

#include "rl/rl_dist.h"

/* Tags of MPI_COMM_WORLD's messages; a frame and a sampling run never
 * overlap (both are collective), so they share the numbers' space. */
enum {
    RL_DIST_TAG_TASK = 1,      /* master -> worker: a band, or positions */
    RL_DIST_TAG_DONE,          /* master -> worker: the run's status, the end */
    RL_DIST_TAG_RESULT,        /* worker -> master: a task's header */
    RL_DIST_TAG_PIXELS,        /* worker -> master: a band's layers */
    RL_DIST_TAG_VALUES,        /* worker -> master: measured values and sets */
    RL_DIST_TAG_SPEC,          /* master -> worker: the next run's property (service) */
    RL_DIST_TAG_END,           /* master -> worker: the service's status, its end */
    RL_DIST_TAG_VT_PART,       /* worker -> master: a VT package's result header (dist_vt.c) */
    RL_DIST_TAG_VT_DATA,       /* worker -> master: ... and its part */
};

struct rl_dist {
    int rank, size;
    bool own_mpi;                      /* we called MPI_Init: we finalize */
    rl_dist_rank_stats *per_rank;      /* size entries */
    uint64_t tasks_done;               /* by this rank, for rl_dist_fault_point */
    /* Workers the sampling took for lost (size entries): they stay lost
     * for the rest of the job, so that later batches and runs do not wait
     * for them again. */
    unsigned char *sampling_lost;
    bool service;                      /* rl_dist_service_begin on the master */
    uint64_t vt_camera;                /* distributed VT frames so far: the camera ID */
    double *vt_speed;                  /* per rank: faces per busy ms of the last VT frame */
    bool vt_speed_valid;               /* ... for balance=precompute */
    bool vt_speed_estimate;            /* ... per busy ms in b_f (cost=estimate), not in faces */
};

/* RL_ERR_IO "distributed run: WHAT: <MPI's text for code>". */
rl_status rl_dist_mpi_failed(int code, const char *what);

/* How long a rank waits for another before it takes it for lost: the
 * environment variable RL_DIST_TIMEOUT in seconds, else this. Generous,
 * since a worker's first answer waits for its scene to load. */
#define RL_DIST_DEFAULT_TIMEOUT_S 120.0
double rl_dist_timeout_s(void);
/* A fraction of a millisecond's sleep between polls. */
void rl_dist_pause(void);
/* A worker waits for the master's next message with tag (MPI_ANY_TAG:
 * any), polling; past the timeout RL_ERR_IO "no word from the master",
 * so that a dead master ends its workers with an error, not a hang. */
rl_status rl_dist_wait(const rl_dist *d, int tag, MPI_Status *ms);
/* ... with a timeout of its own, in seconds, and the setting that the
 * error names (the environment variable that sets the timeout). */
rl_status rl_dist_wait_for(const rl_dist *d, int tag, MPI_Status *ms, double timeout, const char *setting);
/* MPI_Send that gives up past the timeout (RL_ERR_IO naming dest): a
 * large message waits for its receiver, forever if the receiver died. */
rl_status rl_dist_send(const rl_dist *d, const void *buf, int count, MPI_Datatype type, int dest, int tag);
/* Fault injection for the tests of docs/distributed.md: with
 * RL_DIST_FAULT=RANK:N in the environment, rank RANK kills itself with
 * SIGKILL after its N-th task, as a crashed node would vanish. Counts this
 * rank's tasks. */
void rl_dist_fault_point(rl_dist *d);

/* A Vertex Tracing frame over the ranks (dist_vt.c): collective, as
 * rl_dist_render, which calls it for the renderer "vt" in a job of
 * several ranks. */
rl_status rl_dist_vt_frame(rl_dist *d, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                           rl_image *image, rl_render_stats *stats, rl_dist_stats *ds);

#endif
