/* raster_bin.c: sort-middle binning into horizontal bands.
 *
 * A counting sort by band that keeps submission order inside each band: a
 * band later walks its list front to back, which is what makes the threaded
 * result identical to the serial one. Items spanning several bands appear in
 * each of them; items with no rows (culled points) in none. */
#include "core/error.h"
#include "raster/raster_internal.h"

static const rl_raster_rows *rows_at(const void *items, size_t i, size_t stride)
{
    return (const rl_raster_rows *)((const char *)items + i * stride);
}

bool rl_raster_bin(rl_raster_bins *bins, const void *items, size_t count, size_t stride,
                   int num_bands)
{
    if (!rl_reserve((void **)&bins->off, &bins->off_cap, (size_t)num_bands + 1, sizeof *bins->off, 64))
        return false;
    uint32_t *off = bins->off;
    for (int b = 0; b <= num_bands; ++b)
        off[b] = 0;
    /* Count into off[b + 1], so that the prefix sum yields the starts. */
    size_t total = 0;
    for (size_t i = 0; i < count; ++i) {
        const rl_raster_rows *r = rows_at(items, i, stride);
        if (r->y0 >= r->y1)
            continue;   /* culled item */
        int b0 = r->y0 / RL_RASTER_BAND_ROWS, b1 = (r->y1 - 1) / RL_RASTER_BAND_ROWS;
        for (int b = b0; b <= b1; ++b)
            off[b + 1]++;
        total += (size_t)(b1 - b0 + 1);
    }
    if (total > UINT32_MAX || count > UINT32_MAX)
        return false;
    for (int b = 0; b < num_bands; ++b)
        off[b + 1] += off[b];
    if (!rl_reserve((void **)&bins->idx, &bins->idx_cap, total, sizeof *bins->idx, 64))
        return false;
    /* Fill, advancing off[b] as a cursor; afterwards off[b] is the end of
     * band b, i.e. the start of band b + 1: shift back by one. */
    for (size_t i = 0; i < count; ++i) {
        const rl_raster_rows *r = rows_at(items, i, stride);
        if (r->y0 >= r->y1)
            continue;   /* culled item */
        int b0 = r->y0 / RL_RASTER_BAND_ROWS, b1 = (r->y1 - 1) / RL_RASTER_BAND_ROWS;
        for (int b = b0; b <= b1; ++b)
            bins->idx[off[b]++] = (uint32_t)i;
    }
    for (int b = num_bands; b > 0; --b)
        off[b] = off[b - 1];
    off[0] = 0;
    return true;
}
