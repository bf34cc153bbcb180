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

/* The displacement of node i relative to the surface it is bonded to, times the gap scale and the
 * opening scale. */
static void opening(const fs_shell *s, int32_t i, double d[3])
{
    double g = s->cfg.shell.gap_scale * s->cfg.opening_scale;
    for (int k = 0; k < 3; k++)
        d[k] = g * (s->x[3 * (size_t)i + k] - s->anchor[3 * (size_t)i + k]);
}

/* A top corner on the sphere: corner c of triangle t at rest, moved by its node's opening in the
 * layer's tangent plane. */
static void sphere_top(const fs_shell *s, int32_t t, int c, double p[3])
{
    int32_t i = s->mesh->tri[3 * (size_t)t + c];
    const double *n = s->normal + 3 * (size_t)i;
    double dd[3];
    opening(s, i, dd);
    fs_shell_corner(s, s->rest, t, c, p);
    double dn = fs_dot3(dd, n);
    for (int k = 0; k < 3; k++)
        p[k] += dd[k] - dn * n[k];
}

/* ---- texture-space corners ---- */

/* design: a vertex of the mesh appears in texture space once per chart it lies in (twice or more on
 * a UV seam), and triangles of one chart must meet exactly, so the texture points are computed per
 * "corner group": the corners of one node with the same rest texture coordinates. A group's opened
 * point is its rest point plus the mean over its triangles of J_t d, d the node's opening in the
 * triangle's frame and J_t the triangle's map from its frame to texture space. */
typedef struct {
    int32_t n_groups;
    int32_t *group;   /* per corner (3 t + c) */
    double *moved;    /* 2 per group: opened texture point */
    double *rest;     /* 2 per group: rest texture point */
} corner_groups;

static const fs_shell *sort_shell;

static int cmp_corner(const void *pa, const void *pb)
{
    int32_t a = *(const int32_t *)pa, b = *(const int32_t *)pb;
    const fs_mesh *m = sort_shell->mesh;
    int32_t na = m->tri[a], nb = m->tri[b];
    if (na != nb)
        return na < nb ? -1 : 1;
    const double *ua = sort_shell->uv + 2 * (size_t)a, *ub = sort_shell->uv + 2 * (size_t)b;
    for (int k = 0; k < 2; k++)
        if (ua[k] != ub[k])
            return ua[k] < ub[k] ? -1 : 1;
    return a < b ? -1 : a > b;
}

/* J of triangle t: frame coordinates -> texture, [uv1 - uv0, uv2 - uv0] Dm^-1 (row-major 2x2). */
static void texture_map(const fs_shell *s, int32_t t, double J[4])
{
    const double *uv0 = s->uv + 6 * (size_t)t, *di = s->dm_inv + 4 * (size_t)t;
    double du1[2] = {uv0[2] - uv0[0], uv0[3] - uv0[1]}, du2[2] = {uv0[4] - uv0[0], uv0[5] - uv0[1]};
    J[0] = du1[0] * di[0] + du2[0] * di[2];
    J[1] = du1[0] * di[1] + du2[0] * di[3];
    J[2] = du1[1] * di[0] + du2[1] * di[2];
    J[3] = du1[1] * di[1] + du2[1] * di[3];
}

static void groups_build(const fs_shell *s, corner_groups *g)
{
    const fs_mesh *m = s->mesh;
    size_t nc = 3 * (size_t)m->n_tris;
    int32_t *order = fs_malloc((nc + 1) * sizeof *order);
    for (size_t c = 0; c < nc; c++)
        order[c] = (int32_t)c;
    sort_shell = s;
    qsort(order, nc, sizeof *order, cmp_corner);
    g->group = fs_malloc((nc + 1) * sizeof *g->group);
    g->moved = fs_calloc(2 * (nc + 1), sizeof *g->moved);
    g->rest = fs_malloc(2 * (nc + 1) * sizeof *g->rest);
    int32_t *count = fs_calloc(nc + 1, sizeof *count);
    int32_t n = 0;
    for (size_t k = 0; k < nc; k++) {
        int32_t c = order[k];
        if (k == 0 || m->tri[order[k - 1]] != m->tri[c] ||
            memcmp(s->uv + 2 * (size_t)order[k - 1], s->uv + 2 * (size_t)c, 2 * sizeof(double))) {
            g->rest[2 * (size_t)n] = s->uv[2 * (size_t)c];
            g->rest[2 * (size_t)n + 1] = s->uv[2 * (size_t)c + 1];
            n++;
        }
        g->group[c] = n - 1;
    }
    g->n_groups = n;
    /* the mean opened point of each group */
    for (int32_t t = 0; t < m->n_tris; t++) {
        double J[4];
        texture_map(s, t, J);
        const double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
        for (int c = 0; c < 3; c++) {
            double d[3];
            opening(s, m->tri[3 * (size_t)t + c], d);
            double d2[2] = {fs_dot3(d, e1), fs_dot3(d, e2)};
            int32_t q = g->group[3 * (size_t)t + c];
            g->moved[2 * (size_t)q] += J[0] * d2[0] + J[1] * d2[1];
            g->moved[2 * (size_t)q + 1] += J[2] * d2[0] + J[3] * d2[1];
            count[q]++;
        }
    }
    for (int32_t q = 0; q < n; q++)
        for (int k = 0; k < 2; k++)
            g->moved[2 * (size_t)q + k] = g->rest[2 * (size_t)q + k] + g->moved[2 * (size_t)q + k] / count[q];
    free(count);
    free(order);
}

static void groups_free(corner_groups *g)
{
    free(g->group);
    free(g->moved);
    free(g->rest);
}

/* ---- chart borders (mesh domains) ---- */

typedef struct {
    int32_t a, b;  /* origins, smaller first */
    int32_t corner;
} wall_edge;

static int cmp_wall(const void *x, const void *y)
{
    const wall_edge *p = x, *q = y;
    if (p->a != q->a)
        return p->a < q->a ? -1 : 1;
    if (p->b != q->b)
        return p->b < q->b ? -1 : 1;
    return p->corner < q->corner ? -1 : p->corner > q->corner;
}

/* The boundary edges of the mesh (corner c: the edge from corner c to the next of its triangle),
 * sorted by their origins, so that the two walls of a crack (the same pair of origins) come
 * together. Returns the list (caller frees) and sets *n. */
static wall_edge *boundary_edges(const fs_shell *s, size_t *n)
{
    const fs_mesh *m = s->mesh;
    size_t nc = 3 * (size_t)m->n_tris, nw = 0;
    wall_edge *w = fs_malloc((nc + 1) * sizeof *w);
    for (size_t c = 0; c < nc; c++) {
        if (m->adj[c] >= 0)
            continue;
        size_t next = c - c % 3 + (c + 1) % 3;
        int32_t oa = s->origin[m->tri[c]], ob = s->origin[m->tri[next]];
        w[nw++] = (wall_edge){oa < ob ? oa : ob, oa < ob ? ob : oa, (int32_t)c};
    }
    qsort(w, nw, sizeof *w, cmp_wall);
    *n = nw;
    return w;
}

/* Marks (border[3 t + i] = 1) every edge of the texture layout that is a border of its chart: an
 * edge of the mesh's own border, or a UV seam (the triangles across it place its ends at other
 * texture points); not a crack's wall (a boundary edge whose twin, the same pair of origins, is the
 * other wall). */
static void chart_borders(const fs_shell *s, const corner_groups *g, uint8_t *border)
{
    const fs_mesh *m = s->mesh;
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int i = 0; i < 3; i++) {
            size_t c = 3 * (size_t)t + i;
            int32_t u = m->adj[c];
            border[c] = 0;
            if (u >= 0) {
                /* a seam: the neighbour's corners at these nodes are other groups */
                int32_t na = m->tri[c], nb = m->tri[3 * (size_t)t + (i + 1) % 3];
                int ca = fs_mesh_corner_of(m, u, na), cb = fs_mesh_corner_of(m, u, nb);
                if (ca >= 0 && cb >= 0 &&
                    (g->group[3 * (size_t)u + ca] != g->group[c] || g->group[3 * (size_t)u + cb] != g->group[3 * (size_t)t + (i + 1) % 3]))
                    border[c] = 1;
            }
        }
    size_t nw;
    wall_edge *w = boundary_edges(s, &nw);
    for (size_t k = 0; k < nw;) {
        size_t j = k;
        while (j < nw && w[j].a == w[k].a && w[j].b == w[k].b)
            j++;
        if (j - k == 1)
            border[w[k].corner] = 1;
        k = j;
    }
    free(w);
}

/* Pads every chart of the texture layout with a skirt SKIRT_PIXELS (at 1024 pixels) wide that
 * copies its border's attributes (a little lower, so that no real surface is covered), so that
 * filtering and mip-mapping near a chart's border read the chart, not the background. */
#define SKIRT_PIXELS 4.0

static void add_skirts(const fs_shell *s, const corner_groups *g, const attr *top, fs_surface *out)
{
    const fs_mesh *m = s->mesh;
    size_t nc = 3 * (size_t)m->n_tris;
    uint8_t *border = fs_malloc(nc + 1);
    chart_borders(s, g, border);
    double *normal = fs_calloc(2 * ((size_t)g->n_groups + 1), sizeof *normal);
    double *edge_n = fs_malloc(2 * (nc + 1) * sizeof *edge_n);
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int i = 0; i < 3; i++) {
            size_t c = 3 * (size_t)t + i;
            if (!border[c])
                continue;
            const double *uv = s->uv + 6 * (size_t)t;
            const double *p = uv + 2 * i, *q = uv + 2 * ((i + 1) % 3), *r = uv + 2 * ((i + 2) % 3);
            double n[2] = {q[1] - p[1], p[0] - q[0]}, l = hypot(n[0], n[1]);
            if ((r[0] - p[0]) * n[0] + (r[1] - p[1]) * n[1] > 0.0)
                l = -l; /* away from the third corner */
            edge_n[2 * c] = n[0] / l;
            edge_n[2 * c + 1] = n[1] / l;
            for (int e = 0; e < 2; e++) {
                int32_t q2 = g->group[3 * (size_t)t + (i + e) % 3];
                normal[2 * (size_t)q2] += edge_n[2 * c];
                normal[2 * (size_t)q2 + 1] += edge_n[2 * c + 1];
            }
        }
    double width = SKIRT_PIXELS / 1024.0;
    for (int32_t t = 0; t < m->n_tris; t++)
        for (int i = 0; i < 3; i++) {
            size_t c = 3 * (size_t)t + i;
            if (!border[c])
                continue;
            int32_t v[4];
            for (int e = 0; e < 2; e++) {
                int corner = (i + e) % 3;
                int32_t q = g->group[3 * (size_t)t + corner];
                double nx = normal[2 * (size_t)q], ny = normal[2 * (size_t)q + 1], l = hypot(nx, ny);
                double mx = l > 0.0 ? nx / l : edge_n[2 * c], my = l > 0.0 ? ny / l : edge_n[2 * c + 1];
                double cosine = mx * edge_n[2 * c] + my * edge_n[2 * c + 1];
                double w = width / fmax(cosine, 0.5);
                attr a = top[3 * (size_t)t + corner];
                a.height *= 0.999;
                const double *pt = g->moved + 2 * (size_t)q;
                v[e] = fs_surface_add_vertex(out, pt[0], pt[1], a.height, a.crack, a.cell, a.shade);
                v[3 - e] = fs_surface_add_vertex(out, pt[0] + w * mx, pt[1] + w * my, a.height, a.crack, a.cell, a.shade);
            }
            fs_surface_add_tri(out, v[0], v[1], v[2]);
            fs_surface_add_tri(out, v[0], v[2], v[3]);
        }
    free(border);
    free(normal);
    free(edge_n);
}

/* ---- sloping walls ([render] wall_slope) ---- */

/* Where corner c's top is drawn: its texture point (2 numbers), or on the sphere its 3-D point. */
static void top_point(const fs_shell *s, const corner_groups *g, size_t c, double *p)
{
    if (s->mesh->domain.type == FS_DOMAIN_SPHERE) {
        sphere_top(s, (int32_t)(c / 3), (int)(c % 3), p);
        return;
    }
    memcpy(p, g->moved + 2 * (size_t)g->group[c], 2 * sizeof *p);
}

/* The slope down from the wall edge at corner c (to the next corner of its triangle) to its feet,
 * `foot` of the way to the points of the same origins on the wall across, whose edge is at corner
 * c2. Unless the wall across lies in another chart of the texture layout (a crack along a UV seam:
 * its rest points are elsewhere, not a whole period away). */
static void emit_slope(render_ctx *r, const corner_groups *g, const attr *top, size_t c, size_t c2, double foot)
{
    const fs_shell *s = r->s;
    const fs_mesh *m = s->mesh;
    bool sphere = m->domain.type == FS_DOMAIN_SPHERE;
    int dim = sphere ? 3 : 2;
    size_t mine[2] = {c, c - c % 3 + (c + 1) % 3}, across[2] = {c2, c2 - c2 % 3 + (c2 + 1) % 3};
    if (s->origin[m->tri[across[0]]] != s->origin[m->tri[mine[0]]]) {
        size_t t = across[0];
        across[0] = across[1];
        across[1] = t;
    }
    double pt[4][3] = {{0.0}}, shift[2] = {0.0, 0.0};
    attr a[4];
    for (int e = 0; e < 2; e++) {
        double far[3] = {0.0, 0.0, 0.0};
        top_point(s, g, mine[e], pt[e]);
        top_point(s, g, across[e], far);
        if (!sphere) {
            const double *r0 = g->rest + 2 * (size_t)g->group[mine[e]], *r1 = g->rest + 2 * (size_t)g->group[across[e]];
            bool wraps[2] = {fs_domain_wraps_u(&m->domain), fs_domain_wraps_v(&m->domain)};
            for (int k = 0; k < 2; k++) {
                shift[k] = wraps[k] ? round(r0[k] - r1[k]) : 0.0;
                if (fabs(r0[k] - r1[k] - shift[k]) > 1e-9)
                    return;
            }
        }
        for (int k = 0; k < dim; k++)
            pt[3 - e][k] = pt[e][k] + foot * (far[k] + (k < 2 && !sphere ? shift[k] : 0.0) - pt[e][k]);
        a[e] = (attr){top[mine[e]].height * 0.999, 1.0, 0.0, 0.0}; /* under the top it meets (add_skirts) */
        a[3 - e] = (attr){0.0, 1.0, 0.0, 0.0};
    }
    static const int tris[2][3] = {{0, 1, 2}, {0, 2, 3}};
    for (int k = 0; k < 2; k++) {
        double uv[6], p[9];
        attr at[3];
        for (int q = 0; q < 3; q++) {
            const double *x = pt[tris[k][q]];
            at[q] = a[tris[k][q]];
            memcpy(p + 3 * q, x, 3 * sizeof *x);
            uv[2 * q] = x[0];
            uv[2 * q + 1] = x[1];
        }
        emit(r, uv, sphere ? p : NULL, at);
    }
}

/* design: the floor lies under the whole layer and the maps show the highest surface, so a crack's
 * walls slope where a slope is drawn from each wall's top edge down to its feet, half of
 * [render] wall_slope of the way across to the points of the same origins on the wall across; the
 * floor shows between the feet, and where cracks meet the slopes overlap. */
static void add_slopes(render_ctx *r, const corner_groups *g, const attr *top)
{
    double foot = 0.5 * fmin(fmax(r->s->cfg.wall_slope, 0.0), 1.0);
    if (!(foot > 0.0))
        return;
    size_t nw;
    wall_edge *w = boundary_edges(r->s, &nw);
    for (size_t k = 0; k + 1 < nw; k++)
        if (w[k].a == w[k + 1].a && w[k].b == w[k + 1].b && (k + 2 == nw || w[k + 2].a != w[k].a || w[k + 2].b != w[k].b)
            && (k == 0 || w[k - 1].a != w[k].a || w[k - 1].b != w[k].b)) {
            emit_slope(r, g, top, (size_t)w[k].corner, (size_t)w[k + 1].corner, foot);
            emit_slope(r, g, top, (size_t)w[k + 1].corner, (size_t)w[k].corner, foot);
        }
    free(w);
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
    bool pin_u = d->type == FS_DOMAIN_PLANE && !d->periodic_x;
    bool pin_v = (d->type == FS_DOMAIN_PLANE || d->type == FS_DOMAIN_CYLINDER) && !d->periodic_y;
    corner_groups g = {0};
    if (!sphere)
        groups_build(s, &g);
    attr *top = fs_malloc(3 * ((size_t)m->n_tris + 1) * sizeof *top);
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
        attr *a = top + 3 * (size_t)t;
        double uv[6], p[9];
        for (int c = 0; c < 3; c++) {
            int32_t i = m->tri[3 * (size_t)t + c];
            double dd[3];
            opening(s, i, dd);
            a[c] = (attr){h + fs_dot3(dd, n) / s->cfg.shell.gap_scale, 0.0, (double)(label[t] % 65535 + 1), shade};
            if (sphere) {
                sphere_top(s, t, c, p + 3 * c);
                continue;
            }
            const double *moved = g.moved + 2 * (size_t)g.group[3 * (size_t)t + c];
            const double *uv0 = s->uv + 6 * (size_t)t + 2 * c;
            uv[2 * c] = moved[0];
            uv[2 * c + 1] = moved[1];
            /* tops keep to the borders of a texture that does not wrap */
            if (pin_u && (fabs(uv0[0]) < 1e-9 || fabs(uv0[0] - 1.0) < 1e-9))
                uv[2 * c] = uv0[0];
            if (pin_v && (fabs(uv0[1]) < 1e-9 || fabs(uv0[1] - 1.0) < 1e-9))
                uv[2 * c + 1] = uv0[1];
        }
        emit(&r, uv, sphere ? p : NULL, a);
    }
    add_slopes(&r, &g, top);
    if (d->type == FS_DOMAIN_MESH)
        add_skirts(s, &g, top, out);
    groups_free(&g);
    free(top);
    free(label);
    return 0;
}
