/* The wedge model's layer: geometry and materials from the mesh, sparse assembly, equilibrium (CHOLMOD or CG) and element stresses. */
#include "model/wedge/internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/rng.h"
#include "base/sort.h"
#include "base/vec.h"
#include "fracture/eigen.h"
#include "fracture/rank.h"
#include "geom/refine.h"
#include "model/wedge/element.h"
#include "solve/cg.h"

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

static double layer_thickness(const fs_wedge_model *w, double t)
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

static void coords_at(const fs_wedge_model *w, int32_t e, double base_thickness, double x[18])
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
    coords_at(w, e, w->assembled_thickness, x);
}

/* design: the unit displacement patterns of an element whose combinations give its loads.
 *   0..2  shrinkage (thesis Fig. 3.10, see wedge.h): bottom nodes about the bottom centroid, top nodes
 *         about the top centroid, and the top lifted along the centroid-to-centroid vector; the
 *         reference-shape displacement is sum_k (scale_k - 1) pattern_k.
 *   3..5  the linear displacements with unit strain xx, yy and engineering xy (about the element's
 *         centroid). An isoparametric element reproduces linear fields exactly, so K_e times such a
 *         pattern is the element's equivalent nodal force of that constant eigenstrain
 *         (sum_g B^T D eps det J w), without another quadrature. */
static void patterns(const double x[18], double pat[FS_WEDGE_PATTERNS][18])
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
static void shrink_displacement(const fs_wedge_model *w, const double x[18], double u0[18])
{
    double pat[FS_WEDGE_PATTERNS][18];
    patterns(x, pat);
    for (int a = 0; a < 18; a++)
        u0[a] = w->shrink_coef[0] * pat[0][a] + w->shrink_coef[1] * pat[1][a] + w->shrink_coef[2] * pat[2][a];
}

/* ---- DOFs and node -> element lists ---- */

static int32_t elem_dof(const fs_wedge_model *w, int32_t e, int a)
{
    int32_t node = w->mesh->tri[3 * (size_t)e + (a / 3) % 3];
    int local = a / 9 ? 3 : 0; /* a in 0..17: node a / 3, bottom for nodes 0..2 */
    return w->dof[6 * (size_t)node + local + a % 3];
}

/* Numbers the DOFs: free ones (top nodes not pinned) first in node order, then the fixed ones. */
static void number_dofs(fs_wedge_model *w)
{
    int32_t n = w->n_nodes, next = 0;
    w->dof = fs_realloc(w->dof, 6 * (size_t)n * sizeof *w->dof);
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            w->dof[6 * (size_t)i + 3 + k] = w->pinned[i] ? -1 : next++;
    w->n_free = next;
    w->fixed_node_dof = fs_realloc(w->fixed_node_dof, 6 * (size_t)n * sizeof *w->fixed_node_dof);
    for (int32_t i = 0; i < n; i++)
        for (int l = 0; l < 6; l++) {
            int32_t *d = w->dof + 6 * (size_t)i + l;
            if (l < 3 || *d < 0) {
                w->fixed_node_dof[next - w->n_free] = 6 * i + l;
                *d = next++;
            }
        }
    w->n_fixed = next - w->n_free;
}

/* Room each node's element list gets beyond its entries, so that cuts update it in place. */
#define NODE_ELEM_SLACK 3

static void build_node_elems(fs_wedge_model *w)
{
    int32_t n = w->n_nodes;
    free(w->node_elem_start);
    free(w->node_elem);
    w->node_elem_start = fs_calloc((size_t)n + 1, sizeof *w->node_elem_start);
    for (int32_t e = 0; e < w->n_elems; e++)
        for (int c = 0; c < 3; c++)
            w->node_elem_start[w->mesh->tri[3 * (size_t)e + c] + 1]++;
    for (int32_t i = 0; i < n; i++)
        w->node_elem_start[i + 1] += w->node_elem_start[i] + NODE_ELEM_SLACK;
    int32_t *fill = fs_malloc(((size_t)n + 1) * sizeof *fill);
    memcpy(fill, w->node_elem_start, ((size_t)n + 1) * sizeof *fill);
    w->node_elem_used = w->node_elem_capacity = w->node_elem_start[n];
    w->node_elem = fs_malloc(((size_t)w->node_elem_capacity + 1) * sizeof *w->node_elem);
    for (int32_t e = 0; e < w->n_elems; e++)
        for (int c = 0; c < 3; c++) {
            int32_t node = w->mesh->tri[3 * (size_t)e + c];
            /* a node listed twice in one element (tiny periodic meshes) keeps one entry */
            if (fill[node] > w->node_elem_start[node] && w->node_elem[fill[node] - 1] == e)
                continue;
            w->node_elem[fill[node]++] = e;
        }
    w->node_elem_room = fs_realloc(w->node_elem_room, ((size_t)n + 1) * sizeof *w->node_elem_room);
    for (int32_t i = 0; i < n; i++) {
        w->node_elem_count[i] = fill[i] - w->node_elem_start[i];
        w->node_elem_room[i] = w->node_elem_start[i + 1] - w->node_elem_start[i];
    }
    free(fill);
}

/* Entries of node_elem from node_elem_used on for a list of `room`; returns its start. */
static int32_t node_elem_take(fs_wedge_model *w, int32_t room)
{
    FS_ARRAY_RESERVE(w->node_elem, w->node_elem_capacity, w->node_elem_used + room, 64);
    int32_t start = w->node_elem_used;
    w->node_elem_used += room;
    return start;
}

int32_t fs_wedge_elems_at(const fs_wedge_model *w, int32_t i, const int32_t *changed, int32_t n_changed,
                          int32_t first_new, bool living, int32_t *out)
{
    const fs_mesh *m = w->mesh;
    int32_t n = 0;
    if (i < w->n_nodes)
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
            out[n++] = w->node_elem[p];
    for (int32_t q = 0; q < n_changed; q++)
        out[n++] = changed[q];
    for (int32_t t = first_new; t < m->n_tris; t++)
        out[n++] = t;
    fs_sort_int32(out, n);
    int32_t kept = 0;
    for (int32_t q = 0; q < n; q++) {
        int32_t t = out[q];
        if ((kept > 0 && out[kept - 1] == t) || (living && t < w->n_elems && w->state[t] != FS_WEDGE_ALIVE) ||
            fs_mesh_corner_of(m, t, i) < 0)
            continue;
        out[kept++] = t;
    }
    return kept;
}

/* Brings node_elem up to a change that appended nodes from n0 and elements from e0 and rewrote the
 * corners of the listed elements only, so that the nodes whose lists change are the corners of the
 * changed and new elements and those that lost an element (given in lost, nl of them): their lists
 * are recomputed from their old ones and those elements, in place while they fit their room; a list
 * that outgrows it, and a new node's, gets room at the end of node_elem. Once the lists abandoned
 * there take half of it, everything is laid out again. */
static void update_node_elems(fs_wedge_model *w, int32_t n0, int32_t e0, const int32_t *changed, int32_t n_changed,
                              const int32_t *lost, int32_t nl)
{
    const fs_mesh *m = w->mesh;
    int32_t n_new_elems = w->n_elems - e0;
    int32_t *cand = fs_malloc(((size_t)n_changed + n_new_elems + 64) * sizeof *cand);
    int32_t cap_cand = n_changed + n_new_elems + 64;
    w->node_elem_start = fs_realloc(w->node_elem_start, ((size_t)w->n_nodes + 1) * sizeof *w->node_elem_start);
    w->node_elem_room = fs_realloc(w->node_elem_room, ((size_t)w->n_nodes + 1) * sizeof *w->node_elem_room);
    for (int32_t i = n0; i < w->n_nodes; i++) {
        w->node_elem_start[i] = node_elem_take(w, NODE_ELEM_SLACK);
        w->node_elem_room[i] = NODE_ELEM_SLACK;
        w->node_elem_count[i] = 0;
    }
    /* the nodes whose lists change, each once */
    int32_t n_touch = 0, *touch = fs_malloc((3 * ((size_t)n_changed + n_new_elems) + (size_t)nl + 1) * sizeof *touch);
    for (int32_t q = 0; q < n_changed; q++)
        for (int k = 0; k < 3; k++)
            touch[n_touch++] = m->tri[3 * (size_t)changed[q] + k];
    for (int32_t e = e0; e < w->n_elems; e++)
        for (int k = 0; k < 3; k++)
            touch[n_touch++] = m->tri[3 * (size_t)e + k];
    for (int32_t q = 0; q < nl; q++)
        touch[n_touch++] = lost[q];
    n_touch = fs_sort_unique_int32(touch, n_touch);
    for (int32_t t = 0; t < n_touch; t++) {
        int32_t i = touch[t];
        int32_t start = w->node_elem_start[i], count = w->node_elem_count[i];
        if (count + n_changed + n_new_elems > cap_cand) {
            cap_cand = count + n_changed + n_new_elems;
            cand = fs_realloc(cand, (size_t)cap_cand * sizeof *cand);
        }
        int32_t kept = fs_wedge_elems_at(w, i, changed, n_changed, e0, false, cand);
        if (kept > w->node_elem_room[i]) {
            w->node_elem_room[i] = kept + NODE_ELEM_SLACK;
            w->node_elem_start[i] = start = node_elem_take(w, w->node_elem_room[i]);
        }
        memcpy(w->node_elem + start, cand, (size_t)kept * sizeof *cand);
        w->node_elem_count[i] = kept;
    }
    free(touch);
    free(cand);
    if (w->node_elem_used > 2 * (3 * w->n_elems + NODE_ELEM_SLACK * w->n_nodes))
        build_node_elems(w);
}

/* Living elements that use node i. */
static int32_t alive_at_node(const fs_wedge_model *w, int32_t i)
{
    int32_t count = 0;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
        count += w->state[w->node_elem[p]] == FS_WEDGE_ALIVE;
    return count;
}

/* ---- element matrices ---- */

static int element_system(const fs_wedge_model *w, int32_t e, double base_thickness, double K[324],
                             double loads[FS_WEDGE_PATTERNS][18])
{
    double x[18], D[36];
    coords_at(w, e, base_thickness, x);
    for (int i = 0; i < 36; i++)
        D[i] = w->young[e] * w->d_unit[i];
    if (fs_wedge_stiffness(x, D, K) < 0) {
        fs_error(FS_ERR_DATA, "wedge model: element %d is inverted or degenerate (%s)", (int)e, fs_error_message());
        return -1;
    }
    double pat[FS_WEDGE_PATTERNS][18];
    patterns(x, pat);
    int npat = w->growth_mode == FS_WEDGE_GROWTH_EIGENSTRAIN ? FS_WEDGE_PATTERNS : 3;
    memset(loads, 0, sizeof(double) * FS_WEDGE_PATTERNS * 18);
    for (int q = 0; q < npat; q++)
        for (int a = 0; a < 18; a++) {
            double s = 0.0;
            for (int c = 0; c < 18; c++)
                s += K[18 * a + c] * pat[q][c];
            loads[q][a] = s;
        }
    return 0;
}

/* ---- the sparse system ---- */

static int refresh_cache(fs_wedge_model *w, const int32_t *elems, int32_t n);

static int32_t find_entry(const fs_sparse_matrix *m, int32_t i, int32_t j)
{
    int32_t row = i < j ? i : j, col = i < j ? j : i;
    int32_t lo = m->col_ptr[col], hi = m->col_ptr[col + 1] - 1;
    while (lo <= hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (m->row_idx[mid] == row)
            return mid;
        if (m->row_idx[mid] < row)
            lo = mid + 1;
        else
            hi = mid - 1;
    }
    return -1;
}

/* ---- the coupling K_fb (see fs_wedge_coupling) ---- */

/* Room a column is given beyond its entries when it is laid out or moved: a cut adds a few rows. */
#define COUPLING_SLACK 6

static void coupling_free(fs_wedge_coupling *c)
{
    free(c->start);
    free(c->len);
    free(c->cap);
    free(c->row);
    free(c->value);
    memset(c, 0, sizeof *c);
}

/* Makes room for `more` slots at the end of the pool. */
static void coupling_reserve(fs_wedge_coupling *c, size_t more)
{
    if (c->used + more <= c->size)
        return;
    c->size = 2 * (c->used + more);
    c->row = fs_realloc(c->row, c->size * sizeof *c->row);
    c->value = fs_realloc(c->value, c->size * sizeof *c->value);
}

/* Grows the column arrays to n columns; new columns are empty with room for COUPLING_SLACK. */
static void coupling_resize(fs_wedge_coupling *c, int32_t n)
{
    c->start = fs_realloc(c->start, ((size_t)n + 1) * sizeof *c->start);
    c->len = fs_realloc(c->len, ((size_t)n + 1) * sizeof *c->len);
    c->cap = fs_realloc(c->cap, ((size_t)n + 1) * sizeof *c->cap);
    coupling_reserve(c, (size_t)COUPLING_SLACK * (size_t)(n > c->n ? n - c->n : 0));
    for (int32_t k = c->n; k < n; k++) {
        c->start[k] = (int32_t)c->used;
        c->len[k] = 0;
        c->cap[k] = COUPLING_SLACK;
        c->used += COUPLING_SLACK;
    }
    c->n = n;
}

/* The coupling from the fixed columns nf .. a->n - 1 of an upper CSC (their free rows; the fixed
 * columns' own zero diagonals are left out). */
static void coupling_from_csc(fs_wedge_coupling *c, const fs_sparse_matrix *a, int32_t nf)
{
    coupling_free(c);
    int32_t n = a->n - nf;
    size_t total = 0;
    for (int32_t j = nf; j < a->n; j++)
        total += (size_t)(a->col_ptr[j + 1] - a->col_ptr[j]) + COUPLING_SLACK;
    c->size = total + 1;
    c->row = fs_malloc(c->size * sizeof *c->row);
    c->value = fs_malloc(c->size * sizeof *c->value);
    c->start = fs_malloc(((size_t)n + 1) * sizeof *c->start);
    c->len = fs_malloc(((size_t)n + 1) * sizeof *c->len);
    c->cap = fs_malloc(((size_t)n + 1) * sizeof *c->cap);
    for (int32_t k = 0; k < n; k++) {
        int32_t j = nf + k, m = 0;
        c->start[k] = (int32_t)c->used;
        for (int32_t p = a->col_ptr[j]; p < a->col_ptr[j + 1]; p++)
            if (a->row_idx[p] < nf) {
                c->row[c->used + (size_t)m] = a->row_idx[p];
                c->value[c->used + (size_t)m++] = a->values[p];
            }
        c->len[k] = m;
        c->cap[k] = m + COUPLING_SLACK;
        c->used += (size_t)c->cap[k];
        c->entries += (size_t)m;
    }
    c->n = n;
}

/* The slot of (row, column k), or where it would go (the first slot with a larger row) as
 * -1 - position. */
static int32_t coupling_search(const fs_wedge_coupling *c, int32_t k, int32_t row)
{
    int32_t lo = c->start[k], hi = c->start[k] + c->len[k];
    while (lo < hi) {
        int32_t mid = lo + (hi - lo) / 2;
        if (c->row[mid] < row)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo < c->start[k] + c->len[k] && c->row[lo] == row ? lo : -1 - lo;
}

/* Adds (row, column k) with value 0 unless present. A full column moves to the end of the pool with
 * twice the room; when holes fill half the pool it is laid out afresh. */
static void coupling_insert(fs_wedge_coupling *c, int32_t k, int32_t row)
{
    int32_t at = coupling_search(c, k, row);
    if (at >= 0)
        return;
    at = -1 - at;
    if (c->len[k] == c->cap[k]) {
        int32_t cap = 2 * c->cap[k] + COUPLING_SLACK, offset = at - c->start[k];
        coupling_reserve(c, (size_t)cap);
        memcpy(c->row + c->used, c->row + c->start[k], (size_t)c->len[k] * sizeof *c->row);
        memcpy(c->value + c->used, c->value + c->start[k], (size_t)c->len[k] * sizeof *c->value);
        c->start[k] = (int32_t)c->used;
        c->cap[k] = cap;
        c->used += (size_t)cap;
        at = c->start[k] + offset;
    }
    int32_t end = c->start[k] + c->len[k];
    memmove(c->row + at + 1, c->row + at, (size_t)(end - at) * sizeof *c->row);
    memmove(c->value + at + 1, c->value + at, (size_t)(end - at) * sizeof *c->value);
    c->row[at] = row;
    c->value[at] = 0.0;
    c->len[k]++;
    c->entries++;
}

/* Lays the pool out afresh (each column with COUPLING_SLACK room) once moved columns' holes take
 * more than half of it. */
static void coupling_compact(fs_wedge_coupling *c)
{
    size_t live = c->entries + (size_t)COUPLING_SLACK * (size_t)c->n;
    if (2 * live >= c->used)
        return;
    int32_t *row = fs_malloc((live + 1) * sizeof *row);
    double *value = fs_malloc((live + 1) * sizeof *value);
    size_t at = 0;
    for (int32_t k = 0; k < c->n; k++) {
        memcpy(row + at, c->row + c->start[k], (size_t)c->len[k] * sizeof *row);
        memcpy(value + at, c->value + c->start[k], (size_t)c->len[k] * sizeof *value);
        c->start[k] = (int32_t)at;
        c->cap[k] = c->len[k] + COUPLING_SLACK;
        at += (size_t)c->cap[k];
    }
    free(c->row);
    free(c->value);
    c->row = row;
    c->value = value;
    c->used = at;
    c->size = live + 1;
}

/* The slot of the system entry coupling DOFs i and j (not both fixed): in k_free, or in k_fb for a
 * fixed one; *in_fb tells which. -1 if not stored. */
static int32_t system_slot(const fs_wedge_model *w, int32_t i, int32_t j, bool *in_fb)
{
    int32_t row = i < j ? i : j, col = i < j ? j : i;
    *in_fb = col >= w->n_free;
    if (!*in_fb)
        return find_entry(&w->k_free, row, col);
    int32_t p = coupling_search(&w->k_fb, col - w->n_free, row);
    return p >= 0 ? p : -1;
}

double fs_wedge_system_entry(const fs_wedge_model *w, int32_t g, int32_t j)
{
    bool in_fb;
    int32_t p = system_slot(w, g, j, &in_fb);
    return p < 0 ? 0.0 : in_fb ? w->k_fb.value[p] : w->k_free.values[p];
}

/* Calls add(ctx, i, j, value) for every kept pair (a <= c) of the element: fixed-fixed pairs are left
 * out; two local DOFs on one global DOF (a node repeated in a tiny periodic mesh) add the
 * off-diagonal term twice, as the full matrix would. */
static void element_pairs(const fs_wedge_model *w, int32_t e, const double K[324],
                          void (*add)(void *ctx, int32_t i, int32_t j, double v), void *ctx)
{
    int32_t g[18];
    for (int a = 0; a < 18; a++)
        g[a] = elem_dof(w, e, a);
    for (int a = 0; a < 18; a++)
        for (int c = a; c < 18; c++) {
            if (g[a] >= w->n_free && g[c] >= w->n_free)
                continue;
            double v = K[18 * a + c];
            if (c != a && g[a] == g[c])
                v *= 2.0;
            add(ctx, g[a], g[c], v);
        }
}

static void add_to_builder(void *ctx, int32_t i, int32_t j, double v)
{
    fs_sparse_builder_add(ctx, i, j, v);
}

static void add_loads(fs_wedge_model *w, int32_t e, const double loads[FS_WEDGE_PATTERNS][18], const uint8_t *only)
{
    for (int a = 0; a < 18; a++) {
        int32_t g = elem_dof(w, e, a);
        if (g >= w->n_free || (only && !only[g]))
            continue;
        for (int q = 0; q < FS_WEDGE_PATTERNS; q++)
            w->load[FS_WEDGE_PATTERNS * (size_t)g + q] += loads[q][a];
    }
}

/* Free DOFs of nodes without a living element get a unit diagonal (their displacement solves to 0). */
static void fix_orphans(fs_wedge_model *w)
{
    for (int32_t i = 0; i < w->n_nodes; i++) {
        if (alive_at_node(w, i) > 0)
            continue;
        for (int k = 3; k < 6; k++) {
            int32_t g = w->dof[6 * (size_t)i + k];
            if (g < w->n_free) {
                int32_t p = find_entry(&w->k_free, g, g);
                FS_ASSERT(p >= 0);
                w->k_free.values[p] = 1.0;
            }
        }
    }
}

static int factorize(fs_wedge_model *w, bool analyze)
{
    if (w->cfg.solver.method != FS_SOLVER_CHOLMOD || w->n_free == 0)
        return 0;
    double t0 = fs_seconds();
    if (analyze || !w->chol) {
        fs_cholesky_free(w->chol);
        w->chol = fs_cholesky_analyze(&w->k_free);
        if (!w->chol)
            return -1;
        w->counters.analyses++;
    }
    double t1 = fs_seconds();
    int rc = fs_cholesky_factorize(w->chol, &w->k_free);
    double t2 = fs_seconds();
    w->counters.analyze_seconds += t1 - t0;
    w->counters.factor_seconds += t2 - t1;
    w->counters.factorizations++;
    w->updowns_pending = 0;
    w->factor_stale = rc < 0;
    return rc;
}

/* design: thesis §5.4 assembles K_G from every element and §5.5 eliminates the known (fixed) nodal
 * coordinates from the system (its second approach), which halves the unknowns. All DOFs are
 * assembled into one symmetric matrix numbered free-first, without fixed-fixed pairs: its leading
 * block is K_ff, which the solvers use as it lies, and its other columns become K_fb (a coupling with
 * room to grow, fs_wedge_coupling), which turns the prescribed motion of fixed nodes into the
 * right-hand side -K_fb u_b. */
static int build_system(fs_wedge_model *w)
{
    double t0 = fs_seconds();
    number_dofs(w);
    build_node_elems(w);
    int32_t order = w->n_free + w->n_fixed;
    int32_t alive = 0;
    for (int32_t e = 0; e < w->n_elems; e++)
        alive += w->state[e] == FS_WEDGE_ALIVE;
    fs_sparse_builder b;
    fs_sparse_builder_init(&b, order, (size_t)alive * 171);
    free(w->load);
    w->load = fs_calloc((size_t)FS_WEDGE_PATTERNS * (w->n_free ? w->n_free : 1), sizeof *w->load);
    w->load_capacity = w->n_free;
    double K[324], loads[FS_WEDGE_PATTERNS][18];
    for (int32_t e = 0; e < w->n_elems; e++) {
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        if (element_system(w, e, w->assembled_thickness, K, loads) < 0) {
            fs_sparse_builder_free(&b);
            return -1;
        }
        element_pairs(w, e, K, add_to_builder, &b);
        add_loads(w, e, loads, NULL);
    }
    /* every free DOF keeps a diagonal entry, orphans included */
    for (int32_t g = 0; g < w->n_free; g++)
        fs_sparse_builder_add(&b, g, g, 0.0);
    fs_sparse_matrix all = {0};
    int rc = fs_sparse_builder_compress(&b, &all, NULL);
    fs_sparse_builder_free(&b);
    if (rc < 0)
        return -1;
    /* the leading block is K_ff as it stands; the fixed columns go into K_fb */
    coupling_from_csc(&w->k_fb, &all, w->n_free);
    fs_sparse_matrix_free(&w->k_free);
    w->k_free = all;
    w->k_free.n = w->n_free;
    w->k_free_capacity = (size_t)fs_sparse_matrix_nnz(&w->k_free) + 1;
    w->k_free.row_idx = fs_realloc(w->k_free.row_idx, w->k_free_capacity * sizeof *w->k_free.row_idx);
    w->k_free.values = fs_realloc(w->k_free.values, w->k_free_capacity * sizeof *w->k_free.values);
    w->k_free.col_ptr = fs_realloc(w->k_free.col_ptr, ((size_t)w->n_free + 1) * sizeof *w->k_free.col_ptr);
    fix_orphans(w);
    w->rhs = fs_realloc(w->rhs, ((size_t)w->n_free + 1) * sizeof *w->rhs);
    w->x = fs_realloc(w->x, ((size_t)w->n_free + 1) * sizeof *w->x);
    memset(w->x, 0, ((size_t)w->n_free + 1) * sizeof *w->x);
    w->u_fixed = fs_realloc(w->u_fixed, ((size_t)w->n_fixed + 1) * sizeof *w->u_fixed);
    free(w->mark);
    w->mark = fs_calloc((size_t)order + 1, sizeof *w->mark);
    if (refresh_cache(w, NULL, w->n_elems) < 0)
        return -1;
    w->counters.assemble_seconds += fs_seconds() - t0;
    return factorize(w, true);
}

typedef struct {
    fs_wedge_model *w;
    const uint8_t *only; /* if not NULL: add only where both DOFs are marked */
} refill_ctx;

static void add_in_place(void *ctx, int32_t i, int32_t j, double v)
{
    refill_ctx *r = ctx;
    if (r->only && !(r->only[i] && r->only[j]))
        return;
    bool in_fb;
    int32_t p = system_slot(r->w, i, j, &in_fb);
    FS_ASSERT(p >= 0);
    if (in_fb)
        r->w->k_fb.value[p] += v;
    else
        r->w->k_free.values[p] += v;
}

/* Re-adds the contributions of the living elements in `elems` (ascending) into the pattern: all of
 * them when only is NULL, else only the entries and loads whose DOFs are all marked in only. */
static int readd(fs_wedge_model *w, const int32_t *elems, int32_t n, const uint8_t *only)
{
    double K[324], loads[FS_WEDGE_PATTERNS][18];
    refill_ctx r = {w, only};
    for (int32_t q = 0; q < n; q++) {
        int32_t e = elems ? elems[q] : q;
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        if (element_system(w, e, w->assembled_thickness, K, loads) < 0)
            return -1;
        element_pairs(w, e, K, add_in_place, &r);
        add_loads(w, e, loads, only);
    }
    return 0;
}

/* New values on the same pattern (a changed thickness): zero, re-add every living element in order,
 * so the values are those a fresh assembly gives, and re-factorize without a new analysis. */
static int refill_system(fs_wedge_model *w, double base_thickness)
{
    double t0 = fs_seconds();
    w->assembled_thickness = base_thickness;
    fs_sparse_matrix_zero(&w->k_free);
    for (size_t p = 0; p < w->k_fb.used; p++)
        w->k_fb.value[p] = 0.0;
    memset(w->load, 0, (size_t)FS_WEDGE_PATTERNS * w->n_free * sizeof *w->load);
    if (readd(w, NULL, w->n_elems, NULL) < 0 || refresh_cache(w, NULL, w->n_elems) < 0)
        return -1;
    fix_orphans(w);
    w->counters.assemble_seconds += fs_seconds() - t0;
    return factorize(w, false);
}

/* ---- equilibrium ---- */

/* Displacement of the fixed DOFs at time t: the prescribed values plus the growth motion of the
 * bottom nodes (moving mode). */
static void fixed_displacements(fs_wedge_model *w, double t)
{
    const fs_mesh *m = w->mesh;
    for (int32_t j = 0; j < w->n_fixed; j++) {
        int32_t nd = w->fixed_node_dof[j];
        w->u_fixed[j] = w->prescribed[nd];
    }
    if (w->growth_mode != FS_WEDGE_GROWTH_MOVE)
        return;
    for (int32_t i = 0; i < w->n_nodes; i++) {
        const double *p = m->pos + 3 * (size_t)i;
        double q[3];
        fs_growth_flow(&w->growth, p, 0.0, t, q);
        for (int k = 0; k < 3; k++) {
            int32_t g = w->dof[6 * (size_t)i + k];
            w->u_fixed[g - w->n_free] += q[k] - p[k];
        }
    }
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
 * a stale factor is done by CG to solver.tolerance; the factor is rebuilt only when the mesh has not
 * changed since (fs_wedge_refactor). */
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
            rc = factorize(w, true);
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
    shrink_displacement(w, x, u0);
    for (int a = 0; a < 18; a++)
        ue[a] -= u0[a];
    if (fs_wedge_strain(x, ue, r, s, zeta, strain) < 0)
        return -1;
    stress_of(w, e, strain, stress);
    return 0;
}

/* Per-element cache of what the stress check needs at the three top Gauss points: dN/dx (3 x 18)
 * and the strains of the three shrinkage patterns (3 x 3 x 6), so that a stress costs a few hundred
 * flops. Valid while the element's geometry is: refreshed on assembly, thickness change and
 * subdivision. */
#define GAUSS_CACHE 108

/* Strain (Voigt, engineering shears) of nodal displacements u from the shape-function gradients. */
static void strain_from_gradients(const double dndx[18], const double u[18], double strain[6])
{
    double g[3][3] = {{0}};
    for (int n = 0; n < 6; n++)
        for (int i = 0; i < 3; i++)
            for (int j = 0; j < 3; j++)
                g[i][j] += dndx[3 * n + j] * u[3 * n + i];
    strain[0] = g[0][0];
    strain[1] = g[1][1];
    strain[2] = g[2][2];
    strain[3] = g[0][1] + g[1][0];
    strain[4] = g[1][2] + g[2][1];
    strain[5] = g[2][0] + g[0][2];
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
        double sum = 0.0;
        for (int a = 0; a < 18; a++) {
            double unit[18] = {0}, strain[6];
            unit[a] = 1.0;
            strain_from_gradients(cache + 18 * g, unit, strain);
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

static int refresh_cache(fs_wedge_model *w, const int32_t *elems, int32_t n)
{
    for (int32_t q = 0; q < n; q++) {
        int32_t e = elems ? elems[q] : q;
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        double x[18], pat[FS_WEDGE_PATTERNS][18], detj;
        fs_wedge_element_coords(w, e, x);
        patterns(x, pat);
        double *c = w->gauss_cache + GAUSS_CACHE * (size_t)e;
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

static int cmp_bound_desc(const void *a, const void *b)
{
    const bound_entry *x = a, *y = b;
    if (x->bound != y->bound)
        return x->bound < y->bound ? 1 : -1;
    return (x->e > y->e) - (x->e < y->e);
}

/* design: thesis §5.6.1 evaluates the stress at the three Gauss points nearest the top face ("the
 * resulting 9 values are sorted, and the largest one is compared against the material's threshold
 * stress"). Every fracture decision asks only whether the largest ratio exceeds 1 and which element
 * has it (fracture/rank.h, ties within FS_RANK_TIE_REL), so the shared eigen kernel runs only on the
 * elements whose upper bound (fs_eigen_principal_bound) could reach the largest exact ratio, in
 * descending order of the bound, until the next bound falls below the best exact ratio found (less
 * the tie tolerance). Every other ratio holds its bound.
 * With lazy_ratios, an element evaluated before at the same shrinkage and eigenstrain is not evaluated
 * again while its old bound plus ratio_lipschitz times the change of its nodal displacements stays at
 * most LAZY_LEVEL: that sum bounds the exact ratio too. After a removal the displacements change
 * little away from the crack tip (within a few layer thicknesses), so most elements are skipped. Every
 * element that could be over 1 or tie with a maximum over 1 still gets its full bound, so the
 * candidates, the exact ratios and the decisions are the same as without. */
/* The corners of element e need their nodal ratios recomputed. */
static void touch_nodes(fs_wedge_model *w, int32_t e)
{
    for (int c = 0; c < 3; c++)
        w->node_ratio[w->mesh->tri[3 * (size_t)e + c]] = NAN;
}

static int element_ratios(fs_wedge_model *w, const int32_t *elems, int32_t n_elems)
{
    double t0 = fs_seconds();
    int32_t n_over = 0;
    double coef[FS_WEDGE_PATTERNS];
    fs_wedge_load_coefficients(w, coef);
    if (memcmp(coef, w->ratio_ref_coef, sizeof coef) != 0) {
        for (int32_t e = 0; e < w->n_elems; e++)
            w->ratio_ref_bound[e] = NAN;
        memcpy(w->ratio_ref_coef, coef, sizeof coef);
    }
    for (int32_t q = 0; q < n_elems; q++) {
        int32_t e = elems ? elems[q] : q;
        if (w->state[e] != FS_WEDGE_ALIVE) {
            w->ratio[e] = NAN;
            touch_nodes(w, e);
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
                continue;
            }
        }
        const double *c = w->gauss_cache + GAUSS_CACHE * (size_t)e;
        double *st = w->stress_top + 18 * (size_t)e, bound = -INFINITY;
        for (int g = 0; g < FS_WEDGE_GAUSS_TOP; g++) {
            double strain[6];
            strain_from_gradients(c + 18 * g, ue, strain);
            for (int k = 0; k < 3; k++)
                for (int v = 0; v < 6; v++)
                    strain[v] -= w->shrink_coef[k] * c[54 + 18 * g + 6 * k + v];
            stress_of(w, e, strain, st + 6 * g);
            bound = fmax(bound, fs_eigen_principal_bound(st + 6 * g, w->threshold[e]));
        }
        w->ratio[e] = bound / w->threshold[e];
        w->ratio_ref_bound[e] = w->ratio[e];
        touch_nodes(w, e);
        memcpy(ref_u, ue, sizeof ue);
    }
    for (int32_t e = 0; e < w->n_elems; e++)
        n_over += w->state[e] == FS_WEDGE_ALIVE && w->ratio[e] > 1.0;
    if (n_over > 0) {
        bound_entry *list = fs_malloc((size_t)n_over * sizeof *list);
        int32_t n = 0;
        for (int32_t e = 0; e < w->n_elems; e++)
            if (w->state[e] == FS_WEDGE_ALIVE && w->ratio[e] > 1.0)
                list[n++] = (bound_entry){w->ratio[e], e};
        qsort(list, (size_t)n, sizeof *list, cmp_bound_desc);
        double best = -INFINITY;
        for (int32_t q = 0; q < n; q++) {
            if (list[q].bound < best - 2.0 * FS_RANK_TIE_REL * fabs(best))
                break;
            double r = fs_wedge_element_ratio(w, list[q].e);
            if (isnan(r)) {
                free(list);
                return -1;
            }
            w->ratio[list[q].e] = r;
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
}

int fs_wedge_equilibrium(fs_wedge_model *w, double t)
{
    w->residual_valid = false;
    double h = layer_thickness(w, t);
    if (h != w->assembled_thickness && refill_system(w, h) < 0)
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
    fixed_displacements(w, t);
    fs_wedge_build_rhs(w);
    if ((w->factor_stale && w->cfg.solver.relax != FS_RELAX_LOCAL && factorize(w, false) < 0) || solve(w) < 0)
        return -1;
    scatter_u(w);
    w->time = t;
    return element_ratios(w, NULL, w->n_elems);
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
    scatter_u(w);
    w->time = t;
    return element_ratios(w, NULL, w->n_elems);
}

int fs_wedge_update_ratios(fs_wedge_model *w, const int32_t *elems, int32_t n)
{
    return element_ratios(w, elems, elems ? n : w->n_elems);
}

void fs_wedge_prescribe_fixed(fs_wedge_model *w)
{
    fixed_displacements(w, w->time);
    for (int32_t i = 0; i < w->n_nodes; i++)
        for (int l = 0; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g >= w->n_free)
                w->u[6 * (size_t)i + l] = w->u_fixed[g - w->n_free];
        }
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
    memset(stress, 0, 6 * sizeof *stress);
    int count = 0;
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
        for (int k = 0; k < 6; k++)
            stress[k] += s[k];
        count++;
    }
    for (int k = 0; k < 6 && count; k++)
        stress[k] /= count;
    return count;
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

static void grow_arrays(fs_wedge_model *w, int32_t n_nodes, int32_t n_elems)
{
    size_t nn = (size_t)n_nodes, ne = (size_t)n_elems;
    w->normal = fs_realloc(w->normal, 3 * nn * sizeof *w->normal);
    w->thickness_factor = fs_realloc(w->thickness_factor, nn * sizeof *w->thickness_factor);
    w->pinned = fs_realloc(w->pinned, nn * sizeof *w->pinned);
    w->prescribed = fs_realloc(w->prescribed, 6 * nn * sizeof *w->prescribed);
    w->u = fs_realloc(w->u, 6 * nn * sizeof *w->u);
    w->node_elem_count = fs_realloc(w->node_elem_count, nn * sizeof *w->node_elem_count);
    for (size_t i = (size_t)w->n_nodes; i < nn; i++) {
        w->pinned[i] = 0;
        memset(w->prescribed + 6 * i, 0, 6 * sizeof *w->prescribed);
        memset(w->u + 6 * i, 0, 6 * sizeof *w->u);
        node_normal(w, (int32_t)i, w->normal + 3 * i);
    }
    w->state = fs_realloc(w->state, ne * sizeof *w->state);
    w->young = fs_realloc(w->young, ne * sizeof *w->young);
    w->threshold = fs_realloc(w->threshold, ne * sizeof *w->threshold);
    w->ratio = fs_realloc(w->ratio, ne * sizeof *w->ratio);
    w->stress_top = fs_realloc(w->stress_top, 18 * ne * sizeof *w->stress_top);
    w->gauss_cache = fs_realloc(w->gauss_cache, GAUSS_CACHE * ne * sizeof *w->gauss_cache);
    w->edge_rest = fs_realloc(w->edge_rest, 3 * ne * sizeof *w->edge_rest);
    w->node_ratio = fs_realloc(w->node_ratio, nn * sizeof *w->node_ratio);
    w->node_ratio_exact = fs_realloc(w->node_ratio_exact, nn * sizeof *w->node_ratio_exact);
    for (size_t i = (size_t)w->n_nodes; i < nn; i++) {
        w->node_ratio[i] = NAN;
        w->node_ratio_exact[i] = 0;
    }
    w->ratio_lipschitz = fs_realloc(w->ratio_lipschitz, ne * sizeof *w->ratio_lipschitz);
    w->ratio_ref_bound = fs_realloc(w->ratio_ref_bound, ne * sizeof *w->ratio_ref_bound);
    w->ratio_ref_u = fs_realloc(w->ratio_ref_u, 18 * ne * sizeof *w->ratio_ref_u);
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

    grow_arrays(w, mesh->n_nodes, mesh->n_tris);
    for (int32_t i = 0; i < w->n_nodes; i++)
        w->thickness_factor[i] = node_thickness_factor(w, &cfg->thickness_map, i);
    for (int32_t e = 0; e < w->n_elems; e++)
        element_materials(w, e, &cfg->young_map, &cfg->threshold_map);

    w->assembled_thickness = layer_thickness(w, 0.0);
    if (assemble && build_system(w) < 0) {
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
    return build_system(w);
}

void fs_wedge_free(fs_wedge_model *w)
{
    free(w->normal);
    free(w->thickness_factor);
    free(w->pinned);
    free(w->prescribed);
    free(w->u);
    free(w->state);
    free(w->young);
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
    free(w->dof);
    free(w->fixed_node_dof);
    free(w->node_elem_start);
    free(w->node_elem);
    free(w->node_elem_count);
    free(w->node_elem_room);
    fs_sparse_matrix_free(&w->k_free);
    coupling_free(&w->k_fb);
    free(w->load);
    free(w->rhs);
    free(w->x);
    free(w->u_fixed);
    free(w->mark);
    fs_cholesky_free(w->chol);
    free(w->tip_node);
    free(w->tip_dir);
    free(w->tip_scale);
    free(w->open);
    memset(w, 0, sizeof *w);
}

/* ---- mesh changes: removal (Algorithm 7) and subdivision (Algorithms 8-9) ---- */

/* Rank updates of the factor before a numeric re-factorization instead; the updates cost a small
 * fraction of a factorization each (bench/bench_wedge measures both), and a periodic fresh factor
 * bounds the round-off that downdates accumulate and restores the faster supernodal solves. */
#define UPDOWN_LIMIT 128

/* design: thesis Algorithm 7 (removal by reconstruction), generalised to any set of nodes whose
 * elements changed. Every entry of the system coupling two DOFs of the nodes in S, and every load at
 * those DOFs, is set to zero and rebuilt from the living elements touching S, in ascending element
 * order: the values are then exactly those of a fresh assembly (no drift from repeated subtraction,
 * Algorithm 6), and entries no element feeds any more become exact zeros. */
static int update_region(fs_wedge_model *w, const int32_t *nodes, int32_t n)
{
    for (int32_t q = 0; q < n; q++)
        w->node_ratio[nodes[q]] = NAN; /* their neighbourhoods changed */
    int32_t *dofs = fs_malloc(6 * (size_t)(n ? n : 1) * sizeof *dofs);
    int32_t nd = 0;
    for (int32_t q = 0; q < n; q++)
        for (int l = 0; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)nodes[q] + l];
            if (!w->mark[g]) {
                w->mark[g] = 1;
                dofs[nd++] = g;
            }
        }
    fs_sparse_matrix *k = &w->k_free;
    fs_wedge_coupling *c = &w->k_fb;
    for (int32_t q = 0; q < nd; q++) {
        int32_t j = dofs[q];
        if (j >= w->n_free) {
            int32_t col = j - w->n_free;
            for (int32_t p = c->start[col]; p < c->start[col] + c->len[col]; p++)
                if (w->mark[c->row[p]])
                    c->value[p] = 0.0;
            continue;
        }
        for (int32_t p = k->col_ptr[j]; p < k->col_ptr[j + 1]; p++)
            if (w->mark[k->row_idx[p]])
                k->values[p] = 0.0;
        for (int pat = 0; pat < FS_WEDGE_PATTERNS; pat++)
            w->load[FS_WEDGE_PATTERNS * (size_t)j + pat] = 0.0;
    }
    int32_t cap = 0, ne = 0;
    for (int32_t q = 0; q < n; q++)
        cap += w->node_elem_count[nodes[q]];
    int32_t *elems = fs_malloc((size_t)(cap ? cap : 1) * sizeof *elems);
    for (int32_t q = 0; q < n; q++) {
        int32_t i = nodes[q];
        for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
            if (w->state[w->node_elem[p]] == FS_WEDGE_ALIVE)
                elems[ne++] = w->node_elem[p];
    }
    int32_t unique = fs_sort_unique_int32(elems, ne);
    int rc = readd(w, elems, unique, w->mark);
    for (int32_t q = 0; q < n; q++) {
        int32_t i = nodes[q];
        if (alive_at_node(w, i) > 0)
            continue;
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g < w->n_free)
                k->values[find_entry(k, g, g)] = 1.0;
        }
    }
    for (int32_t q = 0; q < nd; q++)
        w->mark[dofs[q]] = 0;
    free(dofs);
    free(elems);
    return rc;
}

/* Dense Cholesky a = L L' of an m x m symmetric matrix in place (row-major, lower triangle used and
 * overwritten with L, the upper set to 0). Returns 0, or -1 if a pivot is not positive. */
static int dense_cholesky(double *a, int m)
{
    for (int j = 0; j < m; j++) {
        double d = a[m * j + j];
        for (int k = 0; k < j; k++)
            d -= a[m * j + k] * a[m * j + k];
        if (!(d > 0.0))
            return -1;
        d = sqrt(d);
        a[m * j + j] = d;
        for (int i = j + 1; i < m; i++) {
            double v = a[m * i + j];
            for (int k = 0; k < j; k++)
                v -= a[m * i + k] * a[m * j + k];
            a[m * i + j] = v / d;
        }
        for (int i = 0; i < j; i++)
            a[m * i + j] = 0.0;
    }
    return 0;
}

/* design: the factor of K_ff after a removal is that of K_ff - K_e,ff (+ a unit diagonal for DOFs left
 * without an element): a rank-m downdate with W = the Cholesky factor of the element's free-free
 * block (m <= 9, positive definite because the element's bottom is fixed), preceded by a rank update
 * with the unit vectors of the orphaned DOFs so that no intermediate matrix is singular. CHOLMOD
 * changes only the columns of L on the paths from those rows to the root of the elimination tree:
 * far cheaper than a factorization, which is done instead after UPDOWN_LIMIT updates or if a
 * downdate fails numerically. */
static int update_factor_after_removal(fs_wedge_model *w, const double K[324], const int32_t *g,
                                       const int32_t *orphans, int32_t n_orphans)
{
    if (!w->chol)
        return 0;
    if (w->updowns_pending >= UPDOWN_LIMIT)
        return factorize(w, false);
    double t0 = fs_seconds();
    int32_t uniq[18], m = 0, local_to_u[18];
    for (int a = 0; a < 18; a++) {
        local_to_u[a] = -1;
        if (g[a] >= w->n_free)
            continue;
        int u = 0;
        while (u < m && uniq[u] != g[a])
            u++;
        if (u == m)
            uniq[m++] = g[a];
        local_to_u[a] = u;
    }
    double M[18 * 18] = {0};
    for (int a = 0; a < 18; a++)
        for (int c = 0; c < 18; c++)
            if (local_to_u[a] >= 0 && local_to_u[c] >= 0)
                M[m * local_to_u[a] + local_to_u[c]] += K[18 * a + c];
    int rc = 0;
    if (n_orphans > 0) {
        int32_t cp[28], ri[27];
        double v[27];
        for (int32_t q = 0; q < n_orphans; q++) {
            cp[q] = q;
            ri[q] = orphans[q];
            v[q] = 1.0;
        }
        cp[n_orphans] = n_orphans;
        rc = fs_cholesky_updown(w->chol, +1, n_orphans, cp, ri, v);
    }
    if (rc == 0 && m > 0 && dense_cholesky(M, m) == 0) {
        int32_t cp[19], ri[18 * 18];
        double v[18 * 18];
        int32_t nz = 0;
        for (int c = 0; c < m; c++) {
            cp[c] = nz;
            for (int r = c; r < m; r++) {
                ri[nz] = uniq[r];
                v[nz++] = M[m * r + c];
            }
        }
        cp[m] = nz;
        rc = fs_cholesky_updown(w->chol, -1, m, cp, ri, v);
    } else if (m > 0) {
        rc = -1;
    }
    w->counters.update_seconds += fs_seconds() - t0;
    if (rc == 0) {
        w->counters.updowns++;
        w->updowns_pending++;
        return 0;
    }
    fs_error_clear();
    return factorize(w, false);
}

int fs_wedge_remove(fs_wedge_model *w, int32_t e)
{
    w->residual_valid = false; /* see fs_wedge_relax */
    FS_ASSERT(e >= 0 && e < w->n_elems && w->state[e] == FS_WEDGE_ALIVE);
    double K[324], loads[FS_WEDGE_PATTERNS][18];
    if (element_system(w, e, w->assembled_thickness, K, loads) < 0)
        return -1;
    int32_t g[18];
    for (int a = 0; a < 18; a++)
        g[a] = elem_dof(w, e, a);
    double t0 = fs_seconds();
    w->state[e] = FS_WEDGE_REMOVED;
    w->ratio[e] = NAN;
    const int32_t *nodes = w->mesh->tri + 3 * (size_t)e;
    if (update_region(w, nodes, 3) < 0)
        return -1;
    w->counters.assemble_seconds += fs_seconds() - t0;
    int32_t orphans[9], n_orphans = 0;
    for (int c = 0; c < 3; c++) {
        if (alive_at_node(w, nodes[c]) > 0)
            continue;
        for (int k = 3; k < 6; k++) {
            int32_t d = w->dof[6 * (size_t)nodes[c] + k];
            bool seen = false;
            for (int32_t q = 0; q < n_orphans; q++)
                seen |= orphans[q] == d;
            if (d < w->n_free && !seen)
                orphans[n_orphans++] = d;
        }
    }
    w->fractures++;
    w->counters.removals++;
    if (w->cfg.solver.relax == FS_RELAX_LOCAL) {
        w->factor_stale |= w->chol != NULL;
        return 0;
    }
    return update_factor_after_removal(w, K, g, orphans, n_orphans);
}

/* design: the system is extended in place after a subdivision or a cut. New nodes are appended and
 * number_dofs keeps the order of the old DOFs (free ones in node order, then the fixed ones), so old
 * free indices stay and every fixed DOF keeps its column of K_fb. K_ff's new pattern is the old one
 * plus the pairs of the changed elements it lacks and the diagonals of the new DOFs. A cut or a
 * bisection couples old nodes only where they were coupled already, so those pairs are in the new
 * nodes' columns, which come last: the old columns stay where they are. A pair of old nodes not
 * coupled before (an edge flip, say) moves the columns behind it, by a merge from the back that never
 * overwrites an entry not yet read. K_fb's new entries go into their columns in place
 * (fs_wedge_coupling). The arrays grow geometrically, so a cut costs what its elements touch, not a
 * pass over the matrix. Entries whose element vanished stay in the pattern as zeros; new entries are
 * 0 (update_region adds the contributions); the pattern changed, so the factor is analysed afresh. */
static int cmp_int64(const void *a, const void *b)
{
    int64_t x = *(const int64_t *)a, y = *(const int64_t *)b;
    return (x > y) - (x < y);
}

static void push_pair(int64_t **pairs, size_t *np, size_t *cap, int64_t key)
{
    FS_ARRAY_RESERVE(*pairs, *cap, *np + 1, 256);
    (*pairs)[(*np)++] = key;
}

/* Grows an array of n_old elements of the given size to n, zeroing the new ones. */
static void *grow_zeroed(void *a, size_t n_old, size_t n, size_t size)
{
    a = fs_realloc(a, (n ? n : 1) * size);
    if (n > n_old)
        memset((char *)a + n_old * size, 0, (n - n_old) * size);
    return a;
}

static int extend_system(fs_wedge_model *w, int32_t n_free_old, int32_t n_fixed_old, const int32_t *elems,
                         int32_t n_changed)
{
    int32_t nf = w->n_free;
    FS_ASSERT(nf >= n_free_old && w->n_fixed >= n_fixed_old && w->k_fb.n == n_fixed_old);
    fs_sparse_matrix *k = &w->k_free;
    fs_wedge_coupling *c = &w->k_fb;
    coupling_resize(c, w->n_fixed);
    size_t cap = 0, np = 0;
    int64_t *pairs = NULL;
    for (int32_t q = 0; q < n_changed; q++) {
        int32_t e = elems[q];
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        int32_t g[18];
        for (int a = 0; a < 18; a++)
            g[a] = elem_dof(w, e, a);
        for (int a = 0; a < 18; a++)
            for (int b = a; b < 18; b++) {
                int32_t row = g[a] < g[b] ? g[a] : g[b], col = g[a] < g[b] ? g[b] : g[a];
                if (row >= nf)
                    continue; /* fixed-fixed */
                if (col >= nf)
                    coupling_insert(c, col - nf, row);
                else if (col >= n_free_old || find_entry(k, row, col) < 0)
                    push_pair(&pairs, &np, &cap, (int64_t)col * nf + row);
            }
    }
    coupling_compact(c);
    for (int32_t j = n_free_old; j < nf; j++) /* diagonals of the new columns */
        push_pair(&pairs, &np, &cap, (int64_t)j * nf + j);
    if (np == 0) {
        free(pairs);
        goto vectors;
    }
    qsort(pairs, np, sizeof *pairs, cmp_int64);

    /* pass 1: the new starts of columns first .. nf - 1 (those before the first new pair stay) */
    int32_t first = (int32_t)(pairs[0] / nf), span = nf - first;
    int32_t *ptr = fs_malloc(((size_t)span + 1) * sizeof *ptr);
    size_t *pair_start = fs_malloc(((size_t)span + 1) * sizeof *pair_start);
    size_t nz = (size_t)k->col_ptr[first < n_free_old ? first : n_free_old], pp = 0;
    for (int32_t j = first; j < nf; j++) {
        int32_t po = j < n_free_old ? k->col_ptr[j] : 0, po_end = j < n_free_old ? k->col_ptr[j + 1] : 0;
        ptr[j - first] = (int32_t)(nz <= INT32_MAX ? nz : INT32_MAX);
        pair_start[j - first] = pp;
        while (po < po_end || (pp < np && pairs[pp] / nf == j)) {
            int64_t r_old = po < po_end ? k->row_idx[po] : INT64_MAX;
            int64_t r_new = pp < np && pairs[pp] / nf == j ? pairs[pp] % nf : INT64_MAX;
            int64_t r = r_old < r_new ? r_old : r_new;
            po += r_old == r;
            while (pp < np && pairs[pp] / nf == j && pairs[pp] % nf == r)
                pp++;
            nz++;
        }
    }
    pair_start[span] = np;
    if (nz > INT32_MAX) {
        free(pairs);
        free(ptr);
        free(pair_start);
        fs_error(FS_ERR_INTERNAL, "wedge model: the stiffness matrix outgrew 32-bit indices");
        return -1;
    }
    ptr[span] = (int32_t)nz;
    if (nz > w->k_free_capacity) {
        w->k_free_capacity = nz + nz / 2;
        k->row_idx = fs_realloc(k->row_idx, w->k_free_capacity * sizeof *k->row_idx);
        k->values = fs_realloc(k->values, w->k_free_capacity * sizeof *k->values);
    }
    /* pass 2: move the columns, last first */
    for (int32_t j = nf - 1; j >= first;) {
        size_t pb = pair_start[j - first], pe = pair_start[j - first + 1];
        if (pb == pe) { /* a run of old columns without new pairs: j2 .. j */
            int32_t j2 = j;
            while (j2 > first && pair_start[j2 - 1 - first] == pair_start[j2 - first])
                j2--;
            size_t len = (size_t)(k->col_ptr[j + 1] - k->col_ptr[j2]);
            if (ptr[j2 - first] != k->col_ptr[j2]) {
                memmove(k->row_idx + ptr[j2 - first], k->row_idx + k->col_ptr[j2], len * sizeof *k->row_idx);
                memmove(k->values + ptr[j2 - first], k->values + k->col_ptr[j2], len * sizeof *k->values);
            }
            j = j2 - 1;
            continue;
        }
        int64_t o = j < n_free_old ? k->col_ptr[j + 1] - 1 : -1, o_begin = j < n_free_old ? k->col_ptr[j] : 0;
        int64_t q = (int64_t)pe - 1, d = ptr[j - first + 1] - 1;
        while (o >= o_begin || q >= (int64_t)pb) {
            int64_t r_old = o >= o_begin ? k->row_idx[o] : -1;
            int64_t r_new = q >= (int64_t)pb ? pairs[q] % nf : -1;
            int64_t r = r_old > r_new ? r_old : r_new;
            double v = r_old == r ? k->values[o--] : 0.0;
            while (q >= (int64_t)pb && pairs[q] % nf == r)
                q--;
            k->row_idx[d] = (int32_t)r;
            k->values[d--] = v;
        }
        FS_ASSERT(d + 1 == ptr[j - first]);
        j--;
    }
    k->col_ptr = fs_realloc(k->col_ptr, ((size_t)nf + 1) * sizeof *k->col_ptr);
    memcpy(k->col_ptr + first, ptr, ((size_t)span + 1) * sizeof *ptr);
    k->n = nf;
    free(pairs);
    free(ptr);
    free(pair_start);

vectors:;
    if (nf > w->load_capacity) {
        w->load_capacity = nf + nf / 2;
        w->load = fs_realloc(w->load, (size_t)FS_WEDGE_PATTERNS * w->load_capacity * sizeof *w->load);
    }
    memset(w->load + FS_WEDGE_PATTERNS * (size_t)n_free_old, 0,
           FS_WEDGE_PATTERNS * (size_t)(nf - n_free_old) * sizeof *w->load);
    w->rhs = fs_realloc(w->rhs, ((size_t)nf + 1) * sizeof *w->rhs);
    w->x = grow_zeroed(w->x, (size_t)n_free_old, (size_t)nf + 1, sizeof *w->x);
    w->u_fixed = fs_realloc(w->u_fixed, ((size_t)w->n_fixed + 1) * sizeof *w->u_fixed);
    w->mark = grow_zeroed(w->mark, (size_t)n_free_old + (size_t)n_fixed_old + 1, (size_t)nf + w->n_fixed + 1,
                          sizeof *w->mark);
    return 0;
}

/* After the sparsity pattern changed: a new analysis and factorization, or with local relaxation
 * none (the factor is dropped and the global solves use CG until fs_wedge_refactor, see solve()). */
static int pattern_changed(fs_wedge_model *w)
{
    if (w->cfg.solver.relax == FS_RELAX_LOCAL && w->cfg.solver.method == FS_SOLVER_CHOLMOD) {
        fs_cholesky_free(w->chol);
        w->chol = NULL;
        w->factor_stale = true;
        return 0;
    }
    return factorize(w, true);
}

/* Marks the listed triangles and returns their descendants after one refinement call: a listed
 * triangle keeps its slot and new triangles name their pre-call ancestor. */
static int32_t descendants(const fs_refine_change *ch, const int32_t *list, int32_t n, uint8_t *flag, int32_t *out)
{
    int32_t m = 0;
    for (int32_t q = 0; q < n; q++)
        if (!flag[list[q]]) {
            flag[list[q]] = 1;
            out[m++] = list[q];
        }
    for (int32_t q = 0; q < ch->n_new_tris; q++)
        if (flag[ch->tri_parent[q]])
            out[m++] = ch->n_tris_before + q;
    for (int32_t q = 0; q < n; q++)
        flag[list[q]] = 0;
    return m;
}

int fs_wedge_subdivide(fs_wedge_model *w, const int32_t *elems, int32_t n, bool to_min_size, int32_t *bisected)
{
    w->residual_valid = false; /* see fs_wedge_relax */
    double t0 = fs_seconds();
    *bisected = 0;
    int32_t n_tris0 = w->n_elems, n_free_old = w->n_free, n_fixed_old = w->n_fixed;
    double min_size = w->cfg.mesh.min_size;
    uint8_t *changed_old = fs_calloc((size_t)n_tris0 + 1, 1);
    int32_t *list = fs_malloc((size_t)(n ? n : 1) * sizeof *list);
    memcpy(list, elems, (size_t)n * sizeof *list);
    int32_t n_list = n;
    fs_refine_change ch = {0};
    while (n_list > 0) {
        if (fs_refine_bisect(w->mesh, list, n_list, min_size, &ch) < 0) {
            free(list);
            free(changed_old);
            fs_refine_change_free(&ch);
            return -1;
        }
        if (ch.n_bisections == 0)
            break;
        *bisected += ch.n_bisections;
        w->open_valid = false;
        grow_arrays(w, w->mesh->n_nodes, w->mesh->n_tris);
        for (int32_t q = 0; q < ch.n_new_nodes; q++) {
            int32_t i = ch.n_nodes_before + q;
            w->thickness_factor[i] =
                0.5 * (w->thickness_factor[ch.node_parent[2 * q]] + w->thickness_factor[ch.node_parent[2 * q + 1]]);
        }
        for (int32_t q = 0; q < ch.n_new_tris; q++) {
            int32_t e = ch.n_tris_before + q, parent = ch.tri_parent[q];
            w->state[e] = w->state[parent];
            w->young[e] = w->young[parent];
            w->threshold[e] = w->threshold[parent];
        }
        for (int32_t q = 0; q < ch.n_changed_tris; q++)
            if (ch.changed_tri[q] < n_tris0)
                changed_old[ch.changed_tri[q]] = 1;
        if (!to_min_size)
            break;
        /* the next level: the listed triangles' descendants still at or above min_size */
        uint8_t *flag = fs_calloc((size_t)w->n_elems, 1);
        int32_t *next = fs_malloc(((size_t)n_list + ch.n_new_tris + 1) * sizeof *next);
        int32_t m = descendants(&ch, list, n_list, flag, next), kept = 0;
        free(flag);
        for (int32_t q = 0; q < m; q++)
            if (fs_refine_tri_size(w->mesh, next[q]) >= min_size)
                next[kept++] = next[q];
        free(list);
        list = next;
        n_list = kept;
    }
    free(list);
    fs_refine_change_free(&ch);
    if (*bisected == 0) {
        free(changed_old);
        return 0;
    }
    w->counters.subdivisions += *bisected;
    number_dofs(w);
    build_node_elems(w);
    int32_t n_changed = 0;
    int32_t *changed = fs_malloc(((size_t)w->n_elems + 1) * sizeof *changed);
    for (int32_t e = 0; e < n_tris0; e++)
        if (changed_old[e])
            changed[n_changed++] = e;
    for (int32_t e = n_tris0; e < w->n_elems; e++)
        changed[n_changed++] = e;
    free(changed_old);
    int32_t *nodes = fs_malloc(3 * (size_t)(n_changed ? n_changed : 1) * sizeof *nodes);
    for (int32_t q = 0; q < n_changed; q++)
        for (int c = 0; c < 3; c++)
            nodes[3 * q + c] = w->mesh->tri[3 * (size_t)changed[q] + c];
    int rc = extend_system(w, n_free_old, n_fixed_old, changed, n_changed);
    if (rc == 0)
        rc = update_region(w, nodes, 3 * n_changed);
    if (rc == 0)
        rc = refresh_cache(w, changed, n_changed);
    free(changed);
    free(nodes);
    w->counters.assemble_seconds += fs_seconds() - t0;
    if (rc < 0)
        return -1;
    return pattern_changed(w);
}

int fs_wedge_refactor(fs_wedge_model *w)
{
    return factorize(w, false);
}

/* The rows of f - K u of these nodes changed (wedge/relax.c keeps the rest of the residual between
 * events); nothing to record while there is no kept residual (global relaxation, or after anything
 * that invalidated it: the next fs_wedge_relax computes it in full). */
static void mark_dirty(fs_wedge_model *w, const int32_t *nodes, int32_t nn)
{
    if (!w->residual_valid)
        return;
    FS_ARRAY_RESERVE(w->dirty_nodes, w->cap_dirty, w->n_dirty + nn, 64);
    memcpy(w->dirty_nodes + w->n_dirty, nodes, (size_t)nn * sizeof *nodes);
    w->n_dirty += nn;
}

int fs_wedge_apply_change(fs_wedge_model *w, const fs_wedge_change *c)
{
    double t0 = fs_seconds();
    w->open_valid = false;
    int32_t n_free_old = w->n_free, n_fixed_old = w->n_fixed, n0 = c->n_nodes_before, e0 = c->n_tris_before;
    grow_arrays(w, w->mesh->n_nodes, w->mesh->n_tris);
    for (int32_t i = n0; i < w->n_nodes; i++) {
        int32_t a = c->node_parent[2 * (i - n0)], b = c->node_parent[2 * (i - n0) + 1];
        double s = c->node_weight[i - n0];
        w->thickness_factor[i] = (1.0 - s) * w->thickness_factor[a] + s * w->thickness_factor[b];
        w->pinned[i] = w->pinned[a];
        for (int l = 0; l < 6; l++) {
            w->u[6 * (size_t)i + l] = (1.0 - s) * w->u[6 * (size_t)a + l] + s * w->u[6 * (size_t)b + l];
            w->prescribed[6 * (size_t)i + l] =
                (1.0 - s) * w->prescribed[6 * (size_t)a + l] + s * w->prescribed[6 * (size_t)b + l];
        }
    }
    for (int32_t e = e0; e < w->n_elems; e++) {
        int32_t parent = c->tri_parent[e - e0];
        w->state[e] = w->state[parent];
        w->young[e] = w->young[parent];
        w->threshold[e] = w->threshold[parent];
    }
    number_dofs(w);
    update_node_elems(w, n0, e0, c->changed, c->n_changed, c->node_parent, 2 * (w->n_nodes - n0));
    int32_t n_changed = c->n_changed + (w->n_elems - e0);
    int32_t *changed = fs_malloc(((size_t)n_changed + 1) * sizeof *changed);
    memcpy(changed, c->changed, (size_t)c->n_changed * sizeof *changed);
    for (int32_t e = e0; e < w->n_elems; e++)
        changed[c->n_changed + (e - e0)] = e;
    /* the nodes whose couplings are rebuilt: those of the changed elements, and every node that lost
     * an element to a copy (a parent of a new node) */
    int32_t n_new = w->n_nodes - n0;
    int32_t *nodes = fs_malloc((3 * (size_t)n_changed + 2 * (size_t)n_new + 1) * sizeof *nodes);
    int32_t nn = 0;
    for (int32_t q = 0; q < n_changed; q++)
        for (int k = 0; k < 3; k++)
            nodes[nn++] = w->mesh->tri[3 * (size_t)changed[q] + k];
    for (int32_t q = 0; q < 2 * n_new; q++)
        nodes[nn++] = c->node_parent[q];
    int rc = extend_system(w, n_free_old, n_fixed_old, changed, n_changed);
    if (rc == 0)
        rc = update_region(w, nodes, nn);
    mark_dirty(w, nodes, nn);
    if (rc == 0)
        rc = refresh_cache(w, changed, n_changed);
    if (rc == 0) /* the stresses of the changed elements at the displacements carried over */
        rc = element_ratios(w, changed, n_changed);
    for (int32_t i = 0; i < w->n_nodes && rc == 0; i++)
        for (int l = 3; l < 6; l++) {
            int32_t g = w->dof[6 * (size_t)i + l];
            if (g < w->n_free)
                w->x[g] = w->u[6 * (size_t)i + l];
        }
    free(changed);
    free(nodes);
    w->counters.assemble_seconds += fs_seconds() - t0;
    if (rc < 0)
        return -1;
    return pattern_changed(w);
}

int fs_wedge_update_geometry(fs_wedge_model *w, const int32_t *elems, int32_t n)
{
    double t0 = fs_seconds();
    int32_t *nodes = fs_malloc((3 * (size_t)n + 1) * sizeof *nodes);
    int32_t nn = 0;
    for (int32_t q = 0; q < n; q++)
        for (int k = 0; k < 3; k++)
            nodes[nn++] = w->mesh->tri[3 * (size_t)elems[q] + k];
    int rc = update_region(w, nodes, nn);
    mark_dirty(w, nodes, nn);
    if (rc == 0)
        rc = refresh_cache(w, elems, n);
    if (rc == 0)
        rc = element_ratios(w, elems, n);
    free(nodes);
    w->counters.assemble_seconds += fs_seconds() - t0;
    if (rc < 0)
        return -1;
    if (w->cfg.solver.relax == FS_RELAX_LOCAL && w->cfg.solver.method == FS_SOLVER_CHOLMOD) {
        w->factor_stale = true; /* the analysis still fits: fs_wedge_refactor only re-factorizes */
        return 0;
    }
    return factorize(w, false);
}

double fs_wedge_element_energy(const fs_wedge_model *w, int32_t e)
{
    if (w->state[e] != FS_WEDGE_ALIVE)
        return 0.0;
    double K[324], loads[FS_WEDGE_PATTERNS][18], x[18], pat[FS_WEDGE_PATTERNS][18], ue[18];
    if (element_system(w, e, w->assembled_thickness, K, loads) < 0) {
        fs_error_clear();
        return NAN;
    }
    fs_wedge_element_coords(w, e, x);
    patterns(x, pat);
    gather_u(w, e, ue);
    double coef[FS_WEDGE_PATTERNS];
    fs_wedge_load_coefficients(w, coef);
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
    return 0.5 * energy;
}

fs_wedge_params fs_wedge_params_default(void) { return (fs_wedge_params){.thickness_gradient = 0.0}; }
