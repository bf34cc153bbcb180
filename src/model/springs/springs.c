/* The springs model: the mass-spring network of thesis ch. 4 on a mesh, growth and shrinkage, and fracture in time. */
#include "model/springs/internal.h"

#include "config.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/uf.h"
#include "base/vec.h"
#include "fracture/event.h"
#include "fracture/rank.h"

/* ==== the springs model ==== */

fs_springs_params fs_springs_params_default(void)
{
    fs_springs_params p = {
        .layers = 1,
        .shear_lag = 2.0,
        .slide_length = -1.0,
        .residual = 1e-3,
        .max_breaks = 0,
        .post = FS_SPRINGS_POST_GLUE,
        .peel = 0.5,
    };
    return p;
}

/* A grey level of a map at uv (v up), floored at 0.01 so no spring is weightless; 1 without a map. */
static double map_sample(const fs_grey_map *m, const double *uv)
{
    double v = fs_grey_map_sample(m, uv[0], uv[1]);
    return v < 0.01 ? 0.01 : v;
}

/* Texture coordinates of a domain point given unwrapped (wrapped here first). */
static void point_uv(const fs_domain *d, const double *p, double *uv)
{
    double q[3] = {p[0], p[1], p[2]};
    fs_domain_wrap(d, q);
    fs_domain_to_uv(d, q, uv);
}

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : (x > y ? 1 : 0);
}

static int check_setup(const fs_model_setup *st)
{
    const fs_springs_params *p = &st->springs;
    if (p->layers < 1 || p->layers > 8) {
        fs_error(FS_ERR_DATA, "[springs] layers: expected an integer in 1..8, got %d", p->layers);
        return -1;
    }
    if (!(p->shear_lag > 0.0) || !isfinite(p->shear_lag)) {
        fs_error(FS_ERR_DATA, "[springs] shear_lag: expected a number > 0, got %g", p->shear_lag);
        return -1;
    }
    if (!(p->residual > 0.0 && p->residual <= 1e-2)) {
        fs_error(FS_ERR_DATA, "[springs] residual: expected a number in (0, 0.01], got %g", p->residual);
        return -1;
    }
    if (p->max_breaks < 0) {
        fs_error(FS_ERR_DATA, "[springs] max_breaks: expected an integer >= 0, got %d", p->max_breaks);
        return -1;
    }
    if ((unsigned)p->post > FS_SPRINGS_POST_FLAT || !(p->peel >= 0.0)) {
        fs_error(FS_ERR_DATA, "[springs] post, peel: expected glue, curl or flat and peel >= 0");
        return -1;
    }
    const fs_material *m = &st->material;
    if (!(m->young > 0.0) || !(m->threshold > 0.0) || !(m->thickness > 0.0) || !(m->jitter >= 0.0 && m->jitter < 1.0) ||
        !(m->poisson > -1.0 && m->poisson < 0.5)) {
        fs_error(FS_ERR_DATA, "[material] young, threshold and thickness must be > 0, jitter in [0, 1), poisson in (-1, 0.5)");
        return -1;
    }
    if (!(st->time.min_step > 0.0) || !(st->time.end >= 0.0) || !isfinite(st->time.end)) {
        fs_error(FS_ERR_DATA, "[time] end >= 0 and min_step > 0 expected (got %g, %g)", st->time.end, st->time.min_step);
        return -1;
    }
    return fs_shrink_check(&st->shrink);
}

/* Largest ratio over intact springs at the net's positions, into ratio[] (NaN when broken). */
static double compute_ratios(const fs_springs *s, const double *x, double *ratio)
{
    const fs_spring_net *net = &s->net;
    double worst = -INFINITY;
    for (int32_t i = 0; i < s->n_material; i++) {
        if (s->broken[i]) {
            ratio[i] = NAN;
            continue;
        }
        double d[3] = {0.0, 0.0, 0.0};
        const double *xa = x + (size_t)s->dim * (size_t)net->node[2 * i];
        const double *xb = x + (size_t)s->dim * (size_t)net->node[2 * i + 1];
        const double *o = net->offset + (size_t)s->dim * (size_t)i;
        for (int q = 0; q < s->dim; q++)
            d[q] = xb[q] + o[q] - xa[q];
        double r = (fs_norm3(d) / net->rest[i] - 1.0) / s->break_strain[i];
        ratio[i] = r;
        if (r > worst)
            worst = r;
    }
    return worst;
}

/* Moves the unknowns' values to time t: rest lengths, stiffnesses, offsets, anchor points. */
static void set_time(fs_springs *s, double t)
{
    fs_spring_net *net = &s->net;
    const fs_model_setup *st = &s->setup;
    int dim = s->dim, L = s->layers;
    double H = fs_material_thickness(&st->material, t, st->time.end);
    double top = fs_pwl_eval(&st->shrink.top, t), bottom = fs_pwl_eval(&st->shrink.bottom, t);
    double J[9];
    fs_growth_jacobian(&s->growth, 0.0, t, J);
    for (int l = 0; l < L; l++) {
        double shrink = bottom + (top - bottom) * (l + 0.5) / L;
        for (int32_t e = 0; e < s->n_edges; e++) {
            int32_t i = l * s->n_edges + e;
            net->rest[i] = (1.0 - shrink) * s->rest0[i];
            net->k[i] = s->broken[i] ? 0.0 : s->coef[i] * H;
            if (dim == 2) {
                const double *o = s->ref_offset + 2 * (size_t)i;
                net->offset[2 * (size_t)i] = J[0] * o[0] + J[1] * o[1];
                net->offset[2 * (size_t)i + 1] = J[3] * o[0] + J[4] * o[1];
            }
        }
    }
    for (int l = 1; l < L; l++)
        for (int32_t i = 0; i < s->n; i++)
            net->k[s->n_material + (l - 1) * s->n + i] = s->inter_coef[i] / H;
    for (int32_t i = 0; i < s->n; i++) {
        double p[3] = {0.0, 0.0, 0.0}, q[3];
        memcpy(p, s->anchor_ref + (size_t)dim * (size_t)i, (size_t)dim * sizeof *p);
        fs_growth_flow(&s->growth, p, 0.0, t, q);
        memcpy(net->anchor_at + (size_t)dim * (size_t)i, q, (size_t)dim * sizeof *q);
        net->anchor_k[i] = s->anchor_coef[i] / H;
    }
    s->state_time = t;
}

/* Starting positions at time t: the accepted ones advanced along the last equilibrium velocity and
 * carried by the background from the accepted time to t. */
static void restore_moved(fs_springs *s, double t)
{
    fs_spring_net *net = &s->net;
    int dim = s->dim;
    double tau = t - s->time;
    memcpy(s->anchor_ref, s->anchor_accepted, (size_t)dim * (size_t)s->n * sizeof *s->anchor_ref);
    for (int32_t i = 0; i < net->n_nodes; i++) {
        double p[3] = {0.0, 0.0, 0.0}, q[3];
        for (int k = 0; k < dim; k++)
            p[k] = s->x_accepted[(size_t)dim * (size_t)i + k] + tau * s->velocity[(size_t)dim * (size_t)i + k];
        fs_growth_flow(&s->growth, p, s->time, t, q);
        memcpy(net->x + (size_t)dim * (size_t)i, q, (size_t)dim * sizeof *q);
    }
}

static double tolerance(const fs_springs *s) { return s->setup.springs.residual * s->force_scale; }

static int relax_current(fs_springs *s)
{
    fs_spring_relax_info info;
    int rc = fs_spring_net_relax_auto(&s->net, tolerance(s), &info);
    s->relax_steps += info.iterations;
#ifdef FS_VALIDATE
    if (rc == 0) {
        int64_t bad = fs_first_nonfinite(s->net.x, (size_t)s->net.n_nodes * (size_t)s->net.dim);
        FS_INVARIANT(bad < 0, "springs model, after an equilibrium at time %g: coordinate %d of node %d is %g", s->time,
                     (int)(bad % s->net.dim), (int)(bad / s->net.dim), s->net.x[bad]);
    }
#endif
    return rc;
}

double fs_springs_equilibrate(fs_springs *s, double t)
{
    if (!isfinite(t)) {
        fs_error(FS_ERR_DATA, "springs: time %g is not finite", t);
        return NAN;
    }
    restore_moved(s, t);
    set_time(s, t);
    s->evaluations++;
    if (relax_current(s) < 0)
        return NAN;
    return compute_ratios(s, s->net.x, s->ratio);
}

static double equilibrate_cb(void *ctx, double t) { return fs_springs_equilibrate(ctx, t); }

void fs_springs_accept(fs_springs *s)
{
    fs_spring_net *net = &s->net;
    int dim = s->dim;
    double t = s->state_time, slide = net->slide;
    if (slide > 0.0) {
        for (int32_t i = 0; i < s->n; i++) {
            const double *x = net->x + (size_t)dim * (size_t)i, *at = net->anchor_at + (size_t)dim * (size_t)i;
            double d[3] = {0.0, 0.0, 0.0}, r = 0.0;
            for (int q = 0; q < dim; q++) {
                d[q] = x[q] - at[q];
                r += d[q] * d[q];
            }
            r = sqrt(r);
            if (r <= slide)
                continue;
            double moved[3] = {0.0, 0.0, 0.0}, back[3];
            for (int q = 0; q < dim; q++)
                moved[q] = x[q] - slide * d[q] / r;
            fs_growth_flow(&s->growth, moved, t, 0.0, back);
            if (dim == 3) {
                double len = fs_norm3(back), R = s->mesh->domain.radius;
                for (int q = 0; q < 3; q++)
                    back[q] *= R / len;
            }
            memcpy(s->anchor_ref + (size_t)dim * (size_t)i, back, (size_t)dim * sizeof *back);
            memcpy(net->anchor_at + (size_t)dim * (size_t)i, moved, (size_t)dim * sizeof *moved);
        }
    }
    s->time = t;
    memcpy(s->x_accepted, net->x, (size_t)dim * (size_t)net->n_nodes * sizeof *net->x);
    memcpy(s->anchor_accepted, s->anchor_ref, (size_t)dim * (size_t)s->n * sizeof *s->anchor_ref);
}

void fs_springs_direction(const fs_springs *s, int32_t spring, double dir[3])
{
    FS_ASSERT(spring >= 0 && spring < s->n_material);
    int32_t e = spring % s->n_edges;
    const double *a = s->mesh->pos + 3 * (size_t)s->mesh->edge[2 * e];
    const double *b = s->mesh->pos + 3 * (size_t)s->mesh->edge[2 * e + 1];
    double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    if (s->dim == 2) {
        d[0] += s->ref_offset[2 * (size_t)spring];
        d[1] += s->ref_offset[2 * (size_t)spring + 1];
        d[2] = 0.0;
    }
    double l = fs_norm3(d);
    for (int q = 0; q < 3; q++)
        dir[q] = l > 0.0 ? d[q] / l : 0.0;
}

int32_t fs_springs_fragments(const fs_springs *s, int32_t *label)
{
    int32_t n = s->n;
    fs_uf_init(label, n);
    int32_t base = (s->layers - 1) * s->n_edges;
    for (int32_t e = 0; e < s->n_edges; e++) {
        if (s->broken[base + e])
            continue;
        fs_uf_union(label, s->mesh->edge[2 * e], s->mesh->edge[2 * e + 1]);
    }
    int32_t count = 0;
    for (int32_t i = 0; i < n; i++) {
        label[i] = fs_uf_find(label, i);
        count += label[i] == i;
    }
    return count;
}

int fs_springs_init(fs_springs *s, const fs_mesh *m, const fs_model_setup *setup)
{
    memset(s, 0, sizeof *s);
    s->setup = *setup;
    s->mesh = m;
    if (check_setup(setup) < 0)
        return -1;
    if (m->n_nodes < 3 || m->n_tris < 1 || !m->edge || !m->edge_tri || !m->tri_edge || !m->ring_start) {
        fs_error(FS_ERR_DATA, "springs: the mesh needs at least 3 nodes, edges and rings (got %d nodes)", (int)m->n_nodes);
        return -1;
    }
    const fs_domain *dom = &m->domain;
    if (fs_growth_field_init(&s->growth, &setup->growth, NULL, dom, setup->time.end) < 0)
        return -1;
    if (fs_voronoi_build(m, &s->vor) < 0)
        return -1;
    const fs_springs_params *p = &setup->springs;
    const fs_material *mat = &setup->material;
    bool sphere = dom->type == FS_DOMAIN_SPHERE;
    int dim = sphere ? 3 : 2, L = p->layers;
    int32_t n = m->n_nodes, ne = m->n_edges;
    s->dim = dim;
    s->n = n;
    s->layers = L;
    s->n_edges = ne;
    s->n_material = L * ne;
    bool wrap_x = !sphere && (dom->type == FS_DOMAIN_CYLINDER || dom->periodic_x);
    bool wrap_y = !sphere && dom->periodic_y;
    s->ext[0] = wrap_x ? fs_domain_extent_x(dom) : 0.0;
    s->ext[1] = wrap_y ? fs_domain_extent_y(dom) : 0.0;

    const fs_grey_map *tmap = &setup->thickness_map, *ymap = &setup->young_map, *smap = &setup->threshold_map;

    size_t nm = (size_t)s->n_material + 1;
    s->rest0 = fs_calloc(nm, sizeof *s->rest0);
    s->coef = fs_calloc(nm, sizeof *s->coef);
    s->ref_offset = fs_calloc(nm * 2, sizeof *s->ref_offset);
    s->break_strain = fs_calloc(nm, sizeof *s->break_strain);
    s->broken = fs_calloc(nm, 1);
    s->ratio = fs_calloc(nm, sizeof *s->ratio);
    s->rate = fs_calloc(nm, sizeof *s->rate);
    s->inter_coef = fs_calloc((size_t)n + 1, sizeof *s->inter_coef);
    s->anchor_coef = fs_calloc((size_t)n + 1, sizeof *s->anchor_coef);
    s->anchor_ref = fs_calloc((size_t)dim * (size_t)n + 1, sizeof *s->anchor_ref);
    s->anchor_accepted = fs_calloc((size_t)dim * (size_t)n + 1, sizeof *s->anchor_accepted);
    s->thick = fs_calloc((size_t)n + 1, sizeof *s->thick);
    double *young_g = fs_calloc((size_t)n + 1, sizeof *young_g);

    double E = mat->young * 100.0; /* N/cm^2 */
    double G = E / (2.0 * (1.0 + mat->poisson));
    double mean_area = 0.0;
    for (int32_t i = 0; i < n; i++)
        mean_area += s->vor.cell_area[i];
    mean_area /= n;
    for (int32_t i = 0; i < n; i++) {
        double uv[2];
        point_uv(dom, m->pos + 3 * (size_t)i, uv);
        s->thick[i] = map_sample(tmap, uv);
        young_g[i] = map_sample(ymap, uv);
        double area = fmax(s->vor.cell_area[i], 1e-3 * mean_area);
        /* anchor: E A / (shear_lag^2 H); inter-layer: G A / (H / L) */
        s->anchor_coef[i] = E * young_g[i] * area / (p->shear_lag * p->shear_lag * s->thick[i]);
        s->inter_coef[i] = G * young_g[i] * area * L / s->thick[i];
        memcpy(s->anchor_ref + (size_t)dim * (size_t)i, m->pos + 3 * (size_t)i, (size_t)dim * sizeof(double));
    }
    double base_strain = mat->threshold / (1000.0 * mat->young);
    for (int32_t e = 0; e < ne; e++) {
        int32_t a = m->edge[2 * e], b = m->edge[2 * e + 1];
        double off[2] = {0.0, 0.0}, d[3], mid[3];
        if (!sphere) {
            int32_t t = m->edge_tri[2 * e];
            int ca = fs_mesh_corner_of(m, t, a), cb = fs_mesh_corner_of(m, t, b);
            FS_ASSERT(ca >= 0 && cb >= 0);
            const int8_t *sh = m->shift + 6 * (size_t)t;
            for (int q = 0; q < 2; q++)
                off[q] = (sh[2 * cb + q] - sh[2 * ca + q]) * (q == 0 ? fs_domain_extent_x(dom) : fs_domain_extent_y(dom));
        }
        const double *pa = m->pos + 3 * (size_t)a, *pb = m->pos + 3 * (size_t)b;
        for (int q = 0; q < 3; q++)
            d[q] = pb[q] + (q < 2 ? off[q] : 0.0) - pa[q];
        if (!sphere)
            d[2] = 0.0;
        double l0 = fs_norm3(d);
        for (int q = 0; q < 3; q++)
            mid[q] = pa[q] + 0.5 * d[q];
        double uv[2];
        if (sphere) {
            double r = fs_norm3(mid);
            for (int q = 0; q < 3; q++)
                mid[q] *= dom->radius / (r > 0.0 ? r : 1.0);
        }
        point_uv(dom, mid, uv);
        double gE = map_sample(ymap, uv), gT = map_sample(smap, uv);
        double w = s->vor.edge_length[e];
        bool inert = a == b || !(l0 > 0.0);
        if (!(w >= 0.0))
            w = 0.0;
        if (!inert && w > 4.0 * l0)
            w = 4.0 * l0;
        for (int l = 0; l < L; l++) {
            int32_t i = l * ne + e;
            s->rest0[i] = inert ? 1.0 : l0;
            s->ref_offset[2 * (size_t)i] = off[0];
            s->ref_offset[2 * (size_t)i + 1] = off[1];
            if (inert) {
                s->broken[i] = 1;
                continue;
            }
            double thick = 0.5 * (s->thick[a] + s->thick[b]);
            s->coef[i] = 1.5 * E * gE * w / l0 * thick / L;
            double u = fs_rand01(setup->seed, FS_RNG_JITTER, (uint64_t)i);
            s->break_strain[i] = base_strain * gT / gE * (1.0 + mat->jitter * (2.0 * u - 1.0));
        }
    }
    free(young_g);

    /* the network: material springs, inter-layer springs, anchors of the bottom layer */
    int32_t n_inter = (L - 1) * n;
    fs_spring_net *net = &s->net;
    fs_spring_net_init(net, dim, L * n, s->n_material + n_inter, n);
    for (int l = 0; l < L; l++)
        for (int32_t e = 0; e < ne; e++) {
            int32_t i = l * ne + e, a = m->edge[2 * e], b = m->edge[2 * e + 1];
            if (a == b) /* a self-edge of a tiny periodic mesh: inert (k stays 0), parked between two
                           distinct nodes so that the pattern stays valid */
                b = (a + 1) % n;
            net->node[2 * (size_t)i] = l * n + a;
            net->node[2 * (size_t)i + 1] = l * n + b;
        }
    for (int l = 1; l < L; l++)
        for (int32_t i = 0; i < n; i++) {
            int32_t sidx = s->n_material + (l - 1) * n + i;
            net->node[2 * (size_t)sidx] = (l - 1) * n + i;
            net->node[2 * (size_t)sidx + 1] = l * n + i;
            net->rest[sidx] = 0.0;
        }
    for (int32_t i = 0; i < n; i++)
        net->anchor_node[i] = i;
    net->slide = p->slide_length > 0.0 ? p->slide_length : 0.0;
    for (int l = 0; l < L; l++)
        for (int32_t i = 0; i < n; i++)
            memcpy(net->x + (size_t)dim * (size_t)(l * n + i), m->pos + 3 * (size_t)i, (size_t)dim * sizeof(double));
    s->x_accepted = fs_calloc((size_t)dim * (size_t)net->n_nodes + 1, sizeof *s->x_accepted);
    s->velocity = fs_calloc((size_t)dim * (size_t)net->n_nodes + 1, sizeof *s->velocity);
    memcpy(s->x_accepted, net->x, (size_t)dim * (size_t)net->n_nodes * sizeof *net->x);
    memcpy(s->anchor_accepted, s->anchor_ref, (size_t)dim * (size_t)n * sizeof *s->anchor_ref);
    set_time(s, 0.0);
    if (fs_spring_net_prepare(net) < 0)
        return -1;
    /* the local relaxation starts a shear-lag length out (in hops of the mean spacing) */
    double spacing = 0.0;
    for (int32_t e = 0; e < ne; e++)
        spacing += s->rest0[e];
    spacing /= ne > 0 ? ne : 1;
    double lag = p->shear_lag * fs_material_thickness(mat, 0.0, setup->time.end);
    double hops = spacing > 0.0 ? ceil(lag / spacing) + 3.0 : 6.0;
    net->local_radius = hops > 1e6 ? 1000000 : (int32_t)hops;
    net->screening = spacing > 0.0 ? fmin(lag / spacing, 1e6) : 3.0;

    /* the residual's unit: the force of a median spring at its break strain, at t = 0 */
    double *forces = fs_malloc(nm * sizeof *forces);
    int32_t cnt = 0;
    for (int32_t i = 0; i < s->n_material; i++)
        if (!s->broken[i])
            forces[cnt++] = net->k[i] * s->break_strain[i] * s->rest0[i];
    if (cnt == 0) {
        free(forces);
        fs_error(FS_ERR_DATA, "springs: the mesh has no usable edges");
        return -1;
    }
    qsort(forces, (size_t)cnt, sizeof *forces, cmp_double);
    s->force_scale = forces[cnt / 2];
    free(forces);
    s->time = 0.0;
    s->state_time = NAN;
    return 0;
}

void fs_springs_free(fs_springs *s)
{
    fs_spring_net_free(&s->net);
    fs_voronoi_free(&s->vor);
    free(s->rest0);
    free(s->coef);
    free(s->ref_offset);
    free(s->break_strain);
    free(s->broken);
    free(s->ratio);
    free(s->rate);
    free(s->inter_coef);
    free(s->anchor_coef);
    free(s->anchor_ref);
    free(s->anchor_accepted);
    free(s->thick);
    free(s->x_accepted);
    free(s->velocity);
    free(s->breaks);
    memset(s, 0, sizeof *s);
}

static bool at_limit(const fs_springs *s)
{
    int limit = s->setup.springs.max_breaks;
    return limit > 0 && s->break_count >= limit;
}

/* design: thesis §4.1, one spring at a time: while an intact spring is over its threshold at the
 * accepted time, the one with the largest ratio breaks and the network re-equilibrates at that time. */
static int cascade(fs_springs *s)
{
    while (!at_limit(s)) {
        int32_t pick = fs_rank_pick(s->ratio, NULL, s->n_material, s->setup.seed);
        if (pick < 0 || !(s->ratio[pick] > 1.0))
            return 0;
        FS_ARRAY_RESERVE(s->breaks, s->break_capacity, s->break_count + 1, 256);
        fs_springs_break *b = s->breaks + s->break_count++;
        b->spring = pick;
        b->time = s->time;
        b->ratio = s->ratio[pick];
        s->broken[pick] = 1;
        s->ratio[pick] = NAN;
        fs_spring_net_cut(&s->net, pick);
        if (relax_current(s) < 0)
            return -1;
        compute_ratios(s, s->net.x, s->ratio);
        fs_springs_accept(s);
    }
    return 0;
}

/* design: the rates of the ratios at the accepted state, by a relaxed equilibrium a little later
 * (time + delta): it also gives the equilibrium velocity that later evaluations start from, so that
 * each of them needs few Newton steps. Returns the earliest predicted crossing of 1 (INFINITY if no
 * ratio grows; time + delta if some ratio is over 1 already there), or NaN with fs_error. The net is
 * left at time + delta, not accepted. */
static double predict_event(fs_springs *s, double delta)
{
    fs_spring_net *net = &s->net;
    int dim = s->dim;
    memcpy(s->rate, s->ratio, (size_t)s->n_material * sizeof *s->rate);
    double t1 = s->time + delta;
    double r1 = fs_springs_equilibrate(s, t1);
    if (isnan(r1))
        return NAN;
    for (int32_t i = 0; i < net->n_nodes; i++) {
        double p[3] = {0.0, 0.0, 0.0}, q[3];
        memcpy(p, net->x + (size_t)dim * (size_t)i, (size_t)dim * sizeof *p);
        fs_growth_flow(&s->growth, p, t1, s->time, q);
        for (int k = 0; k < dim; k++)
            s->velocity[(size_t)dim * (size_t)i + k] = (q[k] - s->x_accepted[(size_t)dim * (size_t)i + k]) / delta;
    }
    if (r1 > 1.0)
        return t1;
    double best = INFINITY;
    for (int32_t i = 0; i < s->n_material; i++) {
        if (s->broken[i])
            continue;
        double rate = (s->ratio[i] - s->rate[i]) / delta;
        if (!(rate > 0.0))
            continue;
        double dt = (1.0 - s->rate[i]) / rate;
        if (dt < best)
            best = dt;
    }
    return s->time + (best > 0.0 ? best : 0.0);
}

int fs_springs_advance(fs_springs *s, double t_end)
{
    const fs_model_setup *st = &s->setup;
    if (!isfinite(t_end) || t_end < s->time) {
        fs_error(FS_ERR_DATA, "springs: cannot advance from t = %g to %g", s->time, t_end);
        return -1;
    }
    if (s->state_time != s->time) {
        if (isnan(fs_springs_equilibrate(s, s->time)))
            return -1;
        fs_springs_accept(s);
    }
    if (cascade(s) < 0)
        return -1;
    double min_step = st->time.min_step;
    double quality = 0.9; /* how far towards the predicted event to jump, adapted to the hits */
    double gap_hint = 0.01 * (t_end - s->time); /* the last time between events */
    while (s->time < t_end && !at_limit(s)) {
        double t_start = s->time;
        fs_progress("springs", s->time / (t_end > 0.0 ? t_end : 1.0), "t = %.4g, %d springs broken", s->time,
                    (int)s->break_count);
        double span = t_end - s->time;
        double delta = fmax(min_step, fmin(0.5 * gap_hint, 0.1 * span));
        double t_pred = predict_event(s, delta);
        if (isnan(t_pred))
            return -1;
        double t0 = s->time, dt = fmax(min_step, 0.25 * span);
        bool jumped = false;
        fs_event_result ev;
        if (t_pred < t_end) {
            double gap = t_pred - s->time, t_lo = s->time + quality * gap;
            dt = fmax(min_step, 0.25 * gap);
            if (t_lo - s->time > min_step) {
                double r = fs_springs_equilibrate(s, t_lo);
                if (isnan(r))
                    return -1;
                if (r <= 1.0) {
                    fs_springs_accept(s);
                    t0 = t_lo;
                    dt = fmax(min_step, 1.5 * (1.0 - quality) * gap);
                    jumped = true;
                } else {
                    dt = fmax(min_step, 0.25 * (t_lo - s->time));
                }
            }
        } else {
            double r = fs_springs_equilibrate(s, t_end);
            if (isnan(r))
                return -1;
            if (r <= 1.0) {
                fs_springs_accept(s);
                break;
            }
        }
        if (fs_event_find(equilibrate_cb, s, t0, dt, t_end, min_step, &ev) < 0)
            return -1;
        if (!ev.found) {
            if (ev.t_last != t_end && isnan(fs_springs_equilibrate(s, t_end)))
                return -1;
            fs_springs_accept(s);
            break;
        }
        /* the event inside the first trial step after the jump: the prediction was good, trust it more */
        if (ev.t > t_start)
            gap_hint = ev.t - t_start;
        if (jumped && ev.t <= t0 + dt)
            quality = fmin(0.97, quality + 0.5 * (1.0 - quality));
        else
            quality = fmax(0.5, quality - 0.2);
        if (ev.t_last != ev.t && isnan(fs_springs_equilibrate(s, ev.t)))
            return -1;
        fs_springs_accept(s);
        if (cascade(s) < 0)
            return -1;
    }
    fs_progress_done();
    fs_debug("springs: t = %g, %d breaks, %lld equilibria, %lld Newton steps, %lld solves, %lld factorizations", s->time,
             (int)s->break_count, (long long)s->evaluations, (long long)s->relax_steps, (long long)s->net.solves,
             (long long)s->net.factorizations);
    return 0;
}

fs_springs *fs_springs_create(const fs_mesh *mesh, const fs_model_setup *setup)
{
    fs_springs *s = fs_malloc(sizeof *s);
    if (fs_springs_init(s, mesh, setup) < 0) {
        fs_springs_free(s);
        free(s);
        return NULL;
    }
    return s;
}

fs_model_info fs_springs_info(const fs_springs *s) { return (fs_model_info){s->break_count, s->time}; }

void fs_springs_report(const fs_springs *s)
{
    fs_debug("springs: t = %g, %d breaks, %lld event-search evaluations, %lld Newton steps, %lld factorizations",
             s->time, (int)s->break_count, (long long)s->evaluations, (long long)s->relax_steps,
             (long long)s->net.factorizations);
}

void fs_springs_destroy(fs_springs *s)
{
    if (!s)
        return;
    fs_springs_free(s);
    free(s);
}
