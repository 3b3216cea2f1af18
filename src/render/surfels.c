/* surfels.c: renderer "surfels", Progressive Blue Surfels (Jähn 2015,
 * Ch. 6): distant parts of the scene are drawn as prefixes of their surfel
 * sequences instead of their meshes.
 *
 * Preprocessing (Sec. 6.1.2): every node of the loose octree (rl_octree.h)
 * whose subtree holds more than `min_triangles` triangles gets a surfel
 * representation of all the objects below it (rl_surfels_build, Sec.
 * 6.1.1), so a whole distant district of a city becomes one node.
 *
 * Rendering (Sec. 6.2), from the root, with A the projected size of a
 * node's bounding box (the area of its screen rectangle, in pixels):
 *  - outside the frustum: skipped;
 *  - A > max_size², or no surfels: its objects are drawn and its children
 *    visited;
 *  - A <= min_size²: a prefix of n = A · coverage · overdraw surfels is
 *    drawn and the subtree is not visited; when n exceeds the sequence,
 *    all are drawn and the point size grows by sqrt(n / count) (the
 *    projected area per surfel, as a side length);
 *  - in between: the prefix and the point size are scaled linearly by
 *    t = (max² - A) / (max² - min²) (0 at the maximum, 1 at the minimum)
 *    and the node's objects and children are drawn as well, so that
 *    switching levels does not pop.
 * Each surfel is a square point of side point_size · relative size ·
 * cos(normal, view direction) pixels (at least 1), hidden when it faces
 * away (Sec. 6.2.1), lit like the meshes by raster's diffuse model at its
 * unlit colour (its 20 bytes hold no specular term).
 *
 * drawer = gl (device: the EGL device) draws the frame, meshes and
 * surfels (GL points of the same sizes), with the GL drawer of src/gl.
 * atlas = gl renders the 8 views of the preprocessing with a GL drawer on
 * the same device (one for all nodes, dropped after the build); the
 * sampling after it is unchanged (docs/gl.md). The two are independent:
 * the atlas decides which surfels exist, the drawer how a frame is drawn.
 *
 * Options (thesis defaults, Sec. 6.3): min_size 100, max_size 200 (sides
 * of the projected size in pixels), overdraw 4, point_size 7, count 40000,
 * resolution 1024, start_sample 160; min_triangles (default = count, "of
 * the order of the surfel count"), max_depth 5, seed 1; plus raster's
 * shading options for the meshes. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/culling.h"
#include "rl/rl_drawer.h"
#include "rl/rl_gl.h"
#include "render/renderer.h"
#include "render/surfels_internal.h"
#include "rl/rl_surfels.h"
#include "rl/rl_timer.h"

static const char *const overlay_choices[] = { "none", "levels", NULL };
static const char *const atlas_choices[] = { "software", "gl", NULL };
enum { ATLAS_SOFTWARE, ATLAS_GL };

static const rl_option_info surfels_options[] = {
    RL_CULL_RASTER_OPTIONS,
    { "atlas", RL_OPT_ENUM, "software",
      "the 8 views of the surfel preprocessing: software | gl (OpenGL on device, docs/gl.md)", 0, 0,
      atlas_choices },
    { "min_size", RL_OPT_FLOAT, "100", "below this projected side (px) a node is surfels only", 0, 1e6, NULL },
    { "max_size", RL_OPT_FLOAT, "200", "above this projected side (px) a node is its meshes only", 0, 1e6, NULL },
    { "overdraw", RL_OPT_FLOAT, "4", "surfels per covered pixel", 0.01, 1000, NULL },
    { "point_size", RL_OPT_FLOAT, "7", "base point size in pixels", 0.1, 256, NULL },
    { "count", RL_OPT_INT, "40000", "surfels per node", 1, 1 << 24, NULL },
    { "resolution", RL_OPT_INT, "1024", "pixels per side of each of the 8 views", 8, 16384, NULL },
    { "start_sample", RL_OPT_INT, "160", "candidates per sample of the progressive sampling", 1, 1000000, NULL },
    { "min_triangles", RL_OPT_INT, "0", "nodes with more triangles get surfels (0: = count)", 0, 4294967295.0,
      NULL },
    { "max_depth", RL_OPT_INT, "5", "maximum depth of the loose octree", 0, RL_OCTREE_MAX_DEPTH, NULL },
    { "seed", RL_OPT_INT, "1", "seed of the surfel sampling", 0, 4294967295.0, NULL },
    { "overlay", RL_OPT_ENUM, "none", "colour the surfels by their octree node's depth instead of lighting them "
      "(levels: 0 red, 1 orange, 2 yellow, 3 green, 4 cyan, 5 blue, 6+ magenta)", 0, 0, overlay_choices },
};

typedef struct surfels_params {
    rl_octree_desc od;
    uint32_t count, resolution, start_sample, min_triangles;
    uint64_t seed, scene_uid;
    int atlas;
    char device[64];              /* atlas = gl: the EGL device */
} surfels_params;

typedef struct surfels_state {
    rl_culling_head head;         /* first: rl_culling_get_stats */
    rl_octree_cache oc;
    surfels_params params;
    bool built;
    rl_surfel_set *sets;          /* per octree node; count 0 = none */
    uint32_t num_sets;
    /* per frame: the points to draw */
    rl_vec3 *pos;
    rl_vec4 *col;
    float *size;
    size_t cap;
    /* per frame: what the traversal decided to draw, in order, and the
     * meshes among it (lit in one parallel pass before drawing) */
    struct draw_cmd *cmds;
    size_t num_cmds, cmds_cap;
    uint32_t *lit;
    size_t lit_cap;
} surfels_state;

/* One step of a frame: a mesh object, or a prefix of m surfels of an
 * octree node's set at a point size. */
typedef struct draw_cmd {
    uint32_t index;               /* object, or octree node for points */
    uint32_t m;                   /* points: the prefix length; 0: an object */
    float point_size;
} draw_cmd;

static void drop_sets(surfels_state *s)
{
    for (uint32_t i = 0; i < s->num_sets; ++i)
        rl_surfel_set_free(&s->sets[i]);
    free(s->sets);
    s->sets = NULL;
    s->num_sets = 0;
    s->built = false;
}

static void surfels_release(void *state)
{
    surfels_state *s = state;
    drop_sets(s);
    rl_octree_cache_release(&s->oc);
    rl_drawer_release(s->head.drawer);
    free(s->pos);
    free(s->col);
    free(s->size);
    free(s->cmds);
    free(s->lit);
}

static void collect_objects(const rl_octree_node *nodes, const uint32_t *objects, uint32_t n, uint32_t *out,
                            uint32_t *count)
{
    const rl_octree_node *node = &nodes[n];
    for (uint32_t k = 0; k < node->num_objects; ++k)
        out[(*count)++] = objects[node->first_object + k];
    for (uint32_t c = 0; c < node->num_children; ++c)
        collect_objects(nodes, objects, node->first_child + c, out, count);
}

/* Sec. 6.1.2: surfels for every node with enough geometry below it. */
static rl_status build_sets(surfels_state *s, rl_renderer *r, const rl_scene *scene, int threads)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    uint32_t nn;
    const rl_octree_node *nodes = rl_octree_nodes(s->oc.tree, &nn);
    const uint32_t *objects = rl_octree_objects(s->oc.tree, NULL);
    s->sets = rl_calloc(nn, sizeof *s->sets);
    uint32_t *list = rl_calloc((size_t)d->num_objects + 1, sizeof *list);
    rl_status st = s->sets && list ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        s->num_sets = nn;
    uint32_t todo = 0, done = 0;
    for (uint32_t n = 0; n < nn; ++n)
        todo += nodes[n].subtree_triangles > s->params.min_triangles;
    /* One GL context and one copy of the scene's buffers for every node. */
    rl_drawer *atlas = NULL;
    const rl_drawer_desc atlas_desc = RL_SURFEL_ATLAS_DRAWER_DESC;
    if (st == RL_OK && todo > 0 && s->params.atlas == ATLAS_GL)
        st = rl_gl_drawer_create(scene, &atlas_desc, s->params.device, &atlas);
    for (uint32_t n = 0; n < nn && st == RL_OK; ++n) {
        if (nodes[n].subtree_triangles <= s->params.min_triangles)
            continue;
        uint32_t count = 0;
        collect_objects(nodes, objects, n, list, &count);
        rl_surfel_desc desc = { .resolution = s->params.resolution, .count = s->params.count,
                                .start_sample = s->params.start_sample, .seed = s->params.seed + n,
                                .threads = threads, .atlas_drawer = atlas };
        st = rl_surfels_build(scene, list, count, &desc, &s->sets[n]);
        if (st == RL_OK && !rl_renderer_progress(r, (double)++done / (double)(todo ? todo : 1)))
            st = rl_error(RL_ERR_CANCELLED, "surfels: cancelled by the progress callback");
    }
    rl_drawer_release(atlas);
    free(list);
    return st;
}

typedef struct surfels_frame {
    surfels_state *s;
    const rl_scene_data *d;
    const rl_octree_node *nodes;
    const uint32_t *objects;
    rl_cull_frame cf;
    float min_size, max_size, overdraw, point_size;
    bool levels;                  /* overlay=levels */
} surfels_frame;

/* overlay=levels: one colour per octree depth, so that a user sees which
 * level of detail each distant district is drawn at (Sec. 6.2). */
static rl_vec3 level_colour(uint32_t depth)
{
    static const float pal[7][3] = { { 1.0f, 0.15f, 0.15f }, { 1.0f, 0.55f, 0.1f }, { 1.0f, 0.95f, 0.15f },
                                     { 0.2f, 0.9f, 0.2f },   { 0.15f, 0.9f, 0.95f }, { 0.2f, 0.35f, 1.0f },
                                     { 0.95f, 0.2f, 0.95f } };
    const float *c = pal[depth < 6 ? depth : 6];
    return rl_v3(c[0], c[1], c[2]);
}

/* Projected size of a box: the area of its screen rectangle in pixels;
 * INFINITY when it reaches behind the near plane. */
static double projected_size(const rl_cull_view *v, rl_aabb b)
{
    double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
    for (int i = 0; i < 8; ++i) {
        rl_vec3 p = rl_v3((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z);
        rl_vec4 c = rl_mat4_mul_vec4(&v->view_proj, rl_v4_from3(p, 1.0f));
        if (!(c.w > v->z_near * 0.5f))
            return INFINITY;
        double x = ((double)c.x / c.w + 1.0) * 0.5 * v->cam.width;
        double y = (1.0 - (double)c.y / c.w) * 0.5 * v->cam.height;
        x0 = x < x0 ? x : x0;
        x1 = x > x1 ? x : x1;
        y0 = y < y0 ? y : y0;
        y1 = y > y1 ? y : y1;
    }
    return (x1 - x0) * (y1 - y0);
}

static rl_status reserve(surfels_state *s, size_t n)
{
    if (n <= s->cap)
        return RL_OK;
    size_t cap = rl_grow_capacity(s->cap, n, 4096);
    rl_vec3 *p = rl_realloc_array(s->pos, cap, sizeof *p);
    if (p)
        s->pos = p;
    rl_vec4 *c = rl_realloc_array(s->col, cap, sizeof *c);
    if (c)
        s->col = c;
    float *z = rl_realloc_array(s->size, cap, sizeof *z);
    if (z)
        s->size = z;
    if (!p || !c || !z)
        return RL_ERR_OUT_OF_MEMORY;
    s->cap = cap;
    return RL_OK;
}

/* Sec. 6.2.1: the first n surfels of set, point size `base` px. */
static rl_status draw_prefix(surfels_frame *f, uint32_t node, uint32_t n, float base)
{
    const rl_surfel_set *set = &f->s->sets[node];
    const rl_vec3 level = level_colour(f->nodes[node].depth);
    surfels_state *s = f->s;
    rl_status st = reserve(s, n);
    if (st != RL_OK)
        return st;
    const rl_vec3 eye = f->cf.view.eye;
    uint32_t kept = 0;
    /* Light and size in parallel, then compact the front-facing points in
     * order, so the result does not depend on the thread count. */
#pragma omp parallel for num_threads(n > 8192 ? f->cf.threads : 1) schedule(static)
    for (int64_t i = 0; i < (int64_t)n; ++i) {
        const rl_surfel *sf = &set->surfels[i];
        rl_vec3 p = rl_v3(sf->position[0], sf->position[1], sf->position[2]);
        rl_vec3 nrm = rl_surfel_normal(sf);
        rl_vec3 to_eye = rl_sub(eye, p);
        float len = rl_length(to_eye);
        float cosv = len > 0.0f ? rl_dot(nrm, to_eye) / len : 1.0f;
        s->pos[i] = p;
        s->size[i] = rl_surfel_point_side(base, rl_surfel_size(sf), cosv);
        if (s->size[i] == 0.0f)
            continue;            /* faces away: hidden */
        rl_vec3 c = f->levels ? level
                              : rl_raster_light_diffuse(f->d, p, nrm, rl_surfel_color(sf), f->cf.ambient, eye);
        s->col[i] = rl_v4_from3(c, 1.0f);
    }
    for (uint32_t i = 0; i < n; ++i) {
        if (s->size[i] == 0.0f)
            continue;
        s->pos[kept] = s->pos[i];
        s->col[kept] = s->col[i];
        s->size[kept] = s->size[i];
        ++kept;
    }
    rl_raster_points pts = { .count = kept, .positions = s->pos, .colors = s->col, .sizes_px = s->size,
                             .object_id = RL_ID_NONE };
    s->head.stats.points_drawn += kept;
    rl_raster_counters c;
    memset(&c, 0, sizeof c);
    st = rl_drawer_draw_points(f->cf.drawer, &pts, &c);
    f->cf.counters.pixels_written += c.pixels_written;
    f->cf.counters.points_drawn += c.points_drawn;
    return st;
}

static rl_status push_cmd(surfels_state *s, draw_cmd c)
{
    if (!rl_reserve((void **)&s->cmds, &s->cmds_cap, s->num_cmds + 1, sizeof *s->cmds, 256))
        return RL_ERR_OUT_OF_MEMORY;
    s->cmds[s->num_cmds++] = c;
    return RL_OK;
}

/* Sec. 6.2's traversal: decides what to draw and appends it to s->cmds
 * (drawn by draw_cmds). */
static rl_status draw_node(surfels_frame *f, uint32_t n)
{
    surfels_state *s = f->s;
    const rl_octree_node *node = &f->nodes[n];
    s->head.stats.nodes_visited++;
    if (!rl_cull_box_in_frustum(&f->cf.view, node->bounds)) {
        s->head.stats.nodes_frustum_culled++;
        return RL_OK;
    }
    const rl_surfel_set *set = n < s->num_sets ? &s->sets[n] : NULL;
    double a = projected_size(&f->cf.view, node->bounds);
    rl_status st = RL_OK;
    if (set && set->count > 0) {
        rl_surfel_lod lod = rl_surfels_node_lod(a, set->coverage, set->count, f->min_size, f->max_size,
                                                f->overdraw, f->point_size);
        if (lod.prefix > 0)
            st = push_cmd(s, (draw_cmd){ n, lod.prefix, lod.point_size });
        if (a <= (double)f->max_size * f->max_size)
            s->head.stats.surfel_nodes++;
        if (st != RL_OK || !lod.descend)
            return st;
    }
    for (uint32_t k = 0; k < node->num_objects && st == RL_OK; ++k) {
        uint32_t o = f->objects[node->first_object + k];
        if (!rl_cull_box_in_frustum(&f->cf.view, f->d->objects[o].bounds))
            continue;
        s->head.stats.objects_drawn++;
        s->head.stats.triangles_drawn += f->d->objects[o].num_triangles;
        st = push_cmd(s, (draw_cmd){ o, 0, 0.0f });
    }
    for (uint32_t c = 0; c < node->num_children && st == RL_OK; ++c)
        st = draw_node(f, node->first_child + c);
    return st;
}

/* Draws the traversal's steps in order, after lighting all its meshes in
 * one parallel pass (one at a time, most are too small to light in
 * parallel, and the other threads would wait). */
static rl_status draw_cmds(surfels_frame *f)
{
    surfels_state *s = f->s;
    size_t k = 0;
    if (!rl_reserve((void **)&s->lit, &s->lit_cap, s->num_cmds, sizeof *s->lit, 256))
        return RL_ERR_OUT_OF_MEMORY;
    for (size_t i = 0; i < s->num_cmds; ++i)
        if (s->cmds[i].m == 0)
            s->lit[k++] = s->cmds[i].index;
    rl_drawer_light(f->cf.drawer, s->lit, (uint32_t)k);
    /* Each run of meshes between surfel prefixes is one list, drawn on all
     * threads together (s->lit holds the runs' objects in order). */
    rl_status st = RL_OK;
    size_t run = 0;
    for (size_t i = 0; i < s->num_cmds && st == RL_OK;) {
        const draw_cmd *c = &s->cmds[i];
        if (c->m) {
            st = draw_prefix(f, c->index, c->m, c->point_size);
            ++i;
            continue;
        }
        size_t n = 0;
        for (; i < s->num_cmds && s->cmds[i].m == 0; ++i)
            ++n;
        st = rl_drawer_draw(f->cf.drawer, s->lit + run, (uint32_t)n, &f->cf.counters);
        run += n;
    }
    return st;
}

/* Unavailable where either the frame's drawer or the atlas wants GL that
 * cannot be had. */
static bool surfels_available(const rl_renderer *r, char *why, size_t n)
{
    if (!rl_cull_available(r, why, n))
        return false;
    if (rl_renderer_opt_enum(r, "atlas") != ATLAS_GL)
        return true;
    char reason[400];
    if (rl_gl_available(rl_renderer_opt_string(r, "device"), reason, sizeof reason))
        return true;
    if (why && n)
        snprintf(why, n, "atlas=gl: %s", reason);
    return false;
}

static rl_status surfels_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                                rl_image *image, rl_render_stats *stats)
{
    surfels_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    memset(&s->head.stats, 0, sizeof s->head.stats);
    s->head.have_frame = false;
    const int threads = (int)rl_renderer_opt_int(r, "threads");
    float min_size = (float)rl_renderer_opt_float(r, "min_size");
    float max_size = (float)rl_renderer_opt_float(r, "max_size");
    if (!(max_size >= min_size))
        return rl_error(RL_ERR_INVALID_ARG, "surfels: max_size %g is below min_size %g", (double)max_size,
                        (double)min_size);

    surfels_params p;
    memset(&p, 0, sizeof p);
    int depth = (int)rl_renderer_opt_int(r, "max_depth");
    p.od = (rl_octree_desc){ .max_depth = depth ? depth : RL_OCTREE_DEPTH_ZERO };
    p.count = (uint32_t)rl_renderer_opt_int(r, "count");
    p.resolution = (uint32_t)rl_renderer_opt_int(r, "resolution");
    p.start_sample = (uint32_t)rl_renderer_opt_int(r, "start_sample");
    p.min_triangles = (uint32_t)rl_renderer_opt_int(r, "min_triangles");
    if (p.min_triangles == 0)
        p.min_triangles = p.count;
    p.seed = (uint64_t)rl_renderer_opt_int(r, "seed");
    p.scene_uid = rl_scene_uid(scene);
    p.atlas = (int)rl_renderer_opt_enum(r, "atlas");
    if (p.atlas == ATLAS_GL) {
        const char *device = rl_renderer_opt_string(r, "device");
        if (strlen(device) >= sizeof p.device)
            return rl_error(RL_ERR_INVALID_ARG, "surfels: device \"%.40s...\" is too long", device);
        snprintf(p.device, sizeof p.device, "%s", device);
    }

    rl_timer t0;
    rl_timer_start(&t0);
    bool rebuilt = false;
    rl_status st = rl_octree_cache_get(&s->oc, scene, &p.od, &rebuilt);
    if (st != RL_OK)
        return st;
    if (rebuilt || !s->built || memcmp(&p, &s->params, sizeof p) != 0) {
        drop_sets(s);
        s->params = p;
        st = build_sets(s, r, scene, threads);
        if (st != RL_OK) {
            drop_sets(s);
            return st;
        }
        s->built = true;
        s->head.stats.preprocess_ms = rl_timer_ms(&t0);
    }
    uint32_t nn;
    const rl_octree_node *nodes = rl_octree_nodes(s->oc.tree, &nn);
    s->head.stats.octree_nodes = nn;
    s->head.stats.octree_depth = rl_octree_depth(s->oc.tree);

    surfels_frame f;
    memset(&f, 0, sizeof f);
    f.s = s;
    f.d = d;
    f.nodes = nodes;
    f.objects = rl_octree_objects(s->oc.tree, NULL);
    f.min_size = min_size;
    f.max_size = max_size;
    f.overdraw = (float)rl_renderer_opt_float(r, "overdraw");
    f.point_size = (float)rl_renderer_opt_float(r, "point_size");
    f.levels = rl_renderer_opt_enum(r, "overlay") == 1;
    st = rl_cull_frame_begin(r, scene, &s->head, cam, image, false, &f.cf);
    if (st != RL_OK)
        return st;
    s->num_cmds = 0;
    st = draw_node(&f, 0);
    if (st == RL_OK)
        st = draw_cmds(&f);
    st = rl_cull_frame_end(&f.cf, st, image, stats);
    if (st != RL_OK)
        return st;
    stats->prep_ms = s->head.stats.preprocess_ms;
    s->head.have_frame = true;
    return RL_OK;
}

const rl_renderer_class rl_surfels_renderer_class = {
    .info = { .name = "surfels",
              .description = "Progressive Blue Surfels: distant octree nodes as prefixes of blue-noise surfel "
                             "sequences (approximate level of detail)",
              .reference = "Jähn 2015, Ch. 6", .frame_bytes_per_pixel = RL_CULL_FRAME_BYTES_PER_PIXEL },
    .options = surfels_options,
    .num_options = sizeof surfels_options / sizeof surfels_options[0],
    .state_size = sizeof(surfels_state),
    .render = surfels_render,
    .release = surfels_release,
    .check = NULL,
    .reset = NULL,
    .available = surfels_available,
};
