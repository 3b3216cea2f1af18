/* gl_pt_shaders.c: the GLSL 4.50 compute shaders of gl-pt (gl_pt.h), the
 * path tracer "pt" (src/render/pathtrace*.c) on the GPU as Schröder 2017
 * runs it (Ch. 5, 6). Each function mirrors the C function of pt named
 * beside it, step for step, so that both compute the same estimator with
 * the same sample numbers; docs/gl.md ("gl-pt") lists what is not ported.
 *
 *   scene buffers     materials, lights, textures, triangles (bindings 0-9)
 *   hash64, sobol     pathtrace_sampler.c: Owen-scrambled Sobol points; the
 *                     64-bit hash in pairs of 32-bit words (GLSL 4.50 core
 *                     has no 64-bit integers)
 *   rng_next          core/rng_gpu.c: LCG, Tausworthe, hybrid (Sec. 5.3),
 *                     the state in an rgba32ui image (the state texture)
 *   wt_hit            accel/watertight.h (Woop, Benthin, Wald 2013)
 *   bvh_query         the binary BVH of accel/bvh_build.c, flattened to
 *                     SSBOs: stack-based, near child first (Sec. 5.4 names
 *                     the BVH as the exact alternative of the thesis)
 *   grid_query        accel/grid.c: a 3-D DDA (Amanatides & Woo 1987) over
 *                     the cells' offsets and triangle lists (Sec. 5.4)
 *   surface_*, phong_ pathtrace_path.c, pathtrace_bsdf.c
 *   ggx_*, brdf_*     pathtrace_ggx.c: GGX with visible-normal sampling and
 *                     the energy compensation from pt's tables (issue 37)
 *   shadow_setup      pathtrace_path.c visible(): a shadow ray for ray_query
 *   ray_query         the one traversal call of the path program (any-hit
 *                     or closest-hit through any structure)
 *   env_*             scene/environment.c (lookup) and pathtrace_env.c
 *                     (sampling by pt's own CDFs, density) and escaped of
 *                     pathtrace_path.c (issue 37)
 *   fresnel_schlick   scene/material.c rl_fresnel_schlick, and the specular
 *                     event of pathtrace_ggx.c rl_pt_specular_event (issue 37)
 *   trace_path        rl_pt_trace_path (Sec. 6.4): one ray per iteration of
 *                     one loop, the camera ray, the shadow rays of Shade
 *                     (Sec. 6.4.2, 6.3: pathtrace_path.c direct_light,
 *                     direct_light_mis, environment_light; the light-vertex
 *                     joins of Sec. 8.4) and the bounces, one ray_query()
 *   main (path)       one sample of every pixel: jittered camera ray
 *                     through the BVH (primary=trace), the path, eq. 8 of
 *                     Sec. 6.5 into the rgba32f accumulation image
 *   main (rays)       a fixed ray set through one structure, for the tests
 *                     that compare it with the CPU's ray for ray */
#include "gl/gl_pt.h"

#ifdef RL_HAVE_GL

#define GLSL(...) #__VA_ARGS__ "\n"

const char *const rl_gl_pt_glsl_header = "#version 450 core\n";

const char *const rl_gl_pt_glsl_common = GLSL(
    const uint NONE = 0xffffffffu;
    const float PI = 3.14159265358979323846;

    /* pbr: GGX's roughness, metallic, and 1 for bsdf = ggx (issue 37) */
    struct Material { vec4 diffuse; vec4 specular; vec4 emission; vec4 extra; uvec4 tex; vec4 pbr; };
    struct Light { vec4 pos; vec4 power; vec4 dir; vec4 extra; };
    struct TexInfo { uint offset; int width; int height; int pad; };
    struct Node { vec4 lo; vec4 hi; };
    struct Hit { float t; float u; float v; uint tri; };

    /* ggx_e: GGX's energy-compensation tables as pt builds them
     * (pathtrace_ggx.c ms_build): E [roughness node][mu node], then E_avg
     * per roughness node; zeros in scenes without GGX */
    layout(std430, binding = 0) readonly buffer Materials {
        float ggx_e[GGX_NODES * GGX_NODES + GGX_NODES];
        Material materials[];
    };
    layout(std430, binding = 1) readonly buffer Lights { Light lights[]; };
    layout(std430, binding = 2) readonly buffer TexInfos { TexInfo tex_info[]; };
    /* Read-only arrays as buffer textures (texture units 0-3; the path
     * program's 4-5): a compute shader may use only 16 storage blocks
     * (llvmpipe's GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS), and the Line
     * Space's walk needs 8 of them. */
    layout(binding = 0) uniform samplerBuffer u_positions;   /* r32f */
    layout(binding = 1) uniform samplerBuffer u_normals;     /* r32f */
    layout(binding = 2) uniform samplerBuffer u_uvs;         /* r32f */
    layout(binding = 3) uniform samplerBuffer u_texels;      /* rgba32f */
    layout(std430, binding = 4) readonly buffer Triangles { uvec4 triangles[]; };
    layout(std430, binding = 8) readonly buffer BvhNodes { Node nodes[]; };
    layout(std430, binding = 9) readonly buffer BvhTris { vec4 bvh_tris[]; };
    layout(std430, binding = 10) readonly buffer CellStart { uint cell_start[]; };
    layout(std430, binding = 11) readonly buffer CellTris { uint cell_tris[]; };

    uniform uint u_num_nodes;
    uniform bool u_masks;
    uniform vec3 u_grid_min;
    uniform vec3 u_grid_cell;
    uniform vec3 u_grid_inv_cell;
    uniform ivec3 u_grid_res;

    bool finite3(vec3 v) { return !any(isnan(v)) && !any(isinf(v)); }
    float max_comp(vec3 v) { return max(max(v.x, v.y), v.z); }
    float fetch1(samplerBuffer b, uint i) { return texelFetch(b, int(i)).x; }
    vec3 position(uint i) { return vec3(fetch1(u_positions, 3u * i), fetch1(u_positions, 3u * i + 1u),
                                        fetch1(u_positions, 3u * i + 2u)); }
    vec3 normal_at(uint i) { return vec3(fetch1(u_normals, 3u * i), fetch1(u_normals, 3u * i + 1u),
                                         fetch1(u_normals, 3u * i + 2u)); }
    vec2 uv_at(uint i) { return vec2(fetch1(u_uvs, 2u * i), fetch1(u_uvs, 2u * i + 1u)); }

    /* The texels of tex_sample (rl_gl_glsl_tex_sample, core/texture_sample.h). */
    vec4 texel_at(TexInfo t, int x, int y)
    {
        return texelFetch(u_texels, int(t.offset + uint(clamp(y, 0, t.height - 1) * t.width + clamp(x, 0, t.width - 1))));
    }
);

/* After rl_gl_glsl_tex_sample (gl_shaders.c), which the program puts between
 * the two parts of common. */
const char *const rl_gl_pt_glsl_common2 = GLSL(
    vec2 interp_uv(uint tri, float u, float v)
    {
        uvec4 T = triangles[tri];
        float w = 1.0 - u - v;
        vec2 t0 = uv_at(T.x), t1 = uv_at(T.y), t2 = uv_at(T.z);
        return vec2(w * t0.x + u * t1.x + v * t2.x, w * t0.y + u * t1.y + v * t2.y);
    }

    /* scene/material.c rl_alpha_masked: a hit in a mask's hole is no hit
     * (the CPU asks again beyond it; skipping it in the loop is the same). */
    bool masked(uint tri, float u, float v)
    {
        if (!u_masks)
            return false;
        Material m = materials[triangles[tri].w];
        if (m.tex.z == NONE)
            return false;
        return tex_sample(m.tex.z, interp_uv(tri, u, v)).w < m.extra.z;
    }

    /* accel/watertight.c: the axis permutation and shear of a ray. The
     * permutation is a matrix of unit rows (kx, ky, kz): a product with it
     * picks the components exactly, where indexing a vector by a varying
     * component costs a scalar access per thread on SIMD hardware. */
    struct WRay { mat3 perm; vec3 s; vec3 o; };

    WRay wt_setup(vec3 o, vec3 d)
    {
        vec3 a = abs(d);
        int kz = a.x > a.y ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
        int kx = kz == 2 ? 0 : kz + 1;
        int ky = kx == 2 ? 0 : kx + 1;
        float dz = kz == 0 ? d.x : (kz == 1 ? d.y : d.z);
        if (dz < 0.0) {
            int s = kx;
            kx = ky;
            ky = s;
        }
        vec3 ex = vec3(equal(ivec3(kx), ivec3(0, 1, 2)));
        vec3 ey = vec3(equal(ivec3(ky), ivec3(0, 1, 2)));
        vec3 ez = vec3(equal(ivec3(kz), ivec3(0, 1, 2)));
        WRay w;
        w.perm = transpose(mat3(ex, ey, ez));
        w.s = vec3(dot(d, ex) / dz, dot(d, ey) / dz, 1.0 / dz);
        w.o = o;
        return w;
    }

    /* accel/watertight.h rl_watertight_hit_k, operation for operation
     * (A = (p0 - o) permuted is its (p0[kx] - ox, p0[ky] - oy, p0[kz] - oz));
     * the exact fallback in double as there. */
    bool wt_hit(WRay w, vec3 p0, vec3 p1, vec3 p2, float t_min, float t_max, out float t, out float u, out float v)
    {
        t = 0.0;
        u = 0.0;
        v = 0.0;
        precise vec3 A = w.perm * (p0 - w.o), B = w.perm * (p1 - w.o), C = w.perm * (p2 - w.o);
        float Az = A.z, Bz = B.z, Cz = C.z;
        precise float Ax = A.x - w.s.x * Az, Ay = A.y - w.s.y * Az;
        precise float Bx = B.x - w.s.x * Bz, By = B.y - w.s.y * Bz;
        precise float Cx = C.x - w.s.x * Cz, Cy = C.y - w.s.y * Cz;
        precise float U = Cx * By - Cy * Bx;
        precise float V = Ax * Cy - Ay * Cx;
        precise float W = Bx * Ay - By * Ax;
        if (U == 0.0 || V == 0.0 || W == 0.0) {
            U = float(double(Cx) * double(By) - double(Cy) * double(Bx));
            V = float(double(Ax) * double(Cy) - double(Ay) * double(Cx));
            W = float(double(Bx) * double(Ay) - double(By) * double(Ax));
        }
        if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0))
            return false;
        float det = U + V + W;
        if (det == 0.0)
            return false;
        Az *= w.s.z;
        Bz *= w.s.z;
        Cz *= w.s.z;
        float T = U * Az + V * Bz + W * Cz;
        float det_abs = abs(det), T_abs = det < 0.0 ? -T : T;
        if (t_min >= 0.0 && T_abs <= 0.0)
            return false;
        float bound = t_max * det_abs * (1.0 + 1.52587890625e-05);
        if (bound > 7.888609052210118e-31 && T_abs > bound)
            return false;
        float th = T / det;
        if (!(th > t_min && th < t_max))
            return false;
        t = th;
        u = V / det;
        v = W / det;
        return true;
    }

    /* Slab test of a node's box against [t_min, t_max]. */
    bool box_hit(vec3 lo, vec3 hi, vec3 o, vec3 inv, float t_min, float t_max)
    {
        vec3 a = (lo - o) * inv, b = (hi - o) * inv;
        vec3 n = min(a, b), f = max(a, b);
        float tn = max(max(n.x, n.y), max(n.z, t_min));
        float tf = min(min(f.x, f.y), min(f.z, t_max));
        return tn <= tf;
    }

    /* The binary BVH (accel/bvh.h rl_bvh_node: the two children of an inner
     * node adjacent, count and split axis in the last word), its leaves'
     * triangles in leaf order (3 vec4 each, the scene ID in the first w).
     * Closest hit into h (t_max shrinks), or with any_hit the first hit. */
    bool bvh_query(vec3 o, vec3 d, float t_min, float t_max, bool any_hit, out Hit h)
    {
        h = Hit(t_max, 0.0, 0.0, NONE);
        if (u_num_nodes == 0u)
            return false;
        WRay w = wt_setup(o, d);
        vec3 inv = 1.0 / d;
        uint stack[BVH_STACK];
        int sp = 0;
        uint node = 0u;
        while (true) {
            Node n = nodes[node];
            bool descend = false;
            if (box_hit(n.lo.xyz, n.hi.xyz, o, inv, t_min, h.t)) {
                uint bits = floatBitsToUint(n.hi.w), index = floatBitsToUint(n.lo.w);
                uint count = bits & 0xffffu;
                if (count > 0u) {
                    for (uint k = index; k < index + count; ++k) {
                        vec4 a = bvh_tris[3u * k], b = bvh_tris[3u * k + 1u], c = bvh_tris[3u * k + 2u];
                        float t, u, v;
                        if (!wt_hit(w, a.xyz, b.xyz, c.xyz, t_min, h.t, t, u, v))
                            continue;
                        uint tri = floatBitsToUint(a.w);
                        if (masked(tri, u, v))
                            continue;
                        h = Hit(t, u, v, tri);
                        if (any_hit)
                            return true;
                    }
                } else {
                    uint axis = bits >> 16;
                    bool flip = (axis == 0u ? d.x : (axis == 1u ? d.y : d.z)) < 0.0;
                    stack[sp++] = flip ? index : index + 1u;
                    node = flip ? index + 1u : index;
                    descend = true;
                }
            }
            if (!descend) {
                if (sp == 0)
                    break;
                node = stack[--sp];
            }
        }
        return h.tri != NONE;
    }

    /* The uniform grid (accel/grid.h): the cells along the ray front to
     * back, each cell's triangles by their scene vertices. The closest hit
     * is final once it lies inside the cell just tested: every nearer
     * triangle is listed in a cell walked before. */
    bool grid_query(vec3 o, vec3 d, float t_min, float t_max, bool any_hit, out Hit h)
    {
        h = Hit(t_max, 0.0, 0.0, NONE);
        vec3 inv = 1.0 / d;
        vec3 gmax = u_grid_min + vec3(u_grid_res) * u_grid_cell;
        vec3 a = (u_grid_min - o) * inv, b = (gmax - o) * inv;
        vec3 n = min(a, b), f = max(a, b);
        float t_enter = max(max(n.x, n.y), max(n.z, t_min));
        /* widened as rl_grid_dda_begin: a ray grazing the bounds is walked */
        float t_exit = min(min(f.x, f.y), min(f.z, t_max));
        t_exit += abs(t_exit) * 1e-6;
        if (!(t_enter <= t_exit))
            return false;
        ivec3 cell = clamp(ivec3(floor((o + d * t_enter - u_grid_min) * u_grid_inv_cell)), ivec3(0), u_grid_res - 1);
        ivec3 step = ivec3(sign(d));
        /* per axis the parameter where the walk crosses the next boundary
         * (recomputed from the plane, as grid.c) */
        vec3 up = vec3(greaterThan(step, ivec3(0)));
        vec3 next = (u_grid_min + (vec3(cell) + up) * u_grid_cell - o) * inv;
        next = mix(next, vec3(INF), equal(step, ivec3(0)));
        WRay w = wt_setup(o, d);
        while (true) {
            uint c = uint(cell.x) + uint(u_grid_res.x) * (uint(cell.y) + uint(u_grid_res.y) * uint(cell.z));
            for (uint k = cell_start[c]; k < cell_start[c + 1u]; ++k) {
                uint tri = cell_tris[k];
                uvec4 T = triangles[tri];
                float t, u, v;
                if (!wt_hit(w, position(T.x), position(T.y), position(T.z), t_min, h.t, t, u, v))
                    continue;
                if (masked(tri, u, v))
                    continue;
                h = Hit(t, u, v, tri);
                if (any_hit)
                    return true;
            }
            float cell_exit = min(next.x, min(next.y, next.z));
            if (h.tri != NONE && h.t <= cell_exit)
                break;
            if (cell_exit > t_exit)
                break;
            /* the axis crossed first: the lowest of x, y, z on a tie */
            bvec3 m = equal(next, vec3(cell_exit));
            m = bvec3(m.x, m.y && !m.x, m.z && !m.x && !m.y);
            cell += ivec3(m) * step;
            if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, u_grid_res)))
                break;
            vec3 crossed = (u_grid_min + (vec3(cell) + up) * u_grid_cell - o) * inv;
            next = mix(next, crossed, m);
        }
        return h.tri != NONE;
    }

    /* Whether the program holds structure k's traversal (gl_pt.c: the
     * path program's variant has those of its frame's structures only,
     * the other programs all): a test of a constant, which the compiler
     * folds, so the walks of the others are not in the program. The BVH
     * is always in (the camera rays take it). */
    bool may_use(int k) { return (STRUCTS & (1u << uint(k))) != 0u; }

    bool query(int structure, vec3 o, vec3 d, float t_min, float t_max, bool any_hit, out Hit h)
    {
        if (may_use(STRUCT_GRID) && structure == STRUCT_GRID)
            return grid_query(o, d, t_min, t_max, any_hit, h);
        return bvh_query(o, d, t_min, t_max, any_hit, h);
    }
);

/* The path tracer: one sample of every pixel per dispatch. */
const char *const rl_gl_pt_glsl_path = GLSL(
    layout(local_size_x = LOCAL_SIZE, local_size_y = LOCAL_SIZE) in;
    layout(rgba32f, binding = 0) uniform image2D u_accum;
    layout(rgba32ui, binding = 1) uniform uimage2D u_rng_state;
    layout(binding = 4) uniform usamplerBuffer u_light_table;  /* rg32ui: cdf bits, source */
    layout(binding = 5) uniform usamplerBuffer u_tri_light;    /* rg32ui: cover, pmf bits */
    float table_cdf(uint k) { return uintBitsToFloat(texelFetch(u_light_table, int(k)).x); }
    uint table_source(uint k) { return texelFetch(u_light_table, int(k)).y; }
    uint tri_cover(uint t) { return texelFetch(u_tri_light, int(t)).x; }
    float tri_pmf(uint t) { return uintBitsToFloat(texelFetch(u_tri_light, int(t)).y); }
    /* The cube shadow maps (rl_gl_pt_set_shadowmaps): per light six faces of
     * u_sm_size^2 eye depths, row 0 the top row, as rl_shadowmap's. Always
     * bound (an empty buffer without maps), so that a compiler that
     * specializes on the bound textures makes one variant. */
    layout(binding = 7) uniform samplerBuffer u_shadow_maps;  /* r32f */
    uniform int u_sm_size;
    uniform float u_sm_bias;
    uniform float u_sm_slope;
    uniform float u_sm_pcf;
    uniform vec3 u_sm_frame[18];       /* per face: right, up, axis (rl_shadowmap_face_frame) */
    /* The scene's environment (rl_gl_pt_set_environment): radiance texels
     * (rgb) from 0, then at u_env_off the weights, the conditional and the
     * marginal running sums of rl_pt_env_build. Always bound, as the maps. */
    layout(binding = 8) uniform samplerBuffer u_env_data;     /* r32f */
    uniform bool u_env;                /* escaping rays see it, not u_background */
    uniform bool u_env_nee;            /* BRDF vertices sample it (pt's env_nee) */
    uniform bool u_ggx_ms;             /* GGX energy compensation (pt's ggx_ms) */
    uniform uint u_env_slot;           /* its 2D sample's slot in a vertex's block */
    uniform ivec2 u_env_map;           /* the map's texels (1 x 1: constant) */
    uniform ivec2 u_env_size;          /* the distribution's grid */
    uniform ivec3 u_env_off;           /* weights, conditional, marginal */
    uniform float u_env_rot;           /* radians about +y */
    uniform double u_env_sum;          /* of the weights */

    uniform ivec2 u_size;
    uniform vec3 u_eye;
    uniform vec3 u_cam_u;
    uniform vec3 u_cam_v;
    uniform vec3 u_cam_w;
    uniform float u_tan_half_fov;
    uniform float u_aspect;
    uniform int u_rng;                 /* 0: sobol, else rl_rng_gpu_kind + 1 */
    uniform uint u_held[2];            /* samples the pixels hold before this one, by the
                                        * parity of x + y */
    uniform bool u_checker;            /* checkerboard (Sec. 8.5): only the pixels whose */
    uniform uint u_parity;             /* x + y has this parity */
    uniform bool u_raster;             /* primary=raster: paths start from u_ids' triangles */
    /* adaptive sampling (pathtrace.c adaptive_tile): per pixel the samples
     * held and this round's share; dispatch u_round_k traces the pixels
     * whose share exceeds it, as sample number held + u_round_k */
    layout(rg32ui, binding = 2) uniform uimage2D u_adapt;
    uniform bool u_adaptive;
    uniform uint u_round_k;
    layout(binding = 6) uniform usampler2D u_ids;
    /* pt's ray counts by rl_ray_type (rl_render_stats.rays) */
    layout(binding = 0, offset = 0) uniform atomic_uint c_primary;
    layout(binding = 0, offset = 4) uniform atomic_uint c_shadow;
    layout(binding = 0, offset = 8) uniform atomic_uint c_reflection;
    layout(binding = 0, offset = 12) uniform atomic_uint c_refraction;
    layout(binding = 0, offset = 16) uniform atomic_uint c_diffuse;
    uniform int u_max_depth;
    uniform int u_rr_depth;
    uniform bool u_rr;
    uniform bool u_mis;
    uniform bool u_mis_hits;
    uniform bool u_tri_lights;
    uniform int u_light_samples;
    uniform uint u_vertex_slots;
    uniform int u_num_lights;
    uniform uint u_table_count;
    uniform uint u_num_textures;
    uniform float u_eps;
    uniform vec3 u_background;
    uniform int u_shadow;
    uniform int u_diffuse;
    uniform int u_specular;
    uniform float u_ls_start;
    uniform float u_ls_offset;
    /* Hybrid light paths (rl_gl_pt_set_light_vertices, Sec. 8.4): the
     * paths' offsets (float bits, 4 a texel) from texel 0, the vertices (6
     * texels each) from u_lv_base. Always bound, as the maps. */
    layout(binding = 9) uniform samplerBuffer u_light_vertices;   /* rgba32f */
    uniform bool u_lvc;                /* the light-vertex strategies are on */
    uniform uint u_lv_paths;           /* light paths in the set (N) */
    uniform uint u_lv_base;
    uniform int u_lv_connect;          /* paths drawn per camera vertex (M) */
    uniform uint u_lv_slot;            /* their slots in a vertex's block */
    uniform float u_lv_nu1;            /* light_samples / M */
    /* The program's variant (gl_pt.c V_*): HAS_GGX, HAS_LIGHT_VERTICES and
     * HAS_ENV 0 leave the GGX lobes, the light-vertex joins and the
     * environment out of the program, as the uniform false would skip
     * them (llvmpipe's compile time grows with the inlined program). */
    bool lvc_on() { return HAS_LIGHT_VERTICES != 0 && u_lvc; }
    bool env_on() { return HAS_ENV != 0 && u_env; }
    bool env_nee_on() { return HAS_ENV != 0 && u_env_nee; }

    /* -------------------------------------------------------- sampler -- */
    const uint SLOT_PIXEL = 0u, SLOT_FIRST_VERTEX = 1u;
    const uint SLOT_EVENT = 0u, SLOT_LOBE = 1u, SLOT_BSDF = 2u, SLOT_RR = 3u, SLOTS_VERTEX = 4u;
    const uint SLOT_LIGHT_PICK = 0u, SLOT_LIGHT_POINT = 1u, SLOT_LIGHT_JITTER = 2u, SLOTS_LIGHT = 3u;

    uvec4 g_state;                     /* the generator state, or x: the pixel's scramble seed */
    uint g_index;
    uint g_slot;

    /* 64-bit words as (low, high) pairs. */
    uvec2 add64(uvec2 a, uvec2 b)
    {
        uint carry;
        uint lo = uaddCarry(a.x, b.x, carry);
        return uvec2(lo, a.y + b.y + carry);
    }
    uvec2 mul64(uvec2 a, uvec2 b)
    {
        uint hi, lo;
        umulExtended(a.x, b.x, hi, lo);
        return uvec2(lo, hi + a.x * b.y + a.y * b.x);
    }
    uvec2 shr64(uvec2 a, int s) { return uvec2((a.x >> s) | (a.y << (32 - s)), a.y >> s); }

    /* core/rng.c rl_hash64 (splitmix64). */
    uvec2 hash64(uvec2 x)
    {
        x = add64(x, uvec2(0x7f4a7c15u, 0x9e3779b9u));
        x = mul64(x ^ shr64(x, 30), uvec2(0x1ce4e5b9u, 0xbf58476du));
        x = mul64(x ^ shr64(x, 27), uvec2(0x133111ebu, 0x94d049bbu));
        return x ^ shr64(x, 31);
    }

    uint scramble_reversed(uint x, uint seed)
    {
        x += seed;
        x ^= x * 0x2c1b3c6cu;
        x *= (seed >> 1) | 1u;
        x ^= x * 0x95a4e8d2u;
        x += seed * 0x632be5abu;
        x ^= x * 0xa3d15f40u;
        x *= 0x8bb84b93u;
        x ^= x * 0x5e27a3f6u;
        return x;
    }
    uint owen_scramble(uint x, uint seed) { return bitfieldReverse(scramble_reversed(bitfieldReverse(x), seed)); }

    const uint sobol1_v[24] = uint[](
        0x80000000u, 0xc0000000u, 0xa0000000u, 0xf0000000u, 0x88000000u, 0xcc000000u, 0xaa000000u, 0xff000000u,
        0x80800000u, 0xc0c00000u, 0xa0a00000u, 0xf0f00000u, 0x88880000u, 0xcccc0000u, 0xaaaa0000u, 0xffff0000u,
        0x80008000u, 0xc000c000u, 0xa000a000u, 0xf000f000u, 0x88008800u, 0xcc00cc00u, 0xaa00aa00u, 0xff00ff00u);

    uint sobol_dim1(uint i)
    {
        uint r = 0u;
        for (i &= 0xffffffu; i != 0u; i &= i - 1u)
            r ^= sobol1_v[findLSB(i)];
        return r;
    }

    uvec3 slot_seeds(uint slot)
    {
        uvec2 h = hash64(uvec2(slot, g_state.x));
        uint s2 = mul64(h, uvec2(0xde82ef95u, 0xd1342543u)).y ^ h.x;
        return uvec3(h.x, h.y, s2);
    }

    float to_unit(uint x) { return float(x >> 8) * (1.0 / 16777216.0); }

    /* core/rng_gpu.c */
    uint ctg_step(uint x, int s1, int s2, int s3, uint m) { return ((x & m) << s3) ^ (((x << s1) ^ x) >> s2); }

    uint rng_next()
    {
        if (u_rng == 1) {
            g_state.w = 1664525u * g_state.w + 1013904223u;
            return g_state.w;
        }
        g_state.x = ctg_step(g_state.x, 13, 19, 12, 4294967294u);
        g_state.y = ctg_step(g_state.y, 2, 25, 4, 4294967288u);
        g_state.z = ctg_step(g_state.z, 3, 11, 17, 4294967280u);
        uint x = g_state.x ^ g_state.y ^ g_state.z;
        if (u_rng == 3) {
            g_state.w = 1664525u * g_state.w + 1013904223u;
            x ^= g_state.w;
        }
        return x;
    }

    /* x 2^-32, as rl_rng_gpu_float; below 1 where rounding would reach it */
    float rng_float() { return min(float(rng_next()) * 2.3283064365386963e-10, 0.99999994); }

    void seek(uint slot) { g_slot = slot; }

    float sample_1d()
    {
        if (u_rng != 0)
            return rng_float();
        uvec3 seed = slot_seeds(g_slot++);
        uint d0 = scramble_reversed(bitfieldReverse(g_index), seed.x);
        return to_unit(owen_scramble(d0, seed.y));
    }

    vec2 sample_2d()
    {
        if (u_rng != 0) {
            float a = rng_float();
            return vec2(a, rng_float());
        }
        uvec3 seed = slot_seeds(g_slot++);
        uint d0 = scramble_reversed(bitfieldReverse(g_index), seed.x);
        return vec2(to_unit(owen_scramble(d0, seed.y)), to_unit(owen_scramble(sobol_dim1(bitfieldReverse(d0)), seed.z)));
    }

    /* -------------------------------------------------------- surface -- */
    struct Surf { vec3 p; vec3 ng; vec3 ns; vec3 v; bool front; vec3 kd; vec2 uv; uint mat; uint tri; };

    /* scene/material.c rl_shading_normal */
    vec3 shading_normal(uint tri, Material m, vec3 ns, vec2 uv)
    {
        uint tex = m.tex.y;
        if (tex == NONE)
            return ns;
        vec3 n = normalize(ns);
        if (!finite3(n))
            return ns;
        uvec4 T = triangles[tri];
        vec3 e1 = position(T.y) - position(T.x), e2 = position(T.z) - position(T.x);
        vec2 t0 = uv_at(T.x), t1 = uv_at(T.y), t2 = uv_at(T.z);
        float du1 = t1.x - t0.x, dv1 = t1.y - t0.y, du2 = t2.x - t0.x, dv2 = t2.y - t0.y;
        float det = du1 * dv2 - du2 * dv1;
        if (!(abs(det) > 1e-20))
            return n;
        float inv = 1.0 / det;
        vec3 Tg = (e1 * dv2 - e2 * dv1) * inv;
        vec3 B = (e2 * du1 - e1 * du2) * inv;
        Tg = Tg - n * dot(n, Tg);
        if (!(dot(Tg, Tg) > 0.0) || !finite3(Tg))
            return n;
        Tg = normalize(Tg);
        vec3 Bo = cross(n, Tg);
        if (dot(Bo, B) < 0.0)
            Bo = -Bo;
        vec4 texel = tex_sample(tex, uv);
        float x = (2.0 * texel.x - 1.0) * m.emission.w, y = (2.0 * texel.y - 1.0) * m.emission.w;
        float z = 2.0 * texel.z - 1.0;
        vec3 bent = Tg * x + Bo * y + n * z;
        return dot(bent, bent) > 0.0 && finite3(bent) ? normalize(bent) : n;
    }

    /* rl_pt_surface_finish: the surface at p on tri, ns the interpolated
     * normal, v towards the viewer */
    Surf surface_finish(uint tri, vec3 p, vec3 ns, vec2 uv, vec3 v)
    {
        uvec4 T = triangles[tri];
        vec3 p0 = position(T.x), p1 = position(T.y), p2 = position(T.z);
        Surf s;
        s.p = p;
        s.uv = uv;
        s.v = v;
        vec3 ng = normalize(cross(p1 - p0, p2 - p0));
        Material m = materials[T.w];
        ns = normalize(shading_normal(tri, m, ns, uv));
        if (!(dot(ns, ns) > 0.0) || !finite3(ns))
            ns = ng;
        s.front = dot(ng, s.v) > 0.0;
        s.ng = s.front ? ng : -ng;
        s.ns = dot(ns, s.v) < 0.0 ? -ns : ns;
        s.mat = T.w;
        s.kd = m.diffuse.rgb;
        if (m.tex.x != NONE)
            s.kd *= tex_sample(m.tex.x, uv).rgb;
        s.tri = tri;
        return s;
    }

    /* rl_pt_surface_at_hit */
    Surf surface_at(Hit h, vec3 dir)
    {
        uvec4 T = triangles[h.tri];
        float u = h.u, v = h.v, w = 1.0 - u - v;
        vec3 p = position(T.x) * w + position(T.y) * u + position(T.z) * v;
        vec3 ns = normal_at(T.x) * w + normal_at(T.y) * u + normal_at(T.z) * v;
        return surface_finish(h.tri, p, ns, interp_uv(h.tri, u, v), -normalize(dir));
    }

    /* primary=raster (pt's G-buffer, gbuffer.c rl_gbuffer_raster): the
     * pixel-centre ray meets the plane of the triangle the raster pass
     * drew there (scene/tri_plane.h rl_tri_plane_hit, barycentrics clamped
     * onto the triangle), the point and normal as fill_pixel makes them
     * (the normal turned towards the camera), v towards the eye */
    bool surface_of_pixel(uint tri, vec3 eye, vec3 dir, out Surf s)
    {
        uvec4 T = triangles[tri];
        vec3 p0 = position(T.x), p1 = position(T.y), p2 = position(T.z);
        vec3 e1 = p1 - p0, e2 = p2 - p0;
        vec3 pv = cross(dir, e2);
        float det = dot(e1, pv);
        if (!(abs(det) > 0.0))
            return false;
        float inv = 1.0 / det;
        vec3 tv = eye - p0;
        float u = dot(tv, pv) * inv;
        vec3 qv = cross(tv, e1);
        float v = dot(dir, qv) * inv;
        float t = dot(e2, qv) * inv;
        u = max(u, 0.0);
        v = max(v, 0.0);
        if (u + v > 1.0) {
            float k = 1.0 / (u + v);
            u *= k;
            v *= k;
        }
        if (isinf(t) || isnan(t) || !(t > 0.0))
            return false;
        float w = 1.0 - u - v;
        vec3 p = p0 * w + p1 * u + p2 * v;
        vec3 n = normalize(normal_at(T.x) * w + normal_at(T.y) * u + normal_at(T.z) * v);
        if (!(dot(n, n) > 0.0) || !finite3(n))
            n = normalize(cross(e1, e2));
        n = dot(n, dir) > 0.0 ? -n : n;
        s = surface_finish(tri, p, n, interp_uv(tri, u, v), normalize(eye - p));
        return true;
    }

    /* pathtrace_path.c surface_of_record: a PNMT record knows only its
     * shading normal, which serves as the geometric one too */
    bool surface_of_record(vec3 p, vec3 n, vec2 uv, uint mat, vec3 v, out Surf s)
    {
        if (mat >= uint(materials.length()) || !finite3(p))
            return false;
        n = normalize(n);
        if (!(dot(n, n) > 0.0) || !finite3(n))
            n = v;
        bool faces = dot(n, v) >= 0.0;
        s.p = p;
        s.v = v;
        s.front = faces;
        s.ng = faces ? n : -n;
        s.ns = s.ng;
        s.mat = mat;
        s.uv = uv;
        Material m = materials[mat];
        s.kd = m.diffuse.rgb;
        if (m.tex.x != NONE)
            s.kd *= tex_sample(m.tex.x, uv).rgb;
        s.tri = NONE;
        return true;
    }

    /* ------------------------------------------------------- ray site -- */
    /* The one traversal call of the path program: every ray of a path
     * (the camera's, the shadow rays, the bounces) through structure,
     * any: a shadow ray, answered by the first hit in (t_min, t_max); else
     * the closest hit, in h for the BVH, the grid and the candidate lists,
     * for the PNMT records in h.tri (NONE) and rec_* (position, normal,
     * uv, material), for the pre-illuminated colours in rec_p. Mesa
     * inlines every GLSL function at each of its calls, so every call of a
     * traversal was another copy of each walk it may take, and llvmpipe's
     * compile time grows with the inlined program: trace_path makes its
     * rays one at a time in one loop and calls this once (docs/gl.md,
     * "One ray site"). */
    bool ray_query(int structure, vec3 o, vec3 d, float t_min, float t_max, bool any, out Hit h, out vec3 rec_p,
                   out vec3 rec_n, out vec2 rec_uv, out uint rec_mat)
    {
        h = Hit(t_max, 0.0, 0.0, NONE);
        rec_p = vec3(0.0);
        rec_n = vec3(0.0);
        rec_uv = vec2(0.0);
        rec_mat = 0u;
        if (may_use(STRUCT_LS_CAND) && structure == STRUCT_LS_CAND)
            return rl_ls_cand_walk(o, d, t_min, t_max, any, h.tri, h.t, h.u, h.v);
        if (may_use(STRUCT_LS_PNMT) && structure == STRUCT_LS_PNMT)
            return rl_ls_pnmt_walk(o, d, t_min, t_max, !any, h.t, h.tri, rec_p, rec_n, rec_uv, rec_mat);
        if (may_use(STRUCT_LS_PREILLUM) && structure == STRUCT_LS_PREILLUM)
            return rl_ls_preillum_walk(o, d, t_min, t_max, !any, rec_p, h.t);
        return query(structure, o, d, t_min, t_max, any, h);
    }

    /* rl_pt_closest: the surface a closest-hit query of ray_query found
     * along the secondary ray from o along dir (false: none to shade) */
    bool surface_of_hit(int structure, vec3 o, vec3 dir, Hit h, vec3 p, vec3 n, vec2 uv, uint mat, out Surf s)
    {
        if (may_use(STRUCT_LS_PNMT) && structure == STRUCT_LS_PNMT) {
            uint tri = h.tri;
            if (tri != NONE) {
                /* the start voxel's exact hit (ls_origin=exact), as
                 * rl_ls_surface_at makes it a record: the walk's own
                 * triangle test again for the barycentrics */
                float t, u, v;
                if (!rl_ls_wt_hit(rl_ls_wt_setup(o, dir), tri, max(0.0, u_ls_start), INF, t, u, v))
                    return false;
                float w = 1.0 - u - v;
                vec3 q0 = vec3(rl_ls_tri_v[9u * tri], rl_ls_tri_v[9u * tri + 1u], rl_ls_tri_v[9u * tri + 2u]);
                vec3 q1 = vec3(rl_ls_tri_v[9u * tri + 3u], rl_ls_tri_v[9u * tri + 4u], rl_ls_tri_v[9u * tri + 5u]);
                vec3 q2 = vec3(rl_ls_tri_v[9u * tri + 6u], rl_ls_tri_v[9u * tri + 7u], rl_ls_tri_v[9u * tri + 8u]);
                uvec4 T = triangles[tri];
                p = q0 * w + q1 * u + q2 * v;
                n = normal_at(T.x) * w + normal_at(T.y) * u + normal_at(T.z) * v;
                float len = length(n);
                if (!(len > 0.0)) {
                    n = cross(q1 - q0, q2 - q0);
                    len = length(n);
                }
                n = len > 0.0 ? n * (1.0 / len) : vec3(0.0, 0.0, 1.0);
                uv = interp_uv(tri, u, v);
                mat = T.w;
            }
            return surface_of_record(p, n, uv, mat, -normalize(dir), s);
        }
        s = surface_at(h, dir);
        return true;
    }

    /* ----------------------------------------------------------- BSDF -- */
    float mean3(vec3 c) { return (c.x + c.y + c.z) * (1.0 / 3.0); }
    /* Schlick 1994's (1 - cos)^5 (pathtrace_ggx.c schlick_weight) */
    float schlick_weight(float c)
    {
        float k = 1.0 - clamp(c, 0.0, 1.0), k2 = k * k;
        return k2 * k2 * k;
    }
    vec3 mirror_dir(Surf s) { return s.ns * (2.0 * dot(s.ns, s.v)) - s.v; }
    float lobe(vec3 r, vec3 wi, float n)
    {
        float c = dot(r, wi);
        return c > 0.0 ? pow(c, n) : 0.0;
    }

    vec3 phong_eval(Surf s, vec3 wi)
    {
        Material m = materials[s.mat];
        vec3 f = s.kd * (1.0 / PI);
        if (max_comp(m.specular.rgb) > 0.0) {
            float n = max(m.specular.w, 0.0);
            f += m.specular.rgb * ((n + 2.0) * 0.5 * (1.0 / PI) * lobe(mirror_dir(s), wi, n));
        }
        return f;
    }

    float diffuse_probability(Surf s)
    {
        float wd = mean3(s.kd), ws = mean3(materials[s.mat].specular.rgb);
        if (!(wd + ws > 0.0))
            return -1.0;
        return wd / (wd + ws);
    }

    float phong_pdf(Surf s, vec3 wi)
    {
        float pd = diffuse_probability(s);
        float cos_theta = dot(s.ns, wi);
        if (pd < 0.0 || cos_theta <= 0.0)
            return 0.0;
        float n = max(materials[s.mat].specular.w, 0.0);
        float pdf = pd * cos_theta / PI;
        if (pd < 1.0)
            pdf += (1.0 - pd) * (n + 1.0) * 0.5 / PI * lobe(mirror_dir(s), wi, n);
        return pdf;
    }

    /* rl_onb_from_normal / rl_onb_to_world */
    vec3 around(vec3 a, float cos_t, float phi)
    {
        float sg = a.z < 0.0 || (a.z == 0.0 && floatBitsToUint(a.z) != 0u) ? -1.0 : 1.0;
        float k = -1.0 / (sg + a.z);
        float b = a.x * a.y * k;
        vec3 t = vec3(1.0 + sg * a.x * a.x * k, sg * b, -sg * a.x);
        vec3 bt = vec3(b, sg + a.y * a.y * k, -a.y);
        float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
        return t * (cos(phi) * sin_t) + bt * (sin(phi) * sin_t) + a * cos_t;
    }

    bool phong_sample(Surf s, float u_lobe, float u1, float u2, out vec3 wi, out vec3 weight)
    {
        wi = vec3(0.0);
        weight = vec3(0.0);
        float pd = diffuse_probability(s);
        if (pd < 0.0)
            return false;
        float phi = 2.0 * PI * u2;
        vec3 dir;
        if (u_lobe < pd) {
            dir = around(s.ns, sqrt(1.0 - u1), phi);
        } else {
            float n = max(materials[s.mat].specular.w, 0.0);
            dir = around(mirror_dir(s), pow(u1, 1.0 / (n + 1.0)), phi);
        }
        float cos_theta = dot(s.ns, dir);
        if (cos_theta <= 0.0 || dot(s.ng, dir) <= 0.0)
            return false;
        float pdf = phong_pdf(s, dir);
        if (!(pdf > 0.0))
            return false;
        wi = dir;
        weight = phong_eval(s, dir) * (cos_theta / pdf);
        return true;
    }

    /* ------------------------------------------------------------ GGX -- */
    /* pathtrace_ggx.c line for line (issue 37, Sec. 13.4 outlook): f =
     * f_d + F D G2 / (4 |wi.n| |wo.n|), D the GGX distribution with alpha
     * = max(roughness^2, 1e-3), G2 Smith's height-correlated term, F
     * Schlick's with F0 between the ior's and k_d by metallic, f_d the
     * coated diffuse lobe; the specular lobe sampled by its visible
     * normals (Heitz 2018), the diffuse one by the cosine, one-sample MIS
     * over the two; u_ggx_ms adds Kulla & Conty's multiple-scattering lobe
     * from pt's own tables (ggx_e). */
    float ggx_alpha(float roughness) { return max(roughness * roughness, 1e-3); }

    float ggx_d(float alpha, float cos_m)
    {
        if (!(cos_m > 0.0))
            return 0.0;
        float a2 = alpha * alpha, c2 = cos_m * cos_m;
        float k = (a2 - 1.0) * c2 + 1.0;
        return a2 / (PI * k * k);
    }

    float ggx_lambda(float alpha, float c)
    {
        if (!(c > 0.0))
            return INF;
        float tan2 = max(0.0, 1.0 - c * c) / (c * c);
        return 0.5 * (sqrt(1.0 + alpha * alpha * tan2) - 1.0);
    }

    float ggx_g1(float alpha, float c) { return 1.0 / (1.0 + ggx_lambda(alpha, c)); }
    float ggx_g2(float alpha, float ci, float co)
    {
        return 1.0 / (1.0 + ggx_lambda(alpha, ci) + ggx_lambda(alpha, co));
    }

    /* rl_pt_ggx_sample_vndf (Heitz 2018, Sec. 3-4) */
    vec3 ggx_sample_vndf(vec3 wo, float alpha, float u1, float u2)
    {
        vec3 vh = normalize(vec3(alpha * wo.x, alpha * wo.y, wo.z));
        float len2 = vh.x * vh.x + vh.y * vh.y;
        vec3 t1 = len2 > 0.0 ? vec3(-vh.y, vh.x, 0.0) * (1.0 / sqrt(len2)) : vec3(1.0, 0.0, 0.0);
        vec3 t2 = cross(vh, t1);
        float r = sqrt(u1), phi = 2.0 * PI * u2;
        float p1 = r * cos(phi), p2 = r * sin(phi);
        float blend = 0.5 * (1.0 + vh.z);
        p2 = (1.0 - blend) * sqrt(max(0.0, 1.0 - p1 * p1)) + blend * p2;
        float p3 = sqrt(max(0.0, 1.0 - p1 * p1 - p2 * p2));
        vec3 nh = t1 * p1 + t2 * p2 + vh * p3;
        return normalize(vec3(alpha * nh.x, alpha * nh.y, max(1e-7, nh.z)));
    }

    /* ms_row, ms_mu, rl_pt_ggx_ms_albedo, rl_pt_ggx_ms_average: the
     * tables' bilinear lookup (mu nodes at (j / (nodes - 1))^2) */
    int ms_row(float roughness, out float t)
    {
        float x = (roughness > 0.0 ? min(roughness, 1.0) : 0.0) * float(GGX_NODES - 1);
        int i = int(x);
        if (i > GGX_NODES - 2)
            i = GGX_NODES - 2;
        t = x - float(i);
        return i;
    }

    float ms_mu(int j)
    {
        float x = float(j) / float(GGX_NODES - 1);
        return x * x;
    }

    float ggx_ms_albedo(float roughness, float mu)
    {
        float t;
        int i = ms_row(roughness, t);
        mu = mu > 0.0 ? min(mu, 1.0) : 0.0;
        int j = int(sqrt(mu) * float(GGX_NODES - 1));
        if (j > GGX_NODES - 2)
            j = GGX_NODES - 2;
        float a = ms_mu(j), b = ms_mu(j + 1);
        float v = clamp((mu - a) / (b - a), 0.0, 1.0);
        int r0 = i * GGX_NODES + j, r1 = r0 + GGX_NODES;
        float e0 = ggx_e[r0] + (ggx_e[r0 + 1] - ggx_e[r0]) * v;
        float e1 = ggx_e[r1] + (ggx_e[r1 + 1] - ggx_e[r1]) * v;
        return e0 + (e1 - e0) * t;
    }

    float ggx_ms_average(float roughness)
    {
        float t;
        int i = ms_row(roughness, t);
        const int avg = GGX_NODES * GGX_NODES;
        return ggx_e[avg + i] + (ggx_e[avg + i + 1] - ggx_e[avg + i]) * t;
    }

    vec3 schlick3(vec3 f0, float c) { return f0 + (vec3(1.0) - f0) * schlick_weight(c); }

    /* ggx_lobe / ggx_setup: the lobes at the outgoing direction, in the
     * frame of rl_onb_from_normal(ns) */
    struct Ggx {
        vec3 t, b, n, wo;
        float alpha;
        vec3 f0;
        float f0d;
        vec3 diffuse;
        float p_spec;              /* < 0: black */
        vec3 ms;                   /* f_ms(wi) = ms (1 - E(wi.z)); zero without it */
        float roughness;
    };

    Ggx ggx_setup(Surf s)
    {
        Material m = materials[s.mat];
        Ggx g;
        vec3 n = s.ns;
        float sg = n.z < 0.0 || (n.z == 0.0 && floatBitsToUint(n.z) != 0u) ? -1.0 : 1.0;
        float k = -1.0 / (sg + n.z);
        float b = n.x * n.y * k;
        g.t = vec3(1.0 + sg * n.x * n.x * k, sg * b, -sg * n.x);
        g.b = vec3(b, sg + n.y * n.y * k, -n.y);
        g.n = n;
        g.wo = vec3(dot(s.v, g.t), dot(s.v, g.b), dot(s.v, g.n));
        g.alpha = ggx_alpha(m.pbr.x);
        float r0 = (m.extra.y - 1.0) / (m.extra.y + 1.0);
        g.f0d = r0 * r0;
        float metal = clamp(m.pbr.y, 0.0, 1.0);
        g.f0 = vec3(g.f0d) * (1.0 - metal) + s.kd * metal;
        g.diffuse = s.kd * (1.0 - metal);
        float w_spec = mean3(schlick3(g.f0, g.wo.z));
        float w_diff = mean3(g.diffuse) * (1.0 - (g.f0d + (1.0 - g.f0d) * schlick_weight(g.wo.z)));
        g.roughness = m.pbr.x;
        g.ms = vec3(0.0);
        if (u_ggx_ms) {
            float e_avg = ggx_ms_average(m.pbr.x);
            float e_o = ggx_ms_albedo(m.pbr.x, g.wo.z);
            if (1.0 - e_avg > 1e-4 && e_o < 1.0) {
                vec3 f_avg = g.f0 + (vec3(1.0) - g.f0) * (1.0 / 21.0);
                vec3 f_ms = f_avg * f_avg * vec3(e_avg);
                f_ms *= vec3(1.0 / (1.0 - f_avg.x * (1.0 - e_avg)), 1.0 / (1.0 - f_avg.y * (1.0 - e_avg)),
                             1.0 / (1.0 - f_avg.z * (1.0 - e_avg)));
                g.ms = f_ms * ((1.0 - e_o) / (PI * (1.0 - e_avg)));
                w_diff += PI * mean3(g.ms);
            }
        }
        g.p_spec = w_spec + w_diff > 0.0 ? w_spec / (w_spec + w_diff) : -1.0;
        return g;
    }

    vec3 ggx_local(Ggx g, vec3 w) { return vec3(dot(w, g.t), dot(w, g.b), dot(w, g.n)); }

    vec3 ggx_eval_local(Ggx g, vec3 wi)
    {
        float ci = wi.z, co = g.wo.z;
        if (!(ci > 0.0) || !(co > 0.0))
            return vec3(0.0);
        float fd0 = g.f0d;
        float coat = (1.0 - (fd0 + (1.0 - fd0) * schlick_weight(ci))) * (1.0 - (fd0 + (1.0 - fd0) * schlick_weight(co)));
        vec3 f = g.diffuse * (coat / PI);
        if (max_comp(g.ms) > 0.0)
            f += g.ms * max(0.0, 1.0 - ggx_ms_albedo(g.roughness, ci));
        vec3 h = wi + g.wo;
        if (!(dot(h, h) > 0.0))
            return f;
        h = normalize(h);
        float spec = ggx_d(g.alpha, h.z) * ggx_g2(g.alpha, ci, co) / (4.0 * ci * co);
        return f + schlick3(g.f0, dot(wi, h)) * spec;
    }

    float ggx_pdf_local(Ggx g, vec3 wi)
    {
        float ci = wi.z, co = g.wo.z;
        if (g.p_spec < 0.0 || !(ci > 0.0) || !(co > 0.0))
            return 0.0;
        float pdf = (1.0 - g.p_spec) * ci / PI;
        vec3 h = wi + g.wo;
        if (g.p_spec > 0.0 && dot(h, h) > 0.0) {
            h = normalize(h);
            /* Heitz 2018, eq. 17 with the reflection's Jacobian */
            pdf += g.p_spec * ggx_g1(g.alpha, co) * ggx_d(g.alpha, h.z) / (4.0 * co);
        }
        return pdf;
    }

    bool ggx_sample(Surf s, Ggx g, float u_lobe, float u1, float u2, out vec3 wi, out vec3 weight)
    {
        wi = vec3(0.0);
        weight = vec3(0.0);
        if (g.p_spec < 0.0 || !(g.wo.z > 0.0))
            return false;
        vec3 local;
        if (u_lobe < g.p_spec) {
            vec3 m = ggx_sample_vndf(g.wo, g.alpha, u1, u2);
            local = m * (2.0 * dot(g.wo, m)) - g.wo;
        } else {
            float r = sqrt(u1), phi = 2.0 * PI * u2;
            local = vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u1)));
        }
        if (!(local.z > 0.0))
            return false;          /* below the horizon: single scattering loses it */
        vec3 dir = normalize(g.t * local.x + g.b * local.y + g.n * local.z);
        if (dot(s.ng, dir) <= 0.0)
            return false;
        float pdf = ggx_pdf_local(g, local);
        if (!(pdf > 0.0) || isinf(pdf))
            return false;
        wi = dir;
        weight = ggx_eval_local(g, local) * (local.z / pdf);
        return true;
    }

    /* rl_pt_bsdf_eval / _pdf / _sample_pdf: Phong or GGX by the material,
     * a runtime branch (one program for both). Every call is about the
     * path's current vertex, whose GGX lobe trace_path sets up once
     * (g_lobe): pt sets it up per call, with the same result; one setup
     * instead of one per call site also keeps the program small, which
     * llvmpipe compiles in proportion to its inlined size. */
    Ggx g_lobe;
    bool is_ggx(Surf s) { return HAS_GGX != 0 && materials[s.mat].pbr.z > 0.0; }

    vec3 brdf_eval(Surf s, vec3 wi)
    {
        return is_ggx(s) ? ggx_eval_local(g_lobe, ggx_local(g_lobe, wi)) : phong_eval(s, wi);
    }

    float brdf_pdf(Surf s, vec3 wi)
    {
        return is_ggx(s) ? ggx_pdf_local(g_lobe, ggx_local(g_lobe, wi)) : phong_pdf(s, wi);
    }

    bool brdf_sample(Surf s, float u_lobe, float u1, float u2, out vec3 wi, out vec3 weight)
    {
        return is_ggx(s) ? ggx_sample(s, g_lobe, u_lobe, u1, u2, wi, weight)
                         : phong_sample(s, u_lobe, u1, u2, wi, weight);
    }

    /* --------------------------------------------------------- lights -- */
    vec3 offset_origin(Surf s, vec3 dir) { return s.p + s.ng * ((dot(dir, s.ng) >= 0.0 ? 1.0 : -1.0) * u_eps); }

    /* raster/shadowmap.c rl_shadowmap_visible (Sec. 8.6): the face of the
     * major axis of p - light, the texel moved by the jitter j (the thesis'
     * PCF-like offset), the slope-scaled bias against acne; a receiver
     * whose geometric normal faces away from the light is in shadow. */
    bool shadowmap_visible(uint light, vec3 p, vec3 n, vec2 j)
    {
        Light L = lights[light];
        vec3 lp = int(L.pos.w) == LIGHT_QUAD ? L.pos.xyz + (L.dir.xyz + L.extra.xyz) * 0.5 : L.pos.xyz;
        vec3 d = p - lp;
        float dist = length(d);
        if (!(dist > 0.0))
            return true;
        float n_len = length(n);
        float cos_t = n_len > 0.0 ? -dot(n, d) / (n_len * dist) : 1.0;
        if (cos_t <= 0.0)
            return false;
        vec3 a = abs(d);
        int face = a.x >= a.y && a.x >= a.z ? int(d.x < 0.0) : (a.y >= a.z ? 2 + int(d.y < 0.0) : 4 + int(d.z < 0.0));
        float depth = dot(d, u_sm_frame[3 * face + 2]);
        float half_size = 0.5 * float(u_sm_size);
        float px = (dot(d, u_sm_frame[3 * face]) / depth + 1.0) * half_size + (2.0 * j.x - 1.0) * u_sm_pcf;
        float py = (1.0 - dot(d, u_sm_frame[3 * face + 1]) / depth) * half_size + (2.0 * j.y - 1.0) * u_sm_pcf;
        /* clamped as floats: a cast of a value beyond int's range is undefined */
        int tx = int(clamp(floor(px), 0.0, float(u_sm_size - 1)));
        int ty = int(clamp(floor(py), 0.0, float(u_sm_size - 1)));
        int base = (int(light) * 6 + face) * u_sm_size * u_sm_size;
        float stored = texelFetch(u_shadow_maps, base + ty * u_sm_size + tx).x;
        float sin_t = sqrt(max(0.0, 1.0 - cos_t * cos_t));
        float tan_t = sin_t < 1000.0 * cos_t ? sin_t / cos_t : 1000.0;
        float texel = 2.0 * depth / float(u_sm_size);
        float bias = u_sm_bias * depth + u_sm_slope * texel * tan_t;
        return depth - bias <= stored;
    }

    /* pathtrace_path.c visible(): the shadow ray aimed at the light point
     * from the offset origin, stopped 1e-4 short of it, as the ray of
     * ray_query (o, d, t_min, t_max through u_shadow); -1: trace it, else
     * the answer without a ray: 1 blocked, 0 not (the shadow maps, looked
     * up for light with the jitter j: no ray, none counted). */
    int shadow_setup(Surf s, vec3 l, float dist, uint light, vec2 j, out vec3 o, out vec3 d, out float t_min,
                     out float t_max)
    {
        o = offset_origin(s, l);
        d = l;
        t_min = 0.0;
        t_max = INF;
        if (may_use(STRUCT_SHADOWMAP) && u_shadow == STRUCT_SHADOWMAP)
            return shadowmap_visible(light, s.p, s.ng, j) ? 0 : 1;
        if (!isinf(dist)) {
            vec3 to = (s.p + l * dist) - o;
            float len = length(to);
            if (len > 0.0)
                d = to * (1.0 / len);
            t_max = len * (1.0 - 1e-4);
        }
        atomicCounterIncrement(c_shadow);
        if ((may_use(STRUCT_LS_PNMT) && u_shadow == STRUCT_LS_PNMT) ||
            (may_use(STRUCT_LS_PREILLUM) && u_shadow == STRUCT_LS_PREILLUM)) {
            /* pt's voxel offsets: at the light's end always, at the
             * surface's with ls_origin=offset */
            t_min = max(0.0, u_ls_start);
            t_max -= u_ls_offset;
            if (!(t_min < t_max))
                return 0;
        }
        return -1;
    }

    /* ---------------------------------------------------- environment -- */
    float env_at(int i) { return texelFetch(u_env_data, i).x; }

    /* scene/environment.c rl_environment_uv */
    vec2 env_uv(vec3 dir)
    {
        float theta = acos(clamp(dir.y, -1.0, 1.0));
        float phi = atan(-dir.z, dir.x) - u_env_rot;
        float u = phi / (2.0 * PI);
        u -= floor(u);
        if (u >= 1.0)
            u = 0.0;
        return vec2(u, clamp(theta / PI, 0.0, 1.0));
    }

    /* rl_environment_direction */
    vec3 env_direction(float u, float v)
    {
        float theta = PI * v, phi = 2.0 * PI * u + u_env_rot;
        float st = sin(theta);
        return vec3(st * cos(phi), cos(theta), -st * sin(phi));
    }

    /* rl_environment_radiance: the nearest texel, no filtering (the
     * uploaded texels are already colour times texel) */
    vec3 env_radiance(vec3 dir)
    {
        vec2 uv = env_uv(dir);
        int x = clamp(int(uv.x * float(u_env_map.x)), 0, u_env_map.x - 1);
        int y = clamp(int(uv.y * float(u_env_map.y)), 0, u_env_map.y - 1);
        int i = 3 * (y * u_env_map.x + x);
        return vec3(env_at(i), env_at(i + 1), env_at(i + 2));
    }

    /* rl_pt_env_pdf: p(u, v) / (2 pi^2 sin theta), in double as there */
    float env_pdf(vec3 dir)
    {
        vec2 uv = env_uv(dir);
        float sin_t = sqrt(max(0.0, 1.0 - dir.y * dir.y));
        if (!(sin_t > 0.0) || !(u_env_sum > 0.0LF))
            return 0.0;
        int w = u_env_size.x, h = u_env_size.y;
        int x = clamp(int(uv.x * float(w)), 0, w - 1), y = clamp(int(uv.y * float(h)), 0, h - 1);
        double p_uv = double(env_at(u_env_off.x + y * w + x)) * double(w) * double(h) / u_env_sum;
        return float(p_uv / (2.0LF * double(PI) * double(PI) * double(sin_t)));
    }

    /* pathtrace_env.c pick: the cell of the n + 1 sums from off holding u,
     * and u's position in it */
    int env_pick(int off, int n, float u, out float frac)
    {
        int lo = 0, hi = n;
        while (hi - lo > 1) {
            int mid = lo + (hi - lo) / 2;
            if (env_at(off + mid) <= u)
                lo = mid;
            else
                hi = mid;
        }
        float c0 = env_at(off + lo), width = env_at(off + lo + 1) - c0;
        frac = width > 0.0 ? clamp((u - c0) / width, 0.0, 0.99999994) : 0.5;
        return lo;
    }

    /* rl_pt_env_sample: row by the marginal, texel by the row's
     * conditional, the density of the texel the direction looks up */
    bool env_sample(float u1, float u2, out vec3 dir, out float pdf)
    {
        dir = vec3(0.0);
        pdf = 0.0;
        float fy, fx;
        int w = u_env_size.x, h = u_env_size.y;
        int y = env_pick(u_env_off.z, h, u1, fy);
        int x = env_pick(u_env_off.y + y * (w + 1), w, u2, fx);
        vec3 d = env_direction((float(x) + fx) / float(w), (float(y) + fy) / float(h));
        float p = env_pdf(d);
        if (!(p > 0.0) || isinf(p))
            return false;
        dir = d;
        pdf = p;
        return true;
    }

    float power_heuristic(float a, float b)
    {
        if (!(a > 0.0))
            return 0.0;
        float r = b / a;
        return 1.0 / (1.0 + r * r);
    }

    float bsdf_pdf(Surf s, vec3 wi) { return dot(s.ng, wi) > 0.0 ? brdf_pdf(s, wi) : 0.0; }

    float triangle_area(uint tri, out vec3 n)
    {
        uvec4 T = triangles[tri];
        vec3 p0 = position(T.x);
        vec3 c = cross(position(T.y) - p0, position(T.z) - p0);
        float len = length(c);
        n = len > 0.0 ? c * (1.0 / len) : vec3(0.0, 0.0, 1.0);
        return 0.5 * len;
    }


    /* ------------------------------------------------ light vertices -- */
    /* Hybrid light paths (Schröder 2017 Sec. 8.4): the CPU traces light
     * subpaths (bdpt's, bd_light_subpath) and hands their surface vertices
     * y_1, y_2, ... to this shader; every BRDF vertex of a camera path joins
     * all vertices of u_lv_connect (= M) paths drawn uniformly from the N
     * of the set, each join divided by M: the light-vertex-cache estimator
     * of Davidovic et al. 2014 with whole paths drawn, so the expectation
     * over the draw is bdpt's connection term with one light subpath and no
     * bias from the draw.
     *
     * MIS (power heuristic, Veach 1997 Sec. 9.2 with sample counts): a path
     * x_0 (on a light) .. x_k (the camera's first hit), k <= max_depth + 1,
     * is made by the strategies s' = 0 .. k (s' vertices from the light):
     * s' = 0 a BRDF ray hits the emitter (1 sample, possible only when
     * k <= max_depth and the light is hittable), s' = 1 next-event
     * estimation (light_samples = a samples), s' >= 2 a join of light
     * vertex x_{s'-1} with camera vertex x_{s'} (M samples); s' = k + 1
     * (light tracing to the pinhole) is not done. With the counts
     * relative to M, nu_0 = 1/M, nu_1 = a/M, nu_{>=2} = 1 (0 where a
     * delta vertex ends the joining edge), and p_i the area densities, the
     * weight of the strategy s that made the path is
     *   w_s = nu_s^2 p_s^2 / sum_s' nu_s'^2 p_s'^2,
     * and these sum to one over the strategies by construction, whatever
     * the densities are, as long as every strategy computes the same ratios
     * p_{j+1} / p_j = pL(x_j) / pE(x_j) (pL: density of x_j made from the
     * light side, pE: from the camera side). Both sides follow bdpt's
     * conventions (bdpt_path.c): densities made by a delta vertex are 1,
     * the BRDF's density carries the event's share 1 - k_r - k_t. The sums
     * run recursively (after Georgiev 2012, "Implementing vertex connection
     * and merging", in area densities):
     *   light side  R_j = (pE_j / pL_j)^2 (nu_j^2 + R_{j-1}): the CPU
     *     stores per vertex y_i the parts that do not depend on the camera
     *     vertex it joins (L1 = nu_i^2 / pL_i^2; L2 = (cos_{i-1} /
     *     d_{i-1,i}^2)^2 (nu_{i-1}^2 + R_{i-2}) / (pL_i pL_{i-1})^2, split
     *     into the part without and the part with s' = 0 so the latter can
     *     be dropped where the path is longer than a BRDF ray can find),
     *     and the join finishes R_i = pE_i^2 (L1 + revW^2 L2) with the two
     *     densities it makes (pE_i from the camera vertex's BRDF, and
     *     pE_{i-1} = revW cos / d^2 from y_i's BRDF turned to the camera);
     *   camera side C_m = (pL_m / pE_m)^2 (nu_{m+1}^2 + C_{m+1}) = pL_m^2
     *     A_m: lv_cam_a below, the previous vertex's A in g_ca; C at the
     *     first hit is 0 (no light tracing).
     * A join (s >= 2) weighs 1 / (1 + R_{s-1} + C_s); next-event
     * estimation 1 / (1 + (pE_0 / (a pL_0))^2 + C_1 / nu_1^2); an emitter
     * hit 1 / (1 + M^2 (pL_0 / pE_0)^2 (nu_1^2 + C_1)). Refused in
     * gl_pathtrace.c: environments, point, spot and directional lights
     * (delta light vertices), payload backends and shadow maps. */
    float g_ca;                        /* A of the previous camera vertex */
    float g_cpe;                       /* pE of the current vertex */
    float g_ccos;                      /* |cos| at the previous vertex towards it */
    float g_cd2;                       /* squared distance between them */
    bool g_cok;                        /* the previous vertex joins (a BRDF vertex, not the pinhole) */
    float g_cdir;                      /* the density the next hit is made with (1: delta) */

    /* bdpt_path.c seen_from: s seen from unit w */
    Surf turned(Surf s, vec3 w)
    {
        Surf r = s;
        r.v = w;
        if (dot(r.ng, w) < 0.0) {
            r.ng = -r.ng;
            r.front = !r.front;
        }
        if (dot(r.ns, w) < 0.0)
            r.ns = -r.ns;
        return r;
    }

    /* bdpt_path.c bsdf_pdf: the BRDF's density with the event's share, at
     * the path's current vertex s (Phong or GGX; GGX's lobe is g_lobe,
     * set up for s) */
    float lv_pdf(Surf s, vec3 wi)
    {
        Material m = materials[s.mat];
        float k = max(0.0, 1.0 - m.diffuse.w - m.extra.x);
        return k > 0.0 && dot(s.ng, wi) > 0.0 ? k * brdf_pdf(s, wi) : 0.0;
    }

    /* lv_pdf at another surface than the current vertex (a light vertex,
     * or a vertex seen from its other direction: turned): GGX's lobe
     * depends on s.v (Sec. 13.4; pathtrace_ggx.c), so it is set up here
     * for s. Only the GGX variant has that code (is_ggx). */
    float lv_pdf_at(Surf s, vec3 wi)
    {
        Material m = materials[s.mat];
        float k = max(0.0, 1.0 - m.diffuse.w - m.extra.x);
        if (!(k > 0.0 && dot(s.ng, wi) > 0.0))
            return 0.0;
        if (is_ggx(s)) {
            Ggx g = ggx_setup(s);
            return k * ggx_pdf_local(g, ggx_local(g, wi));
        }
        return k * phong_pdf(s, wi);
    }

    /* A_m of camera vertex s leaving towards wi (delta: a specular event):
     * C_m = pL_m^2 A_m */
    float lv_cam_a(Surf s, vec3 wi, bool delta)
    {
        float inv = 1.0 / (g_cpe * g_cpe);
        float a = !delta && g_cok ? inv : 0.0;
        if (g_ca > 0.0) {
            float pl = delta ? 1.0 : lv_pdf_at(turned(s, wi), s.v) * g_ccos / g_cd2;
            a += pl * pl * g_ca * inv;
        }
        return a;
    }

    /* the state of the first hit: nothing before it joins */
    void lv_start()
    {
        g_ca = 0.0;
        g_cpe = 1.0;
        g_ccos = 1.0;
        g_cd2 = 1.0;
        g_cok = false;
        g_cdir = 1.0;
    }

    /* leaving s towards dir (density pdf_dir; delta: a specular event) */
    void lv_leave(Surf s, vec3 dir, bool delta)
    {
        g_ca = lv_cam_a(s, dir, delta);
        g_cok = !delta;
        g_ccos = abs(dot(s.ng, dir));
        g_cdir = delta ? -1.0 : lv_pdf(s, dir);
    }

    /* arriving at s from the previous vertex at prev */
    void lv_arrive(Surf s, vec3 prev)
    {
        vec3 d = s.p - prev;
        g_cd2 = dot(d, d);
        g_cpe = g_cdir < 0.0 ? 1.0 : g_cdir * abs(dot(s.ng, d)) / (sqrt(g_cd2) * g_cd2);
    }

    /* the weight of an emitter hit at s (x_0) after the camera's previous
     * vertex; pmf / area the light table's density of the point, two_sided
     * a triangle light (emission density |cos| / 2 pi, else cos / pi) */
    float lv_hit_weight(Surf s, float pmf, float area, bool two_sided)
    {
        if (!(g_ca > 0.0) && !g_cok)
            return 1.0;
        float cos0 = abs(dot(s.ng, s.v));
        float pl0 = pmf / area;
        float pl1 = cos0 / (two_sided ? 2.0 * PI : PI) * g_ccos / g_cd2;
        float nu1 = g_cok ? u_lv_nu1 : 0.0;
        float r = pl0 / g_cpe * float(u_lv_connect);
        float sum = r * r * (nu1 * nu1 + pl1 * pl1 * g_ca);
        return isinf(sum) || isnan(sum) ? 0.0 : 1.0 / (1.0 + sum);
    }

    /* the weight of a light sample at camera vertex s towards unit l:
     * light point at squared distance d2, cos_e there, the table's pmf /
     * area, bsdf_follows && hittable: a BRDF ray could have found it */
    float lv_nee_weight(Surf s, vec3 l, float d2, float cos_e, float pmf, float area, bool two_sided, bool hit)
    {
        float pl0 = pmf / area;
        float pe0 = lv_pdf(s, l) * cos_e / d2;
        float sum = 0.0;
        if (hit) {
            float r = pe0 / (pl0 * float(u_light_samples));
            sum += r * r;
        }
        float pl1 = cos_e / (two_sided ? 2.0 * PI : PI) * abs(dot(s.ng, l)) / d2;
        sum += pl1 * pl1 * lv_cam_a(s, l, false) / (u_lv_nu1 * u_lv_nu1);
        return isinf(sum) || isnan(sum) ? 0.0 : 1.0 / (1.0 + sum);
    }

    vec4 lv_texel(uint i) { return texelFetch(u_light_vertices, int(i)); }
    uint lv_offset(uint j) { return floatBitsToUint(lv_texel(j >> 2)[j & 3u]); }

    /* rl_pt_lights_pick: the last k with cdf[k] <= u */
    uint pick_light(float u)
    {
        uint lo = 0u, hi = u_table_count;
        while (hi - lo > 1u) {
            uint mid = lo + (hi - lo) / 2u;
            if (table_cdf(mid) <= u)
                lo = mid;
            else
                hi = mid;
        }
        return lo;
    }

    /* escaped: a ray that left the scene; after a BRDF bounce with density
     * pdf_bsdf the environment gets the BSDF strategy's weight when light
     * samples also reach it */
    vec3 escaped(vec3 dir, bool after_brdf, float pdf_bsdf)
    {
        if (!env_on())
            return u_background;
        vec3 L = env_radiance(dir);
        if (!env_nee_on() || !after_brdf)
            return L;
        return L * power_heuristic(pdf_bsdf, env_pdf(dir));
    }

    /* rl_pt_cover_point: the quad light whose parallelogram holds p (a
     * PNMT record has no triangle to look up) */
    uint cover_point(vec3 p, float tol)
    {
        for (int i = 0; i < u_num_lights; ++i) {
            Light L = lights[i];
            if (int(L.pos.w) != LIGHT_QUAD)
                continue;
            vec3 eu = L.dir.xyz, ev = L.extra.xyz;
            vec3 n = cross(eu, ev);
            float area = length(n);
            if (!(area > 0.0))
                continue;
            vec3 r = p - L.pos.xyz;
            if (abs(dot(r, n)) / area > tol)
                continue;
            float uu = dot(eu, eu), uv = dot(eu, ev), vv = dot(ev, ev), ru = dot(r, eu), rv = dot(r, ev);
            float det = uu * vv - uv * uv;
            if (!(det > 0.0))
                continue;
            float a = (ru * vv - rv * uv) / det, b = (rv * uu - ru * uv) / det;
            float ta = tol / sqrt(uu), tb = tol / sqrt(vv);
            if (a >= -ta && a <= 1.0 + ta && b >= -tb && b <= 1.0 + tb)
                return uint(i);
        }
        return NONE;
    }

    /* emitted: the emission rule of pathtrace_path.c */
    vec3 emitted(Surf s, bool after_brdf)
    {
        vec3 e = materials[s.mat].emission.rgb;
        if (!(max_comp(e) > 0.0))
            return vec3(0.0);
        uint cover = s.tri != NONE ? tri_cover(s.tri) : cover_point(s.p, 10.0 * u_eps);
        if (cover == NONE)
            return e;
        Light L = lights[cover];
        bool emitting_side = dot(s.v, cross(L.dir.xyz, L.extra.xyz)) > 0.0;
        return emitting_side && !after_brdf ? e : vec3(0.0);
    }

    vec3 emitted_mis(Surf s, bool after_brdf, vec3 prev, float pdf_bsdf)
    {
        if (!after_brdf || !u_mis_hits)
            return emitted(s, after_brdf);
        vec3 e = materials[s.mat].emission.rgb;
        if (!(max_comp(e) > 0.0) || s.tri == NONE)
            return emitted(s, after_brdf);
        uint cover = tri_cover(s.tri);
        float pmf, area;
        if (cover == NONE) {
            if (!u_tri_lights)
                return e;
            pmf = tri_pmf(s.tri);
            vec3 n_unused;
            area = triangle_area(s.tri, n_unused);
        } else {
            Light L = lights[cover];
            vec3 nq = cross(L.dir.xyz, L.extra.xyz);
            if (!(dot(s.v, nq) > 0.0) || !(L.extra.w > 0.0))
                return vec3(0.0);
            e = L.power.rgb;
            pmf = L.power.w;
            area = length(nq);
        }
        float cos_e = dot(s.ng, s.v);
        vec3 dp = s.p - prev;
        float d2 = dot(dp, dp);
        if (!(pmf > 0.0) || !(cos_e > 0.0) || !(area > 0.0))
            return e;
        float p_light = pmf * d2 / (area * cos_e);
        return e * power_heuristic(pdf_bsdf, float(u_light_samples) * p_light);
    }

    /* With light vertices: the emitter hit weighed against next-event
     * estimation and the joins (lv_hit_weight). A quad light that no mesh
     * covers fully keeps pt's rule (its mesh emits only to rays that did
     * not leave a BRDF: no other strategy makes those paths), and so does
     * a hit that no join or light sample could have made (the camera's
     * first hit, or mirror chains from it): the material's emission. */
    vec3 emitted_lvc(Surf s, bool after_brdf)
    {
        vec3 e = materials[s.mat].emission.rgb;
        if (!(max_comp(e) > 0.0))
            return vec3(0.0);
        if (!after_brdf && !(g_ca > 0.0))
            return emitted(s, false);
        uint cover = tri_cover(s.tri);
        if (cover == NONE) {
            float pmf = tri_pmf(s.tri);
            vec3 n_unused;
            float area = triangle_area(s.tri, n_unused);
            if (!(pmf > 0.0) || !(area > 0.0))
                return e;
            return e * lv_hit_weight(s, pmf, area, true);
        }
        Light L = lights[cover];
        if (!(L.extra.w > 0.0))
            return emitted(s, after_brdf);
        vec3 nq = cross(L.dir.xyz, L.extra.xyz);
        float area = length(nq);
        if (!(dot(s.v, nq) > 0.0) || !(area > 0.0) || !(L.power.w > 0.0))
            return vec3(0.0);
        return L.power.rgb * lv_hit_weight(s, L.power.w, area, false);
    }

    /* -------------------------------------------------------- Fresnel -- */

    /* scene/material.c rl_fresnel_schlick: eta = n_t / n_i; from the
     * denser side with the angle on the rarer one (reciprocal), 1 past
     * the critical angle */
    float fresnel_schlick(float cos_i, float eta)
    {
        if (!(eta > 0.0))
            return 1.0;
        float c = clamp(cos_i, 0.0, 1.0);
        if (eta < 1.0) {
            float sin2_t = (1.0 - c * c) / (eta * eta);
            if (sin2_t >= 1.0)
                return 1.0;
            c = sqrt(1.0 - sin2_t);
        }
        float r0 = (eta - 1.0) / (eta + 1.0);
        r0 *= r0;
        float k = 1.0 - c, k2 = k * k;
        return r0 + (1.0 - r0) * k2 * k2 * k;
    }

    /* ----------------------------------------------------------- path -- */
    /* rl_pt_trace_path (Sec. 6.4): the path from the camera ray (eye,
     * cam_dir), or with raster from the G-buffer's surface first; a camera
     * ray that leaves the scene brings miss. One ray per iteration of one
     * loop, all through the one ray_query() call: the camera ray, then per
     * vertex its shadow rays in pt's order (stage SHADOW: the lights,
     * every light's samples with mis=off as pathtrace_path.c direct_light,
     * the light table's light_samples picks with mis as direct_light_mis;
     * the environment's sample, environment_light; the joins with the
     * light vertices, light_vertices, not at the last vertex), each sum
     * apart as pt adds them, then the ray the path goes on along (stage
     * BOUNCE). A shadow ray that pt drops before its test is dropped here
     * before the query too (same rays, same counts); an unblocked one
     * brings C * (a / b) times the BRDF towards l (lights, environment:
     * pt's products in pt's grouping) or C over a join's MIS sum (a). */
    vec3 trace_path(bool raster, Surf first, vec3 eye, vec3 cam_dir, vec3 miss)
    {
        const int VERTEX = 0, SHADOW = 1, PREPARE = 2, BOUNCE = 3;
        vec3 radiance = vec3(0.0), T = vec3(1.0);
        Surf s = first;
        bool after_brdf = false;
        vec3 prev = s.p;
        float prev_pdf = 0.0;
        bool gen = u_rng != 0;
        if (lvc_on())
            lv_start();
        int depth = 0;
        /* without raster the camera ray (through the BVH) comes first */
        bool camera = !raster;
        int stage = raster ? VERTEX : BOUNCE;
        int structure = STRUCT_BVH;
        vec3 dir = cam_dir, origin = eye;
        float origin_t = 0.0;
        bool diffuse_ray = false, refracted = false, last = false;
        uint base = 0u;
        Material m;
        /* the shadow rays: 0 the lights, 1 the environment, 2 the joins,
         * 3 done; the lights' light i (mis=off) and sample k, the joins'
         * light paths drawn so far and the vertices of the last one left */
        int phase = 0, i = 0, k = 0, path = 0;
        uint vi = 0u, vend = 0u;
        vec3 direct = vec3(0.0), env = vec3(0.0), joins = vec3(0.0);
        bool jitter = u_shadow == STRUCT_SHADOWMAP;
        int n = u_light_samples;
        while (true) {
            if (stage == VERTEX) {
                base = SLOT_FIRST_VERTEX + uint(depth) * u_vertex_slots;
                m = materials[s.mat];
                if (HAS_GGX != 0 && m.pbr.z > 0.0)
                    g_lobe = ggx_setup(s);
                vec3 e = lvc_on() ? emitted_lvc(s, after_brdf)
                               : u_mis ? emitted_mis(s, after_brdf, prev, prev_pdf) : emitted(s, after_brdf);
                radiance += T * e;

                float k_r = m.diffuse.w, k_t = m.extra.x;
                seek(base + SLOT_EVENT);
                float u_event = gen || k_r + k_t > 0.0 ? sample_1d() : 1.0;
                refracted = false;
                if (u_event < k_r + k_t) {
                    if (depth >= u_max_depth)
                        break;
                    /* rl_pt_specular_event: with Schlick's Fresnel (extra.w) a
                     * mirror reflects F with F0 = k_s, and within k_t the
                     * event reflects with probability F (weight 1) */
                    vec3 d = -s.v;
                    diffuse_ray = false;
                    dir = d - s.ns * (2.0 * dot(d, s.ns));
                    bool schlick = m.extra.w > 0.0;
                    bool fresnel_mirror = false;
                    if (u_event < k_r && schlick) {
                        T *= m.specular.rgb + (vec3(1.0) - m.specular.rgb) * schlick_weight(dot(s.ns, s.v));
                    } else if (u_event >= k_r && schlick) {
                        float ior = m.extra.y >= 1.0 ? m.extra.y : 1.0;
                        float F = fresnel_schlick(dot(s.ns, s.v), s.front ? ior : 1.0 / ior);
                        float u = k_t > 0.0 ? (u_event - k_r) / k_t : 0.0;
                        fresnel_mirror = u < F;
                    }
                    if (u_event >= k_r && !fresnel_mirror) {
                        float ior = m.extra.y >= 1.0 ? m.extra.y : 1.0;
                        float eta = s.front ? 1.0 / ior : ior;
                        float cos_i = -dot(d, s.ns);
                        float kk = 1.0 - eta * eta * (1.0 - cos_i * cos_i);
                        if (kk >= 0.0) {
                            dir = normalize(d * eta + s.ns * (eta * cos_i - sqrt(kk)));
                            refracted = true;
                        }
                    }
                    after_brdf = false;
                    if (lvc_on())
                        lv_leave(s, dir, true);
                    stage = PREPARE;
                } else {
                    last = depth >= u_max_depth;
                    direct = vec3(0.0);
                    env = vec3(0.0);
                    joins = vec3(0.0);
                    phase = u_mis && u_table_count == 0u ? 1 : 0;
                    i = 0;
                    k = 0;
                    path = 0;
                    vi = 0u;
                    vend = 0u;
                    stage = SHADOW;
                }
            }

            /* the next shadow ray: towards l, dist long (INF: unbounded),
             * with the jitter j of its light's shadow maps */
            int kind = phase;
            vec3 l = vec3(0.0), C = vec3(0.0);
            float dist = INF, a = 1.0, b = 1.0;
            uint light = 0u;
            vec2 j = vec2(0.0);
            /* lights with mis, area kind: weighed after the test, as pt */
            bool weigh = false;
            float d2 = 0.0, cos_e = 0.0, cos_r = 0.0, pmf = 0.0, area = 0.0;
            bool two_sided = false, hittable = false;
            if (stage == SHADOW) {
                if (phase == 0 && !u_mis) {
                    if (i >= u_num_lights) {
                        phase = 1;
                        continue;
                    }
                    Light L = lights[i];
                    uint light_base = base + SLOTS_VERTEX + SLOTS_LIGHT * uint(i) * uint(n);
                    light = uint(i);
                    if (int(L.pos.w) == LIGHT_QUAD) {
                        vec3 nq = cross(L.dir.xyz, L.extra.xyz);
                        area = length(nq);
                        if (!(area > 0.0) || k >= n) {
                            ++i;
                            k = 0;
                            continue;
                        }
                        nq *= 1.0 / area;
                        C = L.power.rgb * (area / float(n));
                        /* both numbers drawn before any test, as pt draws them */
                        seek(light_base + SLOTS_LIGHT * uint(k) + SLOT_LIGHT_POINT);
                        vec2 x = sample_2d();
                        seek(light_base + SLOTS_LIGHT * uint(k) + SLOT_LIGHT_JITTER);
                        j = jitter ? sample_2d() : vec2(0.0);
                        ++k;
                        vec3 q = L.pos.xyz + (L.dir.xyz * x.x + L.extra.xyz * x.y);
                        vec3 to = q - s.p;
                        d2 = dot(to, to);
                        if (!(d2 > 0.0))
                            continue;
                        dist = sqrt(d2);
                        l = to * (1.0 / dist);
                        cos_e = -dot(nq, l);
                        cos_r = dot(s.ns, l);
                        if (cos_e <= 0.0 || cos_r <= 0.0)
                            continue;
                        a = cos_e * cos_r;
                        b = d2;
                    } else {
                        ++i;
                        k = 0;
                        seek(light_base + SLOT_LIGHT_JITTER);
                        j = jitter ? sample_2d() : vec2(0.0);
                        if (!light_delta(L, s.p, C, l, dist))
                            continue;
                        cos_r = dot(s.ns, l);
                        if (cos_r <= 0.0)
                            continue;
                        /* pt's E cos_r: a / 1 is a exactly */
                        a = cos_r;
                    }
                } else if (phase == 0) {
                    if (k >= n) {
                        phase = 1;
                        continue;
                    }
                    uint slot = base + SLOTS_VERTEX + SLOTS_LIGHT * uint(k);
                    ++k;
                    seek(slot + SLOT_LIGHT_PICK);
                    float u_pick = u_table_count > 1u ? sample_1d() : 0.0;
                    seek(slot + SLOT_LIGHT_POINT);
                    vec2 x = sample_2d();
                    seek(slot + SLOT_LIGHT_JITTER);
                    j = jitter ? sample_2d() : vec2(0.0);
                    uint src = table_source(pick_light(u_pick));
                    light = src;
                    vec3 q, n_e;
                    bool is_light = src < uint(u_num_lights);
                    if (is_light) {
                        Light L = lights[src];
                        pmf = L.power.w;
                        if (int(L.pos.w) != LIGHT_QUAD) {
                            if (!light_delta(L, s.p, C, l, dist))
                                continue;
                            cos_r = dot(s.ns, l);
                            if (cos_r <= 0.0)
                                continue;
                            a = cos_r;
                            b = pmf * float(n);
                        } else {
                            n_e = cross(L.dir.xyz, L.extra.xyz);
                            area = length(n_e);
                            n_e *= 1.0 / area;
                            q = L.pos.xyz + (L.dir.xyz * x.x + L.extra.xyz * x.y);
                            C = L.power.rgb;
                            hittable = u_mis_hits && L.extra.w > 0.0;
                            weigh = true;
                        }
                    } else {
                        if (!u_tri_lights)
                            continue;
                        uint t = src - uint(u_num_lights);
                        uvec4 Tv = triangles[t];
                        pmf = tri_pmf(t);
                        area = triangle_area(t, n_e);
                        float r = sqrt(x.x), b1 = x.y * r, b0 = 1.0 - r;
                        q = position(Tv.x) * b0 + position(Tv.y) * b1 + position(Tv.z) * (1.0 - b0 - b1);
                        C = materials[Tv.w].emission.rgb;
                        hittable = true;
                        two_sided = true;
                        weigh = true;
                    }
                    if (weigh) {
                        vec3 to = q - s.p;
                        d2 = dot(to, to);
                        if (!(d2 > 0.0))
                            continue;
                        dist = sqrt(d2);
                        l = to * (1.0 / dist);
                        cos_e = is_light ? -dot(n_e, l) : abs(dot(n_e, l));
                        cos_r = dot(s.ns, l);
                        if (cos_e <= 0.0 || cos_r <= 0.0)
                            continue;
                    }
                } else if (phase == 1) {
                    phase = 2;
                    if (!env_nee_on())
                        continue;
                    seek(base + u_env_slot);
                    vec2 x = sample_2d();
                    if (!env_sample(x.x, x.y, l, b))
                        continue;
                    cos_r = dot(s.ns, l);
                    if (cos_r <= 0.0)
                        continue;
                } else if (phase == 2) {
                    if (last || !lvc_on()) {
                        phase = 3;
                    } else if (vi >= vend) {
                        if (path >= u_lv_connect) {
                            phase = 3;
                        } else {
                            seek(base + u_lv_slot + uint(path));
                            ++path;
                            float u = sample_1d();
                            uint jp = min(uint(u * float(u_lv_paths)), u_lv_paths - 1u);
                            vi = lv_offset(jp);
                            vend = lv_offset(jp + 1u);
                            continue;
                        }
                    } else {
                        uint t = u_lv_base + 6u * vi;
                        ++vi;
                        vec4 t0 = lv_texel(t), t1 = lv_texel(t + 1u), t2 = lv_texel(t + 2u);
                        vec4 t3 = lv_texel(t + 3u), t4 = lv_texel(t + 4u), t5 = lv_texel(t + 5u);
                        int index = int(t4.w);
                        /* pt's longest path: the light vertex's index and the
                         * camera depth add up to at most max_depth */
                        if (index + depth > u_max_depth) {
                            vi = vend;
                            continue;
                        }
                        Surf y;
                        y.p = t0.xyz;
                        y.mat = floatBitsToUint(t0.w);
                        y.ng = t1.xyz;
                        y.ns = t2.xyz;
                        y.v = t3.xyz;
                        y.kd = t5.rgb;
                        y.front = true;
                        y.uv = vec2(0.0);
                        y.tri = NONE;
                        vec3 to = y.p - s.p;
                        d2 = dot(to, to);
                        if (!(d2 > 0.0))
                            continue;
                        vec3 wo = to * inversesqrt(d2);
                        float cos_c = dot(s.ns, wo);
                        if (cos_c <= 0.0 || dot(s.ng, wo) <= 0.0 || dot(y.ns, -wo) <= 0.0 || dot(y.ng, -wo) <= 0.0)
                            continue;
                        float cos_y = dot(y.ng, -wo);
                        /* the BRDFs at both ends (Phong or GGX; y's GGX lobe
                         * at y.v, the camera vertex's is g_lobe) */
                        vec3 f_y;
                        if (is_ggx(y)) {
                            Ggx gy = ggx_setup(y);
                            f_y = ggx_eval_local(gy, ggx_local(gy, -wo));
                        } else {
                            f_y = phong_eval(y, -wo);
                        }
                        C = brdf_eval(s, wo) * f_y * t4.rgb * (cos_c * cos_y / d2);
                        if (!(max_comp(C) > 0.0))
                            continue;
                        /* the shadow ray to y lifted off its surface by eps */
                        vec3 target = y.p + y.ng * u_eps;
                        vec3 tt = target - s.p;
                        dist = length(tt);
                        if (!(dist > 0.0))
                            continue;
                        l = tt / dist;
                        /* the MIS weight's sum (tested after the shadow ray, as pt) */
                        float pe_i = lv_pdf(s, wo) * cos_y / d2;
                        float rev = lv_pdf_at(turned(y, -wo), y.v);
                        float l2 = t2.w + (index + 1 + depth <= u_max_depth ? t3.w : 0.0);
                        float w_light = pe_i * pe_i * (t1.w + rev * rev * l2);
                        float pl_s = lv_pdf_at(y, -wo) * abs(dot(s.ng, wo)) / d2;
                        float w_cam = pl_s * pl_s * lv_cam_a(s, wo, false);
                        a = w_light + w_cam;
                    }
                }
                if (phase == 3) {
                    /* the vertex's shadow rays are done: pt's sums, then
                     * the BRDF sample the path goes on with */
                    radiance += T * direct;
                    if (env_nee_on())
                        radiance += T * env;
                    if (last)
                        break;
                    if (lvc_on())
                        radiance += T * joins;
                    seek(base + SLOT_LOBE);
                    /* rl_pt_bsdf_needs_lobe: GGX picks a lobe, Phong where it has k_s */
                    float u0 = gen || m.pbr.z > 0.0 || max_comp(m.specular.rgb) > 0.0 ? sample_1d() : 0.0;
                    seek(base + SLOT_BSDF);
                    vec2 u12 = sample_2d();
                    vec3 w;
                    if (!brdf_sample(s, u0, u12.x, u12.y, dir, w))
                        break;
                    T *= w;
                    diffuse_ray = true;
                    after_brdf = true;
                    prev_pdf = u_mis || env_nee_on() ? brdf_pdf(s, dir) : 0.0;
                    if (lvc_on())
                        lv_leave(s, dir, false);
                    stage = PREPARE;
                }
            }

            if (stage == PREPARE) {
                prev = s.p;
                if (u_rr && depth >= u_rr_depth) {
                    float q = min(1.0, max_comp(T));
                    seek(base + SLOT_RR);
                    float xi = sample_1d();
                    if (!(xi < q))
                        break;
                    T *= 1.0 / q;
                }
                if (!(max_comp(T) > 0.0))
                    break;
                /* Sec. 11.2, 12.3: mirror and refraction rays may take another
                 * structure than the diffuse bounces */
                structure = diffuse_ray ? u_diffuse : u_specular;
                origin = offset_origin(s, dir);
                if (diffuse_ray)
                    atomicCounterIncrement(c_diffuse);
                else if (refracted)
                    atomicCounterIncrement(c_refraction);
                else
                    atomicCounterIncrement(c_reflection);
                /* the payload walks start at pt's voxel offset */
                origin_t = (may_use(STRUCT_LS_PNMT) && structure == STRUCT_LS_PNMT) ||
                           (may_use(STRUCT_LS_PREILLUM) && structure == STRUCT_LS_PREILLUM) ? max(0.0, u_ls_start)
                                                                                          : 0.0;
                stage = BOUNCE;
            }

            /* the ray: a shadow ray of u_shadow, or the bounce (the camera
             * ray first) */
            bool shadow = stage == SHADOW;
            int rs = structure;
            vec3 ro = origin, rd = dir;
            float t_min = origin_t, t_max = INF;
            int known = -1;
            if (shadow) {
                rs = u_shadow;
                known = shadow_setup(s, l, dist, light, j, ro, rd, t_min, t_max);
            }
            Hit h;
            vec3 rec_p = vec3(0.0), rec_n = vec3(0.0);
            vec2 rec_uv = vec2(0.0);
            uint rec_mat = 0u;
            bool hit = known < 0 ? ray_query(rs, ro, rd, t_min, t_max, shadow, h, rec_p, rec_n, rec_uv, rec_mat)
                                 : known == 1;

            if (shadow) {
                if (hit)
                    continue;
                if (kind == 2) {
                    if (!(isinf(a) || isnan(a)))
                        joins += C * (1.0 / ((1.0 + a) * float(u_lv_connect)));
                    continue;
                }
                if (weigh) {
                    float p_light = pmf * d2 / (area * cos_e);
                    float w = lvc_on() ? lv_nee_weight(s, l, d2, cos_e, pmf, area, two_sided, !last && hittable)
                            : !last && hittable ? power_heuristic(float(n) * p_light, bsdf_pdf(s, l)) : 1.0;
                    a = w * cos_r;
                    b = p_light * float(n);
                } else if (kind == 1) {
                    float w = !last ? power_heuristic(b, bsdf_pdf(s, l)) : 1.0;
                    C = env_radiance(l);
                    a = w * cos_r;
                }
                vec3 f = brdf_eval(s, l) * (C * (a / b));
                if (kind == 0)
                    direct += f;
                else
                    env += f;
                continue;
            }
            if (camera && !hit)
                return miss;
            /* (the camera ray's structure is the BVH) */
            if (may_use(STRUCT_LS_PREILLUM) && structure == STRUCT_LS_PREILLUM) {
                /* the stored direct light ends the path (Sec. 7.4) */
                radiance += T * (hit ? rec_p : escaped(dir, after_brdf, prev_pdf));
                break;
            }
            Surf next;
            if (!hit || !surface_of_hit(structure, origin, dir, h, rec_p, rec_n, rec_uv, rec_mat, next)) {
                radiance += T * escaped(dir, after_brdf, prev_pdf);
                break;
            }
            if (camera) {
                /* the first hit: the path starts */
                camera = false;
                s = next;
                prev = s.p;
                stage = VERTEX;
                continue;
            }
            if (lvc_on())
                lv_arrive(next, s.p);
            s = next;
            ++depth;
            stage = VERTEX;
        }
        return radiance;
    }

    void main()
    {
        ivec2 px = ivec2(gl_GlobalInvocationID.xy);
        if (px.x >= u_size.x || px.y >= u_size.y)
            return;
        /* pathtrace.c active(): the other half waits for the next frame */
        uint cls = uint(px.x + px.y) & 1u;
        if (u_checker && cls != u_parity)
            return;
        uint held = u_held[cls];
        if (u_adaptive) {
            uvec2 a = imageLoad(u_adapt, px).xy;
            if (u_round_k >= a.y)
                return;
            held = a.x + u_round_k;
        }
        g_state = imageLoad(u_rng_state, px);
        g_index = held;
        g_slot = 0u;
        /* the pixel-centre ray: primary=raster's, and the one whose
         * environment radiance pt's uniform passes give a pixel whose
         * camera ray leaves the scene (pathtrace.c path_tile) */
        float cx = (2.0 * (float(px.x) + 0.5) / float(u_size.x) - 1.0) * u_tan_half_fov * u_aspect;
        float cy = (1.0 - 2.0 * (float(px.y) + 0.5) / float(u_size.y)) * u_tan_half_fov;
        vec3 centre = normalize(u_cam_u * cx + u_cam_v * cy - u_cam_w);
        vec3 L = env_on() ? env_radiance(centre) : u_background;
        /* one call of trace_path for both kinds of first hit: Mesa inlines
         * a function at every call, and two calls were two copies of the
         * whole path program (docs/gl.md, "One ray site") */
        Surf first;
        bool go = true;
        vec3 dir = centre;
        if (u_raster) {
            /* the G-buffer's pixel centre: no jitter, no number drawn */
            uint tri = texelFetch(u_ids, px, 0).x;
            go = tri < uint(triangles.length()) && surface_of_pixel(tri, u_eye, centre, first);
        } else {
            seek(SLOT_PIXEL);
            vec2 j = sample_2d();
            /* rl_camera_frame_ray: image plane at distance 1, rows downwards */
            float sx = (2.0 * (float(px.x) + j.x) / float(u_size.x) - 1.0) * u_tan_half_fov * u_aspect;
            float sy = (1.0 - 2.0 * (float(px.y) + j.y) / float(u_size.y)) * u_tan_half_fov;
            dir = normalize(u_cam_u * sx + u_cam_v * sy - u_cam_w);
            atomicCounterIncrement(c_primary);
        }
        if (go)
            L = trace_path(u_raster, first, u_eye, dir, L);
        /* A NaN or infinity would poison the pixel's mean for good; it
         * counts as black, as pt counts the sample but adds nothing. */
        if (!finite3(L))
            L = vec3(0.0);
        if (u_rng != 0)
            imageStore(u_rng_state, px, g_state);
        /* Sec. 6.5, eq. 8: C_{s+1} = s/(s+1) C_s + 1/(s+1) C_trace */
        float n = float(held);
        vec4 c = held == 0u ? vec4(0.0) : imageLoad(u_accum, px);
        /* adaptive: alpha the mean squared luminance, as pt's sum2 */
        float a = 1.0;
        if (u_adaptive) {
            float l = 0.2126 * L.x + 0.7152 * L.y + 0.0722 * L.z;
            a = c.a * (n / (n + 1.0)) + l * l * (1.0 / (n + 1.0));
        }
        imageStore(u_accum, px, vec4(c.rgb * (n / (n + 1.0)) + L * (1.0 / (n + 1.0)), a));
    }
);

/* Adaptive sampling's passes (pathtrace.c pixel_errors, adaptive_shares),
 * one program of 64 threads per work group, by u_mode:
 *   0 errors: per pixel the relative error of the mean e = sqrt(s^2 / n) /
 *     (mean + 0.05) of the luminance (-1 under two samples), from the
 *     accumulation's running means of L and of l^2;
 *   1 smooth: e averaged over the 3 x 3 neighbours that have one (infinite
 *     where none has), and the pixels below the threshold counted;
 *   2 shares: ONE work group: the water-filling t_i = min(cap, lambda e_i)
 *     with sum t_i = budget (lambda by 50 bisection steps when the cap
 *     binds), rounded by the running sum in pixel order, as pt; the sum
 *     runs in units of 1/1024 sample held exactly in doubles, so that each
 *     thread's contiguous chunk can start from an exact prefix;
 *   3 commit: samples held += share. */
const char *const rl_gl_pt_glsl_adapt = GLSL(
    layout(local_size_x = 64) in;
    /* image unit 3 and storage 14-15: none of the path program's, so that
     * the passes and the path dispatches need no rebinding */
    layout(rgba32f, binding = 3) uniform readonly image2D u_accum;
    layout(rg32ui, binding = 2) uniform uimage2D u_adapt;
    layout(std430, binding = 14) buffer Errors { float err[]; };   /* raw, then smoothed */
    layout(std430, binding = 15) buffer Totals {
        uint max_share;
        uint converged;
        uint pad0;
        uint pad1;
        double given;
    };
    uniform int u_mode;
    uniform ivec2 u_size;
    uniform float u_thr;
    uniform double u_budget;
    uniform double u_num_active;

    shared double sh_sum[64];
    shared float sh_hi[64];
    shared float sh_lo[64];
    shared uint sh_n[64];
    shared uint sh_max;

    const float INF_E = uintBitsToFloat(0x7f800000u);

    /* wants_samples: not converged, and an error above zero */
    bool wants(float e) { return !isinf(e) && !isnan(e) && e >= u_thr && e > 0.0; }

    void shares()
    {
        uint t = gl_LocalInvocationID.x;
        uint n = uint(u_size.x) * uint(u_size.y);
        uint chunk = (n + 63u) / 64u;
        uint b = min(n, t * chunk), end = min(n, b + chunk);
        double total = 0.0;
        float e_max = 0.0, e_min = INF_E;
        uint positive = 0u;
        for (uint i = b; i < end; ++i) {
            float e = err[n + i];
            if (!wants(e))
                continue;
            total += double(e);
            e_max = max(e_max, e);
            e_min = min(e_min, e);
            ++positive;
        }
        sh_sum[t] = total;
        sh_hi[t] = e_max;
        sh_lo[t] = e_min;
        sh_n[t] = positive;
        if (t == 0u)
            sh_max = 0u;
        barrier();
        double T = 0.0;
        float E_max = 0.0, E_min = INF_E;
        uint P = 0u;
        for (uint k = 0u; k < 64u; ++k) {
            T += sh_sum[k];
            E_max = max(E_max, sh_hi[k]);
            E_min = min(E_min, sh_lo[k]);
            P += sh_n[k];
        }
        barrier();
        double cap = 8.0 * u_budget / u_num_active;
        bool none = P == 0u || !(T > 0.0);
        /* all: every pixel that wants samples takes the cap */
        bool all = !none && double(P) * cap <= u_budget;
        double lambda = none ? 0.0 : u_budget / T;
        if (!none && !all && lambda * double(E_max) > cap) {
            double lo = lambda, hi = cap / double(E_min);
            for (int it = 0; it < 50; ++it) {
                double mid = 0.5 * (lo + hi), part = 0.0;
                for (uint i = b; i < end; ++i) {
                    float e = err[n + i];
                    if (wants(e))
                        part += min(cap, mid * double(e));
                }
                sh_sum[t] = part;
                barrier();
                double got = 0.0;
                for (uint k = 0u; k < 64u; ++k)
                    got += sh_sum[k];
                barrier();
                if (got < u_budget)
                    lo = mid;
                else
                    hi = mid;
            }
            lambda = hi;
        }
        /* the chunk's sum in 1/1024 samples (integers: exact in double) */
        double q_sum = 0.0;
        for (uint i = b; i < end && !none; ++i) {
            float e = err[n + i];
            if (wants(e))
                q_sum += floor((all ? cap : min(cap, lambda * double(e))) * 1024.0 + 0.5);
        }
        sh_sum[t] = q_sum;
        barrier();
        double run = 0.0, all_q = 0.0;
        for (uint k = 0u; k < 64u; ++k) {
            if (k < t)
                run += sh_sum[k];
            all_q += sh_sum[k];
        }
        double prev = floor(run / 1024.0 + 0.5);
        uint most = 0u;
        for (uint i = b; i < end; ++i) {
            ivec2 px = ivec2(int(i % uint(u_size.x)), int(i / uint(u_size.x)));
            uvec2 a = imageLoad(u_adapt, px).xy;
            uint share = 0u;
            float e = err[n + i];
            if (!none && wants(e)) {
                run += floor((all ? cap : min(cap, lambda * double(e))) * 1024.0 + 0.5);
                double upto = floor(run / 1024.0 + 0.5);
                share = uint(upto - prev);
                prev = upto;
            }
            imageStore(u_adapt, px, uvec4(a.x, share, 0u, 0u));
            most = max(most, share);
        }
        atomicMax(sh_max, most);
        barrier();
        if (t == 0u) {
            max_share = sh_max;
            given = none ? 0.0 : floor(all_q / 1024.0 + 0.5);
        }
    }

    void main()
    {
        if (u_mode == 2) {
            shares();
            return;
        }
        /* rows of work groups beyond 65535 (the least dispatch size GL allows) */
        uint i = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * 64u;
        uint n = uint(u_size.x) * uint(u_size.y);
        if (i >= n)
            return;
        ivec2 px = ivec2(int(i % uint(u_size.x)), int(i / uint(u_size.x)));
        uvec2 a = imageLoad(u_adapt, px).xy;
        if (u_mode == 0) {
            if (a.x < 2u) {
                err[i] = -1.0;
                return;
            }
            vec4 c = imageLoad(u_accum, px);
            double cnt = double(a.x);
            double mean = 0.2126 * double(c.x) + 0.7152 * double(c.y) + 0.0722 * double(c.z);
            double var = (double(c.w) - mean * mean) * cnt / (cnt - 1.0);
            err[i] = float(sqrt(max(var, 0.0) / cnt) / (abs(mean) + 0.05));
        } else if (u_mode == 1) {
            double sum = 0.0;
            int k = 0;
            for (int y = max(px.y - 1, 0); y <= px.y + 1 && y < u_size.y; ++y)
                for (int x = max(px.x - 1, 0); x <= px.x + 1 && x < u_size.x; ++x) {
                    float e = err[uint(y) * uint(u_size.x) + uint(x)];
                    if (e >= 0.0) {
                        sum += double(e);
                        ++k;
                    }
                }
            float sm = k > 0 ? float(sum / double(k)) : INF_E;
            err[n + i] = sm;
            if (sm < u_thr)
                atomicAdd(converged, 1u);
        } else {
            imageStore(u_adapt, px, uvec4(a.x + a.y, 0u, 0u, 0u));
        }
    }
);

/* The shadow maps' depth pass (raster/shadowmap.c render_face): one cube
 * face from the light's point u_sm_eye, the light's casters list pulled by
 * gl_VertexID. The face's frame with unit focal
 * length, y negated so that GL's row 0 is the face's top row as the CPU
 * stores it; clip z is gluPerspective's between the CPU's near and far
 * planes (clipping as the CPU clips). */
const char *const rl_gl_pt_glsl_shadow_vs = GLSL(
    layout(std430, binding = 14) readonly buffer Casters { uint casters[]; };
    uniform vec3 u_sm_eye;
    uniform vec3 u_face_s;
    uniform vec3 u_face_u;
    uniform vec3 u_face_axis;
    uniform float u_near;
    uniform float u_far;
    out float v_depth;
    out vec2 v_uv;
    flat out uint v_material;

    void main()
    {
        uvec4 T = triangles[casters[uint(gl_VertexID) / 3u]];
        uint k = uint(gl_VertexID) % 3u;
        uint vi = k == 0u ? T.x : (k == 1u ? T.y : T.z);
        vec3 d = position(vi) - u_sm_eye;
        float z = dot(d, u_face_axis);
        v_depth = z;
        v_uv = uv_at(vi);
        v_material = T.w;
        gl_Position = vec4(dot(d, u_face_s), -dot(d, u_face_u),
                           (u_far + u_near) / (u_far - u_near) * z - 2.0 * u_far * u_near / (u_far - u_near), z);
    }
);

/* The eye depth, perspective-correct as the software rasterizer's 1 / (1/w)
 * interpolation, into the colour attachment; the depth test on it scaled
 * by the far plane (linear, full float precision, where gluPerspective's
 * window depth would merge surfaces close together far from the light).
 * raster_fill.c mask_keeps: a fragment in an alpha mask's hole is none. */
const char *const rl_gl_pt_glsl_shadow_fs = GLSL(
    in float v_depth;
    in vec2 v_uv;
    flat in uint v_material;
    uniform float u_far;
    layout(location = 0) out float o_depth;

    void main()
    {
        if (u_masks) {
            Material m = materials[v_material];
            if (m.tex.z != NONE && tex_sample(m.tex.z, v_uv).w < m.extra.z)
                discard;
        }
        o_depth = v_depth;
        gl_FragDepth = clamp(v_depth / u_far, 0.0, 1.0);
    }
);

/* The ray set of rl_gl_pt_trace through one structure. */
const char *const rl_gl_pt_glsl_rays = GLSL(
    layout(local_size_x = 64) in;
    struct Ray { vec4 o; vec4 d; };                  /* w: t_min, t_max */
    layout(std430, binding = 14) readonly buffer Rays { Ray rays[]; };
    layout(std430, binding = 15) writeonly buffer Hits { Hit hits[]; };
    uniform uint u_count;
    uniform int u_structure;
    uniform bool u_any;

    void main()
    {
        uint i = gl_GlobalInvocationID.x;
        if (i >= u_count)
            return;
        Ray r = rays[i];
        Hit h;
        if (!query(u_structure, r.o.xyz, r.d.xyz, r.o.w, r.d.w, u_any, h))
            h = Hit(INF, 0.0, 0.0, NONE);
        hits[i] = h;
    }
);

#endif
