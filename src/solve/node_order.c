/* The elimination order kept across cuts (see node_order.h). */
#include "solve/node_order.h"

#include <stdlib.h>

#include "base/error.h"

/* design: a layer or shell cut by cracks changes its system's pattern at every cascade of cuts, and
 * each new pattern needs an analysis before its factorization. METIS's nested dissection fills the
 * factor least (a 20k-triangle shell: 5.8 GFlop a factorization against AMD's 10) but ordering costs
 * some ten times the symbolic work alone. So the order made afresh is kept node by node, and the
 * patterns after cuts are analysed in it: a node a cut made takes the place of the node it was
 * copied from, or else comes right after the last of its neighbours (as a separator's node does;
 * placed with the first, its elimination fills across the separator: three times the flops within
 * 15 cascades on a shell). The cuts still make that order fill more (some 3 % a cascade) while a
 * fresh one would fill less (cracks cut the mesh apart), so the mesh is ordered afresh when an
 * analysis in the kept order costs more than FS_NODE_REORDER times the flops of the last fresh one. */

typedef struct {
    int32_t rank, node;
} ranked_node;

static int compare_ranked(const void *a, const void *b)
{
    const ranked_node *x = a, *y = b;
    if (x->rank != y->rank)
        return (x->rank > y->rank) - (x->rank < y->rank);
    return (x->node > y->node) - (x->node < y->node);
}

/* Places for the nodes made since the order: the place of the node copied from, else the last of its
 * neighbours' (repeated, for a node whose neighbours are new too), else the end. */
static void place_new_nodes(fs_node_order *o, int32_t nn, const int32_t *origin, fs_node_neighbours_fn neighbours,
                            void *ctx)
{
    int32_t from = o->n_nodes;
    o->rank = fs_realloc(o->rank, ((size_t)nn + 1) * sizeof *o->rank);
    for (int32_t i = from; i < nn; i++)
        o->rank[i] = origin && origin[i] >= 0 && origin[i] < from ? o->rank[origin[i]] : -1;
    int32_t cap = 64, *nb = fs_malloc((size_t)cap * sizeof *nb);
    for (bool again = true; again;) {
        again = false;
        bool placed = false;
        for (int32_t i = from; i < nn; i++) {
            if (o->rank[i] >= 0)
                continue;
            int32_t m = neighbours(ctx, i, nb, cap);
            if (m > cap) {
                cap = m;
                nb = fs_realloc(nb, (size_t)cap * sizeof *nb);
                m = neighbours(ctx, i, nb, cap);
            }
            int32_t best = -1;
            for (int32_t q = 0; q < m; q++) {
                int32_t r = o->rank[nb[q]];
                if (r >= 0 && r != INT32_MAX && (best < 0 || r > best))
                    best = r;
            }
            if (best >= 0) {
                o->rank[i] = best;
                placed = true;
            } else {
                again = true;
            }
        }
        if (again && !placed) {
            for (int32_t i = from; i < nn; i++)
                if (o->rank[i] < 0)
                    o->rank[i] = INT32_MAX;
            again = false;
        }
    }
    free(nb);
    o->n_nodes = nn;
}

/* Whether d is one of the unknowns. */
static bool counted(const fs_node_dofs *dofs, int32_t d) { return d >= 0 && d < dofs->n; }

fs_cholesky *fs_node_order_analyze(fs_node_order *o, const fs_sparse_matrix *k, int32_t nn, const fs_node_dofs *dofs,
                                   const int32_t *origin, fs_node_neighbours_fn neighbours, void *ctx, bool *fresh)
{
    int32_t nf = dofs->n;
    if (fresh)
        *fresh = false;
    if (o->rank) {
        FS_ASSERT(nn >= o->n_nodes);
        place_new_nodes(o, nn, origin, neighbours, ctx);
        ranked_node *order = fs_malloc(((size_t)nn + 1) * sizeof *order);
        for (int32_t i = 0; i < nn; i++)
            order[i] = (ranked_node){o->rank[i], i};
        qsort(order, (size_t)nn, sizeof *order, compare_ranked);
        int32_t *perm = fs_malloc(((size_t)nf + 1) * sizeof *perm), p = 0;
        for (int32_t q = 0; q < nn; q++)
            for (int c = 0; c < dofs->count; c++) {
                int32_t d = dofs->dof[(size_t)dofs->stride * order[q].node + dofs->first + c];
                if (counted(dofs, d))
                    perm[p++] = d;
            }
        FS_ASSERT(p == nf);
        fs_cholesky *ch = fs_cholesky_analyze_given(k, perm);
        free(perm);
        free(order);
        if (!ch || fs_cholesky_get_info(ch).flops <= FS_NODE_REORDER * o->flops)
            return ch;
        fs_cholesky_free(ch);
    }
    fs_cholesky *ch = fs_cholesky_analyze(k);
    if (!ch)
        return NULL;
    if (fresh)
        *fresh = true;
    /* each node's place: the first of its unknowns in the order */
    int32_t *node_of = fs_malloc(((size_t)nf + 1) * sizeof *node_of);
    for (int32_t i = 0; i < nn; i++)
        for (int c = 0; c < dofs->count; c++) {
            int32_t d = dofs->dof[(size_t)dofs->stride * i + dofs->first + c];
            if (counted(dofs, d))
                node_of[d] = i;
        }
    o->rank = fs_realloc(o->rank, ((size_t)nn + 1) * sizeof *o->rank);
    for (int32_t i = 0; i < nn; i++)
        o->rank[i] = INT32_MAX;
    const int32_t *perm = fs_cholesky_permutation(ch);
    for (int32_t q = nf - 1; q >= 0; q--)
        o->rank[node_of[perm[q]]] = q;
    free(node_of);
    o->n_nodes = nn;
    o->flops = fs_cholesky_get_info(ch).flops;
    return ch;
}

void fs_node_order_free(fs_node_order *o)
{
    free(o->rank);
    *o = (fs_node_order){0};
}
