/* bench_dist.c: `rl bench dist`: distributed runs (docs/distributed.md)
 * against their rank count. It starts this same rl under mpirun once per
 * rank count and workload, as a user would (`mpirun -np N rl --dist ...`),
 * and reads what the master records (--stats-json, eval.json: "dist"):
 *   tiles     rl --dist render of whitted and pt (--spp) on table and
 *             cluster: the frame's time on the master, speed-up and
 *             parallel efficiency against one rank, load imbalance (the
 *             busiest rank's busy time over the mean), messages and bytes
 *             per frame
 *   sampling  rl --dist eval on city (Jähn 2015, Alg. 5.4): the sampling's
 *             time, speed-up, efficiency, messages and bytes per sample
 * Every run is repeated and the fastest kept (the machine may be shared).
 * Rank counts above the machine's cores are marked oversubscribed: their
 * ranks take turns on the cores, so they measure the protocol, not a
 * speed-up. */
#define _XOPEN_SOURCE 700
#include "bench_args.h"
#include "bench_dist.h"
#include "bench_rays.h"
#include "bench_util.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <ftw.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#define note(...) (fflush(stdout), bench_note("dist", __VA_ARGS__))

static const char bench_dist_help[] =
    "usage: rl bench dist [options]\n"
    "\n"
    "Distributed runs against their rank count: starts this rl under mpirun\n"
    "(mpirun --oversubscribe -np N rl --dist ...) for every rank count and\n"
    "workload, keeps the fastest of --repeats runs, and records time, speed-up\n"
    "and parallel efficiency against one rank, load imbalance (busiest rank's\n"
    "busy time / mean) and messages and bytes per frame or sample. Sections:\n"
    "  tiles     rl --dist render: whitted and pt (--spp) on --scenes\n"
    "  sampling  rl --dist eval (Jaehn 2015, Alg. 5.4) on --eval-scene\n"
    "  vt        rl --dist render --algo vt (Ullmann 2003, Sec. 4.3, Fig. 5.14) on\n"
    "            --scenes, both load balancers (queue, precompute), and the SSIM\n"
    "            on the VT pixels against the one-rank image, without and with\n"
    "            the master's post-pass (--vt-postpass)\n"
    "Rank counts above the machine's cores are marked oversubscribed.\n"
    "\n"
    "options:\n"
    "  --ranks A,B,...    rank counts; default 1,2,3,4\n"
    "  --threads N        OpenMP threads per rank; default 1\n"
    "  --scenes A,B       tiles: scenes; default table,cluster\n"
    "  --size WxH         tiles: image size; default 640x480\n"
    "  --vt-size WxH      vt: image size; default 320x240\n"
    "  --vt-postpass L    vt: the option dist_postpass, each of off,on; default off,on\n"
    "  --vt-overlap S     vt: the option dist_overlap of the post-pass runs, 0..1; default 0\n"
    "  --spp N            tiles: pt's samples per pixel; default 4\n"
    "  --eval-scene S     sampling: scene; default city:blocks=2\n"
    "  --samples N        sampling: samples of the visibility property; default 64\n"
    "  --repeats N        runs per point, the fastest kept; default 2\n"
    "  --mpirun PATH      default mpirun\n"
    "  --only A,B         sections: tiles, sampling, vt\n"
    "  --out FILE.json    default bench/results/dist-YYYYMMDD-HHMMSS.json\n"
    "  --quick            tiny run: ranks 1,2, cornell at 96x64, 1 spp, 16 samples\n"
    "                     on city:blocks=1, one run each\n"
    "\n"
    "As root, Open MPI needs OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1\n"
    "(set for the runs when missing). Example, a 16-core node (bench/dist.sh):\n"
    "  rl bench dist --ranks 1,2,4,8,16 --size 1280x960\n";

enum { SEC_TILES, SEC_SAMPLING, SEC_VT, SEC_COUNT };
static const char *const section_names[SEC_COUNT] = { "tiles", "sampling", "vt" };

#define MAX_RANKS 16
#define MAX_RANK_COUNT 1024
/* A run that takes longer has hung: mpirun and its ranks are ended. */
#define CHILD_TIMEOUT_S 900.0

typedef struct bd_args {
    const char *scenes, *eval_scene, *mpirun, *out, *vt_postpass, *vt_overlap;
    int ranks[MAX_RANKS], num_ranks;
    long long threads, spp, samples, repeats;
    int width, height, vt_width, vt_height;
    unsigned sections;
    bool quick, has_ranks, has_size, has_vt_size, has_spp, has_samples, has_repeats;
} bd_args;

typedef struct bd_ctx {
    const bd_args *a;
    char self[4096];         /* this rl */
    char dir[256];           /* scratch for the runs' outputs */
    int cores;
    char reason[512];
} bd_ctx;

static bool take_ranks(void *ctx, const char *text)
{
    bd_args *a = ctx;
    a->num_ranks = 0;
    const char *p = text;
    while (*p) {
        char *end = NULL;
        errno = 0;
        long n = strtol(p, &end, 10);
        if (end == p || errno || n < 1 || n > MAX_RANK_COUNT || (*end && *end != ',') || a->num_ranks == MAX_RANKS) {
            cli_fail(RL_CLI_USAGE, "bench dist: --ranks: expected up to %d counts in 1..%d, e.g. 1,2,4, got '%s'",
                     MAX_RANKS, MAX_RANK_COUNT, text);
            return false;
        }
        a->ranks[a->num_ranks++] = (int)n;
        p = *end ? end + 1 : end;
    }
    if (a->num_ranks == 0) {
        cli_fail(RL_CLI_USAGE, "bench dist: --ranks: no rank count given");
        return false;
    }
    return true;
}

static cJSON *read_json(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return NULL;
    char *text = NULL;
    size_t len = 0, cap = 0;
    for (;;) {
        if (len + 4096 + 1 > cap) {
            size_t c = cap ? 2 * cap : 65536;
            char *t = c <= (64u << 20) ? realloc(text, c) : NULL;
            if (!t)
                break;
            text = t;
            cap = c;
        }
        size_t got = fread(text + len, 1, 4096, f);
        len += got;
        if (got < 4096)
            break;
    }
    fclose(f);
    cJSON *j = NULL;
    if (text) {
        text[len] = '\0';
        j = cJSON_Parse(text);
    }
    free(text);
    return j;
}

/* Runs argv with stdout and stderr into log; its exit status, or -1 when
 * it could not start or ran past CHILD_TIMEOUT_S (then it is killed). */
static int run_child(char *const *argv, const char *log)
{
    fflush(stdout);
    fflush(stderr);
    pid_t pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        /* Its own process group, so that a hung mpirun goes with its ranks. */
        setpgid(0, 0);
        if (!freopen(log, "w", stdout) || dup2(fileno(stdout), 2) < 0)
            _exit(127);
        execvp(argv[0], argv);
        _exit(127);
    }
    setpgid(pid, pid);
    double t0 = rl_time_s();
    for (;;) {
        int status = 0;
        pid_t got = waitpid(pid, &status, WNOHANG);
        if (got == pid)
            return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        if (got < 0)
            return -1;
        if (rl_time_s() - t0 > CHILD_TIMEOUT_S) {
            kill(-pid, SIGKILL);
            waitpid(pid, &status, 0);
            return -1;
        }
        struct timespec ts = { 0, 20000000 };
        nanosleep(&ts, NULL);
    }
}

/* The last line of a run's log, for the reason of a failure. */
static void log_tail(const char *log, char *out, size_t n)
{
    out[0] = '\0';
    FILE *f = fopen(log, "r");
    if (!f)
        return;
    char line[512];
    while (fgets(line, sizeof line, f))
        if (strncmp(line, "rl: error", 9) == 0 || !out[0])
            snprintf(out, n, "%.300s", line);
    fclose(f);
    out[strcspn(out, "\n")] = '\0';
}

/* One run under mpirun with ranks ranks: rl --dist CMD ARGS...; its
 * "dist" object from the JSON at json_path into *dist (owned by *doc). */
static rl_status mpi_run(bd_ctx *c, int ranks, const char *const *cmd, const char *json_path, cJSON **doc,
                         const cJSON **dist)
{
    char np[16], log[512];
    snprintf(np, sizeof np, "%d", ranks);
    snprintf(log, sizeof log, "%s/run.log", c->dir);
    const char *argv[64];
    int n = 0;
    argv[n++] = c->a->mpirun;
    argv[n++] = "--oversubscribe";
    argv[n++] = "-np";
    argv[n++] = np;
    argv[n++] = c->self;
    argv[n++] = "--dist";
    for (int k = 0; cmd[k] && n < 63; ++k)
        argv[n++] = cmd[k];
    argv[n] = NULL;
    remove(json_path);
    int rc = run_child((char *const *)argv, log);
    char tail[400];
    if (rc != 0) {
        log_tail(log, tail, sizeof tail);
        snprintf(c->reason, sizeof c->reason, "%d ranks: rl --dist %s exited %d: %s", ranks, cmd[0], rc, tail);
        return RL_ERR_IO;
    }
    *doc = read_json(json_path);
    *dist = *doc ? cJSON_GetObjectItemCaseSensitive(*doc, "dist") : NULL;
    if (!*dist || !cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(*dist, "time_ms"))) {
        cJSON_Delete(*doc);
        *doc = NULL;
        snprintf(c->reason, sizeof c->reason, "%d ranks: %.300s has no \"dist\" record", ranks, json_path);
        return RL_ERR_IO;
    }
    return RL_OK;
}

static double num(const cJSON *o, const char *key)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(o, key);
    return cJSON_IsNumber(v) ? v->valuedouble : NAN;
}

/* The busiest rank's busy time over the mean (1: perfectly balanced). */
static double imbalance(const cJSON *dist)
{
    const cJSON *per = cJSON_GetObjectItemCaseSensitive(dist, "per_rank");
    int n = cJSON_GetArraySize(per);
    if (n < 2)
        return 1.0;
    double sum = 0.0, max = 0.0;
    const cJSON *e;
    cJSON_ArrayForEach(e, per)
    {
        double b = num(e, "busy_ms");
        sum += b;
        max = b > max ? b : max;
    }
    return sum > 0.0 ? max / (sum / n) : NAN;
}

/* The runs of one workload over every rank count into arr; per: what the
 * bytes and messages are divided by (1 for a frame, the samples). */
/* Called after a rank count's runs with its entry (the last run's outputs
 * are still in the scratch folder). */
typedef void (*sweep_fn)(bd_ctx *c, int ranks, cJSON *entry, void *user);

static rl_status sweep_with(bd_ctx *c, const char *label, const char *const *cmd, const char *json_path,
                            double per, const char *per_what, cJSON *arr, sweep_fn after, void *user)
{
    double t1 = NAN;
    for (int i = 0; i < c->a->num_ranks; ++i) {
        int ranks = c->a->ranks[i];
        double best = INFINITY;
        cJSON *best_doc = NULL;
        for (long long k = 0; k < c->a->repeats; ++k) {
            cJSON *doc = NULL;
            const cJSON *dist = NULL;
            rl_status st = mpi_run(c, ranks, cmd, json_path, &doc, &dist);
            if (st != RL_OK) {
                cJSON_Delete(best_doc);
                return st;
            }
            /* One rank runs pt's frames as one process does, one call per
             * frame: the record's time_ms is then the last frame's, the
             * stats' the sum of all. */
            double t = ranks == 1 && cJSON_IsNumber(cJSON_GetObjectItemCaseSensitive(doc, "frames"))
                           ? num(doc, "time_ms")
                           : num(dist, "time_ms");
            if (t < best) {
                best = t;
                cJSON_Delete(best_doc);
                best_doc = doc;
            } else {
                cJSON_Delete(doc);
            }
        }
        const cJSON *dist = cJSON_GetObjectItemCaseSensitive(best_doc, "dist");
        if (ranks == 1)
            t1 = best;
        double speedup = bench_ratio(t1, best);
        cJSON *e = cJSON_CreateObject();
        cJSON_AddNumberToObject(e, "ranks", ranks);
        cJSON_AddBoolToObject(e, "oversubscribed", ranks * c->a->threads > c->cores);
        bench_add_num(e, "time_ms", best);
        bench_add_num(e, "speedup", speedup);
        bench_add_num(e, "efficiency", speedup / ranks);
        bench_add_num(e, "imbalance", imbalance(dist));
        char key[64];
        snprintf(key, sizeof key, "messages_per_%s", per_what);
        bench_add_num(e, key, num(dist, "messages") / per);
        snprintf(key, sizeof key, "bytes_per_%s", per_what);
        bench_add_num(e, key, num(dist, "bytes") / per);
        bench_add_num(e, "tasks", num(dist, "tasks"));
        bench_add_num(e, "lost", num(dist, "lost"));
        cJSON_AddItemToObject(e, "dist", cJSON_Duplicate(dist, true));
        cJSON_AddItemToArray(arr, e);
        if (after)
            after(c, ranks, e, user);
        printf("  %-28s %3d ranks%s  %9.1f ms  speed-up %5.2f  efficiency %4.0f%%  imbalance %4.2f  "
               "%7.1f msg, %9.0f B per %s\n",
               label, ranks, ranks * c->a->threads > c->cores ? " (oversubscribed)" : "                 ", best,
               speedup, 100.0 * speedup / ranks, imbalance(dist), num(dist, "messages") / per,
               num(dist, "bytes") / per, per_what);
        cJSON_Delete(best_doc);
    }
    return RL_OK;
}

static rl_status sweep(bd_ctx *c, const char *label, const char *const *cmd, const char *json_path, double per,
                       const char *per_what, cJSON *arr)
{
    return sweep_with(c, label, cmd, json_path, per, per_what, arr, NULL, NULL);
}

static rl_status sec_tiles(void *ctx, cJSON *sec)
{
    bd_ctx *c = ctx;
    const bd_args *a = c->a;
    cJSON *arr = cJSON_AddArrayToObject(sec, "runs");
    char scenes[1024];
    snprintf(scenes, sizeof scenes, "%s", a->scenes);
    char size[32], spp[32], threads[48], png[300], json[300];
    snprintf(size, sizeof size, "%dx%d", a->width, a->height);
    snprintf(spp, sizeof spp, "%lld", a->spp);
    snprintf(threads, sizeof threads, "threads=%lld", a->threads);
    snprintf(png, sizeof png, "%s/frame.png", c->dir);
    snprintf(json, sizeof json, "%s/frame.json", c->dir);
    static const char *const algos[] = { "whitted", "pt" };
    for (char *save = NULL, *scene = strtok_r(scenes, ",", &save); scene; scene = strtok_r(NULL, ",", &save))
        for (int k = 0; k < 2; ++k) {
            bool pt = k == 1;
            const char *cmd[] = { "render", scene, "--algo", algos[k], "--size", size, "--set", threads,
                                  "--out", png, "--stats-json", json, "-q", pt ? "--spp" : NULL, spp, NULL };
            char label[128];
            snprintf(label, sizeof label, "%s %s%s%s", algos[k], scene, pt ? " spp " : "", pt ? spp : "");
            note("tiles: %s", label);
            cJSON *w = cJSON_CreateObject();
            cJSON_AddStringToObject(w, "scene", scene);
            cJSON_AddStringToObject(w, "algorithm", algos[k]);
            cJSON_AddStringToObject(w, "size", size);
            if (pt)
                cJSON_AddNumberToObject(w, "spp", (double)a->spp);
            cJSON *runs = cJSON_AddArrayToObject(w, "ranks");
            cJSON_AddItemToArray(arr, w);
            rl_status st = sweep(c, label, cmd, json, 1.0, "frame", runs);
            if (st != RL_OK)
                return st;
        }
    return RL_OK;
}

static rl_status sec_sampling(void *ctx, cJSON *sec)
{
    bd_ctx *c = ctx;
    const bd_args *a = c->a;
    char samples[32], out[300], json[320];
    snprintf(samples, sizeof samples, "%lld", a->samples);
    snprintf(out, sizeof out, "%s/eval", c->dir);
    snprintf(json, sizeof json, "%s/eval.json", out);
    const char *cmd[] = { "eval", a->eval_scene, "--property", "visibility", "--samples", samples, "--seed", "1",
                          "--out", out, "-q", NULL };
    cJSON_AddStringToObject(sec, "scene", a->eval_scene);
    cJSON_AddStringToObject(sec, "property", "visibility");
    cJSON_AddNumberToObject(sec, "samples", (double)a->samples);
    cJSON *runs = cJSON_AddArrayToObject(sec, "ranks");
    char label[128];
    snprintf(label, sizeof label, "eval %s %s samples", a->eval_scene, samples);
    note("sampling: %s", label);
    return sweep(c, label, cmd, json, (double)a->samples, "sample", runs);
}

/* The vt section's quality: every rank count's image against the one-rank
 * image (one process: rl --dist with one rank renders as rl render), SSIM
 * over the pixels of the VT objects (node attribute vt, inherited). */
typedef struct vt_quality {
    const char *png;
    rl_image *reference;     /* the one-rank image */
    uint8_t *mask;           /* VT-object pixels, or NULL: every pixel */
    uint64_t mask_pixels;
} vt_quality;

/* The VT objects' pixels of scene's default camera at w x h, from an ID
 * image of the raster renderer (the same geometry the frames draw). */
static uint8_t *vt_mask(const char *scene_name, int w, int h, uint64_t *count)
{
    *count = 0;
    rl_scene *scene = NULL;
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_camera cam;
    uint8_t *mask = NULL;
    if (rl_scene_load(scene_name, NULL, &scene) != RL_OK || rl_scene_get_camera(scene, NULL, &cam) != RL_OK ||
        rl_renderer_create("raster", &r) != RL_OK || rl_image_create(w, h, RL_LAYER_COLOR | RL_LAYER_DEPTH |
                                                                                RL_LAYER_ID, &img) != RL_OK)
        goto done;
    cam.width = w;
    cam.height = h;
    if (rl_renderer_render(r, scene, &cam, img, NULL) != RL_OK || !(mask = calloc((size_t)w * (size_t)h, 1)))
        goto done;
    const rl_scene_data *d = rl_scene_get_data(scene);
    for (size_t i = 0; i < (size_t)w * (size_t)h; ++i) {
        uint32_t o = img->object_id[i];
        if (o >= d->num_objects)
            continue;
        for (uint32_t n = d->objects[o].node; n != RL_NONE; n = rl_scene_node_parent(scene, n)) {
            const char *v = rl_scene_node_attr(scene, n, "vt");
            if (v) {
                mask[i] = strcmp(v, "true") == 0;
                break;
            }
        }
        *count += mask[i];
    }
done:
    rl_image_release(img);
    rl_renderer_release(r);
    rl_scene_release(scene);
    if (mask && !*count) {
        free(mask);
        mask = NULL;
    }
    return mask;
}

static void vt_after(bd_ctx *c, int ranks, cJSON *entry, void *user)
{
    (void)c;
    vt_quality *q = user;
    rl_image *img = NULL;
    if (rl_image_read(q->png, &img) != RL_OK)
        return;
    if (ranks == 1 && !q->reference) {
        q->reference = img;
        return;
    }
    rl_metric_options opt = { .mask = q->mask };
    rl_image_metrics m;
    if (q->reference && rl_image_compare(img, q->reference, &opt, &m) == RL_OK) {
        bench_add_num(entry, "ssim_vt", m.ssim);
        bench_add_num(entry, "psnr_vt", m.psnr);
        /* Byte for byte, the whole image (the post-pass' aim). */
        const bool same = img->width == q->reference->width && img->height == q->reference->height &&
                          memcmp(img->color, q->reference->color,
                                 (size_t)img->width * (size_t)img->height * sizeof *img->color) == 0;
        cJSON_AddBoolToObject(entry, "identical", same);
        const cJSON *pp = cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(entry, "dist"), "postpass");
        printf("  %-28s %3d ranks: SSIM %.5f on %s against one rank%s", "", ranks, m.ssim,
               q->mask ? "the VT pixels" : "all pixels", same ? ", identical" : "");
        if (pp)
            printf("; post-pass %.0f traced, %.0f from the parts, %.1f ms, the image %.1f ms after the last part",
                   num(pp, "traced"), num(pp, "reused"), num(pp, "time_ms"), num(pp, "tail_ms"));
        printf("\n");
    }
    rl_image_release(img);
}

/* Fig. 5.14's analogue: distributed Vertex Tracing against the ranks, for
 * both load balancers (Sec. 4.3.2). The first rank count should be 1: it
 * is the reference of the speed-up and of the image. */
static rl_status sec_vt(void *ctx, cJSON *sec)
{
    bd_ctx *c = ctx;
    const bd_args *a = c->a;
    cJSON *arr = cJSON_AddArrayToObject(sec, "runs");
    char scenes[1024];
    snprintf(scenes, sizeof scenes, "%s", a->scenes);
    char size[32], threads[48], png[300], json[300];
    snprintf(size, sizeof size, "%dx%d", a->vt_width, a->vt_height);
    snprintf(threads, sizeof threads, "threads=%lld", a->threads);
    snprintf(png, sizeof png, "%s/vt.png", c->dir);
    snprintf(json, sizeof json, "%s/vt.json", c->dir);
    cJSON_AddStringToObject(sec, "note", "ssim_vt: SSIM (luma, sRGB) on the pixels of the VT objects against the "
                                         "one-rank image of the same balancer; the first rank count's frame "
                                         "includes every rank's BVH build (prep), as the tiles' do");
    static const char *const balances[] = { "queue", "precompute" };
    rl_status st = RL_OK;
    for (char *save = NULL, *scene = strtok_r(scenes, ",", &save); scene && st == RL_OK;
         scene = strtok_r(NULL, ",", &save)) {
        vt_quality q = { .png = png };
        q.mask = vt_mask(scene, a->vt_width, a->vt_height, &q.mask_pixels);
        for (int k = 0; k < 4 && st == RL_OK; ++k) {
            const bool post = k % 2 == 1;
            if (!strstr(a->vt_postpass, post ? "on" : "off"))
                continue;
            char balance[48], postpass[48], overlap[64];
            snprintf(balance, sizeof balance, "balance=%s", balances[k / 2]);
            snprintf(postpass, sizeof postpass, "dist_postpass=%s", post ? "on" : "off");
            snprintf(overlap, sizeof overlap, "dist_overlap=%s", a->vt_overlap);
            const char *cmd[] = { "render", scene, "--algo", "vt", "--size", size, "--set", threads, "--set", balance,
                                  "--set", postpass, "--set", overlap, "--out", png, "--stats-json", json, "-q",
                                  NULL };
            char label[128];
            snprintf(label, sizeof label, "vt %s %s%s", scene, balances[k / 2], post ? " post-pass" : "");
            note("vt: %s", label);
            cJSON *w = cJSON_CreateObject();
            cJSON_AddStringToObject(w, "scene", scene);
            cJSON_AddStringToObject(w, "algorithm", "vt");
            cJSON_AddStringToObject(w, "balance", balances[k / 2]);
            cJSON_AddStringToObject(w, "dist_postpass", post ? "on" : "off");
            if (post)
                cJSON_AddNumberToObject(w, "dist_overlap", strtod(a->vt_overlap, NULL));
            cJSON_AddStringToObject(w, "size", size);
            cJSON_AddNumberToObject(w, "vt_pixels", (double)q.mask_pixels);
            cJSON *runs = cJSON_AddArrayToObject(w, "ranks");
            cJSON_AddItemToArray(arr, w);
            st = sweep_with(c, label, cmd, json, 1.0, "frame", runs, vt_after, &q);
            rl_image_release(q.reference);
            q.reference = NULL;
        }
        free(q.mask);
    }
    return st;
}

static int remove_entry(const char *path, const struct stat *sb, int flag, struct FTW *ftw)
{
    (void)sb;
    (void)flag;
    (void)ftw;
    remove(path);
    return 0;
}

static int parse_args(int argc, char **argv, bd_args *a)
{
    const bench_opt rows[] = {
        RL_BENCH_FLAG("--quick", &a->quick),
        RL_BENCH_CUSTOM("--ranks", take_ranks, a, &a->has_ranks),
        RL_BENCH_COUNT("--threads", 4096, &a->threads, NULL),
        RL_BENCH_STRING("--scenes", &a->scenes),
        RL_BENCH_SIZE("--size", &a->width, &a->height, &a->has_size),
        RL_BENCH_SIZE("--vt-size", &a->vt_width, &a->vt_height, &a->has_vt_size),
        RL_BENCH_STRING("--vt-postpass", &a->vt_postpass),
        RL_BENCH_STRING("--vt-overlap", &a->vt_overlap),
        RL_BENCH_COUNT("--spp", 1 << 20, &a->spp, &a->has_spp),
        RL_BENCH_STRING("--eval-scene", &a->eval_scene),
        RL_BENCH_COUNT("--samples", 1 << 24, &a->samples, &a->has_samples),
        RL_BENCH_COUNT("--repeats", 100, &a->repeats, &a->has_repeats),
        RL_BENCH_STRING("--mpirun", &a->mpirun),
        RL_BENCH_SECTIONS(section_names, SEC_COUNT, &a->sections),
        RL_BENCH_OUT(&a->out),
    };
    int rc = bench_parse_args(argc, argv, "bench dist", bench_dist_help, rows, (int)(sizeof rows / sizeof rows[0]));
    if (rc != RL_CLI_OK)
        return rc;
    if (!a->has_ranks) {
        static const int full[] = { 1, 2, 3, 4 };
        a->num_ranks = a->quick ? 2 : 4;
        memcpy(a->ranks, full, sizeof full);
    }
    if (!a->threads)
        a->threads = 1;
    if (!a->scenes)
        a->scenes = a->quick ? "cornell" : "table,cluster";
    if (!a->has_size) {
        a->width = a->quick ? 96 : 640;
        a->height = a->quick ? 64 : 480;
    }
    if (!a->has_vt_size) {
        a->vt_width = a->quick ? 64 : 320;
        a->vt_height = a->quick ? 48 : 240;
    }
    if (!a->vt_postpass)
        a->vt_postpass = "off,on";
    for (const char *p = a->vt_postpass; *p;) {
        size_t n = strcspn(p, ",");
        if (!((n == 2 && strncmp(p, "on", 2) == 0) || (n == 3 && strncmp(p, "off", 3) == 0)))
            return cli_fail(RL_CLI_USAGE, "bench dist: --vt-postpass: expected off, on or off,on, got '%s'",
                            a->vt_postpass);
        p += n + (p[n] == ',');
    }
    if (!a->vt_overlap)
        a->vt_overlap = "0";
    char *end = NULL;
    double overlap = strtod(a->vt_overlap, &end);
    if (end == a->vt_overlap || *end || !(overlap >= 0.0 && overlap <= 1.0))
        return cli_fail(RL_CLI_USAGE, "bench dist: --vt-overlap: expected a share from 0 to 1, got '%s'",
                        a->vt_overlap);
    if (!a->has_spp)
        a->spp = a->quick ? 1 : 4;
    if (!a->eval_scene)
        a->eval_scene = a->quick ? "city:blocks=1" : "city:blocks=2";
    if (!a->has_samples)
        a->samples = a->quick ? 16 : 64;
    if (!a->has_repeats)
        a->repeats = a->quick ? 1 : 2;
    if (!a->mpirun)
        a->mpirun = "mpirun";
    if (!a->sections)
        a->sections = (1u << SEC_COUNT) - 1u;
    return RL_CLI_OK;
}

int bench_dist(int argc, char **argv)
{
    bd_args a = { 0 };
    int rc = parse_args(argc, argv, &a);
    if (rc != RL_CLI_OK)
        return rc == RL_BENCH_HELP_SHOWN ? RL_CLI_OK : rc;
    char why[256];
    if (!rl_dist_available(why, sizeof why))
        return cli_fail(RL_CLI_FAIL, "bench dist: %s", why);
    char out[4096];
    if (!bench_out_path(a.out, "dist", out, sizeof out))
        return RL_CLI_FAIL;
    bd_ctx c = { .a = &a, .cores = omp_get_num_procs() };
    ssize_t len = readlink("/proc/self/exe", c.self, sizeof c.self - 1);
    if (len <= 0)
        return cli_fail(RL_CLI_FAIL, "bench dist: cannot find this rl (/proc/self/exe): %s", strerror(errno));
    c.self[len] = '\0';
    snprintf(c.dir, sizeof c.dir, "/tmp/rl-bench-dist-XXXXXX");
    if (!mkdtemp(c.dir))
        return cli_fail(RL_CLI_FAIL, "bench dist: no scratch folder in /tmp: %s", strerror(errno));
    /* Open MPI refuses root without these; ranks that outnumber the cores
     * yield when idle instead of spinning. */
    if (geteuid() == 0) {
        setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
        setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
    }
    setenv("OMPI_MCA_mpi_yield_when_idle", "1", 0);
    char threads[32];
    snprintf(threads, sizeof threads, "%lld", a.threads);
    setenv("OMP_NUM_THREADS", threads, 1);

    cJSON *root = bench_record_json("dist", (int)a.threads);
    if (!root) {
        nftw(c.dir, remove_entry, 8, FTW_DEPTH | FTW_PHYS);
        return cli_fail(RL_CLI_FAIL, "out of memory");
    }
    cJSON *params = cJSON_AddObjectToObject(root, "parameters");
    cJSON *rl = cJSON_AddArrayToObject(params, "ranks");
    for (int i = 0; i < a.num_ranks; ++i)
        cJSON_AddItemToArray(rl, cJSON_CreateNumber(a.ranks[i]));
    cJSON_AddNumberToObject(params, "threads_per_rank", (double)a.threads);
    cJSON_AddNumberToObject(params, "cores", c.cores);
    cJSON_AddNumberToObject(params, "repeats", (double)a.repeats);
    cJSON_AddStringToObject(params, "mpirun", a.mpirun);
    cJSON_AddStringToObject(params, "time", "the master's time of the distributed call (frame or sampling), "
                                            "scene loading excluded, per-rank structure builds included; "
                                            "fastest of the repeats");
    cJSON_AddBoolToObject(params, "quick", a.quick);
    printf("rl bench dist: ranks");
    for (int i = 0; i < a.num_ranks; ++i)
        printf("%s%d", i ? "," : " ", a.ranks[i]);
    printf(", %lld thread%s per rank, %d cores\n", a.threads, a.threads == 1 ? "" : "s", c.cores);
    static const bench_section_fn fns[SEC_COUNT] = { sec_tiles, sec_sampling, sec_vt };
    rc = bench_run_sections("dist", root, section_names, fns, SEC_COUNT, a.sections, &c, c.reason,
                            (int)a.threads, out);
    cJSON_Delete(root);
    nftw(c.dir, remove_entry, 8, FTW_DEPTH | FTW_PHYS);
    return rc;
}
