/* gl_pt.c: the host side of the GPU path tracer (gl_pt.h): the scene and
 * its structures in shader storage buffers, the two state images of
 * Schröder 2017 (Sec. 5.3: the per-pixel generator states, rgba32ui;
 * Sec. 6.5: the accumulated colour, rgba32f), one dispatch of the path
 * program per sample and frame, and the read-back of the mean.
 *
 * Buffers (gl_pt_shaders.c names them): 0 materials, 1 lights, 2 texture
 * records, 3 texels, 4 triangles (three vertex indices and the material),
 * 5 positions, 6 normals, 7 uvs, 8 BVH nodes, 9 BVH triangles, 10 grid cell
 * offsets, 11 grid cell lists, 12 light table, 13 per-triangle light data,
 * 14 and 15 the ray set and hits of rl_gl_pt_trace. Of these, 3, 5, 6, 7,
 * 12 and 13 are read as buffer textures (units 0-5, tex_buffers below), so
 * that the path program stays within 16 storage blocks with the Line
 * Space's 8 at 16-23 (rl_gl_pt_set_linespace, gl_linespace.h). For the
 * same reason the environment's arrays (rl_gl_pt_set_environment) are one
 * r32f buffer texture on unit 8, not storage buffers.
 *
 * The BVH is accel/bvh_build.c's binary tree as built (the CPU traversal
 * then collapses it into a wide tree, which a GPU thread gains nothing
 * from): its 32-byte nodes go up unchanged, and its leaf-order triangle
 * copy as three vec4 per triangle, the scene ID in the first w, so that a
 * leaf reads its triangles contiguously. */
#include "gl/gl_pt.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "gl/gl_context.h"

#ifdef RL_HAVE_GL

#include <epoxy/gl.h>

#include "accel/bvh.h"
#include "accel/grid.h"
#include "gl/gl_linespace.h"
#include "gl/gl_shaders.h"
#include "raster/shadowmap_internal.h"
#include "scene/masks.h"

#define LOCAL 8                    /* the path program's work group: 8 x 8 pixels */
#define RAYS_LOCAL 64

enum {
    B_MATERIALS = 0, B_LIGHTS, B_TEX_INFO, B_TEXELS, B_TRIANGLES, B_POSITIONS, B_NORMALS, B_UVS,
    B_BVH_NODES, B_BVH_TRIS, B_CELL_START, B_CELL_TRIS, B_LIGHT_TABLE, B_TRI_LIGHT, B_RAYS, B_HITS,
    B_COUNT
};

/* The arrays the shaders read as buffer textures (gl_pt_shaders.c: a
 * compute shader has 16 storage blocks, the Line Space takes 8), by
 * texture unit, with the buffer and the texel format. */
enum { T_POSITIONS = 0, T_NORMALS, T_UVS, T_TEXELS, T_LIGHT_TABLE, T_TRI_LIGHT, T_COUNT };
static const struct {
    int buffer;
    GLenum format;
    unsigned texel_bytes;
} tex_buffers[T_COUNT] = {
    { B_POSITIONS, GL_R32F, 4 }, { B_NORMALS, GL_R32F, 4 }, { B_UVS, GL_R32F, 4 },
    { B_TEXELS, GL_RGBA32F, 16 }, { B_LIGHT_TABLE, GL_RG32UI, 8 }, { B_TRI_LIGHT, GL_RG32UI, 8 },
};

static bool buffer_texture(GLuint b)
{
    for (int t = 0; t < T_COUNT; ++t)
        if ((GLuint)tex_buffers[t].buffer == b)
            return true;
    return false;
}

/* The uniforms of a program, by name once. */
typedef struct uniforms {
    GLint num_nodes, masks, grid_min, grid_cell, grid_inv_cell, grid_res;
    GLint size, eye, cam_u, cam_v, cam_w, tan_half_fov, aspect, rng, held, checker, parity, raster, max_depth,
        rr_depth, rr, mis, mis_hits, tri_lights, light_samples, vertex_slots, num_lights, table_count,
        num_textures, eps, background, shadow, diffuse, specular, ls_start, ls_offset;
    GLint sm_size, sm_bias, sm_slope, sm_pcf, sm_frame;
    GLint env, env_nee, env_slot, env_map, env_size, env_rot, env_sum, env_off;
    GLint ggx_ms, adaptive, round_k;
    GLint lvc, lv_paths, lv_base, lv_connect, lv_slot, lv_nu1;
    GLint count, structure, any;
} uniforms;

/* The shadow maps' depth pass (rl_gl_pt_set_shadowmaps). */
#define SM_UNIT 7                  /* the path program's texture unit of the maps */
#define SM_CASTERS 14              /* the casters list's storage binding (B_RAYS's: the pass is
                                    * no ray set's) */
/* The path program's compile-time variants (docs/gl.md, "Path-program
 * variants"): llvmpipe compiles the program in proportion to its inlined
 * size, so the parts a frame cannot reach are left out by the GLSL
 * preprocessor's HAS_* (gl_pt_shaders.c) rather than skipped by a uniform:
 * GGX (no material of the scene is GGX), the light-vertex joins of Sec.
 * 8.4 (no light paths this frame) and the environment (none set). A left
 * out part is one whose uniform would be false, so every variant computes
 * what the full program computes. */
enum { V_GGX = 1, V_LIGHT_VERTICES = 2, V_ENV = 4, V_STRUCTURE_SHIFT = 3, PATH_VARIANTS = 16 };
/* The structures too: the variant holds the traversals of the frame's
 * shadow, diffuse and specular structures (STRUCTS, a bit per
 * rl_gl_pt_structure) and no other, so that a BVH frame does not compile
 * the grid's walk, the three Line Space walks and the shadow-map lookup
 * it never takes (docs/gl.md, "One ray site"). The other programs have all
 * bits, and the path program always the BVH's (its camera rays). */
#define ALL_STRUCTURES ((1u << RL_GL_PT_STRUCTURE_COUNT) - 1u)

#define ENV_UNIT 8                 /* the path program's texture unit of the environment */
#define LV_UNIT 9                  /* the path program's texture unit of the light vertices */

struct rl_gl_pt {
    rl_gl_context *ctx;
    const rl_scene_data *data;
    float eps;
    int threads;
    uint32_t table_count;
    uint32_t num_nodes;
    bool masks;
    /* the path program of this frame's variant (use_variant) and its
     * uniforms; the variants made so far (up to PATH_VARIANTS), with their
     * keys (V_* bits and the structures') */
    GLuint path_prog, rays_prog;
    uniforms pu, ru;
    GLuint variant_prog[PATH_VARIANTS];
    unsigned variant_key[PATH_VARIANTS];
    uniforms variant_u[PATH_VARIANTS];
    unsigned variants_made;       /* the next slot to fill is variants_made % PATH_VARIANTS */
    bool has_ggx;                 /* a material of the scene is GGX */
    GLuint buf[B_COUNT];
    GLuint tex[T_COUNT];
    /* the grid, built on first use */
    bool have_grid;
    int grid_res;
    rl_vec3 grid_min, grid_cell, grid_inv_cell;
    int grid_dims[3];
    /* the Line Space of the LS structures (rl_gl_pt_set_linespace) */
    rl_gl_ls *ls;
    unsigned ls_payloads;
    /* the accumulation */
    GLuint tex_accum, tex_rng;
    int width, height;
    uint64_t held[2];             /* samples per pixel, by the parity of x + y */
    uint64_t frames;              /* since the reset */
    /* primary=raster: the raster pass's triangle per pixel (r32ui) */
    GLuint tex_ids;
    /* adaptive sampling: per pixel the samples held and the round's share
     * (rg32ui, image unit 2), the passes' program (made on first use), its
     * errors (2 floats per pixel) and totals; the samples of all pixels
     * together, and those of the uniform start (equal in every pixel) */
    GLuint tex_adapt, adapt_prog, adapt_err, adapt_tot;
    GLint a_mode, a_size, a_thr, a_budget, a_num_active;
    size_t adapt_err_pixels;
    uint64_t counted;
    uint32_t start_count;
    bool adapt_counts;            /* tex_adapt's counts are this accumulation's */
    /* texture output (rl_gl_pt_set_texture_output): the last frame's mean,
     * not yet taken */
    bool texture_out;
    rl_gl_frame out;
    /* the ray counters (atomic_uint, one per rl_ray_type) */
    GLuint counters;
    /* the cube shadow maps (rl_gl_pt_set_shadowmaps): the depth pass's
     * program, made on first use, and the maps as an r32f buffer texture
     * (an empty one until then) */
    GLuint sm_prog;
    GLint sm_eye, sm_face_s, sm_face_u, sm_face_axis, sm_near, sm_far, sm_masks;
    GLuint sm_buf, sm_tex;
    bool have_sm;
    rl_shadowmap_desc sm_desc;
    /* the environment (rl_gl_pt_set_environment): radiance texels, then
     * weights, conditional and marginal sums, in one r32f buffer texture
     * (a 12-byte one without) at the offsets env_off */
    GLuint env_buf, env_tex;
    bool have_env;
    int env_map[2], env_size[2], env_off[3];
    float env_rot;
    double env_sum;
    /* hybrid light paths (rl_gl_pt_set_light_vertices): the paths'
     * offsets (as float bits, 4 a texel) then the vertices in one rgba32f
     * buffer texture (a 12-byte one without) */
    GLuint lv_buf, lv_tex;
    uint32_t lv_paths, lv_base;
};

static void replace_buffer(rl_gl_pt *pt, int slot, const void *data, size_t bytes, GLbitfield flags)
{
    if (pt->buf[slot])
        glDeleteBuffers(1, &pt->buf[slot]);
    pt->buf[slot] = rl_gl_make_buffer(data, bytes, flags);
}

static void put4(float *dst, rl_vec3 v, float w)
{
    dst[0] = v.x;
    dst[1] = v.y;
    dst[2] = v.z;
    dst[3] = w;
}

static uint32_t valid_texture(const rl_scene_data *d, uint32_t t)
{
    return t < d->num_textures && d->textures[t] ? t : RL_NONE;
}

static void locate(GLuint p, uniforms *u)
{
#define U(field, name) u->field = glGetUniformLocation(p, name)
    U(num_nodes, "u_num_nodes");
    U(masks, "u_masks");
    U(grid_min, "u_grid_min");
    U(grid_cell, "u_grid_cell");
    U(grid_inv_cell, "u_grid_inv_cell");
    U(grid_res, "u_grid_res");
    U(size, "u_size");
    U(eye, "u_eye");
    U(cam_u, "u_cam_u");
    U(cam_v, "u_cam_v");
    U(cam_w, "u_cam_w");
    U(tan_half_fov, "u_tan_half_fov");
    U(aspect, "u_aspect");
    U(rng, "u_rng");
    U(held, "u_held");
    U(checker, "u_checker");
    U(parity, "u_parity");
    U(raster, "u_raster");
    U(max_depth, "u_max_depth");
    U(rr_depth, "u_rr_depth");
    U(rr, "u_rr");
    U(mis, "u_mis");
    U(mis_hits, "u_mis_hits");
    U(tri_lights, "u_tri_lights");
    U(light_samples, "u_light_samples");
    U(vertex_slots, "u_vertex_slots");
    U(num_lights, "u_num_lights");
    U(table_count, "u_table_count");
    U(num_textures, "u_num_textures");
    U(eps, "u_eps");
    U(background, "u_background");
    U(shadow, "u_shadow");
    U(diffuse, "u_diffuse");
    U(specular, "u_specular");
    U(ls_start, "u_ls_start");
    U(ls_offset, "u_ls_offset");
    U(sm_size, "u_sm_size");
    U(sm_bias, "u_sm_bias");
    U(sm_slope, "u_sm_slope");
    U(sm_pcf, "u_sm_pcf");
    U(sm_frame, "u_sm_frame");
    U(env, "u_env");
    U(env_nee, "u_env_nee");
    U(env_slot, "u_env_slot");
    U(env_map, "u_env_map");
    U(env_size, "u_env_size");
    U(env_rot, "u_env_rot");
    U(env_sum, "u_env_sum");
    U(env_off, "u_env_off");
    U(ggx_ms, "u_ggx_ms");
    U(adaptive, "u_adaptive");
    U(round_k, "u_round_k");
    U(lvc, "u_lvc");
    U(lv_paths, "u_lv_paths");
    U(lv_base, "u_lv_base");
    U(lv_connect, "u_lv_connect");
    U(lv_slot, "u_lv_slot");
    U(lv_nu1, "u_lv_nu1");
    U(count, "u_count");
    U(structure, "u_structure");
    U(any, "u_any");
#undef U
}

/* The path program includes the Line Space walk (its defines first, right
 * after #version); the ray-set program has no use for it. body NULL: the
 * shadow maps' depth pass, a vertex and a fragment stage. */
static GLuint compute_program(const char *body, bool linespace, unsigned variant, const char *what)
{
    char defines[640];
    snprintf(defines, sizeof defines,
             "#define LOCAL_SIZE %d\n#define BVH_STACK %d\n#define STRUCT_BVH %d\n#define STRUCT_GRID %d\n"
             "#define STRUCT_LS_CAND %d\n#define STRUCT_LS_PNMT %d\n#define STRUCT_LS_PREILLUM %d\n"
             "#define STRUCT_SHADOWMAP %d\n"
             "#define LIGHT_POINT %d\n#define LIGHT_SPOT %d\n#define LIGHT_DIRECTIONAL %d\n#define LIGHT_QUAD %d\n"
             "#define INF uintBitsToFloat(0x7f800000u)\n#define GGX_NODES %d\n",
             LOCAL, RL_BVH_MAX_DEPTH, (int)RL_GL_PT_BVH, (int)RL_GL_PT_GRID, (int)RL_GL_PT_LS_CANDIDATES, (int)RL_GL_PT_LS_PNMT,
             (int)RL_GL_PT_LS_PREILLUM, (int)RL_GL_PT_SHADOWMAP, (int)RL_LIGHT_POINT, (int)RL_LIGHT_SPOT,
             (int)RL_LIGHT_DIRECTIONAL, (int)RL_LIGHT_QUAD, RL_GL_PT_GGX_NODES);
    if (!body) {
        /* the shadow maps' depth pass: common's declarations, and for the
         * fragment stage the texture lookup of the masks */
        const char *const vs[] = { rl_gl_pt_glsl_header, defines, rl_gl_pt_glsl_common, rl_gl_pt_glsl_shadow_vs };
        const char *const fs[] = { rl_gl_pt_glsl_header, defines, rl_gl_pt_glsl_common, rl_gl_glsl_tex_sample,
                                   rl_gl_pt_glsl_shadow_fs };
        GLuint v = rl_gl_compile(GL_VERTEX_SHADER, vs, 4, what);
        GLuint f = v ? rl_gl_compile(GL_FRAGMENT_SHADER, fs, 5, what) : 0;
        if (v && !f)
            glDeleteShader(v);
        return f ? rl_gl_link(v, f, what) : 0;
    }
    /* the path program's variant (V_*); the other programs have no use
     * for it and keep their texts */
    char has[128];
    if (linespace)
        snprintf(has, sizeof has,
                 "#define HAS_GGX %d\n#define HAS_LIGHT_VERTICES %d\n#define HAS_ENV %d\n#define STRUCTS %uu\n",
                 (variant & V_GGX) != 0, (variant & V_LIGHT_VERTICES) != 0, (variant & V_ENV) != 0,
                 variant >> V_STRUCTURE_SHIFT);
    else
        snprintf(has, sizeof has, "#define STRUCTS %uu\n", ALL_STRUCTURES);
    const char *const parts[] = { rl_gl_pt_glsl_header, linespace ? rl_gl_linespace_glsl() : "", defines, has,
                                  rl_gl_pt_glsl_common, rl_gl_glsl_tex_sample, rl_gl_pt_glsl_common2,
                                  rl_gl_glsl_light_delta, body };
    GLuint s = rl_gl_compile(GL_COMPUTE_SHADER, parts, 9, what);
    return s ? rl_gl_link(s, 0, what) : 0;
}

static rl_status check_block(uint64_t bytes, GLint64 max_block, const char *what)
{
    if (bytes > (uint64_t)max_block)
        return rl_error(RL_ERR_LIMIT, "gl-pt: the scene's %s (%llu MiB) exceed this GL's shader storage block size "
                        "(%lld MiB)", what, (unsigned long long)(bytes >> 20), (long long)(max_block >> 20));
    return RL_OK;
}

/* Materials and lights as gl_pt_shaders.c reads them: what does not depend
 * on the point lit (a spot's cosines, a directional light's direction) is
 * computed here with the C functions of scene/light_eval.c. The materials'
 * buffer starts with GGX's energy-compensation tables (ggx_ms, or zeros):
 * a storage block of their own would be the path program's 17th with the
 * Line Space (llvmpipe allows 16), a texture unit another llvmpipe variant
 * key entry. */
#define GGX_TABLE_FLOATS (RL_GL_PT_GGX_NODES * RL_GL_PT_GGX_NODES + RL_GL_PT_GGX_NODES)
static rl_status upload_materials_lights(rl_gl_pt *pt, const rl_gl_pt_lights *lt, const float *ggx_ms)
{
    const rl_scene_data *d = pt->data;
    typedef struct {
        float diffuse[4], specular[4], emission[4], extra[4];
        uint32_t tex[4];
        float pbr[4];
    } material;
    _Static_assert(GGX_TABLE_FLOATS * sizeof(float) % 16 == 0, "std430 aligns the materials to 16 bytes");
    const size_t head = GGX_TABLE_FLOATS * sizeof(float);
    unsigned char *block = rl_calloc(1, head + sizeof(material) * (d->num_materials ? d->num_materials : 1));
    rl_gl_light *lights = rl_calloc(d->num_lights ? d->num_lights : 1, sizeof *lights);
    if (!block || !lights) {
        free(block);
        free(lights);
        return RL_ERR_OUT_OF_MEMORY;
    }
    if (ggx_ms)
        memcpy(block, ggx_ms, head);
    material *mats = (material *)(void *)(block + head);
    for (uint32_t i = 0; i < d->num_materials; ++i) {
        const rl_material *m = &d->materials[i];
        put4(mats[i].diffuse, m->diffuse, m->reflectivity);
        put4(mats[i].specular, m->specular, m->shininess);
        put4(mats[i].emission, m->emission, m->normal_scale);
        mats[i].extra[0] = m->transmissivity;
        mats[i].extra[1] = m->ior;
        mats[i].extra[2] = m->alpha_cutoff;
        mats[i].extra[3] = m->fresnel == RL_FRESNEL_SCHLICK ? 1.0f : 0.0f;   /* issue 37 */
        mats[i].tex[0] = valid_texture(d, m->diffuse_texture);
        mats[i].tex[1] = valid_texture(d, m->normal_texture);
        mats[i].tex[2] = rl_material_mask(d, i);
        mats[i].tex[3] = RL_NONE;
        /* issue 37's GGX BRDF (pathtrace_ggx.c): roughness, metallic */
        mats[i].pbr[0] = m->roughness;
        mats[i].pbr[1] = m->metallic;
        mats[i].pbr[2] = m->bsdf == RL_BSDF_GGX ? 1.0f : 0.0f;
    }
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        rl_gl_light *o = &lights[i];
        rl_vec3 power = rl_scale(L->color, L->intensity);
        float pmf = lt->light_pmf ? lt->light_pmf[i] : 0.0f;
        switch (L->type) {
        case RL_LIGHT_DIRECTIONAL: {
            rl_vec3 l = rl_normalize(rl_neg(L->direction));
            put4(o->pos, rl_v3s(0.0f), (float)RL_LIGHT_DIRECTIONAL);
            put4(o->dir, l, 0.0f);
            o->extra[1] = rl_length2(l) > 0.0f ? 1.0f : 0.0f;
            break;
        }
        case RL_LIGHT_QUAD:
            put4(o->pos, L->position, (float)RL_LIGHT_QUAD);
            put4(o->dir, L->edge_u, 0.0f);
            put4(o->extra, L->edge_v, lt->light_hittable && lt->light_hittable[i] ? 1.0f : 0.0f);
            break;
        case RL_LIGHT_SPOT:
            put4(o->pos, L->position, (float)RL_LIGHT_SPOT);
            put4(o->dir, rl_normalize(L->direction), cosf(rl_radians(L->spot_outer_deg)));
            o->extra[0] = cosf(rl_radians(L->spot_inner_deg));
            break;
        default:
            put4(o->pos, L->position, (float)RL_LIGHT_POINT);
            break;
        }
        put4(o->power, power, pmf);
    }
    pt->buf[B_MATERIALS] = rl_gl_make_buffer(block, head + sizeof *mats * d->num_materials, 0);
    pt->buf[B_LIGHTS] = rl_gl_make_buffer(lights, sizeof *lights * d->num_lights, 0);
    free(block);
    free(lights);
    return RL_OK;
}

/* Triangles (indices and material), vertex arrays and the per-triangle
 * light data (covering quad, MIS probability). */
static rl_status upload_geometry(rl_gl_pt *pt, const rl_gl_pt_lights *lt, GLint64 max_block)
{
    const rl_scene_data *d = pt->data;
    rl_status st = check_block((uint64_t)d->num_triangles * 16, max_block, "triangles");
    if (st == RL_OK)
        st = check_block((uint64_t)d->num_vertices * sizeof(rl_vec3), max_block, "vertices");
    if (st != RL_OK)
        return st;
    uint32_t *tris = rl_calloc(d->num_triangles ? d->num_triangles : 1, 4 * sizeof *tris);
    uint32_t *tri_light = rl_calloc(d->num_triangles ? d->num_triangles : 1, 2 * sizeof *tri_light);
    if (!tris || !tri_light) {
        free(tris);
        free(tri_light);
        return RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        memcpy(&tris[4 * (size_t)t], &d->indices[3 * (size_t)t], 3 * sizeof *tris);
        tris[4 * (size_t)t + 3] = d->triangle_material[t];
        tri_light[2 * (size_t)t] = lt->tri_cover ? lt->tri_cover[t] : RL_NONE;
        float pmf = lt->tri_pmf ? lt->tri_pmf[t] : 0.0f;
        memcpy(&tri_light[2 * (size_t)t + 1], &pmf, sizeof pmf);
    }
    pt->buf[B_TRIANGLES] = rl_gl_make_buffer(tris, 16 * (size_t)d->num_triangles, 0);
    pt->buf[B_TRI_LIGHT] = rl_gl_make_buffer(tri_light, 8 * (size_t)d->num_triangles, 0);
    free(tris);
    free(tri_light);
    pt->buf[B_POSITIONS] = rl_gl_make_buffer(d->positions, sizeof(rl_vec3) * d->num_vertices, 0);
    pt->buf[B_NORMALS] = rl_gl_make_buffer(d->normals, sizeof(rl_vec3) * d->num_vertices, 0);
    pt->buf[B_UVS] = rl_gl_make_buffer(d->uvs, sizeof(rl_vec2) * d->num_vertices, 0);

    /* the table: (cdf, source) pairs, count + 1 cdf values */
    float *table = rl_calloc((size_t)lt->count + 1, 2 * sizeof *table);
    if (!table)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t k = 0; k <= lt->count && lt->cdf; ++k) {
        table[2 * (size_t)k] = lt->cdf[k];
        uint32_t src = k < lt->count ? lt->source[k] : RL_NONE;
        memcpy(&table[2 * (size_t)k + 1], &src, sizeof src);
    }
    pt->table_count = lt->cdf ? lt->count : 0;
    pt->buf[B_LIGHT_TABLE] = rl_gl_make_buffer(table, 2 * sizeof *table * ((size_t)lt->count + 1), 0);
    free(table);
    return RL_OK;
}

static rl_status upload_bvh(rl_gl_pt *pt, GLint64 max_block)
{
    const rl_scene_data *d = pt->data;
    rl_accel_desc desc = { .kind = RL_ACCEL_BVH, .threads = pt->threads };
    rl_accel_stats stats;
    rl_bvh bvh;
    memset(&bvh, 0, sizeof bvh);
    memset(&stats, 0, sizeof stats);
    if (d->num_triangles == 0) {
        pt->num_nodes = 0;
        pt->buf[B_BVH_NODES] = rl_gl_make_buffer(NULL, 0, 0);
        pt->buf[B_BVH_TRIS] = rl_gl_make_buffer(NULL, 0, 0);
        return RL_OK;
    }
    rl_status st = rl_bvh_build(d, &desc, &bvh, &stats);
    if (st != RL_OK)
        return st;
    _Static_assert(sizeof(rl_bvh_node) == 32, "a node is two vec4");
    st = check_block((uint64_t)bvh.num_tris * 48, max_block, "BVH triangles");
    float *tris = st == RL_OK ? rl_calloc(bvh.num_tris ? bvh.num_tris : 1, 12 * sizeof *tris) : NULL;
    if (st == RL_OK && !tris)
        st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK) {
        for (uint32_t k = 0; k < bvh.num_tris; ++k) {
            const rl_bvh_tri *t = &bvh.tris[k];
            float id;
            memcpy(&id, &t->id, sizeof id);
            put4(&tris[12 * (size_t)k], t->p0, id);
            put4(&tris[12 * (size_t)k + 4], t->p1, 0.0f);
            put4(&tris[12 * (size_t)k + 8], t->p2, 0.0f);
        }
        pt->num_nodes = bvh.num_nodes;
        pt->buf[B_BVH_NODES] = rl_gl_make_buffer(bvh.nodes, sizeof *bvh.nodes * bvh.num_nodes, 0);
        pt->buf[B_BVH_TRIS] = rl_gl_make_buffer(tris, 48 * (size_t)bvh.num_tris, 0);
    }
    free(tris);
    rl_bvh_free(&bvh);
    return st;
}

/* The grid of accel/grid.h with grid_res cells per axis (0: heuristic):
 * cell offsets and lists as they are. */
static rl_status ensure_grid(rl_gl_pt *pt, int grid_res)
{
    if (pt->have_grid && pt->grid_res == grid_res)
        return RL_OK;
    GLint64 max_block = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
    rl_accel_desc desc = { .kind = RL_ACCEL_GRID, .threads = pt->threads,
                           .grid_res = { grid_res, grid_res, grid_res } };
    rl_grid *g = NULL;
    rl_status st = rl_grid_build(pt->data, &desc, &g);
    if (st != RL_OK)
        return st;
    st = check_block(((uint64_t)g->num_cells + 1) * 4, max_block, "grid cells");
    if (st == RL_OK)
        st = check_block(g->num_references * 4, max_block, "grid lists");
    if (st == RL_OK) {
        replace_buffer(pt, B_CELL_START, g->cell_start, sizeof *g->cell_start * ((size_t)g->num_cells + 1), 0);
        replace_buffer(pt, B_CELL_TRIS, g->cell_tris, sizeof *g->cell_tris * (size_t)g->num_references, 0);
        pt->grid_min = g->bounds.min;
        pt->grid_cell = g->cell_size;
        pt->grid_inv_cell = g->inv_cell_size;
        memcpy(pt->grid_dims, g->res, sizeof pt->grid_dims);
        pt->grid_res = grid_res;
        pt->have_grid = true;
    }
    rl_grid_free(g);
    return st;
}

/* The uniforms common to both programs, and the buffers bound. */
static void bind_scene(rl_gl_pt *pt, GLuint p, const uniforms *u)
{
    for (GLuint t = 0; t < T_COUNT; ++t)
        glBindTextureUnit(t, pt->tex[t]);
    glProgramUniform1ui(p, u->num_nodes, pt->num_nodes);
    glProgramUniform1i(p, u->masks, pt->masks);
    if (pt->have_grid) {
        glProgramUniform3f(p, u->grid_min, pt->grid_min.x, pt->grid_min.y, pt->grid_min.z);
        glProgramUniform3f(p, u->grid_cell, pt->grid_cell.x, pt->grid_cell.y, pt->grid_cell.z);
        glProgramUniform3f(p, u->grid_inv_cell, pt->grid_inv_cell.x, pt->grid_inv_cell.y, pt->grid_inv_cell.z);
        glProgramUniform3i(p, u->grid_res, pt->grid_dims[0], pt->grid_dims[1], pt->grid_dims[2]);
    }
    for (GLuint b = 0; b < B_COUNT; ++b)
        if (pt->buf[b] && !buffer_texture(b))
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, b, pt->buf[b]);
}

/* The buffer textures over the uploaded arrays; RL_ERR_LIMIT past the GL's
 * texel count. */
static rl_status make_buffer_textures(rl_gl_pt *pt)
{
    GLint max_texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    for (int t = 0; t < T_COUNT; ++t) {
        GLint64 bytes = 0;
        glGetNamedBufferParameteri64v(pt->buf[tex_buffers[t].buffer], GL_BUFFER_SIZE, &bytes);
        if ((uint64_t)bytes / tex_buffers[t].texel_bytes > (uint64_t)max_texels)
            return rl_error(RL_ERR_LIMIT, "gl-pt: %lld bytes of a scene array exceed this GL's buffer texture "
                            "size of %d texels", (long long)bytes, (int)max_texels);
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->tex[t]);
        glTextureBuffer(pt->tex[t], tex_buffers[t].format, pt->buf[tex_buffers[t].buffer]);
    }
    return RL_OK;
}

/* The shadow maps' buffer where there are none: three texels, not
 * rl_gl_make_buffer's four. llvmpipe's variant key holds the power-of-two flag of
 * a buffer's byte size, and the maps' lights x 6 x size^2 floats are never
 * a power of two, so 12 bytes keep one variant of the path program with
 * and without maps. The environment's buffer without an environment is the
 * same (and one with is padded off a power of two). */
static GLuint no_maps(void)
{
    const float none[3] = { 0.0f, 0.0f, 0.0f };
    GLuint b = 0;
    glCreateBuffers(1, &b);
    glNamedBufferStorage(b, sizeof none, none, 0);
    return b;
}

static void drop_frame(rl_gl_pt *pt);

void rl_gl_pt_release(rl_gl_pt *pt)
{
    if (!pt)
        return;
    if ((pt->ls || pt->out.texture || pt->out.fence) && rl_gl_context_make_current(pt->ctx) == RL_OK) {
        rl_gl_ls_release(pt->ls);
        /* in the caller's share group (rl_gl_share_with) it would outlive
         * the context */
        drop_frame(pt);
        rl_gl_context_done(pt->ctx);
    }
    rl_gl_context_release(pt->ctx);   /* its objects go with it */
    free(pt);
}

rl_status rl_gl_pt_create(const rl_scene *scene, const rl_gl_pt_desc *desc, rl_gl_pt **out)
{
    if (!scene || !desc || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_create: NULL argument");
    *out = NULL;
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return rl_error(RL_ERR_NOT_COMMITTED, "rl_gl_pt_create: the scene is not committed");
    rl_gl_pt *pt = rl_calloc(1, sizeof *pt);
    if (!pt)
        return RL_ERR_OUT_OF_MEMORY;
    pt->data = d;
    pt->eps = desc->eps;
    pt->threads = desc->threads;
    pt->masks = rl_data_has_masks(d);
    rl_status st = rl_gl_context_create(desc->device, &pt->ctx);
    GLint64 max_block = 0;
    if (st == RL_OK) {
        glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &max_block);
        /* the path program is made by the first frame, in the variant it
         * needs (use_variant) */
        pt->rays_prog = compute_program(rl_gl_pt_glsl_rays, false, 0, "gl-pt rays");
        st = pt->rays_prog ? RL_OK : RL_ERR_INTERNAL;
    }
    if (st == RL_OK) {
        for (uint32_t i = 0; i < d->num_materials; ++i)
            pt->has_ggx = pt->has_ggx || d->materials[i].bsdf == RL_BSDF_GGX;
        locate(pt->rays_prog, &pt->ru);
        st = upload_materials_lights(pt, &desc->lights, desc->ggx_ms);
    }
    if (st == RL_OK)
        st = rl_gl_upload_textures(pt->data, max_block, "gl-pt", &pt->buf[B_TEX_INFO], &pt->buf[B_TEXELS]);
    if (st == RL_OK)
        st = upload_geometry(pt, &desc->lights, max_block);
    if (st == RL_OK)
        st = upload_bvh(pt, max_block);
    if (st == RL_OK)
        st = make_buffer_textures(pt);
    if (st == RL_OK) {
        pt->sm_buf = no_maps();
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->sm_tex);
        glTextureBuffer(pt->sm_tex, GL_R32F, pt->sm_buf);
        pt->env_buf = no_maps();
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->env_tex);
        glTextureBuffer(pt->env_tex, GL_R32F, pt->env_buf);
        pt->lv_buf = no_maps();
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->lv_tex);
        glTextureBuffer(pt->lv_tex, GL_RGBA32F, pt->lv_buf);
        st = rl_gl_check("rl_gl_pt_create");
    }
    if (st != RL_OK) {
        rl_gl_pt_release(pt);
        return st;
    }
    rl_gl_context_done(pt->ctx);
    *out = pt;
    return RL_OK;
}

const rl_gl_info *rl_gl_pt_info(const rl_gl_pt *pt)
{
    return pt ? rl_gl_context_info(pt->ctx) : NULL;
}

/* The allocated extent of an image side: never a power of two where the
 * limit allows. llvmpipe compiles a variant of the path program for each
 * power-of-two pattern of the bound images' sides (its sampler state keys
 * on it), and one variant of this program costs it about 100 s of CPU; with
 * the sides padded, 24 x 24, 32 x 32 and 64 x 48 share one. The pixels
 * beyond w x h are never written or read. */
static int unpowered(int n, int limit)
{
    int m = n;
    while (m > 0 && (m & (m - 1)) == 0)
        ++m;
    return m <= limit ? m : n;
}

/* New state images when the size changes; the states and a cleared sum on
 * every reset. */
static rl_status reset_images(rl_gl_pt *pt, int w, int h, const uint32_t *states)
{
    if (!pt->tex_accum || pt->width != w || pt->height != h) {
        GLint max_size = 0;
        glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
        if (w > max_size || h > max_size)
            return rl_error(RL_ERR_LIMIT, "gl-pt: %d x %d exceeds this GL's texture size limit %d", w, h,
                            (int)max_size);
        if (pt->tex_accum) {
            glDeleteTextures(1, &pt->tex_accum);
            glDeleteTextures(1, &pt->tex_rng);
            glDeleteTextures(1, &pt->tex_ids);
            glDeleteTextures(1, &pt->tex_adapt);
        }
        const int aw = unpowered(w, max_size), ah = unpowered(h, max_size);
        glCreateTextures(GL_TEXTURE_2D, 1, &pt->tex_accum);
        glTextureStorage2D(pt->tex_accum, 1, GL_RGBA32F, aw, ah);
        glCreateTextures(GL_TEXTURE_2D, 1, &pt->tex_rng);
        glTextureStorage2D(pt->tex_rng, 1, GL_RGBA32UI, aw, ah);
        /* bound in both primary modes: a shader compiler that specializes
         * on the bound textures (llvmpipe) then makes one variant */
        glCreateTextures(GL_TEXTURE_2D, 1, &pt->tex_ids);
        glTextureStorage2D(pt->tex_ids, 1, GL_R32UI, aw, ah);
        /* an integer texture with the default linear filters is incomplete
         * and every texelFetch reads 0 */
        glTextureParameteri(pt->tex_ids, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(pt->tex_ids, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        /* bound always, for the same reason */
        glCreateTextures(GL_TEXTURE_2D, 1, &pt->tex_adapt);
        glTextureStorage2D(pt->tex_adapt, 1, GL_RG32UI, aw, ah);
        pt->width = w;
        pt->height = h;
    }
    glTextureSubImage2D(pt->tex_rng, 0, 0, 0, w, h, GL_RGBA_INTEGER, GL_UNSIGNED_INT, states);
    const float zero[4] = { 0.0f, 0.0f, 0.0f, 0.0f };
    glClearTexImage(pt->tex_accum, 0, GL_RGBA, GL_FLOAT, zero);
    const GLuint none[4] = { 0, 0, 0, 0 };
    glClearTexImage(pt->tex_adapt, 0, GL_RG_INTEGER, GL_UNSIGNED_INT, none);
    pt->held[0] = pt->held[1] = 0;
    pt->frames = 0;
    pt->counted = 0;
    pt->start_count = 0;
    pt->adapt_counts = false;
    return RL_OK;
}


/* The ray counters added to rays and cleared. */
static void drain_counters(rl_gl_pt *pt, uint64_t rays[RL_GL_PT_RAY_TYPES])
{
    uint32_t c[RL_GL_PT_RAY_TYPES];
    glMemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    glGetNamedBufferSubData(pt->counters, 0, sizeof c, c);
    for (int k = 0; k < RL_GL_PT_RAY_TYPES; ++k)
        rays[k] += c[k];
    const uint32_t zero = 0;
    glClearNamedBufferData(pt->counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
}

/* The most rays of one type a dispatch of w x h paths can trace: the
 * primary ray, and per path vertex (the camera hit and max_depth bounces)
 * the shadow rays (the environment's one included) and one continuing ray. */
static uint64_t rays_bound(const rl_gl_pt_frame *f, uint32_t num_lights)
{
    uint64_t per_vertex = (uint64_t)f->light_samples * (f->mis ? 1u : (num_lights ? num_lights : 1u)) + 1u +
                          (f->env_nee ? 1u : 0u) +
                          (uint64_t)(f->light_connect > 0 ? f->light_connect : 0) * ((uint64_t)f->max_depth + 1u);
    return (uint64_t)f->cam.width * (uint64_t)f->cam.height * (1u + ((uint64_t)f->max_depth + 1u) * per_vertex);
}

/* The dispatches of one round: dispatch k traces sample k of every pixel
 * with more than k to trace (all of them without adaptive sampling, where
 * held numbers the samples). The counters are read only when the next
 * dispatch could wrap them. */
static void dispatch_samples(rl_gl_pt *pt, uint32_t count, const GLuint held_base[2], GLuint gx, GLuint gy,
                             uint64_t bound, uint64_t *pending, uint64_t rays[RL_GL_PT_RAY_TYPES])
{
    const GLuint p = pt->path_prog;
    for (uint32_t k = 0; k < count; ++k) {
        if (*pending > 0 && *pending + bound > UINT32_MAX) {
            drain_counters(pt, rays);
            *pending = 0;
        }
        /* One sample per dispatch: the accumulation of eq. 8 reads what the
         * previous sample wrote. Each class of pixels numbers its own
         * samples (checkerboard traces one class per frame). */
        const GLuint held[2] = { held_base[0] + k, held_base[1] + k };
        glProgramUniform1uiv(p, pt->pu.held, 2, held);
        glProgramUniform1ui(p, pt->pu.round_k, k);
        glDispatchCompute(gx, gy, 1);
        glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        *pending += bound;
    }
}

/* Adaptive sampling's program and buffers for w x h pixels. */
static rl_status adapt_prepare(rl_gl_pt *pt, size_t pixels)
{
    if (!pt->adapt_prog) {
        const char *const parts[] = { rl_gl_pt_glsl_header, rl_gl_pt_glsl_adapt };
        GLuint s = rl_gl_compile(GL_COMPUTE_SHADER, parts, 2, "gl-pt adaptive");
        GLuint p = s ? rl_gl_link(s, 0, "gl-pt adaptive") : 0;
        if (!p)
            return RL_ERR_INTERNAL;
        pt->adapt_prog = p;
        pt->a_mode = glGetUniformLocation(p, "u_mode");
        pt->a_size = glGetUniformLocation(p, "u_size");
        pt->a_thr = glGetUniformLocation(p, "u_thr");
        pt->a_budget = glGetUniformLocation(p, "u_budget");
        pt->a_num_active = glGetUniformLocation(p, "u_num_active");
        pt->adapt_tot = rl_gl_make_buffer(NULL, 32, GL_DYNAMIC_STORAGE_BIT);
    }
    if (pt->adapt_err_pixels != pixels) {
        if (pt->adapt_err)
            glDeleteBuffers(1, &pt->adapt_err);
        pt->adapt_err = rl_gl_make_buffer(NULL, 2 * sizeof(float) * pixels, 0);
        pt->adapt_err_pixels = pixels;
    }
    return RL_OK;
}

/* One of the passes (gl_pt_shaders.c rl_gl_pt_glsl_adapt, u_mode). */
enum { ADAPT_ERRORS = 0, ADAPT_SMOOTH, ADAPT_SHARES, ADAPT_COMMIT };
static void adapt_pass(rl_gl_pt *pt, int mode, int w, int h, float thr, double budget)
{
    const GLuint p = pt->adapt_prog;
    glUseProgram(p);
    glBindImageTexture(3, pt->tex_accum, 0, GL_FALSE, 0, GL_READ_ONLY, GL_RGBA32F);
    glBindImageTexture(2, pt->tex_adapt, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RG32UI);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 14, pt->adapt_err);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 15, pt->adapt_tot);
    glProgramUniform1i(p, pt->a_mode, mode);
    glProgramUniform2i(p, pt->a_size, w, h);
    glProgramUniform1f(p, pt->a_thr, thr);
    glProgramUniform1d(p, pt->a_budget, budget);
    glProgramUniform1d(p, pt->a_num_active, (double)w * (double)h);
    const uint64_t groups = ((uint64_t)w * (uint64_t)h + 63u) / 64u;
    if (mode == ADAPT_SHARES) {
        glDispatchCompute(1, 1, 1);
    } else {
        const GLuint gx = groups < 65535u ? (GLuint)groups : 65535u;
        glDispatchCompute(gx, (GLuint)((groups + gx - 1) / gx), 1);
    }
    glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
}

/* pathtrace.c adaptive_passes on the GPU: the uniform start up to
 * adaptive_min_spp (equal in every pixel, so a clear sets its shares),
 * then rounds by error, each at most doubling the mean count, until the
 * frame's spp x pixels are spent or nothing wants more. The shares come
 * from the GPU passes; the CPU reads back three numbers per round. */
static rl_status adaptive_frame(rl_gl_pt *pt, const rl_gl_pt_frame *f, GLuint gx, GLuint gy, uint64_t bound,
                                uint64_t rays[RL_GL_PT_RAY_TYPES], uint64_t *samples, uint64_t *converged)
{
    const int w = f->cam.width, h = f->cam.height;
    const uint64_t n = (uint64_t)w * (uint64_t)h;
    rl_status st = adapt_prepare(pt, (size_t)n);
    if (st != RL_OK)
        return st;
    const uint32_t min_spp = (uint32_t)f->adaptive_min_spp, spp = (uint32_t)f->spp;
    const uint64_t budget = (uint64_t)spp * n;
    uint64_t spent = 0, pending = 0;
    const GLuint zero_held[2] = { 0, 0 };
    if (pt->start_count < min_spp) {
        const uint32_t need = min_spp - pt->start_count, share = need < spp ? need : spp;
        const GLuint v[4] = { pt->start_count, share, 0, 0 };
        glClearTexImage(pt->tex_adapt, 0, GL_RG_INTEGER, GL_UNSIGNED_INT, v);
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT | GL_SHADER_IMAGE_ACCESS_BARRIER_BIT);
        glUseProgram(pt->path_prog);
        dispatch_samples(pt, share, zero_held, gx, gy, bound, &pending, rays);
        adapt_pass(pt, ADAPT_COMMIT, w, h, f->adaptive_threshold, 0.0);
        pt->start_count += share;
        spent = (uint64_t)share * n;
        pt->counted += spent;
    }
    uint64_t remaining = budget - spent;
    struct {
        GLuint max_share, converged, pad[2];
        double given;
    } tot;
    *converged = 0;
    while (remaining > 0) {
        const uint64_t mean = pt->counted / n;
        uint64_t round = n * (mean > 1 ? mean : 1);
        round = round < remaining ? round : remaining;
        memset(&tot, 0, sizeof tot);
        glNamedBufferSubData(pt->adapt_tot, 0, sizeof tot, &tot);
        adapt_pass(pt, ADAPT_ERRORS, w, h, f->adaptive_threshold, 0.0);
        adapt_pass(pt, ADAPT_SMOOTH, w, h, f->adaptive_threshold, 0.0);
        adapt_pass(pt, ADAPT_SHARES, w, h, f->adaptive_threshold, (double)round);
        glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        glGetNamedBufferSubData(pt->adapt_tot, 0, sizeof tot, &tot);
        *converged = tot.converged;
        const uint64_t given = (uint64_t)tot.given;
        if (given == 0)
            break;
        glUseProgram(pt->path_prog);
        dispatch_samples(pt, tot.max_share, zero_held, gx, gy, bound, &pending, rays);
        adapt_pass(pt, ADAPT_COMMIT, w, h, f->adaptive_threshold, 0.0);
        spent += given;
        pt->counted += given;
        remaining -= round;
    }
    glUseProgram(pt->path_prog);
    pt->adapt_counts = true;
    *samples = spent;
    return RL_OK;
}

/* Deletes the frame texture nobody took (the context current). */
static void drop_frame(rl_gl_pt *pt)
{
    if (pt->out.fence)
        glDeleteSync((GLsync)pt->out.fence);
    if (pt->out.texture)
        glDeleteTextures(1, &pt->out.texture);
    pt->out = (rl_gl_frame){ 0 };
}

/* The path program of variant v (V_*), made on its first use: a scene
 * without GGX, a frame without light paths and a tracer without an
 * environment compile the smaller program. */
static rl_status use_variant(rl_gl_pt *pt, unsigned v)
{
    int slot = -1;
    for (int i = 0; i < PATH_VARIANTS && slot < 0; ++i)
        if (pt->variant_prog[i] && pt->variant_key[i] == v)
            slot = i;
    if (slot < 0) {
        GLuint p = compute_program(rl_gl_pt_glsl_path, true, v, "gl-pt path");
        if (!p)
            return RL_ERR_INTERNAL;
        /* a tracer that meets more variants than it keeps (rl view
         * stepping through the structures) makes the oldest again */
        slot = (int)(pt->variants_made++ % PATH_VARIANTS);
        if (pt->variant_prog[slot])
            glDeleteProgram(pt->variant_prog[slot]);
        pt->variant_prog[slot] = p;
        pt->variant_key[slot] = v;
        locate(p, &pt->variant_u[slot]);
    }
    pt->path_prog = pt->variant_prog[slot];
    pt->pu = pt->variant_u[slot];
    return RL_OK;
}

static rl_status render_frame(rl_gl_pt *pt, const rl_gl_pt_frame *f, float *rgba, uint64_t rays[RL_GL_PT_RAY_TYPES],
                              uint64_t *samples, uint64_t *converged)
{
    const rl_scene_data *d = pt->data;
    const int w = f->cam.width, h = f->cam.height;
    rl_status st = RL_OK;
    if (f->reset_states)
        st = reset_images(pt, w, h, f->reset_states);
    else if (!pt->tex_accum || pt->width != w || pt->height != h)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_render: a new %d x %d accumulation needs its states", w, h);
    if (st == RL_OK && (f->shadow == RL_GL_PT_GRID || f->diffuse == RL_GL_PT_GRID || f->specular == RL_GL_PT_GRID))
        st = ensure_grid(pt, f->grid_res);
    /* each LS structure needs its payload in the tracer's Line Space */
    const rl_gl_pt_structure used[3] = { f->shadow, f->diffuse, f->specular };
    const unsigned need[RL_GL_PT_STRUCTURE_COUNT] = { 0, 0, RL_LS_CANDIDATES, RL_LS_PNMT, RL_LS_PREILLUM, 0 };
    for (int i = 0; i < 3 && st == RL_OK; ++i)
        if (need[used[i]] && (!pt->ls || !(pt->ls_payloads & need[used[i]])))
            st = rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_render: a Line Space structure without a Line Space "
                          "holding its payload (rl_gl_pt_set_linespace)");
    if (st == RL_OK && f->shadow == RL_GL_PT_SHADOWMAP && !pt->have_sm)
        st = rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_render: shadow maps not made (rl_gl_pt_set_shadowmaps)");
    const bool lvc = f->light_connect > 0 && pt->lv_paths > 0;
    if (st == RL_OK)
        st = use_variant(pt, (pt->has_ggx ? V_GGX : 0u) | (lvc ? V_LIGHT_VERTICES : 0u) | (pt->have_env ? V_ENV : 0u) |
                                 ((1u << RL_GL_PT_BVH) | (1u << f->shadow) | (1u << f->diffuse) | (1u << f->specular))
                                     << V_STRUCTURE_SHIFT);
    if (st != RL_OK)
        return st;
    const GLuint p = pt->path_prog;
    const uniforms *u = &pt->pu;
    glUseProgram(p);
    bind_scene(pt, p, u);
    glBindImageTexture(0, pt->tex_accum, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32F);
    glBindImageTexture(1, pt->tex_rng, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RGBA32UI);
    glBindImageTexture(2, pt->tex_adapt, 0, GL_FALSE, 0, GL_READ_WRITE, GL_RG32UI);
    const rl_camera_frame *c = &f->cam;
    glProgramUniform2i(p, u->size, w, h);
    glProgramUniform3f(p, u->eye, c->eye.x, c->eye.y, c->eye.z);
    glProgramUniform3f(p, u->cam_u, c->u.x, c->u.y, c->u.z);
    glProgramUniform3f(p, u->cam_v, c->v.x, c->v.y, c->v.z);
    glProgramUniform3f(p, u->cam_w, c->w.x, c->w.y, c->w.z);
    glProgramUniform1f(p, u->tan_half_fov, c->tan_half_fov_y);
    glProgramUniform1f(p, u->aspect, c->aspect);
    glProgramUniform1i(p, u->rng, f->rng);
    glProgramUniform1i(p, u->checker, f->checkerboard);
    const uint32_t parity = (uint32_t)(pt->frames & 1u);
    glProgramUniform1ui(p, u->parity, parity);
    glProgramUniform1i(p, u->raster, f->raster_ids != NULL);
    if (f->raster_ids) {
        glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
        glTextureSubImage2D(pt->tex_ids, 0, 0, 0, w, h, GL_RED_INTEGER, GL_UNSIGNED_INT, f->raster_ids);
    }
    glBindTextureUnit(6, pt->tex_ids);
    glBindTextureUnit(SM_UNIT, pt->sm_tex);
    glBindTextureUnit(ENV_UNIT, pt->env_tex);
    glBindTextureUnit(LV_UNIT, pt->lv_tex);
    if (pt->have_sm) {
        glProgramUniform1i(p, u->sm_size, pt->sm_desc.size);
        glProgramUniform1f(p, u->sm_bias, pt->sm_desc.bias);
        glProgramUniform1f(p, u->sm_slope, pt->sm_desc.slope_bias);
        glProgramUniform1f(p, u->sm_pcf, pt->sm_desc.pcf_radius);
        float frames[18][3];
        for (int face = 0; face < 6; ++face) {
            rl_vec3 v[3];
            rl_shadowmap_face_frame(face, &v[0], &v[1], &v[2]);
            for (int k = 0; k < 3; ++k)
                memcpy(frames[3 * face + k], &v[k], sizeof frames[0]);
        }
        glProgramUniform3fv(p, u->sm_frame, 18, &frames[0][0]);
    }
    if (!pt->counters) {
        pt->counters = rl_gl_make_buffer(NULL, 32, GL_DYNAMIC_STORAGE_BIT);
        const uint32_t zero = 0;
        glClearNamedBufferData(pt->counters, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    }
    glBindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, pt->counters);
    glProgramUniform1i(p, u->max_depth, f->max_depth);
    glProgramUniform1i(p, u->rr_depth, f->rr_depth);
    glProgramUniform1i(p, u->rr, f->rr);
    glProgramUniform1i(p, u->mis, f->mis);
    glProgramUniform1i(p, u->mis_hits, f->mis && f->mis_hits);
    glProgramUniform1i(p, u->tri_lights, f->mis && f->tri_lights);
    glProgramUniform1i(p, u->light_samples, f->light_samples);
    /* pathtrace.c: sampler slots per path vertex */
    uint32_t slots = 4u + 3u * (uint32_t)f->light_samples * (f->mis ? 1u : (d->num_lights ? d->num_lights : 1u));
    /* the environment's sample: one slot after the lights', in scenes
     * that have one (pathtrace.c) */
    glProgramUniform1ui(p, u->env_slot, slots);
    slots += pt->have_env ? 1u : 0u;
    /* hybrid light paths: one slot per drawn light path, after the rest
     * (none without, so that the other slots keep their places) */
    glProgramUniform1i(p, u->lvc, lvc);
    glProgramUniform1ui(p, u->lv_slot, slots);
    glProgramUniform1ui(p, u->lv_paths, pt->lv_paths);
    glProgramUniform1ui(p, u->lv_base, pt->lv_base);
    glProgramUniform1i(p, u->lv_connect, f->light_connect);
    glProgramUniform1f(p, u->lv_nu1, f->light_nu1);
    glProgramUniform1ui(p, u->vertex_slots, slots + (lvc ? (uint32_t)f->light_connect : 0u));
    glProgramUniform1i(p, u->env, pt->have_env);
    glProgramUniform1i(p, u->env_nee, pt->have_env && f->env_nee);
    glProgramUniform1i(p, u->ggx_ms, f->ggx_ms);
    glProgramUniform2i(p, u->env_map, pt->env_map[0], pt->env_map[1]);
    glProgramUniform2i(p, u->env_size, pt->env_size[0], pt->env_size[1]);
    glProgramUniform3i(p, u->env_off, pt->env_off[0], pt->env_off[1], pt->env_off[2]);
    glProgramUniform1f(p, u->env_rot, pt->env_rot);
    glProgramUniform1d(p, u->env_sum, pt->env_sum);
    glProgramUniform1i(p, u->num_lights, (GLint)d->num_lights);
    glProgramUniform1ui(p, u->table_count, pt->table_count);
    glProgramUniform1ui(p, u->num_textures, d->num_textures);
    glProgramUniform1f(p, u->eps, pt->eps);
    glProgramUniform3f(p, u->background, f->background.x, f->background.y, f->background.z);
    glProgramUniform1i(p, u->shadow, (GLint)f->shadow);
    glProgramUniform1i(p, u->diffuse, (GLint)f->diffuse);
    glProgramUniform1i(p, u->specular, (GLint)f->specular);
    glProgramUniform1f(p, u->ls_start, f->ls_start);
    glProgramUniform1f(p, u->ls_offset, f->ls_offset);
    if (pt->ls) {
        rl_gl_ls_bind(pt->ls);
        rl_gl_ls_set_uniforms(pt->ls, p);
    }
    const GLuint gx = (GLuint)(w + LOCAL - 1) / LOCAL, gy = (GLuint)(h + LOCAL - 1) / LOCAL;
    const uint64_t bound = rays_bound(f, d->num_lights);
    glProgramUniform1i(p, u->adaptive, f->adaptive);
    *converged = 0;
    if (f->adaptive) {
        st = adaptive_frame(pt, f, gx, gy, bound, rays, samples, converged);
        if (st != RL_OK)
            return st;
        drain_counters(pt, rays);
        /* the mean samples per pixel (the filters' noise scale) */
        pt->held[0] = pt->held[1] = pt->counted / ((uint64_t)w * (uint64_t)h);
    } else {
        uint64_t pending = 0;
        const GLuint held[2] = { (GLuint)pt->held[0], (GLuint)pt->held[1] };
        dispatch_samples(pt, (uint32_t)f->spp, held, gx, gy, bound, &pending, rays);
        drain_counters(pt, rays);
        for (int c = 0; c < 2; ++c)
            if (!f->checkerboard || (uint32_t)c == parity)
                pt->held[c] += (uint64_t)f->spp;
        *samples = 0;
    }
    pt->frames++;
    if (rgba) {
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glGetTextureSubImage(pt->tex_accum, 0, 0, 0, 0, w, h, 1, GL_RGBA, GL_FLOAT,
                             (GLsizei)((size_t)w * (size_t)h * 4 * sizeof(float)), rgba);
    } else if (pt->texture_out) {
        /* The mean stays on the GPU: a copy of the image's part of the
         * accumulation (which may be larger) for the caller, and a fence. */
        drop_frame(pt);
        glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
        glCreateTextures(GL_TEXTURE_2D, 1, &pt->out.texture);
        glTextureStorage2D(pt->out.texture, 1, GL_RGBA32F, w, h);
        glTextureParameteri(pt->out.texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        glTextureParameteri(pt->out.texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        glCopyImageSubData(pt->tex_accum, GL_TEXTURE_2D, 0, 0, 0, 0, pt->out.texture, GL_TEXTURE_2D, 0, 0, 0, 0, w,
                           h, 1);
        pt->out.width = w;
        pt->out.height = h;
        pt->out.fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
        glFlush();
    } else {
        glFinish();
    }
    return rl_gl_check("rl_gl_pt_render");
}

rl_status rl_gl_pt_render(rl_gl_pt *pt, const rl_gl_pt_frame *frame, float *rgba, rl_gl_pt_result *res)
{
    if (!pt || !frame)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_render: NULL argument");
    if (frame->cam.width < 1 || frame->cam.height < 1 || frame->spp < 1 || frame->light_samples < 1 ||
        (unsigned)frame->shadow >= RL_GL_PT_STRUCTURE_COUNT || (unsigned)frame->diffuse >= RL_GL_PT_STRUCTURE_COUNT ||
        (unsigned)frame->specular >= RL_GL_PT_STRUCTURE_COUNT || frame->diffuse == RL_GL_PT_SHADOWMAP ||
        frame->specular == RL_GL_PT_SHADOWMAP ||
        frame->rng < 0 || frame->rng > 3)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_render: bad frame settings");
    const uint64_t most = frame->reset_states ? 0 : (pt->held[0] > pt->held[1] ? pt->held[0] : pt->held[1]);
    if (most + (uint64_t)frame->spp > UINT32_MAX)
        return rl_error(RL_ERR_LIMIT, "gl-pt: more than 2^32 samples per pixel in one accumulation");
    if (frame->adaptive && (frame->checkerboard || frame->adaptive_min_spp < 2 || !(frame->adaptive_threshold >= 0.0f)))
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_render: adaptive sampling needs adaptive_min_spp >= 2, a "
                        "threshold >= 0 and no checkerboard");
    uint64_t rays[RL_GL_PT_RAY_TYPES] = { 0 }, samples = 0, converged = 0;
    rl_status st = rl_gl_context_make_current(pt->ctx);
    if (st == RL_OK) {
        /* an untaken texture of an earlier frame must not pass for this one's */
        drop_frame(pt);
        st = render_frame(pt, frame, rgba, rays, &samples, &converged);
    }
    if (st != RL_OK && frame->reset_states) {
        pt->held[0] = pt->held[1] = 0;
        pt->frames = 0;
    }
    if (res) {
        memcpy(res->held, pt->held, sizeof res->held);
        res->frames = pt->frames;
        memcpy(res->rays, rays, sizeof res->rays);
        res->samples = samples;
        res->converged = converged;
    }
    rl_gl_context_done(pt->ctx);
    return st;
}

rl_status rl_gl_pt_sample_counts(rl_gl_pt *pt, uint32_t *counts)
{
    if (!pt || !counts || !pt->adapt_counts)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_sample_counts: needs a tracer after an adaptive frame");
    rl_status st = rl_gl_context_make_current(pt->ctx);
    if (st != RL_OK)
        return st;
    const size_t n = (size_t)pt->width * (size_t)pt->height;
    uint32_t *both = rl_alloc(2 * n * sizeof *both);
    if (!both) {
        rl_gl_context_done(pt->ctx);
        return RL_ERR_OUT_OF_MEMORY;
    }
    glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
    glGetTextureSubImage(pt->tex_adapt, 0, 0, 0, 0, pt->width, pt->height, 1, GL_RG_INTEGER, GL_UNSIGNED_INT,
                         (GLsizei)(2 * n * sizeof *both), both);
    for (size_t i = 0; i < n; ++i)
        counts[i] = both[2 * i];
    free(both);
    st = rl_gl_check("rl_gl_pt_sample_counts");
    rl_gl_context_done(pt->ctx);
    return st;
}

void rl_gl_pt_set_texture_output(rl_gl_pt *pt, bool on)
{
    pt->texture_out = on;
}

bool rl_gl_pt_take_frame(rl_gl_pt *pt, rl_gl_frame *out)
{
    if (!pt->out.texture)
        return false;
    *out = pt->out;
    pt->out = (rl_gl_frame){ 0 };
    return true;
}

rl_status rl_gl_pt_set_linespace(rl_gl_pt *pt, const rl_linespace *ls, const rl_accel *grid,
                                 const rl_linespace_desc *desc)
{
    if (!pt || (!ls && (!grid || !desc)))
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_set_linespace: NULL argument");
    rl_status st = rl_gl_context_make_current(pt->ctx);
    if (st != RL_OK)
        return st;
    rl_gl_ls_release(pt->ls);
    pt->ls = NULL;
    pt->ls_payloads = 0;
    const rl_gl_ls_limits lim = { 0 };
    rl_gl_ls *g = NULL;
    st = ls ? rl_gl_ls_upload(ls, &lim, &g) : rl_gl_ls_build(grid, desc, &lim, &g);
    if (st == RL_OK) {
        rl_gl_ls_stats gs;
        rl_gl_ls_get_stats(g, &gs);
        pt->ls = g;
        pt->ls_payloads = gs.payloads;
    }
    rl_gl_context_done(pt->ctx);
    return st;
}

/* The depth pass's program, once. */
static rl_status shadow_program(rl_gl_pt *pt)
{
    if (pt->sm_prog)
        return RL_OK;
    GLuint p = compute_program(NULL, false, 0, "gl-pt shadow maps");
    if (!p)
        return RL_ERR_INTERNAL;
    pt->sm_prog = p;
    pt->sm_eye = glGetUniformLocation(p, "u_sm_eye");
    pt->sm_face_s = glGetUniformLocation(p, "u_face_s");
    pt->sm_face_u = glGetUniformLocation(p, "u_face_u");
    pt->sm_face_axis = glGetUniformLocation(p, "u_face_axis");
    pt->sm_near = glGetUniformLocation(p, "u_near");
    pt->sm_far = glGetUniformLocation(p, "u_far");
    pt->sm_masks = glGetUniformLocation(p, "u_masks");
    return RL_OK;
}

/* Every light's six faces drawn into a size x size target (eye depth in an
 * r32f colour attachment, the test on a float depth buffer) and copied,
 * face by face, into maps at (light * 6 + face) * size^2 through the pixel
 * pack buffer: the maps never leave the GPU. A light's casters
 * (rl_shadowmap_casts) go up into one list buffer, light after light. */
static rl_status draw_shadowmaps(rl_gl_pt *pt, const rl_shadowmap_desc *p, GLuint maps)
{
    const rl_scene_data *d = pt->data;
    const int size = p->size;
    uint32_t *list = rl_calloc(d->num_triangles ? d->num_triangles : 1, sizeof *list);
    if (!list)
        return RL_ERR_OUT_OF_MEMORY;
    GLuint casters = rl_gl_make_buffer(NULL, sizeof *list * d->num_triangles, GL_DYNAMIC_STORAGE_BIT);
    GLuint color = 0, depth = 0, fbo = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &color);
    glTextureStorage2D(color, 1, GL_R32F, size, size);
    glCreateTextures(GL_TEXTURE_2D, 1, &depth);
    glTextureStorage2D(depth, 1, GL_DEPTH_COMPONENT32F, size, size);
    glCreateFramebuffers(1, &fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, color, 0);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth, 0);
    rl_status st = RL_OK;
    if (glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        st = rl_error(RL_ERR_INTERNAL, "gl-pt: the shadow maps' %d x %d target is incomplete", size, size);
    if (st == RL_OK) {
        const GLuint prog = pt->sm_prog;
        glUseProgram(prog);
        for (GLuint t = 0; t < T_COUNT; ++t)
            glBindTextureUnit(t, pt->tex[t]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, B_MATERIALS, pt->buf[B_MATERIALS]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, B_TEX_INFO, pt->buf[B_TEX_INFO]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, B_TRIANGLES, pt->buf[B_TRIANGLES]);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, SM_CASTERS, casters);
        glProgramUniform1i(prog, pt->sm_masks, pt->masks);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo);
        glViewport(0, 0, size, size);
        glDisable(GL_CULL_FACE);
        glDisable(GL_BLEND);
        glEnable(GL_DEPTH_TEST);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        /* an empty VAO: the vertices are pulled from the storage buffers */
        GLuint vao = 0;
        glCreateVertexArrays(1, &vao);
        glBindVertexArray(vao);
        /* the software rasterizer's cleared depth: nothing there, lit */
        const float far_away[4] = { INFINITY, 0.0f, 0.0f, 0.0f };
        const float one = 1.0f;
        glBindBuffer(GL_PIXEL_PACK_BUFFER, maps);
        glPixelStorei(GL_PACK_ALIGNMENT, 4);
        const size_t face_bytes = (size_t)size * (size_t)size * sizeof(float);
        for (uint32_t li = 0; li < d->num_lights; ++li) {
            const rl_vec3 eye = rl_shadowmap_light_point(&d->lights[li]);
            float z_near, z_far;
            rl_shadowmap_depth_range(d, eye, &z_near, &z_far);
            uint32_t count = 0;
            for (uint32_t t = 0; t < d->num_triangles; ++t)
                if (rl_shadowmap_casts(d, &d->lights[li], t))
                    list[count++] = t;
            if (count > 0)
                glNamedBufferSubData(casters, 0, (GLsizeiptr)(sizeof *list * count), list);
            glProgramUniform3f(prog, pt->sm_eye, eye.x, eye.y, eye.z);
            glProgramUniform1f(prog, pt->sm_near, z_near);
            glProgramUniform1f(prog, pt->sm_far, z_far);
            for (int face = 0; face < 6; ++face) {
                rl_vec3 fs, fu, fa;
                rl_shadowmap_face_frame(face, &fs, &fu, &fa);
                glProgramUniform3f(prog, pt->sm_face_s, fs.x, fs.y, fs.z);
                glProgramUniform3f(prog, pt->sm_face_u, fu.x, fu.y, fu.z);
                glProgramUniform3f(prog, pt->sm_face_axis, fa.x, fa.y, fa.z);
                glClearNamedFramebufferfv(fbo, GL_COLOR, 0, far_away);
                glClearNamedFramebufferfv(fbo, GL_DEPTH, 0, &one);
                if (count > 0)
                    glDrawArrays(GL_TRIANGLES, 0, (GLsizei)(3u * count));
                const size_t offset = ((size_t)li * 6u + (size_t)face) * face_bytes;
                glGetTextureImage(color, 0, GL_RED, GL_FLOAT, (GLsizei)face_bytes, (void *)(uintptr_t)offset);
            }
        }
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glBindVertexArray(0);
        glDeleteVertexArrays(1, &vao);
        glDisable(GL_DEPTH_TEST);
        glFinish();
    }
    glDeleteFramebuffers(1, &fbo);
    glDeleteTextures(1, &color);
    glDeleteTextures(1, &depth);
    glDeleteBuffers(1, &casters);
    free(list);
    rl_status gl = rl_gl_check("rl_gl_pt_set_shadowmaps");
    return st != RL_OK ? st : gl;
}

static rl_status make_shadowmaps(rl_gl_pt *pt, const rl_shadowmap_desc *p)
{
    const rl_scene_data *d = pt->data;
    GLint max_texels = 0, max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    const uint64_t texels = (uint64_t)d->num_lights * 6u * (uint64_t)p->size * (uint64_t)p->size;
    if (p->size > max_size)
        return rl_error(RL_ERR_LIMIT, "gl-pt: shadow maps of %d texels a side exceed this GL's texture size %d",
                        p->size, (int)max_size);
    if (texels > (uint64_t)max_texels || texels > (uint64_t)INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "gl-pt: %u lights x 6 faces x %d^2 shadow-map texels exceed this GL's buffer "
                        "texture size of %d texels (a smaller shadowmap_size fits)", d->num_lights, p->size,
                        (int)max_texels);
    if ((uint64_t)d->num_triangles * 3u > (uint64_t)INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "gl-pt: %u triangles are too many to draw into shadow maps in one call",
                        d->num_triangles);
    rl_status st = shadow_program(pt);
    if (st != RL_OK)
        return st;
    GLuint maps = texels ? rl_gl_make_buffer(NULL, texels * sizeof(float), 0) : no_maps();
    st = draw_shadowmaps(pt, p, maps);
    if (st != RL_OK) {
        glDeleteBuffers(1, &maps);
        return st;
    }
    glDeleteTextures(1, &pt->sm_tex);
    glDeleteBuffers(1, &pt->sm_buf);
    pt->sm_buf = maps;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->sm_tex);
    glTextureBuffer(pt->sm_tex, GL_R32F, pt->sm_buf);
    return rl_gl_check("rl_gl_pt_set_shadowmaps");
}

rl_status rl_gl_pt_set_shadowmaps(rl_gl_pt *pt, const rl_shadowmap_desc *desc)
{
    if (!pt)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_set_shadowmaps: NULL argument");
    rl_shadowmap_desc p;
    rl_status st = rl_shadowmap_resolve_desc(desc, "rl_gl_pt_set_shadowmaps", &p);
    if (st == RL_OK)
        st = rl_shadowmap_check_lights(pt->data, "gl-pt shadow maps");
    if (st != RL_OK)
        return st;
    if (pt->have_sm && memcmp(&p, &pt->sm_desc, sizeof p) == 0)
        return RL_OK;
    st = rl_gl_context_make_current(pt->ctx);
    if (st != RL_OK)
        return st;
    pt->have_sm = false;
    st = make_shadowmaps(pt, &p);
    if (st == RL_OK) {
        pt->sm_desc = p;
        pt->have_sm = true;
    }
    rl_gl_context_done(pt->ctx);
    return st;
}

/* The environment's arrays into one r32f buffer: radiance texels (rgb),
 * weights, conditional sums, marginal sums; one float of padding where the
 * byte size would be a power of two (no_maps). */
static rl_status upload_environment(rl_gl_pt *pt, const rl_gl_pt_env *e)
{
    const size_t texels = (size_t)e->map_width * (size_t)e->map_height;
    const size_t cells = (size_t)e->width * (size_t)e->height;
    const size_t n_w = cells, n_c = ((size_t)e->width + 1) * (size_t)e->height, n_m = (size_t)e->height + 1;
    size_t total = 3 * texels + n_w + n_c + n_m;
    if (((total * 4) & (total * 4 - 1)) == 0)
        ++total;
    GLint max_texels = 0;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    if (total > (size_t)max_texels || total > (size_t)INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "gl-pt: the environment's %zu floats (map %d x %d) exceed this GL's buffer "
                        "texture size of %d texels", total, e->map_width, e->map_height, (int)max_texels);
    float *data = rl_calloc(total, sizeof *data);
    if (!data)
        return RL_ERR_OUT_OF_MEMORY;
    memcpy(data, e->radiance, 3 * texels * sizeof *data);
    memcpy(data + 3 * texels, e->weight, n_w * sizeof *data);
    memcpy(data + 3 * texels + n_w, e->conditional, n_c * sizeof *data);
    memcpy(data + 3 * texels + n_w + n_c, e->marginal, n_m * sizeof *data);
    GLuint b = rl_gl_make_buffer(data, total * sizeof *data, 0);
    free(data);
    glDeleteTextures(1, &pt->env_tex);
    glDeleteBuffers(1, &pt->env_buf);
    pt->env_buf = b;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->env_tex);
    glTextureBuffer(pt->env_tex, GL_R32F, pt->env_buf);
    pt->env_map[0] = e->map_width;
    pt->env_map[1] = e->map_height;
    pt->env_size[0] = e->width;
    pt->env_size[1] = e->height;
    pt->env_off[0] = (int)(3 * texels);
    pt->env_off[1] = (int)(3 * texels + n_w);
    pt->env_off[2] = (int)(3 * texels + n_w + n_c);
    pt->env_rot = e->rotation;
    pt->env_sum = e->sum;
    pt->have_env = true;
    return rl_gl_check("rl_gl_pt_set_environment");
}

rl_status rl_gl_pt_set_light_vertices(rl_gl_pt *pt, const rl_gl_pt_light_vertices *lv)
{
    if (!pt || !lv || (lv->paths > 0 && (!lv->offsets || (lv->offsets[lv->paths] > 0 && !lv->data))))
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_set_light_vertices: NULL argument");
    const uint32_t n = lv->paths;
    for (uint32_t j = 0; j < n; ++j)
        if (lv->offsets[j] > lv->offsets[j + 1] || (j == 0 && lv->offsets[0] != 0))
            return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_set_light_vertices: offsets not from 0 upwards");
    const size_t count = n ? lv->offsets[n] : 0;
    const size_t base = n ? ((size_t)n + 1 + 3) / 4 : 0;    /* texels of offsets */
    size_t texels = base + count * (RL_GL_PT_LV_FLOATS / 4);
    if (n > 0 && ((texels * 16) & (texels * 16 - 1)) == 0)
        ++texels;                  /* off a power of two: one variant (no_maps) */
    GLint max_texels = 0;
    rl_status st = rl_gl_context_make_current(pt->ctx);
    if (st != RL_OK)
        return st;
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
    if (texels > (size_t)max_texels || texels > (size_t)INT32_MAX) {
        rl_gl_context_done(pt->ctx);
        return rl_error(RL_ERR_LIMIT, "gl-pt: %zu light vertices of %u paths exceed this GL's buffer texture size "
                        "of %d texels", count, n, (int)max_texels);
    }
    GLuint b = 0;
    if (n > 0) {
        float *data = rl_calloc(texels, 4 * sizeof *data);
        if (!data) {
            rl_gl_context_done(pt->ctx);
            return RL_ERR_OUT_OF_MEMORY;
        }
        memcpy(data, lv->offsets, ((size_t)n + 1) * sizeof *lv->offsets);
        if (count)
            memcpy(data + 4 * base, lv->data, count * RL_GL_PT_LV_FLOATS * sizeof *data);
        b = rl_gl_make_buffer(data, texels * 4 * sizeof *data, 0);
        free(data);
    } else {
        b = no_maps();
    }
    glDeleteTextures(1, &pt->lv_tex);
    glDeleteBuffers(1, &pt->lv_buf);
    pt->lv_buf = b;
    glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->lv_tex);
    glTextureBuffer(pt->lv_tex, GL_RGBA32F, pt->lv_buf);
    pt->lv_paths = n;
    pt->lv_base = (uint32_t)base;
    st = rl_gl_check("rl_gl_pt_set_light_vertices");
    rl_gl_context_done(pt->ctx);
    return st;
}

rl_status rl_gl_pt_set_environment(rl_gl_pt *pt, const rl_gl_pt_env *env)
{
    if (!pt)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_set_environment: NULL argument");
    if (env && (!env->radiance || !env->weight || !env->conditional || !env->marginal || env->map_width < 1 ||
                env->map_height < 1 || env->width < 1 || env->height < 1 || !isfinite(env->rotation) ||
                !(env->sum >= 0.0) || !isfinite(env->sum)))
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_set_environment: missing arrays, empty grids or a bad sum");
    rl_status st = rl_gl_context_make_current(pt->ctx);
    if (st != RL_OK)
        return st;
    if (env) {
        st = upload_environment(pt, env);
    } else {
        glDeleteTextures(1, &pt->env_tex);
        glDeleteBuffers(1, &pt->env_buf);
        pt->env_buf = no_maps();
        glCreateTextures(GL_TEXTURE_BUFFER, 1, &pt->env_tex);
        glTextureBuffer(pt->env_tex, GL_R32F, pt->env_buf);
        pt->have_env = false;
        st = rl_gl_check("rl_gl_pt_set_environment");
    }
    rl_gl_context_done(pt->ctx);
    return st;
}

static rl_status trace_rays(rl_gl_pt *pt, rl_gl_pt_structure structure, int grid_res, bool any, const rl_ray *rays,
                            uint32_t n, rl_hit *hits)
{
    rl_status st = structure == RL_GL_PT_GRID ? ensure_grid(pt, grid_res) : RL_OK;
    if (st != RL_OK)
        return st;
    float *in = rl_calloc(n, 8 * sizeof *in);
    if (!in)
        return RL_ERR_OUT_OF_MEMORY;
    for (uint32_t i = 0; i < n; ++i) {
        put4(&in[8 * (size_t)i], rays[i].o, rays[i].t_min);
        put4(&in[8 * (size_t)i + 4], rays[i].d, rays[i].t_max);
    }
    replace_buffer(pt, B_RAYS, in, 32 * (size_t)n, 0);
    replace_buffer(pt, B_HITS, NULL, 16 * (size_t)n, 0);
    free(in);
    const GLuint p = pt->rays_prog;
    glUseProgram(p);
    bind_scene(pt, p, &pt->ru);
    glProgramUniform1ui(p, pt->ru.count, n);
    glProgramUniform1i(p, pt->ru.structure, (GLint)structure);
    glProgramUniform1i(p, pt->ru.any, any);
    glDispatchCompute((n + RAYS_LOCAL - 1) / RAYS_LOCAL, 1, 1);
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    struct { float t, u, v; uint32_t tri; } *out = rl_calloc(n, 16);
    if (!out)
        return RL_ERR_OUT_OF_MEMORY;
    glGetNamedBufferSubData(pt->buf[B_HITS], 0, 16 * (GLsizeiptr)n, out);
    for (uint32_t i = 0; i < n; ++i)
        hits[i] = (rl_hit){ out[i].t, out[i].u, out[i].v, out[i].tri, RL_ID_NONE };
    free(out);
    return rl_gl_check("rl_gl_pt_trace");
}

rl_status rl_gl_pt_trace(rl_gl_pt *pt, rl_gl_pt_structure structure, int grid_res, bool any, const rl_ray *rays,
                         uint32_t n, rl_hit *hits)
{
    if (!pt || (n && (!rays || !hits)) || (unsigned)structure > RL_GL_PT_GRID)
        return rl_error(RL_ERR_INVALID_ARG, "rl_gl_pt_trace: bad argument (BVH or GRID)");
    if (n == 0)
        return RL_OK;
    if ((uint64_t)n * 32 > (uint64_t)INT32_MAX)
        return rl_error(RL_ERR_LIMIT, "rl_gl_pt_trace: %u rays in one call", n);
    rl_status st = rl_gl_context_make_current(pt->ctx);
    if (st == RL_OK)
        st = trace_rays(pt, structure, grid_res, any, rays, n, hits);
    rl_gl_context_done(pt->ctx);
    return st;
}

#else /* !RL_HAVE_GL */

struct rl_gl_pt {
    int unused;
};

rl_status rl_gl_pt_create(const rl_scene *scene, const rl_gl_pt_desc *desc, rl_gl_pt **out)
{
    (void)scene;
    if (out)
        *out = NULL;
    rl_gl_context *ctx = NULL;
    return rl_gl_context_create(desc ? desc->device : NULL, &ctx);
}

void rl_gl_pt_release(rl_gl_pt *pt) { (void)pt; }

const rl_gl_info *rl_gl_pt_info(const rl_gl_pt *pt)
{
    (void)pt;
    return NULL;
}

void rl_gl_pt_set_texture_output(rl_gl_pt *pt, bool on)
{
    (void)pt;
    (void)on;
}

bool rl_gl_pt_take_frame(rl_gl_pt *pt, rl_gl_frame *out)
{
    (void)pt;
    (void)out;
    return false;
}

rl_status rl_gl_pt_render(rl_gl_pt *pt, const rl_gl_pt_frame *frame, float *rgba, rl_gl_pt_result *res)
{
    (void)pt;
    (void)frame;
    (void)rgba;
    if (res)
        memset(res, 0, sizeof *res);
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_pt_sample_counts(rl_gl_pt *pt, uint32_t *counts)
{
    (void)pt;
    (void)counts;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_pt_set_linespace(rl_gl_pt *pt, const rl_linespace *ls, const rl_accel *grid,
                                 const rl_linespace_desc *desc)
{
    (void)pt;
    (void)ls;
    (void)grid;
    (void)desc;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_pt_set_shadowmaps(rl_gl_pt *pt, const rl_shadowmap_desc *desc)
{
    (void)pt;
    (void)desc;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_pt_set_light_vertices(rl_gl_pt *pt, const rl_gl_pt_light_vertices *lv)
{
    (void)pt;
    (void)lv;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_pt_set_environment(rl_gl_pt *pt, const rl_gl_pt_env *env)
{
    (void)pt;
    (void)env;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

rl_status rl_gl_pt_trace(rl_gl_pt *pt, rl_gl_pt_structure structure, int grid_res, bool any, const rl_ray *rays,
                         uint32_t n, rl_hit *hits)
{
    (void)pt;
    (void)structure;
    (void)grid_res;
    (void)any;
    (void)rays;
    (void)n;
    (void)hits;
    return rl_error(RL_ERR_UNSUPPORTED, "gl: built without OpenGL");
}

#endif
