/* Element-plane split geometry (ray against a fan sector, crack directions, edge collapse) and the Griffith energy check. */
#include "fracture/split.h"

#include <math.h>

static double cross2(const double a[2], const double b[2])
{
    return a[0] * b[1] - a[1] * b[0];
}

fs_split_hit fs_split_ray_sector(const double a[2], const double b[2], const double d[2], double snap, double *s)
{
    *s = -1.0;
    double area = cross2(a, b);
    if (!(area > 0.0) || (d[0] == 0.0 && d[1] == 0.0))
        return FS_SPLIT_MISS;
    if (cross2(a, d) < 0.0 || cross2(d, b) < 0.0)
        return FS_SPLIT_MISS;
    /* the line a + s (b - a) meets the ray where cross(a + s (b - a), d) = 0 */
    double e[2] = {b[0] - a[0], b[1] - a[1]};
    double den = cross2(e, d);
    if (den == 0.0)
        return FS_SPLIT_MISS;
    double t = -cross2(a, d) / den;
    t = fmin(1.0, fmax(0.0, t));
    *s = t;
    if (t <= snap)
        return FS_SPLIT_AT_A;
    if (t >= 1.0 - snap)
        return FS_SPLIT_AT_B;
    return FS_SPLIT_EDGE;
}

bool fs_split_crack_direction(const double m[2], double dir[2])
{
    double len = hypot(m[0], m[1]);
    if (!(len > 0.0) || !isfinite(len)) {
        dir[0] = dir[1] = 0.0;
        return false;
    }
    dir[0] = -m[1] / len;
    dir[1] = m[0] / len;
    return true;
}

void fs_split_continue_direction(const double dir[2], const double incoming[2], double out[2])
{
    double dot = dir[0] * incoming[0] + dir[1] * incoming[1];
    double sign = dot < 0.0 ? -1.0 : 1.0;
    out[0] = sign * dir[0];
    out[1] = sign * dir[1];
}

void fs_split_project_onto_line(const double q[2], const double d[2], double out[2])
{
    double t = q[0] * d[0] + q[1] * d[1];
    out[0] = t * d[0];
    out[1] = t * d[1];
}

double fs_griffith_toughness_model_units(double toughness_j_per_m2)
{
    return 1e-4 * toughness_j_per_m2;
}

double fs_griffith_release(double e1, double e2, double a)
{
    if (!(a > 0.0))
        return NAN;
    return (e1 - e2) / a;
}

bool fs_griffith_extends(double e1, double e2, double a, double gc)
{
    double g = fs_griffith_release(e1, e2, a);
    return g > gc;
}
