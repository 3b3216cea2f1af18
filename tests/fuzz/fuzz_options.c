/* fuzz_options.c: libFuzzer harness for the option parsing of `rl render`:
 * its argument parser (parse_args: every flag, the number, size, vector
 * and duration parsers, the output checks) and, for a command line it
 * accepts, the renderer it names configured by its --set KEY=VALUE
 * options (rl_renderer_create, rl_renderer_set: the typed option tables of
 * every renderer) and the frame plan. Nothing is loaded or rendered.
 *
 * The parser is static in apps/rl/cmd_render.c, so this file includes that
 * source; the other apps/rl sources but main.c are linked in
 * (tests/fuzz/CMakeLists.txt). An input is a command line: arguments
 * separated by NUL or newline bytes, after an implicit "render". The CLI
 * prints its error lines to stderr: run with -close_fd_mask=3 (smoke.sh
 * and `make fuzz` do). Any exit code is fine; crashes, leaks and sanitizer
 * reports are not. Seeds: corpus/options. */
#include "../../apps/rl/cmd_render.c"

#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

enum { MAX_ARGS = 64 };

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *text = malloc(size + 1);
    char *argv[MAX_ARGS + 2];
    const char **sets = calloc(MAX_ARGS + 2, sizeof *sets);
    if (!text || !sets) {
        free(text);
        free(sets);
        return 0;
    }
    memcpy(text, data, size);
    text[size] = '\0';
    int argc = 0;
    argv[argc++] = "render";
    for (char *p = text; argc <= MAX_ARGS && p <= text + size;) {
        char *end = p;
        while (end < text + size && *end != '\n' && *end != '\0')
            ++end;
        *end = '\0';
        argv[argc++] = p;
        p = end + 1;
    }
    argv[argc] = NULL;
    render_args a = { .algo = "raster", .preview_s = -1.0, .sets = sets };
    int rc = parse_args(argc, argv, &a);
    if (rc == RL_CLI_OK)
        rc = check_outputs(&a);
    rl_renderer *r = NULL;
    if (rc == RL_CLI_OK)
        rc = create_renderer(&a, &r);
    loop_plan plan;
    if (rc == RL_CLI_OK && !a.camera_path)
        plan_loop(&a, r, &plan);
    rl_renderer_release(r);
    rl_clear_error();
    free(sets);
    free(text);
    return 0;
}
