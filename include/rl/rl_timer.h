/* rl_timer.h: monotonic timers and a TTY-aware progress bar.
 *
 * The progress bar is the stock rl_progress_fn for applications: it prints to
 * the stream the application gives (normally stderr), draws an updating bar
 * only when that stream is a terminal, writes at most a few plain lines
 * otherwise, and stays silent for work that finishes within its delay
 * (1 s by default). The library itself never creates one. */
#ifndef RL_TIMER_H
#define RL_TIMER_H

#include <stdio.h>
#include "rl/rl_common.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Seconds from a monotonic clock with an arbitrary origin. */
RL_API double rl_time_s(void);
typedef struct rl_timer { double start_s; } rl_timer;
RL_API void rl_timer_start(rl_timer *t);
RL_API double rl_timer_ms(const rl_timer *t);

typedef struct rl_progress rl_progress;
/* label: e.g. "render cornell"; stream: where to draw (NULL = stderr). */
RL_API rl_status rl_progress_create(const char *label, FILE *stream, rl_progress **out);
RL_API void rl_progress_set_delay(rl_progress *p, double seconds);
/* Thread-safe; matches rl_progress_fn (pass the rl_progress* as user). */
RL_API bool rl_progress_update(void *progress, double done);
/* Finishes the line (if anything was drawn) and frees. NULL is a no-op. */
RL_API void rl_progress_finish(rl_progress *p);

#ifdef __cplusplus
}
#endif
#endif
