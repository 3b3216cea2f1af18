/* culling.c: see culling.h. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#ifdef _OPENMP
#include <omp.h>
#endif
#include "render/culling.h"
#include "render/renderer.h"
#include "rl/rl_gl.h"

void rl_cull_view_make(const rl_camera *cam, rl_aabb scene_bounds, rl_cull_view *v)
{
    memset(v, 0, sizeof *v);
    v->cam = rl_camera_resolve(cam);
    v->eye = v->cam.eye;
    float z_near = v->cam.z_near, z_far = v->cam.z_far;
    if (!(z_near > 0.0f))
        rl_camera_clip_range(&v->cam, scene_bounds, &z_near, &z_far);
    v->z_near = z_near;
    v->z_far = z_far;
    v->view = rl_camera_view(&v->cam);
    v->proj = rl_camera_projection(&v->cam, z_near, z_far);
    v->view_proj = rl_mat4_mul(&v->proj, &v->view);

    /* Gribb & Hartmann 2001: the clip planes are sums and differences of
     * the rows of the view-projection (column vectors, -w <= x,y,z <= w). */
    const float(*m)[4] = v->view_proj.m;
    for (int i = 0; i < 6; ++i) {
        int row = i / 2;
        float s = (i & 1) ? -1.0f : 1.0f;
        rl_vec4 p = { m[3][0] + s * m[row][0], m[3][1] + s * m[row][1], m[3][2] + s * m[row][2],
                      m[3][3] + s * m[row][3] };
        float len = sqrtf(p.x * p.x + p.y * p.y + p.z * p.z);
        if (len > 0.0f)
            p = (rl_vec4){ p.x / len, p.y / len, p.z / len, p.w / len };
        v->planes[i] = p;
    }
    float ty = tanf(0.5f * rl_radians(v->cam.fov_deg));
    float tx = ty * (float)v->cam.width / (float)v->cam.height;
    v->near_radius = z_near * sqrtf(1.0f + tx * tx + ty * ty);
}

bool rl_cull_box_in_frustum(const rl_cull_view *v, rl_aabb b)
{
    for (int i = 0; i < 6; ++i) {
        const rl_vec4 p = v->planes[i];
        /* The box corner farthest along the plane normal. */
        rl_vec3 c = { p.x >= 0.0f ? b.max.x : b.min.x, p.y >= 0.0f ? b.max.y : b.min.y,
                      p.z >= 0.0f ? b.max.z : b.min.z };
        float dist = p.x * c.x + p.y * c.y + p.z * c.z + p.w;
        /* A small slack: a box touching a plane is kept. */
        if (dist < -1e-5f * (fabsf(p.w) + 1.0f))
            return false;
    }
    return true;
}

float rl_cull_box_distance(rl_vec3 eye, rl_aabb b)
{
    float dx = rl_maxf(rl_maxf(b.min.x - eye.x, 0.0f), eye.x - b.max.x);
    float dy = rl_maxf(rl_maxf(b.min.y - eye.y, 0.0f), eye.y - b.max.y);
    float dz = rl_maxf(rl_maxf(b.min.z - eye.z, 0.0f), eye.z - b.max.z);
    return sqrtf(dx * dx + dy * dy + dz * dz);
}

bool rl_cull_box_near_eye(const rl_cull_view *v, rl_aabb b)
{
    return rl_cull_box_distance(v->eye, b) <= 2.0f * v->near_radius;
}

void rl_box_query_reset(rl_box_query *q)
{
    q->boxes = 0;
}

rl_aabb rl_box_query_bounds(rl_aabb b, float margin)
{
    rl_vec3 e = rl_aabb_extent(b);
    float grow = margin * rl_maxf(rl_maxf(e.x, e.y), e.z) + 1e-6f;
    return (rl_aabb){ rl_sub(b.min, rl_v3s(grow)), rl_add(b.max, rl_v3s(grow)) };
}

rl_status rl_box_query_add(rl_box_query *q, rl_aabb b, float margin)
{
    if (q->boxes == q->cap_boxes) {
        size_t cap = q->cap_boxes ? 2 * q->cap_boxes : 64;
        rl_vec3 *p = realloc(q->positions, cap * 8 * sizeof *p);
        if (!p)
            return RL_ERR_OUT_OF_MEMORY;
        q->positions = p;
        uint32_t *ix = realloc(q->indices, cap * 36 * sizeof *ix);
        if (!ix)
            return RL_ERR_OUT_OF_MEMORY;
        q->indices = ix;
        q->cap_boxes = cap;
    }
    b = rl_box_query_bounds(b, margin);
    rl_vec3 *p = q->positions + (size_t)q->boxes * 8;
    for (int i = 0; i < 8; ++i)
        p[i] = rl_v3((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z);
    /* Counter-clockwise seen from outside, so that back faces can be culled. */
    static const uint32_t faces[36] = { 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                                        2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5 };
    uint32_t *ix = q->indices + (size_t)q->boxes * 36;
    for (int i = 0; i < 36; ++i)
        ix[i] = q->boxes * 8 + faces[i];
    q->boxes++;
    return RL_OK;
}

rl_status rl_box_query_run(rl_box_query *q, rl_drawer *dr, uint64_t *pixels, rl_raster_counters *c)
{
    *pixels = 0;
    if (q->boxes == 0)
        return RL_OK;
    rl_raster_batch batch;
    memset(&batch, 0, sizeof batch);
    batch.num_vertices = q->boxes * 8;
    batch.positions = q->positions;
    batch.num_triangles = q->boxes * 12;
    batch.indices = q->indices;
    batch.flags = RL_RASTER_CULL_BACK;
    return rl_drawer_query(dr, &batch, pixels, c);
}

rl_status rl_box_query_issue(rl_box_query *q, rl_drawer *dr, uint32_t *handle, rl_raster_counters *c)
{
    rl_raster_batch batch;
    memset(&batch, 0, sizeof batch);
    batch.num_vertices = q->boxes * 8;
    batch.positions = q->positions;
    batch.num_triangles = q->boxes * 12;
    batch.indices = q->indices;
    batch.flags = RL_RASTER_CULL_BACK;
    return rl_drawer_query_issue(dr, &batch, handle, c);
}

void rl_box_query_free(rl_box_query *q)
{
    free(q->positions);
    free(q->indices);
    memset(q, 0, sizeof *q);
}

rl_status rl_cull_target_begin(rl_image *image, rl_vec3 background, rl_cull_target *t)
{
    memset(t, 0, sizeof *t);
    t->image = *image;
    size_t num_pixels = (size_t)image->width * (size_t)image->height;
    if (!(t->image.layers & RL_LAYER_DEPTH) || !t->image.depth) {
        t->own_depth = rl_calloc(num_pixels ? num_pixels : 1, sizeof *t->own_depth);
        if (!t->own_depth)
            return RL_ERR_OUT_OF_MEMORY;
        t->image.depth = t->own_depth;
        t->image.layers |= RL_LAYER_DEPTH;
    }
    if (!(t->image.layers & RL_LAYER_ID) || !t->image.object_id || !t->image.triangle_id)
        t->flags |= RL_RASTER_NO_ID;
    rl_image_clear_to(&t->image, rl_v4_from3(background, 1.0f));
    return RL_OK;
}

void rl_cull_target_end(rl_cull_target *t)
{
    free(t->own_depth);
    t->own_depth = NULL;
}

static bool renderer_progress(void *user, double done)
{
    return rl_renderer_progress((const rl_renderer *)user, done);
}

rl_status rl_cull_draw_all(rl_renderer *r, rl_drawer *dr, rl_cull_target *t, const rl_camera *cam, rl_aabb bounds,
                           rl_render_stats *stats)
{
    rl_raster_counters counters;
    memset(&counters, 0, sizeof counters);
    rl_status st = rl_drawer_begin_camera(dr, &t->image, cam, bounds);
    if (st == RL_OK)
        st = rl_drawer_draw_all(dr, &counters, renderer_progress, r);
    if (st == RL_OK)
        st = rl_drawer_end(dr);
    if (st != RL_OK)
        return st;
    stats->triangles_rasterized = counters.triangles_drawn;
    stats->pixels_written = counters.pixels_written;
    stats->samples = (uint64_t)t->image.width * (uint64_t)t->image.height;
    return RL_OK;
}

rl_status rl_octree_cache_get(rl_octree_cache *c, const rl_scene *scene, const rl_octree_desc *desc,
                              bool *rebuilt)
{
    *rebuilt = false;
    uint64_t uid = rl_scene_uid(scene);
    if (c->tree && c->scene_uid == uid && memcmp(&c->desc, desc, sizeof *desc) == 0)
        return RL_OK;
    rl_octree_release(c->tree);
    c->tree = NULL;
    rl_status st = rl_octree_build(scene, desc, &c->tree);
    if (st != RL_OK)
        return st;
    c->scene_uid = uid;
    c->desc = *desc;
    *rebuilt = true;
    return RL_OK;
}

void rl_octree_cache_release(rl_octree_cache *c)
{
    rl_octree_release(c->tree);
    memset(c, 0, sizeof *c);
}

static bool is_culling_renderer(const rl_renderer *r)
{
    static const char *const names[] = { "chcpp", "svs", "visset", "surfels", "select" };
    for (size_t i = 0; r && i < sizeof names / sizeof names[0]; ++i)
        if (strcmp(rl_renderer_name(r), names[i]) == 0)
            return true;
    return false;
}

const rl_culling_stats *rl_cull_stats_of(const rl_renderer *r)
{
    const rl_culling_head *h = is_culling_renderer(r) ? rl_renderer_state(r) : NULL;
    return h && h->have_frame ? &h->stats : NULL;
}

rl_status rl_culling_get_stats(const rl_renderer *r, rl_culling_stats *out)
{
    if (!is_culling_renderer(r) || !out)
        return rl_error(RL_ERR_INVALID_ARG,
                        "rl_culling_get_stats: needs a chcpp, svs, visset, surfels or select renderer and out");
    const rl_culling_stats *stats = rl_cull_stats_of(r);
    if (!stats)
        return rl_error(RL_ERR_INVALID_ARG, "rl_culling_get_stats: no frame rendered yet");
    *out = *stats;
    return RL_OK;
}

const char *const rl_cull_shading_choices[] = { "flat", "gouraud", "textured", NULL };
const char *const rl_cull_drawer_choices[] = { "software", "gl", NULL };

bool rl_cull_available(const rl_renderer *r, char *why, size_t n)
{
    if (rl_renderer_opt_enum(r, "drawer") != RL_CULL_DRAWER_GL)
        return true;
    return rl_gl_available(rl_renderer_opt_string(r, "device"), why, n);
}

/* A new drawer for desc on the backend the options ask for. */
static rl_status make_drawer(rl_renderer *r, const rl_scene *scene, const rl_drawer_desc *desc,
                             rl_culling_head *head)
{
    head->device[0] = head->info[0] = '\0';
    if (rl_renderer_opt_enum(r, "drawer") != RL_CULL_DRAWER_GL)
        return rl_drawer_create(scene, desc, &head->drawer);
    const char *device = rl_renderer_opt_string(r, "device");
    if (strlen(device) >= sizeof head->device)
        return rl_error(RL_ERR_INVALID_ARG, "%s: device \"%.40s...\" is too long", rl_renderer_name(r), device);
    rl_status st = rl_gl_drawer_create(scene, desc, device, &head->drawer);
    if (st != RL_OK)
        return st;
    snprintf(head->device, sizeof head->device, "%s", device);
    rl_gl_info info;
    if (rl_gl_info_get(device, &info) == RL_OK)
        snprintf(head->info, sizeof head->info, "%s | %s | %s", info.vendor, info.renderer, info.version);
    return RL_OK;
}

/* Whether the kept drawer is on the backend and device the options ask for. */
static bool same_backend(rl_renderer *r, const rl_culling_head *head)
{
    const bool gl = rl_renderer_opt_enum(r, "drawer") == RL_CULL_DRAWER_GL;
    if (strcmp(rl_drawer_backend(head->drawer), gl ? "gl" : "software") != 0)
        return false;
    return !gl || strcmp(head->device, rl_renderer_opt_string(r, "device")) == 0;
}

rl_status rl_cull_frame_begin(rl_renderer *r, const rl_scene *scene, rl_culling_head *head, const rl_camera *cam,
                              rl_image *image, bool deferred, rl_cull_frame *f)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    memset(f, 0, sizeof *f);
    f->threads_opt = (int)rl_renderer_opt_int(r, "threads");
#ifdef _OPENMP
    f->threads = f->threads_opt > 0 ? f->threads_opt : omp_get_max_threads();
#else
    f->threads = 1;
#endif
    f->ambient = (float)rl_renderer_opt_float(r, "ambient");
    rl_drawer_desc desc = {
        .shading = (rl_raster_shading)rl_renderer_opt_enum(r, "shading"),
        .ambient = f->ambient,
        .threads = f->threads_opt,
        .flags = rl_renderer_opt_bool(r, "cull") ? RL_RASTER_CULL_BACK : 0u,
        .deferred_counts = deferred,
        .query_delay = head->query_delay,
    };
    rl_status st = rl_cull_target_begin(image, rl_renderer_opt_color(r, "background"), &f->target);
    if (st != RL_OK)
        return st;
    desc.flags |= f->target.flags;
    rl_cull_view_make(cam, d->bounds, &f->view);
    /* The drawer is kept while the scene and options stay: its buffers
     * span the whole scene (and a GL drawer's context is costly). */
    if (!rl_drawer_fits(head->drawer, scene, &desc) || !same_backend(r, head)) {
        rl_drawer_release(head->drawer);
        head->drawer = NULL;
        st = make_drawer(r, scene, &desc, head);
        f->new_drawer = true;
    }
    f->drawer = head->drawer;
    f->device = head->info[0] ? head->info : NULL;
    if (st == RL_OK)
        st = rl_drawer_begin(f->drawer, &f->target.image, &f->view.view, &f->view.proj, f->view.eye);
    if (st != RL_OK) {
        rl_cull_target_end(&f->target);
        f->drawer = NULL;
    }
    return st;
}

rl_status rl_cull_frame_end(rl_cull_frame *f, rl_status st, const rl_image *image, rl_render_stats *stats)
{
    rl_status end = f->drawer ? rl_drawer_end(f->drawer) : RL_OK;
    if (st == RL_OK)
        st = end;
    rl_cull_target_end(&f->target);
    f->drawer = NULL;
    if (st == RL_OK && stats) {
        stats->triangles_rasterized = f->counters.triangles_drawn;
        stats->points_drawn = f->counters.points_drawn;
        stats->pixels_written = f->counters.pixels_written;
        stats->samples = (uint64_t)image->width * image->height;
        stats->device = f->device;
    }
    return st;
}
