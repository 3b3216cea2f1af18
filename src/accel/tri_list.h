/* tri_list.h: a list of triangle IDs tested against one ray, the inner loop
 * of the uniform grid (grid.c) and of the Line Space's candidate lists
 * (linespace_query.c), which walk cells front to back and test each cell's
 * list against the whole ray.
 *
 * A triangle that spans several cells is in several lists; a small
 * direct-mapped mailbox per ray skips most re-tests (a re-test cannot change
 * the result, so the mailbox only saves time). The closest hit keeps ties at
 * equal t to the lower triangle ID, as the brute-force reference does
 * (accel.c), and after a hit tests one ulp past its t so that such a tie is
 * still seen. IDs equal to RL_ID_NONE (empty slots of fixed-size lists) are
 * skipped. */
#ifndef RL_ACCEL_TRI_LIST_H
#define RL_ACCEL_TRI_LIST_H

#include <math.h>
#include <string.h>

#include "accel/watertight.h"

#define RL_MAILBOX_SIZE 16

typedef struct rl_mailbox {
    uint32_t ids[RL_MAILBOX_SIZE];
} rl_mailbox;

static inline void rl_mailbox_init(rl_mailbox *m) { memset(m->ids, 0xff, sizeof m->ids); }

/* True when id was tested for this ray already; else remembers it. */
static inline bool rl_mailbox_seen(rl_mailbox *m, uint32_t id)
{
    uint32_t *box = &m->ids[id & (RL_MAILBOX_SIZE - 1)];
    if (*box == id)
        return true;
    *box = id;
    return false;
}

/* The closest hit so far: id RL_ID_NONE while there is none. */
typedef struct rl_tri_closest {
    uint32_t id;
    float t, u, v;
} rl_tri_closest;

/* Tests ids[0..count) (vertices verts[3 id ..]) within (t_min, *limit),
 * keeping the closest in *best and pulling *limit in behind it. */
static inline void rl_tri_list_closest(const rl_vec3 *verts, const uint32_t *ids, uint32_t count,
                                       const rl_ray_watertight *w, float t_min, rl_mailbox *mailbox,
                                       rl_tri_closest *best, float *limit)
{
    for (uint32_t j = 0; j < count; ++j) {
        uint32_t id = ids[j];
        if (id == RL_ID_NONE || rl_mailbox_seen(mailbox, id))
            continue;
        const rl_vec3 *v = verts + 3 * (size_t)id;
        float t, u, vv;
        if (!rl_watertight_hit(w, v[0], v[1], v[2], t_min, *limit, &t, &u, &vv))
            continue;
        if (best->id == RL_ID_NONE || t < best->t || (t == best->t && id < best->id)) {
            *best = (rl_tri_closest){ id, t, u, vv };
            *limit = nextafterf(t, INFINITY);
        }
    }
}

/* Whether any of ids[0..count) is hit within (t_min, t_max). */
static inline bool rl_tri_list_any(const rl_vec3 *verts, const uint32_t *ids, uint32_t count,
                                   const rl_ray_watertight *w, float t_min, float t_max, rl_mailbox *mailbox)
{
    for (uint32_t j = 0; j < count; ++j) {
        uint32_t id = ids[j];
        if (id == RL_ID_NONE || rl_mailbox_seen(mailbox, id))
            continue;
        const rl_vec3 *v = verts + 3 * (size_t)id;
        float t, u, vv;
        if (rl_watertight_hit(w, v[0], v[1], v[2], t_min, t_max, &t, &u, &vv))
            return true;
    }
    return false;
}

#endif
