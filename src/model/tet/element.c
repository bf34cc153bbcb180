/* The linear tetrahedron: gradients, stiffness, strain, stress, nodal forces. */
#include "model/tet/element.h"

#include <math.h>

#include "base/vec.h"

int fs_tet_lame(double young, double poisson, double *lambda, double *mu)
{
    if (!(young > 0.0) || !(poisson > -1.0 && poisson < 0.5))
        return -1;
    *lambda = young * poisson / ((1.0 + poisson) * (1.0 - 2.0 * poisson));
    *mu = young / (2.0 * (1.0 + poisson));
    return 0;
}

int fs_tet_gradients(const double x[12], double g[12], double *volume)
{
    double e[3][3];
    for (int c = 0; c < 3; c++)
        fs_sub3(e[c], x + 3 * (c + 1), x);
    /* the rows of the inverse of [e1 e2 e3] (columns) are the gradients of N1..N3 */
    double c0[3], c1[3], c2[3];
    fs_cross3(c0, e[1], e[2]);
    fs_cross3(c1, e[2], e[0]);
    fs_cross3(c2, e[0], e[1]);
    double det = fs_dot3(e[0], c0);
    *volume = det / 6.0;
    if (!(det > 0.0))
        return -1;
    for (int k = 0; k < 3; k++) {
        g[3 + k] = c0[k] / det;
        g[6 + k] = c1[k] / det;
        g[9 + k] = c2[k] / det;
        g[k] = -(g[3 + k] + g[6 + k] + g[9 + k]);
    }
    return 0;
}

void fs_tet_stiffness(const double g[12], double volume, double lambda, double mu, double K[144])
{
    for (int a = 0; a < 4; a++)
        for (int b = 0; b < 4; b++) {
            const double *ga = g + 3 * a, *gb = g + 3 * b;
            double dot = fs_dot3(ga, gb);
            for (int i = 0; i < 3; i++)
                for (int j = 0; j < 3; j++)
                    K[12 * (3 * a + i) + 3 * b + j] =
                        volume * (lambda * ga[i] * gb[j] + mu * gb[i] * ga[j] + (i == j ? mu * dot : 0.0));
        }
}

void fs_tet_strain(const double g[12], const double u[12], double strain[6])
{
    double d[3][3] = {{0}}; /* d[i][j] = du_i / dx_j */
    for (int c = 0; c < 4; c++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                d[i][j] += u[3 * c + i] * g[3 * c + j];
    fs_voigt_strain(d, strain);
}

void fs_tet_stress(double lambda, double mu, const double strain[6], double stress[6])
{
    double tr = strain[0] + strain[1] + strain[2];
    for (int k = 0; k < 3; k++)
        stress[k] = lambda * tr + 2.0 * mu * strain[k];
    for (int k = 3; k < 6; k++)
        stress[k] = mu * strain[k];
}

void fs_tet_forces(const double g[12], double volume, const double stress[6], double f[12])
{
    for (int c = 0; c < 4; c++) {
        const double *gc = g + 3 * c;
        f[3 * c] = -volume * (stress[0] * gc[0] + stress[3] * gc[1] + stress[5] * gc[2]);
        f[3 * c + 1] = -volume * (stress[3] * gc[0] + stress[1] * gc[1] + stress[4] * gc[2]);
        f[3 * c + 2] = -volume * (stress[5] * gc[0] + stress[4] * gc[1] + stress[2] * gc[2]);
    }
}
