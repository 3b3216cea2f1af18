/* property_visibility.c: the property "visibility", pixel visibility of a
 * position (Jähn 2015, Sec. 4.2.2, Def. 4 and 5).
 *
 * The omnidirectional viewer is approximated by a cube: six 90° frusta with
 * square images of `resolution`² pixels (default 1024 as in the thesis), one
 * per face (rl_property_direction order). The whole scene is rasterized into
 * each face with object IDs (src/raster, top-left fill rule, depth test);
 * an object is visible when it owns at least one pixel of one face. The
 * near plane is the `near` option (default 0.1 m); the far plane encloses
 * the whole scene from the position, as in the thesis ("die Entfernung zur
 * Fernebene wird ... so gewählt, dass die komplette Szene eingeschlossen
 * ist"). Objects entirely in front of the near plane are therefore never
 * visible (Fig. 4.2).
 *
 * In contrast to the thesis, which renders the depth buffer and then issues
 * one hardware occlusion query per object with the depth test set to
 * "equal", the count is read directly from the object-ID layer of the same
 * depth pass: a pixel belongs to the object that won its depth test. Both
 * give the set of objects contributing a depth value (Def. 5); reading IDs
 * needs one pass instead of two and gives the exact pixel count per object.
 *
 * Values (`measure`): objects (Def. 4, default), polygons (triangles of the
 * visible objects) or pixels (covered pixels of all faces). direction[i] is
 * the same measure for face i alone. The set is the visible objects.
 *
 * Only objects whose bounding box reaches into a face's frustum are drawn
 * into it (a conservative box-against-planes test): an object outside the
 * frustum covers no pixel centre, so the counts are the same as drawing
 * everything, at about a sixth of the triangle setup.
 *
 * Workers: each has its own rasterizer, image and counters. With several
 * workers every rasterizer runs single-threaded (the parallelism is across
 * positions, Jähn 2015, Sec. 5.5); a single worker's rasterizer uses all
 * threads. The `threads` option overrides both.
 *
 * backend=gl renders the same six views on OpenGL and counts on the GPU
 * (src/gl/gl_visibility.c): the per-object pixels and the per-face counts
 * come back as one small buffer instead of six ID images. One GL counter
 * (one context, one copy of the scene on the device) serves every worker,
 * one position at a time: the device is one, and the workers' frustum
 * tests and reductions still run in parallel around it. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <omp.h>

#include "core/error.h"
#include "eval/property_internal.h"
#include "gl/gl_visibility.h"
#include "rl/rl_drawer.h"

static const char *const measure_choices[] = { "objects", "polygons", "pixels", NULL };
enum { MEASURE_OBJECTS = 0, MEASURE_POLYGONS, MEASURE_PIXELS };
static const char *const backend_choices[] = { "software", "gl", NULL };
enum { BACKEND_SOFTWARE = 0, BACKEND_GL };

static const rl_option_info visibility_options[] = {
    { "resolution", RL_OPT_INT, "1024",
      "pixels per side of each of the six cube faces (Jähn 2015 uses 1024)", 1, 4096, NULL },
    { "near", RL_OPT_FLOAT, "0.1",
      "near-plane distance in scene units (m); closer geometry is not seen", 1e-6, 1e6, NULL },
    { "measure", RL_OPT_ENUM, "objects",
      "objects: visible objects; polygons: their triangles; pixels: covered pixels",
      0, 0, measure_choices },
    { "threads", RL_OPT_INT, "0",
      "rasterizer threads per worker (0: all for a single worker, 1 per worker otherwise)", 0,
      1024, NULL },
    { "backend", RL_OPT_ENUM, "software",
      "software: the software rasterizer, counted on the CPU; gl: OpenGL 4.5, counted on the GPU",
      0, 0, backend_choices },
    { "device", RL_OPT_STRING, "",
      "EGL device of backend gl: auto, surfaceless or a device number; empty: $RL_EGL_DEVICE, else auto",
      0, 0, NULL },
};

typedef struct vis_worker {
    rl_drawer *drawer;          /* IDs only (rl_drawer.h, any backend), kept for every face */
    rl_image *img;              /* depth + IDs, resolution² */
    uint32_t *pixels;           /* per object, this evaluation */
    uint32_t *seen;             /* per object: stamp of the last face that saw it */
    uint8_t *mask;              /* per object: drawn into the current face; gl: 6 faces */
    uint32_t stamp;
} vis_worker;

typedef struct vis_state {
    const rl_scene_data *d;
    int resolution;
    float z_near;
    int measure;
    int workers;
    int threads;                /* per rasterizer; 0 = all */
    vis_worker *w;
    rl_gl_visibility *gl;       /* backend gl: shared by the workers under lock */
    omp_lock_t lock;
} vis_state;

static const char *visibility_unit(const rl_property *p)
{
    static const char *const units[] = { "objects", "triangles", "pixels" };
    return units[rl_property_opt_enum(p, "measure")];
}

static void visibility_release(void *state)
{
    vis_state *s = state;
    if (!s)
        return;
    if (s->gl) {
        rl_gl_visibility_release(s->gl);
        omp_destroy_lock(&s->lock);
    }
    for (int i = 0; s->w && i < s->workers; ++i) {
        rl_drawer_release(s->w[i].drawer);
        rl_image_release(s->w[i].img);
        free(s->w[i].pixels);
        free(s->w[i].seen);
        free(s->w[i].mask);
    }
    free(s->w);
    free(s);
}

/* The GL counter of backend gl, with a clear error where there is no GL. */
static rl_status make_gl(rl_property *p, const rl_scene *scene, vis_state *s)
{
    const char *device = rl_property_opt(p, "device");
    char why[256];
    if (!rl_gl_available(device, why, sizeof why))
        return rl_error(RL_ERR_UNSUPPORTED, "%s: backend gl: OpenGL unavailable: %s", rl_property_name(p), why);
    rl_status st = rl_gl_visibility_create(scene, s->resolution, device, &s->gl);
    if (st != RL_OK)
        return st;
    omp_init_lock(&s->lock);
    return RL_OK;
}

static rl_status visibility_commit(rl_property *p, const rl_scene *scene, int workers,
                                   void **state, uint32_t *set_size)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    if (d->num_triangles == 0 || d->num_objects == 0)
        return rl_error(RL_ERR_EMPTY_SCENE, "%s: the scene has no objects", rl_property_name(p));
    vis_state *s = rl_calloc(1, sizeof *s);
    if (!s)
        return RL_ERR_OUT_OF_MEMORY;
    s->d = d;
    s->resolution = (int)rl_property_opt_int(p, "resolution");
    s->z_near = (float)rl_property_opt_float(p, "near");
    s->measure = rl_property_opt_enum(p, "measure");
    s->workers = workers;
    s->threads = (int)rl_property_opt_int(p, "threads");
    if (s->threads == 0)
        s->threads = workers > 1 ? 1 : 0;
    s->w = rl_calloc((size_t)workers, sizeof *s->w);
    rl_status st = s->w ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    const bool gl = rl_property_opt_enum(p, "backend") == BACKEND_GL;
    if (st == RL_OK && gl)
        st = make_gl(p, scene, s);
    const int threads = s->threads;
    for (int i = 0; st == RL_OK && i < workers; ++i) {
        vis_worker *w = &s->w[i];
        w->pixels = rl_calloc(d->num_objects, sizeof *w->pixels);
        w->mask = rl_calloc((size_t)d->num_objects * (gl ? 6 : 1), sizeof *w->mask);
        if (!w->pixels || !w->mask)
            st = RL_ERR_OUT_OF_MEMORY;
        if (gl || st != RL_OK)
            continue;
        st = rl_image_create(s->resolution, s->resolution, RL_LAYER_DEPTH | RL_LAYER_ID, &w->img);
        w->seen = st == RL_OK ? rl_calloc(d->num_objects, sizeof *w->seen) : NULL;
        if (st == RL_OK && !w->seen)
            st = RL_ERR_OUT_OF_MEMORY;
        /* Unlit, so the mask's contents may change from face to face. */
        const rl_drawer_desc desc = { .flags = RL_RASTER_NO_COLOR, .threads = threads, .object_mask = w->mask };
        if (st == RL_OK)
            st = rl_drawer_create(scene, &desc, &w->drawer);
    }
    if (st != RL_OK) {
        visibility_release(s);
        return st;
    }
    *state = s;
    *set_size = d->num_objects;
    return RL_OK;
}

/* Far plane that encloses the scene seen from pos: the farthest corner of
 * the bounds is at most that far along any view axis. */
static float far_plane(const rl_scene_data *d, rl_vec3 pos, float z_near)
{
    float far2 = 0.0f;
    for (int c = 0; c < 8; ++c) {
        rl_vec3 corner = rl_v3(c & 1 ? d->bounds.max.x : d->bounds.min.x,
                               c & 2 ? d->bounds.max.y : d->bounds.min.y,
                               c & 4 ? d->bounds.max.z : d->bounds.min.z);
        far2 = rl_maxf(far2, rl_length2(rl_sub(corner, pos)));
    }
    float z_far = 1.01f * sqrtf(far2);
    return z_far > 2.0f * z_near ? z_far : 2.0f * z_near;
}

/* Marks in mask the objects whose bounds may reach into the 90° frustum
 * of direction dir (up up) beyond the near plane. The frustum is
 * dot(dir, q) >= |dot(up, q)|, >= |dot(right, q)| and >= z_near for q =
 * p - pos; a box is culled when one of these five half-spaces misses all
 * of it, with a small margin so that rounding never culls a visible box. */
static void frustum_mask(const rl_scene_data *d, rl_vec3 pos, rl_vec3 dir, rl_vec3 up,
                         float z_near, uint8_t *mask)
{
    const rl_vec3 right = rl_cross(dir, up);
    const rl_vec3 planes[5] = { rl_sub(dir, up), rl_add(dir, up), rl_sub(dir, right),
                                rl_add(dir, right), dir };
    const double offsets[5] = { 0.0, 0.0, 0.0, 0.0, z_near };
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        rl_aabb b = d->objects[o].bounds;
        const double lo[3] = { (double)b.min.x - pos.x, (double)b.min.y - pos.y,
                               (double)b.min.z - pos.z };
        const double hi[3] = { (double)b.max.x - pos.x, (double)b.max.y - pos.y,
                               (double)b.max.z - pos.z };
        double scale = 1.0;
        for (int k = 0; k < 3; ++k)
            scale += fabs(lo[k]) + fabs(hi[k]);
        bool inside = true;
        for (int i = 0; i < 5 && inside; ++i) {
            const double n[3] = { planes[i].x, planes[i].y, planes[i].z };
            double best = 0.0;          /* max of n . q over the box */
            for (int k = 0; k < 3; ++k)
                best += n[k] > 0.0 ? n[k] * hi[k] : n[k] * lo[k];
            inside = best - offsets[i] >= -1e-5 * scale;
        }
        mask[o] = inside;
    }
}

/* Sec. 4.2.2: a frustum that covers exactly one cube face. */
static void face_camera(const vis_state *s, rl_vec3 pos, int face, float z_far, rl_mat4 *view, rl_mat4 *proj)
{
    rl_vec3 dir, up;
    rl_property_direction(face, &dir, &up);
    rl_camera cam = { .eye = pos, .target = rl_add(pos, dir), .up = up, .fov_deg = 90.0f,
                      .width = s->resolution, .height = s->resolution,
                      .z_near = s->z_near, .z_far = z_far };
    *view = rl_camera_view(&cam);
    *proj = rl_camera_projection(&cam, s->z_near, z_far);
}

/* count_pixels on the GL counter: the same views and frustum masks, the
 * counting on the GPU. */
static rl_status count_pixels_gl(vis_state *s, vis_worker *w, rl_vec3 pos, double *direction)
{
    const rl_scene_data *d = s->d;
    const float z_far = far_plane(d, pos, s->z_near);
    rl_mat4 view_proj[6];
    const uint8_t *masks[6];
    for (int face = 0; face < 6; ++face) {
        rl_mat4 view, proj;
        face_camera(s, pos, face, z_far, &view, &proj);
        view_proj[face] = rl_mat4_mul(&proj, &view);
        rl_vec3 dir, up;
        rl_property_direction(face, &dir, &up);
        uint8_t *mask = w->mask + (size_t)face * d->num_objects;
        frustum_mask(d, pos, dir, up, s->z_near, mask);
        masks[face] = mask;
    }
    rl_gl_view_counts views[6];
    omp_set_lock(&s->lock);
    rl_status st = rl_gl_visibility_count(s->gl, view_proj, masks, w->pixels, views);
    omp_unset_lock(&s->lock);
    if (st != RL_OK || !direction)
        return st;
    for (int face = 0; face < 6; ++face)
        direction[face] = s->measure == MEASURE_OBJECTS    ? (double)views[face].objects
                          : s->measure == MEASURE_POLYGONS ? (double)views[face].polygons
                                                           : (double)views[face].pixels;
    return RL_OK;
}

/* Rasterizes the six faces and counts pixels per object into w->pixels;
 * per-face measures go to direction (may be NULL). */
static rl_status count_pixels(vis_state *s, vis_worker *w, rl_vec3 pos, double *direction)
{
    if (s->gl)
        return count_pixels_gl(s, w, pos, direction);
    const rl_scene_data *d = s->d;
    const size_t n = (size_t)s->resolution * (size_t)s->resolution;
    memset(w->pixels, 0, d->num_objects * sizeof *w->pixels);
    const float z_far = far_plane(d, pos, s->z_near);
    for (int face = 0; face < 6; ++face) {
        rl_vec3 dir, up;
        rl_property_direction(face, &dir, &up);
        rl_mat4 view, proj;
        face_camera(s, pos, face, z_far, &view, &proj);
        frustum_mask(d, pos, dir, up, s->z_near, w->mask);
        rl_image_clear(w->img);
        rl_status st = rl_drawer_begin(w->drawer, w->img, &view, &proj, pos);
        if (st == RL_OK)
            st = rl_drawer_draw_all(w->drawer, NULL, NULL, NULL);
        if (st == RL_OK)
            st = rl_drawer_end(w->drawer);
        if (st != RL_OK)
            return st;

        if (++w->stamp == 0) {      /* wrapped: forget every old stamp */
            memset(w->seen, 0, d->num_objects * sizeof *w->seen);
            w->stamp = 1;
        }
        uint64_t face_objects = 0, face_polygons = 0, face_pixels = 0;
        const uint32_t *ids = w->img->object_id;
        for (size_t k = 0; k < n; ++k) {
            uint32_t o = ids[k];
            if (o >= d->num_objects)
                continue;           /* RL_ID_NONE: background */
            ++w->pixels[o];
            ++face_pixels;
            if (w->seen[o] != w->stamp) {
                w->seen[o] = w->stamp;
                ++face_objects;
                face_polygons += d->objects[o].num_triangles;
            }
        }
        if (direction)
            direction[face] = s->measure == MEASURE_OBJECTS    ? (double)face_objects
                              : s->measure == MEASURE_POLYGONS ? (double)face_polygons
                                                               : (double)face_pixels;
    }
    return RL_OK;
}

static rl_status visibility_evaluate(rl_property *p, void *state, int worker, rl_vec3 pos,
                                     rl_property_result *out)
{
    (void)p;
    vis_state *s = state;
    vis_worker *w = &s->w[worker];
    double direction[6];
    rl_status st = count_pixels(s, w, pos, direction);
    if (st != RL_OK)
        return st;
    const rl_scene_data *d = s->d;
    uint64_t objects = 0, polygons = 0, pixels = 0;
    if (out->set)
        memset(out->set, 0, ((size_t)d->num_objects + 63) / 64 * sizeof *out->set);
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        if (!w->pixels[o])
            continue;
        /* Def. 4/5: visible = contributes at least one depth value */
        ++objects;
        polygons += d->objects[o].num_triangles;
        pixels += w->pixels[o];
        if (out->set)
            out->set[o / 64] |= UINT64_C(1) << (o % 64);
    }
    out->value = s->measure == MEASURE_OBJECTS    ? (double)objects
                 : s->measure == MEASURE_POLYGONS ? (double)polygons
                                                  : (double)pixels;
    memcpy(out->direction, direction, sizeof direction);
    return RL_OK;
}

rl_status rl_property_visibility_pixels(rl_property *p, void *state, int worker, rl_vec3 pos,
                                        uint32_t *pixels_per_object)
{
    (void)p;
    vis_state *s = state;
    vis_worker *w = &s->w[worker];
    rl_status st = count_pixels(s, w, pos, NULL);
    if (st != RL_OK)
        return st;
    memcpy(pixels_per_object, w->pixels, s->d->num_objects * sizeof *pixels_per_object);
    return RL_OK;
}

const rl_property_class rl_property_visibility_class = {
    .info = { "visibility",
              "Pixel visibility: objects (or their triangles, or pixels) seen in the six cube "
              "faces around the position",
              "Jähn 2015, Sec. 4.2.2, Def. 4/5" },
    .options = visibility_options,
    .num_options = sizeof visibility_options / sizeof visibility_options[0],
    .unit = visibility_unit,
    .commit = visibility_commit,
    .evaluate = visibility_evaluate,
    .release = visibility_release,
};
