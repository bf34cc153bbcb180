/* The 1-D mass-spring chain of thesis Appendix A: exact equilibria, breaks in time, analytic solution. */
#include "model/springs/springs1d.h"

#include <math.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/rng.h"
#include "fracture/event.h"
#include "fracture/rank.h"

/* Beyond this the index arithmetic (2n scratch, n - 1 springs) could overflow int32_t. */
#define SPRINGS1D_MAX_MASSES (1 << 28)

fs_springs1d_params fs_springs1d_params_default(void)
{
    fs_springs1d_params p;
    p.length = 10.0;
    p.material_stiffness = 1.0;
    p.anchor_stiffness = 1.0;
    p.strain_rate = 1.0;
    p.threshold_strain = 0.01;
    p.jitter = 0.0;
    p.masses = 101;
    p.seed = 1;
    p.min_step = 1e-12;
    return p;
}

static int positive(double v)
{
    return isfinite(v) && v > 0.0;
}

static int check_params(const fs_springs1d_params *p)
{
    if (!positive(p->length)) {
        fs_error(FS_ERR_DATA, "springs1d: length must be a positive number (got %g)", p->length);
        return -1;
    }
    if (!positive(p->material_stiffness)) {
        fs_error(FS_ERR_DATA, "springs1d: material_stiffness must be a positive number (got %g)",
                 p->material_stiffness);
        return -1;
    }
    if (!positive(p->anchor_stiffness)) {
        fs_error(FS_ERR_DATA, "springs1d: anchor_stiffness must be a positive number (got %g)",
                 p->anchor_stiffness);
        return -1;
    }
    if (!isfinite(p->strain_rate)) {
        fs_error(FS_ERR_DATA, "springs1d: strain_rate must be finite (got %g)", p->strain_rate);
        return -1;
    }
    if (!positive(p->threshold_strain)) {
        fs_error(FS_ERR_DATA, "springs1d: threshold_strain must be a positive number (got %g)",
                 p->threshold_strain);
        return -1;
    }
    if (!(p->jitter >= 0.0 && p->jitter < 1.0)) {
        fs_error(FS_ERR_DATA, "springs1d: jitter must be in [0, 1) (got %g)", p->jitter);
        return -1;
    }
    if (p->masses < 2 || p->masses > SPRINGS1D_MAX_MASSES) {
        fs_error(FS_ERR_DATA, "springs1d: masses must be in [2, %d] (got %d)", SPRINGS1D_MAX_MASSES,
                 (int)p->masses);
        return -1;
    }
    if (!positive(p->min_step)) {
        fs_error(FS_ERR_DATA, "springs1d: min_step must be a positive number (got %g)", p->min_step);
        return -1;
    }
    return 0;
}

int fs_springs1d_init(fs_springs1d *s, const fs_springs1d_params *p)
{
    memset(s, 0, sizeof *s);
    if (check_params(p) < 0)
        return -1;
    int32_t n = p->masses;
    s->params = *p;
    s->masses = n;
    s->spacing = p->length / (double)(n - 1);
    s->time = 0.0;
    s->slip = fs_calloc((size_t)n, sizeof *s->slip);
    s->threshold = fs_malloc((size_t)(n - 1) * sizeof *s->threshold);
    s->broken = fs_calloc((size_t)(n - 1), sizeof *s->broken);
    s->ratio = fs_calloc((size_t)(n - 1), sizeof *s->ratio);
    s->scratch = fs_malloc(2 * (size_t)n * sizeof *s->scratch);
    for (int32_t j = 0; j < n - 1; j++) {
        double factor = 1.0;
        if (p->jitter > 0.0)
            factor = 1.0 + p->jitter * (2.0 * fs_rand01(p->seed, FS_RNG_JITTER, (uint64_t)j) - 1.0);
        s->threshold[j] = p->threshold_strain * factor;
    }
    return 0;
}

void fs_springs1d_free(fs_springs1d *s)
{
    free(s->slip);
    free(s->threshold);
    free(s->broken);
    free(s->ratio);
    free(s->breaks);
    free(s->scratch);
    memset(s, 0, sizeof *s);
}

/* Anchor stiffness of mass i (N/cm): k h inside, k h / 2 at the two ends (thesis Eq. A.7-A.8). */
static double anchor_of(const fs_springs1d *s, int32_t i)
{
    double c = s->params.anchor_stiffness * s->spacing;
    return (i == 0 || i == s->masses - 1) ? 0.5 * c : c;
}

/* Stiffness of spring j (N/cm), 0 outside the chain or once broken. */
static double spring_of(const fs_springs1d *s, int32_t j)
{
    if (j < 0 || j >= s->masses - 1 || s->broken[j])
        return 0.0;
    return s->params.material_stiffness / s->spacing;
}

double fs_springs1d_equilibrate(fs_springs1d *s, double t)
{
    if (!isfinite(t)) {
        fs_error(FS_ERR_DATA, "springs1d: cannot bring the chain to time %g", t);
        return NAN;
    }
    /* design: with positions p_i = x_i (1 + eps_b) + w_i the balance of mass i,
     *   s_i (p_{i+1} - p_i - h) - s_{i-1} (p_i - p_{i-1} - h) - c_i w_i = 0   (thesis Eq. A.1),
     * becomes the tridiagonal system in the slips w (the anchor spring extensions)
     *   (s_{i-1} + s_i + c_i) w_i - s_{i-1} w_{i-1} - s_i w_{i+1} = eps_b h (s_i - s_{i-1}),
     * with s = EA / h for an intact spring and 0 for a broken or missing one, so the load is EA eps_b
     * pulling outwards at every free end and nothing elsewhere. Every diagonal exceeds the sum of its
     * off-diagonals by c_i > 0, so the Thomas elimination is stable without pivoting. */
    int32_t n = s->masses;
    double h = s->spacing, eps = s->params.strain_rate * t;
    double *cp = s->scratch, *dp = s->scratch + n;
    for (int32_t i = 0; i < n; i++) {
        double left = spring_of(s, i - 1), right = spring_of(s, i);
        double diag = left + right + anchor_of(s, i);
        double rhs = eps * h * (right - left);
        /* Row i: -left w_{i-1} + diag w_i - right w_{i+1} = rhs; eliminate w_{i-1}. */
        double denom = i > 0 ? diag + left * cp[i - 1] : diag;
        cp[i] = -right / denom;
        dp[i] = (i > 0 ? rhs + left * dp[i - 1] : rhs) / denom;
    }
    s->slip[n - 1] = dp[n - 1];
    for (int32_t i = n - 2; i >= 0; i--)
        s->slip[i] = dp[i] - cp[i] * s->slip[i + 1];
    s->time = t;

    double max = -INFINITY;
    for (int32_t j = 0; j < n - 1; j++) {
        if (s->broken[j]) {
            s->ratio[j] = NAN;
            continue;
        }
        s->ratio[j] = fs_springs1d_spring_strain(s, j) / s->threshold[j];
        if (s->ratio[j] > max)
            max = s->ratio[j];
    }
    return max;
}

double fs_springs1d_spring_strain(const fs_springs1d *s, int32_t j)
{
    if (s->broken[j])
        return 0.0;
    /* length / h - 1 with a(x_{j+1}) - a(x_j) = h (1 + eps_b), without forming the positions. */
    return s->params.strain_rate * s->time + (s->slip[j + 1] - s->slip[j]) / s->spacing;
}

double fs_springs1d_position(const fs_springs1d *s, int32_t i)
{
    double x = (double)i * s->spacing;
    return x * (1.0 + s->params.strain_rate * s->time) + s->slip[i];
}

/* The event search's view of the chain: its largest ratio at time t. */
static double event_ratio(void *ctx, double t)
{
    return fs_springs1d_equilibrate(ctx, t);
}

static void record_break(fs_springs1d *s, int32_t j)
{
    FS_ARRAY_RESERVE(s->breaks, s->break_capacity, s->break_count + 1, 16);
    fs_springs1d_break *b = &s->breaks[s->break_count++];
    b->time = s->time;
    b->x = ((double)j + 0.5) * s->spacing;
    b->spring = j;
    s->broken[j] = 1;
}

int fs_springs1d_run(fs_springs1d *s, double t_end)
{
    if (!isfinite(t_end) || !(t_end >= s->time)) {
        fs_error(FS_ERR_DATA, "springs1d: cannot run from time %g to %g", s->time, t_end);
        return -1;
    }
    int32_t springs = s->masses - 1;
    double max = fs_springs1d_equilibrate(s, s->time);
    for (;;) {
        if (isnan(max))
            return -1;
        if (max > 1.0) {
            int32_t j = fs_rank_pick(s->ratio, NULL, springs, s->params.seed);
            FS_ASSERT(j >= 0 && !s->broken[j]);
            record_break(s, j);
            max = fs_springs1d_equilibrate(s, s->time);
            continue;
        }
        if (s->break_count == springs || s->time >= t_end)
            break;
        /* The first trial step covers a 64th of what is left; the search doubles it from there. */
        fs_event_result ev;
        if (fs_event_find(event_ratio, s, s->time, (t_end - s->time) / 64.0, t_end, s->params.min_step,
                          &ev) < 0)
            return -1;
        if (!ev.found) {
            max = ev.t_last == t_end ? ev.ratio : fs_springs1d_equilibrate(s, t_end);
            if (isnan(max))
                return -1;
            break;
        }
        max = ev.t_last == ev.t ? ev.ratio : fs_springs1d_equilibrate(s, ev.t);
    }
    return 0;
}

double fs_springs1d_decay_length(const fs_springs1d_params *p)
{
    return sqrt(p->material_stiffness / p->anchor_stiffness);
}

double fs_springs1d_analytic_strain(double eps_b, double lambda, double l, double s)
{
    return eps_b * (1.0 - cosh(s / lambda) / cosh(0.5 * l / lambda));
}

double fs_springs1d_analytic_crack_time(const fs_springs1d_params *p, double l)
{
    double lambda = fs_springs1d_decay_length(p);
    /* 1 - 1/cosh(y) = 2 sinh^2(y/2) / cosh(y), free of cancellation for short segments. */
    double y = 0.5 * l / lambda, sh = sinh(0.5 * y);
    double relief = 2.0 * sh * sh / cosh(y);
    if (!(p->strain_rate > 0.0) || !(relief > 0.0))
        return INFINITY;
    return p->threshold_strain / (p->strain_rate * relief);
}

fs_springs1d_break fs_springs1d_analytic_first_crack(const fs_springs1d_params *p)
{
    fs_springs1d_break b;
    b.time = fs_springs1d_analytic_crack_time(p, p->length);
    b.x = 0.5 * p->length;
    b.spring = -1;
    return b;
}

int32_t fs_springs1d_analytic_cracks(const fs_springs1d_params *p, int32_t generations, fs_springs1d_break *out)
{
    if (generations < 0 || generations > 30) {
        fs_error(FS_ERR_DATA, "springs1d: analytic crack generations must be in [0, 30] (got %d)",
                 (int)generations);
        return -1;
    }
    int32_t count = 0;
    for (int32_t g = 0; g < generations; g++) {
        int32_t pieces = (int32_t)1 << g;
        double l = p->length / (double)pieces;
        double t = fs_springs1d_analytic_crack_time(p, l);
        for (int32_t m = 0; m < pieces; m++) {
            out[count].time = t;
            out[count].x = ((double)m + 0.5) * l;
            out[count].spring = -1;
            count++;
        }
    }
    return count;
}
