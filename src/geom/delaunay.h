/* Delaunay triangulation of a point set on a domain through Qhull (the only file that includes Qhull). */
#ifndef FS_GEOM_DELAUNAY_H
#define FS_GEOM_DELAUNAY_H

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

#endif
