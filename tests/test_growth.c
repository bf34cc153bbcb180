/* Tests of the background growth fields, their flow maps and eigenstrain, shrinkage and thickness over time. */
#include <math.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "check.h"
#include "field/growth.h"

static fs_domain plane_domain(void)
{
    fs_domain d = fs_domain_default();
    d.width = 8.0;
    d.height = 6.0;
    return d;
}

static fs_domain round_domain(fs_domain_type type, double radius)
{
    fs_domain d = fs_domain_default();
    d.type = type;
    d.radius = radius;
    d.height = 10.0;
    fs_domain_normalize(&d);
    return d;
}

static fs_growth_field planar_field(double r1, double r2, double angle, double fx, double fy)
{
    fs_growth g = fs_growth_default();
    g.type = FS_GROWTH_PLANAR;
    g.r1 = r1;
    g.r2 = r2;
    g.angle = angle;
    fs_growth_fixed_point fp = {fx, fy};
    fs_domain d = plane_domain();
    fs_growth_field f;
    FS_ASSERT(fs_growth_field_init(&f, &g, &fp, &d, 10.0) == 0);
    return f;
}

static fs_growth_field radial_field(fs_growth_type type, double radius, double rate, double axis_ratio)
{
    fs_growth g = fs_growth_default();
    g.type = type;
    g.rate = rate;
    g.axis_ratio = axis_ratio;
    fs_domain d = round_domain(type == FS_GROWTH_CYLINDER ? FS_DOMAIN_CYLINDER : FS_DOMAIN_SPHERE, radius);
    fs_growth_field f;
    FS_ASSERT(fs_growth_field_init(&f, &g, NULL, &d, 10.0) == 0);
    return f;
}

/* A point on the sphere of the given radius, from hashed normal variates. */
static void sphere_point(double radius, uint64_t i, double p[3])
{
    for (int k = 0; k < 3; k++)
        p[k] = fs_rand_normal(7, FS_RNG_TEST, 3 * i + (uint64_t)k);
    double n = fs_norm3(p);
    for (int k = 0; k < 3; k++)
        p[k] *= radius / n;
}

static double dist3(const double *a, const double *b)
{
    double d[3];
    fs_sub3(d, a, b);
    return fs_norm3(d);
}

/* A circle under anisotropic planar growth (r1 != r2, axis at 30 degrees) becomes the ellipse with
 * semi-axes rho e^{r1 t} along the 30-degree axis and rho e^{r2 t} across it. */
static void test_planar_ellipse(void)
{
    const double r1 = 0.3, r2 = -0.1, t = 2.0, rho = 1.5, alpha = 30.0 * FS_PI / 180.0;
    fs_growth_field f = planar_field(r1, r2, 30.0, 2.0, 3.0);
    const double c[3] = {5.0, 1.0, 0.0};
    double c1[3];
    fs_growth_flow(&f, c, 0.0, t, c1);
    const double u[2] = {cos(alpha), sin(alpha)}, w[2] = {-sin(alpha), cos(alpha)};
    const double a = rho * exp(r1 * t), b = rho * exp(r2 * t);

    enum { N = 360 };
    double worst = 0.0, cxx = 0.0, cyy = 0.0, cxy = 0.0;
    for (int i = 0; i < N; i++) {
        double th = 2.0 * FS_PI * i / N;
        double p[3] = {c[0] + rho * cos(th), c[1] + rho * sin(th), 0.0}, q[3];
        fs_growth_flow(&f, p, 0.0, t, q);
        double dx = q[0] - c1[0], dy = q[1] - c1[1];
        double pu = dx * u[0] + dy * u[1], pw = dx * w[0] + dy * w[1];
        double e = fabs((pu / a) * (pu / a) + (pw / b) * (pw / b) - 1.0);
        worst = e > worst ? e : worst;
        CHECK(q[2] == 0.0);
        cxx += dx * dx;
        cyy += dy * dy;
        cxy += dx * dy;
    }
    CHECK_MSG(worst < 1e-12, "ellipse equation residual %g", worst);

    /* The ends of the circle's diameters along u and w land on the ellipse's vertices. */
    double pu[3] = {c[0] + rho * u[0], c[1] + rho * u[1], 0.0}, pw[3] = {c[0] + rho * w[0], c[1] + rho * w[1], 0.0};
    double qu[3], qw[3];
    fs_growth_flow(&f, pu, 0.0, t, qu);
    fs_growth_flow(&f, pw, 0.0, t, qw);
    CHECK_NEAR(qu[0], c1[0] + a * u[0], 1e-12);
    CHECK_NEAR(qu[1], c1[1] + a * u[1], 1e-12);
    CHECK_NEAR(qw[0], c1[0] + b * w[0], 1e-12);
    CHECK_NEAR(qw[1], c1[1] + b * w[1], 1e-12);

    /* A fit: the principal axis of the second moments of the grown points is at 30 degrees, and the
     * moments along and across it are a^2/2 and b^2/2 per point. */
    double fit = 0.5 * atan2(2.0 * cxy, cxx - cyy);
    CHECK_NEAR(fit, alpha, 1e-12);
    double mu = (cxx * u[0] * u[0] + 2.0 * cxy * u[0] * u[1] + cyy * u[1] * u[1]) / N;
    double mw = (cxx * w[0] * w[0] + 2.0 * cxy * w[0] * w[1] + cyy * w[1] * w[1]) / N;
    CHECK_NEAR(mu, 0.5 * a * a, 1e-12);
    CHECK_NEAR(mw, 0.5 * b * b, 1e-12);

    /* The thesis' Fig. 3.6 "horizontal growth": angle 0 (thesis alpha = pi/2), r1 = 1, r2 = 0 stretches
     * x by e^t and leaves y alone. */
    fs_growth_field h = planar_field(1.0, 0.0, 0.0, 0.0, 0.0);
    const double p0[3] = {0.0, 0.0, 0.0}, ex[3] = {1.0, 0.0, 0.0}, ey[3] = {0.0, 1.0, 0.0};
    CHECK_NEAR(fs_growth_stretch(&h, p0, ex, 0.0, 1.5), exp(1.5), 1e-12);
    CHECK_NEAR(fs_growth_stretch(&h, p0, ey, 0.0, 1.5), 1.0, 1e-15);
}

/* Isogonic planar growth (r1 = r2) is a pure scaling about the fixed point, which does not move,
 * whatever the angle. */
static void test_planar_isogonic(void)
{
    const double r = 0.2, t = 3.0, k = exp(r * t);
    fs_growth_field f = planar_field(r, r, 37.0, 3.0, 4.0);
    const double fixed[3] = {3.0, 4.0, 0.0};
    double q[3];
    fs_growth_flow(&f, fixed, 0.0, t, q);
    CHECK(q[0] == 3.0 && q[1] == 4.0 && q[2] == 0.0);
    double v[3];
    fs_growth_velocity(&f, fixed, t, v);
    CHECK(v[0] == 0.0 && v[1] == 0.0);

    for (uint64_t i = 0; i < 50; i++) {
        double p[3] = {fs_rand_range(1, FS_RNG_TEST, 2 * i, 0.0, 8.0),
                       fs_rand_range(1, FS_RNG_TEST, 2 * i + 1, 0.0, 6.0), 0.0};
        fs_growth_flow(&f, p, 0.0, t, q);
        CHECK_NEAR(q[0] - 3.0, k * (p[0] - 3.0), 1e-12);
        CHECK_NEAR(q[1] - 4.0, k * (p[1] - 4.0), 1e-12);
    }
    /* Every direction stretches alike, and the strain is isotropic with no shear. */
    double eps[4];
    fs_growth_strain(&f, 0.0, t, eps, NULL);
    CHECK_NEAR(eps[0], k - 1.0, 1e-14);
    CHECK_NEAR(eps[3], k - 1.0, 1e-14);
    CHECK(eps[1] == 0.0 && eps[2] == 0.0);

    /* Without a fixed point the centre of the domain rectangle stays put. */
    fs_growth g = fs_growth_default();
    g.type = FS_GROWTH_PLANAR;
    g.r1 = 0.5;
    g.r2 = 0.1;
    fs_domain d = plane_domain();
    fs_growth_field c;
    CHECK(fs_growth_field_init(&c, &g, NULL, &d, 1.0) == 0);
    const double centre[3] = {4.0, 3.0, 0.0};
    fs_growth_flow(&c, centre, 0.0, 1.0, q);
    CHECK(q[0] == 4.0 && q[1] == 3.0);
}

/* flow(t0 -> t1) then flow(t1 -> t2) is flow(t0 -> t2), and flowing back returns to the start. */
static void test_flow_composition(void)
{
    fs_growth_field fields[4] = {
        planar_field(0.3, -0.1, 30.0, 2.0, 3.0),
        radial_field(FS_GROWTH_CYLINDER, 2.0, 0.5, 1.0),
        radial_field(FS_GROWTH_SPHERE, 3.0, 0.4, 4.0),
        planar_field(0.0, 0.0, 0.0, 0.0, 0.0),
    };
    const double t0 = 0.5, t1 = 2.0, t2 = 4.5;
    for (int k = 0; k < 4; k++) {
        for (uint64_t i = 0; i < 20; i++) {
            double p[3];
            if (fields[k].type == FS_GROWTH_SPHERE) {
                sphere_point(fs_growth_radius(&fields[k], t0), i, p);
            } else {
                p[0] = fs_rand_range(2, FS_RNG_TEST, 2 * i, 0.0, 8.0);
                p[1] = fs_rand_range(2, FS_RNG_TEST, 2 * i + 1, 0.0, 6.0);
                p[2] = 0.0;
            }
            double a[3], b[3], direct[3], back[3];
            fs_growth_flow(&fields[k], p, t0, t1, a);
            fs_growth_flow(&fields[k], a, t1, t2, b);
            fs_growth_flow(&fields[k], p, t0, t2, direct);
            fs_growth_flow(&fields[k], direct, t2, t0, back);
            for (int j = 0; j < 3; j++) {
                CHECK_NEAR(b[j], direct[j], 1e-12 * (1.0 + fabs(direct[j])));
                CHECK_NEAR(back[j], p[j], 1e-12 * (1.0 + fabs(p[j])));
            }
        }
    }
}

/* The cylinder stretches only around: a segment along the axis keeps its length, one around the
 * trunk stretches by R(t)/R0, points keep their angle, and the strain has only the around component. */
static void test_cylinder(void)
{
    const double r0 = 2.0, rate = 0.5, t = 3.0, k = (r0 + rate * t) / r0;
    fs_growth_field f = radial_field(FS_GROWTH_CYLINDER, r0, rate, 1.0);
    CHECK_NEAR(fs_growth_radius(&f, t), 3.5, 1e-15);

    const double p[3] = {5.0, 4.0, 0.0}, along[3] = {0.0, 1.0, 0.0}, around[3] = {1.0, 0.0, 0.0};
    const double diag[3] = {1.0, 1.0, 0.0};
    CHECK(fs_growth_stretch(&f, p, along, 0.0, t) == 1.0);
    CHECK_NEAR(fs_growth_stretch(&f, p, around, 0.0, t), k, 1e-15);
    CHECK_NEAR(fs_growth_stretch(&f, p, diag, 0.0, t), sqrt((k * k + 1.0) / 2.0), 1e-15);

    /* A finite segment in the unwrapped coordinates, by the flow map. */
    const double q[3] = {5.0, 7.0, 0.0}, s[3] = {6.2, 4.0, 0.0};
    double p1[3], q1[3], s1[3];
    fs_growth_flow(&f, p, 0.0, t, p1);
    fs_growth_flow(&f, q, 0.0, t, q1);
    fs_growth_flow(&f, s, 0.0, t, s1);
    CHECK_NEAR(dist3(p1, q1), 3.0, 1e-14);
    CHECK_NEAR(dist3(p1, s1), 1.2 * k, 1e-14);
    CHECK(p1[1] == p[1]);
    /* The angle s / R is unchanged: the point moves straight out from the axis (thesis Eq. 3.5). */
    CHECK_NEAR(p1[0] / fs_growth_radius(&f, t), p[0] / r0, 1e-15);

    double eps[4], voigt[3];
    fs_growth_strain(&f, 0.0, t, eps, voigt);
    CHECK_NEAR(eps[0], k - 1.0, 1e-15);
    CHECK(eps[1] == 0.0 && eps[2] == 0.0 && eps[3] == 0.0);
    CHECK_NEAR(voigt[0], k - 1.0, 1e-15);
    CHECK(voigt[1] == 0.0 && voigt[2] == 0.0);

    /* The relative elemental rate of growth is rate / R(t) around and 0 along the axis (thesis §3.3.1:
     * T_G e1 != 0, T_G e2 = 0). */
    CHECK_NEAR(fs_growth_rate_along(&f, p, around, t), rate / 3.5, 1e-15);
    CHECK(fs_growth_rate_along(&f, p, along, t) == 0.0);
}

/* Isogonic sphere: all distances scale by R(t)/R0 and the points stay on the grown sphere. */
static void test_sphere_isogonic(void)
{
    const double r0 = 3.0, rate = 0.4, t = 2.5, k = (r0 + rate * t) / r0;
    fs_growth_field f = radial_field(FS_GROWTH_SPHERE, r0, rate, 1.0);
    double prev[3] = {0.0, 0.0, r0}, prev1[3];
    fs_growth_flow(&f, prev, 0.0, t, prev1);
    for (uint64_t i = 0; i < 40; i++) {
        double p[3], p1[3];
        sphere_point(r0, i, p);
        fs_growth_flow(&f, p, 0.0, t, p1);
        CHECK_NEAR(fs_norm3(p1), r0 + rate * t, 1e-13);
        CHECK_NEAR(dist3(p1, prev1), k * dist3(p, prev), 1e-13);
        /* A tangent direction at p stretches by k whatever its orientation. */
        double axis[3] = {0.3, -0.7, 0.2}, tangent[3];
        fs_cross3(tangent, p, axis);
        CHECK_NEAR(fs_growth_stretch(&f, p, tangent, 0.0, t), k, 1e-14);
        memcpy(prev, p, sizeof prev);
        memcpy(prev1, p1, sizeof prev1);
    }
}

/* Elongated sphere, axis_ratio 4: the z semi-axis grows 4 times as fast (cm per time unit) as the
 * equatorial radius, and grown points lie on that spheroid. */
static void test_sphere_elongated(void)
{
    const double r0 = 3.0, rate = 0.4, t = 2.5;
    fs_growth_field f = radial_field(FS_GROWTH_SPHERE, r0, rate, 4.0);
    const double a = r0 + rate * t, c = r0 + 4.0 * rate * t;
    CHECK_NEAR(fs_growth_radius(&f, t), a, 1e-15);
    CHECK_NEAR(fs_growth_radius_z(&f, t), c, 1e-15);

    const double pole[3] = {0.0, 0.0, r0}, equator[3] = {0.0, r0, 0.0};
    double pole1[3], equator1[3];
    fs_growth_flow(&f, pole, 0.0, t, pole1);
    fs_growth_flow(&f, equator, 0.0, t, equator1);
    CHECK_NEAR(pole1[2], c, 1e-14);
    CHECK_NEAR(equator1[1], a, 1e-14);
    CHECK_NEAR((pole1[2] - r0) / (equator1[1] - r0), 4.0, 1e-12);
    double vp[3], ve[3];
    fs_growth_velocity(&f, pole1, t, vp);
    fs_growth_velocity(&f, equator1, t, ve);
    CHECK_NEAR(vp[2], 4.0 * ve[1], 1e-14);
    CHECK_NEAR(ve[1], rate, 1e-15);

    for (uint64_t i = 0; i < 40; i++) {
        double p[3], p1[3];
        sphere_point(r0, i, p);
        fs_growth_flow(&f, p, 0.0, t, p1);
        double e = (p1[0] * p1[0] + p1[1] * p1[1]) / (a * a) + p1[2] * p1[2] / (c * c);
        CHECK_NEAR(e, 1.0, 1e-12);
    }
}

static void set_pwl(fs_pwl *f, const double knots[][2], int n)
{
    f->n = n;
    for (int i = 0; i < n; i++) {
        f->t[i] = knots[i][0];
        f->v[i] = knots[i][1];
    }
}

/* Shrinkage eigenstrain is minus the piecewise-linear shrinkage, at its knots and between them; the
 * reference-shape scales follow Fig. 3.10; thickness changes linearly over the run. */
static void test_shrink_and_thickness(void)
{
    fs_shrink s = fs_shrink_default();
    const double top_knots[3][2] = {{0.0, 0.0}, {1.0, 0.2}, {3.0, 0.5}};
    const double bottom_knots[2][2] = {{2.0, 0.0}, {4.0, -0.5}};
    set_pwl(&s.top, top_knots, 3);
    set_pwl(&s.bottom, bottom_knots, 2);

    double top, bottom;
    fs_shrink_eigenstrain(&s, 1.0, &top, &bottom);
    CHECK_NEAR(top, -0.2, 1e-15);
    CHECK(bottom == 0.0);
    fs_shrink_eigenstrain(&s, 2.0, &top, &bottom);
    CHECK_NEAR(top, -0.35, 1e-15);
    CHECK(bottom == 0.0);
    fs_shrink_eigenstrain(&s, 3.5, &top, &bottom);
    CHECK_NEAR(top, -0.5, 1e-15);
    CHECK_NEAR(bottom, 0.375, 1e-15);
    fs_shrink_eigenstrain(&s, -1.0, &top, &bottom);
    CHECK(top == 0.0 && bottom == 0.0);
    fs_shrink_eigenstrain(&s, 9.0, &top, NULL);
    CHECK_NEAR(top, -0.5, 1e-15);

    double scale[3];
    fs_shrink_scales(&s, 3.5, scale);
    CHECK_NEAR(scale[0], 1.375, 1e-15);
    CHECK_NEAR(scale[1], 0.5, 1e-15);
    CHECK_NEAR(scale[2], 1.0 - 0.5 * (0.5 - 0.375), 1e-15);

    CHECK(fs_shrink_check(&s) == 0);
    fs_shrink none = fs_shrink_default();
    CHECK(fs_shrink_check(&none) == 0);
    fs_shrink_eigenstrain(&none, 5.0, &top, &bottom);
    CHECK(top == 0.0 && bottom == 0.0);
    s.bottom.v[0] = 1.0;
    fs_error_clear();
    CHECK(fs_shrink_check(&s) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(strstr(fs_error_message(), "bottom") != NULL);

    fs_material m = fs_material_default();
    m.thickness = 0.5;
    m.thickness_final = 2.0;
    CHECK(fs_material_thickness(&m, 0.0, 10.0) == 0.5);
    CHECK_NEAR(fs_material_thickness(&m, 5.0, 10.0), 1.25, 1e-15);
    CHECK_NEAR(fs_material_thickness(&m, 2.5, 10.0), 0.875, 1e-15);
    CHECK(fs_material_thickness(&m, 10.0, 10.0) == 2.0);
    CHECK(fs_material_thickness(&m, 20.0, 10.0) == 2.0);
    CHECK(fs_material_thickness(&m, -1.0, 10.0) == 0.5);
    m.thickness_final = -1.0;
    CHECK(fs_material_thickness(&m, 5.0, 10.0) == 0.5);
}

/* Central difference in p of the flow map, column j of the in-plane deformation gradient. */
static void fd_column(const fs_growth_field *f, const double p[3], int j, double t0, double t1, double h,
                      double col[2])
{
    double a[3] = {p[0], p[1], p[2]}, b[3] = {p[0], p[1], p[2]}, qa[3], qb[3];
    a[j] -= h;
    b[j] += h;
    fs_growth_flow(f, a, t0, t1, qa);
    fs_growth_flow(f, b, t0, t1, qb);
    col[0] = (qb[0] - qa[0]) / (2.0 * h);
    col[1] = (qb[1] - qa[1]) / (2.0 * h);
}

/* The eigenstrain is the strain of the flow map: the Biot strain sym(F) - I with F measured by finite
 * differences of the flow on small segments, and exactly stretch - 1 along a principal direction. */
static void test_eigenstrain_matches_flow(void)
{
    const double t0 = 0.5, t1 = 2.0, h = 1e-4;
    fs_growth_field fields[2] = {planar_field(0.3, -0.1, 30.0, 2.0, 3.0),
                                 radial_field(FS_GROWTH_CYLINDER, 2.0, 0.5, 1.0)};
    const double p[3] = {6.5, 1.5, 0.0};
    for (int k = 0; k < 2; k++) {
        double cx[2], cy[2], eps[4], voigt[3];
        fd_column(&fields[k], p, 0, t0, t1, h, cx);
        fd_column(&fields[k], p, 1, t0, t1, h, cy);
        fs_growth_strain(&fields[k], t0, t1, eps, voigt);
        double fd_xx = cx[0] - 1.0, fd_yy = cy[1] - 1.0, fd_xy = 0.5 * (cx[1] + cy[0]);
        CHECK_NEAR(eps[0], fd_xx, 1e-9);
        CHECK_NEAR(eps[3], fd_yy, 1e-9);
        CHECK_NEAR(eps[1], fd_xy, 1e-9);
        CHECK_NEAR(eps[2], fd_xy, 1e-9);
        CHECK_NEAR(voigt[0], fd_xx, 1e-9);
        CHECK_NEAR(voigt[1], fd_yy, 1e-9);
        CHECK_NEAR(voigt[2], 2.0 * fd_xy, 1e-9);
        /* F is symmetric: no rotation hides in the Biot strain. */
        CHECK_NEAR(cx[1], cy[0], 1e-9);
    }
    /* Along the r1 axis a small segment stretches by exactly 1 + u . eps u = e^{r1 (t1 - t0)}. */
    const double alpha = 30.0 * FS_PI / 180.0, u[3] = {cos(alpha), sin(alpha), 0.0};
    double eps[4], a[3], b[3] = {p[0] + h * u[0], p[1] + h * u[1], 0.0};
    fs_growth_strain(&fields[0], t0, t1, eps, NULL);
    fs_growth_flow(&fields[0], p, t0, t1, a);
    fs_growth_flow(&fields[0], b, t0, t1, b);
    double euu = u[0] * u[0] * eps[0] + u[0] * u[1] * (eps[1] + eps[2]) + u[1] * u[1] * eps[3];
    CHECK_NEAR(dist3(a, b) / h - 1.0, euu, 1e-9);
    CHECK_NEAR(euu, exp(0.3 * (t1 - t0)) - 1.0, 1e-14);
    /* No growth, no strain. */
    fs_growth_field none = planar_field(0.0, 0.0, 0.0, 0.0, 0.0);
    fs_growth_strain(&none, 0.0, 5.0, eps, NULL);
    CHECK(eps[0] == 0.0 && eps[1] == 0.0 && eps[2] == 0.0 && eps[3] == 0.0);
}

/* The velocity field is the time derivative of the flow map, and the rate of growth along a direction
 * is the time derivative of the log of the stretch. */
static void test_velocity_is_flow_derivative(void)
{
    fs_growth_field fields[3] = {planar_field(0.3, -0.1, 30.0, 2.0, 3.0),
                                 radial_field(FS_GROWTH_CYLINDER, 2.0, 0.5, 1.0),
                                 radial_field(FS_GROWTH_SPHERE, 3.0, 0.4, 4.0)};
    const double t = 1.7, h = 1e-5;
    for (int k = 0; k < 3; k++) {
        double p[3] = {6.5, 1.5, 0.0};
        if (fields[k].type == FS_GROWTH_SPHERE)
            sphere_point(3.0, 5, p);
        double p_at_t[3], ahead[3], behind[3], v[3];
        fs_growth_flow(&fields[k], p, 0.0, t, p_at_t);
        fs_growth_flow(&fields[k], p, 0.0, t + h, ahead);
        fs_growth_flow(&fields[k], p, 0.0, t - h, behind);
        fs_growth_velocity(&fields[k], p_at_t, t, v);
        for (int j = 0; j < 3; j++)
            CHECK_NEAR(v[j], (ahead[j] - behind[j]) / (2.0 * h), 1e-8);

        const double d0[3] = {0.6, -0.8, fields[k].type == FS_GROWTH_SPHERE ? 0.5 : 0.0};
        double J[9], d[3];
        fs_growth_jacobian(&fields[k], 0.0, t, J);
        for (int i = 0; i < 3; i++)
            d[i] = J[3 * i] * d0[0] + J[3 * i + 1] * d0[1] + J[3 * i + 2] * d0[2];
        double rate = fs_growth_rate_along(&fields[k], p_at_t, d, t);
        double fd = (log(fs_growth_stretch(&fields[k], p, d0, 0.0, t + h)) -
                     log(fs_growth_stretch(&fields[k], p, d0, 0.0, t - h))) / (2.0 * h);
        CHECK_NEAR(rate, fd, 1e-8);
    }
}

/* Growth that does not suit the domain, or a radius that would shrink to nothing, is bad data. */
static void test_init_errors(void)
{
    fs_growth_field f;
    fs_growth g = fs_growth_default();
    fs_domain plane = plane_domain(), cyl = round_domain(FS_DOMAIN_CYLINDER, 2.0),
              sph = round_domain(FS_DOMAIN_SPHERE, 2.0);

    g.type = FS_GROWTH_CYLINDER;
    fs_error_clear();
    CHECK(fs_growth_field_init(&f, &g, NULL, &plane, 1.0) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(fs_growth_field_init(&f, &g, NULL, &cyl, 1.0) == 0);
    g.rate = -1.0;
    fs_error_clear();
    CHECK(fs_growth_field_init(&f, &g, NULL, &cyl, 2.0) == -1);
    CHECK(strstr(fs_error_message(), "[growth] rate") != NULL);
    CHECK(fs_growth_field_init(&f, &g, NULL, &cyl, 1.5) == 0);

    g.type = FS_GROWTH_SPHERE;
    g.rate = -0.5;
    g.axis_ratio = 4.0;
    fs_error_clear();
    CHECK(fs_growth_field_init(&f, &g, NULL, &sph, 1.0) == -1);
    CHECK(strstr(fs_error_message(), "axis_ratio") != NULL);
    g.axis_ratio = 1.0;
    CHECK(fs_growth_field_init(&f, &g, NULL, &sph, 1.0) == 0);

    g.type = FS_GROWTH_PLANAR;
    fs_error_clear();
    CHECK(fs_growth_field_init(&f, &g, NULL, &sph, 1.0) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(fs_growth_field_init(&f, &g, NULL, &cyl, 1.0) == 0);
    CHECK(fs_growth_field_init(&f, &g, NULL, &plane, -1.0) == -1);

    /* No growth: everything stays where it is. */
    g.type = FS_GROWTH_NONE;
    CHECK(fs_growth_field_init(&f, &g, NULL, &sph, 1.0) == 0);
    const double p[3] = {1.0, 1.0, 1.0};
    double q[3];
    fs_growth_flow(&f, p, 0.0, 1.0, q);
    CHECK(q[0] == 1.0 && q[1] == 1.0 && q[2] == 1.0);
    fs_error_clear();
}

int main(void)
{
    RUN(test_planar_ellipse);
    RUN(test_planar_isogonic);
    RUN(test_flow_composition);
    RUN(test_cylinder);
    RUN(test_sphere_isogonic);
    RUN(test_sphere_elongated);
    RUN(test_shrink_and_thickness);
    RUN(test_eigenstrain_matches_flow);
    RUN(test_velocity_is_flow_derivative);
    RUN(test_init_errors);
    return check_finish();
}
