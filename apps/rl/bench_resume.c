/* bench_resume.c: see bench_resume.h. */
#define _POSIX_C_SOURCE 200809L
#include "bench_resume.h"

#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct bench_resume {
    char dir[1024];
    char path[1280];
};

/* The whole file, NUL-terminated and malloc'd; NULL if it cannot be read
 * (*missing tells a file that is not there from one that fails). */
static char *slurp(const char *path, bool *missing)
{
    *missing = false;
    FILE *f = fopen(path, "rb");
    if (!f) {
        *missing = true;
        return NULL;
    }
    char *text = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 4096 + 1 > cap) {
            cap = cap ? 2 * cap : 8192;
            char *t = realloc(text, cap);
            if (!t) {
                free(text);
                fclose(f);
                return NULL;
            }
            text = t;
        }
        size_t n = fread(text + len, 1, 4096, f);
        len += n;
        if (n < 4096)
            break;
    }
    bool ok = !ferror(f);
    fclose(f);
    if (!ok) {
        free(text);
        return NULL;
    }
    text[len] = '\0';
    return text;
}

/* Through a temporary and a rename (rl_output.h): a run killed while
 * saving leaves the previous state, never half a file. */
static bool write_atomic(const char *path, const char *text)
{
    rl_output *o = NULL;
    rl_clear_error();
    rl_status st = rl_output_open(path, &o);
    if (st == RL_OK) {
        fputs(text, rl_output_file(o));
        st = rl_output_commit(o);
    }
    if (st != RL_OK)
        cli_fail_status(RL_CLI_FAIL, st, path);
    return st == RL_OK;
}

bool bench_resume_open(const char *dir, const char *key, bench_resume **out)
{
    *out = NULL;
    if (strlen(dir) >= sizeof((bench_resume *)0)->dir) {
        cli_fail(RL_CLI_FAIL, "%s: path too long", dir);
        return false;
    }
    if (!cli_make_dirs(dir))
        return false;
    bench_resume *r = calloc(1, sizeof *r);
    if (!r) {
        cli_fail(RL_CLI_FAIL, "out of memory");
        return false;
    }
    snprintf(r->dir, sizeof r->dir, "%s", dir);
    const char *key_path = bench_resume_path(r, "key.txt");
    bool missing = false;
    char *have = slurp(key_path, &missing);
    bool ok;
    if (have) {
        ok = strcmp(have, key) == 0;
        if (!ok)
            cli_fail(RL_CLI_FAIL, "%s holds a run with other options (%.*s), not this one (%.*s); use another "
                        "folder or the same options", dir, (int)strcspn(have, "\n"), have,
                        (int)strcspn(key, "\n"), key);
    } else if (missing) {
        ok = write_atomic(key_path, key);
    } else {
        ok = false;
        cli_fail(RL_CLI_FAIL, "%s: cannot read", key_path);
    }
    free(have);
    if (!ok) {
        free(r);
        return false;
    }
    *out = r;
    return true;
}

void bench_resume_close(bench_resume *r)
{
    free(r);
}

const char *bench_resume_path(bench_resume *r, const char *name)
{
    snprintf(r->path, sizeof r->path, "%s/%s", r->dir, name);
    return r->path;
}

bool bench_resume_load(bench_resume *r, const char *name, double **values, size_t *count)
{
    *values = NULL;
    *count = 0;
    const char *path = bench_resume_path(r, name);
    bool missing = false;
    char *text = slurp(path, &missing);
    if (!text) {
        if (!missing)
            cli_fail(RL_CLI_FAIL, "%s: cannot read", path);
        return missing;
    }
    cJSON *root = cJSON_Parse(text);
    free(text);
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, "values");
    int n = cJSON_IsArray(arr) ? cJSON_GetArraySize(arr) : -1;
    double *v = n >= 0 ? malloc((size_t)(n > 0 ? n : 1) * sizeof *v) : NULL;
    bool ok = v != NULL;
    for (int i = 0; ok && i < n; ++i) {
        const cJSON *x = cJSON_GetArrayItem(arr, i);
        ok = cJSON_IsNumber(x) && isfinite(x->valuedouble);
        if (ok)
            v[i] = x->valuedouble;
    }
    cJSON_Delete(root);
    if (!ok) {
        free(v);
        cli_fail(RL_CLI_FAIL, "%s: not a saved series ({\"values\": [numbers]}); delete it to measure again",
                    bench_resume_path(r, name));
        return false;
    }
    *values = v;
    *count = (size_t)n;
    return true;
}

bool bench_resume_save(bench_resume *r, const char *name, const double *values, size_t count)
{
    cJSON *root = cJSON_CreateObject();
    cJSON *arr = root ? cJSON_AddArrayToObject(root, "values") : NULL;
    bool ok = arr != NULL;
    for (size_t i = 0; ok && i < count; ++i)
        ok = cJSON_AddItemToArray(arr, cJSON_CreateNumber(values[i]));
    char *text = ok ? cJSON_Print(root) : NULL;
    cJSON_Delete(root);
    if (!text) {
        cli_fail(RL_CLI_FAIL, "out of memory while saving %s", name);
        return false;
    }
    ok = write_atomic(bench_resume_path(r, name), text);
    free(text);
    return ok;
}

bool bench_resume_save_approx(bench_resume *r, const char *name, const rl_approx *a)
{
    /* Atomic itself (rl_output.h); the caller reports the library's error. */
    return rl_approx_save_json(a, bench_resume_path(r, name)) == RL_OK;
}

rl_status bench_resume_load_approx(bench_resume *r, const char *name, rl_approx **out)
{
    *out = NULL;
    const char *path = bench_resume_path(r, name);
    FILE *f = fopen(path, "r");
    if (!f)
        return RL_OK;
    fclose(f);
    return rl_approx_load_json(path, out);
}
