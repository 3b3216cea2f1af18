/* plot.c: what every plot shares (plot_internal.h): output, canvas, axes,
 * ticks, labels, legend and colour bar, drawn with cairo.
 *
 * Everything is first drawn into memory: SVG through cairo's stream surface
 * into a growing buffer, PNG through cairo_surface_write_to_png_stream. Only
 * then is a file opened, so a failed plot leaves nothing behind (rl_plot.h),
 * and a failed write removes its partial file.
 *
 * SVG kept in memory is meant to be inlined into an HTML report, where every
 * plot shares one id namespace. cairo names its glyph symbols and clip paths
 * "glyph0-1", "clip1" in every file, so two inlined plots would borrow each
 * other's glyphs; the ids are therefore prefixed with a hash of the plot's
 * own text, and the XML declaration, which HTML does not want, is dropped.
 *
 * Style: spines left and bottom only, outward ticks, light grid lines at the
 * major ticks, tick values at 1-2-5 steps (Heckbert 1990, "Nice numbers for
 * graph labels", Graphics Gems I), DejaVu Sans sized with the canvas. */
#include "eval/plot_internal.h"

#include <cairo-svg.h>
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "rl/rl_output.h"
#include "rl/rl_path.h"

#define FONT_FAMILY "DejaVu Sans"
#define CAP_HEIGHT 0.73      /* DejaVu Sans cap height in em */
#define MINUS "\xe2\x88\x92" /* U+2212: typographic minus, as in print */

/* ---- series colours ---------------------------------------------------- */

rl_vec3 rl_plot_series_color(size_t i)
{
    /* Okabe & Ito 2008, "Color Universal Design": distinguishable under all
     * common colour-vision deficiencies; yellow last, it is faint on white. */
    static const unsigned hex[] = { 0x0072B2, 0xD55E00, 0x009E73, 0xE69F00,
                                    0xCC79A7, 0x56B4E9, 0x555555, 0xF0E442 };
    unsigned c = hex[i % (sizeof hex / sizeof hex[0])];
    return rl_v3((c >> 16 & 0xff) / 255.0f, (c >> 8 & 0xff) / 255.0f, (c & 0xff) / 255.0f);
}

/* ---- output ------------------------------------------------------------ */

static bool buf_append(rl_plot_buf *b, const void *data, size_t n)
{
    if (b->failed)
        return false;
    if (b->size + n + 1 > b->cap) {
        size_t cap = b->cap ? b->cap : 1 << 16;
        while (cap < b->size + n + 1)
            cap *= 2;
        unsigned char *d = rl_realloc_array(b->data, cap, 1);
        if (!d) {
            b->failed = true;
            return false;
        }
        b->data = d;
        b->cap = cap;
    }
    memcpy(b->data + b->size, data, n);
    b->size += n;
    b->data[b->size] = '\0';
    return true;
}

static cairo_status_t on_write(void *closure, const unsigned char *data, unsigned int length)
{
    return buf_append(closure, data, length) ? CAIRO_STATUS_SUCCESS : CAIRO_STATUS_WRITE_ERROR;
}

rl_status rl_plot_check(const char *fn, const rl_plot_style *style, const rl_plot_output *out,
                        int default_w, int default_h, int *width, int *height)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "%s: output is NULL", fn);
    if ((out->path != NULL) == (out->svg != NULL))
        return rl_error(RL_ERR_INVALID_ARG, "%s: give exactly one of output path and svg", fn);
    if (out->path && !rl_path_has_ext(out->path, ".svg") && !rl_path_has_ext(out->path, ".png"))
        return rl_error(RL_ERR_INVALID_ARG, "%s: %s: extension must be .svg or .png", fn, out->path);
    int w = style && style->width ? style->width : default_w;
    int h = style && style->height ? style->height : default_h;
    if (w < RL_PLOT_MIN_SIZE || w > RL_PLOT_MAX_SIZE || h < RL_PLOT_MIN_SIZE || h > RL_PLOT_MAX_SIZE)
        return rl_error(RL_ERR_INVALID_ARG, "%s: size %dx%d outside %d..%d", fn, w, h,
                        RL_PLOT_MIN_SIZE, RL_PLOT_MAX_SIZE);
    *width = w;
    *height = h;
    return RL_OK;
}

static rl_status cairo_failure(const char *fn, cairo_status_t s, const rl_plot_buf *b)
{
    if (s == CAIRO_STATUS_NO_MEMORY || (b && b->failed))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: out of memory while drawing", fn);
    return rl_error(RL_ERR_INTERNAL, "%s: cairo: %s", fn, cairo_status_to_string(s));
}

rl_status rl_plot_begin(rl_plot *p, const char *fn, const rl_plot_output *out, int width, int height)
{
    memset(p, 0, sizeof *p);
    p->fn = fn;
    p->out = out;
    p->png = out->path && rl_path_has_ext(out->path, ".png");
    p->width = width;
    p->height = height;
    if (p->png) {
        p->surface = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height);
    } else {
        p->surface = cairo_svg_surface_create_for_stream(on_write, &p->svg, width, height);
        if (cairo_surface_status(p->surface) == CAIRO_STATUS_SUCCESS)
            /* CSS pixels: an inlined plot appears at its nominal size. */
            cairo_svg_surface_set_document_unit(p->surface, CAIRO_SVG_UNIT_PX);
    }
    cairo_status_t s = cairo_surface_status(p->surface);
    if (s == CAIRO_STATUS_SUCCESS) {
        p->cr = cairo_create(p->surface);
        s = cairo_status(p->cr);
    }
    if (s != CAIRO_STATUS_SUCCESS) {
        rl_status st = cairo_failure(fn, s, &p->svg);
        rl_plot_abort(p);
        return st;
    }
    cairo_set_source_rgb(p->cr, 1, 1, 1);
    cairo_paint(p->cr);
    cairo_select_font_face(p->cr, FONT_FAMILY, CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    /* 11 px ticks at the default 640 x 420, growing slower than the canvas
     * so that large plots are not cartoonish and small ones stay legible. */
    double s_min = fmin(width / 640.0, height / 420.0);
    p->font = 11.0 * fmax(0.75, fmin(2.5, sqrt(s_min)));
    p->ax0 = 0;
    p->ay0 = 0;
    p->ax1 = width;
    p->ay1 = height;
    return RL_OK;
}

void rl_plot_abort(rl_plot *p)
{
    if (p->cr)
        cairo_destroy(p->cr);
    if (p->surface)
        cairo_surface_destroy(p->surface);
    free(p->svg.data);
    memset(p, 0, sizeof *p);
}

/* The output's messages name the file, which says enough without fn. */
static rl_status write_file(const char *path, const unsigned char *data, size_t n)
{
    rl_output *o = NULL;
    rl_status st = rl_output_open(path, &o);
    if (st != RL_OK)
        return st;
    fwrite(data, 1, n, rl_output_file(o));
    return rl_output_commit(o);
}

/* FNV-1a, 32 bit: a short, content-derived id prefix. */
static unsigned hash_text(const unsigned char *s, size_t n)
{
    unsigned h = 2166136261u;
    for (size_t i = 0; i < n; ++i)
        h = (h ^ s[i]) * 16777619u;
    return h;
}

/* Rewrites cairo's SVG for inlining: no XML declaration, ids prefixed. */
static rl_status inline_svg(rl_plot_buf *b, char **result)
{
    const char *src = (const char *)b->data;
    const char *start = strstr(src, "<svg");
    if (!start)
        return rl_error(RL_ERR_INTERNAL, "svg output lacks <svg>");
    char prefix[16];
    int plen = snprintf(prefix, sizeof prefix, "rl%08x-", hash_text(b->data, b->size));
    static const char *const keys[] = { " id=\"", "href=\"#", "url(#" };
    rl_plot_buf o = { 0 };
    const char *s = start;
    while (*s) {
        size_t best = (size_t)-1;
        size_t klen = 0;
        for (int k = 0; k < 3; ++k) {
            const char *hit = strstr(s, keys[k]);
            if (hit && (size_t)(hit - s) < best) {
                best = (size_t)(hit - s);
                klen = strlen(keys[k]);
            }
        }
        if (best == (size_t)-1) {
            buf_append(&o, s, strlen(s));
            break;
        }
        buf_append(&o, s, best + klen);
        buf_append(&o, prefix, (size_t)plen);
        s += best + klen;
    }
    /* Trailing newline dropped: the string ends with "</svg>". */
    while (o.size > 0 && (o.data[o.size - 1] == '\n' || o.data[o.size - 1] == ' '))
        o.data[--o.size] = '\0';
    if (o.failed || !o.data) {
        free(o.data);
        return rl_error(RL_ERR_OUT_OF_MEMORY, "out of memory while rewriting svg");
    }
    *result = (char *)o.data;
    return RL_OK;
}

rl_status rl_plot_end(rl_plot *p)
{
    rl_status st = RL_OK;
    cairo_status_t s = cairo_status(p->cr);
    cairo_destroy(p->cr);
    p->cr = NULL;
    if (s == CAIRO_STATUS_SUCCESS) {
        if (p->png) {
            cairo_surface_flush(p->surface);
            s = cairo_surface_write_to_png_stream(p->surface, on_write, &p->svg);
        } else {
            cairo_surface_finish(p->surface);
            s = cairo_surface_status(p->surface);
        }
    }
    if (s != CAIRO_STATUS_SUCCESS || p->svg.failed || !p->svg.data) {
        st = cairo_failure(p->fn, s, &p->svg);
    } else if (p->out->path) {
        st = write_file(p->out->path, p->svg.data, p->svg.size);
    } else {
        char *text = NULL;
        st = inline_svg(&p->svg, &text);
        if (st == RL_OK)
            *p->out->svg = text;
    }
    rl_plot_abort(p);
    return st;
}

/* ---- text -------------------------------------------------------------- */

void rl_plot_set_color(rl_plot *p, rl_vec3 c, double alpha)
{
    cairo_set_source_rgba(p->cr, c.x, c.y, c.z, alpha);
}

static void set_font(rl_plot *p, double size, bool bold)
{
    cairo_select_font_face(p->cr, FONT_FAMILY, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(p->cr, size);
}

double rl_plot_text_width(rl_plot *p, const char *s, double size, bool bold)
{
    set_font(p, size, bold);
    cairo_text_extents_t e;
    cairo_text_extents(p->cr, s, &e);
    return e.x_advance;
}

double rl_plot_text(rl_plot *p, const char *s, double x, double y, double ha, double va,
                    double size, bool bold, double angle)
{
    double w = rl_plot_text_width(p, s, size, bold);
    cairo_save(p->cr);
    cairo_translate(p->cr, x, y);
    cairo_rotate(p->cr, -angle);
    cairo_move_to(p->cr, -ha * w, CAP_HEIGHT * size * (1.0 - va));
    cairo_show_text(p->cr, s);
    cairo_new_path(p->cr);
    cairo_restore(p->cr);
    return w;
}

/* Tick labels of the form "10^k" get a raised, smaller exponent. */
static double label_width(rl_plot *p, const char *s, double size)
{
    const char *caret = strchr(s, '^');
    if (!caret)
        return rl_plot_text_width(p, s, size, false);
    char base[16];
    size_t n = (size_t)(caret - s) < sizeof base - 1 ? (size_t)(caret - s) : sizeof base - 1;
    memcpy(base, s, n);
    base[n] = '\0';
    return rl_plot_text_width(p, base, size, false) + rl_plot_text_width(p, caret + 1, 0.72 * size, false);
}

static void draw_label(rl_plot *p, const char *s, double x, double y, double ha, double va, double size)
{
    const char *caret = strchr(s, '^');
    if (!caret) {
        rl_plot_text(p, s, x, y, ha, va, size, false, 0.0);
        return;
    }
    char base[16];
    size_t n = (size_t)(caret - s) < sizeof base - 1 ? (size_t)(caret - s) : sizeof base - 1;
    memcpy(base, s, n);
    base[n] = '\0';
    double w = label_width(p, s, size);
    double x0 = x - ha * w;
    double wb = rl_plot_text(p, base, x0, y, 0.0, va, size, false, 0.0);
    /* The exponent sits at half the cap height above the base's top half. */
    rl_plot_text(p, caret + 1, x0 + wb, y - 0.45 * CAP_HEIGHT * size, 0.0, va, 0.72 * size, false, 0.0);
}

/* ---- axes -------------------------------------------------------------- */

void rl_plot_axis_range(rl_plot_axis *a, double lo, double hi, bool log, bool pad)
{
    a->log = log;
    if (log) {
        double l = log10(lo), h = log10(hi);
        if (!(h > l)) {
            l -= 0.5;
            h += 0.5;
        }
        if (pad) {
            double d = 0.04 * (h - l);
            l -= d;
            h += d;
        }
        a->lo = pow(10.0, l);
        a->hi = pow(10.0, h);
        return;
    }
    if (!(hi > lo)) {
        double d = fmax(fabs(lo) * 0.1, 0.5);
        lo -= d;
        hi += d;
    } else if (pad) {
        double d = 0.04 * (hi - lo);
        lo -= d;
        hi += d;
    }
    a->lo = lo;
    a->hi = hi;
}

double rl_plot_map(const rl_plot_axis *a, double v)
{
    double t;
    if (a->log)
        t = (log10(v) - log10(a->lo)) / (log10(a->hi) - log10(a->lo));
    else
        t = (v - a->lo) / (a->hi - a->lo);
    return a->px0 + t * (a->px1 - a->px0);
}

/* Smallest 1, 2 or 5 times a power of ten that is >= x. */
static double nice_step(double x)
{
    double e = pow(10.0, floor(log10(x)));
    double f = x / e;
    double m = f <= 1.0 + 1e-9 ? 1.0 : f <= 2.0 + 1e-9 ? 2.0 : f <= 5.0 + 1e-9 ? 5.0 : 10.0;
    return m * e;
}

static void linear_ticks(double lo, double hi, int max_ticks, rl_plot_ticks *t)
{
    double step = nice_step((hi - lo) / fmax(1, max_ticks - 1));
    t->step = step;
    t->n = 0;
    double first = ceil(lo / step - 1e-9);
    for (int i = 0; t->n < RL_PLOT_MAX_TICKS; ++i) {
        double v = (first + i) * step;
        if (v > hi + 1e-9 * step)
            break;
        if (fabs(v) < 1e-12 * step)
            v = 0.0;
        t->v[t->n++] = v;
    }
}

void rl_plot_compute_ticks(const rl_plot_axis *a, int max_ticks, rl_plot_ticks *t)
{
    memset(t, 0, sizeof *t);
    max_ticks = max_ticks < 2 ? 2 : max_ticks > RL_PLOT_MAX_TICKS ? RL_PLOT_MAX_TICKS : max_ticks;
    if (!a->log) {
        linear_ticks(a->lo, a->hi, max_ticks, t);
        return;
    }
    double l = log10(a->lo), h = log10(a->hi);
    int k0 = (int)ceil(l - 1e-9), k1 = (int)floor(h + 1e-9);
    int decades = k1 - k0 + 1;
    if (decades >= 2) {
        /* Decades, thinned to every ds-th; minor ticks at 2..9 between. */
        int ds = (decades + max_ticks - 1) / max_ticks;
        for (int k = k0; k <= k1 && t->n < RL_PLOT_MAX_TICKS; ++k)
            if (((k % ds) + ds) % ds == 0)
                t->v[t->n++] = pow(10.0, k);
        if (ds == 1)
            for (int k = k0 - 1; k <= k1; ++k)
                for (int m = 2; m <= 9; ++m) {
                    double v = m * pow(10.0, k);
                    if (v >= a->lo && v <= a->hi && t->n_minor < RL_PLOT_MAX_TICKS * 4)
                        t->minor[t->n_minor++] = v;
                }
        return;
    }
    /* Less than two decades: 1-2-5 marks, or plain linear ones. */
    for (int k = k0 - 1; k <= k1 + 1; ++k)
        for (int m = 1; m <= 5; m = m == 1 ? 2 : m + 3) {
            double v = m * pow(10.0, k);
            if (v >= a->lo * (1 - 1e-9) && v <= a->hi * (1 + 1e-9) && t->n < RL_PLOT_MAX_TICKS)
                t->v[t->n++] = v;
        }
    if (t->n < 3)
        linear_ticks(a->lo, a->hi, max_ticks, t);
}

/* Replaces a leading '-' by the typographic minus. */
static void with_minus(const char *s, char *buf, size_t n)
{
    if (s[0] == '-')
        snprintf(buf, n, MINUS "%s", s + 1);
    else
        snprintf(buf, n, "%s", s);
}

void rl_plot_format(double v, const rl_plot_ticks *t, bool log, char *buf, size_t n)
{
    char tmp[64];
    if (log && t->step == 0.0) {
        double k = log10(v);
        double kr = floor(k + 0.5);
        if (fabs(k - kr) < 1e-9 && (kr < -3 || kr > 5)) {
            char e[16];
            snprintf(e, sizeof e, "%d", (int)kr);
            char em[24];
            with_minus(e, em, sizeof em);
            snprintf(buf, n, "10^%s", em);
            return;
        }
        snprintf(tmp, sizeof tmp, "%.6g", v);
        with_minus(tmp, buf, n);
        return;
    }
    double step = t->step > 0.0 ? t->step : 1.0;
    double mag = 0.0;
    for (int i = 0; i < t->n; ++i)
        mag = fmax(mag, fabs(t->v[i]));
    if (mag >= 1e6 || (mag > 0.0 && mag < 1e-3)) {
        /* Scientific: as many mantissa digits as the step resolves. */
        int digits = (int)ceil(log10(mag / step) - 1e-9) + 1;
        digits = digits < 1 ? 1 : digits > 12 ? 12 : digits;
        snprintf(tmp, sizeof tmp, "%.*g", digits, v);
    } else {
        int dec = step >= 1.0 ? 0 : (int)ceil(-log10(step) - 1e-9);
        snprintf(tmp, sizeof tmp, "%.*f", dec, v == 0.0 ? 0.0 : v);
    }
    with_minus(tmp, buf, n);
}

/* ---- layout and frame -------------------------------------------------- */

static double tick_len(const rl_plot *p) { return 0.4 * p->font; }
static double pad(const rl_plot *p) { return 0.9 * p->font; }

void rl_plot_layout(rl_plot *p, const rl_plot_style *style, const rl_plot_ticks *yt, bool y_log,
                    double extra_right, double extra_bottom)
{
    double f = p->font;
    double top = pad(p);
    top += 0.3 * f;
    if (style && style->title)
        top += 1.3 * f * 1.5;
    double bottom = pad(p) + tick_len(p) + 0.5 * f + CAP_HEIGHT * f + extra_bottom;
    if (style && style->x_label)
        bottom += 0.8 * f + CAP_HEIGHT * 1.1 * f + 0.35 * f;
    double ylab = 0.0;
    if (yt) {
        char buf[64];
        for (int i = 0; i < yt->n; ++i) {
            rl_plot_format(yt->v[i], yt, y_log, buf, sizeof buf);
            ylab = fmax(ylab, label_width(p, buf, f));
        }
    }
    double left = pad(p) + tick_len(p) + 0.5 * f + ylab;
    if (style && style->y_label)
        left += 0.8 * f + 1.1 * f;
    double right = pad(p) + fmax(extra_right, 1.2 * f);
    p->ax0 = left;
    p->ax1 = fmax(left + 1.0, p->width - right);
    p->ay0 = top;
    p->ay1 = fmax(top + 1.0, p->height - bottom);
    p->x.px0 = p->ax0;
    p->x.px1 = p->ax1;
    p->y.px0 = p->ay1;
    p->y.px1 = p->ay0;
}

/* Crisp 1-px lines in PNG: centre them on pixel centres. */
static double snap(double v) { return floor(v) + 0.5; }

static const rl_vec3 INK = { 0.15f, 0.15f, 0.15f };
static const rl_vec3 SPINE = { 0.3f, 0.3f, 0.3f };
static const rl_vec3 GRID = { 0.88f, 0.88f, 0.88f };

void rl_plot_draw_grid(rl_plot *p, const rl_plot_ticks *xt, const rl_plot_ticks *yt)
{
    cairo_t *cr = p->cr;
    cairo_save(cr);
    rl_plot_set_color(p, GRID, 1.0);
    cairo_set_line_width(cr, 1.0);
    if (yt)
        for (int i = 0; i < yt->n; ++i) {
            double y = snap(rl_plot_map(&p->y, yt->v[i]));
            if (y < p->ay0 - 0.5 || y > p->ay1 + 0.5)
                continue;
            cairo_move_to(cr, p->ax0, y);
            cairo_line_to(cr, p->ax1, y);
        }
    if (xt)
        for (int i = 0; i < xt->n; ++i) {
            double x = snap(rl_plot_map(&p->x, xt->v[i]));
            if (x < p->ax0 - 0.5 || x > p->ax1 + 0.5)
                continue;
            cairo_move_to(cr, x, p->ay0);
            cairo_line_to(cr, x, p->ay1);
        }
    cairo_stroke(cr);
    cairo_restore(cr);
}

void rl_plot_draw_title(rl_plot *p, const rl_plot_style *style)
{
    if (!style || !style->title)
        return;
    rl_plot_set_color(p, INK, 1.0);
    double f = 1.3 * p->font;
    /* Just above the plot area, wherever the plot moved it (equal aspect). */
    rl_plot_text(p, style->title, 0.5 * (p->ax0 + p->ax1), p->ay0 - 0.3 * p->font - 1.5 * f, 0.5, 0.0,
                 f, true, 0.0);
}

void rl_plot_draw_axes(rl_plot *p, const rl_plot_style *style, const rl_plot_ticks *xt,
                       const rl_plot_ticks *yt, bool draw_x_labels)
{
    cairo_t *cr = p->cr;
    double f = p->font, tl = tick_len(p);
    double xb = snap(p->ay1), yl = snap(p->ax0);
    cairo_save(cr);
    cairo_set_line_width(cr, 1.0);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_SQUARE);
    rl_plot_set_color(p, SPINE, 1.0);
    /* Spines: bottom and left only, the data needs no box. */
    cairo_move_to(cr, p->ax0, xb);
    cairo_line_to(cr, p->ax1, xb);
    cairo_move_to(cr, yl, p->ay0);
    cairo_line_to(cr, yl, p->ay1);
    cairo_stroke(cr);
    cairo_set_line_cap(cr, CAIRO_LINE_CAP_BUTT);
    char buf[64];
    if (xt) {
        for (int i = 0; i < xt->n; ++i) {
            double x = rl_plot_map(&p->x, xt->v[i]);
            if (x < p->ax0 - 0.5 || x > p->ax1 + 0.5)
                continue;
            cairo_move_to(cr, snap(x), xb);
            cairo_line_to(cr, snap(x), xb + tl);
        }
        for (int i = 0; i < xt->n_minor; ++i) {
            double x = rl_plot_map(&p->x, xt->minor[i]);
            cairo_move_to(cr, snap(x), xb);
            cairo_line_to(cr, snap(x), xb + 0.55 * tl);
        }
        cairo_stroke(cr);
        if (draw_x_labels) {
            rl_plot_set_color(p, INK, 1.0);
            for (int i = 0; i < xt->n; ++i) {
                double x = rl_plot_map(&p->x, xt->v[i]);
                if (x < p->ax0 - 0.5 || x > p->ax1 + 0.5)
                    continue;
                rl_plot_format(xt->v[i], xt, p->x.log, buf, sizeof buf);
                draw_label(p, buf, x, xb + tl + 0.5 * f, 0.5, 0.0, f);
            }
        }
    }
    double label_left = p->ax0;
    if (yt) {
        rl_plot_set_color(p, SPINE, 1.0);
        for (int i = 0; i < yt->n; ++i) {
            double y = rl_plot_map(&p->y, yt->v[i]);
            if (y < p->ay0 - 0.5 || y > p->ay1 + 0.5)
                continue;
            cairo_move_to(cr, yl, snap(y));
            cairo_line_to(cr, yl - tl, snap(y));
        }
        for (int i = 0; i < yt->n_minor; ++i) {
            double y = rl_plot_map(&p->y, yt->minor[i]);
            cairo_move_to(cr, yl, snap(y));
            cairo_line_to(cr, yl - 0.55 * tl, snap(y));
        }
        cairo_stroke(cr);
        rl_plot_set_color(p, INK, 1.0);
        for (int i = 0; i < yt->n; ++i) {
            double y = rl_plot_map(&p->y, yt->v[i]);
            if (y < p->ay0 - 0.5 || y > p->ay1 + 0.5)
                continue;
            rl_plot_format(yt->v[i], yt, p->y.log, buf, sizeof buf);
            draw_label(p, buf, yl - tl - 0.5 * f, y, 1.0, 0.5, f);
            label_left = fmin(label_left, yl - tl - 0.5 * f - label_width(p, buf, f));
        }
    }
    rl_plot_set_color(p, INK, 1.0);
    double lf = 1.1 * f;
    if (style && style->x_label) {
        double y = xb + tl + 0.5 * f + CAP_HEIGHT * f + 0.8 * f + 0.35 * f;
        if (!draw_x_labels)
            y = xb + tl + 0.5 * f;
        rl_plot_text(p, style->x_label, 0.5 * (p->ax0 + p->ax1), y, 0.5, 0.0, lf, false, 0.0);
    }
    if (style && style->y_label) {
        double x = fmin(label_left - 0.8 * f, p->ax0 - tl - 0.5 * f - 0.8 * f);
        /* Rotated to read bottom to top; its baseline faces the axis. */
        rl_plot_text(p, style->y_label, x, 0.5 * (p->ay0 + p->ay1), 0.5, 1.0, lf, false, RL_PI / 2);
    }
    cairo_restore(cr);
}

/* ---- legend ------------------------------------------------------------ */

static int occ_index(double v, double lo, double hi)
{
    int i = (int)floor((v - lo) / (hi - lo) * RL_PLOT_OCC);
    return i < 0 ? 0 : i >= RL_PLOT_OCC ? RL_PLOT_OCC - 1 : i;
}

void rl_plot_mark_point(rl_plot *p, double x, double y)
{
    if (!(x >= p->ax0 && x <= p->ax1 && y >= p->ay0 && y <= p->ay1))
        return;
    unsigned char *c = &p->occ[occ_index(y, p->ay0, p->ay1)][occ_index(x, p->ax0, p->ax1)];
    if (*c < 255)
        ++*c;
}

void rl_plot_mark_segment(rl_plot *p, double x0, double y0, double x1, double y1)
{
    double cell = fmin(p->ax1 - p->ax0, p->ay1 - p->ay0) / RL_PLOT_OCC;
    double len = hypot(x1 - x0, y1 - y0);
    int steps = (int)fmin(4096.0, ceil(len / fmax(0.5, 0.5 * cell)));
    for (int i = 0; i <= steps; ++i) {
        double t = steps ? (double)i / steps : 0.0;
        rl_plot_mark_point(p, x0 + t * (x1 - x0), y0 + t * (y1 - y0));
    }
}

void rl_plot_mark_rect(rl_plot *p, double x0, double y0, double x1, double y1)
{
    double ya = fmax(fmin(y0, y1), p->ay0), yb = fmin(fmax(y0, y1), p->ay1);
    double xa = fmax(fmin(x0, x1), p->ax0), xb = fmin(fmax(x0, x1), p->ax1);
    if (!(xb >= xa && yb >= ya))
        return;
    for (int j = occ_index(ya, p->ay0, p->ay1); j <= occ_index(yb, p->ay0, p->ay1); ++j)
        for (int i = occ_index(xa, p->ax0, p->ax1); i <= occ_index(xb, p->ax0, p->ax1); ++i)
            if (p->occ[j][i] < 255)
                ++p->occ[j][i];
}

static double occupancy(const rl_plot *p, double x0, double y0, double x1, double y1)
{
    double sum = 0.0;
    for (int j = occ_index(y0, p->ay0, p->ay1); j <= occ_index(y1, p->ay0, p->ay1); ++j)
        for (int i = occ_index(x0, p->ax0, p->ax1); i <= occ_index(x1, p->ax0, p->ax1); ++i)
            sum += p->occ[j][i];
    return sum;
}

static void rounded_rect(cairo_t *cr, double x, double y, double w, double h, double r)
{
    cairo_new_sub_path(cr);
    cairo_arc(cr, x + w - r, y + r, r, -RL_PI / 2, 0);
    cairo_arc(cr, x + w - r, y + h - r, r, 0, RL_PI / 2);
    cairo_arc(cr, x + r, y + h - r, r, RL_PI / 2, RL_PI);
    cairo_arc(cr, x + r, y + r, r, RL_PI, 1.5 * RL_PI);
    cairo_close_path(cr);
}

void rl_plot_legend(rl_plot *p, const rl_plot_legend_entry *e, size_t n)
{
    if (n == 0)
        return;
    cairo_t *cr = p->cr;
    double f = 0.95 * p->font;
    double row = 1.55 * f, sw = 1.9 * f, gap = 0.5 * f, in = 0.6 * f;
    double tw = 0.0;
    bool any_swatch = false;
    for (size_t i = 0; i < n; ++i) {
        tw = fmax(tw, rl_plot_text_width(p, e[i].text, f, false));
        any_swatch |= e[i].kind != 3;
    }
    double w = 2 * in + (any_swatch ? sw + gap : 0.0) + tw;
    double h = 2 * in + row * (double)n - (row - CAP_HEIGHT * f) + 0.1 * f;
    double m = 0.6 * p->font;
    double xs[2] = { p->ax1 - m - w, p->ax0 + m + 0.5 * p->font };
    double ys[2] = { p->ay0 + m, p->ay1 - m - h };
    /* Least covered corner; ties go to top right, the conventional place. */
    double best = INFINITY, bx = xs[0], by = ys[0];
    for (int j = 0; j < 2; ++j)
        for (int i = 0; i < 2; ++i) {
            double o = occupancy(p, xs[i], ys[j], xs[i] + w, ys[j] + h);
            if (o < best) {
                best = o;
                bx = xs[i];
                by = ys[j];
            }
        }
    cairo_save(cr);
    rounded_rect(cr, bx, by, w, h, 0.3 * f);
    cairo_set_source_rgba(cr, 1, 1, 1, 0.88);
    cairo_fill_preserve(cr);
    cairo_set_source_rgb(cr, 0.8, 0.8, 0.8);
    cairo_set_line_width(cr, 0.8);
    cairo_stroke(cr);
    for (size_t i = 0; i < n; ++i) {
        double cy = by + in + row * (double)i + 0.5 * CAP_HEIGHT * f;
        double tx = bx + in;
        if (any_swatch) {
            rl_plot_set_color(p, e[i].color, 1.0);
            if (e[i].kind == 0) {
                cairo_rectangle(cr, tx + 0.2 * sw, cy - 0.4 * f, 0.6 * sw, 0.8 * f);
                rl_plot_set_color(p, e[i].color, 0.35);
                cairo_fill_preserve(cr);
                rl_plot_set_color(p, e[i].color, 1.0);
                cairo_set_line_width(cr, 1.2);
                cairo_stroke(cr);
            } else if (e[i].kind == 1) {
                cairo_set_line_width(cr, 2.0);
                if (e[i].dashed) {
                    double d[2] = { 4.0, 3.0 };
                    cairo_set_dash(cr, d, 2, 0.0);
                }
                cairo_move_to(cr, tx, cy);
                cairo_line_to(cr, tx + sw, cy);
                cairo_stroke(cr);
                cairo_set_dash(cr, NULL, 0, 0.0);
            } else if (e[i].kind == 2) {
                cairo_arc(cr, tx + 0.5 * sw, cy, 0.28 * f, 0, 2 * RL_PI);
                cairo_fill(cr);
            }
            tx += sw + gap;
        }
        rl_plot_set_color(p, INK, 1.0);
        rl_plot_text(p, e[i].text, tx, cy, 0.0, 0.5, f, false, 0.0);
    }
    cairo_restore(cr);
}

/* ---- colour bar -------------------------------------------------------- */

static void colorbar_ticks(const rl_plot *p, double vmin, double vmax, rl_plot_ticks *t)
{
    rl_plot_axis a = { .lo = vmin, .hi = vmax };
    int n = (int)fmax(3.0, fmin(8.0, (p->ay1 - p->ay0) / (3.0 * p->font)));
    rl_plot_compute_ticks(&a, n, t);
}

double rl_plot_colorbar_width(rl_plot *p, double vmin, double vmax, const char *unit)
{
    double f = p->font;
    rl_plot_ticks t;
    /* The plot area is not known yet: assume the canvas height. */
    rl_plot q = *p;
    q.ay0 = 0;
    q.ay1 = p->height * 0.8;
    colorbar_ticks(&q, vmin, vmax, &t);
    double lw = 0.0;
    char buf[64];
    for (int i = 0; i < t.n; ++i) {
        rl_plot_format(t.v[i], &t, false, buf, sizeof buf);
        lw = fmax(lw, rl_plot_text_width(p, buf, f, false));
    }
    double w = 1.6 * f + 1.3 * f + tick_len(p) + 0.4 * f + lw;
    if (unit && *unit)
        w += 0.9 * f + 1.1 * f;
    return w;
}

void rl_plot_colorbar(rl_plot *p, double x, const char *cmap, bool reverse, double vmin, double vmax,
                      const char *unit)
{
    cairo_t *cr = p->cr;
    double f = p->font;
    double bx = x + 1.6 * f, bw = 1.3 * f, top = p->ay0, bot = p->ay1;
    cairo_save(cr);
    /* A gradient with the map's own resolution: cairo interpolates between
     * stops in display space exactly as rl_plot_colormap does. */
    cairo_pattern_t *g = cairo_pattern_create_linear(0, bot, 0, top);
    for (int i = 0; i <= 32; ++i) {
        double t = i / 32.0;
        rl_vec3 c = rl_plot_colormap(cmap, reverse ? 1.0 - t : t);
        cairo_pattern_add_color_stop_rgb(g, t, c.x, c.y, c.z);
    }
    cairo_rectangle(cr, bx, top, bw, bot - top);
    cairo_set_source(cr, g);
    cairo_fill(cr);
    cairo_pattern_destroy(g);
    rl_plot_ticks t;
    colorbar_ticks(p, vmin, vmax, &t);
    rl_plot_axis a = { .lo = vmin, .hi = vmax, .px0 = bot, .px1 = top };
    cairo_set_line_width(cr, 1.0);
    rl_plot_set_color(p, SPINE, 1.0);
    cairo_rectangle(cr, snap(bx), snap(top), floor(bw), floor(bot - top));
    double tl = tick_len(p), xr = snap(bx) + floor(bw);
    for (int i = 0; i < t.n; ++i) {
        double y = snap(rl_plot_map(&a, t.v[i]));
        cairo_move_to(cr, xr, y);
        cairo_line_to(cr, xr + tl, y);
    }
    cairo_stroke(cr);
    rl_plot_set_color(p, INK, 1.0);
    char buf[64];
    double lw = 0.0;
    for (int i = 0; i < t.n; ++i) {
        rl_plot_format(t.v[i], &t, false, buf, sizeof buf);
        lw = fmax(lw, rl_plot_text(p, buf, xr + tl + 0.4 * f, rl_plot_map(&a, t.v[i]), 0.0, 0.5, f,
                                   false, 0.0));
    }
    if (unit && *unit)
        rl_plot_text(p, unit, xr + tl + 0.4 * f + lw + 0.9 * f, 0.5 * (top + bot), 0.5, 0.0, 1.1 * f,
                     false, RL_PI / 2);
    cairo_restore(cr);
}

/* ---- images ------------------------------------------------------------ */

static double clamp01(double v) { return v > 0.0 ? (v < 1.0 ? v : 1.0) : 0.0; }

cairo_surface_t *rl_plot_image_surface(const rl_image *img)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_ARGB32, img->width, img->height);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS) {
        cairo_surface_destroy(s);
        rl_error(RL_ERR_OUT_OF_MEMORY, "cannot allocate a %dx%d image surface", img->width, img->height);
        return NULL;
    }
    cairo_surface_flush(s);
    unsigned char *data = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < img->height; ++y) {
        uint32_t *row = (uint32_t *)(void *)(data + (size_t)y * (size_t)stride);
        for (int x = 0; x < img->width; ++x) {
            rl_vec4 c = img->color[(size_t)y * (size_t)img->width + (size_t)x];
            double a = clamp01(c.w);
            /* Display encoding as in rl_image_write_png; cairo wants it
             * premultiplied, in native-endian ARGB words. */
            uint32_t r = (uint32_t)lrint(rl_linear_to_srgb((float)clamp01(c.x)) * a * 255.0);
            uint32_t g = (uint32_t)lrint(rl_linear_to_srgb((float)clamp01(c.y)) * a * 255.0);
            uint32_t b = (uint32_t)lrint(rl_linear_to_srgb((float)clamp01(c.z)) * a * 255.0);
            row[x] = (uint32_t)lrint(a * 255.0) << 24 | r << 16 | g << 8 | b;
        }
    }
    cairo_surface_mark_dirty(s);
    return s;
}
