/* A fill-reducing elimination order kept node by node while cuts change a mesh's system: the analyses after cuts reuse it, and it is made afresh only when it has filled too much. */
#ifndef FS_SOLVE_NODE_ORDER_H
#define FS_SOLVE_NODE_ORDER_H

#include <stdbool.h>
#include <stdint.h>

#include "solve/sparse.h"

/* The kept order. Zero it before the first use; fs_node_order_free releases it. */
typedef struct {
    int32_t *rank;   /* per node: its place in the order (INT32_MAX: after every other) */
    int32_t n_nodes; /* nodes that have a place; the nodes after them came since */
    double flops;    /* flops of a factorization in the order made afresh last */
} fs_node_order;

/* Where a mesh's nodes have their unknowns: node i's are dof[stride i + first + k] for k < count,
 * each counted when 0 <= it < n (the order of the matrix; other values are fixed or absent). Every
 * unknown belongs to one node. */
typedef struct {
    const int32_t *dof;
    int stride, first, count;
    int32_t n;
} fs_node_dofs;

/* Writes node i's neighbours in the mesh (repeats and i itself allowed) into out, at most cap of
 * them, and returns how many it has (more than cap: called again with room for all). */
typedef int32_t (*fs_node_neighbours_fn)(void *ctx, int32_t i, int32_t *out, int32_t cap);

/* Analyses k (fs_cholesky_analyze_given) in the kept order, the nodes made since placed first at
 * the place of the node they were copied from (origin[i], if 0 <= origin[i] < the nodes placed;
 * origin may be NULL), else after the last of their placed neighbours, else last. When that costs
 * more than FS_NODE_REORDER times the flops of the last fresh order, or there is no order yet, it
 * orders afresh (fs_cholesky_analyze) and keeps that order; *fresh (may be NULL) tells which.
 * n_nodes >= the nodes placed. Returns the analysis, or NULL with fs_error. */
#define FS_NODE_REORDER 1.25
fs_cholesky *fs_node_order_analyze(fs_node_order *o, const fs_sparse_matrix *k, int32_t n_nodes,
                                   const fs_node_dofs *dofs, const int32_t *origin,
                                   fs_node_neighbours_fn neighbours, void *ctx, bool *fresh);

void fs_node_order_free(fs_node_order *o);

#endif
