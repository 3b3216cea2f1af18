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
 * temporary file first (fuzz_temp.h: a tmpfs where there is one). "file"
 * and "texture" keys may name real files; run it in a scratch directory.
 * Any status is fine; crashes, leaks and sanitizer reports are not. */
#include "fuzz_temp.h"

#include "rl/rl_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[512];
    if (!fuzz_temp_write(path, sizeof path, "json", data, size))
        return 0;
    rl_scene *scene = NULL;
    if (rl_scene_load_json(path, &scene) == RL_OK)
        rl_scene_release(scene);
    rl_clear_error();
    fuzz_temp_done(path);
    return 0;
}
