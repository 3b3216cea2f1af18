/* stats_internal.h: what the evaluation layer shares of stats.c beyond
 * rl_stats.h. */
#ifndef RL_EVAL_STATS_INTERNAL_H
#define RL_EVAL_STATS_INTERNAL_H

#include <stddef.h>

/* Pearson's r of n >= 2 finite pairs into *r: 0, or 1 / 2 when x / y is
 * constant (r undefined, *r untouched). Records no error: for callers to
 * whom an undefined r is an answer, not a failure (a plot's caption). */
int rl_stats_pearson(const double *x, const double *y, size_t n, double *r);

#endif
