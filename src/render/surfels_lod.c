/* surfels_lod.c: the level-of-detail rule of Progressive Blue Surfels
 * (Jähn 2015, Sec. 6.2; surfels_internal.h): how much of a node's surfel
 * sequence a frame draws, and how large each point is. */
#include <math.h>

#include "render/surfels_internal.h"

rl_surfel_lod rl_surfels_node_lod(double area, double coverage, uint32_t count, float min_size,
                                  float max_size, float overdraw, float point_size)
{
    rl_surfel_lod lod = { 0, 0.0f, true };
    const double min2 = (double)min_size * min_size, max2 = (double)max_size * max_size;
    if (count == 0 || !(area <= max2))
        return lod;               /* meshes only (also for NaN or +inf) */
    /* Sec. 6.2: prefix = projected size x coverage x overdraw; when that
     * exceeds the sequence, all of it is drawn and the point size grows
     * with the projected area per drawn surfel (as a side length, since a
     * point's size is its side). */
    double want = area * coverage * overdraw;
    double grow = want > count ? sqrt(want / count) : 1.0;
    /* Between the two sizes, prefix and point size fall linearly from
     * their values at min_size to zero at max_size, and the node's meshes
     * are drawn too, so that switching levels does not pop. */
    double t = area <= min2 ? 1.0 : (max2 - area) / (max2 - min2);
    double len = t * (want < count ? want : count);
    double m = ceil(len);
    lod.prefix = m >= count ? count : (uint32_t)m;
    lod.point_size = (float)(t * point_size * grow);
    lod.descend = !(area <= min2);
    return lod;
}

float rl_surfel_point_side(float point_size, float relative_size, float cos_view)
{
    /* Sec. 6.2.1: the node's point size weighted by the surfel's relative
     * size and the cosine to the viewer; points facing away are hidden,
     * the others cover at least one pixel. */
    if (!(cos_view > 0.0f))
        return 0.0f;
    float side = point_size * relative_size * cos_view;
    return side > 1.0f ? side : 1.0f;
}
