/* Mesh surgery of a crack in a tetrahedral mesh: node splits along a plane by edge splits (O'Brien & Hodgins §4.3). */
#include "geom/tetcut.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/sort.h"
#include "base/vec.h"

void fs_tetcut_result_free(fs_tetcut_result *r)
{
    free(r->from);
    free(r->weight);
    free(r->parent);
    fs_tet_list_free(&r->changed);
    memset(r, 0, sizeof *r);
}

static void result_reset(const fs_tetmesh *m, fs_tetcut_result *r)
{
    r->n_nodes_before = m->n_nodes;
    r->n_tets_before = m->n_tets;
    r->changed.n = 0;
    r->node_minus = -1;
}

/* Records node i (just added) as coming from a and b at w. */
static void record_node(fs_tetcut_result *r, int32_t i, int32_t a, int32_t b, double w)
{
    int32_t k = i - r->n_nodes_before;
    if (k >= r->cap_nodes) {
        r->cap_nodes = 2 * k + 16;
        r->from = fs_realloc(r->from, 2 * (size_t)r->cap_nodes * sizeof *r->from);
        r->weight = fs_realloc(r->weight, (size_t)r->cap_nodes * sizeof *r->weight);
    }
    r->from[2 * k] = a;
    r->from[2 * k + 1] = b;
    r->weight[k] = w;
}

static void record_tet(fs_tetcut_result *r, int32_t t, int32_t parent)
{
    int32_t k = t - r->n_tets_before;
    if (k >= r->cap_tets) {
        r->cap_tets = 2 * k + 16;
        r->parent = fs_realloc(r->parent, (size_t)r->cap_tets * sizeof *r->parent);
    }
    r->parent[k] = parent;
}

static void record_changed(fs_tetcut_result *r, int32_t t)
{
    if (t < r->n_tets_before)
        fs_tet_list_push(&r->changed, t);
}

static int corner_of(const fs_tetmesh *m, int32_t t, int32_t node)
{
    for (int c = 0; c < 4; c++)
        if (m->tet[4 * (size_t)t + c] == node)
            return c;
    return -1;
}

/* Splits the edge and returns the new node; *qshift receives its shift relative to a's frame. */
static int32_t split_edge(fs_tetmesh *m, int32_t a, int32_t b, const int8_t rel[2], double w, fs_tetcut_result *r,
                          int8_t qshift[2])
{
    const double *pa = m->pos + 3 * (size_t)a, *pb = m->pos + 3 * (size_t)b;
    double q[3], unwrapped[3];
    for (int k = 0; k < 3; k++) {
        double bk = pb[k] + (k < 2 ? rel[k] * m->period[k] : 0.0);
        unwrapped[k] = q[k] = pa[k] + w * (bk - pa[k]);
    }
    for (int k = 0; k < 2; k++) {
        qshift[k] = 0;
        if (m->period[k] > 0.0) {
            double f = floor(q[k] / m->period[k]);
            q[k] -= f * m->period[k];
            if (q[k] >= m->period[k])
                q[k] = 0.0;
            qshift[k] = (int8_t)lround((unwrapped[k] - q[k]) / m->period[k]);
        }
    }
    double za = m->zeta[a], zb = m->zeta[b];
    int32_t qn = fs_tetmesh_add_node(m, q, za == zb ? za : za + w * (zb - za));
    record_node(r, qn, a, b, w);
    fs_tet_list around = {0};
    fs_tetmesh_edge_tets(m, a, b, rel, &around);
    for (int32_t k = 0; k < around.n; k++) {
        int32_t t = around.v[k];
        int ca = corner_of(m, t, a), cb = corner_of(m, t, b);
        int32_t v[4];
        int8_t s[8];
        memcpy(v, m->tet + 4 * (size_t)t, sizeof v);
        memcpy(s, m->shift + 8 * (size_t)t, sizeof s);
        int8_t sq[2] = {(int8_t)(s[2 * ca] + qshift[0]), (int8_t)(s[2 * ca + 1] + qshift[1])};
        int32_t v2[4];
        int8_t s2[8];
        memcpy(v2, v, sizeof v2);
        memcpy(s2, s, sizeof s2);
        v[cb] = qn; /* the half at a */
        s[2 * cb] = sq[0];
        s[2 * cb + 1] = sq[1];
        v2[ca] = qn; /* the half at b */
        s2[2 * ca] = sq[0];
        s2[2 * ca + 1] = sq[1];
        fs_tetmesh_set_tet(m, t, v, s);
        record_changed(r, t);
        int32_t t2 = fs_tetmesh_add_tet(m, v2, s2);
        record_tet(r, t2, t);
    }
    fs_tet_list_free(&around);
    return qn;
}

int32_t fs_tetcut_split_edge(fs_tetmesh *m, int32_t a, int32_t b, const int8_t rel[2], double w,
                             fs_tetcut_result *out)
{
    int8_t qs[2];
    return split_edge(m, a, b, rel, w, out, qs);
}

/* Gives node v one copy per piece of its elements beyond the first (pieces joined through faces at
 * v). */
static void separate_pieces(fs_tetmesh *m, int32_t v, fs_tetcut_result *r)
{
    const fs_tet_list *l = &m->node_tets[v];
    int32_t k = l->n;
    if (k < 2)
        return;
    int32_t *tets = fs_malloc((size_t)k * sizeof *tets), *root = fs_malloc((size_t)k * sizeof *root);
    memcpy(tets, l->v, (size_t)k * sizeof *tets);
    for (int32_t i = 0; i < k; i++)
        root[i] = i;
    for (int32_t i = 0; i < k; i++)
        for (int32_t j = i + 1; j < k; j++) {
            /* a shared face at v: two further corners in common, at the same shifts relative to v */
            int32_t ti = tets[i], tj = tets[j];
            int ci = corner_of(m, ti, v), cj = corner_of(m, tj, v);
            const int8_t *si = m->shift + 8 * (size_t)ti, *sj = m->shift + 8 * (size_t)tj;
            int common = 0;
            for (int a = 0; a < 4; a++) {
                if (a == ci)
                    continue;
                for (int b = 0; b < 4; b++) {
                    if (b == cj || m->tet[4 * (size_t)ti + a] != m->tet[4 * (size_t)tj + b])
                        continue;
                    if (si[2 * a] - si[2 * ci] == sj[2 * b] - sj[2 * cj] &&
                        si[2 * a + 1] - si[2 * ci + 1] == sj[2 * b + 1] - sj[2 * cj + 1])
                        common++;
                }
            }
            if (common < 2)
                continue;
            int32_t ri = i, rj = j;
            while (root[ri] != ri)
                ri = root[ri];
            while (root[rj] != rj)
                rj = root[rj];
            if (ri != rj)
                root[ri > rj ? ri : rj] = ri < rj ? ri : rj;
        }
    /* pieces in order of their smallest element; the first keeps v */
    int32_t *copy = fs_malloc((size_t)k * sizeof *copy);
    for (int32_t i = 0; i < k; i++) {
        int32_t ri = i;
        while (root[ri] != ri)
            ri = root[ri];
        root[i] = ri;
        copy[i] = -1;
    }
    for (int32_t i = 0; i < k; i++) {
        if (root[i] == 0)
            continue;
        if (copy[root[i]] < 0) {
            double p[3];
            memcpy(p, m->pos + 3 * (size_t)v, sizeof p);
            copy[root[i]] = fs_tetmesh_add_node(m, p, m->zeta[v]);
            record_node(r, copy[root[i]], v, v, 0.0);
        }
        int32_t t = tets[i];
        int32_t nv[4];
        memcpy(nv, m->tet + 4 * (size_t)t, sizeof nv);
        nv[corner_of(m, t, v)] = copy[root[i]];
        fs_tetmesh_set_tet(m, t, nv, m->shift + 8 * (size_t)t);
        record_changed(r, t);
    }
    free(copy);
    free(tets);
    free(root);
}

/* A corner of the star: node, signed distance to the plane, side (-1, 0 on the plane, +1). */
typedef struct {
    int32_t node;
    double d;
    int side;
} star_corner;

/* Edges are cut no nearer their ends than this fraction (snap_near_crossings). */
#define EDGE_MIN 0.2

static star_corner *find_corner(star_corner *cs, int32_t n, int32_t node)
{
    for (int32_t i = 0; i < n; i++)
        if (cs[i].node == node)
            return &cs[i];
    return NULL;
}

/* Classifies the corners of the elements at node (once each) against the plane through it with unit
 * normal nrm, with the snapping of p, into cs (room for 3 per element); returns their number. */
static int32_t classify(const fs_tetmesh *m, int32_t node, const double nrm[3], const fs_tetcut_params *p,
                        star_corner *cs)
{
    double sin_snap = sin(p->snap_angle);
    int32_t n_cs = 0;
    const fs_tet_list *star = &m->node_tets[node];
    for (int32_t k = 0; k < star->n; k++) {
        int32_t t = star->v[k];
        double x[12];
        fs_tetmesh_corners(m, t, x);
        int cn = corner_of(m, t, node);
        for (int c = 0; c < 4; c++) {
            int32_t v = m->tet[4 * (size_t)t + c];
            if (c == cn || find_corner(cs, n_cs, v))
                continue;
            double r[3];
            fs_sub3(r, x + 3 * c, x + 3 * cn);
            double d = fs_dot3(r, nrm);
            bool snapped = fabs(d) < p->snap_distance || fabs(d) < sin_snap * fs_norm3(r);
            cs[n_cs++] = (star_corner){v, d, snapped || d == 0.0 ? 0 : (d > 0.0 ? 1 : -1)};
        }
    }
    return n_cs;
}

/* The paper's thresholds keep the cut points away from the splitting node's corners; they do not keep
 * a cut point from landing next to the corner at the near end of a long edge, whose halves would be
 * a sliver. So an edge is cut only between EDGE_MIN and 1 - EDGE_MIN of its length: a corner nearer
 * than that to where the plane crosses one of its edges is taken as on the plane too, until no such
 * crossing is left. */
static void snap_near_crossings(const fs_tetmesh *m, int32_t node, star_corner *cs, int32_t n_cs)
{
    const fs_tet_list *star = &m->node_tets[node];
    for (bool changed = true; changed;) {
        changed = false;
        for (int32_t k = 0; k < star->n; k++) {
            const int32_t *v = m->tet + 4 * (size_t)star->v[k];
            for (int c1 = 0; c1 < 4; c1++)
                for (int c2 = c1 + 1; c2 < 4; c2++) {
                    if (v[c1] == node || v[c2] == node)
                        continue;
                    star_corner *k1 = find_corner(cs, n_cs, v[c1]), *k2 = find_corner(cs, n_cs, v[c2]);
                    if (k1->side * k2->side >= 0)
                        continue;
                    double w = k1->d / (k1->d - k2->d);
                    if (w < EDGE_MIN) {
                        k1->side = 0;
                        changed = true;
                    } else if (w > 1.0 - EDGE_MIN) {
                        k2->side = 0;
                        changed = true;
                    }
                }
        }
    }
}

int fs_tetcut_sides(const fs_tetmesh *m, int32_t node, const double normal[3], const fs_tetcut_params *p)
{
    double len = fs_norm3(normal);
    if (!(len > 0.0) || !isfinite(len))
        return 0;
    double nrm[3] = {normal[0] / len, normal[1] / len, normal[2] / len};
    int32_t cap = 3 * m->node_tets[node].n + 8;
    star_corner buf[192], *cs = cap <= 192 ? buf : fs_malloc((size_t)cap * sizeof *cs);
    int32_t n = classify(m, node, nrm, p, cs);
    snap_near_crossings(m, node, cs, n);
    int sides = 0;
    for (int32_t i = 0; i < n; i++)
        sides |= cs[i].side > 0 ? 1 : (cs[i].side < 0 ? 2 : 0);
    if (cs != buf)
        free(cs);
    return sides;
}

typedef struct {
    int32_t a, b;
    int8_t rel[2];
    double w;
} cut_edge;

int fs_tetcut_node(fs_tetmesh *m, int32_t node, const double normal[3], const fs_tetcut_params *p,
                   fs_tetcut_result *out)
{
    FS_ASSERT(m->node_tets);
    result_reset(m, out);
    double len = fs_norm3(normal);
    if (!(len > 0.0) || !isfinite(len)) {
        fs_error(FS_ERR_DATA, "tetcut: the fracture plane at node %d has no normal", (int)node);
        return -1;
    }
    double nrm[3] = {normal[0] / len, normal[1] / len, normal[2] / len};

    /* classify the corners of the star */
    fs_tet_list star = {0};
    for (int32_t k = 0; k < m->node_tets[node].n; k++)
        fs_tet_list_push(&star, m->node_tets[node].v[k]);
    int32_t cap_cs = 4 * star.n + 8;
    star_corner *cs = fs_malloc((size_t)cap_cs * sizeof *cs);
    int32_t n_cs = classify(m, node, nrm, p, cs);
    snap_near_crossings(m, node, cs, n_cs);
    int sides = 0;
    for (int32_t i = 0; i < n_cs; i++)
        sides |= cs[i].side > 0 ? 1 : (cs[i].side < 0 ? 2 : 0);
    if (sides != 3) {
        free(cs);
        fs_tet_list_free(&star);
        return 0;
    }

    /* the edges of the star between corners on opposite sides */
    int32_t n_edges = 0;
    cut_edge *edges = fs_malloc(6 * (size_t)star.n * sizeof *edges);
    for (int32_t k = 0; k < star.n; k++) {
        int32_t t = star.v[k];
        const int32_t *v = m->tet + 4 * (size_t)t;
        const int8_t *s = m->shift + 8 * (size_t)t;
        for (int c1 = 0; c1 < 4; c1++)
            for (int c2 = c1 + 1; c2 < 4; c2++) {
                if (v[c1] == node || v[c2] == node)
                    continue;
                const star_corner *k1 = find_corner(cs, n_cs, v[c1]), *k2 = find_corner(cs, n_cs, v[c2]);
                if (k1->side * k2->side >= 0)
                    continue;
                cut_edge e = {v[c1], v[c2], {(int8_t)(s[2 * c2] - s[2 * c1]), (int8_t)(s[2 * c2 + 1] - s[2 * c1 + 1])},
                              k1->d / (k1->d - k2->d)};
                if (e.a > e.b) {
                    int32_t tmp = e.a;
                    e.a = e.b;
                    e.b = tmp;
                    e.rel[0] = (int8_t)-e.rel[0];
                    e.rel[1] = (int8_t)-e.rel[1];
                    e.w = 1.0 - e.w;
                }
                bool seen = false;
                for (int32_t q = 0; q < n_edges && !seen; q++)
                    seen = edges[q].a == e.a && edges[q].b == e.b && edges[q].rel[0] == e.rel[0] &&
                           edges[q].rel[1] == e.rel[1];
                if (!seen)
                    edges[n_edges++] = e;
            }
    }
    fs_tet_list on_plane = {0};
    for (int32_t q = 0; q < n_edges; q++) {
        int8_t qs[2];
        int32_t qn = split_edge(m, edges[q].a, edges[q].b, edges[q].rel, edges[q].w, out, qs);
        if (n_cs == cap_cs) {
            cap_cs *= 2;
            cs = fs_realloc(cs, (size_t)cap_cs * sizeof *cs);
        }
        cs[n_cs++] = (star_corner){qn, 0.0, 0};
        fs_tet_list_push(&on_plane, qn);
    }
    free(edges);
    for (int32_t i = 0; i < n_cs; i++)
        if (cs[i].side == 0 && cs[i].node < out->n_nodes_before)
            fs_tet_list_push(&on_plane, cs[i].node);

    /* each element at the node now lies on one side: the copy takes the negative ones */
    double p0[3];
    memcpy(p0, m->pos + 3 * (size_t)node, sizeof p0);
    int32_t minus = fs_tetmesh_add_node(m, p0, m->zeta[node]);
    record_node(out, minus, node, node, 0.0);
    out->node_minus = minus;
    star.n = 0;
    for (int32_t k = 0; k < m->node_tets[node].n; k++)
        fs_tet_list_push(&star, m->node_tets[node].v[k]);
    for (int32_t k = 0; k < star.n; k++) {
        int32_t t = star.v[k];
        int side = 0;
        double dsum = 0.0;
        int cn = corner_of(m, t, node);
        for (int c = 0; c < 4; c++) {
            if (c == cn)
                continue;
            const star_corner *sc = find_corner(cs, n_cs, m->tet[4 * (size_t)t + c]);
            FS_ASSERT(sc && !(side * sc->side < 0));
            if (sc->side)
                side = sc->side;
            dsum += sc->d;
        }
        if (side == 0)
            side = dsum < 0.0 ? -1 : 1;
        if (side > 0)
            continue;
        int32_t v[4];
        memcpy(v, m->tet + 4 * (size_t)t, sizeof v);
        v[cn] = minus;
        fs_tetmesh_set_tet(m, t, v, m->shift + 8 * (size_t)t);
        record_changed(out, t);
    }
    free(cs);
    fs_tet_list_free(&star);

    /* nodes on the plane whose elements fell apart (the crack ran through them to a boundary) */
    separate_pieces(m, node, out);
    separate_pieces(m, minus, out);
    for (int32_t k = 0; k < on_plane.n; k++)
        separate_pieces(m, on_plane.v[k], out);
    fs_tet_list_free(&on_plane);
    out->changed.n = fs_sort_unique_int32(out->changed.v, out->changed.n);
    return 1;
}
