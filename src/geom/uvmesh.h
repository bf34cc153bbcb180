/* UV-mapped triangle meshes a user brings (Wavefront OBJ): reading, welding and the checks that refuse meshes a model cannot take. */
#ifndef FS_GEOM_UVMESH_H
#define FS_GEOM_UVMESH_H

#include <stddef.h>
#include <stdint.h>

#include "geom/mesh.h"

/* The largest mesh accepted, in triangles (after polygons are split into fans). */
#define FS_UVMESH_MAX_TRIS 200000

/* design: an artist's mesh for [domain] type = mesh (SPEC §2). The OBJ file gives positions (v, in
 * cm), texture coordinates (vt) and faces (f, every corner with a texture coordinate: v/vt or
 * v/vt/vn; polygons are split into fans from their first corner). Positions that are equal to the
 * last digit are one vertex (the mesh is welded by position), so a UV seam, where a position has two
 * texture coordinates, is a seam of the maps only: the surface is one piece across it.
 * The mesh is refused (FS_ERR_DATA, the message naming the file and the defect, with the line of the
 * face where there is one) when
 *   - a line cannot be read (a number, an index out of range, a face of fewer than 3 corners),
 *   - it has no faces, or more than FS_UVMESH_MAX_TRIS triangles,
 *   - a face corner has no texture coordinate (missing UVs),
 *   - a texture coordinate lies outside [0, 1] (beyond 1e-6),
 *   - a triangle is degenerate in space (two corners at one vertex, or no area),
 *   - a triangle is degenerate in texture space (less than 1e-12 of the unit square),
 *   - an edge has more than two faces, or two faces run along it the same way (non-manifold or
 *     inconsistently oriented), or the faces around a vertex do not form one fan (a non-manifold
 *     vertex),
 *   - two triangles overlap in texture space (beyond touching along their borders).
 * A file that cannot be opened is FS_ERR_NOINPUT; a read error FS_ERR_IO. */

/* The mesh read: out is a mesh of domain type FS_DOMAIN_MESH (positions in space, no shifts, with
 * adjacency, edges and rings), whose domain width and height are both sqrt(area / texture area), the
 * cm per unit of texture; *corner_uv (6 per triangle, caller frees) the corners' texture
 * coordinates. Returns 0, or -1 with fs_error and nothing allocated. */
int fs_uvmesh_read(const char *path, fs_mesh *out, double **corner_uv);

/* As fs_uvmesh_read from text in memory (len bytes); name is what messages call it. */
int fs_uvmesh_parse(const char *text, size_t len, const char *name, fs_mesh *out, double **corner_uv);

#endif
