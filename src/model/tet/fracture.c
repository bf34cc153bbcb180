/* The tetrahedral model's fracture: node ratios from the separation tensor, event searches in time, node splits, bonds coming loose, local relaxation. */
#include "model/tet/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/sort.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "fracture/event.h"
#include "fracture/rank.h"
#include "fracture/separation.h"
#include "geom/region.h"
#include "model/tet/element.h"
#include "solve/cg.h"

/* Nodes with at most this many elements keep their element forces on the stack. */
#define NODE_TETS_ON_STACK 64
/* Event searches start with this fraction of the time left. */
#define SEARCH_FIRST_STEP 0.125
/* A node is searched again after a relaxation when one of its elements' stresses changed by more
 * than this fraction of the load's typical stress. */
#define SEARCH_AGAIN 1e-4
/* Relative residual at which the local systems' conjugate gradients stop. */
#define LOCAL_TOLERANCE 1e-6
/* A relaxation that still leaves a large residual grows by this many rings of nodes. */
#define RELAX_GROW_RINGS 2

/* ---- node ratios ---- */

static int corner_of(const fs_tetmesh *m, int32_t t, int32_t node)
{
    for (int c = 0; c < 4; c++)
        if (m->tet[4 * (size_t)t + c] == node)
            return c;
    return -1;
}

/* design: O'Brien & Hodgins §4.1-4.2 with the fracture/separation kernel: each element at the node
 * splits its stress into tensile and compressive parts and exerts the nodal forces of each
 * (f = -vol sigma g, the paper's Eq. 31 at first order), whose separation tensor's largest eigenvalue
 * v+ (a force) would be compared with the paper's toughness tau. Here it is divided by the node's
 * cross-section across the eigenvector n, A = 1/2 sum_e vol_e |g_e . n|: in a uniform uniaxial stress
 * s along n every element's force lies along n and v+ = s A exactly, so v+ / A is a stress, the ratio
 * v+ / (A threshold) is s / threshold there whatever the mesh, and [material] threshold keeps the
 * meaning it has in the other models (the paper's tau, a force per node, would make the pattern
 * depend on the element size). */
double fs_tet_node_ratio(const fs_tet *s, int32_t i, const double *c, int *kind, double normal[3])
{
    const fs_tet_list *l = &s->mesh.node_tets[i];
    double buf[2 * 3 * NODE_TETS_ON_STACK] = {0.0};
    double *fp = l->n <= NODE_TETS_ON_STACK ? buf : fs_malloc(6 * (size_t)l->n * sizeof *fp), *fm = fp + 3 * l->n;
    double fint[3] = {0.0, 0.0, 0.0};
    for (int32_t q = 0; q < l->n; q++) {
        int32_t t = l->v[q];
        int ci = corner_of(&s->mesh, t, i);
        const double *g = s->grad + 12 * (size_t)t + 3 * ci;
        double sigma[6], plus[6], minus[6];
        if (c) {
            fs_tet_stress_at(s, t, c, sigma);
            fs_separation_split_stress(sigma, plus, minus);
        } else {
            const double *ref = s->split_ref + 12 * (size_t)t;
            for (int k = 0; k < 6; k++) {
                plus[k] = ref[6 + k];
                minus[k] = ref[k] - ref[6 + k];
            }
        }
        double vol = s->vol[t], *p = fp + 3 * q, *m = fm + 3 * q;
        p[0] = -vol * (plus[0] * g[0] + plus[3] * g[1] + plus[5] * g[2]);
        p[1] = -vol * (plus[3] * g[0] + plus[1] * g[1] + plus[4] * g[2]);
        p[2] = -vol * (plus[5] * g[0] + plus[4] * g[1] + plus[2] * g[2]);
        m[0] = -vol * (minus[0] * g[0] + minus[3] * g[1] + minus[5] * g[2]);
        m[1] = -vol * (minus[3] * g[0] + minus[1] * g[1] + minus[4] * g[2]);
        m[2] = -vol * (minus[5] * g[0] + minus[4] * g[1] + minus[2] * g[2]);
        for (int k = 0; k < 3; k++)
            fint[k] += p[k] + m[k];
    }
    /* the largest eigenvalue whose plane cuts the node's elements (O'Brien & Hodgins: further planes
     * for further eigenvalues); a node on a crack wall pulled across the wall cannot split along it */
    double zeta[9], value[3], vec[9], ratio = 0.0;
    fs_separation_tensor(fp, l->n, fm, l->n, zeta);
    if (fp != buf)
        free(fp);
    if (fs_eigen_sym3(zeta, value, vec) < 0)
        value[0] = value[1] = value[2] = 0.0;
    *kind = 0;
    if (normal)
        normal[0] = normal[1] = normal[2] = 0.0;
    for (int e = 0; e < 3 && value[e] > 0.0; e++) {
        const double *n = vec + 3 * e;
        if (fs_tetcut_sides(&s->mesh, i, n, &s->snap) != 3)
            continue;
        double area = 0.0;
        for (int32_t q = 0; q < l->n; q++) {
            int32_t t = l->v[q];
            const double *g = s->grad + 12 * (size_t)t + 3 * corner_of(&s->mesh, t, i);
            area += 0.5 * s->vol[t] * fabs(fs_dot3(g, n));
        }
        if (area > 0.0)
            ratio = value[e] / (area * s->threshold[i]);
        if (normal)
            memcpy(normal, n, 3 * sizeof *normal);
        break;
    }
    if (s->bonded[i] && s->par.bond > 0.0 && s->area[i] > 0.0) {
        /* the pull of the layer off its substrate (peeling; the shear that holds the layer's
         * shrinkage is the bond's job and does not loosen it here) */
        double nn[3];
        fs_tet_normal(s, i, nn);
        double rb = fs_dot3(fint, nn) / (s->area[i] * 1e-3 * s->par.bond);
        if (rb > ratio) {
            ratio = rb;
            *kind = 1;
        }
    }
    return ratio;
}

/* ---- event searches ---- */

typedef struct {
    fs_tet *s;
    int32_t node;
} search_ctx;

static double search_ratio(void *ctx, double t)
{
    search_ctx *q = ctx;
    double c[FS_TET_LOADS];
    int kind;
    fs_tet_coefficients(q->s, t, c);
    q->s->counters.evaluations++;
    return fs_tet_node_ratio(q->s, q->node, c, &kind, NULL);
}

/* Proportional loads: the node's ratio is r_ref alpha(t), no evaluation of the node needed. */
static double scaled_ratio(void *ctx, double t)
{
    search_ctx *q = ctx;
    return q->s->r_ref[q->node] * fs_tet_alpha(q->s, t);
}

double fs_tet_ratio_now(const fs_tet *s, int32_t i, const double *c)
{
    int kind;
    return s->proportional ? s->r_ref[i] * fs_tet_alpha(s, s->time) : fs_tet_node_ratio(s, i, c, &kind, NULL);
}

int fs_tet_search_node(fs_tet *s, int32_t i, double t0)
{
    s->counters.searches++;
    s->t_cross[i] = INFINITY;
    if (s->mesh.node_tets[i].n == 0)
        return 0;
    search_ctx ctx = {s, i};
    fs_event_fn f = search_ratio;
    if (s->proportional) {
        int kind;
        s->r_ref[i] = fs_tet_node_ratio(s, i, NULL, &kind, NULL);
        s->counters.evaluations++;
        f = scaled_ratio;
        if (!(s->r_ref[i] > 0.0))
            return 0;
    }
    if (f(&ctx, t0) > 1.0) {
        s->t_cross[i] = t0;
        return 0;
    }
    if (!(t0 < s->end))
        return 0;
    double min_step = s->cfg.time.min_step;
    double dt = fmax(SEARCH_FIRST_STEP * (s->end - t0), min_step);
    fs_event_result r;
    if (fs_event_find(f, &ctx, t0, dt, s->end, min_step, &r) < 0)
        return -1;
    if (r.found)
        s->t_cross[i] = r.t;
    return 0;
}

/* ---- local relaxation ---- */

static void next_stamp(fs_tet *s)
{
    if (++s->stamp_now == INT32_MAX) {
        memset(s->stamp, 0, (size_t)s->cap_nodes * sizeof *s->stamp);
        s->stamp_now = 1;
    }
}

/* The tetrahedra of the listed nodes, each once, in the order the nodes list them, into *out
 * (growing); returns the count. */
static int32_t tets_of(fs_tet *s, const int32_t *nodes, int32_t n, int32_t **out, int32_t *cap)
{
    if (s->cap_tet_stamp < s->mesh.n_tets) {
        int32_t old = s->cap_tet_stamp;
        s->cap_tet_stamp = s->mesh.n_tets + s->mesh.n_tets / 2 + 64;
        s->tet_stamp = fs_realloc(s->tet_stamp, (size_t)s->cap_tet_stamp * sizeof *s->tet_stamp);
        memset(s->tet_stamp + old, 0, (size_t)(s->cap_tet_stamp - old) * sizeof *s->tet_stamp);
    }
    if (++s->tet_stamp_now == INT32_MAX) {
        memset(s->tet_stamp, 0, (size_t)s->cap_tet_stamp * sizeof *s->tet_stamp);
        s->tet_stamp_now = 1;
    }
    int32_t m = 0;
    for (int32_t q = 0; q < n; q++) {
        const fs_tet_list *l = &s->mesh.node_tets[nodes[q]];
        if (m + l->n > *cap) {
            *cap = 2 * (m + l->n) + 64;
            *out = fs_realloc(*out, (size_t)*cap * sizeof **out);
        }
        for (int32_t k = 0; k < l->n; k++) {
            int32_t t = l->v[k];
            if (s->tet_stamp[t] != s->tet_stamp_now) {
                s->tet_stamp[t] = s->tet_stamp_now;
                (*out)[m++] = t;
            }
        }
    }
    return m;
}

/* The forces of every load's current displacements in tetrahedron t: f[12 * k + ...]. */
static void element_forces(const fs_tet *s, int32_t t, double *f)
{
    for (int k = 0; k < s->n_loads; k++) {
        double sigma[6];
        fs_tet_load_stress(s, t, k, sigma);
        fs_tet_forces(s->grad + 12 * (size_t)t, s->vol[t], sigma, f + 12 * k);
    }
}

/* Whether the residual (element forces less the regularising spring) at the free nodes listed is
 * below the tolerance for every load. */
static bool residual_small(const fs_tet *s, const int32_t *nodes, int32_t n)
{
    int nl = s->n_loads;
    double tol = s->cfg.solver.relax_tolerance;
    double *r = fs_malloc(3 * (size_t)nl * sizeof *r), f[12 * FS_TET_LOADS];
    bool small = true;
    for (int32_t q = 0; q < n && small; q++) {
        int32_t i = nodes[q];
        if (s->bonded[i])
            continue;
        for (int k = 0; k < 3 * nl; k++)
            r[k] = -s->reg * s->u[3 * (size_t)nl * i + k];
        const fs_tet_list *l = &s->mesh.node_tets[i];
        for (int32_t e = 0; e < l->n; e++) {
            int32_t t = l->v[e];
            int ci = corner_of(&s->mesh, t, i);
            element_forces(s, t, f);
            for (int k = 0; k < nl; k++)
                for (int a = 0; a < 3; a++)
                    r[3 * k + a] += f[12 * k + 3 * ci + a];
        }
        for (int k = 0; k < nl && small; k++)
            small = sqrt(r[3 * k] * r[3 * k] + r[3 * k + 1] * r[3 * k + 1] + r[3 * k + 2] * r[3 * k + 2]) <=
                    tol * s->load[k].scale;
    }
    free(r);
    return small;
}

/* The 3 x 3 block of the stiffness of tetrahedron t coupling corner a (rows) and corner b (columns):
 * vol (lambda g_a g_b^T + mu g_b g_a^T + mu (g_a . g_b) I), as fs_tet_stiffness. */
static void stiffness_block(const fs_tet *s, int32_t t, int a, int b, double k[9])
{
    const double *ga = s->grad + 12 * (size_t)t + 3 * a, *gb = s->grad + 12 * (size_t)t + 3 * b;
    double vol = s->vol[t], lambda = s->lambda[t], mu = s->mu[t], dot = fs_dot3(ga, gb);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            k[3 * i + j] = vol * (lambda * ga[i] * gb[j] + mu * gb[i] * ga[j] + (i == j ? mu * dot : 0.0));
}

/* design: one local solve, u += K_RR^-1 r_R for every load, on the free nodes of the region with the
 * rest held. The matrix is assembled straight into compressed columns (solve/sparse.h's layout, the
 * unknowns node by node), node by node from the node's elements, without the general builder's sort:
 * a relaxation is all of an event's solving and is repeated thousands of times. The system is solved
 * by conjugate gradients with 3 x 3 block preconditioning (solve/cg.h): it is small, well conditioned
 * (its boundary is held), and a direct factor of a compact 3-D region fills in almost completely; a
 * region holding a piece that came off is solved by a direct factor instead. */
static int solve_region(fs_tet *s, const int32_t *region, int32_t nr, const int32_t *tets, int32_t nt)
{
    int nl = s->n_loads;
    if (s->cap_map < s->cap_nodes) {
        s->dof_map = fs_realloc(s->dof_map, (size_t)s->cap_nodes * sizeof *s->dof_map);
        for (int32_t i = s->cap_map; i < s->cap_nodes; i++)
            s->dof_map[i] = -1;
        s->cap_map = s->cap_nodes;
    }
    if (s->cap_slot < s->mesh.n_tets) {
        s->cap_slot = s->mesh.n_tets + s->mesh.n_tets / 2 + 64;
        s->tet_slot = fs_realloc(s->tet_slot, (size_t)s->cap_slot * sizeof *s->tet_slot);
    }
    int32_t *local = s->dof_map; /* per node: its number among the region's free nodes, or -1 */
    int32_t m = 0;
    int32_t *nodes = fs_malloc(((size_t)nr + 1) * sizeof *nodes);
    for (int32_t q = 0; q < nr; q++)
        if (!s->bonded[region[q]]) {
            local[region[q]] = m;
            nodes[m++] = region[q];
        }
    int rc = 0;
    if (m > 0) {
        double *ef = fs_malloc(((size_t)nt * 12 * nl + 1) * sizeof *ef);
        for (int32_t e = 0; e < nt; e++) {
            s->tet_slot[tets[e]] = e;
            element_forces(s, tets[e], ef + (size_t)12 * nl * e);
        }
        /* each node's neighbours numbered before it, ascending */
        int32_t *nb_start = fs_malloc(((size_t)m + 1) * sizeof *nb_start), nb_cap = 16 * m + 64, nb_n = 0;
        int32_t *nb = fs_malloc((size_t)nb_cap * sizeof *nb);
        int32_t *pos = fs_malloc((size_t)m * sizeof *pos);
        for (int32_t q = 0; q < m; q++)
            pos[q] = -1;
        for (int32_t ln = 0; ln < m; ln++) {
            nb_start[ln] = nb_n;
            const fs_tet_list *l = &s->mesh.node_tets[nodes[ln]];
            for (int32_t e = 0; e < l->n; e++)
                for (int c = 0; c < 4; c++) {
                    int32_t lj = local[s->mesh.tet[4 * (size_t)l->v[e] + c]];
                    if (lj < 0 || lj >= ln || pos[lj] >= 0)
                        continue;
                    pos[lj] = 0;
                    if (nb_n == nb_cap) {
                        nb_cap *= 2;
                        nb = fs_realloc(nb, (size_t)nb_cap * sizeof *nb);
                    }
                    nb[nb_n++] = lj;
                }
            fs_sort_int32(nb + nb_start[ln], nb_n - nb_start[ln]);
            for (int32_t k = nb_start[ln]; k < nb_n; k++)
                pos[nb[k]] = -1;
        }
        nb_start[m] = nb_n;
        int32_t n = 3 * m;
        fs_sparse_matrix K;
        K.n = n;
        K.col_ptr = fs_malloc(((size_t)n + 1) * sizeof *K.col_ptr);
        int32_t p = 0;
        for (int32_t ln = 0; ln < m; ln++)
            for (int a = 0; a < 3; a++) {
                K.col_ptr[3 * ln + a] = p;
                p += 3 * (nb_start[ln + 1] - nb_start[ln]) + a + 1;
            }
        K.col_ptr[n] = p;
        K.row_idx = fs_malloc(((size_t)p + 1) * sizeof *K.row_idx);
        K.values = fs_calloc((size_t)p + 1, sizeof *K.values);
        double *rhs = fs_calloc((size_t)nl * n, sizeof *rhs);
        for (int32_t ln = 0; ln < m; ln++) {
            int32_t i = nodes[ln], nbn = nb_start[ln + 1] - nb_start[ln];
            for (int32_t k = 0; k < nbn; k++)
                pos[nb[nb_start[ln] + k]] = k;
            for (int a = 0; a < 3; a++) {
                int32_t *rows = K.row_idx + K.col_ptr[3 * ln + a];
                for (int32_t k = 0; k < nbn; k++)
                    for (int b = 0; b < 3; b++)
                        rows[3 * k + b] = 3 * nb[nb_start[ln] + k] + b;
                for (int b = 0; b <= a; b++)
                    rows[3 * nbn + b] = 3 * ln + b;
            }
            const fs_tet_list *l = &s->mesh.node_tets[i];
            for (int32_t e = 0; e < l->n; e++) {
                int32_t t = l->v[e];
                int ci = corner_of(&s->mesh, t, i);
                for (int c = 0; c < 4; c++) {
                    int32_t lj = local[s->mesh.tet[4 * (size_t)t + c]];
                    if (lj < 0 || lj > ln)
                        continue;
                    double k9[9]; /* rows: node lj's components, columns: node ln's */
                    stiffness_block(s, t, c, ci, k9);
                    for (int a = 0; a < 3; a++) {
                        double *col = K.values + K.col_ptr[3 * ln + a];
                        if (lj < ln)
                            for (int b = 0; b < 3; b++)
                                col[3 * pos[lj] + b] += k9[3 * b + a];
                        else
                            for (int b = 0; b <= a; b++)
                                col[3 * nbn + b] += k9[3 * b + a];
                    }
                }
                const double *f = ef + (size_t)12 * nl * s->tet_slot[t];
                for (int k = 0; k < nl; k++)
                    for (int a = 0; a < 3; a++)
                        rhs[(size_t)k * n + 3 * ln + a] += f[12 * k + 3 * ci + a];
            }
            for (int a = 0; a < 3; a++) {
                K.values[K.col_ptr[3 * ln + a + 1] - 1] += s->reg;
                for (int k = 0; k < nl; k++)
                    rhs[(size_t)k * n + 3 * ln + a] -= s->reg * s->u[3 * ((size_t)nl * i + k) + a];
            }
            for (int32_t k = 0; k < nbn; k++)
                pos[nb[nb_start[ln] + k]] = -1;
        }
        double *x = fs_calloc((size_t)nl * n, sizeof *x);
        fs_cg_params cp = fs_cg_params_default();
        cp.block = 3;
        cp.tolerance = LOCAL_TOLERANCE;
        for (int k = 0; k < nl && rc == 0; k++)
            if (fs_cg_solve(&K, rhs + (size_t)k * n, x + (size_t)k * n, cp, NULL) < 0)
                rc = -1;
        if (rc < 0) {
            /* a piece that came off altogether is held only by the regularising springs: too badly
             * conditioned for the iteration, not for a direct factor */
            fs_cholesky *chol = fs_cholesky_analyze_small(&K);
            rc = !chol || fs_cholesky_factorize(chol, &K) < 0 || fs_cholesky_solve(chol, nl, rhs, x) < 0 ? -1 : 0;
            fs_cholesky_free(chol);
            s->counters.direct_solves++;
        }
        if (rc == 0)
            for (int32_t ln = 0; ln < m; ln++)
                for (int k = 0; k < nl; k++)
                    for (int a = 0; a < 3; a++)
                        s->u[3 * ((size_t)nl * nodes[ln] + k) + a] += x[(size_t)k * n + 3 * ln + a];
        fs_sparse_matrix_free(&K);
        free(x);
        free(rhs);
        free(pos);
        free(nb);
        free(nb_start);
        free(ef);
        s->counters.local_solves++;
        s->counters.local_unknowns += n;
    }
    for (int32_t q = 0; q < m; q++)
        local[nodes[q]] = -1;
    free(nodes);
    return rc;
}

/* design: thesis §5.8 (adaptive local relaxation) for this model: a fracture changes the layer only
 * near the cut, and a layer bonded to its substrate answers a local change within a few thicknesses
 * (shear lag), so the displacements are solved again only for the nodes within relax_radius mean edge
 * lengths of the changed ones (their neighbours held), by CHOLMOD on that small system. The residual
 * of the nodes just outside the region (every load's element forces at them, which were in
 * equilibrium before) must then be below relax_tolerance times a typical element force of that
 * load, else the region grows by two rings and the solve is repeated. Every element the solve moved
 * gets its stresses again, and every node of those elements a new event search from now. */
/* The connections of node i for the region search: to every other corner of its elements, one hop. */
static void node_links(void *ctx, int32_t i, fs_region *r)
{
    const fs_tet *s = ctx;
    const fs_tet_list *l = &s->mesh.node_tets[i];
    for (int32_t q = 0; q < l->n; q++)
        for (int c = 0; c < 4; c++) {
            int32_t j = s->mesh.tet[4 * (size_t)l->v[q] + c];
            if (j != i)
                fs_region_reach(r, j, 1.0);
        }
}

int fs_tet_relax_local(fs_tet *s, const int32_t *nodes, int32_t n)
{
    double t0 = fs_seconds();
    if (s->cap_region < s->mesh.n_nodes) {
        int32_t old = s->cap_region;
        s->cap_region = s->cap_nodes;
        FS_ARRAY_RESIZE(s->region, s->cap_region);
        FS_ARRAY_RESIZE(s->dist, s->cap_region);
        for (int32_t i = old; i < s->cap_region; i++)
            s->dist[i] = INFINITY;
    }
    int32_t *region = s->region, *tets = NULL, tcap = 0, nt = 0, moved = 0;
    double radius = ceil(s->cfg.solver.relax_radius);
    int rc = 0;
    for (;;) {
        /* the nodes within radius hops of the changed ones, then those one hop further out */
        int32_t all = fs_region_grow(nodes, n, radius + 1.0, FS_REGION_TIES_BY_ARRIVAL, node_links, s, s->dist, region);
        int32_t nr = 0;
        while (nr < all && s->dist[region[nr]] <= radius)
            nr++;
        nt = tets_of(s, region, nr, &tets, &tcap);
        rc = solve_region(s, region, nr, tets, nt);
        bool done = rc < 0 || nr == all || residual_small(s, region + nr, all - nr);
        fs_region_forget(s->dist, region, all);
        moved = nr;
        if (done)
            break;
        radius += RELAX_GROW_RINGS;
    }
    /* the elements of the moved nodes get their stresses again; the nodes of those whose stresses
     * changed by more than SEARCH_AGAIN of a typical stress, and the given ones, are searched again */
    int nl = s->n_loads;
    int32_t nn = 0, ncap = n + 256;
    int32_t *touched = fs_malloc((size_t)ncap * sizeof *touched);
    next_stamp(s);
    for (int32_t q = 0; q < n; q++)
        if (s->stamp[nodes[q]] != s->stamp_now) {
            s->stamp[nodes[q]] = s->stamp_now;
            touched[nn++] = nodes[q];
        }
    if (rc == 0) {
        nt = tets_of(s, region, moved, &tets, &tcap);
        double old[6 * FS_TET_LOADS];
        for (int32_t e = 0; e < nt; e++) {
            int32_t t = tets[e];
            double *st = s->stress + 6 * (size_t)nl * t;
            memcpy(old, st, 6 * (size_t)nl * sizeof *old);
            fs_tet_update_stress(s, t);
            bool changed = false;
            for (int k = 0; k < nl && !changed; k++) {
                double tol = SEARCH_AGAIN * s->load[k].scale / (s->mean_edge * s->mean_edge);
                for (int q = 0; q < 6 && !changed; q++)
                    changed = fabs(st[6 * k + q] - old[6 * k + q]) > tol;
            }
            if (!changed)
                continue;
            for (int c = 0; c < 4; c++) {
                int32_t v = s->mesh.tet[4 * (size_t)t + c];
                if (s->stamp[v] == s->stamp_now)
                    continue;
                s->stamp[v] = s->stamp_now;
                if (nn == ncap) {
                    ncap = 2 * ncap;
                    touched = fs_realloc(touched, (size_t)ncap * sizeof *touched);
                }
                touched[nn++] = v;
            }
        }
    }
    s->counters.local_seconds += fs_seconds() - t0;
    double t1 = fs_seconds();
    if (rc == 0) {
        fs_sort_int32(touched, nn);
        for (int32_t q = 0; q < nn && rc == 0; q++)
            rc = fs_tet_search_node(s, touched[q], s->time);
    }
    free(touched);
    s->counters.search_seconds += fs_seconds() - t1;
    free(tets);
    return rc;
}

/* ---- events ---- */

/* Node i's share of the bonded bottom: a third of each face of its elements whose corners are all
 * bonded and on the substrate. */
static double bond_area(const fs_tet *s, int32_t i)
{
    if (!s->bonded[i])
        return 0.0;
    double a = 0.0;
    const fs_tet_list *l = &s->mesh.node_tets[i];
    for (int32_t q = 0; q < l->n; q++) {
        int32_t t = l->v[q];
        const int32_t *v = s->mesh.tet + 4 * (size_t)t;
        for (int f = 0; f < 4; f++) {
            const int *fc = fs_tet_face[f];
            if (v[fc[0]] != i && v[fc[1]] != i && v[fc[2]] != i)
                continue;
            bool bottom = true;
            for (int k = 0; k < 3; k++)
                bottom = bottom && s->bonded[v[fc[k]]] && s->mesh.zeta[v[fc[k]]] == 0.0;
            if (!bottom)
                continue;
            double x[12], e1[3], e2[3], n[3];
            fs_tetmesh_corners(&s->mesh, t, x);
            fs_sub3(e1, x + 3 * fc[1], x + 3 * fc[0]);
            fs_sub3(e2, x + 3 * fc[2], x + 3 * fc[0]);
            fs_cross3(n, e1, e2);
            a += fs_norm3(n) / 6.0;
        }
    }
    return a;
}

/* The nodes of the listed tetrahedra and of the new ones from `first` on, sorted, unique. */
static int32_t nodes_of_tets(const fs_tet *s, const int32_t *tets, int32_t n, int32_t first, int32_t **out)
{
    int32_t total = 4 * (n + s->mesh.n_tets - first);
    int32_t *v = fs_malloc(((size_t)total + 1) * sizeof *v), m = 0;
    for (int32_t q = 0; q < n; q++)
        for (int c = 0; c < 4; c++)
            v[m++] = s->mesh.tet[4 * (size_t)tets[q] + c];
    for (int32_t t = first; t < s->mesh.n_tets; t++)
        for (int c = 0; c < 4; c++)
            v[m++] = s->mesh.tet[4 * (size_t)t + c];
    *out = v;
    return fs_sort_unique_int32(v, m);
}

int fs_tet_split(fs_tet *s, int32_t i, const double normal[3])
{
    double t0 = fs_seconds();
    fs_tetcut_result *r = &s->cut;
    int rc = fs_tetcut_node(&s->mesh, i, normal, &s->snap, r);
    if (rc <= 0)
        return rc;
    fs_tet_grow(s);
    int nl = s->n_loads;
    for (int32_t j = r->n_nodes_before; j < s->mesh.n_nodes; j++) {
        int32_t k = j - r->n_nodes_before, a = r->from[2 * k], b = r->from[2 * k + 1];
        double w = r->weight[k];
        for (int q = 0; q < 3 * nl; q++) {
            double ua = s->u[3 * (size_t)nl * a + q], ub = s->u[3 * (size_t)nl * b + q];
            s->u[3 * (size_t)nl * j + q] = a == b ? ua : ua + w * (ub - ua);
        }
        s->threshold[j] = a == b ? s->threshold[a] : s->threshold[a] + w * (s->threshold[b] - s->threshold[a]);
        s->bonded[j] = s->bonded[a] && s->bonded[b];
        s->t_cross[j] = INFINITY;
    }
    fs_tet_number_dofs(s);
    int32_t *nodes = NULL;
    int32_t nn = nodes_of_tets(s, r->changed.v, r->changed.n, r->n_tets_before, &nodes);
    for (int32_t q = 0; q < r->changed.n && rc >= 0; q++)
        if (fs_tet_update_geometry(s, r->changed.v[q]) < 0)
            rc = -1;
    for (int32_t t = r->n_tets_before; t < s->mesh.n_tets && rc >= 0; t++) {
        int32_t parent = r->parent[t - r->n_tets_before];
        s->lambda[t] = s->lambda[parent];
        s->mu[t] = s->mu[parent];
        if (fs_tet_update_geometry(s, t) < 0)
            rc = -1;
    }
    if (rc >= 0) {
        for (int32_t q = 0; q < r->changed.n; q++)
            for (int k = 0; k < nl; k++)
                fs_tet_load_eigenstrain(s, k, r->changed.v[q], s->eps0 + 6 * ((size_t)nl * r->changed.v[q] + k));
        for (int32_t t = r->n_tets_before; t < s->mesh.n_tets; t++)
            for (int k = 0; k < nl; k++)
                fs_tet_load_eigenstrain(s, k, t, s->eps0 + 6 * ((size_t)nl * t + k));
        for (int32_t q = 0; q < nn; q++)
            s->area[nodes[q]] = bond_area(s, nodes[q]);
    }
    s->counters.cut_seconds += fs_seconds() - t0;
    if (rc >= 0 && fs_tet_relax_local(s, nodes, nn) < 0)
        rc = -1;
    free(nodes);
    if (rc >= 0)
        s->counters.splits++;
    return rc < 0 ? -1 : 1;
}

int fs_tet_debond(fs_tet *s, int32_t i)
{
    s->bonded[i] = 0;
    fs_tet_number_dofs(s);
    /* the node and its neighbours: their bonded areas change */
    int32_t *nodes = fs_malloc((size_t)s->mesh.n_nodes * sizeof *nodes);
    double *dist = fs_malloc((size_t)s->mesh.n_nodes * sizeof *dist);
    for (int32_t q = 0; q < s->mesh.n_nodes; q++)
        dist[q] = INFINITY;
    int32_t n = fs_region_grow(&i, 1, 1.0, FS_REGION_TIES_BY_ARRIVAL, node_links, s, dist, nodes);
    free(dist);
    for (int32_t q = 0; q < n; q++)
        s->area[nodes[q]] = bond_area(s, nodes[q]);
    int rc = fs_tet_relax_local(s, nodes, n);
    free(nodes);
    if (rc == 0)
        s->counters.debonds++;
    return rc;
}

/* design: the events in time. Every node keeps the time of its next fracture (t_cross, from the
 * shared event search fracture/event.h over its own ratio, the loads being known functions of time);
 * a change re-searches only the nodes whose elements it moved (fs_tet_relax_local). The next event is
 * at the smallest t_cross; of the nodes over their threshold then, the one with the largest ratio
 * breaks (fracture/rank.h, ties by seed): its node splits along the separation tensor's plane, or its
 * bond comes loose. The nodes of the new crack front are usually over their threshold at once, so
 * cracks run from their tips at the same time until they stop (O'Brien & Hodgins: "crack tips
 * continue from split nodes"). */
int fs_tet_advance(fs_tet *s, double t)
{
    int32_t cap = 0;
    double *ratio = NULL;
    uint64_t *id = NULL;
    int32_t *cand = NULL;
    int rc = 0;
    for (;;) {
        if (s->par.max_events > 0 && s->events >= s->par.max_events)
            break;
        double tn = INFINITY;
        for (int32_t i = 0; i < s->mesh.n_nodes; i++)
            tn = fmin(tn, s->t_cross[i]);
        if (!(tn <= t))
            break;
        if (tn > s->time)
            s->time = tn;
        double c[FS_TET_LOADS];
        fs_tet_coefficients(s, s->time, c);
        int32_t n = 0;
        for (int32_t i = 0; i < s->mesh.n_nodes; i++) {
            if (!(s->t_cross[i] <= s->time))
                continue;
            if (n == cap) {
                cap = 2 * cap + 16;
                ratio = fs_realloc(ratio, (size_t)cap * sizeof *ratio);
                id = fs_realloc(id, (size_t)cap * sizeof *id);
                cand = fs_realloc(cand, (size_t)cap * sizeof *cand);
            }
            ratio[n] = fs_tet_ratio_now(s, i, c);
            id[n] = (uint64_t)i;
            cand[n++] = i;
        }
        int32_t pick = fs_rank_pick(ratio, id, n, s->cfg.seed);
        if (pick < 0 || !(ratio[pick] > 1.0)) {
            /* the searches' brackets ended past a dip below the threshold: search those nodes again */
            for (int32_t q = 0; q < n && rc == 0; q++)
                rc = fs_tet_search_node(s, cand[q], s->time);
            if (rc < 0)
                break;
            continue;
        }
        int32_t i = cand[pick], kind;
        double normal[3] = {0.0, 0.0, 0.0};
        double fresh = fs_tet_node_ratio(s, i, s->proportional ? NULL : c, &kind, normal);
        if (s->proportional)
            fresh *= fs_tet_alpha(s, s->time);
        if (!(fresh > 1.0)) {
            /* its elements moved a little since its search (below SEARCH_AGAIN): search it again */
            if ((rc = fs_tet_search_node(s, i, s->time)) < 0)
                break;
            continue;
        }
        s->events++;
        if (kind == 1) {
            rc = fs_tet_debond(s, i);
        } else {
            int split = fs_tet_split(s, i, normal);
            rc = split < 0 ? -1 : 0;
            if (split == 0) {
                s->counters.failed_splits++;
                s->t_cross[i] = INFINITY; /* until its elements change */
            }
        }
        if (rc < 0)
            break;
        if (s->events % 64 == 0)
            fs_progress("tet", s->end > 0.0 ? s->time / s->end : -1.0, "%lld fractures, %d tetrahedra",
                        (long long)(s->counters.splits + s->counters.debonds), (int)s->mesh.n_tets);
    }
    free(ratio);
    free(id);
    free(cand);
    if (rc == 0 && s->time < t)
        s->time = t;
    return rc;
}
