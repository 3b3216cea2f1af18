/* rl_filter.h: noise-reduction filters for path-traced images (Schröder
 * 2017, Sec. 8.2, after Priese 2015), optionally guided by a G-buffer.
 *
 *   GAUSS      linear smoothing with a Gaussian of sigma_s pixels;
 *   BILATERAL  Gaussian in distance and in colour difference (sigma_r), and,
 *              with a G-buffer, in normal (1 - n·n', sigma_n) and relative
 *              depth difference (sigma_z), and zero between different
 *              objects or between a seen and an empty pixel;
 *   ANISO      anisotropic diffusion (Perona & Malik 1990): `iterations`
 *              explicit steps of rate lambda over the 4 neighbours with the
 *              conductance g(d) = exp(-(d/kappa)^2), d the RGB distance;
 *              with a G-buffer, conductance is multiplied by the same
 *              G-buffer weight, so it is zero across object edges and
 *              vanishes across normal or depth edges;
 *   KUWAHARA   each pixel takes the mean of the least-variant of the four
 *              (r+1)x(r+1) quadrants around it (r = radius; 1 = the thesis'
 *              four 2x2 groups of the 3x3 neighbourhood);
 *   ATROUS     the edge-avoiding a-trous wavelet transform (Dammertz,
 *              Sewtz, Hanika, Lensch 2010; issue 37): `iterations` passes of
 *              the 5x5 B3-spline kernel with holes 2^i pixels apart, each tap
 *              weighted by exp(-|dc|^2 / sigma_r_i^2) on colour (sigma_r_i =
 *              sigma_r 2^-i), exp(-|dn|^2 / sigma_n^2) on the G-buffer
 *              normals and exp(-|dx|^2 / sigma_x^2) on its world positions;
 *              the result is the last coarse level (the detail coefficients
 *              are the noise that is dropped). Taps outside the image drop
 *              out of the normalised sum.
 * Filters read and write RL_LAYER_COLOR (linear RGB; alpha is copied from
 * `in`) and leave other layers as they are in the output. Borders clamp.
 * GAUSS and KUWAHARA ignore the G-buffer; its normal, depth and object
 * arrays (ATROUS: normal and position) may each be NULL (that term is then
 * dropped). Multithreaded
 * (OpenMP) and deterministic: results do not depend on the thread count.
 * `in` and `out` must have the same size and must not be the same image. */
#ifndef RL_FILTER_H
#define RL_FILTER_H

#include "rl/rl_common.h"
#include "rl/rl_gbuffer.h"
#include "rl/rl_image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum rl_filter_kind {
    RL_FILTER_NONE = 0,
    RL_FILTER_GAUSS,
    RL_FILTER_BILATERAL,
    RL_FILTER_ANISO,
    RL_FILTER_KUWAHARA,
    RL_FILTER_ATROUS,
    RL_FILTER_KIND_COUNT
} rl_filter_kind;

typedef struct rl_filter_desc {           /* zero = default */
    rl_filter_kind kind;
    float sigma_s;            /* spatial sigma in pixels; 0 -> 1.5 */
    int radius;               /* window radius; 0 -> ceil(2·sigma_s) (Kuwahara: 1) */
    float sigma_r;            /* colour sigma (linear units); 0 -> 0.1 */
    float sigma_n;            /* normal sigma (1 - n·n'; ATROUS: |n - n'|); 0 -> 0.1 */
    float sigma_z;            /* relative depth sigma; 0 -> 0.05 */
    int iterations;           /* ANISO: 0 -> 20; ATROUS (1..12): 0 -> 5 */
    float lambda;             /* ANISO rate, at most 0.25 for stability; 0 -> 0.2 */
    float kappa;              /* ANISO conductance scale; 0 -> 0.1 */
    float sigma_x;            /* ATROUS position sigma in world units; 0 -> per pixel,
                               * 2^iterations times the distance to its nearest
                               * seen 4-neighbour (the pixel's footprint) */
} rl_filter_desc;

RL_API const char *rl_filter_kind_name(rl_filter_kind kind);    /* "gauss", ... */
RL_API rl_status rl_filter_kind_parse(const char *name, rl_filter_kind *out);
/* RL_ERR_INVALID_ARG for NULL, size mismatch, in == out, out-of-range
 * parameters, or a G-buffer of another size. g may be NULL. Multithreaded. */
RL_API rl_status rl_filter_apply(const rl_filter_desc *desc, const rl_image *in,
                                 const rl_gbuffer *g, rl_image *out);

#ifdef __cplusplus
}
#endif
#endif
