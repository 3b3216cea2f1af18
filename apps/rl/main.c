/* main.c: entry point of `rl`: global flags, log output, subcommand dispatch.
 *
 * Global flags may stand before or after the subcommand (`rl -q render ...`
 * and `rl render ... -q` mean the same), so they are taken out of argv first
 * and the subcommand sees only its own arguments. */
#include "cli.h"

#include <errno.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>

typedef struct command {
    const char *name;
    int (*run)(int argc, char **argv);
    const char *summary;
} command;

static const command commands[] = {
    { "scenes", cli_scenes, "list the built-in scenes and their parameters" },
    { "algos", cli_algos, "list the renderers, their papers and options (alias: renderers)" },
    { "renderers", cli_algos, NULL },
    { "info", cli_info, "print statistics and cameras of a scene" },
    { "render", cli_render, "render a scene to PNG or EXR" },
    { "view", cli_view, "an interactive window on any renderer: fly, switch renderers, record paths" },
    { "demo", cli_demo, "render every built-in scene with every renderer + HTML report" },
    { "eval", cli_eval, "approximate a position-dependent property over a region (heat map, statistics)" },
    { "compare", cli_compare, "compare renderers over a sampled region: time, operations, image quality" },
    { "bench", cli_bench, "benchmarks: bench rays (accelerators), bench vt (Vertex Tracing), bench pt (Line Space path tracing), bench sampling (property approximation), bench surfels (Progressive Blue Surfels), bench culling (CHC++, SVS, visible sets)" },
};

static void print_usage(FILE *out)
{
    fprintf(out,
            "usage: rl [-v|-q] [--plugin FILE] [import limits] <command> [options]\n"
            "\n"
            "renderlab " RL_CLI_VERSION ": a laboratory of rendering algorithms.\n"
            "\n"
            "commands:\n");
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (commands[i].summary)
            fprintf(out, "  %-10s %s\n", commands[i].name, commands[i].summary);
    fprintf(out,
            "  %-10s show this text (also: rl --help); rl <command> --help for details\n"
            "\n"
            "global flags (before or after the command):\n"
            "  -v, --verbose   debug log and the phases' times (load, build, frame)\n"
            "  -q, --quiet     errors only\n"
            "  --plugin FILE   load renderers from a shared object (README, \"Your own renderer\")\n"
            "  --version       print the version\n"
            "  --dist          spread the work over the ranks of an MPI job: run as\n"
            "                  mpirun -np N rl --dist render ... (also eval, compare,\n"
            "                  bench sampling; docs/distributed.md)\n"
            "\n"
            "model files (OBJ, PLY, glTF, DAE, ...; also a JSON scene's \"file\") are imported\n"
            "with Assimp in a child process, so that a malformed file costs an error, not rl:\n"
            "  --import-timeout S    wall-clock and CPU seconds per file (default %u)\n"
            "  --import-memory MiB   memory the importer may add (default %u)\n"
            "  --trusted-import      import in this process, without limits: UNSAFE for\n"
            "                        files you do not trust (a bad one can crash or hang rl)\n"
            "  --max-texture-pixels MPIX  largest texture in 2^20 pixels, read from its\n"
            "                        header before decoding (default %llu = 8192x8192)\n"
            "\n"
            "example:\n"
            "  rl render cornell --algo raster --size 640x480 --out cornell.png\n",
            "help", RL_IMPORT_DEFAULT_TIMEOUT_S, RL_IMPORT_DEFAULT_MEMORY_MIB,
            (unsigned long long)(RL_TEXTURE_MAX_PIXELS >> 20));
}

/* Log lines of the library go to stderr as "rl: warning: ...". */
static void log_to_stderr(void *user, rl_log_level level, const char *message)
{
    (void)user;
    fprintf(stderr, "rl: %s: %s\n", rl_log_level_name(level), message);
}

/* "unknown command 'rendr' (did you mean 'render'? see rl --help)". */
static int unknown_command(const char *name)
{
    const char *names[sizeof commands / sizeof commands[0] + 1];
    size_t n = 0;
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        names[n++] = commands[i].name;
    names[n++] = "help";
    char hint[96];
    return cli_fail(RL_CLI_USAGE, "unknown command '%s' (%ssee rl --help)", name,
                    cli_did_you_mean(name, names, n, hint, sizeof hint));
}

/* "--name V" or "--name=V": 1 and *value set when argv[*i] is the flag
 * (*i advanced past a separate value), 0 when it is another argument. */
static int global_value(int argc, char **argv, int *i, const char *name, const char **value)
{
    size_t n = strlen(name);
    if (strncmp(argv[*i], name, n) != 0 || (argv[*i][n] != '\0' && argv[*i][n] != '='))
        return 0;
    *value = argv[*i][n] == '=' ? argv[*i] + n + 1 : (*i + 1 < argc ? argv[++*i] : NULL);
    return 1;
}

/* A whole number in [lo, hi], or a usage error (-1 after printing). */
static int parse_limit(const char *flag, const char *text, unsigned long lo, unsigned long hi,
                       const char *unit, uint32_t *out)
{
    char *end = NULL;
    errno = 0;
    unsigned long v = text && *text && *text != '-' ? strtoul(text, &end, 10) : 0;
    if (!text || !*text || *end || errno || v < lo || v > hi) {
        cli_fail(RL_CLI_USAGE, "%s: expected %s from %lu to %lu, got '%s'", flag, unit, lo, hi,
                 text ? text : "");
        return -1;
    }
    *out = (uint32_t)v;
    return 0;
}

int main(int argc, char **argv)
{
    cli_set_command_line(argc, argv);   /* for the reports, before the flags are taken out */
    /* A write past the file size limit (ulimit -f) would kill rl by SIGXFSZ
     * mid-file; ignored, it fails with EFBIG, which the writers report as
     * an error and clean up after, like a full disk. */
    signal(SIGXFSZ, SIG_IGN);
    rl_log_level level = RL_LOG_INFO;
    enum { MAX_PLUGINS = 8 };
    const char *plugins[MAX_PLUGINS];
    int n = 0, num_plugins = 0;
    rl_import_limits import = { 0 };
    const char *v = NULL;
    bool dist = false;
    /* Take out global flags wherever they are; keep everything else in order. */
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i];
        if (global_value(argc, argv, &i, "--import-timeout", &v)) {
            if (parse_limit("--import-timeout", v, 1, 86400, "seconds", &import.timeout_s) < 0)
                return RL_CLI_USAGE;
        } else if (global_value(argc, argv, &i, "--import-memory", &v)) {
            if (parse_limit("--import-memory", v, 64, 1ul << 22, "MiB", &import.memory_mib) < 0)
                return RL_CLI_USAGE;
        } else if (global_value(argc, argv, &i, "--max-texture-pixels", &v)) {
            uint32_t mpix = 0;
            if (parse_limit("--max-texture-pixels", v, 1, 1ul << 12, "megapixels (2^20 pixels)", &mpix) < 0)
                return RL_CLI_USAGE;
            rl_texture_set_max_pixels((unsigned long long)mpix << 20);
        } else if (strcmp(a, "--trusted-import") == 0)
            import.in_process = true;
        else if (strcmp(a, "--dist") == 0)
            dist = true;
        else if (strcmp(a, "-v") == 0 || strcmp(a, "--verbose") == 0)
            level = RL_LOG_DEBUG;
        else if (strcmp(a, "-q") == 0 || strcmp(a, "--quiet") == 0)
            level = RL_LOG_ERROR;
        else if (strcmp(a, "--plugin") == 0 || strncmp(a, "--plugin=", 9) == 0) {
            const char *path = a[8] == '=' ? a + 9 : (i + 1 < argc ? argv[++i] : NULL);
            if (!path || !*path)
                return cli_fail(RL_CLI_USAGE, "--plugin needs a file (a shared object defining rl_plugin_init)");
            if (num_plugins == MAX_PLUGINS)
                return cli_fail(RL_CLI_USAGE, "at most %d --plugin files", MAX_PLUGINS);
            plugins[num_plugins++] = path;
        } else
            argv[n++] = argv[i];
    }
    argv[n] = NULL;
    rl_scene_set_import_limits(&import);
    rl_log_set_level(level);
    rl_log_set_callback(log_to_stderr, NULL);
    /* Before the subcommand, so that it finds the plugins' renderers by name. */
    for (int i = 0; i < num_plugins; i++) {
        int code = cli_load_plugin(plugins[i]);
        if (code)
            return code;
    }

    if (n == 0)
        return cli_fail(RL_CLI_USAGE, "no command given (commands: scenes, algos, info, "
                                         "render, view, demo, eval, compare, bench; see rl --help)");
    const char *name = argv[0];
    if (strcmp(name, "help") == 0 && n > 1) {
        /* "rl help render" is "rl render --help". */
        static char help_flag[] = "--help";
        char *help_argv[] = { argv[1], help_flag, NULL };
        for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
            if (strcmp(argv[1], commands[i].name) == 0)
                return commands[i].run(2, help_argv);
        return unknown_command(argv[1]);
    }
    if (cli_is_help(name) || strcmp(name, "help") == 0) {
        print_usage(stdout);
        return RL_CLI_OK;
    }
    if (strcmp(name, "--version") == 0) {
        printf("rl (renderlab) %s\n", RL_CLI_VERSION);
        return RL_CLI_OK;
    }
    for (size_t i = 0; i < sizeof commands / sizeof commands[0]; i++)
        if (strcmp(name, commands[i].name) == 0) {
            if (!dist)
                return commands[i].run(n, argv);
            bool spreads = strcmp(name, "render") == 0 || strcmp(name, "eval") == 0 ||
                           strcmp(name, "compare") == 0 ||
                           (strcmp(name, "bench") == 0 && n > 1 &&
                            (strcmp(argv[1], "sampling") == 0 || strcmp(argv[1], "culling") == 0));
            if (!spreads)
                return cli_fail(RL_CLI_USAGE, "--dist: only rl render, eval, compare, bench sampling and bench "
                                              "culling run distributed so far (docs/distributed.md)");
            int rc = cli_dist_begin(NULL, NULL);
            return cli_dist_end(rc == RL_CLI_OK ? commands[i].run(n, argv) : rc);
        }
    if (name[0] == '-')
        return cli_fail(RL_CLI_USAGE, "unknown option '%s' (see rl --help)", name);
    return unknown_command(name);
}
