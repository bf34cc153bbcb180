/* Atomic output: files are staged under temporary names in their final directory and renamed into
 * place together at the end, so an interrupted or failed run leaves no half-written file. */
#ifndef FS_IO_OUTPUT_H
#define FS_IO_OUTPUT_H

#include <stdio.h>

typedef struct fs_output fs_output;

/* Starts an output set in directory dir (created if missing, with parents). Returns NULL with
 * fs_error(FS_ERR_CANTCREAT) if the directory cannot be created or written. */
fs_output *fs_output_begin(const char *dir);

/* Reserves a file named `name` (normally without a directory part; a relative subpath must name an
 * existing subdirectory) and returns the temporary path to write it to, valid until commit/abort:
 * "dir/.STEM.tmp-PID-N.EXT" for NAME = STEM.EXT (hidden, and keeping the extension that image
 * writers choose their format by). Staging the same name again returns the same path. */
const char *fs_output_stage(fs_output *o, const char *name);

/* Final path of a staged file (dir/name). */
const char *fs_output_final_path(fs_output *o, const char *name);

/* Renames every staged file into place, then frees o. Returns 0 or -1 with fs_error(FS_ERR_IO)
 * (a staged file that was never written is an error); on failure the temporary files not yet
 * renamed are removed. */
int fs_output_commit(fs_output *o);

/* Removes every staged temporary file and frees o. */
void fs_output_abort(fs_output *o);

#endif
