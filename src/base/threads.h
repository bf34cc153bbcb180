/* The process-wide budget of threads that fissure's parallel work may use (-j/--threads). */
#ifndef FS_BASE_THREADS_H
#define FS_BASE_THREADS_H

#include <stdbool.h>

/* Largest thread count fs_threads_set accepts. */
#define FS_THREADS_MAX 256

/* Sets the budget: n in 1 .. FS_THREADS_MAX threads, or 0 for one per online processor (also the
 * budget when it was never set). Call before any parallel work starts (the CLI does, while parsing
 * its options); values out of range are clamped. Results never depend on it: parallel code splits
 * its work so that the output is the same for any thread count. */
void fs_threads_set(int n);

/* The budget: at least 1, at most FS_THREADS_MAX. */
int fs_threads(void);

/* Whether fs_threads_set was called: libraries with thread settings of their own (the BLAS) keep
 * them, environment variables included, unless it was. */
bool fs_threads_given(void);

#endif
