/* dist_balance.h: the pre-compute balancer's cut (Ullmann 2003, Sec.
 * 4.3.3), without MPI, so that it is tested in every build. */
#ifndef RL_DIST_BALANCE_H
#define RL_DIST_BALANCE_H

#include <stddef.h>
#include <stdint.h>

/* Cuts n items in their order into ranks consecutive runs, count[i] items
 * for rank i, so that rank i's share of the summed cost is speed[i] over
 * the summed speed (b_Slave_i = c_Slave_i / c_total * b_total). cost NULL:
 * every item costs 1 (the faces themselves are the load). A rank of speed
 * 0 (lost, or not measured) gets nothing; no speed above 0: equal shares.
 * Each cut lies at the item boundary nearest its cumulative target, so a
 * rank's cost misses its share by less than one item's cost at each end. */
void rl_dist_cut_by_cost(const double *cost, uint32_t n, const double *speed, size_t ranks, uint32_t *count);

#endif
