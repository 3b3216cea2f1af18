/* cmd_render.c: `rl render SCENE --out FILE ...`: one frame of one scene
 * with one renderer, plus optional depth/ID layers and a stats file. A
 * progressive renderer (pt) renders frames into its accumulation until a
 * time budget or a sample count is reached, writes previews to --out on the
 * way, and on Ctrl-C saves what it has.
 *
 * Everything that can be checked without rendering is checked first, in the
 * order of cost: arguments and sizes (exit 2), output formats (2), output
 * folders (1), renderer name and options (2), then the scene (1) and its
 * camera (1). A long render is never wasted on a typo in a path. */
#include "cli.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl_options.h"
#include "rl/rl_pt.h"

static const char render_help[] =
    "usage: rl render SCENE --out FILE.png|FILE.exr [options]\n"
    "\n"
    "Renders one frame and prints a one-line summary (algorithm, size, times,\n"
    "triangles rasterized, pixels written, rays by type). Times: prep is the\n"
    "one-time preparation (sampled inputs, structures built for the scene),\n"
    "frame the rest of the frame; -v adds the phases load, build and frame.\n"
    "\n"
    "Progressive renderers (pt) add frames to one accumulation until --time is\n"
    "spent or --spp is reached; with neither (and no --set spp or accumulate)\n"
    "they take their default budget (pt: 10 s, see rl algos). The summary then\n"
    "gives frames, samples per pixel and the time. Ctrl-C stops, saves what\n"
    "has accumulated and exits 130; a second Ctrl-C aborts without saving.\n"
    "Under mpirun with --dist (docs/distributed.md) every band renders all the\n"
    "frames, so several ranks need --spp (no --time, no --preview).\n"
    "\n"
    "SCENE  a built-in name (see rl scenes), optionally with parameters\n"
    "       (cornell-teapot:triangles=70000), a .json scene or a mesh file\n"
    "\n"
    "options:\n"
    "  --out FILE          colour output, .png (8-bit sRGB) or .exr (half float)\n"
    "  --algo NAME         renderer (see rl algos); default raster\n"
    "  --size WxH          resolution; default the camera's, else 1280x720\n"
    "  --camera NAME       a camera of the scene; default its first one\n"
    "  --eye x,y,z         override the camera position\n"
    "  --target x,y,z      override the point looked at\n"
    "  --up x,y,z          override the up vector\n"
    "  --fov DEG           override the vertical field of view\n"
    "  --set KEY=VALUE     renderer option, repeatable (see rl algos)\n"
    "  --tonemap OP        PNG: none (clamp; default), reinhard (L/(1+L) on\n"
    "                      luminance) or aces (Narkowicz 2015 fit)\n"
    "  --exposure EV       PNG: scale by 2^EV before the tone mapping; default 0\n"
    "                      (EXR output stays linear: neither applies to it)\n"
    "  --depth-out FILE    depth layer: .exr raw eye-space depth in R,G,B,\n"
    "                      .png grey (nearest white, background black)\n"
    "  --id-out FILE.png   object IDs in false colour (background black)\n"
    "  --stats-json FILE   render and scene statistics as JSON\n"
    "  --max-memory SIZE   refuse a frame estimated to need more (e.g. 8G, 512M);\n"
    "                      default the available memory (MemAvailable)\n"
    "\n"
    "progressive renderers (pt):\n"
    "  --time DURATION     time budget, e.g. 500ms, 10s, 2m (at least one frame)\n"
    "  --spp N             stop at N samples per pixel (reproducible, unlike --time);\n"
    "                      with --time, whichever comes first\n"
    "  --preview SECONDS   write the image so far to --out this often (through a\n"
    "                      temporary file and a rename); default 5s, 0: never\n"
    "\n"
    "model files (the same as SCENE:cameras=off,lights=add,...; see rl scenes):\n"
    CLI_MODEL_FLAGS_HELP
    "\n"
    "camera paths (the scene's \"camera_path\", e.g. cluster's or a JSON scene's):\n"
    "  --camera-path       render the path's frames instead of one camera; --out\n"
    "                      (and --depth-out, --id-out) then hold one integer\n"
    "                      conversion for the frame number: frames/%%04d.png\n"
    "  --frames N          N frames spread evenly over the path (first and last key)\n"
    "  --fps F             frames at 1/F s steps from the first key; default 25\n"
    "                      (--stats-json: one entry per frame)\n"
    "\n"
    "example:\n"
    "  rl render cornell --algo raster --size 640x480 --out cornell.png \\\n"
    "     --set raster.shading=flat --depth-out depth.exr --stats-json stats.json\n"
    "  rl render cornell --algo pt --time 30s --tonemap aces --out pt.png\n";

typedef struct render_args {
    const char *scene, *algo, *out, *camera, *depth_out, *id_out, *stats_json;
    bool has_size, has_eye, has_target, has_up, has_fov;
    bool camera_path;           /* --camera-path */
    cli_model_flags model;      /* --file-cameras, --file-lights, --headlight, --orbit */
    long long frames;           /* --frames, 0: from --fps */
    double fps;                 /* --fps, 0: default */
    int width, height;
    rl_vec3 eye, target, up;
    float fov_deg;
    const char **sets; /* --set values, pointers into argv */
    int num_sets;
    double time_s;              /* --time, 0: none */
    long long spp;              /* --spp, 0: none */
    double preview_s;           /* --preview, < 0: the default */
    rl_tonemap_desc tonemap;    /* --tonemap, --exposure */
    bool has_tonemap;           /* either was given */
    double max_memory;          /* --max-memory in bytes, 0: MemAvailable */
} render_args;

/* Previews of a progressive render: often enough to watch it converge,
 * rarely enough that encoding them costs little next to the frames. */
#define PREVIEW_DEFAULT_S 5.0
/* The longest budget and preview interval: a week bounds a typo. */
#define DURATION_MAX_S 604800.0

/* Whether name holds exactly one conversion %d, %Nd or %0Nd (N < 10) and no
 * other %: a frame file pattern that snprintf fills safely. */
static bool frame_pattern_ok(const char *name)
{
    int conversions = 0;
    for (const char *p = name; *p; ++p) {
        if (*p != '%')
            continue;
        ++p;
        if (*p == '0')
            ++p;
        if (*p >= '1' && *p <= '9')
            ++p;
        if (*p != 'd')
            return false;
        ++conversions;
    }
    return conversions == 1;
}

/* The file of frame i for a pattern that passed frame_pattern_ok. */
static bool frame_name(const char *pattern, long long i, char *out, size_t size)
{
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
#endif
    int n = snprintf(out, size, pattern, (int)i);
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
    return n > 0 && (size_t)n < size;
}

/* Returns RL_CLI_OK, an exit code, or -1 when --help was printed. */
static int parse_args(int argc, char **argv, render_args *a)
{
    for (int i = 1; i < argc; i++) {
        const char *v = NULL;
        int m;
        if (cli_is_help(argv[i])) {
            fputs(render_help, stdout);
            return -1;
        }
#define VALUE(name) ((m = cli_take_value(argc, argv, &i, name, &v)) != 0)
        if (VALUE("--out")) a->out = v;
        else if (VALUE("--algo")) a->algo = v;
        else if (VALUE("--camera")) a->camera = v;
        else if (VALUE("--depth-out")) a->depth_out = v;
        else if (VALUE("--id-out")) a->id_out = v;
        else if (VALUE("--stats-json")) a->stats_json = v;
        else if (VALUE("--set")) a->sets[a->num_sets++] = v;
        else if (strcmp(argv[i], "--camera-path") == 0) {
            a->camera_path = true;
            m = 0;
        } else if (VALUE("--frames")) {
            if (m > 0 && (!rl_parse_int(v, &a->frames) || a->frames < 1 || a->frames > 1000000))
                return cli_fail(RL_CLI_USAGE, "--frames: expected a count in [1, 1000000], got '%s'", v);
        } else if (VALUE("--fps")) {
            if (m > 0 && (!rl_parse_float(v, &a->fps) || !(a->fps > 0.0) || a->fps > 10000.0))
                return cli_fail(RL_CLI_USAGE, "--fps: expected frames per second in (0, 10000], got '%s'", v);
        }
        else if (VALUE("--max-memory")) {
            if (m > 0 && !cli_parse_bytes(v, &a->max_memory))
                return cli_fail(RL_CLI_USAGE, "--max-memory: expected an amount such as 8G or 512M, got '%s'", v);
        }
        else if (VALUE("--size")) {
            if (m > 0 && !cli_parse_size(v, &a->width, &a->height))
                return RL_CLI_USAGE;
            a->has_size = true;
        } else if (VALUE("--eye")) {
            if (m > 0 && !cli_parse_vec3("--eye", v, &a->eye))
                return RL_CLI_USAGE;
            a->has_eye = true;
        } else if (VALUE("--target")) {
            if (m > 0 && !cli_parse_vec3("--target", v, &a->target))
                return RL_CLI_USAGE;
            a->has_target = true;
        } else if (VALUE("--up")) {
            if (m > 0 && !cli_parse_vec3("--up", v, &a->up))
                return RL_CLI_USAGE;
            a->has_up = true;
        } else if (VALUE("--fov")) {
            double fov = 0.0;
            if (m > 0 && (!rl_parse_float(v, &fov) || fov <= 0.0 || fov >= 180.0))
                return cli_fail(RL_CLI_USAGE, "--fov: expected degrees in (0, 180), got '%s'",
                                   v);
            a->fov_deg = (float)fov;
            a->has_fov = true;
        } else if (VALUE("--time")) {
            if (m > 0 && (!cli_parse_duration(v, &a->time_s) || !(a->time_s > 0.0) || a->time_s > DURATION_MAX_S))
                return cli_fail(RL_CLI_USAGE, "--time: expected a duration such as 500ms, 10s or 2m "
                                              "(above 0, at most a week), got '%s'", v);
        } else if (VALUE("--spp")) {
            if (m > 0 && (!rl_parse_int(v, &a->spp) || a->spp < 1 || a->spp > 1000000000))
                return cli_fail(RL_CLI_USAGE, "--spp: expected samples per pixel in [1, 1000000000], got '%s'", v);
        } else if (VALUE("--preview")) {
            if (m > 0 && (!cli_parse_duration(v, &a->preview_s) || a->preview_s > DURATION_MAX_S))
                return cli_fail(RL_CLI_USAGE, "--preview: expected an interval such as 5s or 500ms (0: no "
                                              "previews), got '%s'", v);
        } else if (VALUE("--exposure")) {
            if (m > 0 && (!rl_parse_float(v, &a->tonemap.exposure_ev) || !(fabs(a->tonemap.exposure_ev) <= 64.0)))
                return cli_fail(RL_CLI_USAGE, "--exposure: expected stops in [-64, 64], got '%s'", v);
            a->has_tonemap = true;
        } else if (VALUE("--tonemap")) {
            if (m > 0 && rl_tonemap_parse(v, &a->tonemap.op) != RL_OK) {
                rl_clear_error();
                return cli_fail(RL_CLI_USAGE, "--tonemap: expected none, reinhard or aces, got '%s'", v);
            }
            a->has_tonemap = true;
        } else if ((m = cli_take_model_flag(argc, argv, &i, &a->model)) != 0) {
        } else if (argv[i][0] == '-' || a->scene)
            return cli_unknown_arg("render", argv[i]);
        else
            a->scene = argv[i];
#undef VALUE
        if (m < 0)
            return RL_CLI_USAGE; /* missing value, already reported */
    }
    if (!a->scene)
        return cli_fail(RL_CLI_USAGE, "render: missing SCENE (see rl render --help)");
    if (!a->out)
        return cli_fail(RL_CLI_USAGE, "render: missing --out FILE.png|FILE.exr");
    for (int k = 0; k < a->num_sets; k++) {
        const char *eq = strchr(a->sets[k], '=');
        if (!eq || eq == a->sets[k])
            return cli_fail(RL_CLI_USAGE, "--set: expected KEY=VALUE, got '%s'", a->sets[k]);
    }
    /* Two outputs in one file: the second write would silently replace the
     * first (issue 34). */
    const char *outs[] = { a->out, a->depth_out, a->id_out, a->stats_json };
    const char *out_flags[] = { "--out", "--depth-out", "--id-out", "--stats-json" };
    for (int x = 0; x < 4; ++x)
        for (int y = x + 1; y < 4; ++y)
            if (outs[x] && outs[y] && cli_same_file(outs[x], outs[y]))
                return cli_fail(RL_CLI_USAGE, "%s and %s name the same file '%s'", out_flags[x], out_flags[y],
                                outs[y]);
    if (a->has_up && !(rl_length2(a->up) > 0.0f))
        return cli_fail(RL_CLI_USAGE, "--up: a direction, not the zero vector");
    if (!a->camera_path && (a->frames || a->fps > 0.0))
        return cli_fail(RL_CLI_USAGE, "--frames and --fps go with --camera-path");
    if (a->camera_path && (a->time_s > 0.0 || a->spp || a->preview_s >= 0.0))
        return cli_fail(RL_CLI_USAGE, "--time, --spp and --preview render one view progressively; they do not go "
                                      "with --camera-path");
    if (a->camera_path) {
        if (a->frames && a->fps > 0.0)
            return cli_fail(RL_CLI_USAGE, "--frames and --fps: give one of them");
        if (a->camera || a->has_eye || a->has_target || a->has_up || a->has_fov)
            return cli_fail(RL_CLI_USAGE, "--camera-path: the path sets the camera (no --camera, --eye, "
                                          "--target, --up, --fov)");
        const char *patterns[] = { a->out, a->depth_out, a->id_out };
        const char *names[] = { "--out", "--depth-out", "--id-out" };
        for (int k = 0; k < 3; k++)
            if (patterns[k] && !frame_pattern_ok(patterns[k]))
                return cli_fail(RL_CLI_USAGE, "%s %s: with --camera-path the name holds one integer conversion "
                                              "for the frame number and no other %%, e.g. frames/%%04d.png",
                                names[k], patterns[k]);
    }
    return RL_CLI_OK;
}

/* Output formats and folders, before anything expensive. */
static int check_outputs(const render_args *a)
{
    static const char *const image_ext[] = { ".png", ".exr", NULL };
    static const char *const png_ext[] = { ".png", NULL };
    if (!cli_has_extension(a->out, image_ext))
        return cli_fail(RL_CLI_USAGE, "%s: unsupported output format (use .png or .exr)",
                           a->out);
    if (a->depth_out && !cli_has_extension(a->depth_out, image_ext))
        return cli_fail(RL_CLI_USAGE, "%s: unsupported depth format (use .png or .exr)",
                           a->depth_out);
    if (a->id_out && !cli_has_extension(a->id_out, png_ext))
        return cli_fail(RL_CLI_USAGE, "%s: unsupported ID format (use .png)", a->id_out);
    if (a->has_tonemap && !cli_has_extension(a->out, png_ext))
        return cli_fail(RL_CLI_USAGE, "%s: --tonemap and --exposure are for PNG output (EXR stays linear)", a->out);
    const char *paths[] = { a->out, a->depth_out, a->id_out, a->stats_json };
    for (size_t k = 0; k < sizeof paths / sizeof paths[0]; k++)
        if (paths[k] && !cli_check_writable(paths[k]))
            return RL_CLI_FAIL;
    return RL_CLI_OK;
}

static int create_renderer(const render_args *a, rl_renderer **out)
{
    rl_clear_error();
    rl_status st = rl_renderer_create(a->algo, out);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_USAGE, st, NULL);
    for (int k = 0; k < a->num_sets; k++) {
        char key[128];
        const char *value = NULL;
        if (!cli_split_option("--set", a->sets[k], key, sizeof key, &value))
            return RL_CLI_USAGE;
        rl_clear_error();
        st = rl_renderer_set(*out, key, value);
        if (st != RL_OK)
            return cli_fail_status(RL_CLI_USAGE, st, "--set");
    }
    return RL_CLI_OK;
}

/* The scene's camera with the command-line overrides applied. */
static int choose_camera(const render_args *a, const rl_scene *scene, rl_camera *cam)
{
    rl_clear_error();
    rl_status st = rl_scene_get_camera(scene, a->camera, cam);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, "--camera");
    const rl_scene_data *data = rl_scene_get_data(scene);
    bool scene_has_cameras = data && data->num_cameras > 0;
    if (a->has_eye) cam->eye = a->eye;
    if (a->has_target) cam->target = a->target;
    if (a->has_up) cam->up = a->up;
    if (a->has_fov) cam->fov_deg = a->fov_deg;
    if (a->has_size) {
        cam->width = a->width;
        cam->height = a->height;
    } else if (!scene_has_cameras || cam->width <= 0 || cam->height <= 0) {
        /* The camera the library frames for a scene without one carries
         * only the library's default size, not a choice of the scene's. */
        cam->width = RL_CLI_DEFAULT_WIDTH;
        cam->height = RL_CLI_DEFAULT_HEIGHT;
    }
    if (!scene_has_cameras && !a->has_eye && !a->has_target && !a->has_up && !a->has_fov) {
        /* The framing fits the model to the image's aspect ratio, which is
         * only known now. */
        rl_camera fit;
        if (rl_scene_fit_camera(scene, cam->width, cam->height, &fit) == RL_OK)
            *cam = fit;
    }
    *cam = rl_camera_resolve(cam);
    rl_clear_error();
    st = rl_camera_validate(cam);
    if (st != RL_OK && !a->has_eye && !a->has_target && !a->has_up && !a->has_fov)
        /* Nothing of it was the user's: the scene's own camera, or the
         * framing of a model whose coordinates are near the float limit. */
        return cli_fail(RL_CLI_FAIL, "%s: no usable camera for this scene (%s; are its coordinates within "
                        "float range?)", a->scene, rl_last_error());
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_USAGE, st, "camera");
    return RL_CLI_OK;
}

/* The memory a frame of the camera's size needs, estimated before anything
 * is allocated: the image's layers, the renderer's own buffers
 * (rl_renderer_frame_bytes) and the writing (the encoder's pixels, 8 bytes
 * for EXR, 4 for PNG, and a tone-mapped copy when asked). A 16384 x 16384
 * frame took 4.2-5.3 GB with no warning (measured on cornell, PNG: raster
 * 5.3 GB peak, estimated 7.0 GiB; vt 9.5 GB, estimated 10.0 GiB); above
 * --max-memory, or else the available memory, it is refused with the
 * estimate. */
static int check_frame_memory(const render_args *a, const rl_renderer *r, const rl_camera *cam)
{
    unsigned layers = RL_LAYER_COLOR | (a->depth_out ? RL_LAYER_DEPTH : 0u) | (a->id_out ? RL_LAYER_ID : 0u);
    return cli_check_frame_memory(r, cam->width, cam->height, layers,
                                  8.0 + (a->has_tonemap ? sizeof(rl_vec4) : 0.0), a->max_memory);
}

/* Writes img's colour to path, tone mapped for PNG when asked. Previews
 * name --out itself: the writers go through a temporary file and a rename
 * (rl_output.h), so whoever watches --out (a viewer during a long render)
 * never sees half a file, and a failed write leaves the old one. */
static rl_status write_color(const render_args *a, const rl_image *img, const char *path)
{
    const rl_image *src = img;
    rl_image *mapped = NULL;
    rl_status st = RL_OK;
    if (a->tonemap.op != RL_TONEMAP_NONE || a->tonemap.exposure_ev != 0.0) {
        /* A copy: the frame may be accumulated further, and stays linear. */
        st = rl_image_create(img->width, img->height, RL_LAYER_COLOR, &mapped);
        if (st == RL_OK) {
            memcpy(mapped->color, img->color, (size_t)img->width * (size_t)img->height * sizeof *img->color);
            st = rl_image_tonemap(mapped, &a->tonemap);
            src = mapped;
        }
    }
    if (st == RL_OK)
        st = rl_image_write(src, path);
    rl_image_release(mapped);
    return st;
}

static rl_status write_stats_json(const render_args *a, const rl_scene *scene, const rl_image *img,
                                  const rl_render_stats *stats, double inputs_ms, const cli_accumulation *acc,
                                  const char *path)
{
    cJSON *obj = cli_render_stats_json(stats, inputs_ms);
    if (!obj)
        return RL_ERR_OUT_OF_MEMORY;
    cJSON_AddStringToObject(obj, "algorithm", a->algo);
    cJSON_AddStringToObject(obj, "scene", a->scene);
    cJSON_AddNumberToObject(obj, "width", img->width);
    cJSON_AddNumberToObject(obj, "height", img->height);
    cJSON_AddStringToObject(obj, "file", a->out);
    cJSON *dist = cli_dist_json();
    if (dist)
        cJSON_AddItemToObject(obj, "dist", dist);
    if (a->has_tonemap) {
        cJSON_AddStringToObject(obj, "tonemap", rl_tonemap_name(a->tonemap.op));
        cJSON_AddNumberToObject(obj, "exposure_ev", a->tonemap.exposure_ev);
    }
    if (acc) {
        /* The counters above are summed over the frames. */
        cJSON_AddNumberToObject(obj, "frames", (double)acc->frames);
        cJSON_AddNumberToObject(obj, "spp", acc->spp);
        cJSON_AddNumberToObject(obj, "elapsed_s", acc->elapsed_s);
        cJSON_AddNumberToObject(obj, "time_budget_s", acc->budget_s);
        cJSON_AddNumberToObject(obj, "target_spp", (double)acc->target_spp);
        cJSON_AddStringToObject(obj, "stopped", acc->stopped);
    }
    cJSON *scene_stats = cli_scene_stats_json(scene);
    if (scene_stats)
        cJSON_AddItemToObject(obj, "scene_stats", scene_stats);
    rl_status st = cli_write_json_status(obj, path);
    cJSON_Delete(obj);
    return st;
}

/* Every output of the run (--out, --depth-out, --id-out, --stats-json) is
 * written to a temporary beside it, and all are renamed together once each
 * one was written (rl_output_batch): a run whose depth image fails keeps
 * the previous --out as well. acc: how a progressive loop ended, for the
 * stats file; NULL for one frame. */
static int write_outputs(const render_args *a, const rl_scene *scene, const rl_image *img,
                         const rl_render_stats *stats, double inputs_ms, const cli_accumulation *acc)
{
    rl_output_batch *batch = NULL;
    const char *what = a->out, *tmp = NULL;
    rl_clear_error();
    rl_status st = rl_output_batch_create(&batch);
    if (st == RL_OK && (st = rl_output_batch_add(batch, what, &tmp)) == RL_OK)
        st = write_color(a, img, tmp);
    if (st == RL_OK && a->depth_out && (st = rl_output_batch_add(batch, what = a->depth_out, &tmp)) == RL_OK)
        st = cli_write_depth(img, tmp);
    if (st == RL_OK && a->id_out && (st = rl_output_batch_add(batch, what = a->id_out, &tmp)) == RL_OK)
        st = cli_write_ids(img, tmp);
    if (st == RL_OK && a->stats_json && (st = rl_output_batch_add(batch, what = a->stats_json, &tmp)) == RL_OK)
        st = write_stats_json(a, scene, img, stats, inputs_ms, acc, tmp);
    if (st == RL_OK) {
        what = "outputs";
        st = rl_output_batch_commit(batch);
    }
    rl_output_batch_release(batch);
    return st == RL_OK ? RL_CLI_OK : cli_fail_status(RL_CLI_FAIL, st, what);
}

/* How many frames: one, or a progressive loop with its limits. */
typedef struct loop_plan {
    bool loop;
    double budget_s;          /* 0: none */
    long long target_spp;     /* 0: none */
    double preview_s;         /* 0: no previews */
} loop_plan;

static const rl_renderer_info *renderer_info(const char *name)
{
    size_t n = 0;
    const rl_renderer_info *list = rl_renderer_list(&n);
    for (size_t i = 0; i < n; i++)
        if (strcmp(list[i].name, name) == 0)
            return &list[i];
    return NULL;
}

/* Whether --set chose the samples of the frame ("spp") or switched the
 * accumulation off: the user asked for one frame of a given quality, as
 * before budgets existed, so no default budget is added. */
static bool sets_frame_quality(const render_args *a, const char *algo)
{
    size_t prefix = strlen(algo);
    for (int k = 0; k < a->num_sets; k++) {
        const char *key = a->sets[k];
        if (strncmp(key, algo, prefix) == 0 && key[prefix] == '.')
            key += prefix + 1;
        size_t len = strcspn(key, "=");
        if ((len == 3 && strncmp(key, "spp", 3) == 0) || (len == 10 && strncmp(key, "accumulate", 10) == 0))
            return true;
    }
    return false;
}

/* Before the scene is loaded, so that a flag that cannot apply costs nothing. */
static int plan_loop(const render_args *a, const rl_renderer *r, loop_plan *p)
{
    const char *name = rl_renderer_name(r);
    const rl_renderer_info *info = renderer_info(name);
    bool progressive = info && info->progressive;
    if (!progressive && (a->time_s > 0.0 || a->spp || a->preview_s >= 0.0))
        return cli_fail(RL_CLI_USAGE, "--time, --spp and --preview need a progressive renderer such as pt; %s "
                                      "renders its image in one frame", name);
    p->budget_s = a->time_s;
    p->target_spp = a->spp;
    if (progressive && !p->budget_s && !p->target_spp && !sets_frame_quality(a, name))
        p->budget_s = info->default_time_s;
    p->loop = p->budget_s > 0.0 || p->target_spp > 0;
    p->preview_s = !p->loop ? 0.0 : a->preview_s >= 0.0 ? a->preview_s : PREVIEW_DEFAULT_S;
    if (p->loop && cli_dist_ranks() > 1) {
        /* Every band renders all the frames (rl_dist_render_frames), so
         * their number is fixed before the bands go out, and the image
         * exists only when the last band is back. */
        if (a->time_s > 0.0 || !p->target_spp)
            return cli_fail(RL_CLI_USAGE, "--dist: %s over several ranks renders a fixed number of samples: give "
                            "--spp N (or --set spp=N for one frame), not %s", name,
                            a->time_s > 0.0 ? "--time" : "the default time budget");
        if (a->preview_s >= 0.0)
            return cli_fail(RL_CLI_USAGE, "--dist: no --preview over several ranks (the image is whole only at "
                                          "the end)");
        p->preview_s = 0.0;
    }
    return RL_CLI_OK;
}

/* The renderer's progress callback during the loop: Ctrl-C cancels the
 * frame; the bar shows the share of the budget (or of the samples) spent. */
typedef struct loop_progress {
    rl_progress *bar;
    const loop_plan *plan;
    double start_s;
    double spp, frame_spp;    /* accumulated before this frame; the last frame's */
} loop_progress;

static bool on_progress(void *user, double done)
{
    loop_progress *lp = user;
    if (cli_interrupted())
        return false;
    if (!lp->bar)
        return true;
    double share = done;
    if (lp->plan->loop) {
        share = 0.0;
        if (lp->plan->budget_s > 0.0)
            share = (rl_time_s() - lp->start_s) / lp->plan->budget_s;
        if (lp->plan->target_spp && lp->frame_spp > 0.0)
            share = fmax(share, (lp->spp + done * lp->frame_spp) / (double)lp->plan->target_spp);
    }
    rl_progress_update(lp->bar, share);
    return true;
}

static void add_stats(rl_render_stats *sum, const rl_render_stats *s)
{
    sum->time_ms += s->time_ms;
    sum->prep_ms += s->prep_ms;
    for (int t = 0; t < RL_RAY_TYPE_COUNT; t++)
        sum->rays[t] += s->rays[t];
    sum->triangles_rasterized += s->triangles_rasterized;
    sum->pixels_written += s->pixels_written;
    sum->samples += s->samples;
    sum->occlusion_queries += s->occlusion_queries;
    sum->points_drawn += s->points_drawn;
    if (s->device)
        sum->device = s->device;
}

/* --dist over several ranks: the frames one process renders to reach
 * --spp, all of them in every band (rl_dist_render_frames), so that the
 * image is the one-process image. */
static int render_dist_frames(const render_args *a, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                              rl_image *img, const loop_plan *plan, rl_render_stats *sum, cli_accumulation *acc)
{
    double pixels = (double)cam->width * (double)cam->height;
    uint64_t samples = 0;
    long long frames = 0;
    /* The stopping rule of render_frames, on pt's samples per frame. */
    while ((double)samples / pixels < (double)plan->target_spp) {
        uint64_t s = rl_pt_frame_samples(r, cam->width, cam->height, (uint64_t)frames);
        if (s == 0)
            return cli_fail(RL_CLI_USAGE, "--dist --spp: %s does not say its samples per frame in advance; only pt "
                            "renders progressively over several ranks", rl_renderer_name(r));
        if (frames == RL_DIST_MAX_FRAMES)
            return cli_fail(RL_CLI_USAGE, "--dist --spp %lld: more than %d frames", plan->target_spp,
                            RL_DIST_MAX_FRAMES);
        samples += s;
        frames++;
    }
    /* The bar: the share of the bands done, as the samples of one frame. */
    loop_progress lp = { .plan = plan, .start_s = rl_time_s(), .frame_spp = (double)plan->target_spp };
    char label[256];
    snprintf(label, sizeof label, "render %s, %lld frames", a->scene, frames);
    if (rl_log_get_level() >= RL_LOG_INFO && cli_dist_master())
        rl_progress_create(label, stderr, &lp.bar);
    rl_renderer_set_progress(r, on_progress, &lp);
    cli_interrupt_begin("\nrl: interrupted: cancelling the render (Ctrl-C again aborts)\n");
    rl_clear_error();
    rl_status st = cli_render_frames_call(r, scene, cam, frames, img, sum);
    int rc = RL_CLI_OK;
    if (st == RL_ERR_CANCELLED && cli_interrupted())
        rc = cli_fail(RL_CLI_INTERRUPTED, "render: interrupted before the bands were done; nothing written");
    else if (st != RL_OK)
        rc = cli_fail_status(RL_CLI_FAIL, st, "render");
    acc->frames = rc == RL_CLI_OK ? frames : 0;     /* a cancelled run has no image to save */
    acc->spp = (double)sum->samples / pixels;
    acc->elapsed_s = rl_time_s() - lp.start_s;
    acc->target_spp = plan->target_spp;
    acc->stopped = "spp";
    rl_renderer_set_progress(r, NULL, NULL);
    rl_progress_finish(lp.bar);
    cli_interrupt_end();
    return rc;
}

/* One frame, or the progressive loop: frames until the budget would be
 * overrun by one more (mean frame time; at least one frame), the samples
 * are reached, or Ctrl-C. *sum gets the counters summed over the frames.
 * RL_CLI_INTERRUPTED with acc->frames > 0: img holds what accumulated (a
 * cancelled frame leaves the image as the last finished one made it). */
static int render_frames(const render_args *a, rl_renderer *r, const rl_scene *scene, const rl_camera *cam,
                         rl_image *img, const loop_plan *plan, rl_render_stats *sum, cli_accumulation *acc)
{
    loop_progress lp = { .plan = plan, .start_s = rl_time_s() };
    /* The bar is chatter: -q silences it with the info log. */
    char label[256];
    snprintf(label, sizeof label, "render %s", a->scene);
    if (rl_log_get_level() >= RL_LOG_INFO)
        rl_progress_create(label, stderr, &lp.bar);
    rl_renderer_set_progress(r, on_progress, &lp);
    cli_interrupt_begin(plan->loop ? "\nrl: interrupted: saving what has accumulated (Ctrl-C again aborts)\n"
                                   : "\nrl: interrupted: cancelling the render (Ctrl-C again aborts)\n");
    double pixels = (double)cam->width * (double)cam->height;
    double next_preview = plan->preview_s > 0.0 ? lp.start_s + plan->preview_s : INFINITY;
    acc->budget_s = plan->budget_s;
    acc->target_spp = plan->target_spp;
    acc->stopped = "time";
    int rc = RL_CLI_OK;
    for (;;) {
        rl_render_stats stats = { 0 };
        rl_clear_error();
        rl_status st = cli_render_call(r, scene, cam, img, &stats);
        if (st == RL_ERR_CANCELLED && cli_interrupted()) {
            rc = RL_CLI_INTERRUPTED;
            break;
        }
        if (st != RL_OK) {
            rc = cli_fail_status(RL_CLI_FAIL, st, "render");
            break;
        }
        add_stats(sum, &stats);
        acc->frames++;
        lp.frame_spp = (double)stats.samples / pixels;
        lp.spp = acc->spp = (double)sum->samples / pixels;
        if (!plan->loop)
            break;
        if (cli_interrupted()) {
            rc = RL_CLI_INTERRUPTED;
            break;
        }
        if (plan->target_spp && acc->spp >= (double)plan->target_spp) {
            acc->stopped = "spp";
            break;
        }
        if (plan->target_spp && stats.samples == 0) {
            rc = cli_fail(RL_CLI_FAIL, "--spp: %s reports no samples, so the target cannot be reached",
                          rl_renderer_name(r));
            break;
        }
        double now = rl_time_s();
        double mean_frame_s = (sum->time_ms - sum->prep_ms) / (double)acc->frames / 1e3;
        if (plan->budget_s > 0.0 && now - lp.start_s + mean_frame_s > plan->budget_s) {
            acc->stopped = "time";
            break;
        }
        if (now >= next_preview) {
            rl_clear_error();
            rl_status wst = write_color(a, img, a->out);
            if (wst != RL_OK) {
                rc = cli_fail_status(RL_CLI_FAIL, wst, a->out);
                break;
            }
            next_preview = rl_time_s() + plan->preview_s;
        }
    }
    acc->elapsed_s = rl_time_s() - lp.start_s;
    rl_renderer_set_progress(r, NULL, NULL);
    rl_progress_finish(lp.bar);
    cli_interrupt_end();
    if (rc == RL_CLI_INTERRUPTED) {
        acc->stopped = "interrupt";
        if (acc->frames == 0)
            return cli_fail(RL_CLI_INTERRUPTED, "render: interrupted before the first frame was done; nothing "
                                                "written");
    }
    return rc;
}

static int render_frame(const render_args *a)
{
    rl_renderer *renderer = NULL;
    rl_scene *scene = NULL;
    rl_image *img = NULL;
    rl_camera cam;
    rl_render_stats stats = { 0 };
    cli_accumulation acc = { 0 };
    loop_plan plan = { 0 };
    double load_ms = 0.0, inputs_ms = 0.0;
    rl_timer phase;
    int rc = check_outputs(a);
    if (rc == RL_CLI_OK)
        rc = create_renderer(a, &renderer);
    if (rc == RL_CLI_OK)
        rc = plan_loop(a, renderer, &plan);
    rl_timer_start(&phase);
    if (rc == RL_CLI_OK)
        rc = cli_load_scene_with(a->scene, &a->model, &scene);
    load_ms = rl_timer_ms(&phase);
    if (rc == RL_CLI_OK)
        rc = choose_camera(a, scene, &cam);
    if (rc == RL_CLI_OK)
        rc = check_frame_memory(a, renderer, &cam);
    if (rc == RL_CLI_OK) {
        /* visset and select: their sampled properties, before the frame. */
        rl_clear_error();
        rl_timer_start(&phase);
        rl_status st = rl_renderer_prepare_inputs(renderer, scene);
        inputs_ms = rl_timer_ms(&phase);
        if (st != RL_OK)
            rc = cli_fail_status(RL_CLI_FAIL, st, "render");
    }
    if (rc == RL_CLI_OK) {
        unsigned layers = RL_LAYER_COLOR | (a->depth_out ? RL_LAYER_DEPTH : 0u) |
                          (a->id_out ? RL_LAYER_ID : 0u);
        rl_clear_error();
        rl_status st = rl_image_create(cam.width, cam.height, layers, &img);
        if (st != RL_OK)
            rc = cli_fail_status(RL_CLI_FAIL, st, "image");
    }
    if (rc == RL_CLI_OK)
        rc = plan.loop && cli_dist_ranks() > 1 ? render_dist_frames(a, renderer, scene, &cam, img, &plan, &stats, &acc)
                                               : render_frames(a, renderer, scene, &cam, img, &plan, &stats, &acc);
    /* Ctrl-C in a loop keeps the frames that were finished. */
    bool saving = rc == RL_CLI_OK || (rc == RL_CLI_INTERRUPTED && acc.frames > 0);
    if (saving && cli_dist_master()) {   /* --dist: the workers hold only their bands */
        cli_debug("timing: load %.1f ms, build %.1f ms (inputs %.1f ms, for the scene %.1f ms), frame %.1f ms",
                  load_ms, inputs_ms + stats.prep_ms, inputs_ms, stats.prep_ms, stats.time_ms - stats.prep_ms);
        int wrc = write_outputs(a, scene, img, &stats, inputs_ms, plan.loop ? &acc : NULL);
        if (wrc != RL_CLI_OK)
            rc = wrc;
        else if (plan.loop)
            cli_print_accumulation_summary(stdout, rl_renderer_name(renderer), a->scene, cam.width, cam.height,
                                           &stats, inputs_ms, &acc);
        else
            cli_print_summary(stdout, rl_renderer_name(renderer), a->scene, cam.width, cam.height, &stats,
                              inputs_ms);
        cli_print_dist_summary(stdout);
    }
    rl_image_release(img);
    rl_scene_release(scene);
    rl_renderer_release(renderer);
    return rc;
}

/* One frame's entry of the path's stats JSON. */
static cJSON *frame_json(long long i, double t, const rl_camera *cam, const char *file, const rl_render_stats *stats,
                         double inputs_ms)
{
    cJSON *e = cli_render_stats_json(stats, inputs_ms);
    if (!e)
        return NULL;
    cJSON_AddNumberToObject(e, "frame", (double)i);
    cJSON_AddNumberToObject(e, "time_s", t);
    cJSON_AddStringToObject(e, "file", file);
    const rl_vec3 v[2] = { cam->eye, cam->target };
    const char *keys[2] = { "eye", "target" };
    for (int k = 0; k < 2; k++) {
        cJSON *a = cJSON_AddArrayToObject(e, keys[k]);
        const double c[3] = { v[k].x, v[k].y, v[k].z };
        for (int j = 0; a && j < 3; j++)
            cJSON_AddItemToArray(a, cJSON_CreateNumber(c[j]));
    }
    cJSON_AddNumberToObject(e, "fov_deg", cam->fov_deg);
    return e;
}

/* --camera-path: the scene's path as frames, one renderer kept across them
 * (so temporal coherence and kept structures carry over, as in a
 * walkthrough), files named by the --out pattern. */
static int render_path(const render_args *a)
{
    rl_renderer *renderer = NULL;
    rl_scene *scene = NULL;
    rl_image *img = NULL;
    rl_progress *progress = NULL;
    cJSON *report = NULL, *frames_json = NULL;
    /* Formats and folders, checked on frame 0's names before any work. */
    render_args first = *a;
    char out0[4096], depth0[4096], ids0[4096];
    if (!frame_name(a->out, 0, out0, sizeof out0) ||
        (a->depth_out && !frame_name(a->depth_out, 0, depth0, sizeof depth0)) ||
        (a->id_out && !frame_name(a->id_out, 0, ids0, sizeof ids0)))
        return cli_fail(RL_CLI_USAGE, "%s: the frame names are too long", a->out);
    first.out = out0;
    first.depth_out = a->depth_out ? depth0 : NULL;
    first.id_out = a->id_out ? ids0 : NULL;
    int rc = check_outputs(&first);
    if (rc == RL_CLI_OK)
        rc = create_renderer(a, &renderer);
    rl_timer phase;
    rl_timer_start(&phase);
    if (rc == RL_CLI_OK)
        rc = cli_load_scene_with(a->scene, &a->model, &scene);
    double load_ms = rl_timer_ms(&phase), inputs_ms = 0.0;
    const rl_scene_data *d = scene ? rl_scene_get_data(scene) : NULL;
    const rl_camera_path *path = d ? d->camera_path : NULL;
    if (rc == RL_CLI_OK && !path)
        rc = cli_fail(RL_CLI_USAGE, "%s: the scene has no camera_path (see docs/scene-format.md)", a->scene);
    rl_camera size;
    if (rc == RL_CLI_OK)
        rc = choose_camera(a, scene, &size);      /* the size: --size, the scene camera's, or the default */
    if (rc == RL_CLI_OK)
        rc = check_frame_memory(a, renderer, &size);
    /* Frames: --frames N spread evenly over the keys, else 1/fps steps. */
    double duration = path ? rl_camera_path_duration(path) : 0.0, fps = a->fps > 0.0 ? a->fps : 25.0;
    long long n = a->frames ? a->frames : (long long)floor(duration * fps + 1e-9) + 1;
    if (rc == RL_CLI_OK && n > 1000000)
        rc = cli_fail(RL_CLI_USAGE, "--fps %g over %g s makes %lld frames (at most 1000000)", fps, duration, n);
    if (rc == RL_CLI_OK) {
        rl_clear_error();
        rl_timer_start(&phase);
        rl_status st = rl_renderer_prepare_inputs(renderer, scene);
        inputs_ms = rl_timer_ms(&phase);
        unsigned layers = RL_LAYER_COLOR | (a->depth_out ? RL_LAYER_DEPTH : 0u) | (a->id_out ? RL_LAYER_ID : 0u);
        if (st == RL_OK)
            st = rl_image_create(size.width, size.height, layers, &img);
        if (st != RL_OK)
            rc = cli_fail_status(RL_CLI_FAIL, st, "render");
    }
    if (rc == RL_CLI_OK && a->stats_json) {
        report = cJSON_CreateObject();
        if (report) {
            cJSON_AddStringToObject(report, "algorithm", a->algo);
            cJSON_AddStringToObject(report, "scene", a->scene);
            cJSON_AddNumberToObject(report, "width", size.width);
            cJSON_AddNumberToObject(report, "height", size.height);
            cJSON_AddNumberToObject(report, "duration_s", duration);
            cJSON *ss = cli_scene_stats_json(scene);
            if (ss)
                cJSON_AddItemToObject(report, "scene_stats", ss);
            frames_json = cJSON_AddArrayToObject(report, "frames");
        }
        if (!frames_json)
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
    }
    if (rc == RL_CLI_OK) {
        char label[256];
        snprintf(label, sizeof label, "render %s, %lld frames", a->scene, n);
        if (rl_log_get_level() >= RL_LOG_INFO)
            rl_progress_create(label, stderr, &progress);
    }
    /* Frames without their preparation (the first frame's builds, the
     * inputs), which is reported once, apart. */
    double frames_ms = 0.0, max_ms = 0.0, prep_ms = inputs_ms;
    for (long long i = 0; rc == RL_CLI_OK && i < n; i++) {
        double t = a->frames ? (n > 1 ? duration * (double)i / (double)(n - 1) : 0.0) : (double)i / fps;
        rl_camera cam = rl_camera_path_eval(path, rl_camera_path_key(path, 0)->time_s + t);
        cam.width = size.width;
        cam.height = size.height;
        cam = rl_camera_resolve(&cam);
        rl_render_stats stats = { 0 };
        render_args fa = *a;
        char out[4096], depth[4096], ids[4096];
        bool named = frame_name(a->out, i, out, sizeof out) &&
                     (!a->depth_out || frame_name(a->depth_out, i, depth, sizeof depth)) &&
                     (!a->id_out || frame_name(a->id_out, i, ids, sizeof ids));
        if (!named) {
            rc = cli_fail(RL_CLI_USAGE, "%s: frame %lld's name is too long", a->out, i);
            break;
        }
        fa.out = out;
        fa.depth_out = a->depth_out ? depth : NULL;
        fa.id_out = a->id_out ? ids : NULL;
        fa.stats_json = NULL;
        rl_clear_error();
        rl_status st = cli_render_call(renderer, scene, &cam, img, &stats);
        if (st != RL_OK) {
            char what[64];
            snprintf(what, sizeof what, "render, frame %lld", i);
            rc = cli_fail_status(RL_CLI_FAIL, st, what);
            break;
        }
        if (cli_dist_master())
            rc = write_outputs(&fa, scene, img, &stats, 0.0, NULL);
        double frame_ms = stats.time_ms - stats.prep_ms;
        frames_ms += frame_ms;
        prep_ms += stats.prep_ms;
        max_ms = frame_ms > max_ms ? frame_ms : max_ms;
        if (rc == RL_CLI_OK && frames_json) {
            cJSON *e = frame_json(i, t, &cam, out, &stats, i == 0 ? inputs_ms : 0.0);
            if (!e)
                rc = cli_fail(RL_CLI_FAIL, "out of memory");
            else
                cJSON_AddItemToArray(frames_json, e);
        }
        if (progress)
            rl_progress_update(progress, (double)(i + 1) / (double)n);
    }
    rl_progress_finish(progress);
    if (rc == RL_CLI_OK && report && cli_dist_master() && !cli_write_json(report, a->stats_json))
        rc = RL_CLI_FAIL;
    if (rc == RL_CLI_OK) {
        char prep[32];
        cli_format_ms(prep_ms, prep, sizeof prep);
        cli_debug("timing: load %.1f ms, build %.1f ms (inputs %.1f ms), frames %.1f ms", load_ms, prep_ms, inputs_ms,
                  frames_ms);
        printf("%s %dx%d %s: %lld frames of %.3g s, prep %s, frame %.1f ms on average (max %.1f), %s\n",
               rl_renderer_name(renderer), size.width, size.height, a->scene, n, duration, prep,
               frames_ms / (double)n, max_ms, a->out);
    }
    cJSON_Delete(report);
    rl_image_release(img);
    rl_scene_release(scene);
    rl_renderer_release(renderer);
    return rc;
}

int cli_render(int argc, char **argv)
{
    render_args a = { .algo = "raster", .preview_s = -1.0 };
    a.sets = calloc((size_t)argc, sizeof *a.sets);
    if (!a.sets)
        return cli_fail(RL_CLI_FAIL, "out of memory");
    int rc = parse_args(argc, argv, &a);
    if (rc == RL_CLI_OK)
        rc = a.camera_path ? render_path(&a) : render_frame(&a);
    free(a.sets);
    return rc < 0 ? RL_CLI_OK : rc;
}
