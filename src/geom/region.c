/* Regions grown from seed nodes: Dijkstra's search over the connections a model reports. */
#include "geom/region.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "base/array.h"
#include "base/error.h"

/* A node waiting to be expanded, at distance d, reached as the seq-th. */
typedef struct {
    double d;
    int32_t node;
    int64_t seq;
} heap_item;

struct fs_region {
    double *dist;
    int32_t *out, n_out;
    double radius;
    double d;              /* distance of the node being expanded */
    fs_region_ties ties;
    heap_item *heap;       /* binary min-heap by (d, node) or (d, seq) */
    int32_t n_heap, cap_heap;
    int64_t seq;
};

static bool heap_less(const fs_region *r, heap_item x, heap_item y)
{
    if (x.d != y.d)
        return x.d < y.d;
    return r->ties == FS_REGION_TIES_BY_NODE ? x.node < y.node : x.seq < y.seq;
}

static void heap_push(fs_region *r, double d, int32_t node)
{
    FS_ARRAY_RESERVE(r->heap, r->cap_heap, r->n_heap + 1, 256);
    int32_t i = r->n_heap++;
    heap_item it = {d, node, r->seq++};
    while (i > 0 && heap_less(r, it, r->heap[(i - 1) / 2])) {
        r->heap[i] = r->heap[(i - 1) / 2];
        i = (i - 1) / 2;
    }
    r->heap[i] = it;
}

static heap_item heap_pop(fs_region *r)
{
    heap_item top = r->heap[0], last = r->heap[--r->n_heap];
    int32_t i = 0;
    for (;;) {
        int32_t c = 2 * i + 1;
        if (c >= r->n_heap)
            break;
        if (c + 1 < r->n_heap && heap_less(r, r->heap[c + 1], r->heap[c]))
            c++;
        if (!heap_less(r, r->heap[c], last))
            break;
        r->heap[i] = r->heap[c];
        i = c;
    }
    if (r->n_heap > 0)
        r->heap[i] = last;
    return top;
}

void fs_region_reach(fs_region *r, int32_t j, double length)
{
    double d = r->d + length;
    if (d <= r->radius && d < r->dist[j]) {
        if (r->dist[j] == INFINITY)
            r->out[r->n_out++] = j;
        r->dist[j] = d;
        heap_push(r, d, j);
    }
}

int32_t fs_region_grow(const int32_t *seeds, int32_t n_seeds, double radius, fs_region_ties ties,
                       fs_region_edges_fn edges, void *ctx, double *dist, int32_t *out)
{
    fs_region r = {.dist = dist, .out = out, .radius = radius, .ties = ties};
    for (int32_t q = 0; q < n_seeds; q++) {
        if (dist[seeds[q]] == 0.0)
            continue; /* a repeat */
        dist[seeds[q]] = 0.0;
        out[r.n_out++] = seeds[q];
        heap_push(&r, 0.0, seeds[q]);
    }
    while (r.n_heap > 0) {
        heap_item it = heap_pop(&r);
        if (it.d > dist[it.node])
            continue; /* reached again at a shorter distance since */
        r.d = it.d;
        edges(ctx, it.node, &r);
    }
    free(r.heap);
    return r.n_out;
}

void fs_region_forget(double *dist, const int32_t *out, int32_t n)
{
    for (int32_t k = 0; k < n; k++)
        dist[out[k]] = INFINITY;
}
