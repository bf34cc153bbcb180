/* The JSON sidecar written beside the maps. */
#ifndef FS_IO_SIDECAR_H
#define FS_IO_SIDECAR_H

#include <stdint.h>

#include "render/render.h"
#include "sim/settings.h"
#include "sim/sim.h"

/* One written map, as the sidecar describes it. */
typedef struct {
    const char *kind;        /* "height", "normal", ... */
    const char *file;        /* file name (no directory) */
    const fs_image *image;   /* NULL for a file that is not an image (the crack graph) */
    const char *color_space; /* "linear", "srgb", "data" */
    const char *channels;    /* what each channel holds (NULL: not described) */
    const char *usage;       /* where the target engine takes the file (NULL: no engine) */
} fs_sidecar_map;

/* The time-lapse frames of a run (--frames), as the sidecar describes them. */
typedef struct {
    int32_t count;               /* frames, numbered 1 .. count */
    const char *file_pattern;    /* how frame files are named, e.g. "NAME_frame_NNNN_KIND.png" */
    const double *time;          /* count: simulated time of each frame */
    const int64_t *fractures;    /* count: fracture events up to each frame */
    const double *height_min_cm, *height_max_cm; /* count: each frame's height map range */
    const fs_sidecar_map *map;   /* per map kind written for every frame: file is the kind's name
                                    pattern, image a frame's image (its pixels are not read) */
    int n_maps;
} fs_sidecar_frames;

/* Writes the sidecar to path: version, preset name and hash, seed, every resolved parameter,
 * statistics, the engine target (--target) and per file its colour space, bit depth, channels and
 * their meaning, engine usage, normal convention, height scale and tileability (never for the
 * perspective preview), the time-lapse frames if frames is not NULL, and `files`: every file of
 * the run but the sidecar (io/output.h's fs_output_names), which is what makes a whole set.
 * preset_text is the preset file's content (hashed), or NULL. Returns 0 or -1. */
int fs_sidecar_write(const char *path, const fs_config *cfg, const char *preset_text, const fs_stats *stats,
                     const fs_maps *maps, const char *target, const fs_sidecar_map *list, int n_maps,
                     const fs_sidecar_frames *frames, const char *const *files, int n_files, double wall_seconds);

#endif
