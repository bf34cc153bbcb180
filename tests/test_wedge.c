/* Tests of the wedge finite element model: assembled layers against analytic stresses, patch test, solvers, time steps, fracture. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"
#include "check.h"
#include "setup.h"
#include "wedge_fixture.h"
#include "fracture/eigen.h"
#include "fracture/event.h"
#include "geom/delaunay.h"
#include "geom/refine.h"
#include "geom/sample.h"
#include "image/image.h"
#include "model/wedge/internal.h"
#include "model/wedge/element.h"

/* A configuration for the wedge model: E = 10000 MPa, nu = 0.3, no jitter, no growth, no shrinkage. */
static fs_config base_config(void)
{
    fs_config c = fs_config_default();
    c.preset.model = FS_MODEL_WEDGE;
    c.material.young = 10000.0;
    c.material.poisson = 0.3;
    c.material.threshold = 200.0;
    c.material.jitter = 0.0;
    c.material.thickness = 0.2;
    c.material.thickness_final = -1.0;
    c.fracture.method = FS_FRACTURE_REMOVE;
    c.time.end = 1.0;
    c.time.min_step = 1e-3;
    c.mesh.min_size = 1e3;
    c.solver.tolerance = 1e-10;
    c.solver.relax = FS_RELAX_GLOBAL; /* the factor updates after removals (test_wedge_relax covers local) */
    return c;
}

/* A linear ramp from 0 at t = 0 to v at t = 1. */
static fs_pwl ramp(double v)
{
    fs_pwl f = {0};
    f.n = 2;
    f.t[0] = 0.0;
    f.v[0] = 0.0;
    f.t[1] = 1.0;
    f.v[1] = v;
    return f;
}

/* Centroid of element e's bottom triangle (unwrapped domain coordinates). */
static void centroid(const fs_mesh *m, int32_t e, double c[3])
{
    c[0] = c[1] = c[2] = 0.0;
    for (int k = 0; k < 3; k++) {
        double p[3];
        fs_mesh_corner(m, e, k, p);
        for (int j = 0; j < 3; j++)
            c[j] += p[j] / 3.0;
    }
}

/* Distance of a plane point from the border of the w x h rectangle. */
static double border_distance(const double *p, double w, double h)
{
    return fmin(fmin(p[0], w - p[0]), fmin(p[1], h - p[1]));
}

/* A wide bonded layer under uniform isotropic shrinkage eps: sigma_xx = sigma_yy = E eps / (1 - nu)
 * and no other stress, away from the free edges (SPEC §9), on a real mesh through the assembly. */
static void test_bonded_layer_shrinkage(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 6.0;
    double eps = 1e-3;
    cfg.shrink.top = ramp(eps);
    cfg.shrink.bottom = ramp(eps);
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 1200, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_equilibrium(&w, 1.0) == 0);
    double expect = cfg.material.young * eps / (1.0 - cfg.material.poisson);
    double worst = 0.0, worst_other = 0.0;
    int counted = 0;
    for (int32_t e = 0; e < w.n_elems; e++) {
        double c[3];
        centroid(&m, e, c);
        if (border_distance(c, 6.0, 6.0) < 10.0 * cfg.material.thickness)
            continue;
        counted++;
        for (int g = 0; g < 3; g++) {
            const double *s = w.stress_top + 18 * (size_t)e + 6 * g;
            worst = fmax(worst, fmax(fabs(s[0] - expect), fabs(s[1] - expect)) / expect);
            worst_other = fmax(worst_other, fmax(fmax(fabs(s[2]), fabs(s[3])), fmax(fabs(s[4]), fabs(s[5]))) / expect);
        }
    }
    CHECK(counted > 100);
    CHECK_MSG(worst < 0.01, "in-plane stress off by %.3g of E eps / (1 - nu) = %g MPa", worst, expect);
    CHECK_MSG(worst_other < 0.01, "other stress components up to %.3g of %g MPa", worst_other, expect);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Largest absolute difference of two arrays, relative to the largest absolute value of b. */
static double rel_diff(const double *a, const double *b, size_t n)
{
    double d = 0.0, m = 0.0;
    for (size_t i = 0; i < n; i++) {
        d = fmax(d, fabs(a[i] - b[i]));
        m = fmax(m, fabs(b[i]));
    }
    return m > 0.0 ? d / m : d;
}

/* Principal stress and direction (largest) of element e at its first top Gauss point. */
static void principal(const fs_wedge_model *w, int32_t e, double *sigma1, double dir[3])
{
    double sig[3], dirs[9];
    CHECK(fs_eigen_principal_stress(w->stress_top + 18 * (size_t)e, sig, dirs) == 0);
    *sigma1 = sig[0];
    memcpy(dir, dirs, 3 * sizeof *dir);
}

/* Anisotropic planar growth of the background (r1 along 30 degrees, r2 < r1): away from the edges
 * the largest principal stress points along the fastest growth and has the bonded-layer value
 * E / (1 - nu^2) (eps1 + nu eps2), eps_i = exp(r_i t) - 1; and the periodic layer, loaded by the
 * equivalent eigenstrain instead of moving its bottom nodes, has the same stresses. */
static void test_anisotropic_growth(void)
{
    double t = 1e-3, angle = 30.0;
    double axis[2] = {cos(angle * FS_PI / 180.0), sin(angle * FS_PI / 180.0)};
    double expect_dir_sigma = 0.0;
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 6.0;
    cfg.growth.type = FS_GROWTH_PLANAR;
    cfg.growth.r1 = 1.0;
    cfg.growth.r2 = 0.25;
    cfg.growth.angle = angle;
    double e1 = expm1(cfg.growth.r1 * t), e2 = expm1(cfg.growth.r2 * t), nu = cfg.material.poisson;
    expect_dir_sigma = cfg.material.young / (1.0 - nu * nu) * (e1 + nu * e2);
    double sigma_move = 0.0, sigma_periodic = 0.0;
    for (int periodic = 0; periodic < 2; periodic++) {
        cfg.domain.periodic_x = cfg.domain.periodic_y = periodic;
        fs_mesh m = {0};
        CHECK(wedge_test_mesh(&cfg, 1200, &m) == 0);
        fs_wedge_model w;
        CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
        CHECK(w.growth_mode == (periodic ? FS_WEDGE_GROWTH_EIGENSTRAIN : FS_WEDGE_GROWTH_MOVE));
        CHECK(fs_wedge_equilibrium(&w, t) == 0);
        double worst_angle = 0.0, worst_sigma = 0.0, sum = 0.0;
        int counted = 0;
        for (int32_t e = 0; e < w.n_elems; e++) {
            double c[3];
            centroid(&m, e, c);
            if (!periodic && border_distance(c, 6.0, 6.0) < 10.0 * cfg.material.thickness)
                continue;
            double s1, dir[3];
            principal(&w, e, &s1, dir);
            worst_angle = fmax(worst_angle, acos(fmin(1.0, fabs(dir[0] * axis[0] + dir[1] * axis[1]))) * 180.0 / FS_PI);
            worst_sigma = fmax(worst_sigma, fabs(s1 - expect_dir_sigma) / expect_dir_sigma);
            sum += s1;
            counted++;
        }
        CHECK(counted > 100);
        CHECK_MSG(worst_angle < 1.0, "periodic %d: principal direction off by %.3g degrees", periodic, worst_angle);
        CHECK_MSG(worst_sigma < 0.01, "periodic %d: largest principal stress off by %.3g of %g MPa", periodic,
                  worst_sigma, expect_dir_sigma);
        if (periodic)
            sigma_periodic = sum / counted;
        else
            sigma_move = sum / counted;
        fs_wedge_free(&w);
        fs_mesh_free(&m);
    }
    CHECK_NEAR(sigma_periodic, sigma_move, 1e-3 * expect_dir_sigma);
}

/* Patch test on an assembled mesh: the bottom nodes and the top nodes on the border take a linear
 * displacement whose top face is traction free (gamma_xz = gamma_yz = sigma_zz = 0); the solved
 * interior reproduces it exactly, with the same constant strain at every Gauss point of every element. */
static void test_patch(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = 4.0;
    cfg.domain.height = 3.0;
    cfg.material.thickness = 0.3;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 160, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    const double A[2][2] = {{1e-3, 2e-4}, {-5e-4, 3e-4}}, a = 4e-4, b = -2e-4, nu = cfg.material.poisson;
    const double wz[3] = {-a, -b, -nu / (1.0 - nu) * (A[0][0] + A[1][1])};
    const double strain[6] = {A[0][0], A[1][1], wz[2], A[0][1] + A[1][0], 0.0, 0.0};
    uint8_t *pinned = calloc((size_t)m.n_nodes, 1);
    for (int32_t t = 0; t < m.n_tris; t++)
        for (int i = 0; i < 3; i++)
            if (m.adj[3 * t + i] < 0) {
                pinned[m.tri[3 * t + i]] = 1;
                pinned[m.tri[3 * t + (i + 1) % 3]] = 1;
            }
    double h = cfg.material.thickness;
    double *exact = calloc(6 * (size_t)m.n_nodes, sizeof *exact);
    for (int32_t i = 0; i < m.n_nodes; i++) {
        const double *p = m.pos + 3 * (size_t)i;
        for (int top = 0; top < 2; top++) {
            double z = top ? h : 0.0, *u = exact + 6 * (size_t)i + 3 * top;
            u[0] = A[0][0] * p[0] + A[0][1] * p[1] + wz[0] * z;
            u[1] = A[1][0] * p[0] + A[1][1] * p[1] + wz[1] * z;
            u[2] = a * p[0] + b * p[1] + wz[2] * z;
        }
    }
    memcpy(w.prescribed, exact, 6 * (size_t)m.n_nodes * sizeof *exact);
    CHECK(fs_wedge_pin_top(&w, pinned) == 0);
    CHECK(w.n_free > 30);
    CHECK(fs_wedge_equilibrium(&w, 0.0) == 0);
    CHECK(rel_diff(w.u, exact, 6 * (size_t)m.n_nodes) < 1e-10);
    double worst = 0.0;
    for (int32_t e = 0; e < w.n_elems; e++) {
        double x[18], ue[18];
        fs_wedge_element_coords(&w, e, x);
        for (int c = 0; c < 3; c++)
            for (int k = 0; k < 3; k++) {
                ue[3 * c + k] = w.u[6 * (size_t)m.tri[3 * e + c] + k];
                ue[3 * (c + 3) + k] = w.u[6 * (size_t)m.tri[3 * e + c] + 3 + k];
            }
        for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
            double s[6];
            CHECK(fs_wedge_strain(x, ue, fs_wedge_gauss[g][0], fs_wedge_gauss[g][1], fs_wedge_gauss[g][2], s) == 0);
            worst = fmax(worst, rel_diff(s, strain, 6));
        }
    }
    CHECK_MSG(worst < 1e-9, "strain differs from the constant strain by %.3g (relative)", worst);
    free(pinned);
    free(exact);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

static double event_fn(void *ctx, double t)
{
    fs_wedge_model *w = ctx;
    return fs_wedge_equilibrium(w, t) < 0 ? NAN : fs_wedge_max_ratio(w);
}

/* A drying layer whose shrinkage (and so its stress) grows with time: the adaptive time step finds
 * the first fracture within time.min_step of a brute-force scan at every multiple of min_step. */
static void test_event_time(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 3.0;
    cfg.domain.periodic_x = cfg.domain.periodic_y = true;
    cfg.material.jitter = 0.2;
    cfg.material.threshold = 8000.0;
    cfg.shrink.top = ramp(2e-3);
    cfg.shrink.bottom = ramp(5e-4);
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 100, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    fs_event_result r;
    CHECK(fs_event_find(event_fn, &w, 0.0, 0.01, 1.0, cfg.time.min_step, &r) == 0);
    CHECK(r.found);
    double t_scan = NAN;
    for (int k = 1; k <= 1000; k++) {
        double t = k * cfg.time.min_step;
        CHECK(fs_wedge_equilibrium(&w, t) == 0);
        if (fs_wedge_max_ratio(&w) > 1.0) {
            t_scan = t;
            break;
        }
    }
    CHECK(t_scan > 0.05 && t_scan < 0.95);
    CHECK_MSG(fabs(r.t - t_scan) <= cfg.time.min_step, "event at %g, scan at %g", r.t, t_scan);
    CHECK(r.evaluations < 30);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* A periodic layer under growth and uneven shrinkage solved by CHOLMOD and by CG, before and after
 * removing elements (a factor updated by downdates against CG on the updated matrix). */
static void test_cholmod_vs_cg(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 4.0;
    cfg.domain.periodic_x = cfg.domain.periodic_y = true;
    cfg.growth.type = FS_GROWTH_PLANAR;
    cfg.growth.r1 = 0.5;
    cfg.growth.r2 = 0.1;
    cfg.growth.angle = 70.0;
    cfg.shrink.top = ramp(3e-3);
    cfg.shrink.bottom = ramp(1e-3);
    fs_mesh m1 = {0}, m2 = {0};
    CHECK(wedge_test_mesh(&cfg, 600, &m1) == 0);
    CHECK(wedge_test_mesh(&cfg, 600, &m2) == 0);
    fs_wedge_model a, b;
    cfg.solver.method = FS_SOLVER_CHOLMOD;
    CHECK(fs_wedge_init(&a, &m1, SETUP(&cfg)) == 0);
    cfg.solver.method = FS_SOLVER_CG;
    CHECK(fs_wedge_init(&b, &m2, SETUP(&cfg)) == 0);
    for (int round = 0; round < 2; round++) {
        CHECK(fs_wedge_equilibrium(&a, 0.5) == 0);
        CHECK(fs_wedge_equilibrium(&b, 0.5) == 0);
        double d = rel_diff(b.u, a.u, 6 * (size_t)a.n_nodes);
        CHECK_MSG(d < 1e3 * cfg.solver.tolerance, "round %d: CG and CHOLMOD differ by %.3g", round, d);
        for (int32_t e = 5; e < a.n_elems && round == 0; e += 37) {
            CHECK(fs_wedge_remove(&a, e) == 0);
            CHECK(fs_wedge_remove(&b, e) == 0);
        }
    }
    CHECK(a.counters.updowns > 0);
    CHECK(b.counters.cg_iterations > 0);
    fs_wedge_free(&a);
    fs_wedge_free(&b);
    fs_mesh_free(&m1);
    fs_mesh_free(&m2);
}

/* The system updated in place after removals (Algorithm 7 plus factor downdates, orphaned nodes
 * included) and after subdivisions (extended pattern) solves to what a fresh assembly solves to. */
static void test_updates_match_fresh_assembly(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 4.0;
    cfg.domain.periodic_x = true;
    cfg.shrink.top = ramp(3e-3);
    cfg.shrink.bottom = ramp(1e-3);
    cfg.mesh.min_size = 0.05;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 400, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    /* all the elements around node 10 (orphaning its top node), and a scattered few */
    for (int32_t p = w.node_elem_start[10]; p < w.node_elem_start[10] + w.node_elem_count[10]; p++)
        CHECK(fs_wedge_remove(&w, w.node_elem[p]) == 0);
    for (int32_t e = 3; e < w.n_elems; e += 41)
        if (w.state[e] == FS_WEDGE_ALIVE)
            CHECK(fs_wedge_remove(&w, e) == 0);
    int32_t list[3] = {100, 200, 300}, bisected = 0;
    CHECK(fs_wedge_subdivide(&w, list, 3, false, &bisected) == 0);
    CHECK(bisected >= 3);
    CHECK(w.n_elems > m.n_tris - bisected);
    int32_t list2[2] = {w.n_elems - 1, 150};
    CHECK(fs_wedge_subdivide(&w, list2, 2, true, &bisected) == 0);
    CHECK(fs_wedge_remove(&w, w.n_elems - 1) == 0);
    CHECK(w.counters.updowns > 0 && w.counters.analyses >= 3);
    CHECK(fs_wedge_equilibrium(&w, 0.7) == 0);
    size_t n = 6 * (size_t)w.n_nodes;
    double *u = malloc(n * sizeof *u);
    memcpy(u, w.u, n * sizeof *u);
    CHECK(w.u[6 * 10 + 3] == 0.0 && w.u[6 * 10 + 4] == 0.0 && w.u[6 * 10 + 5] == 0.0);
    uint8_t *none = calloc((size_t)w.n_nodes, 1);
    CHECK(fs_wedge_pin_top(&w, none) == 0); /* a fresh numbering, assembly and factorization */
    CHECK(fs_wedge_equilibrium(&w, 0.7) == 0);
    double d = rel_diff(u, w.u, n);
    CHECK_MSG(d < 1e-9, "updated and fresh systems differ by %.3g", d);
    free(u);
    free(none);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Growth of a cylinder's radius (bark) stretches the layer around the trunk only: the largest
 * principal stress is the hoop stress E eps / (1 - nu^2), eps = dR / R, along the circumference. */
static void test_cylinder_growth(void)
{
    fs_config cfg = base_config();
    cfg.domain.type = FS_DOMAIN_CYLINDER;
    cfg.domain.radius = 1.0;
    cfg.domain.height = 6.0;
    cfg.domain.periodic_y = true;
    cfg.growth.type = FS_GROWTH_CYLINDER;
    cfg.growth.rate = 0.5;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 600, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    double t = 2e-3, eps = cfg.growth.rate * t / cfg.domain.radius, nu = cfg.material.poisson;
    double expect = cfg.material.young * eps / (1.0 - nu * nu);
    CHECK(fs_wedge_equilibrium(&w, t) == 0);
    double worst = 0.0, worst_dir = 1.0;
    for (int32_t e = 0; e < w.n_elems; e++) {
        double s1, dir[3];
        principal(&w, e, &s1, dir);
        worst = fmax(worst, fabs(s1 - expect) / expect);
        worst_dir = fmin(worst_dir, fabs(dir[0]));
    }
    CHECK_MSG(worst < 0.01, "hoop stress off by %.3g of %g MPa", worst, expect);
    CHECK(worst_dir > cos(FS_PI / 180.0));
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Isogonic growth of a sphere stretches a thin bonded layer equally in every tangent direction:
 * sigma_1 = sigma_2 = E eps_t / (1 - nu). At the bottom eps_t = eps = dR / R; up through the layer
 * (sigma_rr = 0, so eps_rr = -2 nu / (1 - nu) eps_t) the radial displacement eps R + eps_rr z over
 * the radius R + z gives eps_t(z) = eps (1 - (z / R) (1 + nu) / (1 - nu)) to first order in z / R,
 * here at the height of the top Gauss points. */
static void test_sphere_growth(void)
{
    fs_config cfg = base_config();
    cfg.domain.type = FS_DOMAIN_SPHERE;
    cfg.domain.radius = 3.0;
    cfg.material.thickness = 0.03;
    cfg.growth.type = FS_GROWTH_SPHERE;
    cfg.growth.rate = 1.0;
    cfg.growth.axis_ratio = 1.0;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 1500, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(w.growth_mode == FS_WEDGE_GROWTH_MOVE && !w.flat);
    double t = 3e-4, eps = cfg.growth.rate * t / cfg.domain.radius, nu = cfg.material.poisson;
    double z = 0.5 * (1.0 + fs_wedge_gauss[0][2]) * cfg.material.thickness;
    double expect = cfg.material.young * eps / (1.0 - nu) * (1.0 - z / cfg.domain.radius * (1.0 + nu) / (1.0 - nu));
    CHECK(fs_wedge_equilibrium(&w, t) == 0);
    double worst = 0.0;
    for (int32_t e = 0; e < w.n_elems; e++) {
        double sig[3];
        CHECK(fs_eigen_principal_stress(w.stress_top + 18 * (size_t)e, sig, NULL) == 0);
        worst = fmax(worst, fmax(fabs(sig[0] - expect), fabs(sig[1] - expect)) / expect);
    }
    CHECK_MSG(worst < 0.015, "tangential stresses off by %.3g of %g MPa", worst, expect);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* A run of drying mud with element removal: fractures happen, the state stays finite, the layer
 * breaks into several fragments, and the render mesh shows them (cells) and the removed elements
 * (cracks at the floor). */
static void test_removal_run(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 3.0;
    cfg.domain.periodic_x = cfg.domain.periodic_y = true;
    cfg.material.thickness = 0.1;
    cfg.material.jitter = 0.1;
    cfg.material.threshold = 2000.0;
    cfg.shrink.top = ramp(2e-3);
    cfg.shrink.bottom = ramp(2e-3);
    cfg.time.min_step = 1e-3;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 400, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_simulate(&w, 1.0) == 0);
    CHECK(w.time == 1.0);
    CHECK(w.fractures > 10);
    bool finite = true;
    for (size_t i = 0; i < 6 * (size_t)w.n_nodes; i++)
        finite &= isfinite(w.u[i]);
    CHECK(finite);
    CHECK(fs_wedge_max_ratio(&w) <= 1.0);
    int32_t *label = malloc((size_t)w.n_elems * sizeof *label);
    int32_t fragments = fs_wedge_fragments(&w, label);
    CHECK_MSG(fragments >= 2, "%d fragments", (int)fragments);
    fs_surface r;
    CHECK(fs_wedge_surface(&w, &r) == 0);
    CHECK(r.n_tris == w.n_elems);
    int cracks = 0, bad = 0;
    for (int32_t t = 0; t < r.n_tris; t++) {
        int32_t v = r.tri[3 * t];
        bool removed = w.state[t] == FS_WEDGE_REMOVED;
        cracks += removed;
        bad += removed ? !(r.crack[v] == 1.0f && r.cell[v] == 0.0f && r.height[v] == 0.0f)
                       : !(r.crack[v] == 0.0f && r.cell[v] == (float)(label[t] + 1) && r.height[v] > 0.09f);
    }
    CHECK(cracks == w.fractures);
    CHECK(bad == 0);
    fs_surface_free(&r);
    free(label);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Dynamic subdivision (thesis Algorithm 8): on a coarse mesh, overstressed elements are bisected
 * until they are below mesh.min_size before any is removed, so every removed element is small; the
 * layer still cracks into fragments, and the system updated through all of it solves like a fresh one. */
static void test_subdivision_run(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 3.0;
    cfg.domain.periodic_x = cfg.domain.periodic_y = true;
    cfg.material.thickness = 0.15;
    cfg.material.jitter = 0.1;
    cfg.material.threshold = 20000.0;
    cfg.shrink.top = ramp(3e-3);
    cfg.shrink.bottom = ramp(1.5e-3);
    cfg.mesh.min_size = 0.2;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 60, &m) == 0);
    int32_t tris0 = m.n_tris;
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_simulate(&w, 1.0) == 0);
    CHECK(w.counters.subdivisions > 0 && w.n_elems > tris0);
    CHECK(w.fractures > 5);
    int big = 0;
    for (int32_t e = 0; e < w.n_elems; e++)
        big += w.state[e] == FS_WEDGE_REMOVED && fs_refine_tri_size(&m, e) >= cfg.mesh.min_size;
    CHECK_MSG(big == 0, "%d removed elements not below min_size", big);
    int32_t *label = malloc((size_t)w.n_elems * sizeof *label);
    CHECK(fs_wedge_fragments(&w, label) >= 2);
    free(label);
    size_t n = 6 * (size_t)w.n_nodes;
    double *u = malloc(n * sizeof *u);
    memcpy(u, w.u, n * sizeof *u);
    uint8_t *none = calloc((size_t)w.n_nodes, 1);
    CHECK(fs_wedge_pin_top(&w, none) == 0);
    CHECK(fs_wedge_equilibrium(&w, 1.0) == 0);
    CHECK(rel_diff(u, w.u, n) < 1e-9);
    free(u);
    free(none);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* The largest principal stress at element e's top Gauss points over its threshold, from w->u. */
static double fresh_ratio(const fs_wedge_model *w, int32_t e)
{
    double best = -INFINITY;
    for (int g = 0; g < FS_WEDGE_GAUSS_TOP; g++) {
        double s[6], sig[3];
        if (fs_wedge_element_stress(w, e, fs_wedge_gauss[g][0], fs_wedge_gauss[g][1], fs_wedge_gauss[g][2], s) < 0 ||
            fs_eigen_principal_stress(s, sig, NULL) < 0)
            return NAN;
        best = fmax(best, sig[0]);
    }
    return best / w->threshold[e];
}

/* Lazy ratios (fs_wedge_element_ratios in wedge/equilibrium.c) skip elements whose bound cannot have reached 1 since their
 * last evaluation: along a run of removals at one time, every ratio still bounds the exact one from
 * the displacements, the model removes the same elements in the same order as with every ratio
 * evaluated, and some elements were indeed skipped (their stored stress is older than the state). */
static void test_lazy_ratios(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 3.0;
    cfg.domain.periodic_x = cfg.domain.periodic_y = true;
    cfg.material.thickness = 0.1;
    cfg.material.jitter = 0.1;
    cfg.material.threshold = 2000.0;
    cfg.shrink.top = ramp(2e-3);
    cfg.shrink.bottom = ramp(2e-3);
    fs_mesh m1 = {0}, m2 = {0};
    CHECK(wedge_test_mesh(&cfg, 400, &m1) == 0);
    CHECK(wedge_test_mesh(&cfg, 400, &m2) == 0);
    fs_wedge_model a, b;
    CHECK(fs_wedge_init(&a, &m1, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_init(&b, &m2, SETUP(&cfg)) == 0);
    b.lazy_ratios = true;
    /* stresses grow in proportion to t: go to just past the first fracture */
    CHECK(fs_wedge_equilibrium(&a, 1.0) == 0);
    double t = 1.05 / fs_wedge_max_ratio(&a);
    CHECK(fs_wedge_equilibrium(&a, t) == 0);
    CHECK(fs_wedge_equilibrium(&b, t) == 0);
    int removals = 0, bounded = 1, same = 1, stale = 0;
    while (removals < 60 && fs_wedge_max_ratio(&a) > 1.0) {
        same &= fs_wedge_max_ratio(&a) == fs_wedge_max_ratio(&b);
        int ra, rb;
        CHECK(fs_wedge_fracture(&a, &ra) == 0 && fs_wedge_fracture(&b, &rb) == 0);
        CHECK(fs_wedge_equilibrium(&a, t) == 0);
        CHECK(fs_wedge_equilibrium(&b, t) == 0);
        removals++;
        for (int32_t e = 0; e < b.n_elems; e++) {
            same &= a.state[e] == b.state[e];
            if (b.state[e] != FS_WEDGE_ALIVE)
                continue;
            double exact = fresh_ratio(&b, e);
            bounded &= b.ratio[e] >= exact - 1e-12 * fabs(exact);
            stale += b.ratio[e] <= 1.0 && fabs(fs_wedge_element_ratio(&b, e) - exact) > 1e-9 * fabs(exact);
        }
    }
    CHECK_MSG(removals >= 20, "%d removals", removals);
    CHECK(bounded);
    CHECK(same);
    CHECK_MSG(stale > 0, "no element was skipped");
    fs_wedge_free(&a);
    fs_wedge_free(&b);
    fs_mesh_free(&m1);
    fs_mesh_free(&m2);
}

/* A layer that thickens over time (bark, thesis Table 5.2) is, at each time, the layer of that
 * thickness: the same displacements as a model built with the thickness constant at its value then,
 * here on a non-periodic plane under uneven shrinkage, where the thickness matters near the edges. */
static void test_thickness_over_time(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = 3.0;
    cfg.domain.height = 2.0;
    cfg.shrink.top = ramp(3e-3);
    cfg.shrink.bottom = ramp(1e-3);
    cfg.material.thickness = 0.2;
    cfg.material.thickness_final = 0.6;
    fs_mesh m1 = {0}, m2 = {0};
    CHECK(wedge_test_mesh(&cfg, 150, &m1) == 0);
    CHECK(wedge_test_mesh(&cfg, 150, &m2) == 0);
    fs_wedge_model a, b;
    CHECK(fs_wedge_init(&a, &m1, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_remove(&a, 7) == 0);
    CHECK(fs_wedge_equilibrium(&a, 0.5) == 0);
    CHECK_NEAR(a.assembled_thickness, 0.4, 1e-15);
    cfg.material.thickness = 0.4;
    cfg.material.thickness_final = -1.0;
    CHECK(fs_wedge_init(&b, &m2, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_remove(&b, 7) == 0);
    CHECK(fs_wedge_equilibrium(&b, 0.5) == 0);
    double d = rel_diff(a.u, b.u, 6 * (size_t)a.n_nodes);
    CHECK_MSG(d < 1e-12, "thickening layer differs from the constant one by %.3g", d);
    CHECK(rel_diff(a.stress_top, b.stress_top, 18 * (size_t)a.n_elems) < 1e-9);
    fs_wedge_free(&a);
    fs_wedge_free(&b);
    fs_mesh_free(&m1);
    fs_mesh_free(&m2);
}

/* A thickening layer keeps each element's stiffness as h K1 + K0 + K2 / h (system.c): at any base
 * thickness it equals the quadrature's, with the nodes' thickness factors uneven across the element
 * (a thickness gradient), and it follows a changed factor. */
static void test_stiffness_parts(void)
{
    fs_config cfg = base_config();
    cfg.domain.width = 3.0;
    cfg.domain.height = 2.0;
    cfg.material.thickness = 0.2;
    cfg.material.thickness_final = 0.6;
    cfg.wedge.thickness_gradient = 0.8;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 150, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(w.k_parts_on);
    double K[324], direct[324], x[18], D[36], loads[FS_WEDGE_PATTERNS][18], worst = 0.0;
    for (int round = 0; round < 2; round++) {
        if (round == 1) /* a node of element 0 thicker: its parts are refitted */
            w.thickness_factor[m.tri[0]] *= 1.5;
        static const double hs[3] = {0.05, 0.4, 3.0};
        for (int32_t e = 0; e < w.n_elems; e++)
            for (int i = 0; i < 3; i++) {
                CHECK(fs_wedge_element_system(&w, e, hs[i], K, loads) == 0);
                fs_wedge_coords_at(&w, e, hs[i], x);
                for (int k = 0; k < 36; k++)
                    D[k] = w.young[e] * w.d_unit[k];
                CHECK(fs_wedge_stiffness(x, D, direct) == 0);
                double scale = 0.0, diff = 0.0;
                for (int p = 0; p < 324; p++) {
                    scale = fmax(scale, fabs(direct[p]));
                    diff = fmax(diff, fabs(K[p] - direct[p]));
                }
                worst = fmax(worst, diff / scale);
            }
    }
    CHECK_MSG(worst < 1e-11, "stiffness from its parts differs from the quadrature by %.3g", worst);
    printf("  stiffness from its parts against the quadrature: %.3g relative\n", worst);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* The thickness gradient and a grey-level thickness map scale the layer node by node: the render
 * mesh's heights are the thickness times 1 + gradient (u - 1/2) times the map's grey level. */
static void test_thickness_gradient_and_map(void)
{
    float grey[16 * 16];
    for (int j = 0; j < 16; j++) /* grey = v at the pixel centres: rows top to bottom */
        for (int i = 0; i < 16; i++)
            grey[16 * j + i] = (float)(1.0 - (j + 0.5) / 16.0);
    fs_config cfg = base_config();
    cfg.domain.width = cfg.domain.height = 2.0;
    cfg.material.thickness = 0.5;
    cfg.wedge.thickness_gradient = 0.8;
    fs_model_setup setup = fs_config_model_setup(&cfg);
    setup.thickness_map = (fs_grey_map){.width = 16, .height = 16, .grey = grey};
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 200, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, &setup) == 0);
    CHECK(fs_wedge_equilibrium(&w, 0.0) == 0);
    fs_surface r;
    CHECK(fs_wedge_surface(&w, &r) == 0);
    double worst = 0.0;
    for (int32_t v = 0; v < r.n_verts; v++) {
        double u = r.uv[2 * v], vv = r.uv[2 * v + 1];
        /* within the pixel centres the map is linear; at the borders it is clamped */
        if (vv < 1.0 / 32.0 || vv > 1.0 - 1.0 / 32.0)
            continue;
        double expect = 0.5 * (1.0 + 0.8 * (u - 0.5)) * vv;
        worst = fmax(worst, fabs(r.height[v] - expect));
    }
    CHECK_MSG(worst < 0.5 * 0.01, "heights off by %.3g cm", worst);
    fs_surface_free(&r);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Every living element's energy (fs_wedge_element_energy) asked twice, with what the elements kept
 * from before, against the same energies computed afresh (fs_wedge_energy_forget): the number that
 * differ in any bit. */
static int energies_differing(fs_wedge_model *w)
{
    double *kept = malloc(2 * (size_t)w->n_elems * sizeof *kept);
    for (int pass = 0; pass < 2; pass++)
        for (int32_t e = 0; e < w->n_elems; e++)
            kept[2 * (size_t)e + pass] = fs_wedge_element_energy(w, e);
    fs_wedge_energy_forget(w);
    int differ = 0;
    for (int32_t e = 0; e < w->n_elems; e++) {
        double fresh = fs_wedge_element_energy(w, e);
        differ += (kept[2 * (size_t)e] != fresh) + (kept[2 * (size_t)e + 1] != fresh);
    }
    free(kept);
    return differ;
}

/* The element strain energies of Griffith's balance. A bonded layer under uniform shrinkage eps
 * stores E eps^2 / (1 - nu) per volume away from its edges (the in-plane elastic strain is eps and
 * the stress E eps / (1 - nu)). The energies each element keeps and reuses (equilibrium.c) equal
 * fresh ones bit for bit: at equilibrium, after some displacements change, and after the layer
 * thickens (its stiffnesses then fitted in thickness). */
static void test_element_energy(void)
{
    for (int thickening = 0; thickening < 2; thickening++) {
        fs_config cfg = base_config();
        cfg.domain.width = cfg.domain.height = 6.0;
        double eps = 1e-3;
        cfg.shrink.top = ramp(eps);
        cfg.shrink.bottom = ramp(eps);
        if (thickening)
            cfg.material.thickness_final = 0.4;
        fs_mesh m = {0};
        CHECK(wedge_test_mesh(&cfg, 1200, &m) == 0);
        fs_wedge_model w;
        CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
        CHECK(w.k_parts_on == (thickening == 1));
        CHECK(fs_wedge_equilibrium(&w, 1.0) == 0);
        double expect = cfg.material.young * eps * eps / (1.0 - cfg.material.poisson), worst = 0.0;
        for (int32_t e = 0; e < w.n_elems; e++) {
            double c[3], p[3][3];
            centroid(&m, e, c);
            if (border_distance(c, 6.0, 6.0) < 10.0 * w.assembled_thickness)
                continue;
            for (int k = 0; k < 3; k++)
                fs_mesh_corner(&m, e, k, p[k]);
            double area = 0.5 * fabs((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[2][0] - p[0][0]) * (p[1][1] - p[0][1]));
            worst = fmax(worst, fabs(fs_wedge_element_energy(&w, e) / (area * w.assembled_thickness) - expect) / expect);
        }
        CHECK_MSG(worst < 0.01, "energy density off by %.3g of E eps^2 / (1 - nu)", worst);
        CHECK(energies_differing(&w) == 0);
        for (int32_t i = 0; i < w.n_nodes; i += 7)
            w.u[6 * (size_t)i + 3] += 1e-5;
        CHECK(energies_differing(&w) == 0);
        CHECK(fs_wedge_equilibrium(&w, 0.5) == 0);
        CHECK(energies_differing(&w) == 0);
        fs_wedge_free(&w);
        fs_mesh_free(&m);
    }
}

int main(void)
{
    RUN(test_bonded_layer_shrinkage);
    RUN(test_anisotropic_growth);
    RUN(test_patch);
    RUN(test_event_time);
    RUN(test_cholmod_vs_cg);
    RUN(test_updates_match_fresh_assembly);
    RUN(test_cylinder_growth);
    RUN(test_sphere_growth);
    RUN(test_removal_run);
    RUN(test_subdivision_run);
    RUN(test_lazy_ratios);
    RUN(test_thickness_over_time);
    RUN(test_stiffness_parts);
    RUN(test_thickness_gradient_and_map);
    RUN(test_element_energy);
    return check_finish();
}
