/* bench_pt_bdpt.h: the bdpt section of `rl bench pt` (issue 37): pt
 * against bdpt at equal time; see bench_pt_bdpt.c. */
#ifndef RL_APP_BENCH_PT_BDPT_H
#define RL_APP_BENCH_PT_BDPT_H

#include <stdbool.h>

#include "rl/rl_common.h"

struct cJSON;

typedef struct bench_pt_bdpt_args {
    int threads;
    bool quick;
} bench_pt_bdpt_args;

/* Fills sec; RL_OK or the failing status. */
rl_status bench_pt_bdpt(const bench_pt_bdpt_args *a, struct cJSON *sec);
/* --only hybrid: gl-pt without and with light paths (light_paths=1024,
 * overlapped and not) at equal CPU time on the same scenes. */
rl_status bench_pt_hybrid(const bench_pt_bdpt_args *a, struct cJSON *sec);

#endif
