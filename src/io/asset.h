/* The 3-D outputs of a run, bound to its maps: --mesh FILE.obj with FILE.mtl, and --asset
 * FILE.gltf (with FILE.bin) or FILE.glb. */
#ifndef FS_IO_ASSET_H
#define FS_IO_ASSET_H

#include "geom/surface.h"
#include "io/output.h"
#include "io/sidecar.h"
#include "render/render.h"
#include "sim/settings.h"

/* What the 3-D outputs are made from. Pointers are borrowed. */
typedef struct {
    const char *mesh_path;        /* --mesh: the OBJ to write (its MTL beside it), or NULL */
    const char *asset_path;       /* --asset: the .gltf or .glb to write, or NULL */
    const fs_surface *surface;    /* the final texture-space surface (lifted into 3-D here) */
    const fs_config *cfg;
    const char *name;             /* the output name: object, material and node name */
    const char *map_dir;          /* the output directory of the maps */
    fs_output *map_out;           /* the maps' output set, staged but not committed (a .glb reads
                                     the images it embeds from there) */
    const fs_sidecar_map *maps;   /* the files the run wrote into map_dir (io/target.h) */
    int n_maps;
    const char *target;           /* the --target they were written for */
    double height_min_cm, height_max_cm; /* the height map's range */
} fs_asset_inputs;

/* design: the layer is lifted once (render/lift.c, heights at scale 1) and written by
 * io/obj.c and io/gltf.c. Maps are referred to by paths relative to the file that names them (the
 * MTL, the .gltf): --mesh and --asset may lie outside the output directory.
 *
 * The MTL binds what Wavefront's format and Blender's importer have slots for: the base colour
 * (map_Kd), the normal map (map_Bump, an OpenGL normal map as Blender reads it; a DirectX one is
 * named in a comment, not bound), the height as displacement (disp), roughness as Ns and the PBR
 * extension's Pr and Pm; occlusion has no slot and is named in a comment. The glTF material binds
 * the base colour, the normal map and the packed occlusion-roughness-metallic map of --target
 * gltf; glTF 2.0 has no height slot, so the height map is named in material.extras and in the
 * sidecar, not bound.
 *
 * Stages each requested file in its own output set (*mesh_out, *asset_out; NULL when not
 * requested), to be committed with the maps. Returns 0, or -1 with fs_error and nothing left
 * staged. */
int fs_asset_stage(const fs_asset_inputs *in, fs_output **mesh_out, fs_output **asset_out);

/* The files of the requested 3-D outputs, for the sidecar and stdout: per file a sidecar entry
 * (kind "mesh", "mesh_material", "asset" or "asset_buffer", file = its path relative to the
 * output directory, usage = what it holds and binds) into list, with its strings in storage, and
 * the path as the command line named it (the directory of --mesh or --asset joined with the file
 * name) in paths. At most 4 files; returns how many. */
int fs_asset_files(const fs_asset_inputs *in, fs_sidecar_map *list, char (*storage)[1024], char (*paths)[1024]);

#endif
