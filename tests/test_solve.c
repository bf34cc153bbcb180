/* Tests of the sparse solvers: assembly, products, CHOLMOD Cholesky (factor, refactor, update) and CG. */
#include <dlfcn.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "base/error.h"
#include "base/rng.h"
#include "check.h"
#include "solve/cg.h"
#include "solve/node_order.h"
#include "solve/sparse.h"

static const double pi = 3.14159265358979323846;

static double norm2(int32_t n, const double *v)
{
    double s = 0.0;
    for (int32_t i = 0; i < n; i++)
        s += v[i] * v[i];
    return sqrt(s);
}

/* ||a - b|| / ||b||. */
static double relative_difference(int32_t n, const double *a, const double *b)
{
    double d = 0.0;
    for (int32_t i = 0; i < n; i++)
        d += (a[i] - b[i]) * (a[i] - b[i]);
    return sqrt(d) / norm2(n, b);
}

/* ||b - A x|| / ||b||. */
static double relative_residual(const fs_sparse_matrix *a, const double *x, const double *b)
{
    double *ax = malloc((size_t)a->n * sizeof *ax);
    fs_sparse_matvec(a, x, ax);
    double r = relative_difference(a->n, ax, b);
    free(ax);
    return r;
}

static double *random_vector(int32_t n, uint64_t seed)
{
    double *v = malloc((size_t)n * sizeof *v);
    for (int32_t i = 0; i < n; i++)
        v[i] = fs_rand_range(seed, FS_RNG_TEST, (uint64_t)i, -1.0, 1.0);
    return v;
}

/* The 5-point Laplacian on an m×m grid of interior points with zero Dirichlet boundary: eigenvalues
 * 4 sin²(iπ/(2(m+1))) + 4 sin²(jπ/(2(m+1))). */
static void assemble_poisson(int32_t m, fs_sparse_matrix *a)
{
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, m * m, 0);
    for (int32_t y = 0; y < m; y++) {
        for (int32_t x = 0; x < m; x++) {
            int32_t i = y * m + x;
            fs_sparse_builder_add(&b, i, i, 4.0);
            if (x + 1 < m)
                fs_sparse_builder_add(&b, i, i + 1, -1.0);
            if (y + 1 < m)
                fs_sparse_builder_add(&b, i + m, i, -1.0);
        }
    }
    CHECK(fs_sparse_builder_compress(&b, a, NULL) == 0);
    fs_sparse_builder_free(&b);
}

static double poisson_condition(int32_t m)
{
    double lo = sin(pi / (2.0 * (m + 1)));
    double hi = sin(m * pi / (2.0 * (m + 1)));
    return hi * hi / (lo * lo);
}

/* A plane-stress strip of linear (constant-strain) triangles: nx×ny cells of size h, two triangles each,
 * 2 unknowns per node, the bottom row of nodes fixed. Element e has Young's modulus
 * E (1 + variation u_e), u_e uniform in [0, 1) from seed. */
typedef struct {
    int32_t nx, ny;
    int32_t n;        /* unknowns */
    int32_t *dof;     /* per node: first unknown, or -1 if fixed */
} strip;

static strip strip_make(int32_t nx, int32_t ny)
{
    strip s;
    s.nx = nx;
    s.ny = ny;
    s.dof = malloc((size_t)(nx + 1) * (size_t)(ny + 1) * sizeof *s.dof);
    s.n = 0;
    for (int32_t y = 0; y <= ny; y++) {
        for (int32_t x = 0; x <= nx; x++) {
            s.dof[y * (nx + 1) + x] = y == 0 ? -1 : s.n;
            if (y > 0)
                s.n += 2;
        }
    }
    return s;
}

static int32_t strip_elements(const strip *s) { return 2 * s->nx * s->ny; }

/* Global indices (6) and stiffness (6×6, row-major) of element e. */
static void strip_element(const strip *s, int32_t e, double variation, uint64_t seed, int32_t idx[6], double ke[36])
{
    const double young = 1000.0, poisson = 0.3, h = 0.5, thickness = 0.1;
    int32_t cell = e / 2, cx = cell % s->nx, cy = cell / s->nx;
    int32_t n00 = cy * (s->nx + 1) + cx, n10 = n00 + 1, n01 = n00 + s->nx + 1, n11 = n01 + 1;
    int32_t nodes[3];
    if (e % 2 == 0) {
        nodes[0] = n00;
        nodes[1] = n10;
        nodes[2] = n11;
    } else {
        nodes[0] = n00;
        nodes[1] = n11;
        nodes[2] = n01;
    }
    double px[3], py[3];
    for (int a = 0; a < 3; a++) {
        int32_t node = nodes[a];
        px[a] = h * (node % (s->nx + 1));
        py[a] = h * (node / (s->nx + 1));
        int32_t d = s->dof[node];
        idx[2 * a] = d < 0 ? -1 : d;
        idx[2 * a + 1] = d < 0 ? -1 : d + 1;
    }
    double area2 = (px[1] - px[0]) * (py[2] - py[0]) - (px[2] - px[0]) * (py[1] - py[0]);
    double dn_dx[3] = {(py[1] - py[2]) / area2, (py[2] - py[0]) / area2, (py[0] - py[1]) / area2};
    double dn_dy[3] = {(px[2] - px[1]) / area2, (px[0] - px[2]) / area2, (px[1] - px[0]) / area2};
    double bm[3][6] = {{0}};
    for (int a = 0; a < 3; a++) {
        bm[0][2 * a] = dn_dx[a];
        bm[1][2 * a + 1] = dn_dy[a];
        bm[2][2 * a] = dn_dy[a];
        bm[2][2 * a + 1] = dn_dx[a];
    }
    double ee = young * (1.0 + variation * fs_rand01(seed, FS_RNG_TEST, (uint64_t)e));
    double f = ee / (1.0 - poisson * poisson);
    double d[3][3] = {{f, f * poisson, 0.0}, {f * poisson, f, 0.0}, {0.0, 0.0, f * (1.0 - poisson) / 2.0}};
    double volume = 0.5 * area2 * thickness;
    for (int i = 0; i < 6; i++) {
        for (int j = 0; j < 6; j++) {
            double sum = 0.0;
            for (int k = 0; k < 3; k++)
                for (int l = 0; l < 3; l++)
                    sum += bm[k][i] * d[k][l] * bm[l][j];
            ke[i * 6 + j] = volume * sum;
        }
    }
}

/* Assembles the strip; if first is not NULL it receives each element's first entry number. */
static void strip_assemble(const strip *s, double variation, uint64_t seed, fs_sparse_matrix *a, int32_t **slots,
                           size_t *first)
{
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, s->n, (size_t)strip_elements(s) * 21);
    for (int32_t e = 0; e < strip_elements(s); e++) {
        int32_t idx[6];
        double ke[36];
        strip_element(s, e, variation, seed, idx, ke);
        if (first)
            first[e] = b.count;
        fs_sparse_builder_add_block(&b, 6, idx, ke);
    }
    if (slots)
        *slots = malloc(b.count * sizeof **slots);
    CHECK(fs_sparse_builder_compress(&b, a, slots ? *slots : NULL) == 0);
    fs_sparse_builder_free(&b);
}

static void test_builder_sums_duplicates(void)
{
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, 4, 2);
    fs_sparse_builder_add(&b, 0, 0, 1.0);
    fs_sparse_builder_add(&b, 1, 0, 2.0);
    fs_sparse_builder_add(&b, 0, 1, 3.0);
    fs_sparse_builder_add(&b, 2, 2, 5.0);
    fs_sparse_builder_add(&b, 3, 1, -1.0);
    fs_sparse_builder_add(&b, 2, 2, 0.5);
    CHECK(fs_sparse_builder_add(&b, 1, 3, 4.0) == 6);
    int32_t slots[7];
    fs_sparse_matrix m;
    CHECK(fs_sparse_builder_compress(&b, &m, slots) == 0);

    const int32_t col_ptr[] = {0, 1, 3, 4, 6};
    const int32_t row_idx[] = {0, 0, 1, 2, 1, 3};
    const double values[] = {1.0, 5.0, 0.0, 5.5, 3.0, 0.0};
    const int32_t expected_slots[] = {0, 1, 1, 3, 4, 3, 4};
    CHECK(m.n == 4 && fs_sparse_matrix_nnz(&m) == 6);
    for (int j = 0; j <= 4; j++)
        CHECK(m.col_ptr[j] == col_ptr[j]);
    for (int p = 0; p < 6; p++) {
        CHECK(m.row_idx[p] == row_idx[p]);
        CHECK(m.values[p] == values[p]);
    }
    for (int e = 0; e < 7; e++)
        CHECK(slots[e] == expected_slots[e]);
    fs_sparse_matrix_free(&m);
    fs_sparse_builder_free(&b);
}

/* A builder cleared and reused for patterns of other orders and sizes (as a model rebuilds its
 * pattern after each cut) compresses each exactly as a fresh builder does. */
static void test_builder_reused(void)
{
    fs_sparse_builder reused;
    fs_sparse_builder_init(&reused, 1, 0);
    const int32_t orders[] = {9, 3, 20, 5};
    for (int round = 0; round < 4; round++) {
        int32_t n = orders[round];
        fs_sparse_builder fresh;
        fs_sparse_builder_init(&fresh, n, 0);
        fs_sparse_builder_clear(&reused, n);
        for (int32_t e = 0; e < 6 * n; e++) { /* a fixed pseudo-random sequence of entries */
            int32_t r = (int32_t)((e * 7 + round * 3) % n), c = (int32_t)((e * 13 + 5) % n);
            double v = 1.0 + 0.25 * e - round;
            fs_sparse_builder_add(&fresh, r, c, v);
            fs_sparse_builder_add(&reused, r, c, v);
        }
        int32_t slots_a[6 * 20], slots_b[6 * 20];
        fs_sparse_matrix a, b;
        CHECK(fs_sparse_builder_compress(&fresh, &a, slots_a) == 0);
        CHECK(fs_sparse_builder_compress(&reused, &b, slots_b) == 0);
        CHECK(a.n == n && b.n == n && fs_sparse_matrix_nnz(&a) == fs_sparse_matrix_nnz(&b));
        for (int32_t j = 0; j <= n; j++)
            CHECK(a.col_ptr[j] == b.col_ptr[j]);
        for (int32_t p = 0; p < fs_sparse_matrix_nnz(&a); p++)
            CHECK(a.row_idx[p] == b.row_idx[p] && a.values[p] == b.values[p]);
        for (int32_t e = 0; e < 6 * n; e++)
            CHECK(slots_a[e] == slots_b[e]);
        fs_sparse_matrix_free(&a);
        fs_sparse_matrix_free(&b);
        fs_sparse_builder_free(&fresh);
    }
    fs_sparse_builder_free(&reused);
}

/* Random entries, some columns holding more distinct rows than a small sort handles: every column's
 * rows strictly increasing with its diagonal, every value the sum of its pair's entries in entry
 * order (against a dense sum made in the same order, bit for bit), every slot at its pair. */
static void test_builder_random_columns(void)
{
    const int32_t n = 120;
    const size_t count = 6000;
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, n, 0);
    double *dense = calloc((size_t)n * n, sizeof *dense);
    int32_t *rows = malloc(count * sizeof *rows), *cols = malloc(count * sizeof *cols);
    for (size_t e = 0; e < count; e++) {
        /* column 7 and the last ten collect many rows */
        int32_t c = e % 3 == 0 ? (e % 2 ? 7 : n - 1 - (int32_t)(e % 10))
                               : (int32_t)(fs_rand01(5, FS_RNG_TEST, 2 * e) * n);
        int32_t r = (int32_t)(fs_rand01(5, FS_RNG_TEST, 2 * e + 1) * n);
        double v = fs_rand_range(5, FS_RNG_TEST, 1000000 + e, -1.0, 1.0);
        fs_sparse_builder_add(&b, r, c, v);
        rows[e] = r < c ? r : c;
        cols[e] = r < c ? c : r;
        dense[(size_t)cols[e] * n + rows[e]] += v;
    }
    int32_t *slots = malloc(count * sizeof *slots);
    fs_sparse_matrix m;
    CHECK(fs_sparse_builder_compress(&b, &m, slots) == 0);
    int bad = 0, wide = 0;
    for (int32_t j = 0; j < n; j++) {
        wide += m.col_ptr[j + 1] - m.col_ptr[j] > 48;
        bad += m.row_idx[m.col_ptr[j + 1] - 1] != j;
        for (int32_t p = m.col_ptr[j]; p < m.col_ptr[j + 1]; p++) {
            bad += p > m.col_ptr[j] && m.row_idx[p] <= m.row_idx[p - 1];
            bad += m.values[p] != dense[(size_t)j * n + m.row_idx[p]];
        }
    }
    for (size_t e = 0; e < count; e++)
        bad += slots[e] < m.col_ptr[cols[e]] || slots[e] >= m.col_ptr[cols[e] + 1] || m.row_idx[slots[e]] != rows[e];
    CHECK_MSG(bad == 0 && wide > 0, "%d wrong entries or slots (%d columns past a small sort)", bad, wide);
    fs_sparse_matrix_free(&m);
    fs_sparse_builder_free(&b);
    free(dense);
    free(rows);
    free(cols);
    free(slots);
}

static void test_matvec_matches_dense(void)
{
    enum { n = 7 };
    double dense[n][n];
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, n, 0);
    for (int i = 0; i < n; i++) {
        for (int j = i; j < n; j++) {
            double u = fs_rand01(11, FS_RNG_TEST, (uint64_t)(i * n + j));
            double v = u < 0.4 ? 0.0 : 2.0 * u - 1.0;
            dense[i][j] = dense[j][i] = v;
            if (v != 0.0)
                fs_sparse_builder_add(&b, j, i, v);
        }
    }
    fs_sparse_matrix m;
    CHECK(fs_sparse_builder_compress(&b, &m, NULL) == 0);
    double *x = random_vector(n, 12);
    double y[n];
    fs_sparse_matvec(&m, x, y);
    for (int i = 0; i < n; i++) {
        double s = 0.0;
        for (int j = 0; j < n; j++)
            s += dense[i][j] * x[j];
        CHECK_NEAR(y[i], s, 1e-14);
    }
    free(x);
    fs_sparse_matrix_free(&m);
    fs_sparse_builder_free(&b);
}

/* A principal submatrix holds exactly the entries between the listed unknowns, renumbered, in the
 * storage rules (rows ascending, diagonal last), and leaves the scratch map as it found it. */
static void test_principal_submatrix(void)
{
    enum { n = 7, m = 4 };
    double dense[n][n];
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, n, 0);
    for (int i = 0; i < n; i++) {
        for (int j = i; j < n; j++) {
            double u = fs_rand01(13, FS_RNG_TEST, (uint64_t)(i * n + j));
            double v = u < 0.4 && i != j ? 0.0 : 2.0 * u - 1.0;
            dense[i][j] = dense[j][i] = v;
            if (v != 0.0)
                fs_sparse_builder_add(&b, i, j, v);
        }
    }
    fs_sparse_matrix a;
    CHECK(fs_sparse_builder_compress(&b, &a, NULL) == 0);
    const int32_t idx[m] = {1, 2, 4, 6};
    int32_t map[n];
    for (int i = 0; i < n; i++)
        map[i] = -1;
    fs_sparse_matrix sub = {0};
    fs_sparse_matrix_principal(&a, idx, m, map, &sub);
    CHECK(sub.n == m);
    for (int i = 0; i < n; i++)
        CHECK(map[i] == -1);
    int32_t expected_nnz = 0;
    for (int c = 0; c < m; c++) {
        for (int r = 0; r <= c; r++)
            expected_nnz += dense[idx[r]][idx[c]] != 0.0;
        CHECK(sub.row_idx[sub.col_ptr[c + 1] - 1] == c);
        for (int32_t p = sub.col_ptr[c]; p < sub.col_ptr[c + 1]; p++) {
            CHECK(p == sub.col_ptr[c] || sub.row_idx[p] > sub.row_idx[p - 1]);
            CHECK(sub.values[p] == dense[idx[sub.row_idx[p]]][idx[c]]);
        }
    }
    CHECK(fs_sparse_matrix_nnz(&sub) == expected_nnz);
    fs_sparse_matrix_free(&sub);
    fs_sparse_matrix_free(&a);
    fs_sparse_builder_free(&b);
}

/* Rewriting the values through the slots after a material change reproduces a fresh assembly exactly. */
static void test_slots_reproduce_fresh_assembly(void)
{
    strip s = strip_make(12, 9);
    int32_t ne = strip_elements(&s);
    size_t *first = malloc((size_t)ne * sizeof *first);
    int32_t *slots;
    fs_sparse_matrix a, fresh;
    strip_assemble(&s, 0.5, 1, &a, &slots, first);
    strip_assemble(&s, 0.8, 2, &fresh, NULL, NULL);

    fs_sparse_matrix_zero(&a);
    for (int32_t e = 0; e < ne; e++) {
        int32_t idx[6];
        double ke[36];
        strip_element(&s, e, 0.8, 2, idx, ke);
        fs_sparse_matrix_add_block(&a, 6, idx, ke, slots + first[e]);
    }
    CHECK(a.n == fresh.n && fs_sparse_matrix_nnz(&a) == fs_sparse_matrix_nnz(&fresh));
    int same = 1;
    for (int32_t j = 0; j <= a.n; j++)
        same &= a.col_ptr[j] == fresh.col_ptr[j];
    for (int32_t p = 0; p < fs_sparse_matrix_nnz(&a); p++)
        same &= a.row_idx[p] == fresh.row_idx[p] && a.values[p] == fresh.values[p];
    CHECK_MSG(same, "slot update differs from a fresh assembly");
    free(first);
    free(slots);
    free(s.dof);
    fs_sparse_matrix_free(&a);
    fs_sparse_matrix_free(&fresh);
}

static void test_cholesky_solves_poisson(void)
{
    enum { m = 50, n = m * m, nrhs = 3 };
    fs_sparse_matrix a;
    assemble_poisson(m, &a);
    double *b = random_vector(n * nrhs, 3);
    double *x = malloc((size_t)n * nrhs * sizeof *x);
    double *x1 = malloc((size_t)n * sizeof *x1);
    fs_cholesky *c = fs_cholesky_analyze(&a);
    CHECK(c != NULL);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_solve(c, 1, b, x1) == 0);
    CHECK_MSG(relative_residual(&a, x1, b) <= 1e-10, "residual %g", relative_residual(&a, x1, b));
    CHECK(fs_cholesky_solve(c, nrhs, b, x) == 0);
    for (int r = 0; r < nrhs; r++)
        CHECK_MSG(relative_residual(&a, x + r * n, b + r * n) <= 1e-10, "rhs %d", r);
    CHECK(relative_difference(n, x, x1) <= 1e-13);
    fs_cholesky_info info = fs_cholesky_get_info(c);
    CHECK(info.n == n && info.factor_nonzeros >= fs_sparse_matrix_nnz(&a) && info.flops > 0.0);
    fs_cholesky_free(c);
    free(b);
    free(x);
    free(x1);
    fs_sparse_matrix_free(&a);
}


/* A graph for the kept order's test: nodes with up to 8 neighbours each. */
typedef struct {
    int32_t n, nb[2000][8], count[2000];
} graph;

static void graph_link(graph *g, int32_t a, int32_t b)
{
    g->nb[a][g->count[a]++] = b;
    g->nb[b][g->count[b]++] = a;
}

static int32_t graph_neighbours(void *ctx, int32_t i, int32_t *out, int32_t cap)
{
    const graph *g = ctx;
    for (int32_t k = 0; k < g->count[i] && k < cap; k++)
        out[k] = g->nb[i][k];
    return g->count[i];
}

/* The graph's Laplacian plus 4 on the diagonal (positive definite), one unknown a node. */
static void graph_matrix(const graph *g, fs_sparse_matrix *a)
{
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, g->n, 0);
    for (int32_t i = 0; i < g->n; i++) {
        fs_sparse_builder_add(&b, i, i, 4.0 + g->count[i]);
        for (int32_t k = 0; k < g->count[i]; k++)
            if (g->nb[i][k] > i)
                fs_sparse_builder_add(&b, i, g->nb[i][k], -1.0);
    }
    CHECK(fs_sparse_builder_compress(&b, a, NULL) == 0);
    fs_sparse_builder_free(&b);
}

/* The order kept across cuts (solve/node_order.h): ordered afresh the first time; after a cut
 * (a column of nodes duplicated, the copies taking over their links to the right, and one node with
 * no origin) analysed in the kept order, each copy at its origin's place and the orphan after its
 * last neighbour, solving as well; ordered afresh again when the kept order has been spoilt. */
static void test_node_order_kept_across_cuts(void)
{
    enum { m = 40, nn = m * m };
    graph *g = calloc(1, sizeof *g);
    g->n = nn;
    for (int32_t y = 0; y < m; y++)
        for (int32_t x = 0; x < m; x++) {
            if (x + 1 < m)
                graph_link(g, y * m + x, y * m + x + 1);
            if (y + 1 < m)
                graph_link(g, y * m + x, (y + 1) * m + x);
        }
    int32_t dof[2000], origin[2000];
    for (int32_t i = 0; i < 2000; i++)
        dof[i] = origin[i] = i;
    fs_node_order o = {0};
    fs_sparse_matrix a;
    graph_matrix(g, &a);
    fs_node_dofs dofs = {dof, 1, 0, 1, nn};
    bool fresh = false;
    fs_cholesky *c = fs_node_order_analyze(&o, &a, nn, &dofs, origin, graph_neighbours, g, &fresh);
    CHECK(c != NULL && fresh && o.n_nodes == nn && o.flops == fs_cholesky_get_info(c).flops);
    fs_cholesky_free(c);
    fs_sparse_matrix_free(&a);

    /* the cut between columns 20 and 21: the copies of column 20 link to column 21 and to each other */
    for (int32_t y = 0; y < m; y++) {
        int32_t old = y * m + 20, right = old + 1, copy = nn + y;
        for (int32_t k = 0; k < g->count[old]; k++)
            if (g->nb[old][k] == right)
                g->nb[old][k] = g->nb[old][--g->count[old]];
        for (int32_t k = 0; k < g->count[right]; k++)
            if (g->nb[right][k] == old)
                g->nb[right][k] = g->nb[right][--g->count[right]];
        graph_link(g, copy, right);
        if (y > 0)
            graph_link(g, copy, copy - 1);
        origin[copy] = old;
    }
    int32_t orphan = nn + m;
    graph_link(g, orphan, 5);
    graph_link(g, orphan, 700);
    origin[orphan] = -1;
    g->n = nn + m + 1;
    graph_matrix(g, &a);
    dofs.n = g->n;
    int32_t rank5 = o.rank[5], rank700 = o.rank[700];
    c = fs_node_order_analyze(&o, &a, g->n, &dofs, origin, graph_neighbours, g, &fresh);
    CHECK(c != NULL && !fresh && !strcmp(fs_cholesky_get_info(c).ordering, "given"));
    CHECK(fs_cholesky_get_info(c).flops <= FS_NODE_REORDER * o.flops);
    int misplaced = 0;
    for (int32_t y = 0; y < m; y++)
        misplaced += o.rank[nn + y] != o.rank[y * m + 20];
    CHECK_MSG(misplaced == 0, "%d copies away from their origins", misplaced);
    CHECK(o.rank[orphan] == (rank5 > rank700 ? rank5 : rank700));
    double *b = random_vector(g->n, 9), *x = malloc((size_t)g->n * sizeof *x);
    CHECK(fs_cholesky_factorize(c, &a) == 0 && fs_cholesky_solve(c, 1, b, x) == 0);
    CHECK_MSG(relative_residual(&a, x, b) <= 1e-10, "residual %g", relative_residual(&a, x, b));
    fs_cholesky_free(c);

    /* a spoilt order (the nodes scattered) fills far more: ordered afresh */
    for (int32_t i = 0; i < g->n; i++)
        o.rank[i] = (int32_t)(((int64_t)i * 7919) % g->n);
    c = fs_node_order_analyze(&o, &a, g->n, &dofs, origin, graph_neighbours, g, &fresh);
    CHECK(c != NULL && fresh && strcmp(fs_cholesky_get_info(c).ordering, "given") != 0);
    fs_cholesky_free(c);
    fs_node_order_free(&o);
    CHECK(o.rank == NULL);
    fs_sparse_matrix_free(&a);
    free(b);
    free(x);
    free(g);
}

/* An analysis in a given order solves as well, reports that order (up to CHOLMOD's postorder, still a
 * permutation), and the order of a fresh analysis given back fills the same. */
static void test_cholesky_given_order(void)
{
    enum { m = 30, n = m * m };
    fs_sparse_matrix a;
    assemble_poisson(m, &a);
    double *b = random_vector(n, 4), *x = malloc((size_t)n * sizeof *x);
    fs_cholesky *fresh = fs_cholesky_analyze(&a);
    CHECK(fresh != NULL);
    int32_t *perm = malloc((size_t)n * sizeof *perm);
    memcpy(perm, fs_cholesky_permutation(fresh), (size_t)n * sizeof *perm);
    fs_cholesky *again = fs_cholesky_analyze_given(&a, perm);
    CHECK(again != NULL && !strcmp(fs_cholesky_get_info(again).ordering, "given"));
    CHECK(fs_cholesky_get_info(again).factor_nonzeros == fs_cholesky_get_info(fresh).factor_nonzeros);
    /* the natural order of a grid, row by row: a band, more fill than nested dissection, solving alike */
    for (int32_t k = 0; k < n; k++)
        perm[k] = k;
    fs_cholesky *band = fs_cholesky_analyze_given(&a, perm);
    CHECK(band != NULL && fs_cholesky_get_info(band).factor_nonzeros > fs_cholesky_get_info(fresh).factor_nonzeros);
    const int32_t *got = fs_cholesky_permutation(band);
    int32_t *seen = calloc(n, sizeof *seen);
    int bad = 0;
    for (int32_t k = 0; k < n; k++)
        bad += got[k] < 0 || got[k] >= n || seen[got[k]]++;
    CHECK(bad == 0);
    CHECK(fs_cholesky_factorize(band, &a) == 0 && fs_cholesky_solve(band, 1, b, x) == 0);
    CHECK_MSG(relative_residual(&a, x, b) <= 1e-10, "residual %g", relative_residual(&a, x, b));
    fs_cholesky_free(fresh);
    fs_cholesky_free(again);
    fs_cholesky_free(band);
    free(seen);
    free(perm);
    free(b);
    free(x);
    fs_sparse_matrix_free(&a);
}

static void test_cholesky_solves_elasticity(void)
{
    strip s = strip_make(60, 60);
    fs_sparse_matrix a;
    strip_assemble(&s, 0.5, 4, &a, NULL, NULL);
    double *b = random_vector(s.n, 5);
    double *x = malloc((size_t)s.n * sizeof *x);
    fs_cholesky *c = fs_cholesky_analyze(&a);
    CHECK(c != NULL);
    fs_cholesky_info info = fs_cholesky_get_info(c);
    CHECK_MSG(info.supernodal == 1, "a 2-D elasticity matrix of %d unknowns should get a supernodal factor", s.n);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_solve(c, 1, b, x) == 0);
    CHECK_MSG(relative_residual(&a, x, b) <= 1e-10, "residual %g", relative_residual(&a, x, b));
    fs_cholesky_free(c);
    free(b);
    free(x);
    free(s.dof);
    fs_sparse_matrix_free(&a);
}

/* Refactorizing after scaling every value by s gives the solution divided by s. */
static void test_refactorize_scaled_values(void)
{
    const double scale = 3.5;
    strip s = strip_make(40, 30);
    fs_sparse_matrix a;
    strip_assemble(&s, 0.5, 6, &a, NULL, NULL);
    double *b = random_vector(s.n, 7);
    double *x1 = malloc((size_t)s.n * sizeof *x1);
    double *x2 = malloc((size_t)s.n * sizeof *x2);
    fs_cholesky *c = fs_cholesky_analyze(&a);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_solve(c, 1, b, x1) == 0);
    for (int32_t p = 0; p < fs_sparse_matrix_nnz(&a); p++)
        a.values[p] *= scale;
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_solve(c, 1, b, x2) == 0);
    for (int32_t i = 0; i < s.n; i++)
        x2[i] *= scale;
    CHECK(relative_difference(s.n, x2, x1) <= 1e-12);
    fs_cholesky_free(c);
    free(b);
    free(x1);
    free(x2);
    free(s.dof);
    fs_sparse_matrix_free(&a);
}

/* Adds W W' (W given by columns in CSC) into a builder: each unordered pair once. */
static void add_outer(fs_sparse_builder *b, int32_t rank, const int32_t *col_ptr, const int32_t *rows,
                      const double *w)
{
    for (int32_t j = 0; j < rank; j++)
        for (int32_t p = col_ptr[j]; p < col_ptr[j + 1]; p++)
            for (int32_t q = p; q < col_ptr[j + 1]; q++)
                fs_sparse_builder_add(b, rows[p], rows[q], w[p] * w[q]);
}

/* A rank-2 update W W' matches a fresh factorization of A + W W'; the downdate brings back the solution of
 * A; refactorizing A after an update discards it and starts again from the analysis. */
static void test_updown_matches_fresh_factorization(void)
{
    strip s = strip_make(40, 30);
    int32_t ne = strip_elements(&s);
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, s.n, 0);
    for (int32_t e = 0; e < ne; e++) {
        int32_t idx[6];
        double ke[36];
        strip_element(&s, e, 0.5, 8, idx, ke);
        fs_sparse_builder_add_block(&b, 6, idx, ke);
    }
    fs_sparse_matrix a, a_plus;
    CHECK(fs_sparse_builder_compress(&b, &a, NULL) == 0);

    /* Two spring-like columns: sqrt(k) (e_i - e_j) on an x and a y unknown of neighbouring nodes, and a
     * column touching rows far apart. */
    const int32_t col_ptr[] = {0, 2, 5};
    int32_t rows[] = {100, 102, s.n - 1, 7, s.n / 2};
    double w[] = {30.0, -30.0, 12.0, -5.0, 8.0};
    add_outer(&b, 2, col_ptr, rows, w);
    CHECK(fs_sparse_builder_compress(&b, &a_plus, NULL) == 0);

    double *rhs = random_vector(s.n, 9);
    double *x = malloc((size_t)s.n * sizeof *x);
    double *x_orig = malloc((size_t)s.n * sizeof *x_orig);
    double *x_fresh = malloc((size_t)s.n * sizeof *x_fresh);

    fs_cholesky *fresh = fs_cholesky_analyze(&a_plus);
    CHECK(fs_cholesky_factorize(fresh, &a_plus) == 0);
    CHECK(fs_cholesky_solve(fresh, 1, rhs, x_fresh) == 0);

    fs_cholesky *c = fs_cholesky_analyze(&a);
    int supernodal = fs_cholesky_get_info(c).supernodal;
    CHECK_MSG(supernodal == 1, "the update should start from a supernodal factor (converted to LDL' by CHOLMOD)");
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_solve(c, 1, rhs, x_orig) == 0);
    CHECK(fs_cholesky_updown(c, +1, 2, col_ptr, rows, w) == 0);
    CHECK(fs_cholesky_solve(c, 1, rhs, x) == 0);
    CHECK_MSG(relative_difference(s.n, x, x_fresh) <= 1e-10, "update: %g", relative_difference(s.n, x, x_fresh));
    CHECK(relative_residual(&a_plus, x, rhs) <= 1e-10);
    CHECK(fs_cholesky_updown(c, -1, 2, col_ptr, rows, w) == 0);
    CHECK(fs_cholesky_solve(c, 1, rhs, x) == 0);
    CHECK_MSG(relative_difference(s.n, x, x_orig) <= 1e-10, "downdate: %g", relative_difference(s.n, x, x_orig));

    CHECK(fs_cholesky_updown(c, +1, 2, col_ptr, rows, w) == 0);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_get_info(c).supernodal == supernodal);
    CHECK(fs_cholesky_solve(c, 1, rhs, x) == 0);
    CHECK(relative_difference(s.n, x, x_orig) <= 1e-12);

    fs_cholesky_free(c);
    fs_cholesky_free(fresh);
    free(rhs);
    free(x);
    free(x_orig);
    free(x_fresh);
    free(s.dof);
    fs_sparse_builder_free(&b);
    fs_sparse_matrix_free(&a);
    fs_sparse_matrix_free(&a_plus);
}

/* Output capture, to assert that a failing call prints nothing. */
typedef struct {
    FILE *file;
    int saved_out, saved_err;
} capture;

static capture capture_begin(void)
{
    capture cap;
    fflush(stdout);
    fflush(stderr);
    cap.file = tmpfile();
    cap.saved_out = dup(1);
    cap.saved_err = dup(2);
    dup2(fileno(cap.file), 1);
    dup2(fileno(cap.file), 2);
    return cap;
}

static long capture_end(capture cap)
{
    fflush(stdout);
    fflush(stderr);
    dup2(cap.saved_out, 1);
    dup2(cap.saved_err, 2);
    close(cap.saved_out);
    close(cap.saved_err);
    fseek(cap.file, 0, SEEK_END);
    long size = ftell(cap.file);
    fclose(cap.file);
    return size;
}

static int starts_with(const char *s, const char *prefix) { return strncmp(s, prefix, strlen(prefix)) == 0; }

/* An indefinite matrix gives -1 and FS_ERR_INTERNAL naming the failing column, prints nothing, blocks
 * solves, and a later positive definite matrix with the same pattern factorizes again. */
static void test_indefinite_matrix_fails_cleanly(void)
{
    enum { n = 20, bad = 7 };
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, n, 0);
    for (int32_t i = 0; i < n; i++)
        fs_sparse_builder_add(&b, i, i, i == bad ? -1.0 : 2.0 + i);
    fs_sparse_matrix d;
    CHECK(fs_sparse_builder_compress(&b, &d, NULL) == 0);
    fs_sparse_builder_free(&b);
    fs_cholesky *c = fs_cholesky_analyze(&d);
    fs_error_clear();
    capture cap = capture_begin();
    int status = fs_cholesky_factorize(c, &d);
    long printed = capture_end(cap);
    CHECK(status == -1);
    CHECK(fs_error_domain() == FS_ERR_INTERNAL);
    CHECK_MSG(strcmp(fs_error_message(), "cholmod: matrix not positive definite at column 7") == 0, "%s",
              fs_error_message());
    CHECK(printed == 0);
    double rhs[n], x[n];
    for (int i = 0; i < n; i++)
        rhs[i] = 1.0;
    CHECK(fs_cholesky_solve(c, 1, rhs, x) == -1);
    d.values[bad] = 1.0;
    CHECK(fs_cholesky_factorize(c, &d) == 0);
    CHECK(fs_cholesky_solve(c, 1, rhs, x) == 0);
    CHECK_NEAR(x[bad], 1.0, 1e-15);
    CHECK_NEAR(x[3], 1.0 / 5.0, 1e-15);
    fs_cholesky_free(c);
    fs_sparse_matrix_free(&d);

    /* Poisson shifted by -5 I has eigenvalues on both sides of 0 (its spectrum is inside (0, 8)). */
    fs_sparse_matrix a;
    assemble_poisson(30, &a);
    for (int32_t j = 0; j < a.n; j++)
        a.values[a.col_ptr[j + 1] - 1] -= 5.0;
    c = fs_cholesky_analyze(&a);
    fs_error_clear();
    cap = capture_begin();
    status = fs_cholesky_factorize(c, &a);
    printed = capture_end(cap);
    CHECK(status == -1 && fs_error_domain() == FS_ERR_INTERNAL);
    CHECK_MSG(starts_with(fs_error_message(), "cholmod: matrix not positive definite at column "), "%s",
              fs_error_message());
    CHECK(printed == 0);
    fs_cholesky_free(c);
    fs_sparse_matrix_free(&a);

    /* The same through the supernodal factorization: a negative diagonal entry in column k of an SPD
     * matrix makes k the first non-positive pivot whatever the ordering (every pivot eliminated before it
     * belongs to a positive definite principal submatrix). */
    strip s = strip_make(60, 60);
    const int32_t k = 1234;
    strip_assemble(&s, 0.5, 14, &a, NULL, NULL);
    a.values[a.col_ptr[k + 1] - 1] = -1.0;
    c = fs_cholesky_analyze(&a);
    CHECK(fs_cholesky_get_info(c).supernodal == 1);
    fs_error_clear();
    cap = capture_begin();
    status = fs_cholesky_factorize(c, &a);
    printed = capture_end(cap);
    CHECK(status == -1 && fs_error_domain() == FS_ERR_INTERNAL);
    CHECK_MSG(strcmp(fs_error_message(), "cholmod: matrix not positive definite at column 1234") == 0, "%s",
              fs_error_message());
    CHECK(printed == 0);
    fs_cholesky_free(c);
    fs_sparse_matrix_free(&a);
    free(s.dof);
}

/* A downdate that removes more than the matrix holds fails without printing. */
static void test_downdate_to_indefinite_fails(void)
{
    fs_sparse_matrix a;
    assemble_poisson(20, &a);
    fs_cholesky *c = fs_cholesky_analyze(&a);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    const int32_t col_ptr[] = {0, 1};
    const int32_t rows[] = {150};
    const double w[] = {3.0};
    fs_error_clear();
    capture cap = capture_begin();
    int status = fs_cholesky_updown(c, -1, 1, col_ptr, rows, w);
    long printed = capture_end(cap);
    CHECK(status == -1 && fs_error_domain() == FS_ERR_INTERNAL);
    CHECK_MSG(strcmp(fs_error_message(), "cholmod: matrix not positive definite at column 150 after downdate") == 0,
              "%s", fs_error_message());
    CHECK(printed == 0);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    fs_cholesky_free(c);
    fs_sparse_matrix_free(&a);
}

/* CG reaches its tolerance on the true residual, and then differs from the Cholesky solution by at most
 * cond(A) times that tolerance (Poisson's condition number is known in closed form). */
static void test_cg_agrees_with_cholesky(void)
{
    enum { m = 30, n = m * m };
    const double tolerance = 1e-10;
    fs_sparse_matrix a;
    assemble_poisson(m, &a);
    double *b = random_vector(n, 10);
    double *x_chol = malloc(n * sizeof *x_chol);
    double *x = calloc(n, sizeof *x);
    fs_cholesky *c = fs_cholesky_analyze(&a);
    CHECK(fs_cholesky_factorize(c, &a) == 0);
    CHECK(fs_cholesky_solve(c, 1, b, x_chol) == 0);

    fs_cg_params params = fs_cg_params_default();
    params.tolerance = tolerance;
    double reported;
    int iterations = fs_cg_solve(&a, b, x, params, &reported);
    CHECK_MSG(iterations > 0 && iterations < n, "iterations %d", iterations);
    double residual = relative_residual(&a, x, b);
    CHECK_MSG(residual <= tolerance, "residual %g", residual);
    CHECK_NEAR(reported, residual, 1e-14);
    double kappa = poisson_condition(m);
    CHECK_MSG(relative_difference(n, x, x_chol) <= kappa * tolerance, "error %g, bound %g",
              relative_difference(n, x, x_chol), kappa * tolerance);

    for (int32_t i = 0; i < n; i++)
        x[i] = x_chol[i];
    CHECK(fs_cg_solve(&a, b, x, params, NULL) == 0);
    fs_cholesky_free(c);
    free(b);
    free(x);
    free(x_chol);
    fs_sparse_matrix_free(&a);
}

static void test_cg_reports_failures(void)
{
    enum { m = 30, n = m * m };
    fs_sparse_matrix a;
    assemble_poisson(m, &a);
    double *b = random_vector(n, 13);
    double *x = calloc(n, sizeof *x);
    fs_cg_params params = fs_cg_params_default();
    params.tolerance = 1e-10;
    params.max_iterations = 2;
    fs_error_clear();
    double reported = 0.0;
    CHECK(fs_cg_solve(&a, b, x, params, &reported) == -1);
    CHECK(fs_error_domain() == FS_ERR_INTERNAL);
    CHECK_MSG(starts_with(fs_error_message(), "cg: no convergence after 2 iterations (relative residual "), "%s",
              fs_error_message());
    CHECK(reported > params.tolerance);

    for (int32_t i = 0; i < n; i++)
        x[i] = 0.0;
    a.values[a.col_ptr[5] - 1] = 0.0;
    fs_error_clear();
    CHECK(fs_cg_solve(&a, b, x, fs_cg_params_default(), NULL) == -1);
    CHECK(fs_error_domain() == FS_ERR_INTERNAL);
    CHECK_MSG(starts_with(fs_error_message(), "cg: diagonal entry 4 "), "%s", fs_error_message());
    free(b);
    free(x);
    fs_sparse_matrix_free(&a);
}

/* ---- fs_pcg on an operator ---- */

/* A matrix as an operator with the Jacobi preconditioner, and a Euclidean stopping rule. */
typedef struct {
    const fs_sparse_matrix *a;
    double *inv_diag;
    double limit;
    int32_t applies, fail_after; /* products so far; the preconditioner fails after this many calls (< 0: never) */
    int32_t preconditions;
    fs_cg_sum sum;
} matrix_op;

static void matrix_apply(void *ctx, const double *x, double *y)
{
    matrix_op *o = ctx;
    o->applies++;
    fs_sparse_matvec(o->a, x, y);
}

static int matrix_precondition(void *ctx, const double *r, double *z)
{
    matrix_op *o = ctx;
    if (o->fail_after >= 0 && o->preconditions++ >= o->fail_after) {
        fs_error(FS_ERR_INTERNAL, "test: preconditioner failed");
        return -1;
    }
    for (int32_t i = 0; i < o->a->n; i++)
        z[i] = o->inv_diag[i] * r[i];
    return 0;
}

static bool matrix_converged(void *ctx, const double *r)
{
    const matrix_op *o = ctx;
    return sqrt(fs_cg_dot(o->a->n, r, r, o->sum)) <= o->limit;
}

static void matrix_op_init(matrix_op *o, const fs_sparse_matrix *a, double limit, fs_cg_sum sum)
{
    memset(o, 0, sizeof *o);
    o->a = a;
    o->limit = limit;
    o->fail_after = -1;
    o->sum = sum;
    o->inv_diag = malloc((size_t)a->n * sizeof *o->inv_diag);
    for (int32_t j = 0; j < a->n; j++)
        o->inv_diag[j] = 1.0 / a->values[a->col_ptr[j + 1] - 1]; /* the diagonal ends each column */
}

/* fs_cg_solve is fs_pcg on the matrix with the Jacobi preconditioner: the same iterations and the
 * same solution bit for bit; the sequential sums converge too, to within the tolerance. */
static void test_pcg_operator_matches_matrix_cg(void)
{
    enum { m = 20, n = m * m };
    fs_sparse_matrix a;
    assemble_poisson(m, &a);
    double *b = random_vector(n, 21);
    double *x_cg = calloc(n, sizeof *x_cg), *x = calloc(n, sizeof *x), *work = malloc(4 * n * sizeof *work);
    fs_cg_params params = fs_cg_params_default();
    params.tolerance = 1e-9;
    int iterations = fs_cg_solve(&a, b, x_cg, params, NULL);
    CHECK(iterations > 0);

    matrix_op o;
    matrix_op_init(&o, &a, params.tolerance * norm2(n, b), FS_CG_SUM_INTERLEAVED);
    fs_cg_operator op = {n, matrix_apply, matrix_precondition, matrix_converged, &o};
    fs_pcg_params pp = {n, FS_CG_SUM_INTERLEAVED, false, true};
    fs_pcg_vectors v = {work, work + n, work + 2 * n, work + 3 * n};
    fs_pcg_result res = fs_pcg(&op, b, x, &pp, v);
    CHECK(res.status == FS_PCG_CONVERGED && res.iterations == iterations);
    CHECK(memcmp(x, x_cg, n * sizeof *x) == 0);
    CHECK(relative_residual(&a, x, b) <= params.tolerance);
    /* on return r is the true residual b - A x */
    double *ax = malloc(n * sizeof *ax);
    fs_sparse_matvec(&a, x, ax);
    double worst = 0.0;
    for (int32_t i = 0; i < n; i++)
        worst = fmax(worst, fabs(v.r[i] - (b[i] - ax[i])));
    CHECK(worst == 0.0);

    /* from zero with the recurrence residual and sequential sums: x's content is ignored */
    for (int32_t i = 0; i < n; i++)
        x[i] = 1e9;
    o.sum = FS_CG_SUM_SEQUENTIAL;
    o.applies = 0;
    fs_pcg_params seq = {n, FS_CG_SUM_SEQUENTIAL, true, false};
    res = fs_pcg(&op, b, x, &seq, v);
    CHECK(res.status == FS_PCG_CONVERGED);
    CHECK(o.applies == res.iterations); /* one product per iteration, none for the start */
    CHECK_MSG(relative_residual(&a, x, b) <= 2 * params.tolerance, "residual %g", relative_residual(&a, x, b));
    CHECK(relative_difference(n, x, x_cg) <= 1e-6);

    /* a cap on the iterations, and a preconditioner that fails on its third call */
    fs_pcg_params few = {3, FS_CG_SUM_SEQUENTIAL, true, false};
    res = fs_pcg(&op, b, x, &few, v);
    CHECK(res.status == FS_PCG_MAX_ITERATIONS && res.iterations == 3);
    o.fail_after = 2;
    fs_error_clear();
    res = fs_pcg(&op, b, x, &seq, v);
    CHECK(res.status == FS_PCG_FAILED && res.iterations == 2);
    CHECK(strcmp(fs_error_message(), "test: preconditioner failed") == 0);
    free(o.inv_diag);
    free(ax);
    free(work);
    free(x);
    free(x_cg);
    free(b);
    fs_sparse_matrix_free(&a);
}

/* A 2 x 2 operator given by its entries, preconditioner the identity. */
typedef struct {
    double a[4];
} small_op;

static void small_apply(void *ctx, const double *x, double *y)
{
    const small_op *o = ctx;
    y[0] = o->a[0] * x[0] + o->a[1] * x[1];
    y[1] = o->a[2] * x[0] + o->a[3] * x[1];
}

static int small_identity(void *ctx, const double *r, double *z)
{
    (void)ctx;
    z[0] = r[0];
    z[1] = r[1];
    return 0;
}

static bool small_converged(void *ctx, const double *r)
{
    (void)ctx;
    return fabs(r[0]) <= 1e-14 && fabs(r[1]) <= 1e-14;
}

/* By hand: CG solves an SPD 2 x 2 system in two iterations; an indefinite one breaks down on its
 * first direction (p'Ap = 0), which fs_pcg reports with the curvature. */
static void test_pcg_small_cases(void)
{
    small_op spd = {{4, 1, 1, 3}};
    fs_cg_operator op = {2, small_apply, small_identity, small_converged, &spd};
    double b[2] = {1, 2}, x[2] = {0, 0}, r[2], z[2], p[2], q[2];
    fs_pcg_params params = {10, FS_CG_SUM_SEQUENTIAL, true, true};
    fs_pcg_result res = fs_pcg(&op, b, x, &params, (fs_pcg_vectors){r, z, p, q});
    CHECK(res.status == FS_PCG_CONVERGED && res.iterations == 2);
    CHECK_NEAR(x[0], 1.0 / 11.0, 1e-15);
    CHECK_NEAR(x[1], 7.0 / 11.0, 1e-15);
    /* started at the solution with true_residual: no iteration */
    res = fs_pcg(&op, b, x, &(fs_pcg_params){10, FS_CG_SUM_SEQUENTIAL, false, true}, (fs_pcg_vectors){r, z, p, q});
    CHECK(res.status == FS_PCG_CONVERGED && res.iterations == 0);

    small_op indefinite = {{1, 0, 0, -1}};
    op.ctx = &indefinite;
    double one[2] = {1, 1};
    res = fs_pcg(&op, one, x, &params, (fs_pcg_vectors){r, z, p, q});
    CHECK(res.status == FS_PCG_BREAKDOWN && res.iterations == 0);
    CHECK(res.curvature == 0.0 && res.rz == 2.0);
}

/* The two summation orders by hand: sequential is one running sum, interleaved four partial sums. */
static void test_cg_dot_orders(void)
{
    const double u[5] = {1e16, 1, -1e16, 1, 1}, v[5] = {1, 1, 1, 1, 1};
    /* ((((1e16 + 1) - 1e16) + 1) + 1): the first 1 is lost to rounding */
    CHECK(fs_cg_dot(5, u, v, FS_CG_SUM_SEQUENTIAL) == 2.0);
    /* (1e16 + 1) + (1 + 1) ... partial sums s0 = 1e16 + 1, s1 = 1, s2 = -1e16, s3 = 1 */
    CHECK(fs_cg_dot(5, u, v, FS_CG_SUM_INTERLEAVED) == ((1e16 + 1.0) + 1.0) + (-1e16 + 1.0));
    CHECK(fs_cg_dot(0, u, v, FS_CG_SUM_SEQUENTIAL) == 0.0);
}

/* The Kronecker product of the m x m grid Laplacian with an SPD 3x3 coupling c: three unknowns per
 * grid point, strongly coupled within the point, like a node's displacement in elasticity. */
static void assemble_coupled(int32_t m, const double c[9], fs_sparse_matrix *a)
{
    fs_sparse_matrix p;
    assemble_poisson(m, &p);
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, 3 * m * m, 0);
    for (int32_t j = 0; j < p.n; j++)
        for (int32_t k = p.col_ptr[j]; k < p.col_ptr[j + 1]; k++) {
            int32_t i = p.row_idx[k];
            for (int r = 0; r < 3; r++)
                for (int q = 0; q < 3; q++)
                    if (3 * i + r <= 3 * j + q && (i != j || r <= q))
                        fs_sparse_builder_add(&b, 3 * i + r, 3 * j + q, p.values[k] * c[3 * r + q]);
        }
    CHECK(fs_sparse_builder_compress(&b, a, NULL) == 0);
    fs_sparse_builder_free(&b);
    fs_sparse_matrix_free(&p);
}

/* The max_residual rule stops once no entry of b - A x exceeds the bound, and sooner than the
 * Euclidean rule with the same bound on the whole vector. */
static void test_cg_max_residual(void)
{
    enum { m = 20, n = 3 * m * m };
    const double c[9] = {4, 3, 2, 3, 4, 3, 2, 3, 4};
    fs_sparse_matrix a;
    assemble_coupled(m, c, &a);
    double *b = random_vector(n, 23);
    double *x = calloc(n, sizeof *x), *ax = calloc(n, sizeof *ax);
    double bmax = 0.0, b2 = 0.0;
    for (int i = 0; i < n; i++) {
        bmax = fmax(bmax, fabs(b[i]));
        b2 += b[i] * b[i];
    }
    double bound = 1e-4 * bmax;
    fs_cg_params params = fs_cg_params_default();
    params.block = 3;
    params.max_residual = bound;
    int by_max = fs_cg_solve(&a, b, x, params, NULL);
    fs_sparse_matvec(&a, x, ax);
    double worst = 0.0;
    for (int i = 0; i < n; i++)
        worst = fmax(worst, fabs(b[i] - ax[i]));
    CHECK_MSG(by_max > 0 && worst <= bound, "%d iterations, largest residual %g > %g", by_max, worst, bound);
    for (int i = 0; i < n; i++)
        x[i] = 0.0;
    params.max_residual = 0.0;
    params.tolerance = bound / sqrt(b2);
    int by_norm = fs_cg_solve(&a, b, x, params, NULL);
    CHECK_MSG(by_norm > by_max, "Euclidean rule %d iterations, max rule %d", by_norm, by_max);
    fs_sparse_matrix_free(&a);
    free(b);
    free(x);
    free(ax);
}

/* The 3x3 block preconditioner solves to the same tolerance in fewer iterations than Jacobi when the
 * three unknowns of a point are coupled, and reports a block that is not positive definite. */
static void test_cg_block_preconditioner(void)
{
    enum { m = 20, n = 3 * m * m };
    const double c[9] = {4, 3, 2, 3, 4, 3, 2, 3, 4};
    fs_sparse_matrix a;
    assemble_coupled(m, c, &a);
    double *b = random_vector(n, 17);
    double *x1 = calloc(n, sizeof *x1), *x3 = calloc(n, sizeof *x3);
    fs_cg_params params = fs_cg_params_default();
    params.tolerance = 1e-10;
    int jacobi = fs_cg_solve(&a, b, x1, params, NULL);
    params.block = 3;
    int blocks = fs_cg_solve(&a, b, x3, params, NULL);
    CHECK_MSG(jacobi > 0 && blocks > 0 && blocks < jacobi, "Jacobi %d iterations, 3x3 blocks %d", jacobi, blocks);
    CHECK(relative_residual(&a, x3, b) <= 1e-10);
    CHECK(relative_difference(n, x1, x3) <= 1e-6);

    const double bad[9] = {1, 2, 0, 2, 1, 0, 0, 0, 1}; /* indefinite: the matrix is not SPD either */
    fs_sparse_matrix_free(&a);
    assemble_coupled(m, bad, &a);
    fs_error_clear();
    CHECK(fs_cg_solve(&a, b, x3, params, NULL) == -1);
    CHECK_MSG(starts_with(fs_error_message(), "cg: diagonal block of unknowns 0-2 is not positive definite"), "%s",
              fs_error_message());
    free(b);
    free(x1);
    free(x3);
    fs_sparse_matrix_free(&a);
}

/* The 3x3-block CG on a principal submatrix of whole nodes, copied straight from the matrix
 * (fs_cg_solve_principal), gives the same iterates bit for bit as CG on the extracted submatrix, leaves
 * map at -1, and solves the submatrix system. A matrix whose blocks are not whole (an entry missing
 * from one off-diagonal block) goes through the general copy and is solved as well. */
static void test_cg_principal_blocks(void)
{
    enum { m = 16, n = 3 * m * m };
    const double c[9] = {4, 3, 2, 3, 4, 3, 2, 3, 4};
    fs_sparse_matrix a;
    assemble_coupled(m, c, &a);
    int32_t idx[n], k = 0, map[n];
    for (int32_t node = 0; node < m * m; node++)
        if (node % 5 != 2) /* a principal submatrix of whole nodes, some left out */
            for (int l = 0; l < 3; l++)
                idx[k++] = 3 * node + l;
    for (int i = 0; i < n; i++)
        map[i] = -1;
    double *b = random_vector(k, 29);
    double *x_direct = calloc(n, sizeof *x_direct), *x_sub = calloc(n, sizeof *x_sub);
    fs_cg_params params = fs_cg_params_default();
    params.block = 3;
    params.tolerance = 1e-10;
    int direct = fs_cg_solve_principal(&a, idx, k, map, b, x_direct, params, NULL);
    int unset = 0;
    for (int i = 0; i < n; i++)
        unset += map[i] != -1;
    CHECK(unset == 0);
    fs_sparse_matrix sub = {0};
    fs_sparse_matrix_principal(&a, idx, k, map, &sub);
    int extracted = fs_cg_solve(&sub, b, x_sub, params, NULL);
    CHECK_MSG(direct > 0 && direct == extracted, "%d and %d iterations", direct, extracted);
    CHECK(memcmp(x_direct, x_sub, (size_t)k * sizeof *x_sub) == 0);
    CHECK(relative_residual(&sub, x_direct, b) <= 1e-10);
    fs_sparse_matrix_free(&sub);

    /* the same coupling with entry (0, 3 + 1) left out of the pattern: not whole blocks */
    fs_sparse_builder bl;
    fs_sparse_builder_init(&bl, n, 0);
    for (int32_t j = 0; j < a.n; j++)
        for (int32_t p = a.col_ptr[j]; p < a.col_ptr[j + 1]; p++)
            if (!(a.row_idx[p] == 0 && j == 4))
                fs_sparse_builder_add(&bl, a.row_idx[p], j, a.values[p]);
    fs_sparse_matrix irregular;
    CHECK(fs_sparse_builder_compress(&bl, &irregular, NULL) == 0);
    fs_sparse_builder_free(&bl);
    double *bb = random_vector(n, 31), *xi = calloc(n, sizeof *xi);
    CHECK(fs_cg_solve(&irregular, bb, xi, params, NULL) > 0);
    CHECK(relative_residual(&irregular, xi, bb) <= 1e-10);
    for (int i = 0; i < n; i++)
        xi[i] = 0.0;
    for (int i = 0; i < n; i++)
        idx[i] = i;
    CHECK(fs_cg_solve_principal(&irregular, idx, n, map, bb, xi, params, NULL) > 0);
    CHECK(relative_residual(&irregular, xi, bb) <= 1e-10);
    fs_sparse_matrix_free(&irregular);
    fs_sparse_matrix_free(&a);
    free(b);
    free(bb);
    free(xi);
    free(x_direct);
    free(x_sub);
}

/* The factor and the solution do not depend on the BLAS's thread count: OpenBLAS's threaded
 * dpotrf, dgemm and dtrsm round otherwise than its one-thread ones on supernodes of this size, so
 * the solver puts it on one thread whatever it was set to (issue 16: -j changed the fractures). */
static void test_cholesky_independent_of_blas_threads(void)
{
    void (*set_threads)(int) = NULL;
    *(void **)(&set_threads) = dlsym(RTLD_DEFAULT, "openblas_set_num_threads");
    if (!set_threads) {
        printf("skip: the BLAS is not OpenBLAS\n");
        return;
    }
    enum { n = 600 };
    fs_sparse_builder bld;
    fs_sparse_builder_init(&bld, n, 0);
    for (int32_t i = 0; i < n; i++)
        for (int32_t j = i; j < n; j++)
            fs_sparse_builder_add(&bld, i, j, (i == j ? n : 0.0) + fs_rand_range(7, FS_RNG_TEST, (uint64_t)(i * n + j), -1, 1));
    fs_sparse_matrix a;
    CHECK(fs_sparse_builder_compress(&bld, &a, NULL) == 0);
    fs_sparse_builder_free(&bld);
    double *b = random_vector(n, 11);
    double *x[3];
    const int threads[3] = {1, 4, 2};
    for (int k = 0; k < 3; k++) {
        x[k] = malloc((size_t)n * sizeof *x[k]);
        set_threads(threads[k]);
        fs_cholesky *c = fs_cholesky_analyze(&a);
        CHECK(c != NULL);
        set_threads(threads[k]);
        CHECK(c && fs_cholesky_factorize(c, &a) == 0);
        CHECK(c && fs_cholesky_solve(c, 1, b, x[k]) == 0);
        fs_cholesky_free(c);
    }
    CHECK_MSG(relative_residual(&a, x[0], b) <= 1e-12, "residual %g", relative_residual(&a, x[0], b));
    CHECK_MSG(memcmp(x[0], x[1], (size_t)n * sizeof *x[0]) == 0, "BLAS on 4 threads: another solution");
    CHECK_MSG(memcmp(x[0], x[2], (size_t)n * sizeof *x[0]) == 0, "BLAS on 2 threads: another solution");
    for (int k = 0; k < 3; k++)
        free(x[k]);
    free(b);
    fs_sparse_matrix_free(&a);
}

/* CHOLMOD's OpenMP regions run on the calling thread once an analysis has been made (when the
 * process has OpenMP at all: Debian's CHOLMOD brings libgomp). */
static void test_cholesky_openmp_regions_serial(void)
{
    int (*get_levels)(void) = NULL;
    *(void **)(&get_levels) = dlsym(RTLD_DEFAULT, "omp_get_max_active_levels");
    if (!get_levels) {
        printf("skip: no OpenMP in the process\n");
        return;
    }
    fs_sparse_builder bld;
    fs_sparse_builder_init(&bld, 2, 0);
    fs_sparse_builder_add(&bld, 0, 0, 2.0);
    fs_sparse_builder_add(&bld, 1, 1, 2.0);
    fs_sparse_matrix a;
    CHECK(fs_sparse_builder_compress(&bld, &a, NULL) == 0);
    fs_cholesky *c = fs_cholesky_analyze(&a);
    CHECK(c != NULL);
    CHECK_MSG(get_levels() == 0, "OpenMP max active levels %d after an analysis", get_levels());
    fs_cholesky_free(c);
    fs_sparse_matrix_free(&a);
    fs_sparse_builder_free(&bld);
}

int main(void)
{
    RUN(test_builder_sums_duplicates);
    RUN(test_builder_reused);
    RUN(test_builder_random_columns);
    RUN(test_matvec_matches_dense);
    RUN(test_principal_submatrix);
    RUN(test_slots_reproduce_fresh_assembly);
    RUN(test_cholesky_solves_poisson);
    RUN(test_cholesky_given_order);
    RUN(test_node_order_kept_across_cuts);
    RUN(test_cholesky_solves_elasticity);
    RUN(test_refactorize_scaled_values);
    RUN(test_updown_matches_fresh_factorization);
    RUN(test_indefinite_matrix_fails_cleanly);
    RUN(test_downdate_to_indefinite_fails);
    RUN(test_cg_agrees_with_cholesky);
    RUN(test_cg_reports_failures);
    RUN(test_cg_block_preconditioner);
    RUN(test_cg_principal_blocks);
    RUN(test_cg_max_residual);
    RUN(test_pcg_operator_matches_matrix_cg);
    RUN(test_pcg_small_cases);
    RUN(test_cg_dot_orders);
    RUN(test_cholesky_independent_of_blas_threads);
    RUN(test_cholesky_openmp_regions_serial);
    return check_finish();
}
