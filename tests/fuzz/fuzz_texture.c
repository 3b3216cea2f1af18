/* fuzz_texture.c: libFuzzer harness for the image readers: the texture
 * loader (rl_texture_load: stb_image, PNG/JPEG/BMP/TGA/..., the pixel
 * limit read from the header) and rl_image_read (PNG through libpng, EXR
 * through OpenEXR).
 *
 * Built by `make build-fuzz` (see fuzz_load_json.c); seeds in
 * corpus/texture (tests/fuzz/make_corpus.sh): small PNGs of every colour
 * type and depth, interlaced, and EXRs. An input with the EXR magic goes to
 * rl_image_read as .exr; any other to rl_texture_load and to rl_image_read
 * as .png. The texture limit is lowered to 2^20 pixels so that an input
 * claiming a huge picture costs milliseconds, not a gigabyte; the limit's
 * own check is the same at any value. Any status is fine; crashes, leaks
 * and sanitizer reports are not (findings inside OpenEXR or libpng are
 * theirs: see findings/README.md). */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "rl/rl_image.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    rl_texture_set_max_pixels(1u << 20);
    return 0;
}

static bool put(const char *path, const uint8_t *data, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return false;
    fwrite(data, 1, size, f);
    return fclose(f) == 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static const uint8_t exr_magic[4] = { 0x76, 0x2f, 0x31, 0x01 };
    bool exr = size >= 4 && memcmp(data, exr_magic, 4) == 0;
    char path[64];
    snprintf(path, sizeof path, "/tmp/rl_fuzz_%ld.%s", (long)getpid(), exr ? "exr" : "png");
    if (!put(path, data, size))
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
    return 0;
}
