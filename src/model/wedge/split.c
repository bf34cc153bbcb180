/* The wedge model's fracture by element splitting (thesis §5.7): nodal criterion, node duplication, element cutting, crack tips, edge collapse, Griffith termination. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/imap.h"
#include "base/uf.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "fracture/rank.h"
#include "fracture/separation.h"
#include "fracture/split.h"
#include "geom/cut.h"
#include "geom/refine.h"
#include "model/wedge/internal.h"
#include "model/wedge/frame.h"

/* design: thesis §5.7. The layer is a surface mesh extruded into wedge columns, and a crack always
 * cuts a whole column (the top and the bottom node of a mesh node together), so splitting is a 2-D
 * operation on the surface mesh, done in the tangent plane of the breaking node n (the unwrapped
 * flat frame on the plane and cylinder, with the periodic corner shifts; the plane through n normal
 * to the sphere on the sphere).
 *
 * Criterion (§5.7.1): the nodal stress of n's top node (the average of its elements' top Gauss point
 * nearest n) against the mean threshold of those elements. The crack line is normal to the largest
 * principal direction projected onto the tangent plane.
 *
 * Cut (Algorithms 10 and 12): a new crack sends two opposite rays from n, a tip one ray, the one that
 * continues its crack. The ray leaves the fan of n through the far edge ab of one sector (n, a, b)
 * (fs_split_ray_sector); the sector and its neighbour across ab are split at the crossing p, so the
 * mesh stays conforming. When p falls within SNAP of a or b, that node is moved onto the crack line if
 * it is free (edge collapse, Algorithm 12: interior, not on a crack, not a tip, not pinned, every
 * element around it stays well shaped and it does not cross a periodic seam); otherwise the ray is
 * snapped through it. Then every node on a cut whose fan the cuts disconnect (n itself, and a far end
 * lying on a crack wall or the boundary) is duplicated: each further connected sector of its fan gets
 * a copy, at the same position. Crack edges are thus simply boundary edges of the mesh, cracks that
 * reach an existing crack end in a T-junction, and a far end whose fan stays connected becomes a tip.
 * Elements are never removed: fragments separate because they no longer share nodes.
 *
 * Tips: averaged over the elements around a tip, the nodal stress mixes the loaded element ahead of
 * the crack with the unloaded walls behind it and misses the stress concentration that the thesis
 * resolves with a temporary finer mesh at the tip (§5.7.8); this model takes instead, at a tip, the
 * largest ratio (and its direction) among the top Gauss points nearest the tip, one per element: the
 * coarse estimate. With fracture.tip_submodel the thesis's sub-model (wedge/tips.c) decides for the
 * tip about to extend, and calibrates that tip's estimate (see tip_submodel_check).
 *
 * Order (Fig. 5.20): tips first (largest ratio over 1 among tips), new cracks only when no tip is
 * over its threshold; new cracks start only at nodes off every crack and boundary (interior nodes).
 *
 * Griffith (§5.7.4, Algorithm 11), for tip extensions when fracture.griffith is set: the elastic
 * energy before (e1) and after (e2, at the new equilibrium) the extension, G = (e1 - e2) / a with a
 * the new wall area (cut length times the local thickness). If G <= Gc (material.toughness) the
 * crack is terminated: as in Algorithm 11 the extension that was measured stays, and its new tip is
 * retired, so the crack cannot run further and no energy is created by undoing. The energies are
 * summed over the elements within GRIFFITH_RINGS edge rings of n (the same material before and
 * after: split elements keep their slot or name it as parent), not over the whole layer; the
 * release of a short extension is concentrated there, and it keeps the check's cost independent of
 * the layer's size, at the price of slightly underestimating G.
 *
 * Subdivision around tips (§5.7.6): before a node breaks, the elements of its one-ring and their
 * neighbours that are not yet below mesh.min_size are bisected (fs_wedge_subdivide) and the event
 * ends there; the model relaxes and the criterion is evaluated again on the finer mesh.
 *
 * Smoothing (§5.7.9, mesh.smooth_radius): after a cut, the free nodes around the new tips are moved
 * by angle-based smoothing (fs_wedge_smooth, wedge/tips.c) before the model relaxes.
 *
 * The global system after a cut is updated in place for the changed elements (fs_wedge_apply_change)
 * and re-factorized; duplicated and new nodes start from the displacement of the nodes they came
 * from. */

/* Fraction of an edge within which a cut snaps to (or collapses) its end node. */
#define SNAP 0.2
/* An edge collapse is refused if an element around the moved node would keep less than this
 * fraction of its area. */
#define COLLAPSE_MIN_AREA 0.25
/* Edge rings around the breaking node whose elements the Griffith energies are summed over. */
#define GRIFFITH_RINGS 6

/* ---- the nodal criterion ---- */

/* The top stresses the criterion reads: a, or the blend a + s (b - a) when b is not NULL. */
typedef struct {
    const double *a, *b;
    double s;
} stresses;

/* Voigt stress at top Gauss point c of element e. */
static void stress_at(const stresses *st, int32_t e, int c, double out[6])
{
    const double *a = st->a + 18 * (size_t)e + 6 * c;
    if (!st->b) {
        memcpy(out, a, 6 * sizeof *out);
        return;
    }
    const double *b = st->b + 18 * (size_t)e + 6 * c;
    for (int k = 0; k < 6; k++)
        out[k] = a[k] + st->s * (b[k] - a[k]);
}

/* Ratio of the top Gauss point of element e nearest corner c, and its principal direction. */
static double point_ratio(const fs_wedge_model *w, const stresses *st, int32_t e, int c, double m[3])
{
    double sigma1, v[6];
    stress_at(st, e, c, v);
    if (fs_nodal_principal_plane(v, &sigma1, m) < 0) {
        fs_error_clear();
        return -INFINITY;
    }
    return sigma1 / w->threshold[e];
}

/* Ratio at crack tip i: the largest over its elements of the ratio at the top Gauss point nearest the
 * tip, and that point's principal direction (see the design note). */
static double tip_ratio_of(const fs_wedge_model *w, const stresses *st, int32_t i, double m[3])
{
    double best = -INFINITY;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
        int32_t e = w->node_elem[p];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        int c = fs_mesh_corner_of(w->mesh, e, i);
        double d[3];
        double r = point_ratio(w, st, e, c, d);
        if (r > best) {
            best = r;
            if (m)
                memcpy(m, d, sizeof d);
        }
    }
    return best;
}

/* The mean of the stresses at the top Gauss points nearest node i over its living elements (top point
 * c is the one nearest corner c, wedge_element.h) and the mean of their thresholds; false for a node
 * without a living element. */
static bool node_mean_stress(const fs_wedge_model *w, const stresses *st, int32_t i, double s[6], double *thr)
{
    fs_nodal_stress mean = {{0.0}, 0};
    double sum = 0.0;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
        int32_t e = w->node_elem[p];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        int c = fs_mesh_corner_of(w->mesh, e, i);
        double v[6];
        stress_at(st, e, c, v);
        fs_nodal_stress_add(&mean, v);
        sum += w->threshold[e];
    }
    if (!fs_nodal_stress_mean(&mean, s))
        return false;
    *thr = sum / mean.count;
    return true;
}

/* Nodal ratio of node i (thesis §5.7.1), and the fracture plane normal (3-D, unit) if m is not NULL.
 * The stresses are those the last equilibrium left in stress_top (or a blend, st). -inf for a node
 * without a living element or with a non-finite stress. */
static double node_ratio_of(const fs_wedge_model *w, const stresses *st, int32_t i, double m[3])
{
    double s[6], thr, sigma1;
    if (!node_mean_stress(w, st, i, s, &thr))
        return -INFINITY;
    if (fs_nodal_principal_plane(s, &sigma1, m) < 0) {
        fs_error_clear();
        return -INFINITY;
    }
    return sigma1 / thr;
}

/* An upper bound of node_ratio_of(w, st, i, NULL), tight where it exceeds level (see
 * fs_eigen_principal_bound; the division by the same positive mean threshold keeps the order). NaN
 * where only the exact ratio will do: a stress that is not finite, a threshold that is not positive. */
static double node_bound_of(const fs_wedge_model *w, const stresses *st, int32_t i, double level)
{
    double s[6], thr;
    if (!node_mean_stress(w, st, i, s, &thr))
        return -INFINITY;
    if (!(thr > 0.0))
        return NAN;
    double b = fs_eigen_principal_bound(s, level * thr) / thr;
    return isfinite(b) ? b : NAN;
}

static double tip_ratio(const fs_wedge_model *w, int32_t i, double m[3])
{
    const stresses st = {w->stress_top, NULL, 0.0};
    return tip_ratio_of(w, &st, i, m);
}

static double node_ratio(const fs_wedge_model *w, int32_t i, double m[3])
{
    const stresses st = {w->stress_top, NULL, 0.0};
    return node_ratio_of(w, &st, i, m);
}

/* node_ratio without the direction, from the cache w->node_ratio where it holds the exact value. */
static double cached_node_ratio(fs_wedge_model *w, int32_t i)
{
    if (isnan(w->node_ratio[i]) || !w->node_ratio_exact[i]) {
        double r = node_ratio(w, i, NULL);
        w->node_ratio[i] = isnan(r) ? -INFINITY : r;
        w->node_ratio_exact[i] = 1;
    }
    return w->node_ratio[i];
}

/* An upper bound of node i's ratio from the cache (exact or a bound), else computed and cached, tight
 * where it exceeds level. NaN if only the exact ratio will do (node_bound_of). */
static double cached_node_bound(fs_wedge_model *w, int32_t i, double level)
{
    if (isnan(w->node_ratio[i])) {
        const stresses st = {w->stress_top, NULL, 0.0};
        double b = node_bound_of(w, &st, i, level);
        if (isnan(b))
            return NAN;
        w->node_ratio[i] = b;
        w->node_ratio_exact[i] = 0;
    }
    return w->node_ratio[i];
}

/* Whether node i lies on a boundary edge of the mesh, from its element list (every triangle using
 * it, node_elem). */
static uint8_t node_open(const fs_wedge_model *w, int32_t i)
{
    const fs_mesh *m = w->mesh;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
        int32_t t = w->node_elem[p], c = fs_mesh_corner_of(m, t, i);
        /* the two edges at corner c: c to c + 1 (edge c) and c - 1 to c (edge c - 1) */
        if (m->adj[3 * (size_t)t + c] < 0 || m->adj[3 * (size_t)t + (c + 2) % 3] < 0)
            return 1;
    }
    return 0;
}

/* w->open, brought up to date: open[i] = 1 for a node on a boundary edge of the mesh (a crack wall, a
 * tip or the domain's border). The flags stay valid until the mesh changes: fs_wedge_apply_change
 * brings them up to its change (fs_wedge_open_update), anything else (fs_wedge_subdivide) clears
 * them, and the next call makes one pass over the mesh. */
static const uint8_t *open_nodes(fs_wedge_model *w)
{
    const fs_mesh *m = w->mesh;
    if (!w->open_valid) {
        FS_ASSERT(m->n_nodes == w->n_nodes); /* w->open has the per-node arrays' room */
        memset(w->open, 0, (size_t)m->n_nodes + 1);
        for (int32_t h = 0; h < 3 * m->n_tris; h++)
            if (m->adj[h] < 0) {
                w->open[m->tri[h]] = 1;
                w->open[m->tri[3 * (h / 3) + (h % 3 + 1) % 3]] = 1;
            }
        w->open_valid = true;
    }
    return w->open;
}

void fs_wedge_open_update(fs_wedge_model *w, const int32_t *nodes, int32_t n)
{
    if (!w->open_valid)
        return;
    for (int32_t q = 0; q < n; q++)
        w->open[nodes[q]] = node_open(w, nodes[q]);
#ifdef FS_VALIDATE
    for (int32_t i = 0; i < w->n_nodes; i++)
        FS_INVARIANT(w->open[i] == node_open(w, i), "wedge: node %d's open flag is stale after a change", (int)i);
#endif
}

/* design: the nodal ratios are wanted only where they could be the largest (the event search) or over
 * 1 (the pick of an event), so the Jacobi decomposition runs only where a cheap bound (about a sixth
 * of its cost, fs_eigen_principal_bound) does not settle the question; the cache keeps the bound, and
 * a blend between snapshots turns a bound into the exact ratio at that snapshot only where its answer
 * depends on it. Every answer is the one the exact ratios everywhere would give, bit for bit. */
double fs_wedge_split_max_ratio(fs_wedge_model *w)
{
    double best = -INFINITY;
    for (int32_t k = 0; k < w->n_tips; k++)
        best = fmax(best, tip_ratio(w, w->tip_node[k], NULL) * w->tip_scale[k]);
    const uint8_t *open = open_nodes(w);
    for (int32_t i = 0; i < w->n_nodes; i++)
        if (!open[i] && w->node_ratio_exact[i] && !isnan(w->node_ratio[i]))
            best = fmax(best, w->node_ratio[i]);
    for (int32_t i = 0; i < w->n_nodes; i++)
        if (!open[i] && !(cached_node_bound(w, i, best) <= best))
            best = fmax(best, cached_node_ratio(w, i));
    return best;
}

/* The exact ratio of node i in snapshot s (same mesh as w), as cached_node_ratio would have cached
 * it: from the snapshot's cache where that holds it, else from the snapshot's stresses. */
static double snapshot_ratio(const fs_wedge_model *w, const fs_wedge_snapshot *s, int32_t i)
{
    if (s->node_ratio_exact[i] && !isnan(s->node_ratio[i]))
        return s->node_ratio[i];
    const stresses st = {s->stress_top, NULL, 0.0};
    double r = node_ratio_of(w, &st, i, NULL);
    return isnan(r) ? -INFINITY : r;
}

/* The larger of node i's exact ratios in a and b. */
static double end_ratio(const fs_wedge_model *w, const fs_wedge_snapshot *a, const fs_wedge_snapshot *b, int32_t i)
{
    return fmax(snapshot_ratio(w, a, i), snapshot_ratio(w, b, i));
}

/* An upper bound of end_ratio from the snapshots' caches, NaN where either holds nothing. */
static double end_bound(const fs_wedge_snapshot *a, const fs_wedge_snapshot *b, int32_t i)
{
    double ua = a->node_ratio[i], ub = b->node_ratio[i];
    return isnan(ua) || isnan(ub) ? NAN : fmax(ua, ub);
}

double fs_wedge_split_blend_ratio(fs_wedge_model *w, const fs_wedge_snapshot *a, const fs_wedge_snapshot *b,
                                  double t)
{
    FS_ASSERT(a->n_nodes == w->n_nodes && b->n_nodes == w->n_nodes && a->n_elems == w->n_elems &&
              b->n_elems == w->n_elems);
    double span = b->time - a->time;
    const stresses st = {a->stress_top, b->stress_top, span > 0.0 ? (t - a->time) / span : 1.0};
    double best = -INFINITY, bound = -INFINITY;
    for (int32_t k = 0; k < w->n_tips; k++)
        best = fmax(best, tip_ratio_of(w, &st, w->tip_node[k], NULL) * w->tip_scale[k]);
    const uint8_t *open = open_nodes(w);
    /* nodes whose end ratios are at most 1 by their bounds: they can only raise `bound`, which
     * matters only if nothing is over 1 */
    int32_t *later = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *later), n_later = 0;
    for (int32_t i = 0; i < w->n_nodes; i++) {
        if (open[i])
            continue;
        if (end_bound(a, b, i) <= 1.0) {
            later[n_later++] = i;
            continue;
        }
        double end = end_ratio(w, a, b, i);
        if (end > 1.0)
            best = fmax(best, node_ratio_of(w, &st, i, NULL));
        else
            bound = fmax(bound, end);
    }
    for (int32_t q = 0; q < n_later && !(best > 1.0); q++)
        if (end_bound(a, b, later[q]) > bound)
            bound = fmax(bound, end_ratio(w, a, b, later[q]));
    free(later);
    return best > 1.0 ? best : fmax(best, bound);
}

/* ---- tips ---- */

static int32_t tip_find(const fs_wedge_model *w, int32_t node)
{
    for (int32_t k = 0; k < w->n_tips; k++)
        if (w->tip_node[k] == node)
            return k;
    return -1;
}

static void tip_remove(fs_wedge_model *w, int32_t node)
{
    int32_t k = tip_find(w, node);
    if (k < 0)
        return;
    w->n_tips--;
    memmove(w->tip_node + k, w->tip_node + k + 1, (size_t)(w->n_tips - k) * sizeof *w->tip_node);
    memmove(w->tip_dir + 3 * k, w->tip_dir + 3 * (k + 1), 3 * (size_t)(w->n_tips - k) * sizeof *w->tip_dir);
    memmove(w->tip_scale + k, w->tip_scale + k + 1, (size_t)(w->n_tips - k) * sizeof *w->tip_scale);
}

static void tip_add(fs_wedge_model *w, int32_t node, const double dir[3])
{
    if (tip_find(w, node) >= 0)
        return;
    if (FS_ARRAY_GROW(w->cap_tips, w->n_tips + 1, 16)) {
        FS_ARRAY_RESIZE(w->tip_node, w->cap_tips);
        FS_ARRAY_RESIZE(w->tip_dir, 3 * (size_t)w->cap_tips);
        FS_ARRAY_RESIZE(w->tip_scale, w->cap_tips);
    }
    w->tip_node[w->n_tips] = node;
    w->tip_scale[w->n_tips] = 1.0;
    memcpy(w->tip_dir + 3 * (size_t)w->n_tips, dir, 3 * sizeof *dir);
    w->n_tips++;
}

/* ---- growing lists ---- */

typedef struct {
    int32_t *v;
    int32_t n, cap;
} ilist;

static void ilist_push(ilist *l, int32_t x)
{
    FS_ARRAY_RESERVE(l->v, l->cap, l->n + 1, 16);
    l->v[l->n++] = x;
}

/* Adds x to the set (the keys of m); true if it was not in it. */
static bool set_insert(fs_imap *m, int32_t x)
{
    bool found;
    fs_imap_get(m, (uint64_t)x, 0, &found);
    return !found;
}

/* ---- the cut (the mesh surgery itself is geom/cut.h's) ---- */

/* One cut: the mesh surgery's record, and the model it changes. */
typedef struct {
    fs_cut cut;
    fs_wedge_model *w;
} cut_state;

/* fs_cut_tris_fn of the wedge model: the living elements at node i in the mesh as the cut has changed
 * it so far, from node_elem and the cut's changed and new triangles (fs_wedge_elems_at). */
static int32_t wedge_tris_at(void *ctx, const fs_cut *cut, int32_t i, int32_t **out, int32_t *cap)
{
    const fs_wedge_model *w = ctx;
    int32_t room = (i < w->n_nodes ? w->node_elem_count[i] : 0) + cut->n_changed + (w->mesh->n_tris - cut->n_tris_before);
    FS_ARRAY_RESERVE(*out, *cap, room, 16);
    return fs_wedge_elems_at(w, i, cut->changed_list, cut->n_changed, cut->n_tris_before, true, *out);
}

/* Living triangles that have node i as a corner, ascending, in the mesh as the cut has changed it so
 * far, into the list out. */
static void tris_at(const cut_state *cs, int32_t i, ilist *out)
{
    out->n = fs_cut_tris_at(&cs->cut, i, &out->v, &out->cap);
}

/* Corner c of triangle t relative to corner cn, in the 2-D frame. */
static void rel_2d(const fs_mesh *m, const fs_wedge_frame *f, int32_t t, int cn, int c, double out[2])
{
    double a[3], b[3], d[3];
    fs_mesh_corner(m, t, cn, a);
    fs_mesh_corner(m, t, c, b);
    fs_sub3(d, b, a);
    fs_wedge_frame_to_2d(f, d, out);
}

/* Twice the signed area of triangle t projected into frame f. */
static double area_2d(const fs_mesh *m, const fs_wedge_frame *f, int32_t t)
{
    double a[2], b[2];
    rel_2d(m, f, t, 0, 1, a);
    rel_2d(m, f, t, 0, 2, b);
    return a[0] * b[1] - a[1] * b[0];
}

/* Edge collapse (Algorithm 12): moves free node v by delta (2-D, frame f) if every triangle around
 * it keeps COLLAPSE_MIN_AREA of its area and the node stays inside the fundamental domain.
 * Returns true if it moved. */
static bool collapse(cut_state *cs, const fs_wedge_frame *f, int32_t v, const double delta[2], const uint8_t *open)
{
    fs_wedge_model *w = cs->w;
    fs_mesh *m = w->mesh;
    if (v < w->n_nodes && (open[v] || w->pinned[v] || tip_find(w, v) >= 0))
        return false;
    double d3[3], old[3], moved[3], wrapped[3];
    fs_wedge_frame_from_2d(f, delta, d3);
    memcpy(old, m->pos + 3 * (size_t)v, sizeof old);
    for (int k = 0; k < 3; k++)
        moved[k] = old[k] + d3[k];
    memcpy(wrapped, moved, sizeof wrapped);
    fs_domain_wrap(&m->domain, wrapped);
    if (w->flat && (wrapped[0] != moved[0] || wrapped[1] != moved[1]))
        return false;
    ilist ring = {0};
    tris_at(cs, v, &ring);
    double *before = fs_malloc(((size_t)ring.n + 1) * sizeof *before);
    for (int32_t q = 0; q < ring.n; q++)
        before[q] = area_2d(m, f, ring.v[q]);
    memcpy(m->pos + 3 * (size_t)v, wrapped, sizeof wrapped);
    bool ok = true;
    for (int32_t q = 0; q < ring.n && ok; q++)
        ok = area_2d(m, f, ring.v[q]) > COLLAPSE_MIN_AREA * before[q];
    if (!ok) {
        memcpy(m->pos + 3 * (size_t)v, old, sizeof old);
    } else {
        fs_wedge_node_moved(w, v);
        for (int32_t q = 0; q < ring.n; q++)
            fs_cut_mark_changed(&cs->cut, ring.v[q]);
    }
    free(before);
    free(ring.v);
    return ok;
}

/* One ray from n along d (2-D, frame f): splits or snaps, returns the far end of the cut (-1 when the
 * ray leaves through a gap of the fan: nothing cut). */
static int32_t cast_ray(cut_state *cs, const fs_wedge_frame *f, int32_t n, const double d[2], const uint8_t *open)
{
    fs_wedge_model *w = cs->w;
    fs_mesh *m = w->mesh;
    ilist fan = {0};
    tris_at(cs, n, &fan);
    int32_t far = -1;
    for (int32_t q = 0; q < fan.n && far < 0; q++) {
        int32_t t = fan.v[q];
        int cn = fs_mesh_corner_of(m, t, n), ia = (cn + 1) % 3, ib = (cn + 2) % 3;
        double a[2], b[2], s;
        rel_2d(m, f, t, cn, ia, a);
        rel_2d(m, f, t, cn, ib, b);
        fs_split_hit hit = fs_split_ray_sector(a, b, d, SNAP, &s);
        if (hit == FS_SPLIT_MISS)
            continue;
        if (hit == FS_SPLIT_EDGE) {
            far = fs_cut_split_edge(&cs->cut, t, ia, s);
            break;
        }
        int c = hit == FS_SPLIT_AT_A ? ia : ib;
        const double *pv = hit == FS_SPLIT_AT_A ? a : b;
        far = m->tri[3 * (size_t)t + c];
        double on_line[2], delta[2];
        fs_split_project_onto_line(pv, d, on_line);
        delta[0] = on_line[0] - pv[0];
        delta[1] = on_line[1] - pv[1];
        collapse(cs, f, far, delta, open);
    }
    free(fan.v);
    return far;
}

/* Elements within GRIFFITH_RINGS edge rings of node n (before a cut), ascending. */
static void griffith_region(const fs_wedge_model *w, int32_t n, ilist *out)
{
    uint8_t *seen_node = fs_calloc((size_t)w->n_nodes, 1), *seen_elem = fs_calloc((size_t)w->n_elems, 1);
    ilist front = {0}, next = {0};
    ilist_push(&front, n);
    seen_node[n] = 1;
    for (int ring = 0; ring < GRIFFITH_RINGS; ring++) {
        next.n = 0;
        for (int32_t q = 0; q < front.n; q++) {
            int32_t i = front.v[q];
            for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++) {
                int32_t e = w->node_elem[p];
                seen_elem[e] = 1;
                for (int c = 0; c < 3; c++) {
                    int32_t j = w->mesh->tri[3 * (size_t)e + c];
                    if (!seen_node[j]) {
                        seen_node[j] = 1;
                        ilist_push(&next, j);
                    }
                }
            }
        }
        ilist tmp = front;
        front = next;
        next = tmp;
    }
    out->n = 0;
    for (int32_t e = 0; e < w->n_elems; e++)
        if (seen_elem[e])
            ilist_push(out, e);
    free(front.v);
    free(next.v);
    free(seen_node);
    free(seen_elem);
}

static double region_energy(fs_wedge_model *w, const ilist *region, int32_t first_new)
{
    double e = 0.0;
    for (int32_t q = 0; q < region->n; q++)
        e += fs_wedge_element_energy(w, region->v[q]);
    for (int32_t t = first_new; t < w->n_elems; t++)
        e += fs_wedge_element_energy(w, t);
    return e;
}

/* Bisects the one-ring of n and its neighbours down to mesh.min_size (§5.7.6). *bisected > 0 if the
 * mesh changed. */
static int subdivide_around(fs_wedge_model *w, int32_t n, int32_t *bisected)
{
    ilist list = {0};
    const fs_mesh *m = w->mesh;
    for (int32_t p = w->node_elem_start[n]; p < w->node_elem_start[n] + w->node_elem_count[n]; p++) {
        int32_t e = w->node_elem[p];
        for (int k = -1; k < 3; k++) {
            int32_t t = k < 0 ? e : m->adj[3 * (size_t)e + k];
            if (t >= 0 && w->state[t] == FS_WEDGE_ALIVE && fs_refine_tri_size(m, t) >= w->cfg.mesh.min_size)
                ilist_push(&list, t);
        }
    }
    *bisected = 0;
    int rc = list.n ? fs_wedge_subdivide(w, list.v, list.n, true, bisected) : 0;
    free(list.v);
    return rc;
}

/* Cuts the mesh at n along the rays (3-D unit directions), updates the mesh structures, the model and
 * the tips. ends receives the far ends of the cuts (-1 for a ray that cut nothing), lengths their
 * lengths (cm). Returns the number of cuts made, or -1. */
static int cut_at_node(fs_wedge_model *w, int32_t n, const double (*rays)[3], int n_rays, int32_t ends[2],
                       double lengths[2])
{
    fs_mesh *m = w->mesh;
    fs_wedge_frame f;
    fs_wedge_frame_at(w, n, &f);
    const uint8_t *open = open_nodes(w);
    cut_state cs = {.w = w};
    fs_cut_begin(&cs.cut, m, wedge_tris_at, w);
    int cuts = 0;
    for (int r = 0; r < n_rays; r++) {
        double d[2];
        fs_wedge_frame_to_2d(&f, rays[r], d);
        double len = hypot(d[0], d[1]);
        ends[r] = -1;
        lengths[r] = 0.0;
        if (!(len > 0.0))
            continue;
        d[0] /= len;
        d[1] /= len;
        if (r > 0 && fs_cut_update_adjacency(&cs.cut) < 0)
            goto fail;
        int32_t far = cast_ray(&cs, &f, n, d, open);
        if (far < 0 || far == n)
            continue;
        ends[r] = far;
        double pn[3], pf[3], diff[3];
        memcpy(pn, m->pos + 3 * (size_t)n, sizeof pn);
        memcpy(pf, m->pos + 3 * (size_t)far, sizeof pf);
        fs_domain_delta(&m->domain, pn, pf, diff);
        lengths[r] = fs_norm3(diff);
        cuts++;
    }
    if (cuts == 0) {
        fs_cut_free(&cs.cut);
        return 0;
    }
    if (fs_cut_update_adjacency(&cs.cut) < 0)
        goto fail;
    int32_t cut_ends[2], n_cut = 0;
    for (int r = 0; r < n_rays; r++)
        if (ends[r] >= 0)
            cut_ends[n_cut++] = ends[r];
    /* far ends first: once a far end is split, the two sides of its cut no longer share an edge */
    int32_t sectors_far[2] = {1, 1};
    for (int r = 0; r < n_rays; r++)
        if (ends[r] >= 0) {
            sectors_far[r] = fs_cut_duplicate_node(&cs.cut, ends[r], &n, 1);
            if (sectors_far[r] > 1 && fs_cut_update_adjacency(&cs.cut) < 0)
                goto fail;
        }
    fs_cut_duplicate_node(&cs.cut, n, cut_ends, n_cut);
    if (fs_cut_update_adjacency(&cs.cut) < 0)
        goto fail;
    if (m->n_nodes == cs.cut.n_nodes_before && m->n_tris == cs.cut.n_tris_before)
        cuts = 0; /* the cut ran along an existing crack: nothing separated (geometry may have moved) */
    fs_mesh_drop_derived(m); /* the wedge model uses neither edges nor rings */

    int32_t *changed = fs_cut_changed_ascending(&cs.cut);
    fs_wedge_change ch = {cs.cut.n_nodes_before, cs.cut.n_tris_before, cs.cut.node_parent, cs.cut.node_weight,
                          cs.cut.tri_parent, changed, cs.cut.n_changed};
    bool end_open[2] = {false, false}; /* before the cut: the change makes the flags stale */
    for (int r = 0; r < n_rays; r++)
        end_open[r] = ends[r] >= 0 && ends[r] < cs.cut.n_nodes_before && open[ends[r]];
    int rc = fs_wedge_apply_change(w, &ch);
    free(changed);
    tip_remove(w, n);
    for (int r = 0; r < n_rays && cuts > 0; r++) {
        if (ends[r] < 0)
            continue;
        if (sectors_far[r] > 1 || end_open[r])
            tip_remove(w, ends[r]);
        if (sectors_far[r] == 1)
            tip_add(w, ends[r], rays[r]);
    }
    fs_cut_free(&cs.cut);
    return rc < 0 ? -1 : cuts;
fail:
    w->open_valid = false;
    fs_cut_free(&cs.cut);
    return -1;
}

/* Angle-based smoothing (§5.7.9, fs_wedge_smooth) around the tips the cut made (the far ends that
 * are still tips), when mesh.smooth_radius is set. Returns 0 or -1. */
static int smooth_new_tips(fs_wedge_model *w, const int32_t ends[2], int n_rays)
{
    if (!(w->cfg.mesh.smooth_radius > 0.0))
        return 0;
    int32_t centres[2], n = 0;
    for (int r = 0; r < n_rays; r++)
        if (ends[r] >= 0 && tip_find(w, ends[r]) >= 0)
            centres[n++] = ends[r];
    if (n == 0)
        return 0;
    double radius = w->cfg.mesh.smooth_radius * fs_wedge_tips_unit(w);
    return fs_wedge_smooth(w, centres, n, radius, w->cfg.mesh.smooth_iterations, NULL);
}

/* The fracture plane normal m (3-D, unit) that steers tip node i, whose crack arrived along ahead:
 * the principal plane of the stress averaged ahead of it (fs_tip_stress) over the top Gauss points
 * of the living elements that the unbroken material connects to i within 3 radii. m is left as it is
 * (the tip's most loaded element's plane) when the average pulls on no plane or direction_radius is
 * 0. */
static void tip_average_plane(fs_wedge_model *w, int32_t i, const double ahead[3], double m[3])
{
    if (!(w->cfg.fracture.direction_radius > 0.0))
        return;
    fs_mesh *mesh = w->mesh;
    double radius = w->cfg.fracture.direction_radius * fs_wedge_tips_unit(w);
    const double *tip = mesh->pos + 3 * (size_t)i;
    ilist nodes = {0}, elems = {0};
    fs_imap node_set, elem_set;
    fs_imap_init(&node_set, 64);
    fs_imap_init(&elem_set, 64);
    ilist_push(&nodes, i);
    set_insert(&node_set, i);
    for (int32_t q = 0; q < nodes.n; q++) {
        int32_t v = nodes.v[q];
        for (int32_t p = w->node_elem_start[v]; p < w->node_elem_start[v] + w->node_elem_count[v]; p++) {
            int32_t e = w->node_elem[p];
            if (w->state[e] != FS_WEDGE_ALIVE || !set_insert(&elem_set, e))
                continue;
            ilist_push(&elems, e);
            for (int c = 0; c < 3; c++) {
                int32_t j = mesh->tri[3 * (size_t)e + c];
                double d[3];
                fs_domain_delta(&mesh->domain, tip, mesh->pos + 3 * (size_t)j, d);
                if (fs_norm3(d) <= 3.0 * radius && set_insert(&node_set, j))
                    ilist_push(&nodes, j);
            }
        }
    }
    fs_imap_free(&node_set);
    fs_imap_free(&elem_set);
    const stresses st = {w->stress_top, NULL, 0.0};
    fs_tip_stress avg;
    fs_tip_stress_begin(&avg, ahead, w->normal + 3 * (size_t)i, radius);
    for (int32_t q = 0; q < elems.n; q++) {
        int32_t e = elems.v[q];
        double rel[3][3];
        for (int c = 0; c < 3; c++)
            fs_domain_delta(&mesh->domain, tip, mesh->pos + 3 * (size_t)mesh->tri[3 * (size_t)e + c], rel[c]);
        double ab[3], ac[3], n[3];
        fs_sub3(ab, rel[1], rel[0]);
        fs_sub3(ac, rel[2], rel[0]);
        fs_cross3(n, ab, ac);
        double third = fs_norm3(n) / 6.0;
        for (int c = 0; c < 3; c++) {
            /* top Gauss point c sits at (2/3, 1/6, 1/6) of the triangle from corner c */
            double at[3], s[6];
            for (int k = 0; k < 3; k++)
                at[k] = (4.0 * rel[c][k] + rel[(c + 1) % 3][k] + rel[(c + 2) % 3][k]) / 6.0;
            stress_at(&st, e, c, s);
            fs_tip_stress_add(&avg, at, w->normal + 3 * (size_t)mesh->tri[3 * (size_t)e + c], third, s);
        }
    }
    free(nodes.v);
    free(elems.v);
    double mean[6], sigma1, plane[3];
    if (!fs_tip_stress_mean(&avg, mean))
        return;
    if (fs_nodal_principal_plane(mean, &sigma1, plane) < 0) {
        fs_error_clear();
        return;
    }
    if (sigma1 > 0.0)
        memcpy(m, plane, sizeof plane);
}

/* The in-plane crack direction at node n from the fracture plane normal m (3-D). */
static bool crack_direction(const fs_wedge_model *w, int32_t n, const double m[3], double dir[3])
{
    fs_wedge_frame f;
    fs_wedge_frame_at(w, n, &f);
    double m2[2], d2[2];
    fs_wedge_frame_to_2d(&f, m, m2);
    if (!fs_split_crack_direction(m2, d2))
        return false;
    fs_wedge_frame_from_2d(&f, d2, dir);
    return true;
}

/* The tip with the largest (scaled) ratio over 1, skipping those flagged in tried (may be NULL); -1
 * if none. */
static int32_t pick_tip(const fs_wedge_model *w, const uint8_t *tried)
{
    if (w->n_tips == 0)
        return -1;
    double *r = fs_malloc((size_t)w->n_tips * sizeof *r);
    uint64_t *id = fs_malloc((size_t)w->n_tips * sizeof *id);
    for (int32_t k = 0; k < w->n_tips; k++) {
        r[k] = tip_ratio(w, w->tip_node[k], NULL) * w->tip_scale[k];
        if (!(r[k] > 1.0) || (tried && tried[k]))
            r[k] = NAN;
        id[k] = (uint64_t)w->tip_node[k];
    }
    int32_t k = fs_rank_pick(r, id, w->n_tips, w->cfg.seed);
    free(r);
    free(id);
    return k;
}

/* design: thesis §5.7.8 in the event loop. A sub-model costs a small assembly, factorization and
 * solve, so it is spent where the decision is made: the coarse estimate (tip_ratio, times the tip's
 * scale) ranks the tips and drives the search in time, and only the tip about to extend gets a
 * sub-model, whose nodal stress decides whether it extends (its over-threshold check) and where to
 * (its direction). The tip's scale becomes the sub-model ratio over its coarse ratio, so the estimate
 * of that tip agrees with the sub-model at this state and follows the coarse one as the load changes:
 * a tip the sub-model finds below its threshold drops below 1, the next tip is tried, and the search
 * in time finds when the scaled estimate crosses 1 again, where the sub-model checks once more (a
 * secant-like iteration on the tip's true ratio). A tip the sub-model finds without tension gets
 * scale 0 and no longer extends. An extended tip's new tip inherits the scale (the same crack, the
 * same kind of concentration); a new crack's tips start at 1. */
static int tip_submodel_check(fs_wedge_model *w, int32_t k, double *ratio, double m[3])
{
    int32_t node = w->tip_node[k];
    double unit = fs_wedge_tips_unit(w);
    if (fs_wedge_tip_submodel(w, node, w->cfg.fracture.tip_submodel_radius * unit,
                              w->cfg.fracture.tip_submodel_size * unit, ratio, m, NULL) < 0)
        return -1;
    double coarse = tip_ratio(w, node, NULL);
    w->tip_scale[k] = *ratio > 0.0 && coarse > 0.0 ? *ratio / coarse : 0.0;
    return 0;
}

int fs_wedge_split_event(fs_wedge_model *w, int *changed)
{
    *changed = 0;
    /* tips first (Fig. 5.20) */
    int32_t pick = -1;
    bool from_tip = false, have_m = false;
    double m[3], scale = 1.0;
    if (!w->cfg.fracture.tip_submodel) {
        int32_t k = pick_tip(w, NULL);
        if (k >= 0) {
            pick = w->tip_node[k];
            from_tip = true;
        }
    } else {
        uint8_t *tried = fs_calloc((size_t)w->n_tips + 1, 1);
        for (int32_t k; (k = pick_tip(w, tried)) >= 0;) {
            /* §5.7.6 first, so the sub-model starts from the finer layer */
            int32_t bisected = 0;
            if (subdivide_around(w, w->tip_node[k], &bisected) < 0) {
                free(tried);
                return -1;
            }
            if (bisected > 0) {
                free(tried);
                *changed = 1;
                return fs_wedge_equilibrium(w, w->time) < 0 ? -1 : 0;
            }
            double sub;
            if (tip_submodel_check(w, k, &sub, m) < 0) {
                free(tried);
                return -1;
            }
            if (sub > 1.0) {
                pick = w->tip_node[k];
                from_tip = have_m = true;
                scale = w->tip_scale[k];
                break;
            }
            tried[k] = 1;
            w->counters.submodel_rejections++;
        }
        free(tried);
    }
    if (pick < 0) {
        const uint8_t *open = open_nodes(w);
        double *r = fs_malloc(((size_t)w->n_nodes + 1) * sizeof *r);
        for (int32_t i = 0; i < w->n_nodes; i++) {
            r[i] = open[i] || cached_node_bound(w, i, 1.0) <= 1.0 ? NAN : cached_node_ratio(w, i);
            if (!(r[i] > 1.0))
                r[i] = NAN;
        }
        pick = fs_rank_pick(r, NULL, w->n_nodes, w->cfg.seed);
        free(r);
    }
    if (pick < 0)
        return 1;

    int32_t bisected = 0; /* (a tip the sub-model accepted was subdivided around already) */
    if (!have_m && subdivide_around(w, pick, &bisected) < 0)
        return -1;
    if (bisected > 0) {
        /* new midpoint nodes carry no displacement yet: a global solve, not a local relaxation */
        *changed = 1;
        return fs_wedge_equilibrium(w, w->time) < 0 ? -1 : 0;
    }

    double dir[3], rays[2][3];
    if (!have_m) {
        if (from_tip) {
            tip_ratio(w, pick, m);
            tip_average_plane(w, pick, w->tip_dir + 3 * (size_t)tip_find(w, pick), m);
        } else
            node_ratio(w, pick, m);
    }
    if (!crack_direction(w, pick, m, dir)) {
        tip_remove(w, pick);
        return 0;
    }
    int n_rays = 2;
    memcpy(rays[0], dir, sizeof rays[0]);
    for (int k = 0; k < 3; k++)
        rays[1][k] = -dir[k];
    if (from_tip) {
        const double *in = w->tip_dir + 3 * (size_t)tip_find(w, pick);
        double s = fs_dot3(dir, in) < 0.0 ? -1.0 : 1.0;
        for (int k = 0; k < 3; k++)
            rays[0][k] = s * dir[k];
        n_rays = 1;
    }

    bool griffith = from_tip && w->cfg.fracture.griffith;
    ilist region = {0};
    double e1 = 0.0;
    int32_t first_new = w->n_elems;
    double h = w->assembled_thickness * w->thickness_factor[pick];
    if (griffith) {
        griffith_region(w, pick, &region);
        e1 = region_energy(w, &region, w->n_elems);
    }
    int32_t ends[2];
    double lengths[2];
    int cuts = cut_at_node(w, pick, (const double(*)[3])rays, n_rays, ends, lengths);
    if (cuts < 0) {
        free(region.v);
        return -1;
    }
    if (cuts == 0) {
        /* the ray leaves through a gap of the fan: this crack cannot go on */
        tip_remove(w, pick);
        free(region.v);
        return 0;
    }
    *changed = 1;
    w->fractures++;
    if (from_tip && tip_find(w, ends[0]) >= 0)
        w->tip_scale[tip_find(w, ends[0])] = scale;
    if (griffith) {
        bool local = w->cfg.solver.relax == FS_RELAX_LOCAL;
        if ((local ? fs_wedge_relax(w, NULL, 0) : fs_wedge_equilibrium(w, w->time)) < 0) {
            free(region.v);
            return -1;
        }
        double e2 = region_energy(w, &region, first_new);
        double gc = fs_griffith_toughness_model_units(w->cfg.material.toughness);
        if (!fs_griffith_extends(e1, e2, lengths[0] * h, gc) && tip_find(w, ends[0]) >= 0) {
            tip_remove(w, ends[0]);
            w->griffith_stops++;
        }
    }
    free(region.v);
    return smooth_new_tips(w, ends, n_rays);
}
