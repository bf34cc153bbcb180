/* The wedge model's global system: DOF numbering, node element lists, element matrices, the sparse K_ff and its coupling K_fb, assembly and factorization (thesis §5.4-5.5). */
#include "model/wedge/internal.h"

#include "config.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "base/error.h"
#include "base/log.h"
#include "base/sort.h"
#include "base/threads.h"
#include "model/wedge/element.h"

/* ---- DOFs and node -> element lists ---- */

int32_t fs_wedge_elem_dof(const fs_wedge_model *w, int32_t e, int a)
{
    int32_t node = w->mesh->tri[3 * (size_t)e + (a / 3) % 3];
    int local = a / 9 ? 3 : 0; /* a in 0..17: node a / 3, bottom for nodes 0..2 */
    return w->dof[6 * (size_t)node + local + a % 3];
}

/* Room in dof and fixed_node_dof for n nodes (with the per-node arrays' room, fs_wedge_grow_arrays). */
static void dof_reserve(fs_wedge_model *w, int32_t n)
{
    if (w->dof_cap < n) {
        w->dof_cap = w->node_cap > n ? w->node_cap : n;
        FS_ARRAY_RESIZE(w->dof, 6 * (size_t)w->dof_cap);
        FS_ARRAY_RESIZE(w->fixed_node_dof, 6 * (size_t)w->dof_cap);
    }
}

/* Numbers the DOFs: free ones (top nodes not pinned) first in node order, then the fixed ones. Nothing
 * kept from the old numbering survives it (the fixed displacements, x in step with u). */
void fs_wedge_number_dofs(fs_wedge_model *w)
{
    int32_t n = w->n_nodes, next = 0;
    dof_reserve(w, n);
    for (int32_t i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            w->dof[6 * (size_t)i + 3 + k] = w->pinned[i] ? -1 : next++;
    w->n_free = next;
    for (int32_t i = 0; i < n; i++)
        for (int l = 0; l < 6; l++) {
            int32_t *d = w->dof + 6 * (size_t)i + l;
            if (l < 3 || *d < 0) {
                w->fixed_node_dof[next - w->n_free] = 6 * i + l;
                *d = next++;
            }
        }
    w->n_fixed = next - w->n_free;
    w->fixed_exact = 0;
    w->x_synced = false;
    w->pattern_version++;
}

/* fs_wedge_number_dofs after nodes n0 .. n_nodes - 1 were appended (a cut's copies), the nodes before
 * keeping their pinned flags: those keep their free indices and their places among the fixed DOFs
 * (whose indices move up by the new free DOFs, so the kept fixed displacements stay valid), and the
 * new nodes' DOFs come after, free and fixed. The same numbering, without numbering every node again. */
void fs_wedge_number_appended(fs_wedge_model *w, int32_t n0)
{
    int32_t n = w->n_nodes, nf0 = w->n_free, next = nf0;
    dof_reserve(w, n);
    for (int32_t i = n0; i < n; i++)
        for (int k = 0; k < 3; k++)
            w->dof[6 * (size_t)i + 3 + k] = w->pinned[i] ? -1 : next++;
    int32_t shift = next - nf0, j = w->n_fixed;
    w->n_free = next;
    for (int32_t i = 0; i < n0 && shift > 0; i++)
        for (int l = 0; l < 6; l++)
            if (w->dof[6 * (size_t)i + l] >= nf0)
                w->dof[6 * (size_t)i + l] += shift;
    for (int32_t i = n0; i < n; i++)
        for (int l = 0; l < 6; l++) {
            int32_t *d = w->dof + 6 * (size_t)i + l;
            if (l < 3 || *d < 0) {
                w->fixed_node_dof[j] = 6 * i + l;
                *d = w->n_free + j++;
            }
        }
    w->n_fixed = j;
    w->x_synced = false;
    w->pattern_version++;
#ifdef FS_VALIDATE
    int32_t *dof = fs_malloc(6 * (size_t)n * sizeof *dof), *fixed = fs_malloc(((size_t)j + 1) * sizeof *fixed);
    memcpy(dof, w->dof, 6 * (size_t)n * sizeof *dof);
    memcpy(fixed, w->fixed_node_dof, (size_t)j * sizeof *fixed);
    int32_t exact = w->fixed_exact;
    fs_wedge_number_dofs(w);
    w->fixed_exact = exact;
    FS_INVARIANT(w->n_free == next && w->n_fixed == j && memcmp(dof, w->dof, 6 * (size_t)n * sizeof *dof) == 0 &&
                     memcmp(fixed, w->fixed_node_dof, (size_t)j * sizeof *fixed) == 0,
                 "wedge model: the numbering of %d nodes appended to %d differs from numbering them all", n - n0, n0);
    free(dof);
    free(fixed);
#endif
}

/* Room each node's element list gets beyond its entries, so that cuts update it in place. */
#define NODE_ELEM_SLACK 3

void fs_wedge_build_node_elems(fs_wedge_model *w)
{
    int32_t n = w->n_nodes;
    free(w->node_elem_start);
    free(w->node_elem);
    w->node_elem_start = fs_calloc((size_t)w->node_cap + 1, sizeof *w->node_elem_start);
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
    FS_ARRAY_RESIZE(w->node_elem_room, (size_t)w->node_cap + 1);
    w->node_elem_cap = w->node_cap;
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
void fs_wedge_update_node_elems(fs_wedge_model *w, int32_t n0, int32_t e0, const int32_t *changed, int32_t n_changed,
                              const int32_t *lost, int32_t nl)
{
    const fs_mesh *m = w->mesh;
    int32_t n_new_elems = w->n_elems - e0;
    int32_t *cand = fs_malloc(((size_t)n_changed + n_new_elems + 64) * sizeof *cand);
    int32_t cap_cand = n_changed + n_new_elems + 64;
    if (w->node_elem_cap < w->node_cap) {
        FS_ARRAY_RESIZE(w->node_elem_start, (size_t)w->node_cap + 1);
        FS_ARRAY_RESIZE(w->node_elem_room, (size_t)w->node_cap + 1);
        w->node_elem_cap = w->node_cap;
    }
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
        fs_wedge_build_node_elems(w);
}

/* Living elements that use node i. */
int32_t fs_wedge_alive_at_node(const fs_wedge_model *w, int32_t i)
{
    int32_t count = 0;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
        count += w->state[w->node_elem[p]] == FS_WEDGE_ALIVE;
    return count;
}

/* ---- element matrices ---- */

/* design: a layer whose thickness changes in time ([material] thickness_final) is assembled anew at
 * every equilibrium at a new thickness. On a flat frame an element is a prism whose top corners lie
 * h f_i above its bottom corners (h the base thickness, f_i the nodes' thickness factors), so with
 * z = zeta h F(xi, eta) its Jacobian's determinant is h F det J2 and its strain-displacement
 * matrix is a part free of h plus 1 / h times the d/dzeta part: over the same Gauss points the
 * stiffness is exactly K(h) = h K1 + K0 + K2 / h. The three parts are fitted from the stiffness at
 * h / 2, h and 2 h the second time an element is assembled with the same inputs (k_key: corners,
 * thickness factors, Young's modulus; the first time it is integrated directly, so that a layer
 * whose corners move, as under growth on a plane that does not wrap, costs no more than without
 * the parts), and refitted when the inputs change; every other thickness costs two multiply-adds
 * an entry instead of a quadrature. */
static int element_stiffness(const fs_wedge_model *w, int32_t e, double h, const double x[18], const double D[36],
                             double K[324])
{
    if (!w->k_parts_on)
        return fs_wedge_stiffness(x, D, K);
    double key[FS_WEDGE_K_KEY];
    for (int c = 0; c < 3; c++) {
        key[2 * c] = x[3 * c];
        key[2 * c + 1] = x[3 * c + 1];
        key[6 + c] = w->thickness_factor[w->mesh->tri[3 * (size_t)e + c]];
    }
    key[9] = w->young[e];
    double *parts = w->k_parts + 3 * FS_WEDGE_PAIRS * (size_t)e, *kept = w->k_key + FS_WEDGE_K_KEY * (size_t)e;
    if (memcmp(key, kept, sizeof key) != 0) { /* new inputs: integrate, fit next time */
        memcpy(kept, key, sizeof key);
        parts[0] = NAN;
        return fs_wedge_stiffness(x, D, K);
    }
    if (isnan(parts[0])) {
        /* K(a_i) = a_i K1 + K0 + K2 / a_i at a = h/2, h, 2h, solved for the parts entry by entry:
         * the inverse of [[a_i, 1, 1/a_i]] is [[2, -6, 4], [-6, 15, -6], [4, -6, 2]] / 3 with its
         * rows scaled by 1/h, 1 and h */
        static const double inv[3][3] = {{2.0, -6.0, 4.0}, {-6.0, 15.0, -6.0}, {4.0, -6.0, 2.0}};
        double (*ka)[324] = fs_malloc(3 * sizeof *ka), xa[18];
        for (int i = 0; i < 3; i++) {
            fs_wedge_coords_at(w, e, h * (i == 0 ? 0.5 : i == 1 ? 1.0 : 2.0), xa);
            if (fs_wedge_stiffness(xa, D, ka[i]) < 0) {
                free(ka);
                return -1;
            }
        }
        double row_scale[3] = {1.0 / (3.0 * h), 1.0 / 3.0, h / 3.0};
        for (int j = 0; j < 3; j++)
            for (int a = 0, q = 0; a < 18; a++)
                for (int c = a; c < 18; c++, q++) {
                    int p = 18 * a + c;
                    parts[FS_WEDGE_PAIRS * j + q] =
                        row_scale[j] * (inv[j][0] * ka[0][p] + inv[j][1] * ka[1][p] + inv[j][2] * ka[2][p]);
                }
        free(ka);
    }
    /* the parts are symmetric (the quadrature's stiffness is, entry for entry): their upper triangles */
    for (int a = 0, q = 0; a < 18; a++)
        for (int c = a; c < 18; c++, q++)
            K[18 * a + c] = K[18 * c + a] =
                h * parts[q] + parts[FS_WEDGE_PAIRS + q] + parts[2 * FS_WEDGE_PAIRS + q] / h;
    return 0;
}

int fs_wedge_element_stiffness(const fs_wedge_model *w, int32_t e, double base_thickness, double x[18], double K[324])
{
    double D[36];
    fs_wedge_coords_at(w, e, base_thickness, x);
    for (int i = 0; i < 36; i++)
        D[i] = w->young[e] * w->d_unit[i];
    if (element_stiffness(w, e, base_thickness, x, D, K) < 0) {
        fs_error(FS_ERR_DATA, "wedge model: element %d is inverted or degenerate (%s)", (int)e, fs_error_message());
        return -1;
    }
    return 0;
}

bool fs_wedge_stiffness_repeats(const fs_wedge_model *w, int32_t e)
{
    return !w->k_parts_on || !isnan(w->k_parts[3 * FS_WEDGE_PAIRS * (size_t)e]);
}

int fs_wedge_element_system(const fs_wedge_model *w, int32_t e, double base_thickness, double K[324],
                             double loads[FS_WEDGE_PATTERNS][18])
{
    double x[18];
    if (fs_wedge_element_stiffness(w, e, base_thickness, x, K) < 0)
        return -1;
    double pat[FS_WEDGE_PATTERNS][18];
    fs_wedge_patterns(x, pat);
    int npat = w->growth_mode == FS_WEDGE_GROWTH_EIGENSTRAIN ? FS_WEDGE_PATTERNS : 3;
    memset(loads, 0, sizeof(double) * FS_WEDGE_PATTERNS * 18);
    /* K pat over the pattern's nonzero entries (a pattern moves a third to a half of the element's
     * unknowns), in ascending order: the other terms are exact zeros, so the sums are the full ones
     * bit for bit */
    for (int q = 0; q < npat; q++) {
        int nz[18], count = 0;
        for (int c = 0; c < 18; c++)
            if (pat[q][c] != 0.0)
                nz[count++] = c;
        for (int a = 0; a < 18; a++) {
            double s = 0.0;
            for (int t = 0; t < count; t++)
                s += K[18 * a + nz[t]] * pat[q][nz[t]];
            loads[q][a] = s;
        }
    }
    return 0;
}

/* ---- the sparse system ---- */


int32_t fs_wedge_find_entry(const fs_sparse_matrix *m, int32_t i, int32_t j)
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

void fs_wedge_coupling_free(fs_wedge_coupling *c)
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
void fs_wedge_coupling_resize(fs_wedge_coupling *c, int32_t n)
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
    fs_wedge_coupling_free(c);
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
void fs_wedge_coupling_insert(fs_wedge_coupling *c, int32_t k, int32_t row)
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
void fs_wedge_coupling_compact(fs_wedge_coupling *c)
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
        return fs_wedge_find_entry(&w->k_free, row, col);
    int32_t p = coupling_search(&w->k_fb, col - w->n_free, row);
    return p >= 0 ? p : -1;
}

double fs_wedge_system_entry(const fs_wedge_model *w, int32_t g, int32_t j)
{
    bool in_fb;
    int32_t p = system_slot(w, g, j, &in_fb);
    return p < 0 ? 0.0 : in_fb ? w->k_fb.value[p] : w->k_free.values[p];
}

/* Calls add(ctx, q, i, j, value) for every kept pair q (a <= c, counted row by row, FS_WEDGE_PAIRS in
 * all) of the element: fixed-fixed pairs are left out; two local DOFs on one global DOF (a node
 * repeated in a tiny periodic mesh) add the off-diagonal term twice, as the full matrix would. */
static void element_pairs(const fs_wedge_model *w, int32_t e, const double K[324],
                          void (*add)(void *ctx, int q, int32_t i, int32_t j, double v), void *ctx)
{
    int32_t g[18];
    for (int a = 0; a < 18; a++)
        g[a] = fs_wedge_elem_dof(w, e, a);
    for (int a = 0, q = 0; a < 18; a++)
        for (int c = a; c < 18; c++, q++) {
            if (g[a] >= w->n_free && g[c] >= w->n_free)
                continue;
            double v = K[18 * a + c];
            if (c != a && g[a] == g[c])
                v *= 2.0;
            add(ctx, q, g[a], g[c], v);
        }
}

static void add_to_builder(void *ctx, int q, int32_t i, int32_t j, double v)
{
    (void)q;
    fs_sparse_builder_add(ctx, i, j, v);
}

static void add_loads(fs_wedge_model *w, int32_t e, const double loads[FS_WEDGE_PATTERNS][18], const uint8_t *only)
{
    for (int a = 0; a < 18; a++) {
        int32_t g = fs_wedge_elem_dof(w, e, a);
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
        if (fs_wedge_alive_at_node(w, i) > 0)
            continue;
        for (int k = 3; k < 6; k++) {
            int32_t g = w->dof[6 * (size_t)i + k];
            if (g < w->n_free) {
                int32_t p = fs_wedge_find_entry(&w->k_free, g, g);
                FS_ASSERT(p >= 0);
                w->k_free.values[p] = 1.0;
            }
        }
    }
}

/* fs_node_neighbours_fn of the wedge model: the corners of node i's elements, dead ones too. */
static int32_t element_neighbours(void *ctx, int32_t i, int32_t *out, int32_t cap)
{
    const fs_wedge_model *w = ctx;
    int32_t n = 0;
    for (int32_t p = w->node_elem_start[i]; p < w->node_elem_start[i] + w->node_elem_count[i]; p++)
        for (int c = 0; c < 3; c++, n++)
            if (n < cap)
                out[n] = w->mesh->tri[3 * (size_t)w->node_elem[p] + c];
    return n;
}

/* design: the pattern changes with every cascade of cuts, and each change needs a new analysis: it is
 * made in the order kept across the cuts (solve/node_order.h), a node a cut made placed at its nearer
 * parent. */
int fs_wedge_factorize(fs_wedge_model *w, bool analyze)
{
#ifdef FS_VALIDATE
    fs_wedge_check_system(w, "assembly");
#endif
    if (w->cfg.solver.method != FS_SOLVER_CHOLMOD || w->n_free == 0)
        return 0;
    double t0 = fs_seconds();
    if (analyze || !w->chol) {
        fs_cholesky_free(w->chol);
        fs_node_dofs dofs = {w->dof, 6, 3, 3, w->n_free};
        w->chol = fs_node_order_analyze(&w->order, &w->k_free, w->n_nodes, &dofs, w->origin, element_neighbours, w,
                                        NULL);
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
int fs_wedge_build_system(fs_wedge_model *w)
{
    double t0 = fs_seconds();
    fs_wedge_number_dofs(w);
    fs_wedge_build_node_elems(w);
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
        if (fs_wedge_element_system(w, e, w->assembled_thickness, K, loads) < 0) {
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
    if (fs_wedge_refresh_cache(w, NULL, w->n_elems) < 0)
        return -1;
    w->counters.assemble_seconds += fs_seconds() - t0;
    return fs_wedge_factorize(w, true);
}

typedef struct {
    fs_wedge_model *w;
    const uint8_t *only; /* if not NULL: add only where both DOFs are marked */
} refill_ctx;

static void add_in_place(void *ctx, int q, int32_t i, int32_t j, double v)
{
    (void)q;
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
int fs_wedge_readd(fs_wedge_model *w, const int32_t *elems, int32_t n, const uint8_t *only)
{
    double K[324], loads[FS_WEDGE_PATTERNS][18];
    refill_ctx r = {w, only};
    for (int32_t q = 0; q < n; q++) {
        int32_t e = elems ? elems[q] : q;
        if (w->state[e] != FS_WEDGE_ALIVE)
            continue;
        if (fs_wedge_element_system(w, e, w->assembled_thickness, K, loads) < 0)
            return -1;
        element_pairs(w, e, K, add_in_place, &r);
        add_loads(w, e, loads, only);
    }
    return 0;
}

/* design: a layer that thickens is refilled at every equilibrium at a new thickness, every element
 * anew. Its element systems (each element writing only its own slots, its stiffness parts included)
 * are computed on several threads a chunk at a time (a quarter of the elements, at least 64 and at
 * most REFILL_CHUNK) into one of two buffers, and added into the pattern in element order, one chunk
 * by one thread while the other threads compute the next chunk into the other buffer (the adding
 * reads nothing the computing writes): the values are those of one loop, whatever the threads. Where
 * each pair of an element's DOFs lies in the pattern is looked up once per pattern (on the threads
 * too) and kept in refill_slot: the event search refills the same pattern at several thicknesses
 * between cuts. */
#define REFILL_CHUNK 4096

/* refill_slot entries: a slot of k_free (>= 0), of k_fb (-2 - slot), or a fixed-fixed pair left out */
#define SLOT_NONE (-1)

typedef struct {
    fs_wedge_model *w;
    int32_t e0;
    bool slots;                             /* look the slots up too */
    double *k;                              /* a chunk's stiffness matrices */
    double (*loads)[FS_WEDGE_PATTERNS][18]; /* and their loads */
    uint8_t *failed;                        /* per element of the chunk: its system or cache failed */
    int32_t *slot;                          /* the current element's refill_slot entries */
} refill_chunk;

/* element_pairs' callback that records where pair q lies (the value is not used). */
static void record_slot(void *ctx, int q, int32_t i, int32_t j, double v)
{
    (void)v;
    const refill_chunk *c = ctx;
    bool in_fb;
    int32_t p = system_slot(c->w, i, j, &in_fb);
    FS_ASSERT(p >= 0);
    c->slot[q] = in_fb ? -2 - p : p;
}

static void refill_range(void *ctx, int32_t i0, int32_t i1)
{
    const refill_chunk *c = ctx;
    fs_wedge_model *w = c->w;
    for (int32_t i = i0; i < i1; i++) {
        int32_t e = c->e0 + i;
        c->failed[i] = w->state[e] == FS_WEDGE_ALIVE &&
                       fs_wedge_element_system(w, e, w->assembled_thickness, c->k + 324 * (size_t)i, c->loads[i]) < 0;
        if (c->slots && w->state[e] == FS_WEDGE_ALIVE) {
            /* each thread its own view of the chunk, pointing at the element's slots */
            refill_chunk mine = *c;
            mine.slot = w->refill_slot + FS_WEDGE_PAIRS * (size_t)e;
            for (int q = 0; q < FS_WEDGE_PAIRS; q++)
                mine.slot[q] = SLOT_NONE;
            element_pairs(w, e, c->k + 324 * (size_t)i, record_slot, &mine);
        }
    }
}

/* element_pairs' callback that adds pair q's value at its kept slot. */
static void add_at_slot(void *ctx, int q, int32_t i, int32_t j, double v)
{
    (void)i;
    (void)j;
    refill_chunk *c = ctx;
    if (c->slot[q] >= 0)
        c->w->k_free.values[c->slot[q]] += v;
    else
        c->w->k_fb.value[-2 - c->slot[q]] += v;
}

/* One round of the refill: item 0 adds chunk `add` (computed, n_add elements) into the pattern in
 * element order, items 1 .. FS_RANGE_PARTS compute the parts of chunk `next` (n_next elements). */
typedef struct {
    refill_chunk *add, *next;
    int32_t n_add, n_next;
    int32_t failed_at; /* the first element of add whose system failed (not added), else -1 */
} refill_round;

/* Adds the elements of chunk r->add from `from` on into the pattern, in element order. An element
 * whose system failed stops it (failed_at), unless retry is set: then its system is computed again on
 * this thread (an error is the thread's own, and its message is wanted) and added if that succeeds.
 * Returns 0, or -1 with fs_error. */
static int add_chunk(refill_round *r, int32_t from, bool retry)
{
    refill_chunk *c = r->add;
    fs_wedge_model *w = c->w;
    for (int32_t i = from; i < r->n_add; i++) {
        int32_t e = c->e0 + i;
        if (c->failed[i] && !retry) {
            r->failed_at = i;
            return 0;
        }
        double *k = c->k + 324 * (size_t)i;
        if (c->failed[i] && fs_wedge_element_system(w, e, w->assembled_thickness, k, c->loads[i]) < 0)
            return -1;
        if (w->state[e] == FS_WEDGE_ALIVE) {
            c->slot = w->refill_slot + FS_WEDGE_PAIRS * (size_t)e;
            element_pairs(w, e, k, add_at_slot, c);
            add_loads(w, e, c->loads[i], NULL);
        }
    }
    return 0;
}

static void refill_round_item(void *ctx, int32_t item)
{
    refill_round *r = ctx;
    if (item == 0) {
        if (r->add)
            add_chunk(r, 0, false);
        return;
    }
    int32_t i0, i1;
    fs_parallel_part(r->n_next, FS_RANGE_PARTS, item - 1, &i0, &i1);
    refill_range(r->next, i0, i1);
}

/* design: at a new thickness the stress check's element caches (fs_wedge_refresh_cache) are needed
 * only once the system is solved, and the factorization runs on one thread (CHOLMOD's BLAS is kept on
 * one), so the caches are refreshed on a second thread while the calling thread factorizes, in
 * parallel parts when nothing is factorized. Each writes only its own data (the factor; each
 * element's caches), so the results are those of one after the other, for any thread count. */
typedef struct {
    fs_wedge_model *w;
    uint8_t *failed;            /* per element: its cache failed (degenerate) */
    int factor_rc;              /* fs_wedge_factorize's, and its error where it failed */
    fs_errdomain factor_domain;
    char factor_message[512];
} refresh_job;

static void refresh_range(void *ctx, int32_t e0, int32_t e1)
{
    refresh_job *j = ctx;
    for (int32_t e = e0; e < e1; e++)
        if (fs_wedge_refresh_cache(j->w, &e, 1) < 0) {
            j->failed[e] = 1;
            fs_error_clear();
        }
}

static void refresh_item(void *ctx, int32_t i)
{
    refresh_job *j = ctx;
    if (i == 1) {
        refresh_range(j, 0, j->w->n_elems);
        return;
    }
    j->factor_rc = fs_wedge_factorize(j->w, false);
    if (j->factor_rc < 0) { /* the error is this thread's own: carried to the caller's */
        j->factor_domain = fs_error_domain();
        snprintf(j->factor_message, sizeof j->factor_message, "%s", fs_error_message());
        fs_error_clear();
    }
}

/* Re-factorizes (fs_wedge_factorize, without a new analysis) and refreshes every element's caches. */
static int factorize_and_refresh(fs_wedge_model *w)
{
    refresh_job j = {w, fs_calloc((size_t)w->n_elems + 1, 1), 0, FS_OK, ""};
    if (w->cfg.solver.method == FS_SOLVER_CHOLMOD && w->n_free > 0)
        fs_parallel_for(2, 0, refresh_item, &j);
    else
        fs_parallel_ranges(w->n_elems, 256, refresh_range, &j);
    int rc = 0;
    for (int32_t e = 0; e < w->n_elems && rc == 0; e++)
        if (j.failed[e]) /* again on this thread, for its message */
            rc = fs_wedge_refresh_cache(w, &e, 1);
    free(j.failed);
    if (rc == 0 && j.factor_rc < 0) {
        fs_error(j.factor_domain, "%s", j.factor_message);
        rc = -1;
    }
    return rc;
}

/* New values on the same pattern (a changed thickness): zero, re-add every living element in order,
 * so the values are those a fresh assembly gives, and re-factorize without a new analysis. */
int fs_wedge_refill_system(fs_wedge_model *w, double base_thickness)
{
    double t0 = fs_seconds();
    w->assembled_thickness = base_thickness;
    fs_sparse_matrix_zero(&w->k_free);
    for (size_t p = 0; p < w->k_fb.used; p++)
        w->k_fb.value[p] = 0.0;
    memset(w->load, 0, (size_t)FS_WEDGE_PATTERNS * w->n_free * sizeof *w->load);
    /* at least four chunks (of 64 elements or more), so that adding one overlaps computing the next */
    int32_t chunk = w->n_elems / 4 < 64 ? 64 : (w->n_elems / 4 > REFILL_CHUNK ? REFILL_CHUNK : w->n_elems / 4);
    bool slots = w->refill_slot_version != w->pattern_version || w->refill_slot_elems < w->n_elems;
    refill_chunk c[2];
    for (int b = 0; b < 2; b++)
        c[b] = (refill_chunk){w, 0, slots, fs_malloc((324 * (size_t)chunk + 1) * sizeof *c[b].k),
                              fs_malloc(((size_t)chunk + 1) * sizeof *c[b].loads), fs_malloc((size_t)chunk + 1), NULL};
    if (slots && w->refill_slot_elems < w->n_elems) {
        w->refill_slot_elems = w->n_elems + w->n_elems / 4;
        free(w->refill_slot);
        w->refill_slot = fs_malloc(FS_WEDGE_PAIRS * (size_t)w->refill_slot_elems * sizeof *w->refill_slot);
    }
    int rc = 0;
    int32_t n_chunks = (w->n_elems + chunk - 1) / chunk;
    /* round k adds chunk k - 1 and computes chunk k */
    for (int32_t k = 0; k <= n_chunks && rc == 0; k++) {
        refill_round r = {k > 0 ? &c[(k - 1) % 2] : NULL, k < n_chunks ? &c[k % 2] : NULL, 0, 0, -1};
        if (r.add)
            r.n_add = w->n_elems - r.add->e0 < chunk ? w->n_elems - r.add->e0 : chunk;
        if (r.next) {
            r.next->e0 = k * chunk;
            r.n_next = w->n_elems - r.next->e0 < chunk ? w->n_elems - r.next->e0 : chunk;
        }
        if (!r.add)
            fs_parallel_ranges(r.n_next, 256, refill_range, r.next);
        else
            fs_parallel_for(r.next ? 1 + FS_RANGE_PARTS : 1, 0, refill_round_item, &r);
        if (r.failed_at >= 0)
            rc = add_chunk(&r, r.failed_at, true);
    }
    for (int b = 0; b < 2; b++) {
        free(c[b].k);
        free(c[b].loads);
        free(c[b].failed);
    }
    /* a failure leaves slots unset: looked up again next time */
    w->refill_slot_version = rc == 0 ? w->pattern_version : 0;
    if (rc < 0)
        return -1;
    fix_orphans(w);
    w->counters.assemble_seconds += fs_seconds() - t0;
    return factorize_and_refresh(w);
}
