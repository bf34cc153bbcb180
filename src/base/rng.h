/* Deterministic counter-based random numbers: a value is a hash of (seed, purpose, index), so it does
 * not depend on iteration order or thread count. Never use rand(). */
#ifndef FS_BASE_RNG_H
#define FS_BASE_RNG_H

#include <stdint.h>

/* Purposes keep independent random streams apart. Append new values; never renumber. */
typedef enum {
    FS_RNG_SAMPLE_INIT = 1,   /* initial point positions */
    FS_RNG_SAMPLE_RADIUS = 2, /* perturbed repulsion radii */
    FS_RNG_NOISE = 3,         /* lattice values of noise fields */
    FS_RNG_CELL_COLOR = 4,    /* per-cell colour variation */
    FS_RNG_JITTER = 5,        /* per-element material jitter */
    FS_RNG_TIEBREAK = 6,      /* ranking ties between fracture candidates */
    FS_RNG_TEST = 100         /* tests only */
} fs_rng_purpose;

/* 64 well-mixed bits for (seed, purpose, index). */
uint64_t fs_hash3(uint64_t seed, uint32_t purpose, uint64_t index);

/* Uniform double in [0, 1) for (seed, purpose, index). */
double fs_rand01(uint64_t seed, uint32_t purpose, uint64_t index);

/* Uniform double in [lo, hi). */
double fs_rand_range(uint64_t seed, uint32_t purpose, uint64_t index, double lo, double hi);

/* Standard normal variate (Box–Muller on two hashed uniforms). */
double fs_rand_normal(uint64_t seed, uint32_t purpose, uint64_t index);

#endif
