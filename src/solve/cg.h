/* Preconditioned conjugate gradients on an operator, and the Jacobi-preconditioned matrix CG built on it: the iterative baseline for the equilibrium solves (thesis §5.4). */
#ifndef FS_SOLVE_CG_H
#define FS_SOLVE_CG_H

#include <stdbool.h>
#include <stdint.h>

#include "solve/sparse.h"

/* ---- conjugate gradients on an operator ---- */

/* How fs_pcg adds up its dot products. Both are fixed orders, so both are deterministic; they round
 * differently, so a caller keeps the one its results were made with. */
typedef enum {
    FS_CG_SUM_INTERLEAVED = 0, /* four interleaved partial sums, added pairwise at the end (the additions
                                  of one running sum would wait on each other) */
    FS_CG_SUM_SEQUENTIAL       /* one running sum in index order */
} fs_cg_sum;

/* A symmetric positive definite operator A on n unknowns, its preconditioner M^-1 and the stopping
 * rule, as callbacks on the caller's ctx. */
typedef struct {
    int32_t n;
    void (*apply)(void *ctx, const double *x, double *y);       /* y = A x (every entry written) */
    int (*precondition)(void *ctx, const double *r, double *z); /* z = M^-1 r (M symmetric positive
                                                                   definite): 0, or -1 with fs_error */
    bool (*converged)(void *ctx, const double *r);              /* whether residual r is small enough */
    void *ctx;
} fs_cg_operator;

/* How fs_pcg starts and judges convergence. */
typedef struct {
    int32_t max_iterations; /* updates of x at most (> 0) */
    fs_cg_sum sum;
    bool from_zero;         /* start from x = 0 with r = b, without a product (x's content on entry is
                               ignored); else from x as given, r = b - A x */
    bool true_residual;     /* judge convergence on b - A x: stop before the first iteration if the
                               starting residual passes, and when the recurrence's residual passes,
                               recompute r = b - A x and accept only if that passes too (else the search
                               restarts from it, p = M^-1 r); without it the recurrence's r decides */
} fs_pcg_params;

typedef enum {
    FS_PCG_CONVERGED = 0,  /* op->converged accepted the residual */
    FS_PCG_MAX_ITERATIONS, /* max_iterations done without that */
    FS_PCG_BREAKDOWN,      /* a search direction with p'Ap <= 0 (or NaN): A is not positive definite,
                              or the residual was already zero to rounding (see rz) */
    FS_PCG_FAILED          /* the preconditioner failed (its fs_error is kept) */
} fs_pcg_status;

typedef struct {
    fs_pcg_status status;
    int32_t iterations;    /* updates of x made */
    double curvature;      /* at a breakdown: the p'Ap found */
    double rz;             /* at a breakdown: r'z of the current residual (0: nothing left to reduce) */
} fs_pcg_result;

/* The caller's vectors of n doubles each for fs_pcg: on return r holds the last residual (the true
 * one after a convergence with true_residual); z, p and q are scratch. None may overlap b or x. */
typedef struct {
    double *r, *z, *p, *q;
} fs_pcg_vectors;

/* design: textbook preconditioned CG (Hestenes–Stiefel recurrences):
 *     r = b - A x, z = M^-1 r, p = z; repeat: q = A p, alpha = r'z / p'q, x += alpha p, r -= alpha q,
 *     stop if converged(r), z = M^-1 r, beta = r'z (new) / r'z (old), p = z + beta p.
 * Every vector operation runs in index order and every dot product in the order params.sum names,
 * so the iterates are the same bit for bit on every run and machine (-ffp-contract=off). The
 * recurrence residual drifts from the true one in floating point; true_residual guards against
 * that at the cost of a product per claimed convergence.
 * Solves A x = b into x. Returns the status and the iterations; never calls fs_error itself. */
fs_pcg_result fs_pcg(const fs_cg_operator *op, const double *b, double *x, const fs_pcg_params *params,
                     fs_pcg_vectors v);

/* u . v over n entries, summed as sum says (what fs_pcg's dot products are). */
double fs_cg_dot(int32_t n, const double *u, const double *v, fs_cg_sum sum);

/* ---- the matrix CG ---- */

/* Stopping rule of fs_cg_solve. */
typedef struct {
    double tolerance;       /* stop when ||b - A x|| <= tolerance ||b|| (Euclidean norms) */
    int32_t max_iterations; /* give up after this many iterations; <= 0 means n */
    int32_t block;          /* 1: Jacobi (diagonal) preconditioner; 3: the inverses of the 3x3 diagonal
                               blocks of unknowns 3k .. 3k + 2 (a node's displacement: n must be a
                               multiple of 3), which converges in fewer iterations for elasticity */
    double max_residual;    /* > 0: stop instead when no entry of b - A x exceeds this in magnitude
                               (the tolerance is then unused) */
} fs_cg_params;

/* tolerance 1e-8, max_iterations 0 (that is, n), block 1, max_residual 0. */
fs_cg_params fs_cg_params_default(void);

/* Solves A x = b for the symmetric positive definite matrix whose upper triangle a stores, by conjugate
 * gradients preconditioned with diag(A) or its 3x3 diagonal blocks (params.block). x holds the starting guess on entry (zeros, or the previous
 * step's solution) and the solution on return; b and x have a->n elements and must not overlap.
 * Convergence is judged on the true residual, recomputed when the recurrence claims convergence. If
 * relative_residual is not NULL it receives the final ||b - A x|| / ||b|| (Euclidean norms, also when
 * params.max_residual is the rule). Scratch memory ((3 + block) n doubles, and with block 3 a copy
 * of the matrix in 3x3 blocks, both triangles, for the products) is allocated per call. Returns the number of iterations (0 if the guess already satisfies the tolerance;
 * x = 0 if b = 0), or -1 with FS_ERR_INTERNAL: "cg: no convergence after N iterations (relative residual
 * r)", or when a diagonal entry or block, or a curvature p'Ap is not positive (A is not positive definite). */
int fs_cg_solve(const fs_sparse_matrix *a, const double *b, double *x, fs_cg_params params,
                double *relative_residual);

/* fs_cg_solve on the principal submatrix of a on the unknowns idx (m of them, strictly increasing;
 * b and x have m elements, x[q] the unknown idx[q]). map is scratch as in fs_sparse_matrix_principal
 * (a->n entries, all -1 on entry and on return). With params.block = 3, idx listing whole nodes (idx[3k]
 * a multiple of 3, then the next two) and a made of whole 3x3 blocks (elasticity: each node's three
 * columns list the same coupled nodes), the solver's blocks are copied straight from a, without the
 * submatrix; the result is the same bit for bit. */
int fs_cg_solve_principal(const fs_sparse_matrix *a, const int32_t *idx, int32_t m, int32_t *map, const double *b,
                          double *x, fs_cg_params params, double *relative_residual);

#endif
