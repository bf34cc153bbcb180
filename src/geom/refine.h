/* Conforming longest-edge bisection of triangle meshes (Rivara), reporting exactly what changed. */
#ifndef FS_GEOM_REFINE_H
#define FS_GEOM_REFINE_H

#include <stdbool.h>
#include <stdint.h>

#include "geom/mesh.h"

/* What one call of fs_refine_bisect changed, so a model can extend its per-node and per-element
 * arrays and update its global system for only the changed elements (thesis §5.6.4, Algorithms 6-7).
 *
 * Nodes: old nodes never move and keep their index; new nodes are n_nodes_before .. n_nodes_before +
 * n_new_nodes - 1, in creation order. New node k = n_nodes_before + i is the midpoint of the edge
 * joining node_parent[2i] and node_parent[2i+1] (in the unwrapped frame: node_parent_shift[2i..2i+1]
 * is the image offset, in periods, of the second parent relative to the first; always 0 on the
 * sphere, where the midpoint is projected onto the sphere). A parent may itself be a new node of the
 * same call, created earlier, so interpolating in index order is always possible.
 *
 * Triangles: a split triangle keeps its index for one child and the other child is appended, so
 *   - changed_tri lists, ascending, the triangles with index < n_tris_before whose corners changed
 *     (the slot now holds a descendant of the triangle that was there before the call);
 *   - triangles n_tris_before .. n_tris_before + n_new_tris - 1 are new, and tri_parent[i] is the
 *     index (< n_tris_before) of the pre-call triangle that new triangle n_tris_before + i lies in;
 *   - every other triangle is untouched (same corners, same shifts; its adjacency may point to new
 *     triangles).
 * A pre-call triangle's area is exactly covered by its slot and the new triangles naming it as parent
 * (plane, cylinder; on the sphere up to the projection of the new midpoints).
 *
 * Ownership: the arrays belong to the struct. Zero it ({0}) before its first use; each call releases
 * the arrays of the previous call; fs_refine_change_free releases them at the end. */
typedef struct {
    int32_t n_nodes_before;
    int32_t n_tris_before;

    int32_t n_new_nodes;
    int32_t *node_parent;      /* 2 * n_new_nodes node indices */
    int8_t *node_parent_shift; /* 2 * n_new_nodes: (x, y) image offset of the second parent */

    int32_t n_new_tris;
    int32_t *tri_parent;       /* n_new_tris pre-call triangle indices */

    int32_t n_changed_tris;
    int32_t *changed_tri;      /* n_changed_tris ascending pre-call triangle indices */

    int32_t n_bisections;      /* triangles bisected, counting propagation (each split edge bisects 1 or 2) */
    int32_t n_skipped;         /* listed triangles left alone because their longest edge is below min_size */
    bool rings_rebuilt;        /* the rings were rebuilt from scratch instead of updated (a pinched node) */
} fs_refine_change;

/* Size of triangle t as refinement sees it: its longest edge (cm; the chord on the sphere). */
double fs_refine_tri_size(const fs_mesh *m, int32_t t);

/* design: thesis §5.6.4, Algorithm 9 (Rivara and Inostroza [58]); implemented as the longest-edge
 * propagation path (LEPP) of Rivara. To bisect t, follow t0 = t, t1 = the neighbour across the
 * longest edge of t0, t2 = the neighbour across the longest edge of t1, ... until a triangle t_k whose
 * longest edge is also the longest edge of the neighbour across it (or lies on the boundary): that
 * "terminal" edge is split at its midpoint, bisecting both triangles that share it; then the walk
 * resumes from t_{k-1}, until t itself has been bisected. Every triangle is therefore only ever split
 * across its own longest edge, the mesh stays conforming after every step (no hanging nodes), and
 * the Rosenberg-Stenger bound holds: every angle of every descendant is at least half the smallest
 * angle of the triangle it descends from (on the sphere up to the small change the projection of
 * midpoints makes).
 *
 * "Longest" is a strict total order on edges shared by both sides: squared length computed the same
 * way from either triangle, ties broken by the node indices (and image offsets), so lattice meshes
 * with many equal edges are refined deterministically.
 *
 * min_size and propagation: a listed triangle whose longest edge is below min_size is not split
 * (counted in n_skipped). Propagation never splits a triangle smaller than that either: along the
 * path every longest edge is longer than the previous one, so every edge split while bisecting t is
 * at least as long as t's longest edge, and every triangle split across it has that edge as its
 * longest. Conformity never forces a small triangle to split; it forces larger neighbours to split.
 *
 * Batches: the listed triangles (indices before the call; duplicates allowed) are processed in order;
 * one that was already bisected as part of an earlier one's propagation in the same call is not
 * bisected again. The result depends only on the mesh and the list, never on timing.
 *
 * Periodic plane / cylinder: the midpoint of an edge that straddles a seam is computed in the
 * unwrapped frame and wrapped into the fundamental domain (fs_domain_wrap); the children's corner
 * shifts are recomputed from it (first corner at shift (0, 0)), consistently on both sides. Sphere:
 * the midpoint is projected onto the sphere. Plane (z = 0) and cylinder coordinates are kept as is.
 *
 * Requires adjacency (m->adj). Updates tri, shift (when present), pos and adj incrementally; the edge
 * arrays too when m->tri_edge is set (the split edge keeps its index for the half at its first
 * parent's end, new edges are appended); the rings when m->ring_start is set, by walking the rings
 * of the nodes around changed triangles and moving the others in place (an O(n_nodes) memmove, no
 * walk of the untouched mesh). adj and the rings equal what fs_mesh_build_adjacency /
 * fs_mesh_build_rings would produce; the edges equal fs_mesh_build_edges's up to their numbering.
 * The grown arrays keep up to 1/8 spare room (still plain malloc blocks, released by fs_mesh_free)
 * so that a sequence of small calls does not copy them every time.
 * Cost: proportional to the triangles split, plus that O(n) move. Measured on a 100 000-triangle
 * Delaunay mesh (2-core machine under load): 5-7 ms to bisect 1000 listed triangles (about 3800
 * bisections with propagation), 0.15 ms for one triangle; rebuilding adjacency, edges and rings from
 * scratch instead would take 50-70 ms.
 *
 * change may be NULL. Returns 0. Returns -1 with fs_error(FS_ERR_INTERNAL), changing nothing (change
 * included), for a triangle index out of range, a negative or non-finite min_size or a mesh without
 * adjacency; -1 with fs_error(FS_ERR_DATA) when propagation meets two triangles sharing more than one
 * edge (a periodic mesh of a handful of nodes per period, or a broken one): the mesh is then left
 * conforming and valid as refined so far, and change describes what was done. */
int fs_refine_bisect(fs_mesh *m, const int32_t *tris, int32_t n_tris, double min_size, fs_refine_change *change);

void fs_refine_change_free(fs_refine_change *change);

#endif
