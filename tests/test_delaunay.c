/* Tests of the Delaunay meshes on every domain, mesh adjacency and rings, and the Voronoi dual. */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/threads.h"
#include "base/vec.h"
#include "check.h"
#include "geom/delaunay.h"
#include "geom/mesh.h"

/* ---- point sets ---- */

static fs_points points_alloc(int32_t n)
{
    fs_points p = {n, calloc(3 * (size_t)n, sizeof(double))};
    return p;
}

static fs_points uniform_points(int32_t n, double w, double h, uint64_t seed)
{
    fs_points p = points_alloc(n);
    for (int32_t i = 0; i < n; i++) {
        p.p[3 * i] = w * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)i);
        p.p[3 * i + 1] = h * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)i + 1);
    }
    return p;
}

/* One point per cell of a gx x gy grid, jittered inside the middle 80% of its cell. */
static fs_points jittered_points(int gx, int gy, double w, double h, uint64_t seed)
{
    fs_points p = points_alloc(gx * gy);
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            int32_t k = j * gx + i;
            p.p[3 * k] = w * (i + 0.1 + 0.8 * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)k)) / gx;
            p.p[3 * k + 1] = h * (j + 0.1 + 0.8 * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)k + 1)) / gy;
        }
    return p;
}

static fs_points sphere_points(int32_t n, double r, uint64_t seed)
{
    fs_points p = points_alloc(n);
    for (int32_t i = 0; i < n; i++) {
        double z = 2.0 * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)i) - 1.0;
        double phi = 2.0 * FS_PI * fs_rand01(seed, FS_RNG_TEST, 2 * (uint64_t)i + 1);
        double s = sqrt(1.0 - z * z);
        p.p[3 * i] = r * s * cos(phi);
        p.p[3 * i + 1] = r * s * sin(phi);
        p.p[3 * i + 2] = r * z;
    }
    return p;
}

static fs_domain plane_domain(double w, double h, bool px, bool py)
{
    fs_domain d = fs_domain_default();
    d.width = w;
    d.height = h;
    d.periodic_x = px;
    d.periodic_y = py;
    return d;
}

/* ---- mesh facts ---- */

static double period_of(const fs_mesh *m, int axis)
{
    if (m->domain.type == FS_DOMAIN_SPHERE)
        return 0.0;
    bool wraps = axis == 0 ? m->domain.periodic_x : m->domain.periodic_y;
    return wraps ? (axis == 0 ? fs_domain_extent_x(&m->domain) : fs_domain_extent_y(&m->domain)) : 0.0;
}

static int64_t euler(const fs_mesh *m) { return (int64_t)m->n_nodes - m->n_edges + m->n_tris; }

static int count_nonpositive(const fs_mesh *m)
{
    int bad = 0;
    for (int32_t t = 0; t < m->n_tris; t++)
        bad += !(fs_mesh_tri_area(m, t) > 0.0);
    return bad;
}

static double total_area(const fs_mesh *m)
{
    double s = 0.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        s += fs_mesh_tri_area(m, t);
    return s;
}

/* Circumcircle of triangle t in its unwrapped frame. */
static void circle_of(const fs_mesh *m, int32_t t, double *c, double *r)
{
    double a[3], b[3], q[3];
    fs_mesh_corner(m, t, 0, a);
    fs_mesh_corner(m, t, 1, b);
    fs_mesh_corner(m, t, 2, q);
    double bx = b[0] - a[0], by = b[1] - a[1], cx = q[0] - a[0], cy = q[1] - a[1];
    double d = 2.0 * (bx * cy - by * cx), b2 = bx * bx + by * by, c2 = cx * cx + cy * cy;
    double ux = (cy * b2 - by * c2) / d, uy = (bx * c2 - cx * b2) / d;
    c[0] = a[0] + ux;
    c[1] = a[1] + uy;
    *r = hypot(ux, uy);
}

/* Points (and their periodic images) strictly inside some triangle's circumcircle, relative tolerance
 * 1e-9. Image ranges cover the part of each circle that meets the band the points occupy. */
static int count_circle_violations(const fs_mesh *m)
{
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int32_t i = 0; i < m->n_nodes; i++)
        for (int d = 0; d < 2; d++) {
            lo[d] = fmin(lo[d], m->pos[3 * i + d]);
            hi[d] = fmax(hi[d], m->pos[3 * i + d]);
        }
    double per[2] = {period_of(m, 0), period_of(m, 1)};
    int bad = 0;
    for (int32_t t = 0; t < m->n_tris; t++) {
        double c[2], r;
        circle_of(m, t, c, &r);
        int kmin[2] = {0, 0}, kmax[2] = {0, 0};
        for (int d = 0; d < 2; d++) {
            if (per[d] == 0.0)
                continue;
            int o = 1 - d;
            double half = r;
            if (per[o] == 0.0 && (c[o] < lo[o] || c[o] > hi[o])) {
                double dist = c[o] < lo[o] ? lo[o] - c[o] : c[o] - hi[o];
                half = dist >= r ? 0.0 : sqrt((r - dist) * (r + dist));
            }
            kmin[d] = (int)floor((c[d] - half) / per[d]) - 1;
            kmax[d] = (int)floor((c[d] + half) / per[d]) + 1;
        }
        for (int32_t i = 0; i < m->n_nodes; i++)
            for (int kx = kmin[0]; kx <= kmax[0]; kx++)
                for (int ky = kmin[1]; ky <= kmax[1]; ky++) {
                    double x = m->pos[3 * i] + kx * per[0] - c[0], y = m->pos[3 * i + 1] + ky * per[1] - c[1];
                    if (x * x + y * y < r * r * (1.0 - 1e-9))
                        bad++;
                }
    }
    return bad;
}

/* Edges that are not locally Delaunay: the far corner of the neighbour across an edge lies strictly
 * inside the triangle's circumcircle (relative tolerance 1e-9). A triangulation whose edges are all
 * locally Delaunay is the Delaunay triangulation. */
static int count_nonlocal(const fs_mesh *m)
{
    double per[2] = {period_of(m, 0), period_of(m, 1)};
    int bad = 0;
    for (int32_t t = 0; t < m->n_tris; t++) {
        double c[2], r;
        circle_of(m, t, c, &r);
        for (int i = 0; i < 3; i++) {
            int32_t u = m->adj[3 * t + i];
            if (u < 0)
                continue;
            int32_t a = m->tri[3 * t + i], b = m->tri[3 * t + (i + 1) % 3];
            const int8_t *sa = m->shift + 6 * t + 2 * i, *sb = m->shift + 6 * t + 2 * ((i + 1) % 3);
            for (int j = 0; j < 3; j++) {
                int k = (j + 1) % 3;
                const int8_t *ub = m->shift + 6 * u + 2 * j, *ua = m->shift + 6 * u + 2 * k;
                if (m->tri[3 * u + j] != b || m->tri[3 * u + k] != a || ub[0] - ua[0] != sb[0] - sa[0] ||
                    ub[1] - ua[1] != sb[1] - sa[1])
                    continue;
                double q[3];
                fs_mesh_corner(m, u, (j + 2) % 3, q);
                double x = q[0] + (sa[0] - ua[0]) * per[0] - c[0], y = q[1] + (sa[1] - ua[1]) * per[1] - c[1];
                bad += x * x + y * y < r * r * (1.0 - 1e-9);
            }
        }
    }
    return bad;
}

/* Consecutive triangles of every ring are neighbours; closed rings also wrap around; a ring that
 * starts at the boundary starts with its node's boundary edge. Returns the number of open rings, or
 * -1 on a violation. */
static int check_rings(const fs_mesh *m)
{
    int open = 0;
    for (int32_t v = 0; v < m->n_nodes; v++) {
        int32_t s = m->ring_start[v], e = m->ring_start[v + 1];
        if (e - s < 1)
            return -1;
        for (int32_t k = s; k + 1 < e; k++) {
            int32_t t = m->ring_tri[k], u = m->ring_tri[k + 1];
            if (m->adj[3 * t] != u && m->adj[3 * t + 1] != u && m->adj[3 * t + 2] != u)
                return -1;
        }
        int32_t first = m->ring_tri[s], last = m->ring_tri[e - 1];
        bool closed = m->adj[3 * last] == first || m->adj[3 * last + 1] == first || m->adj[3 * last + 2] == first;
        bool starts_open = false, has_v = false;
        for (int c = 0; c < 3; c++)
            if (m->tri[3 * first + c] == v) {
                has_v = true;
                starts_open |= m->adj[3 * first + c] < 0;
            }
        if (!has_v)
            return -1;
        if (starts_open)
            open++;
        else if (!closed)
            return -1;
    }
    return open;
}

static const double *sort_pos;
static int cmp_xy(const void *pa, const void *pb)
{
    const double *a = sort_pos + 3 * *(const int32_t *)pa, *b = sort_pos + 3 * *(const int32_t *)pb;
    if (a[0] != b[0])
        return a[0] < b[0] ? -1 : 1;
    return a[1] < b[1] ? -1 : a[1] > b[1];
}

/* The boundary of the mesh is the convex hull's: every boundary edge runs counter-clockwise along
 * a hull edge (collinear points on the hull are vertices too), and together they are as long as
 * the hull's perimeter. The hull comes from a monotone chain without collinear points. */
static bool boundary_is_hull(const fs_mesh *m)
{
    int32_t n = m->n_nodes;
    int32_t *idx = malloc((size_t)n * sizeof *idx), *hull = malloc(2 * (size_t)n * sizeof *hull);
    for (int32_t i = 0; i < n; i++)
        idx[i] = i;
    sort_pos = m->pos;
    qsort(idx, (size_t)n, sizeof *idx, cmp_xy);
    int k = 0;
    for (int32_t i = 0; i < n; i++) {
        while (k >= 2 && fs_orient2(m->pos + 3 * hull[k - 2], m->pos + 3 * hull[k - 1], m->pos + 3 * idx[i]) <= 0)
            k--;
        hull[k++] = idx[i];
    }
    for (int32_t i = n - 2, lower = k + 1; i >= 0; i--) {
        while (k >= lower && fs_orient2(m->pos + 3 * hull[k - 2], m->pos + 3 * hull[k - 1], m->pos + 3 * idx[i]) <= 0)
            k--;
        hull[k++] = idx[i];
    }
    k--;
    double perimeter = 0.0, length = 0.0, scale = 0.0;
    for (int i = 0; i < k; i++) {
        const double *a = m->pos + 3 * hull[i], *b = m->pos + 3 * hull[i + 1];
        perimeter += hypot(b[0] - a[0], b[1] - a[1]);
        scale = fmax(scale, fmax(fabs(a[0]), fabs(a[1])));
    }
    bool ok = true;
    for (int32_t h = 0; h < 3 * m->n_tris && ok; h++) {
        if (m->adj[h] >= 0)
            continue;
        const double *p = m->pos + 3 * m->tri[h], *q = m->pos + 3 * m->tri[3 * (h / 3) + (h % 3 + 1) % 3];
        length += hypot(q[0] - p[0], q[1] - p[1]);
        bool on_hull = false;
        for (int i = 0; i < k && !on_hull; i++) {
            const double *a = m->pos + 3 * hull[i], *b = m->pos + 3 * hull[i + 1];
            double ab = hypot(b[0] - a[0], b[1] - a[1]);
            double dp = fs_orient2(a, b, p) / ab, dq = fs_orient2(a, b, q) / ab;
            double along = (q[0] - p[0]) * (b[0] - a[0]) + (q[1] - p[1]) * (b[1] - a[1]);
            on_hull = fabs(dp) <= 1e-12 * scale && fabs(dq) <= 1e-12 * scale && along > 0.0;
        }
        ok = on_hull;
    }
    free(idx);
    free(hull);
    return ok && fabs(length - perimeter) <= 1e-9 * perimeter;
}

/* ---- Voronoi facts ---- */

static double sum_cells(const fs_mesh *m, const fs_voronoi *v)
{
    double s = 0.0;
    for (int32_t i = 0; i < m->n_nodes; i++)
        s += v->cell_area[i];
    return s;
}

static double edge_len(const fs_mesh *m, int32_t e)
{
    int32_t t = m->edge_tri[2 * e];
    int i = 0;
    while (m->tri_edge[3 * t + i] != e)
        i++;
    double a[3], b[3], d[3];
    fs_mesh_corner(m, t, i, a);
    fs_mesh_corner(m, t, (i + 1) % 3, b);
    fs_sub3(d, b, a);
    return fs_norm3(d);
}

/* On a closed Delaunay mesh each Voronoi cell splits into triangles of height |e|/2 over the dual
 * edges, so cell_area[v] = sum over v's edges of |e| * dual / 4. Returns the largest relative
 * mismatch. */
static double cell_identity_error(const fs_mesh *m, const fs_voronoi *v)
{
    double *acc = calloc((size_t)m->n_nodes, sizeof *acc);
    for (int32_t e = 0; e < m->n_edges; e++) {
        double q = 0.25 * edge_len(m, e) * v->edge_length[e];
        acc[m->edge[2 * e]] += q;
        acc[m->edge[2 * e + 1]] += q;
    }
    double worst = 0.0;
    for (int32_t i = 0; i < m->n_nodes; i++)
        worst = fmax(worst, fabs(acc[i] - v->cell_area[i]) / v->cell_area[i]);
    free(acc);
    return worst;
}

/* The dual length of every interior edge, recomputed from either side's frame, matches. */
static bool dual_symmetric(const fs_mesh *m, const fs_voronoi *v)
{
    double per[2] = {period_of(m, 0), period_of(m, 1)};
    for (int32_t e = 0; e < m->n_edges; e++) {
        int32_t t = m->edge_tri[2 * e], u = m->edge_tri[2 * e + 1];
        if (u < 0)
            continue;
        double len[2];
        for (int side = 0; side < 2; side++) {
            int32_t p = side ? u : t, q = side ? t : u;
            /* frame offset of q relative to p through node edge[2e], first occurrence in each */
            int cp = 0, cq = 0;
            while (m->tri_edge[3 * p + cp] != e)
                cp++;
            int32_t a = m->tri[3 * p + cp], b = m->tri[3 * p + (cp + 1) % 3];
            while (!(m->tri_edge[3 * q + cq] == e && m->tri[3 * q + cq] == b && m->tri[3 * q + (cq + 1) % 3] == a))
                cq++;
            int ca = (cq + 1) % 3;
            const int8_t *sp = m->shift + 6 * p + 2 * cp, *sq = m->shift + 6 * q + 2 * ca;
            const double *xp = v->circumcenter + 3 * p, *xq = v->circumcenter + 3 * q;
            len[side] = hypot(xq[0] + (sp[0] - sq[0]) * per[0] - xp[0], xq[1] + (sp[1] - sq[1]) * per[1] - xp[1]);
        }
        if (fabs(len[0] - len[1]) > 1e-9 * (len[0] + 1e-12) || fabs(len[0] - v->edge_length[e]) > 1e-9 * (len[0] + 1e-12))
            return false;
    }
    return true;
}

static int count_nonpositive_dual(const fs_mesh *m, const fs_voronoi *v)
{
    int bad = 0;
    for (int32_t e = 0; e < m->n_edges; e++)
        bad += !(v->edge_length[e] > 0.0);
    return bad;
}

/* ---- tests ---- */

static void test_plane_random(void)
{
    fs_domain d = plane_domain(10.0, 6.0, false, false);
    fs_points p = uniform_points(800, 10.0, 6.0, 11);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    CHECK(m.n_nodes == 800);
    CHECK(count_nonpositive(&m) == 0);
    CHECK(count_circle_violations(&m) == 0);
    CHECK(count_nonlocal(&m) == 0);
    CHECK(euler(&m) == 1);
    int32_t b = fs_mesh_count_boundary_edges(&m);
    CHECK(m.n_tris == 2 * m.n_nodes - b - 2);
    CHECK(boundary_is_hull(&m));
    CHECK(check_rings(&m) == b);
    bool ordered = true;
    for (int32_t e = 0; e < m.n_edges; e++)
        ordered &= m.edge[2 * e] < m.edge[2 * e + 1];
    CHECK(ordered);
    fs_mesh_free(&m);
    free(p.p);
}

/* A triangular lattice whose outer rows and columns are collinear: no zero-area triangle, every
 * boundary point on the hull is used. */
static void test_plane_lattice(void)
{
    int gx = 20, gy = 15;
    fs_points p = points_alloc(gx * gy);
    double dx = 0.5, dy = 0.5 * sqrt(3.0) * dx;
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            int k = j * gx + i;
            double shift = (j % 2) ? 0.5 * dx : 0.0;
            p.p[3 * k] = (i == 0 || i == gx - 1) ? i * dx : i * dx + shift;
            p.p[3 * k + 1] = j * dy;
        }
    fs_domain d = plane_domain(gx * dx, gy * dy, false, false);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    CHECK(count_nonpositive(&m) == 0);
    CHECK(euler(&m) == 1);
    int32_t b = fs_mesh_count_boundary_edges(&m);
    CHECK_MSG(b == 2 * (gx - 1) + 2 * (gy - 1), "boundary edges %d", (int)b);
    CHECK(m.n_tris == 2 * m.n_nodes - b - 2);
    CHECK_NEAR(total_area(&m), (gx - 1) * dx * (gy - 1) * dy, 1e-9 * (gx * dx * gy * dy));
    fs_mesh_free(&m);
    free(p.p);
}

static void torus_facts(const fs_mesh *m, double w, double h)
{
    CHECK(count_nonpositive(m) == 0);
    CHECK(fs_mesh_count_boundary_edges(m) == 0);
    CHECK(check_rings(m) == 0);
    CHECK(euler(m) == 0);
    CHECK(m->n_tris == 2 * m->n_nodes);
    CHECK_NEAR(total_area(m), w * h, 1e-9 * w * h);
    CHECK(count_nonlocal(m) == 0);
}

static void test_torus(void)
{
    double w = 7.0, h = 5.0;
    fs_domain d = plane_domain(w, h, true, true);
    fs_points sets[2] = {uniform_points(700, w, h, 21), jittered_points(30, 20, w, h, 22)};
    for (int s = 0; s < 2; s++) {
        fs_mesh m;
        CHECK(fs_delaunay(&d, &sets[s], &m) == 0);
        torus_facts(&m, w, h);
        CHECK(count_circle_violations(&m) == 0);
        fs_mesh_free(&m);
        free(sets[s].p);
    }
}

/* A square grid on the plane: every cell is cocircular, any diagonal is Delaunay; the mesh is
 * still a valid triangulation of the rectangle. */
static void test_plane_square_grid(void)
{
    int gx = 15, gy = 11;
    fs_points p = points_alloc(gx * gy);
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            p.p[3 * (j * gx + i)] = i * 0.5;
            p.p[3 * (j * gx + i) + 1] = j * 0.5;
        }
    fs_domain d = plane_domain(gx * 0.5, gy * 0.5, false, false);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    CHECK(count_nonpositive(&m) == 0);
    CHECK(euler(&m) == 1);
    CHECK(m.n_tris == 2 * (gx - 1) * (gy - 1));
    CHECK(fs_mesh_count_boundary_edges(&m) == 2 * (gx - 1) + 2 * (gy - 1));
    CHECK(count_circle_violations(&m) == 0);
    CHECK_NEAR(total_area(&m), (gx - 1) * 0.5 * (gy - 1) * 0.5, 1e-12);
    fs_mesh_free(&m);
    free(p.p);
}

/* A square grid is cocircular everywhere: the tie-breaking retry must still close the torus. */
static void test_torus_square_grid(void)
{
    int gx = 12, gy = 9;
    fs_points p = points_alloc(gx * gy);
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            p.p[3 * (j * gx + i)] = i * 0.5;
            p.p[3 * (j * gx + i) + 1] = j * 0.5;
        }
    fs_domain d = plane_domain(gx * 0.5, gy * 0.5, true, true);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    torus_facts(&m, gx * 0.5, gy * 0.5);
    fs_mesh_free(&m);
    free(p.p);
}

/* Three and five points on a torus: edges from a node to its own image, triangles next to
 * themselves across the seam. */
static void test_torus_tiny(void)
{
    int sizes[2] = {3, 5};
    for (int s = 0; s < 2; s++) {
        fs_domain d = plane_domain(3.0, 2.0, true, true);
        fs_points p = uniform_points(sizes[s], 3.0, 2.0, 31 + s);
        fs_mesh m;
        CHECK(fs_delaunay(&d, &p, &m) == 0);
        torus_facts(&m, 3.0, 2.0);
        CHECK(count_circle_violations(&m) == 0);
        fs_voronoi v;
        CHECK(fs_voronoi_build(&m, &v) == 0);
        CHECK_NEAR(sum_cells(&m, &v), 6.0, 1e-9 * 6.0);
        fs_voronoi_free(&v);
        fs_mesh_free(&m);
        free(p.p);
    }
}

/* Periodic in one direction: an annulus whose boundaries run along the lowest and highest rows. */
static void strip_facts(const fs_mesh *m, int axis, double period)
{
    int o = 1 - axis;
    double lo = INFINITY, hi = -INFINITY;
    for (int32_t i = 0; i < m->n_nodes; i++) {
        lo = fmin(lo, m->pos[3 * i + o]);
        hi = fmax(hi, m->pos[3 * i + o]);
    }
    CHECK(count_nonpositive(m) == 0);
    CHECK(euler(m) == 0);
    CHECK(check_rings(m) >= 0);
    int off_row = 0;
    for (int64_t h = 0; h < 3 * (int64_t)m->n_tris; h++) {
        if (m->adj[h] >= 0)
            continue;
        double ya = m->pos[3 * m->tri[h] + o], yb = m->pos[3 * m->tri[3 * (h / 3) + (h % 3 + 1) % 3] + o];
        off_row += !((ya == lo && yb == lo) || (ya == hi && yb == hi));
    }
    CHECK(off_row == 0);
    CHECK(fs_mesh_count_boundary_edges(m) >= 2);
    CHECK_NEAR(total_area(m), period * (hi - lo), 1e-9 * period * (hi - lo));
    CHECK(count_nonlocal(m) == 0);
    if (m->n_nodes <= 2000)
        CHECK(count_circle_violations(m) == 0);
}

static void test_periodic_one_direction(void)
{
    for (int axis = 0; axis < 2; axis++) {
        fs_domain d = plane_domain(6.0, 4.0, axis == 0, axis == 1);
        fs_points p = uniform_points(400, 6.0, 4.0, 41 + axis);
        fs_mesh m;
        CHECK(fs_delaunay(&d, &p, &m) == 0);
        strip_facts(&m, axis, axis == 0 ? 6.0 : 4.0);
        fs_mesh_free(&m);
        free(p.p);
    }
}

/* Points whose outer rows lie exactly on y = 0 and y = H (as a sampler clamping to the domain
 * leaves them): every point of those rows is on the boundary, joined to its neighbours. */
static void test_periodic_rows(void)
{
    int gx = 24, gy = 10;
    double w = 6.0, h = 3.0;
    fs_points p = jittered_points(gx, gy, w, h, 51);
    for (int i = 0; i < gx; i++) {
        p.p[3 * i + 1] = 0.0;
        p.p[3 * ((gy - 1) * gx + i) + 1] = h;
    }
    fs_domain d = plane_domain(w, h, true, false);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    strip_facts(&m, 0, w);
    CHECK(fs_mesh_count_boundary_edges(&m) == 2 * gx);
    fs_mesh_free(&m);
    free(p.p);
}

static void test_cylinder(void)
{
    double r = 1.5, h = 4.0, w = 2.0 * FS_PI * r;
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_CYLINDER;
    d.radius = r;
    d.height = h;
    fs_points p = jittered_points(24, 10, w, h, 61);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    CHECK(m.domain.periodic_x);
    strip_facts(&m, 0, w);
    fs_voronoi v;
    CHECK(fs_voronoi_build(&m, &v) == 0);
    CHECK_NEAR(sum_cells(&m, &v), w * h, 1e-9 * w * h);
    fs_voronoi_free(&v);
    fs_mesh_free(&m);

    d.periodic_y = true;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    torus_facts(&m, w, h);
    CHECK(count_circle_violations(&m) == 0);
    fs_mesh_free(&m);
    free(p.p);
}

/* Largest signed distance of any point outside a triangle's plane (inside its circumcircle). */
static double sphere_worst_outside(const fs_mesh *m)
{
    double worst = -INFINITY;
    for (int32_t t = 0; t < m->n_tris; t++) {
        double a[3], b[3], c[3], ab[3], ac[3], n[3], q[3];
        fs_mesh_corner(m, t, 0, a);
        fs_mesh_corner(m, t, 1, b);
        fs_mesh_corner(m, t, 2, c);
        fs_sub3(ab, b, a);
        fs_sub3(ac, c, a);
        fs_cross3(n, ab, ac);
        double len = fs_norm3(n);
        for (int32_t i = 0; i < m->n_nodes; i++) {
            fs_sub3(q, m->pos + 3 * i, a);
            worst = fmax(worst, fs_dot3(n, q) / len);
        }
    }
    return worst;
}

static void test_sphere(void)
{
    double r = 2.0, full = 4.0 * FS_PI * r * r;
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_SPHERE;
    d.radius = r;
    double deficit[2];
    int sizes[2] = {1000, 4000};
    for (int s = 0; s < 2; s++) {
        fs_points p = sphere_points(sizes[s], r, 71);
        fs_mesh m;
        CHECK(fs_delaunay(&d, &p, &m) == 0);
        CHECK(euler(&m) == 2);
        CHECK(m.n_tris == 2 * m.n_nodes - 4);
        CHECK(fs_mesh_count_boundary_edges(&m) == 0);
        CHECK(check_rings(&m) == 0);
        CHECK(count_nonpositive(&m) == 0);
        if (s == 0)
            CHECK(sphere_worst_outside(&m) <= 1e-9 * r);
        deficit[s] = (full - total_area(&m)) / full;
        CHECK(deficit[s] > 0.0);
        fs_mesh_free(&m);
        free(p.p);
    }
    CHECK_MSG(deficit[0] < 0.01, "area deficit %g", deficit[0]);
    CHECK_MSG(deficit[1] < 0.5 * deficit[0], "deficits %g %g", deficit[0], deficit[1]);
}

/* Jittered points whose outer rows and columns lie exactly on the edges that do not wrap, as the
 * sampler leaves them (it snaps particles to a non-periodic side). */
static fs_points clamped_points(int gx, int gy, double w, double h, bool wrap_x, bool wrap_y, uint64_t seed)
{
    fs_points p = jittered_points(gx, gy, w, h, seed);
    for (int j = 0; j < gy; j++)
        for (int i = 0; i < gx; i++) {
            double *q = p.p + 3 * (j * gx + i);
            if (!wrap_x && (i == 0 || i == gx - 1))
                q[0] = i == 0 ? 0.0 : w;
            if (!wrap_y && (j == 0 || j == gy - 1))
                q[1] = j == 0 ? 0.0 : h;
        }
    return p;
}

/* More than 65536 points are triangulated in blocks (in parallel): the merged mesh is still the
 * one Delaunay triangulation, with no seam along the block cuts, on every 2-D domain. In the last
 * set a notch in the bottom edge is bridged by a hull edge across the cut between the blocks: the
 * triangulation falls back to one block. */
static void test_blocks(void)
{
    double w = 27.0, h = 26.0;
    int gx = 270, gy = 260;
    for (int k = 0; k < 4; k++) {
        bool wx = k == 1 || k == 2, wy = k == 2;
        fs_points p = clamped_points(gx, gy, w, h, wx, wy, 101);
        if (k == 3) {
            /* a notch in the middle of the bottom edge, bridged by one long hull edge */
            int32_t kept = 0;
            for (int32_t i = 0; i < p.n; i++) {
                const double *q = p.p + 3 * i;
                if (fabs(q[0] - 0.5 * w) < 4.0 && q[1] < 2.0)
                    continue;
                memmove(p.p + 3 * kept++, q, 3 * sizeof *q);
            }
            p.n = kept;
        }
        fs_domain d = plane_domain(w, h, wx, wy);
        fs_mesh m;
        CHECK(fs_delaunay(&d, &p, &m) == 0);
        CHECK(count_nonpositive(&m) == 0);
        CHECK(count_nonlocal(&m) == 0);
        if (k == 0 || k == 3) {
            int32_t b = fs_mesh_count_boundary_edges(&m);
            CHECK(euler(&m) == 1);
            CHECK(m.n_tris == 2 * m.n_nodes - b - 2);
            CHECK(boundary_is_hull(&m));
        } else if (k == 1) {
            CHECK(euler(&m) == 0);
            CHECK(check_rings(&m) >= 0);
            CHECK(fs_mesh_count_boundary_edges(&m) == 2 * gx);
        } else {
            torus_facts(&m, w, h);
        }
        fs_mesh_free(&m);
        free(p.p);
    }
}

/* The numbering of a mesh (nodes as given; triangles, edges and rings in their canonical order) is
 * part of every output. Large sets, triangulated in blocks and with the mesh passes run in parallel,
 * give the same arrays on one thread and on two, equal to digests recorded with the serial merge,
 * adjacency, edges and rings (a change here changes outputs). A copy of such a mesh with one
 * triangle twice is refused with the same message at either thread count. */
static void test_numbering(void)
{
    static const uint64_t want[3] = {UINT64_C(0x768fa9d2cba5f6ec), UINT64_C(0x37eb322ca1e91ba0),
                                     UINT64_C(0xb1512453eff15fc9)};
    double w = 27.0, h = 26.0;
    for (int k = 0; k < 3; k++) {
        bool wx = k >= 1, wy = k == 2;
        fs_points p = clamped_points(270, 260, w, h, wx, wy, 202);
        fs_domain d = plane_domain(w, h, wx, wy);
        char why[2][1024];
        for (int threads = 1; threads <= 2; threads++) {
            fs_threads_set(threads);
            fs_mesh m;
            CHECK(fs_delaunay(&d, &p, &m) == 0);
            uint64_t got = fs_mesh_digest(&m);
            CHECK_MSG(got == want[k], "set %d, %d threads: digest %016llx, expected %016llx", k, threads,
                      (unsigned long long)got, (unsigned long long)want[k]);
            m.tri = realloc(m.tri, (3 * (size_t)m.n_tris + 3) * sizeof *m.tri);
            m.shift = realloc(m.shift, (6 * (size_t)m.n_tris + 6) * sizeof *m.shift);
            memcpy(m.tri + 3 * (size_t)m.n_tris, m.tri + 3 * (size_t)(m.n_tris / 2), 3 * sizeof *m.tri);
            memcpy(m.shift + 6 * (size_t)m.n_tris, m.shift + 6 * (size_t)(m.n_tris / 2), 6 * sizeof *m.shift);
            m.n_tris++;
            CHECK(fs_mesh_build_adjacency(&m) == -1);
            snprintf(why[threads - 1], sizeof why[0], "%s", fs_error_message());
            fs_mesh_free(&m);
        }
        CHECK_MSG(strcmp(why[0], why[1]) == 0, "set %d: '%s' on one thread, '%s' on two", k, why[0], why[1]);
        free(p.p);
    }
    fs_threads_set(0);
}

static void test_voronoi_torus(void)
{
    double w = 5.0, h = 4.0;
    fs_domain d = plane_domain(w, h, true, true);
    fs_points p = uniform_points(600, w, h, 81);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    fs_voronoi v;
    CHECK(fs_voronoi_build(&m, &v) == 0);
    CHECK_NEAR(sum_cells(&m, &v), w * h, 1e-9 * w * h);
    CHECK(count_nonpositive_dual(&m, &v) == 0);
    CHECK(dual_symmetric(&m, &v));
    CHECK_MSG(cell_identity_error(&m, &v) < 1e-9, "cell identity %g", cell_identity_error(&m, &v));
    int small = 0;
    for (int32_t i = 0; i < m.n_nodes; i++)
        small += !(v.cell_area[i] > 0.0);
    CHECK(small == 0);
    fs_voronoi_free(&v);
    fs_mesh_free(&m);
    free(p.p);
}

static bool inside_rect(const double *p, double w, double h)
{
    return p[0] >= 0.0 && p[0] <= w && p[1] >= 0.0 && p[1] <= h;
}

static void test_voronoi_plane(void)
{
    double w = 8.0, h = 5.0;
    fs_domain d = plane_domain(w, h, false, false);
    fs_points sets[2] = {uniform_points(500, w, h, 91), jittered_points(25, 16, w, h, 92)};
    for (int s = 0; s < 2; s++) {
        fs_mesh m;
        CHECK(fs_delaunay(&d, &sets[s], &m) == 0);
        fs_voronoi v;
        CHECK(fs_voronoi_build(&m, &v) == 0);
        CHECK_NEAR(sum_cells(&m, &v), w * h, 1e-9 * w * h);
        /* edges whose circumcentres both lie inside the rectangle keep their full length; zero
         * length only where the Voronoi edge leaves the rectangle */
        int negative = 0, wrong = 0;
        for (int32_t e = 0; e < m.n_edges; e++) {
            negative += v.edge_length[e] < 0.0;
            int32_t t = m.edge_tri[2 * e], u = m.edge_tri[2 * e + 1];
            const double *ct = v.circumcenter + 3 * t, *cu = u >= 0 ? v.circumcenter + 3 * u : NULL;
            bool in_t = inside_rect(ct, w, h), in_u = cu && inside_rect(cu, w, h);
            if (in_t && in_u)
                wrong += fabs(v.edge_length[e] - hypot(ct[0] - cu[0], ct[1] - cu[1])) > 1e-12 * w;
            if (in_t && !(v.edge_length[e] > 0.0))
                wrong++;
        }
        CHECK(negative == 0);
        CHECK(wrong == 0);
        /* a cell whose circumcentres all lie inside the rectangle is not clipped: |e| * dual / 4 */
        double *acc = calloc((size_t)m.n_nodes, sizeof *acc);
        for (int32_t e = 0; e < m.n_edges; e++) {
            double q = 0.25 * edge_len(&m, e) * v.edge_length[e];
            acc[m.edge[2 * e]] += q;
            acc[m.edge[2 * e + 1]] += q;
        }
        int whole = 0, mismatch = 0;
        for (int32_t i = 0; i < m.n_nodes; i++) {
            bool inside = true;
            for (int32_t k = m.ring_start[i]; k < m.ring_start[i + 1]; k++) {
                int32_t t = m.ring_tri[k];
                inside &= inside_rect(v.circumcenter + 3 * t, w, h) && m.adj[3 * t] >= 0 && m.adj[3 * t + 1] >= 0 &&
                          m.adj[3 * t + 2] >= 0;
            }
            if (!inside)
                continue;
            whole++;
            mismatch += fabs(acc[i] - v.cell_area[i]) > 1e-9 * v.cell_area[i];
        }
        free(acc);
        CHECK(mismatch == 0);
        CHECK_MSG(whole > m.n_nodes * 3 / 4, "%d of %d cells unclipped", whole, (int)m.n_nodes);
        fs_voronoi_free(&v);
        fs_mesh_free(&m);
        free(sets[s].p);
    }
}

static void test_voronoi_strip(void)
{
    double w = 6.0, h = 4.0;
    fs_domain d = plane_domain(w, h, true, false);
    fs_points p = uniform_points(300, w, h, 95);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    fs_voronoi v;
    CHECK(fs_voronoi_build(&m, &v) == 0);
    CHECK_NEAR(sum_cells(&m, &v), w * h, 1e-9 * w * h);
    fs_voronoi_free(&v);
    fs_mesh_free(&m);
    free(p.p);
}

static void test_voronoi_sphere(void)
{
    double r = 3.0, full = 4.0 * FS_PI * r * r;
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_SPHERE;
    d.radius = r;
    fs_points p = sphere_points(1500, r, 97);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &p, &m) == 0);
    fs_voronoi v;
    CHECK(fs_voronoi_build(&m, &v) == 0);
    CHECK_NEAR(sum_cells(&m, &v), full, 1e-9 * full);
    CHECK(count_nonpositive_dual(&m, &v) == 0);
    bool on_sphere = true;
    for (int32_t t = 0; t < m.n_tris; t++)
        on_sphere &= fabs(fs_norm3(v.circumcenter + 3 * t) - r) < 1e-9 * r;
    CHECK(on_sphere);
    /* flat-triangle identity only holds to the curvature of the cells: h^2 / R^2 ~ 1e-2 */
    CHECK_MSG(cell_identity_error(&m, &v) < 0.05, "cell identity %g", cell_identity_error(&m, &v));
    fs_voronoi_free(&v);
    fs_mesh_free(&m);
    free(p.p);
}

static bool fails_with_data_error(const fs_domain *d, const fs_points *p)
{
    fs_mesh m;
    fs_error_clear();
    int rc = fs_delaunay(d, p, &m);
    bool ok = rc == -1 && fs_error_domain() == FS_ERR_DATA && m.n_nodes == 0 && !m.tri && !m.pos;
    if (rc == 0)
        fs_mesh_free(&m);
    return ok;
}

static void test_degenerate(void)
{
    fs_domain plane = plane_domain(10.0, 10.0, false, false);
    fs_domain torus = plane_domain(10.0, 10.0, true, true);
    fs_domain strip = plane_domain(10.0, 10.0, true, false);
    fs_domain sphere = fs_domain_default();
    sphere.type = FS_DOMAIN_SPHERE;
    sphere.radius = 1.0;

    fs_points two = uniform_points(2, 10.0, 10.0, 1);
    CHECK(fails_with_data_error(&plane, &two));
    CHECK(fails_with_data_error(&torus, &two));
    fs_points none = {0, NULL};
    CHECK(fails_with_data_error(&plane, &none));

    fs_points line = points_alloc(50);
    for (int i = 0; i < 50; i++) {
        line.p[3 * i] = 0.1 * i;
        line.p[3 * i + 1] = 0.3 + 0.05 * i;
    }
    CHECK(fails_with_data_error(&plane, &line));
    for (int i = 0; i < 50; i++)
        line.p[3 * i + 1] = 2.5;
    CHECK(fails_with_data_error(&strip, &line));

    fs_points dup = uniform_points(100, 10.0, 10.0, 2);
    dup.p[3 * 70] = dup.p[3 * 20];
    dup.p[3 * 70 + 1] = dup.p[3 * 20 + 1];
    CHECK(fails_with_data_error(&plane, &dup));
    CHECK(strstr(fs_error_message(), "20") && strstr(fs_error_message(), "70"));
    CHECK(fails_with_data_error(&torus, &dup));
    /* the same point modulo the period */
    fs_points seam = uniform_points(100, 10.0, 10.0, 3);
    seam.p[3 * 5] = 0.0;
    seam.p[3 * 6] = 10.0;
    seam.p[3 * 6 + 1] = seam.p[3 * 5 + 1];
    CHECK(fails_with_data_error(&torus, &seam));

    fs_points three = sphere_points(3, 1.0, 4);
    CHECK(fails_with_data_error(&sphere, &three));
    fs_points ring = points_alloc(20);
    for (int i = 0; i < 20; i++) {
        ring.p[3 * i] = cos(0.3 * i);
        ring.p[3 * i + 1] = sin(0.3 * i);
    }
    CHECK(fails_with_data_error(&sphere, &ring));
    fs_points off = sphere_points(100, 1.0, 5);
    off.p[3 * 10] *= 1.1;
    CHECK(fails_with_data_error(&sphere, &off));
    fs_points cap = sphere_points(200, 1.0, 6);
    for (int i = 0; i < 200; i++)
        cap.p[3 * i + 2] = fabs(cap.p[3 * i + 2]) * 0.5 + 0.5;
    for (int i = 0; i < 200; i++) {
        double s = sqrt(fmax(0.0, 1.0 - cap.p[3 * i + 2] * cap.p[3 * i + 2]));
        double l = hypot(cap.p[3 * i], cap.p[3 * i + 1]);
        cap.p[3 * i] = l > 0 ? cap.p[3 * i] * s / l : s;
        cap.p[3 * i + 1] = l > 0 ? cap.p[3 * i + 1] * s / l : 0.0;
    }
    CHECK(fails_with_data_error(&sphere, &cap));

    fs_points nan = uniform_points(10, 1.0, 1.0, 7);
    nan.p[4] = NAN;
    CHECK(fails_with_data_error(&plane, &nan));

    free(two.p);
    free(line.p);
    free(dup.p);
    free(seam.p);
    free(three.p);
    free(ring.p);
    free(off.p);
    free(cap.p);
    free(nan.p);
}

/* Hand-made meshes: a square of two triangles, then a fin of three triangles on one edge. */
static void test_adjacency(void)
{
    double pos[5 * 3] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0, 0.5, -1, 0};
    int32_t tri[9] = {0, 1, 2, 0, 2, 3, 0, 2, 4};
    int8_t shift[18] = {0};
    fs_mesh m;
    memset(&m, 0, sizeof m);
    m.domain = plane_domain(2.0, 2.0, false, false);
    m.n_nodes = 5;
    m.pos = malloc(sizeof pos);
    memcpy(m.pos, pos, sizeof pos);
    m.n_tris = 2;
    m.tri = malloc(sizeof tri);
    memcpy(m.tri, tri, sizeof tri);
    m.shift = malloc(sizeof shift);
    memcpy(m.shift, shift, sizeof shift);
    CHECK(fs_mesh_build_adjacency(&m) == 0);
    CHECK(m.adj[2] == 1 && m.adj[3] == 0);
    CHECK(fs_mesh_count_boundary_edges(&m) == 4);
    fs_mesh_build_edges(&m);
    CHECK(m.n_edges == 5);
    fs_mesh_build_rings(&m);
    CHECK(m.ring_start[1] - m.ring_start[0] == 2 && m.ring_tri[m.ring_start[0]] == 0);
    CHECK_NEAR(fs_mesh_tri_area(&m, 1), 0.5, 1e-15);

    m.n_tris = 3;
    fs_error_clear();
    CHECK(fs_mesh_build_adjacency(&m) == -1 && fs_error_domain() == FS_ERR_DATA);
    fs_mesh_free(&m);
    CHECK(m.pos == NULL && m.n_nodes == 0);
}

/* Adds a node at position p (which may point into m->pos, which moves). */
static int32_t add_node(fs_mesh *m, const double p[3])
{
    double q[3] = {p[0], p[1], p[2]};
    m->pos = realloc(m->pos, 3 * ((size_t)m->n_nodes + 1) * sizeof *m->pos);
    memcpy(m->pos + 3 * (size_t)m->n_nodes, q, sizeof q);
    return m->n_nodes++;
}

/* Appends triangle (a, b, c) with zero shifts. */
static void add_tri(fs_mesh *m, int32_t a, int32_t b, int32_t c)
{
    m->tri = realloc(m->tri, 3 * ((size_t)m->n_tris + 1) * sizeof *m->tri);
    m->shift = realloc(m->shift, 6 * ((size_t)m->n_tris + 1) * sizeof *m->shift);
    int32_t *t = m->tri + 3 * (size_t)m->n_tris;
    t[0] = a, t[1] = b, t[2] = c;
    memset(m->shift + 6 * (size_t)m->n_tris, 0, 6 * sizeof *m->shift);
    m->n_tris++;
}

/* Does the adjacency equal that of a full rebuild? */
static bool adjacency_as_rebuilt(const fs_mesh *m)
{
    int32_t *local = malloc(3 * (size_t)m->n_tris * sizeof *local);
    memcpy(local, m->adj, 3 * (size_t)m->n_tris * sizeof *local);
    fs_mesh copy = *m;
    copy.adj = NULL;
    bool same = fs_mesh_build_adjacency(&copy) == 0 &&
                memcmp(local, copy.adj, 3 * (size_t)m->n_tris * sizeof *local) == 0;
    free(copy.adj);
    free(local);
    return same;
}

/* Local changes of a torus mesh (off the seams, where the shifts are zero): a node inserted in a
 * triangle (one changed, two new), a triangle cut loose by giving it copies of two of its nodes, a
 * whole batch of both at once. After each, fs_mesh_update_adjacency equals a full rebuild. */
static void test_update_adjacency(void)
{
    double w = 6.0, h = 5.0;
    fs_domain d = plane_domain(w, h, true, true);
    fs_points pts = uniform_points(600, w, h, 31);
    fs_mesh m;
    CHECK(fs_delaunay(&d, &pts, &m) == 0);
    free(pts.p);
    int changes = 0;
    for (int round = 0; round < 3; round++) {
        int32_t n_tris_before = m.n_tris, changed[40], n_changed = 0;
        for (int32_t t = 7 + 13 * round; t < n_tris_before && n_changed < (round == 2 ? 40 : 1); t += 37) {
            bool seam = false;
            for (int k = 0; k < 6; k++)
                seam |= m.shift[6 * (size_t)t + k] != 0;
            if (seam)
                continue;
            int32_t *c = m.tri + 3 * (size_t)t, a = c[0], b = c[1], e = c[2];
            if ((t / 37) % 2 == 0) { /* insert the centroid */
                double p[3] = {0, 0, 0};
                for (int k = 0; k < 3; k++)
                    for (int l = 0; l < 3; l++)
                        p[l] += m.pos[3 * (size_t)c[k] + l] / 3.0;
                int32_t q = add_node(&m, p);
                c = m.tri + 3 * (size_t)t;
                c[2] = q;
                add_tri(&m, b, e, q);
                add_tri(&m, e, a, q);
            } else { /* cut it loose at two corners */
                int32_t a2 = add_node(&m, m.pos + 3 * (size_t)a), b2 = add_node(&m, m.pos + 3 * (size_t)b);
                c = m.tri + 3 * (size_t)t;
                c[0] = a2, c[1] = b2;
            }
            changed[n_changed++] = t;
        }
        CHECK(n_changed > 0);
        CHECK(fs_mesh_update_adjacency(&m, n_tris_before, changed, n_changed) == 0);
        CHECK_MSG(adjacency_as_rebuilt(&m), "round %d: %d changed, %d new triangles", round, (int)n_changed,
                  (int)(m.n_tris - n_tris_before));
        changes += n_changed;
    }
    CHECK(changes > 10);
    fs_mesh_free(&m);
}

int main(void)
{
    RUN(test_adjacency);
    RUN(test_update_adjacency);
    RUN(test_plane_random);
    RUN(test_plane_lattice);
    RUN(test_plane_square_grid);
    RUN(test_torus);
    RUN(test_torus_square_grid);
    RUN(test_torus_tiny);
    RUN(test_periodic_one_direction);
    RUN(test_periodic_rows);
    RUN(test_cylinder);
    RUN(test_sphere);
    RUN(test_blocks);
    RUN(test_numbering);
    RUN(test_voronoi_torus);
    RUN(test_voronoi_plane);
    RUN(test_voronoi_strip);
    RUN(test_voronoi_sphere);
    RUN(test_degenerate);
    return check_finish();
}
