/* plot_heatmap.c: heat map of a 2-D slice of an approximated scene property
 * (Jähn 2015, Sec. 5.6.1, Fig. 5.3b): each region is filled with the colour
 * of its value, optionally over a top view of the scene, with region
 * borders, sample positions and a colour bar.
 *
 * The map keeps equal aspect, so regions look as they lie in the scene.
 * Opaque cells are filled without antialiasing: neighbouring regions then
 * share pixel edges exactly and no background seams show between them (the
 * usual conflation artefact of antialiased abutting fills). Regions without
 * data (NaN) are hatched; the hatch lines follow one global diagonal
 * pattern, so adjacent empty regions read as one area. In contrast to the
 * thesis, which also maps values to height (Fig. 5.3c), the plot is flat. */
#include "rl/rl_plot.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "eval/plot_internal.h"

static const char *FN = "rl_plot_heatmap_draw";

static rl_status validate(const rl_plot_heatmap *h)
{
    if (!h)
        return rl_error(RL_ERR_INVALID_ARG, "%s: heat map is NULL", FN);
    if (!h->cells || h->count == 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: no cells", FN);
    for (size_t i = 0; i < h->count; ++i) {
        const rl_plot_cell *c = &h->cells[i];
        if (!isfinite(c->x0) || !isfinite(c->y0) || !isfinite(c->x1) || !isfinite(c->y1))
            return rl_error(RL_ERR_INVALID_ARG, "%s: cell %zu has a non-finite corner", FN, i);
        if (isinf(c->value))
            return rl_error(RL_ERR_INVALID_ARG, "%s: cell %zu has an infinite value", FN, i);
    }
    double ext[4] = { h->x0, h->y0, h->x1, h->y1 };
    for (int k = 0; k < 4; ++k)
        if (!isfinite(ext[k]))
            return rl_error(RL_ERR_INVALID_ARG, "%s: extent is not finite", FN);
    if (isnan(h->vmin) || isnan(h->vmax) || isinf(h->vmin) || isinf(h->vmax) || h->vmin > h->vmax)
        return rl_error(RL_ERR_INVALID_ARG, "%s: colour range [%g, %g] is invalid", FN, h->vmin, h->vmax);
    if (h->colormap && !rl_plot_colormap_valid(h->colormap))
        return rl_error(RL_ERR_INVALID_ARG, "%s: unknown colour map \"%s\"", FN, h->colormap);
    if (!(h->cell_alpha >= 0.0f && h->cell_alpha <= 1.0f))
        return rl_error(RL_ERR_INVALID_ARG, "%s: cell_alpha %g outside [0, 1]", FN, h->cell_alpha);
    if (h->num_points > 0 && !h->points)
        return rl_error(RL_ERR_INVALID_ARG, "%s: points is NULL", FN);
    for (size_t i = 0; i < 2 * h->num_points; ++i)
        if (!isfinite(h->points[i]))
            return rl_error(RL_ERR_INVALID_ARG, "%s: point %zu is not finite", FN, i / 2);
    if (h->overlay) {
        const rl_image *o = h->overlay;
        if (!(o->layers & RL_LAYER_COLOR) || !o->color || o->width < 1 || o->height < 1)
            return rl_error(RL_ERR_INVALID_ARG, "%s: overlay has no colour layer", FN);
    }
    return RL_OK;
}

typedef struct frame {
    double x0, y0, x1, y1;            /* extent in plot-plane units */
    double vmin, vmax;
    const char *cmap;
} frame;

static void resolve(const rl_plot_heatmap *h, frame *f)
{
    f->cmap = h->colormap ? h->colormap : "viridis";
    if (h->x0 == 0 && h->y0 == 0 && h->x1 == 0 && h->y1 == 0) {
        f->x0 = f->y0 = INFINITY;
        f->x1 = f->y1 = -INFINITY;
        for (size_t i = 0; i < h->count; ++i) {
            const rl_plot_cell *c = &h->cells[i];
            f->x0 = fmin(f->x0, fmin(c->x0, c->x1));
            f->x1 = fmax(f->x1, fmax(c->x0, c->x1));
            f->y0 = fmin(f->y0, fmin(c->y0, c->y1));
            f->y1 = fmax(f->y1, fmax(c->y0, c->y1));
        }
    } else {
        f->x0 = fmin(h->x0, h->x1);
        f->x1 = fmax(h->x0, h->x1);
        f->y0 = fmin(h->y0, h->y1);
        f->y1 = fmax(h->y0, h->y1);
    }
    if (h->vmin < h->vmax) {
        f->vmin = h->vmin;
        f->vmax = h->vmax;
    } else {
        f->vmin = INFINITY;
        f->vmax = -INFINITY;
        for (size_t i = 0; i < h->count; ++i)
            if (!isnan(h->cells[i].value)) {
                f->vmin = fmin(f->vmin, h->cells[i].value);
                f->vmax = fmax(f->vmax, h->cells[i].value);
            }
        if (f->vmin > f->vmax) { /* no data at all */
            f->vmin = 0.0;
            f->vmax = 1.0;
        } else if (f->vmin == f->vmax) {
            double d = fmax(fabs(f->vmin) * 0.1, 0.5);
            f->vmin -= d;
            f->vmax += d;
        }
    }
    /* A diverging map must put its neutral colour on 0. */
    if (strcmp(f->cmap, "coolwarm") == 0 && f->vmin < 0.0 && f->vmax > 0.0) {
        double m = fmax(-f->vmin, f->vmax);
        f->vmin = -m;
        f->vmax = m;
    }
}

static void hatch(rl_plot *p, double x0, double y0, double x1, double y1, bool fill)
{
    cairo_t *cr = p->cr;
    cairo_save(cr);
    cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
    if (fill) {
        cairo_set_source_rgb(cr, 0.94, 0.94, 0.94);
        cairo_fill_preserve(cr);
    }
    cairo_clip(cr);
    double s = 0.55 * p->font;        /* hatch spacing */
    /* Lines x - y = k s: k from the cell's corners, so all cells line up. */
    double k0 = floor((x0 - y1) / s), k1 = ceil((x1 - y0) / s);
    for (double k = k0; k <= k1; k += 1.0) {
        cairo_move_to(cr, k * s + y0, y0);
        cairo_line_to(cr, k * s + y1, y1);
    }
    cairo_set_source_rgba(cr, 0.45, 0.45, 0.45, 0.7);
    cairo_set_line_width(cr, 0.8);
    cairo_stroke(cr);
    cairo_restore(cr);
}

rl_status rl_plot_heatmap_draw(const rl_plot_heatmap *h, const rl_plot_style *style,
                               const rl_plot_output *out)
{
    rl_status st = validate(h);
    if (st != RL_OK)
        return st;
    int width, height;
    st = rl_plot_check(FN, style, out, 640, 420, &width, &height);
    if (st != RL_OK)
        return st;
    frame fr;
    resolve(h, &fr);
    if (!(fr.x1 > fr.x0) || !(fr.y1 > fr.y0))
        return rl_error(RL_ERR_INVALID_ARG, "%s: extent [%g, %g] x [%g, %g] is empty", FN, fr.x0,
                        fr.x1, fr.y0, fr.y1);
    float alpha = h->cell_alpha > 0.0f ? h->cell_alpha : h->overlay ? 0.75f : 1.0f;

    cairo_surface_t *overlay = NULL;
    if (h->overlay && !(overlay = rl_plot_image_surface(h->overlay)))
        return RL_ERR_OUT_OF_MEMORY;
    rl_plot p;
    st = rl_plot_begin(&p, FN, out, width, height);
    if (st != RL_OK) {
        cairo_surface_destroy(overlay);
        return st;
    }
    cairo_t *cr = p.cr;
    double f = p.font;

    /* Layout: ticks on a guessed height first (they set the left margin),
     * then the largest equal-aspect map that fits, centred with its bar. */
    p.x.lo = fr.x0;
    p.x.hi = fr.x1;
    p.y.lo = fr.y0;
    p.y.hi = fr.y1;
    rl_plot_ticks xt, yt;
    rl_plot_compute_ticks(&p.y, (int)fmax(3, (height - 6 * f) / (3.5 * f)), &yt);
    double cbw = rl_plot_colorbar_width(&p, fr.vmin, fr.vmax, h->unit);
    rl_plot_layout(&p, style, &yt, false, cbw, 0.0);
    double aw = p.ax1 - p.ax0, ah = p.ay1 - p.ay0;
    double scale = fmin(aw / (fr.x1 - fr.x0), ah / (fr.y1 - fr.y0));
    double mw = scale * (fr.x1 - fr.x0), mh = scale * (fr.y1 - fr.y0);
    double shift_x = 0.5 * (aw - mw), shift_y = 0.5 * (ah - mh);
    p.ax0 += shift_x;
    p.ax1 = p.ax0 + mw;
    p.ay0 += shift_y;
    p.ay1 = p.ay0 + mh;
    p.x.px0 = p.ax0;
    p.x.px1 = p.ax1;
    p.y.px0 = p.ay1;
    p.y.px1 = p.ay0;
    rl_plot_compute_ticks(&p.x, (int)fmax(3, mw / (6.0 * f)), &xt);
    rl_plot_compute_ticks(&p.y, (int)fmax(3, mh / (3.5 * f)), &yt);

    cairo_save(cr);
    cairo_rectangle(cr, p.ax0, p.ay0, mw, mh);
    cairo_clip(cr);
    if (overlay) {
        /* Stretched over the extent; row 0 is the top (largest y). */
        cairo_save(cr);
        cairo_translate(cr, p.ax0, p.ay0);
        cairo_scale(cr, mw / h->overlay->width, mh / h->overlay->height);
        cairo_set_source_surface(cr, overlay, 0, 0);
        cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_GOOD);
        cairo_pattern_set_extend(cairo_get_source(cr), CAIRO_EXTEND_PAD);
        cairo_paint(cr);
        cairo_restore(cr);
    }
    cairo_antialias_t aa = alpha >= 1.0f ? CAIRO_ANTIALIAS_NONE : CAIRO_ANTIALIAS_DEFAULT;
    for (size_t i = 0; i < h->count; ++i) {
        const rl_plot_cell *c = &h->cells[i];
        double x0 = rl_plot_map(&p.x, fmin(c->x0, c->x1)), x1 = rl_plot_map(&p.x, fmax(c->x0, c->x1));
        double y0 = rl_plot_map(&p.y, fmax(c->y0, c->y1)), y1 = rl_plot_map(&p.y, fmin(c->y0, c->y1));
        if (isnan(c->value)) {
            hatch(&p, x0, y0, x1, y1, !overlay);
            continue;
        }
        double t = (c->value - fr.vmin) / (fr.vmax - fr.vmin);
        rl_vec3 col = rl_plot_colormap(fr.cmap, h->reverse ? 1.0 - t : t);
        cairo_set_antialias(cr, aa);
        cairo_rectangle(cr, x0, y0, x1 - x0, y1 - y0);
        rl_plot_set_color(&p, col, alpha);
        cairo_fill(cr);
        cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
    }
    if (h->borders) {
        cairo_set_line_width(cr, fmax(0.5, 0.05 * f));
        cairo_set_source_rgba(cr, 0.1, 0.1, 0.1, 0.45);
        for (size_t i = 0; i < h->count; ++i) {
            const rl_plot_cell *c = &h->cells[i];
            double x0 = rl_plot_map(&p.x, c->x0), x1 = rl_plot_map(&p.x, c->x1);
            double y0 = rl_plot_map(&p.y, c->y0), y1 = rl_plot_map(&p.y, c->y1);
            cairo_rectangle(cr, x0, y1, x1 - x0, y0 - y1);
        }
        cairo_stroke(cr);
    }
    if (h->num_points > 0) {
        /* Dark dots with a light rim read on every colour of the map. */
        double r = fmax(1.2, 0.16 * f);
        for (size_t i = 0; i < h->num_points; ++i) {
            double x = rl_plot_map(&p.x, h->points[2 * i]), y = rl_plot_map(&p.y, h->points[2 * i + 1]);
            cairo_new_sub_path(cr);
            cairo_arc(cr, x, y, r, 0, 2 * RL_PI);
        }
        cairo_set_source_rgb(cr, 0.08, 0.08, 0.08);
        cairo_fill_preserve(cr);
        cairo_set_source_rgba(cr, 1, 1, 1, 0.9);
        cairo_set_line_width(cr, 0.6);
        cairo_stroke(cr);
    }
    cairo_restore(cr);

    /* A full thin frame: the map is an image, not a chart with data ink. */
    cairo_set_line_width(cr, 1.0);
    cairo_set_source_rgb(cr, 0.3, 0.3, 0.3);
    cairo_rectangle(cr, floor(p.ax0) + 0.5, floor(p.ay0) + 0.5, floor(p.ax1) - floor(p.ax0),
                    floor(p.ay1) - floor(p.ay0));
    cairo_stroke(cr);
    rl_plot_draw_axes(&p, style, &xt, &yt, true);
    rl_plot_draw_title(&p, style);
    rl_plot_colorbar(&p, p.ax1, fr.cmap, h->reverse, fr.vmin, fr.vmax, h->unit);
    cairo_surface_destroy(overlay);
    return rl_plot_end(&p);
}
