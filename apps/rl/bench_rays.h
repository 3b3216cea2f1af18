/* bench_rays.h: what the files of `rl bench rays` share: the ray workloads
 * and the timing loop (bench_rays.c), the results and their JSON report
 * (bench_report.c); the command itself is cmd_bench.c.
 *
 * The standard workloads of Wald-style ray-tracing benchmarks:
 *   primary  one ray per pixel of the scene camera, in scanline order of
 *            8x8 tiles, so that neighbouring rays are coherent;
 *   shadow   from every primary hit point towards the first light, any hit;
 *   diffuse  a cosine-weighted hemisphere direction from every primary hit
 *            point, in pixel order, so that neighbouring rays are incoherent.
 * The rays are generated once per scene and shared by every accelerator, so
 * the comparison is exact and the hit counts must agree. */
#ifndef RL_APP_BENCH_RAYS_H
#define RL_APP_BENCH_RAYS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "rl/rl.h"

enum { RL_BENCH_PRIMARY = 0, RL_BENCH_SHADOW, RL_BENCH_DIFFUSE, RL_BENCH_WORKLOADS };

/* "primary", "shadow", "diffuse". */
const char *bench_workload_name(int workload);

typedef struct bench_rays {
    rl_ray *rays[RL_BENCH_WORKLOADS];
    size_t count[RL_BENCH_WORKLOADS];
} bench_rays;

/* Generates the three workloads for scene, with primary rays of cam (its
 * width x height pixels) and primary hits found with reference (any
 * committed accel of the same scene). seed drives the diffuse directions.
 * Returns false only when out of memory (*out then stays empty). */
bool bench_make_rays(const rl_scene *scene, const rl_camera *cam, const rl_accel *reference,
                        uint64_t seed, int threads, bench_rays *out);
void bench_rays_free(bench_rays *rays);

/* The packet section's workloads: primary rays in scanline order of 4x2
 * pixel tiles (one packet of 8 rays per tile) and the shadow rays of their
 * hits to the first light, in the same order (as bench_make_rays: the
 * diffuse slot stays empty). False only when out of memory. */
#define RL_BENCH_PACKET_TILE_W 4
#define RL_BENCH_PACKET_TILE_H 2
bool bench_make_packet_rays(const rl_scene *scene, const rl_camera *cam, const rl_accel *reference,
                            int threads, bench_rays *out);

typedef struct bench_timing {
    uint64_t hits;          /* of the warm-up pass */
    double best_s;          /* fastest timed pass, wall clock */
    double best_cpu_s;      /* least CPU time of the threads over the passes */
    int runs;               /* timed passes */
    bool deterministic;     /* every pass found the same number of hits */
} bench_timing;

/* Times each of accels on the same rays: one warm-up pass each (which counts
 * the hits), then interleaved timed passes until each has run min_runs
 * times and for min_total_s in all (at most max_runs); out[i] for accels[i].
 * Closest hit (rl_accel_intersect) unless any_hit (rl_accel_occluded);
 * where batched[i] (batched may be NULL), the batch queries
 * rl_accel_intersect_n / rl_accel_occluded_n on chunks of rays instead. */
void bench_time_rays(const rl_accel *const *accels, const bool *batched, int num_accels,
                     const rl_ray *rays, size_t count, bool any_hit, int threads, int min_runs,
                     int max_runs, double min_total_s, bench_timing *out);

/* Results of one accelerator on one scene. */
typedef struct bench_accel_result {
    rl_accel_kind kind;
    const char *status;                 /* "ok", "unavailable", "failed" */
    char reason[256];                   /* why not "ok" */
    rl_accel_stats stats;
    bench_timing timing[RL_BENCH_WORKLOADS];
    double mrays_per_s[RL_BENCH_WORKLOADS];       /* wall clock; NAN without rays */
    double ratio_to_embree[RL_BENCH_WORKLOADS];   /* NAN when unknown */
    /* Per CPU second of tracing threads: robust to other load on the machine. */
    double mrays_per_cpu_s[RL_BENCH_WORKLOADS];
    double cpu_ratio_to_embree[RL_BENCH_WORKLOADS];
} bench_accel_result;

/* The packet section: one accelerator traced with single queries or with
 * the batch queries (packets of 8: our packet traversal for bvh,
 * rtcIntersect8 / rtcOccluded8 for embree) on the primary and shadow rays
 * of 4x2 tiles (bench_make_packet_rays). */
#define RL_BENCH_PACKET_WORKLOADS 2        /* primary, shadow */
#define RL_BENCH_PACKET_RUNS 4             /* bvh, embree x single, packets */
typedef struct bench_packet_result {
    rl_accel_kind kind;
    bool packets;                                  /* batch queries, else single */
    bench_timing timing[RL_BENCH_PACKET_WORKLOADS];
    double mrays_per_s[RL_BENCH_PACKET_WORKLOADS];
    double mrays_per_cpu_s[RL_BENCH_PACKET_WORKLOADS];
    /* CPU-time ratios: to Embree's packets of the same run, and to the
     * same accelerator's single queries; NAN when unknown. */
    double cpu_ratio_to_embree_packets[RL_BENCH_PACKET_WORKLOADS];
    double cpu_ratio_to_single[RL_BENCH_PACKET_WORKLOADS];
} bench_packet_result;

typedef struct bench_scene_result {
    const char *arg;                    /* as given to --scenes */
    char label[64];                     /* short name for the table */
    const char *status;                 /* "ok", "skipped", "failed" */
    char reason[256];
    uint64_t triangles;
    int width, height;                  /* primary rays */
    size_t rays[RL_BENCH_WORKLOADS];
    bool hits_agree[RL_BENCH_WORKLOADS];
    bench_accel_result *accels;
    int num_accels;
    /* The packet section (num_packet_runs 0: not run). */
    size_t packet_rays[RL_BENCH_PACKET_WORKLOADS];
    bool packet_hits_agree[RL_BENCH_PACKET_WORKLOADS];
    bench_packet_result packet_runs[RL_BENCH_PACKET_RUNS];
    int num_packet_runs;
    int packet_mismatches;              /* packet workloads whose hit counts differ */
} bench_scene_result;

typedef struct bench_params {
    int width, height;                  /* --size, after --rays */
    long long rays;                     /* --rays, 0 = one per pixel of --size */
    int threads;
    bool quick;
    int min_runs, max_runs;
    double min_total_s;
    uint64_t seed;
} bench_params;

/* The head of every benchmark record: benchmark name, renderlab version, UTC
 * date, the command line, the build and the machine (cli_machine_json);
 * NULL when out of memory. */
struct cJSON *bench_record_json(const char *benchmark, int threads);

/* The whole run as one JSON object: machine, date, version, parameters,
 * per scene/accel/workload rays, hits, seconds, Mrays/s, ratio to Embree.
 * NULL when out of memory. */
struct cJSON *bench_report_json(const bench_params *params,
                                   const bench_scene_result *scenes, int num_scenes,
                                   int hit_mismatches);

#endif
