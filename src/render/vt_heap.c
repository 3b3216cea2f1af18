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

/* Whether x belongs above y. */
static inline bool above(vt_heap_item x, vt_heap_item y)
{
    if (x.length != y.length)
        return x.length > y.length;
    return x.edge < y.edge;
}

rl_status vt_heap_push(vt_heap *h, uint32_t edge, float length)
{
    rl_status st = vt_array_reserve((void **)&h->items, &h->cap, (uint64_t)h->count + 1, sizeof *h->items, 1024,
                                    VT_HEAP_MAX_ITEMS, "vt edge list");
    if (st != RL_OK)
        return st;
    /* A NaN length would break the ordering for every other edge. */
    if (isnan(length))
        length = -INFINITY;
    vt_heap_item x = { length, edge };
    /* The order (length, then edge index) is total, so the pops come out
     * the same whichever way the elements are moved. Moving the hole up
     * writes each displaced parent once instead of swapping. */
    uint32_t i = h->count++;
    while (i > 0) {
        uint32_t parent = (i - 1) / 2;
        if (!above(x, h->items[parent]))
            break;
        h->items[i] = h->items[parent];
        i = parent;
    }
    h->items[i] = x;
    return RL_OK;
}

bool vt_heap_pop(vt_heap *h, uint32_t *edge, float *length)
{
    if (h->count == 0)
        return false;
    if (edge)
        *edge = h->items[0].edge;
    if (length)
        *length = h->items[0].length;
    uint32_t n = --h->count;
    if (n == 0)
        return true;
    vt_heap_item x = h->items[n];
    uint32_t i = 0;
    for (;;) {
        uint32_t best = 2 * i + 1;
        if (best >= n)
            break;
        if (best + 1 < n && above(h->items[best + 1], h->items[best]))
            ++best;
        if (!above(h->items[best], x))
            break;
        h->items[i] = h->items[best];
        i = best;
    }
    h->items[i] = x;
    return true;
}

float vt_heap_top(const vt_heap *h)
{
    return h->count ? h->items[0].length : -INFINITY;
}

void vt_heap_shrink(vt_heap *h)
{
    /* Growth doubles from 1024, so the room stays 1024 times a power of
     * two; the smallest such room with half of it free is kept. The items
     * are the same in the same places: the pops do not change. */
    if (h->count > VT_HEAP_MAX_ITEMS / 2)
        return;
    uint32_t cap = 1024;
    while (cap < h->count || cap - h->count < cap / 2)
        cap *= 2;
    if (cap >= h->cap || h->cap - cap < 4096)
        return;
    vt_heap_item *items = vt_array_resize(h->items, (size_t)h->cap * sizeof *items, (size_t)cap * sizeof *items);
    if (!items)
        return;                   /* the larger room stays: only memory */
    h->items = items;
    h->cap = cap;
}

void vt_heap_clear(vt_heap *h)
{
    h->count = 0;
}

void vt_heap_free(vt_heap *h)
{
    if (!h)
        return;
    vt_array_free(h->items, (size_t)h->cap * sizeof *h->items);
    h->items = NULL;
    h->count = h->cap = 0;
}
