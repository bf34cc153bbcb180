/* Atomic output: files are staged under temporary names in their final directory and renamed into
 * place together at the end, the set's sidecar last, so an interrupted or failed run leaves no
 * half-written file and no sidecar beside files of another run. */
#ifndef FS_IO_OUTPUT_H
#define FS_IO_OUTPUT_H

#include <stddef.h>
#include <stdio.h>

typedef struct fs_output fs_output;

/* Checks, before any work, that an output set could be started in dir: dir, or the nearest of its
 * ancestors that exists, is a writable directory, and dir/NAME fits in a path for a file name of
 * longest_name bytes. Creates nothing. Returns 0, or -1 with fs_error(FS_ERR_CANTCREAT). */
int fs_output_check(const char *dir, size_t longest_name);

/* The directory of a file path (malloc'd: "." for a bare name, "/" at the root), and in *file the
 * file name in it (pointing into path). */
char *fs_output_dir_of(const char *path, const char **file);

/* Starts an output set in directory dir (created if missing, with parents). Returns NULL with
 * fs_error(FS_ERR_CANTCREAT) if the directory cannot be created or written. */
fs_output *fs_output_begin(const char *dir);

/* Reserves a file named `name` (normally without a directory part; a relative subpath must name an
 * existing subdirectory) and returns the temporary path to write it to, valid until commit/abort:
 * "dir/.STEM.tmp-PID-N.EXT" for NAME = STEM.EXT (hidden, and keeping the extension that image
 * writers choose their format by). Staging the same name again returns the same path. */
const char *fs_output_stage(fs_output *o, const char *name);

/* fs_output_stage for the set's sidecar, the file that lists the others: the commit removes an
 * existing file of its final name before it moves any other file into place, and moves it last. */
const char *fs_output_stage_seal(fs_output *o, const char *name);

/* Moves every file staged in `from` (a set without a sidecar, possibly in another directory) into
 * o, to be committed with o's files (before o's sidecar), and frees `from`. */
void fs_output_merge(fs_output *o, fs_output *from);

/* The files of the set but its sidecar, in commit order, as the sidecar lists them: names relative
 * to o's directory, absolute paths for files merged from another directory. The array is the
 * caller's to free; its strings live until commit/abort. */
const char **fs_output_names(fs_output *o, int *count);

/* Final path of a staged file (dir/name). */
const char *fs_output_final_path(fs_output *o, const char *name);

/* Removes an existing sidecar of the set's name, then renames every staged file into place, the
 * sidecar last, then frees o. Returns 0 or -1 with fs_error(FS_ERR_IO) (a staged file that was never
 * written is an error); on failure nothing of the set stays: its temporary files are removed, and
 * so are the files already moved into place. */
int fs_output_commit(fs_output *o);

/* Removes every staged temporary file and frees o. */
void fs_output_abort(fs_output *o);

/* Blocks SIGHUP, SIGINT, SIGQUIT, SIGTERM, SIGXCPU and SIGXFSZ (those not ignored) in the
 * calling thread. The program calls it before any thread starts (from its preinit array, before
 * the libraries' constructors start theirs), so that every thread inherits the mask. */
void fs_output_block_signals(void);

/* Starts the thread that waits for those signals: on one it removes the temporary files of every
 * output set not yet committed, and the files a commit in progress has moved into place, then
 * ends the process by the same signal. SIGXFSZ makes the write that caused it fail instead.
 * SIGKILL cannot be caught: a killed run may leave its temporary files (fissure(1) says
 * what a reader makes of the rest). Returns 0, or -1 with fs_error (the signals then keep their
 * default action). */
int fs_output_cleanup_on_signals(void);

#endif
