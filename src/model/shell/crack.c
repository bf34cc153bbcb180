/* Cracks in the shell: a face over its threshold is cut along its crack line (through a vertex, or on from a crack tip), vertices budge onto the line, and the mesh separates by the shared surgery (geom/cut.h). */
#include "model/shell/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/vec.h"
#include "fracture/rank.h"
#include "fracture/separation.h"
#include "fracture/split.h"
#include "geom/cut.h"

/* design: Gingold et al. §"Discretization of fracture" and Fig. 6: a face over its threshold breaks
 * along the line normal to its principal direction through the one vertex v0 whose line crosses the
 * face (the middle vertex along the principal direction), the crack running from v0 across the
 * opposite edge, which is split. Where v0 is inside the material (its fan closed) the line runs on
 * through v0 into the sector across it, so the crack opens: v0 is duplicated into the two sides
 * (fs_cut_duplicate_node) and the far ends, the new vertices on the split edges, are the crack's tips;
 * where v0 is already on a border or a crack, the one segment into the face opens it. A face with a
 * crack tip for a corner continues that crack from the tip (the ray of its crack line that goes on
 * the way the crack came; thesis §5.7.3), so cracks grow from their tips instead of starting anew
 * beside them. A crack line that passes within [shell] budge of an edge's end does not split the
 * edge: the end is budged onto the line (Fig. 7; moved in the rest shape, its strains absorbed into
 * the plastic strain so that nothing changes but the discretisation) and the crack runs along the
 * existing edge, or, when the end cannot move (on a border, a crack or a UV seam, or held), it runs
 * to the end as it is. A crack that reaches a border or another crack duplicates the vertex it ends
 * at as well, joining the other crack. */

/* Faces cut in one batch, between two equilibria. */
#define MAX_BATCH 64

/* The faces at node v now (ascending). */
static int32_t fan_of(const fs_cut *c, int32_t v, int32_t **fan, int32_t *cap)
{
    return fs_cut_tris_at(c, v, fan, cap);
}

/* Whether the faces around v close around it (every edge at v shared by two of them). */
static bool closed_fan(const fs_mesh *m, int32_t v, const int32_t *fan, int32_t n)
{
    for (int32_t q = 0; q < n; q++) {
        int32_t t = fan[q];
        int k = fs_mesh_corner_of(m, t, v);
        if (m->adj[3 * (size_t)t + k] < 0 || m->adj[3 * (size_t)t + (k + 2) % 3] < 0)
            return false;
    }
    return n > 0;
}

/* Where the ray from node v along dir (3-D, tangent) leaves v's fan: the face, the corner of v in it,
 * the parameter along the opposite edge (from the corner after v's) and the kind of hit; each face
 * judged in its own rest frame. The first face (ascending) that holds the ray, or if none does
 * exactly (the frames of a curved fan disagree by rounding), the one that misses it least. Returns
 * FS_SPLIT_MISS when the ray points out of the material. */
typedef struct {
    int32_t tri;
    int corner;
    double s;
    fs_split_hit kind;
} ray_hit;

static fs_split_hit cast_ray(const fs_shell *s, int32_t v, const double dir[3], const int32_t *fan, int32_t n,
                             ray_hit *hit)
{
    const fs_mesh *m = s->mesh;
    double best = INFINITY;
    hit->kind = FS_SPLIT_MISS;
    for (int32_t q = 0; q < n; q++) {
        int32_t t = fan[q];
        int k = fs_mesh_corner_of(m, t, v);
        const double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
        double pv[3], pa[3], pb[3];
        fs_shell_corner(s, s->rest, t, k, pv);
        fs_shell_corner(s, s->rest, t, (k + 1) % 3, pa);
        fs_shell_corner(s, s->rest, t, (k + 2) % 3, pb);
        double a[2], b[2], d[2] = {fs_dot3(dir, e1), fs_dot3(dir, e2)};
        double da[3], db[3];
        fs_sub3(da, pa, pv);
        fs_sub3(db, pb, pv);
        a[0] = fs_dot3(da, e1), a[1] = fs_dot3(da, e2);
        b[0] = fs_dot3(db, e1), b[1] = fs_dot3(db, e2);
        double sp;
        fs_split_hit h = fs_split_ray_sector(a, b, d, s->cfg.shell.budge, &sp);
        if (h == FS_SPLIT_EDGE) {
            /* nor closer to an end than budge mean edge lengths: no edge shorter than that, so a crack
             * that runs towards a vertex reaches it instead of cutting ever smaller faces */
            double len = hypot(b[0] - a[0], b[1] - a[1]), near = s->cfg.shell.budge * s->unit;
            if (sp * len < near)
                h = FS_SPLIT_AT_A;
            else if ((1.0 - sp) * len < near)
                h = FS_SPLIT_AT_B;
        }
        if (h != FS_SPLIT_MISS) {
            *hit = (ray_hit){t, k, sp, h};
            return h;
        }
        /* how far outside the sector the ray is, in angle (radians, roughly) */
        double la = hypot(a[0], a[1]), lb = hypot(b[0], b[1]), ld = hypot(d[0], d[1]);
        double out = fmax(-(a[0] * d[1] - a[1] * d[0]) / (la * ld), -(d[0] * b[1] - d[1] * b[0]) / (ld * lb));
        double dot = (a[0] + b[0]) * d[0] + (a[1] + b[1]) * d[1];
        if (dot > 0.0 && out < best && out < 1e-6) {
            best = out;
            *hit = (ray_hit){t, k, -1.0, FS_SPLIT_MISS};
        }
    }
    if (best < INFINITY) {
        /* rounding between the frames: cross the nearer end of the opposite edge */
        int32_t t = hit->tri;
        const double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
        double pv[3], pa[3], pb[3], da[3], db[3];
        fs_shell_corner(s, s->rest, t, hit->corner, pv);
        fs_shell_corner(s, s->rest, t, (hit->corner + 1) % 3, pa);
        fs_shell_corner(s, s->rest, t, (hit->corner + 2) % 3, pb);
        fs_sub3(da, pa, pv);
        fs_sub3(db, pb, pv);
        double d[2] = {fs_dot3(dir, e1), fs_dot3(dir, e2)};
        double ca = fs_dot3(da, e1) * d[1] - fs_dot3(da, e2) * d[0];
        hit->s = ca < 0.0 ? 0.0 : 1.0;
        hit->kind = ca < 0.0 ? FS_SPLIT_AT_A : FS_SPLIT_AT_B;
    }
    return hit->kind;
}

/* ---- budging ---- */

/* Whether node w may be budged: inside the material (closed fan), not held, every corner of it at
 * one texture point (not on a UV seam) with no periodic shift, not a crack tip. */
static bool may_budge(const fs_shell *s, int32_t w, const int32_t *fan, int32_t n)
{
    const fs_mesh *m = s->mesh;
    if (s->pin[w] || s->tip_dir[3 * (size_t)w] != 0.0 || s->tip_dir[3 * (size_t)w + 1] != 0.0 ||
        s->tip_dir[3 * (size_t)w + 2] != 0.0 || !closed_fan(m, w, fan, n))
        return false;
    const double *uv0 = NULL;
    for (int32_t q = 0; q < n; q++) {
        int32_t t = fan[q];
        int k = fs_mesh_corner_of(m, t, w);
        for (int j = 0; j < 3; j++)
            if (m->shift[6 * (size_t)t + 2 * j] || m->shift[6 * (size_t)t + 2 * j + 1])
                return false;
        const double *uv = s->uv + 6 * (size_t)t + 2 * k;
        if (uv0 && (uv[0] != uv0[0] || uv[1] != uv0[1]))
            return false;
        uv0 = uv;
    }
    return true;
}

/* The strains of the faces around node w, kept while w moves: the triangles with w as a corner or
 * across an edge from one (their bending strain reads w's dihedral angles). */
static int32_t budge_region(const fs_shell *s, const int32_t *fan, int32_t n, int32_t *out)
{
    const fs_mesh *m = s->mesh;
    int32_t k = 0;
    for (int32_t q = 0; q < n; q++)
        out[k++] = fan[q];
    for (int32_t q = 0; q < n; q++)
        for (int i = 0; i < 3; i++) {
            int32_t u = m->adj[3 * (size_t)fan[q] + i];
            bool seen = u < 0;
            for (int32_t r = 0; r < k && !seen; r++)
                seen = out[r] == u;
            if (!seen)
                out[k++] = u;
        }
    return k;
}

/* The 2x2 tensor a (xx, yy, xy) of the frame (f1, f2) in the frame (e1, e2) of the same plane. */
static void rotate_tensor(const double *f1, const double *f2, const double *e1, const double *e2, const double a[3],
                          double out[3])
{
    double R[4] = {fs_dot3(e1, f1), fs_dot3(e1, f2), fs_dot3(e2, f1), fs_dot3(e2, f2)};
    double A[4] = {a[0], a[2], a[2], a[1]}, T[4], B[4];
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            T[2 * i + j] = R[2 * i] * A[j] + R[2 * i + 1] * A[2 + j];
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++)
            B[2 * i + j] = T[2 * i] * R[2 * j] + T[2 * i + 1] * R[2 * j + 1];
    out[0] = B[0];
    out[1] = B[3];
    out[2] = 0.5 * (B[1] + B[2]);
}

/* Moves node w (rest, current, anchor and texture point) to the point s of the edge from corner
 * ia to corner ia + 1 of face t, absorbing the change of the strains around it in the plastic
 * strain (Gingold et al., Fig. 7). Returns 0 or -1. */
/* Whether moving node w to the rest point p keeps every face of its fan facing the same way with at
 * least a third of its area (a budge must not fold or flatten a face). */
static bool budge_keeps_faces(const fs_shell *s, int32_t w, const double p[3], const int32_t *fan, int32_t n)
{
    const fs_mesh *m = s->mesh;
    for (int32_t q = 0; q < n; q++) {
        int32_t t = fan[q];
        int k = fs_mesh_corner_of(m, t, w);
        double x[3][3], moved[3], d1[3], d2[3], n_old[3], n_new[3];
        for (int c = 0; c < 3; c++)
            fs_shell_corner(s, s->rest, t, c, x[c]);
        fs_sub3(d1, x[1], x[0]);
        fs_sub3(d2, x[2], x[0]);
        fs_cross3(n_old, d1, d2);
        memcpy(moved, p, sizeof moved);
        memcpy(x[k], moved, sizeof moved);
        fs_sub3(d1, x[1], x[0]);
        fs_sub3(d2, x[2], x[0]);
        fs_cross3(n_new, d1, d2);
        double a_old = fs_norm3(n_old);
        if (!(fs_dot3(n_new, n_old) >= a_old * a_old / 3.0))
            return false;
    }
    return true;
}

static int budge(fs_shell *s, int32_t w, int32_t t, int ia, double sp, const int32_t *fan, int32_t n)
{
    fs_mesh *m = s->mesh;
    int32_t *region = fs_malloc(((size_t)n * 4 + 1) * sizeof *region);
    int32_t nr = budge_region(s, fan, n, region);
    double *before = fs_malloc(((size_t)nr * 12 + 1) * sizeof *before);
    fs_shell_update_phi_of(s, s->x, region, nr);
    for (int32_t q = 0; q < nr; q++) {
        double *b = before + 12 * (size_t)q;
        fs_shell_elastic_strains(s, s->x, region[q], b, b + 3);
        memcpy(b + 6, s->frame + 6 * (size_t)region[q], 6 * sizeof *b);
    }
    int ib = (ia + 1) % 3;
    double ra[3], rb[3], xa[3], xb[3];
    fs_shell_corner(s, s->rest, t, ia, ra);
    fs_shell_corner(s, s->rest, t, ib, rb);
    fs_shell_corner(s, s->x, t, ia, xa);
    fs_shell_corner(s, s->x, t, ib, xb);
    int32_t a = m->tri[3 * (size_t)t + ia], b = m->tri[3 * (size_t)t + ib];
    double uv[2];
    for (int k = 0; k < 2; k++)
        uv[k] = s->uv[6 * (size_t)t + 2 * ia + k] + sp * (s->uv[6 * (size_t)t + 2 * ib + k] - s->uv[6 * (size_t)t + 2 * ia + k]);
    for (int k = 0; k < 3; k++) {
        s->rest[3 * (size_t)w + k] = ra[k] + sp * (rb[k] - ra[k]);
        s->x[3 * (size_t)w + k] = xa[k] + sp * (xb[k] - xa[k]);
        double pa = s->anchor0[3 * (size_t)a + k], pb = s->anchor0[3 * (size_t)b + k];
        s->anchor0[3 * (size_t)w + k] = pa + sp * (pb - pa);
        double ma = m->pos[3 * (size_t)a + k], mb = m->pos[3 * (size_t)b + k];
        m->pos[3 * (size_t)w + k] = ma + sp * (mb - ma);
    }
    if (m->domain.type == FS_DOMAIN_SPHERE)
        fs_domain_wrap(&m->domain, m->pos + 3 * (size_t)w);
    for (int32_t q = 0; q < n; q++) {
        int k = fs_mesh_corner_of(m, fan[q], w);
        s->uv[6 * (size_t)fan[q] + 2 * k] = uv[0];
        s->uv[6 * (size_t)fan[q] + 2 * k + 1] = uv[1];
    }
    int rc = fs_shell_rest_geometry_of(s, region, nr);
    if (rc == 0) {
        fs_shell_update_phi_of(s, s->x, region, nr);
        for (int32_t q = 0; q < nr; q++) {
            int32_t u = region[q];
            const double *kept = before + 12 * (size_t)q;
            double em_old[3], ec_old[3], em[3], ec[3];
            const double *f1 = kept + 6, *f2 = kept + 9, *e1 = s->frame + 6 * (size_t)u, *e2 = e1 + 3;
            rotate_tensor(f1, f2, e1, e2, kept, em_old);
            rotate_tensor(f1, f2, e1, e2, kept + 3, ec_old);
            fs_shell_elastic_strains(s, s->x, u, em, ec);
            double *pl = s->plastic + 6 * (size_t)u;
            for (int k = 0; k < 3; k++) {
                pl[k] += em[k] - em_old[k];
                pl[3 + k] += ec[k] - ec_old[k];
            }
        }
        s->counters.budges++;
    }
    free(region);
    free(before);
    return rc;
}

/* ---- bringing the state up to a cut ---- */

/* The mesh as it was when the cut began (the kernel rewrites the corners of the triangles it changes;
 * the state's own arrays are rewritten only by apply_cut). */
typedef struct {
    int32_t *tri;
    int8_t *shift;
} before_cut;

static void before_take(const fs_shell *s, before_cut *b)
{
    const fs_mesh *m = s->mesh;
    size_t n = (size_t)m->n_tris;
    b->tri = fs_malloc(3 * n * sizeof *b->tri);
    b->shift = fs_malloc(6 * n * sizeof *b->shift);
    memcpy(b->tri, m->tri, 3 * n * sizeof *b->tri);
    memcpy(b->shift, m->shift, 6 * n * sizeof *b->shift);
}

static void before_free(before_cut *b)
{
    free(b->tri);
    free(b->shift);
}

/* The ancestors of a cut's faces as they were: texture points, frames and plastic strains. */
typedef struct {
    int32_t n, *tri;
    double *uv, *frame, *plastic;
} ancestors;

static int32_t ancestor_row(const ancestors *a, int32_t t)
{
    for (int32_t q = 0; q < a->n; q++)
        if (a->tri[q] == t)
            return q;
    return -1;
}

/* The period offset (3-D) that brings the point x nearest to y. */
static void nearest_image(const fs_shell *s, const double x[3], const double y[3], double out[3])
{
    double d[3];
    fs_sub3(d, y, x);
    out[0] = out[1] = out[2] = 0.0;
    for (int p = 0; p < 2; p++) {
        const double *P = s->period[p];
        double pp = fs_dot3(P, P);
        if (!(pp > 0.0))
            continue;
        double k = round(fs_dot3(d, P) / pp);
        for (int q = 0; q < 3; q++)
            out[q] += k * P[q];
    }
}

/* Texture point of the point x (rest, 3-D) of ancestor face a (row r of anc) as it was before the cut. */
static void ancestor_uv(const fs_shell *s, const before_cut *b, const ancestors *anc, int32_t a, int32_t r,
                        const double x[3], double uv[2])
{
    double y[3][3], c[3] = {0.0, 0.0, 0.0};
    for (int k = 0; k < 3; k++) {
        int32_t node = b->tri[3 * (size_t)a + k];
        int sx = b->shift[6 * (size_t)a + 2 * k], sy = b->shift[6 * (size_t)a + 2 * k + 1];
        for (int q = 0; q < 3; q++) {
            y[k][q] = s->rest[3 * (size_t)node + q] + sx * s->period[0][q] + sy * s->period[1][q];
            c[q] += y[k][q] / 3.0;
        }
    }
    double off[3], xp[3];
    nearest_image(s, x, c, off);
    for (int q = 0; q < 3; q++)
        xp[q] = x[q] + off[q];
    const double *e1 = anc->frame + 6 * (size_t)r, *e2 = e1 + 3;
    double d1[3], d2[3], dx[3];
    fs_sub3(d1, y[1], y[0]);
    fs_sub3(d2, y[2], y[0]);
    fs_sub3(dx, xp, y[0]);
    double A = fs_dot3(d1, e1), B = fs_dot3(d2, e1), C = fs_dot3(d1, e2), D = fs_dot3(d2, e2);
    double px = fs_dot3(dx, e1), py = fs_dot3(dx, e2), det = A * D - B * C;
    double l1 = (D * px - B * py) / det, l2 = (A * py - C * px) / det, l0 = 1.0 - l1 - l2;
    const double *u = anc->uv + 6 * (size_t)r;
    uv[0] = l0 * u[0] + l1 * u[2] + l2 * u[4];
    uv[1] = l0 * u[1] + l1 * u[3] + l2 * u[5];
}

/* The new nodes' rest, current and anchor positions from their parents (a copy keeps its parent's;
 * a point of an edge is that point of the edge, taken across the seams by the nearest image, placed
 * where the mesh put the node). */
static void new_nodes(fs_shell *s, const fs_cut *c)
{
    const fs_mesh *m = s->mesh;
    for (int32_t i = c->n_nodes_before; i < m->n_nodes; i++) {
        int32_t k = i - c->n_nodes_before, a = c->node_parent[2 * k], b = c->node_parent[2 * k + 1];
        double w = c->node_weight[k];
        double ra[3], rb[3], off[3], raw[3];
        memcpy(ra, s->rest + 3 * (size_t)a, sizeof ra);
        memcpy(rb, s->rest + 3 * (size_t)b, sizeof rb);
        nearest_image(s, rb, ra, off);
        for (int q = 0; q < 3; q++)
            raw[q] = ra[q] + w * (rb[q] + off[q] - ra[q]);
        /* the image the mesh keeps the node in: its position wrapped into the period */
        double wrap[3] = {0.0, 0.0, 0.0};
        if (m->domain.type == FS_DOMAIN_PLANE) {
            wrap[0] = m->pos[3 * (size_t)i] - raw[0];
            wrap[1] = m->pos[3 * (size_t)i + 1] - raw[1];
        } else if (m->domain.type == FS_DOMAIN_CYLINDER) {
            wrap[2] = m->pos[3 * (size_t)i + 1] - raw[2];
        }
        for (int q = 0; q < 3; q++) {
            s->rest[3 * (size_t)i + q] = raw[q] + wrap[q];
            double xa = s->x[3 * (size_t)a + q], xb = s->x[3 * (size_t)b + q] + off[q];
            s->x[3 * (size_t)i + q] = xa + w * (xb - xa) + wrap[q];
            double pa = s->anchor0[3 * (size_t)a + q], pb = s->anchor0[3 * (size_t)b + q];
            s->anchor0[3 * (size_t)i + q] = pa + w * (pb - pa);
            s->f_ext[3 * (size_t)i + q] = 0.0;
            s->tip_dir[3 * (size_t)i + q] = 0.0;
        }
        if (m->domain.type == FS_DOMAIN_PLANE || m->domain.type == FS_DOMAIN_CYLINDER)
            memcpy(s->anchor0 + 3 * (size_t)i, m->pos + 3 * (size_t)i, 3 * sizeof *s->anchor0);
        s->pin[i] = (uint8_t)(s->pin[a] & s->pin[b]);
        s->origin[i] = a == b ? s->origin[a] : i;
    }
}

/* Brings the state up to the cut c: new nodes and faces, the changed faces' texture points and
 * plastic strains (carried from their ancestors' frames), the rest geometry of the faces the cut
 * touched and their hinges. What depends on whole rings of faces (the nodes' areas and normals, the
 * anchors, the DOFs, the mesh's edges and rings) is brought up to date once per batch
 * (batch_done). Returns 0 or -1. */
static int apply_cut(fs_shell *s, const fs_cut *c, const before_cut *b)
{
    fs_mesh *m = s->mesh;
    int32_t n_old = c->n_tris_before, n_new = m->n_tris - n_old;
    fs_shell_reserve(s, m->n_nodes, m->n_tris);
    s->n_nodes = m->n_nodes;
    new_nodes(s, c);
    /* the ancestors' rows before anything is rewritten */
    ancestors anc;
    anc.tri = fs_malloc(((size_t)c->n_changed + n_new + 1) * sizeof *anc.tri);
    anc.n = 0;
    for (int32_t q = 0; q < c->n_changed + n_new; q++) {
        int32_t a = q < c->n_changed ? c->changed_list[q] : c->tri_parent[q - c->n_changed];
        if (ancestor_row(&anc, a) < 0)
            anc.tri[anc.n++] = a;
    }
    anc.uv = fs_malloc(6 * ((size_t)anc.n + 1) * sizeof *anc.uv);
    anc.frame = fs_malloc(6 * ((size_t)anc.n + 1) * sizeof *anc.frame);
    anc.plastic = fs_malloc(6 * ((size_t)anc.n + 1) * sizeof *anc.plastic);
    for (int32_t r = 0; r < anc.n; r++) {
        memcpy(anc.uv + 6 * (size_t)r, s->uv + 6 * (size_t)anc.tri[r], 6 * sizeof *anc.uv);
        memcpy(anc.frame + 6 * (size_t)r, s->frame + 6 * (size_t)anc.tri[r], 6 * sizeof *anc.frame);
        memcpy(anc.plastic + 6 * (size_t)r, s->plastic + 6 * (size_t)anc.tri[r], 6 * sizeof *anc.plastic);
    }
    for (int32_t t = n_old; t < m->n_tris; t++) {
        int32_t a = c->tri_parent[t - n_old];
        s->young[t] = s->young[a];
        s->threshold[t] = s->threshold[a];
        s->thick_factor[t] = s->thick_factor[a];
        for (int i = 0; i < 3; i++)
            s->twin[3 * (size_t)t + i] = -1;
    }
    s->n_tris = m->n_tris;
    int32_t *list = fs_malloc(((size_t)c->n_changed + n_new + 1) * sizeof *list);
    for (int32_t q = 0; q < c->n_changed + n_new; q++)
        list[q] = q < c->n_changed ? c->changed_list[q] : n_old + (q - c->n_changed);
    int rc = fs_shell_rest_geometry_of(s, list, c->n_changed + n_new);
    for (int32_t q = 0; q < c->n_changed + n_new && rc == 0; q++) {
        int32_t t = list[q];
        int32_t a = t < n_old ? t : c->tri_parent[t - n_old], r = ancestor_row(&anc, a);
        for (int k = 0; k < 3; k++) {
            double x[3];
            fs_shell_corner(s, s->rest, t, k, x);
            ancestor_uv(s, b, &anc, a, r, x, s->uv + 6 * (size_t)t + 2 * k);
        }
        const double *f = anc.frame + 6 * (size_t)r, *e = s->frame + 6 * (size_t)t;
        rotate_tensor(f, f + 3, e, e + 3, anc.plastic + 6 * (size_t)r, s->plastic + 6 * (size_t)t);
        rotate_tensor(f, f + 3, e, e + 3, anc.plastic + 6 * (size_t)r + 3, s->plastic + 6 * (size_t)t + 3);
    }
    free(list);
    free(anc.tri);
    free(anc.uv);
    free(anc.frame);
    free(anc.plastic);
    return rc;
}

/* After a batch of cuts: the nodes' areas and normals, the anchors of the new nodes (all, at the
 * current time), the DOFs, the mesh's edges and rings. */
static void batch_done(fs_shell *s)
{
    fs_mesh *m = s->mesh;
    fs_mesh_drop_derived(m);
    fs_mesh_build_edges(m);
    fs_mesh_build_rings(m);
    fs_shell_node_geometry(s);
    fs_shell_set_time(s, s->time);
    fs_shell_number_dofs(s);
    s->rate_valid = false;
}

/* ---- one face ---- */

/* The rest direction (3-D, unit) of the crack line of face t: its frame's in-plane normal of the
 * principal direction m. */
static void crack_line(const fs_shell *s, int32_t t, const double m[2], double dir[3])
{
    const double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
    double d[2];
    fs_split_crack_direction(m, d);
    for (int k = 0; k < 3; k++)
        dir[k] = d[0] * e1[k] + d[1] * e2[k];
}

static bool is_tip(const fs_shell *s, int32_t v)
{
    const double *d = s->tip_dir + 3 * (size_t)v;
    return d[0] != 0.0 || d[1] != 0.0 || d[2] != 0.0;
}

/* One face's cut: the surgery record, and the state before it (taken before the first change of
 * the mesh, after any budge). */
typedef struct {
    fs_cut cut;
    before_cut before;
    bool taken;
    int32_t *fan;
    int32_t cap;
} face_cut;

static void take_before(fs_shell *s, face_cut *fc)
{
    if (!fc->taken)
        before_take(s, &fc->before);
    fc->taken = true;
}

/* The rest geometry the next ray of the same cut reads in v0's fan: the new nodes' positions and the
 * new faces' frames (a face split off lies in its parent's plane). apply_cut brings the rest up to
 * date once the cut is whole. */
static void cut_geometry(fs_shell *s, const fs_cut *c)
{
    const fs_mesh *m = s->mesh;
    fs_shell_reserve(s, m->n_nodes, m->n_tris);
    new_nodes(s, c);
    for (int32_t t = c->n_tris_before; t < m->n_tris; t++)
        memcpy(s->frame + 6 * (size_t)t, s->frame + 6 * (size_t)c->tri_parent[t - c->n_tris_before],
               6 * sizeof *s->frame);
}

/* The end of the ray from v0 that hit h: the split point of the hit edge, or its near end (budged
 * onto the ray when it may move, and only while the mesh is as the state knows it). Returns the end
 * node, or -1 with fs_error. */
static int32_t ray_end(fs_shell *s, face_cut *fc, const ray_hit *h)
{
    fs_mesh *m = s->mesh;
    fs_cut *c = &fc->cut;
    int ia = (h->corner + 1) % 3;
    if (h->kind == FS_SPLIT_EDGE) {
        take_before(s, fc);
        int32_t p = fs_cut_split_edge(c, h->tri, ia, h->s);
        if (fs_cut_update_adjacency(c) < 0)
            return -1;
        cut_geometry(s, c);
        return p;
    }
    int32_t w = m->tri[3 * (size_t)h->tri + (h->kind == FS_SPLIT_AT_A ? ia : (ia + 1) % 3)];
    int32_t n = fan_of(c, w, &fc->fan, &fc->cap);
    if (fc->taken || !(h->s > 0.0 && h->s < 1.0) || !may_budge(s, w, fc->fan, n))
        return w;
    double pa[3], pb[3], p[3];
    fs_shell_corner(s, s->rest, h->tri, ia, pa);
    fs_shell_corner(s, s->rest, h->tri, (ia + 1) % 3, pb);
    for (int k = 0; k < 3; k++)
        p[k] = pa[k] + h->s * (pb[k] - pa[k]);
    if (budge_keeps_faces(s, w, p, fc->fan, n) && budge(s, w, h->tri, ia, h->s, fc->fan, n) < 0)
        return -1;
    return w;
}

/* The stresses the faces had at the batch's equilibrium (fs_shell_face_ratios): faces from n on are
 * the batch's own and have none. */
typedef struct {
    const double *stress;
    int32_t n;
} face_stresses;

/* The unit normal of face t in the rest shape, by its corners' order, into normal. */
static void face_normal(const fs_shell *s, int32_t t, double normal[3])
{
    double p[3][3], ab[3], ac[3];
    for (int k = 0; k < 3; k++)
        fs_shell_corner(s, s->rest, t, k, p[k]);
    fs_sub3(ab, p[1], p[0]);
    fs_sub3(ac, p[2], p[0]);
    fs_cross3(normal, ab, ac);
    double twice = fs_norm3(normal);
    for (int j = 0; j < 3 && twice > 0.0; j++)
        normal[j] /= twice;
}

static int32_t find_in(const int32_t *list, int32_t n, int32_t x)
{
    for (int32_t k = 0; k < n; k++)
        if (list[k] == x)
            return k;
    return -1;
}

/* The fracture plane normal m (3-D, unit) that steers the crack of tip v: the principal plane of the
 * stress averaged ahead of v (fs_tip_stress, the crack arrived along tip_dir[v]) over the faces the
 * material connects to v within 3 radii of it (in the rest shape), each at its centroid with its
 * rest area (area0). False when [fracture] direction_radius is 0 or the average pulls on no plane: then the
 * face's own direction stands. */
static bool tip_average_plane(const fs_shell *s, face_cut *fc, const face_stresses *fs, int32_t v, const double normal[3],
                              double m[3])
{
    double radius = s->cfg.fracture.direction_radius * s->unit;
    if (!(radius > 0.0))
        return false;
    const fs_mesh *mesh = s->mesh;
    int32_t *nodes = NULL, *faces = NULL, n_nodes = 0, n_faces = 0, cap_nodes = 0, cap_faces = 0;
    double *offset = NULL; /* 3 per entry of nodes: its rest position from v, periods unwrapped */
    FS_ARRAY_RESERVE(nodes, cap_nodes, 1, 32);
    offset = fs_realloc(offset, 3 * (size_t)cap_nodes * sizeof *offset);
    nodes[n_nodes++] = v;
    offset[0] = offset[1] = offset[2] = 0.0;
    fs_tip_stress avg;
    fs_tip_stress_begin(&avg, s->tip_dir + 3 * (size_t)v, normal, radius);
    for (int32_t q = 0; q < n_nodes; q++) {
        int32_t n = fan_of(&fc->cut, nodes[q], &fc->fan, &fc->cap);
        for (int32_t i = 0; i < n; i++) {
            int32_t t = fc->fan[i];
            if (t >= fs->n || find_in(faces, n_faces, t) >= 0)
                continue;
            FS_ARRAY_RESERVE(faces, cap_faces, n_faces + 1, 32);
            faces[n_faces++] = t;
            double p[3][3], from[3], centroid[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < 3; k++)
                fs_shell_corner(s, s->rest, t, k, p[k]);
            memcpy(from, p[fs_mesh_corner_of(mesh, t, nodes[q])], sizeof from);
            for (int k = 0; k < 3; k++) {
                double off[3];
                for (int j = 0; j < 3; j++) {
                    off[j] = offset[3 * (size_t)q + j] + p[k][j] - from[j];
                    centroid[j] += off[j] / 3.0;
                }
                int32_t u = mesh->tri[3 * (size_t)t + k];
                if (fs_norm3(off) <= 3.0 * radius && find_in(nodes, n_nodes, u) < 0) {
                    int32_t old_cap = cap_nodes;
                    FS_ARRAY_RESERVE(nodes, cap_nodes, n_nodes + 1, 32);
                    if (cap_nodes != old_cap)
                        offset = fs_realloc(offset, 3 * (size_t)cap_nodes * sizeof *offset);
                    memcpy(offset + 3 * (size_t)n_nodes, off, sizeof off);
                    nodes[n_nodes++] = u;
                }
            }
            double normal_t[3];
            face_normal(s, t, normal_t);
            fs_tip_stress_add(&avg, centroid, normal_t, s->area0[t], fs->stress + 6 * (size_t)t);
        }
    }
    free(nodes);
    free(faces);
    free(offset);
    double mean[6], sigma1;
    if (!fs_tip_stress_mean(&avg, mean))
        return false;
    if (fs_nodal_principal_plane(mean, &sigma1, m) < 0) {
        fs_error_clear();
        return false;
    }
    return sigma1 > 0.0;
}

/* The start of face f's crack: a corner that is a crack tip whose continuation (the ray of the crack
 * line on the way the crack came) leaves through its fan; else the middle corner along the principal
 * direction, with the ray into f first and, when that corner is inside the material, the opposite
 * ray. Fills rays and returns how many (the start in *v0). */
static int crack_start(const fs_shell *s, face_cut *fc, const face_stresses *fs, int32_t f, const double mdir[2],
                       const double dir[3], int32_t *v0, double rays[2][3])
{
    const fs_mesh *m = s->mesh;
    for (int k = 0; k < 3; k++) {
        int32_t v = m->tri[3 * (size_t)f + k];
        if (!is_tip(s, v))
            continue;
        double line[3], plane[3], normal[3];
        memcpy(line, dir, sizeof line);
        const double *e1 = s->frame + 6 * (size_t)f, *e2 = e1 + 3;
        face_normal(s, f, normal);
        if (tip_average_plane(s, fc, fs, v, normal, plane)) {
            /* the averaged plane's trace in f */
            const double in_f[2] = {fs_dot3(plane, e1), fs_dot3(plane, e2)};
            if (hypot(in_f[0], in_f[1]) > 1e-6)
                crack_line(s, f, in_f, line);
        }
        double sign = fs_dot3(line, s->tip_dir + 3 * (size_t)v) < 0.0 ? -1.0 : 1.0;
        for (int q = 0; q < 3; q++)
            rays[0][q] = sign * line[q];
        int32_t n = fan_of(&fc->cut, v, &fc->fan, &fc->cap);
        ray_hit h;
        if (cast_ray(s, v, rays[0], fc->fan, n, &h) != FS_SPLIT_MISS) {
            *v0 = v;
            return 1;
        }
    }
    const double *e1 = s->frame + 6 * (size_t)f, *e2 = e1 + 3;
    double normal[3], p[3][3], proj[3];
    for (int q = 0; q < 3; q++)
        normal[q] = mdir[0] * e1[q] + mdir[1] * e2[q];
    for (int k = 0; k < 3; k++) {
        fs_shell_corner(s, s->rest, f, k, p[k]);
        proj[k] = fs_dot3(p[k], normal);
    }
    int mid = 0;
    for (int k = 0; k < 3; k++)
        if ((proj[k] - proj[(k + 1) % 3]) * (proj[k] - proj[(k + 2) % 3]) <= 0.0)
            mid = k;
    *v0 = m->tri[3 * (size_t)f + mid];
    /* the ray between the two edges of f at the middle corner goes into f */
    double da[3], db[3], nn[3], ca[3], cb[3];
    fs_sub3(da, p[(mid + 1) % 3], p[mid]);
    fs_sub3(db, p[(mid + 2) % 3], p[mid]);
    fs_cross3(nn, da, db);
    fs_cross3(ca, da, dir);
    fs_cross3(cb, dir, db);
    double sign = fs_dot3(ca, nn) >= 0.0 && fs_dot3(cb, nn) >= 0.0 ? 1.0 : -1.0;
    for (int q = 0; q < 3; q++) {
        rays[0][q] = sign * dir[q];
        rays[1][q] = -sign * dir[q];
    }
    int32_t n = fan_of(&fc->cut, *v0, &fc->fan, &fc->cap);
    return closed_fan(m, *v0, fc->fan, n) ? 2 : 1;
}

/* The nodes a cut changed the surroundings of: the corners of its new and changed faces and the
 * parents of its new nodes, appended to *out (count *n, capacity *cap). */
static void changed_nodes(const fs_shell *s, const fs_cut *c, int32_t **out, int32_t *n, int32_t *cap)
{
    const fs_mesh *m = s->mesh;
    int32_t n_new = m->n_tris - c->n_tris_before, n_nodes = m->n_nodes - c->n_nodes_before;
    FS_ARRAY_RESERVE(*out, *cap, *n + 3 * (c->n_changed + n_new) + 2 * n_nodes, 64);
    for (int32_t q = 0; q < c->n_changed + n_new; q++) {
        int32_t t = q < c->n_changed ? c->changed_list[q] : c->n_tris_before + (q - c->n_changed);
        for (int k = 0; k < 3; k++)
            (*out)[(*n)++] = m->tri[3 * (size_t)t + k];
    }
    for (int32_t k = 0; k < 2 * n_nodes; k++)
        (*out)[(*n)++] = c->node_parent[k];
}

/* Cuts face f along its crack line; the nodes it changed the surroundings of are appended to *touched
 * (count *n_touched, capacity *cap_touched). Returns 1 if a crack opened, 0 if nothing changed, -1 on
 * failure. */
static int cut_face(fs_shell *s, const face_stresses *fs, int32_t f, const double mdir[2], int32_t **touched,
                    int32_t *n_touched, int32_t *cap_touched)
{
    fs_mesh *m = s->mesh;
    double dir[3], rays[2][3];
    crack_line(s, f, mdir, dir);
    face_cut fc;
    memset(&fc, 0, sizeof fc);
    fs_cut_begin(&fc.cut, m, NULL, NULL);
    int32_t v0;
    int n_rays = crack_start(s, &fc, fs, f, mdir, dir, &v0, rays);
    int32_t ends[2];
    double end_dir[2][3];
    int n_ends = 0, rc = 0;
    for (int r = 0; r < n_rays; r++) {
        int32_t n = fan_of(&fc.cut, v0, &fc.fan, &fc.cap);
        ray_hit h;
        if (cast_ray(s, v0, rays[r], fc.fan, n, &h) == FS_SPLIT_MISS)
            continue;
        int32_t e = ray_end(s, &fc, &h);
        if (e < 0) {
            rc = -1;
            break;
        }
        if (e == v0 || (n_ends == 1 && ends[0] == e))
            continue;
        ends[n_ends] = e;
        memcpy(end_dir[n_ends++], rays[r], sizeof end_dir[0]);
    }
    int opened = 0;
    bool tip[2] = {false, false};
    if (rc == 0 && n_ends > 0) {
        take_before(s, &fc);
        opened = fs_cut_duplicate_node(&fc.cut, v0, ends, n_ends) > 1;
        if (fs_cut_update_adjacency(&fc.cut) < 0)
            rc = -1;
        /* an end on a border or another crack opens too; inside the material it is a tip */
        for (int k = 0; k < n_ends && rc == 0 && opened; k++) {
            tip[k] = fs_cut_duplicate_node(&fc.cut, ends[k], &v0, 1) == 1;
            if (fs_cut_update_adjacency(&fc.cut) < 0)
                rc = -1;
        }
    }
    if (rc == 0 && fc.taken && (m->n_nodes > fc.cut.n_nodes_before || fc.cut.n_changed > 0)) {
        int32_t origin_v0 = s->origin[v0];
        changed_nodes(s, &fc.cut, touched, n_touched, cap_touched);
        if (apply_cut(s, &fc.cut, &fc.before) < 0)
            rc = -1;
        for (int32_t i = 0; i < s->n_nodes && rc == 0; i++)
            if (s->origin[i] == origin_v0)
                memset(s->tip_dir + 3 * (size_t)i, 0, 3 * sizeof *s->tip_dir);
        for (int k = 0; k < n_ends && rc == 0; k++) {
            if (tip[k])
                memcpy(s->tip_dir + 3 * (size_t)ends[k], end_dir[k], 3 * sizeof *s->tip_dir);
            else
                memset(s->tip_dir + 3 * (size_t)ends[k], 0, 3 * sizeof *s->tip_dir);
        }
    }
    if (opened && rc == 0) {
        s->fractures++;
        s->counters.cuts++;
    }
    if (fc.taken)
        before_free(&fc.before);
    fs_cut_free(&fc.cut);
    free(fc.fan);
    return rc < 0 ? -1 : opened;
}

int32_t fs_shell_fracture_batch(fs_shell *s, int32_t **seeds, int32_t *n_seeds)
{
    int32_t n = s->n_tris;
    double *ratio = fs_malloc(((size_t)n + 1) * sizeof *ratio);
    double *mdir = fs_malloc(2 * ((size_t)n + 1) * sizeof *mdir);
    double *stress = fs_malloc(6 * ((size_t)n + 1) * sizeof *stress);
    fs_shell_face_ratios(s, ratio, mdir, stress);
    const face_stresses stresses = {stress, n};
    int32_t n_cand = 0;
    int32_t *cand = fs_malloc(((size_t)n + 1) * sizeof *cand);
    for (int32_t t = 0; t < n; t++)
        if (ratio[t] > 1.0)
            cand[n_cand++] = t;
    double *cr = fs_malloc(((size_t)n_cand + 1) * sizeof *cr);
    uint64_t *cid = fs_malloc(((size_t)n_cand + 1) * sizeof *cid);
    for (int32_t q = 0; q < n_cand; q++) {
        cr[q] = ratio[cand[q]];
        cid[q] = (uint64_t)cand[q];
    }
    /* faces near a cut are skipped until the next equilibrium: their stresses are out of date */
    int32_t *changed = NULL, n_changed = 0, cap_changed = 0;
    uint8_t *near_mark = fs_calloc((size_t)s->n_nodes + 1, 1);
    int32_t n_mark = s->n_nodes;
    int32_t cuts = 0;
    for (int32_t k = 0; k < MAX_BATCH; k++) {
        int32_t q = fs_rank_pick(cr, cid, n_cand, s->cfg.seed);
        if (q < 0)
            break;
        cr[q] = NAN;
        int32_t f = cand[q];
        bool near = false;
        for (int j = 0; j < 3; j++)
            near |= near_mark[s->mesh->tri[3 * (size_t)f + j]];
        for (int i = 0; i < 3 && !near; i++) {
            int32_t u = s->mesh->adj[3 * (size_t)f + i];
            for (int j = 0; j < 3 && u >= 0; j++)
                near |= near_mark[s->mesh->tri[3 * (size_t)u + j]];
        }
        if (near)
            continue;
        int32_t from = n_changed;
        int rc = cut_face(s, &stresses, f, mdir + 2 * (size_t)f, &changed, &n_changed, &cap_changed);
        if (rc < 0) {
            cuts = -1;
            break;
        }
        cuts += rc;
        if (s->n_nodes > n_mark) {
            near_mark = fs_realloc(near_mark, (size_t)s->n_nodes + 1);
            memset(near_mark + n_mark, 0, (size_t)(s->n_nodes - n_mark) + 1);
            n_mark = s->n_nodes;
        }
        for (int32_t i = from; i < n_changed; i++)
            near_mark[changed[i]] = 1;
    }
    if (n_changed > 0)
        batch_done(s);
    /* the seeds: each changed node once, ascending */
    int32_t ns = 0;
    for (int32_t i = 0; i < n_changed; i++)
        near_mark[changed[i]] = 2;
    for (int32_t i = 0; i < n_mark && i < s->n_nodes; i++)
        if (near_mark[i] == 2)
            changed[ns++] = i;
    *seeds = changed;
    *n_seeds = ns;
    free(near_mark);
    free(ratio);
    free(mdir);
    free(stress);
    free(cand);
    free(cr);
    free(cid);
    return cuts;
}
