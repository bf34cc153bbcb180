/* Tests of the wedge model's adaptive local relaxation (thesis §5.8): agreement with global solves, cracks as barriers, radius control, locality. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "setup.h"
#include "wedge_fixture.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "model/wedge/internal.h"

/* A bonded layer 0.2 cm thick, E = 10000 MPa, nu = 0.3, whose top shrinks twice as fast as its bottom. */
static fs_config base_config(double size, fs_relax_mode relax)
{
    fs_config c = fs_config_default();
    c.preset.model = FS_MODEL_WEDGE;
    c.domain.width = c.domain.height = size;
    c.material.young = 10000.0;
    c.material.poisson = 0.3;
    c.material.threshold = 200.0;
    c.material.jitter = 0.0;
    c.material.thickness = 0.2;
    c.material.thickness_final = -1.0;
    c.fracture.method = FS_FRACTURE_REMOVE;
    c.mesh.min_size = 1e3;
    c.solver.tolerance = 1e-8;
    c.solver.relax = relax;
    c.solver.relax_tolerance = 1e-7;
    c.shrink.top.n = c.shrink.bottom.n = 2;
    c.shrink.top.t[1] = c.shrink.bottom.t[1] = 1.0;
    c.shrink.top.v[1] = 2e-3;
    c.shrink.bottom.v[1] = 1e-3;
    return c;
}

/* The element whose centroid is nearest (x, y). */
static int32_t element_near(const fs_mesh *m, double x, double y)
{
    int32_t best = -1;
    double bd = INFINITY;
    for (int32_t e = 0; e < m->n_tris; e++) {
        double c[2] = {0.0, 0.0};
        for (int k = 0; k < 3; k++) {
            double p[3];
            fs_mesh_corner(m, e, k, p);
            c[0] += p[0] / 3.0;
            c[1] += p[1] / 3.0;
        }
        double d = hypot(c[0] - x, c[1] - y);
        if (d < bd) {
            bd = d;
            best = e;
        }
    }
    return best;
}

/* Largest difference of the displacements of two models on one mesh, relative to the largest value. */
static double u_diff(const fs_wedge_model *a, const fs_wedge_model *b)
{
    double d = 0.0, s = 0.0;
    for (size_t i = 0; i < 6 * (size_t)a->n_nodes; i++) {
        d = fmax(d, fabs(a->u[i] - b->u[i]));
        s = fmax(s, fabs(b->u[i]));
    }
    return s > 0.0 ? d / s : d;
}

/* Largest difference of the top stresses of the living elements, relative to the largest stress. */
static double stress_diff(const fs_wedge_model *a, const fs_wedge_model *b)
{
    double d = 0.0, s = 0.0;
    for (int32_t e = 0; e < a->n_elems; e++) {
        if (a->state[e] != FS_WEDGE_ALIVE)
            continue;
        for (int k = 0; k < 18; k++) {
            d = fmax(d, fabs(a->stress_top[18 * (size_t)e + k] - b->stress_top[18 * (size_t)e + k]));
            s = fmax(s, fabs(b->stress_top[18 * (size_t)e + k]));
        }
    }
    return s > 0.0 ? d / s : d;
}

/* Two models on one mesh at equilibrium at t = 1: a relaxes locally, b globally. */
static void pair_init_with(fs_mesh *m, fs_config ca, fs_wedge_model *a, fs_wedge_model *b)
{
    fs_config cb = ca;
    cb.solver.relax = FS_RELAX_GLOBAL;
    CHECK(fs_wedge_init(a, m, SETUP(&ca)) == 0);
    CHECK(fs_wedge_init(b, m, SETUP(&cb)) == 0);
    CHECK(fs_wedge_equilibrium(a, 1.0) == 0);
    CHECK(fs_wedge_equilibrium(b, 1.0) == 0);
}

static void pair_init(fs_mesh *m, double size, fs_wedge_model *a, fs_wedge_model *b)
{
    pair_init_with(m, base_config(size, FS_RELAX_LOCAL), a, b);
}


/* After removals in a bonded layer under shrinkage, local relaxation reaches the global solution:
 * displacements, stresses, the ratios fracture decides on, and the element that breaks next. */
static void test_local_matches_global(void)
{
    fs_config cfg = base_config(6.0, FS_RELAX_LOCAL);
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 1500, &m) == 0);
    fs_wedge_model a, b;
    pair_init(&m, 6.0, &a, &b);
    const double spots[3][2] = {{3.0, 3.0}, {3.1, 3.05}, {1.5, 4.0}};
    for (int s = 0; s < 3; s++) {
        int32_t e = element_near(&m, spots[s][0], spots[s][1]);
        if (a.state[e] != FS_WEDGE_ALIVE)
            continue;
        CHECK(fs_wedge_remove(&a, e) == 0);
        CHECK(fs_wedge_remove(&b, e) == 0);
        CHECK(a.factor_stale && !b.factor_stale);
        CHECK(fs_wedge_relax(&a, NULL, 0) == 0);
        CHECK(fs_wedge_equilibrium(&b, 1.0) == 0);
        double du = u_diff(&a, &b), ds = stress_diff(&a, &b);
        CHECK_MSG(du < 1e-6, "removal %d: displacements differ by %.3g of the largest", s, du);
        CHECK_MSG(ds < 1e-6, "removal %d: stresses differ by %.3g of the largest", s, ds);
        CHECK_NEAR(fs_wedge_max_ratio(&a), fs_wedge_max_ratio(&b), 1e-6 * fabs(fs_wedge_max_ratio(&b)));
        int ra = 0, rb = 0;
        CHECK(fs_wedge_fracture(&a, &ra) == fs_wedge_fracture(&b, &rb));
        CHECK(ra == rb);
        if (ra) {
            CHECK(fs_wedge_relax(&a, NULL, 0) == 0);
            CHECK(fs_wedge_equilibrium(&b, 1.0) == 0);
            CHECK(u_diff(&a, &b) < 1e-6);
        }
    }
    for (int32_t e = 0; e < a.n_elems; e++)
        CHECK(a.state[e] == b.state[e]);
    CHECK_MSG(a.counters.local_relaxations > 0, "no relaxation stayed local (%lld fallbacks)",
              (long long)a.counters.global_fallbacks);
    /* the next equilibrium at a new time is solved by CG from the current state, without
     * re-factorizing the stale factor, and agrees with the factor to the CG tolerance */
    int64_t factorizations = a.counters.factorizations;
    CHECK(fs_wedge_equilibrium(&a, 0.9) == 0);
    CHECK(fs_wedge_equilibrium(&b, 0.9) == 0);
    CHECK(a.factor_stale && a.counters.factorizations == factorizations);
    CHECK_MSG(u_diff(&a, &b) < 1e-6, "CG and the factor differ by %.3g of the largest", u_diff(&a, &b));
    fs_wedge_free(&a);
    fs_wedge_free(&b);
    fs_mesh_free(&m);
}

/* A global solve with a stale factor that CG cannot finish (here: an iteration limit far too small)
 * falls back to a fresh factorization and the direct solve, and gets the factor's answer. */
static void test_stalled_cg_falls_back(void)
{
    fs_config cfg = base_config(4.0, FS_RELAX_LOCAL);
    cfg.solver.max_iterations = 3;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 600, &m) == 0);
    fs_wedge_model a, b;
    pair_init_with(&m, cfg, &a, &b);
    CHECK(fs_wedge_remove(&a, element_near(&m, 2.0, 2.0)) == 0);
    CHECK(fs_wedge_remove(&b, element_near(&m, 2.0, 2.0)) == 0);
    CHECK(a.factor_stale);
    int64_t factorizations = a.counters.factorizations;
    CHECK_MSG(fs_wedge_equilibrium(&a, 0.9) == 0, "%s", fs_error_message());
    CHECK(fs_wedge_equilibrium(&b, 0.9) == 0);
    CHECK(!a.factor_stale && a.counters.factorizations == factorizations + 1);
    CHECK_MSG(u_diff(&a, &b) < 1e-9, "fallback and factor differ by %.3g of the largest", u_diff(&a, &b));
    fs_wedge_free(&a);
    fs_wedge_free(&b);
    fs_mesh_free(&m);
}

/* Is the node in the list? */
static bool listed(const int32_t *list, int32_t n, int32_t node)
{
    for (int32_t q = 0; q < n; q++)
        if (list[q] == node)
            return true;
    return false;
}

/* A strip of removed elements across the layer is a barrier: the region grown from a node beside it
 * never reaches the far side, though the far side is within the radius as the crow flies (and is
 * reached when the strip is intact); a local relaxation there leaves the far side untouched. */
static void test_crack_is_barrier(void)
{
    fs_config cfg = base_config(4.0, FS_RELAX_LOCAL);
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 800, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_equilibrium(&w, 1.0) == 0);
    const double x0 = 1.8, x1 = 2.2, radius = 1.5;
    int32_t seed = -1;
    double best = INFINITY;
    for (int32_t i = 0; i < m.n_nodes; i++) {
        double d = hypot(m.pos[3 * (size_t)i] - (x0 - 0.3), m.pos[3 * (size_t)i + 1] - 2.0);
        if (d < best) {
            best = d;
            seed = i;
        }
    }
    int32_t *out = malloc((size_t)m.n_nodes * sizeof *out);
    int32_t n_intact = fs_wedge_relax_region(&w, &seed, 1, radius, out);
    bool far_reached = false;
    for (int32_t q = 0; q < n_intact; q++)
        far_reached |= m.pos[3 * (size_t)out[q]] > x1 + 0.1;
    CHECK_MSG(far_reached, "the intact layer should be crossed");
    CHECK(out[0] == seed);

    for (int32_t e = 0; e < m.n_tris; e++) {
        double lo = INFINITY, hi = -INFINITY;
        for (int k = 0; k < 3; k++) {
            double p[3];
            fs_mesh_corner(&m, e, k, p);
            lo = fmin(lo, p[0]);
            hi = fmax(hi, p[0]);
        }
        if (hi > x0 && lo < x1)
            CHECK(fs_wedge_remove(&w, e) == 0);
    }
    CHECK(fs_wedge_equilibrium(&w, 1.0) == 0);
    int32_t n = fs_wedge_relax_region(&w, &seed, 1, radius, out);
    int32_t far = 0, near = 0, across = -1;
    for (int32_t q = 0; q < n; q++) {
        double x = m.pos[3 * (size_t)out[q]];
        far += x > x1 - 1e-12;
        near += x < x0 && x > x0 - radius + 0.5;
    }
    for (int32_t i = 0; i < m.n_nodes && across < 0; i++)
        if (m.pos[3 * (size_t)i] > x1 && m.pos[3 * (size_t)i] < x1 + 0.2 && fabs(m.pos[3 * (size_t)i + 1] - 2.0) < 0.3)
            across = i;
    CHECK(across >= 0 && !listed(out, n, across));
    CHECK_MSG(far == 0, "%d nodes across the removed strip were marked", (int)far);
    CHECK(near > 10);

    double *before = malloc(6 * (size_t)m.n_nodes * sizeof *before);
    memcpy(before, w.u, 6 * (size_t)m.n_nodes * sizeof *before);
    w.relax_unit = 0.0;
    w.cfg.solver.relax_radius = 10.0;
    CHECK(fs_wedge_relax(&w, &seed, 1) == 0);
    CHECK(w.counters.local_relaxations == 1 && w.counters.global_fallbacks == 0);
    bool untouched = true;
    for (int32_t i = 0; i < m.n_nodes; i++)
        if (m.pos[3 * (size_t)i] > x1)
            untouched &= memcmp(w.u + 6 * (size_t)i, before + 6 * (size_t)i, 6 * sizeof *before) == 0;
    CHECK(untouched);
    free(before);
    free(out);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* A tolerance no local solve meets forces the global fallback after the local attempts at doubling
 * radii reach a quarter of the unknowns, and the radius for the next event is twice the last one
 * tried; a success at the first try shrinks it by 3/4, never below one mean edge length. */
static void test_radius_control(void)
{
    fs_config cfg = base_config(4.0, FS_RELAX_LOCAL);
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 800, &m) == 0);
    fs_wedge_model w, g;
    pair_init(&m, 4.0, &w, &g);
    CHECK(fs_wedge_relax(&w, NULL, 0) == 0); /* in balance: nothing to do, the radius is set */
    CHECK(w.relax_unit > 0.0);
    CHECK_NEAR(w.relax_radius, cfg.solver.relax_radius * w.relax_unit, 1e-12);
    CHECK(w.counters.local_relaxations == 1 && w.counters.local_dofs == 0);

    int32_t e = element_near(&m, 2.0, 2.0);
    CHECK(fs_wedge_remove(&w, e) == 0);
    CHECK(fs_wedge_remove(&g, e) == 0);
    w.relax_radius = w.relax_unit;
    w.cfg.solver.relax_tolerance = 1e-15;
    CHECK(fs_wedge_relax(&w, NULL, 0) == 0);
    CHECK(w.counters.global_fallbacks == 1);
    CHECK(w.counters.relax_retries >= 1);
    CHECK_NEAR(w.relax_radius, w.relax_unit * pow(2.0, (double)w.counters.relax_retries + 1.0), 1e-9);
    CHECK(w.factor_stale); /* the fallback solved by CG (see solve() in wedge/equilibrium.c) */
    CHECK(fs_wedge_equilibrium(&g, 1.0) == 0);
    CHECK_MSG(u_diff(&w, &g) < 1e-6, "the fallback and the factor differ by %.3g of the largest", u_diff(&w, &g));

    e = element_near(&m, 1.0, 3.0);
    CHECK(fs_wedge_remove(&w, e) == 0);
    w.cfg.solver.relax_tolerance = 1e-3;
    w.relax_radius = 10.0 * w.relax_unit;
    double r0 = w.relax_radius;
    int64_t retries = w.counters.relax_retries;
    CHECK(fs_wedge_relax(&w, NULL, 0) == 0);
    CHECK(w.counters.local_relaxations == 2 && w.counters.global_fallbacks == 1);
    CHECK(w.counters.relax_retries == retries);
    CHECK_NEAR(w.relax_radius, 0.75 * r0, 1e-12);
    CHECK(w.factor_stale);

    e = element_near(&m, 3.0, 1.0);
    CHECK(fs_wedge_remove(&w, e) == 0);
    w.relax_radius = w.relax_unit;
    w.cfg.solver.relax_tolerance = 1.0;
    CHECK(fs_wedge_relax(&w, NULL, 0) == 0);
    CHECK(w.counters.local_relaxations == 3 && w.counters.relax_retries == retries);
    CHECK_NEAR(w.relax_radius, w.relax_unit, 1e-12);
    fs_wedge_free(&w);
    fs_wedge_free(&g);
    fs_mesh_free(&m);
}

/* A removal far from everything in a thin layer relaxes locally, at the default tolerance, with a
 * small fraction of the unknowns (all attempts together), and the result matches a global solve to
 * the tolerance. */
static void test_far_change_is_local(void)
{
    fs_config cfg = base_config(10.0, FS_RELAX_LOCAL);
    cfg.material.thickness = 0.1;
    cfg.solver.relax_tolerance = fs_config_default().solver.relax_tolerance;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 5000, &m) == 0);
    fs_wedge_model a, b;
    pair_init_with(&m, cfg, &a, &b);
    int32_t e = element_near(&m, 5.0, 5.0);
    CHECK(fs_wedge_remove(&a, e) == 0);
    CHECK(fs_wedge_remove(&b, e) == 0);
    CHECK(fs_wedge_relax(&a, NULL, 0) == 0);
    CHECK(fs_wedge_equilibrium(&b, 1.0) == 0);
    CHECK_MSG(a.counters.local_relaxations == 1 && a.counters.global_fallbacks == 0, "%lld fallbacks",
              (long long)a.counters.global_fallbacks);
    CHECK_MSG(a.counters.local_dofs > 0 && a.counters.local_dofs * 10 < a.n_free,
              "%lld local unknowns of %d", (long long)a.counters.local_dofs, (int)a.n_free);
    CHECK(u_diff(&a, &b) < cfg.solver.relax_tolerance);
    CHECK(stress_diff(&a, &b) < cfg.solver.relax_tolerance);
    fs_wedge_free(&a);
    fs_wedge_free(&b);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_local_matches_global);
    RUN(test_crack_is_barrier);
    RUN(test_radius_control);
    RUN(test_far_change_is_local);
    RUN(test_stalled_cg_falls_back);
    return check_finish();
}
