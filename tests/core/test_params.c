/* test_params.c: "key=value" parsing, typed lookups with ranges and the
 * unused-key check that turns typos into errors. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <string.h>

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

static void test_typed_lookups_validate_and_keep_defaults(void **state)
{
    (void)state;
    rl_params p;
    assert_int_equal(rl_params_parse("n=12 x=0.25 b=yes e=grid big=1e400 neg=-3 hex=0x10", &p), RL_OK);
    long long n = 5, missing = 9;
    double x = 1, big = 0;
    bool b = false;
    int e = -1;
    assert_int_equal(rl_params_int(&p, "test", "n", 1, 100, &n), RL_OK);
    assert_int_equal(n, 12);
    assert_int_equal(rl_params_int(&p, "test", "absent", 1, 100, &missing), RL_OK);
    assert_int_equal(missing, 9);
    assert_int_equal(rl_params_float(&p, "test", "x", 0, 1, &x), RL_OK);
    assert_true(x == 0.25);
    assert_int_equal(rl_params_bool(&p, "test", "b", &b), RL_OK);
    assert_true(b);
    static const char *const kinds[] = { "bvh", "grid", "linespace", NULL };
    assert_int_equal(rl_params_enum(&p, "test", "e", kinds, &e), RL_OK);
    assert_int_equal(e, 1);
    rl_clear_error();
    assert_int_equal(rl_params_float(&p, "test", "big", 0, 1e300, &big), RL_ERR_INVALID_ARG);
    assert_true(big == 0);
    long long neg = 0;
    assert_int_equal(rl_params_int(&p, "test", "neg", 0, 10, &neg), RL_ERR_INVALID_ARG);
    assert_int_equal(neg, 0);
    long long hex = 0;
    assert_int_equal(rl_params_int(&p, "test", "hex", 0, 100, &hex), RL_ERR_INVALID_ARG);
    rl_params_free(&p);
    rl_clear_error();
}

static void test_range_error_names_context_key_value_and_range(void **state)
{
    (void)state;
    rl_params p;
    assert_int_equal(rl_params_parse("spp=5000", &p), RL_OK);
    long long spp = 1;
    rl_clear_error();
    assert_int_equal(rl_params_int(&p, "pathtrace", "spp", 1, 4096, &spp), RL_ERR_INVALID_ARG);
    const char *msg = rl_last_error();
    assert_non_null(strstr(msg, "pathtrace"));
    assert_non_null(strstr(msg, "spp=5000"));
    assert_non_null(strstr(msg, "4096"));
    assert_int_equal(spp, 1);
    rl_params_free(&p);

    assert_int_equal(rl_params_parse("kind=octree flag=maybe", &p), RL_OK);
    static const char *const kinds[] = { "bvh", "grid", NULL };
    int k = 0;
    bool flag = true;
    rl_clear_error();
    assert_int_equal(rl_params_enum(&p, "accel", "kind", kinds, &k), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "bvh, grid"));
    assert_int_equal(rl_params_bool(&p, "accel", "flag", &flag), RL_ERR_INVALID_ARG);
    assert_true(flag);
    rl_params_free(&p);
    rl_clear_error();
}

static void test_unused_key_is_reported_with_accepted_list(void **state)
{
    (void)state;
    rl_params p;
    assert_int_equal(rl_params_parse("seed=3 sampels=4", &p), RL_OK);
    long long seed = 0;
    assert_int_equal(rl_params_int(&p, "sphere_field", "seed", 0, 1000, &seed), RL_OK);
    rl_clear_error();
    assert_int_equal(rl_params_check_unused(&p, "sphere_field", "seed, samples"), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "\"sampels\""));
    assert_non_null(strstr(rl_last_error(), "seed, samples"));
    assert_non_null(rl_params_get(&p, "sampels"));
    assert_int_equal(rl_params_check_unused(&p, "sphere_field", "seed, samples"), RL_OK);
    rl_params_free(&p);
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
        cmocka_unit_test(test_typed_lookups_validate_and_keep_defaults),
        cmocka_unit_test(test_range_error_names_context_key_value_and_range),
        cmocka_unit_test(test_unused_key_is_reported_with_accepted_list),
        cmocka_unit_test(test_strict_number_conversions),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
