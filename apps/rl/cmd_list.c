/* cmd_list.c: `rl scenes` and `rl algos`: what the library offers, read from
 * its registries (rl_builtin_scenes, rl_renderer_list) so the lists never
 * drift from the code. */
#include "cli.h"

/* Takes only --help; anything else is a usage error. */
static int no_arguments(int argc, char **argv, const char *help)
{
    for (int i = 1; i < argc; i++) {
        if (cli_is_help(argv[i])) {
            fputs(help, stdout);
            return -1;
        }
        return cli_unknown_arg(argv[0], argv[i]);
    }
    return RL_CLI_OK;
}

int cli_scenes(int argc, char **argv)
{
    int rc = no_arguments(argc, argv,
                          "usage: rl scenes\n"
                          "\n"
                          "Lists the built-in scenes with their description and parameters\n"
                          "(key, type, default, help, range), the same tables rl algos prints.\n"
                          "Parameters follow the scene name after a colon wherever a scene\n"
                          "is expected.\n"
                          "\n"
                          "example:\n"
                          "  rl scenes\n"
                          "  rl render cornell-teapot:triangles=70000 --out teapot.png\n");
    if (rc != RL_CLI_OK)
        return rc < 0 ? RL_CLI_OK : rc;
    size_t count = 0;
    const rl_builtin_info *scenes = rl_builtin_scenes(&count);
    for (size_t i = 0; i < count; i++) {
        printf("%s: %s\n", scenes[i].name, scenes[i].description ? scenes[i].description : "");
        printf("  parameters:%s\n", scenes[i].num_options ? "" : " none");
        for (size_t k = 0; k < scenes[i].num_options; k++)
            cli_print_option(stdout, &scenes[i].options[k]);
        putchar('\n');
    }
    /* A model file takes parameters too (rl_model_options). */
    size_t num_model = 0;
    const rl_option_info *model = rl_model_options(&num_model);
    printf("model files (OBJ, PLY, STL, glTF, DAE, FBX, 3DS, ... as FILE:key=value): framed and "
           "lit when they bring no camera or light\n  parameters:\n");
    for (size_t k = 0; k < num_model; k++)
        cli_print_option(stdout, &model[k]);
    return RL_CLI_OK;
}

int cli_algos(int argc, char **argv)
{
    int rc = no_arguments(argc, argv,
                          "usage: rl algos   (alias: rl renderers)\n"
                          "\n"
                          "Lists the renderers with their description, paper reference and\n"
                          "options (key, type, default, help). Set options on the command line\n"
                          "with --set key=value; the key may carry the renderer's name.\n"
                          "\n"
                          "example:\n"
                          "  rl algos\n"
                          "  rl render cornell --algo raster --set raster.shading=flat "
                          "--out flat.png\n");
    if (rc != RL_CLI_OK)
        return rc < 0 ? RL_CLI_OK : rc;
    size_t count = 0;
    const rl_renderer_info *list = rl_renderer_list(&count);
    for (size_t i = 0; i < count; i++) {
        printf("%s: %s\n", list[i].name, list[i].description ? list[i].description : "");
        if (list[i].reference && *list[i].reference)
            printf("  reference: %s\n", list[i].reference);
        if (list[i].regions)
            printf("  distributable: renders image regions, so rl --dist render spreads it over MPI ranks\n");
        if (list[i].progressive)
            printf("  progressive: rl render adds frames until --time or --spp (default budget %g s)\n",
                   list[i].default_time_s);
        rl_renderer *r = NULL;
        rl_clear_error();
        if (rl_renderer_create(list[i].name, &r) != RL_OK)
            return cli_fail_status(RL_CLI_FAIL, rl_last_status(), list[i].name);
        char why[256];
        if (!rl_renderer_available(r, why, sizeof why))
            printf("  unavailable: %s\n", why);
        size_t num_options = 0;
        const rl_option_info *options = rl_renderer_options(r, &num_options);
        printf("  options:%s\n", num_options ? "" : " none");
        for (size_t k = 0; k < num_options; k++)
            cli_print_option(stdout, &options[k]);
        rl_renderer_release(r);
        if (i + 1 < count)
            putchar('\n');
    }
    return RL_CLI_OK;
}
