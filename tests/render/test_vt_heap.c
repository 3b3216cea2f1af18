/* test_vt_heap.c: the edge list of Vertex Tracing (vt_heap.c; Ullmann 2003,
 * Sec. 3.3, Fig. 3.4): longest first, equal lengths by smaller edge index,
 * checked against a sorted reference under random interleaved pushes and
 * pops. */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "render/vt_internal.h"

static void test_empty_heap(void **state)
{
    (void)state;
    vt_heap h = { 0 };
    uint32_t e = 7;
    float len = 3.0f;
    assert_false(vt_heap_pop(&h, &e, &len));
    assert_int_equal(e, 7);
    assert_true(vt_heap_top(&h) == -INFINITY);
    vt_heap_free(&h);
    vt_heap_free(&h);
}

static void test_longest_first_ties_by_index(void **state)
{
    (void)state;
    vt_heap h = { 0 };
    const uint32_t edges[] = { 9, 3, 5, 1, 8, 2, 7 };
    const float lens[] = { 2.0f, 5.0f, 2.0f, 2.0f, 5.0f, 0.5f, 2.0f };
    for (size_t i = 0; i < 7; ++i)
        assert_int_equal(vt_heap_push(&h, edges[i], lens[i]), RL_OK);
    assert_int_equal(h.count, 7);
    assert_float_equal(vt_heap_top(&h), 5.0f, 0.0f);
    const uint32_t want_e[] = { 3, 8, 1, 5, 7, 9, 2 };
    const float want_l[] = { 5.0f, 5.0f, 2.0f, 2.0f, 2.0f, 2.0f, 0.5f };
    for (size_t i = 0; i < 7; ++i) {
        uint32_t e;
        float len;
        assert_true(vt_heap_pop(&h, &e, &len));
        assert_int_equal(e, want_e[i]);
        assert_float_equal(len, want_l[i], 0.0f);
    }
    assert_false(vt_heap_pop(&h, NULL, NULL));
    assert_int_equal(vt_heap_push(&h, 4, 1.0f), RL_OK);
    vt_heap_clear(&h);
    assert_int_equal(h.count, 0);
    assert_true(vt_heap_top(&h) == -INFINITY);
    /* the same edge twice is two entries; a NaN length sorts last */
    assert_int_equal(vt_heap_push(&h, 4, 1.0f), RL_OK);
    assert_int_equal(vt_heap_push(&h, 6, NAN), RL_OK);
    assert_int_equal(vt_heap_push(&h, 4, 1.0f), RL_OK);
    uint32_t e;
    assert_true(vt_heap_pop(&h, &e, NULL) && e == 4);
    assert_true(vt_heap_pop(&h, &e, NULL) && e == 4);
    assert_true(vt_heap_pop(&h, &e, NULL) && e == 6);
    vt_heap_free(&h);
    assert_null(h.items);
    assert_int_equal(h.cap, 0);
}

typedef struct entry { float len; uint32_t edge; } entry;

/* Pop order: longer first, then the smaller edge index. */
static int cmp_entry(const void *pa, const void *pb)
{
    const entry *a = pa, *b = pb;
    if (a->len != b->len)
        return a->len > b->len ? -1 : 1;
    return (a->edge > b->edge) - (a->edge < b->edge);
}

static uint64_t rng_next(uint64_t *s)
{
    *s ^= *s << 13;
    *s ^= *s >> 7;
    *s ^= *s << 17;
    return *s;
}

static void test_agrees_with_sorted_reference(void **state)
{
    (void)state;
    enum { N = 10000 };
    entry *ref = malloc(sizeof *ref * N);
    assert_non_null(ref);
    size_t nref = 0;
    vt_heap h = { 0 };
    uint64_t seed = 0x9e3779b97f4a7c15ull;
    for (int step = 0; step < 3 * N; ++step) {
        bool push = nref == 0 || (nref < N && rng_next(&seed) % 3 != 0);
        if (push) {
            /* few distinct lengths and edges: many exact ties and duplicates */
            entry en = { (float)(rng_next(&seed) % 50) * 0.25f,
                         (uint32_t)(rng_next(&seed) % 2000) };
            assert_int_equal(vt_heap_push(&h, en.edge, en.len), RL_OK);
            ref[nref++] = en;
            continue;
        }
        size_t best = 0;
        for (size_t i = 1; i < nref; ++i)
            if (cmp_entry(&ref[i], &ref[best]) < 0)
                best = i;
        uint32_t e;
        float len;
        assert_float_equal(vt_heap_top(&h), ref[best].len, 0.0f);
        assert_true(vt_heap_pop(&h, &e, &len));
        assert_int_equal(e, ref[best].edge);
        assert_float_equal(len, ref[best].len, 0.0f);
        ref[best] = ref[--nref];
        assert_int_equal(h.count, nref);
    }
    qsort(ref, nref, sizeof *ref, cmp_entry);
    for (size_t i = 0; i < nref; ++i) {
        uint32_t e;
        float len;
        assert_true(vt_heap_pop(&h, &e, &len));
        assert_int_equal(e, ref[i].edge);
        assert_float_equal(len, ref[i].len, 0.0f);
    }
    assert_false(vt_heap_pop(&h, NULL, NULL));
    vt_heap_free(&h);
    free(ref);
}

/* vt_heap_shrink gives back the room of a list that emptied (the
 * refinement calls it after each stage's pops) and keeps its items and
 * their pop order; a list still more than half full, or one whose spare
 * room is small, keeps its room. */
static void test_shrink_keeps_the_order(void **state)
{
    (void)state;
    enum { N = 200000, KEEP = 3000 };
    vt_heap h = { 0 }, ref = { 0 };
    uint64_t seed = 0x2545f4914f6cdd1dull;
    for (int i = 0; i < N; ++i) {
        float len = (float)(rng_next(&seed) % 4096) * 0.125f;
        uint32_t edge = (uint32_t)(rng_next(&seed) % 50000);
        assert_int_equal(vt_heap_push(&h, edge, len), RL_OK);
        assert_int_equal(vt_heap_push(&ref, edge, len), RL_OK);
    }
    uint32_t full = h.cap;
    assert_true(full >= N);
    vt_heap_shrink(&h);               /* full: nothing to give back */
    assert_int_equal(h.cap, full);
    for (int i = 0; i < N - KEEP; ++i) {
        uint32_t a, b;
        assert_true(vt_heap_pop(&h, &a, NULL) && vt_heap_pop(&ref, &b, NULL));
        assert_int_equal(a, b);
    }
    vt_heap_shrink(&h);
    /* the smallest 1024 * 2^k at least twice the items */
    assert_int_equal(h.cap, 8192);
    assert_int_equal(h.count, KEEP);
    vt_heap_shrink(&h);               /* already small */
    assert_int_equal(h.cap, 8192);
    /* it grows again from there */
    for (int i = 0; i < 20000; ++i) {
        float len = (float)(rng_next(&seed) % 4096) * 0.125f;
        uint32_t edge = (uint32_t)(rng_next(&seed) % 50000);
        assert_int_equal(vt_heap_push(&h, edge, len), RL_OK);
        assert_int_equal(vt_heap_push(&ref, edge, len), RL_OK);
    }
    uint32_t a, b;
    float la, lb;
    while (vt_heap_pop(&ref, &b, &lb)) {
        assert_true(vt_heap_pop(&h, &a, &la));
        assert_int_equal(a, b);
        assert_float_equal(la, lb, 0.0f);
    }
    assert_false(vt_heap_pop(&h, NULL, NULL));
    vt_heap_shrink(&h);               /* empty: back to the first room */
    assert_int_equal(h.cap, 1024);
    vt_heap_free(&h);
    vt_heap_free(&ref);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_empty_heap),
        cmocka_unit_test(test_longest_first_ties_by_index),
        cmocka_unit_test(test_agrees_with_sorted_reference),
        cmocka_unit_test(test_shrink_keeps_the_order),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
