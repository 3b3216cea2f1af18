/* vt_heap.c: the edge list of Vertex Tracing (Ullmann 2003, Sec. 3.3,
 * Fig. 3.4): edges sorted by projected length, longest first. A binary
 * max-heap instead of the thesis' binary tree with a list through it
 * (Fig. 4.10): the same O(log n) insertion, the longest edge in O(1), and no
 * degeneration on presorted input (footnote 4 of Sec. 3.3). Equal lengths
 * pop in increasing edge index, so refinement order never depends on the
 * heap's internal layout. */
#include <math.h>
#include <stdlib.h>

#include "core/error.h"
#include "render/vt_internal.h"

#define VT_HEAP_MAX_ITEMS (1u << 31)

/* Whether element i belongs above element j. */
static bool above(const vt_heap *h, uint32_t i, uint32_t j)
{
    if (h->keys[i] != h->keys[j])
        return h->keys[i] > h->keys[j];
    return h->items[i] < h->items[j];
}

static void swap_at(vt_heap *h, uint32_t i, uint32_t j)
{
    uint32_t it = h->items[i];
    h->items[i] = h->items[j];
    h->items[j] = it;
    float k = h->keys[i];
    h->keys[i] = h->keys[j];
    h->keys[j] = k;
}

rl_status vt_heap_push(vt_heap *h, uint32_t edge, float length)
{
    if (h->count == h->cap) {
        if (h->cap >= VT_HEAP_MAX_ITEMS)
            return rl_error(RL_ERR_LIMIT, "vt edge list: more than 2^31 edges");
        uint32_t cap = h->cap ? 2 * h->cap : 1024;
        uint32_t *items = rl_realloc_array(h->items, cap, sizeof *items);
        if (!items)
            return RL_ERR_OUT_OF_MEMORY;
        h->items = items;
        float *keys = rl_realloc_array(h->keys, cap, sizeof *keys);
        if (!keys)
            return RL_ERR_OUT_OF_MEMORY;
        h->keys = keys;
        h->cap = cap;
    }
    /* A NaN length would break the ordering for every other edge. */
    if (isnan(length))
        length = -INFINITY;
    uint32_t i = h->count++;
    h->items[i] = edge;
    h->keys[i] = length;
    while (i > 0) {
        uint32_t parent = (i - 1) / 2;
        if (!above(h, i, parent))
            break;
        swap_at(h, i, parent);
        i = parent;
    }
    return RL_OK;
}

bool vt_heap_pop(vt_heap *h, uint32_t *edge, float *length)
{
    if (h->count == 0)
        return false;
    if (edge)
        *edge = h->items[0];
    if (length)
        *length = h->keys[0];
    uint32_t n = --h->count;
    h->items[0] = h->items[n];
    h->keys[0] = h->keys[n];
    uint32_t i = 0;
    for (;;) {
        uint32_t best = i, l = 2 * i + 1, r = 2 * i + 2;
        if (l < n && above(h, l, best))
            best = l;
        if (r < n && above(h, r, best))
            best = r;
        if (best == i)
            break;
        swap_at(h, i, best);
        i = best;
    }
    return true;
}

float vt_heap_top(const vt_heap *h)
{
    return h->count ? h->keys[0] : -INFINITY;
}

void vt_heap_clear(vt_heap *h)
{
    h->count = 0;
}

void vt_heap_free(vt_heap *h)
{
    if (!h)
        return;
    free(h->items);
    free(h->keys);
    h->items = NULL;
    h->keys = NULL;
    h->count = h->cap = 0;
}
