/* Regions of a node graph (a mesh's edges, a spring network) grown from seed nodes up to a path length, for local relaxations and sub-models. */
#ifndef FS_GEOM_REGION_H
#define FS_GEOM_REGION_H

#include <stdint.h>

/* design: a local relaxation solves only the nodes near a change (thesis §5.8): those joined to a
 * seed by a path through the model's intact connections (the edges of living elements, unbroken
 * springs) no longer than a radius, so that cracks are barriers. fs_region_grow finds them by
 * Dijkstra's search from the seeds; the model says which connections count, and how long they are,
 * through a callback, so one search serves a metric radius (the wedge: edge lengths at rest) and a
 * radius in hops (the springs: every spring of length 1, which makes the search breadth-first).
 * Nodes come out in the order they are first reached; among the nodes waiting at equal distance the
 * search expands the lowest index first (FS_REGION_TIES_BY_NODE) or the first reached
 * (FS_REGION_TIES_BY_ARRIVAL: with unit lengths exactly the order of a breadth-first queue). The
 * result depends on the graph, the seeds' order and the callback's order only. */

typedef struct fs_region fs_region;

/* Reports node i's connections that count: calls fs_region_reach(r, j, length) for each neighbour
 * j of i across a connection of that length (> 0), in a fixed order. */
typedef void (*fs_region_edges_fn)(void *ctx, int32_t i, fs_region *r);

/* From within an fs_region_edges_fn: node j is length away from the node being expanded. */
void fs_region_reach(fs_region *r, int32_t j, double length);

typedef enum { FS_REGION_TIES_BY_NODE = 0, FS_REGION_TIES_BY_ARRIVAL } fs_region_ties;

/* The nodes within radius of the seeds (n_seeds, repeats counted once): every node with a path of
 * at most radius to a seed, the seeds first in their order, then the others in the order they are
 * first reached, into out (room for every node); returns how many. dist is the caller's scratch with
 * an entry per node, all INFINITY on entry; on return the nodes listed in out hold their distance
 * (the caller sets them back to INFINITY before the next search: fs_region_forget). */
int32_t fs_region_grow(const int32_t *seeds, int32_t n_seeds, double radius, fs_region_ties ties,
                       fs_region_edges_fn edges, void *ctx, double *dist, int32_t *out);

/* dist[out[k]] = INFINITY for the n nodes of a search's result. */
void fs_region_forget(double *dist, const int32_t *out, int32_t n);

#endif
