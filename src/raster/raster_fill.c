/* raster_fill.c: the pixel loop: edge functions, depth test, attributes.
 *
 * Edge functions (Pineda 1988, "A parallel algorithm for polygon
 * rasterization") are evaluated exactly in int64 on 24.8 fixed-point
 * vertices; they decide coverage, one covered span per row (row_span), so
 * the pixel loop itself tests no edges. Barycentrics
 * come from the unsnapped vertices (see rl_raster_prim). 1/w and
 * attribute/w are linear in screen space, so depth = 1 / (1/w) and
 * colour = (colour/w) / (1/w) are perspective-correct (Heckbert & Moreton
 * 1991, "Interpolation for polygon texture mapping and shading"). Draws and
 * occlusion queries run this same code, a query just has no layer to write,
 * so their counts agree by construction.
 *
 * Multi-pass and multi-texturing for Vertex Tracing's reconstruction
 * (Ullmann 2003, Sec. 3.5.4, 3.5.5), done in one pass or several:
 *  - layers: the fragment is the sum over layers of colour x texel, where
 *    the thesis sums texture units in hardware (Sec. 3.5.5);
 *  - RL_RASTER_DEPTH_EQUAL + RL_RASTER_BLEND_ADD: a later pass over the same
 *    triangles adds its colour exactly where the first pass won (Sec. 3.5.4,
 *    glDepthFunc(GL_EQUAL) with additive blending). Exact equality is safe
 *    here, unlike on hardware with varying invariance: the same triangle with
 *    the same view and target goes through the same deterministic transform,
 *    clipping, setup and interpolation (no thread-dependent order, no FMA
 *    contraction in ISO C mode), so its fragments get bit-identical depth;
 *    a different, nearer triangle wrote a different depth there, and equal
 *    depth from another triangle is as rare as an exact tie. */
#include <math.h>
#include <string.h>

#include "core/texture_sample.h"
#include "raster/raster_internal.h"

static inline rl_vec4 mul4(rl_vec4 a, rl_vec4 b)
{
    return rl_v4(a.x * b.x, a.y * b.y, a.z * b.z, a.w * b.w);
}

/* The perspective-correct uv of a textured or masked prim. */
static inline rl_vec2 prim_uv(const rl_raster_prim *p, double l0, double l1, double l2, double inv_iw)
{
    const rl_vec2 *t = p->uvw;
    return rl_v2((float)((l0 * t[0].x + l1 * t[1].x + l2 * t[2].x) * inv_iw),
                 (float)((l0 * t[0].y + l1 * t[1].y + l2 * t[2].y) * inv_iw));
}

/* Whether a masked prim keeps its fragment: the test of rl_alpha_masked()
 * (alpha below the cutoff is a hole), on the same bilinear lookup. */
static bool mask_keeps(const rl_raster_prim *p, double l0, double l1, double l2, double inv_iw)
{
    return !(rl_texture_sample_inline(p->mask, prim_uv(p, l0, l1, l2, inv_iw)).w < p->cutoff);
}

static inline __attribute__((always_inline)) rl_vec4
shade(const rl_raster_prim *p, double l0, double l1, double l2, double inv_iw)
{
    rl_vec4 c = p->color;
    if (p->gouraud) {
        const rl_vec4 *a = p->cw;
        c = rl_v4((float)((l0 * a[0].x + l1 * a[1].x + l2 * a[2].x) * inv_iw),
                  (float)((l0 * a[0].y + l1 * a[1].y + l2 * a[2].y) * inv_iw),
                  (float)((l0 * a[0].z + l1 * a[1].z + l2 * a[2].z) * inv_iw),
                  (float)((l0 * a[0].w + l1 * a[1].w + l2 * a[2].w) * inv_iw));
    }
    if (p->tex)
        c = mul4(c, rl_texture_sample_inline(p->tex, prim_uv(p, l0, l1, l2, inv_iw)));
    return c;
}

/* A layered prim's layers, read from the batch once per fill call instead of
 * once per fragment: the untextured layers summed per source vertex (their
 * sum interpolates like each of them), the textured ones kept apart. */
typedef struct layer_terms {
    rl_vec4 plain[3];             /* rgb: untextured layers; w: layer 0's alpha */
    int num_tex;
    rl_vec4 col[RL_RASTER_MAX_LAYERS][3];
    rl_vec2 uv[RL_RASTER_MAX_LAYERS][3];
    const rl_texture *tex[RL_RASTER_MAX_LAYERS];
} layer_terms;

static void gather_layers(const rl_raster_batch *b, const rl_raster_prim_src *src, layer_terms *t)
{
    const uint32_t *tri = &b->indices[3 * (size_t)src->triangle];
    for (int k = 0; k < 3; ++k)
        t->plain[k] = rl_v4(0.0f, 0.0f, 0.0f, b->layers[0].colors[tri[k]].w);
    t->num_tex = 0;
    for (uint32_t i = 0; i < b->num_layers; ++i) {
        const rl_raster_layer *layer = &b->layers[i];
        const rl_texture *tex = NULL;
        if (layer->uvs && layer->textures && layer->triangle_texture) {
            uint32_t ti = layer->triangle_texture[src->triangle];
            if (ti != RL_ID_NONE)
                tex = layer->textures[ti];
        }
        for (int k = 0; k < 3; ++k) {
            rl_vec4 c = layer->colors[tri[k]];
            if (tex) {
                t->col[t->num_tex][k] = c;
                t->uv[t->num_tex][k] = layer->uvs[tri[k]];
            } else {
                t->plain[k].x += c.x;
                t->plain[k].y += c.y;
                t->plain[k].z += c.z;
            }
        }
        if (tex)
            t->tex[t->num_tex++] = tex;
    }
}

/* Ullmann 2003, Sec. 3.5.5: sum over layers of colour x texel, both
 * interpolated at the source triangle's perspective-correct barycentrics;
 * alpha is layer 0's (interpolated, not modulated). */
static inline __attribute__((always_inline)) rl_vec4
shade_layers(const layer_terms *t, const rl_raster_prim_src *src, double l0, double l1, double l2,
             double inv_iw)
{
    const rl_vec3 *bw = src->bw;
    const float b0 = (float)((l0 * bw[0].x + l1 * bw[1].x + l2 * bw[2].x) * inv_iw);
    const float b1 = (float)((l0 * bw[0].y + l1 * bw[1].y + l2 * bw[2].y) * inv_iw);
    const float b2 = (float)((l0 * bw[0].z + l1 * bw[1].z + l2 * bw[2].z) * inv_iw);
    const rl_vec4 *q = t->plain;
    rl_vec4 sum = rl_v4(b0 * q[0].x + b1 * q[1].x + b2 * q[2].x,
                        b0 * q[0].y + b1 * q[1].y + b2 * q[2].y,
                        b0 * q[0].z + b1 * q[1].z + b2 * q[2].z,
                        b0 * q[0].w + b1 * q[1].w + b2 * q[2].w);
    for (int i = 0; i < t->num_tex; ++i) {
        const rl_vec4 *c = t->col[i];
        const rl_vec2 *uv = t->uv[i];
        rl_vec4 texel = rl_texture_sample_inline(
            t->tex[i], rl_v2(b0 * uv[0].x + b1 * uv[1].x + b2 * uv[2].x,
                             b0 * uv[0].y + b1 * uv[1].y + b2 * uv[2].y));
        sum.x += (b0 * c[0].x + b1 * c[1].x + b2 * c[2].x) * texel.x;
        sum.y += (b0 * c[0].y + b1 * c[1].y + b2 * c[2].y) * texel.y;
        sum.z += (b0 * c[0].z + b1 * c[1].z + b2 * c[2].z) * texel.z;
    }
    return sum;
}

/* ---- four pixels at a time ----------------------------------------------
 * Full groups of four pixels of a span run the scalar loop's arithmetic
 * lane by lane in GCC/Clang vector extensions (SSE, AVX2 or AVX-512,
 * whatever the build targets). Each lane performs the same operations in
 * the same order (ISO C mode allows no FMA contraction), so every fragment
 * gets the same bits as from the scalar loop, which still does the tails.
 * Per lane stay the texel fetches and, for single-layer prims, the colour
 * arithmetic (four channels wide already); layered fragments are summed
 * channel by channel. */
#define LANES 4
typedef double vd __attribute__((vector_size(8 * LANES)));
typedef float vf __attribute__((vector_size(4 * LANES)));
typedef int32_t vi __attribute__((vector_size(4 * LANES)));

/* A group's barycentric planes at its pixel centres, and 1 / (1/w). */
typedef struct frag4 {
    vd l0, l1, l2, inv_iw;
} frag4;

static inline vf vfloor(vf x)
{
    vf r = x;
    for (int j = 0; j < LANES; ++j)
        r[j] = floorf(x[j]);
    return r;
}

/* double lanes to float lanes (a macro: a 32-byte vector argument would
 * change the ABI of builds without AVX, which warn about it). */
#define vcvt_f(x) __builtin_convertvector((x), vf)

/* (l0 a0 + l1 a1 + l2 a2) / (1/w): one perspective-correct attribute for
 * four lanes, in double like the scalar code. */
static inline vf interp(const frag4 *f, float a0, float a1, float a2)
{
    return vcvt_f((f->l0 * (double)a0 + f->l1 * (double)a1 + f->l2 * (double)a2) * f->inv_iw);
}

/* rl_texture_sample_inline's texel addresses and weights for four lanes. */
typedef struct tex4 {
    vi x0, x1, y0, y1;
    vf w00, w10, w01, w11;
} tex4;

static inline tex4 tex_address(const rl_texture *tex, vf u, vf v)
{
    const vi exponent = { 0x7f800000, 0x7f800000, 0x7f800000, 0x7f800000 };
    /* isfinite(u) ? u - floorf(u) : 0 */
    u = (vf)((vi)(u - vfloor(u)) & (((vi)u & exponent) != exponent));
    v = (vf)((vi)(v - vfloor(v)) & (((vi)v & exponent) != exponent));
    const int w = tex->width, h = tex->height;
    vf fx = u * (float)w - 0.5f;
    vf fy = (1.0f - v) * (float)h - 0.5f;
    vf x0f = vfloor(fx), y0f = vfloor(fy);
    vf tx = fx - x0f, ty = fy - y0f;
    tex4 a;
    a.x0 = __builtin_convertvector(x0f, vi);
    a.y0 = __builtin_convertvector(y0f, vi);
    a.x1 = a.x0 + 1;
    a.y1 = a.y0 + 1;
    a.x0 += (a.x0 < 0) & w;
    a.y0 += (a.y0 < 0) & h;
    a.x1 -= (a.x1 >= w) & w;
    a.y1 -= (a.y1 >= h) & h;
    a.w00 = (1 - tx) * (1 - ty);
    a.w10 = tx * (1 - ty);
    a.w01 = (1 - tx) * ty;
    a.w11 = tx * ty;
    return a;
}

static inline __attribute__((always_inline)) rl_vec4
tex_fetch(const rl_texture *tex, const tex4 *a, int j)
{
    return rl_texture_blend(tex, a->x0[j], a->x1[j], a->y0[j], a->y1[j], a->w00[j], a->w10[j],
                            a->w01[j], a->w11[j]);
}

/* Four colours channel by channel (structure of arrays), and the
 * transposes to and from the pixels' rl_vec4. */
typedef struct col4 {
    vf r, g, b, a;
} col4;

static inline col4 to_lanes(const rl_vec4 v[LANES])
{
    return (col4){ (vf){ v[0].x, v[1].x, v[2].x, v[3].x }, (vf){ v[0].y, v[1].y, v[2].y, v[3].y },
                   (vf){ v[0].z, v[1].z, v[2].z, v[3].z }, (vf){ v[0].w, v[1].w, v[2].w, v[3].w } };
}

static inline void from_lanes(col4 c, rl_vec4 out[LANES])
{
    for (int j = 0; j < LANES; ++j)
        out[j] = rl_v4(c.r[j], c.g[j], c.b[j], c.a[j]);
}

/* The four lanes' texels of one lookup, channel by channel. */
static inline __attribute__((always_inline)) col4 tex_lanes(const rl_texture *tex, vf u, vf v)
{
    const tex4 a = tex_address(tex, u, v);
    rl_vec4 texel[LANES];
    for (int j = 0; j < LANES; ++j)
        texel[j] = tex_fetch(tex, &a, j);
    return to_lanes(texel);
}

/* shade() for four lanes. */
static inline __attribute__((always_inline)) void
shade4(const rl_raster_prim *p, const frag4 *f, rl_vec4 out[LANES])
{
    if (p->gouraud) {
        const rl_vec4 *a = p->cw;
        from_lanes((col4){ interp(f, a[0].x, a[1].x, a[2].x), interp(f, a[0].y, a[1].y, a[2].y),
                           interp(f, a[0].z, a[1].z, a[2].z), interp(f, a[0].w, a[1].w, a[2].w) },
                   out);
    } else {
        for (int j = 0; j < LANES; ++j)
            out[j] = p->color;
    }
    if (p->tex) {
        const rl_vec2 *t = p->uvw;
        const tex4 a = tex_address(p->tex, interp(f, t[0].x, t[1].x, t[2].x),
                                   interp(f, t[0].y, t[1].y, t[2].y));
        for (int j = 0; j < LANES; ++j)
            out[j] = mul4(out[j], tex_fetch(p->tex, &a, j));
    }
}

/* shade_layers() for four lanes. */
static inline __attribute__((always_inline)) void
shade_layers4(const layer_terms *t, const rl_raster_prim_src *src, const frag4 *f,
              rl_vec4 out[LANES])
{
    const rl_vec3 *bw = src->bw;
    const vf b0 = interp(f, bw[0].x, bw[1].x, bw[2].x);
    const vf b1 = interp(f, bw[0].y, bw[1].y, bw[2].y);
    const vf b2 = interp(f, bw[0].z, bw[1].z, bw[2].z);
    const rl_vec4 *q = t->plain;
    col4 sum = { b0 * q[0].x + b1 * q[1].x + b2 * q[2].x, b0 * q[0].y + b1 * q[1].y + b2 * q[2].y,
                 b0 * q[0].z + b1 * q[1].z + b2 * q[2].z, b0 * q[0].w + b1 * q[1].w + b2 * q[2].w };
    for (int i = 0; i < t->num_tex; ++i) {
        const rl_vec4 *c = t->col[i];
        const rl_vec2 *uv = t->uv[i];
        const col4 x = tex_lanes(t->tex[i], b0 * uv[0].x + b1 * uv[1].x + b2 * uv[2].x,
                                 b0 * uv[0].y + b1 * uv[1].y + b2 * uv[2].y);
        sum.r += (b0 * c[0].x + b1 * c[1].x + b2 * c[2].x) * x.r;
        sum.g += (b0 * c[0].y + b1 * c[1].y + b2 * c[2].y) * x.g;
        sum.b += (b0 * c[0].z + b1 * c[1].z + b2 * c[2].z) * x.b;
    }
    from_lanes(sum, out);
}

/* The lanes of value where pass is set replace those at dst (4 bytes each). */
static inline void blend_store(void *dst, vi value, vi pass)
{
    vi old;
    memcpy(&old, dst, sizeof old);
    old = (value & pass) | (old & ~pass);
    memcpy(dst, &old, sizeof old);
}

/* Whether pixel x of the row is inside all three edges: edge k is
 * e_k(x) = e[k] - dy[k] s (x - x0), exact in int64. */
static inline bool covered(const int64_t e[3], const int64_t dy_s[3], int x0, int x)
{
    const int64_t dx = x - x0;
    return ((e[0] - dy_s[0] * dx) | (e[1] - dy_s[1] * dx) | (e[2] - dy_s[2] * dx)) >= 0;
}

/* The covered columns [*lo, *hi) of a row. A row of a triangle covers one
 * interval (the intersection of three half-lines), and each edge with
 * dy != 0 bounds it on one side, at x0 + e[k] / (dy[k] s). The bounds are
 * estimated in double with the reciprocal inv[k] = 1 / (dy[k] s) taken once
 * per prim: rounding e[k] (up to 2^58) to double moves a bound by at most
 * 32 / 256 px, the rest by far less, so a quarter pixel of margin keeps
 * every covered pixel; the exact int64 test then trims the ends, and the
 * pixel loop needs no edge test at all. Returns false for an empty row. */
static inline bool row_span(const int64_t e[3], const int64_t dy_s[3], const double inv[3], int x0,
                            int x1, int *lo, int *hi)
{
    double l = x0, h = x1;
    for (int k = 0; k < 3; ++k) {
        if (dy_s[k] == 0) {
            if (e[k] < 0)
                return false;
            continue;
        }
        const double xk = x0 + (double)e[k] * inv[k];
        if (dy_s[k] > 0)
            h = xk + 1.25 < h ? xk + 1.25 : h;  /* e_k falls with x: x <= xk */
        else
            l = xk - 0.25 > l ? xk - 0.25 : l;  /* e_k rises with x: x >= xk */
    }
    if (!(l < h))
        return false;
    int a = (int)ceil(l) > x0 ? (int)ceil(l) : x0;
    int b = (int)floor(h) < x1 ? (int)floor(h) : x1;
    while (a < b && !covered(e, dy_s, x0, a))
        ++a;
    while (b > a && !covered(e, dy_s, x0, b - 1))
        --b;
    *lo = a;
    *hi = b;
    return a < b;
}

#define SPAN_ROWS RL_RASTER_BAND_ROWS

/* The pixel loop, compiled twice: plain (the common single pass, kept as
 * lean as before multi-pass existed) and multi (DEPTH_EQUAL, BLEND_ADD,
 * layers, alpha masks). Both run the same depth arithmetic, so a multi pass sees the
 * depth a plain pass wrote. */
static inline __attribute__((always_inline)) uint64_t
fill_prim(const rl_raster_target *t, const rl_raster_prim *p, const rl_raster_prim_src *src,
          int row0, int row1, const bool multi)
{
    const int y0 = p->y0 > row0 ? p->y0 : row0, y1 = p->y1 < row1 ? p->y1 : row1;
    if (y0 >= y1)
        return 0;
    const int64_t s = RL_RASTER_SUBPIXEL, half = RL_RASTER_SUBPIXEL / 2;
    /* Edge k runs from vertex k+1 to k+2 and is positive on the inside. */
    int64_t dx[3], dy[3], dy_s[3], row_e[3];
    double inv[3];
    const int64_t px0 = p->x0 * s + half, py0 = y0 * s + half;
    for (int k = 0; k < 3; ++k) {
        int a = (k + 1) % 3, b = (k + 2) % 3;
        dx[k] = (int64_t)p->vx[b] - p->vx[a];
        dy[k] = (int64_t)p->vy[b] - p->vy[a];
        row_e[k] = dx[k] * (py0 - p->vy[a]) - dy[k] * (px0 - p->vx[a]) + p->bias[k];
        dy_s[k] = dy[k] * s;
        inv[k] = dy[k] ? 1.0 / (double)dy_s[k] : 0.0;
    }
    const bool write_color = t->color != NULL;
    const bool depth_equal = multi && t->depth_equal;
    const bool layered = multi && t->layered && write_color;
    const bool masked = multi && p->mask;
    layer_terms terms;
    if (layered) {
        gather_layers(t->layered, src, &terms);
    } else {
        /* Never read; set so that no compiler thinks it might be. */
        terms.num_tex = 0;
        terms.plain[0] = terms.plain[1] = terms.plain[2] = rl_v4(0.0f, 0.0f, 0.0f, 0.0f);
    }
    uint64_t passed = 0;
    /* Exact spans first, a block of rows at a time: the pixel loop then
     * tests no edges and keeps no edge values in registers. */
    int span_lo[SPAN_ROWS], span_hi[SPAN_ROWS];
    for (int yb = y0; yb < y1; yb += SPAN_ROWS) {
        const int yb1 = y1 - yb < SPAN_ROWS ? y1 : yb + SPAN_ROWS;
        for (int y = yb; y < yb1; ++y) {
            if (!row_span(row_e, dy_s, inv, p->x0, p->x1, &span_lo[y - yb], &span_hi[y - yb]))
                span_lo[y - yb] = span_hi[y - yb] = 0;
            row_e[0] += dx[0] * s;
            row_e[1] += dx[1] * s;
            row_e[2] += dx[2] * s;
        }
        for (int y = yb; y < yb1; ++y) {
            const int xs = span_lo[y - yb], xe = span_hi[y - yb];
            if (xs >= xe)
                continue;
            const double cy = y + 0.5;
            const double r0 = p->ly[0] * cy + p->l0[0], r1 = p->ly[1] * cy + p->l0[1],
                         r2 = p->ly[2] * cy + p->l0[2];
            size_t pix = (size_t)y * (size_t)t->width + (size_t)xs;
            int x = xs;
            for (; x + LANES <= xe; x += LANES, pix += LANES) {
                frag4 f;
                const vd cx = (vd){ x, x + 1, x + 2, x + 3 } + 0.5;
                f.l0 = p->lx[0] * cx + r0;
                f.l1 = p->lx[1] * cx + r1;
                f.l2 = p->lx[2] * cx + r2;
                const vd iw = f.l0 * (double)p->iw[0] + f.l1 * (double)p->iw[1] +
                              f.l2 * (double)p->iw[2];
                f.inv_iw = 1.0 / iw;
                const vd z = t->perspective ? f.inv_iw
                                            : (f.l0 * (double)p->dw[0] + f.l1 * (double)p->dw[1] +
                                               f.l2 * (double)p->dw[2]) * f.inv_iw;
                const vf zf = vcvt_f(z);
                vi pass = { -1, -1, -1, -1 };
                if (t->depth_test) {
                    vf dt;
                    memcpy(&dt, t->depth_test + pix, sizeof dt);
                    pass = depth_equal ? zf == dt : zf < dt;
                }
                if (masked)
                    for (int j = 0; j < LANES; ++j)
                        if (pass[j] && !mask_keeps(p, f.l0[j], f.l1[j], f.l2[j], f.inv_iw[j]))
                            pass[j] = 0;
                const int count = -(pass[0] + pass[1] + pass[2] + pass[3]);
                if (!count)
                    continue;
                passed += (uint64_t)count;
                if (t->depth)
                    blend_store(t->depth + pix, (vi)zf, pass);
                if (t->object_id)
                    blend_store(t->object_id + pix, (vi){ 0, 0, 0, 0 } + (int32_t)p->object_id, pass);
                if (t->triangle_id)
                    blend_store(t->triangle_id + pix, (vi){ 0, 0, 0, 0 } + (int32_t)p->triangle_id,
                                pass);
                if (!write_color)
                    continue;
                rl_vec4 c[LANES];
                if (layered)
                    shade_layers4(&terms, src, &f, c);
                else
                    shade4(p, &f, c);
                for (int j = 0; j < LANES; ++j) {
                    if (!pass[j])
                        continue;
                    if (multi && t->blend_add) {
                        rl_vec4 dst = t->color[pix + (size_t)j];
                        c[j] = rl_v4(dst.x + c[j].x, dst.y + c[j].y, dst.z + c[j].z, dst.w);
                    }
                    t->color[pix + (size_t)j] = c[j];
                }
            }
            for (; x < xe; ++x, ++pix) {
                const double cx = x + 0.5;
                double l0 = p->lx[0] * cx + r0, l1 = p->lx[1] * cx + r1,
                       l2 = p->lx[2] * cx + r2;
                double iw = l0 * p->iw[0] + l1 * p->iw[1] + l2 * p->iw[2];
                double inv_iw = 1.0 / iw;
                double z = t->perspective ? inv_iw
                                          : (l0 * p->dw[0] + l1 * p->dw[1] + l2 * p->dw[2]) * inv_iw;
                float zf = (float)z;
                if (t->depth_test &&
                    !(depth_equal ? zf == t->depth_test[pix] : zf < t->depth_test[pix]))
                    continue;
                if (masked && !mask_keeps(p, l0, l1, l2, inv_iw))
                    continue;
                ++passed;
                if (t->depth)
                    t->depth[pix] = zf;
                if (write_color) {
                    rl_vec4 c = layered ? shade_layers(&terms, src, l0, l1, l2, inv_iw)
                                        : shade(p, l0, l1, l2, inv_iw);
                    if (multi && t->blend_add) {
                        rl_vec4 dst = t->color[pix];
                        c = rl_v4(dst.x + c.x, dst.y + c.y, dst.z + c.z, dst.w);
                    }
                    t->color[pix] = c;
                }
                if (t->object_id)
                    t->object_id[pix] = p->object_id;
                if (t->triangle_id)
                    t->triangle_id[pix] = p->triangle_id;
            }
        }
    }
    return passed;
}

uint64_t rl_raster_fill_prim(const rl_raster_target *t, const rl_raster_prim *p,
                             const rl_raster_prim_src *src, int row0, int row1)
{
    if (t->depth_equal || t->blend_add || t->layered || p->mask)
        return fill_prim(t, p, src, row0, row1, true);
    return fill_prim(t, p, src, row0, row1, false);
}

uint64_t rl_raster_fill_point(const rl_raster_target *t, const rl_raster_point *p,
                              int row0, int row1)
{
    const int y0 = p->y0 > row0 ? p->y0 : row0, y1 = p->y1 < row1 ? p->y1 : row1;
    uint64_t passed = 0;
    for (int y = y0; y < y1; ++y) {
        size_t pix = (size_t)y * (size_t)t->width + (size_t)p->x0;
        for (int x = p->x0; x < p->x1; ++x, ++pix) {
            if (t->depth_test && !(t->depth_equal ? p->depth == t->depth_test[pix]
                                                  : p->depth < t->depth_test[pix]))
                continue;
            ++passed;
            if (t->depth)
                t->depth[pix] = p->depth;
            if (t->color) {
                rl_vec4 c = p->color, dst = t->color[pix];
                t->color[pix] = t->blend_add ? rl_v4(dst.x + c.x, dst.y + c.y, dst.z + c.z, dst.w)
                                             : c;
            }
            if (t->object_id)
                t->object_id[pix] = p->object_id;
            if (t->triangle_id)
                t->triangle_id[pix] = p->point_id;
        }
    }
    return passed;
}
