/* Tests of the tetrahedral model's finite elements (model/tet): rigid modes, patch test, a bonded layer's stress, a free bilayer's curvature. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/rng.h"
#include "base/vec.h"
#include "check.h"
#include "dense.h"
#include "fracture/eigen.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "geom/tetmesh.h"
#include "model/tet/element.h"
#include "model/tet/internal.h"

static void random_tet(uint64_t k, double x[12])
{
    do {
        for (int c = 0; c < 12; c++)
            x[c] = fs_rand_range(11, FS_RNG_TEST, 12 * k + c, -1.0, 1.0);
        if (fs_tet_volume(x) < 0.0) {
            for (int d = 0; d < 3; d++) {
                double tmp = x[6 + d];
                x[6 + d] = x[9 + d];
                x[9 + d] = tmp;
            }
        }
        k += 1000;
    } while (fs_tet_quality(x) < 0.2);
}

/* A free tetrahedron's stiffness has exactly six zero eigenvalues: three translations and three
 * (infinitesimal) rotations. */
static void test_rigid_modes(void)
{
    double lambda, mu;
    CHECK(fs_tet_lame(10.0, 0.3, &lambda, &mu) == 0);
    CHECK_NEAR(mu, 10.0 / 2.6, 1e-12);
    CHECK_NEAR(lambda, 3.0 / (1.3 * 0.4), 1e-12);
    CHECK(fs_tet_lame(10.0, 0.5, &lambda, &mu) == -1);
    for (uint64_t k = 0; k < 20; k++) {
        double x[12], g[12], vol, K[144], w[12];
        random_tet(k, x);
        CHECK(fs_tet_gradients(x, g, &vol) == 0);
        CHECK_NEAR(vol, fs_tet_volume(x), 1e-14);
        fs_tet_stiffness(g, vol, lambda, mu, K);
        double scale = 0.0;
        for (int i = 0; i < 144; i++)
            scale = fmax(scale, fabs(K[i]));
        jacobi_eigenvalues(K, 12, w);
        int zero = 0, positive = 0;
        for (int i = 0; i < 12; i++) {
            zero += fabs(w[i]) < 1e-10 * scale;
            positive += w[i] > 1e-6 * scale;
        }
        CHECK_MSG(zero == 6 && positive == 6, "%d zero and %d positive eigenvalues", zero, positive);
    }
    /* an inverted element is refused */
    double x[12] = {0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 1, 0}, g[12], vol;
    CHECK(fs_tet_gradients(x, g, &vol) == -1 && vol < 0.0);
}

/* A rigid rotation (small: u = w x r) strains nothing and exerts no force; a linear field is
 * reproduced exactly (the element's own patch test). */
static void test_rotation_and_linear_field(void)
{
    double lambda, mu;
    fs_tet_lame(7.0, 0.25, &lambda, &mu);
    for (uint64_t k = 0; k < 20; k++) {
        double x[12], g[12], vol, u[12], eps[6], sig[6], f[12];
        random_tet(100 + k, x);
        fs_tet_gradients(x, g, &vol);
        double w[3] = {0.3, -0.2, 0.5}, t[3] = {1.0, 2.0, -1.0};
        for (int c = 0; c < 4; c++) {
            double r[3];
            fs_cross3(r, w, x + 3 * c);
            for (int d = 0; d < 3; d++)
                u[3 * c + d] = r[d] + t[d];
        }
        fs_tet_strain(g, u, eps);
        fs_tet_stress(lambda, mu, eps, sig);
        fs_tet_forces(g, vol, sig, f);
        double m = 0.0;
        for (int i = 0; i < 12; i++)
            m = fmax(m, fabs(f[i]));
        for (int i = 0; i < 6; i++)
            m = fmax(m, fabs(eps[i]));
        CHECK(m < 1e-13);
        /* u = A x: strain sym(A), engineering shears */
        double A[9] = {0.01, 0.002, -0.003, 0.004, -0.02, 0.001, 0.0, 0.005, 0.015};
        for (int c = 0; c < 4; c++)
            for (int d = 0; d < 3; d++)
                u[3 * c + d] = A[3 * d] * x[3 * c] + A[3 * d + 1] * x[3 * c + 1] + A[3 * d + 2] * x[3 * c + 2];
        fs_tet_strain(g, u, eps);
        CHECK_NEAR(eps[0], 0.01, 1e-14);
        CHECK_NEAR(eps[1], -0.02, 1e-14);
        CHECK_NEAR(eps[2], 0.015, 1e-14);
        CHECK_NEAR(eps[3], 0.006, 1e-14);
        CHECK_NEAR(eps[4], 0.006, 1e-14);
        CHECK_NEAR(eps[5], -0.003, 1e-14);
        /* the element's forces balance (no net force, no net moment) */
        fs_tet_stress(lambda, mu, eps, sig);
        fs_tet_forces(g, vol, sig, f);
        double net[3] = {0, 0, 0}, mom[3] = {0, 0, 0};
        for (int c = 0; c < 4; c++) {
            double r[3];
            fs_cross3(r, x + 3 * c, f + 3 * c);
            for (int d = 0; d < 3; d++) {
                net[d] += f[3 * c + d];
                mom[d] += r[d];
            }
        }
        CHECK(fs_norm3(net) < 1e-14 && fs_norm3(mom) < 1e-14);
    }
}

/* A small layer mesh of a plane (plain or periodic), count points per layer. */
static int layer_mesh(double w, double h, int layers, int32_t count, bool periodic, fs_tetmesh *m)
{
    fs_domain d = fs_domain_default();
    d.width = d.height = w;
    d.periodic_x = d.periodic_y = periodic;
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = count;
    sp.seed = 7;
    fs_points pts = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0)
        return -1;
    fs_tetlayer_params lp = fs_tetlayer_params_default();
    lp.thickness = h;
    lp.layers = layers;
    lp.seed = 7;
    int rc = fs_tetmesh_layer(&d, &pts, &lp, m);
    fs_points_free(&pts);
    return rc;
}

static fs_model_setup setup_for(double young, double poisson)
{
    fs_model_setup c = fs_model_setup_default();
    c.kind = FS_MODEL_TET;
    c.material.young = young;
    c.material.poisson = poisson;
    c.material.threshold = 1e9; /* no fracture here */
    c.material.jitter = 0.0;
    c.time.end = 1.0;
    return c;
}

/* The patch test on a mesh: every boundary node held at u = A X, the interior solved, every node
 * lands on the linear field and every element carries the same stress. */
static void test_patch(void)
{
    fs_tetmesh m;
    CHECK(layer_mesh(2.0, 0.8, 3, 60, false, &m) == 0);
    fs_model_setup cfg = setup_for(5.0, 0.3);
    cfg.growth.type = FS_GROWTH_NONE;
    fs_tet s;
    memset(&s, 0, sizeof s);
    CHECK(fs_tet_init(&s, &m, &cfg, false) == 0);
    /* one load: the boundary moved by A X */
    const double A[9] = {0.01, 0.002, -0.003, 0.004, -0.02, 0.001, 0.0, 0.005, 0.015};
    s.n_loads = 1;
    s.load[0] = (fs_tet_load){.kind = FS_TET_MOVE};
    memcpy(s.load[0].move, A, sizeof A);
    fs_tet_grow(&s);
    int32_t *adj = malloc(4 * (size_t)s.mesh.n_tets * sizeof *adj);
    fs_tetmesh_adjacency(&s.mesh, adj);
    int32_t boundary = 0;
    for (int32_t h = 0; h < 4 * s.mesh.n_tets; h++)
        if (adj[h] < 0)
            for (int k = 0; k < 3; k++) {
                int32_t v = s.mesh.tet[4 * (size_t)(h / 4) + fs_tet_face[h % 4][k]];
                boundary += !s.bonded[v];
                s.bonded[v] = 1;
            }
    free(adj);
    for (int32_t t = 0; t < s.mesh.n_tets; t++)
        memset(s.eps0 + 6 * (size_t)t, 0, 6 * sizeof(double));
    s.n_free = 0;
    for (int32_t i = 0; i < 3 * s.mesh.n_nodes; i++)
        s.dof[i] = -1;
    fs_tet_number_dofs(&s);
    CHECK(boundary > 0 && s.n_free > 0); /* some nodes are inside */
    CHECK(fs_tet_solve_global(&s) == 0);
    double worst = 0.0, c = 1.0;
    for (int32_t i = 0; i < s.mesh.n_nodes; i++) {
        const double *p = s.mesh.pos + 3 * (size_t)i;
        double u[3];
        fs_tet_displacement(&s, i, &c, u);
        for (int d = 0; d < 3; d++)
            worst = fmax(worst, fabs(u[d] - (A[3 * d] * p[0] + A[3 * d + 1] * p[1] + A[3 * d + 2] * p[2])));
    }
    CHECK_MSG(worst < 1e-9, "largest departure from the linear field %g cm", worst);
    double eps[6] = {0.01, -0.02, 0.015, 0.006, 0.006, -0.003}, want[6], got[6];
    fs_tet_stress(s.lambda[0], s.mu[0], eps, want);
    double sw = 0.0;
    for (int32_t t = 0; t < s.mesh.n_tets; t++) {
        fs_tet_stress_at(&s, t, &c, got);
        for (int q = 0; q < 6; q++)
            sw = fmax(sw, fabs(got[q] - want[q]));
    }
    CHECK_MSG(sw < 1e-8, "largest stress departure %g MPa", sw);
    fs_tet_free(&s);
}

/* A layer bonded to a rigid substrate with an isotropic mismatch eps (both surfaces shrink by eps)
 * carries sigma = E eps / (1 - nu) in its plane and nothing across it (SPEC §9). */
static void test_bonded_layer(void)
{
    fs_tetmesh m;
    CHECK(layer_mesh(3.0, 0.6, 2, 150, true, &m) == 0);
    fs_model_setup cfg = setup_for(10.0, 0.3);
    const double eps = 0.004;
    cfg.shrink.top = (fs_pwl){2, {0.0, 1.0}, {0.0, eps}};
    cfg.shrink.bottom = (fs_pwl){2, {0.0, 1.0}, {0.0, eps}};
    fs_tet s;
    memset(&s, 0, sizeof s);
    CHECK(fs_tet_init(&s, &m, &cfg, true) == 0);
    CHECK(s.n_loads == 2 && s.proportional);
    double c[FS_TET_LOADS], want = 10.0 * eps / (1.0 - 0.3), worst = 0.0;
    fs_tet_coefficients(&s, 1.0, c);
    for (int32_t t = 0; t < s.mesh.n_tets; t++) {
        double sig[6];
        fs_tet_stress_at(&s, t, c, sig);
        worst = fmax(worst, fmax(fabs(sig[0] - want), fabs(sig[1] - want)) / want);
        worst = fmax(worst, fmax(fabs(sig[2]), fmax(fabs(sig[3]), fmax(fabs(sig[4]), fabs(sig[5])))) / want);
    }
    CHECK_MSG(worst < 0.01, "largest relative departure from E eps / (1 - nu): %g", worst);
    /* half-way, half the stress (the loads are linear in time) */
    fs_tet_coefficients(&s, 0.5, c);
    double sig[6];
    fs_tet_stress_at(&s, 0, c, sig);
    CHECK_NEAR(sig[0], 0.5 * want, 0.01 * want);
    fs_tet_free(&s);
}

/* Curvature of a free bilayer: the top half shrunk by d relative to the bottom half; a quadratic
 * fitted to the mid-plane's deflection over the middle of the plate. */
static double bilayer_curvature(int layers, int32_t count, double h, double w, double d)
{
    fs_tetmesh m;
    if (layer_mesh(w, h, layers, count, false, &m) < 0)
        return NAN;
    fs_model_setup cfg = setup_for(10.0, 0.3);
    cfg.shrink.top = (fs_pwl){2, {0.0, 1.0}, {d, d}};
    fs_tet s;
    memset(&s, 0, sizeof s);
    if (fs_tet_init(&s, &m, &cfg, false) < 0)
        return NAN;
    /* the load's eigenstrain replaced by the bilayer's: -d in the plane of the top half */
    for (int32_t t = 0; t < s.mesh.n_tets; t++) {
        double zeta = 0.0;
        for (int c = 0; c < 4; c++)
            zeta += 0.25 * s.mesh.zeta[s.mesh.tet[4 * (size_t)t + c]];
        double *e0 = s.eps0 + 6 * (size_t)t;
        memset(e0, 0, 6 * sizeof *e0);
        if (zeta > 0.5)
            e0[0] = e0[1] = -1.0;
    }
    if (fs_tet_solve_global(&s) < 0)
        return NAN;
    /* least squares: w = a + b x + c y + e x^2 + f y^2 + g x y over mid-plane nodes near the middle */
    double N[6][7] = {{0}};
    double coef = d;
    for (int32_t i = 0; i < s.mesh.n_nodes; i++) {
        const double *p = s.mesh.pos + 3 * (size_t)i;
        double x = p[0] - 0.5 * w, y = p[1] - 0.5 * w;
        if (s.mesh.zeta[i] != 0.5 || fabs(x) > 0.25 * w || fabs(y) > 0.25 * w)
            continue;
        double u[3];
        fs_tet_displacement(&s, i, &coef, u);
        double row[7] = {1.0, x, y, x * x, y * y, x * y, u[2]};
        for (int a = 0; a < 6; a++)
            for (int b = 0; b < 7; b++)
                N[a][b] += row[a] * row[b];
    }
    for (int a = 0; a < 6; a++) { /* Gauss-Jordan */
        int piv = a;
        for (int r = a + 1; r < 6; r++)
            if (fabs(N[r][a]) > fabs(N[piv][a]))
                piv = r;
        for (int b = 0; b < 7; b++) {
            double tmp = N[a][b];
            N[a][b] = N[piv][b];
            N[piv][b] = tmp;
        }
        for (int r = 0; r < 6; r++) {
            if (r == a)
                continue;
            double f = N[r][a] / N[a][a];
            for (int b = 0; b < 7; b++)
                N[r][b] -= f * N[a][b];
        }
    }
    double kx = 2.0 * N[3][6] / N[3][3], ky = 2.0 * N[4][6] / N[4][4];
    fs_tet_free(&s);
    return 0.5 * (kx + ky);
}

/* Timoshenko: equal thicknesses and moduli, mismatch d, total thickness h: kappa = 3 d / (2 h). */
static void test_bilayer(void)
{
    const double h = 1.0, w = 4.0, d = 0.01, want = 3.0 * d / (2.0 * h);
    double coarse = bilayer_curvature(2, 80, h, w, d);
    double medium = bilayer_curvature(4, 256, h, w, d);
    double fine = bilayer_curvature(8, 1024, h, w, d);
    double ec = fabs(coarse - want) / want, em = fabs(medium - want) / want, ef = fabs(fine - want) / want;
    printf("bilayer curvature: %.5f, %.5f, %.5f per cm against %.5f (errors %.1f %%, %.1f %%, %.1f %%)\n", coarse,
           medium, fine, want, 100 * ec, 100 * em, 100 * ef);
    CHECK(ef < 0.05);
    CHECK(em < ec && ef < em);
}

static int cmp_edge(const void *a, const void *b)
{
    const int64_t *x = a, *y = b;
    return (*x > *y) - (*x < *y);
}

/* The closed pieces of a cracked layer: every edge of the solid is used as often one way as the other
 * (closed and consistently oriented), and the pieces enclose the layer's volume. */
static void check_solid_closed(const fs_tet *s)
{
    fs_solid solid = {0};
    CHECK(fs_tet_solid(s, &solid) == 0);
    CHECK(solid.n_tris > 0);
    int64_t *e = malloc((3 * (size_t)solid.n_tris + 1) * sizeof *e);
    for (int32_t f = 0; f < solid.n_tris; f++)
        for (int k = 0; k < 3; k++) {
            int64_t a = solid.tri[3 * f + k], b = solid.tri[3 * f + (k + 1) % 3];
            e[3 * f + k] = a * 2 * (int64_t)solid.n_pos + b;
        }
    qsort(e, 3 * (size_t)solid.n_tris, sizeof *e, cmp_edge);
    /* each directed edge as often as its opposite (twice each way where a crack pinches a piece
     * along an edge it did not cut) */
    int32_t unmatched = 0, n_e = 3 * solid.n_tris;
    for (int32_t q = 0; q < n_e;) {
        int32_t r = q;
        while (r < n_e && e[r] == e[q])
            r++;
        int64_t a = e[q] / (2 * (int64_t)solid.n_pos), b = e[q] % (2 * (int64_t)solid.n_pos);
        int64_t back = b * 2 * (int64_t)solid.n_pos + a;
        int64_t *hit = bsearch(&back, e, (size_t)n_e, sizeof *e, cmp_edge);
        int32_t opposite = 0;
        if (hit) {
            int64_t *lo = hit, *hi = hit;
            while (lo > e && lo[-1] == back)
                lo--;
            while (hi + 1 < e + n_e && hi[1] == back)
                hi++;
            opposite = (int32_t)(hi - lo + 1);
        }
        unmatched += opposite != r - q;
        q = r;
    }
    free(e);
    CHECK_MSG(unmatched == 0, "%d directed edges not matched by as many opposite ones", (int)unmatched);
    /* the enclosed volume (divergence theorem) is the layer's, up to the displacements */
    double vol = 0.0, want = 0.0;
    for (int32_t f = 0; f < solid.n_tris; f++) {
        const double *a = solid.pos + 3 * (size_t)solid.tri[3 * f], *b = solid.pos + 3 * (size_t)solid.tri[3 * f + 1],
                     *c = solid.pos + 3 * (size_t)solid.tri[3 * f + 2];
        double cr[3];
        fs_cross3(cr, b, c);
        vol += fs_dot3(a, cr) / 6.0;
    }
    for (int32_t t = 0; t < s->mesh.n_tets; t++)
        want += s->vol[t];
    CHECK_MSG(fabs(vol - want) < 0.02 * want, "pieces enclose %g cm^3, the layer has %g", vol, want);
    fs_solid_free(&solid);
}

/* Whether a boundary face with corners v is inside the strip of test_strip_breaks_across (not its
 * top, bottom or sides): a crack wall. */
static bool strip_inside(const fs_tet *s, const int32_t v[3])
{
    int inside = 0;
    for (int k = 0; k < 3; k++) {
        const double *p = s->mesh.pos + 3 * (size_t)v[k];
        inside += s->mesh.zeta[v[k]] > 0.0 && s->mesh.zeta[v[k]] < 1.0 && p[0] > 0.0 && p[0] < 6.0 && p[1] > 0.0 &&
                  p[1] < 2.0;
    }
    return inside > 0;
}

/* Whether a boundary face with corners v is neither on the layer's top nor on its bottom (on a domain
 * without sides: a crack wall). */
static bool off_top_and_bottom(const fs_tet *s, const int32_t v[3])
{
    return !(s->mesh.zeta[v[0]] == s->mesh.zeta[v[1]] && s->mesh.zeta[v[1]] == s->mesh.zeta[v[2]]);
}

/* The mean orientation of the crack walls (the boundary faces is_wall accepts): the principal axis
 * of the area-weighted sum of n n^T over them, into dir; false when there are none. */
static bool wall_direction(const fs_tet *s, bool (*is_wall)(const fs_tet *, const int32_t[3]), double dir[3])
{
    int32_t *adj = malloc((4 * (size_t)s->mesh.n_tets + 1) * sizeof *adj);
    fs_tetmesh_adjacency(&s->mesh, adj);
    double nn[9] = {0}, area = 0.0;
    for (int32_t h = 0; h < 4 * s->mesh.n_tets; h++) {
        if (adj[h] >= 0)
            continue;
        const int *f = fs_tet_face[h % 4];
        int32_t v[3];
        for (int k = 0; k < 3; k++)
            v[k] = s->mesh.tet[4 * (size_t)(h / 4) + f[k]];
        if (!is_wall(s, v))
            continue;
        double x[12], e1[3], e2[3], n[3];
        fs_tetmesh_corners(&s->mesh, h / 4, x);
        fs_sub3(e1, x + 3 * f[1], x + 3 * f[0]);
        fs_sub3(e2, x + 3 * f[2], x + 3 * f[0]);
        fs_cross3(n, e1, e2);
        double a = fs_norm3(n);
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                nn[3 * i + j] += n[i] * n[j] / a;
        area += a;
    }
    free(adj);
    if (!(area > 0.0))
        return false;
    double val[3], vec[9];
    fs_eigen_sym3(nn, val, vec);
    memcpy(dir, vec, 3 * sizeof *dir);
    return true;
}

/* Meshes domain d (count points from sample_seed) and runs the tet model of cfg on it to t = 1 (at
 * most cfg->tet.max_events events); at least 10 nodes must split. Returns the model (its mesh in
 * *mesh), or NULL. */
static fs_tet *grow_cracks(fs_domain d, uint64_t sample_seed, const fs_model_setup *cfg, fs_mesh *mesh)
{
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = 300;
    sp.seed = sample_seed;
    fs_points pts = {0};
    CHECK(fs_sample_repulsion(&d, &sp, &pts) == 0 && fs_delaunay(&d, &pts, mesh) == 0);
    fs_points_free(&pts);
    fs_tet *s = fs_tet_create(mesh, cfg);
    CHECK(s != NULL);
    if (!s) {
        fs_mesh_free(mesh);
        return NULL;
    }
    CHECK(fs_tet_advance(s, 1.0) == 0);
    CHECK(s->counters.splits > 10);
    return s;
}

/* The angle (degrees) between the mean orientation of the crack walls that is_wall keeps and the
 * x axis (90 when there are none). */
static double wall_angle_to_x(const fs_tet *s, bool (*is_wall)(const fs_tet *, const int32_t *))
{
    double vec[3];
    bool found = wall_direction(s, is_wall, vec);
    CHECK(found);
    return found ? acos(fmin(fabs(vec[0]), 1.0)) * 180.0 / FS_PI : 90.0;
}

/* A strip bonded to a substrate stretched along x breaks across the stretch: the walls of its cracks
 * face along x (their mean orientation, the principal axis of the area-weighted sum of n n^T, within 5
 * degrees: single faces zigzag where the cut snapped to existing nodes). */
static void test_strip_breaks_across(void)
{
    fs_domain d = fs_domain_default();
    d.width = 6.0;
    d.height = 2.0;
    fs_model_setup cfg = setup_for(10.0, 0.3);
    cfg.seed = 4;
    cfg.material.threshold = 50.0;
    cfg.material.thickness = 0.3;
    cfg.growth.type = FS_GROWTH_PLANAR;
    cfg.growth.r1 = 0.02;
    cfg.growth.r2 = 0.0;
    cfg.growth.angle = 0.0;
    cfg.time.min_step = 1e-3;
    cfg.tet.max_events = 40;
    fs_mesh mesh = {0};
    fs_tet *s = grow_cracks(d, 3, &cfg, &mesh);
    if (!s)
        return;
    double angle = wall_angle_to_x(s, strip_inside);
    printf("strip: %lld splits, crack walls %.2f degrees off the stretch's normal plane on average\n",
           (long long)s->counters.splits, angle);
    CHECK(angle < 5.0);
    check_solid_closed(s);
    fs_tet_destroy(s);
    fs_mesh_free(&mesh);
}

/* Bark: a layer on a trunk that grows in girth only (cylinder growth, periodic along the axis) is
 * stretched around the trunk, so it splits along the axis: the crack walls face around the trunk (x
 * in the unrolled layer), their mean orientation within 20 degrees of it. */
static void test_bark_cracks_along_axis(void)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_CYLINDER;
    d.radius = 1.0;
    d.height = 6.0;
    d.periodic_y = true;
    fs_model_setup cfg = setup_for(10.0, 0.3);
    cfg.seed = 6;
    cfg.material.threshold = 50.0;
    cfg.material.thickness = 0.3;
    cfg.growth.type = FS_GROWTH_CYLINDER;
    cfg.growth.rate = 0.02;
    cfg.time.min_step = 1e-3;
    cfg.tet.max_events = 40;
    fs_mesh mesh = {0};
    fs_tet *s = grow_cracks(d, 5, &cfg, &mesh);
    if (!s)
        return;
    double angle = wall_angle_to_x(s, off_top_and_bottom);
    printf("bark: %lld splits, crack walls %.2f degrees off the plane across the trunk's circumference\n",
           (long long)s->counters.splits, angle);
    CHECK(angle < 20.0);
    fs_tet_destroy(s);
    fs_mesh_free(&mesh);
}

int main(void)
{
    RUN(test_rigid_modes);
    RUN(test_rotation_and_linear_field);
    RUN(test_patch);
    RUN(test_bonded_layer);
    RUN(test_bilayer);
    RUN(test_strip_breaks_across);
    RUN(test_bark_cracks_along_axis);
    return check_finish();
}
