/* fuzz_approx.c: libFuzzer harness for the approximation loader
 * (rl_approx_load_json: the approx.json of `rl eval`, the resume files of
 * `rl bench`: cJSON, the header keys, the sampling desc, the region tree).
 *
 * Built by `make build-fuzz` (see fuzz_load_json.c); seeds in corpus/approx
 * (tests/fuzz/make_corpus.sh). Each input is written to a per-process
 * temporary file, since the loader reads a file. Any status is fine;
 * crashes, leaks and sanitizer reports are not. */
#define _POSIX_C_SOURCE 200809L
#include <stdint.h>
#include <stdio.h>
#include <unistd.h>

#include "rl/rl_sampling.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/rl_fuzz_%ld.approx.json", (long)getpid());
    FILE *f = fopen(path, "wb");
    if (!f)
        return 0;
    fwrite(data, 1, size, f);
    fclose(f);
    rl_approx *a = NULL;
    if (rl_approx_load_json(path, &a) == RL_OK)
        rl_approx_release(a);
    rl_clear_error();
    return 0;
}
