/* Small 2-D / 3-D vector helpers on plain double arrays. */
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

#endif
