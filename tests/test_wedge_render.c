/* Tests of the wedge model's render mesh (model/wedge/surface.c): with element splitting, the fragment tops and the crack floor partition texture space, and the lift closes every crack with walls. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "setup.h"
#include "geom/delaunay.h"
#include "geom/sample.h"
#include "io/preset.h"
#include "model/wedge/internal.h"

/* A preset of presets/ with the given element count and seed, fracture by splitting. */
static fs_config preset_config(const char *name, int32_t elements, uint64_t seed)
{
    fs_config c = fs_config_default();
    char path[1024];
    snprintf(path, sizeof path, "%s/presets/%s.ini", FS_SRCDIR, name);
    int rc = fs_preset_load(path, &c);
    CHECK_MSG(rc == 0, "%s: %s", path, fs_error_message());
    c.preset.seed = seed;
    c.mesh.elements = elements;
    c.fracture.method = FS_FRACTURE_SPLIT;
    return c;
}

/* Samples, meshes and simulates cfg as fs_sim_run does for the wedge model; returns the render mesh
 * of the final state (and the domain) in *out. Returns 0 or -1. */
static int run(const fs_config *cfg, fs_surface *out, fs_domain *domain)
{
    fs_domain d = cfg->domain;
    fs_domain_normalize(&d);
    *domain = d;
    fs_sample_params sp = fs_sample_params_default();
    sp.count = cfg->mesh.elements / 2;
    sp.iterations = cfg->mesh.relax_iterations;
    sp.radius_jitter = cfg->mesh.radius_jitter;
    sp.seed = cfg->preset.seed;
    fs_points pts = {0};
    fs_mesh m = {0};
    if (fs_sample_repulsion(&d, &sp, &pts) < 0 || fs_delaunay(&d, &pts, &m) < 0) {
        fs_points_free(&pts);
        return -1;
    }
    fs_points_free(&pts);
    fs_wedge_model w;
    if (fs_wedge_init(&w, &m, SETUP(cfg)) < 0) {
        fs_mesh_free(&m);
        return -1;
    }
    int rc = fs_wedge_simulate(&w, cfg->time.end);
    if (rc == 0)
        rc = fs_wedge_surface(&w, out);
    printf("  %s seed %llu: %lld splits, %d render triangles\n", cfg->preset.name, (unsigned long long)cfg->preset.seed,
           (long long)w.fractures, (int)out->n_tris);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
    return rc;
}

/* Twice the signed area of render triangle t in texture space. */
static double uv_area2(const fs_surface *m, int32_t t)
{
    const float *a = m->uv + 2 * m->tri[3 * t], *b = m->uv + 2 * m->tri[3 * t + 1], *c = m->uv + 2 * m->tri[3 * t + 2];
    return ((double)b[0] - a[0]) * ((double)c[1] - a[1]) - ((double)b[1] - a[1]) * ((double)c[0] - a[0]);
}

static int cmp_pos(const void *x, const void *y)
{
    const double *a = *(const double *const *)x, *b = *(const double *const *)y;
    for (int k = 0; k < 3; k++)
        if (a[k] != b[k])
            return a[k] < b[k] ? -1 : 1;
    return 0;
}

static int cmp_edge(const void *x, const void *y)
{
    const int64_t a = *(const int64_t *)x, b = *(const int64_t *)y;
    return a < b ? -1 : (a > b);
}

/* V - E + F of l with equal positions taken as one (copies where fragments touch). */
static long merged_euler(const fs_lifted_mesh *l)
{
    const double **order = malloc(sizeof *order * (size_t)(l->n_pos + 1));
    int32_t *id = malloc(sizeof *id * (size_t)(l->n_pos + 1));
    for (int32_t i = 0; i < l->n_pos; i++)
        order[i] = l->pos + 3 * (size_t)i;
    qsort(order, (size_t)l->n_pos, sizeof *order, cmp_pos);
    long v = 0;
    for (int32_t i = 0; i < l->n_pos; i++) {
        if (i == 0 || cmp_pos(order + i, order + i - 1) != 0)
            v++;
        id[(order[i] - l->pos) / 3] = (int32_t)(v - 1);
    }
    int64_t *e = malloc(sizeof *e * (3 * (size_t)l->n_tris + 1));
    for (int32_t t = 0; t < l->n_tris; t++)
        for (int k = 0; k < 3; k++) {
            int64_t a = id[l->corner[9 * (size_t)t + 3 * k]], b = id[l->corner[9 * (size_t)t + 3 * ((k + 1) % 3)]];
            e[3 * t + k] = a < b ? a << 32 | b : b << 32 | a;
        }
    qsort(e, 3 * (size_t)l->n_tris, sizeof *e, cmp_edge);
    long n_e = 0;
    for (size_t i = 0; i < 3 * (size_t)l->n_tris; i++)
        n_e += i == 0 || e[i] != e[i - 1];
    free(order);
    free(id);
    free(e);
    return v - n_e + l->n_tris;
}

/* design: the facts that make the split model's render mesh a partition of texture space, and its
 * lift a closed layer: no triangle is turned over, the areas sum to the whole texture (periodic
 * domains: every point is covered once, pieces outside [0, 1]^2 wrap), the floor is the cracks'
 * share of it, and the lift has walls, no edge of more than two triangles, boundary only on the
 * borders of the domain (a tile is a flat slab, a trunk segment an open tube: the plane's four
 * sides, the cylinder's two ends) and the Euler characteristic of a disk (plane) or a tube. With
 * upright walls ([render] wall_slope 0) the crack's vertices lie on the floor and the lift adds
 * walls; sloping walls are crack too, from the tops' height down, and leave no step to close. */
static void check_partition(const char *preset, int32_t elements, uint64_t seed, double slope, long euler_expected)
{
    fs_config cfg = preset_config(preset, elements, seed);
    cfg.render.wall_slope = slope;
    fs_surface m = {0};
    fs_domain d;
    int rc = run(&cfg, &m, &d);
    CHECK_MSG(rc == 0, "%s: %s", preset, fs_error_message());
    if (rc < 0)
        return;
    double total = 0.0, floor = 0.0, worst = 0.0;
    int32_t floors = 0;
    for (int32_t t = 0; t < m.n_tris; t++) {
        double a = 0.5 * uv_area2(&m, t);
        total += a;
        worst = fmin(worst, a);
        bool crack = true;
        for (int k = 0; k < 3; k++) {
            int32_t v = m.tri[3 * t + k];
            crack = crack && m.crack[v] == 1.0f;
            if (m.crack[v] == 1.0f)
                CHECK(m.height[v] >= 0.0f && (slope > 0.0 || m.height[v] == 0.0f) && m.cell[v] == 0.0f);
            else
                CHECK(m.height[v] > 0.0f && m.cell[v] >= 1.0f);
        }
        floor += crack ? a : 0.0;
        floors += crack;
    }
    printf("  %s, wall_slope %g: texture area %.12f, floor %.5f in %d triangles, most negative triangle %.3g\n", preset,
           slope, total, floor, (int)floors, worst);
    /* texture coordinates are floats (steps of 6e-8 near 1): a sliver's area rounds by ~1e-9 */
    CHECK_MSG(worst > -1e-8, "%s: a triangle turned over (area %g)", preset, worst);
    CHECK_NEAR(total, 1.0, 1e-7);
    CHECK_MSG(floor > 1e-4 && floor < 0.2, "%s: crack floor %g of the texture", preset, floor);

    fs_lifted_mesh l;
    CHECK(fs_render_lift(&m, &d, 1.0, &l) == 0);
    int32_t *edges, bad = -1, walls = 0, off_border = 0;
    int32_t n_b = fs_lifted_mesh_boundary(&l, &edges, &bad);
    for (int32_t t = 0; t < l.n_tris; t++)
        walls += l.wall[t];
    double tol = 1e-6 * fmax(fs_domain_extent_x(&d), fs_domain_extent_y(&d));
    for (int32_t i = 0; i < n_b; i++) {
        const double *a = l.pos + 3 * (size_t)edges[2 * i], *b = l.pos + 3 * (size_t)edges[2 * i + 1];
        bool on = false;
        if (d.type == FS_DOMAIN_PLANE)
            for (int q = 0; q < 2; q++) {
                double ext = q ? d.height : d.width;
                on = on || (fabs(a[q]) < tol && fabs(b[q]) < tol) || (fabs(a[q] - ext) < tol && fabs(b[q] - ext) < tol);
            }
        else
            on = (fabs(a[2]) < tol && fabs(b[2]) < tol) || (fabs(a[2] - d.height) < tol && fabs(b[2] - d.height) < tol);
        off_border += !on;
    }
    free(edges);
    long chi = merged_euler(&l);
    printf("  %s: lift %d triangles (%d walls), %d boundary edges, %d off the borders, euler %ld\n", preset,
           (int)l.n_tris, (int)walls, (int)n_b, (int)off_border, chi);
    CHECK(bad == 0);
    /* upright walls are steps the lift closes; sloping ones join the tops to the floor themselves */
    CHECK_MSG(slope > 0.0 ? walls == 0 : walls > 0, "%s: %d walls added by the lift", preset, (int)walls);
    CHECK_MSG(off_border == 0, "%s: %d boundary edges inside the domain (cracks left open)", preset, (int)off_border);
    CHECK_MSG(chi == euler_expected, "%s: Euler characteristic %ld, expected %ld", preset, chi, euler_expected);
    fs_lifted_mesh_free(&l);
    fs_surface_free(&m);
}

/* Drying mud on a periodic tile: polygons with T-junctions. */
static void test_mud_partition(void)
{
    check_partition("mud", 600, 1, 0.0, 1);
    check_partition("mud", 600, 1, 0.6, 1);
    check_partition("mud", 600, 1, 1.0, 1);
}

/* The trunk cracked by splitting (bark-remove with fracture.method = split), periodic both ways:
 * long axial cracks, walls crossing where the axial compression presses cross cracks shut, and
 * junction holes turned over at narrow sectors. */
static void test_trunk_partition(void)
{
    check_partition("bark-remove", 500, 2, 0.0, 0);
    check_partition("bark-remove", 500, 2, 0.8, 0);
}

int main(void)
{
    RUN(test_mud_partition);
    RUN(test_trunk_partition);
    return check_finish();
}
