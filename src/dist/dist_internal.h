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
};

struct rl_dist {
    int rank, size;
    bool own_mpi;                      /* we called MPI_Init: we finalize */
    rl_dist_rank_stats *per_rank;      /* size entries */
};

/* RL_ERR_IO "distributed run: WHAT: <MPI's text for code>". */
rl_status rl_dist_mpi_failed(int code, const char *what);

#endif
