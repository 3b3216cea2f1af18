/* bench_surfels.h: `rl bench surfels`, the Table 6.1 timings of the
 * Progressive Blue Surfels preprocessing (Jähn 2015, Sec. 6.4.3) with the
 * sampling quality of each variant; see bench_surfels.c. cmd_bench.c
 * dispatches `rl bench surfels` here. */
#ifndef RL_APP_BENCH_SURFELS_H
#define RL_APP_BENCH_SURFELS_H

/* argv[0] is "bench", argv[1] "surfels"; returns an exit code (cli.h). */
int bench_surfels(int argc, char **argv);

#endif
