/* test_renderer_register.c: renderers from outside the library
 * (rl_renderer_register): they join the registry after the built-ins, are
 * created, configured and rendered by name like them, and are measured by
 * the properties; bad classes and taken names are refused, and concurrent
 * registration gives every name to exactly one class. The registry is
 * global to the process, so the cases run in order and use their own names. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_property.h"
#include "rl/rl_render.h"
#include "rl/rl_scene.h"
#include "render_fixtures.h"

/* A renderer that fills the image with its "colour" option, scaled by its
 * "gain", and counts what it did: enough to see the options arrive typed. */
typedef struct fill_state {
    int frames;
} fill_state;

static int fill_released;     /* releases of a state that rendered */

static rl_status fill_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                             rl_image *image, rl_render_stats *stats)
{
    (void)scene;
    (void)cam;
    fill_state *s = state;
    s->frames++;
    rl_vec3 c = rl_scale(rl_renderer_opt_color(r, "colour"), (float)rl_renderer_opt_float(r, "gain"));
    if (rl_renderer_opt_bool(r, "grey"))
        c = rl_v3s((c.x + c.y + c.z) / 3.0f);
    for (int y = 0; y < image->height; ++y)
        for (int x = 0; x < image->width; ++x)
            *rl_image_pixel(image, x, y) = rl_v4_from3(c, 1.0f);
    stats->pixels_written = (uint64_t)image->width * (uint64_t)image->height;
    stats->samples = (uint64_t)rl_renderer_opt_int(r, "spp") * stats->pixels_written;
    return RL_OK;
}

static void fill_release(void *state)
{
    const fill_state *s = state;
    if (s->frames)
        fill_released++;
}

static const char *const modes[] = { "a", "b", NULL };
static const rl_option_info fill_options[] = {
    { "colour", RL_OPT_COLOR, "1,0.5,0", "fill colour", 0, 0, NULL },
    { "gain", RL_OPT_FLOAT, "1", "multiplies the colour", 0, 4, NULL },
    { "spp", RL_OPT_INT, "1", "samples per pixel (counted only)", 1, 64, NULL },
    { "grey", RL_OPT_BOOL, "false", "average the channels", 0, 0, NULL },
    { "mode", RL_OPT_ENUM, "b", "unused", 0, 0, modes },
};

static rl_renderer_class_desc fill_desc(const char *name)
{
    return (rl_renderer_class_desc){
        .info = { name, "fills the image", "" },
        .options = fill_options,
        .num_options = sizeof fill_options / sizeof fill_options[0],
        .state_size = sizeof(fill_state),
        .render = fill_render,
        .release = fill_release,
    };
}

static rl_scene *make_scene(void) { return fx_triangle_scene(true); }

static bool listed(const char *name, size_t *index)
{
    size_t n = 0;
    const rl_renderer_info *infos = rl_renderer_list(&n);
    for (size_t i = 0; i < n; ++i)
        if (strcmp(infos[i].name, name) == 0) {
            if (index)
                *index = i;
            return true;
        }
    return false;
}

static void test_registered_class_is_listed_after_the_builtins(void **state)
{
    (void)state;
    size_t before = 0, at = 0;
    rl_renderer_list(&before);
    assert_false(listed("fill", NULL));
    rl_renderer_class_desc d = fill_desc("fill");
    assert_int_equal(rl_renderer_register(&d), RL_OK);
    size_t after = 0;
    const rl_renderer_info *infos = rl_renderer_list(&after);
    assert_int_equal(after, before + 1);
    assert_true(listed("fill", &at));
    assert_int_equal(at, before);
    assert_string_equal(infos[at].description, "fills the image");
    assert_true(listed("raster", &at));
    assert_true(at < before);
}

static void test_registered_renderer_renders_with_typed_options(void **state)
{
    (void)state;
    rl_scene *scene = make_scene();
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("fill", &r), RL_OK);
    assert_string_equal(rl_renderer_name(r), "fill");
    size_t count = 0;
    assert_non_null(rl_renderer_options(r, &count));
    assert_int_equal(count, 5);
    assert_int_equal(rl_renderer_set(r, "fill.gain", "2"), RL_OK);
    assert_int_equal(rl_renderer_set(r, "spp", "4"), RL_OK);
    assert_int_equal(rl_renderer_set(r, "colour", "0.25,0.5,0"), RL_OK);
    assert_string_equal(rl_renderer_get(r, "mode"), "b");
    assert_int_equal(rl_renderer_opt_enum(r, "mode"), 1);
    /* The table's types and ranges are checked as for a built-in. */
    assert_int_equal(rl_renderer_set(r, "gain", "5"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "spp", "x"), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_renderer_set(r, "nope", "1"), RL_ERR_INVALID_ARG);
    rl_clear_error();
    /* Unknown keys read as zero: an implementation's mistake, not a crash. */
    assert_int_equal(rl_renderer_opt_int(r, "nope"), 0);
    assert_string_equal(rl_renderer_opt_string(r, "nope"), "");

    rl_camera cam = { .eye = { 0, 0, 4 }, .target = { 0, 0, 0 }, .width = 8, .height = 6 };
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(8, 6, RL_LAYER_COLOR, &img), RL_OK);
    rl_render_stats stats;
    assert_int_equal(rl_renderer_render(r, scene, &cam, img, &stats), RL_OK);
    rl_vec4 p = *rl_image_pixel(img, 3, 2);
    assert_float_equal(p.x, 0.5f, 1e-6f);
    assert_float_equal(p.y, 1.0f, 1e-6f);
    assert_float_equal(p.z, 0.0f, 1e-6f);
    assert_int_equal(stats.pixels_written, 48);
    assert_int_equal(stats.samples, 4 * 48);
    assert_true(stats.time_ms >= 0.0);
    /* The generic checks run before the class is called. */
    rl_image *wrong = NULL;
    assert_int_equal(rl_image_create(4, 4, RL_LAYER_COLOR, &wrong), RL_OK);
    assert_int_equal(rl_renderer_render(r, scene, &cam, wrong, NULL), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(fill_released, 0);
    rl_renderer_release(r);
    assert_int_equal(fill_released, 1);
    rl_image_release(wrong);
    rl_image_release(img);
    rl_scene_release(scene);
}

static void test_registered_renderer_is_measured_by_properties(void **state)
{
    (void)state;
    rl_scene *scene = make_scene();
    rl_property *p = NULL;
    assert_int_equal(rl_property_create("ops", &p), RL_OK);
    assert_int_equal(rl_property_set(p, "renderer", "fill"), RL_OK);
    assert_int_equal(rl_property_set(p, "renderer_options", "spp=3"), RL_OK);
    assert_int_equal(rl_property_set(p, "counter", "samples"), RL_OK);
    assert_int_equal(rl_property_set(p, "width", "4"), RL_OK);
    assert_int_equal(rl_property_set(p, "height", "4"), RL_OK);
    assert_int_equal(rl_property_commit(p, scene, 1), RL_OK);
    rl_property_sample s = { 0 };
    assert_int_equal(rl_property_evaluate(p, 0, (rl_vec3){ 0, 0, 2 }, &s), RL_OK);
    assert_float_equal(s.value, 3 * 16, 0.0);   /* max over the six directions */
    rl_property_release(p);
    rl_scene_release(scene);
}

static void test_register_refuses_taken_names(void **state)
{
    (void)state;
    size_t before = 0;
    rl_renderer_list(&before);
    rl_renderer_class_desc d = fill_desc("raster");
    assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "\"raster\" exists already"));
    rl_clear_error();
    d = fill_desc("fill");
    assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
    rl_clear_error();
    size_t after = 0;
    rl_renderer_list(&after);
    assert_int_equal(after, before);
}

static void test_register_refuses_malformed_classes(void **state)
{
    (void)state;
    size_t before = 0;
    rl_renderer_list(&before);
    assert_int_equal(rl_renderer_register(NULL), RL_ERR_INVALID_ARG);
    const char *const bad_names[] = { NULL, "", "a:b", "a.b", "a b", "a=b", "a,b",
                                      "abcdefghijklmnopqrstuvwxyz012345" /* 32 */ };
    for (size_t i = 0; i < sizeof bad_names / sizeof bad_names[0]; ++i) {
        rl_renderer_class_desc d = fill_desc(bad_names[i]);
        assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
        rl_clear_error();
    }
    rl_renderer_class_desc d = fill_desc("no_render");
    d.render = NULL;
    assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
    /* A default outside its own range, of the wrong type, or without a key. */
    const rl_option_info bad_range[] = { { "n", RL_OPT_INT, "9", "", 0, 4, NULL } };
    const rl_option_info bad_type[] = { { "b", RL_OPT_BOOL, "maybe", "", 0, 0, NULL } };
    const rl_option_info no_key[] = { { NULL, RL_OPT_INT, "1", "", 0, 4, NULL } };
    const rl_option_info *tables[] = { bad_range, bad_type, no_key };
    for (size_t i = 0; i < 3; ++i) {
        d = fill_desc("bad_options");
        d.options = tables[i];
        d.num_options = 1;
        assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
        rl_clear_error();
    }
    d = fill_desc("no_table");
    d.options = NULL;
    assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
    rl_clear_error();
    size_t after = 0;
    rl_renderer_list(&after);
    assert_int_equal(after, before);
}

static void test_register_copies_the_strings(void **state)
{
    (void)state;
    char name[32] = "copied", description[32] = "kept";
    rl_renderer_class_desc d = fill_desc(name);
    d.info.description = description;
    d.info.reference = NULL;
    assert_int_equal(rl_renderer_register(&d), RL_OK);
    strcpy(name, "changed");
    strcpy(description, "gone");
    size_t at = 0;
    assert_true(listed("copied", &at));
    const rl_renderer_info *infos = rl_renderer_list(NULL);
    assert_string_equal(infos[at].description, "kept");
    assert_string_equal(infos[at].reference, "");
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("copied", &r), RL_OK);
    rl_renderer_release(r);
}

/* Threads racing for the same names: each name goes to exactly one. */
static void test_concurrent_registration_gives_each_name_once(void **state)
{
    (void)state;
    enum { THREADS = 8, NAMES = 4 };
    static char names[NAMES][16];
    int won[NAMES] = { 0 };
    for (int i = 0; i < NAMES; ++i)
        snprintf(names[i], sizeof names[i], "race%d", i);
#pragma omp parallel for num_threads(THREADS)
    for (int t = 0; t < THREADS * NAMES; ++t) {
        rl_renderer_class_desc d = fill_desc(names[t % NAMES]);
        if (rl_renderer_register(&d) == RL_OK) {
#pragma omp atomic
            won[t % NAMES]++;
        }
        rl_clear_error();
    }
    for (int i = 0; i < NAMES; ++i) {
        assert_int_equal(won[i], 1);
        assert_true(listed(names[i], NULL));
    }
}

/* Last: fills the registry. */
static void test_progressive_class_declares_its_default_budget(void **state)
{
    (void)state;
    size_t at = 0;
    assert_true(listed("pt", &at));
    const rl_renderer_info *infos = rl_renderer_list(NULL);
    assert_true(infos[at].progressive && infos[at].default_time_s > 0.0);
    assert_true(listed("raster", &at));
    assert_false(infos[at].progressive);
    rl_renderer_class_desc d = fill_desc("fill_progressive");
    d.info.progressive = true;
    d.info.default_time_s = -1.0;
    assert_int_equal(rl_renderer_register(&d), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_false(listed("fill_progressive", NULL));
    d.info.default_time_s = 2.5;
    assert_int_equal(rl_renderer_register(&d), RL_OK);
    assert_true(listed("fill_progressive", &at));
    infos = rl_renderer_list(NULL);
    assert_true(infos[at].progressive);
    assert_true(infos[at].default_time_s == 2.5);
}

static void test_register_stops_at_the_limit(void **state)
{
    (void)state;
    static char names[RL_RENDERER_MAX_REGISTERED + 1][16];
    rl_status st = RL_OK;
    int added = 0;
    for (int i = 0; i <= RL_RENDERER_MAX_REGISTERED && st == RL_OK; ++i) {
        snprintf(names[i], sizeof names[i], "many%d", i);
        rl_renderer_class_desc d = fill_desc(names[i]);
        st = rl_renderer_register(&d);
        added += st == RL_OK;
    }
    assert_int_equal(st, RL_ERR_LIMIT);
    rl_clear_error();
    assert_true(added < RL_RENDERER_MAX_REGISTERED);   /* the earlier cases took some */
    rl_renderer *r = NULL;
    assert_int_equal(rl_renderer_create("many0", &r), RL_OK);
    rl_renderer_release(r);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_registered_class_is_listed_after_the_builtins),
        cmocka_unit_test(test_registered_renderer_renders_with_typed_options),
        cmocka_unit_test(test_registered_renderer_is_measured_by_properties),
        cmocka_unit_test(test_register_refuses_taken_names),
        cmocka_unit_test(test_register_refuses_malformed_classes),
        cmocka_unit_test(test_register_copies_the_strings),
        cmocka_unit_test(test_concurrent_registration_gives_each_name_once),
        cmocka_unit_test(test_progressive_class_declares_its_default_budget),
        cmocka_unit_test(test_register_stops_at_the_limit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
