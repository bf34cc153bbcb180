/* The springs model's 3-D post-process (thesis §4.5, Fig. 4.10): extruded cells relaxed as spring sub-networks, drawn into a render mesh. */
#include "model/springs/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/vec.h"

/* design notes (see also springs.h):
 * - A junction is a point where cells meet: a Delaunay triangle (its circumcentre, or its centroid
 *   when a border triangle's circumcentre falls outside the border edge), the midpoint of a border
 *   edge of a non-periodic domain, or a border node itself. Its members are the masses of the cells
 *   meeting there, each with the image shift that puts it in the junction's frame.
 * - At every level, the members of a junction are grouped by the intact springs among them in the
 *   layer below the level (level 0: all together, except in curl mode where layer 0 decides); a
 *   group shares one node. A group's initial position is the image of the junction under its own
 *   masses: the affine map of three, the similarity of two, the free shrinkage of one.
 * - Positions are world positions at the final time in each node's own frame (junction or cell);
 *   a cell sees a junction node through the offset J (shift * period); texture coordinates come
 *   from the inverse background flow. */

/* A junction: up to three member masses. */
typedef struct {
    int8_t count;          /* members */
    int32_t node[3];       /* mesh nodes */
    int8_t shift[3][2];    /* image shifts of the members in the junction's frame */
    int32_t edge[3];       /* mesh edge between members m and (m + 1) % 3 (count 3), or member 0-1 (count 2); -1 */
    double ref[3];         /* reference point (domain coordinates, junction frame) */
} junction;

/* One corner of a cell polygon: a junction and the cell's member slot in it. */
typedef struct {
    int32_t junction;
    int8_t member;
    int32_t edge_after;    /* mesh edge dual to the polygon side from this corner to the next; -1 on a border */
} corner;

typedef struct {
    const fs_springs *s;
    const fs_mesh *m;
    bool sphere;
    int L;                 /* layers */
    int levels;            /* L + 1 */
    double period[2];      /* image period (cm) per axis, 0 on non-wrapping axes */
    double J[9];           /* growth Jacobian from 0 to the final time */
    double t;              /* final time */
    double H;              /* thickness at the final time (cm) */
    double shrink_level[9];/* shrinkage at each level */
    double a_axis, c_axis; /* sphere: equatorial and polar radii at the final time */
    double spacing;        /* mean reference length of the mesh edges (cm) */

    int32_t n_junctions;
    junction *junctions;
    int32_t *corner_start; /* n_nodes + 1 */
    corner *corners;

    int32_t *group_node;   /* (level * n_junctions + j) * 3 + member -> post-network node */
    int32_t *center_node;  /* level * n + i -> post-network node */
    int32_t n_post;        /* nodes of the post network */
    double *init;          /* 3 * n_post initial positions (world, own frame) */
    double *refp;          /* 3 * n_post reference positions (own frame) */
    int8_t *post_level;    /* n_post */
} post_ctx;

/* ---- small helpers ---- */

static int corner_index(const fs_mesh *m, int32_t t, int32_t node)
{
    for (int c = 0; c < 3; c++)
        if (m->tri[3 * (size_t)t + c] == node)
            return c;
    return -1;
}

/* Reference position of a member in the junction's frame (domain coordinates). */
static void member_ref(const post_ctx *c, const junction *jn, int m, double *out)
{
    const double *p = c->m->pos + 3 * (size_t)jn->node[m];
    out[0] = p[0] + jn->shift[m][0] * c->period[0];
    out[1] = p[1] + jn->shift[m][1] * c->period[1];
    out[2] = c->sphere ? p[2] : 0.0;
}

/* World position (final time) of mass (layer, node) seen with an image shift. */
static void member_world(const post_ctx *c, int layer, int32_t node, const int8_t *shift, double *out)
{
    const fs_springs *s = c->s;
    const double *x = s->net.x + (size_t)s->dim * (size_t)(layer * s->n + node);
    if (c->sphere) {
        out[0] = x[0];
        out[1] = x[1];
        out[2] = x[2];
        return;
    }
    double o[2] = {shift[0] * c->period[0], shift[1] * c->period[1]};
    out[0] = x[0] + c->J[0] * o[0] + c->J[1] * o[1];
    out[1] = x[1] + c->J[3] * o[0] + c->J[4] * o[1];
    out[2] = 0.0;
}

/* The world offset of an image shift (what a cell adds to a junction node seen from its frame is
 * minus this, for the cell's member shift). */
static void shift_world(const post_ctx *c, const int8_t *shift, double *out)
{
    out[0] = out[1] = out[2] = 0.0;
    if (c->sphere)
        return;
    double o[2] = {shift[0] * c->period[0], shift[1] * c->period[1]};
    out[0] = c->J[0] * o[0] + c->J[1] * o[1];
    out[1] = c->J[3] * o[0] + c->J[4] * o[1];
}

static void unit(const double *p, double *n)
{
    double r = fs_norm3(p);
    for (int k = 0; k < 3; k++)
        n[k] = r > 0.0 ? p[k] / r : 0.0;
}

/* ---- junctions and cells ---- */

/* Moves a border point onto the nearest side of the rectangle along the non-wrapping axes. */
static void snap_border(const post_ctx *c, double *p)
{
    const fs_domain *d = &c->m->domain;
    double ext[2] = {fs_domain_extent_x(d), fs_domain_extent_y(d)};
    int best_axis = -1;
    double best = INFINITY, value = 0.0;
    for (int a = 0; a < 2; a++) {
        if (c->period[a] > 0.0)
            continue;
        double lo = fabs(p[a]), hi = fabs(ext[a] - p[a]);
        if (lo < best) {
            best = lo;
            best_axis = a;
            value = 0.0;
        }
        if (hi < best) {
            best = hi;
            best_axis = a;
            value = ext[a];
        }
    }
    if (best_axis >= 0)
        p[best_axis] = value;
}

static int build_junctions(post_ctx *c)
{
    const fs_mesh *m = c->m;
    const fs_springs *s = c->s;
    int32_t n = m->n_nodes, nt = m->n_tris, ne = m->n_edges;
    /* border edges and border nodes */
    int32_t n_bedges = 0, n_bnodes = 0;
    int32_t *edge_junction = fs_malloc(((size_t)ne + 1) * sizeof *edge_junction);
    int32_t *node_junction = fs_malloc(((size_t)n + 1) * sizeof *node_junction);
    for (int32_t e = 0; e < ne; e++)
        edge_junction[e] = m->edge_tri[2 * e + 1] < 0 ? nt + n_bedges++ : -1;
    for (int32_t i = 0; i < n; i++) {
        node_junction[i] = -1;
        int32_t r0 = m->ring_start[i], r1 = m->ring_start[i + 1];
        if (r1 <= r0 || c->sphere)
            continue;
        int32_t tf = m->ring_tri[r0];
        int cf = corner_index(m, tf, i);
        if (m->adj[3 * (size_t)tf + cf] < 0)
            node_junction[i] = nt + n_bedges + n_bnodes++;
    }
    c->n_junctions = nt + n_bedges + n_bnodes;
    c->junctions = fs_calloc((size_t)c->n_junctions + 1, sizeof *c->junctions);

    for (int32_t t = 0; t < nt; t++) {
        junction *jn = c->junctions + t;
        jn->count = 3;
        double X[3][3];
        for (int k = 0; k < 3; k++) {
            jn->node[k] = m->tri[3 * (size_t)t + k];
            jn->shift[k][0] = m->shift ? m->shift[6 * (size_t)t + 2 * k] : 0;
            jn->shift[k][1] = m->shift ? m->shift[6 * (size_t)t + 2 * k + 1] : 0;
            jn->edge[k] = m->tri_edge[3 * (size_t)t + k];
            member_ref(c, jn, k, X[k]);
        }
        memcpy(jn->ref, s->vor.circumcenter + 3 * (size_t)t, sizeof jn->ref);
        if (!c->sphere) {
            jn->ref[2] = 0.0;
            /* a border triangle whose circumcentre lies beyond its border edge: use the centroid */
            for (int k = 0; k < 3; k++) {
                if (m->adj[3 * (size_t)t + k] >= 0)
                    continue;
                const double *a = X[k], *b = X[(k + 1) % 3];
                if (fs_orient2(a, b, jn->ref) <= 0.0) {
                    for (int q = 0; q < 2; q++)
                        jn->ref[q] = (X[0][q] + X[1][q] + X[2][q]) / 3.0;
                    break;
                }
            }
        }
    }
    for (int32_t e = 0; e < ne; e++) {
        int32_t j = edge_junction[e];
        if (j < 0)
            continue;
        junction *jn = c->junctions + j;
        int32_t t = m->edge_tri[2 * e];
        jn->count = 2;
        jn->edge[0] = e;
        jn->edge[1] = jn->edge[2] = -1;
        for (int k = 0; k < 2; k++) {
            int32_t node = m->edge[2 * e + k];
            int cidx = corner_index(m, t, node);
            jn->node[k] = node;
            jn->shift[k][0] = m->shift ? m->shift[6 * (size_t)t + 2 * cidx] : 0;
            jn->shift[k][1] = m->shift ? m->shift[6 * (size_t)t + 2 * cidx + 1] : 0;
        }
        double a[3], b[3];
        member_ref(c, jn, 0, a);
        member_ref(c, jn, 1, b);
        for (int q = 0; q < 3; q++)
            jn->ref[q] = 0.5 * (a[q] + b[q]);
        snap_border(c, jn->ref);
    }
    /* border nodes: the one nearest to each corner of the rectangle takes the corner */
    const fs_domain *d = &m->domain;
    double ext[2] = {fs_domain_extent_x(d), fs_domain_extent_y(d)};
    int32_t nearest[4] = {-1, -1, -1, -1};
    double nearest_d[4] = {INFINITY, INFINITY, INFINITY, INFINITY};
    bool corners_exist = c->period[0] == 0.0 && c->period[1] == 0.0;
    for (int32_t i = 0; i < n; i++) {
        int32_t j = node_junction[i];
        if (j < 0)
            continue;
        junction *jn = c->junctions + j;
        jn->count = 1;
        jn->node[0] = i;
        jn->edge[0] = jn->edge[1] = jn->edge[2] = -1;
        member_ref(c, jn, 0, jn->ref);
        snap_border(c, jn->ref);
        if (corners_exist)
            for (int k = 0; k < 4; k++) {
                double cx = (k & 1) ? ext[0] : 0.0, cy = (k & 2) ? ext[1] : 0.0;
                const double *p = m->pos + 3 * (size_t)i;
                double dist = hypot(p[0] - cx, p[1] - cy);
                if (dist < nearest_d[k]) {
                    nearest_d[k] = dist;
                    nearest[k] = i;
                }
            }
    }
    for (int k = 0; k < 4; k++)
        if (nearest[k] >= 0) {
            junction *jn = c->junctions + node_junction[nearest[k]];
            jn->ref[0] = (k & 1) ? ext[0] : 0.0;
            jn->ref[1] = (k & 2) ? ext[1] : 0.0;
        }

    /* cell polygons */
    c->corner_start = fs_calloc((size_t)n + 2, sizeof *c->corner_start);
    for (int32_t i = 0; i < n; i++) {
        int32_t deg = m->ring_start[i + 1] - m->ring_start[i];
        c->corner_start[i + 1] = c->corner_start[i] + deg + (node_junction[i] >= 0 ? 3 : 0);
    }
    c->corners = fs_calloc((size_t)c->corner_start[n] + 1, sizeof *c->corners);
    for (int32_t i = 0; i < n; i++) {
        corner *out = c->corners + c->corner_start[i];
        int32_t r0 = m->ring_start[i], r1 = m->ring_start[i + 1];
        int k = 0;
        bool open = node_junction[i] >= 0;
        if (open) {
            int32_t tf = m->ring_tri[r0];
            int cf = corner_index(m, tf, i);
            int32_t e_first = m->tri_edge[3 * (size_t)tf + cf];
            const junction *jn = c->junctions + edge_junction[e_first];
            out[k].junction = edge_junction[e_first];
            out[k].member = (int8_t)(jn->node[0] == i ? 0 : 1);
            out[k].edge_after = e_first;
            k++;
        }
        for (int32_t r = r0; r < r1; r++) {
            int32_t t = m->ring_tri[r];
            int ci = corner_index(m, t, i);
            out[k].junction = t;
            out[k].member = (int8_t)ci;
            out[k].edge_after = m->tri_edge[3 * (size_t)t + (ci + 2) % 3];
            k++;
        }
        if (open) {
            int32_t e_last = out[k - 1].edge_after;
            const junction *jn = c->junctions + edge_junction[e_last];
            out[k].junction = edge_junction[e_last];
            out[k].member = (int8_t)(jn->node[0] == i ? 0 : 1);
            out[k].edge_after = -1;
            k++;
            out[k].junction = node_junction[i];
            out[k].member = 0;
            out[k].edge_after = -1;
            k++;
        }
        FS_ASSERT(k == c->corner_start[i + 1] - c->corner_start[i]);
    }
    free(edge_junction);
    free(node_junction);
    return 0;
}

/* The shift of the cell's own mass in a junction (its frame relative to the junction's). */
static const int8_t *corner_shift(const post_ctx *c, const corner *k)
{
    return c->junctions[k->junction].shift[k->member];
}

/* ---- groups and nodes ---- */

/* The layer whose springs group the members at a level, or -1 when they are all glued. */
static int grouping_layer(const post_ctx *c, int level)
{
    if (level > 0)
        return level - 1;
    return c->s->setup.springs.post == FS_SPRINGS_POST_CURL ? 0 : -1;
}

static bool intact(const post_ctx *c, int layer, int32_t edge)
{
    if (edge < 0)
        return false;
    return !c->s->broken[(size_t)layer * (size_t)c->s->n_edges + (size_t)edge];
}

/* root[m]: the smallest member of m's group. */
static void junction_groups(const post_ctx *c, const junction *jn, int level, int *root)
{
    int gl = grouping_layer(c, level);
    for (int m = 0; m < 3; m++)
        root[m] = m;
    if (jn->count == 1)
        return;
    if (gl < 0) {
        for (int m = 0; m < jn->count; m++)
            root[m] = 0;
        return;
    }
    if (jn->count == 2) {
        if (intact(c, gl, jn->edge[0]))
            root[1] = 0;
        return;
    }
    bool link[3];
    for (int k = 0; k < 3; k++)
        link[k] = intact(c, gl, jn->edge[k]); /* members k and k + 1 */
    int links = link[0] + link[1] + link[2];
    if (links >= 2) {
        root[0] = root[1] = root[2] = 0;
        return;
    }
    if (link[0])
        root[1] = 0;
    else if (link[1])
        root[2] = 1;
    else if (link[2])
        root[2] = 0;
}

/* Shrinkage of the layer whose masses place a level's nodes. */
static double level_layer_shrink(const post_ctx *c, int level)
{
    int layer = level > 0 ? level - 1 : 0;
    const fs_shrink *sh = &c->s->setup.shrink;
    double top = fs_pwl_eval(&sh->top, c->t), bottom = fs_pwl_eval(&sh->bottom, c->t);
    return bottom + (top - bottom) * (layer + 0.5) / c->L;
}

/* The initial world position (junction frame) of the group of `root` at a level, on the surface. */
static void group_position(const post_ctx *c, const junction *jn, const int *root, int g, int level, double *out)
{
    int layer = level > 0 ? level - 1 : 0;
    int members[3], cnt = 0;
    for (int m = 0; m < jn->count; m++)
        if (root[m] == g)
            members[cnt++] = m;
    double X[3][3], x[3][3];
    for (int k = 0; k < cnt; k++) {
        member_ref(c, jn, members[k], X[k]);
        member_world(c, layer, jn->node[members[k]], jn->shift[members[k]], x[k]);
    }
    const double *V = jn->ref;
    if (cnt == 3) {
        double bc[3];
        if (c->sphere) {
            double e1[3], e2[3], v[3], nrm[3];
            fs_sub3(e1, X[1], X[0]);
            fs_sub3(e2, X[2], X[0]);
            fs_sub3(v, V, X[0]);
            fs_cross3(nrm, e1, e2);
            double nn = fs_dot3(nrm, nrm), cr[3];
            fs_cross3(cr, v, e2);
            bc[1] = fs_dot3(cr, nrm) / nn;
            fs_cross3(cr, e1, v);
            bc[2] = fs_dot3(cr, nrm) / nn;
        } else {
            double det = fs_orient2(X[0], X[1], X[2]);
            bc[1] = fs_orient2(X[0], V, X[2]) / det;
            bc[2] = fs_orient2(X[0], X[1], V) / det;
        }
        bc[0] = 1.0 - bc[1] - bc[2];
        for (int q = 0; q < 3; q++)
            out[q] = bc[0] * x[0][q] + bc[1] * x[1][q] + bc[2] * x[2][q];
        if (c->sphere) {
            /* back onto the mid-surface radius of the masses */
            double r = (fs_norm3(x[0]) + fs_norm3(x[1]) + fs_norm3(x[2])) / 3.0, len = fs_norm3(out);
            for (int q = 0; q < 3; q++)
                out[q] *= r / len;
        }
        return;
    }
    if (cnt == 2) {
        double E[3], v[3], e[3];
        fs_sub3(E, X[1], X[0]);
        fs_sub3(v, V, X[0]);
        fs_sub3(e, x[1], x[0]);
        double EE = fs_dot3(E, E);
        double alpha = fs_dot3(v, E) / EE;
        double perpE[3], perpe[3];
        if (c->sphere) {
            double nX[3], nx[3], mid[3];
            for (int q = 0; q < 3; q++)
                mid[q] = X[0][q] + X[1][q];
            unit(mid, nX);
            fs_cross3(perpE, nX, E);
            for (int q = 0; q < 3; q++)
                mid[q] = x[0][q] + x[1][q];
            unit(mid, nx);
            fs_cross3(perpe, nx, e);
        } else {
            perpE[0] = -E[1];
            perpE[1] = E[0];
            perpE[2] = 0.0;
            perpe[0] = -e[1];
            perpe[1] = e[0];
            perpe[2] = 0.0;
        }
        double beta = fs_dot3(v, perpE) / fs_dot3(perpE, perpE);
        for (int q = 0; q < 3; q++)
            out[q] = x[0][q] + alpha * e[q] + beta * perpe[q];
        return;
    }
    double scale = 1.0 - level_layer_shrink(c, level);
    for (int q = 0; q < 3; q++)
        out[q] = x[0][q] + scale * (V[q] - X[0][q]);
}

/* A point of the surface lifted by height z along the surface normal (world). */
static void lift(const post_ctx *c, const double *base, double z, double *out)
{
    if (!c->sphere) {
        out[0] = base[0];
        out[1] = base[1];
        out[2] = z;
        return;
    }
    double nrm[3];
    unit(base, nrm);
    for (int q = 0; q < 3; q++)
        out[q] = base[q] + z * nrm[q];
}

static int32_t add_post_node(post_ctx *c, int32_t *cap, int level, const double *init, const double *ref)
{
    if (FS_ARRAY_GROW(*cap, c->n_post + 1, 1024)) {
        FS_ARRAY_RESIZE(c->init, 3 * (size_t)*cap);
        FS_ARRAY_RESIZE(c->refp, 3 * (size_t)*cap);
        FS_ARRAY_RESIZE(c->post_level, *cap);
    }
    int32_t id = c->n_post++;
    memcpy(c->init + 3 * (size_t)id, init, 3 * sizeof *init);
    memcpy(c->refp + 3 * (size_t)id, ref, 3 * sizeof *ref);
    c->post_level[id] = (int8_t)level;
    return id;
}

static double level_height(const post_ctx *c, int level, double thick)
{
    return c->H * thick * level / c->L;
}

static void build_nodes(post_ctx *c)
{
    const fs_springs *s = c->s;
    int32_t nj = c->n_junctions, n = s->n, cap = 0;
    c->group_node = fs_malloc(((size_t)c->levels * (size_t)nj * 3 + 1) * sizeof *c->group_node);
    c->center_node = fs_malloc(((size_t)c->levels * (size_t)n + 1) * sizeof *c->center_node);
    for (int level = 0; level < c->levels; level++) {
        double sk = c->shrink_level[level];
        for (int32_t j = 0; j < nj; j++) {
            const junction *jn = c->junctions + j;
            int root[3];
            junction_groups(c, jn, level, root);
            double thick = 0.0;
            for (int m = 0; m < jn->count; m++)
                thick += s->thick[jn->node[m]];
            thick /= jn->count;
            double z = level_height(c, level, thick);
            int32_t *slot = c->group_node + ((size_t)level * (size_t)nj + (size_t)j) * 3;
            for (int m = 0; m < 3; m++)
                slot[m] = -1;
            for (int m = 0; m < jn->count; m++) {
                if (root[m] != m)
                    continue;
                double base[3], init[3], ref[3];
                group_position(c, jn, root, m, level, base);
                lift(c, base, z * (1.0 - sk), init);
                lift(c, jn->ref, z, ref);
                slot[m] = add_post_node(c, &cap, level, init, ref);
            }
            for (int m = 0; m < jn->count; m++)
                slot[m] = slot[root[m]];
        }
        for (int32_t i = 0; i < n; i++) {
            int layer = level > 0 ? level - 1 : 0;
            static const int8_t zero[2] = {0, 0};
            double base[3], init[3], ref[3], X[3];
            member_world(c, layer, i, zero, base);
            const double *p = c->m->pos + 3 * (size_t)i;
            X[0] = p[0];
            X[1] = p[1];
            X[2] = c->sphere ? p[2] : 0.0;
            double z = level_height(c, level, s->thick[i]);
            lift(c, base, z * (1.0 - sk), init);
            lift(c, X, z, ref);
            c->center_node[(size_t)level * (size_t)n + (size_t)i] = add_post_node(c, &cap, level, init, ref);
        }
    }
}

/* The post node of cell corner k at a level, and the world offset that brings it into the cell's frame. */
static int32_t corner_node(const post_ctx *c, const corner *k, int level, double *offset)
{
    double w[3];
    shift_world(c, corner_shift(c, k), w);
    for (int q = 0; q < 3; q++)
        offset[q] = -w[q];
    return c->group_node[((size_t)level * (size_t)c->n_junctions + (size_t)k->junction) * 3 + (size_t)k->member];
}

/* Reference offset (domain coordinates) of a corner's junction frame seen from the cell. */
static void corner_ref_offset(const post_ctx *c, const corner *k, double *offset)
{
    const int8_t *sh = corner_shift(c, k);
    offset[0] = -sh[0] * c->period[0];
    offset[1] = -sh[1] * c->period[1];
    offset[2] = 0.0;
}

/* ---- the post network ---- */

typedef struct {
    int32_t a, b;
    double off[3];     /* world offset added to b (minus a's) */
    double rest;
    double k;
} post_spring;

typedef struct {
    post_spring *v;
    int32_t n, cap;
} spring_list;

static void push_spring(const post_ctx *c, spring_list *list, int32_t a, const double *oa, const double *ra_off,
                        int32_t b, const double *ob, const double *rb_off, double E, double volume)
{
    if (a == b)
        return;
    FS_ARRAY_RESERVE(list->v, list->cap, list->n + 1, 4096);
    post_spring *sp = list->v + list->n;
    sp->a = a;
    sp->b = b;
    for (int q = 0; q < 3; q++)
        sp->off[q] = ob[q] - oa[q];
    double d[3];
    const double *ra = c->refp + 3 * (size_t)a, *rb = c->refp + 3 * (size_t)b;
    for (int q = 0; q < 3; q++)
        d[q] = (rb[q] + rb_off[q]) - (ra[q] + ra_off[q]);
    double l = fs_norm3(d);
    /* two junctions that nearly coincide (a nearly cocircular quad of masses) add nothing but a stiff,
     * ill-conditioned spring */
    if (!(l > 0.02 * c->spacing))
        return;
    double shrink = 0.5 * (c->shrink_level[c->post_level[a]] + c->shrink_level[c->post_level[b]]);
    double lk = l > 0.2 * c->spacing ? l : 0.2 * c->spacing;
    sp->rest = (1.0 - shrink) * l;
    sp->k = E * volume / (lk * lk);
    list->n++;
}

/* Distance (cm, along mesh edges) from every mass to the nearest crack of the bottom layer. */
static double *crack_distance(const post_ctx *c)
{
    const fs_springs *s = c->s;
    const fs_mesh *m = c->m;
    int32_t n = s->n;
    double *dist = fs_malloc(((size_t)n + 1) * sizeof *dist);
    for (int32_t i = 0; i < n; i++)
        dist[i] = INFINITY;
    /* Bellman-Ford sweeps over the edges until nothing changes (the distances only need to be good
     * within a few cells of the cracks, and a few sweeps give them) */
    for (int32_t e = 0; e < s->n_edges; e++) {
        if (!s->broken[e] || m->edge[2 * e] == m->edge[2 * e + 1])
            continue;
        double half = 0.5 * s->rest0[e];
        for (int k = 0; k < 2; k++) {
            int32_t i = m->edge[2 * e + k];
            if (half < dist[i])
                dist[i] = half;
        }
    }
    for (int sweep = 0; sweep < 64; sweep++) {
        bool changed = false;
        for (int32_t e = 0; e < s->n_edges; e++) {
            int32_t a = m->edge[2 * e], b = m->edge[2 * e + 1];
            double l = s->rest0[e];
            if (dist[a] + l < dist[b]) {
                dist[b] = dist[a] + l;
                changed = true;
            }
            if (dist[b] + l < dist[a]) {
                dist[a] = dist[b] + l;
                changed = true;
            }
        }
        if (!changed)
            break;
    }
    return dist;
}

/* Builds, relaxes (unless flat) and leaves the post network's positions in net->x. */
static int relax_post(post_ctx *c, fs_spring_net *net)
{
    const fs_springs *s = c->s;
    int32_t n = s->n;
    fs_springs_post mode = s->setup.springs.post;
    double E = s->setup.material.young * 100.0;
    spring_list list = {NULL, 0, 0};
    for (int32_t i = 0; i < n; i++) {
        int32_t k0 = c->corner_start[i], k1 = c->corner_start[i + 1], nk = k1 - k0;
        static const double zero[3] = {0.0, 0.0, 0.0};
        for (int32_t kk = 0; kk < nk; kk++) {
            const corner *ka = c->corners + k0 + kk, *kb = c->corners + k0 + (kk + 1) % nk;
            double ra[3], rb[3];
            corner_ref_offset(c, ka, ra);
            corner_ref_offset(c, kb, rb);
            /* prism volume from the reference triangle (site, a, b) times the layer height */
            const double *site = c->refp + 3 * (size_t)c->center_node[i];
            const double *pa = c->refp + 3 * (size_t)corner_node(c, ka, 0, (double[3]){0}),
                         *pb = c->refp + 3 * (size_t)corner_node(c, kb, 0, (double[3]){0});
            double ea[3], eb[3], cr[3];
            for (int q = 0; q < 3; q++) {
                ea[q] = pa[q] + ra[q] - site[q];
                eb[q] = pb[q] + rb[q] - site[q];
            }
            fs_cross3(cr, ea, eb);
            double area = 0.5 * fs_norm3(cr);
            double floor_area = 1e-4 * (fs_dot3(ea, ea) + fs_dot3(eb, eb));
            if (area < floor_area)
                area = floor_area;
            for (int l = 0; l < c->L; l++) {
                double oa0[3], ob0[3], oa1[3], ob1[3];
                int32_t A0 = corner_node(c, ka, l, oa0), B0 = corner_node(c, kb, l, ob0);
                int32_t A1 = corner_node(c, ka, l + 1, oa1), B1 = corner_node(c, kb, l + 1, ob1);
                int32_t C0 = c->center_node[(size_t)l * (size_t)n + (size_t)i];
                int32_t C1 = c->center_node[(size_t)(l + 1) * (size_t)n + (size_t)i];
                double h = c->H * s->thick[i] / c->L;
                double vol = area * h;
                /* top face edges, the side edge of b, the two face diagonals; the bottom face only
                 * for the lowest layer; the centre column once per cell */
                push_spring(c, &list, A1, oa1, ra, B1, ob1, rb, E, vol);
                push_spring(c, &list, C1, zero, zero, B1, ob1, rb, E, vol);
                push_spring(c, &list, B0, ob0, rb, B1, ob1, rb, E, vol);
                push_spring(c, &list, A0, oa0, ra, B1, ob1, rb, E, vol);
                push_spring(c, &list, C0, zero, zero, B1, ob1, rb, E, vol);
                if (l == 0) {
                    push_spring(c, &list, A0, oa0, ra, B0, ob0, rb, E, vol);
                    push_spring(c, &list, C0, zero, zero, B0, ob0, rb, E, vol);
                }
                if (kk == 0)
                    push_spring(c, &list, C0, zero, zero, C1, zero, zero, E, vol * nk);
            }
        }
    }

    /* fixed bottom; in curl mode the bottom near cracks comes free, held by weak tethers */
    uint8_t *fixed = fs_calloc((size_t)c->n_post + 1, 1);
    uint8_t *peeled_node = fs_calloc((size_t)c->n_post + 1, 1);
    double *dist = mode == FS_SPRINGS_POST_CURL ? crack_distance(c) : NULL;
    double peel = s->setup.springs.peel;
    for (int32_t p = 0; p < c->n_post; p++)
        fixed[p] = c->post_level[p] == 0;
    if (dist) {
        /* a bottom node comes free when every cell it belongs to is within peel of a crack */
        for (int32_t p = 0; p < c->n_post; p++)
            peeled_node[p] = c->post_level[p] == 0;
        for (int32_t i = 0; i < n; i++) {
            bool peeled = dist[i] <= peel;
            if (peeled)
                continue;
            peeled_node[c->center_node[i]] = 0;
            for (int32_t kk = c->corner_start[i]; kk < c->corner_start[i + 1]; kk++) {
                double off[3];
                peeled_node[corner_node(c, c->corners + kk, 0, off)] = 0;
            }
        }
        for (int32_t p = 0; p < c->n_post; p++)
            if (peeled_node[p])
                fixed[p] = 0;
    }
    int32_t n_tethers = 0;
    for (int32_t p = 0; p < c->n_post; p++)
        n_tethers += peeled_node[p];

    fs_spring_net_init(net, 3, c->n_post, list.n, n_tethers);
    memcpy(net->x, c->init, 3 * (size_t)c->n_post * sizeof *net->x);
    memcpy(net->fixed, fixed, (size_t)c->n_post);
    double k_mean = 0.0;
    for (int32_t k = 0; k < list.n; k++) {
        const post_spring *sp = list.v + k;
        net->node[2 * (size_t)k] = sp->a;
        net->node[2 * (size_t)k + 1] = sp->b;
        memcpy(net->offset + 3 * (size_t)k, sp->off, sizeof sp->off);
        net->rest[k] = sp->rest;
        net->k[k] = sp->k;
        k_mean += sp->k;
    }
    k_mean /= list.n > 0 ? list.n : 1;
    int32_t a = 0;
    for (int32_t p = 0; p < c->n_post; p++)
        if (peeled_node[p]) {
            net->anchor_node[a] = p;
            memcpy(net->anchor_at + 3 * (size_t)a, c->init + 3 * (size_t)p, 3 * sizeof(double));
            net->anchor_k[a] = 1e-3 * k_mean;
            a++;
        }
    free(fixed);
    free(peeled_node);
    free(dist);
    /* the force unit: a mean spring stretched by its own length */
    double force = 0.0;
    for (int32_t k = 0; k < list.n; k++)
        force += list.v[k].k * list.v[k].rest;
    force /= list.n > 0 ? list.n : 1;
    free(list.v);
    if (mode == FS_SPRINGS_POST_FLAT)
        return 0;
    if (fs_spring_net_prepare(net) < 0)
        return -1;
    /* the shapes need strains to about 1e-4, far below a pixel */
    double tol = 1e-4 * force;
    fs_spring_relax_info info;
    if (fs_spring_net_relax(net, tol, 400, &info) < 0)
        return -1;
    fs_debug("springs: post-process of %d nodes, %d springs relaxed in %d steps (%d factorizations)",
             (int)c->n_post, (int)net->n_springs, info.iterations, info.factorizations);
    return 0;
}

/* ---- emission ---- */

/* Texture coordinates and height of a world point (cell frame) at the final time. */
static void to_texture(const post_ctx *c, const double *p, double *uv, double *height)
{
    const fs_domain *d = &c->m->domain;
    if (!c->sphere) {
        double q[3] = {p[0], p[1], 0.0}, back[3];
        fs_growth_flow(&c->s->growth, q, c->t, 0.0, back);
        uv[0] = back[0] / fs_domain_extent_x(d);
        uv[1] = back[1] / fs_domain_extent_y(d);
        *height = p[2];
        return;
    }
    double nrm[3];
    unit(p, nrm);
    double rho = 1.0 / sqrt((nrm[0] * nrm[0] + nrm[1] * nrm[1]) / (c->a_axis * c->a_axis) +
                            nrm[2] * nrm[2] / (c->c_axis * c->c_axis));
    *height = fs_norm3(p) - rho;
    double back[3];
    fs_growth_flow(&c->s->growth, p, c->t, 0.0, back);
    double r = fs_norm3(back);
    for (int q = 0; q < 3; q++)
        back[q] *= d->radius / (r > 0.0 ? r : 1.0);
    fs_domain_to_uv(d, back, uv);
}

typedef struct {
    double p[3];      /* world, cell frame */
    double crack, cell, shade;
} emit_vertex;

static double wrap_near(double u, double ref) { return u - floor(u - ref + 0.5); }

static void put_vertex(fs_surface *out, double u, double v, double h, const emit_vertex *e)
{
    fs_surface_add_vertex(out, u, v, h > 0.0 ? h : 0.0, e->crack, e->cell, e->shade);
}

/* A triangle of the sphere containing a pole: three columns from its edges to the pole's row. */
static bool emit_pole(const post_ctx *c, fs_surface *out, const emit_vertex *v[3])
{
    for (int pole = 0; pole < 2; pole++) {
        double P[3] = {0.0, 0.0, pole ? 1.0 : -1.0};
        bool inside = true;
        for (int k = 0; k < 3; k++) {
            double cr[3];
            fs_cross3(cr, v[k]->p, v[(k + 1) % 3]->p);
            if (fs_dot3(cr, P) < 0.0)
                inside = false;
        }
        if (!inside)
            continue;
        double vp = pole ? 1.0 : 0.0;
        const int steps = 8;
        for (int k = 0; k < 3; k++) {
            const emit_vertex *a = v[k], *b = v[(k + 1) % 3];
            double u_prev = 0.0;
            int32_t base = out->n_verts;
            for (int j = 0; j <= steps; j++) {
                double t = (double)j / steps, p[3], uv[2], h;
                for (int q = 0; q < 3; q++)
                    p[q] = a->p[q] + (b->p[q] - a->p[q]) * t;
                to_texture(c, p, uv, &h);
                double u = uv[0];
                if (j > 0) {
                    double du = u - u_prev;
                    du -= floor(du);
                    if (!pole)
                        du -= 1.0;
                    u = u_prev + du;
                }
                u_prev = u;
                emit_vertex e = *a;
                e.crack = a->crack + (b->crack - a->crack) * t;
                put_vertex(out, u, uv[1], h, &e);
                put_vertex(out, u, vp, h, &e);
            }
            for (int j = 0; j < steps; j++) {
                int32_t i0 = base + 2 * j;
                fs_surface_add_tri(out, i0, i0 + 2, i0 + 3);
                fs_surface_add_tri(out, i0, i0 + 3, i0 + 1);
            }
        }
        return true;
    }
    return false;
}

static void emit_tri(const post_ctx *c, fs_surface *out, const emit_vertex *a, const emit_vertex *b,
                     const emit_vertex *d, int depth, bool face)
{
    const emit_vertex *v[3] = {a, b, d};
    double uv[3][2], h[3];
    for (int k = 0; k < 3; k++)
        to_texture(c, v[k]->p, uv[k], &h[k]);
    if (c->sphere) {
        if (face && depth == 0 && emit_pole(c, out, v))
            return;
        for (int k = 1; k < 3; k++)
            uv[k][0] = wrap_near(uv[k][0], uv[0][0]);
        /* split while the equirectangular map bends the triangle noticeably */
        double span = 0.0;
        for (int k = 0; k < 3; k++)
            span = fmax(span, fabs(uv[k][0] - uv[(k + 1) % 3][0]));
        double lat = fmax(fabs(uv[0][1] - 0.5), fmax(fabs(uv[1][1] - 0.5), fabs(uv[2][1] - 0.5)));
        if (depth < 4 && span * (1.0 + 4.0 * lat) > 0.02) {
            emit_vertex m[3];
            for (int k = 0; k < 3; k++) {
                m[k] = *v[k];
                for (int q = 0; q < 3; q++)
                    m[k].p[q] = 0.5 * (v[k]->p[q] + v[(k + 1) % 3]->p[q]);
                m[k].crack = 0.5 * (v[k]->crack + v[(k + 1) % 3]->crack);
            }
            emit_tri(c, out, a, &m[0], &m[2], depth + 1, face);
            emit_tri(c, out, &m[0], b, &m[1], depth + 1, face);
            emit_tri(c, out, &m[2], &m[1], d, depth + 1, face);
            emit_tri(c, out, &m[0], &m[1], &m[2], depth + 1, face);
            return;
        }
    }
    int32_t base = out->n_verts;
    for (int k = 0; k < 3; k++)
        put_vertex(out, uv[k][0], uv[k][1], h[k], v[k]);
    fs_surface_add_tri(out, base, base + 1, base + 2);
}

/* Position of post node p seen from a cell, with the offset. */
static void node_pos(const fs_spring_net *net, int32_t p, const double *off, double *out)
{
    for (int q = 0; q < 3; q++)
        out[q] = net->x[3 * (size_t)p + q] + off[q];
}

/* The member of corner k's junction that is the cell across mesh edge `edge` from k's own (an edge
 * of the junction at k's member), or -1 if none. */
static int across_member(const post_ctx *c, const corner *k, int32_t edge)
{
    const junction *jn = c->junctions + k->junction;
    int m = k->member;
    if (edge < 0)
        return -1;
    if (jn->count == 3)
        return jn->edge[m] == edge ? (m + 1) % 3 : (jn->edge[(m + 2) % 3] == edge ? (m + 2) % 3 : -1);
    return jn->count == 2 && jn->edge[0] == edge ? 1 - m : -1;
}

/* Whether the cell of the polygon side from corner ka to kb shares the nodes at both of the side's
 * junctions with its neighbour across the side, at level: there the two cells are joined, whatever
 * the spring between them. */
static bool side_joined(const post_ctx *c, const corner *ka, const corner *kb, int level)
{
    const corner *k[2] = {ka, kb};
    for (int q = 0; q < 2; q++) {
        int other = across_member(c, k[q], ka->edge_after);
        size_t base = ((size_t)level * (size_t)c->n_junctions + (size_t)k[q]->junction) * 3;
        if (other < 0 || c->group_node[base + (size_t)k[q]->member] != c->group_node[base + (size_t)other])
            return false;
    }
    return true;
}

/* Twice the signed area of (a, b, d) in texture space (plane and cylinder). */
static double uv_area2(const double *a, const double *b, const double *d)
{
    return (b[0] - a[0]) * (d[1] - a[1]) - (b[1] - a[1]) * (d[0] - a[0]);
}

/* design: a cell's top is a fan from its centre node to its corners, but the relaxed centre can
 * leave the part of the polygon from which every side is seen (the kernel), and a fan triangle then
 * folds over its side, drawing a flap beyond the cell over the crack. Such a top (plane and
 * cylinder) is instead cut into ears of its corner polygon, the centre splitting the ear that holds
 * it (or left out if it lies outside the polygon). Returns true if the fan is fine and nothing was
 * emitted; false when the top was emitted here. */
static bool emit_top_folded(const post_ctx *c, fs_surface *out, const emit_vertex *centre, const emit_vertex *ring,
                            int32_t nk)
{
    if (c->sphere || nk > 64)
        return true;
    double uv[65][2], h;
    to_texture(c, centre->p, uv[64], &h);
    for (int32_t k = 0; k < nk; k++)
        to_texture(c, ring[k].p, uv[k], &h);
    bool folded = false;
    for (int32_t k = 0; k < nk && !folded; k++)
        folded = uv_area2(uv[64], uv[k], uv[(k + 1) % nk]) <= 0.0;
    if (!folded)
        return true;
    int32_t idx[64], n = nk, ears[64][3], n_ears = 0;
    for (int32_t k = 0; k < nk; k++)
        idx[k] = k;
    while (n > 3) {
        int32_t ear = -1;
        for (int32_t k = 0; k < n && ear < 0; k++) {
            const double *a = uv[idx[(k + n - 1) % n]], *b = uv[idx[k]], *d = uv[idx[(k + 1) % n]];
            if (uv_area2(a, b, d) <= 0.0)
                continue;
            bool empty = true;
            for (int32_t j = 0; j < n && empty; j++) {
                if (j == k || j == (k + 1) % n || j == (k + n - 1) % n)
                    continue;
                const double *x = uv[idx[j]];
                empty = !(uv_area2(a, b, x) >= 0.0 && uv_area2(b, d, x) >= 0.0 && uv_area2(d, a, x) >= 0.0);
            }
            if (empty)
                ear = k;
        }
        if (ear < 0)
            return true; /* not a simple polygon: keep the fan */
        ears[n_ears][0] = idx[(ear + n - 1) % n];
        ears[n_ears][1] = idx[ear];
        ears[n_ears][2] = idx[(ear + 1) % n];
        n_ears++;
        for (int32_t j = ear; j + 1 < n; j++)
            idx[j] = idx[j + 1];
        n--;
    }
    if (uv_area2(uv[idx[0]], uv[idx[1]], uv[idx[2]]) <= 0.0)
        return true; /* a polygon that crosses itself (a corner pushed over a side): keep the fan */
    memcpy(ears[n_ears++], idx, sizeof ears[0]);
    bool placed = false;
    for (int32_t e = 0; e < n_ears; e++) {
        const emit_vertex *v[3] = {ring + ears[e][0], ring + ears[e][1], ring + ears[e][2]};
        bool inside = !placed;
        for (int k = 0; k < 3 && inside; k++)
            inside = uv_area2(uv[ears[e][k]], uv[ears[e][(k + 1) % 3]], uv[64]) > 0.0;
        if (!inside) {
            emit_tri(c, out, v[0], v[1], v[2], 0, true);
            continue;
        }
        placed = true;
        for (int k = 0; k < 3; k++)
            emit_tri(c, out, centre, v[k], v[(k + 1) % 3], 0, true);
    }
    return false;
}

static void emit(const post_ctx *c, const fs_spring_net *net, fs_surface *out)
{
    const fs_springs *s = c->s;
    int32_t n = s->n;
    int32_t *label = fs_malloc(((size_t)n + 1) * sizeof *label);
    fs_springs_fragments(s, label);
    uint64_t seed = s->setup.seed;
    int top = c->L;
    emit_vertex *ring = NULL;
    int32_t cap_ring = 0;
    for (int32_t i = 0; i < n; i++) {
        int32_t k0 = c->corner_start[i], k1 = c->corner_start[i + 1], nk = k1 - k0;
        if (nk < 3)
            continue;
        emit_vertex cell_v = {{0.0, 0.0, 0.0}, 0.0, (double)(label[i] % 65535 + 1), 0.0};
        cell_v.shade = 0.75 * (2.0 * fs_rand01(seed, FS_RNG_CELL_COLOR, (uint64_t)label[i]) - 1.0) +
                       0.25 * (2.0 * fs_rand01(seed, FS_RNG_CELL_COLOR, (uint64_t)n + (uint64_t)i) - 1.0);
        emit_vertex wall_v = {{0.0, 0.0, 0.0}, 1.0, 0.0, 0.0};
        static const double zero[3] = {0.0, 0.0, 0.0};
        emit_vertex centre = cell_v;
        node_pos(net, c->center_node[(size_t)top * (size_t)n + (size_t)i], zero, centre.p);
        if (nk > cap_ring) {
            cap_ring = nk;
            ring = fs_realloc(ring, (size_t)cap_ring * sizeof *ring);
        }
        for (int32_t kk = 0; kk < nk; kk++) {
            double o[3];
            ring[kk] = cell_v;
            node_pos(net, corner_node(c, c->corners + k0 + kk, top, o), o, ring[kk].p);
        }
        bool fan = emit_top_folded(c, out, &centre, ring, nk);
        for (int32_t kk = 0; kk < nk; kk++) {
            const corner *ka = c->corners + k0 + kk, *kb = c->corners + k0 + (kk + 1) % nk;
            double oa[3], ob[3];
            if (fan)
                emit_tri(c, out, &centre, ring + kk, ring + (kk + 1) % nk, 0, true);
            /* open walls: on a border, or down through the layers whose spring broke, unless the
             * cells still share their nodes at both ends above and below the layer (a broken
             * spring whose junctions the other springs around them hold together: the wall would
             * have no width, and the two cells would each draw it) */
            for (int l = c->L - 1; l >= 0; l--) {
                bool open = ka->edge_after < 0 || !intact(c, l, ka->edge_after);
                if (!open || (side_joined(c, ka, kb, l + 1) && side_joined(c, ka, kb, l)))
                    continue;
                emit_vertex a1 = wall_v, b1 = wall_v, a0 = wall_v, b0 = wall_v;
                node_pos(net, corner_node(c, ka, l + 1, oa), oa, a1.p);
                node_pos(net, corner_node(c, kb, l + 1, ob), ob, b1.p);
                node_pos(net, corner_node(c, ka, l, oa), oa, a0.p);
                node_pos(net, corner_node(c, kb, l, ob), ob, b0.p);
                emit_tri(c, out, &a1, &b1, &b0, 0, false);
                emit_tri(c, out, &a1, &b0, &a0, 0, false);
            }
        }
    }
    free(ring);
    free(label);
}

int fs_springs_surface(const fs_springs *s, fs_surface *out)
{
    post_ctx c;
    memset(&c, 0, sizeof c);
    c.s = s;
    c.m = s->mesh;
    c.sphere = s->dim == 3;
    c.L = s->layers;
    c.levels = s->layers + 1;
    c.period[0] = s->ext[0];
    c.period[1] = s->ext[1];
    c.t = s->time;
    fs_growth_jacobian(&s->growth, 0.0, c.t, c.J);
    c.H = fs_material_thickness(&s->setup.material, c.t, s->setup.time.end);
    double top = fs_pwl_eval(&s->setup.shrink.top, c.t), bottom = fs_pwl_eval(&s->setup.shrink.bottom, c.t);
    for (int k = 0; k < c.levels; k++)
        c.shrink_level[k] = bottom + (top - bottom) * k / c.L;
    for (int32_t e = 0; e < s->n_edges; e++)
        c.spacing += s->rest0[e];
    c.spacing /= s->n_edges > 0 ? s->n_edges : 1;
    c.a_axis = fs_growth_radius(&s->growth, c.t);
    c.c_axis = fs_growth_radius_z(&s->growth, c.t);

    int rc = build_junctions(&c);
    fs_spring_net net;
    memset(&net, 0, sizeof net);
    if (rc == 0) {
        build_nodes(&c);
        rc = relax_post(&c, &net);
    }
    if (rc == 0)
        emit(&c, &net, out);
    fs_spring_net_free(&net);
    free(c.junctions);
    free(c.corner_start);
    free(c.corners);
    free(c.group_node);
    free(c.center_node);
    free(c.init);
    free(c.refp);
    free(c.post_level);
    return rc;
}
