/* Tests of the wedge model around crack tips: refinement by von Mises discontinuity, crack-tip sub-models, angle-based smoothing (thesis §5.7.7-5.7.9). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "check.h"
#include "setup.h"
#include "wedge_fixture.h"
#include "geom/delaunay.h"
#include "geom/refine.h"
#include "geom/sample.h"
#include "model/wedge/internal.h"

/* The strip of wedge_fixture.h, relaxed to a tight tolerance. */
static fs_config strip_config(void)
{
    fs_config c = wedge_strip_config();
    c.solver.relax_tolerance = 1e-6;
    return c;
}

/* Brings the layer just over its threshold, then runs events (relaxing after each) until one crack
 * has made `events` cuts: a short straight crack across the stretch with two tips. */
static void grow_crack(fs_wedge_model *w, int events)
{
    double t = 0.0;
    while (t < 1.0) {
        t += 0.01;
        CHECK(fs_wedge_equilibrium(w, t) == 0);
        if (fs_wedge_split_max_ratio(w) > 1.0)
            break;
    }
    for (int k = 0; k < events; k++) {
        int changed = 0;
        if (fs_wedge_split_event(w, &changed) != 0 || !changed)
            break;
        CHECK(fs_wedge_relax(w, NULL, 0) == 0);
    }
}

/* The crack walls of a mesh: its boundary half-edges as segments (unwrapped corner positions). */
typedef struct {
    int32_t n;
    double *seg; /* 4 per wall: a.x, a.y, b.x, b.y */
} walls;

static walls walls_of(const fs_mesh *m)
{
    walls wl = {0, malloc(sizeof(double) * 4 * (3 * (size_t)m->n_tris + 1))};
    for (int32_t h = 0; h < 3 * m->n_tris; h++) {
        if (m->adj[h] >= 0)
            continue;
        double a[3], b[3];
        fs_mesh_corner(m, h / 3, h % 3, a);
        fs_mesh_corner(m, h / 3, (h % 3 + 1) % 3, b);
        double *s = wl.seg + 4 * (size_t)wl.n++;
        s[0] = a[0], s[1] = a[1], s[2] = b[0], s[3] = b[1];
    }
    return wl;
}

/* Checks the mesh is a valid, conforming cracked layer after refinement: every triangle has a
 * positive area, the adjacency is symmetric and equals a fresh build from the triangles, and every
 * boundary half-edge lies on (and runs along) a crack wall of the mesh before: a hanging node inside
 * the material would leave boundary edges where there was no crack. (Bisection may split a wall on
 * one side of a crack only: the walls are free surfaces, so the two sides need not match.) */
static void check_conforming(const fs_mesh *m, const walls *before)
{
    int32_t bad_area = 0, bad_adj = 0, stray = 0;
    for (int32_t t = 0; t < m->n_tris; t++) {
        if (!(fs_mesh_tri_area(m, t) > 0.0))
            bad_area++;
        for (int i = 0; i < 3; i++) {
            int32_t u = m->adj[3 * t + i];
            if (u < 0)
                continue;
            bool back = false;
            for (int j = 0; j < 3; j++)
                back |= m->adj[3 * u + j] == t;
            bad_adj += !back;
        }
    }
    CHECK_MSG(bad_area == 0, "%d triangles with non-positive area", (int)bad_area);
    CHECK_MSG(bad_adj == 0, "%d one-sided adjacencies", (int)bad_adj);
    fs_mesh fresh = {0};
    fresh.domain = m->domain;
    fresh.n_nodes = m->n_nodes;
    fresh.pos = malloc(sizeof(double) * 3 * (size_t)m->n_nodes);
    memcpy(fresh.pos, m->pos, sizeof(double) * 3 * (size_t)m->n_nodes);
    fresh.n_tris = m->n_tris;
    fresh.tri = malloc(sizeof(int32_t) * 3 * (size_t)m->n_tris);
    memcpy(fresh.tri, m->tri, sizeof(int32_t) * 3 * (size_t)m->n_tris);
    if (m->shift) {
        fresh.shift = malloc(6 * (size_t)m->n_tris);
        memcpy(fresh.shift, m->shift, 6 * (size_t)m->n_tris);
    }
    CHECK(fs_mesh_build_adjacency(&fresh) == 0);
    CHECK(memcmp(fresh.adj, m->adj, sizeof(int32_t) * 3 * (size_t)m->n_tris) == 0);
    fs_mesh_free(&fresh);
    double ex = fs_domain_extent_x(&m->domain), ey = fs_domain_extent_y(&m->domain);
    walls now = walls_of(m);
    for (int32_t q = 0; q < now.n; q++) {
        const double *c = now.seg + 4 * (size_t)q;
        bool on = false;
        for (int32_t r = 0; r < before->n && !on; r++) {
            const double *s = before->seg + 4 * (size_t)r;
            double ox = round((c[0] - s[0]) / ex) * ex, oy = round((c[1] - s[1]) / ey) * ey;
            double dx = s[2] - s[0], dy = s[3] - s[1], l2 = dx * dx + dy * dy;
            bool ok = true;
            for (int k = 0; k < 2 && ok; k++) {
                double px = c[2 * k] - ox - s[0], py = c[2 * k + 1] - oy - s[1];
                double along = (px * dx + py * dy) / l2, across = fabs(px * dy - py * dx) / sqrt(l2);
                ok = across < 1e-9 && along > -1e-9 && along < 1.0 + 1e-9;
            }
            on = ok && (c[2] - c[0]) * dx + (c[3] - c[1]) * dy > 0.0;
        }
        stray += !on;
    }
    free(now.seg);
    CHECK_MSG(stray == 0, "%d boundary edges off the crack walls (hanging nodes)", (int)stray);
}

static double total_area(const fs_mesh *m)
{
    double a = 0.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        a += fs_mesh_tri_area(m, t);
    return a;
}

/* Nodes on a crack wall (a boundary edge of the periodic mesh). */
static uint8_t *crack_nodes(const fs_mesh *m)
{
    uint8_t *on = calloc((size_t)m->n_nodes, 1);
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        if (m->adj[h] < 0) {
            on[m->tri[h]] = 1;
            on[m->tri[3 * (h / 3) + (h % 3 + 1) % 3]] = 1;
        }
    return on;
}

/* Shortest periodic distance from point p to any flagged node. */
static double distance_to(const fs_mesh *m, const uint8_t *flag, int32_t n_flag_nodes, const double *p)
{
    double best = INFINITY;
    for (int32_t i = 0; i < n_flag_nodes; i++) {
        if (!flag[i])
            continue;
        double d[3];
        fs_domain_delta(&m->domain, p, m->pos + 3 * (size_t)i, d);
        best = fmin(best, hypot(d[0], d[1]));
    }
    return best;
}

/* Largest entry of f - K u over the free DOFs, from the assembled system, and the acceptance bound of
 * local relaxation (solver.relax_tolerance times the root mean square of f). */
static double max_residual(const fs_wedge_model *w, double *tau)
{
    int32_t nf = w->n_free;
    double coef[FS_WEDGE_PATTERNS] = {w->shrink_coef[0], w->shrink_coef[1], w->shrink_coef[2],
                                      w->eigenstrain[0], w->eigenstrain[1], w->eigenstrain[2]};
    double *f = calloc((size_t)nf + 1, sizeof *f), *ku = calloc((size_t)nf + 1, sizeof *ku);
    double *x = calloc((size_t)nf + 1, sizeof *x);
    for (int32_t i = 0; i < w->n_nodes; i++)
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g < nf)
                x[g] = w->u[6 * (size_t)i + l];
        }
    for (int32_t i = 0; i < nf; i++)
        for (int q = 0; q < FS_WEDGE_PATTERNS; q++)
            f[i] += coef[q] * w->load[FS_WEDGE_PATTERNS * (size_t)i + q];
    const fs_sparse_matrix *k = &w->k_free;
    for (int32_t j = 0; j < nf; j++)
        for (int32_t p = k->col_ptr[j]; p < k->col_ptr[j + 1]; p++) {
            int32_t i = k->row_idx[p];
            ku[i] += k->values[p] * x[j];
            if (i != j)
                ku[j] += k->values[p] * x[i];
        }
    const fs_wedge_coupling *c = &w->k_fb;
    for (int32_t col = 0; col < c->n; col++)
        for (int32_t p = c->start[col]; p < c->start[col] + c->len[col]; p++)
            f[c->row[p]] -= c->value[p] * w->u_fixed[col];
    double worst = 0.0, f2 = 0.0;
    for (int32_t i = 0; i < nf; i++) {
        worst = fmax(worst, fabs(f[i] - ku[i]));
        f2 += f[i] * f[i];
    }
    *tau = w->cfg.solver.relax_tolerance * sqrt(f2 / nf);
    free(f);
    free(ku);
    free(x);
    return worst;
}

/* ---- §5.7.7 ---- */

/* The largest indicator among the nodes farther than dist from every tip. */
static double indicator_away(const fs_wedge_model *w, const double *ind, double dist)
{
    uint8_t *tip = calloc((size_t)w->n_nodes, 1);
    for (int32_t k = 0; k < w->n_tips; k++)
        tip[w->tip_node[k]] = 1;
    double best = 0.0;
    for (int32_t i = 0; i < w->n_nodes; i++)
        if (!isnan(ind[i]) && distance_to(w->mesh, tip, w->n_nodes, w->mesh->pos + 3 * (size_t)i) > dist)
            best = fmax(best, ind[i]);
    free(tip);
    return best;
}

/* Around a short crack in a stretched layer the von Mises stresses of a node's elements disagree;
 * rounds of Algorithm 13 bisect there and nowhere far from the crack, keep the mesh conforming and
 * its area, and bring the indicator below the threshold everywhere but at the crack tips, where the
 * stress is singular (the indicator there does not vanish under refinement, see wedge/tips.c). */
static void test_vm_refinement(void)
{
    const double threshold = 0.25;
    fs_config cfg = strip_config();
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    grow_crack(&w, 3);
    CHECK(fs_wedge_equilibrium(&w, w.time) == 0);
    CHECK(w.n_tips == 2);
    double unit = fs_wedge_tips_unit(&w);
    uint8_t *crack = crack_nodes(&m);
    int32_t n0 = w.n_nodes;
    double area0 = total_area(&m);
    walls walls0 = walls_of(&m);
    double *ind = malloc(sizeof *ind * (size_t)w.n_nodes);
    double largest = fs_wedge_vm_discontinuity(&w, ind), away = indicator_away(&w, ind, unit);
    /* without a crack the layer is uniform: nothing to refine */
    int32_t far_over = 0;
    for (int32_t i = 0; i < w.n_nodes; i++)
        far_over += ind[i] > threshold && distance_to(&m, crack, n0, m.pos + 3 * (size_t)i) > 2.0 * unit;
    printf("before: largest indicator %.3f, %.3f beyond one edge length from the tips\n", largest, away);
    CHECK_MSG(away > threshold, "indicator away from the tips %.3f: nothing to test", away);
    CHECK_MSG(far_over == 0, "%d nodes over the threshold far from the crack", (int)far_over);
    w.cfg.mesh.min_size = 0.25 * unit;
    for (int round = 1; round <= 3; round++) {
        int32_t bisected = 0;
        CHECK(fs_wedge_refine_vm(&w, threshold, 1, &bisected) == 0);
        ind = realloc(ind, sizeof *ind * (size_t)w.n_nodes);
        largest = fs_wedge_vm_discontinuity(&w, ind);
        double now = indicator_away(&w, ind, unit), far = 0.0;
        for (int32_t i = n0; i < w.n_nodes; i++)
            far = fmax(far, distance_to(&m, crack, n0, m.pos + 3 * (size_t)i));
        printf("round %d: %d bisections, %d elements, largest indicator %.3f, %.3f beyond one edge length from the "
               "tips; new nodes at most %.2f edge lengths from the crack\n",
               round, (int)bisected, (int)w.n_elems, largest, now, far / unit);
        CHECK(bisected > 0);
        CHECK_MSG(far < 2.5 * unit, "a new node %.2f edge lengths from the crack", far / unit);
        CHECK_MSG(now < away, "round %d: indicator away from the tips %.3f, was %.3f", round, now, away);
        away = now;
    }
    CHECK_MSG(away < threshold, "indicator away from the tips still %.3f", away);
    CHECK(w.counters.vm_rounds == 3 && w.counters.vm_bisections > 0);
    check_conforming(&m, &walls0);
    CHECK_NEAR(total_area(&m), area0, 1e-9 * area0);
    free(walls0.seg);
    free(crack);
    free(ind);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* The coarse estimate at a tip (wedge/split.c): the largest ratio among its elements' top Gauss points
 * nearest it. */
static double coarse_estimate(const fs_wedge_model *w, int32_t tip)
{
    double best = -INFINITY;
    for (int32_t p = w->node_elem_start[tip]; p < w->node_elem_start[tip] + w->node_elem_count[tip]; p++) {
        int32_t e = w->node_elem[p];
        int c = 0;
        while (w->mesh->tri[3 * (size_t)e + c] != tip)
            c++;
        double sigma[3];
        CHECK(fs_eigen_principal_stress(w->stress_top + 18 * (size_t)e + 6 * c, sigma, NULL) == 0);
        best = fmax(best, sigma[0] / w->threshold[e]);
    }
    return best;
}

/* ---- §5.7.8 ---- */

/* At the tip of a straight crack across a uniaxially stretched layer: without refinement the
 * sub-model reproduces the layer's nodal stress (its rim is held at the layer's solution); refined,
 * the tip stress exceeds the coarse average (and, from an eighth of an edge length, the coarse
 * estimate) and grows as the elements shrink like size^-alpha with an exponent that settles near the
 * 1/2 of a sharp crack's 1/sqrt(r) field: the refinement resolves the crack-tip concentration, whose
 * peak is singular, so the tip stress itself has no limit; the result converges in the sub-model's
 * radius (the layer beyond it does not matter); and the principal direction stays along the
 * stretch, so the crack runs across it. */
static void test_submodel(void)
{
    fs_config cfg = strip_config();
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    grow_crack(&w, 3);
    CHECK(fs_wedge_equilibrium(&w, w.time) == 0);
    CHECK(w.n_tips == 2);
    double unit = fs_wedge_tips_unit(&w);
    int32_t tip = w.tip_node[0], elems0 = w.n_elems;
    double estimate = coarse_estimate(&w, tip);
    double ratio, mdir[3];
    fs_wedge_submodel_info info;
    CHECK(fs_wedge_tip_submodel(&w, tip, 4.0 * unit, 10.0 * unit, &ratio, mdir, &info) == 0);
    printf("no refinement: ratio %.6f, layer's nodal ratio %.6f, coarse estimate %.4f, %d elements\n", ratio,
           info.coarse_ratio, estimate, (int)info.elems);
    CHECK(info.bisections == 0 && info.elems == info.extracted_elems);
    CHECK_NEAR(ratio, info.coarse_ratio, 1e-6 * fabs(info.coarse_ratio));
    double coarse = info.coarse_ratio;

    double sizes[] = {0.25, 0.125, 0.0625, 0.03125};
    double prev_ratio = 0.0, prev_size = 0.0, prev_alpha = NAN;
    for (size_t k = 0; k < sizeof sizes / sizeof sizes[0]; k++) {
        CHECK(fs_wedge_tip_submodel(&w, tip, 4.0 * unit, sizes[k] * unit, &ratio, mdir, &info) == 0);
        /* the exponent of ratio ~ size^-alpha between this refinement and the last */
        double alpha = k ? log(ratio / prev_ratio) / log(prev_size / info.tip_size) : NAN;
        double off = acos(fmin(1.0, fabs(mdir[0]))) * 57.29577951308232;
        printf("size %.4f edge lengths: tip ratio %.4f, exponent %.3f, %d elements, %d bisections, tip elements up "
               "to %.4f cm, plane normal %.2f degrees off x\n",
               sizes[k], ratio, alpha, (int)info.elems, (int)info.bisections, info.tip_size, off);
        CHECK(info.tip_size < sizes[k] * unit);
        CHECK_MSG(ratio > coarse, "tip ratio %.4f, coarse %.4f", ratio, coarse);
        if (k >= 1)
            CHECK_MSG(ratio > estimate, "tip ratio %.4f, coarse estimate %.4f", ratio, estimate);
        CHECK_MSG(off < 5.0, "principal plane normal %.2f degrees off the stretch", off);
        if (k >= 1)
            CHECK_MSG(alpha > 0.4 && alpha < 0.65, "exponent %.3f", alpha);
        if (k >= 2)
            CHECK_MSG(fabs(alpha - prev_alpha) < 0.03, "exponent %.3f after %.3f", alpha, prev_alpha);
        prev_ratio = ratio;
        prev_size = info.tip_size;
        prev_alpha = alpha;
    }
    double radii[] = {2.0, 4.0, 8.0, 16.0}, last = 0.0, last_change = INFINITY;
    for (size_t k = 0; k < sizeof radii / sizeof radii[0]; k++) {
        CHECK(fs_wedge_tip_submodel(&w, tip, radii[k] * unit, 0.25 * unit, &ratio, NULL, &info) == 0);
        double change = k ? fabs(ratio / last - 1.0) : INFINITY;
        printf("radius %.0f edge lengths: tip ratio %.5f (change %.5f), %d elements\n", radii[k], ratio, change,
               (int)info.elems);
        if (k >= 1)
            CHECK_MSG(change < 0.01 && change <= last_change, "radius %g: change %.5f after %.5f", radii[k], change,
                      last_change);
        last = ratio;
        last_change = k ? change : INFINITY;
    }
    /* the layer is untouched */
    CHECK(w.n_elems == elems0 && w.counters.submodels == 9);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* ---- §5.7.9 ---- */

/* The smallest angle (degrees) of the living triangles with a corner among the listed nodes, and
 * their smallest area. */
static double min_angle_at(const fs_wedge_model *w, const int32_t *nodes, int32_t n, double *min_area)
{
    const fs_mesh *m = w->mesh;
    uint8_t *in = calloc((size_t)w->n_nodes, 1);
    for (int32_t q = 0; q < n; q++)
        in[nodes[q]] = 1;
    double worst = 180.0;
    *min_area = INFINITY;
    for (int32_t t = 0; t < m->n_tris; t++) {
        const int32_t *c = m->tri + 3 * (size_t)t;
        if (!(in[c[0]] || in[c[1]] || in[c[2]]))
            continue;
        double p[3][3];
        for (int k = 0; k < 3; k++)
            fs_mesh_corner(m, t, k, p[k]);
        for (int k = 0; k < 3; k++) {
            const double *a = p[k], *b = p[(k + 1) % 3], *d = p[(k + 2) % 3];
            double u[2] = {b[0] - a[0], b[1] - a[1]}, v[2] = {d[0] - a[0], d[1] - a[1]};
            double ang = atan2(fabs(u[0] * v[1] - u[1] * v[0]), u[0] * v[0] + u[1] * v[1]);
            worst = fmin(worst, ang * 57.29577951308232);
        }
        *min_area = fmin(*min_area, fs_mesh_tri_area(m, t));
    }
    free(in);
    return worst;
}

/* The living elements' top stresses and the displacements agree with a fresh global solve on the
 * same model, to a fraction of their largest values. */
static void check_equilibrium(fs_wedge_model *w, double tol)
{
    double tau, r = max_residual(w, &tau);
    printf("residual %.3g (local relaxation accepts %.3g)\n", r, tau);
    CHECK_MSG(r <= tau, "residual %.3g over the tolerance %.3g", r, tau);
    size_t nu = 6 * (size_t)w->n_nodes;
    double *u = malloc(sizeof *u * nu);
    memcpy(u, w->u, sizeof *u * nu);
    CHECK(fs_wedge_equilibrium(w, w->time) == 0);
    double d = 0.0, s = 0.0;
    for (size_t i = 0; i < nu; i++) {
        d = fmax(d, fabs(u[i] - w->u[i]));
        s = fmax(s, fabs(w->u[i]));
    }
    printf("displacements within %.3g of a global solve (relative)\n", d / s);
    CHECK_MSG(d <= tol * s, "displacements %.3g off a global solve (relative)", d / s);
    free(u);
}

/* An interior node pulled most of the way towards a neighbour makes a patch of slivers; smoothing
 * restores its angles, keeps every area positive, and after local relaxation the layer (with the
 * moved elements' new stiffnesses and reference shapes) is in equilibrium. */
static void test_smooth_distorted(void)
{
    fs_config cfg = strip_config();
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
    /* the node nearest the centre, pulled 60 % of the way to its first neighbour */
    int32_t node = 0;
    for (int32_t i = 1; i < m.n_nodes; i++)
        if (hypot(m.pos[3 * i] - 2.0, m.pos[3 * i + 1] - 2.0) <
            hypot(m.pos[3 * node] - 2.0, m.pos[3 * node + 1] - 2.0))
            node = i;
    int32_t t0 = 0;
    while (m.tri[3 * t0] != node && m.tri[3 * t0 + 1] != node && m.tri[3 * t0 + 2] != node)
        t0++;
    int c = m.tri[3 * t0] == node ? 0 : m.tri[3 * t0 + 1] == node ? 1 : 2;
    double a[3], b[3];
    fs_mesh_corner(&m, t0, c, a);
    fs_mesh_corner(&m, t0, (c + 1) % 3, b);
    for (int k = 0; k < 2; k++)
        m.pos[3 * node + k] += 0.6 * (b[k] - a[k]);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_equilibrium(&w, 0.15) == 0);
    double unit = fs_wedge_tips_unit(&w);
    int32_t *region = malloc(sizeof *region * (size_t)w.n_nodes);
    int32_t n_region = fs_wedge_relax_region(&w, &node, 1, 3.0 * unit, region);
    double area0, before = min_angle_at(&w, region, n_region, &area0);
    CHECK(area0 > 0.0);
    int32_t moved = 0;
    CHECK(fs_wedge_smooth(&w, &node, 1, 3.0 * unit, 3, &moved) == 0);
    double area1, after = min_angle_at(&w, region, n_region, &area1);
    printf("distorted patch: smallest angle %.2f -> %.2f degrees, %d nodes moved, smallest area %.4f -> %.4f cm^2\n",
           before, after, (int)moved, area0, area1);
    CHECK(moved > 0);
    CHECK_MSG(after > before + 10.0, "smallest angle %.2f -> %.2f degrees", before, after);
    CHECK(area1 > 0.0);
    CHECK(fs_wedge_relax(&w, NULL, 0) == 0);
    check_equilibrium(&w, 1e-4);
    free(region);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Around a new crack tip: smoothing never lowers the smallest angle of the elements there, moves no
 * crack node, keeps areas positive, and the layer relaxes back to equilibrium. */
static void test_smooth_tip(void)
{
    fs_config cfg = strip_config();
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    grow_crack(&w, 3);
    CHECK(w.n_tips == 2);
    double unit = fs_wedge_tips_unit(&w);
    int32_t *region = malloc(sizeof *region * (size_t)w.n_nodes);
    int32_t n_region = fs_wedge_relax_region(&w, w.tip_node, w.n_tips, 3.0 * unit, region);
    uint8_t *crack = crack_nodes(&m);
    double *pos0 = malloc(sizeof *pos0 * 3 * (size_t)m.n_nodes);
    memcpy(pos0, m.pos, sizeof *pos0 * 3 * (size_t)m.n_nodes);
    double area0, before = min_angle_at(&w, region, n_region, &area0);
    int32_t moved = 0;
    CHECK(fs_wedge_smooth(&w, w.tip_node, w.n_tips, 3.0 * unit, 3, &moved) == 0);
    double area1, after = min_angle_at(&w, region, n_region, &area1);
    int32_t crack_moved = 0;
    for (int32_t i = 0; i < m.n_nodes; i++)
        crack_moved += crack[i] && memcmp(pos0 + 3 * (size_t)i, m.pos + 3 * (size_t)i, 3 * sizeof *pos0) != 0;
    printf("around the tips: smallest angle %.2f -> %.2f degrees, %d nodes moved, smallest area %.5f -> %.5f cm^2\n",
           before, after, (int)moved, area0, area1);
    CHECK(moved > 0);
    CHECK_MSG(after >= before, "smallest angle %.2f -> %.2f degrees", before, after);
    CHECK(area1 > 0.0);
    CHECK(crack_moved == 0);
    CHECK(fs_wedge_relax(&w, NULL, 0) == 0);
    check_equilibrium(&w, 1e-4);
    free(pos0);
    free(crack);
    free(region);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* ---- in the time loop ---- */

/* Mean direction of the crack walls (degrees from x, doubled-angle average) and its coherence. */
static double crack_angle(const fs_mesh *m, double *coherence, double *length)
{
    double c2 = 0.0, s2 = 0.0, len = 0.0;
    for (int32_t h = 0; h < 3 * m->n_tris; h++) {
        if (m->adj[h] >= 0)
            continue;
        double a[3], b[3];
        fs_mesh_corner(m, h / 3, h % 3, a);
        fs_mesh_corner(m, h / 3, (h % 3 + 1) % 3, b);
        double dx = b[0] - a[0], dy = b[1] - a[1], l = hypot(dx, dy), th = atan2(dy, dx);
        len += l;
        c2 += l * cos(2.0 * th);
        s2 += l * sin(2.0 * th);
    }
    *coherence = len > 0.0 ? hypot(c2, s2) / len : 0.0;
    *length = len;
    return 0.5 * atan2(s2, c2) * 57.29577951308232;
}

/* Each feature on in a run of the stretched layer: the cracks still run across the stretch, the mesh
 * stays valid, and the feature did its work (counters). */
static void test_simulation(void)
{
    for (int k = 0; k < 4; k++) {
        fs_config cfg = strip_config();
        const char *name = "none";
        if (k == 1) {
            name = "refine_vm";
            cfg.mesh.refine_vm = 0.25;
            cfg.mesh.min_size = 0.2;
        } else if (k == 2) {
            name = "tip_submodel";
            cfg.fracture.tip_submodel = true;
        } else if (k == 3) {
            name = "smooth_radius";
            cfg.mesh.smooth_radius = 3.0;
        }
        fs_mesh m = {0};
        CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
        fs_wedge_model w;
        CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
        CHECK(fs_wedge_simulate(&w, 0.3) == 0);
        double coherence, length, angle = crack_angle(&m, &coherence, &length);
        const fs_wedge_counters *c = &w.counters;
        printf("%s: %lld splits, %d elements, crack walls %.1f cm at %.1f degrees (coherence %.2f); %lld vm rounds "
               "(%lld bisections), %lld sub-models (%lld below threshold), %lld smoothings (%lld nodes)\n",
               name, (long long)w.fractures, (int)w.n_elems, length, angle, coherence, (long long)c->vm_rounds,
               (long long)c->vm_bisections, (long long)c->submodels, (long long)c->submodel_rejections,
               (long long)c->smoothings, (long long)c->smoothed_nodes);
        CHECK(w.fractures > 3 && length > 4.0);
        CHECK_MSG(90.0 - fabs(angle) < 5.0 && coherence > 0.6, "%s: cracks at %.1f degrees, coherence %.2f", name,
                  angle, coherence);
        if (k == 1)
            CHECK(c->vm_rounds > 0 && c->vm_bisections > 0);
        if (k == 2)
            CHECK(c->submodels > 0);
        if (k == 3)
            CHECK(c->smoothings > 0 && c->smoothed_nodes > 0);
        for (int32_t t = 0; t < m.n_tris; t++)
            CHECK(fs_mesh_tri_area(&m, t) > 0.0);
        fs_wedge_free(&w);
        fs_mesh_free(&m);
    }
}

int main(void)
{
    RUN(test_vm_refinement);
    RUN(test_submodel);
    RUN(test_smooth_distorted);
    RUN(test_smooth_tip);
    RUN(test_simulation);
    return check_finish();
}
