/* The tetrahedral model's layer: mesh, materials, load cases, the global solve (CHOLMOD) and element stresses. */
#include "model/tet/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/vec.h"
#include "field/map.h"
#include "fracture/separation.h"
#include "model/tet/element.h"

/* Layer spacing that makes the tetrahedra about as tall as wide, in point spacings (geom/tetmesh.c). */
#define ISOTROPIC_LAYER 0.8165
/* Automatic layer counts stay within these. */
#define AUTO_LAYERS_MAX 6
/* The spring on every free unknown, relative to an element's stiffness E * edge. */
#define REG_RELATIVE 1e-9

fs_tet_params fs_tet_params_default(void)
{
    fs_tet_params p = {.layers = 0, .snap_distance = 0.3, .snap_angle = 5.729577951308232, .bond = 0.0,
                       .max_events = 0};
    return p;
}

/* ---- storage ---- */

void fs_tet_grow(fs_tet *s)
{
    int nl = s->n_loads > 0 ? s->n_loads : 1;
    if (s->mesh.n_tets > s->cap_tets) {
        int32_t old = s->cap_tets, cap = s->mesh.n_tets + s->mesh.n_tets / 2 + 64;
        s->grad = fs_realloc(s->grad, 12 * (size_t)cap * sizeof *s->grad);
        s->vol = fs_realloc(s->vol, (size_t)cap * sizeof *s->vol);
        s->lambda = fs_realloc(s->lambda, (size_t)cap * sizeof *s->lambda);
        s->mu = fs_realloc(s->mu, (size_t)cap * sizeof *s->mu);
        s->eps0 = fs_realloc(s->eps0, 6 * (size_t)nl * cap * sizeof *s->eps0);
        s->stress = fs_realloc(s->stress, 6 * (size_t)nl * cap * sizeof *s->stress);
        s->split_ref = fs_realloc(s->split_ref, 12 * (size_t)cap * sizeof *s->split_ref);
        memset(s->split_ref + 12 * (size_t)old, 0, 12 * (size_t)(cap - old) * sizeof *s->split_ref);
        memset(s->eps0 + 6 * (size_t)nl * old, 0, 6 * (size_t)nl * (cap - old) * sizeof *s->eps0);
        memset(s->stress + 6 * (size_t)nl * old, 0, 6 * (size_t)nl * (cap - old) * sizeof *s->stress);
        s->cap_tets = cap;
    }
    if (s->mesh.n_nodes > s->cap_nodes) {
        int32_t old = s->cap_nodes, cap = s->mesh.n_nodes + s->mesh.n_nodes / 2 + 64;
        s->u = fs_realloc(s->u, 3 * (size_t)nl * cap * sizeof *s->u);
        s->threshold = fs_realloc(s->threshold, (size_t)cap * sizeof *s->threshold);
        s->area = fs_realloc(s->area, (size_t)cap * sizeof *s->area);
        s->bonded = fs_realloc(s->bonded, (size_t)cap);
        s->dof = fs_realloc(s->dof, 3 * (size_t)cap * sizeof *s->dof);
        s->t_cross = fs_realloc(s->t_cross, (size_t)cap * sizeof *s->t_cross);
        s->stamp = fs_realloc(s->stamp, (size_t)cap * sizeof *s->stamp);
        s->r_ref = fs_realloc(s->r_ref, (size_t)cap * sizeof *s->r_ref);
        memset(s->u + 3 * (size_t)nl * old, 0, 3 * (size_t)nl * (cap - old) * sizeof *s->u);
        memset(s->area + old, 0, (size_t)(cap - old) * sizeof *s->area);
        memset(s->bonded + old, 0, (size_t)(cap - old));
        for (size_t k = 3 * (size_t)old; k < 3 * (size_t)cap; k++)
            s->dof[k] = -1;
        for (int32_t i = old; i < cap; i++) {
            s->threshold[i] = 0.0;
            s->t_cross[i] = INFINITY;
            s->stamp[i] = 0;
            s->r_ref[i] = 0.0;
        }
        s->cap_nodes = cap;
    }
}

void fs_tet_free(fs_tet *s)
{
    fs_tetmesh_free(&s->mesh);
    free(s->grad);
    free(s->vol);
    free(s->lambda);
    free(s->mu);
    free(s->eps0);
    free(s->stress);
    free(s->split_ref);
    free(s->u);
    free(s->threshold);
    free(s->area);
    free(s->bonded);
    free(s->dof);
    free(s->t_cross);
    free(s->stamp);
    free(s->r_ref);
    free(s->dof_map);
    free(s->tet_slot);
    free(s->tet_stamp);
    free(s->region);
    free(s->dist);
    fs_tetcut_result_free(&s->cut);
    memset(s, 0, sizeof *s);
}

/* ---- geometry and materials ---- */

void fs_tet_normal(const fs_tet *s, int32_t i, double n[3])
{
    if (s->mesh.domain.type == FS_DOMAIN_SPHERE) {
        const double *p = s->mesh.pos + 3 * (size_t)i;
        double r = fs_norm3(p);
        for (int k = 0; k < 3; k++)
            n[k] = p[k] / r;
        return;
    }
    n[0] = n[1] = 0.0;
    n[2] = 1.0;
}

/* The texture coordinates of a material point (its foot on the substrate). */
static void material_uv(const fs_tet *s, const double *p, double uv[2])
{
    const fs_domain *d = &s->mesh.domain;
    double q[3] = {p[0], p[1], d->type == FS_DOMAIN_SPHERE ? p[2] : 0.0};
    if (d->type != FS_DOMAIN_SPHERE)
        fs_domain_wrap(d, q);
    fs_domain_to_uv(d, q, uv);
}

static void centroid(const fs_tet *s, int32_t t, double c[3], double *zeta)
{
    double x[12];
    fs_tetmesh_corners(&s->mesh, t, x);
    *zeta = 0.0;
    for (int k = 0; k < 3; k++)
        c[k] = 0.25 * (x[k] + x[3 + k] + x[6 + k] + x[9 + k]);
    for (int i = 0; i < 4; i++)
        *zeta += 0.25 * s->mesh.zeta[s->mesh.tet[4 * (size_t)t + i]];
}

int fs_tet_update_geometry(fs_tet *s, int32_t t)
{
    double x[12];
    fs_tetmesh_corners(&s->mesh, t, x);
    if (fs_tet_gradients(x, s->grad + 12 * (size_t)t, &s->vol[t]) < 0) {
        fs_error(FS_ERR_INTERNAL, "tet: element %d has volume %g cm^3", (int)t, s->vol[t]);
        return -1;
    }
    return 0;
}

void fs_tet_load_eigenstrain(const fs_tet *s, int k, int32_t t, double eps0[6])
{
    const fs_tet_load *l = &s->load[k];
    if (l->kind == FS_TET_EIGEN) {
        memcpy(eps0, l->eps0, 6 * sizeof *eps0);
        return;
    }
    memset(eps0, 0, 6 * sizeof *eps0);
    if (l->kind == FS_TET_MOVE)
        return;
    double c[3], zeta, n[3] = {0.0, 0.0, 1.0};
    centroid(s, t, c, &zeta);
    if (s->mesh.domain.type == FS_DOMAIN_SPHERE) {
        double r = fs_norm3(c);
        for (int i = 0; i < 3; i++)
            n[i] = c[i] / r;
    }
    /* -(a (I - n n^T) + b n n^T): in the plane a, across the layer b */
    double a = l->kind == FS_TET_SHRINK_BOTTOM ? 1.0 - zeta : zeta, b = 0.5;
    double m[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            m[i][j] = -(a * ((i == j) - n[i] * n[j]) + b * n[i] * n[j]);
    eps0[0] = m[0][0];
    eps0[1] = m[1][1];
    eps0[2] = m[2][2];
    eps0[3] = 2.0 * m[0][1];
    eps0[4] = 2.0 * m[1][2];
    eps0[5] = 2.0 * m[2][0];
}

void fs_tet_coefficients(const fs_tet *s, double t, double *c)
{
    double eps[4] = {0}, J[9] = {0};
    bool have_eps = false, have_j = false;
    for (int k = 0; k < s->n_loads; k++) {
        const fs_tet_load *l = &s->load[k];
        switch (l->kind) {
        case FS_TET_SHRINK_BOTTOM: c[k] = fs_pwl_eval(&s->cfg.shrink.bottom, t); break;
        case FS_TET_SHRINK_TOP: c[k] = fs_pwl_eval(&s->cfg.shrink.top, t); break;
        case FS_TET_EIGEN:
            if (!have_eps)
                fs_growth_strain(&s->growth, 0.0, t, eps, NULL);
            have_eps = true;
            c[k] = eps[2 * l->ci + l->cj];
            break;
        case FS_TET_MOVE:
            if (!have_j)
                fs_growth_jacobian(&s->growth, 0.0, t, J);
            have_j = true;
            c[k] = J[3 * l->ci + l->cj] - (l->ci == l->cj ? 1.0 : 0.0);
            break;
        }
    }
}

double fs_tet_alpha(const fs_tet *s, double t)
{
    double c[FS_TET_LOADS], dot = 0.0, norm = 0.0;
    fs_tet_coefficients(s, t, c);
    for (int k = 0; k < s->n_loads; k++) {
        dot += c[k] * s->c_ref[k];
        norm += s->c_ref[k] * s->c_ref[k];
    }
    return norm > 0.0 ? dot / norm : 0.0;
}

/* Whether the loads are proportional over the run (see fs_tet.proportional): checked at the knots of
 * the shrinkage functions and at 64 times (the coefficients are linear between knots, and growth's
 * are one load case or follow one radius); c_ref is the largest coefficient vector met. */
static void check_proportional(fs_tet *s)
{
    int nt = 0;
    double times[2 * FS_PWL_MAX + 65];
    for (int q = 0; q <= 64; q++)
        times[nt++] = s->end * q / 64.0;
    const fs_pwl *f[2] = {&s->cfg.shrink.bottom, &s->cfg.shrink.top};
    for (int w = 0; w < 2; w++)
        for (int k = 0; k < f[w]->n; k++)
            if (f[w]->t[k] > 0.0 && f[w]->t[k] < s->end)
                times[nt++] = f[w]->t[k];
    double best = 0.0;
    memset(s->c_ref, 0, sizeof s->c_ref);
    for (int q = 0; q < nt; q++) {
        double c[FS_TET_LOADS], n = 0.0;
        fs_tet_coefficients(s, times[q], c);
        for (int k = 0; k < s->n_loads; k++)
            n += c[k] * c[k];
        if (n > best) {
            best = n;
            memcpy(s->c_ref, c, sizeof c);
        }
    }
    s->proportional = s->n_loads > 0 && best > 0.0;
    for (int q = 0; q < nt && s->proportional; q++) {
        double c[FS_TET_LOADS], a = fs_tet_alpha(s, times[q]), off = 0.0;
        fs_tet_coefficients(s, times[q], c);
        for (int k = 0; k < s->n_loads; k++)
            off += (c[k] - a * s->c_ref[k]) * (c[k] - a * s->c_ref[k]);
        s->proportional = a >= -1e-15 && off <= 1e-24 * best;
    }
}

/* The prescribed displacement of bonded node i under load k (3 values). */
static void prescribed(const fs_tet *s, int k, int32_t i, double out[3])
{
    const fs_tet_load *l = &s->load[k];
    out[0] = out[1] = out[2] = 0.0;
    if (l->kind != FS_TET_MOVE)
        return;
    const double *p = s->mesh.pos + 3 * (size_t)i;
    double d[3] = {p[0] - l->centre[0], p[1] - l->centre[1], p[2] - l->centre[2]};
    for (int a = 0; a < 3; a++)
        out[a] = l->move[3 * a] * d[0] + l->move[3 * a + 1] * d[1] + l->move[3 * a + 2] * d[2];
}

void fs_tet_load_stress(const fs_tet *s, int32_t t, int k, double sigma[6])
{
    const int32_t *v = s->mesh.tet + 4 * (size_t)t;
    int nl = s->n_loads;
    double u[12], eps[6];
    for (int c = 0; c < 4; c++)
        memcpy(u + 3 * c, s->u + 3 * ((size_t)nl * v[c] + k), 3 * sizeof *u);
    fs_tet_strain(s->grad + 12 * (size_t)t, u, eps);
    const double *e0 = s->eps0 + 6 * ((size_t)nl * t + k);
    for (int q = 0; q < 6; q++)
        eps[q] -= e0[q];
    fs_tet_stress(s->lambda[t], s->mu[t], eps, sigma);
}

void fs_tet_update_stress(fs_tet *s, int32_t t)
{
    int nl = s->n_loads;
    for (int k = 0; k < nl; k++)
        fs_tet_load_stress(s, t, k, s->stress + 6 * ((size_t)nl * t + k));
    if (s->proportional) {
        double *ref = s->split_ref + 12 * (size_t)t;
        fs_tet_stress_at(s, t, s->c_ref, ref);
        fs_separation_split_stress(ref, ref + 6, NULL);
    }
}

void fs_tet_displacement(const fs_tet *s, int32_t i, const double *c, double out[3])
{
    int nl = s->n_loads;
    out[0] = out[1] = out[2] = 0.0;
    for (int k = 0; k < nl; k++)
        for (int a = 0; a < 3; a++)
            out[a] += c[k] * s->u[3 * ((size_t)nl * i + k) + a];
}

void fs_tet_stress_at(const fs_tet *s, int32_t t, const double *c, double out[6])
{
    int nl = s->n_loads;
    const double *st = s->stress + 6 * (size_t)nl * t;
    for (int q = 0; q < 6; q++)
        out[q] = 0.0;
    for (int k = 0; k < nl; k++)
        for (int q = 0; q < 6; q++)
            out[q] += c[k] * st[6 * k + q];
}

/* Bonded nodes' shares of the bonded bottom: a third of each bottom face (all corners bonded). */
static void bonded_areas(fs_tet *s)
{
    for (int32_t i = 0; i < s->mesh.n_nodes; i++)
        s->area[i] = 0.0;
    int32_t *adj = fs_malloc((4 * (size_t)s->mesh.n_tets + 1) * sizeof *adj);
    fs_tetmesh_adjacency(&s->mesh, adj);
    for (int32_t h = 0; h < 4 * s->mesh.n_tets; h++) {
        if (adj[h] >= 0)
            continue;
        const int *f = fs_tet_face[h % 4];
        const int32_t *v = s->mesh.tet + 4 * (size_t)(h / 4);
        if (!s->bonded[v[f[0]]] || !s->bonded[v[f[1]]] || !s->bonded[v[f[2]]])
            continue;
        double x[12], e1[3], e2[3], n[3];
        fs_tetmesh_corners(&s->mesh, h / 4, x);
        fs_sub3(e1, x + 3 * f[1], x + 3 * f[0]);
        fs_sub3(e2, x + 3 * f[2], x + 3 * f[0]);
        fs_cross3(n, e1, e2);
        double a = fs_norm3(n) / 6.0;
        for (int k = 0; k < 3; k++)
            s->area[v[f[k]]] += a;
    }
    free(adj);
}

void fs_tet_number_dofs(fs_tet *s)
{
    for (int32_t i = 0; i < s->mesh.n_nodes; i++)
        for (int a = 0; a < 3; a++) {
            int32_t *d = s->dof + 3 * (size_t)i + a;
            if (s->bonded[i])
                *d = -1;
            else if (*d < 0)
                *d = s->n_free++;
        }
}

/* ---- the global solve ---- */

/* The unknowns of tetrahedron t's 12 displacements (-1 where bonded), through map (NULL: global
 * numbering; else local numbers of the global unknowns, -1 outside). */
static void element_dofs(const fs_tet *s, int32_t t, const int32_t *map, int32_t idx[12])
{
    for (int c = 0; c < 4; c++)
        for (int a = 0; a < 3; a++) {
            int32_t g = s->dof[3 * (size_t)s->mesh.tet[4 * (size_t)t + c] + a];
            idx[3 * c + a] = g < 0 ? -1 : (map ? map[g] : g);
        }
}

int fs_tet_solve_global(fs_tet *s)
{
    double t0 = fs_seconds();
    int nl = s->n_loads;
    int32_t n = s->n_free;
    if (n == 0 || nl == 0) {
        for (int32_t t = 0; t < s->mesh.n_tets; t++)
            fs_tet_update_stress(s, t);
        return 0;
    }
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, n, 78 * (size_t)s->mesh.n_tets + (size_t)n);
    double *rhs = fs_calloc((size_t)nl * n, sizeof *rhs);
    for (int32_t t = 0; t < s->mesh.n_tets; t++) {
        double K[144];
        int32_t idx[12];
        const double *g = s->grad + 12 * (size_t)t;
        fs_tet_stiffness(g, s->vol[t], s->lambda[t], s->mu[t], K);
        element_dofs(s, t, NULL, idx);
        fs_sparse_builder_add_block(&b, 12, idx, K);
        for (int k = 0; k < nl; k++) {
            /* the eigenstrain's force vol g sigma0, less K times the prescribed displacements */
            double e0[6], s0[6], f[12], ub[12];
            memcpy(e0, s->eps0 + 6 * ((size_t)nl * t + k), sizeof e0);
            fs_tet_stress(s->lambda[t], s->mu[t], e0, s0);
            fs_tet_forces(g, s->vol[t], s0, f);
            bool moved = false;
            for (int c = 0; c < 4; c++) {
                int32_t v = s->mesh.tet[4 * (size_t)t + c];
                if (s->bonded[v])
                    prescribed(s, k, v, ub + 3 * c);
                else
                    ub[3 * c] = ub[3 * c + 1] = ub[3 * c + 2] = 0.0;
                moved = moved || ub[3 * c] != 0.0 || ub[3 * c + 1] != 0.0 || ub[3 * c + 2] != 0.0;
            }
            for (int a = 0; a < 12; a++) {
                if (idx[a] < 0)
                    continue;
                double r = -f[a];
                if (moved)
                    for (int q = 0; q < 12; q++)
                        r -= K[12 * a + q] * ub[q];
                rhs[(size_t)k * n + idx[a]] += r;
            }
        }
    }
    for (int32_t i = 0; i < n; i++)
        fs_sparse_builder_add(&b, i, i, s->reg);
    fs_sparse_matrix K = {0};
    int rc = fs_sparse_builder_compress(&b, &K, NULL);
    fs_sparse_builder_free(&b);
    double *x = NULL;
    if (rc == 0) {
        fs_cholesky *chol = fs_cholesky_analyze(&K);
        x = fs_malloc((size_t)nl * n * sizeof *x);
        rc = !chol || fs_cholesky_factorize(chol, &K) < 0 || fs_cholesky_solve(chol, nl, rhs, x) < 0 ? -1 : 0;
        fs_cholesky_free(chol);
    }
    fs_sparse_matrix_free(&K);
    if (rc == 0) {
        for (int32_t i = 0; i < s->mesh.n_nodes; i++)
            for (int k = 0; k < nl; k++) {
                double *u = s->u + 3 * ((size_t)nl * i + k);
                if (s->bonded[i]) {
                    prescribed(s, k, i, u);
                    continue;
                }
                for (int a = 0; a < 3; a++)
                    u[a] = x[(size_t)k * n + s->dof[3 * (size_t)i + a]];
            }
        for (int32_t t = 0; t < s->mesh.n_tets; t++)
            fs_tet_update_stress(s, t);
    }
    free(x);
    free(rhs);
    s->counters.global_solves++;
    s->counters.solve_seconds += fs_seconds() - t0;
    return rc;
}

/* ---- set-up ---- */

/* Whether entry (i, j) of F - I (eigenstrain) or J - I (move) is ever nonzero over the run. */
static bool growth_entry_used(const fs_tet *s, bool eigen, int i, int j)
{
    for (int q = 1; q <= 8; q++) {
        double t = s->end * q / 8.0, v;
        if (eigen) {
            double eps[4];
            fs_growth_strain(&s->growth, 0.0, t, eps, NULL);
            v = eps[2 * i + j];
        } else {
            double J[9];
            fs_growth_jacobian(&s->growth, 0.0, t, J);
            v = J[3 * i + j] - (i == j ? 1.0 : 0.0);
        }
        if (v != 0.0)
            return true;
    }
    return false;
}

static bool pwl_used(const fs_pwl *f)
{
    for (int k = 0; k < f->n; k++)
        if (f->v[k] != 0.0)
            return true;
    return false;
}

static void add_load(fs_tet *s, fs_tet_load l)
{
    FS_ASSERT(s->n_loads < FS_TET_LOADS);
    s->load[s->n_loads++] = l;
}

static void choose_loads(fs_tet *s)
{
    const fs_domain *d = &s->mesh.domain;
    s->n_loads = 0;
    if (pwl_used(&s->cfg.shrink.bottom))
        add_load(s, (fs_tet_load){.kind = FS_TET_SHRINK_BOTTOM});
    if (pwl_used(&s->cfg.shrink.top))
        add_load(s, (fs_tet_load){.kind = FS_TET_SHRINK_TOP});
    if (s->growth.type == FS_GROWTH_NONE)
        return;
    bool periodic = d->type == FS_DOMAIN_CYLINDER || (d->type == FS_DOMAIN_PLANE && (d->periodic_x || d->periodic_y));
    if (periodic) {
        static const int entries[3][2] = {{0, 0}, {1, 1}, {0, 1}};
        for (int q = 0; q < 3; q++) {
            int i = entries[q][0], j = entries[q][1];
            if (!growth_entry_used(s, true, i, j))
                continue;
            fs_tet_load l = {.kind = FS_TET_EIGEN, .ci = i, .cj = j};
            /* the layer's eigenstrain is -(F - I): per unit coefficient -1 (engineering shear -2) */
            l.eps0[q == 2 ? 3 : q] = q == 2 ? -2.0 : -1.0;
            add_load(s, l);
        }
        return;
    }
    if (d->type == FS_DOMAIN_SPHERE) {
        /* (x, y) scale by a(t) / a0, z by c(t) / c0 */
        fs_tet_load xy = {.kind = FS_TET_MOVE, .ci = 0, .cj = 0}, z = {.kind = FS_TET_MOVE, .ci = 2, .cj = 2};
        xy.move[0] = xy.move[4] = 1.0;
        z.move[8] = 1.0;
        if (growth_entry_used(s, false, 0, 0))
            add_load(s, xy);
        if (growth_entry_used(s, false, 2, 2))
            add_load(s, z);
        return;
    }
    for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
            if (!growth_entry_used(s, false, i, j))
                continue;
            fs_tet_load l = {.kind = FS_TET_MOVE, .ci = i, .cj = j};
            l.move[3 * i + j] = 1.0;
            l.centre[0] = s->growth.fixed[0];
            l.centre[1] = s->growth.fixed[1];
            add_load(s, l);
        }
}

int fs_tet_init(fs_tet *s, fs_tetmesh *mesh, const fs_model_setup *cfg, bool bond_bottom)
{
    double t0 = fs_seconds();
    s->mesh = *mesh;
    memset(mesh, 0, sizeof *mesh);
    s->cfg = *cfg;
    s->par = cfg->tet;
    s->end = cfg->time.end;
    const fs_material *mat = &cfg->material;
    if (fs_growth_field_init(&s->growth, &cfg->growth, NULL, &s->mesh.domain, cfg->time.end) < 0) {
        fs_tet_free(s);
        return -1;
    }
    fs_tetmesh_build_node_tets(&s->mesh);
    choose_loads(s);
    check_proportional(s);
    fs_tet_grow(s);
    int nl = s->n_loads;

    double edges = 0.0;
    for (int32_t t = 0; t < s->mesh.n_tets; t++) {
        double x[12];
        fs_tetmesh_corners(&s->mesh, t, x);
        for (int a = 0; a < 4; a++)
            for (int b = a + 1; b < 4; b++) {
                double d[3];
                fs_sub3(d, x + 3 * b, x + 3 * a);
                edges += fs_norm3(d);
            }
    }
    s->mean_edge = s->mesh.n_tets ? edges / (6.0 * s->mesh.n_tets) : 1.0;
    s->reg = REG_RELATIVE * mat->young * s->mean_edge;
    s->snap.snap_distance = s->par.snap_distance * s->mean_edge;
    s->snap.snap_angle = s->par.snap_angle * FS_PI / 180.0;

    for (int32_t t = 0; t < s->mesh.n_tets; t++) {
        if (fs_tet_update_geometry(s, t) < 0) {
            fs_tet_free(s);
            return -1;
        }
        double c[3], zeta, uv[2];
        centroid(s, t, c, &zeta);
        material_uv(s, c, uv);
        double young = mat->young * fs_grey_map_factor(&cfg->young_map, uv[0], uv[1]);
        if (fs_tet_lame(young, mat->poisson, &s->lambda[t], &s->mu[t]) < 0) {
            fs_error(FS_ERR_DATA, "[material] young, poisson: expected E > 0 and -1 < nu < 0.5, got %g MPa and %g",
                     young, mat->poisson);
            fs_tet_free(s);
            return -1;
        }
        for (int k = 0; k < nl; k++)
            fs_tet_load_eigenstrain(s, k, t, s->eps0 + 6 * ((size_t)nl * t + k));
    }
    for (int32_t i = 0; i < s->mesh.n_nodes; i++) {
        double uv[2];
        material_uv(s, s->mesh.pos + 3 * (size_t)i, uv);
        double jitter = 1.0 + mat->jitter * fs_rand_range(cfg->seed, FS_RNG_JITTER, (uint64_t)i, -1.0, 1.0);
        s->threshold[i] = 1e-3 * mat->threshold * jitter * fs_grey_map_factor(&cfg->threshold_map, uv[0], uv[1]);
        s->bonded[i] = bond_bottom && s->mesh.zeta[i] == 0.0;
    }
    bonded_areas(s);
    fs_tet_number_dofs(s);
    if (fs_tet_solve_global(s) < 0) {
        fs_tet_free(s);
        return -1;
    }
    /* a typical element force of each load alone: the residual tests are relative to it */
    for (int k = 0; k < nl; k++) {
        double sum = 0.0;
        for (int32_t t = 0; t < s->mesh.n_tets; t++) {
            const double *st = s->stress + 6 * ((size_t)nl * t + k);
            for (int q = 0; q < 6; q++)
                sum += st[q] * st[q];
        }
        double rms = s->mesh.n_tets ? sqrt(sum / s->mesh.n_tets) : 0.0;
        s->load[k].scale = rms * s->mean_edge * s->mean_edge;
    }
    s->counters.mesh_seconds += fs_seconds() - t0;
    return 0;
}

/* ---- the model interface ---- */

fs_tet *fs_tet_create(fs_mesh *mesh, const fs_model_setup *setup)
{
    double t0 = fs_seconds();
    const fs_material *mat = &setup->material;
    fs_domain dom = mesh->domain;
    fs_domain_normalize(&dom);
    if (!(mat->young > 0.0) || !(mat->poisson > -1.0 && mat->poisson < 0.5) || !(mat->threshold > 0.0)) {
        fs_error(FS_ERR_DATA, "[material] young, poisson, threshold: expected E > 0, -1 < nu < 0.5 and a positive "
                 "threshold, got %g MPa, %g, %g kPa", mat->young, mat->poisson, mat->threshold);
        return NULL;
    }
    if (!(mat->thickness > 0.0)) {
        fs_error(FS_ERR_DATA, "[material] thickness: expected a positive thickness, got %g cm", mat->thickness);
        return NULL;
    }
    if (mat->thickness_final >= 0.0 && mat->thickness_final != mat->thickness) {
        fs_error(FS_ERR_DATA, "[material] thickness_final: the tet model keeps its layer's thickness; expected none "
                 "(or %g cm), got %g cm", mat->thickness, mat->thickness_final);
        return NULL;
    }
    if (setup->fracture.method != FS_FRACTURE_SPLIT) {
        fs_error(FS_ERR_DATA, "[fracture] method: the tet model fractures by splitting nodes; expected split");
        return NULL;
    }
    if (fs_shrink_check(&setup->shrink) < 0)
        return NULL;
    if (dom.type == FS_DOMAIN_SPHERE && mat->thickness > 0.5 * dom.radius) {
        fs_error(FS_ERR_DATA, "[material] thickness: %g cm on a sphere of radius %g cm: expected at most half the "
                 "radius", mat->thickness, dom.radius);
        return NULL;
    }
    double spacing = fs_sample_spacing(&dom, mesh->n_nodes);
    int layers = setup->tet.layers;
    if (layers <= 0) {
        layers = (int)lround(mat->thickness / (ISOTROPIC_LAYER * spacing));
        layers = layers < 1 ? 1 : (layers > AUTO_LAYERS_MAX ? AUTO_LAYERS_MAX : layers);
    }
    fs_points top = {mesh->n_nodes, mesh->pos};
    fs_tetlayer_params lp = fs_tetlayer_params_default();
    lp.thickness = mat->thickness;
    lp.layers = layers;
    lp.iterations = setup->mesh.relax_iterations;
    lp.radius_jitter = setup->mesh.radius_jitter;
    lp.seed = setup->seed;
    fs_tetmesh tm;
    if (fs_tetmesh_layer(&dom, &top, &lp, &tm) < 0)
        return NULL;
    /* the thickness map scales each node's height above the substrate */
    if (setup->thickness_map.grey) {
        for (int32_t i = 0; i < tm.n_nodes; i++) {
            double *p = tm.pos + 3 * (size_t)i, uv[2], q[3] = {p[0], p[1], dom.type == FS_DOMAIN_SPHERE ? p[2] : 0.0};
            if (dom.type != FS_DOMAIN_SPHERE)
                fs_domain_wrap(&dom, q);
            fs_domain_to_uv(&dom, q, uv);
            double f = fs_grey_map_factor(&setup->thickness_map, uv[0], uv[1]);
            if (dom.type == FS_DOMAIN_SPHERE) {
                double r = fs_norm3(p), scale = (dom.radius + (r - dom.radius) * f) / r;
                for (int k = 0; k < 3; k++)
                    p[k] *= scale;
            } else {
                p[2] *= f;
            }
        }
    }
    fs_tet *s = fs_calloc(1, sizeof *s);
    s->spacing = spacing;
    if (fs_tet_init(s, &tm, setup, true) < 0) {
        free(s);
        return NULL;
    }
    s->counters.mesh_seconds = fs_seconds() - t0;
    fs_debug("tet: %d nodes, %d tetrahedra in %d layers, %d free unknowns, %d load cases%s; mean edge %.3g cm",
             (int)s->mesh.n_nodes, (int)s->mesh.n_tets, layers, (int)s->n_free, s->n_loads,
             s->proportional ? " (proportional)" : "", s->mean_edge);
    for (int32_t i = 0; i < s->mesh.n_nodes; i++)
        if (fs_tet_search_node(s, i, 0.0) < 0) {
            fs_tet_destroy(s);
            return NULL;
        }
    return s;
}

fs_model_info fs_tet_info(const fs_tet *s)
{
    return (fs_model_info){s->counters.splits + s->counters.debonds, s->time};
}

void fs_tet_report(const fs_tet *s)
{
    const fs_tet_counters *c = &s->counters;
    fs_debug("tet: %lld splits (%lld found no plane), %lld bonds came loose; %d nodes, %d tetrahedra now",
             (long long)c->splits, (long long)c->failed_splits, (long long)c->debonds, (int)s->mesh.n_nodes,
             (int)s->mesh.n_tets);
    fs_debug("tet: %lld node searches (%lld ratio evaluations), %lld local solves (%.1f unknowns on average, %lld "
             "by a direct factor), %lld global", (long long)c->searches, (long long)c->evaluations,
             (long long)c->local_solves, c->local_solves ? (double)c->local_unknowns / (double)c->local_solves : 0.0,
             (long long)c->direct_solves, (long long)c->global_solves);
    fs_debug("tet: seconds: set-up %.2f, global solves %.2f, local solves %.2f, searches %.2f, cuts %.2f",
             c->mesh_seconds, c->solve_seconds, c->local_seconds, c->search_seconds, c->cut_seconds);
}

void fs_tet_destroy(fs_tet *s)
{
    if (!s)
        return;
    fs_tet_free(s);
    free(s);
}
