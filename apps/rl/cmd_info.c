/* cmd_info.c: `rl info SCENE [--json]`: what a scene contains after loading
 * and flattening (rl_scene_stats), and the cameras and lights a render of it
 * uses. */
#include "cli.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

static const char info_help[] =
    "usage: rl info SCENE [--json] [model-file flags]\n"
    "\n"
    "Loads SCENE and prints its statistics: nodes, meshes, objects, triangles,\n"
    "vertices, materials, textures, lights, cameras, bounds, memory, dropped\n"
    "triangles; then the cameras and lights a render will use (a model file's\n"
    "framing camera and default lights included).\n"
    "\n"
    "SCENE  a built-in name (see rl scenes), optionally with parameters\n"
    "       (cornell-teapot:triangles=70000), a .json scene or a mesh file\n"
    "       (OBJ, PLY, STL, glTF, ...)\n"
    "\n"
    "options:\n"
    "  --json   print the statistics as one JSON object\n"
    CLI_MODEL_FLAGS_HELP
    "\n"
    "example:\n"
    "  rl info cornell\n"
    "  rl info city:blocks=4 --json\n";

static void print_camera(const char *name, const rl_camera *c, const char *note)
{
    rl_camera r = rl_camera_resolve(c);
    printf("  camera %-10s eye (%g, %g, %g), target (%g, %g, %g), fov %.4g deg, %dx%d%s\n", name,
           r.eye.x, r.eye.y, r.eye.z, r.target.x, r.target.y, r.target.z, r.fov_deg, r.width,
           r.height, note);
}

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
    if (!data)
        return;
    /* What a render uses: every camera (the first is the default), or the
     * framing made for a scene without one; and every light, including
     * the defaults a model file gets. */
    for (uint32_t i = 0; i < data->num_cameras; i++)
        print_camera(data->camera_names && data->camera_names[i] ? data->camera_names[i] : "?",
                     &data->cameras[i], i == 0 ? " (default)" : "");
    if (data->num_cameras == 0) {
        rl_camera cam;
        if (rl_scene_get_camera(scene, NULL, &cam) == RL_OK)
            print_camera("framed", &cam, " (default: fits the model, refitted to --size)");
    }
    for (uint32_t i = 0; i < data->num_lights; i++) {
        const rl_light *l = &data->lights[i];
        printf("  light %-5u %-11s colour (%g, %g, %g) x %g", i, rl_light_type_name(l->type),
               l->color.x, l->color.y, l->color.z, l->intensity);
        if (l->type != RL_LIGHT_DIRECTIONAL)
            printf(", at (%g, %g, %g)", l->position.x, l->position.y, l->position.z);
        if (l->type == RL_LIGHT_DIRECTIONAL || l->type == RL_LIGHT_SPOT)
            printf(", towards (%g, %g, %g)", l->direction.x, l->direction.y, l->direction.z);
        if (l->type == RL_LIGHT_SPOT)
            printf(", cone %g..%g deg", l->spot_inner_deg, l->spot_outer_deg);
        putchar('\n');
    }
}

int cli_info(int argc, char **argv)
{
    const char *source = NULL;
    bool json = false;
    cli_model_flags model = { "" };
    for (int i = 1; i < argc; i++) {
        if (cli_is_help(argv[i])) {
            fputs(info_help, stdout);
            return RL_CLI_OK;
        }
        int m;
        if (strcmp(argv[i], "--json") == 0)
            json = true;
        else if ((m = cli_take_model_flag(argc, argv, &i, &model)) != 0) {
            if (m < 0)
                return RL_CLI_USAGE;
        } else if (argv[i][0] == '-' || source)
            return cli_unknown_arg("info", argv[i]);
        else
            source = argv[i];
    }
    if (!source)
        return cli_fail(RL_CLI_USAGE, "info: missing SCENE (see rl info --help)");

    rl_scene *scene = NULL;
    int rc = cli_load_scene_with(source, &model, &scene);
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
