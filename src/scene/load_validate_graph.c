/* load_validate_graph.c: node hierarchies checked before Assimp walks them.
 *
 * Assimp builds its node tree by recursion, one stack frame (or several)
 * per level: a glTF node chain 100,000 deep, a Collada file nesting 100,000
 * <node> elements, or an <instance_node> that refers to its own node or an
 * ancestor overflows its stack (the last one recursing forever). Collada's
 * instancing also copies the instanced subtree, so a few kilobytes of
 * nodes that instance the previous one twice expand to 2^40 nodes. The
 * checks below see all of that in one linear pass over the text:
 *   - glTF 2.0 (spec, "Nodes and Hierarchy": the nodes form disjoint
 *     strict trees): child indices in range, no node with two parents, no
 *     cycle, depth at most RL_IMPORT_MAX_NODE_DEPTH;
 *   - Collada 1.4/1.5: <node> nesting plus <instance_node url="#id">
 *     references form a graph that must be acyclic, at most
 *     RL_IMPORT_MAX_NODE_DEPTH deep and at most RL_IMPORT_MAX_NODE_COPIES
 *     nodes once instancing is expanded.
 * The isolated import would survive these files too; the checks turn a
 * crash or a timeout into an error that says what is wrong. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "core/error.h"
#include "core/json.h"
#include "scene/load_internal.h"

#define NONE UINT32_MAX

/* Depth of each node below its root, walking up the (single) parent links
 * with memoisation: O(n) over all nodes. A walk that meets a node of its own
 * walk has found a cycle. */
static rl_status check_parents(const char *path, const uint32_t *parent, uint32_t n)
{
    int64_t *depth = rl_alloc(((size_t)n + 1) * sizeof *depth);
    uint32_t *walk = rl_alloc(((size_t)n + 1) * sizeof *walk);
    rl_status st = depth && walk ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (uint32_t v = 0; v < n && st == RL_OK; ++v)
        depth[v] = -1;   /* -1 unknown, -2 on the current walk */
    for (uint32_t v = 0; v < n && st == RL_OK; ++v) {
        uint32_t k = 0, u = v;
        while (u != NONE && depth[u] == -1) {
            depth[u] = -2;
            walk[k++] = u;
            u = parent[u];
        }
        if (u != NONE && depth[u] == -2) {
            st = rl_error(RL_ERR_PARSE, "%s: node %u is its own ancestor (a cycle in the node "
                          "hierarchy)", path, u);
            break;
        }
        int64_t d = u == NONE ? -1 : depth[u];
        while (k > 0) {
            depth[walk[--k]] = ++d;
            if (d >= RL_IMPORT_MAX_NODE_DEPTH) {
                st = rl_error(RL_ERR_LIMIT, "%s: node hierarchy deeper than %d levels", path,
                              RL_IMPORT_MAX_NODE_DEPTH);
                break;
            }
        }
    }
    free(depth);
    free(walk);
    return st;
}

rl_status rl_check_gltf_nodes(const char *path, const char *json, size_t size)
{
    cJSON *root = cJSON_ParseWithLength(json, size);
    if (!root)
        return RL_OK;   /* not JSON we can read: Assimp reports it */
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    int count = cJSON_IsArray(nodes) ? cJSON_GetArraySize(nodes) : 0;
    uint32_t n = count > 0 ? (uint32_t)count : 0;
    uint32_t *parent = rl_alloc(((size_t)n + 1) * sizeof *parent);
    rl_status st = parent ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (uint32_t v = 0; v < n && st == RL_OK; ++v)
        parent[v] = NONE;
    uint32_t v = 0;
    const cJSON *node, *list = n ? nodes : NULL;
    cJSON_ArrayForEach(node, list) {
        const cJSON *children = cJSON_GetObjectItemCaseSensitive(node, "children");
        const cJSON *c, *kids = cJSON_IsArray(children) ? children : NULL;
        cJSON_ArrayForEach(c, kids) {
            if (st != RL_OK)
                break;
            double d = cJSON_IsNumber(c) ? c->valuedouble : -1.0;
            if (!(d >= 0.0 && d < (double)n && d == (double)(uint32_t)d))
                st = rl_error(RL_ERR_PARSE, "%s: node %u has a child that is not a node index",
                              path, v);
            else if (parent[(uint32_t)d] != NONE)
                st = rl_error(RL_ERR_PARSE, "%s: node %u has two parents (%u and %u)", path,
                              (uint32_t)d, parent[(uint32_t)d], v);
            else
                parent[(uint32_t)d] = v;
        }
        ++v;
    }
    if (st == RL_OK)
        st = check_parents(path, parent, n);
    free(parent);
    cJSON_Delete(root);
    return st;
}

/* ---- Collada ------------------------------------------------------------ */

typedef struct span { const char *p; size_t n; } span;

/* An edge of the node graph: parent -> child <node>, or node -> the node
 * its <instance_node> names (url, resolved to `to` after the scan). */
typedef struct dae_edge {
    uint32_t from, to;
    span url;
} dae_edge;

typedef struct dae_graph {
    span *ids;                  /* per <node>: its id attribute, or empty */
    uint32_t num_nodes, cap_nodes;
    dae_edge *edges;
    uint32_t num_edges, cap_edges;
} dae_graph;

static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

/* The value of attribute name in the tag text [p, end), quotes removed. */
static span attribute(const char *p, const char *end, const char *name)
{
    size_t len = strlen(name);
    for (const char *q = p; q + len < end; ++q) {
        if (!is_space(q[0]) || memcmp(q + 1, name, len) != 0)
            continue;
        const char *r = q + 1 + len;
        while (r < end && is_space(*r))
            ++r;
        if (r >= end || *r != '=')
            continue;
        ++r;
        while (r < end && is_space(*r))
            ++r;
        if (r >= end || (*r != '"' && *r != '\''))
            continue;
        const char *close = memchr(r + 1, *r, (size_t)(end - r - 1));
        if (close)
            return (span){ r + 1, (size_t)(close - r - 1) };
    }
    return (span){ NULL, 0 };
}

static bool tag_is(const char *p, const char *end, const char *name)
{
    size_t len = strlen(name);
    return (size_t)(end - p) >= len && memcmp(p, name, len) == 0 &&
           (p + len == end || is_space(p[len]) || p[len] == '/');
}

static rl_status add_edge(dae_graph *g, uint32_t from, uint32_t to, span url)
{
    if (!rl_reserve_u32((void **)&g->edges, &g->cap_edges, (uint64_t)g->num_edges + 1,
                        sizeof *g->edges, 256))
        return RL_ERR_OUT_OF_MEMORY;
    g->edges[g->num_edges++] = (dae_edge){ from, to, url };
    return RL_OK;
}

/* One pass over the XML: <node> elements (nesting checked on the way) and
 * the edges between them. Comments, CDATA and declarations are skipped. */
static rl_status scan_dae(const char *path, const char *data, size_t size, dae_graph *g)
{
    uint32_t stack[RL_IMPORT_MAX_NODE_DEPTH];
    uint32_t depth = 0;
    const char *p = data, *end = data + size;
    while ((p = memchr(p, '<', (size_t)(end - p))) != NULL) {
        const char *close_with = ">";
        if (end - p >= 4 && memcmp(p, "<!--", 4) == 0)
            close_with = "-->";
        else if (end - p >= 9 && memcmp(p, "<![CDATA[", 9) == 0)
            close_with = "]]>";
        const char *tag_end = p + 1;
        size_t cl = strlen(close_with);
        while (tag_end + cl <= end && memcmp(tag_end, close_with, cl) != 0) {
            /* quoted attribute values may hold '>' */
            if (cl == 1 && (*tag_end == '"' || *tag_end == '\'')) {
                const char *q = memchr(tag_end + 1, *tag_end, (size_t)(end - tag_end - 1));
                tag_end = q ? q : end;
            }
            if (tag_end < end)
                ++tag_end;
        }
        if (tag_end + cl > end)
            break;   /* cut off: Assimp reports it */
        const char *name = p + 1;
        bool self_closing = cl == 1 && tag_end > name && tag_end[-1] == '/';
        if (cl == 1 && tag_is(name, tag_end, "node")) {
            if (depth == RL_IMPORT_MAX_NODE_DEPTH)
                return rl_error(RL_ERR_LIMIT, "%s: <node> elements nested deeper than %d levels",
                                path, RL_IMPORT_MAX_NODE_DEPTH);
            if (!rl_reserve_u32((void **)&g->ids, &g->cap_nodes, (uint64_t)g->num_nodes + 1,
                                sizeof *g->ids, 256))
                return RL_ERR_OUT_OF_MEMORY;
            uint32_t id = g->num_nodes++;
            g->ids[id] = attribute(name + 4, tag_end, "id");
            if (depth > 0 && add_edge(g, stack[depth - 1], id, (span){ NULL, 0 }) != RL_OK)
                return RL_ERR_OUT_OF_MEMORY;
            if (!self_closing)
                stack[depth++] = id;
        } else if (cl == 1 && name[0] == '/' && tag_is(name + 1, tag_end, "node")) {
            if (depth > 0)
                --depth;
        } else if (cl == 1 && tag_is(name, tag_end, "instance_node") && depth > 0) {
            span url = attribute(name + 13, tag_end, "url");
            if (url.n > 1 && url.p[0] == '#' &&
                add_edge(g, stack[depth - 1], NONE, (span){ url.p + 1, url.n - 1 }) != RL_OK)
                return RL_ERR_OUT_OF_MEMORY;
        }
        p = tag_end + cl;
    }
    return RL_OK;
}

typedef struct id_ref { span id; uint32_t node; } id_ref;

static int cmp_span(span a, span b)
{
    int c = memcmp(a.p, b.p, a.n < b.n ? a.n : b.n);
    return c ? c : (a.n > b.n) - (a.n < b.n);
}

static int cmp_id_ref(const void *a, const void *b)
{
    return cmp_span(((const id_ref *)a)->id, ((const id_ref *)b)->id);
}

/* Height (levels below and including a node, instancing expanded) and the
 * number of nodes an instance of it copies, by an iterative post-order
 * depth-first walk over the children lists (CSR: first[v]..first[v+1]). */
static rl_status walk_dae(const char *path, const span *ids, uint32_t n, const uint32_t *first,
                          const uint32_t *to)
{
    uint32_t *height = rl_calloc((size_t)n + 1, sizeof *height);
    uint64_t *copies = rl_calloc((size_t)n + 1, sizeof *copies);
    uint8_t *state = rl_calloc((size_t)n + 1, 1);   /* 0 new, 1 on the path, 2 done */
    uint32_t *stack = rl_alloc(((size_t)n + 1) * sizeof *stack);
    uint32_t *next = rl_alloc(((size_t)n + 1) * sizeof *next);
    rl_status st = height && copies && state && stack && next ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    for (uint32_t s = 0; s < n && st == RL_OK; ++s) {
        if (state[s])
            continue;
        uint32_t k = 0;
        stack[k++] = s;
        state[s] = 1;
        next[s] = first[s];
        while (k > 0 && st == RL_OK) {
            uint32_t v = stack[k - 1];
            if (next[v] < first[v + 1]) {
                uint32_t w = to[next[v]++];
                if (state[w] == 1)
                    st = rl_error(RL_ERR_PARSE, "%s: <node id=\"%.*s\"> instances itself or an "
                                  "ancestor (a cycle in the node hierarchy)", path,
                                  (int)(ids[w].n < 200 ? ids[w].n : 200), ids[w].p ? ids[w].p : "");
                else if (state[w] == 0) {
                    state[w] = 1;
                    next[w] = first[w];
                    stack[k++] = w;
                }
                continue;
            }
            uint32_t h = 0;
            uint64_t c = 1;
            for (uint32_t e = first[v]; e < first[v + 1]; ++e) {
                h = height[to[e]] > h ? height[to[e]] : h;
                c += copies[to[e]];
            }
            height[v] = h + 1;
            copies[v] = c < RL_IMPORT_MAX_NODE_COPIES ? c : RL_IMPORT_MAX_NODE_COPIES + 1ull;
            state[v] = 2;
            --k;
            if (height[v] > RL_IMPORT_MAX_NODE_DEPTH)
                st = rl_error(RL_ERR_LIMIT, "%s: node hierarchy deeper than %d levels once "
                              "<instance_node> is expanded", path, RL_IMPORT_MAX_NODE_DEPTH);
            else if (copies[v] > RL_IMPORT_MAX_NODE_COPIES)
                st = rl_error(RL_ERR_LIMIT, "%s: <instance_node> expands to more than %llu nodes",
                              path, (unsigned long long)RL_IMPORT_MAX_NODE_COPIES);
        }
    }
    free(height);
    free(copies);
    free(state);
    free(stack);
    free(next);
    return st;
}

rl_status rl_check_dae_nodes(const char *path, const char *data, size_t size)
{
    dae_graph g = { 0 };
    rl_status st = scan_dae(path, data, size, &g);
    id_ref *refs = NULL;
    uint32_t *first = NULL, *to = NULL;
    if (st == RL_OK && g.num_nodes > 0) {
        refs = rl_alloc((size_t)g.num_nodes * sizeof *refs);
        first = rl_calloc((size_t)g.num_nodes + 2, sizeof *first);
        to = rl_alloc(((size_t)g.num_edges + 1) * sizeof *to);
        st = refs && first && to ? RL_OK : RL_ERR_OUT_OF_MEMORY;
    }
    if (st == RL_OK && g.num_nodes > 0) {
        uint32_t named = 0;
        for (uint32_t v = 0; v < g.num_nodes; ++v)
            if (g.ids[v].n > 0)
                refs[named++] = (id_ref){ g.ids[v], v };
        qsort(refs, named, sizeof *refs, cmp_id_ref);
        /* Resolve url edges; one to an unknown id is Assimp's to report. */
        for (uint32_t e = 0; e < g.num_edges; ++e) {
            if (g.edges[e].to != NONE)
                continue;
            id_ref key = { g.edges[e].url, 0 };
            const id_ref *hit = bsearch(&key, refs, named, sizeof *refs, cmp_id_ref);
            g.edges[e].to = hit ? hit->node : NONE;
        }
        for (uint32_t e = 0; e < g.num_edges; ++e)
            if (g.edges[e].to != NONE)
                first[g.edges[e].from + 1]++;
        for (uint32_t v = 0; v < g.num_nodes; ++v)
            first[v + 1] += first[v];
        uint32_t *fill = rl_alloc(((size_t)g.num_nodes + 1) * sizeof *fill);
        if (!fill)
            st = RL_ERR_OUT_OF_MEMORY;
        else {
            memcpy(fill, first, (size_t)g.num_nodes * sizeof *fill);
            for (uint32_t e = 0; e < g.num_edges; ++e)
                if (g.edges[e].to != NONE)
                    to[fill[g.edges[e].from]++] = g.edges[e].to;
            free(fill);
            st = walk_dae(path, g.ids, g.num_nodes, first, to);
        }
    }
    free(refs);
    free(first);
    free(to);
    free(g.ids);
    free(g.edges);
    return st;
}
