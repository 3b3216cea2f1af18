/* eval_common.h: what `rl eval`, `rl compare` and `rl bench sampling`
 * share: the sampling options, the region defaults, the scene top view
 * under heat maps, region values as weighted series, validation at random
 * points, and the JSON/HTML pieces of their reports. */
#ifndef RL_APP_EVAL_COMMON_H
#define RL_APP_EVAL_COMMON_H

#include <stdbool.h>
#include <stddef.h>

#include "html.h"
#include "rl/rl.h"

struct cJSON;

typedef struct eval_sampling {
    rl_sampling_desc desc;
    bool has_region, has_height, has_min_side;
    bool model;          /* a model file (cli_is_model_file): default region around it */
} eval_sampling;

/* The help lines of the shared options. */
extern const char eval_sampling_help[];

/* Defaults before parsing: 2-D, 256 samples, blue noise with corners. */
void eval_sampling_init(eval_sampling *s);
/* Takes one sampling option at argv[*i]: 1 taken (and *i advanced past its
 * value), 0 not a sampling option, -1 bad value (error printed). */
int eval_sampling_arg(int argc, char **argv, int *i, eval_sampling *s);
/* Fills what depends on the scene: the region (its bounds; for a model,
 * eval_model_region), the slice height (the middle of the region's y
 * extent; for a model, the region's side facing it), min_side (1 m, or 1/64 of
 * the longest side when that is smaller, so that small scenes refine).
 * Prints the error and returns false for a region outside the scene or a
 * height outside the region (neither is checked for a model, whose region
 * lies outside it on purpose). */
bool eval_sampling_finish(eval_sampling *s, const rl_scene *scene);

/* The default region of a model: a box outside the model's bounds on the
 * side of its default view, holding the framing camera's orbit in x and z
 * (see eval_common.c for why). *height receives the 2-D slice: the side of
 * the box that faces the model. False when the scene cannot be framed. */
bool eval_model_region(const rl_scene *scene, rl_aabb *region, float *height);

/* A near-orthographic view from high above of the region's x/z extent at
 * the slice height (raster renderer, flat shading), `width` pixels wide;
 * row 0 is the -z side. NULL when it fails (the heat map is then drawn
 * without it). */
rl_image *eval_top_view(const rl_scene *scene, rl_aabb region, float height, int width);

/* Leaf values and their weights (area or volume) of an approximation;
 * malloc'd arrays; false when out of memory. */
bool eval_leaf_series(const rl_approx *a, double **values, double **weights, size_t *n);

/* Heat map SVG of the approximation (2-D: every leaf; 3-D: the leaves cut
 * by the plane y = height), x right and -z up, over the top view (may be
 * NULL), with the sample positions. vmin == vmax: the data's range. With
 * png_path the same map is also written there as PNG. NULL (error printed)
 * on failure. */
char *eval_heatmap_svg(const rl_approx *a, float height, const rl_image *top,
                          const char *title, double vmin, double vmax, bool reverse,
                          const char *png_path);

/* Uniform random positions in the sampled region (2-D: on the slice),
 * seeded; malloc'd, count entries. */
rl_vec3 *eval_random_positions(const rl_approx *a, size_t count, uint64_t seed);
/* rl_property_measure into a malloc'd array, with a progress bar named
 * progress_label (NULL: none). */
rl_status eval_measure(rl_property *p, const rl_vec3 *pos, size_t count, double **values,
                          const char *progress_label);

/* The approximation at every position (into approx, may be NULL) and its
 * absolute error against measured (into err): the validation of Sec. 5.7. */
rl_status eval_errors(const rl_approx *a, const rl_vec3 *pos, const double *measured,
                         size_t count, double *approx, double *err);

struct cJSON *eval_stats_json(const rl_stats *s);
struct cJSON *eval_desc_json(const rl_sampling_desc *d);
const char *eval_positions_name(rl_position_variant v);
/* "measure" or "diameter" (rl_quality_size), for options and records. */
const char *eval_quality_size_name(rl_quality_size q);
/* Parses the value of `option` as a quality size; false after printing a
 * usage error. */
bool eval_parse_quality_size(const char *option, const char *text, rl_quality_size *out);
/* The value of `option` (--visibility-backend of rl compare and rl bench
 * sampling) as the visibility property's backend, software or gl, into
 * *out (a static string); false after printing a usage error. */
bool eval_parse_visibility_backend(const char *option, const char *text, const char **out);
/* Five-number summary plus mean as table cells (formatted into buf). */
void eval_stats_cells(const rl_stats *s, char buf[7][32]);

/* "time (renderer=whitted, repeats=3)": the property's name with its
 * renderer (when it has one) and every option set away from its default,
 * so that a report names the experiment. */
void eval_property_label(const rl_property *p, char *out, size_t size);

/* How far a timing moves when nothing but the run changes: the property
 * measured `runs` times at one position (the first sample's) after the
 * measurement proper. Times of one renderer three times over gave 18, 35
 * and 19 ms on a busy machine; the spread says how far to trust a
 * difference. */
typedef struct eval_spread {
    int runs;                    /* 0: not measured */
    rl_vec3 pos;
    rl_stats stats;              /* of the runs: min, quartiles, median, max */
} eval_spread;
#define EVAL_SPREAD_RUNS 5
extern const char eval_spread_help[];
/* Takes "--spread N" (0..100) at argv[*i]: 1 taken, 0 not it, -1 bad
 * value (printed). */
int eval_spread_arg(int argc, char **argv, int *i, int *runs);
/* Measures the spread when p is a timing (RL_PROPERTY_EXCLUSIVE) and runs
 * > 0; otherwise out->runs = 0. The measurement's status (its message in
 * rl_last_error()). */
rl_status eval_spread_measure(rl_property *p, const rl_approx *a, int runs, const char *label, eval_spread *out);
struct cJSON *eval_spread_json(const eval_spread *s);   /* JSON null when not measured */
/* "5 runs at (x, y, z): min 18.2, median 19.0, max 35.1 ms (IQR 0.4)". */
void eval_spread_text(const eval_spread *s, const char *unit, char *out, size_t size);

#endif
