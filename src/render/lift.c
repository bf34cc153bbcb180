/* Lifting a texture-space render mesh into a welded, oriented 3-D triangle mesh with its steps closed. */
#include "render/render.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/imap.h"
#include "base/log.h"
#include "base/uf.h"
#include "base/vec.h"

/* Positions closer than this fraction of the domain's size are one vertex. The render mesh gives
 * one point the same float texture coordinates in every triangle, except where a model computed it
 * in two periods (u and u + 1 differ by up to an ulp of 1, 1.2e-7); models' smallest features are
 * some 1e-6 of the domain (leg cuts 1e-4 of a cell's radius). */
static const double weld_fraction = 2.5e-7;

/* Corner normals average the triangles within this angle of their own triangle (degrees). */
static const double crease_degrees = 50.0;

static uint64_t pair_key(int32_t a, int32_t b) { return (uint64_t)(uint32_t)a << 32 | (uint32_t)b; }

/* ---- welding points within a tolerance through a hashed grid of cells at least four times the
 * tolerance; an axis may be periodic (its cells and distances wrap) ---- */

typedef struct {
    double cell[3], tol, tol2;
    double period[3];   /* > 0 on a periodic axis */
    long long n_cells[3]; /* cells along a periodic axis */
    fs_imap grid;       /* hashed cell -> newest point in it (others chained through next) */
    int32_t *next;
    double *p;          /* 3 per point */
    int32_t n, cap;
    /* every query so far, by its exact coordinates, and its answer: most queries repeat one
     * exactly, and a repeated query has the same answer (points only ever get added, with higher
     * indices than any earlier answer) */
    fs_imap seen;       /* hash of the bits -> newest query with that hash */
    double *q;          /* 3 per query */
    int32_t *q_answer, *q_next;
    int32_t n_q, cap_q;
} welder;

/* A hash key of three integers: a grid cell's indices, or a corner's three ids. */
static uint64_t triple_key(long long x, long long y, long long z)
{
    return fs_mix64(fs_mix64(fs_mix64((uint64_t)x) ^ (uint64_t)y) ^ (uint64_t)z);
}

/* period may be NULL (no periodic axis). */
static void welder_init(welder *w, double tol, const double *period, size_t expect)
{
    memset(w, 0, sizeof *w);
    w->tol = tol;
    w->tol2 = tol * tol;
    for (int q = 0; q < 3; q++) {
        w->cell[q] = 4.0 * tol;
        w->period[q] = period ? period[q] : 0.0;
        if (w->period[q] > 0.0) {
            w->n_cells[q] = (long long)floor(w->period[q] / (4.0 * tol));
            if (w->n_cells[q] < 1)
                w->n_cells[q] = 1;
            w->cell[q] = w->period[q] / (double)w->n_cells[q];
        }
    }
    fs_imap_init(&w->grid, expect);
    fs_imap_init(&w->seen, expect);
}

static void welder_free(welder *w)
{
    fs_imap_free(&w->grid);
    free(w->next);
    free(w->p);
    fs_imap_free(&w->seen);
    free(w->q);
    free(w->q_answer);
    free(w->q_next);
}

static long long wrap_cell(const welder *w, int q, long long c)
{
    if (w->period[q] <= 0.0)
        return c;
    c %= w->n_cells[q];
    return c < 0 ? c + w->n_cells[q] : c;
}

/* The index of the lowest-numbered point within the tolerance of x, or a new point at x. Cells
 * are at least twice the tolerance, so besides x's own cell only the neighbour across a cell
 * border nearer than the tolerance can hold such a point, along each axis. */
static int32_t weld_search(welder *w, const double *x)
{
    long long c[3];
    int side[3];
    for (int q = 0; q < 3; q++) {
        double f = x[q] / w->cell[q];
        c[q] = (long long)floor(f);
        double off = (f - (double)c[q]) * w->cell[q];
        side[q] = off <= w->tol ? -1 : (off >= w->cell[q] - w->tol ? 1 : 0);
    }
    int32_t best = -1;
    for (int dz = 0; dz <= (side[2] != 0); dz++)
        for (int dy = 0; dy <= (side[1] != 0); dy++)
            for (int dx = 0; dx <= (side[0] != 0); dx++) {
                uint64_t key = triple_key(wrap_cell(w, 0, c[0] + dx * side[0]),
                                          wrap_cell(w, 1, c[1] + dy * side[1]),
                                          wrap_cell(w, 2, c[2] + dz * side[2]));
                const int32_t *head = fs_imap_find(&w->grid, key);
                for (int32_t i = head ? *head : -1; i >= 0; i = w->next[i]) {
                    const double *p = w->p + 3 * (size_t)i;
                    double e2 = 0.0;
                    for (int q = 0; q < 3; q++) {
                        double e = p[q] - x[q];
                        if (w->period[q] > 0.0)
                            e -= w->period[q] * round(e / w->period[q]);
                        e2 += e * e;
                    }
                    if (e2 <= w->tol2 && (best < 0 || i < best))
                        best = i;
                }
            }
    if (best >= 0)
        return best;
    if (FS_ARRAY_GROW(w->cap, w->n + 1, 1024)) {
        FS_ARRAY_RESIZE(w->p, 3 * (size_t)w->cap);
        FS_ARRAY_RESIZE(w->next, w->cap);
    }
    int32_t i = w->n++;
    memcpy(w->p + 3 * (size_t)i, x, 3 * sizeof *x);
    bool found;
    uint64_t key = triple_key(wrap_cell(w, 0, c[0]), wrap_cell(w, 1, c[1]), wrap_cell(w, 2, c[2]));
    int32_t *slot = fs_imap_get(&w->grid, key, i, &found);
    w->next[i] = found ? *slot : -1;
    *slot = i;
    return i;
}

static int32_t weld(welder *w, const double *x)
{
    uint64_t h = 0;
    for (int q = 0; q < 3; q++) {
        uint64_t bits;
        memcpy(&bits, x + q, sizeof bits);
        h = fs_mix64(h ^ bits);
    }
    bool found;
    int32_t *slot = fs_imap_get(&w->seen, h, -1, &found);
    for (int32_t i = *slot; i >= 0; i = w->q_next[i])
        if (!memcmp(w->q + 3 * (size_t)i, x, 3 * sizeof *x))
            return w->q_answer[i];
    int32_t answer = weld_search(w, x);
    if (FS_ARRAY_GROW(w->cap_q, w->n_q + 1, 1024)) {
        FS_ARRAY_RESIZE(w->q, 3 * (size_t)w->cap_q);
        FS_ARRAY_RESIZE(w->q_answer, w->cap_q);
        FS_ARRAY_RESIZE(w->q_next, w->cap_q);
    }
    int32_t i = w->n_q++;
    memcpy(w->q + 3 * (size_t)i, x, 3 * sizeof *x);
    w->q_answer[i] = answer;
    w->q_next[i] = *slot;
    *slot = i;
    return answer;
}

/* ---- exact de-duplication of small float tuples (texture coordinates, normals) ---- */

typedef struct {
    int dim;
    fs_imap table;  /* hash of the bits -> newest tuple with that hash */
    int32_t *next;
    float *v;
    int32_t n, cap;
} dedup;

static void dedup_init(dedup *d, int dim, size_t expect)
{
    memset(d, 0, sizeof *d);
    d->dim = dim;
    fs_imap_init(&d->table, expect);
}

static int32_t dedup_add(dedup *d, const float *x)
{
    uint64_t h = 0;
    for (int q = 0; q < d->dim; q++) {
        uint32_t bits;
        memcpy(&bits, x + q, sizeof bits);
        h = fs_mix64(h ^ bits);
    }
    bool found;
    int32_t *slot = fs_imap_get(&d->table, h, -1, &found);
    for (int32_t i = *slot; i >= 0; i = d->next[i])
        if (!memcmp(d->v + (size_t)d->dim * (size_t)i, x, (size_t)d->dim * sizeof *x))
            return i;
    if (FS_ARRAY_GROW(d->cap, d->n + 1, 1024)) {
        FS_ARRAY_RESIZE(d->v, (size_t)d->dim * (size_t)d->cap);
        FS_ARRAY_RESIZE(d->next, d->cap);
    }
    int32_t i = d->n++;
    memcpy(d->v + (size_t)d->dim * (size_t)i, x, (size_t)d->dim * sizeof *x);
    d->next[i] = *slot;
    *slot = i;
    return i;
}

/* ---- the lift ---- */

/* A point of texture space with its height, and its canonical id: points that are one point of
 * the texture (up to rounding, in any period) share an id, whatever their heights. */
typedef struct {
    double u, v, h;
    int32_t id;
} uvh;

typedef struct {
    int32_t pos[3], uv[3];
    uint8_t wall;
} tri;

/* A point where an edge meets a line of the texture square's grid, as first computed. */
typedef struct {
    double along, t; /* the coordinate along the line, and the parameter from the lower-id end */
    int32_t id;
} cut_point;

typedef struct {
    fs_domain d;
    double scale;
    bool wrap[2];
    double ext[2];       /* extents of the texture square in cm, for the canonical weld */
    welder canon;        /* canonical points: (u ext_x, v ext_y, 0), periodic on wrapping axes */
    fs_imap cut_map[4];  /* (lower id, higher id) of an edge -> its cut by a line of constant u (0, 1)
                          * or v (2, 3); on a wrapping axis every line is one (0 or 2), on another
                          * the lines 0 and 1 differ */
    cut_point *cuts;
    int32_t n_cuts, cap_cuts;
    welder pos, base;
    int32_t *pos_base;   /* per position: its welded base point (height 0) */
    int32_t cap_base;
    dedup uv;
    int32_t *memo_pos, *memo_uv; /* per render-mesh vertex: its weld when drawn unshifted, or -1 */
    tri *t;
    int32_t n_t, cap_t;
} lift_ctx;

static double coord(const uvh *p, int axis) { return axis ? p->v : p->u; }

static int32_t canonical_id(lift_ctx *c, double u, double v)
{
    double x[3] = {u * c->ext[0], v * c->ext[1], 0.0};
    return weld(&c->canon, x);
}

/* design: an edge that crosses a seam is cut there by both of its triangles, which may hold its
 * ends in different periods (u and u + 1 differ in float); computed twice, the two cuts would
 * miss each other by rounding magnified by the edge's slope. So the first computation of the cut of
 * an edge of the texture (named by its ends' canonical ids) is kept and reused, shifted into the
 * caller's period; cut points get canonical ids too, so the second clipping axis cuts the new edges
 * consistently. Edges over the same segment of the texture at different heights (the two sides of
 * a step) share the cut too, with their own heights interpolated, so their cut points stay one
 * above the other and the step is still closed by a wall. Cuts interpolate in texture space, as
 * the renderer does, so the lifted pieces show what the maps show. */
static uvh cut(lift_ctx *c, const uvh *a, const uvh *b, int axis, double line)
{
    if (b->id < a->id || (b->id == a->id && coord(b, axis) < coord(a, axis))) {
        const uvh *t = a;
        a = b;
        b = t;
    }
    double da = coord(a, axis), db = coord(b, axis);
    double t = db != da ? (line - da) / (db - da) : 0.0;
    uvh x = {a->u + t * (b->u - a->u), a->v + t * (b->v - a->v), 0.0, -1};
    double *along = axis ? &x.u : &x.v;
    bool found;
    int map = 2 * axis + (!c->wrap[axis] && line > 0.5);
    int32_t *slot = fs_imap_get(&c->cut_map[map], pair_key(a->id, b->id), c->n_cuts, &found);
    if (!found) {
        FS_ARRAY_RESERVE(c->cuts, c->cap_cuts, c->n_cuts + 1, 256);
        if (axis)
            x.v = line;
        else
            x.u = line;
        x.id = canonical_id(c, x.u, x.v);
        c->cuts[c->n_cuts++] = (cut_point){*along, t, x.id};
    } else {
        const cut_point *k = c->cuts + *slot;
        double shift = c->wrap[1 - axis] ? round(*along - k->along) : 0.0;
        *along = k->along + shift;
        t = k->t;
        x.id = k->id;
    }
    x.h = a->h + t * (b->h - a->h);
    if (axis)
        x.v = line;
    else
        x.u = line;
    return x;
}

/* Sutherland–Hodgman: the part of polygon `in` where sign * (coord - line) >= 0. */
static int clip_half(lift_ctx *c, const uvh *in, int n, int axis, double line, double sign, uvh *out)
{
    int m = 0;
    for (int i = 0; i < n; i++) {
        const uvh *a = in + i, *b = in + (i + 1) % n;
        double da = sign * (coord(a, axis) - line), db = sign * (coord(b, axis) - line);
        if (da >= 0.0)
            out[m++] = *a;
        if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0))
            out[m++] = cut(c, a, b, axis, line);
    }
    return m;
}

static void push_tri(lift_ctx *c, tri t)
{
    FS_ARRAY_RESERVE(c->t, c->cap_t, c->n_t + 1, 1024);
    c->t[c->n_t++] = t;
}

/* Welds the lifted point of (u, v, h) and its texture coordinate. */
static void add_point(lift_ctx *c, const uvh *x, int32_t *pos, int32_t *uv)
{
    double tex[2] = {x->u, x->v}, p[3], base[3], n[3], world[3];
    fs_domain_from_uv(&c->d, tex, p);
    fs_domain_embed(&c->d, p, base);
    fs_domain_normal(&c->d, p, n);
    for (int q = 0; q < 3; q++)
        world[q] = base[q] + x->h * c->scale * n[q];
    int32_t before = c->pos.n;
    *pos = weld(&c->pos, world);
    if (*pos == before) {
        if (c->cap_base < c->pos.cap) {
            c->cap_base = c->pos.cap;
            c->pos_base = fs_realloc(c->pos_base, (size_t)c->cap_base * sizeof *c->pos_base);
        }
        c->pos_base[*pos] = weld(&c->base, base);
    }
    float f[2] = {(float)x->u, (float)x->v};
    *uv = dedup_add(&c->uv, f);
}

/* One clipped, shifted piece: a convex polygon fanned into triangles. */
static void emit_polygon(lift_ctx *c, const uvh *p, int n)
{
    int32_t pos[16], uv[16];
    for (int i = 0; i < n; i++)
        add_point(c, p + i, pos + i, uv + i);
    for (int i = 1; i + 1 < n; i++) {
        int k[3] = {0, i, i + 1};
        if (pos[k[0]] == pos[k[1]] || pos[k[1]] == pos[k[2]] || pos[k[2]] == pos[k[0]])
            continue;
        tri t = {{pos[k[0]], pos[k[1]], pos[k[2]]}, {uv[k[0]], uv[k[1]], uv[k[2]]}, 0};
        push_tri(c, t);
    }
}

/* Clips one render-mesh triangle (vertices src) to [0, 1]^2, shifting the pieces outside back by
 * whole periods on wrapping axes. A triangle inside the square needs no clipping, and its
 * vertices' welds are remembered per render-mesh vertex (most are shared by several triangles). */
static void emit_triangle(lift_ctx *c, uvh *v, const int32_t *src)
{
    bool inside = true;
    for (int i = 0; i < 3; i++)
        inside = inside && v[i].u >= 0.0 && v[i].u <= 1.0 && v[i].v >= 0.0 && v[i].v <= 1.0;
    if (inside) {
        int32_t pos[3], uv[3];
        for (int i = 0; i < 3; i++) {
            if (c->memo_pos[src[i]] < 0)
                add_point(c, v + i, c->memo_pos + src[i], c->memo_uv + src[i]);
            pos[i] = c->memo_pos[src[i]];
            uv[i] = c->memo_uv[src[i]];
        }
        if (pos[0] != pos[1] && pos[1] != pos[2] && pos[2] != pos[0])
            push_tri(c, (tri){{pos[0], pos[1], pos[2]}, {uv[0], uv[1], uv[2]}, 0});
        return;
    }
    int k_lo[2], k_hi[2];
    for (int axis = 0; axis < 2; axis++) {
        double lo = coord(v, axis), hi = lo;
        for (int i = 1; i < 3; i++) {
            lo = fmin(lo, coord(v + i, axis));
            hi = fmax(hi, coord(v + i, axis));
        }
        if (c->wrap[axis]) {
            k_lo[axis] = (int)floor(lo);
            k_hi[axis] = (int)ceil(hi) - 1;
            if (k_hi[axis] < k_lo[axis])
                k_hi[axis] = k_lo[axis];
        } else {
            k_lo[axis] = k_hi[axis] = 0;
        }
    }
    for (int i = 0; i < 3; i++)
        v[i].id = canonical_id(c, v[i].u, v[i].v);
    for (int ku = k_lo[0]; ku <= k_hi[0]; ku++)
        for (int kv = k_lo[1]; kv <= k_hi[1]; kv++) {
            uvh a[16], b[16];
            int n = 3;
            memcpy(a, v, 3 * sizeof *v);
            n = clip_half(c, a, n, 0, (double)ku, 1.0, b);
            n = clip_half(c, b, n, 0, (double)ku + 1.0, -1.0, a);
            n = clip_half(c, a, n, 1, (double)kv, 1.0, b);
            n = clip_half(c, b, n, 1, (double)kv + 1.0, -1.0, a);
            if (n < 3)
                continue;
            for (int i = 0; i < n; i++) {
                a[i].u -= ku;
                a[i].v -= kv;
            }
            emit_polygon(c, a, n);
        }
}

/* An undirected edge and the (at most two recorded) triangles on it. */
typedef struct {
    int32_t a, b;      /* a < b */
    int32_t face[2];
    int8_t side[2];    /* per face: the corner k where the edge runs from corner k to k + 1 */
    int32_t count;
} edge_rec;

typedef struct {
    fs_imap map;
    edge_rec *e;
    int32_t n;
    int32_t *face_edge; /* 3 per triangle: its edges, corner k to k + 1 */
} edge_table;

/* Records every edge of the first n_t triangles (positions as currently oriented). */
static void edges_build(edge_table *et, const tri *t, int32_t n_t)
{
    fs_imap_init(&et->map, 3 * (size_t)n_t / 2 + 16);
    et->e = fs_malloc((3 * (size_t)n_t + 1) * sizeof *et->e);
    et->face_edge = fs_malloc((3 * (size_t)n_t + 1) * sizeof *et->face_edge);
    et->n = 0;
    for (int32_t f = 0; f < n_t; f++)
        for (int k = 0; k < 3; k++) {
            int32_t a = t[f].pos[k], b = t[f].pos[(k + 1) % 3];
            int32_t lo = a < b ? a : b, hi = a < b ? b : a;
            bool found;
            int32_t *slot = fs_imap_get(&et->map, pair_key(lo, hi), et->n, &found);
            if (!found)
                et->e[et->n++] = (edge_rec){lo, hi, {f, -1}, {(int8_t)k, -1}, 0};
            et->face_edge[3 * f + k] = *slot;
            edge_rec *r = et->e + *slot;
            if (r->count < 2) {
                r->face[r->count] = f;
                r->side[r->count] = (int8_t)k;
            }
            r->count++;
        }
}

static void edges_free(edge_table *et)
{
    fs_imap_free(&et->map);
    free(et->e);
    free(et->face_edge);
}

static void flip(tri *t)
{
    int32_t p = t->pos[1], u = t->uv[1];
    t->pos[1] = t->pos[2];
    t->uv[1] = t->uv[2];
    t->pos[2] = p;
    t->uv[2] = u;
}

/* Whether triangle t runs along the edge from position a to position b. */
static bool runs(const tri *t, int32_t a, int32_t b)
{
    for (int k = 0; k < 3; k++)
        if (t->pos[k] == a)
            return t->pos[(k + 1) % 3] == b;
    return false;
}

/* Sorted positions of a triangle, for finding coincident ones. */
typedef struct {
    int32_t p[3];
    int32_t f;
} tri_key;

static int cmp_tri_key(const void *x, const void *y)
{
    const tri_key *a = x, *b = y;
    for (int q = 0; q < 3; q++)
        if (a->p[q] != b->p[q])
            return a->p[q] < b->p[q] ? -1 : 1;
    return a->f < b->f ? -1 : (a->f > b->f);
}

/* design: two cells may each draw the same sliver along their shared edge (a T-junction filler
 * whose three corners lie on the edge), so the lifted mesh can hold coincident triangles, and an
 * edge of four. Coincident triangles cancel in pairs (they bound nothing), leaving one copy of an
 * odd number. Returns how many were removed. */
static int32_t drop_coincident(lift_ctx *c)
{
    tri_key *k = fs_malloc(((size_t)c->n_t + 1) * sizeof *k);
    for (int32_t f = 0; f < c->n_t; f++) {
        int32_t *p = k[f].p;
        memcpy(p, c->t[f].pos, sizeof k[f].p);
        for (int i = 1; i < 3; i++)
            for (int j = i; j > 0 && p[j - 1] > p[j]; j--) {
                int32_t t = p[j];
                p[j] = p[j - 1];
                p[j - 1] = t;
            }
        k[f].f = f;
    }
    qsort(k, (size_t)c->n_t, sizeof *k, cmp_tri_key);
    uint8_t *drop = fs_calloc((size_t)c->n_t + 1, 1);
    int32_t removed = 0;
    for (int32_t i = 0; i < c->n_t;) {
        int32_t j = i + 1;
        while (j < c->n_t && !memcmp(k[j].p, k[i].p, sizeof k[i].p))
            j++;
        for (int32_t q = i; q + 1 < j; q += 2) {
            drop[k[q].f] = drop[k[q + 1].f] = 1;
            removed += 2;
        }
        i = j;
    }
    int32_t n = 0;
    for (int32_t f = 0; f < c->n_t; f++)
        if (!drop[f])
            c->t[n++] = c->t[f];
    c->n_t = n;
    free(k);
    free(drop);
    return removed;
}

/* Twice the signed area of triangle t in texture space. */
static double uv_area2(const lift_ctx *c, const tri *t)
{
    const float *a = c->uv.v + 2 * (size_t)t->uv[0], *b = c->uv.v + 2 * (size_t)t->uv[1];
    const float *d = c->uv.v + 2 * (size_t)t->uv[2];
    return ((double)b[0] - a[0]) * ((double)d[1] - a[1]) - ((double)b[1] - a[1]) * ((double)d[0] - a[0]);
}

/* design: the sign of a triangle's area in texture space says whether it faces outwards, but not
 * reliably for slivers (the texture map is not affine: the sphere's map bends chords, a cylinder's
 * radius varies with height) nor where a model's triangles overlap in texture space (a warped cell
 * that is not star-shaped about its site folds its fan), and walls a model drew have no such area.
 * So orientation is made consistent by topology first: breadth first across two-triangle edges from
 * the first triangle of each connected piece, each neighbour made to run the shared edge the other
 * way; then a piece whose total signed texture area is negative is turned over as a whole. */
static void orient(lift_ctx *c)
{
    edge_table et;
    edges_build(&et, c->t, c->n_t);
    int32_t *queue = fs_malloc(((size_t)c->n_t + 1) * sizeof *queue);
    uint8_t *seen = fs_calloc((size_t)c->n_t + 1, 1);
    for (int32_t first = 0; first < c->n_t; first++) {
        if (seen[first])
            continue;
        int32_t head = 0, tail = 0;
        queue[tail++] = first;
        seen[first] = 1;
        double vote = 0.0;
        while (head < tail) {
            int32_t f = queue[head++];
            vote += uv_area2(c, c->t + f);
            for (int k = 0; k < 3; k++) {
                const edge_rec *r = et.e + et.face_edge[3 * f + k];
                if (r->count != 2)
                    continue;
                int32_t g = r->face[0] == f ? r->face[1] : r->face[0];
                if (seen[g])
                    continue;
                /* the edge must run opposite ways in the two triangles; flipping g keeps its
                 * corner indices of this edge's ends, so later lookups go by position */
                if (runs(c->t + f, r->a, r->b) == runs(c->t + g, r->a, r->b))
                    flip(c->t + g);
                seen[g] = 1;
                queue[tail++] = g;
            }
        }
        if (vote < 0.0)
            for (int32_t i = 0; i < tail; i++)
                flip(c->t + queue[i]);
    }
    edges_free(&et);
    free(queue);
    free(seen);
}

/* A boundary half-edge: positions a -> b as its triangle runs, with their texture vertices. */
typedef struct {
    int32_t a, b, ua, ub;
} half_edge;

/* design: a step in a texture-space height field (say a cell top at the edge of a crack) shows up
 * as two boundary edges over the same segment of the texture, one from each surface, running in
 * opposite directions. Their base points (the positions at height 0) coincide, so pairing boundary
 * half-edges a -> b with c -> d where base(c) = base(b) and base(d) = base(a) finds every step;
 * the quad (b, a, d, c) between them closes it, oriented against both. Segments where more than one
 * boundary runs each way are left open rather than guessed. */
static void close_steps(lift_ctx *c)
{
    edge_table et;
    edges_build(&et, c->t, c->n_t);
    half_edge *h = NULL;
    int32_t n_h = 0;
    for (int32_t i = 0; i < et.n; i++) {
        const edge_rec *r = et.e + i;
        if (r->count != 1)
            continue;
        const tri *f = c->t + r->face[0];
        int k = r->side[0];
        int32_t a = f->pos[k], b = f->pos[(k + 1) % 3];
        if (c->pos_base[a] == c->pos_base[b])
            continue;
        h = fs_realloc(h, (size_t)(n_h + 1) * sizeof *h);
        h[n_h++] = (half_edge){a, b, f->uv[k], f->uv[(k + 1) % 3]};
    }
    edges_free(&et);

    fs_imap by_base;
    fs_imap_init(&by_base, (size_t)n_h);
    int32_t *count = fs_calloc((size_t)n_h + 1, sizeof *count);
    for (int32_t i = 0; i < n_h; i++) {
        bool found;
        int32_t *slot = fs_imap_get(&by_base, pair_key(c->pos_base[h[i].a], c->pos_base[h[i].b]), i, &found);
        count[*slot]++;
    }
    int32_t n_before = c->n_t;
    for (int32_t i = 0; i < n_h; i++) {
        int32_t A = c->pos_base[h[i].a], B = c->pos_base[h[i].b];
        const int32_t *mine = fs_imap_find(&by_base, pair_key(A, B)), *other = fs_imap_find(&by_base, pair_key(B, A));
        if (!other || count[*mine] != 1 || count[*other] != 1 || *other < i)
            continue;
        const half_edge *e = h + i, *p = h + *other;
        /* e = a -> b, p = c -> d with base(c) = base(b), base(d) = base(a) */
        tri w1 = {{e->b, e->a, p->b}, {e->ub, e->ua, p->ub}, 1};
        tri w2 = {{e->b, p->b, p->a}, {e->ub, p->ub, p->ua}, 1};
        if (w1.pos[1] != w1.pos[2])
            push_tri(c, w1);
        if (w2.pos[0] != w2.pos[2])
            push_tri(c, w2);
    }
    fs_debug("lift: %d boundary edges, %d wall triangles added", (int)n_h, (int)(c->n_t - n_before));
    fs_imap_free(&by_base);
    free(count);
    free(h);
}

/* design: where steps of different heights meet at one point of the texture (a crack floor, a bevel
 * edge and the neighbouring fan's slightly higher bevel), the walls' vertical side edges over that
 * point do not match: one wall runs from 0 up to h2 while the others run 0 -> h1 -> h2. Each vertical
 * boundary edge is therefore cut at the heights of the other boundary vertices over the same base
 * point, its triangle fanned from the opposite corner, until no vertical boundary edge has such a
 * vertex inside it. */
static int32_t split_columns(lift_ctx *c)
{
    edge_table et;
    edges_build(&et, c->t, c->n_t);
    fs_imap column;              /* base point -> newest entry of its list */
    fs_imap_init(&column, 64);
    int32_t *col_vertex = NULL, *col_next = NULL, n_col = 0;
    int32_t *edges = NULL, n_edges = 0; /* face * 3 + corner of each vertical boundary edge */
    for (int32_t i = 0; i < et.n; i++) {
        const edge_rec *r = et.e + i;
        if (r->count != 1 || c->pos_base[r->a] != c->pos_base[r->b])
            continue;
        edges = fs_realloc(edges, (size_t)(n_edges + 1) * sizeof *edges);
        edges[n_edges++] = 3 * r->face[0] + r->side[0];
        int32_t ends[2] = {r->a, r->b};
        for (int q = 0; q < 2; q++) {
            bool found;
            int32_t *slot = fs_imap_get(&column, (uint64_t)c->pos_base[ends[q]], -1, &found);
            col_vertex = fs_realloc(col_vertex, (size_t)(n_col + 1) * sizeof *col_vertex);
            col_next = fs_realloc(col_next, (size_t)(n_col + 1) * sizeof *col_next);
            col_vertex[n_col] = ends[q];
            col_next[n_col] = *slot;
            *slot = n_col++;
        }
    }
    edges_free(&et);
    uint8_t *touched = fs_calloc((size_t)c->n_t + 1, 1);
    int32_t splits = 0, n_before = c->n_t;
    for (int32_t i = 0; i < n_edges; i++) {
        int32_t f = edges[i] / 3;
        int k = edges[i] % 3;
        if (touched[f])
            continue;
        tri t = c->t[f];
        int32_t a = t.pos[k], b = t.pos[(k + 1) % 3];
        const double *pa = c->pos.p + 3 * (size_t)a, *pb = c->pos.p + 3 * (size_t)b;
        double ab[3];
        fs_sub3(ab, pb, pa);
        double len2 = fs_dot3(ab, ab);
        int32_t mid[16];
        double at[16];
        int n_mid = 0;
        for (int32_t j = *fs_imap_find(&column, (uint64_t)c->pos_base[a]); j >= 0 && n_mid < 16; j = col_next[j]) {
            int32_t v = col_vertex[j];
            double am[3];
            fs_sub3(am, c->pos.p + 3 * (size_t)v, pa);
            double s = fs_dot3(am, ab) / len2;
            bool seen = v == a || v == b;
            for (int q = 0; q < n_mid && !seen; q++)
                seen = mid[q] == v;
            if (seen || !(s > 1e-9 && s < 1.0 - 1e-9))
                continue;
            int q = n_mid++;
            for (; q > 0 && at[q - 1] > s; q--) {
                at[q] = at[q - 1];
                mid[q] = mid[q - 1];
            }
            at[q] = s;
            mid[q] = v;
        }
        if (n_mid == 0)
            continue;
        touched[f] = 1;
        splits++;
        /* (a, b, x) becomes (a, m1, x), (m1, m2, x), ..., (mk, b, x); the new points share a's
         * texture vertex (they lie over the same point of the texture) */
        int32_t x = t.pos[(k + 2) % 3], ux = t.uv[(k + 2) % 3], ua = t.uv[k], ub = t.uv[(k + 1) % 3];
        for (int q = 0; q <= n_mid; q++) {
            tri piece = t;
            piece.pos[0] = q == 0 ? a : mid[q - 1];
            piece.uv[0] = ua;
            piece.pos[1] = q == n_mid ? b : mid[q];
            piece.uv[1] = q == n_mid ? ub : ua;
            piece.pos[2] = x;
            piece.uv[2] = ux;
            if (q == 0)
                c->t[f] = piece;
            else
                push_tri(c, piece);
        }
    }
    fs_debug("lift: %d vertical boundary edges, %d split into %d triangles", (int)n_edges, (int)splits,
             (int)(c->n_t - n_before + splits));
    fs_imap_free(&column);
    free(col_vertex);
    free(col_next);
    free(edges);
    free(touched);
    return splits;
}

/* The corner of triangle f at position v (FS_ASSERT: there is one). */
static int corner_at(const tri *f, int32_t v)
{
    for (int k = 0; k < 3; k++)
        if (f->pos[k] == v)
            return k;
    FS_ASSERT(!"corner_at: the triangle has no such position");
    return 0;
}

/* One triangle around a non-manifold edge: its angle about the edge and which way it faces. */
typedef struct {
    double angle;
    int32_t face;
    int8_t front_ccw; /* its front side is the counter-clockwise side about the edge */
} fan_entry;

static int cmp_fan(const void *x, const void *y)
{
    const fan_entry *a = x, *b = y;
    if (a->angle != b->angle)
        return a->angle < b->angle ? -1 : 1;
    return a->face < b->face ? -1 : (a->face > b->face);
}

/* design: where two fragments touch only along a line or at a point (wedge elements alive on one
 * diagonal of a node and removed on the other; a springs cell corner touching its neighbour's), the
 * welded surface has edges of four triangles and vertices whose triangles form several fans. Such a
 * mesh is not a manifold, and OBJ readers, normal smoothing and booleans get it wrong. So the
 * triangles around an edge of more than two are sorted by angle about it and each is paired with its
 * neighbour on its back side (the material side: a fragment's two walls at its corner go together,
 * not a wall of each fragment across the air between them); a pair, like the two triangles of an
 * ordinary edge, joins its triangles' corners at the edge's ends. Each position then keeps one
 * copy per group of joined corners around it, the first group the original index, so every edge has
 * at most two triangles and every fragment's surface is a manifold of its own, meeting the others
 * at coinciding positions. An edge whose triangles do not pair up (an odd number, or neighbours that
 * do not face each other) is left as it is. Returns the number of positions added. */
static int32_t split_nonmanifold(lift_ctx *c)
{
    edge_table et;
    edges_build(&et, c->t, c->n_t);
    int32_t n_corner = 3 * c->n_t;
    int32_t *parent = fs_malloc(((size_t)n_corner + 1) * sizeof *parent);
    fs_uf_init(parent, n_corner);
    /* faces of the edges of more than two, as lists */
    int32_t *start = fs_calloc((size_t)et.n + 2, sizeof *start);
    int32_t n_bad = 0;
    for (int32_t f = 0; f < c->n_t; f++)
        for (int k = 0; k < 3; k++) {
            int32_t r = et.face_edge[3 * f + k];
            if (et.e[r].count > 2)
                start[r + 1]++;
        }
    for (int32_t r = 0; r < et.n; r++) {
        n_bad += et.e[r].count > 2;
        start[r + 1] += start[r];
    }
    int32_t *fill = fs_malloc(((size_t)et.n + 1) * sizeof *fill);
    memcpy(fill, start, (size_t)et.n * sizeof *fill);
    int32_t *faces = fs_malloc(((size_t)start[et.n] + 1) * sizeof *faces);
    for (int32_t f = 0; f < c->n_t; f++)
        for (int k = 0; k < 3; k++) {
            int32_t r = et.face_edge[3 * f + k];
            if (et.e[r].count > 2)
                faces[fill[r]++] = f;
        }
    free(fill);
    fan_entry *fan = NULL;
    int32_t cap_fan = 0, unpaired = 0;
    for (int32_t r = 0; r < et.n; r++) {
        const edge_rec *er = et.e + r;
        if (er->count == 2) {
            for (int q = 0; q < 2; q++) {
                int32_t v = q ? er->b : er->a;
                fs_uf_union(parent, 3 * er->face[0] + corner_at(c->t + er->face[0], v),
                         3 * er->face[1] + corner_at(c->t + er->face[1], v));
            }
            continue;
        }
        if (er->count < 3)
            continue;
        int32_t m = start[r + 1] - start[r];
        if (m > cap_fan) {
            cap_fan = m;
            fan = fs_realloc(fan, (size_t)cap_fan * sizeof *fan);
        }
        const double *pa = c->pos.p + 3 * (size_t)er->a, *pb = c->pos.p + 3 * (size_t)er->b;
        double axis[3], u[3], w[3];
        fs_sub3(axis, pb, pa);
        double len = fs_norm3(axis);
        for (int q = 0; q < 3; q++)
            axis[q] /= len;
        /* a unit vector across the axis, then the third of a right-handed frame */
        double pick[3] = {0.0, 0.0, 0.0};
        int least = fabs(axis[0]) <= fabs(axis[1]) && fabs(axis[0]) <= fabs(axis[2]) ? 0
                    : (fabs(axis[1]) <= fabs(axis[2]) ? 1 : 2);
        pick[least] = 1.0;
        fs_cross3(u, axis, pick);
        double len_u = fs_norm3(u);
        for (int q = 0; q < 3; q++)
            u[q] /= len_u;
        fs_cross3(w, axis, u);
        for (int32_t i = 0; i < m; i++) {
            int32_t f = faces[start[r] + i];
            const tri *t = c->t + f;
            int32_t x = t->pos[0] != er->a && t->pos[0] != er->b ? t->pos[0]
                        : (t->pos[1] != er->a && t->pos[1] != er->b ? t->pos[1] : t->pos[2]);
            double d[3], n[3], e1[3], e2[3], turn[3];
            fs_sub3(d, c->pos.p + 3 * (size_t)x, pa);
            fs_sub3(e1, c->pos.p + 3 * (size_t)t->pos[1], c->pos.p + 3 * (size_t)t->pos[0]);
            fs_sub3(e2, c->pos.p + 3 * (size_t)t->pos[2], c->pos.p + 3 * (size_t)t->pos[0]);
            fs_cross3(n, e1, e2);
            fs_cross3(turn, axis, d); /* the counter-clockwise direction about the axis at d */
            fan[i] = (fan_entry){atan2(fs_dot3(d, w), fs_dot3(d, u)), f, (int8_t)(fs_dot3(n, turn) > 0.0)};
        }
        qsort(fan, (size_t)m, sizeof *fan, cmp_fan);
        /* the back side of a triangle facing counter-clockwise is its clockwise neighbour */
        bool ok = m % 2 == 0;
        for (int32_t i = 0; ok && i < m; i++) {
            int32_t j = fan[i].front_ccw ? (i + m - 1) % m : (i + 1) % m;
            int32_t back = fan[j].front_ccw ? (j + m - 1) % m : (j + 1) % m;
            ok = back == i && fan[i].front_ccw != fan[j].front_ccw;
        }
        for (int32_t i = 0; i < m; i++) {
            int32_t j = ok ? (fan[i].front_ccw ? (i + m - 1) % m : (i + 1) % m) : 0;
            for (int q = 0; q < 2; q++) {
                int32_t v = q ? er->b : er->a;
                fs_uf_union(parent, 3 * fan[i].face + corner_at(c->t + fan[i].face, v),
                         3 * fan[j].face + corner_at(c->t + fan[j].face, v));
            }
        }
        unpaired += !ok;
    }
    free(fan);
    free(faces);
    free(start);
    edges_free(&et);

    /* one copy of each position per group of joined corners; the group met first keeps it */
    int32_t *group_pos = fs_malloc(((size_t)n_corner + 1) * sizeof *group_pos); /* per root: its position */
    int32_t *owner = fs_malloc(((size_t)c->pos.n + 1) * sizeof *owner);         /* per position: its first root */
    for (int32_t i = 0; i < c->pos.n; i++)
        owner[i] = -1;
    int32_t added = 0;
    for (int32_t i = 0; i < n_corner; i++) {
        int32_t v = c->t[i / 3].pos[i % 3], root = fs_uf_find(parent, i);
        if (root == i) {
            if (owner[v] < 0) {
                owner[v] = root;
                group_pos[root] = v;
            } else {
                if (FS_ARRAY_GROW(c->pos.cap, c->pos.n + 1, 1024)) {
                    FS_ARRAY_RESIZE(c->pos.p, 3 * (size_t)c->pos.cap);
                    FS_ARRAY_RESIZE(c->pos.next, c->pos.cap);
                }
                memcpy(c->pos.p + 3 * (size_t)c->pos.n, c->pos.p + 3 * (size_t)v, 3 * sizeof *c->pos.p);
                group_pos[root] = c->pos.n++;
                added++;
            }
        }
        c->t[i / 3].pos[i % 3] = group_pos[root];
    }
    if (n_bad > 0 || added > 0)
        fs_debug("lift: %d edges of more than two triangles (%d not paired), %d positions added", (int)n_bad,
                 (int)unpaired, (int)added);
    free(group_pos);
    free(owner);
    free(parent);
    return added;
}

/* Unit normal and the corner angles of triangle f; the normal is zero for a degenerate triangle. */
static void face_geometry(const lift_ctx *c, const tri *f, double *n, double *angle)
{
    const double *p[3];
    for (int k = 0; k < 3; k++)
        p[k] = c->pos.p + 3 * (size_t)f->pos[k];
    double e1[3], e2[3];
    fs_sub3(e1, p[1], p[0]);
    fs_sub3(e2, p[2], p[0]);
    fs_cross3(n, e1, e2);
    double len = fs_norm3(n);
    for (int q = 0; q < 3; q++)
        n[q] = len > 0.0 ? n[q] / len : 0.0;
    for (int k = 0; k < 3; k++) {
        double a[3], b[3];
        fs_sub3(a, p[(k + 1) % 3], p[k]);
        fs_sub3(b, p[(k + 2) % 3], p[k]);
        double la = fs_norm3(a), lb = fs_norm3(b);
        double cs = la > 0.0 && lb > 0.0 ? fs_dot3(a, b) / (la * lb) : 1.0;
        angle[k] = acos(cs > 1.0 ? 1.0 : (cs < -1.0 ? -1.0 : cs));
    }
}

/* Corner normals (see render.h), written into out as the lifted mesh's corners. */
static void build_normals(const lift_ctx *c, fs_lifted_mesh *out)
{
    int32_t n_p = c->pos.n, n_t = c->n_t;
    double *fn = fs_malloc((3 * (size_t)n_t + 1) * sizeof *fn);
    double *fa = fs_malloc((3 * (size_t)n_t + 1) * sizeof *fa);
    int32_t *start = fs_calloc((size_t)n_p + 1, sizeof *start);
    for (int32_t f = 0; f < n_t; f++) {
        face_geometry(c, c->t + f, fn + 3 * (size_t)f, fa + 3 * (size_t)f);
        for (int k = 0; k < 3; k++)
            start[c->t[f].pos[k] + 1]++;
    }
    for (int32_t i = 0; i < n_p; i++)
        start[i + 1] += start[i];
    int32_t *fill = fs_malloc(((size_t)n_p + 1) * sizeof *fill);
    memcpy(fill, start, (size_t)n_p * sizeof *fill);
    int32_t *star = fs_malloc((3 * (size_t)n_t + 1) * sizeof *star); /* face * 3 + corner */
    for (int32_t f = 0; f < n_t; f++)
        for (int k = 0; k < 3; k++)
            star[fill[c->t[f].pos[k]]++] = 3 * f + k;
    free(fill);

    const double crease = cos(crease_degrees * FS_PI / 180.0);
    /* normals are shared only among the corners of one position: each position keeps the list of
     * the normals its corners got so far */
    float *normals = fs_malloc((3 * (size_t)n_t + 1) * 3 * sizeof *normals);
    int32_t n_normals = 0;
    int32_t *first = fs_malloc(((size_t)n_p + 1) * sizeof *first);
    int32_t *next = fs_malloc((3 * (size_t)n_t + 1) * sizeof *next);
    for (int32_t i = 0; i < n_p; i++)
        first[i] = -1;
    for (int32_t f = 0; f < n_t; f++) {
        const double *nf = fn + 3 * (size_t)f;
        bool flat = fs_dot3(nf, nf) > 0.0;
        for (int k = 0; k < 3; k++) {
            int32_t v = c->t[f].pos[k];
            double sum[3] = {0.0, 0.0, 0.0}, all[3] = {0.0, 0.0, 0.0};
            for (int32_t s = start[v]; s < start[v + 1]; s++) {
                int32_t g = star[s] / 3;
                const double *ng = fn + 3 * (size_t)g;
                double w = fa[star[s]];
                for (int q = 0; q < 3; q++)
                    all[q] += w * ng[q];
                if (!flat || fs_dot3(nf, ng) >= crease)
                    for (int q = 0; q < 3; q++)
                        sum[q] += w * ng[q];
            }
            double len = fs_norm3(sum);
            if (!(len > 0.0)) {
                memcpy(sum, all, sizeof sum);
                len = fs_norm3(sum);
            }
            float n[3] = {0.0f, 0.0f, 1.0f};
            if (len > 0.0)
                for (int q = 0; q < 3; q++)
                    n[q] = (float)(sum[q] / len);
            int32_t *corner = out->corner + 9 * (size_t)f + 3 * k;
            corner[0] = v;
            corner[1] = c->t[f].uv[k];
            int32_t id = first[v];
            while (id >= 0 && memcmp(normals + 3 * (size_t)id, n, sizeof n))
                id = next[id];
            if (id < 0) {
                id = n_normals++;
                memcpy(normals + 3 * (size_t)id, n, sizeof n);
                next[id] = first[v];
                first[v] = id;
            }
            corner[2] = id;
        }
    }
    out->n_normal = n_normals;
    out->normal = fs_realloc(normals, (3 * (size_t)n_normals + 1) * sizeof *normals);
    free(first);
    free(next);
    free(fn);
    free(fa);
    free(start);
    free(star);
}

int fs_render_lift(const fs_surface *m, const fs_domain *dom, double height_scale, fs_lifted_mesh *out)
{
    memset(out, 0, sizeof *out);
    lift_ctx c;
    memset(&c, 0, sizeof c);
    c.d = *dom;
    fs_domain_normalize(&c.d);
    c.scale = height_scale;
    c.wrap[0] = fs_domain_wraps_u(&c.d);
    c.wrap[1] = fs_domain_wraps_v(&c.d);
    c.ext[0] = fs_domain_extent_x(&c.d);
    c.ext[1] = fs_domain_extent_y(&c.d);

    double h_lo = 0.0, h_hi = 0.0;
    for (int32_t i = 0; i < m->n_verts; i++) {
        if (!isfinite(m->uv[2 * i]) || !isfinite(m->uv[2 * i + 1]) || !isfinite(m->height[i])) {
            fs_error(FS_ERR_INTERNAL, "lift: render mesh vertex %d has a non-finite position or height", (int)i);
            return -1;
        }
        h_lo = fmin(h_lo, m->height[i]);
        h_hi = fmax(h_hi, m->height[i]);
    }
    double size = fmax(fs_domain_extent_x(&c.d), fs_domain_extent_y(&c.d));
    size = fmax(size, (h_hi - h_lo) * fabs(height_scale));
    double tol = weld_fraction * size;
    double period[3] = {c.wrap[0] ? c.ext[0] : 0.0, c.wrap[1] ? c.ext[1] : 0.0, 0.0};
    welder_init(&c.canon, tol, period, (size_t)m->n_verts);
    for (int k = 0; k < 4; k++)
        fs_imap_init(&c.cut_map[k], 64);
    welder_init(&c.pos, tol, NULL, (size_t)m->n_verts);
    welder_init(&c.base, tol, NULL, (size_t)m->n_verts);
    dedup_init(&c.uv, 2, (size_t)m->n_verts);

    c.memo_pos = fs_malloc(((size_t)m->n_verts + 1) * sizeof *c.memo_pos);
    c.memo_uv = fs_malloc(((size_t)m->n_verts + 1) * sizeof *c.memo_uv);
    for (int32_t i = 0; i < m->n_verts; i++)
        c.memo_pos[i] = c.memo_uv[i] = -1;
    for (int32_t k = 0; k < m->n_tris; k++) {
        uvh v[3];
        for (int i = 0; i < 3; i++) {
            int32_t j = m->tri[3 * k + i];
            v[i] = (uvh){m->uv[2 * j], m->uv[2 * j + 1], m->height[j], -1};
        }
        emit_triangle(&c, v, m->tri + 3 * k);
    }
    int32_t coincident = drop_coincident(&c);
    if (coincident > 0)
        fs_debug("lift: %d coincident triangles removed", (int)coincident);
    orient(&c);
    close_steps(&c);
    for (int pass = 0; pass < 4 && split_columns(&c) > 0; pass++)
        continue;
    split_nonmanifold(&c);

    out->weld_tolerance = tol;
    out->n_uv = c.uv.n;
    out->uv = c.uv.v;
    c.uv.v = NULL;
    out->n_tris = c.n_t;
    out->corner = fs_malloc((9 * (size_t)c.n_t + 1) * sizeof *out->corner);
    out->wall = fs_malloc((size_t)c.n_t + 1);
    for (int32_t f = 0; f < c.n_t; f++)
        out->wall[f] = c.t[f].wall;
    build_normals(&c, out);
    out->n_pos = c.pos.n;
    out->pos = c.pos.p;
    c.pos.p = NULL;

    welder_free(&c.canon);
    for (int k = 0; k < 4; k++)
        fs_imap_free(&c.cut_map[k]);
    free(c.cuts);
    welder_free(&c.pos);
    welder_free(&c.base);
    fs_imap_free(&c.uv.table);
    free(c.uv.next);
    free(c.pos_base);
    free(c.memo_pos);
    free(c.memo_uv);
    free(c.t);
    return 0;
}

int fs_render_solid(const fs_solid *s, fs_lifted_mesh *out)
{
    memset(out, 0, sizeof *out);
    for (int64_t k = 0; k < 3 * (int64_t)s->n_pos; k++)
        if (!isfinite(s->pos[k])) {
            fs_error(FS_ERR_INTERNAL, "lift: solid position %d is not finite", (int)(k / 3));
            return -1;
        }
    lift_ctx c;
    memset(&c, 0, sizeof c);
    c.pos.p = s->pos;
    c.pos.n = s->n_pos;
    c.n_t = s->n_tris;
    c.t = fs_malloc(((size_t)s->n_tris + 1) * sizeof *c.t);
    dedup_init(&c.uv, 2, 3 * (size_t)s->n_tris);
    for (int32_t f = 0; f < s->n_tris; f++)
        for (int k = 0; k < 3; k++) {
            c.t[f].pos[k] = s->tri[3 * (size_t)f + k];
            c.t[f].uv[k] = dedup_add(&c.uv, s->uv + 6 * (size_t)f + 2 * k);
        }
    out->n_tris = s->n_tris;
    out->corner = fs_malloc((9 * (size_t)s->n_tris + 1) * sizeof *out->corner);
    out->wall = fs_malloc((size_t)s->n_tris + 1);
    memcpy(out->wall, s->wall, (size_t)s->n_tris);
    build_normals(&c, out);
    out->n_uv = c.uv.n;
    out->uv = c.uv.v;
    out->n_pos = s->n_pos;
    out->pos = fs_malloc((3 * (size_t)s->n_pos + 1) * sizeof *out->pos);
    memcpy(out->pos, s->pos, 3 * (size_t)s->n_pos * sizeof *out->pos);
    fs_imap_free(&c.uv.table);
    free(c.uv.next);
    free(c.t);
    return 0;
}

void fs_lifted_mesh_free(fs_lifted_mesh *l)
{
    if (!l)
        return;
    free(l->pos);
    free(l->uv);
    free(l->normal);
    free(l->corner);
    free(l->wall);
    memset(l, 0, sizeof *l);
}

int32_t fs_lifted_mesh_boundary(const fs_lifted_mesh *l, int32_t **edges, int32_t *n_bad)
{
    *edges = NULL;
    fs_imap map;
    fs_imap_init(&map, 3 * (size_t)l->n_tris / 2 + 16);
    /* per undirected edge: the directed edge of its first triangle and how many triangles use it */
    int32_t *first = fs_malloc((6 * (size_t)l->n_tris + 2) * sizeof *first);
    int32_t *count = fs_calloc(3 * (size_t)l->n_tris + 1, sizeof *count);
    uint8_t *twice = fs_calloc(3 * (size_t)l->n_tris + 1, 1); /* run the same way by two triangles */
    int32_t n = 0, bad = 0;
    for (int32_t f = 0; f < l->n_tris; f++)
        for (int k = 0; k < 3; k++) {
            int32_t a = l->corner[9 * (size_t)f + 3 * k], b = l->corner[9 * (size_t)f + 3 * ((k + 1) % 3)];
            bool found;
            int32_t *slot = fs_imap_get(&map, pair_key(a < b ? a : b, a < b ? b : a), n, &found);
            if (!found) {
                first[2 * n] = a;
                first[2 * n + 1] = b;
                n++;
            } else if (first[2 * *slot] == a) {
                twice[*slot] = 1;
            }
            count[*slot]++;
        }
    int32_t n_b = 0;
    for (int32_t i = 0; i < n; i++) {
        bad += count[i] > 2 || twice[i];
        n_b += count[i] == 1;
    }
    if (n_bad)
        *n_bad = bad;
    int32_t *e = fs_malloc((2 * (size_t)n_b + 1) * sizeof *e), j = 0;
    for (int32_t i = 0; i < n; i++)
        if (count[i] == 1) {
            e[2 * j] = first[2 * i];
            e[2 * j + 1] = first[2 * i + 1];
            j++;
        }
    *edges = e;
    fs_imap_free(&map);
    free(first);
    free(count);
    free(twice);
    return n_b;
}

int32_t fs_lifted_mesh_vertices(const fs_lifted_mesh *l, int32_t **vert, uint32_t **tris)
{
    fs_imap map;
    fs_imap_init(&map, (size_t)l->n_pos);
    int32_t *v = fs_malloc((9 * (size_t)l->n_tris + 3) * sizeof *v);
    int32_t *next = fs_malloc((3 * (size_t)l->n_tris + 1) * sizeof *next);
    uint32_t *t = fs_malloc((3 * (size_t)l->n_tris + 1) * sizeof *t);
    int32_t n = 0;
    for (size_t k = 0; k < 3 * (size_t)l->n_tris; k++) {
        const int32_t *c = l->corner + 3 * k;
        bool found;
        uint64_t key = triple_key(c[0], c[1], c[2]);
        int32_t *slot = fs_imap_get(&map, key, -1, &found);
        int32_t i = *slot;
        while (i >= 0 && memcmp(v + 3 * (size_t)i, c, 3 * sizeof *c))
            i = next[i];
        if (i < 0) {
            i = n++;
            memcpy(v + 3 * (size_t)i, c, 3 * sizeof *c);
            next[i] = *slot;
            *slot = i;
        }
        t[k] = (uint32_t)i;
    }
    fs_imap_free(&map);
    free(next);
    *vert = v;
    *tris = t;
    return n;
}
