/* The search in time for the next fracture event: grow the step to a bracket, then bisect (Algorithm 5). */
#ifndef FS_FRACTURE_EVENT_H
#define FS_FRACTURE_EVENT_H

/* The largest candidate ratio (stress/threshold, stretch/threshold) of the model brought to time t
 * and relaxed to equilibrium; > 1 means at least one fracture candidate. It may be expensive (one
 * equilibrium solve per call). On failure it calls fs_error and returns NaN. */
typedef double (*fs_event_fn)(void *ctx, double t);

typedef struct {
    int found;        /* 1: f > 1 at t; 0: f <= 1 at every time tried up to t_end */
    double t;         /* found: the earliest time tried with f > 1 (the bracket's right end);
                         else t_end */
    double t_before;  /* the latest time known with f <= 1 (the bracket's left end; t0 at worst) */
    double ratio;     /* f(t); NaN if f was never called (t0 == t_end) */
    double t_last;    /* time of the last call of f: the model state the callback left behind is at
                         t_last, which need not be t (re-evaluate at t when they differ) */
    int evaluations;  /* number of calls of f */
} fs_event_result;

/* design: thesis §5.6.2, Algorithm 5 (adaptive time-step control). From t0, where f(t0) <= 1 is
 * assumed and not evaluated, try t0 + dt, doubling dt after every step with no event (the thesis
 * advances "in successively larger time increments"), clamped to t_end, until f > 1 or t_end is
 * reached. Then bisect the bracket [t_before, t] until t - t_before < min_step. The answer is the right
 * end, so f(t) > 1 always holds and t is at most min_step after the true first crossing, provided f
 * crosses 1 at most once inside each forward step (an excursion above 1 shorter than the step can be
 * missed, as in the thesis). Cost: about log2((t - t0) / dt_trial) + log2(step / min_step) calls.
 *
 * dt_trial: the first step (raised to min_step if smaller); min_step: the time resolution (> 0);
 * t_end >= t0. Returns 0 with *out filled, or -1 with fs_error(FS_ERR_DATA) for bad arguments, or -1
 * with the callback's message kept if f returned NaN (then only out->evaluations and
 * out->t_last are meaningful). */
int fs_event_find(fs_event_fn f, void *ctx, double t0, double dt_trial, double t_end, double min_step,
                  fs_event_result *out);

/* design: Algorithm 5 pays one equilibrium solve for every time it tries, about ten per event when
 * it bisects to min_step. Between two equilibria of an unchanged model whose loads are affine in time
 * (linear elasticity, shrinkage between the knots of its piecewise linear functions), every state in
 * between is the linear blend of the two, so the bisection can run on blends, which cost no solve.
 * fs_event_find_estimated does that and checks the answer with exact evaluations:
 * - forward steps as fs_event_find, each an exact call;
 * - in a bracket lo < hi with f(lo) <= 1 < f(hi) (both exact), bisect `estimate` to min_step, giving
 *   [a, b] with estimate(a) <= 1 < estimate(b); evaluate exactly at b (unless b is hi) and at a
 *   (unless a is lo, or the exact value at b matched the estimate within 1e-9 relative: then the
 *   blend is exact and so is its value at a); each exact value narrows the bracket, and when the
 *   exact values confirm [a, b] the search ends;
 * - after ESTIMATED_ROUNDS rounds that did not, plain bisection with exact calls (loads far from
 *   affine).
 * The result has the guarantees of fs_event_find (f(t) > 1 exactly at the returned t; the bracket's
 * left end exactly at most 1, within min_step below it unless only estimates said so after a
 * matching exact value). Typical cost: the forward steps plus one or two exact calls.
 *
 * Contract of the callbacks: `exact` is as fs_event_fn, and the model keeps the states of its exact
 * calls: the latest one with a value <= 1 (or the state at t0, where the search starts) as the
 * bracket's left end, the latest one with a value > 1 as its right end; `estimate(ctx, t)` returns the
 * ratio of the blend of those two states at t (lo <= t <= hi), NaN on failure. The model is left in
 * whatever state the last call made; out->t_last and out->last_exact say which. */
typedef struct {
    fs_event_fn exact;
    fs_event_fn estimate;
} fs_event_fns;

int fs_event_find_estimated(const fs_event_fns *f, void *ctx, double t0, double dt_trial, double t_end,
                            double min_step, fs_event_result *out, int *last_exact);

#endif
