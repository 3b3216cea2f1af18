/* test_alloc.c: the grow-by-doubling helpers shared by the rasterizer, the
 * octree, CHC++, surfels and Vertex Tracing (rl_reserve, rl_reserve_u32,
 * rl_grow_capacity), and rl_big_alloc for the Line Space's arrays. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include "core/bigalloc.h"
#include "core/error.h"

static void test_reserve_doubles_from_first_and_keeps_contents(void **state)
{
    (void)state;
    int *a = NULL;
    size_t cap = 0;
    assert_true(rl_reserve((void **)&a, &cap, 0, sizeof *a, 8));
    assert_null(a);                         /* nothing needed, nothing allocated */
    assert_true(rl_reserve((void **)&a, &cap, 3, sizeof *a, 8));
    assert_int_equal(cap, 8);
    for (int i = 0; i < 8; ++i)
        a[i] = i * i;
    assert_true(rl_reserve((void **)&a, &cap, 8, sizeof *a, 8));
    assert_int_equal(cap, 8);               /* enough already */
    assert_true(rl_reserve((void **)&a, &cap, 9, sizeof *a, 8));
    assert_int_equal(cap, 16);
    assert_true(rl_reserve((void **)&a, &cap, 100, sizeof *a, 8));
    assert_int_equal(cap, 128);
    for (int i = 0; i < 8; ++i)
        assert_int_equal(a[i], i * i);
    free(a);
}

static void test_grow_capacity_is_what_reserve_allocates(void **state)
{
    (void)state;
    assert_int_equal(rl_grow_capacity(0, 0, 8), 0);
    assert_int_equal(rl_grow_capacity(0, 3, 8), 8);
    assert_int_equal(rl_grow_capacity(0, 3, 0), 4);     /* from 1 */
    assert_int_equal(rl_grow_capacity(8, 8, 8), 8);
    assert_int_equal(rl_grow_capacity(8, 9, 8), 16);
    assert_int_equal(rl_grow_capacity(8, 100, 8), 128);
    assert_int_equal(rl_grow_capacity(SIZE_MAX / 2 + 2, SIZE_MAX, 1), SIZE_MAX);
    for (size_t need = 1; need < 300; need += 7) {
        int *a = NULL;
        size_t cap = 5;
        size_t expect = rl_grow_capacity(cap, need, 4);
        cap = 0;
        assert_true(rl_reserve((void **)&a, &cap, 5, sizeof *a, 5));
        assert_true(rl_reserve((void **)&a, &cap, need, sizeof *a, 4));
        assert_int_equal(cap, expect);
        free(a);
    }
}

static void test_reserve_fails_cleanly_on_overflow(void **state)
{
    (void)state;
    double *a = NULL;
    size_t cap = 0;
    assert_true(rl_reserve((void **)&a, &cap, 4, sizeof *a, 4));
    double *before = a;
    rl_clear_error();
    assert_false(rl_reserve((void **)&a, &cap, SIZE_MAX / 2, sizeof *a, 4));
    assert_ptr_equal(a, before);            /* untouched on failure */
    assert_int_equal(cap, 4);
    assert_int_equal(rl_last_status(), RL_ERR_OUT_OF_MEMORY);
    free(a);

    uint32_t *b = NULL;
    uint32_t cap32 = 0;
    assert_true(rl_reserve_u32((void **)&b, &cap32, 5, sizeof *b, 4));
    assert_int_equal(cap32, 8);
    rl_clear_error();
    assert_false(rl_reserve_u32((void **)&b, &cap32, (uint64_t)UINT32_MAX + 1, sizeof *b, 4));
    assert_int_equal(cap32, 8);
    assert_int_equal(rl_last_status(), RL_ERR_OUT_OF_MEMORY);
    free(b);
}

static void test_big_alloc_aligns_large_huge_arrays_and_works_with_realloc_and_free(void **state)
{
    (void)state;
    /* Small or plain: malloc, any alignment, usable. */
    unsigned char *small = rl_big_alloc(100, true), *plain = rl_big_alloc(RL_BIG_ALLOC_MIN, false);
    assert_non_null(small);
    assert_non_null(plain);
    memset(small, 1, 100);
    memset(plain, 2, RL_BIG_ALLOC_MIN);
    free(small);
    free(plain);
    /* Large with huge pages: 2 MiB-aligned on Linux, every byte usable
     * (the size is not a multiple of 2 MiB), and realloc keeps the data
     * when the Line Space shrinks an array to its occupied shafts. */
    size_t n = RL_BIG_ALLOC_MIN + 12345;
    uint32_t *a = rl_big_alloc(n * sizeof *a, true);
    assert_non_null(a);
#if defined(__linux__)
    assert_int_equal((uintptr_t)a % ((uintptr_t)2 << 20), 0);
#endif
    for (size_t i = 0; i < n; ++i)
        a[i] = (uint32_t)(i * 2654435761u);
    uint32_t *b = realloc(a, 1000 * sizeof *b);
    assert_non_null(b);
    for (size_t i = 0; i < 1000; ++i)
        assert_int_equal(b[i], (uint32_t)(i * 2654435761u));
    free(b);
    /* A size that overflows when rounded to whole huge pages. */
    assert_null(rl_big_alloc(SIZE_MAX - 5, true));
}

static void test_big_array_zero_fills_and_reports_overflow(void **state)
{
    (void)state;
    size_t n = RL_BIG_ALLOC_MIN / sizeof(uint64_t) + 3;
    uint64_t *a = rl_big_array(n, sizeof *a, true);
    assert_non_null(a);
    for (size_t i = 0; i < n; ++i)
        assert_true(a[i] == 0);
    free(a);
    uint8_t *b = rl_big_array(10, 1, false);    /* small: plain malloc */
    assert_non_null(b);
    free(b);
    rl_clear_error();
    assert_null(rl_big_array(SIZE_MAX / 2, 4, false));
    assert_int_equal(rl_last_status(), RL_ERR_OUT_OF_MEMORY);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reserve_doubles_from_first_and_keeps_contents),
        cmocka_unit_test(test_grow_capacity_is_what_reserve_allocates),
        cmocka_unit_test(test_reserve_fails_cleanly_on_overflow),
        cmocka_unit_test(test_big_alloc_aligns_large_huge_arrays_and_works_with_realloc_and_free),
        cmocka_unit_test(test_big_array_zero_fills_and_reports_overflow),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
