/* Tests of the shared split kernels: ray against fan sector, crack directions, edge collapse, Griffith release rate. */
#include <math.h>
#include <stdint.h>

#include "base/rng.h"
#include "check.h"
#include "fracture/split.h"

/* A ray through the sector crosses its far edge where the lines meet; snapping near the ends. */
static void test_ray_sector(void)
{
    const double a[2] = {1.0, -1.0}, b[2] = {1.0, 1.0};
    double s;
    const double along_x[2] = {2.0, 0.0};
    CHECK(fs_split_ray_sector(a, b, along_x, 0.2, &s) == FS_SPLIT_EDGE);
    CHECK_NEAR(s, 0.5, 1e-15);
    const double up[2] = {1.0, 0.5}; /* meets x = 1 at y = 0.5: s = 0.75 */
    CHECK(fs_split_ray_sector(a, b, up, 0.2, &s) == FS_SPLIT_EDGE);
    CHECK_NEAR(s, 0.75, 1e-15);
    const double near_b[2] = {1.0, 0.8}; /* s = 0.9 */
    CHECK(fs_split_ray_sector(a, b, near_b, 0.2, &s) == FS_SPLIT_AT_B);
    CHECK_NEAR(s, 0.9, 1e-15);
    const double near_a[2] = {1.0, -0.9}; /* s = 0.05 */
    CHECK(fs_split_ray_sector(a, b, near_a, 0.2, &s) == FS_SPLIT_AT_A);
    const double back[2] = {-1.0, 0.0}; /* the opposite ray misses the sector */
    CHECK(fs_split_ray_sector(a, b, back, 0.2, &s) == FS_SPLIT_MISS);
    CHECK(s == -1.0);
    const double outside[2] = {0.2, 1.0}; /* beyond b's side */
    CHECK(fs_split_ray_sector(a, b, outside, 0.2, &s) == FS_SPLIT_MISS);
    /* a clockwise (inverted) sector and a zero direction never hit */
    CHECK(fs_split_ray_sector(b, a, along_x, 0.2, &s) == FS_SPLIT_MISS);
    const double zero[2] = {0.0, 0.0};
    CHECK(fs_split_ray_sector(a, b, zero, 0.2, &s) == FS_SPLIT_MISS);
}

/* Around a full fan of sectors every direction is claimed by one sector (or two on a shared edge),
 * and the crossing point lies on the ray. */
static void test_fan_covers_all_directions(void)
{
    double pts[7][2];
    for (int k = 0; k < 7; k++) {
        double ang = 2.0 * 3.14159265358979 * (k + 0.3 * fs_rand01(7, FS_RNG_TEST, (uint64_t)k)) / 7.0;
        double r = 1.0 + fs_rand01(7, FS_RNG_TEST, 100 + (uint64_t)k);
        pts[k][0] = r * cos(ang);
        pts[k][1] = r * sin(ang);
    }
    int worst_hits = 10, best_hits = 0;
    double worst_off = 0.0;
    for (int q = 0; q < 360; q++) {
        double d[2] = {cos(q * 0.0174532925 + 0.001), sin(q * 0.0174532925 + 0.001)};
        int hits = 0;
        for (int k = 0; k < 7; k++) {
            const double *a = pts[k], *b = pts[(k + 1) % 7];
            double s;
            if (fs_split_ray_sector(a, b, d, 0.0, &s) == FS_SPLIT_MISS)
                continue;
            hits++;
            double p[2] = {a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])};
            worst_off = fmax(worst_off, fabs(p[0] * d[1] - p[1] * d[0]));
            CHECK(p[0] * d[0] + p[1] * d[1] > 0.0);
        }
        worst_hits = hits < worst_hits ? hits : worst_hits;
        best_hits = hits > best_hits ? hits : best_hits;
    }
    CHECK(worst_hits >= 1 && best_hits <= 2);
    CHECK_MSG(worst_off < 1e-12, "crossing off the ray by %g", worst_off);
}

static void test_directions(void)
{
    const double m[2] = {3.0, 0.0};
    double d[2];
    CHECK(fs_split_crack_direction(m, d));
    CHECK_NEAR(d[0], 0.0, 1e-15); /* a plane normal to x: the crack runs along y */
    CHECK_NEAR(fabs(d[1]), 1.0, 1e-15);
    const double zero[2] = {0.0, 0.0};
    CHECK(!fs_split_crack_direction(zero, d) && d[0] == 0.0 && d[1] == 0.0);
    const double dir[2] = {0.6, 0.8}, in[2] = {-1.0, 0.0};
    double out[2];
    fs_split_continue_direction(dir, in, out);
    CHECK(out[0] == -0.6 && out[1] == -0.8);
    const double q[2] = {1.0, 1.0}, line[2] = {1.0, 0.0};
    fs_split_project_onto_line(q, line, out);
    CHECK(out[0] == 1.0 && out[1] == 0.0);
}

/* Griffith: 1 J/m^2 is 1e-4 MPa cm; G = released energy per area; extends only above Gc. */
static void test_griffith(void)
{
    CHECK_NEAR(fs_griffith_toughness_model_units(100.0), 1e-2, 1e-18);
    /* 1e-4 J released over 0.1 cm^2 (1e-5 m^2): G = 10 J/m^2 = 1e-3 MPa cm */
    CHECK_NEAR(fs_griffith_release(3e-4, 2e-4, 0.1), 1e-3, 1e-15);
    CHECK(fs_griffith_extends(3e-4, 2e-4, 0.1, fs_griffith_toughness_model_units(9.0)));
    CHECK(!fs_griffith_extends(3e-4, 2e-4, 0.1, fs_griffith_toughness_model_units(11.0)));
    CHECK(isnan(fs_griffith_release(1.0, 0.0, 0.0)));
    CHECK(!fs_griffith_extends(1.0, 0.0, 0.0, 0.0));
}

int main(void)
{
    RUN(test_ray_sector);
    RUN(test_fan_covers_all_directions);
    RUN(test_directions);
    RUN(test_griffith);
    return check_finish();
}
