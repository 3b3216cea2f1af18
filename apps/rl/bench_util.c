/* bench_util.c: see bench_util.h. */
#define _POSIX_C_SOURCE 200809L
#include "bench_util.h"

#include "bench_rays.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "rl/rl_options.h"

void bench_note(const char *bench, const char *fmt, ...)
{
    if (rl_log_get_level() < RL_LOG_INFO)
        return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "bench %s: ", bench);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void bench_add_num(cJSON *o, const char *key, double value)
{
    if (isfinite(value))
        cJSON_AddNumberToObject(o, key, value);
    else
        cJSON_AddNullToObject(o, key);
}

uint64_t bench_rays_total(const rl_render_stats *s)
{
    uint64_t n = 0;
    for (int k = 0; k < RL_RAY_TYPE_COUNT; k++)
        n += s->rays[k];
    return n;
}

cJSON *bench_rays_json(const rl_render_stats *s)
{
    cJSON *o = cJSON_CreateObject();
    for (int k = 0; o && k < RL_RAY_TYPE_COUNT; k++)
        cJSON_AddNumberToObject(o, rl_ray_type_name((rl_ray_type)k), (double)s->rays[k]);
    if (o)
        cJSON_AddNumberToObject(o, "total", (double)bench_rays_total(s));
    return o;
}

cJSON *bench_metrics_json(const rl_image_metrics *m)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    bench_add_num(o, "ssim", m->ssim);
    bench_add_num(o, "rmse", m->rmse);
    bench_add_num(o, "psnr", m->psnr);    /* null when the images are equal */
    bench_add_num(o, "max_abs", m->max_abs);
    cJSON_AddNumberToObject(o, "pixels", (double)m->pixels);
    return o;
}

double bench_ratio(double a, double b)
{
    return b != 0.0 ? a / b : NAN;
}

bool bench_parse_count(const char *option, const char *text, long long max, long long *out)
{
    long long v;
    if (!rl_parse_int(text, &v) || v < 1 || v > max) {
        cli_fail(RL_CLI_USAGE, "%s: expected a whole number in 1..%lld, got '%s'", option, max,
                    text);
        return false;
    }
    *out = v;
    return true;
}

bool bench_parse_sections(const char *text, const char *const *names, int count,
                             unsigned *sections)
{
    *sections = 0;
    const char *p = text;
    for (;;) {
        size_t n = strcspn(p, ",");
        int found = -1;
        for (int k = 0; k < count; k++)
            if (n == strlen(names[k]) && strncmp(p, names[k], n) == 0)
                found = k;
        if (found < 0) {
            char list[256] = "";
            for (int k = 0; k < count; k++) {
                size_t len = strlen(list);
                snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "", names[k]);
            }
            cli_fail(RL_CLI_USAGE, "--only: expected sections among %s, got '%s'", list, text);
            return false;
        }
        *sections |= 1u << found;
        if (p[n] == '\0')
            return true;
        p += n + 1;
    }
}

bool bench_default_out(const char *prefix, char *path, size_t size)
{
    time_t now = time(NULL);
    struct tm utc;
    char stamp[32];
    if (!gmtime_r(&now, &utc) || !strftime(stamp, sizeof stamp, "%Y%m%d-%H%M%S", &utc))
        snprintf(stamp, sizeof stamp, "%lld", (long long)now);
    snprintf(path, size, "bench/results/%s-%s.json", prefix, stamp);
    return cli_make_dirs("bench/results");
}

bool bench_out_path(const char *given, const char *prefix, char *path, size_t size)
{
    if (!given)
        return bench_default_out(prefix, path, size);
    if ((size_t)snprintf(path, size, "%s", given) >= size) {
        cli_fail(RL_CLI_USAGE, "--out: path longer than %zu characters", size - 1);
        return false;
    }
    return cli_check_writable(path);
}

int bench_run_sections(const char *bench, cJSON *root, const char *const *names,
                          const bench_section_fn *fns, int count, unsigned wanted, void *ctx,
                          char *reason, int threads, const char *out)
{
    int rc = RL_CLI_OK;
    char failed[512] = "";
    for (int k = 0; k < count; k++) {
        if (!((wanted >> k) & 1u))
            continue;
        cJSON *sec = cJSON_AddObjectToObject(root, names[k]);
        if (!sec) {
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
            break;
        }
        reason[0] = '\0';
        rl_clear_error();
        rl_status st = fns[k](ctx, sec);
        if (st == RL_OK) {
            cJSON_AddStringToObject(sec, "status", "ok");
            continue;
        }
        /* The other sections may still work: record why and go on. */
        const char *why = reason[0] ? reason : rl_last_error();
        if (!why || !*why)
            why = rl_status_string(st);
        cJSON_AddStringToObject(sec, "status", "failed");
        cJSON_AddStringToObject(sec, "reason", why);
        printf("\n%s: failed: %s\n", names[k], why);
        if (!failed[0])
            snprintf(failed, sizeof failed, "%s (%s)", names[k], why);
    }
    /* Again for the load average after the run: how busy the machine was. */
    cJSON *machine = cli_machine_json(threads);
    if (machine && !cJSON_ReplaceItemInObjectCaseSensitive(root, "machine", machine))
        cJSON_Delete(machine);
    if (rc == RL_CLI_OK) {
        if (!cJSON_GetObjectItem(root, "machine") || !cJSON_GetObjectItem(root, "parameters"))
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
        else if (!cli_write_json(root, out))
            rc = RL_CLI_FAIL;
        else
            bench_note(bench, "wrote %s", out);
    }
    if (rc == RL_CLI_OK && failed[0])
        rc = cli_fail(RL_CLI_FAIL, "bench %s: section %s failed", bench, failed);
    return rc;
}

double bench_cpu_ms(void)
{
    struct timespec ts;
    if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0)
        return 0.0;
    return (double)ts.tv_sec * 1e3 + (double)ts.tv_nsec * 1e-6;
}

rl_status bench_render_for_cpu(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *img,
                               int threads, double budget_s, bench_budget_run *out)
{
    bench_budget_run run = { 0 };
    rl_status st = RL_OK;
    rl_timer timer;
    if (threads < 1)
        threads = 1;
    do {
        rl_render_stats s;
        double c0 = bench_cpu_ms();
        rl_timer_start(&timer);
        st = rl_renderer_render(r, scene, cam, img, &s);
        run.wall_ms += rl_timer_ms(&timer);
        run.cpu_ms += bench_cpu_ms() - c0;
        run.frames++;
    } while (st == RL_OK && run.cpu_ms / 1e3 / threads < budget_s);
    *out = run;
    return st;
}
