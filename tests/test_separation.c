/* Tests of the separation tensor kernel (fracture/separation): the tensile/compressive split and the tensor of balanced and unbalanced forces. */
#include <math.h>
#include <string.h>

#include "base/rng.h"
#include "check.h"
#include "fracture/eigen.h"
#include "fracture/separation.h"

static double max_abs6(const double a[6])
{
    double m = 0.0;
    for (int k = 0; k < 6; k++)
        m = fmax(m, fabs(a[k]));
    return m;
}

static void test_split(void)
{
    for (int k = 0; k < 200; k++) {
        double s[6];
        for (int c = 0; c < 6; c++)
            s[c] = fs_rand_normal(4, FS_RNG_TEST, 6 * (uint64_t)k + c);
        double plus[6], minus[6], vp[3], vm[3];
        CHECK(fs_separation_split(s, plus, minus) == 0);
        double diff[6];
        for (int c = 0; c < 6; c++)
            diff[c] = plus[c] + minus[c] - s[c];
        CHECK(max_abs6(diff) < 1e-12 * max_abs6(s));
        CHECK(fs_eigen_principal_stress(plus, vp, NULL) == 0 && fs_eigen_principal_stress(minus, vm, NULL) == 0);
        CHECK(vp[2] > -1e-12 && vm[0] < 1e-12); /* plus has no compression, minus no tension */
        /* the positive eigenvalues of s are those of plus */
        double vs[3];
        fs_eigen_principal_stress(s, vs, NULL);
        CHECK_NEAR(vp[0], fmax(vs[0], 0.0), 1e-12);
        CHECK_NEAR(vm[2], fmin(vs[2], 0.0), 1e-12);
    }
    /* all tensile, all compressive: exact, no decomposition */
    double t[6] = {2, 1, 3, 0.1, 0.2, 0.1}, plus[6], minus[6];
    CHECK(fs_separation_split(t, plus, minus) == 0);
    CHECK(!memcmp(plus, t, sizeof t) && max_abs6(minus) == 0.0);
    double c[6] = {-2, -1, -3, 0.1, 0.2, 0.1};
    CHECK(fs_separation_split(c, plus, minus) == 0);
    CHECK(!memcmp(minus, c, sizeof c) && max_abs6(plus) == 0.0);
    double bad[6] = {NAN, 0, 0, 0, 0, 0};
    CHECK(fs_separation_split(bad, plus, minus) == -1);
}

static void test_m(void)
{
    double a[3] = {3.0, -4.0, 0.0}, m[6], v[3], dirs[9];
    fs_separation_m(a, m);
    CHECK(fs_eigen_principal_stress(m, v, dirs) == 0);
    CHECK_NEAR(v[0], 5.0, 1e-12);
    CHECK_NEAR(v[1], 0.0, 1e-12);
    CHECK_NEAR(v[2], 0.0, 1e-12);
    CHECK_NEAR(fabs(dirs[0] * 0.6 - dirs[1] * 0.8), 1.0, 1e-12);
    double zero[3] = {0, 0, 0};
    fs_separation_m(zero, m);
    CHECK(max_abs6(m) == 0.0);
}

static void test_tensor(void)
{
    /* balanced tension from both sides along x: separates the node across the plane x = 0 */
    fs_separation s;
    fs_separation_init(&s);
    double f1[3] = {2.0, 0, 0}, f2[3] = {-2.0, 0, 0}, z[3] = {0, 0, 0}, zeta[6], value, n[3];
    fs_separation_add(&s, f1, z);
    fs_separation_add(&s, f2, z);
    fs_separation_tensor(&s, zeta);
    CHECK(fs_separation_largest(zeta, &value, n) == 0);
    CHECK_NEAR(value, 2.0, 1e-12);
    CHECK_NEAR(fabs(n[0]), 1.0, 1e-12);
    /* an unbalanced force (a pull on one side only) does not separate */
    fs_separation_init(&s);
    fs_separation_add(&s, f1, z);
    fs_separation_tensor(&s, zeta);
    CHECK(max_abs6(zeta) < 1e-15);
    /* balanced compression closes: negative */
    fs_separation_init(&s);
    fs_separation_add(&s, z, f1);
    fs_separation_add(&s, z, f2);
    fs_separation_tensor(&s, zeta);
    CHECK(fs_separation_largest(zeta, &value, n) == 0);
    CHECK(value <= 1e-15);
    CHECK_NEAR(zeta[0], -2.0, 1e-12);
    /* invariance under a rotation of the frame */
    double ang = 0.7, c = cos(ang), sn = sin(ang);
    double g[4][3] = {{1.0, 0.5, -0.2}, {-0.4, -0.9, 0.3}, {-0.6, 0.4, -0.1}, {0.2, 0.1, 0.9}};
    double vals[2];
    for (int rot = 0; rot < 2; rot++) {
        fs_separation_init(&s);
        for (int k = 0; k < 4; k++) {
            double f[3] = {g[k][0], g[k][1], g[k][2]};
            if (rot) {
                double x = c * f[0] - sn * f[1], y = sn * f[0] + c * f[1];
                f[0] = x;
                f[1] = y;
            }
            double fm[3] = {-0.3 * f[1], 0.3 * f[0], 0.1 * f[2]};
            fs_separation_add(&s, f, fm);
        }
        fs_separation_tensor(&s, zeta);
        CHECK(fs_separation_largest(zeta, &vals[rot], n) == 0);
    }
    CHECK_NEAR(vals[0], vals[1], 1e-12);
}

int main(void)
{
    RUN(test_split);
    RUN(test_m);
    RUN(test_tensor);
    return check_finish();
}
