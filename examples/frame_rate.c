/* frame_rate.c: how fast one renderer draws a scene frame after frame, as
 * `rl view` asks for them while the camera moves: one renderer and one
 * image kept over all frames, the camera flying a little forward each
 * frame (a fiftieth of a percent of the distance to its target, as W held
 * in the viewer). Prints one JSON object with every frame's wall and
 * process CPU time and the minima over the frames after the first (which
 * carries the renderer's preparation). bench/README.md, "rl view", uses it.
 *
 *     frame_rate SCENE RENDERER FRAMES [WxH [KEY=VALUE ...]]
 *     frame_rate city raster 8 1280x720 threads=2
 *
 * Build against an installed renderlab:
 *     cc frame_rate.c $(pkg-config --cflags --libs renderlab) -o frame_rate */
#define _POSIX_C_SOURCE 200809L
#include <rl/rl.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static double clock_ms(clockid_t id)
{
    struct timespec t;
    clock_gettime(id, &t);
    return (double)t.tv_sec * 1e3 + (double)t.tv_nsec * 1e-6;
}

static int usage(void)
{
    fprintf(stderr, "usage: frame_rate SCENE RENDERER FRAMES [WxH [KEY=VALUE ...]]\n");
    return 2;
}

int main(int argc, char **argv)
{
    if (argc < 4)
        return usage();
    const int frames = atoi(argv[3]);
    int width = 1280, height = 720;
    if (frames < 2 || frames > 10000 || (argc > 4 && (sscanf(argv[4], "%dx%d", &width, &height) != 2 ||
                                                     width < 1 || height < 1)))
        return usage();

    rl_scene *scene = NULL;
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam;
    rl_status st = rl_scene_load(argv[1], NULL, &scene);
    if (st == RL_OK)
        st = rl_scene_get_camera(scene, NULL, &cam);
    if (st == RL_OK)
        st = rl_renderer_create(argv[2], &r);
    for (int i = 5; i < argc && st == RL_OK; ++i) {
        char *eq = strchr(argv[i], '=');
        if (!eq) {
            fprintf(stderr, "frame_rate: expected KEY=VALUE, got '%s'\n", argv[i]);
            return 2;
        }
        *eq = '\0';
        st = rl_renderer_set(r, argv[i], eq + 1);
    }
    cam.width = width;
    cam.height = height;
    /* The viewer's layers: the renderers write IDs and depth there too. */
    if (st == RL_OK)
        st = rl_image_create(width, height, RL_LAYER_COLOR | RL_LAYER_DEPTH | RL_LAYER_ID, &img);
    const rl_vec3 step = rl_scale(rl_sub(cam.target, cam.eye), 2e-4f);
    double min_wall = 0.0, min_cpu = 0.0;
    if (st == RL_OK)
        printf("{\"scene\": \"%s\", \"renderer\": \"%s\", \"width\": %d, \"height\": %d, \"frames\": [",
               argv[1], argv[2], width, height);
    for (int f = 0; f < frames && st == RL_OK; ++f) {
        rl_camera c = cam;
        c.eye = rl_add(cam.eye, rl_scale(step, (float)f));
        c.target = rl_add(cam.target, rl_scale(step, (float)f));
        rl_render_stats stats;
        memset(&stats, 0, sizeof stats);
        const double wall0 = clock_ms(CLOCK_MONOTONIC), cpu0 = clock_ms(CLOCK_PROCESS_CPUTIME_ID);
        st = rl_renderer_render(r, scene, &c, img, &stats);
        const double wall = clock_ms(CLOCK_MONOTONIC) - wall0, cpu = clock_ms(CLOCK_PROCESS_CPUTIME_ID) - cpu0;
        if (st != RL_OK)
            break;
        if (f == 1 || (f > 1 && wall < min_wall))
            min_wall = wall;
        if (f == 1 || (f > 1 && cpu < min_cpu))
            min_cpu = cpu;
        printf("%s\n  {\"wall_ms\": %.2f, \"cpu_ms\": %.2f, \"triangles\": %llu, \"points\": %llu, \"pixels\": %llu}",
               f ? "," : "", wall, cpu, (unsigned long long)stats.triangles_rasterized,
               (unsigned long long)stats.points_drawn, (unsigned long long)stats.pixels_written);
    }
    if (st == RL_OK)
        printf("],\n \"min_wall_ms\": %.2f, \"min_cpu_ms\": %.2f}\n", min_wall, min_cpu);
    else
        fprintf(stderr, "frame_rate: %s\n", rl_last_error());
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(scene);
    return st == RL_OK ? 0 : 1;
}
