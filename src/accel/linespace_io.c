/* linespace_io.c: saving and loading a built Line Space (Schröder 2017,
 * Sec. 13.3 suggests storing it instead of rebuilding).
 *
 * File (little-endian; refused on a big-endian host):
 *   header   "RLLS", u32 version (2), i32 n, i32 k, u32 dynamic, u32 payloads,
 *            i32 res[3], f32 bounds min[3] max[3], u32 num_triangles,
 *            u64 scene fingerprint, u32 num_cells, u32 num_blocks,
 *            u64 num_cand, u64 empty_shafts, u64 candidates,
 *            u64 truncated_shafts, u32 max_candidates, f64 mean_candidates
 *   arrays   voxel_slot, occupancy (u64 pairs: bits, rank), cand (if
 *            CANDIDATES), cand_start (dynamic), pnmt (if PNMT), preillum
 *            (if PREILLUM), as in rl_linespace.h; the ranks are checked
 *            against the bits on load. Version
 *            1 stored records for every shaft, empty ones included; such
 *            files are refused (rebuild and save again).
 *   u64      checksum over all bytes before it
 * The fingerprint folds the triangle count and every vertex coordinate's
 * bits through rl_hash64. Load checks the header's sizes against the file's
 * length before allocating anything, then the checksum (RL_ERR_PARSE), then
 * that the file belongs to the given grid and scene (RL_ERR_INVALID_ARG),
 * then the arrays' contents (occupancy bits against the header's count,
 * indices in range, monotone offsets, PNMT and PREILLUM records finite and
 * in their ranges: a forged file whose checksum was recomputed is refused
 * like a corrupt one, RL_ERR_PARSE). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/accel_internal.h"
#include "accel/linespace_internal.h"
#include "core/bigalloc.h"
#include "core/half.h"
#include "core/error.h"
#include "rl/rl_output.h"
#include "core/half.h"
#include "rl/rl_rng.h"

#define LS_MAGIC "RLLS"
#define LS_VERSION 2u
#define HEADER_BYTES 128

static bool little_endian(void)
{
    uint16_t x = 1;
    unsigned char c;
    memcpy(&c, &x, 1);
    return c == 1;
}

/* Bijective per word, so a change in any one word always changes the sum.
 * Not static: the tests and the fuzz harness re-seal edited files with it,
 * as a forger would, to reach the record checks behind the sum. */
uint64_t rl_ls_file_hash(uint64_t h, const void *data, size_t n)
{
    const unsigned char *p = data;
    for (; n >= 8; n -= 8, p += 8) {
        uint64_t w;
        memcpy(&w, p, 8);
        h = (h ^ w) * 0xbf58476d1ce4e5b9ull;
        h ^= h >> 31;
    }
    if (n) {
        uint64_t w = 0;
        memcpy(&w, p, n);
        h = (h ^ w ^ ((uint64_t)n << 56)) * 0x94d049bb133111ebull;
        h ^= h >> 29;
    }
    return h;
}

static uint64_t fingerprint(const rl_grid *g)
{
    uint64_t h = rl_hash64(g->num_triangles ^ 0x524c4c53ull);
    const float *f = (const float *)g->tri_verts;
    for (size_t i = 0; i < 9 * (size_t)g->num_triangles; ++i) {
        uint32_t bits;
        memcpy(&bits, &f[i], 4);
        h = rl_hash64(h ^ bits);
    }
    return h;
}

typedef struct header {
    uint32_t version, dynamic, payloads, num_triangles, num_cells, num_blocks, max_candidates;
    int32_t n, k, res[3];
    float bounds[6];
    uint64_t fingerprint, num_cand, empty_shafts, candidates, truncated_shafts;
    double mean_candidates;
} header;

static void put(unsigned char *b, size_t *at, const void *v, size_t n)
{
    memcpy(b + *at, v, n);
    *at += n;
}

static void get(const unsigned char *b, size_t *at, void *v, size_t n)
{
    memcpy(v, b + *at, n);
    *at += n;
}

static void encode(const header *h, unsigned char *b)
{
    size_t at = 0;
    memset(b, 0, HEADER_BYTES);
    put(b, &at, LS_MAGIC, 4);
    put(b, &at, &h->version, 4);
    put(b, &at, &h->n, 4);
    put(b, &at, &h->k, 4);
    put(b, &at, &h->dynamic, 4);
    put(b, &at, &h->payloads, 4);
    put(b, &at, h->res, 12);
    put(b, &at, h->bounds, 24);
    put(b, &at, &h->num_triangles, 4);
    put(b, &at, &h->fingerprint, 8);
    put(b, &at, &h->num_cells, 4);
    put(b, &at, &h->num_blocks, 4);
    put(b, &at, &h->num_cand, 8);
    put(b, &at, &h->empty_shafts, 8);
    put(b, &at, &h->candidates, 8);
    put(b, &at, &h->truncated_shafts, 8);
    put(b, &at, &h->max_candidates, 4);
    put(b, &at, &h->mean_candidates, 8);
}

static bool decode(const unsigned char *b, header *h)
{
    size_t at = 4;
    if (memcmp(b, LS_MAGIC, 4) != 0)
        return false;
    get(b, &at, &h->version, 4);
    get(b, &at, &h->n, 4);
    get(b, &at, &h->k, 4);
    get(b, &at, &h->dynamic, 4);
    get(b, &at, &h->payloads, 4);
    get(b, &at, h->res, 12);
    get(b, &at, h->bounds, 24);
    get(b, &at, &h->num_triangles, 4);
    get(b, &at, &h->fingerprint, 8);
    get(b, &at, &h->num_cells, 4);
    get(b, &at, &h->num_blocks, 4);
    get(b, &at, &h->num_cand, 8);
    get(b, &at, &h->empty_shafts, 8);
    get(b, &at, &h->candidates, 8);
    get(b, &at, &h->truncated_shafts, 8);
    get(b, &at, &h->max_candidates, 4);
    get(b, &at, &h->mean_candidates, 8);
    return true;
}

/* The arrays of a Line Space with header h, in file order. */
typedef struct array_sizes {
    uint64_t slot, occ, cand, start, pnmt, preillum;   /* elements */
} array_sizes;

/* h->empty_shafts <= the shafts (checked before). */
static array_sizes sizes_of(const header *h)
{
    uint32_t S = rl_ls_shafts_per_voxel(h->n);
    uint64_t occupied = (uint64_t)h->num_blocks * S - h->empty_shafts;
    array_sizes s = { h->num_cells, 2 * (uint64_t)h->num_blocks * ((S + 63u) / 64u), 0, 0, 0, 0 };
    if (h->payloads & RL_LS_CANDIDATES) {
        s.cand = h->num_cand;
        if (h->dynamic)
            s.start = occupied + 1;
    }
    if (h->payloads & RL_LS_PNMT)
        s.pnmt = occupied * 16;
    if (h->payloads & RL_LS_PREILLUM)
        s.preillum = occupied * 8;
    return s;
}

static uint64_t file_bytes(array_sizes s)
{
    return HEADER_BYTES + 4 * (s.slot + s.cand + s.start) + 8 * s.occ + 2 * (s.pnmt + s.preillum) + 8;
}

static bool write_hashed(FILE *f, const void *p, size_t n, uint64_t *h)
{
    *h = rl_ls_file_hash(*h, p, n);
    return n == 0 || fwrite(p, 1, n, f) == n;
}

rl_status rl_linespace_save(const rl_linespace *ls, const char *path)
{
    if (!ls || !path)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_save: NULL linespace or path");
    if (!ls->committed)
        return rl_error(RL_ERR_NOT_COMMITTED, "linespace: commit before saving");
    if (!little_endian())
        return rl_error(RL_ERR_UNSUPPORTED, "linespace: files are little-endian only");
    const rl_grid *g = ls->grid;
    header h = { .version = LS_VERSION, .dynamic = ls->dynamic, .payloads = ls->payloads,
                 .num_triangles = g->num_triangles, .num_cells = ls->num_cells,
                 .num_blocks = ls->num_blocks, .max_candidates = ls->stats.max_candidates,
                 .n = ls->n, .k = ls->k, .fingerprint = fingerprint(g), .num_cand = ls->num_cand,
                 .empty_shafts = ls->stats.empty_shafts, .candidates = ls->stats.candidates,
                 .truncated_shafts = ls->stats.truncated_shafts,
                 .mean_candidates = ls->stats.mean_candidates };
    for (int a = 0; a < 3; ++a) {
        h.res[a] = g->res[a];
        h.bounds[a] = rl_vget(g->bounds.min, a);
        h.bounds[3 + a] = rl_vget(g->bounds.max, a);
    }
    if (!(ls->payloads & RL_LS_CANDIDATES))
        h.num_cand = 0;
    array_sizes s = sizes_of(&h);
    /* Through a temporary and a rename: a save that fails or is killed
     * leaves the previous cache (or none), never a truncated one. */
    rl_output *o = NULL;
    rl_status st = rl_output_open(path, &o);
    if (st != RL_OK)
        return st;
    FILE *f = rl_output_file(o);
    unsigned char buf[HEADER_BYTES];
    encode(&h, buf);
    uint64_t sum = 0;
    bool ok = write_hashed(f, buf, HEADER_BYTES, &sum) &&
              write_hashed(f, ls->voxel_slot, 4 * s.slot, &sum) &&
              write_hashed(f, ls->occupied, 8 * s.occ, &sum) &&
              write_hashed(f, ls->cand, 4 * s.cand, &sum) &&
              write_hashed(f, ls->cand_start, 4 * s.start, &sum) &&
              write_hashed(f, ls->pnmt, 2 * s.pnmt, &sum) &&
              write_hashed(f, ls->preillum, 2 * s.preillum, &sum);
    ok = ok && fwrite(&sum, 1, 8, f) == 8;
    if (!ok) {
        st = rl_error(RL_ERR_IO, "%s: cannot write: %s", path, strerror(errno));
        rl_output_abort(o);
        return st;
    }
    return rl_output_commit(o);
}

static bool read_hashed(FILE *f, void *p, size_t n, uint64_t *h)
{
    if (n && fread(p, 1, n, f) != n)
        return false;
    *h = rl_ls_file_hash(*h, p, n);
    return true;
}

static bool in_range(uint16_t h, float lo, float hi)
{
    float f = rl_half_to_float(h);
    return f >= lo && f <= hi;      /* false for NaN */
}

/* The records as a build writes them (rl_linespace.h): the checksum only
 * proves that a file is whole, and a forged one with a recomputed sum
 * would hand NaN surfaces or a material past the scene's to the renderer.
 * Positions are voxel-relative in [0, 1], the normal's x and y in [-1, 1],
 * the material ID + 1 (signed) names a material of the scene, texture
 * coordinates and pre-illuminated colours are finite (colours >= 0). */
static rl_status check_records(const rl_linespace *ls, const char *path)
{
    const uint32_t materials = ls->data->num_materials;
    for (uint64_t i = 0; ls->pnmt && i < 2 * ls->num_occupied; ++i) {
        const uint16_t *r = ls->pnmt + i * RL_LS_PNMT_RECORD;
        uint32_t id = 0;
        bool ok = in_range(r[RL_LS_PNMT_PX], 0.0f, 1.0f) && in_range(r[RL_LS_PNMT_PY], 0.0f, 1.0f) &&
                  in_range(r[RL_LS_PNMT_PZ], 0.0f, 1.0f) && in_range(r[RL_LS_PNMT_NX], -1.0f, 1.0f) &&
                  in_range(r[RL_LS_PNMT_NY], -1.0f, 1.0f) &&
                  in_range(r[RL_LS_PNMT_U], -65504.0f, 65504.0f) && in_range(r[RL_LS_PNMT_V], -65504.0f, 65504.0f) &&
                  rl_ls_pnmt_material(rl_half_to_float(r[RL_LS_PNMT_MAT]), &id) && id < materials;
        if (!ok)
            return rl_error(RL_ERR_PARSE, "%s: the %s surface record of occupied shaft %llu is not one a build "
                            "writes (not finite, outside its voxel or an unknown material)", path,
                            i % 2 ? "back" : "front", (unsigned long long)(i / 2));
    }
    for (uint64_t i = 0; ls->preillum && i < 8 * ls->num_occupied; ++i)
        if (!in_range(ls->preillum[i], 0.0f, 65504.0f))
            return rl_error(RL_ERR_PARSE, "%s: pre-illuminated colour of shaft %llu is negative or not finite",
                            path, (unsigned long long)(i / 8));
    return RL_OK;
}

static rl_status check_contents(const rl_linespace *ls, const char *path)
{
    const rl_grid *g = ls->grid;
    uint32_t next = 0;
    for (uint32_t c = 0; c < ls->num_cells; ++c) {
        bool filled = g->cell_start[c + 1] > g->cell_start[c];
        uint32_t slot = ls->voxel_slot[c];
        if (filled ? slot != next++ : slot != RL_NONE)
            return rl_error(RL_ERR_PARSE, "%s: voxel slot of cell %u does not match the grid", path, c);
    }
    if (next != ls->num_blocks)
        return rl_error(RL_ERR_PARSE, "%s: %u blocks, the grid has %u filled voxels", path,
                        ls->num_blocks, next);
    /* Bits past the last shaft of a block are never set. */
    const uint32_t S = ls->shafts_per_voxel, W = ls->occ_words;
    const uint64_t pad = S % 64u ? ~0ull << (S % 64u) : 0;
    uint64_t set = 0;
    for (uint64_t b = 0; b < ls->num_blocks; ++b) {
        const uint64_t *w = ls->occupied + 2 * b * W;
        if (w[2 * (W - 1)] & pad)
            return rl_error(RL_ERR_PARSE, "%s: occupancy bits past the last shaft of block %llu", path,
                            (unsigned long long)b);
        for (uint32_t i = 0; i < W; ++i) {
            if (w[2 * i + 1] != set)
                return rl_error(RL_ERR_PARSE, "%s: shaft ranks do not count the occupancy bits (block %llu)",
                                path, (unsigned long long)b);
            set += (uint64_t)__builtin_popcountll(w[2 * i]);
        }
    }
    if (set != ls->num_occupied)
        return rl_error(RL_ERR_PARSE, "%s: %llu occupied shafts, the header says %llu", path,
                        (unsigned long long)set, (unsigned long long)ls->num_occupied);
    uint64_t occupied = ls->num_occupied;
    if (ls->cand_start) {
        if (ls->cand_start[0] != 0 || ls->cand_start[occupied] != ls->num_cand)
            return rl_error(RL_ERR_PARSE, "%s: candidate offsets do not span the list", path);
        for (uint64_t i = 0; i < occupied; ++i)
            if (ls->cand_start[i + 1] < ls->cand_start[i])
                return rl_error(RL_ERR_PARSE, "%s: candidate offsets decrease at shaft %llu", path,
                                (unsigned long long)i);
    }
    for (uint64_t i = 0; ls->cand && i < ls->num_cand; ++i)
        if (ls->cand[i] >= g->num_triangles && (ls->dynamic || ls->cand[i] != RL_NONE))
            return rl_error(RL_ERR_PARSE, "%s: candidate %llu is not a triangle ID", path,
                            (unsigned long long)i);
    return check_records(ls, path);
}

/* The header read and checked against itself and the file's length; f is
 * left at the first array. *shafts: filled voxels x shafts per voxel. */
static rl_status load_header(FILE *f, const char *path, unsigned char buf[HEADER_BYTES], header *h,
                             uint64_t *shafts, array_sizes *s)
{
    if (fread(buf, 1, HEADER_BYTES, f) != HEADER_BYTES)
        return rl_error(RL_ERR_PARSE, "%s: truncated header", path);
    if (!decode(buf, h))
        return rl_error(RL_ERR_PARSE, "%s: not a Line Space file (magic)", path);
    if (h->version != LS_VERSION)
        return rl_error(RL_ERR_PARSE, "%s: version %u, this build reads version %u", path, h->version, LS_VERSION);
    if (h->n < 1 || h->n > RL_LS_MAX_N || h->k < 2 || h->k > RL_LS_MAX_K || (h->k & 1) || h->dynamic > 1 ||
        h->payloads == 0 || (h->payloads & ~(unsigned)(RL_LS_CANDIDATES | RL_LS_PNMT | RL_LS_PREILLUM)) ||
        h->num_blocks > h->num_cells)
        return rl_error(RL_ERR_PARSE, "%s: corrupt header (n, k, flags or counts)", path);
    *shafts = (uint64_t)h->num_blocks * rl_ls_shafts_per_voxel(h->n);
    if (*shafts > UINT32_MAX - 1u || h->empty_shafts > *shafts || h->num_cand > (uint64_t)UINT32_MAX * RL_LS_MAX_K ||
        ((h->payloads & RL_LS_CANDIDATES) && !h->dynamic &&
         h->num_cand != (*shafts - h->empty_shafts) * (uint64_t)h->k) ||
        ((h->payloads & RL_LS_CANDIDATES) && h->dynamic && h->num_cand > UINT32_MAX))
        return rl_error(RL_ERR_PARSE, "%s: corrupt header (array sizes)", path);
    *s = sizes_of(h);
    if (fseeko(f, 0, SEEK_END) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot seek", path);
    off_t len = ftello(f);
    if (len < 0 || (uint64_t)len != file_bytes(*s))
        return rl_error(RL_ERR_PARSE, "%s: %lld bytes, the header describes %llu (truncated or corrupt)", path,
                        (long long)len, (unsigned long long)file_bytes(*s));
    if (fseeko(f, HEADER_BYTES, SEEK_SET) != 0)
        return rl_error(RL_ERR_IO, "%s: cannot seek", path);
    return RL_OK;
}

/* The arrays into ls (allocated here), checked against the stored sum. */
static rl_status load_arrays(FILE *f, const char *path, const unsigned char buf[HEADER_BYTES], array_sizes s,
                             rl_linespace *ls)
{
    ls->voxel_slot = malloc((size_t)(s.slot ? s.slot : 1) * 4);
    ls->occupied = malloc((size_t)(s.occ ? s.occ : 1) * 8);
    ls->cand = s.cand ? rl_big_alloc((size_t)s.cand * 4, true) : NULL;
    ls->cand_start = s.start ? rl_big_alloc((size_t)s.start * 4, true) : NULL;
    ls->pnmt = s.pnmt ? rl_big_alloc((size_t)s.pnmt * 2, true) : NULL;
    ls->preillum = s.preillum ? rl_big_alloc((size_t)s.preillum * 2, true) : NULL;
    if (!ls->voxel_slot || !ls->occupied || (s.cand && !ls->cand) || (s.start && !ls->cand_start) ||
        (s.pnmt && !ls->pnmt) || (s.preillum && !ls->preillum))
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: out of memory for %llu bytes", path,
                        (unsigned long long)file_bytes(s));
    uint64_t sum = rl_ls_file_hash(0, buf, HEADER_BYTES), stored = 0;
    bool ok = read_hashed(f, ls->voxel_slot, 4 * s.slot, &sum) && read_hashed(f, ls->occupied, 8 * s.occ, &sum) &&
              read_hashed(f, ls->cand, 4 * s.cand, &sum) && read_hashed(f, ls->cand_start, 4 * s.start, &sum) &&
              read_hashed(f, ls->pnmt, 2 * s.pnmt, &sum) && read_hashed(f, ls->preillum, 2 * s.preillum, &sum) &&
              fread(&stored, 1, 8, f) == 8;
    if (!ok)
        return rl_error(RL_ERR_PARSE, "%s: truncated", path);
    if (stored != sum)
        return rl_error(RL_ERR_PARSE, "%s: checksum mismatch (corrupt file)", path);
    return RL_OK;
}

/* An intact file: does it belong to this grid and scene? */
static rl_status check_grid(const rl_accel *grid, const header *h, const char *path)
{
    const rl_grid *g = rl_accel_grid_state(grid);
    if (!g)
        return rl_error(RL_ERR_INVALID_ARG, "linespace: needs a committed RL_ACCEL_GRID accel");
    bool same_grid = h->num_cells == g->num_cells;
    for (int a = 0; a < 3; ++a)
        same_grid = same_grid && h->res[a] == g->res[a] && h->bounds[a] == rl_vget(g->bounds.min, a) &&
                    h->bounds[3 + a] == rl_vget(g->bounds.max, a);
    if (!same_grid)
        return rl_error(RL_ERR_INVALID_ARG, "%s: built on another grid (%d x %d x %d cells or bounds differ)", path,
                        h->res[0], h->res[1], h->res[2]);
    if (h->num_triangles != g->num_triangles || h->fingerprint != fingerprint(g))
        return rl_error(RL_ERR_INVALID_ARG, "%s: built for another scene (triangle fingerprint differs)", path);
    return RL_OK;
}

/* A Line Space made for grid from the header, taking over the arrays that
 * were read into tmp (freed), checked and with the file's statistics. */
static rl_status adopt(const rl_accel *grid, const header *h, uint64_t shafts, rl_linespace *tmp, const char *path,
                       rl_linespace **out)
{
    rl_linespace_desc d = { .n = h->n, .k = h->k, .dynamic = h->dynamic != 0, .payloads = h->payloads };
    rl_linespace *ls = NULL;
    rl_status st = rl_linespace_create(grid, &d, &ls);
    if (st)
        return st;
    ls->voxel_slot = tmp->voxel_slot;
    ls->cand = tmp->cand;
    ls->cand_start = tmp->cand_start;
    ls->pnmt = tmp->pnmt;
    ls->preillum = tmp->preillum;
    ls->occupied = tmp->occupied;
    free(tmp);
    *out = ls;
    ls->num_blocks = h->num_blocks;
    ls->occ_words = (ls->shafts_per_voxel + 63u) / 64u;
    ls->num_occupied = shafts - h->empty_shafts;
    ls->num_cand = (h->payloads & RL_LS_CANDIDATES) ? h->num_cand : 0;
    if ((st = check_contents(ls, path)))
        return st;
    rl_linespace_stats *t = &ls->stats;
    t->filled_voxels = h->num_blocks;
    t->shafts = shafts;
    t->empty_shafts = h->empty_shafts;
    t->candidates = h->candidates;
    t->max_candidates = h->max_candidates;
    t->mean_candidates = h->mean_candidates;
    t->truncated_shafts = h->truncated_shafts;
    t->memory_bytes = rl_ls_memory_bytes(ls);
    ls->committed = true;
    return RL_OK;
}

rl_status rl_linespace_load(const rl_accel *grid, const char *path, rl_linespace **out)
{
    if (!grid || !path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_linespace_load: NULL argument");
    if (!little_endian())
        return rl_error(RL_ERR_UNSUPPORTED, "linespace: files are little-endian only");
    FILE *f = fopen(path, "rb");
    if (!f)
        return rl_error(RL_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    unsigned char buf[HEADER_BYTES];
    header h;
    uint64_t shafts = 0;
    array_sizes s = { 0 };
    rl_linespace *ls = NULL;
    rl_status st = load_header(f, path, buf, &h, &shafts, &s);
    if (st == RL_OK && !(ls = rl_calloc(1, sizeof *ls)))
        st = RL_ERR_OUT_OF_MEMORY;
    if (st == RL_OK)
        st = load_arrays(f, path, buf, s, ls);
    if (st == RL_OK)
        st = check_grid(grid, &h, path);
    rl_linespace *loaded = NULL;
    if (st == RL_OK) {
        st = adopt(grid, &h, shafts, ls, path, &loaded);
        if (loaded)
            ls = loaded;       /* tmp was taken over */
    }
    fclose(f);
    if (st) {
        rl_linespace_release(ls);
        return st;
    }
    *out = ls;
    return RL_OK;
}
