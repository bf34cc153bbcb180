/* JSON documents through jansson: the only file that includes it (see json.h). */
#include "io/json.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* design: fs_json is jansson's json_t under another name; the casts are the whole wrapper. A
 * jansson constructor returns NULL only when out of memory, which the rest of fissure treats as
 * fatal (fs_malloc), so the wrappers do too. */
static void out_of_memory(const char *what)
{
    fprintf(stderr, "fissure: out of memory %s\n", what);
    abort();
}

static fs_json *wrap(json_t *v)
{
    if (!v)
        out_of_memory("building a JSON document");
    return (fs_json *)v;
}

static json_t *unwrap(const fs_json *v)
{
    return (json_t *)v;
}

fs_json *fs_json_object(void) { return wrap(json_object()); }
fs_json *fs_json_array(void) { return wrap(json_array()); }
fs_json *fs_json_bool(bool v) { return wrap(json_boolean(v)); }
fs_json *fs_json_null(void) { return wrap(json_null()); }
fs_json *fs_json_integer(int64_t v) { return wrap(json_integer((json_int_t)v)); }

fs_json *fs_json_string(const char *s)
{
    json_t *v = s ? json_string(s) : NULL;
    return wrap(v ? v : json_null());
}

bool fs_json_valid_utf8(const char *s)
{
    json_t *v = s ? json_string(s) : NULL;
    json_decref(v);
    return v != NULL;
}

fs_json *fs_json_real(double v)
{
    return wrap(isfinite(v) ? json_real(v) : json_null());
}

void fs_json_set(fs_json *obj, const char *key, fs_json *value)
{
    if (json_object_set_new(unwrap(obj), key, unwrap(value)) != 0)
        out_of_memory("setting a JSON key");
}

fs_json *fs_json_get(fs_json *obj, const char *key)
{
    return (fs_json *)json_object_get(unwrap(obj), key);
}

void fs_json_del(fs_json *obj, const char *key)
{
    json_object_del(unwrap(obj), key);
}

void fs_json_append(fs_json *array, fs_json *value)
{
    if (json_array_append_new(unwrap(array), unwrap(value)) != 0)
        out_of_memory("appending to a JSON array");
}

size_t fs_json_size(const fs_json *v)
{
    json_t *j = unwrap(v);
    return json_is_array(j) ? json_array_size(j) : json_is_object(j) ? json_object_size(j) : 0;
}

fs_json *fs_json_at(fs_json *array, size_t i)
{
    return (fs_json *)json_array_get(unwrap(array), i);
}

const char *fs_json_text(const fs_json *v)
{
    return json_string_value(unwrap(v));
}

double fs_json_number(const fs_json *v)
{
    json_t *j = unwrap(v);
    return json_is_number(j) ? json_number_value(j) : NAN;
}

fs_json *fs_json_read(const char *path)
{
    return (fs_json *)json_load_file(path, 0, NULL);
}

static size_t flags(fs_json_format fmt)
{
    size_t f = JSON_PRESERVE_ORDER | JSON_INDENT(fmt.indent < 0 ? 0 : fmt.indent > 31 ? 31 : fmt.indent);
    if (fmt.precision > 0)
        f |= JSON_REAL_PRECISION(fmt.precision > 31 ? 31 : fmt.precision);
    if (fmt.indent <= 0)
        f |= JSON_COMPACT;
    return f;
}

int fs_json_write(const fs_json *root, const char *path, fs_json_format fmt)
{
    return json_dump_file(unwrap(root), path, flags(fmt)) == 0 ? 0 : -1;
}

char *fs_json_dump(const fs_json *root, fs_json_format fmt)
{
    return json_dumps(unwrap(root), flags(fmt));
}

void fs_json_free(fs_json *v)
{
    json_decref(unwrap(v));
}
