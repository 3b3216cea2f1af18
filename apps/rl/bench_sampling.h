/* bench_sampling.h: `rl bench sampling`, the measurements of Jähn 2015,
 * Sec. 5.7 (Fig. 5.5, Table 5.1) for the samplers of rl_sampling.h; see
 * bench_sampling.c. cmd_bench.c dispatches `rl bench sampling` here. */
#ifndef RL_APP_BENCH_SAMPLING_H
#define RL_APP_BENCH_SAMPLING_H

/* argv[0] is "bench", argv[1] "sampling"; returns an exit code (cli.h). */
int bench_sampling(int argc, char **argv);

#endif
