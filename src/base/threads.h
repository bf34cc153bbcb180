/* The process-wide budget of threads that fissure's parallel work may use (-j/--threads), and the one parallel loop. */
#ifndef FS_BASE_THREADS_H
#define FS_BASE_THREADS_H

#include <stdbool.h>
#include <stdint.h>

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

/* design: the one way fissure runs work in parallel. A loop over items 0 .. n - 1 whose item i writes
 * only outputs that belong to i (its slot of an array, its own log, its range of a vector) and reads
 * nothing another item writes: then the outputs are the same whichever thread runs which item, in
 * whatever order, so they never depend on the thread count. A sum or other reduction over the items
 * is left to the caller, done afterwards in index order (so it is the same floating-point sum for
 * any thread count, as STYLE.md asks). Items are handed out in index order to whichever thread is
 * free, so items of uneven cost, or a thread held up by other work on the machine, balance out.
 * Work over one index range is cut into contiguous parts by fs_parallel_part, a static partition
 * that depends only on the range and the part count (not on the thread count, unless the caller
 * makes the part count follow it and keeps the result independent of it, as a stable sort does). */

/* The body of a parallel loop: item i of the work ctx describes. */
typedef void (*fs_parallel_fn)(void *ctx, int32_t i);

/* Runs fn(ctx, i) once for every i in [0, n): on the calling thread and up to threads - 1 more
 * (threads <= 0: fs_threads(); never more threads than items), returning when all are done. A
 * thread that cannot be started leaves its share to the others (at worst the calling thread does
 * everything). Nothing happens for n <= 0. */
void fs_parallel_for(int32_t n, int threads, fs_parallel_fn fn, void *ctx);

/* Work over the items [i0, i1) of a range. */
typedef void (*fs_range_fn)(void *ctx, int32_t i0, int32_t i1);

/* design: a pass over many cheap items (every element's stress, every hinge of a shell) runs in
 * FS_RANGE_PARTS fixed contiguous parts (fs_parallel_part) on fs_threads() threads, each part calling
 * fn on its range; whatever sums over items is left to the caller, in item order, so the results are
 * the same for any thread count and the same as one loop. A pass of fewer than min_items items runs
 * on the calling thread alone (starting threads costs tens of microseconds). fn(ctx, i0, i1) must
 * write only the slots of its own items. */
#define FS_RANGE_PARTS 32
void fs_parallel_ranges(int32_t n, int32_t min_items, fs_range_fn fn, void *ctx);

/* Part p of [0, n) cut into parts contiguous ranges of sizes differing by at most one:
 * [n p / parts, n (p + 1) / parts), into *i0 and *i1. 0 <= p < parts. */
static inline void fs_parallel_part(int32_t n, int parts, int p, int32_t *i0, int32_t *i1)
{
    *i0 = (int32_t)((int64_t)n * p / parts);
    *i1 = (int32_t)((int64_t)n * (p + 1) / parts);
}

#endif
