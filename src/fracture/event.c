/* The next-fracture-event search in time: step doubling to a bracket, then bisection (thesis Algorithm 5). */
#include "fracture/event.h"

#include <math.h>

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

int fs_event_find(fs_event_fn f, void *ctx, double t0, double dt_trial, double t_end, double min_step,
                  fs_event_result *out)
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

    /* Forward: grow the step until the ratio passes 1 or the end is reached. */
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
    if (!(value > 1.0)) {
        out->t = t_end;
        return 0;
    }

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
