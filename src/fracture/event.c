/* The next-fracture-event search in time: step doubling to a bracket, then bisection (thesis Algorithm 5). */
#include "fracture/event.h"

#include <math.h>
#include <stdbool.h>

#include "base/error.h"

/* Calls f at t and records the call; returns -1 if f failed (NaN). */
static int evaluate(fs_event_fn f, void *ctx, double t, fs_event_result *out, double *value)
{
    *value = f(ctx, t);
    out->evaluations++;
    out->t_last = t;
    if (isnan(*value)) {
        if (fs_error_domain() == FS_OK)
            fs_error(FS_ERR_INTERNAL, "fracture event search: the stress evaluation failed at t = %g", t);
        return -1;
    }
    return 0;
}

/* The forward steps of Algorithm 5 from t0 (see fs_event_find): fills out->t_before and out->ratio,
 * *hi with the first time tried with f > 1 (or the last time tried). Returns 1 if f > 1 there, 0 if
 * not (out->t = t_end), -1 on failure. */
static int forward(fs_event_fn f, void *ctx, double t0, double dt_trial, double t_end, double min_step,
                   fs_event_result *out, double *hi_out)
{
    out->found = 0;
    out->t = t_end;
    out->t_before = t0;
    out->ratio = NAN;
    out->t_last = t0;
    out->evaluations = 0;
    if (!f || !isfinite(t0) || !isfinite(t_end) || !(t_end >= t0) || !isfinite(dt_trial) ||
        !(dt_trial > 0.0) || !isfinite(min_step) || !(min_step > 0.0)) {
        fs_error(FS_ERR_DATA, "fracture event search: need t_end >= t0 and positive steps "
                 "(t0 = %g, t_end = %g, trial step = %g, min_step = %g)", t0, t_end, dt_trial, min_step);
        return -1;
    }
    /* Grow the step until the ratio passes 1 or the end is reached. */
    double lo = t0, dt = dt_trial < min_step ? min_step : dt_trial, hi = t0, value = NAN;
    while (lo < t_end) {
        hi = lo + dt >= t_end ? t_end : lo + dt;
        if (hi <= lo) { /* the step is below the resolution of t: grow it without calling f */
            dt *= 2.0;
            continue;
        }
        if (evaluate(f, ctx, hi, out, &value) < 0)
            return -1;
        if (value > 1.0)
            break;
        lo = hi;
        dt *= 2.0;
    }
    out->ratio = value;
    out->t_before = lo;
    *hi_out = hi;
    return value > 1.0;
}

int fs_event_find(fs_event_fn f, void *ctx, double t0, double dt_trial, double t_end, double min_step,
                  fs_event_result *out)
{
    double hi, lo, value;
    int rc = forward(f, ctx, t0, dt_trial, t_end, min_step, out, &hi);
    if (rc <= 0)
        return rc;
    lo = out->t_before;
    value = out->ratio;
    /* Bisect: keep f(lo) <= 1 < f(hi). */
    double hi_value = value;
    while (hi - lo >= min_step) {
        double mid = lo + 0.5 * (hi - lo);
        if (mid <= lo || mid >= hi)
            break; /* the bracket is down to adjacent doubles */
        if (evaluate(f, ctx, mid, out, &value) < 0)
            return -1;
        if (value > 1.0) {
            hi = mid;
            hi_value = value;
        } else {
            lo = mid;
        }
    }
    out->found = 1;
    out->t = hi;
    out->t_before = lo;
    out->ratio = hi_value;
    return 0;
}

/* Rounds of estimated bisection before plain bisection takes over. */
#define ESTIMATED_ROUNDS 4

/* Calls the estimate at t and records the call; returns -1 if it failed (NaN). */
static int estimate(const fs_event_fns *f, void *ctx, double t, fs_event_result *out, int *last_exact,
                    double *value)
{
    *value = f->estimate(ctx, t);
    out->evaluations++;
    out->t_last = t;
    *last_exact = 0;
    if (isnan(*value)) {
        if (fs_error_domain() == FS_OK)
            fs_error(FS_ERR_INTERNAL, "fracture event search: the stress estimate failed at t = %g", t);
        return -1;
    }
    return 0;
}

int fs_event_find_estimated(const fs_event_fns *f, void *ctx, double t0, double dt_trial, double t_end,
                            double min_step, fs_event_result *out, int *last_exact)
{
    *last_exact = 1;
    if (!f || !f->exact || !f->estimate) {
        fs_error(FS_ERR_DATA, "fracture event search: missing callback");
        return -1;
    }
    double lo, hi, hi_value, value, est;
    int rc = forward(f->exact, ctx, t0, dt_trial, t_end, min_step, out, &hi);
    if (rc <= 0)
        return rc;
    lo = out->t_before;
    hi_value = out->ratio;
    for (int round = 0; hi - lo >= min_step; round++) {
        double a = lo, b = hi;
        if (round >= ESTIMATED_ROUNDS) { /* plain bisection */
            a = lo + 0.5 * (hi - lo);
            if (a <= lo || a >= hi)
                break;
            if (evaluate(f->exact, ctx, a, out, &value) < 0)
                return -1;
            *last_exact = 1;
            if (value > 1.0) {
                hi = a;
                hi_value = value;
            } else {
                lo = a;
            }
            continue;
        }
        while (b - a >= min_step) {
            double mid = a + 0.5 * (b - a);
            if (mid <= a || mid >= b)
                break;
            if (estimate(f, ctx, mid, out, last_exact, &value) < 0)
                return -1;
            if (value > 1.0)
                b = mid;
            else
                a = mid;
        }
        bool matched = false;
        if (b < hi) {
            if (estimate(f, ctx, b, out, last_exact, &est) < 0 || evaluate(f->exact, ctx, b, out, &value) < 0)
                return -1;
            *last_exact = 1;
            if (!(value > 1.0)) {
                lo = b;
                continue;
            }
            hi = b;
            hi_value = value;
            matched = fabs(value - est) <= 1e-9 * fabs(value);
        }
        if (a > lo && !matched) {
            if (evaluate(f->exact, ctx, a, out, &value) < 0)
                return -1;
            *last_exact = 1;
            if (value > 1.0) {
                hi = a;
                hi_value = value;
                continue;
            }
        }
        lo = a;
        break;
    }
    out->found = 1;
    out->t = hi;
    out->t_before = lo;
    out->ratio = hi_value;
    return 0;
}
