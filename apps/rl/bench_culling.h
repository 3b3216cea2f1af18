/* bench_culling.h: `rl bench culling`, Jähn 2015 Ch. 7 applications of
 * the culling renderers (bench_culling.c); cmd_bench.c dispatches here. */
#ifndef RL_APP_BENCH_CULLING_H
#define RL_APP_BENCH_CULLING_H

/* argv[0] is "bench", argv[1] "culling"; returns an exit code (cli.h). */
int bench_culling(int argc, char **argv);

#endif
