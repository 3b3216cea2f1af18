/* accel_cache.c: see accel_cache.h. */
#include "render/accel_cache.h"

#include <string.h>

#include "core/error.h"
#include "rl/rl_scene.h"
#include "rl/rl_timer.h"

rl_status rl_accel_cache_get(rl_accel_cache *c, const char *who, const rl_scene *scene,
                             rl_accel_kind kind, int threads,
                             bool (*progress)(void *user, double done), void *user, double *built_ms)
{
    if (built_ms)
        *built_ms = 0.0;
    if (!rl_accel_kind_available(kind))
        return rl_error(RL_ERR_UNSUPPORTED, "%s: accel=%s is not available in this build", who,
                        rl_accel_kind_name(kind));
    uint64_t uid = rl_scene_uid(scene);
    if (c->accel && c->scene_uid == uid && c->kind == kind)
        return RL_OK;
    rl_accel_cache_release(c);
    rl_timer t;
    rl_timer_start(&t);
    rl_accel *a = NULL;
    rl_accel_desc desc = { .kind = kind, .threads = threads, .progress = progress, .user = user };
    rl_status st = rl_accel_create(scene, &desc, &a);
    if (st == RL_OK)
        st = rl_accel_commit(a);
    if (st != RL_OK) {
        rl_accel_release(a);
        return st;
    }
    c->accel = a;
    c->scene_uid = uid;
    c->kind = kind;
    if (built_ms)
        *built_ms = rl_timer_ms(&t);
    return RL_OK;
}

void rl_accel_cache_release(rl_accel_cache *c)
{
    rl_accel_release(c->accel);
    memset(c, 0, sizeof *c);
}
