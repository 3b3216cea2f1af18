/* cli_stats.c: scene and render statistics as JSON and as a summary line,
 * shared by `rl info --json`, `rl render --stats-json` and `rl demo`. */
#include "cli.h"

#include <cjson/cJSON.h>
#include <stdlib.h>
#include <string.h>

static cJSON *vec3_json(rl_vec3 v)
{
    const double xyz[3] = { v.x, v.y, v.z };
    return cJSON_CreateDoubleArray(xyz, 3);
}

/* cJSON stores numbers as double: exact for counts below 2^53. */
static void add_count(cJSON *obj, const char *key, uint64_t value)
{
    cJSON_AddNumberToObject(obj, key, (double)value);
}

cJSON *cli_scene_stats_json(const rl_scene *scene)
{
    rl_scene_stats st;
    rl_scene_get_stats(scene, &st);
    cJSON *obj = cJSON_CreateObject();
    if (!obj)
        return NULL;
    cJSON_AddStringToObject(obj, "name", rl_scene_name(scene) ? rl_scene_name(scene) : "");
    add_count(obj, "nodes", st.nodes);
    add_count(obj, "meshes", st.meshes);
    add_count(obj, "objects", st.objects);
    add_count(obj, "mesh_triangles", st.mesh_triangles);
    add_count(obj, "triangles", st.triangles);
    add_count(obj, "vertices", st.vertices);
    add_count(obj, "emissive_triangles", st.emissive_triangles);
    add_count(obj, "materials", st.materials);
    add_count(obj, "textures", st.textures);
    add_count(obj, "lights", st.lights);
    add_count(obj, "cameras", st.cameras);
    add_count(obj, "memory_bytes", st.memory_bytes);
    add_count(obj, "dropped_degenerate", st.dropped_degenerate);
    add_count(obj, "dropped_nonfinite", st.dropped_nonfinite);
    cJSON *bounds = cJSON_AddObjectToObject(obj, "bounds");
    if (bounds) {
        cJSON_AddItemToObject(bounds, "min", vec3_json(st.bounds.min));
        cJSON_AddItemToObject(bounds, "max", vec3_json(st.bounds.max));
    }
    cJSON *names = cJSON_AddArrayToObject(obj, "camera_names");
    const rl_scene_data *data = rl_scene_is_committed(scene) ? rl_scene_get_data(scene) : NULL;
    if (names && data)
        for (uint32_t i = 0; i < data->num_cameras; i++)
            cJSON_AddItemToArray(names, cJSON_CreateString(
                                            data->camera_names && data->camera_names[i]
                                                ? data->camera_names[i] : ""));
    /* The cameras and lights in full, as rl info prints them. */
    cJSON *views = cJSON_AddArrayToObject(obj, "camera_list");
    for (uint32_t i = 0; views && data && i <= data->num_cameras; i++) {
        rl_camera c;
        if (i == data->num_cameras && (i > 0 || rl_scene_get_camera(scene, NULL, &c) != RL_OK))
            break;
        if (i < data->num_cameras)
            c = data->cameras[i];
        c = rl_camera_resolve(&c);
        cJSON *v = cJSON_CreateObject();
        if (!v)
            break;
        cJSON_AddStringToObject(v, "name", i < data->num_cameras && data->camera_names
                                               ? data->camera_names[i] : "framed");
        cJSON_AddItemToObject(v, "eye", vec3_json(c.eye));
        cJSON_AddItemToObject(v, "target", vec3_json(c.target));
        cJSON_AddItemToObject(v, "up", vec3_json(c.up));
        cJSON_AddNumberToObject(v, "fov_deg", c.fov_deg);
        cJSON_AddNumberToObject(v, "width", c.width);
        cJSON_AddNumberToObject(v, "height", c.height);
        cJSON_AddItemToArray(views, v);
    }
    cJSON *lights = cJSON_AddArrayToObject(obj, "light_list");
    for (uint32_t i = 0; lights && data && i < data->num_lights; i++) {
        const rl_light *l = &data->lights[i];
        cJSON *v = cJSON_CreateObject();
        if (!v)
            break;
        cJSON_AddStringToObject(v, "type", rl_light_type_name(l->type));
        cJSON_AddItemToObject(v, "color", vec3_json(l->color));
        cJSON_AddNumberToObject(v, "intensity", l->intensity);
        cJSON_AddItemToObject(v, "position", vec3_json(l->position));
        cJSON_AddItemToObject(v, "direction", vec3_json(l->direction));
        cJSON_AddItemToArray(lights, v);
    }
    return obj;
}

cJSON *cli_render_stats_json(const rl_render_stats *stats, double inputs_ms)
{
    cJSON *obj = cJSON_CreateObject();
    if (!obj)
        return NULL;
    /* One-time preparation apart from the frame: select on city spends
     * most of its first render building, which is not its frame time. */
    cJSON_AddNumberToObject(obj, "time_ms", stats->time_ms);
    cJSON_AddNumberToObject(obj, "prep_ms", inputs_ms + stats->prep_ms);
    cJSON_AddNumberToObject(obj, "frame_ms", stats->time_ms - stats->prep_ms);
    cJSON_AddNumberToObject(obj, "inputs_ms", inputs_ms);
    cJSON *rays = cJSON_AddObjectToObject(obj, "rays");
    uint64_t total = 0;
    for (int t = 0; t < RL_RAY_TYPE_COUNT; t++) {
        if (rays)
            add_count(rays, rl_ray_type_name((rl_ray_type)t), stats->rays[t]);
        total += stats->rays[t];
    }
    add_count(obj, "rays_total", total);
    add_count(obj, "triangles_rasterized", stats->triangles_rasterized);
    add_count(obj, "points_drawn", stats->points_drawn);
    add_count(obj, "occlusion_queries", stats->occlusion_queries);
    add_count(obj, "pixels_written", stats->pixels_written);
    add_count(obj, "samples", stats->samples);
    if (stats->device)
        cJSON_AddStringToObject(obj, "device", stats->device);
    return obj;
}

rl_status cli_write_json_status(const cJSON *item, const char *path)
{
    char *text = cJSON_Print(item);
    if (!text)
        return RL_ERR_OUT_OF_MEMORY;
    rl_output *o = NULL;
    rl_status st = rl_output_open(path, &o);
    if (st == RL_OK) {
        fputs(text, rl_output_file(o));
        fputc('\n', rl_output_file(o));
        st = rl_output_commit(o);
    }
    free(text);
    return st;
}

bool cli_write_json(const cJSON *item, const char *path)
{
    rl_clear_error();
    rl_status st = cli_write_json_status(item, path);
    if (st != RL_OK)
        cli_fail_status(RL_CLI_FAIL, st, path);
    return st == RL_OK;
}

/* The counters of a summary line, each only where it applies. */
static void print_counters(FILE *out, const rl_render_stats *stats)
{
    /* Rasterization counts only for the algorithms that rasterize. */
    if (stats->triangles_rasterized)
        fprintf(out, ", %llu triangles rasterized", (unsigned long long)stats->triangles_rasterized);
    if (stats->points_drawn)
        fprintf(out, ", %llu points", (unsigned long long)stats->points_drawn);
    if (stats->occlusion_queries)
        fprintf(out, ", %llu occlusion queries", (unsigned long long)stats->occlusion_queries);
    fprintf(out, ", %llu pixels written", (unsigned long long)stats->pixels_written);
    /* Ray counts only for the algorithms that trace any. */
    for (int t = 0; t < RL_RAY_TYPE_COUNT; t++)
        if (stats->rays[t])
            fprintf(out, ", %llu %s rays", (unsigned long long)stats->rays[t],
                    rl_ray_type_name((rl_ray_type)t));
    fputc('\n', out);
}

void cli_print_summary(FILE *out, const char *algo, const char *scene, int width,
                          int height, const rl_render_stats *stats, double inputs_ms)
{
    char prep[32], frame[32];
    cli_format_ms(inputs_ms + stats->prep_ms, prep, sizeof prep);
    cli_format_ms(stats->time_ms - stats->prep_ms, frame, sizeof frame);
    fprintf(out, "%s %dx%d %s: prep %s, frame %s", algo, width, height, scene, prep, frame);
    print_counters(out, stats);
}

void cli_print_accumulation_summary(FILE *out, const char *algo, const char *scene, int width, int height,
                                    const rl_render_stats *sum, double inputs_ms, const cli_accumulation *acc)
{
    char prep[32], frame[32];
    cli_format_ms(inputs_ms + sum->prep_ms, prep, sizeof prep);
    double frames = acc->frames > 0 ? (double)acc->frames : 1.0;
    cli_format_ms((sum->time_ms - sum->prep_ms) / frames, frame, sizeof frame);
    fprintf(out, "%s %dx%d %s: prep %s, %lld frame%s, %.4g spp in %.3g s", algo, width, height, scene, prep,
            acc->frames, acc->frames == 1 ? "" : "s", acc->spp, acc->elapsed_s);
    /* Why it stopped, so that a short render is not mistaken for a budget. */
    if (strcmp(acc->stopped, "interrupt") == 0)
        fprintf(out, " (interrupted by Ctrl-C)");
    else if (strcmp(acc->stopped, "spp") == 0)
        fprintf(out, " (target %lld spp)", acc->target_spp);
    else
        fprintf(out, " (time budget %.3g s)", acc->budget_s);
    fprintf(out, ", frame %s on average", frame);
    print_counters(out, sum);
}
