/* Quasi-static equilibrium of the shell: Newton's method on its energy, CHOLMOD for the steps, a backtracking line search. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"

/* Newton iterations before giving up, and line-search halvings per iteration. */
#define MAX_NEWTON 60
#define MAX_CUTS 40

void fs_shell_number_dofs(fs_shell *s)
{
    int32_t n = 0;
    for (int32_t i = 0; i < s->n_nodes; i++)
        for (int k = 0; k < 3; k++)
            s->dof[3 * (size_t)i + k] = (s->pin[i] >> k) & 1 ? -1 : n++;
    s->n_free = n;
    s->pattern_valid = false;
    s->factored = false;
    free(s->work);
    s->work = fs_malloc((2 * (size_t)n + 6 * (size_t)s->n_nodes + 1) * sizeof *s->work);
}

/* The scale of the forces: the force of a strain of 1 on one mean edge's cross-section. */
static double force_scale(const fs_shell *s)
{
    double area = 0.0, yh = 0.0;
    for (int32_t t = 0; t < s->n_tris; t++) {
        area += s->area0[t];
        yh += s->area0[t] * s->young[t] * fs_shell_tri_thickness(s, t);
    }
    if (!(area > 0.0))
        return 1.0;
    double edge = sqrt(2.0 * area / s->n_tris);
    return yh / area * edge;
}

/* Factorizes s->K, shifting its diagonal by growing multiples of its mean when it is not positive
 * definite (far from equilibrium, or under compression). Returns 0 or -1. */
static int factorize(fs_shell *s)
{
    double t0 = fs_seconds();
    if (!s->chol) {
        s->chol = fs_cholesky_analyze(&s->K);
        s->counters.analyses++;
        if (!s->chol)
            return -1;
    }
    int rc = fs_cholesky_factorize(s->chol, &s->K);
    if (rc < 0) {
        int32_t n = s->K.n;
        double mean = 0.0;
        for (int32_t j = 0; j < n; j++)
            mean += fabs(s->K.values[s->K.col_ptr[j + 1] - 1]);
        mean = n ? mean / n : 1.0;
        double shift = 1e-6 * mean, added = 0.0;
        for (int attempt = 0; attempt < 12 && rc < 0; attempt++) {
            for (int32_t j = 0; j < n; j++)
                s->K.values[s->K.col_ptr[j + 1] - 1] += shift - added;
            added = shift;
            fs_error_clear();
            rc = fs_cholesky_factorize(s->chol, &s->K);
            shift *= 10.0;
            s->counters.shifted++;
        }
    }
    s->counters.factor_seconds += fs_seconds() - t0;
    s->counters.newton_iterations++;
    return rc;
}

/* design: Newton's method with a lazily refreshed Hessian. The factor of the Hessian is kept across
 * iterations, equilibria and time steps (it only depends on the state through the small geometric
 * and stress stiffening terms of a small-strain shell) and refreshed when the residual stops falling
 * by at least RATE_REFRESH per iteration, when its step is not a descent direction or the line
 * search fails with it, and always after a change of the mesh. With a fresh factor this is Newton's
 * method; with a slightly stale one a fast linear iteration that costs a back-substitution. */
#define RATE_REFRESH 0.25

static double residual(const fs_shell *s, const double *g, double *r)
{
    double rmax = 0.0;
    for (int32_t i = 0; i < s->n_nodes; i++)
        for (int k = 0; k < 3; k++) {
            int32_t d = s->dof[3 * (size_t)i + k];
            if (d >= 0) {
                r[d] = -g[3 * (size_t)i + k];
                rmax = fmax(rmax, fabs(r[d]));
            }
        }
    return rmax;
}

int fs_shell_equilibrium(fs_shell *s)
{
    int32_t nf = s->n_free, nn = s->n_nodes;
    double *r = s->work, *p = r + nf, *trial = p + nf, *gt = trial + 3 * (size_t)nn;
    double *g = s->grad;
    double f_tol = 1e-11 * force_scale(s);
    double x_scale = 0.0;
    for (int32_t t = 0; t < s->n_tris; t++)
        x_scale += s->area0[t];
    x_scale = s->n_tris ? sqrt(2.0 * x_scale / s->n_tris) : 1.0;
    double x_tol = 1e-10 * x_scale;
    s->counters.solves++;
    double t0 = fs_seconds();
    double e = fs_shell_energy(s, s->x, g, false);
    bool refresh = !s->factored, fresh = false;
    for (int iter = 0; iter < MAX_NEWTON && isfinite(e); iter++) {
        double rmax = residual(s, g, r);
        if (rmax <= f_tol) {
            s->counters.solve_seconds += fs_seconds() - t0;
            return 0;
        }
        if (refresh) {
            s->factored = false;
            if (!isfinite(fs_shell_energy(s, s->x, NULL, true)) || factorize(s) < 0)
                break;
            s->factored = true;
            refresh = false;
            fresh = true;
        }
        if (fs_cholesky_solve(s->chol, 1, r, p) < 0)
            break;
        s->counters.back_solves++;
        double slope = 0.0, pmax = 0.0; /* -g . p */
        for (int32_t d = 0; d < nf; d++) {
            slope += r[d] * p[d];
            pmax = fmax(pmax, fabs(p[d]));
        }
        if (!(slope > 0.0)) {
            if (fresh)
                break; /* a positive definite factor always gives a descent direction */
            refresh = true;
            continue;
        }
        double alpha = 1.0, et = NAN;
        bool accepted = false;
        for (int cut = 0; cut < MAX_CUTS; cut++) {
            memcpy(trial, s->x, 3 * (size_t)nn * sizeof *trial);
            for (int32_t i = 0; i < nn; i++)
                for (int k = 0; k < 3; k++) {
                    int32_t d = s->dof[3 * (size_t)i + k];
                    if (d >= 0)
                        trial[3 * (size_t)i + k] += alpha * p[d];
                }
            et = fs_shell_energy(s, trial, gt, false);
            /* Armijo, with room for rounding once the decrease is below it */
            if (isfinite(et) && et <= e - 1e-4 * alpha * slope + 1e-12 * fabs(e)) {
                accepted = true;
                break;
            }
            alpha *= 0.5;
            s->counters.line_search_cuts++;
            if (!fresh && cut >= 1)
                break; /* a stale factor that needs cuts: refresh rather than crawl */
        }
        if (!accepted) {
            if (fresh)
                break;
            refresh = true;
            continue;
        }
        memcpy(s->x, trial, 3 * (size_t)nn * sizeof *trial);
        memcpy(g, gt, 3 * (size_t)nn * sizeof *g);
        e = et;
        if (alpha * pmax <= x_tol) {
            s->counters.solve_seconds += fs_seconds() - t0;
            return 0;
        }
        double rnew = residual(s, g, r);
        if (!fresh && (alpha < 1.0 || rnew > RATE_REFRESH * rmax))
            refresh = true;
        fresh = false;
    }
    s->counters.solve_seconds += fs_seconds() - t0;
    if (fs_error_domain() == FS_OK)
        fs_error(FS_ERR_INTERNAL, "shell: no equilibrium at t = %g (Newton's method did not converge)", s->time);
    return -1;
}
