/* A preloaded rename(2) for the kill test (tests/cli_output_sets.sh): with FISSURE_KILL_RENAME=N
 * the process sends itself SIGKILL just before its Nth rename, with -N just after it, so that a
 * test can stop a run at every step of its commit. Without the variable it only renames. */
#include <dlfcn.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>

int rename(const char *from, const char *to)
{
    static int calls;
    static int (*next_rename)(const char *, const char *);
    if (!next_rename)
        *(void **)(&next_rename) = dlsym(RTLD_NEXT, "rename");
    const char *at = getenv("FISSURE_KILL_RENAME");
    int n = at ? atoi(at) : 0;
    calls++;
    if (n > 0 && calls == n)
        raise(SIGKILL);
    int rc = next_rename(from, to);
    if (n < 0 && calls == -n)
        raise(SIGKILL);
    return rc;
}
