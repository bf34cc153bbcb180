/* The discrete shell's rest geometry and its energy: membrane, bending and bond, with the exact gradient and Hessian. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/threads.h"
#include "base/vec.h"

/* ---- geometry ---- */

void fs_shell_corner(const fs_shell *s, const double *p, int32_t t, int c, double out[3])
{
    const fs_mesh *m = s->mesh;
    int32_t node = m->tri[3 * (size_t)t + c];
    int sx = m->shift[6 * (size_t)t + 2 * c], sy = m->shift[6 * (size_t)t + 2 * c + 1];
    for (int k = 0; k < 3; k++)
        out[k] = p[3 * (size_t)node + k] + sx * s->period[0][k] + sy * s->period[1][k];
}

/* The period offset of corner c of triangle t. */
static void corner_offset(const fs_shell *s, int32_t t, int c, double out[3])
{
    const fs_mesh *m = s->mesh;
    int sx = m->shift[6 * (size_t)t + 2 * c], sy = m->shift[6 * (size_t)t + 2 * c + 1];
    for (int k = 0; k < 3; k++)
        out[k] = sx * s->period[0][k] + sy * s->period[1][k];
}

double fs_shell_tri_thickness(const fs_shell *s, int32_t t)
{
    return s->thickness * s->thick_factor[t];
}

/* design: a hinge (an interior edge and its two triangles) is stored at the half-edge 3 t + i (edge i
 * of triangle t, corners i and i + 1) of the smaller of its two half-edges, its owner, so that the
 * hinges of a mesh being cut stay where they are: a cut only rebuilds the hinges of the faces it
 * touched (the mesh's edge list is renumbered by every change). */

int32_t fs_shell_owner(const fs_shell *s, int32_t h)
{
    int32_t w = s->twin[h];
    return w < 0 ? -1 : (w < h ? w : h);
}

/* The 12 coordinates of the hinge owned by half-edge h at node positions p. */
static void hinge_coords(const fs_shell *s, const double *p, int32_t h, double x[12])
{
    const int32_t *n = s->hinge + 4 * (size_t)h;
    const double *off = s->hinge_off + 12 * (size_t)h;
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++)
            x[3 * v + k] = p[3 * (size_t)n[v] + k] + off[3 * v + k];
}

/* The twin of half-edge 3 t + i: the half-edge of the triangle across running the other way, or -1. */
static int32_t find_twin(const fs_mesh *m, int32_t t, int i)
{
    int32_t u = m->adj[3 * (size_t)t + i];
    if (u < 0)
        return -1;
    int32_t a = m->tri[3 * (size_t)t + i], b = m->tri[3 * (size_t)t + (i + 1) % 3];
    for (int j = 0; j < 3; j++)
        if (m->tri[3 * (size_t)u + j] == b && m->tri[3 * (size_t)u + (j + 1) % 3] == a)
            return 3 * u + j;
    return -1;
}

/* The hinge owned by half-edge h (its twin set): nodes a, b (the edge, a -> b in h's triangle), c1
 * (opposite in h's triangle), c2 (opposite in the twin's) and their offsets into h's frame. */
static void build_hinge(fs_shell *s, int32_t h)
{
    const fs_mesh *m = s->mesh;
    int32_t *n = s->hinge + 4 * (size_t)h;
    int32_t w = s->twin[h], t1 = h / 3, t2 = w / 3;
    int i = h % 3, j = w % 3;
    double *off = s->hinge_off + 12 * (size_t)h;
    n[0] = m->tri[3 * (size_t)t1 + i];
    n[1] = m->tri[3 * (size_t)t1 + (i + 1) % 3];
    n[2] = m->tri[3 * (size_t)t1 + (i + 2) % 3];
    n[3] = m->tri[3 * (size_t)t2 + (j + 2) % 3];
    corner_offset(s, t1, i, off);
    corner_offset(s, t1, (i + 1) % 3, off + 3);
    corner_offset(s, t1, (i + 2) % 3, off + 6);
    /* t2's frame moved onto t1's by the difference of node a's offsets in the two (a is t2's corner
     * j + 1) */
    double a2[3], c2[3];
    corner_offset(s, t2, (j + 1) % 3, a2);
    corner_offset(s, t2, (j + 2) % 3, c2);
    for (int k = 0; k < 3; k++)
        off[9 + k] = c2[k] + off[k] - a2[k];
}

/* The rest data of triangle t (frame, Dm^-1, area, bending terms, axes). Returns 0 or -1. */
static int tri_rest(fs_shell *s, int32_t t)
{
    const fs_mesh *m = s->mesh;
    double x[3][3];
    for (int c = 0; c < 3; c++)
        fs_shell_corner(s, s->rest, t, c, x[c]);
    double d1[3], d2[3], n[3];
    fs_sub3(d1, x[1], x[0]);
    fs_sub3(d2, x[2], x[0]);
    fs_cross3(n, d1, d2);
    double l1 = fs_norm3(d1), nn = fs_norm3(n);
    if (!(nn > 1e-14 * l1 * l1) || !(l1 > 0.0)) {
        fs_error(FS_ERR_DATA, "shell: triangle %d (nodes %d, %d, %d) is degenerate", (int)t,
                 (int)m->tri[3 * (size_t)t], (int)m->tri[3 * (size_t)t + 1], (int)m->tri[3 * (size_t)t + 2]);
        return -1;
    }
    double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
    for (int k = 0; k < 3; k++) {
        e1[k] = d1[k] / l1;
        n[k] /= nn;
    }
    fs_cross3(e2, n, e1);
    /* 2-D corners in the frame */
    double p[3][2] = {{0.0, 0.0}, {l1, 0.0}, {fs_dot3(d2, e1), fs_dot3(d2, e2)}};
    double a = p[1][0], b = p[2][0], c = p[1][1], d = p[2][1]; /* Dm = [[a, b], [c, d]] */
    double det = a * d - b * c;
    double *di = s->dm_inv + 4 * (size_t)t;
    di[0] = d / det, di[1] = -b / det, di[2] = -c / det, di[3] = a / det;
    s->area0[t] = 0.5 * det;
    for (int i = 0; i < 3; i++) {
        const double *pa = p[i], *pb = p[(i + 1) % 3];
        double v[2] = {pb[0] - pa[0], pb[1] - pa[1]};
        double l = sqrt(v[0] * v[0] + v[1] * v[1]);
        double tn[2] = {v[1] / l, -v[0] / l}; /* unit normal of the edge in the plane */
        s->bend_c[3 * (size_t)t + i] = l / (2.0 * s->area0[t]);
        double *T = s->bend_t + 9 * (size_t)t + 3 * i;
        T[0] = tn[0] * tn[0], T[1] = tn[1] * tn[1], T[2] = tn[0] * tn[1];
    }
    if (s->axes) {
        /* the domain's axes at the centroid, for the growth eigenstrain */
        double dx[3] = {1.0, 0.0, 0.0}, dy[3] = {0.0, 1.0, 0.0};
        if (m->domain.type == FS_DOMAIN_CYLINDER) {
            double cx = (x[0][0] + x[1][0] + x[2][0]) / 3.0, cy = (x[0][1] + x[1][1] + x[2][1]) / 3.0;
            double r = sqrt(cx * cx + cy * cy);
            dx[0] = -cy / r, dx[1] = cx / r, dx[2] = 0.0;
            dy[0] = 0.0, dy[1] = 0.0, dy[2] = 1.0;
        }
        double *R = s->axes + 4 * (size_t)t;
        R[0] = fs_dot3(e1, dx), R[1] = fs_dot3(e1, dy), R[2] = fs_dot3(e2, dx), R[3] = fs_dot3(e2, dy);
    }
    return 0;
}

/* The rest hinge owned by half-edge h: built and its rest phi. Returns 0 or -1. */
static int hinge_rest(fs_shell *s, int32_t h)
{
    build_hinge(s, h);
    double x[12];
    hinge_coords(s, s->rest, h, x);
    double phi = fs_shell_hinge_phi(x, NULL, NULL);
    if (!isfinite(phi)) {
        const int32_t *n = s->hinge + 4 * (size_t)h;
        fs_error(FS_ERR_DATA, "shell: the rest surface folds back on itself at the edge of nodes %d and %d",
                 (int)n[0], (int)n[1]);
        return -1;
    }
    s->phi0[h] = phi;
    s->phi[h] = phi;
    return 0;
}

int fs_shell_rest_geometry_of(fs_shell *s, const int32_t *tris, int32_t n)
{
    const fs_mesh *m = s->mesh;
    int32_t nt = tris ? n : m->n_tris;
    /* the half-edges across the listed triangles before: their twins may have changed too */
    int32_t *stale = NULL, n_stale = 0;
    if (tris) {
        stale = fs_malloc((3 * (size_t)nt + 1) * sizeof *stale);
        for (int32_t q = 0; q < nt; q++)
            for (int i = 0; i < 3; i++) {
                int32_t w = s->twin[3 * (size_t)tris[q] + i];
                if (w >= 0 && w < 3 * m->n_tris)
                    stale[n_stale++] = w;
            }
    }
    for (int32_t q = 0; q < nt; q++) {
        int32_t t = tris ? tris[q] : q;
        for (int i = 0; i < 3; i++) {
            int32_t w = find_twin(m, t, i);
            s->twin[3 * (size_t)t + i] = w;
            if (w >= 0)
                s->twin[w] = 3 * t + i;
        }
    }
    for (int32_t q = 0; q < n_stale; q++) {
        int32_t h = stale[q], w = find_twin(m, h / 3, h % 3);
        s->twin[h] = w;
        if (w >= 0)
            s->twin[w] = h;
    }
    int rc = 0;
    for (int32_t q = 0; q < nt && rc == 0; q++)
        rc = tri_rest(s, tris ? tris[q] : q);
    for (int32_t q = 0; q < nt && rc == 0; q++) {
        int32_t t = tris ? tris[q] : q;
        for (int i = 0; i < 3 && rc == 0; i++) {
            int32_t o = fs_shell_owner(s, 3 * t + i);
            if (o >= 0)
                rc = hinge_rest(s, o);
        }
    }
    for (int32_t q = 0; q < n_stale && rc == 0; q++) {
        int32_t o = fs_shell_owner(s, stale[q]);
        if (o >= 0)
            rc = hinge_rest(s, o);
    }
    free(stale);
    return rc;
}

void fs_shell_update_phi_of(fs_shell *s, const double *p, const int32_t *tris, int32_t n)
{
    for (int32_t q = 0; q < n; q++)
        for (int i = 0; i < 3; i++) {
            int32_t o = fs_shell_owner(s, 3 * tris[q] + i);
            if (o >= 0) {
                double x[12];
                hinge_coords(s, p, o, x);
                s->phi[o] = fs_shell_hinge_phi(x, NULL, NULL);
            }
        }
}

int fs_shell_rest_geometry(fs_shell *s)
{
    return fs_shell_rest_geometry_of(s, NULL, 0);
}

/* phi (and its gradient) of the hinge owned by half-edge h at positions p. */
static void hinge_phi_at(fs_shell *s, const double *p, int32_t h, bool with_grad)
{
    double x[12];
    hinge_coords(s, p, h, x);
    s->phi[h] = fs_shell_hinge_phi(x, with_grad ? s->dphi + 12 * (size_t)h : NULL, NULL);
}

/* ---- whole-shell passes on several threads ---- */

/* design: the whole shell is evaluated thousands of times a run (every Newton step of every
 * equilibrium, every test of the fracture criterion), each time over every hinge and triangle. The
 * per-hinge and per-triangle work (bending angles, strains, stresses, a triangle's own forces) runs
 * in fixed parts on several threads (fs_parallel_ranges), each item writing only its own slots;
 * whatever sums over items (energy, nodal forces) is then added up in item order on one thread: the
 * same floating-point operations in the same order as one loop, so the results are the same for any
 * thread count, and the same as before the passes were split. Scopes of fewer than PASS_MIN items
 * (a local relaxation's) stay on the calling thread. */
#define PASS_MIN 4096

void fs_shell_parallel(int32_t n, fs_range_fn fn, void *ctx) { fs_parallel_ranges(n, PASS_MIN, fn, ctx); }

typedef struct {
    fs_shell *s;
    const fs_shell_system *sys;
    const double *p;
    bool with_grad, derivs;
} pass_ctx;

static void phi_range(void *ctx, int32_t h0, int32_t h1)
{
    const pass_ctx *c = ctx;
    for (int32_t h = h0; h < h1; h++)
        if (fs_shell_owner(c->s, h) == h)
            hinge_phi_at(c->s, c->p, h, c->with_grad);
}

void fs_shell_update_phi(fs_shell *s, const double *p, bool with_grad)
{
    pass_ctx c = {.s = s, .p = p, .with_grad = with_grad};
    fs_shell_parallel(3 * s->mesh->n_tris, phi_range, &c);
}

/* ---- strains ---- */

/* The deformation gradient F (3x2, columns f0, f1) of triangle t at positions p. */
static void deformation_gradient(const fs_shell *s, const double *p, int32_t t, double f0[3], double f1[3])
{
    double x[3][3];
    for (int c = 0; c < 3; c++)
        fs_shell_corner(s, p, t, c, x[c]);
    const double *di = s->dm_inv + 4 * (size_t)t;
    for (int k = 0; k < 3; k++) {
        double d1 = x[1][k] - x[0][k], d2 = x[2][k] - x[0][k];
        f0[k] = d1 * di[0] + d2 * di[2];
        f1[k] = d1 * di[1] + d2 * di[3];
    }
}

void fs_shell_strains(const fs_shell *s, const double *p, int32_t t, double em[3], double ec[3])
{
    double f0[3], f1[3];
    deformation_gradient(s, p, t, f0, f1);
    em[0] = 0.5 * (fs_dot3(f0, f0) - 1.0);
    em[1] = 0.5 * (fs_dot3(f1, f1) - 1.0);
    em[2] = 0.5 * fs_dot3(f0, f1);
    ec[0] = ec[1] = ec[2] = 0.0;
    for (int i = 0; i < 3; i++) {
        int32_t o = fs_shell_owner(s, 3 * t + i);
        if (o < 0)
            continue;
        double w = s->bend_c[3 * (size_t)t + i] * (s->phi[o] - s->phi0[o]);
        const double *T = s->bend_t + 9 * (size_t)t + 3 * i;
        for (int k = 0; k < 3; k++)
            ec[k] += w * T[k];
    }
}

void fs_shell_eigenstrain(const fs_shell *s, int32_t t, double em[3], double ec[3])
{
    em[0] = em[1] = s->em_iso;
    em[2] = 0.0;
    if (s->growth_mode == FS_SHELL_GROWTH_EIGENSTRAIN) {
        /* -(F_g - I) in the frame: R G R^T */
        const double *R = s->axes + 4 * (size_t)t, *g = s->growth_eps;
        for (int a = 0; a < 2; a++)
            for (int b = a; b < 2; b++) {
                double v = 0.0;
                for (int i = 0; i < 2; i++)
                    for (int j = 0; j < 2; j++)
                        v += R[2 * a + i] * g[2 * i + j] * R[2 * b + j];
                em[a == b ? a : 2] -= v;
            }
    }
    double k = s->kappa_h / fs_shell_tri_thickness(s, t);
    ec[0] = ec[1] = k;
    ec[2] = 0.0;
}

void fs_shell_elastic_strains(const fs_shell *s, const double *p, int32_t t, double em[3], double ec[3])
{
    double sm[3], sc[3];
    fs_shell_strains(s, p, t, em, ec);
    fs_shell_eigenstrain(s, t, sm, sc);
    const double *pl = s->plastic + 6 * (size_t)t;
    for (int k = 0; k < 3; k++) {
        em[k] -= sm[k] + pl[k];
        ec[k] -= sc[k] + pl[3 + k];
    }
}

/* ---- energy ---- */

/* W(e) per unit stiffness: ((1 - nu) tr(e^2) + nu tr(e)^2) / (2 (1 - nu^2)), and the stress-like
 * derivative dW/de = ((1 - nu) e + nu tr(e) I) / (1 - nu^2) into sig (tensor components). */
static double density(const double e[3], double nu, double sig[3])
{
    double tr = e[0] + e[1], c = 1.0 / (1.0 - nu * nu);
    sig[0] = c * ((1.0 - nu) * e[0] + nu * tr);
    sig[1] = c * ((1.0 - nu) * e[1] + nu * tr);
    sig[2] = c * (1.0 - nu) * e[2];
    return 0.5 * (sig[0] * e[0] + sig[1] * e[1] + 2.0 * sig[2] * e[2]);
}

/* The nodes of triangle t's element: its corners, then the nodes opposite its interior edges, each
 * once. loc[0..2] the local index of its corners, opp[i] that of the node across edge i (-1). */
static int stencil(const fs_shell *s, int32_t t, int32_t nodes[6], int loc[3], int opp[3])
{
    const fs_mesh *m = s->mesh;
    int k = 0;
    for (int c = 0; c < 3; c++) {
        int32_t v = m->tri[3 * (size_t)t + c];
        int q = 0;
        while (q < k && nodes[q] != v)
            q++;
        if (q == k)
            nodes[k++] = v;
        loc[c] = q;
    }
    for (int i = 0; i < 3; i++) {
        opp[i] = -1;
        int32_t o = fs_shell_owner(s, 3 * t + i);
        if (o < 0)
            continue;
        const int32_t *h = s->hinge + 4 * (size_t)o;
        int32_t v = o == 3 * t + i ? h[3] : h[2];
        int q = 0;
        while (q < k && nodes[q] != v)
            q++;
        if (q == k)
            nodes[k++] = v;
        opp[i] = q;
    }
    return k;
}

/* Local index (in stencil nodes) of each of the four nodes of the hinge owned by o. */
static void hinge_local(const fs_shell *s, int32_t o, const int32_t *nodes, int k, int out[4])
{
    const int32_t *h = s->hinge + 4 * (size_t)o;
    for (int v = 0; v < 4; v++) {
        int q = 0;
        while (q < k && nodes[q] != h[v])
            q++;
        FS_ASSERT(q < k);
        out[v] = q;
    }
}

/* The element block's DOF indices: 3 per stencil node. */
static void block_dofs(const fs_shell_system *sys, const int32_t *nodes, int k, int32_t *idx)
{
    for (int q = 0; q < k; q++)
        for (int c = 0; c < 3; c++)
            idx[3 * q + c] = sys->dof[3 * (size_t)nodes[q] + c];
}

/* The bond of node i: its stiffness matrix (9) at the current thickness. */
static void bond_matrix(const fs_shell *s, int32_t i, double K[9])
{
    const double *n = s->normal + 3 * (size_t)i;
    double kt = s->bond_t * s->node_area[i], kn = s->bond_n * s->node_area[i];
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++)
            K[3 * a + b] = (a == b ? kt : 0.0) + (kn - kt) * n[a] * n[b];
}

void fs_shell_system_free(fs_shell_system *sys)
{
    free(sys->dof);
    free(sys->slots);
    fs_sparse_matrix_free(&sys->K);
    fs_cholesky_free(sys->chol);
    memset(sys, 0, sizeof *sys);
}

/* design: the Hessian's pattern is built a node at a time. DOFs are numbered a node at a time (its
 * free components consecutive), so the column of a DOF holds all the DOFs of every node that shares
 * a stencil with its node and comes before it, then its own node's up to the diagonal. Each node's
 * earlier neighbours (deduplicated, in DOF order) give the columns, and an element block's entry
 * finds its slot from the place of its row's node among its column node's neighbours. This gives
 * the pattern and slots that summing the blocks' scalar entries through a sparse builder
 * (fs_sparse_builder_compress) gives, from 15 node pairs a stencil instead of up to 171 entries. */

/* A column node's earlier neighbour: its first DOF and the DOFs of the neighbours before it. */
typedef struct {
    int32_t first;
    int32_t before;
} neighbour;

/* Where the rows of node fr start in the columns of node fc (fr <= fc, their first DOFs): entry
 * (r, c) of the pair is at col_ptr[c] + this + (r - fr). A column holds its node's earlier
 * neighbours, then its own node's DOFs up to the diagonal. */
static int32_t pair_base(const int32_t *own, const int32_t *nb_start, const neighbour *nb, int32_t fr, int32_t fc)
{
    if (fr == fc)
        return own[fc];
    int32_t lo = nb_start[fc], hi = nb_start[fc + 1] - 1;
    while (lo < hi) {
        int32_t mid = (lo + hi) / 2;
        if (nb[mid].first < fr)
            lo = mid + 1;
        else
            hi = mid;
    }
    FS_ASSERT(nb[lo].first == fr);
    return nb[lo].before;
}

/* The first DOF of each of the kn nodes of a block over idx (3 DOFs a node, -1 held), -1 for a node
 * without one. */
static void block_firsts(const int32_t *first, const int32_t *idx, int kn, int32_t fn[6])
{
    for (int i = 0; i < kn; i++) {
        fn[i] = -1;
        for (int c = 0; c < 3 && fn[i] < 0; c++)
            if (idx[3 * i + c] >= 0)
                fn[i] = first[idx[3 * i + c]];
    }
}

/* The nodes of a stored stencil (6 slots, -1 past the last). */
static int stencil_size(const int32_t *nodes)
{
    int k = 0;
    while (k < 6 && nodes[k] >= 0)
        k++;
    return k;
}

/* Appends the slots of a block over idx (k DOFs, 3 a node, -1 skipped) in fs_sparse_matrix_add_block's
 * order; the place of each pair of its nodes is found once. */
static int32_t *block_slots(const fs_sparse_matrix *K, const int32_t *first, const int32_t *own,
                            const int32_t *nb_start, const neighbour *nb, const int32_t *idx, int k, int32_t *out)
{
    int32_t fn[6], base[6][6];
    int kn = k / 3;
    block_firsts(first, idx, kn, fn);
    for (int i = 0; i < kn; i++)
        for (int j = i; j < kn; j++)
            if (fn[i] >= 0 && fn[j] >= 0)
                base[i][j] = base[j][i] = fn[i] < fn[j] ? pair_base(own, nb_start, nb, fn[i], fn[j])
                                                        : pair_base(own, nb_start, nb, fn[j], fn[i]);
    for (int a = 0; a < k; a++) {
        if (idx[a] < 0)
            continue;
        for (int c = a; c < k; c++)
            if (idx[c] >= 0) {
                int32_t lo = idx[a] < idx[c] ? idx[a] : idx[c], hi = idx[a] < idx[c] ? idx[c] : idx[a];
                *out++ = K->col_ptr[hi] + base[a / 3][c / 3] + (lo - first[lo]);
            }
    }
    return out;
}

/* Builds the sparsity pattern of the Hessian (triangle blocks, then node blocks) and its slots. */
static int build_pattern(fs_shell *s, fs_shell_system *sys)
{
    fs_sparse_matrix_free(&sys->K);
    free(sys->slots);
    sys->slots = NULL;
    fs_cholesky_free(sys->chol);
    sys->chol = NULL;
    sys->factored = false;
    int32_t nt = fs_shell_scope_tris(s->mesh->n_tris, sys), nn = fs_shell_scope_nodes(s->n_nodes, sys), nf = sys->n_free;
    /* each DOF's node, named by its first DOF; own[f]: the DOFs of node f's earlier neighbours */
    int32_t *first = fs_malloc(((size_t)nf + 1) * sizeof *first);
    int32_t *own = fs_calloc((size_t)nf + 1, sizeof *own);
    int32_t *count = fs_calloc((size_t)nf + 1, sizeof *count);
    int32_t *nb_start = fs_calloc((size_t)nf + 2, sizeof *nb_start);
    for (int32_t q = 0; q < nn; q++) {
        int32_t i = fs_shell_scope_node(sys, q), f = -1;
        for (int c = 0; c < 3; c++) {
            int32_t d = sys->dof[3 * (size_t)i + c];
            if (d >= 0) {
                f = f < 0 ? d : f;
                first[d] = f;
                count[f]++;
            }
        }
    }
    /* the stencils once (6 nodes a triangle, -1 past its k), and the stencil pairs of each column
     * node (with repeats), then sorted and deduplicated */
    int32_t *st = fs_malloc(6 * ((size_t)nt + 1) * sizeof *st);
    size_t n_slots = 6 * (size_t)nn;
    for (int32_t q = 0; q < nt; q++) {
        int32_t *nodes = st + 6 * (size_t)q, fr[6], idx[18];
        int loc[3], opp[3];
        int k = stencil(s, fs_shell_scope_tri(sys, q), nodes, loc, opp);
        for (int a = k; a < 6; a++)
            nodes[a] = -1;
        block_dofs(sys, nodes, k, idx);
        block_firsts(first, idx, k, fr);
        n_slots += (size_t)(3 * k) * (size_t)(3 * k + 1) / 2;
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++)
                if (fr[a] >= 0 && fr[a] < fr[b])
                    nb_start[fr[b] + 1]++;
    }
    for (int32_t f = 0; f < nf; f++)
        nb_start[f + 1] += nb_start[f];
    neighbour *nb = fs_malloc(((size_t)nb_start[nf] + 1) * sizeof *nb);
    int32_t *cursor = fs_malloc(((size_t)nf + 1) * sizeof *cursor);
    memcpy(cursor, nb_start, (size_t)nf * sizeof *cursor);
    for (int32_t q = 0; q < nt; q++) {
        const int32_t *nodes = st + 6 * (size_t)q;
        int32_t fr[6], idx[18];
        int k = stencil_size(nodes);
        block_dofs(sys, nodes, k, idx);
        block_firsts(first, idx, k, fr);
        for (int a = 0; a < k; a++)
            for (int b = 0; b < k; b++)
                if (fr[a] >= 0 && fr[a] < fr[b])
                    nb[cursor[fr[b]]++].first = fr[a];
    }
    int32_t kept = 0;
    for (int32_t f = 0; f < nf; f++) {
        int32_t from = nb_start[f], to = nb_start[f + 1];
        nb_start[f] = kept;
        for (int32_t p = from; p < to; p++) { /* insertion into the kept, sorted run */
            int32_t v = nb[p].first, at = kept;
            while (at > nb_start[f] && nb[at - 1].first > v)
                at--;
            if (at > nb_start[f] && nb[at - 1].first == v)
                continue;
            memmove(nb + at + 1, nb + at, (size_t)(kept - at) * sizeof *nb);
            nb[at].first = v;
            kept++;
        }
        for (int32_t p = nb_start[f]; p < kept; p++) {
            nb[p].before = own[f];
            own[f] += count[nb[p].first];
        }
    }
    nb_start[nf] = kept;
    /* the columns */
    fs_sparse_matrix *K = &sys->K;
    K->n = nf;
    K->col_ptr = fs_malloc(((size_t)nf + 1) * sizeof *K->col_ptr);
    int64_t nnz = 0;
    for (int32_t c = 0; c < nf; c++) {
        K->col_ptr[c] = (int32_t)nnz;
        nnz += own[first[c]] + (c - first[c]) + 1;
        if (nnz > INT32_MAX) {
            fs_error(FS_ERR_INTERNAL, "shell: the Hessian's %lld stored entries exceed the 32-bit index range",
                     (long long)nnz);
            free(first), free(own), free(count), free(nb_start), free(nb), free(cursor), free(st);
            return -1;
        }
    }
    K->col_ptr[nf] = (int32_t)nnz;
    K->row_idx = fs_malloc(((size_t)nnz + 1) * sizeof *K->row_idx);
    K->values = fs_calloc((size_t)nnz + 1, sizeof *K->values);
    for (int32_t c = 0; c < nf; c++) {
        int32_t p = K->col_ptr[c], f = first[c];
        for (int32_t e = nb_start[f]; e < nb_start[f + 1]; e++)
            for (int32_t r = nb[e].first; r < nb[e].first + count[nb[e].first]; r++)
                K->row_idx[p++] = r;
        for (int32_t r = f; r <= c; r++)
            K->row_idx[p++] = r;
    }
    /* the slots, in the order the assembly adds the blocks */
    sys->slots = fs_malloc((n_slots + 1) * sizeof *sys->slots);
    int32_t *out = sys->slots;
    for (int32_t q = 0; q < nt; q++) {
        const int32_t *nodes = st + 6 * (size_t)q;
        int32_t idx[18];
        int k = stencil_size(nodes);
        block_dofs(sys, nodes, k, idx);
        out = block_slots(K, first, own, nb_start, nb, idx, 3 * k, out);
    }
    for (int32_t q = 0; q < nn; q++)
        out = block_slots(K, first, own, nb_start, nb, sys->dof + 3 * (size_t)fs_shell_scope_node(sys, q), 3, out);
    sys->n_slots = (size_t)(out - sys->slots);
    free(first), free(own), free(count), free(nb_start), free(nb), free(cursor), free(st);
    sys->pattern_valid = true;
    return 0;
}

/* phi (and its gradient) of the interior edges of the scope's triangles. */
static void scope_phi(fs_shell *s, const fs_shell_system *sys, const double *p, bool with_grad)
{
    if (!sys->tris) {
        fs_shell_update_phi(s, p, with_grad);
        return;
    }
    for (int32_t q = 0; q < sys->n_tris; q++)
        for (int i = 0; i < 3; i++) {
            int32_t o = fs_shell_owner(s, 3 * sys->tris[q] + i);
            if (o >= 0)
                hinge_phi_at(s, p, o, with_grad);
        }
}

/* The terms of each triangle of the scope (q in [q0, q1)) into s->terms: its energy, dE/dphi of its
 * three edges (with derivs), and the membrane forces on its corners (with with_grad). */
#define TERMS 13
static void tri_terms(void *ctx, int32_t q0, int32_t q1)
{
    const pass_ctx *c = ctx;
    const fs_shell *s = c->s;
    double nu = s->cfg.material.poisson;
    for (int32_t q = q0; q < q1; q++) {
        int32_t t = fs_shell_scope_tri(c->sys, q);
        double *term = s->terms + TERMS * (size_t)t, *dedphi = term + 1;
        double em[3], ec[3];
        fs_shell_elastic_strains(s, c->p, t, em, ec);
        double h = fs_shell_tri_thickness(s, t), A = s->area0[t], Y = s->young[t];
        double sm[3], sc[3];
        double wm = density(em, nu, sm), wc = density(ec, nu, sc);
        double km = A * h * Y, kb = A * h * h * h / 12.0 * Y;
        term[0] = km * wm + kb * wc;
        if (!c->derivs)
            continue;
        for (int i = 0; i < 3; i++) {
            const double *T = s->bend_t + 9 * (size_t)t + 3 * i;
            dedphi[i] = kb * s->bend_c[3 * (size_t)t + i] * (sc[0] * T[0] + sc[1] * T[1] + 2.0 * sc[2] * T[2]);
        }
        if (!c->with_grad)
            continue;
        /* membrane: grad_a = km F S g_a */
        double f0[3], f1[3];
        deformation_gradient(s, c->p, t, f0, f1);
        const double *di = s->dm_inv + 4 * (size_t)t;
        double ga[3][2] = {{-di[0] - di[2], -di[1] - di[3]}, {di[0], di[1]}, {di[2], di[3]}};
        for (int a = 0; a < 3; a++) {
            double w0 = sm[0] * ga[a][0] + sm[2] * ga[a][1], w1 = sm[2] * ga[a][0] + sm[1] * ga[a][1];
            for (int k = 0; k < 3; k++)
                term[4 + 3 * a + k] = km * (f0[k] * w0 + f1[k] * w1);
        }
    }
}

/* design: pass 2 of an evaluation with the Hessian computes HESSIAN_CHUNK element matrices at a
 * time on several threads (fs_shell_parallel), each into its own slot of s->ke, and adds them into
 * the matrix on one thread in element order: the same sums as one loop, for any thread count. */
#define HESSIAN_CHUNK 8192

typedef struct {
    fs_shell *s;
    const fs_shell_system *sys;
    const double *p, *gphi;
    int32_t q0;                    /* the chunk's first scope triangle */
} element_ctx;

/* The element matrix of triangle t (its stencil's 3 k DOFs, row-major) into e, with gphi the
 * summed dE/dphi of the hinges. */
static void element_matrix(const fs_shell *s, const double *p, const double *gphi, int32_t t, fs_shell_element *e)
{
    double nu = s->cfg.material.poisson;
    int32_t *nodes = e->nodes;
    double *ke = e->m;
    int loc[3], opp[3];
    int k = e->k = stencil(s, t, nodes, loc, opp), n = 3 * k;
    memset(ke, 0, (size_t)n * n * sizeof *ke);
    double h = fs_shell_tri_thickness(s, t), A = s->area0[t], Y = s->young[t];
    double km = A * h * Y, kb = A * h * h * h / 12.0 * Y, cn = 1.0 / (1.0 - nu * nu);
    /* membrane */
    double em[3], ec[3], sm[3], f0[3], f1[3];
    fs_shell_elastic_strains(s, p, t, em, ec);
    density(em, nu, sm);
    deformation_gradient(s, p, t, f0, f1);
    const double *di = s->dm_inv + 4 * (size_t)t;
    double ga[3][2] = {{-di[0] - di[2], -di[1] - di[3]}, {di[0], di[1]}, {di[2], di[3]}};
    for (int b = 0; b < 3; b++)
        for (int kk = 0; kk < 3; kk++) {
            /* column (b, kk): dG = sym(f_kk g_b^T), f_kk = row kk of F */
            double fk[2] = {f0[kk], f1[kk]};
            double dG[3] = {fk[0] * ga[b][0], fk[1] * ga[b][1], 0.5 * (fk[0] * ga[b][1] + fk[1] * ga[b][0])};
            double tr = dG[0] + dG[1];
            double dS[3] = {cn * ((1.0 - nu) * dG[0] + nu * tr), cn * ((1.0 - nu) * dG[1] + nu * tr),
                            cn * (1.0 - nu) * dG[2]};
            for (int a = 0; a < 3; a++) {
                double sab = ga[b][0] * (sm[0] * ga[a][0] + sm[2] * ga[a][1]) +
                             ga[b][1] * (sm[2] * ga[a][0] + sm[1] * ga[a][1]);
                double w0 = dS[0] * ga[a][0] + dS[2] * ga[a][1], w1 = dS[2] * ga[a][0] + dS[1] * ga[a][1];
                int row = 3 * loc[a], col = 3 * loc[b] + kk;
                for (int r = 0; r < 3; r++)
                    ke[(row + r) * n + col] += km * ((r == kk ? sab : 0.0) + f0[r] * w0 + f1[r] * w1);
            }
        }
    /* bending: Q_ij grad phi_i grad phi_j^T */
    int hl[3][4];
    int32_t own[3];
    bool live[3];
    for (int i = 0; i < 3; i++) {
        own[i] = fs_shell_owner(s, 3 * t + i);
        live[i] = own[i] >= 0;
        if (live[i])
            hinge_local(s, own[i], nodes, k, hl[i]);
    }
    for (int i = 0; i < 3; i++) {
        if (!live[i])
            continue;
        const double *Ti = s->bend_t + 9 * (size_t)t + 3 * i;
        const double *dpi = s->dphi + 12 * (size_t)own[i];
        for (int j = 0; j < 3; j++) {
            if (!live[j])
                continue;
            const double *Tj = s->bend_t + 9 * (size_t)t + 3 * j;
            double tt = Ti[0] * Tj[0] + Ti[1] * Tj[1] + 2.0 * Ti[2] * Tj[2];
            double qq = kb * s->bend_c[3 * (size_t)t + i] * s->bend_c[3 * (size_t)t + j] * cn *
                        ((1.0 - nu) * tt + nu * (Ti[0] + Ti[1]) * (Tj[0] + Tj[1]));
            const double *dpj = s->dphi + 12 * (size_t)own[j];
            for (int va = 0; va < 4; va++)
                for (int ra = 0; ra < 3; ra++) {
                    double wa = qq * dpi[3 * va + ra];
                    double *row = ke + (3 * hl[i][va] + ra) * n;
                    for (int vb = 0; vb < 4; vb++)
                        for (int rb = 0; rb < 3; rb++)
                            row[3 * hl[j][vb] + rb] += wa * dpj[3 * vb + rb];
                }
        }
    }
    /* the second derivatives of phi of the hinges t owns */
    for (int i = 0; i < 3; i++) {
        int32_t o = own[i];
        if (!live[i] || o != 3 * t + i || gphi[o] == 0.0)
            continue;
        double x[12], hh[144];
        hinge_coords(s, p, o, x);
        fs_shell_hinge_phi(x, NULL, hh);
        for (int va = 0; va < 4; va++)
            for (int vb = 0; vb < 4; vb++)
                for (int ra = 0; ra < 3; ra++)
                    for (int rb = 0; rb < 3; rb++)
                        ke[(3 * hl[i][va] + ra) * n + 3 * hl[i][vb] + rb] +=
                            gphi[o] * hh[(3 * va + ra) * 12 + 3 * vb + rb];
    }
}

static void element_range(void *ctx, int32_t i0, int32_t i1)
{
    const element_ctx *c = ctx;
    for (int32_t i = i0; i < i1; i++)
        element_matrix(c->s, c->p, c->gphi, fs_shell_scope_tri(c->sys, c->q0 + i), c->s->ke + i);
}

/* Zeroes what an evaluation over sys's scope accumulates: the gradient (g, may be NULL) at the
 * corners of its triangles and of the hinges they own, and dE/dphi (gphi, may be NULL) at those
 * hinges; everywhere for the whole shell. A local relaxation's scope is a few hundred of the
 * shell's nodes, so clearing only it keeps the cost of its evaluations to its size. */
static void clear_scope(const fs_shell *s, const fs_shell_system *sys, double *g, double *gphi)
{
    const fs_mesh *m = s->mesh;
    if (!sys->tris) {
        if (g)
            memset(g, 0, 3 * (size_t)s->n_nodes * sizeof *g);
        if (gphi)
            memset(gphi, 0, 3 * (size_t)m->n_tris * sizeof *gphi);
        return;
    }
    for (int32_t q = 0; q < sys->n_tris; q++) {
        int32_t t = sys->tris[q];
        for (int i = 0; i < 3; i++) {
            int32_t o = fs_shell_owner(s, 3 * t + i);
            if (g) {
                memset(g + 3 * (size_t)m->tri[3 * (size_t)t + i], 0, 3 * sizeof *g);
                if (o >= 0)
                    for (int v = 0; v < 4; v++)
                        memset(g + 3 * (size_t)s->hinge[4 * (size_t)o + v], 0, 3 * sizeof *g);
            }
            if (gphi && o >= 0)
                gphi[o] = 0.0;
        }
    }
    if (g)
        for (int32_t q = 0; q < sys->n_nodes; q++)
            memset(g + 3 * (size_t)sys->nodes[q], 0, 3 * sizeof *g);
}

double fs_shell_energy(fs_shell *s, const double *p, double *grad, bool hessian)
{
    return fs_shell_energy_in(s, &s->sys, p, grad, hessian);
}

double fs_shell_energy_in(fs_shell *s, fs_shell_system *sys, const double *p, double *grad, bool hessian)
{
    const fs_mesh *m = s->mesh;
    double t_start = fs_seconds();
    if (hessian && !sys->pattern_valid && build_pattern(s, sys) < 0)
        return NAN;
    bool derivs = grad || hessian;
    scope_phi(s, sys, p, derivs);
    int32_t nt = fs_shell_scope_tris(s->mesh->n_tris, sys), nn = fs_shell_scope_nodes(s->n_nodes, sys);
    double energy = 0.0;
    double *g = grad;
    /* dE/dphi per edge, summed over its two triangles, for the hinges' second derivatives */
    double *gphi = hessian ? s->gphi : NULL;
    if (g || gphi)
        clear_scope(s, sys, g, gphi);
    /* pass 1: each triangle's terms, then energies, gradients and dE/dphi summed in order */
    pass_ctx pc = {.s = s, .sys = sys, .p = p, .with_grad = g != NULL, .derivs = derivs};
    fs_shell_parallel(nt, tri_terms, &pc);
    for (int32_t q = 0; q < nt; q++) {
        int32_t t = fs_shell_scope_tri(sys, q);
        const double *term = s->terms + TERMS * (size_t)t, *dedphi = term + 1;
        energy += term[0];
        if (!isfinite(energy))
            break;
        if (!derivs)
            continue;
        for (int i = 0; i < 3; i++) {
            int32_t o = fs_shell_owner(s, 3 * t + i);
            if (gphi && o >= 0)
                gphi[o] += dedphi[i];
        }
        if (!g)
            continue;
        for (int c = 0; c < 3; c++) {
            int32_t node = m->tri[3 * (size_t)t + c];
            for (int k = 0; k < 3; k++)
                g[3 * (size_t)node + k] += term[4 + 3 * c + k];
        }
        /* bending: sum_i dE/dphi_i grad phi_i */
        for (int i = 0; i < 3; i++) {
            int32_t o = fs_shell_owner(s, 3 * t + i);
            if (o < 0)
                continue;
            const int32_t *hn = s->hinge + 4 * (size_t)o;
            const double *dp = s->dphi + 12 * (size_t)o;
            for (int v = 0; v < 4; v++)
                for (int k = 0; k < 3; k++)
                    g[3 * (size_t)hn[v] + k] += dedphi[i] * dp[3 * v + k];
        }
    }
    /* the bond and the loads */
    for (int32_t q = 0; q < nn && isfinite(energy); q++) {
        int32_t i = fs_shell_scope_node(sys, q);
        double K[9], d[3], f[3];
        bond_matrix(s, i, K);
        fs_sub3(d, p + 3 * (size_t)i, s->anchor + 3 * (size_t)i);
        for (int a = 0; a < 3; a++)
            f[a] = K[3 * a] * d[0] + K[3 * a + 1] * d[1] + K[3 * a + 2] * d[2];
        const double *fe = s->f_ext + 3 * (size_t)i;
        energy += 0.5 * fs_dot3(f, d) - fs_dot3(fe, p + 3 * (size_t)i);
        if (g)
            for (int a = 0; a < 3; a++)
                g[3 * (size_t)i + a] += f[a] - fe[a];
    }
    if (!isfinite(energy) || !hessian) {
        s->counters.assemble_seconds += fs_seconds() - t_start;
        return isfinite(energy) ? energy : NAN;
    }

    /* pass 2: the Hessian, element by element in the pattern's order (a chunk of elements' matrices
     * at a time, on several threads, then added on one) */
    fs_sparse_matrix_zero(&sys->K);
    const int32_t *slot = sys->slots;
    int32_t chunk = nt < HESSIAN_CHUNK ? nt : HESSIAN_CHUNK;
    if (s->ke_cap < chunk) {
        free(s->ke);
        s->ke = fs_malloc((size_t)chunk * sizeof *s->ke);
        s->ke_cap = chunk;
    }
    for (int32_t q0 = 0; q0 < nt; q0 += chunk) {
        int32_t q1 = nt - q0 < chunk ? nt : q0 + chunk;
        element_ctx ec = {s, sys, p, gphi, q0};
        fs_shell_parallel(q1 - q0, element_range, &ec);
        for (int32_t q = q0; q < q1; q++) {
            const fs_shell_element *e = s->ke + (q - q0);
            int32_t idx[18];
            block_dofs(sys, e->nodes, e->k, idx);
            slot += fs_sparse_matrix_add_block(&sys->K, 3 * e->k, idx, e->m, slot);
        }
    }
    for (int32_t q = 0; q < nn; q++) {
        int32_t i = fs_shell_scope_node(sys, q);
        double K[9];
        bond_matrix(s, i, K);
        slot += fs_sparse_matrix_add_block(&sys->K, 3, sys->dof + 3 * (size_t)i, K, slot);
    }
    FS_ASSERT((size_t)(slot - sys->slots) == sys->n_slots);
    s->counters.assemble_seconds += fs_seconds() - t_start;
    return energy;
}
