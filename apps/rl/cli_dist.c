/* cli_dist.c: the global flag --dist (rl_dist.h). Under mpirun every rank
 * runs the same command line; rank 0 prints and writes, the workers render
 * their bands quietly (their standard output goes to /dev/null, their
 * errors still reach the terminal through mpirun). */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <cjson/cJSON.h>
#include <stdio.h>

static rl_dist *dist;
static rl_dist_stats last;
static bool have_last;          /* the last run was spread over several ranks */
static bool ran;                /* a run went through rl_dist (any ranks) */
static bool sampling;           /* the last run sampled: chunks of positions, not bands of pixels */

int cli_dist_begin(int *argc, char ***argv)
{
    rl_clear_error();
    rl_status st = rl_dist_init(argc, argv, &dist);
    if (st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, "--dist");
    if (rl_dist_rank(dist) > 0) {
        /* The master shows the run: its bar counts every rank's bands, and
         * the workers' warnings would repeat its own (the same scene). */
        rl_log_set_level(RL_LOG_ERROR);
        if (!freopen("/dev/null", "w", stdout))
            return cli_fail(RL_CLI_FAIL, "--dist: rank %d cannot silence its output", rl_dist_rank(dist));
    }
    return RL_CLI_OK;
}

int cli_dist_end(int rc)
{
    rl_dist_release(dist, rc == RL_CLI_OK ? RL_OK : RL_ERR_CANCELLED);
    dist = NULL;
    return rc;
}

bool cli_dist_active(void)
{
    return dist != NULL;
}

bool cli_dist_master(void)
{
    return rl_dist_rank(dist) == 0;
}

rl_status cli_render_call(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, rl_image *img,
                          rl_render_stats *stats)
{
    if (!dist)
        return rl_renderer_render(r, scene, cam, img, stats);
    rl_status st = rl_dist_render(dist, r, scene, cam, img, stats, &last);
    have_last = st == RL_OK && last.ranks > 1;
    ran = st == RL_OK;
    return st;
}

int cli_dist_ranks(void)
{
    return rl_dist_size(dist);
}

rl_status cli_render_frames_call(rl_renderer *r, const rl_scene *scene, const rl_camera *cam, long long frames,
                                 rl_image *img, rl_render_stats *stats)
{
    rl_status st = rl_dist_render_frames(dist, r, scene, cam, (uint64_t)frames, img, stats, &last);
    have_last = st == RL_OK && last.ranks > 1;
    ran = st == RL_OK;
    return st;
}

rl_status cli_sample_call(rl_property *p, const rl_sampling_desc *desc, rl_approx **out)
{
    if (!dist)
        return rl_sample_property(p, desc, out);
    rl_status st = rl_dist_sample_property(dist, p, desc, out, &last);
    have_last = st == RL_OK && last.ranks > 1;
    ran = st == RL_OK;
    sampling = true;
    return st;
}

rl_status cli_measure_call(rl_property *p, const rl_vec3 *pos, size_t count, double *values)
{
    if (!dist)
        return rl_property_measure(p, pos, count, values, NULL, NULL);
    rl_status st = rl_dist_measure(dist, p, pos, count, values, &last);
    have_last = st == RL_OK && last.ranks > 1;
    ran = st == RL_OK;
    sampling = true;
    return st;
}

void cli_dist_service_begin(void)
{
    if (dist && rl_dist_size(dist) > 1 && rl_dist_rank(dist) == 0)
        rl_dist_service_begin(dist);
}

int cli_dist_service_end(int rc)
{
    if (!dist || rl_dist_size(dist) == 1 || rl_dist_rank(dist) != 0)
        return rc;
    rl_clear_error();
    rl_status st = rl_dist_service_end(dist, rc == RL_CLI_OK ? RL_OK : RL_ERR_CANCELLED);
    if (rc == RL_CLI_OK && st != RL_OK)
        return cli_fail_status(RL_CLI_FAIL, st, "--dist");
    return rc;
}

int cli_dist_serve(const rl_scene *scene, int threads)
{
    if (!dist || rl_dist_rank(dist) == 0)
        return RL_CLI_OK;
    rl_clear_error();
    rl_status st = rl_dist_serve_properties(dist, scene, threads);
    sampling = true;
    return st == RL_OK ? RL_CLI_OK : cli_fail_status(RL_CLI_FAIL, st, "--dist");
}

cJSON *cli_dist_json(void)
{
    if (!ran || !cli_dist_master())
        return NULL;
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddNumberToObject(o, "ranks", last.ranks);
    cJSON_AddStringToObject(o, "task", sampling ? "chunk" : last.task_kind ? last.task_kind : "band");
    cJSON_AddNumberToObject(o, "tasks", (double)last.tasks);
    cJSON_AddNumberToObject(o, "messages", (double)last.messages);
    cJSON_AddNumberToObject(o, "bytes", (double)last.bytes);
    cJSON_AddNumberToObject(o, "time_ms", last.time_ms);
    cJSON_AddNumberToObject(o, "lost", last.lost);
    if (last.task_kind)
        cJSON_AddNumberToObject(o, "dropped", (double)last.dropped);
    if (last.postpass) {
        cJSON *pp = cJSON_AddObjectToObject(o, "postpass");
        if (pp) {
            cJSON_AddNumberToObject(pp, "reused", (double)last.postpass_reused);
            cJSON_AddNumberToObject(pp, "traced", (double)last.postpass_traced);
            cJSON_AddNumberToObject(pp, "time_ms", last.postpass_ms);
            cJSON_AddBoolToObject(pp, "overlapped", last.postpass_overlapped);
            cJSON_AddNumberToObject(pp, "early_ms", last.postpass_early_ms);
            cJSON_AddNumberToObject(pp, "tail_ms", last.postpass_tail_ms);
        }
    }
    cJSON *ranks = cJSON_AddArrayToObject(o, "per_rank");
    for (int k = 0; ranks && last.per_rank && k < last.ranks; k++) {
        cJSON *e = cJSON_CreateObject();
        if (!e)
            break;
        cJSON_AddNumberToObject(e, "tasks", (double)last.per_rank[k].tasks);
        cJSON_AddNumberToObject(e, sampling ? "positions" : last.task_kind ? "faces" : "pixels", (double)last.per_rank[k].pixels);
        cJSON_AddNumberToObject(e, "busy_ms", last.per_rank[k].busy_ms);
        cJSON_AddItemToArray(ranks, e);
    }
    return o;
}

void cli_print_dist_summary(FILE *out)
{
    if (!have_last || !cli_dist_master())
        return;
    const bool faces = !sampling && last.task_kind;      /* Vertex Tracing's face packages */
    const char *task = sampling ? "chunks" : faces ? "packages" : "bands",
               *item = sampling ? "positions" : faces ? "faces" : "pixels";
    fprintf(out, "dist: %d ranks, %llu %s, %llu messages, %.1f MB; per rank: %s, %s, busy ms, idle %%\n",
            last.ranks, (unsigned long long)last.tasks, task, (unsigned long long)last.messages,
            (double)last.bytes / 1e6, task, item);
    if (last.lost)
        fprintf(out, "dist: %d worker%s lost (silent past RL_DIST_TIMEOUT); the master handed their %s to the "
                "others\n", last.lost, last.lost == 1 ? "" : "s", task);
    if (last.dropped)
        fprintf(out, "dist: %llu result%s of an older camera dropped\n", (unsigned long long)last.dropped,
                last.dropped == 1 ? "" : "s");
    if (last.postpass)
        fprintf(out, "dist: post-pass: %llu samples from the parts, %llu traced on the master, %.1f ms; %s, the "
                "image %.1f ms after the last part\n", (unsigned long long)last.postpass_reused,
                (unsigned long long)last.postpass_traced, last.postpass_ms,
                last.postpass_overlapped ? "overlapped" : "not overlapped", last.postpass_tail_ms);
    for (int k = 0; k < last.ranks; k++) {
        const rl_dist_rank_stats *p = &last.per_rank[k];
        double idle = last.time_ms > 0.0 ? 100.0 * (1.0 - p->busy_ms / last.time_ms) : 0.0;
        fprintf(out, "  rank %d%s: %llu, %llu, %.1f, %.0f%%\n", k, k == 0 ? " (master)" : "",
                (unsigned long long)p->tasks, (unsigned long long)p->pixels, p->busy_ms, idle < 0.0 ? 0.0 : idle);
    }
}
