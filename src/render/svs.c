/* svs.c: renderer "svs", Spherical Visibility Sampling (Eikel, Jähn,
 * Fischer & Meyer auf der Heide 2013), the approximate global-visibility
 * method that Jähn 2015 compares with CHC++ (Sec. 2.1.1, 7.4).
 *
 * Preprocessing: every node of the loose octree gets a visibility sphere,
 * the bounding sphere of its subtree's objects, and for each of D sample
 * directions on it the set of objects visible from outside the sphere in
 * that direction. A set is found by rendering the candidates
 * orthographically from the direction into an ID buffer (resolution²
 * pixels framing the sphere) and keeping the objects that cover a pixel.
 * Bottom-up, the candidates of a node are its own objects plus its
 * children's sets for the same direction: with a parallel projection an
 * object hidden inside a child from direction d stays hidden in the parent
 * from d, so the pruning loses nothing that the sampling would have found.
 * Directions: the vertices of an icosahedron subdivided `levels` times
 * (12, 42, 162, ...; default 42).
 *
 * Rendering: the tree is traversed from the root; a node outside the
 * frustum is skipped; a node whose sphere does not contain the viewer is
 * drawn as the union of the sets of the `neighbours` (3) sample
 * directions nearest to the direction from the sphere's centre to the
 * viewer (usually the corners of the spherical triangle around it; near
 * an edge of the triangle a vertex beyond the edge can be nearer than the
 * opposite corner, a choice that needs no triangle search), each object
 * once and only if its box is in the frustum; a node around the viewer
 * draws its own objects and recurses. Approximate on purpose: between the
 * samples, and for viewers close to a sphere, where a perspective view
 * sees more than the parallel one, visible objects can be missed; local
 * occlusion by near objects is not used (Jähn 2015, Sec. 7.4). Its image
 * quality is measured against the conservative reference (rl compare, the
 * quality property).
 *
 * Options: the raster renderer's, drawer (software | gl: the frame is drawn
 * by the GL drawer of src/gl; the sets are still sampled by the software
 * drawer, docs/gl.md) and device, plus max_depth 5, looseness 2.0,
 * levels 1 (42 directions), resolution 128, neighbours 3, distance 1. The
 * sample count and resolution are our defaults; the SVS paper varies both.
 * distance > 1 (ours) uses a node's sets only from viewers farther than
 * that many radii, recursing closer in: less preprocessed error from
 * perspective, more objects drawn. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "render/culling.h"
#include "rl/rl_drawer.h"
#include "render/renderer.h"
#include "rl/rl_timer.h"

static const rl_option_info svs_options[] = {
    RL_CULL_RASTER_OPTIONS,
    { "max_depth", RL_OPT_INT, "5", "maximum depth of the loose octree (0: all objects in the root)", 0,
      RL_OCTREE_MAX_DEPTH, NULL },
    { "looseness", RL_OPT_FLOAT, "2", "loose octree enlargement factor k", 1, 8, NULL },
    { "levels", RL_OPT_INT, "1", "icosahedron subdivisions for the sample directions (0: 12, 1: 42, 2: 162)",
      0, 3, NULL },
    { "resolution", RL_OPT_INT, "128", "pixels per side of each visibility sample", 8, 4096, NULL },
    { "neighbours", RL_OPT_INT, "3", "sample directions whose sets are drawn together", 1, 12, NULL },
    { "distance", RL_OPT_FLOAT, "1", "use a node's sets beyond this many sphere radii (1: outside the sphere)",
      1, 1000, NULL },
};

typedef struct svs_params {
    rl_octree_desc od;
    int levels, resolution;
} svs_params;

typedef struct svs_state {
    rl_culling_head head;         /* first: rl_culling_get_stats */
    rl_octree_cache oc;
    uint64_t scene_uid;
    svs_params params;
    bool built;
    rl_vec3 *dirs;                /* unit sample directions */
    uint32_t num_dirs;
    /* Node n, direction k: objects set_objects[set_offset[n*D+k] ..
     * set_offset[n*D+k+1]), ascending. */
    uint64_t *set_offset;
    uint32_t *set_objects;
    uint32_t *stamp;              /* per object: frame it was drawn in */
    uint32_t frame;
    /* This frame's objects, in the order the traversal found them: drawn
     * as one list (rl_drawer_draw), on all threads. */
    uint32_t *draw;
    uint32_t num_draw;
} svs_state;

static void drop_sets(svs_state *s)
{
    free(s->dirs);
    free(s->set_offset);
    free(s->set_objects);
    free(s->stamp);
    free(s->draw);
    s->dirs = NULL;
    s->set_offset = NULL;
    s->set_objects = NULL;
    s->stamp = NULL;
    s->draw = NULL;
    s->built = false;
}

static void svs_release(void *state)
{
    svs_state *s = state;
    drop_sets(s);
    rl_octree_cache_release(&s->oc);
    rl_drawer_release(s->head.drawer);
}

/* --- sample directions: a subdivided icosahedron --- */

typedef struct dir_list {
    rl_vec3 *v;
    uint32_t n, cap;
} dir_list;

static uint32_t dir_add(dir_list *l, rl_vec3 p)
{
    p = rl_normalize(p);
    for (uint32_t i = 0; i < l->n; ++i)   /* the shared midpoints of adjacent faces */
        if (rl_length2(rl_sub(l->v[i], p)) < 1e-10f)
            return i;
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 64;
        rl_vec3 *v = realloc(l->v, l->cap * sizeof *v);
        if (!v)
            return RL_NONE;
        l->v = v;
    }
    l->v[l->n] = p;
    return l->n++;
}

static rl_status make_directions(int levels, rl_vec3 **out, uint32_t *count)
{
    const float g = 1.6180339887f;
    const rl_vec3 ico[12] = { { -1, g, 0 }, { 1, g, 0 }, { -1, -g, 0 }, { 1, -g, 0 },
                              { 0, -1, g }, { 0, 1, g }, { 0, -1, -g }, { 0, 1, -g },
                              { g, 0, -1 }, { g, 0, 1 }, { -g, 0, -1 }, { -g, 0, 1 } };
    static const uint32_t faces[20][3] = { { 0, 11, 5 }, { 0, 5, 1 }, { 0, 1, 7 }, { 0, 7, 10 }, { 0, 10, 11 },
                                           { 1, 5, 9 }, { 5, 11, 4 }, { 11, 10, 2 }, { 10, 7, 6 }, { 7, 1, 8 },
                                           { 3, 9, 4 }, { 3, 4, 2 }, { 3, 2, 6 }, { 3, 6, 8 }, { 3, 8, 9 },
                                           { 4, 9, 5 }, { 2, 4, 11 }, { 6, 2, 10 }, { 8, 6, 7 }, { 9, 8, 1 } };
    dir_list l = { 0 };
    uint32_t nf = 20;
    uint32_t *tri = malloc(sizeof faces);
    rl_status st = tri ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (int i = 0; i < 12 && st == RL_OK; ++i)
        if (dir_add(&l, ico[i]) == RL_NONE)
            st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        memcpy(tri, faces, sizeof faces);
    for (int level = 0; level < levels && st == RL_OK; ++level) {
        uint32_t *next = malloc((size_t)nf * 4 * 3 * sizeof *next);
        if (!next) {
            st = RL_ERR_OUT_OF_MEMORY;
            break;
        }
        for (uint32_t f = 0; f < nf && st == RL_OK; ++f) {
            uint32_t a = tri[3 * f], b = tri[3 * f + 1], c = tri[3 * f + 2];
            uint32_t ab = dir_add(&l, rl_add(l.v[a], l.v[b]));
            uint32_t bc = dir_add(&l, rl_add(l.v[b], l.v[c]));
            uint32_t ca = dir_add(&l, rl_add(l.v[c], l.v[a]));
            if (ab == RL_NONE || bc == RL_NONE || ca == RL_NONE) {
                st = RL_ERR_OUT_OF_MEMORY;
                break;
            }
            const uint32_t sub[12] = { a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca };
            memcpy(next + 12 * f, sub, sizeof sub);
        }
        free(tri);
        tri = next;
        nf *= 4;
    }
    free(tri);
    if (st != RL_OK) {
        free(l.v);
        return st;
    }
    *out = l.v;
    *count = l.n;
    return RL_OK;
}

/* --- preprocessing --- */

static void sphere_of(rl_aabb b, rl_vec3 *c, float *r)
{
    *c = rl_aabb_center(b);
    *r = 0.5f * rl_length(rl_aabb_extent(b)) * 1.001f + 1e-6f;
}

/* Orthographic view of the sphere (c, r) from direction dir. */
static void ortho_view(rl_vec3 c, float r, rl_vec3 dir, rl_mat4 *view, rl_mat4 *proj)
{
    rl_vec3 eye = rl_add(c, rl_scale(dir, 2.0f * r));
    rl_vec3 up = fabsf(dir.y) > 0.99f ? rl_v3(1, 0, 0) : rl_v3(0, 1, 0);
    *view = rl_mat4_look_at(eye, c, up);
    *proj = rl_mat4_orthographic(r, r, 0.5f * r, 3.5f * r);   /* the sphere spans depths [r, 3r] */
}

typedef struct svs_worker {
    rl_image *img;
    rl_drawer *drawer;            /* IDs only, one thread: the workers run in parallel */
    uint32_t *cand;               /* candidate objects */
    uint32_t *stamp;              /* per object: dedupe of candidates and results */
    uint32_t tick;
} svs_worker;

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return x < y ? -1 : x > y;
}

/* The visible set of node n from direction k into out (ascending);
 * returns its size. */
static rl_status sample_set(const svs_state *s, const rl_scene_data *d, const rl_octree_node *nodes,
                            const uint32_t *objects, uint32_t *const *child_sets, const uint32_t *child_sizes,
                            uint32_t n, uint32_t k, svs_worker *w, uint32_t *out, uint32_t *size)
{
    const rl_octree_node *node = &nodes[n];
    if (++w->tick == 0) {
        memset(w->stamp, 0, d->num_objects * sizeof *w->stamp);
        w->tick = 1;
    }
    uint32_t nc = 0;
    for (uint32_t i = 0; i < node->num_objects; ++i) {
        uint32_t o = objects[node->first_object + i];
        if (w->stamp[o] != w->tick) {
            w->stamp[o] = w->tick;
            w->cand[nc++] = o;
        }
    }
    for (uint32_t c = 0; c < node->num_children; ++c) {
        const uint32_t *set = child_sets[c];
        for (uint32_t i = 0; i < child_sizes[c]; ++i)
            if (w->stamp[set[i]] != w->tick) {
                w->stamp[set[i]] = w->tick;
                w->cand[nc++] = set[i];
            }
    }
    *size = 0;
    if (nc <= 1) {   /* nothing can hide a lone object from outside */
        if (nc)
            out[(*size)++] = w->cand[0];
        return RL_OK;
    }
    rl_vec3 c;
    float r;
    sphere_of(node->bounds, &c, &r);
    rl_mat4 view, proj;
    ortho_view(c, r, s->dirs[k], &view, &proj);
    rl_image_clear(w->img);
    rl_status st = rl_drawer_begin(w->drawer, w->img, &view, &proj, rl_v3s(0.0f));
    if (st == RL_OK)
        st = rl_drawer_draw(w->drawer, w->cand, nc, NULL);
    if (st == RL_OK)
        st = rl_drawer_end(w->drawer);
    if (st != RL_OK)
        return st;
    if (++w->tick == 0) {
        memset(w->stamp, 0, d->num_objects * sizeof *w->stamp);
        w->tick = 1;
    }
    size_t np = (size_t)w->img->width * w->img->height;
    for (size_t p = 0; p < np; ++p) {
        uint32_t o = w->img->object_id[p];
        if (o < d->num_objects && w->stamp[o] != w->tick) {
            w->stamp[o] = w->tick;
            out[(*size)++] = o;
        }
    }
    qsort(out, *size, sizeof *out, cmp_u32);
    return RL_OK;
}

static rl_status build_sets(svs_state *s, const rl_scene *scene, int threads)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    uint32_t nn;
    const rl_octree_node *nodes = rl_octree_nodes(s->oc.tree, &nn);
    const uint32_t *objects = rl_octree_objects(s->oc.tree, NULL);
    rl_status st = make_directions(s->params.levels, &s->dirs, &s->num_dirs);
    if (st != RL_OK)
        return st;
    const uint32_t D = s->num_dirs;
    /* Per node and direction a set, built bottom-up (children have larger
     * indices than their parents), kept as separate arrays until packed. */
    uint32_t **sets = rl_calloc((size_t)nn * D, sizeof *sets);
    uint32_t *sizes = rl_calloc((size_t)nn * D, sizeof *sizes);
    s->stamp = rl_calloc(d->num_objects, sizeof *s->stamp);
    s->draw = rl_calloc(d->num_objects ? d->num_objects : 1, sizeof *s->draw);
    if (!sets || !sizes || !s->stamp || !s->draw) {
        free(sets);
        free(sizes);
        return RL_ERR_OUT_OF_MEMORY;
    }
#ifdef _OPENMP
    int nt = threads > 0 ? threads : omp_get_max_threads();
#else
    int nt = 1;
    (void)threads;
#endif
    svs_worker *w = rl_calloc((size_t)nt, sizeof *w);
    st = w ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    const rl_drawer_desc desc = { .flags = RL_RASTER_NO_COLOR, .threads = 1 };
    for (int i = 0; i < nt && st == RL_OK; ++i) {
        st = rl_image_create(s->params.resolution, s->params.resolution, RL_LAYER_DEPTH | RL_LAYER_ID, &w[i].img);
        if (st == RL_OK)
            st = rl_drawer_create(scene, &desc, &w[i].drawer);
        if (st == RL_OK) {
            w[i].cand = rl_calloc(d->num_objects, sizeof *w[i].cand);
            w[i].stamp = rl_calloc(d->num_objects, sizeof *w[i].stamp);
            if (!w[i].cand || !w[i].stamp)
                st = RL_ERR_OUT_OF_MEMORY;
        }
    }
    for (int64_t n = (int64_t)nn - 1; n >= 0 && st == RL_OK; --n) {
        const rl_octree_node *node = &nodes[n];
        rl_status shared = RL_OK;
#pragma omp parallel for num_threads(nt) schedule(dynamic, 1)
        for (int64_t k = 0; k < (int64_t)D; ++k) {
#ifdef _OPENMP
            svs_worker *me = &w[omp_get_thread_num()];
#else
            svs_worker *me = &w[0];
#endif
            uint32_t *child_sets[8];
            uint32_t child_sizes[8];
            uint32_t cap = node->num_objects;
            for (uint32_t c = 0; c < node->num_children; ++c) {
                size_t idx = (size_t)(node->first_child + c) * D + (size_t)k;
                child_sets[c] = sets[idx];
                child_sizes[c] = sizes[idx];
                cap += sizes[idx];
            }
            uint32_t *out = malloc(((size_t)cap + 1) * sizeof *out);
            uint32_t size = 0;
            rl_status my = out ? sample_set(s, d, nodes, objects, child_sets, child_sizes, (uint32_t)n,
                                            (uint32_t)k, me, out, &size)
                               : RL_ERR_OUT_OF_MEMORY;
            sets[(size_t)n * D + (size_t)k] = out;
            sizes[(size_t)n * D + (size_t)k] = size;
            if (my != RL_OK) {
#pragma omp critical(svs_error)
                shared = my;
            }
        }
        st = shared;
    }
    for (int i = 0; i < nt && w; ++i) {
        rl_image_release(w[i].img);
        rl_drawer_release(w[i].drawer);
        free(w[i].cand);
        free(w[i].stamp);
    }
    free(w);

    /* Pack into one array. */
    uint64_t total = 0;
    for (size_t i = 0; i < (size_t)nn * D; ++i)
        total += sizes[i];
    if (st == RL_OK) {
        s->set_offset = rl_calloc((size_t)nn * D + 1, sizeof *s->set_offset);
        s->set_objects = rl_calloc(total + 1, sizeof *s->set_objects);
        if (!s->set_offset || !s->set_objects)
            st = RL_ERR_OUT_OF_MEMORY;
    }
    uint64_t at = 0;
    for (size_t i = 0; i < (size_t)nn * D; ++i) {
        if (st == RL_OK) {
            s->set_offset[i] = at;
            memcpy(s->set_objects + at, sets[i], (size_t)sizes[i] * sizeof *sets[i]);
            at += sizes[i];
        }
        free(sets[i]);
    }
    if (st == RL_OK)
        s->set_offset[(size_t)nn * D] = at;
    free(sets);
    free(sizes);
    return st;
}

/* --- rendering --- */

typedef struct svs_frame {
    svs_state *s;
    const rl_scene_data *d;
    const rl_octree_node *nodes;
    const uint32_t *objects;
    rl_cull_frame cf;
    uint32_t neighbours;
    float distance;
} svs_frame;

static rl_status draw_object(svs_frame *f, uint32_t o)
{
    svs_state *s = f->s;
    if (s->stamp[o] == s->frame)
        return RL_OK;
    s->stamp[o] = s->frame;
    if (!rl_cull_box_in_frustum(&f->cf.view, f->d->objects[o].bounds))
        return RL_OK;
    s->head.stats.objects_drawn++;
    s->head.stats.triangles_drawn += f->d->objects[o].num_triangles;
    s->draw[s->num_draw++] = o;       /* once per frame (the stamp) */
    return RL_OK;
}

static rl_status draw_node(svs_frame *f, uint32_t n)
{
    svs_state *s = f->s;
    const rl_octree_node *node = &f->nodes[n];
    s->head.stats.nodes_visited++;
    if (!rl_cull_box_in_frustum(&f->cf.view, node->bounds)) {
        s->head.stats.nodes_frustum_culled++;
        return RL_OK;
    }
    rl_vec3 c;
    float r;
    sphere_of(node->bounds, &c, &r);
    rl_vec3 to_eye = rl_sub(f->cf.view.eye, c);
    float dist = rl_length(to_eye);
    rl_status st = RL_OK;
    if (dist > f->distance * r) {
        /* Outside the visibility sphere: the sets of the nearest samples. */
        rl_vec3 u = rl_scale(to_eye, 1.0f / dist);
        uint32_t best[12];
        float best_dot[12];
        uint32_t nb = 0;
        for (uint32_t k = 0; k < s->num_dirs; ++k) {
            float dk = rl_dot(u, s->dirs[k]);
            uint32_t j = nb < f->neighbours ? nb++ : nb;
            if (j == f->neighbours && !(dk > best_dot[j - 1]))
                continue;
            if (j == f->neighbours)
                --j;
            while (j > 0 && best_dot[j - 1] < dk) {
                best[j] = best[j - 1];
                best_dot[j] = best_dot[j - 1];
                --j;
            }
            best[j] = k;
            best_dot[j] = dk;
        }
        for (uint32_t i = 0; i < nb && st == RL_OK; ++i) {
            size_t idx = (size_t)n * s->num_dirs + best[i];
            for (uint64_t a = s->set_offset[idx]; a < s->set_offset[idx + 1] && st == RL_OK; ++a)
                st = draw_object(f, s->set_objects[a]);
        }
        s->head.stats.nodes_occluded += node->subtree_objects > 0;
        return st;
    }
    for (uint32_t k = 0; k < node->num_objects && st == RL_OK; ++k)
        st = draw_object(f, f->objects[node->first_object + k]);
    for (uint32_t ch = 0; ch < node->num_children && st == RL_OK; ++ch)
        st = draw_node(f, node->first_child + ch);
    return st;
}

static rl_status svs_render(rl_renderer *r, void *state, const rl_scene *scene, const rl_camera *cam,
                            rl_image *image, rl_render_stats *stats)
{
    svs_state *s = state;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    memset(&s->head.stats, 0, sizeof s->head.stats);
    s->head.have_frame = false;

    int depth = (int)rl_renderer_opt_int(r, "max_depth");
    svs_params p;
    memset(&p, 0, sizeof p);
    p.od = (rl_octree_desc){ .max_depth = depth ? depth : RL_OCTREE_DEPTH_ZERO,
                             .looseness = (float)rl_renderer_opt_float(r, "looseness") };
    p.levels = (int)rl_renderer_opt_int(r, "levels");
    p.resolution = (int)rl_renderer_opt_int(r, "resolution");
    const int threads = (int)rl_renderer_opt_int(r, "threads");
    rl_timer t0;
    rl_timer_start(&t0);
    bool rebuilt = false;
    rl_status st = rl_octree_cache_get(&s->oc, scene, &p.od, &rebuilt);
    if (st != RL_OK)
        return st;
    if (rebuilt || !s->built || memcmp(&p, &s->params, sizeof p) != 0 || s->scene_uid != rl_scene_uid(scene)) {
        drop_sets(s);
        s->params = p;
        s->scene_uid = rl_scene_uid(scene);
        st = build_sets(s, scene, threads);
        if (st != RL_OK) {
            drop_sets(s);
            return rl_error(st, "svs: visibility spheres of %u objects", d->num_objects);
        }
        s->built = true;
        s->frame = 0;
        s->head.stats.preprocess_ms = rl_timer_ms(&t0);
    }
    uint32_t nn;
    const rl_octree_node *nodes = rl_octree_nodes(s->oc.tree, &nn);
    s->head.stats.octree_nodes = nn;
    s->head.stats.octree_depth = rl_octree_depth(s->oc.tree);

    svs_frame f;
    memset(&f, 0, sizeof f);
    f.s = s;
    f.d = d;
    f.nodes = nodes;
    f.objects = rl_octree_objects(s->oc.tree, NULL);
    f.neighbours = (uint32_t)rl_renderer_opt_int(r, "neighbours");
    f.distance = (float)rl_renderer_opt_float(r, "distance");
    if (f.neighbours > s->num_dirs)
        f.neighbours = s->num_dirs;
    st = rl_cull_frame_begin(r, scene, &s->head, cam, image, true, &f.cf);
    if (st != RL_OK)
        return st;
    if (++s->frame == 0) {
        memset(s->stamp, 0, d->num_objects * sizeof *s->stamp);
        s->frame = 1;
    }
    s->num_draw = 0;
    st = draw_node(&f, 0);
    if (st == RL_OK)
        st = rl_drawer_draw(f.cf.drawer, s->draw, s->num_draw, &f.cf.counters);
    st = rl_cull_frame_end(&f.cf, st, image, stats);
    if (st != RL_OK)
        return st;
    stats->prep_ms = s->head.stats.preprocess_ms;
    s->head.have_frame = true;
    return RL_OK;
}

const rl_renderer_class rl_svs_renderer_class = {
    .info = { .name = "svs",
              .description = "Spherical Visibility Sampling: per octree node, the objects visible from outside in "
                             "sampled directions (approximate)",
              .reference = "Eikel, Jähn, Fischer & Meyer auf der Heide 2013; Jähn 2015, Sec. 2.1.1, 7.4",
              .frame_bytes_per_pixel = RL_CULL_FRAME_BYTES_PER_PIXEL },
    .options = svs_options,
    .num_options = sizeof svs_options / sizeof svs_options[0],
    .state_size = sizeof(svs_state),
    .render = svs_render,
    .release = svs_release,
    .check = NULL,
    .reset = NULL,
    .available = rl_cull_available,
};
