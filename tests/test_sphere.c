/* Tests of the conforming refinement of sphere triangles into the equirectangular texture (geom/sphere_surface.h). */
#include "geom/sphere_surface.h"
#include "render/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/vec.h"
#include "check.h"

#define RADIUS 5.0

/* What the vertex callback saw: every vertex's weights, for the checks. */
typedef struct {
    fs_surface *out;
    double height;
    int32_t n, cap;
    double *w; /* 3 per vertex */
} recorder;

static int32_t record_vertex(void *user, double u, double v, const double w[3])
{
    recorder *r = user;
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 256;
        r->w = realloc(r->w, 3 * (size_t)r->cap * sizeof *r->w);
    }
    memcpy(r->w + 3 * (size_t)r->n++, w, 3 * sizeof *w);
    return fs_surface_add_vertex(r->out, u, v, r->height, 0.0, 1.0, 0.0);
}

static fs_domain sphere_domain(void)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_SPHERE;
    d.radius = RADIUS;
    return d;
}

/* An octahedron turned so that neither pole is a corner or on an edge. */
static void turned(const double *p, double *out)
{
    const double a = 0.4, b = 0.7; /* about z, then about x */
    double q[3] = {cos(a) * p[0] - sin(a) * p[1], sin(a) * p[0] + cos(a) * p[1], p[2]};
    out[0] = q[0];
    out[1] = cos(b) * q[1] - sin(b) * q[2];
    out[2] = sin(b) * q[1] + cos(b) * q[2];
}

/* Cuts triangle (a, b, c) on the sphere into four, levels times, with the edge midpoints pushed
 * out onto the sphere, and draws the pieces. */
static void draw_cut(const fs_sphere_refiner *s, const double *a, const double *b, const double *c, int levels)
{
    if (levels == 0) {
        fs_sphere_triangle(s, a, b, c);
        return;
    }
    const double *v[3] = {a, b, c};
    double m[3][3];
    for (int k = 0; k < 3; k++) {
        for (int q = 0; q < 3; q++)
            m[k][q] = 0.5 * (v[k][q] + v[(k + 1) % 3][q]);
        double r = fs_norm3(m[k]);
        for (int q = 0; q < 3; q++)
            m[k][q] *= RADIUS / r;
    }
    draw_cut(s, a, m[0], m[2], levels - 1);
    draw_cut(s, m[0], b, m[1], levels - 1);
    draw_cut(s, m[2], m[1], c, levels - 1);
    draw_cut(s, m[0], m[1], m[2], levels - 1);
}

/* Draws the turned octahedron, each face cut into 64 (edges of 0.6 to 1 radius / 8, as long as a
 * model's triangles), counter-clockwise seen from outside. */
static void draw_octahedron(const fs_sphere_refiner *s)
{
    static const double corner[6][3] = {{1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (int f = 0; f < 8; f++) {
        int i = f % 4, j = (f + 1) % 4, top = f < 4 ? 4 : 5;
        const double *c[3] = {corner[i], corner[j], corner[top]};
        if (top == 5) { /* below the equator the order turns round to stay counter-clockwise */
            c[0] = corner[j];
            c[1] = corner[i];
        }
        double p[3][3];
        for (int k = 0; k < 3; k++) {
            for (int q = 0; q < 3; q++)
                p[k][q] = c[k][q] * RADIUS;
            turned(p[k], p[k]);
        }
        draw_cut(s, p[0], p[1], p[2], 3);
    }
}

/* The refined octahedron lifts into a closed sphere: every edge has two triangles running opposite
 * ways (no T-junctions, also across the seam and around both poles, which lie inside faces),
 * Euler characteristic 2; its image covers the texture square once (area 1); and the weights handed
 * to the caller are convex combinations. */
static void octahedron_closes(void)
{
    fs_domain d = sphere_domain();
    fs_surface m = {0};
    recorder rec = {&m, 0.1, 0, 0, NULL};
    fs_sphere_refiner s = {&d, 5e-4, &m, record_vertex, &rec};
    draw_octahedron(&s);
    CHECK(m.n_tris > 8 * 64);

    double area = 0.0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        const float *a = m.uv + 2 * m.tri[3 * t], *b = m.uv + 2 * m.tri[3 * t + 1], *c = m.uv + 2 * m.tri[3 * t + 2];
        area += 0.5 * (((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]));
    }
    CHECK_NEAR(area, 1.0, 2e-3);
    int bad_weights = 0;
    for (int32_t i = 0; i < rec.n; i++) {
        const double *w = rec.w + 3 * i;
        bad_weights += !(fabs(w[0] + w[1] + w[2] - 1.0) < 1e-12 && w[0] > -1e-12 && w[1] > -1e-12 && w[2] > -1e-12);
    }
    CHECK(bad_weights == 0);

    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    int32_t *edges, bad = -1;
    int32_t n_boundary = fs_lifted_mesh_boundary(&l, &edges, &bad);
    free(edges);
    CHECK_MSG(n_boundary == 0 && bad == 0, "%d boundary edges, %d bad", (int)n_boundary, (int)bad);
    long e = (3L * l.n_tris + n_boundary) / 2;
    CHECK(l.n_pos - e + l.n_tris == 2);
    double off = 0.0; /* heights are floats in the render mesh */
    for (int32_t i = 0; i < l.n_pos; i++)
        off = fmax(off, fabs(fs_norm3(l.pos + 3 * (size_t)i) - (RADIUS + 0.1)));
    CHECK(off < 1e-6);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
    free(rec.w);
}

/* The distinct texture points of the vertices a drawing put on the chord between two corners (the
 * other corner's weight exactly 0), sorted by (v, u), u reduced into [0, 1). Returns the count. */
static int chord_points(const recorder *r, const fs_surface *m, int other, double *uv, int cap)
{
    int n = 0;
    for (int32_t i = 0; i < r->n && n < cap; i++)
        if (r->w[3 * i + other] == 0.0) {
            uv[2 * n] = m->uv[2 * i] - floor(m->uv[2 * i]);
            uv[2 * n + 1] = m->uv[2 * i + 1];
            n++;
        }
    for (int a = 1; a < n; a++) /* insertion sort */
        for (int b = a; b > 0 && (uv[2 * b + 1] < uv[2 * b - 1] || (uv[2 * b + 1] == uv[2 * b - 1] && uv[2 * b] < uv[2 * b - 2])); b--)
            for (int q = 0; q < 2; q++) {
                double t = uv[2 * b + q];
                uv[2 * b + q] = uv[2 * b - 2 + q];
                uv[2 * b - 2 + q] = t;
            }
    int k = 0;
    for (int a = 0; a < n; a++)
        if (k == 0 || fabs(uv[2 * a] - uv[2 * k - 2]) > 1e-6 || uv[2 * a + 1] != uv[2 * k - 1]) {
            uv[2 * k] = uv[2 * a];
            uv[2 * k + 1] = uv[2 * a + 1];
            k++;
        }
    return k;
}

/* A long chord ab at 55 degrees north, bent by the map, between the triangles (a, c, b) below it
 * and (b, d, a) above it, given in opposite directions: both cut it at the same points (v bit for
 * bit, since the points are; u to float precision, since a pole triangle's columns unwrap each u
 * from the one before). Above the chord, d lies either near the pole or so that (b, d, a) holds the
 * pole and its chords are drawn as columns down to the pole's row. */
static void neighbours_agree(void)
{
    fs_domain d = sphere_domain();
    const double d_uv[2][2] = {{0.22, 0.95}, {0.70, 0.85}};
    for (int around_pole = 0; around_pole < 2; around_pole++) {
        double uv[4][2] = {{0.10, 0.80}, {0.35, 0.82}, {0.20, 0.60}, {d_uv[around_pole][0], d_uv[around_pole][1]}};
        double p[4][3]; /* a, b, c, d */
        for (int k = 0; k < 4; k++)
            fs_domain_from_uv(&d, uv[k], p[k]);
        fs_surface m1 = {0}, m2 = {0};
        recorder r1 = {&m1, 0.0, 0, 0, NULL}, r2 = {&m2, 0.0, 0, 0, NULL};
        fs_sphere_refiner s1 = {&d, 5e-4, &m1, record_vertex, &r1}, s2 = {&d, 5e-4, &m2, record_vertex, &r2};
        fs_sphere_triangle(&s1, p[0], p[2], p[1]);
        fs_sphere_triangle(&s2, p[1], p[3], p[0]);
        static double c1[2 * 4096], c2[2 * 4096];
        int n1 = chord_points(&r1, &m1, 1, c1, 4096), n2 = chord_points(&r2, &m2, 1, c2, 4096);
        CHECK_MSG(n1 > 4, "around the pole %d: %d points on the chord", around_pole, n1);
        CHECK_MSG(n1 == n2, "around the pole %d: %d and %d points on the chord", around_pole, n1, n2);
        int same = n1 == n2;
        for (int k = 0; k < n1 && same; k++)
            same = c1[2 * k + 1] == c2[2 * k + 1] && fabs(c1[2 * k] - c2[2 * k]) < 1e-6;
        CHECK_MSG(same, "around the pole %d: the sides cut the chord at different points", around_pole);
        fs_surface_free(&m1);
        fs_surface_free(&m2);
        free(r1.w);
        free(r2.w);
    }
}

int main(void)
{
    RUN(octahedron_closes);
    RUN(neighbours_agree);
    return check_finish();
}
