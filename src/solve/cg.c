/* Preconditioned conjugate gradients on an operator, and on an upper-triangle CSC matrix with a Jacobi preconditioner: the baseline beside CHOLMOD. */
#include "solve/cg.h"

#include <float.h>
#include <math.h>
#include <stdbool.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"

fs_cg_params fs_cg_params_default(void)
{
    fs_cg_params params;
    params.tolerance = 1e-8;
    params.max_iterations = 0;
    params.block = 1;
    params.max_residual = 0.0;
    return params;
}

/* u . v summed in four interleaved partial sums (a fixed order, so deterministic): the additions of
 * one running sum would wait on each other. */
static double dot(int32_t n, const double *u, const double *v)
{
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    int32_t i = 0;
    for (; i + 4 <= n; i += 4) {
        s0 += u[i] * v[i];
        s1 += u[i + 1] * v[i + 1];
        s2 += u[i + 2] * v[i + 2];
        s3 += u[i + 3] * v[i + 3];
    }
    for (; i < n; i++)
        s0 += u[i] * v[i];
    return (s0 + s1) + (s2 + s3);
}

/* u . v in one running sum, in index order. */
static double dot_sequential(int32_t n, const double *u, const double *v)
{
    double s = 0.0;
    for (int32_t i = 0; i < n; i++)
        s += u[i] * v[i];
    return s;
}

double fs_cg_dot(int32_t n, const double *u, const double *v, fs_cg_sum sum)
{
    return sum == FS_CG_SUM_SEQUENTIAL ? dot_sequential(n, u, v) : dot(n, u, v);
}

/* r = b - A x, using q for A x. */
static void residual(const fs_cg_operator *op, const double *b, const double *x, double *r, double *q)
{
    op->apply(op->ctx, x, q);
    for (int32_t i = 0; i < op->n; i++)
        r[i] = b[i] - q[i];
}

fs_pcg_result fs_pcg(const fs_cg_operator *op, const double *b, double *x, const fs_pcg_params *params,
                     fs_pcg_vectors v)
{
    FS_ASSERT(params->max_iterations > 0);
    int32_t n = op->n;
    double *r = v.r, *z = v.z, *p = v.p, *q = v.q;
    fs_pcg_result res = {FS_PCG_CONVERGED, 0, 0.0, 0.0};
    if (params->from_zero) {
        memset(x, 0, (size_t)n * sizeof *x);
        memcpy(r, b, (size_t)n * sizeof *r);
    } else {
        residual(op, b, x, r, q);
    }
    if (params->true_residual && op->converged(op->ctx, r))
        return res;
    if (op->precondition(op->ctx, r, z) < 0) {
        res.status = FS_PCG_FAILED;
        return res;
    }
    double rz = fs_cg_dot(n, r, z, params->sum);
    memcpy(p, z, (size_t)n * sizeof *p);
    while (res.iterations < params->max_iterations) {
        op->apply(op->ctx, p, q);
        double curvature = fs_cg_dot(n, p, q, params->sum);
        if (!(curvature > 0.0)) {
            res.status = FS_PCG_BREAKDOWN;
            res.curvature = curvature;
            res.rz = rz;
            return res;
        }
        double alpha = rz / curvature;
        for (int32_t i = 0; i < n; i++) {
            x[i] += alpha * p[i];
            r[i] -= alpha * q[i];
        }
        res.iterations++;
        if (op->converged(op->ctx, r)) {
            if (!params->true_residual)
                return res;
            residual(op, b, x, r, q);
            if (op->converged(op->ctx, r))
                return res;
            /* the recurrence drifted: restart the search from the true residual */
            if (op->precondition(op->ctx, r, z) < 0) {
                res.status = FS_PCG_FAILED;
                return res;
            }
            rz = fs_cg_dot(n, r, z, params->sum);
            memcpy(p, z, (size_t)n * sizeof *p);
            continue;
        }
        if (res.iterations == params->max_iterations)
            break;
        if (op->precondition(op->ctx, r, z) < 0) {
            res.status = FS_PCG_FAILED;
            return res;
        }
        double rz_next = fs_cg_dot(n, r, z, params->sum);
        double beta = rz_next / rz;
        rz = rz_next;
        for (int32_t i = 0; i < n; i++)
            p[i] = z[i] + beta * p[i];
    }
    res.status = FS_PCG_MAX_ITERATIONS;
    return res;
}

/* The largest |v[i]|, or NaN if an entry is not finite (so such a residual never passes a bound),
 * in four interleaved running maxima. */
static double max_abs(int32_t n, const double *v)
{
    double m0 = 0.0, m1 = 0.0, m2 = 0.0, m3 = 0.0;
    bool bad = false;
    int32_t i = 0;
    for (; i + 4 <= n; i += 4) {
        double a0 = fabs(v[i]), a1 = fabs(v[i + 1]), a2 = fabs(v[i + 2]), a3 = fabs(v[i + 3]);
        m0 = a0 > m0 ? a0 : m0;
        m1 = a1 > m1 ? a1 : m1;
        m2 = a2 > m2 ? a2 : m2;
        m3 = a3 > m3 ? a3 : m3;
        bad |= !(a0 <= DBL_MAX) | !(a1 <= DBL_MAX) | !(a2 <= DBL_MAX) | !(a3 <= DBL_MAX);
    }
    for (; i < n; i++) {
        double a = fabs(v[i]);
        m0 = a > m0 ? a : m0;
        bad |= !(a <= DBL_MAX);
    }
    m0 = m1 > m0 ? m1 : m0;
    m2 = m3 > m2 ? m3 : m2;
    return bad ? NAN : m2 > m0 ? m2 : m0;
}

/* design: with block = 3 the matrix is first copied into 3x3 blocks, one row of blocks per node
 * (block compressed rows) holding the blocks on and above the diagonal, the diagonal block first and
 * whole. The product reads one column index per nine values, and each stored off-diagonal block
 * serves both its row (B x_j) and, transposed, its column (B^T x_i): where the upper-triangle product
 * (fs_sparse_matvec) reads an index per value, and a copy in both triangles reads every value twice,
 * this reads the half of the matrix once, and the product is bound by reading the matrix. The copy
 * costs about one product. The sums run in a fixed order, so results are deterministic. */
typedef struct {
    int32_t nb;       /* rows (and columns) of blocks: n / 3 */
    int32_t *row_ptr; /* nb + 1 offsets into col and v */
    int32_t *col;     /* block column of each stored block, ascending (>= its row) */
    int32_t *diag;    /* per block row: the slot of its diagonal block (its first), -1 if it has none */
    double *v;        /* 9 per block, row-major */
} block3_matrix;

static void block3_free(block3_matrix *b)
{
    free(b->row_ptr);
    free(b->col);
    free(b->diag);
    free(b->v);
}

/* Lays out b's nb block rows from their block counts (next[i], turned into each row's first free
 * slot) and allocates the blocks (zeroed if zero is set: else the caller writes every entry), with no
 * diagonal block found yet. */
static void block3_alloc(block3_matrix *b, int32_t nb, int32_t *next, bool zero)
{
    b->nb = nb;
    b->row_ptr = fs_malloc(((size_t)nb + 1) * sizeof *b->row_ptr);
    int32_t total = 0;
    for (int32_t i = 0; i < nb; i++) {
        b->row_ptr[i] = total;
        total += next[i];
        next[i] = b->row_ptr[i];
    }
    b->row_ptr[nb] = total;
    b->col = fs_malloc(((size_t)total + 1) * sizeof *b->col);
    b->v = zero ? fs_calloc(9 * ((size_t)total + 1), sizeof *b->v) : fs_malloc(9 * ((size_t)total + 1) * sizeof *b->v);
    b->diag = fs_malloc(((size_t)nb + 1) * sizeof *b->diag);
    for (int32_t i = 0; i < nb; i++)
        b->diag[i] = -1;
}

/* Copies the upper-triangle CSC a (a->n a multiple of 3) into b; absent entries of a stored block
 * are 0. */
static void block3_build(const fs_sparse_matrix *a, block3_matrix *b)
{
    int32_t nb = a->n / 3;
    int32_t *mark = fs_malloc(((size_t)nb + 1) * sizeof *mark);
    int32_t *next = fs_calloc((size_t)nb + 1, sizeof *next);
    int32_t *slot = fs_malloc(((size_t)nb + 1) * sizeof *slot);
    for (int32_t i = 0; i < nb; i++)
        mark[i] = -1;
    /* pass 1: blocks per block row (block (I, J) with I <= J, as the entries of a are) */
    for (int32_t jb = 0; jb < nb; jb++)
        for (int32_t j = 3 * jb; j < 3 * jb + 3; j++)
            for (int32_t p = a->col_ptr[j]; p < a->col_ptr[j + 1]; p++) {
                int32_t ib = a->row_idx[p] / 3;
                if (mark[ib] != jb) {
                    mark[ib] = jb;
                    next[ib]++;
                }
            }
    block3_alloc(b, nb, next, true);
    for (int32_t i = 0; i < nb; i++)
        mark[i] = -1;
    /* pass 2: place the blocks (by ascending block column: the diagonal block first) and their values;
     * the diagonal block gets both triangles */
    for (int32_t jb = 0; jb < nb; jb++)
        for (int32_t j = 3 * jb; j < 3 * jb + 3; j++)
            for (int32_t p = a->col_ptr[j]; p < a->col_ptr[j + 1]; p++) {
                int32_t i = a->row_idx[p], ib = i / 3;
                if (mark[ib] != jb) {
                    mark[ib] = jb;
                    slot[ib] = next[ib]++;
                    b->col[slot[ib]] = jb;
                    if (ib == jb)
                        b->diag[ib] = slot[ib];
                }
                double *v = b->v + 9 * (size_t)slot[ib];
                v[3 * (i % 3) + j % 3] = a->values[p];
                if (ib == jb)
                    v[3 * (j % 3) + i % 3] = a->values[p];
            }
    free(mark);
    free(next);
    free(slot);
}

/* design: the elasticity systems come in whole 3x3 blocks: a node's three unknowns are consecutive
 * from a multiple of 3, and the three columns of a node list the same coupled nodes (all nine entries
 * of each block off the diagonal, the upper six of the diagonal block). Such a matrix, or its
 * principal submatrix on whole nodes, is copied into blocks straight from its columns, a triple of
 * rows at a time; anything else goes through the general copy (block3_build). */

/* Whether block column g (unknowns 3g .. 3g + 2) of a has the layout above; *k receives its number
 * of coupled nodes above the diagonal. */
static bool block_column_regular(const fs_sparse_matrix *a, int32_t g, int32_t *k)
{
    const int32_t *cp = a->col_ptr + 3 * (size_t)g, *ri = a->row_idx;
    int32_t len0 = cp[1] - cp[0], len1 = cp[2] - cp[1], len2 = cp[3] - cp[2];
    if (len2 < 3 || len2 % 3 != 0 || len1 != len2 - 1 || len0 != len2 - 2)
        return false;
    int32_t kk = len2 / 3 - 1, c = 3 * g;
    for (int32_t q = 0; q < kk; q++) {
        int32_t t = ri[cp[2] + 3 * q];
        if (t % 3 != 0 || t >= c)
            return false;
        for (int l = 0; l < 3; l++)
            for (int r = 0; r < 3; r++)
                if (ri[cp[l] + 3 * q + r] != t + r)
                    return false;
    }
    if (ri[cp[1] - 1] != c || ri[cp[2] - 2] != c || ri[cp[2] - 1] != c + 1 || ri[cp[3] - 3] != c ||
        ri[cp[3] - 2] != c + 1 || ri[cp[3] - 1] != c + 2)
        return false;
    *k = kk;
    return true;
}

/* The blocks of the principal submatrix of a on the whole nodes idx (m unknowns; NULL: all of a, m =
 * a->n), map as in fs_sparse_matrix_principal (unused without idx). Returns false, b untouched, if a
 * does not have the layout of the design note there or idx does not list whole nodes. */
static bool block3_build_regular(const fs_sparse_matrix *a, const int32_t *idx, int32_t m, int32_t *map,
                                 block3_matrix *b)
{
    int32_t nb = m / 3;
    int32_t *kk = fs_malloc(((size_t)nb + 1) * sizeof *kk), *next = fs_calloc((size_t)nb + 1, sizeof *next);
    bool ok = m % 3 == 0;
    for (int32_t jb = 0; jb < nb && ok; jb++) {
        int32_t c = idx ? idx[3 * jb] : 3 * jb;
        ok = c % 3 == 0 && (!idx || (idx[3 * jb + 1] == c + 1 && idx[3 * jb + 2] == c + 2)) &&
             block_column_regular(a, c / 3, &kk[jb]);
    }
    if (idx)
        for (int32_t q = 0; q < m && ok; q++)
            map[idx[q]] = q;
    /* pass 1: blocks per block row */
    for (int32_t jb = 0; jb < nb && ok; jb++) {
        const int32_t *rows = a->row_idx + a->col_ptr[(idx ? idx[3 * jb] : 3 * jb) + 2];
        for (int32_t q = 0; q < kk[jb]; q++) {
            int32_t i = idx ? map[rows[3 * q]] : rows[3 * q];
            if (i >= 0)
                next[i / 3]++;
        }
        next[jb]++;
    }
    if (ok)
        block3_alloc(b, nb, next, false); /* pass 2 writes all nine entries of every block */
    /* pass 2: the blocks, a triple of rows of the node's three columns at a time (by ascending block
     * column, so a row's diagonal block comes first); the diagonal block gets both triangles */
    for (int32_t jb = 0; jb < nb && ok; jb++) {
        int32_t c = idx ? idx[3 * jb] : 3 * jb;
        const int32_t *p = a->col_ptr + c;
        for (int32_t q = 0; q <= kk[jb]; q++) {
            int32_t ib = q < kk[jb] ? (idx ? map[a->row_idx[p[2] + 3 * q]] : a->row_idx[p[2] + 3 * q]) : 3 * jb;
            if (ib < 0)
                continue;
            ib /= 3;
            int32_t slot = next[ib]++;
            b->col[slot] = jb;
            double *u = b->v + 9 * (size_t)slot;
            for (int l = 0; l < 3; l++)
                for (int r = 0; r < 3; r++) {
                    /* entry (row 3 ib + r, column 3 jb + l); the diagonal block holds r <= l only */
                    if (ib == jb && r > l)
                        continue;
                    double v = a->values[p[l] + 3 * q + r];
                    u[3 * r + l] = v;
                    if (ib == jb)
                        u[3 * l + r] = v;
                }
            if (ib == jb)
                b->diag[jb] = slot;
        }
    }
    if (idx)
        for (int32_t q = 0; q < m; q++)
            map[idx[q]] = -1;
    free(kk);
    free(next);
    return ok;
}

/* y = B x: row I adds B_II x_I and, for each block above the diagonal, B_IJ x_J to y_I and B_IJ^T x_I
 * to y_J, which is complete once row J begins (J > I). */
static void block3_matvec(const block3_matrix *restrict b, const double *restrict x, double *restrict y)
{
    memset(y, 0, 3 * (size_t)b->nb * sizeof *y);
    for (int32_t ib = 0; ib < b->nb; ib++) {
        double *yi = y + 3 * (size_t)ib;
        const double x0 = x[3 * (size_t)ib], x1 = x[3 * (size_t)ib + 1], x2 = x[3 * (size_t)ib + 2];
        double y0 = yi[0], y1 = yi[1], y2 = yi[2];
        int32_t p = b->row_ptr[ib];
        if (b->diag[ib] == p) {
            const double *v = b->v + 9 * (size_t)p++;
            y0 += v[0] * x0 + v[1] * x1 + v[2] * x2;
            y1 += v[3] * x0 + v[4] * x1 + v[5] * x2;
            y2 += v[6] * x0 + v[7] * x1 + v[8] * x2;
        }
        for (; p < b->row_ptr[ib + 1]; p++) {
            const double *v = b->v + 9 * (size_t)p, *xj = x + 3 * (size_t)b->col[p];
            double *yj = y + 3 * (size_t)b->col[p];
            y0 += v[0] * xj[0] + v[1] * xj[1] + v[2] * xj[2];
            y1 += v[3] * xj[0] + v[4] * xj[1] + v[5] * xj[2];
            y2 += v[6] * xj[0] + v[7] * xj[1] + v[8] * xj[2];
            yj[0] += v[0] * x0 + v[3] * x1 + v[6] * x2;
            yj[1] += v[1] * x0 + v[4] * x1 + v[7] * x2;
            yj[2] += v[2] * x0 + v[5] * x1 + v[8] * x2;
        }
        yi[0] = y0;
        yi[1] = y1;
        yi[2] = y2;
    }
}

/* The operator CG multiplies by: the blocks when there are (block = 3), else the CSC itself. */
typedef struct {
    const fs_sparse_matrix *a;
    const block3_matrix *b;
} operator_t;

static void apply(const operator_t *op, const double *x, double *y)
{
    if (op->b)
        block3_matvec(op->b, x, y);
    else
        fs_sparse_matvec(op->a, x, y);
}

/* z = M^-1 r with the preconditioner inv (block 1: n inverse diagonal entries; block 3: n / 3 inverse
 * 3x3 blocks, row-major). */
static void precondition(int32_t n, int32_t block, const double *inv, const double *r, double *z)
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
}

/* The preconditioner of fs_cg_solve (see precondition) into inv: the inverse diagonal of a, or the
 * inverses of the diagonal blocks of blocks. Returns 0, or -1 with fs_error if a diagonal entry or
 * block is not positive definite. */
static int preconditioner(const fs_sparse_matrix *a, const block3_matrix *blocks, double *inv)
{
    if (!blocks) {
        int32_t n = a->n;
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
    static const double zero[9] = {0};
    for (int32_t ib = 0; ib < blocks->nb; ib++) {
        const double *m = blocks->diag[ib] >= 0 ? blocks->v + 9 * (size_t)blocks->diag[ib] : zero;
        /* the inverse by cofactors; positive definite iff the leading minors (m[0], adj[8], det)
         * are positive */
        double adj[9], det = fs_mat3_adjugate(m, adj);
        if (!(m[0] > 0.0 && adj[8] > 0.0 && det > 0.0)) {
            fs_error(FS_ERR_INTERNAL, "cg: diagonal block of unknowns %d-%d is not positive definite", 3 * ib,
                     3 * ib + 2);
            return -1;
        }
        double *v = inv + 9 * (size_t)ib;
        for (int k = 0; k < 9; k++)
            v[k] = adj[k] / det;
    }
    return 0;
}

/* fs_cg_solve's side of fs_pcg: the matrix, the preconditioner and the stopping rule. */
typedef struct {
    const operator_t *op;
    int32_t n, block;
    const double *inv;
    const fs_cg_params *params;
    double limit; /* tolerance ||b|| */
} cg_ctx;

static void cg_apply(void *ctx, const double *x, double *y) { apply(((const cg_ctx *)ctx)->op, x, y); }

static int cg_precondition(void *ctx, const double *r, double *z)
{
    const cg_ctx *c = ctx;
    precondition(c->n, c->block, c->inv, r, z);
    return 0;
}

/* With a max_residual, every entry of r within it, else the Euclidean norm of r within limit. */
static bool cg_converged(void *ctx, const double *r)
{
    const cg_ctx *c = ctx;
    if (c->params->max_residual > 0.0)
        return max_abs(c->n, r) <= c->params->max_residual;
    return sqrt(dot(c->n, r, r)) <= c->limit;
}

/* fs_cg_solve on n unknowns with the matrix op (with blocks: params.block = 3): fs_pcg from x, on the
 * true residual, with the interleaved sums. */
static int cg_run(const operator_t *op, int32_t n, const double *b, double *x, fs_cg_params params,
                  double *relative_residual)
{
    int32_t max_iterations = params.max_iterations > 0 ? params.max_iterations : n;
    double bnorm = sqrt(dot(n, b, b));
    if (relative_residual)
        *relative_residual = 0.0;
    if (bnorm == 0.0) {
        for (int32_t i = 0; i < n; i++)
            x[i] = 0.0;
        return 0;
    }

    int32_t block = op->b ? 3 : 1;
    double *scratch = fs_malloc((4 + (size_t)block) * (size_t)n * sizeof *scratch);
    fs_pcg_vectors v = {scratch, scratch + n, scratch + 2 * (size_t)n, scratch + 3 * (size_t)n};
    double *inv = scratch + 4 * (size_t)n;
    int status = -1;
    if (preconditioner(op->a, op->b, inv) < 0)
        goto done;
    cg_ctx c = {op, n, block, inv, &params, params.tolerance * bnorm};
    fs_cg_operator a = {n, cg_apply, cg_precondition, cg_converged, &c};
    fs_pcg_params pcg = {max_iterations, FS_CG_SUM_INTERLEAVED, false, true};
    fs_pcg_result res = fs_pcg(&a, b, x, &pcg, v);
    if (res.status == FS_PCG_BREAKDOWN) {
        fs_error(FS_ERR_INTERNAL, "cg: matrix not positive definite (p'Ap = %g at iteration %d)", res.curvature,
                 res.iterations);
        goto done;
    }
    double rnorm = sqrt(dot(n, v.r, v.r));
    if (relative_residual)
        *relative_residual = rnorm / bnorm;
    if (res.status != FS_PCG_CONVERGED) {
        fs_error(FS_ERR_INTERNAL, "cg: no convergence after %d iterations (relative residual %.3g)", res.iterations,
                 rnorm / bnorm);
        goto done;
    }
    status = res.iterations;
done:
    free(scratch);
    return status;
}

int fs_cg_solve(const fs_sparse_matrix *a, const double *b, double *x, fs_cg_params params,
                double *relative_residual)
{
    FS_ASSERT(params.block != 3 || a->n % 3 == 0);
    block3_matrix blocks = {0};
    operator_t op = {a, NULL};
    if (params.block == 3) {
        if (!block3_build_regular(a, NULL, a->n, NULL, &blocks))
            block3_build(a, &blocks);
        op.b = &blocks;
    }
    int status = cg_run(&op, a->n, b, x, params, relative_residual);
    block3_free(&blocks);
    return status;
}

int fs_cg_solve_principal(const fs_sparse_matrix *a, const int32_t *idx, int32_t m, int32_t *map, const double *b,
                          double *x, fs_cg_params params, double *relative_residual)
{
    block3_matrix blocks = {0};
    if (params.block == 3 && block3_build_regular(a, idx, m, map, &blocks)) {
        operator_t op = {NULL, &blocks};
        int status = cg_run(&op, m, b, x, params, relative_residual);
        block3_free(&blocks);
        return status;
    }
    fs_sparse_matrix sub = {0};
    fs_sparse_matrix_principal(a, idx, m, map, &sub);
    int status = fs_cg_solve(&sub, b, x, params, relative_residual);
    fs_sparse_matrix_free(&sub);
    return status;
}
