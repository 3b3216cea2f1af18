/* fuzz_load_json.c: libFuzzer harness for the JSON scene loader
 * (rl_scene_load_json: cJSON + positions, every key reader, transforms,
 * materials, lights, cameras, camera paths).
 *
 * Built with clang by `make build-fuzz` (RL_FUZZ=ON: the library
 * instrumented, ASan+UBSan) into build-fuzz/tests/fuzz/; `make check` runs a
 * short deterministic smoke run on corpus/json (tests/fuzz/smoke.sh), `make
 * fuzz FUZZ_SECONDS=N` a longer one that keeps what it finds.
 *
 * The loader reads a file, so each input is written to a per-process
 * temporary file first. "file" and "texture" keys may name real files;
 * run it in a scratch directory. Any status is fine; crashes, leaks and
 * sanitizer reports are not. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

#include "rl/rl_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/rl_fuzz_%ld.json", (long)getpid());
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    rl_scene *scene = NULL;
    if (rl_scene_load_json(path, &scene) == RL_OK)
        rl_scene_release(scene);
    rl_clear_error();
    return 0;
}
