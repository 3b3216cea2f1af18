/* custom_renderer.c: a renderer written outside the library, registered
 * with rl_renderer_register() and measured against the built-ins the way
 * `rl compare` measures (Jähn 2015, Ch. 4-5): positions chosen by adaptive
 * sampling of pixel visibility over a slice of the scene, then, at exactly
 * those positions, rendering time (Def. 6) and image quality against
 * whitted (Def. 7) of every renderer, so that the comparison is paired.
 *
 * The renderer, "eyelight", casts one primary ray per pixel through a BVH
 * (rl_accel) and shades with a light at the eye: diffuse colour times
 * ambient + (1 - ambient) |cos θ|. It has the two kinds of options an
 * algorithm usually has, an enum and a number, and keeps its
 * per-scene work (the BVH) in its state between frames.
 *
 *     custom_renderer [OUTDIR]      writes eyelight.png and whitted.png there
 *
 * The same file, compiled with -DRL_EXAMPLE_PLUGIN as a shared object, is a
 * plugin of the rl tool instead (rl_plugin_init below, no main):
 *     cc -shared -fPIC -DRL_EXAMPLE_PLUGIN custom_renderer.c $(pkg-config --cflags renderlab) -o eyelight.so
 *     rl --plugin ./eyelight.so compare cornell --algos eyelight,raster,whitted */
#include <rl/rl.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

/* ---- the renderer ---------------------------------------------------- */

static const char *const accel_choices[] = { "bvh", "grid", NULL };
static const rl_option_info eyelight_options[] = {
    { "accel", RL_OPT_ENUM, "bvh", "ray queries: bvh or grid", 0, 0, accel_choices },
    { "ambient", RL_OPT_FLOAT, "0.15", "light that does not depend on the angle", 0, 1, NULL },
};

typedef struct eyelight {
    rl_accel *accel;          /* built for scene_uid with kind */
    uint64_t scene_uid;
    rl_accel_kind kind;
} eyelight;

static void eyelight_release(void *state)
{
    eyelight *e = state;
    rl_accel_release(e->accel);
}

/* Builds the accelerator once per scene and kind: a renderer keeps its
 * per-scene preprocessing, so that only the first frame pays for it. */
static rl_status eyelight_prepare(eyelight *e, const rl_scene *scene, rl_accel_kind kind)
{
    if (e->accel && e->scene_uid == rl_scene_uid(scene) && e->kind == kind)
        return RL_OK;
    rl_accel_release(e->accel);
    e->accel = NULL;
    rl_accel *a = NULL;
    rl_status st = rl_accel_create(scene, &(rl_accel_desc){ .kind = kind }, &a);
    if (st == RL_OK)
        st = rl_accel_commit(a);
    if (st != RL_OK) {
        rl_accel_release(a);
        return st;
    }
    e->accel = a;
    e->scene_uid = rl_scene_uid(scene);
    e->kind = kind;
    return RL_OK;
}

static rl_status eyelight_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                                 rl_image *image, rl_render_stats *stats)
{
    eyelight *e = state;
    rl_accel_kind kind = rl_renderer_opt_enum(r, "accel") == 1 ? RL_ACCEL_GRID : RL_ACCEL_BVH;
    float ambient = (float)rl_renderer_opt_float(r, "ambient");
    rl_status st = eyelight_prepare(e, scene, kind);
    if (st != RL_OK)
        return st;
    const rl_scene_data *data = rl_scene_get_data(scene);
    rl_camera_frame frame = rl_camera_frame_make(cam);
    for (int y = 0; y < image->height; ++y) {
        for (int x = 0; x < image->width; ++x) {
            rl_ray ray = rl_camera_frame_ray(&frame, (float)x + 0.5f, (float)y + 0.5f);
            rl_hit hit;
            rl_vec4 colour = { 0, 0, 0, 1 };
            if (rl_accel_intersect(e->accel, &ray, &hit)) {
                const uint32_t *t = &data->indices[3 * (size_t)hit.triangle];
                rl_vec3 p0 = data->positions[t[0]], p1 = data->positions[t[1]], p2 = data->positions[t[2]];
                rl_vec3 n = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
                float cos_theta = fabsf(rl_dot(n, ray.d));
                rl_vec3 kd = data->materials[data->triangle_material[hit.triangle]].diffuse;
                rl_vec3 c = rl_scale(kd, ambient + (1.0f - ambient) * cos_theta);
                colour = (rl_vec4){ c.x, c.y, c.z, 1 };
            }
            *rl_image_pixel(image, x, y) = colour;
        }
        if (!rl_renderer_progress(r, (double)(y + 1) / image->height))
            return RL_ERR_CANCELLED;
    }
    stats->rays[RL_RAY_PRIMARY] = (uint64_t)image->width * (uint64_t)image->height;
    stats->pixels_written = stats->rays[RL_RAY_PRIMARY];
    return RL_OK;
}

static const rl_renderer_class_desc eyelight_class = {
    .info = { "eyelight", "ray casting with a light at the eye (examples/custom_renderer.c)", "" },
    .options = eyelight_options,
    .num_options = sizeof eyelight_options / sizeof eyelight_options[0],
    .state_size = sizeof(eyelight),
    .render = eyelight_render,
    .release = eyelight_release,
};

#ifdef RL_EXAMPLE_PLUGIN
/* What `rl --plugin` calls: register, and rl does the measuring. */
rl_status rl_plugin_init(void);
rl_status rl_plugin_init(void) { return rl_renderer_register(&eyelight_class); }
#else
/* ---- measuring it ---------------------------------------------------- */

enum { MAX_SAMPLES = 12, SIZE = 64 };

static rl_status check(rl_status st, const char *what)
{
    if (st != RL_OK)
        fprintf(stderr, "custom_renderer: %s: %s (%s)\n", what, rl_last_error(), rl_status_name(st));
    return st;
}

static rl_status render_one(const char *algo, const rl_scene *scene, const rl_camera *cam, rl_image **out)
{
    rl_renderer *r = NULL;
    rl_status st = rl_renderer_create(algo, &r);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, out);
    if (st == RL_OK)
        st = rl_renderer_render(r, scene, cam, *out, NULL);
    rl_renderer_release(r);
    return st;
}

/* A property of renderer `algo` ("time" or "quality"), set up as rl compare
 * does: small cube faces, measured at given positions. */
static rl_status make_property(const char *kind, const char *algo, const rl_scene *scene, rl_property **out)
{
    char size[16];
    snprintf(size, sizeof size, "%d", SIZE);
    rl_property *p = NULL;
    rl_status st = rl_property_create(kind, &p);
    if (st == RL_OK)
        st = rl_property_set(p, "renderer", algo);
    if (st == RL_OK)
        st = rl_property_set(p, "width", size);
    if (st == RL_OK)
        st = rl_property_set(p, "height", size);
    if (st == RL_OK && strcmp(kind, "time") == 0)
        st = rl_property_set(p, "repeats", "1");
    if (st == RL_OK && strcmp(kind, "quality") == 0) {
        st = rl_property_set(p, "reference", "whitted");
        if (st == RL_OK)
            st = rl_property_set(p, "metric", "ssim");
    }
    if (st == RL_OK)
        st = rl_property_commit(p, scene, 0);
    if (st != RL_OK) {
        rl_property_release(p);
        return st;
    }
    *out = p;
    return RL_OK;
}

/* Adaptive sampling of pixel visibility over the slice at the camera's
 * height inside the scene (Sec. 5.4): where the visible set changes, more
 * samples. Returns the positions it chose. */
static rl_status choose_positions(const rl_scene *scene, float height, rl_vec3 *pos, size_t *count)
{
    rl_property *vis = NULL;
    rl_approx *approx = NULL;
    rl_status st = rl_property_create("visibility", &vis);
    if (st == RL_OK)
        st = rl_property_set(vis, "resolution", "32");
    if (st == RL_OK)
        st = rl_property_commit(vis, scene, 0);
    rl_aabb b = rl_scene_get_data(scene)->bounds;
    rl_vec3 inset = rl_scale(rl_sub(b.max, b.min), 0.1f);
    rl_sampling_desc desc = {
        .region = { rl_add(b.min, inset), rl_sub(b.max, inset) },
        .dims = 2,
        .height = height,
        .max_samples = MAX_SAMPLES,
        .seed = 1,
    };
    if (st == RL_OK)
        st = rl_sample_property(vis, &desc, &approx);
    size_t n = st == RL_OK ? rl_approx_sample_count(approx) : 0;
    for (size_t i = 0; i < n && i < MAX_SAMPLES; ++i)
        rl_approx_sample(approx, (uint32_t)i, &pos[i], NULL);
    *count = n < MAX_SAMPLES ? n : MAX_SAMPLES;
    rl_approx_release(approx);
    rl_property_release(vis);
    return st;
}

int main(int argc, char **argv)
{
    const char *outdir = argc > 1 ? argv[1] : ".";

    if (check(rl_renderer_register(&eyelight_class), "register eyelight") != RL_OK)
        return 1;
    /* A second class by a taken name is refused, built-in or not. */
    rl_status clash = rl_renderer_register(&(rl_renderer_class_desc){
        .info = { .name = "whitted" }, .render = eyelight_render });
    printf("registering \"whitted\" again: %s: %s\n", rl_status_name(clash), rl_last_error());
    rl_clear_error();
    if (clash != RL_ERR_INVALID_ARG)
        return 1;

    size_t num_algos = 0;
    const rl_renderer_info *algos = rl_renderer_list(&num_algos);
    printf("renderers:");
    for (size_t i = 0; i < num_algos; ++i)
        printf(" %s", algos[i].name);
    printf("\n");

    rl_scene *scene = NULL;
    rl_image *ours = NULL, *ref = NULL;
    rl_camera cam;
    rl_status st = check(rl_scene_load("cornell", NULL, &scene), "load");
    if (st == RL_OK)
        st = check(rl_scene_get_camera(scene, NULL, &cam), "camera");
    cam.width = 160;
    cam.height = 120;

    /* One view, side by side with the exact ray tracer. */
    rl_image_metrics m;
    if (st == RL_OK)
        st = check(render_one("eyelight", scene, &cam, &ours), "render eyelight");
    if (st == RL_OK)
        st = check(render_one("whitted", scene, &cam, &ref), "render whitted");
    if (st == RL_OK)
        st = check(rl_image_compare(ours, ref, NULL, &m), "compare");
    if (st == RL_OK) {
        char path[1024];
        snprintf(path, sizeof path, "%s/eyelight.png", outdir);
        st = check(rl_image_write(ours, path), "write");
        snprintf(path, sizeof path, "%s/whitted.png", outdir);
        if (st == RL_OK)
            st = check(rl_image_write(ref, path), "write");
        printf("camera view: eyelight vs whitted: SSIM %.3f, PSNR %.1f dB\n", m.ssim, m.psnr);
    }

    /* Over a region: the same positions for every renderer. */
    rl_vec3 pos[MAX_SAMPLES];
    size_t n = 0;
    if (st == RL_OK)
        st = check(choose_positions(scene, cam.eye.y, pos, &n), "sample visibility");
    if (st == RL_OK)
        printf("%zu positions by adaptive sampling of visibility\n%-10s %10s %24s\n", n, "renderer",
               "median ms", "median SSIM vs whitted");
    const char *const compared[] = { "eyelight", "raster" };
    for (size_t a = 0; st == RL_OK && a < 2; ++a) {
        double values[2][MAX_SAMPLES];
        rl_stats stats[2];
        const char *const kinds[2] = { "time", "quality" };
        for (int k = 0; st == RL_OK && k < 2; ++k) {
            rl_property *p = NULL;
            st = check(make_property(kinds[k], compared[a], scene, &p), kinds[k]);
            if (st == RL_OK)
                st = check(rl_property_measure(p, pos, n, values[k], NULL, NULL), "measure");
            if (st == RL_OK)
                st = check(rl_stats_compute(values[k], NULL, n, &stats[k]), "statistics");
            rl_property_release(p);
        }
        if (st == RL_OK)
            printf("%-10s %10.3f %24.3f\n", compared[a], stats[0].q[2], stats[1].q[2]);
    }

    rl_image_release(ours);
    rl_image_release(ref);
    rl_scene_release(scene);
    return st == RL_OK ? 0 : 1;
}
#endif
