/* The wedge model's layer: its construction from the mesh (geometry, materials from the maps, arrays), its release, and its invariant checks. */
#include "model/wedge/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/rng.h"
#include "base/vec.h"
#include "model/wedge/element.h"

/* Map factors are clamped to this floor so that a black pixel cannot make an element singular. */
#define MAP_FLOOR 0.02

/* ---- grey-level maps (thesis §5.9) ---- */

/* The map factor at a domain point (unwrapped coordinates are fine: the map wraps with the domain). */
static double map_at(const fs_grey_map *m, const fs_domain *d, const double *p)
{
    if (!m->grey)
        return 1.0;
    double uv[2];
    fs_domain_to_uv(d, p, uv);
    return fmax(fs_grey_map_sample(m, uv[0], uv[1]), MAP_FLOOR);
}

/* A map averaged over a triangle: its centroid and the three interior points (2/3, 1/6, 1/6). */
static double map_average(const fs_grey_map *m, const fs_domain *d, const double corner[3][3])
{
    if (!m->grey)
        return 1.0;
    static const double bary[4][3] = {
        {1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0}, {2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0},
        {1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0}, {1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0}};
    double sum = 0.0;
    for (int q = 0; q < 4; q++) {
        double p[3];
        for (int k = 0; k < 3; k++)
            p[k] = bary[q][0] * corner[0][k] + bary[q][1] * corner[1][k] + bary[q][2] * corner[2][k];
        if (d->type == FS_DOMAIN_SPHERE) {
            double r = fs_norm3(p);
            for (int k = 0; k < 3; k++)
                p[k] *= d->radius / r;
        }
        sum += map_at(m, d, p);
    }
    return sum / 4.0;
}

/* ---- geometry ---- */

double fs_wedge_layer_thickness(const fs_wedge_model *w, double t)
{
    return fs_material_thickness(&w->cfg.material, t, w->cfg.time.end);
}

/* Nodal thickness factor: the thickness map at the node and the linear gradient across u. */
static double node_thickness_factor(const fs_wedge_model *w, const fs_grey_map *tmap, int32_t i)
{
    const fs_domain *d = &w->mesh->domain;
    const double *p = w->mesh->pos + 3 * (size_t)i;
    double uv[2];
    fs_domain_to_uv(d, p, uv);
    double f = 1.0 + w->cfg.wedge.thickness_gradient * (uv[0] - 0.5);
    return fmax(f, MAP_FLOOR) * map_at(tmap, d, p);
}

static void node_normal(const fs_wedge_model *w, int32_t i, double n[3])
{
    if (w->flat) {
        n[0] = n[1] = 0.0;
        n[2] = 1.0;
        return;
    }
    fs_domain_normal(&w->mesh->domain, w->mesh->pos + 3 * (size_t)i, n);
}

void fs_wedge_coords_at(const fs_wedge_model *w, int32_t e, double base_thickness, double x[18])
{
    const fs_mesh *m = w->mesh;
    for (int c = 0; c < 3; c++) {
        int32_t node = m->tri[3 * (size_t)e + c];
        double *b = x + 3 * c, *t = x + 3 * (c + 3);
        fs_mesh_corner(m, e, c, b);
        if (w->flat)
            b[2] = 0.0;
        double h = base_thickness * w->thickness_factor[node];
        const double *n = w->normal + 3 * (size_t)node;
        for (int k = 0; k < 3; k++)
            t[k] = b[k] + h * n[k];
    }
}

void fs_wedge_element_coords(const fs_wedge_model *w, int32_t e, double x[18])
{
    fs_wedge_coords_at(w, e, w->assembled_thickness, x);
}

/* design: the unit displacement patterns of an element whose combinations give its loads.
 *   0..2  shrinkage (thesis Fig. 3.10, see wedge.h): bottom nodes about the bottom centroid, top nodes
 *         about the top centroid, and the top lifted along the centroid-to-centroid vector; the
 *         reference-shape displacement is sum_k (scale_k - 1) pattern_k.
 *   3..5  the linear displacements with unit strain xx, yy and engineering xy (about the element's
 *         centroid). An isoparametric element reproduces linear fields exactly, so K_e times such a
 *         pattern is the element's equivalent nodal force of that constant eigenstrain
 *         (sum_g B^T D eps det J w), without another quadrature. */
void fs_wedge_patterns(const double x[18], double pat[FS_WEDGE_PATTERNS][18])
{
    double cb[3] = {0}, ct[3] = {0}, cm[3];
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            cb[k] += x[3 * c + k] / 3.0;
            ct[k] += x[3 * (c + 3) + k] / 3.0;
        }
    for (int k = 0; k < 3; k++)
        cm[k] = 0.5 * (cb[k] + ct[k]);
    memset(pat, 0, sizeof(double) * FS_WEDGE_PATTERNS * 18);
    for (int c = 0; c < 3; c++)
        for (int k = 0; k < 3; k++) {
            pat[0][3 * c + k] = x[3 * c + k] - cb[k];
            pat[1][3 * (c + 3) + k] = x[3 * (c + 3) + k] - ct[k];
            pat[2][3 * (c + 3) + k] = ct[k] - cb[k];
        }
    for (int a = 0; a < 6; a++) {
        double dx = x[3 * a] - cm[0], dy = x[3 * a + 1] - cm[1];
        pat[3][3 * a] = dx;
        pat[4][3 * a + 1] = dy;
        pat[5][3 * a] = 0.5 * dy;
        pat[5][3 * a + 1] = 0.5 * dx;
    }
}

/* The reference-shape displacement u0 of an element at the current shrinkage coefficients. */
void fs_wedge_shrink_displacement(const fs_wedge_model *w, const double x[18], double u0[18])
{
    double pat[FS_WEDGE_PATTERNS][18];
    fs_wedge_patterns(x, pat);
    for (int a = 0; a < 18; a++)
        u0[a] = w->shrink_coef[0] * pat[0][a] + w->shrink_coef[1] * pat[1][a] + w->shrink_coef[2] * pat[2][a];
}

/* ---- construction ---- */

/* Per-element materials: Young's modulus and threshold with their maps, threshold jitter by element id. */
static void element_materials(fs_wedge_model *w, int32_t e, const fs_grey_map *ymap, const fs_grey_map *tmap)
{
    const fs_material *mat = &w->cfg.material;
    double corner[3][3];
    for (int c = 0; c < 3; c++)
        fs_mesh_corner(w->mesh, e, c, corner[c]);
    w->young[e] = mat->young * map_average(ymap, &w->mesh->domain, corner);
    double jitter = 1.0 + mat->jitter * (2.0 * fs_rand01(w->cfg.seed, FS_RNG_JITTER, (uint64_t)e) - 1.0);
    w->threshold[e] = 1e-3 * mat->threshold * jitter * map_average(tmap, &w->mesh->domain, corner);
}

/* Room for n, with a quarter more when it grows past cap: the arrays are reallocated a few times in
 * a run instead of at every cut (each cut adds a few nodes and elements). */
static bool grow_capacity(int32_t *cap, int32_t n)
{
    if (n <= *cap)
        return false;
    *cap = n + n / 4 + 16;
    return true;
}

void fs_wedge_grow_arrays(fs_wedge_model *w, int32_t n_nodes, int32_t n_elems)
{
    if (grow_capacity(&w->node_cap, n_nodes)) {
        size_t nn = (size_t)w->node_cap;
        FS_ARRAY_RESIZE(w->normal, 3 * nn);
        FS_ARRAY_RESIZE(w->thickness_factor, nn);
        FS_ARRAY_RESIZE(w->pinned, nn);
        FS_ARRAY_RESIZE(w->origin, nn);
        FS_ARRAY_RESIZE(w->prescribed, 6 * nn);
        FS_ARRAY_RESIZE(w->u, 6 * nn);
        FS_ARRAY_RESIZE(w->node_elem_count, nn);
        FS_ARRAY_RESIZE(w->node_ratio, nn);
        FS_ARRAY_RESIZE(w->node_ratio_exact, nn);
        FS_ARRAY_RESIZE(w->open, nn + 1);
    }
    size_t old_cap = (size_t)w->elem_cap;
    if (grow_capacity(&w->elem_cap, n_elems)) {
        size_t ne = (size_t)w->elem_cap;
        FS_ARRAY_RESIZE(w->state, ne);
        FS_ARRAY_RESIZE(w->young, ne);
        if (w->k_parts_on) {
            FS_ARRAY_RESIZE(w->k_parts, 3 * FS_WEDGE_PAIRS * ne);
            FS_ARRAY_RESIZE(w->k_key, FS_WEDGE_K_KEY * ne);
        }
        FS_ARRAY_RESIZE(w->threshold, ne);
        FS_ARRAY_RESIZE(w->ratio, ne);
        FS_ARRAY_RESIZE(w->stress_top, 18 * ne);
        FS_ARRAY_RESIZE(w->gauss_cache, FS_WEDGE_GAUSS_CACHE * ne);
        FS_ARRAY_RESIZE(w->edge_rest, 3 * ne);
        FS_ARRAY_RESIZE(w->ratio_lipschitz, ne);
        FS_ARRAY_RESIZE(w->ratio_ref_bound, ne);
        FS_ARRAY_RESIZE(w->ratio_ref_u, 18 * ne);
        FS_ARRAY_RESIZE(w->energy_kept, ne);
        for (size_t e = old_cap; e < ne; e++)
            w->energy_kept[e] = NULL;
    }
    size_t nn = (size_t)n_nodes, ne = (size_t)n_elems;
    for (size_t i = (size_t)w->n_nodes; i < nn; i++) {
        w->pinned[i] = 0;
        w->origin[i] = -1;
        memset(w->prescribed + 6 * i, 0, 6 * sizeof *w->prescribed);
        memset(w->u + 6 * i, 0, 6 * sizeof *w->u);
        node_normal(w, (int32_t)i, w->normal + 3 * i);
        w->node_ratio[i] = NAN;
        w->node_ratio_exact[i] = 0;
    }
    if (w->k_parts_on)
        for (size_t q = FS_WEDGE_K_KEY * (size_t)w->n_elems; q < FS_WEDGE_K_KEY * ne; q++)
            w->k_key[q] = NAN;
    for (size_t e = (size_t)w->n_elems; e < ne; e++) {
        w->state[e] = FS_WEDGE_ALIVE;
        w->ratio[e] = NAN;
        memset(w->stress_top + 18 * e, 0, 18 * sizeof *w->stress_top);
        w->ratio_lipschitz[e] = 0.0;
        w->ratio_ref_bound[e] = NAN;
        memset(w->ratio_ref_u + 18 * e, 0, 18 * sizeof *w->ratio_ref_u);
    }
    w->n_nodes = n_nodes;
    w->n_elems = n_elems;
}

/* fs_wedge_init, with the assembly and factorization left out unless assemble is set. */
static int init_model(fs_wedge_model *w, fs_mesh *mesh, const fs_model_setup *cfg, bool assemble)
{
    memset(w, 0, sizeof *w);
    w->mesh = mesh;
    w->cfg = *cfg;
    if (cfg->solver.relax == FS_RELAX_AUTO) /* see fs_solver_params and thesis §5.8 */
        w->cfg.solver.relax = FS_RELAX_LOCAL;
    w->lazy_ratios = cfg->fracture.method == FS_FRACTURE_REMOVE;
    fs_domain_normalize(&w->mesh->domain);
    const fs_domain *d = &mesh->domain;
    w->flat = d->type != FS_DOMAIN_SPHERE;
    w->k_parts_on = w->flat && fs_material_thickness(&cfg->material, 0.0, cfg->time.end)
                                   != fs_material_thickness(&cfg->material, cfg->time.end, cfg->time.end);
    w->time = 0.0;

    if (fs_wedge_elasticity(1.0, cfg->material.poisson, w->d_unit) < 0 || !(cfg->material.young > 0.0) ||
        !(cfg->material.threshold > 0.0)) {
        fs_error(FS_ERR_DATA, "[material] young, poisson, threshold: expected E > 0, -1 < nu < 0.5 and a "
                 "positive threshold, got %g MPa, %g, %g kPa", cfg->material.young, cfg->material.poisson,
                 cfg->material.threshold);
        return -1;
    }
    if (fs_shrink_check(&cfg->shrink) < 0)
        return -1;
    if (fs_growth_field_init(&w->growth, &cfg->growth, NULL, d, cfg->time.end) < 0)
        return -1;
    if (w->growth.type == FS_GROWTH_NONE)
        w->growth_mode = FS_WEDGE_GROWTH_NONE;
    else if (d->type == FS_DOMAIN_CYLINDER || (d->type == FS_DOMAIN_PLANE && (d->periodic_x || d->periodic_y)))
        w->growth_mode = FS_WEDGE_GROWTH_EIGENSTRAIN;
    else
        w->growth_mode = FS_WEDGE_GROWTH_MOVE;

    fs_wedge_grow_arrays(w, mesh->n_nodes, mesh->n_tris);
    for (int32_t i = 0; i < w->n_nodes; i++)
        w->thickness_factor[i] = node_thickness_factor(w, &cfg->thickness_map, i);
    for (int32_t e = 0; e < w->n_elems; e++)
        element_materials(w, e, &cfg->young_map, &cfg->threshold_map);

    w->assembled_thickness = fs_wedge_layer_thickness(w, 0.0);
    if (assemble && fs_wedge_build_system(w) < 0) {
        fs_wedge_free(w);
        return -1;
    }
    return 0;
}

int fs_wedge_init(fs_wedge_model *w, fs_mesh *mesh, const fs_model_setup *cfg)
{
    return init_model(w, mesh, cfg, true);
}

int fs_wedge_init_unassembled(fs_wedge_model *w, fs_mesh *mesh, const fs_model_setup *cfg)
{
    return init_model(w, mesh, cfg, false);
}

int fs_wedge_pin_top(fs_wedge_model *w, const uint8_t *pinned)
{
    w->residual_valid = false; /* see fs_wedge_relax */
    for (int32_t i = 0; i < w->n_nodes; i++)
        w->pinned[i] = pinned[i] != 0;
    return fs_wedge_build_system(w);
}

void fs_wedge_free(fs_wedge_model *w)
{
    free(w->normal);
    free(w->thickness_factor);
    free(w->pinned);
    free(w->origin);
    fs_node_order_free(&w->order);
    free(w->prescribed);
    free(w->u);
    free(w->state);
    free(w->young);
    free(w->k_parts);
    free(w->k_key);
    free(w->refill_slot);
    free(w->threshold);
    free(w->ratio);
    free(w->stress_top);
    free(w->node_ratio);
    free(w->node_ratio_exact);
    free(w->residual);
    free(w->dirty_nodes);
    free(w->gauss_cache);
    free(w->edge_rest);
    free(w->ratio_lipschitz);
    free(w->ratio_ref_bound);
    free(w->ratio_ref_u);
    fs_wedge_energy_forget(w);
    free(w->energy_kept);
    free(w->dof);
    free(w->fixed_node_dof);
    free(w->node_elem_start);
    free(w->node_elem);
    free(w->node_elem_count);
    free(w->node_elem_room);
    fs_sparse_matrix_free(&w->k_free);
    fs_wedge_coupling_free(&w->k_fb);
    free(w->load);
    free(w->rhs);
    free(w->x);
    free(w->u_fixed);
    free(w->fixed_moved);
    fs_wedge_relax_scratch_free(w);
    free(w->mark);
    fs_cholesky_free(w->chol);
    free(w->tip_node);
    free(w->tip_dir);
    free(w->tip_scale);
    free(w->open);
    memset(w, 0, sizeof *w);
}


fs_wedge_params fs_wedge_params_default(void) { return (fs_wedge_params){.thickness_gradient = 0.0}; }

void fs_wedge_check_mesh(const fs_wedge_model *w, const char *after)
{
    char why[256];
    FS_INVARIANT(fs_mesh_check(w->mesh, why, sizeof why), "wedge model, after %s: the mesh: %s", after, why);
    FS_INVARIANT(w->mesh->n_tris == w->n_elems && w->mesh->n_nodes == w->n_nodes,
                 "wedge model, after %s: %d elements and %d nodes for a mesh of %d triangles and %d nodes", after,
                 (int)w->n_elems, (int)w->n_nodes, (int)w->mesh->n_tris, (int)w->mesh->n_nodes);
}

void fs_wedge_check_system(const fs_wedge_model *w, const char *after)
{
    char why[256];
    FS_INVARIANT(w->k_free.n == w->n_free, "wedge model, after %s: K_ff of order %d for %d free unknowns", after,
                 (int)w->k_free.n, (int)w->n_free);
    FS_INVARIANT(fs_sparse_matrix_check(&w->k_free, why, sizeof why), "wedge model, after %s: K_ff: %s", after, why);
}

void fs_wedge_check_state(const fs_wedge_model *w, const char *after)
{
    int64_t bad = fs_first_nonfinite(w->u, 6 * (size_t)w->n_nodes);
    FS_INVARIANT(bad < 0, "wedge model, after %s at time %g: displacement %d of node %d is %g", after, w->time,
                 (int)(bad % 6), (int)(bad / 6), w->u[bad]);
    for (int32_t e = 0; e < w->n_elems; e++) {
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        bad = fs_first_nonfinite(w->stress_top + 18 * (size_t)e, 18);
        FS_INVARIANT(bad < 0, "wedge model, after %s at time %g: stress component %d of element %d is %g", after,
                     w->time, (int)bad, (int)e, w->stress_top[18 * (size_t)e + bad]);
    }
}
