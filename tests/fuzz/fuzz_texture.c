/* fuzz_texture.c: libFuzzer harness for the image readers: the texture
 * loader (rl_texture_load: stb_image, PNG/JPEG/BMP/TGA/..., the pixel
 * limit read from the header) and rl_image_read (PNG through libpng, EXR
 * through OpenEXR).
 *
 * Built by `make build-fuzz` (see fuzz_load_json.c); seeds in
 * corpus/texture (tests/fuzz/make_corpus.sh): small PNGs of every colour
 * type and depth, interlaced, and EXRs. An input with the EXR magic goes to
 * rl_image_read as .exr; any other to rl_texture_load and to rl_image_read
 * as .png. The texture limit is lowered to 2^14 pixels (128 x 128, the
 * seeds are at most 9 x 9): the limit's own check is the same at any value,
 * and so is the per-texel conversion below it, but stb_image decodes a
 * BMP or TGA whose pixels are missing as zeros, so a 24-byte TGA claiming
 * 65 x 8194 pixels is a valid picture, and at the earlier 2^20 such inputs
 * cost 88 ms each under ASan, 300 times a typical one, most of it the
 * instrumented conversion loop (bench/README.md, "Fuzzing", 2026-12-06).
 * Any status is fine; crashes, leaks and sanitizer reports are not
 * (findings inside OpenEXR or libpng are theirs: see findings/README.md). */
#include "fuzz_temp.h"

#include <string.h>

#include "rl/rl_image.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    rl_texture_set_max_pixels(1u << 14);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const uint8_t exr_magic[4] = { 0x76, 0x2f, 0x31, 0x01 };
    bool exr = size >= 4 && memcmp(data, exr_magic, 4) == 0;
    char path[512];
    if (!fuzz_temp_write(path, sizeof path, exr ? "exr" : "png", data, size))
        return 0;
    if (!exr) {
        rl_texture *tex = NULL;
        if (rl_texture_load(path, &tex) == RL_OK)
            rl_texture_release(tex);
        rl_clear_error();
    }
    rl_image *img = NULL;
    if (rl_image_read(path, &img) == RL_OK)
        rl_image_release(img);
    rl_clear_error();
    fuzz_temp_done(path);
    return 0;
}
