/* cli_scene.c: turns a SCENE argument ("name[:k=v,...]", a .json scene or a
 * mesh file) into a loaded, committed scene. */
#include "cli.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

bool cli_is_builtin(const char *name)
{
    size_t count = 0;
    const rl_builtin_info *list = rl_builtin_scenes(&count);
    for (size_t i = 0; i < count; i++)
        if (strcmp(list[i].name, name) == 0)
            return true;
    return false;
}

bool cli_is_model_file(const char *arg)
{
    char *source = NULL, *params = NULL;
    if (!cli_split_source(arg, &source, &params))
        return false;
    bool model = !cli_is_builtin(source) && !cli_has_extension(source, (const char *const[]){ ".json", NULL });
    free(source);
    free(params);
    return model;
}

static void append_param(cli_model_flags *f, const char *key, const char *value)
{
    size_t n = strlen(f->params);
    snprintf(f->params + n, sizeof f->params - n, "%s%s=%s", n ? "," : "", key, value);
}

int cli_take_model_flag(int argc, char **argv, int *i, cli_model_flags *flags)
{
    const char *v = NULL;
    int m;
    if (strcmp(argv[*i], "--headlight") == 0) {
        append_param(flags, "headlight", "true");
        return 1;
    }
    if ((m = cli_take_value(argc, argv, i, "--file-cameras", &v)) != 0) {
        if (m > 0)
            append_param(flags, "cameras", v);
        return m;
    }
    if ((m = cli_take_value(argc, argv, i, "--file-lights", &v)) != 0) {
        if (m > 0)
            append_param(flags, "lights", v);
        return m;
    }
    if ((m = cli_take_value(argc, argv, i, "--orbit", &v)) != 0) {
        if (m < 0)
            return m;
        double az, el;
        char tail;
        if (sscanf(v, "%lf,%lf%c", &az, &el, &tail) != 2) {
            cli_fail(RL_CLI_USAGE, "--orbit: expected AZIMUTH,ELEVATION in degrees, got '%s'", v);
            return -1;
        }
        char text[64];
        snprintf(text, sizeof text, "%.9g", az);
        append_param(flags, "azimuth", text);
        snprintf(text, sizeof text, "%.9g", el);
        append_param(flags, "elevation", text);
        return 1;
    }
    return 0;
}

int cli_load_scene_with(const char *arg, const cli_model_flags *flags, rl_scene **out)
{
    if (!flags || !flags->params[0])
        return cli_load_scene(arg, out);
    char *source = NULL, *params = NULL;
    if (!cli_split_source(arg, &source, &params))
        return cli_fail(RL_CLI_FAIL, "out of memory");
    bool builtin = cli_is_builtin(source), json = cli_has_extension(source, (const char *const[]){ ".json", NULL });
    int rc = RL_CLI_OK;
    if (builtin || json) {
        rc = cli_fail(RL_CLI_USAGE, "%s: --file-cameras, --file-lights, --headlight and --orbit "
                      "apply to model files, not to %s", arg, builtin ? "built-in scenes" : "JSON scenes");
    } else {
        /* The flags come after the source's own parameters: the last value
         * of a key wins. */
        size_t n = strlen(source) + (params ? strlen(params) : 0) + strlen(flags->params) + 3;
        char *joined = malloc(n);
        if (!joined)
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
        else {
            snprintf(joined, n, "%s:%s%s%s", source, params ? params : "", params ? "," : "",
                     flags->params);
            rc = cli_load_scene(joined, out);
            free(joined);
        }
    }
    free(source);
    free(params);
    return rc;
}

int cli_load_scene(const char *arg, rl_scene **out)
{
    char *source = NULL, *params = NULL;
    if (!cli_split_source(arg, &source, &params))
        return cli_fail(RL_CLI_FAIL, "out of memory");
    rl_clear_error();
    rl_status st = rl_scene_load(source, params, out);
    int rc = RL_CLI_OK;
    if (st != RL_OK) {
        /* The loader's message names the file (and line:col for JSON); only
         * add the argument when it would otherwise be missing. */
        const char *msg = rl_last_error();
        bool named = msg && strstr(msg, source) != NULL;
        /* A bad parameter of a built-in was typed on the command line: that
         * is usage (2), whereas a bad value inside a file is input (1). */
        int code = st == RL_ERR_INVALID_ARG && cli_is_builtin(source) ? RL_CLI_USAGE : RL_CLI_FAIL;
        /* Neither a file nor a built-in: perhaps a typo of a built-in. */
        size_t count = 0;
        const rl_builtin_info *list = rl_builtin_scenes(&count);
        rl_suggestion sg = { 0 };
        for (size_t i = 0; st == RL_ERR_IO && !cli_is_builtin(source) && i < count; i++)
            rl_suggest(&sg, source, list[i].name);
        if (sg.name)
            rc = cli_fail(code, "%s (did you mean '%s'?)", msg && *msg ? msg : rl_status_string(st), sg.name);
        else
            rc = cli_fail_status(code, st, named ? NULL : arg);
    }
    free(source);
    free(params);
    return rc;
}
