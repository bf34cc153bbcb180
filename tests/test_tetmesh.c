/* Tests of the tetrahedral layer meshes (geom/tetmesh): valid tetrahedra, matched faces and seams, the layer's volume and topology. */
#include <math.h>
#include <string.h>

#include "base/vec.h"
#include "check.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "geom/tetmesh.h"

static int build(fs_domain d, int32_t per_layer, double h, int layers, fs_tetmesh *m)
{
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = per_layer;
    sp.seed = 5;
    fs_points pts = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0)
        return -1;
    fs_tetlayer_params p = fs_tetlayer_params_default();
    p.thickness = h;
    p.layers = layers;
    p.seed = 5;
    int rc = fs_tetmesh_layer(&d, &pts, &p, m);
    fs_points_free(&pts);
    return rc;
}

/* Every boundary face lies on the top or the bottom (all corners zeta 1, or all 0), or, where given,
 * on the sides that do not wrap (each corner on a side: the sampler leaves corners of the rectangle
 * open, and the hull cuts them by faces across two sides). */
static int32_t faces_off_surfaces(const fs_tetmesh *m, bool sides_allowed)
{
    int32_t *adj = malloc((4 * (size_t)m->n_tets + 1) * sizeof *adj);
    fs_tetmesh_adjacency(m, adj);
    int32_t off = 0;
    double ex = fs_domain_extent_x(&m->domain), ey = fs_domain_extent_y(&m->domain);
    for (int32_t h = 0; h < 4 * m->n_tets; h++) {
        if (adj[h] >= 0)
            continue;
        const int *f = fs_tet_face[h % 4];
        int top = 0, bottom = 0, side = 0;
        for (int k = 0; k < 3; k++) {
            int32_t v = m->tet[4 * (size_t)(h / 4) + f[k]];
            const double *p = m->pos + 3 * (size_t)v;
            top += m->zeta[v] == 1.0;
            bottom += m->zeta[v] == 0.0;
            side += p[0] == 0.0 || p[0] == ex || p[1] == 0.0 || p[1] == ey;
        }
        off += !(top == 3 || bottom == 3 || (sides_allowed && side == 3));
    }
    free(adj);
    return off;
}

static void test_periodic_slab(void)
{
    fs_domain d = fs_domain_default();
    d.width = 6;
    d.height = 4;
    d.periodic_x = d.periodic_y = true;
    fs_tetmesh m;
    CHECK(build(d, 400, 0.5, 2, &m) == 0);
    fs_tetmesh_report r;
    CHECK(fs_tetmesh_check(&m, &r) == 0);
    CHECK(r.nonpositive == 0 && r.bad_faces == 0 && r.unused_nodes == 0);
    CHECK_NEAR(r.volume, 6.0 * 4.0 * 0.5, 1e-9 * 12.0);
    CHECK(r.components == 1);
    CHECK(r.euler == 0); /* a torus times an interval */
    CHECK(faces_off_surfaces(&m, false) == 0); /* the seams are matched: no boundary there */
    /* top and bottom are covered once each: their boundary faces' projected areas add up */
    int32_t *adj = malloc(4 * (size_t)m.n_tets * sizeof *adj);
    fs_tetmesh_adjacency(&m, adj);
    double top = 0.0, bottom = 0.0;
    int seam = 0;
    for (int32_t h = 0; h < 4 * m.n_tets; h++) {
        if (adj[h] >= 0)
            continue;
        double x[12], e1[3], e2[3], n[3];
        fs_tetmesh_corners(&m, h / 4, x);
        const int *f = fs_tet_face[h % 4];
        fs_sub3(e1, x + 3 * f[1], x + 3 * f[0]);
        fs_sub3(e2, x + 3 * f[2], x + 3 * f[0]);
        fs_cross3(n, e1, e2);
        if (n[2] > 0.0)
            top += 0.5 * n[2];
        else
            bottom -= 0.5 * n[2];
    }
    for (int32_t t = 0; t < m.n_tets; t++)
        for (int c = 0; c < 8; c++)
            seam += m.shift[8 * (size_t)t + c] != 0;
    free(adj);
    CHECK_NEAR(top, 24.0, 1e-9 * 24.0);
    CHECK_NEAR(bottom, 24.0, 1e-9 * 24.0);
    CHECK(seam > 0); /* tetrahedra do straddle the seams */
    fs_tetmesh_free(&m);
}

static void test_plane(void)
{
    fs_domain d = fs_domain_default();
    d.width = 5;
    d.height = 5;
    fs_tetmesh m;
    CHECK(build(d, 300, 0.6, 3, &m) == 0);
    fs_tetmesh_report r;
    CHECK(fs_tetmesh_check(&m, &r) == 0);
    CHECK(r.components == 1);
    CHECK(r.euler == 1); /* a ball */
    CHECK(faces_off_surfaces(&m, true) == 0);
    /* the hull of the sampled sides: the box, up to the corners the sampler leaves open */
    CHECK(r.volume <= 5.0 * 5.0 * 0.6 * (1.0 + 1e-12) && r.volume > 0.99 * 15.0);
    CHECK(m.n_nodes == 4 * 300);
    fs_tetmesh_free(&m);
}

static void test_cylinder(void)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_CYLINDER;
    d.radius = 1.5;
    d.height = 6;
    d.periodic_y = true;
    fs_tetmesh m;
    CHECK(build(d, 400, 0.4, 2, &m) == 0);
    fs_tetmesh_report r;
    CHECK(fs_tetmesh_check(&m, &r) == 0);
    CHECK_NEAR(r.volume, 2.0 * FS_PI * 1.5 * 6.0 * 0.4, 1e-9 * 25.0);
    CHECK(r.euler == 0);
    CHECK(faces_off_surfaces(&m, false) == 0);
    fs_tetmesh_free(&m);
    /* not wrapping along the axis: the ends are sides */
    d.periodic_y = false;
    CHECK(build(d, 400, 0.4, 2, &m) == 0);
    CHECK(fs_tetmesh_check(&m, &r) == 0);
    CHECK(r.euler == 0); /* an annulus times an interval */
    CHECK(faces_off_surfaces(&m, true) == 0);
    fs_tetmesh_free(&m);
}

static void test_sphere(void)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_SPHERE;
    d.radius = 2.0;
    fs_tetmesh m;
    CHECK(build(d, 500, 0.3, 2, &m) == 0);
    fs_tetmesh_report r;
    CHECK(fs_tetmesh_check(&m, &r) == 0);
    CHECK(r.components == 1);
    CHECK(r.euler == 2); /* a sphere times an interval */
    CHECK(faces_off_surfaces(&m, false) == 0);
    /* the shell between two inscribed polyhedra: a little less than the true shell */
    double shell = 4.0 / 3.0 * FS_PI * (pow(2.3, 3.0) - pow(2.0, 3.0));
    CHECK(r.volume < shell && r.volume > 0.97 * shell);
    fs_tetmesh_free(&m);
}

/* Periodic 3-D Delaunay of a small lattice-free set: every copy kept once, whatever the margin. */
static void test_delaunay_tets(void)
{
    fs_domain d = fs_domain_default();
    d.width = d.height = 3.0;
    d.periodic_x = d.periodic_y = true;
    fs_tetmesh a, b;
    CHECK(build(d, 60, 0.8, 2, &a) == 0);
    fs_tets wide;
    double period[2] = {3.0, 3.0};
    /* the mesher's node positions are the Delaunay's (true heights taken back): compare counts with a
     * run at a margin of a whole period */
    double *iso = malloc(3 * (size_t)a.n_nodes * sizeof *iso);
    memcpy(iso, a.pos, 3 * (size_t)a.n_nodes * sizeof *iso);
    CHECK(fs_delaunay_tets(iso, a.n_nodes, period, 3.0, false, &wide) == 0);
    double vol = 0.0;
    for (int32_t t = 0; t < wide.n_tets; t++) {
        double x[12];
        for (int c = 0; c < 4; c++)
            for (int k = 0; k < 3; k++)
                x[3 * c + k] = iso[3 * (size_t)wide.tet[4 * t + c] + k] + (k < 2 ? wide.shift[8 * t + 2 * c + k] * 3.0 : 0.0);
        double v = fs_tet_volume(x);
        CHECK(v >= 0.0);
        vol += v;
    }
    CHECK_NEAR(vol, 9.0 * 0.8, 1e-9 * 7.2);
    fs_tets_free(&wide);
    free(iso);
    (void)b;
    fs_tetmesh_free(&a);
    /* too few points */
    fs_tets none;
    double p[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    double zero[2] = {0, 0};
    CHECK(fs_delaunay_tets(p, 3, zero, 0.0, false, &none) == -1);
}

int main(void)
{
    RUN(test_periodic_slab);
    RUN(test_plane);
    RUN(test_cylinder);
    RUN(test_sphere);
    RUN(test_delaunay_tets);
    return check_finish();
}
