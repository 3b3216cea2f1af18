/* load_isolate.c: rl_scene_import runs Assimp (load_assimp.c) where a crash
 * costs an error, not the process: in a child made by fork(), under an
 * address-space limit (RLIMIT_AS), a CPU-time limit (RLIMIT_CPU) and a
 * wall-clock deadline kept by the parent.
 *
 * Why fork and not a helper executable: the child needs the caller's scene
 * as it is (texture sharing by path, unique camera names, ids) and the
 * library's code, and a helper would have to be found on disk. The child
 * runs one thread (the one that forked) and touches no OpenMP; it logs
 * through the stream, never through the caller's log callback (whose locks
 * another thread may have held at the fork), and writes with write(2). It
 * imports into its copy of the scene, streams what the import added through
 * a pipe (import_stream.c) and leaves with _exit, so that no atexit
 * handler, stdio buffer or leak checker of the parent's image runs twice. The parent reads
 * the pipe with poll() until the deadline, kills the child when it passes,
 * reaps it (never a zombie), and turns its end into one error:
 *   a signal                 RL_ERR_CRASHED  "FILE: the importer crashed (signal 11)"
 *   SIGXCPU / CPU time used  RL_ERR_LIMIT    "FILE: the importer ran out of CPU time (N s)"
 *   the deadline             RL_ERR_LIMIT    "FILE: the importer ran out of time (N s)"
 *   out of memory            RL_ERR_LIMIT    "FILE: the importer exceeded its memory limit (N MiB)"
 *   SIGINT (Ctrl-C)          RL_ERR_CANCELLED "FILE: the import was interrupted"
 * The cheap pre-checks of our own (rl_check_mesh_file) run in the parent
 * before the fork. rl_import_limits.in_process skips the child: trusted
 * files only (rl_scene.h). */
#define _GNU_SOURCE   /* pipe2, wait4 */
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "core/error.h"
#include "scene/load_internal.h"
#include "scene/scene_internal.h"

#if defined(__SANITIZE_ADDRESS__)
#define RL_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RL_ASAN 1
#endif
#endif

static rl_import_limits process_limits;

void rl_scene_set_import_limits(const rl_import_limits *limits)
{
    rl_import_limits none = { 0 };
    process_limits = limits ? *limits : none;
}

rl_import_limits rl_scene_import_limits(void)
{
    rl_import_limits l = process_limits;
    if (l.timeout_s == 0)
        l.timeout_s = RL_IMPORT_DEFAULT_TIMEOUT_S;
    if (l.memory_mib == 0)
        l.memory_mib = RL_IMPORT_DEFAULT_MEMORY_MIB;
    return l;
}

/* The desc's non-zero fields over the process-wide limits. */
static rl_import_limits effective_limits(const rl_scene_import_desc *desc)
{
    rl_import_limits l = rl_scene_import_limits();
    if (desc->limits.timeout_s)
        l.timeout_s = desc->limits.timeout_s;
    if (desc->limits.memory_mib)
        l.memory_mib = desc->limits.memory_mib;
    l.in_process = l.in_process || desc->limits.in_process;
    return l;
}

/* The address space this process has mapped now (Linux: /proc/self/statm,
 * in pages); 0 when unknown. The child inherits all of it, so its limit is
 * this plus what the import may add. */
static uint64_t mapped_bytes(void)
{
    FILE *f = fopen("/proc/self/statm", "r");
    if (!f)
        return 0;
    unsigned long long pages = 0;
    if (fscanf(f, "%llu", &pages) != 1)
        pages = 0;
    fclose(f);
    long page = sysconf(_SC_PAGESIZE);
    return page > 0 ? pages * (uint64_t)page : 0;
}

static void child_log(void *user, rl_log_level level, const char *message)
{
    rl_import_writer_warning(user, level, message);
}

/* In the child: limits, the import, the stream; never returns. */
static _Noreturn void run_child(int fd, rl_scene *scene, const char *path, uint32_t parent,
                                const rl_scene_import_desc *desc, const rl_import_limits *lim,
                                uint64_t address_space)
{
    /* A crash here is reported by the parent; a core file of it would
     * only litter the working directory. */
    struct rlimit core = { 0, 0 };
    setrlimit(RLIMIT_CORE, &core);
    /* SIGXCPU at the soft limit, SIGKILL a second later if it is caught. */
    struct rlimit cpu = { lim->timeout_s, (rlim_t)lim->timeout_s + 1 };
    setrlimit(RLIMIT_CPU, &cpu);
#ifndef RL_ASAN
    /* Not under AddressSanitizer: its shadow memory reserves terabytes of
     * address space up front, and any limit would fail every allocation. */
    if (address_space > 0) {
        struct rlimit as = { address_space, address_space };
        setrlimit(RLIMIT_AS, &as);
    }
#else
    (void)address_space;
#endif
    /* A Ctrl-C ends the import, whatever handler the parent had: the
     * parent reports it as cancelled. */
    signal(SIGINT, SIG_DFL);
    rl_import_writer w;
    rl_import_writer_init(&w, fd, scene);
    rl_log_set_callback(child_log, &w);
    rl_clear_error();
    uint32_t root = RL_NONE;
    rl_status st = rl_assimp_import(scene, path, parent, desc, &root);
    rl_log_set_callback(NULL, NULL);
    const char *msg = rl_last_error();
    rl_import_writer_finish(&w, scene, st, msg[0] ? msg : rl_status_string(st), root);
    _exit(w.failed ? 3 : 0);
}

static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct pipe_result {
    uint8_t *bytes;
    size_t len, cap;
    bool timed_out, too_big, no_memory, failed;
} pipe_result;

/* Reads fd to its end, the deadline, or max bytes. */
static void read_child(int fd, double deadline, size_t max, pipe_result *r)
{
    for (;;) {
        double left = deadline - now_s();
        if (left <= 0.0) {
            r->timed_out = true;
            return;
        }
        struct pollfd p = { fd, POLLIN, 0 };
        int n = poll(&p, 1, left > 1e6 ? 1000000000 : (int)(left * 1000.0) + 1);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0) {
            r->failed = true;   /* the stream ends short and is reported malformed */
            return;
        }
        if (n == 0)
            continue;
        if (r->len == r->cap) {
            if (r->len >= max) {
                r->too_big = true;
                return;
            }
            size_t want = r->cap ? r->cap * 2 : 1u << 20;
            if (!rl_reserve((void **)&r->bytes, &r->cap, want < max ? want : max, 1, 1u << 20)) {
                r->no_memory = true;
                return;
            }
        }
        ssize_t k = read(fd, r->bytes + r->len, r->cap - r->len);
        if (k < 0 && (errno == EINTR || errno == EAGAIN))
            continue;
        if (k < 0)
            r->failed = true;
        if (k <= 0)
            return;
        r->len += (size_t)k;
    }
}

static rl_status import_isolated(rl_scene *scene, const char *path, uint32_t parent,
                                 const rl_scene_import_desc *desc, const rl_import_limits *lim,
                                 uint32_t *root_node)
{
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot start the importer: pipe: %s", path,
                        strerror(errno));
    /* A pipe holds 64 KiB by default: the child would stop at every 64 KiB
     * until the parent is scheduled to read. 1 MiB (the unprivileged
     * maximum) lets both run; failing to get it only costs time. */
#ifdef F_SETPIPE_SZ
    fcntl(fds[0], F_SETPIPE_SZ, 1 << 20);
#endif
    uint64_t allowance = (uint64_t)lim->memory_mib << 20;
    uint64_t mapped = mapped_bytes();
    double start = now_s();
    pid_t pid = fork();
    if (pid < 0) {
        int e = errno;
        close(fds[0]);
        close(fds[1]);
        return rl_error(RL_ERR_IO, "%s: cannot start the importer: fork: %s", path, strerror(e));
    }
    if (pid == 0) {
        close(fds[0]);
        run_child(fds[1], scene, path, parent, desc, lim, mapped ? mapped + allowance : 0);
    }
    close(fds[1]);
    /* The stream holds at most what the child could allocate, and some
     * slack for its framing. */
    pipe_result r = { 0 };
    read_child(fds[0], start + lim->timeout_s, (size_t)(allowance + (64u << 20)), &r);
    close(fds[0]);
    if (r.timed_out || r.too_big || r.no_memory || r.failed)
        kill(pid, SIGKILL);   /* it must not outlive our interest in it */
    int status = 0;
    struct rusage ru;
    memset(&ru, 0, sizeof ru);
    while (wait4(pid, &status, 0, &ru) < 0 && errno == EINTR)
        ;
    double cpu_s = (double)ru.ru_utime.tv_sec + (double)ru.ru_stime.tv_sec +
                   1e-6 * ((double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_usec);
    rl_debug("%s: imported in a child process: %.3f s, %.3f s CPU, %ld MiB peak, %zu bytes back",
             path, now_s() - start, cpu_s, ru.ru_maxrss / 1024, r.len);
    rl_status st = RL_OK;
    if (r.timed_out)
        st = rl_error(RL_ERR_LIMIT, "%s: the importer ran out of time (%u s)", path, lim->timeout_s);
    else if (r.too_big)
        st = rl_error(RL_ERR_LIMIT, "%s: the importer's result exceeds %u MiB", path,
                      lim->memory_mib + 64);
    else if (r.no_memory)
        st = rl_error(RL_ERR_OUT_OF_MEMORY, "%s: out of memory reading the importer's result",
                      path);
    else if (WIFSIGNALED(status) &&
             (WTERMSIG(status) == SIGXCPU ||
              (WTERMSIG(status) == SIGKILL && cpu_s >= (double)lim->timeout_s)))
        st = rl_error(RL_ERR_LIMIT, "%s: the importer ran out of CPU time (%u s)", path,
                      lim->timeout_s);
    else if (WIFSIGNALED(status) && WTERMSIG(status) == SIGINT)
        st = rl_error(RL_ERR_CANCELLED, "%s: the import was interrupted", path);
    else if (r.failed)
        st = rl_error(RL_ERR_IO, "%s: reading the importer's result failed", path);
    else if (WIFSIGNALED(status))
        st = rl_error(RL_ERR_CRASHED, "%s: the importer crashed (signal %d)", path,
                      WTERMSIG(status));
    else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        /* Sanitizer builds report a crash and exit with a status. */
        st = rl_error(RL_ERR_CRASHED, "%s: the importer crashed (exit status %d)", path,
                      WIFEXITED(status) ? WEXITSTATUS(status) : -1);
    else
        st = rl_import_stream_apply(scene, r.bytes, r.len, path, parent, lim->memory_mib,
                                    root_node);
    free(r.bytes);
    return st;
}

RL_API rl_status rl_scene_import(rl_scene *scene, const char *path, uint32_t parent,
                                 uint32_t *root_node)
{
    return rl_scene_import_with(scene, path, parent, NULL, root_node);
}

RL_API rl_status rl_scene_import_with(rl_scene *scene, const char *path, uint32_t parent,
                                      const rl_scene_import_desc *desc, uint32_t *root_node)
{
    if (!scene || !path || !root_node)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_import: NULL argument");
    rl_scene_import_desc defaults = { 0 };
    if (!desc)
        desc = &defaults;
    rl_status st = rl_scene_check_mutable(scene, "rl_scene_import");
    if (st != RL_OK)
        return st;
    if (parent >= scene->num_nodes)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_import: no parent node %u", parent);

    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    fclose(f);
    st = rl_check_mesh_file(path);
    if (st != RL_OK)
        return st;
    rl_import_limits lim = effective_limits(desc);
    if (lim.in_process)
        return rl_assimp_import(scene, path, parent, desc, root_node);
    return import_isolated(scene, path, parent, desc, &lim, root_node);
}
