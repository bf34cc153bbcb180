/* Jobs files: parsing and checking every line, picking job N, listing (see jobs.h). */
#include "cli/jobs.h"

#include <ctype.h>
#include <errno.h>
#include <stdbool.h>
#include <stdlib.h>
#include <string.h>

#include "base/error.h"
#include "io/preset.h"

/* Splits line into blank-separated fields, in place and into field[], or only counts them when
 * field is NULL; returns their count. */
static int split_fields(char *line, char **field)
{
    int n = 0;
    char *p = line;
    while (*p) {
        while (*p && isspace((unsigned char)*p))
            p++;
        if (!*p)
            break;
        if (field)
            field[n] = p;
        n++;
        while (*p && !isspace((unsigned char)*p))
            p++;
        if (*p && field)
            *p++ = '\0';
    }
    return n;
}

static bool parse_seed(const char *s, uint64_t *seed)
{
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (end == s || *end || errno || s[0] == '-' || s[0] == '+')
        return false;
    *seed = v;
    return true;
}

/* SECTION.KEY=VALUE with non-empty section and key. */
static bool is_override(const char *s)
{
    const char *eq = strchr(s, '='), *dot = strchr(s, '.');
    return eq && dot && dot > s && dot + 1 < eq;
}

/* preset, made relative to dir when it is a relative path. */
static char *resolve_preset(const char *preset, const char *dir)
{
    if (!strchr(preset, '/') || preset[0] == '/' || !dir)
        return fs_strdup(preset);
    size_t n = strlen(dir) + strlen(preset) + 2;
    char *p = fs_malloc(n);
    snprintf(p, n, "%s/%s", dir, preset);
    return p;
}

void fs_jobs_free(fs_job *jobs, int n)
{
    if (!jobs)
        return;
    for (int i = 0; i < n; i++) {
        free(jobs[i].preset);
        free(jobs[i].name);
        for (int k = 0; k < jobs[i].n_sets; k++)
            free(jobs[i].sets[k]);
        free(jobs[i].sets);
    }
}

/* Reads one line of any length (without its newline) into *buf; returns false at the end. */
static bool read_line(FILE *f, char **buf, size_t *cap)
{
    size_t n = 0;
    int c;
    while ((c = fgetc(f)) != EOF && c != '\n') {
        if (n + 2 > *cap) {
            *cap = *cap ? 2 * *cap : 256;
            *buf = fs_realloc(*buf, *cap);
        }
        (*buf)[n++] = (char)c;
    }
    if (c == EOF && n == 0)
        return false;
    if (n + 1 > *cap) {
        *cap = n + 1;
        *buf = fs_realloc(*buf, *cap);
    }
    (*buf)[n] = '\0';
    return true;
}

static int bad_line(const char *path, int line, const char *what, const char *got)
{
    fs_error(FS_ERR_DATA, "%s:%d: %s%s%s%s", path, line, what, got ? ", got '" : "", got ? got : "", got ? "'" : "");
    return -1;
}

/* Parses one job line (fields already split). */
static int parse_job(const char *path, const char *dir, int line, char **field, int n, fs_job *job)
{
    if (n < 3)
        return bad_line(path, line, "expected PRESET SEED NAME [SECTION.KEY=VALUE]...", NULL);
    memset(job, 0, sizeof *job);
    job->line = line;
    if (!parse_seed(field[1], &job->seed))
        return bad_line(path, line, "SEED: expected a non-negative integer", field[1]);
    if (strchr(field[2], '/'))
        return bad_line(path, line, "NAME: expected a file name prefix without '/'", field[2]);
    for (int k = 3; k < n; k++) {
        if (!is_override(field[k]))
            return bad_line(path, line, "expected an override SECTION.KEY=VALUE", field[k]);
        /* the key and the value's syntax, checked as --set checks them (ranges that depend on the
         * preset are checked when the job runs) */
        fs_config scratch = fs_config_default();
        if (fs_preset_set(&scratch, field[k]) < 0) {
            char *msg = fs_strdup(fs_error_message());
            fs_error(FS_ERR_DATA, "%s:%d: %s", path, line, msg);
            free(msg);
            return -1;
        }
    }
    job->preset = resolve_preset(field[0], dir);
    job->name = fs_strdup(field[2]);
    job->n_sets = n - 3;
    job->sets = fs_calloc((size_t)job->n_sets + 1, sizeof *job->sets);
    for (int k = 3; k < n; k++)
        job->sets[k - 3] = fs_strdup(field[k]);
    return 0;
}

int fs_jobs_read(const char *path, fs_job **jobs)
{
    *jobs = NULL;
    FILE *f = fopen(path, "r");
    if (!f) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open the jobs file: %s", path, strerror(errno));
        return -1;
    }
    char *dir = fs_strdup(path);
    char *slash = strrchr(dir, '/');
    if (slash)
        slash[slash == dir ? 1 : 0] = '\0';
    else {
        free(dir);
        dir = NULL;
    }
    char *buf = NULL;
    size_t cap = 0;
    int n = 0, cap_jobs = 0, line = 0, rc = 0;
    fs_job *list = NULL;
    while (rc == 0 && read_line(f, &buf, &cap)) {
        line++;
        const char *p = buf;
        while (isspace((unsigned char)*p))
            p++;
        if (!*p || *p == '#')
            continue;
        int nf = split_fields(buf, NULL);
        char **field = fs_malloc(((size_t)nf + 1) * sizeof *field);
        split_fields(buf, field);
        if (n == cap_jobs) {
            cap_jobs = cap_jobs ? 2 * cap_jobs : 16;
            list = fs_realloc(list, (size_t)cap_jobs * sizeof *list);
        }
        rc = parse_job(path, dir, line, field, nf, &list[n]);
        free(field);
        if (rc < 0)
            break;
        for (int i = 0; i < n && rc == 0; i++)
            if (!strcmp(list[i].name, list[n].name)) {
                fs_error(FS_ERR_DATA, "%s:%d: NAME '%s' is already the name of the job on line %d (the jobs "
                                      "would write the same files)",
                         path, line, list[n].name, list[i].line);
                rc = -1;
            }
        n++;
    }
    bool read_error = ferror(f) != 0;
    fclose(f);
    free(buf);
    free(dir);
    if (rc == 0 && read_error) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot read the jobs file", path);
        rc = -1;
    }
    if (rc == 0 && n == 0) {
        fs_error(FS_ERR_DATA, "%s: no job in the file (expected lines PRESET SEED NAME [SECTION.KEY=VALUE]...)",
                 path);
        rc = -1;
    }
    if (rc < 0) {
        fs_jobs_free(list, n);
        free(list);
        return -1;
    }
    *jobs = list;
    return n;
}

int fs_job_load(const char *spec, fs_job *job)
{
    memset(job, 0, sizeof *job);
    const char *colon = strrchr(spec, ':');
    char *end = NULL;
    long k = 0;
    if (colon && colon != spec) {
        errno = 0;
        k = strtol(colon + 1, &end, 10);
    }
    if (!colon || colon == spec || end == colon + 1 || *end || errno || k < 1 || !isdigit((unsigned char)colon[1])) {
        fs_error(FS_ERR_USAGE, "--job: expected FILE:N with N a job number from 1, got '%s'", spec);
        return -1;
    }
    char *path = fs_strdup(spec);
    path[colon - spec] = '\0';
    fs_job *jobs;
    int n = fs_jobs_read(path, &jobs);
    if (n >= 0 && k > n)
        fs_error(FS_ERR_USAGE, "--job %s: %s has %d job%s, numbered 1 to %d", spec, path, n, n == 1 ? "" : "s", n);
    free(path);
    if (n < 0)
        return -1;
    if (k > n) {
        fs_jobs_free(jobs, n);
        free(jobs);
        return -1;
    }
    *job = jobs[k - 1];
    memset(&jobs[k - 1], 0, sizeof jobs[k - 1]);
    fs_jobs_free(jobs, n);
    free(jobs);
    return 0;
}

int fs_jobs_list(const char *path, FILE *out)
{
    fs_job *jobs;
    int n = fs_jobs_read(path, &jobs);
    if (n < 0)
        return -1;
    for (int i = 0; i < n; i++) {
        fprintf(out, "%d\t%s\t-s %llu -n %s", i + 1, jobs[i].name, (unsigned long long)jobs[i].seed, jobs[i].name);
        for (int k = 0; k < jobs[i].n_sets; k++)
            fprintf(out, " --set %s", jobs[i].sets[k]);
        fprintf(out, " %s\n", jobs[i].preset);
    }
    fs_jobs_free(jobs, n);
    free(jobs);
    return 0;
}

char *fs_job_expand_name(const char *pattern, const char *name)
{
    static const char key[] = "{name}";
    size_t count = 0;
    for (const char *p = strstr(pattern, key); p; p = strstr(p + 1, key))
        count++;
    char *out = fs_malloc(strlen(pattern) + count * strlen(name) + 1), *o = out;
    for (const char *p = pattern; *p;) {
        if (!strncmp(p, key, sizeof key - 1)) {
            o += sprintf(o, "%s", name);
            p += sizeof key - 1;
        } else {
            *o++ = *p++;
        }
    }
    *o = '\0';
    return out;
}
