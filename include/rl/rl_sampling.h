/* rl_sampling.h: global approximation of a position-dependent property by
 * sampling (Jähn 2015, Ch. 5).
 *
 * rl_sample_property() evaluates a committed rl_property at many positions
 * of a region and returns an approximation (rl_approx): a hierarchy of
 * axis-aligned regions (a quadtree-like tree for 2-D slices, an octree-like
 * tree for 3-D regions) whose leaves carry the combined value of the
 * samples inside them. Point queries descend the tree.
 *
 * Methods:
 *   RL_SAMPLING_GRID      Regular sampling (Sec. 5.3, Alg. 5.2): the region
 *                         cut into res.x x res.y x res.z equal boxes, one
 *                         sample at each centre; the reference method.
 *                         With grid_shift (ours) every sample sits at the
 *                         same random offset (from the seed) inside its
 *                         box instead: a randomly shifted lattice, which
 *                         keeps the even cover but not the one alignment
 *                         of the centred lattice with the scene (on a
 *                         regular scene such as `city` that alignment
 *                         moves the grid's error by up to 40 % between
 *                         neighbouring sample counts; bench/README.md).
 *   RL_SAMPLING_ADAPTIVE  Adaptive sampling (Sec. 5.4, Alg. 5.3, default):
 *                         a priority queue of regions ordered by quality
 *                             q = n / (diameter * (max - min))
 *                         (n samples in the region, max - min of their
 *                         values; a region with max == min has q = +inf
 *                         unless it has no samples, q = 0). The worst region
 *                         is split: in 2 along its longest side when
 *                         longest / shortest > sqrt(2), otherwise into 8
 *                         (3-D) or 4 (2-D) equal parts, always at
 *                         0.5f * (min + max), so that neighbours share
 *                         bit-identical corners. A region whose split would
 *                         make a side shorter than min_side (or whose
 *                         midpoint is not representable) is not split
 *                         again (it leaves the queue). Flat regions (q =
 *                         +inf) are split only when no other region is
 *                         left, oldest first. Each new region
 *                         gets samples_base + samples_per_meter * diameter
 *                         samples (rounded up), minus the samples it already
 *                         holds. Samples on region boundaries are shared:
 *                         a sample belongs to every region whose closed box
 *                         contains it. Stops when the sample budget or the
 *                         time budget is spent, or no region can be split.
 *
 * Position variants (how an adaptive region chooses new samples, Sec. 5.4.2):
 *   RL_POSITIONS_RANDOM             uniform random in the region;
 *   RL_POSITIONS_BLUE_NOISE         best of `candidates` (200) uniform
 *                                   candidates by distance to the nearest
 *                                   sample taken so far anywhere (McCool &
 *                                   Fiume 1992; default, see below);
 *   RL_POSITIONS_BLUE_NOISE_CORNERS the region's corners first (when not
 *                                   yet sampled), then blue noise (the
 *                                   thesis' choice for region values);
 *   RL_POSITIONS_GRID               the cell centres of the smallest k^d
 *                                   lattice with k^d >= count, all of them
 *                                   (within the budget).
 *
 * 2-D slices: dims = 2 samples the horizontal plane y = height over the
 * region's x and z extent (y is up in renderlab); region.min.y/max.y are
 * ignored and the approximation's boxes and samples have y = height.
 *
 * Parallel sampling (Sec. 5.5, Alg. 5.4): the positions of all regions made
 * by one split are evaluated as one batch by `workers` threads, each with
 * its own worker index into the property (a property flagged
 * RL_PROPERTY_EXCLUSIVE is evaluated one position at a time). The batch is
 * the work unit a distributed sampler will send to its nodes. Results do
 * not depend on the number of workers: positions are chosen before the
 * batch is evaluated, from the seed alone.
 *
 * Combining values of a region (Alg. 5.3, line 24): mean (default), max or
 * min of the samples inside it; sets are always combined by union.
 *
 * Budgets: at most max_samples evaluations in all. When a split asks for
 * more new positions than the budget has left, its new regions are filled in
 * order and the rest get none; a leaf without samples then takes the
 * combined value (and set, and linear fit) of the samples of its nearest
 * ancestor that has some. The time budget is checked between batches, so a
 * run can overshoot it by one batch (the grid method evaluates batches of 8
 * positions per worker; cells it did not reach take the value of all the
 * samples taken). The adaptive tree is capped at 64 * max_samples + 1024
 * regions, so parameters under which splits take no new samples cannot
 * split forever. The whole region is itself sampled
 * first (as a new region), before the first split; in contrast to Alg. 5.3,
 * line 6, which inserts it unsampled, this gives every approximation a value
 * even when the region is too small to split.
 *
 * Linear fits (Sec. 5.2: a region may carry a gradient instead of a value,
 * Fig. 5.3d): with desc.linear each leaf also fits its samples by least
 * squares with value = offset + gradient . (pos - box centre);
 * rl_approx_query() then returns the fit. A leaf whose own samples give no
 * fit (fewer than dims + 1, all on a line or plane, or a non-finite value;
 * this happens where the budget cut the last split) is fitted to the
 * samples of its nearest ancestor that give one; a leaf without any keeps
 * its combined value (region.linear = false). value, min and max stay those
 * of the leaf's own samples (or, without any, its ancestor's).
 *
 * Point queries and the deviation from the thesis: the thesis answers a
 * query with the combined value of the region holding the position. Every
 * adaptive region holds 5 + 0.05 * diameter samples or more, so with the
 * same budget the regions are several times coarser than the cells of the
 * regular grid (one sample each), and the mean of a region's samples (its
 * shared corners on walls included) is a poor guess inside it wherever the
 * property jumps; this is why the thesis found the grid better in one case
 * of Sec. 5.7. By default a query weights the idw_neighbors (4) nearest
 * samples of all by their inverse squared distance (RL_INTERP_IDW,
 * Shepard's interpolation, a scattered-data alternative to the thesis'
 * Delaunay interpolation in Alg. 5.3, line 21); a query on a sample
 * returns that sample's value, and every answer lies within the range of
 * the samples. RL_INTERP_NEAREST returns the value of the nearest sample
 * (the samples' Voronoi regions). Both search across leaf borders by
 * branch and bound over the region tree (rings of cells on a grid), so
 * adaptive sampling keeps every sample's resolution where it placed them
 * densely. Region values, statistics and heat maps are unchanged;
 * RL_INTERP_REGION gives the thesis' queries. For the centred grid the
 * nearest sample is the cell's own (its centre), the thesis' query; for a
 * shifted grid a nearest-sample query near a cell's border may answer with
 * the neighbour's sample, i.e. the shifted lattice's own Voronoi cells.
 * Measured in `rl bench sampling` (bench/README.md): on `city` the weighting
 * lowers the error of every sampler in nearly every case, the grid's too.
 *
 * Positions, a further deviation: blue noise without the corners is the
 * default. A region's corners serve the thesis' region values (its mean
 * then spans the whole box); queries that interpolate the nearest samples
 * do not need them, and the corners on the sampled domain's own boundary
 * cover only a half, quarter or eighth of the area an inner sample covers.
 * Measured in `rl bench sampling` (bench/README.md).
 *
 * The quality rule, a second deviation: the thesis splits the region of
 * lowest q = n / (diameter * (max - min)). Halving a 2-D region's sides
 * quarters its area but only halves its diameter, so q favours small
 * regions that vary, and the rest of the domain stays sparse. With
 * RL_QUALITY_MEASURE (default) the size is the area or volume: q is the
 * sample density over the value range. RL_QUALITY_DIAMETER is the thesis.
 * Measured in `rl bench sampling` (bench/README.md).
 *
 * Failure: RL_ERR_INVALID_ARG for a NULL argument, a bad region (not
 * finite, empty, or inverted; for 2-D only x and z are checked, and height
 * must be finite), dims not 0, 2 or 3, an unknown enum value, max_seconds
 * negative or NaN, min_side / samples_base / samples_per_meter negative or
 * not finite, a negative grid_res, or workers < 0 or above the property's
 * committed workers; RL_ERR_LIMIT for max_samples, a grid (res.x * res.y *
 * res.z) above RL_SAMPLING_MAX_SAMPLES, or candidates above
 * RL_SAMPLING_MAX_CANDIDATES; RL_ERR_NOT_COMMITTED for an uncommitted
 * property; RL_ERR_CANCELLED when the progress callback returns false; the
 * property's own error otherwise (the first failing position of a batch).
 * *out stays NULL on failure. */
#ifndef RL_SAMPLING_H
#define RL_SAMPLING_H

#include "rl/rl_common.h"
#include "rl/rl_math.h"
#include "rl/rl_property.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Caps on absurd requests: total samples (and grid cells) and blue-noise
 * candidates per sample. */
#define RL_SAMPLING_MAX_SAMPLES    (1u << 24)
#define RL_SAMPLING_MAX_CANDIDATES (1u << 16)
/* Neighbours of an inverse-distance-weighted query: the default and the cap. */
#define RL_SAMPLING_DEFAULT_IDW_NEIGHBORS 4
#define RL_SAMPLING_MAX_IDW_NEIGHBORS 32

typedef enum rl_sampling_method {
    RL_SAMPLING_ADAPTIVE = 0,
    RL_SAMPLING_GRID,
} rl_sampling_method;

typedef enum rl_position_variant {
    RL_POSITIONS_BLUE_NOISE = 0,
    RL_POSITIONS_BLUE_NOISE_CORNERS,
    RL_POSITIONS_RANDOM,
    RL_POSITIONS_GRID,
} rl_position_variant;

typedef enum rl_combine {
    RL_COMBINE_MEAN = 0,
    RL_COMBINE_MAX,
    RL_COMBINE_MIN,
} rl_combine;

/* What a point query returns inside a leaf. */
typedef enum rl_interpolation {
    /* Shepard's inverse distance weighting (power 2) of the idw_neighbors
     * (4) nearest samples of all, across leaf borders. Our default, see
     * below. */
    RL_INTERP_IDW = 0,
    /* The value of the nearest sample (of all samples, across leaf
     * borders): every sample keeps its own resolution. */
    RL_INTERP_NEAREST,
    /* The leaf's combined value (Alg. 5.3, lines 23-25): the thesis. */
    RL_INTERP_REGION,
} rl_interpolation;

/* The size in the quality q = n / (size * (max - min)) that picks the
 * region to split next (Alg. 5.3, line 9). */
typedef enum rl_quality_size {
    /* The region's area (2-D) or volume (3-D): q is then the sample
     * density over the value range, and a split raises it by the same
     * factor everywhere. Our default, see below. */
    RL_QUALITY_MEASURE = 0,
    /* The region's diameter (Sec. 5.4.2): the thesis. */
    RL_QUALITY_DIAMETER,
} rl_quality_size;

typedef struct rl_sampling_desc {          /* zero = default */
    rl_aabb region;                        /* required */
    int dims;                              /* 2 or 3; 0 -> 3 */
    float height;                          /* dims = 2: the slice y = height */
    rl_sampling_method method;
    rl_position_variant positions;         /* adaptive only */
    uint32_t max_samples;                  /* sample budget; 0 -> 1024;
                                              <= RL_SAMPLING_MAX_SAMPLES */
    double max_seconds;                    /* time budget; 0 or +inf -> none */
    float min_side;                        /* m; 0 -> 1 (Sec. 5.4.2) */
    float samples_base;                    /* 0 -> 5 */
    float samples_per_meter;               /* 0 -> 0.05 */
    uint32_t candidates;                   /* blue noise; 0 -> 200 */
    int grid_res[3];                       /* grid method; all 0 (2-D: x and z 0)
                                              -> from max_samples, cells as
                                              close to cubes as possible with
                                              res.x * res.y * res.z <=
                                              max_samples; otherwise each used
                                              component >= 1 and max_samples
                                              is ignored; 2-D uses x and z */
    rl_combine combine;
    bool linear;                           /* also fit a gradient per leaf; queries
                                              then use the fit (overrides
                                              interpolation) */
    rl_interpolation interpolation;        /* point queries; default idw */
    uint32_t idw_neighbors;                /* RL_INTERP_IDW: 0 -> 4;
                                              <= RL_SAMPLING_MAX_IDW_NEIGHBORS */
    rl_quality_size quality_size;          /* adaptive; default measure */
    bool grid_shift;                       /* grid method: every cell's sample at
                                              one seeded random offset from its
                                              cell's corner, the same in all
                                              cells (a randomly shifted lattice);
                                              default the cell centres (Alg. 5.2) */
    uint64_t seed;
    int workers;                           /* 0 -> rl_property_workers(p) */
    rl_progress_fn progress;               /* done = samples / max_samples */
    void *progress_user;
    /* Optional: measures each batch of positions in place of the
     * property's workers, e.g. on the ranks of an MPI job (rl_dist.h,
     * Jähn 2015 Alg. 5.4's sampling nodes). It must give what
     * rl_property_measure_sets gives: values[i] and, when sets is not NULL,
     * the set of pos[i] at sets + i * words. NULL: the property's workers. */
    rl_status (*measure)(void *user, const rl_vec3 *pos, uint32_t count, double *values, uint64_t *sets,
                         size_t words);
    void *measure_user;
    /* Optional: a checkpoint file, a journal of every measured batch
     * flushed to the disk as it is measured. Where it exists, the run
     * replays its batches and measures on from its end, so that a run that
     * stopped is continued by starting it again (the same approximation;
     * time properties keep their recorded values). The file must belong to
     * this run: the property, its options, the set size, the sampling
     * settings and checkpoint_key (the caller's own, e.g. the scene) are
     * its key, and every replayed batch must have the recorded positions;
     * otherwise RL_ERR_IO or RL_ERR_INVALID_ARG, the file untouched. A
     * batch cut off by a killed process is cut away. NULL: none. */
    const char *checkpoint;
    const char *checkpoint_key;
} rl_sampling_desc;

typedef struct rl_approx rl_approx;

/* A leaf region of an approximation. */
typedef struct rl_approx_region {
    rl_aabb box;                           /* 2-D: min.y = max.y = height */
    double value;                          /* combined value of its samples */
    double min, max;                       /* of its samples */
    double quality;                        /* q at the end (INFINITY if flat) */
    uint32_t samples;                      /* samples inside (shared ones too) */
    uint32_t depth;                        /* splits from the root */
    bool linear;                           /* a fit exists (desc.linear) */
    double offset;                         /* fit: value at the box centre */
    double gradient[3];                    /* fit: d value / d pos (2-D: [1] = 0) */
} rl_approx_region;

RL_API rl_status rl_sample_property(rl_property *p, const rl_sampling_desc *desc,
                                    rl_approx **out);
/* Measures the committed property p at count given positions, values[i]
 * at pos[i], as rl_sample_property measures its samples: exclusive
 * properties (times, RL_PROPERTY_EXCLUSIVE) one position at a time on the
 * calling thread outside any parallel region, the others on the property's
 * workers; a value does not depend on which worker measured it. progress
 * (may be NULL) is called on the calling thread with the fraction done;
 * returning false cancels (RL_ERR_CANCELLED). On failure the status and
 * message of the first failing position (a worker's message is moved to
 * the calling thread); values are then partly written. RL_ERR_INVALID_ARG
 * (NULL arguments), RL_ERR_NOT_COMMITTED. */
RL_API rl_status rl_property_measure(rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                                     rl_progress_fn progress, void *user);
/* rl_property_measure, and for properties with sets (rl_property_set_size
 * above 0) also the set of every position into sets + i * words, words =
 * rl_property_set_words(p); sets may be NULL. What a sampling node of a
 * distributed run measures. */
RL_API rl_status rl_property_measure_sets(rl_property *p, const rl_vec3 *pos, size_t count, double *values,
                                          uint64_t *sets, rl_progress_fn progress, void *user);
RL_API void rl_approx_release(rl_approx *a);                 /* NULL is a no-op */

RL_API int rl_approx_dims(const rl_approx *a);
RL_API rl_aabb rl_approx_bounds(const rl_approx *a);         /* 2-D: y = height */
/* The sampled property's name and unit as recorded at sampling time. */
RL_API const char *rl_approx_property(const rl_approx *a);
RL_API const char *rl_approx_unit(const rl_approx *a);
RL_API uint32_t rl_approx_set_size(const rl_approx *a);     /* 0: no sets */
/* Area (2-D) or volume (3-D) of the sampled region. */
RL_API double rl_approx_measure(const rl_approx *a);
RL_API double rl_approx_seconds(const rl_approx *a);        /* wall time of sampling */

RL_API uint32_t rl_approx_region_count(const rl_approx *a); /* leaves */
/* RL_ERR_INVALID_ARG for NULL, RL_ERR_NOT_FOUND for i >= the count (also
 * for rl_approx_sample). */
RL_API rl_status rl_approx_get_region(const rl_approx *a, uint32_t i, rl_approx_region *out);
/* The union set of leaf i (rl_approx_set_size bits; rl_approx_set_size / 64
 * rounded up words), or NULL without sets or for i out of range. */
RL_API const uint64_t *rl_approx_region_set(const rl_approx *a, uint32_t i);

RL_API uint32_t rl_approx_sample_count(const rl_approx *a);
/* pos and value may be NULL. Samples are numbered in evaluation order. */
RL_API rl_status rl_approx_sample(const rl_approx *a, uint32_t i, rl_vec3 *pos, double *value);
/* The set of sample i, or NULL without sets or for i out of range. */
RL_API const uint64_t *rl_approx_sample_set(const rl_approx *a, uint32_t i);

/* The same regions and sample positions with other values: values[i] is
 * the new value of sample i (rl_approx_sample order), and every leaf is
 * recombined from them with the original combine rule and linear setting;
 * named property/unit, without sets. For measuring several properties at
 * exactly the positions one adaptive sampling chose (rl compare), so that
 * their comparison is paired. RL_ERR_INVALID_ARG for NULL arguments or a
 * value that is not finite. */
RL_API rl_status rl_approx_with_values(const rl_approx *a, const double *values,
                                       const char *property, const char *unit, rl_approx **out);

/* Point query: the approximation's value at pos as desc.interpolation
 * says (idw, nearest sample or the leaf's value; the leaf's linear fit at
 * pos when it has one; for 2-D, pos.y is ignored) and, when region is
 * non-NULL, the index of the leaf containing pos. Leaves are numbered depth first, children in the order
 * x before y before z, low before high; on a boundary the leaf with the
 * smaller index wins. RL_ERR_NOT_FOUND outside the (closed) bounds or for a
 * non-finite pos; RL_ERR_INVALID_ARG for NULL a or value. */
RL_API rl_status rl_approx_query(const rl_approx *a, rl_vec3 pos, double *value, uint32_t *region);

/* Changes how rl_approx_query() answers (the samples and regions stay):
 * e.g. the same approximation queried by nearest sample and by inverse
 * distance weighting. idw_neighbors 0 -> 4. RL_ERR_INVALID_ARG for NULL or
 * an unknown value, RL_ERR_LIMIT above RL_SAMPLING_MAX_IDW_NEIGHBORS. */
RL_API rl_status rl_approx_set_interpolation(rl_approx *a, rl_interpolation interpolation,
                                             uint32_t idw_neighbors);
/* JSON with the desc, the tree, the leaves (with sets as index lists) and
 * the samples; load gives an approximation that answers every query
 * identically. RL_ERR_IO, RL_ERR_PARSE (with the offending key) on load. */
/* A renderer input (rl_position_lookup, rl_render.h) over a, which it
 * takes over: a is released with the lookup (its release). Regions are
 * a's leaves; a point outside a's bounds (a 2-D slice: outside its x-z
 * extent, at any height) is not covered. No object pixels offered. On
 * failure a stays the caller's. */
RL_API rl_status rl_approx_lookup(rl_approx *a, rl_position_lookup *out);
/* Gives r the measured inputs its options ask for (rl_renderer_input_slots):
 * visset's visible sets and select's times or threshold property, loaded
 * from the approx.json files its options name or sampled over the scene as
 * they describe (visset.c, select.c). Work done before for the same
 * options and scene is skipped, so it may be called before every frame;
 * renderers without inputs return RL_OK at once. The inputs borrow scene
 * (visset's budget measures pixels in it on demand): render r only with
 * this scene until it is called again for another. Errors: those of
 * loading or sampling; RL_ERR_NOT_COMMITTED. */
RL_API rl_status rl_renderer_prepare_inputs(rl_renderer *r, const rl_scene *scene);

/* The bitsets a loaded file may need (one per node and per sample, of
 * "set_size" bits each): checked before they are allocated, since empty
 * sets take 2 bytes of file each. Above it: RL_ERR_PARSE at "set_size". */
#define RL_APPROX_MAX_SET_BYTES ((size_t)1 << 30)
RL_API rl_status rl_approx_save_json(const rl_approx *a, const char *path);
RL_API rl_status rl_approx_load_json(const char *path, rl_approx **out);

#ifdef __cplusplus
}
#endif
#endif
