/* fuzz_approx.c: libFuzzer harness for the approximation loader
 * (rl_approx_load_json: the approx.json of `rl eval`, the resume files of
 * `rl bench`: cJSON, the header keys, the sampling desc, the region tree).
 *
 * Built by `make build-fuzz` (see fuzz_load_json.c); seeds in corpus/approx
 * (tests/fuzz/make_corpus.sh). Each input is written to a per-process
 * temporary file (fuzz_temp.h), since the loader reads a file. Any status
 * is fine; crashes, leaks and sanitizer reports are not. */
#include "fuzz_temp.h"

#include "rl/rl_sampling.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char path[512];
    if (!fuzz_temp_write(path, sizeof path, "approx.json", data, size))
        return 0;
    rl_approx *a = NULL;
    if (rl_approx_load_json(path, &a) == RL_OK)
        rl_approx_release(a);
    rl_clear_error();
    fuzz_temp_done(path);
    return 0;
}
