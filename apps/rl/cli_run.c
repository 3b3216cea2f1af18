/* cli_run.c: what makes a measurement readable later, shared by every
 * report of `rl` (render, demo, eval, compare, bench): the command line,
 * the build, the machine, its load at the start and the end (a busy
 * machine skews timings, so the tool warns when the load exceeds the
 * threads), the phases of a run for -v, and "did you mean" for names the
 * tool itself checks. */
#define _DEFAULT_SOURCE
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>

static char command_line[4096];

void cli_set_command_line(int argc, char **argv)
{
    command_line[0] = '\0';
    for (int i = 0; i < argc; i++) {
        size_t used = strlen(command_line);
        /* Quote what a shell would split, so that the line can be rerun. */
        bool quote = argv[i][0] == '\0' || strpbrk(argv[i], " \t'\"$;&|<>()*?") != NULL;
        snprintf(command_line + used, sizeof command_line - used, "%s%s%s%s", i ? " " : "",
                 quote ? "'" : "", argv[i], quote ? "'" : "");
    }
}

const char *cli_command_line(void)
{
    return command_line;
}

int cli_threads(void)
{
    return omp_get_max_threads();
}

/* "model name : AMD EPYC ..." from /proc/cpuinfo; "unknown" elsewhere. */
static void cpu_model(char *out, size_t size)
{
    snprintf(out, size, "unknown");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        const char *colon = strchr(line, ':');
        if (strncmp(line, "model name", 10) == 0 && colon) {
            colon++;
            while (*colon == ' ' || *colon == '\t')
                colon++;
            snprintf(out, size, "%s", colon);
            out[strcspn(out, "\r\n")] = '\0';
            break;
        }
    }
    fclose(f);
}

/* "0.52 0.58 0.59": 1, 5 and 15 minutes; "unknown" where there is none. */
static void load_text(char *out, size_t size)
{
    double l[3];
    if (getloadavg(l, 3) == 3)
        snprintf(out, size, "%.2f %.2f %.2f", l[0], l[1], l[2]);
    else
        snprintf(out, size, "unknown");
}

cJSON *cli_machine_json(int threads)
{
    cJSON *m = cJSON_CreateObject();
    if (!m)
        return NULL;
    struct utsname u;
    char text[sizeof u.sysname + sizeof u.release + sizeof u.version + sizeof u.machine + 8];
    if (uname(&u) == 0) {
        snprintf(text, sizeof text, "%s %s %s %s", u.sysname, u.release, u.version, u.machine);
        cJSON_AddStringToObject(m, "uname", text);
    } else {
        cJSON_AddNullToObject(m, "uname");
    }
    char cpu[256];
    cpu_model(cpu, sizeof cpu);
    cJSON_AddStringToObject(m, "cpu", cpu);
    cJSON_AddNumberToObject(m, "nproc", omp_get_num_procs());
    cJSON_AddNumberToObject(m, "threads", threads);
    char load[64];
    load_text(load, sizeof load);
    cJSON_AddStringToObject(m, "loadavg_at_end", load);
    return m;
}

void cli_build_text(char *out, size_t size)
{
#ifdef NDEBUG
    const char *type = "release";
#else
    const char *type = "debug";
#endif
#if defined(__SANITIZE_ADDRESS__)
    const char *san = ", ASan";
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
    const char *san = ", ASan";
#else
    const char *san = "";
#endif
#else
    const char *san = "";
#endif
#if defined(__clang__)
    const char *compiler = "clang " __clang_version__;
#elif defined(__GNUC__)
    const char *compiler = "GCC " __VERSION__;
#else
    const char *compiler = "an unknown compiler";
#endif
    snprintf(out, size, "renderlab %s, %s%s, %s%s", RL_CLI_VERSION, type, san, compiler,
             rl_accel_kind_available(RL_ACCEL_EMBREE) ? ", Embree" : "");
}

cJSON *cli_experiment_json(int threads)
{
    cJSON *e = cJSON_CreateObject();
    if (!e)
        return NULL;
    char build[512];
    cli_build_text(build, sizeof build);
    cJSON_AddStringToObject(e, "command", command_line);
    cJSON_AddStringToObject(e, "build", build);
    cJSON_AddItemToObject(e, "machine", cli_machine_json(threads));
    return e;
}

/* The 1-minute load; false where the system does not say. */
static bool load_now(double l[3])
{
    return getloadavg(l, 3) == 3;
}

static void warn_if_busy(const cli_load *l, const double load[3], const char *when)
{
    if (load[0] > (double)l->threads && rl_log_get_level() >= RL_LOG_WARN)
        fprintf(stderr, "rl: warning: load average %.2f at the %s exceeds the %d threads: other work "
                        "competes for the processors, so times are inflated and noisy\n",
                load[0], when, l->threads);
}

void cli_load_begin(cli_load *l, int threads)
{
    memset(l, 0, sizeof *l);
    l->threads = threads;
    l->known_start = load_now(l->start);
    if (l->known_start)
        warn_if_busy(l, l->start, "start");
}

void cli_load_end(cli_load *l)
{
    l->known_end = load_now(l->end);
    if (l->known_end)
        warn_if_busy(l, l->end, "end");
}

static cJSON *triple(const double v[3], bool known)
{
    return known ? cJSON_CreateDoubleArray(v, 3) : cJSON_CreateNull();
}

cJSON *cli_load_json(const cli_load *l)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddItemToObject(o, "start", triple(l->start, l->known_start));
    cJSON_AddItemToObject(o, "end", triple(l->end, l->known_end));
    cJSON_AddNumberToObject(o, "threads", l->threads);
    bool busy = (l->known_start && l->start[0] > l->threads) || (l->known_end && l->end[0] > l->threads);
    cJSON_AddBoolToObject(o, "exceeds_threads", busy);
    return o;
}

void cli_load_text(const cli_load *l, char *out, size_t size)
{
    char start[32] = "unknown", end[32] = "unknown";
    if (l->known_start)
        snprintf(start, sizeof start, "%.2f", l->start[0]);
    if (l->known_end)
        snprintf(end, sizeof end, "%.2f", l->end[0]);
    snprintf(out, size, "load average (1 min) %s at the start, %s at the end, %d threads%s", start, end,
             l->threads,
             (l->known_start && l->start[0] > l->threads) || (l->known_end && l->end[0] > l->threads)
                 ? ": busier than the threads, times are inflated"
                 : "");
}

void cli_format_ms(double ms, char *out, size_t size)
{
    if (fabs(ms) >= 10000.0)
        snprintf(out, size, "%.1f s", ms / 1000.0);
    else
        snprintf(out, size, "%.1f ms", ms);
}

void cli_debug(const char *fmt, ...)
{
    if (rl_log_get_level() < RL_LOG_DEBUG)
        return;
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    fprintf(stderr, "rl: debug: %s\n", line);
}

const char *cli_did_you_mean(const char *typed, const char *const *names, size_t count, char *buf,
                             size_t size)
{
    rl_suggestion s = { 0 };
    for (size_t i = 0; i < count; i++)
        rl_suggest(&s, typed, names[i]);
    if (!s.name || size == 0)
        return "";
    snprintf(buf, size, "did you mean '%s'? ", s.name);
    return buf;
}
