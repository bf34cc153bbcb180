/* Tests of the tangent frames (geom/tangent): the direction u grows and the handedness on planes
 * and a cylinder, mirrored texture mapping splitting a vertex, and walls with no texture area. */
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

#include "check.h"
#include "geom/tangent.h"

#define PI 3.14159265358979323846

/* A (n+1) x (n+1) grid of vertices on the unit square in the plane z = 0, normal +z, texture
 * coordinates (flip_u ? 1 - x : x, y), two counter-clockwise triangles per cell. */
typedef struct {
    float pos[3 * 16], normal[3 * 16], uv[2 * 16];
    uint32_t tri[3 * 18];
    int32_t n_vert, n_tris;
} grid;

static void grid_make(grid *g, int n, bool flip_u)
{
    g->n_vert = (n + 1) * (n + 1);
    g->n_tris = 2 * n * n;
    for (int j = 0; j <= n; j++)
        for (int i = 0; i <= n; i++) {
            int v = j * (n + 1) + i;
            float x = (float)i / n, y = (float)j / n;
            g->pos[3 * v] = x;
            g->pos[3 * v + 1] = y;
            g->pos[3 * v + 2] = 0.0f;
            g->normal[3 * v] = g->normal[3 * v + 1] = 0.0f;
            g->normal[3 * v + 2] = 1.0f;
            g->uv[2 * v] = flip_u ? 1.0f - x : x;
            g->uv[2 * v + 1] = y;
        }
    int t = 0;
    for (int j = 0; j < n; j++)
        for (int i = 0; i < n; i++) {
            uint32_t a = (uint32_t)(j * (n + 1) + i), b = a + 1, c = a + (uint32_t)n + 1, d = c + 1;
            uint32_t q[6] = {a, b, d, a, d, c};
            for (int k = 0; k < 6; k++)
                g->tri[3 * t + k] = q[k];
            t += 2;
        }
}

static void check_frame(const float *t, double tx, double ty, double tz, double w)
{
    CHECK_NEAR(t[0], tx, 1e-6);
    CHECK_NEAR(t[1], ty, 1e-6);
    CHECK_NEAR(t[2], tz, 1e-6);
    CHECK(t[3] == w);
}

static void test_plane(void)
{
    for (int flip = 0; flip < 2; flip++) {
        grid g;
        grid_make(&g, 3, flip);
        int32_t *src;
        float *tan;
        int32_t n = fs_tangents_build(g.pos, g.normal, g.uv, NULL, g.n_vert, g.tri, g.n_tris, &src, &tan);
        CHECK(n == g.n_vert); /* one handedness: no vertex split */
        /* u grows along +x (or -x when mirrored); w = -1 for the mirrored mapping, so that
         * cross(n, t) * w = +y, the way v grows, either way */
        for (int32_t v = 0; v < n; v++) {
            CHECK(src[v] == v);
            check_frame(tan + 4 * v, flip ? -1.0 : 1.0, 0.0, 0.0, flip ? -1.0 : 1.0);
        }
        free(src);
        free(tan);
    }
}

/* Two cells side by side, the right one mirrored in u about their shared edge: the shared
 * vertices are used both ways and are split, the mirrored triangles moved to the copies. */
static void test_mirror_splits(void)
{
    grid g;
    grid_make(&g, 2, false);
    /* u = x on the left cells, u = 1 - x on the right ones: u goes 0, 1/2, 0 across */
    for (int32_t v = 0; v < g.n_vert; v++)
        if (g.pos[3 * v] > 0.75f)
            g.uv[2 * v] = 0.0f;
    int32_t *src;
    float *tan;
    int32_t n = fs_tangents_build(g.pos, g.normal, g.uv, NULL, g.n_vert, g.tri, g.n_tris, &src, &tan);
    CHECK(n == g.n_vert + 3); /* the three vertices on x = 1/2 */
    for (int32_t v = g.n_vert; v < n; v++) {
        CHECK_NEAR(g.pos[3 * src[v]], 0.5, 1e-6);
        check_frame(tan + 4 * v, -1.0, 0.0, 0.0, -1.0);
        check_frame(tan + 4 * src[v], 1.0, 0.0, 0.0, 1.0);
    }
    for (int32_t f = 0; f < g.n_tris; f++) {
        const uint32_t *c = g.tri + 3 * f;
        bool right = g.pos[3 * src[c[0]]] + g.pos[3 * src[c[1]]] + g.pos[3 * src[c[2]]] > 1.5f;
        for (int k = 0; k < 3; k++) {
            uint32_t v = g.tri[3 * f + k];
            CHECK(tan[4 * v + 3] == (right ? -1.0f : 1.0f));
        }
    }
    free(src);
    free(tan);
}

/* A cylinder of radius 1 around z, u = angle / 2 pi, v = z: the tangent is the way the angle grows,
 * (-sin a, cos a, 0), for every vertex (the seam's copies included). */
static void test_cylinder(void)
{
    enum { SEG = 12, N = (SEG + 1) * 2 };
    float pos[3 * N], normal[3 * N], uv[2 * N];
    uint32_t tri[6 * SEG];
    for (int i = 0; i <= SEG; i++)
        for (int j = 0; j < 2; j++) {
            int v = 2 * i + j;
            double a = 2.0 * PI * i / SEG;
            pos[3 * v] = (float)cos(a);
            pos[3 * v + 1] = (float)sin(a);
            pos[3 * v + 2] = (float)j;
            normal[3 * v] = (float)cos(a);
            normal[3 * v + 1] = (float)sin(a);
            normal[3 * v + 2] = 0.0f;
            uv[2 * v] = (float)i / SEG;
            uv[2 * v + 1] = (float)j;
        }
    for (int i = 0; i < SEG; i++) {
        uint32_t a = 2 * (uint32_t)i, b = a + 2, c = a + 1, d = a + 3;
        uint32_t q[6] = {a, b, d, a, d, c};
        for (int k = 0; k < 6; k++)
            tri[6 * i + k] = q[k];
    }
    int32_t *src;
    float *tan;
    int32_t n = fs_tangents_build(pos, normal, uv, NULL, N, tri, 2 * SEG, &src, &tan);
    CHECK(n == N);
    for (int v = 0; v < N; v++) {
        double a = 2.0 * PI * (v / 2) / SEG;
        CHECK_MSG(fabs(tan[4 * v] + sin(a)) < 1e-5 && fabs(tan[4 * v + 1] - cos(a)) < 1e-5 &&
                      fabs(tan[4 * v + 2]) < 1e-6 && tan[4 * v + 3] == 1.0f,
                  "vertex %d: (%g %g %g %g)", v, tan[4 * v], tan[4 * v + 1], tan[4 * v + 2], tan[4 * v + 3]);
    }
    free(src);
    free(tan);
}

/* A step: the top z = 1 (x <= 1) and a floor z = 0 (x >= 1) joined by a wall x = 1 facing +x,
 * plus a wall y = 0 facing -y along the top's front edge. Walls have no texture area (their top
 * and bottom share texture coordinates); each wall vertex is a copy (same pos_id) of a top or
 * floor vertex. The wall facing -y takes the top's tangent +x; the wall facing +x cannot (+x is
 * its normal) and gets some unit tangent perpendicular to its normal. */
static void test_walls(void)
{
    /* 0..3: top square [0,1]^2 at z = 1; 4..7: floor square [1,2]x[0,1] at z = 0;
     * 8..11: wall x = 1 (8, 9 top at y = 0, 1; 10, 11 bottom); 12..15: wall y = 0 (12, 13 top at
     * x = 0, 1; 14, 15 bottom) */
    float pos[3 * 16] = {0, 0, 1, 1, 0, 1, 1, 1, 1, 0, 1, 1, 1, 0, 0, 2, 0, 0, 2, 1, 0, 1, 1, 0,
                         1, 0, 1, 1, 1, 1, 1, 0, 0, 1, 1, 0, 0, 0, 1, 1, 0, 1, 0, 0, 0, 1, 0, 0};
    float normal[3 * 16], uv[2 * 16];
    int32_t pos_id[16] = {0, 1, 2, 3, 4, 5, 6, 7, 1, 2, 4, 7, 0, 1, 8, 9};
    for (int v = 0; v < 16; v++) {
        float nx = v >= 8 && v < 12 ? 1.0f : 0.0f, ny = v >= 12 ? -1.0f : 0.0f, nz = v < 8 ? 1.0f : 0.0f;
        normal[3 * v] = nx;
        normal[3 * v + 1] = ny;
        normal[3 * v + 2] = nz;
        uv[2 * v] = pos[3 * v] / 2.0f;
        uv[2 * v + 1] = pos[3 * v + 1];
    }
    uint32_t tri[] = {0, 1, 2, 0, 2, 3, 4, 5, 6, 4, 6, 7, 10, 11, 9, 10, 9, 8, 14, 15, 13, 14, 13, 12};
    int32_t *src;
    float *tan;
    int32_t n = fs_tangents_build(pos, normal, uv, pos_id, 16, tri, 8, &src, &tan);
    CHECK(n == 16);
    for (int v = 0; v < 8; v++)
        check_frame(tan + 4 * v, 1.0, 0.0, 0.0, 1.0);
    for (int v = 12; v < 16; v++)
        check_frame(tan + 4 * v, 1.0, 0.0, 0.0, 1.0);
    for (int v = 8; v < 12; v++) {
        const float *t = tan + 4 * v;
        CHECK_NEAR(t[0] * t[0] + t[1] * t[1] + t[2] * t[2], 1.0, 1e-6);
        CHECK_NEAR(t[0], 0.0, 1e-6); /* perpendicular to the wall's normal +x */
        CHECK(t[3] == 1.0f);
    }
    free(src);
    free(tan);
}

int main(void)
{
    RUN(test_plane);
    RUN(test_mirror_splits);
    RUN(test_cylinder);
    RUN(test_walls);
    return check_finish();
}
