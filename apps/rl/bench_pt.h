/* bench_pt.h: `rl bench pt`, the measurements of Schröder 2017 (Table 1,
 * Diagrams 1-3, Ch. 12) for the path tracer and the Line Space; see
 * bench_pt.c. cmd_bench.c dispatches `rl bench pt` here. */
#ifndef RL_APP_BENCH_PT_H
#define RL_APP_BENCH_PT_H

/* argv[0] is "bench", argv[1] "pt"; returns an exit code (cli.h). */
int bench_pt(int argc, char **argv);

#endif
