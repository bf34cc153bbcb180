/* Capacities of growable arrays. */
#include "base/array.h"

#include <stdint.h>

size_t fs_array_capacity(size_t cap, size_t need, size_t first)
{
    FS_ASSERT(first > 0);
    size_t c = cap ? cap : first;
    while (c < need) {
        FS_ASSERT(c <= SIZE_MAX / 2);
        c *= 2;
    }
    return need <= INT32_MAX && c > INT32_MAX ? INT32_MAX : c;
}
