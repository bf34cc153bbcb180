/* Delaunay triangulation of a point set on a domain through Qhull (the only file that includes Qhull). */
#ifndef FS_GEOM_DELAUNAY_H
#define FS_GEOM_DELAUNAY_H

#include <stdbool.h>

#include "geom/mesh.h"
#include "geom/sample.h"

/* Triangulates pts on domain d into out (positions copied; tri, shift and adjacency filled; edges
 * and rings built):
 *   plane       Delaunay by the paraboloid lift (boundary = convex hull)
 *   periodic    points copied across the seams, one copy of each triangle kept: no boundary, no seam
 *   cylinder    as a plane periodic in x (and in y when periodic_y)
 *   sphere      3-D convex hull of the points (which must lie on the sphere)
 * Returns 0, or -1 with fs_error: FS_ERR_DATA for degenerate input (fewer than 3 or 4 points,
 * all collinear/coplanar, duplicates that leave no valid mesh), FS_ERR_INTERNAL when Qhull fails
 * (its exit code and message in the error). */
int fs_delaunay(const fs_domain *d, const fs_points *pts, fs_mesh *out);

/* Tetrahedra as Qhull's 3-D Delaunay gives them (see fs_delaunay_tets). Owned by the caller. */
typedef struct {
    int32_t n_tets;
    int32_t *tet;    /* 4 node indices per tetrahedron, positively oriented (the corners as unwrapped
                      * by their shifts span a positive volume, or zero for a flat one) */
    int8_t *shift;   /* 8 per tetrahedron: the image shift (sx, sy) of each corner in periods; the
                      * smallest corner (node, then shift) is at (0, 0) */
} fs_tets;

/* The 3-D Delaunay tetrahedralization of n points (3 coordinates each) through Qhull ("d Qbb Qc Qz
 * Qt"), periodic in x where period[0] > 0 and in y where period[1] > 0 (the points must lie in
 * [0, period) there): each point is copied across the wrapping sides when it lies within `margin` of
 * the fundamental cell, and one copy of each tetrahedron is kept. A margin too narrow leaves a
 * triangulation that is wrong near the seams; the caller checks and retries wider. merge: run Qhull
 * with facet merging at once (slower; the fallback when the unmerged run fails or its result does
 * not check). Returns 0, or -1
 * with fs_error (FS_ERR_DATA for fewer than 4 points, non-finite or degenerate input; FS_ERR_INTERNAL
 * when Qhull fails). */
int fs_delaunay_tets(const double *pts, int32_t n, const double period[2], double margin, bool merge,
                     fs_tets *out);
void fs_tets_free(fs_tets *t);

#endif
