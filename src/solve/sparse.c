/* Sparse symmetric assembly and products, and the only CHOLMOD user: sparse Cholesky for the equilibrium solves. */
#include "solve/sparse.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cholmod.h>
#include <dlfcn.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"

_Static_assert(sizeof(int) == sizeof(int32_t), "the int interface of CHOLMOD reads our int32_t arrays");

void fs_sparse_builder_init(fs_sparse_builder *b, int32_t n, size_t capacity_hint)
{
    FS_ASSERT(n >= 0);
    b->n = n;
    b->count = 0;
    b->capacity = capacity_hint;
    b->rows = fs_malloc(capacity_hint * sizeof *b->rows);
    b->cols = fs_malloc(capacity_hint * sizeof *b->cols);
    b->values = fs_malloc(capacity_hint * sizeof *b->values);
    b->scratch = NULL;
    b->scratch_size = 0;
}

void fs_sparse_builder_free(fs_sparse_builder *b)
{
    free(b->rows);
    free(b->cols);
    free(b->values);
    free(b->scratch);
    memset(b, 0, sizeof *b);
}

void fs_sparse_builder_clear(fs_sparse_builder *b, int32_t n)
{
    FS_ASSERT(n >= 0);
    b->n = n;
    b->count = 0;
}

static void builder_reserve(fs_sparse_builder *b, size_t extra)
{
    if (FS_ARRAY_GROW(b->capacity, b->count + extra, 64)) {
        FS_ARRAY_RESIZE(b->rows, b->capacity);
        FS_ARRAY_RESIZE(b->cols, b->capacity);
        FS_ARRAY_RESIZE(b->values, b->capacity);
    }
}

size_t fs_sparse_builder_add(fs_sparse_builder *b, int32_t row, int32_t col, double value)
{
    FS_ASSERT(row >= 0 && row < b->n && col >= 0 && col < b->n);
    builder_reserve(b, 1);
    size_t e = b->count++;
    b->rows[e] = row < col ? row : col;
    b->cols[e] = row < col ? col : row;
    b->values[e] = value;
    return e;
}

int32_t fs_sparse_builder_add_block(fs_sparse_builder *b, int32_t k, const int32_t *idx, const double *ke)
{
    FS_ASSERT(k >= 0);
    builder_reserve(b, (size_t)k * (size_t)(k + 1) / 2);
    int32_t added = 0;
    for (int32_t a = 0; a < k; a++) {
        if (idx[a] < 0)
            continue;
        for (int32_t c = a; c < k; c++) {
            if (idx[c] < 0)
                continue;
            FS_ASSERT(a == c || idx[a] != idx[c]);
            fs_sparse_builder_add(b, idx[a], idx[c], ke[(size_t)a * (size_t)k + (size_t)c]);
            added++;
        }
    }
    return added;
}

/* An entry bucketed into its column, with what compression reads of it. */
typedef struct {
    double value;
    int32_t row;
    uint32_t entry;
} column_entry;

/* The distinct rows of one column's entries, and the diagonal j, into list (marking each with j in
 * mark). Returns how many. */
static int32_t column_rows(const column_entry *col, size_t k, int32_t j, int32_t *mark, int32_t *list)
{
    int32_t u = 0;
    for (size_t q = 0; q < k; q++) {
        int32_t r = col[q].row;
        if (mark[r] != j) {
            mark[r] = j;
            list[u++] = r;
        }
    }
    if (mark[j] != j) {
        mark[j] = j;
        list[u++] = j;
    }
    return u;
}

static int compare_int32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

static void sort_rows(int32_t *list, int32_t u)
{
    if (u > 48) {
        qsort(list, (size_t)u, sizeof *list, compare_int32);
        return;
    }
    for (int32_t i = 1; i < u; i++) {
        int32_t v = list[i], k = i;
        for (; k > 0 && list[k - 1] > v; k--)
            list[k] = list[k - 1];
        list[k] = v;
    }
}

/* design: one stable counting sort buckets the entries by column, carrying each entry's row and value
 * along so that the columns are then read in sequence; a column's distinct rows are marked, sorted (a
 * column holds a few dozen) and numbered, and its entries summed into them in entry order, which
 * fs_sparse_matrix_add_block repeats exactly. O(n + count) plus the columns' small sorts. */
int fs_sparse_builder_compress(fs_sparse_builder *b, fs_sparse_matrix *out, int32_t *slots)
{
    int32_t n = b->n;
    size_t count = b->count;
    if (count > UINT32_MAX) {
        fs_error(FS_ERR_INTERNAL, "sparse: %zu entries exceed the 32-bit entry numbers", count);
        return -1;
    }
    size_t bytes = 2 * ((size_t)n + 1) * sizeof(size_t) + count * sizeof(column_entry) +
                   3 * ((size_t)n + 1) * sizeof(int32_t);
    size_t need = (bytes + sizeof(size_t) - 1) / sizeof(size_t);
    if (need > b->scratch_size) {
        /* with room to grow: a mesh being cut asks for a little more each time, and a block this
         * large comes fresh from the kernel, page by page */
        free(b->scratch);
        b->scratch_size = need + need / 2;
        b->scratch = fs_malloc(b->scratch_size * sizeof *b->scratch);
    }
    size_t *start = b->scratch, *cursor = start + (size_t)n + 1;
    column_entry *bucket = (column_entry *)(cursor + (size_t)n + 1);
    int32_t *mark = (int32_t *)(bucket + count), *pos = mark + (size_t)n + 1, *list = pos + (size_t)n + 1;

    memset(start, 0, ((size_t)n + 1) * sizeof *start);
    for (size_t e = 0; e < count; e++)
        start[b->cols[e] + 1]++;
    for (int32_t j = 0; j < n; j++)
        start[j + 1] += start[j];
    memcpy(cursor, start, ((size_t)n + 1) * sizeof *cursor);
    for (size_t e = 0; e < count; e++)
        bucket[cursor[b->cols[e]]++] = (column_entry){b->values[e], b->rows[e], (uint32_t)e};

    size_t nnz = 0;
    for (int32_t i = 0; i < n; i++)
        mark[i] = -1;
    for (int32_t j = 0; j < n; j++)
        nnz += (size_t)column_rows(bucket + start[j], start[j + 1] - start[j], j, mark, list);
    if (nnz > (size_t)INT32_MAX) {
        fs_error(FS_ERR_INTERNAL, "sparse: %zu stored entries exceed the 32-bit index range", nnz);
        return -1;
    }

    out->n = n;
    out->col_ptr = fs_malloc(((size_t)n + 1) * sizeof *out->col_ptr);
    out->row_idx = fs_malloc(nnz * sizeof *out->row_idx);
    out->values = fs_malloc(nnz * sizeof *out->values);
    for (int32_t i = 0; i < n; i++)
        mark[i] = -1;
    int32_t p = 0;
    for (int32_t j = 0; j < n; j++) {
        const column_entry *col = bucket + start[j];
        size_t k = start[j + 1] - start[j];
        int32_t u = column_rows(col, k, j, mark, list);
        sort_rows(list, u);
        out->col_ptr[j] = p;
        for (int32_t q = 0; q < u; q++) {
            pos[list[q]] = p + q;
            out->row_idx[p + q] = list[q];
            out->values[p + q] = 0.0;
        }
        for (size_t q = 0; q < k; q++) {
            int32_t at = pos[col[q].row];
            out->values[at] += col[q].value;
            if (slots)
                slots[col[q].entry] = at;
        }
        p += u;
    }
    out->col_ptr[n] = p;
    return 0;
}

void fs_sparse_matrix_free(fs_sparse_matrix *m)
{
    free(m->col_ptr);
    free(m->row_idx);
    free(m->values);
    memset(m, 0, sizeof *m);
}

bool fs_sparse_matrix_check(const fs_sparse_matrix *m, char *why, size_t len)
{
    char dummy[8];
    if (!why) {
        why = dummy;
        len = sizeof dummy;
    }
    if (m->n < 0 || (m->n > 0 && (!m->col_ptr || m->col_ptr[0] != 0))) {
        snprintf(why, len, "order %d, or col_ptr does not start at 0", (int)m->n);
        return false;
    }
    for (int32_t j = 0; j < m->n; j++) {
        int32_t p0 = m->col_ptr[j], p1 = m->col_ptr[j + 1];
        if (p1 <= p0) {
            snprintf(why, len, "column %d is empty (col_ptr %d, %d): no diagonal entry", (int)j, (int)p0, (int)p1);
            return false;
        }
        for (int32_t p = p0; p < p1; p++) {
            int32_t i = m->row_idx[p];
            if (i < 0 || i > j || (p > p0 && i <= m->row_idx[p - 1])) {
                snprintf(why, len, "column %d: row %d at entry %d is below the diagonal, out of range or out of order",
                         (int)j, (int)i, (int)p);
                return false;
            }
            if (!isfinite(m->values[p])) {
                snprintf(why, len, "entry (%d, %d) is %g", (int)i, (int)j, m->values[p]);
                return false;
            }
        }
        if (m->row_idx[p1 - 1] != j) {
            snprintf(why, len, "column %d does not end with its diagonal entry", (int)j);
            return false;
        }
    }
    return true;
}

void fs_sparse_matrix_zero(fs_sparse_matrix *m)
{
    int32_t nnz = fs_sparse_matrix_nnz(m);
    for (int32_t p = 0; p < nnz; p++)
        m->values[p] = 0.0;
}

int32_t fs_sparse_matrix_add_block(fs_sparse_matrix *m, int32_t k, const int32_t *idx, const double *ke,
                                   const int32_t *slots)
{
    int32_t used = 0;
    for (int32_t a = 0; a < k; a++) {
        if (idx[a] < 0)
            continue;
        for (int32_t c = a; c < k; c++) {
            if (idx[c] < 0)
                continue;
            m->values[slots[used++]] += ke[(size_t)a * (size_t)k + (size_t)c];
        }
    }
    return used;
}

void fs_sparse_matvec(const fs_sparse_matrix *m, const double *x, double *y)
{
    int32_t n = m->n;
    for (int32_t i = 0; i < n; i++)
        y[i] = 0.0;
    for (int32_t j = 0; j < n; j++) {
        double xj = x[j];
        double yj = 0.0;
        for (int32_t p = m->col_ptr[j]; p < m->col_ptr[j + 1]; p++) {
            int32_t i = m->row_idx[p];
            double v = m->values[p];
            if (i == j) {
                yj += v * xj;
            } else {
                y[i] += v * xj;
                yj += v * x[i];
            }
        }
        y[j] += yj;
    }
}

void fs_sparse_matrix_principal(const fs_sparse_matrix *a, const int32_t *idx, int32_t m, int32_t *map,
                                fs_sparse_matrix *out)
{
    for (int32_t q = 0; q < m; q++) {
        FS_ASSERT(idx[q] >= 0 && idx[q] < a->n && (q == 0 || idx[q] > idx[q - 1]));
        map[idx[q]] = q;
    }
    size_t nz = 0;
    for (int32_t q = 0; q < m; q++)
        for (int32_t p = a->col_ptr[idx[q]]; p < a->col_ptr[idx[q] + 1]; p++)
            nz += map[a->row_idx[p]] >= 0;
    out->n = m;
    out->col_ptr = fs_malloc(((size_t)m + 1) * sizeof *out->col_ptr);
    out->row_idx = fs_malloc((nz + 1) * sizeof *out->row_idx);
    out->values = fs_malloc((nz + 1) * sizeof *out->values);
    int32_t k = 0;
    for (int32_t q = 0; q < m; q++) {
        out->col_ptr[q] = k;
        for (int32_t p = a->col_ptr[idx[q]]; p < a->col_ptr[idx[q] + 1]; p++) {
            int32_t r = map[a->row_idx[p]];
            if (r >= 0) {
                out->row_idx[k] = r;
                out->values[k++] = a->values[p];
            }
        }
    }
    out->col_ptr[m] = k;
    for (int32_t q = 0; q < m; q++)
        map[idx[q]] = -1;
}

struct fs_cholesky {
    cholmod_common common;     /* CHOLMOD's settings, statistics and workspace; one per object */
    cholmod_factor *factor;    /* the factor being used: symbolic until the first factorization */
    cholmod_factor *symbolic;  /* the analysis as it came, restored when factor no longer matches it */
    int32_t n;                 /* order of the analysed matrix */
    int32_t nnz;               /* stored entries of the analysed matrix (a cheap pattern check) */
    int32_t *inverse_perm;     /* inverse_perm[i]: position of unknown i in CHOLMOD's ordering */
    double factor_nonzeros;    /* nnz(L) predicted by the analysis (later calls overwrite common's copy) */
    double flops;              /* flop count of one factorization, from the analysis */
    int valid;                 /* factor holds a successful numeric factorization */
    int stale;                 /* factor differs from symbolic in kind (after updown or a failure) */
    cholmod_dense *solve_y;    /* solve workspace kept between calls */
    cholmod_dense *solve_e;    /* solve workspace kept between calls */
};

/* CHOLMOD reports through a plain function pointer without user data, so the last message of this
 * thread is kept here and read by the wrapper that made the call. */
static _Thread_local char cholmod_message[256];

static void store_cholmod_message(int status, const char *file, int line, const char *message)
{
    (void)file;
    (void)line;
    snprintf(cholmod_message, sizeof cholmod_message, "%s (status %d)", message ? message : "", status);
}

static const char *cholmod_status_name(int status)
{
    switch (status) {
    case CHOLMOD_NOT_INSTALLED: return "method not installed";
    case CHOLMOD_OUT_OF_MEMORY: return "out of memory";
    case CHOLMOD_TOO_LARGE: return "integer overflow";
    case CHOLMOD_INVALID: return "invalid input";
    case CHOLMOD_GPU_PROBLEM: return "GPU failure";
    case CHOLMOD_NOT_POSDEF: return "matrix not positive definite";
    default: return "unknown status";
    }
}

static void report_failure(const fs_cholesky *c, const char *what)
{
    if (cholmod_message[0])
        fs_error(FS_ERR_INTERNAL, "cholmod: %s failed: %s", what, cholmod_message);
    else
        fs_error(FS_ERR_INTERNAL, "cholmod: %s failed: %s (status %d)", what,
                 cholmod_status_name(c->common.status), c->common.status);
}

/* A header over the caller's arrays (upper triangle, sorted, packed): CHOLMOD reads them in place. */
static cholmod_sparse wrap_matrix(const fs_sparse_matrix *a)
{
    cholmod_sparse s;
    memset(&s, 0, sizeof s);
    s.nrow = (size_t)a->n;
    s.ncol = (size_t)a->n;
    s.nzmax = (size_t)fs_sparse_matrix_nnz(a);
    s.p = a->col_ptr;
    s.i = a->row_idx;
    s.x = a->values;
    s.stype = 1;
    s.itype = CHOLMOD_INT;
    s.xtype = CHOLMOD_REAL;
    s.dtype = CHOLMOD_DOUBLE;
    s.sorted = 1;
    s.packed = 1;
    return s;
}

void fs_cholesky_free(fs_cholesky *c)
{
    if (!c)
        return;
    cholmod_free_factor(&c->factor, &c->common);
    cholmod_free_factor(&c->symbolic, &c->common);
    cholmod_free_dense(&c->solve_y, &c->common);
    cholmod_free_dense(&c->solve_e, &c->common);
    cholmod_finish(&c->common);
    free(c->inverse_perm);
    free(c);
}

/* design: CHOLMOD's supernodal factorization and solves spend their time in the BLAS, which is
 * whatever libblas.so.3 the system provides (fissure links CHOLMOD only). OpenBLAS, Debian's usual
 * one, runs its kernels on a pool of threads, and its threaded paths round differently from its
 * one-thread path and from each other: with OpenBLAS 0.3.21, dpotrf, dgemm, dtrsm and dgemv give
 * other bits at 2, 3 or 4 threads than at 1 on matrices from about 50 rows, the size of the
 * supernodes of a few thousand elements. That made the fracture sequence, and every map, depend on
 * -j and on the processors (mud-springs, seed 11, 1500 elements: 2934 fractures at -j 1, 2933 at
 * -j 2). The rounding of a kernel cannot be made independent of its split from outside the BLAS,
 * so the BLAS always runs on one thread: its pool is sized when it loads (OPENBLAS_NUM_THREADS,
 * OMP_NUM_THREADS, else the processors), and its run-time entry openblas_set_num_threads, looked up
 * in the process (dlsym, no link-time dependency), is called with 1 before every analysis and
 * factorization, whatever -j and the environment say. It costs next to nothing on the presets (mud:
 * 8.6 to 11 s with one BLAS thread or two on two cores: the supernodes are small); the thread budget
 * goes to the work that splits without changing a bit (sampling, Delaunay blocks, the rasteriser).
 * Another BLAS is left as it is configured.
 *
 * CHOLMOD itself (Debian's, built with OpenMP) opens parallel regions of a fixed 4 threads inside the
 * supernodal factorization to clear and copy each supernode's block: thousands of forks and joins
 * per factorization, each waking threads through futexes, which on two cores cost more than the
 * copies (the shell's whole-sphere factorization at 20k triangles, 10 GFlop: 1.43 s, and 0.77 s with
 * those regions on one thread, with another process running). OpenMP's max-active-levels set to 0
 * (omp_set_max_active_levels, looked up the same way in the libgomp CHOLMOD loads) runs every
 * parallel region on the calling thread; fissure itself uses no OpenMP. */
static void apply_blas_threads(void)
{
    static bool looked_up;
    static void (*set_threads)(int);
    static void (*set_levels)(int);
    if (!looked_up) {
        looked_up = true;
        void *self = dlopen(NULL, RTLD_LAZY);
        if (self) {
            *(void **)(&set_threads) = dlsym(self, "openblas_set_num_threads");
            *(void **)(&set_levels) = dlsym(self, "omp_set_max_active_levels");
            dlclose(self);
        }
        fs_debug("cholmod: BLAS %s; OpenMP regions %s", set_threads ? "on one thread (openblas_set_num_threads)"
                                                                    : "left as configured (not OpenBLAS)",
                 set_levels ? "on the calling thread (omp_set_max_active_levels)" : "absent");
    }
    if (set_threads)
        set_threads(1);
    if (set_levels)
        set_levels(0);
}

typedef enum { ANALYZE_BEST, ANALYZE_SMALL, ANALYZE_GIVEN } analyze_mode;

static fs_cholesky *analyze(const fs_sparse_matrix *a, analyze_mode mode, const int32_t *perm);

fs_cholesky *fs_cholesky_analyze(const fs_sparse_matrix *a)
{
    return analyze(a, ANALYZE_BEST, NULL);
}

fs_cholesky *fs_cholesky_analyze_small(const fs_sparse_matrix *a)
{
    return analyze(a, ANALYZE_SMALL, NULL);
}

fs_cholesky *fs_cholesky_analyze_given(const fs_sparse_matrix *a, const int32_t *perm)
{
    return analyze(a, ANALYZE_GIVEN, perm);
}

const int32_t *fs_cholesky_permutation(const fs_cholesky *c)
{
    return c->symbolic->Perm;
}

static fs_cholesky *analyze(const fs_sparse_matrix *a, analyze_mode mode, const int32_t *perm)
{
    apply_blas_threads();
    fs_cholesky *c = fs_calloc(1, sizeof *c);
    cholmod_message[0] = '\0';
    if (!cholmod_start(&c->common)) {
        report_failure(c, "start");
        free(c);
        return NULL;
    }
    c->common.print = 0;
    c->common.error_handler = store_cholmod_message;
    c->common.quick_return_if_not_posdef = 1;
    /* A simplicial LDL' factorization accepts indefinite matrices with nonzero pivots; LL' stops at the
     * first non-positive pivot, which is the test we want. */
    c->common.final_ll = 1;
    /* design: CHOLMOD's default stops at AMD when AMD fills well. Try METIS's nested dissection as well
     * (its default suite: the user ordering, absent here, AMD, METIS if built in) and keep the one
     * with the least fill: on the wedge layers it gives ~13 % fewer entries in L and a balanced
     * elimination tree, whose short paths make the rank updates after removals ~30 % cheaper
     * (bench_wedge), for a few tens of ms more per analysis. */
    c->common.nmethods = 3;
    if (mode != ANALYZE_BEST) {
        /* fs_cholesky_analyze_small: AMD alone and a simplicial factor (no BLAS calls); _given: the
         * caller's order (CHOLMOD still postorders its elimination tree) */
        c->common.nmethods = 1;
        c->common.method[0].ordering = mode == ANALYZE_GIVEN ? CHOLMOD_GIVEN : CHOLMOD_AMD;
        if (mode == ANALYZE_SMALL)
            c->common.supernodal = CHOLMOD_SIMPLICIAL;
    }
    c->n = a->n;
    c->nnz = fs_sparse_matrix_nnz(a);

    cholmod_sparse view = wrap_matrix(a);
    c->factor = cholmod_analyze_p(&view, (int *)perm, NULL, 0, &c->common);
    if (!c->factor || c->common.status < CHOLMOD_OK) {
        report_failure(c, "analyze");
        fs_cholesky_free(c);
        return NULL;
    }
    c->symbolic = cholmod_copy_factor(c->factor, &c->common);
    if (!c->symbolic) {
        report_failure(c, "copy_factor");
        fs_cholesky_free(c);
        return NULL;
    }
    c->factor_nonzeros = c->common.lnz;
    c->flops = c->common.fl;
    const int *order = c->factor->Perm;
    c->inverse_perm = fs_malloc(((size_t)a->n + 1) * sizeof *c->inverse_perm);
    for (int32_t k = 0; k < a->n; k++)
        c->inverse_perm[order[k]] = k;
    return c;
}

/* Puts the symbolic analysis back as the factor, after an update changed the factor's kind or a failed
 * factorization left it half-written. */
static int restore_symbolic(fs_cholesky *c)
{
    cholmod_free_factor(&c->factor, &c->common);
    c->factor = cholmod_copy_factor(c->symbolic, &c->common);
    if (!c->factor) {
        report_failure(c, "copy_factor");
        return -1;
    }
    c->stale = 0;
    return 0;
}

int fs_cholesky_factorize(fs_cholesky *c, const fs_sparse_matrix *a)
{
    FS_ASSERT(a->n == c->n && fs_sparse_matrix_nnz(a) == c->nnz);
    apply_blas_threads();
    c->valid = 0;
    cholmod_message[0] = '\0';
    if (c->stale && restore_symbolic(c) != 0)
        return -1;

    cholmod_sparse view = wrap_matrix(a);
    int ok = cholmod_factorize(&view, c->factor, &c->common);
    if (c->common.status == CHOLMOD_NOT_POSDEF) {
        size_t minor = c->factor->minor;
        const int *perm = c->factor->Perm;
        c->stale = 1;
        fs_error(FS_ERR_INTERNAL, "cholmod: matrix not positive definite at column %d",
                 minor < (size_t)c->n ? perm[minor] : -1);
        return -1;
    }
    if (!ok || c->common.status < CHOLMOD_OK) {
        c->stale = 1;
        report_failure(c, "factorize");
        return -1;
    }
    c->valid = 1;
    return 0;
}

/* design: the right-hand sides and the solution are dense headers over the caller's arrays. CHOLMOD's
 * cholmod_solve2 keeps a solution matrix that already has the requested size, type and leading dimension
 * (cholmod_ensure_dense), so x is written in place; b is only read. */
int fs_cholesky_solve(fs_cholesky *c, int32_t nrhs, const double *b, double *x)
{
    FS_ASSERT(nrhs >= 0);
    if (!c->valid) {
        fs_error(FS_ERR_INTERNAL, "cholmod: solve without a valid factorization");
        return -1;
    }
    if (nrhs == 0 || c->n == 0)
        return 0;
    cholmod_dense rhs, sol;
    memset(&rhs, 0, sizeof rhs);
    rhs.nrow = (size_t)c->n;
    rhs.ncol = (size_t)nrhs;
    rhs.nzmax = (size_t)c->n * (size_t)nrhs;
    rhs.d = (size_t)c->n;
    rhs.x = (void *)b;
    rhs.xtype = CHOLMOD_REAL;
    rhs.dtype = CHOLMOD_DOUBLE;
    sol = rhs;
    sol.x = x;
    cholmod_dense *solution = &sol;

    cholmod_message[0] = '\0';
    int ok = cholmod_solve2(CHOLMOD_A, c->factor, &rhs, NULL, &solution, NULL, &c->solve_y, &c->solve_e,
                            &c->common);
    FS_ASSERT(solution == &sol);
    if (!ok || c->common.status < CHOLMOD_OK) {
        report_failure(c, "solve");
        return -1;
    }
    return 0;
}

/* Sorts one column of C by row (columns of an update are short), carrying the values along. */
static void sort_column(int *rows, double *values, int32_t len)
{
    for (int32_t k = 1; k < len; k++) {
        int r = rows[k];
        double v = values[k];
        int32_t m = k;
        while (m > 0 && rows[m - 1] > r) {
            rows[m] = rows[m - 1];
            values[m] = values[m - 1];
            m--;
        }
        rows[m] = r;
        values[m] = v;
    }
    for (int32_t k = 1; k < len; k++)
        FS_ASSERT(rows[k] != rows[k - 1]);
}

/* The first column (in CHOLMOD's order) whose pivot D(j,j) of a simplicial LDL' factor is not positive, or
 * -1. cholmod_updown leaves such a factor and does not judge the sign of D, so a downdate that removes
 * more than the matrix holds is caught here; the diagonal is the first entry of each column. */
static int32_t ldl_first_nonpositive_pivot(const cholmod_factor *f)
{
    FS_ASSERT(!f->is_super && !f->is_ll);
    const int *lp = f->p;
    const double *lx = f->x;
    for (size_t j = 0; j < f->n; j++)
        if (!(lx[lp[j]] > 0.0))
            return (int32_t)j;
    return -1;
}

/* design: CHOLMOD factors P A P', so W is permuted into C = P W (row i of W becomes row inverse_perm[i])
 * and each column sorted, as cholmod_updown requires. */
int fs_cholesky_updown(fs_cholesky *c, int sign, int32_t rank, const int32_t *col_ptr,
                       const int32_t *row_idx, const double *values)
{
    FS_ASSERT(rank >= 0 && sign != 0);
    if (!c->valid) {
        fs_error(FS_ERR_INTERNAL, "cholmod: update without a valid factorization");
        return -1;
    }
    if (rank == 0)
        return 0;
    int32_t nz = col_ptr[rank] - col_ptr[0];
    cholmod_message[0] = '\0';
    cholmod_sparse *w = cholmod_allocate_sparse((size_t)c->n, (size_t)rank, (size_t)nz, 1, 1, 0,
                                                CHOLMOD_REAL, &c->common);
    if (!w) {
        report_failure(c, "allocate_sparse");
        return -1;
    }
    int *wp = w->p;
    int *wi = w->i;
    double *wx = w->x;
    for (int32_t j = 0; j <= rank; j++)
        wp[j] = col_ptr[j] - col_ptr[0];
    for (int32_t p = 0; p < nz; p++) {
        int32_t i = row_idx[col_ptr[0] + p];
        FS_ASSERT(i >= 0 && i < c->n);
        wi[p] = c->inverse_perm[i];
        wx[p] = values[col_ptr[0] + p];
    }
    for (int32_t j = 0; j < rank; j++)
        sort_column(wi + wp[j], wx + wp[j], wp[j + 1] - wp[j]);

    int ok = cholmod_updown(sign > 0, w, c->factor, &c->common);
    cholmod_free_sparse(&w, &c->common);
    c->stale = 1;
    if (!ok || c->common.status < CHOLMOD_OK) {
        c->valid = 0;
        report_failure(c, "updown");
        return -1;
    }
    int32_t column = ldl_first_nonpositive_pivot(c->factor);
    if (column >= 0) {
        const int *perm = c->factor->Perm;
        c->valid = 0;
        fs_error(FS_ERR_INTERNAL, "cholmod: matrix not positive definite at column %d after downdate",
                 perm[column]);
        return -1;
    }
    return 0;
}

fs_cholesky_info fs_cholesky_get_info(const fs_cholesky *c)
{
    static const char *const names[] = {"natural", "given", "amd", "metis", "nesdis", "colamd", "postordered"};
    const cholmod_factor *f = c->symbolic;
    fs_cholesky_info info;
    info.n = c->n;
    info.factor_nonzeros = c->factor_nonzeros;
    info.flops = c->flops;
    info.supernodal = f->is_super ? 1 : 0;
    info.ordering = f->ordering >= 0 && f->ordering <= 6 ? names[f->ordering] : "unknown";
    return info;
}
