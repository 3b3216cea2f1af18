/* plot_lines.c: correlation plots, line plots and plain images (rl_plot.h).
 *
 * The correlation plot compares measured with approximated values at the
 * same positions, as in the evaluation of the sampling methods (Jähn 2015,
 * Sec. 5.7: 2000 random positions, the absolute difference is the error);
 * both axes share one range and one scale, so the line y = x is the
 * diagonal and distance from it is the error. Line plots draw convergence
 * curves, on logarithmic axes where asked. */
#include "rl/rl_plot.h"
#include "rl/rl_stats.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/plot_internal.h"
#include "eval/stats_internal.h"

enum { MAX_SERIES = 64, MARKERS_UP_TO = 40 };

/* ---- correlation ------------------------------------------------------- */

rl_status rl_plot_correlation(const double *measured, const double *approximated, size_t n,
                              const rl_plot_style *style, const rl_plot_output *out)
{
    const char *fn = "rl_plot_correlation";
    if (!measured || !approximated || n == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no data", fn);
    double lo = INFINITY, hi = -INFINITY, err_sum = 0.0, err_max = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!isfinite(measured[i]) || !isfinite(approximated[i]))
            return rl_error(RL_ERR_INVALID_ARG, "%s: pair %zu is not finite", fn, i);
        lo = fmin(lo, fmin(measured[i], approximated[i]));
        hi = fmax(hi, fmax(measured[i], approximated[i]));
        double e = fabs(approximated[i] - measured[i]);
        err_sum += e;
        err_max = fmax(err_max, e);
    }
    int width, height;
    rl_status st = rl_plot_check(fn, style, out, 640, 420, &width, &height);
    if (st != RL_OK)
        return st;
    /* Undefined for constant data; the plot still shows the points. Asked
     * without recording an error, so that none of the caller's is erased. */
    double r = NAN;
    if (n >= 2 && rl_stats_pearson(measured, approximated, n, &r) != 0)
        r = NAN;
    rl_plot p;
    st = rl_plot_begin(&p, fn, out, width, height);
    if (st != RL_OK)
        return st;
    cairo_t *cr = p.cr;
    double f = p.font;
    rl_plot_style sty = style ? *style : (rl_plot_style){ 0 };
    if (!sty.x_label)
        sty.x_label = "measured";
    if (!sty.y_label)
        sty.y_label = "approximated";
    rl_plot_axis_range(&p.x, lo, hi, false, true);
    p.y = p.x;
    rl_plot_ticks xt, yt;
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (height - 6 * f) / (3.5 * f)), &yt);
    rl_plot_layout(&p, &sty, &yt, false, 0.0, 0.0);
    /* Square plot area, centred: one unit is as long on both axes. */
    double side = fmin(p.ax1 - p.ax0, p.ay1 - p.ay0);
    p.ax0 += 0.5 * (p.ax1 - p.ax0 - side);
    p.ax1 = p.ax0 + side;
    p.ay1 = p.ay0 + side;
    p.x.px0 = p.ax0;
    p.x.px1 = p.ax1;
    p.y.px0 = p.ay1;
    p.y.px1 = p.ay0;
    int nt = (int)fmax(3, side / (4.5 * f));
    rl_plot_compute_ticks(&p.x, nt, &xt);
    rl_plot_compute_ticks(&p.y, nt, &yt);
    rl_plot_draw_grid(&p, &xt, &yt);

    cairo_save(cr);
    cairo_rectangle(cr, p.ax0, p.ay0, p.ax1 - p.ax0, p.ay1 - p.ay0);
    cairo_clip(cr);
    double d[2] = { 5.0, 4.0 };
    cairo_set_dash(cr, d, 2, 0.0);
    cairo_set_source_rgb(cr, 0.45, 0.45, 0.45);
    cairo_set_line_width(cr, 1.2);
    cairo_move_to(cr, rl_plot_map(&p.x, p.x.lo), rl_plot_map(&p.y, p.y.lo));
    cairo_line_to(cr, rl_plot_map(&p.x, p.x.hi), rl_plot_map(&p.y, p.y.hi));
    cairo_stroke(cr);
    cairo_set_dash(cr, NULL, 0, 0.0);
    rl_plot_mark_segment(&p, p.ax0, p.ay1, p.ax1, p.ay0);
    /* Many points: smaller and fainter, so that density stays visible. */
    double alpha = n <= 200 ? 0.75 : fmax(0.12, 0.75 * sqrt(200.0 / (double)n));
    double rad = n <= 500 ? 0.27 * f : 0.19 * f;
    rl_vec3 col = rl_plot_series_color(0);
    rl_plot_set_color(&p, col, alpha);
    for (size_t i = 0; i < n; ++i) {
        double x = rl_plot_map(&p.x, measured[i]), y = rl_plot_map(&p.y, approximated[i]);
        cairo_new_sub_path(cr);
        cairo_arc(cr, x, y, rad, 0, 2 * RL_PI);
        /* One fill per point: overlapping dots must add up in density. */
        cairo_fill(cr);
        rl_plot_mark_point(&p, x, y);
    }
    cairo_restore(cr);
    rl_plot_draw_axes(&p, &sty, &xt, &yt, true);
    rl_plot_draw_title(&p, &sty);

    char l0[64], l2[64], l3[64], l4[64];
    snprintf(l0, sizeof l0, "samples (n = %zu)", n);
    if (isnan(r))
        snprintf(l2, sizeof l2, "Pearson r: undefined");
    else
        snprintf(l2, sizeof l2, "Pearson r = %.4f", r);
    snprintf(l3, sizeof l3, "mean |error| = %.4g", err_sum / (double)n);
    snprintf(l4, sizeof l4, "max |error| = %.4g", err_max);
    rl_plot_legend_entry e[] = {
        { .text = l0, .color = col, .kind = 2 },
        { .text = "y = x", .color = { 0.45f, 0.45f, 0.45f }, .kind = 1, .dashed = true },
        { .text = l2, .kind = 3 },
        { .text = l3, .kind = 3 },
        { .text = l4, .kind = 3 },
    };
    rl_plot_legend(&p, e, sizeof e / sizeof e[0]);
    return rl_plot_end(&p);
}

/* ---- lines ------------------------------------------------------------- */

rl_status rl_plot_lines_draw(const rl_plot_lines *lines, const rl_plot_style *style,
                             const rl_plot_output *out)
{
    const char *fn = "rl_plot_lines_draw";
    if (!lines || !lines->xs || lines->count == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no x values", fn);
    if (!lines->series || lines->num_series == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no series", fn);
    if (lines->num_series > MAX_SERIES)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %zu series, at most %d", fn, lines->num_series, MAX_SERIES);
    size_t n = lines->count;
    double xlo = INFINITY, xhi = -INFINITY, ylo = INFINITY, yhi = -INFINITY;
    for (size_t i = 0; i < n; ++i) {
        double x = lines->xs[i];
        if (!isfinite(x) || (lines->log_x && !(x > 0.0)))
            return rl_error(RL_ERR_INVALID_ARG, "%s: x[%zu] = %g is not %s", fn, i, x,
                            lines->log_x ? "positive" : "finite");
        xlo = fmin(xlo, x);
        xhi = fmax(xhi, x);
    }
    for (size_t s = 0; s < lines->num_series; ++s) {
        const rl_plot_series *se = &lines->series[s];
        if (!se->values || se->count != n)
            return rl_error(RL_ERR_INVALID_ARG, "%s: series %zu has %zu values, expected %zu", fn, s,
                            se->values ? se->count : 0, n);
        for (size_t i = 0; i < n; ++i) {
            double y = se->values[i];
            if (!isfinite(y) || (lines->log_y && !(y > 0.0)))
                return rl_error(RL_ERR_INVALID_ARG, "%s: series %zu value %zu = %g is not %s", fn, s,
                                i, y, lines->log_y ? "positive" : "finite");
            ylo = fmin(ylo, y);
            yhi = fmax(yhi, y);
        }
    }
    int width, height;
    rl_status st = rl_plot_check(fn, style, out, 640, 420, &width, &height);
    if (st != RL_OK)
        return st;
    rl_plot p;
    st = rl_plot_begin(&p, fn, out, width, height);
    if (st != RL_OK)
        return st;
    cairo_t *cr = p.cr;
    double f = p.font;
    rl_plot_axis_range(&p.x, xlo, xhi, lines->log_x, true);
    rl_plot_axis_range(&p.y, ylo, yhi, lines->log_y, true);
    rl_plot_ticks xt, yt;
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (height - 6 * f) / (3.5 * f)), &yt);
    rl_plot_layout(&p, style, &yt, lines->log_y, 0.0, 0.0);
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (p.ay1 - p.ay0) / (3.5 * f)), &yt);
    rl_plot_compute_ticks(&p.x, (int)fmax(3, (p.ax1 - p.ax0) / (6.0 * f)), &xt);
    rl_plot_draw_grid(&p, &xt, &yt);
    cairo_save(cr);
    cairo_rectangle(cr, p.ax0 - 0.5 * f, p.ay0 - 0.5 * f, p.ax1 - p.ax0 + f, p.ay1 - p.ay0 + f);
    cairo_clip(cr);
    cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
    for (size_t s = 0; s < lines->num_series; ++s) {
        const double *y = lines->series[s].values;
        rl_vec3 col = rl_plot_series_color(s);
        for (size_t i = 0; i < n; ++i) {
            double px = rl_plot_map(&p.x, lines->xs[i]), py = rl_plot_map(&p.y, y[i]);
            if (i == 0)
                cairo_move_to(cr, px, py);
            else
                cairo_line_to(cr, px, py);
            if (i > 0)
                rl_plot_mark_segment(&p, rl_plot_map(&p.x, lines->xs[i - 1]),
                                     rl_plot_map(&p.y, y[i - 1]), px, py);
            else
                rl_plot_mark_point(&p, px, py);
        }
        rl_plot_set_color(&p, col, 1.0);
        cairo_set_line_width(cr, fmax(1.5, 0.17 * f));
        cairo_stroke(cr);
        if (n <= MARKERS_UP_TO) {
            for (size_t i = 0; i < n; ++i) {
                cairo_new_sub_path(cr);
                cairo_arc(cr, rl_plot_map(&p.x, lines->xs[i]), rl_plot_map(&p.y, y[i]),
                          fmax(2.2, 0.27 * f), 0, 2 * RL_PI);
            }
            cairo_fill_preserve(cr);
            cairo_set_source_rgb(cr, 1, 1, 1);
            cairo_set_line_width(cr, 0.9);
            cairo_stroke(cr);
        }
    }
    cairo_restore(cr);
    rl_plot_draw_axes(&p, style, &xt, &yt, true);
    rl_plot_draw_title(&p, style);
    if (lines->num_series > 1 || lines->series[0].name) {
        rl_plot_legend_entry e[MAX_SERIES];
        char names[MAX_SERIES][128];
        for (size_t s = 0; s < lines->num_series; ++s) {
            if (lines->series[s].name)
                snprintf(names[s], sizeof names[s], "%s", lines->series[s].name);
            else
                snprintf(names[s], sizeof names[s], "series %zu", s + 1);
            e[s] = (rl_plot_legend_entry){ .text = names[s], .color = rl_plot_series_color(s), .kind = 1 };
        }
        rl_plot_legend(&p, e, lines->num_series);
    }
    return rl_plot_end(&p);
}

/* ---- image ------------------------------------------------------------- */

rl_status rl_plot_image(const rl_image *image, const rl_plot_style *style, const rl_plot_output *out)
{
    const char *fn = "rl_plot_image";
    if (!image || !(image->layers & RL_LAYER_COLOR) || !image->color || image->width < 1 ||
        image->height < 1)
        return rl_error(RL_ERR_INVALID_ARG, "%s: image is NULL or has no colour layer", fn);
    /* Size 0 keeps the image's size; one side given keeps its aspect. */
    rl_plot_style sty = style ? *style : (rl_plot_style){ 0 };
    if (sty.width == 0 && sty.height == 0) {
        sty.width = image->width;
        sty.height = image->height;
    } else if (sty.width == 0) {
        sty.width = (int)lround((double)sty.height * image->width / image->height);
    } else if (sty.height == 0) {
        sty.height = (int)lround((double)sty.width * image->height / image->width);
    }
    int width, height;
    rl_status st = rl_plot_check(fn, &sty, out, image->width, image->height, &width, &height);
    if (st != RL_OK)
        return st;
    cairo_surface_t *img = rl_plot_image_surface(image);
    if (!img)
        return RL_ERR_OUT_OF_MEMORY;
    rl_plot p;
    st = rl_plot_begin(&p, fn, out, width, height);
    if (st != RL_OK) {
        cairo_surface_destroy(img);
        return st;
    }
    cairo_t *cr = p.cr;
    double f = p.font;
    /* A title and a caption (x_label) take room above and below. */
    double top = sty.title ? 2.6 * f : 0.0;
    double bottom = sty.x_label ? 2.2 * f : 0.0;
    double aw = width, ah = fmax(1.0, height - top - bottom);
    double s = fmin(aw / image->width, ah / image->height);
    double w = s * image->width, h = s * image->height;
    double x0 = 0.5 * (aw - w), y0 = top + 0.5 * (ah - h);
    cairo_save(cr);
    cairo_rectangle(cr, x0, y0, w, h);
    cairo_clip(cr);
    cairo_translate(cr, x0, y0);
    cairo_scale(cr, s, s);
    cairo_set_source_surface(cr, img, 0, 0);
    /* Magnified renders keep their pixels; reduced ones are filtered. */
    cairo_pattern_set_filter(cairo_get_source(cr), s >= 2.0 ? CAIRO_FILTER_NEAREST : CAIRO_FILTER_GOOD);
    cairo_pattern_set_extend(cairo_get_source(cr), CAIRO_EXTEND_PAD);
    cairo_paint(cr);
    cairo_restore(cr);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    if (sty.title)
        rl_plot_text(&p, sty.title, 0.5 * width, 0.8 * f, 0.5, 0.0, 1.3 * f, true, 0.0);
    if (sty.x_label)
        rl_plot_text(&p, sty.x_label, 0.5 * width, y0 + h + 0.7 * f, 0.5, 0.0, 1.1 * f, false, 0.0);
    cairo_surface_destroy(img);
    return rl_plot_end(&p);
}
