/* Jacobi-preconditioned conjugate gradients on an upper-triangle CSC matrix: the baseline beside CHOLMOD. */
#include "solve/cg.h"

#include <math.h>

#include "base/error.h"

fs_cg_params fs_cg_params_default(void)
{
    fs_cg_params params;
    params.tolerance = 1e-8;
    params.max_iterations = 0;
    return params;
}

static double dot(int32_t n, const double *u, const double *v)
{
    double s = 0.0;
    for (int32_t i = 0; i < n; i++)
        s += u[i] * v[i];
    return s;
}

/* r = b - A x, using q as scratch; returns ||r||. */
static double true_residual(const fs_sparse_matrix *a, const double *b, const double *x, double *r, double *q)
{
    fs_sparse_matvec(a, x, q);
    for (int32_t i = 0; i < a->n; i++)
        r[i] = b[i] - q[i];
    return sqrt(dot(a->n, r, r));
}

/* z = M^-1 r with the Jacobi preconditioner; returns r'z. */
static double precondition(int32_t n, const double *inv_diag, const double *r, double *z)
{
    for (int32_t i = 0; i < n; i++)
        z[i] = inv_diag[i] * r[i];
    return dot(n, r, z);
}

/* design: textbook preconditioned CG (Hestenes–Stiefel recurrences). The recurrence residual drifts from
 * the true one in floating point, so convergence is only accepted after recomputing b - A x; if that
 * fails, the search restarts from the true residual. */
int fs_cg_solve(const fs_sparse_matrix *a, const double *b, double *x, fs_cg_params params,
                double *relative_residual)
{
    int32_t n = a->n;
    int32_t max_iterations = params.max_iterations > 0 ? params.max_iterations : n;
    double bnorm = sqrt(dot(n, b, b));
    if (relative_residual)
        *relative_residual = 0.0;
    if (bnorm == 0.0) {
        for (int32_t i = 0; i < n; i++)
            x[i] = 0.0;
        return 0;
    }

    double *scratch = fs_malloc(4 * (size_t)n * sizeof *scratch);
    double *inv_diag = scratch;
    double *r = scratch + n;
    double *z = scratch + 2 * (size_t)n;
    double *p = scratch + 3 * (size_t)n;
    double *q = z; /* A p and the residual scratch share z's storage: each is dead before z is rewritten */
    int status = -1;

    for (int32_t j = 0; j < n; j++) {
        double d = 0.0;
        for (int32_t k = a->col_ptr[j + 1] - 1; k >= a->col_ptr[j]; k--) {
            if (a->row_idx[k] == j) {
                d = a->values[k];
                break;
            }
        }
        if (!(d > 0.0)) {
            fs_error(FS_ERR_INTERNAL, "cg: diagonal entry %d is %g, not positive", j, d);
            goto done;
        }
        inv_diag[j] = 1.0 / d;
    }

    double limit = params.tolerance * bnorm;
    double rnorm = true_residual(a, b, x, r, q);
    int32_t iterations = 0;
    if (rnorm > limit) {
        double rz = precondition(n, inv_diag, r, z);
        for (int32_t i = 0; i < n; i++)
            p[i] = z[i];
        while (iterations < max_iterations) {
            fs_sparse_matvec(a, p, q);
            double curvature = dot(n, p, q);
            if (!(curvature > 0.0)) {
                fs_error(FS_ERR_INTERNAL, "cg: matrix not positive definite (p'Ap = %g at iteration %d)",
                         curvature, iterations);
                goto done;
            }
            double alpha = rz / curvature;
            for (int32_t i = 0; i < n; i++) {
                x[i] += alpha * p[i];
                r[i] -= alpha * q[i];
            }
            iterations++;
            rnorm = sqrt(dot(n, r, r));
            if (rnorm <= limit) {
                rnorm = true_residual(a, b, x, r, q);
                if (rnorm <= limit)
                    break;
                rz = precondition(n, inv_diag, r, z);
                for (int32_t i = 0; i < n; i++)
                    p[i] = z[i];
                continue;
            }
            double rz_next = precondition(n, inv_diag, r, z);
            double beta = rz_next / rz;
            rz = rz_next;
            for (int32_t i = 0; i < n; i++)
                p[i] = z[i] + beta * p[i];
        }
    }
    if (relative_residual)
        *relative_residual = rnorm / bnorm;
    if (rnorm > limit) {
        fs_error(FS_ERR_INTERNAL, "cg: no convergence after %d iterations (relative residual %.3g)", iterations,
                 rnorm / bnorm);
        goto done;
    }
    status = iterations;
done:
    free(scratch);
    return status;
}
