/* Tests of atomic output sets (io/output.h): staging, commit, abort and unwritable directories. */
#include "io/output.h"

#include <dirent.h>
#include <signal.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "base/error.h"
#include "check.h"

static char tmpdir[] = "/tmp/fissure-test-output-XXXXXX";

static bool exists(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0;
}

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    CHECK_MSG(f != NULL, "cannot write %s", path);
    if (f) {
        fputs(text, f);
        fclose(f);
    }
}

static char *read_text(const char *path)
{
    static char buf[256];
    FILE *f = fopen(path, "r");
    if (!f)
        return NULL;
    size_t n = fread(buf, 1, sizeof buf - 1, f);
    buf[n] = '\0';
    fclose(f);
    return buf;
}

/* Number of directory entries other than . and .. */
static int count_entries(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return -1;
    int n = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            n++;
    closedir(d);
    return n;
}

static void remove_tree(const char *dir)
{
    DIR *d = opendir(dir);
    if (!d)
        return;
    struct dirent *e;
    char path[512];
    while ((e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, ".."))
            continue;
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (lstat(path, &st) == 0 && S_ISDIR(st.st_mode))
            remove_tree(path);
        else
            unlink(path);
    }
    closedir(d);
    rmdir(dir);
}

/* Staged files live under hidden temporary names in the final directory and nothing exists under
 * the final names until commit; after commit the final names hold the content and no temporary
 * file is left. Missing parent directories are created. */
static void test_commit(void)
{
    char dir[256];
    snprintf(dir, sizeof dir, "%s/a/b/c", tmpdir);
    fs_output *o = fs_output_begin(dir);
    CHECK_MSG(o != NULL, "%s", fs_error_message());
    if (!o)
        return;
    const char *t1 = fs_output_stage(o, "x_height.png");
    const char *t2 = fs_output_stage(o, "x.json");
    CHECK(strncmp(t1, dir, strlen(dir)) == 0 && t1[strlen(dir)] == '/' && t1[strlen(dir) + 1] == '.');
    CHECK(strstr(t1, "/.x_height.tmp-") != NULL && !strcmp(t1 + strlen(t1) - 4, ".png") && strcmp(t1, t2) != 0);
    CHECK(!strcmp(t2 + strlen(t2) - 5, ".json"));
    CHECK(fs_output_stage(o, "x.json") == t2);
    write_text(t1, "height");
    write_text(t2, "json");
    char f1[512], f2[512];
    snprintf(f1, sizeof f1, "%s", fs_output_final_path(o, "x_height.png"));
    snprintf(f2, sizeof f2, "%s", fs_output_final_path(o, "x.json"));
    CHECK(!strcmp(f1 + strlen(dir), "/x_height.png"));
    CHECK(!exists(f1) && !exists(f2));
    CHECK(exists(t1) && exists(t2));
    CHECK(fs_output_commit(o) == 0);
    CHECK(exists(f1) && exists(f2));
    const char *text = read_text(f1);
    CHECK(text && !strcmp(text, "height"));
    CHECK(count_entries(dir) == 2);
}

/* A committed set replaces earlier files of the same name. */
static void test_replace(void)
{
    char dir[256];
    snprintf(dir, sizeof dir, "%s/replace", tmpdir);
    fs_output *o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    write_text(fs_output_stage(o, "m.png"), "old");
    CHECK(fs_output_commit(o) == 0);
    o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    write_text(fs_output_stage(o, "m.png"), "new");
    char final[512];
    snprintf(final, sizeof final, "%s", fs_output_final_path(o, "m.png"));
    const char *text = read_text(final);
    CHECK(text && !strcmp(text, "old"));
    CHECK(fs_output_commit(o) == 0);
    text = read_text(final);
    CHECK(text && !strcmp(text, "new"));
    CHECK(count_entries(dir) == 1);
}

/* Abort removes every staged file: the directory is left as it was. */
static void test_abort(void)
{
    char dir[256];
    snprintf(dir, sizeof dir, "%s/abort", tmpdir);
    fs_output *o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    write_text(fs_output_stage(o, "a.png"), "a");
    write_text(fs_output_stage(o, "b.png"), "b");
    fs_output_stage(o, "never-written.png");
    CHECK(count_entries(dir) == 2);
    fs_output_abort(o);
    CHECK(count_entries(dir) == 0);
}

/* A staged file that was never written makes the commit fail with FS_ERR_IO, and leaves no
 * temporary file behind. */
static void test_commit_missing(void)
{
    char dir[256];
    snprintf(dir, sizeof dir, "%s/missing", tmpdir);
    fs_output *o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    fs_output_stage(o, "ghost.png");
    write_text(fs_output_stage(o, "after.png"), "x");
    fs_error_clear();
    CHECK(fs_output_commit(o) == -1);
    CHECK(fs_error_domain() == FS_ERR_IO);
    CHECK(count_entries(dir) == 0);
}

/* A name reaching into an existing subdirectory is staged beside its final place (the rename stays
 * within one directory). */
static void test_subdirectory(void)
{
    char dir[256], sub[300];
    snprintf(dir, sizeof dir, "%s/nested", tmpdir);
    snprintf(sub, sizeof sub, "%s/meshes", dir);
    fs_output *o = fs_output_begin(sub);
    CHECK(o != NULL);
    if (o)
        fs_output_abort(o);
    o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    const char *t = fs_output_stage(o, "meshes/x.obj");
    CHECK(strncmp(t, sub, strlen(sub)) == 0 && !strncmp(t + strlen(sub), "/.x.tmp-", 8));
    write_text(t, "o x");
    CHECK(fs_output_commit(o) == 0);
    char final[512];
    snprintf(final, sizeof final, "%s/x.obj", sub);
    CHECK(exists(final));
    CHECK(count_entries(sub) == 1);
}

/* A directory that cannot be created (its parent is a regular file), or that cannot be written,
 * gives FS_ERR_CANTCREAT and no output set. */
static void test_unwritable(void)
{
    char file[256], dir[512];
    snprintf(file, sizeof file, "%s/plain-file", tmpdir);
    write_text(file, "not a directory");
    snprintf(dir, sizeof dir, "%s/sub", file);
    fs_error_clear();
    CHECK(fs_output_begin(dir) == NULL);
    CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
    CHECK(strstr(fs_error_message(), "plain-file") != NULL);
    fs_error_clear();
    CHECK(fs_output_begin(file) == NULL);
    CHECK(fs_error_domain() == FS_ERR_CANTCREAT);

    /* Permission bits do not stop root, so this part only runs as an ordinary user. */
    if (geteuid() != 0) {
        snprintf(dir, sizeof dir, "%s/read-only", tmpdir);
        CHECK(mkdir(dir, 0555) == 0);
        fs_error_clear();
        CHECK(fs_output_begin(dir) == NULL);
        CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
        snprintf(file, sizeof file, "%s/read-only/below", tmpdir);
        fs_error_clear();
        CHECK(fs_output_begin(file) == NULL);
        CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
        chmod(dir, 0755);
    }
}

/* The sidecar (the seal) is moved last, and an old sidecar of the same name goes before any file
 * of the new set replaces one it lists; the set lists its files but the sidecar. */
static void test_seal(void)
{
    char dir[256], old_json[512], old_map[512], other[512];
    snprintf(dir, sizeof dir, "%s/seal", tmpdir);
    fs_output *o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    write_text(fs_output_stage(o, "n_height.png"), "old height");
    write_text(fs_output_stage(o, "n_normal.png"), "old normal");
    write_text(fs_output_stage_seal(o, "n.json"), "old sidecar");
    snprintf(old_json, sizeof old_json, "%s", fs_output_final_path(o, "n.json"));
    snprintf(old_map, sizeof old_map, "%s", fs_output_final_path(o, "n_normal.png"));
    CHECK(fs_output_commit(o) == 0);

    /* a second set of the same name whose commit fails half-way: one file was never written */
    o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    write_text(fs_output_stage(o, "n_height.png"), "new height");
    fs_output_stage(o, "n_normal.png");
    write_text(fs_output_stage_seal(o, "n.json"), "new sidecar");
    int n = 0;
    const char **names = fs_output_names(o, &n);
    CHECK(n == 2 && !strcmp(names[0], "n_height.png") && !strcmp(names[1], "n_normal.png"));
    free(names);
    fs_error_clear();
    CHECK(fs_output_commit(o) == -1);
    CHECK(fs_error_domain() == FS_ERR_IO);
    /* neither sidecar is left beside the files: the old one went first, the new one never came; the
     * new height that was already moved into place is removed again */
    CHECK(!exists(old_json));
    snprintf(other, sizeof other, "%s/n_height.png", dir);
    CHECK(!exists(other));
    const char *text = read_text(old_map);
    CHECK(text && !strcmp(text, "old normal"));
    CHECK(count_entries(dir) == 1);

    /* a whole set: the sidecar and its files, nothing else */
    o = fs_output_begin(dir);
    CHECK(o != NULL);
    if (!o)
        return;
    write_text(fs_output_stage(o, "n_height.png"), "third height");
    write_text(fs_output_stage_seal(o, "n.json"), "third sidecar");
    CHECK(fs_output_commit(o) == 0);
    text = read_text(old_json);
    CHECK(text && !strcmp(text, "third sidecar"));
    CHECK(count_entries(dir) == 3);
}

/* Files staged in another directory join a set and are committed with it, listed by absolute path;
 * files staged in the same directory keep their names. */
static void test_merge(void)
{
    char dir[256], elsewhere[256], same[256];
    snprintf(dir, sizeof dir, "%s/merge", tmpdir);
    snprintf(elsewhere, sizeof elsewhere, "%s/merge-mesh", tmpdir);
    snprintf(same, sizeof same, "%s/merge/.", tmpdir);
    fs_output *o = fs_output_begin(dir), *m = fs_output_begin(elsewhere), *f = fs_output_begin(same);
    CHECK(o && m && f);
    if (!o || !m || !f)
        return;
    write_text(fs_output_stage(o, "a.png"), "a");
    write_text(fs_output_stage(f, "a_frame_0001.png"), "frame");
    write_text(fs_output_stage(m, "a.obj"), "mesh");
    fs_output_merge(o, f);
    fs_output_merge(o, m);
    write_text(fs_output_stage_seal(o, "a.json"), "sidecar");
    int n = 0;
    const char **names = fs_output_names(o, &n);
    char want[512];
    snprintf(want, sizeof want, "%s/a.obj", elsewhere);
    CHECK(n == 3 && !strcmp(names[0], "a.png") && !strcmp(names[1], "a_frame_0001.png"));
    CHECK_MSG(n == 3 && !strcmp(names[2], want), "%s", n == 3 ? names[2] : "");
    free(names);
    CHECK(count_entries(elsewhere) == 1 && count_entries(dir) == 3);
    CHECK(fs_output_commit(o) == 0);
    CHECK(exists(want));
    CHECK(count_entries(elsewhere) == 1 && count_entries(dir) == 3);
}

/* fs_output_check creates nothing, accepts a directory still to be made below a writable one, and
 * refuses a path through a regular file or a name too long for a path. */
static void test_check(void)
{
    char dir[512], file[256];
    snprintf(dir, sizeof dir, "%s/check/a/b", tmpdir);
    CHECK(fs_output_check(dir, 40) == 0);
    snprintf(dir, sizeof dir, "%s/check", tmpdir);
    CHECK(!exists(dir));
    snprintf(file, sizeof file, "%s/check-file", tmpdir);
    write_text(file, "x");
    fs_error_clear();
    CHECK(fs_output_check(file, 40) == -1);
    CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
    CHECK_MSG(strstr(fs_error_message(), "not a directory") != NULL, "%s", fs_error_message());
    snprintf(dir, sizeof dir, "%s/below/c", file);
    fs_error_clear();
    CHECK(fs_output_check(dir, 40) == -1);
    CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
    fs_error_clear();
    CHECK(fs_output_check(tmpdir, 5000) == -1);
    CHECK(fs_error_domain() == FS_ERR_CANTCREAT);
    CHECK(fs_output_check(".", 40) == 0);
}

/* A termination signal removes the staged files of every uncommitted set, leaves committed files,
 * and ends the process by that signal (blocked in the main thread: the cleanup thread takes it). */
static void test_signal_cleanup(void)
{
    char dir[256];
    snprintf(dir, sizeof dir, "%s/signal", tmpdir);
    pid_t pid = fork();
    if (pid == 0) {
        if (fs_output_cleanup_on_signals() != 0)
            _exit(2);
        fs_output *done = fs_output_begin(dir);
        write_text(fs_output_stage(done, "kept.png"), "kept");
        if (fs_output_commit(done) != 0)
            _exit(3);
        fs_output *a = fs_output_begin(dir), *b = fs_output_begin(dir);
        for (int i = 0; i < 100; i++) {
            char name[32];
            snprintf(name, sizeof name, "f%03d.png", i);
            write_text(fs_output_stage(i % 2 ? a : b, name), "x");
        }
        fs_output_stage(a, "never-written.png");
        kill(getpid(), SIGTERM);
        for (;;)
            pause();
    }
    int status = 0;
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid);
    CHECK_MSG(WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM, "status %d", status);
    CHECK_MSG(count_entries(dir) == 1, "%d files left", count_entries(dir));
    char kept[512];
    snprintf(kept, sizeof kept, "%s/kept.png", dir);
    CHECK(exists(kept));
}

int main(void)
{
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 99;
    }
    RUN(test_commit);
    RUN(test_replace);
    RUN(test_abort);
    RUN(test_commit_missing);
    RUN(test_subdirectory);
    RUN(test_unwritable);
    RUN(test_seal);
    RUN(test_merge);
    RUN(test_check);
    RUN(test_signal_cleanup);
    remove_tree(tmpdir);
    return check_finish();
}
