/* Batch jobs files (--job FILE:N, --list-jobs FILE): one run of fissure a line, for job arrays on
 * Slurm, GNU Parallel or any scheduler that hands out numbers. */
#ifndef FS_CLI_JOBS_H
#define FS_CLI_JOBS_H

#include <stdint.h>
#include <stdio.h>

/* One job: the run `fissure [OPTION]... -s SEED -n NAME --set OVERRIDE... PRESET`. */
typedef struct {
    char *preset;    /* as written, but a relative path (one with a '/') is made relative to the
                        jobs file's directory; a plain name is looked up on the preset path */
    uint64_t seed;
    char *name;      /* the output name */
    char **sets;     /* SECTION.KEY=VALUE overrides, applied after the command line's --set */
    int n_sets;
    int line;        /* where it is in the file (1-based) */
} fs_job;

/* The jobs of a file. Format (fissure(1), JOBS FILES): one job a line, fields separated by blanks:
 *     PRESET SEED NAME [SECTION.KEY=VALUE]...
 * Blank lines and lines whose first non-blank character is '#' are not jobs; jobs are numbered
 * from 1 in file order. SEED is a non-negative integer, NAME a file name prefix without '/' used
 * by no other job, each override has the form SECTION.KEY=VALUE (a value cannot hold blanks) and
 * names a preset key with a value of the right syntax, as --set checks them.
 * Every line is checked, so that every job of a bad file fails alike. Returns the number of jobs
 * (jobs allocated, fs_jobs_free frees them), or -1 with fs_error: FS_ERR_NOINPUT when the file
 * cannot be read, FS_ERR_DATA naming FILE:LINE and what was expected for a bad line or a file with
 * no job. */
int fs_jobs_read(const char *path, fs_job **jobs);
void fs_jobs_free(fs_job *jobs, int n);

/* Parses "FILE:N" (N from 1, the last ':' separating them) and reads job N of FILE into *job
 * (fs_jobs_free(job, 1) frees it). Returns 0, or -1 with fs_error: FS_ERR_USAGE for a spec that is
 * not FILE:N or an N past the last job, else as fs_jobs_read. */
int fs_job_load(const char *spec, fs_job *job);

/* Prints each job of the file as "N<TAB>NAME<TAB>the options of the same run made alone", one a
 * line. Returns 0, or -1 with fs_error as fs_jobs_read. */
int fs_jobs_list(const char *path, FILE *out);

/* pattern with every "{name}" replaced by name (caller frees): --mesh and --asset paths of a batch,
 * one file per job. */
char *fs_job_expand_name(const char *pattern, const char *name);

#endif
