/* gl_visibility.c: the visibility property's ID renders and their counting
 * on OpenGL 4.5 (gl_visibility.h).
 *
 * Jähn 2015 (Sec. 4.2.2, Def. 4/5) renders the depth buffer of six cube
 * faces and then asks one hardware occlusion query per object with the
 * depth test "equal". Like the software property, this draws object IDs in
 * the same depth pass (a pixel belongs to the object that won its depth
 * test), and instead of reading the six ID images back and counting on the
 * CPU, a compute pass counts on the GPU:
 *
 *   id_vs, id_fs   the ID pass: the vertex stage of the GL drawer
 *                  (gl_shaders.c: the same clip coordinates, window depth
 *                  K / w tested with GL_GREATER, the near plane as a clip
 *                  distance, y negated), so that its pixels are gl-raster's;
 *                  the fragment writes the object of its triangle and drops
 *                  what an alpha mask drops (raster_fill.c mask_keeps)
 *   count_cs       one invocation per run of RUN pixels of a row of one
 *                  layer: runs of equal IDs add to the object's pixels with
 *                  one atomic each; the first run of an object in a layer
 *                  (an atomicOr on the object's six layer bits says which)
 *                  adds the object and its triangles to that layer's counts
 *
 * What comes back per position is one buffer: 3 counts per view and the
 * pixels of every object, the per-object measure from which the property
 * makes its set and its values (rl_property_object_pixels).
 *
 * Geometry is uploaded once: the scene's positions and uvs as vertex
 * arrays, its index buffer, the object of every triangle and, only when
 * the scene has alpha-masked materials, the mask per triangle and the
 * alpha of the mask textures. Objects are contiguous triangle ranges in
 * index order (scene commit), so every run of consecutive selected objects
 * is one glDrawElements, and drawing them in index order keeps the
 * software's order for exact depth ties (the first drawn keeps the pixel). */
#include "gl/gl_visibility.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "gl/gl_context.h"
#include "scene/masks.h"

#ifdef RL_HAVE_GL

#include <epoxy/gl.h>

#include "gl/gl_shaders.h"

#define GLSL(...) #__VA_ARGS__ "\n"

/* Pixels per compute invocation, and invocations per work group. */
#define RUN 16
#define GROUP 64
#define VIEWS RL_GL_VISIBILITY_VIEWS

static const float depth_k = 0x1p-40f;   /* as the GL drawer (gl_shaders.c) */

static const char *const header = "#version 450 core\n";

static const char *const id_vs = GLSL(
    layout(location = 0) in vec3 a_pos;
    layout(location = 1) in vec2 a_uv;
    uniform mat4 u_view_proj;
    uniform float u_depth_k;
    out vec2 v_uv;
    invariant gl_Position;
    out float gl_ClipDistance[1];

    void main()
    {
        vec4 c = u_view_proj * vec4(a_pos, 1.0);
        gl_ClipDistance[0] = c.z + c.w;
        gl_Position = vec4(c.x, -c.y, u_depth_k, c.w);
        v_uv = a_uv;
    }
);

/* The mask test is core/texture_sample.h's bilinear repeat lookup on the
 * alpha channel alone (the only channel it tests), the arithmetic of
 * gl_shaders.c tex_sample term for term. */
static const char *const id_fs = GLSL(
    const uint NONE = 0xffffffffu;
    struct Mask { uint offset; int width; int height; float cutoff; };
    layout(std430, binding = 0) readonly buffer TriObject { uint tri_object[]; };
    layout(std430, binding = 1) readonly buffer TriMask { uint tri_mask[]; };
    layout(std430, binding = 2) readonly buffer Masks { Mask masks[]; };
    layout(std430, binding = 3) readonly buffer Alpha { float alpha[]; };
    uniform uint u_first_triangle;
    uniform bool u_masks;
    in vec2 v_uv;
    layout(location = 0) out uint o_object;

    float alpha_at(Mask m, int x, int y)
    {
        return alpha[m.offset + uint(clamp(y, 0, m.height - 1) * m.width + clamp(x, 0, m.width - 1))];
    }

    float alpha_sample(Mask m, vec2 uv)
    {
        float u = isnan(uv.x) || isinf(uv.x) ? 0.0 : uv.x - floor(uv.x);
        float v = isnan(uv.y) || isinf(uv.y) ? 0.0 : uv.y - floor(uv.y);
        float fx = u * float(m.width) - 0.5;
        float fy = (1.0 - v) * float(m.height) - 0.5;
        float x0f = floor(fx), y0f = floor(fy);
        float tx = fx - x0f, ty = fy - y0f;
        int x0 = int(x0f), y0 = int(y0f);
        int x1 = x0 + 1, y1 = y0 + 1;
        x0 += x0 < 0 ? m.width : 0;
        y0 += y0 < 0 ? m.height : 0;
        x1 -= x1 >= m.width ? m.width : 0;
        y1 -= y1 >= m.height ? m.height : 0;
        return (1.0 - tx) * (1.0 - ty) * alpha_at(m, x0, y0) + tx * (1.0 - ty) * alpha_at(m, x1, y0) +
               (1.0 - tx) * ty * alpha_at(m, x0, y1) + tx * ty * alpha_at(m, x1, y1);
    }

    void main()
    {
        uint tri = u_first_triangle + uint(gl_PrimitiveID);
        if (u_masks && tri_mask[tri] != NONE) {
            Mask m = masks[tri_mask[tri]];
            if (alpha_sample(m, v_uv) < m.cutoff)
                discard;
        }
        o_object = tri_object[tri];
    }
);

static const char *const count_cs = GLSL(
    const uint NONE = 0xffffffffu;
    layout(local_size_x = GROUP_SIZE) in;
    layout(binding = 0) uniform usampler2DArray u_ids;
    /* counts[3 v]: objects of view v, [3 v + 1]: their triangles,
     * [3 v + 2]: covered pixels; counts[3 VIEWS + o]: pixels of object o */
    layout(std430, binding = 0) buffer Counts { uint counts[]; };
    layout(std430, binding = 1) coherent buffer Seen { uint seen[]; };
    layout(std430, binding = 2) readonly buffer ObjectTriangles { uint object_triangles[]; };
    uniform int u_resolution;
    uniform uint u_num_objects;

    void add_run(uint view, uint o, uint n)
    {
        atomicAdd(counts[3u * NUM_VIEWS + o], n);
        uint bit = 1u << view;
        /* The plain read spares the atomic once the object is known; only
         * the atomicOr decides who counts it. */
        if ((seen[o] & bit) == 0u && (atomicOr(seen[o], bit) & bit) == 0u) {
            atomicAdd(counts[3u * view], 1u);
            atomicAdd(counts[3u * view + 1u], object_triangles[o]);
        }
    }

    void main()
    {
        uint view = gl_GlobalInvocationID.z;
        int y = int(gl_GlobalInvocationID.y);
        int x0 = int(gl_GlobalInvocationID.x) * RUN_LENGTH;
        if (x0 >= u_resolution)
            return;
        int x1 = min(x0 + RUN_LENGTH, u_resolution);
        uint current = NONE, n = 0u, covered = 0u;
        for (int x = x0; x < x1; ++x) {
            uint id = texelFetch(u_ids, ivec3(x, y, int(view)), 0).r;
            if (id >= u_num_objects)
                id = NONE;
            if (id != current) {
                if (current != NONE)
                    add_run(view, current, n);
                current = id;
                n = 0u;
            }
            ++n;
            covered += id != NONE ? 1u : 0u;
        }
        if (current != NONE)
            add_run(view, current, n);
        if (covered > 0u)
            atomicAdd(counts[3u * view + 2u], covered);
    }
);

struct rl_gl_visibility {
    rl_gl_context *ctx;
    const rl_scene_data *data;
    int resolution;
    bool has_masks;
    bool counted;                 /* the ID layers hold a count's views */
    GLuint id_prog, count_prog;
    GLint u_view_proj, u_depth_k, u_first_triangle, u_masks, u_resolution, u_num_objects;
    GLuint vao, vbo_pos, vbo_uv, ibo;
    GLuint ssbo_tri_object, ssbo_tri_mask, ssbo_masks, ssbo_alpha, ssbo_counts, ssbo_seen, ssbo_object_triangles;
    GLuint fbo, tex_ids, depth_buffer;
};

static rl_status make_programs(rl_gl_visibility *v)
{
    const char *const vs[] = { header, id_vs };
    const char *const fs[] = { header, id_fs };
    GLuint a = rl_gl_compile(GL_VERTEX_SHADER, vs, 2, "visibility ID");
    GLuint b = a ? rl_gl_compile(GL_FRAGMENT_SHADER, fs, 2, "visibility ID") : 0;
    if (!b) {
        glDeleteShader(a);
        return RL_ERR_INTERNAL;
    }
    v->id_prog = rl_gl_link(a, b, "visibility ID");
    char defines[160];
    snprintf(defines, sizeof defines, "#define GROUP_SIZE %d\n#define RUN_LENGTH %d\n#define NUM_VIEWS %du\n", GROUP,
             RUN, VIEWS);
    const char *const cs[] = { header, defines, count_cs };
    GLuint c = v->id_prog ? rl_gl_compile(GL_COMPUTE_SHADER, cs, 3, "visibility count") : 0;
    v->count_prog = c ? rl_gl_link(c, 0, "visibility count") : 0;
    if (!v->count_prog)
        return RL_ERR_INTERNAL;
    v->u_view_proj = glGetUniformLocation(v->id_prog, "u_view_proj");
    v->u_depth_k = glGetUniformLocation(v->id_prog, "u_depth_k");
    v->u_first_triangle = glGetUniformLocation(v->id_prog, "u_first_triangle");
    v->u_masks = glGetUniformLocation(v->id_prog, "u_masks");
    v->u_resolution = glGetUniformLocation(v->count_prog, "u_resolution");
    v->u_num_objects = glGetUniformLocation(v->count_prog, "u_num_objects");
    return RL_OK;
}

/* The mask of every triangle and the alpha of the mask textures, for the
 * scenes with alpha-masked materials. */
static rl_status upload_masks(rl_gl_visibility *v, GLint64 max_block)
{
    const rl_scene_data *d = v->data;
    typedef struct { uint32_t offset; int32_t width, height; float cutoff; } mask_info;
    mask_info *info = rl_calloc(d->num_materials, sizeof *info);
    uint32_t *entry = rl_calloc(d->num_materials, sizeof *entry);
    uint32_t *tri_mask = rl_calloc(d->num_triangles, sizeof *tri_mask);
    rl_status st = info && entry && tri_mask ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    /* One entry per masked material; a texture masking several materials
     * is stored once per material, which keeps the lookup one index. */
    uint64_t texels = 0;
    uint32_t count = 0;
    for (uint32_t m = 0; st == RL_OK && m < d->num_materials; ++m) {
        uint32_t t = rl_material_mask(d, m);
        entry[m] = RL_NONE;
        if (t == RL_NONE)
            continue;
        const rl_texture *tex = d->textures[t];
        info[count] = (mask_info){ (uint32_t)texels, tex->width, tex->height, d->materials[m].alpha_cutoff };
        entry[m] = count++;
        texels += (uint64_t)tex->width * (uint64_t)tex->height;
    }
    if (st == RL_OK && (texels * sizeof(float) > (uint64_t)max_block || texels > UINT32_MAX))
        st = rl_error(RL_ERR_LIMIT, "gl: the scene's alpha masks (%llu texels) exceed this GL's shader storage "
                      "block size (%lld MiB)", (unsigned long long)texels, (long long)(max_block >> 20));
    float *alpha = st == RL_OK ? rl_calloc(texels ? texels : 1, sizeof *alpha) : NULL;
    if (st == RL_OK && !alpha)
        st = RL_ERR_OUT_OF_MEMORY;
    for (uint32_t m = 0; st == RL_OK && m < d->num_materials; ++m) {
        if (entry[m] == RL_NONE)
            continue;
        const rl_texture *tex = d->textures[rl_material_mask(d, m)];
        const size_t n = (size_t)tex->width * (size_t)tex->height;
        for (size_t i = 0; i < n; ++i)
            alpha[info[entry[m]].offset + i] = tex->texels[i].w;
    }
    for (uint32_t t = 0; st == RL_OK && t < d->num_triangles; ++t) {
        uint32_t m = d->triangle_material[t];
        tri_mask[t] = m < d->num_materials ? entry[m] : RL_NONE;
    }
    if (st == RL_OK) {
        v->ssbo_tri_mask = rl_gl_make_buffer(tri_mask, sizeof *tri_mask * d->num_triangles, 0);
        v->ssbo_masks = rl_gl_make_buffer(info, sizeof *info * count, 0);
        v->ssbo_alpha = rl_gl_make_buffer(alpha, sizeof *alpha * texels, 0);
    }
    free(info);
    free(entry);
    free(tri_mask);
    free(alpha);
    return st;
}

static rl_status upload_scene(rl_gl_visibility *v, GLint64 max_block)
{
    const rl_scene_data *d = v->data;
    if ((uint64_t)d->num_triangles * sizeof(uint32_t) > (uint64_t)max_block ||
        3ull * d->num_triangles > INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "gl: %u triangles exceed this GL's shader storage block size (%lld MiB)",
                        d->num_triangles, (long long)(max_block >> 20));
    if ((18ull + d->num_objects) * sizeof(uint32_t) > (uint64_t)max_block)
        return rl_error(RL_ERR_LIMIT, "gl: %u objects exceed this GL's shader storage block size", d->num_objects);
    v->vbo_pos = rl_gl_make_buffer(d->positions, sizeof(rl_vec3) * d->num_vertices, 0);
    v->vbo_uv = rl_gl_make_buffer(d->uvs, sizeof(rl_vec2) * d->num_vertices, 0);
    v->ibo = rl_gl_make_buffer(d->indices, 3 * sizeof(uint32_t) * d->num_triangles, 0);
    glCreateVertexArrays(1, &v->vao);
    glVertexArrayVertexBuffer(v->vao, 0, v->vbo_pos, 0, sizeof(rl_vec3));
    glVertexArrayVertexBuffer(v->vao, 1, v->vbo_uv, 0, sizeof(rl_vec2));
    glVertexArrayAttribFormat(v->vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
    glVertexArrayAttribFormat(v->vao, 1, 2, GL_FLOAT, GL_FALSE, 0);
    for (GLuint a = 0; a < 2; ++a) {
        glVertexArrayAttribBinding(v->vao, a, a);
        glEnableVertexArrayAttrib(v->vao, a);
    }
    glVertexArrayElementBuffer(v->vao, v->ibo);
    v->ssbo_tri_object = rl_gl_make_buffer(d->triangle_object, sizeof(uint32_t) * d->num_triangles, 0);

    uint32_t *tris = rl_calloc(d->num_objects ? d->num_objects : 1, sizeof *tris);
    if (!tris)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t o = 0; o < d->num_objects; ++o)
        tris[o] = d->objects[o].num_triangles;
    v->ssbo_object_triangles = rl_gl_make_buffer(tris, sizeof *tris * d->num_objects, 0);
    free(tris);
    v->ssbo_counts = rl_gl_make_buffer(NULL, sizeof(uint32_t) * (3 * VIEWS + (size_t)d->num_objects),
                                 GL_DYNAMIC_STORAGE_BIT);
    v->ssbo_seen = rl_gl_make_buffer(NULL, sizeof(uint32_t) * d->num_objects, GL_DYNAMIC_STORAGE_BIT);
    v->has_masks = rl_data_has_masks(d);
    return v->has_masks ? upload_masks(v, max_block) : RL_OK;
}

/* The six ID layers and the depth buffer they share. */
static rl_status make_framebuffer(rl_gl_visibility *v)
{
    GLint max_size = 0, max_fb = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    glGetIntegerv(GL_MAX_FRAMEBUFFER_WIDTH, &max_fb);
    const int r = v->resolution;
    if (r > max_size || r > max_fb)
        return rl_error(RL_ERR_LIMIT, "gl: %d² views exceed this GL's texture size limit %d", r,
                        (int)(max_size < max_fb ? max_size : max_fb));
    glCreateTextures(GL_TEXTURE_2D_ARRAY, 1, &v->tex_ids);
    glTextureStorage3D(v->tex_ids, 1, GL_R32UI, r, r, VIEWS);
    /* Integer textures are incomplete with the default (linear) filters,
     * and texelFetch of an incomplete texture reads 0. */
    glTextureParameteri(v->tex_ids, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(v->tex_ids, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glCreateRenderbuffers(1, &v->depth_buffer);
    glNamedRenderbufferStorage(v->depth_buffer, GL_DEPTH_COMPONENT32F, r, r);
    glCreateFramebuffers(1, &v->fbo);
    glNamedFramebufferTextureLayer(v->fbo, GL_COLOR_ATTACHMENT0, v->tex_ids, 0, 0);
    glNamedFramebufferRenderbuffer(v->fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, v->depth_buffer);
    GLenum status = glCheckNamedFramebufferStatus(v->fbo, GL_DRAW_FRAMEBUFFER);
    rl_status st = rl_gl_check("the visibility framebuffer");
    if (st == RL_OK && status != GL_FRAMEBUFFER_COMPLETE)
        st = rl_error(RL_ERR_INTERNAL, "gl: the %d² visibility framebuffer is incomplete (0x%x)", r,
                      (unsigned)status);
    return st;
}

void rl_gl_visibility_release(rl_gl_visibility *v)
{
    if (!v)
        return;
    /* The context's objects go with it. */
    rl_gl_context_release(v->ctx);
    free(v);
}

rl_status rl_gl_visibility_create(const rl_scene *scene, int resolution, const char *device,
                                  rl_gl_visibility **out)
{
    if (!scene || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_visibility_create: NULL argument");
    *out = NULL;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_gl_visibility_create: the scene is not committed");
    if (resolution < 1 || resolution > 4096)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_visibility_create: resolution %d outside [1, 4096]", resolution);
    rl_gl_visibility *v = rl_calloc(1, sizeof *v);
    if (!v)
        return RL_ERR_OUT_OF_MEMORY;
    v->data = d;
    v->resolution = resolution;
    rl_status st = rl_gl_context_create(device, &v->ctx);
    GLint64 max_block = 0;
    if (st == RL_OK) {
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
        st = make_programs(v);
    }
    if (st == RL_OK)
        st = upload_scene(v, max_block);
    if (st == RL_OK)
        st = make_framebuffer(v);
    if (st == RL_OK) {
        glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
        glEnable(GL_CLIP_DISTANCE0);
        st = rl_gl_check("rl_gl_visibility_create");
    }
    if (st != RL_OK) {
        rl_gl_visibility_release(v);
        return st;
    }
    rl_gl_context_done(v->ctx);
    *out = v;
    return RL_OK;
}

const rl_gl_info *rl_gl_visibility_info(const rl_gl_visibility *v)
{
    return v ? rl_gl_context_info(v->ctx) : NULL;
}

/* Draws the selected objects of one view, each run of consecutive
 * selected objects as one range of the index buffer. */
static void draw_view(rl_gl_visibility *v, const uint8_t *mask)
{
    const rl_scene_data *d = v->data;
    uint32_t o = 0;
    while (o < d->num_objects) {
        if (mask && !mask[o]) {
            ++o;
            continue;
        }
        const uint32_t first = d->objects[o].first_triangle;
        uint32_t end = o + 1;
        while (end < d->num_objects && (!mask || mask[end]))
            ++end;
        const uint32_t last = d->objects[end - 1].first_triangle + d->objects[end - 1].num_triangles;
        if (last > first) {
            glProgramUniform1ui(v->id_prog, v->u_first_triangle, first);
            glDrawElements(GL_TRIANGLES, (GLsizei)(3 * (last - first)), GL_UNSIGNED_INT,
                           (const void *)((uintptr_t)first * 3 * sizeof(uint32_t)));
        }
        o = end;
    }
}

static rl_status count_views(rl_gl_visibility *v, const rl_mat4 view_proj[VIEWS], const uint8_t *const *masks,
                             uint32_t *pixels, rl_gl_view_counts views[VIEWS])
{
    const rl_scene_data *d = v->data;
    const int r = v->resolution;
    const GLuint zero = 0, none = RL_ID_NONE;
    const GLfloat far = 0.0f;     /* window depth K / w: 0 is infinitely far */
    glClearNamedBufferData(v->ssbo_counts, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glClearNamedBufferData(v->ssbo_seen, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);

    glBindFramebuffer(GL_FRAMEBUFFER, v->fbo);
    glViewport(0, 0, r, r);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GREATER);
    glDepthMask(GL_TRUE);
    glDisable(GL_CULL_FACE);
    glUseProgram(v->id_prog);
    glProgramUniform1f(v->id_prog, v->u_depth_k, depth_k);
    glProgramUniform1i(v->id_prog, v->u_masks, v->has_masks);
    glBindVertexArray(v->vao);
    const GLuint ssbos[] = { v->ssbo_tri_object, v->ssbo_tri_mask, v->ssbo_masks, v->ssbo_alpha };
    for (GLuint i = 0; i < 4; ++i)
        if (ssbos[i])
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, i, ssbos[i]);
    for (int i = 0; i < VIEWS; ++i) {
        glNamedFramebufferTextureLayer(v->fbo, GL_COLOR_ATTACHMENT0, v->tex_ids, 0, i);
        glClearNamedFramebufferuiv(v->fbo, GL_COLOR, 0, &none);
        glClearNamedFramebufferfv(v->fbo, GL_DEPTH, 0, &far);
        /* rl_mat4 is row-major: transposed on upload. */
        glProgramUniformMatrix4fv(v->id_prog, v->u_view_proj, 1, GL_TRUE, &view_proj[i].m[0][0]);
        draw_view(v, masks ? masks[i] : NULL);
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    glUseProgram(v->count_prog);
    glProgramUniform1i(v->count_prog, v->u_resolution, r);
    glProgramUniform1ui(v->count_prog, v->u_num_objects, d->num_objects);
    glBindTextureUnit(0, v->tex_ids);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, v->ssbo_counts);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, v->ssbo_seen);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, v->ssbo_object_triangles);
    const GLuint runs = ((GLuint)r + RUN - 1) / RUN;
    glDispatchCompute((runs + GROUP - 1) / GROUP, (GLuint)r, VIEWS);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);

    uint32_t counts[3 * VIEWS];
    glGetNamedBufferSubData(v->ssbo_counts, 0, sizeof counts, counts);
    glGetNamedBufferSubData(v->ssbo_counts, sizeof counts, (GLsizeiptr)(sizeof *pixels * d->num_objects), pixels);
    for (int i = 0; i < VIEWS; ++i)
        views[i] = (rl_gl_view_counts){ counts[3 * i], counts[3 * i + 1], counts[3 * i + 2] };
    return rl_gl_check("rl_gl_visibility_count");
}

rl_status rl_gl_visibility_count(rl_gl_visibility *v, const rl_mat4 view_proj[VIEWS], const uint8_t *const *masks,
                                 uint32_t *pixels, rl_gl_view_counts views[VIEWS])
{
    if (!v || !view_proj || !pixels || !views)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_visibility_count: NULL argument");
    rl_status st = rl_gl_context_make_current(v->ctx);
    if (st == RL_OK)
        st = count_views(v, view_proj, masks, pixels, views);
    v->counted = st == RL_OK;
    rl_gl_context_done(v->ctx);
    return st;
}

rl_status rl_gl_visibility_read_ids(rl_gl_visibility *v, int view, uint32_t *ids)
{
    if (!v || !ids || view < 0 || view >= VIEWS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_visibility_read_ids: bad argument (view %d)", view);
    if (!v->counted)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_visibility_read_ids: no count to read");
    rl_status st = rl_gl_context_make_current(v->ctx);
    if (st == RL_OK) {
        const int r = v->resolution;
        glGetTextureSubImage(v->tex_ids, 0, 0, 0, view, r, r, 1, GL_RED_INTEGER, GL_UNSIGNED_INT,
                             (GLsizei)((size_t)r * (size_t)r * sizeof *ids), ids);
        st = rl_gl_check("rl_gl_visibility_read_ids");
    }
    rl_gl_context_done(v->ctx);
    return st;
}

#else /* !RL_HAVE_GL */

struct rl_gl_visibility {
    int unused;
};

rl_status rl_gl_visibility_create(const rl_scene *scene, int resolution, const char *device,
                                  rl_gl_visibility **out)
{
    (void)scene;
    (void)resolution;
    if (out)
        *out = NULL;
    rl_gl_context *ctx = NULL;
    return rl_gl_context_create(device, &ctx);
}

void rl_gl_visibility_release(rl_gl_visibility *v) { (void)v; }

const rl_gl_info *rl_gl_visibility_info(const rl_gl_visibility *v)
{
    (void)v;
    return NULL;
}

rl_status rl_gl_visibility_count(rl_gl_visibility *v, const rl_mat4 view_proj[RL_GL_VISIBILITY_VIEWS],
                                 const uint8_t *const *masks, uint32_t *pixels,
                                 rl_gl_view_counts views[RL_GL_VISIBILITY_VIEWS])
{
    (void)v;
    (void)view_proj;
    (void)masks;
    (void)pixels;
    (void)views;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_visibility_read_ids(rl_gl_visibility *v, int view, uint32_t *ids)
{
    (void)v;
    (void)view;
    (void)ids;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

#endif
