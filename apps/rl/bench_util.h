/* bench_util.h: what every `rl bench` subcommand shares: progress notes,
 * JSON number and ray/metric objects, argument parsing of counts and
 * section lists, the default output path, and the loop that runs named
 * sections into one record (a failed section is recorded with its reason
 * and the others still run). */
#ifndef RL_APP_BENCH_UTIL_H
#define RL_APP_BENCH_UTIL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rl/rl.h"
#include "rl/rl_metrics.h"

struct cJSON;

/* "bench NAME: ..." on stderr when the log level includes info. */
void bench_note(const char *bench, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* JSON has no NaN or infinity: unknown values become null. */
void bench_add_num(struct cJSON *o, const char *key, double value);
uint64_t bench_rays_total(const rl_render_stats *s);
/* {primary, shadow, ..., total} */
struct cJSON *bench_rays_json(const rl_render_stats *s);
/* {ssim, rmse, psnr, max_abs, pixels} */
struct cJSON *bench_metrics_json(const rl_image_metrics *m);
double bench_ratio(double a, double b);          /* NaN when b is 0 */
/* The process's CPU time so far (all threads), in ms; 0 where unknown. */
double bench_cpu_ms(void);

/* What bench_render_for_cpu did. */
typedef struct bench_budget_run {
    long long frames;     /* renders made (each adds the renderer's spp) */
    double wall_ms, cpu_ms;
} bench_budget_run;
/* Renders frames of r into img until the process's CPU time divided by
 * threads reaches budget_s (at least one frame). r accumulates over frames
 * of one camera (pt, bdpt). CPU time over threads is what a quiet
 * machine's wall clock would show on a shared one, so equal budgets are
 * equal time for renderers that keep their threads busy. */
rl_status bench_render_for_cpu(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *img,
                               int threads, double budget_s, bench_budget_run *out);

/* A whole number in 1..max for option; prints the usage error. */
bool bench_parse_count(const char *option, const char *text, long long max, long long *out);
/* --only: a comma-separated subset of names[0..count-1] as bits. */
bool bench_parse_sections(const char *text, const char *const *names, int count,
                             unsigned *sections);
/* bench/results/PREFIX-YYYYMMDD-HHMMSS.json (UTC), creating the folder. */
bool bench_default_out(const char *prefix, char *path, size_t size);
/* Where a benchmark writes its record: --out (given, may be NULL) when its
 * folder is writable, else the default name above; into path (size bytes).
 * False (error printed) for a path too long or not writable. */
bool bench_out_path(const char *given, const char *prefix, char *path, size_t size);

/* One section: fills sec; on failure may write why into the reason buffer
 * given to bench_run_sections (else rl_last_error() is recorded). */
typedef rl_status (*bench_section_fn)(void *ctx, struct cJSON *sec);
/* Runs the sections whose bit is set in `wanted`, in order, each into
 * root[names[k]] with "status": "ok" or "failed" and "reason". reason is
 * cleared before each section. Then refreshes root["machine"] (the load
 * average after the run) and writes root to out. Returns RL_CLI_OK, or
 * RL_CLI_FAIL (printed) when a section failed or the file was not written. */
int bench_run_sections(const char *bench, struct cJSON *root, const char *const *names,
                          const bench_section_fn *fns, int count, unsigned wanted, void *ctx,
                          char *reason, int threads, const char *out);

#endif
