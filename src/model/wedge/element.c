/* The 6-node wedge element of thesis §5.3: isoparametric shape functions, Table 5.1 quadrature, K, stresses. */
#include "model/wedge/element.h"

#include <math.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"

/* design: thesis Table 5.1 combines the 3-point Gauss rule through the thickness (zeta = 0,
 * +-sqrt(3/5), weights 8/9, 5/9) with the 3-point interior triangle rule ((2/3, 1/6, 1/6) and
 * permutations), listing the weights 5/27 and 8/27. Those sum to 2 although the reference wedge
 * (triangle of area 1/2 times thickness 2) has volume 1: the table's triangle weights (1/3) are
 * normalised to a unit-area triangle. We halve them (5/54, 8/54) so that sum det J w is the element
 * volume (tested), which gives the physical stiffness; the points are the table's, in its order. The
 * rule integrates degree 2 in (r, s) and degree 5 in zeta exactly, enough for det J and for
 * B^T D B det J of an undistorted wedge. */
#define GAUSS_Z 0.77459666924148337704   /* sqrt(3/5) */
#define W_END (5.0 / 54.0)
#define W_MID (8.0 / 54.0)

const double fs_wedge_gauss[FS_WEDGE_GAUSS][4] = {
    {2.0 / 3.0, 1.0 / 6.0, GAUSS_Z, W_END},
    {1.0 / 6.0, 2.0 / 3.0, GAUSS_Z, W_END},
    {1.0 / 6.0, 1.0 / 6.0, GAUSS_Z, W_END},
    {2.0 / 3.0, 1.0 / 6.0, 0.0, W_MID},
    {1.0 / 6.0, 2.0 / 3.0, 0.0, W_MID},
    {1.0 / 6.0, 1.0 / 6.0, 0.0, W_MID},
    {2.0 / 3.0, 1.0 / 6.0, -GAUSS_Z, W_END},
    {1.0 / 6.0, 2.0 / 3.0, -GAUSS_Z, W_END},
    {1.0 / 6.0, 1.0 / 6.0, -GAUSS_Z, W_END},
};

/* Thesis Eq. 5.9–5.14: N = (triangle coordinate) * (1 -+ zeta) / 2. */
void fs_wedge_shape(double r, double s, double zeta, double n[6])
{
    const double tri[3] = {r, s, 1.0 - r - s};
    const double lo = 0.5 * (1.0 - zeta), hi = 0.5 * (1.0 + zeta);
    for (int i = 0; i < 3; i++) {
        n[i] = tri[i] * lo;
        n[i + 3] = tri[i] * hi;
    }
}

void fs_wedge_shape_deriv(double r, double s, double zeta, double dn[18])
{
    const double tri[3] = {r, s, 1.0 - r - s};
    const double dtri_dr[3] = {1.0, 0.0, -1.0}, dtri_ds[3] = {0.0, 1.0, -1.0};
    const double lo = 0.5 * (1.0 - zeta), hi = 0.5 * (1.0 + zeta);
    for (int i = 0; i < 3; i++) {
        double *b = dn + 3 * i, *t = dn + 3 * (i + 3);
        b[0] = dtri_dr[i] * lo;
        b[1] = dtri_ds[i] * lo;
        b[2] = -0.5 * tri[i];
        t[0] = dtri_dr[i] * hi;
        t[1] = dtri_ds[i] * hi;
        t[2] = 0.5 * tri[i];
    }
}

/* Thesis Eq. 5.27–5.30: J[l][k] = dx_k / d(r,s,zeta)_l, and dN/dx = J^-1 dN/d(r,s,zeta). */
int fs_wedge_gradients(const double x[18], double r, double s, double zeta, double dndx[18], double *detj)
{
    double dn[18], J[3][3] = {{0}};
    fs_wedge_shape_deriv(r, s, zeta, dn);
    for (int i = 0; i < FS_WEDGE_NODES; i++)
        for (int l = 0; l < 3; l++)
            for (int k = 0; k < 3; k++)
                J[l][k] += dn[3 * i + l] * x[3 * i + k];
    /* Cofactors: inv[k][l] = cof[l][k] / det. */
    double cof[3][3];
    cof[0][0] = J[1][1] * J[2][2] - J[1][2] * J[2][1];
    cof[0][1] = J[1][2] * J[2][0] - J[1][0] * J[2][2];
    cof[0][2] = J[1][0] * J[2][1] - J[1][1] * J[2][0];
    cof[1][0] = J[0][2] * J[2][1] - J[0][1] * J[2][2];
    cof[1][1] = J[0][0] * J[2][2] - J[0][2] * J[2][0];
    cof[1][2] = J[0][1] * J[2][0] - J[0][0] * J[2][1];
    cof[2][0] = J[0][1] * J[1][2] - J[0][2] * J[1][1];
    cof[2][1] = J[0][2] * J[1][0] - J[0][0] * J[1][2];
    cof[2][2] = J[0][0] * J[1][1] - J[0][1] * J[1][0];
    double det = J[0][0] * cof[0][0] + J[0][1] * cof[0][1] + J[0][2] * cof[0][2];
    *detj = det;
    if (!(det > 0.0) || !isfinite(det)) {
        fs_error(FS_ERR_DATA, "wedge element is inverted or degenerate (det J = %g at r = %g, s = %g, zeta = %g)",
                 det, r, s, zeta);
        return -1;
    }
    double inv = 1.0 / det;
    /* dN_i/dx_k = sum_l (J^-1)[k][l] dN_i/dxi_l = sum_l cof[l][k] dN_i/dxi_l / det. */
    for (int i = 0; i < FS_WEDGE_NODES; i++)
        for (int k = 0; k < 3; k++)
            dndx[3 * i + k] = (cof[0][k] * dn[3 * i] + cof[1][k] * dn[3 * i + 1] + cof[2][k] * dn[3 * i + 2]) * inv;
    return 0;
}

int fs_wedge_elasticity(double young, double poisson, double D[36])
{
    if (!(young > 0.0) || !isfinite(young) || !(poisson > -1.0 && poisson < 0.5)) {
        fs_error(FS_ERR_DATA, "wedge material: need Young's modulus > 0 and -1 < Poisson's ratio < 0.5 "
                 "(got E = %g MPa, nu = %g)", young, poisson);
        return -1;
    }
    double c = young / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    memset(D, 0, 36 * sizeof *D);
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++)
            D[6 * i + j] = i == j ? c * (1.0 - poisson) : c * poisson;
        D[6 * (i + 3) + (i + 3)] = 0.5 * young / (1.0 + poisson); /* shear modulus G */
    }
    return 0;
}

/* design: the strain-displacement matrix B (6x18, thesis §5.3.3) has three nonzero entries per
 * column: displacement component k of a node enters the strain rows STRAIN_ROW[k] (ascending)
 * through its shape function's derivative along STRAIN_AXIS[k]. The products with B (D B, B' D B,
 * B' sigma) run over those entries only, in the same ascending order as dense sums, whose other
 * terms are exact zeros: the results are the dense products' bit for bit, at a third to a half of
 * their multiplications. */
static const int STRAIN_ROW[3][3] = {{0, 3, 5}, {1, 3, 4}, {2, 4, 5}};
static const int STRAIN_AXIS[3][3] = {{0, 1, 2}, {1, 0, 2}, {2, 1, 0}};

/* B's nonzero entries from the Cartesian derivatives: bval[j][t] is B[STRAIN_ROW[j % 3][t]][j]. */
static void strain_entries(const double dndx[18], double bval[FS_WEDGE_DOF][3])
{
    for (int j = 0; j < FS_WEDGE_DOF; j++)
        for (int t = 0; t < 3; t++)
            bval[j][t] = dndx[3 * (j / 3) + STRAIN_AXIS[j % 3][t]];
}

/* Strain (engineering shears) from the Cartesian derivatives: eps = B u, written out. */
static void strain_from_gradients(const double dndx[18], const double u[18], double e[6])
{
    double g[3][3] = {{0}}; /* g[a][b] = d u_a / d x_b */
    for (int i = 0; i < FS_WEDGE_NODES; i++)
        for (int a = 0; a < 3; a++)
            for (int b = 0; b < 3; b++)
                g[a][b] += u[3 * i + a] * dndx[3 * i + b];
    fs_voigt_strain(g, e);
}

static void mat6_vec(const double D[36], const double v[6], double out[6])
{
    for (int i = 0; i < 6; i++) {
        double sum = 0.0;
        for (int j = 0; j < 6; j++)
            sum += D[6 * i + j] * v[j];
        out[i] = sum;
    }
}

int fs_wedge_volume(const double x[18], double *volume)
{
    double dndx[18], detj, v = 0.0;
    *volume = 0.0;
    for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
        const double *p = fs_wedge_gauss[g];
        if (fs_wedge_gradients(x, p[0], p[1], p[2], dndx, &detj) < 0)
            return -1;
        v += detj * p[3];
    }
    *volume = v;
    return 0;
}

int fs_wedge_stiffness(const double x[18], const double D[36], double K[324])
{
    double Kup[FS_WEDGE_DOF][FS_WEDGE_DOF] = {{0}};
    for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
        const double *p = fs_wedge_gauss[g];
        double dndx[18], detj, DB[6][FS_WEDGE_DOF], bval[FS_WEDGE_DOF][3];
        if (fs_wedge_gradients(x, p[0], p[1], p[2], dndx, &detj) < 0)
            return -1;
        strain_entries(dndx, bval);
        for (int a = 0; a < 6; a++)
            for (int j = 0; j < FS_WEDGE_DOF; j++) {
                const int *row = STRAIN_ROW[j % 3];
                double sum = 0.0;
                sum += D[6 * a + row[0]] * bval[j][0];
                sum += D[6 * a + row[1]] * bval[j][1];
                sum += D[6 * a + row[2]] * bval[j][2];
                DB[a][j] = sum;
            }
        double wdet = detj * p[3];
        for (int i = 0; i < FS_WEDGE_DOF; i++) {
            const int *row = STRAIN_ROW[i % 3];
            for (int j = i; j < FS_WEDGE_DOF; j++) {
                double sum = 0.0;
                sum += bval[i][0] * DB[row[0]][j];
                sum += bval[i][1] * DB[row[1]][j];
                sum += bval[i][2] * DB[row[2]][j];
                Kup[i][j] += sum * wdet;
            }
        }
    }
    for (int i = 0; i < FS_WEDGE_DOF; i++)
        for (int j = i; j < FS_WEDGE_DOF; j++)
            K[FS_WEDGE_DOF * i + j] = K[FS_WEDGE_DOF * j + i] = Kup[i][j];
    return 0;
}

int fs_wedge_strain(const double x[18], const double u[18], double r, double s, double zeta,
                    double strain[6])
{
    double dndx[18], detj;
    if (fs_wedge_gradients(x, r, s, zeta, dndx, &detj) < 0)
        return -1;
    strain_from_gradients(dndx, u, strain);
    return 0;
}

/* Thesis Eq. 5.53, with the eigenstrain subtracted: sigma = D (B u - eps0). */
static int stress_at(const double x[18], const double D[36], const double u[18], const double eps0[6],
                     double r, double s, double zeta, double out[6])
{
    double e[6];
    if (fs_wedge_strain(x, u, r, s, zeta, e) < 0)
        return -1;
    if (eps0)
        for (int c = 0; c < 6; c++)
            e[c] -= eps0[c];
    mat6_vec(D, e, out);
    return 0;
}

int fs_wedge_stress(const double x[18], const double D[36], const double u[18], const double eps0[6],
                    double stress_gauss[54], double stress_centre[6])
{
    if (stress_gauss)
        for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
            const double *p = fs_wedge_gauss[g];
            if (stress_at(x, D, u, eps0, p[0], p[1], p[2], stress_gauss + 6 * g) < 0)
                return -1;
        }
    if (stress_centre && stress_at(x, D, u, eps0, 1.0 / 3.0, 1.0 / 3.0, 0.0, stress_centre) < 0)
        return -1;
    return 0;
}

int fs_wedge_eigenstrain_force(const double x[18], const double D[36], const double eps0[6], double f[18])
{
    double sigma0[6], acc[FS_WEDGE_DOF] = {0};
    mat6_vec(D, eps0, sigma0);
    for (int g = 0; g < FS_WEDGE_GAUSS; g++) {
        const double *p = fs_wedge_gauss[g];
        double dndx[18], detj, bval[FS_WEDGE_DOF][3];
        if (fs_wedge_gradients(x, p[0], p[1], p[2], dndx, &detj) < 0)
            return -1;
        strain_entries(dndx, bval);
        double wdet = detj * p[3];
        for (int i = 0; i < FS_WEDGE_DOF; i++) {
            const int *row = STRAIN_ROW[i % 3];
            double sum = 0.0;
            sum += bval[i][0] * sigma0[row[0]];
            sum += bval[i][1] * sigma0[row[1]];
            sum += bval[i][2] * sigma0[row[2]];
            acc[i] += sum * wdet;
        }
    }
    memcpy(f, acc, sizeof acc);
    return 0;
}
