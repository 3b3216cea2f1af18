/* render_scene.c: the smallest renderlab program. Loads a built-in scene,
 * renders it with one renderer (the rasterizer unless told otherwise) and
 * writes a PNG.
 *
 *     render_scene [OUT.png [RENDERER [SCENE]]]     default: render_scene.png raster cornell
 *
 * Build against an installed renderlab:
 *     cc render_scene.c $(pkg-config --cflags --libs renderlab) -o render_scene */
#include <rl/rl.h>

#include <stdio.h>

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : "render_scene.png";
    const char *algo = argc > 2 ? argv[2] : "raster";
    const char *source = argc > 3 ? argv[3] : "cornell";

    rl_scene *scene = NULL;
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam;
    rl_render_stats stats;
    /* Every call that can fail returns a status; the first failure on this
     * thread keeps its message for rl_last_error(). */
    rl_status st = rl_scene_load(source, NULL, &scene);   /* committed */
    if (st == RL_OK)
        st = rl_scene_get_camera(scene, NULL, &cam);
    cam.width = 320;
    cam.height = 240;
    if (st == RL_OK)
        st = rl_renderer_create(algo, &r);
    if (st == RL_OK)
        st = rl_image_create(cam.width, cam.height, RL_LAYER_COLOR, &img);
    if (st == RL_OK)
        st = rl_renderer_render(r, scene, &cam, img, &stats);
    if (st == RL_OK)
        st = rl_image_write(img, out);
    if (st == RL_OK)
        printf("%s with %s, %dx%d in %.1f ms -> %s\n", rl_scene_name(scene), algo, cam.width, cam.height,
               stats.time_ms, out);
    else
        fprintf(stderr, "render_scene: %s (%s)\n", rl_last_error(), rl_status_name(st));
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(scene);
    return st == RL_OK ? 0 : 1;
}
