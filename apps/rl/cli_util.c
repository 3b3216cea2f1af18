/* cli_util.c: argument parsing, error lines and path checks shared by the
 * subcommands of `rl`. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "rl/rl_options.h"
#include "rl/rl_path.h"

int cli_fail(int code, const char *fmt, ...)
{
    char line[1200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    /* One line, always: a multi-line library message would break scripts
     * that read the first line of stderr. */
    for (char *c = line; *c; c++)
        if (*c == '\n' || *c == '\r')
            *c = ' ';
    fprintf(stderr, "rl: error: %s\n", line);
    return code;
}

int cli_fail_status(int code, rl_status status, const char *what)
{
    const char *msg = rl_last_error();
    if (!msg || !*msg)
        msg = rl_status_string(status);
    /* Library messages usually name the file or item already. */
    if (what && *what && !strstr(msg, what))
        return cli_fail(code, "%s: %s", what, msg);
    return cli_fail(code, "%s", msg);
}

bool cli_split_option(const char *what, const char *text, char *key, size_t key_size,
                         const char **value)
{
    const char *eq = strchr(text, '=');
    if (!eq || eq == text) {
        cli_fail(RL_CLI_USAGE, "%s: expected KEY=VALUE, got '%s'", what, text);
        return false;
    }
    size_t n = (size_t)(eq - text);
    if (n >= key_size) {
        cli_fail(RL_CLI_USAGE, "%s: key too long in '%s'", what, text);
        return false;
    }
    memcpy(key, text, n);
    key[n] = '\0';
    *value = eq + 1;
    return true;
}

bool cli_is_help(const char *arg)
{
    return strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0;
}

int cli_take_value(int argc, char **argv, int *i, const char *name, const char **value)
{
    const char *arg = argv[*i];
    size_t n = strlen(name);
    if (strncmp(arg, name, n) != 0)
        return 0;
    if (arg[n] == '=') {
        *value = arg + n + 1;
        return 1;
    }
    if (arg[n] != '\0')
        return 0;
    if (*i + 1 >= argc) {
        cli_fail(RL_CLI_USAGE, "%s needs a value (see --help)", name);
        return -1;
    }
    *i += 1;
    *value = argv[*i];
    return 1;
}

int cli_unknown_arg(const char *command, const char *arg)
{
    if (arg[0] == '-')
        return cli_fail(RL_CLI_USAGE, "%s: unknown option '%s' (see rl %s --help)", command,
                           arg, command);
    return cli_fail(RL_CLI_USAGE, "%s: unexpected argument '%s' (see rl %s --help)", command,
                       arg, command);
}

bool cli_parse_duration(const char *text, double *seconds)
{
    static const struct { const char *unit; double s; } units[] = {
        { "ms", 1e-3 }, { "s", 1.0 }, { "m", 60.0 }, { "h", 3600.0 }, { "", 1.0 },
    };
    size_t len = strlen(text);
    for (size_t k = 0; k < sizeof units / sizeof units[0]; k++) {
        size_t n = strlen(units[k].unit);
        if (len <= n || strcmp(text + len - n, units[k].unit) != 0)
            continue;
        char number[64];
        if (len - n >= sizeof number)
            return false;
        memcpy(number, text, len - n);
        number[len - n] = '\0';
        double v;
        /* The first unit that ends the text decides: "2m" is minutes, and
         * "2ms" never reaches "s". */
        if (!rl_parse_float(number, &v) || !isfinite(v) || v < 0.0)
            return false;
        *seconds = v * units[k].s;
        return true;
    }
    return false;
}

bool cli_parse_bytes(const char *text, double *bytes)
{
    static const char units[] = "KMGT";
    size_t len = strlen(text);
    char number[64];
    if (len == 0 || len >= sizeof number)
        return false;
    memcpy(number, text, len + 1);
    double scale = 1.0;
    const char *u = strchr(units, toupper((unsigned char)text[len - 1]));
    if (u && *u) {
        scale = pow(1024.0, (double)(u - units + 1));
        number[len - 1] = '\0';
    }
    double v;
    if (!rl_parse_float(number, &v) || !isfinite(v) || !(v > 0.0))
        return false;
    *bytes = v * scale;
    return true;
}

double cli_available_memory(void)
{
    FILE *f = fopen("/proc/meminfo", "r");
    if (!f)
        return 0.0;
    char line[256];
    unsigned long long kib = 0;
    while (fgets(line, sizeof line, f))
        if (sscanf(line, "MemAvailable: %llu kB", &kib) == 1)
            break;
    fclose(f);
    return (double)kib * 1024.0;
}

int cli_check_frame_memory(const rl_renderer *r, int width, int height, unsigned layers, double extra_per_pixel,
                           double max_memory)
{
    double need = rl_image_bytes(width, height, layers) + rl_renderer_frame_bytes(r, width, height) +
                  (double)width * (double)height * extra_per_pixel;
    double limit = max_memory > 0.0 ? max_memory : cli_available_memory();
    if (limit > 0.0 && need > limit)
        return cli_fail(RL_CLI_FAIL, "a %dx%d frame of %s needs about %.2f GiB, more than the %.2f GiB %s", width,
                        height, rl_renderer_name(r), need / 1073741824.0, limit / 1073741824.0,
                        max_memory > 0.0 ? "of --max-memory" : "available (MemAvailable; see --max-memory)");
    return RL_CLI_OK;
}

bool cli_parse_size(const char *text, int *width, int *height)
{
    const char *x = strpbrk(text, "xX");
    long long w = 0, h = 0;
    bool ok = x != NULL;
    if (ok) {
        char wtext[32];
        size_t n = (size_t)(x - text);
        ok = n > 0 && n < sizeof wtext;
        if (ok) {
            memcpy(wtext, text, n);
            wtext[n] = '\0';
            ok = rl_parse_int(wtext, &w) && rl_parse_int(x + 1, &h);
        }
    }
    if (!ok) {
        cli_fail(RL_CLI_USAGE, "--size: expected WIDTHxHEIGHT such as 1280x720, got '%s'",
                    text);
        return false;
    }
    /* Refuse before anything is allocated: 20000x20000 RGBA float is 6 GB. */
    if (w < 1 || h < 1 || w > RL_IMAGE_MAX_SIZE || h > RL_IMAGE_MAX_SIZE) {
        cli_fail(RL_CLI_USAGE, "--size: %lldx%lld is outside 1..%d per side", w, h,
                    RL_IMAGE_MAX_SIZE);
        return false;
    }
    *width = (int)w;
    *height = (int)h;
    return true;
}

bool cli_parse_vec3(const char *option, const char *text, rl_vec3 *out)
{
    double v[3];
    const char *p = text;
    for (int k = 0; k < 3; k++) {
        const char *end = strchr(p, ',');
        size_t n = end ? (size_t)(end - p) : strlen(p);
        char part[64];
        bool last = k == 2;
        if (n == 0 || n >= sizeof part || (last != (end == NULL))) {
            cli_fail(RL_CLI_USAGE, "%s: expected x,y,z such as 0,1,5, got '%s'", option, text);
            return false;
        }
        memcpy(part, p, n);
        part[n] = '\0';
        if (!rl_parse_float(part, &v[k])) {
            cli_fail(RL_CLI_USAGE, "%s: '%s' is not a finite number (in '%s')", option, part,
                        text);
            return false;
        }
        p = end ? end + 1 : p + n;
    }
    *out = rl_v3((float)v[0], (float)v[1], (float)v[2]);
    return true;
}

bool cli_has_extension(const char *path, const char *const *extensions)
{
    /* A bare ".png" names no file. */
    for (const char *const *e = extensions; *e; e++)
        if (strlen(path) > strlen(*e) && rl_path_has_ext(path, *e))
            return true;
    return false;
}

/* Folder part of path ("." when there is none); malloc'd. */
static char *folder_of(const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        return strdup(".");
    if (slash == path)
        return strdup("/");
    size_t n = (size_t)(slash - path);
    char *dir = malloc(n + 1);
    if (dir) {
        memcpy(dir, path, n);
        dir[n] = '\0';
    }
    return dir;
}

bool cli_check_writable(const char *path)
{
    char *dir = folder_of(path);
    if (!dir) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    struct stat st;
    bool ok = false;
    if (stat(dir, &st) != 0)
        cli_fail(RL_CLI_FAIL, "%s: cannot write: folder '%s' does not exist", path, dir);
    else if (!S_ISDIR(st.st_mode))
        cli_fail(RL_CLI_FAIL, "%s: cannot write: '%s' is not a folder", path, dir);
    else if (access(dir, W_OK) != 0)
        cli_fail(RL_CLI_FAIL, "%s: cannot write: folder '%s' is not writable", path, dir);
    else if (stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        cli_fail(RL_CLI_FAIL, "%s: cannot write: it is a folder", path);
    else
        ok = true;
    free(dir);
    return ok;
}

bool cli_make_dirs(const char *dir)
{
    char *copy = strdup(dir);
    if (!copy) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    bool ok = true;
    /* Create each prefix in turn; existing folders are fine. */
    for (char *p = copy + 1; ok; p++) {
        bool end = *p == '\0';
        if (*p == '/' || end) {
            char saved = *p;
            *p = '\0';
            struct stat st;
            if (mkdir(copy, 0777) != 0 && errno != EEXIST) {
                cli_fail(RL_CLI_FAIL, "%s: cannot create folder: %s", copy, strerror(errno));
                ok = false;
            } else if (stat(copy, &st) != 0 || !S_ISDIR(st.st_mode)) {
                cli_fail(RL_CLI_FAIL, "%s: exists and is not a folder", copy);
                ok = false;
            }
            *p = saved;
        }
        if (end)
            break;
    }
    free(copy);
    return ok;
}

bool cli_split_source(const char *arg, char **source, char **params)
{
    struct stat st;
    const char *colon = strrchr(arg, ':');
    *params = NULL;
    /* "cornell-teapot:triangles=70000": parameters always contain '=', and a
     * real file whose name happens to contain ':' wins. */
    if (colon && strchr(colon, '=') && stat(arg, &st) != 0) {
        size_t n = (size_t)(colon - arg);
        *source = malloc(n + 1);
        *params = strdup(colon + 1);
        if (!*source || !*params) {
            free(*source);
            free(*params);
            *source = *params = NULL;
            return false;
        }
        memcpy(*source, arg, n);
        (*source)[n] = '\0';
        return true;
    }
    *source = strdup(arg);
    return *source != NULL;
}

static const char *option_type_name(rl_option_type t)
{
    switch (t) {
    case RL_OPT_INT: return "int";
    case RL_OPT_FLOAT: return "float";
    case RL_OPT_BOOL: return "bool";
    case RL_OPT_ENUM: return "enum";
    case RL_OPT_STRING: return "string";
    case RL_OPT_COLOR: return "color";
    }
    return "?";
}

/* A range bound: whole numbers in full (9007199254740992, not 9.0072e+15),
 * others and the huge sentinels (1e+300) as %g. */
static void put_bound(FILE *out, double v)
{
    if (v == floor(v) && fabs(v) < 1e16)
        fprintf(out, "%.0f", v);
    else
        fprintf(out, "%g", v);
}

void cli_print_option(FILE *out, const rl_option_info *o)
{
    /* An empty default: "" for text, "-" (none: the help says what then) else. */
    const char *def = o->default_value && *o->default_value ? o->default_value
                      : o->type == RL_OPT_STRING             ? "\"\""
                                                             : "-";
    fprintf(out, "    %-22s %-6s default %-10s %s", o->key, option_type_name(o->type), def, o->help ? o->help : "");
    if ((o->type == RL_OPT_INT || o->type == RL_OPT_FLOAT) && o->max > o->min) {
        /* Tables write "no limit" as the largest exact integer (2^53 - 1)
         * or as +-1e300; such a side is left out rather than printed. */
        bool lo = o->min > -9007199254740991.0, hi = o->max < 9007199254740991.0;
        if (lo && hi) {
            fputs(" [", out);
            put_bound(out, o->min);
            fputs("..", out);
            put_bound(out, o->max);
            fputs("]", out);
        } else if (lo || hi) {
            fputs(lo ? " [>= " : " [<= ", out);
            put_bound(out, lo ? o->min : o->max);
            fputs("]", out);
        }
    }
    if (o->type == RL_OPT_ENUM && o->choices) {
        fprintf(out, " {");
        for (const char *const *c = o->choices; *c; c++)
            fprintf(out, "%s%s", c == o->choices ? "" : ", ", *c);
        fprintf(out, "}");
    }
    fputc('\n', out);
}

bool cli_same_file(const char *a, const char *b)
{
    if (strcmp(a, b) == 0)
        return true;
    /* Different spellings of one existing file ("./x.png", a link). */
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}
