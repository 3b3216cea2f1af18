/* threads.h: how many OpenMP threads a thread-count option may ask for
 * (internal). */
#ifndef RL_CORE_THREADS_H
#define RL_CORE_THREADS_H

/* The most threads this process should start in one parallel region: 8
 * per processor (more only wait for a core), half the RLIMIT_NPROC left
 * to the user, and as many as half the address space left under
 * RLIMIT_AS holds, at one stack and one malloc arena each. OpenMP does not
 * fail when it cannot start a thread, it exits the process: with
 * threads=1024 under an 8 GB address-space limit, libgomp printed
 * "Thread creation failed" and exited 1. At least 1. */
int rl_threads_creatable(void);

/* requested (> 0) clamped to rl_threads_creatable(), with a warning that
 * starts with what (e.g. the renderer's name); 0 and negatives pass
 * unchanged. */
int rl_threads_clamp(int requested, const char *what);

#endif
