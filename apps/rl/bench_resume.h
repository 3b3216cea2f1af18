/* bench_resume.h: a folder in which a long benchmark keeps what it has
 * measured so far, so that a run that stops (a machine lent for a few
 * hours, a crash) can be continued by the same command instead of being
 * started over.
 *
 * The folder holds key.txt, the options of the run that made it: only a
 * run with the same key may continue there. Named value series are saved
 * after every block (written to a temporary file and renamed, so that a
 * run killed while saving leaves the previous block intact); other files
 * (a saved approximation) go to bench_resume_path(). */
#ifndef RL_APP_BENCH_RESUME_H
#define RL_APP_BENCH_RESUME_H

#include "rl/rl_sampling.h"

#include <stdbool.h>
#include <stddef.h>

typedef struct bench_resume bench_resume;

/* Opens dir (made if missing) for a run described by key. Fails, with the
 * error printed, when dir belongs to a run with another key. */
bool bench_resume_open(const char *dir, const char *key, bench_resume **out);
void bench_resume_close(bench_resume *r);      /* NULL is a no-op */
/* dir/name, valid until the next call. */
const char *bench_resume_path(bench_resume *r, const char *name);
/* The series saved under name: *values malloc'd (NULL and 0 when none was
 * saved). False, with the error printed, for an unreadable file. */
bool bench_resume_load(bench_resume *r, const char *name, double **values, size_t *count);
/* Saves count values under name, replacing what was there. */
bool bench_resume_save(bench_resume *r, const char *name, const double *values, size_t count);
/* Saves a sampled approximation under name, also through a temporary file
 * and a rename: a run killed while saving leaves no half file that the
 * next run would fail to load. False on failure (the library's error, or
 * one printed). */
bool bench_resume_save_approx(bench_resume *r, const char *name, const rl_approx *a);
/* The approximation saved under name: RL_OK with *out NULL when none was
 * saved; the library's status and message (RL_ERR_IO, RL_ERR_PARSE) for a
 * file that cannot be loaded, which a run must not silently sample over. */
rl_status bench_resume_load_approx(bench_resume *r, const char *name, rl_approx **out);

#endif
