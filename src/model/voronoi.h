/* The voronoi model: the non-physical baseline, cracks along the Voronoi edges of sampled points. */
#ifndef FS_MODEL_VORONOI_H
#define FS_MODEL_VORONOI_H

#include <stdint.h>

#include "geom/mesh.h"
#include "geom/surface.h"

typedef struct {
    double crack_width;  /* full width of a crack at the top surface (cm) */
    double bevel;        /* width of the rounded rim of each cell (cm) */
    double depth;        /* crack depth below the cell tops (cm) */
    double warp;         /* amplitude of the noise displacement of crack lines (cm) */
    double warp_scale;   /* feature size of the warping noise (cm) */
    int subdivisions;    /* segments each Voronoi edge is cut into before warping */
} fs_voronoi_params;

fs_voronoi_params fs_voronoi_params_default(void);

/* Builds the texture-space render mesh of the cracked cells for Delaunay mesh m (its dual gives
 * the cells). Cell ids are node index + 1 (wrapping past 65535 to stay non-zero). Periodic domains
 * stay periodic: warping noise wraps with the domain. Returns 0 or -1 with fs_error. */
int fs_voronoi_surface(const fs_mesh *m, const fs_voronoi_params *p, uint64_t seed, fs_surface *out);

#endif
