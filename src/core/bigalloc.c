/* bigalloc.c: large arrays on transparent huge pages (see bigalloc.h). */
#define _DEFAULT_SOURCE
#include "core/bigalloc.h"
#include "core/error.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#define HUGE_PAGE ((size_t)2 << 20)

void *rl_big_alloc(size_t bytes, bool huge)
{
    if (!huge || bytes < RL_BIG_ALLOC_MIN)
        return malloc(bytes ? bytes : 1);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    /* Whole huge pages: the advice covers the array's last page too. */
    size_t rounded = (bytes + HUGE_PAGE - 1) & ~(HUGE_PAGE - 1);
    if (rounded < bytes)
        return NULL;
    void *p = NULL;
    if (posix_memalign(&p, HUGE_PAGE, rounded) != 0)
        return NULL;
    /* Advice only: a kernel without THP (or with it off) keeps 4 KiB
     * pages, and the array works the same. */
    (void)madvise(p, rounded, MADV_HUGEPAGE);
    return p;
#else
    return malloc(bytes);
#endif
}

void *rl_big_array(size_t count, size_t size, bool zero)
{
    if (size && count > SIZE_MAX / size) {
        rl_error(RL_ERR_OUT_OF_MEMORY, "allocation of %zu x %zu bytes overflows", count, size);
        return NULL;
    }
    size_t bytes = count * size;
    void *p = rl_big_alloc(bytes, true);
    if (!p) {
        rl_error(RL_ERR_OUT_OF_MEMORY, "out of memory allocating %zu x %zu bytes", count, size);
        return NULL;
    }
    if (zero)
        memset(p, 0, bytes ? bytes : 1);
    return p;
}

void rl_big_prefault(void *p, size_t bytes)
{
#if defined(__linux__) && defined(MADV_POPULATE_WRITE)
    /* madvise wants a page-aligned start: round it up (the part before
     * is faulted by its writer). Errors (an older kernel: EINVAL) only
     * leave the faults to the writer. */
    uintptr_t start = ((uintptr_t)p + 4095) & ~(uintptr_t)4095, end = (uintptr_t)p + bytes;
    if (p && end > start)
        (void)madvise((void *)start, end - start, MADV_POPULATE_WRITE);
#else
    (void)p;
    (void)bytes;
#endif
}
