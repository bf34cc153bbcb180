/* The wedge model's mesh changes: element removal (Algorithm 7), subdivision (Algorithms 8-9), cuts and moved nodes, each updating the system in place. */
#include "model/wedge/internal.h"

#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/sort.h"
#include "geom/refine.h"

/* ---- mesh changes: removal (Algorithm 7) and subdivision (Algorithms 8-9) ---- */

/* Rank updates of the factor before a numeric re-factorization instead; the updates cost a small
 * fraction of a factorization each (bench/bench_wedge measures both), and a periodic fresh factor
 * bounds the round-off that downdates accumulate and restores the faster supernodal solves. */
#define UPDOWN_LIMIT 128

/* design: thesis Algorithm 7 (removal by reconstruction), generalised to any set of nodes whose
 * elements changed. Every entry of the system coupling two DOFs of the nodes in S, and every load at
 * those DOFs, is set to zero and rebuilt from the living elements touching S, in ascending element
 * order: the values are then exactly those of a fresh assembly (no drift from repeated subtraction,
 * Algorithm 6), and entries no element feeds any more become exact zeros. */
static int update_region(fs_wedge_model *w, const int32_t *nodes, int32_t n)
{
    for (int32_t q = 0; q < n; q++)
        w->node_ratio[nodes[q]] = NAN; /* their neighbourhoods changed */
    int32_t *dofs = fs_malloc(6 * (size_t)(n ? n : 1) * sizeof *dofs);
    int32_t nd = 0;
    for (int32_t q = 0; q < n; q++)
        for (int l = 0; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)nodes[q] + l];
            if (!w->mark[g]) {
                w->mark[g] = 1;
                dofs[nd++] = g;
            }
        }
    fs_sparse_matrix *k = &w->k_free;
    fs_wedge_coupling *c = &w->k_fb;
    for (int32_t q = 0; q < nd; q++) {
        int32_t j = dofs[q];
        if (j >= w->n_free) {
            int32_t col = j - w->n_free;
            for (int32_t p = c->start[col]; p < c->start[col] + c->len[col]; p++)
                if (w->mark[c->row[p]])
                    c->value[p] = 0.0;
            continue;
        }
        for (int32_t p = k->col_ptr[j]; p < k->col_ptr[j + 1]; p++)
            if (w->mark[k->row_idx[p]])
                k->values[p] = 0.0;
        for (int pat = 0; pat < FS_WEDGE_PATTERNS; pat++)
            w->load[FS_WEDGE_PATTERNS * (size_t)j + pat] = 0.0;
    }
    int32_t cap = 0, ne = 0;
    for (int32_t q = 0; q < n; q++)
        cap += w->node_elem_count[nodes[q]];
    int32_t *elems = fs_malloc((size_t)(cap ? cap : 1) * sizeof *elems);
    for (int32_t q = 0; q < n; q++) {
        int32_t i = nodes[q];
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
            if (w->state[w->node_elem[p]] == FS_WEDGE_ALIVE)
                elems[ne++] = w->node_elem[p];
    }
    int32_t unique = fs_sort_unique_int32(elems, ne);
    int rc = fs_wedge_readd(w, elems, unique, w->mark);
    for (int32_t q = 0; q < n; q++) {
        int32_t i = nodes[q];
        if (fs_wedge_alive_at_node(w, i) > 0)
            continue;
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g < w->n_free)
                k->values[fs_wedge_find_entry(k, g, g)] = 1.0;
        }
    }
    for (int32_t q = 0; q < nd; q++)
        w->mark[dofs[q]] = 0;
    free(dofs);
    free(elems);
    return rc;
}

/* Dense Cholesky a = L L' of an m x m symmetric matrix in place (row-major, lower triangle used and
 * overwritten with L, the upper set to 0). Returns 0, or -1 if a pivot is not positive. */
static int dense_cholesky(double *a, int m)
{
    for (int j = 0; j < m; j++) {
        double d = a[m * j + j];
        for (int k = 0; k < j; k++)
            d -= a[m * j + k] * a[m * j + k];
        if (!(d > 0.0))
            return -1;
        d = sqrt(d);
        a[m * j + j] = d;
        for (int i = j + 1; i < m; i++) {
            double v = a[m * i + j];
            for (int k = 0; k < j; k++)
                v -= a[m * i + k] * a[m * j + k];
            a[m * i + j] = v / d;
        }
        for (int i = 0; i < j; i++)
            a[m * i + j] = 0.0;
    }
    return 0;
}

/* design: the factor of K_ff after a removal is that of K_ff - K_e,ff (+ a unit diagonal for DOFs left
 * without an element): a rank-m downdate with W = the Cholesky factor of the element's free-free
 * block (m <= 9, positive definite because the element's bottom is fixed), preceded by a rank update
 * with the unit vectors of the orphaned DOFs so that no intermediate matrix is singular. CHOLMOD
 * changes only the columns of L on the paths from those rows to the root of the elimination tree:
 * far cheaper than a factorization, which is done instead after UPDOWN_LIMIT updates or if a
 * downdate fails numerically. */
static int update_factor_after_removal(fs_wedge_model *w, const double K[324], const int32_t *g,
                                       const int32_t *orphans, int32_t n_orphans)
{
    if (!w->chol)
        return 0;
    if (w->updowns_pending >= UPDOWN_LIMIT)
        return fs_wedge_factorize(w, false);
    double t0 = fs_seconds();
    int32_t uniq[18], m = 0, local_to_u[18];
    for (int a = 0; a < 18; a++) {
        local_to_u[a] = -1;
        if (g[a] >= w->n_free)
            continue;
        int u = 0;
        while (u < m && uniq[u] != g[a])
            u++;
        if (u == m)
            uniq[m++] = g[a];
        local_to_u[a] = u;
    }
    double M[18 * 18] = {0};
    for (int a = 0; a < 18; a++)
        for (int c = 0; c < 18; c++)
            if (local_to_u[a] >= 0 && local_to_u[c] >= 0)
                M[m * local_to_u[a] + local_to_u[c]] += K[18 * a + c];
    int rc = 0;
    if (n_orphans > 0) {
        int32_t cp[28], ri[27];
        double v[27];
        for (int32_t q = 0; q < n_orphans; q++) {
            cp[q] = q;
            ri[q] = orphans[q];
            v[q] = 1.0;
        }
        cp[n_orphans] = n_orphans;
        rc = fs_cholesky_updown(w->chol, +1, n_orphans, cp, ri, v);
    }
    if (rc == 0 && m > 0 && dense_cholesky(M, m) == 0) {
        int32_t cp[19], ri[18 * 18];
        double v[18 * 18];
        int32_t nz = 0;
        for (int c = 0; c < m; c++) {
            cp[c] = nz;
            for (int r = c; r < m; r++) {
                ri[nz] = uniq[r];
                v[nz++] = M[m * r + c];
            }
        }
        cp[m] = nz;
        rc = fs_cholesky_updown(w->chol, -1, m, cp, ri, v);
    } else if (m > 0) {
        rc = -1;
    }
    w->counters.update_seconds += fs_seconds() - t0;
    if (rc == 0) {
        w->counters.updowns++;
        w->updowns_pending++;
        return 0;
    }
    fs_error_clear();
    return fs_wedge_factorize(w, false);
}

int fs_wedge_remove(fs_wedge_model *w, int32_t e)
{
    w->residual_valid = false; /* see fs_wedge_relax */
    FS_ASSERT(e >= 0 && e < w->n_elems && w->state[e] == FS_WEDGE_ALIVE);
    double K[324], loads[FS_WEDGE_PATTERNS][18];
    if (fs_wedge_element_system(w, e, w->assembled_thickness, K, loads) < 0)
        return -1;
    int32_t g[18];
    for (int a = 0; a < 18; a++)
        g[a] = fs_wedge_elem_dof(w, e, a);
    double t0 = fs_seconds();
    w->state[e] = FS_WEDGE_REMOVED;
    w->ratio[e] = NAN;
    const int32_t *nodes = w->mesh->tri + 3 * (size_t)e;
    if (update_region(w, nodes, 3) < 0)
        return -1;
    w->counters.assemble_seconds += fs_seconds() - t0;
    int32_t orphans[9], n_orphans = 0;
    for (int c = 0; c < 3; c++) {
        if (fs_wedge_alive_at_node(w, nodes[c]) > 0)
            continue;
        for (int k = 3; k < 6; k++) {
            int32_t d = w->dof[6 * (size_t)nodes[c] + k];
            bool seen = false;
            for (int32_t q = 0; q < n_orphans; q++)
                seen |= orphans[q] == d;
            if (d < w->n_free && !seen)
                orphans[n_orphans++] = d;
        }
    }
    w->fractures++;
    w->counters.removals++;
    if (w->cfg.solver.relax == FS_RELAX_LOCAL) {
        w->factor_stale |= w->chol != NULL;
        return 0;
    }
    return update_factor_after_removal(w, K, g, orphans, n_orphans);
}

/* design: the system is extended in place after a subdivision or a cut. New nodes are appended and
 * number_dofs keeps the order of the old DOFs (free ones in node order, then the fixed ones), so old
 * free indices stay and every fixed DOF keeps its column of K_fb. K_ff's new pattern is the old one
 * plus the pairs of the changed elements it lacks and the diagonals of the new DOFs. A cut or a
 * bisection couples old nodes only where they were coupled already, so those pairs are in the new
 * nodes' columns, which come last: the old columns stay where they are. A pair of old nodes not
 * coupled before (an edge flip, say) moves the columns behind it, by a merge from the back that never
 * overwrites an entry not yet read. K_fb's new entries go into their columns in place
 * (fs_wedge_coupling). The arrays grow geometrically, so a cut costs what its elements touch, not a
 * pass over the matrix. Entries whose element vanished stay in the pattern as zeros; new entries are
 * 0 (update_region adds the contributions); the pattern changed, so the factor is analysed afresh. */
static int cmp_int64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

static void push_pair(int64_t **pairs, size_t *np, size_t *cap, int64_t key)
{
    FS_ARRAY_RESERVE(*pairs, *cap, *np + 1, 256);
    (*pairs)[(*np)++] = key;
}

/* Grows an array of n_old elements of the given size to n, zeroing the new ones. */
static void *grow_zeroed(void *a, size_t n_old, size_t n, size_t size)
{
    a = fs_realloc(a, (n ? n : 1) * size);
    if (n > n_old)
        memset((char *)a + n_old * size, 0, (n - n_old) * size);
    return a;
}

static int extend_system(fs_wedge_model *w, int32_t n_free_old, int32_t n_fixed_old, const int32_t *elems,
                         int32_t n_changed)
{
    int32_t nf = w->n_free;
    FS_ASSERT(nf >= n_free_old && w->n_fixed >= n_fixed_old && w->k_fb.n == n_fixed_old);
    w->pattern_version++;
    fs_sparse_matrix *k = &w->k_free;
    fs_wedge_coupling *c = &w->k_fb;
    fs_wedge_coupling_resize(c, w->n_fixed);
    size_t cap = 0, np = 0;
    int64_t *pairs = NULL;
    for (int32_t q = 0; q < n_changed; q++) {
        int32_t e = elems[q];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        int32_t g[18];
        for (int a = 0; a < 18; a++)
            g[a] = fs_wedge_elem_dof(w, e, a);
        for (int a = 0; a < 18; a++)
            for (int b = a; b < 18; b++) {
                int32_t row = g[a] < g[b] ? g[a] : g[b], col = g[a] < g[b] ? g[b] : g[a];
                if (row >= nf)
                    continue; /* fixed-fixed */
                if (col >= nf)
                    fs_wedge_coupling_insert(c, col - nf, row);
                else if (col >= n_free_old || fs_wedge_find_entry(k, row, col) < 0)
                    push_pair(&pairs, &np, &cap, (int64_t)col * nf + row);
            }
    }
    fs_wedge_coupling_compact(c);
    for (int32_t j = n_free_old; j < nf; j++) /* diagonals of the new columns */
        push_pair(&pairs, &np, &cap, (int64_t)j * nf + j);
    if (np == 0) {
        free(pairs);
        goto vectors;
    }
    qsort(pairs, np, sizeof *pairs, cmp_int64);

    /* pass 1: the new starts of columns first .. nf - 1 (those before the first new pair stay) */
    int32_t first = (int32_t)(pairs[0] / nf), span = nf - first;
    int32_t *ptr = fs_malloc(((size_t)span + 1) * sizeof *ptr);
    size_t *pair_start = fs_malloc(((size_t)span + 1) * sizeof *pair_start);
    size_t nz = (size_t)k->col_ptr[first < n_free_old ? first : n_free_old], pp = 0;
    for (int32_t j = first; j < nf; j++) {
        int32_t po = j < n_free_old ? k->col_ptr[j] : 0, po_end = j < n_free_old ? k->col_ptr[j + 1] : 0;
        ptr[j - first] = (int32_t)(nz <= INT32_MAX ? nz : INT32_MAX);
        pair_start[j - first] = pp;
        while (po < po_end || (pp < np && pairs[pp] / nf == j)) {
            int64_t r_old = po < po_end ? k->row_idx[po] : INT64_MAX;
            int64_t r_new = pp < np && pairs[pp] / nf == j ? pairs[pp] % nf : INT64_MAX;
            int64_t r = r_old < r_new ? r_old : r_new;
            po += r_old == r;
            while (pp < np && pairs[pp] / nf == j && pairs[pp] % nf == r)
                pp++;
            nz++;
        }
    }
    pair_start[span] = np;
    if (nz > INT32_MAX) {
        free(pairs);
        free(ptr);
        free(pair_start);
        fs_error(FS_ERR_INTERNAL, "wedge model: the stiffness matrix outgrew 32-bit indices");
        return -1;
    }
    ptr[span] = (int32_t)nz;
    if (nz > w->k_free_capacity) {
        w->k_free_capacity = nz + nz / 2;
        k->row_idx = fs_realloc(k->row_idx, w->k_free_capacity * sizeof *k->row_idx);
        k->values = fs_realloc(k->values, w->k_free_capacity * sizeof *k->values);
    }
    /* pass 2: move the columns, last first */
    for (int32_t j = nf - 1; j >= first;) {
        size_t pb = pair_start[j - first], pe = pair_start[j - first + 1];
        if (pb == pe) { /* a run of old columns without new pairs: j2 .. j */
            int32_t j2 = j;
            while (j2 > first && pair_start[j2 - 1 - first] == pair_start[j2 - first])
                j2--;
            size_t len = (size_t)(k->col_ptr[j + 1] - k->col_ptr[j2]);
            if (ptr[j2 - first] != k->col_ptr[j2]) {
                memmove(k->row_idx + ptr[j2 - first], k->row_idx + k->col_ptr[j2], len * sizeof *k->row_idx);
                memmove(k->values + ptr[j2 - first], k->values + k->col_ptr[j2], len * sizeof *k->values);
            }
            j = j2 - 1;
            continue;
        }
        int64_t o = j < n_free_old ? k->col_ptr[j + 1] - 1 : -1, o_begin = j < n_free_old ? k->col_ptr[j] : 0;
        int64_t q = (int64_t)pe - 1, d = ptr[j - first + 1] - 1;
        while (o >= o_begin || q >= (int64_t)pb) {
            int64_t r_old = o >= o_begin ? k->row_idx[o] : -1;
            int64_t r_new = q >= (int64_t)pb ? pairs[q] % nf : -1;
            int64_t r = r_old > r_new ? r_old : r_new;
            double v = r_old == r ? k->values[o--] : 0.0;
            while (q >= (int64_t)pb && pairs[q] % nf == r)
                q--;
            k->row_idx[d] = (int32_t)r;
            k->values[d--] = v;
        }
        FS_ASSERT(d + 1 == ptr[j - first]);
        j--;
    }
    k->col_ptr = fs_realloc(k->col_ptr, ((size_t)nf + 1) * sizeof *k->col_ptr);
    memcpy(k->col_ptr + first, ptr, ((size_t)span + 1) * sizeof *ptr);
    k->n = nf;
    free(pairs);
    free(ptr);
    free(pair_start);

vectors:;
    if (nf > w->load_capacity) {
        w->load_capacity = nf + nf / 2;
        w->load = fs_realloc(w->load, (size_t)FS_WEDGE_PATTERNS * w->load_capacity * sizeof *w->load);
    }
    memset(w->load + FS_WEDGE_PATTERNS * (size_t)n_free_old, 0,
           FS_WEDGE_PATTERNS * (size_t)(nf - n_free_old) * sizeof *w->load);
    w->rhs = fs_realloc(w->rhs, ((size_t)nf + 1) * sizeof *w->rhs);
    w->x = grow_zeroed(w->x, (size_t)n_free_old, (size_t)nf + 1, sizeof *w->x);
    w->u_fixed = fs_realloc(w->u_fixed, ((size_t)w->n_fixed + 1) * sizeof *w->u_fixed);
    w->mark = grow_zeroed(w->mark, (size_t)n_free_old + (size_t)n_fixed_old + 1, (size_t)nf + w->n_fixed + 1,
                          sizeof *w->mark);
    return 0;
}

/* After the sparsity pattern changed: a new analysis and factorization, or with local relaxation
 * none (the factor is dropped and the global solves use CG until fs_wedge_refactor, see solve() in equilibrium.c). */
static int pattern_changed(fs_wedge_model *w)
{
#ifdef FS_VALIDATE
    fs_wedge_check_mesh(w, "a change of the mesh");
    fs_wedge_check_system(w, "a change of the mesh");
#endif
    if (w->cfg.solver.relax == FS_RELAX_LOCAL && w->cfg.solver.method == FS_SOLVER_CHOLMOD) {
        fs_cholesky_free(w->chol);
        w->chol = NULL;
        w->factor_stale = true;
        return 0;
    }
    return fs_wedge_factorize(w, true);
}

/* Marks the listed triangles and returns their descendants after one refinement call: a listed
 * triangle keeps its slot and new triangles name their pre-call ancestor. */
static int32_t descendants(const fs_refine_change *ch, const int32_t *list, int32_t n, uint8_t *flag, int32_t *out)
{
    int32_t m = 0;
    for (int32_t q = 0; q < n; q++)
        if (!flag[list[q]]) {
            flag[list[q]] = 1;
            out[m++] = list[q];
        }
    for (int32_t q = 0; q < ch->n_new_tris; q++)
        if (flag[ch->tri_parent[q]])
            out[m++] = ch->n_tris_before + q;
    for (int32_t q = 0; q < n; q++)
        flag[list[q]] = 0;
    return m;
}

int fs_wedge_subdivide(fs_wedge_model *w, const int32_t *elems, int32_t n, bool to_min_size, int32_t *bisected)
{
    w->residual_valid = false; /* see fs_wedge_relax */
    double t0 = fs_seconds();
    *bisected = 0;
    int32_t n_tris0 = w->n_elems, n_free_old = w->n_free, n_fixed_old = w->n_fixed;
    double min_size = w->cfg.mesh.min_size;
    uint8_t *changed_old = fs_calloc((size_t)n_tris0 + 1, 1);
    int32_t *list = fs_malloc((size_t)(n ? n : 1) * sizeof *list);
    memcpy(list, elems, (size_t)n * sizeof *list);
    int32_t n_list = n;
    fs_refine_change ch = {0};
    while (n_list > 0) {
        if (fs_refine_bisect(w->mesh, list, n_list, min_size, &ch) < 0) {
            free(list);
            free(changed_old);
            fs_refine_change_free(&ch);
            return -1;
        }
        if (ch.n_bisections == 0)
            break;
        *bisected += ch.n_bisections;
        w->open_valid = false;
        fs_wedge_grow_arrays(w, w->mesh->n_nodes, w->mesh->n_tris);
        for (int32_t q = 0; q < ch.n_new_nodes; q++) {
            int32_t i = ch.n_nodes_before + q;
            w->thickness_factor[i] =
                0.5 * (w->thickness_factor[ch.node_parent[2 * q]] + w->thickness_factor[ch.node_parent[2 * q + 1]]);
        }
        for (int32_t q = 0; q < ch.n_new_tris; q++) {
            int32_t e = ch.n_tris_before + q, parent = ch.tri_parent[q];
            w->state[e] = w->state[parent];
            w->young[e] = w->young[parent];
            w->threshold[e] = w->threshold[parent];
        }
        for (int32_t q = 0; q < ch.n_changed_tris; q++)
            if (ch.changed_tri[q] < n_tris0)
                changed_old[ch.changed_tri[q]] = 1;
        if (!to_min_size)
            break;
        /* the next level: the listed triangles' descendants still at or above min_size */
        uint8_t *flag = fs_calloc((size_t)w->n_elems, 1);
        int32_t *next = fs_malloc(((size_t)n_list + ch.n_new_tris + 1) * sizeof *next);
        int32_t m = descendants(&ch, list, n_list, flag, next), kept = 0;
        free(flag);
        for (int32_t q = 0; q < m; q++)
            if (fs_refine_tri_size(w->mesh, next[q]) >= min_size)
                next[kept++] = next[q];
        free(list);
        list = next;
        n_list = kept;
    }
    free(list);
    fs_refine_change_free(&ch);
    if (*bisected == 0) {
        free(changed_old);
        return 0;
    }
    w->counters.subdivisions += *bisected;
    fs_wedge_number_dofs(w);
    fs_wedge_build_node_elems(w);
    int32_t n_changed = 0;
    int32_t *changed = fs_malloc(((size_t)w->n_elems + 1) * sizeof *changed);
    for (int32_t e = 0; e < n_tris0; e++)
        if (changed_old[e])
            changed[n_changed++] = e;
    for (int32_t e = n_tris0; e < w->n_elems; e++)
        changed[n_changed++] = e;
    free(changed_old);
    int32_t *nodes = fs_malloc(3 * (size_t)(n_changed ? n_changed : 1) * sizeof *nodes);
    for (int32_t q = 0; q < n_changed; q++)
        for (int c = 0; c < 3; c++)
            nodes[3 * q + c] = w->mesh->tri[3 * (size_t)changed[q] + c];
    int rc = extend_system(w, n_free_old, n_fixed_old, changed, n_changed);
    if (rc == 0)
        rc = update_region(w, nodes, 3 * n_changed);
    if (rc == 0)
        rc = fs_wedge_refresh_cache(w, changed, n_changed);
    free(changed);
    free(nodes);
    w->counters.assemble_seconds += fs_seconds() - t0;
    if (rc < 0)
        return -1;
    return pattern_changed(w);
}

int fs_wedge_refactor(fs_wedge_model *w)
{
    return fs_wedge_factorize(w, false);
}

/* The rows of f - K u of these nodes changed (wedge/relax.c keeps the rest of the residual between
 * events); nothing to record while there is no kept residual (global relaxation, or after anything
 * that invalidated it: the next fs_wedge_relax computes it in full). */
static void mark_dirty(fs_wedge_model *w, const int32_t *nodes, int32_t nn)
{
    if (!w->residual_valid)
        return;
    FS_ARRAY_RESERVE(w->dirty_nodes, w->cap_dirty, w->n_dirty + nn, 64);
    memcpy(w->dirty_nodes + w->n_dirty, nodes, (size_t)nn * sizeof *nodes);
    w->n_dirty += nn;
}

int fs_wedge_apply_change(fs_wedge_model *w, const fs_wedge_change *c)
{
    double t0 = fs_seconds();
    int32_t n_free_old = w->n_free, n_fixed_old = w->n_fixed, n0 = c->n_nodes_before, e0 = c->n_tris_before;
    bool synced = w->x_synced;
    fs_wedge_grow_arrays(w, w->mesh->n_nodes, w->mesh->n_tris);
    for (int32_t i = n0; i < w->n_nodes; i++) {
        int32_t a = c->node_parent[2 * (i - n0)], b = c->node_parent[2 * (i - n0) + 1];
        double s = c->node_weight[i - n0];
        w->thickness_factor[i] = (1.0 - s) * w->thickness_factor[a] + s * w->thickness_factor[b];
        w->pinned[i] = w->pinned[a];
        w->origin[i] = s <= 0.5 ? a : b;
        for (int l = 0; l < 6; l++) {
            w->u[6 * (size_t)i + l] = (1.0 - s) * w->u[6 * (size_t)a + l] + s * w->u[6 * (size_t)b + l];
            w->prescribed[6 * (size_t)i + l] =
                (1.0 - s) * w->prescribed[6 * (size_t)a + l] + s * w->prescribed[6 * (size_t)b + l];
        }
    }
    for (int32_t e = e0; e < w->n_elems; e++) {
        int32_t parent = c->tri_parent[e - e0];
        w->state[e] = w->state[parent];
        w->young[e] = w->young[parent];
        w->threshold[e] = w->threshold[parent];
    }
    fs_wedge_number_appended(w, n0);
    fs_wedge_update_node_elems(w, n0, e0, c->changed, c->n_changed, c->node_parent, 2 * (w->n_nodes - n0));
    int32_t n_changed = c->n_changed + (w->n_elems - e0);
    int32_t *changed = fs_malloc(((size_t)n_changed + 1) * sizeof *changed);
    memcpy(changed, c->changed, (size_t)c->n_changed * sizeof *changed);
    for (int32_t e = e0; e < w->n_elems; e++)
        changed[c->n_changed + (e - e0)] = e;
    /* the nodes whose couplings are rebuilt: those of the changed elements, and every node that lost
     * an element to a copy (a parent of a new node) */
    int32_t n_new = w->n_nodes - n0;
    int32_t *nodes = fs_malloc((3 * (size_t)n_changed + 2 * (size_t)n_new + 1) * sizeof *nodes);
    int32_t nn = 0;
    for (int32_t q = 0; q < n_changed; q++)
        for (int k = 0; k < 3; k++)
            nodes[nn++] = w->mesh->tri[3 * (size_t)changed[q] + k];
    for (int32_t q = 0; q < 2 * n_new; q++)
        nodes[nn++] = c->node_parent[q];
    fs_wedge_open_update(w, nodes, nn);
    int rc = extend_system(w, n_free_old, n_fixed_old, changed, n_changed);
    if (rc == 0)
        rc = update_region(w, nodes, nn);
    mark_dirty(w, nodes, nn);
    if (rc == 0)
        rc = fs_wedge_refresh_cache(w, changed, n_changed);
    if (rc == 0) /* the stresses of the changed elements at the displacements carried over */
        rc = fs_wedge_element_ratios(w, changed, n_changed);
    if (rc == 0) /* the old nodes kept their unknowns and displacements: in x already if it was in step */
        fs_wedge_sync_x(w, synced ? n0 : 0);
    free(changed);
    free(nodes);
    w->counters.assemble_seconds += fs_seconds() - t0;
    if (rc < 0)
        return -1;
    return pattern_changed(w);
}

int fs_wedge_update_geometry(fs_wedge_model *w, const int32_t *elems, int32_t n)
{
    double t0 = fs_seconds();
    int32_t *nodes = fs_malloc((3 * (size_t)n + 1) * sizeof *nodes);
    int32_t nn = 0;
    for (int32_t q = 0; q < n; q++)
        for (int k = 0; k < 3; k++)
            nodes[nn++] = w->mesh->tri[3 * (size_t)elems[q] + k];
    int rc = update_region(w, nodes, nn);
    mark_dirty(w, nodes, nn);
    if (rc == 0)
        rc = fs_wedge_refresh_cache(w, elems, n);
    if (rc == 0)
        rc = fs_wedge_element_ratios(w, elems, n);
    free(nodes);
    w->counters.assemble_seconds += fs_seconds() - t0;
    if (rc < 0)
        return -1;
    if (w->cfg.solver.relax == FS_RELAX_LOCAL && w->cfg.solver.method == FS_SOLVER_CHOLMOD) {
        w->factor_stale = true; /* the analysis still fits: fs_wedge_refactor only re-factorizes */
        return 0;
    }
    return fs_wedge_factorize(w, false);
}
