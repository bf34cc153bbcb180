/* Jacobi-preconditioned conjugate gradients: the iterative baseline for the equilibrium solves (thesis §5.4). */
#ifndef FS_SOLVE_CG_H
#define FS_SOLVE_CG_H

#include <stdint.h>

#include "solve/sparse.h"

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
