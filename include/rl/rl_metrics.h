/* rl_metrics.h: image-quality metrics, for comparing an approximate renderer
 * against a reference (Vertex Tracing vs Whitted, Line Space vs BVH, SVS vs
 * CHC++).
 *
 * All metrics read the colour layers of two images of equal size, clamp each
 * channel to [0, 1] and encode it to sRGB first (what a viewer sees and
 * what the 8-bit PNG holds), unless the options say linear. An optional mask
 * (one byte per pixel, nonzero = counted) restricts the comparison, e.g. to
 * the pixels of the objects an algorithm computes.
 *
 * SSIM follows Wang, Bovik, Sheikh, Simoncelli 2004 (IEEE TIP 13(4)): an
 * 11x11 Gaussian window with sigma 1.5, K1 = 0.01, K2 = 0.03, dynamic range
 * L = 1, computed on luma Y = 0.299 R + 0.587 G + 0.114 B (Rec. 601) or per
 * RGB channel averaged, and averaged over the window centres inside the
 * image (and inside the mask). Windows are truncated at the borders (the
 * weights renormalised), so every pixel is a window centre. A mask selects
 * window centres only: each window still reads all its pixels, masked or
 * not.
 *
 * Hierarchical (multi-scale) SSIM, ssim_levels = L in 2..5: the
 * multi-scale SSIM of Wang, Simoncelli & Bovik 2003 over a Gaussian pyramid
 * (Burt 1981: the separable kernel [1 4 6 4 1] / 16, truncated and
 * renormalised at the borders, then every second pixel, so a level of n
 * pixels has ceil(n / 2)). Contrast x structure is averaged at every level,
 * the full SSIM (with luminance) at the coarsest; the means are combined as
 * a product with the 2003 paper's exponents (0.0448, 0.2856, 0.3001,
 * 0.2363, 0.1333; the first L renormalised to sum to 1), negative means
 * taken as 0. rl_image_compare() then reports it in `ssim`; RMSE, PSNR and
 * max_abs stay single-scale. Masks and the per-pixel map are single-scale
 * only (RL_ERR_INVALID_ARG with L > 1). Jähn 2015, Sec. 4.2.5 uses it to
 * emphasise large-area errors.
 *
 * Outputs stay untouched on failure. */
#ifndef RL_METRICS_H
#define RL_METRICS_H

#include "rl/rl_common.h"
#include "rl/rl_image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_metric_options {    /* zero = default */
    const uint8_t *mask;              /* width*height, nonzero = counted; NULL = all */
    bool linear;                      /* compare linear values instead of sRGB */
    bool ssim_rgb;                    /* SSIM per channel, averaged (default: luma) */
    int ssim_levels;                  /* 0 or 1: single-scale SSIM; 2..5: multi-scale */
} rl_metric_options;

typedef struct rl_image_metrics {
    double rmse;                      /* root mean squared error over RGB, in [0, 1] */
    double psnr;                      /* dB, 10 log10(1 / mse); INFINITY when equal */
    double ssim;                      /* mean SSIM in [-1, 1] */
    double max_abs;                   /* largest absolute channel difference */
    uint64_t pixels;                  /* pixels counted */
} rl_image_metrics;

/* RL_ERR_INVALID_ARG for NULL or size-mismatched images, missing colour
 * layers, a mask that selects no pixel, ssim_levels outside 0..5 or a mask
 * with ssim_levels > 1. With ssim_levels > 1, `ssim` is the multi-scale
 * SSIM. */
RL_API rl_status rl_image_compare(const rl_image *test, const rl_image *reference,
                                  const rl_metric_options *opt, rl_image_metrics *out);

/* The per-pixel SSIM map (width*height floats, 0 outside the mask), for
 * difference pictures; out must hold width*height values. Single-scale
 * only: RL_ERR_INVALID_ARG for ssim_levels > 1. */
RL_API rl_status rl_image_ssim_map(const rl_image *test, const rl_image *reference,
                                   const rl_metric_options *opt, float *out);

/* A false-colour picture of |test - reference| (per pixel max channel
 * difference of the sRGB-encoded values, scaled by gain, clamped to 1),
 * for reports; like Ullmann 2003 Fig. 5.1d. Black (alpha 1) where equal,
 * then red, yellow, white. RL_ERR_INVALID_ARG as above, or for a gain that
 * is not finite and positive. */
RL_API rl_status rl_image_difference(const rl_image *test, const rl_image *reference, float gain,
                                     rl_image **out);

#ifdef __cplusplus
}
#endif
#endif
