/* fuzz_linespace_cache.c: libFuzzer harness for the Line Space cache
 * loader (rl_linespace_load: header, sizes against the file's length,
 * checksum, grid and scene fingerprint, array contents) and the queries on
 * what it accepts.
 *
 * The grid is fixed: the builtin Cornell box in a 2x2x2 grid, so that the
 * seeds (corpus/linespace, written by this harness when RL_FUZZ_WRITE_SEEDS
 * names a folder: `make_corpus.sh`) belong to it and mutations reach the
 * checks after the fingerprint. The file's checksum would stop almost
 * every mutation before those checks; so each input is loaded twice: as
 * it is, and with its last 8 bytes replaced by the checksum of the rest
 * (linespace_io.c's own rl_ls_file_hash, so the two cannot drift apart).
 * A loaded Line Space answers a few rays: a file that passed the checks must be safe to query. Any
 * status is fine; crashes, leaks and sanitizer reports are not. */
#include "fuzz_temp.h"

#include <string.h>

#include "rl/rl_accel.h"
#include "rl/rl_linespace.h"
#include "rl/rl_scene.h"

#include "accel/linespace_internal.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static rl_scene *scene;
static rl_accel *grid;

/* The seeds: every payload and list kind this grid can hold, small. */
static void write_seeds(const char *dir)
{
    static const struct { const char *name; rl_linespace_desc desc; } seeds[] = {
        { "fixed-k2.rlls", { .n = 1, .k = 2 } },
        { "dynamic.rlls", { .n = 1, .dynamic = true } },
        { "pnmt.rlls", { .n = 1, .payloads = RL_LS_PNMT } },
        { "dynamic-pnmt.rlls", { .n = 1, .dynamic = true, .payloads = RL_LS_CANDIDATES | RL_LS_PNMT } },
    };
    for (size_t i = 0; i < sizeof seeds / sizeof seeds[0]; ++i) {
        rl_linespace *ls = NULL;
        char path[1024];
        snprintf(path, sizeof path, "%s/%s", dir, seeds[i].name);
        if (rl_linespace_create(grid, &seeds[i].desc, &ls) != RL_OK || rl_linespace_commit(ls) != RL_OK ||
            rl_linespace_save(ls, path) != RL_OK)
            fprintf(stderr, "fuzz_linespace_cache: %s: %s\n", path, rl_last_error());
        rl_linespace_release(ls);
    }
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    if (rl_scene_create_builtin("cornell", NULL, &scene) != RL_OK ||
        rl_accel_create(scene, &(rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { 2, 2, 2 } }, &grid) != RL_OK ||
        rl_accel_commit(grid) != RL_OK) {
        fprintf(stderr, "fuzz_linespace_cache: cannot build the grid: %s\n", rl_last_error());
        abort();
    }
    const char *dir = getenv("RL_FUZZ_WRITE_SEEDS");
    if (dir && *dir)
        write_seeds(dir);
    return 0;
}

static void load(const uint8_t *data, size_t size)
{
    char path[512];
    if (!fuzz_temp_write(path, sizeof path, "rlls", data, size))
        return;
    rl_linespace *ls = NULL;
    if (rl_linespace_load(grid, path, &ls) == RL_OK) {
        rl_linespace_stats s;
        rl_linespace_get_stats(ls, &s);
        /* Rays from inside the box through its voxels, in every octant. */
        for (int i = 0; i < 8; ++i) {
            rl_vec3 dir = rl_v3(i & 1 ? 1.0f : -1.0f, i & 2 ? 0.7f : -0.7f, i & 4 ? 0.4f : -0.4f);
            rl_ray ray = { .o = rl_v3(0.278f, 0.27f, 0.28f), .d = dir, .t_min = 0.0f, .t_max = 1e30f };
            rl_hit hit;
            if (s.payloads & RL_LS_CANDIDATES) {
                rl_linespace_intersect(ls, &ray, &hit);
                rl_linespace_occluded(ls, &ray);
            }
            if (s.payloads & RL_LS_PNMT) {
                rl_ray r2 = ray;
                rl_ls_surface surf;
                rl_linespace_pnmt_intersect(ls, &r2, &surf);
                rl_linespace_pnmt_occluded(ls, &ray);
            }
        }
        rl_linespace_release(ls);
    }
    rl_clear_error();
    fuzz_temp_done(path);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    load(data, size);
    if (size >= 16) {
        uint8_t *fixed = malloc(size);
        if (!fixed)
            return 0;
        memcpy(fixed, data, size);
        uint64_t sum = rl_ls_file_hash(0, fixed, size - 8);
        memcpy(fixed + size - 8, &sum, 8);
        load(fixed, size);
        free(fixed);
    }
    return 0;
}
