/* Tests of wedge fracture by element splitting: crack direction under uniaxial stretch, Griffith termination, mesh validity after splits. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "base/vec.h"
#include "check.h"
#include "setup.h"
#include "wedge_fixture.h"
#include "geom/delaunay.h"
#include "geom/refine.h"
#include "geom/sample.h"
#include "model/wedge/internal.h"

/* Crack edges of a periodic mesh: boundary half-edges (each crack edge appears once per side). Sums
 * their length and the length-weighted doubled-angle moments of their directions. */
typedef struct {
    double length;      /* total wall length (cm), both sides */
    double c2, s2;      /* sum of length * cos(2 theta), length * sin(2 theta) */
    int32_t half_edges;
} crack_stats;

static crack_stats cracks_of(const fs_mesh *m)
{
    crack_stats s = {0};
    for (int32_t h = 0; h < 3 * m->n_tris; h++) {
        if (m->adj[h] >= 0)
            continue;
        double a[3], b[3];
        fs_mesh_corner(m, h / 3, h % 3, a);
        fs_mesh_corner(m, h / 3, (h % 3 + 1) % 3, b);
        double dx = b[0] - a[0], dy = b[1] - a[1], len = hypot(dx, dy), th = atan2(dy, dx);
        s.length += len;
        s.c2 += len * cos(2.0 * th);
        s.s2 += len * sin(2.0 * th);
        s.half_edges++;
    }
    return s;
}

static int32_t find_root(int32_t *parent, int32_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

static const double *sort_pos;

static int cmp_pos(const void *a, const void *b)
{
    const double *p = sort_pos + 3 * (size_t)*(const int32_t *)a, *q = sort_pos + 3 * (size_t)*(const int32_t *)b;
    for (int k = 0; k < 3; k++)
        if (p[k] != q[k])
            return p[k] < q[k] ? -1 : 1;
    return 0;
}

/* Length (cm) of the longest connected crack: crack walls joined through their nodes, duplicated
 * nodes (same position) counted as one. */
static double longest_crack(const fs_mesh *m)
{
    int32_t n = m->n_nodes;
    int32_t *parent = malloc(sizeof *parent * (size_t)n), *order = malloc(sizeof *order * (size_t)n);
    double *len = calloc((size_t)n, sizeof *len);
    for (int32_t i = 0; i < n; i++)
        parent[i] = order[i] = i;
    sort_pos = m->pos;
    qsort(order, (size_t)n, sizeof *order, cmp_pos);
    for (int32_t q = 1; q < n; q++)
        if (cmp_pos(order + q - 1, order + q) == 0)
            parent[find_root(parent, order[q])] = find_root(parent, order[q - 1]);
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        if (m->adj[h] < 0) {
            int32_t a = find_root(parent, m->tri[h]), b = find_root(parent, m->tri[3 * (h / 3) + (h % 3 + 1) % 3]);
            if (a != b)
                parent[a] = b;
        }
    for (int32_t h = 0; h < 3 * m->n_tris; h++)
        if (m->adj[h] < 0) {
            double a[3], b[3];
            fs_mesh_corner(m, h / 3, h % 3, a);
            fs_mesh_corner(m, h / 3, (h % 3 + 1) % 3, b);
            len[find_root(parent, m->tri[h])] += 0.5 * hypot(b[0] - a[0], b[1] - a[1]);
        }
    double best = 0.0;
    for (int32_t i = 0; i < n; i++)
        best = fmax(best, len[i]);
    free(parent);
    free(order);
    free(len);
    return best;
}

/* Checks the mesh is a valid cracked layer: every wedge has positive volume (positive bottom area,
 * positive thickness), adjacency is symmetric, every edge is shared by at most two triangles (the
 * adjacency builder fails otherwise), and every boundary half-edge (a crack wall) is matched by a
 * wall of the same geometric edge running the other way on a duplicated node pair. */
static void check_valid(const fs_wedge_model *w)
{
    const fs_mesh *m = w->mesh;
    int32_t bad_area = 0, bad_adj = 0, unmatched = 0;
    for (int32_t t = 0; t < m->n_tris; t++) {
        if (!(fs_mesh_tri_area(m, t) > 0.0))
            bad_area++;
        for (int i = 0; i < 3; i++) {
            int32_t u = m->adj[3 * t + i];
            if (u < 0)
                continue;
            bool back = false;
            for (int j = 0; j < 3; j++)
                back |= m->adj[3 * u + j] == t;
            bad_adj += !back;
        }
    }
    CHECK_MSG(bad_area == 0, "%d triangles with non-positive area", (int)bad_area);
    CHECK_MSG(bad_adj == 0, "%d one-sided adjacencies", (int)bad_adj);
    for (int32_t i = 0; i < w->n_nodes; i++)
        CHECK(w->thickness_factor[i] > 0.0);
    /* crack walls pair up: half-edge a->b on one side, b'->a' on the other, same positions */
    for (int32_t h = 0; h < 3 * m->n_tris; h++) {
        if (m->adj[h] >= 0)
            continue;
        double a[3], b[3];
        fs_mesh_corner(m, h / 3, h % 3, a);
        fs_mesh_corner(m, h / 3, (h % 3 + 1) % 3, b);
        bool found = false;
        for (int32_t g = 0; g < 3 * m->n_tris && !found; g++) {
            if (m->adj[g] >= 0 || g == h)
                continue;
            double c[3], d[3];
            fs_mesh_corner(m, g / 3, g % 3, c);
            fs_mesh_corner(m, g / 3, (g % 3 + 1) % 3, d);
            double dx = fs_domain_extent_x(&m->domain), dy = fs_domain_extent_y(&m->domain);
            double ox = round((d[0] - a[0]) / dx) * dx, oy = round((d[1] - a[1]) / dy) * dy;
            found = fabs(d[0] - ox - a[0]) < 1e-9 && fabs(d[1] - oy - a[1]) < 1e-9 &&
                    fabs(c[0] - ox - b[0]) < 1e-9 && fabs(c[1] - oy - b[1]) < 1e-9 &&
                    !(m->tri[g] == m->tri[(h / 3) * 3 + (h % 3 + 1) % 3] &&
                      m->tri[(g / 3) * 3 + (g % 3 + 1) % 3] == m->tri[h]);
        }
        unmatched += !found;
    }
    CHECK_MSG(unmatched == 0, "%d crack walls without a facing wall on duplicated nodes (hanging)", (int)unmatched);
}

/* The first crack under uniaxial tension along x runs along y, and splitting keeps the mesh valid. */
static void test_crack_perpendicular(void)
{
    fs_config cfg = wedge_strip_config();
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    int32_t nodes0 = w.n_nodes;
    /* run until the first cracks have run */
    CHECK(fs_wedge_simulate(&w, 0.3) == 0);
    crack_stats s = cracks_of(&m);
    CHECK_MSG(w.fractures > 3, "%lld splits", (long long)w.fractures);
    CHECK_MSG(s.length > 4.0, "crack wall length %g cm", s.length);
    /* mean doubled angle: a crack along y has theta = +-90 degrees, cos(2 theta) = -1 */
    double mean_angle = 0.5 * atan2(s.s2, s.c2) * 57.29577951308232;
    double off = 90.0 - fabs(mean_angle);
    CHECK_MSG(off < 5.0, "cracks run at %.2f degrees from x (expected 90)", mean_angle);
    double coherence = hypot(s.c2, s.s2) / s.length;
    CHECK_MSG(coherence > 0.6, "crack directions scattered (coherence %.2f)", coherence);
    CHECK(w.n_nodes > nodes0);
    check_valid(&w);
    /* the fragments separate only when nodes are duplicated: every split adds nodes */
    CHECK(w.n_nodes - nodes0 >= w.fractures);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* One split at an interior node: node count and wall area grow as expected. */
static void test_single_split(void)
{
    fs_config cfg = wedge_strip_config();
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 400, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    double t = 0.0;
    /* bring the layer over its threshold */
    while (t < 1.0) {
        t += 0.01;
        CHECK(fs_wedge_equilibrium(&w, t) == 0);
        if (fs_wedge_split_max_ratio(&w) > 1.0)
            break;
    }
    CHECK(fs_wedge_split_max_ratio(&w) > 1.0);
    int32_t nodes0 = w.n_nodes, tris0 = w.n_elems;
    crack_stats before = cracks_of(&m);
    int changed = 0;
    CHECK(fs_wedge_split_event(&w, &changed) == 0);
    CHECK(changed == 1);
    crack_stats after = cracks_of(&m);
    CHECK(before.half_edges == 0);
    /* a new crack: two cuts from the node, each splitting two triangles or snapping to a node; the
     * breaking node is duplicated once: 1 to 3 new nodes, 0 to 4 new triangles, 4 wall half-edges */
    CHECK_MSG(w.n_nodes - nodes0 >= 1 && w.n_nodes - nodes0 <= 3, "%d new nodes", (int)(w.n_nodes - nodes0));
    CHECK_MSG(w.n_elems - tris0 <= 4, "%d new triangles", (int)(w.n_elems - tris0));
    CHECK_MSG(after.half_edges == 4, "%d wall half-edges", (int)after.half_edges);
    CHECK(w.n_tips == 2);
    /* the wall area is the cut length times the thickness on each side */
    double area = 0.5 * after.length * cfg.material.thickness;
    CHECK(area > 0.0 && area < 4.0 * fs_refine_tri_size(&m, 0) * cfg.material.thickness + 1.0);
    check_valid(&w);
    CHECK(fs_wedge_equilibrium(&w, w.time) == 0);
    int32_t *labels = malloc(sizeof *labels * (size_t)w.n_elems);
    CHECK(fs_wedge_fragments(&w, labels) == 1); /* a crack with two tips does not separate */
    free(labels);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Entry (row, col) of an upper CSC matrix (0 when not stored). */
static double csc_entry(const fs_sparse_matrix *k, int32_t row, int32_t col)
{
    for (int32_t p = k->col_ptr[col]; p < k->col_ptr[col + 1]; p++)
        if (k->row_idx[p] == row)
            return k->values[p];
    return 0.0;
}

/* The model's whole system as one upper CSC of order n_free + n_fixed: K_ff and K_fb (fixed column
 * n_free + k). */
static void whole_system(const fs_wedge_model *w, fs_sparse_matrix *out)
{
    const fs_sparse_matrix *k = &w->k_free;
    const fs_wedge_coupling *c = &w->k_fb;
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, w->n_free + w->n_fixed, 0);
    for (int32_t j = 0; j < k->n; j++)
        for (int32_t p = k->col_ptr[j]; p < k->col_ptr[j + 1]; p++)
            fs_sparse_builder_add(&b, k->row_idx[p], j, k->values[p]);
    for (int32_t col = 0; col < c->n; col++)
        for (int32_t p = c->start[col]; p < c->start[col] + c->len[col]; p++)
            fs_sparse_builder_add(&b, c->row[p], w->n_free + col, c->value[p]);
    CHECK(fs_sparse_builder_compress(&b, out, NULL) == 0);
    fs_sparse_builder_free(&b);
}

/* The model's system, extended in place by its changes, is well formed (K_ff: rows strictly ascending
 * in every column, which ends on its diagonal; K_fb: free rows strictly ascending in every column,
 * within its room in the pool) and equals a fresh assembly of the changed mesh: every entry of the
 * fresh one with the same value, every other stored entry zero. Re-assembles w. */
static void check_system_is_fresh(fs_wedge_model *w)
{
    const fs_sparse_matrix *kf = &w->k_free;
    const fs_wedge_coupling *c = &w->k_fb;
    int32_t bad = 0;
    for (int32_t j = 0; j < kf->n; j++) {
        for (int32_t p = kf->col_ptr[j]; p + 1 < kf->col_ptr[j + 1]; p++)
            bad += kf->row_idx[p] >= kf->row_idx[p + 1];
        bad += kf->col_ptr[j + 1] == kf->col_ptr[j] || kf->row_idx[kf->col_ptr[j + 1] - 1] != j;
    }
    CHECK(kf->n == w->n_free && c->n == w->n_fixed && c->used <= c->size);
    for (int32_t col = 0; col < c->n; col++) {
        bad += c->len[col] > c->cap[col] || (size_t)c->start[col] + (size_t)c->cap[col] > c->used;
        for (int32_t p = c->start[col]; p < c->start[col] + c->len[col]; p++)
            bad += c->row[p] < 0 || c->row[p] >= w->n_free || (p > c->start[col] && c->row[p - 1] >= c->row[p]);
    }
    CHECK_MSG(bad == 0, "%d malformed columns", (int)bad);
    /* node_elem, updated in place by the changes: each node's elements, ascending */
    int32_t wrong = 0;
    int32_t *count = calloc((size_t)w->n_nodes + 1, sizeof *count);
    for (int32_t e = 0; e < w->n_elems; e++)
        for (int k = 0; k < 3; k++) {
            int32_t i = w->mesh->tri[3 * (size_t)e + k], p = w->node_elem_start[i];
            if ((k > 0 && w->mesh->tri[3 * (size_t)e + k - 1] == i) || (k == 2 && w->mesh->tri[3 * (size_t)e] == i))
                continue;
            wrong += count[i] >= w->node_elem_count[i] || w->node_elem[p + count[i]] != e;
            count[i]++;
        }
    for (int32_t i = 0; i < w->n_nodes; i++)
        wrong += count[i] != w->node_elem_count[i];
    free(count);
    CHECK_MSG(wrong == 0, "%d wrong node_elem entries", (int)wrong);
    fs_sparse_matrix old, fresh;
    whole_system(w, &old);
    int32_t order = old.n;
    uint8_t *none = calloc((size_t)w->n_nodes + 1, 1);
    CHECK(fs_wedge_pin_top(w, none) == 0); /* the same numbering, assembled afresh */
    free(none);
    whole_system(w, &fresh);
    CHECK(fresh.n == order);
    double scale = 0.0, worst = 0.0;
    for (int32_t p = 0; p < fs_sparse_matrix_nnz(&old); p++)
        scale = fmax(scale, fabs(old.values[p]));
    int32_t missing = 0;
    for (int32_t j = 0; j < order && fresh.n == order; j++) {
        for (int32_t p = fresh.col_ptr[j]; p < fresh.col_ptr[j + 1]; p++) {
            int32_t i = fresh.row_idx[p];
            bool stored = false;
            for (int32_t q = old.col_ptr[j]; q < old.col_ptr[j + 1]; q++)
                stored |= old.row_idx[q] == i;
            missing += !stored && fresh.values[p] != 0.0;
            worst = fmax(worst, fabs(fresh.values[p] - csc_entry(&old, i, j)));
        }
        for (int32_t q = old.col_ptr[j]; q < old.col_ptr[j + 1]; q++)
            worst = fmax(worst, fabs(old.values[q] - csc_entry(&fresh, old.row_idx[q], j)));
    }
    CHECK_MSG(missing == 0, "%d fresh entries missing from the extended matrix", (int)missing);
    CHECK_MSG(worst <= 1e-12 * scale, "extended and fresh matrices differ by %.3g of %.3g", worst, scale);
    fs_sparse_matrix_free(&old);
    fs_sparse_matrix_free(&fresh);
}

/* The cuts extend the system in place correctly; with growth that moves the fixed bottom nodes, so
 * the coupling is exercised too. */
/* The stretched strip of 600 elements, not periodic, as a model on m. */
static void open_strip(fs_mesh *m, fs_wedge_model *w)
{
    fs_config cfg = wedge_strip_config();
    cfg.domain.periodic_x = cfg.domain.periodic_y = false;
    CHECK(wedge_test_mesh(&cfg, 600, m) == 0);
    CHECK(fs_wedge_init(w, m, SETUP(&cfg)) == 0);
}

static void test_extended_matrix_is_fresh(void)
{
    fs_mesh m = {0};
    fs_wedge_model w;
    open_strip(&m, &w);
    CHECK(fs_wedge_simulate(&w, 1.0) == 0);
    CHECK_MSG(w.fractures >= 10, "%lld splits", (long long)w.fractures);
    check_system_is_fresh(&w);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* A thickening layer is refilled at each new thickness through the pattern slots it keeps between
 * cuts (system.c): after cuts and refills in turn, and one more refill after the last cut, its system
 * is still a fresh assembly's. */
static void test_refilled_matrix_is_fresh(void)
{
    fs_config cfg = wedge_strip_config();
    cfg.domain.periodic_x = cfg.domain.periodic_y = false;
    cfg.material.thickness_final = 0.4;
    fs_mesh m = {0};
    CHECK(wedge_test_mesh(&cfg, 600, &m) == 0);
    fs_wedge_model w;
    CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
    CHECK(fs_wedge_simulate(&w, 0.8) == 0);
    CHECK_MSG(w.fractures >= 10, "%lld splits", (long long)w.fractures);
    uint64_t version = w.pattern_version;
    CHECK(fs_wedge_equilibrium(&w, 0.9) == 0);
    CHECK(w.refill_slot_version == version && w.assembled_thickness > 0.2);
    check_system_is_fresh(&w);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Twice the signed area of the triangle of nodes a, b, c (the plane: z ignored). */
static double orientation(const fs_mesh *m, int32_t a, int32_t b, int32_t c)
{
    const double *p = m->pos + 3 * (size_t)a, *q = m->pos + 3 * (size_t)b, *r = m->pos + 3 * (size_t)c;
    return (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0]);
}

/* A change that couples old nodes not coupled before (an edge flip: cuts and bisections never do)
 * adds entries to old columns of K_ff, which moves the columns behind them: the system still equals
 * a fresh assembly. */
static void test_flip_extends_old_columns(void)
{
    fs_mesh m = {0};
    fs_wedge_model w;
    open_strip(&m, &w);
    CHECK(fs_wedge_equilibrium(&w, 0.5) == 0);
    int flips = 0;
    for (int32_t t = 0; t < m.n_tris && flips < 3; t += 37) {
        for (int i = 0; i < 3; i++) {
            int32_t u = m.adj[3 * (size_t)t + i];
            if (u < 0 || u == t)
                continue;
            int32_t a = m.tri[3 * (size_t)t + i], b = m.tri[3 * (size_t)t + (i + 1) % 3];
            int32_t c = m.tri[3 * (size_t)t + (i + 2) % 3], d = -1;
            for (int k = 0; k < 3; k++)
                if (m.tri[3 * (size_t)u + k] != a && m.tri[3 * (size_t)u + k] != b)
                    d = m.tri[3 * (size_t)u + k];
            /* the quadrilateral a d b c must be convex for the flip to (a, d, c), (d, b, c) */
            if (d < 0 || orientation(&m, a, d, c) <= 0.0 || orientation(&m, d, b, c) <= 0.0)
                continue;
            int32_t ta[3] = {a, d, c}, tb[3] = {d, b, c};
            memcpy(m.tri + 3 * (size_t)t, ta, sizeof ta);
            memcpy(m.tri + 3 * (size_t)u, tb, sizeof tb);
            fs_mesh_drop_derived(&m);
            CHECK(fs_mesh_build_adjacency(&m) == 0);
            fs_mesh_build_edges(&m);
            fs_mesh_build_rings(&m);
            int32_t changed[2] = {t < u ? t : u, t < u ? u : t};
            fs_wedge_change ch = {m.n_nodes, m.n_tris, NULL, NULL, NULL, changed, 2};
            CHECK(fs_wedge_apply_change(&w, &ch) == 0);
            flips++;
            break;
        }
    }
    CHECK_MSG(flips == 3, "%d flips", flips);
    check_system_is_fresh(&w);
    fs_wedge_free(&w);
    fs_mesh_free(&m);
}

/* Griffith: a high toughness stops the crack after its first extension, a zero one does not. */
static void test_griffith(void)
{
    double length[2];
    int64_t stops[2];
    for (int k = 0; k < 2; k++) {
        fs_config cfg = wedge_strip_config();
        cfg.fracture.griffith = true;
        cfg.material.toughness = k ? 1e6 : 0.0;
        fs_mesh m = {0};
        CHECK(wedge_test_mesh(&cfg, 450, &m) == 0);
        fs_wedge_model w;
        CHECK(fs_wedge_init(&w, &m, SETUP(&cfg)) == 0);
        CHECK(fs_wedge_simulate(&w, 0.3) == 0);
        length[k] = longest_crack(&m);
        stops[k] = w.griffith_stops;
        fs_wedge_free(&w);
        fs_mesh_free(&m);
    }
    CHECK_MSG(stops[0] == 0, "%lld tips stopped with zero toughness", (long long)stops[0]);
    CHECK_MSG(stops[1] > 0, "no tip stopped with a high toughness");
    CHECK_MSG(length[1] < 0.5 * length[0], "longest crack %g cm with toughness, %g cm without", length[1], length[0]);
    printf("longest crack %g cm with toughness, %g cm without\n", length[1], length[0]);
}

int main(void)
{
    RUN(test_single_split);
    RUN(test_crack_perpendicular);
    RUN(test_griffith);
    RUN(test_extended_matrix_is_fresh);
    RUN(test_refilled_matrix_is_fresh);
    RUN(test_flip_extends_old_columns);
    return check_finish();
}
