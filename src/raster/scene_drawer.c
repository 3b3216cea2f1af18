/* scene_drawer.c: how a committed scene is drawn by the software
 * rasterizer (scene_drawer.h): local Phong lighting and one batch per
 * object. The "raster" renderer draws through it, and so do the hybrid and
 * culling renderers (Vertex Tracing's ID/Z pre-pass and non-VT objects,
 * CHC++, SVS, visset, surfels) and the visibility property, so that
 * "rasterized" means the same thing everywhere.
 *
 * Lighting is the local part of the Phong model of Ullmann 2003, Sec. 3.1
 * (eq. 3.1 without the k_r/k_t terms): emission + ambient * k_d +
 * sum over lights of E * (k_d max(0, n.l) + k_s max(0, r.v)^n). It is
 * evaluated per vertex and interpolated by the rasterizer (gouraud,
 * textured) or once per triangle at its centroid with the geometric normal
 * (flat). No shadows: a rasterizer has no visibility between surface and
 * light.
 *
 * Deviations, on purpose:
 *  - two-sided lighting: the normal is flipped towards the viewer, so open
 *    meshes and meshes with inconsistent winding look the same from both
 *    sides (OpenGL's GL_LIGHT_MODEL_TWO_SIDE);
 *  - quad lights are approximated by a point light at their centre with
 *    intensity * area * max(0, cos at the light);
 *  - textured: the rasterizer multiplies the whole interpolated colour by
 *    the texel, so the texture modulates specular and emission too, not only
 *    k_d as in the ray tracers. Fine for matte textured scenes, which is
 *    what textures are used for here. The rasterizer could now split it
 *    (two layers, or a second RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD
 *    pass, Ullmann 2003, Sec. 3.5.4-3.5.5); not done, so that "raster"
 *    images stay comparable with earlier runs.
 *
 * Materials from real models (glTF 2.0): alpha masks drop fragments in
 * every pass, lit or not, so IDs and depth show the holes the ray tracers
 * see; normal maps are applied per pixel by rl_scene_drawer_finish, a
 * deferred pass over the ID layer at the end of a frame, because Gouraud
 * interpolation would blur a map's detail away.
 *
 * With RL_RASTER_NO_COLOR nothing is lit at all (the ID/Z pre-pass of
 * Vertex Tracing). An object whose box lies outside the view is neither
 * lit nor drawn (rl_raster_box_outside: the rasterizer would drop all of
 * its triangles), and in gouraud and textured shading a vertex is lit only
 * when the rasterizer keeps a triangle that uses it (rl_raster_lazy_colors);
 * both leave the image as it was and save most of the work of a frame in a
 * large scene. A colour lit in an earlier frame is kept where it cannot
 * have changed (phong_cached: no specular term, the same side towards the
 * eye), so a moving camera relights few vertices of most scenes. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#ifdef _OPENMP
#include <omp.h>
#endif

#include "core/error.h"
#include "raster/scene_drawer.h"
#include "rl/rl_raster.h"
#include "scene/light_eval.h"
#include "scene/masks.h"
#include "scene/tri_plane.h"

/* What every lighting evaluation needs; read-only, shared by all threads. */
typedef struct shade_ctx {
    const rl_scene_data *data;
    rl_vec3 eye;
    float ambient;
} shade_ctx;

/* Irradiance-like scale E of light L at p and the unit direction l towards
 * it; returns false where the light does not reach p. */
static bool light_at(const rl_light *L, rl_vec3 p, rl_vec3 *E, rl_vec3 *l)
{
    float dist;
    if (L->type != RL_LIGHT_QUAD)
        return rl_light_eval_delta(L, p, E, l, &dist);
    /* A quad light as one point at its centre, emitting side only and
     * foreshortened like a small area light: power·area·cos_light / d². */
    rl_vec3 normal = rl_cross(L->edge_u, L->edge_v);
    float area = rl_length(normal);
    rl_vec3 pos = rl_add(L->position, rl_scale(rl_add(L->edge_u, L->edge_v), 0.5f));
    rl_vec3 to_light = rl_sub(pos, p);
    float d2 = rl_length2(to_light);
    if (!(d2 > 0.0f) || !(area > 0.0f))
        return false;
    *l = rl_scale(to_light, 1.0f / sqrtf(d2));
    float cos_light = rl_dot(rl_scale(normal, 1.0f / area), rl_neg(*l));
    rl_vec3 power = rl_scale(rl_scale(L->color, L->intensity), area * rl_maxf(0.0f, cos_light));
    *E = rl_scale(power, 1.0f / d2);
    return cos_light > 0.0f;
}

/* The direction from p to the eye, and whether two-sided lighting turns
 * n around to face it. */
static inline bool phong_flips(const shade_ctx *ctx, rl_vec3 p, rl_vec3 n, rl_vec3 *v)
{
    *v = rl_normalize(rl_sub(ctx->eye, p));
    return rl_dot(n, *v) < 0.0f;
}

/* Whether phong() depends on the eye only through phong_flips(): without
 * a specular term the eye's direction enters nowhere else. */
static inline bool phong_view_free(const rl_material *m)
{
    return !(rl_vmax_comp(m->specular) > 0.0f);
}

/* phong() with n already facing the viewer and v from phong_flips(). */
static rl_vec4 phong_lit(const shade_ctx *ctx, const rl_material *m, rl_vec3 p, rl_vec3 n, rl_vec3 v)
{
    rl_vec3 c = rl_add(m->emission, rl_scale(m->diffuse, ctx->ambient));
    bool specular = !phong_view_free(m);
    for (uint32_t i = 0; i < ctx->data->num_lights; ++i) {
        rl_vec3 E, l;
        if (!light_at(&ctx->data->lights[i], p, &E, &l))
            continue;
        float n_dot_l = rl_dot(n, l);
        if (n_dot_l <= 0.0f)
            continue;
        rl_vec3 term = rl_scale(m->diffuse, n_dot_l);
        if (specular) {
            rl_vec3 r = rl_sub(rl_scale(n, 2.0f * n_dot_l), l);   /* l mirrored about n */
            float r_dot_v = rl_maxf(0.0f, rl_dot(r, v));
            term = rl_add(term, rl_scale(m->specular, powf(r_dot_v, m->shininess)));
        }
        c = rl_add(c, rl_mul(term, E));
    }
    return rl_v4_from3(c, 1.0f);
}

/* Local Phong colour at p with shading normal n (Ullmann 2003, eq. 3.1
 * without the recursive terms). */
static rl_vec4 phong(const shade_ctx *ctx, const rl_material *m, rl_vec3 p, rl_vec3 n)
{
    rl_vec3 v;
    if (phong_flips(ctx, p, n, &v))
        n = rl_neg(n);                        /* two-sided lighting */
    return phong_lit(ctx, m, p, n, v);
}

/* Values of a vertex's (or corner's) lit_side: what its colour holds. */
enum { SIDE_NONE, SIDE_FRONT, SIDE_BACK };

/* phong() into *out, kept from an earlier frame where that is the same
 * value: a material without specular lights a vertex with one of two
 * colours, one per side it shows the eye, neither of which depends on
 * where the eye is (the lights, the material and the ambient term are the
 * drawer's for its whole life). *side remembers which of them *out holds,
 * so that a still or slowly moving camera relights only the vertices
 * whose side turned and those with a specular term; the kept colour is
 * the same computation on the same inputs, so images stay bit-identical. */
static void phong_cached(const shade_ctx *ctx, const rl_material *m, rl_vec3 p, rl_vec3 n, uint8_t *side,
                         rl_vec4 *out)
{
    rl_vec3 v;
    const bool flips = phong_flips(ctx, p, n, &v);
    const uint8_t now = flips ? SIDE_BACK : SIDE_FRONT;
    const bool view_free = phong_view_free(m);
    if (view_free && *side == now)
        return;
    *out = phong_lit(ctx, m, p, flips ? rl_neg(n) : n, v);
    *side = view_free ? now : SIDE_NONE;
}

rl_vec3 rl_raster_light_diffuse(const rl_scene_data *d, rl_vec3 p, rl_vec3 n, rl_vec3 kd, float ambient,
                                rl_vec3 eye)
{
    rl_vec3 v = rl_sub(eye, p);
    if (rl_dot(n, v) < 0.0f)
        n = rl_neg(n);                        /* two-sided, as phong() */
    rl_vec3 c = rl_scale(kd, ambient);
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        rl_vec3 E, l;
        if (!light_at(&d->lights[i], p, &E, &l))
            continue;
        float n_dot_l = rl_dot(n, l);
        if (n_dot_l > 0.0f)
            c = rl_add(c, rl_mul(rl_scale(kd, n_dot_l), E));
    }
    return c;
}

/* Per-draw buffers; everything is NULL unless the shading mode needs it. */
typedef struct frame_buffers {
    uint32_t *object_material;   /* per object: shared material or RL_NONE */
    uint32_t *vertex_material;   /* per vertex of single-material objects */
    rl_vec4 *vertex_colors;      /* gouraud/textured, single-material objects */
    rl_vec4 *face_colors;        /* flat */
    /* Per vertex, face and corner colour: which side's colour it holds
     * (phong_cached), kept across frames. */
    uint8_t *vertex_side, *face_side, *corner_side;
    /* Objects mixing materials: one vertex per triangle corner, indexed by
     * 3 * global triangle index, because a shared vertex would need one
     * colour per material. */
    rl_vec3 *corner_positions;
    rl_vec2 *corner_uvs;
    rl_vec4 *corner_colors;
    uint32_t *triangle_texture;  /* per triangle, textured mode */
    /* Per scene corner (3 per triangle): the index its object's batch
     * uses for it, the object-local vertex (or, for objects drawn by
     * corners, the local corner). Made when the object is first drawn and
     * kept: the batches of a list must all be ready before
     * rl_raster_draw_many, and calloc leaves the pages of objects never
     * drawn untouched. */
    uint32_t *local;
    uint8_t *local_ready;        /* per object */
    /* Alpha masks, per scene triangle, only when some material has one:
     * its texture (RL_ID_NONE: whole) and cutoff (rl_raster_batch). */
    uint32_t *mask_texture;
    float *mask_cutoff;
} frame_buffers;

static void free_buffers(frame_buffers *b)
{
    free(b->object_material);
    free(b->vertex_material);
    free(b->vertex_colors);
    free(b->face_colors);
    free(b->vertex_side);
    free(b->face_side);
    free(b->corner_side);
    free(b->corner_positions);
    free(b->corner_uvs);
    free(b->corner_colors);
    free(b->triangle_texture);
    free(b->local);
    free(b->local_ready);
    free(b->mask_texture);
    free(b->mask_cutoff);
}

static uint32_t texture_of(const rl_scene_data *d, uint32_t material)
{
    uint32_t t = d->materials[material].diffuse_texture;
    return t < d->num_textures ? t : RL_ID_NONE;
}

/* The per-triangle mask arrays, when the scene has any masked material:
 * every pass (lit or not) drops the same fragments, as the ray tracers
 * skip the same hits. */
static rl_status prepare_masks(const rl_scene_data *d, frame_buffers *b)
{
    if (!rl_data_has_masks(d))
        return RL_OK;
    b->mask_texture = rl_calloc((size_t)d->num_triangles + 1, sizeof *b->mask_texture);
    b->mask_cutoff = rl_calloc((size_t)d->num_triangles + 1, sizeof *b->mask_cutoff);
    if (!b->mask_texture || !b->mask_cutoff)
        return RL_ERR_OUT_OF_MEMORY;
    for (size_t t = 0; t < d->num_triangles; ++t) {
        uint32_t m = d->triangle_material[t];
        b->mask_texture[t] = rl_material_mask(d, m);
        b->mask_cutoff[t] = d->materials[m].alpha_cutoff;
    }
    return RL_OK;
}

static bool selected(const uint8_t *mask, uint32_t object)
{
    return !mask || mask[object];
}

/* Allocates what the mode needs and finds each object's shared material.
 * Unlit draws need only the index scratch; unselected objects get no
 * lighting (their vertices keep material RL_NONE). */
static rl_status prepare(const rl_scene_data *d, rl_raster_shading shading, bool lit,
                         const uint8_t *mask, frame_buffers *b)
{
    bool any_mixed = false;
    b->object_material = rl_calloc(d->num_objects ? d->num_objects : 1, sizeof *b->object_material);
    if (!b->object_material)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *obj = &d->objects[o];
        uint32_t m = rl_object_material(d, o);
        b->object_material[o] = m;
        any_mixed |= obj->num_triangles > 0 && m == RL_NONE && selected(mask, o);
    }
    b->local = rl_calloc((size_t)d->num_triangles * 3 + 1, sizeof *b->local);
    b->local_ready = rl_calloc(d->num_objects ? d->num_objects : 1, 1);
    if (!b->local || !b->local_ready)
        return RL_ERR_OUT_OF_MEMORY;
    rl_status st = prepare_masks(d, b);
    if (st != RL_OK || !lit)
        return st;

    if (shading == RL_SHADING_FLAT) {
        b->face_colors = rl_calloc((size_t)d->num_triangles + 1, sizeof *b->face_colors);
        b->face_side = rl_calloc((size_t)d->num_triangles + 1, sizeof *b->face_side);
        return b->face_colors && b->face_side ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    }

    size_t nv = (size_t)d->num_vertices + 1;
    b->vertex_material = rl_calloc(nv, sizeof *b->vertex_material);
    b->vertex_colors = rl_calloc(nv, sizeof *b->vertex_colors);
    b->vertex_side = rl_calloc(nv, sizeof *b->vertex_side);
    if (!b->vertex_material || !b->vertex_colors || !b->vertex_side)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t v = 0; v < d->num_vertices; ++v)
        b->vertex_material[v] = RL_NONE;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *obj = &d->objects[o];
        if (!selected(mask, o))
            continue;
        for (uint32_t v = 0; v < obj->num_vertices; ++v)
            b->vertex_material[obj->first_vertex + v] = b->object_material[o];
    }
    if (!any_mixed)
        return RL_OK;
    size_t corners = (size_t)d->num_triangles * 3;
    b->corner_positions = rl_calloc(corners, sizeof *b->corner_positions);
    b->corner_uvs = rl_calloc(corners, sizeof *b->corner_uvs);
    b->corner_colors = rl_calloc(corners, sizeof *b->corner_colors);
    b->corner_side = rl_calloc(corners, sizeof *b->corner_side);
    b->triangle_texture = rl_calloc(d->num_triangles, sizeof *b->triangle_texture);
    if (!b->corner_positions || !b->corner_uvs || !b->corner_colors || !b->corner_side || !b->triangle_texture)
        return RL_ERR_OUT_OF_MEMORY;
    /* What does not depend on the eye, once: positions, uvs, textures. */
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *obj = &d->objects[o];
        if (b->object_material[o] != RL_NONE || !selected(mask, o))
            continue;
        for (size_t t = obj->first_triangle; t < (size_t)obj->first_triangle + obj->num_triangles; ++t) {
            uint32_t m = d->triangle_material[t];
            for (int k = 0; k < 3; ++k) {
                uint32_t vi = d->indices[3 * t + k];
                b->corner_positions[3 * t + k] = d->positions[vi];
                b->corner_uvs[3 * t + k] = d->uvs[vi];
            }
            b->triangle_texture[t] = shading == RL_SHADING_TEXTURED ? texture_of(d, m) : RL_ID_NONE;
        }
    }
    return RL_OK;
}

/* Flat shading of triangle t: the geometric normal at its centroid. */
static void light_face(const shade_ctx *ctx, frame_buffers *b, int64_t t)
{
    const rl_scene_data *d = ctx->data;
    const uint32_t *tri = &d->indices[3 * t];
    rl_vec3 p0 = d->positions[tri[0]], p1 = d->positions[tri[1]], p2 = d->positions[tri[2]];
    rl_vec3 centroid = rl_scale(rl_add(rl_add(p0, p1), p2), 1.0f / 3.0f);
    rl_vec3 n = rl_normalize(rl_cross(rl_sub(p1, p0), rl_sub(p2, p0)));
    phong_cached(ctx, &d->materials[d->triangle_material[t]], centroid, n, &b->face_side[t], &b->face_colors[t]);
}

/* Corner c (3 t + k) of triangle t of a mixed-material object, lit with
 * the triangle's own material (prepare() made its position and uv). */
static void light_corner(const shade_ctx *ctx, frame_buffers *b, size_t c)
{
    const rl_scene_data *d = ctx->data;
    uint32_t vi = d->indices[c];
    phong_cached(ctx, &d->materials[d->triangle_material[c / 3]], d->positions[vi], d->normals[vi],
                 &b->corner_side[c], &b->corner_colors[c]);
}

/* Object o's batch indices (b->local), made on its first draw: the
 * identity over its corners when it is drawn by corners, else its triangles'
 * scene indices made local to its vertices. */
static rl_status object_indices(const rl_scene_data *d, frame_buffers *b, uint32_t o, bool corners)
{
    if (b->local_ready[o])
        return RL_OK;
    const rl_object *obj = &d->objects[o];
    const size_t first = (size_t)obj->first_triangle * 3, n = (size_t)obj->num_triangles * 3;
    uint32_t *local = b->local + first;
    if (corners) {
        for (size_t i = 0; i < n; ++i)
            local[i] = (uint32_t)i;
    } else {
        /* Scene indices are global; the batch sees only this object's vertices. */
        const uint32_t *tri = d->indices + first;
        for (size_t i = 0; i < n; ++i) {
            local[i] = tri[i] - obj->first_vertex;
            if (tri[i] < obj->first_vertex || local[i] >= obj->num_vertices)
                return rl_error(RL_ERR_INTERNAL, "raster: object %u has a vertex index outside its range", o);
        }
    }
    b->local_ready[o] = 1;
    return RL_OK;
}

/* One batch per object: object IDs come from the batch, triangle IDs are the
 * scene's global (flattened) triangle indices. Unlit draws take the
 * object's own vertices even for mixed materials: the corner copies hold
 * the same positions, so depth and IDs are bit-identical either way. lazy
 * (NULL: colours filled already) must outlive the draw of the batch. */
static rl_status object_batch(const rl_scene_data *d, uint32_t o, rl_raster_shading shading, bool lit,
                              unsigned flags, frame_buffers *b, const rl_raster_lazy_colors *lazy,
                              rl_raster_batch *batch)
{
    const rl_object *obj = &d->objects[o];
    memset(batch, 0, sizeof *batch);
    batch->num_triangles = obj->num_triangles;
    batch->first_triangle_id = obj->first_triangle;
    batch->object_id = o;
    batch->flags = flags;
    batch->indices = b->local + (size_t)obj->first_triangle * 3;

    uint32_t m = b->object_material[o];
    const bool corners = lit && shading != RL_SHADING_FLAT && m == RL_NONE;
    rl_status st = object_indices(d, b, o, corners);
    if (st != RL_OK)
        return st;
    const size_t first = (size_t)obj->first_triangle * 3;
    if (corners) {
        batch->num_vertices = obj->num_triangles * 3;
        batch->positions = b->corner_positions + first;
        batch->colors = b->corner_colors + first;
        batch->lazy = lazy;
        if (shading == RL_SHADING_TEXTURED) {
            batch->uvs = b->corner_uvs + first;
            batch->triangle_texture = b->triangle_texture + obj->first_triangle;
            batch->textures = d->textures;
        }
    } else {
        batch->num_vertices = obj->num_vertices;
        batch->positions = d->positions + obj->first_vertex;
        if (lit && shading == RL_SHADING_FLAT) {
            batch->face_colors = b->face_colors + obj->first_triangle;
        } else if (lit) {
            batch->colors = b->vertex_colors + obj->first_vertex;
            batch->lazy = lazy;
            uint32_t tex = shading == RL_SHADING_TEXTURED ? texture_of(d, m) : RL_ID_NONE;
            if (tex != RL_ID_NONE) {
                batch->uvs = d->uvs + obj->first_vertex;
                batch->texture = d->textures[tex];
            }
        }
    }
    if (b->mask_texture) {
        /* uvs alone texture nothing (only a texture does), so setting them
         * for the mask leaves gouraud and flat colours as they were. */
        batch->uvs = corners ? b->corner_uvs + first : d->uvs + obj->first_vertex;
        batch->textures = d->textures;
        batch->mask_texture = b->mask_texture + obj->first_triangle;
        batch->mask_cutoff = b->mask_cutoff + obj->first_triangle;
    }
    return RL_OK;
}

/* The drawer: buffers prepared once, objects lit on first draw. */
struct rl_scene_drawer {
    const rl_scene_data *data;
    rl_drawer_desc opt;
    bool lit;                    /* the draws write colour */
    bool normal_maps;            /* lit per vertex, and some material has a normal map */
    shade_ctx ctx;
    int threads;
    uint8_t *object_lit;         /* per object: lighting done */
    uint32_t *todo;              /* scratch of rl_scene_drawer_light, one per object */
    /* Lazy lighting (rl_raster_lazy_colors) in gouraud/textured mode: a
     * stamp per scene vertex and per corner of mixed-material objects, and
     * the value of this frame's lighting. */
    uint32_t *stamps;            /* per vertex (single-material objects) */
    uint32_t *corner_stamps;     /* per corner (mixed objects), if any */
    uint32_t frame;
    frame_buffers b;
    /* Scratch of a list draw (rl_scene_drawer_draw_list): the objects to
     * draw, their batches and their lazy colours, list_cap of each. */
    uint32_t *list;
    rl_raster_batch *batches;
    struct lazy_slot *lazies;
    size_t list_cap;
};

static rl_status check_desc(const rl_drawer_desc *opt, const char *fn)
{
    if (opt->shading != RL_SHADING_FLAT && opt->shading != RL_SHADING_GOURAUD &&
        opt->shading != RL_SHADING_TEXTURED)
        return rl_error(RL_ERR_INVALID_ARG, "%s: unknown shading %d", fn, (int)opt->shading);
    if (opt->threads < 0)
        return rl_error(RL_ERR_INVALID_ARG, "%s: threads %d < 0", fn, opt->threads);
    return RL_OK;
}

void rl_scene_drawer_release(rl_scene_drawer *dr)
{
    if (!dr)
        return;
    free_buffers(&dr->b);
    free(dr->object_lit);
    free(dr->todo);
    free(dr->stamps);
    free(dr->corner_stamps);
    free(dr->list);
    free(dr->batches);
    free(dr->lazies);
    free(dr);
}

rl_status rl_scene_drawer_create(const rl_scene_data *d, rl_vec3 eye, const rl_drawer_desc *desc,
                                 rl_scene_drawer **out)
{
    if (!d || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_drawer_create: NULL argument");
    *out = NULL;
    rl_scene_drawer *dr = rl_calloc(1, sizeof *dr);
    if (!dr)
        return RL_ERR_OUT_OF_MEMORY;
    dr->data = d;
    if (desc)
        dr->opt = *desc;
    rl_status st = check_desc(&dr->opt, "rl_scene_drawer_create");
    if (st != RL_OK) {
        free(dr);
        return st;
    }
    dr->lit = !(dr->opt.flags & RL_RASTER_NO_COLOR);
    /* Multi-pass blending (DEPTH_EQUAL, BLEND_ADD) adds to what is there;
     * a per-pixel pass that replaces colours would break it. */
    for (uint32_t m = 0; m < d->num_materials && dr->lit && dr->opt.shading != RL_SHADING_FLAT &&
                         !(dr->opt.flags & (RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD)); ++m)
        dr->normal_maps |= d->materials[m].normal_texture < d->num_textures;
#ifdef _OPENMP
    dr->threads = dr->opt.threads > 0 ? dr->opt.threads : omp_get_max_threads();
#else
    dr->threads = 1;
#endif
    dr->ctx = (shade_ctx){ d, eye, dr->opt.ambient };
    dr->object_lit = rl_calloc(d->num_objects ? d->num_objects : 1, 1);
    dr->todo = dr->lit ? rl_calloc(d->num_objects ? d->num_objects : 1, sizeof *dr->todo) : NULL;
    bool lazy = dr->lit && dr->opt.shading != RL_SHADING_FLAT;
    dr->stamps = lazy ? rl_calloc((size_t)d->num_vertices + 1, sizeof *dr->stamps) : NULL;
    dr->frame = 1;
    bool have = dr->object_lit && (dr->todo || !dr->lit) && (dr->stamps || !lazy);
    st = have ? prepare(d, dr->opt.shading, dr->lit, dr->opt.object_mask, &dr->b) : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK && lazy && dr->b.corner_colors) {
        dr->corner_stamps = rl_calloc((size_t)d->num_triangles * 3, sizeof *dr->corner_stamps);
        st = dr->corner_stamps ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    }
    if (st != RL_OK) {
        rl_scene_drawer_release(dr);
        return rl_error(st, "rl_scene_drawer_create: buffers for %u triangles", d->num_triangles);
    }
    *out = dr;
    return RL_OK;
}

/* Objects with more vertices are lit with several threads. */
#define BIG_OBJECT_VERTICES 4096

/* Lights one object's vertices, corners or faces, with up to `threads`
 * threads when it is big enough to pay. Every result depends only on its
 * own element, so the output does not depend on the thread count. */
static void light_object(rl_scene_drawer *dr, uint32_t o, int threads)
{
    const rl_scene_data *d = dr->data;
    const rl_object *obj = &d->objects[o];
    frame_buffers *b = &dr->b;
    const shade_ctx *ctx = &dr->ctx;
    if (obj->num_vertices <= BIG_OBJECT_VERTICES)
        threads = 1;
    const int64_t t0 = obj->first_triangle, t1 = t0 + obj->num_triangles;
    if (dr->opt.shading == RL_SHADING_FLAT) {
#pragma omp parallel for num_threads(threads) schedule(static)
        for (int64_t t = t0; t < t1; ++t)
            light_face(ctx, b, t);
        return;
    }
    uint32_t m = b->object_material[o];
    if (m != RL_NONE) {
        const int64_t v0 = obj->first_vertex, v1 = v0 + obj->num_vertices;
#pragma omp parallel for num_threads(threads) schedule(static)
        for (int64_t v = v0; v < v1; ++v)
            phong_cached(ctx, &d->materials[m], d->positions[v], d->normals[v], &b->vertex_side[v],
                         &b->vertex_colors[v]);
        return;
    }
#pragma omp parallel for num_threads(threads) schedule(static)
    for (int64_t c = 3 * t0; c < 3 * t1; ++c)
        light_corner(ctx, b, (size_t)c);
}

void rl_scene_drawer_new_frame(rl_scene_drawer *dr, rl_vec3 eye)
{
    dr->ctx.eye = eye;
    memset(dr->object_lit, 0, dr->data->num_objects ? dr->data->num_objects : 1);
    /* Every stamp is now out of date; after 2^31 - 2 frames start over. */
    if (++dr->frame >= (1u << 31)) {
        if (dr->stamps)
            memset(dr->stamps, 0, ((size_t)dr->data->num_vertices + 1) * sizeof *dr->stamps);
        if (dr->corner_stamps)
            memset(dr->corner_stamps, 0, (size_t)dr->data->num_triangles * 3 * sizeof *dr->corner_stamps);
        dr->frame = 1;
    }
}

/* Objects whose vertices (or corners) are lit on demand while drawn. */
static bool lit_lazily(const rl_scene_drawer *dr, uint32_t o)
{
    return dr->stamps && (dr->b.object_material[o] != RL_NONE || dr->corner_stamps);
}

/* rl_raster_lazy_colors' shade for vertex v of a single-material object,
 * as light_object would light it; user is the object's lazy_object. */
typedef struct lazy_object {
    rl_scene_drawer *dr;
    uint32_t first;              /* first vertex, or first corner */
    const rl_material *material; /* NULL: mixed, corners */
} lazy_object;

static void shade_vertex(void *user, uint32_t v)
{
    const lazy_object *u = user;
    const rl_scene_data *d = u->dr->data;
    const uint32_t g = u->first + v;
    phong_cached(&u->dr->ctx, u->material, d->positions[g], d->normals[g], &u->dr->b.vertex_side[g],
                 &u->dr->b.vertex_colors[g]);
}

/* The same for corner v of a mixed-material object. */
static void shade_corner(void *user, uint32_t v)
{
    const lazy_object *u = user;
    light_corner(&u->dr->ctx, &u->dr->b, (size_t)u->first + v);
}

void rl_scene_drawer_light(rl_scene_drawer *dr, const uint32_t *objects, uint32_t count)
{
    if (!dr || !dr->lit || !objects)
        return;
    /* Each object once (2 marks one queued in this call), so at most
     * num_objects of them. */
    uint32_t n = 0, *todo = dr->todo;
    for (uint32_t i = 0; i < count; ++i) {
        uint32_t o = objects[i];
        if (o < dr->data->num_objects && selected(dr->opt.object_mask, o) && !dr->object_lit[o] &&
            !lit_lazily(dr, o)) {
            dr->object_lit[o] = 2;
            todo[n++] = o;
        }
    }
    /* Big objects one at a time with every thread (light_object decides),
     * the many small ones side by side. */
    uint32_t small = 0;
    for (uint32_t i = 0; i < n; ++i) {
        uint32_t o = todo[i];
        if (dr->data->objects[o].num_vertices > BIG_OBJECT_VERTICES) {
            light_object(dr, o, dr->threads);
            dr->object_lit[o] = 1;
        } else {
            todo[small++] = o;
        }
    }
    /* Every list draw comes here, mostly with nothing (or one object) to
     * light: no parallel region then, which would cost more than it does. */
    if (small == 1) {
        light_object(dr, todo[0], 1);
    } else if (small > 1) {
#pragma omp parallel for num_threads(dr->threads) schedule(dynamic, 1)
        for (int64_t i = 0; i < (int64_t)small; ++i)
            light_object(dr, todo[i], 1);
    }
    for (uint32_t i = 0; i < small; ++i)
        dr->object_lit[todo[i]] = 1;
}

/* A batch's lazy colours, kept until the list it belongs to is drawn. */
typedef struct lazy_slot {
    rl_raster_lazy_colors colors;
    lazy_object user;
} lazy_slot;

/* The lazy colours of object o, in slot; NULL when o is lit eagerly. */
static const rl_raster_lazy_colors *object_lazy(rl_scene_drawer *dr, uint32_t o, lazy_slot *slot)
{
    if (!dr->lit || !lit_lazily(dr, o))
        return NULL;
    const rl_object *obj = &dr->data->objects[o];
    const uint32_t m = dr->b.object_material[o];
    slot->user = (lazy_object){ dr, obj->first_vertex, NULL };
    slot->colors = (rl_raster_lazy_colors){ shade_vertex, &slot->user, dr->stamps + obj->first_vertex, dr->frame };
    if (m != RL_NONE) {
        slot->user.material = &dr->data->materials[m];
    } else {
        slot->user.first = obj->first_triangle * 3;
        slot->colors.shade = shade_corner;
        slot->colors.stamps = dr->corner_stamps + slot->user.first;
    }
    return &slot->colors;
}

static rl_status reserve_list(rl_scene_drawer *dr, size_t count)
{
    if (count <= dr->list_cap)
        return RL_OK;
    size_t cap = rl_grow_capacity(dr->list_cap, count, 64);
    uint32_t *list = rl_realloc_array(dr->list, cap, sizeof *list);
    if (list)
        dr->list = list;
    rl_raster_batch *batches = rl_realloc_array(dr->batches, cap, sizeof *batches);
    if (batches)
        dr->batches = batches;
    lazy_slot *lazies = rl_realloc_array(dr->lazies, cap, sizeof *lazies);
    if (lazies)
        dr->lazies = lazies;
    if (!list || !batches || !lazies)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "rl_scene_drawer: a list of %zu objects", count);
    dr->list_cap = cap;
    return RL_OK;
}

/* Draws objects[0 .. count) (NULL: first, first + 1, ...) in order, as one
 * rl_raster_draw_many, so that many small objects are drawn on all threads
 * together. fn names the caller in errors. */
static rl_status draw_objects(rl_scene_drawer *dr, rl_raster *ras, const uint32_t *objects, uint32_t first,
                              uint32_t count, rl_raster_counters *c, const char *fn)
{
    if (!dr || !ras || (!objects && count > 0 && first + (uint64_t)count > dr->data->num_objects))
        return rl_error(RL_ERR_INVALID_ARG, "%s: NULL argument or objects out of range", fn);
    const rl_scene_data *d = dr->data;
    rl_status st = reserve_list(dr, count);
    if (st != RL_OK)
        return st;
    /* What is drawn: selected objects with triangles whose box is not
     * entirely outside the view (every triangle of those would fail the
     * trivial reject, so neither light nor transform them: the image is
     * the same); the others only count as submitted. */
    uint32_t n = 0;
    uint64_t skipped = 0;
    for (uint32_t i = 0; i < count; ++i) {
        const uint32_t o = objects ? objects[i] : first + i;
        if (o >= d->num_objects)
            return rl_error(RL_ERR_INVALID_ARG, "%s: object %u of %u", fn, o, d->num_objects);
        if (!selected(dr->opt.object_mask, o) || d->objects[o].num_triangles == 0)
            continue;
        if (rl_raster_box_outside(ras, d->objects[o].bounds))
            skipped += d->objects[o].num_triangles;
        else
            dr->list[n++] = o;
    }
    /* Eager lighting (flat shading) in one parallel pass over the list. */
    rl_scene_drawer_light(dr, dr->list, n);
    for (uint32_t i = 0; i < n && st == RL_OK; ++i) {
        const uint32_t o = dr->list[i];
        st = object_batch(d, o, dr->opt.shading, dr->lit, dr->opt.flags, &dr->b,
                          object_lazy(dr, o, &dr->lazies[i]), &dr->batches[i]);
    }
    if (st == RL_OK)
        st = rl_raster_draw_many(ras, dr->batches, n, c);
    if (st == RL_OK && c)
        c->triangles_in += skipped;
    return st;
}

rl_status rl_scene_drawer_draw(rl_scene_drawer *dr, rl_raster *ras, uint32_t object, rl_raster_counters *c)
{
    if (!dr)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_drawer_draw: NULL argument");
    return draw_objects(dr, ras, &object, 0, 1, c, "rl_scene_drawer_draw");
}

rl_status rl_scene_drawer_draw_list(rl_scene_drawer *dr, rl_raster *ras, const uint32_t *objects, uint32_t count,
                                    rl_raster_counters *c)
{
    if (!dr || (!objects && count > 0))
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_drawer_draw_list: NULL argument");
    return draw_objects(dr, ras, objects, 0, count, c, "rl_scene_drawer_draw_list");
}

rl_status rl_scene_drawer_draw_all(rl_scene_drawer *dr, rl_raster *ras, rl_raster_counters *c,
                                   bool (*progress)(void *user, double done), void *user)
{
    if (!dr || !ras)
        return rl_error(RL_ERR_INVALID_ARG, "rl_scene_drawer_draw_all: NULL argument");
    const uint32_t total = dr->data->num_objects;
    /* Progress about a hundred times, in lists long enough to keep every
     * thread busy. */
    uint32_t step = total / 100 + 1;
    if (step < 1024)
        step = 1024;
    rl_status st = RL_OK;
    for (uint32_t o = 0; st == RL_OK && o < total; o += step) {
        uint32_t n = total - o < step ? total - o : step;
        st = draw_objects(dr, ras, NULL, o, n, c, "rl_scene_drawer_draw_all");
        if (st == RL_OK && progress && !progress(user, (double)(o + n) / total))
            st = rl_error(RL_ERR_CANCELLED, "raster: cancelled by the progress callback");
    }
    return st;
}

rl_status rl_raster_draw_scene(rl_raster *ras, const rl_scene_data *d, rl_vec3 eye,
                               const rl_drawer_desc *desc, rl_raster_counters *c,
                               bool (*progress)(void *user, double done), void *user)
{
    if (!ras || !d)
        return rl_error(RL_ERR_INVALID_ARG, "rl_raster_draw_scene: NULL argument");
    rl_scene_drawer *dr = NULL;
    rl_status st = rl_scene_drawer_create(d, eye, desc, &dr);
    if (st == RL_OK)
        st = rl_scene_drawer_draw_all(dr, ras, c, progress, user);
    rl_scene_drawer_release(dr);
    return st;
}

/* Pixel i's colour, shaded anew where it shows a normal-mapped triangle of
 * a selected object. */
static void shade_pixel(const rl_scene_drawer *dr, rl_image *target, const rl_mat4 *inv, int x, int y)
{
    const rl_scene_data *d = dr->data;
    const size_t i = (size_t)y * (size_t)target->width + (size_t)x;
    const uint32_t tri = target->triangle_id[i];
    if (tri >= d->num_triangles)
        return;
    const uint32_t mi = d->triangle_material[tri], o = d->triangle_object[tri];
    const rl_material *m = &d->materials[mi];
    /* A surfel's pixel holds a point ID, which names no triangle of o. */
    if (m->normal_texture >= d->num_textures || !selected(dr->opt.object_mask, o) ||
        (target->object_id && target->object_id[i] != o))
        return;
    /* The pixel centre's line between the near plane (NDC z = -1) and
     * NDC z = 0, both finite for perspective and orthographic views. */
    const float nx = 2.0f * ((float)x + 0.5f) / (float)target->width - 1.0f;
    const float ny = 1.0f - 2.0f * ((float)y + 0.5f) / (float)target->height;
    rl_vec4 a = rl_mat4_mul_vec4(inv, rl_v4(nx, ny, -1.0f, 1.0f));
    rl_vec4 b = rl_mat4_mul_vec4(inv, rl_v4(nx, ny, 0.0f, 1.0f));
    if (!(a.w != 0.0f && b.w != 0.0f))
        return;
    rl_vec3 pa = rl_scale(rl_v3(a.x, a.y, a.z), 1.0f / a.w), pb = rl_scale(rl_v3(b.x, b.y, b.z), 1.0f / b.w);
    rl_ray ray = { pa, 0.0f, rl_sub(pb, pa), INFINITY };
    float t, u, v;
    if (!rl_tri_plane_hit(d, tri, &ray, &t, &u, &v))
        return;
    const uint32_t *idx = &d->indices[3 * (size_t)tri];
    const float w = 1.0f - u - v;
    rl_vec3 p = rl_ray_at(&ray, t);
    rl_vec3 ns = rl_add(rl_add(rl_scale(d->normals[idx[0]], w), rl_scale(d->normals[idx[1]], u)),
                        rl_scale(d->normals[idx[2]], v));
    rl_vec2 t0 = d->uvs[idx[0]], t1 = d->uvs[idx[1]], t2 = d->uvs[idx[2]];
    rl_vec2 uv = rl_v2(w * t0.x + u * t1.x + v * t2.x, w * t0.y + u * t1.y + v * t2.y);
    /* Two-sided as phong(): the map bends the normal of the side seen. */
    if (rl_dot(ns, rl_sub(dr->ctx.eye, p)) < 0.0f)
        ns = rl_neg(ns);
    rl_vec3 n = rl_normalize(rl_shading_normal(d, tri, rl_normalize(ns), uv));
    rl_vec4 c = phong(&dr->ctx, m, p, n);
    uint32_t tex = dr->opt.shading == RL_SHADING_TEXTURED ? texture_of(d, mi) : RL_ID_NONE;
    if (tex != RL_ID_NONE) {
        rl_vec4 texel = rl_texture_sample(d->textures[tex], uv);
        c = rl_v4(c.x * texel.x, c.y * texel.y, c.z * texel.z, c.w * texel.w);
    }
    target->color[i] = c;
}

void rl_scene_drawer_finish(rl_scene_drawer *dr, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj)
{
    if (!dr || !dr->normal_maps || !target || !(target->layers & RL_LAYER_COLOR) || !target->color ||
        !(target->layers & RL_LAYER_ID) || !target->triangle_id)
        return;
    rl_mat4 view_proj = rl_mat4_mul(proj, view), inv;
    if (!rl_mat4_invert(&view_proj, &inv))
        return;
    const int height = target->height;
#pragma omp parallel for num_threads(dr->threads) schedule(dynamic, 4)
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < target->width; ++x)
            shade_pixel(dr, target, &inv, x, y);
}
