/* The shell model's render mesh in texture space: the fragments at their opened positions over a floor that shows through the cracks. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "geom/sphere_surface.h"

/* Sphere: largest uv deviation of a chord's midpoint image from the mean of its ends' images before
 * the chord is halved (geom/sphere_surface.h). */
#define SPHERE_UV_TOLERANCE 5e-4

static int32_t find_root(int32_t *parent, int32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

int32_t fs_shell_fragments(const fs_shell *s, int32_t *label)
{
    const fs_mesh *m = s->mesh;
    int32_t n = m->n_tris;
    int32_t *parent = fs_malloc(((size_t)n + 1) * sizeof *parent);
    for (int32_t t = 0; t < n; t++)
        parent[t] = t;
    for (int32_t t = 0; t < n; t++)
        for (int i = 0; i < 3; i++) {
            int32_t u = m->adj[3 * (size_t)t + i];
            if (u < 0)
                continue;
            int32_t a = find_root(parent, t), b = find_root(parent, u);
            if (a < b)
                parent[b] = a;
            else if (b < a)
                parent[a] = b;
        }
    int32_t count = 0;
    for (int32_t t = 0; t < n; t++) {
        int32_t r = find_root(parent, t);
        label[t] = r == t ? count++ : label[r];
    }
    free(parent);
    return count;
}

typedef struct {
    double height, crack, cell, shade;
} attr;

typedef struct {
    const fs_shell *s;
    fs_surface *out;
    fs_sphere_refiner sphere;
    const attr *sphere_attr;
} render_ctx;

static int32_t sphere_vertex(void *user, double u, double v, const double w[3])
{
    const render_ctx *r = user;
    const attr *a = r->sphere_attr;
    return fs_surface_add_vertex(r->out, u, v, w[0] * a[0].height + w[1] * a[1].height + w[2] * a[2].height,
                                 w[0] * a[0].crack + w[1] * a[1].crack + w[2] * a[2].crack,
                                 w[0] * a[0].cell + w[1] * a[1].cell + w[2] * a[2].cell,
                                 w[0] * a[0].shade + w[1] * a[1].shade + w[2] * a[2].shade);
}

/* One triangle: in texture space (uv, 6 numbers) or, on the sphere, of 3-D points (p, 9 numbers). */
static void emit(render_ctx *r, const double *uv, const double *p, const attr a[3])
{
    if (p) {
        r->sphere_attr = a;
        fs_sphere_triangle(&r->sphere, p, p + 3, p + 6);
        return;
    }
    int32_t v[3];
    for (int c = 0; c < 3; c++)
        v[c] = fs_surface_add_vertex(r->out, uv[2 * c], uv[2 * c + 1], a[c].height, a[c].crack, a[c].cell, a[c].shade);
    fs_surface_add_tri(r->out, v[0], v[1], v[2]);
}

/* The displacement of node i relative to the surface it is bonded to, times the gap scale. */
static void opening(const fs_shell *s, int32_t i, double d[3])
{
    double g = s->cfg.shell.gap_scale;
    for (int k = 0; k < 3; k++)
        d[k] = g * (s->x[3 * (size_t)i + k] - s->anchor[3 * (size_t)i + k]);
}

int fs_shell_surface(const fs_shell *s, fs_surface *out)
{
    const fs_mesh *m = s->mesh;
    const fs_domain *d = &m->domain;
    bool sphere = d->type == FS_DOMAIN_SPHERE;
    render_ctx r = {s, out, {d, SPHERE_UV_TOLERANCE, out, sphere_vertex, NULL}, NULL};
    r.sphere.user = &r;
    int32_t *label = fs_malloc(((size_t)m->n_tris + 1) * sizeof *label);
    fs_shell_fragments(s, label);
    static const attr floor_attr = {0.0, 1.0, 0.0, 0.0};
    const attr floor3[3] = {floor_attr, floor_attr, floor_attr};
    bool pin_u = d->type == FS_DOMAIN_PLANE && !d->periodic_x, pin_v = d->type == FS_DOMAIN_PLANE && !d->periodic_y;
    if (d->type == FS_DOMAIN_CYLINDER)
        pin_v = !d->periodic_y;
    /* the floor: the rest layout */
    for (int32_t t = 0; t < m->n_tris; t++) {
        double p[9];
        if (sphere)
            for (int c = 0; c < 3; c++)
                fs_shell_corner(s, s->rest, t, c, p + 3 * c);
        emit(&r, s->uv + 6 * (size_t)t, sphere ? p : NULL, floor3);
    }
    /* the tops */
    for (int32_t t = 0; t < m->n_tris; t++) {
        double shade = 2.0 * fs_rand01(s->cfg.seed, FS_RNG_CELL_COLOR, (uint64_t)label[t]) - 1.0;
        double h = fs_shell_tri_thickness(s, t);
        const double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
        double n[3];
        fs_cross3(n, e1, e2);
        attr a[3];
        double uv[6], p[9];
        const double *uv0 = s->uv + 6 * (size_t)t;
        /* J: frame coordinates -> uv, [uv1 - uv0, uv2 - uv0] Dm^-1 */
        const double *di = s->dm_inv + 4 * (size_t)t;
        double du1[2] = {uv0[2] - uv0[0], uv0[3] - uv0[1]}, du2[2] = {uv0[4] - uv0[0], uv0[5] - uv0[1]};
        double J[4] = {du1[0] * di[0] + du2[0] * di[2], du1[0] * di[1] + du2[0] * di[3],
                       du1[1] * di[0] + du2[1] * di[2], du1[1] * di[1] + du2[1] * di[3]};
        for (int c = 0; c < 3; c++) {
            int32_t i = m->tri[3 * (size_t)t + c];
            double dd[3];
            opening(s, i, dd);
            a[c] = (attr){h + fs_dot3(dd, n) / s->cfg.shell.gap_scale, 0.0, (double)(label[t] % 65535 + 1), shade};
            if (sphere) {
                fs_shell_corner(s, s->rest, t, c, p + 3 * c);
                for (int k = 0; k < 3; k++)
                    p[3 * c + k] += dd[k] - fs_dot3(dd, s->normal + 3 * (size_t)i) * s->normal[3 * (size_t)i + k];
                continue;
            }
            double d2[2] = {fs_dot3(dd, e1), fs_dot3(dd, e2)};
            uv[2 * c] = uv0[2 * c] + J[0] * d2[0] + J[1] * d2[1];
            uv[2 * c + 1] = uv0[2 * c + 1] + J[2] * d2[0] + J[3] * d2[1];
            /* tops keep to the borders of a texture that does not wrap */
            if (pin_u && (fabs(uv0[2 * c]) < 1e-9 || fabs(uv0[2 * c] - 1.0) < 1e-9))
                uv[2 * c] = uv0[2 * c];
            if (pin_v && (fabs(uv0[2 * c + 1]) < 1e-9 || fabs(uv0[2 * c + 1] - 1.0) < 1e-9))
                uv[2 * c + 1] = uv0[2 * c + 1];
        }
        emit(&r, uv, sphere ? p : NULL, a);
    }
    free(label);
    return 0;
}
