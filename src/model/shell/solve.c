/* Quasi-static equilibrium of the shell: Newton's method on its energy, CHOLMOD for the steps, a backtracking line search. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "solve/node_order.h"

/* Newton iterations before giving up, and line-search halvings per iteration. */
#define MAX_NEWTON 60
#define MAX_CUTS 40

void fs_shell_number_dofs(fs_shell *s)
{
    int32_t n = 0;
    for (int32_t i = 0; i < s->n_nodes; i++)
        for (int k = 0; k < 3; k++)
            s->sys.dof[3 * (size_t)i + k] = (s->pin[i] >> k) & 1 ? -1 : n++;
    s->sys.n_free = n;
    s->sys.pattern_valid = false;
    s->sys.factored = false;
}

/* Scratch for a solve of n_free unknowns. */
static double *work(fs_shell *s, int32_t n_free)
{
    size_t need = 2 * (size_t)n_free + 6 * (size_t)s->n_nodes + 1;
    if (need > s->work_size) {
        free(s->work);
        s->work = fs_malloc(need * sizeof *s->work);
        s->work_size = need;
    }
    return s->work;
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

/* design: the whole shell's system is re-analysed after every cascade of cuts, a few hundred times a
 * run, and factored only a few times per pattern: it is analysed in an order kept across the cuts
 * (solve/node_order.h), a node a cut made placed at the node it was duplicated from. */

/* fs_node_neighbours_fn of the shell: the corners of node i's ring of triangles. */
static int32_t ring_neighbours(void *ctx, int32_t i, int32_t *out, int32_t cap)
{
    const fs_mesh *m = ctx;
    int32_t n = 0;
    for (int32_t k = m->ring_start[i]; k < m->ring_start[i + 1]; k++)
        for (int c = 0; c < 3; c++, n++)
            if (n < cap)
                out[n] = m->tri[3 * (size_t)m->ring_tri[k] + c];
    return n;
}

static fs_cholesky *analyze_whole(fs_shell *s, fs_shell_system *sys)
{
    fs_node_dofs dofs = {sys->dof, 3, 0, 3, sys->n_free};
    bool fresh = false;
    fs_cholesky *c =
        fs_node_order_analyze(&s->order, &sys->K, s->n_nodes, &dofs, s->origin, ring_neighbours, s->mesh, &fresh);
    s->counters.orderings += fresh;
    return c;
}

/* Factorizes sys->K, shifting its diagonal by growing multiples of its mean when it is not positive
 * definite (far from equilibrium, or under compression). Returns 0 or -1. */
static int factorize(fs_shell *s, fs_shell_system *sys)
{
    double t0 = fs_seconds();
    if (!sys->chol) {
        /* a local relaxation's small system: AMD alone and a simplicial factor */
        sys->chol = sys == &s->sys ? analyze_whole(s, sys) : fs_cholesky_analyze_small(&sys->K);
        s->counters.analyses++;
        if (!sys->chol)
            return -1;
    }
    int rc = fs_cholesky_factorize(sys->chol, &sys->K);
    if (rc < 0) {
        fs_sparse_matrix *K = &sys->K;
        int32_t n = K->n;
        double mean = 0.0;
        for (int32_t j = 0; j < n; j++)
            mean += fabs(K->values[K->col_ptr[j + 1] - 1]);
        mean = n ? mean / n : 1.0;
        double shift = 1e-6 * mean, added = 0.0;
        for (int attempt = 0; attempt < 12 && rc < 0; attempt++) {
            for (int32_t j = 0; j < n; j++)
                K->values[K->col_ptr[j + 1] - 1] += shift - added;
            added = shift;
            fs_error_clear();
            rc = fs_cholesky_factorize(sys->chol, K);
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

static double residual(const fs_shell *s, const fs_shell_system *sys, const double *g, double *r)
{
    double rmax = 0.0;
    for (int32_t q = 0, n = fs_shell_scope_nodes(s->n_nodes, sys); q < n; q++)
        for (int k = 0, i = fs_shell_scope_node(sys, q); k < 3; k++) {
            int32_t d = sys->dof[3 * (size_t)i + k];
            if (d >= 0) {
                r[d] = -g[3 * (size_t)i + k];
                rmax = fmax(rmax, fabs(r[d]));
            }
        }
    return rmax;
}

double fs_shell_residual(fs_shell *s)
{
    double *g = s->grad;
    fs_shell_energy(s, s->x, g, false);
    double rmax = 0.0;
    for (size_t k = 0; k < 3 * (size_t)s->n_nodes; k++)
        if (s->sys.dof[k] >= 0)
            rmax = fmax(rmax, fabs(g[k]));
    return rmax;
}

int fs_shell_equilibrium(fs_shell *s)
{
    return fs_shell_solve(s, &s->sys);
}

int fs_shell_solve(fs_shell *s, fs_shell_system *sys)
{
    int32_t nf = sys->n_free, nn = s->n_nodes;
    double *r = work(s, nf), *p = r + nf, *trial = p + nf, *gt = trial + 3 * (size_t)nn;
    double *g = s->grad;
    double f_tol = 1e-11 * force_scale(s);
    double x_scale = s->unit;
    double x_tol = 1e-10 * x_scale;
    s->counters.solves++;
    double t0 = fs_seconds();
    double e = fs_shell_energy_in(s, sys, s->x, g, false);
    /* the trial positions: x, but for the scope's nodes (the only ones that move) */
    int32_t n_scope = fs_shell_scope_nodes(nn, sys);
    memcpy(trial, s->x, 3 * (size_t)nn * sizeof *trial);
    bool refresh = !sys->factored, fresh = false;
    for (int iter = 0; iter < MAX_NEWTON && isfinite(e); iter++) {
        double rmax = residual(s, sys, g, r);
        if (rmax <= f_tol) {
            s->counters.solve_seconds += fs_seconds() - t0;
            return 0;
        }
        if (refresh) {
            sys->factored = false;
            if (!isfinite(fs_shell_energy_in(s, sys, s->x, NULL, true)) || factorize(s, sys) < 0)
                break;
            sys->factored = true;
            refresh = false;
            fresh = true;
        }
        if (fs_cholesky_solve(sys->chol, 1, r, p) < 0)
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
            for (int32_t q = 0; q < n_scope; q++)
                for (int k = 0, i = fs_shell_scope_node(sys, q); k < 3; k++) {
                    size_t c = 3 * (size_t)i + k;
                    int32_t d = sys->dof[c];
                    trial[c] = d >= 0 ? s->x[c] + alpha * p[d] : s->x[c];
                }
            et = fs_shell_energy_in(s, sys, trial, gt, false);
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
        for (int32_t q = 0; q < n_scope; q++) {
            size_t i = (size_t)fs_shell_scope_node(sys, q);
            memcpy(s->x + 3 * i, trial + 3 * i, 3 * sizeof *trial);
            memcpy(g + 3 * i, gt + 3 * i, 3 * sizeof *g);
        }
        e = et;
        if (alpha * pmax <= x_tol) {
            s->counters.solve_seconds += fs_seconds() - t0;
            return 0;
        }
        double rnew = residual(s, sys, g, r);
        if (!fresh && (alpha < 1.0 || rnew > RATE_REFRESH * rmax))
            refresh = true;
        fresh = false;
    }
    s->counters.solve_seconds += fs_seconds() - t0;
    if (fs_error_domain() == FS_OK)
        fs_error(FS_ERR_INTERNAL, "shell: no equilibrium at t = %g (Newton's method did not converge)", s->time);
    return -1;
}
