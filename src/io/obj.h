/* Wavefront OBJ output of the cracked 3-D layer (NAME.obj with --mesh, SPEC §6). */
#ifndef FS_IO_OBJ_H
#define FS_IO_OBJ_H

#include "render/render.h"

/* Writes m to exactly `path` (not atomic by itself: io/output.h stages files) as one object named
 * `name`: positions in cm ("v"), texture coordinates in [0, 1] with v up the maps ("vt"), unit
 * normals ("vn") and triangles "f p/t/n" counter-clockwise seen from outside, the layer's
 * triangles in group "layer" and the walls the lift added in group "walls". Comment lines at the
 * top carry `comment` (may be NULL) and the counts. With mtllib (a file name relative to the OBJ,
 * or NULL for none) the file loads that material library and uses its material `name` for every
 * face. Returns 0 or -1 with fs_error(FS_ERR_IO). */
int fs_obj_write(const char *path, const fs_lifted_mesh *m, const char *name, const char *comment, const char *mtllib);

#endif
