/* The voronoi model (SPEC §5): noise-warped Voronoi cells with cracks and bevels, as a render mesh. */
#include "model/voronoi.h"

#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "field/noise.h"
#include "geom/sphere_surface.h"

/* design: a cell is the polygon of the circumcentres of its node's ring, brought into the node's
 * frame (plane, cylinder) with the corner shifts; an open ring (a node on the convex hull of a
 * non-periodic plane) is closed by the two rays along the outward normals of its boundary edges and
 * a far point on their bisector, and the polygon is clipped to the domain rectangle along the axes
 * that do not wrap. Each Voronoi edge is cut into `subdivisions` pieces, computed from the edge's
 * lexicographically smaller end; then every boundary point and the site are moved by a smooth warp
 * field of position only (periodic with the domain; tangential on the sphere; its normal component
 * fades out towards a non-wrapping border so cells still end exactly on it). The Voronoi vertices
 * move too, so the cracks bend smoothly through them, and the two cells of an edge produce the
 * same polyline.
 *   A cell is a fan of triangles (site, p_k, p_k+1). In a fan triangle the distance to the
 * segment p_k p_k+1 is affine (0 on it, h at the site), so the iso-lines d = crack_width / 2 and
 * d = crack_width / 2 + bevel cut it into a crack band, a bevel band and the top. Each leg (site,
 * p_k) carries the cut points of both fan triangles beside it, and each band is triangulated by
 * zipping its two legs, so the render mesh is conforming: it has no cracks of its own at any
 * resolution. Border segments of a clipped cell continue the distance of the Voronoi segment next
 * to them (zone_polyline).
 *   Sphere: the bands are built on the chords in 3-D and drawn by fs_sphere_triangle
 * (geom/sphere_surface.h), which refines them edge by edge until the equirectangular map is close to
 * affine on each piece, still conforming, and cuts a triangle containing a pole at the pole. */

fs_voronoi_params fs_voronoi_params_default(void)
{
    fs_voronoi_params p = {
        .crack_width = 0.06,
        .bevel = 0.05,
        .depth = 0.3,
        .warp = 0.08,
        .warp_scale = 1.0,
        .subdivisions = 8,
    };
    return p;
}

enum { SEG_BORDER = 0, SEG_CRACK = 1 };
enum { BAND_CRACK = 0, BAND_BEVEL = 1, BAND_TOP = 2 };

/* Sphere refinement: largest uv deviation of a chord's image from the straight line before the
 * chord is halved (geom/sphere_surface.h). */
#define SPHERE_UV_TOLERANCE 2e-4

/* Vertex attributes of the render mesh besides the position. */
typedef struct {
    double height, crack, cell, shade;
} attr;

/* A vertex of one band before emission: position in the node's frame (3-D on the sphere). */
typedef struct {
    double p[3];
    attr a;
} band_vertex;

/* A closed polygon, 3 coordinates per point; label[k] describes the edge from point k to k + 1. */
typedef struct {
    double *p;
    uint8_t *label;
    int n, cap;
} polygon;

/* The distance to the crack over one fan triangle (site, p_k, p_k+1) is affine: d0[0] at p_k,
 * d0[1] at p_k+1 and apex at the site. cut[side][i] is the parameter along leg `side` (0 from p_k,
 * 1 from p_k+1, 0 at the base and 1 at the site) where it reaches crack_width / 2 (i = 0) and
 * crack_width / 2 + bevel (i = 1). */
typedef struct {
    double d0[2], apex;
    double cut[2][2];
} fan_info;

typedef struct {
    const fs_mesh *m;
    const fs_voronoi *vor;
    const fs_voronoi_params *prm;
    fs_surface *out;
    bool sphere;
    double ext[2];         /* extents of the unwrapped rectangle (plane, cylinder) */
    bool wraps[2];         /* the domain is periodic along x / y */
    int noise_period[2];   /* integer noise periods on wrapping axes */
    double noise_scale[2]; /* domain coordinate -> noise lattice coordinate */
    uint64_t warp_seed[3]; /* one noise channel per displacement component */
    double half_width, rim;
    fs_sphere_refiner sphere_refiner; /* sphere: draws the band triangles */
    const band_vertex *sphere_corner[3]; /* the band triangle it draws */
    polygon cell, clipped, line, zoned;
    double *line_apex;     /* per segment of line: distance of the site from its line */
    int *zone_src;         /* per segment of zoned: the segment of line whose distance it uses, or -1 */
    fan_info *fan;         /* per segment of zoned */
    double *leg_cut;       /* 4 per leg: sorted cut points in (0, 1) */
    int *leg_ncut;
    int cap_seg;
    band_vertex *bv;
    int n_bv, cap_bv;
    int *bt;
    int n_bt, cap_bt;
} ctx;

/* ---- small helpers ---- */

static void poly_push(polygon *poly, const double *p, int label)
{
    if (FS_ARRAY_GROW(poly->cap, poly->n + 1, 64)) {
        FS_ARRAY_RESIZE(poly->p, 3 * (size_t)poly->cap);
        FS_ARRAY_RESIZE(poly->label, poly->cap);
    }
    memcpy(poly->p + 3 * (size_t)poly->n, p, 3 * sizeof *p);
    poly->label[poly->n++] = (uint8_t)label;
}

static void poly_free(polygon *poly)
{
    free(poly->p);
    free(poly->label);
}

/* Lexicographic order of points, so that both cells of an edge compute its points from the same end. */
static bool lex_less(const double *a, const double *b)
{
    for (int k = 0; k < 3; k++)
        if (a[k] != b[k])
            return a[k] < b[k];
    return false;
}

/* a + (b - a) wb + (c - a) wc */
static attr attr_bary(attr a, attr b, attr c, double wb, double wc)
{
    attr r = {
        a.height + (b.height - a.height) * wb + (c.height - a.height) * wc,
        a.crack + (b.crack - a.crack) * wb + (c.crack - a.crack) * wc,
        a.cell + (b.cell - a.cell) * wb + (c.cell - a.cell) * wc,
        a.shade + (b.shade - a.shade) * wb + (c.shade - a.shade) * wc,
    };
    return r;
}

static int corner_of(const fs_mesh *m, int32_t t, int32_t node)
{
    for (int c = 0; c < 3; c++)
        if (m->tri[3 * (size_t)t + c] == node)
            return c;
    return 0;
}

static void project_sphere(double radius, double *p)
{
    double r = fs_norm3(p);
    if (r > 0.0)
        for (int k = 0; k < 3; k++)
            p[k] *= radius / r;
}


/* ---- warp ---- */

/* Moves p by the warp field (see the design note). */
static void warp_point(const ctx *c, double *p)
{
    double w = c->prm->warp;
    if (w <= 0.0)
        return;
    if (c->sphere) {
        double s = 1.0 / c->prm->warp_scale, d[3], n[3];
        for (int k = 0; k < 3; k++)
            d[k] = w * fs_noise3(c->warp_seed[k], p[0] * s, p[1] * s, p[2] * s);
        fs_domain_normal(&c->m->domain, p, n);
        double dn = fs_dot3(d, n);
        for (int k = 0; k < 3; k++)
            p[k] += d[k] - dn * n[k];
        project_sphere(c->m->domain.radius, p);
        return;
    }
    double x = p[0] * c->noise_scale[0], y = p[1] * c->noise_scale[1];
    double d[2];
    for (int k = 0; k < 2; k++) {
        d[k] = w * fs_noise2(c->warp_seed[k], x, y, c->noise_period[0], c->noise_period[1]);
        if (!c->wraps[k]) {
            double f = fmin(p[k], c->ext[k] - p[k]) / (2.0 * w);
            d[k] *= f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
        }
    }
    p[0] += d[0];
    p[1] += d[1];
}

/* ---- cell polygons ---- */

/* The unclipped Voronoi polygon of node in its own frame; false if the node has no usable ring. */
static bool cell_polygon(ctx *c, int32_t node)
{
    const fs_mesh *m = c->m;
    polygon *poly = &c->cell;
    poly->n = 0;
    int32_t r0 = m->ring_start[node], r1 = m->ring_start[node + 1];
    if (r1 <= r0)
        return false;
    const double *site = m->pos + 3 * (size_t)node;
    double far = 0.0;
    for (int32_t r = r0; r < r1; r++) {
        int32_t t = m->ring_tri[r];
        const double *cc = c->vor->circumcenter + 3 * (size_t)t;
        double q[3] = {cc[0], cc[1], cc[2]};
        if (!c->sphere) {
            int k = corner_of(m, t, node);
            const int8_t *s = m->shift + 6 * (size_t)t;
            for (int a = 0; a < 2; a++)
                q[a] -= (s[2 * k + a] - s[a]) * c->ext[a] * (c->wraps[a] ? 1.0 : 0.0);
            q[2] = 0.0;
            far = fmax(far, hypot(q[0] - site[0], q[1] - site[1]));
        }
        poly_push(poly, q, SEG_CRACK);
    }
    int32_t tf = m->ring_tri[r0];
    int cf = corner_of(m, tf, node);
    if (c->sphere || m->adj[3 * (size_t)tf + cf] >= 0)
        return poly->n >= 3;

    /* open ring: rays along the outward normals of the two boundary edges, closed far away */
    int32_t tl = m->ring_tri[r1 - 1];
    int cl = corner_of(m, tl, node);
    double n_first[2], n_last[2], bis[2];
    fs_mesh_boundary_normal(m, tf, cf, n_first);
    fs_mesh_boundary_normal(m, tl, (cl + 2) % 3, n_last);
    bis[0] = n_first[0] + n_last[0];
    bis[1] = n_first[1] + n_last[1];
    double len = hypot(bis[0], bis[1]);
    if (len < 1e-9) {
        bis[0] = -n_last[1];
        bis[1] = n_last[0];
    } else {
        bis[0] /= len;
        bis[1] /= len;
    }
    double reach = 4.0 * (c->ext[0] + c->ext[1] + far) + 1.0;
    const double *ql = poly->p + 3 * (size_t)(poly->n - 1);
    double a[3] = {ql[0] + reach * n_last[0], ql[1] + reach * n_last[1], 0.0};
    double b[3] = {site[0] + 2.0 * reach * bis[0], site[1] + 2.0 * reach * bis[1], 0.0};
    double f[3] = {poly->p[0] + reach * n_first[0], poly->p[1] + reach * n_first[1], 0.0};
    poly_push(poly, a, SEG_BORDER);
    poly_push(poly, b, SEG_BORDER);
    poly_push(poly, f, SEG_CRACK);
    return true;
}

/* Sutherland-Hodgman against one side of the rectangle (axis, keep p[axis] >= bound when lower,
 * else <= bound). Parts of edges keep their label; the new edges along the bound are borders.
 * Crossings are computed from the lexicographically smaller end so neighbours agree exactly. */
static void clip_side(const polygon *in, polygon *out, int axis, bool lower, double bound)
{
    out->n = 0;
    for (int k = 0; k < in->n; k++) {
        const double *s = in->p + 3 * (size_t)k, *e = in->p + 3 * (size_t)((k + 1) % in->n);
        bool s_in = lower ? s[axis] >= bound : s[axis] <= bound;
        bool e_in = lower ? e[axis] >= bound : e[axis] <= bound;
        double x[3] = {0.0, 0.0, 0.0};
        if (s_in != e_in) {
            const double *a = lex_less(s, e) ? s : e, *b = a == s ? e : s;
            double t = (bound - a[axis]) / (b[axis] - a[axis]);
            for (int j = 0; j < 3; j++)
                x[j] = a[j] + (b[j] - a[j]) * t;
            x[axis] = bound;
        }
        if (s_in) {
            poly_push(out, s, in->label[k]);
            if (!e_in)
                poly_push(out, x, SEG_BORDER);
        } else if (e_in) {
            poly_push(out, x, in->label[k]);
        }
    }
}

/* Clips c->cell to the rectangle along the non-wrapping axes; returns the polygon to use. */
static polygon *clip_cell(ctx *c)
{
    polygon *cur = &c->cell, *other = &c->clipped;
    if (c->sphere)
        return cur;
    for (int axis = 0; axis < 2; axis++) {
        if (c->wraps[axis])
            continue;
        for (int side = 0; side < 2; side++) {
            clip_side(cur, other, axis, side == 0, side == 0 ? 0.0 : c->ext[axis]);
            polygon *tmp = cur;
            cur = other;
            other = tmp;
        }
    }
    return cur;
}

/* The warped boundary polyline of a cell: Voronoi edges cut into pieces, every point warped. */
static void cell_polyline(ctx *c, const polygon *poly)
{
    polygon *line = &c->line;
    line->n = 0;
    int pieces = c->prm->subdivisions > 1 ? c->prm->subdivisions : 1;
    double radius = c->m->domain.radius;
    for (int k = 0; k < poly->n; k++) {
        const double *s = poly->p + 3 * (size_t)k, *e = poly->p + 3 * (size_t)((k + 1) % poly->n);
        int label = poly->label[k];
        poly_push(line, s, label);
        if (label != SEG_CRACK)
            continue;
        bool swap = lex_less(e, s);
        const double *a = swap ? e : s, *b = swap ? s : e;
        for (int q = 1; q < pieces; q++) {
            double t = (double)(swap ? pieces - q : q) / pieces, x[3];
            for (int j = 0; j < 3; j++)
                x[j] = a[j] + (b[j] - a[j]) * t;
            if (c->sphere)
                project_sphere(radius, x);
            poly_push(line, x, SEG_CRACK);
        }
    }
    for (int k = 0; k < line->n; k++)
        warp_point(c, line->p + 3 * (size_t)k);
}

/* ---- emission ---- */

static int band_vertex_add(ctx *c, const double *p, attr a)
{
    FS_ARRAY_RESERVE(c->bv, c->cap_bv, c->n_bv + 1, 64);
    band_vertex *v = c->bv + c->n_bv;
    memcpy(v->p, p, sizeof v->p);
    v->a = a;
    return c->n_bv++;
}

static void band_tri_add(ctx *c, int a, int b, int d)
{
    FS_ARRAY_RESERVE(c->bt, c->cap_bt, c->n_bt + 3, 192);
    c->bt[c->n_bt++] = a;
    c->bt[c->n_bt++] = b;
    c->bt[c->n_bt++] = d;
}

static void add_vertex(ctx *c, double u, double v, attr a)
{
    fs_surface_add_vertex(c->out, u, v, a.height, a.crack, a.cell, a.shade);
}

/* fs_sphere_refiner.vertex: a vertex with the attributes of the band triangle's corners mixed by w. */
static int32_t sphere_vertex(void *user, double u, double v, const double w[3])
{
    ctx *c = user;
    const band_vertex *const *t = c->sphere_corner;
    attr a = attr_bary(t[0]->a, t[1]->a, t[2]->a, w[1], w[2]);
    return fs_surface_add_vertex(c->out, u, v, a.height, a.crack, a.cell, a.shade);
}

/* Sends the collected band vertices and triangles to the render mesh. */
static void flush_band(ctx *c)
{
    if (c->sphere) {
        for (int k = 0; k < c->n_bt; k += 3) {
            for (int j = 0; j < 3; j++)
                c->sphere_corner[j] = c->bv + c->bt[k + j];
            fs_sphere_triangle(&c->sphere_refiner, c->sphere_corner[0]->p, c->sphere_corner[1]->p,
                               c->sphere_corner[2]->p);
        }
    } else {
        int32_t base = c->out->n_verts;
        for (int k = 0; k < c->n_bv; k++)
            add_vertex(c, c->bv[k].p[0] / c->ext[0], c->bv[k].p[1] / c->ext[1], c->bv[k].a);
        for (int k = 0; k < c->n_bt; k += 3)
            fs_surface_add_tri(c->out, base + c->bt[k], base + c->bt[k + 1], base + c->bt[k + 2]);
    }
    c->n_bv = 0;
    c->n_bt = 0;
}

/* Signed distance of s from the line through a, b (positive on its left, seen from outside on the
 * sphere); 0 for a degenerate segment. */
static double signed_distance(const ctx *c, const double *a, const double *b, const double *s)
{
    double ab[3], as[3], cr[3];
    fs_sub3(ab, b, a);
    fs_sub3(as, s, a);
    double len = fs_norm3(ab);
    if (len == 0.0)
        return 0.0;
    fs_cross3(cr, ab, as);
    if (!c->sphere)
        return cr[2] / len;
    double n[3];
    fs_domain_normal(&c->m->domain, s, n);
    return fs_dot3(cr, n) / len;
}

static void ensure_segments(ctx *c, int n)
{
    if (n <= c->cap_seg)
        return;
    c->cap_seg = n + n / 2 + 16;
    c->line_apex = fs_realloc(c->line_apex, (size_t)c->cap_seg * sizeof *c->line_apex);
    c->zone_src = fs_realloc(c->zone_src, (size_t)c->cap_seg * sizeof *c->zone_src);
    c->fan = fs_realloc(c->fan, (size_t)c->cap_seg * sizeof *c->fan);
    c->leg_cut = fs_realloc(c->leg_cut, 4 * (size_t)c->cap_seg * sizeof *c->leg_cut);
    c->leg_ncut = fs_realloc(c->leg_ncut, (size_t)c->cap_seg * sizeof *c->leg_ncut);
}

/* Point at parameter t on the leg from p to the site (t = 0 at p, 1 at the site). */
static void leg_point(const double *p, const double *site, double t, double *out)
{
    for (int q = 0; q < 3; q++)
        out[q] = t == 0.0 ? p[q] : (t == 1.0 ? site[q] : p[q] + (site[q] - p[q]) * t);
}

/* Cut parameters closer than this are one cut, and cuts this close to either end sit on it: the
 * two fan triangles of a leg then agree on its points even when their own cuts differ by rounding
 * (consecutive pieces of a straight Voronoi edge have the same distance to the site). */
#define CUT_EPS 1e-4

/* Where a raw cut parameter of a band lands on a leg: 0, 1, or the leg cut it was merged into
 * (the largest leg cut not above it). */
static double snap_cut(const double *cut, int ncut, double x)
{
    if (x < CUT_EPS)
        return 0.0;
    if (x > 1.0 - CUT_EPS)
        return 1.0;
    double s = x;
    for (int k = 0; k < ncut && cut[k] <= x; k++)
        s = cut[k];
    return s;
}

/* The points of a band [lo, hi] (already snapped) on one leg: lo, the leg's cuts strictly inside,
 * and hi unless the band is empty on this leg. */
static int band_chain(const double *cut, int ncut, double lo, double hi, double *t)
{
    int n = 0;
    t[n++] = lo;
    for (int k = 0; k < ncut; k++)
        if (cut[k] > lo && cut[k] < hi)
            t[n++] = cut[k];
    if (hi > lo)
        t[n++] = hi;
    return n;
}

static attr band_attr(const ctx *c, int band, double dist, attr top)
{
    if (band == BAND_CRACK) {
        attr a = {0.0, 1.0, 0.0, 0.0};
        return a;
    }
    if (band == BAND_BEVEL && c->prm->bevel > 0.0) {
        double f = (dist - c->half_width) / c->prm->bevel;
        f = f < 0.0 ? 0.0 : (f > 1.0 ? 1.0 : f);
        top.height = c->rim + (c->prm->depth - c->rim) * f;
    }
    return top;
}

/* Parameter along a leg (0 at a base point where the distance is d0, 1 at the site where it is
 * apex) at which the distance reaches level. */
static double cut_param(double level, double d0, double apex)
{
    if (level <= d0)
        return 0.0;
    if (level >= apex)
        return 1.0;
    return (level - d0) / (apex - d0);
}

/* Appends one zoned segment: its start point, label, source segment of c->line and the distance
 * at both of its ends. */
static void zone_push(ctx *c, const double *p, int label, int src, double d_start, double d_end)
{
    polygon *z = &c->zoned;
    poly_push(z, p, label);
    ensure_segments(c, z->n);
    c->zone_src[z->n - 1] = src;
    c->fan[z->n - 1].d0[0] = d_start;
    c->fan[z->n - 1].d0[1] = d_end;
}

/* design: where a cell is clipped, a crack meets the domain border. The border segments of the
 * polyline carry no crack of their own; instead a border segment next to a Voronoi segment
 * continues that segment's distance function, so the crack and bevel run straight into the
 * border at full width. The border segment is cut where that distance reaches crack_width / 2
 * and crack_width / 2 + bevel (and, with Voronoi segments at both ends, where their distances are
 * equal), so each piece's base lies in one band. */
static void zone_polyline(ctx *c, const double *site)
{
    const polygon *in = &c->line;
    int n = in->n;
    ensure_segments(c, n);
    for (int k = 0; k < n; k++)
        c->line_apex[k] = in->label[k] == SEG_CRACK
                              ? signed_distance(c, in->p + 3 * (size_t)k, in->p + 3 * (size_t)((k + 1) % n), site)
                              : 0.0;
    double c1 = c->half_width, c2 = c->half_width + c->prm->bevel;
    c->zoned.n = 0;
    for (int k = 0; k < n; k++) {
        const double *p = in->p + 3 * (size_t)k, *q = in->p + 3 * (size_t)((k + 1) % n);
        if (in->label[k] == SEG_CRACK) {
            zone_push(c, p, SEG_CRACK, k, 0.0, 0.0);
            continue;
        }
        int prev = (k + n - 1) % n, next = (k + 1) % n;
        bool has_prev = in->label[prev] == SEG_CRACK, has_next = in->label[next] == SEG_CRACK;
        double dp = has_prev ? signed_distance(c, in->p + 3 * (size_t)prev, p, q) : 0.0;
        double dn = has_next ? signed_distance(c, q, in->p + 3 * (size_t)((next + 1) % n), p) : 0.0;
        has_prev = has_prev && dp > 0.0;
        has_next = has_next && dn > 0.0;
        double split = has_prev && has_next ? dn / (dp + dn) : (has_prev ? 1.0 : 0.0);
        double s[6];
        int src[6], m = 0;
        s[m] = 0.0;
        src[m++] = has_prev && split > 0.0 ? prev : (has_next ? next : -1);
        if (has_prev) {
            double levels[2] = {c1, c2};
            for (int i = 0; i < 2; i++) {
                double t = levels[i] / dp;
                if (t > s[m - 1] && t < split) {
                    s[m] = t;
                    src[m++] = prev;
                }
            }
        }
        if (has_prev && has_next && split > s[m - 1] && split < 1.0) {
            s[m] = split;
            src[m++] = next;
        }
        if (has_next) {
            double levels[2] = {c2, c1};
            for (int i = 0; i < 2; i++) {
                double t = 1.0 - levels[i] / dn;
                if (t > s[m - 1] && t > split && t < 1.0) {
                    s[m] = t;
                    src[m++] = next;
                }
            }
        }
        for (int i = 0; i < m; i++) {
            double a = s[i], b = i + 1 < m ? s[i + 1] : 1.0, x[3];
            for (int j = 0; j < 3; j++)
                x[j] = a == 0.0 ? p[j] : p[j] + (q[j] - p[j]) * a;
            double da = 0.0, db = 0.0;
            if (src[i] == prev && has_prev) {
                da = a * dp;
                db = b * dp;
            } else if (src[i] == next && has_next) {
                da = (1.0 - a) * dn;
                db = (1.0 - b) * dn;
            }
            zone_push(c, x, SEG_BORDER, src[i], da, db);
        }
    }
}

/* Emits the fan of one cell over its warped polyline c->line around the warped site. */
static void emit_cell(ctx *c, const double *site, attr top)
{
    zone_polyline(c, site);
    const polygon *line = &c->zoned;
    int n = line->n;
    double levels[2] = {c->half_width, c->half_width + c->prm->bevel};
    for (int k = 0; k < n; k++) {
        fan_info *f = c->fan + k;
        int src = c->zone_src[k];
        f->apex = src >= 0 ? c->line_apex[src] : 0.0;
        for (int side = 0; side < 2; side++)
            for (int i = 0; i < 2; i++)
                f->cut[side][i] = src >= 0 ? cut_param(levels[i], f->d0[side], f->apex) : 0.0;
    }
    for (int k = 0; k < n; k++) {
        const double *mine = c->fan[k].cut[0], *prev = c->fan[(k + n - 1) % n].cut[1];
        double cand[4] = {prev[0], prev[1], mine[0], mine[1]};
        for (int i = 1; i < 4; i++)
            for (int j = i; j > 0 && cand[j - 1] > cand[j]; j--) {
                double tmp = cand[j];
                cand[j] = cand[j - 1];
                cand[j - 1] = tmp;
            }
        double *out = c->leg_cut + 4 * (size_t)k;
        int m = 0;
        for (int i = 0; i < 4; i++) {
            double t = cand[i];
            if (t < CUT_EPS || t > 1.0 - CUT_EPS || (m > 0 && t - out[m - 1] < CUT_EPS))
                continue;
            out[m++] = t;
        }
        c->leg_ncut[k] = m;
    }

    for (int k = 0; k < n; k++) {
        int k1 = (k + 1) % n;
        const fan_info *f = c->fan + k;
        const double *base[2] = {line->p + 3 * (size_t)k, line->p + 3 * (size_t)k1};
        const double *cut[2] = {c->leg_cut + 4 * (size_t)k, c->leg_cut + 4 * (size_t)k1};
        int ncut[2] = {c->leg_ncut[k], c->leg_ncut[k1]};
        /* band bounds on both legs, snapped to the legs' cuts; the site is reached on both or neither */
        double bound[2][4];
        for (int side = 0; side < 2; side++) {
            bound[side][0] = 0.0;
            bound[side][1] = snap_cut(cut[side], ncut[side], f->cut[side][0]);
            bound[side][2] = snap_cut(cut[side], ncut[side], f->cut[side][1]);
            bound[side][3] = 1.0;
        }
        for (int i = 1; i < 3; i++)
            if (bound[0][i] == 1.0 || bound[1][i] == 1.0)
                bound[0][i] = bound[1][i] = 1.0;
        for (int band = 0; band < 3; band++) {
            double lo[2] = {bound[0][band], bound[1][band]}, hi[2] = {bound[0][band + 1], bound[1][band + 1]};
            if (!(hi[0] > lo[0]) && !(hi[1] > lo[1]))
                continue;
            double t[2][6];
            int nt[2], idx[2][6];
            bool apex = hi[0] == 1.0;
            for (int side = 0; side < 2; side++) {
                nt[side] = band_chain(cut[side], ncut[side], lo[side], hi[side], t[side]);
                if (apex)
                    nt[side]--;
                for (int i = 0; i < nt[side]; i++) {
                    double p[3], d = f->d0[side] + (f->apex - f->d0[side]) * t[side][i];
                    leg_point(base[side], site, t[side][i], p);
                    idx[side][i] = band_vertex_add(c, p, band_attr(c, band, d, top));
                }
            }
            int i = 0, j = 0;
            while (i < nt[0] - 1 || j < nt[1] - 1) {
                if (j == nt[1] - 1 || (i < nt[0] - 1 && t[0][i + 1] <= t[1][j + 1])) {
                    band_tri_add(c, idx[0][i], idx[1][j], idx[0][i + 1]);
                    i++;
                } else {
                    band_tri_add(c, idx[0][i], idx[1][j], idx[1][j + 1]);
                    j++;
                }
            }
            if (apex) {
                int is = band_vertex_add(c, site, band_attr(c, band, f->apex, top));
                band_tri_add(c, idx[0][nt[0] - 1], idx[1][nt[1] - 1], is);
            }
        }
        flush_band(c);
    }
}

static void ctx_free(ctx *c)
{
    poly_free(&c->cell);
    poly_free(&c->clipped);
    poly_free(&c->line);
    poly_free(&c->zoned);
    free(c->line_apex);
    free(c->zone_src);
    free(c->fan);
    free(c->leg_cut);
    free(c->leg_ncut);
    free(c->bv);
    free(c->bt);
}

static int check_params(const fs_voronoi_params *p)
{
    if (!(p->crack_width >= 0.0) || !(p->bevel >= 0.0) || !(p->depth >= 0.0) || !(p->warp >= 0.0)) {
        fs_error(FS_ERR_DATA, "voronoi: crack_width, bevel, depth and warp must be >= 0");
        return -1;
    }
    if (p->warp > 0.0 && !(p->warp_scale > 0.0)) {
        fs_error(FS_ERR_DATA, "voronoi: warp_scale must be > 0 (got %g)", p->warp_scale);
        return -1;
    }
    if (p->subdivisions < 1) {
        fs_error(FS_ERR_DATA, "voronoi: subdivisions must be >= 1 (got %d)", p->subdivisions);
        return -1;
    }
    return 0;
}

int fs_voronoi_surface(const fs_mesh *m, const fs_voronoi_params *p, uint64_t seed, fs_surface *out)
{
    if (m->n_nodes <= 0 || m->n_tris <= 0) {
        fs_error(FS_ERR_DATA, "voronoi: the mesh has no nodes or triangles");
        return -1;
    }
    if (!m->ring_start || !m->ring_tri || !m->edge || !m->tri_edge || !m->adj) {
        fs_error(FS_ERR_DATA, "voronoi: the mesh lacks adjacency, edges or rings (build them first)");
        return -1;
    }
    if (check_params(p) < 0)
        return -1;
    fs_voronoi vor;
    if (fs_voronoi_build(m, &vor) < 0)
        return -1;

    ctx c;
    memset(&c, 0, sizeof c);
    c.m = m;
    c.vor = &vor;
    c.prm = p;
    c.out = out;
    const fs_domain *d = &m->domain;
    c.sphere = d->type == FS_DOMAIN_SPHERE;
    c.ext[0] = fs_domain_extent_x(d);
    c.ext[1] = fs_domain_extent_y(d);
    c.wraps[0] = !c.sphere && (d->type == FS_DOMAIN_CYLINDER || d->periodic_x);
    c.wraps[1] = !c.sphere && d->periodic_y;
    for (int k = 0; k < 2; k++) {
        if (c.wraps[k] && p->warp > 0.0) {
            double periods = round(c.ext[k] / p->warp_scale);
            c.noise_period[k] = periods < 1.0 ? 1 : (periods > 1e6 ? 1000000 : (int)periods);
            c.noise_scale[k] = c.noise_period[k] / c.ext[k];
        } else {
            c.noise_period[k] = 0;
            c.noise_scale[k] = p->warp > 0.0 ? 1.0 / p->warp_scale : 0.0;
        }
    }
    for (int k = 0; k < 3; k++)
        c.warp_seed[k] = fs_hash3(seed, FS_RNG_NOISE, UINT64_MAX - (uint64_t)k);
    c.half_width = 0.5 * p->crack_width;
    c.rim = p->depth > p->bevel ? p->depth - p->bevel : 0.0;
    c.sphere_refiner = (fs_sphere_refiner){d, SPHERE_UV_TOLERANCE, out, sphere_vertex, &c};

    for (int32_t node = 0; node < m->n_nodes; node++) {
        if (!cell_polygon(&c, node))
            continue;
        const polygon *poly = clip_cell(&c);
        if (poly->n < 3)
            continue;
        cell_polyline(&c, poly);
        double site[3];
        memcpy(site, m->pos + 3 * (size_t)node, sizeof site);
        warp_point(&c, site);
        attr top = {
            p->depth,
            0.0,
            (double)(node % 65535 + 1),
            2.0 * fs_rand01(seed, FS_RNG_CELL_COLOR, (uint64_t)node) - 1.0,
        };
        emit_cell(&c, site, top);
    }
    ctx_free(&c);
    fs_voronoi_free(&vor);
    return 0;
}
