/* bigalloc.h: allocation of large arrays that a build writes once, on
 * transparent huge pages where the system offers them (internal). */
#ifndef RL_CORE_BIGALLOC_H
#define RL_CORE_BIGALLOC_H

#include <stdbool.h>
#include <stddef.h>

/* Arrays below this size come from plain malloc. */
#define RL_BIG_ALLOC_MIN ((size_t)4 << 20)

/* malloc for an array of `bytes`; with `huge`, an array of at least
 * RL_BIG_ALLOC_MIN bytes is aligned to 2 MiB and, on Linux, advised for
 * transparent huge pages (madvise MADV_HUGEPAGE; ignored where the kernel
 * has them off). The result is released with free() and may be passed to
 * realloc(). NULL when out of memory (no error is set: callers report
 * what they were building). Why: a Line Space is gigabytes written once
 * by a build, and on virtual machines every 4 KiB first-touch fault is
 * expensive; one 2 MiB fault instead of 512 halved the bunny 64^3 build
 * on the 2-core VM of 2026-12-03 (docs/line-space.md). */
void *rl_big_alloc(size_t bytes, bool huge);

/* An array of count items of size bytes through rl_big_alloc(huge = true),
 * overflow-checked, zero-filled when `zero`; sets RL_ERR_OUT_OF_MEMORY
 * with a message on failure (as rl_alloc). For the acceleration
 * structures' build arrays: a BVH over `city` (1.4 M triangles) built in
 * 0.58-0.67 s with them against 1.55-1.7 s without on the same VM. */
void *rl_big_array(size_t count, size_t size, bool zero);

/* Faults the pages of p[0..bytes) in without changing their contents
 * (Linux >= 5.14: madvise MADV_POPULATE_WRITE; elsewhere a no-op), so that
 * an idle thread can take a later writer's first-touch faults off its
 * path; safe while another thread reads or writes the array. Why: first
 * touches of fresh memory cost about 2 ms per MiB on the 2-core VM (a 200
 * MiB memset: 0.4-0.6 s the first time in a process, 31 ms on pages it
 * freed just before), more than building a BVH over them (bench/README.md,
 * rays, 2026-12-06). */
void rl_big_prefault(void *p, size_t bytes);

#endif
