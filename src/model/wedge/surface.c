/* The wedge model's render mesh in texture space: the fragment tops, and the floor of removed elements or of the crack gaps between split fragments. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/uf.h"
#include "base/vec.h"
#include "model/wedge/internal.h"
#include "geom/sphere_surface.h"

/* Sphere: largest uv deviation of a chord's midpoint image from the mean of its ends' images
 * before the chord is halved (geom/sphere_surface.h). */
#define SPHERE_UV_TOLERANCE 5e-4

/* Most points of a polygon of floor where cracks meet (before the feet of sloping walls). */
#define JUNCTION_CAP 64

int32_t fs_wedge_fragments(const fs_wedge_model *w, int32_t *labels)
{
    int32_t n = w->n_elems;
    int32_t *parent = fs_malloc((size_t)(n ? n : 1) * sizeof *parent);
    fs_uf_init(parent, n);
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
            fs_uf_union(parent, first, e);
        }
    }
    /* roots are the smallest element of their component, so labels follow the smallest elements */
    int32_t count = 0;
    for (int32_t e = 0; e < n; e++) {
        if (w->state[e] != FS_WEDGE_ALIVE) {
            labels[e] = -1;
            continue;
        }
        int32_t r = fs_uf_find(parent, e);
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

static int32_t add_vertex(fs_surface *out, double u, double v, attr a)
{
    return fs_surface_add_vertex(out, u, v, a.height, a.crack, a.cell, a.shade);
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

/* In-plane displacement of a node's top (cm, model frame) times [render] opening_scale, added to p: what
 * opens the cracks of the split method. */
static void top_shift(const fs_wedge_model *w, int32_t node, double *p)
{
    const double *u = w->u + 6 * (size_t)node + 3, *n = w->normal + 3 * (size_t)node;
    double un = n[0] * u[0] + n[1] * u[1] + n[2] * u[2], scale = w->cfg.opening_scale;
    for (int k = 0; k < 3; k++)
        p[k] += scale * (u[k] - un * n[k]);
}

/* ---- emitting ---- */

typedef struct {
    const fs_wedge_model *w;
    fs_surface *out;
    fs_sphere_refiner sphere; /* draws the triangles of a sphere (the frame is not flat) */
    const attr *sphere_attr;  /* the corners' attributes of the triangle it draws */
    double ext[2];   /* the unwrapped rectangle (flat frames) */
    bool wrap[2];    /* flat frames: the axis is periodic (never on the sphere, which has no shifts) */
    double tol;      /* cm: points this close to a line lie on it */
    int32_t *label;  /* fragment of each element, -1 if removed */
    int32_t *group;  /* per node: its rest point, the same for nodes at one rest position */
    double *delta;   /* split: 3 per point id (wall_point.id): where it is drawn, less its displaced
                      * position; nonzero only where walls cross (close_crossings) */
    int32_t *parent; /* split: union-find over point ids joining copies where walls cross, or NULL */
    double foot;     /* split: where a sloping wall meets the floor, as a share of the floor's width
                      * from the wall (half of [render] wall_slope); 0: upright walls */
    int32_t feet;    /* split: feet drawn so far (they are points of the surface of their own) */
    bool fan_ears;   /* split: clip_ears dips the ears' diagonals between two corners to the floor
                      * (emit_ear) */
} render_ctx;

/* fs_sphere_refiner.vertex: a vertex with the attributes of the triangle's corners mixed by w. */
static int32_t sphere_vertex(void *user, double u, double v, const double w[3])
{
    const render_ctx *r = user;
    const attr *a = r->sphere_attr;
    return add_vertex(r->out, u, v, attr_mix(a[0], a[1], a[2], w[0], w[1], w[2]));
}

/* One triangle of points in the model frame (flat frames: the unwrapped rectangle, z = 0). */
static void emit_tri(render_ctx *r, const double p[3][3], const attr a[3])
{
    if (!r->w->flat) {
        r->sphere_attr = a;
        fs_sphere_triangle(&r->sphere, p[0], p[1], p[2]);
        return;
    }
    int32_t v[3];
    for (int c = 0; c < 3; c++)
        v[c] = add_vertex(r->out, p[c][0] / r->ext[0], p[c][1] / r->ext[1], a[c]);
    fs_surface_add_tri(r->out, v[0], v[1], v[2]);
}

static attr top_attr(const render_ctx *r, int32_t e, int32_t node)
{
    double shade = 2.0 * fs_rand01(r->w->cfg.seed, FS_RNG_CELL_COLOR, (uint64_t)r->label[e]) - 1.0;
    return (attr){top_height(r->w, node), 0.0, (double)(r->label[e] % 65535 + 1), shade};
}

static const attr floor_attr = {0.0, 1.0, 0.0, 0.0};

/* ---- fracture by splitting: the fragment tops and the floor of the crack gaps between them ---- */

/* A point of the top surface on a crack wall, in the frame of the element it was taken from. */
typedef struct {
    int32_t id;      /* its node, or n_nodes + k for the k-th point inserted on a wall */
    int32_t vertex;  /* which point of the surface it is: its id, or the smallest id of the points
                      * joined with it where a crack closes (close_crossings) */
    int32_t group;   /* its rest point (render_ctx.group) */
    double rest[3];  /* rest position, unwrapped in the element's frame */
    double moved[3]; /* its displaced top position in the same frame, as the model has it */
    double top[3];   /* where it is drawn: moved + render_ctx.delta */
    attr a;          /* the top's attributes there */
} wall_point;

/* Corner c of living element e as a wall point: at its rest position moved by the in-plane
 * displacement of its top node. On a border of a non-periodic axis the motion across the border
 * is left out, so the tops still reach the border of the texture and cover it. */
static wall_point corner_point(const render_ctx *r, int32_t e, int c)
{
    const fs_mesh *m = r->w->mesh;
    wall_point p;
    p.id = p.vertex = m->tri[3 * (size_t)e + c];
    p.group = r->group[p.id];
    fs_mesh_corner(m, e, c, p.rest);
    memcpy(p.moved, p.rest, sizeof p.moved);
    top_shift(r->w, p.id, p.moved);
    if (r->w->flat)
        for (int q = 0; q < 2; q++)
            if (!r->wrap[q] && (fabs(p.rest[q]) <= r->tol || fabs(p.rest[q] - r->ext[q]) <= r->tol))
                p.moved[q] = p.rest[q];
    for (int k = 0; k < 3; k++)
        p.top[k] = p.moved[k] + r->delta[3 * (size_t)p.id + k];
    if (r->parent)
        p.vertex = fs_uf_find(r->parent, p.id);
    p.a = top_attr(r, e, p.id);
    return p;
}

static wall_point lerp_point(const wall_point *a, const wall_point *b, double t)
{
    wall_point p = *a;
    for (int k = 0; k < 3; k++) {
        p.rest[k] = a->rest[k] + t * (b->rest[k] - a->rest[k]);
        p.moved[k] = p.top[k] = a->moved[k] + t * (b->moved[k] - a->moved[k]);
    }
    p.a = attr_mix(a->a, b->a, a->a, 1.0 - t, t, 0.0);
    return p;
}

/* Moves p by whole periods so that its rest position comes nearest `rest` (flat periodic axes). */
static void align_point(const render_ctx *r, wall_point *p, const double *rest)
{
    for (int q = 0; q < 2; q++)
        if (r->wrap[q]) {
            double k = round((rest[q] - p->rest[q]) / r->ext[q]) * r->ext[q];
            p->rest[q] += k;
            p->moved[q] += k;
            p->top[q] += k;
        }
}

/* Twice the signed area of (a, b, c) seen from outside the layer. */
static double area2(const render_ctx *r, const double *a, const double *b, const double *c)
{
    double e1[3], e2[3], n[3];
    fs_sub3(e1, b, a);
    fs_sub3(e2, c, a);
    fs_cross3(n, e1, e2);
    if (r->w->flat)
        return n[2];
    double s[3] = {a[0] + b[0] + c[0], a[1] + b[1] + c[1], a[2] + b[2] + c[2]};
    double len = fs_norm3(s);
    return len > 0.0 ? fs_dot3(n, s) / len : 0.0;
}

/* A triangle over three points where they are drawn, with their attributes, unless two of them are
 * one point of the surface. */
static void emit_points(render_ctx *r, const wall_point *a, const wall_point *b, const wall_point *c)
{
    if (a->vertex == b->vertex || b->vertex == c->vertex || c->vertex == a->vertex)
        return;
    const wall_point *v[3] = {a, b, c};
    double p[3][3];
    attr at[3];
    for (int k = 0; k < 3; k++) {
        memcpy(p[k], v[k]->top, sizeof p[k]);
        at[k] = v[k]->a;
    }
    emit_tri(r, (const double(*)[3])p, at);
}

/* design: [render] wall_slope s draws each wall of a crack sloping from the top of its fragment down
 * to the floor over the share s / 2 of the gap next to it, so a crack's section is a trapezoid, a V
 * at s = 1. Every edge of the floor across a crack (from a copy a of a rest point to another copy
 * b) gets two points where the walls meet the floor, its feet, a + (s / 2)(b - a) and
 * b + (s / 2)(a - b); the floor quads of the pairs (split_render_mesh) and the polygons where cracks
 * meet (emit_junction) put the same feet on their common edges, so they meet vertex to vertex. The
 * slope between a wall's top edge and its feet has the wall's attributes: crack coverage 1 and the
 * height of the top at its upper edge. */

/* The foot of the slope on the floor's edge from a across to b: the point near a. */
static wall_point foot_point(render_ctx *r, const wall_point *a, const wall_point *b)
{
    wall_point f = *a;
    for (int k = 0; k < 3; k++)
        f.top[k] = a->top[k] + r->foot * (b->top[k] - a->top[k]);
    f.vertex = -2 - r->feet++;
    f.a = floor_attr;
    return f;
}

/* A wall's top edge point as the upper edge of its slope: the top's height, the crack's cover. */
static wall_point slope_top(const wall_point *p)
{
    wall_point s = *p;
    s.a = (attr){p->a.height, 1.0, 0.0, 0.0};
    return s;
}

/* A quad (a, b, c, d) counter-clockwise, split along the diagonal that keeps both triangles the
 * larger; corners that are one point of the surface make it a triangle or nothing. */
static void emit_quad(render_ctx *r, const wall_point *a, const wall_point *b, const wall_point *c,
                      const wall_point *d)
{
    const wall_point *q[4] = {a, b, c, d};
    bool diag_bd = b->vertex != c->vertex && a->vertex != d->vertex
                   && fmin(area2(r, a->top, b->top, c->top), area2(r, a->top, c->top, d->top))
                          < fmin(area2(r, a->top, b->top, d->top), area2(r, b->top, c->top, d->top));
    static const int tris[2][2][3] = {{{0, 1, 2}, {0, 2, 3}}, {{0, 1, 3}, {1, 2, 3}}};
    for (int t = 0; t < 2; t++) {
        const int *ix = tris[diag_bd][t];
        emit_points(r, q[ix[0]], q[ix[1]], q[ix[2]]);
    }
}

/* The floor of the pair quad (q, p, q2, p2) between the walls p -> q and p2 -> q2: one quad with
 * upright walls, else a slope down from each wall and the floor between their feet. */
static void emit_gap(render_ctx *r, const wall_point quad[4])
{
    if (r->foot <= 0.0) {
        wall_point f[4];
        for (int c = 0; c < 4; c++) {
            f[c] = quad[c];
            f[c].a = floor_attr;
        }
        emit_quad(r, f + 0, f + 1, f + 2, f + 3);
        return;
    }
    const wall_point *q = quad + 0, *p = quad + 1, *q2 = quad + 2, *p2 = quad + 3;
    wall_point tq = slope_top(q), tp = slope_top(p), tq2 = slope_top(q2), tp2 = slope_top(p2);
    wall_point fp = foot_point(r, p, q2), fq2 = foot_point(r, q2, p), fp2 = foot_point(r, p2, q),
               fq = foot_point(r, q, p2);
    if (p->vertex == q2->vertex) /* a crack tip: both feet are the tip */
        fp = fq2 = tp;
    if (q->vertex == p2->vertex)
        fq = fp2 = tq;
    if (r->foot >= 0.5) { /* a V: the feet meet in the middle */
        fq2 = fp;
        fp2 = fq;
    }
    emit_quad(r, &tq, &tp, &fp, &fq);
    emit_quad(r, &fq, &fp, &fq2, &fp2);
    emit_quad(r, &fq2, &tq2, &tp2, &fp2);
}

/* ---- rest points: nodes at one rest position (a node and its duplicates) ---- */

typedef struct {
    double x[3];
    int32_t node;
} node_pos;

static int cmp_node_pos(const void *x, const void *y)
{
    const node_pos *a = x, *b = y;
    for (int k = 0; k < 3; k++)
        if (a->x[k] != b->x[k])
            return a->x[k] < b->x[k] ? -1 : 1;
    return a->node < b->node ? -1 : (a->node > b->node);
}

/* Fills group[n_nodes] (groups numbered in the order of their smallest position) and returns the
 * number of groups; *gpos (caller frees) gets 3 coordinates per group. */
static int32_t rest_groups(const fs_mesh *m, int32_t *group, double **gpos)
{
    node_pos *s = fs_malloc(((size_t)m->n_nodes + 1) * sizeof *s);
    for (int32_t i = 0; i < m->n_nodes; i++) {
        memcpy(s[i].x, m->pos + 3 * (size_t)i, sizeof s[i].x);
        s[i].node = i;
    }
    qsort(s, (size_t)m->n_nodes, sizeof *s, cmp_node_pos);
    double *g = fs_malloc((3 * (size_t)m->n_nodes + 3) * sizeof *g);
    int32_t n = 0;
    for (int32_t i = 0; i < m->n_nodes; i++) {
        if (i == 0 || memcmp(s[i].x, s[i - 1].x, sizeof s[i].x) != 0) {
            memcpy(g + 3 * (size_t)n, s[i].x, sizeof s[i].x);
            n++;
        }
        group[s[i].node] = n - 1;
    }
    free(s);
    *gpos = g;
    return n;
}

/* A uniform grid of rest points over the rectangle (or the sphere's bounding square) in x and y. */
typedef struct {
    int n[2];
    double lo[2], cell[2];
    bool wrap[2];
    int32_t *start, *item; /* per cell, its groups (CSR) */
} group_grid;

static int grid_cell(const group_grid *g, int q, double x)
{
    long long i = (long long)floor((x - g->lo[q]) / g->cell[q]);
    if (g->wrap[q]) {
        i %= g->n[q];
        return (int)(i < 0 ? i + g->n[q] : i);
    }
    return (int)(i < 0 ? 0 : (i >= g->n[q] ? g->n[q] - 1 : i));
}

static void grid_build(group_grid *g, const render_ctx *r, const double *gpos, const uint8_t *use, int32_t n_groups)
{
    int32_t count = 0;
    for (int32_t i = 0; i < n_groups; i++)
        count += use[i];
    int side = (int)ceil(sqrt((double)count));
    side = side < 1 ? 1 : (side > 1024 ? 1024 : side);
    for (int q = 0; q < 2; q++) {
        g->n[q] = side;
        g->wrap[q] = r->wrap[q];
        g->lo[q] = r->w->flat ? 0.0 : -r->w->mesh->domain.radius;
        g->cell[q] = (r->w->flat ? r->ext[q] : 2.0 * r->w->mesh->domain.radius) / side;
    }
    size_t cells = (size_t)side * (size_t)side;
    g->start = fs_calloc(cells + 1, sizeof *g->start);
    g->item = fs_malloc(((size_t)count + 1) * sizeof *g->item);
    int32_t *cell_of = fs_malloc(((size_t)n_groups + 1) * sizeof *cell_of);
    for (int32_t i = 0; i < n_groups; i++)
        if (use[i]) {
            const double *x = gpos + 3 * (size_t)i;
            cell_of[i] = grid_cell(g, 1, x[1]) * side + grid_cell(g, 0, x[0]);
            g->start[cell_of[i] + 1]++;
        }
    for (size_t c = 0; c < cells; c++)
        g->start[c + 1] += g->start[c];
    int32_t *fill = fs_malloc((cells + 1) * sizeof *fill);
    memcpy(fill, g->start, cells * sizeof *fill);
    for (int32_t i = 0; i < n_groups; i++)
        if (use[i])
            g->item[fill[cell_of[i]]++] = i;
    free(fill);
    free(cell_of);
}

/* The cells to visit along axis q for coordinates in [a, b]: raw indices *i0 .. *i1 (reduced
 * modulo the grid on a periodic axis, each cell at most once). */
static void grid_range(const group_grid *g, int q, double a, double b, long long *i0, long long *i1)
{
    *i0 = (long long)floor((a - g->lo[q]) / g->cell[q]);
    *i1 = (long long)floor((b - g->lo[q]) / g->cell[q]);
    if (g->wrap[q]) {
        if (*i1 - *i0 + 1 >= g->n[q]) {
            *i0 = 0;
            *i1 = g->n[q] - 1;
        }
    } else {
        *i0 = *i0 < 0 ? 0 : (*i0 >= g->n[q] ? g->n[q] - 1 : *i0);
        *i1 = *i1 < 0 ? 0 : (*i1 >= g->n[q] ? g->n[q] - 1 : *i1);
    }
}

/* A rest point found inside a wall edge: its parameter along the edge. */
typedef struct {
    double t;
    int32_t group;
} on_edge;

static int cmp_on_edge(const void *x, const void *y)
{
    const on_edge *a = x, *b = y;
    if (a->t != b->t)
        return a->t < b->t ? -1 : 1;
    return a->group < b->group ? -1 : (a->group > b->group);
}

/* Where rest point x lies along the rest wall edge from a to b: its parameter t, and *off, its
 * distance from the edge. Flat frames: the foot of x on the segment. Sphere: the edge is the arc of
 * the great circle through a and b, since the nodes that split an edge are projected onto the
 * sphere (wedge/split.c); t is where the ray to x meets the chord, *off the distance of x from the
 * plane of the great circle (or infinite when x is on the far side of the sphere). */
static double edge_param(const render_ctx *r, const double *a, const double *b, const double *x, double *off)
{
    double ab[3], ax[3];
    fs_sub3(ab, b, a);
    fs_sub3(ax, x, a);
    if (r->w->flat) {
        double t = fs_dot3(ax, ab) / fs_dot3(ab, ab), d[3];
        for (int q = 0; q < 3; q++)
            d[q] = ax[q] - t * ab[q];
        *off = fs_norm3(d);
        return t;
    }
    double m[3], xa[3], xb[3], mid[3] = {a[0] + b[0], a[1] + b[1], a[2] + b[2]};
    fs_cross3(m, a, b);
    double mm = fs_norm3(m);
    fs_cross3(xa, a, x);
    fs_cross3(xb, ab, x);
    double den = fs_dot3(xb, m);
    if (!(mm > 0.0) || fs_dot3(x, mid) <= 0.0 || den == 0.0) {
        *off = INFINITY;
        return 0.0;
    }
    *off = fabs(fs_dot3(x, m)) / mm;
    return -fs_dot3(xa, m) / den; /* (a + t ab) x x = 0 along m */
}

/* The rest points of the grid strictly inside the rest wall edge from a to b (edge_param), sorted
 * along it: where a crack ending on this one cut the wall on the other side only. Returns the count
 * (*found grows as needed). */
static int32_t points_on_edge(const render_ctx *r, const group_grid *g, const double *gpos, const wall_point *a,
                              const wall_point *b, on_edge **found, int32_t *cap)
{
    double ab[3], mid[3];
    fs_sub3(ab, b->rest, a->rest);
    for (int k = 0; k < 3; k++)
        mid[k] = 0.5 * (a->rest[k] + b->rest[k]);
    /* on the sphere the arc bulges out of the chord's box by at most its sagitta, |ab|^2 / (8 R) */
    double reach = r->tol + (r->w->flat ? 0.0 : fs_dot3(ab, ab) / (4.0 * r->w->mesh->domain.radius));
    long long lo[2], hi[2];
    for (int q = 0; q < 2; q++)
        grid_range(g, q, fmin(a->rest[q], b->rest[q]) - reach, fmax(a->rest[q], b->rest[q]) + reach, lo + q, hi + q);
    int32_t n = 0;
    for (long long iy = lo[1]; iy <= hi[1]; iy++)
        for (long long ix = lo[0]; ix <= hi[0]; ix++) {
            long long cx = g->wrap[0] ? ((ix % g->n[0]) + g->n[0]) % g->n[0] : ix;
            long long cy = g->wrap[1] ? ((iy % g->n[1]) + g->n[1]) % g->n[1] : iy;
            size_t cell = (size_t)cy * (size_t)g->n[0] + (size_t)cx;
            for (int32_t k = g->start[cell]; k < g->start[cell + 1]; k++) {
                int32_t grp = g->item[k];
                if (grp == a->group || grp == b->group)
                    continue;
                wall_point x = {.rest = {0}};
                memcpy(x.rest, gpos + 3 * (size_t)grp, sizeof x.rest);
                align_point(r, &x, mid);
                double off, t = edge_param(r, a->rest, b->rest, x.rest, &off);
                if (!(t > 1e-9 && t < 1.0 - 1e-9) || !(off <= r->tol))
                    continue;
                FS_ARRAY_RESERVE(*found, *cap, n + 1, 8);
                (*found)[n++] = (on_edge){t, grp};
            }
        }
    if (n > 1)
        qsort(*found, (size_t)n, sizeof **found, cmp_on_edge);
    return n;
}

/* A wall sub-edge (points k -> k + 1 of the wall point list) by its rest points, for pairing it
 * with the one on the other side of the crack, which runs between the same rest points the other
 * way: the key is (g0, g1, d) for the direction that puts the smaller key first, with d the whole
 * periods from the rest point g0 to g1 beyond their base positions. */
typedef struct {
    int32_t g[2], d[2];
    int32_t dir;     /* 0: the sub-edge runs g0 -> g1; 1: the other way */
    int32_t first;   /* index of its first point */
} sub_key;

static int cmp_sub_key(const void *x, const void *y)
{
    const sub_key *a = x, *b = y;
    for (int q = 0; q < 2; q++) {
        if (a->g[q] != b->g[q])
            return a->g[q] < b->g[q] ? -1 : 1;
        if (a->d[q] != b->d[q])
            return a->d[q] < b->d[q] ? -1 : 1;
    }
    if (a->dir != b->dir)
        return a->dir < b->dir ? -1 : 1;
    return a->first < b->first ? -1 : (a->first > b->first);
}

/* The tops of the living elements, each with the points that other walls' ends put on its wall
 * edges as vertices of its own (fanned from the opposite corner, or from its centroid when more
 * than one edge has such points), so that the floor meets the tops vertex to vertex. */
static void emit_tops(render_ctx *r, const int32_t *elem_wall, const int32_t *wall_first, const int32_t *wall_n,
                      const wall_point *pts)
{
    const fs_wedge_model *w = r->w;
    for (int32_t e = 0; e < w->n_elems; e++) {
        if (r->label[e] < 0) {
            double p[3][3];
            attr f[3] = {floor_attr, floor_attr, floor_attr};
            for (int c = 0; c < 3; c++)
                fs_mesh_corner(w->mesh, e, c, p[c]);
            emit_tri(r, (const double(*)[3])p, f);
            continue;
        }
        wall_point corner[3];
        for (int c = 0; c < 3; c++)
            corner[c] = corner_point(r, e, c);
        int split_edges = 0, last = 0;
        for (int c = 0; c < 3; c++) {
            int32_t wl = elem_wall[3 * (size_t)e + c];
            if (wl >= 0 && wall_n[wl] > 2) {
                split_edges++;
                last = c;
            }
        }
        /* the boundary of the element with its inserted points, from corner `from` on */
        int from = split_edges == 1 ? (last + 2) % 3 : 0;
        wall_point ring[64];
        int n = 0;
        for (int j = 0; j < 3; j++) {
            int c = (from + j) % 3;
            ring[n++] = corner[c];
            int32_t wl = elem_wall[3 * (size_t)e + c];
            if (wl >= 0)
                for (int32_t k = 1; k + 1 < wall_n[wl] && n < 63; k++)
                    ring[n++] = pts[wall_first[wl] + k];
        }
        double p[3][3];
        attr a[3];
        if (split_edges <= 1) { /* a fan from ring[0]: the element itself when nothing is inserted */
            for (int k = 1; k + 1 < n; k++) {
                const wall_point *v[3] = {ring, ring + k, ring + k + 1};
                for (int c = 0; c < 3; c++) {
                    memcpy(p[c], v[c]->top, sizeof p[c]);
                    a[c] = v[c]->a;
                }
                emit_tri(r, (const double(*)[3])p, a);
            }
            continue;
        }
        wall_point centre = corner[0];
        for (int k = 0; k < 3; k++)
            centre.top[k] = (corner[0].top[k] + corner[1].top[k] + corner[2].top[k]) / 3.0;
        centre.a = attr_mix(corner[0].a, corner[1].a, corner[2].a, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0);
        for (int k = 0; k < n; k++) {
            const wall_point *v[3] = {&centre, ring + k, ring + (k + 1) % n};
            for (int c = 0; c < 3; c++) {
                memcpy(p[c], v[c]->top, sizeof p[c]);
                a[c] = v[c]->a;
            }
            emit_tri(r, (const double(*)[3])p, a);
        }
    }
}


/* The quad of floor between a pair of wall sub-edges p -> q and p2 -> q2 (pair: their first
 * points), as (q, p, q2, p2) counter-clockwise, in the frame of the first. */
static void pair_quad(const render_ctx *r, const wall_point *pts, const int32_t *pair, wall_point quad[4])
{
    quad[0] = pts[pair[0] + 1];
    quad[1] = pts[pair[0]];
    quad[2] = pts[pair[1] + 1];
    quad[3] = pts[pair[1]];
    align_point(r, quad + 2, quad[1].rest);
    align_point(r, quad + 3, quad[0].rest);
}

/* An edge of the floor across a crack at one rest point, running with the floor on its left. */
typedef struct {
    int32_t group;
    int32_t order;   /* creation order, for a deterministic sort */
    int32_t pair;    /* the pair whose quad it bounds */
    int32_t end;     /* 0: p -> q2, 1: p2 -> q */
    wall_point from, to;
} cross_edge;

static int cmp_cross(const void *x, const void *y)
{
    const cross_edge *a = x, *b = y;
    if (a->group != b->group)
        return a->group < b->group ? -1 : 1;
    return a->order < b->order ? -1 : (a->order > b->order);
}

/* The edges of the pairs' quads across their cracks, p -> q2 and p2 -> q, where those are two
 * points (not at a crack tip), sorted by rest point; x has room for 2 n_pairs. Returns the count. */
static int32_t cross_edges(const render_ctx *r, const wall_point *pts, const int32_t *pair, int32_t n_pairs,
                           cross_edge *x)
{
    int32_t n = 0;
    for (int32_t i = 0; i < n_pairs; i++) {
        wall_point quad[4];
        pair_quad(r, pts, pair + 2 * i, quad);
        for (int k = 0; k < 2; k++) {
            const wall_point *from = quad + 1 + 2 * k, *to = quad + (2 + 2 * k) % 4;
            if (from->vertex != to->vertex) {
                x[n] = (cross_edge){from->group, n, i, k, *from, *to};
                n++;
            }
        }
    }
    qsort(x, (size_t)n, sizeof *x, cmp_cross);
    return n;
}

/* The holes the floors of the pairs leave where cracks meet: at each rest point, the cross edges
 * that do not cancel (two floors meeting edge to edge) chain into loops around a hole. The loops'
 * points go to *loop (caller frees) counter-clockwise around each hole, in the frame of the loop's
 * first point, loop k from start[k] to start[k + 1] (*start, caller frees); (*edge)[j] (caller
 * frees) is the cross edge (index into x) under the hole's side from point j to the next. Returns
 * the number of loops. */
static int32_t junction_loops(const render_ctx *r, const cross_edge *x, int32_t n, wall_point **loop, int32_t **edge,
                              int32_t **start)
{
    uint8_t *used = fs_calloc((size_t)n + 1, 1);
    wall_point *pt = NULL;
    int32_t *ed = NULL, *first = fs_malloc(sizeof *first);
    int32_t n_pt = 0, cap_pt = 0, n_loops = 0;
    first[0] = 0;
    for (int32_t i = 0; i < n;) {
        int32_t j = i + 1;
        while (j < n && x[j].group == x[i].group)
            j++;
        for (int32_t a = i; a < j; a++)
            for (int32_t b = a + 1; b < j && !used[a]; b++)
                if (!used[b] && x[a].from.vertex == x[b].to.vertex && x[a].to.vertex == x[b].from.vertex)
                    used[a] = used[b] = 1;
        for (int32_t s = i; s < j; s++) {
            if (used[s])
                continue;
            int32_t m = 0, cur = s;
            bool closed = false;
            used[s] = 1;
            for (;;) {
                if (FS_ARRAY_GROW(cap_pt, n_pt + m + 1, 16)) {
                    FS_ARRAY_RESIZE(pt, cap_pt);
                    FS_ARRAY_RESIZE(ed, cap_pt);
                }
                pt[n_pt + m] = x[cur].from;
                ed[n_pt + m] = cur;
                align_point(r, pt + n_pt + m, x[s].from.rest);
                m++;
                if (x[cur].to.vertex == x[s].from.vertex) {
                    closed = true;
                    break;
                }
                int32_t next = -1;
                for (int32_t k = i; k < j && next < 0; k++)
                    if (!used[k] && x[k].from.vertex == x[cur].to.vertex)
                        next = k;
                if (next < 0)
                    break;
                used[next] = 1;
                cur = next;
            }
            if (!closed || m < 3)
                continue; /* an open chain ends on a border of the domain */
            /* the chain f_0 -> f_1 -> ... runs around the hole clockwise (the floors lie to its
             * left): reversed, point k is f_(m-1-k), and the side from it to the next is chain edge
             * m - 2 - k (mod m) */
            int32_t *chain = fs_malloc((size_t)m * sizeof *chain);
            memcpy(chain, ed + n_pt, (size_t)m * sizeof *chain);
            for (int32_t k = 0; k < m / 2; k++) {
                wall_point t = pt[n_pt + k];
                pt[n_pt + k] = pt[n_pt + m - 1 - k];
                pt[n_pt + m - 1 - k] = t;
            }
            for (int32_t k = 0; k < m; k++)
                ed[n_pt + k] = chain[(m - 2 - k + 2 * m) % m];
            free(chain);
            n_pt += m;
            n_loops++;
            first = fs_realloc(first, ((size_t)n_loops + 1) * sizeof *first);
            first[n_loops] = n_pt;
        }
        i = j;
    }
    free(used);
    *loop = pt;
    *edge = ed;
    *start = first;
    return n_loops;
}

static double loop_area2(const render_ctx *r, const wall_point *p, int32_t m)
{
    double a = 0.0;
    for (int32_t k = 1; k + 1 < m; k++)
        a += area2(r, p[0].top, p[k].top, p[k + 1].top);
    return a;
}

/* Joins the points a and b (vertices) of the surface. */
static void join(render_ctx *r, int32_t a, int32_t b)
{
    fs_uf_union(r->parent, a, b);
}

/* Moves every joined set of points to its mean position: sets r->delta for each id, then redraws
 * and renames pts. The mean is taken over the points' moved positions. */
static void apply_joins(render_ctx *r, wall_point *pts, int32_t n_pts, int32_t n_ids)
{
    int32_t *rep = fs_malloc(((size_t)n_ids + 1) * sizeof *rep); /* per id: a point of it */
    for (int32_t i = 0; i < n_ids; i++)
        rep[i] = -1;
    for (int32_t k = 0; k < n_pts; k++)
        if (rep[pts[k].id] < 0)
            rep[pts[k].id] = k;
    double *sum = fs_calloc(4 * (size_t)n_ids + 1, sizeof *sum); /* per root: 3 coordinates, count */
    for (int32_t i = 0; i < n_ids; i++) {
        int32_t root = fs_uf_find(r->parent, i);
        if (rep[i] < 0 || root == i)
            continue;
        for (int32_t k = 0; k < 2; k++) { /* the root's own point once, then i's */
            int32_t who = k ? i : root;
            if (k == 0 && sum[4 * (size_t)root + 3] > 0.0)
                continue;
            wall_point t = pts[rep[who]];
            align_point(r, &t, pts[rep[root]].rest);
            for (int q = 0; q < 3; q++)
                sum[4 * (size_t)root + q] += t.moved[q];
            sum[4 * (size_t)root + 3] += 1.0;
        }
    }
    for (int32_t i = 0; i < n_ids; i++) {
        int32_t root = fs_uf_find(r->parent, i);
        const double *s = sum + 4 * (size_t)root;
        if (rep[i] < 0 || s[3] < 2.0)
            continue;
        const wall_point *own = pts + rep[i];
        wall_point t = *own;
        align_point(r, &t, pts[rep[root]].rest);
        for (int q = 0; q < 3; q++) /* the mean, moved back by the periods t was moved by */
            r->delta[3 * (size_t)i + q] = s[q] / s[3] - (t.rest[q] - own->rest[q]) - own->moved[q];
    }
    for (int32_t k = 0; k < n_pts; k++) {
        for (int q = 0; q < 3; q++)
            pts[k].top[q] = pts[k].moved[q] + r->delta[3 * (size_t)pts[k].id + q];
        pts[k].vertex = fs_uf_find(r->parent, pts[k].id);
    }
    free(sum);
    free(rep);
}

/* An ear (points i, j, k) that clip_ears cuts from polygon p (m points): a triangle. With
 * render_ctx.fan_ears, a side of it that is a diagonal of the polygon between two points above the
 * floor (two corners on walls' top edges, which would bridge the crack at their height) is cut at
 * its midpoint, a point of floor (computed from its end with the smaller index, so the ear on the
 * other side cuts it at the same point), and the ear is fanned from the first such point. */
static void emit_ear(render_ctx *r, const wall_point *p, int32_t m, int32_t i, int32_t j, int32_t k)
{
    int32_t ix[3] = {i, j, k};
    wall_point ring[6];
    int n = 0, first_mid = -1;
    for (int s = 0; s < 3; s++) {
        int32_t a = ix[s], b = ix[(s + 1) % 3];
        ring[n++] = p[a];
        if (!r->fan_ears || (a + 1) % m == b || (b + 1) % m == a || !(p[a].a.height > 0.0 && p[b].a.height > 0.0))
            continue;
        const wall_point *lo = p + (a < b ? a : b), *hi = p + (a < b ? b : a);
        ring[n] = *lo;
        for (int q = 0; q < 3; q++)
            ring[n].top[q] = 0.5 * (lo->top[q] + hi->top[q]);
        ring[n].vertex = -2 - r->feet++;
        ring[n].a = floor_attr;
        if (first_mid < 0)
            first_mid = n;
        n++;
    }
    if (first_mid < 0)
        first_mid = 0;
    for (int s = 1; s + 1 < n; s++)
        emit_points(r, ring + first_mid, ring + (first_mid + s) % n, ring + (first_mid + s + 1) % n);
}

/* Triangulates a small counter-clockwise polygon by clipping ears, emitting the triangles if emit.
 * Returns whether every triangle was an ear of positive area; when not, and emit is set, what is
 * left is fanned. */
static bool clip_ears(render_ctx *r, const wall_point *p, int32_t m, bool emit)
{
    int32_t idx[3 * JUNCTION_CAP], n = 0;
    for (int32_t k = 0; k < m && n < 3 * JUNCTION_CAP; k++)
        idx[n++] = k;
    while (n > 3) {
        int32_t ear = -1;
        for (int32_t k = 0; k < n && ear < 0; k++) {
            const double *a = p[idx[(k + n - 1) % n]].top, *b = p[idx[k]].top, *c = p[idx[(k + 1) % n]].top;
            if (area2(r, a, b, c) <= 0.0)
                continue;
            bool empty = true;
            for (int32_t j = 0; j < n && empty; j++) {
                const double *x = p[idx[j]].top;
                if (j == k || j == (k + 1) % n || j == (k + n - 1) % n)
                    continue;
                empty = !(area2(r, a, b, x) >= 0.0 && area2(r, b, c, x) >= 0.0 && area2(r, c, a, x) >= 0.0);
            }
            if (empty)
                ear = k;
        }
        if (ear < 0)
            break;
        if (emit)
            emit_ear(r, p, m, idx[(ear + n - 1) % n], idx[ear], idx[(ear + 1) % n]);
        for (int32_t j = ear; j + 1 < n; j++)
            idx[j] = idx[j + 1];
        n--;
    }
    bool ok = n == 3 && area2(r, p[idx[0]].top, p[idx[1]].top, p[idx[2]].top) > 0.0;
    for (int32_t k = 1; emit && k + 1 < n; k++)
        emit_ear(r, p, m, idx[0], idx[k], idx[k + 1]);
    return ok;
}

/* The hole of junction loop c (m points, its sides' cross edges in edge) merged with the quads of
 * floor on its sides that are not yet consumed: each side c_k -> c_k+1 is replaced by the two far
 * points of its quad (one where the far end is a crack tip). Writes at most cap points to poly,
 * in the frame of c, with cross[j] telling whether the side from point j to the next crosses a
 * crack (else it runs along a wall), and returns the count (0 if they do not fit). */
static int32_t junction_polygon(const render_ctx *r, const wall_point *pts, const int32_t *pair, const cross_edge *x,
                                const wall_point *c, const int32_t *edge, int32_t m, const uint8_t *consumed,
                                wall_point *poly, uint8_t *cross, int32_t cap)
{
    int32_t n = 0;
    for (int32_t k = 0; k < m; k++) {
        if (n == cap)
            return 0;
        cross[n] = 1;
        poly[n++] = c[k];
        const cross_edge *e = x + edge[k];
        if (consumed[e->pair])
            continue;
        cross[n - 1] = 0;
        wall_point quad[4]; /* q, p, q2, p2 */
        pair_quad(r, pts, pair + 2 * e->pair, quad);
        /* the side runs from the cross edge's end to its start: q2 -> (p2, q) -> p, or
         * q -> (p, q2) -> p2 */
        wall_point far[2] = {e->end ? quad[1] : quad[3], e->end ? quad[2] : quad[0]};
        int32_t added[2] = {-1, -1};
        for (int f = 0; f < 2; f++) {
            align_point(r, far + f, c[k].rest);
            const wall_point *next = c + (k + 1) % m;
            if (far[f].vertex == poly[n - 1].vertex || far[f].vertex == next->vertex)
                continue;
            if (n == cap)
                return 0;
            cross[n] = 0;
            added[f] = n;
            poly[n++] = far[f];
        }
        if (added[0] >= 0 && added[1] >= 0) /* far[0] -> far[1]: the quad's other edge across its crack */
            cross[added[0]] = 1;
    }
    return n;
}

/* The polygon p (n points, the feet marked in foot) cut into the floor between its feet and, for
 * each run of corners between two feet, a sloping piece (foot, corners, foot): the slopes meet in
 * mitres. A run whose piece would turn over (a corner carried past the line between its feet)
 * joins the floor's polygon instead, which then rises to that corner. Drawn if emit; returns
 * whether every piece is a simple polygon (cut into ears of positive area) and there are three
 * feet or more. */
static bool mitred(render_ctx *r, const wall_point *p, const bool *foot, int32_t n, bool emit)
{
    wall_point inner[3 * JUNCTION_CAP], run[3 * JUNCTION_CAP];
    int32_t n_inner = 0, n_feet = 0, first = -1;
    for (int32_t k = 0; k < n; k++)
        if (foot[k]) {
            n_feet++;
            if (first < 0)
                first = k;
        }
    if (n_feet < 3)
        return false;
    for (int32_t i = first, done = 0; done < n_feet; done++) {
        int32_t j = (i + 1) % n, len = 1;
        run[0] = p[i];
        while (!foot[j]) {
            run[len++] = p[j];
            j = (j + 1) % n;
        }
        run[len++] = p[j];
        inner[n_inner++] = p[i];
        if (len > 2 && !clip_ears(r, run, len, false))
            for (int32_t k = 1; k + 1 < len; k++)
                inner[n_inner++] = run[k];
        else if (len > 2 && emit)
            clip_ears(r, run, len, true);
        i = j;
    }
    if (!clip_ears(r, inner, n_inner, false))
        return false;
    if (emit)
        clip_ears(r, inner, n_inner, true);
    return true;
}

/* A polygon of floor where cracks meet (c, m points counter-clockwise; cross as junction_polygon
 * gives it, or NULL when every side crosses a crack): with upright walls a flat floor. With sloping
 * walls the feet of the slopes go on its sides across cracks, so that it meets the quads' slopes
 * edge to edge, and its corners lie on the walls' top edges: mitred (the slopes from each run of
 * corners down to the feet beside it, the floor between the feet), or, where that does not make
 * simple pieces (a polygon merged with the quads of a crack, wrapped around a corner carried into
 * the gap), cut into ears whose diagonals between two corners dip to the floor at their midpoints,
 * so that no ear bridges the gap at the tops' height. */
static void emit_junction(render_ctx *r, const wall_point *c, const uint8_t *cross, int32_t m)
{
    wall_point poly[3 * JUNCTION_CAP];
    bool is_foot[3 * JUNCTION_CAP];
    int32_t n = 0;
    for (int32_t k = 0; k < m && k < JUNCTION_CAP; k++) {
        const wall_point *next = c + (k + 1) % m;
        poly[n] = r->foot > 0.0 ? slope_top(c + k) : c[k];
        if (r->foot <= 0.0)
            poly[n].a = floor_attr;
        is_foot[n++] = false;
        if (r->foot <= 0.0 || (cross && !cross[k]) || next->vertex == c[k].vertex)
            continue;
        for (int f = 0; f < (r->foot < 0.5 ? 2 : 1); f++) {
            is_foot[n] = true;
            poly[n++] = f ? foot_point(r, next, c + k) : foot_point(r, c + k, next);
        }
    }
    if (r->foot <= 0.0) {
        clip_ears(r, poly, n, true);
        return;
    }
    if (mitred(r, poly, is_foot, n, false)) {
        mitred(r, poly, is_foot, n, true);
        return;
    }
    r->fan_ears = true;
    clip_ears(r, poly, n, true);
    r->fan_ears = false;
}

/* design: the model has no contact, so where a crack is pressed shut its two walls can pass each
 * other, and the tops then overlap in texture space (the maps show the higher one); the floor
 * between them would be turned over. Where the walls of a pair of sub-edges cross at an end (the
 * other side's point lies on the material side of this side's wall), the two copies there are
 * joined: drawn at their mean position as one point, so the tops meet there and the floor of the
 * pair shrinks to a triangle or vanishes.
 * Where cracks meet, the hole between the copies of the node can come out turned over although no
 * tops overlap: a copy at the apex of a narrow sector is carried past the line between its
 * neighbours, into a neighbouring crack's mouth. The hole is then merged with the quads of floor
 * on its sides into one polygon, which is simple (junction_polygon, clip_ears); only if it is not
 * are the hole's points joined (for a triangle the copy opposite its longest side with the nearer
 * end of that side, for a larger polygon all of them).
 * Returns the number of points joined to another (0: nothing moved). */
static int32_t close_crossings(render_ctx *r, wall_point *pts, int32_t n_pts, const int32_t *pair, int32_t n_pairs,
                               int32_t n_ids)
{
    r->parent = fs_malloc(((size_t)n_ids + 1) * sizeof *r->parent);
    fs_uf_init(r->parent, n_ids);
    int32_t joined = 0;
    for (int32_t i = 0; i < n_pairs; i++) {
        wall_point quad[4]; /* q, p, q2, p2 */
        pair_quad(r, pts, pair + 2 * i, quad);
        double dir[3], out[3] = {0.0, 0.0, 1.0}, right[3];
        fs_sub3(dir, quad[0].rest, quad[1].rest);
        if (!r->w->flat)
            memcpy(out, quad[1].rest, sizeof out);
        fs_cross3(right, dir, out); /* from this side's wall into the crack */
        for (int k = 0; k < 2; k++) {
            const wall_point *mine = quad + 1 - k, *other = quad + 2 + k;
            double gap[3];
            fs_sub3(gap, other->moved, mine->moved);
            if (mine->vertex != other->vertex && fs_dot3(gap, right) < 0.0
                && fs_uf_find(r->parent, mine->id) != fs_uf_find(r->parent, other->id)) {
                join(r, mine->id, other->id);
                joined++;
            }
        }
    }
    if (joined > 0)
        apply_joins(r, pts, n_pts, n_ids);

    cross_edge *x = fs_malloc((2 * (size_t)n_pairs + 1) * sizeof *x);
    int32_t n_x = cross_edges(r, pts, pair, n_pairs, x);
    wall_point *loop, poly[JUNCTION_CAP];
    uint8_t cross[JUNCTION_CAP];
    int32_t *edge, *start;
    int32_t n_loops = junction_loops(r, x, n_x, &loop, &edge, &start), joined_loops = 0;
    uint8_t *consumed = fs_calloc((size_t)n_pairs + 1, 1);
    for (int32_t k = 0; k < n_loops; k++) {
        const wall_point *p = loop + start[k];
        int32_t m = start[k + 1] - start[k];
        if (loop_area2(r, p, m) >= 0.0)
            continue;
        int32_t n = junction_polygon(r, pts, pair, x, p, edge + start[k], m, consumed, poly, cross, JUNCTION_CAP);
        if (n >= 3 && clip_ears(r, poly, n, false)) {
            for (int32_t c = 0; c < m; c++)
                consumed[x[edge[start[k] + c]].pair] = 1;
            continue;
        }
        if (m == 3) {
            int longest = 0;
            double best = -1.0;
            for (int c = 0; c < 3; c++) {
                double d[3];
                fs_sub3(d, p[(c + 1) % 3].top, p[c].top);
                if (fs_dot3(d, d) > best) {
                    best = fs_dot3(d, d);
                    longest = c;
                }
            }
            const wall_point *o = p + (longest + 2) % 3, *a = p + longest, *b = p + (longest + 1) % 3;
            double da[3], db[3];
            fs_sub3(da, a->top, o->top);
            fs_sub3(db, b->top, o->top);
            join(r, o->id, (fs_dot3(da, da) <= fs_dot3(db, db) ? a : b)->id);
            joined++;
        } else {
            for (int32_t c = 1; c < m; c++)
                join(r, p[0].id, p[c].id);
            joined += m - 1;
        }
        joined_loops++;
    }
    free(consumed);
    if (joined_loops > 0)
        apply_joins(r, pts, n_pts, n_ids);
    free(loop);
    free(edge);
    free(start);
    free(x);
    return joined;
}

/* design: with fracture by splitting (wedge/split.c) every element stays alive and a crack is a pair
 * of walls, boundary edges of the surface mesh on nodes duplicated at one rest position, which the
 * in-plane displacement of the top nodes opens. The render mesh must partition texture space (the
 * lift of render.h closes steps between neighbouring surfaces), so it holds the fragment tops at
 * their displaced positions and a floor exactly in the gaps between them:
 *  - the two walls of a crack are paired by rest position along the crack line, across periodic
 *    seams: every wall edge is cut at the rest points of the other walls strictly inside it (a crack
 *    that ends on an earlier one mid-edge cuts the wall on its own side only, so one wall edge can
 *    face two on the other side), and the top element fans over the cut points, so that afterwards
 *    each wall sub-edge p -> q has exactly one partner p2 -> q2 running between the same rest
 *    points the other way;
 *  - each pair bounds a quad (q, p, q2, p2) of floor, a triangle at a crack tip where p and q2 are
 *    one node;
 *  - where cracks meet (T-junctions, a crack ending on a wall mid-edge), the quads' edges across
 *    the cracks at one rest point leave a small polygon between the copies of the node, filled too;
 *  - crossings of walls where a crack is pressed shut are resolved first (close_crossings).
 * Texture maps do not change except where walls cross: the floor has the attributes of the exposed
 * background. On the sphere the same mesh is drawn in 3-D and each triangle is refined into the
 * texture by fs_sphere_triangle (geom/sphere_surface.h), which cuts a shared chord at the same points on
 * both sides, so tops and floor still meet vertex to vertex and the lift is closed. A wall edge there
 * is an arc of a great circle, not its chord: the nodes that split an edge lie on the sphere
 * (points_on_edge, edge_param). */
static int split_render_mesh(render_ctx *r)
{
    const fs_wedge_model *w = r->w;
    const fs_mesh *m = w->mesh;
    double *gpos = NULL;
    int32_t n_groups = rest_groups(m, r->group, &gpos);
    r->delta = fs_calloc(3 * (size_t)m->n_nodes + 3, sizeof *r->delta);

    /* walls: boundary edges of living elements off the borders of non-periodic axes */
    int32_t *elem_wall = fs_malloc((3 * (size_t)w->n_elems + 1) * sizeof *elem_wall);
    int32_t n_walls = 0;
    uint8_t *use = fs_calloc((size_t)n_groups + 1, 1);
    for (int32_t e = 0; e < w->n_elems; e++)
        for (int c = 0; c < 3; c++) {
            elem_wall[3 * (size_t)e + c] = -1;
            if (r->label[e] < 0 || m->adj[3 * (size_t)e + c] >= 0)
                continue;
            double a[3], b[3];
            fs_mesh_corner(m, e, c, a);
            fs_mesh_corner(m, e, (c + 1) % 3, b);
            bool border = false;
            for (int q = 0; q < 2 && w->flat; q++)
                for (int s = 0; s < 2 && !r->wrap[q]; s++) {
                    double line = s ? r->ext[q] : 0.0;
                    border = border || (fabs(a[q] - line) <= r->tol && fabs(b[q] - line) <= r->tol);
                }
            if (border)
                continue;
            elem_wall[3 * (size_t)e + c] = n_walls++;
            use[r->group[m->tri[3 * (size_t)e + c]]] = 1;
            use[r->group[m->tri[3 * (size_t)e + (c + 1) % 3]]] = 1;
        }
    group_grid grid;
    grid_build(&grid, r, gpos, use, n_groups);
    free(use);

    /* the points of every wall: its ends and the rest points inside it */
    int32_t *wall_first = fs_malloc(((size_t)n_walls + 1) * sizeof *wall_first);
    int32_t *wall_n = fs_malloc(((size_t)n_walls + 1) * sizeof *wall_n);
    wall_point *pts = NULL;
    int32_t n_pts = 0, cap_pts = 0, inserted = 0;
    on_edge *found = NULL;
    int32_t cap_found = 0;
    for (int32_t e = 0; e < w->n_elems; e++)
        for (int c = 0; c < 3; c++) {
            int32_t wl = elem_wall[3 * (size_t)e + c];
            if (wl < 0)
                continue;
            wall_point a = corner_point(r, e, c), b = corner_point(r, e, (c + 1) % 3);
            int32_t k = points_on_edge(r, &grid, gpos, &a, &b, &found, &cap_found);
            FS_ARRAY_RESERVE(pts, cap_pts, n_pts + k + 2, 64);
            wall_first[wl] = n_pts;
            wall_n[wl] = k + 2;
            pts[n_pts++] = a;
            for (int32_t i = 0; i < k; i++) {
                wall_point x = lerp_point(&a, &b, found[i].t);
                x.id = x.vertex = m->n_nodes + inserted++;
                x.group = found[i].group;
                pts[n_pts++] = x;
            }
            pts[n_pts++] = b;
        }
    free(found);
    free(grid.start);
    free(grid.item);
    int32_t n_ids = m->n_nodes + inserted;
    r->delta = fs_realloc(r->delta, (3 * (size_t)n_ids + 3) * sizeof *r->delta);
    memset(r->delta + 3 * (size_t)m->n_nodes, 0, 3 * (size_t)inserted * sizeof *r->delta);

    /* pair the sub-edges of the walls across their cracks */
    sub_key *keys = fs_malloc(((size_t)n_pts + 1) * sizeof *keys);
    int32_t n_keys = 0;
    for (int32_t wl = 0; wl < n_walls; wl++)
        for (int32_t k = wall_first[wl]; k + 1 < wall_first[wl] + wall_n[wl]; k++) {
            const wall_point *p = pts + k, *q = pts + k + 1;
            int32_t g[2] = {p->group, q->group}, d[2] = {0, 0};
            for (int ax = 0; ax < 2; ax++)
                if (r->wrap[ax]) {
                    double span = (q->rest[ax] - p->rest[ax]) - (gpos[3 * (size_t)g[1] + ax] - gpos[3 * (size_t)g[0] + ax]);
                    d[ax] = (int32_t)lround(span / r->ext[ax]);
                }
            bool forward = g[0] < g[1] || (g[0] == g[1] && (d[0] > 0 || (d[0] == 0 && d[1] > 0)));
            keys[n_keys++] = forward ? (sub_key){{g[0], g[1]}, {d[0], d[1]}, 0, k}
                                     : (sub_key){{g[1], g[0]}, {-d[0], -d[1]}, 1, k};
        }
    qsort(keys, (size_t)n_keys, sizeof *keys, cmp_sub_key);
    int32_t *pair = fs_malloc(((size_t)n_keys + 1) * sizeof *pair); /* 2 per pair: first points */
    int32_t n_pairs = 0, unpaired = 0;
    for (int32_t i = 0; i < n_keys;) {
        int32_t j = i + 1;
        while (j < n_keys && !memcmp(keys[j].g, keys[i].g, sizeof keys[i].g) && !memcmp(keys[j].d, keys[i].d, sizeof keys[i].d))
            j++;
        if (j - i == 2 && keys[i].dir != keys[i + 1].dir) {
            pair[2 * n_pairs] = keys[i].first;
            pair[2 * n_pairs + 1] = keys[i + 1].first;
            n_pairs++;
        } else {
            unpaired += j - i;
        }
        i = j;
    }
    free(keys);

    int32_t joined = close_crossings(r, pts, n_pts, pair, n_pairs, n_ids);
    emit_tops(r, elem_wall, wall_first, wall_n, pts);
    /* the holes where cracks meet; one that comes out turned over is merged with the quads on its
     * sides (close_crossings made sure that those make a simple polygon, or joined its points) */
    cross_edge *x = fs_malloc((2 * (size_t)n_pairs + 1) * sizeof *x);
    int32_t n_x = cross_edges(r, pts, pair, n_pairs, x);
    wall_point *loop, poly[JUNCTION_CAP];
    uint8_t cross[JUNCTION_CAP];
    int32_t *edge, *start;
    int32_t n_loops = junction_loops(r, x, n_x, &loop, &edge, &start), merged = 0;
    uint8_t *consumed = fs_calloc((size_t)n_pairs + 1, 1);
    for (int32_t k = 0; k < n_loops; k++) {
        const wall_point *p = loop + start[k];
        int32_t size = start[k + 1] - start[k], n;
        if (loop_area2(r, p, size) >= 0.0
            || (n = junction_polygon(r, pts, pair, x, p, edge + start[k], size, consumed, poly, cross,
                                     JUNCTION_CAP)) < 3) {
            emit_junction(r, p, NULL, size);
            continue;
        }
        emit_junction(r, poly, cross, n);
        for (int32_t c = 0; c < size; c++)
            consumed[x[edge[start[k] + c]].pair] = 1;
        merged++;
    }
    for (int32_t i = 0; i < n_pairs; i++) {
        if (consumed[i])
            continue;
        wall_point quad[4]; /* q, p, q2, p2 */
        pair_quad(r, pts, pair + 2 * i, quad);
        emit_gap(r, quad);
    }
    free(consumed);
    fs_debug("wedge render: %d crack walls, %d points inserted on them, %d floor quads, %d junctions filled "
             "(%d merged with their quads), %d wall edges unpaired, %d points joined where walls cross",
             (int)n_walls, (int)inserted, (int)n_pairs, (int)n_loops, (int)merged, (int)unpaired, (int)joined);
    free(loop);
    free(edge);
    free(start);
    free(x);
    free(pair);
    free(pts);
    free(wall_first);
    free(wall_n);
    free(elem_wall);
    free(gpos);
    free(r->delta);
    free(r->parent);
    r->delta = NULL;
    r->parent = NULL;
    return 0;
}

int fs_wedge_surface(const fs_wedge_model *w, fs_surface *out)
{
    memset(out, 0, sizeof *out);
    const fs_mesh *m = w->mesh;
    render_ctx r = {.w = w,
                    .out = out,
                    .ext = {fs_domain_extent_x(&m->domain), fs_domain_extent_y(&m->domain)},
                    .wrap = {w->flat && fs_domain_wraps_u(&m->domain), w->flat && fs_domain_wraps_v(&m->domain)}};
    r.sphere = (fs_sphere_refiner){&m->domain, SPHERE_UV_TOLERANCE, out, sphere_vertex, &r};
    r.tol = 1e-9 * fmax(r.ext[0], r.ext[1]);
    r.foot = 0.5 * fmin(fmax(w->cfg.wall_slope, 0.0), 1.0);
    r.label = fs_malloc(((size_t)w->n_elems + 1) * sizeof *r.label);
    fs_wedge_fragments(w, r.label);
    int rc = 0;
    if (w->cfg.fracture.method == FS_FRACTURE_SPLIT) {
        r.group = fs_malloc(((size_t)m->n_nodes + 1) * sizeof *r.group);
        rc = split_render_mesh(&r);
        free(r.group);
    } else {
        /* element removal: the tops of the living elements and the floor of the removed ones, at
         * their rest positions */
        for (int32_t e = 0; e < w->n_elems; e++) {
            double p[3][3];
            attr a[3];
            for (int c = 0; c < 3; c++) {
                fs_mesh_corner(m, e, c, p[c]);
                a[c] = r.label[e] < 0 ? floor_attr : top_attr(&r, e, m->tri[3 * (size_t)e + c]);
            }
            emit_tri(&r, (const double(*)[3])p, a);
        }
    }
    free(r.label);
    return rc;
}
