/* Networks of point masses and springs relaxed to equilibrium: global inexact Newton on CHOLMOD, local conjugate gradients. */
#include "model/springs/internal.h"

#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/vec.h"
#include "geom/region.h"
#include "solve/cg.h"

/* ==== the generic network ==== */

void fs_spring_net_init(fs_spring_net *net, int dim, int32_t n_nodes, int32_t n_springs, int32_t n_anchors)
{
    FS_ASSERT(dim == 2 || dim == 3);
    FS_ASSERT(n_nodes >= 0 && n_springs >= 0 && n_anchors >= 0);
    memset(net, 0, sizeof *net);
    net->dim = dim;
    net->n_nodes = n_nodes;
    net->n_springs = n_springs;
    net->n_anchors = n_anchors;
    size_t nn = (size_t)n_nodes + 1, ns = (size_t)n_springs + 1, na = (size_t)n_anchors + 1;
    net->x = fs_calloc(nn * (size_t)dim, sizeof *net->x);
    net->fixed = fs_calloc(nn, 1);
    net->node = fs_calloc(2 * ns, sizeof *net->node);
    net->offset = fs_calloc(ns * (size_t)dim, sizeof *net->offset);
    net->rest = fs_calloc(ns, sizeof *net->rest);
    net->k = fs_calloc(ns, sizeof *net->k);
    net->anchor_node = fs_calloc(na, sizeof *net->anchor_node);
    net->anchor_at = fs_calloc(na * (size_t)dim, sizeof *net->anchor_at);
    net->anchor_k = fs_calloc(na, sizeof *net->anchor_k);
}

void fs_spring_net_free(fs_spring_net *net)
{
    free(net->x);
    free(net->fixed);
    free(net->node);
    free(net->offset);
    free(net->rest);
    free(net->k);
    free(net->anchor_node);
    free(net->anchor_at);
    free(net->anchor_k);
    free(net->dof);
    fs_sparse_matrix_free(&net->K);
    free(net->node_slot);
    free(net->spring_slot);
    free(net->slots);
    fs_cholesky_free(net->chol);
    free(net->fact_x);
    free(net->fact_rest);
    free(net->fact_k);
    free(net->fact_offset);
    free(net->work);
    free(net->adj_start);
    free(net->adj_spring);
    free(net->anc_start);
    free(net->anc_list);
    free(net->local_map);
    free(net->local_dist);
    free(net->seeds);
    memset(net, 0, sizeof *net);
}

int fs_spring_net_prepare(fs_spring_net *net)
{
    int dim = net->dim;
    int32_t n = net->n_nodes;
    free(net->dof);
    net->dof = fs_malloc(((size_t)n + 1) * sizeof *net->dof);
    int32_t nd = 0;
    for (int32_t i = 0; i < n; i++) {
        net->dof[i] = net->fixed[i] ? -1 : nd;
        nd += net->fixed[i] ? 0 : dim;
    }
    net->n_dof = nd;

    /* entries: each free node's diagonal block (upper triangle), each free-free spring's full
     * off-diagonal block */
    int per_node = dim * (dim + 1) / 2, per_spring = dim * dim;
    size_t count = 0;
    for (int32_t s = 0; s < net->n_springs; s++) {
        int32_t a = net->node[2 * s], b = net->node[2 * s + 1];
        FS_ASSERT(a != b && a >= 0 && b >= 0 && a < n && b < n);
        if (net->dof[a] >= 0 && net->dof[b] >= 0)
            count += (size_t)per_spring;
    }
    count += (size_t)per_node * (size_t)(nd / dim);
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, nd, count);
    free(net->node_slot);
    free(net->spring_slot);
    net->node_slot = fs_malloc(((size_t)n + 1) * sizeof *net->node_slot);
    net->spring_slot = fs_malloc(((size_t)net->n_springs + 1) * sizeof *net->spring_slot);
    for (int32_t i = 0; i < n; i++) {
        int32_t d = net->dof[i];
        net->node_slot[i] = -1;
        if (d < 0)
            continue;
        net->node_slot[i] = (int32_t)b.count;
        for (int p = 0; p < dim; p++)
            for (int q = p; q < dim; q++)
                fs_sparse_builder_add(&b, d + p, d + q, 0.0);
    }
    for (int32_t s = 0; s < net->n_springs; s++) {
        int32_t da = net->dof[net->node[2 * s]], db = net->dof[net->node[2 * s + 1]];
        net->spring_slot[s] = -1;
        if (da < 0 || db < 0)
            continue;
        net->spring_slot[s] = (int32_t)b.count;
        for (int p = 0; p < dim; p++)
            for (int q = 0; q < dim; q++)
                fs_sparse_builder_add(&b, da + p, db + q, 0.0);
    }
    free(net->slots);
    net->slots = fs_malloc((b.count + 1) * sizeof *net->slots);
    fs_sparse_matrix_free(&net->K);
    int rc = fs_sparse_builder_compress(&b, &net->K, net->slots);
    fs_sparse_builder_free(&b);
    if (rc < 0)
        return -1;

    fs_cholesky_free(net->chol);
    net->chol = NULL;
    net->factor_valid = false;
    if (nd > 0) {
        net->chol = fs_cholesky_analyze(&net->K);
        if (!net->chol)
            return -1;
        fs_cholesky_info ci = fs_cholesky_get_info(net->chol);
        /* a solve reads the factor twice: about 4 flops per entry */
        net->factor_cost = ci.factor_nonzeros > 0.0 ? ci.flops / (4.0 * ci.factor_nonzeros) : 1.0;
    }
    size_t nx = (size_t)n * (size_t)dim + 1;
    free(net->fact_x);
    free(net->fact_rest);
    free(net->fact_k);
    free(net->fact_offset);
    free(net->work);
    net->fact_x = fs_calloc(nx, sizeof *net->fact_x);
    net->fact_rest = fs_calloc((size_t)net->n_springs + 1, sizeof *net->fact_rest);
    net->fact_k = fs_calloc((size_t)net->n_springs + 1, sizeof *net->fact_k);
    net->fact_offset = fs_calloc(((size_t)net->n_springs + 1) * (size_t)dim, sizeof *net->fact_offset);
    net->work = fs_calloc(7 * ((size_t)nd + 1) + nx, sizeof *net->work);

    /* adjacency for the local relaxation */
    free(net->adj_start);
    free(net->adj_spring);
    free(net->anc_start);
    free(net->anc_list);
    free(net->local_map);
    net->adj_start = fs_calloc((size_t)n + 2, sizeof *net->adj_start);
    net->adj_spring = fs_malloc(2 * ((size_t)net->n_springs + 1) * sizeof *net->adj_spring);
    net->anc_start = fs_calloc((size_t)n + 2, sizeof *net->anc_start);
    net->anc_list = fs_malloc(((size_t)net->n_anchors + 1) * sizeof *net->anc_list);
    net->local_map = fs_malloc(((size_t)n + 1) * sizeof *net->local_map);
    free(net->local_dist);
    net->local_dist = fs_malloc(((size_t)n + 1) * sizeof *net->local_dist);
    free(net->seeds);
    net->seeds = fs_malloc(((size_t)n + 1) * sizeof *net->seeds);
    for (int32_t i = 0; i < n; i++) {
        net->local_map[i] = -1;
        net->local_dist[i] = INFINITY;
    }
    for (int32_t s = 0; s < net->n_springs; s++) {
        net->adj_start[net->node[2 * s] + 1]++;
        net->adj_start[net->node[2 * s + 1] + 1]++;
    }
    for (int32_t a = 0; a < net->n_anchors; a++)
        net->anc_start[net->anchor_node[a] + 1]++;
    for (int32_t i = 0; i < n; i++) {
        net->adj_start[i + 1] += net->adj_start[i];
        net->anc_start[i + 1] += net->anc_start[i];
    }
    int32_t *fill = fs_malloc(((size_t)n + 1) * sizeof *fill);
    memcpy(fill, net->adj_start, (size_t)n * sizeof *fill);
    for (int32_t s = 0; s < net->n_springs; s++) {
        net->adj_spring[fill[net->node[2 * s]]++] = s;
        net->adj_spring[fill[net->node[2 * s + 1]]++] = s;
    }
    memcpy(fill, net->anc_start, (size_t)n * sizeof *fill);
    for (int32_t a = 0; a < net->n_anchors; a++)
        net->anc_list[fill[net->anchor_node[a]]++] = a;
    free(fill);
    return 0;
}

/* d = x_b + offset - x_a for spring s over positions x and offsets off; returns |d|. */
static double spring_vector(const fs_spring_net *net, int32_t s, const double *x, const double *off, double *d)
{
    int dim = net->dim;
    const double *xa = x + (size_t)dim * (size_t)net->node[2 * s];
    const double *xb = x + (size_t)dim * (size_t)net->node[2 * s + 1];
    const double *o = off + (size_t)dim * (size_t)s;
    double l2 = 0.0;
    for (int q = 0; q < dim; q++) {
        d[q] = xb[q] + o[q] - xa[q];
        l2 += d[q] * d[q];
    }
    return sqrt(l2);
}

/* The spring's tangent block H (dim x dim, row-major) for vector d of length l: k (n n^T + c (I - n n^T))
 * with c = max(0, 1 - L / l); k I for a zero-rest-length or collapsed spring. */
static void spring_block(int dim, double k, double rest, const double *d, double l, double *H)
{
    double c = 1.0, nv[3] = {0.0, 0.0, 0.0};
    if (rest > 0.0 && l > 1e-300) {
        c = 1.0 - rest / l;
        if (c < 0.0)
            c = 0.0;
        for (int q = 0; q < dim; q++)
            nv[q] = d[q] / l;
    }
    for (int p = 0; p < dim; p++)
        for (int q = 0; q < dim; q++)
            H[p * dim + q] = k * ((1.0 - c) * nv[p] * nv[q] + (p == q ? c : 0.0));
}

/* Anchor a (its stiffness k not 0) at positions x: d = its node's position minus its point, *r2 = |d|^2;
 * returns the factor g of its force -g d on the node: k, or k slide / |d| beyond the slide length
 * (where the anchor pulls with a constant force). */
static double anchor_pull(const fs_spring_net *net, int32_t a, const double *x, double d[3], double *r2)
{
    int dim = net->dim;
    double k = net->anchor_k[a];
    const double *xi = x + (size_t)dim * (size_t)net->anchor_node[a], *at = net->anchor_at + (size_t)dim * (size_t)a;
    double s = 0.0;
    for (int q = 0; q < dim; q++) {
        d[q] = xi[q] - at[q];
        s += d[q] * d[q];
    }
    *r2 = s;
    double r = sqrt(s);
    return net->slide > 0.0 && r > net->slide ? k * net->slide / r : k;
}

/* Energy and, when f is not NULL, the forces on the free unknowns, at positions x. Returns the
 * energy; *fmax (if not NULL) receives the largest node force norm. */
static double net_eval(const fs_spring_net *net, const double *x, double *f, double *fmax)
{
    int dim = net->dim;
    double energy = 0.0;
    if (f)
        memset(f, 0, (size_t)net->n_dof * sizeof *f);
    for (int32_t s = 0; s < net->n_springs; s++) {
        double k = net->k[s];
        if (k == 0.0)
            continue;
        double d[3];
        double l = spring_vector(net, s, x, net->offset, d), rest = net->rest[s];
        double stretch = l - rest;
        energy += 0.5 * k * stretch * stretch;
        if (!f)
            continue;
        /* force on b: -k (l - L) n = -k (1 - L / l) d; zero-rest-length: -k d */
        double g = rest > 0.0 ? (l > 1e-300 ? k * stretch / l : 0.0) : k;
        int32_t da = net->dof[net->node[2 * s]], db = net->dof[net->node[2 * s + 1]];
        for (int q = 0; q < dim; q++) {
            if (da >= 0)
                f[da + q] += g * d[q];
            if (db >= 0)
                f[db + q] -= g * d[q];
        }
    }
    double slide = net->slide;
    for (int32_t a = 0; a < net->n_anchors; a++) {
        double k = net->anchor_k[a];
        if (k == 0.0)
            continue;
        int32_t i = net->anchor_node[a];
        double d[3], r2, g = anchor_pull(net, a, x, d, &r2), r = sqrt(r2);
        if (slide > 0.0 && r > slide)
            energy += k * slide * (r - slide) + 0.5 * k * slide * slide;
        else
            energy += 0.5 * k * r2;
        int32_t di = net->dof[i];
        if (f && di >= 0)
            for (int q = 0; q < dim; q++)
                f[di + q] -= g * d[q];
    }
    if (fmax) {
        double worst = 0.0;
        if (f)
            for (int32_t i = 0; i < net->n_nodes; i++) {
                int32_t di = net->dof[i];
                if (di < 0)
                    continue;
                double s2 = 0.0;
                for (int q = 0; q < dim; q++)
                    s2 += f[di + q] * f[di + q];
                if (s2 > worst)
                    worst = s2;
            }
        *fmax = sqrt(worst);
    }
    return energy;
}

double fs_spring_net_energy(const fs_spring_net *net) { return net_eval(net, net->x, NULL, NULL); }

double fs_spring_net_force(const fs_spring_net *net, double *f)
{
    double *buf = f ? f : fs_malloc(((size_t)net->n_dof + 1) * sizeof *buf);
    double fmax = 0.0;
    net_eval(net, net->x, buf, &fmax);
    if (!f)
        free(buf);
    return fmax;
}

/* Adds the dim x dim block H (sign +1 or -1) to node i's diagonal block. */
static void add_diag(fs_spring_net *net, int32_t i, const double *H, double sign)
{
    int dim = net->dim;
    int32_t e = net->node_slot[i];
    if (e < 0)
        return;
    for (int p = 0; p < dim; p++)
        for (int q = p; q < dim; q++)
            net->K.values[net->slots[e++]] += sign * H[p * dim + q];
}

/* Assembles the tangent at the current positions (values only; the pattern is fixed). A relative
 * 1e-12 of the mean diagonal keeps nodes that lost every spring regular. */
static void net_assemble(fs_spring_net *net)
{
    int dim = net->dim;
    fs_sparse_matrix_zero(&net->K);
    double H[9];
    for (int32_t s = 0; s < net->n_springs; s++) {
        double k = net->k[s];
        if (k == 0.0)
            continue;
        int32_t a = net->node[2 * s], b = net->node[2 * s + 1];
        if (net->dof[a] < 0 && net->dof[b] < 0)
            continue;
        double d[3];
        double l = spring_vector(net, s, net->x, net->offset, d);
        spring_block(dim, k, net->rest[s], d, l, H);
        add_diag(net, a, H, 1.0);
        add_diag(net, b, H, 1.0);
        int32_t e = net->spring_slot[s];
        if (e >= 0)
            for (int p = 0; p < dim * dim; p++)
                net->K.values[net->slots[e + p]] -= H[p];
    }
    double slide = net->slide;
    for (int32_t a = 0; a < net->n_anchors; a++) {
        double k = net->anchor_k[a];
        int32_t i = net->anchor_node[a];
        if (k == 0.0 || net->dof[i] < 0)
            continue;
        if (slide > 0.0) {
            const double *xi = net->x + (size_t)dim * (size_t)i, *at = net->anchor_at + (size_t)dim * (size_t)a;
            double r2 = 0.0;
            for (int q = 0; q < dim; q++)
                r2 += (xi[q] - at[q]) * (xi[q] - at[q]);
            double r = sqrt(r2);
            if (r > slide)
                k *= slide / r;
        }
        for (int p = 0; p < dim * dim; p++)
            H[p] = (p % (dim + 1) == 0) ? k : 0.0;
        add_diag(net, i, H, 1.0);
    }
    /* regularisation */
    double sum = 0.0;
    int32_t cnt = 0;
    for (int32_t j = 0; j < net->K.n; j++) {
        sum += fabs(net->K.values[net->K.col_ptr[j + 1] - 1]);
        cnt++;
    }
    double eps = cnt ? 1e-12 * sum / cnt : 0.0;
    if (eps == 0.0)
        eps = 1e-300;
    for (int32_t j = 0; j < net->K.n; j++)
        net->K.values[net->K.col_ptr[j + 1] - 1] += eps;
#ifdef FS_VALIDATE
    char why[256];
    FS_INVARIANT(fs_sparse_matrix_check(&net->K, why, sizeof why), "springs network, after assembling the tangent: %s",
                 why);
#endif
}

/* Assembles and factorizes at the current state, remembering it for downdates. */
static int net_refactor(fs_spring_net *net)
{
    net_assemble(net);
    net->factor_valid = false;
    net->factorizations++;
    net->stale_solves = 0;
    if (fs_cholesky_factorize(net->chol, &net->K) < 0)
        return -1;
    int dim = net->dim;
    memcpy(net->fact_x, net->x, (size_t)net->n_nodes * (size_t)dim * sizeof *net->x);
    memcpy(net->fact_rest, net->rest, (size_t)net->n_springs * sizeof *net->rest);
    memcpy(net->fact_k, net->k, (size_t)net->n_springs * sizeof *net->k);
    memcpy(net->fact_offset, net->offset, (size_t)net->n_springs * (size_t)dim * sizeof *net->offset);
    net->factor_valid = true;
    return 0;
}

/* p = M^-1 f with the current factor. */
static int net_solve(fs_spring_net *net, const double *f, double *p)
{
    net->solves++;
    return fs_cholesky_solve(net->chol, 1, f, p);
}

/* x_out = x + alpha p on the free unknowns (fixed nodes copied). */
static void net_step(const fs_spring_net *net, const double *x, const double *p, double alpha, double *x_out)
{
    int dim = net->dim;
    for (int32_t i = 0; i < net->n_nodes; i++) {
        int32_t di = net->dof[i];
        const double *xi = x + (size_t)dim * (size_t)i;
        double *yo = x_out + (size_t)dim * (size_t)i;
        for (int q = 0; q < dim; q++)
            yo[q] = di >= 0 ? xi[q] + alpha * p[di + q] : xi[q];
    }
}

/* The tangent K and the factor M of an earlier one as fs_pcg's operator (solve/cg.h). */
typedef struct {
    fs_spring_net *net;
    double target; /* of the Euclidean norm of the residual */
} net_pcg_ctx;

static void net_pcg_apply(void *ctx, const double *x, double *y)
{
    fs_sparse_matvec(&((net_pcg_ctx *)ctx)->net->K, x, y);
}

static int net_pcg_precondition(void *ctx, const double *r, double *z) { return net_solve(((net_pcg_ctx *)ctx)->net, r, z); }

static bool net_pcg_converged(void *ctx, const double *r)
{
    const net_pcg_ctx *c = ctx;
    return sqrt(fs_cg_dot(c->net->n_dof, r, r, FS_CG_SUM_SEQUENTIAL)) <= c->target;
}

/* Solves K p = f (K assembled at the current state) by conjugate gradients preconditioned with the
 * factor M (fs_pcg from p = 0, sequential sums), until ||K p - f|| <= target or max_it iterations.
 * Returns the iterations used, max_it + 1 if not converged (or a direction of no curvature after the
 * first), -1 on a solver failure. r, z, d, q are n_dof scratch vectors. */
static int net_pcg(fs_spring_net *net, const double *f, double *p, double target, int max_it, double *r, double *z,
                   double *d, double *q)
{
    net_pcg_ctx c = {net, target};
    fs_cg_operator k = {net->n_dof, net_pcg_apply, net_pcg_precondition, net_pcg_converged, &c};
    fs_pcg_params params = {max_it, FS_CG_SUM_SEQUENTIAL, true, false};
    fs_pcg_result res = fs_pcg(&k, f, p, &params, (fs_pcg_vectors){r, z, d, q});
    switch (res.status) {
    case FS_PCG_CONVERGED:
        return res.iterations;
    case FS_PCG_BREAKDOWN:
        return res.iterations == 0 ? -1 : max_it + 1;
    case FS_PCG_MAX_ITERATIONS:
        return max_it + 1;
    default:
        return -1;
    }
}

/* design: inexact Newton. Each step assembles the tangent K at the current positions and solves
 * K p = f by conjugate gradients preconditioned with the Cholesky factor M of an earlier tangent
 * (exact in topology through the downdates of fs_spring_net_cut): a few iterations while M is close,
 * one after a refactorization. The factor is renewed after a step whose solve took more than PCG_MAX
 * iterations or had to be damped. The linear solve reduces the residual by two decades or to 0.3
 * tolerance; an Armijo line search on the energy keeps the steps descending. */
#define PCG_MAX 8

int fs_spring_net_relax(fs_spring_net *net, double tolerance, int max_iterations, fs_spring_relax_info *info)
{
    fs_spring_relax_info local;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    info->energy_monotone = true;
    int32_t nd = net->n_dof;
    size_t nx = (size_t)net->n_nodes * (size_t)net->dim, stride = (size_t)nd + 1;
    double *f = net->work, *p = f + stride, *f_trial = p + stride, *r = f_trial + stride, *z = r + stride,
           *d = z + stride, *q = d + stride, *x_trial = q + stride;
    double fmax = 0.0;
    double energy = net_eval(net, net->x, f, &fmax);
    info->energy_start = info->energy_end = energy;
    info->residual_start = info->residual_end = fmax;
    if (!isfinite(energy) || !isfinite(fmax)) {
        fs_error(FS_ERR_INTERNAL, "springs: the network's energy is not finite before relaxation");
        return -1;
    }
    if (fmax <= tolerance || nd == 0)
        return 0;

    bool refactor = !net->factor_valid;
    int failures = 0;
    for (int it = 0; it < max_iterations; it++) {
        bool fresh = false;
        if (refactor) {
            if (net_refactor(net) < 0)
                return -1;
            info->factorizations++;
            refactor = false;
            fresh = true;
        } else {
            net_assemble(net);
        }
        double fnorm = 0.0;
        for (int32_t j = 0; j < nd; j++)
            fnorm += f[j] * f[j];
        /* inexact Newton: two decades per step, or down to the tolerance */
        double target = 0.3 * tolerance > 1e-2 * sqrt(fnorm) ? 0.3 * tolerance : 1e-2 * sqrt(fnorm);
        int used = net_pcg(net, f, p, target, fresh ? 4 * PCG_MAX : PCG_MAX, r, z, d, q);
        if (used < 0)
            return -1;
        /* iterations past the first are what a stale factor costs; once they add up to the price of
         * a factorization (in solves, from CHOLMOD's flop counts), renew it */
        if (!fresh)
            net->stale_solves += used - 1;
        bool slow = used > PCG_MAX || net->stale_solves > net->factor_cost;
        double slope = 0.0;
        for (int32_t j = 0; j < nd; j++)
            slope += f[j] * p[j];
        if (!(slope > 0.0)) {
            if (fresh) {
                fs_error(FS_ERR_INTERNAL, "springs: the Newton direction is not a descent direction (f.p = %g)", slope);
                return -1;
            }
            refactor = true;
            continue;
        }
        double alpha = 1.0, e_trial = energy, fmax_trial = fmax;
        bool accepted = false;
        for (int ls = 0; ls < 40; ls++) {
            net_step(net, net->x, p, alpha, x_trial);
            e_trial = net_eval(net, x_trial, f_trial, &fmax_trial);
            if (isfinite(e_trial) && isfinite(fmax_trial)) {
                bool armijo = e_trial <= energy - 1e-4 * alpha * slope;
                bool flat = e_trial <= energy + 1e-12 * fabs(energy) && fmax_trial < fmax;
                if (armijo || flat) {
                    accepted = true;
                    break;
                }
            }
            alpha *= 0.5;
        }
        info->iterations++;
        if (!accepted) {
            if (fresh || ++failures > 8) {
                fs_error(FS_ERR_INTERNAL,
                         "springs: the line search failed after %d steps (residual %g N, tolerance %g N)",
                         info->iterations, fmax, tolerance);
                return -1;
            }
            refactor = true;
            continue;
        }
        if (e_trial > energy + 1e-12 * fabs(energy))
            info->energy_monotone = false;
        memcpy(net->x, x_trial, nx * sizeof *net->x);
        memcpy(f, f_trial, (size_t)nd * sizeof *f);
        energy = e_trial;
        fmax = fmax_trial;
        info->energy_end = energy;
        info->residual_end = fmax;
        if (fmax <= tolerance)
            return 0;
        refactor = alpha < 1.0 || slow;
    }
    fs_error(FS_ERR_INTERNAL, "springs: no equilibrium after %d steps (residual %g N, tolerance %g N)",
             info->iterations, fmax, tolerance);
    return -1;
}

/* One step p = M^-1 f from the current positions, whose forces f (in net->work) and energy are
 * given; on a step, f and *fworst are updated to the new positions. Returns 1, 0 or -1 as
 * fs_spring_net_step. */
static int net_step_once(fs_spring_net *net, double energy, double *fworst)
{
    int32_t nd = net->n_dof;
    size_t nx = (size_t)net->n_nodes * (size_t)net->dim, stride = (size_t)nd + 1;
    double *f = net->work, *p = f + stride, *f_trial = p + stride, *x_trial = f_trial + 5 * stride;
    if (nd == 0 || *fworst == 0.0)
        return 0;
    if (!net->factor_valid && net_refactor(net) < 0)
        return -1;
    if (net_solve(net, f, p) < 0)
        return -1;
    double slope = 0.0;
    for (int32_t j = 0; j < nd; j++)
        slope += f[j] * p[j];
    if (!(slope > 0.0))
        return 0;
    double alpha = 1.0;
    for (int ls = 0; ls < 20; ls++, alpha *= 0.5) {
        double f_new;
        net_step(net, net->x, p, alpha, x_trial);
        double e_trial = net_eval(net, x_trial, f_trial, &f_new);
        if (isfinite(e_trial) && e_trial <= energy - 1e-4 * alpha * slope) {
            memcpy(net->x, x_trial, nx * sizeof *net->x);
            memcpy(f, f_trial, (size_t)nd * sizeof *f);
            *fworst = f_new;
            return 1;
        }
    }
    return 0;
}

int fs_spring_net_step(fs_spring_net *net, double *residual)
{
    double energy = net_eval(net, net->x, net->work, residual);
    return net_step_once(net, energy, residual);
}

/* Force on node i at positions x (dim entries to out). */
static void node_force(const fs_spring_net *net, int32_t i, const double *x, double *out)
{
    int dim = net->dim;
    for (int q = 0; q < dim; q++)
        out[q] = 0.0;
    for (int32_t p = net->adj_start[i]; p < net->adj_start[i + 1]; p++) {
        int32_t s = net->adj_spring[p];
        double k = net->k[s];
        if (k == 0.0)
            continue;
        double d[3];
        double l = spring_vector(net, s, x, net->offset, d), rest = net->rest[s];
        double g = rest > 0.0 ? (l > 1e-300 ? k * (l - rest) / l : 0.0) : k;
        double sign = net->node[2 * s] == i ? 1.0 : -1.0;
        for (int q = 0; q < dim; q++)
            out[q] += sign * g * d[q];
    }
    for (int32_t p = net->anc_start[i]; p < net->anc_start[i + 1]; p++) {
        int32_t a = net->anc_list[p];
        if (net->anchor_k[a] == 0.0)
            continue;
        double d[3], r2, g = anchor_pull(net, a, x, d, &r2);
        for (int q = 0; q < dim; q++)
            out[q] -= g * d[q];
    }
}

static double norm_dim(const double *v, int dim)
{
    double s2 = 0.0;
    for (int q = 0; q < dim; q++)
        s2 += v[q] * v[q];
    return sqrt(s2);
}

/* The region of a local relaxation and its scratch. */
typedef struct {
    int32_t n;               /* region nodes */
    int32_t *nodes;          /* n_nodes entries */
    int32_t ns, cap_s;       /* springs with an end in the region (each once), intact */
    int32_t *springs;
    double *H;               /* dim * dim per region spring */
    double *P;               /* dim * dim per node: inverse of its diagonal block */
    double *f, *p, *r, *z, *d, *q, *x_save;
} local_region;

static void region_clear(fs_spring_net *net, local_region *g)
{
    for (int32_t k = 0; k < g->n; k++)
        net->local_map[g->nodes[k]] = -1;
    g->n = 0;
    g->ns = 0;
}

/* fs_region_edges_fn of a spring network: the intact springs of node i to free nodes, one hop each,
 * in the order of its adjacency. */
static void intact_springs(void *ctx, int32_t i, fs_region *r)
{
    const fs_spring_net *net = ctx;
    for (int32_t p = net->adj_start[i]; p < net->adj_start[i + 1]; p++) {
        int32_t s = net->adj_spring[p];
        if (net->k[s] == 0.0)
            continue;
        int32_t j = net->node[2 * s] == i ? net->node[2 * s + 1] : net->node[2 * s];
        if (net->dof[j] >= 0)
            fs_region_reach(r, j, 1.0);
    }
}

/* Breadth-first over intact springs from the seeds to the given depth, free nodes only (geom/region.h
 * with one hop per spring, ties by arrival: the nodes in the order of a breadth-first queue). */
static void region_grow(fs_spring_net *net, local_region *g, const int32_t *seeds, int32_t n_seeds, int32_t radius)
{
    region_clear(net, g);
    int32_t *free_seeds = fs_malloc(((size_t)n_seeds + 1) * sizeof *free_seeds), n_free = 0;
    for (int32_t k = 0; k < n_seeds; k++)
        if (net->dof[seeds[k]] >= 0)
            free_seeds[n_free++] = seeds[k];
    if (!g->nodes)
        g->nodes = fs_malloc(((size_t)net->n_nodes + 1) * sizeof *g->nodes);
    g->n = fs_region_grow(free_seeds, n_free, radius, FS_REGION_TIES_BY_ARRIVAL, intact_springs, net, net->local_dist,
                          g->nodes);
    fs_region_forget(net->local_dist, g->nodes, g->n);
    for (int32_t k = 0; k < g->n; k++)
        net->local_map[g->nodes[k]] = k;
    free(free_seeds);
    for (int32_t k = 0; k < g->n; k++) {
        int32_t i = g->nodes[k];
        for (int32_t p = net->adj_start[i]; p < net->adj_start[i + 1]; p++) {
            int32_t s = net->adj_spring[p];
            if (net->k[s] == 0.0)
                continue;
            int32_t a = net->node[2 * s], b = net->node[2 * s + 1];
            int32_t other = a == i ? b : a;
            if (net->local_map[other] >= 0 && a != i)
                continue; /* both ends inside: counted from its first end */
            FS_ARRAY_RESERVE(g->springs, g->cap_s, g->ns + 1, 1024);
            g->springs[g->ns++] = s;
        }
    }
    int dim = net->dim;
    size_t nv = (size_t)g->n * (size_t)dim + 1;
    g->H = fs_realloc(g->H, ((size_t)g->ns * (size_t)(dim * dim) + 1) * sizeof *g->H);
    g->P = fs_realloc(g->P, (size_t)g->n * (size_t)(dim * dim) * sizeof *g->P + sizeof *g->P);
    double **vecs[] = {&g->f, &g->p, &g->r, &g->z, &g->d, &g->q, &g->x_save};
    for (size_t v = 0; v < sizeof vecs / sizeof vecs[0]; v++)
        *vecs[v] = fs_realloc(*vecs[v], nv * sizeof **vecs[v]);
}

static void region_free(fs_spring_net *net, local_region *g)
{
    region_clear(net, g);
    free(g->nodes);
    free(g->springs);
    free(g->H);
    free(g->P);
    free(g->f);
    free(g->p);
    free(g->r);
    free(g->z);
    free(g->d);
    free(g->q);
    free(g->x_save);
}

/* Energy of the springs and anchors that touch the region. */
static double region_energy(const fs_spring_net *net, const local_region *g)
{
    int dim = net->dim;
    double e = 0.0;
    for (int32_t k = 0; k < g->ns; k++) {
        int32_t s = g->springs[k];
        double d[3];
        double l = spring_vector(net, s, net->x, net->offset, d) - net->rest[s];
        e += 0.5 * net->k[s] * l * l;
    }
    for (int32_t k = 0; k < g->n; k++) {
        int32_t i = g->nodes[k];
        for (int32_t p = net->anc_start[i]; p < net->anc_start[i + 1]; p++) {
            int32_t a = net->anc_list[p];
            double kk = net->anchor_k[a];
            const double *xi = net->x + (size_t)dim * (size_t)i, *at = net->anchor_at + (size_t)dim * (size_t)a;
            double r2 = 0.0;
            for (int q = 0; q < dim; q++)
                r2 += (xi[q] - at[q]) * (xi[q] - at[q]);
            double r = sqrt(r2), sl = net->slide;
            e += sl > 0.0 && r > sl ? kk * sl * (r - sl) + 0.5 * kk * sl * sl : 0.5 * kk * r2;
        }
    }
    return e;
}

/* Forces on the region's nodes into g->f; returns the largest node force. */
static double region_forces(const fs_spring_net *net, local_region *g)
{
    int dim = net->dim;
    double worst = 0.0;
    for (int32_t k = 0; k < g->n; k++) {
        double *fk = g->f + (size_t)dim * (size_t)k;
        node_force(net, g->nodes[k], net->x, fk);
        worst = fmax(worst, norm_dim(fk, dim));
    }
    return worst;
}

/* The tangent blocks of the region's springs and the inverted diagonal blocks. */
static void region_tangent(const fs_spring_net *net, local_region *g)
{
    int dim = net->dim, dd = dim * dim;
    memset(g->P, 0, (size_t)g->n * (size_t)dd * sizeof *g->P);
    for (int32_t k = 0; k < g->ns; k++) {
        int32_t s = g->springs[k];
        double d[3];
        double l = spring_vector(net, s, net->x, net->offset, d);
        double *H = g->H + (size_t)dd * (size_t)k;
        spring_block(dim, net->k[s], net->rest[s], d, l, H);
        for (int e = 0; e < 2; e++) {
            int32_t li = net->local_map[net->node[2 * s + e]];
            if (li >= 0)
                for (int m = 0; m < dd; m++)
                    g->P[(size_t)dd * (size_t)li + m] += H[m];
        }
    }
    for (int32_t k = 0; k < g->n; k++) {
        int32_t i = g->nodes[k];
        double *P = g->P + (size_t)dd * (size_t)k;
        for (int32_t p = net->anc_start[i]; p < net->anc_start[i + 1]; p++) {
            int32_t a = net->anc_list[p];
            double kk = net->anchor_k[a];
            if (net->slide > 0.0) {
                const double *xi = net->x + (size_t)dim * (size_t)i, *at = net->anchor_at + (size_t)dim * (size_t)a;
                double r2 = 0.0;
                for (int q = 0; q < dim; q++)
                    r2 += (xi[q] - at[q]) * (xi[q] - at[q]);
                if (sqrt(r2) > net->slide)
                    kk *= net->slide / sqrt(r2);
            }
            for (int q = 0; q < dim; q++)
                P[q * dim + q] += kk;
        }
        double tr = 0.0;
        for (int q = 0; q < dim; q++)
            tr += P[q * dim + q];
        double eps = 1e-12 * (tr > 0.0 ? tr : 1.0);
        for (int q = 0; q < dim; q++)
            P[q * dim + q] += eps;
    }
}

/* Inverts a symmetric positive definite dim x dim block in place (2 or 3). */
static void invert_block(double *A, int dim)
{
    if (dim == 2) {
        double det = A[0] * A[3] - A[1] * A[2];
        double a = A[0];
        A[0] = A[3] / det;
        A[3] = a / det;
        A[1] = -A[1] / det;
        A[2] = -A[2] / det;
        return;
    }
    fs_mat3_inverse(A, A);
}

/* y = K_RR v over the region (nodes outside held: their v is 0); D holds the diagonal blocks (springs,
 * anchors and the regularisation), the springs' tangent blocks give the rest. */
static void region_apply(const fs_spring_net *net, const local_region *g, const double *D, const double *v, double *y)
{
    int dim = net->dim, dd = dim * dim;
    /* diagonal blocks (springs + anchors) */
    for (int32_t k = 0; k < g->n; k++) {
        const double *B = D + (size_t)dd * (size_t)k, *vk = v + (size_t)dim * (size_t)k;
        double *yk = y + (size_t)dim * (size_t)k;
        for (int p = 0; p < dim; p++) {
            double acc = 0.0;
            for (int q = 0; q < dim; q++)
                acc += B[p * dim + q] * vk[q];
            yk[p] = acc;
        }
    }
    /* off-diagonal: -H between two region ends */
    for (int32_t k = 0; k < g->ns; k++) {
        int32_t s = g->springs[k];
        int32_t la = net->local_map[net->node[2 * s]], lb = net->local_map[net->node[2 * s + 1]];
        if (la < 0 || lb < 0)
            continue;
        const double *H = g->H + (size_t)dd * (size_t)k;
        const double *va = v + (size_t)dim * (size_t)la, *vb = v + (size_t)dim * (size_t)lb;
        double *ya = y + (size_t)dim * (size_t)la, *yb = y + (size_t)dim * (size_t)lb;
        for (int p = 0; p < dim; p++) {
            double ha = 0.0, hb = 0.0;
            for (int q = 0; q < dim; q++) {
                ha += H[p * dim + q] * vb[q];
                hb += H[p * dim + q] * va[q];
            }
            ya[p] -= ha;
            yb[p] -= hb;
        }
    }
}

/* Largest node norm of a region vector. */
static double region_max(const local_region *g, const double *v, int dim)
{
    double worst = 0.0;
    for (int32_t k = 0; k < g->n; k++)
        worst = fmax(worst, norm_dim(v + (size_t)dim * (size_t)k, dim));
    return worst;
}

/* The region's K_RR and its block-Jacobi preconditioner as fs_pcg's operator (solve/cg.h). */
typedef struct {
    const fs_spring_net *net;
    const local_region *g;
    const double *D;  /* the diagonal blocks (g->P holds their inverses) */
    double target;    /* of the largest node residual */
} region_pcg_ctx;

static void region_pcg_apply(void *ctx, const double *x, double *y)
{
    const region_pcg_ctx *c = ctx;
    region_apply(c->net, c->g, c->D, x, y);
}

static int region_pcg_precondition(void *ctx, const double *r, double *z)
{
    const region_pcg_ctx *c = ctx;
    int dim = c->net->dim, dd = dim * dim;
    for (int32_t k = 0; k < c->g->n; k++) {
        const double *P = c->g->P + (size_t)dd * (size_t)k, *rk = r + (size_t)dim * (size_t)k;
        double *zk = z + (size_t)dim * (size_t)k;
        for (int p = 0; p < dim; p++) {
            double acc = 0.0;
            for (int q = 0; q < dim; q++)
                acc += P[p * dim + q] * rk[q];
            zk[p] = acc;
        }
    }
    return 0;
}

static bool region_pcg_converged(void *ctx, const double *r)
{
    const region_pcg_ctx *c = ctx;
    return region_max(c->g, r, c->net->dim) <= c->target;
}

/* Solves K_RR p = f by block-Jacobi preconditioned CG (fs_pcg from p = 0, sequential sums) until the
 * largest node residual is below target. D holds the diagonal blocks, g->P their inverses. Returns
 * the iterations (a direction of no curvature with nothing left to reduce counts as converged), or -1. */
static int region_cg(const fs_spring_net *net, local_region *g, const double *D, double target)
{
    region_pcg_ctx c = {net, g, D, target};
    fs_cg_operator k = {g->n * net->dim, region_pcg_apply, region_pcg_precondition, region_pcg_converged, &c};
    fs_pcg_params params = {50 + 10 * (int)sqrt((double)g->n) + 2000, FS_CG_SUM_SEQUENTIAL, true, false};
    fs_pcg_result res = fs_pcg(&k, g->f, g->p, &params, (fs_pcg_vectors){g->r, g->z, g->d, g->q});
    if (res.status == FS_PCG_CONVERGED)
        return res.iterations;
    if (res.status == FS_PCG_BREAKDOWN && res.rz == 0.0)
        return res.iterations + 1;
    return -1;
}

/* Largest force on the nodes just outside the region (joined to it by an intact spring). */
static double region_ring_force(const fs_spring_net *net, const local_region *g)
{
    int dim = net->dim;
    double worst = 0.0, f[3];
    for (int32_t k = 0; k < g->ns; k++) {
        int32_t s = g->springs[k];
        for (int e = 0; e < 2; e++) {
            int32_t j = net->node[2 * s + e];
            if (net->local_map[j] >= 0 || net->dof[j] < 0)
                continue;
            node_force(net, j, net->x, f);
            worst = fmax(worst, norm_dim(f, dim));
        }
    }
    return worst;
}

int fs_spring_net_relax_local(fs_spring_net *net, const int32_t *seeds, int32_t n_seeds, double tolerance,
                              fs_spring_relax_info *info)
{

    fs_spring_relax_info local;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    info->energy_monotone = true;
    int dim = net->dim, dd = dim * dim;
    local_region g;
    memset(&g, 0, sizeof g);
    double *D = NULL;
    int32_t radius = net->local_radius > 0 ? net->local_radius : 6;
    bool first = true;
    int rc = 0;
    for (;;) {
        region_grow(net, &g, seeds, n_seeds, radius);
        if (g.n == 0)
            break;
        if (3 * (int64_t)g.n > net->n_nodes) {
            region_clear(net, &g);
            fs_spring_relax_info global;
            rc = fs_spring_net_relax(net, tolerance, 200, &global);
            info->iterations += global.iterations;
            info->factorizations += global.factorizations;
            info->residual_end = global.residual_end;
            info->energy_monotone = info->energy_monotone && global.energy_monotone;
            break;
        }
        D = fs_realloc(D, ((size_t)g.n * (size_t)dd + 1) * sizeof *D);
        double energy = region_energy(net, &g);
        double fmax = region_forces(net, &g);
        if (first) {
            info->energy_start = energy;
            info->residual_start = fmax;
            first = false;
        }
        int steps = 0;
        while (fmax > tolerance) {
            if (++steps > 30) {
                fs_error(FS_ERR_INTERNAL, "springs: no local equilibrium after %d steps (residual %g N, tolerance %g N)",
                         steps - 1, fmax, tolerance);
                rc = -1;
                break;
            }
            region_tangent(net, &g);
            memcpy(D, g.P, (size_t)g.n * (size_t)dd * sizeof *D);
            for (int32_t k = 0; k < g.n; k++)
                invert_block(g.P + (size_t)dd * (size_t)k, dim);
            if (region_cg(net, &g, D, 0.1 * tolerance) < 0) {
                fs_error(FS_ERR_INTERNAL, "springs: conjugate gradients failed on a region of %d nodes", (int)g.n);
                rc = -1;
                break;
            }
            for (int32_t k = 0; k < g.n; k++)
                memcpy(g.x_save + (size_t)dim * (size_t)k, net->x + (size_t)dim * (size_t)g.nodes[k],
                       (size_t)dim * sizeof *g.x_save);
            double alpha = 1.0, e_new = energy;
            for (int ls = 0; ls < 30; ls++) {
                for (int32_t k = 0; k < g.n; k++)
                    for (int q = 0; q < dim; q++)
                        net->x[(size_t)dim * (size_t)g.nodes[k] + q] =
                            g.x_save[(size_t)dim * (size_t)k + q] + alpha * g.p[(size_t)dim * (size_t)k + q];
                e_new = region_energy(net, &g);
                if (e_new <= energy + 1e-12 * fabs(energy))
                    break;
                alpha *= 0.5;
            }
            if (e_new > energy + 1e-12 * fabs(energy))
                info->energy_monotone = false;
            energy = e_new;
            fmax = region_forces(net, &g);
            info->iterations++;
        }
        if (rc < 0)
            break;
        info->energy_end = energy;
        info->residual_end = fmax;
        double ring = region_ring_force(net, &g);
        if (ring <= tolerance)
            break;
        radius *= 2;
    }
    region_free(net, &g);
    free(D);
    return rc;
}

void fs_spring_net_cut(fs_spring_net *net, int32_t s)
{
    FS_ASSERT(s >= 0 && s < net->n_springs);
    net->k[s] = 0.0;
    if (!net->factor_valid || net->fact_k[s] == 0.0)
        return;
    int dim = net->dim;
    int32_t a = net->node[2 * s], b = net->node[2 * s + 1];
    int32_t da = net->dof[a], db = net->dof[b];
    if (da < 0 && db < 0)
        return;
    double d[3];
    double l = spring_vector(net, s, net->fact_x, net->fact_offset, d), rest = net->fact_rest[s], k = net->fact_k[s];
    /* eigenvectors of the block: n with k, its normals with k c (all k for a zero rest length) */
    double c = 1.0, nv[3] = {1.0, 0.0, 0.0};
    if (rest > 0.0 && l > 1e-300) {
        c = fmax(0.0, 1.0 - rest / l);
        for (int q = 0; q < dim; q++)
            nv[q] = d[q] / l;
    } else {
        c = 1.0;
    }
    double vec[3][3];
    double lam[3];
    memcpy(vec[0], nv, sizeof nv);
    lam[0] = k;
    if (dim == 2) {
        vec[1][0] = -nv[1];
        vec[1][1] = nv[0];
        vec[1][2] = 0.0;
        lam[1] = k * c;
    } else {
        double helper[3] = {0.0, 0.0, 0.0};
        int m = fabs(nv[0]) < fabs(nv[1]) ? (fabs(nv[0]) < fabs(nv[2]) ? 0 : 2) : (fabs(nv[1]) < fabs(nv[2]) ? 1 : 2);
        helper[m] = 1.0;
        fs_cross3(vec[1], nv, helper);
        double len = fs_norm3(vec[1]);
        for (int q = 0; q < 3; q++)
            vec[1][q] /= len;
        fs_cross3(vec[2], nv, vec[1]);
        lam[1] = lam[2] = k * c;
    }
    int32_t col_ptr[4], rows[18];
    double vals[18];
    int rank = 0, nz = 0;
    col_ptr[0] = 0;
    for (int m = 0; m < dim; m++) {
        if (!(lam[m] > 0.0))
            continue;
        double w = sqrt(lam[m]);
        for (int q = 0; q < dim; q++) {
            if (da >= 0) {
                rows[nz] = da + q;
                vals[nz++] = w * vec[m][q];
            }
            if (db >= 0) {
                rows[nz] = db + q;
                vals[nz++] = -w * vec[m][q];
            }
        }
        col_ptr[++rank] = nz;
    }
    net->fact_k[s] = 0.0;
    if (fs_cholesky_updown(net->chol, -1, rank, col_ptr, rows, vals) < 0) {
        net->factor_valid = false;
        fs_error_clear();
    }
}

int fs_spring_net_relax_auto(fs_spring_net *net, double tolerance, fs_spring_relax_info *info)
{
    fs_spring_relax_info local;
    if (!info)
        info = &local;
    memset(info, 0, sizeof *info);
    info->energy_monotone = true;
    double fworst = 0.0;
    double *f = net->work;
    double energy = net_eval(net, net->x, f, &fworst);
    info->energy_start = info->energy_end = energy;
    info->residual_start = info->residual_end = fworst;
    if (!isfinite(energy) || !isfinite(fworst)) {
        fs_error(FS_ERR_INTERNAL, "springs: the forces are not finite before relaxation");
        return -1;
    }
    if (fworst <= tolerance)
        return 0;
    /* a large imbalance that a local relaxation would have to chase over much of the network (it
     * decays by e over `screening` hops): one step of the factor first, which holds the topology
     * exactly, so what is left is small and local */
    double reach = (net->screening > 0.0 ? net->screening : 3.0) * log(fworst / tolerance);
    if (3.0 * reach * reach * 3.0 > (double)net->n_nodes) {
        int stepped = net_step_once(net, energy, &fworst);
        if (stepped < 0)
            return -1;
        info->iterations += stepped;
        info->residual_end = fworst;
        if (fworst <= tolerance) {
            info->energy_end = fs_spring_net_energy(net);
            return 0;
        }
    }
    int32_t limit = net->n_nodes / 16, count = 0;
    int dim = net->dim;
    for (int32_t i = 0; i < net->n_nodes && count <= limit; i++) {
        int32_t di = net->dof[i];
        if (di >= 0 && norm_dim(f + di, dim) > tolerance)
            net->seeds[count++] = i;
    }
    fs_spring_relax_info inner;
    int rc = count <= limit ? fs_spring_net_relax_local(net, net->seeds, count, tolerance, &inner)
                            : fs_spring_net_relax(net, tolerance, 200, &inner);
    info->iterations += inner.iterations;
    info->factorizations += inner.factorizations;
    info->residual_end = inner.residual_end;
    info->energy_monotone = info->energy_monotone && inner.energy_monotone;
    if (rc == 0)
        info->energy_end = fs_spring_net_energy(net);
    return rc;
}
