/* The wedge model's render mesh: the top surface of the remaining elements by fragment and the floor of removed ones, in texture space. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "model/wedge.h"

/* Sphere: largest uv deviation of a chord's midpoint image from the mean of its ends before a
 * triangle is split into four, and the depth limit of that splitting. */
#define SPHERE_UV_TOLERANCE 5e-4
#define SPHERE_MAX_DEPTH 6

static int32_t find_root(int32_t *parent, int32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

int32_t fs_wedge_fragments(const fs_wedge_model *w, int32_t *labels)
{
    int32_t n = w->n_elems;
    int32_t *parent = fs_malloc((size_t)(n ? n : 1) * sizeof *parent);
    for (int32_t e = 0; e < n; e++)
        parent[e] = e;
    for (int32_t i = 0; i < w->n_nodes; i++) {
        int32_t first = -1;
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
            int32_t e = w->node_elem[p];
            if (w->state[e] != FS_WEDGE_ALIVE)
                continue;
            if (first < 0) {
                first = e;
                continue;
            }
            int32_t a = find_root(parent, first), b = find_root(parent, e);
            if (a != b) {
                if (a < b)
                    parent[b] = a;
                else
                    parent[a] = b;
            }
        }
    }
    /* roots are the smallest element of their component, so labels follow the smallest elements */
    int32_t count = 0;
    for (int32_t e = 0; e < n; e++) {
        if (w->state[e] != FS_WEDGE_ALIVE) {
            labels[e] = -1;
            continue;
        }
        int32_t r = find_root(parent, e);
        labels[e] = r == e ? count++ : labels[r];
    }
    free(parent);
    return count;
}

typedef struct {
    double height, crack, cell, shade;
} attr;

static attr attr_mix(attr a, attr b, attr c, double wa, double wb, double wc)
{
    attr r = {wa * a.height + wb * b.height + wc * c.height, wa * a.crack + wb * b.crack + wc * c.crack,
              wa * a.cell + wb * b.cell + wc * c.cell, wa * a.shade + wb * b.shade + wc * c.shade};
    return r;
}

static int32_t add_vertex(fs_render_mesh *out, double u, double v, attr a)
{
    return fs_render_mesh_add_vertex(out, u, v, a.height, a.crack, a.cell, a.shade);
}

/* ---- sphere ---- */

typedef struct {
    const fs_domain *d;
    fs_render_mesh *out;
} sphere_ctx;

static void sphere_uv(const sphere_ctx *s, const double *p, double uv[2])
{
    double q[3], r = fs_norm3(p);
    for (int k = 0; k < 3; k++)
        q[k] = p[k] * (s->d->radius / r);
    fs_domain_to_uv(s->d, q, uv);
}

/* u of b brought within half a period of u of a. */
static double unwrap_u(double ua, double ub)
{
    while (ub - ua > 0.5)
        ub -= 1.0;
    while (ub - ua < -0.5)
        ub += 1.0;
    return ub;
}

static void midpoint(const double *a, const double *b, double *m)
{
    for (int k = 0; k < 3; k++)
        m[k] = 0.5 * (a[k] + b[k]);
}

static bool chord_bends(const sphere_ctx *s, const double *a, const double *b)
{
    double ua[2], ub[2], um[2], m[3];
    midpoint(a, b, m);
    sphere_uv(s, a, ua);
    sphere_uv(s, b, ub);
    sphere_uv(s, m, um);
    ub[0] = unwrap_u(ua[0], ub[0]);
    um[0] = unwrap_u(ua[0], um[0]);
    return fabs(um[0] - 0.5 * (ua[0] + ub[0])) + fabs(um[1] - 0.5 * (ua[1] + ub[1])) > SPHERE_UV_TOLERANCE;
}

static void sphere_leaf(const sphere_ctx *s, const double p[3][3], const attr a[3])
{
    int32_t v[3];
    double u0 = 0.0;
    for (int c = 0; c < 3; c++) {
        double uv[2];
        sphere_uv(s, p[c], uv);
        if (c == 0)
            u0 = uv[0];
        else
            uv[0] = unwrap_u(u0, uv[0]);
        v[c] = add_vertex(s->out, uv[0], uv[1], a[c]);
    }
    fs_render_mesh_add_tri(s->out, v[0], v[1], v[2]);
}

static void sphere_refine(const sphere_ctx *s, const double p[3][3], const attr a[3], int depth)
{
    bool split = false;
    for (int c = 0; c < 3 && depth < SPHERE_MAX_DEPTH && !split; c++)
        split = chord_bends(s, p[c], p[(c + 1) % 3]);
    if (!split) {
        sphere_leaf(s, p, a);
        return;
    }
    double m[3][3];
    attr am[3];
    for (int c = 0; c < 3; c++) {
        midpoint(p[c], p[(c + 1) % 3], m[c]);
        am[c] = attr_mix(a[c], a[(c + 1) % 3], a[c], 0.5, 0.5, 0.0);
    }
    double q[3][3];
    attr aq[3];
    for (int c = 0; c < 3; c++) { /* corner triangles (p_c, m_c, m_c-1) */
        memcpy(q[0], p[c], sizeof q[0]);
        memcpy(q[1], m[c], sizeof q[1]);
        memcpy(q[2], m[(c + 2) % 3], sizeof q[2]);
        aq[0] = a[c];
        aq[1] = am[c];
        aq[2] = am[(c + 2) % 3];
        sphere_refine(s, q, aq, depth + 1);
    }
    sphere_refine(s, m, am, depth + 1);
}

/* Triangle (pole, a, b): strips of meridians from points of the chord ab up to the pole's row of the
 * texture, carrying the pole's attributes there. */
static void sphere_pole_wedge(const sphere_ctx *s, double pole_v, attr ap, const double *a, const double *b,
                              attr aa, attr ab)
{
    double ua[2], ub[2];
    sphere_uv(s, a, ua);
    sphere_uv(s, b, ub);
    double du = unwrap_u(ua[0], ub[0]) - ua[0];
    int n = 1 + (int)ceil(fabs(du) * 128.0);
    double prev_uv[2] = {ua[0], ua[1]};
    attr prev = aa;
    for (int k = 1; k <= n; k++) {
        double t = (double)k / n, p[3], uv[2];
        for (int c = 0; c < 3; c++)
            p[c] = a[c] + t * (b[c] - a[c]);
        sphere_uv(s, p, uv);
        uv[0] = unwrap_u(prev_uv[0], uv[0]);
        attr cur = attr_mix(aa, ab, aa, 1.0 - t, t, 0.0);
        int32_t v0 = add_vertex(s->out, prev_uv[0], prev_uv[1], prev);
        int32_t v1 = add_vertex(s->out, uv[0], uv[1], cur);
        int32_t v2 = add_vertex(s->out, uv[0], pole_v, ap);
        int32_t v3 = add_vertex(s->out, prev_uv[0], pole_v, ap);
        fs_render_mesh_add_tri(s->out, v0, v1, v2);
        fs_render_mesh_add_tri(s->out, v0, v2, v3);
        prev_uv[0] = uv[0];
        prev_uv[1] = uv[1];
        prev = cur;
    }
}

/* design: as in model/voronoi.c, a sphere triangle is drawn in the equirectangular texture with its u
 * values unwrapped around its first corner, split into four while the map bends its edges, and a
 * triangle around a pole is cut at the pole into three whose images are strips of meridians
 * reaching the pole's row. */
static void sphere_triangle(const sphere_ctx *s, const double p[3][3], const attr a[3])
{
    for (int k = 0; k < 2; k++) {
        double pole[3] = {0.0, 0.0, k ? s->d->radius : -s->d->radius};
        double sum[3] = {0}, cr[3];
        for (int c = 0; c < 3; c++)
            for (int j = 0; j < 3; j++)
                sum[j] += p[c][j];
        if (fs_dot3(pole, sum) <= 0.0)
            continue;
        bool inside = true;
        for (int c = 0; c < 3 && inside; c++) {
            fs_cross3(cr, p[c], p[(c + 1) % 3]);
            inside = fs_dot3(pole, cr) >= 0.0;
        }
        if (!inside)
            continue;
        /* the pole's attributes: barycentric weights of the pole's projection onto the flat triangle */
        double e1[3], e2[3], n[3], q[3], w[3];
        fs_sub3(e1, p[1], p[0]);
        fs_sub3(e2, p[2], p[0]);
        fs_cross3(n, e1, e2);
        double nn = fs_dot3(n, n);
        for (int c = 0; c < 3; c++) {
            double x[3], y[3];
            fs_sub3(x, p[(c + 1) % 3], pole);
            fs_sub3(y, p[(c + 2) % 3], pole);
            fs_cross3(q, x, y);
            w[c] = fs_dot3(q, n) / nn;
        }
        attr ap = attr_mix(a[0], a[1], a[2], w[0], w[1], w[2]);
        double pole_v = k ? 1.0 : 0.0;
        for (int c = 0; c < 3; c++)
            sphere_pole_wedge(s, pole_v, ap, p[c], p[(c + 1) % 3], a[c], a[(c + 1) % 3]);
        return;
    }
    sphere_refine(s, p, a, 0);
}

/* ---- the mesh ---- */

/* Height of the top of the layer over a node (cm): its thickness plus the normal displacement of the
 * top relative to the bottom. */
static double top_height(const fs_wedge_model *w, int32_t node)
{
    const double *u = w->u + 6 * (size_t)node, *n = w->normal + 3 * (size_t)node;
    double rise = n[0] * (u[3] - u[0]) + n[1] * (u[4] - u[1]) + n[2] * (u[5] - u[2]);
    return w->assembled_thickness * w->thickness_factor[node] + rise;
}

/* In-plane displacement of a node's top (cm, model frame): what opens the cracks of the split method. */
static void top_shift(const fs_wedge_model *w, int32_t node, double *p)
{
    const double *u = w->u + 6 * (size_t)node + 3, *n = w->normal + 3 * (size_t)node;
    double un = n[0] * u[0] + n[1] * u[1] + n[2] * u[2];
    for (int k = 0; k < 3; k++)
        p[k] += u[k] - un * n[k];
}

/* design: with fracture by splitting (wedge_split.c) every element stays alive and a crack is a pair
 * of walls on duplicated nodes at the same rest position, so the render draws a floor of every
 * element at height 0 marked crack, and over it the top surface at the displaced top-node positions:
 * the in-plane displacement opens the cracks (the highest surface wins, render.h). */
int fs_wedge_render_mesh(const fs_wedge_model *w, fs_render_mesh *out)
{
    memset(out, 0, sizeof *out);
    int32_t *label = fs_malloc((size_t)(w->n_elems ? w->n_elems : 1) * sizeof *label);
    fs_wedge_fragments(w, label);
    const fs_mesh *m = w->mesh;
    const fs_domain *d = &m->domain;
    double ext[2] = {fs_domain_extent_x(d), fs_domain_extent_y(d)};
    sphere_ctx sc = {d, out};
    bool split = w->cfg.fracture.method == FS_FRACTURE_SPLIT;
    for (int pass = split ? 0 : 1; pass < 2; pass++)
    for (int32_t e = 0; e < w->n_elems; e++) {
        attr a[3];
        double p[3][3];
        for (int c = 0; c < 3; c++) {
            int32_t node = m->tri[3 * (size_t)e + c];
            fs_mesh_corner(m, e, c, p[c]);
            if (pass == 1 && split && label[e] >= 0)
                top_shift(w, node, p[c]);
            if (pass == 0 || label[e] < 0) {
                a[c] = (attr){0.0, 1.0, 0.0, 0.0};
            } else {
                double shade = 2.0 * fs_rand01(w->cfg.preset.seed, FS_RNG_CELL_COLOR, (uint64_t)label[e]) - 1.0;
                a[c] = (attr){top_height(w, node), 0.0, (double)(label[e] % 65535 + 1), shade};
            }
        }
        if (w->flat) {
            int32_t v[3];
            for (int c = 0; c < 3; c++)
                v[c] = add_vertex(out, p[c][0] / ext[0], p[c][1] / ext[1], a[c]);
            fs_render_mesh_add_tri(out, v[0], v[1], v[2]);
        } else {
            sphere_triangle(&sc, (const double(*)[3])p, a);
        }
    }
    free(label);
    return 0;
}
