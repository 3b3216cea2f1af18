/* test_approx_io.c: approximations as JSON (src/eval/approx_io.c): a round
 * trip answers every query, region and sample identically; truncated,
 * foreign and malformed files are refused with RL_ERR_PARSE, missing ones
 * with RL_ERR_IO. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl_property.h"
#include "rl/rl_rng.h"
#include "rl/rl_sampling.h"

static void tmp_path(char *buf, size_t n, const char *name)
{
    const char *base = getenv("RL_TEST_TMP");
    snprintf(buf, n, "%s/%s", base ? base : "/tmp", name);
}

/* Values with NaN holes (written as "nan"), flat areas (quality +inf) and a
 * set over 100 objects. */
static double f_value(rl_vec3 p)
{
    if (p.x > 7.0f && p.z > 7.0f)
        return NAN;
    return p.x < 3.0f ? 2.0 : sin(p.x) * cos(0.5 * p.z) + 0.25 * p.y;
}

static rl_status commit_100(void *user, const rl_scene *scene, int workers, uint32_t *set_size)
{
    (void)scene;
    (void)workers;
    *set_size = *(const uint32_t *)user;
    return RL_OK;
}

static rl_status evaluate(void *user, int worker, rl_vec3 pos, double *value, uint64_t *set)
{
    (void)worker;
    uint32_t bits = *(const uint32_t *)user;
    *value = f_value(pos);
    if (set && bits) {
        memset(set, 0, (bits + 63) / 64 * sizeof *set);
        uint32_t i = (uint32_t)(fabsf(pos.x) * 7.0f + fabsf(pos.z) * 3.0f) % bits;
        set[i / 64] |= 1ull << (i % 64);
        set[0] |= 1u;
    }
    return RL_OK;
}

static rl_property *make_property(uint32_t *bits)
{
    rl_property *p = NULL;
    rl_property_callbacks cb = { .name = "io-test", .unit = "things", .commit = commit_100, .evaluate = evaluate };
    assert_int_equal(rl_property_create_custom(&cb, bits, &p), RL_OK);
    assert_int_equal(rl_property_commit(p, NULL, 2), RL_OK);
    return p;
}

static void same_double(double a, double b)
{
    if (memcmp(&a, &b, sizeof a) != 0)
        fail_msg("%.17g != %.17g", a, b);
}

static void assert_identical(const rl_approx *a, const rl_approx *b, uint64_t seed)
{
    assert_int_equal(rl_approx_dims(a), rl_approx_dims(b));
    rl_aabb ba = rl_approx_bounds(a), bb = rl_approx_bounds(b);
    assert_memory_equal(&ba, &bb, sizeof ba);
    assert_string_equal(rl_approx_property(a), rl_approx_property(b));
    assert_string_equal(rl_approx_unit(a), rl_approx_unit(b));
    assert_int_equal(rl_approx_set_size(a), rl_approx_set_size(b));
    same_double(rl_approx_measure(a), rl_approx_measure(b));
    same_double(rl_approx_seconds(a), rl_approx_seconds(b));
    size_t words = (rl_approx_set_size(a) + 63) / 64;
    assert_int_equal(rl_approx_region_count(a), rl_approx_region_count(b));
    for (uint32_t i = 0; i < rl_approx_region_count(a); ++i) {
        rl_approx_region ra, rb;
        assert_int_equal(rl_approx_get_region(a, i, &ra), RL_OK);
        assert_int_equal(rl_approx_get_region(b, i, &rb), RL_OK);
        assert_memory_equal(&ra.box, &rb.box, sizeof ra.box);
        same_double(ra.value, rb.value);
        same_double(ra.min, rb.min);
        same_double(ra.max, rb.max);
        same_double(ra.quality, rb.quality);
        assert_int_equal(ra.samples, rb.samples);
        assert_int_equal(ra.depth, rb.depth);
        assert_int_equal(ra.linear, rb.linear);
        same_double(ra.offset, rb.offset);
        for (int k = 0; k < 3; ++k)
            same_double(ra.gradient[k], rb.gradient[k]);
        if (words)
            assert_memory_equal(rl_approx_region_set(a, i), rl_approx_region_set(b, i), words * 8);
    }
    assert_int_equal(rl_approx_sample_count(a), rl_approx_sample_count(b));
    for (uint32_t i = 0; i < rl_approx_sample_count(a); ++i) {
        rl_vec3 pa, pb;
        double va, vb;
        assert_int_equal(rl_approx_sample(a, i, &pa, &va), RL_OK);
        assert_int_equal(rl_approx_sample(b, i, &pb, &vb), RL_OK);
        assert_memory_equal(&pa, &pb, sizeof pa);
        same_double(va, vb);
        if (words)
            assert_memory_equal(rl_approx_sample_set(a, i), rl_approx_sample_set(b, i), words * 8);
        /* Sample positions lie on boundaries, where ties are decided. */
        double qa, qb;
        uint32_t la, lb;
        assert_int_equal(rl_approx_query(a, pa, &qa, &la), RL_OK);
        assert_int_equal(rl_approx_query(b, pa, &qb, &lb), RL_OK);
        same_double(qa, qb);
        assert_int_equal(la, lb);
    }
    rl_rng rng;
    rl_rng_seed(&rng, seed, 1);
    for (int i = 0; i < 1000; ++i) {
        rl_vec3 p = { ba.min.x + (ba.max.x - ba.min.x) * rl_rng_float(&rng),
                      ba.min.y + (ba.max.y - ba.min.y) * rl_rng_float(&rng),
                      ba.min.z + (ba.max.z - ba.min.z) * rl_rng_float(&rng) };
        double qa, qb;
        uint32_t la, lb;
        assert_int_equal(rl_approx_query(a, p, &qa, &la), RL_OK);
        assert_int_equal(rl_approx_query(b, p, &qb, &lb), RL_OK);
        same_double(qa, qb);
        assert_int_equal(la, lb);
    }
}

static rl_approx *round_trip(const rl_approx *a, const char *name)
{
    char path[1024];
    tmp_path(path, sizeof path, name);
    if (rl_approx_save_json(a, path) != RL_OK)
        fail_msg("save: %s", rl_last_error());
    rl_approx *b = NULL;
    if (rl_approx_load_json(path, &b) != RL_OK)
        fail_msg("load: %s", rl_last_error());
    return b;
}

static void test_round_trip_answers_every_query_identically(void **state)
{
    (void)state;
    uint32_t bits = 100;
    rl_property *p = make_property(&bits);
    const rl_sampling_desc descs[] = {
        { .region = { { 0, 0, 0 }, { 10, 3, 10 } }, .max_samples = 500, .min_side = 0.1f, .seed = 3 },
        { .region = { { 0, 0, 0 }, { 10, 3, 10 } }, .max_samples = 301, .min_side = 0.1f, .linear = true,
          .positions = RL_POSITIONS_RANDOM, .combine = RL_COMBINE_MAX, .seed = UINT64_MAX },
        { .region = { { -1.1f, 0, 0.3f }, { 9.7f, 0, 10.1f } }, .dims = 2, .height = 1.7f, .max_samples = 257,
          .min_side = 0.05f, .linear = true },
        { .region = { { 0, 0, 0 }, { 10, 3, 10 } }, .method = RL_SAMPLING_GRID, .max_samples = 200 },
        { .region = { { 0, 0, 0 }, { 10, 0, 10 } }, .dims = 2, .method = RL_SAMPLING_GRID, .grid_res = { 7, 0, 3 },
          .linear = true },
        { .region = { { 0, 0, 0 }, { 10, 3, 10 } }, .method = RL_SAMPLING_GRID, .max_samples = 64,
          .grid_shift = true, .seed = 11 },
    };
    for (size_t i = 0; i < sizeof descs / sizeof descs[0]; ++i) {
        rl_approx *a = NULL;
        if (rl_sample_property(p, &descs[i], &a) != RL_OK)
            fail_msg("sample: %s", rl_last_error());
        rl_approx *b = round_trip(a, "approx_round_trip.json");
        assert_identical(a, b, i);
        /* And once more: a loaded approximation saves the same file. */
        rl_approx *c = round_trip(b, "approx_round_trip2.json");
        assert_identical(a, c, i + 100);
        rl_approx_release(a);
        rl_approx_release(b);
        rl_approx_release(c);
    }
    bits = 0;
    rl_property_release(p);
    p = make_property(&bits);
    rl_approx *a = NULL;
    assert_int_equal(rl_sample_property(p, &descs[0], &a), RL_OK);
    rl_approx *b = round_trip(a, "approx_no_sets.json");
    assert_identical(a, b, 7);
    assert_null(rl_approx_region_set(b, 0));
    rl_approx_release(a);
    rl_approx_release(b);
    rl_property_release(p);
}

/* ---- broken files -------------------------------------------------------- */

static char *read_text(const char *path, long *len)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    *len = ftell(f);
    fseek(f, 0, SEEK_SET);
    char *buf = malloc((size_t)*len + 1);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)*len, f), (size_t)*len);
    buf[*len] = '\0';
    fclose(f);
    return buf;
}

static void write_text(const char *path, const char *text, size_t n)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    assert_int_equal(fwrite(text, 1, n, f), n);
    fclose(f);
}

static void expect_load(const char *path, rl_status want)
{
    rl_approx *a = NULL;
    rl_clear_error();
    rl_status st = rl_approx_load_json(path, &a);
    if (st != want)
        fail_msg("%s: got %s, expected %s (%s)", path, rl_status_name(st), rl_status_name(want), rl_last_error());
    assert_null(a);
    assert_true(strlen(rl_last_error()) > 0);
    rl_clear_error();
}

/* Loads the saved file as cJSON, lets edit() change it, writes it back to
 * `broken` and expects RL_ERR_PARSE with `key` in the message. */
static void expect_edit_refused(const char *good, const char *broken, void (*edit)(cJSON *root), const char *key)
{
    long len;
    char *text = read_text(good, &len);
    cJSON *root = cJSON_Parse(text);
    free(text);
    assert_non_null(root);
    edit(root);
    char *out = cJSON_Print(root);
    cJSON_Delete(root);
    write_text(broken, out, strlen(out));
    cJSON_free(out);
    rl_approx *a = NULL;
    rl_clear_error();
    assert_int_equal(rl_approx_load_json(broken, &a), RL_ERR_PARSE);
    assert_null(a);
    if (!strstr(rl_last_error(), key))
        fail_msg("message \"%s\" does not name \"%s\"", rl_last_error(), key);
    rl_clear_error();
}

static void edit_version(cJSON *r) { cJSON_ReplaceItemInObject(r, "version", cJSON_CreateNumber(2)); }
static void edit_format(cJSON *r) { cJSON_ReplaceItemInObject(r, "format", cJSON_CreateString("renderlab-linespace")); }
static void edit_unknown_key(cJSON *r) { cJSON_AddNumberToObject(r, "bounce", 3); }
static void edit_missing_key(cJSON *r) { cJSON_DeleteItemFromObject(r, "samples"); }
static void edit_dims(cJSON *r) { cJSON_ReplaceItemInObject(r, "dims", cJSON_CreateNumber(4)); }
static void edit_leaf_value(cJSON *r)
{
    cJSON *leaf = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "leaves"), 1);
    cJSON_ReplaceItemInObject(leaf, "value", cJSON_CreateString("lots"));
}
static void edit_leaf_key(cJSON *r)
{
    cJSON *leaf = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "leaves"), 0);
    cJSON_AddNumberToObject(leaf, "colour", 1);
}
static void edit_child_index(cJSON *r)
{
    cJSON *node = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "nodes"), 0);
    cJSON_ReplaceItemInArray(node, cJSON_GetArraySize(node) - 1, cJSON_CreateNumber(100000));
}
static void edit_child_cycle(cJSON *r)
{
    cJSON *node = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "nodes"), 0);
    cJSON_ReplaceItemInArray(node, cJSON_GetArraySize(node) - 1, cJSON_CreateNumber(0));
}
static void edit_drop_leaf(cJSON *r) { cJSON_DeleteItemFromArray(cJSON_GetObjectItem(r, "leaves"), 0); }
static void edit_set_index(cJSON *r)
{
    cJSON *leaf = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "leaves"), 0);
    cJSON_AddItemToArray(cJSON_GetObjectItem(leaf, "set"), cJSON_CreateNumber(100));
}
static void edit_sample(cJSON *r)
{
    cJSON *s = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "samples"), 2);
    cJSON_ReplaceItemInArray(s, 0, cJSON_CreateNumber(1e6));
}
static void edit_sample_float(cJSON *r)
{
    cJSON *s = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "samples"), 2);
    cJSON_ReplaceItemInArray(s, 0, cJSON_CreateNumber(0.1));
}
static void edit_desc(cJSON *r)
{
    cJSON_ReplaceItemInObject(cJSON_GetObjectItem(r, "desc"), "positions", cJSON_CreateString("poisson"));
}
static void edit_seed(cJSON *r)
{
    cJSON_ReplaceItemInObject(cJSON_GetObjectItem(r, "desc"), "seed", cJSON_CreateNumber(5));
}
static void edit_grid_shift(cJSON *r)
{
    cJSON_ReplaceItemInObject(cJSON_GetObjectItem(r, "desc"), "grid_shift", cJSON_CreateString("yes"));
}
static void edit_grid(cJSON *r)
{
    cJSON *node = cJSON_GetArrayItem(cJSON_GetObjectItem(r, "nodes"), 0);
    cJSON_ReplaceItemInArray(node, 0, cJSON_CreateString("grid"));
}

/* Issue 34: 200 samples and their nodes, each claiming a set of 2^26 bits,
 * would be 1.7 GB of bitsets from a file of kilobytes. */
static void edit_set_size_bomb(cJSON *r)
{
    cJSON_ReplaceItemInObject(r, "set_size", cJSON_CreateNumber(1 << 26));
}

static void test_broken_files_are_refused(void **state)
{
    (void)state;
    uint32_t bits = 100;
    rl_property *p = make_property(&bits);
    rl_approx *a = NULL;
    assert_int_equal(rl_sample_property(p, &(rl_sampling_desc){ .region = { { 0, 0, 0 }, { 10, 3, 10 } },
                                                               .max_samples = 200 },
                                        &a),
                     RL_OK);
    char good[1024], broken[1024];
    tmp_path(good, sizeof good, "approx_good.json");
    tmp_path(broken, sizeof broken, "approx_broken.json");
    assert_int_equal(rl_approx_save_json(a, good), RL_OK);

    long len;
    char *text = read_text(good, &len);
    for (long cut = 1; cut < len; cut += len / 37 + 1) {
        write_text(broken, text, (size_t)cut);
        expect_load(broken, RL_ERR_PARSE);
    }
    write_text(broken, "", 0);
    expect_load(broken, RL_ERR_PARSE);
    write_text(broken, "[1, 2]", 6);
    expect_load(broken, RL_ERR_PARSE);
    free(text);

    /* Re-printed by cJSON (numbers shortened to 15 digits where that comes
     * within its epsilon): still the same approximation. */
    text = read_text(good, &len);
    cJSON *root = cJSON_Parse(text);
    free(text);
    assert_non_null(root);
    char *reprinted = cJSON_Print(root);
    cJSON_Delete(root);
    write_text(broken, reprinted, strlen(reprinted));
    cJSON_free(reprinted);
    rl_approx *again = NULL;
    if (rl_approx_load_json(broken, &again) != RL_OK)
        fail_msg("re-printed file: %s", rl_last_error());
    /* The same float positions; values within cJSON's rounding. */
    assert_int_equal(rl_approx_sample_count(again), rl_approx_sample_count(a));
    for (uint32_t i = 0; i < rl_approx_sample_count(a); ++i) {
        rl_vec3 pa, pb;
        double va, vb;
        assert_int_equal(rl_approx_sample(a, i, &pa, &va), RL_OK);
        assert_int_equal(rl_approx_sample(again, i, &pb, &vb), RL_OK);
        assert_memory_equal(&pa, &pb, sizeof pa);
        assert_float_equal(va, vb, 1e-12 * (1.0 + fabs(va)));
        assert_int_equal(rl_approx_query(again, pa, &vb, NULL), RL_OK);
        assert_float_equal(va, vb, 1e-12 * (1.0 + fabs(va)));
    }
    rl_approx_release(again);

    expect_edit_refused(good, broken, edit_version, "version");
    expect_edit_refused(good, broken, edit_format, "format");
    expect_edit_refused(good, broken, edit_unknown_key, "bounce");
    expect_edit_refused(good, broken, edit_missing_key, "samples");
    expect_edit_refused(good, broken, edit_dims, "dims");
    expect_edit_refused(good, broken, edit_leaf_value, "value");
    expect_edit_refused(good, broken, edit_leaf_key, "colour");
    expect_edit_refused(good, broken, edit_child_index, "nodes");
    expect_edit_refused(good, broken, edit_child_cycle, "nodes");
    expect_edit_refused(good, broken, edit_drop_leaf, "leaves");
    expect_edit_refused(good, broken, edit_set_index, "set");
    expect_edit_refused(good, broken, edit_sample, "samples");
    expect_edit_refused(good, broken, edit_sample_float, "samples");
    expect_edit_refused(good, broken, edit_desc, "positions");
    expect_edit_refused(good, broken, edit_seed, "seed");
    expect_edit_refused(good, broken, edit_grid_shift, "grid_shift");
    expect_edit_refused(good, broken, edit_grid, "nodes");
    expect_edit_refused(good, broken, edit_set_size_bomb, "set_size");

    char missing[1024];
    tmp_path(missing, sizeof missing, "approx_does_not_exist.json");
    remove(missing);
    expect_load(missing, RL_ERR_IO);
    rl_approx *out = NULL;
    assert_int_equal(rl_approx_load_json(NULL, &out), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_approx_load_json(good, NULL), RL_ERR_INVALID_ARG);
    assert_int_equal(rl_approx_save_json(NULL, good), RL_ERR_INVALID_ARG);
    char nodir[1024];
    tmp_path(nodir, sizeof nodir, "no/such/dir/approx.json");
    assert_int_equal(rl_approx_save_json(a, nodir), RL_ERR_IO);
    rl_clear_error();
    rl_approx_release(a);
    rl_property_release(p);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_round_trip_answers_every_query_identically),
        cmocka_unit_test(test_broken_files_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
