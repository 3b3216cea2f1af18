/* cli_scene.c: turns a SCENE argument ("name[:k=v,...]", a .json scene or a
 * mesh file) into a loaded, committed scene. */
#include "cli.h"

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
