/* bench_vt.h: `rl bench vt`, the Ch. 5 measurements of Vertex Tracing
 * (Ullmann 2003, Sec. 5.1-5.3) against the Whitted ray tracer of the same
 * run; see bench_vt.c. cmd_bench.c dispatches `rl bench vt` here. */
#ifndef RL_APP_BENCH_VT_H
#define RL_APP_BENCH_VT_H

/* argv[0] is "bench", argv[1] "vt"; returns an exit code (cli.h). */
int bench_vt(int argc, char **argv);

#endif
