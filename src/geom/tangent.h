/* Per-vertex tangent frames of a textured triangle mesh, for tangent-space normal maps. */
#ifndef FS_GEOM_TANGENT_H
#define FS_GEOM_TANGENT_H

#include <stdint.h>

/* Computes a tangent (x, y, z, w) for every vertex of an indexed triangle mesh the way MikkTSpace
 * does, so that a normal map baked in texture space reads the same in any engine that follows it
 * (glTF 2.0, Blender, Unreal, Unity):
 *   - xyz is the direction in which u grows on the surface, projected onto the plane of the vertex
 *     normal and normalised: the angle-weighted mean over the triangles around the vertex;
 *   - w = +1 where the texture is not mirrored (the bitangent cross(normal, xyz) points the way v
 *     grows), -1 where it is. A vertex used by triangles of both kinds is split in two.
 * Texture coordinates have v growing up the image, the direction +Y (green) of an OpenGL normal
 * map points (a glTF writer flips v to its t = 1 - v and keeps w).
 *
 * pos (3 per vertex), normal (3 per vertex, unit) and uv (2 per vertex) describe n_vert vertices;
 * tri holds 3 vertex indices per triangle, counter-clockwise seen from the side the normals face,
 * and is rewritten where vertices are split. pos_id (may be NULL) gives per vertex a position
 * identity: vertices that are copies of one point with other normals or texture coordinates share
 * it. A vertex whose triangles all have a degenerate texture mapping (zero area in uv, as the walls
 * of cracks have) takes the tangent of the copies of its point, projected onto its own normal plane,
 * and any unit vector perpendicular to its normal when that fails.
 *
 * Returns the number of vertices after splitting, n_out >= n_vert; *source (n_out, caller frees)
 * names the input vertex of each (source[i] = i for i < n_vert) and *tangent (4 * n_out floats,
 * caller frees) holds the tangents. Deterministic: the result depends on the input only. */
int32_t fs_tangents_build(const float *pos, const float *normal, const float *uv, const int32_t *pos_id,
                          int32_t n_vert, uint32_t *tri, int32_t n_tris, int32_t **source, float **tangent);

#endif
