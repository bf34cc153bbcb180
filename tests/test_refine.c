/* Tests of conforming longest-edge bisection (Rivara LEPP) on plane, periodic plane, cylinder and sphere. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "check.h"
#include "geom/delaunay.h"
#include "geom/mesh.h"
#include "geom/refine.h"
#include "geom/sample.h"

/* ---- meshes ---- */

/* One point per cell of a gx x gy grid on [0, w) x [0, h), jittered inside the middle 70% of its cell. */
static fs_points jittered_points(int gx, int gy, double w, double h, uint64_t seed)
{
    fs_points p = {gx * gy, calloc(3 * (size_t)gx * gy, sizeof(double))};
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            int32_t k = j * gx + i;
            p.p[3 * k] = w * (i + 0.15 + 0.7 * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)k)) / gx;
            p.p[3 * k + 1] = h * (j + 0.15 + 0.7 * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)k + 1)) / gy;
        }
    return p;
}

/* A Fibonacci spiral on the sphere with a small random jitter (no four points co-circular). */
static fs_points sphere_points(int32_t n, double r, uint64_t seed)
{
    fs_points p = {n, calloc(3 * (size_t)n, sizeof(double))};
    double golden = FS_PI * (3.0 - sqrt(5.0));
    for (int32_t i = 0; i < n; i++) {
        double z = 1.0 - (2.0 * i + 1.0) / n + 0.3 / n * (fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)i) - 0.5);
        double phi = golden * i + 0.3 * (fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)i + 1) - 0.5) / sqrt((double)n);
        double s = sqrt(1.0 - z * z);
        p.p[3 * i] = r * s * cos(phi);
        p.p[3 * i + 1] = r * s * sin(phi);
        p.p[3 * i + 2] = r * z;
    }
    return p;
}

typedef enum { PLANE, PERIODIC, CYLINDER, SPHERE } kind;

static const char *kind_name[] = {"plane", "periodic", "cylinder", "sphere"};

static fs_domain domain_of(kind k)
{
    fs_domain d = fs_domain_default();
    if (k == PERIODIC) {
        d.width = 8.0;
        d.height = 6.0;
        d.periodic_x = d.periodic_y = true;
    } else if (k == CYLINDER) {
        d.type = FS_DOMAIN_CYLINDER;
        d.radius = 1.5;
        d.height = 7.0;
    } else if (k == SPHERE) {
        d.type = FS_DOMAIN_SPHERE;
        d.radius = 3.0;
    }
    fs_domain_normalize(&d);
    return d;
}

static int build_mesh(kind k, int g, uint64_t seed, fs_mesh *m)
{
    fs_domain d = domain_of(k);
    fs_points p;
    if (k == SPHERE)
        p = sphere_points(2 * g * g, d.radius, seed);
    else
        p = jittered_points(g, g, fs_domain_extent_x(&d), fs_domain_extent_y(&d), seed);
    int rc = fs_delaunay(&d, &p, m);
    fs_points_free(&p);
    return rc;
}

/* ---- geometry ---- */

static double period_of(const fs_mesh *m, int axis)
{
    const fs_domain *d = &m->domain;
    bool wraps = axis == 0 ? (d->type == FS_DOMAIN_CYLINDER || (d->type == FS_DOMAIN_PLANE && d->periodic_x))
                           : (d->type != FS_DOMAIN_SPHERE && d->periodic_y);
    return wraps ? (axis == 0 ? fs_domain_extent_x(d) : fs_domain_extent_y(d)) : 0.0;
}

static double total_area(const fs_mesh *m)
{
    double s = 0.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        s += fs_mesh_tri_area(m, t);
    return s;
}

/* Smallest interior angle of triangle t (radians), in its unwrapped frame (3-D chords on the sphere). */
static double min_angle(const fs_mesh *m, int32_t t)
{
    double p[3][3];
    for (int c = 0; c < 3; c++)
        fs_mesh_corner(m, t, c, p[c]);
    double best = FS_PI;
    for (int c = 0; c < 3; c++) {
        double u[3], v[3];
        fs_sub3(u, p[(c + 1) % 3], p[c]);
        fs_sub3(v, p[(c + 2) % 3], p[c]);
        double cr[3];
        fs_cross3(cr, u, v);
        double a = atan2(fs_norm3(cr), fs_dot3(u, v));
        if (a < best)
            best = a;
    }
    return best;
}

static double mesh_min_angle(const fs_mesh *m)
{
    double best = FS_PI;
    for (int32_t t = 0; t < m->n_tris; t++)
        best = fmin(best, min_angle(m, t));
    return best;
}

static double boundary_length(const fs_mesh *m)
{
    double s = 0.0;
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        if (m->adj[h] < 0) {
            double a[3], b[3], d[3];
            fs_mesh_corner(m, h / 3, h % 3, a);
            fs_mesh_corner(m, h / 3, (h % 3 + 1) % 3, b);
            fs_sub3(d, b, a);
            s += fs_norm3(d);
        }
    return s;
}

static int euler_expected(const fs_mesh *m)
{
    if (m->domain.type == FS_DOMAIN_SPHERE)
        return 2;
    bool px = period_of(m, 0) > 0.0, py = period_of(m, 1) > 0.0;
    return px || py ? 0 : 1;
}

/* ---- structural facts ---- */

static fs_mesh rebuilt_copy(const fs_mesh *m, int *rc)
{
    fs_mesh c;
    memset(&c, 0, sizeof c);
    c.domain = m->domain;
    c.n_nodes = m->n_nodes;
    c.n_tris = m->n_tris;
    c.pos = malloc(3 * (size_t)m->n_nodes * sizeof *c.pos);
    memcpy(c.pos, m->pos, 3 * (size_t)m->n_nodes * sizeof *c.pos);
    c.tri = malloc(3 * (size_t)m->n_tris * sizeof *c.tri);
    memcpy(c.tri, m->tri, 3 * (size_t)m->n_tris * sizeof *c.tri);
    if (m->shift) {
        c.shift = malloc(6 * (size_t)m->n_tris * sizeof *c.shift);
        memcpy(c.shift, m->shift, 6 * (size_t)m->n_tris * sizeof *c.shift);
    }
    *rc = fs_mesh_build_adjacency(&c);
    fs_mesh_build_edges(&c);
    fs_mesh_build_rings(&c);
    return c;
}

/* Counts of violations of the facts a refined mesh must keep. */
typedef struct {
    int nonpositive;    /* triangles with area <= 0 (sphere: facing inward) */
    int shift_origin;   /* triangles whose first corner is not at image (0, 0) */
    int adj_mismatch;   /* adjacency entries differing from a rebuild from scratch */
    int unpaired;       /* half-edges with a neighbour but no matching reverse half-edge there */
    int edge_bad;       /* half-edges whose edge record disagrees with the triangle */
    int edge_use;       /* edges not used by exactly two half-edges (one on a boundary) */
    int ring_mismatch;  /* ring entries differing from a rebuild from scratch */
    int64_t euler;      /* V - E + F with the maintained edge count */
    int32_t rebuilt_edges;
    int rebuild_rc;
} mesh_facts;

static mesh_facts check_structure(const fs_mesh *m)
{
    mesh_facts f;
    memset(&f, 0, sizeof f);
    for (int32_t t = 0; t < m->n_tris; t++) {
        f.nonpositive += !(fs_mesh_tri_area(m, t) > 0.0);
        if (m->shift)
            f.shift_origin += m->shift[6 * t] != 0 || m->shift[6 * t + 1] != 0;
    }
    fs_mesh c = rebuilt_copy(m, &f.rebuild_rc);
    f.rebuilt_edges = c.n_edges;
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        f.adj_mismatch += m->adj[h] != c.adj[h];

    int32_t *use = calloc((size_t)m->n_edges + 1, sizeof *use);
    for (int32_t h = 0; h < 3 * m->n_tris; h++) {
        int32_t t = h / 3, i = h % 3, j = (i + 1) % 3;
        int32_t a = m->tri[h], b = m->tri[3 * t + j];
        int sa[2] = {0, 0}, sb[2] = {0, 0};
        if (m->shift) {
            sa[0] = m->shift[6 * t + 2 * i];
            sa[1] = m->shift[6 * t + 2 * i + 1];
            sb[0] = m->shift[6 * t + 2 * j];
            sb[1] = m->shift[6 * t + 2 * j + 1];
        }
        int32_t u = m->adj[h];
        if (u >= 0) {
            int found = 0;
            for (int k = 0; k < 3; k++) {
                int32_t g = 3 * u + k, gn = 3 * u + (k + 1) % 3;
                if (m->tri[g] != b || m->tri[gn] != a || m->adj[g] != t)
                    continue;
                int ok = 1;
                if (m->shift)
                    for (int q = 0; q < 2; q++)
                        ok &= m->shift[6 * u + 2 * ((k + 1) % 3) + q] - m->shift[6 * u + 2 * k + q] == sa[q] - sb[q];
                found += ok;
            }
            f.unpaired += found != 1;
        }
        int32_t e = m->tri_edge[h];
        if (e < 0 || e >= m->n_edges) {
            f.edge_bad++;
            continue;
        }
        use[e]++;
        int32_t lo = a < b ? a : b, hi = a < b ? b : a;
        const int32_t *et = m->edge_tri + 2 * e;
        bool ends = m->edge[2 * e] == lo && m->edge[2 * e + 1] == hi;
        bool sides = (et[0] == t && et[1] == u) || (et[1] == t && et[0] == u);
        f.edge_bad += !(ends && sides);
    }
    for (int32_t e = 0; e < m->n_edges; e++)
        f.edge_use += !(use[e] == 2 || (use[e] == 1 && m->edge_tri[2 * e + 1] < 0));
    free(use);

    for (int32_t v = 0; v <= m->n_nodes; v++)
        f.ring_mismatch += m->ring_start[v] != c.ring_start[v];
    if (!f.ring_mismatch)
        for (int32_t k = 0; k < m->ring_start[m->n_nodes]; k++)
            f.ring_mismatch += m->ring_tri[k] != c.ring_tri[k];
    f.euler = (int64_t)m->n_nodes - m->n_edges + m->n_tris;
    fs_mesh_free(&c);
    return f;
}

static bool structure_ok(const fs_mesh *m, const char *what)
{
    mesh_facts f = check_structure(m);
    bool ok = f.nonpositive == 0 && f.shift_origin == 0 && f.adj_mismatch == 0 && f.unpaired == 0 &&
              f.edge_bad == 0 && f.edge_use == 0 && f.ring_mismatch == 0 && f.rebuild_rc == 0 &&
              f.rebuilt_edges == m->n_edges && f.euler == euler_expected(m);
    CHECK_MSG(ok,
              "%s: nonpositive %d, shift origin %d, adj %d, unpaired %d, edge %d, edge use %d, ring %d, "
              "rebuild rc %d, edges %d vs %d rebuilt, euler %lld (want %d)",
              what, f.nonpositive, f.shift_origin, f.adj_mismatch, f.unpaired, f.edge_bad, f.edge_use,
              f.ring_mismatch, f.rebuild_rc, (int)m->n_edges, (int)f.rebuilt_edges, (long long)f.euler,
              euler_expected(m));
    return ok;
}

/* Nodes lying strictly inside an edge they are not an end of (a hanging node), on the plane and
 * cylinder: each node is compared with every edge through its nearest periodic image. */
static int count_hanging_nodes(const fs_mesh *m)
{
    double px = period_of(m, 0), py = period_of(m, 1);
    int bad = 0;
    for (int32_t e = 0; e < m->n_edges; e++) {
        int32_t t = m->edge_tri[2 * e];
        int i = 0;
        while (i < 2 && m->tri_edge[3 * t + i] != e)
            i++;
        double a[3], b[3];
        fs_mesh_corner(m, t, i, a);
        fs_mesh_corner(m, t, (i + 1) % 3, b);
        double dx = b[0] - a[0], dy = b[1] - a[1], l2 = dx * dx + dy * dy;
        for (int32_t v = 0; v < m->n_nodes; v++) {
            if (v == m->edge[2 * e] || v == m->edge[2 * e + 1])
                continue;
            double x = m->pos[3 * v] - a[0], y = m->pos[3 * v + 1] - a[1];
            if (px > 0.0)
                x -= px * round((x - 0.5 * dx) / px);
            if (py > 0.0)
                y -= py * round((y - 0.5 * dy) / py);
            double along = x * dx + y * dy, across = x * dy - y * dx;
            if (along > 1e-9 * l2 && along < (1.0 - 1e-9) * l2 && fabs(across) <= 1e-9 * l2)
                bad++;
        }
    }
    return bad;
}

/* Whether some half-edge still joins a and b with image offset d (b relative to a), either way. */
static bool has_edge(const fs_mesh *m, int32_t a, int32_t b, const int8_t *d)
{
    for (int32_t k = m->ring_start[a]; k < m->ring_start[a + 1]; k++) {
        int32_t t = m->ring_tri[k];
        for (int i = 0; i < 3; i++) {
            int j = (i + 1) % 3;
            int32_t p = m->tri[3 * t + i], q = m->tri[3 * t + j];
            int rel[2] = {0, 0};
            if (m->shift)
                for (int s = 0; s < 2; s++)
                    rel[s] = m->shift[6 * t + 2 * j + s] - m->shift[6 * t + 2 * i + s];
            if (p == a && q == b && rel[0] == d[0] && rel[1] == d[1])
                return true;
            if (p == b && q == a && rel[0] == -d[0] && rel[1] == -d[1])
                return true;
        }
    }
    return false;
}

/* ---- one refinement round with its bookkeeping checks ---- */

typedef struct {
    fs_mesh *m;
    int32_t *origin;       /* per triangle: the triangle of the initial mesh it descends from */
    double *origin_angle;  /* per initial triangle: its smallest angle */
    int32_t n_origin;
} lineage;

static void lineage_init(lineage *l, fs_mesh *m)
{
    l->m = m;
    l->n_origin = m->n_tris;
    l->origin = malloc((size_t)m->n_tris * sizeof *l->origin);
    l->origin_angle = malloc((size_t)m->n_tris * sizeof *l->origin_angle);
    for (int32_t t = 0; t < m->n_tris; t++) {
        l->origin[t] = t;
        l->origin_angle[t] = min_angle(m, t);
    }
}

static void lineage_free(lineage *l)
{
    free(l->origin);
    free(l->origin_angle);
}

/* Refines tris and checks the change record against the mesh before and after: untouched triangles
 * are identical, each new node is the wrapped (sphere: projected) midpoint of its parents, and (off
 * the sphere) each pre-call triangle's area is exactly covered by its slot and its new children. */
static int refine_checked(lineage *l, const int32_t *tris, int32_t n, double min_size, fs_refine_change *ch)
{
    fs_mesh *m = l->m;
    int32_t nt0 = m->n_tris, nn0 = m->n_nodes;
    int32_t *tri0 = malloc(3 * (size_t)nt0 * sizeof *tri0);
    memcpy(tri0, m->tri, 3 * (size_t)nt0 * sizeof *tri0);
    double *area0 = malloc((size_t)nt0 * sizeof *area0);
    for (int32_t t = 0; t < nt0; t++)
        area0[t] = fs_mesh_tri_area(m, t);

    int rc = fs_refine_bisect(m, tris, n, min_size, ch);
    CHECK(rc == 0);
    CHECK(ch->n_nodes_before == nn0 && ch->n_tris_before == nt0 && !ch->rings_rebuilt);
    CHECK(ch->n_new_nodes == m->n_nodes - nn0 && ch->n_new_tris == m->n_tris - nt0);

    uint8_t *changed = calloc((size_t)nt0, 1);
    int order_ok = 1;
    for (int32_t q = 0; q < ch->n_changed_tris; q++) {
        changed[ch->changed_tri[q]] = 1;
        order_ok &= q == 0 || ch->changed_tri[q] > ch->changed_tri[q - 1];
    }
    CHECK(order_ok);
    int untouched_differ = 0, changed_same = 0;
    for (int32_t t = 0; t < nt0; t++) {
        bool same = memcmp(tri0 + 3 * t, m->tri + 3 * t, 3 * sizeof *tri0) == 0;
        untouched_differ += !changed[t] && !same;
        changed_same += changed[t] && same;
    }
    CHECK_MSG(untouched_differ == 0 && changed_same == 0, "%d untouched triangles changed, %d listed as changed are not",
              untouched_differ, changed_same);

    bool sphere = m->domain.type == FS_DOMAIN_SPHERE;
    double px = period_of(m, 0), py = period_of(m, 1), worst = 0.0;
    int parent_order = 0;
    for (int32_t i = 0; i < ch->n_new_nodes; i++) {
        int32_t a = ch->node_parent[2 * i], b = ch->node_parent[2 * i + 1];
        parent_order += !(a >= 0 && b >= 0 && a < nn0 + i && b < nn0 + i);
        const double *pa = m->pos + 3 * a, *pb = m->pos + 3 * b, *pm = m->pos + 3 * (nn0 + i);
        double mid[3];
        for (int k = 0; k < 3; k++)
            mid[k] = 0.5 * (pa[k] + pb[k]);
        mid[0] += 0.5 * ch->node_parent_shift[2 * i] * px;
        mid[1] += 0.5 * ch->node_parent_shift[2 * i + 1] * py;
        if (sphere) {
            double s = m->domain.radius / fs_norm3(mid);
            for (int k = 0; k < 3; k++)
                mid[k] *= s;
        }
        double d[3];
        fs_domain_delta(&m->domain, mid, pm, d);
        worst = fmax(worst, fs_norm3(d));
        if (!sphere) {
            bool inside = pm[0] >= 0.0 && pm[0] < fs_domain_extent_x(&m->domain) && pm[1] >= 0.0 &&
                          pm[1] < fs_domain_extent_y(&m->domain);
            worst = inside ? worst : INFINITY;
        } else {
            worst = fmax(worst, fabs(fs_norm3(pm) - m->domain.radius));
        }
    }
    CHECK(parent_order == 0);
    CHECK_MSG(worst <= 1e-12 * (sphere ? m->domain.radius : fs_domain_extent_x(&m->domain)),
              "new node off its parents' midpoint or outside the domain by %g", worst);

    int no_hanging = 0;
    for (int32_t i = 0; i < ch->n_new_nodes; i++)
        no_hanging += has_edge(m, ch->node_parent[2 * i], ch->node_parent[2 * i + 1], ch->node_parent_shift + 2 * i);
    CHECK_MSG(no_hanging == 0, "%d split edges still present next to their midpoint", no_hanging);

    int bad_parent = 0;
    l->origin = realloc(l->origin, (size_t)m->n_tris * sizeof *l->origin);
    for (int32_t i = 0; i < ch->n_new_tris; i++) {
        int32_t p = ch->tri_parent[i];
        bad_parent += !(p >= 0 && p < nt0 && changed[p]);
        l->origin[nt0 + i] = l->origin[p >= 0 && p < nt0 ? p : 0];
    }
    CHECK(bad_parent == 0);
    if (!sphere && bad_parent == 0) {
        double *cover = calloc((size_t)nt0, sizeof *cover);
        for (int32_t t = 0; t < nt0; t++)
            cover[t] = fs_mesh_tri_area(m, t);
        for (int32_t i = 0; i < ch->n_new_tris; i++)
            cover[ch->tri_parent[i]] += fs_mesh_tri_area(m, nt0 + i);
        double err = 0.0;
        for (int32_t t = 0; t < nt0; t++)
            err = fmax(err, fabs(cover[t] - area0[t]) / area0[t]);
        CHECK_MSG(err <= 1e-12, "children cover their parent's area with relative error %g", err);
        free(cover);
    }
    free(changed);
    free(tri0);
    free(area0);
    return rc;
}

/* Triangles picked at random with probability frac (deterministic in seed and round). */
static int32_t pick(const fs_mesh *m, double frac, uint64_t seed, int round, int32_t *out)
{
    int32_t n = 0;
    for (int32_t t = 0; t < m->n_tris; t++)
        if (fs_rand01(seed, FS_RNG_TEST, (uint64_t)round << 32 | (uint64_t)t) < frac)
            out[n++] = t;
    return n;
}

/* design: Rosenberg and Stenger (1975): bisecting a triangle across its longest edge, and its
 * children likewise, never makes an angle smaller than half the smallest angle of the original.
 * LEPP only ever splits a triangle across its own longest edge, so every triangle keeps at least half
 * the smallest angle of the initial triangle it descends from: that is the bound asserted, per
 * lineage (on the sphere too: midpoints projected outward change the angles by O(h / R), which the
 * bound has room for on these meshes). */
static void refine_rounds(kind k)
{
    fs_mesh m;
    CHECK(build_mesh(k, 10, 7, &m) == 0);
    lineage l;
    lineage_init(&l, &m);
    double area_before = total_area(&m), boundary_before = boundary_length(&m), angle_before = mesh_min_angle(&m);
    int32_t tris_before = m.n_tris;
    structure_ok(&m, kind_name[k]);
    fs_refine_change ch = {0};
    int bisections = 0;
    for (int round = 0; round < 8; round++) {
        int32_t *list = malloc((size_t)m.n_tris * sizeof *list);
        int32_t n = pick(&m, 0.12, 11 + k, round, list);
        refine_checked(&l, list, n, 0.0, &ch);
        CHECK(ch.n_skipped == 0 && ch.n_bisections >= n && !ch.rings_rebuilt);
        bisections += ch.n_bisections;
        free(list);
        char what[64];
        snprintf(what, sizeof what, "%s round %d", kind_name[k], round);
        if (!structure_ok(&m, what))
            break;
    }
    CHECK(m.n_tris > 4 * tris_before);
    if (k != SPHERE) {
        CHECK_NEAR(total_area(&m), area_before, 1e-12 * area_before);
        CHECK_NEAR(boundary_length(&m), boundary_before, 1e-12 * (boundary_before + 1.0));
        CHECK(count_hanging_nodes(&m) == 0);
    } else {
        int off = 0;
        for (int32_t v = 0; v < m.n_nodes; v++)
            off += fabs(fs_norm3(m.pos + 3 * v) - m.domain.radius) > 1e-12 * m.domain.radius;
        CHECK(off == 0);
        double sphere_area = fs_domain_area(&m.domain);
        CHECK(total_area(&m) > area_before && total_area(&m) < sphere_area);
    }
    if (k == PERIODIC)
        CHECK_NEAR(total_area(&m), fs_domain_area(&m.domain), 1e-12 * fs_domain_area(&m.domain));
    int below = 0;
    double worst_ratio = INFINITY;
    for (int32_t t = 0; t < m.n_tris; t++) {
        double ratio = min_angle(&m, t) / l.origin_angle[l.origin[t]];
        worst_ratio = fmin(worst_ratio, ratio);
        below += ratio < 0.5 * (1.0 - 1e-9);
    }
    double angle_after = mesh_min_angle(&m);
    CHECK_MSG(below == 0, "%s: %d triangles below half their ancestor's smallest angle (worst ratio %.4f)",
              kind_name[k], below, worst_ratio);
    CHECK(angle_after >= 0.5 * angle_before * (1.0 - 1e-9));
    printf("  %s: %d -> %d triangles in 8 rounds (%d bisections); min angle %.2f -> %.2f deg, worst ratio to "
           "ancestor %.3f\n",
           kind_name[k], (int)tris_before, (int)m.n_tris, bisections, angle_before * 180.0 / FS_PI,
           angle_after * 180.0 / FS_PI, worst_ratio);
    fs_refine_change_free(&ch);
    lineage_free(&l);
    fs_mesh_free(&m);
}

static void test_plane_rounds(void) { refine_rounds(PLANE); }
static void test_periodic_rounds(void) { refine_rounds(PERIODIC); }
static void test_cylinder_rounds(void) { refine_rounds(CYLINDER); }
static void test_sphere_rounds(void) { refine_rounds(SPHERE); }

/* The edges crossing the seams of a periodic tile are refined like any other: refine every triangle
 * that straddles a seam, several times over. */
static void test_seam_triangles(void)
{
    fs_mesh m;
    CHECK(build_mesh(PERIODIC, 8, 3, &m) == 0);
    lineage l;
    lineage_init(&l, &m);
    fs_refine_change ch = {0};
    int straddling = 0;
    for (int round = 0; round < 4; round++) {
        int32_t *list = malloc((size_t)m.n_tris * sizeof *list);
        int32_t n = 0;
        for (int32_t t = 0; t < m.n_tris; t++) {
            const int8_t *s = m.shift + 6 * t;
            if (s[2] || s[3] || s[4] || s[5])
                list[n++] = t;
        }
        straddling += n;
        refine_checked(&l, list, n, 0.0, &ch);
        free(list);
        structure_ok(&m, "seams");
    }
    CHECK(straddling > 0);
    CHECK_NEAR(total_area(&m), fs_domain_area(&m.domain), 1e-12 * fs_domain_area(&m.domain));
    CHECK(count_hanging_nodes(&m) == 0);
    fs_refine_change_free(&ch);
    lineage_free(&l);
    fs_mesh_free(&m);
}

/* A hexagonal lattice: every edge of a triangle has the same length, so "longest" is decided by the
 * tie-break alone; refinement must still conform and be reproducible. */
static void test_lattice_ties(void)
{
    fs_domain d = domain_of(PERIODIC);
    fs_points p;
    CHECK(fs_sample_hex(&d, 120, &p) == 0);
    fs_mesh a, b;
    CHECK(fs_delaunay(&d, &p, &a) == 0);
    CHECK(fs_delaunay(&d, &p, &b) == 0);
    fs_points_free(&p);
    lineage l;
    lineage_init(&l, &a);
    fs_refine_change ch = {0}, ch2 = {0};
    for (int round = 0; round < 5; round++) {
        int32_t *list = malloc((size_t)a.n_tris * sizeof *list);
        int32_t n = pick(&a, 0.2, 5, round, list);
        refine_checked(&l, list, n, 0.0, &ch);
        CHECK(fs_refine_bisect(&b, list, n, 0.0, &ch2) == 0);
        free(list);
        structure_ok(&a, "lattice");
    }
    CHECK(a.n_tris == b.n_tris && a.n_nodes == b.n_nodes);
    if (a.n_tris == b.n_tris && a.n_nodes == b.n_nodes) {
        CHECK(memcmp(a.tri, b.tri, 3 * (size_t)a.n_tris * sizeof *a.tri) == 0);
        CHECK(memcmp(a.pos, b.pos, 3 * (size_t)a.n_nodes * sizeof *a.pos) == 0);
        CHECK(memcmp(a.shift, b.shift, 6 * (size_t)a.n_tris * sizeof *a.shift) == 0);
    }
    CHECK(count_hanging_nodes(&a) == 0);
    CHECK_NEAR(total_area(&a), fs_domain_area(&d), 1e-12 * fs_domain_area(&d));
    fs_refine_change_free(&ch);
    fs_refine_change_free(&ch2);
    lineage_free(&l);
    fs_mesh_free(&a);
    fs_mesh_free(&b);
}

/* min_size: listed triangles smaller than it are left alone, and propagation never splits a
 * triangle smaller than it either (the path only climbs to longer edges), so no triangle made has a
 * longest edge below min_size / 2 (a child keeps half its parent's longest edge). Refining
 * everything until nothing changes therefore ends with every triangle in [min_size / 2, min_size). */
static void test_min_size(void)
{
    fs_mesh m;
    CHECK(build_mesh(PLANE, 10, 21, &m) == 0);
    double *size = malloc((size_t)m.n_tris * sizeof *size), *sorted = malloc((size_t)m.n_tris * sizeof *sorted);
    for (int32_t t = 0; t < m.n_tris; t++)
        sorted[t] = size[t] = fs_refine_tri_size(&m, t);
    double min_size = 0.0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        int32_t smaller = 0;
        for (int32_t s = 0; s < m.n_tris; s++)
            smaller += sorted[s] < sorted[t];
        if (smaller == m.n_tris / 2)
            min_size = sorted[t];
    }
    CHECK(min_size > 0.0);
    int32_t *all = malloc((size_t)m.n_tris * sizeof *all);
    int32_t below = 0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        all[t] = t;
        below += size[t] < min_size;
    }
    fs_refine_change ch = {0};
    CHECK(fs_refine_bisect(&m, all, m.n_tris, min_size, &ch) == 0);
    CHECK(ch.n_skipped == below);
    int small_split = 0;
    for (int32_t q = 0; q < ch.n_changed_tris; q++)
        small_split += size[ch.changed_tri[q]] < min_size;
    CHECK_MSG(small_split == 0, "%d triangles below min_size were split", small_split);
    CHECK(ch.n_changed_tris == ch.n_tris_before - below);
    structure_ok(&m, "min_size");
    free(all);

    int32_t nt0 = ch.n_tris_before;
    uint8_t *made = calloc((size_t)nt0, 1);
    for (int32_t q = 0; q < ch.n_changed_tris; q++)
        made[ch.changed_tri[q]] = 1;
    int rounds = 0;
    while (rounds < 20) {
        all = malloc((size_t)m.n_tris * sizeof *all);
        for (int32_t t = 0; t < m.n_tris; t++)
            all[t] = t;
        CHECK(fs_refine_bisect(&m, all, m.n_tris, min_size, &ch) == 0);
        free(all);
        for (int32_t q = 0; q < ch.n_changed_tris; q++)
            if (ch.changed_tri[q] < nt0)
                made[ch.changed_tri[q]] = 1;
        rounds++;
        if (ch.n_new_tris == 0)
            break;
    }
    CHECK(rounds < 20);
    int too_large = 0, too_small = 0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        double s = fs_refine_tri_size(&m, t);
        too_large += !(s < min_size);
        too_small += (t >= nt0 || made[t]) && s < 0.5 * min_size * (1.0 - 1e-12);
    }
    CHECK_MSG(too_large == 0 && too_small == 0,
              "after refining to min_size: %d triangles still >= min_size, %d made below min_size / 2", too_large,
              too_small);
    free(made);
    structure_ok(&m, "min_size converged");
    fs_refine_change_free(&ch);
    free(size);
    free(sorted);
    fs_mesh_free(&m);
}

/* Point location by brute force: the triangle containing p (p away from the seams). */
static int32_t locate(const fs_mesh *m, const double *p)
{
    for (int32_t t = 0; t < m->n_tris; t++) {
        double c[3][3];
        for (int k = 0; k < 3; k++)
            fs_mesh_corner(m, t, k, c[k]);
        if (fs_orient2(c[0], c[1], p) >= 0.0 && fs_orient2(c[1], c[2], p) >= 0.0 && fs_orient2(c[2], c[0], p) >= 0.0)
            return t;
    }
    return -1;
}

/* Refining the triangle at one spot again and again gives a graded mesh: tiny triangles at the spot,
 * the original triangles far away, and between them sizes that change by at most a bounded factor
 * from a triangle to its neighbour (with every angle >= beta, the law of sines bounds the ratio of
 * two neighbours' longest edges by 1 / sin(beta)). */
static void test_graded(void)
{
    fs_mesh m;
    CHECK(build_mesh(PERIODIC, 12, 5, &m) == 0);
    double spot[3] = {4.3, 3.1, 0.0};
    double h0 = 0.0;
    for (int32_t t = 0; t < m.n_tris; t++)
        h0 = fmax(h0, fs_refine_tri_size(&m, t));
    double min_size = h0 / 200.0;
    int32_t nt0 = m.n_tris;
    fs_refine_change ch = {0};
    int iterations = 0;
    uint8_t *touched = calloc((size_t)nt0, 1);
    for (; iterations < 100; iterations++) {
        int32_t t = locate(&m, spot);
        CHECK(t >= 0);
        if (t < 0 || fs_refine_tri_size(&m, t) < min_size)
            break;
        CHECK(fs_refine_bisect(&m, &t, 1, min_size, &ch) == 0);
        for (int32_t q = 0; q < ch.n_changed_tris; q++)
            if (ch.changed_tri[q] < nt0)
                touched[ch.changed_tri[q]] = 1;
    }
    CHECK(iterations < 100);
    structure_ok(&m, "graded");
    CHECK(count_hanging_nodes(&m) == 0);

    int32_t untouched = 0;
    for (int32_t t = 0; t < nt0; t++)
        untouched += !touched[t];
    double beta = mesh_min_angle(&m), worst = 0.0;
    for (int32_t h = 0; h < 3 * m.n_tris; h++)
        if (m.adj[h] >= 0)
            worst = fmax(worst, fs_refine_tri_size(&m, h / 3) / fs_refine_tri_size(&m, m.adj[h]));
    CHECK_MSG(worst <= 1.0 / sin(beta) * (1.0 + 1e-9), "neighbour size ratio %g exceeds 1/sin(%g deg)", worst,
              beta * 180.0 / FS_PI);

    /* size against distance from the spot: the smallest triangles are at the spot, and the triangles
     * within each distance band get larger further out */
    double band_max[4] = {0.0, 0.0, 0.0, 0.0}, band_min[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    double edges[5] = {0.0, 0.05 * h0, 0.3 * h0, 1.0 * h0, INFINITY};
    for (int32_t t = 0; t < m.n_tris; t++) {
        double c[3] = {0.0, 0.0, 0.0}, d[3];
        for (int k = 0; k < 3; k++) {
            double p[3];
            fs_mesh_corner(&m, t, k, p);
            c[0] += p[0] / 3.0;
            c[1] += p[1] / 3.0;
        }
        fs_domain_wrap(&m.domain, c);
        fs_domain_delta(&m.domain, spot, c, d);
        double dist = hypot(d[0], d[1]), s = fs_refine_tri_size(&m, t);
        for (int b = 0; b < 4; b++)
            if (dist >= edges[b] && dist < edges[b + 1]) {
                band_max[b] = fmax(band_max[b], s);
                band_min[b] = fmin(band_min[b], s);
            }
    }
    for (int b = 0; b + 1 < 4; b++)
        CHECK_MSG(band_min[b] < band_min[b + 1] && band_max[b] < band_max[b + 1],
                  "band %d sizes %g .. %g, band %d sizes %g .. %g", b, band_min[b], band_max[b], b + 1,
                  band_min[b + 1], band_max[b + 1]);
    CHECK(untouched > nt0 * 3 / 4);
    printf("  graded: %d bisection calls, %d -> %d triangles, %d of %d initial untouched, neighbour ratio <= %.2f "
           "(bound %.2f), smallest size by distance band %.3g %.3g %.3g %.3g\n",
           iterations, (int)nt0, (int)m.n_tris, (int)untouched, (int)nt0, worst, 1.0 / sin(beta), band_min[0],
           band_min[1], band_min[2], band_min[3]);
    free(touched);
    fs_refine_change_free(&ch);
    fs_mesh_free(&m);
}

/* Periodic meshes of a few nodes per period have triangles whose corners repeat a node at different
 * images, and neighbours across two edges: refinement either works or refuses with FS_ERR_DATA, and
 * the mesh stays valid and covers the tile either way. */
static void test_tiny_periodic(void)
{
    int sizes[4][2] = {{1, 3}, {2, 2}, {3, 2}, {3, 3}};
    for (int s = 0; s < 4; s++) {
        fs_domain d = domain_of(PERIODIC);
        fs_points p = jittered_points(sizes[s][0], sizes[s][1], d.width, d.height, 9);
        fs_mesh m;
        CHECK(fs_delaunay(&d, &p, &m) == 0);
        fs_points_free(&p);
        fs_refine_change ch = {0};
        for (int round = 0; round < 5; round++) {
            int32_t *all = malloc((size_t)m.n_tris * sizeof *all);
            for (int32_t t = 0; t < m.n_tris; t++)
                all[t] = t;
            int32_t n = m.n_tris;
            if (fs_refine_bisect(&m, all, n, 0.0, &ch) != 0) {
                CHECK(fs_error_domain() == FS_ERR_DATA);
                free(all);
                break;
            }
            free(all);
            char what[64];
            snprintf(what, sizeof what, "tiny %dx%d round %d", sizes[s][0], sizes[s][1], round);
            structure_ok(&m, what);
        }
        structure_ok(&m, "tiny");
        CHECK_NEAR(total_area(&m), fs_domain_area(&d), 1e-12 * fs_domain_area(&d));
        fs_refine_change_free(&ch);
        fs_mesh_free(&m);
    }
}

/* Bad requests fail with FS_ERR_INTERNAL and leave the mesh as it was. */
static void test_errors(void)
{
    fs_mesh m;
    CHECK(build_mesh(PLANE, 5, 2, &m) == 0);
    int32_t n_tris = m.n_tris, n_nodes = m.n_nodes;
    int32_t bad = n_tris, ok = 0;
    fs_refine_change ch = {0};
    CHECK(fs_refine_bisect(&m, &bad, 1, 0.0, &ch) == -1);
    CHECK(fs_error_domain() == FS_ERR_INTERNAL);
    CHECK(strstr(fs_error_message(), "refine") != NULL);
    CHECK(fs_refine_bisect(&m, &ok, 1, -1.0, &ch) == -1);
    CHECK(fs_refine_bisect(&m, &ok, 1, NAN, &ch) == -1);
    CHECK(m.n_tris == n_tris && m.n_nodes == n_nodes);
    CHECK(fs_refine_bisect(&m, NULL, 0, 0.0, &ch) == 0);
    CHECK(ch.n_new_nodes == 0 && ch.n_new_tris == 0 && ch.n_changed_tris == 0);
    CHECK(fs_refine_bisect(&m, &ok, 1, 0.0, NULL) == 0);
    CHECK(m.n_tris > n_tris);
    fs_refine_change_free(&ch);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_plane_rounds);
    RUN(test_periodic_rounds);
    RUN(test_cylinder_rounds);
    RUN(test_sphere_rounds);
    RUN(test_seam_triangles);
    RUN(test_lattice_ties);
    RUN(test_min_size);
    RUN(test_graded);
    RUN(test_tiny_periodic);
    RUN(test_errors);
    return check_finish();
}
