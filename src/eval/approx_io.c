/* approx_io.c: an approximation (Jähn 2015, Ch. 5) as JSON, so that a long
 * sampling run is done once and evaluated, plotted or queried later.
 *
 *   { "format": "renderlab-approx", "version": 1,
 *     "property", "unit", "dims", "height", "bounds": [[min], [max]],
 *     "set_size", "seconds", "desc": { the resolved sampling desc },
 *     "nodes":  [ ["leaf"] | ["split2", axis, first_child] |
 *                 ["split", first_child] | ["grid", nx, ny, nz, first_child] ],
 *     "leaves": [ { "value", "min", "max", "quality", "samples", "linear",
 *                   "offset", "gradient", "set": [object indices] } ],
 *     "samples": [ [x, y, z, value] ], "sample_sets": [ [object indices] ] }
 *
 * Boxes are not stored: the loader replays the splits in the order they
 * were made (by first_child), which rebuilds bit-identical boxes with the
 * same midpoint rule, so queries answer identically. Real numbers are
 * written with the fewest of 15 to 17 significant digits that read back
 * exactly (floats pass through doubles exactly); non-finite ones as the
 * strings "nan", "inf", "-inf". The loader checks
 * every key and value; anything malformed is RL_ERR_PARSE at the offending
 * key, with its line and column. */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/json.h"
#include "eval/sampling_internal.h"

#define FORMAT_NAME "renderlab-approx"
#define FORMAT_VERSION 1
/* Bits in a set: the scene's object count; this only stops absurd files. */
#define MAX_SET_SIZE (1u << 26)

static const char *const method_names[] = { "adaptive", "grid", NULL };
static const char *const interpolation_names[] = { "idw", "nearest", "region", NULL };
static const char *const position_names[] = { "blue_noise", "blue_noise_corners", "random", "lattice", NULL };
static const char *const combine_names[] = { "mean", "max", "min", NULL };

/* ---- saving ---- */

/* cJSON prints 15 digits unless they miss the value by more than a relative
 * epsilon, which can lose the last bit; we print the shortest of 15, 16, 17
 * digits that reads back exactly, as raw JSON number text. */
static cJSON *num(double v)
{
    if (isnan(v))
        return cJSON_CreateString("nan");
    if (isinf(v))
        return cJSON_CreateString(v > 0 ? "inf" : "-inf");
    char buf[40];
    for (int digits = 15; digits <= 17; ++digits) {
        snprintf(buf, sizeof buf, "%.*g", digits, v);
        if (strtod(buf, NULL) == v)
            break;
    }
    return cJSON_CreateRaw(buf);
}

static bool add(cJSON *obj, const char *key, cJSON *item)
{
    if (!item)
        return false;
    cJSON_AddItemToObject(obj, key, item);
    return true;
}

static bool push(cJSON *arr, cJSON *item)
{
    if (!item)
        return false;
    cJSON_AddItemToArray(arr, item);
    return true;
}

static cJSON *vec3(rl_vec3 v)
{
    cJSON *a = cJSON_CreateArray();
    if (a && !(push(a, num(v.x)) && push(a, num(v.y)) && push(a, num(v.z)))) {
        cJSON_Delete(a);
        return NULL;
    }
    return a;
}

static cJSON *index_set(const uint64_t *set, uint32_t bits)
{
    cJSON *a = cJSON_CreateArray();
    for (uint32_t i = 0; a && i < bits; ++i)
        if ((set[i / 64] >> (i % 64)) & 1u)
            if (!push(a, cJSON_CreateNumber(i))) {
                cJSON_Delete(a);
                return NULL;
            }
    return a;
}

static cJSON *save_desc(const rl_sampling_desc *d)
{
    char seed[32];
    snprintf(seed, sizeof seed, "%" PRIu64, d->seed);
    cJSON *o = cJSON_CreateObject(), *res = cJSON_CreateArray();
    if (!o || !add(o, "grid_res", res)) {
        cJSON_Delete(o);
        cJSON_Delete(res);
        return NULL;
    }
    bool ok = push(res, cJSON_CreateNumber(d->grid_res[0])) && push(res, cJSON_CreateNumber(d->grid_res[1])) &&
              push(res, cJSON_CreateNumber(d->grid_res[2])) &&
              add(o, "method", cJSON_CreateString(method_names[d->method])) &&
              add(o, "positions", cJSON_CreateString(position_names[d->positions])) &&
              add(o, "max_samples", cJSON_CreateNumber(d->max_samples)) &&
              add(o, "max_seconds", num(d->max_seconds)) && add(o, "min_side", num(d->min_side)) &&
              add(o, "samples_base", num(d->samples_base)) &&
              add(o, "samples_per_meter", num(d->samples_per_meter)) &&
              add(o, "candidates", cJSON_CreateNumber(d->candidates)) &&
              add(o, "combine", cJSON_CreateString(combine_names[d->combine])) &&
              add(o, "seed", cJSON_CreateString(seed)) && add(o, "workers", cJSON_CreateNumber(d->workers)) &&
              add(o, "linear", cJSON_CreateBool(d->linear)) &&
              add(o, "interpolation", cJSON_CreateString(interpolation_names[d->interpolation])) &&
              add(o, "idw_neighbors", cJSON_CreateNumber(d->idw_neighbors)) &&
              add(o, "quality_size", cJSON_CreateString(d->quality_size == RL_QUALITY_DIAMETER
                                                            ? "diameter" : "measure")) &&
              add(o, "grid_shift", cJSON_CreateBool(d->grid_shift));
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

static cJSON *save_node(const rl_approx *a, const rl_approx_node *n)
{
    cJSON *arr = cJSON_CreateArray();
    bool ok = arr != NULL;
    switch (n->kind) {
    case RL_NODE_LEAF: ok = ok && push(arr, cJSON_CreateString("leaf")); break;
    case RL_NODE_SPLIT2:
        ok = ok && push(arr, cJSON_CreateString("split2")) && push(arr, cJSON_CreateNumber(n->axis)) &&
             push(arr, cJSON_CreateNumber(n->first_child));
        break;
    case RL_NODE_SPLIT_ALL:
        ok = ok && push(arr, cJSON_CreateString("split")) && push(arr, cJSON_CreateNumber(n->first_child));
        break;
    default:
        ok = ok && push(arr, cJSON_CreateString("grid")) && push(arr, cJSON_CreateNumber(n->res[0])) &&
             push(arr, cJSON_CreateNumber(n->res[1])) && push(arr, cJSON_CreateNumber(n->res[2])) &&
             push(arr, cJSON_CreateNumber(n->first_child));
        break;
    }
    (void)a;
    if (!ok) {
        cJSON_Delete(arr);
        return NULL;
    }
    return arr;
}

static cJSON *save_leaf(const rl_approx *a, uint32_t i)
{
    const rl_approx_region *r = &a->leaves[i];
    cJSON *o = cJSON_CreateObject();
    bool ok = o && add(o, "value", num(r->value)) && add(o, "min", num(r->min)) && add(o, "max", num(r->max)) &&
              add(o, "quality", num(r->quality)) && add(o, "samples", cJSON_CreateNumber(r->samples)) &&
              add(o, "linear", cJSON_CreateBool(r->linear));
    if (ok && r->linear) {
        cJSON *g = cJSON_CreateArray();
        ok = add(o, "gradient", g) && push(g, num(r->gradient[0])) && push(g, num(r->gradient[1])) &&
             push(g, num(r->gradient[2])) && add(o, "offset", num(r->offset));
    }
    if (ok && a->set_words)
        ok = add(o, "set", index_set(a->leaf_sets + (size_t)i * a->set_words, a->set_size));
    if (!ok) {
        cJSON_Delete(o);
        return NULL;
    }
    return o;
}

/* Creates an empty array or object as obj[key]; NULL when out of memory. */
static cJSON *add_new(cJSON *obj, const char *key, bool array)
{
    cJSON *c = array ? cJSON_CreateArray() : cJSON_CreateObject();
    return add(obj, key, c) ? c : NULL;
}

static cJSON *build(const rl_approx *a)
{
    cJSON *root = cJSON_CreateObject();
    if (!root)
        return NULL;
    cJSON *bounds = NULL, *nodes = NULL, *leaves = NULL, *samples = NULL, *sets = NULL;
    bool ok = add(root, "format", cJSON_CreateString(FORMAT_NAME)) &&
              add(root, "version", cJSON_CreateNumber(FORMAT_VERSION)) &&
              add(root, "property", cJSON_CreateString(a->property)) &&
              add(root, "unit", cJSON_CreateString(a->unit)) && add(root, "dims", cJSON_CreateNumber(a->dims)) &&
              add(root, "height", num(a->height)) && (bounds = add_new(root, "bounds", true)) &&
              push(bounds, vec3(a->bounds.min)) && push(bounds, vec3(a->bounds.max)) &&
              add(root, "set_size", cJSON_CreateNumber(a->set_size)) && add(root, "seconds", num(a->seconds)) &&
              add(root, "desc", save_desc(&a->desc)) && (nodes = add_new(root, "nodes", true)) &&
              (leaves = add_new(root, "leaves", true)) && (samples = add_new(root, "samples", true)) &&
              (!a->set_words || (sets = add_new(root, "sample_sets", true)));
    for (uint32_t i = 0; ok && i < a->node_count; ++i)
        ok = push(nodes, save_node(a, &a->nodes[i]));
    for (uint32_t i = 0; ok && i < a->leaf_count; ++i)
        ok = push(leaves, save_leaf(a, i));
    for (uint32_t i = 0; ok && i < a->sample_count; ++i) {
        cJSON *s = cJSON_CreateArray();
        rl_vec3 p = a->sample_pos[i];
        ok = push(samples, s) && push(s, num(p.x)) && push(s, num(p.y)) && push(s, num(p.z)) &&
             push(s, num(a->sample_value[i]));
        if (ok && a->set_words)
            ok = push(sets, index_set(a->sample_sets + (size_t)i * a->set_words, a->set_size));
    }
    if (!ok) {
        cJSON_Delete(root);
        return NULL;
    }
    return root;
}

rl_status rl_approx_save_json(const rl_approx *a, const char *path)
{
    if (!a || !path)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_save_json: approximation or path is NULL");
    cJSON *root = build(a);
    if (!root)
        return rl_error(RL_ERR_OUT_OF_MEMORY, "%s: cannot build the JSON document", path);
    rl_status st = rl_json_write_file(root, path);
    cJSON_Delete(root);
    return st;
}

/* ---- loading ---- */

typedef struct loader {
    const rl_json_doc *doc;
    uint32_t want_set_size;     /* RL_APPROX_ANY_SET_SIZE: no scene to compare with */
} loader;

static rl_status member(const loader *l, const cJSON *obj, const char *key, const char *what, cJSON **out)
{
    cJSON *c = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!c)
        return rl_json_error(l->doc, obj, "missing key \"%s\" in %s", key, what);
    *out = c;
    return RL_OK;
}

/* A number, or "nan", "inf", "-inf" (how the saver writes non-finite ones). */
static rl_status get_num(const loader *l, const cJSON *item, const char *key, double *out)
{
    if (cJSON_IsNumber(item)) {
        *out = item->valuedouble;
        return RL_OK;
    }
    if (cJSON_IsString(item)) {
        const char *s = item->valuestring;
        if (strcmp(s, "nan") == 0) {
            *out = NAN;
            return RL_OK;
        }
        if (strcmp(s, "inf") == 0 || strcmp(s, "-inf") == 0) {
            *out = s[0] == '-' ? -INFINITY : INFINITY;
            return RL_OK;
        }
    }
    return rl_json_error(l->doc, item, "\"%s\": expected a number", key);
}

static rl_status get_finite(const loader *l, const cJSON *item, const char *key, double *out)
{
    double v = 0.0;
    rl_status st = get_num(l, item, key, &v);
    if (st == RL_OK && !isfinite(v))
        return rl_json_error(l->doc, item, "\"%s\": expected a finite number", key);
    if (st == RL_OK)
        *out = v;
    return st;
}

/* A float stored as a double must come back as the same float. Tools that
 * re-print the file may shorten the number to 15 digits (cJSON does), which
 * moves it by far less than 1e-12 of itself but no longer hits the float
 * exactly; such a number still names one float. A value like 0.1 (1.5e-9
 * from the nearest float) was not written by us and is refused. */
static rl_status get_float(const loader *l, const cJSON *item, const char *key, float *out)
{
    double v = 0.0;
    rl_status st = get_finite(l, item, key, &v);
    if (st != RL_OK)
        return st;
    if (fabs(v) > 3.4e38 || fabs((double)(float)v - v) > 1e-12 * fabs(v))
        return rl_json_error(l->doc, item, "\"%s\": %.17g is not a single-precision number", key, v);
    *out = (float)v;
    return RL_OK;
}

static rl_status get_uint(const loader *l, const cJSON *item, const char *key, uint64_t max, uint64_t *out)
{
    if (!cJSON_IsNumber(item) || !(item->valuedouble >= 0.0) || item->valuedouble != floor(item->valuedouble) ||
        item->valuedouble > (double)max)
        return rl_json_error(l->doc, item, "\"%s\": expected an integer in [0, %" PRIu64 "]", key, max);
    *out = (uint64_t)item->valuedouble;
    return RL_OK;
}

static rl_status get_enum(const loader *l, const cJSON *item, const char *key, const char *const *names, int *out)
{
    if (cJSON_IsString(item))
        for (int i = 0; names[i]; ++i)
            if (strcmp(item->valuestring, names[i]) == 0) {
                *out = i;
                return RL_OK;
            }
    return rl_json_error(l->doc, item, "\"%s\": unknown value", key);
}

static rl_status get_array(const loader *l, const cJSON *item, const char *key, int min_len, int max_len, int *len)
{
    if (!cJSON_IsArray(item))
        return rl_json_error(l->doc, item, "\"%s\": expected an array", key);
    int n = cJSON_GetArraySize(item);
    if (n < min_len || n > max_len)
        return rl_json_error(l->doc, item, "\"%s\": expected %d to %d elements, found %d", key, min_len, max_len, n);
    *len = n;
    return RL_OK;
}

static rl_status get_vec3(const loader *l, const cJSON *item, const char *key, rl_vec3 *out)
{
    int n = 0;
    rl_status st = get_array(l, item, key, 3, 3, &n);
    float v[3];
    const cJSON *c = item ? item->child : NULL;
    for (int i = 0; st == RL_OK && i < 3; ++i, c = c->next)
        st = get_float(l, c, key, &v[i]);
    if (st == RL_OK)
        *out = (rl_vec3){ v[0], v[1], v[2] };
    return st;
}

static rl_status get_set(const loader *l, const cJSON *item, const char *key, uint32_t bits, uint64_t *set)
{
    int n = 0;
    rl_status st = get_array(l, item, key, 0, (int)bits, &n);
    for (const cJSON *c = st == RL_OK ? item->child : NULL; c && st == RL_OK; c = c->next) {
        uint64_t i = 0;
        st = get_uint(l, c, key, bits - 1u, &i);
        if (st == RL_OK)
            set[i / 64] |= 1ull << (i % 64);
    }
    return st;
}

static rl_status load_desc(const loader *l, const cJSON *o, int dims, rl_sampling_desc *d)
{
    static const char *const keys[] = { "method", "positions", "max_samples", "max_seconds", "min_side",
                                        "samples_base", "samples_per_meter", "candidates", "grid_res",
                                        "combine", "seed", "workers", "linear", "interpolation",
                                        "idw_neighbors", "quality_size", "grid_shift", NULL };
    rl_status st = rl_json_check_keys(l->doc, o, "\"desc\"", keys);
    cJSON *c = NULL;
    int e = 0;
    uint64_t u = 0;
    double v = 0.0;
    memset(d, 0, sizeof *d);
    d->dims = dims;
    if (st == RL_OK && (st = member(l, o, "method", "\"desc\"", &c)) == RL_OK &&
        (st = get_enum(l, c, "method", method_names, &e)) == RL_OK)
        d->method = (rl_sampling_method)e;
    if (st == RL_OK && (st = member(l, o, "positions", "\"desc\"", &c)) == RL_OK &&
        (st = get_enum(l, c, "positions", position_names, &e)) == RL_OK)
        d->positions = (rl_position_variant)e;
    if (st == RL_OK && (st = member(l, o, "combine", "\"desc\"", &c)) == RL_OK &&
        (st = get_enum(l, c, "combine", combine_names, &e)) == RL_OK)
        d->combine = (rl_combine)e;
    if (st == RL_OK && (st = member(l, o, "max_samples", "\"desc\"", &c)) == RL_OK &&
        (st = get_uint(l, c, "max_samples", RL_SAMPLING_MAX_SAMPLES, &u)) == RL_OK)
        d->max_samples = (uint32_t)u;
    if (st == RL_OK && (st = member(l, o, "candidates", "\"desc\"", &c)) == RL_OK &&
        (st = get_uint(l, c, "candidates", RL_SAMPLING_MAX_CANDIDATES, &u)) == RL_OK)
        d->candidates = (uint32_t)u;
    if (st == RL_OK && (st = member(l, o, "workers", "\"desc\"", &c)) == RL_OK &&
        (st = get_uint(l, c, "workers", INT32_MAX, &u)) == RL_OK)
        d->workers = (int)u;
    if (st == RL_OK && (st = member(l, o, "max_seconds", "\"desc\"", &c)) == RL_OK &&
        (st = get_num(l, c, "max_seconds", &v)) == RL_OK) {
        if (isnan(v) || v < 0.0)
            return rl_json_error(l->doc, c, "\"max_seconds\": expected a number >= 0");
        d->max_seconds = v;
    }
    const char *fkeys[] = { "min_side", "samples_base", "samples_per_meter" };
    float *fields[] = { &d->min_side, &d->samples_base, &d->samples_per_meter };
    for (int i = 0; i < 3 && st == RL_OK; ++i)
        if ((st = member(l, o, fkeys[i], "\"desc\"", &c)) == RL_OK &&
            (st = get_float(l, c, fkeys[i], fields[i])) == RL_OK && *fields[i] < 0.0f)
            return rl_json_error(l->doc, c, "\"%s\": expected a number >= 0", fkeys[i]);
    int n = 0;
    if (st == RL_OK && (st = member(l, o, "grid_res", "\"desc\"", &c)) == RL_OK &&
        (st = get_array(l, c, "grid_res", 3, 3, &n)) == RL_OK) {
        const cJSON *r = c->child;
        for (int i = 0; i < 3 && st == RL_OK; ++i, r = r->next)
            if ((st = get_uint(l, r, "grid_res", RL_SAMPLING_MAX_SAMPLES, &u)) == RL_OK)
                d->grid_res[i] = (int)u;
    }
    if (st == RL_OK && (st = member(l, o, "seed", "\"desc\"", &c)) == RL_OK) {
        const char *s = cJSON_IsString(c) ? c->valuestring : "";
        char *end = NULL;
        unsigned long long seed = strtoull(s, &end, 10);
        if (!s[0] || *end || s[0] == '-' || s[0] == '+' || s[0] == ' ')
            return rl_json_error(l->doc, c, "\"seed\": expected an unsigned integer as a string");
        d->seed = (uint64_t)seed;
    }
    if (st == RL_OK && (st = member(l, o, "linear", "\"desc\"", &c)) == RL_OK) {
        if (!cJSON_IsBool(c))
            return rl_json_error(l->doc, c, "\"linear\": expected true or false");
        d->linear = cJSON_IsTrue(c);
    }
    if (st == RL_OK && (st = member(l, o, "interpolation", "\"desc\"", &c)) == RL_OK &&
        (st = get_enum(l, c, "interpolation", interpolation_names, &e)) == RL_OK)
        d->interpolation = (rl_interpolation)e;
    /* Files written before the option existed have no neighbour count. */
    d->idw_neighbors = RL_SAMPLING_DEFAULT_IDW_NEIGHBORS;
    c = cJSON_GetObjectItemCaseSensitive(o, "idw_neighbors");
    if (st == RL_OK && c && (st = get_uint(l, c, "idw_neighbors", RL_SAMPLING_MAX_IDW_NEIGHBORS, &u)) == RL_OK) {
        if (u == 0)
            return rl_json_error(l->doc, c, "\"idw_neighbors\": expected 1 to %d", RL_SAMPLING_MAX_IDW_NEIGHBORS);
        d->idw_neighbors = (uint32_t)u;
    }
    /* Files written before the option existed were made with the diameter. */
    d->quality_size = RL_QUALITY_DIAMETER;
    c = cJSON_GetObjectItemCaseSensitive(o, "quality_size");
    if (st == RL_OK && c) {
        const char *s = cJSON_IsString(c) ? c->valuestring : "";
        if (strcmp(s, "measure") != 0 && strcmp(s, "diameter") != 0)
            return rl_json_error(l->doc, c, "\"quality_size\": expected \"measure\" or \"diameter\"");
        d->quality_size = strcmp(s, "diameter") == 0 ? RL_QUALITY_DIAMETER : RL_QUALITY_MEASURE;
    }
    /* Optional too: older files have centred grids. */
    c = cJSON_GetObjectItemCaseSensitive(o, "grid_shift");
    if (st == RL_OK && c) {
        if (!cJSON_IsBool(c))
            return rl_json_error(l->doc, c, "\"grid_shift\": expected true or false");
        d->grid_shift = cJSON_IsTrue(c);
    }
    return st;
}

/* Replays the splits in creation order (ascending first_child): each one
 * appends its children at the end, exactly where the file says they are. */
typedef struct split_rec {
    uint32_t node, first;
    rl_approx_node_kind kind;
    int axis, res[3];
    const cJSON *item;
} split_rec;

static int cmp_split(const void *x, const void *y)
{
    const split_rec *a = x, *b = y;
    return (a->first > b->first) - (a->first < b->first);
}

static rl_status load_nodes(const loader *l, const cJSON *nodes, rl_approx *a)
{
    int count = 0;
    rl_status st = get_array(l, nodes, "nodes", 1, INT32_MAX, &count);
    if (st != RL_OK)
        return st;
    split_rec *splits = rl_calloc((size_t)count, sizeof *splits);
    if (!splits)
        return RL_ERR_OUT_OF_MEMORY;
    uint32_t ns = 0, index = 0;
    for (const cJSON *c = nodes->child; c && st == RL_OK; c = c->next, ++index) {
        int len = 0;
        if ((st = get_array(l, c, "nodes", 1, 5, &len)) != RL_OK)
            break;
        const cJSON *kind = c->child;
        const char *k = cJSON_IsString(kind) ? kind->valuestring : "";
        split_rec r = { .node = index, .item = c, .res = { 1, 1, 1 } };
        uint64_t u[4] = { 0, 0, 0, 0 };
        int want = strcmp(k, "leaf") == 0 ? 1 : strcmp(k, "split2") == 0 ? 3 : strcmp(k, "split") == 0 ? 2
                 : strcmp(k, "grid") == 0 ? 5 : -1;
        if (want < 0 || want != len) {
            st = rl_json_error(l->doc, c, "\"nodes\"[%u]: expected [\"leaf\"], [\"split2\", axis, first], "
                               "[\"split\", first] or [\"grid\", nx, ny, nz, first]", index);
            break;
        }
        if (want == 1)
            continue;
        int v = 0;
        for (const cJSON *e = kind->next; e && st == RL_OK; e = e->next, ++v)
            st = get_uint(l, e, "nodes", e->next ? RL_SAMPLING_MAX_SAMPLES : (uint64_t)count - 1u, &u[v]);
        if (st != RL_OK)
            break;
        r.first = (uint32_t)u[v - 1];
        if (want == 3) {
            r.kind = RL_NODE_SPLIT2;
            r.axis = (int)u[0];
            if (r.axis > 2 || (a->dims == 2 && r.axis == 1))
                st = rl_json_error(l->doc, c, "\"nodes\"[%u]: axis %d is not split in %d-D", index, r.axis, a->dims);
        } else if (want == 2) {
            r.kind = RL_NODE_SPLIT_ALL;
        } else {
            r.kind = RL_NODE_GRID;
            for (int i = 0; i < 3; ++i)
                r.res[i] = (int)u[i];
            if (r.res[0] < 1 || r.res[1] < 1 || r.res[2] < 1 || (a->dims == 2 && r.res[1] != 1) ||
                (double)r.res[0] * r.res[1] * r.res[2] > (double)RL_SAMPLING_MAX_SAMPLES)
                st = rl_json_error(l->doc, c, "\"nodes\"[%u]: bad grid resolution", index);
        }
        splits[ns++] = r;
    }
    /* The children the splits make must be exactly the other nodes; checked
     * before replaying, so a forged grid cannot make us allocate much. */
    double made = 1.0;
    for (uint32_t i = 0; i < ns && st == RL_OK; ++i)
        made += splits[i].kind == RL_NODE_SPLIT2 ? 2.0
              : splits[i].kind == RL_NODE_SPLIT_ALL ? (a->dims == 2 ? 4.0 : 8.0)
              : (double)splits[i].res[0] * splits[i].res[1] * splits[i].res[2];
    if (st == RL_OK && made != (double)count)
        st = rl_json_error(l->doc, nodes, "\"nodes\": %d nodes but the splits make %.0f", count, made);
    if (st == RL_OK) {
        qsort(splits, ns, sizeof *splits, cmp_split);
        if (rl_approx_add_node(a, a->bounds, RL_APPROX_NONE, 0) == RL_APPROX_NONE)
            st = RL_ERR_OUT_OF_MEMORY;
    }
    for (uint32_t i = 0; i < ns && st == RL_OK; ++i) {
        split_rec *r = &splits[i];
        if (r->node >= a->node_count || a->nodes[r->node].kind != RL_NODE_LEAF || r->first != a->node_count) {
            st = rl_json_error(l->doc, r->item, "\"nodes\"[%u]: children at %u do not form a tree", r->node, r->first);
            break;
        }
        if (rl_approx_split(a, r->node, r->kind, r->axis, r->res) == RL_APPROX_NONE)
            st = rl_last_status() != RL_OK ? rl_last_status() : RL_ERR_OUT_OF_MEMORY;
    }
    if (st == RL_OK && a->node_count != (uint32_t)count)
        st = rl_json_error(l->doc, nodes, "\"nodes\": %d nodes but the splits make %u", count, a->node_count);
    free(splits);
    return st;
}

static rl_status load_leaf(const loader *l, const cJSON *o, rl_approx *a, uint32_t i)
{
    static const char *const keys[] = { "value", "min", "max", "quality", "samples", "linear",
                                        "offset", "gradient", "set", NULL };
    rl_status st = rl_json_check_keys(l->doc, o, "a leaf", keys);
    rl_approx_region *r = &a->leaves[i];
    cJSON *c = NULL;
    const char *nums[] = { "value", "min", "max", "quality" };
    double *dst[] = { &r->value, &r->min, &r->max, &r->quality };
    for (int k = 0; k < 4 && st == RL_OK; ++k)
        if ((st = member(l, o, nums[k], "a leaf", &c)) == RL_OK)
            st = get_num(l, c, nums[k], dst[k]);
    uint64_t u = 0;
    if (st == RL_OK && (st = member(l, o, "samples", "a leaf", &c)) == RL_OK &&
        (st = get_uint(l, c, "samples", a->sample_count, &u)) == RL_OK)
        r->samples = (uint32_t)u;
    if (st == RL_OK && (st = member(l, o, "linear", "a leaf", &c)) == RL_OK) {
        if (!cJSON_IsBool(c))
            return rl_json_error(l->doc, c, "\"linear\": expected true or false");
        r->linear = cJSON_IsTrue(c);
    }
    cJSON *off = cJSON_GetObjectItemCaseSensitive(o, "offset"), *g = cJSON_GetObjectItemCaseSensitive(o, "gradient");
    if (st == RL_OK && r->linear) {
        int n;
        if ((st = member(l, o, "offset", "a linear leaf", &off)) == RL_OK &&
            (st = get_finite(l, off, "offset", &r->offset)) == RL_OK &&
            (st = member(l, o, "gradient", "a linear leaf", &g)) == RL_OK &&
            (st = get_array(l, g, "gradient", 3, 3, &n)) == RL_OK) {
            const cJSON *e = g->child;
            for (int k = 0; k < 3 && st == RL_OK; ++k, e = e->next)
                st = get_finite(l, e, "gradient", &r->gradient[k]);
            if (st == RL_OK && a->dims == 2 && r->gradient[1] != 0.0)
                st = rl_json_error(l->doc, g, "\"gradient\": a 2-D leaf has no y component");
        }
    } else if (st == RL_OK && (off || g)) {
        st = rl_json_error(l->doc, off ? off : g, "\"%s\" in a leaf that is not linear", off ? "offset" : "gradient");
    }
    cJSON *set = cJSON_GetObjectItemCaseSensitive(o, "set");
    if (st == RL_OK && a->set_words) {
        if ((st = member(l, o, "set", "a leaf", &set)) == RL_OK)
            st = get_set(l, set, "set", a->set_size, a->leaf_sets + (size_t)i * a->set_words);
    } else if (st == RL_OK && set) {
        st = rl_json_error(l->doc, set, "\"set\" without \"set_size\"");
    }
    return st;
}

static rl_status load_samples(const loader *l, const cJSON *root, rl_approx *a)
{
    cJSON *samples = NULL, *sets = cJSON_GetObjectItemCaseSensitive(root, "sample_sets");
    int n = 0;
    rl_status st = member(l, root, "samples", "the file", &samples);
    if (st == RL_OK)
        st = get_array(l, samples, "samples", 0, (int)RL_SAMPLING_MAX_SAMPLES, &n);
    if (st != RL_OK)
        return st;
    if (a->set_words) {
        int m;
        if ((st = member(l, root, "sample_sets", "a file with sets", &sets)) != RL_OK ||
            (st = get_array(l, sets, "sample_sets", n, n, &m)) != RL_OK)
            return st;
    } else if (sets) {
        return rl_json_error(l->doc, sets, "\"sample_sets\" without \"set_size\"");
    }
    uint64_t *scratch = a->set_words ? rl_calloc(a->set_words, sizeof *scratch) : NULL;
    if (a->set_words && !scratch)
        return RL_ERR_OUT_OF_MEMORY;
    const cJSON *sc = a->set_words ? sets->child : NULL;
    for (const cJSON *c = samples->child; c && st == RL_OK; c = c->next) {
        int len = 0;
        float p[3];
        double v = 0.0;
        if ((st = get_array(l, c, "samples", 4, 4, &len)) != RL_OK)
            break;
        const cJSON *e = c->child;
        for (int k = 0; k < 3 && st == RL_OK; ++k, e = e->next)
            st = get_float(l, e, "samples", &p[k]);
        if (st == RL_OK)
            st = get_num(l, e, "samples", &v);
        rl_vec3 pos = { p[0], p[1], p[2] };
        if (st == RL_OK && !rl_box_holds(a->bounds, pos))
            st = rl_json_error(l->doc, c, "\"samples\": position outside \"bounds\"");
        if (st == RL_OK && a->set_words) {
            memset(scratch, 0, a->set_words * sizeof *scratch);
            st = get_set(l, sc, "sample_sets", a->set_size, scratch);
            sc = sc->next;
        }
        if (st == RL_OK && rl_approx_add_sample(a, pos, v, scratch) == RL_APPROX_NONE)
            st = RL_ERR_OUT_OF_MEMORY;
    }
    free(scratch);
    return st;
}

/* The sets are bitsets of set_size bits, one per node (an upper bound on
 * the leaves) and one per sample: an empty set is 2 bytes of file and
 * set_size / 8 bytes of memory, so a small file can claim gigabytes. Both
 * are checked before anything is allocated: the size against the scene
 * the sets are for, and the total against RL_APPROX_MAX_SET_BYTES. */
static rl_status check_set_size(const loader *l, const cJSON *root, const cJSON *item, uint64_t set_size)
{
    if (l->want_set_size != RL_APPROX_ANY_SET_SIZE && set_size != l->want_set_size)
        return rl_error(RL_ERR_INVALID_ARG,
                        "%s: sets of %" PRIu64 " objects, the scene has %u (is it the visibility property "
                        "of this scene?)",
                        rl_json_name(l->doc), set_size, l->want_set_size);
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    const cJSON *samples = cJSON_GetObjectItemCaseSensitive(root, "samples");
    double sets = (double)(cJSON_IsArray(nodes) ? cJSON_GetArraySize(nodes) : 0) +
                  (double)(cJSON_IsArray(samples) ? cJSON_GetArraySize(samples) : 0);
    double bytes = sets * (double)((set_size + 63) / 64) * 8.0;
    if (bytes > (double)RL_APPROX_MAX_SET_BYTES)
        return rl_json_error(l->doc, item,
                             "\"set_size\": %.0f sets of %" PRIu64 " bits would take %.0f MiB, more than "
                             "the limit of %.0f MiB",
                             sets, set_size, bytes / 1048576.0, (double)RL_APPROX_MAX_SET_BYTES / 1048576.0);
    return RL_OK;
}

static rl_status load(const loader *l, const cJSON *root, rl_approx **out)
{
    static const char *const keys[] = { "format", "version", "property", "unit", "dims", "height", "bounds",
                                        "set_size", "seconds", "desc", "nodes", "leaves", "samples",
                                        "sample_sets", NULL };
    rl_status st = rl_json_check_keys(l->doc, root, "the file", keys);
    cJSON *c = NULL;
    if (st == RL_OK && (st = member(l, root, "format", "the file", &c)) == RL_OK &&
        !(cJSON_IsString(c) && strcmp(c->valuestring, FORMAT_NAME) == 0))
        return rl_json_error(l->doc, c, "\"format\": expected \"%s\"", FORMAT_NAME);
    uint64_t u = 0;
    if (st == RL_OK && (st = member(l, root, "version", "the file", &c)) == RL_OK &&
        (st = get_uint(l, c, "version", UINT32_MAX, &u)) == RL_OK && u != FORMAT_VERSION)
        return rl_json_error(l->doc, c, "\"version\": %" PRIu64 " is not supported (expected %d)", u,
                             FORMAT_VERSION);
    const char *names[2] = { "", "" };
    const char *name_keys[2] = { "property", "unit" };
    for (int k = 0; k < 2 && st == RL_OK; ++k)
        if ((st = member(l, root, name_keys[k], "the file", &c)) == RL_OK) {
            if (!cJSON_IsString(c))
                return rl_json_error(l->doc, c, "\"%s\": expected a string", name_keys[k]);
            names[k] = c->valuestring;
        }
    int dims = 0;
    float height = 0.0f;
    if (st == RL_OK && (st = member(l, root, "dims", "the file", &c)) == RL_OK &&
        (st = get_uint(l, c, "dims", 3, &u)) == RL_OK) {
        if (u != 2 && u != 3)
            return rl_json_error(l->doc, c, "\"dims\": expected 2 or 3");
        dims = (int)u;
    }
    if (st == RL_OK && (st = member(l, root, "height", "the file", &c)) == RL_OK)
        st = get_float(l, c, "height", &height);
    rl_aabb bounds = { { 0, 0, 0 }, { 0, 0, 0 } };
    cJSON *b = NULL;
    int n = 0;
    if (st == RL_OK && (st = member(l, root, "bounds", "the file", &b)) == RL_OK &&
        (st = get_array(l, b, "bounds", 2, 2, &n)) == RL_OK && (st = get_vec3(l, b->child, "bounds", &bounds.min)) == RL_OK &&
        (st = get_vec3(l, b->child->next, "bounds", &bounds.max)) == RL_OK) {
        for (int k = 0; k < rl_approx_axis_count(dims); ++k) {
            int ax = rl_approx_axis(dims, k);
            if (!(rl_v3_get(bounds.max, ax) > rl_v3_get(bounds.min, ax)))
                return rl_json_error(l->doc, b, "\"bounds\": empty or inverted");
        }
        if (dims == 2 && (bounds.min.y != height || bounds.max.y != height))
            return rl_json_error(l->doc, b, "\"bounds\": a 2-D slice has y = \"height\"");
    }
    uint64_t set_size = 0;
    if (st == RL_OK && (st = member(l, root, "set_size", "the file", &c)) == RL_OK &&
        (st = get_uint(l, c, "set_size", MAX_SET_SIZE, &set_size)) == RL_OK)
        st = check_set_size(l, root, c, set_size);
    double seconds = 0.0;
    if (st == RL_OK && (st = member(l, root, "seconds", "the file", &c)) == RL_OK)
        st = get_finite(l, c, "seconds", &seconds);
    if (st != RL_OK)
        return st;
    rl_approx *a = NULL;
    if ((st = rl_approx_alloc(dims, height, bounds, names[0], names[1], (uint32_t)set_size, &a)) != RL_OK)
        return st;
    a->seconds = seconds;
    if ((st = member(l, root, "desc", "the file", &c)) == RL_OK)
        st = load_desc(l, c, dims, &a->desc);
    if (st == RL_OK)
        a->desc.region = bounds;
    if (st == RL_OK)
        a->desc.height = height;
    if (st == RL_OK && (st = member(l, root, "nodes", "the file", &c)) == RL_OK)
        st = load_nodes(l, c, a);
    if (st == RL_OK)
        st = load_samples(l, root, a);
    if (st == RL_OK)
        st = rl_approx_number_leaves(a);
    if (st == RL_OK && (st = member(l, root, "leaves", "the file", &c)) == RL_OK &&
        (st = get_array(l, c, "leaves", (int)a->leaf_count, (int)a->leaf_count, &n)) == RL_OK) {
        const cJSON *e = c->child;
        for (uint32_t i = 0; i < a->leaf_count && st == RL_OK; ++i, e = e->next)
            st = load_leaf(l, e, a, i);
    }
    if (st == RL_OK) {
        for (uint32_t i = 0; i < a->node_count; ++i)
            if (a->nodes[i].kind == RL_NODE_LEAF) {
                a->leaves[a->nodes[i].leaf].box = a->nodes[i].box;
                a->leaves[a->nodes[i].leaf].depth = a->nodes[i].depth;
            }
        st = rl_approx_index_samples(a);
    }
    if (st == RL_OK) {
        *out = a;
        return RL_OK;
    }
    rl_approx_release(a);
    return st;
}

rl_status rl_approx_load_json(const char *path, rl_approx **out)
{
    return rl_approx_load_json_sets(path, RL_APPROX_ANY_SET_SIZE, out);
}

rl_status rl_approx_load_json_sets(const char *path, uint32_t set_size, rl_approx **out)
{
    if (!path || !out)
        return rl_error(RL_ERR_INVALID_ARG, "rl_approx_load_json: path or out is NULL");
    rl_json_doc *doc = NULL;
    rl_status st = rl_json_parse_file(path, &doc);
    if (st != RL_OK)
        return st;
    loader l = { doc, set_size };
    rl_approx *a = NULL;
    st = load(&l, rl_json_root(doc), &a);
    rl_json_free(doc);
    if (st == RL_OK)
        *out = a;
    return st;
}
