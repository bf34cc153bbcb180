/* Shared set-up of the mesh tests: structured grid meshes built by hand, and topological counts. */
#ifndef FS_TESTS_MESH_FIXTURE_H
#define FS_TESTS_MESH_FIXTURE_H

#include <stdlib.h>
#include <string.h>

#include "base/uf.h"
#include "geom/delaunay.h"
#include "geom/mesh.h"
#include "geom/sample.h"

/* An nx x ny grid of unit squares, each cut by its diagonal (i, j)-(i+1, j+1) into two
 * counter-clockwise triangles: (i, j) (i+1, j) (i+1, j+1) and (i, j) (i+1, j+1) (i, j+1), square
 * (i, j) giving triangles 2 (j nx + i) and 2 (j nx + i) + 1. Plane: an nx x ny cm rectangle with
 * (nx + 1)(ny + 1) nodes, node (i, j) = j (nx + 1) + i at (i, j). Periodic: a torus of nx ny nodes,
 * node (i, j) = j nx + i, the corners beyond the seams wrapped with a shift. Adjacency built. */
static inline void grid_mesh(int nx, int ny, bool periodic, fs_mesh *m)
{
    memset(m, 0, sizeof *m);
    m->domain = fs_domain_default();
    m->domain.width = nx;
    m->domain.height = ny;
    m->domain.periodic_x = m->domain.periodic_y = periodic;
    int cols = periodic ? nx : nx + 1, rows = periodic ? ny : ny + 1;
    m->n_nodes = cols * rows;
    m->pos = calloc(3 * (size_t)m->n_nodes, sizeof *m->pos);
    for (int j = 0; j < rows; j++)
        for (int i = 0; i < cols; i++) {
            m->pos[3 * (j * cols + i)] = i;
            m->pos[3 * (j * cols + i) + 1] = j;
        }
    m->n_tris = 2 * nx * ny;
    m->tri = malloc(3 * (size_t)m->n_tris * sizeof *m->tri);
    if (periodic)
        m->shift = calloc(6 * (size_t)m->n_tris, sizeof *m->shift);
    static const int corner[2][3][2] = {{{0, 0}, {1, 0}, {1, 1}}, {{0, 0}, {1, 1}, {0, 1}}};
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++)
            for (int h = 0; h < 2; h++) {
                int t = 2 * (j * nx + i) + h;
                for (int k = 0; k < 3; k++) {
                    int ci = i + corner[h][k][0], cj = j + corner[h][k][1];
                    int wi = periodic ? ci % nx : ci, wj = periodic ? cj % ny : cj;
                    m->tri[3 * t + k] = wj * cols + wi;
                    if (periodic) {
                        m->shift[6 * t + 2 * k] = (int8_t)(ci / nx);
                        m->shift[6 * t + 2 * k + 1] = (int8_t)(cj / ny);
                    }
                }
            }
    fs_mesh_build_adjacency(m);
}

/* A periodic w x w cm tile of about `points` nodes, Poisson-disk sampled with the seed and meshed.
 * Returns 0, or -1 with fs_error. */
static inline int sampled_tile(double w, int32_t points, uint64_t seed, fs_mesh *m)
{
    fs_domain d = fs_domain_default();
    d.width = d.height = w;
    d.periodic_x = d.periodic_y = true;
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = points;
    sp.seed = seed;
    fs_points pts = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0)
        return -1;
    int rc = fs_delaunay(&d, &pts, m);
    fs_points_free(&pts);
    return rc;
}

/* Undirected edges: the half-edges joined in pairs, plus the boundary ones. */
static inline int32_t mesh_edges(const fs_mesh *m)
{
    int32_t boundary = fs_mesh_count_boundary_edges(m);
    return (3 * m->n_tris - boundary) / 2 + boundary;
}

/* The Euler characteristic V - E + F. */
static inline int32_t mesh_euler(const fs_mesh *m) { return m->n_nodes - mesh_edges(m) + m->n_tris; }

/* Pieces of the mesh: triangles joined across their shared edges. */
static inline int32_t mesh_components(const fs_mesh *m)
{
    int32_t *parent = malloc(((size_t)m->n_tris + 1) * sizeof *parent);
    fs_uf_init(parent, m->n_tris);
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        if (m->adj[h] >= 0)
            fs_uf_union(parent, h / 3, m->adj[h]);
    int32_t count = 0;
    for (int32_t t = 0; t < m->n_tris; t++)
        count += fs_uf_find(parent, t) == t;
    free(parent);
    return count;
}

/* The sum of the triangles' signed areas. */
static inline double mesh_area(const fs_mesh *m)
{
    double s = 0.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        s += fs_mesh_tri_area(m, t);
    return s;
}

#endif
