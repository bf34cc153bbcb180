/* Triangle meshes on a domain with adjacency and the Voronoi dual; models refine and split them. */
#ifndef FS_GEOM_MESH_H
#define FS_GEOM_MESH_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "geom/domain.h"

/* design: node positions are in domain coordinates (domain.h). On a periodic plane or cylinder a
 * triangle may straddle the seam: each corner then carries an integer image offset (shift) so that
 *   unwrapped corner position = pos[node] + (shift_x * extent_x, shift_y * extent_y)
 * gives a geometrically coherent, counter-clockwise triangle. Offsets are relative: a triangle is
 * stored with the smallest shifts that make it coherent, its first corner at shift (0, 0).
 * On the sphere triangles are counter-clockwise seen from outside; shifts are all zero.
 * Edge i of a triangle joins corners i and (i+1)%3; adj[3t+i] is the triangle across it. */
typedef struct {
    fs_domain domain;

    int32_t n_nodes;
    double *pos;         /* 3 * n_nodes, domain coordinates */

    int32_t n_tris;
    int32_t *tri;        /* 3 * n_tris corner node indices */
    int8_t *shift;       /* 6 * n_tris: (shift_x, shift_y) per corner; all zero off the seams */
    int32_t *adj;        /* 3 * n_tris: neighbour across edge i, or -1 on a boundary */

    /* Unique undirected edges, built by fs_mesh_build_edges. */
    int32_t n_edges;
    int32_t *edge;       /* 2 * n_edges node indices, edge[2e] < edge[2e+1] (or equal on tiny periodic meshes) */
    int32_t *edge_tri;   /* 2 * n_edges: the triangles on either side, -1 on a boundary */
    int32_t *tri_edge;   /* 3 * n_tris: edge index of each triangle edge */

    /* Node -> incident triangles, in counter-clockwise order around the node (CSR). Built by
     * fs_mesh_build_rings; for a boundary node the ring starts at the boundary. */
    int32_t *ring_start; /* n_nodes + 1 */
    int32_t *ring_tri;   /* ring_start[n_nodes] entries */
} fs_mesh;

/* The Voronoi dual of a Delaunay mesh. */
typedef struct {
    double *circumcenter;   /* 3 * n_tris, in the unwrapped frame of the triangle's first corner (sphere: projected onto the sphere) */
    double *cell_area;      /* n_nodes: area of each node's Voronoi cell (clipped to the domain on a non-periodic plane) (cm^2) */
    double *edge_length;    /* n_edges: length of the Voronoi edge dual to each Delaunay edge (cm) */
} fs_voronoi;

/* Releases everything the mesh owns and zeroes it. */
void fs_mesh_free(fs_mesh *m);

/* Fills adj from tri (and shift). Returns 0, or -1 with fs_error(FS_ERR_DATA) if an edge is shared by
 * more than two triangles (non-manifold). */
int fs_mesh_build_adjacency(fs_mesh *m);

/* Brings adj up to a local change: triangles n_tris_before .. n_tris - 1 are new, the listed ones
 * (below n_tris_before, repeats allowed) changed corners or shifts, and adj was valid for the mesh
 * before the change. The result equals fs_mesh_build_adjacency's; the cost is that of the listed
 * triangles and their neighbours (plus a pass over a byte per triangle). Returns 0, or -1 with
 * fs_error(FS_ERR_DATA) for a non-manifold edge. */
int fs_mesh_update_adjacency(fs_mesh *m, int32_t n_tris_before, const int32_t *changed, int32_t n_changed);

/* Checks the invariants every model's mesh keeps, after construction and after every cut: corners
 * are nodes of the mesh; each triangle has positive signed area (counter-clockwise, fs_mesh_tri_area)
 * and its corners are distinct; adj is symmetric and pairs half-edges that run the other way along
 * the same edge (same nodes and image offset), and every such pair is joined (no two triangles share
 * an edge without knowing it); no directed edge occurs twice (the mesh is consistently oriented
 * and each edge has at most two triangles); the triangles at each node form one fan joined across
 * its edges (the mesh is a manifold at every node: a crack always duplicates the nodes it
 * disconnects). Cost O(n_tris) plus a sort per node of its corners. Returns true, or false with a
 * message naming the triangle, node or edge in why (len bytes, may be NULL). */
bool fs_mesh_check(const fs_mesh *m, char *why, size_t len);

/* Frees the edge arrays and the rings (after a change that invalidates them, for users that do not
 * need them; fs_mesh_build_edges and fs_mesh_build_rings make them again). */
void fs_mesh_drop_derived(fs_mesh *m);

/* Fills the edge arrays. Requires adjacency. */
void fs_mesh_build_edges(fs_mesh *m);

/* Fills ring_start / ring_tri. Requires adjacency. */
void fs_mesh_build_rings(fs_mesh *m);

/* Unwrapped position of corner c (0..2) of triangle t (see the design note). out has 3 components. */
void fs_mesh_corner(const fs_mesh *m, int32_t t, int c, double *out);

/* The corner (0..2) of triangle t at node, or -1 if node is none of its corners. */
static inline int fs_mesh_corner_of(const fs_mesh *m, int32_t t, int32_t node)
{
    for (int c = 0; c < 3; c++)
        if (m->tri[3 * (size_t)t + c] == node)
            return c;
    return -1;
}

/* Outward unit normal (x, y; z = 0) of the boundary edge from corner i to corner (i+1)%3 of triangle t
 * (plane and cylinder; the triangle lies to the edge's left), in the unwrapped frame of t. */
void fs_mesh_boundary_normal(const fs_mesh *m, int32_t t, int i, double *n);

/* Signed area of triangle t (cm^2; positive when correctly oriented). */
double fs_mesh_tri_area(const fs_mesh *m, int32_t t);

/* Number of boundary edges (adj == -1). */
int32_t fs_mesh_count_boundary_edges(const fs_mesh *m);

/* A 64-bit digest (FNV-1a) of what the mesh hands on: positions, triangles (corners in order), image
 * shifts, and the adjacency, edges and rings where they are built. Equal meshes, numbered alike,
 * have equal digests; for tests and benchmarks that compare meshes across builds or thread counts. */
uint64_t fs_mesh_digest(const fs_mesh *m);

/* Computes the Voronoi dual. Requires edges and rings. Caller frees with fs_voronoi_free. */
int fs_voronoi_build(const fs_mesh *m, fs_voronoi *out);
void fs_voronoi_free(fs_voronoi *v);

#endif
