/* evaluate_property.c: a position-dependent scene property (Jähn 2015,
 * Ch. 4), approximated over a region by adaptive sampling (Ch. 5) and
 * summarised by weighted statistics.
 *
 * The property is pixel visibility: the number of objects a viewer sees
 * around itself (the six faces of a cube) at a position (Def. 4/5). Sampled
 * over the horizontal slice at eye height of the `table` scene, every
 * leaf region of the approximation then weighs its value by its area, so
 * that the mean is a mean over the slice, not over where the sampler
 * happened to look.
 *
 *     evaluate_property [OUT.json]      also saves the approximation there */
#include <rl/rl.h>

#include <stdio.h>
#include <stdlib.h>

int main(int argc, char **argv)
{
    const char *out = argc > 1 ? argv[1] : NULL;
    rl_scene *scene = NULL;
    rl_property *vis = NULL;
    rl_approx *approx = NULL;
    double *values = NULL, *areas = NULL;
    rl_stats stats;

    rl_status st = rl_scene_load("table", NULL, &scene);
    if (st == RL_OK)
        st = rl_property_create("visibility", &vis);
    if (st == RL_OK)
        st = rl_property_set(vis, "resolution", "64");      /* cube faces of 64² pixels */
    if (st == RL_OK)
        st = rl_property_commit(vis, scene, 0);            /* all threads as workers */
    rl_aabb b = scene ? rl_scene_get_data(scene)->bounds : (rl_aabb){ { 0, 0, 0 }, { 0, 0, 0 } };
    rl_sampling_desc desc = {
        .region = b,
        .dims = 2,
        .height = b.min.y + 0.6f * (b.max.y - b.min.y),
        .max_samples = 48,
        .seed = 7,
    };
    if (st == RL_OK)
        st = rl_sample_property(vis, &desc, &approx);

    uint32_t n = st == RL_OK ? rl_approx_region_count(approx) : 0;
    if (st == RL_OK && (!(values = malloc(n * sizeof *values)) || !(areas = malloc(n * sizeof *areas))))
        st = RL_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; st == RL_OK && i < n; ++i) {
        rl_approx_region r;
        st = rl_approx_get_region(approx, i, &r);
        values[i] = r.value;
        areas[i] = (double)(r.box.max.x - r.box.min.x) * (double)(r.box.max.z - r.box.min.z);
    }
    if (st == RL_OK)
        st = rl_stats_compute(values, areas, n, &stats);
    if (st == RL_OK) {
        printf("%s over %.1f m² of %s at y = %.2f m: %u samples, %u regions, %.2f s\n",
               rl_approx_property(approx), rl_approx_measure(approx), rl_scene_name(scene), desc.height,
               rl_approx_sample_count(approx), n, rl_approx_seconds(approx));
        printf("visible %s: area-weighted mean %.1f, median %.1f, min %.0f, max %.0f\n",
               rl_approx_unit(approx), stats.mean, stats.q[2], stats.min, stats.max);
        double centre;
        rl_vec3 c = rl_scale(rl_add(b.min, b.max), 0.5f);
        if (rl_approx_query(approx, (rl_vec3){ c.x, desc.height, c.z }, &centre, NULL) == RL_OK)
            printf("at the centre: %.1f\n", centre);
    }
    if (st == RL_OK && out)
        st = rl_approx_save_json(approx, out);
    if (st != RL_OK)
        fprintf(stderr, "evaluate_property: %s (%s)\n", rl_last_error(), rl_status_name(st));
    free(values);
    free(areas);
    rl_approx_release(approx);
    rl_property_release(vis);
    rl_scene_release(scene);
    return st == RL_OK ? 0 : 1;
}
