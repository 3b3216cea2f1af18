/* test_timer.c: monotonic timing and the progress reporter's behaviour on a
 * non-terminal stream (quiet within its delay, one line per 25% at most). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "rl/rl_timer.h"

static void test_timer_is_monotonic_and_in_milliseconds(void **state)
{
    (void)state;
    rl_timer t;
    rl_timer_start(&t);
    double a = rl_time_s(), prev = a;
    for (int i = 0; i < 100000; ++i) {
        double now = rl_time_s();
        assert_true(now >= prev);
        prev = now;
    }
    double ms = rl_timer_ms(&t);
    assert_true(ms >= 0 && ms < 10000);
    assert_true(ms >= 1e3 * (prev - a) * 0.999);
}

/* Reads everything written to f so far. */
static size_t slurp(FILE *f, char *buf, size_t n)
{
    fflush(f);
    rewind(f);
    size_t got = fread(buf, 1, n - 1, f);
    buf[got] = '\0';
    return got;
}

static void test_progress_is_silent_within_its_delay(void **state)
{
    (void)state;
    FILE *f = tmpfile();
    assert_non_null(f);
    rl_progress *p = NULL;
    assert_int_equal(rl_progress_create("quick", f, &p), RL_OK);
    for (int i = 0; i <= 100; ++i)
        assert_true(rl_progress_update(p, i / 100.0));
    rl_progress_finish(p);
    char buf[256];
    assert_int_equal(slurp(f, buf, sizeof buf), 0);
    fclose(f);
    rl_progress_finish(NULL);
}

static void test_progress_on_a_pipe_prints_at_most_one_line_per_quarter(void **state)
{
    (void)state;
    FILE *f = tmpfile();
    assert_non_null(f);
    rl_progress *p = NULL;
    assert_int_equal(rl_progress_create("render cornell", f, &p), RL_OK);
    rl_progress_set_delay(p, 0.0);
    /* Updates from many threads at once, out of order, must stay well formed. */
    #pragma omp parallel for
    for (int i = 0; i <= 2000; ++i)
        rl_progress_update(p, i / 2000.0);
    rl_progress_update(p, 1.0);
    rl_progress_finish(p);
    char buf[4096];
    slurp(f, buf, sizeof buf);
    int lines = 0;
    for (char *c = buf; *c; ++c)
        lines += *c == '\n';
    assert_true(lines >= 1 && lines <= 5);
    assert_non_null(strstr(buf, "render cornell: 100%\n"));
    assert_null(strchr(buf, '\r'));  /* no terminal control on a pipe */
    fclose(f);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_timer_is_monotonic_and_in_milliseconds),
        cmocka_unit_test(test_progress_is_silent_within_its_delay),
        cmocka_unit_test(test_progress_on_a_pipe_prints_at_most_one_line_per_quarter),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
