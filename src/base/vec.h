/* Small 2-D / 3-D vector and 3x3 matrix helpers on plain double arrays. */
#ifndef FS_BASE_VEC_H
#define FS_BASE_VEC_H

#include <math.h>

#define FS_PI 3.14159265358979323846

static inline double fs_dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static inline double fs_norm3(const double *a) { return sqrt(fs_dot3(a, a)); }
static inline void fs_sub3(double *out, const double *a, const double *b)
{
    out[0] = a[0] - b[0];
    out[1] = a[1] - b[1];
    out[2] = a[2] - b[2];
}
static inline void fs_cross3(double *out, const double *a, const double *b)
{
    double x = a[1] * b[2] - a[2] * b[1], y = a[2] * b[0] - a[0] * b[2], z = a[0] * b[1] - a[1] * b[0];
    out[0] = x;
    out[1] = y;
    out[2] = z;
}
/* Twice the signed area of triangle (a, b, c) in the plane (positive when counter-clockwise). */
static inline double fs_orient2(const double *a, const double *b, const double *c)
{
    return (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
}

/* The adjugate (transposed cofactors) of the row-major 3x3 matrix m into adj (not aliasing m), so that
 * m adj = det(m) I; returns det(m), expanded along the first row (m[0] adj[0] + m[1] adj[3] +
 * m[2] adj[6]). adj[8] = m[0] m[4] - m[1] m[3] is the leading 2x2 minor: with m[0] and det, the
 * test of positive definiteness of a symmetric m. */
static inline double fs_mat3_adjugate(const double *m, double *adj)
{
    adj[0] = m[4] * m[8] - m[5] * m[7];
    adj[1] = m[2] * m[7] - m[1] * m[8];
    adj[2] = m[1] * m[5] - m[2] * m[4];
    adj[3] = m[5] * m[6] - m[3] * m[8];
    adj[4] = m[0] * m[8] - m[2] * m[6];
    adj[5] = m[2] * m[3] - m[0] * m[5];
    adj[6] = m[3] * m[7] - m[4] * m[6];
    adj[7] = m[1] * m[6] - m[0] * m[7];
    adj[8] = m[0] * m[4] - m[1] * m[3];
    return m[0] * adj[0] + m[1] * adj[3] + m[2] * adj[6];
}

/* The inverse of the row-major 3x3 matrix m into inv (may alias m): adj(m) / det(m), each entry
 * divided (not multiplied by 1 / det). Returns det(m); when it is 0 inv holds infinities or NaN, so
 * a caller that can meet a singular m tests the result. */
static inline double fs_mat3_inverse(const double *m, double *inv)
{
    double adj[9];
    double det = fs_mat3_adjugate(m, adj);
    for (int k = 0; k < 9; k++)
        inv[k] = adj[k] / det;
    return det;
}

/* The strain of a displacement gradient g (g[i][j] = d u_i / d x_j) in Voigt order with engineering
 * shears: xx, yy, zz, xy, yz, zx. */
static inline void fs_voigt_strain(const double g[3][3], double strain[6])
{
    strain[0] = g[0][0];
    strain[1] = g[1][1];
    strain[2] = g[2][2];
    strain[3] = g[0][1] + g[1][0];
    strain[4] = g[1][2] + g[2][1];
    strain[5] = g[2][0] + g[0][2];
}

#endif
