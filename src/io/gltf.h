/* glTF 2.0 output of the cracked 3-D layer with its material (--asset FILE.gltf or FILE.glb). */
#ifndef FS_IO_GLTF_H
#define FS_IO_GLTF_H

#include <stdbool.h>

#include "render/render.h"

/* One texture of the material: the image's URI relative to the asset (a path with '/'
 * separators; the writer percent-encodes it) and where its PNG can be read now (for a .glb, which
 * embeds it). A texture with uri NULL is not bound. */
typedef struct {
    const char *uri;
    const char *read_path;
} fs_gltf_texture;

/* What the asset holds besides the mesh. */
typedef struct {
    const char *name;           /* node, mesh and material name */
    const char *generator;      /* asset.generator, e.g. "fissure 0.1.0" */
    fs_gltf_texture base_color; /* sRGB colour */
    fs_gltf_texture normal;     /* tangent-space normals, OpenGL (+Y up) as glTF requires */
    fs_gltf_texture orm;        /* R occlusion, G roughness, B metallic (io/target.h's gltf packing) */
    double roughness;           /* roughnessFactor when orm is not bound */
    bool wrap_u, wrap_v;        /* sampler wrap: REPEAT on tiling axes, else CLAMP_TO_EDGE */
    bool double_sided;          /* the layer is open (plane, cylinder): seen from below too */
    const char *height_uri;     /* the height map beside the asset (NULL: none); glTF 2.0 has no
                                   height slot, so it is named in material.extras, not bound */
    double height_min_cm, height_max_cm; /* its range, for material.extras */
} fs_gltf_material;

/* Writes the lifted mesh m as a glTF 2.0 asset: one scene, one node, one mesh of one indexed
 * triangle primitive with POSITION (metres, +Y up: a point (x, y, z) in cm of m, z up, becomes
 * (x, z, -y) / 100), NORMAL, TEXCOORD_0 (t = 1 - v: glTF's t runs down the image) and, when the
 * normal texture is bound, TANGENT (geom/tangent.h, which follows MikkTSpace as glTF asks), and one
 * metallic-roughness material binding mat's textures. With glb false, path gets the JSON and
 * bin_path the binary buffer, which the JSON names by bin_uri (relative to the asset); with glb
 * true, path gets one binary glTF file that embeds the buffer and the images (bin_path unused).
 * Writes exactly the paths given (io/output.h stages them). Returns 0, or -1 with fs_error
 * (FS_ERR_IO when a file cannot be written or an image read). */
int fs_gltf_write(const char *path, const char *bin_path, const char *bin_uri, bool glb, const fs_lifted_mesh *m,
                  const fs_gltf_material *mat);

#endif
