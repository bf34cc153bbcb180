/* Tests of lifting render meshes into 3-D (render/lift.c) and writing them as OBJ (io/obj.h). */
#include "render/render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "base/vec.h"
#include "check.h"
#include "io/obj.h"

/* An axis-aligned quad [u0,u1] x [v0,v1] at one height, with vertices of its own. */
static void add_quad(fs_surface *m, double u0, double v0, double u1, double v1, double height)
{
    int32_t a = fs_surface_add_vertex(m, u0, v0, height, 0.0, 1.0, 0.0);
    int32_t b = fs_surface_add_vertex(m, u1, v0, height, 0.0, 1.0, 0.0);
    int32_t c = fs_surface_add_vertex(m, u1, v1, height, 0.0, 1.0, 0.0);
    int32_t d = fs_surface_add_vertex(m, u0, v1, height, 0.0, 1.0, 0.0);
    fs_surface_add_tri(m, a, b, c);
    fs_surface_add_tri(m, a, c, d);
}

/* V - E + F over the positions, edges and triangles of l. */
static long euler(const fs_lifted_mesh *l)
{
    int32_t *edges, bad = -1;
    int32_t n_boundary = fs_lifted_mesh_boundary(l, &edges, &bad);
    free(edges);
    CHECK(bad == 0);
    /* every edge has one or two triangles: 3 F = 2 E - boundary */
    long e = (3L * l->n_tris + n_boundary) / 2;
    return (long)l->n_pos - e + l->n_tris;
}

static int32_t count_walls(const fs_lifted_mesh *l)
{
    int32_t n = 0;
    for (int32_t t = 0; t < l->n_tris; t++)
        n += l->wall[t] != 0;
    return n;
}

/* A crack floor beside a raised cell top: a step along u = 1/2 of 0.2 cm on a 10 x 10 cm plane. The
 * lift closes it by one vertical wall (two triangles) facing the low side, and the layer is a disk
 * bounded only by the domain's border. */
static void plane_step(void)
{
    fs_surface m = {0};
    add_quad(&m, 0.0, 0.0, 0.5, 1.0, 0.2);
    add_quad(&m, 0.5, 0.0, 1.0, 1.0, 0.0);
    fs_domain d = fs_domain_default();
    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    CHECK(l.n_pos == 8);
    CHECK(l.n_tris == 6);
    CHECK(count_walls(&l) == 2);
    for (int32_t i = 0; i < l.n_pos; i++) {
        const double *p = l.pos + 3 * i;
        CHECK(fabs(p[2]) < 1e-12 || fabs(p[2] - 0.2) < 1e-7);
        CHECK(p[0] > -1e-9 && p[0] < 10.0 + 1e-9 && p[1] > -1e-9 && p[1] < 10.0 + 1e-9);
    }
    for (int32_t t = 0; t < l.n_tris; t++)
        for (int k = 0; k < 3; k++) {
            const int32_t *c = l.corner + 9 * t + 3 * k;
            const double *p = l.pos + 3 * c[0];
            const float *uv = l.uv + 2 * c[1], *n = l.normal + 3 * c[2];
            CHECK_NEAR(p[0], 10.0 * uv[0], 1e-5);
            CHECK_NEAR(p[1], 10.0 * uv[1], 1e-5);
            if (l.wall[t]) {
                CHECK_NEAR(n[0], 1.0, 1e-6); /* the wall faces the crack floor, +x */
            } else {
                CHECK_NEAR(n[2], 1.0, 1e-6);
            }
        }
    int32_t *edges;
    int32_t n_b = fs_lifted_mesh_boundary(&l, &edges, NULL);
    CHECK(n_b == 8); /* top and bottom of both halves, the two outer sides, the wall's two ends */
    for (int32_t e = 0; e < n_b; e++) {
        const double *a = l.pos + 3 * edges[2 * e], *b = l.pos + 3 * edges[2 * e + 1];
        bool border = (fabs(a[0]) < 1e-9 && fabs(b[0]) < 1e-9) || (fabs(a[0] - 10) < 1e-6 && fabs(b[0] - 10) < 1e-6) ||
                      (fabs(a[1]) < 1e-9 && fabs(b[1]) < 1e-9) || (fabs(a[1] - 10) < 1e-6 && fabs(b[1] - 10) < 1e-6);
        CHECK_MSG(border, "boundary edge (%g, %g) - (%g, %g) off the border", a[0], a[1], b[0], b[1]);
    }
    free(edges);
    CHECK(euler(&l) == 1);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

/* A band of eight quads around a cylinder (radius 1, height 2) at 0.1 cm, starting before the seam
 * so that one quad straddles it: the lift cuts it at the seam, keeps texture coordinates in [0, 1],
 * welds the seam's two sides into one column of positions and makes an open tube (Euler 0) bounded
 * only at its two ends, every position at radius 1.1. */
static void cylinder_seam(void)
{
    fs_surface m = {0};
    for (int k = 0; k < 8; k++)
        add_quad(&m, -0.05 + k / 8.0, 0.0, -0.05 + (k + 1) / 8.0, 1.0, 0.1);
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_CYLINDER;
    d.radius = 1.0;
    d.height = 2.0;
    fs_domain_normalize(&d);
    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    /* two rows of the quads' eight edge columns and of the seam, and the seam's cut of the
     * straddling quad's diagonal */
    CHECK_MSG(l.n_pos == 19, "%d positions", (int)l.n_pos);
    CHECK(count_walls(&l) == 0);
    for (int32_t i = 0; i < l.n_pos; i++) {
        const double *p = l.pos + 3 * i;
        CHECK_NEAR(hypot(p[0], p[1]), 1.1, 1e-7); /* heights are floats */
    }
    for (int32_t i = 0; i < l.n_uv; i++)
        CHECK(l.uv[2 * i] >= 0.0f && l.uv[2 * i] <= 1.0f && l.uv[2 * i + 1] >= 0.0f && l.uv[2 * i + 1] <= 1.0f);
    int32_t *edges;
    int32_t n_b = fs_lifted_mesh_boundary(&l, &edges, NULL);
    CHECK(n_b == 18);
    for (int32_t e = 0; e < n_b; e++) {
        double za = l.pos[3 * edges[2 * e] + 2], zb = l.pos[3 * edges[2 * e + 1] + 2];
        CHECK((fabs(za) < 1e-9 && fabs(zb) < 1e-9) || (fabs(za - 2) < 1e-9 && fabs(zb - 2) < 1e-9));
    }
    free(edges);
    CHECK(euler(&l) == 0);
    /* outward normals, counter-clockwise seen from outside */
    for (int32_t t = 0; t < l.n_tris; t++) {
        const int32_t *c = l.corner + 9 * t;
        const double *a = l.pos + 3 * c[0], *b = l.pos + 3 * c[3], *e = l.pos + 3 * c[6];
        double u[3], v[3], n[3];
        fs_sub3(u, b, a);
        fs_sub3(v, e, a);
        fs_cross3(n, u, v);
        double mid[3] = {a[0] + b[0] + e[0], a[1] + b[1] + e[1], 0.0};
        CHECK(fs_dot3(n, mid) > 0.0);
    }
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

/* A latitude-longitude grid over a sphere of radius 2 (u in eighths, v in quarters, at 0.05 cm):
 * the rows at the poles collapse to one position each and their triangles drop out, the seam
 * closes, and the result is a closed sphere: no boundary, Euler characteristic 2, 8 * 3 + 2
 * positions. */
static void sphere_closed(void)
{
    fs_surface m = {0};
    for (int j = 0; j < 4; j++)
        for (int k = 0; k < 8; k++)
            add_quad(&m, k / 8.0, j / 4.0, (k + 1) / 8.0, (j + 1) / 4.0, 0.05);
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_SPHERE;
    d.radius = 2.0;
    fs_domain_normalize(&d);
    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    CHECK(l.n_pos == 26);
    int32_t *edges;
    CHECK(fs_lifted_mesh_boundary(&l, &edges, NULL) == 0);
    free(edges);
    CHECK(euler(&l) == 2);
    for (int32_t i = 0; i < l.n_pos; i++)
        CHECK_NEAR(fs_norm3(l.pos + 3 * i), 2.05, 1e-7);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

/* Coincident triangles bound nothing: two copies cancel, a third copy stays. */
static void coincident_cancel(void)
{
    fs_domain d = fs_domain_default();
    for (int copies = 1; copies <= 3; copies++) {
        fs_surface m = {0};
        for (int c = 0; c < copies; c++) {
            int32_t a = fs_surface_add_vertex(&m, 0.1, 0.1, 0.0, 0.0, 1.0, 0.0);
            int32_t b = fs_surface_add_vertex(&m, 0.6, 0.1, 0.0, 0.0, 1.0, 0.0);
            int32_t e = fs_surface_add_vertex(&m, 0.3, 0.5, 0.0, 0.0, 1.0, 0.0);
            if (c == 1)
                fs_surface_add_tri(&m, a, e, b); /* the opposite way round */
            else
                fs_surface_add_tri(&m, a, b, e);
        }
        fs_lifted_mesh l;
        CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
        CHECK(l.n_tris == copies % 2);
        fs_lifted_mesh_free(&l);
        fs_surface_free(&m);
    }
}

/* Steps of different heights meeting at one point: a floor (0) with two raised tops beside it, one
 * at 0.3 and, across the leg between them, one at 0.31. The three walls meet over one point of the
 * texture; the lift cuts the tall wall's vertical edge at the lower wall's height so that every edge
 * keeps two triangles, and the whole stays a disk. */
static void uneven_steps(void)
{
    fs_surface m = {0};
    add_quad(&m, 0.0, 0.0, 0.5, 0.5, 0.0);  /* floor, in two quads that meet the tops' corners */
    add_quad(&m, 0.0, 0.5, 0.5, 1.0, 0.0);
    add_quad(&m, 0.5, 0.0, 1.0, 0.5, 0.3);  /* lower top */
    add_quad(&m, 0.5, 0.5, 1.0, 1.0, 0.31); /* higher top */
    fs_domain d = fs_domain_default();
    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    int32_t *edges;
    int32_t n_b = fs_lifted_mesh_boundary(&l, &edges, NULL);
    CHECK(n_b > 0);
    for (int32_t e = 0; e < n_b; e++) {
        const double *a = l.pos + 3 * edges[2 * e], *b = l.pos + 3 * edges[2 * e + 1];
        bool border = (fabs(a[0]) < 1e-9 && fabs(b[0]) < 1e-9) || (fabs(a[0] - 10) < 1e-6 && fabs(b[0] - 10) < 1e-6) ||
                      (fabs(a[1]) < 1e-9 && fabs(b[1]) < 1e-9) || (fabs(a[1] - 10) < 1e-6 && fabs(b[1] - 10) < 1e-6);
        CHECK_MSG(border, "boundary edge (%g, %g, %g) - (%g, %g, %g) off the border", a[0], a[1], a[2], b[0], b[1],
                  b[2]);
    }
    free(edges);
    CHECK(euler(&l) == 1);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

/* Two raised cells touching only at the centre of the plane, across two crack floors (a checkerboard
 * of quads, as wedge elements alive on one diagonal of a node and removed on the other): the four
 * walls at the centre would share one upright edge. The lift gives each cell its own copies of the
 * centre's top position and of that edge, so every edge has at most two triangles running opposite
 * ways, and the two cells share no position above the floor. */
static void touching_corners(void)
{
    fs_surface m = {0};
    add_quad(&m, 0.0, 0.0, 0.5, 0.5, 0.2);
    add_quad(&m, 0.5, 0.5, 1.0, 1.0, 0.2);
    add_quad(&m, 0.5, 0.0, 1.0, 0.5, 0.0);
    add_quad(&m, 0.0, 0.5, 0.5, 1.0, 0.0);
    fs_domain d = fs_domain_default();
    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    int32_t *edges, bad = -1;
    fs_lifted_mesh_boundary(&l, &edges, &bad);
    free(edges);
    CHECK_MSG(bad == 0, "%d edges with more than two triangles or running the same way", (int)bad);
    /* the centre's top (5, 5, 0.2): one copy per cell */
    int32_t copies = 0;
    for (int32_t i = 0; i < l.n_pos; i++)
        copies += fabs(l.pos[3 * i] - 5.0) < 1e-9 && fabs(l.pos[3 * i + 1] - 5.0) < 1e-9 &&
                  fabs(l.pos[3 * i + 2] - 0.2) < 1e-6;
    CHECK_MSG(copies == 2, "%d positions at the centre's top, expected 2", (int)copies);
    /* no triangle of one cell's top (u < 1/2, v < 1/2) uses a position of the other's */
    int32_t shared = 0;
    for (int32_t f = 0; f < l.n_tris; f++) {
        if (l.wall[f])
            continue;
        for (int32_t g = 0; g < l.n_tris; g++) {
            if (l.wall[g])
                continue;
            double cf = 0.0, cg = 0.0, hf = 0.0, hg = 0.0;
            for (int k = 0; k < 3; k++) {
                cf += l.pos[3 * l.corner[9 * f + 3 * k]] + l.pos[3 * l.corner[9 * f + 3 * k] + 1];
                cg += l.pos[3 * l.corner[9 * g + 3 * k]] + l.pos[3 * l.corner[9 * g + 3 * k] + 1];
                hf += l.pos[3 * l.corner[9 * f + 3 * k] + 2];
                hg += l.pos[3 * l.corner[9 * g + 3 * k] + 2];
            }
            if (hf < 0.5 || hg < 0.5 || !(cf < 30.0 && cg > 30.0))
                continue;
            for (int a = 0; a < 3; a++)
                for (int b = 0; b < 3; b++)
                    shared += l.corner[9 * f + 3 * a] == l.corner[9 * g + 3 * b];
        }
    }
    CHECK_MSG(shared == 0, "the two cells' tops share %d corners", (int)shared);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

/* The OBJ file holds exactly the lifted mesh: as many v, vt, vn and f lines as positions, texture
 * vertices, normals and triangles, walls in their own group, and the same bytes for the same mesh. */
static void obj_file(void)
{
    fs_surface m = {0};
    add_quad(&m, 0.0, 0.0, 0.5, 1.0, 0.2);
    add_quad(&m, 0.5, 0.0, 1.0, 1.0, 0.0);
    fs_domain d = fs_domain_default();
    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    char dir[] = "/tmp/fissure-test-lift-XXXXXX";
    CHECK(mkdtemp(dir) != NULL);
    char path[2][64];
    for (int k = 0; k < 2; k++) {
        snprintf(path[k], sizeof path[k], "%s/m%d.obj", dir, k);
        CHECK(fs_obj_write(path[k], &l, "step", "test", NULL) == 0);
    }
    FILE *f = fopen(path[0], "r");
    CHECK(f != NULL);
    int v = 0, vt = 0, vn = 0, faces = 0, groups = 0;
    char line[256];
    while (f && fgets(line, sizeof line, f)) {
        v += !strncmp(line, "v ", 2);
        vt += !strncmp(line, "vt ", 3);
        vn += !strncmp(line, "vn ", 3);
        faces += !strncmp(line, "f ", 2);
        groups += !strcmp(line, "g layer\n") || !strcmp(line, "g walls\n");
    }
    if (f)
        fclose(f);
    CHECK(v == l.n_pos && vt == l.n_uv && vn == l.n_normal && faces == l.n_tris && groups == 2);
    char cmd[200];
    snprintf(cmd, sizeof cmd, "cmp -s %s %s", path[0], path[1]);
    CHECK(system(cmd) == 0);
    CHECK(fs_obj_write("/nonexistent-dir/m.obj", &l, "step", NULL, NULL) < 0 && fs_error_domain() == FS_ERR_IO);
    for (int k = 0; k < 2; k++)
        unlink(path[k]);
    rmdir(dir);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

int main(void)
{
    RUN(plane_step);
    RUN(cylinder_seam);
    RUN(sphere_closed);
    RUN(coincident_cancel);
    RUN(uneven_steps);
    RUN(touching_corners);
    RUN(obj_file);
    return check_finish();
}
