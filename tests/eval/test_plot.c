/* test_plot.c: plots for evaluation reports (src/eval/plot*.c). Every plot
 * kind renders to inlinable SVG text and to PNG files of the asked size; a
 * heat map cell shows its colour map value and lets an overlay through where
 * it should; colour maps end on their published key colours; bad input and
 * unwritable paths fail without leaving files. The PNGs written here under
 * RL_TEST_TMP double as examples to look at. */
#define _GNU_SOURCE /* RTLD_DEFAULT */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <cairo/cairo.h>
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl_image.h"
#include "rl/rl_plot.h"
#include "rl/rl_stats.h"
#include "rl/rl_rng.h"

#define assert_near(a, b, eps)                                                       \
    do {                                                                             \
        double a_ = (a), b_ = (b);                                                   \
        if (!(fabs(a_ - b_) <= (eps)))                                               \
            fail_msg("%.17g != %.17g (eps %g)", a_, b_, (double)(eps));              \
    } while (0)

static void tmp_path(char *buf, size_t n, const char *name)
{
    const char *base = getenv("RL_TEST_TMP");
    snprintf(buf, n, "%s/%s", base ? base : "/tmp", name);
}

static bool exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

static void assert_svg_text(char *svg)
{
    assert_non_null(svg);
    assert_true(strncmp(svg, "<?xml", 5) == 0 || strstr(svg, "<svg") != NULL);
    size_t n = strlen(svg);
    assert_true(n > 6 && strcmp(svg + n - 6, "</svg>") == 0);
    /* Inlined next to other plots: cairo's bare ids would clash. */
    assert_null(strstr(svg, "id=\"glyph"));
    assert_null(strstr(svg, "href=\"#glyph"));
    free(svg);
}

static rl_image *read_png(const char *path, int w, int h)
{
    rl_image *img = NULL;
    if (rl_image_read(path, &img) != RL_OK)
        fail_msg("%s: %s", path, rl_last_error());
    assert_int_equal(img->width, w);
    assert_int_equal(img->height, h);
    return img;
}

/* Display (sRGB) value of a pixel; rl_image_read decodes to linear. */
static rl_vec3 display(rl_image *img, int x, int y)
{
    rl_vec4 c = *rl_image_pixel(img, x, y);
    return rl_v3(rl_linear_to_srgb(c.x), rl_linear_to_srgb(c.y), rl_linear_to_srgb(c.z));
}

static void assert_color(rl_vec3 a, rl_vec3 b, double eps)
{
    if (fabs(a.x - b.x) > eps || fabs(a.y - b.y) > eps || fabs(a.z - b.z) > eps)
        fail_msg("(%g %g %g) != (%g %g %g)", a.x, a.y, a.z, b.x, b.y, b.z);
}

/* Renders to memory, to .svg and to .png, and reads the PNG back. */
typedef rl_status (*draw_fn)(const void *data, const rl_plot_style *style, const rl_plot_output *out);

static void render_all(draw_fn draw, const void *data, const rl_plot_style *style, const char *name,
                       int w, int h)
{
    char *svg = NULL;
    rl_status st = draw(data, style, &(rl_plot_output){ .svg = &svg });
    if (st != RL_OK)
        fail_msg("%s svg: %s", name, rl_last_error());
    assert_svg_text(svg);
    char path[512], file[128];
    snprintf(file, sizeof file, "plot_%s.svg", name);
    tmp_path(path, sizeof path, file);
    assert_int_equal(draw(data, style, &(rl_plot_output){ .path = path }), RL_OK);
    assert_true(exists(path));
    snprintf(file, sizeof file, "plot_%s.png", name);
    tmp_path(path, sizeof path, file);
    assert_int_equal(draw(data, style, &(rl_plot_output){ .path = path }), RL_OK);
    rl_image_release(read_png(path, w, h));
}

/* ---- fixtures ---------------------------------------------------------- */

/* A quadtree of regions over [0,16]^2 with a "visible objects" count that
 * peaks in one corner and a hole without data, as Sec. 5.6.1 would show. */
typedef struct quad_fixture {
    rl_plot_cell cells[1024]; /* 4^5 at depth 5 */
    size_t count;
    double points[2048];
} quad_fixture;

static double property(double x, double y)
{
    return 40.0 + 260.0 * exp(-((x - 4) * (x - 4) + (y - 11) * (y - 11)) / 12.0) +
           60.0 * exp(-((x - 12) * (x - 12) + (y - 4) * (y - 4)) / 6.0);
}

static void split(quad_fixture *q, double x0, double y0, double s, int depth)
{
    double cx = x0 + 0.5 * s, cy = y0 + 0.5 * s;
    double span = fabs(property(x0, y0) - property(x0 + s, y0 + s)) +
                  fabs(property(x0 + s, y0) - property(x0, y0 + s));
    if (depth < 5 && (depth < 2 || span > 25.0)) {
        double h = 0.5 * s;
        split(q, x0, y0, h, depth + 1);
        split(q, x0 + h, y0, h, depth + 1);
        split(q, x0, y0 + h, h, depth + 1);
        split(q, x0 + h, y0 + h, h, depth + 1);
        return;
    }
    double v = property(cx, cy);
    if (cx > 12 && cy > 12)
        v = NAN;
    q->points[2 * q->count] = x0;
    q->points[2 * q->count + 1] = y0;
    q->cells[q->count++] = (rl_plot_cell){ x0, y0, x0 + s, y0 + s, v };
}

/* A stand-in for a scene's top view: ground with a soft gradient and a few
 * dark building roofs (rows top to bottom, as rl_image stores them). */
static rl_image *top_view(int w, int h)
{
    static const int roofs[][4] = { { 6, 8, 22, 20 }, { 30, 34, 44, 58 }, { 48, 6, 60, 18 }, { 10, 40, 20, 50 } };
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(w, h, RL_LAYER_COLOR, &img), RL_OK);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float g = 0.55f + 0.25f * (float)x / (float)w;
            rl_vec4 c = rl_v4(g * 0.9f, g, g * 0.8f, 1.0f);
            for (size_t r = 0; r < sizeof roofs / sizeof roofs[0]; ++r) {
                int x0 = roofs[r][0] * w / 64, y0 = roofs[r][1] * h / 64;
                int x1 = roofs[r][2] * w / 64, y1 = roofs[r][3] * h / 64;
                if (x >= x0 && x < x1 && y >= y0 && y < y1)
                    c = rl_v4(0.08f, 0.08f, 0.1f, 1.0f);
            }
            *rl_image_pixel(img, x, y) = c;
        }
    return img;
}

/* ---- heat map ---------------------------------------------------------- */

static rl_status draw_heatmap(const void *d, const rl_plot_style *s, const rl_plot_output *o)
{
    return rl_plot_heatmap_draw(d, s, o);
}

static void test_heatmap_renders_svg_and_png(void **state)
{
    (void)state;
    static quad_fixture q;
    q.count = 0;
    split(&q, 0, 0, 16, 0);
    rl_image *top = top_view(64, 64);
    rl_plot_heatmap h = { .cells = q.cells, .count = q.count, .borders = true, .unit = "visible objects",
                          .overlay = top, .points = q.points, .num_points = q.count };
    rl_plot_style style = { .title = "Visible objects (slice y = 1.7 m)", .x_label = "x [m]", .y_label = "z [m]" };
    render_all(draw_heatmap, &h, &style, "heatmap", 640, 420);
    /* Without overlay, magma reversed, NaN hatched on grey. */
    h.overlay = NULL;
    h.points = NULL;
    h.num_points = 0;
    h.colormap = "magma";
    h.reverse = true;
    h.unit = "ms";
    render_all(draw_heatmap, &h, &(rl_plot_style){ .width = 500, .height = 500 }, "heatmap_magma", 500, 500);
    /* Differences centred on zero. */
    for (size_t i = 0; i < q.count; ++i)
        q.cells[i].value = isnan(q.cells[i].value) ? NAN : q.cells[i].value - 100.0;
    h.colormap = "coolwarm";
    h.reverse = false;
    h.borders = false;
    h.unit = "difference";
    render_all(draw_heatmap, &h, &(rl_plot_style){ .width = 800, .height = 400, .title = "Difference" },
               "heatmap_coolwarm", 800, 400);
    rl_image_release(top);
}

/* 3 x 3 cells of 1 x 1; the middle one covers the canvas centre. */
static void three_by_three(rl_plot_cell *c, double centre_value)
{
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i)
            c[3 * j + i] = (rl_plot_cell){ i, j, i + 1, j + 1, (i == 1 && j == 1) ? centre_value : 3.0 * (i + j) / 4.0 };
}

static void test_heatmap_cell_has_its_colormap_colour(void **state)
{
    (void)state;
    rl_plot_cell c[9];
    three_by_three(c, 1.0);
    char path[512];
    tmp_path(path, sizeof path, "plot_heatmap_cell.png");
    rl_plot_heatmap h = { .cells = c, .count = 9, .vmin = 0, .vmax = 4, .cell_alpha = 1.0f };
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_OK);
    rl_image *img = read_png(path, 640, 420);
    assert_color(display(img, 320, 210), rl_plot_colormap("viridis", 0.25), 2.5 / 255);
    rl_image_release(img);

    h.colormap = "magma";
    h.reverse = true;
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_OK);
    img = read_png(path, 640, 420);
    assert_color(display(img, 320, 210), rl_plot_colormap("magma", 0.75), 2.5 / 255);
    rl_image_release(img);
}

static void test_heatmap_overlay_shows_through(void **state)
{
    (void)state;
    rl_image *red = NULL;
    assert_int_equal(rl_image_create(8, 8, RL_LAYER_COLOR, &red), RL_OK);
    rl_image_fill(red, rl_v4(1, 0, 0, 1));
    rl_plot_cell c[9];
    char path[512];
    tmp_path(path, sizeof path, "plot_heatmap_overlay.png");

    /* A NaN cell: only the hatch lies over the overlay. */
    three_by_three(c, NAN);
    rl_plot_heatmap h = { .cells = c, .count = 9, .vmin = 0, .vmax = 4, .cell_alpha = 1.0f, .overlay = red };
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_OK);
    rl_image *img = read_png(path, 640, 420);
    int red_px = 0;
    for (int y = 205; y <= 215; ++y)
        for (int x = 315; x <= 325; ++x) {
            rl_vec3 p = display(img, x, y);
            red_px += p.x > 0.95f && p.y < 0.05f && p.z < 0.05f;
        }
    assert_true(red_px > 60); /* of 121; the rest is hatch */
    rl_image_release(img);

    /* A half-transparent cell: the blend of cell and overlay (in display
     * space, as cairo composites). */
    three_by_three(c, 2.0);
    h.cell_alpha = 0.5f;
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_OK);
    img = read_png(path, 640, 420);
    rl_vec3 m = rl_plot_colormap("viridis", 0.5);
    assert_color(display(img, 320, 210), rl_v3(0.5f * m.x + 0.5f, 0.5f * m.y, 0.5f * m.z), 3.0 / 255);
    rl_image_release(img);

    /* Default alpha with an overlay is 0.75: still not the pure map colour. */
    h.cell_alpha = 0.0f;
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_OK);
    img = read_png(path, 640, 420);
    assert_color(display(img, 320, 210), rl_v3(0.75f * m.x + 0.25f, 0.75f * m.y, 0.75f * m.z), 3.0 / 255);
    rl_image_release(img);
    rl_image_release(red);
}

/* ---- violin and histogram ---------------------------------------------- */

typedef struct series_fixture {
    double v[3][2000], w[3][2000];
    rl_plot_series s[3];
} series_fixture;

static void make_series(series_fixture *f)
{
    rl_rng rng;
    rl_rng_seed(&rng, 7, 1);
    static const char *names[3] = { "grid", "adaptive random", "blue noise + corners" };
    for (int k = 0; k < 3; ++k) {
        for (int i = 0; i < 2000; ++i) {
            /* Bimodal: most regions see few objects, a cluster sees many. */
            double u1 = rl_rng_double(&rng) + 1e-12, u2 = rl_rng_double(&rng);
            double g = sqrt(-2 * log(u1)) * cos(2 * 3.14159265358979 * u2);
            bool far = rl_rng_double(&rng) < 0.3;
            f->v[k][i] = far ? 180 + 25 * g - 20 * k : 40 + 10 * g + 5 * k;
            f->w[k][i] = 0.25 + rl_rng_double(&rng);
        }
        f->s[k] = (rl_plot_series){ .name = names[k], .values = f->v[k], .weights = f->w[k], .count = 2000 };
    }
}

typedef struct series_args {
    const rl_plot_series *s;
    size_t n;
    int bins;
} series_args;

static rl_status draw_violin(const void *d, const rl_plot_style *s, const rl_plot_output *o)
{
    const series_args *a = d;
    return rl_plot_violin(a->s, a->n, s, o);
}

static rl_status draw_histogram(const void *d, const rl_plot_style *s, const rl_plot_output *o)
{
    const series_args *a = d;
    return rl_plot_histogram(a->s, a->n, a->bins, s, o);
}

static void test_violin_and_histogram_render(void **state)
{
    (void)state;
    static series_fixture f;
    make_series(&f);
    rl_plot_style style = { .title = "Visible objects per region (area-weighted)", .y_label = "visible objects",
                            .x_label = "sampling method" };
    render_all(draw_violin, &(series_args){ f.s, 3, 0 }, &style, "violin", 640, 420);
    render_all(draw_violin, &(series_args){ f.s, 1, 0 }, &(rl_plot_style){ .width = 300, .height = 300 },
               "violin_one", 300, 300);
    style = (rl_plot_style){ .title = "Distribution", .x_label = "visible objects" };
    render_all(draw_histogram, &(series_args){ f.s, 3, 0 }, &style, "histogram", 640, 420);
    render_all(draw_histogram, &(series_args){ f.s, 1, 12 }, NULL, "histogram_12", 640, 420);
    /* Constant data still draws. */
    const double c[] = { 5, 5, 5 };
    rl_plot_series cs = { .name = "constant", .values = c, .count = 3 };
    render_all(draw_violin, &(series_args){ &cs, 1, 0 }, NULL, "violin_constant", 640, 420);
    render_all(draw_histogram, &(series_args){ &cs, 1, 0 }, NULL, "histogram_constant", 640, 420);
}

/* ---- correlation, lines, image ----------------------------------------- */

typedef struct pairs {
    double x[2000], y[2000];
    size_t n;
} pairs;

static rl_status draw_correlation(const void *d, const rl_plot_style *s, const rl_plot_output *o)
{
    const pairs *p = d;
    return rl_plot_correlation(p->x, p->y, p->n, s, o);
}

static rl_status draw_lines(const void *d, const rl_plot_style *s, const rl_plot_output *o)
{
    return rl_plot_lines_draw(d, s, o);
}

static rl_status draw_image(const void *d, const rl_plot_style *s, const rl_plot_output *o)
{
    return rl_plot_image(d, s, o);
}

static void test_correlation_lines_and_image_render(void **state)
{
    (void)state;
    static pairs p;
    rl_rng rng;
    rl_rng_seed(&rng, 3, 2);
    p.n = 2000;
    for (size_t i = 0; i < p.n; ++i) {
        p.x[i] = 300 * rl_rng_double(&rng);
        p.y[i] = p.x[i] + 20 * (rl_rng_double(&rng) - 0.5) * (1 + p.x[i] / 100);
    }
    render_all(draw_correlation, &p, &(rl_plot_style){ .title = "Approximation vs. measurement" },
               "correlation", 640, 420);
    p.n = 1; /* r undefined: still a plot */
    render_all(draw_correlation, &p, NULL, "correlation_one", 640, 420);

    double xs[12], a[12], b[12], c[12];
    for (int i = 0; i < 12; ++i) {
        xs[i] = pow(2.0, i + 4);
        a[i] = 40.0 / sqrt(xs[i]);
        b[i] = 25.0 / pow(xs[i], 0.7);
        c[i] = 30.0 / pow(xs[i], 0.6) + 0.05;
    }
    rl_plot_series s[3] = { { .name = "grid", .values = a, .count = 12 },
                            { .name = "adaptive", .values = b, .count = 12 },
                            { .name = "blue noise", .values = c, .count = 12 } };
    rl_plot_lines l = { .xs = xs, .count = 12, .series = s, .num_series = 3, .log_x = true, .log_y = true };
    render_all(draw_lines, &l, &(rl_plot_style){ .title = "Convergence", .x_label = "samples", .y_label = "mean error" },
               "lines_log", 640, 420);
    l.log_x = l.log_y = false;
    l.num_series = 1;
    render_all(draw_lines, &l, &(rl_plot_style){ .width = 400, .height = 300 }, "lines", 400, 300);

    rl_image *img = top_view(96, 64);
    render_all(draw_image, img, NULL, "image", 96, 64);
    render_all(draw_image, img, &(rl_plot_style){ .width = 300, .title = "Render" }, "image_title", 300, 200);
    rl_image_release(img);

    /* Negative y on a log axis is an error. */
    a[3] = -1;
    l.log_y = true;
    char *svg = NULL;
    assert_int_equal(rl_plot_lines_draw(&l, NULL, &(rl_plot_output){ .svg = &svg }), RL_ERR_INVALID_ARG);
    assert_null(svg);
}

/* ---- colour maps ------------------------------------------------------- */

static void test_colormap_endpoints_match_published_colours(void **state)
{
    (void)state;
    /* matplotlib _viridis_data / _magma_data first and last entries;
     * Moreland 2009 CoolWarmFloat33 first, middle and last rows. */
    assert_color(rl_plot_colormap("viridis", 0), rl_v3(0.267004f, 0.004874f, 0.329415f), 1e-6);
    assert_color(rl_plot_colormap("viridis", 1), rl_v3(0.993248f, 0.906157f, 0.143936f), 1e-6);
    assert_color(rl_plot_colormap("magma", 0), rl_v3(0.001462f, 0.000466f, 0.013866f), 1e-6);
    assert_color(rl_plot_colormap("magma", 1), rl_v3(0.987053f, 0.991438f, 0.749504f), 1e-6);
    assert_color(rl_plot_colormap("coolwarm", 0), rl_v3(0.2298057f, 0.298717966f, 0.753683153f), 1e-6);
    assert_color(rl_plot_colormap("coolwarm", 0.5), rl_v3(0.865395197f, 0.86541021f, 0.865395561f), 1e-6);
    assert_color(rl_plot_colormap("coolwarm", 1), rl_v3(0.705673158f, 0.01555616f, 0.150232812f), 1e-6);
    /* viridis(0.5) is #21918c in the 256-entry table (index 127/128). */
    assert_color(rl_plot_colormap("viridis", 0.5), rl_v3(0x21 / 255.0f, 0x91 / 255.0f, 0x8c / 255.0f), 1.5 / 255);
    /* Clamping, NaN and unknown names. */
    assert_color(rl_plot_colormap("viridis", -3), rl_plot_colormap("viridis", 0), 0);
    assert_color(rl_plot_colormap("viridis", 7), rl_plot_colormap("viridis", 1), 0);
    assert_color(rl_plot_colormap("viridis", NAN), rl_plot_colormap("viridis", 0), 0);
    assert_color(rl_plot_colormap("jet", 0.3), rl_plot_colormap("viridis", 0.3), 0);
    assert_color(rl_plot_colormap(NULL, 0.3), rl_plot_colormap("viridis", 0.3), 0);
    assert_true(rl_plot_colormap_valid("magma"));
    assert_false(rl_plot_colormap_valid("jet"));
    assert_false(rl_plot_colormap_valid(NULL));
}

/* ---- failures ---------------------------------------------------------- */

static void test_bad_input_writes_nothing(void **state)
{
    (void)state;
    rl_plot_cell c[9];
    three_by_three(c, 1.0);
    rl_plot_heatmap h = { .cells = c, .count = 9 };
    char path[512], jpg[512];
    tmp_path(path, sizeof path, "plot_bad.png");
    tmp_path(jpg, sizeof jpg, "plot_bad.jpg");
    remove(path);
    remove(jpg);
    char *svg = NULL;
    rl_plot_output png = { .path = path };

    assert_int_equal(rl_plot_heatmap_draw(&(rl_plot_heatmap){ .count = 9 }, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&(rl_plot_heatmap){ .cells = c }, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(NULL, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path, .svg = &svg }),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ 0 }), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = jpg }), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&h, &(rl_plot_style){ .width = 9 }, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_heatmap_draw(&h, &(rl_plot_style){ .height = 10000 }, &png), RL_ERR_INVALID_ARG);
    rl_plot_heatmap bad = h;
    bad.colormap = "jet";
    assert_int_equal(rl_plot_heatmap_draw(&bad, NULL, &png), RL_ERR_INVALID_ARG);
    bad = h;
    bad.cell_alpha = 1.5f;
    assert_int_equal(rl_plot_heatmap_draw(&bad, NULL, &png), RL_ERR_INVALID_ARG);
    bad = h;
    bad.num_points = 3;
    assert_int_equal(rl_plot_heatmap_draw(&bad, NULL, &png), RL_ERR_INVALID_ARG);
    rl_plot_cell degenerate = { 1, 1, 1, 1, 0 };
    assert_int_equal(rl_plot_heatmap_draw(&(rl_plot_heatmap){ .cells = &degenerate, .count = 1 }, NULL, &png),
                     RL_ERR_INVALID_ARG);

    const double v[] = { 1, NAN, 3 };
    rl_plot_series s = { .name = "nan", .values = v, .count = 3 };
    assert_int_equal(rl_plot_violin(&s, 1, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_histogram(&s, 1, 0, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_violin(NULL, 1, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_violin(&s, 0, NULL, &png), RL_ERR_INVALID_ARG);
    const double ok[] = { 1, 2, 3 };
    s.values = ok;
    assert_int_equal(rl_plot_histogram(&s, 1, -1, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_violin(&s, 1, &(rl_plot_style){ .width = 10000 }, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_correlation(v, ok, 3, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_correlation(ok, ok, 0, NULL, &png), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_lines_draw(&(rl_plot_lines){ .xs = ok, .count = 3 }, NULL, &png), RL_ERR_INVALID_ARG);
    rl_plot_series short_s = { .values = ok, .count = 2 };
    assert_int_equal(rl_plot_lines_draw(&(rl_plot_lines){ .xs = ok, .count = 3, .series = &short_s, .num_series = 1 },
                                        NULL, &png),
                     RL_ERR_INVALID_ARG);
    assert_int_equal(rl_plot_image(NULL, NULL, &png), RL_ERR_INVALID_ARG);
    rl_image *tiny = NULL;
    assert_int_equal(rl_image_create(8, 8, RL_LAYER_COLOR, &tiny), RL_OK);
    assert_int_equal(rl_plot_image(tiny, NULL, &png), RL_ERR_INVALID_ARG); /* 8 < 16 */
    rl_image_release(tiny);

    assert_false(exists(path));
    assert_false(exists(jpg));
    assert_null(svg);
}

/* Constant data has no correlation; the plot is drawn all the same, and
 * the caller's earlier error is neither erased nor covered. */
static void test_constant_correlation_keeps_the_callers_error(void **state)
{
    (void)state;
    rl_clear_error();
    double r = 0.0;
    assert_int_equal(rl_stats_correlation(NULL, NULL, 2, &r), RL_ERR_INVALID_ARG);   /* the caller's */
    char before[256];
    snprintf(before, sizeof before, "%s", rl_last_error());
    const double flat[] = { 2, 2, 2, 2 }, rising[] = { 1, 2, 3, 4 };
    char *svg = NULL;
    assert_int_equal(rl_plot_correlation(flat, rising, 4, NULL, &(rl_plot_output){ .svg = &svg }), RL_OK);
    assert_non_null(svg);
    free(svg);
    assert_string_equal(rl_last_error(), before);
    rl_clear_error();
}

static void test_unwritable_path_is_an_io_error(void **state)
{
    (void)state;
    rl_plot_cell c[9];
    three_by_three(c, 1.0);
    rl_plot_heatmap h = { .cells = c, .count = 9 };
    char path[512];
    tmp_path(path, sizeof path, "no/such/directory/plot.svg");
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_ERR_IO);
    tmp_path(path, sizeof path, "no/such/directory/plot.png");
    assert_int_equal(rl_plot_heatmap_draw(&h, NULL, &(rl_plot_output){ .path = path }), RL_ERR_IO);
    assert_false(exists(path));
}

/* cairo and fontconfig keep font caches for the life of the process, which
 * LeakSanitizer reports; free them after the last test so that it sees
 * only renderlab's own leaks. Safe only here: no cairo object is alive and
 * no other thread draws. fontconfig comes in as cairo's dependency and is
 * not on our link line, hence the lookup. */
static void release_font_caches(void)
{
    cairo_debug_reset_static_data();
    void (*fc_fini)(void) = NULL;
    *(void **)&fc_fini = dlsym(RTLD_DEFAULT, "FcFini");
    if (fc_fini)
        fc_fini();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_heatmap_renders_svg_and_png),
        cmocka_unit_test(test_heatmap_cell_has_its_colormap_colour),
        cmocka_unit_test(test_heatmap_overlay_shows_through),
        cmocka_unit_test(test_violin_and_histogram_render),
        cmocka_unit_test(test_correlation_lines_and_image_render),
        cmocka_unit_test(test_colormap_endpoints_match_published_colours),
        cmocka_unit_test(test_bad_input_writes_nothing),
        cmocka_unit_test(test_unwritable_path_is_an_io_error),
        cmocka_unit_test(test_constant_correlation_keeps_the_callers_error),
    };
    int failed = cmocka_run_group_tests(tests, NULL, NULL);
    release_font_caches();
    return failed;
}
