/* Union-find (disjoint sets) over index ranges: fragments, joined points, the sectors of a node's fan. */
#ifndef FS_BASE_UF_H
#define FS_BASE_UF_H

#include <stdint.h>

/* design: the sets live in a caller-owned array parent[0 .. n) (parent[i] == i: i is a root). The
 * root of a set is always its smallest index (a union links the larger root under the smaller), so
 * the result of a sequence of unions does not depend on the order of the operands, and a root
 * found while scanning indices upwards is the first index of its set seen. fs_uf_find halves the
 * path as it walks it (parent[i] = parent[parent[i]]), which keeps trees shallow without ranks. */

/* parent[i] = i for i in [0, n): n singletons. */
void fs_uf_init(int32_t *parent, int32_t n);

/* The root (smallest index) of i's set; shortens the path from i on the way. */
int32_t fs_uf_find(int32_t *parent, int32_t i);

/* Joins the sets of a and b (finding a's root first, then b's); returns the root of the union. */
int32_t fs_uf_union(int32_t *parent, int32_t a, int32_t b);

#endif
