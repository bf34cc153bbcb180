/* Smooth deterministic noise fields on domains, periodic where the domain is. */
#ifndef FS_FIELD_NOISE_H
#define FS_FIELD_NOISE_H

#include <stdint.h>

/* Gradient (Perlin-style) noise in 2-D with lattice spacing 1, value in about [-1, 1]. If period_x
 * (period_y) > 0 the field repeats with that integer period in x (y). Deterministic in seed. */
double fs_noise2(uint64_t seed, double x, double y, int period_x, int period_y);

/* Gradient noise in 3-D (for the sphere), lattice spacing 1. */
double fs_noise3(uint64_t seed, double x, double y, double z);

#endif
