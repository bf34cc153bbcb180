/* Conforming longest-edge bisection (Rivara's LEPP) of triangle meshes with incremental updates. */
#include "geom/refine.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/sort.h"
#include "base/vec.h"

/* State of one fs_refine_bisect call. The mesh arrays hold cap_* entries during the call (see
 * slack_count). */
typedef struct {
    fs_mesh *m;
    double period[2];  /* period along x / y, 0 in a direction that does not wrap */
    bool has_edges;
    bool has_rings;
    int32_t n_nodes0, n_tris0;
    int32_t cap_nodes, cap_tris, cap_edges;

    int32_t *node_parent;      /* 2 per new node */
    int8_t *node_parent_shift; /* 2 per new node */
    int32_t *tri_parent;       /* 1 per new triangle: its pre-call ancestor */

    /* Pre-call slots split during this call: a hash set (open addressing, -1 = empty) for "was it
     * split", and the same slots in the order they were first split. Neither costs O(n_tris). */
    int32_t *split_set;
    int32_t split_cap;         /* power of two, at least twice n_split */
    int32_t *split_list;
    int32_t n_split, cap_split_list;

    int32_t *stack;            /* the longest-edge propagation path being walked */
    int32_t n_stack, cap_stack;
    int32_t n_bisections;
} refiner;

/* ---- half-edges and the order of edges ---- */

/* Image offset (in periods) of corner c of triangle t. */
static void corner_shift(const fs_mesh *m, int32_t t, int c, int *s)
{
    if (m->shift) {
        s[0] = m->shift[6 * (size_t)t + 2 * c];
        s[1] = m->shift[6 * (size_t)t + 2 * c + 1];
    } else {
        s[0] = s[1] = 0;
    }
}

/* Half-edge h = 3 t + i runs from corner i to corner (i + 1) % 3: its nodes and the offset of its
 * end relative to its start. */
typedef struct {
    int32_t from, to;
    int d[2];
} half_edge;

static half_edge half_edge_of(const fs_mesh *m, int32_t h)
{
    int32_t t = h / 3;
    int i = (int)(h % 3), j = (i + 1) % 3;
    half_edge e = {m->tri[h], m->tri[3 * (size_t)t + j], {0, 0}};
    int si[2], sj[2];
    corner_shift(m, t, i, si);
    corner_shift(m, t, j, sj);
    e.d[0] = sj[0] - si[0];
    e.d[1] = sj[1] - si[1];
    return e;
}

/* The half-edge running the other way along the same edge, or -1 on a boundary. The image offsets
 * are compared only when the neighbour holds the same pair of nodes twice (a tiny periodic mesh). */
static int32_t partner(const fs_mesh *m, int32_t h)
{
    int32_t u = m->adj[h];
    if (u < 0)
        return -1;
    int32_t t = h / 3, from = m->tri[h], to = m->tri[3 * t + (h % 3 + 1) % 3];
    const int32_t *v = m->tri + 3 * (size_t)u;
    int32_t found = -1, count = 0;
    for (int j = 0; j < 3; j++)
        if (v[j] == to && v[(j + 1) % 3] == from && m->adj[3 * u + j] == t) {
            found = 3 * u + j;
            count++;
        }
    if (count <= 1)
        return found;
    half_edge e = half_edge_of(m, h);
    for (int j = 0; j < 3; j++) {
        int32_t g = 3 * u + j;
        if (g == h || v[j] != to || m->adj[g] != t)
            continue;
        half_edge f = half_edge_of(m, g);
        if (f.to == e.from && f.d[0] == -e.d[0] && f.d[1] == -e.d[1])
            return g;
    }
    return -1;
}

/* An edge as a key of the strict total order "longer than": squared length, then the node pair,
 * then the image offset. Both triangles sharing an edge compute the same key: the vector is
 * (pos[to] - pos[from]) + offset * period, whose rounding is odd under reversal. */
typedef struct {
    double len2;
    int32_t lo, hi;
    int d[2];
} edge_key;

static edge_key key_of(const fs_mesh *m, const double *period, int32_t h)
{
    half_edge e = half_edge_of(m, h);
    const double *a = m->pos + 3 * (size_t)e.from, *b = m->pos + 3 * (size_t)e.to;
    double v[3];
    for (int k = 0; k < 3; k++)
        v[k] = b[k] - a[k];
    v[0] += e.d[0] * period[0];
    v[1] += e.d[1] * period[1];
    edge_key key = {v[0] * v[0] + v[1] * v[1] + v[2] * v[2], e.from, e.to, {e.d[0], e.d[1]}};
    bool flip = e.from > e.to || (e.from == e.to && (e.d[0] < 0 || (e.d[0] == 0 && e.d[1] < 0)));
    if (flip) {
        key.lo = e.to;
        key.hi = e.from;
        key.d[0] = -e.d[0];
        key.d[1] = -e.d[1];
    }
    return key;
}

static bool key_greater(const edge_key *x, const edge_key *y)
{
    if (x->len2 != y->len2)
        return x->len2 > y->len2;
    if (x->lo != y->lo)
        return x->lo > y->lo;
    if (x->hi != y->hi)
        return x->hi > y->hi;
    if (x->d[0] != y->d[0])
        return x->d[0] > y->d[0];
    return x->d[1] > y->d[1];
}

/* Index (0..2) of the longest edge of t; its squared length in *len2 when not NULL. */
static int longest_edge(const fs_mesh *m, const double *period, int32_t t, double *len2)
{
    edge_key best = key_of(m, period, 3 * t);
    int bi = 0;
    for (int i = 1; i < 3; i++) {
        edge_key k = key_of(m, period, 3 * t + i);
        if (key_greater(&k, &best)) {
            best = k;
            bi = i;
        }
    }
    if (len2)
        *len2 = best.len2;
    return bi;
}

static void periods_of(const fs_mesh *m, double *period)
{
    const fs_domain *d = &m->domain;
    bool wraps_x = d->type == FS_DOMAIN_CYLINDER || (d->type == FS_DOMAIN_PLANE && d->periodic_x);
    bool wraps_y = d->type != FS_DOMAIN_SPHERE && d->periodic_y;
    period[0] = wraps_x ? fs_domain_extent_x(d) : 0.0;
    period[1] = wraps_y ? fs_domain_extent_y(d) : 0.0;
}

double fs_refine_tri_size(const fs_mesh *m, int32_t t)
{
    double period[2], len2;
    periods_of(m, period);
    longest_edge(m, period, t, &len2);
    return sqrt(len2);
}

/* ---- growth of the mesh arrays ---- */

/* design: fs_mesh has no capacity fields, so the mesh arrays are always (re)allocated to a capacity
 * that is a function of their count alone: the count rounded up to a step of 1/8 of its leading
 * power of two (at least 256 entries). A call that stays within the step asks realloc for the size
 * the block already has, which costs nothing, instead of growing and trimming a 100k-entry array on
 * every call; across calls an array is copied about once per 1/8 of growth. realloc is always asked
 * for the size needed, so arrays that someone else sized exactly are safe too. */
static int32_t slack_count(int64_t n)
{
    int64_t p = 1;
    while (p * 2 <= n)
        p *= 2;
    int64_t step = p / 8 > 256 ? p / 8 : 256;
    int64_t c = (n + step - 1) / step * step;
    FS_ASSERT(c <= INT32_MAX / 3);
    return (int32_t)c;
}

/* Room for n_nodes + nodes, n_tris + tris and n_edges + edges entries. */
static void reserve(refiner *r, int32_t nodes, int32_t tris, int32_t edges)
{
    fs_mesh *m = r->m;
    if (m->n_nodes + nodes > r->cap_nodes) {
        r->cap_nodes = slack_count((int64_t)m->n_nodes + nodes);
        m->pos = fs_realloc(m->pos, 3 * (size_t)r->cap_nodes * sizeof *m->pos);
        size_t extra = (size_t)(r->cap_nodes - r->n_nodes0);
        r->node_parent = fs_realloc(r->node_parent, 2 * extra * sizeof *r->node_parent);
        r->node_parent_shift = fs_realloc(r->node_parent_shift, 2 * extra * sizeof *r->node_parent_shift);
    }
    if (m->n_tris + tris > r->cap_tris) {
        r->cap_tris = slack_count((int64_t)m->n_tris + tris);
        size_t cap = (size_t)r->cap_tris;
        m->tri = fs_realloc(m->tri, 3 * cap * sizeof *m->tri);
        m->adj = fs_realloc(m->adj, 3 * cap * sizeof *m->adj);
        if (m->shift)
            m->shift = fs_realloc(m->shift, 6 * cap * sizeof *m->shift);
        if (r->has_edges)
            m->tri_edge = fs_realloc(m->tri_edge, 3 * cap * sizeof *m->tri_edge);
        r->tri_parent = fs_realloc(r->tri_parent, (cap - (size_t)r->n_tris0) * sizeof *r->tri_parent);
    }
    if (r->has_edges && m->n_edges + edges > r->cap_edges) {
        r->cap_edges = slack_count((int64_t)m->n_edges + edges);
        m->edge = fs_realloc(m->edge, 2 * (size_t)r->cap_edges * sizeof *m->edge);
        m->edge_tri = fs_realloc(m->edge_tri, 2 * (size_t)r->cap_edges * sizeof *m->edge_tri);
    }
}

/* ---- the set of split pre-call slots ---- */

static uint32_t slot_hash(int32_t t, int32_t cap) { return ((uint32_t)t * 2654435761u) & (uint32_t)(cap - 1); }

static bool was_split(const refiner *r, int32_t t)
{
    for (uint32_t h = slot_hash(t, r->split_cap);; h = (h + 1) & (uint32_t)(r->split_cap - 1)) {
        if (r->split_set[h] == t)
            return true;
        if (r->split_set[h] < 0)
            return false;
    }
}

static void set_insert(int32_t *set, int32_t cap, int32_t t)
{
    uint32_t h = slot_hash(t, cap);
    while (set[h] >= 0 && set[h] != t)
        h = (h + 1) & (uint32_t)(cap - 1);
    set[h] = t;
}

static void add_split(refiner *r, int32_t t)
{
    if (was_split(r, t))
        return;
    if (2 * (r->n_split + 1) > r->split_cap) {
        int32_t cap = 2 * r->split_cap;
        int32_t *set = fs_malloc((size_t)cap * sizeof *set);
        for (int32_t q = 0; q < cap; q++)
            set[q] = -1;
        for (int32_t q = 0; q < r->n_split; q++)
            set_insert(set, cap, r->split_list[q]);
        free(r->split_set);
        r->split_set = set;
        r->split_cap = cap;
    }
    set_insert(r->split_set, r->split_cap, t);
    FS_ARRAY_RESERVE(r->split_list, r->cap_split_list, r->n_split + 1, 64);
    r->split_list[r->n_split++] = t;
}

/* ---- one split ---- */

/* The pre-call triangle that slot s descends from. */
static int32_t ancestor(const refiner *r, int32_t s) { return s < r->n_tris0 ? s : r->tri_parent[s - r->n_tris0]; }

/* Writes triangle t = (n0, n1, n2) with corner shifts s0, s1, s2 moved so corner 0 is at (0, 0). */
static void set_tri(fs_mesh *m, int32_t t, int32_t n0, int32_t n1, int32_t n2, const int *s0, const int *s1,
                    const int *s2)
{
    int32_t *v = m->tri + 3 * (size_t)t;
    v[0] = n0;
    v[1] = n1;
    v[2] = n2;
    if (m->shift) {
        int8_t *s = m->shift + 6 * (size_t)t;
        s[0] = 0;
        s[1] = 0;
        s[2] = (int8_t)(s1[0] - s0[0]);
        s[3] = (int8_t)(s1[1] - s0[1]);
        s[4] = (int8_t)(s2[0] - s0[0]);
        s[5] = (int8_t)(s2[1] - s0[1]);
    }
}

static void set_adj(fs_mesh *m, int32_t t, int32_t a0, int32_t a1, int32_t a2)
{
    m->adj[3 * (size_t)t] = a0;
    m->adj[3 * (size_t)t + 1] = a1;
    m->adj[3 * (size_t)t + 2] = a2;
}

static void set_edge(fs_mesh *m, int32_t e, int32_t p, int32_t q, int32_t t0, int32_t t1)
{
    m->edge[2 * (size_t)e] = p < q ? p : q;
    m->edge[2 * (size_t)e + 1] = p < q ? q : p;
    m->edge_tri[2 * (size_t)e] = t0;
    m->edge_tri[2 * (size_t)e + 1] = t1;
}

static void replace_edge_tri(fs_mesh *m, int32_t e, int32_t from, int32_t to)
{
    int32_t *et = m->edge_tri + 2 * (size_t)e;
    if (et[0] == from)
        et[0] = to;
    else if (et[1] == from)
        et[1] = to;
}

static void set_tri_edge(fs_mesh *m, int32_t t, int32_t e0, int32_t e1, int32_t e2)
{
    m->tri_edge[3 * (size_t)t] = e0;
    m->tri_edge[3 * (size_t)t + 1] = e1;
    m->tri_edge[3 * (size_t)t + 2] = e2;
}

static void mark_split(refiner *r, int32_t t)
{
    if (t < r->n_tris0)
        add_split(r, t);
    r->n_bisections++;
}

/* design: splits edge i of t (and edge iu of its neighbour u, or u = -1 on a boundary) at its
 * midpoint m. With t = (a, b, c) from corner i and u = (b, a, d) from corner iu:
 *   slot t  <- (a, m, c)    new tb <- (m, b, c)
 *   slot u  <- (b, m, d)    new ub <- (m, a, d)
 * so only the outer neighbours across b-c and a-d need their adjacency pointed at new triangles.
 * The midpoint is taken in the frame where a has offset 0 and wrapped: m sits at offset w there,
 * hence at (offset of a) + w in every triangle's frame. Edge a-b keeps its index for a-m. */
static void split_edge(refiner *r, int32_t t, int i, int32_t u, int iu)
{
    reserve(r, 1, 2, 3);
    fs_mesh *m = r->m;
    int j = (i + 1) % 3, k = (i + 2) % 3;
    int32_t a = m->tri[3 * t + i], b = m->tri[3 * t + j], c = m->tri[3 * t + k];
    int sa[2], sb[2], sc[2];
    corner_shift(m, t, i, sa);
    corner_shift(m, t, j, sb);
    corner_shift(m, t, k, sc);
    int d[2] = {sb[0] - sa[0], sb[1] - sa[1]};

    const double *pa = m->pos + 3 * (size_t)a, *pb = m->pos + 3 * (size_t)b;
    double mid[3], wrapped[3];
    int w[2] = {0, 0};
    for (int q = 0; q < 3; q++)
        mid[q] = 0.5 * (pa[q] + pb[q]);
    mid[0] += 0.5 * d[0] * r->period[0];
    mid[1] += 0.5 * d[1] * r->period[1];
    memcpy(wrapped, mid, sizeof mid);
    fs_domain_wrap(&m->domain, wrapped);
    for (int q = 0; q < 2; q++)
        if (r->period[q] > 0.0)
            w[q] = (int)lround((mid[q] - wrapped[q]) / r->period[q]);

    int32_t nm = m->n_nodes++;
    memcpy(m->pos + 3 * (size_t)nm, wrapped, sizeof wrapped);
    int32_t ni = nm - r->n_nodes0;
    r->node_parent[2 * ni] = a;
    r->node_parent[2 * ni + 1] = b;
    r->node_parent_shift[2 * ni] = (int8_t)d[0];
    r->node_parent_shift[2 * ni + 1] = (int8_t)d[1];

    int32_t nt_j = m->adj[3 * t + j], nt_k = m->adj[3 * t + k];
    int32_t pt_j = partner(m, 3 * t + j);
    int32_t tb = m->n_tris++;
    r->tri_parent[tb - r->n_tris0] = ancestor(r, t);
    int sm_t[2] = {sa[0] + w[0], sa[1] + w[1]};

    int32_t ju = 0, ku = 0, du = -1, nu_j = -1, nu_k = -1, pu_j = -1, ub = -1;
    int su_b[2] = {0, 0}, su_a[2] = {0, 0}, su_d[2] = {0, 0};
    if (u >= 0) {
        ju = (iu + 1) % 3;
        ku = (iu + 2) % 3;
        du = m->tri[3 * u + ku];
        corner_shift(m, u, iu, su_b);
        corner_shift(m, u, ju, su_a);
        corner_shift(m, u, ku, su_d);
        nu_j = m->adj[3 * u + ju];
        nu_k = m->adj[3 * u + ku];
        pu_j = partner(m, 3 * u + ju);
        ub = m->n_tris++;
        r->tri_parent[ub - r->n_tris0] = ancestor(r, u);
    }

    int32_t e_ab = 0, e_bc = 0, e_ca = 0, e_ad = 0, e_db = 0;
    if (r->has_edges) {
        e_ab = m->tri_edge[3 * t + i];
        e_bc = m->tri_edge[3 * t + j];
        e_ca = m->tri_edge[3 * t + k];
        if (u >= 0) {
            e_ad = m->tri_edge[3 * u + ju];
            e_db = m->tri_edge[3 * u + ku];
        }
    }

    set_tri(m, t, a, nm, c, sa, sm_t, sc);
    set_tri(m, tb, nm, b, c, sm_t, sb, sc);
    set_adj(m, t, ub, tb, nt_k);
    set_adj(m, tb, u, nt_j, t);
    if (pt_j >= 0)
        m->adj[pt_j] = tb;
    mark_split(r, t);
    if (u >= 0) {
        int sm_u[2] = {su_a[0] + w[0], su_a[1] + w[1]};
        set_tri(m, u, b, nm, du, su_b, sm_u, su_d);
        set_tri(m, ub, nm, a, du, sm_u, su_a, su_d);
        set_adj(m, u, tb, ub, nu_k);
        set_adj(m, ub, t, nu_j, u);
        if (pu_j >= 0)
            m->adj[pu_j] = ub;
        mark_split(r, u);
    }

    if (r->has_edges) {
        int32_t e_mb = m->n_edges++, e_mc = m->n_edges++;
        set_edge(m, e_ab, a, nm, t, ub);
        set_edge(m, e_mb, nm, b, tb, u);
        set_edge(m, e_mc, nm, c, t, tb);
        replace_edge_tri(m, e_bc, t, tb);
        set_tri_edge(m, t, e_ab, e_mc, e_ca);
        set_tri_edge(m, tb, e_mb, e_bc, e_mc);
        if (u >= 0) {
            int32_t e_md = m->n_edges++;
            set_edge(m, e_md, nm, du, u, ub);
            replace_edge_tri(m, e_ad, u, ub);
            set_tri_edge(m, u, e_mb, e_md, e_db);
            set_tri_edge(m, ub, e_ab, e_ad, e_md);
        }
    }
}

/* ---- the propagation path ---- */

static void push(refiner *r, int32_t t)
{
    FS_ARRAY_RESERVE(r->stack, r->cap_stack, r->n_stack + 1, 64);
    r->stack[r->n_stack++] = t;
}

/* Whether t and its neighbour u (-1: none) across edge i share only that edge, as split_edge
 * assumes. Two triangles sharing two edges occur only on periodic meshes of a handful of nodes. */
static bool single_shared_edge(const fs_mesh *m, int32_t t, int i, int32_t u)
{
    if (u == t)
        return false;
    for (int q = 1; q < 3; q++) {
        int32_t x = m->adj[3 * t + (i + q) % 3];
        if (x == t || (u >= 0 && x == u))
            return false;
    }
    if (u >= 0)
        for (int q = 0; q < 3; q++) {
            int32_t x = m->adj[3 * u + q];
            if (x == u)
                return false;
        }
    return true;
}

/* Bisects t0 (Algorithm 9 as a longest-edge propagation path; see refine.h). The path is strictly
 * increasing in the edge order, so it cannot cycle, and t_{k+1} of a terminal pair is never on the
 * stack: only the top is ever split. Returns -1 with fs_error for a mesh too coarse to split. */
static int refine_one(refiner *r, int32_t t0)
{
    fs_mesh *m = r->m;
    r->n_stack = 0;
    push(r, t0);
    while (r->n_stack > 0) {
        int32_t t = r->stack[r->n_stack - 1];
        int i = longest_edge(m, r->period, t, NULL);
        int32_t h = 3 * t + i, u = m->adj[h], g = u >= 0 ? partner(m, h) : -1;
        if (!single_shared_edge(m, t, i, u) || (u >= 0 && g < 0)) {
            fs_error(FS_ERR_DATA,
                     "refine: triangles %d and %d share more than one edge or disagree on their adjacency "
                     "(a periodic mesh too coarse to refine, or a broken mesh)",
                     (int)t, (int)u);
            return -1;
        }
        if (u < 0) {
            split_edge(r, t, i, -1, 0);
            r->n_stack--;
            continue;
        }
        int iu = (int)(g % 3);
        if (longest_edge(m, r->period, u, NULL) == iu) {
            split_edge(r, t, i, u, iu);
            r->n_stack--;
        } else {
            push(r, u);
        }
    }
    return 0;
}

/* ---- rings ---- */

/* The corner of the same node in the next triangle clockwise / counter-clockwise, or -1 at a
 * boundary (corner k = 3 t + c; the edge clockwise of it is half-edge k, the one counter-clockwise
 * is half-edge 3 t + (c + 2) % 3). */
static int32_t corner_cw(const fs_mesh *m, int32_t k)
{
    int32_t g = partner(m, k);
    return g < 0 ? -1 : 3 * (g / 3) + (g % 3 + 1) % 3;
}

static int32_t corner_ccw(const fs_mesh *m, int32_t k) { return partner(m, 3 * (k / 3) + (k % 3 + 2) % 3); }

/* Reverses v[lo .. hi - 1]; three reversals rotate an array in place. */
static void reverse(int32_t *v, int32_t lo, int32_t hi)
{
    for (hi--; lo < hi; lo++, hi--) {
        int32_t x = v[lo];
        v[lo] = v[hi];
        v[hi] = x;
    }
}

/* Appends the ring of the node at corner k0 (triangle indices) to *buf, ordered as
 * fs_mesh_build_rings orders a single fan: from the boundary corner of an open fan, from the lowest
 * corner of a closed one. Returns its length, or -1 if the walk does not close within limit steps. */
static int32_t walk_ring(const fs_mesh *m, int32_t k0, int32_t limit, int32_t **buf, int32_t *n, int32_t *cap)
{
    int32_t start = k0, steps = 0;
    bool closed = false;
    for (;;) {
        int32_t nk = corner_cw(m, start);
        if (nk < 0)
            break;
        if (nk == k0) {
            closed = true;
            break;
        }
        start = nk;
        if (++steps > limit)
            return -1;
    }
    int32_t begin = *n, count = 0, k = start, lowest = 0;
    do {
        FS_ARRAY_RESERVE(*buf, *cap, *n + 1, 64);
        if (count == 0 || k < (*buf)[begin + lowest])
            lowest = count;
        (*buf)[(*n)++] = k;
        if (++count > limit)
            return -1;
        k = corner_ccw(m, k);
    } while (k >= 0 && k != start);
    int32_t *v = *buf + begin;
    if (closed && lowest > 0) {
        reverse(v, 0, lowest);
        reverse(v, lowest, count);
        reverse(v, 0, count);
    }
    for (int32_t q = 0; q < count; q++)
        v[q] /= 3;
    return count;
}

/* One node whose ring is rewritten: a corner of it to walk from, and where its ring goes. */
typedef struct {
    int32_t node, corner;
    int32_t old_begin, old_end; /* its ring in the old arrays (empty for a new node) */
    int32_t at, deg;            /* its new ring in the walk buffer */
    int64_t shift_after;        /* how far the rings of the untouched nodes after it move */
} ring_fix;

/* design: only the nodes at the corners of changed or new triangles can have a different ring; they
 * are walked anew through the adjacency. Degrees never decrease under bisection, so the rings of the
 * untouched nodes only move towards the end of the arrays, run by run between touched nodes: they
 * are moved in place from the last run to the first (memmove), and ring_start is offset likewise.
 * A node whose corners form several fans (pinched, never produced by fs_delaunay) would be
 * under-counted by the walk: the degree sum then disagrees with 3 n_tris and the rings are rebuilt
 * from scratch. Returns false if it fell back to the rebuild. */
static bool update_rings(refiner *r)
{
    fs_mesh *m = r->m;
    int32_t nn = m->n_nodes, nt = m->n_tris, old_total = m->ring_start[r->n_nodes0];
    int32_t n_touch = r->n_split + (nt - r->n_tris0);
    uint8_t *mark = fs_calloc((size_t)nn, 1);
    int32_t *anchor = fs_malloc((size_t)nn * sizeof *anchor); /* read only where marked */
    int32_t nu = 0;
    for (int32_t q = 0; q < n_touch; q++) {
        int32_t t = q < r->n_split ? r->split_list[q] : r->n_tris0 + (q - r->n_split);
        for (int c = 0; c < 3; c++) {
            int32_t v = m->tri[3 * t + c];
            if (!mark[v]) {
                mark[v] = 1;
                anchor[v] = 3 * t + c;
                nu++;
            }
        }
    }
    ring_fix *fix = fs_malloc((size_t)(nu ? nu : 1) * sizeof *fix);
    nu = 0;
    for (int32_t v = 0; v < nn; v++)
        if (mark[v]) {
            fix[nu].node = v;
            fix[nu].corner = anchor[v];
            nu++;
        }
    free(mark);
    free(anchor);

    int32_t *buf = NULL, n_buf = 0, cap_buf = 0;
    int64_t total = old_total, shift = 0;
    bool ok = nu >= nn - r->n_nodes0;
    for (int32_t q = 0; q < nu && ok; q++) {
        ring_fix *f = fix + q;
        bool old = f->node < r->n_nodes0;
        f->old_begin = old ? m->ring_start[f->node] : old_total;
        f->old_end = old ? m->ring_start[f->node + 1] : old_total;
        f->at = n_buf;
        f->deg = walk_ring(m, f->corner, 3 * nt, &buf, &n_buf, &cap_buf);
        ok = f->deg >= 0 && f->deg >= f->old_end - f->old_begin;
        shift += f->deg - (f->old_end - f->old_begin);
        f->shift_after = shift;
        total += f->deg - (f->old_end - f->old_begin);
    }
    if (!ok || total != 3 * (int64_t)nt) {
        free(fix);
        free(buf);
        fs_mesh_build_rings(m);
        return false;
    }
    m->ring_start = fs_realloc(m->ring_start, (size_t)slack_count((int64_t)nn + 1) * sizeof *m->ring_start);
    m->ring_tri = fs_realloc(m->ring_tri, 3 * (size_t)slack_count(nt) * sizeof *m->ring_tri);
    int32_t *start = m->ring_start, *ring = m->ring_tri;
    for (int32_t q = nu - 1; q >= 0; q--) {
        const ring_fix *f = fix + q;
        /* the untouched old nodes after f, up to the next touched node */
        int32_t run_end_node = q + 1 < nu && fix[q + 1].node < r->n_nodes0 ? fix[q + 1].node : r->n_nodes0;
        int32_t run_end = q + 1 < nu ? fix[q + 1].old_begin : old_total;
        if (f->node + 1 < run_end_node) {
            int32_t from = f->old_end;
            memmove(ring + from + f->shift_after, ring + from, (size_t)(run_end - from) * sizeof *ring);
            for (int32_t x = f->node + 1; x < run_end_node; x++)
                start[x] += (int32_t)f->shift_after;
        }
        int32_t at = (int32_t)(f->old_begin + f->shift_after - (f->deg - (f->old_end - f->old_begin)));
        start[f->node] = at;
        memcpy(ring + at, buf + f->at, (size_t)f->deg * sizeof *ring);
    }
    start[nn] = 3 * nt;
    free(fix);
    free(buf);
    return true;
}

/* ---- the call ---- */

static int validate(const fs_mesh *m, const int32_t *tris, int32_t n_tris, double min_size)
{
    if (!m->adj) {
        fs_error(FS_ERR_INTERNAL, "refine: the mesh has no adjacency (call fs_mesh_build_adjacency first)");
        return -1;
    }
    if (!(min_size >= 0.0) || !isfinite(min_size)) {
        fs_error(FS_ERR_INTERNAL, "refine: min_size %g must be finite and >= 0", min_size);
        return -1;
    }
    if (n_tris < 0 || (n_tris > 0 && !tris)) {
        fs_error(FS_ERR_INTERNAL, "refine: bad triangle list (%d entries)", (int)n_tris);
        return -1;
    }
    for (int32_t q = 0; q < n_tris; q++)
        if (tris[q] < 0 || tris[q] >= m->n_tris) {
            fs_error(FS_ERR_INTERNAL, "refine: listed triangle %d (entry %d) is not in the mesh of %d triangles",
                     (int)tris[q], (int)q, (int)m->n_tris);
            return -1;
        }
    return 0;
}

void fs_refine_change_free(fs_refine_change *change)
{
    free(change->node_parent);
    free(change->node_parent_shift);
    free(change->tri_parent);
    free(change->changed_tri);
    memset(change, 0, sizeof *change);
}

static void *trimmed(void *p, size_t n, size_t size) { return fs_realloc(p, (n ? n : 1) * size); }

int fs_refine_bisect(fs_mesh *m, const int32_t *tris, int32_t n_tris, double min_size, fs_refine_change *change)
{
    if (validate(m, tris, n_tris, min_size) != 0)
        return -1;
    refiner r;
    memset(&r, 0, sizeof r);
    r.m = m;
    periods_of(m, r.period);
    r.has_edges = m->tri_edge && m->edge && m->edge_tri;
    r.has_rings = m->ring_start && m->ring_tri;
    r.n_nodes0 = r.cap_nodes = m->n_nodes;
    r.n_tris0 = r.cap_tris = m->n_tris;
    r.cap_edges = m->n_edges;
    r.split_cap = 64;
    r.split_set = fs_malloc((size_t)r.split_cap * sizeof *r.split_set);
    for (int32_t q = 0; q < r.split_cap; q++)
        r.split_set[q] = -1;

    /* on Delaunay meshes a bisection propagates to about two split edges on average */
    int32_t guess = n_tris < (INT32_MAX / 3 - 64) / 8 ? n_tris : (INT32_MAX / 3 - 64) / 8;
    int rc = 0;
    int32_t skipped = 0;
    bool rings_rebuilt = false;
    for (int32_t q = 0; q < n_tris && rc == 0; q++) {
        int32_t t = tris[q];
        if (was_split(&r, t))
            continue;
        double len2;
        longest_edge(m, r.period, t, &len2);
        if (sqrt(len2) < min_size) {
            skipped++;
            continue;
        }
        if (m->n_nodes == r.n_nodes0)
            reserve(&r, 3 * guess + 8, 6 * guess + 16, 9 * guess + 24);
        rc = refine_one(&r, t);
    }

    int32_t new_nodes = m->n_nodes - r.n_nodes0, new_tris = m->n_tris - r.n_tris0;
    if (new_nodes > 0) {
        size_t cn = (size_t)slack_count(m->n_nodes), ct = (size_t)slack_count(m->n_tris);
        m->pos = fs_realloc(m->pos, 3 * cn * sizeof *m->pos);
        m->tri = fs_realloc(m->tri, 3 * ct * sizeof *m->tri);
        m->adj = fs_realloc(m->adj, 3 * ct * sizeof *m->adj);
        if (m->shift)
            m->shift = fs_realloc(m->shift, 6 * ct * sizeof *m->shift);
        if (r.has_edges) {
            size_t ce = (size_t)slack_count(m->n_edges);
            m->tri_edge = fs_realloc(m->tri_edge, 3 * ct * sizeof *m->tri_edge);
            m->edge = fs_realloc(m->edge, 2 * ce * sizeof *m->edge);
            m->edge_tri = fs_realloc(m->edge_tri, 2 * ce * sizeof *m->edge_tri);
        }
        if (r.has_rings)
            rings_rebuilt = !update_rings(&r);
    }

    if (change) {
        fs_refine_change_free(change);
        change->n_nodes_before = r.n_nodes0;
        change->n_tris_before = r.n_tris0;
        change->n_new_nodes = new_nodes;
        change->node_parent = trimmed(r.node_parent, 2 * (size_t)new_nodes, sizeof *r.node_parent);
        change->node_parent_shift = trimmed(r.node_parent_shift, 2 * (size_t)new_nodes, sizeof *r.node_parent_shift);
        change->n_new_tris = new_tris;
        change->tri_parent = trimmed(r.tri_parent, (size_t)new_tris, sizeof *r.tri_parent);
        if (r.n_split > 1)
            fs_sort_int32(r.split_list, r.n_split);
        change->changed_tri = trimmed(r.split_list, (size_t)r.n_split, sizeof *r.split_list);
        change->n_changed_tris = r.n_split;
        change->n_bisections = r.n_bisections;
        change->n_skipped = skipped;
        change->rings_rebuilt = rings_rebuilt;
    } else {
        free(r.node_parent);
        free(r.node_parent_shift);
        free(r.tri_parent);
        free(r.split_list);
    }
    free(r.split_set);
    free(r.stack);
    return rc;
}
