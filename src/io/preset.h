/* Presets: INI files (libinih) into fs_config, key by key checked, and back to INI. */
#ifndef FS_IO_PRESET_H
#define FS_IO_PRESET_H

#include <stdio.h>

#include "sim/settings.h"

/* Parses the preset file at path over cfg (which the caller set to fs_config_default()). Unknown
 * sections and keys, bad types, values out of range and disallowed words are errors reported as
 *   FILE:LINE: [section] key: expected ..., got '...'
 * Only a regular file of at most 1 MiB is read (a FIFO or a device is refused without blocking).
 * Returns 0, or -1 with fs_error(FS_ERR_NOINPUT) for a missing, unreadable or irregular file or
 * FS_ERR_DATA for bad content or a file over the cap. */
int fs_preset_load(const char *path, fs_config *cfg);

/* The text of the preset file at path (for its hash): a regular file of at most 1 MiB, as
 * fs_preset_load reads it. Returns a malloc'd string, or NULL with fs_error. */
char *fs_preset_read_text(const char *path);

/* Parses a preset from memory; `origin` names it in messages. */
int fs_preset_load_string(const char *text, const char *origin, fs_config *cfg);

/* Applies one override "section.key=value" (the --set option) with the same checks; messages read
 * "--set section.key: expected ...". Returns 0 or -1 with fs_error(FS_ERR_USAGE or FS_ERR_DATA). */
int fs_preset_set(fs_config *cfg, const char *assignment);

/* Checks cross-key consistency (e.g. cylinder needs a radius, sphere is not periodic). */
int fs_preset_validate(const fs_config *cfg, const char *origin);

/* Calls fn for every key of the resolved configuration in a fixed order, with its value formatted
 * exactly as the parser reads it back. Used by --dump-preset and the JSON sidecar. */
typedef void (*fs_preset_visit_fn)(void *ctx, const char *section, const char *key, const char *value);
void fs_preset_visit(const fs_config *cfg, fs_preset_visit_fn fn, void *ctx);

/* Writes the resolved configuration as INI that parses back to the same config. */
void fs_preset_dump(const fs_config *cfg, FILE *out);

/* Resolves a preset argument: an existing path is used as is; otherwise NAME (or NAME.ini) is searched
 * on the preset path: $FISSURE_PRESET_PATH (colon-separated), $XDG_DATA_HOME/fissure/presets
 * (default ~/.local/share), the installed FS_PKGDATADIR/presets, and the source tree's presets/
 * (FS_SRCDIR/presets) for an uninstalled build. Returns a malloc'd path, or NULL with
 * fs_error(FS_ERR_NOINPUT) listing where it looked. */
char *fs_preset_find(const char *name);

/* Lists the presets found on the preset path, one per line "NAME<TAB>DESCRIPTION", sorted by name,
 * each name once (the first found wins). Returns the count, or -1 with fs_error. */
int fs_preset_list(FILE *out);

#endif
