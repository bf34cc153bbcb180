/* Grey-level maps over texture space (thesis §5.9): loaded by sim from images, sampled by the models. */
#ifndef FS_FIELD_MAP_H
#define FS_FIELD_MAP_H

#include <stdbool.h>

/* A grey level in [0, 1] per pixel, laid out as every map of the project (render.h's convention:
 * row 0 at the top, v growing up the image). A map with no pixels (grey NULL) is "no map": its
 * samples are 1. The pixels are owned by whoever filled the struct (sim, from the preset's images);
 * a model that is handed a map only samples it. */
typedef struct {
    int width, height;
    float *grey;         /* width * height, or NULL for no map */
    bool wrap_u, wrap_v; /* sample across the seam on axes where the domain wraps, else clamp */
} fs_grey_map;

/* The bilinear grey level at texture coordinates (u, v), pixel centres at (i + 1/2) / width and
 * 1 - (j + 1/2) / height; 1 for no map. */
double fs_grey_map_sample(const fs_grey_map *m, double u, double v);

/* Frees the pixels and zeroes the map. */
void fs_grey_map_free(fs_grey_map *m);

#endif
