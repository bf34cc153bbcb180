/* The wedge model's equilibrium: the right-hand side, the solve, stresses and fracture ratios, snapshots and their blend (thesis §5.5-5.6). */
#include "model/wedge/internal.h"

#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/threads.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "fracture/rank.h"
#include "fracture/separation.h"
#include "model/wedge/element.h"
#include "solve/cg.h"

/* ---- equilibrium ---- */

/* Displacement at time t of node i's fixed DOFs of fixed index `from` on: the prescribed value plus,
 * for the bottom node, its growth motion (moving mode). */
static void fixed_node(fs_wedge_model *w, int32_t i, double t, int32_t from)
{
    const double *p = w->mesh->pos + 3 * (size_t)i;
    double q[3];
    bool move = w->growth_mode == FS_WEDGE_GROWTH_MOVE;
    if (move)
        fs_growth_flow(&w->growth, p, 0.0, t, q);
    for (int l = 0; l < 6; l++) {
        int32_t j = w->dof[6 * (size_t)i + l] - w->n_free; /* negative: free */
        if (j < from)
            continue;
        w->u_fixed[j] = w->prescribed[6 * (size_t)i + l];
        if (move && l < 3)
            w->u_fixed[j] += q[l] - p[l];
    }
}

/* The displacements of the fixed DOFs from the fixed index `from` on (the others untouched) at time
 * t. A node's fixed DOFs follow those of the nodes before it (fs_wedge_number_dofs), so the nodes
 * start at the one of index from. */
static void fixed_displacements(fs_wedge_model *w, double t, int32_t from)
{
    for (int32_t i = from < w->n_fixed ? w->fixed_node_dof[from] / 6 : w->n_nodes; i < w->n_nodes; i++)
        fixed_node(w, i, t, from);
    w->n_fixed_moved = 0;
}

void fs_wedge_build_rhs(fs_wedge_model *w)
{
    int32_t nf = w->n_free;
    double coef[FS_WEDGE_PATTERNS];
    fs_wedge_load_coefficients(w, coef);
    for (int32_t i = 0; i < nf; i++) {
        double s = 0.0;
        for (int q = 0; q < FS_WEDGE_PATTERNS; q++)
            s += coef[q] * w->load[FS_WEDGE_PATTERNS * (size_t)i + q];
        w->rhs[i] = s;
    }
    const fs_wedge_coupling *c = &w->k_fb;
    for (int32_t k = 0; k < c->n; k++) {
        double uk = w->u_fixed[k];
        if (uk == 0.0)
            continue;
        for (int32_t p = c->start[k]; p < c->start[k] + c->len[k]; p++)
            w->rhs[c->row[p]] -= c->value[p] * uk;
    }
}

/* Scales the starting guess w->x of a CG solve by the factor that minimises the energy along it,
 * (x . b) / (x . K x): the previous displacements fit the new loads exactly when those are the old ones
 * times a factor (shrinkage and isogonic growth from a common start), and closely when nearly so. */
static void scale_guess(fs_wedge_model *w)
{
    int32_t n = w->n_free;
    double *kx = fs_malloc((size_t)n * sizeof *kx);
    fs_sparse_matvec(&w->k_free, w->x, kx);
    double xb = 0.0, xkx = 0.0;
    for (int32_t i = 0; i < n; i++) {
        xb += w->x[i] * w->rhs[i];
        xkx += w->x[i] * kx[i];
    }
    free(kx);
    if (xkx > 0.0 && isfinite(xb / xkx))
        for (int32_t i = 0; i < n; i++)
            w->x[i] *= xb / xkx;
}

/* design: with local relaxation (thesis §5.8) the mesh changes at nearly every event and the factor
 * is dropped (fs_wedge_apply_change); re-analysing and re-factorizing it for each global solve cost
 * 5-10 times a conjugate-gradient solve started from the current displacements, which are close to
 * the answer (the layer is well conditioned: every wedge's bottom is held). So a global solve with
 * a stale factor is done by CG to solver.tolerance. The factor is made again only by a refill at a
 * new thickness (fs_wedge_refill_system), by the fallback below, or on request (fs_wedge_refactor).
 * Even on bark-l, whose CG solves take about 100 iterations, analysing and factorizing at every
 * global solve instead cost 7.4 s against CG's 6.4 s. */
static int solve(fs_wedge_model *w)
{
    double t0 = fs_seconds();
    int rc = 0;
    if (w->n_free == 0) {
    } else if (w->cfg.solver.method == FS_SOLVER_CHOLMOD && !w->factor_stale) {
        rc = fs_cholesky_solve(w->chol, 1, w->rhs, w->x);
    } else {
        fs_cg_params p = fs_cg_params_default();
        p.tolerance = w->cfg.solver.tolerance;
        p.max_iterations = w->cfg.solver.max_iterations;
        if (w->cfg.solver.method == FS_SOLVER_CHOLMOD) {
            /* the CG baseline stays the thesis's: Jacobi, from the previous displacements */
            scale_guess(w);
            p.block = 3; /* a node's three unknowns are consecutive (number_dofs) */
        }
        int it = fs_cg_solve(&w->k_free, w->rhs, w->x, p, NULL);
        if (it >= 0) {
            w->counters.cg_iterations += it;
        } else if (w->cfg.solver.method == FS_SOLVER_CHOLMOD) {
            /* CG can stall on a mesh that many cuts have left ill-conditioned: a fresh analysis (the
             * pattern has changed since the factor) and factorization, and the direct solve */
            fs_debug("wedge: %s; solving with a fresh factorization", fs_error_message());
            fs_error_clear();
            rc = fs_wedge_factorize(w, true);
            if (rc == 0)
                rc = fs_cholesky_solve(w->chol, 1, w->rhs, w->x);
        } else {
            rc = -1;
        }
    }
    w->counters.solves++;
    w->counters.solve_seconds += fs_seconds() - t0;
    return rc;
}

static void gather_u(const fs_wedge_model *w, int32_t e, double ue[18])
{
    const int32_t *tri = w->mesh->tri + 3 * (size_t)e;
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            ue[3 * c + k] = w->u[6 * (size_t)tri[c] + k];
            ue[3 * (c + 3) + k] = w->u[6 * (size_t)tri[c] + 3 + k];
        }
}

/* Stress from a strain net of the eigenstrain: sigma = E D1 (strain - eps0). */
static void stress_of(const fs_wedge_model *w, int32_t e, const double strain[6], double stress[6])
{
    double eps[6] = {strain[0] - w->eigenstrain[0], strain[1] - w->eigenstrain[1], strain[2],
                     strain[3] - w->eigenstrain[2], strain[4], strain[5]};
    for (int i = 0; i < 6; i++) {
        double s = 0.0;
        for (int j = 0; j < 6; j++)
            s += w->d_unit[6 * i + j] * eps[j];
        stress[i] = w->young[e] * s;
    }
}

int fs_wedge_element_stress(const fs_wedge_model *w, int32_t e, double r, double s, double zeta, double stress[6])
{
    double x[18], ue[18], u0[18], strain[6];
    fs_wedge_element_coords(w, e, x);
    gather_u(w, e, ue);
    fs_wedge_shrink_displacement(w, x, u0);
    for (int a = 0; a < 18; a++)
        ue[a] -= u0[a];
    if (fs_wedge_strain(x, ue, r, s, zeta, strain) < 0)
        return -1;
    stress_of(w, e, strain, stress);
    return 0;
}

/* Strain (Voigt, engineering shears) of nodal displacements u from the shape-function gradients. */
static void strain_from_gradients(const double dndx[18], const double u[18], double strain[6])
{
    double g[3][3] = {{0}};
    for (int n = 0; n < 6; n++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                g[i][j] += dndx[3 * n + j] * u[3 * n + i];
    fs_voigt_strain(g, strain);
}

/* design: a bound of how fast an element's ratio can change with its nodal displacements u_e, for
 * the lazy re-evaluation in element_ratios. The stress at a Gauss point is linear in u_e, sigma = E D B
 * u_e + const, and the largest eigenvalue of a symmetric tensor moves by at most the spectral norm of
 * the change (Weyl), which is at most its Frobenius norm, at most ||W D B||_F ||du_e|| (W weighs the
 * Voigt shears by sqrt 2 to give the tensor norm). The largest over the three top Gauss points, times
 * E over the threshold. */
static double ratio_lipschitz(const fs_wedge_model *w, int32_t e, const double *cache)
{
    double worst = 0.0;
    for (int g = 0; g < FS_WEDGE_GAUSS_TOP; g++) {
        const double *dndx = cache + 18 * g;
        double sum = 0.0;
        for (int a = 0; a < 18; a++) {
            /* the strain of a unit displacement a = 3 n + i (strain_from_gradients of a unit vector):
             * the gradient's row i is node n's shape-function gradient */
            double g3[3][3] = {{0}}, strain[6];
            for (int j = 0; j < 3; j++)
                g3[a % 3][j] = dndx[3 * (a / 3) + j];
            fs_voigt_strain(g3, strain);
            for (int i = 0; i < 6; i++) {
                double s = 0.0;
                for (int j = 0; j < 6; j++)
                    s += w->d_unit[6 * i + j] * strain[j];
                sum += (i < 3 ? 1.0 : 2.0) * s * s;
            }
        }
        worst = fmax(worst, sqrt(sum));
    }
    return worst * w->young[e] / w->threshold[e];
}

int fs_wedge_refresh_cache(fs_wedge_model *w, const int32_t *elems, int32_t n)
{
    for (int32_t q = 0; q < n; q++) {
        int32_t e = elems ? elems[q] : q;
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        double x[18], pat[FS_WEDGE_PATTERNS][18], detj;
        fs_wedge_element_coords(w, e, x);
        fs_wedge_patterns(x, pat);
        double *c = w->gauss_cache + FS_WEDGE_GAUSS_CACHE * (size_t)e;
        for (int g = 0; g < FS_WEDGE_GAUSS_TOP; g++) {
            double *dndx = c + 18 * g;
            if (fs_wedge_gradients(x, fs_wedge_gauss[g][0], fs_wedge_gauss[g][1], fs_wedge_gauss[g][2], dndx, &detj) < 0) {
                fs_error(FS_ERR_DATA, "wedge model: element %d is inverted or degenerate (det J = %g)", (int)e, detj);
                return -1;
            }
            for (int k = 0; k < 3; k++)
                strain_from_gradients(dndx, pat[k], c + 54 + 18 * g + 6 * k);
        }
        w->ratio_lipschitz[e] = ratio_lipschitz(w, e, c);
        w->ratio_ref_bound[e] = NAN;
        for (int k = 0; k < 3; k++) {
            double a[3], b[3], d[3];
            fs_mesh_corner(w->mesh, e, k, a);
            fs_mesh_corner(w->mesh, e, (k + 1) % 3, b);
            fs_sub3(d, a, b);
            w->edge_rest[3 * (size_t)e + k] = fs_norm3(d);
        }
    }
    return 0;
}

/* Lazy ratio bounds (element_ratios) above this are evaluated in full: below 1 by more than the tie
 * tolerance of fracture/rank.h, so a lazy bound never joins a tie with a maximum over 1. */
#define LAZY_LEVEL (1.0 - 4.0 * FS_RANK_TIE_REL)

/* Relative allowance for rounding in a lazy ratio bound. */
#define LAZY_MARGIN 1e-9

double fs_wedge_element_ratio(const fs_wedge_model *w, int32_t e)
{
    if (w->state[e] != FS_WEDGE_ALIVE)
        return NAN;
    double best = -INFINITY, sigma[3];
    for (int g = 0; g < FS_WEDGE_GAUSS_TOP; g++) {
        if (fs_eigen_principal_stress(w->stress_top + 18 * (size_t)e + 6 * g, sigma, NULL) < 0)
            return NAN;
        best = fmax(best, sigma[0]);
    }
    return best / w->threshold[e];
}

typedef struct {
    double bound;
    int32_t e;
} bound_entry;

/* Whether x comes before y: the larger bound first, the smaller element on a tie. */
static bool bound_before(const bound_entry *x, const bound_entry *y)
{
    return x->bound != y->bound ? x->bound > y->bound : x->e < y->e;
}

/* Moves h[i] down the binary heap h (n entries, the first in bound_before order at the root). */
static void heap_down(bound_entry *h, int32_t n, int32_t i)
{
    for (;;) {
        int32_t l = 2 * i + 1, r = l + 1, top = i;
        if (l < n && bound_before(h + l, h + top))
            top = l;
        if (r < n && bound_before(h + r, h + top))
            top = r;
        if (top == i)
            return;
        bound_entry t = h[i];
        h[i] = h[top];
        h[top] = t;
        i = top;
    }
}

/* design: thesis §5.6.1 evaluates the stress at the three Gauss points nearest the top face ("the
 * resulting 9 values are sorted, and the largest one is compared against the material's threshold
 * stress"). Every removal asks only whether the largest ratio exceeds 1 and which element has it
 * (fracture/rank.h, ties within FS_RANK_TIE_REL; splitting decides on nodal ratios computed from the
 * stresses, wedge/split.c, and leaves the element ratios as bounds), so the shared eigen kernel runs
 * only on the elements whose upper bound (fs_eigen_principal_bound) could reach the largest exact
 * ratio, in descending order of the bound, until the next bound falls below the best exact ratio
 * found (less the tie tolerance). Every other ratio holds its bound. Where the layer holds many
 * elements over 1 that do not break (Griffith's criterion stops cracks), the candidates come off a
 * binary heap, in the same order as a sort, which would cost n log n at every call for the few that
 * are needed; the heap holds only the elements whose bound reaches the exact ratio of the first
 * candidate (the largest bound) less the tie tolerance, as no other could come off it before the
 * search stops.
 * With lazy_ratios, an element evaluated before at the same shrinkage and eigenstrain is not evaluated
 * again while its old bound plus ratio_lipschitz times the change of its nodal displacements stays at
 * most LAZY_LEVEL: that sum bounds the exact ratio too. After a removal the displacements change
 * little away from the crack tip (within a few layer thicknesses), so most elements are skipped. Every
 * element that could be over 1 or tie with a maximum over 1 still gets its full bound, so the
 * candidates, the exact ratios and the decisions are the same as without. The bounds of a long list
 * (a whole layer's, a large relaxation's) are evaluated on several threads in fixed parts
 * (fs_parallel_ranges), each element writing only its own slots; the nodal ratios its corners share
 * are marked stale afterwards on the calling thread, so the results do not depend on the threads. */
/* The corners of element e need their nodal ratios recomputed. */
static void touch_nodes(fs_wedge_model *w, int32_t e)
{
    for (int c = 0; c < 3; c++)
        w->node_ratio[w->mesh->tri[3 * (size_t)e + c]] = NAN;
}

/* The listed elements' ratio bounds (fs_wedge_element_ratios) on one thread. */
typedef struct {
    fs_wedge_model *w;
    const int32_t *elems;
    uint8_t *touched; /* per listed element: 1 if its corners' nodal ratios need recomputing */
} ratio_pass;

static void ratio_range(void *ctx, int32_t q0, int32_t q1)
{
    const ratio_pass *c = ctx;
    fs_wedge_model *w = c->w;
    for (int32_t q = q0; q < q1; q++) {
        int32_t e = c->elems ? c->elems[q] : q;
        c->touched[q] = 1;
        if (w->state[e] != FS_WEDGE_ALIVE) {
            w->ratio[e] = NAN;
            continue;
        }
        double ue[18];
        gather_u(w, e, ue);
        double *ref_u = w->ratio_ref_u + 18 * (size_t)e;
        if (w->lazy_ratios && !isnan(w->ratio_ref_bound[e])) {
            double d2 = 0.0;
            for (int a = 0; a < 18; a++)
                d2 += (ue[a] - ref_u[a]) * (ue[a] - ref_u[a]);
            double ref = w->ratio_ref_bound[e];
            double lazy = ref + w->ratio_lipschitz[e] * sqrt(d2) + LAZY_MARGIN * fabs(ref);
            if (lazy <= LAZY_LEVEL) {
                w->ratio[e] = lazy;
                c->touched[q] = 0;
                continue;
            }
        }
        const double *gc = w->gauss_cache + FS_WEDGE_GAUSS_CACHE * (size_t)e;
        double *st = w->stress_top + 18 * (size_t)e, bound = -INFINITY;
        for (int g = 0; g < FS_WEDGE_GAUSS_TOP; g++) {
            double strain[6];
            strain_from_gradients(gc + 18 * g, ue, strain);
            for (int k = 0; k < 3; k++)
                for (int v = 0; v < 6; v++)
                    strain[v] -= w->shrink_coef[k] * gc[54 + 18 * g + 6 * k + v];
            stress_of(w, e, strain, st + 6 * g);
            bound = fmax(bound, fs_eigen_principal_bound(st + 6 * g, w->threshold[e]));
        }
        w->ratio[e] = bound / w->threshold[e];
        w->ratio_ref_bound[e] = w->ratio[e];
        memcpy(ref_u, ue, sizeof ue);
    }
}

/* The smallest bound that could still tie with, or beat, the best exact ratio found (fracture/rank.h);
 * it grows with best. */
static double tie_floor(double best)
{
    return best - 2.0 * FS_RANK_TIE_REL * fabs(best);
}

/* Fewer listed elements than this are evaluated on the calling thread. */
#define RATIO_PARALLEL_MIN 2048

int fs_wedge_element_ratios(fs_wedge_model *w, const int32_t *elems, int32_t n_elems)
{
    double t0 = fs_seconds();
    double coef[FS_WEDGE_PATTERNS];
    fs_wedge_load_coefficients(w, coef);
    if (memcmp(coef, w->ratio_ref_coef, sizeof coef) != 0) {
        for (int32_t e = 0; e < w->n_elems; e++)
            w->ratio_ref_bound[e] = NAN;
        memcpy(w->ratio_ref_coef, coef, sizeof coef);
    }
    /* each element writes only its own slots; the nodal ratios its corners share are marked after */
    ratio_pass pass = {w, elems, fs_malloc((size_t)n_elems + 1)};
    fs_parallel_ranges(n_elems, RATIO_PARALLEL_MIN, ratio_range, &pass);
    for (int32_t q = 0; q < n_elems; q++)
        if (pass.touched[q])
            touch_nodes(w, elems ? elems[q] : q);
    free(pass.touched);
    if (w->cfg.fracture.method == FS_FRACTURE_SPLIT) {
        /* splitting decides on nodal ratios from the stresses (wedge/split.c): only removal picks
         * from the element ratios, so they stay bounds */
        w->counters.stress_seconds += fs_seconds() - t0;
        return 0;
    }
    /* the elements over 1 and the first candidate among them; then the heap of those that could
     * still come off it: bounds within the tie tolerance of its exact ratio or over it (best only
     * grows) */
    bound_entry top = {-INFINITY, -1}, *list = NULL;
    int32_t n = 0, cap = 0;
    for (int32_t e = 0; e < w->n_elems; e++)
        if (w->state[e] == FS_WEDGE_ALIVE && w->ratio[e] > 1.0) {
            if (n == cap) {
                cap = 2 * cap + 64;
                list = fs_realloc(list, (size_t)cap * sizeof *list);
            }
            list[n++] = (bound_entry){w->ratio[e], e};
            if (top.e < 0 || bound_before(&list[n - 1], &top))
                top = list[n - 1];
        }
    if (top.e >= 0) {
        double best = fs_wedge_element_ratio(w, top.e);
        if (isnan(best)) {
            free(list);
            return -1;
        }
        w->ratio[top.e] = best;
        double lowest = tie_floor(best);
        int32_t kept = 0;
        for (int32_t q = 0; q < n; q++)
            if (list[q].e != top.e && list[q].bound >= lowest)
                list[kept++] = list[q];
        n = kept;
        for (int32_t i = n / 2 - 1; i >= 0; i--)
            heap_down(list, n, i);
        for (int32_t left = n; left > 0;) {
            bound_entry next = list[0];
            if (next.bound < tie_floor(best))
                break;
            list[0] = list[--left];
            heap_down(list, left, 0);
            double r = fs_wedge_element_ratio(w, next.e);
            if (isnan(r)) {
                free(list);
                return -1;
            }
            w->ratio[next.e] = r;
            best = fmax(best, r);
        }
        free(list);
    }
    w->counters.stress_seconds += fs_seconds() - t0;
    return 0;
}

/* w->u from the free unknowns w->x and the fixed displacements w->u_fixed. */
static void scatter_u(fs_wedge_model *w)
{
    for (int32_t i = 0; i < w->n_nodes; i++)
        for (int l = 0; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            w->u[6 * (size_t)i + l] = g < w->n_free ? w->x[g] : w->u_fixed[g - w->n_free];
        }
    w->x_synced = true;
}

int fs_wedge_equilibrium(fs_wedge_model *w, double t)
{
    w->residual_valid = false;
    double h = fs_wedge_layer_thickness(w, t);
    if (h != w->assembled_thickness && fs_wedge_refill_system(w, h) < 0)
        return -1;
    double scale[3];
    fs_shrink_scales(&w->cfg.shrink, t, scale);
    for (int k = 0; k < 3; k++)
        w->shrink_coef[k] = scale[k] - 1.0;
    w->eigenstrain[0] = w->eigenstrain[1] = w->eigenstrain[2] = 0.0;
    if (w->growth_mode == FS_WEDGE_GROWTH_EIGENSTRAIN) {
        double v[3];
        fs_growth_strain(&w->growth, 0.0, t, NULL, v);
        for (int k = 0; k < 3; k++)
            w->eigenstrain[k] = -v[k];
    }
    w->fixed_exact = 0; /* until u holds them too */
    w->x_synced = false;
    fixed_displacements(w, t, 0);
    fs_wedge_build_rhs(w);
    if ((w->factor_stale && w->cfg.solver.relax != FS_RELAX_LOCAL && fs_wedge_factorize(w, false) < 0) || solve(w) < 0)
        return -1;
    scatter_u(w);
    w->time = t;
    w->fixed_time = t;
    w->fixed_exact = w->n_fixed;
    int rc = fs_wedge_element_ratios(w, NULL, w->n_elems);
#ifdef FS_VALIDATE
    if (rc == 0)
        fs_wedge_check_state(w, "an equilibrium");
#endif
    return rc;
}

void fs_wedge_snapshot_take(const fs_wedge_model *w, fs_wedge_snapshot *s)
{
    s->time = w->time;
    s->thickness = w->assembled_thickness;
    memcpy(s->coef, w->shrink_coef, sizeof w->shrink_coef);
    memcpy(s->coef + 3, w->eigenstrain, sizeof w->eigenstrain);
    if (s->n_free != w->n_free || !s->x) {
        free(s->x);
        s->x = fs_malloc(((size_t)w->n_free + 1) * sizeof *s->x);
    }
    if (s->n_fixed != w->n_fixed || !s->u_fixed) {
        free(s->u_fixed);
        s->u_fixed = fs_malloc(((size_t)w->n_fixed + 1) * sizeof *s->u_fixed);
    }
    if (s->n_nodes != w->n_nodes || !s->node_ratio) {
        free(s->node_ratio);
        free(s->node_ratio_exact);
        s->node_ratio = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *s->node_ratio);
        s->node_ratio_exact = fs_malloc((size_t)w->n_nodes + 1);
    }
    if (s->n_elems != w->n_elems || !s->stress_top) {
        free(s->stress_top);
        s->stress_top = fs_malloc((18 * (size_t)w->n_elems + 1) * sizeof *s->stress_top);
    }
    s->n_free = w->n_free;
    s->n_fixed = w->n_fixed;
    s->n_nodes = w->n_nodes;
    s->n_elems = w->n_elems;
    memcpy(s->x, w->x, (size_t)w->n_free * sizeof *s->x);
    memcpy(s->u_fixed, w->u_fixed, (size_t)w->n_fixed * sizeof *s->u_fixed);
    memcpy(s->node_ratio, w->node_ratio, (size_t)w->n_nodes * sizeof *s->node_ratio);
    memcpy(s->node_ratio_exact, w->node_ratio_exact, (size_t)w->n_nodes);
    memcpy(s->stress_top, w->stress_top, 18 * (size_t)w->n_elems * sizeof *s->stress_top);
}

void fs_wedge_snapshot_free(fs_wedge_snapshot *s)
{
    free(s->x);
    free(s->u_fixed);
    free(s->node_ratio);
    free(s->node_ratio_exact);
    free(s->stress_top);
    memset(s, 0, sizeof *s);
}

int fs_wedge_interpolate(fs_wedge_model *w, const fs_wedge_snapshot *a, const fs_wedge_snapshot *b, double t)
{
    FS_ASSERT(a->n_free == w->n_free && b->n_free == w->n_free && a->n_fixed == w->n_fixed &&
              b->n_fixed == w->n_fixed);
    double span = b->time - a->time, s = span > 0.0 ? (t - a->time) / span : 1.0;
    w->residual_valid = false;
    for (int k = 0; k < 3; k++) {
        w->shrink_coef[k] = a->coef[k] + s * (b->coef[k] - a->coef[k]);
        w->eigenstrain[k] = a->coef[3 + k] + s * (b->coef[3 + k] - a->coef[3 + k]);
    }
    for (int32_t i = 0; i < w->n_free; i++)
        w->x[i] = a->x[i] + s * (b->x[i] - a->x[i]);
    for (int32_t j = 0; j < w->n_fixed; j++)
        w->u_fixed[j] = a->u_fixed[j] + s * (b->u_fixed[j] - a->u_fixed[j]);
    w->fixed_exact = 0; /* a blend, not what fixed_displacements gives */
    scatter_u(w);
    w->time = t;
    return fs_wedge_element_ratios(w, NULL, w->n_elems);
}

int fs_wedge_update_ratios(fs_wedge_model *w, const int32_t *elems, int32_t n)
{
    return fs_wedge_element_ratios(w, elems, elems ? n : w->n_elems);
}

void fs_wedge_node_moved(fs_wedge_model *w, int32_t node)
{
    if (node >= w->n_nodes)
        return; /* a node of the cut under way: its fixed DOFs are new */
    FS_ARRAY_RESERVE(w->fixed_moved, w->cap_fixed_moved, w->n_fixed_moved + 1, 16);
    w->fixed_moved[w->n_fixed_moved++] = node;
}

void fs_wedge_sync_x(fs_wedge_model *w, int32_t first)
{
    for (int32_t i = first; i < w->n_nodes; i++)
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g < w->n_free)
                w->x[g] = w->u[6 * (size_t)i + l];
        }
    w->x_synced = true;
}

void fs_wedge_prescribe_fixed(fs_wedge_model *w)
{
    /* the fixed DOFs the model holds at this time already keep their values (a cut adds some and
     * keeps the others' numbers): the same as computing them again, without a pass over the mesh */
    int32_t from = w->fixed_time == w->time ? w->fixed_exact : 0;
    for (int32_t q = 0; q < w->n_fixed_moved && from > 0; q++) { /* nodes a cut moved */
        int32_t i = w->fixed_moved[q];
        fixed_node(w, i, w->time, 0);
        for (int l = 0; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g >= w->n_free)
                w->u[6 * (size_t)i + l] = w->u_fixed[g - w->n_free];
        }
    }
    fixed_displacements(w, w->time, from);
    /* fixed_node_dof lists the node DOF of each fixed one (fs_wedge_number_dofs) */
    for (int32_t j = from; j < w->n_fixed; j++)
        w->u[w->fixed_node_dof[j]] = w->u_fixed[j];
    w->fixed_time = w->time;
    w->fixed_exact = w->n_fixed;
#ifdef FS_VALIDATE
    /* the kept values are those of computing all of them afresh, bit for bit */
    double *kept = fs_malloc(((size_t)w->n_fixed + 1) * sizeof *kept);
    memcpy(kept, w->u_fixed, (size_t)w->n_fixed * sizeof *kept);
    fixed_displacements(w, w->time, 0);
    for (int32_t j = 0; j < w->n_fixed; j++)
        FS_INVARIANT(memcmp(&kept[j], &w->u_fixed[j], sizeof *kept) == 0 &&
                         memcmp(&w->u[w->fixed_node_dof[j]], &kept[j], sizeof *kept) == 0,
                     "wedge model at time %g: fixed DOF %d (node DOF %d) kept %.17g, u %.17g, afresh %.17g",
                     w->time, (int)j, (int)w->fixed_node_dof[j], kept[j], w->u[w->fixed_node_dof[j]],
                     w->u_fixed[j]);
    free(kept);
#endif
}

double fs_wedge_max_ratio(const fs_wedge_model *w)
{
    double best = -INFINITY;
    for (int32_t e = 0; e < w->n_elems; e++)
        if (w->state[e] == FS_WEDGE_ALIVE && w->ratio[e] > best)
            best = w->ratio[e];
    return best;
}

int fs_wedge_nodal_stress(const fs_wedge_model *w, int32_t node, bool top, double stress[6])
{
    /* The Gauss point nearest corner c: (2/3, 1/6) for node 0 (r = 1), (1/6, 2/3) for node 1 (s = 1),
     * (1/6, 1/6) for node 2; the top row of Table 5.1 for top nodes, the bottom row otherwise. */
    fs_nodal_stress mean = {{0.0}, 0};
    for (int32_t p = w->node_elem_start[node]; p < w->node_elem_start[node] + w->node_elem_count[node]; p++) {
        int32_t e = w->node_elem[p];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        int c = 0;
        while (c < 3 && w->mesh->tri[3 * (size_t)e + c] != node)
            c++;
        FS_ASSERT(c < 3);
        const double *g = fs_wedge_gauss[(top ? 0 : 6) + c];
        double s[6];
        if (fs_wedge_element_stress(w, e, g[0], g[1], g[2], s) < 0)
            return -1;
        fs_nodal_stress_add(&mean, s);
    }
    fs_nodal_stress_mean(&mean, stress);
    return mean.count;
}


/* design: Griffith's balance (wedge/split.c) sums the strain energy of the elements within a few
 * rings of a crack tip before and after each cut, some 160 elements. Nearly all of them are the same
 * elements, with the same stiffness and mostly the same displacements, as at the balance before, so
 * each element keeps the inputs of its stiffness (coordinates, corner thickness factors, modulus), the
 * stiffness (its upper triangle: the quadrature's stiffness is symmetric entry for entry), and the
 * displacements, load coefficients and energy last computed from them. A stiffness is kept only when
 * the same inputs give the same one again (fs_wedge_stiffness_repeats), so the results are those of
 * computing everything afresh, bit for bit. */
#define ENERGY_INPUTS 22
struct fs_wedge_energy_kept {
    double in[ENERGY_INPUTS];        /* coordinates, corner thickness factors, Young's modulus; in[0]
                                        NaN: none */
    double k[FS_WEDGE_PAIRS];        /* the stiffness's upper triangle, row by row */
    double u[18], coef[FS_WEDGE_PATTERNS]; /* the displacements and load coefficients of energy */
    double energy;                   /* NaN: not computed for u and coef */
};

void fs_wedge_energy_forget(fs_wedge_model *w)
{
    for (int32_t e = 0; w->energy_kept && e < w->elem_cap; e++) {
        free(w->energy_kept[e]);
        w->energy_kept[e] = NULL;
    }
}

double fs_wedge_element_energy(fs_wedge_model *w, int32_t e)
{
    if (w->state[e] != FS_WEDGE_ALIVE)
        return 0.0;
    struct fs_wedge_energy_kept *kept = w->energy_kept[e];
    if (!kept) {
        kept = w->energy_kept[e] = fs_malloc(sizeof *kept);
        kept->in[0] = NAN;
    }
    double in[ENERGY_INPUTS], x[18], u[18], coef[FS_WEDGE_PATTERNS], K[324];
    fs_wedge_element_coords(w, e, x);
    memcpy(in, x, sizeof x);
    for (int c = 0; c < 3; c++)
        in[18 + c] = w->thickness_factor[w->mesh->tri[3 * (size_t)e + c]];
    in[21] = w->young[e];
    gather_u(w, e, u);
    fs_wedge_load_coefficients(w, coef);
    if (!isnan(kept->in[0]) && memcmp(in, kept->in, sizeof in) == 0) {
        if (!isnan(kept->energy) && memcmp(u, kept->u, sizeof u) == 0 && memcmp(coef, kept->coef, sizeof coef) == 0)
            return kept->energy;
        for (int a = 0, q = 0; a < 18; a++)
            for (int b = a; b < 18; b++, q++)
                K[18 * a + b] = K[18 * b + a] = kept->k[q];
    } else {
        if (fs_wedge_element_stiffness(w, e, w->assembled_thickness, x, K) < 0) {
            fs_error_clear();
            return NAN;
        }
        for (int a = 0, q = 0; a < 18; a++)
            for (int b = a; b < 18; b++, q++)
                kept->k[q] = K[18 * a + b];
        memcpy(kept->in, in, sizeof in);
        if (!fs_wedge_stiffness_repeats(w, e))
            kept->in[0] = NAN; /* used this once */
    }
    double pat[FS_WEDGE_PATTERNS][18], ue[18];
    fs_wedge_patterns(x, pat);
    memcpy(ue, u, sizeof u);
    for (int a = 0; a < 18; a++)
        for (int q = 0; q < FS_WEDGE_PATTERNS; q++)
            ue[a] -= coef[q] * pat[q][a];
    double energy = 0.0;
    for (int a = 0; a < 18; a++) {
        double f = 0.0;
        for (int b = 0; b < 18; b++)
            f += K[18 * a + b] * ue[b];
        energy += f * ue[a];
    }
    energy *= 0.5;
    memcpy(kept->u, u, sizeof u);
    memcpy(kept->coef, coef, sizeof coef);
    kept->energy = isnan(kept->in[0]) ? NAN : energy;
    return energy;
}
