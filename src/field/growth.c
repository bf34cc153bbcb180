/* Background growth fields and their exact flow maps, the equivalent eigenstrain, shrinkage and thickness over time. */
#include "field/growth.h"

#include <math.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"

/* design: the planar growth tensor (thesis §3.3.1, the matrix T_G before Eq. 3.5, partly scrambled in
 * the extraction and re-derived here) is G = r1 u u^T + r2 w w^T with u = (cos alpha, sin alpha) the
 * direction of r1 and w = (-sin alpha, cos alpha) its normal; its third eigenvalue (the z axis) is 0.
 * The thesis measures alpha from the y axis with u = (sin alpha, cos alpha), which gives its
 * G_xx = r1 sin^2 + r2 cos^2 and G_xy = (r1 - r2) sin cos; field.h measures the angle from the x axis.
 * G is symmetric with these eigenvectors, so exp(G dt) = e^{r1 dt} u u^T + e^{r2 dt} w w^T exactly,
 * without a series. */

/* The radius at t of a radius that starts at r0 and grows by rate per time unit. */
static double linear_radius(double r0, double rate, double t) { return r0 + rate * t; }

int fs_growth_field_init(fs_growth_field *f, const fs_growth *g, const fs_growth_fixed_point *fixed,
                         const fs_domain *d, double time_end)
{
    memset(f, 0, sizeof *f);
    f->type = FS_GROWTH_NONE;
    f->axis1[0] = 1.0;
    f->radius0 = d->radius;

    if (!(time_end >= 0.0) || !isfinite(time_end)) {
        fs_error(FS_ERR_DATA, "[time] end: expected a finite time >= 0 for growth, got %g", time_end);
        return -1;
    }
    switch (g->type) {
    case FS_GROWTH_NONE:
        return 0;
    case FS_GROWTH_PLANAR: {
        if (d->type == FS_DOMAIN_SPHERE) {
            fs_error(FS_ERR_DATA, "[growth] type: expected none or sphere for a sphere domain, got 'planar'");
            return -1;
        }
        if (!isfinite(g->r1) || !isfinite(g->r2) || !isfinite(g->angle)) {
            fs_error(FS_ERR_DATA, "[growth] r1, r2, angle: expected finite numbers");
            return -1;
        }
        double a = g->angle * (FS_PI / 180.0);
        f->r1 = g->r1;
        f->r2 = g->r2;
        f->axis1[0] = cos(a);
        f->axis1[1] = sin(a);
        if (fixed) {
            f->fixed[0] = fixed->fixed_x;
            f->fixed[1] = fixed->fixed_y;
        } else {
            f->fixed[0] = 0.5 * fs_domain_extent_x(d);
            f->fixed[1] = 0.5 * fs_domain_extent_y(d);
        }
        break;
    }
    case FS_GROWTH_CYLINDER:
    case FS_GROWTH_SPHERE: {
        fs_domain_type want = g->type == FS_GROWTH_CYLINDER ? FS_DOMAIN_CYLINDER : FS_DOMAIN_SPHERE;
        if (d->type != want) {
            fs_error(FS_ERR_DATA, "[growth] type: growth '%s' needs a %s domain, got '%s'",
                     fs_growth_type_name(g->type), fs_domain_type_name(want), fs_domain_type_name(d->type));
            return -1;
        }
        double ratio = g->type == FS_GROWTH_SPHERE ? g->axis_ratio : 1.0;
        if (!isfinite(g->rate) || !isfinite(ratio)) {
            fs_error(FS_ERR_DATA, "[growth] rate, axis_ratio: expected finite numbers");
            return -1;
        }
        if (!(d->radius > 0.0)) {
            fs_error(FS_ERR_DATA, "[domain] radius: expected a positive radius, got %g", d->radius);
            return -1;
        }
        double r_end = linear_radius(d->radius, g->rate, time_end);
        if (!(r_end > 0.0)) {
            fs_error(FS_ERR_DATA, "[growth] rate: the radius %g + %g * %g (time end) = %g cm must stay positive",
                     d->radius, g->rate, time_end, r_end);
            return -1;
        }
        double c_end = linear_radius(d->radius, ratio * g->rate, time_end);
        if (!(c_end > 0.0)) {
            fs_error(FS_ERR_DATA,
                     "[growth] axis_ratio: the z semi-axis %g + %g * %g * %g (time end) = %g cm must stay positive",
                     d->radius, ratio, g->rate, time_end, c_end);
            return -1;
        }
        f->rate = g->rate;
        f->rate_z = ratio * g->rate;
        break;
    }
    default:
        fs_error(FS_ERR_DATA, "[growth] type: unknown growth type %d", (int)g->type);
        return -1;
    }
    f->type = g->type;
    return 0;
}

double fs_growth_radius(const fs_growth_field *f, double t)
{
    if (f->type == FS_GROWTH_CYLINDER || f->type == FS_GROWTH_SPHERE)
        return linear_radius(f->radius0, f->rate, t);
    return f->radius0;
}

double fs_growth_radius_z(const fs_growth_field *f, double t)
{
    if (f->type == FS_GROWTH_SPHERE)
        return linear_radius(f->radius0, f->rate_z, t);
    return fs_growth_radius(f, t);
}

/* The planar 2x2 matrix e1 u u^T + e2 w w^T (row-major); exactly e1 I when e1 == e2. */
static void planar_matrix(const fs_growth_field *f, double e1, double e2, double m[4])
{
    if (e1 == e2) {
        m[0] = m[3] = e1;
        m[1] = m[2] = 0.0;
        return;
    }
    double c = f->axis1[0], s = f->axis1[1];
    m[0] = e1 * c * c + e2 * s * s;
    m[3] = e1 * s * s + e2 * c * c;
    m[1] = m[2] = (e1 - e2) * c * s;
}

/* Scale factors of the cylinder / sphere flow from t0 to t1: around (ka) and along z (kc). */
static void radial_factors(const fs_growth_field *f, double t0, double t1, double *ka, double *kc)
{
    double a0 = fs_growth_radius(f, t0), a1 = fs_growth_radius(f, t1);
    FS_ASSERT(a0 > 0.0 && a1 > 0.0);
    *ka = a1 / a0;
    if (f->type == FS_GROWTH_SPHERE) {
        double c0 = fs_growth_radius_z(f, t0), c1 = fs_growth_radius_z(f, t1);
        FS_ASSERT(c0 > 0.0 && c1 > 0.0);
        *kc = c1 / c0;
    } else {
        *kc = 1.0;
    }
}

void fs_growth_jacobian(const fs_growth_field *f, double t0, double t1, double J[9])
{
    for (int i = 0; i < 9; i++)
        J[i] = (i % 4 == 0) ? 1.0 : 0.0;
    switch (f->type) {
    case FS_GROWTH_NONE:
        return;
    case FS_GROWTH_PLANAR: {
        double dt = t1 - t0, m[4];
        planar_matrix(f, exp(f->r1 * dt), exp(f->r2 * dt), m);
        J[0] = m[0];
        J[1] = m[1];
        J[3] = m[2];
        J[4] = m[3];
        return;
    }
    case FS_GROWTH_CYLINDER: {
        double ka, kc;
        radial_factors(f, t0, t1, &ka, &kc);
        J[0] = ka;
        return;
    }
    case FS_GROWTH_SPHERE: {
        double ka, kc;
        radial_factors(f, t0, t1, &ka, &kc);
        J[0] = J[4] = ka;
        J[8] = kc;
        return;
    }
    }
}

void fs_growth_flow(const fs_growth_field *f, const double p[3], double t0, double t1, double out[3])
{
    double J[9], q[3];
    fs_growth_jacobian(f, t0, t1, J);
    if (f->type == FS_GROWTH_PLANAR) {
        double dx = p[0] - f->fixed[0], dy = p[1] - f->fixed[1];
        q[0] = f->fixed[0] + (J[0] * dx + J[1] * dy);
        q[1] = f->fixed[1] + (J[3] * dx + J[4] * dy);
        q[2] = p[2];
    } else {
        /* The other Jacobians are diagonal: scale each coordinate about the origin. */
        q[0] = J[0] * p[0];
        q[1] = J[4] * p[1];
        q[2] = J[8] * p[2];
    }
    out[0] = q[0];
    out[1] = q[1];
    out[2] = q[2];
}

/* The velocity gradient grad v at time t (3x3); the velocity is grad v (p - origin of the field). */
static void velocity_gradient(const fs_growth_field *f, double t, double L[9])
{
    for (int i = 0; i < 9; i++)
        L[i] = 0.0;
    switch (f->type) {
    case FS_GROWTH_NONE:
        return;
    case FS_GROWTH_PLANAR: {
        double m[4];
        planar_matrix(f, f->r1, f->r2, m);
        L[0] = m[0];
        L[1] = m[1];
        L[3] = m[2];
        L[4] = m[3];
        return;
    }
    case FS_GROWTH_CYLINDER: {
        double r = fs_growth_radius(f, t);
        FS_ASSERT(r > 0.0);
        L[0] = f->rate / r;
        return;
    }
    case FS_GROWTH_SPHERE: {
        double a = fs_growth_radius(f, t), c = fs_growth_radius_z(f, t);
        FS_ASSERT(a > 0.0 && c > 0.0);
        L[0] = L[4] = f->rate / a;
        L[8] = f->rate_z / c;
        return;
    }
    }
}

void fs_growth_velocity(const fs_growth_field *f, const double p[3], double t, double v[3])
{
    double L[9], q[3] = {p[0], p[1], p[2]};
    velocity_gradient(f, t, L);
    if (f->type == FS_GROWTH_PLANAR) {
        q[0] -= f->fixed[0];
        q[1] -= f->fixed[1];
    }
    for (int i = 0; i < 3; i++)
        v[i] = L[3 * i] * q[0] + L[3 * i + 1] * q[1] + L[3 * i + 2] * q[2];
}

double fs_growth_stretch(const fs_growth_field *f, const double p[3], const double d[3], double t0, double t1)
{
    (void)p;
    double J[9], jd[3];
    double len = fs_norm3(d);
    FS_ASSERT(len > 0.0);
    fs_growth_jacobian(f, t0, t1, J);
    for (int i = 0; i < 3; i++)
        jd[i] = J[3 * i] * d[0] + J[3 * i + 1] * d[1] + J[3 * i + 2] * d[2];
    return fs_norm3(jd) / len;
}

double fs_growth_rate_along(const fs_growth_field *f, const double p[3], const double d[3], double t)
{
    (void)p;
    double L[9];
    double len2 = fs_dot3(d, d);
    FS_ASSERT(len2 > 0.0);
    velocity_gradient(f, t, L);
    double sum = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            sum += d[i] * L[3 * i + j] * d[j];
    return sum / len2;
}

void fs_growth_strain(const fs_growth_field *f, double t0, double t1, double eps[4], double voigt[3])
{
    FS_ASSERT(f->type != FS_GROWTH_SPHERE);
    double J[9];
    fs_growth_jacobian(f, t0, t1, J);
    double e[4] = {J[0] - 1.0, J[1], J[3], J[4] - 1.0};
    if (eps)
        memcpy(eps, e, sizeof e);
    if (voigt) {
        voigt[0] = e[0];
        voigt[1] = e[3];
        voigt[2] = e[1] + e[2];
    }
}

void fs_shrink_eigenstrain(const fs_shrink *s, double t, double *top, double *bottom)
{
    if (top)
        *top = -fs_pwl_eval(&s->top, t);
    if (bottom)
        *bottom = -fs_pwl_eval(&s->bottom, t);
}

void fs_shrink_scales(const fs_shrink *s, double t, double scale[3])
{
    double top = fs_pwl_eval(&s->top, t), bottom = fs_pwl_eval(&s->bottom, t);
    scale[0] = 1.0 - bottom;
    scale[1] = 1.0 - top;
    scale[2] = 1.0 - 0.5 * (top + bottom);
}

static int check_pwl(const fs_pwl *p, const char *key)
{
    for (int i = 0; i < p->n; i++) {
        if (!(p->v[i] < 1.0)) {
            fs_error(FS_ERR_DATA,
                     "[shrink] %s: expected shrinkage values below 1, got %g at t = %g (the material would vanish)",
                     key, p->v[i], p->t[i]);
            return -1;
        }
    }
    return 0;
}

int fs_shrink_check(const fs_shrink *s)
{
    if (check_pwl(&s->top, "top") < 0 || check_pwl(&s->bottom, "bottom") < 0)
        return -1;
    return 0;
}

double fs_material_thickness(const fs_material *m, double t, double time_end)
{
    if (m->thickness_final < 0.0 || !(time_end > 0.0))
        return m->thickness;
    if (!(t > 0.0))
        return m->thickness;
    if (!(t < time_end))
        return m->thickness_final;
    return m->thickness + (m->thickness_final - m->thickness) * (t / time_end);
}
