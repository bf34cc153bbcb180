/* Error reporting and checked allocation. */
#include "base/error.h"

#include <errno.h>
#ifdef __GLIBC__
#include <malloc.h>
#endif
#include <math.h>
#include <stdarg.h>
#include <string.h>

static _Thread_local char error_message[1024];
static _Thread_local fs_errdomain error_domain = FS_OK;

void fs_error(fs_errdomain domain, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(error_message, sizeof error_message, fmt, ap);
    va_end(ap);
    error_domain = domain;
}

int fs_close_written(FILE *f, const char *path, const char *what)
{
    /* a failed buffered write leaves its errno; the close's flush sets it again if it fails */
    int err = ferror(f) ? (errno ? errno : EIO) : 0;
    if (fclose(f) != 0 && !err)
        err = errno ? errno : EIO;
    if (!err)
        return 0;
    fs_error(FS_ERR_IO, "%s: cannot write %s: %s", path, what, strerror(err));
    return -1;
}

const char *fs_error_message(void) { return error_message; }
fs_errdomain fs_error_domain(void) { return error_domain; }

void fs_error_clear(void)
{
    error_message[0] = '\0';
    error_domain = FS_OK;
}

void fs_invariant_failed(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "fissure: internal error: %s:%d: invariant broken: ", file, line);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
    abort();
}

int64_t fs_first_nonfinite(const double *v, size_t n)
{
    for (size_t i = 0; i < n; i++)
        if (!isfinite(v[i]))
            return (int64_t)i;
    return -1;
}

static void *check_alloc(void *p, size_t size)
{
    if (!p && size) {
        fprintf(stderr, "fissure: out of memory (%zu bytes)\n", size);
        abort();
    }
    return p;
}

void *fs_malloc(size_t size) { return check_alloc(malloc(size ? size : 1), size); }
void *fs_calloc(size_t count, size_t size) { return check_alloc(calloc(count ? count : 1, size ? size : 1), count * size); }
void *fs_realloc(void *ptr, size_t size) { return check_alloc(realloc(ptr, size ? size : 1), size); }
char *fs_strdup(const char *s) { return s ? check_alloc(strdup(s), strlen(s) + 1) : NULL; }

/* design: glibc hands blocks from 128 KiB up to the system (mmap) and gives the free top of a heap
 * back once it exceeds 128 KiB, raising both limits only as it sees large blocks freed; each return
 * costs a page fault per 4 KiB when the memory is used again, and a Qhull run (up to a hundred MB in
 * a worker thread) or a mesh array freed and allocated again pays it over and over (a quarter of the
 * CPU time of meshing a million points). So no block is mapped on its own: all come from the heap,
 * and up to 1 GiB of free top is kept, so that memory is reused from the start. Mapping blocks of
 * 32 MiB and more (glibc's own dynamic maximum) and keeping 64 MiB of free top still paid it for
 * every factor of a large sparse system: the shell model factors its 20 000-triangle Hessian (some
 * 50 MB) a few hundred times a run, and the page faults of each fresh factor (860 000 in its first
 * minute, 60 000 with these limits) cost a third of its factorization. The peak is unchanged: what
 * is kept is what was in use before. One arena for all
 * threads, so that what a worker thread frees serves the next allocation on any thread and the peak
 * stays where it was (with an arena per thread, memory a worker keeps is lost to the others: a fifth
 * more at a million points on two threads); the threads allocate few, large blocks (Qhull carves
 * its nodes from 64 KiB buffers), so they hardly wait for its lock. */
void fs_alloc_setup(void)
{
#ifdef __GLIBC__
    mallopt(M_MMAP_MAX, 0);
    mallopt(M_TRIM_THRESHOLD, 1 << 30);
    mallopt(M_ARENA_MAX, 1);
#endif
}
