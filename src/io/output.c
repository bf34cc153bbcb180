/* Atomic output sets: stage files under hidden temporary names, then rename them all into place,
 * the set's sidecar last; remove what is staged when a termination signal ends the process. */
#include "io/output.h"

#include <errno.h>
#include <limits.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "base/error.h"

/* Where a staged file is. The signal cleanup reads it to know what to remove. */
enum {
    FILE_STAGED, /* at its temporary path (or not written yet) */
    FILE_MOVING, /* being renamed: at one of the two paths */
    FILE_MOVED,  /* at its final path, moved by a commit that has not finished */
    FILE_KEPT    /* at its final path, the set committed: no longer this process's to remove */
};

typedef struct {
    char *name;       /* file name as staged: relative to the set's directory */
    char *listed;     /* how the set lists it: name, or an absolute path for a file merged from
                         another directory */
    char *temp_path;  /* dir/.STEM.tmp-PID-N.EXT, what the caller writes */
    char *final_path; /* dir/NAME */
    atomic_int state;
} output_file;

/* design: the signal cleanup (below) walks the live sets while the program may be changing them
 * on another thread, so nothing it reads ever moves: files sit in fixed chunks that are only
 * appended (a file's fields are set before the count that publishes it), and sets in a fixed
 * table of slots. A set is freed only after its slot is cleared and no cleanup has started (the
 * cleanup marks itself before it reads a slot, the freer clears the slot before it looks at the
 * mark; both sequentially consistent, so one of them sees the other). A set the cleanup may be
 * reading is left to the process's end, which the cleanup brings. */
#define CHUNK_FILES 64

typedef struct file_chunk {
    output_file files[CHUNK_FILES];
    struct file_chunk *next;
} file_chunk;

struct fs_output {
    char *dir;
    file_chunk *first, *last;
    atomic_int n_files;   /* files published in the chunks */
    int seal;             /* index of the sidecar (fs_output_stage_seal), -1 for none */
    char **extra_paths;   /* final paths asked for names that were never staged */
    int n_extra, cap_extra;
    atomic_bool committed; /* every file is in place: the signal cleanup leaves the set alone */
    int slot;             /* in live_sets, -1 when it did not get one */
};

#define MAX_LIVE_SETS 32
static struct fs_output *_Atomic live_sets[MAX_LIVE_SETS];
static atomic_int cleanup_started; /* the signal cleanup has begun */

/* Distinguishes temporary names of several output sets in one process. */
static atomic_ulong output_counter;

static char *join_path(const char *dir, const char *prefix, const char *name, const char *suffix)
{
    size_t n = strlen(dir) + strlen(prefix) + strlen(name) + strlen(suffix) + 2;
    char *p = fs_malloc(n);
    snprintf(p, n, "%s/%s%s%s", dir, prefix, name, suffix);
    return p;
}

static output_file *file_at(const fs_output *o, int i)
{
    file_chunk *c = o->first;
    for (; i >= CHUNK_FILES; i -= CHUNK_FILES)
        c = c->next;
    return &c->files[i];
}

/* mkdir -p: creates dir and any missing parents. */
static int make_dirs(const char *dir)
{
    char *path = fs_strdup(dir);
    size_t len = strlen(path);
    while (len > 1 && path[len - 1] == '/')
        path[--len] = '\0';
    for (char *p = path + 1;; p++) {
        bool end = *p == '\0';
        if (*p == '/' || end) {
            *p = '\0';
            if (mkdir(path, 0777) != 0 && errno != EEXIST) {
                fs_error(FS_ERR_CANTCREAT, "%s: cannot create output directory: %s", path, strerror(errno));
                free(path);
                return -1;
            }
            if (end)
                break;
            *p = '/';
        }
    }
    struct stat st;
    if (stat(path, &st) != 0 || !S_ISDIR(st.st_mode)) {
        fs_error(FS_ERR_CANTCREAT, "%s: output path is not a directory", path);
        free(path);
        return -1;
    }
    free(path);
    return 0;
}

int fs_output_check(const char *dir, size_t longest_name)
{
    if (!dir || !*dir)
        dir = ".";
    if (strlen(dir) + 1 + longest_name >= PATH_MAX) {
        fs_error(FS_ERR_CANTCREAT, "%.64s...: output directory name too long: %s", dir, strerror(ENAMETOOLONG));
        return -1;
    }
    /* the directory, or the nearest of its ancestors that exists, which mkdir -p would create in */
    char *path = fs_strdup(dir);
    struct stat st;
    for (;;) {
        size_t len = strlen(path);
        while (len > 1 && path[len - 1] == '/')
            path[--len] = '\0';
        if (stat(path, &st) == 0)
            break;
        int err = errno;
        char *slash = strrchr(path, '/');
        if (err != ENOENT || !slash || !strcmp(path, ".")) {
            if (err == ENOENT && !slash) {
                strcpy(path, ".");
                continue;
            }
            fs_error(FS_ERR_CANTCREAT, "%s: cannot create output directory: %s", dir, strerror(err));
            free(path);
            return -1;
        }
        if (slash == path)
            slash[1] = '\0';
        else
            *slash = '\0';
    }
    int rc = 0;
    if (!S_ISDIR(st.st_mode)) {
        fs_error(FS_ERR_CANTCREAT, "%s: output path is not a directory", path);
        rc = -1;
    } else if (access(path, W_OK | X_OK) != 0) {
        fs_error(FS_ERR_CANTCREAT, "%s: output directory is not writable: %s", path, strerror(errno));
        rc = -1;
    }
    free(path);
    return rc;
}

char *fs_output_dir_of(const char *path, const char **file)
{
    char *dir = fs_strdup(path);
    char *slash = strrchr(dir, '/');
    *file = slash ? path + (slash - dir) + 1 : path;
    if (!slash)
        strcpy(dir, ".");
    else
        slash[slash == dir ? 1 : 0] = '\0';
    return dir;
}

fs_output *fs_output_begin(const char *dir)
{
    if (!dir || !*dir)
        dir = ".";
    if (make_dirs(dir) != 0)
        return NULL;
    if (access(dir, W_OK | X_OK) != 0) {
        fs_error(FS_ERR_CANTCREAT, "%s: output directory is not writable: %s", dir, strerror(errno));
        return NULL;
    }
    fs_output *o = fs_calloc(1, sizeof *o);
    o->dir = fs_strdup(dir);
    o->seal = -1;
    o->slot = -1;
    for (int s = 0; s < MAX_LIVE_SETS && o->slot < 0; s++) {
        struct fs_output *expected = NULL;
        if (atomic_compare_exchange_strong(&live_sets[s], &expected, o))
            o->slot = s;
    }
    return o;
}

/* The staged file named name, or NULL; its index in *index when asked. */
static output_file *find_file(fs_output *o, const char *name, int *index)
{
    int n = atomic_load(&o->n_files), i = 0;
    for (file_chunk *c = o->first; c && i < n; c = c->next)
        for (int k = 0; k < CHUNK_FILES && i < n; k++, i++)
            if (!strcmp(c->files[k].name, name)) {
                if (index)
                    *index = i;
                return &c->files[k];
            }
    return NULL;
}

/* A new file slot at the end of the chunks (not yet published). */
static output_file *new_file(fs_output *o)
{
    int n = atomic_load(&o->n_files);
    if (n % CHUNK_FILES == 0 && (n > 0 || !o->first)) {
        file_chunk *c = fs_calloc(1, sizeof *c);
        if (o->last)
            o->last->next = c;
        else
            o->first = c;
        o->last = c;
    }
    return &o->last->files[n % CHUNK_FILES];
}

const char *fs_output_stage(fs_output *o, const char *name)
{
    FS_ASSERT(name && *name);
    output_file *f = find_file(o, name, NULL);
    if (f)
        return f->temp_path;
    f = new_file(o);
    f->name = fs_strdup(name);
    f->listed = fs_strdup(name);
    f->final_path = join_path(o->dir, "", name, "");

    /* The temporary file sits beside the final one (a name may reach into an existing
     * subdirectory), so the rename never crosses a file system; it keeps the extension, which is
     * how image writers choose the format. */
    char *dir = fs_strdup(o->dir);
    const char *base = strrchr(name, '/');
    if (base) {
        char *sub = fs_strdup(name);
        sub[base - name] = '\0';
        char *joined = join_path(o->dir, "", sub, "");
        free(dir);
        free(sub);
        dir = joined;
        base++;
    } else {
        base = name;
    }
    char *stem = fs_strdup(base);
    const char *dot = strrchr(base, '.');
    const char *ext = dot && dot != base ? dot : "";
    stem[strlen(base) - strlen(ext)] = '\0';
    char suffix[96];
    snprintf(suffix, sizeof suffix, ".tmp-%ld-%lu%s", (long)getpid(), atomic_fetch_add(&output_counter, 1UL), ext);
    f->temp_path = join_path(dir, ".", stem, suffix);
    free(stem);
    free(dir);
    atomic_store(&f->state, FILE_STAGED);
    atomic_fetch_add(&o->n_files, 1);
    return f->temp_path;
}

const char *fs_output_stage_seal(fs_output *o, const char *name)
{
    const char *path = fs_output_stage(o, name);
    find_file(o, name, &o->seal);
    return path;
}

/* Whether two directories are one (the same device and inode). */
static bool same_directory(const char *a, const char *b)
{
    struct stat sa, sb;
    return stat(a, &sa) == 0 && stat(b, &sb) == 0 && sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
}

/* dir as an absolute path (the working directory before a relative one), or NULL. */
static char *absolute_dir(const char *dir)
{
    if (dir[0] == '/')
        return fs_strdup(dir);
    char cwd[PATH_MAX];
    if (!getcwd(cwd, sizeof cwd))
        return NULL;
    if (!strcmp(dir, "."))
        return fs_strdup(cwd);
    return join_path(cwd, "", dir, "");
}

void fs_output_merge(fs_output *o, fs_output *from)
{
    if (!from)
        return;
    FS_ASSERT(from->seal < 0);
    bool same = same_directory(o->dir, from->dir);
    char *abs_dir = same ? NULL : absolute_dir(from->dir);
    int n = atomic_load(&from->n_files);
    for (int i = 0; i < n; i++) {
        output_file *src = file_at(from, i);
        output_file *f = new_file(o);
        f->name = fs_strdup(src->name);
        f->temp_path = fs_strdup(src->temp_path);
        f->final_path = fs_strdup(src->final_path);
        f->listed = same ? fs_strdup(src->name)
                         : abs_dir ? join_path(abs_dir, "", src->name, "") : fs_strdup(src->final_path);
        atomic_store(&f->state, FILE_STAGED);
        atomic_fetch_add(&o->n_files, 1);
    }
    free(abs_dir);
    /* the files now belong to o: from goes without removing them */
    atomic_store(&from->committed, true);
    fs_output_abort(from);
}

const char **fs_output_names(fs_output *o, int *count)
{
    int n = atomic_load(&o->n_files), i = 0, m = 0;
    const char **names = fs_malloc((size_t)(n ? n : 1) * sizeof *names);
    for (file_chunk *c = o->first; c && i < n; c = c->next)
        for (int k = 0; k < CHUNK_FILES && i < n; k++, i++)
            if (i != o->seal)
                names[m++] = c->files[k].listed;
    *count = m;
    return names;
}

const char *fs_output_final_path(fs_output *o, const char *name)
{
    output_file *f = find_file(o, name, NULL);
    if (f)
        return f->final_path;
    if (o->n_extra == o->cap_extra) {
        o->cap_extra = o->cap_extra ? 2 * o->cap_extra : 4;
        o->extra_paths = fs_realloc(o->extra_paths, (size_t)o->cap_extra * sizeof *o->extra_paths);
    }
    char *p = join_path(o->dir, "", name, "");
    o->extra_paths[o->n_extra++] = p;
    return p;
}

/* Takes the set out of the signal cleanup's view, then frees it (unless the cleanup has started:
 * then the process is about to end, and the set stays for it). */
static void output_free(fs_output *o)
{
    if (o->slot >= 0) {
        atomic_store(&live_sets[o->slot], NULL);
        if (atomic_load(&cleanup_started))
            return;
    }
    int n = atomic_load(&o->n_files);
    for (int i = 0; i < n; i++) {
        output_file *f = file_at(o, i);
        free(f->name);
        free(f->listed);
        free(f->temp_path);
        free(f->final_path);
    }
    for (file_chunk *c = o->first; c;) {
        file_chunk *next = c->next;
        free(c);
        c = next;
    }
    for (int i = 0; i < o->n_extra; i++)
        free(o->extra_paths[i]);
    free(o->extra_paths);
    free(o->dir);
    free(o);
}

/* Removes what the set has put anywhere: temporary files, and the files a failed commit already
 * moved into place. */
static void remove_files(fs_output *o)
{
    int n = atomic_load(&o->n_files);
    for (int i = 0; i < n; i++) {
        output_file *f = file_at(o, i);
        int state = atomic_load(&f->state);
        if (state == FILE_STAGED || state == FILE_MOVING)
            unlink(f->temp_path);
        if (state == FILE_MOVING || state == FILE_MOVED)
            unlink(f->final_path);
    }
}

static int move_file(output_file *f)
{
    atomic_store(&f->state, FILE_MOVING);
    if (rename(f->temp_path, f->final_path) != 0) {
        int err = errno;
        atomic_store(&f->state, FILE_STAGED);
        fs_error(FS_ERR_IO, "%s: cannot move into place: %s", f->final_path, strerror(err));
        return -1;
    }
    atomic_store(&f->state, FILE_MOVED);
    return 0;
}

int fs_output_commit(fs_output *o)
{
    int n = atomic_load(&o->n_files);
    int rc = 0;
    /* design: a sidecar beside files of another run must never be: the old sidecar goes before
     * any file of this run replaces a file it lists, and the new one comes last, so that while
     * it exists every file it lists is of its run (a reader's rule, fissure(1)). */
    if (o->seal >= 0 && unlink(file_at(o, o->seal)->final_path) != 0 && errno != ENOENT) {
        fs_error(FS_ERR_IO, "%s: cannot remove the previous sidecar: %s", file_at(o, o->seal)->final_path,
                 strerror(errno));
        rc = -1;
    }
    for (int i = 0; rc == 0 && i < n; i++)
        if (i != o->seal)
            rc = move_file(file_at(o, i));
    if (rc == 0 && o->seal >= 0)
        rc = move_file(file_at(o, o->seal));
    if (rc == 0) {
        atomic_store(&o->committed, true);
        for (int i = 0; i < n; i++)
            atomic_store(&file_at(o, i)->state, FILE_KEPT);
    } else {
        /* after a failure nothing of this run stays: neither its temporary files nor the files it
         * already moved into place */
        remove_files(o);
    }
    output_free(o);
    return rc;
}

void fs_output_abort(fs_output *o)
{
    if (!o)
        return;
    if (!atomic_load(&o->committed))
        remove_files(o);
    output_free(o);
}

/* ---- signals ---- */

/* design: a termination signal is taken by a thread of our own that waits for it (sigwait) while
 * every other thread blocks it, rather than by a handler: METIS, under CHOLMOD's analysis, installs
 * a SIGTERM handler of its own for the length of each ordering call that longjmps back into METIS,
 * which swallowed a SIGTERM (the run went on) and would jump across threads if another thread took
 * it. With the signals blocked everywhere no handler ever runs, whoever installed it: the signals
 * are blocked in the main thread before any library starts a thread (fs_output_block_signals, called
 * from the program's preinit array), so every thread inherits the mask, and sigwait returns them
 * here. The waiting thread removes what the live sets have put down, reading them with the
 * lock-free protocol above, then ends the process by the signal. SIGXFSZ, sent to the thread that
 * writes past the file size limit, stays blocked there: the write fails (EFBIG) and the error path
 * cleans up. SIGPIPE keeps its default: a reader that goes away (fissure --list-presets | head -1)
 * ends fissure quietly, and stdout is written only once the set is in place. */
static const int cleanup_signals[] = {SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGXCPU, SIGXFSZ};
#define N_CLEANUP_SIGNALS ((int)(sizeof cleanup_signals / sizeof cleanup_signals[0]))

static sigset_t blocked;
static atomic_bool blocked_ready;

void fs_output_block_signals(void)
{
    if (atomic_load(&blocked_ready)) {
        pthread_sigmask(SIG_BLOCK, &blocked, NULL);
        return;
    }
    sigemptyset(&blocked);
    for (int i = 0; i < N_CLEANUP_SIGNALS; i++) {
        struct sigaction old;
        /* a signal ignored when fissure started (nohup, a background job's SIGINT) stays ignored */
        if (sigaction(cleanup_signals[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            continue;
        sigaddset(&blocked, cleanup_signals[i]);
    }
    pthread_sigmask(SIG_BLOCK, &blocked, NULL);
    atomic_store(&blocked_ready, true);
}

static void *signal_thread(void *arg)
{
    (void)arg;
    int sig = 0;
    while (sigwait(&blocked, &sig) != 0)
        ;
    atomic_store(&cleanup_started, 1);
    for (int s = 0; s < MAX_LIVE_SETS; s++) {
        fs_output *o = atomic_load(&live_sets[s]);
        if (o && !atomic_load(&o->committed))
            remove_files(o);
    }
    /* the signal's default action, from this thread: the process ends with the signal's status */
    struct sigaction dfl;
    memset(&dfl, 0, sizeof dfl);
    dfl.sa_handler = SIG_DFL;
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, NULL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    pthread_sigmask(SIG_UNBLOCK, &one, NULL);
    raise(sig);
    _exit(128 + sig);
}

int fs_output_cleanup_on_signals(void)
{
    _Static_assert(ATOMIC_INT_LOCK_FREE == 2 && ATOMIC_POINTER_LOCK_FREE == 2 && ATOMIC_BOOL_LOCK_FREE == 2,
                   "the cleanup reads the sets with lock-free atomics");
    fs_output_block_signals();
    pthread_t t;
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
    int rc = pthread_create(&t, &attr, signal_thread, NULL);
    pthread_attr_destroy(&attr);
    if (rc != 0) {
        /* without the waiting thread the signals would stay blocked: back to their default action */
        pthread_sigmask(SIG_UNBLOCK, &blocked, NULL);
        fs_error(FS_ERR_INTERNAL, "cannot start the thread that cleans up on signals: %s", strerror(rc));
        return -1;
    }
    return 0;
}
