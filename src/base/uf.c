/* Union-find with path halving; the smaller root wins. */
#include "base/uf.h"

void fs_uf_init(int32_t *parent, int32_t n)
{
    for (int32_t i = 0; i < n; i++)
        parent[i] = i;
}

int32_t fs_uf_find(int32_t *parent, int32_t i)
{
    while (parent[i] != i) {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    return i;
}

int32_t fs_uf_union(int32_t *parent, int32_t a, int32_t b)
{
    a = fs_uf_find(parent, a);
    b = fs_uf_find(parent, b);
    if (a < b)
        parent[b] = a;
    else if (b < a)
        parent[a] = b;
    return a < b ? a : b;
}
