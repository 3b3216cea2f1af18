/* raster_setup.c: triangle setup: trivial reject, homogeneous clipping,
 * viewport mapping, snapping, back-face culling, fill-rule biases.
 *
 * Clipping is Sutherland-Hodgman ("Reentrant polygon clipping", 1974) in clip space
 * against the near plane z >= -w and a guard band |x| <= g_x w, |y| <= g_y w
 * far outside the viewport. The sides of the viewport are not clipped (the
 * pixel loop's bounding box does that), so most triangles are never clipped
 * at all; the guard band only keeps snapped coordinates small enough for
 * exact int64 edge functions. The clipped convex polygon is drawn as a fan.
 *
 * Fill rule: top-left, as in Direct3D 10 (pixel centres at +0.5; a centre on
 * a top or left edge is inside). With the triangle ordered so that twice its
 * area is positive in y-down pixel space, an edge a->b is "top" when it is
 * horizontal with dx > 0 and "left" when dy < 0.
 *
 * Layered draws (rl_raster_layer) carry each polygon vertex's barycentrics in
 * its source triangle through clipping and store them, over w, in a side
 * record next to the prim (rl_raster_prim_src); the layers' colours and uvs
 * are then read from the batch at fill time. */
#include <math.h>

#include "core/error.h"
#include "raster/raster_internal.h"

/* A clip-space vertex with everything that is interpolated along edges. */
typedef struct cvert {
    rl_vec4 p;
    rl_vec4 c;
    rl_vec2 uv;
    float d;
    rl_vec3 b;                    /* barycentrics in the source triangle */
} cvert;

/* Outcode bits: planes that clip (distance < 0 is outside) and the viewport
 * sides, which only reject. */
enum {
    OUT_NEAR = 1 << 0, OUT_GX_POS = 1 << 1, OUT_GX_NEG = 1 << 2, OUT_GY_POS = 1 << 3,
    OUT_GY_NEG = 1 << 4, CLIP_PLANES = 0x1f,
    OUT_X_POS = 1 << 5, OUT_X_NEG = 1 << 6, OUT_Y_POS = 1 << 7, OUT_Y_NEG = 1 << 8,
};

/* Convex polygon after clipping against at most 5 planes: 3 + 5 vertices. */
#define MAX_POLY 9

static float plane_dist(int plane, rl_vec4 p, float gx, float gy)
{
    switch (plane) {
    case 0: return p.z + p.w;
    case 1: return gx * p.w - p.x;
    case 2: return gx * p.w + p.x;
    case 3: return gy * p.w - p.y;
    default: return gy * p.w + p.y;
    }
}

static unsigned outcode(rl_vec4 p, float gx, float gy)
{
    unsigned oc = 0;
    for (int k = 0; k < 5; ++k)
        if (plane_dist(k, p, gx, gy) < 0.0f)
            oc |= 1u << k;
    if (p.x > p.w) oc |= OUT_X_POS;
    if (p.x < -p.w) oc |= OUT_X_NEG;
    if (p.y > p.w) oc |= OUT_Y_POS;
    if (p.y < -p.w) oc |= OUT_Y_NEG;
    return oc;
}

static cvert lerp_vert(const cvert *a, const cvert *b, float t)
{
    cvert v;
    v.p = rl_v4(rl_lerpf(a->p.x, b->p.x, t), rl_lerpf(a->p.y, b->p.y, t),
                rl_lerpf(a->p.z, b->p.z, t), rl_lerpf(a->p.w, b->p.w, t));
    v.c = rl_v4(rl_lerpf(a->c.x, b->c.x, t), rl_lerpf(a->c.y, b->c.y, t),
                rl_lerpf(a->c.z, b->c.z, t), rl_lerpf(a->c.w, b->c.w, t));
    v.uv = rl_v2(rl_lerpf(a->uv.x, b->uv.x, t), rl_lerpf(a->uv.y, b->uv.y, t));
    v.d = rl_lerpf(a->d, b->d, t);
    v.b = rl_v3(rl_lerpf(a->b.x, b->b.x, t), rl_lerpf(a->b.y, b->b.y, t),
                rl_lerpf(a->b.z, b->b.z, t));
    return v;
}

/* Sutherland-Hodgman against the planes in mask; returns the new count. */
static int clip_polygon(cvert *poly, int n, unsigned mask, float gx, float gy)
{
    cvert tmp[MAX_POLY];
    for (int plane = 0; plane < 5 && n >= 3; ++plane) {
        if (!(mask & (1u << plane)))
            continue;
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const cvert *a = &poly[i], *b = &poly[(i + 1) % n];
            float da = plane_dist(plane, a->p, gx, gy), db = plane_dist(plane, b->p, gx, gy);
            if (da >= 0.0f)
                tmp[m++] = *a;
            /* Always interpolate from the inside vertex so that an edge shared
             * by two triangles is cut at the same point in either direction. */
            if (da >= 0.0f && db < 0.0f)
                tmp[m++] = lerp_vert(a, b, da / (da - db));
            else if (da < 0.0f && db >= 0.0f)
                tmp[m++] = lerp_vert(b, a, db / (db - da));
        }
        for (int i = 0; i < m; ++i)
            poly[i] = tmp[i];
        n = m;
    }
    return n;
}

/* Floor division for possibly negative fixed-point values. */
static int64_t floor_div(int64_t a, int64_t b)
{
    int64_t q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

static int32_t clamp_i32(int64_t v, int32_t lo, int32_t hi)
{
    return v < lo ? lo : (v > hi ? hi : (int32_t)v);
}

/* Twice the signed area of the snapped triangle, exact. */
static inline int64_t twice_area(int32_t ax, int32_t ay, int32_t bx, int32_t by, int32_t cx, int32_t cy)
{
    return ((int64_t)bx - ax) * ((int64_t)cy - ay) - ((int64_t)by - ay) * ((int64_t)cx - ax);
}

/* The pixels [x0, x1) x [y0, y1) of the viewport whose centres lie in the
 * bounding box of the snapped vertices; false when there are none. */
static inline bool pixel_box(const int32_t xs[3], const int32_t ys[3], int width, int height,
                             int32_t *x0, int32_t *x1, int32_t *y0, int32_t *y1)
{
    int64_t min_x = xs[0], max_x = xs[0], min_y = ys[0], max_y = ys[0];
    for (int k = 1; k < 3; ++k) {
        min_x = xs[k] < min_x ? xs[k] : min_x;
        max_x = xs[k] > max_x ? xs[k] : max_x;
        min_y = ys[k] < min_y ? ys[k] : min_y;
        max_y = ys[k] > max_y ? ys[k] : max_y;
    }
    /* Pixel x is a candidate when its centre x*256 + 128 lies in [min, max]. */
    const int64_t half = RL_RASTER_SUBPIXEL / 2;
    *x0 = clamp_i32(-floor_div(-(min_x - half), RL_RASTER_SUBPIXEL), 0, width);
    *x1 = clamp_i32(floor_div(max_x - half, RL_RASTER_SUBPIXEL) + 1, 0, width);
    *y0 = clamp_i32(-floor_div(-(min_y - half), RL_RASTER_SUBPIXEL), 0, height);
    *y1 = clamp_i32(floor_div(max_y - half, RL_RASTER_SUBPIXEL) + 1, 0, height);
    return *x0 < *x1 && *y0 < *y1;
}

/* A projected polygon vertex. */
typedef struct svert {
    int32_t x, y;                 /* snapped */
    double fx, fy;                /* exact pixel position */
    float iw, dw;
    rl_vec4 cw;
    rl_vec2 uvw;
    rl_vec3 bw;                   /* source barycentrics / w */
} svert;

/* The snapped pixel position of clip-space p, the exact one in fx, fy and
 * 1/w in *inv_w_out; false where it cannot be projected (w <= 0, or beyond
 * the guard band). */
static inline bool snap(rl_vec4 p, int width, int height, int32_t *x, int32_t *y, double *fx,
                        double *fy, double *inv_w_out)
{
    if (!(p.w > 0.0f))
        return false;
    double inv_w = 1.0 / p.w;
    *inv_w_out = inv_w;
    double x_pix = (p.x * inv_w + 1.0) * 0.5 * width;
    double y_pix = (1.0 - p.y * inv_w) * 0.5 * height;
    /* Cannot trigger after guard-band clipping except through rounding; it
     * keeps the fixed-point bound a hard guarantee. */
    if (!(fabs(x_pix) < 2.0 * RL_RASTER_GUARD_PX) || !(fabs(y_pix) < 2.0 * RL_RASTER_GUARD_PX))
        return false;
    *fx = x_pix;
    *fy = y_pix;
    /* Round half up; any rule works as long as a shared vertex always snaps
     * the same way, which a pure function of its position guarantees. */
    *x = (int32_t)floor(x_pix * RL_RASTER_SUBPIXEL + 0.5);
    *y = (int32_t)floor(y_pix * RL_RASTER_SUBPIXEL + 0.5);
    return true;
}

/* The attributes over w of v, whose position s holds already (snap). */
static inline void project_attributes(const cvert *v, double inv_w, bool layered, svert *s)
{
    float iw = (float)inv_w;
    s->iw = iw;
    s->dw = v->d * iw;
    s->cw = rl_v4(v->c.x * iw, v->c.y * iw, v->c.z * iw, v->c.w * iw);
    s->uvw = rl_v2(v->uv.x * iw, v->uv.y * iw);
    if (layered)
        s->bw = rl_v3(v->b.x * iw, v->b.y * iw, v->b.z * iw);
}

static bool project(const cvert *v, int width, int height, bool layered, svert *s)
{
    double inv_w;
    if (!snap(v->p, width, height, &s->x, &s->y, &s->fx, &s->fy, &inv_w))
        return false;
    project_attributes(v, inv_w, layered, s);
    return true;
}

/* Edge a->b of a triangle with positive area in y-down pixel space. */
static int32_t fill_bias(const svert *a, const svert *b)
{
    int64_t dx = (int64_t)b->x - a->x, dy = (int64_t)b->y - a->y;
    bool top_left = dy < 0 || (dy == 0 && dx > 0);
    return top_left ? 0 : -1;
}

/* Sets up triangle (a, b, c) into *p (and, when src is not NULL, the
 * source barycentrics into *src in p's vertex order); false when it is
 * degenerate, culled, or its bounding box holds no pixel centre of the
 * viewport. */
static bool setup_tri(const svert *a, const svert *b, const svert *c, bool cull_back,
                      int width, int height, rl_raster_prim *p, rl_raster_prim_src *src)
{
    int64_t area2 = twice_area(a->x, a->y, b->x, b->y, c->x, c->y);
    if (area2 == 0)
        return false;
    /* Counter-clockwise as seen by the camera (y up) is clockwise in y-down
     * pixel space, i.e. negative area2: those are front faces. */
    if (area2 > 0 && cull_back)
        return false;
    const svert *v[3] = { a, b, c };
    if (area2 < 0) {
        v[1] = c;
        v[2] = b;
        area2 = -area2;
    }
    const int32_t xs[3] = { v[0]->x, v[1]->x, v[2]->x }, ys[3] = { v[0]->y, v[1]->y, v[2]->y };
    if (!pixel_box(xs, ys, width, height, &p->x0, &p->x1, &p->y0, &p->y1))
        return false;
    /* Barycentric planes from the exact positions; where snapping changed
     * the triangle too much (nearly degenerate), from the snapped ones. */
    double ax[3], ay[3];
    for (int k = 0; k < 3; ++k) {
        ax[k] = v[k]->fx;
        ay[k] = v[k]->fy;
    }
    double area = (ax[1] - ax[0]) * (ay[2] - ay[0]) - (ay[1] - ay[0]) * (ax[2] - ax[0]);
    double snapped_area = (double)area2 / ((double)RL_RASTER_SUBPIXEL * RL_RASTER_SUBPIXEL);
    if (!(area > 0.5 * snapped_area && area < 2.0 * snapped_area)) {
        for (int k = 0; k < 3; ++k) {
            ax[k] = (double)v[k]->x / RL_RASTER_SUBPIXEL;
            ay[k] = (double)v[k]->y / RL_RASTER_SUBPIXEL;
        }
        area = snapped_area;
    }
    const double inv_area = 1.0 / area;
    for (int k = 0; k < 3; ++k) {
        /* Edge function of the edge opposite k, over the area. */
        int i = (k + 1) % 3, j = (k + 2) % 3;
        double ex = ax[j] - ax[i], ey = ay[j] - ay[i];
        p->lx[k] = -ey * inv_area;
        p->ly[k] = ex * inv_area;
        p->l0[k] = (ey * ax[i] - ex * ay[i]) * inv_area;
    }
    for (int k = 0; k < 3; ++k) {
        p->vx[k] = v[k]->x;
        p->vy[k] = v[k]->y;
        p->iw[k] = v[k]->iw;
        p->dw[k] = v[k]->dw;
        p->cw[k] = v[k]->cw;
        p->uvw[k] = v[k]->uvw;
        p->bias[k] = fill_bias(v[(k + 1) % 3], v[(k + 2) % 3]);
    }
    if (src)
        for (int k = 0; k < 3; ++k)
            src->bw[k] = v[k]->bw;
    return true;
}

static bool vec4_finite(rl_vec4 v)
{
    return isfinite(v.x) && isfinite(v.y) && isfinite(v.z) && isfinite(v.w);
}

/* Whether unclipped triangle (a, b, c) can reach setup_tri and pass it: the
 * same tests on the same snapped corners (project, the area's sign, the
 * pixel box), before a single attribute is read. Most triangles of a large
 * scene fail here, being back-facing or too small to cover a pixel centre,
 * and skip all attribute work; the answer is setup_tri's by construction
 * (the same pure functions of the same positions), which keeps every image
 * bit-identical. */
static bool may_cover(const cvert poly[3], bool cull_back, int width, int height, svert sv[3],
                      double inv_w[3])
{
    int32_t xs[3], ys[3];
    for (int k = 0; k < 3; ++k) {
        if (!snap(poly[k].p, width, height, &sv[k].x, &sv[k].y, &sv[k].fx, &sv[k].fy, &inv_w[k]))
            return false;
        xs[k] = sv[k].x;
        ys[k] = sv[k].y;
    }
    int64_t area2 = twice_area(xs[0], ys[0], xs[1], ys[1], xs[2], ys[2]);
    if (area2 == 0 || (area2 > 0 && cull_back))
        return false;
    int32_t x0, x1, y0, y1;
    return pixel_box(xs, ys, width, height, &x0, &x1, &y0, &y1);
}

/* Colour of vertex v of a batch with lazy colours (rl_raster_lazy_colors):
 * stamps[v] == 2 frame means shaded this frame, 2 frame - 1 that a thread
 * is shading it now; whoever moves it to "busy" shades, everyone else waits
 * for "done" (a rare, short wait: parallel chunks share few vertices). */
static rl_vec4 lazy_color(const rl_raster_batch *b, uint32_t v, bool alone)
{
    const rl_raster_lazy_colors *lz = b->lazy;
    const uint32_t done = 2 * lz->frame, busy = done - 1;
    if (alone) {
        /* No other thread reads these stamps during this draw
         * (rl_raster_chunk.lazy_alone): no locked instruction, which would
         * stall on the stamp's cache miss with every access around it. */
        if (__atomic_load_n(&lz->stamps[v], __ATOMIC_RELAXED) != done) {
            lz->shade(lz->user, v);
            __atomic_store_n(&lz->stamps[v], done, __ATOMIC_RELAXED);
        }
        return b->colors[v];
    }
    uint32_t s = __atomic_load_n(&lz->stamps[v], __ATOMIC_ACQUIRE);
    if (s != done) {
        if (s != busy && __atomic_compare_exchange_n(&lz->stamps[v], &s, busy, false, __ATOMIC_ACQUIRE,
                                                     __ATOMIC_ACQUIRE)) {
            lz->shade(lz->user, v);
            __atomic_store_n(&lz->stamps[v], done, __ATOMIC_RELEASE);
        } else {
            while (__atomic_load_n(&lz->stamps[v], __ATOMIC_ACQUIRE) != done)
                ;
        }
    }
    return b->colors[v];
}

bool rl_raster_setup(const rl_raster *r, const rl_raster_batch *b, const rl_vec4 *clip,
                     const float *eye_depth, uint32_t first, uint32_t count, rl_raster_chunk *chunk)
{
    const int width = r->target->width, height = r->target->height;
    const float gx = r->guard_x, gy = r->guard_y;
    const bool cull_back = (b->flags & RL_RASTER_CULL_BACK) != 0;
    const bool layered = b->num_layers > 0;
    const bool lazy = b->lazy && b->colors && !layered;
    for (uint32_t t = first; t < first + count; ++t) {
        const uint32_t *tri = &b->indices[3 * (size_t)t];
        cvert poly[MAX_POLY];
        unsigned oc_and = ~0u, oc_or = 0;
        bool finite = true;
        for (int k = 0; k < 3; ++k) {
            poly[k].p = clip[tri[k]];
            finite = finite && vec4_finite(poly[k].p);
            unsigned oc = outcode(poly[k].p, gx, gy);
            oc_and &= oc;
            oc_or |= oc;
        }
        /* Non-finite positions are skipped silently (rl_raster.h). */
        if (!finite || oc_and != 0)
            continue;
        /* An unclipped triangle keeps its corners: their snapped
         * positions (and 1/w) serve the setup below as they are. */
        svert sv[MAX_POLY];
        double inv_w[3] = { 0.0, 0.0, 0.0 };
        const bool clipped = (oc_or & CLIP_PLANES) != 0;
        if (!clipped && !may_cover(poly, cull_back, width, height, sv, inv_w))
            continue;

        const rl_texture *tex = NULL;
        if (b->uvs && !layered) {
            if (b->triangle_texture && b->textures) {
                uint32_t ti = b->triangle_texture[t];
                tex = ti == RL_ID_NONE ? NULL : b->textures[ti];
            } else {
                tex = b->texture;
            }
        }
        const rl_texture *mask = NULL;
        if (b->mask_texture && b->mask_texture[t] != RL_ID_NONE)
            mask = b->textures[b->mask_texture[t]];
        for (int k = 0; k < 3; ++k) {
            poly[k].c = !b->colors ? rl_v4(0, 0, 0, 0)
                        : lazy ? lazy_color(b, tri[k], chunk->lazy_alone) : b->colors[tri[k]];
            poly[k].uv = tex || mask ? b->uvs[tri[k]] : rl_v2(0, 0);
            poly[k].d = r->perspective ? 0.0f : eye_depth[tri[k]];
            poly[k].b = rl_v3(k == 0 ? 1.0f : 0.0f, k == 1 ? 1.0f : 0.0f, k == 2 ? 1.0f : 0.0f);
        }
        int n = 3;
        if (clipped) {
            n = clip_polygon(poly, n, oc_or & CLIP_PLANES, gx, gy);
            if (n < 3)
                continue;
            bool ok = true;
            for (int k = 0; k < n && ok; ++k)
                ok = project(&poly[k], width, height, layered, &sv[k]);
            if (!ok)
                continue;
        } else {
            for (int k = 0; k < 3; ++k)
                project_attributes(&poly[k], inv_w[k], layered, &sv[k]);
        }

        rl_raster_prim proto;
        proto.gouraud = b->colors != NULL;
        proto.color = b->face_colors ? b->face_colors[t] : b->color;
        proto.tex = tex;
        proto.mask = mask;
        proto.cutoff = mask ? b->mask_cutoff[t] : 0.0f;
        proto.triangle_id = b->triangle_ids ? b->triangle_ids[t] : b->first_triangle_id + t;
        proto.object_id = b->object_ids ? b->object_ids[t] : b->object_id;
        bool drawn = false;
        for (int k = 1; k + 1 < n; ++k) {
            if (chunk->num_prims == chunk->prim_cap &&
                !rl_reserve((void **)&chunk->prims, &chunk->prim_cap, chunk->num_prims + 1,
                            sizeof *chunk->prims, 64))
                return false;
            rl_raster_prim_src *src = NULL;
            if (layered) {
                if (!rl_reserve((void **)&chunk->srcs, &chunk->src_cap, chunk->num_prims + 1,
                                sizeof *chunk->srcs, 64))
                    return false;
                src = &chunk->srcs[chunk->num_prims];
                src->triangle = t;
            }
            rl_raster_prim *p = &chunk->prims[chunk->num_prims];
            *p = proto;
            if (setup_tri(&sv[0], &sv[k], &sv[k + 1], cull_back, width, height, p, src)) {
                chunk->num_prims++;
                drawn = true;
            }
        }
        chunk->triangles_drawn += drawn;
    }
    return true;
}
