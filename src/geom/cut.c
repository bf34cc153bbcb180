/* Mesh surgery of cracks: split edges, duplicated nodes, and the record of the change. */
#include "geom/cut.h"

#include <math.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/sort.h"
#include "base/uf.h"

void fs_cut_begin(fs_cut *c, fs_mesh *m, fs_cut_tris_fn tris_at, void *ctx)
{
    memset(c, 0, sizeof *c);
    c->mesh = m;
    c->n_nodes_before = m->n_nodes;
    c->n_tris_before = m->n_tris;
    c->n_tris_adj = m->n_tris;
    c->changed = fs_calloc((size_t)m->n_tris + 1, 1);
    c->tris_at = tris_at;
    c->tris_ctx = ctx;
}

void fs_cut_free(fs_cut *c)
{
    free(c->node_parent);
    free(c->node_weight);
    free(c->tri_parent);
    free(c->changed);
    free(c->changed_list);
    memset(c, 0, sizeof *c);
}

void fs_cut_mark_changed(fs_cut *c, int32_t t)
{
    if (t < c->n_tris_before && !c->changed[t]) {
        c->changed[t] = 1;
        FS_ARRAY_RESERVE(c->changed_list, c->cap_changed, c->n_changed + 1, 16);
        c->changed_list[c->n_changed++] = t;
    }
}

int32_t fs_cut_new_node(fs_cut *c, const double pos[3], int32_t a, int32_t b, double w)
{
    fs_mesh *m = c->mesh;
    double p[3] = {pos[0], pos[1], pos[2]}; /* pos may point into m->pos, which moves */
    int32_t i = m->n_nodes++;
    m->pos = fs_realloc(m->pos, 3 * (size_t)m->n_nodes * sizeof *m->pos);
    memcpy(m->pos + 3 * (size_t)i, p, sizeof p);
    int32_t k = i - c->n_nodes_before;
    if (FS_ARRAY_GROW(c->cap_nodes, k + 1, 8)) {
        FS_ARRAY_RESIZE(c->node_parent, 2 * (size_t)c->cap_nodes);
        FS_ARRAY_RESIZE(c->node_weight, c->cap_nodes);
    }
    c->node_parent[2 * k] = a;
    c->node_parent[2 * k + 1] = b;
    c->node_weight[k] = w;
    return i;
}

int32_t fs_cut_new_tri(fs_cut *c, int32_t parent)
{
    fs_mesh *m = c->mesh;
    int32_t t = m->n_tris++;
    m->tri = fs_realloc(m->tri, 3 * (size_t)m->n_tris * sizeof *m->tri);
    memcpy(m->tri + 3 * (size_t)t, m->tri + 3 * (size_t)parent, 3 * sizeof *m->tri);
    if (m->shift) {
        m->shift = fs_realloc(m->shift, 6 * (size_t)m->n_tris * sizeof *m->shift);
        memcpy(m->shift + 6 * (size_t)t, m->shift + 6 * (size_t)parent, 6 * sizeof *m->shift);
    }
    int32_t k = t - c->n_tris_before;
    FS_ARRAY_RESERVE(c->tri_parent, c->cap_tris, k + 1, 8);
    c->tri_parent[k] = parent < c->n_tris_before ? parent : c->tri_parent[parent - c->n_tris_before];
    return t;
}

void fs_cut_normalize_shifts(fs_mesh *m, int32_t t)
{
    if (!m->shift)
        return;
    int8_t *s = m->shift + 6 * (size_t)t;
    int8_t s0 = s[0], s1 = s[1];
    for (int k = 0; k < 3; k++) {
        s[2 * k] = (int8_t)(s[2 * k] - s0);
        s[2 * k + 1] = (int8_t)(s[2 * k + 1] - s1);
    }
}

void fs_cut_set_corner(fs_mesh *m, int32_t t, int k, int32_t node, const double p[3])
{
    m->tri[3 * (size_t)t + k] = node;
    if (!m->shift)
        return;
    const double *q = m->pos + 3 * (size_t)node;
    double ex = fs_domain_extent_x(&m->domain), ey = fs_domain_extent_y(&m->domain);
    m->shift[6 * (size_t)t + 2 * k] = (int8_t)lround((p[0] - q[0]) / ex);
    m->shift[6 * (size_t)t + 2 * k + 1] = (int8_t)lround((p[1] - q[1]) / ey);
}

int32_t fs_cut_tris_at(const fs_cut *c, int32_t node, int32_t **out, int32_t *cap)
{
    if (c->tris_at)
        return c->tris_at(c->tris_ctx, c, node, out, cap);
    const fs_mesh *m = c->mesh;
    int32_t n = 0;
    for (int32_t t = 0; t < m->n_tris; t++)
        if (fs_mesh_corner_of(m, t, node) >= 0) {
            FS_ARRAY_RESERVE(*out, *cap, n + 1, 16);
            (*out)[n++] = t;
        }
    return n;
}

int fs_cut_update_adjacency(fs_cut *c)
{
    fs_mesh *m = c->mesh;
    int32_t n_new = c->n_tris_adj - c->n_tris_before;
    int32_t *list = fs_malloc(((size_t)c->n_changed + (size_t)n_new + 1) * sizeof *list);
    if (c->n_changed > 0)
        memcpy(list, c->changed_list, (size_t)c->n_changed * sizeof *list);
    for (int32_t q = 0; q < n_new; q++)
        list[c->n_changed + q] = c->n_tris_before + q;
    int rc = fs_mesh_update_adjacency(m, c->n_tris_adj, list, c->n_changed + n_new);
    c->n_tris_adj = m->n_tris;
    free(list);
    return rc;
}

int32_t fs_cut_split_edge(fs_cut *c, int32_t t, int ia, double s)
{
    fs_mesh *m = c->mesh;
    bool sphere = m->domain.type == FS_DOMAIN_SPHERE;
    int ib = (ia + 1) % 3;
    int32_t a = m->tri[3 * (size_t)t + ia], b = m->tri[3 * (size_t)t + ib];
    int32_t u = m->adj[3 * (size_t)t + ia];
    double pa[3], pb[3], p[3], q[3];
    fs_mesh_corner(m, t, ia, pa);
    fs_mesh_corner(m, t, ib, pb);
    for (int k = 0; k < 3; k++)
        p[k] = pa[k] + s * (pb[k] - pa[k]);
    memcpy(q, p, sizeof q);
    fs_domain_wrap(&m->domain, q);
    if (sphere) /* the unwrapped frame is the sphere itself: the node's position, on it */
        memcpy(p, q, sizeof p);
    int32_t i = fs_cut_new_node(c, q, a, b, s);
    int32_t t2 = fs_cut_new_tri(c, t);
    fs_cut_set_corner(m, t, ib, i, p);
    fs_cut_set_corner(m, t2, ia, i, p);
    fs_cut_normalize_shifts(m, t2);
    fs_cut_mark_changed(c, t);
    if (u >= 0) {
        int ua = fs_mesh_corner_of(m, u, a), ub = fs_mesh_corner_of(m, u, b);
        double qa[3], qb[3], pu[3];
        fs_mesh_corner(m, u, ua, qa);
        fs_mesh_corner(m, u, ub, qb);
        for (int k = 0; k < 3; k++)
            pu[k] = qa[k] + s * (qb[k] - qa[k]);
        if (sphere)
            memcpy(pu, q, sizeof pu);
        int32_t u2 = fs_cut_new_tri(c, u);
        fs_cut_set_corner(m, u, ub, i, pu);
        fs_cut_set_corner(m, u2, ua, i, pu);
        fs_cut_normalize_shifts(m, u2);
        fs_cut_mark_changed(c, u);
    }
    return i;
}

int32_t fs_cut_duplicate_node(fs_cut *c, int32_t v, const int32_t *cut, int32_t n_cut)
{
    fs_mesh *m = c->mesh;
    int32_t *fan = NULL, cap = 0;
    int32_t n_fan = fs_cut_tris_at(c, v, &fan, &cap);
    int32_t *parent = fs_malloc(((size_t)n_fan + 1) * sizeof *parent);
    fs_uf_init(parent, n_fan);
    for (int32_t q = 0; q < n_fan; q++) {
        int32_t t = fan[q];
        int k = fs_mesh_corner_of(m, t, v);
        for (int side = 0; side < 2; side++) {
            int edge = side ? k : (k + 2) % 3; /* the two edges of t at v */
            int32_t other = m->tri[3 * (size_t)t + (side ? (k + 1) % 3 : (k + 2) % 3)];
            int32_t u = m->adj[3 * (size_t)t + edge];
            if (u < 0)
                continue;
            bool is_cut = false;
            for (int32_t l = 0; l < n_cut; l++)
                is_cut |= cut[l] == other;
            if (is_cut)
                continue;
            for (int32_t r = 0; r < n_fan; r++)
                if (fan[r] == u)
                    fs_uf_union(parent, q, r);
        }
    }
    int32_t sectors = 0;
    int32_t *copy = fs_malloc(((size_t)n_fan + 1) * sizeof *copy);
    for (int32_t q = 0; q < n_fan; q++) {
        int32_t r = fs_uf_find(parent, q);
        if (r != q) {
            copy[q] = copy[r];
            continue;
        }
        copy[q] = sectors++ == 0 ? v : fs_cut_new_node(c, m->pos + 3 * (size_t)v, v, v, 0.0);
    }
    for (int32_t q = 0; q < n_fan; q++)
        if (copy[q] != v) {
            int32_t t = fan[q];
            m->tri[3 * (size_t)t + fs_mesh_corner_of(m, t, v)] = copy[q];
            fs_cut_mark_changed(c, t);
        }
    free(copy);
    free(parent);
    free(fan);
    return sectors;
}

int32_t *fs_cut_changed_ascending(const fs_cut *c)
{
    int32_t *out = fs_malloc(((size_t)c->n_changed + 1) * sizeof *out);
    memcpy(out, c->changed_list, (size_t)c->n_changed * sizeof *out);
    fs_sort_int32(out, c->n_changed);
    return out;
}
