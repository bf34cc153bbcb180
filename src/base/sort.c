/* Sorting of index lists. */
#include "base/sort.h"

#include <stdlib.h>

static int cmp_int32(const void *a, const void *b)
{
    int32_t x = *(const int32_t *)a, y = *(const int32_t *)b;
    return (x > y) - (x < y);
}

void fs_sort_int32(int32_t *v, int32_t n)
{
    if (n > 1)
        qsort(v, (size_t)n, sizeof *v, cmp_int32);
}

int32_t fs_sort_unique_int32(int32_t *v, int32_t n)
{
    fs_sort_int32(v, n);
    int32_t kept = 0;
    for (int32_t q = 0; q < n; q++)
        if (kept == 0 || v[kept - 1] != v[q])
            v[kept++] = v[q];
    return kept;
}
