/* drawer.c: rl_drawer (rl_drawer.h) over its backends, and the software
 * backend: the rasterizer of rasterizer.c with the scene drawer of
 * scene_drawer.c, whose images every software renderer shares. Every call
 * checks its arguments once here and dispatches through the backend's
 * table (drawer_backend.h). */
#include "raster/drawer_backend.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "raster/scene_drawer.h"

struct rl_drawer {
    const rl_drawer_ops *ops;
    void *impl;
    uint64_t scene_uid;
    rl_drawer_desc desc;
    bool in_frame;
    /* The query slots: open[i] while slot i's answer is unread (SLOT_KEPT:
     * and it outlives the frame's end); free_slots a stack of the slots
     * below num_slots that are not open. */
    uint8_t *open;
    uint32_t *free_slots;
    uint32_t num_slots, num_free, cap_slots;
    /* desc.query_delay: per slot, the polls left that find no answer. */
    uint32_t *late;
};

enum { SLOT_FREE, SLOT_OPEN, SLOT_KEPT };

void *rl_drawer_impl(const rl_drawer *d, const rl_drawer_ops *ops)
{
    return d && d->ops == ops ? d->impl : NULL;
}

rl_status rl_drawer_make(const rl_drawer_ops *ops, void *impl, const rl_scene *scene, const rl_drawer_desc *desc,
                         rl_drawer **out)
{
    rl_drawer *dr = rl_calloc(1, sizeof *dr);
    if (!dr) {
        ops->release(impl);
        return RL_ERR_OUT_OF_MEMORY;
    }
    *dr = (rl_drawer){ .ops = ops, .impl = impl, .scene_uid = rl_scene_uid(scene) };
    if (desc)
        dr->desc = *desc;
    *out = dr;
    return RL_OK;
}

void rl_drawer_release(rl_drawer *dr)
{
    if (!dr)
        return;
    dr->ops->release(dr->impl);
    free(dr->open);
    free(dr->free_slots);
    free(dr->late);
    free(dr);
}

bool rl_drawer_fits(const rl_drawer *dr, const rl_scene *scene, const rl_drawer_desc *desc)
{
    static const rl_drawer_desc zero;
    const rl_drawer_desc *d = desc ? desc : &zero;
    return dr && scene && dr->scene_uid == rl_scene_uid(scene) && dr->desc.shading == d->shading &&
           dr->desc.ambient == d->ambient && dr->desc.threads == d->threads && dr->desc.flags == d->flags &&
           dr->desc.object_mask == d->object_mask && dr->desc.deferred_counts == d->deferred_counts &&
           dr->desc.query_delay == d->query_delay;
}

const char *rl_drawer_backend(const rl_drawer *dr) { return dr ? dr->ops->name : NULL; }

/* Every slot free again but the kept ones, which stay open for the next
 * frame (once: kept again, they outlive that one too). The stack lists the
 * free ones downwards, so that the next frame takes slot 0 first. */
static void drop_queries(rl_drawer *dr, bool keep)
{
    dr->num_free = 0;
    for (uint32_t i = dr->num_slots; i-- > 0;) {
        if (keep && dr->open[i] == SLOT_KEPT) {
            dr->open[i] = SLOT_OPEN;
            continue;
        }
        dr->open[i] = SLOT_FREE;
        dr->free_slots[dr->num_free++] = i;
    }
}

rl_status rl_drawer_begin(rl_drawer *dr, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj,
                          rl_vec3 eye)
{
    if (!dr || !target || !view || !proj)
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_begin: NULL argument");
    if (!(target->layers & RL_LAYER_DEPTH) || !target->depth)
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_begin: the target has no depth layer");
    if (dr->in_frame)
        drop_queries(dr, false);   /* a frame that failed never ended */
    rl_status st = dr->ops->begin(dr->impl, target, view, proj, eye);
    dr->in_frame = st == RL_OK;
    return st;
}

rl_status rl_drawer_begin_camera(rl_drawer *dr, rl_image *target, const rl_camera *cam, rl_aabb scene_bounds)
{
    if (!dr || !target || !cam)
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_begin_camera: NULL argument");
    rl_mat4 view, proj;
    rl_status st = rl_raster_camera_matrices(cam, scene_bounds, &view, &proj);
    return st == RL_OK ? rl_drawer_begin(dr, target, &view, &proj, cam->eye) : st;
}

/* Calls between begin and end only. */
static rl_status in_frame(const rl_drawer *dr, const char *fn)
{
    if (!dr)
        return rl_error(RL_ERR_INVALID_ARG, "%s: NULL drawer", fn);
    return dr->in_frame ? RL_OK : rl_error(RL_ERR_INVALID_ARG, "%s: no frame begun (rl_drawer_begin)", fn);
}

void rl_drawer_light(rl_drawer *dr, const uint32_t *objects, uint32_t count)
{
    if (dr && dr->in_frame && (objects || !count))
        dr->ops->light(dr->impl, objects, count);
}

rl_status rl_drawer_draw(rl_drawer *dr, const uint32_t *objects, uint32_t count, rl_raster_counters *c)
{
    rl_status st = in_frame(dr, "rl_drawer_draw");
    if (st == RL_OK && count && !objects)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw: NULL object list");
    return st == RL_OK ? dr->ops->draw(dr->impl, objects, count, c) : st;
}

rl_status rl_drawer_draw_all(rl_drawer *dr, rl_raster_counters *c, rl_progress_fn progress, void *user)
{
    rl_status st = in_frame(dr, "rl_drawer_draw_all");
    return st == RL_OK ? dr->ops->draw_all(dr->impl, c, progress, user) : st;
}

/* A free query slot: the most recently freed one, so that a frame reuses
 * few (and the GL backend few query objects), else a new one. */
static rl_status take_slot(rl_drawer *dr, uint32_t *slot)
{
    if (dr->num_free) {
        *slot = dr->free_slots[--dr->num_free];
        return RL_OK;
    }
    if (dr->num_slots >= RL_DRAWER_MAX_QUERIES)
        return rl_error(RL_ERR_LIMIT, "rl_drawer_query_issue: %u queries open, none read", dr->num_slots);
    if (dr->num_slots == dr->cap_slots) {
        uint32_t cap = dr->cap_slots ? 2 * dr->cap_slots : 64;
        uint8_t *open = realloc(dr->open, cap);
        if (!open)
            return RL_ERR_OUT_OF_MEMORY;
        dr->open = open;
        uint32_t *free_slots = realloc(dr->free_slots, cap * sizeof *free_slots);
        if (!free_slots)
            return RL_ERR_OUT_OF_MEMORY;
        dr->free_slots = free_slots;
        uint32_t *late = realloc(dr->late, cap * sizeof *late);
        if (!late)
            return RL_ERR_OUT_OF_MEMORY;
        dr->late = late;
        dr->cap_slots = cap;
    }
    *slot = dr->num_slots++;
    return RL_OK;
}

static rl_status open_slot(const rl_drawer *dr, uint32_t handle, const char *fn)
{
    if (handle < dr->num_slots && dr->open[handle] != SLOT_FREE)
        return RL_OK;
    return rl_error(RL_ERR_INVALID_ARG, "%s: query %u is not open in this frame", fn, handle);
}

rl_status rl_drawer_query_issue(rl_drawer *dr, const rl_raster_batch *boxes, uint32_t *handle,
                                rl_raster_counters *c)
{
    rl_status st = in_frame(dr, "rl_drawer_query_issue");
    if (st == RL_OK && (!boxes || !handle))
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_query_issue: NULL argument");
    uint32_t slot = 0;
    if (st == RL_OK)
        st = take_slot(dr, &slot);
    if (st != RL_OK)
        return st;
    st = dr->ops->query_issue(dr->impl, boxes, slot);
    if (st != RL_OK) {
        dr->free_slots[dr->num_free++] = slot;
        return st;
    }
    if (c)
        c->triangles_in += boxes->num_triangles;
    dr->open[slot] = SLOT_OPEN;
    dr->late[slot] = dr->desc.query_delay;
    *handle = slot;
    return RL_OK;
}

rl_status rl_drawer_query_poll(rl_drawer *dr, uint32_t handle, bool *ready)
{
    rl_status st = in_frame(dr, "rl_drawer_query_poll");
    if (st == RL_OK && !ready)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_query_poll: NULL argument");
    if (st == RL_OK)
        st = open_slot(dr, handle, "rl_drawer_query_poll");
    if (st != RL_OK)
        return st;
    if (dr->late[handle] > 0) {
        dr->late[handle]--;
        *ready = false;
        return RL_OK;
    }
    return dr->ops->query_poll(dr->impl, handle, ready);
}

rl_status rl_drawer_query_result(rl_drawer *dr, uint32_t handle, uint64_t *pixels)
{
    rl_status st = in_frame(dr, "rl_drawer_query_result");
    if (st == RL_OK && !pixels)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_query_result: NULL argument");
    if (st == RL_OK)
        st = open_slot(dr, handle, "rl_drawer_query_result");
    if (st != RL_OK)
        return st;
    *pixels = 0;
    st = dr->ops->query_result(dr->impl, handle, pixels);
    /* Read or failed, the slot is free again: a failed frame ends anyway. */
    dr->open[handle] = SLOT_FREE;
    dr->free_slots[dr->num_free++] = handle;
    return st;
}

rl_status rl_drawer_query_keep(rl_drawer *dr, uint32_t handle)
{
    rl_status st = in_frame(dr, "rl_drawer_query_keep");
    if (st == RL_OK)
        st = open_slot(dr, handle, "rl_drawer_query_keep");
    if (st == RL_OK)
        dr->open[handle] = SLOT_KEPT;
    return st;
}

rl_status rl_drawer_query(rl_drawer *dr, const rl_raster_batch *boxes, uint64_t *pixels, rl_raster_counters *c)
{
    rl_status st = in_frame(dr, "rl_drawer_query");
    if (st == RL_OK && (!boxes || !pixels))
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_query: NULL argument");
    uint32_t handle = 0;
    if (st == RL_OK)
        st = rl_drawer_query_issue(dr, boxes, &handle, c);
    return st == RL_OK ? rl_drawer_query_result(dr, handle, pixels) : st;
}

rl_status rl_drawer_draw_batch(rl_drawer *dr, const rl_raster_batch *batch, rl_raster_counters *c)
{
    rl_status st = in_frame(dr, "rl_drawer_draw_batch");
    if (st == RL_OK && !batch)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_batch: NULL batch");
    return st == RL_OK ? dr->ops->draw_batch(dr->impl, batch, c) : st;
}

rl_status rl_drawer_draw_points(rl_drawer *dr, const rl_raster_points *points, rl_raster_counters *c)
{
    rl_status st = in_frame(dr, "rl_drawer_draw_points");
    if (st == RL_OK && !points)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_points: NULL points");
    return st == RL_OK ? dr->ops->draw_points(dr->impl, points, c) : st;
}

rl_status rl_drawer_end(rl_drawer *dr)
{
    rl_status st = in_frame(dr, "rl_drawer_end");
    if (st != RL_OK)
        return st;
    dr->in_frame = false;
    drop_queries(dr, true);
    return dr->ops->end(dr->impl);
}

/* ---- the software backend ---- */

typedef struct software {
    rl_raster *ras;
    rl_scene_drawer *drawer;
    /* The frame, for rl_scene_drawer_finish at its end. */
    rl_image *target;
    rl_mat4 view, proj;
    bool points;                  /* points or caller batches drawn: IDs are
                                   * not all the scene's triangles as drawn */
    uint64_t *answers;            /* per query slot: answered at the issue */
    uint32_t cap_answers;
} software;

static void sw_release(void *impl)
{
    software *sw = impl;
    if (!sw)
        return;
    rl_scene_drawer_release(sw->drawer);
    rl_raster_release(sw->ras);
    free(sw->answers);
    free(sw);
}

static rl_status sw_begin(void *impl, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj, rl_vec3 eye)
{
    software *sw = impl;
    rl_scene_drawer_new_frame(sw->drawer, eye);
    sw->target = target;
    sw->view = *view;
    sw->proj = *proj;
    sw->points = false;
    return rl_raster_set_target(sw->ras, target, view, proj);
}

static void sw_light(void *impl, const uint32_t *objects, uint32_t count)
{
    software *sw = impl;
    rl_scene_drawer_light(sw->drawer, objects, count);
}

static rl_status sw_draw(void *impl, const uint32_t *objects, uint32_t count, rl_raster_counters *c)
{
    software *sw = impl;
    return rl_scene_drawer_draw_list(sw->drawer, sw->ras, objects, count, c);
}

static rl_status sw_draw_all(void *impl, rl_raster_counters *c, rl_progress_fn progress, void *user)
{
    software *sw = impl;
    return rl_scene_drawer_draw_all(sw->drawer, sw->ras, c, progress, user);
}

/* The software rasterizer answers at once: the answer waits in its slot. */
static rl_status sw_query_issue(void *impl, const rl_raster_batch *boxes, uint32_t slot)
{
    software *sw = impl;
    if (!rl_reserve_u32((void **)&sw->answers, &sw->cap_answers, (uint64_t)slot + 1, sizeof *sw->answers, 64))
        return RL_ERR_OUT_OF_MEMORY;
    sw->answers[slot] = 0;
    return rl_raster_query(sw->ras, boxes, &sw->answers[slot]);
}

static rl_status sw_query_poll(void *impl, uint32_t slot, bool *ready)
{
    (void)impl;
    (void)slot;
    *ready = true;
    return RL_OK;
}

static rl_status sw_query_result(void *impl, uint32_t slot, uint64_t *pixels)
{
    software *sw = impl;
    *pixels = sw->answers[slot];
    return RL_OK;
}

static rl_status sw_draw_batch(void *impl, const rl_raster_batch *batch, rl_raster_counters *c)
{
    software *sw = impl;
    /* Its pixels carry scene triangle IDs without the scene's shading:
     * the deferred normal-map pass must not shade them again. */
    sw->points = true;
    return rl_raster_draw(sw->ras, batch, c);
}

static rl_status sw_draw_points(void *impl, const rl_raster_points *points, rl_raster_counters *c)
{
    software *sw = impl;
    sw->points = true;
    return rl_raster_draw_points(sw->ras, points, c);
}

static rl_status sw_end(void *impl)
{
    software *sw = impl;
    if (!sw->points)
        rl_scene_drawer_finish(sw->drawer, sw->target, &sw->view, &sw->proj);
    return RL_OK;
}

static const rl_drawer_ops software_ops = {
    .name = "software",
    .release = sw_release,
    .begin = sw_begin,
    .light = sw_light,
    .draw = sw_draw,
    .draw_all = sw_draw_all,
    .query_issue = sw_query_issue,
    .query_poll = sw_query_poll,
    .query_result = sw_query_result,
    .draw_batch = sw_draw_batch,
    .draw_points = sw_draw_points,
    .end = sw_end,
};

rl_status rl_drawer_create(const rl_scene *scene, const rl_drawer_desc *desc, rl_drawer **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_create: NULL argument");
    *out = NULL;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_drawer_create: the scene is not committed");
    software *sw = rl_calloc(1, sizeof *sw);
    if (!sw)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st = rl_raster_create(&(rl_raster_desc){ .threads = desc ? desc->threads : 0 }, &sw->ras);
    if (st == RL_OK)
        st = rl_scene_drawer_create(d, rl_v3s(0.0f), desc, &sw->drawer);
    if (st != RL_OK) {
        sw_release(sw);
        return st;
    }
    return rl_drawer_make(&software_ops, sw, scene, desc, out);
}
