/* plot_violin.c: violin plots and histograms of weighted series (Jähn 2015,
 * Sec. 5.6.2, Fig. 5.3f).
 *
 * Sec. 5.6.2 advises against box plots alone, since the distribution of a
 * scene property over a region often has several modes; a violin (Hintze &
 * Nelson 1998, "Violin plots: a box plot-density trace synergism") shows
 * them, and the box inside keeps the quartiles readable. Values are weighted
 * by region area or volume throughout (rl_stats.h).
 *
 * Violins are cut at the data's minimum and maximum (no density is drawn
 * where no region lies; a property such as an error cannot be negative) and
 * each is scaled to the same maximum width, so shapes compare across series
 * while areas do not. Histograms bin all series over one common range, with
 * Freedman & Diaconis 1981 bin widths, h = 2 IQR n^(-1/3), n again Kish's
 * effective sample size. */
#include "rl/rl_plot.h"
#include "rl/rl_stats.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/plot_internal.h"

enum {
    KDE_POINTS = 200,      /* density samples per violin */
    MAX_SERIES = 64,
    MAX_BINS = 1000
};

static rl_status validate_series(const char *fn, const rl_plot_series *series, size_t n,
                                 rl_stats *stats)
{
    if (!series || n == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no series", fn);
    if (n > MAX_SERIES)
        return rl_error(RL_ERR_INVALID_ARG, "%s: %zu series, at most %d", fn, n, MAX_SERIES);
    for (size_t i = 0; i < n; ++i) {
        if (!series[i].values || series[i].count == 0)
            return rl_error(RL_ERR_INVALID_ARG, "%s: series %zu is empty", fn, i);
        rl_status st = rl_stats_compute(series[i].values, series[i].weights, series[i].count, &stats[i]);
        if (st != RL_OK)
            return rl_error(st, "%s: series %zu: %s", fn, i, rl_last_error());
    }
    return RL_OK;
}

static void series_name(const rl_plot_series *s, size_t i, char *buf, size_t n)
{
    if (s->name)
        snprintf(buf, n, "%s", s->name);
    else
        snprintf(buf, n, "series %zu", i + 1);
}

/* ---- violin ------------------------------------------------------------ */

typedef struct violin {
    double xs[KDE_POINTS], d[KDE_POINTS];
    double dmax;
    double q05, q25, q50, q75, q95;
} violin;

static rl_status compute_violin(const rl_plot_series *s, const rl_stats *st, violin *v)
{
    static const double qs[5] = { 0.05, 0.25, 0.5, 0.75, 0.95 };
    double q[5];
    rl_status r = rl_stats_quantiles(s->values, s->weights, s->count, qs, 5, q);
    if (r != RL_OK)
        return r;
    v->q05 = q[0];
    v->q25 = q[1];
    v->q50 = q[2];
    v->q75 = q[3];
    v->q95 = q[4];
    v->dmax = 0.0;
    if (!(st->max > st->min))
        return RL_OK;
    for (int i = 0; i < KDE_POINTS; ++i)
        v->xs[i] = st->min + (st->max - st->min) * i / (KDE_POINTS - 1);
    r = rl_stats_kde(s->values, s->weights, s->count, 0.0, v->xs, KDE_POINTS, v->d, NULL);
    if (r != RL_OK)
        return r;
    for (int i = 0; i < KDE_POINTS; ++i)
        v->dmax = fmax(v->dmax, v->d[i]);
    return RL_OK;
}

static const rl_vec3 BOX = { 0.22f, 0.22f, 0.22f };

rl_status rl_plot_violin(const rl_plot_series *series, size_t n, const rl_plot_style *style,
                         const rl_plot_output *out)
{
    const char *fn = "rl_plot_violin";
    rl_stats stats[MAX_SERIES];
    rl_status st = validate_series(fn, series, n, stats);
    if (st != RL_OK)
        return st;
    int width, height;
    st = rl_plot_check(fn, style, out, 640, 420, &width, &height);
    if (st != RL_OK)
        return st;
    violin *v = rl_calloc(n, sizeof *v);
    if (!v)
        return RL_ERR_OUT_OF_MEMORY;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < n && st == RL_OK; ++i) {
        st = compute_violin(&series[i], &stats[i], &v[i]);
        lo = fmin(lo, stats[i].min);
        hi = fmax(hi, stats[i].max);
    }
    rl_plot p;
    if (st == RL_OK)
        st = rl_plot_begin(&p, fn, out, width, height);
    if (st != RL_OK) {
        free(v);
        return st;
    }
    cairo_t *cr = p.cr;
    double f = p.font;

    /* Names under the violins; tilted when they would collide. */
    char name[256];
    double name_w = 0.0;
    for (size_t i = 0; i < n; ++i) {
        series_name(&series[i], i, name, sizeof name);
        name_w = fmax(name_w, rl_plot_text_width(&p, name, f, false));
    }
    double slot_guess = (width - 8.0 * f) / (double)n;
    bool tilt = name_w > 0.92 * slot_guess;
    double tilt_angle = RL_PI / 6;
    double extra_bottom = tilt ? name_w * sin(tilt_angle) : 0.0;

    rl_plot_axis_range(&p.y, lo, hi, false, true);
    rl_plot_ticks yt;
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (height - 6 * f) / (3.5 * f)), &yt);
    rl_plot_layout(&p, style, &yt, false, 0.0, extra_bottom);
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (p.ay1 - p.ay0) / (3.5 * f)), &yt);
    p.x.lo = 0.0;
    p.x.hi = (double)n;
    rl_plot_draw_grid(&p, NULL, &yt);

    double slot = (p.ax1 - p.ax0) / (double)n;
    double half = 0.42 * slot;
    double box_w = fmin(0.09 * slot, 1.0 * f);
    for (size_t i = 0; i < n; ++i) {
        const violin *vi = &v[i];
        double cx = rl_plot_map(&p.x, (double)i + 0.5);
        rl_vec3 col = rl_plot_series_color(i);
        if (vi->dmax > 0.0) {
            cairo_move_to(cr, cx, rl_plot_map(&p.y, vi->xs[0]));
            for (int k = 0; k < KDE_POINTS; ++k)
                cairo_line_to(cr, cx + half * vi->d[k] / vi->dmax, rl_plot_map(&p.y, vi->xs[k]));
            for (int k = KDE_POINTS - 1; k >= 0; --k)
                cairo_line_to(cr, cx - half * vi->d[k] / vi->dmax, rl_plot_map(&p.y, vi->xs[k]));
            cairo_close_path(cr);
            rl_plot_set_color(&p, col, 0.28);
            cairo_fill_preserve(cr);
            rl_plot_set_color(&p, col, 1.0);
            cairo_set_line_width(cr, 1.3);
            cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
            cairo_stroke(cr);
        } else {
            /* Constant data: a density is a spike; draw a flat bar. */
            double y = rl_plot_map(&p.y, stats[i].min);
            rl_plot_set_color(&p, col, 1.0);
            cairo_set_line_width(cr, 2.0);
            cairo_move_to(cr, cx - half, y);
            cairo_line_to(cr, cx + half, y);
            cairo_stroke(cr);
        }
        /* Whiskers at the 5 % and 95 % quantiles, the box at the quartiles. */
        rl_plot_set_color(&p, BOX, 1.0);
        cairo_set_line_width(cr, fmax(1.2, 0.12 * f));
        cairo_move_to(cr, cx, rl_plot_map(&p.y, vi->q05));
        cairo_line_to(cr, cx, rl_plot_map(&p.y, vi->q95));
        cairo_stroke(cr);
        double yb = rl_plot_map(&p.y, vi->q25), yt_ = rl_plot_map(&p.y, vi->q75);
        cairo_rectangle(cr, cx - 0.5 * box_w, yt_, box_w, fmax(1.0, yb - yt_));
        cairo_fill(cr);
        /* Median: white mark across the box; mean: white dot, dark rim. */
        double ym = rl_plot_map(&p.y, vi->q50);
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_set_line_width(cr, fmax(1.5, 0.18 * f));
        cairo_move_to(cr, cx - 0.5 * box_w, ym);
        cairo_line_to(cr, cx + 0.5 * box_w, ym);
        cairo_stroke(cr);
        cairo_arc(cr, cx, rl_plot_map(&p.y, stats[i].mean), fmax(2.0, 0.26 * f), 0, 2 * RL_PI);
        cairo_set_source_rgb(cr, 1, 1, 1);
        cairo_fill_preserve(cr);
        rl_plot_set_color(&p, BOX, 1.0);
        cairo_set_line_width(cr, 1.0);
        cairo_stroke(cr);
    }
    /* The axis helper would put the x label where the names go. */
    rl_plot_style sty = style ? *style : (rl_plot_style){ 0 };
    sty.x_label = NULL;
    rl_plot_draw_axes(&p, &sty, NULL, &yt, false);
    /* Bottom spine and the series names as category labels. */
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    cairo_set_line_width(cr, 1.0);
    cairo_move_to(cr, p.ax0, floor(p.ay1) + 0.5);
    cairo_line_to(cr, p.ax1, floor(p.ay1) + 0.5);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0.15, 0.15, 0.15);
    for (size_t i = 0; i < n; ++i) {
        series_name(&series[i], i, name, sizeof name);
        double cx = rl_plot_map(&p.x, (double)i + 0.5);
        if (tilt)
            rl_plot_text(&p, name, cx + 0.3 * f, p.ay1 + 0.9 * f, 1.0, 0.0, f, false, tilt_angle);
        else
            rl_plot_text(&p, name, cx, p.ay1 + 0.9 * f, 0.5, 0.0, f, false, 0.0);
    }
    if (style && style->x_label)
        rl_plot_text(&p, style->x_label, 0.5 * (p.ax0 + p.ax1), p.ay1 + 2.8 * f + extra_bottom, 0.5,
                     0.0, 1.1 * f, false, 0.0);
    rl_plot_draw_title(&p, style);
    free(v);
    return rl_plot_end(&p);
}

/* ---- histogram --------------------------------------------------------- */

/* Freedman-Diaconis width of one series; 0 when its IQR is 0. */
static double fd_width(const rl_plot_series *s, const rl_stats *st)
{
    double sw = 0.0, sw2 = 0.0;
    for (size_t i = 0; i < s->count; ++i) {
        double w = s->weights ? s->weights[i] : 1.0;
        sw += w;
        sw2 += w * w;
    }
    double n_eff = sw * sw / sw2;
    return 2.0 * (st->q[3] - st->q[1]) * pow(n_eff, -1.0 / 3.0);
}

rl_status rl_plot_histogram(const rl_plot_series *series, size_t n, int bins,
                            const rl_plot_style *style, const rl_plot_output *out)
{
    const char *fn = "rl_plot_histogram";
    rl_stats stats[MAX_SERIES];
    rl_status st = validate_series(fn, series, n, stats);
    if (st != RL_OK)
        return st;
    if (bins < 0 || bins > MAX_BINS)
        return rl_error(RL_ERR_INVALID_ARG, "%s: bins %d outside 0..%d", fn, bins, MAX_BINS);
    int width, height;
    st = rl_plot_check(fn, style, out, 640, 420, &width, &height);
    if (st != RL_OK)
        return st;
    double lo = INFINITY, hi = -INFINITY, h_fd = INFINITY, count = 0.0;
    for (size_t i = 0; i < n; ++i) {
        lo = fmin(lo, stats[i].min);
        hi = fmax(hi, stats[i].max);
        double w = fd_width(&series[i], &stats[i]);
        if (w > 0.0)
            h_fd = fmin(h_fd, w);
        count += (double)stats[i].count;
    }
    if (!(hi > lo)) {
        double d = fmax(fabs(lo) * 0.1, 0.5);
        lo -= d;
        hi += d;
    }
    if (bins == 0) {
        double b = isfinite(h_fd) ? ceil((hi - lo) / h_fd) : ceil(sqrt(count));
        bins = (int)fmax(5.0, fmin(100.0, b));
    }
    double *share = rl_calloc((size_t)bins * n, sizeof *share);
    if (!share)
        return RL_ERR_OUT_OF_MEMORY;
    double top = 0.0;
    for (size_t s = 0; s < n; ++s) {
        double *h = share + s * (size_t)bins;
        for (size_t i = 0; i < series[s].count; ++i) {
            double w = series[s].weights ? series[s].weights[i] : 1.0;
            int b = (int)floor((series[s].values[i] - lo) / (hi - lo) * bins);
            b = b < 0 ? 0 : b >= bins ? bins - 1 : b; /* max falls in the last bin */
            h[b] += w / stats[s].total_weight;
        }
        for (int b = 0; b < bins; ++b)
            top = fmax(top, h[b]);
    }
    rl_plot p;
    st = rl_plot_begin(&p, fn, out, width, height);
    if (st != RL_OK) {
        free(share);
        return st;
    }
    cairo_t *cr = p.cr;
    double f = p.font;
    rl_plot_style sty = style ? *style : (rl_plot_style){ 0 };
    if (!sty.y_label)
        sty.y_label = "share of weight";
    rl_plot_axis_range(&p.x, lo, hi, false, true);
    p.y.lo = 0.0;
    p.y.hi = top * 1.08;
    rl_plot_ticks xt, yt;
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (height - 6 * f) / (3.5 * f)), &yt);
    rl_plot_layout(&p, &sty, &yt, false, 0.0, 0.0);
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (p.ay1 - p.ay0) / (3.5 * f)), &yt);
    rl_plot_compute_ticks(&p.x, (int)fmax(3, (p.ax1 - p.ax0) / (6.0 * f)), &xt);
    rl_plot_draw_grid(&p, NULL, &yt);
    double base = rl_plot_map(&p.y, 0.0);
    for (size_t s = 0; s < n; ++s) {
        const double *h = share + s * (size_t)bins;
        rl_vec3 col = rl_plot_series_color(s);
        /* One outline per series (a step line), lightly filled beneath, so
         * overlapping series stay distinguishable. */
        cairo_move_to(cr, rl_plot_map(&p.x, lo), base);
        for (int b = 0; b < bins; ++b) {
            double x0 = rl_plot_map(&p.x, lo + (hi - lo) * b / bins);
            double x1 = rl_plot_map(&p.x, lo + (hi - lo) * (b + 1) / bins);
            double y = rl_plot_map(&p.y, h[b]);
            cairo_line_to(cr, x0, y);
            cairo_line_to(cr, x1, y);
            if (h[b] > 0.0)
                rl_plot_mark_rect(&p, x0, y, x1, base);
        }
        cairo_line_to(cr, rl_plot_map(&p.x, hi), base);
        rl_plot_set_color(&p, col, n > 1 ? 0.16 : 0.3);
        cairo_fill_preserve(cr);
        rl_plot_set_color(&p, col, 1.0);
        cairo_set_line_width(cr, 1.5);
        cairo_set_line_join(cr, CAIRO_LINE_JOIN_MITER);
        cairo_stroke(cr);
    }
    rl_plot_draw_axes(&p, &sty, &xt, &yt, true);
    rl_plot_draw_title(&p, &sty);
    if (n > 1 || series[0].name) {
        rl_plot_legend_entry e[MAX_SERIES];
        char names[MAX_SERIES][128];
        for (size_t s = 0; s < n; ++s) {
            series_name(&series[s], s, names[s], sizeof names[s]);
            e[s] = (rl_plot_legend_entry){ .text = names[s], .color = rl_plot_series_color(s), .kind = 0 };
        }
        rl_plot_legend(&p, e, n);
    }
    free(share);
    return rl_plot_end(&p);
}
