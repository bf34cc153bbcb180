/* Sparse symmetric matrices: assembly into compressed columns, products, and sparse Cholesky (CHOLMOD). */
#ifndef FS_SOLVE_SPARSE_H
#define FS_SOLVE_SPARSE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* A symmetric n×n matrix stored as its upper triangle in compressed sparse columns (CSC).
 * Column j holds entries (row_idx[p], j) with values[p] for col_ptr[j] <= p < col_ptr[j+1]; the rows of
 * a column are strictly increasing, every row <= j, and every column holds its diagonal entry, last
 * (so the diagonal of column j is values[col_ptr[j+1] - 1], possibly 0). The arrays are flat so that
 * models may rewrite values in place between factorizations (the pattern stays fixed), and so that
 * CHOLMOD reads them without a copy. Owned by whoever holds the struct; fs_sparse_matrix_free releases
 * the arrays. */
typedef struct {
    int32_t n;        /* number of rows and columns (unknowns) */
    int32_t *col_ptr; /* n + 1 offsets into row_idx and values; col_ptr[n] is the number of stored entries */
    int32_t *row_idx; /* row of each stored entry */
    double *values;   /* value of each stored entry */
} fs_sparse_matrix;

/* Accumulates (row, col, value) entries of a symmetric matrix before compression. An entry names an
 * unordered pair: (i, j) and (j, i) are the same stored entry, so add each off-diagonal contribution once,
 * in either triangle. Entries that name the same pair are summed. Entries are numbered 0, 1, 2, ... in the
 * order they are added; compression reports, for each entry number, the index in values it landed in. */
typedef struct {
    int32_t n;        /* order of the matrix being built */
    size_t count;     /* entries added so far */
    size_t capacity;  /* entries that fit before the arrays grow */
    int32_t *rows;    /* per entry: the smaller of its two indices (upper triangle) */
    int32_t *cols;    /* per entry: the larger of its two indices */
    double *values;   /* per entry: its value */
    size_t *scratch;  /* compression's work space, kept for the next compression */
    size_t scratch_size;
} fs_sparse_builder;

/* Starts an empty builder for an n×n matrix (n >= 0). capacity_hint entries are reserved (0 is fine);
 * the arrays grow as needed. Release with fs_sparse_builder_free. */
void fs_sparse_builder_init(fs_sparse_builder *b, int32_t n, size_t capacity_hint);
void fs_sparse_builder_free(fs_sparse_builder *b);

/* Forgets all entries (keeps the storage) so the builder can assemble a new pattern of order n; a
 * builder that assembles pattern after pattern (a model whose mesh changes) reuses its arrays and its
 * compression's work space instead of allocating them afresh each time. */
void fs_sparse_builder_clear(fs_sparse_builder *b, int32_t n);

/* Adds value at (row, col), 0 <= row, col < n (checked with FS_ASSERT). Returns the entry number. */
size_t fs_sparse_builder_add(fs_sparse_builder *b, int32_t row, int32_t col, double value);

/* Adds a dense symmetric k×k block ke (row-major, only its upper triangle ke[a*k+c], c >= a, is read)
 * whose local index a maps to global index idx[a]; idx[a] < 0 marks a constrained unknown whose rows and
 * columns are left out. Pairs are visited for a = 0..k-1, c = a..k-1 and each kept pair becomes one entry,
 * so the entries of one call are numbered consecutively, starting at b->count as it was before the call.
 * Two local indices must not map to the same global index (FS_ASSERT). Returns the number of
 * entries added (at most k(k+1)/2). */
int32_t fs_sparse_builder_add_block(fs_sparse_builder *b, int32_t k, const int32_t *idx, const double *ke);

/* Compresses the entries into out (which must not hold arrays: it is overwritten), summing duplicates in
 * entry order and inserting a zero diagonal entry where a column has none. If slots is not NULL it has
 * b->count elements and receives, for each entry number, the index into out->values the entry was summed
 * into. The builder's entries are unchanged (it keeps the work space). Returns 0, or -1 with
 * FS_ERR_INTERNAL if the matrix has more than INT32_MAX stored entries. */
int fs_sparse_builder_compress(fs_sparse_builder *b, fs_sparse_matrix *out, int32_t *slots);

/* Releases the arrays of m and zeroes the struct (a zeroed struct may be freed again). */
void fs_sparse_matrix_free(fs_sparse_matrix *m);

/* Checks the storage rules above: col_ptr starts at 0 and never decreases, every row index lies in
 * [0, j] for column j and increases strictly down the column, every column ends with its diagonal
 * entry, and every value is finite (so the symmetric matrix the upper triangle stands for is well
 * defined). Returns true, or false with a message naming the column, row and value in why (len
 * bytes; may be NULL). For --enable-validate builds and tests. */
bool fs_sparse_matrix_check(const fs_sparse_matrix *m, char *why, size_t len);

/* Number of stored entries (upper triangle including the diagonal). */
static inline int32_t fs_sparse_matrix_nnz(const fs_sparse_matrix *m) { return m->col_ptr[m->n]; }

/* Sets every stored value to 0, keeping the pattern (before re-adding contributions through slots). */
void fs_sparse_matrix_zero(fs_sparse_matrix *m);

/* Adds the block that fs_sparse_builder_add_block added with the same k and idx, to the values in place:
 * slots are that call's entries' slots, consecutive (the slot array returned by compression, from the
 * entry number of the block's first entry). Returns the number of slots consumed. Summing contributions
 * in the order they were first added reproduces a fresh assembly bit for bit. */
int32_t fs_sparse_matrix_add_block(fs_sparse_matrix *m, int32_t k, const int32_t *idx, const double *ke,
                                   const int32_t *slots);

/* y = A x for the full symmetric matrix A whose upper triangle m stores; x and y have m->n elements and
 * must not overlap. Deterministic (fixed summation order). */
void fs_sparse_matvec(const fs_sparse_matrix *m, const double *x, double *y);

/* The principal submatrix of a on the m unknowns idx (strictly increasing): out (which must not hold
 * arrays) receives, in the same storage rules, the entries of a whose row and column are both listed,
 * unknown idx[q] becoming q. map is scratch of a->n entries, all -1 on entry and again on return
 * (callers keep one array across calls, so the cost is that of the listed columns). Release out with
 * fs_sparse_matrix_free. */
void fs_sparse_matrix_principal(const fs_sparse_matrix *a, const int32_t *idx, int32_t m, int32_t *map,
                                fs_sparse_matrix *out);

/* Sparse Cholesky factorization A = P' L L' P (or L D L') of a symmetric positive definite matrix through
 * CHOLMOD: a fill-reducing ordering (the better of AMD and METIS) and a
 * supernodal or simplicial factor (CHOLMOD chooses by the flop count). Opaque; one object per thread. */
typedef struct fs_cholesky fs_cholesky;

/* Facts about an analysis, for logs and benchmarks. */
typedef struct {
    int32_t n;                /* order of the matrix */
    double factor_nonzeros;   /* entries of L predicted by the analysis */
    double flops;             /* floating-point operations of one numeric factorization */
    int supernodal;           /* 1 if the factor is supernodal, 0 if simplicial */
    const char *ordering;     /* "amd", "metis", "nesdis", "natural", ... (static string) */
} fs_cholesky_info;

/* Orders and symbolically factorizes the pattern of a (its values are not read). Returns a new object to
 * release with fs_cholesky_free, or NULL with FS_ERR_INTERNAL if CHOLMOD fails (out of memory, matrix too
 * large for 32-bit indices). */
fs_cholesky *fs_cholesky_analyze(const fs_sparse_matrix *a);

/* fs_cholesky_analyze for a small system factored once or a few times (a local relaxation): AMD alone
 * and a simplicial factor. Below a few thousand unknowns that is several times faster: METIS's
 * analysis costs more than it saves there, and the supernodal factor's many small BLAS calls hand
 * work to the BLAS's threads and back. Results as fs_cholesky_analyze's up to rounding. */
fs_cholesky *fs_cholesky_analyze_small(const fs_sparse_matrix *a);

/* fs_cholesky_analyze in the order perm (perm[k] = the unknown eliminated k-th, a permutation of
 * 0..n-1; CHOLMOD keeps it up to a postorder of its elimination tree): the symbolic work alone, no
 * ordering, for a pattern close to one already ordered (a mesh after a few cuts, its new unknowns
 * placed beside those they came from). */
fs_cholesky *fs_cholesky_analyze_given(const fs_sparse_matrix *a, const int32_t *perm);

/* The order an analysis eliminates in: element k is the unknown eliminated k-th (n elements, owned
 * by c). */
const int32_t *fs_cholesky_permutation(const fs_cholesky *c);

/* Numerically factorizes a with its current values. a must have the pattern given to
 * fs_cholesky_analyze (same n and entry count are checked with FS_ASSERT; the pattern itself is the
 * caller's contract). Call again after rewriting a->values to refactorize cheaply: the ordering and the
 * symbolic factor are reused. This also discards any fs_cholesky_updown applied since.
 * Returns 0, or -1 with FS_ERR_INTERNAL "cholmod: matrix not positive definite at column J" (J an index of
 * a, in the original numbering) or another CHOLMOD failure; after -1, solves fail until a successful
 * factorization. Nothing is printed. */
int fs_cholesky_factorize(fs_cholesky *c, const fs_sparse_matrix *a);

/* Solves A x = b for nrhs right-hand sides stored one after another (b[r*n + i] is row i of the r-th);
 * x has the same layout and must not overlap b. The solution is written straight into x. Returns 0, or -1
 * with FS_ERR_INTERNAL if there is no valid factorization or CHOLMOD fails. */
int fs_cholesky_solve(fs_cholesky *c, int32_t nrhs, const double *b, double *x);

/* Changes the factorization of A into that of A + W W' (sign > 0, update) or A - W W' (sign < 0,
 * downdate), where W is a sparse n×rank matrix in compressed columns (col_ptr has rank + 1 elements;
 * rows within a column in any order, without repeats). Cheap when W touches few rows: use it for small
 * changes such as one spring breaking (W = sqrt(k) (e_i - e_j) per direction). The factor becomes
 * simplicial LDL'; the caller's matrix is not changed, and the next fs_cholesky_factorize starts from
 * the original symbolic analysis again. Returns 0, or -1 with FS_ERR_INTERNAL if there is no valid
 * factorization, CHOLMOD fails, or a downdate leaves the matrix not positive definite ("cholmod: matrix
 * not positive definite at column J after downdate"; solves then fail until the next factorization). */
int fs_cholesky_updown(fs_cholesky *c, int sign, int32_t rank, const int32_t *col_ptr,
                       const int32_t *row_idx, const double *values);

/* Facts about the analysis of c. */
fs_cholesky_info fs_cholesky_get_info(const fs_cholesky *c);

/* Releases c and everything CHOLMOD allocated for it; NULL is allowed. */
void fs_cholesky_free(fs_cholesky *c);

#endif
