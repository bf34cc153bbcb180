/* Tests of the union-find: components of a graph against a flood fill, roots are the smallest index,
 * and the result does not depend on the order of the unions. */
#include <stdint.h>
#include <string.h>

#include "base/rng.h"
#include "base/uf.h"
#include "check.h"

enum { N = 500, EDGES = 420 };

/* Component of every vertex by repeated relaxation to the smallest reachable index (brute force). */
static void flood(const int32_t (*edge)[2], int32_t n_edges, int32_t *comp)
{
    for (int32_t i = 0; i < N; i++)
        comp[i] = i;
    for (int changed = 1; changed;) {
        changed = 0;
        for (int32_t e = 0; e < n_edges; e++) {
            int32_t a = edge[e][0], b = edge[e][1];
            int32_t m = comp[a] < comp[b] ? comp[a] : comp[b];
            if (comp[a] != m || comp[b] != m) {
                comp[a] = comp[b] = m;
                changed = 1;
            }
        }
    }
}

static void random_edges(int32_t (*edge)[2])
{
    for (int32_t e = 0; e < EDGES; e++) {
        edge[e][0] = (int32_t)(fs_rand01(5, FS_RNG_TEST, 2 * (uint64_t)e) * N);
        edge[e][1] = (int32_t)(fs_rand01(5, FS_RNG_TEST, 2 * (uint64_t)e + 1) * N);
    }
}

/* The sets after a random sequence of unions are the components of the graph, each with its smallest
 * vertex as the root. */
static void test_uf_components(void)
{
    static int32_t edge[EDGES][2], parent[N], comp[N];
    random_edges(edge);
    flood((const int32_t(*)[2])edge, EDGES, comp);
    fs_uf_init(parent, N);
    for (int32_t e = 0; e < EDGES; e++) {
        int32_t r = fs_uf_union(parent, edge[e][0], edge[e][1]);
        CHECK(r == fs_uf_find(parent, edge[e][0]) && r == fs_uf_find(parent, edge[e][1]));
    }
    int32_t bad = 0, roots = 0, comps = 0;
    for (int32_t i = 0; i < N; i++) {
        bad += fs_uf_find(parent, i) != comp[i];
        roots += parent[i] == i;
        comps += comp[i] == i;
    }
    CHECK(bad == 0);
    CHECK(roots == comps);
    CHECK(comps > 1 && comps < N); /* the graph has some components of several vertices */
}

/* The same edges in reverse order and with their ends swapped give the same roots. */
static void test_uf_order_independent(void)
{
    static int32_t edge[EDGES][2], p1[N], p2[N];
    random_edges(edge);
    fs_uf_init(p1, N);
    fs_uf_init(p2, N);
    for (int32_t e = 0; e < EDGES; e++) {
        fs_uf_union(p1, edge[e][0], edge[e][1]);
        fs_uf_union(p2, edge[EDGES - 1 - e][1], edge[EDGES - 1 - e][0]);
    }
    int32_t differ = 0;
    for (int32_t i = 0; i < N; i++)
        differ += fs_uf_find(p1, i) != fs_uf_find(p2, i);
    CHECK(differ == 0);
}

/* A chain joined from its far end: find halves the path, and the root is 0. */
static void test_uf_chain(void)
{
    int32_t parent[64];
    fs_uf_init(parent, 64);
    for (int32_t i = 63; i > 0; i--)
        CHECK(fs_uf_union(parent, i, i - 1) == i - 1);
    for (int32_t i = 0; i < 64; i++)
        CHECK(fs_uf_find(parent, i) == 0);
    /* after finds from every index, no path is longer than two links */
    int32_t longest = 0;
    for (int32_t i = 0; i < 64; i++) {
        int32_t len = 0;
        for (int32_t j = i; parent[j] != j; j = parent[j])
            len++;
        longest = len > longest ? len : longest;
    }
    CHECK(longest <= 2);
    CHECK(fs_uf_union(parent, 5, 5) == 0); /* a union within one set changes nothing */
}

int main(void)
{
    RUN(test_uf_components);
    RUN(test_uf_order_independent);
    RUN(test_uf_chain);
    return check_finish();
}
