/* linespace.c: the Line Space object (rl_linespace.h): argument checks,
 * commit (the build is linespace_build.c), stats and the raw arrays.
 * Lifecycle as rl_accel (Embree-like): create borrows a committed grid
 * accel, commit builds once, queries (linespace_query.c) cannot fail. */
#include <stdlib.h>
#include <string.h>

#include "accel/accel_internal.h"
#include "accel/linespace_internal.h"
#include "core/error.h"

rl_status rl_linespace_create(const rl_accel *grid, const rl_linespace_desc *desc, rl_linespace **out)
{
    if (!grid || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_create: NULL grid or out");
    const rl_grid *g = rl_accel_grid_state(grid);
    if (!g)
        return rl_error(RL_ERR_INVALID_ARG,
                        "linespace: needs a committed RL_ACCEL_GRID accel (its voxels host the shafts)");
    rl_linespace_desc d = desc ? *desc : (rl_linespace_desc){ 0 };
    int n = d.n ? d.n : RL_LS_DEFAULT_N, k = d.k ? d.k : RL_LS_DEFAULT_K;
    unsigned payloads = d.payloads ? d.payloads : RL_LS_CANDIDATES;
    if (n < 1 || n > RL_LS_MAX_N)
        return rl_error(RL_ERR_INVALID_ARG, "linespace: n = %d not in 1..%d", d.n, RL_LS_MAX_N);
    if (k < 2 || k > RL_LS_MAX_K || (k & 1))
        return rl_error(RL_ERR_INVALID_ARG, "linespace: k = %d must be even and in 2..%d", d.k,
                        RL_LS_MAX_K);
    if (payloads & ~(unsigned)(RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM))
        return rl_error(RL_ERR_INVALID_ARG, "linespace: unknown payload bits 0x%x", payloads);
    if (d.threads < 0)
        return rl_error(RL_ERR_INVALID_ARG, "linespace: threads %d < 0", d.threads);
    const rl_scene *scene = rl_accel_scene(grid);
    const rl_scene_data *data = scene ? rl_scene_get_data(scene) : NULL;
    if (!data)
        return rl_error(RL_ERR_INVALID_ARG, "linespace: the grid's scene has no committed data");
    rl_linespace *ls = rl_calloc(1, sizeof *ls);
    if (!ls)
        return RL_ERR_OUT_OF_MEMORY;
    ls->accel = grid;
    ls->grid = g;
    ls->data = data;
    ls->masked = rl_data_has_masks(data);
    ls->n = n;
    ls->k = k;
    ls->dynamic = d.dynamic;
    ls->huge_pages = !d.small_pages;
    ls->payloads = payloads;
    ls->threads = d.threads;
    ls->progress = d.progress;
    ls->user = d.user;
    ls->shafts_per_voxel = rl_ls_shafts_per_voxel(n);
    ls->num_cells = g->num_cells;
    rl_linespace_stats *st = &ls->stats;
    st->n = n;
    st->k = k;
    st->dynamic = d.dynamic;
    st->payloads = payloads;
    for (int a = 0; a < 3; ++a)
        st->grid_res[a] = g->res[a];
    st->voxels = g->num_cells;
    *out = ls;
    return RL_OK;
}

rl_status rl_linespace_set_shader(rl_linespace *ls, rl_ls_shade_fn fn, void *user)
{
    if (!ls || !fn)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_set_shader: NULL linespace or function");
    ls->shade = fn;
    ls->shade_user = user;
    return RL_OK;
}

rl_status rl_linespace_set_origin(rl_linespace *ls, rl_ls_origin origin)
{
    if (!ls)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_set_origin: NULL linespace");
    if (origin != RL_LS_ORIGIN_EXACT && origin != RL_LS_ORIGIN_RECORDS)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_set_origin: unknown rule %d", (int)origin);
    ls->origin = origin;
    return RL_OK;
}

size_t rl_ls_memory_bytes(const rl_linespace *ls)
{
    uint64_t occ = ls->num_occupied;
    size_t bytes = (size_t)ls->num_cells * sizeof(uint32_t);
    if (ls->cand)
        bytes += (size_t)ls->num_cand * sizeof(uint32_t);
    if (ls->cand_start)
        bytes += (size_t)(occ + 1) * sizeof(uint32_t);
    if (ls->pnmt)
        bytes += (size_t)occ * 16 * sizeof(uint16_t);
    if (ls->preillum)
        bytes += (size_t)occ * 8 * sizeof(uint16_t);
    if (ls->occupied)
        bytes += (size_t)ls->num_blocks * ls->occ_words * 2 * sizeof(uint64_t);
    return bytes;
}

bool rl_ls_occupancy_alloc(rl_linespace *ls)
{
    ls->occ_words = (ls->shafts_per_voxel + 63u) / 64u;
    size_t words = (size_t)ls->num_blocks * ls->occ_words;
    ls->occupied = calloc(words ? 2 * words : 2, sizeof *ls->occupied);
    return ls->occupied != NULL;
}

rl_status rl_linespace_commit(rl_linespace *ls)
{
    if (!ls)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_commit: NULL linespace");
    if (ls->committed)
        return RL_OK;
    if ((ls->payloads & RL_LS_PREILLUM) && !ls->shade)
        return rl_error(RL_ERR_INVALID_ARG,
                        "linespace: PREILLUM needs a shading function (rl_linespace_set_shader)");
    rl_status s = rl_ls_build(ls);
    if (s) {
        rl_ls_free_arrays(ls);
        return s;
    }
    ls->stats.memory_bytes = rl_ls_memory_bytes(ls);
    ls->committed = true;
    return RL_OK;
}

void rl_linespace_release(rl_linespace *ls)
{
    if (!ls)
        return;
    rl_ls_free_arrays(ls);
    free(ls);
}

void rl_linespace_get_stats(const rl_linespace *ls, rl_linespace_stats *out)
{
    if (!out)
        return;
    if (!ls) {
        memset(out, 0, sizeof *out);
        return;
    }
    *out = ls->stats;
}

const rl_accel *rl_linespace_grid(const rl_linespace *ls) { return ls ? ls->accel : NULL; }

void rl_linespace_get_data(const rl_linespace *ls, rl_linespace_data *out)
{
    if (!out)
        return;
    memset(out, 0, sizeof *out);
    if (!ls || !ls->committed)
        return;
    out->n = ls->n;
    out->k = ls->k;
    out->dynamic = ls->dynamic;
    out->shafts_per_voxel = ls->shafts_per_voxel;
    out->num_cells = ls->num_cells;
    out->num_blocks = ls->num_blocks;
    out->voxel_slot = ls->voxel_slot;
    out->cand = ls->cand;
    out->cand_start = ls->cand_start;
    out->num_cand = ls->num_cand;
    out->pnmt = ls->pnmt;
    out->preillum = ls->preillum;
    out->occ_words = ls->occ_words;
    out->num_occupied = ls->num_occupied;
    out->occupancy = ls->occupied;
}
