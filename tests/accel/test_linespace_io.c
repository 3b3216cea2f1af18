/* test_linespace_io.c: saving and loading a Line Space
 * (src/accel/linespace_io.c): bit-identical answers after a round trip;
 * corrupt, truncated and foreign files refused, and intact files whose
 * surface records are not surfaces of the scene. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "rl/rl_accel.h"
#include "rl/rl_linespace.h"
#include "rl/rl_rng.h"
#include "rl/rl_scene.h"

#include "accel/linespace_internal.h"

static void tmp_path(char *buf, size_t n, const char *name)
{
    const char *base = getenv("RL_TEST_TMP");
    snprintf(buf, n, "%s/%s", base ? base : "/tmp", name);
}

static rl_scene *builtin(const char *name, const char *params)
{
    rl_scene *s = NULL;
    if (rl_scene_create_builtin(name, params, &s) != RL_OK)
        fail_msg("%s: %s", name, rl_last_error());
    return s;
}

static rl_accel *grid_of(const rl_scene *s, int res)
{
    rl_accel *a = NULL;
    assert_int_equal(rl_accel_create(s, &(rl_accel_desc){ .kind = RL_ACCEL_GRID, .grid_res = { res, res, res } },
                                     &a),
                     RL_OK);
    assert_int_equal(rl_accel_commit(a), RL_OK);
    return a;
}

static rl_vec3 shade(void *user, const rl_ls_surface *s, rl_vec3 dir)
{
    (void)user;
    return rl_v3(s->n.x * 0.5f + 0.5f, dir.y * 0.5f + 0.5f, s->uv.x);
}

static float uniform(rl_rng *r, float lo, float hi) { return lo + (hi - lo) * rl_rng_float(r); }

static void copy_file(const char *from, const char *to, long truncate_to, long flip_at)
{
    FILE *f = fopen(from, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    unsigned char *buf = malloc((size_t)len);
    assert_non_null(buf);
    assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    if (flip_at >= 0)
        buf[flip_at % len] ^= 0x10;
    FILE *g = fopen(to, "wb");
    assert_non_null(g);
    size_t n = truncate_to >= 0 ? (size_t)truncate_to : (size_t)len;
    assert_int_equal(fwrite(buf, 1, n, g), n);
    fclose(g);
    free(buf);
}

static long file_size(const char *path)
{
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fclose(f);
    return len;
}

/* A copy of `from` with the 16-bit word at `at` set to value and the
 * checksum recomputed, as a forger would: over the header, then each of
 * the arrays (bytes[]) in turn. */
static void forge(const char *from, const char *to, const size_t bytes[7], long at, uint16_t value)
{
    long len = file_size(from);
    unsigned char *buf = malloc((size_t)len);
    assert_non_null(buf);
    FILE *f = fopen(from, "rb");
    assert_non_null(f);
    assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    memcpy(buf + at, &value, 2);
    uint64_t sum = 0;
    size_t off = 0;
    for (int i = 0; i < 7; off += bytes[i++])
        sum = rl_ls_file_hash(sum, buf + off, bytes[i]);
    assert_int_equal(off, (size_t)len - 8);
    memcpy(buf + len - 8, &sum, 8);
    FILE *g = fopen(to, "wb");
    assert_non_null(g);
    assert_int_equal(fwrite(buf, 1, (size_t)len, g), (size_t)len);
    fclose(g);
    free(buf);
}

/* Issue 34: records that no build writes, in a file whose checksum was
 * recomputed (NaN fields, a position outside its voxel, a material the
 * scene lacks, a NaN colour), are refused; the unchanged copy loads. */
static void forged_records_are_refused(const rl_accel *grid, const rl_linespace *ls, const char *path,
                                       const char *bad)
{
    rl_linespace_data d;
    rl_linespace_get_data(ls, &d);
    uint64_t occupied = d.num_occupied;
    const size_t bytes[7] = { 128, 4 * (size_t)d.num_cells, 8 * 2 * (size_t)d.num_blocks * d.occ_words,
                              4 * (size_t)d.num_cand, d.cand_start ? 4 * (size_t)(occupied + 1) : 0,
                              2 * 16 * (size_t)occupied, 2 * 8 * (size_t)occupied };
    long len = file_size(path);
    long preillum = len - 8 - (long)(occupied * 8 * 2), pnmt = preillum - (long)(occupied * 16 * 2);
    const uint16_t nan = 0x7e00, two = 0x4000, many = 0x6400 /* 1024 */;
    struct { long at; uint16_t value; } cases[] = {
        { pnmt + 2 * 5, nan },                         /* material (front record of shaft 0) */
        { pnmt + 2 * (16 * (long)(occupied / 2) + 8 + 5), nan },   /* material (back record) */
        { pnmt + 2 * 0, nan },                         /* position x */
        { pnmt + 2 * 1, two },                         /* position y outside its voxel */
        { pnmt + 2 * 3, nan },                         /* normal x */
        { pnmt + 2 * 5, many },                        /* material 1023 */
        { pnmt + 2 * 6, nan },                         /* texture u */
        { preillum + 2 * 9, nan },                     /* colour */
    };
    rl_linespace *back = NULL;
    forge(path, bad, bytes, pnmt + 2 * 5, 0x3c00 /* material 0 */);
    if (rl_linespace_load(grid, bad, &back) != RL_OK)
        fail_msg("a valid record re-summed: %s", rl_last_error());
    rl_linespace_release(back);
    back = NULL;
    for (size_t i = 0; i < sizeof cases / sizeof *cases; ++i) {
        forge(path, bad, bytes, cases[i].at, cases[i].value);
        rl_clear_error();
        if (rl_linespace_load(grid, bad, &back) != RL_ERR_PARSE)
            fail_msg("forged record %zu was not refused: %s", i, rl_last_error());
        assert_null(back);
        assert_non_null(strstr(rl_last_error(), "record") ? rl_last_error() : strstr(rl_last_error(), "colour"));
    }
    rl_clear_error();
}

static void round_trip(bool dynamic)
{
    rl_scene *s = builtin("cornell-teapot", "triangles=2000");
    const rl_scene_data *d = rl_scene_get_data(s);
    rl_accel *grid = grid_of(s, 6);
    rl_linespace *ls = NULL;
    rl_linespace_desc desc = { .n = 4, .k = 6, .dynamic = dynamic,
                               .payloads = RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM };
    assert_int_equal(rl_linespace_create(grid, &desc, &ls), RL_OK);
    assert_int_equal(rl_linespace_set_shader(ls, shade, NULL), RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_OK);
    char path[512], bad[512];
    tmp_path(path, sizeof path, dynamic ? "ls_dyn.rlls" : "ls_fixed.rlls");
    tmp_path(bad, sizeof bad, "ls_bad.rlls");
    assert_int_equal(rl_linespace_save(ls, path), RL_OK);

    rl_linespace *back = NULL;
    if (rl_linespace_load(grid, path, &back) != RL_OK)
        fail_msg("load: %s", rl_last_error());
    rl_linespace_stats a, b;
    rl_linespace_get_stats(ls, &a);
    rl_linespace_get_stats(back, &b);
    assert_int_equal(a.shafts, b.shafts);
    assert_int_equal(a.candidates, b.candidates);
    assert_int_equal(a.memory_bytes, b.memory_bytes);
    assert_true(b.dynamic == dynamic);
    rl_rng r;
    rl_rng_seed(&r, 99, 1);
    for (int i = 0; i < 10000; ++i) {
        rl_vec3 o = rl_v3(uniform(&r, d->bounds.min.x, d->bounds.max.x), uniform(&r, d->bounds.min.y, d->bounds.max.y),
                          uniform(&r, d->bounds.min.z, d->bounds.max.z));
        rl_ray ray = { .o = o, .d = rl_v3(uniform(&r, -1, 1), uniform(&r, -1, 1), uniform(&r, -1, 1)),
                       .t_min = 0.0f, .t_max = rl_rng_bounded(&r, 2) ? INFINITY : 0.3f };
        rl_ray r1 = ray, r2 = ray;
        rl_hit h1, h2;
        bool b1 = rl_linespace_intersect(ls, &r1, &h1), b2 = rl_linespace_intersect(back, &r2, &h2);
        assert_true(b1 == b2);
        assert_memory_equal(&h1, &h2, sizeof h1);
        assert_true(rl_linespace_occluded(ls, &ray) == rl_linespace_occluded(back, &ray));
        rl_ls_surface s1, s2;
        memset(&s1, 0, sizeof s1);
        memset(&s2, 0, sizeof s2);
        assert_true(rl_linespace_pnmt_intersect(ls, &ray, &s1) == rl_linespace_pnmt_intersect(back, &ray, &s2));
        assert_memory_equal(&s1, &s2, sizeof s1);
        rl_vec3 c1 = { 0 }, c2 = { 0 };
        float t1 = 0, t2 = 0;
        assert_true(rl_linespace_preillum(ls, &ray, &c1, &t1) == rl_linespace_preillum(back, &ray, &c2, &t2));
        assert_memory_equal(&c1, &c2, sizeof c1);
        assert_memory_equal(&t1, &t2, sizeof t1);
    }
    rl_linespace_release(back);

    /* Flipped bytes (header, arrays, checksum), truncation: RL_ERR_PARSE. */
    long len = file_size(path);
    long spots[] = { 0, 5, 40, 130, len / 2, len - 20, len - 1 };
    for (size_t i = 0; i < sizeof spots / sizeof *spots; ++i) {
        copy_file(path, bad, -1, spots[i]);
        back = NULL;
        rl_clear_error();
        assert_int_equal(rl_linespace_load(grid, bad, &back), RL_ERR_PARSE);
        assert_null(back);
    }
    forged_records_are_refused(grid, ls, path, bad);
    long cuts[] = { 0, 10, 127, len / 3, len - 1 };
    for (size_t i = 0; i < sizeof cuts / sizeof *cuts; ++i) {
        copy_file(path, bad, cuts[i], -1);
        rl_clear_error();
        assert_int_equal(rl_linespace_load(grid, bad, &back), RL_ERR_PARSE);
        assert_null(back);
    }
    rl_clear_error();
    assert_int_equal(rl_linespace_load(grid, "/nonexistent/dir/x.rlls", &back), RL_ERR_IO);

    /* Another scene, another grid: RL_ERR_INVALID_ARG with a message. */
    rl_scene *other = builtin("cornell-teapot", "triangles=1000");
    rl_accel *other_grid = grid_of(other, 6);
    rl_clear_error();
    assert_int_equal(rl_linespace_load(other_grid, path, &back), RL_ERR_INVALID_ARG);
    assert_non_null(strstr(rl_last_error(), "another"));
    rl_accel *grid7 = grid_of(s, 7);
    rl_clear_error();
    assert_int_equal(rl_linespace_load(grid7, path, &back), RL_ERR_INVALID_ARG);
    assert_null(back);
    rl_clear_error();
    rl_accel_release(grid7);
    rl_accel_release(other_grid);
    rl_scene_release(other);
    remove(bad);
    remove(path);
    rl_linespace_release(ls);
    rl_accel_release(grid);
    rl_scene_release(s);
}

static void test_linespace_dynamic_round_trip_is_bit_identical_and_bad_files_are_refused(void **state)
{
    (void)state;
    round_trip(true);
}

static void test_linespace_fixed_round_trip_is_bit_identical_and_bad_files_are_refused(void **state)
{
    (void)state;
    round_trip(false);
}

/* A PNMT record whose material half is NaN, or names a material the scene
 * lacks, in an otherwise intact file: refused at load (fuzz_linespace_cache
 * found the NaN turned into a material index by the query, undefined). */
static void test_linespace_pnmt_record_with_a_bad_material_is_refused(void **state)
{
    (void)state;
    rl_scene *s = builtin("cornell", NULL);
    rl_accel *grid = grid_of(s, 2);
    rl_linespace *ls = NULL;
    assert_int_equal(rl_linespace_create(grid, &(rl_linespace_desc){ .n = 1, .payloads = RL_LS_PNMT }, &ls), RL_OK);
    assert_int_equal(rl_linespace_commit(ls), RL_OK);
    char path[1024], bad[1024];
    tmp_path(path, sizeof path, "ls_pnmt_material.rlls");
    tmp_path(bad, sizeof bad, "ls_pnmt_material_bad.rlls");
    assert_int_equal(rl_linespace_save(ls, path), RL_OK);
    rl_linespace_stats st;
    rl_linespace_get_stats(ls, &st);
    rl_linespace_release(ls);
    long len = file_size(path);
    unsigned char *buf = malloc((size_t)len);
    assert_non_null(buf);
    FILE *f = fopen(path, "rb");
    assert_non_null(f);
    assert_int_equal(fread(buf, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    /* The PNMT array ends the file before the checksum: 16 halves per
     * occupied shaft, the material the 6th of each 8-half record. */
    uint64_t occupied = st.shafts - st.empty_shafts;
    unsigned char *pnmt = buf + len - 8 - 32 * (long)occupied;
    long used = -1;
    for (uint64_t r = 0; r < 2 * occupied && used < 0; ++r)
        if (pnmt[16 * r + 10] | pnmt[16 * r + 11])
            used = 16 * (long)r + 10;
    assert_true(used >= 0);
    static const uint16_t materials[] = { 0x7e00 /* NaN */, 0x5bff /* 255.9: no such material */,
                                          0xfc00 /* -inf */ };
    for (size_t k = 0; k < sizeof materials / sizeof materials[0]; ++k) {
        unsigned char *copy = malloc((size_t)len);
        assert_non_null(copy);
        memcpy(copy, buf, (size_t)len);
        memcpy(copy + (pnmt - buf) + used, &materials[k], 2);
        uint64_t sum = rl_ls_file_hash(0, copy, (size_t)len - 8);
        memcpy(copy + len - 8, &sum, 8);
        FILE *g = fopen(bad, "wb");
        assert_non_null(g);
        assert_int_equal(fwrite(copy, 1, (size_t)len, g), (size_t)len);
        fclose(g);
        free(copy);
        rl_linespace *loaded = NULL;
        assert_int_equal(rl_linespace_load(grid, bad, &loaded), RL_ERR_PARSE);
        assert_null(loaded);
        rl_clear_error();
    }
    /* The same file unedited but re-sealed still loads: the checksum is right. */
    uint64_t sum = rl_ls_file_hash(0, buf, (size_t)len - 8);
    memcpy(buf + len - 8, &sum, 8);
    FILE *g = fopen(bad, "wb");
    assert_non_null(g);
    assert_int_equal(fwrite(buf, 1, (size_t)len, g), (size_t)len);
    fclose(g);
    rl_linespace *loaded = NULL;
    assert_int_equal(rl_linespace_load(grid, bad, &loaded), RL_OK);
    rl_linespace_release(loaded);
    free(buf);
    rl_accel_release(grid);
    rl_scene_release(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_linespace_dynamic_round_trip_is_bit_identical_and_bad_files_are_refused),
        cmocka_unit_test(test_linespace_fixed_round_trip_is_bit_identical_and_bad_files_are_refused),
        cmocka_unit_test(test_linespace_pnmt_record_with_a_bad_material_is_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
