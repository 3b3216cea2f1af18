/* test_corpus.c: every model of Debian's assimp-testmodels, rendered as a new
 * user would render it, `rl render FILE --algo raster`, in a child process with a time limit.
 * rl imports each file the default way, with Assimp isolated in a child of
 * its own (load_isolate.c), so a crash or hang of Assimp shows up as exit 1
 * ("noload") and a crash of rl itself stays a failure of ours.
 *
 * The file's cameras are left out (`FILE:cameras=off`): the check is of our
 * default framing, the tight fit from the default orbit. The file's lights
 * stay in. A model that loads must give an image that is
 *   - not mostly background: the object-ID layer covers >= 8 % of the pixels,
 *   - framed: the covered pixels span >= 60 % of the width or the height,
 *   - lit and not flat: the covered pixels are not all black, and their
 *     luminance varies (shading, texture or several materials).
 * Files that fail to load, or fail a check for a reason that is the file's
 * (an empty scene, a point cloud, a malformed file kept as Assimp's own
 * regression input), are listed with the reason in corpus_expected.tsv. Any
 * other outcome fails the test, and so does a listed file that now passes, so
 * that the list and the counts in docs/scene-format.md stay true.
 *
 * RL_CORPUS_DIR overrides the corpus folder; RL_CORPUS_ONLY=substring runs the
 * files whose path contains it; RL_CORPUS_STRIDE=N runs every N-th file of the
 * sorted list (the sanitizer build runs a third: there a render costs three
 * times the CPU, almost all of it process start-up and Assimp, which is not
 * instrumented, and the Release build renders every file). The per-format
 * table is printed at the end. */
#define _XOPEN_SOURCE 700
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <ctype.h>
#include <errno.h>
#include <fcntl.h>
#include <ftw.h>
#include <math.h>
#include <spawn.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "rl/rl_image.h"

extern char **environ;

#define CORPUS_DEFAULT "/usr/share/assimp/models"
#define MAX_FILES 2048
#define TIME_LIMIT "60"

/* What the corpus holds beside models: images, buffers, text, shaders. */
static const char *const skip_ext[] = {
    "png", "jpg", "jpeg", "tga", "bmp", "gif", "dds", "txt", "bin", "mtl", "glsl",
    "md", "pdf", "skin", "shader", "xml", "html", "mat", "h", "vert", "frag", "material",
    "license", "readme", "uc",
};
/* Folders that hold no models to render: deliberately broken files
 * (the fuzz corpus has them), reference pictures and sources. */
static const char *const skip_dir[] = {
    "/invalid/", "/ReferenceImages/", "/SourceFiles/", "/ParsingFiles/",
};

static char *files[MAX_FILES];
static size_t num_files;
static size_t root_len;

static const char *ext_of(const char *path)
{
    const char *base = strrchr(path, '/') ? strrchr(path, '/') + 1 : path;
    const char *dot = strrchr(base, '.');
    return dot ? dot + 1 : base;   /* "README", "LICENSE": the name itself */
}

static bool ieq(const char *a, const char *b)
{
    for (; *a && *b; ++a, ++b)
        if (tolower((unsigned char)*a) != tolower((unsigned char)*b))
            return false;
    return *a == *b;
}

static int collect(const char *path, const struct stat *sb, int type, struct FTW *ftw)
{
    (void)sb;
    (void)ftw;
    if (type != FTW_F)
        return 0;
    for (size_t i = 0; i < sizeof skip_dir / sizeof skip_dir[0]; ++i)
        if (strstr(path, skip_dir[i]))
            return 0;
    const char *ext = ext_of(path);
    for (size_t i = 0; i < sizeof skip_ext / sizeof skip_ext[0]; ++i)
        if (ieq(ext, skip_ext[i]))
            return 0;
    const char *only = getenv("RL_CORPUS_ONLY");
    if (only && only[0] && !strstr(path, only))
        return 0;
    if (num_files < MAX_FILES)
        files[num_files++] = strdup(path);
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Runs argv, returns its exit status, or 128 + signal. */
static int run(char *const argv[], const char *log)
{
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 1, log, O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&fa, 1, 2);
    pid_t pid;
    int err = posix_spawnp(&pid, argv[0], &fa, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&fa);
    if (err != 0)
        return -1;
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

typedef enum outcome { OK, NOLOAD, TIMEOUT, CRASH, BACKGROUND, LOOSE, DARK, FLAT, N_OUTCOMES } outcome;
static const char *const outcome_name[N_OUTCOMES] = {
    "ok", "noload", "timeout", "crash", "background", "loose", "dark", "flat",
};

static float luminance(rl_vec4 c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

/* The checks of the header on the colour image and the ID picture (PNG,
 * background black). */
static outcome judge(const char *color_png, const char *id_png, char *why, size_t why_size)
{
    rl_image *col = NULL, *ids = NULL;
    if (rl_image_read(color_png, &col) != RL_OK || rl_image_read(id_png, &ids) != RL_OK ||
        col->width != ids->width || col->height != ids->height) {
        rl_image_release(col);
        rl_image_release(ids);
        snprintf(why, why_size, "unreadable output");
        return CRASH;
    }
    int w = col->width, h = col->height;
    size_t covered = 0;
    int x0 = w, x1 = -1, y0 = h, y1 = -1;
    double lmin = INFINITY, lmax = -INFINITY, lsum = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            rl_vec4 id = ids->color[(size_t)y * w + x];
            if (id.x + id.y + id.z <= 0.0f)
                continue;
            ++covered;
            x0 = x < x0 ? x : x0;
            x1 = x > x1 ? x : x1;
            y0 = y < y0 ? y : y0;
            y1 = y > y1 ? y : y1;
            double l = luminance(col->color[(size_t)y * w + x]);
            lmin = l < lmin ? l : lmin;
            lmax = l > lmax ? l : lmax;
            lsum += l;
        }
    rl_image_release(col);
    rl_image_release(ids);
    double cover = (double)covered / ((double)w * h);
    double span = covered ? fmax((x1 - x0 + 1.0) / w, (y1 - y0 + 1.0) / h) : 0.0;
    double mean = covered ? lsum / (double)covered : 0.0;
    snprintf(why, why_size, "cover %.1f%%, span %.0f%%, luminance %.3f..%.3f mean %.3f",
             100.0 * cover, 100.0 * span, covered ? lmin : 0.0, covered ? lmax : 0.0, mean);
    if (cover < 0.08)
        return BACKGROUND;
    if (span < 0.6)
        return LOOSE;
    if (mean < 0.01)
        return DARK;
    if (lmax - lmin < 0.02)
        return FLAT;
    return OK;
}

/* corpus_expected.tsv: "relative/path<TAB>outcome<TAB>reason" per line. */
typedef struct expected {
    char path[512];
    outcome want;
    bool seen;
} expected;
static expected expect[512];
static size_t num_expect;

static void read_expected(void)
{
    char path[1024];
    snprintf(path, sizeof path, "%s/scene/corpus_expected.tsv", RL_TEST_SOURCE_DIR);
    FILE *f = fopen(path, "r");
    assert_non_null(f);
    char line[1024];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || line[0] == '\n')
            continue;
        char *tab1 = strchr(line, '\t');
        char *tab2 = tab1 ? strchr(tab1 + 1, '\t') : NULL;
        assert_non_null(tab2);
        *tab1 = *tab2 = '\0';
        assert_true(num_expect < sizeof expect / sizeof expect[0]);
        expected *e = &expect[num_expect++];
        snprintf(e->path, sizeof e->path, "%.511s", line);
        e->want = N_OUTCOMES;
        for (int o = 0; o < N_OUTCOMES; ++o)
            if (strcmp(tab1 + 1, outcome_name[o]) == 0)
                e->want = (outcome)o;
        if (e->want == N_OUTCOMES || e->want == OK)
            fail_msg("corpus_expected.tsv: %s: unknown outcome \"%s\"", line, tab1 + 1);
    }
    fclose(f);
}

static expected *find_expected(const char *rel)
{
    for (size_t i = 0; i < num_expect; ++i)
        if (strcmp(expect[i].path, rel) == 0)
            return &expect[i];
    return NULL;
}

/* Per format (lower-case extension): files, loaded, passed. */
typedef struct format_count {
    char ext[16];
    int files, loaded, passed;
} format_count;

static void count(format_count *fc, size_t *n, const char *path, outcome o)
{
    char ext[16];
    snprintf(ext, sizeof ext, "%s", ext_of(path));
    for (char *c = ext; *c; ++c)
        *c = (char)tolower((unsigned char)*c);
    size_t i = 0;
    while (i < *n && strcmp(fc[i].ext, ext) != 0)
        ++i;
    if (i == *n) {
        memset(&fc[i], 0, sizeof fc[i]);
        snprintf(fc[i].ext, sizeof fc[i].ext, "%s", ext);
        ++*n;
    }
    fc[i].files++;
    fc[i].loaded += o != NOLOAD && o != TIMEOUT && o != CRASH;
    fc[i].passed += o == OK;
}

static int cmp_format(const void *a, const void *b)
{
    return strcmp(((const format_count *)a)->ext, ((const format_count *)b)->ext);
}

static void test_corpus(void **state)
{
    (void)state;
    const char *root = getenv("RL_CORPUS_DIR");
    if (!root || !root[0])
        root = CORPUS_DEFAULT;
    struct stat sb;
    if (stat(root, &sb) != 0) {
        /* make check installs assimp-testmodels; only a hand-made build
         * without it gets here. */
        print_message("corpus %s missing (Debian package assimp-testmodels)\n", root);
        skip();
    }
    const char *rl = getenv("RL_BIN");
    assert_non_null(rl);
    const char *tmp = getenv("RL_TEST_TMP");
    char dir[1024];
    snprintf(dir, sizeof dir, "%s/corpus", tmp && tmp[0] ? tmp : ".");
    mkdir(dir, 0777);
    read_expected();

    root_len = strlen(root);
    /* Some of Assimp's importers leak (AMF: 1148 bytes per file); in a
     * sanitizer build LeakSanitizer would turn that into exit 1, a "noload"
     * that is not one. The renders leave leak checks to the other tests,
     * which run our code on files we write (the stacks here are Assimp's,
     * unsymbolised, so no suppression can single them out). */
    setenv("ASAN_OPTIONS", "detect_leaks=0", 1);
    assert_int_equal(nftw(root, collect, 16, FTW_PHYS), 0);
    qsort(files, num_files, sizeof files[0], cmp_str);
    assert_true(num_files > 0);

    const char *stride_env = getenv("RL_CORPUS_STRIDE");
    const size_t stride = stride_env && atoi(stride_env) > 1 ? (size_t)atoi(stride_env) : 1;
    static format_count fc[128];
    size_t nfc = 0, tried = 0;
    int failures = 0, loaded = 0, passed = 0;
    for (size_t i = 0; i < num_files; ++i) {
        if (i % stride != 0)
            continue;
        ++tried;
        const char *rel = files[i] + root_len + (files[i][root_len] == '/');
        char png[1100], idp[1100], log[1100], why[256] = "";
        snprintf(png, sizeof png, "%s/%04zu.png", dir, i);
        snprintf(idp, sizeof idp, "%s/%04zu.id.png", dir, i);
        snprintf(log, sizeof log, "%s/%04zu.log", dir, i);
        /* The default framing of the model (the file's own cameras frame
         * what their authors chose, often an animation's start or nothing). */
        char source[1100];
        snprintf(source, sizeof source, "%s:cameras=off", files[i]);
        char *argv[] = { "timeout", "-s", "KILL", TIME_LIMIT, (char *)rl, "-q", "render", source,
                         "--algo", "raster", "--size", "160x120", "--out", png,
                         "--id-out", idp, NULL };
        int rc = run(argv, log);
        outcome o;
        if (rc == 0)
            o = judge(png, idp, why, sizeof why);
        else if (rc == 1) {
            o = NOLOAD;
            FILE *f = fopen(log, "r");
            if (f) {
                char line[256] = "";
                while (fgets(line, sizeof line, f))
                    if (strstr(line, "error"))
                        snprintf(why, sizeof why, "%s", line);
                fclose(f);
                why[strcspn(why, "\n")] = '\0';
            }
        } else if (rc == 137 || rc == 124) {
            o = TIMEOUT;
            snprintf(why, sizeof why, "over %s s", TIME_LIMIT);
        } else {
            o = CRASH;
            snprintf(why, sizeof why, "exit status %d", rc);
        }
        count(fc, &nfc, files[i], o);
        loaded += o != NOLOAD && o != TIMEOUT && o != CRASH;
        passed += o == OK;
        expected *e = find_expected(rel);
        if (e)
            e->seen = true;
        outcome want = e ? e->want : OK;
        if (o != want) {
            ++failures;
            print_message("FAIL %s: %s (expected %s) %s\n", rel, outcome_name[o],
                          outcome_name[want], why);
        } else if (getenv("RL_CORPUS_VERBOSE")) {
            print_message("     %s: %s %s\n", rel, outcome_name[o], why);
        }
    }
    for (size_t i = 0; i < num_expect; ++i)
        if (!expect[i].seen && !getenv("RL_CORPUS_ONLY") && stride == 1) {
            ++failures;
            print_message("FAIL corpus_expected.tsv lists %s, which the corpus lacks\n",
                          expect[i].path);
        }

    qsort(fc, nfc, sizeof fc[0], cmp_format);
    print_message("| format | files | load | pass |\n|---|---:|---:|---:|\n");
    for (size_t i = 0; i < nfc; ++i)
        print_message("| %s | %d | %d | %d |\n", fc[i].ext, fc[i].files, fc[i].loaded,
                      fc[i].passed);
    print_message("| all | %zu | %d | %d |\n", tried, loaded, passed);
    if (stride > 1)
        print_message("every %zu-th of %zu files (RL_CORPUS_STRIDE)\n", stride, num_files);
    for (size_t i = 0; i < num_files; ++i)
        free(files[i]);
    assert_int_equal(failures, 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_corpus),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
