/* bench_gl.h: `rl bench gl`, a quick overview of the OpenGL backend
 * against the software paths (gl-raster vs raster frames, the visibility
 * property on GL vs software); see bench_gl.c. cmd_bench.c dispatches
 * `rl bench gl` here. */
#ifndef RL_APP_BENCH_GL_H
#define RL_APP_BENCH_GL_H

/* argv[0] is "bench", argv[1] "gl"; returns an exit code (cli.h). */
int bench_gl(int argc, char **argv);

#endif
