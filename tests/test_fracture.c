/* Tests of the shared fracture kernels: eigen decomposition, principal stresses, nodal planes and the separation tensor, ranking, event search. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "base/error.h"
#include "base/rng.h"
#include "check.h"
#include "fracture/eigen.h"
#include "fracture/event.h"
#include "fracture/rank.h"
#include "base/vec.h"
#include "fracture/separation.h"

/* ---- eigen ---- */

/* Largest |a - V diag(l) V^T| entry, with vectors + 3k the k-th eigenvector. */
static double reconstruction_error(const double a[9], const double l[3], const double v[9])
{
    double worst = 0.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double sum = 0.0;
            for (int k = 0; k < 3; k++)
                sum += v[3 * k + i] * l[k] * v[3 * k + j];
            worst = fmax(worst, fabs(sum - a[3 * i + j]));
        }
    return worst;
}

/* Largest |V^T V - I| entry. */
static double orthonormality_error(const double v[9])
{
    double worst = 0.0;
    for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
            double dot = v[3 * a] * v[3 * b] + v[3 * a + 1] * v[3 * b + 1] + v[3 * a + 2] * v[3 * b + 2];
            worst = fmax(worst, fabs(dot - (a == b ? 1.0 : 0.0)));
        }
    return worst;
}

static int same9(const double a[9], const double b[9])
{
    for (int k = 0; k < 9; k++)
        if (a[k] != b[k])
            return 0;
    return 1;
}

static double det3(const double v[9])
{
    return v[0] * (v[4] * v[8] - v[5] * v[7]) - v[1] * (v[3] * v[8] - v[5] * v[6]) +
           v[2] * (v[3] * v[7] - v[4] * v[6]);
}

/* A random rotation Q (rows orthonormal, det +1) from a random unit quaternion. */
static void random_rotation(uint64_t index, double q[9])
{
    double w = fs_rand_normal(21, FS_RNG_TEST, 4 * index), x = fs_rand_normal(21, FS_RNG_TEST, 4 * index + 1);
    double y = fs_rand_normal(21, FS_RNG_TEST, 4 * index + 2), z = fs_rand_normal(21, FS_RNG_TEST, 4 * index + 3);
    double n = sqrt(w * w + x * x + y * y + z * z);
    w /= n, x /= n, y /= n, z /= n;
    const double r[9] = {1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
                         2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
                         2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)};
    memcpy(q, r, sizeof r);
}

/* a = Q^T diag(l) Q: the rows of Q are the eigenvectors. */
static void compose(const double q[9], const double l[3], double a[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double sum = 0.0;
            for (int k = 0; k < 3; k++)
                sum += q[3 * k + i] * l[k] * q[3 * k + j];
            a[3 * i + j] = sum;
        }
}

/* The checks every decomposition must pass: sorted, orthonormal, right-handed, reconstructs a. */
static void check_decomposition(const double a[9], double tol)
{
    double l[3], v[9];
    CHECK(fs_eigen_sym3(a, l, v) == 0);
    CHECK(l[0] >= l[1] && l[1] >= l[2]);
    CHECK_NEAR(orthonormality_error(v), 0.0, 1e-14);
    CHECK_NEAR(det3(v), 1.0, 1e-14);
    CHECK_NEAR(reconstruction_error(a, l, v), 0.0, tol);
}

static void test_eigen_random(void)
{
    double worst = 0.0;
    for (uint64_t m = 0; m < 2000; m++) {
        double a[9];
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++)
                a[3 * i + j] = a[3 * j + i] = fs_rand_range(7, FS_RNG_TEST, 9 * m + 3 * (uint64_t)i + (uint64_t)j, -1, 1);
        double l[3], v[9];
        CHECK(fs_eigen_sym3(a, l, v) == 0);
        CHECK(l[0] >= l[1] && l[1] >= l[2]);
        worst = fmax(worst, reconstruction_error(a, l, v));
        worst = fmax(worst, orthonormality_error(v));
        CHECK_NEAR(det3(v), 1.0, 1e-14);
        /* Trace and determinant are invariants. */
        CHECK_NEAR(l[0] + l[1] + l[2], a[0] + a[4] + a[8], 1e-14);
        CHECK_NEAR(l[0] * l[1] * l[2], det3(a), 1e-14);
    }
    CHECK_MSG(worst < 1e-12, "worst error %g", worst);
    /* Scale does not matter: the same matrices at 1e150 and 1e-150. */
    for (uint64_t m = 0; m < 50; m++) {
        double a[9], big[9], tiny[9];
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++)
                a[3 * i + j] = a[3 * j + i] = fs_rand_range(8, FS_RNG_TEST, 9 * m + 3 * (uint64_t)i + (uint64_t)j, -1, 1);
        for (int k = 0; k < 9; k++) {
            big[k] = a[k] * 1e150;
            tiny[k] = a[k] * 1e-150;
        }
        check_decomposition(big, 1e-12 * 1e150);
        check_decomposition(tiny, 1e-12 * 1e-150);
    }
}

static void test_eigen_prescribed(void)
{
    /* Known spectra, including repeated and nearly repeated eigenvalues, in random orientations. */
    static const double spectra[][3] = {{3, 1, -2}, {1, 1, -2}, {4, -1, -1}, {2, 2, 2},
                                        {1 + 1e-13, 1, 0.5}, {1e-9, 0, -1e-9}, {1e6, 1, 1e-6}};
    for (uint64_t k = 0; k < sizeof spectra / sizeof spectra[0]; k++)
        for (uint64_t rot = 0; rot < 40; rot++) {
            double q[9], a[9], l[3], v[9];
            random_rotation(40 * k + rot, q);
            compose(q, spectra[k], a);
            double scale = fabs(spectra[k][0]) + fabs(spectra[k][2]);
            CHECK(fs_eigen_sym3(a, l, v) == 0);
            for (int i = 0; i < 3; i++)
                CHECK_NEAR(l[i], spectra[k][i], 1e-14 * scale);
            check_decomposition(a, 1e-14 * scale);
            /* A simple eigenvalue's vector is the prescribed one up to sign. */
            if (spectra[k][0] - spectra[k][1] > 1e-3 * scale)
                CHECK_NEAR(fabs(v[0] * q[0] + v[1] * q[1] + v[2] * q[2]), 1.0, 1e-12);
        }
}

static void test_eigen_exact_cases(void)
{
    double l[3], v[9];
    const double diag[9] = {2, 0, 0, 0, -1, 0, 0, 0, 5};
    CHECK(fs_eigen_sym3(diag, l, v) == 0);
    CHECK(l[0] == 5 && l[1] == 2 && l[2] == -1);
    const double want[9] = {0, 0, 1, 1, 0, 0, 0, 1, 0}; /* e_z, e_x, e_z x e_x = e_y */
    CHECK(same9(v, want));

    const double repeated[9] = {3, 0, 0, 0, 3, 0, 0, 0, 3};
    CHECK(fs_eigen_sym3(repeated, l, v) == 0);
    CHECK(l[0] == 3 && l[1] == 3 && l[2] == 3);
    const double ident[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    CHECK(same9(v, ident));

    const double zero[9] = {0};
    CHECK(fs_eigen_sym3(zero, l, v) == 0);
    CHECK(l[0] == 0 && l[1] == 0 && l[2] == 0);
    CHECK(same9(v, ident));

    /* Two equal diagonal entries, one different: still exact, ties kept in axis order. */
    const double two[9] = {-4, 0, 0, 0, 7, 0, 0, 0, -4};
    CHECK(fs_eigen_sym3(two, l, v) == 0);
    CHECK(l[0] == 7 && l[1] == -4 && l[2] == -4);
    CHECK(v[1] == 1 && v[3] == 1 && v[8] == -1); /* e_y, e_x, e_y x e_x = -e_z */

    /* Values only. */
    CHECK(fs_eigen_sym3(diag, l, NULL) == 0);
    CHECK(l[0] == 5 && l[1] == 2 && l[2] == -1);

    /* Non-finite input is an error, not a hang. */
    const double bad[9] = {1, NAN, 0, NAN, 1, 0, 0, 0, 1};
    fs_error_clear();
    CHECK(fs_eigen_sym3(bad, l, v) == -1);
    CHECK(fs_error_domain() == FS_ERR_INTERNAL);
    fs_error_clear();
}

static void test_principal_stress(void)
{
    /* Pure shear tau_xy: principal stresses +-tau on planes at 45 degrees. */
    const double tau = 2.5;
    const double shear[6] = {0, 0, 0, tau, 0, 0};
    double s[3], d[9];
    CHECK(fs_eigen_principal_stress(shear, s, d) == 0);
    CHECK_NEAR(s[0], tau, 1e-15);
    CHECK_NEAR(s[1], 0.0, 1e-15);
    CHECK_NEAR(s[2], -tau, 1e-15);
    CHECK_NEAR(d[0], sqrt(0.5), 1e-15);
    CHECK_NEAR(d[1], sqrt(0.5), 1e-15);
    CHECK_NEAR(fabs(d[6]), sqrt(0.5), 1e-15);
    CHECK_NEAR(fabs(d[7]), sqrt(0.5), 1e-15);
    CHECK_NEAR(d[6] * d[7], -0.5, 1e-15);
    CHECK_NEAR(fabs(d[5]), 1.0, 1e-15);
    /* The same for tau_yz and tau_zx: the Voigt order is xx, yy, zz, xy, yz, zx. */
    const double shear_yz[6] = {0, 0, 0, 0, tau, 0}, shear_zx[6] = {0, 0, 0, 0, 0, tau};
    CHECK(fs_eigen_principal_stress(shear_yz, s, d) == 0);
    CHECK_NEAR(s[0], tau, 1e-15);
    CHECK_NEAR(d[1] * d[2], 0.5, 1e-15);
    CHECK(fs_eigen_principal_stress(shear_zx, s, d) == 0);
    CHECK_NEAR(s[2], -tau, 1e-15);
    CHECK_NEAR(d[6] * d[8], -0.5, 1e-15);
    CHECK_NEAR(fs_eigen_von_mises(shear), sqrt(3.0) * tau, 1e-14);

    /* Uniaxial stress along a tilted unit direction n: principal (sigma, 0, 0) with normal +-n, and
     * von Mises |sigma|, for tension and compression. */
    const double n[3] = {2.0 / 7.0, 3.0 / 7.0, 6.0 / 7.0};
    for (int sign = -1; sign <= 1; sign += 2) {
        double sigma = sign * 40.0;
        const double st[6] = {sigma * n[0] * n[0], sigma * n[1] * n[1], sigma * n[2] * n[2],
                              sigma * n[0] * n[1], sigma * n[1] * n[2], sigma * n[2] * n[0]};
        CHECK_NEAR(fs_eigen_von_mises(st), fabs(sigma), 1e-12);
        CHECK(fs_eigen_principal_stress(st, s, d) == 0);
        const double *dir = sigma > 0 ? d : d + 6;
        CHECK_NEAR(sigma > 0 ? s[0] : s[2], sigma, 1e-12);
        CHECK_NEAR(sigma > 0 ? s[2] : s[0], 0.0, 1e-12);
        CHECK_NEAR(fabs(dir[0] * n[0] + dir[1] * n[1] + dir[2] * n[2]), 1.0, 1e-14);
    }
    const double uni[6] = {-3, 0, 0, 0, 0, 0};
    CHECK(fs_eigen_von_mises(uni) == 3.0);
    /* A hydrostatic stress has no von Mises stress. */
    const double hydro[6] = {5, 5, 5, 0, 0, 0};
    CHECK(fs_eigen_von_mises(hydro) == 0.0);

    /* Principal strains: an engineering shear gamma gives +-gamma/2. */
    const double gamma[6] = {0, 0, 0, 0.002, 0, 0};
    CHECK(fs_eigen_principal_strain(gamma, s, NULL) == 0);
    CHECK_NEAR(s[0], 0.001, 1e-18);
    CHECK_NEAR(s[2], -0.001, 1e-18);
}

/* The cheap bound of the largest principal stress never falls below the Jacobi value (the kernel's
 * own, bit for bit), whatever the level, and is within its margin of it where it exceeds the level:
 * random stresses, and prescribed spectra with repeated and nearly repeated eigenvalues. */
static void check_bound(const double a[9], double scale)
{
    const double s[6] = {a[0], a[4], a[8], a[1], a[5], a[2]};
    double sigma[3];
    CHECK(fs_eigen_principal_stress(s, sigma, NULL) == 0);
    const double levels[] = {-INFINITY, sigma[0] - 1e-3 * scale, sigma[0], sigma[0] + 1e-3 * scale, INFINITY};
    for (int k = 0; k < 5; k++) {
        double b = fs_eigen_principal_bound(s, levels[k]);
        CHECK_MSG(b >= sigma[0], "bound %.17g below %.17g at level %g", b, sigma[0], levels[k]);
        if (b > levels[k])
            CHECK_MSG(b - sigma[0] <= 3e-6 * scale, "bound %.17g loose over %.17g (scale %g)", b, sigma[0], scale);
    }
}

static void test_principal_bound(void)
{
    for (uint64_t m = 0; m < 2000; m++) {
        double a[9];
        for (int i = 0; i < 3; i++)
            for (int j = i; j < 3; j++)
                a[3 * i + j] = a[3 * j + i] = fs_rand_range(9, FS_RNG_TEST, 9 * m + 3 * (uint64_t)i + (uint64_t)j, -1, 1);
        check_bound(a, 3.0);
    }
    static const double spectra[][3] = {{3, 1, -2}, {1, 1, -2}, {4, -1, -1}, {2, 2, 2},     {1 + 1e-13, 1, 0.5},
                                        {1e-9, 0, -1e-9}, {1e6, 1, 1e-6}, {5, 5, 5 - 1e-12}, {0, 0, 0}};
    for (uint64_t k = 0; k < sizeof spectra / sizeof spectra[0]; k++)
        for (uint64_t rot = 0; rot < 40; rot++) {
            double q[9], a[9];
            random_rotation(1000 + 40 * k + rot, q);
            compose(q, spectra[k], a);
            check_bound(a, fabs(spectra[k][0]) + fabs(spectra[k][2]) + 1e-300);
        }
    /* Axis-aligned stresses are bounded exactly by their largest entry at the closed form. */
    const double axis[6] = {2, -1, 0.5, 0, 0, 0};
    CHECK_NEAR(fs_eigen_principal_bound(axis, -INFINITY), 2.0, 1e-5);
    const double bad[6] = {NAN, 0, 0, 0, 0, 0};
    CHECK(!isfinite(fs_eigen_principal_bound(bad, 0.0)));
}

/* ---- rank ---- */

static void test_rank_largest(void)
{
    const double ratio[] = {0.3, 1.2, 0.9, 1.5, 1.1, -2.0};
    CHECK(fs_rank_pick(ratio, NULL, 6, 1) == 3);
    const uint64_t ids[] = {50, 40, 30, 20, 10, 0};
    for (uint64_t seed = 0; seed < 20; seed++)
        CHECK(fs_rank_pick(ratio, ids, 6, seed) == 3);
    CHECK(fs_rank_count_over(ratio, 6) == 3);
    /* Exactly 1 is not over the threshold. */
    const double edge[] = {1.0, 1.0 + 1e-15, 0.999};
    CHECK(fs_rank_count_over(edge, 3) == 1);
    /* Close ratios that are not ties (relative gap 1e-9): the larger wins for every seed. */
    const double close[] = {2.0, 2.0 * (1 + 1e-9)};
    for (uint64_t seed = 0; seed < 50; seed++)
        CHECK(fs_rank_pick(close, NULL, 2, seed) == 1);
    /* Empty and NaN input. */
    CHECK(fs_rank_pick(ratio, NULL, 0, 1) == -1);
    CHECK(fs_rank_count_over(ratio, 0) == 0);
    const double nans[] = {NAN, NAN};
    CHECK(fs_rank_pick(nans, NULL, 2, 1) == -1);
    const double some_nan[] = {NAN, 0.5, NAN, 0.2};
    CHECK(fs_rank_pick(some_nan, NULL, 4, 1) == 1);
    CHECK(fs_rank_count_over(some_nan, 4) == 0);
}

/* Candidates for the tie tests: four tie at 2 (one 1e-13 relative above), two are lower. */
static const double tie_ratio[6] = {2.0, 1.9, 2.0 * (1 + 1e-13), 2.0, 0.5, 2.0};
static const uint64_t tie_id[6] = {101, 7, 33, 58, 12, 999};

static int next_permutation(int *p, int n)
{
    int i = n - 2;
    while (i >= 0 && p[i] >= p[i + 1])
        i--;
    if (i < 0)
        return 0;
    int j = n - 1;
    while (p[j] <= p[i])
        j--;
    int t = p[i];
    p[i] = p[j];
    p[j] = t;
    for (int a = i + 1, b = n - 1; a < b; a++, b--) {
        t = p[a];
        p[a] = p[b];
        p[b] = t;
    }
    return 1;
}

/* The id chosen among the tied candidates for the given seed, for every order of the input; -1 if
 * two orders disagree. */
static int64_t tie_winner(uint64_t seed)
{
    int perm[6] = {0, 1, 2, 3, 4, 5};
    int64_t winner = -2;
    do {
        double r[6];
        uint64_t id[6];
        for (int k = 0; k < 6; k++) {
            r[k] = tie_ratio[perm[k]];
            id[k] = tie_id[perm[k]];
        }
        int32_t pick = fs_rank_pick(r, id, 6, seed);
        if (pick < 0)
            return -1;
        if (winner == -2)
            winner = (int64_t)id[pick];
        else if (winner != (int64_t)id[pick])
            return -1;
    } while (next_permutation(perm, 6));
    return winner;
}

static void test_rank_ties(void)
{
    /* All 720 orders agree, and the winner is the tied candidate with the smallest hash. */
    for (uint64_t seed = 0; seed < 8; seed++) {
        int64_t w = tie_winner(seed);
        CHECK_MSG(w >= 0, "seed %llu: orders disagree", (unsigned long long)seed);
        uint64_t best = 0;
        int64_t expect = -1;
        for (int k = 0; k < 6; k++) {
            if (tie_ratio[k] < 2.0)
                continue;
            uint64_t h = fs_hash3(seed, FS_RNG_TIEBREAK, tie_id[k]);
            if (expect < 0 || h < best) {
                best = h;
                expect = (int64_t)tie_id[k];
            }
        }
        CHECK(w == expect);
    }
    /* Different seeds break the tie differently: over 64 seeds, at least three of the four tied
     * candidates win sometimes, and the lower ones never do. */
    int wins[6] = {0};
    for (uint64_t seed = 0; seed < 64; seed++) {
        int32_t pick = fs_rank_pick(tie_ratio, tie_id, 6, seed);
        CHECK(pick >= 0);
        if (pick >= 0)
            wins[pick]++;
    }
    CHECK(wins[1] == 0 && wins[4] == 0);
    CHECK((wins[0] > 0) + (wins[2] > 0) + (wins[3] > 0) + (wins[5] > 0) >= 3);
}

/* ---- event ---- */

typedef struct {
    int kind;       /* which ratio function */
    double t_star;  /* first crossing of ratio 1 */
    int calls;
    double last_t;
    int fail_after; /* > 0: return NaN from this call on */
} ratio_ctx;

static double ratio_at(int kind, double t_star, double t)
{
    switch (kind) {
    case 0: return (t / t_star) * (t / t_star);                        /* thesis-like growth: stress ~ t^2 */
    case 1: return 0.8 + 0.2 * pow((t - 2.0) / (t_star - 2.0), 3.0);   /* starts at 0.8 at t = 2 */
    default: return 0.5 + 0.7 * sin(t);                                /* crosses at asin(5/7), falls back later */
    }
}

static double ratio_fn(void *ctx, double t)
{
    ratio_ctx *c = ctx;
    c->calls++;
    c->last_t = t;
    if (c->fail_after > 0 && c->calls >= c->fail_after) {
        fs_error(FS_ERR_INTERNAL, "test: equilibrium failed");
        return NAN;
    }
    return ratio_at(c->kind, c->t_star, t);
}

static void test_event_quadratic(void)
{
    ratio_ctx c = {0, 0.7, 0, 0, 0};
    fs_event_result r;
    CHECK(fs_event_find(ratio_fn, &c, 0.0, 0.01, 10.0, 1e-6, &r) == 0);
    CHECK(r.found == 1);
    CHECK(r.t >= 0.7);
    CHECK(r.t - 0.7 < 1e-6);
    CHECK(r.t_before <= 0.7);
    CHECK(r.t - r.t_before < 1e-6);
    CHECK(r.ratio > 1.0);
    CHECK(r.ratio == ratio_at(0, 0.7, r.t));
    CHECK(r.evaluations == c.calls);
    CHECK(r.t_last == c.last_t);
    /* Logarithmic cost: 7 doubling steps to pass 0.7 from 0.01, then log2(0.64 / 1e-6) bisections. */
    double bound = 2.0 + log2(0.7 / 0.01 + 1.0) + 1.0 + log2(0.7 / 1e-6) + 1.0;
    CHECK_MSG(r.evaluations <= bound, "%d evaluations", r.evaluations);
}

static void test_event_none(void)
{
    ratio_ctx c = {0, 0.7, 0, 0, 0};
    fs_event_result r;
    CHECK(fs_event_find(ratio_fn, &c, 0.0, 0.01, 0.5, 1e-6, &r) == 0);
    CHECK(r.found == 0);
    CHECK(r.t == 0.5);
    CHECK(r.t_last == 0.5);
    CHECK(r.ratio == ratio_at(0, 0.7, 0.5));
    CHECK(r.evaluations == c.calls && r.evaluations <= 7); /* 0.01, 0.03, 0.07, 0.15, 0.31, 0.5 */
    /* An empty interval calls nothing. */
    c.calls = 0;
    CHECK(fs_event_find(ratio_fn, &c, 0.5, 0.01, 0.5, 1e-6, &r) == 0);
    CHECK(r.found == 0 && r.evaluations == 0 && c.calls == 0 && isnan(r.ratio));
    /* The crossing exactly at t_end: f(t_end) = 1 is not over the threshold. */
    c.calls = 0;
    CHECK(fs_event_find(ratio_fn, &c, 0.0, 0.01, 0.7, 1e-6, &r) == 0);
    CHECK(r.found == 0);
}

static void test_event_logarithmic(void)
{
    /* Each factor 2 of resolution costs one more evaluation: 1e-4 -> 1e-8 adds about log2(1e4) = 13.3. */
    int evals[2];
    const double steps[2] = {1e-4, 1e-8};
    for (int k = 0; k < 2; k++) {
        ratio_ctx c = {0, 0.7, 0, 0, 0};
        fs_event_result r;
        CHECK(fs_event_find(ratio_fn, &c, 0.0, 0.01, 10.0, steps[k], &r) == 0);
        CHECK(r.found && r.t >= 0.7 && r.t - 0.7 < steps[k]);
        evals[k] = r.evaluations;
    }
    CHECK_MSG(evals[1] - evals[0] >= 12 && evals[1] - evals[0] <= 15, "%d then %d", evals[0], evals[1]);
    /* A tiny trial step is grown, not walked: from 1e-9 to 0.7 takes about log2(0.7e9) = 29 steps, and
     * the bisection of the last step (up to 0.7 wide) about as many again, not 0.7e9 calls. */
    ratio_ctx c = {0, 0.7, 0, 0, 0};
    fs_event_result r;
    CHECK(fs_event_find(ratio_fn, &c, 0.0, 1e-9, 10.0, 1e-9, &r) == 0);
    CHECK(r.found && r.t >= 0.7 && r.t - 0.7 < 1e-9);
    double bound = log2(0.7 / 1e-9 + 1.0) + 1.0 + log2(0.7 / 1e-9) + 2.0;
    CHECK_MSG(r.evaluations <= bound, "%d evaluations", r.evaluations);
}

/* "The adaptive time step finds the first fracture time within time.min_step of a brute-force scan." */
static void test_event_brute_force(void)
{
    static const struct { int kind; double t_star, t0, dt; } cases[] = {
        {0, 0.7, 0.0, 0.01}, {0, 0.7, 0.3, 0.2}, {0, 0.7, 0.699, 1.0}, {0, 3.3, 1.0, 0.05},
        {1, 2.45, 2.0, 0.01}, {1, 5.0, 2.0, 0.3}, {2, 0.0, 0.0, 0.05}, {2, 0.0, 0.5, 0.001},
    };
    const double min_step = 1e-4, t_end = 20.0;
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double brute = -1.0;
        for (long i = 1; cases[k].t0 + (double)i * min_step <= t_end; i++) {
            double t = cases[k].t0 + (double)i * min_step;
            if (ratio_at(cases[k].kind, cases[k].t_star, t) > 1.0) {
                brute = t;
                break;
            }
        }
        ratio_ctx c = {cases[k].kind, cases[k].t_star, 0, 0, 0};
        fs_event_result r;
        CHECK(fs_event_find(ratio_fn, &c, cases[k].t0, cases[k].dt, t_end, min_step, &r) == 0);
        CHECK_MSG(r.found && brute > 0 && fabs(r.t - brute) <= min_step,
                  "case %zu: adaptive %.9g, brute force %.9g", k, r.t, brute);
        CHECK(r.evaluations < 40);
    }
}

/* A model for fs_event_find_estimated: the exact ratio is ratio_at (kind 3: affine, t / t_star), the
 * estimate blends the exact values at the bracket's ends linearly, as the wedge model blends
 * equilibria. */
typedef struct {
    ratio_ctx exact;
    double lo_t, lo_v, hi_t, hi_v;
    int exact_calls;
} blend_ctx;

static double blend_exact(void *ctx, double t)
{
    blend_ctx *b = ctx;
    b->exact_calls++;
    double v = b->exact.kind == 3 ? t / b->exact.t_star : ratio_fn(&b->exact, t);
    if (v > 1.0)
        b->hi_t = t, b->hi_v = v;
    else
        b->lo_t = t, b->lo_v = v;
    return v;
}

static double blend_estimate(void *ctx, double t)
{
    blend_ctx *b = ctx;
    CHECK(b->lo_t <= t && t <= b->hi_t);
    return b->lo_v + (t - b->lo_t) / (b->hi_t - b->lo_t) * (b->hi_v - b->lo_v);
}

/* The estimated search finds what a brute-force scan finds, within min_step, whether the blend is
 * exact (affine ratio: then with at most two exact calls after the forward steps) or not. */
static void test_event_estimated(void)
{
    static const struct { int kind; double t_star, t0, dt; } cases[] = {
        {3, 0.7, 0.0, 0.01}, {3, 2.5, 1.0, 0.3}, {0, 0.7, 0.0, 0.01}, {0, 3.3, 1.0, 0.05},
        {1, 2.45, 2.0, 0.01}, {1, 5.0, 2.0, 0.3}, {2, 0.0, 0.0, 0.05}, {2, 0.0, 0.5, 0.001},
    };
    const double min_step = 1e-4, t_end = 20.0;
    const fs_event_fns fns = {blend_exact, blend_estimate};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        double brute = -1.0;
        int forward_steps = 0;
        for (double dt = cases[k].dt, t = cases[k].t0; t < t_end; t += dt, dt *= 2.0)
            forward_steps++;
        for (long i = 1; cases[k].t0 + (double)i * min_step <= t_end; i++) {
            double t = cases[k].t0 + (double)i * min_step;
            double v = cases[k].kind == 3 ? t / cases[k].t_star : ratio_at(cases[k].kind, cases[k].t_star, t);
            if (v > 1.0) {
                brute = t;
                break;
            }
        }
        blend_ctx b = {{cases[k].kind, cases[k].t_star, 0, 0, 0}, cases[k].t0, 0.0, t_end, 0.0, 0};
        b.lo_v = cases[k].kind == 3 ? cases[k].t0 / cases[k].t_star : ratio_at(cases[k].kind, cases[k].t_star, cases[k].t0);
        fs_event_result r;
        int last_exact;
        CHECK(fs_event_find_estimated(&fns, &b, cases[k].t0, cases[k].dt, t_end, min_step, &r, &last_exact) == 0);
        CHECK_MSG(r.found && brute > 0 && fabs(r.t - brute) <= min_step,
                  "case %zu: estimated %.9g, brute force %.9g", k, r.t, brute);
        double exact_v = cases[k].kind == 3 ? r.t / cases[k].t_star : ratio_at(cases[k].kind, cases[k].t_star, r.t);
        CHECK(r.ratio == exact_v && r.ratio > 1.0);
        CHECK(r.t - r.t_before < min_step);
        if (cases[k].kind == 3)
            CHECK_MSG(b.exact_calls <= forward_steps + 2, "case %zu: %d exact calls", k, b.exact_calls);
        CHECK_MSG(b.exact_calls < 40, "case %zu: %d exact calls", k, b.exact_calls);
    }
}

static void test_event_errors(void)
{
    ratio_ctx c = {0, 0.7, 0, 0, 0};
    fs_event_result r;
    fs_error_clear();
    CHECK(fs_event_find(ratio_fn, &c, 1.0, 0.1, 0.5, 1e-3, &r) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    fs_error_clear();
    CHECK(fs_event_find(ratio_fn, &c, 0.0, 0.1, 1.0, 0.0, &r) == -1);
    CHECK(fs_event_find(ratio_fn, &c, 0.0, -1.0, 1.0, 1e-3, &r) == -1);
    CHECK(fs_event_find(ratio_fn, &c, 0.0, 0.1, NAN, 1e-3, &r) == -1);
    CHECK(c.calls == 0);
    fs_error_clear();
    /* A failing callback stops the search and its message is kept. */
    ratio_ctx bad = {0, 0.7, 0, 0, 9};
    CHECK(fs_event_find(ratio_fn, &bad, 0.0, 0.01, 10.0, 1e-6, &r) == -1);
    CHECK(bad.calls == 9 && r.evaluations == 9);
    CHECK(strcmp(fs_error_message(), "test: equilibrium failed") == 0);
    fs_error_clear();
}

/* ---- nodal planes and the separation tensor ---- */

/* The nodal mean of two stresses, and its principal plane: sigma_xx 1 and 3 average to 2, normal x. */
static void test_nodal_principal_plane(void)
{
    fs_nodal_stress mean = {{0.0}, 0};
    double s[6];
    CHECK(!fs_nodal_stress_mean(&mean, s) && s[0] == 0.0);
    const double a[6] = {1, 0, 0, 0, 0, 0}, b[6] = {3, -1, 0, 0, 0, 0};
    fs_nodal_stress_add(&mean, a);
    fs_nodal_stress_add(&mean, b);
    CHECK(fs_nodal_stress_mean(&mean, s) && mean.count == 2);
    CHECK(s[0] == 2.0 && s[1] == -0.5 && s[2] == 0.0);
    double sigma1, n[3];
    CHECK(fs_nodal_principal_plane(s, &sigma1, n) == 0);
    CHECK(sigma1 == 2.0 && n[0] == 1.0 && n[1] == 0.0 && n[2] == 0.0);
    /* pure shear tau_xy = 1: sigma1 = 1 on the plane normal to (1, 1, 0) / sqrt 2 */
    const double shear[6] = {0, 0, 0, 1, 0, 0};
    CHECK(fs_nodal_principal_plane(shear, &sigma1, n) == 0);
    CHECK_NEAR(sigma1, 1.0, 1e-15);
    CHECK_NEAR(n[0], sqrt(0.5), 1e-15);
    CHECK_NEAR(n[1], sqrt(0.5), 1e-15);
    const double bad[6] = {NAN, 0, 0, 0, 0, 0};
    fs_error_clear();
    CHECK(fs_nodal_principal_plane(bad, &sigma1, NULL) == -1 && fs_error_domain() == FS_ERR_INTERNAL);
    fs_error_clear();
}

/* The near-tip field of a crack along -x with its tip at the origin (Williams; tensor shears, z = 0)
 * for stress intensities ki (opening) and kii (sliding), at polar (r, theta). */
static void tip_field(double r, double theta, double ki, double kii, double s[6])
{
    double c = 1.0 / sqrt(2.0 * FS_PI * r), h = theta / 2.0, t3 = 1.5 * theta;
    s[0] = c * (ki * cos(h) * (1.0 - sin(h) * sin(t3)) - kii * sin(h) * (2.0 + cos(h) * cos(t3)));
    s[1] = c * (ki * cos(h) * (1.0 + sin(h) * sin(t3)) + kii * sin(h) * cos(h) * cos(t3));
    s[3] = c * (ki * cos(h) * sin(h) * cos(t3) + kii * cos(h) * (1.0 - sin(h) * sin(t3)));
    s[2] = s[4] = s[5] = 0.0;
}

/* The angle (radians, from +x) a crack arriving along +x turns to under the tip stress averaged over
 * the tip field on a polar grid, with the unloaded walls' stress along the crack behind the tip. */
static double tip_turn(double ki, double kii)
{
    const double ahead[3] = {2.0, 0.0, 0.0}; /* any length */
    fs_tip_stress avg;
    fs_tip_stress_begin(&avg, ahead, NULL, 1.0);
    for (int i = 1; i <= 200; i++)
        for (int j = 0; j < 72; j++) {
            double r = 0.02 * i, theta = -FS_PI + (j + 0.5) * (2.0 * FS_PI / 72.0), s[6];
            double at[3] = {r * cos(theta), r * sin(theta), 0.0};
            if (fabs(theta) < FS_PI / 2.0)
                tip_field(r, theta, ki, kii, s);
            else /* the walls behind the tip: stress along the crack only */
                for (int k = 0; k < 6; k++)
                    s[k] = k == 0 ? 50.0 : 0.0;
            fs_tip_stress_add(&avg, at, NULL, r, s);
        }
    double mean[6], sigma1, m[3];
    CHECK(fs_tip_stress_mean(&avg, mean));
    CHECK(fs_nodal_principal_plane(mean, &sigma1, m) == 0 && sigma1 > 0.0);
    double turn = atan2(m[1], m[0]) - FS_PI / 2.0; /* the crack runs normal to m */
    return turn < -FS_PI / 2.0 ? turn + FS_PI : turn;
}

/* The tip stress steers as fracture mechanics says: under pure opening (mode I) the crack runs
 * straight on, whatever the walls behind the tip carry; with a sliding part (mode II) it turns to the
 * side the maximum hoop stress criterion turns it to, by a little less (the average of the field
 * ahead lags its maximum: 0.55 to 0.65 of the criterion's angle for K_II / K_I from 0.1 to 0.5). Samples
 * behind the tip, beyond 3 radii or without size do not count; no sample gives no mean. */
static void test_tip_stress(void)
{
    CHECK_NEAR(tip_turn(1.0, 0.0), 0.0, 1e-6); /* the grid's rounding */
    for (double q = 0.1; q < 0.6; q += 0.2) {
        double mts = 2.0 * atan((1.0 - sqrt(1.0 + 8.0 * q * q)) / (4.0 * q)), turn = tip_turn(1.0, q);
        CHECK(turn < 0.0 && mts < 0.0);
        CHECK(turn / mts > 0.5 && turn / mts < 0.75);
    }
    fs_tip_stress avg;
    const double ahead[3] = {0.0, 1.0, 0.0}, s[6] = {1, 2, 3, 4, 5, 6};
    double mean[6];
    fs_tip_stress_begin(&avg, ahead, NULL, 0.5);
    CHECK(!fs_tip_stress_mean(&avg, mean) && mean[0] == 0.0);
    const double behind[3] = {0.0, -0.1, 0.0}, beside[3] = {1.0, 0.0, 0.0}, far[3] = {0.0, 1.6, 0.0};
    const double near[3] = {0.0, 0.2, 0.0};
    fs_tip_stress_add(&avg, behind, NULL, 1.0, s);
    fs_tip_stress_add(&avg, beside, NULL, 1.0, s);
    fs_tip_stress_add(&avg, far, NULL, 1.0, s);
    fs_tip_stress_add(&avg, near, NULL, 0.0, s);
    CHECK(!fs_tip_stress_mean(&avg, mean));
    fs_tip_stress_add(&avg, near, NULL, 2.0, s);
    CHECK(fs_tip_stress_mean(&avg, mean));
    for (int k = 0; k < 6; k++)
        CHECK_NEAR(mean[k], s[k], 1e-15);
}

/* On a curved layer a sample's stress is turned into the tip's tangent plane: tension along the
 * sample's own tangent y' = (0, cos 30, sin 30), on a face tilted 30 degrees about x, pulls along y
 * at a tip whose normal is z, and the plane is across the layer (no z in it); untilted it would
 * lean half out of the layer. A sample 60 degrees off or more does not count, and the mean is
 * projected onto the tangent plane. */
static void test_tip_stress_surface(void)
{
    const double ahead[3] = {1.0, 0.0, 0.0}, tip_normal[3] = {0.0, 0.0, 1.0}, at[3] = {0.5, 0.0, 0.0};
    double c = cos(FS_PI / 6.0), sn = sin(FS_PI / 6.0);
    const double tilted[3] = {0.0, -sn, c}, y1[3] = {0.0, c, sn};
    const double s[6] = {0.0, y1[1] * y1[1], y1[2] * y1[2], 0.0, y1[1] * y1[2], 0.0};
    fs_tip_stress avg;
    double mean[6], sigma1, m[3];
    fs_tip_stress_begin(&avg, ahead, tip_normal, 1.0);
    fs_tip_stress_add(&avg, at, tilted, 1.0, s);
    CHECK(fs_tip_stress_mean(&avg, mean));
    CHECK(fs_nodal_principal_plane(mean, &sigma1, m) == 0);
    CHECK_NEAR(sigma1, 1.0, 1e-12);
    CHECK_NEAR(fabs(m[1]), 1.0, 1e-12);
    CHECK_NEAR(m[2], 0.0, 1e-12);
    const double steep[3] = {0.0, -sin(FS_PI / 2.8), cos(FS_PI / 2.8)}; /* 64 degrees */
    fs_tip_stress_begin(&avg, ahead, tip_normal, 1.0);
    fs_tip_stress_add(&avg, at, steep, 1.0, s);
    CHECK(!fs_tip_stress_mean(&avg, mean));
    /* the normal's share is projected out: sigma_zz and the z shears vanish */
    const double full[6] = {1, 2, 3, 4, 5, 6};
    fs_tip_stress_add(&avg, at, NULL, 1.0, full);
    CHECK(fs_tip_stress_mean(&avg, mean));
    CHECK(mean[0] == 1.0 && mean[1] == 2.0 && mean[3] == 4.0);
    CHECK(mean[2] == 0.0 && mean[4] == 0.0 && mean[5] == 0.0);
}

/* Eq. 28: m(a) has eigenvalue |a| along a, 0 across it; m(0) = 0. */
/* A plane stress turned into 3-D: in the frame's own axes the components stay where they were; in a
 * tilted frame the trace is sxx + syy, the frame's normal is a principal direction with stress 0,
 * and the stress along e1 and across e1, e2 reads back sxx and sxy. */
static void test_plane_stress_voigt(void)
{
    const double ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0}, plane[3] = {3.0, -1.0, 0.5};
    double out[6];
    fs_plane_stress_voigt(ex, ey, plane, out);
    const double expect[6] = {3.0, -1.0, 0.0, 0.5, 0.0, 0.0};
    for (int k = 0; k < 6; k++)
        CHECK_NEAR(out[k], expect[k], 1e-15);
    double a = 0.7, b = 0.3;
    const double e1[3] = {cos(a), sin(a) * cos(b), sin(a) * sin(b)};
    const double e2[3] = {-sin(a), cos(a) * cos(b), cos(a) * sin(b)};
    double n[3];
    fs_cross3(n, e1, e2);
    fs_plane_stress_voigt(e1, e2, plane, out);
    double m[3][3] = {{out[0], out[3], out[5]}, {out[3], out[1], out[4]}, {out[5], out[4], out[2]}};
    CHECK_NEAR(out[0] + out[1] + out[2], plane[0] + plane[1], 1e-14);
    double mn[3], me1[3];
    for (int i = 0; i < 3; i++) {
        mn[i] = m[i][0] * n[0] + m[i][1] * n[1] + m[i][2] * n[2];
        me1[i] = m[i][0] * e1[0] + m[i][1] * e1[1] + m[i][2] * e1[2];
    }
    CHECK(fs_norm3(mn) < 1e-14);
    CHECK_NEAR(fs_dot3(me1, e1), plane[0], 1e-14);
    CHECK_NEAR(fs_dot3(me1, e2), plane[2], 1e-14);
}

static void test_separation_m(void)
{
    double z[9] = {0};
    const double a[3] = {3, 4, 0}, zero[3] = {0, 0, 0};
    fs_separation_add_m(z, a, 1.0);
    CHECK_NEAR(z[0] + z[4] + z[8], 5.0, 1e-15); /* trace |a| */
    double za[3];
    for (int i = 0; i < 3; i++)
        za[i] = z[3 * i] * a[0] + z[3 * i + 1] * a[1] + z[3 * i + 2] * a[2];
    CHECK_NEAR(za[0], 15.0, 1e-14); /* m(a) a = |a| a */
    CHECK_NEAR(za[1], 20.0, 1e-14);
    CHECK(z[2] == 0.0 && z[8] == 0.0);
    double before[9];
    memcpy(before, z, sizeof z);
    fs_separation_add_m(z, zero, 1.0);
    CHECK(same9(z, before));
}

/* Eqs. 29-30: a stress splits into its tensile and compressive parts, which add up to it. */
static void test_separation_split_stress(void)
{
    const double tension[6] = {2, 0, 0, 0, 0, 0}, compression[6] = {-3, 0, 0, 0, 0, 0};
    double p[6], q[6];
    CHECK(fs_separation_split_stress(tension, p, q) == 0);
    CHECK(p[0] == 2.0 && q[0] == 0.0);
    CHECK(fs_separation_split_stress(compression, p, q) == 0);
    CHECK(p[0] == 0.0 && q[0] == -3.0);
    /* pure shear: eigenvalues +1 along (1, 1, 0) / sqrt 2 and -1 along (1, -1, 0) / sqrt 2 */
    const double shear[6] = {0, 0, 0, 1, 0, 0};
    CHECK(fs_separation_split_stress(shear, p, q) == 0);
    CHECK_NEAR(p[0], 0.5, 1e-15);
    CHECK_NEAR(p[1], 0.5, 1e-15);
    CHECK_NEAR(p[3], 0.5, 1e-15);
    CHECK_NEAR(q[0], -0.5, 1e-15);
    CHECK_NEAR(q[1], -0.5, 1e-15);
    CHECK_NEAR(q[3], 0.5, 1e-15);
    /* random stresses: plus + minus = stress, plus has no negative and minus no positive eigenvalue */
    double worst = 0.0;
    for (uint64_t r = 0; r < 200; r++) {
        double s[6], l[3];
        for (int k = 0; k < 6; k++)
            s[k] = fs_rand_range(31, FS_RNG_TEST, 6 * r + (uint64_t)k, -5.0, 5.0);
        CHECK(fs_separation_split_stress(s, p, q) == 0);
        for (int k = 0; k < 6; k++)
            worst = fmax(worst, fabs(p[k] + q[k] - s[k]));
        CHECK(fs_eigen_principal_stress(p, l, NULL) == 0 && l[2] > -1e-12);
        CHECK(fs_eigen_principal_stress(q, l, NULL) == 0 && l[0] < 1e-12);
    }
    CHECK(worst < 1e-13);
}

/* The forces on a node shared by elements meeting it from the directions normal (outward normals
 * of the elements at the node, unit cross-section): an element under stress s pulls the node with
 * -s n. Tensile and compressive parts from the split of s. */
static void node_forces(const double s[6], const double (*normal)[3], int n, double *f_plus, double *f_minus)
{
    double p[6], q[6];
    CHECK(fs_separation_split_stress(s, p, q) == 0);
    for (int e = 0; e < n; e++) {
        const double *m = normal[e];
        const double *parts[2] = {p, q};
        double *out[2] = {f_plus + 3 * e, f_minus + 3 * e};
        for (int h = 0; h < 2; h++) {
            const double *v = parts[h];
            out[h][0] = -(v[0] * m[0] + v[3] * m[1] + v[5] * m[2]);
            out[h][1] = -(v[3] * m[0] + v[1] * m[1] + v[4] * m[2]);
            out[h][2] = -(v[5] * m[0] + v[4] * m[1] + v[2] * m[2]);
        }
    }
}

/* Eq. 32 by hand: a node between two elements of a bar along x. Uniaxial tension pulls it apart
 * along x (v+ = the stress, fracture plane normal to x); pure compression gives no positive
 * eigenvalue; a cross of four elements in tension along x and compression along y separates along
 * x only; one unbalanced force gives nothing. */
static void test_separation_tensor_cases(void)
{
    const double bar[2][3] = {{1, 0, 0}, {-1, 0, 0}};
    double fp[12], fm[12], z[9], v, n[3];
    const double tension[6] = {2, 0, 0, 0, 0, 0};
    node_forces(tension, bar, 2, fp, fm);
    CHECK(fp[0] == -2.0 && fp[3] == 2.0 && fm[0] == 0.0 && fm[3] == 0.0);
    fs_separation_tensor(fp, 2, fm, 2, z);
    const double want[9] = {2, 0, 0, 0, 0, 0, 0, 0, 0};
    CHECK(same9(z, want));
    CHECK(fs_separation_largest(z, &v, n) == 0);
    CHECK(v == 2.0 && n[0] == 1.0 && n[1] == 0.0 && n[2] == 0.0);

    const double compression[6] = {-2, 0, 0, 0, 0, 0};
    node_forces(compression, bar, 2, fp, fm);
    fs_separation_tensor(fp, 2, fm, 2, z);
    CHECK(z[0] == -2.0);
    CHECK(fs_separation_largest(z, &v, n) == 0);
    CHECK_MSG(!(v > 0.0), "compression has a tensile eigenvalue %g", v);

    const double cross[4][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    const double mixed[6] = {3, -1, 0, 0, 0, 0};
    node_forces(mixed, cross, 4, fp, fm);
    fs_separation_tensor(fp, 4, fm, 4, z);
    const double want_mixed[9] = {3, 0, 0, 0, -1, 0, 0, 0, 0};
    CHECK(same9(z, want_mixed));
    CHECK(fs_separation_largest(z, &v, n) == 0 && v == 3.0 && n[0] == 1.0);

    const double alone[3] = {0.3, -2.0, 1.0};
    fs_separation_tensor(alone, 1, NULL, 0, z);
    for (int k = 0; k < 9; k++)
        CHECK_NEAR(z[k], 0.0, 1e-15);
    fs_separation_tensor(NULL, 0, alone, 1, z);
    for (int k = 0; k < 9; k++)
        CHECK_NEAR(z[k], 0.0, 1e-15);
}

/* zeta is symmetric, and turning every force by a rotation Q turns zeta into Q zeta Q^T (the same
 * eigenvalues): the tensor does not depend on the frame. */
static void test_separation_tensor_symmetry(void)
{
    for (uint64_t trial = 0; trial < 50; trial++) {
        double fp[15], fm[9], rp[15], rm[9], q[9], z[9], zr[9];
        for (int k = 0; k < 15; k++)
            fp[k] = fs_rand_range(41, FS_RNG_TEST, 24 * trial + (uint64_t)k, -1.0, 1.0);
        for (int k = 0; k < 9; k++)
            fm[k] = fs_rand_range(41, FS_RNG_TEST, 24 * trial + 15 + (uint64_t)k, -1.0, 1.0);
        random_rotation(100 + trial, q);
        for (int f = 0; f < 8; f++) {
            const double *src = f < 5 ? fp + 3 * f : fm + 3 * (f - 5);
            double *dst = f < 5 ? rp + 3 * f : rm + 3 * (f - 5);
            for (int i = 0; i < 3; i++)
                dst[i] = q[3 * i] * src[0] + q[3 * i + 1] * src[1] + q[3 * i + 2] * src[2];
        }
        fs_separation_tensor(fp, 5, fm, 3, z);
        fs_separation_tensor(rp, 5, rm, 3, zr);
        double worst = 0.0, asym = 0.0;
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++) {
                double qzq = 0.0;
                for (int k = 0; k < 3; k++)
                    for (int l = 0; l < 3; l++)
                        qzq += q[3 * i + k] * z[3 * k + l] * q[3 * j + l];
                worst = fmax(worst, fabs(qzq - zr[3 * i + j]));
                asym = fmax(asym, fabs(z[3 * i + j] - z[3 * j + i]));
            }
        CHECK(asym == 0.0);
        CHECK_MSG(worst < 1e-13, "rotated tensor off by %g", worst);
        double v1, v2;
        CHECK(fs_separation_largest(z, &v1, NULL) == 0 && fs_separation_largest(zr, &v2, NULL) == 0);
        CHECK_NEAR(v1, v2, 1e-13);
    }
}

int main(void)
{
    RUN(test_eigen_random);
    RUN(test_eigen_prescribed);
    RUN(test_eigen_exact_cases);
    RUN(test_principal_stress);
    RUN(test_principal_bound);
    RUN(test_nodal_principal_plane);
    RUN(test_tip_stress);
    RUN(test_tip_stress_surface);
    RUN(test_plane_stress_voigt);
    RUN(test_separation_m);
    RUN(test_separation_split_stress);
    RUN(test_separation_tensor_cases);
    RUN(test_separation_tensor_symmetry);
    RUN(test_rank_largest);
    RUN(test_rank_ties);
    RUN(test_event_quadratic);
    RUN(test_event_none);
    RUN(test_event_logarithmic);
    RUN(test_event_brute_force);
    RUN(test_event_estimated);
    RUN(test_event_errors);
    return check_finish();
}
