/* Error reporting: one pending message per thread and an error domain that is the CLI's exit status. */
#ifndef FS_BASE_ERROR_H
#define FS_BASE_ERROR_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

/* The domain of an error doubles as the process exit status (sysexits.h values). */
typedef enum {
    FS_OK = 0,
    FS_ERR_USAGE = 64,    /* bad command line */
    FS_ERR_DATA = 65,     /* bad preset or input data */
    FS_ERR_NOINPUT = 66,  /* missing input file */
    FS_ERR_INTERNAL = 70, /* internal error: a library failed, a solver did not converge */
    FS_ERR_CANTCREAT = 73,/* cannot create output */
    FS_ERR_IO = 74        /* read or write failed */
} fs_errdomain;

/* Records an error (printf-style). A later call replaces an earlier message. Functions that fail
 * call this and return -1 (or NULL); the caller either handles it or passes the failure up. */
void fs_error(fs_errdomain domain, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

/* Closes a stream that was written to path. When a write or the close failed, records
 * fs_error(FS_ERR_IO, "PATH: cannot write WHAT: REASON") with the system's reason (No space left on
 * device, ...) and returns -1; else returns 0. */
int fs_close_written(FILE *f, const char *path, const char *what);

/* The pending message ("" if none) and its domain (FS_OK if none). */
const char *fs_error_message(void);
fs_errdomain fs_error_domain(void);
void fs_error_clear(void);

/* Programming errors: abort with file and line. Always on (cheap checks only). */
#define FS_ASSERT(cond)                                                                    \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            fprintf(stderr, "fissure: internal error: %s:%d: assertion '%s' failed\n",   \
                    __FILE__, __LINE__, #cond);                                            \
            abort();                                                                       \
        }                                                                                  \
    } while (0)

/* design: a --enable-validate build (./configure defines FS_VALIDATE in config.h) also checks, after
 * every change of a model's mesh, system or state, the invariants the rest of the code relies on:
 * a manifold, consistently oriented mesh with valid adjacency, a symmetric stiffness stored as a
 * consistent upper triangle, finite displacements and stresses. The checks cost a pass over the model
 * each, so they are compiled only there, in #ifdef FS_VALIDATE blocks of the models; a broken invariant
 * is a programming error and aborts through FS_INVARIANT with a message naming it. */

/* Aborts with file, line and the printf-style message unless cond holds. */
#define FS_INVARIANT(cond, ...)                                      \
    do {                                                             \
        if (!(cond))                                                 \
            fs_invariant_failed(__FILE__, __LINE__, __VA_ARGS__);    \
    } while (0)

void fs_invariant_failed(const char *file, int line, const char *fmt, ...)
    __attribute__((noreturn, format(printf, 3, 4)));

/* The index of the first entry of v[0 .. n) that is NaN or infinite, or -1 if all are finite. */
int64_t fs_first_nonfinite(const double *v, size_t n);

/* Allocation that aborts on exhaustion: out-of-memory is not a recoverable input error here. */
void *fs_malloc(size_t size);
void *fs_calloc(size_t count, size_t size);
void *fs_realloc(void *ptr, size_t size);
char *fs_strdup(const char *s);

/* Tunes the C library's allocator once, at start-up before any thread runs: large blocks that are
 * freed (a Qhull run's nodes, a block's arrays) stay with the process for the next allocation
 * instead of going back to the system and being faulted in again page by page, in the worker
 * threads' arenas too. Only the speed and the resident memory change. A no-op without glibc. */
void fs_alloc_setup(void);

#endif
