/* The wedge model around crack tips (thesis §5.7.7-5.7.9): adaptive refinement by von Mises discontinuity, local multi-resolution sub-models for tip stresses, angle-based smoothing near new tips. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/sort.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "fracture/separation.h"
#include "geom/refine.h"
#include "model/wedge/internal.h"
#include "model/wedge/frame.h"

/* Refinement passes of a sub-model around its tip (each bisects the tip's vicinity once, with
 * propagation); a bound, reached only with a tip_submodel_size far below the mesh. */
#define SUBMODEL_PASSES 40
/* Step lengths a smoothing move tries, as fractions of the angle-based target's displacement. */
static const double smooth_steps[] = {1.0, 0.5, 0.25};

double fs_wedge_tips_unit(fs_wedge_model *w)
{
    if (w->tips_unit <= 0.0)
        w->tips_unit = fs_wedge_mean_edge(w);
    return w->tips_unit;
}

/* ---- §5.7.7: adaptive refinement by von Mises discontinuity (Algorithm 13) ---- */

double fs_wedge_vm_discontinuity(const fs_wedge_model *w, double *indicator)
{
    int32_t n = w->n_nodes;
    double *lo = fs_malloc(((size_t)n + 1) * sizeof *lo), *hi = fs_malloc(((size_t)n + 1) * sizeof *hi);
    for (int32_t i = 0; i < n; i++) {
        lo[i] = INFINITY;
        hi[i] = -INFINITY;
    }
    double top = -INFINITY;
    for (int32_t e = 0; e < w->n_elems; e++) {
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        for (int c = 0; c < 3; c++) {
            /* top Gauss point c is the one nearest corner c (wedge_element.h) */
            const double *s = w->stress_top + 18 * (size_t)e + 6 * c;
            double sigma[3];
            if (fs_eigen_principal_stress(s, sigma, NULL) == 0)
                top = fmax(top, sigma[0]);
            else
                fs_error_clear();
            double vm = fs_eigen_von_mises(s);
            int32_t i = w->mesh->tri[3 * (size_t)e + c];
            lo[i] = fmin(lo[i], vm);
            hi[i] = fmax(hi[i], vm);
        }
    }
    double best = 0.0;
    for (int32_t i = 0; i < n; i++) {
        double d = hi[i] >= lo[i] ? (top > 0.0 ? (hi[i] - lo[i]) / top : 0.0) : NAN;
        if (indicator)
            indicator[i] = d;
        if (d > best)
            best = d;
    }
    free(lo);
    free(hi);
    return best;
}

/* design: thesis §5.7.7, Algorithm 13. The nodal stresses of the elements around a node disagree
 * where the mesh is too coarse for the stress field (Bastian et al.'s indicator): the spread of their
 * von Mises stresses at the node, relative to the largest principal stress in the layer, marks the
 * node, and every element around a marked node is bisected once (Rivara, conforming; never below
 * mesh.min_size, so the marking of elements already at that size is dropped and the loop ends when
 * the indicator can no longer be acted on). Each round re-solves the whole layer, since the new
 * midpoint nodes carry no displacement, and the next round marks from the new stresses. The
 * indicator reads the top Gauss points' stresses the equilibrium left (with lazy_ratios, the element
 * removal method's lazy evaluation, those are first brought up to date). Around a sharp crack tip the
 * stress is singular and the indicator there does not vanish under refinement; min_size and the
 * round limit bound the refinement. */
int fs_wedge_refine_vm(fs_wedge_model *w, double threshold, int rounds, int32_t *bisected)
{
    double t0 = fs_seconds();
    int32_t total = 0;
    int rc = 0;
    double min_size = w->cfg.mesh.min_size;
    for (int round = 0; round < rounds && rc == 0; round++) {
        if (w->lazy_ratios) {
            w->lazy_ratios = false;
            rc = fs_wedge_update_ratios(w, NULL, 0);
            w->lazy_ratios = true;
            if (rc < 0)
                break;
        }
        double *ind = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *ind);
        fs_wedge_vm_discontinuity(w, ind);
        uint8_t *mark = fs_calloc((size_t)w->n_elems + 1, 1);
        for (int32_t i = 0; i < w->n_nodes; i++) {
            if (!(ind[i] > threshold))
                continue;
            for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
                mark[w->node_elem[p]] = 1;
        }
        free(ind);
        int32_t *list = fs_malloc(((size_t)w->n_elems + 1) * sizeof *list), n = 0;
        for (int32_t e = 0; e < w->n_elems; e++)
            if (mark[e] && w->state[e] == FS_WEDGE_ALIVE && fs_refine_tri_size(w->mesh, e) >= min_size)
                list[n++] = e;
        free(mark);
        int32_t b = 0;
        if (n > 0)
            rc = fs_wedge_subdivide(w, list, n, false, &b);
        free(list);
        if (rc < 0 || b == 0)
            break;
        total += b;
        w->counters.vm_rounds++;
        w->counters.vm_bisections += b;
        rc = fs_wedge_equilibrium(w, w->time);
    }
    if (bisected)
        *bisected = total;
    w->counters.vm_seconds += fs_seconds() - t0;
    return rc < 0 ? -1 : 0;
}

/* ---- §5.7.8: local multi-resolution sub-models at crack tips ---- */

/* The nodal ratio of §5.7.1 at node (the stresses of its living elements at their top Gauss point
 * nearest it, averaged; the largest principal stress over their mean threshold) and the normal of
 * its principal plane (m may be NULL). -inf for a node without living elements. */
static int nodal_ratio(const fs_wedge_model *w, int32_t node, double *ratio, double m[3])
{
    double s[6], thr = 0.0;
    int count = fs_wedge_nodal_stress(w, node, true, s);
    *ratio = -INFINITY;
    if (count < 0)
        return -1;
    if (count == 0)
        return 0;
    for (int32_t p = w->node_elem_start[node]; p < w->node_elem_start[node] + w->node_elem_count[node]; p++)
        if (w->state[w->node_elem[p]] == FS_WEDGE_ALIVE)
            thr += w->threshold[w->node_elem[p]];
    double sigma1;
    if (fs_nodal_principal_plane(s, &sigma1, m) < 0)
        return -1;
    *ratio = sigma1 / (thr / count);
    return 0;
}

/* The sub-model's triangles around tip (its fan) and their neighbours across an edge whose longest
 * edge is at least size, ascending (§5.7.6's vicinity, one ring of neighbours). */
static int32_t tip_vicinity(const fs_mesh *m, int32_t tip, double size, uint8_t *flag, int32_t *out)
{
    int32_t n = 0;
    for (int32_t t = 0; t < m->n_tris; t++) {
        if (fs_mesh_corner_of(m, t, tip) < 0)
            continue;
        for (int k = -1; k < 3; k++) {
            int32_t u = k < 0 ? t : m->adj[3 * (size_t)t + k];
            if (u >= 0 && !flag[u]) {
                flag[u] = 1;
                out[n++] = u;
            }
        }
    }
    int32_t kept = 0;
    for (int32_t q = 0; q < n; q++) {
        flag[out[q]] = 0;
        if (fs_refine_tri_size(m, out[q]) >= size)
            out[kept++] = out[q];
    }
    fs_sort_int32(out, kept);
    return kept;
}

/* design: thesis §5.7.8, Fig. 5.24. The stress at a crack tip needs small elements around the tip,
 * and only while it is evaluated, so a copy of the tip's neighbourhood is refined instead of the
 * layer: the nodes within the radius are marked (along the edges of living elements, so cracks are
 * barriers and the far side of a crack is not copied), every living element with a marked corner is
 * copied (nodes, triangles and periodic corner shifts, so the copy has the layer's geometry), and the
 * copy's unmarked nodes are held at the layer's current displacement: "the elements beyond the radius
 * of the sub-model do not affect the stresses at the crack tip". Bottom nodes keep the layer's
 * prescribed values, and the sub-model adds the background's motion itself, so a midpoint made by the
 * refinement gets the background's motion at its own position. The tip's vicinity (§5.7.6: its fan and
 * the neighbours across its edges) is then bisected (Rivara, conforming, with propagation) until its
 * triangles are below the size; midpoints of edges between two held nodes are held at the
 * interpolated displacement (exact: the wedge interpolates linearly along an edge), all others are
 * free; new triangles take the materials of the layer's element they lie in, new nodes the
 * interpolated thickness factor. The copy is built as a wedge model of its own (same material and
 * time, the per-element materials and per-node thickness factors copied rather than re-derived from
 * maps and jitter), solved by one Cholesky factorization, and the tip's nodal stress (§5.7.1) read
 * from it. Nothing of the sub-model is kept. */
int fs_wedge_tip_submodel(fs_wedge_model *w, int32_t node, double radius, double size, double *ratio, double m[3],
                          fs_wedge_submodel_info *info)
{
    double t0 = fs_seconds();
    const fs_mesh *pm = w->mesh;
    fs_wedge_submodel_info inf = {0};
    *ratio = -INFINITY;
    int rc = -1;

    /* 1. the marked nodes and the elements touching them */
    int32_t *region = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *region);
    int32_t n_region = fs_wedge_relax_region(w, &node, 1, radius, region);
    uint8_t *marked = fs_calloc((size_t)w->n_nodes + 1, 1), *taken = fs_calloc((size_t)w->n_elems + 1, 1);
    int32_t *elems = fs_malloc(((size_t)w->n_elems + 1) * sizeof *elems), n_e = 0;
    for (int32_t q = 0; q < n_region; q++)
        marked[region[q]] = 1;
    for (int32_t q = 0; q < n_region; q++) {
        int32_t i = region[q];
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
            int32_t e = w->node_elem[p];
            if (w->state[e] == FS_WEDGE_ALIVE && !taken[e]) {
                taken[e] = 1;
                elems[n_e++] = e;
            }
        }
    }
    free(taken);
    free(region);
    fs_sort_int32(elems, n_e);
    inf.extracted_elems = n_e;

    /* 2. the copy: nodes in order of first use, and per node and per element what the model needs */
    int32_t *map = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *map);
    for (int32_t i = 0; i < w->n_nodes; i++)
        map[i] = -1;
    fs_mesh sm = {0};
    sm.domain = pm->domain;
    sm.n_tris = n_e;
    sm.tri = fs_malloc((3 * (size_t)n_e + 1) * sizeof *sm.tri);
    if (pm->shift)
        sm.shift = fs_malloc((6 * (size_t)n_e + 1) * sizeof *sm.shift);
    int32_t *pnode = fs_malloc((3 * (size_t)n_e + 1) * sizeof *pnode), nn = 0;
    for (int32_t q = 0; q < n_e; q++) {
        for (int c = 0; c < 3; c++) {
            int32_t i = pm->tri[3 * (size_t)elems[q] + c];
            if (map[i] < 0) {
                map[i] = nn;
                pnode[nn++] = i;
            }
            sm.tri[3 * (size_t)q + c] = map[i];
        }
        if (pm->shift)
            memcpy(sm.shift + 6 * (size_t)q, pm->shift + 6 * (size_t)elems[q], 6 * sizeof *sm.shift);
    }
    int32_t tip = map[node];
    free(map);
    sm.n_nodes = nn;
    sm.pos = fs_malloc((3 * (size_t)nn + 1) * sizeof *sm.pos);
    double *thick = fs_malloc(((size_t)nn + 1) * sizeof *thick);
    double *pre = fs_malloc((6 * (size_t)nn + 1) * sizeof *pre);
    uint8_t *pin = fs_malloc((size_t)nn + 1);
    for (int32_t k = 0; k < nn; k++) {
        int32_t i = pnode[k];
        memcpy(sm.pos + 3 * (size_t)k, pm->pos + 3 * (size_t)i, 3 * sizeof *sm.pos);
        thick[k] = w->thickness_factor[i];
        pin[k] = !marked[i] || w->pinned[i];
        memcpy(pre + 6 * (size_t)k, w->prescribed + 6 * (size_t)i, 3 * sizeof *pre);
        memcpy(pre + 6 * (size_t)k + 3, w->u + 6 * (size_t)i + 3, 3 * sizeof *pre); /* = prescribed if pinned */
    }
    free(pnode);
    free(marked);
    int32_t *origin = elems; /* the layer's element of each sub-model triangle */
    elems = NULL;
    fs_refine_change ch = {0};
    fs_wedge_model sub;
    bool have_sub = false;
    if (tip < 0 || n_e == 0) { /* no living element at node */
        rc = 0;
        goto done;
    }
    if (fs_mesh_build_adjacency(&sm) < 0)
        goto done;

    /* 3. refinement around the tip */
    {
        uint8_t *flag = fs_calloc((size_t)sm.n_tris + 1, 1);
        int32_t *list = fs_malloc(((size_t)sm.n_tris + 1) * sizeof *list);
        for (int pass = 0; pass < SUBMODEL_PASSES; pass++) {
            int32_t n = tip_vicinity(&sm, tip, size, flag, list);
            if (n == 0)
                break;
            if (fs_refine_bisect(&sm, list, n, size, &ch) < 0) {
                free(flag);
                free(list);
                goto done;
            }
            if (ch.n_bisections == 0)
                break;
            inf.bisections += ch.n_bisections;
            size_t nn2 = (size_t)sm.n_nodes + 1, nt2 = (size_t)sm.n_tris + 1;
            thick = fs_realloc(thick, nn2 * sizeof *thick);
            pre = fs_realloc(pre, 6 * nn2 * sizeof *pre);
            pin = fs_realloc(pin, nn2);
            origin = fs_realloc(origin, nt2 * sizeof *origin);
            flag = fs_realloc(flag, nt2);
            memset(flag, 0, nt2);
            list = fs_realloc(list, nt2 * sizeof *list);
            for (int32_t q = 0; q < ch.n_new_nodes; q++) {
                int32_t k = ch.n_nodes_before + q, a = ch.node_parent[2 * q], b = ch.node_parent[2 * q + 1];
                thick[k] = 0.5 * (thick[a] + thick[b]);
                pin[k] = pin[a] && pin[b];
                for (int l = 0; l < 6; l++)
                    pre[6 * (size_t)k + l] = 0.5 * (pre[6 * (size_t)a + l] + pre[6 * (size_t)b + l]);
            }
            for (int32_t q = 0; q < ch.n_new_tris; q++)
                origin[ch.n_tris_before + q] = origin[ch.tri_parent[q]];
        }
        free(flag);
        free(list);
    }
    for (int32_t t = 0; t < sm.n_tris; t++)
        if (fs_mesh_corner_of(&sm, t, tip) >= 0)
            inf.tip_size = fmax(inf.tip_size, fs_refine_tri_size(&sm, t));

    /* 4. the sub-model, assembled and factorized once its data are in */
    fs_model_setup c = w->cfg;
    c.thickness_map = c.young_map = c.threshold_map = (fs_grey_map){0};
    c.material.jitter = 0.0;
    c.wedge.thickness_gradient = 0.0;
    c.solver.method = FS_SOLVER_CHOLMOD;
    c.solver.relax = FS_RELAX_GLOBAL;
    c.fracture.tip_submodel = false;
    c.mesh.refine_vm = 0.0;
    c.mesh.smooth_radius = 0.0;
    if (fs_wedge_init_unassembled(&sub, &sm, &c) < 0)
        goto done;
    have_sub = true;
    memcpy(sub.thickness_factor, thick, (size_t)sm.n_nodes * sizeof *thick);
    memcpy(sub.prescribed, pre, 6 * (size_t)sm.n_nodes * sizeof *pre);
    for (int32_t t = 0; t < sm.n_tris; t++) {
        sub.young[t] = w->young[origin[t]];
        sub.threshold[t] = w->threshold[origin[t]];
    }
    if (fs_wedge_pin_top(&sub, pin) < 0 || fs_wedge_equilibrium(&sub, w->time) < 0)
        goto done;
    if (nodal_ratio(&sub, tip, ratio, m) < 0 || nodal_ratio(w, node, &inf.coarse_ratio, NULL) < 0)
        goto done;
    inf.nodes = sub.n_nodes;
    inf.elems = sub.n_elems;
    rc = 0;
done:
    if (have_sub)
        fs_wedge_free(&sub);
    fs_refine_change_free(&ch);
    fs_mesh_free(&sm);
    free(origin);
    free(thick);
    free(pre);
    free(pin);
    w->counters.submodels++;
    w->counters.submodel_elements += inf.elems;
    w->counters.submodel_seconds += fs_seconds() - t0;
    if (info)
        *info = inf;
    return rc;
}

/* ---- §5.7.9: angle-based smoothing near crack tips ---- */

/* Interior angle between 2-D vectors u and v, in [0, pi]. */
static double angle_2d(const double u[2], const double v[2])
{
    return atan2(fabs(u[0] * v[1] - u[1] * v[0]), u[0] * v[0] + u[1] * v[1]);
}

/* The fan of a node: for each living triangle (i, a, b) counter-clockwise, a and b relative to i in
 * the node's tangent frame. */
typedef struct {
    int32_t n, cap;
    int32_t *a, *b;
    double *ra, *rb; /* 2 each per triangle */
} fan_t;

static void fan_free(fan_t *f)
{
    free(f->a);
    free(f->b);
    free(f->ra);
    free(f->rb);
}

/* Fills the fan of node i; false if i is not fully surrounded by living elements (an element around it
 * removed, an edge at it on a crack wall or the border) or appears twice in a triangle. */
static bool fan_of(const fs_wedge_model *w, int32_t i, const fs_wedge_frame *f, fan_t *fan)
{
    const fs_mesh *m = w->mesh;
    fan->n = 0;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
        int32_t t = w->node_elem[p];
        if (w->state[t] != FS_WEDGE_ALIVE)
            return false;
        int c = fs_mesh_corner_of(m, t, i);
        const int32_t *tri = m->tri + 3 * (size_t)t;
        if (tri[(c + 1) % 3] == i || tri[(c + 2) % 3] == i)
            return false;
        for (int k = 0; k < 2; k++) { /* the edges at i: c (i -> a) and c + 2 (b -> i) */
            int32_t u = m->adj[3 * (size_t)t + (k ? (c + 2) % 3 : c)];
            if (u < 0 || w->state[u] != FS_WEDGE_ALIVE)
                return false;
        }
        if (FS_ARRAY_GROW(fan->cap, fan->n + 1, 16)) {
            FS_ARRAY_RESIZE(fan->a, fan->cap);
            FS_ARRAY_RESIZE(fan->b, fan->cap);
            FS_ARRAY_RESIZE(fan->ra, 2 * (size_t)fan->cap);
            FS_ARRAY_RESIZE(fan->rb, 2 * (size_t)fan->cap);
        }
        double pi[3], pa[3], pb[3], d[3];
        fs_mesh_corner(m, t, c, pi);
        fs_mesh_corner(m, t, (c + 1) % 3, pa);
        fs_mesh_corner(m, t, (c + 2) % 3, pb);
        int32_t k = fan->n++;
        fan->a[k] = tri[(c + 1) % 3];
        fan->b[k] = tri[(c + 2) % 3];
        fs_sub3(d, pa, pi);
        fan->ra[2 * k] = fs_dot3(f->e1, d), fan->ra[2 * k + 1] = fs_dot3(f->e2, d);
        fs_sub3(d, pb, pi);
        fan->rb[2 * k] = fs_dot3(f->e1, d), fan->rb[2 * k + 1] = fs_dot3(f->e2, d);
    }
    return fan->n >= 3;
}

/* The smallest angle of the fan's triangles with node i displaced by d (2-D), and whether every one
 * keeps a positive area. */
static double fan_min_angle(const fan_t *fan, const double d[2], bool *positive)
{
    double worst = INFINITY;
    *positive = true;
    for (int32_t k = 0; k < fan->n; k++) {
        double a[2] = {fan->ra[2 * k] - d[0], fan->ra[2 * k + 1] - d[1]};
        double b[2] = {fan->rb[2 * k] - d[0], fan->rb[2 * k + 1] - d[1]};
        if (!(a[0] * b[1] - a[1] * b[0] > 0.0))
            *positive = false;
        double ma[2] = {-a[0], -a[1]}, ab[2] = {b[0] - a[0], b[1] - a[1]}, ba[2] = {-ab[0], -ab[1]};
        double mb[2] = {-b[0], -b[1]};
        worst = fmin(worst, angle_2d(a, b));    /* at i */
        worst = fmin(worst, angle_2d(ab, ma));  /* at a */
        worst = fmin(worst, angle_2d(mb, ba));  /* at b */
    }
    return worst;
}

/* design: thesis §5.7.9, after Zhou and Shimada's angle-based smoothing (a system of torsion springs;
 * their paper is not among ours, so the update is derived here). Node i with neighbours j_1 .. j_k
 * counter-clockwise around it: at neighbour j, the edge j -> i splits the angle between j's edges to
 * its fan neighbours j_next and j_prev into alpha_next (inside triangle (i, j, j_next)) and
 * alpha_prev (inside (i, j_prev, j)). A torsion spring at j pulls the edge towards the bisector: its
 * energy (alpha_next - alpha_prev)^2 vanishes when the edge j -> i is rotated about j by
 * beta_j = (alpha_prev - alpha_next) / 2 (counter-clockwise rotation widens alpha_next and narrows
 * alpha_prev by the same angle), which takes i to P_j = x_j + R(beta_j) (x_i - x_j). With equal
 * spring constants and the small rotations of a smoothing step, the force balance of all k springs at
 * i is the mean of those positions, x_i <- (1/k) sum_j P_j, Zhou and Shimada's update. The move is done
 * in the node's tangent plane (thesis: nodes are kept on the surface; on the sphere they are then
 * projected back onto it) and is kept only if every triangle of the fan keeps a positive area and the
 * fan's smallest angle does not decrease ("smart" smoothing: the quality of the patch can only
 * improve; half and quarter steps are tried before the move is dropped); on a periodic domain a move
 * across a seam is refused (the corner shifts would change). Nodes are swept in ascending order
 * (Gauss-Seidel, deterministic). Only nodes fully surrounded by living elements move: crack walls,
 * tips, the border and pinned nodes stay, so cracks keep their geometry. A moved node keeps its
 * displacement (the starting guess of the relaxation) and its thickness factor, as an edge collapse
 * does. */
static bool smooth_node(fs_wedge_model *w, int32_t i, fan_t *fan)
{
    fs_mesh *m = w->mesh;
    fs_wedge_frame f;
    fs_wedge_frame_at(w, i, &f);
    if (!fan_of(w, i, &f, fan))
        return false;
    /* per neighbour: its relative position and the two angles at it beside the edge to i */
    double delta[2] = {0.0, 0.0};
    int32_t k_nb = 0;
    for (int32_t k = 0; k < fan->n; k++) {
        int32_t j = fan->a[k];
        const double *rj = fan->ra + 2 * k, *rn = fan->rb + 2 * k;
        int32_t prev = -1; /* the triangle (i, j_prev, j): j is its b */
        for (int32_t q = 0; q < fan->n && prev < 0; q++)
            if (fan->b[q] == j && fabs(fan->rb[2 * q] - rj[0]) + fabs(fan->rb[2 * q + 1] - rj[1]) <=
                                      1e-9 * (fabs(rj[0]) + fabs(rj[1])))
                prev = q;
        if (prev < 0)
            return false; /* not a closed fan */
        const double *rp = fan->ra + 2 * prev;
        double to_i[2] = {-rj[0], -rj[1]}, to_next[2] = {rn[0] - rj[0], rn[1] - rj[1]};
        double to_prev[2] = {rp[0] - rj[0], rp[1] - rj[1]};
        double beta = 0.5 * (angle_2d(to_i, to_prev) - angle_2d(to_next, to_i));
        double cb = cos(beta), sb = sin(beta);
        /* P_j - x_i = r_j + R(beta) (x_i - x_j) */
        delta[0] += rj[0] + cb * to_i[0] - sb * to_i[1];
        delta[1] += rj[1] + sb * to_i[0] + cb * to_i[1];
        k_nb++;
    }
    delta[0] /= k_nb;
    delta[1] /= k_nb;
    const double zero[2] = {0.0, 0.0};
    bool positive;
    double before = fan_min_angle(fan, zero, &positive);
    for (size_t s = 0; s < sizeof smooth_steps / sizeof smooth_steps[0]; s++) {
        double d[2] = {smooth_steps[s] * delta[0], smooth_steps[s] * delta[1]};
        if (!(fan_min_angle(fan, d, &positive) >= before) || !positive)
            continue;
        double moved[3], wrapped[3];
        const double *p = m->pos + 3 * (size_t)i;
        for (int k = 0; k < 3; k++)
            moved[k] = p[k] + d[0] * f.e1[k] + d[1] * f.e2[k];
        memcpy(wrapped, moved, sizeof wrapped);
        fs_domain_wrap(&m->domain, wrapped);
        if (w->flat && (wrapped[0] != moved[0] || wrapped[1] != moved[1]))
            return false; /* across a periodic seam */
        double old[3];
        memcpy(old, p, sizeof old);
        memcpy(m->pos + 3 * (size_t)i, wrapped, sizeof wrapped);
        if (!w->flat) { /* the projection onto the sphere moved it off the plane: check again */
            fs_domain_normal(&m->domain, wrapped, w->normal + 3 * (size_t)i);
            fs_wedge_frame g;
            fs_wedge_frame_at(w, i, &g);
            double after = fan_of(w, i, &g, fan) ? fan_min_angle(fan, zero, &positive) : -INFINITY;
            if (!(after >= before) || !positive) {
                memcpy(m->pos + 3 * (size_t)i, old, sizeof old);
                fs_domain_normal(&m->domain, old, w->normal + 3 * (size_t)i);
                fs_wedge_frame_at(w, i, &f);
                fan_of(w, i, &f, fan);
                continue;
            }
        }
        return true;
    }
    return false;
}

int fs_wedge_smooth(fs_wedge_model *w, const int32_t *centres, int32_t n, double radius, int iterations,
                    int32_t *moved)
{
    double t0 = fs_seconds();
    if (moved)
        *moved = 0;
    int32_t *region = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *region);
    int32_t n_region = fs_wedge_relax_region(w, centres, n, radius, region);
    uint8_t *skip = fs_calloc((size_t)w->n_nodes + 1, 1);
    for (int32_t k = 0; k < w->n_tips; k++)
        skip[w->tip_node[k]] = 1;
    int32_t n_cand = 0;
    for (int32_t q = 0; q < n_region; q++)
        if (!skip[region[q]] && !w->pinned[region[q]])
            region[n_cand++] = region[q];
    free(skip);
    fs_sort_int32(region, n_cand);
    uint8_t *was_moved = fs_calloc((size_t)w->n_nodes + 1, 1);
    fan_t fan = {0};
    for (int it = 0; it < iterations; it++) {
        bool any = false;
        for (int32_t q = 0; q < n_cand; q++)
            if (smooth_node(w, region[q], &fan)) {
                was_moved[region[q]] = 1;
                any = true;
            }
        if (!any)
            break;
    }
    fan_free(&fan);
    /* the moved nodes' elements changed geometry: rebuild them in the system */
    uint8_t *flag = fs_calloc((size_t)w->n_elems + 1, 1);
    int32_t n_moved = 0, n_changed = 0;
    for (int32_t q = 0; q < n_cand; q++) {
        int32_t i = region[q];
        if (!was_moved[i])
            continue;
        n_moved++;
        fs_wedge_node_moved(w, i);
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
            flag[w->node_elem[p]] = 1;
    }
    int32_t *changed = fs_malloc(((size_t)w->n_elems + 1) * sizeof *changed);
    for (int32_t e = 0; e < w->n_elems; e++)
        if (flag[e])
            changed[n_changed++] = e;
    free(flag);
    free(was_moved);
    free(region);
    int rc = 0;
    if (n_changed > 0)
        rc = fs_wedge_update_geometry(w, changed, n_changed);
    free(changed);
    w->counters.smoothings++;
    w->counters.smoothed_nodes += n_moved;
    w->counters.smooth_seconds += fs_seconds() - t0;
    if (moved)
        *moved = n_moved;
    return rc;
}
