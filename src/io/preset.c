/* Presets: INI text (through libinih) into fs_config with every key checked, back to INI, and the preset path. */
#include "io/preset.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <ini.h>
#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include "base/error.h"

/* The table below stores enums and counts through int pointers. */
_Static_assert(sizeof(fs_model_kind) == sizeof(int), "enum fs_model_kind is int-sized");
_Static_assert(sizeof(fs_domain_type) == sizeof(int), "enum fs_domain_type is int-sized");
_Static_assert(sizeof(fs_lattice) == sizeof(int), "enum fs_lattice is int-sized");
_Static_assert(sizeof(fs_growth_type) == sizeof(int), "enum fs_growth_type is int-sized");
_Static_assert(sizeof(fs_fracture_method) == sizeof(int), "enum fs_fracture_method is int-sized");
_Static_assert(sizeof(fs_normal_convention) == sizeof(int), "enum fs_normal_convention is int-sized");
_Static_assert(sizeof(fs_solver_method) == sizeof(int), "enum fs_solver_method is int-sized");
_Static_assert(sizeof(fs_relax_mode) == sizeof(int), "enum fs_relax_mode is int-sized");
_Static_assert(_Generic((int32_t)0, int: 1, default: 0), "int32_t is int");

typedef enum {
    KEY_NAME,      /* char[64]: 1..63 characters of [A-Za-z0-9._-] */
    KEY_TEXT,      /* char[256]: one line of at most 255 characters */
    KEY_PATH,      /* char[FS_PATH_MAX]: a file name, relative ones resolved against the preset's directory */
    KEY_WORD,      /* an enum, one of `words` in enum order */
    KEY_BOOL,      /* bool */
    KEY_REAL,      /* double within the bounds */
    KEY_REAL_NONE, /* double within the bounds, or "none" stored as -1 */
    KEY_INT,       /* int within the bounds */
    KEY_SEED,      /* uint64_t */
    KEY_PWL,       /* fs_pwl as "t:v, t:v, ..." or "none" */
    KEY_SIZE,      /* render.width and render.height (or the preview's) as WxH */
    KEY_COLOR,     /* float[3] linear light, written as sRGB #rrggbb */
    KEY_PERIODIC   /* domain.periodic_x and periodic_y as none|x|y|xy */
} key_kind;

/* Bounds of numeric keys. */
enum { GT = 1, GE = 2, LT = 4, LE = 8 };

typedef struct {
    const char *section;
    const char *key;
    key_kind kind;
    size_t offset;            /* of the field in fs_config */
    double lo, hi;
    unsigned bounds;
    const char *const *words; /* KEY_WORD: allowed words, NULL-terminated, in enum order */
    const char *unit;         /* shown in messages, or NULL */
} key_def;

static const char *const section_names[] = {"preset", "domain", "mesh", "material", "growth",
                                            "shrink", "fracture", "time", "render", "voronoi", "solver",
                                            "wedge", "springs", "tet", "shell", NULL};
static const char *const model_words[] = {"voronoi", "springs", "wedge", "shell", "tet", NULL};
static const char *const domain_words[] = {"plane", "cylinder", "sphere", "mesh", NULL};
static const char *const periodic_words[] = {"none", "x", "y", "xy", NULL};
static const char *const lattice_words[] = {"random", "hex", NULL};
static const char *const growth_words[] = {"none", "planar", "cylinder", "sphere", NULL};
static const char *const method_words[] = {"split", "remove", NULL};
static const char *const normal_words[] = {"opengl", "directx", NULL};
static const char *const solver_words[] = {"cholmod", "cg", NULL};
static const char *const relax_words[] = {"auto", "global", "local", NULL};
static const char *const post_words[] = {"glue", "curl", "flat", NULL};

#define OFF(field) offsetof(fs_config, field)

/* Every key, in the order of SPEC §8 and of the dump. */
static const key_def key_table[] = {
    {"preset", "name", KEY_NAME, OFF(preset.name), 0, 0, 0, NULL, NULL},
    {"preset", "description", KEY_TEXT, OFF(preset.description), 0, 0, 0, NULL, NULL},
    {"preset", "model", KEY_WORD, OFF(preset.model), 0, 0, 0, model_words, NULL},
    {"preset", "seed", KEY_SEED, OFF(preset.seed), 0, 0, 0, NULL, NULL},

    {"domain", "type", KEY_WORD, OFF(domain.type), 0, 0, 0, domain_words, NULL},
    {"domain", "width", KEY_REAL, OFF(domain.width), 0, 1e6, GT | LE, NULL, "cm"},
    {"domain", "height", KEY_REAL, OFF(domain.height), 0, 1e6, GT | LE, NULL, "cm"},
    {"domain", "radius", KEY_REAL, OFF(domain.radius), 0, 1e6, GT | LE, NULL, "cm"},
    {"domain", "periodic", KEY_PERIODIC, 0, 0, 0, 0, periodic_words, NULL},
    {"domain", "file", KEY_PATH, OFF(domain_file), 0, 0, 0, NULL, NULL},

    {"mesh", "elements", KEY_INT, OFF(mesh.elements), 16, 20000000, GE | LE, NULL, NULL},
    {"mesh", "min_size", KEY_REAL, OFF(mesh.min_size), 0, 0, GT, NULL, "cm"},
    {"mesh", "lattice", KEY_WORD, OFF(mesh.lattice), 0, 0, 0, lattice_words, NULL},
    {"mesh", "relax_iterations", KEY_INT, OFF(mesh.relax_iterations), 0, 1000, GE | LE, NULL, NULL},
    {"mesh", "radius_jitter", KEY_REAL, OFF(mesh.radius_jitter), 0, 0.9, GE | LE, NULL, NULL},
    {"mesh", "refine_vm", KEY_REAL, OFF(mesh.refine_vm), 0, 100, GE | LE, NULL, NULL},
    {"mesh", "refine_vm_rounds", KEY_INT, OFF(mesh.refine_vm_rounds), 1, 100, GE | LE, NULL, NULL},
    {"mesh", "smooth_radius", KEY_REAL, OFF(mesh.smooth_radius), 0, 100, GE | LE, NULL, "edge lengths"},
    {"mesh", "smooth_iterations", KEY_INT, OFF(mesh.smooth_iterations), 1, 100, GE | LE, NULL, NULL},

    {"material", "young", KEY_REAL, OFF(material.young), 0, 0, GT, NULL, "MPa"},
    {"material", "poisson", KEY_REAL, OFF(material.poisson), 0, 0.499, GE | LE, NULL, NULL},
    {"material", "threshold", KEY_REAL, OFF(material.threshold), 0, 0, GT, NULL, "kPa"},
    {"material", "toughness", KEY_REAL, OFF(material.toughness), 0, 0, GE, NULL, "J/m^2"},
    {"material", "thickness", KEY_REAL, OFF(material.thickness), 0, 0, GT, NULL, "cm"},
    {"material", "thickness_final", KEY_REAL_NONE, OFF(material.thickness_final), 0, 0, GT, NULL, "cm"},
    {"material", "thickness_map", KEY_PATH, OFF(material_files.thickness_map), 0, 0, 0, NULL, NULL},
    {"material", "young_map", KEY_PATH, OFF(material_files.young_map), 0, 0, 0, NULL, NULL},
    {"material", "threshold_map", KEY_PATH, OFF(material_files.threshold_map), 0, 0, 0, NULL, NULL},
    {"material", "jitter", KEY_REAL, OFF(material.jitter), 0, 0.99, GE | LE, NULL, NULL},

    {"growth", "type", KEY_WORD, OFF(growth.type), 0, 0, 0, growth_words, NULL},
    {"growth", "r1", KEY_REAL, OFF(growth.r1), 0, 0, 0, NULL, NULL},
    {"growth", "r2", KEY_REAL, OFF(growth.r2), 0, 0, 0, NULL, NULL},
    {"growth", "angle", KEY_REAL, OFF(growth.angle), 0, 0, 0, NULL, "degrees"},
    {"growth", "rate", KEY_REAL, OFF(growth.rate), 0, 0, 0, NULL, NULL},
    {"growth", "axis_ratio", KEY_REAL, OFF(growth.axis_ratio), 0, 0, GT, NULL, NULL},

    {"shrink", "top", KEY_PWL, OFF(shrink.top), 0, 0, 0, NULL, NULL},
    {"shrink", "bottom", KEY_PWL, OFF(shrink.bottom), 0, 0, 0, NULL, NULL},

    {"fracture", "method", KEY_WORD, OFF(fracture.method), 0, 0, 0, method_words, NULL},
    {"fracture", "griffith", KEY_BOOL, OFF(fracture.griffith), 0, 0, 0, NULL, NULL},
    {"fracture", "tip_submodel", KEY_BOOL, OFF(fracture.tip_submodel), 0, 0, 0, NULL, NULL},
    {"fracture", "tip_submodel_radius", KEY_REAL, OFF(fracture.tip_submodel_radius), 1, 100, GE | LE, NULL,
     "edge lengths"},
    {"fracture", "tip_submodel_size", KEY_REAL, OFF(fracture.tip_submodel_size), 0.01, 1, GE | LE, NULL,
     "edge lengths"},
    {"fracture", "direction_radius", KEY_REAL, OFF(fracture.direction_radius), 0, 10, GE | LE, NULL,
     "edge lengths"},

    {"time", "end", KEY_REAL, OFF(time.end), 0, 0, GT, NULL, NULL},
    {"time", "min_step", KEY_REAL, OFF(time.min_step), 0, 0, GT, NULL, NULL},

    {"render", "size", KEY_SIZE, 0, 16, 16384, GE | LE, NULL, NULL},
    {"render", "preview_size", KEY_SIZE, OFF(render.preview_width), 16, 16384, GE | LE, NULL, NULL},
    {"render", "height_scale", KEY_REAL, OFF(render.height_scale), 0, 0, GT, NULL, NULL},
    {"render", "opening_scale", KEY_REAL, OFF(render.opening_scale), 0, 50, GT | LE, NULL, NULL},
    {"render", "wall_slope", KEY_REAL, OFF(render.wall_slope), 0, 1, GE | LE, NULL, NULL},
    {"render", "supersample", KEY_INT, OFF(render.supersample), 1, 8, GE | LE, NULL, NULL},
    {"render", "normal", KEY_WORD, OFF(render.normal), 0, 0, 0, normal_words, NULL},
    {"render", "color_material", KEY_COLOR, OFF(render.color_material), 0, 0, 0, NULL, NULL},
    {"render", "color_crack", KEY_COLOR, OFF(render.color_crack), 0, 0, 0, NULL, NULL},
    {"render", "color_background", KEY_COLOR, OFF(render.color_background), 0, 0, 0, NULL, NULL},
    {"render", "color_variation", KEY_REAL, OFF(render.color_variation), 0, 1, GE | LE, NULL, NULL},
    {"render", "roughness", KEY_REAL, OFF(render.roughness), 0, 1, GE | LE, NULL, NULL},

    {"voronoi", "crack_width", KEY_REAL, OFF(voronoi.crack_width), 0, 0, GE, NULL, "cm"},
    {"voronoi", "bevel", KEY_REAL, OFF(voronoi.bevel), 0, 0, GE, NULL, "cm"},
    {"voronoi", "depth", KEY_REAL, OFF(voronoi.depth), 0, 0, GT, NULL, "cm"},
    {"voronoi", "warp", KEY_REAL, OFF(voronoi.warp), 0, 0, GE, NULL, "cm"},
    {"voronoi", "warp_scale", KEY_REAL, OFF(voronoi.warp_scale), 0, 0, GT, NULL, "cm"},
    {"voronoi", "subdivisions", KEY_INT, OFF(voronoi.subdivisions), 1, 64, GE | LE, NULL, NULL},

    {"solver", "method", KEY_WORD, OFF(solver.method), 0, 0, 0, solver_words, NULL},
    {"solver", "tolerance", KEY_REAL, OFF(solver.tolerance), 0, 0.1, GT | LE, NULL, NULL},
    {"solver", "max_iterations", KEY_INT, OFF(solver.max_iterations), 0, 1000000000, GE | LE, NULL, NULL},
    {"solver", "relax", KEY_WORD, OFF(solver.relax), 0, 0, 0, relax_words, NULL},
    {"solver", "relax_radius", KEY_REAL, OFF(solver.relax_radius), 1, 1e6, GE | LE, NULL, "edge lengths"},
    {"solver", "relax_tolerance", KEY_REAL, OFF(solver.relax_tolerance), 0, 0.1, GT | LE, NULL, NULL},

    {"wedge", "thickness_gradient", KEY_REAL, OFF(wedge.thickness_gradient), -1.9, 1.9, GE | LE, NULL, NULL},

    {"springs", "layers", KEY_INT, OFF(springs.layers), 1, 8, GE | LE, NULL, NULL},
    {"springs", "shear_lag", KEY_REAL, OFF(springs.shear_lag), 0, 1e6, GT | LE, NULL, NULL},
    {"springs", "slide_length", KEY_REAL_NONE, OFF(springs.slide_length), 0, 0, GT, NULL, "cm"},
    {"springs", "residual", KEY_REAL, OFF(springs.residual), 0, 0.01, GT | LE, NULL, NULL},
    {"springs", "max_breaks", KEY_INT, OFF(springs.max_breaks), 0, 2000000000, GE | LE, NULL, NULL},
    {"springs", "post", KEY_WORD, OFF(springs.post), 0, 0, 0, post_words, NULL},
    {"springs", "peel", KEY_REAL, OFF(springs.peel), 0, 0, GE, NULL, "cm"},

    {"tet", "layers", KEY_INT, OFF(tet.layers), 0, 64, GE | LE, NULL, NULL},
    {"tet", "snap_distance", KEY_REAL, OFF(tet.snap_distance), 0, 0.45, GE | LE, NULL, "edge lengths"},
    {"tet", "snap_angle", KEY_REAL, OFF(tet.snap_angle), 0, 30, GE | LE, NULL, "degrees"},
    {"tet", "bond", KEY_REAL, OFF(tet.bond), 0, 0, GE, NULL, "kPa"},
    {"tet", "max_events", KEY_INT, OFF(tet.max_events), 0, 2000000000, GE | LE, NULL, NULL},
    {"shell", "bond", KEY_REAL, OFF(shell.bond), 0, 1e6, GE | LE, NULL, NULL},
    {"shell", "yield", KEY_REAL, OFF(shell.yield), 0, 0, GE, NULL, "kPa"},
    {"shell", "hardening", KEY_REAL, OFF(shell.hardening), 0, 0, GE, NULL, NULL},
    {"shell", "budge", KEY_REAL, OFF(shell.budge), 0, 0.45, GE | LE, NULL, NULL},
    {"shell", "gap_scale", KEY_REAL, OFF(shell.gap_scale), 1, 1e6, GE | LE, NULL, NULL},
    {"shell", "max_step", KEY_REAL, OFF(shell.max_step), 0, 1, GT | LE, NULL, NULL},
};

#define N_KEYS ((int)(sizeof key_table / sizeof key_table[0]))

static const char *const syntax_message = "syntax error: expected 'key = value' or '[section]'";

/* Largest preset file read (fissure-preset(5)). Presets are a few kilobytes; the cap keeps a huge
 * or endless file from being read into memory without end. */
#define PRESET_MAX_BYTES (1024 * 1024)

/* file_status for something that exists but is neither a regular file nor a directory (a device,
 * a FIFO, a socket): reading it could block or never end. */
#define NOT_REGULAR (-1)

static const char *status_text(int status)
{
    return status == NOT_REGULAR ? "not a regular file" : strerror(status);
}

/* Opens a preset for reading if it is a regular file of at most PRESET_MAX_BYTES. The open does not
 * block (O_NONBLOCK: a FIFO would wait for a writer) and the checks are on the opened file. Returns
 * the stream, or NULL with fs_error(FS_ERR_NOINPUT), or FS_ERR_DATA for a file over the cap. */
static FILE *open_preset(const char *path)
{
    int fd = open(path, O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
    if (fd < 0) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: %s", path, strerror(errno));
        return NULL;
    }
    struct stat st;
    int status = fstat(fd, &st) != 0 ? errno : S_ISDIR(st.st_mode) ? EISDIR : !S_ISREG(st.st_mode) ? NOT_REGULAR : 0;
    if (status != 0) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: %s", path, status_text(status));
        close(fd);
        return NULL;
    }
    if (st.st_size > PRESET_MAX_BYTES) {
        fs_error(FS_ERR_DATA, "%s: preset of %lld bytes: expected at most %d bytes (1 MiB)", path,
                 (long long)st.st_size, PRESET_MAX_BYTES);
        close(fd);
        return NULL;
    }
    int flags = fcntl(fd, F_GETFL);
    FILE *fp = flags == -1 || fcntl(fd, F_SETFL, flags & ~O_NONBLOCK) == -1 ? NULL : fdopen(fd, "r");
    if (!fp) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: %s", path, strerror(errno));
        close(fd);
    }
    return fp;
}

char *fs_preset_read_text(const char *path)
{
    FILE *fp = open_preset(path);
    if (!fp)
        return NULL;
    char *text = fs_malloc(PRESET_MAX_BYTES + 2);
    size_t n = fread(text, 1, PRESET_MAX_BYTES + 1, fp);
    bool failed = ferror(fp) != 0;
    fclose(fp);
    if (failed || n > PRESET_MAX_BYTES) {
        if (failed)
            fs_error(FS_ERR_IO, "%s: cannot read preset", path);
        else
            fs_error(FS_ERR_DATA, "%s: preset larger than %d bytes (1 MiB)", path, PRESET_MAX_BYTES);
        free(text);
        return NULL;
    }
    text[n] = '\0';
    return fs_realloc(text, n + 1);
}

/* ---- small string helpers ---- */

static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

/* "a, b or c" */
static void join_words(const char *const *words, const char *last_sep, char *buf, size_t size)
{
    size_t len = 0;
    buf[0] = '\0';
    for (int i = 0; words[i]; i++) {
        const char *sep = i == 0 ? "" : words[i + 1] ? ", " : last_sep;
        int w = snprintf(buf + len, size - len, "%s%s", sep, words[i]);
        if (w < 0 || (size_t)w >= size - len)
            return;
        len += (size_t)w;
    }
}

/* A value as it appears in a message: long ones are cut. */
static const char *shown(const char *value, char buf[80])
{
    if (strlen(value) < 72)
        return value;
    memcpy(buf, value, 64);
    strcpy(buf + 64, "...");
    return buf;
}

static int section_index(const char *section)
{
    for (int i = 0; section_names[i]; i++)
        if (!strcmp(section_names[i], section))
            return i;
    return -1;
}

static int key_index(const char *section, const char *key)
{
    for (int i = 0; i < N_KEYS; i++)
        if (!strcmp(key_table[i].section, section) && !strcmp(key_table[i].key, key))
            return i;
    return -1;
}

static void section_keys(const char *section, char *buf, size_t size)
{
    const char *words[N_KEYS + 1];
    int n = 0;
    for (int i = 0; i < N_KEYS; i++)
        if (!strcmp(key_table[i].section, section))
            words[n++] = key_table[i].key;
    words[n] = NULL;
    join_words(words, ", ", buf, size);
}

/* ---- values ---- */

/* Whether s is a decimal number as fissure-preset(5) defines it: an optional sign, digits with an
 * optional decimal point (a digit on at least one side), an optional exponent e or E with an
 * optional sign and digits. strtod alone also takes hexadecimal (0x10, 0x1p3), inf and nan. */
static bool decimal_syntax(const char *s)
{
    const char *p = s;
    if (*p == '+' || *p == '-')
        p++;
    int digits = 0;
    while (isdigit((unsigned char)*p)) {
        p++;
        digits++;
    }
    if (*p == '.') {
        p++;
        while (isdigit((unsigned char)*p)) {
            p++;
            digits++;
        }
    }
    if (digits == 0)
        return false;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!isdigit((unsigned char)*p))
            return false;
        while (isdigit((unsigned char)*p))
            p++;
    }
    return *p == '\0';
}

/* A finite decimal number, the whole string consumed. */
static int parse_real(const char *s, double *out)
{
    if (!decimal_syntax(s))
        return -1;
    char *end;
    double v = strtod(s, &end);
    if (end == s || *end || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* A decimal integer, the whole string consumed, within the range of long long. */
static int parse_integer(const char *s, long long *out)
{
    if (!*s || isspace((unsigned char)*s))
        return -1;
    char *end;
    errno = 0;
    long long v = strtoll(s, &end, 10);
    if (end == s || *end || errno == ERANGE)
        return -1;
    *out = v;
    return 0;
}

static int parse_seed(const char *s, uint64_t *out)
{
    for (const char *p = s; *p; p++)
        if (!isdigit((unsigned char)*p))
            return -1;
    if (!*s)
        return -1;
    char *end;
    errno = 0;
    unsigned long long v = strtoull(s, &end, 10);
    if (*end || errno == ERANGE)
        return -1;
    *out = (uint64_t)v;
    return 0;
}

static bool in_bounds(const key_def *k, double v)
{
    if ((k->bounds & GT) && !(v > k->lo))
        return false;
    if ((k->bounds & GE) && !(v >= k->lo))
        return false;
    if ((k->bounds & LT) && !(v < k->hi))
        return false;
    if ((k->bounds & LE) && !(v <= k->hi))
        return false;
    return true;
}

/* What a numeric key accepts: "a number in (0, 1e+06] (cm)". */
static void describe_number(const key_def *k, const char *what, char *buf, size_t size)
{
    char range[96] = "";
    unsigned lo = k->bounds & (GT | GE), hi = k->bounds & (LT | LE);
    if (lo && hi)
        snprintf(range, sizeof range, " in %c%g, %g%c", lo == GT ? '(' : '[', k->lo, k->hi, hi == LT ? ')' : ']');
    else if (lo)
        snprintf(range, sizeof range, " %s %g", lo == GT ? ">" : ">=", k->lo);
    else if (hi)
        snprintf(range, sizeof range, " %s %g", hi == LT ? "<" : "<=", k->hi);
    char unit[32] = "";
    if (k->unit)
        snprintf(unit, sizeof unit, " (%s)", k->unit);
    snprintf(buf, size, "%s%s%s", what, range, unit);
}

/* Whether the text survives being written as an INI value ("key = value") and read back: no control
 * characters, no ';' after white space (which inih takes for a comment), and no ';' first (the
 * dump puts a space before the value, after which it would start a comment). */
static bool representable(const char *s)
{
    if (*s == ';')
        return false;
    for (const char *p = s; *p; p++) {
        if (iscntrl((unsigned char)*p))
            return false;
        if (*p == ';' && p > s && isspace((unsigned char)p[-1]))
            return false;
    }
    return true;
}

/* sRGB decoding of an 8-bit value, in double then rounded once to float: the one definition both the
 * parser and the dump use, so that #rrggbb -> float -> #rrggbb is exact. */
static float srgb8_to_linear(int c)
{
    double s = c / 255.0;
    double l = s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4);
    return (float)l;
}

static int linear_to_srgb8(float v)
{
    int best = 0;
    double best_d = INFINITY;
    for (int c = 0; c < 256; c++) {
        double d = fabs((double)srgb8_to_linear(c) - (double)v);
        if (d < best_d) {
            best_d = d;
            best = c;
        }
    }
    return best;
}

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9')
        return c - '0';
    if (c >= 'a' && c <= 'f')
        return c - 'a' + 10;
    if (c >= 'A' && c <= 'F')
        return c - 'A' + 10;
    return -1;
}

static int parse_color(const char *s, float rgb[3])
{
    if (strlen(s) != 7 || s[0] != '#')
        return -1;
    for (int i = 0; i < 3; i++) {
        int hi = hex_digit(s[1 + 2 * i]), lo = hex_digit(s[2 + 2 * i]);
        if (hi < 0 || lo < 0)
            return -1;
        rgb[i] = srgb8_to_linear(hi * 16 + lo);
    }
    return 0;
}

static int parse_bool(const char *s, bool *out)
{
    static const char *const yes[] = {"true", "yes", "on", "1"};
    static const char *const no[] = {"false", "no", "off", "0"};
    for (int i = 0; i < 4; i++) {
        if (!strcmp(s, yes[i])) {
            *out = true;
            return 0;
        }
        if (!strcmp(s, no[i])) {
            *out = false;
            return 0;
        }
    }
    return -1;
}

/* "t:v, t:v, ..." with 1..FS_PWL_MAX pairs and strictly increasing t, or "none" (no knots). */
static int parse_pwl(const char *s, fs_pwl *out)
{
    fs_pwl f;
    memset(&f, 0, sizeof f);
    if (!strcmp(s, "none")) {
        *out = f;
        return 0;
    }
    const char *p = s;
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t len = comma ? (size_t)(comma - p) : strlen(p);
        char item[160];
        if (f.n == FS_PWL_MAX || len >= sizeof item)
            return -1;
        memcpy(item, p, len);
        item[len] = '\0';
        char *colon = strchr(item, ':');
        if (!colon)
            return -1;
        *colon = '\0';
        double t, v;
        if (parse_real(trim(item), &t) < 0 || parse_real(trim(colon + 1), &v) < 0)
            return -1;
        if (f.n > 0 && !(t > f.t[f.n - 1]))
            return -1;
        f.t[f.n] = t;
        f.v[f.n] = v;
        f.n++;
        if (!comma)
            break;
        p = comma + 1;
    }
    *out = f;
    return 0;
}

static int parse_size(const char *s, int *w, int *h)
{
    const char *x = strchr(s, 'x');
    char a[32];
    size_t len = x ? (size_t)(x - s) : 0;
    if (!x || len >= sizeof a)
        return -1;
    memcpy(a, s, len);
    a[len] = '\0';
    for (const char *p = s; *p; p++)
        if (!isdigit((unsigned char)*p) && p != x)
            return -1;
    long long vw, vh;
    if (parse_integer(a, &vw) < 0 || parse_integer(x + 1, &vh) < 0)
        return -1;
    if (vw < 16 || vw > 16384 || vh < 16 || vh > 16384)
        return -1;
    *w = (int)vw;
    *h = (int)vh;
    return 0;
}

static bool valid_name(const char *s)
{
    size_t n = strlen(s);
    if (n < 1 || n > 63)
        return false;
    for (const char *p = s; *p; p++)
        if (!isalnum((unsigned char)*p) && *p != '.' && *p != '_' && *p != '-')
            return false;
    return true;
}

static int word_index(const char *const *words, const char *s)
{
    for (int i = 0; words[i]; i++)
        if (!strcmp(words[i], s))
            return i;
    return -1;
}

/* Parses `value` for key k into cfg. On failure leaves cfg unchanged and writes what the key expects
 * into why ("a number > 0 (cm)"). base_dir resolves relative paths (NULL keeps them as given). */
static int apply_value(fs_config *cfg, const key_def *k, const char *value, const char *base_dir, char *why,
                       size_t why_size)
{
    char *field = (char *)cfg + k->offset;
    char words[128];
    switch (k->kind) {
    case KEY_NAME:
        if (!valid_name(value)) {
            snprintf(why, why_size, "a name of 1 to 63 characters from A-Z a-z 0-9 . _ -");
            return -1;
        }
        strcpy(field, value);
        return 0;
    case KEY_TEXT:
        if (strlen(value) > 255) {
            snprintf(why, why_size, "at most 255 characters");
            return -1;
        }
        if (!representable(value)) {
            snprintf(why, why_size, "one line without control characters, a leading ';' or ' ;' (a comment)");
            return -1;
        }
        strcpy(field, value);
        return 0;
    case KEY_PATH: {
        if (!representable(value)) {
            snprintf(why, why_size, "a file name without control characters, a leading ';' or ' ;' (a comment)");
            return -1;
        }
        char path[FS_PATH_MAX];
        int n;
        if (value[0] && value[0] != '/' && base_dir) {
            size_t bl = strlen(base_dir);
            n = snprintf(path, sizeof path, "%s%s%s", base_dir, bl && base_dir[bl - 1] == '/' ? "" : "/", value);
        } else {
            n = snprintf(path, sizeof path, "%s", value);
        }
        if (n < 0 || n >= FS_PATH_MAX) {
            snprintf(why, why_size, "a file name of at most %d characters once resolved", FS_PATH_MAX - 1);
            return -1;
        }
        strcpy(field, path);
        return 0;
    }
    case KEY_WORD: {
        int i = word_index(k->words, value);
        if (i < 0) {
            join_words(k->words, " or ", words, sizeof words);
            snprintf(why, why_size, "%s", words);
            return -1;
        }
        *(int *)field = i;
        return 0;
    }
    case KEY_PERIODIC: {
        int i = word_index(k->words, value);
        if (i < 0) {
            join_words(k->words, " or ", words, sizeof words);
            snprintf(why, why_size, "%s", words);
            return -1;
        }
        cfg->domain.periodic_x = i == 1 || i == 3;
        cfg->domain.periodic_y = i == 2 || i == 3;
        return 0;
    }
    case KEY_BOOL: {
        bool b;
        if (parse_bool(value, &b) < 0) {
            snprintf(why, why_size, "true or false");
            return -1;
        }
        *(bool *)field = b;
        return 0;
    }
    case KEY_REAL:
    case KEY_REAL_NONE: {
        double v;
        if (k->kind == KEY_REAL_NONE && !strcmp(value, "none")) {
            *(double *)field = -1.0;
            return 0;
        }
        if (parse_real(value, &v) < 0 || !in_bounds(k, v)) {
            describe_number(k, k->kind == KEY_REAL_NONE ? "none or a number" : "a number", why, why_size);
            return -1;
        }
        *(double *)field = v;
        return 0;
    }
    case KEY_INT: {
        long long v;
        if (parse_integer(value, &v) < 0 || v < (long long)k->lo || v > (long long)k->hi) {
            snprintf(why, why_size, "an integer in %.0f..%.0f", k->lo, k->hi);
            return -1;
        }
        *(int *)field = (int)v;
        return 0;
    }
    case KEY_SEED: {
        uint64_t v;
        if (parse_seed(value, &v) < 0) {
            snprintf(why, why_size, "an integer in 0..%llu", (unsigned long long)UINT64_MAX);
            return -1;
        }
        *(uint64_t *)field = v;
        return 0;
    }
    case KEY_PWL: {
        fs_pwl f;
        if (parse_pwl(value, &f) < 0) {
            snprintf(why, why_size, "none or 1 to %d pairs 't:value' separated by commas, t increasing", FS_PWL_MAX);
            return -1;
        }
        *(fs_pwl *)field = f;
        return 0;
    }
    case KEY_SIZE: {
        int w, h;
        if (parse_size(value, &w, &h) < 0) {
            snprintf(why, why_size, "WIDTHxHEIGHT in pixels, each in 16..16384");
            return -1;
        }
        if (k->offset == OFF(render.preview_width)) {
            cfg->render.preview_width = w;
            cfg->render.preview_height = h;
        } else {
            cfg->render.width = w;
            cfg->render.height = h;
        }
        return 0;
    }
    case KEY_COLOR: {
        float rgb[3];
        if (parse_color(value, rgb) < 0) {
            snprintf(why, why_size, "an sRGB colour #rrggbb");
            return -1;
        }
        memcpy(field, rgb, sizeof rgb);
        return 0;
    }
    }
    snprintf(why, why_size, "a known kind of value");
    return -1;
}

/* The shortest of %.15g, %.16g and %.17g that reads back as exactly v. */
static void format_real(double v, char *buf, size_t size)
{
    for (int digits = 15; digits <= 17; digits++) {
        snprintf(buf, size, "%.*g", digits, v);
        if (strtod(buf, NULL) == v)
            return;
    }
}

/* Formats the value of key k as apply_value reads it back. */
static void format_value(const fs_config *cfg, const key_def *k, char *buf, size_t size)
{
    const char *field = (const char *)cfg + k->offset;
    switch (k->kind) {
    case KEY_NAME:
    case KEY_TEXT:
    case KEY_PATH:
        snprintf(buf, size, "%s", field);
        return;
    case KEY_WORD: {
        int i = *(const int *)field, n = 0;
        while (k->words[n])
            n++;
        snprintf(buf, size, "%s", i >= 0 && i < n ? k->words[i] : "unknown");
        return;
    }
    case KEY_PERIODIC:
        snprintf(buf, size, "%s", k->words[(cfg->domain.periodic_x ? 1 : 0) + (cfg->domain.periodic_y ? 2 : 0)]);
        return;
    case KEY_BOOL:
        snprintf(buf, size, "%s", *(const bool *)field ? "true" : "false");
        return;
    case KEY_REAL:
        format_real(*(const double *)field, buf, size);
        return;
    case KEY_REAL_NONE: {
        double v = *(const double *)field;
        if (v < 0)
            snprintf(buf, size, "none");
        else
            format_real(v, buf, size);
        return;
    }
    case KEY_INT:
        snprintf(buf, size, "%d", *(const int *)field);
        return;
    case KEY_SEED:
        snprintf(buf, size, "%llu", (unsigned long long)*(const uint64_t *)field);
        return;
    case KEY_PWL: {
        const fs_pwl *f = (const fs_pwl *)field;
        if (f->n <= 0) {
            snprintf(buf, size, "none");
            return;
        }
        size_t len = 0;
        buf[0] = '\0';
        for (int i = 0; i < f->n && i < FS_PWL_MAX; i++) {
            char t[32], v[32];
            format_real(f->t[i], t, sizeof t);
            format_real(f->v[i], v, sizeof v);
            int w = snprintf(buf + len, size - len, "%s%s:%s", i ? ", " : "", t, v);
            if (w < 0 || (size_t)w >= size - len)
                return;
            len += (size_t)w;
        }
        return;
    }
    case KEY_SIZE:
        if (k->offset == OFF(render.preview_width))
            snprintf(buf, size, "%dx%d", cfg->render.preview_width, cfg->render.preview_height);
        else
            snprintf(buf, size, "%dx%d", cfg->render.width, cfg->render.height);
        return;
    case KEY_COLOR: {
        const float *rgb = (const float *)field;
        snprintf(buf, size, "#%02x%02x%02x", linear_to_srgb8(rgb[0]), linear_to_srgb8(rgb[1]),
                 linear_to_srgb8(rgb[2]));
        return;
    }
    }
    buf[0] = '\0';
}

/* ---- cross-key checks ---- */

/* Reports a cross-key error on key `blame` of the table, at its line when lines knows it, else at
 * the line of `also` (another key of the rule, -1 for none). */
static int cross_fail(const char *origin, const int *lines, int blame, int also, const char *fmt, ...)
    __attribute__((format(printf, 5, 6)));

static int cross_fail(const char *origin, const int *lines, int blame, int also, const char *fmt, ...)
{
    char what[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    int line = 0;
    if (lines)
        line = lines[blame] ? lines[blame] : also >= 0 ? lines[also] : 0;
    if (line > 0)
        fs_error(FS_ERR_DATA, "%s:%d: [%s] %s: %s", origin, line, key_table[blame].section, key_table[blame].key,
                 what);
    else
        fs_error(FS_ERR_DATA, "%s: [%s] %s: %s", origin, key_table[blame].section, key_table[blame].key, what);
    return -1;
}

/* The key to name in a message: `a`, unless only `b` was written in the preset. */
static int pick(const int *lines, int a, int b)
{
    return lines && !lines[a] && lines[b] ? b : a;
}

static int cross_check(const fs_config *cfg, const char *origin, const int *lines)
{
    const fs_domain *d = &cfg->domain;
    int i_type = key_index("domain", "type"), i_periodic = key_index("domain", "periodic");
    int i_radius = key_index("domain", "radius"), i_width = key_index("domain", "width");
    int i_height = key_index("domain", "height");
    FS_ASSERT((unsigned)d->type <= FS_DOMAIN_MESH && (unsigned)cfg->growth.type <= FS_GROWTH_SPHERE);
    const char *dname = domain_words[d->type];

    int i_file = key_index("domain", "file"), i_model = key_index("preset", "model");
    if (d->type == FS_DOMAIN_MESH) {
        if (!cfg->domain_file[0])
            return cross_fail(origin, lines, i_file, i_type, "expected the path of a UV-mapped OBJ mesh for a mesh "
                              "domain, got ''");
        if (cfg->preset.model != FS_MODEL_SHELL) {
            if (pick(lines, i_model, i_type) == i_model)
                return cross_fail(origin, lines, i_model, -1, "expected shell for a mesh domain, got '%s'",
                                  fs_model_name(cfg->preset.model));
            return cross_fail(origin, lines, i_type, -1, "expected plane, cylinder or sphere for the %s model, got "
                              "'mesh'", fs_model_name(cfg->preset.model));
        }
        if (d->periodic_x || d->periodic_y)
            return cross_fail(origin, lines, i_periodic, -1, "expected none for a mesh domain, got '%s'",
                              periodic_words[(d->periodic_x ? 1 : 0) + (d->periodic_y ? 2 : 0)]);
        if (cfg->growth.type != FS_GROWTH_NONE)
            return cross_fail(origin, lines, key_index("growth", "type"), i_type, "expected none for a mesh domain "
                              "(shrinkage drives it), got '%s'", fs_growth_type_name(cfg->growth.type));
        goto time_checks;
    }

    if (d->type != FS_DOMAIN_PLANE && !(d->radius > 0 && d->radius <= 1e6))
        return cross_fail(origin, lines, i_radius, i_type, "expected a number in (0, 1e+06] (cm) for a %s, got '%g'",
                          dname, d->radius);
    if (d->type != FS_DOMAIN_SPHERE && !(d->height > 0 && d->height <= 1e6))
        return cross_fail(origin, lines, i_height, i_type, "expected a number in (0, 1e+06] (cm) for a %s, got '%g'",
                          dname, d->height);
    if (d->type == FS_DOMAIN_PLANE && !(d->width > 0 && d->width <= 1e6))
        return cross_fail(origin, lines, i_width, i_type, "expected a number in (0, 1e+06] (cm) for a plane, got '%g'",
                          d->width);

    if (d->type == FS_DOMAIN_SPHERE && (d->periodic_x || d->periodic_y)) {
        const char *p = periodic_words[(d->periodic_x ? 1 : 0) + (d->periodic_y ? 2 : 0)];
        if (pick(lines, i_periodic, i_type) == i_periodic)
            return cross_fail(origin, lines, i_periodic, -1, "expected none for a sphere, got '%s'", p);
        return cross_fail(origin, lines, i_type, -1, "expected plane or cylinder for periodic = %s, got 'sphere'", p);
    }

    int i_growth = key_index("growth", "type");
    fs_growth_type g = cfg->growth.type;
    bool growth_ok = g == FS_GROWTH_NONE || (g == FS_GROWTH_PLANAR && d->type != FS_DOMAIN_SPHERE) ||
                     (g == FS_GROWTH_CYLINDER && d->type == FS_DOMAIN_CYLINDER) ||
                     (g == FS_GROWTH_SPHERE && d->type == FS_DOMAIN_SPHERE);
    if (!growth_ok) {
        static const char *const allowed_growth[] = {"none or planar", "none, planar or cylinder", "none or sphere"};
        static const char *const allowed_domain[] = {"any domain", "plane or cylinder", "cylinder", "sphere"};
        if (pick(lines, i_growth, i_type) == i_growth)
            return cross_fail(origin, lines, i_growth, -1, "expected %s for a %s domain, got '%s'",
                              allowed_growth[d->type], dname, fs_growth_type_name(g));
        return cross_fail(origin, lines, i_type, -1, "expected %s for growth type %s, got '%s'", allowed_domain[g],
                          fs_growth_type_name(g), dname);
    }

    int i_lattice = key_index("mesh", "lattice");
    if (cfg->mesh.lattice == FS_LATTICE_HEX && d->type == FS_DOMAIN_SPHERE) {
        if (pick(lines, i_lattice, i_type) == i_lattice)
            return cross_fail(origin, lines, i_lattice, -1, "expected random on a sphere, got 'hex'");
        return cross_fail(origin, lines, i_type, -1, "expected plane or cylinder for lattice hex, got 'sphere'");
    }

    int i_min_size = key_index("mesh", "min_size");
    double extent = fmin(fs_domain_extent_x(d), fs_domain_extent_y(d));
    if (!(cfg->mesh.min_size < extent)) {
        int also = lines && lines[i_type] ? i_type : lines && lines[i_radius] ? i_radius : i_width;
        return cross_fail(origin, lines, i_min_size, also, "expected less than the domain size (%g cm), got '%g'",
                          extent, cfg->mesh.min_size);
    }

time_checks:;
    int i_end = key_index("time", "end"), i_min_step = key_index("time", "min_step");
    if (!(cfg->time.min_step < cfg->time.end)) {
        if (pick(lines, i_min_step, i_end) == i_min_step)
            return cross_fail(origin, lines, i_min_step, -1, "expected less than [time] end (%g), got '%g'",
                              cfg->time.end, cfg->time.min_step);
        return cross_fail(origin, lines, i_end, -1, "expected more than [time] min_step (%g), got '%g'",
                          cfg->time.min_step, cfg->time.end);
    }
    return 0;
}

int fs_preset_validate(const fs_config *cfg, const char *origin)
{
    return cross_check(cfg, origin, NULL);
}

/* ---- parsing ---- */

/* design: inih reads through our line reader so that we know the line of every key (Debian builds it
 * without INI_HANDLER_LINENO), see sections before inih does (it reports no empty sections), strip
 * leading white space (an indented line would otherwise continue the previous value), and pass lines
 * longer than inih's fixed buffer as "key=" with the value kept here. */
typedef struct {
    fs_config *cfg;
    const char *origin;    /* file name or origin used in messages */
    const char *base_dir;  /* directory relative map paths are resolved against, or NULL */
    FILE *fp;              /* the source: a file, */
    const char *text;      /* or the rest of a string */
    char *line;            /* the current physical line */
    size_t cap;
    int lineno;
    size_t bytes;          /* read so far from fp, at most PRESET_MAX_BYTES */
    const char *long_value; /* value of the current line when it did not fit inih's buffer */
    int key_line[N_KEYS];  /* line on which each key was set, 0 if not */
    bool failed;           /* err holds the first error found by the reader or the handler */
    int err_line;          /* its line, 0 if it has none (a read error) */
    fs_errdomain err_domain;
    char err[1024];
} parse_ctx;

static void ctx_fail(parse_ctx *c, fs_errdomain domain, int line, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));

static void ctx_fail(parse_ctx *c, fs_errdomain domain, int line, const char *fmt, ...)
{
    if (c->failed)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err, sizeof c->err, fmt, ap);
    va_end(ap);
    c->failed = true;
    c->err_line = line;
    c->err_domain = domain;
}

/* Reads the next physical line into c->line without its line break. Returns -1 at the end. */
static int next_line(parse_ctx *c)
{
    size_t len = 0;
    if (c->fp) {
        /* byte by byte, so that no line, however long, is read past the cap */
        bool any = false, nul = false;
        int ch;
        errno = 0;
        while ((ch = getc(c->fp)) != EOF) {
            any = true;
            if (++c->bytes > PRESET_MAX_BYTES) {
                ctx_fail(c, FS_ERR_DATA, 0, "%s: preset larger than %d bytes (1 MiB)", c->origin, PRESET_MAX_BYTES);
                return -1;
            }
            if (ch == '\n')
                break;
            nul |= ch == '\0';
            if (len + 2 > c->cap) {
                c->cap = c->cap ? 2 * c->cap : 256;
                c->line = fs_realloc(c->line, c->cap);
            }
            c->line[len++] = (char)ch;
        }
        if (ferror(c->fp)) {
            ctx_fail(c, FS_ERR_IO, 0, "%s: cannot read preset: %s", c->origin, strerror(errno ? errno : EIO));
            return -1;
        }
        if (!any)
            return -1;
        if (!c->line) {
            c->cap = 1;
            c->line = fs_malloc(1);
        }
        c->line[len] = '\0';
        c->lineno++;
        if (nul) {
            ctx_fail(c, FS_ERR_DATA, c->lineno, "%s:%d: %s", c->origin, c->lineno, syntax_message);
            return -1;
        }
    } else {
        if (!*c->text)
            return -1;
        const char *nl = strchr(c->text, '\n');
        len = nl ? (size_t)(nl - c->text) : strlen(c->text);
        if (len + 1 > c->cap) {
            c->cap = len + 1;
            c->line = fs_realloc(c->line, c->cap);
        }
        memcpy(c->line, c->text, len);
        c->line[len] = '\0';
        c->text += len + (nl ? 1 : 0);
        c->lineno++;
    }
    return 0;
}

/* Checks the name of a "[section]" line; inih itself reports a missing ']'. */
static int check_section(parse_ctx *c, const char *s)
{
    const char *close = strchr(s + 1, ']');
    if (!close)
        return 0;
    char name[80];
    size_t len = (size_t)(close - s - 1);
    if (len >= sizeof name)
        len = sizeof name - 1;
    memcpy(name, s + 1, len);
    name[len] = '\0';
    if (section_index(name) >= 0)
        return 0;
    char list[160], vbuf[80];
    join_words(section_names, ", ", list, sizeof list);
    ctx_fail(c, FS_ERR_DATA, c->lineno, "%s:%d: unknown section [%s]: expected one of: %s", c->origin, c->lineno,
             shown(name, vbuf), list);
    return -1;
}

/* A line too long for inih's buffer: comments are dropped, "key = value" is passed as "key=" and the
 * value kept in c->long_value (split as inih splits: at the first '=' or ':', ' ;' starts a comment). */
static char *pass_long_line(parse_ctx *c, char *s, char *buf, int num)
{
    if (*s == ';' || *s == '#') {
        buf[0] = '\0';
        return buf;
    }
    if (*s == '[') {
        memcpy(buf, s, (size_t)num - 1);
        buf[num - 1] = '\0';
        return buf;
    }
    char *p = s;
    bool was_space = false;
    while (*p && *p != '=' && *p != ':' && !(was_space && *p == ';')) {
        was_space = isspace((unsigned char)*p);
        p++;
    }
    size_t name_len = (size_t)(p - s);
    if ((*p != '=' && *p != ':') || name_len + 3 > (size_t)num) {
        ctx_fail(c, FS_ERR_DATA, c->lineno, "%s:%d: %s", c->origin, c->lineno, syntax_message);
        return NULL;
    }
    char *value = p + 1;
    while (isspace((unsigned char)*value))
        value++;
    was_space = false;
    for (char *q = value; *q; q++) {
        if (was_space && *q == ';') {
            *q = '\0';
            break;
        }
        was_space = isspace((unsigned char)*q);
    }
    c->long_value = trim(value);
    memcpy(buf, s, name_len);
    buf[name_len] = '=';
    buf[name_len + 1] = '\0';
    return buf;
}

static char *read_line(char *buf, int num, void *stream)
{
    parse_ctx *c = stream;
    c->long_value = NULL;
    if (c->failed || next_line(c) < 0)
        return NULL;
    char *s = c->line;
    if (c->lineno == 1 && !strncmp(s, "\xEF\xBB\xBF", 3))
        s += 3;
    s = trim(s);
    if (*s == '[' && check_section(c, s) < 0)
        return NULL;
    size_t len = strlen(s);
    if (len + 2 <= (size_t)num) {
        memcpy(buf, s, len + 1);
        return buf;
    }
    return pass_long_line(c, s, buf, num);
}

static int on_key(void *user, const char *section, const char *name, const char *value)
{
    parse_ctx *c = user;
    int line = c->lineno;
    char vbuf[80], list[256], why[256];
    if (c->long_value)
        value = c->long_value;
    if (!*name) {
        ctx_fail(c, FS_ERR_DATA, line, "%s:%d: %s", c->origin, line, syntax_message);
        return 0;
    }
    if (!*section) {
        ctx_fail(c, FS_ERR_DATA, line, "%s:%d: key '%s' outside any section: expected a '[section]' line before it",
                 c->origin, line, shown(name, vbuf));
        return 0;
    }
    int i = key_index(section, name);
    if (i < 0) {
        section_keys(section, list, sizeof list);
        ctx_fail(c, FS_ERR_DATA, line, "%s:%d: unknown key [%s] %s: expected one of: %s", c->origin, line, section,
                 shown(name, vbuf), list);
        return 0;
    }
    if (c->key_line[i]) {
        ctx_fail(c, FS_ERR_DATA, line, "%s:%d: [%s] %s: expected one value (already set on line %d), got '%s'",
                 c->origin, line, section, name, c->key_line[i], shown(value, vbuf));
        return 0;
    }
    if (apply_value(c->cfg, &key_table[i], value, c->base_dir, why, sizeof why) < 0) {
        ctx_fail(c, FS_ERR_DATA, line, "%s:%d: [%s] %s: expected %s, got '%s'", c->origin, line, section, name, why,
                 shown(value, vbuf));
        return 0;
    }
    c->key_line[i] = line;
    return 1;
}

/* Parses the source set up in c over a copy of c->cfg, then checks cross-key consistency; the caller's
 * configuration changes only on success. */
static int parse(parse_ctx *c)
{
    fs_config *target = c->cfg;
    fs_config *work = fs_malloc(sizeof *work);
    *work = *target;
    c->cfg = work;
    int rc = ini_parse_stream(read_line, c, on_key, c);
    free(c->line);
    c->line = NULL;
    c->cfg = target;
    int status = -1;
    if (rc == -2)
        fs_error(FS_ERR_INTERNAL, "%s: out of memory while parsing the preset", c->origin);
    else if (rc > 0 && (!c->failed || c->err_line == 0 || rc < c->err_line))
        fs_error(FS_ERR_DATA, "%s:%d: %s", c->origin, rc, syntax_message);
    else if (c->failed)
        fs_error(c->err_domain, "%s", c->err);
    else if (cross_check(work, c->origin, c->key_line) == 0)
        status = 0;
    if (status == 0)
        *target = *work;
    free(work);
    return status;
}

/* The directory of a file, made absolute so that paths resolved against it survive a dump. */
static char *file_dir(const char *path)
{
    const char *slash = strrchr(path, '/');
    size_t len = !slash ? 0 : slash == path ? 1 : (size_t)(slash - path);
    if (path[0] == '/') {
        char *dir = fs_malloc(len + 1);
        memcpy(dir, path, len);
        dir[len] = '\0';
        return dir;
    }
    char cwd[FS_PATH_MAX];
    if (!getcwd(cwd, sizeof cwd))
        strcpy(cwd, ".");
    size_t n = strlen(cwd) + len + 2;
    char *dir = fs_malloc(n);
    if (len)
        snprintf(dir, n, "%s/%.*s", cwd, (int)len, path);
    else
        snprintf(dir, n, "%s", cwd);
    return dir;
}

int fs_preset_load(const char *path, fs_config *cfg)
{
    FILE *fp = open_preset(path);
    if (!fp)
        return -1;
    parse_ctx *c = fs_calloc(1, sizeof *c);
    c->cfg = cfg;
    c->origin = path;
    c->fp = fp;
    char *dir = file_dir(path);
    c->base_dir = dir;
    int rc = parse(c);
    free(dir);
    free(c);
    fclose(fp);
    return rc;
}

int fs_preset_load_string(const char *text, const char *origin, fs_config *cfg)
{
    parse_ctx *c = fs_calloc(1, sizeof *c);
    c->cfg = cfg;
    c->origin = origin;
    c->text = text;
    int rc = parse(c);
    free(c);
    return rc;
}

int fs_preset_set(fs_config *cfg, const char *assignment)
{
    char lhs[128], value[FS_PATH_MAX + 64], vbuf[80], list[256], why[256];
    const char *eq = strchr(assignment, '=');
    size_t len = eq ? (size_t)(eq - assignment) : 0;
    char *section = NULL, *key = NULL, *dot = NULL;
    if (eq && len < sizeof lhs && strlen(eq + 1) < sizeof value) {
        memcpy(lhs, assignment, len);
        lhs[len] = '\0';
        section = trim(lhs);
        dot = strchr(section, '.');
    }
    if (dot) {
        *dot = '\0';
        key = dot + 1;
    }
    if (!key || !*section || !*key || strchr(key, '.') || strpbrk(section, " \t") || strpbrk(key, " \t")) {
        fs_error(FS_ERR_USAGE, "--set: expected SECTION.KEY=VALUE, got '%s'", shown(assignment, vbuf));
        return -1;
    }
    strcpy(value, eq + 1);
    char *v = trim(value);
    if (section_index(section) < 0) {
        join_words(section_names, ", ", list, sizeof list);
        fs_error(FS_ERR_USAGE, "--set %s.%s: unknown section [%s]: expected one of: %s", section, key, section, list);
        return -1;
    }
    int i = key_index(section, key);
    if (i < 0) {
        section_keys(section, list, sizeof list);
        fs_error(FS_ERR_USAGE, "--set %s.%s: unknown key [%s] %s: expected one of: %s", section, key, section, key,
                 list);
        return -1;
    }
    if (apply_value(cfg, &key_table[i], v, NULL, why, sizeof why) < 0) {
        fs_error(FS_ERR_DATA, "--set %s.%s: expected %s, got '%s'", section, key, why, shown(v, vbuf));
        return -1;
    }
    return 0;
}

/* ---- writing ---- */

void fs_preset_visit(const fs_config *cfg, fs_preset_visit_fn fn, void *ctx)
{
    char value[4096];
    for (int i = 0; i < N_KEYS; i++) {
        format_value(cfg, &key_table[i], value, sizeof value);
        fn(ctx, key_table[i].section, key_table[i].key, value);
    }
}

typedef struct {
    FILE *out;
    const char *section;
} dump_ctx;

static void dump_key(void *ctx, const char *section, const char *key, const char *value)
{
    dump_ctx *d = ctx;
    if (!d->section || strcmp(d->section, section)) {
        fprintf(d->out, "\n[%s]\n", section);
        d->section = section;
    }
    if (*value)
        fprintf(d->out, "%s = %s\n", key, value);
    else
        fprintf(d->out, "%s =\n", key);
}

void fs_preset_dump(const fs_config *cfg, FILE *out)
{
    dump_ctx d = {out, NULL};
    fprintf(out, "# fissure preset (resolved)\n");
    fs_preset_visit(cfg, dump_key, &d);
}

/* ---- the preset path ---- */

typedef struct {
    char **items;
    int n, cap;
} str_list;

static void list_push(str_list *l, char *s)
{
    if (l->n == l->cap) {
        l->cap = l->cap ? 2 * l->cap : 8;
        l->items = fs_realloc(l->items, (size_t)l->cap * sizeof *l->items);
    }
    l->items[l->n++] = s;
}

static void list_free(str_list *l)
{
    for (int i = 0; i < l->n; i++)
        free(l->items[i]);
    free(l->items);
    l->items = NULL;
    l->n = l->cap = 0;
}

static char *path_join(const char *a, const char *b, const char *suffix)
{
    size_t n = strlen(a) + strlen(b) + strlen(suffix) + 2;
    char *p = fs_malloc(n);
    snprintf(p, n, "%s/%s%s", a, b, suffix);
    return p;
}

/* The directories searched for presets, in order (SPEC §7). */
static str_list preset_dirs(void)
{
    str_list dirs = {NULL, 0, 0};
    const char *env = getenv("FISSURE_PRESET_PATH");
    if (env) {
        const char *p = env;
        while (*p) {
            const char *colon = strchr(p, ':');
            size_t len = colon ? (size_t)(colon - p) : strlen(p);
            if (len > 0) {
                char *dir = fs_malloc(len + 1);
                memcpy(dir, p, len);
                dir[len] = '\0';
                list_push(&dirs, dir);
            }
            p += len + (colon ? 1 : 0);
        }
    }
    const char *xdg = getenv("XDG_DATA_HOME");
    const char *home = getenv("HOME");
    if (xdg && xdg[0] == '/')
        list_push(&dirs, path_join(xdg, "fissure/presets", ""));
    else if (home && *home)
        list_push(&dirs, path_join(home, ".local/share/fissure/presets", ""));
    list_push(&dirs, path_join(FS_PKGDATADIR, "presets", ""));
    list_push(&dirs, path_join(FS_SRCDIR, "presets", ""));
    return dirs;
}

/* 0 when path names a regular file, else an errno value (EISDIR for a directory) or NOT_REGULAR. */
static int file_status(const char *path)
{
    struct stat st;
    if (stat(path, &st) != 0)
        return errno;
    return S_ISDIR(st.st_mode) ? EISDIR : S_ISREG(st.st_mode) ? 0 : NOT_REGULAR;
}

static bool is_file(const char *path)
{
    return file_status(path) == 0;
}

static bool has_ini_suffix(const char *name)
{
    size_t n = strlen(name);
    return n > 4 && !strcmp(name + n - 4, ".ini");
}

typedef struct {
    char *stem;  /* file name without .ini: what shadows what along the path */
    char *path;
    char *name;  /* the [preset] name (the stem when unset or unreadable) */
    char *description;
    int order;   /* position along the path */
} found_preset;

/* The *.ini files on the preset path, each stem once (the first found wins), in path order. */
static int scan_presets(found_preset **out)
{
    str_list dirs = preset_dirs();
    found_preset *found = NULL;
    int n = 0, cap = 0;
    for (int i = 0; i < dirs.n; i++) {
        DIR *dir = opendir(dirs.items[i]);
        if (!dir)
            continue;
        struct dirent *e;
        while ((e = readdir(dir))) {
            if (!has_ini_suffix(e->d_name))
                continue;
            size_t stem = strlen(e->d_name) - 4;
            bool seen = false;
            for (int j = 0; j < n && !seen; j++)
                seen = strlen(found[j].stem) == stem && !strncmp(found[j].stem, e->d_name, stem);
            if (seen)
                continue;
            char *path = path_join(dirs.items[i], e->d_name, "");
            if (!is_file(path)) {
                free(path);
                continue;
            }
            if (n == cap) {
                cap = cap ? 2 * cap : 16;
                found = fs_realloc(found, (size_t)cap * sizeof *found);
            }
            found_preset *f = &found[n];
            f->stem = fs_malloc(stem + 1);
            memcpy(f->stem, e->d_name, stem);
            f->stem[stem] = '\0';
            f->path = path;
            f->name = NULL;
            f->description = NULL;
            f->order = n;
            n++;
        }
        closedir(dir);
    }
    list_free(&dirs);
    *out = found;
    return n;
}

/* Reads the [preset] name and description of f (the error message as description when it is broken). */
static void read_preset_info(found_preset *f, fs_config *cfg)
{
    *cfg = fs_config_default();
    cfg->preset.name[0] = '\0';
    if (fs_preset_load(f->path, cfg) == 0) {
        f->name = fs_strdup(cfg->preset.name[0] ? cfg->preset.name : f->stem);
        f->description = fs_strdup(cfg->preset.description);
    } else {
        const char *msg = fs_error_message();
        size_t n = strlen(msg) + 16;
        f->name = fs_strdup(f->stem);
        f->description = fs_malloc(n);
        snprintf(f->description, n, "(unreadable: %s)", msg);
    }
}

static void free_found(found_preset *found, int n)
{
    for (int i = 0; i < n; i++) {
        free(found[i].stem);
        free(found[i].path);
        free(found[i].name);
        free(found[i].description);
    }
    free(found);
}

/* A preset on the path whose [preset] name is `name` (as --list-presets shows it), or NULL. */
static char *find_by_name(const char *name)
{
    found_preset *found;
    int n = scan_presets(&found);
    fs_config *cfg = fs_malloc(sizeof *cfg);
    char *path = NULL;
    for (int i = 0; i < n && !path; i++) {
        read_preset_info(&found[i], cfg);
        if (!strcmp(found[i].name, name))
            path = fs_strdup(found[i].path);
    }
    free(cfg);
    free_found(found, n);
    return path;
}

char *fs_preset_find(const char *name)
{
    int status = file_status(name);
    if (status == 0)
        return fs_strdup(name);
    if (!*name || strchr(name, '/')) {
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: %s", name, status_text(status));
        return NULL;
    }
    str_list dirs = preset_dirs();
    char looked[768];
    size_t len = 0;
    looked[0] = '\0';
    char *unreadable = NULL; /* the first file of the name on the path that is not a regular file */
    int unreadable_status = 0;
    for (int i = 0; i < dirs.n; i++) {
        for (int with_ini = 0; with_ini < (has_ini_suffix(name) ? 1 : 2); with_ini++) {
            char *p = path_join(dirs.items[i], name, with_ini ? ".ini" : "");
            int st = file_status(p);
            if (st == 0) {
                list_free(&dirs);
                free(unreadable);
                return p;
            }
            if (st != ENOENT && st != ENOTDIR && !unreadable) {
                unreadable = p;
                unreadable_status = st;
            } else {
                free(p);
            }
        }
        int w = snprintf(looked + len, sizeof looked - len, "%s%s", i ? ", " : "", dirs.items[i]);
        if (w > 0 && (size_t)w < sizeof looked - len)
            len += (size_t)w;
    }
    list_free(&dirs);
    char *path = find_by_name(name);
    fs_error_clear();
    if (path) {
        free(unreadable);
        return path;
    }
    /* a name that exists here or on the path but cannot be read (a directory, a symlink loop, a
     * device, a FIFO) says why, rather than "no such file" */
    if (status != ENOENT)
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: %s, and not on the preset path (%s)", name,
                 status_text(status), looked);
    else if (unreadable)
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: %s: %s", name, unreadable, status_text(unreadable_status));
    else
        fs_error(FS_ERR_NOINPUT, "%s: cannot open preset: no such file, and not on the preset path (%s)", name,
                 looked);
    free(unreadable);
    return NULL;
}

static int found_cmp(const void *a, const void *b)
{
    const found_preset *x = a, *y = b;
    int c = strcmp(x->name, y->name);
    return c ? c : x->order - y->order;
}

int fs_preset_list(FILE *out)
{
    found_preset *found;
    int n = scan_presets(&found);
    fs_config *cfg = fs_malloc(sizeof *cfg);
    for (int i = 0; i < n; i++)
        read_preset_info(&found[i], cfg);
    free(cfg);
    if (n > 1)
        qsort(found, (size_t)n, sizeof *found, found_cmp);
    int listed = 0;
    for (int i = 0; i < n; i++) {
        if (i > 0 && !strcmp(found[i].name, found[i - 1].name))
            continue;
        fprintf(out, "%s\t%s\n", found[i].name, found[i].description);
        listed++;
    }
    free_found(found, n);
    fs_error_clear();
    if (fflush(out) != 0 || ferror(out)) {
        fs_error(FS_ERR_IO, "cannot write the preset list: %s", strerror(errno));
        return -1;
    }
    return listed;
}
