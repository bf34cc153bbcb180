/* A cheap ambient occlusion term from the height raster: how far each pixel lies below its blurred surroundings. */
#ifndef FS_RENDER_OCCLUSION_H
#define FS_RENDER_OCCLUSION_H

#include <stdbool.h>

#include "image/image.h"
#include "render/render.h"

typedef struct {
    double radius;   /* blur radius as a fraction of the map's shorter side (the cavity scale) */
    double strength; /* occlusion per unit of depth below the blurred surface, in height ranges */
} fs_occlusion_params;

/* radius 0.01 (at least one pixel), strength 1. */
fs_occlusion_params fs_occlusion_params_default(void);

/* Builds an 8-bit single-channel occlusion map, 255 = unoccluded, linear:
 *   ao = 1 - strength * max(0, blur(h) - h) / (h_max - h_min)
 * where blur is three box filters of radius r = radius * min(W, H) pixels (close to a Gaussian of
 * sigma r), wrapping on the given axes and clamped at the other borders. It is not a ray-traced
 * occlusion: crack floors and walls darken by their depth below the surrounding cell tops, flat
 * tops stay at 255. A flat raster gives 255 everywhere. out is allocated (fs_image_free). Returns 0. */
int fs_occlusion_build(const fs_raster *r, const fs_occlusion_params *p, bool wrap_u, bool wrap_v, fs_image *out);

#endif
