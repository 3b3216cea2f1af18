/* accel_cache.h: an acceleration structure kept by a renderer between
 * frames, rebuilt only when the scene (rl_scene_uid) or the kind changes.
 * Shared by the ray-tracing renderers (whitted, vt). */
#ifndef RL_RENDER_ACCEL_CACHE_H
#define RL_RENDER_ACCEL_CACHE_H

#include "rl/rl_accel.h"

typedef struct rl_accel_cache {
    rl_accel *accel;
    uint64_t scene_uid;
    rl_accel_kind kind;
} rl_accel_cache;

/* Makes c->accel a committed accel of `kind` over scene, building it (with
 * progress, may be NULL) unless the cached one fits. RL_ERR_UNSUPPORTED for
 * a kind this build lacks (the message names the renderer `who`).
 * *built_ms (may be NULL) gets the time building took, 0 when it reused. */
rl_status rl_accel_cache_get(rl_accel_cache *c, const char *who, const rl_scene *scene,
                             rl_accel_kind kind, int threads,
                             bool (*progress)(void *user, double done), void *user, double *built_ms);
void rl_accel_cache_release(rl_accel_cache *c);

#endif
