/* gl_shaders.c: the GL drawer's GLSL 4.50 programs. Each function mirrors
 * a C function of the software path line by line, so that the two images
 * agree (docs/gl.md lists the differences that remain):
 *
 *   light_at, phong   <- scene_drawer.c light_at, phong (Ullmann 2003,
 *                        Sec. 3.1, eq. 3.1 without k_r, k_t; two-sided;
 *                        quad lights as points); rl_light_eval_delta
 *   tex_sample        <- core/texture_sample.h (bilinear, repeat, texel
 *                        centres at half-integers, v up), read from one
 *                        buffer of all texels so that any number of
 *                        textures of any size is one binding
 *   shading_normal    <- scene/material.c rl_shading_normal (the
 *                        per-triangle tangent frame of a normal map)
 *   vertex stage      <- Gouraud: phong per vertex (light_object), the
 *                        rasterizer interpolates (Ullmann 2003, Sec. 3.5)
 *   fragment stage    <- flat: phong at the centroid with the geometric
 *                        normal (light_face); textured: colour x texel;
 *                        alpha masks (raster_fill.c mask_keeps); normal
 *                        maps per fragment (rl_scene_drawer_finish's
 *                        deferred pass, done where the fragment is made)
 *
 * Depth: the software rasterizer tests and stores eye depth, 1 / (1/w)
 * interpolated in screen space. Here the window depth is K / w (clip z is
 * the constant K = 2^-40 under glClipControl's zero-to-one range), which
 * is 1/w scaled by a power of two: linear in screen space, tested with
 * GL_GREATER, no far plane, and the float depth buffer keeps full relative
 * precision at every distance ("reversed" depth). The eye depth itself is
 * written to a colour attachment for readback. Affine projections, whose
 * w is 1, use (w - z) / 2 instead. The near plane is a clip distance,
 * z >= -w, as the software clips. RL_RASTER_DEPTH_EQUAL (a later pass
 * adding to what an earlier frame drew) compares eye depths, the frame's
 * uploaded one with the fragment's: both are this interpolation's results,
 * bit for bit, where the window depth made anew from an uploaded eye depth
 * would not be. y is negated so that GL's row 0 is the
 * image's top row: no flip on readback, and front faces (counter-clockwise
 * in NDC) are clockwise in the window. */
#include "gl/gl_shaders.h"

#include <stdlib.h>
#include <string.h>

#include "core/error.h"

#define GLSL(...) #__VA_ARGS__ "\n"

static const char *const header = "#version 450 core\n";

/* Declarations and functions of both triangle stages. */
static const char *const common = GLSL(
    const uint NONE = 0xffffffffu;
    struct Material { vec4 diffuse; vec4 specular; vec4 emission; uvec4 tex; };
    struct Light { vec4 pos; vec4 power; vec4 dir; vec4 extra; };
    struct TexInfo { uint offset; int width; int height; int pad; };
    layout(std430, binding = 0) readonly buffer Materials { Material materials[]; };
    layout(std430, binding = 1) readonly buffer Lights { Light lights[]; };
    layout(std430, binding = 2) readonly buffer TexInfos { TexInfo tex_info[]; };
    layout(std430, binding = 3) readonly buffer Texels { vec4 texels[]; };
    layout(std430, binding = 4) readonly buffer TriMaterial { uint tri_material[]; };
    layout(std430, binding = 5) readonly buffer Indices { uint indices[]; };
    layout(std430, binding = 6) readonly buffer Positions { float positions[]; };
    layout(std430, binding = 7) readonly buffer Uvs { float uvs[]; };
    uniform vec3 u_eye;
    uniform float u_ambient;
    uniform int u_num_lights;
    uniform int u_mode;

    bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }
);

/* Quad lights as points (Ullmann 2003, Sec. 3.1; docs/gl.md), the other
 * kinds by rl_gl_glsl_light_delta; then Phong and the texel fetch. */
static const char *const lighting = GLSL(
    bool light_at(Light L, vec3 p, out vec3 E, out vec3 l)
    {
        if (int(L.pos.w) == 3) {
            E = vec3(0.0);
            l = vec3(0.0);
            vec3 to_light = L.pos.xyz - p;
            float d2 = dot(to_light, to_light);
            if (!(d2 > 0.0) || !(L.power.w > 0.0))
                return false;
            l = to_light * (1.0 / sqrt(d2));
            float cos_light = dot(L.dir.xyz, -l);
            E = (L.power.rgb * (L.power.w * max(0.0, cos_light))) * (1.0 / d2);
            return cos_light > 0.0;
        }
        float dist;
        return light_delta(L, p, E, l, dist);
    }

    vec3 phong(Material m, vec3 p, vec3 n)
    {
        vec3 v = normalize(u_eye - p);
        if (dot(n, v) < 0.0)
            n = -n;
        vec3 c = m.emission.rgb + m.diffuse.rgb * u_ambient;
        bool specular = max(max(m.specular.r, m.specular.g), m.specular.b) > 0.0;
        for (int i = 0; i < u_num_lights; ++i) {
            vec3 E, l;
            if (!light_at(lights[i], p, E, l))
                continue;
            float n_dot_l = dot(n, l);
            if (n_dot_l <= 0.0)
                continue;
            vec3 term = m.diffuse.rgb * n_dot_l;
            if (specular) {
                vec3 r = n * (2.0 * n_dot_l) - l;
                float r_dot_v = max(0.0, dot(r, v));
                float s = r_dot_v > 0.0 ? pow(r_dot_v, m.specular.w) : (m.specular.w == 0.0 ? 1.0 : 0.0);
                term += m.specular.rgb * s;
            }
            c += term * E;
        }
        return c;
    }

    vec4 texel_at(TexInfo t, int x, int y)
    {
        return texels[t.offset + uint(clamp(y, 0, t.height - 1) * t.width + clamp(x, 0, t.width - 1))];
    }
);

/* core/texture_sample.h in GLSL: bilinear, repeat, texel centres at
 * half-integers, v up. It reads texels through texel_at(TexInfo, x, y) and
 * the texture records through tex_info[], which each program declares for
 * its own storage (a storage buffer here, a buffer texture in gl-pt). */
const char *const rl_gl_glsl_tex_sample = GLSL(
    vec4 tex_sample(uint tex, vec2 uv)
    {
        TexInfo t = tex_info[tex];
        float u = isnan(uv.x) || isinf(uv.x) ? 0.0 : uv.x - floor(uv.x);
        float v = isnan(uv.y) || isinf(uv.y) ? 0.0 : uv.y - floor(uv.y);
        float fx = u * float(t.width) - 0.5;
        float fy = (1.0 - v) * float(t.height) - 0.5;
        float x0f = floor(fx), y0f = floor(fy);
        float tx = fx - x0f, ty = fy - y0f;
        int x0 = int(x0f), y0 = int(y0f);
        int x1 = x0 + 1, y1 = y0 + 1;
        x0 += x0 < 0 ? t.width : 0;
        y0 += y0 < 0 ? t.height : 0;
        x1 -= x1 >= t.width ? t.width : 0;
        y1 -= y1 >= t.height ? t.height : 0;
        return (1.0 - tx) * (1.0 - ty) * texel_at(t, x0, y0) + tx * (1.0 - ty) * texel_at(t, x1, y0) +
               (1.0 - tx) * ty * texel_at(t, x0, y1) + tx * ty * texel_at(t, x1, y1);
    }
);

/* The drawer's and gl-pt's light records agree on the three delta kinds,
 * numbered as rl_light_type: pos.w the kind, dir.xyz the spot axis or the
 * directional light's l, dir.w the spot's cos outer, extra.x its cos
 * inner, extra.y whether a directional light is valid. */
_Static_assert((int)RL_GL_LIGHT_POINT == (int)RL_LIGHT_POINT && (int)RL_GL_LIGHT_SPOT == (int)RL_LIGHT_SPOT &&
                   (int)RL_GL_LIGHT_DIRECTIONAL == (int)RL_LIGHT_DIRECTIONAL &&
                   (int)RL_GL_LIGHT_QUAD == (int)RL_LIGHT_QUAD && RL_LIGHT_SPOT == 1 && RL_LIGHT_DIRECTIONAL == 2,
               "rl_gl_glsl_light_delta numbers the kinds as rl_light_type");

/* scene/light_eval.c rl_light_eval_delta in GLSL: a point, spot or
 * directional light's irradiance E at p and direction l towards it, dist
 * its distance (infinite for a directional light); false where it gives
 * none. For programs that declare struct Light as rl_gl_light. */
const char *const rl_gl_glsl_light_delta = GLSL(
    bool light_delta(Light L, vec3 p, out vec3 E, out vec3 l, out float dist)
    {
        int kind = int(L.pos.w);
        E = vec3(0.0);
        l = vec3(0.0);
        dist = uintBitsToFloat(0x7f800000u);
        if (kind == 2) {
            l = L.dir.xyz;
            E = L.power.rgb;
            return L.extra.y > 0.0;
        }
        vec3 to_light = L.pos.xyz - p;
        float d2 = dot(to_light, to_light);
        if (!(d2 > 0.0))
            return false;
        dist = sqrt(d2);
        l = to_light * (1.0 / dist);
        float falloff = 1.0 / d2;
        if (kind == 1) {
            float cos_axis = dot(-l, L.dir.xyz);
            float cos_outer = L.dir.w, cos_inner = L.extra.x;
            falloff *= cos_inner > cos_outer ? smoothstep(cos_outer, cos_inner, cos_axis)
                                             : (cos_axis >= cos_outer ? 1.0 : 0.0);
        }
        E = L.power.rgb * falloff;
        return falloff > 0.0;
    }
);

static const char *const triangle_vs = GLSL(
    layout(location = 0) in vec3 a_pos;
    layout(location = 1) in vec3 a_normal;
    layout(location = 2) in vec2 a_uv;
    layout(location = 3) in uint a_material;
    uniform mat4 u_view_proj;
    uniform vec4 u_view_z;
    uniform bool u_affine;
    uniform float u_depth_k;
    out vec4 v_color;
    out vec3 v_pos;
    out vec3 v_normal;
    out vec2 v_uv;
    out float v_depth;
    invariant gl_Position;
    out float gl_ClipDistance[1];

    void main()
    {
        vec4 c = u_view_proj * vec4(a_pos, 1.0);
        gl_ClipDistance[0] = c.z + c.w;
        if (u_affine) {
            gl_Position = vec4(c.x, -c.y, 0.5 * (c.w - c.z), c.w);
            v_depth = -(dot(u_view_z.xyz, a_pos) + u_view_z.w);
        } else {
            gl_Position = vec4(c.x, -c.y, u_depth_k, c.w);
            v_depth = c.w;
        }
        v_pos = a_pos;
        v_normal = a_normal;
        v_uv = a_uv;
        v_color = vec4(0.0, 0.0, 0.0, 1.0);
        if (u_mode >= 2 && a_material != NONE)
            v_color = vec4(phong(materials[a_material], a_pos, a_normal), 1.0);
    }
);

static const char *const triangle_fs = GLSL(
    in vec4 v_color;
    in vec3 v_pos;
    in vec3 v_normal;
    in vec2 v_uv;
    in float v_depth;
    uniform uint u_object;
    uniform uint u_first_triangle;
    uniform bool u_normal_maps;
    uniform bool u_depth_equal;
    layout(binding = 0) uniform sampler2D u_depth_in;
    layout(location = 0) out vec4 o_color;
    layout(location = 1) out float o_depth;
    layout(location = 2) out uint o_object;
    layout(location = 3) out uint o_triangle;

    vec3 position(uint v) { return vec3(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]); }
    vec2 uv_of(uint v) { return vec2(uvs[2u * v], uvs[2u * v + 1u]); }

    vec3 shading_normal(uint tri, Material m, vec3 ns, vec2 uv)
    {
        vec3 n = normalize(ns);
        if (!finite3(n))
            return ns;
        uint i0 = indices[3u * tri], i1 = indices[3u * tri + 1u], i2 = indices[3u * tri + 2u];
        vec3 e1 = position(i1) - position(i0), e2 = position(i2) - position(i0);
        vec2 t0 = uv_of(i0), t1 = uv_of(i1), t2 = uv_of(i2);
        float du1 = t1.x - t0.x, dv1 = t1.y - t0.y, du2 = t2.x - t0.x, dv2 = t2.y - t0.y;
        float det = du1 * dv2 - du2 * dv1;
        if (!(abs(det) > 1e-20))
            return n;
        float inv = 1.0 / det;
        vec3 T = (e1 * dv2 - e2 * dv1) * inv;
        vec3 B = (e2 * du1 - e1 * du2) * inv;
        T = T - n * dot(n, T);
        if (!(dot(T, T) > 0.0) || !finite3(T))
            return n;
        T = normalize(T);
        vec3 Bo = cross(n, T);
        if (dot(Bo, B) < 0.0)
            Bo = -Bo;
        vec4 texel = tex_sample(m.tex.y, uv);
        float x = (2.0 * texel.x - 1.0) * m.emission.w, y = (2.0 * texel.y - 1.0) * m.emission.w;
        float z = 2.0 * texel.z - 1.0;
        vec3 bent = T * x + Bo * y + n * z;
        return dot(bent, bent) > 0.0 && finite3(bent) ? normalize(bent) : n;
    }

    void main()
    {
        uint tri = u_first_triangle + uint(gl_PrimitiveID);
        o_depth = v_depth;
        o_object = u_object;
        o_triangle = tri;
        o_color = v_color;
        if (u_depth_equal && v_depth != texelFetch(u_depth_in, ivec2(gl_FragCoord.xy), 0).r)
            discard;
        if (u_mode < 0)
            return;
        Material m = materials[tri_material[tri]];
        if (m.tex.z != NONE && tex_sample(m.tex.z, v_uv).w < uintBitsToFloat(m.tex.w))
            discard;
        if (u_mode == 1) {
            uint i0 = indices[3u * tri], i1 = indices[3u * tri + 1u], i2 = indices[3u * tri + 2u];
            vec3 p0 = position(i0), p1 = position(i1), p2 = position(i2);
            vec3 middle = (p0 + p1 + p2) * (1.0 / 3.0);
            o_color = vec4(phong(m, middle, normalize(cross(p1 - p0, p2 - p0))), 1.0);
        } else if (u_mode >= 2) {
            if (u_normal_maps && m.tex.y != NONE) {
                vec3 ns = v_normal;
                if (dot(ns, u_eye - v_pos) < 0.0)
                    ns = -ns;
                o_color = vec4(phong(m, v_pos, normalize(shading_normal(tri, m, normalize(ns), v_uv))), 1.0);
            }
            if (u_mode == 3 && m.tex.x != NONE)
                o_color *= tex_sample(m.tex.x, v_uv);
        }
    }
);

/* Points: square splats of a size in pixels (raster_points.c), depth and
 * colour constant over the square, the point index in the triangle-ID
 * layer. */
static const char *const points_vs = GLSL(
    layout(location = 0) in vec3 a_pos;
    layout(location = 1) in vec4 a_color;
    layout(location = 2) in float a_size;
    layout(location = 3) in uint a_object;
    uniform mat4 u_view_proj;
    uniform vec4 u_view_z;
    uniform bool u_affine;
    uniform float u_depth_k;
    flat out vec4 v_color;
    flat out float v_depth;
    flat out uint v_object;
    flat out uint v_point;
    invariant gl_Position;
    out float gl_ClipDistance[1];

    void main()
    {
        vec4 c = u_view_proj * vec4(a_pos, 1.0);
        bool keep = a_size > 0.0 && !isinf(a_size) && c.w > 0.0;
        gl_ClipDistance[0] = keep ? c.z + c.w : -1.0;
        if (u_affine) {
            gl_Position = vec4(c.x, -c.y, 0.5 * (c.w - c.z), c.w);
            v_depth = -(dot(u_view_z.xyz, a_pos) + u_view_z.w);
        } else {
            gl_Position = vec4(c.x, -c.y, u_depth_k, c.w);
            v_depth = c.w;
        }
        gl_PointSize = keep ? a_size : 1.0;
        v_color = a_color;
        v_object = a_object;
        v_point = uint(gl_VertexID);
    }
);

static const char *const points_fs = GLSL(
    flat in vec4 v_color;
    flat in float v_depth;
    flat in uint v_object;
    flat in uint v_point;
    layout(location = 0) out vec4 o_color;
    layout(location = 1) out float o_depth;
    layout(location = 2) out uint o_object;
    layout(location = 3) out uint o_triangle;

    void main()
    {
        o_color = v_color;
        o_depth = v_depth;
        o_object = v_object;
        o_triangle = v_point;
    }
);

/* Caller-made triangle batches (rl_drawer_draw_batch), for Ullmann 2003,
 * Sec. 3.5: Vertex Tracing's refined mesh drawn with Gouraud shading and
 * its deferred textures by multitexturing (raster_fill.c gather_layers /
 * shade_layers): the fragment is the sum over the layers of the
 * interpolated colour times the texel at the interpolated uv (the colour
 * alone where the face has no texture in that layer), alpha layer 0's;
 * with no layers the interpolated per-vertex colour (Gouraud). Corners
 * come unshared, each with its face's textures and IDs as flat
 * attributes; the clip coordinates are the triangle program's, so that
 * RL_RASTER_DEPTH_EQUAL passes (eq. 3.22's multipass) meet the depth of
 * the pass before them with GL_EQUAL, bit for bit. */
static const char *const batch_vs = GLSL(
    layout(location = 0) in vec3 a_pos;
    layout(location = 1) in uvec4 a_tex;
    layout(location = 2) in uvec2 a_ids;
    layout(location = 3) in vec4 a_col0;
    layout(location = 4) in vec4 a_col1;
    layout(location = 5) in vec4 a_col2;
    layout(location = 6) in vec4 a_col3;
    layout(location = 7) in vec4 a_uv01;
    layout(location = 8) in vec4 a_uv23;
    uniform mat4 u_view_proj;
    uniform vec4 u_view_z;
    uniform bool u_affine;
    uniform float u_depth_k;
    flat out uvec4 v_tex;
    flat out uvec2 v_ids;
    out vec4 v_col[4];
    out vec4 v_uv01;
    out vec4 v_uv23;
    out float v_depth;
    invariant gl_Position;
    out float gl_ClipDistance[1];

    void main()
    {
        vec4 c = u_view_proj * vec4(a_pos, 1.0);
        gl_ClipDistance[0] = c.z + c.w;
        if (u_affine) {
            gl_Position = vec4(c.x, -c.y, 0.5 * (c.w - c.z), c.w);
            v_depth = -(dot(u_view_z.xyz, a_pos) + u_view_z.w);
        } else {
            gl_Position = vec4(c.x, -c.y, u_depth_k, c.w);
            v_depth = c.w;
        }
        v_tex = a_tex;
        v_ids = a_ids;
        v_col[0] = a_col0;
        v_col[1] = a_col1;
        v_col[2] = a_col2;
        v_col[3] = a_col3;
        v_uv01 = a_uv01;
        v_uv23 = a_uv23;
    }
);

static const char *const batch_fs = GLSL(
    flat in uvec4 v_tex;
    flat in uvec2 v_ids;
    in vec4 v_col[4];
    in vec4 v_uv01;
    in vec4 v_uv23;
    in float v_depth;
    uniform int u_num_layers;
    layout(location = 0) out vec4 o_color;
    layout(location = 1) out float o_depth;
    layout(location = 2) out uint o_object;
    layout(location = 3) out uint o_triangle;

    void main()
    {
        o_depth = v_depth;
        o_triangle = v_ids.x;
        o_object = v_ids.y;
        if (u_num_layers == 0) {
            o_color = v_col[0];
            return;
        }
        vec2 uv[4] = vec2[4](v_uv01.xy, v_uv01.zw, v_uv23.xy, v_uv23.zw);
        vec4 sum = vec4(0.0, 0.0, 0.0, v_col[0].w);
        for (int l = 0; l < u_num_layers; ++l) {
            vec3 c = v_col[l].rgb;
            if (v_tex[l] != NONE)
                c *= tex_sample(v_tex[l], uv[l]).rgb;
            sum.rgb += c;
        }
        o_color = sum;
    }
);

/* A frame starts from the target as it is (rl_drawer.h): its eye depth is
 * copied to the depth attachment and turned into window depth, the
 * inverse of what the vertex stage computes. */
static const char *const upload_vs = GLSL(
    out float gl_ClipDistance[1];

    void main()
    {
        vec2 corner = vec2(float((gl_VertexID & 1) << 2) - 1.0, float((gl_VertexID & 2) << 1) - 1.0);
        gl_Position = vec4(corner, 0.0, 1.0);
        gl_ClipDistance[0] = 1.0;       /* the frame enables the near plane's clip distance */
    }
);

static const char *const upload_fs = GLSL(
    layout(binding = 0) uniform sampler2D u_depth_in;
    uniform bool u_affine;
    uniform float u_depth_k;
    uniform vec2 u_affine_z;
    layout(location = 1) out float o_depth;

    void main()
    {
        float d = texelFetch(u_depth_in, ivec2(gl_FragCoord.xy), 0).r;
        float z;
        if (isnan(d))
            z = 1.0;
        else if (u_affine)
            z = 0.5 * (1.0 - (-u_affine_z.x * d + u_affine_z.y));
        else
            z = d > 0.0 ? u_depth_k / d : 1.0;
        o_depth = d;
        gl_FragDepth = isnan(z) ? 1.0 : clamp(z, 0.0, 1.0);
    }
);

GLuint rl_gl_make_buffer(const void *data, size_t bytes, GLbitfield flags)
{
    GLuint b = 0;
    glCreateBuffers(1, &b);
    if (bytes >= 16) {
        glNamedBufferStorage(b, (GLsizeiptr)bytes, data, flags);
    } else {
        uint8_t pad[16] = { 0 };
        if (data && bytes)
            memcpy(pad, data, bytes);
        glNamedBufferStorage(b, 16, pad, flags);
    }
    return b;
}

rl_status rl_gl_upload_textures(const rl_scene_data *d, GLint64 max_block, const char *who, GLuint *tex_info,
                                GLuint *texels)
{
    rl_gl_tex_info *info = rl_calloc(d->num_textures ? d->num_textures : 1, sizeof *info);
    if (!info)
        return RL_ERR_OUT_OF_MEMORY;
    uint64_t total = 0;
    for (uint32_t t = 0; t < d->num_textures; ++t) {
        const rl_texture *tex = d->textures[t];
        info[t].offset = (uint32_t)total;
        info[t].width = tex ? tex->width : 1;
        info[t].height = tex ? tex->height : 1;
        total += tex ? (uint64_t)tex->width * (uint64_t)tex->height : 0;
    }
    if (total * sizeof(rl_vec4) > (uint64_t)max_block || total > UINT32_MAX) {
        free(info);
        return rl_error(RL_ERR_LIMIT, "%s: the scene's textures (%llu texels, %llu MiB) exceed this GL's shader "
                        "storage block size (%lld MiB) or 2^32 texels", who, (unsigned long long)total,
                        (unsigned long long)(total * sizeof(rl_vec4) >> 20), (long long)(max_block >> 20));
    }
    *tex_info = rl_gl_make_buffer(info, sizeof *info * d->num_textures, 0);
    *texels = rl_gl_make_buffer(NULL, total * sizeof(rl_vec4), GL_DYNAMIC_STORAGE_BIT);
    for (uint32_t t = 0; t < d->num_textures; ++t) {
        const rl_texture *tex = d->textures[t];
        if (tex && tex->width > 0 && tex->height > 0)
            glNamedBufferSubData(*texels, (GLintptr)info[t].offset * (GLintptr)sizeof(rl_vec4),
                                 (GLsizeiptr)tex->width * tex->height * (GLsizeiptr)sizeof(rl_vec4), tex->texels);
    }
    free(info);
    return RL_OK;
}

rl_status rl_gl_check(const char *where)
{
    GLenum e = glGetError(), first = e;
    while (e != GL_NO_ERROR)
        e = glGetError();
    if (first == GL_NO_ERROR)
        return RL_OK;
    return rl_error(first == GL_OUT_OF_MEMORY ? RL_ERR_OUT_OF_MEMORY : RL_ERR_INTERNAL, "gl: GL error 0x%x in %s",
                    (unsigned)first, where);
}

GLuint rl_gl_compile(GLenum stage, const char *const *parts, int count, const char *what)
{
    GLuint s = glCreateShader(stage);
    glShaderSource(s, count, parts, NULL);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetShaderInfoLog(s, sizeof log, NULL, log);
        rl_error(RL_ERR_INTERNAL, "gl: the %s shader does not compile: %s", what, log);
        glDeleteShader(s);
        return 0;
    }
    return s;
}

GLuint rl_gl_link(GLuint a, GLuint b, const char *what)
{
    if (!a) {
        glDeleteShader(b);
        return 0;
    }
    GLuint p = glCreateProgram();
    glAttachShader(p, a);
    if (b)
        glAttachShader(p, b);
    glLinkProgram(p);
    glDeleteShader(a);
    glDeleteShader(b);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[512] = "";
        glGetProgramInfoLog(p, sizeof log, NULL, log);
        rl_error(RL_ERR_INTERNAL, "gl: the %s program does not link: %s", what, log);
        glDeleteProgram(p);
        return 0;
    }
    return p;
}

static GLuint link(const char *const *vs, int nvs, const char *const *fs, int nfs, const char *what)
{
    GLuint v = rl_gl_compile(GL_VERTEX_SHADER, vs, nvs, what);
    GLuint f = v ? rl_gl_compile(GL_FRAGMENT_SHADER, fs, nfs, what) : 0;
    if (!f) {
        glDeleteShader(v);
        return 0;
    }
    return rl_gl_link(v, f, what);
}

GLuint rl_gl_program_triangles(void)
{
    const char *const vs[] = { header, common, rl_gl_glsl_light_delta, lighting, rl_gl_glsl_tex_sample, triangle_vs };
    const char *const fs[] = { header, common, rl_gl_glsl_light_delta, lighting, rl_gl_glsl_tex_sample, triangle_fs };
    return link(vs, 6, fs, 6, "triangle");
}

GLuint rl_gl_program_points(void)
{
    const char *const vs[] = { header, points_vs };
    const char *const fs[] = { header, points_fs };
    return link(vs, 2, fs, 2, "point");
}

GLuint rl_gl_program_depth_upload(void)
{
    const char *const vs[] = { header, upload_vs };
    const char *const fs[] = { header, upload_fs };
    return link(vs, 2, fs, 2, "depth upload");
}

GLuint rl_gl_program_batch(void)
{
    const char *const vs[] = { header, batch_vs };
    const char *const fs[] = { header, common, rl_gl_glsl_light_delta, lighting, rl_gl_glsl_tex_sample, batch_fs };
    return link(vs, 2, fs, 6, "batch");
}
