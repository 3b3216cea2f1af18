/* test_suggest.c: "did you mean" (rl_suggest, rl_options.h): edit
 * distances, the closeness rule, and the suggestion in the library's
 * messages for unknown renderers, properties, scenes and option keys. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "rl/rl.h"

static void test_edit_distance_counts_inserts_deletes_and_replacements(void **state)
{
    (void)state;
    assert_int_equal(rl_edit_distance("raster", "raster", 2), 0);
    assert_int_equal(rl_edit_distance("rastr", "raster", 2), 1);       /* insert */
    assert_int_equal(rl_edit_distance("rasterr", "raster", 2), 1);     /* delete */
    assert_int_equal(rl_edit_distance("wbitted", "whitted", 2), 1);    /* replace */
    assert_int_equal(rl_edit_distance("Cornell", "cornell", 2), 0);    /* case ignored */
    assert_int_equal(rl_edit_distance("", "abc", 5), 3);
    /* Beyond the limit: limit + 1, however far. */
    assert_int_equal(rl_edit_distance("visibility", "raster", 2), 3);
    assert_int_equal(rl_edit_distance(NULL, "x", 2), 3);
}

static void test_suggest_picks_the_closest_likely_typo(void **state)
{
    (void)state;
    const char *names[] = { "raster", "whitted", "vt", "pt", "chcpp", "svs" };
    rl_suggestion s = { 0 };
    for (size_t i = 0; i < 6; i++)
        rl_suggest(&s, "whited", names[i]);
    assert_non_null(s.name);
    assert_string_equal(s.name, "whitted");
    /* Short names allow one edit: "xt" is a typo of "vt" (the first of the
     * equally close), "xyz" of nothing. */
    rl_suggestion t = { 0 };
    for (size_t i = 0; i < 6; i++)
        rl_suggest(&t, "xt", names[i]);
    assert_string_equal(t.name, "vt");
    rl_suggestion u = { 0 };
    for (size_t i = 0; i < 6; i++)
        rl_suggest(&u, "xyz", names[i]);
    assert_null(u.name);
}

static void test_library_messages_suggest_the_known_name(void **state)
{
    (void)state;
    rl_renderer *r = NULL;
    rl_clear_error();
    assert_int_equal(rl_renderer_create("rastr", &r), RL_ERR_NOT_FOUND);
    assert_non_null(strstr(rl_last_error(), "did you mean \"raster\"?"));
    rl_property *p = NULL;
    rl_clear_error();
    assert_int_equal(rl_property_create("visibilty", &p), RL_ERR_NOT_FOUND);
    assert_non_null(strstr(rl_last_error(), "did you mean \"visibility\"?"));
    rl_scene *sc = NULL;
    rl_clear_error();
    assert_int_equal(rl_scene_create_builtin("cornel", NULL, &sc), RL_ERR_NOT_FOUND);
    assert_non_null(strstr(rl_last_error(), "did you mean \"cornell\"?"));
    /* Option keys, with or without the renderer's prefix. */
    assert_int_equal(rl_renderer_create("raster", &r), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_renderer_set(r, "raster.shadng", "flat"), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "did you mean \"shading\"?"));
    rl_clear_error();
    assert_int_equal(rl_renderer_set(r, "zzzzzz", "1"), RL_ERR_INVALID_ARG);
    assert_null(strstr(rl_last_error(), "did you mean"));
    rl_renderer_release(r);
    rl_clear_error();
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_edit_distance_counts_inserts_deletes_and_replacements),
        cmocka_unit_test(test_suggest_picks_the_closest_likely_typo),
        cmocka_unit_test(test_library_messages_suggest_the_known_name),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
