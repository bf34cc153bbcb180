/* The shell model's state: the shell built on the mesh, its loads over time, and the time loop. */
#include "model/shell/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/vec.h"

/* Map factors are clamped to this floor so that a black pixel cannot make a triangle singular. */
#define MAP_FLOOR 0.02

fs_shell_params fs_shell_params_default(void)
{
    return (fs_shell_params){
        .bond = 1.0,
        .yield = 0.0,
        .hardening = 0.1,
        .budge = 0.2,
        .gap_scale = 1.0,
        .max_step = 0.05,
    };
}

/* ---- loads over time ---- */

/* The anchor of node i at time t (growth by moving the anchors), 3-D. */
static void anchor_at(const fs_shell *s, int32_t i, double t, double out[3])
{
    const fs_domain *d = &s->mesh->domain;
    const double *p = s->anchor0 + 3 * (size_t)i;
    if (s->growth_mode != FS_SHELL_GROWTH_MOVE) {
        memcpy(out, s->rest + 3 * (size_t)i, 3 * sizeof *out);
        return;
    }
    switch (d->type) {
    case FS_DOMAIN_CYLINDER: {
        /* a point keeps its angle and height on the cylinder of radius R(t) */
        double a = p[0] / d->radius, r = fs_growth_radius(&s->growth, t);
        out[0] = r * cos(a);
        out[1] = r * sin(a);
        out[2] = p[1];
        return;
    }
    case FS_DOMAIN_SPHERE:
        fs_growth_flow(&s->growth, p, 0.0, t, out);
        return;
    default: {
        double q[3];
        fs_growth_flow(&s->growth, p, 0.0, t, q);
        out[0] = q[0];
        out[1] = q[1];
        out[2] = 0.0;
        return;
    }
    }
}

void fs_shell_set_time(fs_shell *s, double t)
{
    const fs_model_setup *c = &s->cfg;
    s->time = t;
    s->thickness = fs_material_thickness(&c->material, t, c->time.end);
    double top, bottom;
    fs_shrink_eigenstrain(&c->shrink, t, &top, &bottom);
    s->em_iso = 0.5 * (top + bottom);
    s->kappa_h = 1.5 * (top - bottom);
    double nu = c->material.poisson;
    s->bond_t = c->shell.bond * c->material.young / ((1.0 + nu) * s->thickness);
    s->bond_n = c->shell.bond * 2.0 * c->material.young / s->thickness;
    if (s->growth_mode == FS_SHELL_GROWTH_EIGENSTRAIN)
        fs_growth_strain(&s->growth, 0.0, t, s->growth_eps, NULL);
    for (int32_t i = 0; i < s->n_nodes; i++)
        anchor_at(s, i, t, s->anchor + 3 * (size_t)i);
}

/* ---- building ---- */

static void reserve_nodes(fs_shell *s, int32_t n)
{
    if (n <= s->cap_nodes)
        return;
    int32_t cap = s->cap_nodes ? s->cap_nodes : 16;
    while (cap < n)
        cap *= 2;
    size_t o = (size_t)s->cap_nodes, c = (size_t)cap;
#define GROW(a, k)                                                        \
    do {                                                                  \
        s->a = fs_realloc(s->a, k * c * sizeof *s->a);                    \
        memset(s->a + k * o, 0, k * (c - o) * sizeof *s->a);              \
    } while (0)
    GROW(rest, 3);
    GROW(x, 3);
    GROW(anchor0, 3);
    GROW(anchor, 3);
    GROW(normal, 3);
    GROW(node_area, 1);
    GROW(pin, 1);
    GROW(f_ext, 3);
    GROW(origin, 1);
    GROW(tip_dir, 3);
    GROW(rate, 3);
    GROW(grad, 3);
    GROW(sys.dof, 3);
    s->cap_nodes = cap;
}

static void reserve_tris(fs_shell *s, int32_t n)
{
    if (n <= s->cap_tris)
        return;
    int32_t cap = s->cap_tris ? s->cap_tris : 16;
    while (cap < n)
        cap *= 2;
    size_t o = (size_t)s->cap_tris, c = (size_t)cap;
    GROW(uv, 6);
    GROW(frame, 6);
    GROW(dm_inv, 4);
    GROW(area0, 1);
    GROW(bend_c, 3);
    GROW(bend_t, 9);
    GROW(young, 1);
    GROW(threshold, 1);
    GROW(thick_factor, 1);
    GROW(plastic, 6);
    if (s->growth_mode == FS_SHELL_GROWTH_EIGENSTRAIN)
        GROW(axes, 4);
    GROW(twin, 3);
    GROW(hinge, 12);
    GROW(hinge_off, 36);
    GROW(phi0, 3);
    GROW(phi, 3);
    GROW(dphi, 36);
    GROW(gphi, 3);
    GROW(terms, 13);
    GROW(face_ratio, 1);
    s->cap_tris = cap;
}

#undef GROW

void fs_shell_reserve(fs_shell *s, int32_t nodes, int32_t tris)
{
    reserve_nodes(s, nodes);
    reserve_tris(s, tris);
}

/* Texture coordinates of the corners of triangle t from the domain (plane and cylinder: the
 * unwrapped corner over the extents, so a triangle across the seam reaches past 1; sphere: each
 * corner's own, only used for sampling maps). */
static void domain_uv(const fs_shell *s, int32_t t, double uv[6])
{
    const fs_mesh *m = s->mesh;
    const fs_domain *d = &m->domain;
    for (int c = 0; c < 3; c++) {
        double p[3];
        fs_mesh_corner(m, t, c, p);
        if (d->type == FS_DOMAIN_SPHERE) {
            fs_domain_to_uv(d, p, uv + 2 * c);
        } else {
            uv[2 * c] = p[0] / fs_domain_extent_x(d);
            uv[2 * c + 1] = p[1] / fs_domain_extent_y(d);
        }
    }
}

/* The mean texture point of triangle t for sampling maps (the sphere: of its centroid's projection). */
static void tri_uv_centre(const fs_shell *s, int32_t t, double uv[2])
{
    const fs_mesh *m = s->mesh;
    if (m->domain.type == FS_DOMAIN_SPHERE) {
        double c[3] = {0.0, 0.0, 0.0};
        for (int k = 0; k < 3; k++)
            for (int q = 0; q < 3; q++)
                c[q] += m->pos[3 * (size_t)m->tri[3 * (size_t)t + k] + q] / 3.0;
        double r = fs_norm3(c);
        for (int q = 0; q < 3; q++)
            c[q] *= m->domain.radius / r;
        fs_domain_to_uv(&m->domain, c, uv);
        return;
    }
    const double *u = s->uv + 6 * (size_t)t;
    uv[0] = (u[0] + u[2] + u[4]) / 3.0;
    uv[1] = (u[1] + u[3] + u[5]) / 3.0;
}

static double map_factor(const fs_grey_map *m, const double uv[2])
{
    return m->grey ? fmax(fs_grey_map_sample(m, uv[0], uv[1]), MAP_FLOOR) : 1.0;
}

/* Young's modulus, threshold (with jitter by triangle id) and thickness factor of triangle t. */
static void tri_materials(fs_shell *s, int32_t t)
{
    const fs_model_setup *c = &s->cfg;
    double uv[2];
    tri_uv_centre(s, t, uv);
    s->young[t] = c->material.young * map_factor(&c->young_map, uv);
    double jitter = 1.0 + c->material.jitter * (2.0 * fs_rand01(c->seed, FS_RNG_JITTER, (uint64_t)t) - 1.0);
    s->threshold[t] = 1e-3 * c->material.threshold * jitter * map_factor(&c->threshold_map, uv);
    s->thick_factor[t] = map_factor(&c->thickness_map, uv);
}

/* Rest normals and areas of the nodes from their triangles. */
void fs_shell_node_geometry(fs_shell *s)
{
    const fs_mesh *m = s->mesh;
    memset(s->normal, 0, 3 * (size_t)s->n_nodes * sizeof *s->normal);
    memset(s->node_area, 0, (size_t)s->n_nodes * sizeof *s->node_area);
    for (int32_t t = 0; t < m->n_tris; t++) {
        const double *e1 = s->frame + 6 * (size_t)t, *e2 = e1 + 3;
        double n[3];
        fs_cross3(n, e1, e2);
        for (int c = 0; c < 3; c++) {
            int32_t i = m->tri[3 * (size_t)t + c];
            s->node_area[i] += s->area0[t] / 3.0;
            for (int k = 0; k < 3; k++)
                s->normal[3 * (size_t)i + k] += s->area0[t] * n[k];
        }
    }
    for (int32_t i = 0; i < s->n_nodes; i++) {
        double *n = s->normal + 3 * (size_t)i, l = fs_norm3(n);
        if (l > 0.0)
            for (int k = 0; k < 3; k++)
                n[k] /= l;
    }
}

static int check_params(const fs_model_setup *c)
{
    const fs_shell_params *p = &c->shell;
    if (!(p->bond >= 0.0 && p->bond <= 1e6)) {
        fs_error(FS_ERR_DATA, "[shell] bond: expected a number in [0, 1e+06], got '%g'", p->bond);
        return -1;
    }
    if (!(p->yield >= 0.0)) {
        fs_error(FS_ERR_DATA, "[shell] yield: expected a number >= 0 (kPa), got '%g'", p->yield);
        return -1;
    }
    if (!(p->hardening >= 0.0)) {
        fs_error(FS_ERR_DATA, "[shell] hardening: expected a number >= 0, got '%g'", p->hardening);
        return -1;
    }
    if (!(p->budge >= 0.0 && p->budge <= 0.45)) {
        fs_error(FS_ERR_DATA, "[shell] budge: expected a number in [0, 0.45], got '%g'", p->budge);
        return -1;
    }
    if (!(p->gap_scale >= 1.0)) {
        fs_error(FS_ERR_DATA, "[shell] gap_scale: expected a number >= 1, got '%g'", p->gap_scale);
        return -1;
    }
    if (!(p->max_step > 0.0 && p->max_step <= 1.0)) {
        fs_error(FS_ERR_DATA, "[shell] max_step: expected a number in (0, 1], got '%g'", p->max_step);
        return -1;
    }
    return 0;
}

fs_shell *fs_shell_build(fs_mesh *mesh, const fs_model_setup *setup)
{
    if (check_params(setup) < 0 || fs_shrink_check(&setup->shrink) < 0)
        return NULL;
    fs_shell *s = fs_calloc(1, sizeof *s);
    s->mesh = mesh;
    s->cfg = *setup;
    const fs_domain *d = &mesh->domain;
    if (fs_growth_field_init(&s->growth, &setup->growth, NULL, d, setup->time.end) < 0) {
        free(s);
        return NULL;
    }
    bool periodic = d->type != FS_DOMAIN_SPHERE && (d->periodic_x || d->periodic_y);
    if (setup->growth.type == FS_GROWTH_NONE)
        s->growth_mode = FS_SHELL_GROWTH_NONE;
    else if (setup->growth.type == FS_GROWTH_PLANAR && (periodic || d->type == FS_DOMAIN_CYLINDER))
        s->growth_mode = FS_SHELL_GROWTH_EIGENSTRAIN;
    else
        s->growth_mode = FS_SHELL_GROWTH_MOVE;
    if (d->type == FS_DOMAIN_PLANE) {
        s->period[0][0] = d->width;
        s->period[1][1] = d->height;
    } else if (d->type == FS_DOMAIN_CYLINDER) {
        s->period[1][2] = d->height; /* around, the embedding closes by itself */
    }
    s->n_nodes = mesh->n_nodes;
    s->n_tris = mesh->n_tris;
    fs_shell_reserve(s, s->n_nodes, s->n_tris);
    for (int32_t i = 0; i < s->n_nodes; i++) {
        const double *p = mesh->pos + 3 * (size_t)i;
        memcpy(s->anchor0 + 3 * (size_t)i, p, 3 * sizeof *p);
        if (d->type == FS_DOMAIN_PLANE) {
            double *r = s->rest + 3 * (size_t)i;
            r[0] = p[0], r[1] = p[1], r[2] = 0.0;
        } else if (d->type == FS_DOMAIN_MESH) {
            memcpy(s->rest + 3 * (size_t)i, p, 3 * sizeof *p);
        } else {
            fs_domain_embed(d, p, s->rest + 3 * (size_t)i);
        }
    }
    memcpy(s->x, s->rest, 3 * (size_t)s->n_nodes * sizeof *s->x);
    for (int32_t i = 0; i < s->n_nodes; i++)
        s->origin[i] = i;
    if (d->type == FS_DOMAIN_MESH && !setup->corner_uv) {
        fs_error(FS_ERR_DATA, "shell: a mesh domain without texture coordinates");
        fs_shell_destroy(s);
        return NULL;
    }
    for (int32_t t = 0; t < s->n_tris; t++) {
        if (d->type == FS_DOMAIN_MESH)
            memcpy(s->uv + 6 * (size_t)t, setup->corner_uv + 6 * (size_t)t, 6 * sizeof *s->uv);
        else
            domain_uv(s, t, s->uv + 6 * (size_t)t);
        tri_materials(s, t);
    }
    if (fs_shell_rest_geometry(s) < 0) {
        fs_shell_destroy(s);
        return NULL;
    }
    fs_shell_node_geometry(s);
    double total = 0.0;
    for (int32_t t = 0; t < s->n_tris; t++)
        for (int i = 0; i < 3; i++) {
            double pa[3], pb[3], ab[3];
            fs_shell_corner(s, s->rest, t, i, pa);
            fs_shell_corner(s, s->rest, t, (i + 1) % 3, pb);
            fs_sub3(ab, pb, pa);
            total += fs_norm3(ab);
        }
    s->unit = s->n_tris ? total / (3.0 * s->n_tris) : 1.0;
    fs_shell_number_dofs(s);
    fs_shell_set_time(s, 0.0);
    return s;
}

fs_shell *fs_shell_create(fs_mesh *mesh, const fs_model_setup *setup)
{
    fs_shell *s = fs_shell_build(mesh, setup);
    if (s && fs_shell_equilibrium(s) < 0) {
        fs_shell_destroy(s);
        return NULL;
    }
    return s;
}

fs_model_info fs_shell_info(const fs_shell *s)
{
    return (fs_model_info){s->fractures, s->time};
}

void fs_shell_report(const fs_shell *s)
{
    const fs_shell_counters *c = &s->counters;
    fs_debug("shell: %d nodes, %d triangles, %lld fractures (%lld budges), %lld steps, %lld search equilibria",
             (int)s->n_nodes, (int)s->n_tris, (long long)s->fractures, (long long)c->budges, (long long)c->steps,
             (long long)c->search_evaluations);
    fs_debug("shell: %lld equilibria, %lld Newton steps, %lld factorizations (%lld shifted, %lld line-search halvings), "
             "%lld analyses (%lld orderings)",
             (long long)c->solves, (long long)c->back_solves, (long long)c->newton_iterations, (long long)c->shifted,
             (long long)c->line_search_cuts, (long long)c->analyses, (long long)c->orderings);
    fs_debug("shell: assembly %.2f s, factorization %.2f s, solves %.2f s in all, fracture %.2f s; %lld plastic updates",
             c->assemble_seconds, c->factor_seconds, c->solve_seconds, c->fracture_seconds,
             (long long)c->plastic_updates);
    fs_debug("shell: %lld local relaxations (%.0f nodes on average), %lld global fallbacks, %.2f s relaxing",
             (long long)c->local_relaxations, c->local_relaxations ? (double)c->local_nodes / c->local_relaxations : 0.0,
             (long long)c->global_fallbacks, c->relax_seconds);
}

void fs_shell_destroy(fs_shell *s)
{
    if (!s)
        return;
    free(s->rest);
    free(s->x);
    free(s->anchor0);
    free(s->anchor);
    free(s->normal);
    free(s->node_area);
    free(s->pin);
    free(s->f_ext);
    free(s->origin);
    free(s->tip_dir);
    free(s->rate);
    free(s->grad);
    free(s->uv);
    free(s->frame);
    free(s->dm_inv);
    free(s->area0);
    free(s->bend_c);
    free(s->bend_t);
    free(s->young);
    free(s->threshold);
    free(s->thick_factor);
    free(s->plastic);
    free(s->axes);
    free(s->hinge);
    free(s->twin);
    free(s->hinge_off);
    free(s->phi0);
    free(s->phi);
    free(s->dphi);
    free(s->gphi);
    free(s->terms);
    free(s->face_ratio);
    free(s->ke);
    free(s->work);
    free(s->local.dof);
    free(s->local.in);
    free(s->local.tris);
    fs_node_order_free(&s->order);
    fs_shell_system_free(&s->sys);
    free(s);
}
