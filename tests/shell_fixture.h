/* Shared set-up of the shell model's unit tests: structured and jittered triangle grids, shells built on them. */
#ifndef FS_TESTS_SHELL_FIXTURE_H
#define FS_TESTS_SHELL_FIXTURE_H

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "model/shell/internal.h"

/* An nx x ny grid of cells over [0, a] x [0, b], two triangles per cell split by the diagonal from
 * (i, j) to (i + 1, j + 1), counter-clockwise seen from +z; node (i, j) is j (nx + 1) + i. jitter
 * (a fraction of the cell) moves interior nodes in the plane by the seed; bump adds
 * z = bump sin(pi x / a) sin(pi y / b) + the jitter's share of z: pos[2] holds it (domain sphere, so
 * the shell takes pos as its 3-D rest shape), or the domain is a non-periodic plane when flat. */
static inline void shell_test_grid(fs_mesh *m, int nx, int ny, double a, double b, double jitter, double bump,
                                   uint64_t seed, bool flat)
{
    memset(m, 0, sizeof *m);
    if (flat) {
        m->domain.type = FS_DOMAIN_PLANE;
        m->domain.width = a;
        m->domain.height = b;
    } else {
        m->domain.type = FS_DOMAIN_SPHERE;
        m->domain.radius = 1.0;
    }
    m->n_nodes = (nx + 1) * (ny + 1);
    m->pos = fs_calloc(3 * (size_t)m->n_nodes, sizeof *m->pos);
    for (int j = 0; j <= ny; j++)
        for (int i = 0; i <= nx; i++) {
            int32_t n = j * (nx + 1) + i;
            double x = a * i / nx, y = b * j / ny;
            if (i > 0 && i < nx && j > 0 && j < ny && jitter > 0.0) {
                x += jitter * a / nx * fs_rand_range(seed, FS_RNG_TEST, 3 * (uint64_t)n, -0.5, 0.5);
                y += jitter * b / ny * fs_rand_range(seed, FS_RNG_TEST, 3 * (uint64_t)n + 1, -0.5, 0.5);
            }
            m->pos[3 * n] = x;
            m->pos[3 * n + 1] = y;
            if (!flat)
                m->pos[3 * n + 2] = bump * sin(3.14159265358979 * x / a) * sin(3.14159265358979 * y / b) +
                                    jitter * 0.1 * a / nx * fs_rand_range(seed, FS_RNG_TEST, 3 * (uint64_t)n + 2, -0.5, 0.5);
        }
    m->n_tris = 2 * nx * ny;
    m->tri = fs_malloc(3 * (size_t)m->n_tris * sizeof *m->tri);
    m->shift = fs_calloc(6 * (size_t)m->n_tris, sizeof *m->shift);
    m->adj = fs_malloc(3 * (size_t)m->n_tris * sizeof *m->adj);
    int32_t t = 0;
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int32_t n00 = j * (nx + 1) + i, n10 = n00 + 1, n01 = n00 + nx + 1, n11 = n01 + 1;
            int32_t lower[3] = {n00, n10, n11}, upper[3] = {n00, n11, n01};
            memcpy(m->tri + 3 * (size_t)t++, lower, sizeof lower);
            memcpy(m->tri + 3 * (size_t)t++, upper, sizeof upper);
        }
    FS_ASSERT(fs_mesh_build_adjacency(m) == 0);
    fs_mesh_build_edges(m);
    fs_mesh_build_rings(m);
}

/* A setup for the shell model: E = 1000 MPa, nu = 0.3, thickness 0.1 cm constant, no growth, no
 * shrinkage, no bond (a free shell), one time unit. */
static inline fs_model_setup shell_test_setup(void)
{
    fs_model_setup c = fs_model_setup_default();
    c.kind = FS_MODEL_SHELL;
    c.seed = 7;
    c.material.young = 1000.0;
    c.material.poisson = 0.3;
    c.material.threshold = 1e9;
    c.material.thickness = 0.1;
    c.material.thickness_final = -1.0;
    c.material.jitter = 0.0;
    c.growth.type = FS_GROWTH_NONE;
    c.shell.bond = 0.0;
    c.time.end = 1.0;
    return c;
}

/* Pins component k (bit mask) of node i at its current position. */
static inline void shell_test_pin(fs_shell *s, int32_t i, unsigned mask)
{
    s->pin[i] |= (uint8_t)mask;
}

#endif
