/* fuzz_load_mesh.c: libFuzzer harness for mesh files through Assimp plus our
 * own checks (load_assimp.c, load_validate.c). The first input byte picks
 * the file extension (obj, ply, stl, gltf, off, dae), the rest is the file.
 * Built and run like fuzz_load_json.c (make build-fuzz, make check's smoke
 * run on corpus/mesh, whose files start with their extension byte; make
 * fuzz), with -detect_leaks=0 (see below).
 *
 * Findings inside Assimp 5.2 itself show where our pre-checks need to grow:
 * so far an ai_assert abort on PLY faces with fewer than 3 corners and
 * endless loops on PLY headers with control bytes or non-numeric ascii
 * bodies (also when the file is named .gltf: Assimp falls back to sniffing
 * the content), all now rejected by load_validate.c. Assimp also leaks a
 * little on some malformed PLY input (no renderlab frames in the report),
 * hence -detect_leaks=0.
 *
 * The import runs in this process (rl_import_limits.in_process): isolated,
 * a crash in Assimp would become an error and the fuzzer would stop seeing
 * what is left to pre-check.
 *
 * Its time per input is Assimp's: about 2.5 ms of CPU under ASan, most of
 * it the OBJ importer's stream buffer (16 MB allocated, zeroed and filled
 * per import, a fresh mmap under ASan's allocator), our checks and mapping
 * about 5 % (bench/README.md, "Fuzzing", 2026-12-06). */
#include "fuzz_temp.h"

#include "rl/rl_scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const char *const ext[] = { "obj", "ply", "stl", "gltf", "off", "dae" };
    if (size < 1)
        return 0;
    static bool configured;
    if (!configured) {
        rl_scene_set_import_limits(&(rl_import_limits){ .in_process = true });
        configured = true;
    }
    char path[512];
    if (!fuzz_temp_write(path, sizeof path, ext[data[0] % (sizeof ext / sizeof ext[0])], data + 1, size - 1))
        return 0;
    rl_scene *scene = NULL;
    if (rl_scene_load(path, NULL, &scene) == RL_OK)
        rl_scene_release(scene);
    rl_clear_error();
    fuzz_temp_done(path);
    return 0;
}
