/* Mesh surgery of a crack in a tetrahedral mesh (O'Brien & Hodgins §4.3): a node split along a plane, the elements it cuts split, snapping to existing nodes. */
#ifndef FS_GEOM_TETCUT_H
#define FS_GEOM_TETCUT_H

#include <stdint.h>

#include "geom/tetmesh.h"

/* The snapping of O'Brien & Hodgins §4.3 (they used 5 mm and 0.1 rad): a corner of an element at the
 * node is taken to lie on the fracture plane when it is nearer the plane than snap_distance, or when
 * the line from the node to it makes an angle smaller than snap_angle with the plane. Besides, an
 * edge is never cut within a fifth of its length from an end: that end is taken as on the plane
 * instead (else the halves of a long edge cut next to its end are slivers). */
typedef struct {
    double snap_distance; /* cm */
    double snap_angle;    /* radians */
} fs_tetcut_params;

/* What a cut changed, for the model to bring its state along. Owned by the caller (reused across
 * cuts: fs_tetcut_node empties it first); fs_tetcut_result_free releases it. */
typedef struct {
    int32_t n_nodes_before, n_tets_before;
    /* per new node (index n_nodes_before + k): the nodes it comes from and where between them:
     * a copy of a when a == b (a node split apart), else the point (1 - w) a + w b of the edge */
    int32_t *from;        /* 2 per new node */
    double *weight;       /* 1 per new node */
    int32_t *parent;      /* per new tetrahedron (index n_tets_before + k): the one it was cut from */
    fs_tet_list changed;  /* tetrahedra below n_tets_before whose corners changed, ascending, unique */
    int32_t node_minus;   /* the copy of the split node that took the negative side, or -1 */
    int32_t cap_nodes, cap_tets;
} fs_tetcut_result;

void fs_tetcut_result_free(fs_tetcut_result *r);

/* design: O'Brien & Hodgins §4.3, as edge splits. The corners of the elements at `node` (its star)
 * are classified by their signed distance to the plane through the node with unit normal `normal`
 * (material coordinates), corners within the snapping thresholds counted as on it. Every edge of the
 * star between corners strictly on opposite sides is split at the plane: a new node there, and every
 * tetrahedron around that edge (in the star or not) replaced by its two halves. After all such
 * splits each element of the star lies on one side (its other corners are on one side or on the
 * plane), which gives the paper's splits (an element cut through two edges into three tetrahedra,
 * through one edge and a snapped corner into two) and its secondary splits of the face and edge
 * neighbours (which do not touch the node and so stay whole across the plane), using only the
 * original nodes and those on the cut edges. The node is then copied: the copy takes the elements on
 * the negative side. Last, every node on the plane whose elements no longer form one piece through
 * shared faces (the crack reached a boundary or an earlier crack through it, the paper's first
 * subtlety) gets one copy per further piece. zeta is interpolated along the cut edges (exact where
 * both ends agree). The node lists must be built.
 * Returns 1 when the node was split, 0 when the plane leaves all its elements on one side (nothing
 * changed), -1 with fs_error(FS_ERR_DATA) for a zero normal. */
int fs_tetcut_node(fs_tetmesh *m, int32_t node, const double normal[3], const fs_tetcut_params *p,
                   fs_tetcut_result *out);

/* Which sides of the plane through `node` with the given normal the corners of its elements lie on,
 * with the snapping above: bit 0 set when some corner is strictly on the positive side, bit 1 when
 * some is on the negative side. fs_tetcut_node splits the node exactly when both are set (3). */
int fs_tetcut_sides(const fs_tetmesh *m, int32_t node, const double normal[3], const fs_tetcut_params *p);

/* Splits the edge from a to b (b's shift relative to a's given by rel, 2 values) at (1 - w) a + w b,
 * 0 < w < 1: one new node, each tetrahedron around the edge replaced by its two halves. Records
 * into out (which it does not empty) as fs_tetcut_node. Returns the new node. */
int32_t fs_tetcut_split_edge(fs_tetmesh *m, int32_t a, int32_t b, const int8_t rel[2], double w,
                             fs_tetcut_result *out);

#endif
