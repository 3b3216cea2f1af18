/* vt_draw.c: reconstruction of the radiance function (Ullmann 2003,
 * Sec. 3.5) through the software rasterizer: the second pass of Fig. 3.17.
 *
 * The non-VT objects are drawn by the raster renderer's own code (hybrid
 * rendering), then the leaf faces of the refined VT meshes with their
 * vertex samples interpolated by Gouraud shading. Textures are not part of
 * the samples (Sec. 3.5.3): each vertex carries, per term (the surface
 * itself, its reflection, its refraction), the light that a texel would
 * multiply and the texture coordinates where it would be looked up, and
 * the rasterizer does the lookup per pixel:
 *   multitexture (Sec. 3.5.5): one pass with four layers, the exact form of
 *       eq. 3.20 in our material model (a texture scales k_d only):
 *       D_prim T_prim + (R_prim + R_refl + R_trans) + D_refl T_refl + D_trans T_trans;
 *   multipass (Sec. 3.5.4): eq. 3.22 in three passes added with blending,
 *       each (C + C_comb) times its texture, the thesis' approximation;
 *   sampled: the textured radiance at the vertices, interpolated (what
 *       happens without deferred textures; for comparison).
 * A face whose three vertices see different reflected (or refracted)
 * textures is an "undefined face" (Fig. 3.21): for that term its vertices'
 * looked-up radiance is interpolated instead.
 *
 * Progressive display (Sec. 3.5.1): redraw rebuilds the image; overdraw
 * draws only the faces of the stages since the last update on top of it,
 * each vertex moved towards the eye by eq. 3.16,
 *     v_k = v - (v - p_a) f k,
 * so that children win the depth test against their parents.
 *
 * reconstruct = gl (run->drawer): the same corner batches, passes and
 * flags go to a GL drawer (rl_drawer_draw_batch; gl_shaders.c batch_vs /
 * batch_fs: Gouraud interpolation by the GPU, the layers' sum of eq. 3.20
 * per fragment, eq. 3.22's passes added by blending where GL_EQUAL finds
 * pass 1's depth), the non-VT objects by the same drawer's scene draw; a
 * frame of the drawer starts from the image as it is and reads it back
 * at its end, so progressive updates and redraws work on the image as
 * with the rasterizer. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/overlay.h"
#include "render/vt_run.h"
#include "rl/rl_timer.h"

#define NUM_LAYERS VT_NUM_LAYERS

void vt_corners_free(vt_corners *b)
{
    free(b->pos);
    for (int l = 0; l < NUM_LAYERS; ++l) {
        free(b->col[l]);
        free(b->uv[l]);
        free(b->tex[l]);
    }
    free(b->idx);
    free(b->tri_ids);
    free(b->obj_ids);
    free(b->faces);
    memset(b, 0, sizeof *b);
}

/* Frees the corner arrays, keeps the face list. */
static void free_corner_arrays(vt_corners *b)
{
    uint32_t *faces = b->faces;
    size_t faces_cap = b->faces_cap;
    b->faces = NULL;
    vt_corners_free(b);
    b->faces = faces;
    b->faces_cap = faces_cap;
}

/* Room for `faces` faces: grows by doubling, never shrinks. */
static bool reserve_corners(vt_corners *b, size_t faces)
{
    if (faces <= b->cap)
        return true;
    size_t cap = rl_grow_capacity(b->cap, faces, 1024);
    free_corner_arrays(b);
    size_t n = cap * 3;
    bool ok = (b->pos = rl_realloc_array(NULL, n, sizeof *b->pos)) &&
              (b->idx = rl_realloc_array(NULL, n, sizeof *b->idx)) &&
              (b->tri_ids = rl_realloc_array(NULL, cap, sizeof *b->tri_ids)) &&
              (b->obj_ids = rl_realloc_array(NULL, cap, sizeof *b->obj_ids));
    for (int l = 0; ok && l < NUM_LAYERS; ++l)
        ok = (b->col[l] = rl_realloc_array(NULL, n, sizeof *b->col[l])) &&
             (b->uv[l] = rl_realloc_array(NULL, n, sizeof *b->uv[l])) &&
             (b->tex[l] = rl_realloc_array(NULL, cap, sizeof *b->tex[l]));
    if (!ok)
        free_corner_arrays(b);
    else
        b->cap = cap;
    return ok;
}

static const rl_texture *texture_at(const rl_scene_data *d, uint32_t tex)
{
    return tex < d->num_textures ? d->textures[tex] : NULL;
}

/* Radiance of one deferred term looked up at the vertex (undefined faces). */
static rl_vec3 looked_up(const rl_scene_data *d, const rl_trace_layer *L)
{
    const rl_texture *t = texture_at(d, L->texture);
    if (!t)
        return rl_add(L->diffuse, L->rest);
    rl_vec4 texel = rl_texture_sample(t, L->uv);
    return rl_add(rl_mul(L->diffuse, rl_v3(texel.x, texel.y, texel.z)), L->rest);
}

static rl_vec4 c4(rl_vec3 c)
{
    return rl_v4_from3(c, 1.0f);
}

/* The texture of the term `layer` on the face when all three vertices see
 * the same one ("defined face", Fig. 3.20), else RL_NONE. */
static uint32_t defined_texture(const rl_scene_data *d, const rl_trace_layer v[3][RL_TRACE_LAYER_COUNT], int layer)
{
    uint32_t t = v[0][layer].texture;
    if (!texture_at(d, t))
        return RL_NONE;
    return v[1][layer].texture == t && v[2][layer].texture == t ? t : RL_NONE;
}

static uint32_t face_texture(const rl_scene_data *d, const vt_face *f)
{
    uint32_t tex = d->materials[d->triangle_material[f->triangle]].diffuse_texture;
    return texture_at(d, tex) ? tex : RL_NONE;
}

/* Fills face slot i (three corners) for the texture mode. */
static void fill_face(const vt_run *run, vt_corners *b, size_t i, const vt_face *f, bool offset)
{
    const rl_scene_data *d = run->data;
    rl_trace_layer v[3][RL_TRACE_LAYER_COUNT];
    for (int k = 0; k < 3; ++k)
        vt_mesh_sample_layers(run->mesh, f->v[k], v[k]);
    float shift = offset ? run->set->overdraw_f * (float)f->stage : 0.0f;
    uint32_t tex0 = face_texture(d, f);
    uint32_t tex_refl = defined_texture(d, v, RL_TRACE_LAYER_REFLECTION);
    uint32_t tex_refr = defined_texture(d, v, RL_TRACE_LAYER_REFRACTION);
    b->tri_ids[i] = f->triangle;
    b->obj_ids[i] = d->triangle_object[f->triangle];
    int mode = run->set->textures;
    b->tex[0][i] = mode == VT_TEX_SAMPLED ? RL_NONE : tex0;
    b->tex[1][i] = RL_NONE;
    b->tex[2][i] = mode == VT_TEX_SAMPLED ? RL_NONE : tex_refl;
    b->tex[3][i] = mode == VT_TEX_SAMPLED ? RL_NONE : tex_refr;
    for (int k = 0; k < 3; ++k) {
        size_t c = 3 * i + (size_t)k;
        const vt_vertex *xv = &run->mesh->verts[f->v[k]];
        /* eq. 3.16 */
        b->pos[c] = shift > 0.0f ? rl_sub(xv->p, rl_scale(rl_sub(xv->p, run->view.eye), shift)) : xv->p;
        b->idx[c] = (uint32_t)c;
        const rl_trace_layer *L = v[k];
        for (int l = 0; l < NUM_LAYERS; ++l)
            b->uv[l][c] = rl_v2(0.0f, 0.0f);
        if (mode == VT_TEX_SAMPLED) {
            b->col[0][c] = c4(run->mesh->samples[f->v[k]].flat);   /* the textured radiance in this mode */
            continue;
        }
        b->uv[0][c] = xv->uv;
        b->uv[2][c] = L[RL_TRACE_LAYER_REFLECTION].uv;
        b->uv[3][c] = L[RL_TRACE_LAYER_REFRACTION].uv;
        rl_vec3 refl = tex_refl != RL_NONE ? L[RL_TRACE_LAYER_REFLECTION].diffuse
                                           : looked_up(d, &L[RL_TRACE_LAYER_REFLECTION]);
        rl_vec3 refr = tex_refr != RL_NONE ? L[RL_TRACE_LAYER_REFRACTION].diffuse
                                           : looked_up(d, &L[RL_TRACE_LAYER_REFRACTION]);
        if (mode == VT_TEX_MULTITEXTURE) {
            /* eq. 3.20: only the diffuse parts are modulated. */
            rl_vec3 rest = L[RL_TRACE_LAYER_PRIMARY].rest;
            if (tex_refl != RL_NONE)
                rest = rl_add(rest, L[RL_TRACE_LAYER_REFLECTION].rest);
            if (tex_refr != RL_NONE)
                rest = rl_add(rest, L[RL_TRACE_LAYER_REFRACTION].rest);
            b->col[0][c] = c4(L[RL_TRACE_LAYER_PRIMARY].diffuse);
            b->col[1][c] = c4(rest);
            b->col[2][c] = c4(refl);
            b->col[3][c] = c4(refr);
        } else {
            /* eq. 3.22: (C + C_comb) x texture per pass. */
            b->col[0][c] = c4(rl_add(L[RL_TRACE_LAYER_PRIMARY].diffuse, L[RL_TRACE_LAYER_PRIMARY].rest));
            b->col[2][c] = c4(tex_refl != RL_NONE ? rl_add(refl, L[RL_TRACE_LAYER_REFLECTION].rest) : refl);
            b->col[3][c] = c4(tex_refr != RL_NONE ? rl_add(refr, L[RL_TRACE_LAYER_REFRACTION].rest) : refr);
        }
    }
}

static bool drawable(const vt_mesh *m, const vt_face *f)
{
    return m->verts[f->v[0]].state == VT_SAMPLED && m->verts[f->v[1]].state == VT_SAMPLED &&
           m->verts[f->v[2]].state == VT_SAMPLED;
}

static bool taken(const vt_run *run, const vt_face *face, bool only_new)
{
    return (only_new ? face->stage > run->drawn_stage : face->leaf) && drawable(run->mesh, face);
}

/* Faces per draw of a single-pass batch. The corners of a face take 364
 * bytes (three corners of four layers), and a 1024x1024 frame at min_edge
 * 1 draws 700,000 faces: a quarter of a GB for one batch, where chunks
 * need 6 MB. The rasterizer keeps submission order across draws as
 * within one, so the image is the same. */
#define DRAW_CHUNK 16384u

/* One pass of a batch: into the rasterizer, or the GL drawer's frame. */
static rl_status draw_pass(vt_run *run, rl_raster *ras, const rl_raster_batch *batch)
{
    return run->drawer ? rl_drawer_draw_batch(run->drawer, batch, &run->counters)
                       : rl_raster_draw(ras, batch, &run->counters);
}

/* The corner batch of faces list[0..count) into the rasterizer (or the
 * drawer), in the texture mode's passes. */
static rl_status draw_batch(vt_run *run, rl_raster *ras, const uint32_t *list, size_t count, bool offset,
                            unsigned id_flags)
{
    const vt_mesh *m = run->mesh;
    vt_corners *b = run->corners;
    if (!reserve_corners(b, count))
        return RL_ERR_OUT_OF_MEMORY;
    /* Each slot depends only on its face: any thread count gives the same
     * batch. */
    const int threads = count >= 4096 ? run->set->threads : 1;
    #pragma omp parallel for num_threads(threads) schedule(static)
    for (int64_t k = 0; k < (int64_t)count; ++k)
        fill_face(run, b, (size_t)k, &m->faces[list[k]], offset);

    rl_raster_batch batch;
    memset(&batch, 0, sizeof batch);
    batch.num_vertices = (uint32_t)(count * 3);
    batch.positions = b->pos;
    batch.num_triangles = (uint32_t)count;
    batch.indices = b->idx;
    batch.triangle_ids = b->tri_ids;
    batch.object_ids = b->obj_ids;
    batch.flags = id_flags;
    rl_raster_layer layers[NUM_LAYERS];
    for (int l = 0; l < NUM_LAYERS; ++l)
        layers[l] = (rl_raster_layer){ b->col[l], b->uv[l], b->tex[l], run->data->textures };
    rl_status st;
    if (run->set->textures == VT_TEX_SAMPLED) {
        batch.colors = b->col[0];
        st = draw_pass(run, ras, &batch);
    } else if (run->set->textures == VT_TEX_MULTITEXTURE) {
        batch.num_layers = NUM_LAYERS;
        batch.layers = layers;
        st = draw_pass(run, ras, &batch);
    } else {
        /* Sec. 3.5.4: pass 1 writes, passes 2 and 3 add where the same
         * faces are in front (depth equal). */
        batch.num_layers = 1;
        batch.layers = &layers[0];
        st = draw_pass(run, ras, &batch);
        for (int l = 2; st == RL_OK && l < NUM_LAYERS; ++l) {
            batch.layers = &layers[l];
            batch.flags = RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD | RL_RASTER_NO_DEPTH | RL_RASTER_NO_ID;
            st = draw_pass(run, ras, &batch);
        }
    }
    return st;
}

typedef struct pick_ctx {
    const vt_run *run;
    bool only_new;
} pick_ctx;

static bool pick_taken(const void *user, const vt_face *face)
{
    const pick_ctx *p = user;
    return taken(p->run, face, p->only_new);
}

static rl_status draw_faces(vt_run *run, rl_raster *ras, bool only_new, unsigned id_flags)
{
    vt_corners *b = run->corners;
    /* In creation order, as the faces were numbered when every split face
     * stayed (vt_mesh.drop_parents): the same submission order, so the
     * same depth ties and pixels written. */
    pick_ctx pick = { run, only_new };
    size_t count = 0;
    if (vt_mesh_pick_in_order(run->mesh, pick_taken, &pick, &b->faces, &b->faces_cap, &count) != RL_OK)
        return RL_ERR_OUT_OF_MEMORY;
    if (!count)
        return RL_OK;
    if (!only_new)
        run->stats.faces_drawn = count;
    const bool offset = run->set->progressive == VT_PROG_OVERDRAW;
    /* Multipass adds passes 2 and 3 where the depth equals pass 1's over
     * all faces; chunks would let a later chunk's equal-depth face drop an
     * earlier chunk's sums, so it draws the whole batch at once. */
    size_t chunk = run->set->textures == VT_TEX_MULTIPASS ? count : DRAW_CHUNK;
    rl_status st = RL_OK;
    for (size_t first = 0; st == RL_OK && first < count; first += chunk)
        st = draw_batch(run, ras, b->faces + first, count - first < chunk ? count - first : chunk, offset,
                        id_flags);
    return st;
}

rl_status vt_draw_target(vt_run *run, rl_image *target)
{
    *target = *run->image;
    if (!(target->layers & RL_LAYER_DEPTH) || !target->depth) {
        if (!run->scratch_depth)
            return rl_error(RL_ERR_INTERNAL, "vt: no scratch depth for an image without depth");
        target->depth = run->scratch_depth;
        target->layers |= RL_LAYER_DEPTH;
    }
    return RL_OK;
}

static unsigned id_flags_of(const rl_image *target)
{
    return (target->layers & RL_LAYER_ID) && target->object_id && target->triangle_id ? 0u
                                                                                    : RL_RASTER_NO_ID;
}

/* The frame's rasterizer (kept by the renderer), aimed at target; with a
 * GL drawer its frame into target begins instead (*out stays NULL) and
 * close_raster ends it. */
static rl_status open_raster(vt_run *run, rl_image *target, rl_raster **out)
{
    *out = NULL;
    if (run->drawer)
        return rl_drawer_begin(run->drawer, target, &run->view_m, &run->proj_m, run->view.eye);
    rl_status st = rl_raster_set_target(run->ras, target, &run->view_m, &run->proj_m);
    if (st == RL_OK)
        *out = run->ras;
    return st;
}

/* The drawer's frame ended after what st says of its draws: read back
 * where they succeeded (a failed call has ended the frame already). */
static rl_status close_raster(vt_run *run, rl_status st)
{
    if (!run->drawer || st != RL_OK)
        return st;
    return rl_drawer_end(run->drawer);
}

/* Copies n items between the frame and the kept base, when both exist. */
static void copy_layer(void *dst, const void *src, size_t n, size_t size)
{
    if (dst && src)
        memcpy(dst, src, n * size);
}

/* The frame's layers into the kept base (save) or back (restore); IDs only
 * when the frame has them. */
static void copy_base(vt_run *run, const rl_image *target, bool save)
{
    size_t n = (size_t)target->width * (size_t)target->height;
    bool ids = !(id_flags_of(target) & RL_RASTER_NO_ID);
    void *frame[4] = { target->color, target->depth, ids ? target->object_id : NULL,
                       ids ? target->triangle_id : NULL };
    void *base[4] = { run->base->color, run->base->depth, run->base->object_id, run->base->triangle_id };
    const size_t size[4] = { sizeof *target->color, sizeof *target->depth, sizeof(uint32_t), sizeof(uint32_t) };
    for (int k = 0; k < 4; ++k)
        copy_layer(save ? base[k] : frame[k], save ? frame[k] : base[k], n, size[k]);
}

rl_status vt_draw_base(vt_run *run)
{
    double t0 = rl_time_s() * 1000.0;
    rl_image target;
    rl_status st = vt_draw_target(run, &target);
    rl_raster *ras = NULL;
    if (st == RL_OK) {
        /* Fig. 3.17, second pass, its rasterized half: clear, the non-VT
         * objects. Drawn once: the pre-pass adds the VT objects to a copy
         * of this depth (with a GL drawer, to its own software depth of
         * them: vt_prepass), the VT faces go on top of it. */
        rl_image_clear_to(&target, rl_v4_from3(run->set->background, 1.0f));
        st = open_raster(run, &target, &ras);
    }
    if (st == RL_OK && run->drawer) {
        /* The drawer was made with object_raster as its object mask. */
        st = close_raster(run, rl_drawer_draw_all(run->drawer, &run->counters, NULL, NULL));
    } else if (st == RL_OK) {
        rl_drawer_desc desc = { .shading = run->set->shading, .ambient = run->set->ambient,
                                      .threads = run->set->threads, .flags = id_flags_of(&target),
                                      .object_mask = run->object_raster };
        st = rl_raster_draw_scene(ras, run->data, run->view.eye, &desc, &run->counters, NULL, NULL);
    }
    size_t n = (size_t)target.width * (size_t)target.height;
    if (st == RL_OK && run->update) {
        bool ids = !(id_flags_of(&target) & RL_RASTER_NO_ID);
        vt_base *b = run->base;
        if (!rl_reserve((void **)&b->color, &b->color_cap, n, sizeof *b->color, n) ||
            !rl_reserve((void **)&b->depth, &b->depth_cap, n, sizeof *b->depth, n) ||
            (ids && (!rl_reserve((void **)&b->object_id, &b->object_id_cap, n, sizeof *b->object_id, n) ||
                     !rl_reserve((void **)&b->triangle_id, &b->triangle_id_cap, n, sizeof *b->triangle_id, n))))
            st = RL_ERR_OUT_OF_MEMORY;
        else {
            copy_base(run, &target, true);
            run->have_base = true;
        }
    }
    run->stats.time_draw_ms += rl_time_s() * 1000.0 - t0;
    return st;
}

void vt_base_free(vt_base *b)
{
    free(b->color);
    free(b->depth);
    free(b->object_id);
    free(b->triangle_id);
    memset(b, 0, sizeof *b);
}

rl_status vt_draw(vt_run *run, bool only_new)
{
    rl_image target;
    rl_status st = vt_draw_target(run, &target);
    if (st != RL_OK)
        return st;
    if (only_new && !run->drawn)
        only_new = false;
    if (!only_new && run->drawn) {
        /* A full redraw starts again from the rasterized half. */
        if (!run->have_base)
            return rl_error(RL_ERR_INTERNAL, "vt: redraw without the kept rasterized image");
        copy_base(run, &target, false);
    }
    rl_raster *ras = NULL;
    st = open_raster(run, &target, &ras);
    if (st == RL_OK)
        st = close_raster(run, draw_faces(run, ras, only_new, id_flags_of(&target)));
    if (st == RL_OK)
        run->drawn = true;
    return st;
}

/* ------------------------------------------------------------- overlay -- */

void vt_draw_overlay(vt_run *run)
{
    const vt_mesh *m = run->mesh;
    rl_image *img = run->image;
    if (run->set->overlay == VT_OVERLAY_WIRE) {
        rl_vec4 c = rl_v4(0.9f, 0.9f, 0.9f, 1.0f);
        for (uint32_t f = 0; f < m->num_faces; ++f) {
            const vt_face *face = &m->faces[f];
            if (!face->leaf || !drawable(m, face) || !face->visible)
                continue;
            for (int k = 0; k < 3; ++k) {
                const vt_vertex *a = &m->verts[face->v[k]], *b = &m->verts[face->v[(k + 1) % 3]];
                if (a->cw > 0.0f && b->cw > 0.0f)
                    rl_overlay_line(img, a->sx, a->sy, b->sx, b->sy, c);
            }
        }
    } else if (run->set->overlay == VT_OVERLAY_SAMPLES) {
        /* Fig. 5.2c-d: red for discontinuities (ray tree), yellow for
         * non-linearities (intensity), blue for forced refinement, grey for
         * the initial pattern. Sec. 6.1's splits join their kind: shafts
         * the discontinuities, the nonlinearity tests the intensities. */
        for (uint32_t v = 0; v < m->num_verts; ++v) {
            const vt_vertex *x = &m->verts[v];
            if (x->state != VT_SAMPLED || !(x->cw > 0.0f))
                continue;
            uint8_t r = run->reason && v < run->per_vertex_cap ? run->reason[v] : 0;
            rl_vec4 c = (r & (VT_REASON_TREE | VT_REASON_SHAFT)) ? rl_v4(1.0f, 0.1f, 0.1f, 1.0f)
                      : (r & (VT_REASON_RGB | VT_REASON_HSV | VT_REASON_NONLINEAR)) ? rl_v4(1.0f, 0.9f, 0.1f, 1.0f)
                      : (r & VT_REASON_FORCED) ? rl_v4(0.2f, 0.5f, 1.0f, 1.0f)
                      : rl_v4(0.6f, 0.6f, 0.6f, 1.0f);
            rl_overlay_plot(img, (int)floorf(x->sx), (int)floorf(x->sy), c);
        }
    }
}

bool vt_update(vt_run *run, uint32_t stage, bool final)
{
    bool overdraw = run->set->progressive == VT_PROG_OVERDRAW;
    if (!final || !run->drawn || !overdraw || stage != run->drawn_stage) {
        if (vt_draw(run, overdraw && run->drawn) != RL_OK) {
            run->failed = true;
            return false;
        }
        run->drawn_stage = stage;
    }
    if (final)
        vt_draw_overlay(run);
    return run->update ? run->update(run->update_user, run->image, stage, final) : true;
}
