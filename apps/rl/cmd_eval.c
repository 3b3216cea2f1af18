/* cmd_eval.c: `rl eval SCENE --property NAME`: a position-dependent property
 * (Jähn 2015, Ch. 4) approximated over a 2-D slice or a 3-D region by
 * adaptive or grid sampling (Ch. 5), evaluated as in Sec. 5.6: region
 * statistics weighted by area/volume, a heat map over the scene's top view,
 * a violin plot and a histogram of the region values, and, with
 * --validate N, the error at N uniform random positions (Sec. 5.7) with a
 * correlation plot. Writes DIR/approx.json (the approximation, loadable with
 * rl_approx_load_json), DIR/eval.json (the numbers) and a self-contained
 * HTML report. Every report names the experiment (the property with its
 * renderer and options, the command line, the build, the machine and its
 * load); a timing also gets its run-to-run spread (--spread). */
#define _POSIX_C_SOURCE 200809L
#include "bench_util.h"
#include "cli.h"
#include "eval_common.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

static const char eval_help_head[] =
    "usage: rl eval SCENE --property NAME [options]\n"
    "       rl eval --list      the properties and their options\n"
    "\n"
    "Approximates a position-dependent property over a region of the scene\n"
    "and writes DIR/approx.json, DIR/eval.json and an HTML report with a heat\n"
    "map, a violin plot and a histogram of the area-weighted region values.\n"
    "\n"
    "options:\n"
    "  --property NAME     visibility, time, ops or quality (see --list)\n"
    "  --set KEY=VALUE     property option, repeatable (e.g. resolution=256,\n"
    "                      renderer=whitted, renderer_options=max_depth=2)\n"
    "  --property2 NAME    sample a combined property (Jaehn 2015, Sec. 4.2.6):\n"
    "                      --property OP NAME, e.g. the time of one renderer\n"
    "                      minus another's\n"
    "  --op OP             of the combined property: minus (default), ratio,\n"
    "                      min or max\n"
    "  --set2 KEY=VALUE    option of --property2, repeatable\n"
    "  --validate N        also measure at N uniform random positions and report\n"
    "                      the absolute error of the approximation there\n"
    "  --out DIR           output folder, created if missing; default out/eval\n"
    "  --report FILE.html  default DIR/report.html\n"
    "  --checkpoint FILE   record every measured batch in FILE; run the same\n"
    "                      command again after a stop and it replays them and\n"
    "                      measures on (also under rl --dist; the file belongs\n"
    "                      to this scene, property, options and sampling)\n";
static const char eval_help_tail[] =
    "\n"
    "example:\n"
    "  rl eval city --property visibility --set resolution=256 --height 1.7 \\\n"
    "     --samples 512 --validate 200 --out out/eval-city\n"
    "  rl eval table --property time --set renderer=vt --property2 time \\\n"
    "     --set2 renderer=raster --dims 3 --samples 128 --out out/vt-minus-raster\n";

#define MAX_SETS 64

/* --op names, in rl_property_op order. */
static const char *const combine_ops[] = { "minus", "ratio", "min", "max", NULL };

typedef struct eval_args {
    const char *scene, *property, *out, *report, *checkpoint;
    const char *sets[MAX_SETS];
    int num_sets;
    const char *second;          /* --property2, or NULL */
    const char *op;              /* --op, or NULL */
    int combine_op;              /* rl_property_op */
    const char *sets2[MAX_SETS];
    int num_sets2;
    long long validate;
    int spread_runs;             /* --spread */
    bool list;
    eval_sampling sampling;
} eval_args;

static void print_help(void)
{
    fputs(eval_help_head, stdout);
    fputs(eval_spread_help, stdout);
    fputs("\n", stdout);
    fputs(eval_sampling_help, stdout);
    fputs(eval_help_tail, stdout);
}

static int print_list(void)
{
    size_t n = 0;
    const rl_property_info *info = rl_property_list(&n);
    for (size_t i = 0; i < n; i++) {
        printf("%s: %s%s%s%s\n", info[i].name, info[i].description,
               *info[i].reference ? " (" : "", info[i].reference, *info[i].reference ? ")" : "");
        rl_property *p = NULL;
        if (rl_property_create(info[i].name, &p) != RL_OK)
            continue;
        size_t no = 0;
        const rl_option_info *o = rl_property_options(p, &no);
        printf("  options (--set KEY=VALUE):%s\n", no ? "" : " none");
        for (size_t k = 0; k < no; k++)
            cli_print_option(stdout, &o[k]);
        rl_property_release(p);
        if (i + 1 < n)
            putchar('\n');
    }
    return RL_CLI_OK;
}

/* The caller's part of a checkpoint's key (rl_sampling_desc): the
 * command's scene and properties with all their options. */
static char *checkpoint_key(const eval_args *a)
{
    size_t len = strlen(a->scene) + strlen(a->property) + 64;
    for (int k = 0; k < a->num_sets; ++k)
        len += strlen(a->sets[k]) + 8;
    for (int k = 0; k < a->num_sets2; ++k)
        len += strlen(a->sets2[k]) + 8;
    if (a->second)
        len += strlen(a->second) + strlen(combine_ops[a->combine_op]) + 32;
    char *key = malloc(len);
    if (!key)
        return NULL;
    size_t at = (size_t)snprintf(key, len, "scene %s\nproperty %s\n", a->scene, a->property);
    for (int k = 0; k < a->num_sets; ++k)
        at += (size_t)snprintf(key + at, len - at, "set %s\n", a->sets[k]);
    if (a->second) {
        at += (size_t)snprintf(key + at, len - at, "property2 %s\nop %s\n", a->second, combine_ops[a->combine_op]);
        for (int k = 0; k < a->num_sets2; ++k)
            at += (size_t)snprintf(key + at, len - at, "set2 %s\n", a->sets2[k]);
    }
    return key;
}

static int parse_args(int argc, char **argv, eval_args *a)
{
    eval_sampling_init(&a->sampling);
    a->out = "out/eval";
    a->spread_runs = EVAL_SPREAD_RUNS;
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        int m;
        if (cli_is_help(argv[i])) {
            print_help();
            return -1;
        }
        if (strcmp(argv[i], "--list") == 0) {
            a->list = true;
            continue;
        }
        if ((m = eval_sampling_arg(argc, argv, &i, &a->sampling)) != 0 ||
            (m = eval_spread_arg(argc, argv, &i, &a->spread_runs)) != 0) {
            if (m < 0)
                return RL_CLI_USAGE;
            continue;
        }
        if ((m = cli_take_value(argc, argv, &i, "--property", &v)) > 0)
            a->property = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--out", &v)) > 0)
            a->out = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--report", &v)) > 0)
            a->report = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--checkpoint", &v)) > 0)
            a->checkpoint = v;
        else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--set", &v)) > 0) {
            if (a->num_sets == MAX_SETS)
                return cli_fail(RL_CLI_USAGE, "--set: at most %d options", MAX_SETS);
            a->sets[a->num_sets++] = v;
        } else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--set2", &v)) > 0) {
            if (a->num_sets2 == MAX_SETS)
                return cli_fail(RL_CLI_USAGE, "--set2: at most %d options", MAX_SETS);
            a->sets2[a->num_sets2++] = v;
        } else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--property2", &v)) > 0) {
            a->second = v;
        } else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--op", &v)) > 0) {
            int k = 0;
            while (combine_ops[k] && strcmp(combine_ops[k], v) != 0)
                k++;
            if (!combine_ops[k])
                return cli_fail(RL_CLI_USAGE, "--op: expected minus, ratio, min or max, got '%s'", v);
            a->combine_op = k;
            a->op = v;
        } else if (m == 0 && (m = cli_take_value(argc, argv, &i, "--validate", &v)) > 0) {
            if (!bench_parse_count("--validate", v, 1 << 20, &a->validate))
                return RL_CLI_USAGE;
        } else if (m == 0 && argv[i][0] != '-' && !a->scene)
            a->scene = argv[i];
        else if (m == 0)
            return cli_unknown_arg("eval", argv[i]);
        if (m < 0)
            return RL_CLI_USAGE;
    }
    if (a->list)
        return RL_CLI_OK;
    if (!a->scene)
        return cli_fail(RL_CLI_USAGE, "eval: no scene given (see rl eval --help)");
    if (!a->property)
        return cli_fail(RL_CLI_USAGE, "eval: no --property given (see rl eval --list)");
    if ((a->num_sets2 || a->op) && !a->second)
        return cli_fail(RL_CLI_USAGE, "%s: only with --property2", a->op ? "--op" : "--set2");
    static const char *const html[] = { ".html", ".htm", NULL };
    if (a->report && !cli_has_extension(a->report, html))
        return cli_fail(RL_CLI_USAGE, "--report: expected a .html file, got '%s'", a->report);
    return RL_CLI_OK;
}

/* Property `name` with the options `sets` applied; usage errors are exit 2. */
static int make_one(const char *name, const char *flag, const char *set_flag, const char *const *sets,
                    int num_sets, rl_property **out)
{
    rl_status st = rl_property_create(name, out);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_USAGE, st, flag);
    for (int k = 0; k < num_sets; k++) {
        char key[128];
        const char *value = NULL;
        if (!cli_split_option(set_flag, sets[k], key, sizeof key, &value)) {
            rl_property_release(*out);
            *out = NULL;
            return RL_CLI_USAGE;
        }
        st = rl_property_set(*out, key, value);
        if (st != RL_OK) {
            rl_property_release(*out);
            *out = NULL;
            return cli_fail_status(RL_CLI_USAGE, st, set_flag);
        }
    }
    return RL_CLI_OK;
}

/* The property to sample: --property with --set, or with --property2 the
 * combined property of it and the second one (Sec. 4.2.6). *first and
 * *second point at the parts (*second NULL without --combine), owned by
 * *out, for the record of their options. */
static int make_property(const eval_args *a, rl_property **out, rl_property **first, rl_property **second)
{
    rl_property *p = NULL, *q = NULL;
    int rc = make_one(a->property, "--property", "--set", a->sets, a->num_sets, &p);
    if (rc == RL_CLI_OK && a->second)
        rc = make_one(a->second, "--property2", "--set2", a->sets2, a->num_sets2, &q);
    if (rc != RL_CLI_OK) {
        rl_property_release(p);
        return rc;
    }
    *first = p;
    *second = q;
    if (!q) {
        *out = p;
        return RL_CLI_OK;
    }
    rl_status st = rl_property_create_combined((rl_property_op)a->combine_op, p, q, out);
    if (st != RL_OK)   /* p and q are released by the call */
        return cli_fail_status(RL_CLI_USAGE, st, "--property2");
    return RL_CLI_OK;
}

static cJSON *options_json(const rl_property *p)
{
    cJSON *opts = cJSON_CreateObject();
    size_t no = 0;
    const rl_option_info *o = rl_property_options(p, &no);
    for (size_t k = 0; opts && k < no; k++)
        cJSON_AddStringToObject(opts, o[k].key, rl_property_get(p, o[k].key));
    return opts;
}

typedef struct eval_result {
    char label[1024];            /* eval_property_label, or "a op b" */
    double prep_ms;              /* rl_property_commit: renderers made, their inputs sampled */
    eval_spread spread;
    cli_load load;
    rl_stats stats;
    bool validated;
    rl_stats error;
    double correlation;
    double *measured, *approximated;
    size_t num_validated;
} eval_result;

static int validate(const eval_args *a, rl_property *p, const rl_approx *ap, eval_result *r)
{
    size_t n = (size_t)a->validate;
    rl_vec3 *pos = eval_random_positions(ap, n, a->sampling.desc.seed + 0x9e3779b9ULL);
    double *approx = malloc(n * sizeof *approx), *err = malloc(n * sizeof *err);
    if (!pos || !approx || !err) {
        free(pos);
        free(approx);
        free(err);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    double *measured = NULL;
    rl_status st = eval_measure(p, pos, n, &measured, "validation");
    if (st == RL_OK)
        st = eval_errors(ap, pos, measured, n, approx, err);
    if (st == RL_OK)
        st = rl_stats_compute(err, NULL, n, &r->error);
    r->correlation = NAN;
    if (st == RL_OK && n >= 2 && rl_stats_correlation(measured, approx, n, &r->correlation) != RL_OK)
        rl_clear_error();    /* a constant property has no correlation */
    free(pos);
    free(err);
    if (st != RL_OK) {
        free(measured);
        free(approx);
        return cli_fail_status(RL_CLI_FAIL, st, "validation");
    }
    r->validated = true;
    r->measured = measured;
    r->approximated = approx;
    r->num_validated = n;
    return RL_CLI_OK;
}

static cJSON *result_json(const eval_args *a, const rl_scene *scene, const rl_property *p,
                          const rl_property *first, const rl_property *second, const rl_approx *ap,
                          const eval_result *r)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "renderlab", RL_CLI_VERSION);
    cJSON_AddItemToObject(root, "experiment", cli_experiment_json(r->load.threads));
    cJSON_AddItemToObject(root, "load", cli_load_json(&r->load));
    cJSON_AddStringToObject(root, "scene", a->scene);
    cJSON_AddItemToObject(root, "scene_stats", cli_scene_stats_json(scene));
    cJSON *dist = cli_dist_json();
    if (dist)
        cJSON_AddItemToObject(root, "dist", dist);
    cJSON *prop = cJSON_AddObjectToObject(root, "property");
    cJSON_AddStringToObject(prop, "name", rl_property_name(p));
    cJSON_AddStringToObject(prop, "label", r->label);
    const char *renderer = rl_property_get(first, "renderer");
    if (renderer)
        cJSON_AddStringToObject(prop, "renderer", renderer);
    cJSON_AddStringToObject(prop, "unit", rl_property_unit(p));
    cJSON_AddItemToObject(prop, "options", options_json(first));
    if (second) {
        cJSON_AddStringToObject(prop, "op", combine_ops[a->combine_op]);
        cJSON *o2 = cJSON_AddObjectToObject(prop, "second");
        cJSON_AddStringToObject(o2, "name", rl_property_name(second));
        cJSON_AddStringToObject(o2, "unit", rl_property_unit(second));
        cJSON_AddItemToObject(o2, "options", options_json(second));
    }
    cJSON_AddItemToObject(root, "sampling", eval_desc_json(&a->sampling.desc));
    cJSON_AddNumberToObject(root, "samples", rl_approx_sample_count(ap));
    cJSON_AddNumberToObject(root, "regions", rl_approx_region_count(ap));
    bench_add_num(root, "seconds", rl_approx_seconds(ap));
    bench_add_num(root, "samples_per_second", rl_approx_sample_count(ap) / rl_approx_seconds(ap));
    bench_add_num(root, "measure", rl_approx_measure(ap));
    cJSON_AddStringToObject(root, "measure_unit", rl_approx_dims(ap) == 2 ? "m^2" : "m^3");
    cJSON_AddItemToObject(root, "region_stats", eval_stats_json(&r->stats));
    /* Preparation (the property's renderers and their inputs) apart; the
     * values are frames: each worker renders one unmeasured frame first. */
    cJSON_AddNumberToObject(root, "prep_ms", r->prep_ms);
    cJSON_AddItemToObject(root, "spread", eval_spread_json(&r->spread));
    if (r->validated) {
        cJSON *v = cJSON_AddObjectToObject(root, "validation");
        cJSON_AddNumberToObject(v, "points", (double)r->num_validated);
        cJSON_AddItemToObject(v, "abs_error", eval_stats_json(&r->error));
        bench_add_num(v, "correlation", r->correlation);
    }
    return root;
}

static void stats_table(html_doc *h, const char *name, const rl_stats *s)
{
    static const char *const head[] = { "", "min", "25 %", "median", "75 %", "max", "mean" };
    char cells[7][32];
    const char *row[7];
    eval_stats_cells(s, cells);
    snprintf(cells[0], sizeof cells[0], "%s", name);
    for (int k = 0; k < 7; k++)
        row[k] = cells[k];
    html_table_begin(h, head, 7);
    html_table_row(h, row, 7);
    html_table_end(h);
}

static int write_report(const eval_args *a, const char *path, const rl_scene *scene,
                        const rl_property *p, const rl_approx *ap, const eval_result *r)
{
    char title[1300];
    snprintf(title, sizeof title, "rl eval: %s on %s", r->label, a->scene);
    html_doc *h = html_begin(path, title);
    if (!h)
        return RL_CLI_FAIL;
    const rl_sampling_desc *d = &a->sampling.desc;
    rl_aabb b = rl_approx_bounds(ap);
    char where[256];
    if (d->dims == 2)
        snprintf(where, sizeof where, "the slice y = %g m over x %g..%g, z %g..%g (%.4g m²)",
                 d->height, b.min.x, b.max.x, b.min.z, b.max.z, rl_approx_measure(ap));
    else
        snprintf(where, sizeof where, "the region %g,%g,%g .. %g,%g,%g (%.4g m³)", b.min.x,
                 b.min.y, b.min.z, b.max.x, b.max.y, b.max.z, rl_approx_measure(ap));
    html_para(h, "Property %s [%s] approximated over %s by %s sampling%s%s: %u samples, %u "
                 "regions, %.1f s (%.1f samples/s). Region values are weighted by their %s "
                 "(Jähn 2015, Sec. 5.6.2).",
                 rl_property_name(p), rl_property_unit(p), where,
                 d->method == RL_SAMPLING_GRID ? "regular grid" : "adaptive",
                 d->method == RL_SAMPLING_GRID ? "" : ", positions ",
                 d->method == RL_SAMPLING_GRID ? "" : eval_positions_name(d->positions),
                 rl_approx_sample_count(ap), rl_approx_region_count(ap), rl_approx_seconds(ap),
                 rl_approx_sample_count(ap) / rl_approx_seconds(ap),
                 d->dims == 2 ? "area" : "volume");
    char build[512], load[256], prep[32];
    cli_build_text(build, sizeof build);
    cli_load_text(&r->load, load, sizeof load);
    cli_format_ms(r->prep_ms, prep, sizeof prep);
    html_para(h, "Experiment: %s. Command: %s. Build: %s. %s. Preparation (prep: the "
                 "property's renderers and their inputs) %s, not in the values.",
              r->label, cli_command_line(), build, load, prep);
    if (r->spread.runs) {
        char spread[256];
        eval_spread_text(&r->spread, rl_property_unit(p), spread, sizeof spread);
        html_para(h, "Run-to-run spread (the same position measured again): %s.", spread);
    }
    html_heading(h, 2, "Distribution");
    stats_table(h, rl_property_unit(p), &r->stats);

    double *values = NULL, *weights = NULL;
    size_t n = 0;
    eval_leaf_series(ap, &values, &weights, &n);
    rl_image *top = eval_top_view(scene, b, d->height, 512);
    bool reverse = false;
    char png[4096];
    snprintf(png, sizeof png, "%s/heatmap.png", a->out);
    char *heat = eval_heatmap_svg(ap, d->height, top, rl_property_name(p), 0, 0, reverse, png);
    rl_plot_series series = { .name = rl_property_unit(p), .values = values, .weights = weights,
                              .count = n };
    char *violin = NULL, *hist = NULL, *corr = NULL;
    rl_plot_style vs = { .width = 320, .height = 420, .title = "region values",
                         .y_label = rl_property_unit(p) };
    rl_plot_style hs = { .width = 480, .height = 420, .title = "histogram",
                         .x_label = rl_property_unit(p), .y_label = "share of the region" };
    if (values && rl_plot_violin(&series, 1, &vs, &(rl_plot_output){ .svg = &violin }) != RL_OK)
        violin = NULL;
    if (values && rl_plot_histogram(&series, 1, 0, &hs, &(rl_plot_output){ .svg = &hist }) != RL_OK)
        hist = NULL;
    html_row_begin(h);
    if (heat)
        html_svg(h, heat, d->dims == 2 ? "Heat map of the regions over the scene's top "
                                            "view; dots are the sample positions."
                                          : "The regions cut by the plane y = --height.");
    html_svg(h, violin, "Violin plot (weighted kernel density) with the box plot inside.");
    html_svg(h, hist, "Histogram of the region values, weighted by area/volume.");
    html_row_end(h);
    if (r->validated) {
        html_heading(h, 2, "Validation");
        html_para(h, "The property measured at %zu uniform random positions against the "
                     "approximation there (Jähn 2015, Sec. 5.7): absolute error below; Pearson "
                     "r = %.4f.", r->num_validated, r->correlation);
        stats_table(h, "|error|", &r->error);
        rl_plot_style cs = { .width = 440, .height = 420, .title = "measured vs approximated",
                             .x_label = "measured", .y_label = "approximated" };
        if (rl_plot_correlation(r->measured, r->approximated, r->num_validated, &cs,
                                &(rl_plot_output){ .svg = &corr }) == RL_OK)
            html_svg(h, corr, NULL);
        else
            rl_clear_error();
    }
    html_para(h, "Data: approx.json (the approximation), eval.json (these numbers), "
                    "heatmap.png (the heat map for papers).");
    free(heat);
    free(violin);
    free(hist);
    free(corr);
    free(values);
    free(weights);
    rl_image_release(top);
    rl_clear_error();
    return html_end(h, path) ? RL_CLI_OK : RL_CLI_FAIL;
}

int cli_eval(int argc, char **argv)
{
    eval_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc < 0 ? RL_CLI_OK : rc;
    if (a.list)
        return print_list();
    rl_property *p = NULL, *first = NULL, *second = NULL;
    if ((rc = make_property(&a, &p, &first, &second)) != RL_CLI_OK)
        return rc;
    char report[4096], json_path[4096], approx_path[4096];
    snprintf(report, sizeof report, "%s", a.report ? a.report : "");
    if (!a.report)
        snprintf(report, sizeof report, "%s/report.html", a.out);
    snprintf(json_path, sizeof json_path, "%s/eval.json", a.out);
    snprintf(approx_path, sizeof approx_path, "%s/approx.json", a.out);
    rl_scene *scene = NULL;
    rl_approx *ap = NULL;
    rl_output_batch *batch = NULL;
    eval_result r = { 0 };
    if (!cli_make_dirs(a.out) || !cli_check_writable(report)) {
        rc = RL_CLI_FAIL;
        goto done;
    }
    eval_property_label(first, r.label, sizeof r.label);
    if (second) {
        size_t used = strlen(r.label);
        snprintf(r.label + used, sizeof r.label - used, " %s ", combine_ops[a.combine_op]);
        used = strlen(r.label);
        eval_property_label(second, r.label + used, sizeof r.label - used);
    }
    cli_load_begin(&r.load, a.sampling.desc.workers > 0 ? a.sampling.desc.workers : cli_threads());
    rl_timer phase;
    rl_timer_start(&phase);
    if ((rc = cli_load_scene(a.scene, &scene)) != RL_CLI_OK)
        goto done;
    cli_debug("timing: load %.1f ms", rl_timer_ms(&phase));
    a.sampling.model = cli_is_model_file(a.scene);
    if (!eval_sampling_finish(&a.sampling, scene)) {
        rc = RL_CLI_USAGE;
        goto done;
    }
    rl_timer_start(&phase);
    rl_status st = rl_property_commit(p, scene, a.sampling.desc.workers);
    r.prep_ms = rl_timer_ms(&phase);
    cli_debug("timing: build %.1f ms (the property's renderers and their inputs)", r.prep_ms);
    if (st != RL_OK) {
        rc = cli_fail_status(st == RL_ERR_INVALID_ARG ? RL_CLI_USAGE : RL_CLI_FAIL, st,
                                "property");
        goto done;
    }
    rl_progress *progress = NULL;
    if (rl_log_get_level() >= RL_LOG_INFO)
        rl_progress_create("sampling", stderr, &progress);
    a.sampling.desc.progress = progress ? rl_progress_update : NULL;
    a.sampling.desc.progress_user = progress;
    char *key = NULL;
    if (a.checkpoint) {
        /* What the library cannot see: the scene, and the options of the
         * two properties of a combined one. */
        if (!(key = checkpoint_key(&a))) {
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
            goto done;
        }
        a.sampling.desc.checkpoint = a.checkpoint;
        a.sampling.desc.checkpoint_key = key;
    }
    st = cli_sample_call(p, &a.sampling.desc, &ap);
    a.sampling.desc.checkpoint = a.sampling.desc.checkpoint_key = NULL;
    free(key);
    if (progress)
        rl_progress_finish(progress);
    a.sampling.desc.progress = NULL;
    if (st != RL_OK) {
        rc = cli_fail_status(RL_CLI_FAIL, st, "sampling");
        goto done;
    }
    if (!cli_dist_master())
        goto done;      /* --dist: a sampling node; the control node reports */
    cli_debug("timing: sampling %.1f ms (%u samples)", 1000.0 * rl_approx_seconds(ap), rl_approx_sample_count(ap));
    rl_clear_error();
    if ((st = eval_spread_measure(p, ap, a.spread_runs, r.label, &r.spread)) != RL_OK) {
        rc = cli_fail_status(RL_CLI_FAIL, st, "spread");
        goto done;
    }
    double *values = NULL, *weights = NULL;
    size_t n = 0;
    if (!eval_leaf_series(ap, &values, &weights, &n)) {
        rc = cli_fail(RL_CLI_FAIL, "out of memory");
        goto done;
    }
    st = rl_stats_compute(values, weights, n, &r.stats);
    free(values);
    free(weights);
    if (st != RL_OK) {
        rc = cli_fail_status(RL_CLI_FAIL, st, "statistics");
        goto done;
    }
    if (a.validate > 0 && (rc = validate(&a, p, ap, &r)) != RL_CLI_OK)
        goto done;
    cli_load_end(&r.load);
    /* approx.json, eval.json and the report go to temporaries, renamed
     * together once all three are written (rl_output_batch): a run that
     * fails at the report keeps the previous run's three files. */
    const char *approx_tmp = NULL, *json_tmp = NULL, *report_tmp = NULL;
    rl_clear_error();
    if ((st = rl_output_batch_create(&batch)) != RL_OK || (st = rl_output_batch_add(batch, approx_path, &approx_tmp)) != RL_OK ||
        (st = rl_output_batch_add(batch, json_path, &json_tmp)) != RL_OK ||
        (st = rl_output_batch_add(batch, report, &report_tmp)) != RL_OK) {
        rc = cli_fail_status(RL_CLI_FAIL, st, "outputs");
        goto done;
    }
    st = rl_approx_save_json(ap, approx_tmp);
    if (st != RL_OK) {
        rc = cli_fail_status(RL_CLI_FAIL, st, approx_path);
        goto done;
    }
    cJSON *root = result_json(&a, scene, p, first, second, ap, &r);
    bool ok = root && cli_write_json(root, json_tmp);
    cJSON_Delete(root);
    if (!ok) {
        rc = RL_CLI_FAIL;
        goto done;
    }
    if ((rc = write_report(&a, report_tmp, scene, p, ap, &r)) != RL_CLI_OK)
        goto done;
    rl_clear_error();
    if ((st = rl_output_batch_commit(batch)) != RL_OK) {
        rc = cli_fail_status(RL_CLI_FAIL, st, "outputs");
        goto done;
    }
    printf("%s on %s: %u samples, %u regions in %.1f s; %s mean %.4g, min %.4g, q25 %.4g, median %.4g, "
           "q75 %.4g, max %.4g",
           r.label, a.scene, rl_approx_sample_count(ap), rl_approx_region_count(ap),
           rl_approx_seconds(ap), rl_property_unit(p), r.stats.mean, r.stats.min, r.stats.q[1], r.stats.q[2],
           r.stats.q[3], r.stats.max);
    if (r.spread.runs) {
        char spread[256];
        eval_spread_text(&r.spread, rl_property_unit(p), spread, sizeof spread);
        printf("; spread: %s", spread);
    }
    if (r.validated)
        printf("; validation at %zu points: mean |error| %.4g, median %.4g", r.num_validated,
               r.error.mean, r.error.q[2]);
    printf("\nwrote %s, %s, %s\n", approx_path, json_path, report);
    cli_print_dist_summary(stdout);
done:
    rl_output_batch_release(batch);
    free(r.measured);
    free(r.approximated);
    rl_approx_release(ap);
    rl_property_release(p);
    rl_scene_release(scene);
    return rc;
}
