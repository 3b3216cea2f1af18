/* cmd_info.c: `rl info SCENE [--json]`: what a scene contains after loading
 * and flattening (rl_scene_stats) and which cameras it brings. */
#include "cli.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

static const char info_help[] =
    "usage: rl info SCENE [--json]\n"
    "\n"
    "Loads SCENE and prints its statistics: nodes, meshes, objects, triangles,\n"
    "vertices, materials, textures, lights, cameras, bounds, memory, dropped\n"
    "triangles, and the names of its cameras.\n"
    "\n"
    "SCENE  a built-in name (see rl scenes), optionally with parameters\n"
    "       (cornell-teapot:triangles=70000), a .json scene or a mesh file\n"
    "       (OBJ, PLY, STL, glTF, ...)\n"
    "\n"
    "options:\n"
    "  --json   print the statistics as one JSON object\n"
    "\n"
    "example:\n"
    "  rl info cornell\n"
    "  rl info city:blocks=4 --json\n";

static void print_text(const rl_scene *scene)
{
    rl_scene_stats st;
    rl_scene_get_stats(scene, &st);
    printf("scene        %s\n", rl_scene_name(scene) ? rl_scene_name(scene) : "");
    printf("nodes        %u\n", st.nodes);
    printf("meshes       %u (%llu triangles)\n", st.meshes,
           (unsigned long long)st.mesh_triangles);
    printf("objects      %u\n", st.objects);
    printf("triangles    %llu\n", (unsigned long long)st.triangles);
    printf("vertices     %llu\n", (unsigned long long)st.vertices);
    printf("emissive     %llu triangles\n", (unsigned long long)st.emissive_triangles);
    printf("materials    %u\n", st.materials);
    printf("textures     %u\n", st.textures);
    printf("lights       %u\n", st.lights);
    printf("bounds       (%g, %g, %g) .. (%g, %g, %g)\n", st.bounds.min.x, st.bounds.min.y,
           st.bounds.min.z, st.bounds.max.x, st.bounds.max.y, st.bounds.max.z);
    printf("memory       %.2f MiB\n", (double)st.memory_bytes / (1024.0 * 1024.0));
    printf("dropped      %llu degenerate, %llu non-finite triangles\n",
           (unsigned long long)st.dropped_degenerate, (unsigned long long)st.dropped_nonfinite);
    printf("cameras      %u", st.cameras);
    const rl_scene_data *data = rl_scene_get_data(scene);
    for (uint32_t i = 0; data && i < data->num_cameras; i++)
        printf("%s%s", i ? ", " : ": ",
               data->camera_names && data->camera_names[i] ? data->camera_names[i] : "?");
    putchar('\n');
}

int cli_info(int argc, char **argv)
{
    const char *source = NULL;
    bool json = false;
    for (int i = 1; i < argc; i++) {
        if (cli_is_help(argv[i])) {
            fputs(info_help, stdout);
            return RL_CLI_OK;
        }
        if (strcmp(argv[i], "--json") == 0)
            json = true;
        else if (argv[i][0] == '-' || source)
            return cli_unknown_arg("info", argv[i]);
        else
            source = argv[i];
    }
    if (!source)
        return cli_fail(RL_CLI_USAGE, "info: missing SCENE (see rl info --help)");

    rl_scene *scene = NULL;
    int rc = cli_load_scene(source, &scene);
    if (rc != RL_CLI_OK)
        return rc;
    if (json) {
        cJSON *obj = cli_scene_stats_json(scene);
        char *text = obj ? cJSON_Print(obj) : NULL;
        if (text)
            printf("%s\n", text);
        else
            rc = cli_fail(RL_CLI_FAIL, "out of memory");
        free(text);
        cJSON_Delete(obj);
    } else {
        print_text(scene);
    }
    rl_scene_release(scene);
    return rc;
}
