/* Tests of the mesh module: adjacency, edges and rings of hand-built grids, the corner shifts across
 * periodic seams, incremental adjacency against a rebuild, and the invariant check. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "geom/mesh.h"
#include "mesh_fixture.h"

/* The neighbour of triangle t across its edge from node a to node b, by searching (-1: none). */
static int32_t across(const fs_mesh *m, int32_t t, int32_t a, int32_t b)
{
    for (int k = 0; k < 3; k++)
        if (m->tri[3 * t + k] == a && m->tri[3 * t + (k + 1) % 3] == b)
            return m->adj[3 * t + k];
    return -2;
}

/* A 3 x 2 plane grid: 12 nodes, 12 triangles, 10 boundary edges, 23 edges, Euler 1; the neighbours
 * of a square's two triangles are the ones the layout says. */
static void test_grid_adjacency(void)
{
    fs_mesh m;
    grid_mesh(3, 2, false, &m);
    CHECK(m.n_nodes == 12 && m.n_tris == 12);
    CHECK(fs_mesh_count_boundary_edges(&m) == 10);
    CHECK(mesh_edges(&m) == 23 && mesh_euler(&m) == 1);
    CHECK(fs_mesh_check(&m, NULL, 0));
    /* square (1, 0): triangles 2 and 3, nodes 1 (1,0), 2 (2,0), 6 (2,1), 5 (1,1) */
    CHECK(across(&m, 2, 1, 6) == -2);  /* not an edge of triangle 2 in that direction */
    CHECK(across(&m, 2, 6, 1) == 3);   /* the diagonal */
    CHECK(across(&m, 3, 1, 6) == 2);
    CHECK(across(&m, 2, 1, 2) == -1);  /* the bottom border */
    CHECK(across(&m, 2, 2, 6) == 5);   /* the right neighbour square's second triangle (2, 7, 6) */
    CHECK(across(&m, 3, 5, 1) == 0);   /* the left square's first triangle (0, 1, 5) */
    CHECK(across(&m, 3, 6, 5) == 8);   /* the square above: (1, 1) is triangles 8 and 9 */
    double area = 0.0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        CHECK(fs_mesh_tri_area(&m, t) == 0.5);
        area += fs_mesh_tri_area(&m, t);
    }
    CHECK(area == 6.0);
    fs_mesh_free(&m);
}

/* Edges and rings: 23 unique edges with two triangles or one on the border; an interior node's ring
 * is its six triangles counter-clockwise, each sharing an edge with the next; a corner node's ring
 * starts at the border. */
static void test_grid_edges_and_rings(void)
{
    fs_mesh m;
    grid_mesh(3, 2, false, &m);
    fs_mesh_build_edges(&m);
    fs_mesh_build_rings(&m);
    CHECK(m.n_edges == 23);
    int32_t two = 0, one = 0;
    for (int32_t e = 0; e < m.n_edges; e++) {
        CHECK(m.edge[2 * e] < m.edge[2 * e + 1]);
        two += m.edge_tri[2 * e + 1] >= 0;
        one += m.edge_tri[2 * e + 1] < 0;
    }
    CHECK(two == 13 && one == 10);
    /* node 5 = (1, 1) is interior: six triangles around it */
    int32_t v = 5, deg = m.ring_start[v + 1] - m.ring_start[v];
    CHECK(deg == 6);
    for (int32_t k = 0; k < deg; k++) {
        int32_t t = m.ring_tri[m.ring_start[v] + k], u = m.ring_tri[m.ring_start[v] + (k + 1) % deg];
        CHECK(fs_mesh_corner_of(&m, t, v) >= 0);
        /* the next triangle counter-clockwise is across t's edge that ends at v */
        int c = fs_mesh_corner_of(&m, t, v);
        CHECK(m.adj[3 * t + (c + 2) % 3] == u);
    }
    /* node 0 = (0, 0), a corner of the rectangle: triangles 0 (0, 1, 5) and 1 (0, 5, 4), counter-clockwise
     * from the border */
    CHECK(m.ring_start[1] - m.ring_start[0] == 2 && m.ring_tri[0] == 0 && m.ring_tri[1] == 1);
    CHECK(m.adj[3 * 0 + 0] < 0); /* the ring's first triangle has the border edge leaving node 0 */
    /* node 3 = (3, 0), the other corner: triangle 4 (2, 3, 7) only */
    CHECK(m.ring_start[4] - m.ring_start[3] == 1 && m.ring_tri[m.ring_start[3]] == 4);
    fs_mesh_free(&m);
}

/* A 4 x 3 torus: no boundary, Euler 0, every triangle counter-clockwise in its unwrapped frame; the
 * triangles beyond the seams carry shifts, and fs_mesh_corner adds them in periods. */
static void test_periodic_corner_shifts(void)
{
    fs_mesh m;
    grid_mesh(4, 3, true, &m);
    CHECK(m.n_nodes == 12 && m.n_tris == 24);
    CHECK(fs_mesh_count_boundary_edges(&m) == 0);
    CHECK(mesh_euler(&m) == 0);
    CHECK(fs_mesh_check(&m, NULL, 0));
    int32_t shifted = 0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        CHECK(fs_mesh_tri_area(&m, t) == 0.5);
        for (int k = 0; k < 3; k++) {
            double p[3];
            fs_mesh_corner(&m, t, k, p);
            const double *q = m.pos + 3 * (size_t)m.tri[3 * t + k];
            CHECK(p[0] == q[0] + 4.0 * m.shift[6 * t + 2 * k] && p[1] == q[1] + 3.0 * m.shift[6 * t + 2 * k + 1]);
            shifted += m.shift[6 * t + 2 * k] != 0 || m.shift[6 * t + 2 * k + 1] != 0;
        }
    }
    /* the last column (3 squares, 2 triangles each, 2 corners beyond x) and the last row likewise */
    CHECK(shifted > 0);
    /* triangle 6 = square (3, 0) first triangle: (3,0) (0,0)+x (0,1)+x */
    CHECK(m.tri[18] == 3 && m.tri[19] == 0 && m.tri[20] == 4);
    CHECK(m.shift[6 * 6 + 2] == 1 && m.shift[6 * 6 + 4] == 1 && m.shift[6 * 6 + 0] == 0);
    /* its neighbour across the seam edge (0,0)+x -> (0,1)+x is square (0, 0)'s second triangle (1) */
    CHECK(across(&m, 6, 0, 4) == 1);
    fs_mesh_free(&m);
}

/* fs_mesh_update_adjacency after a local change equals a rebuild: a triangle split into three at its
 * centroid (one slot rewritten, two appended). */
static void test_update_adjacency_matches_rebuild(void)
{
    for (int periodic = 0; periodic < 2; periodic++) {
        fs_mesh m;
        grid_mesh(4, 3, periodic, &m);
        int32_t t = periodic ? 6 : 9; /* periodic: a triangle across the seam */
        int32_t a = m.tri[3 * t], b = m.tri[3 * t + 1], c = m.tri[3 * t + 2];
        double pa[3], pb[3], pc[3];
        fs_mesh_corner(&m, t, 0, pa);
        fs_mesh_corner(&m, t, 1, pb);
        fs_mesh_corner(&m, t, 2, pc);
        int32_t n = m.n_nodes++;
        m.pos = realloc(m.pos, 3 * (size_t)m.n_nodes * sizeof *m.pos);
        for (int k = 0; k < 3; k++)
            m.pos[3 * n + k] = (pa[k] + pb[k] + pc[k]) / 3.0; /* inside the fundamental cell here */
        int8_t s[6] = {0};
        if (m.shift)
            memcpy(s, m.shift + 6 * t, sizeof s);
        int32_t t1 = m.n_tris, t2 = m.n_tris + 1;
        m.n_tris += 2;
        m.tri = realloc(m.tri, 3 * (size_t)m.n_tris * sizeof *m.tri);
        if (m.shift)
            m.shift = realloc(m.shift, 6 * (size_t)m.n_tris * sizeof *m.shift);
        int32_t corners[3][3] = {{a, b, n}, {b, c, n}, {c, a, n}};
        int32_t slot[3] = {t, t1, t2};
        int from[3][2] = {{0, 1}, {1, 2}, {2, 0}};
        for (int q = 0; q < 3; q++) {
            memcpy(m.tri + 3 * slot[q], corners[q], sizeof corners[q]);
            if (m.shift) {
                int8_t *d = m.shift + 6 * slot[q];
                int8_t x0 = s[2 * from[q][0]], y0 = s[2 * from[q][0] + 1];
                d[0] = 0, d[1] = 0;
                d[2] = (int8_t)(s[2 * from[q][1]] - x0), d[3] = (int8_t)(s[2 * from[q][1] + 1] - y0);
                d[4] = (int8_t)(-x0), d[5] = (int8_t)(-y0); /* the centroid sits at shift (0, 0) */
            }
        }
        CHECK(fs_mesh_update_adjacency(&m, t1, &t, 1) == 0);
        int32_t *adj = malloc(3 * (size_t)m.n_tris * sizeof *adj);
        memcpy(adj, m.adj, 3 * (size_t)m.n_tris * sizeof *adj);
        CHECK(fs_mesh_build_adjacency(&m) == 0);
        CHECK(memcmp(adj, m.adj, 3 * (size_t)m.n_tris * sizeof *adj) == 0);
        char why[200];
        CHECK_MSG(fs_mesh_check(&m, why, sizeof why), "%s", why);
        CHECK(mesh_euler(&m) == (periodic ? 0 : 1));
        CHECK_NEAR(mesh_area(&m), 12.0, 1e-12);
        free(adj);
        fs_mesh_free(&m);
    }
}

/* The invariant check finds a flipped triangle, a broken adjacency, an edge shared without being
 * joined, and a pinched node. */
static void test_check_finds_defects(void)
{
    fs_mesh m;
    char why[200];
    grid_mesh(3, 3, false, &m);
    CHECK(fs_mesh_check(&m, why, sizeof why));
    int32_t keep = m.tri[3 * 4 + 1];
    m.tri[3 * 4 + 1] = m.tri[3 * 4 + 2]; /* triangle 4 reversed */
    m.tri[3 * 4 + 2] = keep;
    CHECK(!fs_mesh_check(&m, why, sizeof why));
    CHECK_MSG(strstr(why, "triangle 4") != NULL, "%s", why);
    m.tri[3 * 4 + 2] = m.tri[3 * 4 + 1];
    m.tri[3 * 4 + 1] = keep;
    CHECK(fs_mesh_check(&m, NULL, 0));
    int32_t save = m.adj[3 * 4 + 2];
    m.adj[3 * 4 + 2] = -1; /* the diagonal of square (2, 0) forgotten on one side */
    CHECK(!fs_mesh_check(&m, why, sizeof why));
    m.adj[3 * 4 + 2] = save;
    m.adj[3 * 5] = -1; /* and on both sides: the edge is shared but not joined */
    m.adj[3 * 4 + 2] = -1;
    CHECK(!fs_mesh_check(&m, why, sizeof why));
    CHECK_MSG(strstr(why, "not joined") != NULL, "%s", why);
    fs_mesh_free(&m);

    /* two triangles touching at one node only: a bow tie */
    fs_mesh b;
    memset(&b, 0, sizeof b);
    b.domain = fs_domain_default();
    b.n_nodes = 5;
    double pos[15] = {0, 0, 0, 1, 0, 0, 1, 1, 0, -1, 0, 0, -1, -1, 0};
    int32_t tri[6] = {0, 1, 2, 0, 3, 4};
    b.pos = malloc(sizeof pos);
    memcpy(b.pos, pos, sizeof pos);
    b.n_tris = 2;
    b.tri = malloc(sizeof tri);
    memcpy(b.tri, tri, sizeof tri);
    CHECK(fs_mesh_build_adjacency(&b) == 0);
    CHECK(!fs_mesh_check(&b, why, sizeof why));
    CHECK_MSG(strstr(why, "node 0") != NULL && strstr(why, "2 fans") != NULL, "%s", why);
    fs_mesh_free(&b);
}

int main(void)
{
    RUN(test_grid_adjacency);
    RUN(test_grid_edges_and_rings);
    RUN(test_periodic_corner_shifts);
    RUN(test_update_adjacency_matches_rebuild);
    RUN(test_check_finds_defects);
    return check_finish();
}
