/* test_output.c: outputs through a temporary and a rename (rl_output.h):
 * the target changes only on commit, failures and aborts leave it and no
 * temporary behind, modes and links are kept, a batch commits all or none,
 * and the image writers (PNG, EXR) keep the old file when a write fails. */
#define _DEFAULT_SOURCE
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <dirent.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rl/rl_image.h"
#include "rl/rl_output.h"

/* A fresh folder per test, so that counting its hidden files counts
 * temporaries left behind. */
static const char *fresh_dir(const char *name)
{
    static char dir[1024];
    const char *base = getenv("RL_TEST_TMP");
    snprintf(dir, sizeof dir, "%s/test_output_%s", base && *base ? base : "/tmp", name);
    char cmd[1100];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
    assert_int_equal(mkdir(dir, 0777), 0);
    return dir;
}

static const char *in_dir(const char *dir, const char *name)
{
    static char buf[4][1200];
    static int next;
    char *p = buf[next++ % 4];
    snprintf(p, sizeof buf[0], "%s/%s", dir, name);
    return p;
}

static int hidden_files(const char *dir)
{
    DIR *d = opendir(dir);
    assert_non_null(d);
    int n = 0;
    for (struct dirent *e; (e = readdir(d));)
        n += e->d_name[0] == '.' && strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0;
    closedir(d);
    return n;
}

static void put_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

static const char *get_text(const char *path)
{
    static char buf[256];
    buf[0] = '\0';
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

static void test_target_changes_only_on_commit(void **state)
{
    (void)state;
    const char *dir = fresh_dir("commit");
    const char *path = in_dir(dir, "a.json");
    put_text(path, "old");
    rl_output *o = NULL;
    assert_int_equal(rl_output_open(path, &o), RL_OK);
    fputs("new", rl_output_file(o));
    fflush(rl_output_file(o));
    assert_string_equal(get_text(path), "old");
    assert_string_equal(get_text(rl_output_temp_path(o)), "new");
    /* The temporary is hidden, beside the target, with its extension. */
    const char *tmp = strrchr(rl_output_temp_path(o), '/') + 1;
    assert_true(strncmp(tmp, ".a.json.", 8) == 0 && strlen(tmp) == strlen(".a.json.XXXXXX.json"));
    assert_int_equal(hidden_files(dir), 1);
    assert_int_equal(rl_output_commit(o), RL_OK);
    assert_string_equal(get_text(path), "new");
    assert_int_equal(hidden_files(dir), 0);
}

static void test_abort_keeps_the_old_file_and_no_temporary(void **state)
{
    (void)state;
    const char *dir = fresh_dir("abort");
    const char *path = in_dir(dir, "a.txt");
    put_text(path, "old");
    rl_output *o = NULL;
    assert_int_equal(rl_output_open(path, &o), RL_OK);
    fputs("half", rl_output_file(o));
    rl_output_abort(o);
    rl_output_abort(NULL);
    assert_string_equal(get_text(path), "old");
    assert_int_equal(hidden_files(dir), 0);
}

static void test_a_new_file_follows_the_umask_and_a_replaced_one_keeps_its_mode(void **state)
{
    (void)state;
    const char *dir = fresh_dir("mode");
    mode_t old_mask = umask(022);
    rl_output *o = NULL;
    assert_int_equal(rl_output_open(in_dir(dir, "new.txt"), &o), RL_OK);
    assert_int_equal(rl_output_commit(o), RL_OK);
    struct stat s;
    assert_int_equal(stat(in_dir(dir, "new.txt"), &s), 0);
    assert_int_equal(s.st_mode & 0777, 0644);
    put_text(in_dir(dir, "kept.txt"), "old");
    assert_int_equal(chmod(in_dir(dir, "kept.txt"), 0640), 0);
    assert_int_equal(rl_output_open(in_dir(dir, "kept.txt"), &o), RL_OK);
    assert_int_equal(rl_output_commit(o), RL_OK);
    assert_int_equal(stat(in_dir(dir, "kept.txt"), &s), 0);
    assert_int_equal(s.st_mode & 0777, 0640);
    umask(old_mask);
}

static void test_a_link_is_followed_not_replaced(void **state)
{
    (void)state;
    const char *dir = fresh_dir("link");
    put_text(in_dir(dir, "real.txt"), "old");
    assert_int_equal(symlink("real.txt", in_dir(dir, "link.txt")), 0);
    rl_output *o = NULL;
    assert_int_equal(rl_output_open(in_dir(dir, "link.txt"), &o), RL_OK);
    fputs("new", rl_output_file(o));
    assert_int_equal(rl_output_commit(o), RL_OK);
    struct stat s;
    assert_int_equal(lstat(in_dir(dir, "link.txt"), &s), 0);
    assert_true(S_ISLNK(s.st_mode));
    assert_string_equal(get_text(in_dir(dir, "real.txt")), "new");
}

static void test_a_device_is_written_directly(void **state)
{
    (void)state;
    rl_output *o = NULL;
    assert_int_equal(rl_output_open("/dev/null", &o), RL_OK);
    assert_string_equal(rl_output_temp_path(o), "/dev/null");
    fputs("gone", rl_output_file(o));
    assert_int_equal(rl_output_commit(o), RL_OK);
    struct stat s;
    assert_int_equal(stat("/dev/null", &s), 0);
    assert_true(S_ISCHR(s.st_mode));
}

static void test_a_folder_or_a_missing_folder_is_an_io_error(void **state)
{
    (void)state;
    const char *dir = fresh_dir("folder");
    rl_output *o = (rl_output *)&o;
    assert_int_equal(rl_output_open(dir, &o), RL_ERR_IO);
    assert_null(o);
    rl_clear_error();
    assert_int_equal(rl_output_open(in_dir(dir, "no/such/a.png"), &o), RL_ERR_IO);
    assert_non_null(strstr(rl_last_error(), "no/such/a.png"));
    rl_clear_error();
    assert_int_equal(rl_output_open(NULL, &o), RL_ERR_INVALID_ARG);
    rl_clear_error();
    assert_int_equal(hidden_files(dir), 0);
}

/* In a child process with a 16 KiB file size limit (SIGXFSZ ignored, so
 * the write fails with EFBIG instead of killing it): writes a file too big
 * for the limit over a good one, through each writer, and checks that the
 * writer fails and leaves the good file and no temporary. */
static void write_past_the_limit(const char *dir, int how)
{
    const char *path = in_dir(dir, how == 0 ? "big.txt" : how == 1 ? "big.png" : "big.exr");
    put_text(path, "good");
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        signal(SIGXFSZ, SIG_IGN);
        struct rlimit lim = { 16384, 16384 };
        if (setrlimit(RLIMIT_FSIZE, &lim) != 0)
            _exit(10);
        rl_status st = RL_OK;
        if (how == 0) {
            rl_output *o = NULL;
            if (rl_output_open(path, &o) != RL_OK)
                _exit(11);
            for (int i = 0; i < 100000; ++i)
                fputs("0123456789", rl_output_file(o));
            st = rl_output_commit(o);
        } else {
            /* Noise: incompressible, so the file outgrows the limit. */
            rl_image *img = NULL;
            if (rl_image_create(256, 256, RL_LAYER_COLOR, &img) != RL_OK)
                _exit(12);
            uint32_t x = 12345;
            for (int i = 0; i < 256 * 256; ++i) {
                x = x * 1664525u + 1013904223u;
                float v = (float)(x >> 8) / 16777216.0f;
                img->color[i] = rl_v4(v, 1.0f - v, v * v, 1.0f);
            }
            st = rl_image_write(img, path);
            rl_image_release(img);
        }
        _exit(st == RL_ERR_IO ? 0 : 20 + (int)st);
    }
    int status = 0;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    assert_true(WIFEXITED(status));
    assert_int_equal(WEXITSTATUS(status), 0);
    assert_string_equal(get_text(path), "good");
    assert_int_equal(hidden_files(dir), 0);
}

static void test_a_write_past_the_size_limit_keeps_the_old_file(void **state)
{
    (void)state;
    const char *dir = fresh_dir("limit");
    write_past_the_limit(dir, 0);
    write_past_the_limit(dir, 1);
    write_past_the_limit(dir, 2);
}

static void test_a_batch_commits_all_or_nothing(void **state)
{
    (void)state;
    const char *dir = fresh_dir("batch");
    const char *a = in_dir(dir, "a.txt"), *b = in_dir(dir, "b.json");
    put_text(a, "old a");
    put_text(b, "old b");
    rl_output_batch *batch = NULL;
    const char *ta = NULL, *tb = NULL;
    assert_int_equal(rl_output_batch_create(&batch), RL_OK);
    assert_int_equal(rl_output_batch_add(batch, a, &ta), RL_OK);
    put_text(ta, "new a");
    assert_int_equal(rl_output_batch_add(batch, b, &tb), RL_OK);
    assert_true(strlen(tb) > 5 && strcmp(tb + strlen(tb) - 5, ".json") == 0);
    assert_int_equal(hidden_files(dir), 2);
    /* b's writer failed: nothing is committed. */
    rl_output_batch_release(batch);
    assert_string_equal(get_text(a), "old a");
    assert_string_equal(get_text(b), "old b");
    assert_int_equal(hidden_files(dir), 0);

    assert_int_equal(rl_output_batch_create(&batch), RL_OK);
    assert_int_equal(rl_output_batch_add(batch, a, &ta), RL_OK);
    assert_int_equal(rl_output_batch_add(batch, b, &tb), RL_OK);
    put_text(ta, "new a");
    put_text(tb, "new b");
    assert_string_equal(get_text(a), "old a");
    assert_int_equal(rl_output_batch_commit(batch), RL_OK);
    assert_string_equal(get_text(a), "new a");
    assert_string_equal(get_text(b), "new b");
    assert_int_equal(rl_output_batch_add(batch, in_dir(dir, "c.txt"), &ta), RL_ERR_INVALID_ARG);
    rl_clear_error();
    rl_output_batch_release(batch);
    rl_output_batch_release(NULL);
    assert_int_equal(hidden_files(dir), 0);
}

static void test_a_batch_refuses_a_folder_before_anything_is_written(void **state)
{
    (void)state;
    const char *dir = fresh_dir("batch_folder");
    rl_output_batch *batch = NULL;
    const char *t = NULL;
    assert_int_equal(rl_output_batch_create(&batch), RL_OK);
    assert_int_equal(rl_output_batch_add(batch, dir, &t), RL_ERR_IO);
    assert_null(t);
    rl_clear_error();
    rl_output_batch_release(batch);
}

/* Through a batch, the image writers replace the batch's temporary with
 * their own; the commit then puts the image in place. */
static void test_an_image_written_through_a_batch_lands_on_commit(void **state)
{
    (void)state;
    const char *dir = fresh_dir("batch_image");
    const char *path = in_dir(dir, "out.png");
    rl_image *img = NULL;
    assert_int_equal(rl_image_create(4, 3, RL_LAYER_COLOR, &img), RL_OK);
    rl_image_fill(img, rl_v4(0.5f, 0.25f, 1.0f, 1.0f));
    rl_output_batch *batch = NULL;
    const char *t = NULL;
    assert_int_equal(rl_output_batch_create(&batch), RL_OK);
    assert_int_equal(rl_output_batch_add(batch, path, &t), RL_OK);
    assert_int_equal(rl_image_write(img, t), RL_OK);
    assert_int_equal(access(path, F_OK), -1);
    assert_int_equal(rl_output_batch_commit(batch), RL_OK);
    rl_output_batch_release(batch);
    rl_image *back = NULL;
    assert_int_equal(rl_image_read(path, &back), RL_OK);
    assert_int_equal(back->width, 4);
    assert_int_equal(hidden_files(dir), 0);
    rl_image_release(back);
    rl_image_release(img);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_target_changes_only_on_commit),
        cmocka_unit_test(test_abort_keeps_the_old_file_and_no_temporary),
        cmocka_unit_test(test_a_new_file_follows_the_umask_and_a_replaced_one_keeps_its_mode),
        cmocka_unit_test(test_a_link_is_followed_not_replaced),
        cmocka_unit_test(test_a_device_is_written_directly),
        cmocka_unit_test(test_a_folder_or_a_missing_folder_is_an_io_error),
        cmocka_unit_test(test_a_write_past_the_size_limit_keeps_the_old_file),
        cmocka_unit_test(test_a_batch_commits_all_or_nothing),
        cmocka_unit_test(test_a_batch_refuses_a_folder_before_anything_is_written),
        cmocka_unit_test(test_an_image_written_through_a_batch_lands_on_commit),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
