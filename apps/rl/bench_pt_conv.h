/* bench_pt_conv.h: the convergence section of `rl bench pt` (issue 37):
 * RMSE against time on Bitterli's Cornell box settings; see
 * bench_pt_conv.c. */
#ifndef RL_APP_BENCH_PT_CONV_H
#define RL_APP_BENCH_PT_CONV_H

#include <stdbool.h>

#include "rl/rl_common.h"

struct cJSON;

typedef struct bench_pt_conv_args {
    int size;                      /* square image side */
    long long ref_spp;             /* reference samples (two halves) */
    long long spp_max;             /* the longest curve */
    int threads;
    const char *out_path;          /* the JSON record; the reference cache goes beside it */
    const char *configs;           /* comma-separated labels to run; NULL = all */
    const char *custom;            /* --conv-set: "key=value,..." of one more configuration
                                    * run to spp_max ("custom"); NULL or "" = none */
    double ref_budget_s;           /* wall seconds of reference rendering in this run; 0 = no limit */
    char *reason;                  /* why the section stopped (budget spent), reason_size bytes */
    size_t reason_size;
} bench_pt_conv_args;

/* Fills sec; RL_OK or the failing status. */
rl_status bench_pt_convergence(const bench_pt_conv_args *a, struct cJSON *sec);

#endif
