/* linespace_object.c: object Line Spaces (Schröder 2017, Sec. 13.2, an
 * outlook the thesis proposes after K. Keul): a Line Space per object
 * instead of per voxel of the scene, so that a ray first meets the
 * object's bounding box and then tests only the few triangles of one shaft.
 *
 * Per mesh, one per-voxel Line Space (rl_linespace.h, dynamic candidate
 * lists) on a grid of `res` voxels per axis over the mesh in object space:
 * the instance's flattened world triangles mapped back by the inverse of
 * its transform, in double, so that the object-space triangle is the exact
 * affine image of the world one up to one float rounding of its vertices.
 * Instances of a mesh whose object-space vertices agree (within 1e-5 of the
 * object's size) share the first one's Line Space: that is the thesis'
 * point that an object may move without a rebuild, here for instances of
 * one mesh at different places (a committed rl_scene is immutable, so a
 * moved object is a new scene and a new rl_ls_objects; docs/line-space.md).
 *
 * Top level: a binary BVH over the instances' world boxes (median split on
 * the longest axis of the centroids), walked near child first. In an
 * instance the world ray is mapped into object space (in double, its
 * origin moved to where it enters the box), the object's grid is walked
 * with the Line Space's shafts, and every candidate is tested in world
 * space against the scene's own triangle with the shared watertight test:
 * the closest hit and ties (lower ID) are the BVH's. Deviations: an
 * instance whose transform cannot be inverted gets a Line Space of its own
 * built in world space; an instance whose triangles do not survive the
 * trip to object space unchanged (the scene drops a triangle that became
 * degenerate) is tested triangle by triangle. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel_internal.h"
#include "accel/linespace_internal.h"
#include "core/error.h"
#include "rl/rl_scene.h"
#include "rl/rl_timer.h"
#include "scene/masks.h"

#define SHARE_TOL_REL 1e-5        /* object-space vertices that count as the same mesh */
#define BOX_GROW_REL 1e-5f        /* instance boxes, against rounding of the box test */
#define SLACK_REL 1e-5f           /* object-space vs world t, see rl_ls_local_ray */
#define LEAF_SIZE 2
#define STACK_SIZE 64

/* One built Line Space, shared by the instances of one mesh. */
typedef struct ls_entry {
    rl_scene *scene;              /* the mesh in object space (or world space) */
    rl_accel *grid;
    rl_linespace *ls;
    uint32_t mesh, num_vertices, num_triangles;
    bool world;                   /* built in world space: identity transform */
    rl_vec3 *local;               /* its object-space vertices, for sharing */
    double diag;                  /* their box's diagonal */
} ls_entry;

typedef struct instance {
    uint32_t entry;               /* RL_NONE: tested triangle by triangle */
    uint32_t first_triangle, num_triangles;
    rl_aabb box;                  /* world, grown by BOX_GROW_REL */
    double inv[3][4];             /* world -> object (identity for world entries) */
} instance;

typedef struct top_node {
    rl_aabb box;
    uint32_t first;               /* leaf: first index into order; inner: left child */
    uint32_t count;               /* leaf: instances; 0: inner, right = first + 1 */
} top_node;

struct rl_ls_objects {
    const rl_scene *scene;
    const rl_scene_data *data;
    int n, res, threads;
    bool committed, masked;
    ls_entry *entries;
    uint32_t num_entries;
    instance *inst;
    uint32_t num_inst;
    uint32_t *order;              /* instances in top-level leaf order */
    top_node *nodes;
    uint32_t num_nodes;
    rl_vec3 *verts;               /* 3 world vertices per scene triangle */
    rl_ls_objects_stats stats;
};

rl_status rl_ls_objects_create(const rl_scene *scene, const rl_ls_objects_desc *desc, rl_ls_objects **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_ls_objects_create: NULL scene or out");
    *out = NULL;
    const rl_scene_data *data = rl_scene_is_committed(scene) ? rl_scene_get_data(scene) : NULL;
    if (!data)
        return rl_error(RL_ERR_INVALID_ARG, "object Line Space: the scene is not committed");
    rl_ls_objects_desc d = desc ? *desc : (rl_ls_objects_desc){ 0 };
    int n = d.n ? d.n : RL_LS_DEFAULT_N, res = d.res ? d.res : RL_LS_OBJECT_DEFAULT_RES;
    if (n < 1 || n > RL_LS_MAX_N)
        return rl_error(RL_ERR_INVALID_ARG, "object Line Space: n = %d not in 1..%d", d.n, RL_LS_MAX_N);
    if (res < 1 || res > RL_LS_OBJECT_MAX_RES)
        return rl_error(RL_ERR_INVALID_ARG, "object Line Space: res = %d not in 1..%d", d.res,
                        RL_LS_OBJECT_MAX_RES);
    if (d.threads < 0)
        return rl_error(RL_ERR_INVALID_ARG, "object Line Space: threads %d < 0", d.threads);
    rl_ls_objects *o = rl_calloc(1, sizeof *o);
    if (!o)
        return RL_ERR_OUT_OF_MEMORY;
    o->scene = scene;
    o->data = data;
    o->n = n;
    o->res = res;
    o->threads = d.threads;
    o->masked = rl_data_has_masks(data);
    o->stats.n = n;
    o->stats.res = res;
    *out = o;
    return RL_OK;
}

/* Everything commit builds, so that a failed commit can be retried. */
static void free_built(rl_ls_objects *o)
{
    for (uint32_t i = 0; i < o->num_entries; ++i) {
        rl_linespace_release(o->entries[i].ls);   /* before the grid it borrows */
        rl_accel_release(o->entries[i].grid);
        rl_scene_release(o->entries[i].scene);
        free(o->entries[i].local);
    }
    free(o->entries);
    free(o->inst);
    free(o->order);
    free(o->nodes);
    free(o->verts);
    o->entries = NULL;
    o->inst = NULL;
    o->order = NULL;
    o->nodes = NULL;
    o->verts = NULL;
    o->num_entries = o->num_inst = o->num_nodes = 0;
    int n = o->stats.n, res = o->stats.res;
    o->stats = (rl_ls_objects_stats){ .n = n, .res = res };
}

void rl_ls_objects_release(rl_ls_objects *o)
{
    if (!o)
        return;
    free_built(o);
    free(o);
}

void rl_ls_objects_get_stats(const rl_ls_objects *o, rl_ls_objects_stats *out)
{
    if (out)
        *out = o ? o->stats : (rl_ls_objects_stats){ 0 };
}

static void to_local(const double m[3][4], rl_vec3 p, double q[3])
{
    for (int r = 0; r < 3; ++r)
        q[r] = m[r][0] * p.x + m[r][1] * p.y + m[r][2] * p.z + m[r][3];
}

/* The instance's vertices in object space (its entry's frame). */
static rl_vec3 *local_vertices(const rl_ls_objects *o, const rl_object *obj, const double m[3][4])
{
    rl_vec3 *v = rl_calloc(obj->num_vertices ? obj->num_vertices : 1, sizeof *v);
    if (!v)
        return NULL;
    for (uint32_t i = 0; i < obj->num_vertices; ++i) {
        double q[3];
        to_local(m, o->data->positions[obj->first_vertex + i], q);
        v[i] = rl_v3((float)q[0], (float)q[1], (float)q[2]);
    }
    return v;
}

static double box_diag(const rl_vec3 *v, uint32_t n)
{
    rl_aabb b = rl_aabb_empty();
    for (uint32_t i = 0; i < n; ++i)
        b = rl_aabb_grow(b, v[i]);
    return rl_length(rl_aabb_extent(b));
}

/* An existing entry this instance's object-space mesh equals. */
static uint32_t find_shared(const rl_ls_objects *o, const rl_object *obj, const rl_vec3 *local)
{
    for (uint32_t e = 0; e < o->num_entries; ++e) {
        const ls_entry *en = &o->entries[e];
        if (en->world || en->mesh != obj->mesh || en->num_vertices != obj->num_vertices ||
            en->num_triangles != obj->num_triangles)
            continue;
        double tol = SHARE_TOL_REL * (en->diag > 0.0 ? en->diag : 1.0);
        uint32_t i = 0;
        while (i < obj->num_vertices && fabs((double)local[i].x - en->local[i].x) <= tol &&
               fabs((double)local[i].y - en->local[i].y) <= tol && fabs((double)local[i].z - en->local[i].z) <= tol)
            ++i;
        if (i == obj->num_vertices)
            return e;
    }
    return RL_NONE;
}

/* The mesh in its own scene and its Line Space. RL_ERR_EMPTY_SCENE (no
 * error recorded) when the scene dropped triangles on the way, which would
 * renumber them: the caller then tests that instance's triangles itself. */
static rl_status build_entry(rl_ls_objects *o, const rl_object *obj, ls_entry *en)
{
    const rl_scene_data *d = o->data;
    uint32_t *idx = rl_calloc(3 * (size_t)obj->num_triangles, sizeof *idx);
    if (!idx)
        return RL_ERR_OUT_OF_MEMORY;
    for (size_t i = 0; i < 3 * (size_t)obj->num_triangles; ++i)
        idx[i] = d->indices[3 * (size_t)obj->first_triangle + i] - obj->first_vertex;
    rl_scene *s = NULL;
    rl_material m = rl_material_default();
    uint32_t mat, mesh, node;
    rl_mesh_desc md = { .name = "object", .num_vertices = obj->num_vertices, .positions = en->local,
                        .num_triangles = obj->num_triangles, .indices = idx };
    rl_status st = rl_scene_create(&s);
    if (st == RL_OK)
        st = rl_scene_add_material(s, &m, &mat);
    md.material = mat;
    if (st == RL_OK)
        st = rl_scene_add_mesh(s, &md, &mesh);
    if (st == RL_OK)
        st = rl_scene_add_node(s, 0, "object", NULL, &node);
    if (st == RL_OK)
        st = rl_scene_node_set_mesh(s, node, mesh);
    free(idx);
    if (st == RL_OK) {
        rl_scene_stats ss;
        rl_scene_get_stats(s, &ss);
        if (ss.dropped_degenerate || ss.dropped_nonfinite) {
            rl_scene_release(s);
            return RL_ERR_EMPTY_SCENE;
        }
        st = rl_scene_commit(s);
    }
    if (st == RL_ERR_EMPTY_SCENE)
        rl_clear_error();
    en->scene = s;
    if (st != RL_OK)
        return st;
    /* A flat axis gets one voxel: more would only repeat its lists. */
    rl_vec3 ext = rl_aabb_extent(rl_scene_get_data(s)->bounds);
    float big = rl_vmax_comp(ext);
    rl_accel_desc gd = { .kind = RL_ACCEL_GRID, .threads = o->threads };
    for (int a = 0; a < 3; ++a)
        gd.grid_res[a] = rl_vget(ext, a) > 1e-3f * big ? o->res : 1;
    if ((st = rl_accel_create(s, &gd, &en->grid)) != RL_OK || (st = rl_accel_commit(en->grid)) != RL_OK)
        return st;
    rl_linespace_desc ld = { .n = o->n, .dynamic = true, .payloads = RL_LS_CANDIDATES, .threads = o->threads };
    if ((st = rl_linespace_create(en->grid, &ld, &en->ls)) != RL_OK || (st = rl_linespace_commit(en->ls)) != RL_OK)
        return st;
    rl_linespace_stats ls;
    rl_linespace_get_stats(en->ls, &ls);
    o->stats.shafts += ls.shafts;
    o->stats.candidates += ls.candidates;
    o->stats.memory_bytes += ls.memory_bytes;
    rl_accel_stats as;
    rl_accel_get_stats(en->grid, &as);
    o->stats.memory_bytes += as.memory_bytes + (size_t)obj->num_vertices * sizeof(rl_vec3);
    return RL_OK;
}

static void set_identity(double m[3][4])
{
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 4; ++c)
            m[r][c] = r == c ? 1.0 : 0.0;
}

/* The largest |coordinate| of b: what float rounding scales with. */
static float max_abs(rl_aabb b)
{
    return rl_vmax_comp(rl_vmax(rl_vmax(b.min, rl_neg(b.min)), rl_vmax(b.max, rl_neg(b.max))));
}

static rl_status add_instance(rl_ls_objects *o, uint32_t object)
{
    const rl_object *obj = &o->data->objects[object];
    instance *in = &o->inst[o->num_inst++];
    in->first_triangle = obj->first_triangle;
    in->num_triangles = obj->num_triangles;
    rl_vec3 ext = rl_aabb_extent(obj->bounds);
    float grow = BOX_GROW_REL * rl_maxf(rl_length(ext), max_abs(obj->bounds));
    in->box.min = rl_sub(obj->bounds.min, rl_v3s(grow));
    in->box.max = rl_add(obj->bounds.max, rl_v3s(grow));
    rl_mat4 inv;
    bool world = !rl_mat4_invert(&obj->world, &inv);
    if (world)
        set_identity(in->inv);
    else
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 4; ++c)
                in->inv[r][c] = inv.m[r][c];
    rl_vec3 *local = local_vertices(o, obj, in->inv);
    if (!local)
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t e = world ? RL_NONE : find_shared(o, obj, local);
    if (e != RL_NONE) {
        free(local);
        in->entry = e;
        return RL_OK;
    }
    ls_entry *en = &o->entries[o->num_entries];
    memset(en, 0, sizeof *en);
    en->mesh = obj->mesh;
    en->num_vertices = obj->num_vertices;
    en->num_triangles = obj->num_triangles;
    en->world = world;
    en->local = local;
    en->diag = box_diag(local, obj->num_vertices);
    rl_status st = build_entry(o, obj, en);
    if (st == RL_ERR_EMPTY_SCENE) {
        free(en->local);
        rl_scene_release(en->scene);
        in->entry = RL_NONE;
        return RL_OK;
    }
    o->num_entries++;               /* released with the rest, also on failure */
    in->entry = o->num_entries - 1;
    o->stats.world_space += world;
    return st;
}

static rl_vec3 centroid(const instance *in) { return rl_aabb_center(in->box); }

/* The top level over order[first .. first+count), node `at` already taken. */
static void build_top(rl_ls_objects *o, uint32_t at, uint32_t first, uint32_t count)
{
    top_node *nd = &o->nodes[at];
    nd->box = rl_aabb_empty();
    rl_aabb cb = rl_aabb_empty();
    for (uint32_t i = first; i < first + count; ++i) {
        nd->box = rl_aabb_union(nd->box, o->inst[o->order[i]].box);
        cb = rl_aabb_grow(cb, centroid(&o->inst[o->order[i]]));
    }
    if (count <= LEAF_SIZE) {
        nd->first = first;
        nd->count = count;
        return;
    }
    rl_vec3 e = rl_aabb_extent(cb);
    int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
    /* Median split: a partial selection sort is enough for the few
     * instances a scene has; the depth stays log2(count). */
    uint32_t half = count / 2;
    for (uint32_t i = 0; i < half; ++i) {
        uint32_t best = first + i;
        for (uint32_t j = first + i + 1; j < first + count; ++j)
            if (rl_vget(centroid(&o->inst[o->order[j]]), axis) < rl_vget(centroid(&o->inst[o->order[best]]), axis))
                best = j;
        uint32_t t = o->order[first + i];
        o->order[first + i] = o->order[best];
        o->order[best] = t;
    }
    uint32_t left = o->num_nodes;
    o->num_nodes += 2;
    nd->first = left;
    nd->count = 0;
    build_top(o, left, first, half);
    build_top(o, left + 1, first + half, count - half);
}

rl_status rl_ls_objects_commit(rl_ls_objects *o)
{
    if (!o)
        return rl_error(RL_ERR_INVALID_ARG, "rl_ls_objects_commit: NULL");
    if (o->committed)
        return RL_OK;
    rl_timer timer;
    rl_timer_start(&timer);
    const rl_scene_data *d = o->data;
    uint32_t no = d->num_objects;
    o->entries = rl_calloc(no ? no : 1, sizeof *o->entries);
    o->inst = rl_calloc(no ? no : 1, sizeof *o->inst);
    o->order = rl_calloc(no ? no : 1, sizeof *o->order);
    o->nodes = rl_calloc(no ? 2 * (size_t)no : 1, sizeof *o->nodes);
    o->verts = rl_calloc(3 * (size_t)(d->num_triangles ? d->num_triangles : 1), sizeof *o->verts);
    if (!o->entries || !o->inst || !o->order || !o->nodes || !o->verts) {
        free_built(o);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t t = 0; t < d->num_triangles; ++t)
        for (int k = 0; k < 3; ++k)
            o->verts[3 * (size_t)t + k] = d->positions[d->indices[3 * (size_t)t + k]];
    rl_status st = RL_OK;
    for (uint32_t i = 0; i < no && st == RL_OK; ++i)
        if (d->objects[i].num_triangles > 0)
            st = add_instance(o, i);
    if (st != RL_OK) {
        free_built(o);
        return st;
    }
    for (uint32_t i = 0; i < o->num_inst; ++i)
        o->order[i] = i;
    if (o->num_inst > 0) {
        o->num_nodes = 1;
        build_top(o, 0, 0, o->num_inst);
    }
    o->committed = true;
    o->stats.objects = o->num_inst;
    o->stats.linespaces = o->num_entries;
    o->stats.memory_bytes += (size_t)d->num_triangles * 3 * sizeof(rl_vec3) +
                             (size_t)o->num_inst * (sizeof(instance) + sizeof(uint32_t)) +
                             (size_t)o->num_nodes * sizeof(top_node);
    o->stats.build_ms = rl_timer_ms(&timer);
    return RL_OK;
}

static bool ray_ok(const rl_ray *r)
{
    if (!rl_vfinite(r->o) || !rl_vfinite(r->d) || !isfinite(r->t_min) || isnan(r->t_max))
        return false;
    return (r->d.x != 0.0f || r->d.y != 0.0f || r->d.z != 0.0f) && r->t_min <= r->t_max;
}

/* The world ray in the instance's object space from t_enter on. */
static void local_ray(const instance *in, const rl_ray *ray, float t_enter, float t_exit, rl_ls_local_ray *lr)
{
    rl_vec3 p = rl_ray_at(ray, t_enter);
    to_local(in->inv, p, lr->o);
    for (int r = 0; r < 3; ++r)
        lr->d[r] = in->inv[r][0] * ray->d.x + in->inv[r][1] * ray->d.y + in->inv[r][2] * ray->d.z;
    lr->t_shift = t_enter;
    float dl = rl_length(ray->d);
    float coord = max_abs(in->box);
    lr->slack = SLACK_REL * (fabsf(t_enter) + fabsf(t_exit - t_enter) + coord / dl);
}

static void brute_closest(const rl_ls_objects *o, const instance *in, const rl_ray_watertight *w, float t_min,
                          rl_tri_closest *best, float *limit)
{
    for (uint32_t t = in->first_triangle; t < in->first_triangle + in->num_triangles; ++t) {
        const rl_vec3 *v = o->verts + 3 * (size_t)t;
        float th, u, vv;
        if (rl_watertight_hit(w, v[0], v[1], v[2], t_min, *limit, &th, &u, &vv) &&
            (best->id == RL_ID_NONE || th < best->t || (th == best->t && t < best->id))) {
            *best = (rl_tri_closest){ t, th, u, vv };
            *limit = nextafterf(th, INFINITY);
        }
    }
}

/* Front-to-back walk of the top level; any = stop at the first hit. */
static bool walk(const rl_ls_objects *o, const rl_ray *ray, bool any, rl_tri_closest *best)
{
    if (o->num_nodes == 0)
        return false;
    rl_ray_watertight w;
    rl_ray_watertight_setup(ray, &w);
    rl_mailbox mailbox;
    rl_mailbox_init(&mailbox);
    float limit = ray->t_max;
    uint32_t stack[STACK_SIZE];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const top_node *nd = &o->nodes[stack[--top]];
        rl_ray r = *ray;
        r.t_max = limit;
        float t0, t1;
        if (!rl_aabb_intersect_ray(nd->box, &r, &t0, &t1))
            continue;
        if (nd->count == 0) {
            float ta, tb, ua, ub;
            bool ha = rl_aabb_intersect_ray(o->nodes[nd->first].box, &r, &ta, &ua);
            bool hb = rl_aabb_intersect_ray(o->nodes[nd->first + 1].box, &r, &tb, &ub);
            uint32_t near = nd->first, far = nd->first + 1;
            if (ha && hb && tb < ta) {
                near = far;
                far = nd->first;
            }
            /* Depth is log2(instances) + 1, far below the stack. */
            if ((near == nd->first ? hb : ha) && top < STACK_SIZE)
                stack[top++] = far;
            if ((near == nd->first ? ha : hb) && top < STACK_SIZE)
                stack[top++] = near;
            continue;
        }
        for (uint32_t k = nd->first; k < nd->first + nd->count; ++k) {
            const instance *in = &o->inst[o->order[k]];
            r.t_max = limit;
            float te, tx;
            if (!rl_aabb_intersect_ray(in->box, &r, &te, &tx))
                continue;
            if (in->entry == RL_NONE) {
                brute_closest(o, in, &w, ray->t_min, best, &limit);
            } else {
                rl_ls_local_ray lr;
                local_ray(in, ray, te, tx, &lr);
                const rl_linespace *ls = o->entries[in->entry].ls;
                if (any) {
                    if (rl_ls_mapped_any(ls, &lr, o->verts, in->first_triangle, &w, ray->t_min, ray->t_max, &mailbox))
                        return true;
                    continue;
                }
                rl_ls_mapped_closest(ls, &lr, o->verts, in->first_triangle, &w, ray->t_min, &mailbox, best, &limit);
            }
            if (any && best->id != RL_ID_NONE)
                return true;
        }
    }
    return best->id != RL_ID_NONE;
}

/* The closest hit, holes of alpha masks included (an rl_closest_hit_fn:
 * state is the rl_ls_objects). */
static bool closest_hit(const void *state, rl_ray *ray, rl_hit *hit)
{
    const rl_ls_objects *o = state;
    rl_tri_closest best = { RL_ID_NONE, ray->t_max, 0.0f, 0.0f };
    if (!walk(o, ray, false, &best))
        return false;
    ray->t_max = best.t;
    hit->t = best.t;
    hit->u = best.u;
    hit->v = best.v;
    hit->triangle = best.id;
    hit->object = o->data->triangle_object[best.id];
    return true;
}

/* Alpha masks as rl_accel_intersect (rl_closest_unmasked_hit). */
bool rl_ls_objects_intersect(const rl_ls_objects *o, rl_ray *ray, rl_hit *hit)
{
    if (!o || !ray || !hit || !o->committed || !ray_ok(ray))
        return false;
    hit->triangle = hit->object = RL_ID_NONE;
    return rl_closest_unmasked_hit(o->data, o->masked, closest_hit, o, ray, hit);
}

bool rl_ls_objects_occluded(const rl_ls_objects *o, const rl_ray *ray)
{
    if (!o || !ray || !o->committed || !ray_ok(ray))
        return false;
    if (o->masked) {
        rl_ray r = *ray;
        rl_hit h;
        return rl_ls_objects_intersect(o, &r, &h);
    }
    rl_tri_closest best = { RL_ID_NONE, ray->t_max, 0.0f, 0.0f };
    return walk(o, ray, true, &best);
}

/* For the scene Line Space (linespace_scene.c): the scene it serves. */
const rl_scene *rl_ls_objects_scene(const rl_ls_objects *o) { return o ? o->scene : NULL; }
bool rl_ls_objects_committed(const rl_ls_objects *o) { return o && o->committed; }
