/* pathtrace_backend.c: the structures behind the path tracer's backends
 * (Schröder 2017, Sec. 5.1, Diagram 3): an exact accelerator per exact
 * backend in use (BVH, grid, Embree), the grid plus its Line Space for the
 * ls-* backends (one Line Space with the union of the payloads the shadow
 * and diffuse backends ask for, on the grid of grid_res), and the shadow
 * maps. Each is built lazily, the first time a frame needs it, and kept
 * until the scene (rl_scene_uid) or its own parameters change, so that
 * switching backends back and forth costs nothing. ls-object builds the
 * object Line Spaces (N = ls_n, ls_object_res voxels per axis and object);
 * ls-scene builds the scene Line Space's signatures over its inner
 * structure (ls_scene_inner: the object Line Spaces, the BVH, or the
 * per-voxel Line Space's candidates on the grid of grid_res).
 *
 * Also here: the quad-light cover of emissive triangles used by the
 * emission rule (pathtrace_path.c). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "render/pathtrace_internal.h"
#include "render/trace_internal.h"
#include "rl/rl_timer.h"


const char *rl_pt_backend_name(rl_pt_backend backend)
{
    static const char *const names[RL_PT_BACKEND_COUNT] = {
        "bvh", "grid", "embree", "ls-candidates", "ls-preillum", "ls-pnmt", "shadowmap", "ls-scene", "ls-object"
    };
    return (unsigned)backend < RL_PT_BACKEND_COUNT ? names[backend] : "unknown";
}

static bool is_exact(rl_pt_backend k)
{
    return k == RL_PT_BACKEND_BVH || k == RL_PT_BACKEND_GRID || k == RL_PT_BACKEND_EMBREE;
}

bool rl_pt_backend_available(rl_pt_backend backend, bool shadow)
{
    if (backend == RL_PT_BACKEND_EMBREE)
        return rl_accel_kind_available(RL_ACCEL_EMBREE);
    if (backend == RL_PT_BACKEND_SHADOWMAP)
        return shadow;
    return (unsigned)backend < RL_PT_BACKEND_COUNT;
}

/* The Line Space on the grid with the payloads the backends need, and pt's
 * shading function for the pre-illuminated colours (Sec. 7.3). */
static rl_status ls_build(const rl_accel *grid, const rl_linespace_desc *desc, rl_ls_shade_fn shade,
                          void *user, rl_linespace **out, double *build_ms)
{
    rl_linespace *ls = NULL;
    *out = NULL;
    rl_status st = rl_linespace_create(grid, desc, &ls);
    if (st == RL_OK && (desc->payloads & RL_LS_PREILLUM))
        st = rl_linespace_set_shader(ls, shade, user);
    if (st == RL_OK)
        st = rl_linespace_commit(ls);
    if (st != RL_OK) {
        rl_linespace_release(ls);
        return st;
    }
    rl_linespace_stats stats;
    rl_linespace_get_stats(ls, &stats);
    *build_ms = stats.build_ms;
    *out = ls;
    return RL_OK;
}

/* "N=5, dynamic lists, candidates+pnmt" for ls_cached's message. */
static void ls_describe(char *buf, size_t size, int n, bool dynamic, int k, unsigned payloads)
{
    int len = dynamic ? snprintf(buf, size, "N=%d, dynamic lists, payloads", n)
                      : snprintf(buf, size, "N=%d, fixed lists of k=%d, payloads", n, k);
    const char *names[3] = { "candidates", "pnmt", "preillum" };
    const unsigned bits[3] = { RL_LS_CANDIDATES, RL_LS_PNMT, RL_LS_PREILLUM };
    char sep = ' ';
    for (int i = 0; i < 3 && len > 0 && (size_t)len < size; ++i)
        if (payloads & bits[i]) {
            len += snprintf(buf + len, size - (size_t)len, "%c%s", sep, names[i]);
            sep = '+';
        }
}

static bool file_exists(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (f)
        fclose(f);
    return f != NULL;
}

/* Whether path is a Line Space file, intact or not: it starts with the
 * magic, or is empty. Anything else was named by mistake and is not ours
 * to overwrite. */
static bool is_cache_file(const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return false;
    char magic[4];
    size_t n = fread(magic, 1, sizeof magic, f);
    fclose(f);
    return n == 0 || (n == sizeof magic && memcmp(magic, "RLLS", 4) == 0);
}

static rl_status ls_build_and_save(const rl_accel *grid, const rl_linespace_desc *desc, const char *path,
                                   rl_linespace **out, double *ms)
{
    rl_status st = ls_build(grid, desc, NULL, NULL, out, ms);
    if (st == RL_OK && (st = rl_linespace_save(*out, path)) != RL_OK) {
        rl_linespace_release(*out);
        *out = NULL;
    }
    return st;
}

/* The Line Space of desc through the cache file `path` (Sec. 13.3 of the
 * thesis proposes keeping it instead of rebuilding): loaded when the file
 * exists, which must then match the grid and the scene (rl_linespace_load
 * checks) and desc (checked here: same N, list kind and k, and at least
 * the payloads asked for); otherwise built and saved there. Pre-illuminated
 * colours depend on the lights and materials, which the file's
 * fingerprint does not cover, so they are refused rather than risked.
 * A damaged file (truncated, checksum wrong, an older version) is stale:
 * a warning, and it is rebuilt and overwritten, rather than failing every
 * later run until someone deletes it. One for another scene or with other
 * options is refused: it may be someone's good cache, named by mistake.
 * *ms: the build or the load time. */
static rl_status ls_cached(const rl_accel *grid, const rl_linespace_desc *desc, const char *path,
                           rl_linespace **out, double *ms)
{
    *out = NULL;
    if (desc->payloads & RL_LS_PREILLUM)
        return rl_error(RL_ERR_INVALID_ARG, "pt: ls_file keeps geometry only (candidates, PNMT); the "
                        "pre-illuminated colours depend on lights and materials and are rebuilt: leave "
                        "ls_file empty with ls-preillum");
    if (!file_exists(path))
        return ls_build_and_save(grid, desc, path, out, ms);
    rl_timer t;
    rl_timer_start(&t);
    rl_linespace *ls = NULL;
    rl_status st = rl_linespace_load(grid, path, &ls);
    if (st == RL_ERR_PARSE && is_cache_file(path)) {
        rl_warn("pt: ls_file %s; rebuilding the Line Space and overwriting the file", rl_last_error());
        rl_clear_error();
        return ls_build_and_save(grid, desc, path, out, ms);
    }
    if (st != RL_OK)
        return st;                        /* the loader's message names the file and the cause */
    *ms = rl_timer_ms(&t);
    rl_linespace_stats s;
    rl_linespace_get_stats(ls, &s);
    if (s.n != desc->n || s.dynamic != desc->dynamic || (!s.dynamic && s.k != desc->k) ||
        (s.payloads & desc->payloads) != desc->payloads) {
        rl_linespace_release(ls);
        char have[96], need[96];
        ls_describe(have, sizeof have, s.n, s.dynamic, s.k, s.payloads);
        ls_describe(need, sizeof need, desc->n, desc->dynamic, desc->k, desc->payloads);
        return rl_error(RL_ERR_INVALID_ARG, "pt: ls_file %s holds a Line Space with %s; these options need %s: "
                        "delete the file or name another", path, have, need);
    }
    *out = ls;
    return RL_OK;
}

/* Shadow maps of every light (Sec. 8.6). */
static rl_status sm_build(const rl_scene *scene, int size, rl_shadowmap **out, double *build_ms)
{
    rl_shadowmap_desc desc = { .size = size };
    rl_status st = rl_shadowmap_create(scene, &desc, out);
    if (st != RL_OK)
        return st;
    *build_ms = rl_shadowmap_build_ms(*out);
    return RL_OK;
}

uint32_t rl_pt_cover_point(const rl_scene_data *d, rl_vec3 p, float tol)
{
    for (uint32_t i = 0; i < d->num_lights; ++i) {
        const rl_light *L = &d->lights[i];
        if (L->type != RL_LIGHT_QUAD)
            continue;
        rl_vec3 n = rl_cross(L->edge_u, L->edge_v);
        float area = rl_length(n);
        if (!(area > 0.0f))
            continue;
        rl_vec3 r = rl_sub(p, L->position);
        if (fabsf(rl_dot(r, n)) / area > tol)
            continue;
        /* (s, t) of p in the parallelogram: solve the 2x2 normal equations
         * of r = s edge_u + t edge_v. */
        float uu = rl_dot(L->edge_u, L->edge_u), uv = rl_dot(L->edge_u, L->edge_v);
        float vv = rl_dot(L->edge_v, L->edge_v), ru = rl_dot(r, L->edge_u), rv = rl_dot(r, L->edge_v);
        float det = uu * vv - uv * uv;
        if (!(det > 0.0f))
            continue;
        float s = (ru * vv - rv * uv) / det, t = (rv * uu - ru * uv) / det;
        float ts = tol / sqrtf(uu), tt = tol / sqrtf(vv);
        if (s >= -ts && s <= 1.0f + ts && t >= -tt && t <= 1.0f + tt)
            return i;
    }
    return RL_NONE;
}

/* Per emissive triangle: the quad light covering all three corners. */
static rl_status build_cover(pt_backends *b, const rl_scene_data *d)
{
    free(b->tri_cover);
    b->tri_cover = rl_calloc(d->num_triangles ? d->num_triangles : 1, sizeof *b->tri_cover);
    if (!b->tri_cover)
        return RL_ERR_OUT_OF_MEMORY;
    float tol = 10.0f * b->eps;
    for (uint32_t t = 0; t < d->num_triangles; ++t) {
        b->tri_cover[t] = RL_NONE;
        if (!(rl_vmax_comp(d->materials[d->triangle_material[t]].emission) > 0.0f))
            continue;
        const uint32_t *idx = &d->indices[3 * (size_t)t];
        uint32_t c0 = rl_pt_cover_point(d, d->positions[idx[0]], tol);
        if (c0 != RL_NONE && rl_pt_cover_point(d, d->positions[idx[1]], tol) == c0 &&
            rl_pt_cover_point(d, d->positions[idx[2]], tol) == c0)
            b->tri_cover[t] = c0;
    }
    return RL_OK;
}

void rl_pt_backends_release(pt_backends *b)
{
    rl_ls_scene_release(b->lss);          /* before the inner structure it borrows */
    rl_ls_objects_release(b->lso);
    rl_linespace_release(b->ls);          /* before the grid it borrows */
    free(b->ls_file);
    for (int k = 0; k < 3; ++k)
        rl_accel_release(b->exact[k]);
    rl_shadowmap_release(b->sm);
    free(b->tri_cover);
    rl_pt_lights_release(&b->lights);
    rl_pt_env_release(&b->env);
    memset(b, 0, sizeof *b);
}

static rl_status build_exact(pt_backends *b, const rl_scene *scene, rl_accel_kind kind, int grid_res,
                             int threads, double *built_ms)
{
    if (b->exact[kind] && (kind != RL_ACCEL_GRID || b->grid_res == grid_res))
        return RL_OK;
    if (kind == RL_ACCEL_GRID) {
        rl_linespace_release(b->ls);      /* it lives on the old grid */
        b->ls = NULL;
        b->ls_ms = 0.0;
        free(b->ls_file);
        b->ls_file = NULL;
    }
    rl_accel_release(b->exact[kind]);
    b->exact[kind] = NULL;
    if (!rl_accel_kind_available(kind))
        return rl_error(RL_ERR_UNSUPPORTED, "pt: %s is not available in this build", rl_accel_kind_name(kind));
    rl_accel_desc desc = { .kind = kind, .threads = threads };
    if (kind == RL_ACCEL_GRID && grid_res > 0)
        desc.grid_res[0] = desc.grid_res[1] = desc.grid_res[2] = grid_res;
    rl_accel *a = NULL;
    rl_timer timer;
    rl_timer_start(&timer);
    rl_status st = rl_accel_create(scene, &desc, &a);
    if (st == RL_OK)
        st = rl_accel_commit(a);
    if (st != RL_OK) {
        rl_accel_release(a);
        return st;
    }
    b->exact[kind] = a;
    b->exact_ms[kind] = rl_timer_ms(&timer);
    *built_ms += b->exact_ms[kind];
    if (kind == RL_ACCEL_GRID)
        b->grid_res = grid_res;
    return RL_OK;
}

static unsigned payload_of(rl_pt_backend k)
{
    switch (k) {
    case RL_PT_BACKEND_LS_CANDIDATES: return RL_LS_CANDIDATES;
    case RL_PT_BACKEND_LS_PNMT: return RL_LS_PNMT;
    case RL_PT_BACKEND_LS_PREILLUM: return RL_LS_PREILLUM;
    default: return 0;
    }
}

rl_status rl_pt_backends_prepare_scene(pt_backends *b, const rl_scene *scene)
{
    const rl_scene_data *d = rl_scene_get_data(scene);
    if (!d)
        return RL_ERR_NOT_COMMITTED;
    uint64_t uid = rl_scene_uid(scene);
    rl_status st;
    if (b->scene_uid != uid || !b->tri_cover) {
        rl_pt_backends_release(b);
        b->scene_uid = uid;
        b->data = d;
        b->eps = rl_trace_origin_eps(d->bounds);   /* as whitted's */
        if ((st = build_cover(b, d)) != RL_OK || (st = rl_pt_lights_build(b, d)) != RL_OK ||
            (st = rl_pt_env_build(&b->env, d->environment, false)) != RL_OK) {
            rl_pt_backends_release(b);    /* the next frame starts over */
            return st;
        }
    }
    return RL_OK;
}

/* The object and scene Line Spaces the backends need (Sec. 13.1, 13.2),
 * after the per-voxel Line Space and the exact structures, since the scene
 * Line Space borrows one of them. */
static rl_status prepare_levels(pt_backends *b, const rl_scene *scene, const pt_settings *set, int threads,
                                double *built_ms)
{
    bool want_scene = set->shadow == RL_PT_BACKEND_LS_SCENE || set->diffuse == RL_PT_BACKEND_LS_SCENE;
    bool want_objects = set->shadow == RL_PT_BACKEND_LS_OBJECT || set->diffuse == RL_PT_BACKEND_LS_OBJECT ||
                        (want_scene && set->ls_scene_inner == PT_LS_INNER_OBJECT);
    rl_status st;
    if (want_objects && (!b->lso || b->lso_n != set->ls_n || b->lso_res != set->ls_object_res)) {
        rl_ls_scene_release(b->lss);      /* it may borrow these */
        b->lss = NULL;
        rl_ls_objects_release(b->lso);
        b->lso = NULL;
        rl_ls_objects_desc od = { .n = set->ls_n, .res = set->ls_object_res, .threads = threads };
        if ((st = rl_ls_objects_create(scene, &od, &b->lso)) != RL_OK ||
            (st = rl_ls_objects_commit(b->lso)) != RL_OK) {
            rl_ls_objects_release(b->lso);
            b->lso = NULL;
            return st;
        }
        rl_ls_objects_stats os;
        rl_ls_objects_get_stats(b->lso, &os);
        b->lso_n = set->ls_n;
        b->lso_res = set->ls_object_res;
        b->lso_ms = os.build_ms;
        *built_ms += os.build_ms;
    }
    if (!want_scene)
        return RL_OK;
    rl_ls_scene_inner inner = { 0 };
    if (set->ls_scene_inner == PT_LS_INNER_OBJECT)
        inner.objects = b->lso;
    else if (set->ls_scene_inner == PT_LS_INNER_CANDIDATES)
        inner.linespace = b->ls;
    else if ((st = build_exact(b, scene, RL_ACCEL_BVH, 0, threads, built_ms)) != RL_OK)
        return st;
    else
        inner.accel = b->exact[RL_ACCEL_BVH];
    const void *ptr = inner.objects ? (const void *)inner.objects
                                    : (inner.linespace ? (const void *)inner.linespace : (const void *)inner.accel);
    if (b->lss && b->lss_inner == ptr && b->lss_n == set->ls_scene_n && b->lss_segments == set->ls_scene_segments &&
        b->lss_cells == set->ls_scene_cells)
        return RL_OK;
    rl_ls_scene_release(b->lss);
    b->lss = NULL;
    rl_ls_scene_desc sd = { .n = set->ls_scene_n, .segments = set->ls_scene_segments, .cells = set->ls_scene_cells,
                            .threads = threads, .inner = inner };
    if ((st = rl_ls_scene_create(scene, &sd, &b->lss)) != RL_OK || (st = rl_ls_scene_commit(b->lss)) != RL_OK) {
        rl_ls_scene_release(b->lss);
        b->lss = NULL;
        return st;
    }
    rl_ls_scene_stats ss;
    rl_ls_scene_get_stats(b->lss, &ss);
    b->lss_inner = ptr;
    b->lss_n = set->ls_scene_n;
    b->lss_segments = set->ls_scene_segments;
    b->lss_cells = set->ls_scene_cells;
    b->lss_ms = ss.build_ms;
    *built_ms += ss.build_ms;
    return RL_OK;
}

rl_status rl_pt_backends_prepare(pt_backends *b, const rl_scene *scene, const pt_settings *set, int threads,
                                 double *built_ms)
{
    *built_ms = 0.0;
    rl_status st = rl_pt_backends_prepare_scene(b, scene);
    if (st != RL_OK)
        return st;
    const rl_scene_data *d = b->data;
    rl_pt_backend kinds[2] = { set->shadow, set->diffuse };
    for (int i = 0; i < 2; ++i) {
        if (!rl_pt_backend_available(kinds[i], i == 0))
            return rl_error(RL_ERR_UNSUPPORTED, "pt: %s=%s is not available in this build", i == 0 ? "shadow" : "diffuse",
                            rl_pt_backend_name(kinds[i]));
    }
    /* Primary rays and the traced G-buffer use the BVH (Sec. 6.4.1 traces
     * them like any ray; the thesis' choice of structure is ours here). */
    if (set->primary == PT_PRIMARY_TRACE && (st = build_exact(b, scene, RL_ACCEL_BVH, 0, threads, built_ms)))
        return st;
    for (int i = 0; i < 2; ++i)
        if (is_exact(kinds[i]) &&
            (st = build_exact(b, scene, (rl_accel_kind)kinds[i], set->grid_res, threads, built_ms)))
            return st;

    bool want_scene = set->shadow == RL_PT_BACKEND_LS_SCENE || set->diffuse == RL_PT_BACKEND_LS_SCENE;
    unsigned payloads = payload_of(set->shadow) | payload_of(set->diffuse);
    if (want_scene && set->ls_scene_inner == PT_LS_INNER_CANDIDATES)
        payloads |= RL_LS_CANDIDATES;
    if (payloads) {
        /* The Line Space lives in the grid's voxels (Sec. 4.2, 6.1). */
        if ((st = build_exact(b, scene, RL_ACCEL_GRID, set->grid_res, threads, built_ms)))
            return st;
        /* The pre-illuminated colours' shadow rays go through the BVH. */
        if ((payloads & RL_LS_PREILLUM) && (st = build_exact(b, scene, RL_ACCEL_BVH, 0, threads, built_ms)))
            return st;
        const char *file = set->ls_file && *set->ls_file ? set->ls_file : NULL;
        /* k sizes fixed lists only: dynamic lists ignore it. */
        bool same = b->ls && b->ls_n == set->ls_n && b->ls_dynamic == set->ls_dynamic &&
                    (set->ls_dynamic || b->ls_k == set->ls_k) &&
                    (b->ls_payloads & payloads) == payloads &&
                    (file ? b->ls_file && strcmp(b->ls_file, file) == 0 : !b->ls_file);
        if (!same) {
            rl_linespace_release(b->ls);
            b->ls = NULL;
            free(b->ls_file);
            b->ls_file = NULL;
            rl_linespace_desc desc = { .n = set->ls_n, .k = set->ls_k, .dynamic = set->ls_dynamic,
                                       .payloads = payloads, .threads = threads };
            double ms = 0.0;
            if (file)
                st = ls_cached(b->exact[RL_ACCEL_GRID], &desc, file, &b->ls, &ms);
            else
                st = ls_build(b->exact[RL_ACCEL_GRID], &desc, rl_pt_preillum_shade, b, &b->ls, &ms);
            if (st == RL_OK && file && !(b->ls_file = rl_strdup(file)))
                st = RL_ERR_OUT_OF_MEMORY;
            if (st != RL_OK) {
                rl_linespace_release(b->ls);
                b->ls = NULL;
                return st;
            }
            b->ls_n = set->ls_n;
            b->ls_k = set->ls_k;
            b->ls_dynamic = set->ls_dynamic;
            b->ls_payloads = payloads;
            b->ls_ms = ms;
            *built_ms += ms;
            /* The stored surfaces of the voxel a ray starts in include the
             * surface it leaves: the thesis skips them by a voxel offset
             * (Sec. 12.1-12.2, Fig. 19/21: "Voxel-Offset ... gegen
             * Selbstbeleuchtung"); one voxel diagonal leaves that voxel. */
            rl_accel_stats gs;
            rl_accel_get_stats(b->exact[RL_ACCEL_GRID], &gs);
            rl_vec3 ext = rl_aabb_extent(d->bounds);
            rl_vec3 voxel = rl_v3(ext.x / (float)(gs.grid_res[0] > 0 ? gs.grid_res[0] : 1),
                                  ext.y / (float)(gs.grid_res[1] > 0 ? gs.grid_res[1] : 1),
                                  ext.z / (float)(gs.grid_res[2] > 0 ? gs.grid_res[2] : 1));
            b->ls_offset = rl_length(voxel);
        }
        /* A query rule, no rebuild: with the offset the start voxel is
         * already past the surface, so records answer there too. */
        rl_linespace_set_origin(b->ls, set->ls_origin_exact ? RL_LS_ORIGIN_EXACT : RL_LS_ORIGIN_RECORDS);
        b->ls_start = set->ls_origin_exact ? 0.0f : b->ls_offset;
    }
    if ((st = prepare_levels(b, scene, set, threads, built_ms)) != RL_OK)
        return st;
    if (set->shadow == RL_PT_BACKEND_SHADOWMAP && (!b->sm || b->sm_size != set->shadowmap_size)) {
        rl_shadowmap_release(b->sm);
        b->sm = NULL;
        double ms = 0.0;
        if ((st = sm_build(scene, set->shadowmap_size, &b->sm, &ms)) != RL_OK)
            return st;
        b->sm_size = set->shadowmap_size;
        b->sm_ms = ms;
        *built_ms += ms;
    }
    return RL_OK;
}
