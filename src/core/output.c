/* output.c: see rl_output.h. The temporary is created with O_EXCL and mode
 * 0666 rather than by mkstemp: mkstemp's 0600 would need the umask to
 * widen it, and reading the umask means setting it, which races with other
 * threads. */
#define _DEFAULT_SOURCE         /* realpath, lstat, fsync */
#include "rl/rl_output.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "core/error.h"
#include "rl/rl_rng.h"

struct rl_output {
    FILE *f;
    char *tmp;                  /* NULL: writing the target directly */
    char *path;                 /* the file to replace, links resolved */
};

typedef struct staged {
    char *tmp;                  /* NULL: written directly, nothing to rename */
    char *path;
} staged;

struct rl_output_batch {
    staged *items;
    size_t count, cap;
    bool committed;
};

/* Where the bytes must end up: a symbolic link's file rather than the
 * link, so that renaming over it does not replace the link by a copy. */
static char *resolve_target(const char *path)
{
    struct stat ls;
    if (lstat(path, &ls) == 0 && S_ISLNK(ls.st_mode)) {
        char *real = realpath(path, NULL);
        if (real)
            return real;
    }
    return rl_strdup(path);
}

/* Six letters that differ between processes, threads and calls; O_EXCL,
 * not the letters, guarantees that no other file is taken over. */
static void random_letters(char *out)
{
    static const char abc[] = "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789";
    static atomic_uint_fast64_t calls;
    struct timespec ts;
    clock_gettime(CLOCK_REALTIME, &ts);
    uint64_t h = rl_hash64(((uint64_t)getpid() << 32) ^ (uint64_t)ts.tv_nsec ^
                           ((uint64_t)ts.tv_sec << 20) ^ (atomic_fetch_add(&calls, 1) * 0x9e3779b97f4a7c15ull));
    for (int i = 0; i < 6; ++i, h /= 62)
        out[i] = abc[h % 62];
}

/* The temporary ".NAME.XXXXXX.EXT" beside target, created empty; *fd open
 * for writing. Messages name `given`, the caller's name for the file. */
static rl_status create_temp(const char *target, const char *given, char **tmp_out, int *fd)
{
    const char *slash = strrchr(target, '/');
    const char *base = slash ? slash + 1 : target;
    const char *ext = strrchr(base, '.');
    if (!ext || ext == base)
        ext = base + strlen(base);
    size_t dir_len = (size_t)(base - target), base_len = strlen(base), ext_len = strlen(ext);
    char *tmp = rl_alloc(dir_len + 1 + base_len + 8 + ext_len + 1);
    if (!tmp)
        return RL_ERR_OUT_OF_MEMORY;
    for (int attempt = 0; attempt < 100; ++attempt) {
        char letters[6];
        random_letters(letters);
        sprintf(tmp, "%.*s.%s.%.6s%s", (int)dir_len, target, base, letters, ext);
        *fd = open(tmp, O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
        if (*fd >= 0) {
            *tmp_out = tmp;
            return RL_OK;
        }
        if (errno != EEXIST)
            break;
    }
    rl_status st = rl_error(RL_ERR_IO, "%s: cannot open for writing: %s", given, strerror(errno));
    free(tmp);
    return st;
}

/* Whether path must be written directly: it exists and is no regular file
 * (a device, FIFO or terminal cannot be replaced by a rename). A folder is
 * an error, found here rather than after the whole file was written. */
static rl_status check_target(const char *path, const char *given, bool *direct)
{
    struct stat s;
    *direct = false;
    if (stat(path, &s) != 0)
        return RL_OK;
    if (S_ISDIR(s.st_mode))
        return rl_error(RL_ERR_IO, "%s: cannot open for writing: %s", given, strerror(EISDIR));
    *direct = !S_ISREG(s.st_mode);
    return RL_OK;
}

/* Renames tmp over path, giving it the mode of the file it replaces. */
static rl_status replace(const char *tmp, const char *path)
{
    struct stat s;
    if (stat(path, &s) == 0 && S_ISREG(s.st_mode))
        chmod(tmp, s.st_mode & 07777);          /* not ours to change: keep the new file's mode */
    if (rename(tmp, path) != 0) {
        rl_status st = rl_error(RL_ERR_IO, "%s: cannot replace it: %s", path, strerror(errno));
        unlink(tmp);
        return st;
    }
    return RL_OK;
}

static void output_free(rl_output *o)
{
    free(o->tmp);
    free(o->path);
    free(o);
}

rl_status rl_output_open(const char *path, rl_output **out)
{
    if (out)
        *out = NULL;
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_output_open: path or out is NULL");
    rl_output *o = rl_calloc(1, sizeof *o);
    if (!o || !(o->path = resolve_target(path))) {
        free(o);
        return RL_ERR_OUT_OF_MEMORY;
    }
    bool direct;
    rl_status st = check_target(o->path, path, &direct);
    if (st == RL_OK && direct) {
        if (!(o->f = fopen(o->path, "wb")))
            st = rl_error(RL_ERR_IO, "%s: cannot open for writing: %s", path, strerror(errno));
    } else if (st == RL_OK) {
        int fd = -1;
        st = create_temp(o->path, path, &o->tmp, &fd);
        if (st == RL_OK && !(o->f = fdopen(fd, "wb"))) {
            st = rl_error(RL_ERR_IO, "%s: cannot open for writing: %s", path, strerror(errno));
            close(fd);
            unlink(o->tmp);
        }
    }
    if (st != RL_OK) {
        output_free(o);
        return st;
    }
    *out = o;
    return RL_OK;
}

FILE *rl_output_file(rl_output *o) { return o ? o->f : NULL; }

const char *rl_output_temp_path(const rl_output *o)
{
    if (!o)
        return NULL;
    return o->tmp ? o->tmp : o->path;
}

rl_status rl_output_commit(rl_output *o)
{
    if (!o)
        return rl_error(RL_ERR_INVALID_ARG, "rl_output_commit: NULL output");
    /* The stream's error flag may have been set by a write long before;
     * errno still holds its reason unless something else failed since. */
    int err = ferror(o->f) ? (errno ? errno : EIO) : 0;
    if (!err && fflush(o->f) != 0)
        err = errno;
    /* Without the sync a crash soon after the rename could leave the new
     * name on an empty file: the old contents lost after all. */
    if (!err && o->tmp && fsync(fileno(o->f)) != 0 && errno != EINVAL)
        err = errno;
    if (fclose(o->f) != 0 && !err)
        err = errno;
    rl_status st = RL_OK;
    if (err) {
        st = rl_error(RL_ERR_IO, "%s: cannot write: %s", o->path, strerror(err));
        if (o->tmp)
            unlink(o->tmp);
    } else if (o->tmp) {
        st = replace(o->tmp, o->path);
    }
    output_free(o);
    return st;
}

void rl_output_abort(rl_output *o)
{
    if (!o)
        return;
    fclose(o->f);
    if (o->tmp)
        unlink(o->tmp);
    output_free(o);
}

rl_status rl_output_batch_create(rl_output_batch **out)
{
    if (!out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_output_batch_create: out is NULL");
    *out = rl_calloc(1, sizeof **out);
    return *out ? RL_OK : RL_ERR_OUT_OF_MEMORY;
}

rl_status rl_output_batch_add(rl_output_batch *b, const char *path, const char **write_to)
{
    if (write_to)
        *write_to = NULL;
    if (!b || !path || !write_to)
        return rl_error(RL_ERR_INVALID_ARG, "rl_output_batch_add: batch, path or write_to is NULL");
    if (b->committed)
        return rl_error(RL_ERR_INVALID_ARG, "rl_output_batch_add: %s: the batch was committed", path);
    if (!rl_reserve((void **)&b->items, &b->cap, b->count + 1, sizeof *b->items, 4))
        return RL_ERR_OUT_OF_MEMORY;
    staged s = { 0 };
    if (!(s.path = resolve_target(path)))
        return RL_ERR_OUT_OF_MEMORY;
    bool direct;
    rl_status st = check_target(s.path, path, &direct);
    if (st == RL_OK && !direct) {
        int fd = -1;
        st = create_temp(s.path, path, &s.tmp, &fd);
        if (st == RL_OK)
            close(fd);
    }
    if (st != RL_OK) {
        free(s.path);
        return st;
    }
    b->items[b->count++] = s;
    *write_to = s.tmp ? s.tmp : s.path;
    return RL_OK;
}

rl_status rl_output_batch_commit(rl_output_batch *b)
{
    if (!b)
        return rl_error(RL_ERR_INVALID_ARG, "rl_output_batch_commit: NULL batch");
    b->committed = true;
    for (size_t i = 0; i < b->count; ++i) {
        staged *s = &b->items[i];
        if (!s->tmp)
            continue;
        rl_status st = replace(s->tmp, s->path);
        free(s->tmp);
        s->tmp = NULL;
        if (st != RL_OK)
            return st;
    }
    return RL_OK;
}

void rl_output_batch_release(rl_output_batch *b)
{
    if (!b)
        return;
    for (size_t i = 0; i < b->count; ++i) {
        if (b->items[i].tmp)
            unlink(b->items[i].tmp);
        free(b->items[i].tmp);
        free(b->items[i].path);
    }
    free(b->items);
    free(b);
}
