/* Tests of the crack surgery kernel (geom/cut): split edges and duplicated nodes on hand-built grids,
 * the record of the change, and the topology after cuts (Euler characteristic, pieces, manifoldness). */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "geom/cut.h"
#include "geom/mesh.h"
#include "mesh_fixture.h"

static bool mesh_ok(const fs_mesh *m)
{
    char why[256];
    bool ok = fs_mesh_check(m, why, sizeof why);
    CHECK_MSG(ok, "%s", why);
    return ok;
}

/* An interior edge split: one node and two triangles more, the record names them, areas and Euler
 * characteristic are kept; a border edge split adds one triangle and one border edge. */
static void test_split_edge(void)
{
    fs_mesh m;
    grid_mesh(3, 3, false, &m); /* node (i, j) = 4 j + i; square (i, j): triangles 2 (3 j + i) + 0, 1 */
    fs_cut c;
    fs_cut_begin(&c, &m, NULL, NULL);
    /* triangle 0 = (0, 1, 5); its edge 1 runs 1 -> 5, shared with triangle 3 = (1, 6, 5) */
    CHECK(m.tri[0] == 0 && m.tri[1] == 1 && m.tri[2] == 5 && m.adj[1] == 3);
    int32_t i = fs_cut_split_edge(&c, 0, 1, 0.25);
    CHECK(i == 16 && m.n_nodes == 17 && m.n_tris == 20);
    CHECK(m.pos[3 * i] == 1.0 && m.pos[3 * i + 1] == 0.25);
    CHECK(c.node_parent[0] == 1 && c.node_parent[1] == 5 && c.node_weight[0] == 0.25);
    CHECK(c.tri_parent[0] == 0 && c.tri_parent[1] == 3);
    CHECK(c.n_changed == 2);
    int32_t *changed = fs_cut_changed_ascending(&c);
    CHECK(changed[0] == 0 && changed[1] == 3);
    free(changed);
    /* t keeps (0, 1, p), the new one gets (0, p, 5) in t's corner order */
    CHECK(m.tri[0] == 0 && m.tri[1] == 1 && m.tri[2] == i);
    CHECK(m.tri[3 * 18] == 0 && m.tri[3 * 18 + 1] == i && m.tri[3 * 18 + 2] == 5);
    CHECK(fs_cut_update_adjacency(&c) == 0);
    mesh_ok(&m);
    CHECK(mesh_euler(&m) == 1 && fs_mesh_count_boundary_edges(&m) == 12);
    CHECK_NEAR(mesh_area(&m), 9.0, 1e-12);
    /* the fan of the new node, by a scan: the four triangles around it, ascending */
    int32_t *fan = NULL, cap = 0;
    CHECK(fs_cut_tris_at(&c, i, &fan, &cap) == 4);
    CHECK(fan[0] == 0 && fan[1] == 3 && fan[2] == 18 && fan[3] == 19);
    /* a border edge: triangle 0's edge 0 (0 -> 1) */
    CHECK(m.adj[0] == -1);
    int32_t j = fs_cut_split_edge(&c, 0, 0, 0.5);
    CHECK(m.n_tris == 21 && m.n_nodes == 18 && m.pos[3 * j] == 0.5 && m.pos[3 * j + 1] == 0.0);
    CHECK(c.tri_parent[2] == 0); /* a descendant of pre-cut triangle 0 */
    CHECK(fs_cut_update_adjacency(&c) == 0);
    mesh_ok(&m);
    CHECK(mesh_euler(&m) == 1 && fs_mesh_count_boundary_edges(&m) == 13);
    CHECK_NEAR(mesh_area(&m), 9.0, 1e-12);
    free(fan);
    fs_cut_free(&c);
    fs_mesh_free(&m);
}

/* A cut right across a 3 x 3 grid along x = 1, node by node from the border: every node of the path
 * splits into two sectors, and the mesh falls into two discs (Euler characteristic 2). */
static void test_cut_across(void)
{
    fs_mesh m;
    grid_mesh(3, 3, false, &m);
    fs_cut c;
    fs_cut_begin(&c, &m, NULL, NULL);
    const int32_t path[4] = {1, 5, 9, 13};
    for (int k = 0; k < 4; k++) {
        int32_t cut[2], n_cut = 0;
        if (k > 0)
            cut[n_cut++] = path[k - 1];
        if (k < 3)
            cut[n_cut++] = path[k + 1];
        CHECK(fs_cut_duplicate_node(&c, path[k], cut, n_cut) == 2);
        CHECK(fs_cut_update_adjacency(&c) == 0);
    }
    CHECK(m.n_nodes == 20 && m.n_tris == 18);
    for (int k = 0; k < 4; k++) { /* copies: parents (v, v), weight 0, at v's position */
        CHECK(c.node_parent[2 * k] == path[k] && c.node_parent[2 * k + 1] == path[k] && c.node_weight[k] == 0.0);
        CHECK(memcmp(m.pos + 3 * (16 + k), m.pos + 3 * path[k], 3 * sizeof *m.pos) == 0);
    }
    mesh_ok(&m);
    CHECK(mesh_components(&m) == 2);
    CHECK(mesh_euler(&m) == 2);
    CHECK(fs_mesh_count_boundary_edges(&m) == 18);
    CHECK_NEAR(mesh_area(&m), 9.0, 1e-12);
    /* the first sector (of the lowest triangle) keeps the node: the left piece keeps 1, 5, 9, 13 */
    for (int32_t t = 0; t < m.n_tris; t++)
        for (int q = 0; q < 3; q++)
            if (m.tri[3 * t + q] == 5) /* node 5 is only in triangles of the left squares (i = 0) */
                CHECK((t / 2) % 3 == 0);
    fs_cut_free(&c);
    fs_mesh_free(&m);
}

/* An interior slit: the middle node of a cut between two interior nodes splits in two, the ends keep
 * one fan (tips); the disc becomes an annulus (Euler characteristic 0) with two more border edges on
 * each side. */
static void test_interior_slit(void)
{
    fs_mesh m;
    grid_mesh(4, 4, false, &m); /* node (i, j) = 5 j + i */
    fs_cut c;
    fs_cut_begin(&c, &m, NULL, NULL);
    int32_t v = 12, ends[2] = {7, 17};
    CHECK(fs_cut_duplicate_node(&c, ends[0], &v, 1) == 1); /* a tip: its fan stays connected */
    CHECK(fs_cut_duplicate_node(&c, ends[1], &v, 1) == 1);
    CHECK(m.n_nodes == 25 && c.n_changed == 0);
    CHECK(fs_cut_duplicate_node(&c, v, ends, 2) == 2);
    CHECK(fs_cut_update_adjacency(&c) == 0);
    CHECK(m.n_nodes == 26 && m.n_tris == 32);
    mesh_ok(&m);
    CHECK(mesh_components(&m) == 1);
    CHECK(mesh_euler(&m) == 0);
    CHECK(fs_mesh_count_boundary_edges(&m) == 16 + 4);
    fs_cut_free(&c);
    fs_mesh_free(&m);
}

/* A split across the seam of a periodic grid: the new node is wrapped into the fundamental cell and
 * carried with a shift by the triangle beyond the seam; the torus stays a torus. */
static void test_split_across_seam(void)
{
    fs_mesh m;
    grid_mesh(4, 3, true, &m);
    fs_cut c;
    fs_cut_begin(&c, &m, NULL, NULL);
    /* triangle 6 = (3, 0+x, 4+x): its edge 1 runs along the seam x = 4 from (4, 0) to (4, 1) */
    CHECK(m.tri[18] == 3 && m.tri[19] == 0 && m.tri[20] == 4 && m.shift[6 * 6 + 2] == 1);
    int32_t i = fs_cut_split_edge(&c, 6, 1, 0.5);
    CHECK(m.pos[3 * i] == 0.0 && m.pos[3 * i + 1] == 0.5);
    CHECK(fs_cut_update_adjacency(&c) == 0);
    mesh_ok(&m);
    CHECK(mesh_euler(&m) == 0 && fs_mesh_count_boundary_edges(&m) == 0);
    CHECK_NEAR(mesh_area(&m), 12.0, 1e-12);
    for (int32_t t = 0; t < m.n_tris; t++) /* normalised: every first corner at shift (0, 0) */
        if (t >= 24 || t == 6 || t == 1)
            CHECK(m.shift[6 * t] == 0 && m.shift[6 * t + 1] == 0);
    double p[3];
    fs_mesh_corner(&m, 6, fs_mesh_corner_of(&m, 6, i), p);
    CHECK(p[0] == 4.0 && p[1] == 0.5); /* seen from triangle 6: beyond the seam */
    fs_cut_free(&c);
    fs_mesh_free(&m);
}

/* A model's own lookup is used instead of the scan (here: one that hides triangle 0, as a model
 * hides removed elements), and duplication follows it. */
static int32_t hide_first(void *ctx, const fs_cut *cut, int32_t node, int32_t **out, int32_t *cap)
{
    int *calls = ctx;
    (*calls)++;
    int32_t n = 0;
    for (int32_t t = 1; t < cut->mesh->n_tris; t++)
        if (fs_mesh_corner_of(cut->mesh, t, node) >= 0) {
            if (n == *cap) {
                *cap = *cap ? 2 * *cap : 8;
                *out = realloc(*out, (size_t)*cap * sizeof **out);
            }
            (*out)[n++] = t;
        }
    return n;
}

static void test_model_lookup(void)
{
    fs_mesh m;
    grid_mesh(3, 3, false, &m);
    fs_cut c;
    int calls = 0;
    fs_cut_begin(&c, &m, hide_first, &calls);
    int32_t *fan = NULL, cap = 0;
    CHECK(fs_cut_tris_at(&c, 5, &fan, &cap) == 5 && calls == 1); /* 6 around node 5, triangle 0 hidden */
    CHECK(fan[0] == 1);
    free(fan);
    fs_cut_free(&c);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_split_edge);
    RUN(test_cut_across);
    RUN(test_interior_slit);
    RUN(test_split_across_seam);
    RUN(test_model_lookup);
    return check_finish();
}
