/* gl_drawer.c: the GL backend of rl_drawer (rl_drawer.h, drawer_backend.h):
 * the scene drawer of src/raster/scene_drawer.c on OpenGL 4.5, for
 * "gl-raster" now and for the culling and level-of-detail renderers, which
 * draw, query and read back only through rl_drawer.
 *
 * Made once per drawer, as the software drawer's buffers: one vertex
 * array of the whole scene (positions, normals, uvs, per-vertex material)
 * with one index range per object, drawn one glDrawElements per object;
 * objects that mix materials get one vertex per triangle corner in lit
 * gouraud and textured shading, exactly where the software drawer makes
 * corners, because a shared vertex would need one colour per material.
 * Materials, lights and all texels live in shader storage buffers
 * (gl_shaders.h); the shading is that of gl_shaders.c.
 *
 * A frame renders into a framebuffer of the target's size: colour RGBA32F,
 * eye depth R32F, object and triangle IDs R32UI, a 32-bit float depth
 * buffer. begin uploads the target's layers (the frame starts from the
 * target as it is), end reads them back; rows need no flip (see
 * gl_shaders.c). Counters: triangles submitted and drawn count whole
 * objects (drawn: box not outside the view; GL does not report its
 * clipping), pixels written are GL_SAMPLES_PASSED, read at the end of each
 * call (with desc.deferred_counts, as chcpp draws, at the frame's end, so
 * that no draw waits for the GPU). Occlusion queries are GL_SAMPLES_PASSED
 * in query objects of a pool
 * kept across frames, issued without waiting and read when the caller asks
 * (rl_drawer_query_poll / _result): chcpp hides their latency as Mattausch
 * et al. 2008 do. */
#include "gl/gl_context.h"

#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "raster/drawer_backend.h"
#include "scene/masks.h"

#ifdef RL_HAVE_GL

#include "gl/gl_frame.h"
#include "gl/gl_shaders.h"

/* Uniform locations of one program (-1: not used by it). */
typedef struct uniforms {
    GLint view_proj, view_z, affine, depth_k, affine_z, eye, ambient, num_lights, mode, object, first_triangle,
        normal_maps, depth_equal, num_layers;
} uniforms;

typedef struct gl_drawer {
    rl_gl_context *ctx;
    const rl_scene_data *data;
    rl_drawer_desc desc;
    int mode;                     /* RL_GL_MODE_* of lit draws */
    bool normal_maps;
    GLuint tri_prog, point_prog, upload_prog, batch_prog;
    uniforms tri_u, point_u, upload_u, batch_u;
    /* The scene, made at create. */
    GLuint vao, vbo_pos, vbo_normal, vbo_uv, vbo_material, ibo;
    GLuint ssbo_materials, ssbo_lights, ssbo_tex_info, ssbo_texels, ssbo_tri_material, ssbo_indices;
    /* Streams of queries and points, refilled by each call. */
    GLuint stream_vao, stream_pos, stream_idx;
    GLuint point_vao, point_pos, point_color, point_size, point_object;
    /* Caller batches (rl_drawer_draw_batch): unshared corners, staged here. */
    GLuint batch_vao, batch_buf;
    rl_gl_batch_corner *corners;
    size_t corners_cap;
    GLuint query;                 /* the pixels of counted draws */
    /* desc.deferred_counts: each counted draw's query object (a pool kept
     * across frames) and its counters, read at the frame's end. */
    GLuint *count_pool;
    rl_raster_counters **count_to;
    uint32_t counts_used, count_n, count_cap, count_to_cap;
    GLuint counting;              /* the query of the counted draw running */
    /* The pool of occlusion query objects, one per slot of rl_drawer.c,
     * kept across frames: a slot's object is reused by later queries. */
    GLuint *pool;
    uint32_t pool_n, pool_cap;
    /* The framebuffer, remade when the target's size changes. */
    GLuint fbo, tex_color, tex_depth, tex_object, tex_triangle, depth_buffer, tex_depth_in;
    int fb_width, fb_height;
    /* Texture output (gl_frame.h): the last frame's colour, not yet taken. */
    bool texture_out;
    rl_gl_frame out;
    bool clear_set;               /* texture output: the target's colour is clear_color */
    float clear_color[4];
    /* The frame. */
    rl_image *target;
    rl_mat4 view_proj;
    bool affine;
} gl_drawer;

static const float depth_k = 0x1p-40f;   /* window depth = K / w, gl_shaders.c */


static void free_framebuffer(gl_drawer *g)
{
    GLuint tex[] = { g->tex_color, g->tex_depth, g->tex_object, g->tex_triangle, g->tex_depth_in };
    glDeleteTextures(5, tex);
    glDeleteRenderbuffers(1, &g->depth_buffer);
    glDeleteFramebuffers(1, &g->fbo);
    g->tex_color = g->tex_depth = g->tex_object = g->tex_triangle = g->tex_depth_in = 0;
    g->depth_buffer = g->fbo = 0;
    g->fb_width = g->fb_height = 0;
}

/* Deletes the frame texture nobody took (the context current). */
static void drop_frame(gl_drawer *g)
{
    if (g->out.fence)
        glDeleteSync((GLsync)g->out.fence);
    if (g->out.texture)
        glDeleteTextures(1, &g->out.texture);
    g->out = (rl_gl_frame){ 0 };
}

static void gl_release(void *impl)
{
    gl_drawer *g = impl;
    if (!g)
        return;
    /* A frame texture lives in the caller's share group, which outlives
     * this context: deleted here, unlike the context's other objects. */
    if ((g->out.texture || g->out.fence) && rl_gl_context_make_current(g->ctx) == RL_OK) {
        drop_frame(g);
        rl_gl_context_done(g->ctx);
    }
    /* The context's objects go with it; they are not deleted one by one. */
    rl_gl_context_release(g->ctx);
    free(g->pool);
    free(g->corners);
    free(g->count_pool);
    free(g->count_to);
    free(g);
}

/* A call that fails ends the frame: the context is let go, so that the
 * next frame may come from another thread (a renderer moves between the
 * threads of an OpenMP pool, e.g. in rl compare). end() lets it go too. */
static rl_status settle(gl_drawer *g, rl_status st)
{
    if (st != RL_OK)
        rl_gl_context_done(g->ctx);
    return st;
}

static uniforms locate(GLuint p)
{
    return (uniforms){
        .view_proj = glGetUniformLocation(p, "u_view_proj"), .view_z = glGetUniformLocation(p, "u_view_z"),
        .affine = glGetUniformLocation(p, "u_affine"), .depth_k = glGetUniformLocation(p, "u_depth_k"),
        .affine_z = glGetUniformLocation(p, "u_affine_z"), .eye = glGetUniformLocation(p, "u_eye"),
        .ambient = glGetUniformLocation(p, "u_ambient"), .num_lights = glGetUniformLocation(p, "u_num_lights"),
        .mode = glGetUniformLocation(p, "u_mode"), .object = glGetUniformLocation(p, "u_object"),
        .first_triangle = glGetUniformLocation(p, "u_first_triangle"),
        .normal_maps = glGetUniformLocation(p, "u_normal_maps"),
        .depth_equal = glGetUniformLocation(p, "u_depth_equal"),
        .num_layers = glGetUniformLocation(p, "u_num_layers"),
    };
}

static uint32_t valid_texture(const rl_scene_data *d, uint32_t t)
{
    return t < d->num_textures && d->textures[t] ? t : RL_NONE;
}

static void put4(float *dst, rl_vec3 v, float w)
{
    dst[0] = v.x;
    dst[1] = v.y;
    dst[2] = v.z;
    dst[3] = w;
}

/* Materials and lights as the shaders read them; what does not depend on
 * the point lit (a quad light's centre, normal and area; a spot's cosines)
 * is computed here with the C functions of the software path. */
static rl_status upload_materials_lights(gl_drawer *g)
{
    const rl_scene_data *d = g->data;
    rl_gl_material *mats = rl_calloc(d->num_materials ? d->num_materials : 1, sizeof *mats);
    rl_gl_light *lights = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *lights);
    if (!mats || !lights) {
        free(mats);
        free(lights);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < d->num_materials; ++i) {
        const rl_material *m = &d->materials[i];
        put4(mats[i].diffuse, m->diffuse, 1.0f);
        put4(mats[i].specular, m->specular, m->shininess);
        put4(mats[i].emission, m->emission, m->normal_scale);
        mats[i].tex[0] = valid_texture(d, m->diffuse_texture);
        mats[i].tex[1] = valid_texture(d, m->normal_texture);
        mats[i].tex[2] = rl_material_mask(d, i);
        memcpy(&mats[i].tex[3], &m->alpha_cutoff, sizeof(float));
    }
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        rl_gl_light *o = &lights[i];
        rl_vec3 power = rl_scale(L->color, L->intensity);
        switch (L->type) {
        case RL_LIGHT_DIRECTIONAL: {
            rl_vec3 l = rl_normalize(rl_neg(L->direction));
            put4(o->pos, rl_v3s(0.0f), (float)RL_GL_LIGHT_DIRECTIONAL);
            put4(o->power, power, 0.0f);
            put4(o->dir, l, 0.0f);
            o->extra[1] = rl_length2(l) > 0.0f ? 1.0f : 0.0f;
            break;
        }
        case RL_LIGHT_QUAD: {
            rl_vec3 normal = rl_cross(L->edge_u, L->edge_v);
            float area = rl_length(normal);
            rl_vec3 centre = rl_add(L->position, rl_scale(rl_add(L->edge_u, L->edge_v), 0.5f));
            put4(o->pos, centre, (float)RL_GL_LIGHT_QUAD);
            put4(o->power, power, area > 0.0f ? area : 0.0f);
            put4(o->dir, area > 0.0f ? rl_scale(normal, 1.0f / area) : rl_v3s(0.0f), 0.0f);
            break;
        }
        case RL_LIGHT_SPOT:
            put4(o->pos, L->position, (float)RL_GL_LIGHT_SPOT);
            put4(o->power, power, 0.0f);
            put4(o->dir, rl_normalize(L->direction), cosf(rl_radians(L->spot_outer_deg)));
            o->extra[0] = cosf(rl_radians(L->spot_inner_deg));
            break;
        default:
            put4(o->pos, L->position, (float)RL_GL_LIGHT_POINT);
            put4(o->power, power, 0.0f);
            break;
        }
    }
    g->ssbo_materials = rl_gl_make_buffer(mats, sizeof *mats * d->num_materials, 0);
    g->ssbo_lights = rl_gl_make_buffer(lights, sizeof *lights * d->num_lights, 0);
    free(mats);
    free(lights);
    return RL_OK;
}

/* Whether object o is drawn by corners (see the header comment). */
static bool by_corners(const gl_drawer *g, const uint32_t *object_material, uint32_t o)
{
    return g->mode >= RL_GL_MODE_GOURAUD && g->data->objects[o].num_triangles > 0 &&
           object_material[o] == RL_NONE;
}

/* The vertex arrays and the index buffer: the scene's own vertices, then
 * the corners of the objects drawn by corners; indices in scene triangle
 * order, so that object o's range starts at 3 * first_triangle. */
static rl_status upload_geometry(gl_drawer *g, GLint64 max_block)
{
    const rl_scene_data *d = g->data;
    uint32_t *object_material = rl_calloc(d->num_objects ? d->num_objects : 1, sizeof *object_material);
    if (!object_material)
        return RL_ERR_OUT_OF_MEMORY;
    uint64_t corners = 0;
    for (uint32_t o = 0; o < d->num_objects; ++o) {
        const rl_object *obj = &d->objects[o];
        object_material[o] = rl_object_material(d, o);
        corners += by_corners(g, object_material, o) ? 3ull * obj->num_triangles : 0;
    }
    const uint64_t nv = (uint64_t)d->num_vertices + corners, ni = 3ull * d->num_triangles;
    if (nv > UINT32_MAX || ni * sizeof(uint32_t) > (uint64_t)PTRDIFF_MAX) {
        free(object_material);
        return rl_error(RL_ERR_LIMIT, "gl: %llu vertices", (unsigned long long)nv);
    }
    /* The fragment stage reads these as storage buffers (flat shading,
     * normal maps): they must fit one block. */
    const bool fetch = g->mode == RL_GL_MODE_FLAT || g->normal_maps;
    uint64_t biggest = (uint64_t)d->num_triangles * sizeof(uint32_t);   /* triangle materials, always */
    if (fetch && ni * sizeof(uint32_t) > biggest)
        biggest = ni * sizeof(uint32_t);
    if (fetch && nv * sizeof(rl_vec3) > biggest)
        biggest = nv * sizeof(rl_vec3);
    if (biggest > (uint64_t)max_block) {
        free(object_material);
        return rl_error(RL_ERR_LIMIT, "gl: the scene's arrays (%llu MiB) exceed this GL's shader storage block size "
                        "(%lld MiB)", (unsigned long long)(biggest >> 20), (long long)(max_block >> 20));
    }
    rl_vec3 *pos = rl_calloc(nv ? nv : 1, sizeof *pos), *nrm = rl_calloc(nv ? nv : 1, sizeof *nrm);
    rl_vec2 *uv = rl_calloc(nv ? nv : 1, sizeof *uv);
    uint32_t *mat = rl_calloc(nv ? nv : 1, sizeof *mat), *idx = rl_calloc(ni ? ni : 1, sizeof *idx);
    rl_status st = pos && nrm && uv && mat && idx ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK) {
        memcpy(pos, d->positions, sizeof *pos * d->num_vertices);
        memcpy(nrm, d->normals, sizeof *nrm * d->num_vertices);
        memcpy(uv, d->uvs, sizeof *uv * d->num_vertices);
        memcpy(idx, d->indices, sizeof *idx * ni);
        for (uint32_t v = 0; v < d->num_vertices; ++v)
            mat[v] = RL_NONE;
        uint32_t next = d->num_vertices;
        for (uint32_t o = 0; o < d->num_objects; ++o) {
            const rl_object *obj = &d->objects[o];
            if (!by_corners(g, object_material, o)) {
                for (uint32_t v = 0; v < obj->num_vertices; ++v)
                    mat[obj->first_vertex + v] = object_material[o];
                continue;
            }
            for (size_t t = obj->first_triangle; t < (size_t)obj->first_triangle + obj->num_triangles; ++t)
                for (int k = 0; k < 3; ++k) {
                    uint32_t vi = d->indices[3 * t + k];
                    pos[next] = d->positions[vi];
                    nrm[next] = d->normals[vi];
                    uv[next] = d->uvs[vi];
                    mat[next] = d->triangle_material[t];
                    idx[3 * t + k] = next++;
                }
        }
        g->vbo_pos = rl_gl_make_buffer(pos, sizeof *pos * nv, 0);
        g->vbo_normal = rl_gl_make_buffer(nrm, sizeof *nrm * nv, 0);
        g->vbo_uv = rl_gl_make_buffer(uv, sizeof *uv * nv, 0);
        g->vbo_material = rl_gl_make_buffer(mat, sizeof *mat * nv, 0);
        g->ibo = rl_gl_make_buffer(idx, sizeof *idx * ni, 0);
        /* The fragment stage's indices are the scene's, corners or not. */
        g->ssbo_indices = fetch ? rl_gl_make_buffer(d->indices, sizeof *idx * ni, 0) : 0;
        g->ssbo_tri_material = rl_gl_make_buffer(d->triangle_material, sizeof(uint32_t) * d->num_triangles, 0);
    }
    free(pos);
    free(nrm);
    free(uv);
    free(mat);
    free(idx);
    free(object_material);
    if (st != RL_OK)
        return rl_error(st, "gl: vertex arrays of %llu vertices", (unsigned long long)nv);

    glCreateVertexArrays(1, &g->vao);
    const GLuint vbos[] = { g->vbo_pos, g->vbo_normal, g->vbo_uv, g->vbo_material };
    const GLsizei strides[] = { sizeof(rl_vec3), sizeof(rl_vec3), sizeof(rl_vec2), sizeof(uint32_t) };
    for (GLuint a = 0; a < 4; ++a) {
        glVertexArrayVertexBuffer(g->vao, a, vbos[a], 0, strides[a]);
        glEnableVertexArrayAttrib(g->vao, a);
        glVertexArrayAttribBinding(g->vao, a, a);
    }
    glVertexArrayAttribFormat(g->vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(g->vao, 1, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(g->vao, 2, 2, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribIFormat(g->vao, 3, 1, GL_UNSIGNED_INT, 0);
    glVertexArrayElementBuffer(g->vao, g->ibo);
    return RL_OK;
}

/* The stream arrays of queries (positions only) and points (one buffer
 * per attribute; absent ones are constant generic attributes). */
static void make_streams(gl_drawer *g)
{
    glCreateBuffers(1, &g->stream_pos);
    glCreateBuffers(1, &g->stream_idx);
    glCreateVertexArrays(1, &g->stream_vao);
    glVertexArrayVertexBuffer(g->stream_vao, 0, g->stream_pos, 0, sizeof(rl_vec3));
    glEnableVertexArrayAttrib(g->stream_vao, 0);
    glVertexArrayAttribFormat(g->stream_vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribBinding(g->stream_vao, 0, 0);
    glVertexArrayElementBuffer(g->stream_vao, g->stream_idx);

    GLuint *bufs[] = { &g->point_pos, &g->point_color, &g->point_size, &g->point_object };
    const GLsizei strides[] = { sizeof(rl_vec3), sizeof(rl_vec4), sizeof(float), sizeof(uint32_t) };
    glCreateVertexArrays(1, &g->point_vao);
    for (GLuint a = 0; a < 4; ++a) {
        glCreateBuffers(1, bufs[a]);
        glVertexArrayVertexBuffer(g->point_vao, a, *bufs[a], 0, strides[a]);
        glVertexArrayAttribBinding(g->point_vao, a, a);
    }
    glVertexArrayAttribFormat(g->point_vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(g->point_vao, 1, 4, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(g->point_vao, 2, 1, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribIFormat(g->point_vao, 3, 1, GL_UNSIGNED_INT, 0);
    glEnableVertexArrayAttrib(g->point_vao, 0);
    glCreateQueries(GL_SAMPLES_PASSED, 1, &g->query);

    /* One interleaved stream of rl_gl_batch_corner (gl_shaders.c batch_vs). */
    glCreateBuffers(1, &g->batch_buf);
    glCreateVertexArrays(1, &g->batch_vao);
    glVertexArrayVertexBuffer(g->batch_vao, 0, g->batch_buf, 0, sizeof(rl_gl_batch_corner));
    glVertexArrayAttribFormat(g->batch_vao, 0, 3, GL_FLOAT, GL_FALSE, offsetof(rl_gl_batch_corner, pos));
    glVertexArrayAttribIFormat(g->batch_vao, 1, 4, GL_UNSIGNED_INT, offsetof(rl_gl_batch_corner, tex));
    glVertexArrayAttribIFormat(g->batch_vao, 2, 2, GL_UNSIGNED_INT, offsetof(rl_gl_batch_corner, ids));
    for (GLuint l = 0; l < 4; ++l)
        glVertexArrayAttribFormat(g->batch_vao, 3 + l, 4, GL_FLOAT, GL_FALSE,
                                  (GLuint)(offsetof(rl_gl_batch_corner, col) + l * sizeof(float[4])));
    for (GLuint h = 0; h < 2; ++h)
        glVertexArrayAttribFormat(g->batch_vao, 7 + h, 4, GL_FLOAT, GL_FALSE,
                                  (GLuint)(offsetof(rl_gl_batch_corner, uv) + h * sizeof(float[4])));
    for (GLuint a = 0; a < 9; ++a) {
        glVertexArrayAttribBinding(g->batch_vao, a, 0);
        glEnableVertexArrayAttrib(g->batch_vao, a);
    }
}

/* The framebuffer for a target of w x h. */
static rl_status ensure_framebuffer(gl_drawer *g, int w, int h)
{
    if (g->fbo && g->fb_width == w && g->fb_height == h)
        return RL_OK;
    free_framebuffer(g);
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &max_size);
    GLint max_h = 0;
    glGetIntegerv(GL_MAX_FRAMEBUFFER_HEIGHT, &max_h);
    if (w > max_size || h > max_h)
        return rl_error(RL_ERR_LIMIT, "gl: a %d x %d target exceeds this GL's framebuffer limit %d x %d", w, h,
                        (int)max_size, (int)max_h);
    /* Readback sizes are GLsizei: the colour layer must stay below 2 GiB. */
    if ((uint64_t)w * (uint64_t)h * sizeof(rl_vec4) > INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "gl: a %d x %d target exceeds 2 GiB of colour", w, h);
    const GLenum formats[] = { GL_RGBA32F, GL_R32F, GL_R32UI, GL_R32UI, GL_R32F };
    GLuint *tex[] = { &g->tex_color, &g->tex_depth, &g->tex_object, &g->tex_triangle, &g->tex_depth_in };
    for (int i = 0; i < 5; ++i) {
        glCreateTextures(GL_TEXTURE_2D, 1, tex[i]);
        glTextureStorage2D(*tex[i], 1, formats[i], w, h);
    }
    glCreateRenderbuffers(1, &g->depth_buffer);
    glNamedRenderbufferStorage(g->depth_buffer, GL_DEPTH_COMPONENT32F, w, h);
    glCreateFramebuffers(1, &g->fbo);
    for (int i = 0; i < 4; ++i)
        glNamedFramebufferTexture(g->fbo, GL_COLOR_ATTACHMENT0 + (GLenum)i, *tex[i], 0);
    glNamedFramebufferRenderbuffer(g->fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g->depth_buffer);
    const GLenum draw[] = { GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2, GL_COLOR_ATTACHMENT3 };
    glNamedFramebufferDrawBuffers(g->fbo, 4, draw);
    GLenum status = glCheckNamedFramebufferStatus(g->fbo, GL_DRAW_FRAMEBUFFER);
    rl_status st = rl_gl_check("the framebuffer");
    if (st == RL_OK && status != GL_FRAMEBUFFER_COMPLETE)
        st = rl_error(RL_ERR_INTERNAL, "gl: the %d x %d framebuffer is incomplete (0x%x)", w, h, (unsigned)status);
    if (st != RL_OK) {
        free_framebuffer(g);
        return st;
    }
    g->fb_width = w;
    g->fb_height = h;
    return RL_OK;
}

static rl_status make_programs(gl_drawer *g)
{
    g->tri_prog = rl_gl_program_triangles();
    g->point_prog = g->tri_prog ? rl_gl_program_points() : 0;
    g->upload_prog = g->point_prog ? rl_gl_program_depth_upload() : 0;
    g->batch_prog = g->upload_prog ? rl_gl_program_batch() : 0;
    if (!g->batch_prog)
        return RL_ERR_INTERNAL;
    g->batch_u = locate(g->batch_prog);
    g->tri_u = locate(g->tri_prog);
    g->point_u = locate(g->point_prog);
    g->upload_u = locate(g->upload_prog);
    return RL_OK;
}

/* Write masks, depth function, culling and blending of a draw's flags. */
static void apply_flags(unsigned flags)
{
    glDepthFunc(flags & RL_RASTER_NO_DEPTH_TEST ? GL_ALWAYS
                : flags & RL_RASTER_DEPTH_EQUAL  ? GL_EQUAL
                                                 : GL_GREATER);
    const GLboolean color = !(flags & RL_RASTER_NO_COLOR), depth = !(flags & RL_RASTER_NO_DEPTH),
                    ids = !(flags & RL_RASTER_NO_ID);
    glDepthMask(depth);
    glColorMaski(0, color, color, color, color);
    glColorMaski(1, depth, GL_FALSE, GL_FALSE, GL_FALSE);
    glColorMaski(2, ids, GL_FALSE, GL_FALSE, GL_FALSE);
    glColorMaski(3, ids, GL_FALSE, GL_FALSE, GL_FALSE);
    if (flags & RL_RASTER_CULL_BACK)
        glEnable(GL_CULL_FACE);
    else
        glDisable(GL_CULL_FACE);
    if (flags & RL_RASTER_BLEND_ADD) {
        /* colour += fragment, alpha kept (rl_raster.h) */
        glEnablei(GL_BLEND, 0);
        glBlendFuncSeparatei(0, GL_ONE, GL_ONE, GL_ZERO, GL_ONE);
    } else {
        glDisablei(GL_BLEND, 0);
    }
}

/* The camera uniforms of program p (locations u). */
static void set_camera(const gl_drawer *g, GLuint p, const uniforms *u, const rl_mat4 *view, const rl_mat4 *proj,
                       rl_vec3 eye)
{
    /* rl_mat4 is row-major: transposed on upload. */
    glProgramUniformMatrix4fv(p, u->view_proj, 1, GL_TRUE, &g->view_proj.m[0][0]);
    glProgramUniform4f(p, u->view_z, view->m[2][0], view->m[2][1], view->m[2][2], view->m[2][3]);
    glProgramUniform1i(p, u->affine, g->affine);
    glProgramUniform1f(p, u->depth_k, depth_k);
    glProgramUniform2f(p, u->affine_z, proj->m[2][2], proj->m[2][3]);
    glProgramUniform3f(p, u->eye, eye.x, eye.y, eye.z);
}

static rl_status gl_begin(void *impl, rl_image *target, const rl_mat4 *view, const rl_mat4 *proj, rl_vec3 eye)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st == RL_OK)
        st = ensure_framebuffer(g, target->width, target->height);
    if (st != RL_OK)
        return settle(g, st);
    g->target = target;
    /* An untaken texture of an earlier frame must not pass for this one's. */
    drop_frame(g);
    g->counts_used = 0;           /* of a frame that failed */
    g->view_proj = rl_mat4_mul(proj, view);
    g->affine = proj->m[3][0] == 0.0f && proj->m[3][1] == 0.0f && proj->m[3][2] == 0.0f && proj->m[3][3] == 1.0f;
    set_camera(g, g->tri_prog, &g->tri_u, view, proj, eye);
    set_camera(g, g->point_prog, &g->point_u, view, proj, eye);
    set_camera(g, g->upload_prog, &g->upload_u, view, proj, eye);
    set_camera(g, g->batch_prog, &g->batch_u, view, proj, eye);

    const int w = target->width, h = target->height;
    if (g->texture_out && g->clear_set)
        glClearTexImage(g->tex_color, 0, GL_RGBA, GL_FLOAT, g->clear_color);
    else if ((target->layers & RL_LAYER_COLOR) && target->color)
        glTextureSubImage2D(g->tex_color, 0, 0, 0, w, h, GL_RGBA, GL_FLOAT, target->color);
    else
        glClearTexImage(g->tex_color, 0, GL_RGBA, GL_FLOAT, NULL);
    const uint32_t none = RL_ID_NONE;
    GLuint ids[] = { g->tex_object, g->tex_triangle };
    uint32_t *layers[] = { target->object_id, target->triangle_id };
    for (int i = 0; i < 2; ++i) {
        if ((target->layers & RL_LAYER_ID) && layers[i])
            glTextureSubImage2D(ids[i], 0, 0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, layers[i]);
        else
            glClearTexImage(ids[i], 0, GL_RED_INTEGER, GL_UNSIGNED_INT, &none);
    }
    glTextureSubImage2D(g->tex_depth_in, 0, 0, 0, w, h, GL_RED, GL_FLOAT, target->depth);

    glBindFramebuffer(GL_FRAMEBUFFER, g->fbo);
    glViewport(0, 0, w, h);
    glEnable(GL_DEPTH_TEST);
    /* The shaders' near plane (gl_shaders.c writes gl_ClipDistance[0]):
     * by the GL spec it clips only while enabled; llvmpipe clips anyway,
     * a GPU driver would not. */
    glEnable(GL_CLIP_DISTANCE0);
    /* The target's eye depth into the depth attachment and the depth
     * buffer (gl_shaders.c upload_fs). */
    apply_flags(RL_RASTER_NO_DEPTH_TEST | RL_RASTER_NO_COLOR | RL_RASTER_NO_ID);
    glUseProgram(g->upload_prog);
    glBindTextureUnit(0, g->tex_depth_in);
    glBindVertexArray(g->stream_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);

    /* The scene's storage buffers stay bound for the frame. */
    const GLuint ssbos[] = { g->ssbo_materials, g->ssbo_lights,       g->ssbo_tex_info, g->ssbo_texels,
                             g->ssbo_tri_material, g->ssbo_indices, g->vbo_pos,       g->vbo_uv };
    for (GLuint i = 0; i < 8; ++i)
        if (ssbos[i])
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, ssbos[i]);
    return settle(g, rl_gl_check("rl_drawer_begin"));
}

static void gl_light(void *impl, const uint32_t *objects, uint32_t count)
{
    /* Lighting runs in the shaders of every draw. */
    (void)impl;
    (void)objects;
    (void)count;
}

static bool selected(const gl_drawer *g, uint32_t o)
{
    return !g->desc.object_mask || g->desc.object_mask[o];
}

/* Whether box lies wholly beyond one plane of the view volume (near,
 * left, right, bottom, top): GL would clip all of it. */
static bool box_outside(const gl_drawer *g, rl_aabb box)
{
    if (!rl_vfinite(box.min) || !rl_vfinite(box.max))
        return false;
    int out[5] = { 0 };
    for (int i = 0; i < 8; ++i) {
        rl_vec3 p = rl_v3(i & 1 ? box.max.x : box.min.x, i & 2 ? box.max.y : box.min.y, i & 4 ? box.max.z : box.min.z);
        const float(*m)[4] = g->view_proj.m;
        float x = m[0][0] * p.x + m[0][1] * p.y + m[0][2] * p.z + m[0][3];
        float y = m[1][0] * p.x + m[1][1] * p.y + m[1][2] * p.z + m[1][3];
        float z = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
        float w = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
        out[0] += z < -w;
        out[1] += x < -w;
        out[2] += x > w;
        out[3] += y < -w;
        out[4] += y > w;
    }
    for (int k = 0; k < 5; ++k)
        if (out[k] == 8)
            return true;
    return false;
}

/* Starts a counted draw with the drawer's flags and the triangle program. */
static void begin_triangles(gl_drawer *g)
{
    const bool lit = !(g->desc.flags & RL_RASTER_NO_COLOR);
    const bool equal = (g->desc.flags & RL_RASTER_DEPTH_EQUAL) && !(g->desc.flags & RL_RASTER_NO_DEPTH_TEST);
    /* Equal depth is tested on eye depth in the fragment stage (gl_shaders.c). */
    apply_flags(equal ? (g->desc.flags & ~(unsigned)RL_RASTER_DEPTH_EQUAL) | RL_RASTER_NO_DEPTH_TEST : g->desc.flags);
    glProgramUniform1i(g->tri_prog, g->tri_u.depth_equal, equal);
    glUseProgram(g->tri_prog);
    glProgramUniform1i(g->tri_prog, g->tri_u.mode, lit ? g->mode : RL_GL_MODE_UNLIT);
    glProgramUniform1i(g->tri_prog, g->tri_u.normal_maps, lit && g->normal_maps);
    glProgramUniform1f(g->tri_prog, g->tri_u.ambient, g->desc.ambient);
    glProgramUniform1i(g->tri_prog, g->tri_u.num_lights, (GLint)g->data->num_lights);
    glBindVertexArray(g->vao);
}

/* Starts the query that counts a draw's pixels: the drawer's one, read at
 * once, or with deferred counts the next of the frame's pool. */
static rl_status start_counted(gl_drawer *g)
{
    g->counting = g->query;
    if (g->desc.deferred_counts) {
        if (g->counts_used == g->count_n) {
            if (!rl_reserve_u32((void **)&g->count_pool, &g->count_cap, (uint64_t)g->count_n + 1,
                                sizeof *g->count_pool, 16))
                return RL_ERR_OUT_OF_MEMORY;
            glCreateQueries(GL_SAMPLES_PASSED, 1, &g->count_pool[g->count_n++]);
        }
        if (!rl_reserve_u32((void **)&g->count_to, &g->count_to_cap, (uint64_t)g->counts_used + 1,
                            sizeof *g->count_to, 16))
            return RL_ERR_OUT_OF_MEMORY;
        g->counting = g->count_pool[g->counts_used];
    }
    glBeginQuery(GL_SAMPLES_PASSED, g->counting);
    return RL_OK;
}

static void draw_object(gl_drawer *g, uint32_t o, rl_raster_counters *c)
{
    const rl_object *obj = &g->data->objects[o];
    if (!selected(g, o) || obj->num_triangles == 0)
        return;
    if (c)
        c->triangles_in += obj->num_triangles;
    if (box_outside(g, obj->bounds))
        return;
    glProgramUniform1ui(g->tri_prog, g->tri_u.object, o);
    glProgramUniform1ui(g->tri_prog, g->tri_u.first_triangle, obj->first_triangle);
    glDrawElements(GL_TRIANGLES, (GLsizei)(3 * obj->num_triangles), GL_UNSIGNED_INT,
                   (const void *)((uintptr_t)obj->first_triangle * 3 * sizeof(uint32_t)));
    if (c)
        c->triangles_drawn += obj->num_triangles;
}

/* Ends a counted draw: the fragments that passed go to pixels_written. */
static rl_status end_counted(gl_drawer *g, rl_raster_counters *c, const char *where)
{
    glEndQuery(GL_SAMPLES_PASSED);
    if (g->desc.deferred_counts) {
        g->count_to[g->counts_used++] = c;
        return rl_gl_check(where);
    }
    GLuint64 passed = 0;
    glGetQueryObjectui64v(g->query, GL_QUERY_RESULT, &passed);
    if (c)
        c->pixels_written += passed;
    return rl_gl_check(where);
}

/* The deferred counts of the frame's draws into their counters. */
static void read_counts(gl_drawer *g)
{
    for (uint32_t i = 0; i < g->counts_used; ++i) {
        if (!g->count_to[i])
            continue;
        GLuint64 passed = 0;
        glGetQueryObjectui64v(g->count_pool[i], GL_QUERY_RESULT, &passed);
        g->count_to[i]->pixels_written += passed;
    }
    g->counts_used = 0;
}

static rl_status gl_draw(void *impl, const uint32_t *objects, uint32_t count, rl_raster_counters *c)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK)
        return settle(g, st);
    for (uint32_t i = 0; i < count; ++i)
        if (objects[i] >= g->data->num_objects)
            return settle(g, rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw: object %u of %u", objects[i],
                                      g->data->num_objects));
    begin_triangles(g);
    st = start_counted(g);
    if (st != RL_OK)
        return settle(g, st);
    for (uint32_t i = 0; i < count; ++i)
        draw_object(g, objects[i], c);
    return settle(g, end_counted(g, c, "rl_drawer_draw"));
}

static rl_status gl_draw_all(void *impl, rl_raster_counters *c, rl_progress_fn progress, void *user)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK)
        return settle(g, st);
    const uint32_t total = g->data->num_objects, step = total / 100 + 1;
    begin_triangles(g);
    st = start_counted(g);
    if (st != RL_OK)
        return settle(g, st);
    for (uint32_t o = 0; o < total && st == RL_OK; ++o) {
        draw_object(g, o, c);
        if (progress && ((o + 1) % step == 0 || o + 1 == total) && !progress(user, (double)(o + 1) / total))
            st = rl_error(RL_ERR_CANCELLED, "gl: cancelled by the progress callback");
    }
    rl_status end = end_counted(g, c, "rl_drawer_draw_all");
    return settle(g, st != RL_OK ? st : end);
}

/* Starts the occlusion query of boxes in query object q: every write
 * masked, the depth test of the boxes' flags only. Nothing is read back. */
static rl_status run_query(gl_drawer *g, const rl_raster_batch *boxes, GLuint q)
{
    if (boxes->num_triangles && (!boxes->positions || !boxes->indices))
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_query: %u triangles without positions or indices",
                        boxes->num_triangles);
    /* An index out of range would read outside the stream on the GPU. */
    const size_t n = 3 * (size_t)boxes->num_triangles;
    if (n > INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "rl_drawer_query: %u triangles in one batch", boxes->num_triangles);
    for (size_t i = 0; i < n; ++i)
        if (boxes->indices[i] >= boxes->num_vertices)
            return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_query: index %u of %u vertices", boxes->indices[i],
                            boxes->num_vertices);
    /* An empty batch still runs its (empty) query, which answers 0. */
    if (n) {
        /* Respecified storage: the driver keeps the old contents for the
         * queries still in flight that read them. */
        glNamedBufferData(g->stream_pos, (GLsizeiptr)(sizeof(rl_vec3) * boxes->num_vertices), boxes->positions,
                          GL_STREAM_DRAW);
        glNamedBufferData(g->stream_idx, (GLsizeiptr)(sizeof(uint32_t) * n), boxes->indices, GL_STREAM_DRAW);
    }
    apply_flags((boxes->flags & (RL_RASTER_DEPTH_EQUAL | RL_RASTER_CULL_BACK)) | RL_RASTER_NO_COLOR |
                RL_RASTER_NO_DEPTH | RL_RASTER_NO_ID);
    glUseProgram(g->tri_prog);
    glProgramUniform1i(g->tri_prog, g->tri_u.mode, RL_GL_MODE_QUERY);
    glProgramUniform1i(g->tri_prog, g->tri_u.depth_equal, 0);
    glBindVertexArray(g->stream_vao);
    glBeginQuery(GL_SAMPLES_PASSED, q);
    if (n)
        glDrawElements(GL_TRIANGLES, (GLsizei)n, GL_UNSIGNED_INT, NULL);
    glEndQuery(GL_SAMPLES_PASSED);
    return rl_gl_check("rl_drawer_query_issue");
}

static rl_status gl_query_issue(void *impl, const rl_raster_batch *boxes, uint32_t slot)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK)
        return settle(g, st);
    if (slot >= g->pool_n) {
        if (!rl_reserve_u32((void **)&g->pool, &g->pool_cap, (uint64_t)slot + 1, sizeof *g->pool, 64))
            return settle(g, RL_ERR_OUT_OF_MEMORY);
        glCreateQueries(GL_SAMPLES_PASSED, (GLsizei)(slot + 1 - g->pool_n), g->pool + g->pool_n);
        g->pool_n = slot + 1;
    }
    return settle(g, run_query(g, boxes, g->pool[slot]));
}

static rl_status gl_query_poll(void *impl, uint32_t slot, bool *ready)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK)
        return settle(g, st);
    GLuint available = GL_FALSE;
    glGetQueryObjectuiv(g->pool[slot], GL_QUERY_RESULT_AVAILABLE, &available);
    *ready = available != GL_FALSE;
    return settle(g, rl_gl_check("rl_drawer_query_poll"));
}

static rl_status gl_query_result(void *impl, uint32_t slot, uint64_t *pixels)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK)
        return settle(g, st);
    GLuint64 passed = 0;
    glGetQueryObjectui64v(g->pool[slot], GL_QUERY_RESULT, &passed);
    *pixels = passed;
    return settle(g, rl_gl_check("rl_drawer_query_result"));
}

/* Triangles of a caller batch staged at a time: a bounded stream (130
 * bytes a corner), drawn in submission order as one draw would. */
#define BATCH_CHUNK 65536u

static rl_status check_batch(const gl_drawer *g, const rl_raster_batch *b)
{
    if (b->face_colors || b->texture || b->uvs || b->triangle_texture || b->lazy)
        return rl_error(RL_ERR_UNSUPPORTED, "rl_drawer_draw_batch: the GL drawer draws layers, per-vertex "
                        "colors or one color (no face colours, batch textures or lazy colours)");
    if (b->num_layers > RL_RASTER_MAX_LAYERS || (b->num_layers && !b->layers))
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_batch: %u layers", b->num_layers);
    for (uint32_t l = 0; l < b->num_layers; ++l) {
        const rl_raster_layer *L = &b->layers[l];
        if (!L->colors)
            return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_batch: layer %u has no colours", l);
        if (L->textures && L->textures != g->data->textures)
            return rl_error(RL_ERR_UNSUPPORTED, "rl_drawer_draw_batch: layer %u's textures are not the "
                            "scene's", l);
    }
    if (b->num_triangles && (!b->positions || !b->indices))
        return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_batch: %u triangles without positions or indices",
                        b->num_triangles);
    const size_t n = 3 * (size_t)b->num_triangles;
    for (size_t i = 0; i < n; ++i)
        if (b->indices[i] >= b->num_vertices)
            return rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_batch: index %u of %u vertices", b->indices[i],
                            b->num_vertices);
    return RL_OK;
}

/* The corners of triangles [first, first + count) of b. */
static void stage_corners(const gl_drawer *g, const rl_raster_batch *b, uint32_t first, uint32_t count)
{
    for (uint32_t i = 0; i < count; ++i) {
        const uint32_t t = first + i;
        uint32_t tex[4] = { RL_NONE, RL_NONE, RL_NONE, RL_NONE };
        for (uint32_t l = 0; l < b->num_layers; ++l) {
            const rl_raster_layer *L = &b->layers[l];
            /* Textured where the software's gather_layers would be. */
            if (L->uvs && L->textures && L->triangle_texture)
                tex[l] = valid_texture(g->data, L->triangle_texture[t]);
        }
        const uint32_t tri = b->triangle_ids ? b->triangle_ids[t] : b->first_triangle_id + t;
        const uint32_t obj = b->object_ids ? b->object_ids[t] : b->object_id;
        for (int k = 0; k < 3; ++k) {
            const uint32_t v = b->indices[3 * (size_t)t + (size_t)k];
            rl_gl_batch_corner *c = &g->corners[3 * (size_t)i + (size_t)k];
            memset(c, 0, sizeof *c);
            c->pos[0] = b->positions[v].x;
            c->pos[1] = b->positions[v].y;
            c->pos[2] = b->positions[v].z;
            memcpy(c->tex, tex, sizeof tex);
            c->ids[0] = tri;
            c->ids[1] = obj;
            for (uint32_t l = 0; l < b->num_layers || l < 1; ++l) {
                const rl_vec4 col = b->num_layers ? b->layers[l].colors[v] : b->colors ? b->colors[v] : b->color;
                c->col[l][0] = col.x;
                c->col[l][1] = col.y;
                c->col[l][2] = col.z;
                c->col[l][3] = col.w;
                if (b->num_layers && b->layers[l].uvs) {
                    c->uv[l][0] = b->layers[l].uvs[v].x;
                    c->uv[l][1] = b->layers[l].uvs[v].y;
                }
            }
        }
    }
}

static rl_status gl_draw_batch(void *impl, const rl_raster_batch *b, rl_raster_counters *c)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st == RL_OK)
        st = check_batch(g, b);
    if (st != RL_OK || b->num_triangles == 0)
        return settle(g, st);
    const uint32_t chunk = b->num_triangles < BATCH_CHUNK ? b->num_triangles : BATCH_CHUNK;
    if (!rl_reserve((void **)&g->corners, &g->corners_cap, 3 * (size_t)chunk, sizeof *g->corners, 3 * 1024))
        return settle(g, RL_ERR_OUT_OF_MEMORY);
    apply_flags(b->flags);
    glUseProgram(g->batch_prog);
    glProgramUniform1i(g->batch_prog, g->batch_u.num_layers, (GLint)b->num_layers);
    glBindVertexArray(g->batch_vao);
    st = start_counted(g);
    if (st != RL_OK)
        return settle(g, st);
    for (uint32_t first = 0; first < b->num_triangles; first += chunk) {
        const uint32_t n = b->num_triangles - first < chunk ? b->num_triangles - first : chunk;
        stage_corners(g, b, first, n);
        /* Respecified storage: the draw before may still read the old. */
        glNamedBufferData(g->batch_buf, (GLsizeiptr)(3 * (size_t)n * sizeof *g->corners), g->corners,
                          GL_STREAM_DRAW);
        glDrawArrays(GL_TRIANGLES, 0, (GLsizei)(3 * n));
    }
    if (c) {
        /* GL does not report its clipping: every triangle counts as drawn. */
        c->triangles_in += b->num_triangles;
        c->triangles_drawn += b->num_triangles;
    }
    return settle(g, end_counted(g, c, "rl_drawer_draw_batch"));
}

/* One point attribute: a stream of count items, or the constant value
 * (NULL data) as the generic attribute. */
static void point_attribute(gl_drawer *g, GLuint a, GLuint buf, const void *data, size_t item, uint32_t count)
{
    if (data) {
        glNamedBufferData(buf, (GLsizeiptr)(item * count), data, GL_STREAM_DRAW);
        glEnableVertexArrayAttrib(g->point_vao, a);
    } else {
        glDisableVertexArrayAttrib(g->point_vao, a);
    }
}

static rl_status gl_draw_points(void *impl, const rl_raster_points *pts, rl_raster_counters *c)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK || pts->count == 0)
        return settle(g, st);
    if (!pts->positions)
        return settle(g, rl_error(RL_ERR_INVALID_ARG, "rl_drawer_draw_points: %u points without positions",
                                  pts->count));
    glBindVertexArray(g->point_vao);
    point_attribute(g, 0, g->point_pos, pts->positions, sizeof(rl_vec3), pts->count);
    point_attribute(g, 1, g->point_color, pts->colors, sizeof(rl_vec4), pts->count);
    point_attribute(g, 2, g->point_size, pts->sizes_px, sizeof(float), pts->count);
    point_attribute(g, 3, g->point_object, pts->object_ids, sizeof(uint32_t), pts->count);
    if (!pts->colors)
        glVertexAttrib4f(1, pts->color.x, pts->color.y, pts->color.z, pts->color.w);
    if (!pts->sizes_px)
        glVertexAttrib1f(2, pts->size_px > 0.0f ? pts->size_px : 1.0f);
    if (!pts->object_ids)
        glVertexAttribI1ui(3, pts->object_id);
    apply_flags(pts->flags);
    glUseProgram(g->point_prog);
    st = start_counted(g);
    if (st != RL_OK)
        return settle(g, st);
    glDrawArrays(GL_POINTS, 0, (GLsizei)pts->count);
    if (c) {
        /* Points in front of the near plane (the software's count also
         * drops those wholly off screen). */
        for (uint32_t i = 0; i < pts->count; ++i) {
            rl_vec4 p = rl_mat4_mul_vec4(&g->view_proj, rl_v4_from3(pts->positions[i], 1.0f));
            c->points_drawn += p.w > 0.0f && p.z >= -p.w;
        }
    }
    return settle(g, end_counted(g, c, "rl_drawer_draw_points"));
}

static rl_status gl_end(void *impl)
{
    gl_drawer *g = impl;
    rl_status st = rl_gl_context_make_current(g->ctx);
    if (st != RL_OK)
        return settle(g, st);
    read_counts(g);
    rl_image *t = g->target;
    const size_t n = (size_t)t->width * (size_t)t->height;
    if (g->texture_out && (t->layers & RL_LAYER_COLOR) && t->color) {
        /* The colour stays on the GPU (gl_frame.h): the frame's colour
         * attachment itself goes to the caller, and a new one takes its
         * place, so that the next frame may draw while the caller shows
         * this one, with no copy. */
        drop_frame(g);
        g->out.texture = g->tex_color;
        glTextureParameteri(g->out.texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(g->out.texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glCreateTextures(GL_TEXTURE_2D, 1, &g->tex_color);
        glTextureStorage2D(g->tex_color, 1, GL_RGBA32F, t->width, t->height);
        glNamedFramebufferTexture(g->fbo, GL_COLOR_ATTACHMENT0, g->tex_color, 0);
        g->out.width = t->width;
        g->out.height = t->height;
        g->out.fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        /* Another context waits on the fence only once it has reached the GPU. */
        glFlush();
    } else if ((t->layers & RL_LAYER_COLOR) && t->color) {
        glGetTextureImage(g->tex_color, 0, GL_RGBA, GL_FLOAT, (GLsizei)(n * sizeof(rl_vec4)), t->color);
    }
    glGetTextureImage(g->tex_depth, 0, GL_RED, GL_FLOAT, (GLsizei)(n * sizeof(float)), t->depth);
    if ((t->layers & RL_LAYER_ID) && t->object_id)
        glGetTextureImage(g->tex_object, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, (GLsizei)(n * sizeof(uint32_t)),
                          t->object_id);
    if ((t->layers & RL_LAYER_ID) && t->triangle_id)
        glGetTextureImage(g->tex_triangle, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, (GLsizei)(n * sizeof(uint32_t)),
                          t->triangle_id);
    g->target = NULL;
    st = rl_gl_check("rl_drawer_end");
    rl_gl_context_done(g->ctx);
    return st;
}

static const rl_drawer_ops gl_ops = {
    .name = "gl",
    .release = gl_release,
    .begin = gl_begin,
    .light = gl_light,
    .draw = gl_draw,
    .draw_all = gl_draw_all,
    .query_issue = gl_query_issue,
    .query_poll = gl_query_poll,
    .query_result = gl_query_result,
    .draw_batch = gl_draw_batch,
    .draw_points = gl_draw_points,
    .end = gl_end,
};

rl_status rl_gl_drawer_create(const rl_scene *scene, const rl_drawer_desc *desc, const char *device,
                              rl_drawer **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_drawer_create: NULL argument");
    *out = NULL;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_gl_drawer_create: the scene is not committed");
    rl_drawer_desc opt = desc ? *desc : (rl_drawer_desc){ 0 };
    if (opt.shading != RL_SHADING_FLAT && opt.shading != RL_SHADING_GOURAUD && opt.shading != RL_SHADING_TEXTURED)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_drawer_create: unknown shading %d", (int)opt.shading);
    gl_drawer *g = rl_calloc(1, sizeof *g);
    if (!g)
        return RL_ERR_OUT_OF_MEMORY;
    g->data = d;
    g->desc = opt;
    g->mode = opt.shading == RL_SHADING_FLAT      ? RL_GL_MODE_FLAT
              : opt.shading == RL_SHADING_GOURAUD ? RL_GL_MODE_GOURAUD
                                                  : RL_GL_MODE_TEXTURED;
    /* As rl_scene_drawer_create: per-pixel normal maps for lit gouraud and
     * textured draws, never in multi-pass blending. */
    const bool lit = !(opt.flags & RL_RASTER_NO_COLOR);
    for (uint32_t m = 0; m < d->num_materials && lit && g->mode != RL_GL_MODE_FLAT &&
                         !(opt.flags & (RL_RASTER_DEPTH_EQUAL | RL_RASTER_BLEND_ADD)); ++m)
        g->normal_maps |= valid_texture(d, d->materials[m].normal_texture) != RL_NONE;
    rl_status st = rl_gl_context_create(device, &g->ctx);
    GLint64 max_block = 0;
    if (st == RL_OK) {
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
        st = make_programs(g);
    }
    if (st == RL_OK)
        st = upload_materials_lights(g);
    if (st == RL_OK)
        st = rl_gl_upload_textures(d, max_block, "gl", &g->ssbo_tex_info, &g->ssbo_texels);
    if (st == RL_OK)
        st = upload_geometry(g, max_block);
    if (st == RL_OK) {
        make_streams(g);
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glFrontFace(GL_CW);      /* y is negated: see gl_shaders.c */
        glCullFace(GL_BACK);
        glEnable(GL_PROGRAM_POINT_SIZE);
        st = rl_gl_check("rl_gl_drawer_create");
    }
    if (st != RL_OK) {
        gl_release(g);
        return st;
    }
    /* The first frame may come from another thread. */
    rl_gl_context_done(g->ctx);
    return rl_drawer_make(&gl_ops, g, scene, desc, out);
}

rl_status rl_gl_drawer_set_texture_output(rl_drawer *d, bool on)
{
    gl_drawer *g = rl_drawer_impl(d, &gl_ops);
    if (!g)
        return rl_error(RL_ERR_UNSUPPORTED, "gl: texture output needs a GL drawer");
    g->texture_out = on;
    return RL_OK;
}

void rl_gl_drawer_set_clear(rl_drawer *d, const float *rgba)
{
    gl_drawer *g = rl_drawer_impl(d, &gl_ops);
    if (!g)
        return;
    g->clear_set = rgba != NULL;
    if (rgba)
        memcpy(g->clear_color, rgba, sizeof g->clear_color);
}

bool rl_gl_drawer_take_frame(rl_drawer *d, rl_gl_frame *out)
{
    gl_drawer *g = rl_drawer_impl(d, &gl_ops);
    if (!g || !g->out.texture)
        return false;
    *out = g->out;
    g->out = (rl_gl_frame){ 0 };
    return true;
}

#else /* !RL_HAVE_GL */

rl_status rl_gl_drawer_create(const rl_scene *scene, const rl_drawer_desc *desc, const char *device,
                              rl_drawer **out)
{
    (void)scene;
    (void)desc;
    if (out)
        *out = NULL;
    rl_gl_context *ctx = NULL;
    return rl_gl_context_create(device, &ctx);
}

rl_status rl_gl_drawer_set_texture_output(rl_drawer *d, bool on)
{
    (void)d;
    (void)on;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: texture output needs a GL drawer");
}

void rl_gl_drawer_set_clear(rl_drawer *d, const float *rgba)
{
    (void)d;
    (void)rgba;
}

bool rl_gl_drawer_take_frame(rl_drawer *d, rl_gl_frame *out)
{
    (void)d;
    (void)out;
    return false;
}

#endif
