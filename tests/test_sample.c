/* Tests of point sampling: repulsion gives evenly spread, irregular, deterministic points on every
 * domain; the hex lattice has six equidistant neighbours and closes up across periodic sides. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"
#include "geom/domain.h"
#include "geom/sample.h"
#include "check.h"

typedef struct {
    const char *name;
    fs_domain d;
} sample_case;

static fs_domain make_domain(fs_domain_type type, double w, double h, double r, bool px, bool py)
{
    fs_domain d = fs_domain_default();
    d.type = type;
    d.width = w;
    d.height = h;
    d.radius = r;
    d.periodic_x = px;
    d.periodic_y = py;
    fs_domain_normalize(&d);
    return d;
}

#define N_CASES 5
static sample_case cases(int i)
{
    sample_case c[N_CASES] = {
        {"plane", make_domain(FS_DOMAIN_PLANE, 10, 10, 0, false, false)},
        {"periodic plane", make_domain(FS_DOMAIN_PLANE, 12, 7, 0, true, true)},
        {"cylinder", make_domain(FS_DOMAIN_CYLINDER, 0, 12, 1.5, false, false)},
        {"cylinder periodic along the axis", make_domain(FS_DOMAIN_CYLINDER, 0, 12, 1.5, false, true)},
        {"sphere", make_domain(FS_DOMAIN_SPHERE, 0, 0, 5, false, false)},
    };
    return c[i];
}

/* Distance between two points of the domain, periodic-aware (sphere: the chord). */
static double dist(const fs_domain *d, const double *a, const double *b)
{
    double v[3];
    fs_domain_delta(d, a, b, v);
    return fs_norm3(v);
}

typedef struct {
    double min, mean, sd; /* of the nearest-neighbour distance over all points */
} nn_stats;

/* Brute force: every pair. */
static nn_stats nearest_neighbours(const fs_domain *d, const fs_points *pts)
{
    double lo = INFINITY, sum = 0, sum2 = 0;
    for (int32_t i = 0; i < pts->n; i++) {
        double best = INFINITY;
        for (int32_t j = 0; j < pts->n; j++)
            if (j != i)
                best = fmin(best, dist(d, pts->p + 3 * i, pts->p + 3 * j));
        lo = fmin(lo, best);
        sum += best;
        sum2 += best * best;
    }
    nn_stats s = {lo, sum / pts->n, 0};
    s.sd = sqrt(fmax(0, sum2 / pts->n - s.mean * s.mean));
    return s;
}

/* Every point inside the domain: a periodic side is half open, a non-periodic side closed (points
 * may be snapped onto it); sphere points on the sphere. */
static bool inside(const fs_domain *d, const double *p)
{
    if (d->type == FS_DOMAIN_SPHERE)
        return fabs(fs_norm3(p) - d->radius) <= 1e-9;
    double ex = fs_domain_extent_x(d), ey = fs_domain_extent_y(d);
    bool okx = p[0] >= 0 && (d->periodic_x ? p[0] < ex : p[0] <= ex);
    bool oky = p[1] >= 0 && (d->periodic_y ? p[1] < ey : p[1] <= ey);
    return okx && oky && p[2] == 0;
}

static fs_sample_params params(int32_t count, uint64_t seed)
{
    fs_sample_params sp = fs_sample_params_default();
    sp.count = count;
    sp.seed = seed;
    return sp;
}

enum { N_POINTS = 1500 };

static void test_defaults(void)
{
    fs_sample_params sp = fs_sample_params_default();
    CHECK(sp.count == 1000 && sp.iterations == 30 && sp.radius_jitter == 0.2 && sp.seed == 1);
    fs_domain d = make_domain(FS_DOMAIN_PLANE, 10, 10, 0, false, false);
    /* A hex lattice of spacing a has one point per sqrt(3)/2 a^2. */
    double a = fs_sample_spacing(&d, 1000);
    CHECK_NEAR(1000 * sqrt(3) / 2 * a * a, 100.0, 1e-9);
}

/* The achieved numbers (n = 1500, default parameters, the five domains): minimum distance 0.67-0.72 x
 * the spacing, mean nearest-neighbour distance 0.89-0.92 x, its standard deviation 0.07-0.08 x
 * (uniformly random points: 0.03-0.04, 0.45-0.47, 0.23). Checked with some margin: min >= 0.6, mean
 * in [0.85, 1.0] (the requirement is min >= 0.5 and mean within 20 %), and sd > 0.03 (evenly spread,
 * but not a lattice). */
static void test_repulsion_spreads_evenly(void)
{
    for (int c = 0; c < N_CASES; c++) {
        sample_case sc = cases(c);
        fs_sample_params sp = params(N_POINTS, 7);
        fs_points pts = {0};
        CHECK_MSG(fs_sample_repulsion(&sc.d, &sp, &pts) == 0, "%s: %s", sc.name, fs_error_message());
        CHECK_MSG(pts.n == N_POINTS, "%s: %d points", sc.name, (int)pts.n);
        int outside = 0;
        for (int32_t i = 0; i < pts.n; i++)
            outside += !inside(&sc.d, pts.p + 3 * i);
        CHECK_MSG(outside == 0, "%s: %d points outside the domain", sc.name, outside);
        double s = fs_sample_spacing(&sc.d, N_POINTS);
        nn_stats st = nearest_neighbours(&sc.d, &pts);
        CHECK_MSG(st.min >= 0.6 * s, "%s: min distance %.3f x spacing", sc.name, st.min / s);
        CHECK_MSG(st.mean >= 0.85 * s && st.mean <= 1.0 * s, "%s: mean nn distance %.3f x spacing", sc.name, st.mean / s);
        CHECK_MSG(st.sd > 0.03 * s, "%s: nn distance sd %.3f x spacing", sc.name, st.sd / s);
        fs_points_free(&pts);
        CHECK(pts.p == NULL && pts.n == 0);
    }
}

/* The bounds above mean something: uniformly random points (no repulsion) fail them. */
static void test_random_points_fail_the_bounds(void)
{
    for (int c = 0; c < N_CASES; c++) {
        sample_case sc = cases(c);
        fs_sample_params sp = params(N_POINTS, 7);
        sp.iterations = 0;
        fs_points pts = {0};
        CHECK(fs_sample_repulsion(&sc.d, &sp, &pts) == 0);
        double s = fs_sample_spacing(&sc.d, N_POINTS);
        nn_stats st = nearest_neighbours(&sc.d, &pts);
        CHECK_MSG(st.min < 0.1 * s, "%s: random min distance %.3f x spacing", sc.name, st.min / s);
        CHECK_MSG(st.mean < 0.6 * s, "%s: random mean nn distance %.3f x spacing", sc.name, st.mean / s);
        fs_points_free(&pts);
    }
}

static void test_deterministic(void)
{
    for (int c = 0; c < N_CASES; c++) {
        sample_case sc = cases(c);
        fs_sample_params sp = params(600, 42);
        fs_points a = {0}, b = {0}, other = {0};
        CHECK(fs_sample_repulsion(&sc.d, &sp, &a) == 0);
        CHECK(fs_sample_repulsion(&sc.d, &sp, &b) == 0);
        sp.seed = 43;
        CHECK(fs_sample_repulsion(&sc.d, &sp, &other) == 0);
        CHECK_MSG(a.n == b.n && memcmp(a.p, b.p, (size_t)a.n * 3 * sizeof(double)) == 0, "%s: same seed differs", sc.name);
        int same = 0;
        for (int32_t i = 0; i < a.n; i++)
            same += memcmp(a.p + 3 * i, other.p + 3 * i, 3 * sizeof(double)) == 0;
        CHECK_MSG(same == 0, "%s: %d points equal under another seed", sc.name, same);
        fs_points_free(&a);
        fs_points_free(&b);
        fs_points_free(&other);
    }
}

/* FNV-1a hash of the bytes of the coordinates. */
static uint64_t points_hash(const fs_points *pts)
{
    uint64_t h = UINT64_C(14695981039346656037);
    const unsigned char *c = (const unsigned char *)pts->p;
    for (size_t i = 0; i < 3 * (size_t)pts->n * sizeof(double); i++) {
        h ^= c[i];
        h *= UINT64_C(1099511628211);
    }
    return h;
}

/* Sets large enough to be sampled on several threads give, bit for bit, the points that the
 * sampler gave when it ran on one thread (the hashes were taken then). */
static void test_threads_keep_the_points(void)
{
    struct {
        const char *name;
        fs_domain d;
        uint64_t hash;
    } c[3] = {
        {"plane", make_domain(FS_DOMAIN_PLANE, 16, 14, 0, false, false), UINT64_C(0x0e61810501590d0d)},
        {"periodic plane", make_domain(FS_DOMAIN_PLANE, 12, 17, 0, true, true), UINT64_C(0xfc321a144a0af033)},
        {"sphere", make_domain(FS_DOMAIN_SPHERE, 0, 0, 4, false, false), UINT64_C(0x6328ad6da89d63bc)},
    };
    for (int k = 0; k < 3; k++) {
        fs_sample_params sp = params(25000, 7);
        fs_points pts = {0};
        CHECK(fs_sample_repulsion(&c[k].d, &sp, &pts) == 0);
        uint64_t h = points_hash(&pts);
        CHECK_MSG(h == c[k].hash, "%s: points hash %016llx, expected %016llx", c[k].name, (unsigned long long)h,
                  (unsigned long long)c[k].hash);
        fs_points_free(&pts);
    }
}

/* Tiny point sets make grids of one or two cells, where a cell neighbours its own periodic images. */
static void test_tiny_sets(void)
{
    fs_domain doms[4] = {
        make_domain(FS_DOMAIN_PLANE, 1, 1, 0, true, true),
        make_domain(FS_DOMAIN_PLANE, 0.2, 30, 0, true, false),
        make_domain(FS_DOMAIN_PLANE, 1, 1, 0, false, false),
        make_domain(FS_DOMAIN_SPHERE, 0, 0, 1, false, false),
    };
    int32_t counts[3] = {3, 4, 9};
    for (int k = 0; k < 4; k++)
        for (int c = 0; c < 3; c++) {
            fs_sample_params sp = params(counts[c], 5);
            fs_points pts = {0};
            CHECK(fs_sample_repulsion(&doms[k], &sp, &pts) == 0);
            CHECK(pts.n == counts[c]);
            int outside = 0;
            for (int32_t i = 0; i < pts.n; i++)
                outside += !inside(&doms[k], pts.p + 3 * i);
            CHECK_MSG(outside == 0, "domain %d, %d points: %d outside", k, (int)counts[c], outside);
            nn_stats st = nearest_neighbours(&doms[k], &pts);
            CHECK_MSG(st.min > 0.3 * fs_sample_spacing(&doms[k], counts[c]), "domain %d, %d points: min %g", k,
                      (int)counts[c], st.min);
            fs_points_free(&pts);
        }
}

/* Sorted distances from point i to its seven nearest neighbours. */
static void seven_nearest(const fs_domain *d, const fs_points *pts, int32_t i, double *out)
{
    for (int q = 0; q < 7; q++)
        out[q] = INFINITY;
    for (int32_t j = 0; j < pts->n; j++) {
        if (j == i)
            continue;
        double v = dist(d, pts->p + 3 * i, pts->p + 3 * j);
        for (int q = 0; q < 7; q++)
            if (v < out[q]) {
                for (int r = 6; r > q; r--)
                    out[r] = out[r - 1];
                out[q] = v;
                break;
            }
    }
}

static void test_hex_plane(void)
{
    fs_domain d = make_domain(FS_DOMAIN_PLANE, 10, 10, 0, false, false);
    fs_points pts = {0};
    CHECK(fs_sample_hex(&d, 1000, &pts) == 0);
    CHECK_MSG(fabs(pts.n - 1000.0) < 100.0, "%d points", (int)pts.n);
    double a = fs_sample_spacing(&d, 1000);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    int outside = 0;
    for (int32_t i = 0; i < pts.n; i++) {
        outside += !inside(&d, pts.p + 3 * i);
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], pts.p[3 * i + k]);
            hi[k] = fmax(hi[k], pts.p[3 * i + k]);
        }
    }
    CHECK(outside == 0);
    /* the lattice is centred */
    CHECK_NEAR(lo[0] + hi[0], 10.0, 1e-9);
    CHECK_NEAR(lo[1] + hi[1], 10.0, 1e-9);
    int interior = 0, six = 0;
    for (int32_t i = 0; i < pts.n; i++) {
        const double *p = pts.p + 3 * i;
        if (p[0] < lo[0] + 0.9 * a || p[0] > hi[0] - 0.9 * a || p[1] < lo[1] + 0.8 * a || p[1] > hi[1] - 0.8 * a)
            continue;
        double nn[7];
        seven_nearest(&d, &pts, i, nn);
        interior++;
        six += fabs(nn[0] - a) <= 1e-9 && fabs(nn[5] - a) <= 1e-9 && nn[6] > 1.7 * a;
    }
    CHECK(interior > 700);
    CHECK_MSG(six == interior, "%d of %d interior points have six neighbours at the spacing", six, interior);
    fs_points_free(&pts);
}

/* Every point of a lattice closed up across its periodic sides sees the same six neighbours as a
 * point in the middle: two at the row spacing ax, four on the diagonals, all at the same distance
 * when the lattice is isotropic. Points on a non-periodic edge (the outermost rows, or the first
 * and last point of each row) are left out. */
static void check_closed_lattice(const char *name, const fs_domain *d, int32_t count, bool isotropic)
{
    fs_points pts = {0};
    CHECK(fs_sample_hex(d, count, &pts) == 0);
    CHECK_MSG(fabs(pts.n - (double)count) < 0.1 * count, "%s: %d points for %d", name, (int)pts.n, (int)count);
    double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
    for (int32_t i = 0; i < pts.n; i++)
        for (int k = 0; k < 2; k++) {
            lo[k] = fmin(lo[k], pts.p[3 * i + k]);
            hi[k] = fmax(hi[k], pts.p[3 * i + k]);
        }
    int32_t mid = 0;
    double best = INFINITY;
    for (int32_t i = 0; i < pts.n; i++) {
        double dx = pts.p[3 * i] - 0.5 * (lo[0] + hi[0]), dy = pts.p[3 * i + 1] - 0.5 * (lo[1] + hi[1]);
        if (hypot(dx, dy) < best) {
            best = hypot(dx, dy);
            mid = i;
        }
    }
    double ref[7];
    seven_nearest(d, &pts, mid, ref);
    double ax = ref[0], diag = ref[5];
    CHECK_MSG(fabs(diag / ax - 1) < 0.05, "%s: anisotropy %g", name, diag / ax - 1);
    if (isotropic)
        CHECK_NEAR(diag, ax, 1e-9);
    bool per[2] = {d->periodic_x, d->periodic_y};
    int checked = 0, same = 0, outside = 0;
    for (int32_t i = 0; i < pts.n; i++) {
        const double *p = pts.p + 3 * i;
        outside += !inside(d, p);
        bool edge = false;
        for (int k = 0; k < 2; k++) {
            double margin = k == 0 ? 0.9 * ax : 0.4 * ax; /* rows alternate by ax / 2; rows are 0.87 ax apart */
            edge |= !per[k] && (p[k] < lo[k] + margin || p[k] > hi[k] - margin);
        }
        if (edge)
            continue;
        double nn[7];
        seven_nearest(d, &pts, i, nn);
        checked++;
        int ok = nn[6] > 1.5 * ax;
        for (int q = 0; q < 6; q++)
            ok &= fabs(nn[q] - ref[q]) <= 1e-9;
        same += ok;
    }
    CHECK_MSG(outside == 0, "%s: %d points outside", name, outside);
    CHECK_MSG(checked > pts.n / 2, "%s: only %d points checked", name, checked);
    CHECK_MSG(same == checked, "%s: %d of %d points have the six lattice neighbours", name, same, checked);
    fs_points_free(&pts);
}

static void test_hex_periodic(void)
{
    fs_domain pxy = make_domain(FS_DOMAIN_PLANE, 10, 7, 0, true, true);
    fs_domain py = make_domain(FS_DOMAIN_PLANE, 10, 7, 0, false, true);
    fs_domain cyl = make_domain(FS_DOMAIN_CYLINDER, 0, 10, 2, false, false);
    fs_domain cyly = make_domain(FS_DOMAIN_CYLINDER, 0, 10, 2, false, true);
    check_closed_lattice("periodic plane", &pxy, 800, false);
    check_closed_lattice("periodic plane in y", &py, 800, true);
    check_closed_lattice("cylinder", &cyl, 800, true);
    check_closed_lattice("cylinder periodic along the axis", &cyly, 800, false);
    /* around the cylinder: a whole number of spacings makes the circumference */
    fs_points pts = {0};
    CHECK(fs_sample_hex(&cyl, 800, &pts) == 0);
    int row = 0;
    for (int32_t i = 0; i < pts.n; i++)
        row += pts.p[3 * i + 1] == pts.p[1];
    double nn[7];
    seven_nearest(&cyl, &pts, pts.n / 2, nn);
    CHECK_NEAR(row * nn[0], 4 * FS_PI, 1e-9);
    fs_points_free(&pts);
}

static void test_errors(void)
{
    fs_domain plane = make_domain(FS_DOMAIN_PLANE, 10, 10, 0, false, false);
    fs_points pts = {0};
    fs_sample_params sp = params(2, 1);

    fs_error_clear();
    CHECK(fs_sample_repulsion(&plane, &sp, &pts) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "expected at least 3 points, got 2") != NULL, "%s", fs_error_message());
    CHECK(pts.n == 0 && pts.p == NULL);

    fs_error_clear();
    sp.count = 50000001;
    CHECK(fs_sample_repulsion(&plane, &sp, &pts) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);

    sp.count = 100;
    fs_domain bad = plane;
    bad.width = 0;
    fs_error_clear();
    CHECK(fs_sample_repulsion(&bad, &sp, &pts) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "width") != NULL, "%s", fs_error_message());

    bad = plane;
    bad.height = NAN;
    fs_error_clear();
    CHECK(fs_sample_repulsion(&bad, &sp, &pts) == -1);
    CHECK_MSG(strstr(fs_error_message(), "height") != NULL, "%s", fs_error_message());

    bad = make_domain(FS_DOMAIN_CYLINDER, 0, 10, -1, false, false);
    fs_error_clear();
    CHECK(fs_sample_repulsion(&bad, &sp, &pts) == -1);
    CHECK_MSG(strstr(fs_error_message(), "radius") != NULL, "%s", fs_error_message());

    bad = make_domain(FS_DOMAIN_SPHERE, 0, 0, INFINITY, false, false);
    fs_error_clear();
    CHECK(fs_sample_repulsion(&bad, &sp, &pts) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strstr(fs_error_message(), "radius") != NULL, "%s", fs_error_message());

    fs_domain sph = make_domain(FS_DOMAIN_SPHERE, 0, 0, 5, false, false);
    fs_error_clear();
    CHECK(fs_sample_hex(&sph, 100, &pts) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK_MSG(strcmp(fs_error_message(), "hex lattice: expected a plane or cylinder domain") == 0, "%s", fs_error_message());

    fs_error_clear();
    CHECK(fs_sample_hex(&plane, 2, &pts) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    CHECK(pts.n == 0 && pts.p == NULL);

    bad = plane;
    bad.width = -3;
    fs_error_clear();
    CHECK(fs_sample_hex(&bad, 100, &pts) == -1);
    CHECK_MSG(strstr(fs_error_message(), "width") != NULL, "%s", fs_error_message());
}

/* Domains far smaller or thinner than their point spacing once asked for a grid of a million cells a
 * side (a sphere of radius 1e-300: 10^12 columns, an abort on a 20 TB allocation); the grid keeps a
 * few cells per point, and the points still lie in the domain. */
static void test_degenerate_domains_bounded(void)
{
    fs_domain d[3] = {make_domain(FS_DOMAIN_SPHERE, 0, 0, 1e-300, false, false),
                      make_domain(FS_DOMAIN_PLANE, 1e6, 1e-10, 0, true, true),
                      make_domain(FS_DOMAIN_PLANE, 1e-300, 10, 0, false, false)};
    for (int k = 0; k < 3; k++) {
        fs_points pts = {0};
        fs_sample_params sp = params(300, 2);
        fs_error_clear();
        int rc = fs_sample_repulsion(&d[k], &sp, &pts);
        CHECK_MSG(rc == 0 || fs_error_domain() == FS_ERR_DATA, "domain %d: %s", k, fs_error_message());
        for (int32_t i = 0; rc == 0 && i < pts.n; i++) {
            const double *p = pts.p + 3 * (size_t)i;
            if (d[k].type == FS_DOMAIN_PLANE)
                CHECK(p[0] >= 0.0 && p[0] <= d[k].width && p[1] >= 0.0 && p[1] <= d[k].height);
            else
                CHECK(fabs(p[0]) <= 1e-300 && fabs(p[1]) <= 1e-300 && fabs(p[2]) <= 1e-300);
        }
        fs_points_free(&pts);
    }
}

int main(void)
{
    RUN(test_defaults);
    RUN(test_repulsion_spreads_evenly);
    RUN(test_random_points_fail_the_bounds);
    RUN(test_deterministic);
    RUN(test_threads_keep_the_points);
    RUN(test_tiny_sets);
    RUN(test_hex_plane);
    RUN(test_hex_periodic);
    RUN(test_errors);
    RUN(test_degenerate_domains_bounded);
    return check_finish();
}
