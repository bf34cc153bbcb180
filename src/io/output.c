/* Atomic output sets: stage files under hidden temporary names, then rename them all into place. */
#include "io/output.h"

#include <errno.h>
#include <stdatomic.h>
#include <stdbool.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "base/error.h"

typedef struct {
    char *name;       /* file name without directory */
    char *temp_path;  /* dir/.NAME.tmp-PID-N, what the caller writes */
    char *final_path; /* dir/NAME */
} output_file;

struct fs_output {
    char *dir;
    output_file *files;
    int n_files, cap_files;
    char **extra_paths; /* final paths asked for names that were never staged */
    int n_extra, cap_extra;
};

/* Distinguishes temporary names of several output sets in one process. */
static atomic_ulong output_counter;

static char *join_path(const char *dir, const char *prefix, const char *name, const char *suffix)
{
    size_t n = strlen(dir) + strlen(prefix) + strlen(name) + strlen(suffix) + 2;
    char *p = fs_malloc(n);
    snprintf(p, n, "%s/%s%s%s", dir, prefix, name, suffix);
    return p;
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
    return o;
}

static output_file *find_file(fs_output *o, const char *name)
{
    for (int i = 0; i < o->n_files; i++)
        if (!strcmp(o->files[i].name, name))
            return &o->files[i];
    return NULL;
}

const char *fs_output_stage(fs_output *o, const char *name)
{
    FS_ASSERT(name && *name);
    output_file *f = find_file(o, name);
    if (f)
        return f->temp_path;
    if (o->n_files == o->cap_files) {
        o->cap_files = o->cap_files ? 2 * o->cap_files : 8;
        o->files = fs_realloc(o->files, (size_t)o->cap_files * sizeof *o->files);
    }
    f = &o->files[o->n_files++];
    f->name = fs_strdup(name);
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
    return f->temp_path;
}

const char *fs_output_final_path(fs_output *o, const char *name)
{
    output_file *f = find_file(o, name);
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

static void output_free(fs_output *o)
{
    for (int i = 0; i < o->n_files; i++) {
        free(o->files[i].name);
        free(o->files[i].temp_path);
        free(o->files[i].final_path);
    }
    for (int i = 0; i < o->n_extra; i++)
        free(o->extra_paths[i]);
    free(o->extra_paths);
    free(o->files);
    free(o->dir);
    free(o);
}

int fs_output_commit(fs_output *o)
{
    int rc = 0;
    int i = 0;
    for (; i < o->n_files; i++) {
        if (rename(o->files[i].temp_path, o->files[i].final_path) != 0) {
            fs_error(FS_ERR_IO, "%s: cannot move into place: %s", o->files[i].final_path, strerror(errno));
            rc = -1;
            break;
        }
    }
    /* After a failure, the files not yet renamed are removed rather than left behind. */
    for (; i < o->n_files; i++)
        unlink(o->files[i].temp_path);
    output_free(o);
    return rc;
}

void fs_output_abort(fs_output *o)
{
    if (!o)
        return;
    for (int i = 0; i < o->n_files; i++)
        unlink(o->files[i].temp_path);
    output_free(o);
}
