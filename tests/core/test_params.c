/* test_params.c: "key=value" lists and the option store that checks them
 * against a table: typed values with ranges, unknown keys listed, the
 * owner's extra check, strict number parsing. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

#include "core/options.h"
#include "core/params.h"

static void test_parse_splits_on_commas_and_whitespace(void **state)
{
    (void)state;
    rl_params p;
    assert_int_equal(rl_params_parse("a=1, b=two\tc= d=x=y", &p), RL_OK);
    assert_int_equal(p.count, 4);
    assert_string_equal(rl_params_get(&p, "a"), "1");
    assert_string_equal(rl_params_get(&p, "b"), "two");
    assert_string_equal(rl_params_get(&p, "c"), "");
    assert_string_equal(rl_params_get(&p, "d"), "x=y");
    assert_null(rl_params_get(&p, "e"));
    rl_params_free(&p);
    assert_int_equal(p.count, 0);
    assert_int_equal(rl_params_parse(NULL, &p), RL_OK);
    assert_int_equal(p.count, 0);
    assert_int_equal(rl_params_parse("  ,, ", &p), RL_OK);
    assert_int_equal(p.count, 0);
    rl_params_free(&p);
}

static void test_repeated_key_keeps_the_last_value(void **state)
{
    (void)state;
    rl_params p;
    assert_int_equal(rl_params_parse("n=1,n=2", &p), RL_OK);
    assert_int_equal(p.count, 1);
    assert_string_equal(rl_params_get(&p, "n"), "2");
    assert_int_equal(rl_params_set(&p, "n", "3"), RL_OK);
    assert_int_equal(rl_params_set(&p, "m", "4"), RL_OK);
    assert_int_equal(p.count, 2);
    assert_string_equal(rl_params_get(&p, "n"), "3");
    assert_int_equal(rl_params_set(&p, "", "4"), RL_ERR_INVALID_ARG);
    rl_params_free(&p);
}

static void test_malformed_items_are_rejected_and_output_untouched(void **state)
{
    (void)state;
    rl_params p = { NULL, 77 };
    rl_clear_error();
    assert_int_equal(rl_params_parse("a=1,oops", &p), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "oops"));
    assert_int_equal(p.count, 77);
    assert_int_equal(rl_params_parse("=5", &p), RL_ERR_INVALID_ARG);
    assert_int_equal(p.count, 77);
    rl_clear_error();
}

/* The option store (options.h) that every key=value owner shares. */
static const char *const kinds[] = { "bvh", "grid", "linespace", NULL };
static const rl_option_info table[] = {
    { "n", RL_OPT_INT, "5", "a count", 1, 100, NULL },
    { "x", RL_OPT_FLOAT, "1", "a fraction", 0, 1, NULL },
    { "b", RL_OPT_BOOL, "false", "a flag", 0, 0, NULL },
    { "e", RL_OPT_ENUM, "bvh", "a kind", 0, 0, kinds },
    { "s", RL_OPT_STRING, "", "a path", 0, 0, NULL },
    { "c", RL_OPT_COLOR, "0.5", "a colour", 0, 0, NULL },
    { "seed", RL_OPT_INT, "1", "a seed", 0, 4294967295.0, NULL },
};
#define TABLE_ROWS (sizeof table / sizeof table[0])

static void test_store_keeps_defaults_and_reads_typed_values(void **state)
{
    (void)state;
    rl_option_store s;
    assert_int_equal(rl_option_store_init(&s, table, TABLE_ROWS, "test"), RL_OK);
    assert_int_equal(rl_option_store_int(&s, "n"), 5);
    assert_false(rl_option_store_given(&s, "n"));
    assert_true(rl_option_store_color(&s, "c").y == 0.5f);
    assert_int_equal(rl_option_store_set(&s, "n", "12", "test", NULL), RL_OK);
    assert_int_equal(rl_option_store_set(&s, "test.x", "0.25", "test", NULL), RL_OK);   /* owner prefix */
    assert_int_equal(rl_option_store_set(&s, "b", "yes", "test", NULL), RL_OK);
    assert_int_equal(rl_option_store_set(&s, "e", "grid", "test", NULL), RL_OK);
    assert_int_equal(rl_option_store_set(&s, "s", "a b", "test", NULL), RL_OK);
    assert_int_equal(rl_option_store_int(&s, "n"), 12);
    assert_true(rl_option_store_given(&s, "n") && rl_option_store_given(&s, "x"));
    assert_true(rl_option_store_float(&s, "x") == 0.25);
    assert_true(rl_option_store_bool(&s, "b"));
    assert_int_equal(rl_option_store_enum(&s, "e"), 1);
    assert_string_equal(rl_option_store_get(&s, "e"), "grid");    /* text as set */
    assert_string_equal(rl_option_store_string(&s, "s"), "a b");
    assert_null(rl_option_store_get(&s, "absent"));
    assert_int_equal(rl_option_store_int(&s, "absent"), 0);
    rl_option_store_free(&s);
    rl_option_store_free(&s);   /* zeroed: a second free is a no-op */
}

static void test_store_refuses_bad_values_naming_context_key_value_and_range(void **state)
{
    (void)state;
    rl_option_store s;
    assert_int_equal(rl_option_store_init(&s, table, TABLE_ROWS, NULL), RL_OK);
    const char *bad[][2] = { { "n", "0" },     { "n", "101" },  { "n", "0x10" }, { "n", "-3" },
                             { "x", "1e400" }, { "x", "nan" },  { "b", "maybe" }, { "e", "octree" },
                             { "c", "-1" },    { "seed", "4294967296" } };
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; ++i) {
        rl_clear_error();
        assert_int_equal(rl_option_store_set(&s, bad[i][0], bad[i][1], "pathtrace", NULL), RL_ERR_INVALID_ARG);
        assert_non_null(strstr(rl_last_error(), "pathtrace"));
        assert_non_null(strstr(rl_last_error(), bad[i][1]));
        assert_false(rl_option_store_given(&s, bad[i][0]));     /* the old value stays */
    }
    assert_int_equal(rl_option_store_int(&s, "n"), 5);
    rl_clear_error();
    rl_option_store_set(&s, "n", "101", "pathtrace", NULL);
    assert_non_null(strstr(rl_last_error(), "[1, 100]"));          /* integers print as integers */
    rl_clear_error();
    rl_option_store_set(&s, "seed", "-1", "pathtrace", NULL);
    assert_non_null(strstr(rl_last_error(), "[0, 4294967295]"));
    rl_clear_error();
    rl_option_store_set(&s, "e", "octree", "accel", NULL);
    assert_non_null(strstr(rl_last_error(), "bvh, grid, linespace"));
    rl_option_store_free(&s);
    rl_clear_error();
}

static rl_status only_even(const char *key, const char *value)
{
    long long v = 0;
    if (strcmp(key, "n") == 0 && rl_parse_int(value, &v) && v % 2)
        return RL_ERR_INVALID_ARG;
    return RL_OK;
}

static void test_store_lists_the_keys_of_an_unknown_one_and_asks_the_owner(void **state)
{
    (void)state;
    rl_option_store s;
    assert_int_equal(rl_option_store_init(&s, table, TABLE_ROWS, "sphere_field"), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_option_store_set(&s, "sampels", "4", "sphere_field", NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "\"sampels\""));
    assert_non_null(strstr(rl_last_error(), "n, x, b, e, s, c, seed"));
    assert_int_equal(rl_option_store_set(&s, "other.n", "4", "sphere_field", NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_option_store_set(&s, "n", "3", "sphere_field", only_even), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_option_store_set(&s, "n", "4", "sphere_field", only_even), RL_OK);
    assert_int_equal(rl_option_store_int(&s, "n"), 4);
    rl_option_store_free(&s);

    rl_option_store none;
    assert_int_equal(rl_option_store_init(&none, NULL, 0, NULL), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_option_store_set(&none, "triangles", "10", "cornell", NULL), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "takes none"));
    rl_option_store_free(&none);
    rl_clear_error();
}

static void test_strict_number_conversions(void **state)
{
    (void)state;
    long long i = 0;
    double d = 0;
    assert_true(rl_parse_int("-42", &i) && i == -42);
    assert_false(rl_parse_int("42abc", &i));
    assert_false(rl_parse_int("", &i));
    assert_false(rl_parse_int(" 1", &i));
    assert_false(rl_parse_int("99999999999999999999", &i));
    assert_true(rl_parse_float("1.5e3", &d) && d == 1500.0);
    assert_false(rl_parse_float("nan", &d));
    assert_false(rl_parse_float("inf", &d));
    assert_false(rl_parse_float("1.0x", &d));
    assert_true(d == 1500.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_parse_splits_on_commas_and_whitespace),
        cmocka_unit_test(test_repeated_key_keeps_the_last_value),
        cmocka_unit_test(test_malformed_items_are_rejected_and_output_untouched),
        cmocka_unit_test(test_store_keeps_defaults_and_reads_typed_values),
        cmocka_unit_test(test_store_refuses_bad_values_naming_context_key_value_and_range),
        cmocka_unit_test(test_store_lists_the_keys_of_an_unknown_one_and_asks_the_owner),
        cmocka_unit_test(test_strict_number_conversions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
