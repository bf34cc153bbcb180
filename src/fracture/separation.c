/* The separation tensor (O'Brien & Hodgins 1999, §4.1-4.2). */
#include "fracture/separation.h"

#include <math.h>
#include <string.h>

#include "fracture/eigen.h"

static void voigt_to_matrix(const double s[6], double a[9])
{
    a[0] = s[0];
    a[4] = s[1];
    a[8] = s[2];
    a[1] = a[3] = s[3];
    a[5] = a[7] = s[4];
    a[2] = a[6] = s[5];
}

int fs_separation_split(const double stress[6], double plus[6], double minus[6])
{
    /* all eigenvalues <= 0, or all >= 0: no decomposition needed */
    if (fs_eigen_principal_bound(stress, 0.0) <= 0.0) {
        memset(plus, 0, 6 * sizeof *plus);
        memcpy(minus, stress, 6 * sizeof *minus);
        return 0;
    }
    const double neg[6] = {-stress[0], -stress[1], -stress[2], -stress[3], -stress[4], -stress[5]};
    if (fs_eigen_principal_bound(neg, 0.0) <= 0.0) {
        memcpy(plus, stress, 6 * sizeof *plus);
        memset(minus, 0, 6 * sizeof *minus);
        return 0;
    }
    double a[9], v[3], n[9];
    voigt_to_matrix(stress, a);
    if (fs_eigen_sym3(a, v, n) < 0) {
        memset(plus, 0, 6 * sizeof *plus);
        memset(minus, 0, 6 * sizeof *minus);
        return -1;
    }
    memset(plus, 0, 6 * sizeof *plus);
    memset(minus, 0, 6 * sizeof *minus);
    for (int i = 0; i < 3; i++) {
        const double *e = n + 3 * i;
        double outer[6] = {e[0] * e[0], e[1] * e[1], e[2] * e[2], e[0] * e[1], e[1] * e[2], e[2] * e[0]};
        double *dst = v[i] > 0.0 ? plus : minus;
        for (int k = 0; k < 6; k++)
            dst[k] += v[i] * outer[k];
    }
    return 0;
}

void fs_separation_m(const double a[3], double m[6])
{
    double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(len > 0.0)) {
        memset(m, 0, 6 * sizeof *m);
        return;
    }
    m[0] = a[0] * a[0] / len;
    m[1] = a[1] * a[1] / len;
    m[2] = a[2] * a[2] / len;
    m[3] = a[0] * a[1] / len;
    m[4] = a[1] * a[2] / len;
    m[5] = a[2] * a[0] / len;
}

void fs_separation_init(fs_separation *s)
{
    memset(s, 0, sizeof *s);
}

void fs_separation_add(fs_separation *s, const double f_plus[3], const double f_minus[3])
{
    double mp[6], mm[6];
    fs_separation_m(f_plus, mp);
    fs_separation_m(f_minus, mm);
    for (int k = 0; k < 3; k++) {
        s->f_plus[k] += f_plus[k];
        s->f_minus[k] += f_minus[k];
    }
    for (int k = 0; k < 6; k++) {
        s->m_plus[k] += mp[k];
        s->m_minus[k] += mm[k];
    }
}

void fs_separation_tensor(const fs_separation *s, double zeta[6])
{
    double up[6], um[6];
    fs_separation_m(s->f_plus, up);
    fs_separation_m(s->f_minus, um);
    for (int k = 0; k < 6; k++)
        zeta[k] = 0.5 * (-up[k] + s->m_plus[k] + um[k] - s->m_minus[k]);
}

int fs_separation_eigen(const double zeta[6], double values[3], double vectors[9])
{
    double a[9];
    voigt_to_matrix(zeta, a);
    return fs_eigen_sym3(a, values, vectors);
}

int fs_separation_largest(const double zeta[6], double *value, double normal[3])
{
    double a[9], v[3], n[9];
    voigt_to_matrix(zeta, a);
    if (fs_eigen_sym3(a, v, n) < 0) {
        *value = 0.0;
        normal[0] = normal[1] = normal[2] = 0.0;
        return -1;
    }
    *value = v[0];
    memcpy(normal, n, 3 * sizeof *normal);
    return 0;
}
