/* rl_plot.h: plots for evaluation reports, drawn with cairo.
 *
 * Heat maps of 2-D slices (Jähn 2015, Sec. 5.6.1, Fig. 5.3b) with a colour
 * bar, an optional scene top-view image under semi-transparent cells,
 * region borders and sample positions; violin plots with a box plot inside
 * (Sec. 5.6.2 warns against box plots alone: a distribution of a scene
 * property often has several modes); histograms; a correlation plot of
 * measured against approximated values; line plots for convergence curves;
 * and a plain image, so that a report can embed renders.
 *
 * Output goes to a file, SVG or PNG by its extension, or to memory as SVG
 * text, which an HTML report inlines: cairo's SVG surface turns text into
 * paths and embeds images as data URIs, so an inlined plot needs no other
 * file and no font on the viewer's side. The in-memory text is made for
 * inlining: it starts at "<svg" (no XML declaration), ends with "</svg>",
 * and its element ids carry a prefix derived from the plot's content, so
 * that several plots in one HTML page do not borrow each other's glyphs.
 * Sizes are in CSS pixels in SVG and pixels in PNG.
 *
 * Weighted data: every series may carry weights (region areas or volumes);
 * densities, quantiles and histogram bars are then weighted (rl_stats.h).
 *
 * Failure: RL_ERR_INVALID_ARG for NULL or empty data, NaN values, both or
 * neither output, an extension other than .svg/.png, a size outside
 * 16..8192, more than 64 series; RL_ERR_IO when the file cannot be
 * written; RL_ERR_OUT_OF_MEMORY. Nothing is written on failure (a file
 * whose write fails half way is removed), and *svg is set only on success. */
#ifndef RL_PLOT_H
#define RL_PLOT_H

#include "rl/rl_common.h"
#include "rl/rl_image.h"
#include "rl/rl_math.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct rl_plot_style {        /* zero = default */
    int width, height;                /* px (CSS px in SVG); 0 -> 640 x 420 */
    const char *title;                /* NULL: none */
    const char *x_label, *y_label;
} rl_plot_style;

typedef struct rl_plot_output {       /* exactly one of the two */
    const char *path;                 /* "x.svg" or "x.png" */
    char **svg;                       /* receives malloc'ed NUL-terminated SVG; free() it */
} rl_plot_output;

/* Colour maps: "viridis" (default, perceptually uniform), "magma", and the
 * diverging "coolwarm" for differences (centred on 0 when vmin < 0 < vmax).
 * Maps t in [0, 1] (clamped) to display (sRGB-encoded) RGB in [0, 1]. Unknown
 * names fall back to viridis (NaN t gives the t = 0 colour);
 * rl_plot_colormap_valid() says whether a name is known. Key colours:
 * matplotlib's viridis and magma (van der Walt & Smith 2015), Moreland's
 * 2009 cool-warm table, interpolated linearly in display space. */
RL_API rl_vec3 rl_plot_colormap(const char *name, double t);
RL_API bool rl_plot_colormap_valid(const char *name);

/* One rectangle of a heat map in plot-plane coordinates (x right, y up). */
typedef struct rl_plot_cell {
    double x0, y0, x1, y1;
    double value;                     /* NaN: drawn hatched grey ("no data") */
} rl_plot_cell;

typedef struct rl_plot_heatmap {
    const rl_plot_cell *cells;
    size_t count;
    double x0, y0, x1, y1;            /* extent shown; all 0 -> the cells' bounds */
    double vmin, vmax;                /* colour range; vmin == vmax -> the data's */
    const char *colormap;             /* NULL -> "viridis"; unknown: INVALID_ARG */
    bool reverse;                     /* high values dark (e.g. time: bad = dark) */
    bool borders;                     /* draw region borders */
    const char *unit;                 /* colour bar label */
    /* Top view drawn under the cells, stretched over the extent; its row 0
     * is the top (largest y). NULL: none. */
    const rl_image *overlay;
    float cell_alpha;                 /* 0 -> 0.75 with an overlay, 1 without */
    const double *points;             /* sample positions, x,y pairs; may be NULL */
    size_t num_points;
} rl_plot_heatmap;

/* The map keeps equal aspect (one unit as long on x as on y). A diverging
 * map ("coolwarm") with vmin < 0 < vmax widens the range to [-m, m],
 * m = max(-vmin, vmax), so that 0 gets the neutral colour. NaN cells are
 * hatched over light grey, or over the overlay when there is one. Also
 * RL_ERR_INVALID_ARG for a non-finite cell corner or extent, an infinite
 * value, vmin > vmax, cell_alpha outside [0, 1], points NULL with
 * num_points > 0, an overlay without colour layer, an empty extent. */
RL_API rl_status rl_plot_heatmap_draw(const rl_plot_heatmap *h, const rl_plot_style *style,
                                      const rl_plot_output *out);

/* A named, optionally weighted, series of values. */
typedef struct rl_plot_series {
    const char *name;
    const double *values;
    const double *weights;            /* NULL: all 1 */
    size_t count;
} rl_plot_series;

/* One violin per series (weighted Gaussian KDE, mirrored), a box inside
 * (weighted quartiles, whiskers at the 5 % and 95 % quantiles), the median
 * as a white mark and the mean as a dot; side by side on a shared axis.
 * Violins are cut at each series' minimum and maximum and scaled to the
 * same width; a constant series is drawn as a flat bar. Series names (NULL:
 * "series i") stand under the violins, tilted when they are too long. */
RL_API rl_status rl_plot_violin(const rl_plot_series *series, size_t n, const rl_plot_style *style,
                                const rl_plot_output *out);

/* Overlaid histograms (outlined bars), bins over the common range; bins 0
 * -> Freedman-Diaconis (the smallest width over the series, with Kish's
 * n_eff; sqrt(n) bins when every IQR is 0), clamped to 5..100; bins < 0 or
 * > 1000: RL_ERR_INVALID_ARG. The y axis is each series' weight share per
 * bin (y_label NULL -> "share of weight"); a legend names the series when
 * there are several or the one has a name. */
RL_API rl_status rl_plot_histogram(const rl_plot_series *series, size_t n, int bins,
                                   const rl_plot_style *style, const rl_plot_output *out);

/* Measured (x) against approximated (y) values, with the line y = x and
 * Pearson's r, mean and max absolute error in the legend; both axes share
 * one range and scale. n >= 1; r reads "undefined" for n = 1 or constant
 * data. Axis labels default to "measured" and "approximated". */
RL_API rl_status rl_plot_correlation(const double *measured, const double *approximated, size_t n,
                                     const rl_plot_style *style, const rl_plot_output *out);

/* Line plot: each series' values are y over the shared xs (count each:
 * a series whose count differs is RL_ERR_INVALID_ARG); log_x/log_y choose
 * logarithmic axes (values must then be > 0). Points are marked when there
 * are at most 40; a legend appears for several or named series. */
typedef struct rl_plot_lines {
    const double *xs;
    size_t count;
    const rl_plot_series *series;     /* weights ignored */
    size_t num_series;
    bool log_x, log_y;
} rl_plot_lines;
RL_API rl_status rl_plot_lines_draw(const rl_plot_lines *lines, const rl_plot_style *style,
                                    const rl_plot_output *out);

/* The image's colour layer (clamped, sRGB-encoded, alpha kept) as a plot,
 * e.g. to embed a render in an HTML report; style size 0 -> the image's
 * size, one side 0 -> the image's aspect (the result must lie in 16..8192).
 * The image is fitted with its aspect; title above, x_label as a caption
 * below; magnified at least 2x it keeps its pixels sharp. */
RL_API rl_status rl_plot_image(const rl_image *image, const rl_plot_style *style,
                               const rl_plot_output *out);

#ifdef __cplusplus
}
#endif
#endif
