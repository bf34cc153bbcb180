/* Nodal principal planes and the separation tensor. */
#include "fracture/separation.h"

#include <math.h>
#include <string.h>

#include "fracture/eigen.h"

void fs_nodal_stress_add(fs_nodal_stress *a, const double s[6])
{
    for (int k = 0; k < 6; k++)
        a->sum[k] += s[k];
    a->count++;
}

bool fs_nodal_stress_mean(const fs_nodal_stress *a, double mean[6])
{
    for (int k = 0; k < 6; k++)
        mean[k] = a->count > 0 ? a->sum[k] / a->count : 0.0;
    return a->count > 0;
}

/* Voigt order xx, yy, zz, xy, yz, zx: the row and column of each component. */
static const int voigt_row[6] = {0, 1, 2, 0, 1, 2}, voigt_col[6] = {0, 1, 2, 1, 2, 0};

static void voigt_to_matrix(const double s[6], double m[3][3])
{
    for (int k = 0; k < 6; k++)
        m[voigt_row[k]][voigt_col[k]] = m[voigt_col[k]][voigt_row[k]] = s[k];
}

/* out = R m R^T as Voigt. */
static void turn(const double r[3][3], const double m[3][3], double out[6])
{
    for (int k = 0; k < 6; k++) {
        int i = voigt_row[k], j = voigt_col[k];
        double sum = 0.0;
        for (int p = 0; p < 3; p++)
            for (int q = 0; q < 3; q++)
                sum += r[i][p] * m[p][q] * r[j][q];
        out[k] = sum;
    }
}

void fs_plane_stress_voigt(const double e1[3], const double e2[3], const double plane[3], double out[6])
{
    for (int k = 0; k < 6; k++) {
        int i = voigt_row[k], j = voigt_col[k];
        out[k] = plane[0] * e1[i] * e1[j] + plane[1] * e2[i] * e2[j] + plane[2] * (e1[i] * e2[j] + e2[i] * e1[j]);
    }
}

void fs_tip_stress_begin(fs_tip_stress *a, const double ahead[3], const double normal[3], double radius)
{
    memset(a, 0, sizeof *a);
    memcpy(a->ahead, ahead, sizeof a->ahead);
    a->radius = radius;
    a->surface = normal != NULL;
    if (normal)
        memcpy(a->normal, normal, sizeof a->normal);
}

void fs_tip_stress_add(fs_tip_stress *a, const double offset[3], const double normal[3], double size,
                       const double s[6])
{
    double along = offset[0] * a->ahead[0] + offset[1] * a->ahead[1] + offset[2] * a->ahead[2];
    double r2 = (offset[0] * offset[0] + offset[1] * offset[1] + offset[2] * offset[2]) / (a->radius * a->radius);
    if (!(along > 0.0) || !(r2 <= 9.0) || !(size > 0.0))
        return;
    double turned[6];
    memcpy(turned, s, sizeof turned);
    if (a->surface && normal) {
        /* Rodrigues: the rotation about v = n x t by the angle between n and t, with c = n . t */
        const double *n = normal, *t = a->normal;
        double v[3] = {n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]};
        double c = n[0] * t[0] + n[1] * t[1] + n[2] * t[2];
        if (!(c > 0.5))
            return;
        double vx[3][3] = {{0.0, -v[2], v[1]}, {v[2], 0.0, -v[0]}, {-v[1], v[0], 0.0}}, r[3][3], m[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double sq = 0.0;
                for (int k = 0; k < 3; k++)
                    sq += vx[i][k] * vx[k][j];
                r[i][j] = (i == j) + vx[i][j] + sq / (1.0 + c);
            }
        voigt_to_matrix(s, m);
        turn(r, m, turned);
    }
    double wt = size * exp(-r2);
    for (int k = 0; k < 6; k++)
        a->sum[k] += wt * turned[k];
    a->weight += wt;
}

bool fs_tip_stress_mean(const fs_tip_stress *a, double mean[6])
{
    bool any = a->weight > 0.0;
    for (int k = 0; k < 6; k++)
        mean[k] = any ? a->sum[k] / a->weight : 0.0;
    if (any && a->surface) {
        /* P S P with P = I - t t^T */
        double p[3][3], m[3][3];
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                p[i][j] = (i == j) - a->normal[i] * a->normal[j];
        voigt_to_matrix(mean, m);
        turn(p, m, mean);
    }
    return any;
}

/* The largest of a decomposition's values (descending) and its vector: *value and normal (if not
 * NULL); passes rc on. */
static int largest_of(int rc, const double values[3], const double vectors[9], double *value, double normal[3])
{
    *value = values[0];
    if (normal)
        memcpy(normal, vectors, 3 * sizeof *normal);
    return rc;
}

int fs_nodal_principal_plane(const double stress[6], double *sigma1, double normal[3])
{
    double sigma[3], dirs[9];
    return largest_of(fs_eigen_principal_stress(stress, sigma, normal ? dirs : NULL), sigma, dirs, sigma1, normal);
}

int fs_separation_split_stress(const double stress[6], double plus[6], double minus[6])
{
    double v[3], n[9];
    int rc = fs_eigen_principal_stress(stress, v, n);
    double p[6] = {0.0}, q[6] = {0.0};
    for (int i = 0; i < 3 && rc == 0; i++) {
        const double *e = n + 3 * i;
        /* v_i e e^T in Voigt order xx, yy, zz, xy, yz, zx */
        const double outer[6] = {e[0] * e[0], e[1] * e[1], e[2] * e[2], e[0] * e[1], e[1] * e[2], e[2] * e[0]};
        double *to = v[i] > 0.0 ? p : q;
        for (int k = 0; k < 6; k++)
            to[k] += v[i] * outer[k];
    }
    if (plus)
        memcpy(plus, p, sizeof p);
    if (minus)
        memcpy(minus, q, sizeof q);
    return rc;
}

void fs_separation_add_m(double zeta[9], const double a[3], double scale)
{
    double len = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    if (!(len > 0.0))
        return;
    double k = scale / len;
    for (int i = 0; i < 3; i++)
        for (int j = i; j < 3; j++) {
            double v = k * a[i] * a[j]; /* once for both triangles: a symmetric zeta stays symmetric */
            zeta[3 * i + j] += v;
            if (j != i)
                zeta[3 * j + i] += v;
        }
}

/* zeta += sign (sum m(f) - m(F)) over n forces f (F their sum): one half of Eq. 32. */
static void add_balanced(double zeta[9], const double *f, int32_t n, double sign)
{
    double total[3] = {0.0, 0.0, 0.0};
    for (int32_t q = 0; q < n; q++) {
        fs_separation_add_m(zeta, f + 3 * (size_t)q, 0.5 * sign);
        for (int k = 0; k < 3; k++)
            total[k] += f[3 * (size_t)q + k];
    }
    fs_separation_add_m(zeta, total, -0.5 * sign);
}

void fs_separation_tensor(const double *f_plus, int32_t n_plus, const double *f_minus, int32_t n_minus,
                          double zeta[9])
{
    memset(zeta, 0, 9 * sizeof *zeta);
    add_balanced(zeta, f_plus, n_plus, 1.0);
    add_balanced(zeta, f_minus, n_minus, -1.0);
}

int fs_separation_largest(const double zeta[9], double *value, double normal[3])
{
    double v[3], n[9];
    return largest_of(fs_eigen_sym3(zeta, v, normal ? n : NULL), v, n, value, normal);
}
