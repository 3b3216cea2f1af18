/* bench_dist.h: `rl bench dist`, distributed runs against their rank
 * count (bench_dist.c). cmd_bench.c dispatches `rl bench dist` here. */
#ifndef RL_APP_BENCH_DIST_H
#define RL_APP_BENCH_DIST_H

/* argv[0] is "bench", argv[1] "dist"; returns an exit code (cli.h). */
int bench_dist(int argc, char **argv);

#endif
