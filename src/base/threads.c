/* The process-wide thread budget: what -j/--threads sets, read by the code that starts threads. */
#include "base/threads.h"

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
