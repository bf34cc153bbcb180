/* The pipeline from a run's surface to its files: raster, maps, preview, occlusion, crack graph, engine target, 3-D files, sidecar, one committed output set. */
#ifndef FS_IO_OUTPUTS_H
#define FS_IO_OUTPUTS_H

#include <stdbool.h>

#include "geom/surface.h"
#include "io/output.h"
#include "io/sidecar.h"
#include "io/target.h"
#include "render/crackgraph.h"
#include "render/render.h"
#include "sim/settings.h"
#include "sim/sim.h"

/* The products of --maps, in the order they are listed and written. */
typedef enum {
    FS_MAP_HEIGHT, FS_MAP_NORMAL, FS_MAP_BASECOLOR, FS_MAP_CRACKMASK, FS_MAP_CRACKDIST, FS_MAP_CELLID, FS_MAP_PREVIEW,
    FS_MAP_OCCLUSION, FS_MAP_CRACKS, FS_MAP_COUNT
} fs_map_kind;

/* The word of --maps for a kind ("height", ..., "cracks"), which io/target.h names and packs. */
const char *fs_map_name(fs_map_kind kind);

/* Whether a kind is a texture-space raster map (what a time-lapse frame can have). */
bool fs_map_is_raster(fs_map_kind kind);

/* What a surface becomes in memory, each part only when asked for, and the seconds each step took. */
typedef struct {
    fs_raster raster;
    fs_maps maps;            /* height, normal, basecolor, crackmask, crackdist, cellid */
    fs_image exr_height;     /* float height in cm straight from the raster (FS_MAP_HEIGHT with exr) */
    fs_image preview;        /* the lit 3-D view (FS_MAP_PREVIEW) */
    fs_image occlusion;      /* ambient occlusion (FS_MAP_OCCLUSION) */
    fs_crackgraph cracks;    /* the crack graph (FS_MAP_CRACKS) */
    double render_seconds, maps_seconds, preview_seconds, occlusion_seconds, cracks_seconds;
} fs_outputs;

/* Renders surface at cfg's render size (wrapping where cfg's domain does) and builds the maps, and
 * those of the preview, occlusion, float height and crack graph that kinds asks for. Returns 0, or
 * -1 with fs_error; out needs fs_outputs_free either way. */
int fs_outputs_build(const fs_surface *surface, const fs_config *cfg, const bool kinds[FS_MAP_COUNT], bool exr,
                     fs_outputs *out);
void fs_outputs_free(fs_outputs *o);

/* Where and how the files of a run go. Pointers are borrowed. */
typedef struct {
    const char *output_dir;
    const char *name;            /* the output name: NAME_height.png, NAME.json, ... */
    bool kinds[FS_MAP_COUNT];
    bool exr;
    fs_target target;
    const char *mesh_path;       /* --mesh FILE.obj (its MTL beside it), or NULL */
    const char *asset_path;      /* --asset FILE.gltf or FILE.glb, or NULL */
    const char *preset_text;     /* the preset file's content, hashed in the sidecar (may be NULL) */
    fs_output *frames;           /* the staged time-lapse frames, taken into the set, or NULL */
    const fs_sidecar_frames *frame_info; /* what the sidecar says of them, or NULL */
    double t_start;              /* fs_seconds() at the start of the run, for the sidecar's wall time */
} fs_outputs_request;

/* The final paths of a committed set, in the order the command line prints them: the maps and the
 * crack graph, the sidecar, then the 3-D files. */
typedef struct {
    int n;
    char **path;
} fs_outputs_paths;
void fs_outputs_paths_free(fs_outputs_paths *p);

/* Writes what b holds for r's kinds as target r->target names and packs them, the 3-D files, and the
 * sidecar, as one output set (io/output.h): the frames of r->frames are merged into it, the sidecar
 * names every file and is moved into place last, and on any failure nothing of the set is left.
 * Returns 0 with the final paths in *paths, or -1 with fs_error (r->frames is taken either way). */
int fs_outputs_write(const fs_outputs *b, const fs_surface *surface, const fs_config *cfg, const fs_stats *stats,
                     const fs_outputs_request *r, fs_outputs_paths *paths);

#endif
