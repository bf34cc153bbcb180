/* Conforming refinement of triangles on the sphere into the equirectangular texture (geom/sphere_surface.h). */
#include "geom/sphere_surface.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "base/array.h"
#include "base/error.h"
#include "base/vec.h"

/* Shortest chord halved (in radii), and a bound on the depth of a triangle's refinement (reached
 * only by thin pieces within a few tenths of a millimetre of a pole, whose long sides keep bending). */
#define SPHERE_MIN_EDGE 1e-3
#define SPHERE_MAX_DEPTH 24
/* Rows of the meridian segments from a pole triangle's chord to its pole. */
#define SPHERE_POLE_ROWS 4

/* A point of the refinement: in 3-D, with its weights of the input triangle's corners. */
typedef struct {
    double p[3];
    double w[3];
} point;

static bool lex_less(const double *a, const double *b)
{
    for (int k = 0; k < 3; k++)
        if (a[k] != b[k])
            return a[k] < b[k];
    return false;
}

/* u moved by a whole number of periods into [ref - 0.5, ref + 0.5). */
static double unwrap_near(double u, double ref) { return u - floor(u - ref + 0.5); }

/* Texture point of the radial projection of p. */
static void sphere_uv(const fs_domain *d, const double *p, double *uv)
{
    double q[3] = {p[0], p[1], p[2]}, r = fs_norm3(q);
    if (r > 0.0)
        for (int k = 0; k < 3; k++)
            q[k] *= d->radius / r;
    fs_domain_to_uv(d, q, uv);
}

/* The midpoint of the chord ab, computed from its lexicographically smaller end. */
static point midpoint(const point *a, const point *b)
{
    if (lex_less(b->p, a->p)) {
        const point *t = a;
        a = b;
        b = t;
    }
    point m;
    for (int q = 0; q < 3; q++) {
        m.p[q] = 0.5 * (a->p[q] + b->p[q]);
        m.w[q] = 0.5 * (a->w[q] + b->w[q]);
    }
    return m;
}

/* Whether the chord pq is halved: it is long enough and the map to texture space is too far from
 * affine along it. A function of the unordered pair only, so neighbours agree. */
static bool split_edge(const fs_sphere_refiner *s, const double *p, const double *q)
{
    if (lex_less(q, p)) {
        const double *t = p;
        p = q;
        q = t;
    }
    double d[3];
    fs_sub3(d, q, p);
    if (fs_norm3(d) <= SPHERE_MIN_EDGE * s->domain->radius)
        return false;
    double mid[3] = {0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])};
    double up[2], uq[2], um[2];
    sphere_uv(s->domain, p, up);
    sphere_uv(s->domain, q, uq);
    sphere_uv(s->domain, mid, um);
    uq[0] = unwrap_near(uq[0], up[0]);
    um[0] = unwrap_near(um[0], up[0]);
    /* near the poles the map is so anisotropic that thin pieces would flip: be stricter there */
    double near_pole = fmax(fabs(um[1] - 0.5) * 2.0 - 0.85, 0.0) / 0.15;
    double tol = s->uv_tolerance * (1.0 - 0.75 * near_pole);
    return hypot(um[0] - 0.5 * (up[0] + uq[0]), um[1] - 0.5 * (up[1] + uq[1])) > tol;
}

/* One piece, its u values unwrapped around its first corner. */
static void emit_leaf(const fs_sphere_refiner *s, const point *a, const point *b, const point *c)
{
    const point *v[3] = {a, b, c};
    int32_t idx[3];
    double u0 = 0.0;
    for (int k = 0; k < 3; k++) {
        double uv[2];
        sphere_uv(s->domain, v[k]->p, uv);
        if (k == 0)
            u0 = uv[0];
        idx[k] = s->vertex(s->user, unwrap_near(uv[0], u0), uv[1], v[k]->w);
    }
    fs_surface_add_tri(s->out, idx[0], idx[1], idx[2]);
}

/* design: each edge is halved when split_edge says so, and a triangle is cut into 2, 3 or 4
 * according to how many of its edges are halved; the pieces repeat the test. An edge that is to be
 * halved is halved at the depth where it first appears, and it appears at the same depth on both
 * sides: an input edge at depth 0 in both input triangles, an edge drawn across a triangle at
 * depth d in both pieces at d + 1, the halves of an edge halved at d in the pieces on both sides at
 * d + 1. So the depth bound stops both sides of an edge alike, and edge_points, which counts the
 * depth the same way, cuts a chord as the triangle across it does. */
static void refine(const fs_sphere_refiner *s, const point *a, const point *b, const point *d, int depth)
{
    const point *v[3] = {a, b, d};
    bool split[3];
    int n = 0;
    for (int k = 0; k < 3; k++) {
        split[k] = depth < SPHERE_MAX_DEPTH && split_edge(s, v[k]->p, v[(k + 1) % 3]->p);
        n += split[k];
    }
    if (n == 0) {
        emit_leaf(s, a, b, d);
        return;
    }
    point mid[3];
    for (int k = 0; k < 3; k++)
        if (split[k])
            mid[k] = midpoint(v[k], v[(k + 1) % 3]);
    if (n == 3) {
        refine(s, a, &mid[0], &mid[2], depth + 1);
        refine(s, &mid[0], b, &mid[1], depth + 1);
        refine(s, &mid[2], &mid[1], d, depth + 1);
        refine(s, &mid[0], &mid[1], &mid[2], depth + 1);
        return;
    }
    if (n == 1) {
        int k = split[0] ? 0 : (split[1] ? 1 : 2);
        refine(s, v[k], &mid[k], v[(k + 2) % 3], depth + 1);
        refine(s, &mid[k], v[(k + 1) % 3], v[(k + 2) % 3], depth + 1);
        return;
    }
    int k = !split[0] ? 0 : (!split[1] ? 1 : 2), k1 = (k + 1) % 3, k2 = (k + 2) % 3;
    refine(s, &mid[k1], v[k2], &mid[k2], depth + 1);
    refine(s, v[k], v[k1], &mid[k1], depth + 1);
    refine(s, v[k], &mid[k1], &mid[k2], depth + 1);
}

/* The points of chord ab as refine cuts it, from a up to but excluding b, appended to *list. */
static void edge_points(const fs_sphere_refiner *s, const point *a, const point *b, int depth, point **list, int *n,
                        int *cap)
{
    if (depth < SPHERE_MAX_DEPTH && split_edge(s, a->p, b->p)) {
        point m = midpoint(a, b);
        edge_points(s, a, &m, depth + 1, list, n, cap);
        edge_points(s, &m, b, depth + 1, list, n, cap);
        return;
    }
    FS_ARRAY_RESERVE(*list, *cap, *n + 1, 32);
    (*list)[(*n)++] = *a;
}

/* Triangle (X, A, B) with X on the ray to pole k: columns of meridian segments from the points of
 * the chord AB to the pole's row. Seen from outside, counter-clockwise about the north pole means
 * increasing longitude, about the south pole decreasing. */
static void emit_pole(const fs_sphere_refiner *s, int k, const point *x, const point *va, const point *vb)
{
    const int rows = SPHERE_POLE_ROWS;
    double pole_v = (double)k;
    bool north = k == 1;
    point *col = NULL;
    int ncol = 0, cap = 0;
    edge_points(s, va, vb, 0, &col, &ncol, &cap);
    if (ncol == cap) {
        cap++;
        col = fs_realloc(col, (size_t)cap * sizeof *col);
    }
    col[ncol++] = *vb;
    int32_t *idx = fs_malloc((size_t)ncol * (rows + 1) * sizeof *idx);
    double u_prev = 0.0;
    for (int j = 0; j < ncol; j++) {
        double uv[2];
        sphere_uv(s->domain, col[j].p, uv);
        double u = uv[0];
        if (j > 0) {
            double step = north ? u - u_prev : u_prev - u;
            step -= floor(step);
            if (step > 1.0 - 1e-9)
                step = 0.0;
            u = north ? u_prev + step : u_prev - step;
        }
        u_prev = u;
        for (int r = 0; r <= rows; r++) {
            double t = (double)r / rows;
            point p;
            for (int q = 0; q < 3; q++) {
                p.p[q] = col[j].p[q] + (x->p[q] - col[j].p[q]) * t;
                p.w[q] = col[j].w[q] + (x->w[q] - col[j].w[q]) * t;
            }
            if (r == rows)
                uv[1] = pole_v;
            else
                sphere_uv(s->domain, p.p, uv);
            idx[j * (rows + 1) + r] = s->vertex(s->user, u, uv[1], p.w);
        }
    }
    for (int j = 0; j + 1 < ncol; j++)
        for (int r = 0; r < rows; r++) {
            int32_t v00 = idx[j * (rows + 1) + r], v01 = idx[j * (rows + 1) + r + 1];
            int32_t v10 = idx[(j + 1) * (rows + 1) + r], v11 = idx[(j + 1) * (rows + 1) + r + 1];
            fs_surface_add_tri(s->out, v00, v10, v11);
            fs_surface_add_tri(s->out, v00, v11, v01);
        }
    free(idx);
    free(col);
}

void fs_sphere_triangle(const fs_sphere_refiner *s, const double a[3], const double b[3], const double c[3])
{
    FS_ASSERT(s->domain->type == FS_DOMAIN_SPHERE);
    double ab[3], ac[3], n[3];
    fs_sub3(ab, b, a);
    fs_sub3(ac, c, a);
    fs_cross3(n, ab, ac);
    double nn = fs_dot3(n, n);
    if (nn == 0.0)
        return;
    point v[3] = {{{a[0], a[1], a[2]}, {1.0, 0.0, 0.0}},
                  {{b[0], b[1], b[2]}, {0.0, 1.0, 0.0}},
                  {{c[0], c[1], c[2]}, {0.0, 0.0, 1.0}}};
    for (int k = 0; k < 2; k++) {
        double pole[3], uv[2] = {0.0, (double)k};
        fs_domain_from_uv(s->domain, uv, pole);
        double len = fs_norm3(pole);
        for (int q = 0; q < 3; q++)
            pole[q] /= len;
        double sum[3] = {a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]}, e[3];
        if (fs_dot3(pole, sum) <= 0.0)
            continue;
        fs_cross3(e, a, b);
        if (fs_dot3(pole, e) < 0.0)
            continue;
        fs_cross3(e, b, c);
        if (fs_dot3(pole, e) < 0.0)
            continue;
        fs_cross3(e, c, a);
        if (fs_dot3(pole, e) < 0.0)
            continue;
        double np = fs_dot3(n, pole);
        if (np <= 0.0)
            continue;
        /* X: where the ray to the pole meets the triangle's plane, with its barycentric weights */
        point x;
        double t = fs_dot3(n, a) / np, xb[3], xc[3], cr[3];
        for (int q = 0; q < 3; q++)
            x.p[q] = pole[q] * t;
        fs_sub3(xb, b, x.p);
        fs_sub3(xc, c, x.p);
        fs_cross3(cr, xb, xc);
        double la = fs_dot3(n, cr) / nn;
        fs_sub3(xb, c, x.p);
        fs_sub3(xc, a, x.p);
        fs_cross3(cr, xb, xc);
        double lb = fs_dot3(n, cr) / nn;
        x.w[0] = la;
        x.w[1] = lb;
        x.w[2] = 1.0 - la - lb;
        emit_pole(s, k, &x, v + 0, v + 1);
        emit_pole(s, k, &x, v + 1, v + 2);
        emit_pole(s, k, &x, v + 2, v + 0);
        return;
    }
    refine(s, v + 0, v + 1, v + 2, 0);
}
