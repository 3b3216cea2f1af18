/* fuzz_temp.h: the per-input temporary file of the harnesses whose loader
 * reads a path (JSON scenes, meshes, approx.json, Line Space caches,
 * textures).
 *
 * Where it lies decides the harness's speed. Rewriting one file in /tmp
 * cost 5.9 ms per input on the ext4 of the 2026-12-06 VM (mounted with
 * `discard`: the truncation of fopen "wb" frees the old blocks with a
 * synchronous discard, and ext4's auto_da_alloc writes the new contents
 * back on close because the file was truncated), 41 us when the file is
 * removed after each input (nothing is ever allocated on the disk) and 11
 * us in a tmpfs (/dev/shm: 11 us rewritten in place, 28 us created and
 * removed), with the same bytes reaching the loader (bench/README.md,
 * "Fuzzing", 2026-12-06). So the file goes to $RL_FUZZ_TMPDIR when set,
 * else /dev/shm when it is a writable folder, else /tmp; in a tmpfs it is
 * rewritten in place and removed when the process exits, elsewhere
 * removed after each input. The name holds the process id, so that
 * harnesses running side by side never share a file. */
#ifndef RL_FUZZ_TEMP_H
#define RL_FUZZ_TEMP_H

#define _POSIX_C_SOURCE 200809L
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/vfs.h>
#include <unistd.h>

#define FUZZ_TMPFS_MAGIC 0x01021994     /* statfs f_type of a tmpfs (linux/magic.h) */

static const char *fuzz_temp_dir_name;
static bool fuzz_temp_in_memory;
/* The files left in the tmpfs, one per extension (the mesh harness has six). */
#define FUZZ_TEMP_MAX_FILES 8
static char fuzz_temp_kept[FUZZ_TEMP_MAX_FILES][512];

static void fuzz_temp_remove_kept(void)
{
    for (int i = 0; i < FUZZ_TEMP_MAX_FILES && fuzz_temp_kept[i][0]; ++i)
        remove(fuzz_temp_kept[i]);
}

static const char *fuzz_temp_dir(void)
{
    if (!fuzz_temp_dir_name) {
        const char *env = getenv("RL_FUZZ_TMPDIR");
        fuzz_temp_dir_name = env && *env ? env : access("/dev/shm", W_OK | X_OK) == 0 ? "/dev/shm" : "/tmp";
        struct statfs fs;
        fuzz_temp_in_memory = statfs(fuzz_temp_dir_name, &fs) == 0 && fs.f_type == FUZZ_TMPFS_MAGIC;
        if (fuzz_temp_in_memory)
            atexit(fuzz_temp_remove_kept);
    }
    return fuzz_temp_dir_name;
}

/* path[path_size] names this process's file with the extension ext ("json",
 * "tar.gz": without the dot); data[size] written to it. False when it
 * cannot be written (the input is then skipped). */
static bool fuzz_temp_write(char *path, size_t path_size, const char *ext, const uint8_t *data, size_t size)
{
    snprintf(path, path_size, "%s/rl_fuzz_%ld.%s", fuzz_temp_dir(), (long)getpid(), ext);
    FILE *f = fopen(path, "wb");
    if (!f)
        return false;
    bool ok = fwrite(data, 1, size, f) == size;
    return fclose(f) == 0 && ok;
}

/* After the input: see above. */
static void fuzz_temp_done(const char *path)
{
    int i = 0;
    while (fuzz_temp_in_memory && i < FUZZ_TEMP_MAX_FILES && fuzz_temp_kept[i][0] &&
           strcmp(fuzz_temp_kept[i], path) != 0)
        ++i;
    if (!fuzz_temp_in_memory || i == FUZZ_TEMP_MAX_FILES)
        remove(path);
    else if (!fuzz_temp_kept[i][0])
        snprintf(fuzz_temp_kept[i], sizeof fuzz_temp_kept[i], "%s", path);
}

#endif
