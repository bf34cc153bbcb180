/* Tests of the domains: texture-space round trips, embedding and normals, periodic deltas and wraps, areas. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "base/rng.h"
#include "base/vec.h"
#include "geom/domain.h"
#include "check.h"

static fs_domain plane(double w, double h, bool px, bool py)
{
    fs_domain d = fs_domain_default();
    d.width = w;
    d.height = h;
    d.periodic_x = px;
    d.periodic_y = py;
    fs_domain_normalize(&d);
    return d;
}

static fs_domain cylinder(double r, double h, bool py)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_CYLINDER;
    d.radius = r;
    d.height = h;
    d.periodic_y = py;
    fs_domain_normalize(&d);
    return d;
}

static fs_domain sphere(double r)
{
    fs_domain d = fs_domain_default();
    d.type = FS_DOMAIN_SPHERE;
    d.radius = r;
    fs_domain_normalize(&d);
    return d;
}

static double rnd(uint64_t i) { return fs_rand01(11, FS_RNG_TEST, i); }

/* A random point of the domain (sphere: on the sphere, uniform in uv). */
static void random_point(const fs_domain *d, uint64_t i, double *p)
{
    double uv[2] = {rnd(2 * i), rnd(2 * i + 1)};
    fs_domain_from_uv(d, uv, p);
}

static void test_default(void)
{
    fs_domain d = fs_domain_default();
    CHECK(d.type == FS_DOMAIN_PLANE);
    CHECK(d.width == 10.0 && d.height == 10.0 && d.radius == 5.0);
    CHECK(!d.periodic_x && !d.periodic_y);
    CHECK(strcmp(fs_domain_type_name(FS_DOMAIN_PLANE), "plane") == 0);
    CHECK(strcmp(fs_domain_type_name(FS_DOMAIN_CYLINDER), "cylinder") == 0);
    CHECK(strcmp(fs_domain_type_name(FS_DOMAIN_SPHERE), "sphere") == 0);
}

static void test_normalize(void)
{
    fs_domain c = fs_domain_default();
    c.type = FS_DOMAIN_CYLINDER;
    CHECK(!c.periodic_x);
    fs_domain_normalize(&c);
    CHECK(c.periodic_x);
    CHECK(!c.periodic_y);
    fs_domain p = plane(3, 4, false, true);
    CHECK(!p.periodic_x && p.periodic_y);
}

static void test_extents_and_areas(void)
{
    fs_domain p = plane(3, 4, false, false), c = cylinder(2, 7, false), s = sphere(5);
    CHECK_NEAR(fs_domain_extent_x(&p), 3.0, 0);
    CHECK_NEAR(fs_domain_extent_y(&p), 4.0, 0);
    CHECK_NEAR(fs_domain_area(&p), 12.0, 1e-12);
    CHECK_NEAR(fs_domain_extent_x(&c), 4.0 * FS_PI, 1e-12);
    CHECK_NEAR(fs_domain_extent_y(&c), 7.0, 0);
    CHECK_NEAR(fs_domain_area(&c), 28.0 * FS_PI, 1e-12);
    CHECK_NEAR(fs_domain_extent_x(&s), 10.0 * FS_PI, 1e-12);
    CHECK_NEAR(fs_domain_extent_y(&s), 5.0 * FS_PI, 1e-12);
    CHECK_NEAR(fs_domain_area(&s), 100.0 * FS_PI, 1e-12);
    /* The cylinder's area is its unwrapped rectangle's. */
    CHECK_NEAR(fs_domain_area(&c), fs_domain_extent_x(&c) * fs_domain_extent_y(&c), 1e-12);
}

static void test_uv_round_trip(void)
{
    fs_domain doms[3] = {plane(3, 4, true, false), cylinder(2, 7, false), sphere(5)};
    for (int k = 0; k < 3; k++) {
        const fs_domain *d = &doms[k];
        double worst_p = 0, worst_uv = 0;
        int in_range = 1;
        for (uint64_t i = 0; i < 1000; i++) {
            double uv[2] = {rnd(2 * i), 0.001 + 0.998 * rnd(2 * i + 1)}, p[3], uv2[2], p2[3];
            fs_domain_from_uv(d, uv, p);
            fs_domain_to_uv(d, p, uv2);
            fs_domain_from_uv(d, uv2, p2);
            in_range &= uv2[0] >= 0 && uv2[0] < 1 && uv2[1] >= 0 && uv2[1] <= 1;
            double du = fabs(uv2[0] - uv[0]);
            du = fmin(du, 1 - du); /* u = 0 and u = 1 are the same longitude */
            worst_uv = fmax(worst_uv, fmax(du, fabs(uv2[1] - uv[1])));
            double dp[3];
            fs_sub3(dp, p2, p);
            worst_p = fmax(worst_p, fs_norm3(dp));
        }
        CHECK_MSG(in_range, "%s: uv out of [0, 1)", fs_domain_type_name(d->type));
        CHECK_MSG(worst_uv < 1e-12, "%s: uv round trip error %g", fs_domain_type_name(d->type), worst_uv);
        CHECK_MSG(worst_p < 1e-12, "%s: point round trip error %g", fs_domain_type_name(d->type), worst_p);
    }
}

static void test_uv_conventions(void)
{
    fs_domain p = plane(3, 4, false, false), c = cylinder(2, 7, false), s = sphere(5);
    double uv[2];
    fs_domain_to_uv(&p, (double[]){1.5, 1.0, 0}, uv);
    CHECK_NEAR(uv[0], 0.5, 1e-15);
    CHECK_NEAR(uv[1], 0.25, 1e-15);
    /* cylinder: u is the angle over 2 pi, s = R * angle */
    fs_domain_to_uv(&c, (double[]){2.0 * FS_PI / 2.0, 3.5, 0}, uv);
    CHECK_NEAR(uv[0], 0.25, 1e-15);
    CHECK_NEAR(uv[1], 0.5, 1e-15);
    /* sphere: longitude from +x towards +y, wrapped into [0, 1); latitude from the south pole */
    fs_domain_to_uv(&s, (double[]){5, 0, 0}, uv);
    CHECK_NEAR(uv[0], 0.0, 1e-15);
    CHECK_NEAR(uv[1], 0.5, 1e-15);
    fs_domain_to_uv(&s, (double[]){0, 5, 0}, uv);
    CHECK_NEAR(uv[0], 0.25, 1e-15);
    fs_domain_to_uv(&s, (double[]){0, -5, 0}, uv);
    CHECK_NEAR(uv[0], 0.75, 1e-15);
    fs_domain_to_uv(&s, (double[]){-5, -1e-300, 0}, uv);
    CHECK(uv[0] >= 0 && uv[0] < 1);
    fs_domain_to_uv(&s, (double[]){0, 0, 5}, uv);
    CHECK_NEAR(uv[1], 1.0, 1e-15);
    fs_domain_to_uv(&s, (double[]){0, 0, -5}, uv);
    CHECK_NEAR(uv[1], 0.0, 1e-15);
    /* slightly off the sphere by rounding must not give NaN */
    fs_domain_to_uv(&s, (double[]){0, 0, 5 * (1 + 1e-15)}, uv);
    CHECK(uv[1] == 1.0);
}

static void test_embed_and_normal(void)
{
    fs_domain p = plane(3, 4, false, false), c = cylinder(2, 7, false), s = sphere(5);
    double worst_r = 0, worst_perp = 0, worst_unit = 0, worst_radial = 0, worst_z = 0;
    int outwards = 1;
    for (uint64_t i = 0; i < 500; i++) {
        double q[3], w[3], n[3];
        random_point(&c, i, q);
        fs_domain_embed(&c, q, w);
        fs_domain_normal(&c, q, n);
        worst_r = fmax(worst_r, fabs(hypot(w[0], w[1]) - 2.0));
        worst_z = fmax(worst_z, fabs(w[2] - q[1]));
        worst_perp = fmax(worst_perp, fabs(n[2]));                       /* normal perpendicular to the axis */
        worst_unit = fmax(worst_unit, fabs(fs_norm3(n) - 1.0));
        worst_radial = fmax(worst_radial, fabs(n[0] * w[1] - n[1] * w[0])); /* parallel to the radius */
        outwards &= n[0] * w[0] + n[1] * w[1] > 0;
    }
    CHECK_NEAR(worst_r, 0, 1e-12);
    CHECK_NEAR(worst_z, 0, 0);
    CHECK_NEAR(worst_perp, 0, 0);
    CHECK_NEAR(worst_unit, 0, 1e-15);
    CHECK_NEAR(worst_radial, 0, 1e-12);
    CHECK(outwards);

    /* s = R pi / 2 is a quarter turn: the point is on +y. */
    double w[3];
    fs_domain_embed(&c, (double[]){FS_PI, 1.0, 0}, w);
    CHECK_NEAR(w[0], 0.0, 1e-15);
    CHECK_NEAR(w[1], 2.0, 1e-15);
    CHECK_NEAR(w[2], 1.0, 0);

    double worst_sr = 0, worst_sn = 0;
    for (uint64_t i = 0; i < 500; i++) {
        double q[3], n[3];
        random_point(&s, i, q);
        fs_domain_embed(&s, q, w);
        fs_domain_normal(&s, q, n);
        worst_sr = fmax(worst_sr, fabs(fs_norm3(w) - 5.0));
        for (int a = 0; a < 3; a++)
            worst_sn = fmax(worst_sn, fabs(n[a] - w[a] / 5.0));
    }
    CHECK_NEAR(worst_sr, 0, 1e-12);
    CHECK_NEAR(worst_sn, 0, 1e-15);

    double n[3];
    fs_domain_embed(&p, (double[]){1, 2, 0}, w);
    fs_domain_normal(&p, (double[]){1, 2, 0}, n);
    CHECK(w[0] == 1 && w[1] == 2 && w[2] == 0);
    CHECK(n[0] == 0 && n[1] == 0 && n[2] == 1);
}

static void test_delta(void)
{
    fs_domain pxy = plane(10, 6, true, true), px = plane(10, 6, true, false), p = plane(10, 6, false, false);
    double a[3] = {0.5, 5.5, 0}, b[3] = {9.5, 0.5, 0}, d[3];
    fs_domain_delta(&pxy, a, b, d);
    CHECK_NEAR(d[0], -1.0, 1e-12);
    CHECK_NEAR(d[1], 1.0, 1e-12);
    fs_domain_delta(&px, a, b, d);
    CHECK_NEAR(d[0], -1.0, 1e-12);
    CHECK_NEAR(d[1], -5.0, 1e-12);
    fs_domain_delta(&p, a, b, d);
    CHECK_NEAR(d[0], 9.0, 1e-12);
    CHECK_NEAR(d[1], -5.0, 1e-12);

    /* On random pairs the periodic delta is the shortest of all images. */
    fs_domain c = cylinder(1, 20, false);
    double period = fs_domain_extent_x(&c);
    int shortest = 1;
    for (uint64_t i = 0; i < 1000; i++) {
        double u[3], v[3], dd[3];
        random_point(&pxy, 2 * i, u);
        random_point(&pxy, 2 * i + 1, v);
        fs_domain_delta(&pxy, u, v, dd);
        for (int sx = -1; sx <= 1; sx++)
            for (int sy = -1; sy <= 1; sy++) {
                double ex = v[0] - u[0] + 10 * sx, ey = v[1] - u[1] + 6 * sy;
                shortest &= hypot(dd[0], dd[1]) <= hypot(ex, ey) + 1e-12;
            }
        shortest &= fabs(dd[0]) <= 5 + 1e-12 && fabs(dd[1]) <= 3 + 1e-12;
        random_point(&c, 2 * i, u);
        random_point(&c, 2 * i + 1, v);
        fs_domain_delta(&c, u, v, dd);
        shortest &= fabs(dd[0]) <= period / 2 + 1e-12;
        shortest &= fabs(dd[1] - (v[1] - u[1])) == 0; /* the axis does not wrap */
        /* the displacement is a whole number of periods away from the plain one */
        double k = (dd[0] - (v[0] - u[0])) / period;
        shortest &= fabs(k - round(k)) < 1e-9;
    }
    CHECK(shortest);

    fs_domain s = sphere(5);
    double sa[3] = {5, 0, 0}, sb[3] = {-5, 0, 0};
    fs_domain_delta(&s, sa, sb, d);
    CHECK(d[0] == -10 && d[1] == 0 && d[2] == 0);
}

static void test_wrap(void)
{
    fs_domain pxy = plane(10, 6, true, true), px = plane(10, 6, true, false);
    double xs[] = {-37.25, -1e-20, -10.0, 0.0, 9.999999999999998, 10.0, 1e6 + 0.5, 23.0};
    int in_range = 1;
    for (size_t i = 0; i < sizeof xs / sizeof *xs; i++) {
        double q[3] = {xs[i], xs[i] * 0.7 - 1.0, 0};
        fs_domain_wrap(&pxy, q);
        in_range &= q[0] >= 0 && q[0] < 10 && q[1] >= 0 && q[1] < 6;
    }
    CHECK(in_range);
    double q[3] = {-37.25, 14.0, 0};
    fs_domain_wrap(&pxy, q);
    CHECK_NEAR(q[0], 2.75, 1e-12);
    CHECK_NEAR(q[1], 2.0, 1e-12);
    double r[3] = {12.5, -3.0, 0};
    fs_domain_wrap(&px, r);
    CHECK_NEAR(r[0], 2.5, 1e-12);
    CHECK(r[1] == -3.0); /* a non-periodic direction is left alone */

    fs_domain c = cylinder(1, 5, false);
    double t[3] = {-FS_PI / 2, 2.0, 0};
    fs_domain_wrap(&c, t);
    CHECK_NEAR(t[0], 1.5 * FS_PI, 1e-12);
    CHECK(t[1] == 2.0);

    fs_domain s = sphere(5);
    double u[3] = {3, 4, 12};
    fs_domain_wrap(&s, u);
    CHECK_NEAR(fs_norm3(u), 5.0, 1e-12);
    CHECK_NEAR(u[2], 5.0 * 12.0 / 13.0, 1e-12);
}

static void test_wraps_uv(void)
{
    fs_domain p = plane(1, 1, false, false), pxy = plane(1, 1, true, true), py = plane(1, 1, false, true);
    fs_domain c = cylinder(1, 1, false), cy = cylinder(1, 1, true), s = sphere(1);
    CHECK(!fs_domain_wraps_u(&p) && !fs_domain_wraps_v(&p));
    CHECK(fs_domain_wraps_u(&pxy) && fs_domain_wraps_v(&pxy));
    CHECK(!fs_domain_wraps_u(&py) && fs_domain_wraps_v(&py));
    CHECK(fs_domain_wraps_u(&c) && !fs_domain_wraps_v(&c));
    CHECK(fs_domain_wraps_u(&cy) && fs_domain_wraps_v(&cy));
    CHECK(fs_domain_wraps_u(&s) && !fs_domain_wraps_v(&s));
}

int main(void)
{
    RUN(test_default);
    RUN(test_normalize);
    RUN(test_extents_and_areas);
    RUN(test_uv_round_trip);
    RUN(test_uv_conventions);
    RUN(test_embed_and_normal);
    RUN(test_delta);
    RUN(test_wrap);
    RUN(test_wraps_uv);
    return check_finish();
}
