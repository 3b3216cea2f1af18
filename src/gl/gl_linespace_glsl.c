/* gl_linespace_glsl.c: the Line Space walk in GLSL 4.50 (gl_linespace.h),
 * the candidate queries of linespace_query.c (Schröder 2017, Sec. 7.2):
 * the 3D-DDA of grid.c over the voxels, in each filled voxel the shaft of
 * the ray's line (entry and exit points in double, cell units, as
 * shaft_of_ray), its occupancy bit and rank, then the watertight test
 * (watertight.h) on the shaft's candidates against the whole ray.
 *
 * Every float expression that the CPU evaluates without FMA is marked
 * `precise` here, so that a GL compiler that would fuse or reorder it gives
 * the CPU's bits: the same voxels, shafts and hits, ray for ray (the test
 * compares them). Deviation: no mailbox (a re-test of a triangle gives the
 * same answer, the CPU's mailbox only saves time), and no alpha masks (the
 * GL Line Space refuses masked scenes, gl_linespace.c). */
#include "gl/gl_linespace.h"

#define GLSL(...) #__VA_ARGS__ "\n"

static const char *const walk_glsl =
    "#define RL_LS_NONE 0xffffffffu\n"
    "#define RL_LS_INF uintBitsToFloat(0x7f800000u)\n"
    GLSL(
    layout(std430, binding = 16) readonly buffer RlLsVoxels { uint rl_ls_voxel_slot[]; };
    layout(std430, binding = 17) readonly buffer RlLsOcc { uvec4 rl_ls_occ[]; };
    layout(std430, binding = 18) readonly buffer RlLsCand { uint rl_ls_cand[]; };
    layout(std430, binding = 19) readonly buffer RlLsStart { uint rl_ls_cand_start[]; };
    layout(std430, binding = 20) readonly buffer RlLsPnmt { uint rl_ls_pnmt[]; };
    layout(std430, binding = 21) readonly buffer RlLsPreillum { uint rl_ls_preillum_rec[]; };
    layout(std430, binding = 22) readonly buffer RlLsTris { float rl_ls_tri_v[]; };
    layout(std430, binding = 23) readonly buffer RlLsCells { uint rl_ls_cells[]; };

    uniform int u_ls_n;
    uniform int u_ls_k;
    uniform bool u_ls_dynamic;
    uniform bool u_ls_has_cand;
    uniform ivec3 u_ls_res;
    uniform vec3 u_ls_min;
    uniform vec3 u_ls_max;
    uniform vec3 u_ls_cell;
    uniform vec3 u_ls_inv_cell;
    uniform uint u_ls_occ_words;
    uniform uint u_ls_cell_tris_at;
    uniform bool u_ls_has_pnmt;
    uniform bool u_ls_has_preillum;
    uniform bool u_ls_origin_exact;

    /* grid.c's plane(): bounds.min + k * cell_size. */
    float rl_ls_plane(int a, int k)
    {
        precise float p = u_ls_min[a] + float(k) * u_ls_cell[a];
        return p;
    }

    /* The DDA state (grid.h). */
    struct RlLsDda {
        ivec3 cur, cell, step;
        vec3 tmax, o, inv;
        float t, t_end;
        bool done;
    };

    bool rl_ls_dda_begin(vec3 o, vec3 d, float t_min, float t_max, out RlLsDda it)
    {
        precise float t_in = -RL_LS_INF, t_out = RL_LS_INF;
        vec3 inv = vec3(0.0);
        it.done = true;
        for (int a = 0; a < 3; ++a) {
            if (d[a] == 0.0) {
                if (o[a] < u_ls_min[a] || o[a] > u_ls_max[a])
                    return false;
                inv[a] = RL_LS_INF;
                continue;
            }
            precise float ia = 1.0 / d[a];
            inv[a] = ia;
            precise float tn = (u_ls_min[a] - o[a]) * ia;
            precise float tf = (u_ls_max[a] - o[a]) * ia;
            if (tn > tf) {
                float s = tn;
                tn = tf;
                tf = s;
            }
            t_in = tn > t_in ? tn : t_in;
            t_out = tf < t_out ? tf : t_out;
        }
        precise float slack = 1e-6 * max(abs(t_in), abs(t_out));
        precise float t0 = max(t_min, t_in - slack);
        precise float t1 = min(t_max, t_out + slack);
        if (!(t0 <= t1))
            return false;
        it.t = t0;
        it.t_end = t1;
        it.o = o;
        it.inv = inv;
        it.done = false;
        for (int a = 0; a < 3; ++a) {
            precise float entry = d[a] == 0.0 ? o[a] : o[a] + d[a] * t0;
            precise float f = floor((entry - u_ls_min[a]) * u_ls_inv_cell[a]);
            int c = !(f >= 0.0) ? 0 : (f >= float(u_ls_res[a] - 1) ? u_ls_res[a] - 1 : int(f));
            it.cell[a] = c;
            it.cur[a] = c;
            if (d[a] == 0.0) {
                it.step[a] = 0;
                it.tmax[a] = RL_LS_INF;
            } else {
                it.step[a] = d[a] > 0.0 ? 1 : -1;
                precise float tm = (rl_ls_plane(a, c + (d[a] > 0.0 ? 1 : 0)) - o[a]) * inv[a];
                it.tmax[a] = tm;
            }
        }
        return true;
    }

    bool rl_ls_dda_next(inout RlLsDda it, out uint cell, out float t0, out float t1)
    {
        if (it.done)
            return false;
        it.cur = it.cell;
        cell = uint(it.cell.x) + uint(u_ls_res.x) * (uint(it.cell.y) + uint(u_ls_res.y) * uint(it.cell.z));
        t0 = it.t;
        int a = it.tmax.x < it.tmax.y ? (it.tmax.x < it.tmax.z ? 0 : 2) : (it.tmax.y < it.tmax.z ? 1 : 2);
        float cross = it.tmax[a];
        if (!(cross < it.t_end)) {
            t1 = it.t_end;
            it.done = true;
            return true;
        }
        float t = cross > it.t ? cross : it.t;
        t1 = t;
        it.t = t;
        it.cell[a] += it.step[a];
        if (it.cell[a] < 0 || it.cell[a] >= u_ls_res[a]) {
            it.done = true;
            return true;
        }
        int k = it.cell[a] + (it.step[a] > 0 ? 1 : 0);
        precise float tm = (rl_ls_plane(a, k) - it.o[a]) * it.inv[a];
        it.tmax[a] = tm;
        return true;
    }

    /* rl_ls_shaft_index for fa != fb (linespace_shaft.c). */
    uint rl_ls_shaft_index(int fa, int pa, int fb, int pb, out bool fwd)
    {
        fwd = fa < fb;
        if (!fwd) {
            int t = fa; fa = fb; fb = t;
            t = pa; pa = pb; pb = t;
        }
        int np = u_ls_n * u_ls_n;
        int pair = fa * 5 - fa * (fa - 1) / 2 + (fb - fa - 1);
        return uint(pair) * uint(np * np) + uint(pa) * uint(np) + uint(pb);
    }

    void rl_ls_nearest_faces(dvec3 e, out int best, out double best_d, out int second, out double second_d)
    {
        best = -1;
        second = -1;
        best_d = double(RL_LS_INF);
        second_d = best_d;
        for (int f = 0; f < 6; ++f) {
            double d = abs((f & 1) != 0 ? 1.0LF - e[f >> 1] : e[f >> 1]);
            if (d < best_d) {
                second = best;
                second_d = best_d;
                best = f;
                best_d = d;
            } else if (d < second_d) {
                second = f;
                second_d = d;
            }
        }
    }

    int rl_ls_patch_of(int f, dvec3 e)
    {
        int a = f >> 1;
        int u = a == 0 ? 1 : 0, v = a == 2 ? 1 : 2;
        double fu = floor(e[u] * double(u_ls_n)), fv = floor(e[v] * double(u_ls_n));
        int i = fu < 0.0LF ? 0 : (fu > double(u_ls_n - 1) ? u_ls_n - 1 : int(fu));
        int j = fv < 0.0LF ? 0 : (fv > double(u_ls_n - 1) ? u_ls_n - 1 : int(fv));
        return i + u_ls_n * j;
    }

    /* shaft_of_ray (linespace_query.c) for the line lo + t·ld in cell
     * units of the whole grid, in voxel xyz. */
    uint rl_ls_shaft_of_ray(ivec3 xyz, dvec3 lo, dvec3 ld, dvec3 linv, out bool fwd)
    {
        fwd = true;
        precise dvec3 o;
        precise double tn = -double(RL_LS_INF), tf = double(RL_LS_INF);
        for (int a = 0; a < 3; ++a) {
            o[a] = lo[a] - double(xyz[a]);
            if (ld[a] == 0.0LF) {
                if (o[a] < 0.0LF || o[a] > 1.0LF)
                    return RL_LS_NONE;
                continue;
            }
            precise double t0 = -o[a] * linv[a];
            precise double t1 = (1.0LF - o[a]) * linv[a];
            if (t0 > t1) {
                double s = t0; t0 = t1; t1 = s;
            }
            tn = t0 > tn ? t0 : tn;
            tf = t1 < tf ? t1 : tf;
        }
        if (!(tn <= tf) || isinf(tn) || isinf(tf) || isnan(tn) || isnan(tf))
            return RL_LS_NONE;
        precise dvec3 en, ex;
        for (int a = 0; a < 3; ++a) {
            en[a] = o[a] + ld[a] * tn;
            ex[a] = o[a] + ld[a] * tf;
        }
        int f0, f1, s0, s1;
        double d0, d1, sd0, sd1;
        rl_ls_nearest_faces(en, f0, d0, s0, sd0);
        rl_ls_nearest_faces(ex, f1, d1, s1, sd1);
        if (f0 == f1) {
            if (sd0 <= sd1 && sd0 <= 1e-5LF)
                f0 = s0;
            else if (sd1 <= 1e-5LF)
                f1 = s1;
            else
                return RL_LS_NONE;
        }
        return rl_ls_shaft_index(f0, rl_ls_patch_of(f0, en), f1, rl_ls_patch_of(f1, ex), fwd);
    }

    bool rl_ls_occupied(uint block, uint shaft, out uint rank)
    {
        uvec4 w = rl_ls_occ[block * u_ls_occ_words + (shaft >> 6u)];
        uint bit = shaft & 63u;
        uint lo_mask = bit >= 32u ? 0xffffffffu : (1u << bit) - 1u;
        uint hi_mask = bit >= 32u ? (1u << (bit - 32u)) - 1u : 0u;
        rank = w.z + uint(bitCount(w.x & lo_mask)) + uint(bitCount(w.y & hi_mask));
        uint word = bit >= 32u ? w.y : w.x;
        return ((word >> (bit & 31u)) & 1u) != 0u;
    }

    /* The list to test in a filled voxel (candidates()): [first, first +
     * count) of rl_ls_cand, or of the cell list when from_cells. */
    void rl_ls_list(uint cell, uint shaft, uint rank, out uint first, out uint count, out bool from_cells)
    {
        from_cells = shaft == RL_LS_NONE || !u_ls_has_cand;
        if (from_cells) {
            first = u_ls_cell_tris_at + rl_ls_cells[cell];
            count = rl_ls_cells[cell + 1u] - rl_ls_cells[cell];
        } else if (u_ls_dynamic) {
            first = rl_ls_cand_start[rank];
            count = rl_ls_cand_start[rank + 1u] - first;
        } else {
            first = rank * uint(u_ls_k);
            count = uint(u_ls_k);
        }
    }

    /* The ray in watertight form (rl_ray_watertight_setup). */
    struct RlLsWt {
        int kx, ky, kz;
        float sx, sy, sz;
        vec3 o;
    };

    RlLsWt rl_ls_wt_setup(vec3 o, vec3 d)
    {
        RlLsWt w;
        float ax = abs(d.x), ay = abs(d.y), az = abs(d.z);
        w.kz = ax > ay ? (ax > az ? 0 : 2) : (ay > az ? 1 : 2);
        w.kx = w.kz == 2 ? 0 : w.kz + 1;
        w.ky = w.kx == 2 ? 0 : w.kx + 1;
        float dz = d[w.kz];
        if (dz < 0.0) {
            int s = w.kx; w.kx = w.ky; w.ky = s;
        }
        precise float sx = d[w.kx] / dz, sy = d[w.ky] / dz, sz = 1.0 / dz;
        w.sx = sx;
        w.sy = sy;
        w.sz = sz;
        w.o = o;
        return w;
    }

    /* rl_watertight_hit_k (watertight.h), operation for operation. */
    bool rl_ls_wt_hit(RlLsWt w, uint id, float t_min, float t_max, out float t, out float u, out float v)
    {
        uint b = 9u * id;
        vec3 p0 = vec3(rl_ls_tri_v[b], rl_ls_tri_v[b + 1u], rl_ls_tri_v[b + 2u]);
        vec3 p1 = vec3(rl_ls_tri_v[b + 3u], rl_ls_tri_v[b + 4u], rl_ls_tri_v[b + 5u]);
        vec3 p2 = vec3(rl_ls_tri_v[b + 6u], rl_ls_tri_v[b + 7u], rl_ls_tri_v[b + 8u]);
        float oz = w.o[w.kz], ox = w.o[w.kx], oy = w.o[w.ky];
        precise float Az = p0[w.kz] - oz, Bz = p1[w.kz] - oz, Cz = p2[w.kz] - oz;
        precise float Ax = (p0[w.kx] - ox) - w.sx * Az, Ay = (p0[w.ky] - oy) - w.sy * Az;
        precise float Bx = (p1[w.kx] - ox) - w.sx * Bz, By = (p1[w.ky] - oy) - w.sy * Bz;
        precise float Cx = (p2[w.kx] - ox) - w.sx * Cz, Cy = (p2[w.ky] - oy) - w.sy * Cz;
        precise float U = Cx * By - Cy * Bx;
        precise float V = Ax * Cy - Ay * Cx;
        precise float W = Bx * Ay - By * Ax;
        if (U == 0.0 || V == 0.0 || W == 0.0) {
            precise double dU = double(Cx) * double(By) - double(Cy) * double(Bx);
            precise double dV = double(Ax) * double(Cy) - double(Ay) * double(Cx);
            precise double dW = double(Bx) * double(Ay) - double(By) * double(Ax);
            U = float(dU);
            V = float(dV);
            W = float(dW);
        }
        if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0))
            return false;
        precise float det = U + V + W;
        if (det == 0.0)
            return false;
        precise float Azs = Az * w.sz, Bzs = Bz * w.sz, Czs = Cz * w.sz;
        precise float T = U * Azs + V * Bzs + W * Czs;
        float det_abs = abs(det), T_abs = det < 0.0 ? -T : T;
        if (t_min >= 0.0 && T_abs <= 0.0)
            return false;
        precise float bound = t_max * det_abs * (1.0 + 1.52587890625e-05);
        if (bound > 7.888609052210118e-31 && T_abs > bound)
            return false;
        precise float th = T / det;
        if (!(th > t_min && th < t_max))
            return false;
        precise float uu = V / det, vv = W / det;
        t = th;
        u = uu;
        v = vv;
        return true;
    }

    /* nextafterf(t, +inf) for the limit behind a hit. */
    float rl_ls_next_up(float t)
    {
        if (t == 0.0)
            return uintBitsToFloat(1u);
        uint b = floatBitsToUint(t);
        return uintBitsToFloat(t > 0.0 ? b + 1u : b - 1u);
    }

    bool rl_ls_ray_ok(vec3 o, vec3 d, float t_min, float t_max)
    {
        if (any(isinf(o)) || any(isnan(o)) || any(isinf(d)) || any(isnan(d)) || isinf(t_min) || isnan(t_min))
            return false;
        if (d.x == 0.0 && d.y == 0.0 && d.z == 0.0)
            return false;
        return t_min <= t_max;
    }

    /* cell_line_setup (linespace_query.c). */
    void rl_ls_line(vec3 o, vec3 d, out dvec3 lo, out dvec3 ld, out dvec3 linv)
    {
        for (int a = 0; a < 3; ++a) {
            double size = double(u_ls_cell[a]);
            precise double x = (double(o[a]) - double(u_ls_min[a])) / size;
            precise double y = double(d[a]) / size;
            lo[a] = x;
            ld[a] = y;
            precise double iy = y != 0.0LF ? 1.0LF / y : 0.0LF;
            linv[a] = iy;
        }
    }

    /* The start of every walk: a valid ray, the 3D-DDA over the voxels
     * and the ray's line in cell units (for its shafts); false where the
     * ray can hit nothing. */
    bool rl_ls_walk_begin(vec3 o, vec3 d, float t_min, float t_max, out RlLsDda it, out dvec3 lo, out dvec3 ld,
                          out dvec3 linv)
    {
        if (!rl_ls_ray_ok(o, d, t_min, t_max) || !rl_ls_dda_begin(o, d, t_min, t_max, it))
            return false;
        rl_ls_line(o, d, lo, ld, linv);
        return true;
    }

    /* The payload walks' exact origin rule (ls_origin=exact, Sec. 12.1):
     * whether the ray starts inside the box, so that its first voxel is
     * the start voxel. */
    bool rl_ls_starts_inside(vec3 o, vec3 d, float t_min)
    {
        precise vec3 start = o + d * t_min;
        return u_ls_origin_exact && all(greaterThanEqual(start, u_ls_min)) && all(lessThanEqual(start, u_ls_max));
    }

    /* The candidate lists' walk (linespace_query.c): the closest hit, or
     * with any the first hit in (t_min, t_max), the any-hit query of
     * shadow rays (that hit is the first the closest-hit walk accepts, so
     * both answer the same rays alike). One function for both, so that a
     * program with one ray site holds one copy of the walk. */
    bool rl_ls_cand_walk(vec3 o, vec3 d, float t_min, float t_max, bool any, out uint tri, out float t, out float u,
                         out float v)
    {
        tri = RL_LS_NONE;
        t = t_max;
        u = 0.0;
        v = 0.0;
        RlLsDda it;
        dvec3 lo, ld, linv;
        if (!rl_ls_walk_begin(o, d, t_min, t_max, it, lo, ld, linv))
            return false;
        RlLsWt w = rl_ls_wt_setup(o, d);
        float limit = t_max;
        uint cell;
        float t0, t1;
        while (rl_ls_dda_next(it, cell, t0, t1)) {
            uint block = rl_ls_voxel_slot[cell];
            if (block != RL_LS_NONE) {
                bool fwd;
                uint shaft = rl_ls_shaft_of_ray(it.cur, lo, ld, linv, fwd);
                uint rank = 0u;
                if (shaft == RL_LS_NONE || rl_ls_occupied(block, shaft, rank)) {
                    uint first, count;
                    bool from_cells;
                    rl_ls_list(cell, shaft, rank, first, count, from_cells);
                    for (uint j = 0u; j < count; ++j) {
                        uint id = from_cells ? rl_ls_cells[first + j] : rl_ls_cand[first + j];
                        float th, uh, vh;
                        if (id == RL_LS_NONE || !rl_ls_wt_hit(w, id, t_min, limit, th, uh, vh))
                            continue;
                        if (tri == RL_LS_NONE || th < t || (th == t && id < tri)) {
                            tri = id;
                            t = th;
                            u = uh;
                            v = vh;
                            if (any)
                                return true;
                            limit = rl_ls_next_up(th);
                        }
                    }
                }
            }
            precise float stop = t1 - 1e-6 * abs(t1);
            if (tri != RL_LS_NONE && t <= stop)
                break;
        }
        return tri != RL_LS_NONE;
    }

    bool rl_ls_intersect(vec3 o, vec3 d, float t_min, float t_max, out uint tri, out float t, out float u,
                         out float v)
    {
        return rl_ls_cand_walk(o, d, t_min, t_max, false, tri, t, u, v);
    }

    bool rl_ls_occluded(vec3 o, vec3 d, float t_min, float t_max)
    {
        uint tri;
        float t, u, v;
        return rl_ls_cand_walk(o, d, t_min, t_max, true, tri, t, u, v);
    }
    /* ---- PNMT (Sec. 7.4; linespace_query.c pnmt_walk) ---- */

    float rl_ls_half(uint rank, int i)
    {
        vec2 h = unpackHalf2x16(rl_ls_pnmt[rank * 8u + uint(i >> 1)]);
        return (i & 1) == 0 ? h.x : h.y;
    }

    /* decode_pnmt: the record of direction fwd of occupied shaft `rank`
     * in voxel xyz; false for an empty record. */
    bool rl_ls_pnmt_decode(ivec3 xyz, uint rank, bool fwd, out vec3 p, out vec3 n, out vec2 uv, out uint material)
    {
        int b = fwd ? 0 : 8;
        float m = rl_ls_half(rank, b + 5);
        float a = m < 0.0 ? -m : m;
        p = vec3(0.0);
        n = vec3(0.0);
        uv = vec2(0.0);
        material = 0u;
        if (!(a >= 1.0 && a <= 65504.0))
            return false;
        precise float mid = a - 1.0 + 0.5;
        material = uint(mid);
        for (int k = 0; k < 3; ++k) {
            float lo = rl_ls_plane(k, xyz[k]), hi = rl_ls_plane(k, xyz[k] + 1);
            precise float ext = hi - lo;
            precise float x = lo + rl_ls_half(rank, b + k) * ext;
            p[k] = x;
        }
        float nx = rl_ls_half(rank, b + 3), ny = rl_ls_half(rank, b + 4);
        precise float q = 1.0 - nx * nx - ny * ny;
        precise float nz = sqrt(0.0 > q ? 0.0 : q);
        n = vec3(nx, ny, m < 0.0 ? -nz : nz);
        uv = vec2(rl_ls_half(rank, b + 6), rl_ls_half(rank, b + 7));
        return true;
    }

    float rl_ls_project_t(vec3 o, vec3 d, vec3 p)
    {
        precise vec3 q = p - o;
        precise float num = q.x * d.x + q.y * d.y + q.z * d.z;
        precise float den = d.x * d.x + d.y * d.y + d.z * d.z;
        precise float t = num / den;
        return t;
    }

    /* voxel_within: every point of voxel xyz projects inside (lo, t_max). */
    bool rl_ls_voxel_within(ivec3 xyz, vec3 o, vec3 d, float lo, float t_max, float r)
    {
        vec3 c;
        for (int k = 0; k < 3; ++k) {
            precise float x = (rl_ls_plane(k, xyz[k]) + rl_ls_plane(k, xyz[k] + 1)) * 0.5;
            c[k] = x;
        }
        float tc = rl_ls_project_t(o, d, c);
        precise float slack = 1e-4 * r + 1e-6 * abs(tc);
        precise float a = tc - r - slack, b = tc + r + slack;
        return a > lo && b < t_max;
    }

    /* origin_hit: the closest hit among the start voxel's triangles (the
     * shaft's dynamic list, else the cell's) before the voxel's exit t1. */
    bool rl_ls_origin_hit(RlLsWt w, uint cell, uint shaft, uint rank, float t_min, float t_max, float t1,
                          out uint tri, out float t)
    {
        precise float end = t1 + 1e-6 * abs(t1);
        float limit = min(t_max, end);
        tri = RL_LS_NONE;
        t = limit;
        uint first, count;
        bool from_cells = shaft == RL_LS_NONE || !u_ls_has_cand || !u_ls_dynamic;
        if (from_cells) {
            first = u_ls_cell_tris_at + rl_ls_cells[cell];
            count = rl_ls_cells[cell + 1u] - rl_ls_cells[cell];
        } else {
            first = rl_ls_cand_start[rank];
            count = rl_ls_cand_start[rank + 1u] - first;
        }
        for (uint j = 0u; j < count; ++j) {
            uint id = from_cells ? rl_ls_cells[first + j] : rl_ls_cand[first + j];
            float th, uh, vh;
            if (id == RL_LS_NONE || !rl_ls_wt_hit(w, id, t_min, limit, th, uh, vh))
                continue;
            if (tri == RL_LS_NONE || th < t || (th == t && id < tri)) {
                tri = id;
                t = th;
                limit = rl_ls_next_up(th);
            }
        }
        return tri != RL_LS_NONE;
    }

    /* rl_linespace_pnmt_intersect (want) / rl_linespace_pnmt_occluded: the
     * first stored surface along the ray. In the start voxel under the
     * exact origin rule the answer is a triangle (tri, t; the caller
     * shades it), elsewhere a record (tri = RL_LS_NONE; p, n, uv,
     * material; t its projection on the ray). */
    bool rl_ls_pnmt_walk(vec3 o, vec3 d, float t_min, float t_max, bool want, out float t, out uint tri, out vec3 p,
                         out vec3 n, out vec2 uv, out uint material)
    {
        t = 0.0;
        tri = RL_LS_NONE;
        p = vec3(0.0);
        n = vec3(0.0);
        uv = vec2(0.0);
        material = 0u;
        RlLsDda it;
        dvec3 lo, ld, linv;
        if (!u_ls_has_pnmt || !rl_ls_walk_begin(o, d, t_min, t_max, it, lo, ld, linv))
            return false;
        RlLsWt w = rl_ls_wt_setup(o, d);
        bool first = rl_ls_starts_inside(o, d, t_min);
        precise float r = want ? 0.0 : 0.5 * sqrt(u_ls_cell.x * u_ls_cell.x + u_ls_cell.y * u_ls_cell.y +
                                                  u_ls_cell.z * u_ls_cell.z) / sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        uint cell;
        float t0, t1;
        while (rl_ls_dda_next(it, cell, t0, t1)) {
            bool origin = first;
            first = false;
            uint block = rl_ls_voxel_slot[cell];
            if (block == RL_LS_NONE)
                continue;
            bool fwd = true;
            uint rank = 0u;
            uint shaft = rl_ls_shaft_of_ray(it.cur, lo, ld, linv, fwd);
            if (shaft != RL_LS_NONE && !rl_ls_occupied(block, shaft, rank))
                continue;
            if (origin || shaft == RL_LS_NONE) {
                if (rl_ls_origin_hit(w, cell, shaft, rank, t_min, t_max, t1, tri, t))
                    return true;
                continue;
            }
            if (!want && rl_ls_voxel_within(it.cur, o, d, t_min, t_max, r))
                return true;
            if (!rl_ls_pnmt_decode(it.cur, rank, fwd, p, n, uv, material))
                continue;
            t = rl_ls_project_t(o, d, p);
            if (t > t_min && t < t_max)
                return true;
        }
        tri = RL_LS_NONE;
        return false;
    }

    bool rl_ls_pnmt_intersect(vec3 o, vec3 d, float t_min, float t_max, out float t, out uint tri, out vec3 p,
                              out vec3 n, out vec2 uv, out uint material)
    {
        return rl_ls_pnmt_walk(o, d, t_min, t_max, true, t, tri, p, n, uv, material);
    }

    bool rl_ls_pnmt_occluded(vec3 o, vec3 d, float t_min, float t_max)
    {
        float t;
        uint tri, material;
        vec3 p, n;
        vec2 uv;
        return rl_ls_pnmt_walk(o, d, t_min, t_max, false, t, tri, p, n, uv, material);
    }
    /* ---- PREILLUM (Sec. 7.3; linespace_query.c preillum_walk) ---- */

    /* rl_linespace_preillum (want: colour and t) / _preillum_occluded: the
     * stored colour of the first surface; t from the PNMT record where one
     * is uploaded, else the middle of the ray's interval in the voxel. The
     * start voxel under the exact origin rule counts a record only beyond
     * a tenth of the voxel diagonal. */
    bool rl_ls_preillum_walk(vec3 o, vec3 d, float t_min, float t_max, bool want, out vec3 color, out float t)
    {
        color = vec3(0.0);
        t = 0.0;
        RlLsDda it;
        dvec3 lo, ld, linv;
        if (!u_ls_has_preillum || !rl_ls_walk_begin(o, d, t_min, t_max, it, lo, ld, linv))
            return false;
        bool first = rl_ls_starts_inside(o, d, t_min);
        precise float len_c = sqrt(u_ls_cell.x * u_ls_cell.x + u_ls_cell.y * u_ls_cell.y + u_ls_cell.z * u_ls_cell.z);
        precise float len_d = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
        precise float margin = 0.1 * len_c / len_d;
        precise float r = want ? 0.0 : 0.5 * len_c / len_d;
        uint cell;
        float t0, t1;
        while (rl_ls_dda_next(it, cell, t0, t1)) {
            bool origin = first;
            first = false;
            uint block = rl_ls_voxel_slot[cell];
            if (block == RL_LS_NONE)
                continue;
            bool fwd = true;
            uint rank = 0u;
            uint shaft = rl_ls_shaft_of_ray(it.cur, lo, ld, linv, fwd);
            if (shaft == RL_LS_NONE || !rl_ls_occupied(block, shaft, rank))
                continue;
            precise float lo_t = origin ? t_min + margin : t_min;
            precise float tm = 0.5 * (t0 + t1);
            float th = tm;
            if (u_ls_has_pnmt) {
                if (!want && rl_ls_voxel_within(it.cur, o, d, lo_t, t_max, r))
                    return true;
                vec3 p, n;
                vec2 uv;
                uint material;
                if (rl_ls_pnmt_decode(it.cur, rank, fwd, p, n, uv, material))
                    th = rl_ls_project_t(o, d, p);
            }
            if (!(th > lo_t && th < t_max))
                continue;
            if (want) {
                uint w = rank * 4u + (fwd ? 0u : 2u);
                vec2 rg = unpackHalf2x16(rl_ls_preillum_rec[w]), ba = unpackHalf2x16(rl_ls_preillum_rec[w + 1u]);
                color = vec3(rg, ba.x);
            }
            t = th;
            return true;
        }
        return false;
    }

    bool rl_ls_preillum(vec3 o, vec3 d, float t_min, float t_max, out vec3 color, out float t)
    {
        return rl_ls_preillum_walk(o, d, t_min, t_max, true, color, t);
    }

    bool rl_ls_preillum_occluded(vec3 o, vec3 d, float t_min, float t_max)
    {
        vec3 color;
        float t;
        return rl_ls_preillum_walk(o, d, t_min, t_max, false, color, t);
    }
);

const char *rl_gl_linespace_glsl(void) { return walk_glsl; }
