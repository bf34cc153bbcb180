/* Symmetric 3x3 eigen decomposition by cyclic Jacobi rotations, and the stress measures built on it. */
#include "fracture/eigen.h"

#include <math.h>
#include <string.h>

#include "base/error.h"

/* Sweeps are quadratically convergent; a 3x3 matrix needs about five. The cap only guards against
 * pathological rounding loops. */
#define JACOBI_MAX_SWEEPS 64

/* design: cyclic Jacobi (Numerical Recipes' jacobi, the method thesis §5.6.1 cites as [52]) rather
 * than the closed-form cubic: every rotation is an exact orthogonal transform, so the result stays
 * accurate for repeated and nearly repeated eigenvalues, where the trigonometric cubic formula loses
 * the eigenvectors. A zero off-diagonal entry is never rotated, so diagonal input is returned exactly.
 * m is the full symmetric matrix, updated in place to diagonal form; v, unless NULL, accumulates the
 * rotations (columns are eigenvectors). The rotations never read v, so the eigenvalues are the same
 * with or without it. */
static void jacobi3(double m[3][3], double (*v)[3])
{
    static const int pairs[3][3] = {{0, 1, 2}, {0, 2, 1}, {1, 2, 0}}; /* p, q, and the third index r */
    if (v)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                v[i][j] = i == j ? 1.0 : 0.0;
    for (int sweep = 0; sweep < JACOBI_MAX_SWEEPS; sweep++) {
        if (m[0][1] == 0.0 && m[0][2] == 0.0 && m[1][2] == 0.0)
            return;
        for (int k = 0; k < 3; k++) {
            int p = pairs[k][0], q = pairs[k][1], r = pairs[k][2];
            double apq = m[p][q];
            if (apq == 0.0)
                continue;
            double g = 100.0 * fabs(apq);
            double dp = m[p][p], dq = m[q][q];
            /* After a few sweeps an entry below the rounding of both diagonal entries is zero. */
            if (sweep > 3 && fabs(dp) + g == fabs(dp) && fabs(dq) + g == fabs(dq)) {
                m[p][q] = m[q][p] = 0.0;
                continue;
            }
            double h = dq - dp, t;
            if (fabs(h) + g == fabs(h)) {
                t = apq / h;
            } else {
                double theta = 0.5 * h / apq;
                t = 1.0 / (fabs(theta) + sqrt(1.0 + theta * theta));
                if (theta < 0.0)
                    t = -t;
            }
            double c = 1.0 / sqrt(1.0 + t * t), s = t * c, tau = s / (1.0 + c);
            m[p][p] = dp - t * apq;
            m[q][q] = dq + t * apq;
            m[p][q] = m[q][p] = 0.0;
            double grp = m[r][p], grq = m[r][q];
            m[r][p] = m[p][r] = grp - s * (grq + grp * tau);
            m[r][q] = m[q][r] = grq + s * (grp - grq * tau);
            for (int i = 0; v && i < 3; i++) {
                double vp = v[i][p], vq = v[i][q];
                v[i][p] = vp - s * (vq + vp * tau);
                v[i][q] = vq + s * (vp - vq * tau);
            }
        }
    }
}

/* Flips u so that its largest-magnitude component (the first of equal ones) is positive. */
static void orient(double *u)
{
    int big = 0;
    for (int i = 1; i < 3; i++)
        if (fabs(u[i]) > fabs(u[big]))
            big = i;
    if (u[big] < 0.0)
        for (int i = 0; i < 3; i++)
            u[i] = -u[i];
}

int fs_eigen_sym3(const double a[9], double values[3], double vectors[9])
{
    double m[3][3], v[3][3];
    const double upper[6] = {a[0], a[4], a[8], a[1], a[5], a[2]};
    for (int i = 0; i < 6; i++) {
        if (!isfinite(upper[i])) {
            memset(values, 0, 3 * sizeof *values);
            if (vectors)
                memset(vectors, 0, 9 * sizeof *vectors);
            fs_error(FS_ERR_INTERNAL, "eigen decomposition: matrix entry is not finite (%g)", upper[i]);
            return -1;
        }
    }
    m[0][0] = a[0];
    m[1][1] = a[4];
    m[2][2] = a[8];
    m[0][1] = m[1][0] = a[1];
    m[1][2] = m[2][1] = a[5];
    m[0][2] = m[2][0] = a[2];
    jacobi3(m, vectors ? v : NULL);

    /* Sort descending; a stable three-element insertion sort keeps equal values in axis order. */
    int order[3] = {0, 1, 2};
    for (int i = 1; i < 3; i++)
        for (int j = i; j > 0 && m[order[j]][order[j]] > m[order[j - 1]][order[j - 1]]; j--) {
            int tmp = order[j];
            order[j] = order[j - 1];
            order[j - 1] = tmp;
        }
    for (int k = 0; k < 3; k++)
        values[k] = m[order[k]][order[k]];
    if (!vectors)
        return 0;
    for (int k = 0; k < 2; k++) {
        for (int i = 0; i < 3; i++)
            vectors[3 * k + i] = v[i][order[k]];
        orient(vectors + 3 * k);
    }
    /* The third vector is already orthogonal to the first two; the cross product fixes the hand.
     * For exactly axis-aligned vectors the cross product is exact too. */
    const double *e0 = vectors, *e1 = vectors + 3;
    vectors[6] = e0[1] * e1[2] - e0[2] * e1[1];
    vectors[7] = e0[2] * e1[0] - e0[0] * e1[2];
    vectors[8] = e0[0] * e1[1] - e0[1] * e1[0];
    return 0;
}

int fs_eigen_principal_stress(const double stress[6], double sigma[3], double dirs[9])
{
    const double a[9] = {stress[0], stress[3], stress[5],
                         stress[3], stress[1], stress[4],
                         stress[5], stress[4], stress[2]};
    return fs_eigen_sym3(a, sigma, dirs);
}

int fs_eigen_principal_strain(const double strain[6], double eps[3], double dirs[9])
{
    const double exy = 0.5 * strain[3], eyz = 0.5 * strain[4], ezx = 0.5 * strain[5];
    const double a[9] = {strain[0], exy, ezx,
                         exy, strain[1], eyz,
                         ezx, eyz, strain[2]};
    return fs_eigen_sym3(a, eps, dirs);
}

/* Relative margin added to the closed-form largest eigenvalue so that it bounds the exact one: the
 * trigonometric formula loses up to about sqrt(machine epsilon) of the deviator's size when the
 * eigenvalues nearly coincide. */
#define CLOSED_FORM_MARGIN 1e-6

/* design: cheap bounds first: the largest of the in-plane 2 x 2 block's eigenvalues and sigma_zz plus
 * the Frobenius norm of the out-of-plane shears (Weyl's inequality; tight near a flat layer's free
 * top), and the mean stress plus sqrt(2/3) times the deviator's Frobenius norm (any frame, so also on
 * the sphere). Where both reach `level`, the closed-form (trigonometric) largest eigenvalue plus a
 * safety margin: about a sixth of the cost of the Jacobi decomposition. */
double fs_eigen_principal_bound(const double s[6], double level)
{
    double mean = 0.5 * (s[0] + s[1]), half = 0.5 * (s[0] - s[1]);
    double in_plane = mean + sqrt(half * half + s[3] * s[3]);
    double bound = fmax(in_plane, s[2]) + sqrt(2.0 * (s[4] * s[4] + s[5] * s[5]));
    double q = (s[0] + s[1] + s[2]) / 3.0;
    double d0 = s[0] - q, d1 = s[1] - q, d2 = s[2] - q;
    double shear2 = s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    double dev2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * shear2;
    bound = fmin(bound, q + sqrt(2.0 * dev2 / 3.0));
    bound += 1e-12 * (fabs(q) + sqrt(dev2)); /* the kernel's own rounding */
    if (bound <= level || dev2 == 0.0)
        return bound;
    double p = sqrt(dev2 / 6.0);
    double b0 = d0 / p, b1 = d1 / p, b2 = d2 / p, b3 = s[3] / p, b4 = s[4] / p, b5 = s[5] / p;
    double det = b0 * (b1 * b2 - b4 * b4) - b3 * (b3 * b2 - b4 * b5) + b5 * (b3 * b4 - b1 * b5);
    double r = fmin(1.0, fmax(-1.0, 0.5 * det));
    double largest = q + 2.0 * p * cos(acos(r) / 3.0);
    return fmin(bound, largest + CLOSED_FORM_MARGIN * (fabs(q) + 2.0 * p));
}

double fs_eigen_von_mises(const double s[6])
{
    double dxy = s[0] - s[1], dyz = s[1] - s[2], dzx = s[2] - s[0];
    double shear = s[3] * s[3] + s[4] * s[4] + s[5] * s[5];
    return sqrt(0.5 * (dxy * dxy + dyz * dyz + dzx * dzx) + 3.0 * shear);
}
