/* Point sampling on a domain: particle repulsion with perturbed radii (thesis §4.4 and §5.2,
 * Algorithms 2-3) on a uniform grid, and the regular hexagonal lattice. */
#ifndef FS_GEOM_SAMPLE_H
#define FS_GEOM_SAMPLE_H

#include <stdint.h>

#include "geom/domain.h"

typedef struct {
    int32_t count;        /* number of points wanted (> 0) */
    int iterations;       /* repulsion iterations */
    double radius_jitter; /* relative random perturbation of each particle's force radius, in [0, 1) */
    uint64_t seed;
} fs_sample_params;

/* count 1000, 30 iterations, radius jitter 0.2, seed 1. */
fs_sample_params fs_sample_params_default(void);

/* A point set in domain coordinates (see domain.h): 3 doubles per point. Owned by the caller;
 * release with fs_points_free. */
typedef struct {
    int32_t n;
    double *p;   /* 3 * n */
} fs_points;

/* Particle repulsion: places params->count points, roughly evenly spaced, on the domain. Cost is
 * O(count * iterations) through a uniform grid of cells about one force radius wide. Periodic
 * directions wrap. Deterministic for a given seed, whatever the number of threads (a large set is
 * sampled on up to one thread per processor). Returns 0, or -1 with fs_error(FS_ERR_DATA, ...)
 * for an impossible request (count < 3, too many points for memory, a degenerate domain). */
int fs_sample_repulsion(const fs_domain *d, const fs_sample_params *params, fs_points *out);

/* Regular hexagonal lattice with about `count` points (plane and cylinder only; on periodic
 * directions the lattice is fitted so it closes up exactly). Returns 0 or -1 with fs_error. */
int fs_sample_hex(const fs_domain *d, int32_t count, fs_points *out);

/* The mean spacing of `count` evenly spread points on the domain: sqrt(2 A / (sqrt(3) count)). */
double fs_sample_spacing(const fs_domain *d, int32_t count);

void fs_points_free(fs_points *pts);

#endif
