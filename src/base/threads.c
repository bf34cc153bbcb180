/* The process-wide thread budget (what -j/--threads sets) and the parallel loop that spends it. */
#include "base/threads.h"

#include <pthread.h>
#include <unistd.h>

static int requested = -1; /* -1: never set; 0: one per online processor */

void fs_threads_set(int n) { requested = n < 0 ? 0 : (n > FS_THREADS_MAX ? FS_THREADS_MAX : n); }

bool fs_threads_given(void) { return requested >= 0; }

int fs_threads(void)
{
    if (requested > 0)
        return requested;
    long n = sysconf(_SC_NPROCESSORS_ONLN);
    return n < 1 ? 1 : (n > FS_THREADS_MAX ? FS_THREADS_MAX : (int)n);
}

/* The shared state of one fs_parallel_for: the next item to hand out. */
typedef struct {
    int32_t n, next;
    fs_parallel_fn fn;
    void *ctx;
    pthread_mutex_t lock;
} parallel_loop;

static void *parallel_worker(void *arg)
{
    parallel_loop *loop = arg;
    for (;;) {
        pthread_mutex_lock(&loop->lock);
        int32_t i = loop->next < loop->n ? loop->next++ : -1;
        pthread_mutex_unlock(&loop->lock);
        if (i < 0)
            return NULL;
        loop->fn(loop->ctx, i);
    }
}

void fs_parallel_for(int32_t n, int threads, fs_parallel_fn fn, void *ctx)
{
    if (n <= 0)
        return;
    if (threads <= 0)
        threads = fs_threads();
    if (threads > FS_THREADS_MAX)
        threads = FS_THREADS_MAX;
    if (threads > n)
        threads = (int)n;
    if (threads <= 1) {
        for (int32_t i = 0; i < n; i++)
            fn(ctx, i);
        return;
    }
    parallel_loop loop = {n, 0, fn, ctx, PTHREAD_MUTEX_INITIALIZER};
    pthread_t thread[FS_THREADS_MAX];
    bool started[FS_THREADS_MAX] = {false};
    for (int t = 1; t < threads; t++)
        started[t] = pthread_create(&thread[t], NULL, parallel_worker, &loop) == 0;
    parallel_worker(&loop);
    for (int t = 1; t < threads; t++)
        if (started[t])
            pthread_join(thread[t], NULL);
}

typedef struct {
    fs_range_fn fn;
    void *ctx;
    int32_t n;
} range_work;

static void range_part(void *ctx, int32_t part)
{
    const range_work *w = ctx;
    int32_t i0, i1;
    fs_parallel_part(w->n, FS_RANGE_PARTS, part, &i0, &i1);
    w->fn(w->ctx, i0, i1);
}

void fs_parallel_ranges(int32_t n, int32_t min_items, fs_range_fn fn, void *ctx)
{
    if (n < min_items) {
        if (n > 0)
            fn(ctx, 0, n);
        return;
    }
    range_work w = {fn, ctx, n};
    fs_parallel_for(FS_RANGE_PARTS, 0, range_part, &w);
}
