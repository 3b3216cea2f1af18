/* bench_pt_conv.c: `rl bench pt --only convergence` (issue 37): how fast
 * the path tracer "pt" reaches a clean image on Bitterli's Cornell box
 * settings (cornell:variant=bitterli, square image, box filter), at its
 * defaults and at the thesis' settings (rng=hybrid, mis=off,
 * light_samples=1), with each improvement switched off in turn, with
 * light-sample splitting (light_samples 2, 4; the default is 1), and with
 * the options of issue 37 item 4: per-pixel adaptive sampling (the frames
 * keep their budget of 4 spp on average, so its checkpoints are at equal
 * mean spp) and the a-trous denoiser (filter=atrous, at full weight:
 * filter_fade=0, applied after every frame and timed with it; it trades
 * bias for variance, so every row also records the mean error; the
 * reference's noise is independent of a filtered image too, so its MSE is
 * subtracted alike).
 *
 * The error: RMSE of linear RGB clamped to the display range [0, 1] (the
 * lamp's radiance of 17 would otherwise let its few edge pixels decide the
 * figure), over all pixels and channels, against a reference rendered at
 * the defaults with --conv-ref-spp samples in two independent halves
 * (seeds REF_SEED_A, REF_SEED_B). The reference is noisy itself: its mean
 * squared error is MSE(half A, half B) / 4 (each half has twice the
 * variance of their mean, and the halves are independent), and that is
 * subtracted from each measured MSE, so the figures estimate the RMSE
 * against the converged image. The reference is cached next to the JSON
 * record (pt-convergence-ref-SIZE-SPP.bin) and reused when it matches;
 * while it is rendered its progress is saved beside it (.bin.part), so an
 * interrupted run or one stopped by --conv-ref-budget continues where it
 * ended when the same command runs again (render_reference).
 *
 * Time: per configuration the accumulation runs in frames that end at the
 * checkpoints 4, 8, ..., --conv-spp-max spp; each checkpoint records the
 * wall time and the process CPU time of the frames so far (builds and a
 * warm-up frame excluded). On a shared machine the wall time is inflated
 * by the other loads; CPU time / threads is what a quiet machine's wall
 * clock would show. Time to an RMSE: interpolated between the checkpoints
 * around it in log-log, else extrapolated along the fitted slope (marked). */
#define _POSIX_C_SOURCE 200809L
#include "bench_pt_conv.h"

#include "bench_util.h"

#include <cjson/cJSON.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "rl/rl_pt.h"
#include "rl/rl_timer.h"

#define note(...) bench_note("pt", __VA_ARGS__)

#define CONV_SCENE "cornell:variant=bitterli"
#define REF_SEED_A "4242"
#define REF_SEED_B "4343"
#define RUN_SEED "1"
#define MAX_CHECKPOINTS 24
#define REF_MAGIC "RLPTREF1"

/* The targets: the production renderer's RMSE at 64 spp, and the
 * two RMSEs whose times are to be halved. */
static const double target_rmse[2] = { 0.0069, 0.0014 };
static const double target_time_s[2] = { 6.0, 96.0 };
#define TARGET_RMSE_64 0.0069

typedef struct conv_config {
    const char *label;
    const char *const *opts;       /* key, value, ..., NULL */
    bool full;                     /* to --conv-spp-max; else to at most 64 spp */
} conv_config;

static const char *const opts_defaults[] = { NULL };
static const char *const opts_thesis[] = { "rng", "hybrid", "mis", "off", "light_samples", "1", "rr_depth", "2", NULL };
static const char *const opts_no_mis[] = { "mis", "off", NULL };
static const char *const opts_no_sobol[] = { "rng", "hybrid", NULL };
static const char *const opts_no_rr[] = { "rr", "false", NULL };
static const char *const opts_ls2[] = { "light_samples", "2", NULL };
static const char *const opts_ls4[] = { "light_samples", "4", NULL };
static const char *const opts_adaptive[] = { "adaptive", "on", NULL };
static const char *const opts_quad_sa[] = { "quad_sampling", "solid_angle", NULL };
static const char *const opts_atrous[] = { "filter", "atrous", "filter_fade", "0", NULL };
static const char *const opts_adaptive_atrous[] = { "adaptive", "on", "filter", "atrous", "filter_fade", "0", NULL };

static const conv_config configs[] = {
    { "defaults", opts_defaults, true },
    { "thesis (rng=hybrid, mis=off, light_samples=1)", opts_thesis, true },
    { "mis=off", opts_no_mis, false },
    { "rng=hybrid", opts_no_sobol, false },
    { "rr=false", opts_no_rr, false },
    { "light_samples=2", opts_ls2, false },
    { "light_samples=4", opts_ls4, false },
    { "adaptive=on", opts_adaptive, true },
    { "quad_sampling=solid_angle", opts_quad_sa, false },
    { "atrous (filter=atrous, filter_fade=0)", opts_atrous, false },
    { "adaptive+atrous (adaptive=on, filter=atrous, filter_fade=0)", opts_adaptive_atrous, false },
};
#define NUM_CONFIGS (sizeof configs / sizeof configs[0])

/* Whether configuration c is in the comma-separated list of labels (their
 * first words: "defaults", "thesis", "mis=off", ...); NULL or "" = all. */
static bool wanted(const char *list, const conv_config *c)
{
    if (!list || !*list)
        return true;
    size_t len = strcspn(c->label, " ");
    for (const char *p = list; *p;) {
        size_t n = strcspn(p, ",");
        if (n == len && strncmp(p, c->label, len) == 0)
            return true;
        p += n;
        if (*p == ',')
            ++p;
    }
    return false;
}

/* The configuration of --conv-set "key=value,...": its label "custom
 * (key=value,...)" and the options split in place. */
#define MAX_CUSTOM_OPTS 16
typedef struct custom_config {
    char label[528], buf[512];
    const char *opts[2 * MAX_CUSTOM_OPTS + 1];
    conv_config config;
} custom_config;

static rl_status bad_set(const char *kv, const char *why)
{
    note("--conv-set %s: %s", kv, why);
    return RL_ERR_INVALID_ARG;
}

static rl_status parse_custom(const char *kv, custom_config *c)
{
    if (strlen(kv) >= sizeof c->buf)
        return bad_set(kv, "too long");
    snprintf(c->label, sizeof c->label, "custom (%s)", kv);
    strcpy(c->buf, kv);
    size_t k = 0;
    for (char *p = c->buf; *p;) {
        char *end = p + strcspn(p, ",");
        bool last = *end == '\0';
        *end = '\0';
        char *eq = strchr(p, '=');
        if (!eq || eq == p)
            return bad_set(kv, "expected KEY=VALUE,...");
        if (k == 2 * MAX_CUSTOM_OPTS)
            return bad_set(kv, "more than 16 options");
        *eq = '\0';
        c->opts[k++] = p;
        c->opts[k++] = eq + 1;
        p = last ? end : end + 1;
    }
    c->opts[k] = NULL;
    c->config = (conv_config){ c->label, c->opts, true };
    return RL_OK;
}

typedef struct checkpoint {
    long long spp;
    double wall_ms, cpu_ms, rmse;
    double mean_err;              /* mean of (image - reference) over pixels and channels, display range */
} checkpoint;

/* Whether the configuration sets option key to value. */
static bool has_opt(const conv_config *c, const char *key, const char *value)
{
    for (size_t i = 0; c->opts[i]; i += 2)
        if (strcmp(c->opts[i], key) == 0 && strcmp(c->opts[i + 1], value) == 0)
            return true;
    return false;
}


static float disp(float v)
{
    return v < 0.0f ? 0.0f : (v < 1.0f ? v : 1.0f);
}

/* Mean squared error of two float RGB buffers in the display range. */
static double mse(const float *a, const float *b, size_t n)
{
    double e = 0.0;
    for (size_t i = 0; i < 3 * n; ++i) {
        double d = disp(a[i]) - disp(b[i]);
        e += d * d;
    }
    return e / (3.0 * (double)n);
}

/* Mean signed difference of a and b in the display range. */
static double mean_diff(const float *a, const float *b, size_t n)
{
    double e = 0.0;
    for (size_t i = 0; i < 3 * n; ++i)
        e += disp(a[i]) - disp(b[i]);
    return e / (3.0 * (double)n);
}

static rl_status set_opts(rl_renderer *r, const char *const *opts)
{
    rl_status st = RL_OK;
    for (size_t i = 0; st == RL_OK && opts[i]; i += 2)
        st = rl_renderer_set(r, opts[i], opts[i + 1]);
    return st;
}

static rl_status make_renderer(const bench_pt_conv_args *a, const char *const *opts, const char *seed,
                               rl_renderer **out)
{
    rl_renderer *r = NULL;
    char threads[16];
    snprintf(threads, sizeof threads, "%d", a->threads);
    rl_status st = rl_renderer_create("pt", &r);
    if (st == RL_OK) st = rl_renderer_set(r, "threads", threads);
    if (st == RL_OK) st = rl_renderer_set(r, "seed", seed);
    if (st == RL_OK) st = set_opts(r, opts);
    if (st != RL_OK) {
        rl_renderer_release(r);
        r = NULL;
    }
    *out = r;
    return st;
}

static bool load_reference(const char *path, int size, long long spp, float *halves, size_t n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    char magic[8];
    int32_t hdr[2];
    int64_t s;
    bool ok = fread(magic, 1, 8, f) == 8 && memcmp(magic, REF_MAGIC, 8) == 0 && fread(hdr, sizeof hdr, 1, f) == 1 &&
              fread(&s, sizeof s, 1, f) == 1 && hdr[0] == size && hdr[1] == size && s == spp &&
              fread(halves, sizeof *halves, 6 * n, f) == 6 * n;
    fclose(f);
    for (size_t i = 0; ok && i < 6 * n; ++i)
        ok = isfinite(halves[i]);
    return ok;
}

static bool save_reference(const char *path, int size, long long spp, const float *halves, size_t n)
{
    char tmp[4400];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        note("cannot write the reference cache %s: %s", tmp, strerror(errno));
        return false;
    }
    int32_t hdr[2] = { size, size };
    int64_t s = spp;
    bool ok = fwrite(REF_MAGIC, 1, 8, f) == 8 && fwrite(hdr, sizeof hdr, 1, f) == 1 &&
              fwrite(&s, sizeof s, 1, f) == 1 && fwrite(halves, sizeof *halves, 6 * n, f) == 6 * n;
    ok = fclose(f) == 0 && ok;
    if (!ok || rename(tmp, path) != 0) {
        note("cannot write the reference cache %s", path);
        remove(tmp);
        return false;
    }
    return true;
}

/* The reference in progress (issue 37: 16384 spp at 512^2 take about 26
 * minutes of two quiet cores, too long for one sitting on a shared
 * machine). Each half is rendered in chunks of REF_CHUNK_MAX spp (or the
 * largest power of two below that divides the half), each chunk a new
 * accumulation whose Sobol points start where the last one ended
 * (sample_offset), so the chunks of a half are the points 0 .. spp/2 - 1
 * of one long render. The chunks' means are summed in double, chunk by
 * chunk in the same order however the work is sliced, so a reference made
 * in several runs is bit for bit the one made at once. The sums and their
 * spp are saved to CACHE.part (tmp + rename) every REF_SAVE_S seconds, at
 * the end of each half and when the budget stops the run. */
#define REF_PART_MAGIC "RLPTREFP"
#define REF_CHUNK_MAX 16
#define REF_SAVE_S 120.0

typedef struct ref_progress {
    int32_t size, chunk;
    int64_t spp;                  /* the whole reference: two halves of spp / 2 */
    int64_t done[2];              /* samples summed per half */
    double *sums;                 /* 6 per pixel: half A's RGB sums, then half B's */
} ref_progress;

static bool load_progress(const char *path, ref_progress *p, size_t n)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    char magic[8];
    int32_t hdr[2];
    int64_t spp, done[2];
    bool ok = fread(magic, 1, 8, f) == 8 && memcmp(magic, REF_PART_MAGIC, 8) == 0 &&
              fread(hdr, sizeof hdr, 1, f) == 1 && fread(&spp, sizeof spp, 1, f) == 1 &&
              fread(done, sizeof done, 1, f) == 1 && hdr[0] == p->size && hdr[1] == p->chunk && spp == p->spp;
    for (int h = 0; ok && h < 2; ++h)
        ok = done[h] >= 0 && done[h] <= p->spp / 2 && done[h] % p->chunk == 0;
    ok = ok && fread(p->sums, sizeof *p->sums, 6 * n, f) == 6 * n && fgetc(f) == EOF;
    fclose(f);
    for (size_t i = 0; ok && i < 6 * n; ++i)
        ok = isfinite(p->sums[i]);
    if (ok) {
        p->done[0] = done[0];
        p->done[1] = done[1];
    }
    return ok;
}

static bool save_progress(const char *path, const ref_progress *p, size_t n)
{
    char tmp[4400];
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", path) >= sizeof tmp)
        return false;
    FILE *f = fopen(tmp, "wb");
    if (!f) {
        note("cannot write the reference progress %s: %s", tmp, strerror(errno));
        return false;
    }
    int32_t hdr[2] = { p->size, p->chunk };
    bool ok = fwrite(REF_PART_MAGIC, 1, 8, f) == 8 && fwrite(hdr, sizeof hdr, 1, f) == 1 &&
              fwrite(&p->spp, sizeof p->spp, 1, f) == 1 && fwrite(p->done, sizeof p->done, 1, f) == 1 &&
              fwrite(p->sums, sizeof *p->sums, 6 * n, f) == 6 * n;
    ok = fclose(f) == 0 && ok;
    if (!ok || rename(tmp, path) != 0) {
        note("cannot write the reference progress %s", path);
        remove(tmp);
        return false;
    }
    return true;
}

/* Renders the chunks of the reference still missing in p, until done or
 * until budget_s seconds (0: none) have passed at a chunk's end; *stopped
 * tells whether the budget stopped it. */
static rl_status render_reference(const bench_pt_conv_args *a, const rl_scene *scene, const rl_camera *cam,
                                  ref_progress *p, const char *part, bool *stopped)
{
    size_t n = (size_t)cam->width * cam->height;
    const char *seeds[2] = { REF_SEED_A, REF_SEED_B };
    int64_t half = p->spp / 2, total0 = p->done[0] + p->done[1];
    rl_image *img = NULL;
    rl_status st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    rl_timer run, since_save;
    rl_timer_start(&run);
    rl_timer_start(&since_save);
    char chunk[24];
    snprintf(chunk, sizeof chunk, "%d", (int)p->chunk);
    *stopped = false;
    for (int h = 0; h < 2 && st == RL_OK && !*stopped; ++h) {
        if (p->done[h] >= half)
            continue;
        rl_renderer *r = NULL;
        if ((st = make_renderer(a, opts_defaults, seeds[h], &r)) == RL_OK)
            st = rl_renderer_set(r, "spp", chunk);
        double *sum = p->sums + 3 * n * (size_t)h;
        while (st == RL_OK && p->done[h] < half) {
            char offset[24];
            snprintf(offset, sizeof offset, "%lld", (long long)p->done[h]);
            /* A new option value starts a new accumulation at that point. */
            if ((st = rl_renderer_set(r, "sample_offset", offset)) != RL_OK)
                break;
            rl_render_stats s;
            if ((st = rl_renderer_render(r, scene, cam, img, &s)) != RL_OK)
                break;
            for (size_t i = 0; i < n; ++i) {
                sum[3 * i + 0] += (double)img->color[i].x * p->chunk;
                sum[3 * i + 1] += (double)img->color[i].y * p->chunk;
                sum[3 * i + 2] += (double)img->color[i].z * p->chunk;
            }
            p->done[h] += p->chunk;
            double secs = rl_timer_ms(&run) / 1e3;
            int64_t total = p->done[0] + p->done[1], now = total - total0;
            note("reference: half %c %lld / %lld spp, %lld / %lld in all; %.0f s this run, about %.0f s left",
                 'A' + h, (long long)p->done[h], (long long)half, (long long)total, (long long)(2 * half), secs,
                 secs / (double)now * (double)(2 * half - total));
            bool over = a->ref_budget_s > 0.0 && secs >= a->ref_budget_s && total < 2 * half;
            if (over || p->done[h] == half || rl_timer_ms(&since_save) >= REF_SAVE_S * 1e3) {
                save_progress(part, p, n);
                rl_timer_start(&since_save);
            }
            if (over) {
                *stopped = true;
                break;
            }
        }
        rl_renderer_release(r);
    }
    rl_image_release(img);
    return st;
}

/* The reference halves (A then B, 3 floats per pixel each), from the
 * cache, or rendered (continuing CACHE.part when there is one); *ref_ms
 * this run's render time (0 when loaded). RL_ERR_CANCELLED with a->reason
 * set when --conv-ref-budget stopped it before the end. */
static rl_status reference(const bench_pt_conv_args *a, const rl_scene *scene, const rl_camera *cam,
                           float *halves, bool *cached, double *ref_ms, char *cache, size_t cache_size,
                           long long *resumed_spp)
{
    size_t n = (size_t)cam->width * cam->height;
    const char *slash = strrchr(a->out_path, '/');
    int dir_len = slash ? (int)(slash - a->out_path) + 1 : 0;
    snprintf(cache, cache_size, "%.*spt-convergence-ref-%d-%lld.bin", dir_len, a->out_path, a->size, a->ref_spp);
    *ref_ms = 0.0;
    *resumed_spp = 0;
    *cached = load_reference(cache, a->size, a->ref_spp, halves, n);
    if (*cached) {
        note("reference loaded from %s", cache);
        return RL_OK;
    }
    char part[4400];
    snprintf(part, sizeof part, "%s.part", cache);
    ref_progress p = { .size = a->size, .spp = a->ref_spp, .chunk = REF_CHUNK_MAX };
    while ((a->ref_spp / 2) % p.chunk != 0)
        p.chunk /= 2;
    p.sums = calloc(6 * n, sizeof *p.sums);
    if (!p.sums)
        return RL_ERR_OUT_OF_MEMORY;
    if (load_progress(part, &p, n)) {
        *resumed_spp = (long long)(p.done[0] + p.done[1]);
        note("reference: continuing %s at %lld / %lld spp", part, *resumed_spp, a->ref_spp / 2 * 2);
    } else {
        memset(p.sums, 0, 6 * n * sizeof *p.sums);
    }
    rl_timer t;
    rl_timer_start(&t);
    bool stopped = false;
    rl_status st = render_reference(a, scene, cam, &p, part, &stopped);
    *ref_ms = rl_timer_ms(&t);
    if (st == RL_OK && stopped) {
        if (a->reason)
            snprintf(a->reason, a->reason_size,
                 "reference incomplete after --conv-ref-budget: %lld / %lld spp saved to %s; rerun the same "
                 "command to continue", (long long)(p.done[0] + p.done[1]), a->ref_spp / 2 * 2, part);
        st = RL_ERR_CANCELLED;
    } else if (st == RL_OK) {
        for (size_t i = 0; i < 6 * n; ++i)
            halves[i] = (float)(p.sums[i] / (double)(a->ref_spp / 2));
        if (save_reference(cache, a->size, a->ref_spp, halves, n))
            remove(part);
    }
    free(p.sums);
    return st;
}

/* Least-squares slope of log(rmse) over log(spp). */
static double fit_slope(const checkpoint *c, int num)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int k = 0;
    for (int i = 0; i < num; ++i) {
        if (!(c[i].rmse > 0.0))
            continue;
        double x = log((double)c[i].spp), y = log(c[i].rmse);
        sx += x;
        sy += y;
        sxx += x * x;
        sxy += x * y;
        ++k;
    }
    double den = k * sxx - sx * sx;
    return k >= 2 && den > 0.0 ? (k * sxy - sx * sy) / den : NAN;
}

/* Time (ms, of the clock chosen by cpu) at which the curve reaches rmse:
 * log-log interpolation, else extrapolation along slope from the last
 * checkpoint (*extrapolated set). */
static double time_to(const checkpoint *c, int num, double rmse, bool cpu, double slope, bool *extrapolated)
{
    *extrapolated = false;
    for (int i = 0; i < num; ++i) {
        double t = cpu ? c[i].cpu_ms : c[i].wall_ms;
        if (c[i].rmse > rmse)
            continue;
        if (i == 0)               /* reached by the first checkpoint */
            return slope < 0.0 ? t * pow(rmse / c[0].rmse, 1.0 / slope) : t;
        double t0 = cpu ? c[i - 1].cpu_ms : c[i - 1].wall_ms;
        double f = (log(rmse) - log(c[i - 1].rmse)) / (log(c[i].rmse) - log(c[i - 1].rmse));
        return exp(log(t0) + f * (log(t) - log(t0)));
    }
    if (num == 0 || !(slope < 0.0))
        return NAN;
    *extrapolated = true;
    /* rmse ~ spp^slope and time ~ spp: t = t_last (rmse / rmse_last)^(1/slope). */
    double t = cpu ? c[num - 1].cpu_ms : c[num - 1].wall_ms;
    return t * pow(rmse / c[num - 1].rmse, 1.0 / slope);
}

static rl_status run_config(const bench_pt_conv_args *a, const conv_config *cc, const rl_scene *scene,
                            const rl_camera *cam, const float *ref, double ref_mse, checkpoint *pts, int *num,
                            float *rgb, double means[3])
{
    rl_renderer *r = NULL;
    rl_image *img = NULL;
    rl_status st = make_renderer(a, cc->opts, "7", &r);
    if (st == RL_OK)
        st = rl_image_create(cam->width, cam->height, RL_LAYER_COLOR, &img);
    /* Frames of 4 spp (every checkpoint is a multiple): any option change
     * restarts the accumulation, so the frame size is set once. A warm-up
     * frame builds the BVH; the seed change then restarts. */
    rl_render_stats s;
    if (st == RL_OK) st = rl_renderer_set(r, "spp", "4");
    if (st == RL_OK) st = rl_renderer_render(r, scene, cam, img, &s);
    if (st == RL_OK) st = rl_renderer_set(r, "seed", RUN_SEED);
    long long max_spp = cc->full ? a->spp_max : (a->spp_max < 64 ? a->spp_max : 64);
    size_t n = (size_t)cam->width * cam->height;
    double wall = 0.0, cpu = 0.0;
    long long done = 0;
    *num = 0;
    for (long long next = 4; st == RL_OK && next <= max_spp && *num < MAX_CHECKPOINTS; next *= 2) {
        while (st == RL_OK && done < next) {
            rl_timer t;
            double c0 = bench_cpu_ms();
            rl_timer_start(&t);
            st = rl_renderer_render(r, scene, cam, img, &s);
            wall += rl_timer_ms(&t);
            cpu += bench_cpu_ms() - c0;
            done += 4;
        }
        if (st != RL_OK)
            break;
        rl_pt_stats ps;
        if ((st = rl_pt_get_stats(r, &ps)) != RL_OK)
            break;
        /* Adaptive frames keep their budget unless pixels converge
         * (adaptive_threshold), which leaves samples unspent. */
        bool adaptive = has_opt(cc, "adaptive", "on");
        if (adaptive ? ps.spp > (double)done + 0.5 || ps.spp < 0.9 * (double)done : llround(ps.spp) != done) {
            note("%s: %g spp accumulated, expected %lld", cc->label, ps.spp, done);
            st = RL_ERR_INTERNAL;
            break;
        }
        for (size_t i = 0; i < n; ++i) {
            rgb[3 * i + 0] = img->color[i].x;
            rgb[3 * i + 1] = img->color[i].y;
            rgb[3 * i + 2] = img->color[i].z;
        }
        checkpoint *p = &pts[(*num)++];
        p->spp = done;
        p->wall_ms = wall;
        p->cpu_ms = cpu;
        double m = mse(rgb, ref, n) - ref_mse;
        p->rmse = m > 0.0 ? sqrt(m) : 0.0;
        p->mean_err = mean_diff(rgb, ref, n);
        note("%s: %lld spp (%.2f accumulated), RMSE %.5f, mean error %+.5f", cc->label, done, ps.spp, p->rmse,
             p->mean_err);
    }
    for (int k = 0; k < 3; ++k)
        means[k] = 0.0;
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < 3; ++k)
            means[k] += rgb[3 * i + k] / (double)n;
    rl_image_release(img);
    rl_renderer_release(r);
    return st;
}

static cJSON *options_json(const char *const *opts)
{
    cJSON *o = cJSON_CreateObject();
    for (size_t i = 0; o && opts[i]; i += 2)
        cJSON_AddStringToObject(o, opts[i], opts[i + 1]);
    return o;
}

static rl_status report_config(const bench_pt_conv_args *a, const conv_config *cc, const checkpoint *pts, int num,
                               cJSON *arr)
{
    double slope = fit_slope(pts, num);
    double rmse64 = NAN;
    for (int i = 0; i < num; ++i)
        if (pts[i].spp == 64)
            rmse64 = pts[i].rmse;
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return RL_ERR_OUT_OF_MEMORY;
    cJSON_AddItemToArray(arr, o);
    cJSON_AddStringToObject(o, "label", cc->label);
    cJSON_AddItemToObject(o, "options", options_json(cc->opts));
    cJSON *pj = cJSON_AddArrayToObject(o, "points");
    for (int i = 0; i < num && pj; ++i) {
        cJSON *p = cJSON_CreateObject();
        if (!p)
            return RL_ERR_OUT_OF_MEMORY;
        cJSON_AddNumberToObject(p, "spp", (double)pts[i].spp);
        bench_add_num(p, "wall_ms", pts[i].wall_ms);
        bench_add_num(p, "cpu_ms", pts[i].cpu_ms);
        bench_add_num(p, "rmse", pts[i].rmse);
        bench_add_num(p, "rmse_sqrt_spp", pts[i].rmse * sqrt((double)pts[i].spp));
        bench_add_num(p, "mean_error", pts[i].mean_err);
        cJSON_AddItemToArray(pj, p);
    }
    bench_add_num(o, "slope", slope);
    bench_add_num(o, "rmse_64spp", rmse64);
    printf("%-48s %9.5f %7.3f", cc->label, rmse64, slope);
    cJSON *tj = cJSON_AddArrayToObject(o, "time_to_rmse");
    for (int k = 0; k < 2 && tj; ++k) {
        bool ex_w, ex_c;
        double wall = time_to(pts, num, target_rmse[k], false, slope, &ex_w) / 1e3;
        double cpu = time_to(pts, num, target_rmse[k], true, slope, &ex_c) / 1e3 / a->threads;
        cJSON *t = cJSON_CreateObject();
        if (!t)
            return RL_ERR_OUT_OF_MEMORY;
        bench_add_num(t, "rmse", target_rmse[k]);
        bench_add_num(t, "wall_s", wall);
        bench_add_num(t, "cpu_s_per_thread", cpu);
        cJSON_AddBoolToObject(t, "extrapolated", ex_w || ex_c);
        bench_add_num(t, "target_s", target_time_s[k]);
        cJSON_AddItemToArray(tj, t);
        printf(" %9.1f %9.1f%s", wall, cpu, ex_w || ex_c ? "*" : " ");
    }
    printf("\n");
    fflush(stdout);
    return RL_OK;
}

rl_status bench_pt_convergence(const bench_pt_conv_args *a, cJSON *sec)
{
    rl_scene *scene = NULL;
    rl_status st = rl_scene_create_builtin("cornell", "variant=bitterli", &scene);
    if (st != RL_OK)
        return st;
    rl_camera cam;
    if ((st = rl_scene_get_camera(scene, NULL, &cam)) != RL_OK) {
        rl_scene_release(scene);
        return st;
    }
    cam.width = cam.height = a->size;
    size_t n = (size_t)a->size * a->size;
    float *halves = malloc(6 * n * sizeof *halves), *ref = malloc(3 * n * sizeof *ref);
    float *rgb = malloc(3 * n * sizeof *rgb);
    checkpoint *pts = malloc((NUM_CONFIGS + 1) * MAX_CHECKPOINTS * sizeof *pts);
    int nums[NUM_CONFIGS + 1] = { 0 };
    double means[NUM_CONFIGS + 1][3];
    if (!halves || !ref || !rgb || !pts)
        st = RL_ERR_OUT_OF_MEMORY;
    bool cached = false;
    double ref_ms = 0.0;
    char cache[4300];
    long long resumed = 0;
    /* --conv-set is checked before the reference is rendered: a typo
     * should not cost the reference's minutes. */
    custom_config cu;
    bool has_custom = a->custom && *a->custom;
    if (st == RL_OK && has_custom && (st = parse_custom(a->custom, &cu)) == RL_OK) {
        rl_renderer *probe = NULL;
        st = make_renderer(a, cu.opts, "7", &probe);
        rl_renderer_release(probe);
    }
    if (st == RL_OK)
        st = reference(a, scene, &cam, halves, &cached, &ref_ms, cache, sizeof cache, &resumed);
    double ref_mse = 0.0, ref_mean[3] = { 0.0, 0.0, 0.0 };
    if (st == RL_OK) {
        for (size_t i = 0; i < 3 * n; ++i) {
            ref[i] = 0.5f * (halves[i] + halves[3 * n + i]);
            ref_mean[i % 3] += ref[i] / (double)n;
        }
        ref_mse = mse(halves, halves + 3 * n, n) / 4.0;
        printf("\nconvergence (%s, %dx%d, %d threads): reference %lld spp (%s), its own RMSE %.5f\n", CONV_SCENE,
               a->size, a->size, a->threads, a->ref_spp, cached ? "cached" : "rendered", sqrt(ref_mse));
        printf("%-48s %9s %7s %9s %9s  %9s %9s\n", "configuration", "RMSE@64", "slope", "t0.0069 s", "cpu/thr s",
               "t0.0014 s", "cpu/thr s");
    }
    cJSON *arr = st == RL_OK ? cJSON_AddArrayToObject(sec, "configurations") : NULL;
    if (st == RL_OK && !arr)
        st = RL_ERR_OUT_OF_MEMORY;
    for (size_t c = 0; st == RL_OK && c < NUM_CONFIGS; ++c) {
        checkpoint *p = pts + c * MAX_CHECKPOINTS;
        if (!wanted(a->configs, &configs[c]))
            continue;
        st = run_config(a, &configs[c], scene, &cam, ref, ref_mse, p, &nums[c], rgb, means[c]);
        if (st == RL_OK)
            st = report_config(a, &configs[c], p, nums[c], arr);
    }
    /* --conv-set: one configuration of the caller's options, to spp_max,
     * against the same reference (an A/B of a setting). */
    if (st == RL_OK && has_custom) {
        checkpoint *p = pts + NUM_CONFIGS * MAX_CHECKPOINTS;
        st = run_config(a, &cu.config, scene, &cam, ref, ref_mse, p, &nums[NUM_CONFIGS], rgb, means[NUM_CONFIGS]);
        if (st == RL_OK)
            st = report_config(a, &cu.config, p, nums[NUM_CONFIGS], arr);
    }
    if (st == RL_OK) {
        cJSON_AddStringToObject(sec, "scene", CONV_SCENE);
        cJSON_AddNumberToObject(sec, "size", a->size);
        cJSON_AddNumberToObject(sec, "threads", a->threads);
        cJSON *r = cJSON_AddObjectToObject(sec, "reference");
        if (r) {
            cJSON_AddNumberToObject(r, "spp", (double)a->ref_spp);
            cJSON_AddStringToObject(r, "renderer", "pt at its defaults, two halves with seeds " REF_SEED_A
                                                   " and " REF_SEED_B);
            cJSON_AddBoolToObject(r, "cached", cached);
            cJSON_AddNumberToObject(r, "resumed_at_spp", (double)resumed);
            cJSON_AddStringToObject(r, "cache_file", cache);
            bench_add_num(r, "render_ms", ref_ms);
            bench_add_num(r, "own_rmse", sqrt(ref_mse));
        }
        cJSON_AddStringToObject(sec, "rmse",
                                "linear RGB clamped to [0,1], all pixels and channels, against the reference; "
                                "the reference's own MSE (MSE of its halves / 4) subtracted");
        cJSON_AddStringToObject(sec, "timing",
                                "frames of 4 spp after a warm-up frame; wall_ms and process cpu_ms summed over "
                                "the frames; cpu_s_per_thread = cpu / threads, a quiet machine's wall time");
        /* Channel means of the defaults' longest run against the reference. */
        cJSON *mj = cJSON_AddArrayToObject(sec, "mean_rel_diff_defaults");
        printf("channel means, defaults at %lld spp vs reference:", nums[0] ? pts[nums[0] - 1].spp : 0);
        for (int k = 0; k < 3 && mj && nums[0]; ++k) {
            double d = ref_mean[k] > 0.0 ? means[0][k] / ref_mean[k] - 1.0 : NAN;
            printf(" %+.3f %%", 100.0 * d);
            cJSON_AddItemToArray(mj, cJSON_CreateNumber(isfinite(d) ? d : 0.0));
        }
        printf("\n* extrapolated along the fitted slope (not reached within --conv-spp-max)\n");
        cJSON *tg = cJSON_AddObjectToObject(sec, "targets");
        if (tg) {
            bench_add_num(tg, "rmse_64spp", TARGET_RMSE_64);
            bench_add_num(tg, "time_to_0.0069_s", target_time_s[0]);
            bench_add_num(tg, "time_to_0.0014_s", target_time_s[1]);
        }
    }
    free(halves);
    free(ref);
    free(rgb);
    free(pts);
    rl_scene_release(scene);
    return st;
}
