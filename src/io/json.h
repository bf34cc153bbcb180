/* JSON documents for the files fissure writes (sidecar, crack graph, glTF): a small C interface to
 * jansson, implemented in json.c, the only file that includes jansson. */
#ifndef FS_IO_JSON_H
#define FS_IO_JSON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/* A JSON value (object, array, string, number, true, false or null). Values are built bottom up:
 * a value handed to fs_json_set or fs_json_append belongs to its parent from then on, and freeing
 * the root frees the whole tree. Objects keep their keys in insertion order. */
typedef struct fs_json fs_json;

fs_json *fs_json_object(void);
fs_json *fs_json_array(void);
fs_json *fs_json_string(const char *s); /* UTF-8; NULL or invalid UTF-8 gives null */
bool fs_json_valid_utf8(const char *s);  /* whether fs_json_string keeps s */
fs_json *fs_json_integer(int64_t v);
fs_json *fs_json_real(double v);        /* a non-finite v gives null (JSON has no such number) */
fs_json *fs_json_bool(bool v);
fs_json *fs_json_null(void);

/* Sets obj[key] = value (replacing an old value), taking value. */
void fs_json_set(fs_json *obj, const char *key, fs_json *value);
/* obj[key] (borrowed), or NULL when missing. */
fs_json *fs_json_get(fs_json *obj, const char *key);
/* Removes obj[key] if present. */
void fs_json_del(fs_json *obj, const char *key);
/* Appends value to array, taking value. */
void fs_json_append(fs_json *array, fs_json *value);
/* Number of elements of an array or keys of an object. */
size_t fs_json_size(const fs_json *v);

/* Reading back a document (tests and tools check what was written): array[i] (borrowed, NULL out
 * of range), a string's text (NULL when v is not a string), a number's value (NaN when v is not a
 * number). */
fs_json *fs_json_at(fs_json *array, size_t i);
const char *fs_json_text(const fs_json *v);
double fs_json_number(const fs_json *v);

/* Formatting of a written document: indent spaces per level (0: one line), and the significant
 * digits of reals (0: as many as make the double read back exactly). */
typedef struct {
    int indent;
    int precision;
} fs_json_format;

/* Writes root to exactly path (not atomic by itself: io/output.h stages files). Returns 0, or -1
 * without fs_error, errno saying why: the caller names the file it was writing. */
int fs_json_write(const fs_json *root, const char *path, fs_json_format fmt);

/* The document as a NUL-terminated string (caller frees), or NULL when out of memory. */
char *fs_json_dump(const fs_json *root, fs_json_format fmt);

/* Parses the JSON file at path; NULL when it cannot be read or is not JSON (the caller reports). */
fs_json *fs_json_read(const char *path);

void fs_json_free(fs_json *v);

#endif
