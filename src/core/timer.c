/* timer.c: wall-clock timing from CLOCK_MONOTONIC, which never jumps with
 * NTP or daylight-saving changes, so intervals are always meaningful. */
#define _POSIX_C_SOURCE 200809L
#include "rl/rl_timer.h"

#include <time.h>

double rl_time_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void rl_timer_start(rl_timer *t) { t->start_s = rl_time_s(); }

double rl_timer_ms(const rl_timer *t) { return 1e3 * (rl_time_s() - t->start_s); }
