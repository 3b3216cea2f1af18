/* test_json.c: JSON parsing with positions: exact line:col of nested items,
 * syntax errors explained at the right place, duplicate and unknown keys,
 * typed reads and writing result files. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/json.h"
#include "rl/rl_rng.h"

static rl_json_doc *parse_ok(const char *text)
{
    rl_json_doc *doc = NULL;
    rl_clear_error();
    rl_status st = rl_json_parse("doc.json", text, strlen(text), &doc);
    if (st != RL_OK)
        fail_msg("parse failed: %s", rl_last_error());
    return doc;
}

/* Parses text expecting failure with `code` and a message containing `want`. */
static void expect_error(const char *text, rl_status code, const char *want)
{
    rl_json_doc *doc = NULL;
    rl_clear_error();
    rl_status st = rl_json_parse("scene.json", text, strlen(text), &doc);
    if (st != code || !strstr(rl_last_error(), want))
        fail_msg("input %s\n  got %s \"%s\"\n  want %s containing \"%s\"", text, rl_status_name(st),
                 rl_last_error(), rl_status_name(code), want);
    assert_null(doc);
    rl_clear_error();
}

static void assert_pos(const rl_json_doc *doc, const cJSON *item, int line, int col)
{
    int l, c;
    assert_non_null(item);
    rl_json_pos(doc, item, &l, &c);
    if (l != line || c != col)
        fail_msg("position %d:%d, expected %d:%d", l, c, line, col);
}

static void test_valid_document_parses_with_member_order(void **state)
{
    (void)state;
    rl_json_doc *doc = parse_ok("{\"b\": 1, \"a\": [true, null, \"s\\u00e9\"], \"c\": {\"d\": -0.5e2}}");
    const cJSON *root = rl_json_root(doc);
    assert_true(cJSON_IsObject(root));
    assert_string_equal(root->child->string, "b");
    assert_int_equal(cJSON_GetArraySize(cJSON_GetObjectItem(root, "a")), 3);
    double d = 0;
    assert_int_equal(rl_json_number(doc, cJSON_GetObjectItem(cJSON_GetObjectItem(root, "c"), "d"), &d), RL_OK);
    assert_true(d == -50.0);
    assert_string_equal(rl_json_name(doc), "doc.json");
    rl_json_free(doc);
    rl_json_free(NULL);
}

static void test_positions_of_nested_keys_are_exact(void **state)
{
    (void)state;
    const char *text =
        "{\n"                                  /* line 1 */
        "  \"camera\": {\n"                    /* 2 */
        "    \"eye\": [0, 1,\n"                /* 3 */
        "            5],\n"                    /* 4 */
        "    \"fov_deg\": 45\n"                /* 5 */
        "  },\n"                               /* 6 */
        "\t\"objects\": [ {\"mesh\": \"a.obj\"}, 7 ]\n" /* 7 */
        "}\n";
    rl_json_doc *doc = parse_ok(text);
    const cJSON *root = rl_json_root(doc);
    const cJSON *camera = cJSON_GetObjectItem(root, "camera");
    const cJSON *eye = cJSON_GetObjectItem(camera, "eye");
    const cJSON *objects = cJSON_GetObjectItem(root, "objects");
    assert_pos(doc, root, 1, 1);
    assert_pos(doc, camera, 2, 3);
    assert_pos(doc, eye, 3, 5);
    assert_pos(doc, cJSON_GetArrayItem(eye, 0), 3, 13);
    assert_pos(doc, cJSON_GetArrayItem(eye, 2), 4, 13);
    assert_pos(doc, cJSON_GetObjectItem(camera, "fov_deg"), 5, 5);
    assert_pos(doc, objects, 7, 2);
    assert_pos(doc, cJSON_GetArrayItem(objects, 0), 7, 15);
    assert_pos(doc, cJSON_GetObjectItem(cJSON_GetArrayItem(objects, 0), "mesh"), 7, 16);
    assert_pos(doc, cJSON_GetArrayItem(objects, 1), 7, 34);
    rl_json_doc *bom = parse_ok("\xEF\xBB\xBF{\"k\": 1}");
    assert_pos(bom, rl_json_root(bom), 1, 1);
    assert_pos(bom, cJSON_GetObjectItem(rl_json_root(bom), "k"), 1, 2);
    rl_json_free(bom);
    /* An item from another tree has no position. */
    cJSON *other = cJSON_CreateNull();
    assert_pos(doc, other, 0, 0);
    cJSON_Delete(other);
    /* Semantic errors point there too. */
    rl_clear_error();
    assert_int_equal(rl_json_error(doc, cJSON_GetObjectItem(camera, "fov_deg"), "fov %d too wide", 45), RL_ERR_PARSE);
    assert_string_equal(rl_last_error(), "doc.json:5:5: fov 45 too wide");
    rl_clear_error();
    rl_json_free(doc);
}

static void test_syntax_errors_report_line_column_and_expectation(void **state)
{
    (void)state;
    expect_error("{\n  \"a\": 1\n  \"b\": 2\n}", RL_ERR_PARSE,
                 "scene.json:3:3: expected ',' or '}' after object member");
    expect_error("[1, 2\n 3]", RL_ERR_PARSE, "scene.json:2:2: expected ',' or ']' after array element");
    expect_error("{\"a\" 1}", RL_ERR_PARSE, "scene.json:1:6: expected ':' after object key");
    expect_error("{\"a\": 1,\n}", RL_ERR_PARSE, "scene.json:2:1: trailing comma before '}'");
    expect_error("[1,]", RL_ERR_PARSE, "scene.json:1:4: trailing comma before ']'");
    expect_error("{a: 1}", RL_ERR_PARSE, "scene.json:1:2: expected a string key or '}'");
    expect_error("{\"x\": 01}", RL_ERR_PARSE, "scene.json:1:7: invalid number");
    expect_error("{\"x\": -}", RL_ERR_PARSE, "scene.json:1:7: invalid number");
    expect_error("{\"x\": 1.}", RL_ERR_PARSE, "scene.json:1:7: invalid number");
    expect_error("{\"x\": 1e+}", RL_ERR_PARSE, "scene.json:1:7: invalid number");
    expect_error("{\"x\": tru}", RL_ERR_PARSE, "scene.json:1:7: invalid literal");
    expect_error("{\"x\": \"a\\q\"}", RL_ERR_PARSE, "scene.json:1:9: invalid escape");
    expect_error("{\"x\": \"\\u12G4\"}", RL_ERR_PARSE, "scene.json:1:8: invalid \\u escape");
    expect_error("{\"x\": \"\\ud800\"}", RL_ERR_PARSE, "scene.json:1:8: unpaired UTF-16");
    expect_error("{\"x\": \"ab\ncd\"}", RL_ERR_PARSE, "scene.json:1:10: unterminated string");
    expect_error("// comment\n{}", RL_ERR_PARSE, "scene.json:1:1: comments are not allowed");
    expect_error("{} {}", RL_ERR_PARSE, "scene.json:1:4: unexpected '{' after the top-level value");
    expect_error("{\"x\": 'y'}", RL_ERR_PARSE, "scene.json:1:7: strings must use double quotes");
    expect_error("[1, , 2]", RL_ERR_PARSE, "scene.json:1:5: expected a value, found ','");
    expect_error("{\"a\": [1, 2}", RL_ERR_PARSE, "scene.json:1:12: expected ',' or ']' after array element, found '}' (array opened at 1:7)");
    /* A byte order mark is skipped and does not shift columns. */
    expect_error("\xEF\xBB\xBF{\"a\" 1}", RL_ERR_PARSE, "scene.json:1:6: expected ':'");
}

static void test_truncated_input_reports_end_of_file(void **state)
{
    (void)state;
    expect_error("{\n  \"a\": [1, 2", RL_ERR_PARSE, "scene.json:2:13: unexpected end of file (array opened at 2:8");
    expect_error("{\"a\": ", RL_ERR_PARSE, "scene.json:1:7: unexpected end of file (expected a value)");
    expect_error("{\"a\": \"abc", RL_ERR_PARSE, "unexpected end of file in string (started at 1:7)");
    expect_error("{\"a\": 1", RL_ERR_PARSE, "scene.json:1:8: unexpected end of file (object opened at 1:1");
    /* Text with a length shorter than the string: only len bytes count. */
    rl_json_doc *doc = NULL;
    rl_clear_error();
    assert_int_equal(rl_json_parse("cut", "[1, 2, 3]", 5, &doc), RL_ERR_PARSE);
    assert_non_null(strstr(rl_last_error(), "cut:1:6: unexpected end of file"));
    assert_null(doc);
    rl_clear_error();
}

static void test_empty_input_is_a_parse_error(void **state)
{
    (void)state;
    expect_error("", RL_ERR_PARSE, "scene.json:1:1: unexpected end of file");
    expect_error("  \n\t", RL_ERR_PARSE, "scene.json:2:2: unexpected end of file");
    rl_json_doc *doc = NULL;
    assert_int_equal(rl_json_parse("null-text", NULL, 0, &doc), RL_ERR_PARSE);
    assert_null(doc);
    rl_clear_error();
}

static void test_duplicate_keys_are_rejected_with_both_positions(void **state)
{
    (void)state;
    expect_error("{\n \"a\": 1,\n \"b\": {\"x\": 1, \"y\": 2,\n   \"x\": 3}\n}", RL_ERR_PARSE,
                 "scene.json:4:4: duplicate key \"x\" (first defined at 3:8)");
    /* Escapes are compared decoded: "\u0061" is "a". */
    expect_error("{\"a\": 1, \"\\u0061\": 2}", RL_ERR_PARSE, "scene.json:1:10: duplicate key \"a\"");
    /* The same key in different objects is fine. */
    rl_json_doc *doc = parse_ok("[{\"a\": 1}, {\"a\": 2}]");
    rl_json_free(doc);
}

static void test_check_keys_names_unknown_key_with_position(void **state)
{
    (void)state;
    rl_json_doc *doc = parse_ok("{\n  \"spp\": 4,\n  \"bounce\": 2\n}");
    static const char *const allowed[] = { "spp", "bounces", NULL };
    static const char *const all[] = { "spp", "bounce", NULL };
    rl_clear_error();
    assert_int_equal(rl_json_check_keys(doc, rl_json_root(doc), "renderer", all), RL_OK);
    assert_int_equal(rl_json_check_keys(doc, rl_json_root(doc), "renderer", allowed), RL_ERR_PARSE);
    assert_string_equal(rl_last_error(),
                        "doc.json:3:3: unknown key \"bounce\" in renderer (expected one of: spp, bounces)");
    rl_clear_error();
    assert_int_equal(rl_json_check_keys(doc, cJSON_GetObjectItem(rl_json_root(doc), "spp"), "renderer", allowed),
                     RL_ERR_PARSE);
    assert_non_null(strstr(rl_last_error(), "doc.json:2:3: expected an object"));
    rl_clear_error();
    rl_json_free(doc);
}

static void test_typed_reads_check_types_and_leave_output_untouched(void **state)
{
    (void)state;
    rl_json_doc *doc = parse_ok("{\"v\": [1, 2.5, -3], \"short\": [1, 2], \"mixed\": [1, \"2\", 3],"
                                " \"s\": \"x\", \"huge\": 1e999, \"f\": [1e39, 0, 0]}");
    const cJSON *root = rl_json_root(doc);
    float v[3] = { 9, 9, 9 };
    assert_int_equal(rl_json_vec3(doc, cJSON_GetObjectItem(root, "v"), v), RL_OK);
    assert_true(v[0] == 1 && v[1] == 2.5f && v[2] == -3);
    float w[3] = { 9, 9, 9 };
    rl_clear_error();
    assert_int_equal(rl_json_vec3(doc, cJSON_GetObjectItem(root, "short"), w), RL_ERR_PARSE);
    assert_non_null(strstr(rl_last_error(), "doc.json:1:21: expected an array of 3 numbers"));
    rl_clear_error();
    assert_int_equal(rl_json_vec3(doc, cJSON_GetObjectItem(root, "mixed"), w), RL_ERR_PARSE);
    assert_non_null(strstr(rl_last_error(), "doc.json:1:51: expected a finite number"));
    assert_int_equal(rl_json_vec3(doc, cJSON_GetObjectItem(root, "f"), w), RL_ERR_PARSE); /* float overflow */
    assert_true(w[0] == 9 && w[1] == 9 && w[2] == 9);
    double d = 7;
    assert_int_equal(rl_json_number(doc, cJSON_GetObjectItem(root, "s"), &d), RL_ERR_PARSE);
    assert_int_equal(rl_json_number(doc, cJSON_GetObjectItem(root, "huge"), &d), RL_ERR_PARSE);
    assert_true(d == 7);
    rl_clear_error();
    rl_json_free(doc);
}

static void test_write_file_round_trips_and_reports_io_errors(void **state)
{
    (void)state;
    const char *dir = getenv("RL_TEST_TMP");
    char path[1024];
    snprintf(path, sizeof path, "%s/test_json_out.json", dir && *dir ? dir : "/tmp");
    cJSON *obj = cJSON_CreateObject();
    cJSON_AddNumberToObject(obj, "ms", 12.5);
    cJSON_AddStringToObject(obj, "name", "cornell");
    assert_int_equal(rl_json_write_file(obj, path), RL_OK);
    rl_json_doc *doc = NULL;
    assert_int_equal(rl_json_parse_file(path, &doc), RL_OK);
    assert_true(cJSON_GetObjectItem(rl_json_root(doc), "ms")->valuedouble == 12.5);
    assert_string_equal(rl_json_name(doc), path);
    rl_json_free(doc);
    rl_clear_error();
    assert_int_equal(rl_json_write_file(obj, "/nonexistent-dir/out.json"), RL_ERR_IO);
    assert_non_null(strstr(rl_last_error(), "/nonexistent-dir/out.json: cannot open for writing: "));
    rl_clear_error();
    doc = NULL;
    assert_int_equal(rl_json_parse_file("/nonexistent-dir/in.json", &doc), RL_ERR_IO);
    assert_non_null(strstr(rl_last_error(), "/nonexistent-dir/in.json: cannot open: "));
    assert_null(doc);
    rl_clear_error();
    cJSON_Delete(obj);
}

static void test_deep_nesting_is_refused_not_overflowed(void **state)
{
    (void)state;
    enum { N = 100000 };
    char *text = malloc(2 * N + 1);
    assert_non_null(text);
    memset(text, '[', N);
    memset(text + N, ']', N);
    text[2 * N] = '\0';
    rl_json_doc *doc = NULL;
    rl_clear_error();
    assert_int_equal(rl_json_parse("deep", text, 2 * N, &doc), RL_ERR_PARSE);
    assert_non_null(strstr(rl_last_error(), "nesting deeper than"));
    assert_null(doc);
    rl_clear_error();
    free(text);
}

static void test_random_mutations_never_crash_or_confuse_the_scanner(void **state)
{
    (void)state;
    /* A cheap in-test fuzzer: the scanner must agree with cJSON (never
     * RL_ERR_INTERNAL) and accept nothing cJSON rejects. */
    static const char seed[] = "{\"a\": [1, -2.5e3, true, null], \"b\": {\"c\": \"x\\u00e9\\n\"}, \"d\": false}";
    static const char alphabet[] = "{}[]\":,.-+eE0123456789tfnul\\ \n\"xu";
    rl_rng rng;
    rl_rng_seed(&rng, 2024, 7);
    char text[sizeof seed];
    int accepted = 0;
    for (int iter = 0; iter < 20000; ++iter) {
        memcpy(text, seed, sizeof seed);
        size_t len = sizeof seed - 1;
        int edits = 1 + (int)rl_rng_bounded(&rng, 3);
        for (int e = 0; e < edits; ++e)
            text[rl_rng_bounded(&rng, (uint32_t)len)] = alphabet[rl_rng_bounded(&rng, sizeof alphabet - 1)];
        if (rl_rng_bounded(&rng, 4) == 0)
            len = rl_rng_bounded(&rng, (uint32_t)len + 1);
        rl_json_doc *doc = NULL;
        rl_clear_error();
        rl_status st = rl_json_parse("fuzz", text, len, &doc);
        if (st != RL_OK && st != RL_ERR_PARSE)
            fail_msg("%.*s -> %s", (int)len, text, rl_last_error());
        if (st == RL_ERR_PARSE && strstr(rl_last_error(), "cannot parse this value"))
            fail_msg("scanner accepted what cJSON rejected: %.*s", (int)len, text);
        accepted += st == RL_OK;
        rl_json_free(doc);
    }
    assert_true(accepted > 100); /* the mutations do not all break the syntax */
    rl_clear_error();
}

/* Issue 34: the size limit and the value count that goes with it refuse a
 * file before it is read and a document before cJSON builds its tree;
 * positions of a large document still come out right (found by scanning
 * again, with no table per value). */
static void test_size_and_value_limits_refuse_before_building(void **state)
{
    (void)state;
    assert_int_equal(rl_json_max_bytes(), RL_JSON_MAX_BYTES);
    rl_json_set_max_bytes(1616);            /* 101 values */
    char text[1700];
    size_t n = 0;
    text[n++] = '[';
    for (int i = 0; i < 100; ++i)
        n += (size_t)snprintf(text + n, sizeof text - n, "%s0", i ? "," : "");
    text[n++] = ']';
    text[n] = '\0';
    rl_json_doc *doc = NULL;
    assert_int_equal(rl_json_parse("ok.json", text, n, &doc), RL_OK);   /* 101 values in 201 bytes */
    rl_json_free(doc);
    doc = NULL;
    rl_json_set_max_bytes(1600);
    expect_error(text, RL_ERR_LIMIT, "101 JSON values, more than the limit of 100");
    memset(text, ' ', sizeof text - 1);
    text[0] = '0';
    text[sizeof text - 1] = '\0';
    expect_error(text, RL_ERR_LIMIT, "1699 bytes of JSON, more than the limit of 1600");

    const char *dir = getenv("RL_TEST_TMP");
    char path[1024];
    snprintf(path, sizeof path, "%s/test_json_big.json", dir && *dir ? dir : "/tmp");
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, strlen(text), f), strlen(text));
    fclose(f);
    rl_clear_error();
    assert_int_equal(rl_json_parse_file(path, &doc), RL_ERR_LIMIT);
    assert_non_null(strstr(rl_last_error(), "rl_json_set_max_bytes"));
    assert_null(doc);
    rl_clear_error();
    remove(path);
    rl_json_set_max_bytes(0);
    assert_int_equal(rl_json_max_bytes(), RL_JSON_MAX_BYTES);

    /* The last of 10000 members, and a key after a long string. */
    size_t cap = (size_t)1 << 20;
    char *big = malloc(cap);
    assert_non_null(big);
    n = (size_t)snprintf(big, cap, "{\"s\": \"%0500d\",\n", 7);
    for (int i = 0; i < 10000; ++i)
        n += (size_t)snprintf(big + n, cap - n, "  \"k%d\": [%d, {\"x\": true}]%s\n", i, i, i < 9999 ? "," : "");
    n += (size_t)snprintf(big + n, cap - n, "}");
    doc = parse_ok(big);
    const cJSON *root = rl_json_root(doc);
    assert_pos(doc, cJSON_GetObjectItem(root, "k0"), 2, 3);
    assert_pos(doc, cJSON_GetObjectItem(root, "k9999"), 10001, 3);
    assert_pos(doc, cJSON_GetObjectItem(cJSON_GetArrayItem(cJSON_GetObjectItem(root, "k9999"), 1), "x"), 10001, 20);
    cJSON *orphan = cJSON_CreateNull();
    int l = -1, c = -1;
    rl_json_pos(doc, orphan, &l, &c);
    assert_int_equal(l, 0);
    assert_int_equal(c, 0);
    cJSON_Delete(orphan);
    rl_json_free(doc);
    free(big);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_size_and_value_limits_refuse_before_building),
        cmocka_unit_test(test_valid_document_parses_with_member_order),
        cmocka_unit_test(test_positions_of_nested_keys_are_exact),
        cmocka_unit_test(test_syntax_errors_report_line_column_and_expectation),
        cmocka_unit_test(test_truncated_input_reports_end_of_file),
        cmocka_unit_test(test_empty_input_is_a_parse_error),
        cmocka_unit_test(test_duplicate_keys_are_rejected_with_both_positions),
        cmocka_unit_test(test_check_keys_names_unknown_key_with_position),
        cmocka_unit_test(test_typed_reads_check_types_and_leave_output_untouched),
        cmocka_unit_test(test_write_file_round_trips_and_reports_io_errors),
        cmocka_unit_test(test_deep_nesting_is_refused_not_overflowed),
        cmocka_unit_test(test_random_mutations_never_crash_or_confuse_the_scanner),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
