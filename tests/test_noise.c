/* Tests of the gradient noise fields: range, lattice zeros, continuity, periodicity, determinism. */
#include "field/noise.h"

#include <math.h>

#include "base/rng.h"
#include "check.h"

/* A sample coordinate in [-50, 50) drawn from the test stream. */
static double coord(uint64_t i) { return fs_rand_range(7, FS_RNG_TEST, i, -50.0, 50.0); }

static void test_range(void)
{
    double lo = 0.0, hi = 0.0, lo3 = 0.0, hi3 = 0.0, sum2 = 0.0;
    int n = 200000;
    for (int i = 0; i < n; i++) {
        double v = fs_noise2(3, coord(3 * i), coord(3 * i + 1), 0, 0);
        double w = fs_noise3(3, coord(3 * i), coord(3 * i + 1), coord(3 * i + 2));
        lo = fmin(lo, v);
        hi = fmax(hi, v);
        lo3 = fmin(lo3, w);
        hi3 = fmax(hi3, w);
        sum2 += v * v;
    }
    CHECK_MSG(lo >= -1.1 && hi <= 1.1, "2-D range [%g, %g]", lo, hi);
    CHECK_MSG(lo3 >= -1.1 && hi3 <= 1.1, "3-D range [%g, %g]", lo3, hi3);
    /* Not degenerate: the field uses a good part of its range and has a sensible spread. */
    CHECK_MSG(hi - lo > 1.0 && hi3 - lo3 > 1.0, "2-D span %g, 3-D span %g", hi - lo, hi3 - lo3);
    double rms = sqrt(sum2 / n);
    CHECK_MSG(rms > 0.1 && rms < 0.6, "rms %g", rms);
}

static void test_lattice_zeros(void)
{
    double worst = 0.0;
    for (int i = -20; i <= 20; i++)
        for (int j = -20; j <= 20; j++) {
            worst = fmax(worst, fabs(fs_noise2(11, i, j, 0, 0)));
            worst = fmax(worst, fabs(fs_noise2(11, i, j, 7, 5)));
            worst = fmax(worst, fabs(fs_noise3(11, i, j, (i * j) % 9)));
        }
    CHECK_MSG(worst == 0.0, "largest value at a lattice point %g", worst);
}

/* The gradient of quintic-faded gradient noise is bounded (about 2.5 per unit in our scaling), so a
 * step of 1e-4 changes the value by well under 1e-3, across cell borders too. */
static void test_continuity(void)
{
    double worst2 = 0.0, worst3 = 0.0;
    const double h = 1e-4;
    for (int i = 0; i < 20000; i++) {
        double x = coord(3 * i), y = coord(3 * i + 1), z = coord(3 * i + 2);
        if (i % 4 == 0)
            x = floor(x) - 0.5 * h; /* straddle a lattice line */
        double a = fs_noise2(5, x, y, 0, 0), b = fs_noise2(5, x + h, y + h, 0, 0);
        worst2 = fmax(worst2, fabs(a - b));
        double c = fs_noise3(5, x, y, z), d = fs_noise3(5, x + h, y, z + h);
        worst3 = fmax(worst3, fabs(c - d));
    }
    CHECK_MSG(worst2 < 1e-3, "2-D change %g over a step of %g", worst2, h);
    CHECK_MSG(worst3 < 1e-3, "3-D change %g over a step of %g", worst3, h);
}

static void test_periodicity(void)
{
    const int px = 7, py = 3;
    double worst = 0.0, worst_other = 0.0;
    for (int i = 0; i < 5000; i++) {
        double x = 0.25 * coord(2 * i), y = 0.25 * coord(2 * i + 1);
        double v = fs_noise2(9, x, y, px, py);
        worst = fmax(worst, fabs(v - fs_noise2(9, x + px, y, px, py)));
        worst = fmax(worst, fabs(v - fs_noise2(9, x, y - py, px, py)));
        worst = fmax(worst, fabs(v - fs_noise2(9, x - 2 * px, y + 3 * py, px, py)));
        /* Only x wraps when only period_x is given: y shifted by py is a different value. */
        worst_other = fmax(worst_other, fabs(fs_noise2(9, x, y, px, 0) - fs_noise2(9, x, y + py, px, 0)));
    }
    CHECK_MSG(worst < 1e-12, "periodic field differs by %g one period away", worst);
    CHECK_MSG(worst_other > 0.1, "non-periodic axis repeats (max difference %g)", worst_other);
    /* A period of 1 still gives a field that is not identically zero. */
    CHECK(fabs(fs_noise2(9, 0.3, 0.6, 1, 1)) > 0.0);
    CHECK_NEAR(fs_noise2(9, 0.3, 0.6, 1, 1), fs_noise2(9, 5.3, -3.4, 1, 1), 1e-12);
}

static void test_determinism_and_seed(void)
{
    int differ2 = 0, differ3 = 0, same = 1;
    for (int i = 0; i < 1000; i++) {
        double x = coord(3 * i), y = coord(3 * i + 1), z = coord(3 * i + 2);
        double a = fs_noise2(1, x, y, 0, 0);
        same &= a == fs_noise2(1, x, y, 0, 0);
        same &= fs_noise3(1, x, y, z) == fs_noise3(1, x, y, z);
        differ2 += fabs(a - fs_noise2(2, x, y, 0, 0)) > 1e-6;
        differ3 += fabs(fs_noise3(1, x, y, z) - fs_noise3(2, x, y, z)) > 1e-6;
    }
    CHECK(same);
    CHECK_MSG(differ2 > 950 && differ3 > 950, "seeds 1 and 2 differ at %d / %d of 1000 points", differ2, differ3);
}

int main(void)
{
    RUN(test_range);
    RUN(test_lattice_zeros);
    RUN(test_continuity);
    RUN(test_periodicity);
    RUN(test_determinism_and_seed);
    return check_finish();
}
