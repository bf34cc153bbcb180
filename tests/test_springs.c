/* Tests of the springs model: relaxation, uniform strain on periodic lattices, crack directions, fracture invariants, the 3-D post-process. */
#include "model/springs/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "check.h"
#include "geom/delaunay.h"
#include "geom/sample.h"

/* ---- set-up ---- */

static fs_domain square(double side, bool periodic)
{
    fs_domain d = fs_domain_default();
    d.width = d.height = side;
    d.periodic_x = d.periodic_y = periodic;
    fs_domain_normalize(&d);
    return d;
}

/* A Delaunay mesh of `count` points on d: particle repulsion or the hexagonal lattice. */
static bool make_mesh(const fs_domain *d, int32_t count, bool hex, uint64_t seed, fs_mesh *m)
{
    fs_points pts = {0};
    int rc;
    if (hex) {
        rc = fs_sample_hex(d, count, &pts);
    } else {
        fs_sample_params sp = fs_sample_params_default();
        sp.count = count;
        sp.seed = seed;
        rc = fs_sample_repulsion(d, &sp, &pts);
    }
    if (rc == 0)
        rc = fs_delaunay(d, &pts, m);
    fs_points_free(&pts);
    CHECK_MSG(rc == 0, "mesh: %s", fs_error_message());
    return rc == 0;
}

static fs_pwl ramp(double v_end)
{
    fs_pwl f;
    memset(&f, 0, sizeof f);
    f.n = 2;
    f.t[0] = 0.0;
    f.v[0] = 0.0;
    f.t[1] = 1.0;
    f.v[1] = v_end;
    return f;
}

static fs_pwl constant(double v)
{
    fs_pwl f;
    memset(&f, 0, sizeof f);
    f.n = 1;
    f.t[0] = 0.0;
    f.v[0] = v;
    return f;
}

/* Break strain 0.01 (threshold 100 kPa on 10 MPa), no jitter, static background, time [0, 1]. */
static fs_model_setup base_setup(void)
{
    fs_model_setup st = fs_model_setup_default();
    st.kind = FS_MODEL_SPRINGS;
    st.springs = fs_springs_params_default();
    st.material = fs_material_default();
    st.material.young = 10.0;
    st.material.threshold = 100.0;
    st.material.thickness = 0.3;
    st.material.jitter = 0.0;
    st.growth = fs_growth_default();
    st.shrink = fs_shrink_default();
    st.time.end = 1.0;
    st.time.min_step = 1e-3;
    st.seed = 7;
    return st;
}

static bool all_finite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return false;
    return true;
}

/* Angle (degrees, in [0, 180)) of a direction in the plane. */
static double direction_angle(const double *dir)
{
    double a = atan2(dir[1], dir[0]) * 180.0 / FS_PI;
    if (a < 0.0)
        a += 180.0;
    if (a >= 180.0)
        a -= 180.0;
    return a;
}

/* ---- relaxation ---- */

/* Relaxation from a disturbed state lowers the energy, monotonically, and ends with every node force
 * under the stated tolerance; the local relaxation after a cut does the same for the whole network. */
static void test_relaxation(void)
{
    fs_domain d = square(6.0, true);
    fs_mesh m = {0};
    if (!make_mesh(&d, 500, false, 3, &m))
        return;
    fs_model_setup st = base_setup();
    st.shrink.top = st.shrink.bottom = constant(0.004);
    st.material.threshold = 1000.0; /* nothing breaks here */
    fs_springs s;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    fs_spring_net *net = &s.net;
    size_t nx = (size_t)net->dim * (size_t)net->n_nodes;
    for (size_t i = 0; i < nx; i++)
        net->x[i] += 0.01 * (2.0 * fs_rand01(1, FS_RNG_TEST, i) - 1.0);
    double tol = 1e-6 * s.force_scale;
    fs_spring_relax_info info;
    CHECK_MSG(fs_spring_net_relax(net, tol, 100, &info) == 0, "%s", fs_error_message());
    CHECK(info.energy_end < info.energy_start);
    CHECK(info.energy_monotone);
    CHECK(info.residual_end <= tol);
    CHECK(fs_spring_net_force(net, NULL) <= tol);
    CHECK(all_finite(net->x, nx));
    CHECK(info.iterations >= 1);

    /* cut one spring: the local relaxation restores the balance of every node */
    double e_before = fs_spring_net_energy(net);
    fs_spring_net_cut(net, 17);
    double e_cut = fs_spring_net_energy(net);
    CHECK(e_cut < e_before); /* the cut spring's stretch energy is gone */
    int32_t seeds[2] = {net->node[34], net->node[35]};
    CHECK(fs_spring_net_force(net, NULL) > tol);
    CHECK_MSG(fs_spring_net_relax_local(net, seeds, 2, tol, &info) == 0, "%s", fs_error_message());
    CHECK(fs_spring_net_force(net, NULL) <= tol);
    CHECK(fs_spring_net_energy(net) < e_cut);
    CHECK(info.energy_monotone);
    CHECK(all_finite(net->x, nx));
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

/* A periodic hexagonal lattice under uniform shrinkage s stays where its anchors are and every spring,
 * seam-crossing ones included, has strain s / (1 - s): the network wraps. Planar isogonic growth of
 * the background at rate r stretches every spring by e^(r t) - 1 and moves every mass with it. */
static void test_uniform_strain_periodic(void)
{
    fs_domain d = square(5.0, true);
    fs_mesh m = {0};
    if (!make_mesh(&d, 400, true, 1, &m))
        return;
    fs_model_setup st = base_setup();
    st.material.threshold = 1000.0; /* break strain 0.1: nothing breaks */
    double shrink = 0.03;
    st.shrink.top = st.shrink.bottom = constant(shrink);
    fs_springs s;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    double worst = fs_springs_equilibrate(&s, 0.5);
    double want = shrink / (1.0 - shrink) / 0.1;
    CHECK_NEAR(worst, want, 1e-9);
    int32_t seam = 0;
    double spread = 0.0, moved = 0.0;
    for (int32_t i = 0; i < s.n_material; i++) {
        if (s.broken[i])
            continue;
        spread = fmax(spread, fabs(s.ratio[i] - want));
        seam += s.ref_offset[2 * (size_t)i] != 0.0 || s.ref_offset[2 * (size_t)i + 1] != 0.0;
    }
    for (int32_t i = 0; i < s.n; i++)
        moved = fmax(moved, hypot(s.net.x[2 * i] - m.pos[3 * i], s.net.x[2 * i + 1] - m.pos[3 * i + 1]));
    CHECK(seam > 0);
    CHECK_MSG(spread <= 1e-9, "ratio spread %g", spread);
    CHECK_MSG(moved <= 1e-9, "masses moved %g cm", moved);
    fs_springs_free(&s);

    st = base_setup();
    st.material.threshold = 1000.0;
    st.growth.type = FS_GROWTH_PLANAR;
    st.growth.r1 = st.growth.r2 = 0.05;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    worst = fs_springs_equilibrate(&s, 1.0);
    want = (exp(0.05) - 1.0) / 0.1;
    CHECK_NEAR(worst, want, 1e-9);
    spread = 0.0;
    moved = 0.0;
    for (int32_t i = 0; i < s.n_material; i++)
        if (!s.broken[i])
            spread = fmax(spread, fabs(s.ratio[i] - want));
    for (int32_t i = 0; i < s.n; i++) {
        double p[3] = {m.pos[3 * i], m.pos[3 * i + 1], 0.0}, q[3];
        fs_growth_flow(&s.growth, p, 0.0, 1.0, q);
        moved = fmax(moved, hypot(s.net.x[2 * i] - q[0], s.net.x[2 * i + 1] - q[1]));
    }
    CHECK_MSG(spread <= 1e-9, "ratio spread under growth %g", spread);
    CHECK_MSG(moved <= 1e-9, "masses off the grown background by %g cm", moved);
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

/* ---- fracture ---- */

/* A hexagonal lattice under isotropic shrinkage breaks springs in the lattice's three directions only,
 * and in all three about equally (thesis §4.2, Fig. 4.5). On a non-periodic plane the Delaunay mesh
 * also holds edges in other directions along the border (the hull of the lattice's zig-zag sides);
 * any of those that break lie on the border, where the lattice ends. */
static void test_hex_three_directions(void)
{
    fs_domain d = square(6.0, false);
    fs_mesh m = {0};
    if (!make_mesh(&d, 700, true, 1, &m))
        return;
    fs_model_setup st = base_setup();
    st.material.jitter = 0.05;
    st.shrink.top = st.shrink.bottom = ramp(0.05);
    st.springs.slide_length = 0.02;
    st.springs.residual = 1e-2;
    st.springs.max_breaks = 250;
    fs_springs s;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    CHECK_MSG(fs_springs_advance(&s, 1.0) == 0, "%s", fs_error_message());
    /* the lattice's directions: the most common edge angle and +-60 degrees */
    int bins[180] = {0};
    for (int32_t e = 0; e < s.n_edges; e++) {
        double dir[3];
        fs_springs_direction(&s, e, dir);
        bins[(int)direction_angle(dir) % 180]++;
    }
    int best = 0;
    for (int a = 1; a < 180; a++)
        if (bins[a] > bins[best])
            best = a;
    int32_t other_edges = 0, count[3] = {0, 0, 0}, stray = 0;
    for (int32_t e = 0; e < s.n_edges; e++) {
        double dir[3];
        fs_springs_direction(&s, e, dir);
        double a = direction_angle(dir);
        bool lattice = false;
        for (int k = 0; k < 3; k++) {
            double diff = fabs(fmod(a - best - 60.0 * k + 540.0, 180.0) - 0.0);
            diff = fmin(diff, 180.0 - diff);
            lattice = lattice || diff < 3.0;
        }
        other_edges += !lattice;
    }
    for (int32_t b = 0; b < s.break_count; b++) {
        double dir[3];
        fs_springs_direction(&s, s.breaks[b].spring, dir);
        double a = direction_angle(dir);
        int which = -1;
        for (int k = 0; k < 3; k++) {
            double diff = fabs(fmod(a - best - 60.0 * k + 540.0, 180.0));
            diff = fmin(diff, 180.0 - diff);
            if (diff < 3.0)
                which = k;
        }
        int32_t e = s.breaks[b].spring % s.n_edges;
        bool border = m.edge_tri[2 * e + 1] < 0;
        for (int k = 0; k < 2 && !border; k++) {
            int32_t t = m.edge_tri[2 * e + k];
            for (int j = 0; j < 3; j++)
                border = border || m.adj[3 * t + j] < 0;
        }
        if (which >= 0)
            count[which]++;
        else if (!border)
            stray++;
    }
    CHECK_MSG(s.break_count >= 100, "only %d breaks", (int)s.break_count);
    CHECK_MSG(other_edges > 0, "the border holds no off-lattice edges to test against");
    CHECK_MSG(stray == 0, "%d broken springs off the lattice directions away from the border", (int)stray);
    for (int k = 0; k < 3; k++)
        CHECK_MSG(count[k] >= s.break_count / 6, "direction %d: %d of %d breaks", k, (int)count[k],
                  (int)s.break_count);
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

/* A random mesh on a cylinder growing around its axis breaks mostly the springs that lie around the
 * trunk, so the cracks (the dual Voronoi edges) run along the axis. */
static void test_cylinder_axis(void)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_CYLINDER;
    d.radius = 1.0;
    d.height = 2.0 * FS_PI;
    fs_domain_normalize(&d);
    fs_mesh m = {0};
    if (!make_mesh(&d, 700, false, 5, &m))
        return;
    fs_model_setup st = base_setup();
    st.material.jitter = 0.1;
    st.growth.type = FS_GROWTH_CYLINDER;
    st.growth.rate = 0.2;
    st.springs.residual = 1e-2;
    st.springs.max_breaks = 150;
    fs_springs s;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    CHECK_MSG(fs_springs_advance(&s, 1.0) == 0, "%s", fs_error_message());
    int32_t around = 0, around_all = 0;
    double mean_cos = 0.0;
    for (int32_t b = 0; b < s.break_count; b++) {
        double dir[3];
        fs_springs_direction(&s, s.breaks[b].spring, dir);
        double c = fabs(dir[0]);
        mean_cos += c;
        around += c > cos(30.0 * FS_PI / 180.0);
    }
    for (int32_t e = 0; e < s.n_edges; e++) {
        double dir[3];
        fs_springs_direction(&s, e, dir);
        around_all += fabs(dir[0]) > cos(30.0 * FS_PI / 180.0);
    }
    mean_cos /= s.break_count > 0 ? s.break_count : 1;
    double frac = (double)around / (s.break_count > 0 ? s.break_count : 1);
    double frac_all = (double)around_all / s.n_edges;
    CHECK_MSG(s.break_count >= 100, "only %d breaks", (int)s.break_count);
    CHECK_MSG(frac >= 0.7, "%.2f of the broken springs lie within 30 degrees of the circumference", frac);
    CHECK_MSG(frac_all < 0.45, "%.2f of all springs lie around (the mesh is not isotropic)", frac_all);
    CHECK_MSG(mean_cos >= 0.8, "mean |cos| to the circumference %.3f", mean_cos);
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

/* What the event loop guarantees: each break was over its threshold when it broke, breaks come in
 * time order, the final state is an equilibrium with every intact ratio <= 1, and nothing is NaN. */
static void test_fracture_invariants(void)
{
    fs_domain d = square(8.0, true);
    fs_mesh m = {0};
    if (!make_mesh(&d, 800, false, 11, &m))
        return;
    fs_model_setup st = base_setup();
    st.material.jitter = 0.1;
    st.shrink.top = st.shrink.bottom = ramp(0.03);
    st.springs.slide_length = 0.02;
    st.springs.residual = 1e-3;
    fs_springs s;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    CHECK_MSG(fs_springs_advance(&s, 1.0) == 0, "%s", fs_error_message());
    CHECK(s.break_count > 0);
    CHECK_NEAR(s.time, 1.0, 0.0);
    bool over = true, ordered = true;
    for (int32_t b = 0; b < s.break_count; b++) {
        over = over && s.breaks[b].ratio > 1.0;
        ordered = ordered && (b == 0 || s.breaks[b].time >= s.breaks[b - 1].time);
    }
    CHECK(over);
    CHECK(ordered);
    /* the first break comes when the weakest spring's threshold is first reached: the shrinkage
     * ramp makes every strain about 0.03 t / (1 - 0.03 t), and the jitter lowers thresholds by <= 10% */
    double t_first = s.breaks[0].time, strain = 0.03 * t_first / (1.0 - 0.03 * t_first);
    CHECK_MSG(strain > 0.009 * 0.85 && strain < 0.01 * 1.05, "first break at strain %g", strain);
    double worst = -INFINITY;
    for (int32_t i = 0; i < s.n_material; i++)
        if (!s.broken[i])
            worst = fmax(worst, s.ratio[i]);
    CHECK(worst <= 1.0);
    CHECK(fs_spring_net_force(&s.net, NULL) <= st.springs.residual * s.force_scale);
    CHECK(all_finite(s.net.x, (size_t)s.dim * (size_t)s.net.n_nodes));
    int32_t *label = malloc((size_t)s.n * sizeof *label);
    int32_t fragments = fs_springs_fragments(&s, label);
    CHECK(fragments >= 1 && fragments <= s.n);
    for (int32_t i = 0; i < s.n; i++)
        CHECK(label[i] <= i && label[label[i]] == label[i]);
    free(label);
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

/* Same seed, identical breaks, positions and render mesh; another seed, other breaks. */
static void run_small(uint64_t seed, fs_springs *s, fs_surface *r, fs_mesh *m)
{
    fs_model_setup st = base_setup();
    st.seed = seed;
    st.material.jitter = 0.1;
    st.shrink.top = st.shrink.bottom = ramp(0.04);
    st.springs.slide_length = 0.02;
    st.springs.residual = 1e-2;
    CHECK_MSG(fs_springs_init(s, m, &st) == 0, "%s", fs_error_message());
    CHECK_MSG(fs_springs_advance(s, 1.0) == 0, "%s", fs_error_message());
    memset(r, 0, sizeof *r);
    CHECK_MSG(fs_springs_surface(s, r) == 0, "%s", fs_error_message());
}

static bool same_breaks(const fs_springs *a, const fs_springs *b)
{
    if (a->break_count != b->break_count)
        return false;
    for (int32_t k = 0; k < a->break_count; k++)
        if (a->breaks[k].spring != b->breaks[k].spring || memcmp(&a->breaks[k].time, &b->breaks[k].time, sizeof(double)) ||
            memcmp(&a->breaks[k].ratio, &b->breaks[k].ratio, sizeof(double)))
            return false;
    return true;
}

static void test_determinism(void)
{
    fs_domain d = square(6.0, true);
    fs_mesh m = {0};
    if (!make_mesh(&d, 400, false, 2, &m))
        return;
    fs_springs a, b, c;
    fs_surface ra, rb, rc;
    run_small(5, &a, &ra, &m);
    run_small(5, &b, &rb, &m);
    run_small(6, &c, &rc, &m);
    CHECK(a.break_count > 10 && a.break_count == b.break_count);
    CHECK(same_breaks(&a, &b));
    CHECK(memcmp(a.net.x, b.net.x, (size_t)a.dim * (size_t)a.net.n_nodes * sizeof *a.net.x) == 0);
    CHECK(ra.n_verts == rb.n_verts && ra.n_tris == rb.n_tris);
    if (ra.n_verts == rb.n_verts && ra.n_tris == rb.n_tris) {
        CHECK(memcmp(ra.uv, rb.uv, 2 * (size_t)ra.n_verts * sizeof *ra.uv) == 0);
        CHECK(memcmp(ra.height, rb.height, (size_t)ra.n_verts * sizeof *ra.height) == 0);
        CHECK(memcmp(ra.tri, rb.tri, 3 * (size_t)ra.n_tris * sizeof *ra.tri) == 0);
    }
    CHECK(!same_breaks(&a, &c));
    fs_surface_free(&ra);
    fs_surface_free(&rb);
    fs_surface_free(&rc);
    fs_springs_free(&a);
    fs_springs_free(&b);
    fs_springs_free(&c);
    fs_mesh_free(&m);
}

/* ---- the 3-D post-process ---- */

/* Heights of the render mesh: tops at most the thickness; crack walls (crack = 1) reach down to the
 * glued level, so with three layers and cracks through the top layer only, walls end at two thirds
 * of the thickness (flat mode places the levels exactly), and full-depth cracks reach the bottom. */
static void test_render_depth(void)
{
    fs_domain d = square(6.0, true);
    fs_mesh m = {0};
    if (!make_mesh(&d, 400, false, 4, &m))
        return;
    fs_model_setup st = base_setup();
    st.material.jitter = 0.05;
    st.material.thickness = 0.45;
    st.shrink.top = ramp(0.05);
    st.shrink.bottom = ramp(0.035);
    st.springs.layers = 3;
    st.springs.slide_length = 0.03;
    st.springs.residual = 1e-2;
    st.springs.post = FS_SPRINGS_POST_FLAT;
    fs_springs s;
    CHECK_MSG(fs_springs_init(&s, &m, &st) == 0, "%s", fs_error_message());
    CHECK_MSG(fs_springs_advance(&s, 1.0) == 0, "%s", fs_error_message());
    int32_t partial = 0, full = 0, ne = s.n_edges;
    for (int32_t e = 0; e < ne; e++) {
        bool top = s.broken[2 * ne + e], mid = s.broken[ne + e], bottom = s.broken[e];
        partial += top && !mid && m.edge[2 * e] != m.edge[2 * e + 1];
        full += top && mid && bottom;
    }
    CHECK_MSG(partial > 0 && full > 0, "%d partial-depth and %d full-depth cracks", (int)partial, (int)full);
    fs_surface r = {0};
    CHECK_MSG(fs_springs_surface(&s, &r) == 0, "%s", fs_error_message());
    /* level 2 of 3 at its shrinkage: 0.45 * 2/3 * (1 - (0.035 + 0.015 * 2/3)) */
    double level2 = 0.45 * 2.0 / 3.0 * (1.0 - (0.035 + 0.015 * 2.0 / 3.0));
    int32_t at_level2 = 0, at_bottom = 0;
    double top_max = 0.0;
    bool finite = true, inside = true;
    for (int32_t v = 0; v < r.n_verts; v++) {
        double h = r.height[v];
        finite = finite && isfinite(h) && isfinite(r.uv[2 * v]) && isfinite(r.uv[2 * v + 1]);
        inside = inside && r.uv[2 * v] > -1.0 && r.uv[2 * v] < 2.0 && r.uv[2 * v + 1] > -1.0 && r.uv[2 * v + 1] < 2.0;
        if (r.crack[v] > 0.5) {
            at_level2 += fabs(h - level2) < 1e-6;
            at_bottom += h < 1e-9;
        } else {
            top_max = fmax(top_max, h);
            CHECK(r.cell[v] >= 1.0 && r.cell[v] <= 65535.0);
        }
    }
    CHECK(finite);
    CHECK(inside);
    CHECK(at_level2 > 0);
    CHECK(at_bottom > 0);
    CHECK(top_max <= 0.45 + 1e-9);
    fs_surface_free(&r);

    /* relaxed: glued walls keep the tops at most the thickness; curl mode lifts the rims above */
    double max_glue = 0.0, max_curl = 0.0;
    for (int mode = 0; mode < 2; mode++) {
        s.setup.springs.post = mode ? FS_SPRINGS_POST_CURL : FS_SPRINGS_POST_GLUE;
        s.setup.springs.peel = 1.0;
        memset(&r, 0, sizeof r);
        CHECK_MSG(fs_springs_surface(&s, &r) == 0, "%s", fs_error_message());
        double hmax = 0.0;
        for (int32_t v = 0; v < r.n_verts; v++) {
            CHECK(isfinite(r.height[v]));
            if (r.crack[v] < 0.5)
                hmax = fmax(hmax, r.height[v]);
        }
        *(mode ? &max_curl : &max_glue) = hmax;
        fs_surface_free(&r);
    }
    CHECK_MSG(max_glue <= 0.45, "glued tops reach %g cm", max_glue);
    CHECK_MSG(max_curl > max_glue, "curl %g cm, glue %g cm", max_curl, max_glue);
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

/* ---- errors ---- */

static void test_bad_parameters(void)
{
    fs_domain d = square(4.0, true);
    fs_mesh m = {0};
    if (!make_mesh(&d, 100, false, 1, &m))
        return;
    fs_springs s;
    fs_model_setup st = base_setup();
    st.springs.layers = 0;
    CHECK(fs_springs_init(&s, &m, &st) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA && strstr(fs_error_message(), "[springs] layers"));
    fs_springs_free(&s);
    st = base_setup();
    st.springs.residual = 0.5;
    CHECK(fs_springs_init(&s, &m, &st) == -1);
    CHECK(strstr(fs_error_message(), "[springs] residual") != NULL);
    fs_springs_free(&s);
    st = base_setup();
    st.growth.type = FS_GROWTH_SPHERE;
    CHECK(fs_springs_init(&s, &m, &st) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    fs_springs_free(&s);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_relaxation);
    RUN(test_uniform_strain_periodic);
    RUN(test_hex_three_directions);
    RUN(test_cylinder_axis);
    RUN(test_fracture_invariants);
    RUN(test_determinism);
    RUN(test_render_depth);
    RUN(test_bad_parameters);
    return check_finish();
}
