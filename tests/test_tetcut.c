/* Tests of the crack surgery of tetrahedral meshes (geom/tetcut): the paper's split counts, snapping, and valid meshes after every cut. */
#include <math.h>
#include <string.h>

#include "base/rng.h"
#include "base/vec.h"
#include "check.h"
#include "geom/sample.h"
#include "geom/tetcut.h"
#include "geom/tetmesh.h"

/* Two tetrahedra sharing the face (a, b, c) = nodes 1, 2, 3; node 0 above it, node 4 below. */
static void two_tets(fs_tetmesh *m)
{
    memset(m, 0, sizeof *m);
    m->domain = fs_domain_default();
    const double p[5][3] = {{0.2, 0.3, 1.0}, {0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.3, 0.3, -1.0}};
    for (int i = 0; i < 5; i++)
        fs_tetmesh_add_node(m, p[i], 0.5);
    int32_t t0[4] = {1, 2, 3, 0}, t1[4] = {1, 3, 2, 4};
    fs_tetmesh_add_tet(m, t0, NULL);
    fs_tetmesh_add_tet(m, t1, NULL);
    fs_tetmesh_build_node_tets(m);
}

static void check_valid(const fs_tetmesh *m, int32_t components, int64_t euler)
{
    fs_tetmesh_report r;
    CHECK(fs_tetmesh_check(m, &r) == 0);
    CHECK_MSG(r.nonpositive == 0 && r.bad_faces == 0 && r.unused_nodes == 0, "%d %d %d", (int)r.nonpositive,
              (int)r.bad_faces, (int)r.unused_nodes);
    if (components >= 0)
        CHECK_MSG(r.components == components, "components %d, expected %d", (int)r.components, (int)components);
    if (euler >= 0)
        CHECK_MSG(r.euler == euler, "Euler characteristic %lld, expected %lld", (long long)r.euler,
                  (long long)euler);
}

static double total_volume(const fs_tetmesh *m)
{
    double v = 0.0;
    for (int32_t t = 0; t < m->n_tets; t++)
        v += fs_tetmesh_volume(m, t);
    return v;
}

static void test_face_split(void)
{
    fs_tetmesh m;
    two_tets(&m);
    double before = total_volume(&m);
    /* a plane through node 0 cutting edges 1-2 and 1-3 (the shared face) and nothing at node 4 */
    double n[3] = {1.0, 1.0, 0.0};
    fs_tetcut_params p = {0.01, 0.01};
    fs_tetcut_result r = {0};
    CHECK(fs_tetcut_node(&m, 0, n, &p, &r) == 1);
    CHECK_MSG(m.n_tets == 6, "%d tetrahedra", (int)m.n_tets);
    CHECK(m.n_nodes == 5 + 2 + 1); /* two on the cut edges, one copy of the split node */
    CHECK(r.node_minus == 7);
    CHECK_NEAR(total_volume(&m), before, 1e-12);
    check_valid(&m, 1, 1); /* a slit from the boundary: still one ball */
    /* the copies of node 0 take one side each */
    int plus = 0, minus = 0;
    for (int32_t t = 0; t < m.n_tets; t++)
        for (int c = 0; c < 4; c++) {
            plus += m.tet[4 * t + c] == 0;
            minus += m.tet[4 * t + c] == 7;
        }
    CHECK(plus >= 1 && minus >= 1 && plus + minus == 3);
    fs_tetcut_result_free(&r);
    fs_tetmesh_free(&m);
}

static void test_snap_to_edge(void)
{
    fs_tetmesh m;
    two_tets(&m);
    /* a plane through node 0 and (nearly) node 3: node 3 snaps onto it, one edge (1-2) is cut */
    double a[3] = {0.0 - 0.2, 1.0 - 0.3, 0.0 - 1.0}, up[3] = {0.0, 0.0, 1.0}, n[3];
    fs_cross3(n, a, up);
    n[0] += 1e-4; /* off by a little: within the snapping distance of node 3 */
    fs_tetcut_params p = {0.01, 0.01};
    fs_tetcut_result r = {0};
    CHECK(fs_tetcut_node(&m, 0, n, &p, &r) == 1);
    CHECK_MSG(m.n_tets == 4, "%d tetrahedra", (int)m.n_tets);
    CHECK(m.n_nodes == 5 + 1 + 1);
    check_valid(&m, 1, 1);
    fs_tetcut_result_free(&r);
    fs_tetmesh_free(&m);
    /* without the thresholds the crossing next to node 3 (within a fifth of edge 1-3) still snaps */
    two_tets(&m);
    fs_tetcut_params none = {0.0, 0.0};
    CHECK(fs_tetcut_node(&m, 0, n, &none, &r) == 1);
    CHECK_MSG(m.n_tets == 4, "%d tetrahedra", (int)m.n_tets);
    check_valid(&m, 1, 1);
    fs_tetcut_result_free(&r);
    fs_tetmesh_free(&m);
}

static void test_no_cut(void)
{
    fs_tetmesh m;
    two_tets(&m);
    /* a plane through node 0 with the whole element on one side */
    double n[3] = {0.0, 0.0, 1.0};
    fs_tetcut_params p = {0.01, 0.01};
    fs_tetcut_result r = {0};
    CHECK(fs_tetcut_node(&m, 0, n, &p, &r) == 0);
    CHECK(m.n_tets == 2 && m.n_nodes == 5);
    double zero[3] = {0, 0, 0};
    CHECK(fs_tetcut_node(&m, 0, zero, &p, &r) == -1);
    fs_tetcut_result_free(&r);
    fs_tetmesh_free(&m);
}

/* Random cuts through a layer: a valid mesh after each, volume kept; cuts through the whole layer
 * make pieces. */
static void test_random_cuts(bool periodic)
{
    fs_domain d = fs_domain_default();
    d.width = d.height = 4.0;
    d.periodic_x = d.periodic_y = periodic;
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = 150;
    sp.seed = 3;
    fs_points pts = {0};
    CHECK(fs_sample_repulsion(&d, &sp, &pts) == 0);
    fs_tetlayer_params lp = fs_tetlayer_params_default();
    lp.thickness = 0.5;
    lp.layers = 2;
    fs_tetmesh m;
    CHECK(fs_tetmesh_layer(&d, &pts, &lp, &m) == 0);
    fs_points_free(&pts);
    fs_tetmesh_build_node_tets(&m);
    double before = total_volume(&m);
    fs_tetcut_params p = {0.03, 0.1};
    fs_tetcut_result r = {0};
    int splits = 0;
    for (int k = 0; k < 60; k++) {
        int32_t node = (int32_t)(fs_rand01(9, FS_RNG_TEST, (uint64_t)k) * m.n_nodes);
        double n[3] = {fs_rand_normal(9, FS_RNG_TEST, 100 + 3 * k), fs_rand_normal(9, FS_RNG_TEST, 101 + 3 * k),
                       0.2 * fs_rand_normal(9, FS_RNG_TEST, 102 + 3 * k)};
        int rc = fs_tetcut_node(&m, node, n, &p, &r);
        CHECK(rc >= 0);
        splits += rc;
        fs_tetmesh_report rep;
        CHECK(fs_tetmesh_check(&m, &rep) == 0);
        CHECK(rep.nonpositive == 0 && rep.bad_faces == 0);
        /* the node lists agree with the tetrahedra */
        int64_t entries = 0;
        for (int32_t i = 0; i < m.n_nodes; i++)
            entries += m.node_tets[i].n;
        CHECK(entries == 4 * (int64_t)m.n_tets);
    }
    CHECK(splits > 30);
    CHECK_NEAR(total_volume(&m), before, 1e-9 * before);
    /* a straight cut across the whole layer along x = 2 splits off a piece on a plane that does not
     * wrap (on a torus it leaves one piece, cut once around) */
    fs_tetmesh_report rep;
    CHECK(fs_tetmesh_check(&m, &rep) == 0);
    int32_t pieces_before = rep.components;
    for (int round = 0; round < 3; round++) {
        int32_t n_nodes = m.n_nodes;
        for (int32_t i = 0; i < n_nodes; i++) {
            if (fabs(m.pos[3 * (size_t)i] - 2.0) < 0.15) {
                double n[3] = {1.0, 0.0, 0.0};
                fs_tetcut_params snap = {1e-6, 1e-6};
                CHECK(fs_tetcut_node(&m, i, n, &snap, &r) >= 0);
            }
        }
    }
    CHECK(fs_tetmesh_check(&m, &rep) == 0);
    CHECK(rep.nonpositive == 0 && rep.bad_faces == 0);
    CHECK_MSG(rep.components >= pieces_before + (periodic ? 0 : 1), "%d pieces, %d before", (int)rep.components,
              (int)pieces_before);
    fs_tetcut_result_free(&r);
    fs_tetmesh_free(&m);
}

static void test_random_cuts_plane(void)
{
    test_random_cuts(false);
}

static void test_random_cuts_periodic(void)
{
    test_random_cuts(true);
}

int main(void)
{
    RUN(test_face_split);
    RUN(test_snap_to_edge);
    RUN(test_no_cut);
    RUN(test_random_cuts_plane);
    RUN(test_random_cuts_periodic);
    return check_finish();
}
