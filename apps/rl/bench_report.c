/* bench_report.c: the JSON record of one `rl bench rays` run.
 *
 * A benchmark figure means little without the machine it ran on and the
 * ratio to a reference measured in the same run (machines, loads and
 * compilers change), so the record carries the machine (cli_run.c), the
 * command line, the build, the date, the renderlab version and every parameter,
 * then per scene, accelerator and workload: rays, hits, seconds, Mrays/s and
 * the ratio to Embree. Unknown values are JSON null, never made up. */
#define _POSIX_C_SOURCE 200809L
#include "bench_rays.h"
#include "cli.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <string.h>
#include <time.h>

/* Adds a number, or null for NaN (JSON has no NaN). */
static void add_number(cJSON *obj, const char *key, double value)
{
    if (isfinite(value))
        cJSON_AddNumberToObject(obj, key, value);
    else
        cJSON_AddNullToObject(obj, key);
}

static cJSON *params_json(const bench_params *p)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    char size[32];
    snprintf(size, sizeof size, "%dx%d", p->width, p->height);
    cJSON_AddStringToObject(o, "size", size);
    if (p->rays > 0)
        cJSON_AddNumberToObject(o, "rays", (double)p->rays);
    else
        cJSON_AddNullToObject(o, "rays");
    cJSON_AddNumberToObject(o, "threads", p->threads);
    cJSON_AddBoolToObject(o, "quick", p->quick);
    cJSON_AddNumberToObject(o, "min_runs", p->min_runs);
    cJSON_AddNumberToObject(o, "max_runs", p->max_runs);
    cJSON_AddNumberToObject(o, "min_total_s", p->min_total_s);
    cJSON_AddNumberToObject(o, "seed", (double)p->seed);
    cJSON_AddStringToObject(o, "tile_order", "8x8 tiles, scanline");
    cJSON_AddStringToObject(o, "timing", "per workload: a warm-up pass per accel, then timed "
                                         "passes interleaved across accels, at least min_runs "
                                         "and min_total_s per accel (at most max_runs); seconds: "
                                         "fastest pass, wall clock; cpu_seconds: least CPU time "
                                         "of the tracing threads");
    return o;
}

static cJSON *stats_json(const rl_accel_stats *s)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddNumberToObject(o, "build_ms", s->build_ms);
    cJSON_AddNumberToObject(o, "memory_bytes", (double)s->memory_bytes);
    cJSON_AddNumberToObject(o, "bytes_per_triangle", s->bytes_per_triangle);
    if (s->kind == RL_ACCEL_BVH) {
        cJSON_AddNumberToObject(o, "nodes", s->nodes);
        cJSON_AddNumberToObject(o, "leaves", s->leaves);
        cJSON_AddNumberToObject(o, "max_depth", s->max_depth);
        cJSON_AddNumberToObject(o, "sah_cost", s->sah_cost);
    } else if (s->kind == RL_ACCEL_GRID) {
        cJSON_AddItemToObject(o, "grid_res", cJSON_CreateIntArray(s->grid_res, 3));
        cJSON_AddNumberToObject(o, "grid_references", (double)s->grid_references);
    }
    return o;
}

static cJSON *accel_json(const bench_scene_result *sc, const bench_accel_result *a)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "accel", rl_accel_kind_name(a->kind));
    cJSON_AddStringToObject(o, "status", a->status);
    if (strcmp(a->status, "ok") != 0) {
        cJSON_AddStringToObject(o, "reason", a->reason);
        return o;
    }
    cJSON_AddItemToObject(o, "build", stats_json(&a->stats));
    cJSON *work = cJSON_AddObjectToObject(o, "workloads");
    for (int w = 0; work && w < RL_BENCH_WORKLOADS; w++) {
        const bench_timing *t = &a->timing[w];
        cJSON *wj = cJSON_AddObjectToObject(work, bench_workload_name(w));
        if (!wj)
            break;
        cJSON_AddNumberToObject(wj, "rays", (double)sc->rays[w]);
        cJSON_AddNumberToObject(wj, "hits", (double)t->hits);
        add_number(wj, "seconds", sc->rays[w] ? t->best_s : NAN);
        cJSON_AddNumberToObject(wj, "runs", t->runs);
        add_number(wj, "mrays_per_s", a->mrays_per_s[w]);
        add_number(wj, "ratio_to_embree", a->ratio_to_embree[w]);
        add_number(wj, "cpu_seconds", sc->rays[w] ? t->best_cpu_s : NAN);
        add_number(wj, "mrays_per_cpu_s", a->mrays_per_cpu_s[w]);
        add_number(wj, "cpu_ratio_to_embree", a->cpu_ratio_to_embree[w]);
        cJSON_AddBoolToObject(wj, "hits_agree", sc->hits_agree[w]);
        cJSON_AddBoolToObject(wj, "deterministic", t->deterministic);
    }
    return o;
}

/* The packet section: per run (accel, single or packets) and workload. */
static cJSON *packets_json(const bench_scene_result *sc)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    char tile[16];
    snprintf(tile, sizeof tile, "%dx%d", RL_BENCH_PACKET_TILE_W, RL_BENCH_PACKET_TILE_H);
    cJSON_AddStringToObject(o, "tile", tile);
    cJSON_AddNumberToObject(o, "packet_size", 8);
    static const char *const names[RL_BENCH_PACKET_WORKLOADS] = { "primary", "shadow" };
    cJSON *rays = cJSON_AddObjectToObject(o, "rays");
    cJSON *agree = cJSON_AddObjectToObject(o, "hits_agree");
    for (int w = 0; rays && agree && w < RL_BENCH_PACKET_WORKLOADS; w++) {
        cJSON_AddNumberToObject(rays, names[w], (double)sc->packet_rays[w]);
        cJSON_AddBoolToObject(agree, names[w], sc->packet_hits_agree[w]);
    }
    cJSON *runs = cJSON_AddArrayToObject(o, "runs");
    for (int k = 0; runs && k < sc->num_packet_runs; k++) {
        const bench_packet_result *r = &sc->packet_runs[k];
        cJSON *rj = cJSON_CreateObject();
        if (!rj)
            break;
        cJSON_AddStringToObject(rj, "accel", rl_accel_kind_name(r->kind));
        cJSON_AddStringToObject(rj, "mode", r->packets ? "packets" : "single");
        cJSON_AddStringToObject(rj, "calls", r->packets ? (r->kind == RL_ACCEL_EMBREE
                                                               ? "rtcIntersect8/rtcOccluded8"
                                                               : "rl_accel_intersect_n/occluded_n")
                                                        : "rl_accel_intersect/occluded");
        cJSON *work = cJSON_AddObjectToObject(rj, "workloads");
        for (int w = 0; work && w < RL_BENCH_PACKET_WORKLOADS; w++) {
            const bench_timing *t = &r->timing[w];
            cJSON *wj = cJSON_AddObjectToObject(work, names[w]);
            if (!wj)
                break;
            bool any = sc->packet_rays[w] > 0;
            cJSON_AddNumberToObject(wj, "hits", (double)t->hits);
            cJSON_AddNumberToObject(wj, "runs", t->runs);
            add_number(wj, "seconds", any ? t->best_s : NAN);
            add_number(wj, "mrays_per_s", r->mrays_per_s[w]);
            add_number(wj, "cpu_seconds", any ? t->best_cpu_s : NAN);
            add_number(wj, "mrays_per_cpu_s", r->mrays_per_cpu_s[w]);
            add_number(wj, "cpu_ratio_to_single", r->cpu_ratio_to_single[w]);
            add_number(wj, "cpu_ratio_to_embree_packets", r->cpu_ratio_to_embree_packets[w]);
            cJSON_AddBoolToObject(wj, "deterministic", t->deterministic);
        }
        cJSON_AddItemToArray(runs, rj);
    }
    return o;
}

static cJSON *scene_json(const bench_scene_result *sc)
{
    cJSON *o = cJSON_CreateObject();
    if (!o)
        return NULL;
    cJSON_AddStringToObject(o, "scene", sc->arg);
    cJSON_AddStringToObject(o, "name", sc->label);
    cJSON_AddStringToObject(o, "status", sc->status);
    if (strcmp(sc->status, "ok") != 0) {
        cJSON_AddStringToObject(o, "reason", sc->reason);
        return o;
    }
    cJSON_AddNumberToObject(o, "triangles", (double)sc->triangles);
    char size[32];
    snprintf(size, sizeof size, "%dx%d", sc->width, sc->height);
    cJSON_AddStringToObject(o, "size", size);
    cJSON *rays = cJSON_AddObjectToObject(o, "rays");
    bool agree = true;
    for (int w = 0; rays && w < RL_BENCH_WORKLOADS; w++) {
        cJSON_AddNumberToObject(rays, bench_workload_name(w), (double)sc->rays[w]);
        agree = agree && sc->hits_agree[w];
    }
    cJSON_AddBoolToObject(o, "hits_agree", agree);
    cJSON *accels = cJSON_AddArrayToObject(o, "accels");
    for (int i = 0; accels && i < sc->num_accels; i++)
        cJSON_AddItemToArray(accels, accel_json(sc, &sc->accels[i]));
    if (sc->num_packet_runs > 0)
        cJSON_AddItemToObject(o, "packets", packets_json(sc));
    else
        cJSON_AddNullToObject(o, "packets");
    return o;
}

cJSON *bench_record_json(const char *benchmark, int threads)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON_AddStringToObject(root, "benchmark", benchmark);
    cJSON_AddStringToObject(root, "renderlab_version", RL_CLI_VERSION);
    char date[32];
    time_t now = time(NULL);
    struct tm utc;
    if (gmtime_r(&now, &utc) && strftime(date, sizeof date, "%Y-%m-%dT%H:%M:%SZ", &utc))
        cJSON_AddStringToObject(root, "date", date);
    else
        cJSON_AddNullToObject(root, "date");
    cJSON_AddStringToObject(root, "command", cli_command_line());
    char build[512];
    cli_build_text(build, sizeof build);
    cJSON_AddStringToObject(root, "build", build);
    cJSON_AddItemToObject(root, "machine", cli_machine_json(threads));
    return root;
}

cJSON *bench_report_json(const bench_params *params, const bench_scene_result *scenes,
                            int num_scenes, int hit_mismatches)
{
    cJSON *root = bench_record_json("rays", params->threads);
    if (!root)
        return NULL;
    cJSON_AddBoolToObject(root, "embree", rl_accel_kind_available(RL_ACCEL_EMBREE));
    cJSON_AddItemToObject(root, "parameters", params_json(params));
    cJSON_AddNumberToObject(root, "hit_mismatches", hit_mismatches);
    cJSON *list = cJSON_AddArrayToObject(root, "scenes");
    for (int i = 0; list && i < num_scenes; i++)
        cJSON_AddItemToArray(list, scene_json(&scenes[i]));
    /* cJSON drops items it could not allocate silently; a record with holes
     * must not pass for a complete one. */
    if (!list || !cJSON_GetObjectItem(root, "machine") || !cJSON_GetObjectItem(root, "parameters")
        || cJSON_GetArraySize(list) != num_scenes) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}
