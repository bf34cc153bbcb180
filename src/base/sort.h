/* Sorting of index lists: node, element and unknown numbers. */
#ifndef FS_BASE_SORT_H
#define FS_BASE_SORT_H

#include <stdint.h>

/* Sorts the n values of v ascending. */
void fs_sort_int32(int32_t *v, int32_t n);

/* Sorts the n values of v ascending and drops repeats; returns the number kept. */
int32_t fs_sort_unique_int32(int32_t *v, int32_t n);

#endif
