/* Tests of the 1-D mass-spring model: the discrete chain against the analytic shear-lag solution. */
#include <math.h>
#include <stdint.h>
#include <string.h>

#include "base/error.h"
#include "check.h"
#include "model/springs/springs1d.h"

/* The refinement levels of the convergence tests: 10, 20, 40, 80, 160 springs. The spring count is
 * even, so the bar's centre is a mass and the first crack lands half a spacing off the centre. */
static const int32_t levels[] = {11, 21, 41, 81, 161};
#define LEVELS ((int)(sizeof levels / sizeof levels[0]))

/* The thesis' form of the type-I solution (Eq. A.6 with the constants of Eq. A.11), for a segment
 * [0, l0] whose end anchors are at a0 and an: the strain p'(x) - 1. */
static double thesis_strain(double a0, double an, double l0, double r, double x)
{
    double d = an - a0 - l0;
    double c1 = -d / (r * l0);
    double c2 = d * (exp(r * l0) - 1.0) / (r * l0 * (exp(r * l0) + 1.0));
    return (an - a0) / l0 + c1 * r * cosh(r * x) + c2 * r * sinh(r * x) - 1.0;
}

/* Largest |force imbalance| over the masses: left and right material spring forces (EA times the
 * strain) and the anchor force (anchor stiffness times the slip), relative to the scale EA eps_b.
 * The strain is formed from the slips, length / h - 1 = eps_b + (w_{j+1} - w_j) / h, not from the
 * positions, whose rounding (1e-16 L) would swamp a 1e-12 check of forces ~EA eps_b on springs of
 * length h. */
static double balance_residual(const fs_springs1d *s)
{
    const fs_springs1d_params *p = &s->params;
    int32_t n = s->masses;
    double h = s->spacing, eps = p->strain_rate * s->time, worst = 0.0;
    for (int32_t i = 0; i < n; i++) {
        double force = 0.0;
        if (i > 0 && !s->broken[i - 1])
            force -= p->material_stiffness * (eps + (s->slip[i] - s->slip[i - 1]) / h);
        if (i < n - 1 && !s->broken[i])
            force += p->material_stiffness * (eps + (s->slip[i + 1] - s->slip[i]) / h);
        double c = p->anchor_stiffness * h * ((i == 0 || i == n - 1) ? 0.5 : 1.0);
        force -= c * s->slip[i];
        worst = fmax(worst, fabs(force));
    }
    return worst / (p->material_stiffness * fabs(eps));
}

/* The positions agree with the slips: position = anchor point + slip, to rounding of the positions. */
static double position_mismatch(const fs_springs1d *s)
{
    double worst = 0.0, stretch = 1.0 + s->params.strain_rate * s->time;
    for (int32_t i = 0; i < s->masses; i++)
        worst = fmax(worst, fabs(fs_springs1d_position(s, i) - (i * s->spacing * stretch + s->slip[i])));
    return worst;
}

/* The analytic solution is the thesis' Eq. A.6/A.11 rewritten about the segment centre, it solves
 * EA u'' = k (u - eps_b x), and it is force-free at the ends and largest at the centre. */
static void test_analytic_solution(void)
{
    double ea = 2.5, k = 0.4, lambda = sqrt(ea / k), eps = 0.03, l = 7.0;
    double worst = 0.0;
    for (int m = 0; m <= 20; m++) {
        double x = l * m / 20.0;
        double mine = fs_springs1d_analytic_strain(eps, lambda, l, x - 0.5 * l);
        double thesis = thesis_strain(1.5, 1.5 + l * (1.0 + eps), l, 1.0 / lambda, x);
        worst = fmax(worst, fabs(mine - thesis));
    }
    CHECK_MSG(worst < 1e-14, "analytic strain differs from the thesis form by %g", worst);

    CHECK_NEAR(fs_springs1d_analytic_strain(eps, lambda, l, -0.5 * l), 0.0, 1e-15);
    CHECK_NEAR(fs_springs1d_analytic_strain(eps, lambda, l, 0.5 * l), 0.0, 1e-15);
    double centre = fs_springs1d_analytic_strain(eps, lambda, l, 0.0);
    CHECK_NEAR(centre, eps * (1.0 - 1.0 / cosh(0.5 * l / lambda)), 1e-16);
    for (int m = 1; m < 10; m++)
        CHECK(fs_springs1d_analytic_strain(eps, lambda, l, 0.05 * l * m) < centre);

    /* The ODE: the strain is u', so EA strain' = k (u - eps x) and, differentiating once more,
     * EA strain'' = k (strain - eps). Checked by central differences at interior points. */
    double dx = 1e-3, ode = 0.0;
    for (int m = -8; m <= 8; m++) {
        double s = 0.05 * l * m;
        double e0 = fs_springs1d_analytic_strain(eps, lambda, l, s);
        double em = fs_springs1d_analytic_strain(eps, lambda, l, s - dx);
        double ep = fs_springs1d_analytic_strain(eps, lambda, l, s + dx);
        ode = fmax(ode, fabs(ea * (ep - 2.0 * e0 + em) / (dx * dx) - k * (e0 - eps)));
    }
    CHECK_MSG(ode < 1e-6 * k * eps, "ODE residual %g", ode);
}

/* The analytic crack times: the centre strain meets the threshold then; the halving hierarchy comes
 * later for each generation, with cracks at the centres of the pieces. */
static void test_analytic_cracks(void)
{
    fs_springs1d_params p = fs_springs1d_params_default();
    double lambda = fs_springs1d_decay_length(&p);
    CHECK_NEAR(lambda, 1.0, 1e-15);
    fs_springs1d_break first = fs_springs1d_analytic_first_crack(&p);
    CHECK_NEAR(first.x, 5.0, 0.0);
    CHECK_NEAR(fs_springs1d_analytic_strain(p.strain_rate * first.time, lambda, p.length, 0.0),
               p.threshold_strain, 1e-15);
    CHECK_NEAR(first.time, 0.01 / (1.0 - 1.0 / cosh(5.0)), 1e-15);

    fs_springs1d_break cracks[15];
    CHECK(fs_springs1d_analytic_cracks(&p, 4, cracks) == 15);
    CHECK(cracks[0].time == first.time && cracks[0].x == first.x);
    for (int32_t g = 0, c = 0; g < 4; g++) {
        int32_t pieces = (int32_t)1 << g;
        double l = p.length / pieces;
        for (int32_t m = 0; m < pieces; m++, c++) {
            CHECK_NEAR(cracks[c].x, (m + 0.5) * l, 1e-14);
            CHECK_NEAR(fs_springs1d_analytic_strain(p.strain_rate * cracks[c].time, lambda, l, 0.0),
                       p.threshold_strain, 1e-15);
            if (c > 0)
                CHECK(cracks[c].time >= cracks[c - 1].time);
            if (m == 0 && g > 0)
                CHECK(cracks[c].time > cracks[c - 1].time);
        }
    }
    /* Each piece, at the moment it is born, is below its own threshold: no cascade. */
    for (int32_t g = 1; g < 4; g++) {
        double born = cracks[((int32_t)1 << (g - 1)) - 1].time;
        double l = p.length / ((int32_t)1 << g);
        CHECK(fs_springs1d_analytic_strain(p.strain_rate * born, lambda, l, 0.0) < p.threshold_strain);
    }
    CHECK(fs_springs1d_analytic_cracks(&p, 31, cracks) == -1);

    p.strain_rate = -1.0;
    CHECK(isinf(fs_springs1d_analytic_crack_time(&p, 5.0)));
    p.strain_rate = 1.0;
    double tiny = fs_springs1d_analytic_crack_time(&p, 1e-3);
    CHECK(isfinite(tiny) && tiny > 1e3);
}

/* Before any crack, the discrete spring strains converge to the analytic strain at the spring
 * midpoints (relative to eps_b). The error is largest at the free ends and falls by 2.5, 3.3, 3.6,
 * 3.8 over the levels, towards the factor 4 of a second-order scheme; checked as > 2.2 per level. */
static void test_equilibrium_converges(void)
{
    double prev = INFINITY;
    for (int lv = 0; lv < LEVELS; lv++) {
        fs_springs1d_params p = fs_springs1d_params_default();
        p.masses = levels[lv];
        fs_springs1d s;
        CHECK(fs_springs1d_init(&s, &p) == 0);
        double t = 0.5 * fs_springs1d_analytic_first_crack(&p).time;
        double max = fs_springs1d_equilibrate(&s, t);
        CHECK(max > 0.4 && max < 0.6);
        double eps = p.strain_rate * t, err = 0.0;
        for (int32_t j = 0; j < s.masses - 1; j++) {
            double mid = (j + 0.5) * s.spacing - 0.5 * p.length;
            err = fmax(err, fabs(fs_springs1d_spring_strain(&s, j) -
                                 fs_springs1d_analytic_strain(eps, 1.0, p.length, mid)));
        }
        err /= eps;
        CHECK_MSG(err < prev, "n = %d: strain error %g, previous level %g", (int)p.masses, err, prev);
        if (lv > 0)
            CHECK_MSG(err < 0.45 * prev, "n = %d: strain error %g did not shrink like h^2 (previous %g)",
                      (int)p.masses, err, prev);
        CHECK_MSG(balance_residual(&s) < 1e-12, "n = %d: residual %g", (int)p.masses, balance_residual(&s));
        prev = err;
        fs_springs1d_free(&s);
    }
    CHECK_MSG(prev < 1e-3, "finest strain error %g", prev);
}

/* Runs the default bar with n masses through the first two generations of cracks. */
static void run_chain(int32_t n, fs_springs1d *s)
{
    fs_springs1d_params p = fs_springs1d_params_default();
    p.masses = n;
    fs_springs1d_break cracks[3];
    fs_springs1d_analytic_cracks(&p, 2, cracks);
    CHECK(fs_springs1d_init(s, &p) == 0);
    /* The third generation starts at about 0.0213, well after this. */
    CHECK(fs_springs1d_run(s, 1.5 * cracks[2].time) == 0);
}

/* The first crack's time and position converge to the analytic ones at its centre, the error
 * shrinking at every level. The time error falls like h^2 (2.8e-3, 7.1e-4, 1.8e-4, 4.4e-5, 1.1e-5);
 * the position error is h / 2, since the centre is a mass and the crack opens in a spring next to it.
 * The finest is checked within 0.01 % in time. */
static void test_first_crack_converges(void)
{
    fs_springs1d_params p = fs_springs1d_params_default();
    fs_springs1d_break exact = fs_springs1d_analytic_first_crack(&p);
    double prev_t = INFINITY, prev_x = INFINITY;
    for (int lv = 0; lv < LEVELS; lv++) {
        fs_springs1d s;
        run_chain(levels[lv], &s);
        CHECK(s.break_count >= 1);
        if (s.break_count >= 1) {
            double et = fabs(s.breaks[0].time - exact.time) / exact.time;
            double ex = fabs(s.breaks[0].x - exact.x);
            CHECK_MSG(et < prev_t, "n = %d: time error %g, previous level %g", (int)levels[lv], et, prev_t);
            CHECK_MSG(ex < prev_x, "n = %d: position error %g, previous level %g", (int)levels[lv], ex, prev_x);
            CHECK_NEAR(ex, 0.5 * s.spacing, 1e-12);
            prev_t = et;
            prev_x = ex;
        }
        fs_springs1d_free(&s);
    }
    CHECK_MSG(prev_t < 1e-4, "finest first-crack time error %g", prev_t);
    CHECK_MSG(prev_x < 0.05, "finest first-crack position error %g", prev_x);
}

/* The second generation: at the finest level the two halves crack at their own centres, within
 * 0.5 % of the analytic halving time (measured 0.3 %). The first crack sits h / 2 off the centre, so
 * the halves differ by h and that error is first order; against the analytic time of each actual
 * piece the agreement is second order (measured 5.5e-5), checked within 0.02 %. */
static void test_second_generation(void)
{
    fs_springs1d s;
    run_chain(levels[LEVELS - 1], &s);
    fs_springs1d_break exact[3];
    fs_springs1d_analytic_cracks(&s.params, 2, exact);
    CHECK(s.break_count == 3);
    if (s.break_count == 3) {
        double cut = s.breaks[0].x, h = s.spacing;
        for (int c = 1; c < 3; c++) {
            const fs_springs1d_break *b = &s.breaks[c];
            int left = b->x < cut;
            double lo = left ? 0.0 : cut, hi = left ? cut : s.params.length;
            double et = fabs(b->time - exact[c].time) / exact[c].time;
            CHECK_MSG(et < 5e-3, "second-generation crack at %g: time error %g", b->x, et);
            CHECK_MSG(fabs(b->x - 0.5 * (lo + hi)) <= 0.5 * h + 1e-12,
                      "crack at %g is not at the centre of its piece [%g, %g]", b->x, lo, hi);
            double own = fs_springs1d_analytic_crack_time(&s.params, hi - lo);
            CHECK_MSG(fabs(b->time - own) / own < 2e-4, "crack at %g: time %g, its piece's analytic time %g",
                      b->x, b->time, own);
        }
        /* The longer piece cracks first. */
        int first_left = s.breaks[1].x < cut;
        CHECK(first_left == (cut > 0.5 * s.params.length));
    }
    fs_springs1d_free(&s);
}

/* An odd number of springs puts a spring at the centre: the first crack is exactly at L / 2, the
 * two halves are mirror images and crack at the same instant (a cascade at one time). */
static void test_symmetric_cascade(void)
{
    fs_springs1d s;
    run_chain(80, &s);
    CHECK(s.break_count == 3);
    if (s.break_count == 3) {
        CHECK_NEAR(s.breaks[0].x, 5.0, 1e-12);
        CHECK(s.breaks[1].time == s.breaks[2].time);
        CHECK_NEAR(s.breaks[1].x + s.breaks[2].x, 10.0, 1e-12);
        CHECK(s.breaks[1].spring != s.breaks[2].spring);
    }
    fs_springs1d_free(&s);
}

/* Equilibrium after many breaks: every mass balances its springs and anchor to 1e-12 of EA eps_b;
 * nothing is NaN; the break list is in time order and each crack is at its spring's midpoint. */
static void test_balance_and_finite(void)
{
    fs_springs1d_params p = fs_springs1d_params_default();
    p.masses = 257;
    p.jitter = 0.2;
    p.seed = 7;
    fs_springs1d s;
    CHECK(fs_springs1d_init(&s, &p) == 0);
    double t_end = 0.3;
    CHECK(fs_springs1d_run(&s, t_end) == 0);
    CHECK(s.time == t_end);
    CHECK(s.break_count > 15);
    CHECK_MSG(balance_residual(&s) < 1e-12, "residual %g", balance_residual(&s));
    CHECK(position_mismatch(&s) < 1e-14 * p.length);
    int finite = 1;
    for (int32_t i = 0; i < s.masses; i++)
        finite &= isfinite(s.slip[i]) && isfinite(fs_springs1d_position(&s, i));
    for (int32_t j = 0; j < s.masses - 1; j++) {
        finite &= isfinite(fs_springs1d_spring_strain(&s, j));
        if (!s.broken[j])
            CHECK(s.ratio[j] <= 1.0);
    }
    for (int32_t c = 0; c < s.break_count; c++) {
        finite &= isfinite(s.breaks[c].time) && isfinite(s.breaks[c].x);
        CHECK(c == 0 || s.breaks[c].time >= s.breaks[c - 1].time);
        CHECK_NEAR(s.breaks[c].x, (s.breaks[c].spring + 0.5) * s.spacing, 1e-12);
    }
    CHECK(finite);
    fs_springs1d_free(&s);
}

/* With threshold jitter the run depends on the seed only: the same seed gives identical breaks, a
 * different seed a different pattern; thresholds stay within the jitter band. */
static void test_jitter_determinism(void)
{
    fs_springs1d runs[3];
    uint64_t seeds[3] = {42, 42, 43};
    for (int r = 0; r < 3; r++) {
        fs_springs1d_params p = fs_springs1d_params_default();
        p.masses = 129;
        p.jitter = 0.3;
        p.seed = seeds[r];
        CHECK(fs_springs1d_init(&runs[r], &p) == 0);
        CHECK(fs_springs1d_run(&runs[r], 0.05) == 0);
    }
    CHECK(runs[0].break_count == runs[1].break_count && runs[0].break_count > 3);
    int same = runs[0].break_count == runs[1].break_count;
    for (int32_t c = 0; same && c < runs[0].break_count; c++)
        same = runs[0].breaks[c].time == runs[1].breaks[c].time && runs[0].breaks[c].x == runs[1].breaks[c].x &&
               runs[0].breaks[c].spring == runs[1].breaks[c].spring;
    CHECK(same);
    CHECK(memcmp(runs[0].slip, runs[1].slip, (size_t)runs[0].masses * sizeof *runs[0].slip) == 0);
    int differ = runs[0].break_count != runs[2].break_count;
    for (int32_t c = 0; !differ && c < runs[0].break_count; c++)
        differ = runs[0].breaks[c].spring != runs[2].breaks[c].spring;
    CHECK(differ);
    double lo = INFINITY, hi = -INFINITY;
    for (int32_t j = 0; j < runs[0].masses - 1; j++) {
        lo = fmin(lo, runs[0].threshold[j]);
        hi = fmax(hi, runs[0].threshold[j]);
    }
    CHECK(lo >= 0.01 * 0.7 && hi < 0.01 * 1.3 && hi - lo > 0.01 * 0.3);
    for (int r = 0; r < 3; r++)
        fs_springs1d_free(&runs[r]);
}

/* A shrinking background compresses the bar: it never cracks, and its strains are negative. */
static void test_compression(void)
{
    fs_springs1d_params p = fs_springs1d_params_default();
    p.strain_rate = -1.0;
    fs_springs1d s;
    CHECK(fs_springs1d_init(&s, &p) == 0);
    CHECK(fs_springs1d_run(&s, 1.0) == 0);
    CHECK(s.break_count == 0);
    CHECK(s.time == 1.0);
    CHECK(fs_springs1d_spring_strain(&s, 50) < 0.0);
    CHECK_MSG(balance_residual(&s) < 1e-12, "residual %g", balance_residual(&s));
    fs_springs1d_free(&s);
}

/* Bad parameters and times are rejected with FS_ERR_DATA. */
static void test_bad_input(void)
{
    fs_springs1d s;
    fs_springs1d_params bad[7];
    for (int b = 0; b < 7; b++)
        bad[b] = fs_springs1d_params_default();
    bad[0].masses = 1;
    bad[1].anchor_stiffness = 0.0;
    bad[2].material_stiffness = NAN;
    bad[3].threshold_strain = -0.1;
    bad[4].jitter = 1.0;
    bad[5].length = INFINITY;
    bad[6].min_step = 0.0;
    for (int b = 0; b < 7; b++) {
        fs_error_clear();
        CHECK(fs_springs1d_init(&s, &bad[b]) == -1);
        CHECK(fs_error_domain() == FS_ERR_DATA);
        CHECK(s.slip == NULL);
        fs_springs1d_free(&s);
    }
    fs_springs1d_params p = fs_springs1d_params_default();
    CHECK(fs_springs1d_init(&s, &p) == 0);
    CHECK(fs_springs1d_run(&s, 0.001) == 0);
    fs_error_clear();
    CHECK(fs_springs1d_run(&s, 0.0) == -1);
    CHECK(fs_error_domain() == FS_ERR_DATA);
    fs_error_clear();
    CHECK(isnan(fs_springs1d_equilibrate(&s, NAN)));
    CHECK(fs_error_domain() == FS_ERR_DATA);
    fs_error_clear();
    fs_springs1d_free(&s);
}

int main(void)
{
    RUN(test_analytic_solution);
    RUN(test_analytic_cracks);
    RUN(test_equilibrium_converges);
    RUN(test_first_crack_converges);
    RUN(test_second_generation);
    RUN(test_symmetric_cascade);
    RUN(test_balance_and_finite);
    RUN(test_jitter_determinism);
    RUN(test_compression);
    RUN(test_bad_input);
    return check_finish();
}
