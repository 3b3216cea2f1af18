/* plugin.c: `rl --plugin FILE.so`: renderers from outside renderlab in rl.
 *
 * A plugin is a shared object that defines
 *     rl_status rl_plugin_init(void);
 * and registers its renderers there with rl_renderer_register()
 * (rl_render.h); they are then listed by `rl algos` and usable wherever a
 * renderer is named (render, compare, eval, bench). rl exports the
 * library's public functions (cmake/rl.dynlist), so the plugin calls the
 * very registry this process uses; it should not link renderlab itself (a
 * second copy would be a second registry). Plugins stay loaded until exit:
 * their classes are in the registry for good. */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <dlfcn.h>

typedef rl_status (*plugin_init_fn)(void);

int cli_load_plugin(const char *path)
{
    void *handle = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!handle)
        return cli_fail(RL_CLI_FAIL, "--plugin %s: %s", path, dlerror());
    /* POSIX's way from an object pointer to a function pointer. */
    plugin_init_fn init;
    *(void **)&init = dlsym(handle, "rl_plugin_init");
    if (!init) {
        dlclose(handle);
        return cli_fail(RL_CLI_FAIL, "--plugin %s: defines no rl_plugin_init()", path);
    }
    rl_status st = init();
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, path);
    return 0;
}
