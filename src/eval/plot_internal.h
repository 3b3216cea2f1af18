/* plot_internal.h: what the plot files share (src/eval/plot*.c): output to a
 * file or memory, the cairo surface, axes with nice ticks, frame, labels,
 * legend and colour bar. Not part of the public API. */
#ifndef RL_EVAL_PLOT_INTERNAL_H
#define RL_EVAL_PLOT_INTERNAL_H

#include <cairo.h>

#include "rl/rl_plot.h"

#define RL_PLOT_MIN_SIZE 16
#define RL_PLOT_MAX_SIZE 8192
#define RL_PLOT_MAX_TICKS 32

/* A growing byte buffer: cairo's SVG and PNG streams end up here first, so
 * that nothing reaches the file system unless drawing succeeded. */
typedef struct rl_plot_buf {
    unsigned char *data;
    size_t size, cap;
    bool failed;                      /* an allocation failed */
} rl_plot_buf;

/* One axis: data range [lo, hi] mapped to pixels [px0, px1] (px1 < px0 for
 * the y axis, whose pixels grow downwards). */
typedef struct rl_plot_axis {
    double lo, hi;
    double px0, px1;
    bool log;
} rl_plot_axis;

typedef struct rl_plot_ticks {
    double v[RL_PLOT_MAX_TICKS];      /* labelled ticks, ascending */
    int n;
    double step;                      /* linear spacing; 0 on log axes */
    double minor[RL_PLOT_MAX_TICKS * 4];
    int n_minor;
} rl_plot_ticks;

/* Occupancy of the plot area on a coarse grid, marked by the data drawing so
 * that the legend can pick the corner it hides least in. */
enum { RL_PLOT_OCC = 48 };

typedef struct rl_plot {
    const char *fn;                   /* public function name, for messages */
    const rl_plot_output *out;
    bool png;
    int width, height;
    cairo_surface_t *surface;
    cairo_t *cr;
    rl_plot_buf svg;
    double font;                      /* tick label size; others derive from it */
    double ax0, ay0, ax1, ay1;        /* plot area in pixels (y down) */
    rl_plot_axis x, y;
    unsigned char occ[RL_PLOT_OCC][RL_PLOT_OCC];
} rl_plot;

/* Categorical series colours (Okabe & Ito 2008, colour-blind safe). */
rl_vec3 rl_plot_series_color(size_t i);

/* Validates out (exactly one target; .svg or .png) and the style's size
 * (default_w x default_h when 0), before any drawing. */
rl_status rl_plot_check(const char *fn, const rl_plot_style *style, const rl_plot_output *out,
                        int default_w, int default_h, int *width, int *height);
/* Creates the surface (white background, DejaVu Sans). */
rl_status rl_plot_begin(rl_plot *p, const char *fn, const rl_plot_output *out, int width,
                        int height);
/* Finishes the surface and delivers the bytes; always releases p. */
rl_status rl_plot_end(rl_plot *p);
/* Releases p without output (after a drawing error). */
void rl_plot_abort(rl_plot *p);

/* Text at (x, y): ha 0/0.5/1 = left/centre/right of x; va 0/0.5/1 = top /
 * middle / baseline-bottom at y (cap-height based, so rows align); angle in
 * radians, counter-clockwise. Returns the text width. */
double rl_plot_text(rl_plot *p, const char *s, double x, double y, double ha, double va,
                    double size, bool bold, double angle);
double rl_plot_text_width(rl_plot *p, const char *s, double size, bool bold);
void rl_plot_set_color(rl_plot *p, rl_vec3 c, double alpha);

/* Axis helpers. */
void rl_plot_axis_range(rl_plot_axis *a, double lo, double hi, bool log, bool pad);
double rl_plot_map(const rl_plot_axis *a, double v);
void rl_plot_compute_ticks(const rl_plot_axis *a, int max_ticks, rl_plot_ticks *t);
/* Tick label for v on an axis with ticks t (Unicode minus, no "-0"). */
void rl_plot_format(double v, const rl_plot_ticks *t, bool log, char *buf, size_t n);

/* Layout: places the plot area inside the canvas, leaving room for the
 * title, axis labels, tick labels (the widest y label measured from yt) and
 * extra_right pixels on the right (colour bar). */
void rl_plot_layout(rl_plot *p, const rl_plot_style *style, const rl_plot_ticks *yt,
                    bool y_log, double extra_right, double extra_bottom);
/* Grid lines, spines, ticks, tick labels, axis labels and title. */
void rl_plot_draw_grid(rl_plot *p, const rl_plot_ticks *xt, const rl_plot_ticks *yt);
void rl_plot_draw_axes(rl_plot *p, const rl_plot_style *style, const rl_plot_ticks *xt,
                       const rl_plot_ticks *yt, bool draw_x_labels);
void rl_plot_draw_title(rl_plot *p, const rl_plot_style *style);

/* Occupancy marks in pixel coordinates. */
void rl_plot_mark_point(rl_plot *p, double x, double y);
void rl_plot_mark_segment(rl_plot *p, double x0, double y0, double x1, double y1);
void rl_plot_mark_rect(rl_plot *p, double x0, double y0, double x1, double y1);

/* Legend in the least occupied corner of the plot area. Entries: a coloured
 * swatch (kind 0 = filled box, 1 = line, 2 = dot, 3 = none) and text. */
typedef struct rl_plot_legend_entry {
    const char *text;
    rl_vec3 color;
    int kind;
    bool dashed;
} rl_plot_legend_entry;
void rl_plot_legend(rl_plot *p, const rl_plot_legend_entry *e, size_t n);

/* Vertical colour bar right of the plot area at x, with ticks and unit. */
void rl_plot_colorbar(rl_plot *p, double x, const char *cmap, bool reverse, double vmin,
                      double vmax, const char *unit);
/* Width the colour bar needs with its labels. */
double rl_plot_colorbar_width(rl_plot *p, double vmin, double vmax, const char *unit);

/* The image's colour layer as a cairo ARGB32 surface (clamped, sRGB encoded,
 * premultiplied); NULL on allocation failure (error recorded). */
cairo_surface_t *rl_plot_image_surface(const rl_image *img);

#endif
