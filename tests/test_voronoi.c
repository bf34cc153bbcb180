/* Tests of the voronoi model: cells tile the texture, cracks follow Voronoi edges, seams close up. */
#include "model/voronoi.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "check.h"
#include "geom/delaunay.h"
#include "geom/sample.h"

/* ---- meshes built by hand ---- */

/* Twice the signed area of (a, b, c) > 0 iff d lies inside its circumcircle (a, b, c counter-clockwise). */
static bool in_circle(const double *a, const double *b, const double *c, const double *d)
{
    double ax = a[0] - d[0], ay = a[1] - d[1], bx = b[0] - d[0], by = b[1] - d[1];
    double cx = c[0] - d[0], cy = c[1] - d[1];
    double det = (ax * ax + ay * ay) * (bx * cy - cx * by) - (bx * bx + by * by) * (ax * cy - cx * ay) +
                 (cx * cx + cy * cy) * (ax * by - bx * ay);
    return det > 0.0;
}

/* Appends triangle (q0, q1, q2) of grid corners with their unwrapped image shifts, storing the shifts
 * relative to the first corner as mesh.h asks. */
static void push_tri(fs_mesh *m, const int32_t *node, const int (*shift)[2], int q0, int q1, int q2)
{
    int q[3] = {q0, q1, q2};
    int32_t t = m->n_tris++;
    for (int k = 0; k < 3; k++) {
        m->tri[3 * t + k] = node[q[k]];
        m->shift[6 * t + 2 * k] = (int8_t)(shift[q[k]][0] - shift[q[0]][0]);
        m->shift[6 * t + 2 * k + 1] = (int8_t)(shift[q[k]][1] - shift[q[0]][1]);
    }
}

/* A Delaunay triangulation of a jittered nx x ny grid on a w x h plane (or cylinder of that
 * unwrapped size). Periodic axes wrap; on a non-periodic y axis the first and last rows lie on
 * y = 0 and y = h so the hull is the rectangle's border. Each grid square is split along the
 * diagonal that passes the empty-circumcircle test, which makes the whole mesh Delaunay for a
 * jitter well below half a cell. */
static void grid_mesh(fs_mesh *m, fs_domain d, int nx, int ny, double jitter, uint64_t seed)
{
    memset(m, 0, sizeof *m);
    fs_domain_normalize(&d);
    m->domain = d;
    double w = fs_domain_extent_x(&d), h = fs_domain_extent_y(&d);
    bool px = d.periodic_x, py = d.periodic_y;
    m->n_nodes = nx * ny;
    m->pos = fs_calloc(3 * (size_t)m->n_nodes, sizeof *m->pos);
    for (int j = 0; j < ny; j++)
        for (int i = 0; i < nx; i++) {
            int32_t v = j * nx + i;
            double jx = fs_rand_range(seed, FS_RNG_TEST, 2 * (uint64_t)v, -jitter, jitter);
            double jy = fs_rand_range(seed, FS_RNG_TEST, 2 * (uint64_t)v + 1, -jitter, jitter);
            m->pos[3 * v] = (i + 0.5 + jx) * w / nx;
            if (py)
                m->pos[3 * v + 1] = (j + 0.5 + jy) * h / ny;
            else
                m->pos[3 * v + 1] = (j + ((j == 0 || j == ny - 1) ? 0.0 : jy)) * h / (ny - 1);
        }
    int sx = px ? nx : nx - 1, sy = py ? ny : ny - 1;
    m->tri = fs_malloc(6 * (size_t)sx * sy * sizeof *m->tri);
    m->shift = fs_calloc(12 * (size_t)sx * sy, sizeof *m->shift);
    for (int j = 0; j < sy; j++)
        for (int i = 0; i < sx; i++) {
            int ci[4] = {i, i + 1, i + 1, i}, cj[4] = {j, j, j + 1, j + 1};
            int32_t node[4];
            int shift[4][2];
            double p[4][2];
            for (int k = 0; k < 4; k++) {
                shift[k][0] = ci[k] == nx;
                shift[k][1] = cj[k] == ny;
                node[k] = (cj[k] % ny) * nx + ci[k] % nx;
                p[k][0] = m->pos[3 * node[k]] + shift[k][0] * w;
                p[k][1] = m->pos[3 * node[k] + 1] + shift[k][1] * h;
            }
            if (!in_circle(p[0], p[1], p[2], p[3])) {
                push_tri(m, node, (const int(*)[2])shift, 0, 1, 2);
                push_tri(m, node, (const int(*)[2])shift, 0, 2, 3);
            } else {
                push_tri(m, node, (const int(*)[2])shift, 0, 1, 3);
                push_tri(m, node, (const int(*)[2])shift, 1, 2, 3);
            }
        }
    FS_ASSERT(fs_mesh_build_adjacency(m) == 0);
    fs_mesh_build_edges(m);
    fs_mesh_build_rings(m);
}

/* An icosahedron with each face cut into f x f triangles, projected onto the sphere and turned so
 * that neither pole is a node or lies on an edge. */
static void geodesic_mesh(fs_mesh *m, double radius, int f)
{
    static const int face[20][3] = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                    {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                    {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                    {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    double g = (1.0 + sqrt(5.0)) / 2.0;
    double ico[12][3] = {{-1, g, 0}, {1, g, 0}, {-1, -g, 0}, {1, -g, 0}, {0, -1, g}, {0, 1, g},
                         {0, -1, -g}, {0, 1, -g}, {g, 0, -1}, {g, 0, 1}, {-g, 0, -1}, {-g, 0, 1}};
    /* a fixed generic rotation */
    double ca = cos(0.3), sa = sin(0.3), cb = cos(0.7), sb = sin(0.7);
    memset(m, 0, sizeof *m);
    m->domain = fs_domain_default();
    m->domain.type = FS_DOMAIN_SPHERE;
    m->domain.radius = radius;
    fs_domain_normalize(&m->domain);
    int per_face = (f + 1) * (f + 2) / 2;
    m->pos = fs_malloc(3 * (size_t)20 * per_face * sizeof *m->pos);
    m->tri = fs_malloc(3 * (size_t)20 * f * f * sizeof *m->tri);
    int32_t *local = fs_malloc((size_t)per_face * sizeof *local);
    for (int fc = 0; fc < 20; fc++) {
        const double *A = ico[face[fc][0]], *B = ico[face[fc][1]], *C = ico[face[fc][2]];
        for (int i = 0, k = 0; i <= f; i++)
            for (int j = 0; i + j <= f; j++, k++) {
                double p[3], q[3], dd[3];
                for (int c = 0; c < 3; c++)
                    p[c] = A[c] + (B[c] - A[c]) * i / f + (C[c] - A[c]) * j / f;
                double r = fs_norm3(p);
                q[0] = p[0] / r;
                q[1] = ca * p[1] / r - sa * p[2] / r;
                q[2] = sa * p[1] / r + ca * p[2] / r;
                p[0] = cb * q[0] + sb * q[2];
                p[1] = q[1];
                p[2] = -sb * q[0] + cb * q[2];
                int32_t found = -1;
                for (int32_t v = 0; v < m->n_nodes && found < 0; v++) {
                    for (int c = 0; c < 3; c++)
                        dd[c] = m->pos[3 * v + c] - radius * p[c];
                    if (fs_norm3(dd) < 1e-9 * radius)
                        found = v;
                }
                if (found < 0) {
                    found = m->n_nodes++;
                    for (int c = 0; c < 3; c++)
                        m->pos[3 * found + c] = radius * p[c];
                }
                local[k] = found;
            }
        for (int i = 0; i < f; i++)
            for (int j = 0; i + j < f; j++) {
                /* index of (i, j) in the row-major triangle layout */
                int k00 = i * (f + 1) - i * (i - 1) / 2 + j;
                int k10 = (i + 1) * (f + 1) - (i + 1) * i / 2 + j;
                int k01 = k00 + 1;
                int32_t t = m->n_tris++;
                m->tri[3 * t] = local[k00];
                m->tri[3 * t + 1] = local[k10];
                m->tri[3 * t + 2] = local[k01];
                if (i + j + 1 < f) {
                    int k11 = k10 + 1;
                    t = m->n_tris++;
                    m->tri[3 * t] = local[k10];
                    m->tri[3 * t + 1] = local[k11];
                    m->tri[3 * t + 2] = local[k01];
                }
            }
    }
    free(local);
    m->shift = fs_calloc(6 * (size_t)m->n_tris, sizeof *m->shift);
    /* make every triangle counter-clockwise seen from outside */
    for (int32_t t = 0; t < m->n_tris; t++) {
        double a[3], b[3], c[3], ab[3], ac[3], n[3];
        fs_mesh_corner(m, t, 0, a);
        fs_mesh_corner(m, t, 1, b);
        fs_mesh_corner(m, t, 2, c);
        fs_sub3(ab, b, a);
        fs_sub3(ac, c, a);
        fs_cross3(n, ab, ac);
        if (fs_dot3(n, a) < 0.0) {
            int32_t tmp = m->tri[3 * t + 1];
            m->tri[3 * t + 1] = m->tri[3 * t + 2];
            m->tri[3 * t + 2] = tmp;
        }
    }
    FS_ASSERT(fs_mesh_build_adjacency(m) == 0);
    fs_mesh_build_edges(m);
    fs_mesh_build_rings(m);
}

/* ---- measurements on a render mesh ---- */

static void tri_uv(const fs_surface *r, int32_t t, double (*p)[2])
{
    for (int k = 0; k < 3; k++) {
        int32_t v = r->tri[3 * t + k];
        p[k][0] = r->uv[2 * v];
        p[k][1] = r->uv[2 * v + 1];
    }
}

static double tri_area(const fs_surface *r, int32_t t)
{
    double p[3][2];
    tri_uv(r, t, p);
    return 0.5 * ((p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]));
}

typedef struct {
    double abs_area, min_area, negative_area, crack_area;
} areas;

static areas measure(const fs_surface *r)
{
    areas a = {0.0, INFINITY, 0.0, 0.0};
    for (int32_t t = 0; t < r->n_tris; t++) {
        double s = tri_area(r, t);
        a.abs_area += fabs(s);
        a.min_area = fmin(a.min_area, s);
        a.negative_area += s < 0.0 ? -s : 0.0;
        const int32_t *v = r->tri + 3 * t;
        if (r->crack[v[0]] == 1.0f && r->crack[v[1]] == 1.0f && r->crack[v[2]] == 1.0f)
            a.crack_area += fabs(s);
    }
    return a;
}

/* Vertices whose attributes break the render contract: cell 0 exactly on cracks, integer ids,
 * shade in [-1, 1], heights between the crack floor and the tops. */
static int32_t bad_attributes(const fs_surface *r, double depth)
{
    int32_t bad = 0;
    for (int32_t v = 0; v < r->n_verts; v++) {
        float cell = r->cell[v];
        bool crack = r->crack[v] == 1.0f;
        bool ok = (cell == 0.0f) == crack && (crack || r->crack[v] == 0.0f) && cell == floorf(cell) &&
                  cell >= 0.0f && cell <= 65535.0f && fabsf(r->shade[v]) <= 1.0f &&
                  r->height[v] >= 0.0f && r->height[v] <= (float)depth * 1.000001f;
        bad += !ok;
    }
    return bad;
}

/* Difference of a and b reduced by whole periods on wrapping axes (|a - b| < 2.5). */
static double wrapped_diff(double a, double b, bool wraps)
{
    double d = a - b;
    if (wraps)
        while (d > 0.5 || d < -0.5)
            d += d > 0.5 ? -1.0 : 1.0;
    return d;
}

typedef struct {
    double p[2], q[2], mid[2];
} dedge;

/* design: directed triangle edges bucketed by their midpoint (wrapped into the unit square on
 * wrapping axes); an edge is matched when an edge of the opposite direction has the same end points
 * up to float rounding and one common whole-period shift. Counts unmatched edges (those on the
 * border of a non-periodic map are reported apart) and matches that cross a seam. With all
 * triangles counter-clockwise, a closed edge set and a total area of 1, the triangles cover the
 * unit square exactly once. */
typedef struct {
    int32_t unmatched, unmatched_border, across_seam, total;
} edge_report;

static edge_report match_edges(const fs_surface *r, bool wu, bool wv)
{
    int G = (int)sqrt(2.0 * r->n_tris);
    G = G < 16 ? 16 : (G > 2048 ? 2048 : G);
    const double tol = 2e-6;
    int32_t ne = 3 * r->n_tris;
    dedge *e = fs_malloc((size_t)ne * sizeof *e);
    int32_t *bucket_of = fs_malloc((size_t)ne * sizeof *bucket_of);
    int32_t *start = fs_calloc((size_t)G * G + 1, sizeof *start), n = 0;
    for (int32_t t = 0; t < r->n_tris; t++) {
        double p[3][2];
        tri_uv(r, t, p);
        for (int k = 0; k < 3; k++) {
            dedge x = {{p[k][0], p[k][1]}, {p[(k + 1) % 3][0], p[(k + 1) % 3][1]}, {0.0, 0.0}};
            if (hypot(x.q[0] - x.p[0], x.q[1] - x.p[1]) < 1e-9)
                continue;
            double mu = 0.5 * (x.p[0] + x.q[0]), mv = 0.5 * (x.p[1] + x.q[1]);
            if (wu)
                mu -= floor(mu);
            if (wv)
                mv -= floor(mv);
            x.mid[0] = mu;
            x.mid[1] = mv;
            int bu = (int)floor(mu * G), bv = (int)floor(mv * G);
            bu = bu < 0 ? 0 : (bu >= G ? G - 1 : bu);
            bv = bv < 0 ? 0 : (bv >= G ? G - 1 : bv);
            e[n] = x;
            bucket_of[n++] = bv * G + bu;
            start[bv * G + bu + 1]++;
        }
    }
    for (int b = 0; b < G * G; b++)
        start[b + 1] += start[b];
    int32_t *fill = fs_malloc((size_t)G * G * sizeof *fill), *order = fs_malloc((size_t)(n ? n : 1) * sizeof *order);
    memcpy(fill, start, (size_t)G * G * sizeof *fill);
    for (int32_t i = 0; i < n; i++)
        order[fill[bucket_of[i]]++] = i;

    edge_report rep = {0, 0, 0, n};
    for (int32_t i = 0; i < n; i++) {
        int bu = bucket_of[i] % G, bv = bucket_of[i] / G;
        int twins = 0, seam = 0;
        for (int dv = -1; dv <= 1; dv++)
            for (int du = -1; du <= 1; du++) {
                int cu = bu + du, cv = bv + dv;
                if (wu)
                    cu = (cu + G) % G;
                if (wv)
                    cv = (cv + G) % G;
                if (cu < 0 || cu >= G || cv < 0 || cv >= G)
                    continue;
                int b = cv * G + cu;
                for (int32_t s = start[b]; s < start[b + 1]; s++) {
                    int32_t j = order[s];
                    if (j == i)
                        continue;
                    const dedge *x = e + i, *y = e + j;
                    if (fabs(wrapped_diff(x->mid[0], y->mid[0], wu)) > tol ||
                        fabs(wrapped_diff(x->mid[1], y->mid[1], wv)) > tol)
                        continue;
                    double a0 = wrapped_diff(y->p[0], x->q[0], wu), a1 = wrapped_diff(y->p[1], x->q[1], wv);
                    double b0 = wrapped_diff(y->q[0], x->p[0], wu), b1 = wrapped_diff(y->q[1], x->p[1], wv);
                    if (fabs(a0) < tol && fabs(a1) < tol && fabs(b0) < tol && fabs(b1) < tol &&
                        fabs((y->p[0] - x->q[0]) - (y->q[0] - x->p[0])) < tol &&
                        fabs((y->p[1] - x->q[1]) - (y->q[1] - x->p[1])) < tol) {
                        twins++;
                        seam += fabs(y->p[0] - x->q[0]) > 0.5 || fabs(y->p[1] - x->q[1]) > 0.5;
                    }
                }
            }
        const dedge *x = e + i;
        bool border = (!wu && ((x->p[0] == 0.0 && x->q[0] == 0.0) || (x->p[0] == 1.0 && x->q[0] == 1.0))) ||
                      (!wv && ((x->p[1] == 0.0 && x->q[1] == 0.0) || (x->p[1] == 1.0 && x->q[1] == 1.0)));
        if (twins == 0) {
            if (border)
                rep.unmatched_border++;
            else
                rep.unmatched++;
        }
        rep.across_seam += seam > 0;
    }
    free(e);
    free(bucket_of);
    free(start);
    free(fill);
    free(order);
    return rep;
}

/* Counts, at the given points of the unit square (n pairs u, v), the emitted triangles (and their
 * copies shifted by a period on wrapping axes) that contain the point: `gaps` points are in none,
 * `overlaps` strictly inside two or more. A point within a hair of an edge counts as in both
 * neighbours. */
static void coverage_at(const fs_surface *r, bool wu, bool wv, const double *pts, int n, int *gaps,
                        int *overlaps)
{
    const int G = 64;
    int32_t *count = fs_calloc((size_t)G * G + 1, sizeof *count);
    int32_t *list = NULL;
    for (int pass = 0; pass < 2; pass++) {
        int32_t *fill = pass ? fs_malloc((size_t)G * G * sizeof *fill) : NULL;
        if (pass)
            memcpy(fill, count, (size_t)G * G * sizeof *fill);
        for (int32_t t = 0; t < r->n_tris; t++) {
            double p[3][2];
            tri_uv(r, t, p);
            double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
            for (int k = 0; k < 3; k++)
                for (int a = 0; a < 2; a++) {
                    lo[a] = fmin(lo[a], p[k][a]);
                    hi[a] = fmax(hi[a], p[k][a]);
                }
            for (int su = wu ? -1 : 0; su <= (wu ? 1 : 0); su++)
                for (int sv = wv ? -1 : 0; sv <= (wv ? 1 : 0); sv++) {
                    int u0 = (int)floor((lo[0] + su) * G), u1 = (int)floor((hi[0] + su) * G);
                    int v0 = (int)floor((lo[1] + sv) * G), v1 = (int)floor((hi[1] + sv) * G);
                    for (int bv = v0 < 0 ? 0 : v0; bv <= v1 && bv < G; bv++)
                        for (int bu = u0 < 0 ? 0 : u0; bu <= u1 && bu < G; bu++) {
                            int b = bv * G + bu;
                            if (pass)
                                list[2 * fill[b]] = t, list[2 * fill[b]++ + 1] = su * 3 + sv;
                            else
                                count[b + 1]++;
                        }
                }
        }
        if (!pass) {
            for (int b = 0; b < G * G; b++)
                count[b + 1] += count[b];
            list = fs_malloc(2 * (size_t)(count[G * G] ? count[G * G] : 1) * sizeof *list);
        }
        free(fill);
    }
    *gaps = *overlaps = 0;
    for (int s = 0; s < n; s++) {
        double x = pts[2 * s], y = pts[2 * s + 1];
        int b = (int)(y * G) * G + (int)(x * G), strict = 0, loose = 0;
        for (int32_t k = count[b]; k < count[b + 1]; k++) {
            int32_t t = list[2 * k];
            int sh = list[2 * k + 1], su = (sh + 4) / 3 - 1, sv = sh - 3 * su;
            double p[3][2];
            tri_uv(r, t, p);
            double q[2] = {x - su, y - sv};
            double area = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
            if (area <= 0.0)
                continue;
            double w[3];
            for (int c = 0; c < 3; c++) {
                const double *a = p[(c + 1) % 3], *bb = p[(c + 2) % 3];
                w[c] = ((bb[0] - a[0]) * (q[1] - a[1]) - (bb[1] - a[1]) * (q[0] - a[0])) / area;
            }
            double mn = fmin(w[0], fmin(w[1], w[2]));
            strict += mn > 1e-4;
            loose += mn > -1e-4;
        }
        *gaps += loose == 0;
        *overlaps += strict > 1;
    }
    free(count);
    free(list);
}

/* coverage_at at random points. */
static void coverage(const fs_surface *r, bool wu, bool wv, int samples, int *gaps, int *overlaps)
{
    double *pts = fs_malloc(2 * (size_t)samples * sizeof *pts);
    for (int s = 0; s < 2 * samples; s++)
        pts[s] = fs_rand01(99, FS_RNG_TEST, (uint64_t)s);
    coverage_at(r, wu, wv, pts, samples, gaps, overlaps);
    free(pts);
}

/* Sum of the lengths of the Voronoi edges of m (cm). */
static double voronoi_edge_length(const fs_mesh *m)
{
    fs_voronoi v;
    FS_ASSERT(fs_voronoi_build(m, &v) == 0);
    double s = 0.0;
    for (int32_t e = 0; e < m->n_edges; e++)
        s += v.edge_length[e];
    fs_voronoi_free(&v);
    return s;
}

/* Top and bevel vertices of cell c (warp 0) are closer to node c - 1 than to any other node
 * (every third vertex is checked, which keeps the brute-force search short). */
static int32_t wrong_cell_vertices(const fs_mesh *m, const fs_surface *r)
{
    int32_t wrong = 0;
    for (int32_t v = 0; v < r->n_verts; v += 3) {
        if (r->cell[v] == 0.0f)
            continue;
        double uv[2] = {r->uv[2 * v], r->uv[2 * v + 1]}, p[3];
        fs_domain_from_uv(&m->domain, uv, p);
        int32_t best = -1;
        double bd = INFINITY;
        for (int32_t n = 0; n < m->n_nodes; n++) {
            double d[3];
            fs_domain_delta(&m->domain, m->pos + 3 * n, p, d);
            double l = fs_norm3(d);
            if (l < bd)
                bd = l, best = n;
        }
        wrong += best + 1 != (int32_t)r->cell[v];
    }
    return wrong;
}

/* ---- tests ---- */

static void test_defaults(void)
{
    fs_voronoi_params p = fs_voronoi_params_default();
    CHECK_NEAR(p.crack_width, 0.06, 1e-15);
    CHECK_NEAR(p.bevel, 0.05, 1e-15);
    CHECK_NEAR(p.depth, 0.3, 1e-15);
    CHECK_NEAR(p.warp, 0.08, 1e-15);
    CHECK_NEAR(p.warp_scale, 1.0, 1e-15);
    CHECK(p.subdivisions == 8);
}

static void test_bad_input(void)
{
    fs_voronoi_params p = fs_voronoi_params_default();
    fs_surface r;
    memset(&r, 0, sizeof r);
    fs_mesh empty;
    memset(&empty, 0, sizeof empty);
    empty.domain = fs_domain_default();
    fs_error_clear();
    CHECK(fs_voronoi_surface(&empty, &p, 1, &r) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(strstr(fs_error_message(), "voronoi") != NULL);

    fs_domain d = fs_domain_default();
    d.periodic_x = d.periodic_y = true;
    fs_mesh m;
    grid_mesh(&m, d, 6, 6, 0.2, 1);
    free(m.ring_start);
    m.ring_start = NULL;
    fs_error_clear();
    CHECK(fs_voronoi_surface(&m, &p, 1, &r) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(r.n_verts == 0 && r.n_tris == 0);
    fs_mesh_free(&m);
}

/* On a periodic plane the emitted triangles tile the unit square exactly once, with and without
 * warping: all are counter-clockwise, their areas sum to 1, every edge has a twin (seams
 * included), and random points are covered once. */
static void check_periodic_tiling(double warp)
{
    fs_domain d = fs_domain_default();
    d.width = 10.0;
    d.height = 8.0;
    d.periodic_x = d.periodic_y = true;
    fs_mesh m;
    grid_mesh(&m, d, 10, 8, 0.3, 5);
    fs_voronoi_params p = fs_voronoi_params_default();
    p.warp = warp;
    p.subdivisions = 5;
    fs_surface r;
    memset(&r, 0, sizeof r);
    CHECK(fs_voronoi_surface(&m, &p, 42, &r) == 0);
    areas a = measure(&r);
    CHECK_NEAR(a.abs_area, 1.0, 1e-6);
    CHECK_MSG(a.min_area > -1e-10, "warp %g: a triangle is clockwise (area %g)", warp, a.min_area);
    CHECK_MSG(bad_attributes(&r, p.depth) == 0, "warp %g: %d vertices break the attribute contract", warp,
              bad_attributes(&r, p.depth));
    edge_report e = match_edges(&r, true, true);
    CHECK_MSG(e.unmatched == 0 && e.unmatched_border == 0, "warp %g: %d of %d edges have no twin", warp,
              e.unmatched + e.unmatched_border, e.total);
    CHECK_MSG(e.across_seam > 50, "warp %g: only %d edges meet their twin across a seam", warp, e.across_seam);
    int gaps, overlaps;
    coverage(&r, true, true, 4000, &gaps, &overlaps);
    CHECK_MSG(gaps == 0 && overlaps == 0, "warp %g: %d gaps, %d overlaps at 4000 points", warp, gaps, overlaps);

    /* crack area: both halves of the strip along each Voronoi edge, less a little at the corners */
    double expect = voronoi_edge_length(&m) * p.crack_width / (d.width * d.height);
    double ratio = a.crack_area / expect;
    if (warp == 0.0) {
        CHECK_MSG(ratio > 0.93 && ratio <= 1.0, "crack area / (edge length * width) = %g", ratio);
        CHECK_MSG(wrong_cell_vertices(&m, &r) == 0, "%d cell vertices are nearer another node",
                  wrong_cell_vertices(&m, &r));
    } else {
        /* warping lengthens the cracks a little */
        CHECK_MSG(ratio > 0.93 && ratio < 1.2, "warped crack area / (edge length * width) = %g", ratio);
    }
    fs_surface_free(&r);
    fs_mesh_free(&m);
}

static void test_periodic_plane(void) { check_periodic_tiling(0.0); }

static void test_periodic_plane_warped(void) { check_periodic_tiling(0.15); }

/* Warping moves the crack lines: with warp 0 every crack vertex is within half a crack width of a
 * bisector between two nodes (d2 - d1 <= crack_width); with warp > crack_width many are not. */
static void test_warp_moves_cracks(void)
{
    fs_domain d = fs_domain_default();
    d.periodic_x = d.periodic_y = true;
    fs_mesh m;
    grid_mesh(&m, d, 8, 8, 0.25, 3);
    fs_voronoi_params p = fs_voronoi_params_default();
    p.subdivisions = 4;
    int32_t off[2] = {0, 0}, total[2] = {0, 0};
    for (int run = 0; run < 2; run++) {
        p.warp = run ? 0.2 : 0.0;
        fs_surface r;
        memset(&r, 0, sizeof r);
        CHECK(fs_voronoi_surface(&m, &p, 7, &r) == 0);
        for (int32_t v = 0; v < r.n_verts; v++) {
            if (r.crack[v] != 1.0f)
                continue;
            double uv[2] = {r.uv[2 * v], r.uv[2 * v + 1]}, q[3];
            fs_domain_from_uv(&m.domain, uv, q);
            double d1 = INFINITY, d2 = INFINITY;
            for (int32_t n = 0; n < m.n_nodes; n++) {
                double dd[3];
                fs_domain_delta(&m.domain, m.pos + 3 * n, q, dd);
                double l = fs_norm3(dd);
                if (l < d1)
                    d2 = d1, d1 = l;
                else if (l < d2)
                    d2 = l;
            }
            off[run] += d2 - d1 > p.crack_width + 1e-5;
            total[run]++;
        }
        fs_surface_free(&r);
    }
    CHECK_MSG(off[0] == 0, "warp 0: %d of %d crack vertices lie off the Voronoi edges", off[0], total[0]);
    CHECK_MSG(off[1] > total[1] / 4, "warp 0.2: only %d of %d crack vertices moved off", off[1], total[1]);
    fs_mesh_free(&m);
}

/* Periodic in x only: the cells are clipped at y = 0 and y = height, the render mesh still tiles
 * the unit square, and its only open edges lie on the non-wrapping border. */
static void test_periodic_x_strip(void)
{
    for (int warped = 0; warped < 2; warped++) {
        fs_domain d = fs_domain_default();
        d.width = 9.0;
        d.height = 6.0;
        d.periodic_x = true;
        fs_mesh m;
        grid_mesh(&m, d, 9, 7, 0.3, 11);
        fs_voronoi_params p = fs_voronoi_params_default();
        p.warp = warped ? 0.15 : 0.0;
        fs_surface r;
        memset(&r, 0, sizeof r);
        CHECK(fs_voronoi_surface(&m, &p, 3, &r) == 0);
        areas a = measure(&r);
        CHECK_NEAR(a.abs_area, 1.0, 1e-6);
        CHECK(a.min_area > -1e-10);
        edge_report e = match_edges(&r, true, false);
        CHECK_MSG(e.unmatched == 0, "warp %g: %d of %d edges have no twin", p.warp, e.unmatched, e.total);
        CHECK(e.unmatched_border > 0);
        int32_t outside = 0;
        for (int32_t v = 0; v < r.n_verts; v++)
            outside += r.uv[2 * v + 1] < 0.0f || r.uv[2 * v + 1] > 1.0f;
        CHECK_MSG(outside == 0, "%d vertices outside the non-wrapping range", outside);
        int gaps, overlaps;
        coverage(&r, true, false, 3000, &gaps, &overlaps);
        CHECK_MSG(gaps == 0 && overlaps == 0, "%d gaps, %d overlaps", gaps, overlaps);
        fs_surface_free(&r);
        fs_mesh_free(&m);
    }
}

/* Cell ids are node + 1 and shades are the per-node hashes; runs are deterministic in the seed. */
static void test_ids_and_determinism(void)
{
    fs_domain d = fs_domain_default();
    d.periodic_x = d.periodic_y = true;
    fs_mesh m;
    grid_mesh(&m, d, 7, 7, 0.2, 9);
    fs_voronoi_params p = fs_voronoi_params_default();
    fs_surface r1, r2, r3;
    memset(&r1, 0, sizeof r1);
    memset(&r2, 0, sizeof r2);
    memset(&r3, 0, sizeof r3);
    CHECK(fs_voronoi_surface(&m, &p, 5, &r1) == 0);
    CHECK(fs_voronoi_surface(&m, &p, 5, &r2) == 0);
    CHECK(fs_voronoi_surface(&m, &p, 6, &r3) == 0);
    CHECK(r1.n_verts == r2.n_verts && r1.n_tris == r2.n_tris);
    CHECK(memcmp(r1.uv, r2.uv, 2 * (size_t)r1.n_verts * sizeof *r1.uv) == 0);
    CHECK(memcmp(r1.tri, r2.tri, 3 * (size_t)r1.n_tris * sizeof *r1.tri) == 0);
    CHECK(memcmp(r1.shade, r2.shade, (size_t)r1.n_verts * sizeof *r1.shade) == 0);
    bool differs = r1.n_verts != r3.n_verts ||
                   memcmp(r1.uv, r3.uv, 2 * (size_t)r1.n_verts * sizeof *r1.uv) != 0;
    CHECK_MSG(differs, "another seed gives the same warped geometry");
    int32_t seen[49] = {0}, bad_shade = 0;
    for (int32_t v = 0; v < r1.n_verts; v++) {
        int id = (int)r1.cell[v];
        if (id == 0)
            continue;
        if (id >= 1 && id <= 49)
            seen[id - 1]++;
        double shade = 2.0 * fs_rand01(5, FS_RNG_CELL_COLOR, (uint64_t)(id - 1)) - 1.0;
        bad_shade += fabs(r1.shade[v] - shade) > 1e-6;
    }
    int32_t missing = 0;
    for (int k = 0; k < 49; k++)
        missing += seen[k] == 0;
    CHECK_MSG(missing == 0, "%d cells have no vertices", missing);
    CHECK_MSG(bad_shade == 0, "%d vertices with a shade that is not their cell's", bad_shade);
    fs_surface_free(&r1);
    fs_surface_free(&r2);
    fs_surface_free(&r3);
    fs_mesh_free(&m);
}

/* The sphere: the map is covered once (areas sum to 1 up to the chordal approximation, every edge
 * has a twin, random points are covered once), the pole rows are covered, cells sit around their
 * nodes. */
static void test_sphere(void)
{
    fs_mesh m;
    geodesic_mesh(&m, 5.0, 4);
    /* the mesh is a convex hull, hence Delaunay on the sphere */
    int32_t not_hull = 0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        double a[3], b[3], c[3], ab[3], ac[3], n[3];
        fs_mesh_corner(&m, t, 0, a);
        fs_mesh_corner(&m, t, 1, b);
        fs_mesh_corner(&m, t, 2, c);
        fs_sub3(ab, b, a);
        fs_sub3(ac, c, a);
        fs_cross3(n, ab, ac);
        for (int32_t v = 0; v < m.n_nodes; v++) {
            double d[3];
            fs_sub3(d, m.pos + 3 * v, a);
            not_hull += fs_dot3(n, d) > 1e-9;
        }
    }
    CHECK(not_hull == 0);
    for (int warped = 0; warped < 2; warped++) {
        fs_voronoi_params p = fs_voronoi_params_default();
        p.warp = warped ? 0.1 : 0.0;
        p.warp_scale = 1.5;
        fs_surface r;
        memset(&r, 0, sizeof r);
        CHECK(fs_voronoi_surface(&m, &p, 8, &r) == 0);
        areas a = measure(&r);
        CHECK_MSG(fabs(a.abs_area - 1.0) < 1e-4, "warp %g: uv area %.6f", p.warp, a.abs_area);
        /* slivers next to the poles may flip in the degenerate map; together they cover less than
         * 2e-5 of it (20 pixels of a 1024 x 1024 map) */
        CHECK_MSG(a.negative_area < 2e-5, "warp %g: clockwise triangles of total area %g", p.warp, a.negative_area);
        edge_report e = match_edges(&r, true, false);
        CHECK_MSG(e.unmatched == 0, "warp %g: %d of %d edges have no twin", p.warp, e.unmatched, e.total);
        CHECK(bad_attributes(&r, p.depth) == 0);
        float umin = INFINITY, umax = -INFINITY;
        for (int32_t v = 0; v < r.n_verts; v++) {
            umin = fminf(umin, r.uv[2 * v]);
            umax = fmaxf(umax, r.uv[2 * v]);
        }
        CHECK_MSG(umin > -1.0f && umax < 2.0f, "u range [%g, %g]", umin, umax);
        int gaps, overlaps;
        coverage(&r, true, false, 3000, &gaps, &overlaps);
        CHECK_MSG(gaps == 0 && overlaps == 0, "warp %g: %d gaps, %d overlaps at 3000 points", p.warp, gaps, overlaps);
        /* rows next to the poles: points along u at v = 0.0005 and 0.9995 */
        double row[800];
        for (int k = 0; k < 400; k++) {
            row[2 * k] = (k % 200 + 0.5) / 200.0;
            row[2 * k + 1] = k < 200 ? 0.0005 : 0.9995;
        }
        int pole_gaps, pole_overlaps;
        coverage_at(&r, true, false, row, 400, &pole_gaps, &pole_overlaps);
        CHECK_MSG(pole_gaps == 0 && pole_overlaps == 0, "warp %g: next to the poles %d gaps, %d overlaps",
                  p.warp, pole_gaps, pole_overlaps);
        if (!warped)
            CHECK_MSG(wrong_cell_vertices(&m, &r) == 0, "%d sphere cell vertices nearer another node",
                      wrong_cell_vertices(&m, &r));
        fs_surface_free(&r);
    }
    fs_mesh_free(&m);
}

/* Real meshes: repulsion-sampled points triangulated by fs_delaunay on every kind of domain. The
 * cells tile the texture (exactly on the plane and cylinder), edges close up (across the seams on
 * wrapping axes; open only on a non-wrapping border), and the cracks cover about their expected
 * area on flat domains. */
static void check_delaunay(fs_domain d, int32_t count, double warp)
{
    fs_domain_normalize(&d);
    fs_sample_params sp = fs_sample_params_default();
    sp.count = count;
    sp.seed = 21;
    fs_points pts;
    fs_mesh m;
    CHECK(fs_sample_repulsion(&d, &sp, &pts) == 0);
    CHECK(fs_delaunay(&d, &pts, &m) == 0);
    fs_voronoi_params p = fs_voronoi_params_default();
    p.warp = warp;
    fs_surface r;
    memset(&r, 0, sizeof r);
    CHECK(fs_voronoi_surface(&m, &p, 4, &r) == 0);
    const char *name = fs_domain_type_name(d.type);
    bool wu = fs_domain_wraps_u(&d), wv = fs_domain_wraps_v(&d);
    bool sphere = d.type == FS_DOMAIN_SPHERE;
    areas a = measure(&r);
    CHECK_MSG(fabs(a.abs_area - 1.0) < (sphere ? 1e-4 : 1e-6), "%s (warp %g): uv area %.9f", name, warp, a.abs_area);
    CHECK_MSG(a.negative_area < (sphere ? 2e-5 : 1e-9), "%s (warp %g): clockwise area %g", name, warp,
              a.negative_area);
    CHECK_MSG(bad_attributes(&r, p.depth) == 0, "%s: %d vertices break the attribute contract", name,
              bad_attributes(&r, p.depth));
    edge_report e = match_edges(&r, wu, wv);
    CHECK_MSG(e.unmatched == 0, "%s (warp %g): %d of %d edges have no twin", name, warp, e.unmatched, e.total);
    CHECK_MSG((e.unmatched_border > 0) == (!wv || !wu), "%s: %d open border edges", name, e.unmatched_border);
    if (wu || wv)
        CHECK_MSG(e.across_seam > 0, "%s: no edge meets its twin across a seam", name);
    int gaps, overlaps;
    coverage(&r, wu, wv, 3000, &gaps, &overlaps);
    CHECK_MSG(gaps == 0 && overlaps == 0, "%s (warp %g): %d gaps, %d overlaps", name, warp, gaps, overlaps);
    if (!sphere) {
        double expect = voronoi_edge_length(&m) * p.crack_width / fs_domain_area(&d);
        double ratio = a.crack_area / expect;
        CHECK_MSG(ratio > 0.9 && ratio < (warp > 0.0 ? 1.2 : 1.0), "%s (warp %g): crack area ratio %g", name, warp,
                  ratio);
    }
    if (warp == 0.0)
        CHECK_MSG(wrong_cell_vertices(&m, &r) == 0, "%s: %d cell vertices nearer another node", name,
                  wrong_cell_vertices(&m, &r));
    fs_surface_free(&r);
    fs_mesh_free(&m);
    fs_points_free(&pts);
}

static void test_delaunay_meshes(void)
{
    fs_domain plane = fs_domain_default();
    check_delaunay(plane, 200, 0.0);
    check_delaunay(plane, 200, 0.08);
    fs_domain tile = fs_domain_default();
    tile.width = 12.0;
    tile.height = 8.0;
    tile.periodic_x = tile.periodic_y = true;
    check_delaunay(tile, 200, 0.0);
    check_delaunay(tile, 200, 0.08);
    fs_domain trunk = fs_domain_default();
    trunk.type = FS_DOMAIN_CYLINDER;
    trunk.radius = 2.0;
    trunk.height = 12.0;
    check_delaunay(trunk, 150, 0.08);
    fs_domain ball = fs_domain_default();
    ball.type = FS_DOMAIN_SPHERE;
    ball.radius = 4.0;
    check_delaunay(ball, 200, 0.0);
    check_delaunay(ball, 200, 0.08);
}

int main(void)
{
    RUN(test_defaults);
    RUN(test_bad_input);
    RUN(test_periodic_plane);
    RUN(test_periodic_plane_warped);
    RUN(test_warp_moves_cracks);
    RUN(test_periodic_x_strip);
    RUN(test_ids_and_determinism);
    RUN(test_sphere);
    RUN(test_delaunay_meshes);
    return check_finish();
}
