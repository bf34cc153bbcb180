/* The discrete shell's rest geometry and its energy: membrane, bending and bond, with the exact gradient and Hessian. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
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

/* The 12 coordinates of hinge e at node positions p. */
static void hinge_coords(const fs_shell *s, const double *p, int32_t e, double x[12])
{
    const int32_t *h = s->hinge + 4 * (size_t)e;
    const double *off = s->hinge_off + 12 * (size_t)e;
    for (int v = 0; v < 4; v++)
        for (int k = 0; k < 3; k++)
            x[3 * v + k] = p[3 * (size_t)h[v] + k] + off[3 * v + k];
}

/* The hinge of edge e: its nodes and offsets from its triangles (see internal.h). */
static void build_hinge(fs_shell *s, int32_t e)
{
    const fs_mesh *m = s->mesh;
    int32_t *h = s->hinge + 4 * (size_t)e;
    int32_t t1 = m->edge_tri[2 * (size_t)e], t2 = m->edge_tri[2 * (size_t)e + 1];
    if (t1 < 0 || t2 < 0) {
        h[0] = h[1] = h[2] = h[3] = -1;
        return;
    }
    int i = 0, j = 0;
    while (i < 3 && m->tri_edge[3 * (size_t)t1 + i] != e)
        i++;
    while (j < 3 && m->tri_edge[3 * (size_t)t2 + j] != e)
        j++;
    FS_ASSERT(i < 3 && j < 3);
    double *off = s->hinge_off + 12 * (size_t)e;
    h[0] = m->tri[3 * (size_t)t1 + i];
    h[1] = m->tri[3 * (size_t)t1 + (i + 1) % 3];
    h[2] = m->tri[3 * (size_t)t1 + (i + 2) % 3];
    h[3] = m->tri[3 * (size_t)t2 + (j + 2) % 3];
    corner_offset(s, t1, i, off);
    corner_offset(s, t1, (i + 1) % 3, off + 3);
    corner_offset(s, t1, (i + 2) % 3, off + 6);
    /* t2's frame moved onto t1's: by the difference of node a's offsets in the two */
    int ja = m->tri[3 * (size_t)t2 + j] == h[0] ? j : (j + 1) % 3;
    double a2[3], c2[3];
    corner_offset(s, t2, ja, a2);
    corner_offset(s, t2, (j + 2) % 3, c2);
    for (int k = 0; k < 3; k++)
        off[9 + k] = c2[k] + off[k] - a2[k];
}

int fs_shell_rest_geometry(fs_shell *s)
{
    const fs_mesh *m = s->mesh;
    for (int32_t t = 0; t < m->n_tris; t++) {
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
    }
    for (int32_t e = 0; e < m->n_edges; e++) {
        build_hinge(s, e);
        s->phi0[e] = 0.0;
        if (s->hinge[4 * (size_t)e] < 0)
            continue;
        double x[12];
        hinge_coords(s, s->rest, e, x);
        double phi = fs_shell_hinge_phi(x, NULL, NULL);
        if (!isfinite(phi)) {
            fs_error(FS_ERR_DATA, "shell: the rest surface folds back on itself at edge %d (nodes %d, %d)", (int)e,
                     (int)m->edge[2 * (size_t)e], (int)m->edge[2 * (size_t)e + 1]);
            return -1;
        }
        s->phi0[e] = phi;
    }
    return 0;
}

void fs_shell_update_phi(fs_shell *s, const double *p, bool with_grad)
{
    for (int32_t e = 0; e < s->mesh->n_edges; e++) {
        if (s->hinge[4 * (size_t)e] < 0) {
            s->phi[e] = 0.0;
            continue;
        }
        double x[12];
        hinge_coords(s, p, e, x);
        s->phi[e] = fs_shell_hinge_phi(x, with_grad ? s->dphi + 12 * (size_t)e : NULL, NULL);
    }
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
        int32_t e = s->mesh->tri_edge[3 * (size_t)t + i];
        if (s->hinge[4 * (size_t)e] < 0)
            continue;
        double w = s->bend_c[3 * (size_t)t + i] * (s->phi[e] - s->phi0[e]);
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
        int32_t e = m->tri_edge[3 * (size_t)t + i];
        const int32_t *h = s->hinge + 4 * (size_t)e;
        if (h[0] < 0)
            continue;
        int32_t v = m->edge_tri[2 * (size_t)e] == t ? h[3] : h[2];
        int q = 0;
        while (q < k && nodes[q] != v)
            q++;
        if (q == k)
            nodes[k++] = v;
        opp[i] = q;
    }
    return k;
}

/* Local index (in stencil nodes) of each of hinge e's four nodes. */
static void hinge_local(const fs_shell *s, int32_t e, const int32_t *nodes, int k, int out[4])
{
    const int32_t *h = s->hinge + 4 * (size_t)e;
    for (int v = 0; v < 4; v++) {
        int q = 0;
        while (q < k && nodes[q] != h[v])
            q++;
        FS_ASSERT(q < k);
        out[v] = q;
    }
}

/* The element block's DOF indices: 3 per stencil node. */
static void block_dofs(const fs_shell *s, const int32_t *nodes, int k, int32_t *idx)
{
    for (int q = 0; q < k; q++)
        for (int c = 0; c < 3; c++)
            idx[3 * q + c] = s->dof[3 * (size_t)nodes[q] + c];
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

/* Builds the sparsity pattern of the Hessian (triangle blocks, then node blocks) and its slots. */
static int build_pattern(fs_shell *s)
{
    const fs_mesh *m = s->mesh;
    fs_sparse_matrix_free(&s->K);
    free(s->slots);
    s->slots = NULL;
    fs_cholesky_free(s->chol);
    s->chol = NULL;
    s->factored = false;
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, s->n_free, (size_t)m->n_tris * 171 + (size_t)s->n_nodes * 6);
    double zero[18 * 18];
    memset(zero, 0, sizeof zero);
    for (int32_t t = 0; t < m->n_tris; t++) {
        int32_t nodes[6], idx[18];
        int loc[3], opp[3];
        int k = stencil(s, t, nodes, loc, opp);
        block_dofs(s, nodes, k, idx);
        fs_sparse_builder_add_block(&b, 3 * k, idx, zero);
    }
    for (int32_t i = 0; i < s->n_nodes; i++)
        fs_sparse_builder_add_block(&b, 3, s->dof + 3 * (size_t)i, zero);
    s->n_slots = b.count;
    s->slots = fs_malloc((b.count + 1) * sizeof *s->slots);
    int rc = fs_sparse_builder_compress(&b, &s->K, s->slots);
    fs_sparse_builder_free(&b);
    if (rc < 0)
        return -1;
    s->pattern_valid = true;
    return 0;
}

double fs_shell_energy(fs_shell *s, const double *p, double *grad, bool hessian)
{
    const fs_mesh *m = s->mesh;
    double t_start = fs_seconds();
    if (hessian && !s->pattern_valid && build_pattern(s) < 0)
        return NAN;
    bool derivs = grad || hessian;
    fs_shell_update_phi(s, p, derivs);
    double nu = s->cfg.material.poisson;
    double energy = 0.0;
    double *g = grad;
    if (g)
        memset(g, 0, 3 * (size_t)s->n_nodes * sizeof *g);
    /* dE/dphi per edge, summed over its two triangles, for the hinges' second derivatives */
    double *gphi = NULL;
    if (hessian)
        gphi = fs_calloc((size_t)m->n_edges + 1, sizeof *gphi);
    /* pass 1: energies, gradients and dE/dphi */
    double *dedphi = derivs ? fs_malloc(3 * (size_t)m->n_tris * sizeof *dedphi + 1) : NULL;
    for (int32_t t = 0; t < m->n_tris; t++) {
        double em[3], ec[3];
        fs_shell_elastic_strains(s, p, t, em, ec);
        double h = fs_shell_tri_thickness(s, t), A = s->area0[t], Y = s->young[t];
        double sm[3], sc[3];
        double wm = density(em, nu, sm), wc = density(ec, nu, sc);
        double km = A * h * Y, kb = A * h * h * h / 12.0 * Y;
        energy += km * wm + kb * wc;
        if (!isfinite(energy))
            break;
        if (!derivs)
            continue;
        for (int i = 0; i < 3; i++) {
            const double *T = s->bend_t + 9 * (size_t)t + 3 * i;
            dedphi[3 * (size_t)t + i] =
                kb * s->bend_c[3 * (size_t)t + i] * (sc[0] * T[0] + sc[1] * T[1] + 2.0 * sc[2] * T[2]);
        }
        if (gphi)
            for (int i = 0; i < 3; i++)
                gphi[m->tri_edge[3 * (size_t)t + i]] += dedphi[3 * (size_t)t + i];
        if (!g)
            continue;
        /* membrane: grad_a = km F S g_a */
        double f0[3], f1[3];
        deformation_gradient(s, p, t, f0, f1);
        const double *di = s->dm_inv + 4 * (size_t)t;
        double ga[3][2] = {{-di[0] - di[2], -di[1] - di[3]}, {di[0], di[1]}, {di[2], di[3]}};
        for (int c = 0; c < 3; c++) {
            double w0 = sm[0] * ga[c][0] + sm[2] * ga[c][1], w1 = sm[2] * ga[c][0] + sm[1] * ga[c][1];
            int32_t node = m->tri[3 * (size_t)t + c];
            for (int k = 0; k < 3; k++)
                g[3 * (size_t)node + k] += km * (f0[k] * w0 + f1[k] * w1);
        }
        /* bending: sum_i dE/dphi_i grad phi_i */
        for (int i = 0; i < 3; i++) {
            int32_t e = m->tri_edge[3 * (size_t)t + i];
            const int32_t *hn = s->hinge + 4 * (size_t)e;
            if (hn[0] < 0)
                continue;
            double d = dedphi[3 * (size_t)t + i];
            const double *dp = s->dphi + 12 * (size_t)e;
            for (int v = 0; v < 4; v++)
                for (int k = 0; k < 3; k++)
                    g[3 * (size_t)hn[v] + k] += d * dp[3 * v + k];
        }
    }
    /* the bond and the loads */
    for (int32_t i = 0; i < s->n_nodes && isfinite(energy); i++) {
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
        free(dedphi);
        free(gphi);
        s->counters.assemble_seconds += fs_seconds() - t_start;
        return isfinite(energy) ? energy : NAN;
    }

    /* pass 2: the Hessian, element by element in the pattern's order */
    fs_sparse_matrix_zero(&s->K);
    const int32_t *slot = s->slots;
    double ke[18 * 18];
    for (int32_t t = 0; t < m->n_tris; t++) {
        int32_t nodes[6], idx[18];
        int loc[3], opp[3];
        int k = stencil(s, t, nodes, loc, opp), n = 3 * k;
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
        bool live[3];
        for (int i = 0; i < 3; i++) {
            int32_t e = m->tri_edge[3 * (size_t)t + i];
            live[i] = s->hinge[4 * (size_t)e] >= 0;
            if (live[i])
                hinge_local(s, e, nodes, k, hl[i]);
        }
        for (int i = 0; i < 3; i++) {
            if (!live[i])
                continue;
            const double *Ti = s->bend_t + 9 * (size_t)t + 3 * i;
            const double *dpi = s->dphi + 12 * (size_t)m->tri_edge[3 * (size_t)t + i];
            for (int j = 0; j < 3; j++) {
                if (!live[j])
                    continue;
                const double *Tj = s->bend_t + 9 * (size_t)t + 3 * j;
                double tt = Ti[0] * Tj[0] + Ti[1] * Tj[1] + 2.0 * Ti[2] * Tj[2];
                double q = kb * s->bend_c[3 * (size_t)t + i] * s->bend_c[3 * (size_t)t + j] * cn *
                           ((1.0 - nu) * tt + nu * (Ti[0] + Ti[1]) * (Tj[0] + Tj[1]));
                const double *dpj = s->dphi + 12 * (size_t)m->tri_edge[3 * (size_t)t + j];
                for (int va = 0; va < 4; va++)
                    for (int vb = 0; vb < 4; vb++)
                        for (int ra = 0; ra < 3; ra++)
                            for (int rb = 0; rb < 3; rb++)
                                ke[(3 * hl[i][va] + ra) * n + 3 * hl[j][vb] + rb] +=
                                    q * dpi[3 * va + ra] * dpj[3 * vb + rb];
            }
        }
        /* the second derivatives of phi of the edges whose first triangle is t */
        for (int i = 0; i < 3; i++) {
            int32_t e = m->tri_edge[3 * (size_t)t + i];
            if (!live[i] || m->edge_tri[2 * (size_t)e] != t || gphi[e] == 0.0)
                continue;
            double x[12], hh[144];
            hinge_coords(s, p, e, x);
            fs_shell_hinge_phi(x, NULL, hh);
            for (int va = 0; va < 4; va++)
                for (int vb = 0; vb < 4; vb++)
                    for (int ra = 0; ra < 3; ra++)
                        for (int rb = 0; rb < 3; rb++)
                            ke[(3 * hl[i][va] + ra) * n + 3 * hl[i][vb] + rb] +=
                                gphi[e] * hh[(3 * va + ra) * 12 + 3 * vb + rb];
        }
        block_dofs(s, nodes, k, idx);
        slot += fs_sparse_matrix_add_block(&s->K, n, idx, ke, slot);
    }
    for (int32_t i = 0; i < s->n_nodes; i++) {
        double K[9];
        bond_matrix(s, i, K);
        slot += fs_sparse_matrix_add_block(&s->K, 3, s->dof + 3 * (size_t)i, K, slot);
    }
    FS_ASSERT((size_t)(slot - s->slots) == s->n_slots);
    free(dedphi);
    free(gphi);
    s->counters.assemble_seconds += fs_seconds() - t_start;
    return energy;
}
