/* Tests of region growth (geom/region): distances and radius on a weighted graph by hand, the
 * breadth-first order with unit lengths, ties, repeated seeds and barriers. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "check.h"
#include "geom/region.h"

/* A graph as an edge list with lengths; edges with length <= 0 are barriers (not reported). */
typedef struct {
    int32_t n_edges;
    const int32_t (*edge)[2];
    const double *length;
    int calls;
} graph;

static void graph_edges(void *ctx, int32_t i, fs_region *r)
{
    graph *g = ctx;
    g->calls++;
    for (int32_t e = 0; e < g->n_edges; e++) {
        if (!(g->length[e] > 0.0))
            continue;
        if (g->edge[e][0] == i)
            fs_region_reach(r, g->edge[e][1], g->length[e]);
        else if (g->edge[e][1] == i)
            fs_region_reach(r, g->edge[e][0], g->length[e]);
    }
}

static void reset(double *dist, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        dist[i] = INFINITY;
}

/* A square 0-1-2-3 with a diagonal 0-2 of length 1.5 and a tail 2-4 of length 2:
 * d(1) = 1, d(3) = 1, d(2) = min(2, 1.5) = 1.5, d(4) = 3.5. */
static void test_region_weighted(void)
{
    static const int32_t edge[6][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 2}, {2, 4}};
    static const double length[6] = {1, 1, 1, 1, 1.5, 2};
    graph g = {6, edge, length, 0};
    double dist[5];
    int32_t out[5];
    reset(dist, 5);
    int32_t seeds[2] = {0, 0};
    int32_t n = fs_region_grow(seeds, 2, 10.0, FS_REGION_TIES_BY_NODE, graph_edges, &g, dist, out);
    CHECK(n == 5);
    CHECK(dist[0] == 0.0 && dist[1] == 1.0 && dist[3] == 1.0 && dist[2] == 1.5 && dist[4] == 3.5);
    /* first reached from 0 in the order of its edges: 1, 3, then 2 (by the diagonal); then 4 from 2 */
    CHECK(out[0] == 0 && out[1] == 1 && out[2] == 3 && out[3] == 2 && out[4] == 4);
    fs_region_forget(dist, out, n);
    for (int32_t i = 0; i < 5; i++)
        CHECK(dist[i] == INFINITY);
    /* radius 1.5: node 4 (3.5) stays out, 2 is just in */
    n = fs_region_grow(seeds, 1, 1.5, FS_REGION_TIES_BY_NODE, graph_edges, &g, dist, out);
    CHECK(n == 4 && dist[4] == INFINITY && dist[2] == 1.5);
    fs_region_forget(dist, out, n);
    /* a crack: without the diagonal and the edge 1-2, node 2 is 2 away through 3 */
    static const double cracked[6] = {1, 0, 1, 1, 0, 2};
    graph h = {6, edge, cracked, 0};
    n = fs_region_grow(seeds, 1, 10.0, FS_REGION_TIES_BY_NODE, graph_edges, &h, dist, out);
    CHECK(n == 5 && dist[2] == 2.0 && dist[4] == 4.0);
    fs_region_forget(dist, out, n);
}

/* A 5 x 5 grid graph with unit lengths from two seeds: ties by arrival give the order of a
 * breadth-first queue, and every node within the hop radius, no other. */
static void test_region_breadth_first(void)
{
    enum { W = 5, N = W * W };
    int32_t edge[2 * W * (W - 1)][2], ne = 0;
    double length[2 * W * (W - 1)];
    for (int y = 0; y < W; y++)
        for (int x = 0; x < W; x++) {
            if (x + 1 < W) {
                edge[ne][0] = y * W + x, edge[ne][1] = y * W + x + 1, length[ne++] = 1.0;
            }
            if (y + 1 < W) {
                edge[ne][0] = y * W + x, edge[ne][1] = (y + 1) * W + x, length[ne++] = 1.0;
            }
        }
    graph g = {ne, (const int32_t(*)[2])edge, length, 0};
    const int32_t seeds[2] = {12, 0};
    for (int radius = 0; radius <= 4; radius++) {
        /* the reference queue */
        int32_t queue[N], depth[N], nq = 0;
        int32_t seen[N];
        memset(seen, 0, sizeof seen);
        for (int k = 0; k < 2; k++) {
            seen[seeds[k]] = 1;
            depth[nq] = 0;
            queue[nq++] = seeds[k];
        }
        for (int32_t head = 0; head < nq; head++) {
            int32_t i = queue[head];
            if (depth[head] >= radius)
                continue;
            for (int32_t e = 0; e < ne; e++) {
                int32_t j = edge[e][0] == i ? edge[e][1] : edge[e][1] == i ? edge[e][0] : -1;
                if (j >= 0 && !seen[j]) {
                    seen[j] = 1;
                    depth[nq] = depth[head] + 1;
                    queue[nq++] = j;
                }
            }
        }
        double dist[N];
        int32_t out[N];
        reset(dist, N);
        int32_t n = fs_region_grow(seeds, 2, radius, FS_REGION_TIES_BY_ARRIVAL, graph_edges, &g, dist, out);
        CHECK_MSG(n == nq && memcmp(out, queue, (size_t)n * sizeof *out) == 0, "radius %d: %d nodes, queue %d", radius,
                  (int)n, (int)nq);
        for (int32_t k = 0; k < n; k++)
            CHECK(dist[out[k]] == depth[k]);
    }
}

int main(void)
{
    RUN(test_region_weighted);
    RUN(test_region_breadth_first);
    return check_finish();
}
