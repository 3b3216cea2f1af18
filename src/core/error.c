/* error.c: status strings, first-error-per-thread messages, log dispatch. */
#include "core/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static _Thread_local char tls_message[1024];
static _Thread_local rl_status tls_status = RL_OK;

static rl_log_fn log_fn;
static void *log_user;
static rl_log_level log_level = RL_LOG_INFO;

const char *rl_status_string(rl_status status)
{
    switch (status) {
#define RL_STATUS_CASE(code, value, msg) case code: return msg;
        RL_STATUS_LIST(RL_STATUS_CASE)
#undef RL_STATUS_CASE
    default: return "unknown status";
    }
}

const char *rl_status_name(rl_status status)
{
    switch (status) {
#define RL_STATUS_CASE(code, value, msg) case code: return #code;
        RL_STATUS_LIST(RL_STATUS_CASE)
#undef RL_STATUS_CASE
    default: return "RL_STATUS_UNKNOWN";
    }
}

const char *rl_last_error(void) { return tls_message; }
rl_status rl_last_status(void) { return tls_status; }

void rl_clear_error(void)
{
    tls_message[0] = '\0';
    tls_status = RL_OK;
}

rl_status rl_error(rl_status status, const char *fmt, ...)
{
    /* The first error is the cause; later ones are usually its consequences. */
    if (tls_status != RL_OK || status == RL_OK)
        return status;
    tls_status = status;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(tls_message, sizeof tls_message, fmt, ap);
    va_end(ap);
    return status;
}

void rl_log_set_callback(rl_log_fn fn, void *user)
{
    log_fn = fn;
    log_user = user;
}

void rl_log_set_level(rl_log_level level) { log_level = level; }
rl_log_level rl_log_get_level(void) { return log_level; }

const char *rl_log_level_name(rl_log_level level)
{
    static const char *names[] = { "error", "warning", "info", "debug" };
    return (unsigned)level < 4 ? names[level] : "log";
}

void rl_log(rl_log_level level, const char *fmt, ...)
{
    if (!log_fn || level > log_level)
        return;
    char line[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    log_fn(log_user, level, line);
}

void *rl_alloc(size_t size)
{
    void *p = malloc(size ? size : 1);
    if (!p)
        rl_error(RL_ERR_OUT_OF_MEMORY, "out of memory allocating %zu bytes", size);
    return p;
}

void *rl_calloc(size_t count, size_t size)
{
    void *p = calloc(count ? count : 1, size ? size : 1);
    if (!p)
        rl_error(RL_ERR_OUT_OF_MEMORY, "out of memory allocating %zu x %zu bytes", count, size);
    return p;
}

void *rl_realloc_array(void *p, size_t count, size_t size)
{
    if (size && count > SIZE_MAX / size) {
        rl_error(RL_ERR_OUT_OF_MEMORY, "allocation of %zu x %zu bytes overflows", count, size);
        return NULL;
    }
    size_t bytes = count * size;
    void *q = realloc(p, bytes ? bytes : 1);
    if (!q)
        rl_error(RL_ERR_OUT_OF_MEMORY, "out of memory allocating %zu x %zu bytes", count, size);
    return q;
}

size_t rl_grow_capacity(size_t cap, size_t count, size_t first)
{
    if (count <= cap)
        return cap;
    size_t n = cap ? cap : (first ? first : 1);
    while (n < count)
        n = n > SIZE_MAX / 2 ? count : n * 2;
    return n;
}

bool rl_reserve(void **array, size_t *cap, size_t count, size_t item_size, size_t first)
{
    if (count <= *cap)
        return true;
    size_t n = rl_grow_capacity(*cap, count, first);
    void *p = rl_realloc_array(*array, n, item_size);
    if (!p)
        return false;
    *array = p;
    *cap = n;
    return true;
}

bool rl_reserve_u32(void **array, uint32_t *cap, uint64_t count, size_t item_size, uint32_t first)
{
    if (count > UINT32_MAX) {
        rl_error(RL_ERR_OUT_OF_MEMORY, "more than 2^32 elements of %zu bytes", item_size);
        return false;
    }
    size_t c = *cap;
    if (!rl_reserve(array, &c, (size_t)count, item_size, first))
        return false;
    *cap = c > UINT32_MAX ? UINT32_MAX : (uint32_t)c;
    return true;
}

char *rl_strdup(const char *s)
{
    size_t n = strlen(s) + 1;
    char *d = rl_alloc(n);
    if (d)
        memcpy(d, s, n);
    return d;
}
