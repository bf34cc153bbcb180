/* Growable arrays: a capacity that doubles, and the reallocation of one or several arrays to it. */
#ifndef FS_BASE_ARRAY_H
#define FS_BASE_ARRAY_H

#include <stddef.h>

#include "base/error.h"

/* design: an array that grows by appends keeps a count and a capacity (elements allocated); when a
 * count would pass the capacity, the capacity doubles (from a first size when it is 0), so n appends
 * copy O(n) elements in all. Arrays that always grow together (the columns of one table: positions,
 * parents, flags of the same items) share one capacity: FS_ARRAY_GROW decides it once and each array
 * follows with FS_ARRAY_RESIZE. Capacities are element counts, whatever the integer type that holds
 * them (int32_t for nodes, elements and points, size_t for matrix entries). */

/* The capacity for at least need elements: cap doubled (first, when cap is 0) as often as it takes;
 * cap itself when it already holds need. first > 0. Never above INT32_MAX while need is not (so an
 * int32_t capacity holds it); aborts (FS_ASSERT) if doubling would overflow a size_t. */
size_t fs_array_capacity(size_t cap, size_t need, size_t first);

/* Reallocates the array ptr (an lvalue pointer) to n elements of its type, keeping the first ones;
 * aborts on exhaustion (fs_realloc). */
#define FS_ARRAY_RESIZE(ptr, n) ((ptr) = fs_realloc((ptr), (size_t)(n) * sizeof *(ptr)))

/* Grows the capacity cap (an lvalue of any integer type) to hold need elements
 * (fs_array_capacity); evaluates to 1 if it changed, then the caller resizes the arrays that share
 * it, else 0. */
#define FS_ARRAY_GROW(cap, need, first)                                                     \
    ((size_t)(need) > (size_t)(cap) ? ((cap) = fs_array_capacity((size_t)(cap), (size_t)(need), (first)), 1) \
                                    : 0)

/* Makes room in the array ptr, of capacity cap, for need elements: the capacity doubles and the
 * array is reallocated when need exceeds it (its elements kept). ptr and cap are evaluated more than
 * once. */
#define FS_ARRAY_RESERVE(ptr, cap, need, first)        \
    do {                                               \
        if (FS_ARRAY_GROW(cap, need, first))           \
            FS_ARRAY_RESIZE(ptr, cap);                 \
    } while (0)

#endif
