/* threads.c: a bound on the threads a parallel region may start (threads.h). */
#define _POSIX_C_SOURCE 200809L
#include "core/threads.h"

#include <omp.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <unistd.h>

#include "core/error.h"

#define THREADS_PER_PROCESSOR 8
/* glibc reserves this much address space per malloc arena (HEAP_MAX_SIZE
 * on 64-bit), and a thread that allocates gets an arena of its own. */
#define ARENA_BYTES ((double)(64 << 20))

/* A worker's stack: OMP_STACKSIZE when set (a number with an optional
 * B/K/M/G suffix, kilobytes without one, as OpenMP defines it), else the
 * default of a new POSIX thread (from RLIMIT_STACK). */
static double stack_bytes(void)
{
    const char *env = getenv("OMP_STACKSIZE");
    if (env && *env) {
        char *end = NULL;
        double v = strtod(env, &end);
        double unit = 1024.0;
        for (; end && *end == ' '; ++end) {}
        if (end && (*end == 'B' || *end == 'b')) unit = 1.0;
        if (end && (*end == 'M' || *end == 'm')) unit = 1048576.0;
        if (end && (*end == 'G' || *end == 'g')) unit = 1073741824.0;
        if (v > 0.0)
            return v * unit;
    }
    pthread_attr_t attr;
    size_t size = 8u << 20;
    if (pthread_attr_init(&attr) == 0) {
        pthread_attr_getstacksize(&attr, &size);
        pthread_attr_destroy(&attr);
    }
    return (double)size;
}

/* Address space in use now (the first field of /proc/self/statm, in
 * pages); 0 where it cannot be read. */
static double address_space_used(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    unsigned long long pages = 0;
    if (f) {
        if (fscanf(f, "%llu", &pages) != 1)
            pages = 0;
        fclose(f);
    }
    long page = sysconf(_SC_PAGESIZE);
    return (double)pages * (double)(page > 0 ? page : 4096);
}

int rl_threads_creatable(void)
{
    int procs = omp_get_num_procs();
    double bound = (double)THREADS_PER_PROCESSOR * (procs > 0 ? procs : 1);
    struct rlimit lim;
    if (getrlimit(RLIMIT_NPROC, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY && (double)lim.rlim_cur / 2.0 < bound)
        bound = (double)lim.rlim_cur / 2.0;
    if (getrlimit(RLIMIT_AS, &lim) == 0 && lim.rlim_cur != RLIM_INFINITY) {
        double left = (double)lim.rlim_cur - address_space_used();
        double fit = 0.5 * left / (stack_bytes() + ARENA_BYTES);
        if (fit < bound)
            bound = fit;
    }
    return bound < 1.0 ? 1 : (int)bound;
}

int rl_threads_clamp(int requested, const char *what)
{
    if (requested <= 0)
        return requested;
    int most = rl_threads_creatable();
    if (requested <= most)
        return requested;
    rl_warn("%s: threads=%d clamped to %d, the most this process can start (%d per processor, RLIMIT_NPROC, "
            "RLIMIT_AS)", what, requested, most, THREADS_PER_PROCESSOR);
    return most;
}
