/* dist_balance.c: the pre-compute balancer's cut (dist_balance.h). */
#include "dist/dist_balance.h"

#include <stdbool.h>

static double item_cost(const double *cost, uint32_t i)
{
    /* A bad estimate (negative, NaN) must not pull a cut backwards. */
    return !cost ? 1.0 : cost[i] > 0.0 ? cost[i] : 0.0;
}

void rl_dist_cut_by_cost(const double *cost, uint32_t n, const double *speed, size_t ranks, uint32_t *count)
{
    if (ranks == 0)
        return;
    double total = 0.0, speeds = 0.0;
    for (uint32_t i = 0; i < n; ++i)
        total += item_cost(cost, i);
    for (size_t r = 0; r < ranks; ++r)
        speeds += speed && speed[r] > 0.0 ? speed[r] : 0.0;
    const bool equal = !(speeds > 0.0);
    if (equal)
        speeds = (double)ranks;
    size_t last = 0;                 /* the last rank with a share: it takes the rest */
    for (size_t r = 0; r < ranks; ++r)
        if (equal || (speed[r] > 0.0))
            last = r;
    /* Walk the items once; the cut after rank r's run lies where the
     * prefix sum comes nearest to the cumulative target. */
    uint32_t at = 0;
    double prefix = 0.0, target = 0.0;
    for (size_t r = 0; r < ranks; ++r) {
        const double v = equal ? 1.0 : speed[r] > 0.0 ? speed[r] : 0.0;
        const uint32_t start = at;
        if (r == last) {
            at = n;
        } else if (v > 0.0) {
            target += total * v / speeds;
            while (at < n) {
                const double c = item_cost(cost, at);
                if (prefix + 0.5 * c > target)
                    break;
                prefix += c;
                ++at;
            }
        }
        count[r] = at - start;
    }
}
