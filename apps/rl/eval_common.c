/* eval_common.c: see eval_common.h. */
#include "eval_common.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "bench_util.h"
#include "cli.h"

const char eval_sampling_help[] =
    "sampling (Jähn 2015, Ch. 5):\n"
    "  --dims 2|3          2: the horizontal slice y = --height (default);\n"
    "                      3: the whole region\n"
    "  --region x0,y0,z0,x1,y1,z1   default: the scene's bounds; for a model\n"
    "                      file a box outside it, on the side of its default\n"
    "                      view, holding that view's orbit (docs/evaluation.md)\n"
    "  --height H          slice height; default the middle of the region's y\n"
    "                      (a model file: the default view's eye, above the model)\n"
    "  --method M          adaptive (Alg. 5.3, default) or grid (Alg. 5.2)\n"
    "  --positions P       bn (default), bn-corners, random or grid: how an\n"
    "                      adaptive region chooses its samples (Sec. 5.4.2)\n"
    "  --samples N         sample budget; default 256\n"
    "  --seconds S         time budget (stops at whichever comes first)\n"
    "  --min-side M        smallest region side; default 1 m, or 1/64 of the\n"
    "                      region's longest side when that is smaller\n"
    "  --samples-base N    samples per new region, constant part; default 5\n"
    "  --samples-per-meter F  samples per metre of region diameter; default 0.05\n"
    "  --combine C         region value: mean (default), max or min\n"
    "  --interp I          point queries: idw (inverse distance weighting of\n"
    "                      the nearest samples, default), nearest (the nearest\n"
    "                      sample) or region (the region's combined value, the\n"
    "                      thesis); see docs/evaluation.md\n"
    "  --idw-neighbors K   samples weighted by an idw query; default 4\n"
    "  --quality-size Q    size in the split priority q = n / (size * range):\n"
    "                      measure (area or volume, default) or diameter (the\n"
    "                      thesis); see docs/evaluation.md\n"
    "  --grid-shift        grid method: one random offset for every cell's\n"
    "                      sample instead of the cell centres (--seed)\n"
    "  --linear            fit a linear function per region instead\n"
    "  --seed N            default 1\n"
    "  --workers N         parallel evaluations; default all threads\n";

static const char *const positions_names[] = { "bn", "bn-corners", "random", "grid" };
static const char *const method_names[] = { "adaptive", "grid" };
static const char *const combine_names[] = { "mean", "max", "min" };
static const char *const interp_names[] = { "idw", "nearest", "region" };
static const char *const quality_size_names[] = { "measure", "diameter" };

const char *eval_positions_name(rl_position_variant v)
{
    return (unsigned)v < 4 ? positions_names[v] : "?";
}

void eval_sampling_init(eval_sampling *s)
{
    memset(s, 0, sizeof *s);
    s->desc.dims = 2;
    s->desc.max_samples = 256;
    s->desc.seed = 1;
}

static int pick(const char *option, const char *v, const char *const *names, int n)
{
    for (int k = 0; k < n; k++)
        if (strcmp(v, names[k]) == 0)
            return k;
    char list[256] = "", hint[96];
    for (int k = 0; k < n; k++) {
        strcat(list, k ? ", " : "");
        strcat(list, names[k]);
    }
    cli_fail(RL_CLI_USAGE, "%s: unknown value '%s' (%sone of %s)", option, v,
             cli_did_you_mean(v, names, (size_t)n, hint, sizeof hint), list);
    return -1;
}

const char *eval_quality_size_name(rl_quality_size q)
{
    return (unsigned)q < 2 ? quality_size_names[q] : "?";
}

bool eval_parse_quality_size(const char *option, const char *text, rl_quality_size *out)
{
    int k = pick(option, text, quality_size_names, 2);
    if (k < 0)
        return false;
    *out = (rl_quality_size)k;
    return true;
}

static const char *const visibility_backends[] = { "software", "gl" };

bool eval_parse_visibility_backend(const char *option, const char *text, const char **out)
{
    int k = pick(option, text, visibility_backends, 2);
    if (k < 0)
        return false;
    *out = visibility_backends[k];
    return true;
}

static bool parse_number(const char *option, const char *v, double lo, double hi, double *out)
{
    char *end = NULL;
    double x = strtod(v, &end);
    if (!*v || *end || !isfinite(x) || x < lo || x > hi) {
        cli_fail(RL_CLI_USAGE, "%s: expected a number in [%g, %g], got '%s'", option, lo, hi, v);
        return false;
    }
    *out = x;
    return true;
}

static bool parse_region(const char *v, rl_aabb *box)
{
    float c[6];
    char *end = NULL;
    const char *p = v;
    for (int k = 0; k < 6; k++) {
        double x = strtod(p, &end);
        if (end == p || !isfinite(x) || (k < 5 && *end != ',') || (k == 5 && *end)) {
            cli_fail(RL_CLI_USAGE, "--region: expected x0,y0,z0,x1,y1,z1, got '%s'", v);
            return false;
        }
        c[k] = (float)x;
        p = end + 1;
    }
    if (!(c[0] <= c[3] && c[1] <= c[4] && c[2] <= c[5])) {
        cli_fail(RL_CLI_USAGE, "--region: the second corner must not be below the first ('%s')", v);
        return false;
    }
    box->min = (rl_vec3){ c[0], c[1], c[2] };
    box->max = (rl_vec3){ c[3], c[4], c[5] };
    return true;
}

int eval_sampling_arg(int argc, char **argv, int *i, eval_sampling *s)
{
    const char *v = NULL;
    int m;
    double x;
    rl_sampling_desc *d = &s->desc;
#define TAKE(name) ((m = cli_take_value(argc, argv, i, name, &v)) != 0)
    if (strcmp(argv[*i], "--linear") == 0) {
        d->linear = true;
        return 1;
    }
    if (strcmp(argv[*i], "--grid-shift") == 0) {
        d->grid_shift = true;
        return 1;
    }
    if (TAKE("--dims")) {
        if (m < 0)
            return -1;
        if (strcmp(v, "2") != 0 && strcmp(v, "3") != 0) {
            cli_fail(RL_CLI_USAGE, "--dims: 2 or 3, got '%s'", v);
            return -1;
        }
        d->dims = v[0] - '0';
    } else if (TAKE("--region")) {
        if (m < 0 || !parse_region(v, &d->region))
            return -1;
        s->has_region = true;
    } else if (TAKE("--height")) {
        if (m < 0 || !parse_number("--height", v, -1e9, 1e9, &x))
            return -1;
        d->height = (float)x;
        s->has_height = true;
    } else if (TAKE("--method")) {
        int k = m < 0 ? -1 : pick("--method", v, method_names, 2);
        if (k < 0)
            return -1;
        d->method = (rl_sampling_method)k;
    } else if (TAKE("--positions")) {
        int k = m < 0 ? -1 : pick("--positions", v, positions_names, 4);
        if (k < 0)
            return -1;
        d->positions = (rl_position_variant)k;
    } else if (TAKE("--interp")) {
        int k = m < 0 ? -1 : pick("--interp", v, interp_names, 3);
        if (k < 0)
            return -1;
        d->interpolation = (rl_interpolation)k;
    } else if (TAKE("--quality-size")) {
        if (m < 0 || !eval_parse_quality_size("--quality-size", v, &d->quality_size))
            return -1;
    } else if (TAKE("--combine")) {
        int k = m < 0 ? -1 : pick("--combine", v, combine_names, 3);
        if (k < 0)
            return -1;
        d->combine = (rl_combine)k;
    } else if (TAKE("--samples")) {
        long long n;
        if (m < 0 || !bench_parse_count("--samples", v, 1 << 24, &n))
            return -1;
        d->max_samples = (uint32_t)n;
    } else if (TAKE("--seconds")) {
        if (m < 0 || !parse_number("--seconds", v, 1e-3, 1e7, &x))
            return -1;
        d->max_seconds = x;
    } else if (TAKE("--min-side")) {
        if (m < 0 || !parse_number("--min-side", v, 1e-6, 1e9, &x))
            return -1;
        d->min_side = (float)x;
        s->has_min_side = true;
    } else if (TAKE("--idw-neighbors")) {
        long long n;
        if (m < 0 || !bench_parse_count("--idw-neighbors", v, RL_SAMPLING_MAX_IDW_NEIGHBORS, &n))
            return -1;
        d->idw_neighbors = (uint32_t)n;
    } else if (TAKE("--samples-base")) {
        if (m < 0 || !parse_number("--samples-base", v, 1, 1e6, &x))
            return -1;
        d->samples_base = (float)x;
    } else if (TAKE("--samples-per-meter")) {
        if (m < 0 || !parse_number("--samples-per-meter", v, 1e-9, 1e6, &x))
            return -1;
        d->samples_per_meter = (float)x;
    } else if (TAKE("--seed")) {
        long long n;
        if (m < 0 || !bench_parse_count("--seed", v, 1LL << 62, &n))
            return -1;
        d->seed = (uint64_t)n;
    } else if (TAKE("--workers")) {
        long long n;
        if (m < 0 || !bench_parse_count("--workers", v, 1024, &n))
            return -1;
        d->workers = (int)n;
    } else
        return 0;
#undef TAKE
    return 1;
}

/* A model file is one object seen from outside: its bounds, the default
 * region of a built-in scene (a room, a city: spaces to stand in), would
 * place nearly every position inside the model, where all one sees is its
 * back faces. The region should hold the positions a viewer of a model
 * takes: around it, at about the distance of its default view. A shell or
 * ring at that distance would be the natural shape, but the sampler
 * (rl_sampling.h) splits axis-aligned boxes and 2-D slices, and a box
 * around the shell holds the model again. So the box is moved out of the
 * model's bounds instead, to the side the default view
 * (rl_scene_fit_camera, with the model file's azimuth and elevation)
 * looks from, above for the default 20° elevation:
 *   x, z: the square of the orbit of the framing camera, the model's
 *         centre +- D (D the framing camera's distance from the centre),
 *         so every azimuth of that orbit, at every distance up to D, is in;
 *   y:    from the eye of the framing camera, or a margin (5 % of D) past
 *         the model's top when the eye is lower, to the orbit's top
 *         (centre + D).
 * The 2-D slice lies on the side facing the model: the default view's
 * height, from its orbit inwards to right above the model. No position is
 * inside the model's bounds, and each one sees the model: the properties
 * look along the six main directions with 120° frusta (property_render.c,
 * property_visibility.c), which overlap and cover the whole sphere. */
bool eval_model_region(const rl_scene *scene, rl_aabb *region, float *height)
{
    const rl_scene_data *sd = rl_scene_get_data(scene);
    rl_camera cam;
    /* Square: the six views are square, and the fit depends on the aspect. */
    if (!sd || rl_scene_fit_camera(scene, 256, 256, &cam) != RL_OK)
        return false;
    rl_aabb b = sd->bounds;
    rl_vec3 c = rl_aabb_center(b);
    float orbit = rl_length(rl_sub(cam.eye, c));
    if (!(orbit > 0.0f) || !isfinite(orbit))
        return false;
    float margin = 0.05f * orbit;
    bool above = cam.eye.y >= c.y;
    float near = above ? fmaxf(cam.eye.y, b.max.y + margin) : fminf(cam.eye.y, b.min.y - margin);
    float far = above ? fmaxf(c.y + orbit, near + margin) : fminf(c.y - orbit, near - margin);
    region->min = rl_v3(fminf(c.x - orbit, b.min.x - margin), fminf(near, far), fminf(c.z - orbit, b.min.z - margin));
    region->max = rl_v3(fmaxf(c.x + orbit, b.max.x + margin), fmaxf(near, far), fmaxf(c.z + orbit, b.max.z + margin));
    *height = near;
    return true;
}

bool eval_sampling_finish(eval_sampling *s, const rl_scene *scene)
{
    rl_sampling_desc *d = &s->desc;
    const rl_scene_data *sd = rl_scene_get_data(scene);
    rl_aabb b = sd->bounds;
    float model_height = 0.0f;
    bool around = s->model && !s->has_region;
    if (around && !eval_model_region(scene, &d->region, &model_height)) {
        cli_fail(RL_CLI_FAIL, "no default region around the model: it cannot be framed");
        return false;
    }
    if (!s->has_region && !around)
        d->region = b;
    /* A region of the user's beside a model, not overlapping it, is a fair
     * choice: a model is seen from outside. */
    else if (s->has_region && !s->model &&
             (d->region.max.x < b.min.x || d->region.min.x > b.max.x ||
              d->region.max.z < b.min.z || d->region.min.z > b.max.z ||
              (d->dims == 3 && (d->region.max.y < b.min.y || d->region.min.y > b.max.y)))) {
        cli_fail(RL_CLI_USAGE, "--region does not overlap the scene (bounds %g,%g,%g .. %g,%g,%g)",
                    b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z);
        return false;
    }
    if (!s->has_height)
        d->height = around ? model_height : 0.5f * (d->region.min.y + d->region.max.y);
    else if (d->dims == 2 && !s->model && (d->height < b.min.y || d->height > b.max.y)) {
        cli_fail(RL_CLI_USAGE, "--height %g is outside the scene's y range [%g, %g]", d->height,
                    b.min.y, b.max.y);
        return false;
    }
    if (!s->has_min_side) {
        float ex = d->region.max.x - d->region.min.x, ez = d->region.max.z - d->region.min.z;
        float ey = d->dims == 3 ? d->region.max.y - d->region.min.y : 0.0f;
        float longest = fmaxf(ex, fmaxf(ey, ez));
        d->min_side = fminf(1.0f, longest / 64.0f);
        if (!(d->min_side > 0.0f))
            d->min_side = 1.0f;
    }
    return true;
}

rl_image *eval_top_view(const rl_scene *scene, rl_aabb region, float height, int width)
{
    float ex = region.max.x - region.min.x, ez = region.max.z - region.min.z;
    if (!(ex > 0.0f) || !(ez > 0.0f) || width < 16)
        return NULL;
    int h = (int)lrintf((float)width * ez / ex);
    if (h < 16 || h > 4 * width)
        return NULL;
    const rl_scene_data *sd = rl_scene_get_data(scene);
    /* Far above, with a narrow field of view: nearly orthographic, and exact
     * at the slice height. Up = -z puts +x to the right of the image. */
    float top = fmaxf(sd->bounds.max.y, height);
    float dist = (top - height) + 20.0f * fmaxf(ex, ez);
    rl_camera cam = {
        .eye = { region.min.x + 0.5f * ex, height + dist, region.min.z + 0.5f * ez },
        .target = { region.min.x + 0.5f * ex, height, region.min.z + 0.5f * ez },
        .up = { 0.0f, 0.0f, -1.0f },
        .fov_deg = 2.0f * atanf(0.5f * ez / dist) * 57.29578f,
        .width = width,
        .height = h,
    };
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    if (rl_renderer_create("raster", &r) != RL_OK ||
        rl_image_create(width, h, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &img) != RL_OK ||
        rl_renderer_render(r, scene, &cam, img, NULL) != RL_OK) {
        rl_image_release(img);
        img = NULL;
    }
    rl_renderer_release(r);
    rl_clear_error();
    return img;
}

bool eval_leaf_series(const rl_approx *a, double **values, double **weights, size_t *n)
{
    uint32_t count = rl_approx_region_count(a);
    double *v = malloc((count ? count : 1) * sizeof *v);
    double *w = malloc((count ? count : 1) * sizeof *w);
    if (!v || !w) {
        free(v);
        free(w);
        return false;
    }
    int dims = rl_approx_dims(a);
    for (uint32_t i = 0; i < count; i++) {
        rl_approx_region r;
        rl_approx_get_region(a, i, &r);
        double dx = r.box.max.x - r.box.min.x, dy = r.box.max.y - r.box.min.y;
        double dz = r.box.max.z - r.box.min.z;
        v[i] = r.value;
        w[i] = dims == 2 ? dx * dz : dx * dy * dz;
    }
    *values = v;
    *weights = w;
    *n = count;
    return true;
}

char *eval_heatmap_svg(const rl_approx *a, float height, const rl_image *top,
                          const char *title, double vmin, double vmax, bool reverse,
                          const char *png_path)
{
    uint32_t count = rl_approx_region_count(a), samples = rl_approx_sample_count(a);
    rl_plot_cell *cells = malloc((count ? count : 1) * sizeof *cells);
    double *points = malloc(2 * (samples ? samples : 1) * sizeof *points);
    char *svg = NULL;
    if (!cells || !points) {
        free(cells);
        free(points);
        cli_fail(RL_CLI_FAIL, "out of memory");
        return NULL;
    }
    int dims = rl_approx_dims(a);
    size_t n = 0, np = 0;
    for (uint32_t i = 0; i < count; i++) {
        rl_approx_region r;
        rl_approx_get_region(a, i, &r);
        if (dims == 3 && (height < r.box.min.y || height > r.box.max.y))
            continue;
        cells[n++] = (rl_plot_cell){ r.box.min.x, -r.box.max.z, r.box.max.x, -r.box.min.z, r.value };
    }
    rl_aabb b = rl_approx_bounds(a);
    for (uint32_t i = 0; i < samples; i++) {
        rl_vec3 p;
        double v;
        rl_approx_sample(a, i, &p, &v);
        /* 3-D: only the samples near the cut, else the map is a cloud. */
        if (dims == 3 && fabsf(p.y - height) > 0.05f * (b.max.y - b.min.y))
            continue;
        points[2 * np] = p.x;
        points[2 * np + 1] = -p.z;
        np++;
    }
    char x_label[] = "x (m)", y_label[] = "-z (m)";
    rl_plot_heatmap h = {
        .cells = cells, .count = n,
        .x0 = b.min.x, .y0 = -b.max.z, .x1 = b.max.x, .y1 = -b.min.z,
        .vmin = vmin, .vmax = vmax, .reverse = reverse, .borders = true,
        .unit = rl_approx_unit(a), .overlay = top, .points = points, .num_points = np,
    };
    rl_plot_style style = { .width = 560, .height = 0, .title = title,
                            .x_label = x_label, .y_label = y_label };
    /* Keep the map's aspect: plot area about 440 points wide. */
    double ex = b.max.x - b.min.x, ez = b.max.z - b.min.z;
    style.height = ex > 0 ? (int)fmin(900.0, fmax(240.0, 440.0 * ez / ex + 110.0)) : 480;
    rl_status st = n ? rl_plot_heatmap_draw(&h, &style, &(rl_plot_output){ .svg = &svg })
                     : RL_ERR_INVALID_ARG;
    if (st == RL_OK && png_path)
        st = rl_plot_heatmap_draw(&h, &style, &(rl_plot_output){ .path = png_path });
    if (st != RL_OK) {
        cli_fail_status(RL_CLI_FAIL, st, "heat map");
        free(svg);
        svg = NULL;
    }
    free(cells);
    free(points);
    return svg;
}

rl_vec3 *eval_random_positions(const rl_approx *a, size_t count, uint64_t seed)
{
    rl_vec3 *pos = malloc((count ? count : 1) * sizeof *pos);
    if (!pos)
        return NULL;
    rl_aabb b = rl_approx_bounds(a);
    rl_rng rng;
    rl_rng_seed(&rng, seed, 0x5eed);
    for (size_t i = 0; i < count; i++) {
        float u = rl_rng_float(&rng), v = rl_rng_float(&rng), w = rl_rng_float(&rng);
        pos[i] = (rl_vec3){ b.min.x + u * (b.max.x - b.min.x),
                            rl_approx_dims(a) == 2 ? b.min.y : b.min.y + v * (b.max.y - b.min.y),
                            b.min.z + w * (b.max.z - b.min.z) };
    }
    return pos;
}

rl_status eval_measure(rl_property *p, const rl_vec3 *pos, size_t count, double **values,
                          const char *progress_label)
{
    double *v = malloc((count ? count : 1) * sizeof *v);
    if (!v)
        return RL_ERR_OUT_OF_MEMORY;
    rl_progress *progress = NULL;
    if (progress_label && rl_log_get_level() >= RL_LOG_INFO)
        rl_progress_create(progress_label, stderr, &progress);
    rl_status st = rl_property_measure(p, pos, count, v, progress ? rl_progress_update : NULL, progress);
    if (progress)
        rl_progress_finish(progress);
    if (st != RL_OK) {
        free(v);
        return st;
    }
    *values = v;
    return RL_OK;
}

rl_status eval_errors(const rl_approx *a, const rl_vec3 *pos, const double *measured,
                         size_t count, double *approx, double *err)
{
    for (size_t i = 0; i < count; i++) {
        double v = 0.0;
        rl_status st = rl_approx_query(a, pos[i], &v, NULL);
        if (st != RL_OK)
            return st;
        if (approx)
            approx[i] = v;
        err[i] = fabs(v - measured[i]);
    }
    return RL_OK;
}

cJSON *eval_stats_json(const rl_stats *s)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    bench_add_num(o, "min", s->min);
    bench_add_num(o, "q25", s->q[1]);
    bench_add_num(o, "median", s->q[2]);
    bench_add_num(o, "q75", s->q[3]);
    bench_add_num(o, "max", s->max);
    bench_add_num(o, "mean", s->mean);
    bench_add_num(o, "stddev", s->stddev);
    bench_add_num(o, "weight", s->total_weight);
    bench_add_num(o, "count", (double)s->count);
    return o;
}

cJSON *eval_desc_json(const rl_sampling_desc *d)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddNumberToObject(o, "dims", d->dims);
    cJSON *r = cJSON_AddArrayToObject(o, "region");
    const float c[6] = { d->region.min.x, d->region.min.y, d->region.min.z,
                         d->region.max.x, d->region.max.y, d->region.max.z };
    for (int k = 0; k < 6 && r; k++)
        cJSON_AddItemToArray(r, cJSON_CreateNumber(c[k]));
    if (d->dims == 2)
        cJSON_AddNumberToObject(o, "height", d->height);
    cJSON_AddStringToObject(o, "method", method_names[d->method]);
    if (d->method == RL_SAMPLING_ADAPTIVE)
        cJSON_AddStringToObject(o, "positions", eval_positions_name(d->positions));
    cJSON_AddNumberToObject(o, "max_samples", d->max_samples);
    bench_add_num(o, "max_seconds", d->max_seconds);
    cJSON_AddNumberToObject(o, "min_side", d->min_side);
    cJSON_AddStringToObject(o, "combine", combine_names[d->combine]);
    cJSON_AddBoolToObject(o, "linear", d->linear);
    cJSON_AddStringToObject(o, "interpolation", interp_names[d->interpolation]);
    if (d->interpolation == RL_INTERP_IDW && !d->linear)
        cJSON_AddNumberToObject(o, "idw_neighbors",
                                d->idw_neighbors ? d->idw_neighbors : RL_SAMPLING_DEFAULT_IDW_NEIGHBORS);
    if (d->method == RL_SAMPLING_ADAPTIVE)
        cJSON_AddStringToObject(o, "quality_size", eval_quality_size_name(d->quality_size));
    else
        cJSON_AddBoolToObject(o, "grid_shift", d->grid_shift);
    cJSON_AddNumberToObject(o, "seed", (double)d->seed);
    return o;
}

void eval_stats_cells(const rl_stats *s, char buf[7][32])
{
    const double v[6] = { s->min, s->q[1], s->q[2], s->q[3], s->max, s->mean };
    for (int k = 0; k < 6; k++)
        snprintf(buf[k + 1], 32, "%.4g", v[k]);
}

void eval_property_label(const rl_property *p, char *out, size_t size)
{
    snprintf(out, size, "%s", rl_property_name(p));
    size_t no = 0;
    const rl_option_info *o = rl_property_options(p, &no);
    int shown = 0;
    for (size_t k = 0; k < no; k++) {
        const char *v = rl_property_get(p, o[k].key);
        bool is_renderer = strcmp(o[k].key, "renderer") == 0;
        if (!v || (!is_renderer && strcmp(v, o[k].default_value ? o[k].default_value : "") == 0))
            continue;
        size_t used = strlen(out);
        snprintf(out + used, size - used, "%s%s=%s", shown++ ? ", " : " (", o[k].key, v);
    }
    if (shown) {
        size_t used = strlen(out);
        snprintf(out + used, size - used, ")");
    }
}

const char eval_spread_help[] =
    "  --spread N          timings: measure again N times at one position (the\n"
    "                      first sample's) and report min, quartiles, median and\n"
    "                      max of those runs, the run-to-run spread; default 5,\n"
    "                      0: off. The load average at the start and the end is\n"
    "                      recorded; a load above the threads is warned about\n";

int eval_spread_arg(int argc, char **argv, int *i, int *runs)
{
    const char *v = NULL;
    int m = cli_take_value(argc, argv, i, "--spread", &v);
    if (m <= 0)
        return m;
    long long n = 0;
    if (!rl_parse_int(v, &n) || n < 0 || n > 100) {
        cli_fail(RL_CLI_USAGE, "--spread: expected a count in [0, 100], got '%s'", v);
        return -1;
    }
    *runs = (int)n;
    return 1;
}

rl_status eval_spread_measure(rl_property *p, const rl_approx *a, int runs, const char *label, eval_spread *out)
{
    memset(out, 0, sizeof *out);
    if (runs <= 0 || !(rl_property_get_flags(p) & RL_PROPERTY_EXCLUSIVE) || rl_approx_sample_count(a) == 0)
        return RL_OK;
    double v0;
    rl_approx_sample(a, 0, &out->pos, &v0);
    rl_vec3 *pos = malloc((size_t)runs * sizeof *pos);
    double *values = NULL;
    if (!pos)
        return RL_ERR_OUT_OF_MEMORY;
    for (int k = 0; k < runs; k++)
        pos[k] = out->pos;
    char what[1100];
    snprintf(what, sizeof what, "%s: spread", label);
    rl_status st = eval_measure(p, pos, (size_t)runs, &values, what);
    if (st == RL_OK)
        st = rl_stats_compute(values, NULL, (size_t)runs, &out->stats);
    free(pos);
    free(values);
    if (st == RL_OK)
        out->runs = runs;
    return st;
}

cJSON *eval_spread_json(const eval_spread *s)
{
    if (s->runs == 0)
        return cJSON_CreateNull();
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddNumberToObject(o, "runs", s->runs);
    const double xyz[3] = { s->pos.x, s->pos.y, s->pos.z };
    cJSON_AddItemToObject(o, "position", cJSON_CreateDoubleArray(xyz, 3));
    bench_add_num(o, "min", s->stats.min);
    bench_add_num(o, "q25", s->stats.q[1]);
    bench_add_num(o, "median", s->stats.q[2]);
    bench_add_num(o, "q75", s->stats.q[3]);
    bench_add_num(o, "max", s->stats.max);
    bench_add_num(o, "iqr", s->stats.q[3] - s->stats.q[1]);
    return o;
}

void eval_spread_text(const eval_spread *s, const char *unit, char *out, size_t size)
{
    if (s->runs == 0) {
        snprintf(out, size, "not measured");
        return;
    }
    snprintf(out, size, "%d runs at (%.3g, %.3g, %.3g): min %.4g, median %.4g, max %.4g %s (IQR %.4g)", s->runs,
             s->pos.x, s->pos.y, s->pos.z, s->stats.min, s->stats.q[2], s->stats.max, unit,
             s->stats.q[3] - s->stats.q[1]);
}
