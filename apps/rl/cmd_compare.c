/* cmd_compare.c: `rl compare SCENE --algos A,B,...`: every given renderer
 * measured over the same adaptively sampled region (Jähn 2015, Ch. 4-5),
 * instead of along one hand-picked camera path:
 *   time      rendering time, max over 6 directions of the median of
 *             --repeats renders (Def. 6, unconditioned);
 *   rays      traced rays,
 *   triangles rasterized triangles and
 *   queries   occlusion queries (Sec. 4.2.4, max over the directions);
 *   quality   hierarchical SSIM (or --quality-metric) against --reference,
 *             min over the directions (Def. 7).
 * The sample positions are chosen once, by adaptive sampling of pixel
 * visibility (the property whose structure most others follow, Sec. 5.7),
 * and every renderer is measured at exactly those positions, so the
 * comparisons are paired. Writes DIR/compare.json and DIR/report.html with
 * side-by-side heat maps (shared colour range per metric) and violin plots.
 * Renderers come from the registry by name, so a new renderer needs no
 * change here. The report names the experiment (command line, build,
 * machine, load) and gives each renderer's time a run-to-run spread
 * (--spread) and its preparation apart. */
#define _POSIX_C_SOURCE 200809L
#include "bench_util.h"
#include "cli.h"
#include "eval_common.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char compare_help_head[] =
    "usage: rl compare SCENE --algos A[:k=v,...],B,... [options]\n"
    "\n"
    "Measures every renderer at the same positions, chosen by adaptive sampling\n"
    "of pixel visibility over a region of the scene, and writes DIR/compare.json\n"
    "and DIR/report.html: heat maps side by side, violin plots and weighted\n"
    "statistics of rendering time, traced rays, rasterized triangles, occlusion\n"
    "queries and image quality against the reference.\n"
    "\n"
    "options:\n"
    "  --algos LIST        renderers (rl algos), each optionally with options:\n"
    "                      pt:shadow=ls-pnmt,diffuse=ls-pnmt,whitted (a k=v item\n"
    "                      after a comma continues the previous renderer's options);\n"
    "                      a bare value sets every option that offers it:\n"
    "                      pt:ls-pnmt is pt:shadow=ls-pnmt,diffuse=ls-pnmt\n"
    "  --reference A[:k=v] the exact reference for quality; default whitted\n"
    "  --quality-metric M  hssim (default: hierarchical SSIM, Jaehn 2015, Sec.\n"
    "                      4.2.5), ssim, psnr (dB, at most 100) or rmse\n"
    "  --metrics LIST      time, rays, triangles, queries, quality; default all\n"
    "  --size WxH          image per direction; default 128x128\n"
    "  --max-memory SIZE   refuse renderers whose frame needs more (e.g. 8G);\n"
    "                      default the available memory\n"
    "  --fov DEG           field of view per direction; default 120 (Sec. 4.2.3)\n"
    "  --repeats N         renders per direction for time (median); default 3\n"
    "  --resolution N      cube-face resolution of the visibility that places\n"
    "                      the samples; default 128\n"
    "  --visibility-backend B  software (default) or gl: that visibility drawn\n"
    "                      by OpenGL and counted on the GPU (docs/gl.md)\n"
    "  --out DIR           output folder; default out/compare\n";
static const char compare_help_tail[] =
    "\n"
    "example:\n"
    "  rl compare cornell --algos raster,whitted,vt,pt:ls-pnmt --samples 64 --out out/cmp\n";

#define MAX_ALGOS 16
enum { M_TIME, M_RAYS, M_TRIANGLES, M_QUERIES, M_QUALITY, M_COUNT };
static const char *const metric_names[M_COUNT] = { "time", "rays", "triangles", "queries", "quality" };
static const char *const metric_titles[M_COUNT] = {
    "Rendering time (Def. 6)", "Traced rays (Sec. 4.2.4)", "Rasterized triangles (Sec. 4.2.4)",
    "Occlusion queries (Sec. 4.2.4)", "Image quality against the reference (Def. 7)"
};
/* The quality property's metrics; the report names them. */
static const char *const quality_metrics[] = { "hssim", "ssim", "psnr", "rmse", NULL };
static const char *const quality_metric_titles[] = { "hierarchical SSIM", "SSIM", "PSNR", "RMSE" };
/* An operation count: a renderer that never does it is left out of its plots. */
static bool is_count(int m) { return m == M_RAYS || m == M_TRIANGLES || m == M_QUERIES; }

typedef struct algo_spec {
    char *label;          /* as given: "pt:shadow=ls-pnmt" */
    char *name;           /* "pt" */
    char *options;        /* "shadow=ls-pnmt" (bare values expanded) or NULL */
} algo_spec;

typedef struct compare_args {
    const char *scene, *out;
    algo_spec algos[MAX_ALGOS];
    int num_algos;
    algo_spec reference;
    int quality_metric;   /* index into quality_metrics */
    unsigned metrics;
    int width, height;
    double max_memory;    /* --max-memory in bytes, 0: MemAvailable */
    double fov_deg;
    long long repeats, resolution;
    const char *vis_backend;  /* --visibility-backend, or NULL: the property's default */
    int spread_runs;      /* --spread */
    eval_sampling sampling;
    cli_load load;
} compare_args;

static void free_spec(algo_spec *s)
{
    free(s->label);
    free(s->name);
    free(s->options);
    memset(s, 0, sizeof *s);
}

static void free_args(compare_args *a)
{
    for (int i = 0; i < a->num_algos; i++)
        free_spec(&a->algos[i]);
    free_spec(&a->reference);
}

/* Appends "key=value" to the growing option string *out (comma-separated). */
static bool append_option(char **out, size_t *len, const char *key, const char *value)
{
    size_t add = strlen(key) + strlen(value) + 2;
    char *grown = realloc(*out, *len + add + 1);
    if (!grown)
        return false;
    *out = grown;
    *len += (size_t)sprintf(grown + *len, "%s%s=%s", *len ? "," : "", key, value);
    return true;
}

/* A bare VALUE (no '=') stands for every enum option of the renderer that
 * offers it: pt:ls-pnmt is pt:shadow=ls-pnmt,diffuse=ls-pnmt, the thesis'
 * name of the variant. Found by the renderer's own option table, so later
 * renderers get the shorthand too. RL_ERR_INVALID_ARG with a message when
 * no option offers the value. */
static rl_status expand_bare_value(const rl_renderer *r, const char *label, const char *value,
                                   char **out, size_t *len)
{
    size_t count = 0;
    const rl_option_info *opts = rl_renderer_options(r, &count);
    int found = 0;
    for (size_t i = 0; i < count; i++) {
        if (opts[i].type != RL_OPT_ENUM || !opts[i].choices)
            continue;
        for (const char *const *c = opts[i].choices; *c; c++) {
            if (strcmp(*c, value) != 0)
                continue;
            if (!append_option(out, len, opts[i].key, value))
                return RL_ERR_OUT_OF_MEMORY;
            found++;
        }
    }
    if (!found) {
        cli_fail(RL_CLI_USAGE, "%s: '%s' is neither KEY=VALUE nor a value of one of the renderer's "
                    "options (see rl algos)", label, value);
        return RL_ERR_INVALID_ARG;
    }
    return RL_OK;
}

/* Splits "name[:k=v,...]" into a spec; checks the renderer and its options
 * by creating it once, and expands bare values (expand_bare_value). */
static bool make_spec(const char *text, algo_spec *s)
{
    s->label = strdup(text);
    const char *colon = strchr(text, ':');
    s->name = colon ? strndup(text, (size_t)(colon - text)) : strdup(text);
    if (!s->label || !s->name) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create(s->name, &r);
    if (st != RL_OK) {
        rl_renderer_release(r);
        cli_fail_status(RL_CLI_USAGE, st, "--algos");
        return false;
    }
    /* The options are checked here, not after minutes of sampling. */
    char *opts = colon && colon[1] ? strdup(colon + 1) : NULL, *save = NULL, *expanded = NULL;
    size_t len = 0;
    if (colon && colon[1] && !opts)
        st = RL_ERR_OUT_OF_MEMORY;
    for (char *kv = opts ? strtok_r(opts, ",", &save) : NULL; kv && st == RL_OK;
         kv = strtok_r(NULL, ",", &save)) {
        const char *eq = strchr(kv, '=');
        if (!eq) {
            st = expand_bare_value(r, s->label, kv, &expanded, &len);
            continue;
        }
        char key[128];
        const char *value = NULL;
        if (!cli_split_option(s->label, kv, key, sizeof key, &value)) {
            st = RL_ERR_INVALID_ARG;
            break;
        }
        if (!append_option(&expanded, &len, key, value))
            st = RL_ERR_OUT_OF_MEMORY;
    }
    /* Set in order, so that a later item wins as everywhere else. */
    char *copy = st == RL_OK && expanded ? strdup(expanded) : NULL;
    for (char *kv = copy ? strtok_r(copy, ",", &save) : NULL; kv && st == RL_OK;
         kv = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(kv, '=');
        *eq = '\0';
        if ((st = rl_renderer_set(r, kv, eq + 1)) != RL_OK)
            cli_fail_status(RL_CLI_USAGE, st, s->label);
    }
    if (st == RL_ERR_OUT_OF_MEMORY || (st == RL_OK && expanded && !copy)) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        st = RL_ERR_OUT_OF_MEMORY;
    }
    free(copy);
    free(opts);
    rl_renderer_release(r);
    s->options = expanded;
    return st == RL_OK;
}

static bool parse_algos(const char *list, compare_args *a)
{
    char *copy = strdup(list);
    if (!copy) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    char item[1024] = "";
    bool ok = true;
    char *save = NULL;
    for (char *tok = strtok_r(copy, ",", &save); ok; tok = strtok_r(NULL, ",", &save)) {
        /* A k=v item (no ':' before its '=') continues the options of the
         * item before it; "pt:spp=1" starts a new renderer. */
        const char *eq = tok ? strchr(tok, '=') : NULL, *colon = tok ? strchr(tok, ':') : NULL;
        if (eq && (!colon || colon > eq) && *item) {
            size_t len = strlen(item);
            snprintf(item + len, sizeof item - len, "%s%s", strchr(item, ':') ? "," : ":", tok);
            continue;
        }
        if (*item) {
            if (a->num_algos == MAX_ALGOS) {
                cli_fail(RL_CLI_USAGE, "--algos: at most %d renderers", MAX_ALGOS);
                ok = false;
                break;
            }
            ok = make_spec(item, &a->algos[a->num_algos++]);
        }
        if (!tok)
            break;
        snprintf(item, sizeof item, "%s", tok);
    }
    free(copy);
    if (ok && a->num_algos == 0) {
        cli_fail(RL_CLI_USAGE, "--algos: no renderer given");
        ok = false;
    }
    return ok;
}

static int parse_args(int argc, char **argv, compare_args *a)
{
    eval_sampling_init(&a->sampling);
    a->sampling.desc.max_samples = 64;
    a->out = "out/compare";
    a->metrics = (1u << M_COUNT) - 1;
    a->width = a->height = 128;
    a->fov_deg = 120.0;
    a->repeats = 3;
    a->resolution = 128;
    a->spread_runs = EVAL_SPREAD_RUNS;
    const char *algos = NULL, *reference = "whitted";
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        int m;
        if (cli_is_help(argv[i])) {
            fputs(compare_help_head, stdout);
            fputs(eval_spread_help, stdout);
            fputs("\n", stdout);
            fputs(eval_sampling_help, stdout);
            fputs(compare_help_tail, stdout);
            return -1;
        }
        if ((m = eval_sampling_arg(argc, argv, &i, &a->sampling)) != 0 ||
            (m = eval_spread_arg(argc, argv, &i, &a->spread_runs)) != 0) {
            if (m < 0)
                return RL_CLI_USAGE;
            continue;
        }
#define VALUE(name) (m == 0 && (m = cli_take_value(argc, argv, &i, name, &v)) > 0)
        m = 0;
        if (VALUE("--algos"))
            algos = v;
        else if (VALUE("--reference"))
            reference = v;
        else if (VALUE("--quality-metric")) {
            int k = 0;
            while (quality_metrics[k] && strcmp(quality_metrics[k], v) != 0)
                k++;
            if (!quality_metrics[k])
                return cli_fail(RL_CLI_USAGE, "--quality-metric: expected hssim, ssim, psnr or rmse, "
                                   "got '%s'", v);
            a->quality_metric = k;
        }
        else if (VALUE("--out"))
            a->out = v;
        else if (VALUE("--metrics")) {
            if (!bench_parse_sections(v, metric_names, M_COUNT, &a->metrics))
                return RL_CLI_USAGE;
        } else if (VALUE("--size")) {
            if (!cli_parse_size(v, &a->width, &a->height))
                return RL_CLI_USAGE;
        } else if (VALUE("--max-memory")) {
            if (!cli_parse_bytes(v, &a->max_memory))
                return cli_fail(RL_CLI_USAGE, "--max-memory: expected an amount such as 512M or 8G, got '%s'", v);
        } else if (VALUE("--fov")) {
            char *end = NULL;
            a->fov_deg = strtod(v, &end);
            if (!*v || *end || !(a->fov_deg > 0.0 && a->fov_deg < 180.0))
                return cli_fail(RL_CLI_USAGE, "--fov: expected degrees in (0, 180), got '%s'", v);
        } else if (VALUE("--repeats")) {
            if (!bench_parse_count("--repeats", v, 1000, &a->repeats))
                return RL_CLI_USAGE;
        } else if (VALUE("--resolution")) {
            if (!bench_parse_count("--resolution", v, 4096, &a->resolution))
                return RL_CLI_USAGE;
        } else if (VALUE("--visibility-backend")) {
            if (!eval_parse_visibility_backend("--visibility-backend", v, &a->vis_backend))
                return RL_CLI_USAGE;
        } else if (m == 0 && argv[i][0] != '-' && !a->scene)
            a->scene = argv[i];
        else if (m == 0)
            return cli_unknown_arg("compare", argv[i]);
#undef VALUE
        if (m < 0)
            return RL_CLI_USAGE;
    }
    if (!a->scene)
        return cli_fail(RL_CLI_USAGE, "compare: no scene given (see rl compare --help)");
    if (!algos)
        return cli_fail(RL_CLI_USAGE, "compare: no --algos given (see rl algos)");
    if (!parse_algos(algos, a) || !make_spec(reference, &a->reference))
        return RL_CLI_USAGE;
    return RL_CLI_OK;
}

/* The property of metric m for renderer s (NULL with the error printed). */
static rl_property *metric_property(const compare_args *a, int m, const algo_spec *s)
{
    rl_property *p = NULL;
    char num[32];
    rl_status st = rl_property_create(m == M_TIME ? "time" : m == M_QUALITY ? "quality" : "ops", &p);
#define SET(k, v) if (st == RL_OK) st = rl_property_set(p, k, v)
    SET("renderer", s->name);
    if (s->options)
        SET("renderer_options", s->options);
    snprintf(num, sizeof num, "%d", a->width);
    SET("width", num);
    snprintf(num, sizeof num, "%d", a->height);
    SET("height", num);
    snprintf(num, sizeof num, "%g", a->fov_deg);
    SET("fov_deg", num);
    if (m == M_TIME) {
        snprintf(num, sizeof num, "%lld", a->repeats);
        SET("repeats", num);
    } else if (is_count(m)) {
        SET("counter", m == M_RAYS ? "rays" : m == M_TRIANGLES ? "triangles" : "occlusion_queries");
    } else if (m == M_QUALITY) {
        SET("metric", quality_metrics[a->quality_metric]);
        SET("reference", a->reference.name);
        if (a->reference.options)
            SET("reference_options", a->reference.options);
    }
#undef SET
    if (st != RL_OK) {
        cli_fail_status(RL_CLI_USAGE, st, s->label);
        rl_property_release(p);
        return NULL;
    }
    return p;
}

typedef struct measured {
    rl_approx *approx;   /* the driver's tree with this renderer's values */
    rl_stats stats;
    double prep_ms;      /* committing the property: the renderer made, its inputs sampled */
    eval_spread spread;  /* time: the same position measured again */
    bool ok;
    char error[256];
} measured;

static void put_metric_section(html_doc *h, const compare_args *a, int m, measured (*res)[M_COUNT],
                               const rl_image *top, float height)
{
    /* Renderers that never do this operation (a rasterizer traces no ray)
     * are left out of its plots rather than shown as a flat zero. */
    int shown[MAX_ALGOS], ns = 0;
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i < a->num_algos; i++) {
        if (!res[i][m].ok)
            continue;
        if (is_count(m) && res[i][m].stats.max <= 0.0)
            continue;
        shown[ns++] = i;
        lo = fmin(lo, res[i][m].stats.min);
        hi = fmax(hi, res[i][m].stats.max);
    }
    html_heading(h, 2, metric_titles[m]);
    if (ns == 0) {
        html_para(h, "No renderer has values for this metric.");
        return;
    }
    static const char *const head[] = { "renderer", "min", "25 %", "median", "75 %", "max", "mean" };
    html_table_begin(h, head, 7);
    for (int k = 0; k < ns; k++) {
        char cells[7][32];
        const char *row[7];
        eval_stats_cells(&res[shown[k]][m].stats, cells);
        snprintf(cells[0], sizeof cells[0], "%.31s", a->algos[shown[k]].label);
        for (int c = 0; c < 7; c++)
            row[c] = cells[c];
        html_table_row(h, row, 7);
    }
    html_table_end(h);
    if (m == M_TIME)
        for (int k = 0; k < ns; k++) {
            const measured *r = &res[shown[k]][m];
            char spread[256], prep[32];
            eval_spread_text(&r->spread, "ms", spread, sizeof spread);
            cli_format_ms(r->prep_ms, prep, sizeof prep);
            html_para(h, "%s: run-to-run spread %s; preparation (prep, not in the times above) %s.",
                      a->algos[shown[k]].label, spread, prep);
        }
    /* One violin per renderer on a shared axis, then the heat maps side by
     * side with one colour range, so colours compare across renderers. */
    rl_plot_series series[MAX_ALGOS];
    double *vals[MAX_ALGOS] = { 0 }, *wts[MAX_ALGOS] = { 0 };
    size_t cnt[MAX_ALGOS] = { 0 };
    for (int k = 0; k < ns; k++) {
        eval_leaf_series(res[shown[k]][m].approx, &vals[k], &wts[k], &cnt[k]);
        series[k] = (rl_plot_series){ a->algos[shown[k]].label, vals[k], wts[k], cnt[k] };
    }
    char *violin = NULL;
    rl_plot_style vs = { .width = 140 + 110 * ns, .height = 420, .title = metric_names[m],
                         .y_label = rl_approx_unit(res[shown[0]][m].approx) };
    if (rl_plot_violin(series, (size_t)ns, &vs, &(rl_plot_output){ .svg = &violin }) != RL_OK)
        violin = NULL;
    html_svg(h, violin, "Area/volume-weighted distributions over the region, one violin "
                           "per renderer, with box plots inside.");
    free(violin);
    html_row_begin(h);
    /* dark = expensive or bad; of the quality metrics only rmse is an error */
    bool reverse = m != M_QUALITY || strcmp(quality_metrics[a->quality_metric], "rmse") == 0;
    for (int k = 0; k < ns; k++) {
        char *svg = eval_heatmap_svg(res[shown[k]][m].approx, height, top,
                                        a->algos[shown[k]].label, lo, hi > lo ? hi : lo + 1e-9,
                                        reverse, NULL);
        html_svg(h, svg, NULL);
        free(svg);
        free(vals[k]);
        free(wts[k]);
    }
    html_row_end(h);
}

static cJSON *result_json(const compare_args *a, const rl_scene *scene, const rl_approx *driver,
                          measured (*res)[M_COUNT])
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "renderlab", RL_CLI_VERSION);
    cJSON_AddItemToObject(root, "experiment", cli_experiment_json(a->load.threads));
    cJSON_AddItemToObject(root, "load", cli_load_json(&a->load));
    cJSON_AddStringToObject(root, "scene", a->scene);
    cJSON_AddItemToObject(root, "scene_stats", cli_scene_stats_json(scene));
    cJSON_AddItemToObject(root, "sampling", eval_desc_json(&a->sampling.desc));
    cJSON_AddNumberToObject(root, "samples", rl_approx_sample_count(driver));
    cJSON_AddNumberToObject(root, "regions", rl_approx_region_count(driver));
    /* Where every renderer was measured, so that a reader can check that the
     * positions are where the experiment meant them (around a model, not in it). */
    cJSON *where = cJSON_AddArrayToObject(root, "positions");
    for (uint32_t k = 0; where && k < rl_approx_sample_count(driver); k++) {
        rl_vec3 p;
        double v;
        rl_approx_sample(driver, k, &p, &v);
        cJSON_AddItemToArray(where, cJSON_CreateFloatArray((const float[]){ p.x, p.y, p.z }, 3));
    }
    cJSON_AddStringToObject(root, "reference", a->reference.label);
    cJSON_AddStringToObject(root, "quality_metric", quality_metrics[a->quality_metric]);
    cJSON_AddNumberToObject(root, "width", a->width);
    cJSON_AddNumberToObject(root, "height", a->height);
    cJSON_AddNumberToObject(root, "fov_deg", a->fov_deg);
    cJSON_AddNumberToObject(root, "repeats", (double)a->repeats);
    if (cli_dist_ranks() > 1) {
        /* Where the measuring ran: the times are this job's (its ranks
         * shared the machines), every other value is one process's. */
        cJSON *dist = cJSON_AddObjectToObject(root, "dist");
        if (dist)
            cJSON_AddNumberToObject(dist, "ranks", cli_dist_ranks());
    }
    cJSON *algos = cJSON_AddArrayToObject(root, "renderers");
    for (int i = 0; i < a->num_algos; i++) {
        cJSON *o = cJSON_CreateObject();
        cJSON_AddStringToObject(o, "renderer", a->algos[i].label);
        for (int m = 0; m < M_COUNT; m++) {
            if (!(a->metrics & (1u << m)))
                continue;
            if (res[i][m].ok) {
                cJSON *s = eval_stats_json(&res[i][m].stats);
                cJSON_AddStringToObject(s, "unit", rl_approx_unit(res[i][m].approx));
                cJSON_AddNumberToObject(s, "prep_ms", res[i][m].prep_ms);
                if (m == M_TIME)
                    cJSON_AddItemToObject(s, "spread", eval_spread_json(&res[i][m].spread));
                cJSON_AddItemToObject(o, metric_names[m], s);
            } else {
                cJSON *s = cJSON_AddObjectToObject(o, metric_names[m]);
                cJSON_AddStringToObject(s, "error", res[i][m].error);
            }
        }
        cJSON_AddItemToArray(algos, o);
    }
    return root;
}

/* Everything a typo can break, checked before the long part: each metric
 * property of each renderer can be made. */
static int check_metrics(const compare_args *a)
{
    for (int i = 0; i < a->num_algos; i++)
        for (int m = 0; m < M_COUNT; m++) {
            if (!(a->metrics & (1u << m)))
                continue;
            rl_property *p = metric_property(a, m, &a->algos[i]);
            if (!p)
                return RL_CLI_USAGE;
            rl_property_release(p);
        }
    return RL_CLI_OK;
}

/* The shared positions (Jähn 2015, Ch. 5): adaptive or grid sampling of
 * pixel visibility places them; every renderer is measured at the same. */
static int place_samples(compare_args *a, const rl_scene *scene, rl_approx **driver, rl_vec3 **pos,
                         uint32_t *count)
{
    rl_property *vis = NULL;
    char num[32];
    snprintf(num, sizeof num, "%lld", a->resolution);
    rl_status st = rl_property_create("visibility", &vis);
    if (st == RL_OK)
        st = rl_property_set(vis, "resolution", num);
    if (st == RL_OK && a->vis_backend)
        st = rl_property_set(vis, "backend", a->vis_backend);
    if (st == RL_OK)
        st = rl_property_commit(vis, scene, a->sampling.desc.workers);
    rl_progress *progress = NULL;
    if (st == RL_OK && rl_log_get_level() >= RL_LOG_INFO)
        rl_progress_create("placing samples", stderr, &progress);
    a->sampling.desc.progress = progress ? rl_progress_update : NULL;
    a->sampling.desc.progress_user = progress;
    if (st == RL_OK)
        st = cli_sample_call(vis, &a->sampling.desc, driver);
    if (progress)
        rl_progress_finish(progress);
    a->sampling.desc.progress = NULL;
    rl_property_release(vis);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, "sampling");
    if (!cli_dist_master()) {
        *pos = NULL;         /* --dist: a sampling node; the positions stay on the control node */
        *count = 0;
        return RL_CLI_OK;
    }
    uint32_t ns = rl_approx_sample_count(*driver);
    if (!(*pos = malloc((ns ? ns : 1) * sizeof **pos)))
        return cli_fail(RL_CLI_FAIL, "out of memory");
    for (uint32_t k = 0; k < ns; k++) {
        double v;
        rl_approx_sample(*driver, k, &(*pos)[k], &v);
    }
    *count = ns;
    return RL_CLI_OK;
}

/* One property at the positions: in this process, or under --dist on every
 * rank (Jähn 2015, Alg. 5.4's sampling nodes for positions placed
 * beforehand). Every rank takes part in every measuring, p NULL where its
 * commit failed, so that the ranks stay in step; the workers get no values. */
static rl_status measure_at(rl_property *p, const rl_vec3 *pos, uint32_t ns, double **values, const char *label)
{
    if (cli_dist_ranks() == 1)
        return p ? eval_measure(p, pos, ns, values, label) : RL_ERR_INVALID_ARG;
    if (!cli_dist_master())
        return cli_measure_call(p, NULL, 0, NULL);
    double *v = malloc((ns ? ns : 1) * sizeof *v);
    rl_status st = cli_measure_call(v ? p : NULL, pos, ns, v);
    if (st != RL_OK || !v) {
        free(v);
        return v ? st : RL_ERR_OUT_OF_MEMORY;
    }
    *values = v;
    return RL_OK;
}

/* Every metric of every renderer at the positions, as an approximation over
 * the driver's regions with weighted statistics; a failure is a warning and
 * counted, the others go on. Returns the number of failures. */
static int measure_all(const compare_args *a, const rl_scene *scene, const rl_approx *driver, const rl_vec3 *pos,
                       uint32_t ns, measured (*res)[M_COUNT])
{
    int failures = 0;
    for (int i = 0; i < a->num_algos; i++) {
        for (int m = 0; m < M_COUNT; m++) {
            if (!(a->metrics & (1u << m)))
                continue;
            measured *r = &res[i][m];
            rl_property *p = metric_property(a, m, &a->algos[i]);
            double *values = NULL, *v2 = NULL, *w2 = NULL;
            size_t n2 = 0;
            char label[300];
            snprintf(label, sizeof label, "%s %s", a->algos[i].label, metric_names[m]);
            rl_clear_error();
            rl_timer phase;
            rl_timer_start(&phase);
            rl_status st = p ? rl_property_commit(p, scene, a->sampling.desc.workers) : RL_ERR_INVALID_ARG;
            r->prep_ms = rl_timer_ms(&phase);
            if (st != RL_OK)
                snprintf(r->error, sizeof r->error, "%s", *rl_last_error() ? rl_last_error() : rl_status_string(st));
            if (st == RL_OK || cli_dist_ranks() > 1) {
                cli_debug("timing: %s: build %.1f ms", label, r->prep_ms);
                rl_timer_start(&phase);
                rl_status mst = measure_at(st == RL_OK ? p : NULL, pos, ns, &values, label);
                cli_debug("timing: %s: %u positions %.1f ms", label, ns, rl_timer_ms(&phase));
                if (st == RL_OK && mst != RL_OK) {
                    st = mst;
                    snprintf(r->error, sizeof r->error, "%s",
                             *rl_last_error() ? rl_last_error() : rl_status_string(st));
                }
            }
            if (!cli_dist_master()) {
                /* A sampling node: the control node reports (and warns). */
                rl_property_release(p);
                continue;
            }
            if (st == RL_OK)
                st = rl_approx_with_values(driver, values, metric_names[m], rl_property_unit(p), &r->approx);
            if (st == RL_OK && m == M_TIME)
                st = eval_spread_measure(p, r->approx, a->spread_runs, label, &r->spread);
            if (st == RL_OK && !eval_leaf_series(r->approx, &v2, &w2, &n2))
                st = RL_ERR_OUT_OF_MEMORY;
            if (st == RL_OK)
                st = rl_stats_compute(v2, w2, n2, &r->stats);
            r->ok = st == RL_OK;
            if (!r->ok) {
                if (!*r->error)
                    snprintf(r->error, sizeof r->error, "%s",
                             *rl_last_error() ? rl_last_error() : rl_status_string(st));
                fprintf(stderr, "rl: warning: %s: %s\n", label, r->error);
                failures++;
            } else if (rl_log_get_level() >= RL_LOG_INFO) {
                fprintf(stderr, "%s: mean %.4g %s, min %.4g, q25 %.4g, median %.4g, q75 %.4g, max %.4g", label,
                        r->stats.mean, rl_property_unit(p), r->stats.min, r->stats.q[1], r->stats.q[2],
                        r->stats.q[3], r->stats.max);
                if (r->spread.runs) {
                    char spread[256];
                    eval_spread_text(&r->spread, rl_property_unit(p), spread, sizeof spread);
                    fprintf(stderr, "; spread: %s", spread);
                }
                fputc('\n', stderr);
            }
            free(values);
            free(v2);
            free(w2);
            rl_property_release(p);
        }
    }
    return failures;
}

/* compare.json and report.html: the setup, where the samples are, and a
 * section per metric. */
static int write_files(const compare_args *a, const rl_scene *scene, const rl_approx *driver, uint32_t ns,
                       measured (*res)[M_COUNT], const char *report, const char *json_path)
{
    cJSON *root = result_json(a, scene, driver, res);
    bool ok = root && cli_write_json(root, json_path);
    cJSON_Delete(root);
    if (!ok)
        return RL_CLI_FAIL;
    char title[256];
    snprintf(title, sizeof title, "rl compare: %s", a->scene);
    html_doc *h = html_begin(report, title);
    if (!h)
        return RL_CLI_FAIL;
    const rl_sampling_desc *d = &a->sampling.desc;
    rl_aabb b = rl_approx_bounds(driver);
    rl_image *top = eval_top_view(scene, b, d->height, 512);
    char renders[64];
    if (a->repeats == 1)
        snprintf(renders, sizeof renders, "one render");
    else
        snprintf(renders, sizeof renders, "the median of %lld renders", a->repeats);
    html_para(h, "%d renderers measured at the same %u positions (%s, %s sampling of pixel "
                 "visibility at %lld² per cube face, %u regions). Per position: 6 directions, "
                 "%dx%d pixels, %g° field of view; time is the maximum over the directions of "
                 "%s, after one unmeasured frame that builds for the scene (its preparation, "
                 "prep, is reported apart); quality is %s against %s, the %s over the "
                 "directions (Jähn 2015, Ch. 4). Statistics are weighted by region %s.",
                 a->num_algos, ns, d->dims == 2 ? "a 2-D slice" : "a 3-D region",
                 d->method == RL_SAMPLING_GRID ? "grid" : "adaptive", a->resolution,
                 rl_approx_region_count(driver), a->width, a->height, a->fov_deg, renders,
                 quality_metric_titles[a->quality_metric], a->reference.label,
                 strcmp(quality_metrics[a->quality_metric], "rmse") == 0 ? "maximum" : "minimum",
                 d->dims == 2 ? "area" : "volume");
    char build[512], load[256];
    cli_build_text(build, sizeof build);
    cli_load_text(&a->load, load, sizeof load);
    html_para(h, "Command: %s. Build: %s. %s.", cli_command_line(), build, load);
    char *vis_svg = eval_heatmap_svg(driver, d->height, top, "visible objects", 0, 0, false, NULL);
    html_svg(h, vis_svg, "Where the samples are: the visibility approximation that placed "
                            "them (adaptive sampling refines where visibility changes).");
    free(vis_svg);
    for (int m = 0; m < M_COUNT; m++)
        if (a->metrics & (1u << m))
            put_metric_section(h, a, m, res, top, d->height);
    html_para(h, "Data: compare.json.");
    rl_image_release(top);
    return html_end(h, report) ? RL_CLI_OK : RL_CLI_FAIL;
}

/* Both files go to temporaries, renamed together once both are written
 * (rl_output_batch): a failed report keeps the previous pair. */
static int write_report(const compare_args *a, const rl_scene *scene, const rl_approx *driver, uint32_t ns,
                        measured (*res)[M_COUNT], const char *report, const char *json_path)
{
    rl_output_batch *batch = NULL;
    const char *json_tmp = NULL, *report_tmp = NULL;
    rl_clear_error();
    rl_status st = rl_output_batch_create(&batch);
    if (st == RL_OK && (st = rl_output_batch_add(batch, json_path, &json_tmp)) == RL_OK)
        st = rl_output_batch_add(batch, report, &report_tmp);
    if (st != RL_OK) {
        rl_output_batch_release(batch);
        return cli_fail_status(RL_CLI_FAIL, st, "outputs");
    }
    int rc = write_files(a, scene, driver, ns, res, report_tmp, json_tmp);
    rl_clear_error();
    if (rc == RL_CLI_OK && (st = rl_output_batch_commit(batch)) != RL_OK)
        rc = cli_fail_status(RL_CLI_FAIL, st, "outputs");
    rl_output_batch_release(batch);
    return rc;
}

/* Every renderer's frame at --size fits in memory (issue 34: a huge size
 * is refused with the estimate before minutes of sampling). */
static int check_frame_memory(const compare_args *a)
{
    int rc = RL_CLI_OK;
    for (int i = -1; i < a->num_algos && rc == RL_CLI_OK; ++i) {
        const algo_spec *s = i < 0 ? &a->reference : &a->algos[i];
        rl_renderer *r = NULL;
        if (rl_renderer_create(s->name, &r) == RL_OK)
            rc = cli_check_frame_memory(r, a->width, a->height, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, 0.0,
                                        a->max_memory);
        rl_renderer_release(r);
    }
    return rc;
}

int cli_compare(int argc, char **argv)
{
    compare_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc == RL_CLI_OK)
        rc = check_frame_memory(&a);
    if (rc != RL_CLI_OK) {
        free_args(&a);
        return rc < 0 ? RL_CLI_OK : rc;
    }
    char report[4096], json_path[4096];
    snprintf(report, sizeof report, "%s/report.html", a.out);
    snprintf(json_path, sizeof json_path, "%s/compare.json", a.out);
    rl_scene *scene = NULL;
    rl_approx *driver = NULL;
    rl_vec3 *pos = NULL;
    uint32_t ns = 0;
    measured (*res)[M_COUNT] = calloc(MAX_ALGOS, sizeof *res);
    if (!res)
        rc = cli_fail(RL_CLI_FAIL, "out of memory");
    if (rc == RL_CLI_OK)
        rc = check_metrics(&a);
    if (rc == RL_CLI_OK && cli_dist_master() && (!cli_make_dirs(a.out) || !cli_check_writable(report)))
        rc = RL_CLI_FAIL;
    if (rc == RL_CLI_OK)
        cli_load_begin(&a.load, a.sampling.desc.workers > 0 ? a.sampling.desc.workers : cli_threads());
    rl_timer phase;
    rl_timer_start(&phase);
    if (rc == RL_CLI_OK)
        rc = cli_load_scene(a.scene, &scene);
    if (rc == RL_CLI_OK)
        cli_debug("timing: load %.1f ms", rl_timer_ms(&phase));
    a.sampling.model = cli_is_model_file(a.scene);
    if (rc == RL_CLI_OK && !eval_sampling_finish(&a.sampling, scene))
        rc = RL_CLI_USAGE;
    if (rc == RL_CLI_OK)
        rc = place_samples(&a, scene, &driver, &pos, &ns);
    int failures = rc == RL_CLI_OK ? measure_all(&a, scene, driver, pos, ns, res) : 0;
    if (rc == RL_CLI_OK)
        cli_load_end(&a.load);
    if (rc == RL_CLI_OK && !cli_dist_master())
        goto done;          /* --dist: a sampling node; the control node writes */
    if (rc == RL_CLI_OK)
        rc = write_report(&a, scene, driver, ns, res, report, json_path);
    if (rc == RL_CLI_OK) {
        printf("compared %d renderers at %u positions of %s; wrote %s, %s\n", a.num_algos, ns, a.scene, json_path,
               report);
        if (failures)
            rc = cli_fail(RL_CLI_FAIL, "%d measurement%s failed (see the warnings)", failures,
                          failures == 1 ? "" : "s");
    }
done:
    if (res)
        for (int i = 0; i < MAX_ALGOS; i++)
            for (int m = 0; m < M_COUNT; m++)
                rl_approx_release(res[i][m].approx);
    free(res);
    free(pos);
    rl_approx_release(driver);
    rl_scene_release(scene);
    free_args(&a);
    return rc;
}
