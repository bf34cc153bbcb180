/* Jacobi-preconditioned conjugate gradients on an upper-triangle CSC matrix: the baseline beside CHOLMOD. */
#include "solve/cg.h"

#include <math.h>
#include <stdbool.h>

#include "base/error.h"

fs_cg_params fs_cg_params_default(void)
{
    fs_cg_params params;
    params.tolerance = 1e-8;
    params.max_iterations = 0;
    params.block = 1;
    params.max_residual = 0.0;
    return params;
}

static double dot(int32_t n, const double *u, const double *v)
{
    double s = 0.0;
    for (int32_t i = 0; i < n; i++)
        s += u[i] * v[i];
    return s;
}

static double max_abs(int32_t n, const double *v)
{
    double m = 0.0;
    for (int32_t i = 0; i < n; i++)
        m = fmax(m, fabs(v[i]));
    return m;
}

/* The stopping rule: with a max_residual, every entry of r within it, else the Euclidean norm rnorm
 * within limit. */
static bool converged(const fs_cg_params *params, int32_t n, const double *r, double rnorm, double limit)
{
    return params->max_residual > 0.0 ? max_abs(n, r) <= params->max_residual : rnorm <= limit;
}

/* r = b - A x, using q as scratch; returns ||r||. */
static double true_residual(const fs_sparse_matrix *a, const double *b, const double *x, double *r, double *q)
{
    fs_sparse_matvec(a, x, q);
    for (int32_t i = 0; i < a->n; i++)
        r[i] = b[i] - q[i];
    return sqrt(dot(a->n, r, r));
}

/* z = M^-1 r with the preconditioner inv (block 1: n inverse diagonal entries; block 3: n / 3 inverse
 * 3x3 blocks, row-major); returns r'z. */
static double precondition(int32_t n, int32_t block, const double *inv, const double *r, double *z)
{
    if (block == 3) {
        for (int32_t k = 0; k < n; k += 3) {
            const double *m = inv + 3 * (size_t)k;
            for (int i = 0; i < 3; i++)
                z[k + i] = m[3 * i] * r[k] + m[3 * i + 1] * r[k + 1] + m[3 * i + 2] * r[k + 2];
        }
    } else {
        for (int32_t i = 0; i < n; i++)
            z[i] = inv[i] * r[i];
    }
    return dot(n, r, z);
}

/* The preconditioner of fs_cg_solve (see precondition) into inv. Returns 0, or -1 with fs_error if a
 * diagonal entry or block is not positive definite. */
static int preconditioner(const fs_sparse_matrix *a, int32_t block, double *inv)
{
    int32_t n = a->n;
    if (block != 3) {
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
                return -1;
            }
            inv[j] = 1.0 / d;
        }
        return 0;
    }
    for (int32_t b0 = 0; b0 < n; b0 += 3) {
        double m[9] = {0};
        for (int32_t j = b0; j < b0 + 3; j++)
            for (int32_t k = a->col_ptr[j]; k < a->col_ptr[j + 1]; k++) {
                int32_t i = a->row_idx[k];
                if (i >= b0 && i <= j) {
                    m[3 * (i - b0) + (j - b0)] = a->values[k];
                    m[3 * (j - b0) + (i - b0)] = a->values[k];
                }
            }
        /* the inverse by cofactors; positive definite iff the leading minors are positive */
        double c00 = m[4] * m[8] - m[5] * m[7], c01 = m[5] * m[6] - m[3] * m[8], c02 = m[3] * m[7] - m[4] * m[6];
        double det = m[0] * c00 + m[1] * c01 + m[2] * c02, minor2 = m[0] * m[4] - m[1] * m[3];
        if (!(m[0] > 0.0 && minor2 > 0.0 && det > 0.0)) {
            fs_error(FS_ERR_INTERNAL, "cg: diagonal block of unknowns %d-%d is not positive definite", b0, b0 + 2);
            return -1;
        }
        double *v = inv + 3 * (size_t)b0;
        v[0] = c00 / det, v[1] = (m[2] * m[7] - m[1] * m[8]) / det, v[2] = (m[1] * m[5] - m[2] * m[4]) / det;
        v[3] = c01 / det, v[4] = (m[0] * m[8] - m[2] * m[6]) / det, v[5] = (m[2] * m[3] - m[0] * m[5]) / det;
        v[6] = c02 / det, v[7] = (m[1] * m[6] - m[0] * m[7]) / det, v[8] = minor2 / det;
    }
    return 0;
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

    int32_t block = params.block == 3 ? 3 : 1;
    FS_ASSERT(n % block == 0);
    double *scratch = fs_malloc((3 + (size_t)block) * (size_t)n * sizeof *scratch);
    double *r = scratch;
    double *z = scratch + n;
    double *p = scratch + 2 * (size_t)n;
    double *inv = scratch + 3 * (size_t)n;
    double *q = z; /* A p and the residual scratch share z's storage: each is dead before z is rewritten */
    int status = -1;
    if (preconditioner(a, block, inv) < 0)
        goto done;

    double limit = params.tolerance * bnorm;
    double rnorm = true_residual(a, b, x, r, q);
    int32_t iterations = 0;
    if (!converged(&params, n, r, rnorm, limit)) {
        double rz = precondition(n, block, inv, r, z);
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
            if (converged(&params, n, r, rnorm, limit)) {
                rnorm = true_residual(a, b, x, r, q);
                if (converged(&params, n, r, rnorm, limit))
                    break;
                rz = precondition(n, block, inv, r, z);
                for (int32_t i = 0; i < n; i++)
                    p[i] = z[i];
                continue;
            }
            double rz_next = precondition(n, block, inv, r, z);
            double beta = rz_next / rz;
            rz = rz_next;
            for (int32_t i = 0; i < n; i++)
                p[i] = z[i] + beta * p[i];
        }
    }
    if (relative_residual)
        *relative_residual = rnorm / bnorm;
    if (!converged(&params, n, r, rnorm, limit)) {
        fs_error(FS_ERR_INTERNAL, "cg: no convergence after %d iterations (relative residual %.3g)", iterations,
                 rnorm / bnorm);
        goto done;
    }
    status = iterations;
done:
    free(scratch);
    return status;
}
