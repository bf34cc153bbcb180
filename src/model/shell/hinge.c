/* The bending measure of one interior edge, phi = 2 tan(theta / 2) of its dihedral angle, with its exact gradient and Hessian. */
#include "model/shell/internal.h"

#include <math.h>
#include <string.h>

#include "base/vec.h"

/* design: phi = 2 tan(theta / 2) = 2 s / (1 + c) with s = sin theta = e . (n1 x n2) and
 * c = cos theta = n1 . n2, e the unit edge a -> b and n1, n2 the unit normals of the two triangles
 * (Gingold et al. choose 2 tan(theta / 2) so that a sharp fold costs without bound; no arc tangent is
 * needed). Its derivatives follow by the chain rule through three maps,
 *   X (12) -> Y = (N1, N2, E) (9)    N1 = (b - a) x (c1 - a), N2 = (a - b) x (c2 - b), E = b - a
 *          -> Z = (n1, n2, e) (9)    each block normalised
 *          -> phi(Z),
 * so grad = J1^T J2^T g3 and
 *   H = J1^T (J2^T H3 J2 + sum_k g3_k d2 Z_k) J1 + sum_m (J2^T g3)_m d2 Y_m,
 * every term exact: d2 Y is the constant second derivative of the cross products, d2 Z that of
 * normalisation, H3 that of phi in (n1, n2, e). */

/* out = [w]x, the matrix of the cross product w x . (row-major 3x3). */
static void skew(const double w[3], double out[9])
{
    out[0] = 0.0, out[1] = -w[2], out[2] = w[1];
    out[3] = w[2], out[4] = 0.0, out[5] = -w[0];
    out[6] = -w[1], out[7] = w[0], out[8] = 0.0;
}

/* Writes the 3x3 block m (scaled by f) into the n-column matrix a at block (bi, bj), adding. */
static void add_block(double *a, int ncol, int bi, int bj, const double m[9], double f)
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            a[(3 * bi + i) * ncol + 3 * bj + j] += f * m[3 * i + j];
}

/* The Jacobian rows (3 x 12, into j1 at row block rb) of N = (p - q) x (r - q) for node blocks p, q, r:
 * dN/dp = -[r - q]x, dN/dr = [p - q]x, dN/dq = [r - p]x. */
static void cross_jacobian(double *j1, int rb, const double *x, int p, int q, int r)
{
    double d[3], m[9];
    for (int k = 0; k < 3; k++)
        d[k] = x[3 * r + k] - x[3 * q + k];
    skew(d, m);
    add_block(j1, 12, rb, p, m, -1.0);
    for (int k = 0; k < 3; k++)
        d[k] = x[3 * p + k] - x[3 * q + k];
    skew(d, m);
    add_block(j1, 12, rb, r, m, 1.0);
    for (int k = 0; k < 3; k++)
        d[k] = x[3 * r + k] - x[3 * p + k];
    skew(d, m);
    add_block(j1, 12, rb, q, m, 1.0);
}

/* Adds the Hessian of lambda . ((p - q) x (r - q)) to h (12 x 12): with B = -[lambda]x, the blocks
 * (p, r) = B, (p, q) = (q, r) = -B and their transposes; (q, q) = B + B^T = 0. */
static void cross_hessian(double *h, const double lambda[3], int p, int q, int r)
{
    double b[9], bt[9];
    skew(lambda, b);
    for (int k = 0; k < 9; k++)
        b[k] = -b[k];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            bt[3 * i + j] = b[3 * j + i];
    add_block(h, 12, p, r, b, 1.0);
    add_block(h, 12, r, p, bt, 1.0);
    add_block(h, 12, p, q, b, -1.0);
    add_block(h, 12, q, p, bt, -1.0);
    add_block(h, 12, q, r, b, -1.0);
    add_block(h, 12, r, q, bt, -1.0);
}

/* Normalises block k of y (9) into z; returns its length. */
static double normalise(const double *y, double *z)
{
    double r = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
    for (int k = 0; k < 3; k++)
        z[k] = y[k] / r;
    return r;
}

double fs_shell_hinge_phi(const double x[12], double *grad, double *hess)
{
    const double *a = x, *b = x + 3, *c1 = x + 6, *c2 = x + 9;
    double y[9], z[9], r[3];
    double ab[3], ac1[3], ba[3], bc2[3];
    for (int k = 0; k < 3; k++) {
        ab[k] = b[k] - a[k];
        ac1[k] = c1[k] - a[k];
        ba[k] = a[k] - b[k];
        bc2[k] = c2[k] - b[k];
    }
    fs_cross3(y, ab, ac1);
    fs_cross3(y + 3, ba, bc2);
    y[6] = ab[0], y[7] = ab[1], y[8] = ab[2];
    for (int k = 0; k < 3; k++) {
        r[k] = normalise(y + 3 * k, z + 3 * k);
        if (!(r[k] > 0.0))
            return NAN;
    }
    const double *n1 = z, *n2 = z + 3, *e = z + 6;
    double n1xn2[3];
    fs_cross3(n1xn2, n1, n2);
    double s = fs_dot3(e, n1xn2);
    double c = fs_dot3(n1, n2);
    double opc = 1.0 + c;
    if (!(opc > 1e-12))
        return NAN;
    double phi = 2.0 * s / opc;
    if (!grad && !hess)
        return phi;
    if (!hess) {
        /* the closed form: d theta / d c1 = -n1 / h1, d theta / d c2 = -n2 / h2 (h the heights of c1,
         * c2 over the edge), the edge's ends sharing -(the sum) by the feet of those heights, and
         * d phi / d theta = 1 + tan^2(theta / 2) */
        double le = r[2], h1 = r[0] / le, h2 = r[1] / le, dd = 1.0 + 0.25 * phi * phi;
        double s1 = 0.0, s2 = 0.0;
        for (int k = 0; k < 3; k++) {
            s1 += ac1[k] * ab[k];
            s2 += (c2[k] - a[k]) * ab[k];
        }
        s1 /= le * le;
        s2 /= le * le;
        for (int k = 0; k < 3; k++) {
            double g1 = dd * n1[k] / h1, g2 = dd * n2[k] / h2;
            grad[k] = (1.0 - s1) * g1 + (1.0 - s2) * g2;
            grad[3 + k] = s1 * g1 + s2 * g2;
            grad[6 + k] = -g1;
            grad[9 + k] = -g2;
        }
        return phi;
    }

    /* level 3: phi(n1, n2, e) */
    double ds[9], dc[9];
    fs_cross3(ds, n2, e);
    fs_cross3(ds + 3, e, n1);
    ds[6] = n1xn2[0], ds[7] = n1xn2[1], ds[8] = n1xn2[2];
    for (int k = 0; k < 3; k++) {
        dc[k] = n2[k];
        dc[3 + k] = n1[k];
        dc[6 + k] = 0.0;
    }
    double f_s = 2.0 / opc, f_c = -2.0 * s / (opc * opc);
    double f_sc = -2.0 / (opc * opc), f_cc = 4.0 * s / (opc * opc * opc);
    double g3[9];
    for (int k = 0; k < 9; k++)
        g3[k] = f_s * ds[k] + f_c * dc[k];

    /* level 2: g2 = J2^T g3, J2 = blockdiag((I - z z^T) / r) */
    double g2[9];
    for (int blk = 0; blk < 3; blk++) {
        const double *zb = z + 3 * blk, *gb = g3 + 3 * blk;
        double d = zb[0] * gb[0] + zb[1] * gb[1] + zb[2] * gb[2];
        for (int k = 0; k < 3; k++)
            g2[3 * blk + k] = (gb[k] - d * zb[k]) / r[blk];
    }

    /* level 1: J1 (9 x 12) */
    double j1[9 * 12];
    memset(j1, 0, sizeof j1);
    cross_jacobian(j1, 0, x, 1, 0, 2); /* N1 = (b - a) x (c1 - a) */
    cross_jacobian(j1, 1, x, 0, 1, 3); /* N2 = (a - b) x (c2 - b) */
    for (int k = 0; k < 3; k++) {
        j1[(6 + k) * 12 + 3 + k] = 1.0; /* E = b - a */
        j1[(6 + k) * 12 + k] = -1.0;
    }
    if (grad)
        for (int j = 0; j < 12; j++) {
            double v = 0.0;
            for (int i = 0; i < 9; i++)
                v += j1[i * 12 + j] * g2[i];
            grad[j] = v;
        }
    if (!hess)
        return phi;

    /* H3 in (n1, n2, e) */
    double h3[81];
    memset(h3, 0, sizeof h3);
    double m[9];
    skew(e, m); /* (n1, n2) block of d2 s: -[e]x */
    add_block(h3, 9, 0, 1, m, -f_s);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            h3[(3 + i) * 9 + j] += f_s * m[3 * i + j]; /* transpose of -[e]x is [e]x */
    skew(n2, m); /* (n1, e) block: [n2]x */
    add_block(h3, 9, 0, 2, m, f_s);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            h3[(6 + i) * 9 + j] -= f_s * m[3 * i + j];
    skew(n1, m); /* (n2, e) block: -[n1]x */
    add_block(h3, 9, 1, 2, m, -f_s);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            h3[(6 + i) * 9 + 3 + j] += f_s * m[3 * i + j];
    for (int k = 0; k < 3; k++) { /* d2 c: (n1, n2) = I */
        h3[k * 9 + 3 + k] += f_c;
        h3[(3 + k) * 9 + k] += f_c;
    }
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 9; j++)
            h3[i * 9 + j] += f_sc * (ds[i] * dc[j] + dc[i] * ds[j]) + f_cc * dc[i] * dc[j];

    /* H2 = J2^T H3 J2 + sum over blocks of g3 . d2 normalise */
    double h2[81];
    for (int bi = 0; bi < 3; bi++)
        for (int bj = 0; bj < 3; bj++) {
            const double *zi = z + 3 * bi, *zj = z + 3 * bj;
            double t[9]; /* H3_ij P_j */
            for (int i = 0; i < 3; i++) {
                const double *row = h3 + (3 * bi + i) * 9 + 3 * bj;
                double d = row[0] * zj[0] + row[1] * zj[1] + row[2] * zj[2];
                for (int j = 0; j < 3; j++)
                    t[3 * i + j] = row[j] - d * zj[j];
            }
            for (int j = 0; j < 3; j++) { /* P_i t */
                double d = zi[0] * t[j] + zi[1] * t[3 + j] + zi[2] * t[6 + j];
                for (int i = 0; i < 3; i++)
                    h2[(3 * bi + i) * 9 + 3 * bj + j] = (t[3 * i + j] - d * zi[i]) / (r[bi] * r[bj]);
            }
        }
    for (int blk = 0; blk < 3; blk++) {
        const double *zb = z + 3 * blk, *mu = g3 + 3 * blk;
        double mn = mu[0] * zb[0] + mu[1] * zb[1] + mu[2] * zb[2], rr = r[blk] * r[blk];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                h2[(3 * blk + i) * 9 + 3 * blk + j] -=
                    (mu[i] * zb[j] + mu[j] * zb[i] + (i == j ? mn : 0.0) - 3.0 * mn * zb[i] * zb[j]) / rr;
    }

    /* H = J1^T H2 J1 + the cross products' second derivatives */
    double t[9 * 12];
    for (int i = 0; i < 9; i++)
        for (int j = 0; j < 12; j++) {
            double v = 0.0;
            for (int k = 0; k < 9; k++)
                v += h2[i * 9 + k] * j1[k * 12 + j];
            t[i * 12 + j] = v;
        }
    for (int i = 0; i < 12; i++)
        for (int j = 0; j < 12; j++) {
            double v = 0.0;
            for (int k = 0; k < 9; k++)
                v += j1[k * 12 + i] * t[k * 12 + j];
            hess[i * 12 + j] = v;
        }
    cross_hessian(hess, g2, 1, 0, 2);
    cross_hessian(hess, g2 + 3, 0, 1, 3);
    return phi;
}
