/* cli.h: what the files of the `rl` command-line tool share.
 *
 * apps/rl parses arguments, calls the public API in include/rl/ and prints;
 * every subcommand lives in its own cmd_<name>.c. Exit codes are part of the
 * interface (scripts and tests rely on them):
 *   0  success
 *   1  failed input or output (scene file, camera, output path, render)
 *   2  bad usage (unknown subcommand/flag/algorithm/option, malformed value)
 *   130  stopped by Ctrl-C (SIGINT), as a shell reports an interrupted
 *      command; rl render has then saved what it had (its summary says so)
 * Every failure prints exactly one line "rl: error: <cause>" to stderr. */
#ifndef RL_APP_CLI_H
#define RL_APP_CLI_H

#include <stdbool.h>
#include <stdio.h>

#include "rl/rl.h"

/* The version comes from project() in CMakeLists.txt. */
#ifndef RL_CLI_VERSION
#error "RL_CLI_VERSION must be defined by the build"
#endif

enum { RL_CLI_OK = 0, RL_CLI_FAIL = 1, RL_CLI_USAGE = 2, RL_CLI_INTERRUPTED = 130 };

/* Default resolution when neither --size nor the scene's camera gives one. */
#define RL_CLI_DEFAULT_WIDTH 1280
#define RL_CLI_DEFAULT_HEIGHT 720

/* Subcommands: argv[0] is the subcommand name; global flags are removed. */
int cli_scenes(int argc, char **argv);
int cli_algos(int argc, char **argv);
int cli_info(int argc, char **argv);
int cli_render(int argc, char **argv);
int cli_demo(int argc, char **argv);
int cli_bench(int argc, char **argv);
int cli_eval(int argc, char **argv);
int cli_compare(int argc, char **argv);
int cli_view(int argc, char **argv);

/* Loads a plugin and runs its rl_plugin_init() (plugin.c); 0, or the exit
 * code with the error printed. */
int cli_load_plugin(const char *path);
/* One row of an option table (rl algos, rl scenes, rl eval --list): key,
 * type, default, help, range (integers as integers) or choices. */
void cli_print_option(FILE *out, const rl_option_info *o);

/* Prints "rl: error: <message>" and returns code. */
int cli_fail(int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;
/* Prints the library's message for a failed call (rl_last_error(), or the
 * status text if the library left none) prefixed by what, and returns code. */
int cli_fail_status(int code, rl_status status, const char *what);

/* True for "-h" and "--help". */
bool cli_is_help(const char *arg);
/* Matches argv[*i] against a value-taking option: "--name VALUE" or
 * "--name=VALUE". Returns 1 and advances *i past the value on a match, 0 if
 * argv[*i] is another argument, -1 (error printed) if the value is missing. */
int cli_take_value(int argc, char **argv, int *i, const char *name, const char **value);
/* Error for an unrecognised argument of a subcommand; returns RL_CLI_USAGE. */
int cli_unknown_arg(const char *command, const char *arg);

/* Splits "KEY=VALUE" into key (a NUL-terminated copy, at most key_size - 1
 * characters) and *value (pointing into text). Prints "<what>: expected
 * KEY=VALUE, got '...'" or "<what>: key too long in '...'" and returns
 * false otherwise. For --set options of renderers and properties. */
bool cli_split_option(const char *what, const char *text, char *key, size_t key_size,
                         const char **value);
/* "WxH" with both sides in 1..RL_IMAGE_MAX_SIZE; prints the error itself. */
bool cli_parse_size(const char *text, int *width, int *height);
/* "x,y,z" of finite floats; prints the error itself (option names the flag). */
bool cli_parse_vec3(const char *option, const char *text, rl_vec3 *out);
/* A duration: a number with a unit ms, s, m or h ("500ms", "10s", "2m";
 * a bare number is seconds), finite and >= 0, into seconds. Prints nothing:
 * the caller names the flag and the range. */
bool cli_parse_duration(const char *text, double *seconds);
/* An amount of memory: a number with a unit K, M, G or T (powers of 1024,
 * "512M", "1.5G"; a bare number is bytes), finite and > 0, into bytes.
 * Prints nothing, as cli_parse_duration. */
bool cli_parse_bytes(const char *text, double *bytes);
/* MemAvailable of /proc/meminfo in bytes: what can be allocated without
 * swapping; 0 where it cannot be read (then nothing is refused on it). */
double cli_available_memory(void);
/* The memory a width x height frame of r needs, estimated before anything
 * is allocated: an image of the layers, the renderer's own buffers
 * (rl_renderer_frame_bytes) and extra_per_pixel bytes of the caller's
 * (writing, tone mapping); above max_memory (bytes; 0: MemAvailable) it
 * prints the estimate and returns RL_CLI_FAIL. */
/* cli_dist.c: the global flag --dist (rl_dist.h). begin joins the MPI job
 * (a usage of its own: one rank prints); end leaves it, aborting the job
 * when rc failed so that no rank waits for this one. cli_render_call
 * renders one frame, spread over the job's ranks under --dist;
 * cli_dist_master is false on the workers, which neither print nor write. */
int cli_dist_begin(int *argc, char ***argv);
int cli_dist_end(int rc);
bool cli_dist_master(void);
/* Whether this run is under --dist (a job of one included). */
bool cli_dist_active(void);
rl_status cli_render_call(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *img,
                          rl_render_stats *stats);
/* The job's ranks (1 without --dist) and a progressive renderer's frames
 * spread over them, every band accumulating all frames
 * (rl_dist_render_frames). */
int cli_dist_ranks(void);
rl_status cli_render_frames_call(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, long long frames,
                                 rl_image *img, rl_render_stats *stats);
/* rl_sample_property, with the job's ranks as sampling nodes under --dist
 * (the approximation on the master; NULL on the workers). */
rl_status cli_sample_call(rl_property *p, const rl_sampling_desc *desc, rl_approx **out);
/* rl_property_measure at positions chosen beforehand, over the job's ranks
 * under --dist (rl_dist_measure): the master passes the positions and gets
 * the values, the workers pass NULL, 0, NULL. Every rank calls it for
 * every property, p NULL where its commit failed, so that they stay in
 * step. */
rl_status cli_measure_call(rl_property *p, const rl_vec3 *pos, size_t count, double *values);
/* The property service (rl_dist.h) for commands whose runs the workers
 * cannot follow (rl bench culling): the master brackets its work with
 * cli_dist_service_begin and cli_dist_service_end(rc), which returns rc or
 * the end's failure; the workers call cli_dist_serve once their scene is
 * loaded, and return its code. Without --dist: no-ops (serve: RL_CLI_OK). */
void cli_dist_service_begin(void);
int cli_dist_service_end(int rc);
int cli_dist_serve(const rl_scene *scene, int threads);
/* The last distributed frame's or sampling's ranks and per-rank work (master only). */
void cli_print_dist_summary(FILE *out);
/* The same as JSON for stats files (rl bench dist reads it): ranks,
 * tasks, messages, bytes, time_ms, lost, per_rank; a run under --dist of
 * one rank too (no per_rank). NULL on workers, without --dist, or when out
 * of memory. */
struct cJSON *cli_dist_json(void);

int cli_check_frame_memory(const rl_renderer *r, int width, int height, unsigned layers, double extra_per_pixel,
                           double max_memory);

/* Extension check before any work: true when path ends in one of the
 * NULL-terminated extensions (".png", ".exr"), case-insensitively. */
bool cli_has_extension(const char *path, const char *const *extensions);
/* True when the folder that will hold path exists and is writable; prints
 * the error itself. Checked up front so a long render is not wasted. */
bool cli_check_writable(const char *path);
/* Whether two output paths name one file: the same text, or one existing
 * file reached two ways. */
bool cli_same_file(const char *a, const char *b);
/* mkdir -p; prints the error itself. */
bool cli_make_dirs(const char *dir);

/* Splits "name:k=v,k=v" into a source and built-in parameters. A path that
 * exists as a file is never split. Returns malloc'd copies (params may be
 * NULL); false only when out of memory. */
bool cli_split_source(const char *arg, char **source, char **params);

/* Loads "name[:k=v,...]" / a .json scene / a mesh file with rl_scene_load.
 * Returns RL_CLI_OK, or RL_CLI_FAIL with the error printed. */
int cli_load_scene(const char *arg, rl_scene **out);
/* True when name is one of the built-in scenes (rl scenes). */
bool cli_is_builtin(const char *name);
/* True when the SCENE argument names a model file (anything rl_scene_load
 * hands to Assimp): neither a built-in nor a .json scene. A model is one
 * object seen from outside, not a space to stand in. */
bool cli_is_model_file(const char *arg);

/* The model-file parameters (rl_model_options) as flags: --file-cameras
 * file|off, --file-lights file|off|add, --headlight, --orbit AZ,EL. They are
 * the same as "model.obj:cameras=off,...", collected as key=value text. */
typedef struct cli_model_flags {
    char params[256];
} cli_model_flags;
#define CLI_MODEL_FLAGS_HELP \
    "  --file-cameras file|off   use the model file's cameras or frame the model\n" \
    "  --file-lights file|off|add  the file's lights, the default lights, or both\n" \
    "  --headlight         a point light at the default view's eye\n" \
    "  --orbit AZ,EL       the framing camera's orbit in degrees (default 25,20)\n" \
    "  (the importer's limits: --import-timeout, --import-memory, --trusted-import; rl --help)\n"
/* 1 when argv[*i] was one of the flags (consumed, *i advanced past its
 * value), 0 when it is not, -1 after printing a usage error. */
int cli_take_model_flag(int argc, char **argv, int *i, cli_model_flags *flags);
/* cli_load_scene with the flags appended to the source's own parameters;
 * flags on a built-in or JSON scene are a usage error. */
int cli_load_scene_with(const char *arg, const cli_model_flags *flags, rl_scene **out);

/* Scene statistics and render statistics as JSON objects (for --json,
 * --stats-json and the demo report); NULL when out of memory. The render
 * statistics separate preparation from the frame: "prep_ms" is inputs_ms
 * (rl_renderer_prepare_inputs, timed by the caller) plus stats->prep_ms,
 * "frame_ms" is time_ms - stats->prep_ms. */
struct cJSON;
struct cJSON *cli_scene_stats_json(const rl_scene *scene);
struct cJSON *cli_render_stats_json(const rl_render_stats *stats, double inputs_ms);
/* Serialises item (indented) to path, atomically (rl_output.h); prints the
 * error itself. The _status form prints nothing and returns the status. */
bool cli_write_json(const struct cJSON *item, const char *path);
rl_status cli_write_json_status(const struct cJSON *item, const char *path);

/* demo_html.c: DIR/index.html from the demo's report.json object (images
 * referenced by their file names next to it); prints the error itself. */
bool cli_write_demo_html(const struct cJSON *report, const char *path);

/* One line on what a render did: "raster 64x48 cornell: prep 0.0 ms,
 * frame 1.2 ms, ..." (prep and frame as in cli_render_stats_json). */
void cli_print_summary(FILE *out, const char *algo, const char *scene, int width,
                          int height, const rl_render_stats *stats, double inputs_ms);

/* How a progressive render loop (rl render --time, --spp) ended, for its
 * summary: frames accumulated, mean samples per pixel, wall time of the
 * frames, the budget it had and why it stopped. */
typedef struct cli_accumulation {
    long long frames;
    double spp;
    double elapsed_s;
    double budget_s;           /* 0: none */
    long long target_spp;      /* 0: none */
    const char *stopped;       /* "time", "spp" or "interrupt" */
} cli_accumulation;
/* "pt 64x48 cornell: prep 1.0 ms, 12 frames, 12 spp in 0.29 s (time budget
 * 0.3 s), frame 24.1 ms on average, ..." with the counters summed over the
 * frames. */
void cli_print_accumulation_summary(FILE *out, const char *algo, const char *scene, int width, int height,
                                    const rl_render_stats *sum, double inputs_ms, const cli_accumulation *acc);

/* interrupt.c: Ctrl-C during a render. begin installs a SIGINT handler
 * that raises a flag and writes message (kept by pointer: a string
 * literal) to stderr; the second Ctrl-C ends the process as usual. A SIGINT
 * that the parent ignores stays ignored. end restores the previous
 * handling. */
void cli_interrupt_begin(const char *message);
bool cli_interrupted(void);
void cli_interrupt_end(void);

/* cli_run.c: naming the experiment in every report. main() records the
 * command line (global flags included) before anything else. */
void cli_set_command_line(int argc, char **argv);
const char *cli_command_line(void);
/* Threads a parallel part uses by default (omp_get_max_threads). */
int cli_threads(void);
/* "renderlab 0.1.0, release, GCC 12.2.0, Embree": version, build type,
 * sanitizer, compiler, optional parts. */
void cli_build_text(char *out, size_t size);
/* {uname, cpu, nproc, threads, loadavg_at_end}: the machine of a record. */
struct cJSON *cli_machine_json(int threads);
/* {command, build, machine}. */
struct cJSON *cli_experiment_json(int threads);

/* The load average (getloadavg) at the start and the end of a timed run;
 * begin and end warn on stderr when the 1-minute load exceeds threads. */
typedef struct cli_load {
    double start[3], end[3];          /* 1, 5, 15 minutes */
    bool known_start, known_end;
    int threads;
} cli_load;
void cli_load_begin(cli_load *l, int threads);
void cli_load_end(cli_load *l);
struct cJSON *cli_load_json(const cli_load *l);   /* {start, end, threads, exceeds_threads} */
void cli_load_text(const cli_load *l, char *out, size_t size);   /* one sentence for reports */

/* "12.3 ms", or "48.2 s" from 10 s on. */
void cli_format_ms(double ms, char *out, size_t size);
/* "rl: debug: ..." on stderr under -v (the phase timings), else nothing. */
void cli_debug(const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;
/* "did you mean 'NAME'? " when one of names is a likely typo of typed
 * (rl_suggest), else ""; written into buf. */
const char *cli_did_you_mean(const char *typed, const char *const *names, size_t count, char *buf,
                             size_t size);

/* Extra layers (layers.c). depth: EXR keeps the raw eye-space depth in
 * R,G,B (alpha 0 where nothing was hit), PNG maps it to grey with the
 * nearest surface white and the background black. ids: a PNG with each
 * object ID hashed to a colour, black where nothing was hit. */
rl_status cli_write_depth(const rl_image *img, const char *path);
rl_status cli_write_ids(const rl_image *img, const char *path);
/* The same pictures as linear colour in out (width x height of img), for
 * display: false where img lacks the layer. */
typedef enum cli_layer { CLI_LAYER_COLOR, CLI_LAYER_DEPTH, CLI_LAYER_IDS } cli_layer;
bool cli_layer_picture(const rl_image *img, cli_layer layer, rl_vec4 *out);

#endif
