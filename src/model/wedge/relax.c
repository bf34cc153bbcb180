/* Adaptive local relaxation of the wedge model after a local change (thesis §5.8): residual marking, edge-path radius, local solve, global fallback. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "config.h"
#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/sort.h"
#include "geom/region.h"
#include "model/wedge/internal.h"
#include "solve/cg.h"
#include "solve/sparse.h"

/* Radius factors of §5.8.3: grown after a shortfall (for a retry and after a global fallback),
 * shrunk after a local success at the first try. */
#define RADIUS_GROW 2.0
#define RADIUS_SHRINK 0.75

/* A list of node indices with room decided by the caller. */
typedef struct {
    int32_t *v;
    int32_t n;
} ilist_t;

/* ---- residual ---- */

/* w->rhs = f - K_fb u_b (fs_wedge_build_rhs) and r = rhs - K_ff x over the free DOFs. Returns
 * ||rhs||. */
static double residual(fs_wedge_model *w, double *r)
{
    fs_wedge_build_rhs(w);
    fs_sparse_matvec(&w->k_free, w->x, r);
    double b2 = 0.0;
    for (int32_t i = 0; i < w->n_free; i++) {
        r[i] = w->rhs[i] - r[i];
        b2 += w->rhs[i] * w->rhs[i];
    }
    return sqrt(b2);
}

/* The largest |v[i]| (NaN entries are passed over, as fmax does), in four interleaved running maxima:
 * each comparison of one running maximum would wait on the one before. */
static double norm_max(const double *v, int32_t n)
{
    double m[4] = {0.0, 0.0, 0.0, 0.0};
    int32_t i = 0;
    for (; i + 4 <= n; i += 4)
        for (int k = 0; k < 4; k++) {
            double a = fabs(v[i + k]);
            m[k] = a > m[k] ? a : m[k];
        }
    for (; i < n; i++) {
        double a = fabs(v[i]);
        m[0] = a > m[0] ? a : m[0];
    }
    double s = m[0];
    for (int k = 1; k < 4; k++)
        s = m[k] > s ? m[k] : s;
    return s;
}

/* ---- marking ---- */

/* Length of the edge between corners a and b of living element e in the surface mesh at rest (cm). */
static double edge_length(const fs_wedge_model *w, int32_t e, int a, int b)
{
    return w->edge_rest[3 * (size_t)e + ((a + 1) % 3 == b ? a : b)];
}

double fs_wedge_mean_edge(const fs_wedge_model *w)
{
    double sum = 0.0;
    int64_t count = 0;
    for (int32_t e = 0; e < w->n_elems; e++) {
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        for (int c = 0; c < 3; c++)
            sum += edge_length(w, e, c, (c + 1) % 3);
        count += 3;
    }
    return count ? sum / (double)count : 1.0;
}

/* fs_region_edges_fn of the wedge model: the edges of node i's living elements, by their length at
 * rest, element by element in node_elem's order, corners in order. */
static void living_edges(void *ctx, int32_t i, fs_region *r)
{
    const fs_wedge_model *w = ctx;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
        int32_t e = w->node_elem[p];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        const int32_t *tri = w->mesh->tri + 3 * (size_t)e;
        int ci = 0;
        while (ci < 3 && tri[ci] != i)
            ci++;
        FS_ASSERT(ci < 3);
        for (int c = 0; c < 3; c++)
            if (tri[c] != i)
                fs_region_reach(r, tri[c], edge_length(w, e, ci, c));
    }
}

/* Dijkstra from the seed nodes along the edges of living elements at rest, up to radius (geom/region.h,
 * ties by node index): every node reached gets its distance in dist (INFINITY on entry) and is
 * appended to out, which receives the seeds first. Returns the number of nodes in out. */
static int32_t grow_region(const fs_wedge_model *w, const int32_t *seeds, int32_t n_seeds, double radius,
                           double *dist, int32_t *out)
{
    return fs_region_grow(seeds, n_seeds, radius, FS_REGION_TIES_BY_NODE, living_edges, (void *)w, dist, out);
}

int32_t fs_wedge_relax_region(const fs_wedge_model *w, const int32_t *seeds, int32_t n, double radius, int32_t *out)
{
    double *dist = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *dist);
    for (int32_t i = 0; i < w->n_nodes; i++)
        dist[i] = INFINITY;
    int32_t count = grow_region(w, seeds, n, radius, dist, out);
    free(dist);
    return count;
}

/* Sorts v (n values in 0 .. range - 1) ascending without repeats; returns the new count. A large list
 * is sorted by marking and scanning its range, a short one by comparisons. */
static int32_t sort_unique(int32_t *v, int32_t n, int32_t range)
{
    if ((int64_t)n * 16 < range)
        return fs_sort_unique_int32(v, n);
    uint8_t *seen = fs_calloc((size_t)range + 1, 1);
    for (int32_t q = 0; q < n; q++)
        seen[v[q]] = 1;
    int32_t m = 0;
    for (int32_t i = 0; i < range; i++)
        if (seen[i])
            v[m++] = i;
    free(seen);
    return m;
}

/* ---- scratch ---- */

/* design: an event relaxes a region of a few hundred nodes, but the model has tens of thousands. So
 * fs_wedge_relax's per-node and per-DOF scratch stays with the model (w->rs) between calls, every
 * array back at rest when a call returns (distances INFINITY, flags 0, map -1), and a call touches
 * only what its region touches: no allocation, fill or copy of the whole mesh per event. The free
 * displacements before the call, which moved_nodes compares with, are saved the first time an attempt
 * changes them (save_x) instead of copied whole. */

/* Gives w->rs room for the current nodes and free DOFs, the new room at rest. */
static void scratch_reserve(fs_wedge_model *w)
{
    if (w->rs.node_cap < w->n_nodes) {
        int32_t old = w->rs.node_cap, cap = w->n_nodes + w->n_nodes / 2 + 16;
        w->rs.dist = fs_realloc(w->rs.dist, (size_t)cap * sizeof *w->rs.dist);
        w->rs.flag = fs_realloc(w->rs.flag, (size_t)cap);
        w->rs.seen = fs_realloc(w->rs.seen, (size_t)cap);
        for (int32_t i = old; i < cap; i++)
            w->rs.dist[i] = INFINITY;
        memset(w->rs.flag + old, 0, (size_t)(cap - old));
        memset(w->rs.seen + old, 0, (size_t)(cap - old));
        w->rs.node_cap = cap;
    }
    if (w->rs.dof_cap < w->n_free) {
        int32_t old = w->rs.dof_cap, cap = w->n_free + w->n_free / 2 + 16;
        w->rs.map = fs_realloc(w->rs.map, (size_t)cap * sizeof *w->rs.map);
        w->rs.saved = fs_realloc(w->rs.saved, (size_t)cap);
        w->rs.before = fs_realloc(w->rs.before, (size_t)cap * sizeof *w->rs.before);
        for (int32_t g = old; g < cap; g++)
            w->rs.map[g] = -1;
        memset(w->rs.saved + old, 0, (size_t)(cap - old));
        w->rs.dof_cap = cap;
    }
}

void fs_wedge_relax_scratch_free(fs_wedge_model *w)
{
    free(w->rs.dist);
    free(w->rs.flag);
    free(w->rs.seen);
    free(w->rs.map);
    free(w->rs.saved);
    free(w->rs.before);
    free(w->rs.touched);
    memset(&w->rs, 0, sizeof w->rs);
}

/* x[g] += d, keeping x[g] as it was before the call the first time. */
static void save_x(fs_wedge_model *w, int32_t g, double d)
{
    if (!w->rs.saved[g]) {
        w->rs.saved[g] = 1;
        w->rs.before[g] = w->x[g];
        FS_ARRAY_RESERVE(w->rs.touched, w->rs.cap_touched, w->rs.n_touched + 1, 256);
        w->rs.touched[w->rs.n_touched++] = g;
    }
    w->x[g] += d;
}

/* ---- the local solve ---- */

/* design: thesis §5.8.2 solves the marked unknowns with the others held. The bonded layer makes the
 * local system well conditioned (every wedge's bottom is fixed), so Jacobi-preconditioned conjugate
 * gradients from zero reach the accuracy needed in tens of iterations, about three times faster
 * than a sparse Cholesky factorization of the same principal submatrix (bench/bench_wedge); the
 * factorization remains the fallback should CG not converge. The acceptance test bounds the largest
 * entry of the residual, so CG stops on that too, once no entry of the local residual exceeds
 * 0.3 tol (leaving room for what the solve changes in the rows around the region): a Euclidean
 * bound of that size would ask up to sqrt(m) times more. */

/* Solves K_MM delta = r_M for the listed free DOFs (ascending); delta receives m values. Returns 0
 * or -1 with fs_error. */
static int local_solve(fs_wedge_model *w, const int32_t *idx, int32_t m, int32_t *map, const double *r,
                       double *delta, double tol)
{
    double *b = fs_malloc((size_t)m * sizeof *b);
    for (int32_t q = 0; q < m; q++) {
        b[q] = r[idx[q]];
        delta[q] = 0.0;
    }
    fs_cg_params p = fs_cg_params_default();
    p.max_residual = 0.3 * tol;
    p.block = 3; /* a node's three unknowns are consecutive (number_dofs) */
    int it = fs_cg_solve_principal(&w->k_free, idx, m, map, b, delta, p, NULL), rc = it < 0 ? -1 : 0;
    if (it > 0)
        w->counters.local_cg_iterations += it;
    if (rc < 0) {
        fs_error_clear();
        fs_sparse_matrix sub = {0};
        fs_sparse_matrix_principal(&w->k_free, idx, m, map, &sub);
        fs_cholesky *c = fs_cholesky_analyze(&sub);
        rc = c ? fs_cholesky_factorize(c, &sub) : -1;
        if (rc == 0)
            rc = fs_cholesky_solve(c, 1, b, delta);
        fs_cholesky_free(c);
        fs_sparse_matrix_free(&sub);
    }
    free(b);
    return rc;
}

/* r -= K_ff delta on the rows it reaches: the columns of the marked DOFs give the rows above them and
 * their own rows from marked rows; the columns of the neighbouring nodes' DOFs (sharing an element
 * with a marked node) give their rows from marked rows. map must hold q for idx[q] and -1 elsewhere. */
static void update_residual(fs_wedge_model *w, const int32_t *nodes, int32_t n_nodes, const uint8_t *in_region,
                            const int32_t *idx, int32_t m, const int32_t *map, const double *delta, double *r,
                            uint8_t *seen)
{
    const fs_sparse_matrix *k = &w->k_free;
    for (int32_t q = 0; q < m; q++) {
        int32_t j = idx[q];
        double dj = delta[q], kd = 0.0;
        for (int32_t p = k->col_ptr[j]; p < k->col_ptr[j + 1]; p++) {
            int32_t i = k->row_idx[p];
            double v = k->values[p];
            r[i] -= v * dj;
            if (i != j && map[i] >= 0)
                kd += v * delta[map[i]];
        }
        r[j] -= kd;
    }
    int32_t nf = w->n_free;
    for (int32_t a = 0; a < n_nodes; a++) {
        int32_t i = nodes[a];
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
            const int32_t *tri = w->mesh->tri + 3 * (size_t)w->node_elem[p];
            for (int c = 0; c < 3; c++) {
                int32_t nb = tri[c];
                if (in_region[nb] || seen[nb])
                    continue;
                seen[nb] = 1;
                for (int l = 3; l < 6; l++) {
                    int32_t j = w->dof[6 * (size_t)nb + l];
                    if (j >= nf)
                        continue;
                    double kd = 0.0;
                    for (int32_t pp = k->col_ptr[j]; pp < k->col_ptr[j + 1]; pp++) {
                        int32_t row = map[k->row_idx[pp]];
                        if (row >= 0)
                            kd += k->values[pp] * delta[row];
                    }
                    r[j] -= kd;
                }
            }
        }
    }
    for (int32_t a = 0; a < n_nodes; a++)
        for (int32_t p = w->node_elem_start[nodes[a]]; p < w->node_elem_start[nodes[a]] + w->node_elem_count[nodes[a]]; p++)
            for (int c = 0; c < 3; c++)
                seen[w->mesh->tri[3 * (size_t)w->node_elem[p] + c]] = 0;
}

/* Recomputes the stresses of the living elements around the listed nodes. */
static int local_stresses(fs_wedge_model *w, const int32_t *nodes, int32_t n_nodes)
{
    int32_t cap = 0;
    for (int32_t a = 0; a < n_nodes; a++)
        cap += w->node_elem_count[nodes[a]];
    int32_t *elems = fs_malloc(((size_t)cap + 1) * sizeof *elems), ne = 0;
    for (int32_t a = 0; a < n_nodes; a++)
        for (int32_t p = w->node_elem_start[nodes[a]]; p < w->node_elem_start[nodes[a]] + w->node_elem_count[nodes[a]]; p++)
            if (w->state[w->node_elem[p]] == FS_WEDGE_ALIVE)
                elems[ne++] = w->node_elem[p];
    int32_t unique = sort_unique(elems, ne, w->n_elems);
    int rc = fs_wedge_update_ratios(w, elems, unique);
    free(elems);
    return rc;
}

/* The largest useful radius: twice the square root of the node count in mean edge lengths spans the
 * mesh. */
static double radius_cap(const fs_wedge_model *w)
{
    return fmax(w->relax_unit * 2.0 * sqrt((double)w->n_nodes), w->relax_unit);
}

/* One local relaxation around the seeds at the given radius: grows the region, solves its free DOFs
 * with the rest held, and updates w->x, w->u and the residual r. *region_out (n_nodes entries) gets
 * the region's nodes, *m_out the number of unknowns. Returns 1 if the solve succeeded, 0 if the local
 * solve failed (error cleared). flag and map are scratch (0 and -1 on entry and on return),
 * dist is INFINITY on entry and on return. */
static int attempt(fs_wedge_model *w, const int32_t *seeds, int32_t n_seeds, double radius, double tol, double *r,
                   double *dist, uint8_t *flag, int32_t *map, int32_t *region, int32_t *n_region_out, int32_t *m_out)
{
    int32_t nf = w->n_free;
    int32_t n_region = grow_region(w, seeds, n_seeds, radius, dist, region);
    int32_t *idx = fs_malloc((6 * (size_t)n_region + 1) * sizeof *idx), m = 0;
    for (int32_t a = 0; a < n_region; a++) {
        flag[region[a]] = 1;
        dist[region[a]] = INFINITY;
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)region[a] + l];
            if (g < nf)
                idx[m++] = g;
        }
    }
    m = sort_unique(idx, m, nf);
    w->counters.local_dofs += m;
    double *delta = fs_malloc(((size_t)m + 1) * sizeof *delta);
    int ok = m > 0 && local_solve(w, idx, m, map, r, delta, tol) == 0;
    if (!ok && m > 0)
        fs_error_clear();
    if (ok) {
        for (int32_t q = 0; q < m; q++) {
            save_x(w, idx[q], delta[q]);
            map[idx[q]] = q;
        }
        update_residual(w, region, n_region, flag, idx, m, map, delta, r, w->rs.seen);
        for (int32_t q = 0; q < m; q++)
            map[idx[q]] = -1;
        for (int32_t a = 0; a < n_region; a++)
            for (int l = 3; l < 6; l++) {
                int32_t g = w->dof[6 * (size_t)region[a] + l];
                if (g < nf)
                    w->u[6 * (size_t)region[a] + l] = w->x[g];
            }
    }
    for (int32_t a = 0; a < n_region; a++)
        flag[region[a]] = 0;
    free(delta);
    free(idx);
    *n_region_out = n_region;
    *m_out = m;
    return ok;
}

/* design: thesis §5.8.3 adapts the radius between events: a global relaxation after a failed local
 * one, and a larger radius next time. A global solve costs a re-factorization here (the factor was
 * left stale by the changes), so a failed attempt first tries again locally at twice the radius,
 * from the improved state, while the region holds less than a quarter of the unknowns and still
 * grows (a fragment enclosed by cracks does not); only then is the solve global. The radius that
 * succeeded is kept for the next event, and shrinks by RADIUS_SHRINK after an event that succeeded at
 * the first try. */
/* design: "stresses recomputed only where nodes moved" (§5.8). The region's outer rings hardly move
 * (the correction decays away from the change): nodes whose displacement changed by less than a tenth
 * of solver.relax_tolerance times the largest change keep their elements' stresses, whose error is
 * then of that order relative to the change, below what the acceptance bound already allows. */

/* Moves the region's nodes (n of them, the first n_seeds of them the seeds, which always count) whose
 * free displacement changed since the call began (save_x) by more than the fraction of the largest
 * change that the design note gives to the front of region; returns their count. */
static int32_t moved_nodes(const fs_wedge_model *w, int32_t *region, int32_t n, int32_t n_seeds)
{
    double largest = 0.0;
    double *change = fs_malloc(((size_t)n + 1) * sizeof *change);
    for (int32_t a = 0; a < n; a++) {
        double c = 0.0;
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)region[a] + l];
            if (g < w->n_free)
                c = fmax(c, fabs(w->x[g] - (w->rs.saved[g] ? w->rs.before[g] : w->x[g])));
        }
        change[a] = c;
        largest = fmax(largest, c);
    }
    int32_t m = 0;
    for (int32_t a = 0; a < n; a++)
        if (a < n_seeds || change[a] > 0.1 * w->cfg.solver.relax_tolerance * largest) {
            int32_t keep = region[a];
            region[a] = region[m];
            region[m++] = keep;
        }
    free(change);
    return m;
}

static int relax_region(fs_wedge_model *w, const int32_t *seeds, int32_t n_seeds, double *r, double tol,
                        double *dist, uint8_t *flag)
{
    int32_t nf = w->n_free, nn = w->n_nodes;
    int32_t *region = fs_malloc(((size_t)nn + 1) * sizeof *region);
    double radius = w->relax_radius;
    int rc = 0;
    int32_t n_before = -1;
    for (int tries = 0;; tries++) {
        int32_t n_region = 0, m = 0;
        int ok = attempt(w, seeds, n_seeds, radius, tol, r, dist, flag, w->rs.map, region, &n_region, &m);
        if (ok && norm_max(r, nf) <= tol) {
            w->counters.local_relaxations++;
            w->relax_radius = tries == 0 ? fmax(RADIUS_SHRINK * radius, w->relax_unit) : radius;
            rc = local_stresses(w, region, moved_nodes(w, region, n_region, n_seeds));
            break;
        }
        double cap = radius_cap(w);
        if (!ok || 4 * (int64_t)m >= nf || radius >= cap || n_region == n_before) {
            /* the global fallback: re-factorizes a stale factor; CG starts from the improved w->x */
            w->counters.global_fallbacks++;
            w->relax_radius = fmin(RADIUS_GROW * radius, cap);
            rc = fs_wedge_equilibrium(w, w->time);
            break;
        }
        w->counters.relax_retries++;
        radius = fmin(RADIUS_GROW * radius, cap);
        n_before = n_region;
    }
    for (int32_t q = 0; q < w->rs.n_touched; q++)
        w->rs.saved[w->rs.touched[q]] = 0;
    w->rs.n_touched = 0;
    free(region);
#ifdef FS_VALIDATE
    if (rc == 0)
        fs_wedge_check_state(w, "a local relaxation");
#endif
    return rc;
}

/* One entry of f - K u: the residual of free unknown g, of node `node`, from the loads at the current
 * coefficients and the stiffness couplings with every unknown of the nodes sharing a living element
 * with it (the only nonzero ones), free (w->x) and fixed (w->u_fixed). nb is scratch for the neighbour
 * list, flag (per node) is 0 on entry and on return. */
static double row_residual(const fs_wedge_model *w, int32_t g, int32_t node, ilist_t *nb, uint8_t *flag)
{
    int32_t nf = w->n_free;
    double coef[FS_WEDGE_PATTERNS];
    fs_wedge_load_coefficients(w, coef);
    double s = 0.0;
    for (int q = 0; q < FS_WEDGE_PATTERNS; q++)
        s += coef[q] * w->load[FS_WEDGE_PATTERNS * (size_t)g + q];
    nb->n = 0;
    for (int32_t p = w->node_elem_start[node]; p < w->node_elem_start[node] + w->node_elem_count[node]; p++) {
        int32_t e = w->node_elem[p];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        for (int c = 0; c < 3; c++) {
            int32_t b = w->mesh->tri[3 * (size_t)e + c];
            if (!flag[b]) {
                flag[b] = 1;
                nb->v[nb->n++] = b;
            }
        }
    }
    for (int32_t q = 0; q < nb->n; q++) {
        int32_t b = nb->v[q];
        flag[b] = 0;
        for (int l = 0; l < 6; l++) {
            int32_t j = w->dof[6 * (size_t)b + l];
            double v = j < nf ? w->x[j] : w->u_fixed[j - nf];
            if (v != 0.0)
                s -= fs_wedge_system_entry(w, g, j) * v;
        }
    }
    return s;
}

/* design: the residual is kept between events. After an accepted local relaxation every entry of
 * f - K u is within the bound; a cut (fs_wedge_apply_change) changes the couplings and loads of the
 * nodes of the elements it changed only (w->dirty_nodes), whose rows are recomputed one by one; new
 * free unknowns come last, so the old ones keep their index. So an event costs what its region costs,
 * not a pass over the whole matrix. The bound keeps the load norm of the last full computation (a
 * cut changes it by the loads of a few elements). Anything else that moves the model (a global solve,
 * a new time, a removal or subdivision) makes the kept residual invalid, and the next call computes
 * it in full. The same goes for the rest of the state: the fixed DOFs' displacements are computed
 * only for the nodes a cut added or moved (fs_wedge_prescribe_fixed), x is copied from u only when
 * something left them apart (x_synced), and the scratch stays allocated (w->rs). */
int fs_wedge_relax(fs_wedge_model *w, const int32_t *changed_nodes, int32_t n)
{
    double t0 = fs_seconds();
    if (w->relax_unit <= 0.0) {
        w->relax_unit = fs_wedge_mean_edge(w);
        w->relax_radius = w->cfg.solver.relax_radius * w->relax_unit;
    }
    int32_t nf = w->n_free, nn = w->n_nodes;
    fs_wedge_prescribe_fixed(w);
    if (!w->x_synced)
        fs_wedge_sync_x(w, 0);
#ifdef FS_VALIDATE
    for (int32_t i = 0; i < nn; i++)
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            FS_INVARIANT(g >= nf || memcmp(&w->x[g], &w->u[6 * (size_t)i + l], sizeof *w->x) == 0,
                         "wedge model at time %g: free DOF %d (node %d) has x %.17g but u %.17g", w->time, (int)g,
                         (int)i, w->x[g], w->u[6 * (size_t)i + l]);
        }
#endif
    scratch_reserve(w);
    double *dist = w->rs.dist;
    uint8_t *flag = w->rs.flag;
    int32_t *seeds = fs_malloc(((size_t)nn + 1) * sizeof *seeds), n_seeds = 0;
    for (int32_t q = 0; q < n; q++)
        if (!flag[changed_nodes[q]]) {
            flag[changed_nodes[q]] = 1;
            seeds[n_seeds++] = changed_nodes[q];
        }

    /* 1. the residual, and as seeds the nodes with a free DOF out of balance */
    double *r, tau;
    if (w->residual_valid && w->residual_n <= nf) {
        r = fs_realloc(w->residual, ((size_t)nf + 1) * sizeof *r);
        w->residual = NULL;
        tau = w->residual_tau;
        /* new nodes come last, and so do their unknowns: all of them are recomputed */
        int32_t first_new = nn, cap = 0;
        while (first_new > 0 && w->dof[6 * (size_t)(first_new - 1) + 3] >= w->residual_n)
            first_new--;
        for (int32_t q = 0; q < w->n_dirty + (nn - first_new); q++) {
            int32_t i = q < w->n_dirty ? w->dirty_nodes[q] : first_new + (q - w->n_dirty);
            cap = w->node_elem_count[i] > cap ? w->node_elem_count[i] : cap;
        }
        ilist_t nb = {fs_malloc((3 * (size_t)cap + 1) * sizeof *nb.v), 0};
        uint8_t *seen = w->rs.seen;
        for (int32_t q = 0; q < w->n_dirty + (nn - first_new); q++) {
            int32_t i = q < w->n_dirty ? w->dirty_nodes[q] : first_new + (q - w->n_dirty);
            bool out = false;
            for (int l = 3; l < 6; l++) {
                int32_t g = w->dof[6 * (size_t)i + l];
                if (g < nf) {
                    r[g] = row_residual(w, g, i, &nb, seen);
                    out |= fabs(r[g]) > tau;
                }
            }
            if (out && !flag[i]) {
                flag[i] = 1;
                seeds[n_seeds++] = i;
            }
        }
        free(nb.v);
    } else {
        r = fs_malloc(((size_t)nf + 1) * sizeof *r);
        double b_norm = residual(w, r);
        tau = nf > 0 ? w->cfg.solver.relax_tolerance * b_norm / sqrt((double)nf) : 0.0;
        for (int32_t i = 0; i < nn; i++) {
            if (flag[i])
                continue;
            for (int l = 3; l < 6; l++) {
                int32_t g = w->dof[6 * (size_t)i + l];
                if (g < nf && fabs(r[g]) > tau) {
                    flag[i] = 1;
                    seeds[n_seeds++] = i;
                    break;
                }
            }
        }
    }
    w->n_dirty = 0;
    for (int32_t q = 0; q < n_seeds; q++)
        flag[seeds[q]] = 0;
    int rc = 0;
    w->residual_valid = true; /* unless the relaxation falls back on a global solve */
    if (n_seeds == 0)
        w->counters.local_relaxations++; /* in balance already */
    else
        rc = relax_region(w, seeds, n_seeds, r, tau, dist, flag);
    if (rc == 0 && w->residual_valid) {
        free(w->residual);
        w->residual = r;
        w->residual_n = nf;
        w->residual_tau = tau;
    } else {
        w->residual_valid = false;
        free(r);
    }
    free(seeds);
    w->counters.local_seconds += fs_seconds() - t0;
    return rc;
}
